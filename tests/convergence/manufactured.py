#!/usr/bin/env python3
"""Manufactured Signorini solutions whose second normal derivative does not vanish on the free part.

For a curve γ = {ρ = 0} (ρ < 0 in ω), a smooth v, a line ℓ = 0 and Q = A·(ℓ⁺)³, the function

    u = v + ρ·(Q − ∇v·∇ρ) / D,   D > 0 smooth with D = |∇ρ|² on γ (|∇ρ|² + ρ², or a constant),

has ∂u/∂n = Q/|∇ρ| on γ (n = ∇ρ/|∇ρ|), because the bracket replaces the normal derivative of v by
Q/|∇ρ|. So ∂u/∂n > 0 where ℓ > 0 (contact: g = u there) and ∂u/∂n = 0 where ℓ < 0 (free), with
g = u − B·ℓ⁻ < u on the free part; f = −Δu + c·u on the whole box. Every ρ is a polynomial
(the star's too), so u and f are smooth except for (ℓ⁺)³. ∂²u/∂n² on the free part is −v_nn plus
terms in v_n: not zero (the script prints its range).

Writes, from one description:
  tests/convergence/manufactured_solutions.hpp   C++ (f, u, ∇u, g) for the convergence tests;
  examples/manufactured_<name>.toml              problem files with muParser expressions.
Run with python3 (needs sympy) from anywhere; the outputs are committed.
"""
import math
import os

import sympy as sp
from sympy.printing.cxx import CXX17CodePrinter

x, y = sp.symbols("x y", real=True)
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


class Pos(sp.Function):
    """Pos(n, s) = max(0, s)^n with exact derivatives n·Pos(n−1, s)."""

    @classmethod
    def eval(cls, n, s):
        if n == 0:
            return None

    def fdiff(self, argindex=2):
        n, s = self.args
        if n == 1:
            return sp.Heaviside(s)
        return n * Pos(n - 1, s)


C = 1.0
V = 1 + sp.Rational(1, 2) * sp.sin(sp.Float(2.1) * x - sp.Float(1.3) * y + sp.Float(0.4)) + sp.Float(0.3) * x * y
A, B = 20, 0.5


def line(beta, d):
    return sp.Float(math.cos(beta)) * (x - sp.Rational(1, 2)) + sp.Float(math.sin(beta)) * (y - sp.Rational(1, 2)) - sp.Float(d)


def problems():
    cx = cy = sp.Rational(1, 2)
    # circle: centre (½, ½), radius 0.3
    circle = dict(name="circle", geometry=dict(shape="circle", center=[0.5, 0.5], radius=0.3),
                  rho=(x - cx) ** 2 + (y - cy) ** 2 - sp.Float(0.09), denominator=sp.Float(4 * 0.09), ell=line(2.2, 0.07))
    # rotated ellipse: semi-axes 0.35, 0.22, angle −0.4
    ang = -0.4
    xi = sp.Float(math.cos(ang)) * (x - cx) + sp.Float(math.sin(ang)) * (y - cy)
    eta = -sp.Float(math.sin(ang)) * (x - cx) + sp.Float(math.cos(ang)) * (y - cy)
    ellipse = dict(name="ellipse", geometry=dict(shape="ellipse", center=[0.5, 0.5], semi_axes=[0.35, 0.22], angle=ang),
                   rho=(xi / sp.Float(0.35)) ** 2 + (eta / sp.Float(0.22)) ** 2 - 1, denominator=None, ell=line(0.9, -0.05))
    # six-lobed star r(t) = 0.3·(1 − 0.6 cos 6t)^(−1/6) (non-convex): ρ = (r⁶ − 0.6·Re((x + iy)⁶) − 0.3⁶)/0.3⁵,
    # a polynomial whose gradient vanishes only at the centre (where ρ = −0.3)
    X, Y = x - cx, y - cy
    re6 = X ** 6 - 15 * X ** 4 * Y ** 2 + 15 * X ** 2 * Y ** 4 - Y ** 6
    star = dict(name="star", geometry=dict(shape="star", center=[0.5, 0.5], r="0.3 * (1 - 0.6 * cos(6 * t))^(-1/6)"),
                rho=((X ** 2 + Y ** 2) ** 3 - sp.Float(0.6) * re6 - sp.Float(0.3) ** 6) / sp.Float(0.3) ** 5,
                denominator=None, ell=line(4.0, 0.04))
    return [circle, ellipse, star]


