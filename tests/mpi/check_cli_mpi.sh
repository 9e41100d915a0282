#!/bin/sh
# The distributed command line (examples/phgmg_mpi_cli.c, build/phgmg-mpi)
# against the serial one: a scrambled chain of 1200 masses (bench/lattice.py,
# N = 2400), 201 snapshots from `phgmg simulate --dt 0.1 --steps 200`,
# reduced by `phgmg reduce --method gmg-pod --r 10` and `--method sp1 --r 10`
# and by `mpirun -np P phgmg-mpi reduce` with the same options at P = 1, 2,
# 3, 4 over the cases (4: more ranks than cores; gmg-pod at P = 1 on the
# linear chain and 4 on the cosh chain, sp1 at 2 (and on the cosh chain
# with dampers at 3, below); every P for every
# method is tests/mpi/test_mpi_nl.c's), each into its own directory. NumPy
# checks:
#   - the same files (NAME.phgmgrom, .c, .json, _Bh, _Qh, _K, _V0.npy) as the
#     serial run, the json's method, N, m, r and snapshot count the serial's,
#     its pod_sigma_ratio and rcond_jr within 1e-10 relative of the serial's;
#   - K, Qh, Bh and V0 within 1e-10 relative (largest difference over the
#     serial array's largest entry) after the sign of each basis column,
#     which the SVD leaves free (signs from the columns of the serial V0:
#     K -> S K S, Qh -> S Qh S, Bh -> S Bh, V0 -> V0 S);
#   - the outputs of `phgmg simulate-rom --dt 0.1 --steps 300` on each model
#     within 1e-10 of those on the serial model (relative to their largest).
# The same chain with an on-site cosh potential on every position
# (--potential cosh:1 --poly-idx idx.npy: 1200 terms, scrambled over the
# ranks' rows), its own 201 snapshots, gmg-pod and sp1 at r = 10 with the
# default ECSW hyper-reduction: besides the above, the arrays of the kept
# terms (P0 after the modes' signs, w, poly, expo) within 1e-10, the json's
# kind, nd and hyper-reduction options the serial's, and the same ECSW
# points as global indices (each kept term's state coordinate, found as the
# row of V0 that its row of P0 is) in the same order. And at P = 3 sp1 with
# --no-hyper (every term kept, gathered from the ranks in serial order) of
# the chain with one function per term and weights (--poly (terms, 2),
# --exp (terms, 4), --poly-w, --poly-idx as int64). DEIM (--hyper qdeim
# with gmg-pod at P = 3, --hyper greedy with sp2 at P = 4; --deim-tol
# 1e-4 --deim-allow-negative): the same points in the same order and the
# same checks. A mass matrix (--E-coo: 1.25 on the positions, a
# consistent-mass pattern on the momenta; its own 201 snapshots from the
# serial simulate) with the cosh terms, gmg-pod at P = 2: the same
# checks, and the json's "E". An index-one RLC grid (bench/rlc_grid.py,
# 8 x 8 mains: N = 288, 144 algebraic lines; rows and states scrambled by
# different permutations) with gmg-pod at P = 3: the same checks and
# the json's N (the differential count), N_full and algebraic. The cosh
# chain with 81 cubic dampers of their own laws (--dampers: between
# momentum and position of every other mass, some one-sided; snapshots
# from the serial simulate), sp1 at P = 3: the same checks, every damper
# kept (the serial command's rule), and the json's "dampers". GMG-QM on
# the cosh chain: the POD manifold, --rn 4 and --lambda cv (chosen by
# held-out regression: the json's lambda_used the serial's; it picks 1e-14
# here, a model that needs simulate-rom --dt 0.01) at P = 3, the greedy
# manifold (default rn, ECSW, --lambda 1e-3) at P = 4: besides the
# above, every block of the quadratic model (G00, G01, G10, G11, Q01, Q11,
# Ms), P1, V2 and M within 1e-10 after the signs of V0's and V2's columns
# (Ms and M: row a by V2's sign, column (j, k) by those of V1's j and k).
# Bad input: a missing --X file at P = 3 must end every rank with a nonzero
# status (each rank's status recorded by a wrapper), one message, within the
# timeout (no rank left waiting in a collective); snapshots of the wrong
# shape, --simulate and options of the serial reduce that the distributed
# build does not take (--ref, springs --poly-jdx, dense --E), a mass matrix
# whose zero row and column make an index-two pencil, a port on an
# algebraic equation, DEIM options without --hyper qdeim/greedy and negative
# DEIM weights without --deim-allow-negative are refused with a message
# naming them (at P = 2; usage errors, refused before any work, at P = 1).
#   sh tests/mpi/check_cli_mpi.sh SERIAL_PHGMG PHGMG_MPI     (make test-mpi)
# MPIRUN overrides the launcher (default: mpirun --oversubscribe --mca
# mpi_yield_when_idle 1, plus
# --allow-run-as-root as root).
set -e
PHGMG=${1:-build/phgmg}
PMPI=${2:-build/phgmg-mpi}
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
if [ -z "$MPIRUN" ]; then
  MPIRUN="mpirun --oversubscribe --mca mpi_yield_when_idle 1"   # waiting ranks yield the core
  [ "$(id -u)" = 0 ] && MPIRUN="$MPIRUN --allow-run-as-root"
