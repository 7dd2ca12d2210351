"""The 3-D contact area against the fitted-mesh references, from results.json of `fictus solve`:

  python3 bench/contact_measure_3d.py BUILD [BEFORE_BUILD] > bench/results/<date>-contact-measure-3d.md

For each problem, variant and N: the contact measure (`contact.measure`) and the whole patches' measure
(`contact.measure_points`) as relative errors against the reference's contact area, and for the spheroid
(whose reference gives the contact boundary: the circle t = t* on γ, t the axial coordinate) how far the
located ends (`contact.boundary`) lie from that circle along γ, in spacings s. With a second build, its
contact measure too (the column "before").

References (tests/references): spheroid3d (axisymmetric, solved in the meridian half-plane: the contact
area to 3e-6 relative), ellipsoid3d (P2 on curved tetrahedra: its contact fraction converges at first
order, 0.5916, 0.5894, 0.5882 on its levels) and ellipsoid3d_mixed (Dirichlet and Neumann caps, the
Signorini belt; contact area to 3e-4).
"""
import json
import math
import os
import platform
import subprocess
import sys
import tempfile

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)
refs = os.path.join(root, "tests", "references")
builds = sys.argv[1:] or ["build"]
work = tempfile.mkdtemp(prefix="fictus-contact-bench-")

CASES = [  # (problem, variant, N list)
    ("spheroid3d", "smooth", [64, 96, 128, 160]),
    ("spheroid3d", "nonsmooth", [64, 96, 128, 160]),
    ("ellipsoid3d", "smooth", [64, 96, 128, 160]),
    ("ellipsoid3d", "nonsmooth", [64, 96, 128, 160]),
    ("ellipsoid3d_mixed", "smooth", [96, 128]),
    ("ellipsoid3d_mixed", "nonsmooth", [96, 128]),
]


def reference_area(name):
    values = json.load(open(os.path.join(refs, name + ".json")))["values"]
    if "contact_area" in values:
        return values["contact_area"]
    return values["contact_fraction"] * values["area_gamma"]


def solve(build, name, variant, n):
    out = os.path.join(work, f"{os.path.basename(os.path.dirname(os.path.dirname(build)))}-{name}-{variant}-{n}")
    subprocess.run([os.path.join(build, "apps", "fictus"), "solve", os.path.join(refs, name + ".toml"), "--N", str(n),
                    "--variant", variant, "--threads", "2", "--error_estimate", "false", "--quiet", "--out", out,
                    "--files", "results.json"], check=True, stderr=subprocess.DEVNULL)
    return json.load(open(os.path.join(out, "results.json")))


def spheroid_ends(results):
    """mean, rms and largest distance of the located ends from the contact circle, in spacings"""
    values = json.load(open(os.path.join(refs, "spheroid3d.json")))["values"]
    t_end, a, b = values["contact_end_t"], 0.19, 0.32
    center, axis = (0.49, 0.51, 0.5), (2 / 7, 3 / 7, 6 / 7)
    rho = a * math.sqrt(1 - t_end**2 / b**2)
    stretch = math.sqrt(1 + (a * a * t_end / (b * b * rho)) ** 2)  # arc length of the meridian per unit t
    spacing = results["boundary"]["spacing"]
    offsets = [(sum((p[k] - center[k]) * axis[k] for k in range(3)) - t_end) * stretch / spacing
               for p in results["contact"]["boundary"]]
    if not offsets:
        return "–"
    mean = sum(offsets) / len(offsets)
    rms = math.sqrt(sum(o * o for o in offsets) / len(offsets))
    return f"{mean:+.3f} / {rms:.3f} / {max(abs(o) for o in offsets):.3f}"


def commit(build):
    src = os.path.dirname(os.path.abspath(build))
    try:
        return subprocess.run(["git", "-C", src, "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (subprocess.CalledProcessError, FileNotFoundError):
        return "?"


print("# The 3-D contact area against fitted-mesh references\n")
print(f"- Machine: {platform.node()}, {os.cpu_count()} CPUs; 2 threads; `--error_estimate false`")
print(f"- Builds: {', '.join(f'{b} (commit {commit(b)})' for b in builds)}")
print("- Errors relative to the reference's contact area; ends: mean / rms / largest distance of the located"
      " ends from the reference's contact circle along γ, in spacings s (spheroid only)\n")
header = "| problem | variant | N | m | measure | whole patches |" + (" before |" if len(builds) > 1 else "")
header += " ends (spheroid) |"
print(header)
print("|" + "---|" * (header.count("|") - 1))
for name, variant, ns in CASES:
    area = reference_area(name)
    for n in ns:
        r = solve(builds[0], name, variant, n)
        c = r["contact"]
        row = (f"| {name} | {variant} | {n} | {r['multipliers']} | {100 * (c['measure'] / area - 1):+.2f} % |"
               f" {100 * (c['measure_points'] / area - 1):+.2f} % |")
        if len(builds) > 1:
            before = solve(builds[1], name, variant, n)["contact"]["measure"]
            row += f" {100 * (before / area - 1):+.2f} % |"
        row += f" {spheroid_ends(r) if name == 'spheroid3d' else '–'} |"
        print(row, flush=True)
