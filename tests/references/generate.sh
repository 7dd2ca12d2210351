#!/usr/bin/env bash
# Regenerates the fitted-mesh reference solutions ellipse.json, star.json,
# peanut.json and tips.json in this folder with FreeFEM (signorini.edp: see
# the comments there for the discretisation, the active-set solver and how
# convergence is judged).  Usage: ./generate.sh [ellipse|star|peanut|tips ...]
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
[ ${#problems[@]} -eq 0 ] && problems=(ellipse star peanut tips)
[ "${MIXED:-0}" = only ] || [ "${AXISYM:-0}" = only ] || [ "${PEANUT:-0}" = only ] && problems=()
for p in ${problems[@]+"${problems[@]}"}; do
  echo "== $p (log: $LOGDIR/$p.log)"
  FreeFem++ -nw -v 0 signorini.edp -problem "$p" -out "$p.json" -pkg "$pkg" > "$LOGDIR/$p.log" 2>&1
  grep -E '^LEVEL' "$LOGDIR/$p.log"
done

# 3-D reference (ellipsoid3d.json, problem ellipsoid3d.toml): P2 on curved
# elements fitted exactly to the ellipsoid (see the comments at the top of
# signorini3d.edp).  Not run by default; regenerate with
#   GEN3D=1 ./generate.sh
# The levels are m = 4,6,8 cells per half axis of the reference cube
# (about 4 minutes of CPU on one core, under 1 GiB).  m = 12 (117649 dofs)
# fails: UMFPACK returns a zero solution (the script stops there).
if [ "${GEN3D:-0}" = 1 ]; then
  echo "== ellipsoid3d (log: $LOGDIR/ellipsoid3d.log)"
  FreeFem++ -nw -v 0 signorini3d.edp -levels 4,6,8 -out ellipsoid3d.json -pkg "$pkg" > "$LOGDIR/ellipsoid3d.log" 2>&1
  grep -E '^LEVEL' "$LOGDIR/ellipsoid3d.log"
fi

# Axisymmetric 3-D reference (spheroid3d.json, problem spheroid3d.toml): the
# prolate spheroid with an oblique axis solved as a 2-D problem in the
# meridian half-plane (weight rho in every integral), P2 on a bamg mesh fitted
# to the meridian ellipse, as signorini.edp (see the comments at the top of
# signorini_axisym.edp).  Not run by default; regenerate with
#   AXISYM=1 ./generate.sh        (after the problems above)
#   AXISYM=only ./generate.sh     (only this one)
# Levels 0..5 (1406980 P2 dofs on the last): about 4 minutes of CPU on one
# core, 3.4 GiB of memory (the last level alone: 3 minutes; a level 6 would
# need about 4 times as much).  Sanity test of the weak form (pure Neumann
# problems with a known solution, no file written):
#   FreeFem++ -nw -v 0 signorini_axisym.edp -test 2 -nlev 4 | grep TEST
if [ "${AXISYM:-0}" != 0 ]; then
  echo "== spheroid3d (log: $LOGDIR/spheroid3d.log)"
  FreeFem++ -nw -v 0 signorini_axisym.edp -nlev 6 -out spheroid3d.json -pkg "$pkg" > "$LOGDIR/spheroid3d.log" 2>&1
  grep -E '^LEVEL' "$LOGDIR/spheroid3d.log"
fi

# Axisymmetric 3-D reference, not convex (peanut3d.json, problem peanut3d.toml): the
# same script with -shape peanut (the meridian a Cassini oval, polar angle as the
# arc's parameter; two contact bands, four contact circles, three of them where
# gamma is concave along its meridian).  Not run by default; regenerate with
#   PEANUT=1 ./generate.sh        (after the problems above)
#   PEANUT=only ./generate.sh     (only this one)
# Levels 0..5 (1007706 P2 dofs on the last): 15 minutes of CPU on one core (the
# last level alone: 10), under 1 GiB of memory.
if [ "${PEANUT:-0}" != 0 ]; then
  echo "== peanut3d (log: $LOGDIR/peanut3d.log)"
  FreeFem++ -nw -v 0 signorini_axisym.edp -shape peanut -nlev 6 -out peanut3d.json -pkg "$pkg" > "$LOGDIR/peanut3d.log" 2>&1
  grep -E '^LEVEL' "$LOGDIR/peanut3d.log"
fi

# Mixed Dirichlet/Neumann/Signorini conditions (peanut_mixed.json and
# ellipsoid3d_mixed.json, problems peanut_mixed.toml and ellipsoid3d_mixed.toml):
# signorini_mixed.edp (2-D, as signorini.edp with the junctions of the parts as
# mesh vertices and the mesh graded towards them) and signorini3d_mixed.edp
# (3-D, as signorini3d.edp with the parts the images of two cube faces, nodes
# graded towards the faces, CG instead of UMFPACK; levels m = 4,6,8,12,16).
# Not run by default; regenerate with
#   MIXED=1 ./generate.sh        (after the problems above)
#   MIXED=only ./generate.sh     (only these two)
# Measured (one core each): peanut_mixed 40 minutes (1798 s of CPU, 2.8 GiB of
# memory, 1201849 P2 dofs on the last level); ellipsoid3d_mixed 29 minutes
# (0.45 GB, 274625 P2 dofs on the last level, m = 16: 18 of the 29 minutes).
if [ "${MIXED:-0}" != 0 ]; then
  echo "== peanut_mixed (log: $LOGDIR/peanut_mixed.log)"
  FreeFem++ -nw -v 0 signorini_mixed.edp -problem peanut_mixed -out peanut_mixed.json -pkg "$pkg" > "$LOGDIR/peanut_mixed.log" 2>&1
  grep -E '^LEVEL' "$LOGDIR/peanut_mixed.log"
  echo "== ellipsoid3d_mixed (log: $LOGDIR/ellipsoid3d_mixed.log)"
  FreeFem++ -nw -v 0 signorini3d_mixed.edp -levels 4,6,8,12,16 -out ellipsoid3d_mixed.json -pkg "$pkg" > "$LOGDIR/ellipsoid3d_mixed.log" 2>&1
  grep -E '^LEVEL' "$LOGDIR/ellipsoid3d_mixed.log"
fi
