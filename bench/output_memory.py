#!/usr/bin/env python3
"""What writing the output files costs: `fictus solve` of the paper's problem (smooth variant) once
with results.json only and once with every file (solution.vti streamed block by block), the wall time
and the peak resident memory of each process (wait4's ru_maxrss), in one run.

usage: output_memory.py FICTUS [--before OLD_FICTUS] [--N 16384] [--threads 2] [--out bench/results]
                        [--repeats 1]
With --before, an older build's program runs the same two solves in the same run (its rows first).
Writes <out>/<date>-output-memory.md with the machine, compiler, threads and commit.
"""
import argparse
import datetime
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time


def run(command):
    start = time.perf_counter()
    child = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(child.pid, 0)
    seconds = time.perf_counter() - start
    error = child.stderr.read().decode()
    child.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"output_memory: {' '.join(command)} failed: {error.strip()}")
    return seconds, usage.ru_maxrss * 1024  # KiB on Linux


def machine():
    model = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as handle:
            for line in handle:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    with open("/proc/meminfo") as handle:
        memory = int(handle.readline().split()[1]) / 2**20
    return f"{model}, {os.cpu_count()} cores, {memory:.0f} GiB"


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("fictus")
    parser.add_argument("--before", help="an older build's fictus, measured in the same run")
    parser.add_argument("--N", type=int, default=16384)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--out", default="bench/results")
    args = parser.parse_args()
    scratch = tempfile.mkdtemp(prefix="fictus-output-memory-")
    programs = ([("before", args.before)] if args.before else []) + [("this build", args.fictus)]
    rows = []
    try:
        for name, program in programs:
            base = [program, "solve", "--N", str(args.N), "--variant", "smooth", "--threads", str(args.threads),
                    "--quiet", "--out", scratch]
            for label, extra in (("results.json only", ["--files", "results.json"]), ("every file", [])):
                for f in os.listdir(scratch):
                    os.remove(os.path.join(scratch, f))
                runs = [run(base + extra) for _ in range(args.repeats)]
                seconds = sorted(r[0] for r in runs)[len(runs) // 2]
                peak = max(r[1] for r in runs)
                sizes = sum(os.path.getsize(os.path.join(scratch, f)) for f in os.listdir(scratch))
                rows.append((name, label, seconds, peak, sizes))
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    compiler = subprocess.run(["c++", "--version"], capture_output=True, text=True).stdout.splitlines()[0]
    lines = [f"# Output files: time and peak memory (bench/output_memory.py)", "",
             f"- machine: {machine()}; {platform.system()} {platform.release()}",
             f"- compiler: {compiler}; threads: {args.threads}; commit: {commit}; "
             f"{datetime.date.today().isoformat()}",
             f"- `fictus solve --N {args.N} --variant smooth --threads {args.threads}` (the paper's problem), "
             f"median of {args.repeats} run(s); peak = the process's maximum resident set", "",
             "| program | files | time [s] | peak memory [GiB] | written [MiB] |", "|---|---|---|---|---|"]
    for name, label, seconds, peak, size in rows:
        lines.append(f"| {name} | {label} | {seconds:.1f} | {peak / 2**30:.2f} | {size / 2**20:.0f} |")
    lines.append("")
    for k in range(0, len(rows), 2):
        lines.append(f"{rows[k][0]}: the files add {(rows[k + 1][3] - rows[k][3]) / 2**30:.2f} GiB to the peak "
                     f"and {rows[k + 1][2] - rows[k][2]:.1f} s.")
    text = "\n".join(lines) + "\n"
    print(text)
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, f"{datetime.date.today().isoformat()}-output-memory.md")
    with open(path, "w") as handle:
        handle.write(text)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
