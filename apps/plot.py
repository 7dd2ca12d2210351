#!/usr/bin/env python3
"""fictus plot DIR: PNG plots of a solve or a reproduction in DIR.

- solution.png  û as a heat map (ω only), γ, Γ and the contact set (from solution.vti, points.csv)
- profiles.png  u − g, ∂u/∂n and λ along γ against arc length (from points.csv)
- convergence.png  relative errors against h with the paper's (from table1.csv / table2.csv)
3-D solves (results.json "dim": 3):
- slices.png   û on three orthogonal planes through the centre of ω (from solution.vti)
- surface.png  γ coloured by contact and by λ (from surface.vtp)
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
from matplotlib.ticker import NullFormatter, ScalarFormatter  # noqa: E402


def plain(axis):
    """Tick labels as plain numbers (scientific beyond 1e±4), never an offset such as "1e−6+9.999e−1"."""
    formatter = ScalarFormatter(useOffset=False)
    formatter.set_powerlimits((-3, 4))
    axis.set_major_formatter(formatter)


def dim_of(folder):
    path = os.path.join(folder, "results.json")
    if not os.path.exists(path):
        return 2
    with open(path) as handle:
        return json.load(handle).get("dim", 2)


def variant_of(folder):
    path = os.path.join(folder, "results.json")
    if not os.path.exists(path):
        return None
    with open(path) as handle:
        return json.load(handle).get("options", {}).get("variant")


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


def read_vti(path):
    """Reads fictus's own solution.vti: ImageData with appended arrays (UInt64 headers, zlib or raw)."""
    with open(path, "rb") as handle:
        data = handle.read()
    head, _, tail = data.partition(b"<AppendedData encoding=\"raw\">")
    text = head.decode()
    compressed = "vtkZLibDataCompressor" in text
    extent = [int(v) for v in re.search(r'WholeExtent="([^"]+)"', text).group(1).split()]
    origin = [float(v) for v in re.search(r'Origin="([^"]+)"', text).group(1).split()]
    spacing = [float(v) for v in re.search(r'Spacing="([^"]+)"', text).group(1).split()]
    raw = tail[tail.index(b"_") + 1:]
    arrays = {}
    for kind, name, offset in re.findall(r'type="(\w+)" Name="(\w+)" format="appended" offset="(\d+)"', text):
        dtype = {"Float64": "<f8", "UInt8": "u1"}[kind]
        values = np.frombuffer(appended_array(raw, int(offset), compressed), dtype=dtype)
        shape = (extent[3] + 1, extent[1] + 1) if extent[5] == 0 else (extent[5] + 1, extent[3] + 1, extent[1] + 1)
        arrays[name] = values.reshape(shape)
    axes = [origin[d] + spacing[d] * np.arange(extent[2 * d + 1] + 1) for d in range(3 if extent[5] else 2)]
    return (*axes, arrays)


def read_csv(path):
    with open(path) as handle:
        rows = list(csv.DictReader(handle))
    return {key: np.array([float(r[key]) for r in rows]) for key in rows[0]}


def closed(v):
    return np.append(v, v[0])


def plot_solution(folder):
    x, y, arrays = read_vti(os.path.join(folder, "solution.vti"))
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
    ax.plot(closed(p["x"]), closed(p["y"]), "k-", lw=1, label="γ")
    if np.any(np.hypot(p["Gamma_x"] - p["x"], p["Gamma_y"] - p["y"]) > 0):
        ax.plot(closed(p["Gamma_x"]), closed(p["Gamma_y"]), "--", color="tab:orange", lw=1, label="Γ")
    contact = p["contact"] > 0
    ax.plot(p["x"][contact], p["y"][contact], "r.", ms=4, label="contact")
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(title, fontsize=10)
    fig.savefig(os.path.join(folder, "solution.png"), dpi=120)
    plt.close(fig)


