#!/bin/sh
# test_stream.sh — `phgmg reduce --stream`: snapshots streamed into an
# incremental POD instead of stored (the time stepper's states with
# --simulate, column blocks of the files with --X).
#
# Usage: sh tests/test_stream.sh build/phgmg      (from the repository root)
#
# On a scrambled 2-D mass-spring lattice (bench/lattice.py, 10 x 20 masses,
# N = 400, sparse coordinate input):
# 1. gmg-pod r = 20 and sp1 r = 16 from --simulate (600 steps): the streamed
#    model's simulate-rom outputs equal the stored run's to 1e-10 relative,
#    and the log states the streamed POD;
# 2. gmg-pod from --X (the same states, in Fortran and in C order): the
#    streamed models equal the stored one's outputs to 1e-10;
# 3. --stream with a method that needs the snapshots themselves (gmg-qm) or
#    with --save-snapshots: a usage error (exit 2) naming the reason.
# Skipped (with a note) if /usr/bin/python3 has no NumPy.
set -u
P=${1:-build/phgmg}
case "$P" in /*) ;; *) P="$PWD/$P" ;; esac
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PY=/usr/bin/python3
T=$(mktemp -d "${TMPDIR:-/tmp}/phgmg_stream.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT INT TERM
npass=0
nfail=0
pass() { npass=$((npass + 1)); }
bad() { echo "FAIL: $*"; nfail=$((nfail + 1)); }
[ -x "$P" ] || { echo "test_stream: $P is not an executable (build it first)"; exit 1; }
cd "$T" || exit 1
if ! "$PY" -c 'import numpy' 2>/dev/null; then
  echo "test_stream: skipped ($PY has no NumPy)"
  exit 0
fi
"$PY" "$ROOT/bench/lattice.py" lat 10 20 >/dev/null || bad "lattice.py failed"
SYS="--J-coo lat/J.npy --R-coo lat/R.npy --Q-coo lat/Q.npy --B lat/B.npy"
SIM="--simulate --steps 600 --dt 0.1"

# the outputs of two models' simulate-rom runs agree to 1e-10 relative
same_y() {
  "$P" simulate-rom --model "$1/rom.phgmgrom" --out "$1/y.npy" --steps 800 --input sin --quiet >/dev/null 2>&1 &&
  "$P" simulate-rom --model "$2/rom.phgmgrom" --out "$2/y.npy" --steps 800 --input sin --quiet >/dev/null 2>&1 &&
  "$PY" - "$1/y.npy" "$2/y.npy" <<'PYEOF'
import sys, numpy as np
a, b = np.load(sys.argv[1]), np.load(sys.argv[2])
assert a.shape == b.shape and np.abs(a).max() > 1e-3, (a.shape, b.shape)
e = np.abs(a - b).max() / np.abs(a).max()
assert e <= 1e-10, e
PYEOF
}

# 1. --simulate streamed against stored
for mr in "gmg-pod 20" "sp1 16"; do
  set -- $mr
  "$P" reduce $SYS $SIM --method $1 --r $2 --out in_$1 --quiet >/dev/null 2>err.txt && pass || bad "reduce $1: $(tail -n 2 err.txt)"
  "$P" reduce $SYS $SIM --method $1 --r $2 --out st_$1 --stream >/dev/null 2>err.txt && pass || bad "reduce $1 --stream: $(tail -n 2 err.txt)"
  grep -q "streamed POD: .* modes kept of 601 snapshots" err.txt && pass || bad "$1 --stream: no streamed POD in the log: $(cat err.txt)"
  same_y in_$1 st_$1 && pass || bad "$1: streamed and stored models differ"
done

# 2. --X read in column blocks (Fortran and C order)
"$P" simulate $SYS --steps 600 --dt 0.1 --out yf.npy --states xf.npy --quiet >/dev/null 2>err.txt && pass || bad "simulate: $(cat err.txt)"
"$PY" -c "import numpy as np; np.save('xc.npy', np.ascontiguousarray(np.load('xf.npy')))" && pass || bad "C-order copy"
"$P" reduce $SYS --X xf.npy --dt 0.1 --method gmg-pod --r 20 --out xin --quiet >/dev/null 2>err.txt && pass || bad "reduce --X: $(cat err.txt)"
for o in xf xc; do
  "$P" reduce $SYS --X $o.npy --dt 0.1 --method gmg-pod --r 20 --out xs_$o --stream >/dev/null 2>err.txt && pass || bad "reduce --X $o --stream: $(tail -n 2 err.txt)"
  grep -q "streaming $o.npy: 601 snapshots in blocks" err.txt && pass || bad "--X $o --stream: not read in blocks: $(cat err.txt)"
  same_y xin xs_$o && pass || bad "--X $o.npy: streamed and stored models differ"
done

# 3. a list of orders from one stream: each model equals the stored run's
"$P" reduce $SYS $SIM --method gmg-pod --r 16,20 --out sw --stream >/dev/null 2>err.txt && pass || bad "reduce --r 16,20 --stream: $(tail -n 2 err.txt)"
[ "$(grep -c "streamed POD: " err.txt)" -eq 1 ] && pass || bad "--r 16,20 --stream: not one stream: $(cat err.txt)"
mkdir -p sw20 && cp sw/rom_gmg_pod_r20.phgmgrom sw20/rom.phgmgrom && same_y in_gmg-pod sw20 && pass || bad "--r 16,20 --stream: the r = 20 model differs from the stored run's"
"$P" reduce $SYS $SIM --method gmg-pod,sp1 --r 20 --out e0 --stream >/dev/null 2>err.txt
[ $? -eq 2 ] && grep -q -- "--stream: one method per run" err.txt && pass || bad "--stream with two methods: $(cat err.txt)"

# 4. what the stream cannot serve: usage errors
"$P" reduce $SYS $SIM --method gmg-qm --r 20 --lambda 1e-3 --out e1 --stream >/dev/null 2>err.txt
[ $? -eq 2 ] && grep -q -- "--stream: not with --method gmg-qm" err.txt && pass || bad "--stream gmg-qm: $(cat err.txt)"
"$P" reduce $SYS $SIM --method gmg-pod --r 20 --save-snapshots --out e2 --stream >/dev/null 2>err.txt
[ $? -eq 2 ] && grep -q -- "--stream: not with --save-snapshots" err.txt && pass || bad "--stream --save-snapshots: $(cat err.txt)"

echo "test_stream: $npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
