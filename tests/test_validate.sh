#!/bin/sh
# test_validate.sh — `phgmg validate` (examples/phgmg_cli.c): reduce,
# then check the reduced model against the full one on test inputs.
#
# Usage: sh tests/test_validate.sh build/phgmg      (from the repository root)
#
# 1. A sound model (GMG-POD, r = 12, the paper's linear MSD trained on
#    u = 0.1 sin t) passes on the training input and on u = 0.1: exit 0.
# 2. An overfitted GMG-QM (lambda = 1e-12, r = 8) fails on u = 0.1 (e_y above
#    --max-ey): exit 1, and on u = 0.1 sin 2t (an input file) its Newton
#    solve fails: exit 1 and the first failing step is reported (step 290 of
#    1000, t = 29, measured; the check accepts any step in 1..999).
#    With --lambda auto (pod or altmin manifold) the same r = 8 passes on all three.
# 3. Bad usage exits 2.
# The model comes from examples/npy_example/make_model.py (NumPy); skipped
# with a note if /usr/bin/python3 has no NumPy.
set -u
P=${1:-build/phgmg}
case "$P" in /*) ;; *) P="$PWD/$P" ;; esac
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PY=/usr/bin/python3
T=$(mktemp -d "${TMPDIR:-/tmp}/phgmg_val.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT INT TERM
npass=0
nfail=0
pass() { npass=$((npass + 1)); }
bad() { echo "FAIL: $*"; nfail=$((nfail + 1)); }
[ -x "$P" ] || { echo "test_validate: $P is not an executable (build it first)"; exit 1; }
if ! $PY -c 'import numpy' >/dev/null 2>&1; then
  echo "test_validate: skipped (no NumPy for $PY)"
  exit 0
fi
cd "$T" || exit 1
$PY "$ROOT/examples/npy_example/make_model.py" m >/dev/null || { echo "FAIL: make_model.py"; exit 1; }
$PY -c "import numpy as np; t = np.arange(1001) * 0.1; np.save('sin2.npy', 0.1 * np.sin(2 * t))" || exit 1
M="--J m/J.npy --R m/R.npy --B m/B.npy --Q m/Q.npy --simulate --quiet"

# 1. a sound model passes
$P validate $M --method gmg-pod --r 12 --out o1 --test-input sin --test-input const > v1.txt 2>&1
rc=$?
[ $rc -eq 0 ] && pass || bad "GMG-POD r=12: exit $rc (expected 0)"
grep -q "validate: passed" v1.txt && pass || bad "GMG-POD r=12: no 'validate: passed'"
[ "$(grep -c ' pass$' v1.txt)" -eq 2 ] && pass || bad "GMG-POD r=12: expected two passing test inputs"
[ -f o1/rom.phgmgrom ] && pass || bad "validate did not write the model"

# 2. an overfitted quadratic manifold fails, with the first failing step
$P validate $M --method gmg-qm --r 8 --lambda 1e-12 --out o2 --test-input const > v2.txt 2>&1
rc=$?
[ $rc -eq 1 ] && pass || bad "GMG-QM lambda=1e-12 on u = 0.1: exit $rc (expected 1)"
grep -q "above --max-ey" v2.txt && pass || bad "GMG-QM on u = 0.1: no e_y verdict"
$P validate $M --method gmg-qm --r 8 --lambda 1e-12 --out o3 --test-input sin --test-input sin2.npy > v3.txt 2>&1
rc=$?
[ $rc -eq 1 ] && pass || bad "GMG-QM lambda=1e-12 on sin 2t: exit $rc (expected 1)"
step=$(sed -n 's/.*first failing step: \([0-9]*\) .*/\1/p' v3.txt | head -1)
if [ -n "$step" ] && [ "$step" -ge 1 ] && [ "$step" -le 999 ]; then pass; else bad "no first failing step reported (got '$step')"; cat v3.txt; fi
grep -q "^sin  .* pass$" v3.txt && pass || bad "the training input should pass (v3)"

