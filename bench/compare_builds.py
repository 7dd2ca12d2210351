#!/usr/bin/env python3
"""Times two builds of `fictus` on the same problems in one run, alternating, and prints the median
of each phase (Markdown). Used to check that a change does not slow a solve down:

    bench/compare_builds.py BEFORE_EXE AFTER_EXE [--N 4096] [--repeats 5] [--threads 2]
                            [--problem FILE] [--variants nonsmooth,smooth]

Without --problem it solves the paper's problem; with it, the problem file (2-D or 3-D) at --N
(bench/sphere_contact.toml: a 3-D problem whose data cost little, so that the solver's steps are timed).
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile

parser = argparse.ArgumentParser()
parser.add_argument("before")
parser.add_argument("after")
parser.add_argument("--N", type=int, default=4096)
parser.add_argument("--repeats", type=int, default=5)
parser.add_argument("--threads", type=int, default=2)
parser.add_argument("--problem", help="a problem file (default: the paper's problem)")
parser.add_argument("--variants", default="nonsmooth,smooth")
args = parser.parse_args()

PHASES = ["nested_start", "coarse_solve", "load", "u0", "fit_contact", "geometry", "kink_correction", "flux_balance", "green_table", "schur", "newton",
          "final_solve", "check", "errors", "quantities", "total"]


def run(exe, variant, out):
    problem = [args.problem] if args.problem else []
    # Without cond(S), which both dimensions compute now; a build from before took it in 2-D only.
    command = [exe, "solve", *problem, "--N", str(args.N), "--variant", variant, "--threads", str(args.threads),
               "--files", "results.json", "--out", out]
    r = subprocess.run([*command, "--no-condition"], capture_output=True, text=True)
    if r.returncode != 0 and "applies to 2-D problems only" in r.stderr:
        r = subprocess.run(command, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"{exe}: {r.stderr.strip()}")
    with open(os.path.join(out, "results.json")) as f:
        r = json.load(f)
    # the answer, to show both builds solved the same problem: the L2 error, else the contact force
    return r["timings"], r["errors"]["rel_l2_omega"] if "errors" in r else r["contact"]["force"]


print(f"| variant | build | " + " | ".join(PHASES) + " | rel. L2(ω) or contact force |")
print("|---|---|" + "---|" * (len(PHASES) + 1))
with tempfile.TemporaryDirectory() as tmp:
    for variant in args.variants.split(","):
        times = {"before": [], "after": []}
        errors = {}
        for _ in range(args.repeats):
            for name in ["before", "after"]:  # alternating: both see the same machine state
                t, e = run(getattr(args, name), variant, os.path.join(tmp, name))
                times[name].append(t)
                errors[name] = e
        medians = {name: {p: statistics.median(t.get(p, 0.0) for t in times[name]) for p in PHASES}
                   for name in times}
        for name in ["before", "after"]:
            print(f"| {variant} | {name} | " + " | ".join(f"{medians[name][p]:.3f}" for p in PHASES)
                  + f" | {errors[name]:.6e} |")
        ratio = medians["after"]["total"] / medians["before"]["total"]
        print(f"| {variant} | after/before | " + " | ".join(
            f"{medians['after'][p] / medians['before'][p]:.3f}" if medians['before'][p] > 0 else "–" for p in PHASES)
              + " | |")