fi
D=$(mktemp -d "${TMPDIR:-/tmp}/check_cli_mpi.XXXXXX")
trap 'rm -rf "$D"' EXIT
$PY bench/lattice.py "$D" 1200 1 --cosh > /dev/null
M="--J-coo $D/J.npy --R-coo $D/R.npy --Q-coo $D/Q.npy --B $D/B.npy"
NL="--potential cosh:1 --poly-idx $D/idx.npy"
PT="--poly $D/pp.npy --exp $D/pe.npy --poly-w $D/pw.npy --poly-idx $D/idx_int.npy"
$PY - "$D" <<'PYEOF'
import sys
import numpy as np
d = sys.argv[1]
idx = np.load(d + '/idx.npy')
k = np.arange(len(idx))
a = 0.5 + 0.4 * np.sin(k)   # w_k a_k (cosh(s) - 1): one function per term
np.save(d + '/pp.npy', np.column_stack([-a, np.zeros(len(k))]))
np.save(d + '/pe.npy', np.column_stack([a / 2, np.ones(len(k)), a / 2, -np.ones(len(k))]))
np.save(d + '/pw.npy', 1.0 + 0.5 * (k % 3))
np.save(d + '/idx_int.npy', idx.astype(np.int64))
# a mass matrix E (triplets): 1.25 on each position (a positive multiple of the unit row there: the cosh
# terms' coordinates; one scale, so that it commutes with the springs' K), a consistent-mass pattern on the
# momenta (2/3 (1 + 0.3 sin^2 k) on the diagonal, 1/6 between neighbours); with Q = blkdiag(K, I) the
# energy matrix E^T Q = blkdiag(1.25 K, E_p) is symmetric positive definite
N = 2 * len(idx)
perm = np.random.default_rng(1).permutation(N)   # bench/lattice.py's order: q = perm[0::2], p = perm[1::2]
q, p = perm[0::2], perm[1::2]
assert (np.sort(q) == np.sort(idx)).all()
n = len(p)
mp = 2.0 / 3.0 * (1.0 + 0.3 * np.sin(np.arange(n)) ** 2)
rows = np.concatenate([q, p, p[:-1], p[1:]])
cols = np.concatenate([q, p, p[1:], p[:-1]])
vals = np.concatenate([1.25 * np.ones(n), mp, np.full(n - 1, 1.0 / 6.0), np.full(n - 1, 1.0 / 6.0)])
np.save(d + '/E.npy', np.column_stack([rows, cols, vals]))
# dampers (i, j, c1, c3), a law each: between momentum and position of every other mass (within the model's
# band), and one-sided on every 40th momentum
dr = [(p[k], q[k], 0.05 + 0.01 * (k % 4), 0.5 + 0.1 * (k % 3)) for k in range(0, n, 2)]
dr += [(p[k], -1, 0.02, 0.3) for k in range(5, n, 40)]
np.save(d + '/damp.npy', np.array(dr, dtype=float))
keep = rows != q[5]   # one position's row empty: an algebraic constraint (refused by phgmg-mpi)
np.save(d + '/E0.npy', np.column_stack([rows[keep], cols[keep], vals[keep]]))
PYEOF
"$PHGMG" simulate $M --dt 0.1 --steps 200 --out "$D/y_full.npy" --states "$D/X.npy" --quiet > /dev/null
"$PHGMG" simulate $M $NL --dt 0.1 --steps 200 --out "$D/y_full_nl.npy" --states "$D/X_nl.npy" --quiet > /dev/null
"$PHGMG" simulate $M $PT --dt 0.1 --steps 200 --out "$D/y_full_pt.npy" --states "$D/X_pt.npy" --quiet > /dev/null
"$PHGMG" simulate $M --E-coo "$D/E.npy" $NL --dt 0.1 --steps 200 --out "$D/y_full_e.npy" --states "$D/X_e.npy" --quiet > /dev/null
"$PHGMG" simulate $M $NL --dampers "$D/damp.npy" --dt 0.1 --steps 200 --out "$D/y_full_d.npy" --states "$D/X_d.npy" --quiet > /dev/null
# an index-one RLC grid (bench/rlc_grid.py: 8 x 8 mains, N = 288, 144 algebraic lines, rows and states
# scrambled by different permutations: the zero rows and zero columns of E are different index sets)
$PY bench/rlc_grid.py "$D/rlc" --n 8 --steps 200 > /dev/null
$PY bench/rlc_grid.py "$D/rlcp" --n 8 --steps 200 --port-on-constraint > /dev/null
MR="--J-coo $D/rlc/J.npy --R-coo $D/rlc/R.npy --Q-coo $D/rlc/Q.npy --E-coo $D/rlc/E.npy --B $D/rlc/B.npy"
"$PHGMG" simulate $MR --dt 0.02 --steps 200 --input "$D/rlc/chirp.npy" --out "$D/y_full_rlc.npy" --states "$D/X_rlc.npy" --quiet > /dev/null
# case: linear (gmg-pod, sp1), cosh (cosh-gmg-pod; sp1 with the cosh terms: damp-sp1), per-term functions without hyper-reduction
# (terms-sp1), cosh with DEIM (qdeim-gmg-pod, greedy-sp2), cosh with a mass matrix (mass-gmg-pod)
for case in gmg-pod sp1 cosh-gmg-pod terms-sp1 qdeim-gmg-pod greedy-sp2 mass-gmg-pod qmpod-gmg-qm qmgreedy-gmg-qm \
            rlc-gmg-pod damp-sp1; do
  model=$M
  rdt=0.1
  ps="1 2 3 4"
  case $case in
    cosh-*) meth=${case#cosh-}; X="$D/X_nl.npy"; opt=$NL ;;
    qdeim-*|greedy-*) meth=${case#*-}; X="$D/X_nl.npy"; opt="$NL --hyper ${case%%-*} --deim-tol 1e-4 --deim-allow-negative" ;;
    mass-*) meth=${case#mass-}; X="$D/X_e.npy"; opt="$NL --E-coo $D/E.npy" ;;
    terms-*) meth=${case#terms-}; X="$D/X_pt.npy"; opt="$PT --no-hyper"; ps=3 ;;
    qmpod-*) meth=gmg-qm; X="$D/X_nl.npy"; opt="$NL --manifold pod --rn 4 --lambda cv"; rdt=0.01 ;;
    qmgreedy-*) meth=gmg-qm; X="$D/X_nl.npy"; opt="$NL --manifold greedy --lambda 1e-3" ;;
    rlc-*) meth=gmg-pod; X="$D/X_rlc.npy"; opt=""; model=$MR ;;
    damp-*) meth=${case#damp-}; X="$D/X_d.npy"; opt="$NL --dampers $D/damp.npy" ;;
    *) meth=$case; X="$D/X.npy"; opt="" ;;
  esac
  case $case in   # every P over the two cases of a method (the library's layer is checked at each P by test_mpi_nl)
    gmg-pod) ps="1" ;; sp1) ps="2" ;; cosh-gmg-pod) ps="4" ;;
    qdeim-*) ps="3" ;; greedy-*) ps="4" ;; mass-*) ps="2" ;; qmpod-*) ps="3" ;; qmgreedy-*) ps="4" ;;
    rlc-*) ps="3" ;; damp-*) ps="3" ;;
  esac
  "$PHGMG" reduce $model $opt --X "$X" --method $meth --r 10 --out "$D/serial_$case" --quiet > /dev/null
  "$PHGMG" simulate-rom --model "$D/serial_$case/rom.phgmgrom" --dt $rdt --steps 300 --out "$D/y_serial_$case.npy" --quiet > /dev/null
  for p in $ps; do
    timeout 120 $MPIRUN -np $p "$PMPI" reduce $model $opt --X "$X" --method $meth --r 10 --out "$D/p${p}_$case" --quiet
    "$PHGMG" simulate-rom --model "$D/p${p}_$case/rom.phgmgrom" --dt $rdt --steps 300 --out "$D/y_p${p}_$case.npy" --quiet > /dev/null
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
NP=2
refused1() { NP=1; refused "$@"; NP=2; }   # a usage error, refused before any work: one rank
refused() {   # expected words, then the options, at NP ranks
  want=$1; shift
  case " $* " in *" --method "*) meth= ;; *) meth="--method gmg-pod" ;; esac   # gmg-pod unless given
  if timeout 60 $MPIRUN -np $NP "$PMPI" reduce $M "$@" $meth --r 10 --out "$D/bad" > /dev/null 2> "$D/err.txt"; then
    echo "check_cli_mpi: FAILED: $* was accepted"; exit 1
  fi
  if ! grep -q -- "$want" "$D/err.txt" || [ -e "$D/bad" ]; then
    echo "check_cli_mpi: FAILED: $*: expected a message with '$want' and no output"; cat "$D/err.txt"; exit 1
  fi
}
refused "expected (2400, ns)" --X "$D/B.npy"
refused1 "--simulate: the distributed build does not simulate" --simulate
refused1 "--ref: not supported by the distributed build" --X "$D/X.npy" --ref mean
refused1 "--poly-jdx: springs" --X "$D/X_nl.npy" $NL --poly-jdx "$D/idx.npy"
refused1 "--deim-tol, --deim-max and --deim-allow-negative apply to --hyper qdeim or greedy" --X "$D/X_nl.npy" $NL --deim-tol 1e-4
refused "use --deim-allow-negative" --X "$D/X_nl.npy" $NL --hyper greedy --deim-tol 1e-4
refused "--E-coo $D/E0.npy: the descriptor model has index two" --X "$D/X_e.npy" $NL --E-coo "$D/E0.npy"
if timeout 60 $MPIRUN -np 3 "$PMPI" reduce --J-coo "$D/rlcp/J.npy" --R-coo "$D/rlcp/R.npy" --Q-coo "$D/rlcp/Q.npy" \
     --E-coo "$D/rlcp/E.npy" --B "$D/rlcp/B.npy" --X "$D/X_rlc.npy" --method gmg-pod --r 10 --out "$D/bad" \
     > /dev/null 2> "$D/err.txt" || ! grep -q "a port on an algebraic equation" "$D/err.txt" || [ -e "$D/bad" ]; then
  echo "check_cli_mpi: FAILED: a port on a constraint was not refused by name"; cat "$D/err.txt"; exit 1
