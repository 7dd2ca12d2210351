"""fictus under mpirun: on one rank a solve runs as without mpirun; on more ranks the run stops with the
error line once and a non-zero exit, and no rank is left waiting (a time limit); started by a launcher
that is not its MPI's, it refuses.

usage: check_mpi_cli.py FICTUS OUT_DIR MPIEXEC [MPIEXEC_FLAG ...] NUMPROC_FLAG
"""
import json
import os
import shutil
import subprocess
import sys

fictus, out = sys.argv[1], sys.argv[2]
launcher, numproc = sys.argv[3:-1], sys.argv[-1]
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def run(ranks, *args):
    command = launcher + [numproc, str(ranks), fictus, *args]
    return subprocess.run(command, env=env, capture_output=True, text=True, timeout=120)


shutil.rmtree(out, ignore_errors=True)
two = run(2, "solve", "--N", "64", "--out", os.path.join(out, "two"))
errors = [line for line in (two.stdout + two.stderr).splitlines() if line.startswith("fictus: error:")]
assert two.returncode != 0, "two ranks: exit code 0"
assert len(errors) == 1, f"two ranks: {len(errors)} error lines, want 1:\n{two.stdout}{two.stderr}"
assert "MPI ranks" in errors[0], errors[0]
assert not os.path.exists(os.path.join(out, "two")), "two ranks: wrote output"

one = run(1, "solve", "--N", "64", "--quiet", "--files", "results.json", "--out", os.path.join(out, "one"))
assert one.returncode == 0, f"one rank: exit {one.returncode}:\n{one.stdout}{one.stderr}"
with open(os.path.join(out, "one", "results.json")) as f:
    results = json.load(f)
serial = subprocess.run([fictus, "solve", "--N", "64", "--quiet", "--files", "results.json", "--out",
                         os.path.join(out, "serial")], capture_output=True, text=True, timeout=120)
assert serial.returncode == 0, serial.stderr
with open(os.path.join(out, "serial", "results.json")) as f:
    expected = json.load(f)
for key in ("force", "measure", "lambda_integral"):
    x, y = results["contact"][key], expected["contact"][key]
    assert abs(x - y) <= 1e-12 * abs(y), f"one rank: contact.{key} {x} against {y} without mpirun"
assert results["contact"]["points"] == expected["contact"]["points"], "one rank: another contact set"
# A launcher that is not this build's MPI (here: Slurm's task count without its PMI): each process would
# run alone, so each refuses.
alone = subprocess.run([fictus, "solve", "--N", "64", "--out", os.path.join(out, "alone")],
                       env=dict(env, SLURM_STEP_NUM_TASKS="3"), capture_output=True, text=True, timeout=120)
assert alone.returncode != 0 and "MPI sees this process alone" in alone.stderr, alone.stderr
assert not os.path.exists(os.path.join(out, "alone")), "alone: wrote output"
print("mpirun: one rank solves as without it; two ranks stop with one error line")
