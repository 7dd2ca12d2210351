"""Walks every option of `fictus options --json` through the four ways in: a problem file, a
command-line flag (its name is the key), results.json's `options` and the Python keyword, in every
dimension it applies to, and checks that the same value arrives each way, and that results.json and
Python list exactly the options of the dimension. A new option without a walk value below fails the test.

Usage: option_walk.py FICTUS_EXE OUT_DIR   (PYTHONPATH must hold the fictus module)
"""
import json
import math
import os
import subprocess
import sys

import fictus

from toml_text import toml_value

exe, out = sys.argv[1], sys.argv[2]

BASES = {
    2: {
        "domain": {"N": 64},
        "geometry": {"shape": "circle", "center": [0.5, 0.5], "radius": 0.25},
        "data": {"f": "1", "g": "0"},
        "formulation": {"variant": "nonsmooth"},
        "solver": {},
    },
    3: {
        "domain": {"dim": 3, "N": 24},
        "geometry": {"shape": "sphere", "center": [0.5, 0.5, 0.5], "radius": 0.25},
        "data": {"f": "1", "g": "0"},
        "formulation": {"variant": "nonsmooth"},
        "solver": {},
    },
}
# A valid value other than the default for every option and dimension, chosen so that the small
# grids above solve quickly. `dim` is walked by the bases themselves (it says which reader a file needs).
WALK = {
    "box": {2: [-0.5, 1.5, -0.5, 1.5], 3: [-0.25, 1.25, -0.25, 1.25, -0.25, 1.25]},
    "N": {2: 72, 3: 28},
    "boundary": "periodic",
    "variant": "smooth",
    "multipliers": {2: 24, 3: 40},
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
    "schur_storage": "dense",
    "flux_balance": False,
    "nested_start": 28,
    "error_estimate": False,
    "fit_contact": 1,
    "condition_number": False,
}


def walk_value(key, dim):
    value = WALK[key]
    return value[dim] if isinstance(value, dict) else value


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


def solve_cli(name, config, flags, keys):
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
missing = sorted(set(o["key"] for o in schema) - set(WALK) - {"dim"})
assert not missing, f"options without a walk value: {missing}"
failures = []
walked = 0
for dim, base in BASES.items():
    keys = [o["key"] for o in schema if dim in o["dims"]]
    for option in schema:
        key, section = option["key"], option["section"]
        if dim not in option["dims"] or key == "dim":
            continue
        value = walk_value(key, dim)
        default = option.get("default_3d", option["default"]) if dim == 3 else option["default"]
        unchanged = base.get(section, {}).get(key, default)
        assert not same(value, unchanged), f"{key} ({dim}-D): the walk value is what arrives without it"
        config = json.loads(json.dumps(base))
        config.setdefault(section, {})[key] = value
        arrived = {
            "file": solve_cli(f"file_{dim}d_{key}", config, (), keys)[key],
            "flag": solve_cli(f"flag_{dim}d_{key}", base, ["--" + key, flag_value(value)], keys)[key],
        }
        python = {s: {k: v for k, v in ks.items() if k != key} for s, ks in base.items()}
        solution = fictus.Problem(**python, **{key: value}).solve(field=False)  # the flat keyword
        assert solution.dim == dim and set(solution.options) == set(keys), \
            f"Python's options {sorted(solution.options)} are not the schema's for {dim}-D"
        assert solution.options["dim"] == dim
        arrived["python"] = solution.options[key]
        for way, got in arrived.items():
            if not same(got, value):
                failures.append(f"{key} ({dim}-D) by {way}: gave {value!r}, arrived {got!r}")
        walked += 1
        print(f"{dim}-D {section}.{key:24s} {value!r:36} file/flag/python: "
              + ", ".join(repr(arrived[w]) for w in ("file", "flag", "python")))
if failures:
    print("\n".join(failures))
    sys.exit(1)
print(f"all {len(schema)} options ({walked} option-dimension pairs) arrive unchanged by file, flag, results.json "
      "and Python")
