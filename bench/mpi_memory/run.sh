#!/bin/sh
# Peak memory per rank of phgmg_mpi_reduce (GMG-POD r = 20, ECSW, 40
# snapshots) at a fixed global N against a small-N baseline, at P = 1, 2, 4
# (bench/README.md, "Memory per rank of the distributed offline phase").
# From the repository's root, after make build/bench_mpi_memory:
#   sh bench/mpi_memory/run.sh [N [NBASE]]      (defaults 2000000 20000)
# Prints the raw lines of build/bench_mpi_memory, then the table: per P the
# growth above the baseline, peak RSS and the library's peak allocation, and
# its ratio to the one-rank growth divided by P (the acceptance: <= 1.15).
set -e
N=${1:-2000000}
NB=${2:-20000}
M="mpirun --oversubscribe"
if [ "$(id -u)" = 0 ]; then M="$M --allow-run-as-root"; fi
B=./build/bench_mpi_memory
RAW=$(mktemp)
for p in 1 2 4; do
  for n in "$NB" "$N"; do
    nice -n 10 $M -np $p $B --N "$n" | tee -a "$RAW"
  done
done
echo
awk -v N="$N" -v NB="$NB" '
  function val(s, k,   i, a) { for (i = 1; i <= NF; ++i) { split($i, a, "="); if (a[1] == k) return a[2] } return "" }
  { p = val($0, "P"); n = val($0, "N"); rss[p, n] = val($0, "rss_kb"); lib[p, n] = val($0, "lib_b"); t[p, n] = val($0, "time_s"); nd[p, n] = val($0, "nd") }
  END {
    r1 = (rss[1, N] - rss[1, NB]) / 1024; l1 = (lib[1, N] - lib[1, NB]) / 1048576
    printf "N = %d, baseline N = %d; peak RSS = VmHWM, max over the ranks; library = peak bytes held (counting allocator), max over the ranks\n\n", N, NB
    printf "| P | RSS(N) [MB] | RSS(base) [MB] | growth [MB] | growth / (growth_1 / P) | library(N) [MB] | library(base) [MB] | growth [MB] | growth / (growth_1 / P) | points | reduce [s] |\n"
    printf "|---|---|---|---|---|---|---|---|---|---|---|\n"
    for (p = 1; p <= 4; p *= 2) {
      g = (rss[p, N] - rss[p, NB]) / 1024; h = (lib[p, N] - lib[p, NB]) / 1048576
      printf "| %d | %.1f | %.1f | %.1f | %.3f | %.1f | %.1f | %.1f | %.3f | %s | %s |\n", p, rss[p, N] / 1024, rss[p, NB] / 1024, g, g / (r1 / p), lib[p, N] / 1048576, lib[p, NB] / 1048576, h, h / (l1 / p), nd[p, N], t[p, N]
      if (g / (r1 / p) > 1.15 || h / (l1 / p) > 1.15) bad = 1
    }
    printf "\nacceptance (growth per rank within 1.15x of growth_1 / P, RSS and library): %s\n", bad ? "NOT met" : "met"
  }' "$RAW"
rm -f "$RAW"
