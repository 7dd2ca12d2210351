#!/usr/bin/env python3
"""Dense against hierarchical Schur storage, one table from the runs' results.json and points.csv.

Usage: compare_schur_storage.py DIR...   (each DIR/o_<N>_<kind> from `fictus solve ... --schur_storage <kind>
--no-condition`: cond(S) is computed with the dense storage only, and would weigh on its total alone)
Prints a markdown table: per N and kind, the phases that differ, the storage, Newton's work, peak memory,
and λ and the contact set against the dense run of the same N.
"""
import csv
import glob
import json
import os
import sys


def load(path):
    with open(os.path.join(path, "results.json")) as f:
        j = json.load(f)
    with open(os.path.join(path, "points.csv")) as f:
        rows = list(csv.DictReader(f))
    return j, [float(r["lambda"]) for r in rows], [r["contact"] for r in rows]


def main():
    runs = {}
    for d in sys.argv[1:]:
        for path in glob.glob(os.path.join(d, "o_*_*")):
            _, n, kind = os.path.basename(path).split("_")
            runs[(int(n), kind)] = load(path)
    print("| N | m | storage | schur [s] | newton [s] | total [s] | Newton steps | fast solves | Krylov its | "
          "LUs | S kept [MiB] | of dense | largest rank | peak [MiB] | max Δλ / max λ | same contact set |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for (n, kind) in sorted(runs, key=lambda k: (k[0], k[1] != "dense")):
        j, lam, contact = runs[(n, kind)]
        dense = runs.get((n, "dense"))
        s = j["inner"]["schur_storage"]
        t = j["timings"]
        diff, same = "", ""
        if dense and kind != "dense":
            top = max(abs(x) for x in dense[1])
            diff = "%.1e" % (max(abs(a - b) for a, b in zip(lam, dense[1])) / top)
            same = "yes" if contact == dense[2] else "no"
        print("| %d | %d | %s | %.1f | %.1f | %.1f | %d | %d | %d | %d | %.1f | %.0f %% | %d | %.0f | %s | %s |" % (
            n, j["multipliers"]["m"] if isinstance(j["multipliers"], dict) else j["multipliers"], kind,
            t["schur"], t["newton"], t["total"], j["newton"]["iterations"], j["inner"]["fast_solves"],
            j["inner"]["krylov_iterations"], j["inner"]["factorizations"], s["bytes"] / 2**20,
            100 * s["compression"], s["largest_rank"], j["peak_memory_bytes"] / 2**20, diff, same))


if __name__ == "__main__":
    main()
