#!/usr/bin/env python3
"""Mutation fuzzer for `fictus solve` (problem files and flag sets), and the replay of its corpus.

  fuzz.py run EXE [--minutes 10] [--seed 1] [--workers 1] [--grow tests/fuzz/corpus]
                  [--findings DIR] [--report FILE]
      Mutates problem files (the examples, tests/bad_inputs, the corpus) and flag sets (from
      `fictus options --json`), runs each case, classifies the outcome and prints the counts per
      class. With --grow, a case whose outcome signature (class, exit code, key, first words of the
      message) is new and acceptable is added to the corpus with that outcome as its expectation.
      Defects (crash, internal, sanitizer, bad_message, nonfinite, changed_output) are written to
      --findings for a person to read.

  fuzz.py replay EXE CASE.json ...
      Runs corpus cases and checks each against its expected outcome (exit code and the key named
      by the error, or success with finite results). Exit 1 on the first mismatch.

  fuzz.py record EXE NAME [--problem FILE] [--corpus DIR] -- ARGS...
      Runs one case and writes it to the corpus with the outcome seen (read it before committing).

Outcome classes. Acceptable: ok (exit 0, results.json and points.csv finite and within 1e100,
Newton converged, foreign files in the folder kept), error (exit 1, 2 or 3, exactly one
`fictus: error: <key>: …` line of at most 240 characters on stderr, the output folder as it was),
timeout (still running after the time limit: the tool is slow, not wrong). A sweep whose Newton fails
for some members (exit 2) writes its complete sweep.csv and sweep.json all the same, those rows marked. Defects: crash (killed
by a signal), bad_exit (an undocumented exit code), internal (exit 4), sanitizer (an ASan/UBSan report), bad_message,
nonfinite (exit 0 with a non-finite or out-of-range number, or Newton not converged),
changed_output (a failing run changed the folder or left a temporary behind).
"""
import argparse
import copy
import hashlib
import json
import math
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import tomllib
from concurrent.futures import ThreadPoolExecutor

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
ACCEPTABLE = ("ok", "error", "timeout")
DEFECTS = ("crash", "bad_exit", "internal", "sanitizer", "bad_message", "nonfinite", "changed_output")
MAX_LINE = 240
OLD_RESULTS = "old results\n"
FOREIGN = "a file fictus did not write\n"
SANITIZER_MARKS = ("runtime error:", "AddressSanitizer", "LeakSanitizer", "UndefinedBehaviorSanitizer")


# ----------------------------------------------------------------------------------------------
# Running one case and classifying what happened
# ----------------------------------------------------------------------------------------------
def finite_numbers(value, where, problems):
    """Collects the places in a JSON value that are null, non-finite or beyond 1e100."""
    if isinstance(value, dict):
        for key, item in value.items():
            finite_numbers(item, f"{where}.{key}", problems)
    elif isinstance(value, list):
        for index, item in enumerate(value):
            finite_numbers(item, f"{where}[{index}]", problems)
    elif value is None:
        problems.append(f"{where} is null")
    elif isinstance(value, float) and (not math.isfinite(value) or abs(value) > 1e100):
        problems.append(f"{where} = {value}")


def check_sweep(folder):
    """Problems with the files of a successful sweep: sweep.csv and sweep.json finite and complete."""
    path = os.path.join(folder, "sweep.csv")
    if not os.path.exists(path):
        return ["sweep.csv was not written"]
    problems = []
    with open(path) as handle:
        rows = list(handle)
    for row in rows[1:]:
        for cell in row.strip().split(","):
            number = float(cell)
            if not math.isfinite(number) or abs(number) > 1e100:
                problems.append(f"sweep.csv: {cell}")
    with open(os.path.join(folder, "sweep.json")) as handle:
        document = json.load(handle)
    if len(document["rows"]) != len(rows) - 1:
        problems.append("sweep.json and sweep.csv differ in rows")
    document.pop("problem", None)
    finite_numbers(document, "sweep", problems)
    return problems


