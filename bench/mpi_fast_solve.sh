#!/bin/sh
# The fast solve's ranks-against-threads table and the memory per rank (bench/mpi_fast_solve.cpp), on
# this machine: 2-D h = 1/4096 and 3-D N = 256 with 2 threads (serial and slab solver) against 2 ranks;
# then the memory per rank at P = 1, 2, 4 (P = 4 oversubscribed: its times are not the machine's).
#   sh bench/mpi_fast_solve.sh [build] > bench/results/<date>-mpi-fast-solve.md
set -e
B=${1:-build}/bench/fictus_bench_mpi_solve
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
M="mpiexec --oversubscribe --bind-to none -n"
$B --dim 2 --N 64 --repeat 1 --header --path serial | sed -n '1,/^$/p'
echo "## Ranks against threads"
echo
$B --dim 2 --N 64 --repeat 1 --header --path serial | sed -n '/^| path/,$p' | head -2
for case in "2 4096" "3 256"; do
  set -- $case
  $B --dim $1 --N $2 --path serial --threads 2
  $M 1 $B --dim $1 --N $2 --threads 2
  $M 2 $B --dim $1 --N $2 --threads 1
  $B --dim $1 --N $2 --path serial --threads 2 --periodic
  $M 2 $B --dim $1 --N $2 --threads 1 --periodic
done
echo
echo "## Memory per rank"
echo
$B --dim 2 --N 64 --repeat 1 --header --path serial | sed -n '/^| path/,$p' | head -2
for N in 256 384; do
  $B --dim 3 --N $N --path serial --threads 1 --repeat 1
  for P in 1 2 4; do $M $P $B --dim 3 --N $N --threads 1 --repeat 1; done
done