fi
refused1 "--E: dense matrices are not read" --X "$D/X_e.npy" --E "$D/E.npy"
refused1 "gmg-qm needs --lambda here" --X "$D/X.npy" --method gmg-qm
refused1 "--lambda auto: phgmg-mpi does not simulate" --X "$D/X.npy" --method gmg-qm --lambda auto
refused1 "--rn wide: not distributed" --X "$D/X.npy" --method gmg-qm --lambda 1e-3 --rn wide
refused1 "--manifold altmin: not distributed" --X "$D/X.npy" --method gmg-qm --lambda 1e-3 --manifold altmin
refused1 "apply to --method gmg-qm only" --X "$D/X.npy" --lambda 1e-3
refused1 "--dampers: phgmg-mpi reduces models with dampers by gmg-pod, sp1 or sp2 without a mass matrix" \
  --X "$D/X_d.npy" $NL --dampers "$D/damp.npy" --method gmg-qm --lambda 1e-3
# An output that is an input file (here --E-coo as the basis' path) is refused and the file left as it was.
mkdir -p "$D/clash" && cp "$D/E.npy" "$D/clash/rom_V0.npy"
if timeout 60 $MPIRUN -np 2 "$PMPI" reduce $M --E-coo "$D/clash/rom_V0.npy" --X "$D/X_e.npy" --method gmg-pod --r 10 \
     --out "$D/clash" > /dev/null 2> "$D/err.txt" || ! grep -q "is the input file of --E-coo" "$D/err.txt" || \
   ! cmp -s "$D/E.npy" "$D/clash/rom_V0.npy" || [ -e "$D/clash/rom.json" ]; then
  echo "check_cli_mpi: FAILED: an output that is the --E-coo file was not refused, or the file changed"; cat "$D/err.txt"; exit 1