def check_success(folder):
    """Problems with the files of a successful run ([] when they are finite and complete)."""
    problems = []
    path = os.path.join(folder, "results.json")
    if not os.path.exists(path):
        return []  # --files may leave results.json out
    with open(path) as handle:
        text = handle.read()
    if text == OLD_RESULTS:
        return ["results.json was not written"]
    results = json.loads(text)
    # Optional figures are null by design when not computed (no exact solution, krylov's cond(S)); the
    # optional blocks are null where they do not apply (the flux balance in 2-D and the smooth variant,
    # the far field, the Schur storage (krylov), the nested start, the independent check, a failure of a
    # converged Newton, the contact fit).
    for key in ("errors", "condition_number", "problem"):
        results.pop(key, None)
    for block, key in ((None, "flux_balance"), ("inner", "far_field"), ("inner", "schur_storage"),
                       ("newton", "nested_start"),
                       ("newton", "failure"), ("signorini", "check"), ("contact", "fit")):
        table = results if block is None else results.get(block, {})
        if isinstance(table, dict) and key in table and table[key] is None:
            table.pop(key)
    finite_numbers(results, "results", problems)
    if not results.get("newton", {}).get("converged", False):
        problems.append("newton.converged is not true")
    points = os.path.join(folder, "points.csv")
    if os.path.exists(points):
        with open(points) as handle:
            for row in list(handle)[1:]:
                for cell in row.strip().split(","):
                    if cell == "":  # dudn_check where the solve made no independent check
                        continue
                    number = float(cell)
                    if not math.isfinite(number) or abs(number) > 1e100:
                        problems.append(f"points.csv: {cell}")
                        break
    return problems


def prepare_folder(parent):
    """An output folder holding an earlier set: a failing run must leave it as it is."""
    folder = os.path.join(parent, "out")
    os.makedirs(folder)
    with open(os.path.join(folder, "results.json"), "w") as handle:
        handle.write(OLD_RESULTS)
    with open(os.path.join(folder, "keep.txt"), "w") as handle:
        handle.write(FOREIGN)
    return folder


def folder_state(folder):
    state = {}
    for name in sorted(os.listdir(folder)):
        with open(os.path.join(folder, name), "rb") as handle:
            state[name] = hashlib.md5(handle.read()).hexdigest()
    return state


def run_case(exe, case, timeout):
    """Runs a case ({"problem": TOML text or null, "args": [...]}) and returns its outcome."""
    with tempfile.TemporaryDirectory(prefix="fictus-fuzz-") as parent:
        folder = prepare_folder(parent)
        before = folder_state(folder)
        command = [exe] + list(case["args"][:1])
        if command[1] in ("solve", "sweep", "reproduce"):
            command += ["--out", folder]
        if case.get("problem") is not None:
            problem = os.path.join(parent, "problem.toml")
            with open(problem, "w", encoding="utf-8", errors="surrogateescape") as handle:
                handle.write(case["problem"])
            command.append(problem)
        command += case["args"][1:]
        env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:exitcode=86",
                   UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:exitcode=87")
        started = time.monotonic()
        try:
            process = subprocess.run(command, capture_output=True, timeout=timeout, env=env, cwd=parent,
                                     start_new_session=True)
        except subprocess.TimeoutExpired as expired:
            return {"class": "timeout", "exit": None, "key": None, "message": "", "seconds": timeout}
        seconds = time.monotonic() - started
        stderr = process.stderr.decode("utf-8", "replace").replace(parent + "/", "")
        rc = process.returncode
        outcome = {"exit": rc, "key": None, "message": "", "seconds": round(seconds, 3)}
        leftovers = [name for name in os.listdir(parent) if name.startswith(".out.tmp")]
        if any(mark in stderr for mark in SANITIZER_MARKS) or rc in (86, 87):
            return dict(outcome, **{"class": "sanitizer", "message": stderr[-2000:]})
        if rc < 0:
            return dict(outcome, **{"class": "crash", "message": stderr[-2000:]})
        if rc not in (0, 1, 2, 3, 4):
            return dict(outcome, **{"class": "bad_exit", "message": stderr[-2000:]})
        if rc == 4:
            return dict(outcome, **{"class": "internal", "message": stderr[-2000:]})
        if rc == 0:
            if command[1] == "sweep":
                problems = check_sweep(folder)
                return dict(outcome, **({"class": "nonfinite", "message": "; ".join(problems)[:2000]} if problems
                                        else {"class": "ok"}))
            if command[1] != "solve":
                return dict(outcome, **{"class": "ok"})
            problems = check_success(folder)
            if not os.path.exists(os.path.join(folder, "keep.txt")):
                problems.append("keep.txt (not written by fictus) was removed")
            if leftovers:
                problems.append(f"temporaries left: {leftovers}")
            if problems:
                return dict(outcome, **{"class": "nonfinite", "message": "; ".join(problems)[:2000]})
            return dict(outcome, **{"class": "ok"})
        lines = stderr.splitlines()
        errors = [line for line in lines if line.startswith("fictus: error")]
        if any(not line.startswith("fictus: ") for line in lines):  # only warnings and progress beside it
            errors.append("a line not from fictus")
        match = re.match(r"fictus: error: (\S+?): \S", errors[0]) if len(errors) == 1 else None
        try:
            process.stderr.decode("utf-8")
        except UnicodeDecodeError:
            match = None  # a message cut inside a UTF-8 sequence
        if not match or len(errors[0].encode()) > MAX_LINE:
            return dict(outcome, **{"class": "bad_message", "message": stderr[-2000:]})
        outcome.update(key=match.group(1), message=errors[0])
        after = folder_state(folder)
        if command[1] == "sweep" and rc == 2:  # a sweep writes its rows, those not converged marked
            problems = check_sweep(folder)
            if problems:
                return dict(outcome, **{"class": "nonfinite", "message": "; ".join(problems)[:2000]})
            after = {name: digest for name, digest in after.items() if name not in ("sweep.csv", "sweep.json")}
        if after != before or leftovers:
            return dict(outcome, **{"class": "changed_output"})
        return dict(outcome, **{"class": "error"})