# 2b. the same reduction with the validated lambda (--lambda auto)
#     passes where lambda = 1e-12 failed: u = 0.1 and u = 0.1 sin 2t; also with
#     the altmin manifold
for man in pod altmin; do
  $P validate $M --method gmg-qm --r 8 --lambda auto --manifold $man --out o6 --test-input sin --test-input const \
     --test-input sin2.npy > v6.txt 2>&1
  rc=$?
  [ $rc -eq 0 ] && pass || { bad "GMG-QM --lambda auto --manifold $man r=8: exit $rc (expected 0)"; cat v6.txt; }
  [ "$(grep -c ' pass$' v6.txt)" -eq 3 ] && pass || bad "GMG-QM --lambda auto --manifold $man: expected three passing inputs"
done

# 3. usage
$P validate $M --method gmg-pod --r 12 --out o4 --max-ey > /dev/null 2>&1
[ $? -eq 2 ] && pass || bad "--max-ey without a value: expected exit 2"
$P validate --J m/J.npy --R m/R.npy --B m/B.npy --Q m/Q.npy --X nothing.npy --method gmg-pod --r 12 --out o5 > /dev/null 2>&1
[ $? -eq 2 ] && pass || bad "validate with --X and no test input: expected exit 2"

# 4. validate checks against the model that was reduced: a nonlinear potential
#    (toda on every spring, amplitude 1 so that it matters). On the training
#    input the full run equals the training snapshots, so the reported e_proj
#    must equal the projection error of the saved snapshots onto span(V0),
#    computed here by NumPy (before the fix validate simulated the linear part
#    only and reported the linear trajectory's e_proj).
$PY -c "import numpy as np; np.save('idx.npy', np.arange(0, 100, 2))" || exit 1
$P validate $M --potential toda --poly-idx idx.npy --no-deim --amp 1 --method gmg-pod --r 12 --out o7 \
   --save-snapshots --max-ey 1 > v7.txt 2>&1
rc=$?
[ $rc -eq 0 ] && pass || { bad "toda validate: exit $rc (expected 0)"; cat v7.txt; }
ep=$(awk '$1 == "sin" {print $4}' v7.txt)
$PY - "$ep" <<'PYEOF' && pass || bad "toda validate: e_proj $ep is not the projection error of the training snapshots"
import sys, numpy as np
X = np.load('o7/rom_snapshots.npy'); V = np.load('o7/rom_V0.npy')
Qb, _ = np.linalg.qr(V)
e = np.linalg.norm(X - Qb @ (Qb.T @ X)) / np.linalg.norm(X)
ep = float(sys.argv[1])
ok = abs(ep - e) <= 1e-3 * e   # validate prints 4 significant digits
print("toda: e_proj reported %.6e, NumPy %.6e" % (ep, e))
sys.exit(0 if ok else 1)
PYEOF

# 5. several --X files (one run each) with their inputs (--X-input) give the
#    same reduced model as simulating the same runs (--simulate --train-input):
#    boundaries and inputs reach --lambda auto; with --X and no known input,
#    validate needs --test-input; the counts must match.
N5="--J m/J.npy --R m/R.npy --B m/B.npy --Q m/Q.npy --quiet"
$P reduce $N5 --simulate --input sin --method gmg-pod --r 4 --out s1 --save-snapshots > /dev/null 2>&1 || bad "snapshots 1"
$P reduce $N5 --simulate --input sin2.npy --method gmg-pod --r 4 --out s2 --save-snapshots > /dev/null 2>&1 || bad "snapshots 2"
$P reduce $N5 --simulate --train-input sin --train-input sin2.npy --method gmg-qm --r 10 --lambda auto --out a1 \
   > /dev/null 2>&1 || bad "reduce --train-input x2"
$P validate $N5 --X s1/rom_snapshots.npy --X s2/rom_snapshots.npy --X-input sin --X-input sin2.npy --method gmg-qm \
   --r 10 --lambda auto --out a2 > v8.txt 2>&1
rc=$?
[ $rc -eq 0 ] && pass || { bad "validate --X x2 --X-input x2: exit $rc (expected 0)"; cat v8.txt; }
[ "$(grep -c ' pass$' v8.txt)" -eq 2 ] && pass || bad "validate --X: expected the two --X-input runs as test inputs"
$PY - <<'PYEOF' && pass || bad "--X x2 with --X-input: not the model of --simulate --train-input x2"
import json, sys, numpy as np
a, b = json.load(open('a1/rom.json')), json.load(open('a2/rom.json'))
ok = a["options"]["lambda_used"] == b["options"]["lambda_used"] and b["options"]["training_runs"] == 2
for f in ("Qh", "G11", "Q11", "Ms", "V0"):
    x, y = np.load('a1/rom_%s.npy' % f), np.load('a2/rom_%s.npy' % f)
    ok = ok and x.shape == y.shape and np.allclose(x, y, rtol=1e-9, atol=1e-12 * max(1.0, np.abs(x).max()))
