#!/bin/sh
# The PETSc + MUMPS example (examples/petsc_mumps.c) against the serial command
# line: a scrambled chain of 1500 masses (bench/lattice.py, N = 3000), 301
# snapshots from `phgmg simulate`, reduced by `phgmg reduce --method gmg-pod
# --r 20` (no reference state: the default --ref none; no step map: the
# default with --X) and by `mpirun -np P build/petsc_mumps` at P = 1, 2, 4.
# The outputs of `phgmg simulate-rom` on each model (300 steps of 0.1, input
# 0.1 sin t) must agree with the serial model's within 1e-10 relative (max
# |y_P - y_serial| / max |y_serial|); so must the example's own test run,
# and the blocks K, Qh, Bh themselves (after the sign of each POD mode, which
# the SVD leaves free; with one port the outputs alone would not see K
# replaced by K^T, e.g. a transposed solve).
#   sh tests/mpi/check_petsc.sh [BUILD]     (make test-petsc)
# MPIRUN overrides the launcher (default: mpirun --oversubscribe, plus
# --allow-run-as-root as root).
set -e
BUILD=${1:-build}
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
if [ -z "$MPIRUN" ]; then
  MPIRUN="mpirun --oversubscribe"
  [ "$(id -u)" = 0 ] && MPIRUN="$MPIRUN --allow-run-as-root"
fi
D=$(mktemp -d "${TMPDIR:-/tmp}/check_petsc.XXXXXX")
trap 'rm -rf "$D"' EXIT
$PY bench/lattice.py "$D" 1500 1 > /dev/null
M="--J-coo $D/J.npy --R-coo $D/R.npy --Q-coo $D/Q.npy --B $D/B.npy"
"$BUILD/phgmg" simulate $M --dt 0.1 --steps 300 --out "$D/y_full.npy" --states "$D/X.npy" --quiet > /dev/null
"$BUILD/phgmg" reduce $M --X "$D/X.npy" --method gmg-pod --r 20 --out "$D/serial" --quiet > /dev/null
"$BUILD/phgmg" simulate-rom --model "$D/serial/rom.phgmgrom" --dt 0.1 --steps 300 --out "$D/y_serial.npy" --quiet > /dev/null
for p in 1 2 4; do
  timeout 300 $MPIRUN -np $p "$BUILD/petsc_mumps" $M --X "$D/X.npy" --r 20 --out "$D/p$p.phgmgrom" \
    --y "$D/yrun_p$p.npy" --npy "$D/p$p" --dt 0.1 --steps 300 > "$D/log_p$p.txt"
  "$BUILD/phgmg" simulate-rom --model "$D/p$p.phgmgrom" --dt 0.1 --steps 300 --out "$D/y_p$p.npy" --quiet > /dev/null
done
$PY - "$D" <<'PYEOF'
import sys
import numpy as np
d = sys.argv[1]
ys = np.load(d + '/y_serial.npy')
yf = np.load(d + '/y_full.npy')
s = np.abs(ys).max()
print('check_petsc: N = 3000, r = 20; reduced (serial) against full output: %.2e relative'
      % (np.abs(ys - yf).max() / np.abs(yf).max()))


def blocks(p):
    """Largest differences of K, Qh, Bh from the serial ones, relative to
    the serial block's largest entry, after flipping the signs of the POD
    modes (mode j's sign from its couplings with the modes before it)."""
    ser = [np.load(d + '/serial/rom_%s.npy' % n) for n in ('K', 'Qh', 'Bh')]
    dis = [np.load(d + '/p%d_%s.npy' % (p, n)) for n in ('K', 'Qh', 'Bh')]
    r = ser[0].shape[0]
    Ks, Qs, Bs = ser[0], ser[1], ser[2].reshape(r, -1)
    Kp, Qp, Bp = dis[0], dis[1], dis[2].reshape(r, -1)
    m = Bs.shape[1]
    sg = np.ones(r)
    for j in range(m, r):
        c = sum(sg[i] * (Qp[i, j] * Qs[i, j] + Kp[i, j] * Ks[i, j] + Kp[j, i] * Ks[j, i]) for i in range(j))
        sg[j] = 1.0 if c >= 0 else -1.0
    S = np.diag(sg)
    rel = lambda a, b: np.abs(a - b).max() / np.abs(b).max()
    return rel(S @ Kp @ S, Ks), rel(S @ Qp @ S, Qs), rel(Bp, Bs)


bad = 0
for p in (1, 2, 4):
    e1 = np.abs(np.load(d + '/y_p%d.npy' % p) - ys).max() / s
    e2 = np.abs(np.load(d + '/yrun_p%d.npy' % p) - ys).max() / s
    print('check_petsc: P = %d: simulate-rom against the serial model %.2e, the example\'s own run %.2e' % (p, e1, e2))
    bad |= not (e1 <= 1e-10 and e2 <= 1e-10)
    eK, eQ, eB = blocks(p)
    print('check_petsc: P = %d: K %.2e, Qh %.2e, Bh %.2e against the serial blocks (relative, after the modes\' signs)'
          % (p, eK, eQ, eB))
    bad |= not (eK <= 1e-10 and eQ <= 1e-10 and eB <= 1e-10)
if bad:
    print('check_petsc: FAILED (tolerance 1e-10 relative)')
    sys.exit(1)
print('check_petsc: passed (tolerance 1e-10 relative)')
PYEOF