def signature(outcome):
    """What makes an outcome new: class, exit code, key and the first words of the message."""
    words = re.sub(r"[-+0-9.e]+|\"[^\"]*\"|'[^']*'", "#", outcome["message"].split(": ", 2)[-1]).split()
    return (outcome["class"], outcome["exit"], outcome["key"], " ".join(words[:4]))


def expectation(outcome):
    expected = {"class": outcome["class"], "exit": outcome["exit"]}
    if outcome["class"] == "error":
        expected["key"] = outcome["key"]
    return expected


def matches(expected, outcome):
    if outcome["class"] != expected["class"] or outcome["exit"] != expected["exit"]:
        return False
    return expected["class"] != "error" or outcome["key"] == expected["key"]


# ----------------------------------------------------------------------------------------------
# Writing TOML (tomllib only reads)
# ----------------------------------------------------------------------------------------------
def toml_value(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(item) for item in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{key} = {toml_value(item)}" for key, item in value.items()) + "}"
    raise TypeError(type(value))


def to_toml(document):
    lines = []
    for section, table in document.items():
        if not isinstance(table, dict):
            lines.append(f"{section} = {toml_value(table)}")
            continue
        lines.append(f"[{section}]")
        lines += [f"{key} = {toml_value(value)}" for key, value in table.items()]
    return "\n".join(lines) + "\n"


# ----------------------------------------------------------------------------------------------
# Mutations
# ----------------------------------------------------------------------------------------------
NUMBERS = [0, 1, -1, 2, 3, 7, 8, 9, 63, 64, 65, 127, 128, 255, 256, 257, 1000, 4096, 100000, 10**9,
           2**31 - 1, 2**31, 2**63 - 1, -(2**63), 0.0, -0.0, 0.5, 1.5, -0.5, 1e-300, 5e-324, 1e-12, 1e12,
           1e100, 1e300, -1e300, 1.7976931348623157e308, float("nan"), float("inf"), float("-inf")]
