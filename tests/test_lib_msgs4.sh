#!/bin/sh
# test_lib_msgs4.sh — the command line's messages name the real cause of a
# refused model (descriptor models, dampers, index-one sizes, the quadratic
# fit's ridge parameter, model files tampered with and re-checksummed).
#
# Usage: sh tests/test_lib_msgs4.sh build/phgmg      (from the repository root)
#
# Each case runs `phgmg` on a small model (a 10-mass chain, a 3-state circuit
# with an algebraic node, a rotated chain whose E has no zero line) and
# checks the exit status and that the error names the option, file and
# cause: E = 0 (dense and sparse), a singular --E-coo without zero lines
# (taken dense only) or with a damper, index two of an E without zero lines, a damper whose
# c1 makes J - R - L singular, a damper on an algebraic line, r beyond the
# differential states of an index-one model, every port acting through a
# constraint (condensed B = 0), --lambda too small for the quadratic fit,
# and a model file whose damper law or feedthrough block was tampered with
# (checksum recomputed: FNV-1a over the bytes before it).
# Needs NumPy (skipped with a note if /usr/bin/python3 has none). Fast (< 3 s).
set -u
P=${1:-build/phgmg}
case "$P" in /*) ;; *) P="$PWD/$P" ;; esac
PY=/usr/bin/python3
T=$(mktemp -d "${TMPDIR:-/tmp}/phgmg_msgs4.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT INT TERM
npass=0
nfail=0
pass() { npass=$((npass + 1)); }
bad() { echo "FAIL: $*"; nfail=$((nfail + 1)); }
[ -x "$P" ] || { echo "test_lib_msgs4: $P is not an executable (build it first)"; exit 1; }
cd "$T" || exit 1
if ! "$PY" -c 'import numpy' 2>/dev/null; then
  echo "test_lib_msgs4: skipped ($PY has no NumPy)"
  exit 0
fi

"$PY" - <<'PYEOF' || { echo "FAIL: model files"; exit 1; }
import numpy as np
def coo(A):
    i, j = np.nonzero(A)
    return np.column_stack([i, j, A[i, j]]).astype(float)
# the chain: x = (q1, p1, q2, p2, ...), force at p1
n = 10; N = 2 * n
J = np.zeros((N, N)); R = np.zeros((N, N)); Q = np.zeros((N, N)); B = np.zeros((N, 1))
for i in range(n):
    q, p = 2 * i, 2 * i + 1
    J[q, p] = 1; J[p, q] = -1; R[p, p] = 0.5; Q[p, p] = 1; Q[q, q] = 1 if i == 0 else 2
    if i + 1 < n: Q[q, q + 2] = -1; Q[q + 2, q] = -1
B[1] = 1
for k, v in dict(J=J, R=R, Q=Q, B=B).items(): np.save(k + ".npy", v)
for k, v in dict(J=J, R=R, Q=Q).items(): np.save(k + "c.npy", coo(v))
np.save("E0.npy", np.zeros((N, N)))
np.save("E0c.npy", np.zeros((0, 3)))
E5 = np.eye(N); E5[5, 5] = 0          # p3 massless (R[5, 5] > 0: index one)
np.save("E5.npy", E5)
np.save("d_big.npy", np.array([[3, -1, 1e300, 0.0]]))
np.save("d_alg.npy", np.array([[5, -1, 1.0, 0.0]]))
np.save("d_ok.npy", np.array([[3, 5, 0.2, 0.1], [7, -1, 0.3, 0.05]]))
np.save("S.npy", np.array([[0.5]]))
# the circuit, x3 algebraic, the port on x3 only
E = np.diag([1.0, 1.0, 0.0]); Jc = np.zeros((3, 3)); Jc[0, 1] = 1; Jc[1, 0] = -1; Jc[1, 2] = 1; Jc[2, 1] = -1
np.save("cE.npy", E); np.save("cJ.npy", Jc); np.save("cR.npy", np.diag([0, 0, 0.5]))
np.save("cQ.npy", np.eye(3)); np.save("cB.npy", np.array([[0.0], [0.0], [1.0]]))
# a chain of 6 with a massless node, rotated (E = P E0 T: no zero line)
n = 6; N = 2 * n
E = np.eye(N); E[n + 2, n + 2] = 0
K = 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
J = np.zeros((N, N)); J[:n, n:] = np.eye(n); J[n:, :n] = -np.eye(n)
D = 0.05 * np.eye(n) + 0.002 * K
R = np.zeros((N, N)); R[n:, n:] = D
D2 = D.copy(); D2[2, :] = 0; D2[:, 2] = 0
R2 = np.zeros((N, N)); R2[n:, n:] = D2          # no damping at the massless node: index two
Q = np.zeros((N, N)); Q[:n, :n] = K; Q[n:, n:] = np.eye(n)
B = np.zeros((N, 1)); B[N - 1] = 1
def refl(s):
    v = np.sin(1.7 * np.arange(1, N + 1) * (s + 1)) + 0.3
    return np.eye(N) - 2 * np.outer(v, v) / (v @ v)
P, T = refl(1), refl(2)
sk = lambda A: (A - A.T) / 2
sy = lambda A: (A + A.T) / 2
Ew, Jw, Rw, Rw2, Qw = P @ E @ T, sk(P @ J @ P.T), sy(P @ R @ P.T), sy(P @ R2 @ P.T), P @ Q @ T
for k, v in dict(Ew=Ew, Jw=Jw, Rw=Rw, Rw2=Rw2, Qw=Qw, Bw=P @ B).items(): np.save(k + ".npy", v)
for k, v in dict(Ew=Ew, Jw=Jw, Rw=Rw, Qw=Qw).items(): np.save(k + "c.npy", coo(v))
np.save("d_w.npy", np.array([[1, 4, 0.2, 0.1]]))
PYEOF

# expect STATUS PATTERN... -- run phgmg with the remaining arguments; the
# exit status must be STATUS and stderr must contain every PATTERN.
expect() {
  st=$1; shift
  pats=""
  while [ "$1" != "--" ]; do pats="$pats
$1"; shift; done
  shift
  "$P" "$@" >out.txt 2>err.txt
  rc=$?
  if [ "$rc" -ne "$st" ]; then bad "phgmg $*: exit $rc, expected $st ($(tail -n 1 err.txt))"; return; fi
  ok=1
  echo "$pats" | while IFS= read -r p; do
    [ -z "$p" ] && continue
    grep -qF -- "$p" err.txt || { echo "FAIL: phgmg $*: no '$p' in: $(tail -n 1 err.txt)"; exit 1; }
  done || ok=0
  if [ "$ok" = 1 ]; then pass; else nfail=$((nfail + 1)); fi
}
SIM="simulate --steps 10 --out y.npy"

# E = 0: the mass matrix named, every row and column zero (not a size mismatch)
expect 1 "E0.npy (--E)" "every row and column of E is zero" -- $SIM --J J.npy --R R.npy --Q Q.npy --B B.npy --E E0.npy
expect 1 "E0c.npy (--E-coo)" "every row and column of E is zero" -- \
  $SIM --J-coo Jc.npy --R-coo Rc.npy --Q-coo Qc.npy --B B.npy --E-coo E0c.npy
# a singular E without zero lines works dense, is refused sparse for what it is
expect 0 -- $SIM --J Jw.npy --R Rw.npy --Q Qw.npy --B Bw.npy --E Ew.npy
expect 1 "Ewc.npy (--E-coo)" "singular E without zero rows and columns is taken in dense form only" -- \
  $SIM --J-coo Jwc.npy --R-coo Rwc.npy --Q-coo Qwc.npy --B Bw.npy --E-coo Ewc.npy
# with a damper that E is not taken (quadratic energy, no dampers): said so
expect 1 "Ew.npy (--E)" "taken with a quadratic energy and no dampers only" -- \
  $SIM --J Jw.npy --R Rw.npy --Q Qw.npy --B Bw.npy --E Ew.npy --dampers d_w.npy
# index two of that E: no zero lines to blame
expect 1 "index two" "E is singular without zero rows or columns" -- \
  $SIM --J Jw.npy --R Rw2.npy --Q Qw.npy --B Bw.npy --E Ew.npy
grep -q "the zero rows and columns of E" err.txt && bad "index two of E without zero lines blamed on its zero lines" || pass
# dampers: c1 = 1e300 makes J - R - L singular (J - R is fine); a damper on an algebraic line
expect 1 "d_big.npy (--dampers)" "dampers' linear part" -- $SIM --J J.npy --R R.npy --Q Q.npy --B B.npy --dampers d_big.npy
grep -q "(--J, --R)" err.txt && bad "the damper's c1 blamed on J and R" || pass
expect 1 "d_alg.npy (--dampers)" "row 0" "state 5" "algebraic line of E" -- \
  $SIM --J J.npy --R R.npy --Q Q.npy --B B.npy --E E5.npy --dampers d_alg.npy
expect 1 "d_alg.npy (--dampers)" "state 5" -- \
  $SIM --J J.npy --R R.npy --Q Q.npy --B B.npy --E E5.npy --dampers d_alg.npy --S S.npy
grep -q "(--P, --S, --N)" err.txt && bad "a damper on an algebraic line blamed on --S" || pass
# index-one sizes: the differential count and the model's
expect 2 "N = 19 differential states" "20 states less 1 algebraic" -- \
  reduce --J J.npy --R R.npy --Q Q.npy --B B.npy --E E5.npy --method gmg-pod --r 20 --simulate --out o
expect 1 "snapshots of size 19: the differential states" -- \
  reduce --J J.npy --R R.npy --Q Q.npy --B B.npy --E E5.npy --method gmg-pod --r 10 --simulate --steps 5 --out o4
# every port through a constraint: the condensed B is zero; gmg-pod (B in its
# basis) refuses, sp1 takes it (the port enters through the feedthrough terms)
expect 1 "every port of cB.npy acts through an algebraic constraint" "port matrix B is zero" -- \
  reduce --J cJ.npy --R cR.npy --Q cQ.npy --B cB.npy --E cE.npy --method gmg-pod --r 2 --simulate --out o2
expect 0 -- reduce --J cJ.npy --R cR.npy --Q cQ.npy --B cB.npy --E cE.npy --method sp1 --r 2 --simulate --out o2s
# a ridge parameter too small for the quadratic fit
expect 1 "--lambda 1e-300" "ridge parameter" -- reduce --J J.npy --R R.npy --Q Q.npy --B B.npy --method gmg-qm \
  --lambda 1e-300 --r 6 --rn 4 --simulate --steps 14 --out o3
expect 0 -- reduce --J J.npy --R R.npy --Q Q.npy --B B.npy --method gmg-qm --lambda 1e-3 --r 6 --rn 4 --simulate \
  --steps 14 --out o3

# model files tampered with, the checksum recomputed: dampers, feedthrough
expect 0 -- reduce --J J.npy --R R.npy --Q Q.npy --B B.npy --dampers d_ok.npy --method gmg-pod --r 6 --simulate \
  --steps 100 --out md
expect 0 -- reduce --J J.npy --R R.npy --Q Q.npy --B B.npy --S S.npy --method gmg-pod --r 6 --simulate \
  --steps 100 --out mf
"$PY" - <<'PYEOF' || bad "tampering the model files"
import struct
def fnv(b):
    h = 2166136261
    for c in b: h = ((h ^ c) * 16777619) & 0xffffffff
    return h
def tamper(src, dst, back, value):
    b = bytearray(open(src, "rb").read())
    assert struct.unpack("<I", b[-4:])[0] == fnv(b[:-4])   # the writer's checksum
    o = len(b) - 4 - 8 * back
    b[o:o + 8] = struct.pack("<d", value)
    b[-4:] = struct.pack("<I", fnv(b[:-4]))
    open(dst, "wb").write(b)
# the last field of a damper model is the laws (two dampers, 4 coefficients each):
# its last scalar is c3 of damper 2; of a feedthrough model PD, its last scalar Dh = S
tamper("md/rom.phgmgrom", "md_bad.phgmgrom", 1, -0.05)
tamper("mf/rom.phgmgrom", "mf_bad.phgmgrom", 1, -0.5)
PYEOF
expect 0 -- info md/rom.phgmgrom
expect 1 "md_bad.phgmgrom" "damper" "the file's damper weights or laws" -- info md_bad.phgmgrom
grep -q "Qh not positive definite" err.txt && bad "a tampered damper law blamed on Qh, R or the step map" || pass
expect 0 -- info mf/rom.phgmgrom
expect 1 "mf_bad.phgmgrom" "feedthrough" "the file's feedthrough block" -- info mf_bad.phgmgrom
grep -q "Qh not positive definite" err.txt && bad "a tampered feedthrough blamed on Qh, R or the step map" || pass

echo "test_lib_msgs4: $npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