def build(p):
    rho, ell = p["rho"], p["ell"]
    grad = lambda e: (sp.diff(e, x), sp.diff(e, y))
    gv, gr = grad(V), grad(rho)
    Q = A * Pos(3, ell)
    D = p["denominator"] if p["denominator"] is not None else gr[0] ** 2 + gr[1] ** 2 + rho ** 2
    u = V + rho * (Q - (gv[0] * gr[0] + gv[1] * gr[1])) / D
    ux, uy = grad(u)
    f = -(sp.diff(ux, x) + sp.diff(uy, y)) + C * u
    g = u - B * Pos(1, -ell)
    return dict(u=u, ux=ux, uy=uy, f=f, g=g)


# ---- printers ----

class CxxPrinter(CXX17CodePrinter):
    def _print_Pos(self, e):
        return f"pos({self._print(e.args[1])}, {int(e.args[0])})"



def muparser(e):
    """A muParser expression: ^ for powers, max for ⁺, common subexpressions as locals "q0 = …, …"."""
    def walk(e):
        if isinstance(e, Pos):
            return f"max(0, {walk(e.args[1])})^{int(e.args[0])}"
        if e.is_Add:
            return "(" + " + ".join(walk(a) for a in e.args) + ")"
        if e.is_Mul:
            return "(" + "*".join(walk(a) for a in e.args) + ")"
        if e.is_Pow:
            base, exponent = e.args
            if exponent == sp.Rational(1, 2):
                return f"sqrt({walk(base)})"
            if exponent == -1:
                return f"(1/{walk(base)})"
            return f"({walk(base)})^({walk(exponent)})"
        if isinstance(e, (sp.sin, sp.cos)):
            return f"{type(e).__name__}({walk(e.args[0])})"
        if e.is_Symbol:
            return e.name
        if e.is_Number:
            return repr(float(e)) if not e.is_Integer else str(int(e))
        raise ValueError(f"cannot print {e!r}")
    subs, (main,) = sp.cse(e, symbols=sp.numbered_symbols("q"), optimizations="basic")
    return ", ".join([f"{a} = {walk(b)}" for a, b in subs] + [walk(main)])


def numeric(expr):
    """A numpy-free float evaluator of an expression (for the checks below)."""
    def pos(s, n):
        return max(0.0, s) ** n

    code = CxxPrinter().doprint(expr).replace("std::", "math.")
    return lambda X, Y: eval(code, {"math": math, "pos": pos, "x": X, "y": Y})


def check(p, e):
    """On γ: Signorini conditions hold, ∂²u/∂n² on the free part is not zero, both parts exist."""
    rho = p["rho"]
    gr = (sp.diff(rho, x), sp.diff(rho, y))
    U, UX, UY, G = (numeric(e[k]) for k in ("u", "ux", "uy", "g"))
    RX, RY, L = numeric(gr[0]), numeric(gr[1]), numeric(p["ell"])
    # points on γ: along rays from the centre, bisection on ρ
    R = numeric(rho)
    n_contact, unn = 0, []
    for k in range(200):
        th = 2 * math.pi * (k + 0.5) / 200
        lo, hi = 0.05, 0.45
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if R(0.5 + mid * math.cos(th), 0.5 + mid * math.sin(th)) < 0:
                lo = mid
            else:
                hi = mid
        X, Y = 0.5 + lo * math.cos(th), 0.5 + lo * math.sin(th)
        nx, ny = RX(X, Y), RY(X, Y)
        nn = math.hypot(nx, ny)
        nx, ny = nx / nn, ny / nn
        dudn = UX(X, Y) * nx + UY(X, Y) * ny
        gap = U(X, Y) - G(X, Y)
        assert gap >= -1e-12 and dudn >= -1e-12 and abs(gap * dudn) < 1e-12, (p["name"], th, gap, dudn)
        if L(X, Y) > 0:
            n_contact += 1
        else:
            eps = 1e-4
            d = lambda s: UX(X + s * nx, Y + s * ny) * nx + UY(X + s * nx, Y + s * ny) * ny
            unn.append((d(eps) - d(-eps)) / (2 * eps))
    print(f"{p['name']}: contact on {n_contact}/200 rays; free part: d2u/dn2 in [{min(unn):.3f}, {max(unn):.3f}], "
          f"mean |d2u/dn2| {sum(abs(v) for v in unn) / len(unn):.3f}")


def toml_value(v):
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, list):
        return "[" + ", ".join(str(a) for a in v) + "]"
    return str(v)