fi
echo "check_cli_mpi: wrong snapshot shape, --simulate, --ref, --poly-jdx, DEIM options without DEIM, negative DEIM weights, an index-two mass matrix, a port on a constraint, dense --E, gmg-qm without --lambda, --lambda auto, --rn wide, --manifold altmin, --lambda with gmg-pod, --dampers with gmg-qm refused with messages naming them; an output on the --E-coo file refused, the file unchanged"

$PY - "$D" <<'PYEOF'
import json
import os
import sys
import numpy as np
d = sys.argv[1]
TOL = 1e-10
rel = lambda a, b: np.abs(a - b).max() / np.abs(b).max()

def coords(P0, V0):
    """The state coordinate of each kept term: the row of V0 that its row of P0 is (-1: none)."""
    out = []
    for row in P0:
        e = np.abs(V0 - row).max(axis=1)
        i = int(np.argmin(e))
        out.append(i if e[i] <= 1e-14 * np.abs(V0).max() else -1)
    return out

bad = 0
for case in ('gmg-pod', 'sp1', 'cosh-gmg-pod', 'terms-sp1', 'qdeim-gmg-pod', 'greedy-sp2', 'mass-gmg-pod',
             'qmpod-gmg-qm', 'qmgreedy-gmg-qm', 'rlc-gmg-pod', 'damp-sp1'):
    nl = case.startswith(('cosh-', 'terms-', 'qdeim-', 'greedy-', 'mass-', 'qmgreedy-', 'qmpod-', 'damp-'))
    qm = case.endswith('gmg-qm')
    names = (('Qh', 'Bh', 'V0', 'G00', 'G01', 'G10', 'G11', 'Q01', 'Q11', 'Ms', 'V2', 'M') if qm else
             ('K', 'Qh', 'Bh', 'V0')) + (('P0', 'w', 'poly', 'expo') if nl else ()) + (('P1',) if nl and qm else ())
    sd = '%s/serial_%s' % (d, case)
    ser = {n: np.load('%s/rom_%s.npy' % (sd, n)) for n in names}
    sj = json.load(open(sd + '/rom.json'))
    ys = np.load('%s/y_serial_%s.npy' % (d, case))
    idx = np.load(d + '/idx.npy').astype(int)
    if case.startswith('terms-'):   # every term, in serial order: P0 = V0[idx] (rows of V0 may repeat here)
        kept = lambda P0, V0: list(idx) if P0.shape[0] == len(idx) and \
            np.abs(P0 - V0[idx]).max() <= 1e-14 * np.abs(V0).max() else [-1]
    else:
        kept = coords
    cs = kept(ser['P0'], ser['V0']) if nl else []
    if nl and (len(cs) < 2 or -1 in cs or len(set(cs)) != len(cs)):
        print('check_cli_mpi: %s: the serial points were not found in V0' % case)
        bad = 1
    for p in {'gmg-pod': (1,), 'sp1': (2,), 'cosh-gmg-pod': (4,), 'terms-sp1': (3,),
              'qdeim-gmg-pod': (3,), 'greedy-sp2': (4,), 'mass-gmg-pod': (2,), 'qmpod-gmg-qm': (3,),
              'qmgreedy-gmg-qm': (4,), 'rlc-gmg-pod': (3,), 'damp-sp1': (3,)}[case]:
        pd = '%s/p%d_%s' % (d, p, case)
        files_ok = sorted(os.listdir(pd)) == sorted(os.listdir(sd))
        pj = json.load(open(pd + '/rom.json'))
        keys_ok = all(pj[k] == sj[k] for k in ('method', 'N', 'N_full', 'algebraic', 'm', 'r', 'rn', 'kind', 'map', 'nd',
                                               'poly_deg', 'E')) and \
            pj['snapshots']['count'] == sj['snapshots']['count'] and pj['files'] == sj['files'] and \
            pj['options'] == sj['options'] and \
            all(pj['system'].get(k) == sj['system'].get(k) for k in ('potential', 'poly', 'exp', 'poly_idx', 'poly_w', 'E',
                                                                     'dampers'))
        if 'hyper' in sj['info'] or 'hyper' in pj['info']:
            hs, hp = sj['info']['hyper'], pj['info']['hyper']
            keys_ok = keys_ok and all(hp[k] == hs[k] for k in ('method', 'points', 'negative_weights', 'tol')) and \
                abs(hp['min_weight'] - hs['min_weight']) <= TOL * abs(hs['min_weight'])
        e_sig = abs(pj['info']['pod_sigma_ratio'] - sj['info']['pod_sigma_ratio']) / sj['info']['pod_sigma_ratio']
        e_rc = abs(pj['info']['rcond_jr'] - sj['info']['rcond_jr']) / sj['info']['rcond_jr']
        dis = {n: np.load('%s/rom_%s.npy' % (pd, n)) for n in names}
        sg = np.sign(np.sum(dis['V0'] * ser['V0'], axis=0))
        sg[sg == 0] = 1.0
        S = np.diag(sg)
        e = {'Qh': rel(S @ dis['Qh'] @ S, ser['Qh']), 'Bh': rel(S @ dis['Bh'], ser['Bh']),
             'V0': rel(dis['V0'] @ S, ser['V0'])}
        if not qm:
            e['K'] = rel(S @ dis['K'] @ S, ser['K'])
        else:   # V2's signs from its columns; Ms and M: row a by V2's, column (j, k) by V1's j and k
            s2 = np.sign(np.sum(dis['V2'] * ser['V2'], axis=0))
            s2[s2 == 0] = 1.0
            S2, s1 = np.diag(s2), sg[pj['m']:]
            SK = np.diag(np.kron(s1, s1))
            for n, a in (('G00', S @ dis['G00'] @ S), ('G01', S @ dis['G01'] @ S2), ('G10', S2 @ dis['G10'] @ S),
                         ('G11', S2 @ dis['G11'] @ S2), ('Q01', S @ dis['Q01'] @ S2), ('Q11', S2 @ dis['Q11'] @ S2),
                         ('Ms', S2 @ dis['Ms'] @ SK), ('M', S2 @ dis['M'] @ SK), ('V2', dis['V2'] @ S2)):
                e[n] = rel(a, ser[n]) if a.shape == ser[n].shape else np.inf
            if nl:
                e['P1'] = rel(dis['P1'] @ S2, ser['P1']) if dis['P1'].shape == ser['P1'].shape else np.inf
        pts = ''
        if nl:
            cd = kept(dis['P0'], dis['V0'])
            same = all(dis[n].shape == ser[n].shape for n in ('P0', 'w', 'poly', 'expo'))
            if same:
                e.update({'P0': rel(dis['P0'] @ S, ser['P0']), 'w': rel(dis['w'], ser['w']),
                          'poly': rel(dis['poly'], ser['poly']), 'expo': rel(dis['expo'], ser['expo'])})
            else:
                e['P0'] = np.inf
            pts_ok = cd == cs
            keys_ok = keys_ok and pts_ok
            pts = '; %d points %s, P0 %.1e, w %.1e, poly %.1e, expo %.1e' % (
                len(cd), 'the same' if pts_ok else 'DIFFER', e['P0'], e.get('w', np.inf), e.get('poly', np.inf),
                e.get('expo', np.inf))
        ey = np.abs(np.load('%s/y_p%d_%s.npy' % (d, p, case)) - ys).max() / np.abs(ys).max()
        ok = files_ok and keys_ok and e_sig <= TOL and e_rc <= TOL and max(e.values()) <= TOL and ey <= TOL
        qms = ', G00..Ms, V2, M, P1 %.1e' % max(e[n] for n in e if n not in ('K', 'Qh', 'Bh', 'V0', 'P0', 'w', 'poly',
                                                                             'expo')) if qm else ''
        print('check_cli_mpi: %-15s P = %d: K %.1e, Qh %.1e, Bh %.1e, V0 %.1e%s, simulate-rom %.1e; '
              'sigma ratio %.1e, rcond %.1e%s; files %s, json %s%s'
              % (case, p, e.get('K', 0.0), e['Qh'], e['Bh'], e['V0'], qms, ey, e_sig, e_rc, pts,
                 'same' if files_ok else 'DIFFER', 'agrees' if keys_ok else 'DIFFERS', '' if ok else '  <-- FAILED'))
        bad |= not ok
if bad:
    print('check_cli_mpi: FAILED (tolerance 1e-10 relative)')
    sys.exit(1)
print('check_cli_mpi: passed (tolerance 1e-10 relative)')
PYEOF
