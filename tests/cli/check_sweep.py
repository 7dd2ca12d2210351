#!/usr/bin/env python3
"""fictus sweep: its members agree with single solves, its contact columns with a manufactured
solution, its CSV header with docs/usage.md, and bad members stop it with one error line.

usage: check_sweep.py FICTUS_EXE SOURCE_DIR WORK_DIR
"""
import csv
import json
import math
import os
import re
import shutil
import subprocess
import sys

exe, source, work = sys.argv[1:4]
examples = os.path.join(source, "examples")
failures = []
os.makedirs(work, exist_ok=True)


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


def run(*args):
    return subprocess.run([exe, *args], capture_output=True, text=True)


def sweep(name, *args):
    out = os.path.join(work, name)
    shutil.rmtree(out, ignore_errors=True)
    r = run("sweep", *args, "--out", out)
    if r.returncode != 0:
        raise SystemExit(f"sweep {' '.join(args)} failed: {r.stderr}")
    with open(os.path.join(out, "sweep.csv")) as f:
        rows = list(csv.DictReader(f))
    with open(os.path.join(out, "sweep.json")) as f:
        document = json.load(f)
    return rows, document


def solve(name, *args):
    out = os.path.join(work, name)
    shutil.rmtree(out, ignore_errors=True)
    r = run("solve", *args, "--files", "results.json", "--out", out, "--quiet")
    if r.returncode != 0:
        raise SystemExit(f"solve {' '.join(args)} failed: {r.stderr}")
    with open(os.path.join(out, "results.json")) as f:
        return json.load(f)


def close(a, b, tol, scale=1.0):
    return abs(a - b) <= tol * max(abs(a), abs(b), scale)


def same_member(row, results, what, tol=1e-8):
    c = results["contact"]
    check(int(row["contact_points"]) == c["points"], f"{what}: contact points {row['contact_points']} = {c['points']}")
    for column, key in [("contact_measure", "measure"), ("contact_force", "force"), ("lambda_integral", "lambda_integral"),
                        ("max_gap", "max_gap")]:
        check(close(float(row[column]), c[key], tol), f"{what}: {column} {row[column]} = solve's {c[key]:.12g}")
    check(int(row["newton_steps"]) == results["newton"]["iterations"], f"{what}: Newton steps equal")
    check(int(row["multipliers"]) == results["multipliers"], f"{what}: m equal")


# 1. Contact columns against the manufactured circle (u = ((x − ½)⁺)³, r = 0.3): contact on the
#    right half, measure πr, force ∫ ∂u/∂n ds = ∫ 3r²cos²θ·cosθ·r dθ over (−π/2, π/2) = 4r³.
r = 0.3
for variant in ["smooth", "nonsmooth"]:
    rows, _ = sweep(f"circle_{variant}", os.path.join(examples, "circle.toml"), "--g-scale", "1",
                    "--variant", variant)
    row = rows[0]
    spacing = float(row["contact_measure"]) / max(int(row["contact_points"]), 1)
    check(abs(float(row["contact_measure"]) - math.pi * r) <= 2.01 * spacing,
          f"circle {variant}: contact measure {row['contact_measure']} within two spacings of pi r = {math.pi * r:.5f}")
    check(close(float(row["contact_force"]), 4 * r**3, 5e-3),
          f"circle {variant}: contact force {row['contact_force']} within 0.5 % of 4 r^3 = {4 * r**3:.5f}")
    check(abs(float(row["min_gap"])) < 1e-12 and float(row["max_gap"]) > 0.02,
          f"circle {variant}: min gap {row['min_gap']} ~ 0, max gap {row['max_gap']} = the free part's opening")

# 2. A [parameters] sweep gives, member by member, what `solve --parameter` gives: in g (Newton
#    only), in f (a new u0) and in the geometry (new rows), each reusing the solver.
parameters = os.path.join(examples, "parameters.toml")
for name, values in [("height", "-0.05,0.04"), ("load", "-2,-0.5"), ("rad", "0.22,0.3")]:
    rows, document = sweep(f"parameter_{name}", parameters, "--parameter", f"{name}={values}", "--N", "128")
    check(document["sweep"] == {"kind": "parameter", "name": name, "values": [float(v) for v in values.split(",")]},
          f"{name}: sweep.json names the family")
    check(list(rows[0].keys())[0] == name, f"{name}: the first column is named {name}")
    for row, value in zip(rows, values.split(",")):
        results = solve(f"parameter_{name}_{value}", parameters, "--parameter", f"{name}={value}", "--N", "128")
        check(results["problem"]["parameters"][name] == float(value), f"{name}={value}: results.json echoes it")
        same_member(row, results, f"{name}={value}")

# 3. --move and --rotate give what a solve of the moved or turned curve gives (g's phi follows the
#    moved center), and --g-scale on the paper's problem what `solve` gives at scale 1.
text = open(parameters).read()
moved = os.path.join(work, "moved.toml")
with open(moved, "w") as f:
    f.write(text.replace("center = [0.5, 0.5]", "center = [0.56, 0.5]"))
