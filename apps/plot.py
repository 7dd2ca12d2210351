#!/usr/bin/env python3
"""fictus plot DIR [--lambda]: PNG plots of a solve, a reproduction or a sweep in DIR.

2-D solves:
- solution.png     û as a heat map (ω only) with its colour bar, γ, Γ, the contact set and where the
                   arc length s along γ starts (s = 0, with the direction in which it grows)
- profiles.png     along γ against s: the gap u − g and ∂u/∂n, the contact pressure where u = g (with
                   the independent check's ∂u/∂n, dashed, where the solve made one); with --lambda, λ
3-D solves (results.json "dim": 3):
- slices.png       û on three orthogonal planes through the centre of ω
- surface.png      γ seen from two sides, coloured by ∂u/∂n (the contact pressure) and by the gap
                   u − g, each with its colour bar; with --lambda, λ too
Reproductions: convergence.png (relative errors against h with the paper's, from table<k>.csv).
Sweeps: sweep.png (the contact force and the contact measure against the swept value, from sweep.csv).

The surface is drawn by the painter's algorithm in the plane of the view: triangles facing away are
dropped and the rest drawn from the farthest to the nearest, so hidden parts never show through.
Needs numpy and matplotlib (Debian: python3-numpy, python3-matplotlib).
"""
import csv
import json
import os
import re
import sys
import zlib

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
from matplotlib.ticker import NullFormatter, ScalarFormatter  # noqa: E402


def plain(axis):
    """Tick labels as plain numbers (scientific beyond 1e±4), never an offset such as "1e−6+9.999e−1"."""
    formatter = ScalarFormatter(useOffset=False)
    formatter.set_powerlimits((-3, 4))
    axis.set_major_formatter(formatter)


def results_of(folder):
    path = os.path.join(folder, "results.json")
    if not os.path.exists(path):
        return {}
    with open(path) as handle:
        return json.load(handle)


# ---------------------------------------------------------------------------------------------
# Reading fictus's own VTK XML files (appended arrays, UInt64 headers, zlib or raw)

def appended_array(raw, offset, compressed):
    """The bytes of one appended array: raw (a UInt64 size, then the bytes) or in VTK's zlib layout
    (UInt64 block count, block size, last block size, compressed sizes, then the blocks)."""
    if not compressed:
        size = int(np.frombuffer(raw[offset:offset + 8], dtype="<u8")[0])
        return raw[offset + 8:offset + 8 + size]
    blocks = int(np.frombuffer(raw[offset:offset + 8], dtype="<u8")[0])
    sizes = np.frombuffer(raw[offset + 24:offset + 24 + 8 * blocks], dtype="<u8")
    start, parts = offset + 24 + 8 * blocks, []
    for size in sizes:
        parts.append(zlib.decompress(raw[start:start + int(size)]))
        start += int(size)
    return b"".join(parts)


TYPES = {"Float64": "<f8", "Float32": "<f4", "UInt8": "u1", "Int32": "<i4", "Int64": "<i8"}


def read_xml_arrays(path):
    """The head of the file (text) and its appended arrays by (section, name): section is the
    enclosing PointData, CellData, Points, Polys or Lines."""
    with open(path, "rb") as handle:
        data = handle.read()
    head, _, tail = data.partition(b"<AppendedData encoding=\"raw\">")
    text = head.decode()
    compressed = "vtkZLibDataCompressor" in text
    raw = tail[tail.index(b"_") + 1:]
    arrays, section = {}, None
    for match in re.finditer(r"<(/?)(PointData|CellData|Points|Polys|Lines)\b|<DataArray ([^>]*)/>", text):
        if match.group(2):
            section = None if match.group(1) else match.group(2)
            continue
        attributes = dict(re.findall(r'(\w+)="([^"]*)"', match.group(3)))
        values = np.frombuffer(appended_array(raw, int(attributes["offset"]), compressed),
                               dtype=TYPES[attributes["type"]])
        components = int(attributes.get("NumberOfComponents", "1"))
        arrays[(section, attributes["Name"])] = values.reshape(-1, components) if components > 1 else values
    return text, arrays


