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
#    With nonlinear dampers (--dampers) the log names the sparse LU (no band
#    fall-back) and the output equals the dense model's to 1e-10 relative.
# 4. A 2-D lattice with a mass matrix (--E-coo) whose E and Q have their
#    columns swapped in pairs (the same outputs): the log names the sparse LU
#    with its matched columns and no fall-back, the output equals the natural
#    order's to 1e-10; with springs 1e10 times stiffer the static pivots fail
#    and the log says the band LU took over.
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

# 2b. nonlinear dampers on the sparse LU (no band fall-back): the same output
#     as the dense model's LU
"$PY" -c "
import numpy as np
np.save('damp.npy', np.array([[5, 17, 0.3, 0.5], [40, -1, 0.2, 1.0], [123, 7, 0.0, 2.0]]))
" && pass || bad "damper file"
"$P" simulate $SYS --dampers damp.npy --amp 5 --steps 300 --out ydn.npy 2>err.txt >/dev/null \
  && pass || bad "simulate --dampers (sparse): $(tail -n 2 err.txt)"
grep -q "stage solver: sparse LU" err.txt && ! grep -q "band LU" err.txt && pass || bad "--dampers: not on the sparse LU: $(cat err.txt)"
"$P" simulate --J J_dense.npy --R R_dense.npy --Q Q_dense.npy --B lat/B.npy --dampers damp.npy \
  --amp 5 --steps 300 --out ydd.npy 2>err.txt >/dev/null && pass || bad "simulate --dampers (dense): $(tail -n 2 err.txt)"
"$PY" -c "
import numpy as np
a, b = np.load('ydn.npy'), np.load('ydd.npy')
e = np.abs(a - b).max() / np.abs(b).max()
assert e <= 1e-10 and np.abs(b).max() > 0.1, e
" && pass || bad "dampers: sparse LU and dense LU outputs differ"

# 4. columns of E and Q swapped in pairs; a fall-back to the band LU is logged
"$PY" - <<'PYEOF' || bad "descriptor lattice files"
import numpy as np
nx = 16; n = nx * nx; N = 2 * n
def lattice(swap, ks):
    J, R, Q, E = [], [], [], []
    for k in range(n):
        x, y = k % nx, k // nx
        nb = [m for m, ok in ((k - nx, y > 0), (k - 1, x > 0), (k + 1, x + 1 < nx), (k + nx, y + 1 < nx)) if ok]
        q, p = 2 * k, 2 * k + 1
        J += [(q, p, 1.0), (p, q, -1.0)]
        R += [(p, p, 0.05)]
        Q += [(p, p, 1.0), (q, q, ks * (len(nb) + 0.1))] + [(q, 2 * m, -ks) for m in nb]
        E += [(q, q, 1.0), (p, p, 1.0)] + [(p, 2 * m + 1, 0.1) for m in nb]
    col = (lambda j: j ^ 2) if swap else (lambda j: j)
    Q = [(i, col(j), v) for i, j, v in Q]
    E = [(i, col(j), v) for i, j, v in E]
    return [np.array(sorted(M, key=lambda t: (t[1], t[0])), dtype=float) for M in (J, R, Q, E)]
B = np.zeros((N, 1)); B[1, 0] = 1.0
for name, swap, ks in (("nat", 0, 1.0), ("swp", 1, 1.0), ("stf", 0, 1e10)):
    for m, M in zip("JRQE", lattice(swap, ks)):
        np.save("%s_%s.npy" % (name, m), M)
np.save("dB.npy", B)
PYEOF
for c in nat swp stf; do
  "$P" simulate --J-coo ${c}_J.npy --R-coo ${c}_R.npy --Q-coo ${c}_Q.npy --E-coo ${c}_E.npy --B dB.npy \
    --steps 40 --out y_$c.npy >/dev/null 2>err_$c.txt || bad "simulate $c: exit $? ($(tail -n 2 err_$c.txt))"
done
grep -q "stage solver: sparse LU (512 columns matched" err_swp.txt && pass || bad "swapped: $(cat err_swp.txt)"
grep -q "static pivots failed" err_swp.txt err_nat.txt && bad "a fall-back logged: $(cat err_swp.txt)" || pass
grep -q "static pivots failed on this model; the stage systems were solved by the band LU" err_stf.txt && pass \
  || bad "the stiff model's fall-back is not logged: $(cat err_stf.txt)"
"$PY" - <<'PYEOF' && pass || bad "swapped columns: outputs differ"
import numpy as np
a, b = np.load("y_nat.npy"), np.load("y_swp.npy")
assert np.abs(a).max() > 0 and np.abs(a - b).max() <= 1e-10 * np.abs(a).max(), np.abs(a - b).max()
PYEOF

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

# 5. a star (one state coupled to all others): its band is wide in every
#    order, yet the sparse LU has no fill; the log names the sparse LU and
#    gives no "dense input would be as fast" hint (true for the band LU only)
"$PY" - <<'PYEOF' || bad "star model generation failed"
import numpy as np
N = 400
np.save("sJ.npy", np.array([(0, i, 1.0) for i in range(1, N)] + [(i, 0, -1.0) for i in range(1, N)]))
np.save("sR.npy", np.array([(i, i, 0.1) for i in range(N)]))
np.save("sQ.npy", np.array([(i, i, 1.0) for i in range(N)]))
B = np.zeros((N, 1)); B[0, 0] = 1.0; np.save("sB.npy", B)
PYEOF
"$P" simulate --J-coo sJ.npy --R-coo sR.npy --Q-coo sQ.npy --B sB.npy --steps 5 --out ys.npy >/dev/null 2>err.txt
grep -q "stage solver: sparse LU" err.txt && ! grep -q "wide band" err.txt && pass \
  || bad "star: sparse LU with a band hint: $(cat err.txt)"

echo "test_simulate: $npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