EXPRESSIONS = ["1", "0", "x", "y", "t", "phi", "s", "1/0", "0/0", "sqrt(-1)", "log(0)", "1e308*10", "x^1000",
               "1e305", "1e300*x", "exp(1000*x)", "(x", "x)", "", " ", "x y", "sin", "sin()", "max(x)",
               "_pi", "x > 0.5 ? 1 : -1", "a = x, a * 2", "b * 2, b = 1", "rand()", "x = 1", "y^x^y^x",
               "0.3 + 0.05 * cos(5 * t)", "0.5 + 0.3 * cos(t)", "0.5 + 0.3 * sin(t)", "0.25 - 0.5*(t>3)",
               "abs(t - 3.14) < 1e-9 ? 0/0 : 0.3", "∞", "x\u0000", "'", "\"", "#", "x" * 1000,
               "(" * 300 + "x" + ")" * 300, "1+" * 5000 + "1"]
WORDS = ["", "smooth", "nonsmooth", "green", "krylov", "dirichlet", "periodic", "all", "zero", "shifted",
         "reconstructed", "circle", "ellipse", "star", "polygon", "parametric", "bogus", "NaN", "true",
         "results.json", "solution.vti", "x" * 300]
KEYS = {"domain": ["box", "N", "boundary"],
        "geometry": ["shape", "center", "radius", "semi_axes", "angle", "vertices", "x", "y", "r"],
        "formulation": ["variant", "multipliers", "offset", "rho", "normal_derivative", "normal_shift"],
        "data": ["c", "f", "g", "exact"],
        "conditions": ["dirichlet", "u", "neumann", "flux"],
        "solver": ["schur", "krylov_tolerance", "krylov_max_iterations", "newton_tolerance", "max_newton",
                   "start", "threads", "max_memory", "load_quadrature", "error_quadrature",
                   "condition_number"],
        "output": ["files"]}
SHAPES = [
    {"shape": "circle", "center": [0.5, 0.5], "radius": 0.3},
    {"shape": "ellipse", "center": [0.5, 0.5], "semi_axes": [0.35, 0.2], "angle": 0.4},
    {"shape": "star", "center": [0.5, 0.5], "r": "0.3 + 0.05 * cos(5 * t)"},
    {"shape": "parametric", "x": "0.5 + 0.3 * cos(t)", "y": "0.5 + 0.2 * sin(t)"},
    {"shape": "polygon", "vertices": [[0.2, 0.2], [0.8, 0.25], [0.7, 0.8], [0.3, 0.7]]},
]


def random_number(rng, like=None):
    choice = rng.random()
    if like is not None and isinstance(like, (int, float)) and not isinstance(like, bool) and choice < 0.3:
        factor = rng.choice([-1, 0.5, 2, 10, 0.1, 1 + 1e-12, 1 - 1e-12, 1e6, 1e-6])
        value = like * factor
        return int(value) if isinstance(like, int) and abs(value) < 2**63 else value
    return rng.choice(NUMBERS)


def random_value(rng, like=None):
    kind = rng.random()
    if isinstance(like, str) and kind < 0.6:
        if rng.random() < 0.4:
            return rng.choice(WORDS)
        base = rng.choice(EXPRESSIONS)
        return base if rng.random() < 0.5 else f"{like} {rng.choice(['+', '*', '/', '-', '^'])} {base}"
    if isinstance(like, list) and kind < 0.6:
        items = copy.deepcopy(like)
        action = rng.randrange(6)
        if action == 0 and items:
            items.pop(rng.randrange(len(items)))
        elif action == 1:
            items.append(copy.deepcopy(rng.choice(items)) if items else random_number(rng))
        elif action == 2 and items:
            index = rng.randrange(len(items))
            items[index] = random_value(rng, items[index])
        elif action == 3:
            items = []
        elif action == 4 and items:
            items = items + items  # traversed twice
        else:
            items = [items]
        return items
    if isinstance(like, (int, float)) and not isinstance(like, bool) and kind < 0.7:
        return random_number(rng, like)
    pick = rng.randrange(5)
    return [random_number(rng), rng.choice(EXPRESSIONS), [random_number(rng), random_number(rng)],
            rng.random() < 0.5, {"a": 1}][pick]