def read_vti(path):
    """fictus's solution.vti: the axes and the point arrays, shaped [j, i] or [k, j, i]."""
    text, found = read_xml_arrays(path)
    extent = [int(v) for v in re.search(r'WholeExtent="([^"]+)"', text).group(1).split()]
    origin = [float(v) for v in re.search(r'Origin="([^"]+)"', text).group(1).split()]
    spacing = [float(v) for v in re.search(r'Spacing="([^"]+)"', text).group(1).split()]
    shape = (extent[3] + 1, extent[1] + 1) if extent[5] == 0 else (extent[5] + 1, extent[3] + 1, extent[1] + 1)
    arrays = {name: values.reshape(shape) for (_, name), values in found.items()}
    axes = [origin[d] + spacing[d] * np.arange(extent[2 * d + 1] + 1) for d in range(3 if extent[5] else 2)]
    return (*axes, arrays)


def read_field(folder):
    """The field of a run: solution.vti, or (a run on several MPI ranks) solution.pvti's pieces put
    together. The axes and the point arrays, shaped [j, i] or [k, j, i]."""
    name = "solution.vti"
    multiblock = os.path.join(folder, "solution.vtm")
    if os.path.exists(multiblock):  # the run's own field, not an earlier run's file beside it
        with open(multiblock) as handle:
            named = re.search(r'name="field" file="([^"]+)"', handle.read())
        name = named.group(1) if named else name
    elif not os.path.exists(os.path.join(folder, name)):
        name = "solution.pvti"
    if name.endswith(".vti"):
        return read_vti(os.path.join(folder, name))
    with open(os.path.join(folder, name)) as handle:
        text = handle.read()
    extent = [int(v) for v in re.search(r'WholeExtent="([^"]+)"', text).group(1).split()]
    origin = [float(v) for v in re.search(r'Origin="([^"]+)"', text).group(1).split()]
    spacing = [float(v) for v in re.search(r'Spacing="([^"]+)"', text).group(1).split()]
    three = extent[5] > 0
    shape = (extent[5] + 1, extent[3] + 1, extent[1] + 1) if three else (extent[3] + 1, extent[1] + 1)
    arrays = {}
    for piece, source in re.findall(r'<Piece Extent="([^"]+)" Source="([^"]+)"', text):
        first, last = [int(v) for v in piece.split()][(4 if three else 2):(6 if three else 4)]
        _, found = read_xml_arrays(os.path.join(folder, source))
        for (_, name), values in found.items():
            whole = arrays.setdefault(name, np.zeros(shape, dtype=values.dtype))
            whole[first:last + 1] = values.reshape((last - first + 1,) + shape[1:])
    axes = [origin[d] + spacing[d] * np.arange(extent[2 * d + 1] + 1) for d in range(3 if three else 2)]
    return (*axes, arrays)


def read_vtp(path):
    """fictus's surface.vtp or offset_surface.vtp: points, triangles (point indices), cell arrays."""
    _, found = read_xml_arrays(path)
    points = found[("Points", "points")]
    triangles = found[("Polys", "connectivity")].reshape(-1, 3)
    cells = {name: values for (section, name), values in found.items() if section == "CellData"}
    return points, triangles, cells


def read_csv(path):
    with open(path) as handle:
        rows = list(csv.DictReader(handle))
    return {key: np.array([float(r[key]) if r[key] != "" else np.nan for r in rows]) for key in rows[0]}


def closed(v):
    return np.append(v, v[0])


# ---------------------------------------------------------------------------------------------
# 2-D

