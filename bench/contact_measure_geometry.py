"""Geometry alone: how well the rules turn exactly located contact ends into a contact area on a
surface's patches. A plane cut n·x > c0 of γ plays the contact set, on the patches of a fictus run
(surface.vtp and points.csv of `fictus solve`, 3-D); every pair of neighbouring patches on either side
gets its end exactly on the cut curve: at the fraction θ of the chord whose nearest point of γ lies on
the plane (the chord dips under γ, and its own crossing of the plane is off the curve by its depth times
the slope; until 2026-11-29 this script took that crossing, which added 0.2–0.5 % rms to every rule).
Areas, against the cut's exact area on the same triangles:
- whole patches: the patches whose point is in the cut;
- strips: the whole patches moved by (θ·d − d_a)·ℓ along each border of length ℓ (fictus's rule until
  2026-11-28);
- polyline: the triangles' part inside the polyline of the ends (ψ = distance to the nearest segment,
  signed by the side of its active points, within 1.5 s; fictus's rule until 2026-11-29);
- curved: the polyline's area plus each segment's bulge, the area between its chord and the cubic
  through its ends and their other neighbours (fictus's rule since).

  /usr/bin/python3 bench/contact_measure_geometry.py RUN_FOLDER [CUTS]   (python3 with vtk)
"""
import sys, numpy as np
from collections import defaultdict
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkCellLocator
from vtkmodules.vtkCommonCore import reference

def read(path):
    r = vtkXMLPolyDataReader(); r.SetFileName(path); r.Update(); return r.GetOutput()

def tri_fraction(tp):
    """share of each triangle where the linear ψ (values at its corners) is < 0"""
    frac = np.empty(len(tp))
    for i, q in enumerate(tp):
        neg = [p < 0 for p in q]
        if all(neg): frac[i] = 1; continue
        if not any(neg): frac[i] = 0; continue
        odd = [j for j in range(3) if neg[j] != (sum(neg) >= 2)][0]
        o1, o2 = (odd + 1) % 3, (odd + 2) % 3
        f = (q[odd] / (q[odd] - q[o1])) * (q[odd] / (q[odd] - q[o2]))
        frac[i] = f if neg[odd] else 1 - f
    return frac

d = sys.argv[1]
surf = read(d + '/surface.vtp')
P = vtk_to_numpy(surf.GetPoints().GetData()); conn = vtk_to_numpy(surf.GetPolys().GetConnectivityArray()).reshape(-1, 3)
patch = vtk_to_numpy(surf.GetCellData().GetArray('patch'))
pts = np.genfromtxt(d + '/points.csv', delimiter=',', names=True)
X = np.stack([pts['x'], pts['y'], pts['z']], 1); w = pts['weight']; m = len(X)
A = 0.5 * np.linalg.norm(np.cross(P[conn[:, 1]] - P[conn[:, 0]], P[conn[:, 2]] - P[conn[:, 0]]), axis=1)
# patch weights from the triangles (as fictus's parts)
wt = np.bincount(patch, weights=A, minlength=m)
# neighbour pairs: edges between triangles of two patches
edge = {}; border = defaultdict(float); corners = defaultdict(list)
for t, (i0, i1, i2) in enumerate(conn):
    for a, b in ((i0, i1), (i1, i2), (i2, i0)):
        k = (min(a, b), max(a, b))
        if k in edge and edge[k] != patch[t]:
            p, q = sorted((edge[k], patch[t])); border[(p, q)] += np.linalg.norm(P[a] - P[b]); corners[(p, q)] += [a, b]
        else: edge[k] = patch[t]
locator = vtkCellLocator(); locator.SetDataSet(surf); locator.BuildLocator()


def onto_gamma(x):
    y = [0.0, 0.0, 0.0]; cell = reference(0); sub = reference(0); d2 = reference(0.0)
    locator.FindClosestPoint(list(x), y, cell, sub, d2)
    return np.array(y)


def on_plane(xa, xb, n, c0):
    """θ at which γ's point nearest to xa + θ(xb − xa) lies on the plane n·x = c0 (the chord itself dips
    under γ: its own crossing of the plane is off the cut curve by the chord's depth times the slope)"""
    g = lambda t: onto_gamma(xa + t * (xb - xa)) @ n - c0
    lo, hi, glo = 0.0, 1.0, g(0.0)
    for _ in range(40):
        mid = 0.5 * (lo + hi); gm = g(mid)
        if (gm > 0) == (glo > 0): lo, glo = mid, gm
        else: hi = mid
    return 0.5 * (lo + hi)


rng = np.random.default_rng(1)
errs = {'whole': [], 'strips': [], 'polyline': [], 'curved': []}


