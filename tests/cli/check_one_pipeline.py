#!/usr/bin/env python3
"""One pipeline for both dimensions, from the command line:

1. a 3-D sweep equals single solves: --g-scale against --parameter scale=v, --parameter lift=… against
   single solves with the same value, --rotate 0 (about x) against the unrotated solve;
2. a results.json alone is enough to solve the run again (2-D and 3-D): a problem file made from its
   problem echo and options gives the same answer; its keys are the same in both dimensions;
3. the box is written in bounds order in both dimensions, and --box works in 3-D;
4. an option of the other dimension is refused (file and flag);
5. --file and --resolution reach a 3-D mesh problem.

usage: check_one_pipeline.py FICTUS SOURCE_DIR SCRATCH
"""
import json
import os
import shutil
import subprocess
import sys

from toml_text import toml_value

FICTUS, SOURCE, SCRATCH = sys.argv[1], sys.argv[2], sys.argv[3]
SPHERE = os.path.join(SOURCE, "tests", "inputs", "sphere_parameters.toml")


def run(*args, ok=True):
    r = subprocess.run([FICTUS, *args], capture_output=True, text=True)
    if ok and r.returncode != 0:
        sys.exit(f"FAIL: fictus {' '.join(args)}: {r.stderr.strip()}")
    return r


def check(condition, message):
    if not condition:
        sys.exit("FAIL: " + message)


def close(a, b, tolerance=1e-9):
    return abs(a - b) <= tolerance * max(abs(a), abs(b), 1e-300)


def solve(folder, *args):
    path = os.path.join(SCRATCH, folder)
    shutil.rmtree(path, ignore_errors=True)
    run("solve", *args, "--files", "results.json", "--out", path, "--quiet")
    with open(os.path.join(path, "results.json")) as f:
        return json.load(f)


def sweep(folder, *args, problem=SPHERE):
    path = os.path.join(SCRATCH, folder)
    shutil.rmtree(path, ignore_errors=True)
    run("sweep", problem, *args, "--out", path)
    with open(os.path.join(path, "sweep.json")) as f:
        return json.load(f)


def same_contact(row, single, what):
    for key, column in (("force", "contact_force"), ("measure", "contact_measure"), ("min_gap", "min_gap")):
        check(close(row[column], single["contact"][key], 1e-9) or abs(row[column] - single["contact"][key]) < 1e-13,
              f"{what}: sweep {column} {row[column]!r}, single solve {single['contact'][key]!r}")
    check(row["contact_points"] == single["contact"]["points"], f"{what}: contact points differ")


def sweeps_equal_single_solves():
    s = sweep("sweep_g", "--g-scale", "0.5,1.5")
    check(s["dim"] == 3 and len(s["rows"]) == 2, f"a 3-D sweep: {s.get('dim')}, {len(s['rows'])} rows")
    for row in s["rows"]:
        single = solve("single_g", SPHERE, "--parameter", f"scale={row['g_scale']!r}")
        same_contact(row, single, f"g_scale = {row['g_scale']}")
    s = sweep("sweep_lift", "--parameter", "lift=-0.02,0.03")
    for row in s["rows"]:
        single = solve("single_lift", SPHERE, "--parameter", f"lift={row['lift']!r}")
        same_contact(row, single, f"lift = {row['lift']}")
        check(row["reused_boundary"] is True, f"lift = {row['lift']}: a parameter of g only keeps the boundary")
    # a mesh surface whose parameter is not in [geometry]: the mesh is kept, not read again
    mesh = os.path.join(SOURCE, "tests", "inputs", "mesh_parameters.toml")
    s = sweep("sweep_mesh", "--parameter", "lift=0,0.05", problem=mesh)
    for row in s["rows"]:
        single = solve("single_mesh", mesh, "--parameter", f"lift={row['lift']!r}")
        same_contact(row, single, f"mesh, lift = {row['lift']}")
        check(row["reused_boundary"] is True, f"mesh, lift = {row['lift']}: the mesh is kept")
    s = sweep("sweep_rotate", "--rotate", "0,0.4", "--axis", "x")
    check(s["sweep"]["axis"] == "x", "the rotation axis is recorded")
    same_contact(s["rows"][0], solve("single_plain", SPHERE), "rotate = 0")


def problem_file_from(results):
    """A problem file made from results.json alone: [geometry], [data], [parameters] as echoed, and
    every option in its section (fictus options --json says which)."""
    schema = json.loads(run("options", "--json").stdout)
    section_of = {o["key"]: o["section"] for o in schema}
    sections = {"domain": {}, "formulation": {}, "data": dict(results["problem"].get("data", {})), "solver": {},
                "geometry": results["problem"]["geometry"], "parameters": results["problem"].get("parameters", {})}
    for key, value in results["options"].items():
        sections[section_of[key]][key] = value
    text = ""
    for name, table in sections.items():
        if table:
            text += f"[{name}]\n" + "".join(f"{k} = {toml_value(v)}\n" for k, v in table.items())
    return text