def plot_profiles(folder):
    p = read_csv(os.path.join(folder, "points.csv"))
    fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
    contact = p["contact"] > 0
    variant = variant_of(folder)
    lam = {"smooth": "λ: control on Γ\n(not a pressure)", "nonsmooth": "λ: contact\npressure on γ"}.get(variant, "λ")
    # Round-off is shown as 0: values below 1e-9 of the problem's scale (|u|, |g|, |∂u/∂n|, |λ|).
    scale = max(np.max(np.abs(p[key])) for key in ("u", "g", "dudn", "lambda"))
    for ax, values, label in zip(axes, (p["u"] - p["g"], p["dudn"], p["lambda"]), ("u − g", "∂u/∂n", lam)):
        values = np.where(np.abs(values) < 1e-9 * scale, 0.0, values)
        plain(ax.yaxis)
        ax.plot(p["s"], values, "k.-", ms=3)
        ax.plot(p["s"][contact], values[contact], "r.", ms=4)
        ax.axhline(0.0, color="gray", lw=0.5, zorder=0)
        ax.set_ylabel(label)
    axes[-1].set_xlabel("arc length s along γ (red: contact)")
    fig.suptitle("Signorini conditions along γ" + (f" ({variant} variant)" if variant else ""))
    fig.savefig(os.path.join(folder, "profiles.png"), dpi=120)
    plt.close(fig)


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
    fig.savefig(os.path.join(folder, "convergence.png"), dpi=120)
    plt.close(fig)


def plot_slices(folder):
    x, y, z, arrays = read_vti(os.path.join(folder, "solution.vti"))
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
    fig.savefig(os.path.join(folder, "slices.png"), dpi=110)
    plt.close(fig)


def read_vtp(path):
    """fictus's own surface.vtp (ASCII PolyData of triangles): the points and the cell arrays."""
    with open(path) as handle:
        text = handle.read()
    def block(name):
        match = re.search(r'Name="%s"[^>]*>([^<]*)<' % name, text)
        return np.array(match.group(1).split(), dtype=float)
    points = np.array(re.search(r"<Points>\s*<DataArray[^>]*>([^<]*)<", text).group(1).split(), dtype=float)
    cells = {name: block(name) for name in ("surface", "contact", "lambda")}
    return points.reshape(-1, 3, 3), cells


def plot_surface(folder):
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    triangles, cells = read_vtp(os.path.join(folder, "surface.vtp"))
    on_gamma = cells["surface"] == 0
    triangles = triangles[on_gamma]
    fig = plt.figure(figsize=(13, 6), constrained_layout=True)
    lam = cells["lambda"][on_gamma]
    colour_maps = [(np.where(cells["contact"][on_gamma] > 0, 1.0, 0.0), plt.get_cmap("coolwarm"), "contact (red)"),
                   ((lam - lam.min()) / max(np.ptp(lam), 1e-300), plt.get_cmap("viridis"),
                    f"λ per patch, {lam.min():.3g} … {lam.max():.3g}")]
    low, high = triangles.reshape(-1, 3).min(axis=0), triangles.reshape(-1, 3).max(axis=0)
    for k, (values, cmap, title) in enumerate(colour_maps):
        ax = fig.add_subplot(1, 2, k + 1, projection="3d")
        ax.add_collection3d(Poly3DCollection(triangles, facecolors=cmap(values), edgecolor="none"))
        for setter, d in ((ax.set_xlim, 0), (ax.set_ylim, 1), (ax.set_zlim, 2)):
            setter(low[d], high[d])
        ax.set_box_aspect(high - low)
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        ax.set_zlabel("z")
        ax.set_title(title, fontsize=10)
    fig.suptitle("fictus: γ, its contact set and the multipliers")
    fig.savefig(os.path.join(folder, "surface.png"), dpi=110)
    plt.close(fig)


def main(folder):
    made = []
    if dim_of(folder) == 3:
        inputs = "solution.vti or surface.vtp"
        if os.path.exists(os.path.join(folder, "solution.vti")):
            plot_slices(folder)
            made.append("slices.png")
        if os.path.exists(os.path.join(folder, "surface.vtp")):
            plot_surface(folder)
            made.append("surface.png")
    else:
        inputs = "solution.vti, points.csv or table<k>.csv"
        if os.path.exists(os.path.join(folder, "solution.vti")) and os.path.exists(os.path.join(folder, "points.csv")):
            plot_solution(folder)
            made.append("solution.png")
        if os.path.exists(os.path.join(folder, "points.csv")):
            plot_profiles(folder)
            made.append("profiles.png")
        if any(os.path.exists(os.path.join(folder, f"table{k}.csv")) for k in (1, 2)):
            plot_convergence(folder)
            made.append("convergence.png")
    if not made:
        print(f"fictus: error: plot: {folder} holds no {inputs}", file=sys.stderr)
        return 1
    print("wrote " + ", ".join(os.path.join(folder, name) for name in made))
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print("usage: plot.py DIR", file=sys.stderr)
        sys.exit(1)
    sys.exit(main(sys.argv[1]))