print("lambda_used", a["options"]["lambda_used"], b["options"]["lambda_used"])
sys.exit(0 if ok else 1)
PYEOF
$P reduce $N5 --X s1/rom_snapshots.npy --X s2/rom_snapshots.npy --method gmg-qm --r 10 --lambda cv --out a3 > /dev/null 2>&1 \
  && grep -q '"training_runs": 2' a3/rom.json && pass || bad "--X x2 --lambda cv: the run boundaries were not passed"
$P validate $N5 --X s1/rom_snapshots.npy --method gmg-pod --r 10 --out a4 > /dev/null 2>&1
[ $? -eq 2 ] && pass || bad "validate --X without a test input: expected exit 2"
$P reduce $N5 --X s1/rom_snapshots.npy --X s2/rom_snapshots.npy --X-input sin --method gmg-pod --r 10 --out a5 > /dev/null 2>&1
[ $? -eq 2 ] && pass || bad "2 --X, 1 --X-input: expected exit 2"

# 6. gmg-qm's default lambda is the validated one (--lambda auto): on random
#    chains (tests/random_chain.py: random masses, stiffnesses, damping, states
#    in a random order; N = 300) the paper's fixed lambda = 1e-3 gives a model
#    whose Newton solve fails on u = 0.1 (measured at every seed 1..6), the
#    default passes on u = 0.1 and u = 0.1 sin t.
for seed in 1 5; do
  $PY "$ROOT/tests/random_chain.py" $seed rc$seed || exit 1
  RC="--J rc$seed/J.npy --R rc$seed/R.npy --B rc$seed/B.npy --Q rc$seed/Q.npy --simulate --steps 200 --quiet"
  $P validate $RC --method gmg-qm --r 12 --lambda 1e-3 --out rq$seed --test-input const --test-input sin > v9.txt 2>&1
  rc=$?
  [ $rc -eq 1 ] && pass || bad "random chain $seed, lambda 1e-3: exit $rc (expected 1: the trap the default avoids)"
  $P validate $RC --method gmg-qm --r 12 --out rd$seed --test-input const --test-input sin > v10.txt 2>&1
  rc=$?
  [ $rc -eq 0 ] && pass || { bad "random chain $seed, default lambda: exit $rc (expected 0)"; cat v10.txt; }
  grep -q '"lambda": "auto"' rd$seed/rom.json && pass || bad "random chain $seed: the default lambda is not auto"
done

# 7. a small model (N = 10): gmg-qm without --rn takes the largest r_n that
#    fits (r + r_n <= N: 6 at r = 4) instead of refusing the default 8
$PY "$ROOT/tests/random_chain.py" 3 small 5 || exit 1
$P reduce --J small/J.npy --R small/R.npy --B small/B.npy --Q small/Q.npy --simulate --steps 200 --quiet \
   --method gmg-qm --r 4 --out sq > /dev/null 2>&1 && grep -q '"rn": 6' sq/rom.json && pass \
  || bad "N = 10, gmg-qm r = 4 without --rn: expected r_n = 6"
$P reduce --J small/J.npy --R small/R.npy --B small/B.npy --Q small/Q.npy --simulate --steps 200 --quiet \
   --method gmg-qm --r 4 --rn 8 --out sq2 > /dev/null 2>&1
[ $? -eq 2 ] && pass || bad "N = 10, --rn 8 at r = 4: expected the usage error"

