#!/usr/bin/env python3
"""Checks a results.json written by `fictus solve` against the documented keys and the
discrete Signorini conditions. Usage: check_results.py DIR"""
import json
import math
import sys

REQUIRED = {
    "version": str, "options": dict, "grid": dict, "multipliers": int, "newton": dict,
    "inner": dict, "timings": dict, "signorini": dict, "errors": dict, "peak_memory_bytes": int,
    "contact": dict, "dim": int, "box": list, "boundary": dict, "alpha": float, "warnings": list,
}


def main(folder):
    with open(f"{folder}/results.json") as handle:
        results = json.load(handle)
    for key, kind in REQUIRED.items():
        assert key in results, f"missing key {key}"
        assert isinstance(results[key], kind), f"{key} is not {kind.__name__}"
    assert "condition_number" in results
    assert isinstance(results["commit"], str) and results["commit"], "commit"
    assert results["problem"]["name"], "problem.name"
    assert "geometry" in results["problem"] and "data" in results["problem"], "problem echo"
    for key in ("N", "h", "n_nodes", "n_unknowns"):
        assert key in results["grid"], f"grid.{key} missing"
    n = results["grid"]["N"]
    assert results["grid"]["n_nodes"] == (n + 1) ** 2
    assert results["grid"]["n_unknowns"] == (n - 1) ** 2
    assert results["newton"]["converged"] is True
    assert 1 <= results["newton"]["iterations"] <= 20
    assert results["inner"]["fast_solves"] >= 2
    assert results["timings"]["total"] > 0
    signorini = results["signorini"]
    assert signorini["min_gap"] >= -1e-10, signorini
    assert signorini["min_normal_derivative"] >= -1e-10, signorini
    assert signorini["max_complementarity"] <= 1e-10, signorini
    contact = results["contact"]
    assert contact["points"] == results["newton"]["n_active"], contact
    assert contact["force"] > 0 and abs(contact["min_gap"]) < 1e-10 and contact["max_gap"] > 0, contact
    for key in ("l2_omega", "h1_omega", "h1semi_omega", "l2_gamma",
                "rel_l2_omega", "rel_h1_omega", "rel_l2_gamma"):
        value = results["errors"][key]
        assert math.isfinite(value) and 0 < value < 1, f"errors.{key} = {value}"
    with open(f"{folder}/points.csv") as handle:
        rows = handle.read().strip().splitlines()
    assert rows[0] == "i,s,x,y,nx,ny,weight,g,u,dudn,lambda,contact,condition,Gamma_x,Gamma_y,dudn_check"
    columns = [row.split(",") for row in rows[1:]]
    arcs = [float(c[6]) for c in columns]
    assert math.isclose(sum(arcs), results["boundary"]["measure"], rel_tol=1e-9), (sum(arcs), results["boundary"])
    force = sum(float(c[9]) * float(c[6]) for c in columns if c[11] == "1")
    measure = sum(float(c[6]) for c in columns if c[11] == "1")
    assert math.isclose(force, contact["force_patches"], rel_tol=1e-9), (force, contact["force_patches"])
    # The force from the domain identity, c∫û − ∫f, and the readings' patch sum: two rules for one number.
    domain = results["domain"]
    assert contact["force_rule"] == "domain" and contact["force"] == domain["flux"], (contact, domain)
    c = results["options"]["c"]
    assert math.isclose(domain["flux"], c * domain["integral_u"] - domain["integral_f"], rel_tol=1e-12, abs_tol=1e-15)
    assert math.isclose(contact["force"], contact["force_patches"], rel_tol=0.05), contact
    energy = 0.5 * domain["integral_grad2"] + 0.5 * c * domain["integral_u2"] - domain["integral_fu"]
    assert math.isclose(domain["energy"], energy, rel_tol=1e-12, abs_tol=1e-15), domain
    estimate = results["estimate"]
    assert estimate["N"] == n // 2 and estimate["seconds"] > 0, estimate
    for key in ("l2_omega", "rel_l2_omega", "force", "measure", "energy", "integral_u"):
        assert math.isfinite(estimate[key]) and estimate[key] >= 0, f"estimate.{key} = {estimate[key]}"
    assert math.isclose(measure, contact["measure_points"], rel_tol=1e-9), (measure, contact["measure_points"])
    # The contact ends located inside the parts move the measure by less than a spacing per end.
    ends = contact["boundary"]
    assert len(ends) >= 2 and all(len(p) == 2 for p in ends), ends
    spacing = results["boundary"]["spacing"]
    assert abs(contact["measure"] - contact["measure_points"]) <= 0.5 * spacing * len(ends), contact
    assert len(rows) == results["multipliers"] + 1
    print("results.json and points.csv OK")


if __name__ == "__main__":
    main(sys.argv[1])
