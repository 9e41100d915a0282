#!/bin/sh
# test_cli_lowrank.sh — reduce --method bt|prbt|phbt (balancing, no snapshots)
# through the command line, against an independent computation (SciPy):
# tests/check_cli_lowrank.py (what it checks is described there) on a small
# lattice and heat model, as COO files (the low-rank solvers) and dense .npy
# files (the dense solvers); and the log of a low-rank run (the solver, the
# Gramian ranks and residuals, the bound).
# Usage: sh tests/test_cli_lowrank.sh build/phgmg      (from the repository root)
# Needs NumPy and SciPy in /usr/bin/python3 (skipped with a note otherwise).
set -u
P=${1:-build/phgmg}
case "$P" in /*) ;; *) P="$PWD/$P" ;; esac
PY=/usr/bin/python3
ROOT=$PWD
T=$(mktemp -d "${TMPDIR:-/tmp}/phgmg_lowrank.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT INT TERM
[ -x "$P" ] || { echo "test_cli_lowrank: $P is not an executable (build it first)"; exit 1; }
if ! "$PY" -c 'import numpy, scipy' 2>/dev/null; then
  echo "test_cli_lowrank: skipped ($PY has no NumPy/SciPy)"
  exit 0
fi
nfail=0
"$PY" "$ROOT/tests/check_cli_lowrank.py" "$P" "$T" > "$T/check.txt" 2>&1 || { cat "$T/check.txt"; nfail=$((nfail + 1)); }
D="$T/lattice"
"$P" reduce --J-coo "$D/J.npy" --R-coo "$D/R.npy" --Q-coo "$D/Q.npy" --B "$D/B.npy" --method bt --r 8 \
  --out "$T/log" --name bt > "$T/log.txt" 2>&1 || { echo "FAIL: bt run"; nfail=$((nfail + 1)); }
for w in "reducing: bt, r = 8 (low-rank, sparse solvers)" "Gramian factor ranks" "Lyapunov residuals" \
         "H-infinity error bound"; do
  grep -F -q "$w" "$T/log.txt" || { echo "FAIL: the log lacks '$w'"; cat "$T/log.txt"; nfail=$((nfail + 1)); }
done
grep -q '"gramian_rank": \[[1-9]' "$T/log/bt.json" || { echo "FAIL: bt.json lacks the Gramian ranks"; nfail=$((nfail + 1)); }
if [ "$nfail" -eq 0 ]; then echo "test_cli_lowrank: all passed"; else echo "test_cli_lowrank: $nfail failed"; exit 1; fi