def plot_solution(folder):
    x, y, arrays = read_field(folder)
    p = read_csv(os.path.join(folder, "points.csv"))
    u = np.where(arrays["inside"] > 0, arrays["u"], np.nan)
    fig, ax = plt.subplots(figsize=(7, 6))
    image = ax.pcolormesh(x, y, u, shading="auto", cmap="viridis")
    bar = fig.colorbar(image, ax=ax, label="û in ω")
    plain(bar.ax.yaxis)
    title = "fictus: û, γ, Γ and the contact set"
    if "u_exact" in arrays:  # the exact solution's contours (dashed) over û's (solid)
        exact = np.where(arrays["inside"] > 0, arrays["u_exact"], np.nan)
        levels = np.linspace(np.nanmin(exact), np.nanmax(exact), 9)[1:-1]
        ax.contour(x, y, u, levels=levels, colors="k", linewidths=0.6)
        ax.contour(x, y, exact, levels=levels, colors="w", linewidths=0.8, linestyles="--")
        title += "\ncontours: û (black), exact solution (white, dashed)"
    geometry = results_of(folder).get("problem", {}).get("geometry", {})
    if isinstance(geometry, dict) and geometry.get("shape") == "polygon":  # γ itself, corners included
        corners = np.array(geometry["vertices"], dtype=float)
        ax.plot(closed(corners[:, 0]), closed(corners[:, 1]), "k-", lw=1, label="γ")
    else:
        ax.plot(closed(p["x"]), closed(p["y"]), "k-", lw=1, label="γ (through the points)")
    if np.any(np.hypot(p["Gamma_x"] - p["x"], p["Gamma_y"] - p["y"]) > 0):
        ax.plot(closed(p["Gamma_x"]), closed(p["Gamma_y"]), "--", color="tab:orange", lw=1, label="Γ")
    contact = p["contact"] > 0
    ax.plot(p["x"][contact], p["y"][contact], "r.", ms=4, label="contact")
    for code, marker, colour, part_label in PARTS:  # mixed conditions: the Dirichlet and Neumann parts
        part = p.get("condition", np.zeros_like(p["x"])) == code
        if np.any(part):
            ax.plot(p["x"][part], p["y"][part], marker, color=colour, ms=4, label=part_label)
    # s = 0: the first point, and an arrow along γ in the direction of increasing s
    ax.plot(p["x"][0], p["y"][0], "o", mfc="none", mec="k", ms=8, label="s = 0")
    step = max(1, len(p["x"]) // 24)
    ax.annotate("", xy=(p["x"][step], p["y"][step]), xytext=(p["x"][0], p["y"][0]),
                arrowprops=dict(arrowstyle="->", color="k", lw=1.2))
    ax.annotate("s = 0", (p["x"][0], p["y"][0]), textcoords="offset points", xytext=(8, -12), fontsize=8)
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(title, fontsize=10)
    save(fig, folder, "solution.png", 120)


def lambda_label(variant):
    return {"smooth": "λ: control on Γ\n(not a pressure)",
            "nonsmooth": "λ: jump of ∂û/∂n\nacross γ (not a force)"}.get(variant, "λ")


PRESSURE = "∂u/∂n: contact\npressure where u = g"
# The parts of γ under other conditions than Signorini's (points.csv `condition`): code, marker, colour, label.
PARTS = ((1, "s", "tab:blue", "Dirichlet: u = u_D"), (2, "^", "tab:green", "Neumann: ∂u/∂n = q"))


def plot_profiles(folder, with_lambda):
    p = read_csv(os.path.join(folder, "points.csv"))
    variant = results_of(folder).get("options", {}).get("variant")
    panels = [(p["u"] - p["g"], "gap u − g"), (p["dudn"], PRESSURE)]
    if with_lambda:
        panels.append((p["lambda"], lambda_label(variant)))
    fig, axes = plt.subplots(len(panels), 1, figsize=(7, 2.4 * len(panels) + 0.6), sharex=True)
    contact = p["contact"] > 0
    # Round-off is shown as 0: values below 1e-9 of the problem's scale (|u|, |g|, |∂u/∂n|).
    scale = max(np.max(np.abs(p[key])) for key in ("u", "g", "dudn"))
    for ax, (values, label) in zip(axes, panels):
        values = np.where(np.abs(values) < 1e-9 * scale, 0.0, values)
        plain(ax.yaxis)
        ax.plot(p["s"], values, "k.-", ms=3, lw=0.8)
        ax.plot(p["s"][contact], values[contact], "r.", ms=4)
        for code, marker, colour, part_label in PARTS:
            part = p.get("condition", np.zeros_like(p["s"])) == code
            if np.any(part):
                ax.plot(p["s"][part], values[part], marker, color=colour, ms=3, label=part_label)
        ax.axhline(0.0, color="gray", lw=0.5, zorder=0)
        ax.set_ylabel(label, fontsize=9)
    check = p.get("dudn_check")
    if check is not None and np.all(np.isfinite(check)):
        axes[1].plot(p["s"], check, "--", color="tab:blue", lw=0.8, label="independent estimate")
        axes[1].plot([], [], "k.-", ms=3, lw=0.8, label="enforced (C_γ û)")
        axes[1].legend(fontsize=7, loc="best")
    mixed = np.any(p.get("condition", np.zeros_like(p["s"])) > 0)
    axes[-1].set_xlabel("arc length s along γ from s = 0 (red: contact" +
                        ("; blue squares: Dirichlet, green triangles: Neumann)" if mixed else ")"))
    fig.suptitle("Signorini conditions along γ" + (f" ({variant} variant)" if variant else ""))
    save(fig, folder, "profiles.png", 120)


PAPER = {  # relative L2(ω), L2(γ) of the paper's Tables 1 and 2, h = 1/128 … 1/4096
    1: ([4.10e-2, 2.00e-2, 9.78e-3, 4.84e-3, 2.27e-3, 1.13e-3], [1.70e-2, 8.52e-3, 4.25e-3, 2.08e-3, 1.09e-3, 7.21e-4]),
    2: ([3.24e-4, 6.31e-5, 1.59e-5, 4.35e-6, 1.38e-6, 8.07e-7], [5.07e-4, 9.10e-5, 2.65e-5, 1.17e-5, 5.18e-6, 2.28e-6]),
}


def slope_triangle(ax, h, e, order, colour):
    """A triangle of slope `order` below the data near its finest h, labelled with the order."""
    h0, h1 = h, h * 2
    e0 = e * 0.3
    e1 = e0 * (h1 / h0) ** order
    ax.loglog([h0, h1, h1, h0], [e0, e0, e1, e0], "-", color=colour, lw=0.8)
    ax.text(h1 * 1.08, np.sqrt(e0 * e1), f"{order}", color=colour, fontsize=8, va="center")


def plot_convergence(folder):
    fig, ax = plt.subplots(figsize=(7.5, 5.5))
    hs = []
    for table, colour in ((1, "C0"), (2, "C1")):
        path = os.path.join(folder, f"table{table}.csv")
        if not os.path.exists(path):
            continue
        t = read_csv(path)
        hs += list(t["h"])
        ax.loglog(t["h"], t["rel_l2_omega"], "o-", color=colour, label=f"Table {table}: L²(ω)")
        ax.loglog(t["h"], t["rel_h1_omega"], "s-", color=colour, label=f"Table {table}: H¹(ω)")
        ax.loglog(t["h"], t["rel_l2_gamma"], "^-", color=colour, label=f"Table {table}: L²(γ)")
        # the paper's rows at the levels shown
        rows = [k for k in range(6) if np.any(np.isclose(t["h"], 1 / 128 / 2 ** k))]
        if rows:
            h_paper = [1 / 128 / 2 ** k for k in rows]
            ax.loglog(h_paper, [PAPER[table][0][k] for k in rows], "o:", color=colour, alpha=0.5,
                      label=f"paper {table}: L²(ω)")
            ax.loglog(h_paper, [PAPER[table][1][k] for k in rows], "^:", color=colour, alpha=0.5,
                      label=f"paper {table}: L²(γ)")
        order = 1 if table == 1 else 2
        slope_triangle(ax, min(t["h"]), min(t["rel_l2_omega"]), order, colour)
    if hs:  # one tick per grid, labelled 1/N
        ticks = sorted(set(hs))
        ax.set_xticks(ticks)
        ax.set_xticklabels([f"1/{round(1 / h)}" for h in ticks])
        ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("h")
    ax.set_ylabel("relative error")
    ax.grid(True, which="major", lw=0.3)
    ax.legend(fontsize=7, ncol=2)
    ax.set_title("fictus convergence; dotted: the paper (its H¹ column is not a relative error)\n"
                 "triangles: slopes 1 (Table 1) and 2 (Table 2)", fontsize=9)
    save(fig, folder, "convergence.png", 120)


# ---------------------------------------------------------------------------------------------
# 3-D

def plot_slices(folder):
    x, y, z, arrays = read_field(folder)
    inside = arrays["inside"] > 0
    u = np.where(inside, arrays["u"], np.nan)  # indexed [k, j, i]
    k, j, i = (int(round(float(np.mean(np.nonzero(inside)[a])))) for a in range(3))
    panels = [(u[k, :, :], x, y, "x", "y", f"z = {z[k]:.3g}"), (u[:, j, :], x, z, "x", "z", f"y = {y[j]:.3g}"),
              (u[:, :, i], y, z, "y", "z", f"x = {x[i]:.3g}")]
    low, high = np.nanmin(u), np.nanmax(u)
    fig, axes = plt.subplots(1, 3, figsize=(15, 5), constrained_layout=True)
    for ax, (values, a, b, la, lb, title) in zip(axes, panels):
        image = ax.pcolormesh(a, b, values, shading="auto", cmap="viridis", vmin=low, vmax=high)
        ax.set_aspect("equal")
        ax.set_xlabel(la)
        ax.set_ylabel(lb)
        ax.set_title(title, fontsize=10)
    bar = fig.colorbar(image, ax=axes, label="û in ω", shrink=0.8)
    plain(bar.ax.yaxis)
    fig.suptitle("fictus: û on three planes through the centre of ω")
    save(fig, folder, "slices.png", 110)


def view_basis(elevation, azimuth):
    """The unit vector towards the viewer and two in the picture plane (right, up), in degrees."""
    e, a = np.radians(elevation), np.radians(azimuth)
    toward = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    right = np.array([-np.sin(a), np.cos(a), 0.0])
    return toward, right, np.cross(toward, right)


def visible_order(points, triangles, normals, toward):
    """The triangles facing the viewer (outward normal towards `toward`), farthest first: the
    painter's algorithm on a closed surface."""
    depth = points[triangles].mean(axis=1) @ toward
    facing = np.nonzero(normals @ toward > 0)[0]
    return facing[np.argsort(depth[facing], kind="stable")]


def draw_surface(ax, points, triangles, normals, values, toward, right, up, cmap, norm):
    order = visible_order(points, triangles, normals, toward)
    corners = points[triangles[order]]
    flat = np.stack([corners @ right, corners @ up], axis=-1)
    shade = 0.55 + 0.45 * np.clip(normals[order] @ toward, 0, 1)  # a little light from the viewer
    colours = cmap(norm(values[order]))
    colours[:, :3] *= shade[:, None]
    ax.add_collection(PolyCollection(flat, facecolors=colours, edgecolors=colours, linewidths=0.3))  # no seams
    ax.set_xlim(flat[..., 0].min(), flat[..., 0].max())
    ax.set_ylim(flat[..., 1].min(), flat[..., 1].max())
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])


