#!/usr/bin/env python3
"""Mutation fuzzer for the surface-mesh reader of `fictus solve` (geometry.shape = "mesh").

  fuzz_mesh.py EXE [--cases 200] [--seed 1] [--findings DIR]

Starts from small meshes in the four formats (OFF, OBJ, ASCII STL, ASCII PLY; a sphere and an
octahedron) and mutates them: numbers replaced by NaN, ±inf, 1e308, huge or negative indices, lines
dropped, repeated or swapped, the file cut short, bytes inserted. Each mutant is solved through a
3-D problem file with N = 16. Acceptable: exit 0 with finite results (every number in results.json
finite and within 1e100), exit 1 or 2 with exactly one `fictus: error: <key>: …` line, or a timeout
(slow, not wrong). Anything else (a signal, an ASan/UBSan report, another exit code, a
message over several lines) is a defect, written to --findings. Exit 1 when there is a defect.
"""
import argparse
import json
import math
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile

SANITIZER_MARKS = ("runtime error:", "AddressSanitizer", "LeakSanitizer", "UndefinedBehaviorSanitizer")
ERROR_LINE = re.compile(r"^fictus: error: [a-z_.]+: .{1,230}$")
PROBLEM = """[domain]
dim = 3
N = 16
[geometry]
shape = "mesh"
file = "{mesh}"
[formulation]
variant = "nonsmooth"
normal_derivative = "shifted"
multipliers = 12
[data]
f = "1"
g = "1 + 0.5*(x - 0.5)"
[output]
files = ["results.json"]
"""


def sphere(levels=1):
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
         (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
         (8, 6, 7), (9, 8, 1)]
    v = [tuple(c / math.sqrt(sum(x * x for x in p)) for c in p) for p in v]
    for _ in range(levels):
        middle, finer = {}, []

        def split(a, b):
            key = (min(a, b), max(a, b))
            if key not in middle:
                m = [v[a][k] + v[b][k] for k in range(3)]
                n = math.sqrt(sum(x * x for x in m))
                v.append(tuple(x / n for x in m))
                middle[key] = len(v) - 1
            return middle[key]

        for a, b, c in f:
            ab, bc, ca = split(a, b), split(b, c), split(c, a)
            finer += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = finer
    return [tuple(0.5 + 0.3 * x for x in p) for p in v], f


def octahedron():
    c, r = 0.5, 0.3
    v = [(c + r, c, c), (c - r, c, c), (c, c + r, c), (c, c - r, c), (c, c, c + r), (c, c, c - r)]
    f = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    return v, f


