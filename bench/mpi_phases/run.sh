#!/bin/sh
# The measurements of bench/README.md ("The distributed offline phase:
# scaling model"), run once at low priority: sh bench/mpi_phases/run.sh OUTDIR
# (from the repository's root, after make build/bench_mpi_phases), then
#   /usr/bin/python3 bench/mpi_scaling.py OUTDIR/p*.json --same OUTDIR/chain_p2_n50000.json OUTDIR/chain_p2_n200000.json
set -e
OUT=${1:-build/scal}
mkdir -p "$OUT"
M="mpirun --oversubscribe"
if [ "$(id -u)" = 0 ]; then M="$M --allow-run-as-root"; fi
B=./build/bench_mpi_phases
T="$OUT/time.txt"
: > "$T"
for n in 25000 100000; do
  for p in 1 2; do
    /usr/bin/time -f "P=$p nloc=$n user %U sys %S wall %e maxrss_kb %M" -a -o "$T" nice -n 10 $M -np $p $B --nloc $n --reps 3 > "$OUT/p${p}_n${n}.json"
  done
done
for p in 3 4; do
  /usr/bin/time -f "P=$p nloc=25000 user %U sys %S wall %e maxrss_kb %M" -a -o "$T" nice -n 10 $M -np $p $B --nloc 25000 --reps 3 > "$OUT/p${p}_n25000.json"
done
for n in 50000 200000; do
  /usr/bin/time -f "chain P=2 nloc=$n user %U sys %S wall %e" -a -o "$T" nice -n 10 $M -np 2 $B --lattice chain --nloc $n > "$OUT/chain_p2_n${n}.json"
done