def plot_surface(folder, with_lambda):
    points, triangles, cells = read_vtp(os.path.join(folder, "surface.vtp"))
    normals = cells["normal"]
    variant = results_of(folder).get("options", {}).get("variant")
    fields = [(cells["dudn"], "∂u/∂n: contact pressure where u = g", "viridis"),
              (cells["gap"], "gap u − g", "magma")]
    lam_surface = None
    if with_lambda:
        if "lambda" in cells:
            fields.append((cells["lambda"], lambda_label(variant).replace("\n", " "), "coolwarm"))
        elif os.path.exists(os.path.join(folder, "offset_surface.vtp")):
            lam_surface = read_vtp(os.path.join(folder, "offset_surface.vtp"))
            fields.append((lam_surface[2]["lambda"], lambda_label(variant).replace("\n", " "), "coolwarm"))
    if "condition" in cells and np.any(cells["condition"] > 0):  # mixed conditions: the parts of γ
        fields.append((cells["condition"], "parts of γ (0 S, 1 D, 2 N)", "viridis"))
    views = [(25, -60, "front"), (-25, 120, "back")]
    fig, axes = plt.subplots(len(fields), 2, figsize=(11, 4.6 * len(fields)), squeeze=False,
                             constrained_layout=True)
    for row, (values, label, cmap_name) in enumerate(fields):
        cmap = plt.get_cmap(cmap_name)
        norm = plt.Normalize(np.min(values), np.max(values) if np.ptp(values) > 0 else np.min(values) + 1)
        surface = (points, triangles, normals) if lam_surface is None or row < 2 else \
            (lam_surface[0], lam_surface[1], lam_surface[2]["normal"])
        for column, (elevation, azimuth, name) in enumerate(views):
            toward, right, up = view_basis(elevation, azimuth)
            ax = axes[row, column]
            draw_surface(ax, *surface, values, toward, right, up, cmap, norm)
            ax.set_title(f"{label}: {name} (elevation {elevation}°, azimuth {azimuth}°)", fontsize=9)
        bar = fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=axes[row, :], shrink=0.8, label=label)
        plain(bar.ax.yaxis)
        if values is cells["dudn"] or values is cells["gap"]:
            bar.ax.axhline(0.0, color="w", lw=1.0)  # the contact/free divide: ∂u/∂n = 0 or u = g
    mixed = "condition" in cells and np.any(cells["condition"] > 0)
    fig.suptitle("fictus: γ coloured by the contact pressure and the gap" + (f" ({variant} variant)" if variant else "") +
                 ("\nparts of γ: 0 Signorini (S), 1 Dirichlet (D), 2 Neumann (N)" if mixed else ""))
    save(fig, folder, "surface.png", 110)