def write_toml(p, e):
    geometry = "\n".join(f"{k} = {toml_value(v)}" for k, v in p["geometry"].items())
    text = f"""# A manufactured Signorini solution on a {p['name']} (generated by tests/convergence/manufactured.py):
# u = v + ρ·(A(ℓ⁺)³ − ∇v·∇ρ)/D with γ = {{ρ = 0}}, so ∂u/∂n = A(ℓ⁺)³/|∇ρ| on γ: contact where
# ℓ > 0, free where ℓ < 0 (there u − g = {B}·ℓ⁻ and ∂²u/∂n² ≠ 0). f = −Δu + c·u.
[domain]
N = 256

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
dir = "results/manufactured_{p['name']}"
"""
    with open(os.path.join(ROOT, "examples", f"manufactured_{p['name']}.toml"), "w") as out:
        out.write(text)


def cxx_function(name, expr, parameters):
    """An inline C++ function `name(parameters)` of expr, common subexpressions as locals t0, t1, …"""
    printer = CxxPrinter()
    subs, (main,) = sp.cse(expr, symbols=sp.numbered_symbols("t"), optimizations="basic")
    return ([f"inline double {name}({parameters}) {{"]
            + [f"  const double {printer.doprint(s)} = {printer.doprint(v)};" for s, v in subs]
            + [f"  return {printer.doprint(main)};", "}"])


def write_cxx(items):
    printer = CxxPrinter()
    lines = ["#pragma once",
             "// Generated by tests/convergence/manufactured.py: do not edit. Manufactured Signorini solutions",
             "// (see that file): f = −Δu + c·u, u, ∇u and the obstacle g, on a circle, a rotated ellipse and a star.",
             "#include <algorithm>", "#include <cmath>", "#include <memory>", "#include <string>", "",
             '#include "fictus/solve/problem.hpp"', '#include "fictus/io/expression.hpp"', '#include "fictus/boundary/shapes.hpp"', "",
             "namespace manufactured {", "",
             "/// max(0, s)^n for n = 1, 2, 3.",
             "inline double pos(double s, int n) { const double p = std::max(0.0, s); return n == 1 ? p : n == 2 ? p * p : p * p * p; }",
             ""]
    for p, e in items:
        name = p["name"]
        lines.append(f"namespace {name} {{")
        for key in ("u", "ux", "uy", "f", "g"):
            lines += cxx_function(key, e[key], "double x, double y")
        lines.append(f"}}  // namespace {name}")
        lines.append("")
    lines.append("struct Problem { std::string name; fictus::Problem problem; };")
    lines.append("")
    lines.append("/// The three problems on the unit box, c = " + str(C) + ", N cells.")
    lines.append("inline std::vector<Problem> all(int N) {")
    lines.append("  std::vector<Problem> out;")
    for p, _ in items:
        name, geo = p["name"], p["geometry"]
        if geo["shape"] == "circle":
            curve = f"std::make_shared<fictus::Ellipse>(fictus::Point2{{0.5, 0.5}}, {geo['radius']}, {geo['radius']})"
        elif geo["shape"] == "ellipse":
            curve = (f"std::make_shared<fictus::Ellipse>(fictus::Point2{{0.5, 0.5}}, {geo['semi_axes'][0]}, "
                     f"{geo['semi_axes'][1]}, {geo['angle']})")
        else:
            curve = (f"std::make_shared<fictus::StarCurve>(fictus::Point2{{0.5, 0.5}}, "
                     f"[r = fictus::Expression(\"{geo['r']}\", {{\"t\"}}, \"geometry.r\")](double t) {{ return r({{t}}); }})")
        lines += ["  {", "    fictus::Problem p;", f'    p.name = "manufactured_{name}";', "    p.N = N;",
                  f"    p.c = {C};", f"    p.gamma = {curve};", f"    p.f = {name}::f;", f"    p.g = {name}::g;",
                  f"    p.exact = {name}::u;",
                  f"    p.exact_gradient = [](double x, double y) {{ return fictus::Point2{{{name}::ux(x, y), {name}::uy(x, y)}}; }};",
                  f'    out.push_back({{"{name}", p}});', "  }"]
    lines += ["  return out;", "}", "", "}  // namespace manufactured", ""]
    with open(os.path.join(ROOT, "tests", "convergence", "manufactured_solutions.hpp"), "w") as out:
        out.write("\n".join(lines))


def main():
    items = []
    for p in problems():
        e = build(p)
        check(p, e)
        write_toml(p, e)
        items.append((p, e))
    write_cxx(items)


if __name__ == "__main__":
    main()
