#!/usr/bin/env bash
# Regenerates the fitted-mesh reference solutions ellipse.json, star.json and
# peanut.json in this folder with FreeFEM (signorini.edp: see the comments
# there for the discretisation, the active-set solver and how convergence is
# judged).  Usage: ./generate.sh [ellipse|star|peanut ...]
# Each problem takes 15 to 25 minutes on one core (about 1e6 P2 dofs on the
# last level) and up to 3 GiB of memory; the full FreeFEM log of each run
# goes to $LOGDIR (default: a new temporary folder), and its per-level
# summary lines are printed here.
set -euo pipefail
cd "$(dirname "$0")"

if ! command -v FreeFem++ >/dev/null 2>&1; then
  if [ "$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi
  $SUDO apt-get update
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y freefem++
fi

# one thread for the sparse direct solver; the results do not depend on it
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
LOGDIR=${LOGDIR:-$(mktemp -d)}
pkg=$(dpkg-query -W -f='${Version}' freefem++ 2>/dev/null || true)

problems=("$@")
[ ${#problems[@]} -eq 0 ] && problems=(ellipse star peanut)
for p in "${problems[@]}"; do
  echo "== $p (log: $LOGDIR/$p.log)"
  FreeFem++ -nw -v 0 signorini.edp -problem "$p" -out "$p.json" -pkg "$pkg" > "$LOGDIR/$p.log" 2>&1
  grep -E '^LEVEL' "$LOGDIR/$p.log"
done