# 8. a failing validate leaves the deployed model alone; bounds and
#    test inputs are checked before any computation.
M8="--J m/J.npy --R m/R.npy --B m/B.npy --Q m/Q.npy --simulate --quiet"
$P reduce $M8 --method gmg-pod --r 12 --out dep > /dev/null 2>&1 || bad "deploy a model"
(cd dep && cksum rom.phgmgrom rom.c rom.json rom_*.npy) > dep_before.txt
$P validate $M8 --method gmg-qm --r 8 --lambda 1e-12 --out dep --test-input const > v11.txt 2>&1
rc=$?
[ $rc -eq 1 ] && pass || bad "failing validate into dep: exit $rc (expected 1)"
(cd dep && cksum rom.phgmgrom rom.c rom.json rom_*.npy) > dep_after.txt
cmp -s dep_before.txt dep_after.txt && pass || bad "a failing validate replaced the deployed model in dep"
ls dep | grep -q '\.tmp$' && bad "a failing validate left temporary files in dep" || pass
grep -q "not written" v11.txt && pass || bad "a failing validate does not say that the model was not written"
$P validate $M8 --method gmg-qm --r 8 --lambda 1e-12 --out newdir/sub --test-input const > /dev/null 2>&1
[ -e newdir ] && bad "a failing validate left the directory it created" || pass
# --max-ey must be a bound: 0 or negative refused; validate's options once each
for bad_ey in 0 -1 0.0; do
  $P validate $M8 --steps 50 --method gmg-pod --r 4 --out o12 --max-ey $bad_ey > v12.txt 2>&1
  rc=$?
  [ $rc -eq 2 ] && pass || bad "--max-ey $bad_ey: exit $rc (expected 2)"
done
for o in "--max-ey 0.5 --max-ey 1" "--test-amp 1 --test-amp 2" "--test-steps 10 --test-steps 20"; do
  $P validate $M8 --steps 50 --method gmg-pod --r 4 --out o12 $o > v12.txt 2>&1
  rc=$?
  [ $rc -eq 2 ] && grep -q "given more than once" v12.txt && pass || bad "repeated '$o': exit $rc (expected 2)"
done
[ -e o12 ] && bad "refused validate runs wrote o12" || pass
# a bad --test-input is found before the reduction and nothing is written
$P validate --J m/J.npy --R m/R.npy --B m/B.npy --Q m/Q.npy --simulate --method gmg-pod --r 12 --out o13 \
   --test-input sin --test-input square > v13.txt 2>&1
rc=$?
[ $rc -eq 2 ] && grep -q -- "--test-input 'square'" v13.txt && pass || bad "--test-input square: exit $rc (expected 2)"
grep -q "simulating\|reducing" v13.txt && bad "--test-input square found after the computation" || pass
$P validate --J m/J.npy --R m/R.npy --B m/B.npy --Q m/Q.npy --simulate --method gmg-pod --r 12 --out o13 \
   --test-input m/J.npy > v13.txt 2>&1
rc=$?
[ $rc -eq 1 ] && grep -q "m/J.npy (--test-input)" v13.txt && pass || bad "--test-input m/J.npy: exit $rc, $(cat v13.txt)"
grep -q "simulating\|reducing" v13.txt && bad "a bad --test-input file found after the computation" || pass
[ -e o13 ] && bad "validate with a bad --test-input wrote o13" || pass
# --test-steps beyond the 4 GiB cap: refused up front
$P validate $M8 --method gmg-pod --r 12 --out o14 --test-steps 2000000000 > v14.txt 2>&1
rc=$?
[ $rc -eq 2 ] && grep -q "would need" v14.txt && pass || bad "--test-steps 2e9: exit $rc (expected 2, 'would need')"
TO=; command -v timeout >/dev/null 2>&1 && TO="timeout 60"   # refused up front: instant; a regression must not hang
$TO $P validate --J m/J.npy --R m/R.npy --B m/B.npy --Q m/Q.npy --simulate --method gmg-pod --r 12 --out o14 \
   --test-steps 10000000 > v14.txt 2>&1
rc=$?
[ $rc -eq 2 ] && grep -q "would need" v14.txt && pass || bad "--test-steps 1e7 (N = 100): exit $rc (expected 2)"
grep -q "simulating\|reducing" v14.txt && bad "--test-steps 1e7 refused only after the computation" || pass
[ -e o14 ] && bad "a refused --test-steps wrote o14" || pass

# 6: huge test amplitudes: an overflow is reported as one (or the norms are
#    computed without overflowing), never as "out of memory"
$P validate $M8 --steps 100 --method gmg-pod --r 8 --out o6a --test-input sin --test-amp 1e160 > v6a.txt 2>&1
rc=$?
if grep -q "out of memory" v6a.txt; then bad "--test-amp 1e160 reported as out of memory"
elif [ $rc -eq 1 ] && grep -q "overflow" v6a.txt; then pass
elif [ $rc -eq 0 ] && grep -q "^sin  .* pass$" v6a.txt; then pass
else bad "--test-amp 1e160: exit $rc: $(tail -n 2 v6a.txt)"; fi

