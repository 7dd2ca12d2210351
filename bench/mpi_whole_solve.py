"""Whole solves under mpirun against the serial solve, on this machine: time, each rank's peak memory
and the agreement of λ and the force, from results.json and points.csv of `fictus solve`.

  python3 bench/mpi_whole_solve.py [build] [case ...] [--against OTHER_BUILD] > bench/results/<date>-mpi-whole-solve.md

(cases by their N: 4096, 128, 192, 256, 384; 384c and 512c for the compressed Schur complement, 192m for
it with many points, 256n for the non-smooth variant; 4096, 128 and 192 when none is given. With
--against, every run on ranks of the 384c, 512c, 192m and 256n cases is made with both builds, one after
the other.)

Cases: 2-D h = 1/4096 (the manufactured circle) and the 3-D sphere of bench/sphere_contact.toml at
N = 128, 192, 256 and 384 (where a grid array is 429 MiB); serially with 2 threads (with the Schur complement
auto chooses, and dense), on 2 ranks × 1 thread, and on 4 ranks × 1 thread (oversubscribed on 2 cores: its
times are not the machine's, its memory per rank is). The compressed cases (384c, 512c): the compressed
Schur complement serially, on 2 and 4 ranks, and the dense one on 2 ranks.
"""
import csv
import json
import os
import platform
import subprocess
import sys
import tempfile

args = sys.argv[1:]
other = None
if "--against" in args:
    at = args.index("--against")
    other = args[at + 1]
    del args[at:at + 2]
build = args[0] if args else "build"
fictus = os.path.join(build, "apps", "fictus")
here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
work = tempfile.mkdtemp(prefix="fictus-mpi-bench-")

CASES = [
    ("2-D circle, h = 1/4096", os.path.join(root, "examples", "manufactured_circle.toml"), ["--N", "4096"]),
    ("3-D sphere, N = 128", os.path.join(here, "sphere_contact.toml"), ["--N", "128"]),
    ("3-D sphere, N = 192", os.path.join(here, "sphere_contact.toml"), ["--N", "192"]),
    ("3-D sphere, N = 256", os.path.join(here, "sphere_contact.toml"), ["--N", "256"]),
    ("3-D sphere, N = 384", os.path.join(here, "sphere_contact.toml"), ["--N", "384"]),
]
RUNS = [  # (name, ranks, threads, extra flags)
    ("serial", 0, 2, []),
    ("serial, dense S", 0, 2, ["--schur_storage", "dense"]),
    ("2 ranks", 2, 1, []),
    ("4 ranks (oversubscribed)", 4, 1, []),
]
# The compressed Schur complement (chosen from m = 5000 on; asked for here wherever m is smaller) on the ranks,
# against the serial compressed solve and the dense blocks on the same ranks.
COMPRESSED = ["--schur_storage", "hierarchical"]
COMPRESSED_RUNS = [
    ("serial, compressed S", 0, 2, COMPRESSED),
    ("2 ranks, compressed S", 2, 1, COMPRESSED),
    ("2 ranks, dense S", 2, 1, ["--schur_storage", "dense"]),
    ("4 ranks, compressed S (oversubscribed)", 4, 1, COMPRESSED),
]
for N in ("384", "512"):
    CASES.append((f"3-D sphere, N = {N}, compressed", os.path.join(here, "sphere_contact.toml"), ["--N", N], "c"))
# Many points on a small grid (s = 2.2h): the preconditioner's groups and the blocks at m = 6000.
CASES.append(("3-D sphere, N = 192, m = 6000, compressed", os.path.join(here, "sphere_contact.toml"),
              ["--N", "192", "--multipliers", "6000"], "m"))
MANY_POINTS_RUNS = [COMPRESSED_RUNS[0], COMPRESSED_RUNS[1], ("3 ranks, compressed S (oversubscribed)", 3, 1, COMPRESSED)]
# The non-smooth variant (kink rows, flux balance, ∫_ω f): its boundary setup is the largest.
CASES.append(("3-D sphere, N = 256, non-smooth", os.path.join(here, "sphere_contact.toml"),
              ["--N", "256", "--variant", "nonsmooth"], "n"))
