#!/usr/bin/env python3
"""Reads solution.vti, curves.vtp, offset_curve.vtp (smooth variant) and solution.vtm with VTK's own
XML readers (python3-vtk9) and checks sizes and values against results.json and points.csv, and that
the files are binary and zlib-compressed. Usage: check_vtk.py DIR"""
import csv
import json
import sys

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLImageDataReader, vtkXMLMultiBlockDataReader, vtkXMLPolyDataReader


def main(folder):
    with open(f"{folder}/results.json") as handle:
        results = json.load(handle)
    with open(f"{folder}/points.csv") as handle:
        points = list(csv.DictReader(handle))
    n, h = results["grid"]["N"], results["grid"]["h"]

    reader = vtkXMLImageDataReader()
    reader.SetFileName(f"{folder}/solution.vti")
    reader.Update()
    image = reader.GetOutput()
    assert image.GetDimensions() == (n + 1, n + 1, 1), image.GetDimensions()
    assert abs(image.GetSpacing()[0] - h) < 1e-15
    data = image.GetPointData()
    u = vtk_to_numpy(data.GetArray("u")).reshape(n + 1, n + 1)
    inside = vtk_to_numpy(data.GetArray("inside")).reshape(n + 1, n + 1)
    assert np.all(u[0, :] == 0) and np.all(u[:, -1] == 0), "Dirichlet boundary values must be 0"
    area = inside.sum() * h * h
    assert abs(area - np.pi * 0.4 * 0.2) < 0.01, f"area of the ω mask {area}"
    if data.GetArray("error") is not None:
        error = vtk_to_numpy(data.GetArray("error"))
        exact = vtk_to_numpy(data.GetArray("u_exact"))
        rel = np.sqrt(np.sum(error ** 2) / np.sum(exact ** 2))
        assert rel < 3 * results["errors"]["rel_l2_omega"] + 1e-12, f"nodal error {rel}"
    # u at a collocation point by bilinear interpolation of the VTK grid = the trace in points.csv
    p = points[len(points) // 3]
    x, y = float(p["x"]), float(p["y"])
    i, j = int(x / h), int(y / h)
    xi, eta = x / h - i, y / h - j
    value = (u[j, i] * (1 - xi) * (1 - eta) + u[j, i + 1] * xi * (1 - eta) + u[j + 1, i] * (1 - xi) * eta
             + u[j + 1, i + 1] * xi * eta)
    assert abs(value - float(p["u"])) < 1e-12, (value, p["u"])

    reader = vtkXMLPolyDataReader()
    reader.SetFileName(f"{folder}/curves.vtp")
    reader.Update()
    poly = reader.GetOutput()
    m = results["multipliers"]
    smooth = results["boundary"]["delta"] > 0
    assert poly.GetNumberOfPoints() == m and poly.GetNumberOfLines() == 1  # γ alone
    data = poly.GetPointData()
    contact = vtk_to_numpy(data.GetArray("contact"))
    assert int(contact.sum()) == results["newton"]["n_active"]
    gap = vtk_to_numpy(data.GetArray("gap"))
    assert np.allclose(gap, [float(q["u"]) - float(q["g"]) for q in points], rtol=0, atol=1e-15)
    assert np.allclose(vtk_to_numpy(data.GetArray("dudn")), [float(q["dudn"]) for q in points], rtol=1e-15)
    lam = [float(q["lambda"]) for q in points]
    if smooth:  # λ lives on Γ: offset_curve.vtp
        assert data.GetArray("lambda") is None
        reader = vtkXMLPolyDataReader()
        reader.SetFileName(f"{folder}/offset_curve.vtp")
        reader.Update()
        offset = reader.GetOutput()
        assert offset.GetNumberOfPoints() == m and offset.GetNumberOfLines() == 1
        gx = vtk_to_numpy(offset.GetPoints().GetData())[:, 0]
        assert np.allclose(gx, [float(q["Gamma_x"]) for q in points], rtol=1e-15)
        assert np.allclose(vtk_to_numpy(offset.GetPointData().GetArray("lambda")), lam, rtol=1e-14, atol=1e-300)
    else:
        assert np.allclose(vtk_to_numpy(data.GetArray("lambda")), lam, rtol=1e-14, atol=1e-300)
    for name in ("solution.vti", "curves.vtp") + (("offset_curve.vtp",) if smooth else ()):
        with open(f"{folder}/{name}", "rb") as handle:
            head = handle.read(2048)
        assert b'compressor="vtkZLibDataCompressor"' in head and b'format="ascii"' not in head, name
    # contact_boundary.vtp: the contact ends located between neighbouring points, as vertices
    ends = vtkXMLPolyDataReader()
    ends.SetFileName(f"{folder}/contact_boundary.vtp")
    ends.Update()
    with open(f"{folder}/results.json") as handle:
        located = json.load(handle)["contact"]["boundary"]
    points = vtk_to_numpy(ends.GetOutput().GetPoints().GetData())
    assert ends.GetOutput().GetNumberOfVerts() == len(located) >= 2, located
    assert np.allclose(points[:, :2], np.array(located), rtol=0, atol=1e-15)
    # solution.vtm opens the run: the field, γ, (smooth) Γ and the contact boundary as blocks
    multi = vtkXMLMultiBlockDataReader()
    multi.SetFileName(f"{folder}/solution.vtm")
    multi.Update()
    blocks = multi.GetOutput()
    names = [blocks.GetMetaData(k).Get(blocks.NAME()) for k in range(blocks.GetNumberOfBlocks())]
    assert names == ["field", "gamma"] + (["Gamma"] if smooth else []) + ["contact boundary"], names
    assert blocks.GetBlock(1).GetNumberOfPoints() == m
    print(f"{folder}: VTK files OK")


if __name__ == "__main__":
    main(sys.argv[1])
