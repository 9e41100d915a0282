#!/bin/sh
# test_cli_defects4.sh — the command line's handling of the inputs added with
# descriptor models, feedthrough, dampers and --ref, on a tiny model (a chain
# of 5 masses, N = 10, written with NumPy), a few steps each (seconds in all).
#
# Usage: sh tests/test_cli_defects4.sh build/phgmg [build/phgmg-float]
#
# 1. No output is ever one of the inputs: every input option (--dampers, --E,
#    --P, --S, --N, --ref FILE, ...) is compared as a file with every output
#    of reduce and simulate (--out's arrays, --states, the clean-up of an
#    earlier run's arrays), however spelled or linked: refused up front
#    (status 2), the input unchanged, nothing written.
# 2. The outputs are checked before any work: a missing directory, a
#    directory where nothing can be created (also as root), a mass matrix in
#    the other storage form than J, R, Q, a step beyond the double range.
# 3. Messages and records: the causes of refused feedthrough, --ref with
#    feedthrough or dampers, a port on an algebraic line; info of a model with
#    dampers and feedthrough; NAME.json names every model file; usage and
#    number messages; the float build's representable range.
# 4. --ref FILE of an index-one model is the same reference as --ref mean
#    when the file holds the mean of the full states.
# Parts that need NumPy are skipped (with a note) if /usr/bin/python3 has none.
set -u
P=${1:-build/phgmg}
case "$P" in /*) ;; *) P="$PWD/$P" ;; esac
PF=${2:-}
case "$PF" in /*|"") ;; *) PF="$PWD/$PF" ;; esac
PY=/usr/bin/python3
T=$(mktemp -d "${TMPDIR:-/tmp}/phgmg_cli4.XXXXXX") || exit 1
trap 'chmod -R u+w "$T" 2>/dev/null; rm -rf "$T"' EXIT INT TERM
npass=0
nfail=0
pass() { npass=$((npass + 1)); }
bad() { echo "FAIL: $*"; nfail=$((nfail + 1)); }
[ -x "$P" ] || { echo "test_cli_defects4: $P is not an executable (build it first)"; exit 1; }
cd "$T" || exit 1
if ! "$PY" -c 'import numpy' 2>/dev/null; then
  echo "test_cli_defects4: skipped ($PY has no NumPy)"
  exit 0
fi

# run_err NAME STATUS PATTERN CMD...: exit STATUS and PATTERN (fixed string) on stderr
run_err() {
  name=$1; want=$2; pat=$3; shift 3
  "$@" >out.txt 2>err.txt
  st=$?
  if [ "$st" -ne "$want" ]; then bad "$name: exit $st, expected $want ($(tail -n 2 err.txt))"
  elif ! grep -F -q -- "$pat" err.txt; then bad "$name: stderr does not mention '$pat': $(tail -n 2 err.txt)"
  else pass; fi
}
run_ok() {
  name=$1; shift
  if "$@" >out.txt 2>err.txt; then pass; else bad "$name: exit $? ($(tail -n 2 err.txt))"; fi
}
# unchanged NAME FILE: FILE still holds the bytes of d.npy (the damper file)
unchanged() { cmp -s "$2" d.npy && pass || bad "$1: $2 was overwritten or removed"; }
# no_work NAME: the refusal came before any computation (no simulation line)
no_work() { grep -q "simulating" err.txt && bad "$1: refused only after the simulation" || pass; }

# the model: 5 masses, x = (q_1..q_5, p_1..p_5), springs K, dampers 0.3 on each mass,
# the port on mass 1; E_alg: the last mass massless (index one); E_mass: a coupled mass matrix
"$PY" - <<'EOF' || bad "model files"
import numpy as np
n = 5; N = 2 * n
K = 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1); K[n-1, n-1] = 1.0
J = np.zeros((N, N)); J[:n, n:] = np.eye(n); J[n:, :n] = -np.eye(n)
R = np.zeros((N, N)); R[n:, n:] = 0.3 * np.eye(n)
Q = np.zeros((N, N)); Q[:n, :n] = K; Q[n:, n:] = np.eye(n)
B = np.zeros((N, 1)); B[n, 0] = 1.0
for nm, A in [('J', J), ('R', R), ('Q', Q), ('B', B)]: np.save(nm + '.npy', A)
E = np.eye(N); E[N-1, N-1] = 0.0; np.save('E_alg.npy', E)
Em = np.eye(N); Em[n:, n:] += 0.1 * (np.eye(n, k=1) + np.eye(n, k=-1)); np.save('E_mass.npy', Em)
def coo(A, nm):
    r, c = np.nonzero(A); np.save(nm, np.column_stack([r, c, A[r, c]]))
coo(J, 'Jc.npy'); coo(R, 'Rc.npy'); coo(Q, 'Qc.npy'); coo(Em, 'Ec.npy')
np.save('S.npy', 0.2 * np.eye(1)); np.save('S_neg.npy', -0.2 * np.eye(1))
np.save('N_sym.npy', np.ones((1, 1))); np.save('P_big.npy', 5.0 * B)
np.save('d.npy', np.array([[n + 1, -1, 0.1, 1.0], [n + 2, n + 3, 0.05, 0.5]]))
EOF
SYS="--J J.npy --R R.npy --Q Q.npy --B B.npy"
SIM="--simulate --steps 20"
RUN="--steps 20 --quiet"

# ---- 1. an input is never an output -----------------------------------------------
cp d.npy d1.npy
run_err "simulate --out is --dampers" 2 "(--dampers)" "$P" simulate $SYS --dampers d1.npy $RUN --out d1.npy
unchanged "simulate --out is --dampers" d1.npy
cp d.npy d2.npy
run_err "simulate --states is --dampers" 2 "(--dampers)" "$P" simulate $SYS --dampers d2.npy $RUN --out y2.npy --states d2.npy
unchanged "simulate --states is --dampers" d2.npy
[ ! -e y2.npy ] && pass || bad "simulate --states is --dampers: --out written"
mkdir o1 && cp d.npy o1/rom_V0.npy
run_err "reduce --dampers in --out" 2 "(--dampers)" "$P" reduce $SYS --dampers o1/rom_V0.npy $SIM --method gmg-pod --r 4 --out o1 --quiet
unchanged "reduce --dampers in --out" o1/rom_V0.npy
[ ! -e o1/rom.phgmgrom ] && pass || bad "reduce --dampers in --out: outputs written"
# an earlier run's array (the step map Phi) replaced by the user's damper file
run_ok "reduce with a step map" "$P" reduce $SYS $SIM --method gmg-pod --r 4 --out o2 --quiet
cp d.npy o2/rom_Phi.npy
run_err "reduce --dampers named like a stale array" 2 "(--dampers)" "$P" reduce $SYS --dampers o2/rom_Phi.npy $SIM --method gmg-pod --r 4 --out o2
unchanged "stale-array clean-up" o2/rom_Phi.npy
mkdir o3 && cp d.npy o3/rom_K.npy
run_err "validate --dampers in --out" 2 "(--dampers)" "$P" validate $SYS --dampers ./o3/rom_K.npy $SIM --method gmg-pod --r 4 --out o3
unchanged "validate --dampers in --out" o3/rom_K.npy

# ---- 2. simulate: --out and --states compared as files ------------------------------
run_err "simulate --out y --states ./y" 2 "same file" "$P" simulate $SYS $RUN --out y4.npy --states ./y4.npy
[ ! -e y4.npy ] && pass || bad "simulate --out y --states ./y: y4.npy written"
ln -s y5.npy l5.npy
run_err "simulate --states a link to --out" 2 "same file" "$P" simulate $SYS $RUN --out y5.npy --states l5.npy
[ ! -e y5.npy ] && pass || bad "simulate --states a link to --out: y5.npy written"
echo keep >y6.npy
run_err "simulate --out y --states ./y (existing)" 2 "same file" "$P" simulate $SYS $RUN --out y6.npy --states ./y6.npy
[ "$(cat y6.npy)" = keep ] && pass || bad "simulate --out y --states ./y: the earlier y6.npy was replaced"

# ---- 3. simulate: E in the other storage form than J, R, Q --------------------------
run_err "simulate --J-coo with --E" 2 "--E-coo" "$P" simulate --J-coo Jc.npy --R-coo Rc.npy --Q-coo Qc.npy --B B.npy --E E_mass.npy $RUN --out y7.npy
run_err "simulate --J with --E-coo" 2 "--E-coo" "$P" simulate $SYS --E-coo Ec.npy $RUN --out y7.npy
[ ! -e y7.npy ] && pass || bad "simulate: E in the other form: output written"

# ---- 13, 20. output paths checked before the work -----------------------------------
run_err "simulate --out nodir/y.npy" 1 "nodir" "$P" simulate $SYS --steps 20 --out nodir/y.npy
no_work "simulate --out nodir/y.npy"
grep -q "\.tmp" err.txt && bad "simulate --out nodir/y.npy: the message names a temporary file" || pass
run_err "simulate --states nodir/x.npy" 1 "nodir" "$P" simulate $SYS --steps 20 --out y8.npy --states nodir/x.npy
no_work "simulate --states nodir/x.npy"
[ ! -e y8.npy ] && pass || bad "simulate --states nodir: --out written"
if [ -d /proc/self ]; then   # nothing can be created in /proc, even as root
  run_err "reduce --out /proc/nope" 1 "/proc" "$P" reduce $SYS $SIM --method gmg-pod --r 4 --out /proc/nope
  no_work "reduce --out /proc/nope"
  run_err "simulate --out /proc/y.npy" 1 "/proc" "$P" simulate $SYS --steps 20 --out /proc/y.npy
  no_work "simulate --out /proc/y.npy"
fi
run_err "reduce: a failing run leaves no new directory" 1 "P_big.npy" "$P" reduce $SYS --E E_alg.npy --P P_big.npy $SIM --method gmg-pod --r 4 --out new2/sub
[ ! -e new2 ] && pass || bad "a failing reduce left the directory it made"
ls -a . o2 | grep -q "phgmg-probe" && bad "a probe file was left behind" || pass

# ---- 31. a step beyond the double range -------------------------------------------
for dt in 1e300 1e308; do
  run_err "simulate --dt $dt" 1 "--dt" "$P" simulate $SYS --dt $dt $RUN --out y9.npy
  [ ! -e y9.npy ] && pass || bad "simulate --dt $dt: output written"
done
run_err "reduce --simulate --dt 1e300" 1 "--dt" "$P" reduce $SYS --simulate --dt 1e300 --steps 20 --method gmg-pod --r 4 --out o9
run_ok "simulate --dt 10 (a large but resolved step)" "$P" simulate $SYS --dt 10 $RUN --out y9.npy

# ---- 4. --ref FILE of an index-one model = --ref mean when it holds the states' mean ----
# the massless mass's momentum moved to the front (the algebraic variable is not last)
"$PY" - <<'EOF' || bad "scrambled index-one files"
import numpy as np
p = np.array([9, 0, 5, 1, 6, 2, 7, 3, 8, 4])
for nm in ['J', 'R', 'Q', 'E_alg']:
    A = np.load(nm + '.npy'); np.save('s' + nm + '.npy', A[np.ix_(p, p)])
np.save('sB.npy', np.load('B.npy')[p])
EOF
SSYS="--J sJ.npy --R sR.npy --Q sQ.npy --B sB.npy --E sE_alg.npy"
run_ok "simulate: scrambled index one" "$P" simulate $SSYS --steps 40 --out ys.npy --states xs.npy --quiet
"$PY" -c "import numpy as np; np.save('xbar.npy', np.load('xs.npy').mean(axis=1))" || bad "mean of the states"
run_ok "reduce --ref mean (index one)" "$P" reduce $SSYS --simulate --steps 40 --method gmg-pod --r 4 --ref mean --out rm --quiet
run_ok "reduce --ref FILE (index one)" "$P" reduce $SSYS --simulate --steps 40 --method gmg-pod --r 4 --ref xbar.npy --out rf --quiet
"$PY" - <<'EOF' && pass || bad "--ref FILE of an index-one model differs from --ref mean"
import numpy as np
for f in ['K', 'Qh', 'V0']:
    a = np.load('rm/rom_%s.npy' % f); b = np.load('rf/rom_%s.npy' % f)
    e = np.abs(a - b).max() / np.abs(a).max()
    assert e <= 1e-10, (f, e)
EOF

# the same model seen through orthogonal changes of coordinates (a dense singular E
# without zero lines): the reference rotated like the snapshots; the port acts on no
# constraint, so the condensed model has no feedthrough and --ref is taken
"$PY" - <<'EOF' || bad "rotated index-one files"
import numpy as np
rng = np.random.default_rng(3)
U, _ = np.linalg.qr(rng.standard_normal((10, 10))); V, _ = np.linalg.qr(rng.standard_normal((10, 10)))
J = np.load('J.npy'); R = np.load('R.npy'); Q = np.load('Q.npy'); B = np.load('B.npy'); E = np.load('E_alg.npy')
np.save('rJ.npy', U.T @ J @ U); np.save('rR.npy', U.T @ R @ U); np.save('rQ.npy', U.T @ Q @ V)
np.save('rB.npy', U.T @ B); np.save('rE.npy', U.T @ E @ V)
EOF
RSYS="--J rJ.npy --R rR.npy --Q rQ.npy --B rB.npy --E rE.npy"
run_ok "simulate: rotated index one" "$P" simulate $RSYS --steps 40 --out yr.npy --states xr.npy --quiet
"$PY" -c "import numpy as np; np.save('xbar_r.npy', np.load('xr.npy').mean(axis=1))" || bad "mean of the rotated states"
run_ok "reduce --ref mean (rotated)" "$P" reduce $RSYS --simulate --steps 40 --method gmg-pod --r 4 --ref mean --out rrm --quiet
run_ok "reduce --ref FILE (rotated)" "$P" reduce $RSYS --simulate --steps 40 --method gmg-pod --r 4 --ref xbar_r.npy --out rrf --quiet
"$PY" - <<'EOF' && pass || bad "--ref FILE of a rotated index-one model differs from --ref mean"
import numpy as np
for f in ['K', 'Qh', 'V0']:
    a = np.load('rrm/rom_%s.npy' % f); b = np.load('rrf/rom_%s.npy' % f)
    e = np.abs(a - b).max() / np.abs(a).max()
    assert e <= 1e-10, (f, e)
EOF

# ---- 11, 12. what gmg-qm and --ref do not take, named ------------------------------
run_err "--ref with --S" 1 "--ref mean does not go with feedthrough" "$P" reduce $SYS --method gmg-pod --ref mean --S S.npy $SIM --r 4 --out o11 --quiet
grep -q "gmg-qm" err.txt && bad "--ref with --S: the message blames gmg-qm" || pass
run_err "--ref with --dampers" 1 "--ref mean does not go with dampers" "$P" reduce $SYS --method sp1 --ref mean --dampers d.npy $SIM --r 4 --out o11 --quiet
"$PY" -c "
import numpy as np
E = np.eye(10); E[5, 5] = 0.0; np.save('E_port.npy', E)   # mass 1, the port's, massless
" || bad "E_port"
run_err "gmg-qm, a port on an algebraic line" 1 "algebraic line of E" "$P" reduce $SYS --E E_port.npy --method gmg-qm $SIM --r 4 --out o12 --quiet
run_err "--ref, a port on an algebraic line" 1 "algebraic line of E" "$P" reduce $SYS --E E_port.npy --method sp1 --ref mean $SIM --r 4 --out o12 --quiet
"$P" --help >help.txt
grep -q "feedthrough, which gmg-qm and --ref do not take" help.txt && pass || bad "--help: no caveat for gmg-qm on a port at a constraint"

# ---- 21. --help does not promise the hyper-reduction of dampers ----------------------
grep -q "hyper-reduced to a weighted subset" help.txt && bad "--help promises hyper-reduced dampers" || pass
grep -q "keeps every damper" help.txt && pass || bad "--help: dampers kept whole not said"
run_err "--no-hyper with dampers only" 2 "dampers of --dampers are not hyper-reduced" "$P" reduce $SYS --dampers d.npy --no-hyper $SIM --method gmg-pod --r 4 --out o21

# ---- 22. info of a model with dampers and feedthrough; 25. NAME.json names every file ----
run_ok "reduce with E, S, dampers" "$P" reduce $SYS --E E_mass.npy --S S.npy --dampers d.npy $SIM --method gmg-pod --r 4 --out o22 --quiet
run_ok "info (dampers, feedthrough)" "$P" info o22/rom.phgmgrom
grep -q "2 nonlinear dampers" out.txt && pass || bad "info does not say dampers: $(head -n 1 out.txt)"
grep -q "leaves out (S + N) u" out.txt && pass || bad "info does not say what the output leaves out: $(cat out.txt)"
"$PY" - <<'EOF' && pass || bad "NAME.json does not record E, S, dampers"
import json
s = json.load(open('o22/rom.json'))['system']
assert s.get('E') == 'E_mass.npy' and s.get('S') == 'S.npy' and s.get('dampers') == 'd.npy', s
EOF

# ---- 23. usage; 27. feedthrough refusals; 28. --amp nan ------------------------------
run_err "no arguments" 2 "phgmg simulate ..." "$P"
run_err "--S not PSD" 1 "S is not positive semidefinite" "$P" simulate $SYS --S S_neg.npy $RUN --out y10.npy
grep -q "error:  " err.txt && bad "--S not PSD: a stray blank in the message" || pass
run_err "--N not skew" 1 "N is not skew-symmetric" "$P" simulate $SYS --N N_sym.npy $RUN --out y10.npy
run_err "--P too large" 1 "P is too large" "$P" simulate $SYS --P P_big.npy $RUN --out y10.npy
run_err "--amp nan" 2 "expected a finite number, got 'nan'" "$P" simulate $SYS --amp nan $RUN --out y10.npy

# ---- 17. the float build: values float cannot hold; info's dt ------------------------
if [ -n "$PF" ] && [ -x "$PF" ]; then
  run_ok "float: reduce" "$PF" reduce $SYS $SIM --method gmg-pod --r 4 --out of --quiet
  for dt in 1e-300 1e39; do
    run_err "float: simulate-rom --dt $dt" 2 "not representable in float" "$PF" simulate-rom --model of/rom.phgmgrom --dt $dt --steps 5 --out yf.npy
  done
  run_ok "float: info" "$PF" info of/rom.phgmgrom
  grep -q "step map for dt = 0\.1\$" out.txt && pass || bad "float: info prints dt as $(grep -o 'dt = [0-9.e+-]*' out.txt)"
  "$PY" -c "import json; d = json.load(open('of/rom.json'))['dt_map']; assert d == 0.1, d" && pass || bad "float: NAME.json's dt_map is not 0.1"
fi

echo "test_cli_defects4: $npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
