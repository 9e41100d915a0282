#!/bin/sh
# The distributed command line (examples/phgmg_mpi_cli.c, build/phgmg-mpi)
# against the serial one: a scrambled chain of 1200 masses (bench/lattice.py,
# N = 2400), 201 snapshots from `phgmg simulate --dt 0.1 --steps 200`,
# reduced by `phgmg reduce --method gmg-pod --r 10` and `--method sp1 --r 10`
# and by `mpirun -np P phgmg-mpi reduce` with the same options at P = 1, 2,
# 3, 4 (4: more ranks than cores), each into its own directory. NumPy checks:
#   - the same files (NAME.phgmgrom, .c, .json, _Bh, _Qh, _K, _V0.npy) as the
#     serial run, the json's method, N, m, r and snapshot count the serial's,
#     its pod_sigma_ratio and rcond_jr within 1e-10 relative of the serial's;
#   - K, Qh, Bh and V0 within 1e-10 relative (largest difference over the
#     serial array's largest entry) after the sign of each basis column,
#     which the SVD leaves free (signs from the columns of the serial V0:
#     K -> S K S, Qh -> S Qh S, Bh -> S Bh, V0 -> V0 S);
#   - the outputs of `phgmg simulate-rom --dt 0.1 --steps 300` on each model
#     within 1e-10 of those on the serial model (relative to their largest).
# Bad input at P = 3: a missing --X file must end every rank with a nonzero
# status (each rank's status recorded by a wrapper), one message, within the
# timeout (no rank left waiting in a collective); snapshots of the wrong
# shape, --simulate and an option of the serial reduce that the distributed
# build does not take (--ref) are refused with a message naming them.
#   sh tests/mpi/check_cli_mpi.sh SERIAL_PHGMG PHGMG_MPI     (make test-mpi)
# MPIRUN overrides the launcher (default: mpirun --oversubscribe, plus
# --allow-run-as-root as root).
set -e
PHGMG=${1:-build/phgmg}
PMPI=${2:-build/phgmg-mpi}
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
if [ -z "$MPIRUN" ]; then
  MPIRUN="mpirun --oversubscribe"
  [ "$(id -u)" = 0 ] && MPIRUN="$MPIRUN --allow-run-as-root"
fi
D=$(mktemp -d "${TMPDIR:-/tmp}/check_cli_mpi.XXXXXX")
trap 'rm -rf "$D"' EXIT
$PY bench/lattice.py "$D" 1200 1 > /dev/null
M="--J-coo $D/J.npy --R-coo $D/R.npy --Q-coo $D/Q.npy --B $D/B.npy"
"$PHGMG" simulate $M --dt 0.1 --steps 200 --out "$D/y_full.npy" --states "$D/X.npy" --quiet > /dev/null
for meth in gmg-pod sp1; do
  "$PHGMG" reduce $M --X "$D/X.npy" --method $meth --r 10 --out "$D/serial_$meth" --quiet > /dev/null
  "$PHGMG" simulate-rom --model "$D/serial_$meth/rom.phgmgrom" --dt 0.1 --steps 300 --out "$D/y_serial_$meth.npy" --quiet > /dev/null
  for p in 1 2 3 4; do
    timeout 120 $MPIRUN -np $p "$PMPI" reduce $M --X "$D/X.npy" --method $meth --r 10 --out "$D/p${p}_$meth" --quiet
    "$PHGMG" simulate-rom --model "$D/p${p}_$meth/rom.phgmgrom" --dt 0.1 --steps 300 --out "$D/y_p${p}_$meth.npy" --quiet > /dev/null
  done
done

# Bad input: a missing snapshot file, every rank's status recorded (the
# wrapper ends with status 0, so that mpirun lets every rank finish; a rank
# left waiting would show as the timeout's status 124).
st=0
timeout 60 $MPIRUN -np 3 sh -c '"$0" reduce $1 --X "$2/missing.npy" --method gmg-pod --r 10 --out "$2/bad" --quiet 2>> "$2/bad_err.txt"; echo $? >> "$2/bad_status.txt"' \
  "$PMPI" "$M" "$D" > /dev/null 2>&1 || st=$?
if [ "$st" != 0 ]; then echo "check_cli_mpi: FAILED: a missing --X file: mpirun status $st (124: timeout)"; exit 1; fi
if [ "$(grep -c . "$D/bad_status.txt")" != 3 ] || grep -qx 0 "$D/bad_status.txt"; then
  echo "check_cli_mpi: FAILED: a missing --X file: rank statuses $(tr '\n' ' ' < "$D/bad_status.txt")"; exit 1
