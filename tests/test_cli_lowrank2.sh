#!/bin/sh
# test_cli_lowrank2.sh — `phgmg validate --method bt|prbt|phbt` on a small
# sparse lattice (8 x 8 masses, N = 128, bench/lowrank_models.py, COO files):
# each run passes, and its output error e_y (validate's table) is below the
# H-infinity error bound 2 sum_{i>r} sigma_i of BT at the same order (the
# bound of the L2 gain of the error system; written by the bt run into
# NAME.json). Options of the test runs (--dt, --steps) are accepted.
# Usage: sh tests/test_cli_lowrank2.sh build/phgmg      (from the repository root)
# Needs NumPy in /usr/bin/python3 (skipped with a note otherwise).
set -u
P=${1:-build/phgmg}
case "$P" in /*) ;; *) P="$PWD/$P" ;; esac
PY=/usr/bin/python3
ROOT=$PWD
T=$(mktemp -d "${TMPDIR:-/tmp}/phgmg_lowrank2.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT INT TERM
[ -x "$P" ] || { echo "test_cli_lowrank2: $P is not an executable (build it first)"; exit 1; }
if ! "$PY" -c 'import numpy' 2>/dev/null; then
  echo "test_cli_lowrank2: skipped ($PY has no NumPy)"
  exit 0
fi
nfail=0
D="$T/lattice"
"$PY" "$ROOT/bench/lowrank_models.py" "$D" lattice 8 > /dev/null || { echo "FAIL: the model"; exit 1; }
M="--J-coo $D/J.npy --R-coo $D/R.npy --Q-coo $D/Q.npy --B $D/B.npy"
for m in bt prbt phbt; do
  # shellcheck disable=SC2086
  "$P" validate $M --method $m --r 12 --out "$T/o" --name $m --dt 0.1 --steps 300 > "$T/$m.txt" 2>&1
  rc=$?
  [ $rc -eq 0 ] || { echo "FAIL: validate --method $m: exit $rc"; cat "$T/$m.txt"; nfail=$((nfail + 1)); continue; }
  grep -q "^validate: passed" "$T/$m.txt" || { echo "FAIL: validate --method $m did not pass"; nfail=$((nfail + 1)); }
done
bound=$(sed -n 's/.*"error_bound": \([0-9.eE+-]*\).*/\1/p' "$T/o/bt.json" 2>/dev/null | head -1)
[ -n "$bound" ] || { echo "FAIL: no error_bound in bt.json"; nfail=$((nfail + 1)); bound=0; }
for m in bt prbt phbt; do
  ey=$(awk '$1 == "sin" { print $3 }' "$T/$m.txt")
  [ -n "$ey" ] || { echo "FAIL: $m: no e_y in validate's table"; nfail=$((nfail + 1)); continue; }
  awk -v e="$ey" -v b="$bound" 'BEGIN { exit !(e + 0 > 0 && e + 0 < b + 0) }' ||
    { echo "FAIL: $m: e_y $ey not below the BT bound $bound"; nfail=$((nfail + 1)); }
  echo "validate --method $m --r 12: e_y $ey (BT bound $bound)"
done
if [ "$nfail" -eq 0 ]; then echo "test_cli_lowrank2: all passed"; else echo "test_cli_lowrank2: $nfail failed"; exit 1; fi
