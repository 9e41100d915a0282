#!/bin/sh
# test_cli_lowrank2.sh — `phgmg validate --method bt|prbt|phbt` on a small
# sparse lattice (8 x 8 masses, N = 128, bench/lowrank_models.py, COO files):
# each run passes, and its output error e_y (validate's table) is below the
# H-infinity error bound 2 sum_{i>r} sigma_i of BT at the same order (the
# bound of the L2 gain of the error system; written by the bt run into
# NAME.json). Options of the test runs (--dt, --steps) are accepted. A sweep
# (--method bt,prbt,phbt --r 10,12) computes the Gramian factors once (its
# log) and writes the same models as six separate runs (files equal).
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
# a sweep over methods and orders: the Gramian factors computed once (the
# log), the models equal (arrays and model files, byte for byte) to those of
# separate runs
# shellcheck disable=SC2086
"$P" reduce $M --method bt,prbt,phbt --r 10,12 --out "$T/sw" > "$T/sw.txt" 2>&1 ||
  { echo "FAIL: the sweep"; cat "$T/sw.txt"; nfail=$((nfail + 1)); }
n=$(grep -c "Gramian factors: computed" "$T/sw.txt")
[ "$n" -eq 1 ] || { echo "FAIL: the sweep computed the Gramian factors $n times"; cat "$T/sw.txt"; nfail=$((nfail + 1)); }
n=$(grep -c "Gramian factors: reused" "$T/sw.txt")
[ "$n" -eq 5 ] || { echo "FAIL: the sweep reused the factors $n times (5 expected)"; nfail=$((nfail + 1)); }
for m in bt prbt phbt; do
  for r in 10 12; do
    # shellcheck disable=SC2086
    "$P" reduce $M --method $m --r $r --out "$T/one" --name "rom_${m}_r$r" --quiet > /dev/null 2>&1 ||
      { echo "FAIL: reduce --method $m --r $r"; nfail=$((nfail + 1)); continue; }
    for f in .phgmgrom _K.npy _Qh.npy _Bh.npy _V0.npy; do
      cmp -s "$T/sw/rom_${m}_r$r$f" "$T/one/rom_${m}_r$r$f" ||
        { echo "FAIL: $m r = $r: rom_${m}_r$r$f differs between the sweep and a separate run"; nfail=$((nfail + 1)); }
    done
  done
done
if [ "$nfail" -eq 0 ]; then echo "test_cli_lowrank2: all passed"; else echo "test_cli_lowrank2: $nfail failed"; exit 1; fi