# 9. inputs and records.
# 5: a symmetric two-port chain (ports on the first and the last mass): with
#    the same signal on both ports the states never leave the symmetric half
#    and GMG's non-degeneracy check fails at every r; the default sin drives
#    each port at its own frequency. Identical inputs are pointed out.
$PY - <<'PYEOF' || exit 1
import numpy as np, os
n = 20; N = 2 * n; os.makedirs('sym', exist_ok=True)
K = 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
Q = np.zeros((N, N)); Q[:n, :n] = K; Q[n:, n:] = np.eye(n)
J = np.zeros((N, N)); J[:n, n:] = np.eye(n); J[n:, :n] = -np.eye(n)
R = np.zeros((N, N)); R[n:, n:] = 0.2 * np.eye(n)
B = np.zeros((N, 2)); B[n, 0] = 1; B[N - 1, 1] = 1
for k, v in dict(J=J, R=R, Q=Q, B=B).items(): np.save('sym/%s.npy' % k, v)
t = np.arange(301) * 0.1
np.save('sym/same.npy', np.column_stack([t, 0.1 * np.sin(t), 0.1 * np.sin(t)]))
PYEOF
SY="--J sym/J.npy --R sym/R.npy --Q sym/Q.npy --B sym/B.npy --simulate --steps 300"
for r in 6 10; do
  $P reduce $SY --method gmg-pod --r $r --out sy --quiet > v15.txt 2>&1
  rc=$?
  [ $rc -eq 0 ] && pass || bad "symmetric 2-port chain, default input, r = $r: exit $rc ($(tail -n 1 v15.txt))"
done
$P reduce $SY --input sym/same.npy --method gmg-pod --r 6 --out sy2 --quiet > v15.txt 2>&1
grep -q "not excited independently" v15.txt && pass || bad "the same table column on both ports is not pointed out"
$P reduce $SY --input const --method gmg-pod --r 6 --out sy2 --quiet > v15.txt 2>&1
grep -q "not excited independently" v15.txt && pass || bad "--input const on two ports is not pointed out"
$P --help | grep -q "own frequency" && pass || bad "--help does not say that sin excites each port at its own frequency"

# 11: the declared --X-input must reproduce the first steps of its run
#     (s1: snapshots of u = 0.1 sin t, dt = 0.1)
$P reduce $N5 --X s1/rom_snapshots.npy --X-input const --method gmg-pod --r 8 --out x11 > v16.txt 2>&1
rc=$?
[ $rc -eq 1 ] && grep -q "does not reproduce" v16.txt && pass || bad "--X-input const for sin snapshots: exit $rc (expected 1)"
$P reduce $N5 --X s1/rom_snapshots.npy --X-input sin --dt 0.05 --method gmg-pod --r 8 --out x11 > v16.txt 2>&1
rc=$?
[ $rc -eq 1 ] && grep -q "does not reproduce" v16.txt && pass || bad "--X-input sin with the wrong --dt: exit $rc (expected 1)"
$P validate $N5 --X s1/rom_snapshots.npy --X-input const --method gmg-qm --r 10 --out x11 > v16.txt 2>&1
rc=$?
[ $rc -eq 1 ] && [ ! -e x11 ] && pass || bad "validate with a wrong --X-input: exit $rc (expected 1, nothing written)"