fi
if [ "$(grep -c 'missing.npy' "$D/bad_err.txt")" != 1 ] || [ -e "$D/bad" ]; then
  echo "check_cli_mpi: FAILED: a missing --X file: expected one message naming it and no output"; cat "$D/bad_err.txt"; exit 1
fi
echo "check_cli_mpi: a missing --X file: status $(sort -u "$D/bad_status.txt" | tr '\n' ' ')on all 3 ranks, one message: $(cat "$D/bad_err.txt")"
# Refused: snapshots of the wrong shape (B has one column), --simulate, --ref.
refused() {   # expected words, then the options
  want=$1; shift
  if timeout 60 $MPIRUN -np 3 "$PMPI" reduce $M "$@" --method gmg-pod --r 10 --out "$D/bad" > /dev/null 2> "$D/err.txt"; then
    echo "check_cli_mpi: FAILED: $* was accepted"; exit 1
  fi
  if ! grep -q -- "$want" "$D/err.txt" || [ -e "$D/bad" ]; then
    echo "check_cli_mpi: FAILED: $*: expected a message with '$want' and no output"; cat "$D/err.txt"; exit 1
  fi
}
refused "expected (2400, ns)" --X "$D/B.npy"
refused "--simulate: the distributed build does not simulate" --simulate
refused "--ref: not supported by the distributed build" --X "$D/X.npy" --ref mean
echo "check_cli_mpi: wrong snapshot shape, --simulate, --ref refused with messages naming them"

$PY - "$D" <<'PYEOF'
import json
import os
import sys
import numpy as np
d = sys.argv[1]
TOL = 1e-10
rel = lambda a, b: np.abs(a - b).max() / np.abs(b).max()
bad = 0
for meth in ('gmg-pod', 'sp1'):
    sd = '%s/serial_%s' % (d, meth)
    ser = {n: np.load('%s/rom_%s.npy' % (sd, n)) for n in ('K', 'Qh', 'Bh', 'V0')}
    sj = json.load(open(sd + '/rom.json'))
    ys = np.load('%s/y_serial_%s.npy' % (d, meth))
    for p in (1, 2, 3, 4):
        pd = '%s/p%d_%s' % (d, p, meth)
        files_ok = sorted(os.listdir(pd)) == sorted(os.listdir(sd))
        pj = json.load(open(pd + '/rom.json'))
        keys_ok = all(pj[k] == sj[k] for k in ('method', 'N', 'm', 'r', 'kind', 'map')) and \
            pj['snapshots']['count'] == sj['snapshots']['count'] and pj['files'] == sj['files']
        e_sig = abs(pj['info']['pod_sigma_ratio'] - sj['info']['pod_sigma_ratio']) / sj['info']['pod_sigma_ratio']
        e_rc = abs(pj['info']['rcond_jr'] - sj['info']['rcond_jr']) / sj['info']['rcond_jr']
        dis = {n: np.load('%s/rom_%s.npy' % (pd, n)) for n in ('K', 'Qh', 'Bh', 'V0')}
        sg = np.sign(np.sum(dis['V0'] * ser['V0'], axis=0))
        sg[sg == 0] = 1.0
        S = np.diag(sg)
        e = {'K': rel(S @ dis['K'] @ S, ser['K']), 'Qh': rel(S @ dis['Qh'] @ S, ser['Qh']),
             'Bh': rel(S @ dis['Bh'], ser['Bh']), 'V0': rel(dis['V0'] @ S, ser['V0'])}
        ey = np.abs(np.load('%s/y_p%d_%s.npy' % (d, p, meth)) - ys).max() / np.abs(ys).max()
        ok = files_ok and keys_ok and e_sig <= TOL and e_rc <= TOL and max(e.values()) <= TOL and ey <= TOL
        print('check_cli_mpi: %-7s P = %d: K %.1e, Qh %.1e, Bh %.1e, V0 %.1e, simulate-rom %.1e; '
              'sigma ratio %.1e, rcond %.1e; files %s, json %s%s'
              % (meth, p, e['K'], e['Qh'], e['Bh'], e['V0'], ey, e_sig, e_rc, 'same' if files_ok else 'DIFFER',
                 'agrees' if keys_ok else 'DIFFERS', '' if ok else '  <-- FAILED'))
        bad |= not ok
if bad:
    print('check_cli_mpi: FAILED (tolerance 1e-10 relative)')
    sys.exit(1)
print('check_cli_mpi: passed (tolerance 1e-10 relative)')
PYEOF
