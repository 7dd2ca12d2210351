#!/usr/bin/env python3
"""Manufactured 3-D Signorini solutions, the construction of manufactured.py on closed surfaces.

For a surface γ = {ρ = 0} (ρ < 0 in ω), a smooth v, a plane ℓ = 0 in general position and Q = A·(ℓ⁺)³,

    u = v + ρ·(Q − ∇v·∇ρ) / D,   D = |∇ρ|² − 2ρ,

has ∂u/∂n = Q/|∇ρ| on γ: contact (g = u) where ℓ > 0, free where ℓ < 0 with g = u − B·ℓ⁻ < u, and
∂²u/∂n² ≠ 0 on the free part (the script prints its range). f = −Δu + c·u on the whole box. D equals
|∇ρ|² on γ and stays ≥ 0.2 in the box (−2ρ > 0 inside, |∇ρ|² > 2ρ outside): with D = |∇ρ|² + ρ², as in
2-D, D fell to ρ² ≈ 0.02 at the centre and u had a steep bump there that the interior error then measured
instead of the boundary treatment.

Writes tests/convergence/manufactured_solutions_3d.hpp (f, u, ∇u, g in C++) and
examples/manufactured_<name>.toml (N = 80 and 96: the smallest grids whose Γ fits the default δ). The
header also holds sphere_neumann and torus_neumann (neumann_problems: no contact), without example files.
Run with python3 and PYTHONHASHSEED=0 (needs sympy; `make manufactured`); the outputs are committed.
"""
import math
import os
import random

import sympy as sp

from manufactured import ROOT, CxxPrinter, Pos, cxx_function, muparser

x, y, z = sp.symbols("x y z", real=True)
C = 1.0
A, B = 20, 0.5
V = (1 + sp.Rational(1, 2) * sp.sin(sp.Float(2.1) * x - sp.Float(1.3) * y + sp.Float(0.7) * z + sp.Float(0.4))
     + sp.Float(0.3) * x * y - sp.Float(0.2) * z * z)


def plane(direction, d):
    n = [float(a) for a in direction]
    length = math.sqrt(sum(a * a for a in n))
    return sum(sp.Float(a / length) * (s - sp.Rational(1, 2)) for a, s in zip(n, (x, y, z))) - sp.Float(d)


def problems():
    c = sp.Rational(1, 2)
    X, Y, Z = x - c, y - c, z - c
    sphere = dict(name="sphere", geometry=dict(shape="sphere", center=[0.5, 0.5, 0.5], radius=0.3),
                  rho=(X ** 2 + Y ** 2 + Z ** 2 - sp.Float(0.09)) / sp.Float(0.6), ell=plane([0.6, -0.5, 0.62], 0.06),
                  semi_axes=(0.3, 0.3, 0.3), N=80)
    a = (0.34, 0.26, 0.2)
    ellipsoid = dict(name="ellipsoid", geometry=dict(shape="ellipsoid", center=[0.5, 0.5, 0.5], semi_axes=list(a)),
                     rho=((X / sp.Float(a[0])) ** 2 + (Y / sp.Float(a[1])) ** 2 + (Z / sp.Float(a[2])) ** 2 - 1)
                     * sp.Float(a[2] / 2), ell=plane([-0.3, 0.7, 0.45], -0.04), semi_axes=a, N=96)
    # torus about the z-axis, R = 0.25, r = 0.1 (genus one, saddle-shaped inner side): the quartic
    # ρ = ((|x|² + R² − r²)² − 4R²(x² + y²))/(8R²r); D = |∇ρ|² + 50ρ² (∇ρ = 0 at the centre, in the hole)
    R, r = 0.25, 0.1
    quartic = ((X ** 2 + Y ** 2 + Z ** 2 + sp.Float(R * R - r * r)) ** 2 - sp.Float(4 * R * R) * (X ** 2 + Y ** 2))
    torus = dict(name="torus", geometry=dict(shape="torus", center=[0.5, 0.5, 0.5], major_radius=R, minor_radius=r),
                 rho=quartic / sp.Float(8 * R * R * r), ell=plane([0.45, 0.55, -0.7], 0.03), N=96, torus=(R, r),
                 D_weight=50)
    return [sphere, ellipsoid, torus]


def neumann_problems():
    """The sphere and the torus with the plane moved off γ (ℓ < 0 in the whole box): ∂u/∂n = 0 on all of
    γ, no contact, and with c = 1 a bias ε in the discrete mean of ∂u/∂n moves u by about ε·|γ|/|ω|
    (10ε on the sphere, 20ε on the torus). C++ only: no example files."""
    out = []
    for p in problems():
        if p["name"] == "ellipsoid":
            continue
        p = dict(p, name=p["name"] + "_neumann", ell=plane([0.3, 0.2, 0.5], 1.0))
        out.append(p)
    return out