def results_alone_redo_the_run():
    keys = {}
    for name, args in (("3d", (SPHERE, "--parameter", "lift=0.01", "--N", "40", "--box", "-0.1,1.1,-0.1,1.1,0,1.2")),
                       ("2d", (os.path.join(SOURCE, "examples", "circle.toml"), "--N", "128", "--variant", "nonsmooth"))):
        first = solve(f"redo_{name}_first", *args)
        keys[name] = {k: sorted(v) if isinstance(v, dict) else None for k, v in first.items()}
        path = os.path.join(SCRATCH, f"redo_{name}.toml")
        with open(path, "w") as f:
            f.write(problem_file_from(first))
        again = solve(f"redo_{name}_again", path)
        for key in ("multipliers", "box", "options"):
            check(first[key] == again[key], f"{name}: {key} differs after the redo: {first[key]} / {again[key]}")
        for key in ("force", "measure", "lambda_integral"):
            check(close(first["contact"][key], again["contact"][key], 1e-12), f"{name}: contact.{key} differs")
        check(first["newton"]["iterations"] == again["newton"]["iterations"], f"{name}: Newton steps differ")
    # the same keys in both dimensions, optional blocks null where unused (3-D adds the triangles and
    # grid.Nz; 2-D's options list is longer; errors come with an exact solution, which the 2-D circle
    # has and the sphere not)
    for key in (set(keys["2d"]) | set(keys["3d"])) - {"errors"}:
        check(key in keys["2d"] and key in keys["3d"], f"results.json: {key} in one dimension only")
        if key not in ("options", "grid", "boundary", "problem", "timings", "errors", "flux_balance"):
            check(keys["2d"][key] == keys["3d"][key], f"results.json: {key} has {keys['2d'][key]} / {keys['3d'][key]}")


def boxes_and_dimensions():
    r = solve("box3d", SPHERE, "--box", "0,1,0,1,0,1")
    check(r["box"] == [0, 1, 0, 1, 0, 1] and r["options"]["box"] == [0, 1, 0, 1, 0, 1], f"3-D box: {r['box']}")
    check(r["condition_number"] > 1, f"cond(S) of a 3-D solve: {r['condition_number']}")  # as in 2-D
    r = run("solve", SPHERE, "--box", "0,0,0,1,1,1", "--out", "", ok=False)
    check(r.returncode == 1 and "domain.box: the box is [x0, x1, y0, y1, z0, z1] (bounds order" in r.stderr,
          f"a 3-D box in the other order: {r.stderr.strip()}")
    r = run("solve", SPHERE, "--box", "0,1,0,1", "--out", "", ok=False)
    check(r.returncode == 1 and "domain.box: expected an array of 6 numbers in 3-D" in r.stderr, r.stderr.strip())
    r = solve("no_condition3d", SPHERE, "--condition_number", "false")
    check(r["condition_number"] is None, f"--condition_number false in 3-D: {r['condition_number']}")
    flat = os.path.join(SCRATCH, "flux_balance_2d.toml")
    with open(os.path.join(SOURCE, "examples", "circle.toml")) as f, open(flat, "w") as g:
        g.write(f.read().replace("[formulation]", "[formulation]\nflux_balance = false"))
    r = run("solve", flat, "--out", "", ok=False)
    check(r.returncode == 1 and "formulation.flux_balance: applies to 3-D problems only (this one is 2-D)" in r.stderr,
          f"a 3-D option in a 2-D file: {r.stderr.strip()}")
    r = run("solve", SPHERE, "--resolution", "32", "--out", "", ok=False)
    check(r.returncode == 1 and "geometry.shape = \"mesh\"" in r.stderr, f"--resolution on a sphere: {r.stderr.strip()}")


def mesh_flags():
    mesh = os.path.join(SOURCE, "examples", "manufactured_torus_mesh.toml")
    r = solve("mesh_flags", mesh, "--N", "48", "--offset", "0", "--resolution", "24", "--file",
              os.path.relpath(os.path.join(SOURCE, "examples", "meshes", "torus.off")))
    check(r["boundary"]["mesh"]["resolution"] == 24, f"--resolution: {r['boundary']['mesh']}")
    check(os.path.isabs(r["problem"]["geometry"]["file"]), "the mesh file is echoed as an absolute path")
    plain = os.path.join(SOURCE, "examples", "circle.toml")
    for flag, value in (("--resolution", "24"), ("--file", "x.off")):
        r = run("solve", plain, flag, value, "--out", os.path.join(SCRATCH, "no_mesh"), ok=False)
        check(r.returncode == 1 and r.stderr.startswith(f"fictus: error: {flag}:"),
              f"{flag} on a 2-D problem names itself: {r.stderr.strip()}")
    r = run("sweep", SPHERE, "--rotate", "0,1", "--axis", "w", ok=False)
    check(r.returncode == 1 and "--axis: expected x, y or z" in r.stderr and "g_scale" not in r.stdout
          and "rotate" not in r.stdout, f"a bad --axis is refused before any work: {r.stdout}{r.stderr}")
    r = run("solve", plain, "--dim", "3", ok=False)
    check(r.returncode == 1 and "--dim: not a flag" in r.stderr, f"--dim: {r.stderr.strip()}")


def main():
    os.makedirs(SCRATCH, exist_ok=True)
    sweeps_equal_single_solves()
    results_alone_redo_the_run()
    boxes_and_dimensions()
    mesh_flags()
    print("one pipeline: 3-D sweeps equal single solves, results.json redoes the run, boxes, dimensions, mesh flags")


if __name__ == "__main__":
    main()
