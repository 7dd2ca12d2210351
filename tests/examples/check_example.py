#!/usr/bin/env python3
"""Checks the results of an example solve: Newton converged, the discrete Signorini conditions hold,
errors below bounds (where an exact solution exists), a non-trivial contact set, and optionally the
same errors as another solve. Usage:
  check_example.py DIR [--max-rel-l2 X] [--max-rel-h1 X] [--max-rel-l2-gamma X] [--compare DIR2] [--mixed]"""
import argparse
import json


def load(folder):
    with open(f"{folder}/results.json") as handle:
        return json.load(handle)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("dir")
    parser.add_argument("--max-rel-l2", type=float)
    parser.add_argument("--max-rel-h1", type=float)
    parser.add_argument("--max-rel-l2-gamma", type=float)
    parser.add_argument("--compare")
    parser.add_argument("--mixed", action="store_true", help="mixed conditions: check the parts of gamma")
    args = parser.parse_args()
    r = load(args.dir)
    echo = r["problem"]  # what was solved: the problem file's geometry and data, or the built-in problem
    assert isinstance(echo["geometry"], str) or "shape" in echo["geometry"], echo
    assert isinstance(echo["data"], str) or {"f", "g"} <= set(echo["data"]), echo
    assert r["newton"]["converged"], r["newton"]
    s = r["signorini"]
    tol = 1e-10  # the Newton systems are solved by dense LU: round-off level
    assert s["min_gap"] >= -tol and s["min_normal_derivative"] >= -tol and s["max_complementarity"] <= tol, s
    n_active, m = r["newton"]["n_active"], r["multipliers"]
    assert 0 < n_active < m, f"contact set is trivial: {n_active} of {m}"
    if args.mixed:  # every part of γ is there, and the Signorini part has contact and free points
        parts = r["conditions"]
        assert all(parts[k]["points"] > 0 for k in ("signorini", "dirichlet", "neumann")), parts
        assert 0 < r["contact"]["points"] < parts["signorini"]["points"], (r["contact"], parts)
        assert not any("conditions.u" in w for w in r["warnings"]), r["warnings"]
    bounds = {"rel_l2_omega": args.max_rel_l2, "rel_h1_omega": args.max_rel_h1, "rel_l2_gamma": args.max_rel_l2_gamma}
    for key, bound in bounds.items():
        if bound is not None:
            assert r["errors"][key] <= bound, f"{key} = {r['errors'][key]:.3e} > {bound:.3e}"
    if args.compare:
        other = load(args.compare)
        for key in ("rel_l2_omega", "rel_h1_omega", "rel_l2_gamma"):
            a, b = r["errors"][key], other["errors"][key]
            assert abs(a - b) <= 1e-6 * abs(b), f"{key}: {a:.12e} vs {b:.12e}"
        assert r["newton"]["iterations"] == other["newton"]["iterations"]
    print(f"{args.dir}: OK ({n_active} of {m} points in contact, {r['newton']['iterations']} Newton steps)")


if __name__ == "__main__":
    main()
