#!/usr/bin/env bash
# Records the hand-made seed cases of the fuzz corpus (each case of the hardening issue, and a few
# that must succeed) with the outcome the given fictus shows. Read the recorded outcomes before
# committing them: a seed must be a clean error naming the key at fault, or a finite success.
# Usage: tests/fuzz/seed_corpus.sh build/apps/fictus
set -euo pipefail
exe=$1
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
bad=$root/tests/bad_inputs
ex=$root/examples
record() { /usr/bin/python3 "$here/fuzz.py" record "$exe" "seed-$1" "${@:2}"; }

# Crashes and undefined behaviour seen before the hardening
record threads_1000000 -- solve --N 64 --threads 1000000
record threads_40000 -- solve --N 64 --threads 40000
record threads_int_max -- solve --N 64 --threads 2147483647
record normal_shift_1e300 -- solve --N 64 --normal_derivative shifted --normal_shift 1e300
record star_nan_between_samples --problem "$here/seeds/star_nan_between_samples.toml" -- solve
record astroid_smooth --problem "$bad/astroid_cusps.toml" -- solve
# Silent wrong answers
record normal_shift_1000 -- solve --N 64 --normal_derivative shifted --normal_shift 1000
for name in square_twice pinched_polygon vertex_on_edge edge_on_edge star_negative_between_samples \
            star_not_closed parametric_not_closed huge_load huge_obstacle exact_nan_inside; do
  record "$name" --problem "$bad/$name.toml" -- solve
done
record x_jump_at_2pi --problem "$here/seeds/x_jump_at_2pi.toml" -- solve
# Resources
record N_100000 -- solve --N 100000
record N_20000_over_max_memory -- solve --N 20000 --max_memory 4
record reproduce_levels_15 -- reproduce --levels 15
# Messages
record parse_not_an_integer -- solve --N abc
record parse_missing_value -- solve --N
record parse_unknown_flag -- solve --bogus 3
record long_expression --problem "$here/seeds/long_expression.toml" -- solve
record zero_area_polygon --problem "$here/seeds/zero_area_polygon.toml" -- solve
record box_1e300 -- solve --N 64 --box 0,1e300,0,1e300
record toml_syntax --problem "$bad/toml_syntax.toml" -- solve
# Successes with finite results
record paper_smooth -- solve --N 128
record paper_nonsmooth_krylov -- solve --N 64 --variant nonsmooth --schur krylov
record star --problem "$ex/star.toml" -- solve
record polygon --problem "$ex/polygon.toml" -- solve --N 96
record manufactured_ellipse --problem "$ex/manufactured_ellipse.toml" -- solve --N 128
record periodic_krylov --problem "$here/seeds/periodic_krylov.toml" -- solve
record parse_flag_then_file --problem "$ex/circle.toml" -- solve --N 128 --variant nonsmooth --files results.json,points.csv
# Found by the fuzzer under UBSan: a semi-axis of 1.8e308 made the curve's extent overflow (NaN cast)
record huge_semi_axis --problem "$here/seeds/huge_semi_axis.toml" -- solve --N 9 --max_memory 1

# Sweeps (found by the fuzzer when sweeps joined it): a turned polygon (its Newton failed while the
# turned curve lost its corners; solves now); an absurd rotation is refused
record sweep_rotated_polygon --problem "$here/seeds/sweep_rotated_polygon.toml" -- sweep --rotate 0,1.0
record sweep_rotate_1e300 --problem "$here/seeds/sweep_rotate_1e300.toml" -- sweep --rotate 1e+300 --normal_shift 1
# Mixed conditions
record mixed_heating --problem "$ex/mixed_heating.toml" -- solve --N 128
record mixed_jump --problem "$root/tests/inputs/mixed_jump.toml" -- solve
record mixed_overlap --problem "$bad/conditions_overlap.toml" -- solve