def mutate_document(rng, document):
    document = copy.deepcopy(document)
    for _ in range(rng.choice([1, 1, 1, 2, 2, 3])):
        action = rng.randrange(10)
        sections = [name for name, table in document.items() if isinstance(table, dict)]
        if action <= 3 and sections:  # change a value
            section = rng.choice(sections)
            if document[section]:
                key = rng.choice(list(document[section]))
                document[section][key] = random_value(rng, document[section][key])
        elif action == 4 and sections:  # remove a key or a section
            section = rng.choice(sections)
            if document[section] and rng.random() < 0.8:
                del document[section][rng.choice(list(document[section]))]
            else:
                del document[section]
        elif action == 5:  # set a known key, perhaps in the wrong section
            section = rng.choice(list(KEYS))
            key = rng.choice(KEYS[section] if rng.random() < 0.8 else KEYS[rng.choice(list(KEYS))])
            current = document.get(section, {}).get(key) if isinstance(document.get(section), dict) else None
            document.setdefault(section, {})
            if isinstance(document[section], dict):
                document[section][key] = random_value(rng, current)
        elif action == 6:  # another shape, with a value changed
            geometry = copy.deepcopy(rng.choice(SHAPES))
            key = rng.choice(list(geometry))
            if key != "shape" and rng.random() < 0.7:
                geometry[key] = random_value(rng, geometry[key])
            document["geometry"] = geometry
        elif action == 7:  # an unknown key or section
            target = rng.choice(sections + ["mesh"]) if sections else "mesh"
            document.setdefault(target, {})
            if isinstance(document[target], dict):
                document[target][rng.choice(["tolerance", "n", "radius2", "é"])] = 1
        elif action == 8 and "geometry" in document:  # polygon vertices: many, collinear or repeated
            count = rng.choice([1, 2, 3, 50, 5000])
            angle = [2 * math.pi * i / count for i in range(count)]
            radius = [0.3 * (1 + 0.3 * rng.choice([0, 1]) * math.cos(7 * a)) for a in angle]
            vertices = [[0.5 + r * math.cos(a), 0.5 + r * math.sin(a)] for r, a in zip(radius, angle)]
            if rng.random() < 0.5 and count > 3:
                vertices.insert(rng.randrange(count), copy.deepcopy(rng.choice(vertices)))
            document["geometry"] = {"shape": "polygon", "vertices": vertices}
        elif action == 9 and rng.random() < 0.3:  # mixed conditions: parts of γ and their values
            document.setdefault("conditions", {})
            if isinstance(document["conditions"], dict):
                key = rng.choice(KEYS["conditions"])
                parts = ["x < 0.4", "y > 0.6", "x > 0.5 && y < 0.5", "z < 0.4", "nx > 0", "1", "0"]
                document["conditions"][key] = rng.choice(parts + EXPRESSIONS if key in ("dirichlet", "neumann")
                                                         else ["0", "1", "x + y", "nx", "nz"] + EXPRESSIONS)
        else:  # a data expression
            document.setdefault("data", {"f": "1", "g": "0"})
            if isinstance(document["data"], dict):
                document["data"][rng.choice(["f", "g", "exact", "c"])] = rng.choice(EXPRESSIONS)
    return document


def mutate_text(rng, text):
    """Byte-level damage: the reader must refuse it, not crash."""
    if not text:
        return text
    action = rng.randrange(5)
    at = rng.randrange(len(text))
    if action == 0:
        return text[:at] + text[at + 1:]
    if action == 1:
        return text[:at] + rng.choice('[]="#\n.,-e{}\\\u00e9\u0000x') + text[at:]
    if action == 2:
        lines = text.splitlines(True)
        line = rng.randrange(len(lines))
        return "".join(lines[:line + 1] + lines[line:])  # a repeated key or section
    if action == 3:
        return text[:at]
    return text[:at] + text[at:at + 200] * 50 + text[at:]


def random_flags(rng, options):
    flags = []
    for _ in range(rng.choice([0, 0, 1, 1, 2, 3])):
        option = rng.choice(options)
        choice = rng.random()
        if "choices" in option and choice < 0.5:
            value = rng.choice(option["choices"])
        elif option["type"] in ("integer", "number") and choice < 0.85:
            value = random_number(rng, option["default"])
        elif option["type"] == "numbers" and choice < 0.85:
            value = random_value(rng, option["default"])
        else:
            value = rng.choice(WORDS + ["1e999", "-", "--N", "0x10", "1,2", " 3"])
        if isinstance(value, list) and rng.random() < 0.7:  # the documented form: --box 0,1,0,1
            flags += [f"--{option['key']}", ",".join(str(item) for item in value)]
        elif isinstance(value, list):
            flags.append(f"--{option['key']}")
            flags += [str(item) for item in value] or [""]
        else:
            flags += [f"--{option['key']}", str(value).lower() if isinstance(value, bool) else str(value)]
    flags = [flag.replace("\0", "") for flag in flags]  # an argument vector cannot hold NUL
    if rng.random() < 0.05:
        flags.append(rng.choice(["--bogus", "--N", "--files", "--out", "extra.toml"]))
    return flags