# ---------------------------------------------------------------------------------------------
# Sweeps

def plot_sweep(folder):
    with open(os.path.join(folder, "sweep.json")) as handle:
        sweep = json.load(handle)
    name = sweep["sweep"]["name"]
    rows = sweep["rows"]
    values = np.array([r[name] for r in rows])
    converged = np.array([bool(r["converged"]) for r in rows])
    fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for ax, key, label in ((axes[0], "contact_force", "contact force ∫ ∂u/∂n over the contact set"),
                           (axes[1], "contact_measure", "contact measure (length or area)")):
        y = np.array([r[key] for r in rows])
        ax.plot(values[converged], y[converged], "k.-", ms=5)
        if not converged.all():
            ax.plot(values[~converged], y[~converged], "rx", ms=7, label="Newton did not converge")
            ax.legend(fontsize=8)
        plain(ax.yaxis)
        ax.set_ylabel(label, fontsize=9)
        ax.grid(True, lw=0.3)
    axes[-1].set_xlabel(name)
    title = sweep.get("problem", {}).get("name") or "the paper's problem"
    fig.suptitle(f"fictus sweep of {name}: {title}")
    save(fig, folder, "sweep.png", 120)


class WriteError(Exception):
    """A plot that could not be written (exit code 3, as an output file of the other commands)."""