def bulge(E, S, across):
    """Σ over the segments of the area between the chord and the cubic through the ends on either side
    (chord-length parameters), on the side opposite `across` (positive: the curve bulges out of the contact
    set); segments whose ends do not each have exactly one other neighbour are left straight"""
    nb = defaultdict(list)
    for i, j in S: nb[i].append(j); nb[j].append(i)
    total = 0.0
    for (i, j), acr in zip(S, across):
        hs = [k for k in nb[i] if k != j]; ks = [k for k in nb[j] if k != i]
        if len(hs) != 1 or len(ks) != 1: continue
        P0, P1 = E[i], E[j]; ell = np.linalg.norm(P1 - P0)
        th = -np.linalg.norm(P0 - E[hs[0]]); tk = ell + np.linalg.norm(E[ks[0]] - P1)
        line = lambda t: P0 + (t / ell) * (P1 - P0)
        M = np.array([[th * (th - ell), th * th * (th - ell)], [tk * (tk - ell), tk * tk * (tk - ell)]])
        ab = np.linalg.solve(M, np.stack([E[hs[0]] - line(th), E[ks[0]] - line(tk)]))
        total -= (ab[0] * (-ell ** 3 / 6) + ab[1] * (-ell ** 4 / 12)) @ acr
    return total
for trial in range(int(sys.argv[2]) if len(sys.argv) > 2 else 20):
    n = rng.normal(size=3); n /= np.linalg.norm(n)
    proj = P @ n; c0 = np.quantile(proj, rng.uniform(0.2, 0.8))
    psi_exact = -(P @ n - c0)  # < 0 where n·x > c0: "contact"
    exact = (A * tri_fraction(psi_exact[conn])).sum()
    act = (X @ n - c0) > 0
    whole = wt[act].sum()
    located = whole; ends = []; at_corner = defaultdict(list)
    for (p, q), l in border.items():
        if act[p] == act[q]: continue
        a, b = (p, q) if act[p] else (q, p)
        fa, fb = X[a] @ n - c0, X[b] @ n - c0
        theta = on_plane(X[a], X[b], n, c0); dist = np.linalg.norm(X[b] - X[a])
        owned = dist * np.sqrt(wt[a]) / (np.sqrt(wt[a]) + np.sqrt(wt[b]))
        located += (theta * dist - owned) * l
        for c in corners[(p, q)]: at_corner[c].append(len(ends))
        ends.append((X[a] + theta * (X[b] - X[a]), X[a]))
    # polyline: ends joined when their borders share a vertex; ψ = signed distance to the nearest segment
    segs = set()
    for c, e in at_corner.items():
        e = sorted(set(e))
        for k in range(len(e) - 1): segs.add((e[k], e[k + 1]))
    E = np.array([e[0] for e in ends]); XA = np.array([e[1] for e in ends])
    S = np.array(sorted(segs)); a_, b_ = E[S[:, 0]], E[S[:, 1]]; ab = b_ - a_; ab2 = np.maximum((ab ** 2).sum(1), 1e-300)
    mid = 0.5 * (a_ + b_); act_pt = 0.5 * (XA[S[:, 0]] + XA[S[:, 1]])
    s = np.sqrt(w.mean()); R = 1.5 * s
    psi = np.full(len(P), np.nan)
    for i0 in range(0, len(P), 2048):
        V = P[i0:i0 + 2048]
        t = np.clip(((V[:, None, :] - a_[None]) * ab[None]).sum(2) / ab2[None], 0, 1)
        C = a_[None] + t[..., None] * ab[None]
        dist = np.linalg.norm(V[:, None, :] - C, axis=2); k = np.argmin(dist, 1); dm = dist[np.arange(len(V)), k]
        # active side: the side of the segment's active points, in the plane of the segment and the vertex's offset
        nrm = np.cross(ab[k], np.cross(act_pt[k] - mid[k], ab[k]))  # towards the active points, ⟂ segment
        side = ((V - C[np.arange(len(V)), k]) * nrm).sum(1)
        psi[i0:i0 + 2048] = np.where(dm < R, np.where(side > 0, -dm, dm), np.nan)
    tri_act = act[patch]
    tp = psi[conn]; fill = np.where(tri_act, -R, R)[:, None] * np.ones((1, 3)); tp = np.where(np.isnan(tp), fill, tp)
    poly = (A * tri_fraction(tp)).sum()
    across = np.cross(ab, np.cross(act_pt - mid, ab)); across /= np.linalg.norm(across, axis=1)[:, None]
    curved = poly + bulge(E, S, across)
    for k, v in (('whole', whole), ('strips', located), ('polyline', poly), ('curved', curved)): errs[k].append(v / exact - 1)
for k, v in errs.items():
    v = np.array(v) * 100
    print('%-9s mean %+.3f%%  rms %.3f%%  max |.| %.3f%%' % (k, v.mean(), np.sqrt((v ** 2).mean()), np.abs(v).max()))