def build(p):
    rho, ell = p["rho"], p["ell"]
    grad = lambda e: [sp.diff(e, s) for s in (x, y, z)]
    gv, gr = grad(V), grad(rho)
    Q = A * Pos(3, ell)
    D = sum(t ** 2 for t in gr) + p["D_weight"] * rho ** 2 if "D_weight" in p else sum(t ** 2 for t in gr) - 2 * rho
    u = V + rho * (Q - sum(a * b for a, b in zip(gv, gr))) / D
    du = grad(u)
    f = -sum(sp.diff(du[k], s) for k, s in enumerate((x, y, z))) + C * u
    g = u - B * Pos(1, -ell)
    return dict(u=u, ux=du[0], uy=du[1], uz=du[2], f=f, g=g, D=D)


def numeric(expr):
    def pos(s, n):
        return max(0.0, s) ** n

    code = CxxPrinter().doprint(expr).replace("std::", "math.")
    return lambda X, Y, Z: eval(code, {"math": math, "pos": pos, "x": X, "y": Y, "z": Z})


def check(p, e):
    """At random points of γ: the Signorini conditions, ∂²u/∂n² ≠ 0 on the free part, both parts (the
    pure Neumann problems: no contact)."""
    U, UX, UY, UZ, G = (numeric(e[k]) for k in ("u", "ux", "uy", "uz", "g"))
    L = numeric(p["ell"])
    D = numeric(e["D"])
    smallest = min(D(i / 10, j / 10, k / 10) for i in range(11) for j in range(11) for k in range(11))
    assert smallest > 0.1, (p["name"], "D", smallest)
    rng = random.Random(1)
    n_contact, unn = 0, []
    for _ in range(300):
        if "torus" in p:
            R, r = p["torus"]
            theta, phi = rng.uniform(0, 2 * math.pi), rng.uniform(0, 2 * math.pi)
            n = [math.cos(phi) * math.cos(theta), math.cos(phi) * math.sin(theta), math.sin(phi)]
            q = [0.5 + (R + r * math.cos(phi)) * math.cos(theta), 0.5 + (R + r * math.cos(phi)) * math.sin(theta),
                 0.5 + r * math.sin(phi)]
        else:
            a = p["semi_axes"]
            d = [rng.gauss(0, 1) for _ in range(3)]
            r = math.sqrt(sum(t * t for t in d))
            q = [0.5 + a[k] * d[k] / r for k in range(3)]
            n = [(q[k] - 0.5) / a[k] ** 2 for k in range(3)]
        nn = math.sqrt(sum(t * t for t in n))
        n = [t / nn for t in n]
        dudn = lambda s: sum(f(*(q[k] + s * n[k] for k in range(3))) * n[i] for i, f in enumerate((UX, UY, UZ)))
        gap = U(*q) - G(*q)
        assert gap >= -1e-12 and dudn(0) >= -1e-12 and abs(gap * dudn(0)) < 1e-12, (p["name"], q, gap, dudn(0))
        if L(*q) > 0:
            n_contact += 1
        else:
            unn.append((dudn(1e-4) - dudn(-1e-4)) / 2e-4)
    print(f"{p['name']}: contact at {n_contact}/300 points; free part: d2u/dn2 in [{min(unn):.3f}, {max(unn):.3f}]; "
          f"D >= {smallest:.3f} in the box")