def save(fig, folder, name, dpi):
    try:
        fig.savefig(os.path.join(folder, name), dpi=dpi)
    except OSError as e:
        raise WriteError(f"cannot write {os.path.join(folder, name)}: {e.strerror or e}") from e
    finally:
        plt.close(fig)


def main(folder, with_lambda=False):
    made = []
    exists = lambda name: os.path.exists(os.path.join(folder, name))  # noqa: E731
    if exists("sweep.json"):
        plot_sweep(folder)
        made.append("sweep.png")
    if results_of(folder).get("dim", 2) == 3:
        inputs = "solution.vti or surface.vtp"
        if exists("solution.vti") or exists("solution.pvti"):
            plot_slices(folder)
            made.append("slices.png")
        if exists("surface.vtp"):
            plot_surface(folder, with_lambda)
            made.append("surface.png")
    else:
        inputs = "solution.vti, points.csv, table<k>.csv or sweep.json"
        if (exists("solution.vti") or exists("solution.pvti")) and exists("points.csv"):
            plot_solution(folder)
            made.append("solution.png")
        if exists("points.csv"):
            plot_profiles(folder, with_lambda)
            made.append("profiles.png")
        if exists("table1.csv") or exists("table2.csv"):
            plot_convergence(folder)
            made.append("convergence.png")
    if not made:
        print(f"fictus: error: plot: {folder} holds no {inputs}", file=sys.stderr)
        return 1
    print("wrote " + ", ".join(os.path.join(folder, name) for name in made))
    return 0


if __name__ == "__main__":
    arguments = [a for a in sys.argv[1:] if a != "--lambda"]
    if len(arguments) != 1:
        print("usage: plot.py DIR [--lambda]", file=sys.stderr)
        sys.exit(1)
    folder = arguments[0]
    try:
        sys.exit(main(folder, "--lambda" in sys.argv[1:]))
    except WriteError as e:
        print(f"fictus: error: plot: {e}"[:240], file=sys.stderr)
        sys.exit(3)
    except (OSError, ValueError, TypeError, KeyError, IndexError, AttributeError, zlib.error) as e:
        # A file that is missing, truncated or not one fictus wrote: one line, not a traceback.
        reason = " ".join(f"{type(e).__name__}: {e}".split())
        print(f"fictus: error: plot: cannot read the results in {folder}: {reason}"[:240], file=sys.stderr)
        sys.exit(1)