# 27: validate with --X runs the training run's length from its first snapshot:
#     on the training input the full run is the snapshots, so e_proj equals
#     their projection error onto span(V0) (NumPy); a run of --steps 1000
#     would not. An input table that ends early is pointed out.
$P reduce $N5 --simulate --steps 300 --method gmg-pod --r 4 --out s3 --save-snapshots > /dev/null 2>&1 || bad "snapshots 3"
$P validate $N5 --X s3/rom_snapshots.npy --X-input sin --method gmg-pod --r 8 --out x27 > v17.txt 2>&1
rc=$?
[ $rc -eq 0 ] && pass || { bad "validate --X (300 steps): exit $rc"; cat v17.txt; }
ep=$(awk '$1 == "sin" {print $4}' v17.txt)
$PY - "$ep" <<'PYEOF' && pass || bad "validate --X: e_proj $ep is not the projection error of the 300-step training run"
import sys, numpy as np
X = np.load('s3/rom_snapshots.npy'); V = np.load('x27/rom_V0.npy')
Qb, _ = np.linalg.qr(V)
e = np.linalg.norm(X - Qb @ (Qb.T @ X)) / np.linalg.norm(X)
ep = float(sys.argv[1])
print("validate --X: e_proj reported %.6e, NumPy %.6e" % (ep, e))
sys.exit(0 if abs(ep - e) <= 1e-3 * e else 1)
PYEOF
$PY -c "import numpy as np; t = np.arange(101) * 0.1; np.save('short.npy', np.column_stack([t, 0.1 * np.sin(t)]))"
$P validate $N5 --simulate --steps 300 --method gmg-pod --r 8 --out x27b --test-input short.npy > v18.txt 2>&1
grep -q "short.npy (--test-input) ends at t = 10" v18.txt && pass || bad "an input table ending before the run is not pointed out"
$P reduce $N5 --X s3/rom_snapshots.npy --method gmg-qm --r 8 --lambda auto --out x27c > v19.txt 2>&1
rc=$?
[ $rc -eq 2 ] && grep -q "needs the inputs of the runs" v19.txt && pass || bad "--lambda auto with --X, no --X-input: exit $rc (expected 2)"
$P reduce $N5 --X s3/rom_snapshots.npy --method gmg-qm --r 8 --out x27c > v19.txt 2>&1
rc=$?
[ $rc -eq 0 ] && grep -q "M = 0" v19.txt && grep -q '"lambda_note"' x27c/rom.json && pass \
  || bad "gmg-qm with --X, no --X-input: M = 0 not said (exit $rc)"

# 12: a huge --dt-map: the step map written must not amplify (spectral
#     radius <= 1, NumPy), or the run is refused naming --dt-map
for d in 1e15 1e300; do
  $P reduce $N5 --simulate --steps 300 --method gmg-pod --r 8 --dt-map $d --out x12 > v20.txt 2>&1
  rc=$?
  if [ $rc -eq 0 ]; then
    $PY -c "
import numpy as np, sys
rho = max(abs(np.linalg.eigvals(np.load('x12/rom_Phi.npy'))))
print('dt-map $d: spectral radius', rho); sys.exit(0 if rho <= 1 + 1e-6 else 1)" && pass || bad "--dt-map $d: unstable step map written"
  else
    [ $rc -eq 1 ] && grep -q -- "--dt-map" v20.txt && pass || bad "--dt-map $d: exit $rc without naming --dt-map"
  fi
  rm -rf x12
done

# 21: the record names the hyper-reduction (method, tolerance, smallest
#     weight, residual); "deim" only for DEIM; gmg-pod records carry no lambda
$P reduce $M --steps 300 --potential toda --poly-idx idx.npy --amp 1 --method gmg-pod --r 12 --out j21 > /dev/null 2>&1 \
  || bad "reduce toda ecsw"
$P reduce $M --steps 300 --potential toda --poly-idx idx.npy --amp 1 --hyper qdeim --deim-allow-negative \
   --method gmg-pod --r 12 --out j21q > /dev/null 2>&1 || bad "reduce toda qdeim"
$PY - <<'PYEOF' && pass || bad "json records of the hyper-reduction / lambda"
import json, sys
e, q = json.load(open('j21/rom.json')), json.load(open('j21q/rom.json'))
ok = e["options"]["hyper"] == "ecsw" and e["options"]["deim"] is False and e["options"]["hyper_tol"] == 1e-6
h = e["info"]["hyper"]
ok = ok and h["method"] == "ecsw" and h["min_weight"] >= 0 and 0 <= h["residual"] <= 1e-6 and h["points"] == e["nd"]
ok = ok and q["options"]["hyper"] == "qdeim" and q["options"]["deim"] is True and q["info"]["hyper"]["method"] == "qdeim"
ok = ok and all(k not in e["options"] for k in ("lambda", "lambda_used", "rn", "manifold"))
print("ecsw:", e["options"], e["info"]["hyper"]); print("qdeim:", q["options"], q["info"]["hyper"])
sys.exit(0 if ok else 1)
PYEOF

echo "test_validate: $npass passed, $nfail failed"
[ $nfail -eq 0 ]
