#!/usr/bin/env python3
"""Other rules for the error estimate, tried offline on the runs of fictus_bench_estimate.

    RAW=runs.json build/bench/fictus_bench_estimate      # every run's numbers
    bench/estimate_variants.py runs.json

For the force, ∫û, the energy and the contact measure, how many runs each rule puts within a factor 3 of
the true error:
  - two grids with the order p (fictus's rule: p = 2, the measure's p = 1), for p = 0.5 … 3;
  - three grids (N/4, N/2, N) with the order observed from the two differences, clamped to [1, 3] (the
    nominal p where the differences change sign);
  - a safeguard against a lucky small difference: the larger of the two-grid estimate and the difference
    from N/4 to N/2 scaled down by 2^p;
  - three grids used only as a flag: the runs whose two differences agree in sign and shrink by 2 … 8,
    against the others.
The three-grid rules need the runs at N/2 and N/4 of the same case (2-D: the two finest N of each case).
"""
import collections
import json
import math
import sys

QUANTITIES = ["l2", "force", "integral_u", "energy", "measure"]
ORDER = {"force": 2, "integral_u": 2, "energy": 2, "measure": 1}


def within_3(estimate, truth):
    return truth is not None and truth != 0 and 1 / 3 <= estimate / abs(truth) <= 3


def main(paths):
    runs = [r for p in paths for r in json.load(open(p))]
    cases = collections.defaultdict(dict)
    for r in runs:
        cases[(r["problem"], r["variant"])][r["N"]] = r
    print("| quantity | dim | rule | runs | within 3× |")
    print("|---|---|---|---|---|")
    for q in ORDER:
        k = QUANTITIES.index(q)
        p0 = ORDER[q]
        for dim in (2, 3):
            counts = collections.defaultdict(lambda: [0, 0])
            for seq in cases.values():
                for N, r in seq.items():
                    e, t = r["estimated"][k], r["truth"][k]
                    if r["dim"] != dim or e is None or t is None or t == 0:
                        continue
                    difference = e * (2**p0 - 1)  # |Q_N − Q_{N/2}|
                    for p in (0.5, 1, 1.5, 2, 2.5, 3):
                        c = counts["two grids, p = %g" % p]
                        c[0] += within_3(difference / (2**p - 1), t)
                        c[1] += 1
                    if N // 2 not in seq or N // 4 not in seq:
                        continue
                    v = lambda n: seq[n]["values"][k]
                    d2, d1 = v(N) - v(N // 2), v(N // 2) - v(N // 4)
                    observed = math.log2(abs(d1) / abs(d2)) if d1 * d2 > 0 else p0
                    rules = {
                        "two grids, p = %g (runs with N/4)" % p0: abs(d2) / (2**p0 - 1),
                        "three grids, observed order in [1, 3]": abs(d2) / (2 ** min(max(observed, 1), 3) - 1),
                        "safeguard": max(abs(d2) / (2**p0 - 1), abs(d1) / (2**p0 - 1) / 2**p0),
                    }
                    for name, estimate in rules.items():
                        counts[name][0] += within_3(estimate, t)
                        counts[name][1] += 1
                    consistent = d1 * d2 > 0 and 2 <= abs(d1 / d2) <= 8
                    c = counts["flag: differences consistent" if consistent else "flag: not consistent"]
                    c[0] += within_3(abs(d2) / (2**p0 - 1), t)
                    c[1] += 1
            for name, (inside, total) in counts.items():
                print("| %s | %d | %s | %d | %d |" % (q, dim, name, total, inside))


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: estimate_variants.py RUNS.json...")
    main(sys.argv[1:])