def as_text(fmt, v, f):
    if fmt == "off":
        return "OFF\n%d %d 0\n" % (len(v), len(f)) + "".join("%r %r %r\n" % p for p in v) + \
            "".join("3 %d %d %d\n" % t for t in f)
    if fmt == "obj":
        return "".join("v %r %r %r\n" % p for p in v) + "".join("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in f)
    if fmt == "stl":
        return "solid s\n" + "".join("facet normal 0 0 0\nouter loop\n" + "".join(
            "vertex %r %r %r\n" % v[k] for k in t) + "endloop\nendfacet\n" for t in f) + "endsolid s\n"
    return ("ply\nformat ascii 1.0\nelement vertex %d\nproperty double x\nproperty double y\nproperty double z\n"
            "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(v), len(f)) +
            "".join("%r %r %r\n" % p for p in v) + "".join("3 %d %d %d\n" % t for t in f))


NUMBERS = ["nan", "inf", "-inf", "1e308", "-1e308", "1e-320", "0", "-1", "2147483648", "99999999999999999999",
           "4294967295", "0.5", "-0", "1e400", "0x10", ""]


def mutate(text, rng):
    lines = text.split("\n")
    for _ in range(rng.randint(1, 3)):
        op = rng.randrange(7)
        if op == 0 or op == 1:  # a number replaced
            spots = [m for m in re.finditer(r"-?[0-9][0-9.e+-]*", text)]
            if spots:
                m = rng.choice(spots)
                text = text[:m.start()] + rng.choice(NUMBERS) + text[m.end():]
            lines = text.split("\n")
            continue
        if op == 2 and len(lines) > 1:
            del lines[rng.randrange(len(lines))]
        elif op == 3:
            k = rng.randrange(len(lines))
            lines.insert(k, lines[k])
        elif op == 4 and len(lines) > 2:
            a, b = rng.randrange(len(lines)), rng.randrange(len(lines))
            lines[a], lines[b] = lines[b], lines[a]
        elif op == 5:
            joined = "\n".join(lines)
            lines = joined[:rng.randrange(len(joined) + 1)].split("\n")
        else:
            joined = "\n".join(lines)
            k = rng.randrange(len(joined) + 1)
            junk = "".join(chr(rng.randrange(1, 256)) for _ in range(rng.randint(1, 8)))
            lines = (joined[:k] + junk + joined[k:]).split("\n")
        text = "\n".join(lines)
    return text


def finite(value):
    if isinstance(value, dict):
        return all(finite(v) for v in value.values())
    if isinstance(value, list):
        return all(finite(v) for v in value)
    return not isinstance(value, float) or (math.isfinite(value) and abs(value) <= 1e100)


def classify(rc, stderr, outdir):
    if any(mark in stderr for mark in SANITIZER_MARKS):
        return "sanitizer"
    if rc < 0:
        return "crash"
    lines = [line for line in stderr.splitlines() if not line.startswith("fictus: warning:")]
    if rc == 0:
        try:
            with open(os.path.join(outdir, "results.json")) as handle:
                return "ok" if finite(json.load(handle)) else "nonfinite"
        except (OSError, ValueError):
            return "nonfinite"
    if rc in (1, 2) and len(lines) == 1 and ERROR_LINE.match(lines[0]):
        return "error"
    return "bad_message" if rc in (1, 2) else "bad_exit"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("exe")
    parser.add_argument("--cases", type=int, default=200)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--findings", default=None)
    args = parser.parse_args()
    rng = random.Random(args.seed)
    seeds = [(fmt, as_text(fmt, *shape)) for fmt in ("off", "obj", "stl", "ply") for shape in (sphere(), octahedron())]
    counts, defects = {}, 0
    work = tempfile.mkdtemp(prefix="fictus_fuzz_mesh_")
    try:
        for case in range(args.cases):
            fmt, text = rng.choice(seeds)
            mutant = mutate(text, rng)
            mesh = os.path.join(work, "mesh.%s" % fmt)
            with open(mesh, "w", encoding="latin-1") as out:
                out.write(mutant)
            problem = os.path.join(work, "problem.toml")
            with open(problem, "w") as out:
                out.write(PROBLEM.format(mesh=os.path.basename(mesh)))
            outdir = os.path.join(work, "out")
            shutil.rmtree(outdir, ignore_errors=True)
            try:
                run = subprocess.run([args.exe, "solve", problem, "--threads", "1", "--quiet", "--out", outdir],
                                     capture_output=True, text=True, errors="replace", timeout=120)
                kind = classify(run.returncode, run.stderr, outdir)
            except subprocess.TimeoutExpired:
                kind, run = "timeout", None
            counts[kind] = counts.get(kind, 0) + 1
            if kind not in ("ok", "error", "timeout"):
                defects += 1
                print("case %d (%s): %s\n%s" % (case, fmt, kind, run.stderr[-2000:] if run else ""), file=sys.stderr)
                if args.findings:
                    os.makedirs(args.findings, exist_ok=True)
                    shutil.copy(mesh, os.path.join(args.findings, "case%d.%s" % (case, fmt)))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print(" ".join("%s %d" % kv for kv in sorted(counts.items())))
    return 1 if defects else 0


if __name__ == "__main__":
    sys.exit(main())