def load_seeds():
    seeds = []
    for folder in ("examples", "tests/bad_inputs", "tests/references"):
        for name in sorted(os.listdir(os.path.join(ROOT, folder))):
            if name.endswith(".toml"):
                with open(os.path.join(ROOT, folder, name), "rb") as handle:
                    try:
                        seeds.append(tomllib.load(handle))
                    except tomllib.TOMLDecodeError:
                        pass
    return seeds


def make_case(rng, seeds, options):
    if rng.random() < 0.12:  # the paper's problem, flags only
        return {"problem": None, "args": ["solve", "--N", str(rng.choice([64, 128]))] + random_flags(rng, options)}
    document = copy.deepcopy(rng.choice(seeds))
    document.pop("output", None)
    if rng.random() < 0.85 and isinstance(document.get("domain"), dict):
        document["domain"]["N"] = rng.choice([96, 128, 128, 192])  # mostly small: many cases a minute
    if rng.random() < 0.85:
        document = mutate_document(rng, document)
    text = to_toml(document)
    if rng.random() < 0.12:
        text = mutate_text(rng, text)
    if rng.random() < 0.1:  # a sweep: a family of the problem, by one of its kinds
        return {"problem": text, "args": ["sweep"] + sweep_family(rng, document) + random_flags(rng, options)}
    return {"problem": text, "args": ["solve"] + random_flags(rng, options)}


def sweep_family(rng, document):
    """--g-scale, --rotate, --move or --parameter with a list of 1–4 values, extreme ones too."""
    values = [random_number(rng, rng.choice([1.0, 0.1, 3.0])) for _ in range(rng.choice([1, 2, 3, 4]))]
    text = ",".join(str(v) for v in values) if rng.random() < 0.8 else rng.choice(["0:1:3", "1:1:0", "a,b", "", "1:2:3:4"])
    names = list(document.get("parameters", {}) or {}) if isinstance(document.get("parameters"), dict) else []
    kind = rng.choice(["--g-scale", "--rotate", "--move"] + (["--parameter"] * 3 if names else []))
    if kind == "--parameter":
        return [kind, f"{rng.choice(names + ['nothere'])}={text}"]
    return [kind, text]


# ----------------------------------------------------------------------------------------------
# Subcommands
# ----------------------------------------------------------------------------------------------
def case_name(case):
    return hashlib.sha1(json.dumps(case, sort_keys=True).encode("utf-8", "surrogateescape")).hexdigest()[:12]


