#!/usr/bin/env python3
"""A 3-D solve's output folder: results.json (dim 3, converged, errors under the bounds, the Signorini
conditions at round-off), points.csv (one row per patch, its columns), and the ParaView files read back
by VTK's own readers (solution.vti: (N+1)³ nodes with u, inside, u_exact, error; surface.vtp: γ's
triangles with shared points, per-patch cell data and point data; offset_surface.vtp: Γ with λ in the
smooth variant; solution.vtm naming them).

usage: check_3d.py FOLDER MAX_REL_L2_OMEGA MAX_REL_L2_GAMMA
"""
import csv
import json
import os
import sys

from vtkmodules.vtkFiltersCore import vtkCleanPolyData
from vtkmodules.vtkIOXML import vtkXMLImageDataReader, vtkXMLMultiBlockDataReader, vtkXMLPolyDataReader
from vtkmodules.util.numpy_support import vtk_to_numpy


def main():
    folder, max_l2, max_gamma = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
    with open(os.path.join(folder, "results.json")) as f:
        r = json.load(f)
    assert r["dim"] == 3, r["dim"]
    assert r["newton"]["converged"] and r["newton"]["iterations"] <= 10, r["newton"]
    s = r["signorini"]
    assert s["min_gap"] > -1e-12 and s["min_normal_derivative"] > -1e-10 and s["max_complementarity"] < 1e-12, s
    e = r["errors"]
    assert e["rel_l2_omega"] < max_l2, e
    assert e["rel_l2_gamma"] < max_gamma, e
    m, N = r["multipliers"], r["grid"]["N"]
    with open(os.path.join(folder, "points.csv")) as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == m, (len(rows), m)
    header = "i x y z nx ny nz weight g u dudn lambda contact condition Gamma_x Gamma_y Gamma_z dudn_check"
    assert list(rows[0].keys()) == header.split(), rows[0].keys()
    assert all(row["dudn_check"] != "" for row in rows)  # the independent check, in 3-D too
    assert sum(int(row["contact"]) for row in rows) == r["contact"]["points"]
    assert abs(sum(float(row["weight"]) for row in rows) - r["boundary"]["measure"]) < 1e-9
    force = sum(float(row["dudn"]) * float(row["weight"]) for row in rows if row["contact"] == "1")
    assert abs(force - r["contact"]["force_patches"]) <= 1e-9 * abs(r["contact"]["force"]), (force, r["contact"])

    image = vtkXMLImageDataReader()
    image.SetFileName(os.path.join(folder, "solution.vti"))
    image.Update()
    data = image.GetOutput()
    assert data.GetDimensions() == (N + 1, N + 1, N + 1), data.GetDimensions()
    point_data = data.GetPointData()
    u, inside, error = (vtk_to_numpy(point_data.GetArray(k)) for k in ("u", "inside", "error"))
    exact = vtk_to_numpy(point_data.GetArray("u_exact"))
    assert inside.sum() > 0 and abs(u[inside == 1] - exact[inside == 1] - error[inside == 1]).max() < 1e-12
    # the nodal error in ω is of the size of the L² error (a field of the right shape and order)
    assert abs(error).max() < 100 * max_l2 * abs(exact).max(), abs(error).max()

    poly = vtkXMLPolyDataReader()
    poly.SetFileName(os.path.join(folder, "surface.vtp"))
    poly.Update()
    surface = poly.GetOutput()
    cells = surface.GetCellData()
    patch, contact = vtk_to_numpy(cells.GetArray("patch")), vtk_to_numpy(cells.GetArray("contact"))
    assert surface.GetNumberOfCells() == len(patch) > m, surface.GetNumberOfCells()
    assert patch.max() == m - 1 and set(contact.tolist()) <= {0, 1}
    # points shared: VTK's own cleaning (exact duplicates) finds none left
    clean = vtkCleanPolyData()
    clean.SetInputData(surface)
    clean.SetTolerance(0.0)
    clean.PointMergingOn()
    clean.Update()
    assert clean.GetOutput().GetNumberOfPoints() == surface.GetNumberOfPoints() < surface.GetNumberOfCells(), (
        clean.GetOutput().GetNumberOfPoints(), surface.GetNumberOfPoints())
    # point data beside the cell data: the means at the points lie within the patches' range
    points = surface.GetPointData()
    for name in ("u", "g", "dudn", "gap", "contact", "dudn_check"):
        at_points, per_cell = vtk_to_numpy(points.GetArray(name)), vtk_to_numpy(cells.GetArray(name))
        assert len(at_points) == surface.GetNumberOfPoints(), name
        assert per_cell.min() - 1e-12 <= at_points.min() and at_points.max() <= per_cell.max() + 1e-12, name
    gap = vtk_to_numpy(cells.GetArray("gap"))
    assert abs(gap - (vtk_to_numpy(cells.GetArray("u")) - vtk_to_numpy(cells.GetArray("g")))).max() < 1e-15
    smooth = r["boundary"]["delta"] > 0
    assert (cells.GetArray("lambda") is None) == smooth  # λ lives on Γ in the smooth variant
    if smooth:
        offset = vtkXMLPolyDataReader()
        offset.SetFileName(os.path.join(folder, "offset_surface.vtp"))
        offset.Update()
        assert offset.GetOutput().GetCellData().GetArray("lambda") is not None
    # contact_boundary.vtp: the located contact ends as vertices, joined into closed polylines (every
    # end has two neighbours along the line but a few where several patch borders meet)
    ends = vtkXMLPolyDataReader()
    ends.SetFileName(os.path.join(folder, "contact_boundary.vtp"))
    ends.Update()
    located, lines = r["contact"]["boundary"], r["contact"]["boundary_lines"]
    assert ends.GetOutput().GetNumberOfVerts() == len(located) >= 3, len(located)
    assert ends.GetOutput().GetNumberOfLines() == len(lines) >= len(located) - 1, (len(lines), len(located))
    degree = [0] * len(located)
    for a, b in lines:
        degree[a] += 1
        degree[b] += 1
    assert sum(d == 2 for d in degree) >= 0.8 * len(located) and min(degree) >= 1, sorted(degree)
    multi = vtkXMLMultiBlockDataReader()
    multi.SetFileName(os.path.join(folder, "solution.vtm"))
    multi.Update()
    blocks = multi.GetOutput()
    names = [blocks.GetMetaData(k).Get(blocks.NAME()) for k in range(blocks.GetNumberOfBlocks())]
    assert names == ["field", "gamma"] + (["Gamma"] if smooth else []) + ["contact boundary"], names
    with open(os.path.join(folder, "surface.vtp"), "rb") as handle:
        head = handle.read(4096)
    assert b'compressor="vtkZLibDataCompressor"' in head and b'format="ascii"' not in head
    print(f"3-D output checked: N = {N}, m = {m}, L2(omega) {e['rel_l2_omega']:.3e}, "
          f"{surface.GetNumberOfCells()} triangles")


if __name__ == "__main__":
    main()
