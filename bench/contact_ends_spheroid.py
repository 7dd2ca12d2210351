"""Where the end's law puts the contact ends on the tilted spheroid (tests/references/spheroid3d), with
the solver's readings and with exact ones. The reference's u is axisymmetric, so its 300 samples on γ
give the exact gap u − g and ∂u/∂n as functions of the axial coordinate t; at each located pair (an
active patch a, a free neighbour b) the law √θ/(1 − θ)^{3/2} = q·d/(1.5·r) is solved with
- the solver's q (∂u/∂n at a) and r (gap at b), or the exact ones at the same points;
- d along the pair (fictus's rule) or across the boundary, d·cos φ (φ: the angle between the pair and
  the meridian; cos φ at least ½).
Printed: mean and rms distance of the ends from the contact circle along γ in spacings s (> 0: inside
the contact set), and the median ratio of the solver's readings to the exact ones.

  /usr/bin/python3 bench/contact_ends_spheroid.py RUN_FOLDER...   (each from `fictus solve
      tests/references/spheroid3d.toml --files results.json,points.csv,surface.vtp`)
"""
import json, os, sys
import numpy as np
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
from vtkmodules.util.numpy_support import vtk_to_numpy

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ref = json.load(open(os.path.join(root, "tests", "references", "spheroid3d.json")))
t_end = ref["values"]["contact_end_t"]
center, axis = np.array([0.49, 0.51, 0.5]), np.array([2, 3, 6]) / 7
samples = np.array(ref["boundary"])  # x, y, z, u, u − g, contact, ∂u/∂n
t_samples = (samples[:, :3] - center) @ axis
order = np.argsort(t_samples)
t_samples, samples = t_samples[order], samples[order]
exact_gap = lambda t: np.interp(t, t_samples, samples[:, 4])
exact_flux = lambda t: np.interp(t, t_samples, samples[:, 6])
a_semi, b_semi = 0.19, 0.32
rho = a_semi * np.sqrt(1 - t_end**2 / b_semi**2)
stretch = np.sqrt(1 + (a_semi**2 * t_end / (b_semi**2 * rho)) ** 2)  # arc length of the meridian per unit t


def fraction(q, r, d):
    if not q > 0:
        return 0.0
    if not (r > 0 and d > 0):
        return 1.0
    target, lo, hi = q * d / (1.5 * r), 0.0, 1.0
    for _ in range(60):
        theta = 0.5 * (lo + hi)
        lo, hi = (theta, hi) if np.sqrt(theta) / (1 - theta) ** 1.5 < target else (lo, theta)
    return 0.5 * (lo + hi)


print("| run | readings | law | mean [s] | rms [s] |")
print("|---|---|---|---|---|")
for run in sys.argv[1:]:
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(os.path.join(run, "surface.vtp"))
    reader.Update()
    surface = reader.GetOutput()
    triangles = vtk_to_numpy(surface.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    patch = vtk_to_numpy(surface.GetCellData().GetArray("patch"))
    points = np.genfromtxt(os.path.join(run, "points.csv"), delimiter=",", names=True)
    x = np.stack([points["x"], points["y"], points["z"]], 1)
    active, flux, gap = points["contact"] > 0.5, points["dudn"], points["u"] - points["g"]
    spacing = json.load(open(os.path.join(run, "results.json")))["boundary"]["spacing"]
    first, pairs = {}, set()  # patches sharing a triangle edge
    for t, corners in enumerate(triangles):
        for e in range(3):
            key = tuple(sorted((corners[e], corners[(e + 1) % 3])))
            if key in first and first[key] != patch[t]:
                pairs.add(tuple(sorted((first[key], patch[t]))))
            first.setdefault(key, patch[t])
    offsets, ratios = {}, {"q": [], "r": []}
    for i, j in pairs:
        if active[i] == active[j]:
            continue
        a, b = (i, j) if active[i] else (j, i)
        d = np.linalg.norm(x[b] - x[a])
        ta, tb = (x[a] - center) @ axis, (x[b] - center) @ axis
        cos_phi = min(1.0, max(0.5, abs(tb - ta) * stretch / d))
        ratios["q"].append(flux[a] / exact_flux(ta))
        ratios["r"].append(gap[b] / exact_gap(tb))
        for readings, q, r in (("solver", flux[a], gap[b]), ("exact", exact_flux(ta), exact_gap(tb))):
            for law, dd in (("along", d), ("across", cos_phi * d)):
                end = x[a] + fraction(q, r, dd) * (x[b] - x[a])
                offsets.setdefault((readings, law), []).append(((end - center) @ axis - t_end) * stretch / spacing)
    for (readings, law), v in offsets.items():
        v = np.array(v)
        print(f"| {os.path.basename(run.rstrip('/'))} | {readings} | {law} | {v.mean():+.3f} | {np.sqrt((v**2).mean()):.3f} |")
    print(f"| {os.path.basename(run.rstrip('/'))} | solver/exact, median | q {np.median(ratios['q']):.3f}, "
          f"r {np.median(ratios['r']):.3f} | | |")
