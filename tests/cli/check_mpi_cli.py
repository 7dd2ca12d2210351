"""fictus under mpirun: on one rank a solve runs as without mpirun; on two and three ranks it solves
distributed, rank 0 printing and writing for all; bad input on every rank or on one rank's layers stops
the run with the error line once and a non-zero exit, a rank failing alone stops all, and no rank is
left waiting (a time limit); started by a launcher that is not its MPI's, it refuses.

usage: check_mpi_cli.py FICTUS OUT_DIR MPIEXEC [MPIEXEC_FLAG ...] NUMPROC_FLAG
"""
import importlib.util
import json
import os
import shutil
import subprocess
import sys

from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLPImageDataReader

fictus, out = sys.argv[1], sys.argv[2]
launcher, numproc = sys.argv[3:-1], sys.argv[-1]
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def run(ranks, *args):
    command = launcher + [numproc, str(ranks), fictus, *args]
    return subprocess.run(command, env=env, capture_output=True, text=True, timeout=120)


shutil.rmtree(out, ignore_errors=True)


def error_lines(result):
    return [line for line in (result.stdout + result.stderr).splitlines() if line.startswith("fictus: error:")]


def serial_results(name, *args):
    done = subprocess.run([fictus, "solve", *args, "--quiet", "--files", "results.json", "--out",
                           os.path.join(out, name)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    with open(os.path.join(out, name, "results.json")) as f:
        return json.load(f)


# Two and three ranks solve together: rank 0 prints one summary and writes the files, the field as
# solution.pvti with a piece per rank; the answers are the serial ones (the ctest mpi.solve_* compares
# every quantity).
expected = serial_results("serial", "--N", "64")
subprocess.run([fictus, "solve", "--N", "64", "--quiet", "--out", os.path.join(out, "serial_field")], check=True,
               capture_output=True, timeout=120)
plot_script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "apps", "plot.py")
loader = importlib.util.spec_from_file_location("plot", plot_script)
plot = importlib.util.module_from_spec(loader)
loader.loader.exec_module(plot)
serial_field = plot.read_field(os.path.join(out, "serial_field"))[-1]["u"]
for ranks in (2, 3):
    folder = os.path.join(out, f"ranks{ranks}")
    together = run(ranks, "solve", "--N", "64", "--out", folder)
    assert together.returncode == 0, f"{ranks} ranks: exit {together.returncode}:\n{together.stdout}{together.stderr}"
    assert together.stdout.count("Newton:") == 1, f"{ranks} ranks: not one summary:\n{together.stdout}"
    with open(os.path.join(folder, "results.json")) as f:
        results = json.load(f)
    assert results["ranks"]["count"] == ranks and len(results["ranks"]["peak_memory_bytes"]) == ranks, results["ranks"]
    for key in ("force", "measure", "lambda_integral"):
        x, y = results["contact"][key], expected["contact"][key]
        assert abs(x - y) <= 1e-11 * abs(y), f"{ranks} ranks: contact.{key} {x} against {y} serially"
    assert results["contact"]["points"] == expected["contact"]["points"], f"{ranks} ranks: another contact set"
    assert not os.path.exists(os.path.join(folder, "solution.vti")), f"{ranks} ranks: solution.vti beside the pieces"
    pieces = [name for name in os.listdir(folder) if name.startswith("solution_") and name.endswith(".vti")]
    assert len(pieces) == ranks, f"{ranks} ranks: pieces {pieces}"
    field = plot.read_field(folder)[-1]["u"]
    assert field.shape == serial_field.shape, (field.shape, serial_field.shape)
    difference = abs(field - serial_field).max() / abs(serial_field).max()
    assert difference < 1e-11, f"{ranks} ranks: the pieces' field differs from the serial one by {difference}"
    # ParaView's reader of parallel images takes the pieces as one field.
    reader = vtkXMLPImageDataReader()
    reader.SetFileName(os.path.join(folder, "solution.pvti"))
    reader.Update()
    read = vtk_to_numpy(reader.GetOutput().GetPointData().GetArray("u")).reshape(serial_field.shape)
    assert abs(read - field).max() == 0, f"{ranks} ranks: VTK reads another field from solution.pvti"

# Twelve ranks on 63 layers (blocks of 6): the last rank holds no layer, and every collective step must
# still meet it there (the readings, the integrals over ω, the pieces of the field).
many = run(12, "solve", "--N", "64", "--quiet", "--files", "results.json,solution.vti", "--out", os.path.join(out, "many"))
assert many.returncode == 0, f"12 ranks: exit {many.returncode}:\n{many.stdout}{many.stderr}"
with open(os.path.join(out, "many", "results.json")) as f:
    results = json.load(f)
assert results["ranks"]["count"] == 12
for key in ("force", "measure", "lambda_integral"):
    x, y = results["contact"][key], expected["contact"][key]
    assert abs(x - y) <= 1e-11 * abs(y), f"12 ranks: contact.{key} {x} against {y} serially"
field = plot.read_field(os.path.join(out, "many"))[-1]["u"]
assert abs(field - serial_field).max() <= 1e-11 * abs(serial_field).max(), "12 ranks: another field"

# The compressed Schur complement on 2 and 12 ranks (3-D; asked for below the m where auto chooses it;
# on 12 ranks some hold few of its blocks): used, without a warning, and the serial answer.
sphere = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples", "manufactured_sphere.toml")
compressed_args = [sphere, "--N", "40", "--schur_storage", "hierarchical", "--error_estimate", "false"]
expected_compressed = serial_results("serial_compressed", *compressed_args)
for ranks in (2, 12):
    folder = os.path.join(out, f"compressed{ranks}")
    compressed = run(ranks, "solve", *compressed_args, "--quiet", "--files", "results.json", "--out", folder)
    assert compressed.returncode == 0, f"compressed, {ranks} ranks: exit {compressed.returncode}:\n{compressed.stderr}"
    with open(os.path.join(folder, "results.json")) as f:
        results = json.load(f)
    storage, serial_storage = results["inner"]["schur_storage"], expected_compressed["inner"]["schur_storage"]
    assert storage["kind"] == "hierarchical", storage
    assert storage["low_rank_blocks"] + storage["full_blocks"] == \
        serial_storage["low_rank_blocks"] + serial_storage["full_blocks"], (storage, serial_storage)
    assert not any("schur_storage" in w for w in results["warnings"]), results["warnings"]
    for key in ("force", "measure", "lambda_integral"):
        x, y = results["contact"][key], expected_compressed["contact"][key]
        assert abs(x - y) <= 1e-11 * abs(y), f"compressed on {ranks} ranks: contact.{key} {x} against {y} serially"
    assert results["contact"]["points"] == expected_compressed["contact"]["points"], f"compressed, {ranks}: contact set"

# Bad input found by every rank, and bad data found by one rank only (f is NaN in the top layers, which
# the last rank holds): one error line (rank 0's), a non-zero exit, no files, no rank left waiting.
for name, args, expect in (("bad_flag", ["--N", "7"], "domain.N"),
                           ("nan_in_a_slab", ["--N", "64", "--parameter", "top=0.95"], "data.f")):
    problem = os.path.join(out, "nan.toml")
    with open(problem, "w") as f:
        f.write('[parameters]\ntop = 2.0\n[geometry]\nshape = "circle"\ncenter = [0.5, 0.5]\nradius = 0.3\n'
                '[data]\nf = "y > top ? sqrt(-1) : 1"\ng = "-1"\n')
    failed = run(2, "solve", problem, *args, "--out", os.path.join(out, name))
    errors = error_lines(failed)
    assert failed.returncode != 0, f"{name}: exit code 0"
    assert len(errors) == 1 and expect in errors[0], f"{name}: want one error line on {expect}:\n{failed.stderr}"
    assert not os.path.exists(os.path.join(out, name)), f"{name}: wrote output"

# A rank that fails alone (the test's hook: the others are already in the solve's collectives) stops
# every rank within seconds, with a non-zero exit.
alone_rank = subprocess.run(launcher + [numproc, "2", fictus, "solve", "--N", "64", "--out", os.path.join(out, "alone_rank")],
                            env=dict(env, FICTUS_TEST_FAIL_ON_RANK="1"), capture_output=True, text=True, timeout=120)
assert alone_rank.returncode != 0, "a rank failing alone: exit code 0"
assert "failed alone" in alone_rank.stderr, alone_rank.stderr
assert not os.path.exists(os.path.join(out, "alone_rank")), "a rank failing alone: wrote output"


def alone_and_on_two_ranks(name, args, result):
    """The command without mpirun and on 2 ranks: the json file `result` each one wrote, and its stdout."""
    got = {}
    for ranks in (0, 2):
        folder = os.path.join(out, f"{name}{ranks}")
        command = [fictus, *args, "--out", folder]
        done = run(ranks, *command[1:]) if ranks else subprocess.run(command, capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, f"{name} on {ranks} ranks: exit {done.returncode}:\n{done.stdout}{done.stderr}"
        with open(os.path.join(folder, result)) as f:
            got[ranks] = (json.load(f), done.stdout)
    return got


# A sweep runs distributed as well: every member on the ranks' slabs, rank 0 writing sweep.csv.
sweeps = {ranks: value[0]["rows"] for ranks, value in
          alone_and_on_two_ranks("sweep", ["sweep", "--g-scale", "0.5,1,2", "--N", "64"], "sweep.json").items()}
assert len(sweeps[0]) == len(sweeps[2]) == 3
for serial_row, row in zip(sweeps[0], sweeps[2]):
    assert row["contact_points"] == serial_row["contact_points"], "sweep on 2 ranks: another contact set"
    for key in ("contact_force", "contact_measure", "lambda_integral"):
        x, y = row[key], serial_row[key]
        assert abs(x - y) <= 1e-11 * abs(y), f"sweep on 2 ranks: {key} {x} against {y} serially"

# reproduce runs its levels distributed (rank 0 writing the tables); plot runs on one rank.
tables = {}
for ranks, (table, stdout) in alone_and_on_two_ranks(
        "reproduce", ["reproduce", "--levels", "6-7", "--table", "1"], "table1.json").items():
    assert stdout.count("Table 1") == 1, f"reproduce on {ranks} ranks: not one table:\n{stdout}"
    tables[ranks] = table["levels"]
for serial_level, level in zip(tables[0], tables[2]):
    for key in ("l2_omega", "h1_omega", "l2_gamma"):
        x, y = level["errors"][key], serial_level["errors"][key]
        assert abs(x - y) <= 1e-11 * abs(y), f"reproduce on 2 ranks: errors.{key} {x} against {y} serially"
plot_refused = run(2, "plot", os.path.join(out, "reproduce0"))
assert plot_refused.returncode != 0 and len(error_lines(plot_refused)) == 1, plot_refused.stderr
assert "fictus plot runs on one rank" in error_lines(plot_refused)[0], error_lines(plot_refused)[0]

one = run(1, "solve", "--N", "64", "--quiet", "--files", "results.json", "--out", os.path.join(out, "one"))
assert one.returncode == 0, f"one rank: exit {one.returncode}:\n{one.stdout}{one.stderr}"
with open(os.path.join(out, "one", "results.json")) as f:
    results = json.load(f)
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
print("mpirun: one rank solves as without it; two and three ranks solve together as one; errors on any rank stop "
      "every rank with one error line")
