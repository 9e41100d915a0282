#!/bin/sh
# test_simulate.sh — `phgmg simulate` (the full model) on a scrambled 2-D lattice.
#
# Usage: sh tests/test_simulate.sh build/phgmg      (from the repository root)
#
# 1. A scrambled 2-D mass-spring lattice (bench/lattice.py, 10 x 20 masses,
#    N = 400, sparse coordinate input): `phgmg simulate` (1000 GL3 steps, dt =
#    0.1, u = 0.1 sin t) names the sparse LU as its stage solver and gives the
#    same output as bench/gl3_scipy.py, the same GL3 steps in SciPy with
#    SuperLU (scipy.sparse.linalg.splu), to 1e-8 relative; --states has the
#    announced shape and its last column reproduces y = B^T Q x.
# 2. The same lattice with the on-site potential cosh (nonlinear, refactored
#    stage matrices): the output agrees with that of the same model given as
#    dense .npy matrices (the dense LU with partial pivoting) to 1e-10 relative.
# 3. Errors: --out naming an input file (refused, the file unchanged), missing
#    options, unknown options.
# Parts that need NumPy/SciPy are skipped (with a note) if /usr/bin/python3 has none.
set -u
P=${1:-build/phgmg}
case "$P" in /*) ;; *) P="$PWD/$P" ;; esac
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PY=/usr/bin/python3
T=$(mktemp -d "${TMPDIR:-/tmp}/phgmg_sim.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT INT TERM
npass=0
nfail=0
pass() { npass=$((npass + 1)); }
bad() { echo "FAIL: $*"; nfail=$((nfail + 1)); }
[ -x "$P" ] || { echo "test_simulate: $P is not an executable (build it first)"; exit 1; }
cd "$T" || exit 1

if ! "$PY" -c 'import numpy, scipy.sparse.linalg' 2>/dev/null; then
  echo "test_simulate: skipped ($PY has no NumPy/SciPy)"
  exit 0
fi
"$PY" "$ROOT/bench/lattice.py" lat 10 20 --cosh >/dev/null || bad "lattice.py failed"
SYS="--J-coo lat/J.npy --R-coo lat/R.npy --Q-coo lat/Q.npy --B lat/B.npy"

# 1. against SciPy + SuperLU
"$P" simulate $SYS --out y.npy --states x.npy >out.txt 2>err.txt && pass || bad "simulate: exit $? ($(tail -n 2 err.txt))"
grep -q "stage solver: sparse LU" err.txt && pass || bad "the log does not name the sparse LU: $(cat err.txt)"
"$PY" "$ROOT/bench/gl3_scipy.py" lat y_scipy.npy >/dev/null && pass || bad "gl3_scipy.py failed"
"$PY" - <<'PYEOF' && pass || bad "simulate vs SciPy"
import numpy as np
import scipy.sparse as sps
y, ys, x = np.load("y.npy"), np.load("y_scipy.npy"), np.load("x.npy")
assert y.shape == (1, 1001) and ys.shape == (1, 1001) and x.shape == (400, 1001), (y.shape, x.shape)
e = np.abs(y - ys).max() / np.abs(ys).max()
assert e <= 1e-8, e
t = np.load("lat/Q.npy")
Q = sps.csc_matrix((t[:, 2], (t[:, 0].astype(int), t[:, 1].astype(int))), shape=(400, 400))
B = np.load("lat/B.npy")
ey = abs(B @ (Q @ x[:, -1]) - y[0, -1]) / np.abs(y).max()
assert ey <= 1e-12, ey
PYEOF

# 2. nonlinear (cosh on every position): sparse LU vs the dense model's LU
"$PY" - <<'PYEOF' || bad "dense copies of the lattice"
import numpy as np
for n in "JRQ":
    t = np.load("lat/%s.npy" % n)
    D = np.zeros((400, 400))
    np.add.at(D, (t[:, 0].astype(int), t[:, 1].astype(int)), t[:, 2])
    np.save("%s_dense.npy" % n, D)
PYEOF
"$P" simulate $SYS --potential cosh:1 --poly-idx lat/idx.npy --amp 20 --steps 300 --out yn.npy 2>err.txt >/dev/null \
  && pass || bad "simulate cosh (sparse): $(tail -n 2 err.txt)"
"$P" simulate --J J_dense.npy --R R_dense.npy --Q Q_dense.npy --B lat/B.npy --potential cosh:1 --poly-idx lat/idx.npy \
  --amp 20 --steps 300 --out yd.npy 2>err.txt >/dev/null && pass || bad "simulate cosh (dense): $(tail -n 2 err.txt)"
"$PY" -c "
import numpy as np
a, b = np.load('yn.npy'), np.load('yd.npy')
e = np.abs(a - b).max() / np.abs(b).max()
assert e <= 1e-10 and np.abs(b).max() > 0.1, e
" && pass || bad "cosh: sparse LU and dense LU outputs differ"

# 3. errors
cp lat/B.npy B_before.npy
"$P" simulate $SYS --out lat/B.npy >/dev/null 2>err.txt
[ $? -eq 2 ] && grep -q "one of the input files" err.txt && cmp -s lat/B.npy B_before.npy && pass \
  || bad "--out naming an input: $(cat err.txt)"
"$P" simulate $SYS --out y2.npy --states lat/J.npy >/dev/null 2>err.txt
[ $? -eq 2 ] && [ ! -e y2.npy ] && pass || bad "--states naming an input: $(cat err.txt)"
"$P" simulate $SYS >/dev/null 2>err.txt
[ $? -eq 2 ] && grep -q -- "--out FILE is required" err.txt && pass || bad "missing --out: $(cat err.txt)"
"$P" simulate $SYS --out y3.npy --method gmg-pod >/dev/null 2>err.txt
[ $? -eq 2 ] && grep -q "unknown option" err.txt && pass || bad "unknown option: $(cat err.txt)"
"$P" simulate --J-coo lat/J.npy --out y3.npy >/dev/null 2>err.txt
[ $? -eq 2 ] && pass || bad "incomplete model: $(cat err.txt)"

echo "test_simulate: $npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
