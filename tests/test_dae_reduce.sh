#!/bin/sh
# test_dae_reduce.sh — reduce and validate of a sparse index-one model given
# as COO files (examples/phgmg_cli.c; manual 1.8): the condensation to the
# differential states is sparse, with no limit on the algebraic lines.
#
# Usage: sh tests/test_dae_reduce.sh build/phgmg      (from the repository root)
#
# 1. A 41 x 41 RLC grid (bench/rlc_grid.py: N = 8 241, 4 120 algebraic lines,
#    beyond the dense condensation's 4 096; rows and states scrambled):
#    validate --simulate --method gmg-pod,sp1 --r 10,20 passes, the log names
#    the condensation (4 121 differential states), and each method's output
#    error e_y on the training input falls from r = 10 to r = 20 (at least
#    100 times: measured about 1e5).
# 2. The same grid with port 1 on a main node without capacitor: its condensed
#    column of B vanishes. gmg-pod refuses, naming port 1 and sp1/sp2 (exit 1,
#    nothing written); sp1 passes validate with e_y falling with r.
# Skipped with a note if /usr/bin/python3 has no NumPy and SciPy.
set -u
P=${1:-build/phgmg}
case "$P" in /*) ;; *) P="$PWD/$P" ;; esac
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PY=/usr/bin/python3
T=$(mktemp -d "${TMPDIR:-/tmp}/phgmg_daer.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT INT TERM
npass=0
nfail=0
pass() { npass=$((npass + 1)); }
bad() { echo "FAIL: $*"; nfail=$((nfail + 1)); }
[ -x "$P" ] || { echo "test_dae_reduce: $P is not an executable (build it first)"; exit 1; }
if ! $PY -c 'import numpy, scipy.sparse' >/dev/null 2>&1; then
  echo "test_dae_reduce: skipped (no NumPy/SciPy for $PY)"
  exit 0
fi
cd "$T" || exit 1
mkdir g p || exit 1
$PY "$ROOT/bench/rlc_grid.py" g --n 41 --steps 600 > g.txt || { echo "FAIL: rlc_grid.py"; exit 1; }
$PY "$ROOT/bench/rlc_grid.py" p --n 41 --steps 600 --port-on-constraint > /dev/null || { echo "FAIL: rlc_grid.py"; exit 1; }
grep -q "algebraic = 4120" g.txt && pass || bad "the grid has 4120 algebraic lines: $(cat g.txt)"
coo() { echo "--J-coo $1/J.npy --R-coo $1/R.npy --Q-coo $1/Q.npy --E-coo $1/E.npy --B $1/B.npy --simulate --steps 600 --dt 0.02 --input $1/chirp.npy"; }

# e_y of the sweep's models (NAME_sweep.json): method r e_y per line
ey() {
  $PY - "$1" <<'PYEOF'
import json, sys
for m in json.load(open(sys.argv[1]))["models"]:
    print(m["method"], m["r"], m["tests"][0]["e_y"])
PYEOF
}
falls() {   # falls FILE METHOD: e_y(r = 20) < 1e-2 e_y(r = 10)
  awk -v m="$2" '$1 == m && $2 == 10 { a = $3 } $1 == m && $2 == 20 { b = $3 } END { exit !(a > 0 && b < 0.01 * a) }' "$1"
}

# 1. beyond 4096 algebraic lines: gmg-pod and sp1
$P validate $(coo g) --method gmg-pod,sp1 --r 10,20 --out o1 > v1.txt 2>&1
rc=$?
[ $rc -eq 0 ] && pass || { bad "validate of the 41 x 41 grid: exit $rc"; tail -5 v1.txt; }
grep -q "4120 algebraic equations and variables (index one); condensed to N = 4121 differential states" v1.txt \
  && pass || bad "the log names the condensation"
[ -f o1/rom_gmg_pod_r20.phgmgrom ] && [ -f o1/rom_sp1_r10.phgmgrom ] && pass || bad "models written"
ey o1/rom_sweep.json > e1.txt 2>/dev/null || bad "o1/rom_sweep.json"
cat e1.txt
falls e1.txt gmg-pod && pass || bad "gmg-pod: e_y falls with r ($(tr '\n' ' ' < e1.txt))"
falls e1.txt sp1 && pass || bad "sp1: e_y falls with r ($(tr '\n' ' ' < e1.txt))"

# 2. a port that acts only through a constraint
$P reduce $(coo p) --method gmg-pod --r 10 --out o2 > v2.txt 2>&1
rc=$?
[ $rc -eq 1 ] && pass || bad "gmg-pod with port 1 on a constraint: exit $rc (expected 1)"
grep -q "port 1 (column 1 of p/B.npy, counted from 0) acts only through a constraint.*use sp1 or sp2" v2.txt \
  && pass || { bad "gmg-pod's refusal names the port"; tail -2 v2.txt; }
[ ! -e o2/rom.phgmgrom ] && pass || bad "nothing written after the refusal"
$P validate $(coo p) --method sp1 --r 10,20 --out o3 > v3.txt 2>&1
rc=$?
[ $rc -eq 0 ] && pass || { bad "sp1 with port 1 on a constraint: exit $rc"; tail -5 v3.txt; }
ey o3/rom_sweep.json > e3.txt 2>/dev/null || bad "o3/rom_sweep.json"
cat e3.txt
falls e3.txt sp1 && pass || bad "sp1 (port on a constraint): e_y falls with r ($(tr '\n' ' ' < e3.txt))"

echo "test_dae_reduce: $npass passed, $nfail failed"
[ $nfail -eq 0 ]
