"""Walks every option of `fictus options --json` through the four ways in: a problem file, a
command-line flag (its name is the key), results.json's `options` and the Python keyword, and checks
that the same value arrives each way. A new option without a walk value below fails the test.

Usage: option_walk.py FICTUS_EXE OUT_DIR   (PYTHONPATH must hold the fictus module)
"""
import json
import math
import os
import subprocess
import sys

import fictus

exe, out = sys.argv[1], sys.argv[2]

BASE = {
    "domain": {"N": 64},
    "geometry": {"shape": "circle", "center": [0.5, 0.5], "radius": 0.25},
    "data": {"f": "1", "g": "0"},
    "formulation": {"variant": "nonsmooth"},
    "solver": {},
}
# A valid value other than the default for every option, chosen so that N = 64 solves quickly.
WALK = {
    "box": [-0.5, 1.5, -0.5, 1.5],
    "N": 72,
    "boundary": "periodic",
    "variant": "smooth",
    "multipliers": 24,
    "offset": 2.0,
    "rho": 0.5,
    "normal_derivative": "shifted",
    "normal_shift": 0.75,
    "c": 2.5,
    "schur": "krylov",
    "krylov_tolerance": 1e-11,
    "krylov_max_iterations": 3000,
    "newton_tolerance": 1e-8,
    "max_newton": 40,
    "start": "zero",
    "threads": 2,
    "max_memory": 16.0,
    "load_quadrature": 3,
    "error_quadrature": 4,
    "far_field": False,
    "flux_balance": False,
    "nested_start": 96,
    "condition_number": False,
}


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    return repr(v)


def flag_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, list):
        return ",".join(repr(x) for x in v)
    return str(v)


def problem_toml(config):
    return "".join(f"[{section}]\n" + "".join(f"{k} = {toml_value(v)}\n" for k, v in keys.items())
                   for section, keys in config.items())


def same(a, b):
    if isinstance(a, list):
        return isinstance(b, list) and len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, float) or isinstance(b, float):
        return math.isclose(float(a), float(b), rel_tol=1e-15)
    return a == b


def solve_cli(name, config, flags=()):
    folder = os.path.join(out, name)
    path = os.path.join(out, name + ".toml")
    with open(path, "w") as f:
        f.write(problem_toml(config))
    run = subprocess.run([exe, "solve", path, "--out", folder, "--files", "results.json", *flags],
                         capture_output=True, text=True)
    if run.returncode != 0:
        raise SystemExit(f"{name}: fictus failed: {run.stderr.strip()}")
    with open(os.path.join(folder, "results.json")) as f:
        options = json.load(f)["options"]
    assert set(options) == set(keys), f"results.json options {sorted(options)} are not the schema's {sorted(keys)}"
    return options


os.makedirs(out, exist_ok=True)
schema = json.loads(subprocess.run([exe, "options", "--json"], capture_output=True, text=True, check=True).stdout)
keys = [o["key"] for o in schema]
missing = sorted(set(keys) - set(WALK))
assert not missing, f"options without a walk value: {missing}"
failures = []
for option in schema:
    key, section, value = option["key"], option["section"], WALK[option["key"]]
    unchanged = BASE.get(section, {}).get(key, option["default"])
    assert not same(value, unchanged), f"{key}: the walk value is what arrives without it"
    config = json.loads(json.dumps(BASE))
    config.setdefault(section, {})[key] = value
    arrived = {
        "file": solve_cli(f"file_{key}", config)[key],
        "flag": solve_cli(f"flag_{key}", BASE, ["--" + key, flag_value(value)])[key],
    }
    python = {s: {k: v for k, v in keys.items() if k != key} for s, keys in BASE.items()}
    solution = fictus.Problem(**python, **{key: value}).solve(field=False)  # the flat keyword
    assert set(solution.options) == set(keys), f"Python's options {sorted(solution.options)} are not the schema's"
    arrived["python"] = solution.options[key]
    for way, got in arrived.items():
        if not same(got, value):
            failures.append(f"{key} by {way}: gave {value!r}, arrived {got!r}")
    print(f"{section}.{key:24s} {value!r:28} file/flag/python: "
          + ", ".join(repr(arrived[w]) for w in ("file", "flag", "python")))
if failures:
    print("\n".join(failures))
    sys.exit(1)
print(f"all {len(schema)} options arrive unchanged by file, flag, results.json and Python")
