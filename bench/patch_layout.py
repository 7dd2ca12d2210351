"""How a 3-D reference problem's quantities move with the layout of the patches on γ (issue 33).

The problem, the grid and N stay; only the patches change: m = round(f·m₀), m₀ the default rule's
(|γ|/(c·h)², c = 5 smooth, 4 non-smooth, |γ| the reference's area_gamma, so m₀ may differ by one
from the solver's own), for the factors f of LAYOUTS (default 0.91 … 1.06 in steps of
0.03, which keeps s within 5 % of the default's). Each m gives another partition of γ by Lloyd's
iteration, so the patch borders fall elsewhere against the contact boundary. (Shifting the box by a
fraction of a cell moves the grid but not the patches: ∫û then moves 3–24 times less;
MOVE=box runs six such shifts of the box [0, 1]³ (h = 1/N; the references' box), uniform in
[−h/2, h/2] per axis, seed 20261207, instead of the layouts.)
Per N: the mean, the standard deviation and the largest of the relative errors over the layouts,
against the fitted-mesh reference of tests/references/NAME.json (contact area: the exact cap where
the reference gives one, else contact_fraction × area_gamma).

  /usr/bin/python3 bench/patch_layout.py NAME VARIANT N,N,... [fictus solve options...]
  /usr/bin/python3 bench/patch_layout.py FILE.toml VARIANT N,N,... [options...]   (no fitted reference)
  e.g. /usr/bin/python3 bench/patch_layout.py spheroid3d smooth 128,160,192,256
       /usr/bin/python3 bench/patch_layout.py spheroid3d smooth 128,160,192 --fit_contact 2
  LAYOUTS="1.0" … for the default layout alone; FICTUS=path/to/fictus for another binary (two code paths
  compared in one session).

Runs `build/apps/fictus solve tests/references/NAME.toml --N N --variant VARIANT --multipliers m
--error_estimate false --threads 2 --out FOLDER --files results.json --quiet` (plus the options
given), FOLDER a temporary one; prints one line per run and a table.

A problem FILE.toml without a fitted reference (e.g. bench/neumann_ellipsoid.toml) gives the same
table with m₀ the solver's own default m: ∫û's relative error where the file gives `exact`
(from errors.integral_u), else each quantity relative to its mean over the layouts (so the columns
measure the spread alone; a quantity whose mean is below its spread, such as the force where nothing is
in contact, stays absolute).
"""
import json, os, subprocess, sys, tempfile
import numpy as np

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
name, variant, sizes, extra = sys.argv[1], sys.argv[2], [int(v) for v in sys.argv[3].split(",")], sys.argv[4:]
factors = [float(v) for v in os.environ.get("LAYOUTS", "0.91,0.94,0.97,1.0,1.03,1.06").split(",")]
move_box = os.environ.get("MOVE", "layout") == "box"
shifts = np.random.default_rng(20261207).uniform(-0.5, 0.5, size=(6, 3))
cases = shifts if move_box else factors
problem = name if name.endswith(".toml") else os.path.join(root, "tests", "references", name + ".toml")
ref = None if name.endswith(".toml") else json.load(open(os.path.join(root, "tests", "references", name + ".json")))["values"]
area = None if ref is None else ref["contact_area"] if "contact_area" in ref else ref["contact_fraction"] * ref["area_gamma"]
relative_u = False  # a FILE.toml with `exact`: ∫û's column is its error


def solve(folder, N, options):
    subprocess.run([os.environ.get("FICTUS", os.path.join(root, "build", "apps", "fictus")), "solve", problem, "--N", str(N), "--variant", variant,
                    "--error_estimate", "false", "--threads", "2", "--out", folder, "--files", "results.json", "--quiet"] +
                   options + extra, check=True, stderr=subprocess.DEVNULL)
    return json.load(open(os.path.join(folder, "results.json")))

quantities = ("contact area", "∫û", "∫|∇û|²", "force")
rows = {}
with tempfile.TemporaryDirectory() as folder:
    for N in sizes:
        if ref is None:
            m0 = solve(folder, N, [])["multipliers"]
        else:
            m0 = ref["area_gamma"] * (N / (5 if variant == "smooth" else 4)) ** 2
        for case in cases:
            if move_box:  # the default m; the box [0, 1]³ moved by a fraction of a cell
                m = round(m0)
                place = ["--box", ",".join(f"{v:.15g}" for d in range(3) for v in (case[d] / N, 1 + case[d] / N))]
            else:
                m, place = round(case * m0), []
            r = solve(folder, N, ["--multipliers", str(m)] + place)
            if ref is None:  # the values themselves, made relative to their means below
                error = (r.get("errors") or {}).get("integral_u")  # ∫û − ∫u where `exact` is given
                relative_u = error is not None
                iu = r["domain"]["integral_u"]
                row = (r["contact"]["measure"], error / (iu - error) if relative_u else iu, r["domain"]["integral_grad2"],
                       r["contact"]["force"])
            else:
                row = (r["contact"]["measure"] / area - 1, r["domain"]["integral_u"] / ref["int_u"] - 1,
                       r["domain"]["integral_grad2"] / ref["int_grad2"] - 1, r["contact"]["force"] / ref["force"] - 1)
            rows.setdefault(N, []).append(row)
            print(f"N = {N}, m = {m}: " + ", ".join(f"{q} {v:+.3e}" for q, v in zip(quantities, row)), flush=True)
what = "relative errors" if ref is not None else (
    "∫û's relative error, the rest relative to their means (absolute where the mean is below the spread)"
    if relative_u else "relative to the means (absolute where the mean is below the spread)")
print(f"\n{name}, {variant} {' '.join(extra)}: {what} over {len(cases)} "
      f"{'box positions' if move_box else 'layouts'} (mean / sd / largest)\n")
print("| N | " + " | ".join(quantities) + " |")
print("|---|" + "---|" * len(quantities))
for N, values in rows.items():
    a = np.array(values)
    for j in range(4 if ref is None else 0):  # no reference: deviations from the mean over the layouts
        mean, spread = a[:, j].mean(), a[:, j].std(ddof=1) if len(a) > 1 else 0.0
        if not (j == 1 and relative_u) and abs(mean) > spread:  # (e.g. the force where nothing is in contact)
            a[:, j] = a[:, j] / mean - 1
    cells = [f"{a[:, j].mean():+.2e} / {a[:, j].std(ddof=1):.1e} / {a[abs(a[:, j]).argmax(), j]:+.2e}" for j in range(4)]
    print(f"| {N} | " + " | ".join(cells) + " |")