def write_toml(p, e, implicit=False):
    """examples/manufactured_NAME.toml; implicit: the torus as a level set (manufactured_torus_implicit.toml)."""
    name = p["name"] + ("_implicit" if implicit else "")
    geometry = "\n".join(f"{k} = {v if not isinstance(v, str) else repr(v)}" for k, v in p["geometry"].items())
    intro = ""
    if implicit:
        R, r = p["torus"]
        geometry = (f'shape = "implicit"\nlevel = "(sqrt((x - 0.5)^2 + (y - 0.5)^2) - {R})^2 + (z - 0.5)^2 - {r * r:g}"\n'
                    f"bounds = [{0.5 - R - r - 0.1:g}, {0.5 + R + r + 0.1:g}, {0.5 - R - r - 0.1:g}, "
                    f"{0.5 + R + r + 0.1:g}, {0.5 - r - 0.05:g}, {0.5 + r + 0.05:g}]")
        intro = ("# The surface is given as a level set (shape = \"implicit\": level(x, y, z) < 0 inside, and a box\n"
                 "# that holds the surface), triangulated by fictus itself; the same problem as manufactured_torus.toml.\n")
    text = f"""{intro}# A manufactured 3-D Signorini solution on a {p['name']} (generated by tests/convergence/manufactured3d.py):
# u = v + ρ·(A(ℓ⁺)³ − ∇v·∇ρ)/D with γ = {{ρ = 0}}, so ∂u/∂n = A(ℓ⁺)³/|∇ρ| on γ: contact where
# ℓ > 0, free where ℓ < 0 (there u − g = {B}·ℓ⁻ and ∂²u/∂n² ≠ 0). f = −Δu + c·u.
[domain]
dim = 3
N = {p['N']}

[geometry]
{geometry}

[formulation]
variant = "smooth"

[data]
c = {C}
exact = "{muparser(e['u'])}"
f = "{muparser(e['f'])}"
g = "{muparser(e['g'])}"

[output]
dir = "results/manufactured_{name}"
"""
    with open(os.path.join(ROOT, "examples", f"manufactured_{name}.toml"), "w") as out:
        out.write(text)


def write_cxx(items):
    """tests/convergence/manufactured_solutions_3d.hpp; `make format` gives it the project's layout."""
    lines = ["#pragma once",
             "// Generated by tests/convergence/manufactured3d.py: do not edit. Manufactured 3-D Signorini",
             "// solutions (see that file): f = −Δu + c·u, u, ∇u and the obstacle g, on a sphere, an ellipsoid",
             "// and a torus, and the pure Neumann problems on the sphere and the torus (no contact).",
             "#include <algorithm>", "#include <cmath>", "#include <memory>", "#include <string>", "#include <vector>", "",
             '#include "fictus/solve/fictitious_domain_solver.hpp"', '#include "fictus/boundary/omega_quadrature.hpp"',
             '#include "fictus/boundary/surface.hpp"', '#include "fictus/solve/surface_discretization.hpp"', "",
             "namespace manufactured3d {", "",
             "/// max(0, s)^n for n = 1, 2, 3.",
             "inline double pos(double s, int n) { const double p = std::max(0.0, s); return n == 1 ? p : n == 2 ? p * p : p * p * p; }",
             ""]
    for p, e in items:
        lines.append(f"namespace {p['name']} {{")
        for key in ("u", "ux", "uy", "uz", "f", "g"):
            lines += cxx_function(key, e[key], "double x, double y, double z")
        lines.append(f"}}  // namespace {p['name']}")
        lines.append("")
    lines += ["struct Problem { std::string name; fictus::SurfaceProblem problem; };", "",
              f"/// The problems in the unit box, c = {C}, N cells.", "inline std::vector<Problem> all(int N) {",
              "  std::vector<Problem> out;"]
    for p, _ in items:
        name = p["name"]
        if "torus" in p:
            surface = f"std::make_shared<fictus::Torus>(fictus::Point3{{0.5, 0.5, 0.5}}, {p['torus'][0]}, {p['torus'][1]})"
        else:
            a = p["semi_axes"]
            surface = f"std::make_shared<fictus::Ellipsoid>(fictus::Point3{{0.5, 0.5, 0.5}}, fictus::Point3{{{a[0]}, {a[1]}, {a[2]}}})"
        lines += ["  {", "    fictus::SurfaceProblem p;", "    p.N = N;", f"    p.c = {C};", f"    p.gamma = {surface};",
                  f"    p.f = {name}::f;", f"    p.g = {name}::g;", f"    p.exact = {name}::u;",
                  f"    p.exact_gradient = [](double x, double y, double z) {{ return fictus::Point3{{{name}::ux(x, y, z), {name}::uy(x, y, z), {name}::uz(x, y, z)}}; }};",
                  f'    out.push_back({{"{name}", p}});', "  }"]
    lines += ["  return out;", "}", "", "}  // namespace manufactured3d", ""]
    with open(os.path.join(ROOT, "tests", "convergence", "manufactured_solutions_3d.hpp"), "w") as out:
        out.write("\n".join(lines))


def main():
    items = []
    for p in problems():
        e = build(p)
        check(p, e)
        write_toml(p, e)
        if "torus" in p:
            write_toml(p, e, implicit=True)
        items.append((p, e))
    for p in neumann_problems():
        e = build(p)
        check(p, e)
        items.append((p, e))
    write_cxx(items)


if __name__ == "__main__":
    main()
