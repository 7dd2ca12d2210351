#!/usr/bin/env python3
"""What `fictus plot` draws, read from the figures themselves (apps/plot.py imported, savefig caught):

- 2-D profiles: the gap u − g and ∂u/∂n (the contact pressure), λ only with --lambda and never called
  a pressure; the solution picture marks s = 0 and has a colour bar;
- 3-D surface: coloured by ∂u/∂n and by the gap with a colour bar each; the painter's order draws no
  face turned away from the viewer and goes from far to near;
- a sweep folder: the contact force and measure against the swept value.

usage: check_plot_content.py PLOT_PY FOLDER_2D FOLDER_3D FOLDER_SWEEP
"""
import importlib.util
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def load(path):
    spec = importlib.util.spec_from_file_location("fictus_plot", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class Figures:
    """The figures plot.py saves, by file name (their saving is skipped)."""

    def __init__(self):
        self.saved = {}
        original = matplotlib.figure.Figure.savefig

        def catch(figure, path, *args, **kwargs):
            self.saved[path.rsplit("/", 1)[-1]] = figure
        matplotlib.figure.Figure.savefig = catch
        self.original = original

    def take(self):
        saved, self.saved = self.saved, {}
        return saved


def labels(figure):
    return [ax.get_ylabel() for ax in figure.axes]


def check(condition, message):
    if not condition:
        print("FAIL:", message)
        sys.exit(1)


def main(plot_py, folder_2d, folder_3d, folder_sweep):
    plot = load(plot_py)
    figures = Figures()
    plt.close = lambda *args, **kwargs: None  # keep the figures to read them

    plot.main(folder_2d)
    saved = figures.take()
    profile = labels(saved["profiles.png"])
    check(len(profile) == 2, f"profiles without --lambda: two panels, got {profile}")
    check(profile[0].startswith("gap u − g") and profile[1].startswith("∂u/∂n"), f"panels: {profile}")
    check(not any(label.startswith("λ") for label in profile), f"λ drawn unasked: {profile}")
    solution = saved["solution.png"]
    check(any(ax.get_label() == "<colorbar>" for ax in solution.axes), "solution.png has no colour bar")
    legend = [t.get_text() for t in solution.axes[0].get_legend().get_texts()]
    check("s = 0" in legend, f"s = 0 is not marked: {legend}")

    plot.main(folder_2d, True)
    profile = labels(figures.take()["profiles.png"])
    check(len(profile) == 3 and profile[2].startswith("λ"), f"profiles with --lambda: {profile}")
    check("pressure" not in profile[2] or "not a pressure" in profile[2], f"λ called a pressure: {profile[2]!r}")

    plot.main(folder_3d)
    surface = figures.take()["surface.png"]
    bars = [ax.get_ylabel() for ax in surface.axes if ax.get_label() == "<colorbar>"]
    check(len(bars) == 2 and bars[0].startswith("∂u/∂n") and bars[1].startswith("gap u − g"), f"colour bars: {bars}")
    points, triangles, cells = plot.read_vtp(f"{folder_3d}/surface.vtp")
    for elevation, azimuth in ((25, -60), (-25, 120), (90, 0), (0, 45)):
        toward, _, _ = plot.view_basis(elevation, azimuth)
        order = plot.visible_order(points, triangles, cells["normal"], toward)
        check(len(order) > 0 and np.all(cells["normal"][order] @ toward > 0), "a face turned away is drawn")
        depth = points[triangles[order]].mean(axis=1) @ toward
        check(np.all(np.diff(depth) >= 0), "the painter's order is not from far to near")
        facing = np.count_nonzero(cells["normal"] @ toward > 0)
        check(len(order) == facing, "a face turned towards the viewer is missing")

    plot.main(folder_sweep)
    sweep = labels(figures.take()["sweep.png"])
    check(len(sweep) == 2 and "force" in sweep[0] and "measure" in sweep[1], f"sweep panels: {sweep}")
    print("plot content: profiles, solution, surface (painter's order) and sweep as expected")


if __name__ == "__main__":
    main(*sys.argv[1:5])