NONSMOOTH_RUNS = [RUNS[0], RUNS[2], RUNS[3]]
chosen = args[1:] or ["4096", "128", "192"]
CASES = [c for c in CASES if c[2][1] + (c[3] if len(c) > 3 else "") in chosen]


def run(problem, flags, ranks, threads, folder, program=fictus):
    command = [program, "solve", problem, *flags, "--threads", str(threads), "--quiet", "--files",
               "results.json,points.csv", "--out", folder]
    if ranks:
        command = ["mpiexec", "--oversubscribe", "--bind-to", "none", "-n", str(ranks)] + command
    subprocess.run(command, env=env, check=True, capture_output=True, timeout=3600)
    with open(os.path.join(folder, "results.json")) as f:
        results = json.load(f)
    with open(os.path.join(folder, "points.csv")) as f:
        lam = [float(r["lambda"]) for r in csv.DictReader(f)]
    return results, lam


def commit():
    try:
        return subprocess.run(["git", "-C", root, "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


mpi = subprocess.run(["mpiexec", "--version"], capture_output=True, text=True).stdout.splitlines()[0]
print("# Whole solves on several MPI ranks against the serial solve\n")
print(f"- Machine: {platform.node()}, {os.cpu_count()} CPUs; {mpi}; commit {commit()}; Release build.")
print("- Each run: `fictus solve FILE --N N --threads T`, under `mpiexec --oversubscribe --bind-to none -n P` for P")
print("  ranks. Time: results.json's total; memory: each rank's peak (VmHWM), the largest and the sum.")
print("- λ and the force against the first serial run: max |Δλ| / max |λ|, and |ΔF| / |F|.\n")
if other:
    print(f"- Runs marked {other} are that build's, the others {build}'s.")
print("| case | run | m | Schur | Newton steps | time [s] | geometry, schur, newton [s] | peak of a rank [MiB] "
      "| peaks summed [MiB] | Δλ | ΔF |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for n_case, (case, problem, flags, *kind) in enumerate(CASES):
    reference = None
    runs = {(): RUNS, ("c",): COMPRESSED_RUNS, ("m",): MANY_POINTS_RUNS, ("n",): NONSMOOTH_RUNS}[tuple(kind)]
    if other and kind:
        runs = [(r[0] + (f", {other}" if b else ""), *r[1:], b) for r in runs for b in ([0, 1] if r[1] else [0])]
    for n_run, (name, ranks, threads, extra, *by_other) in enumerate(runs):
        folder = os.path.join(work, f"{n_case}-{n_run}")
        program = os.path.join(other, "apps", "fictus") if by_other and by_other[0] else fictus
        results, lam = run(problem, flags + extra, ranks, threads, folder, program)
        peaks = results.get("ranks", {}).get("peak_memory_bytes", [results["peak_memory_bytes"]])
        force = results["contact"]["force"]
        if reference is None:
            reference = (lam, force)
        dl = max(abs(a - b) for a, b in zip(lam, reference[0])) / max(abs(a) for a in reference[0])
        df = abs(force - reference[1]) / abs(reference[1])
        storage = ((results.get("inner") or {}).get("schur_storage") or {}).get("kind", "")
        print(f"| {case} | {name}, {max(ranks, 1)} × {threads} | {results['multipliers']} | {storage} "
              f"| {results['newton']['iterations']} | {results['timings']['total']:.2f} "
              f"| {results['timings'].get('geometry', 0):.1f}, {results['timings']['schur']:.1f}, "
              f"{results['timings']['newton']:.1f} "
              f"| {max(peaks) / 2**20:.0f} | {sum(peaks) / 2**20:.0f} | {dl:.1e} | {df:.1e} |", flush=True)