rows, _ = sweep("move", parameters, "--move", "0,0.06", "--N", "128")
same_member(rows[1], solve("moved", moved, "--N", "128"), "move 0.06", tol=1e-7)
ellipse = os.path.join(work, "ellipse.toml")
turned = os.path.join(work, "turned.toml")
body = """[domain]\nN = 128\n[geometry]\nshape = "ellipse"\ncenter = [0.5, 0.5]\nsemi_axes = [0.3, 0.15]\nangle = {angle}\n
[data]\nf = "-1 - x"\ng = "0.04 * sin(2 * phi) + 0.1 * (x - 0.5)"\n"""
with open(ellipse, "w") as f:
    f.write(body.format(angle=0.0))
with open(turned, "w") as f:
    f.write(body.format(angle=0.7))
rows, _ = sweep("rotate", ellipse, "--rotate", "0.7")
same_member(rows[0], solve("turned", turned), "rotate 0.7", tol=1e-7)
rows, _ = sweep("paper", "--g-scale", "0.5,1", "--N", "128")
same_member(rows[1], solve("paper", "--N", "128", "--condition_number", "false"), "paper g_scale 1")

# 3b. A turned or moved polygon keeps its corners (points off the corners, the kink projector): angle 0
#     and shift 0 give what the obstacle family gives at scale 1; the smooth variant stays refused.
polygon = os.path.join(examples, "polygon.toml")
reference = sweep("polygon_scale", polygon, "--g-scale", "1")[0][0]
for kind in ("--rotate", "--move"):
    row = sweep(f"polygon{kind}", polygon, kind, "0")[0][0]
    check(row["converged"] == "1" and all(row[c] == reference[c] for c in ("contact_points", "newton_steps")) and
          close(float(row["contact_force"]), float(reference["contact_force"]), 1e-12),
          f"polygon {kind} 0 = --g-scale 1 ({row['contact_points']} vs {reference['contact_points']} points)")
r = run("sweep", polygon, "--rotate", "0,0.1", "--variant", "smooth", "--out", "")
check(r.returncode == 1 and "formulation.variant" in r.stderr and "(at" not in r.stderr,
      f"a polygon in the smooth variant is the base problem's error, not a member's: {r.stderr.strip()}")

# 3c. The file is read once: a sweep of a pipe works.
with open(parameters) as f:
    r = subprocess.run([exe, "sweep", "/dev/stdin", "--parameter", "height=0,0.01", "--N", "128", "--out", ""],
                       stdin=f, capture_output=True, text=True)
check(r.returncode == 0 and len(r.stdout.strip().splitlines()) == 4, f"sweep of a pipe: {r.stderr.strip()}")

# 4. The CSV header is the documented one (docs/usage.md, the sweep's column table).
usage = open(os.path.join(source, "docs", "usage.md")).read()
section = usage[usage.index("## `fictus sweep`"):usage.index("## `fictus options`")]
documented = ["height"]
for line in section.splitlines():
    if line.startswith("| `") and "` |" in line and not line.startswith("| `--"):
        documented += [c.strip(" `") for c in line.split("|")[1].split(",")]
header = list(sweep("header", parameters, "--parameter", "height=0", "--N", "128")[0][0].keys())
check(header == documented, f"CSV header {header} is the documented {documented}")

# 5. Bad families and bad members: exit 1, one line naming what is wrong, nothing written.
out = os.path.join(work, "bad")
for args, expected in [
    (["--parameter", "nothere=1,2"], r"--parameter: nothere is not in the problem file's \[parameters\]"),
    (["--parameter", "rad=0.2,0.5"], r"\(at rad = 0.5\)"),
    (["--parameter", "height"], r"--parameter: expected NAME=LIST"),
    (["--g-scale", "1", "--rotate", "0"], r"give exactly one of"),
    (["--parameter", "height=1:2:x"], r"--parameter: expected a list"),
]:
    shutil.rmtree(out, ignore_errors=True)
    r = run("sweep", parameters, "--N", "128", *args, "--out", out)
    lines = r.stderr.strip().splitlines()
    check(r.returncode == 1 and len(lines) == 1 and lines[0].startswith("fictus: error: ") and
          re.search(expected, lines[0]) is not None and not os.path.exists(out),
          f"sweep {' '.join(args)}: exit {r.returncode}, {lines}")
clash = os.path.join(work, "clash.toml")
with open(clash, "w") as f:
    f.write(text.replace("[parameters]", "[parameters]\nseconds = 1.0").replace("0.05 * sin", "seconds * 0.05 * sin"))
r = run("sweep", clash, "--parameter", "seconds=1,2", "--N", "128", "--out", "")
check(r.returncode == 1 and "clash with that column" in r.stderr, f"a parameter named like a column: {r.stderr.strip()}")
# Newton fails for a member: exit 2, the key first, the member named, the rows written.
out = os.path.join(work, "newton")
shutil.rmtree(out, ignore_errors=True)
r = run("sweep", "--N", "128", "--g-scale", "1,2", "--max_newton", "2", "--out", out)
check(r.returncode == 2 and r.stderr.startswith("fictus: error: solver.max_newton: at g_scale = 1 (2 of 2") and
      os.path.exists(os.path.join(out, "sweep.csv")), f"Newton failing in a sweep: {r.stderr.strip()[:200]}")
r = run("sweep", "--N", "64", "--parameter", "a=1", "--out", "")
check(r.returncode == 1 and "needs a problem file" in r.stderr, "--parameter without a file is refused")

if failures:
    print(f"{len(failures)} checks failed")
    sys.exit(1)
print("all checks passed")
