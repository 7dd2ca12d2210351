#!/usr/bin/env python3
"""Solve the paper's problem from Python and draw the solution and the contact set.

    PYTHONPATH=build/python python3 examples/python/solve_paper.py [out.png]
"""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import fictus  # noqa: E402

problem = fictus.Problem.paper(N=512, variant="smooth")
s = problem.solve()
print(s, f"relative L2(omega) error {s.errors['rel_l2_omega']:.3e}, {s.timings['total']:.2f} s")
assert s.converged and s.signorini["max_complementarity"] < 1e-10

inside = ((s.x[None, :] - 0.5) / 0.4) ** 2 + ((s.y[:, None] - 0.5) / 0.2) ** 2 < 1
fig, ax = plt.subplots(figsize=(7, 5))
image = ax.pcolormesh(s.x, s.y, np.where(inside, s.u, np.nan), shading="auto")
fig.colorbar(image, label="û")
closed = lambda a: np.append(a, a[:1])  # noqa: E731
ax.plot(closed(s.points[:, 0]), closed(s.points[:, 1]), "k-", lw=1, label="γ")
ax.plot(closed(s.gamma_points[:, 0]), closed(s.gamma_points[:, 1]), "--", color="tab:orange", lw=1, label="Γ")
ax.plot(s.points[s.contact, 0], s.points[s.contact, 1], "r.", label="contact")
ax.set_aspect("equal")
ax.legend()
out = sys.argv[1] if len(sys.argv) > 1 else "paper_solution.png"
fig.savefig(out, dpi=120)
print("wrote", out)
