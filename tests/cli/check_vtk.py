#!/usr/bin/env python3
"""Reads solution.vti and curves.vtp with VTK's own XML readers (python3-vtk9) and checks sizes and
values against results.json and points.csv. Usage: check_vtk.py DIR"""
import csv
import json
import sys

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLImageDataReader, vtkXMLPolyDataReader


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
    curves = 2 if results["curve"]["delta"] > 0 else 1
    assert poly.GetNumberOfPoints() == curves * m and poly.GetNumberOfLines() == curves
    lam = vtk_to_numpy(poly.GetPointData().GetArray("lambda"))
    contact = vtk_to_numpy(poly.GetPointData().GetArray("contact"))
    assert np.allclose(lam[:m], [float(q["lambda"]) for q in points], rtol=1e-14, atol=1e-300)
    assert int(contact[:m].sum()) == results["newton"]["n_active"]
    print(f"{folder}: VTK files OK")


if __name__ == "__main__":
    main(sys.argv[1])