def fuzz(args):
    rng = random.Random(args.seed)
    options = json.loads(subprocess.run([args.exe, "options", "--json"], capture_output=True,
                                        check=True).stdout)
    options = [option for option in options if option["key"] != "threads"] + [
        {"key": "threads", "type": "integer", "default": 1}]
    seeds = load_seeds()
    seen = set()
    if args.grow:
        os.makedirs(args.grow, exist_ok=True)
        for name in sorted(os.listdir(args.grow)):
            with open(os.path.join(args.grow, name)) as handle:
                stored = json.load(handle)
            seen.add(tuple(stored.get("signature", [])))
            if stored.get("problem"):
                try:
                    seeds.append(tomllib.loads(stored["problem"]))
                except tomllib.TOMLDecodeError:
                    pass
    counts = {name: 0 for name in ACCEPTABLE + DEFECTS}
    deadline = time.monotonic() + 60 * args.minutes
    added = 0

    def one(case):
        return case, run_case(args.exe, case, args.timeout)

    with ThreadPoolExecutor(args.workers) as pool:
        pending = []
        while time.monotonic() < deadline or pending:
            while time.monotonic() < deadline and len(pending) < args.workers:
                pending.append(pool.submit(one, make_case(rng, seeds, options)))
            case, outcome = pending.pop(0).result()
            counts[outcome["class"]] += 1
            key = signature(outcome)
            if (outcome["class"] in DEFECTS or outcome["class"] == "timeout") and args.findings:
                os.makedirs(args.findings, exist_ok=True)
                with open(os.path.join(args.findings, case_name(case) + ".json"), "w") as handle:
                    json.dump(dict(case, outcome=outcome), handle, indent=1, ensure_ascii=False)
            elif outcome["class"] in ("ok", "error") and args.grow and key not in seen and len(
                    json.dumps(case)) < 20000 and added < args.max_grow:
                seen.add(key)
                added += 1
                with open(os.path.join(args.grow, "fuzz-" + case_name(case) + ".json"), "w") as handle:
                    json.dump(dict(case, expect=expectation(outcome), signature=list(key)), handle, indent=1,
                              ensure_ascii=False)
    total = sum(counts.values())
    lines = [f"fuzz: {args.exe}, {args.minutes} min, seed {args.seed}, {args.workers} worker(s), "
             f"{total} cases, {added} added to the corpus",
             "| class | cases |", "|---|---|"] + [f"| {name} | {counts[name]} |" for name in counts]
    print("\n".join(lines))
    if args.report:
        with open(args.report, "w") as handle:
            handle.write("\n".join(lines) + "\n")
    return 1 if any(counts[name] for name in DEFECTS) else 0


def replay(args):
    for path in args.cases:
        with open(path) as handle:
            case = json.load(handle)
        outcome = run_case(args.exe, case, args.timeout)
        expected = case["expect"]
        if not matches(expected, outcome):
            print(f"{os.path.basename(path)}: expected {expected}, got {outcome}")
            return 1
        print(f"{os.path.basename(path)}: {outcome['class']} (exit {outcome['exit']}"
              f"{', ' + outcome['key'] if outcome['key'] else ''}) as expected, {outcome['seconds']} s")
    return 0


def record(args):
    problem = None
    if args.problem:
        with open(args.problem) as handle:
            problem = handle.read()
    case = {"problem": problem, "args": args.args}
    outcome = run_case(args.exe, case, args.timeout)
    if outcome["class"] not in ("ok", "error"):
        print(f"not recorded: {outcome}")
        return 1
    path = os.path.join(args.corpus, args.name + ".json")
    with open(path, "w") as handle:
        json.dump(dict(case, expect=expectation(outcome), signature=list(signature(outcome))), handle,
                  indent=1, ensure_ascii=False)
    print(f"{path}: {outcome['class']} exit {outcome['exit']} {outcome['message']}")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    commands = parser.add_subparsers(dest="command", required=True)
    run = commands.add_parser("run")
    run.add_argument("exe")
    run.add_argument("--minutes", type=float, default=10)
    run.add_argument("--seed", type=int, default=1)
    run.add_argument("--workers", type=int, default=1)
    run.add_argument("--timeout", type=float, default=30)
    run.add_argument("--grow")
    run.add_argument("--max-grow", type=int, default=40, help="cases added to the corpus at most")
    run.add_argument("--findings")
    run.add_argument("--report")
    again = commands.add_parser("replay")
    again.add_argument("exe")
    again.add_argument("cases", nargs="+")
    again.add_argument("--timeout", type=float, default=120)
    rec = commands.add_parser("record")
    rec.add_argument("exe")
    rec.add_argument("name")
    rec.add_argument("--problem")
    rec.add_argument("--corpus", default=os.path.join(HERE, "corpus"))
    rec.add_argument("--timeout", type=float, default=120)
    argv = sys.argv[1:]
    rest = argv[argv.index("--") + 1:] if "--" in argv else []
    args = parser.parse_args(argv[:len(argv) - len(rest) - (1 if "--" in argv else 0)])
    args.exe = os.path.abspath(args.exe)
    args.args = rest  # record: the fictus arguments after "--"
    return {"run": fuzz, "replay": replay, "record": record}[args.command](args)


if __name__ == "__main__":
    sys.exit(main())
