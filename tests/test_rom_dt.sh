#!/bin/sh
# test_rom_dt.sh — the step a reduced model was trained at, recorded by reduce
# and used by simulate-rom.
#
# Usage: sh tests/test_rom_dt.sh build/phgmg      (from the repository root; also
#        run on build/phgmg-float, whose model files hold dt as a float)
#
# A mass-spring chain of 4 masses (N = 8, damped, one force port), GMG-POD
# r = 4 without a step map (--dt-map 0):
# 1. trained by --simulate at --dt 0.02: simulate-rom without --dt steps at
#    0.02 (the log says so, the output equals that of --dt 0.02 exactly and
#    differs from that of --dt 0.1); --dt 0.05 takes precedence, with a note
#    naming the training dt; info shows it.
# 2. trained on --X snapshots with --dt 0.02: the same default; without --dt
#    the model records no step: simulate-rom steps at 0.1 and says so.
# 3. a model with a step map (--dt-map 0.04) still defaults to the map's step.
# 4. reduce's --degeneracy-tol reaches the library: 0.99 refuses the chain's
#    model with a message naming the option and the measure; 0 is a usage
#    error.
# 5. the log of a full-model simulation of a nonlinear model (Toda springs)
#    names the Newton tolerance used (the default, relative, or --newton-tol)
#    and how to tighten it; a linear model's log has no such line.
# Needs NumPy to write the matrices (skipped with a note otherwise).
set -u
P=${1:-build/phgmg}
case "$P" in /*) ;; *) P="$PWD/$P" ;; esac
PY=/usr/bin/python3
T=$(mktemp -d "${TMPDIR:-/tmp}/phgmg_romdt.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT INT TERM
npass=0
nfail=0
pass() { npass=$((npass + 1)); }
bad() { echo "FAIL: $*"; nfail=$((nfail + 1)); }
[ -x "$P" ] || { echo "test_rom_dt: $P is not an executable (build it first)"; exit 1; }
cd "$T" || exit 1
if ! "$PY" -c 'import numpy' 2>/dev/null; then
  echo "test_rom_dt: skipped ($PY has no NumPy)"
  exit 0
fi
"$PY" - <<'PYEOF' || bad "writing the chain"
import numpy as np
n = 4
K = 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
Z = np.zeros((n, n))
J = np.block([[Z, np.eye(n)], [-np.eye(n), Z]])
R = np.block([[Z, Z], [Z, 0.2 * np.eye(n)]])
Q = np.block([[K, Z], [Z, np.eye(n)]])
B = np.zeros(2 * n); B[n] = 1.0
idx = np.arange(n)
for k, v in dict(J=J, R=R, Q=Q, B=B, idx=idx).items():
    np.save(k + ".npy", v)
PYEOF
SYS="--J J.npy --R R.npy --Q Q.npy --B B.npy"
same() { "$PY" -c "import numpy as np, sys; a, b = np.load('$1'), np.load('$2'); sys.exit(0 if a.shape == b.shape and (a == b).all() else 1)"; }

# 1. --simulate at dt 0.02, no step map
"$P" reduce $SYS --simulate --dt 0.02 --steps 300 --method gmg-pod --r 4 --dt-map 0 --save-snapshots --out o1 \
  >/dev/null 2>err.txt && pass || bad "reduce --simulate: $(tail -n 2 err.txt)"
"$P" simulate-rom --model o1/rom.phgmgrom --steps 100 --out yd.npy >/dev/null 2>err.txt && pass \
  || bad "simulate-rom: $(tail -n 2 err.txt)"
grep -q "steps of dt = 0.02" err.txt && pass || bad "simulate-rom without --dt does not step at 0.02: $(cat err.txt)"
grep -q "note:" err.txt && bad "a note without a reason: $(cat err.txt)" || pass
"$P" simulate-rom --model o1/rom.phgmgrom --steps 100 --dt 0.02 --out y02.npy >/dev/null 2>&1 && pass || bad "--dt 0.02"
"$P" simulate-rom --model o1/rom.phgmgrom --steps 100 --dt 0.1 --out y10.npy >/dev/null 2>&1 && pass || bad "--dt 0.1"
same yd.npy y02.npy && pass || bad "the default output differs from --dt 0.02's"
same yd.npy y10.npy && bad "the default output equals --dt 0.1's" || pass
"$P" simulate-rom --model o1/rom.phgmgrom --steps 100 --dt 0.05 --out y05.npy >/dev/null 2>err.txt && pass \
  || bad "--dt 0.05: $(tail -n 2 err.txt)"
grep -q "steps of dt = 0.05" err.txt && pass || bad "--dt 0.05 does not take precedence: $(cat err.txt)"
grep -q "note: --dt 0.05 differs from the model's training dt 0.02" err.txt && pass \
  || bad "no note on --dt differing from the training dt: $(cat err.txt)"
grep -q '"dt": 0.02' o1/rom.json && pass || bad "rom.json does not record the training dt"
grep -q '"degeneracy_tol": 1e-12' o1/rom.json && pass || bad "rom.json does not record the degeneracy tolerance"
"$P" info o1/rom.phgmgrom 2>&1 | grep -q "trained at dt = 0.02" && pass || bad "info does not show the training dt"

# 2. --X snapshots with and without --dt
"$P" reduce $SYS --X o1/rom_snapshots.npy --dt 0.02 --method gmg-pod --r 4 --out o2 >/dev/null 2>err.txt && pass \
  || bad "reduce --X --dt: $(tail -n 2 err.txt)"
"$P" simulate-rom --model o2/rom.phgmgrom --steps 100 --out y2.npy >/dev/null 2>err.txt && pass \
  || bad "simulate-rom (--X model): $(tail -n 2 err.txt)"
grep -q "steps of dt = 0.02" err.txt && pass || bad "the --X model does not step at 0.02: $(cat err.txt)"
"$P" reduce $SYS --X o1/rom_snapshots.npy --method gmg-pod --r 4 --out o3 >/dev/null 2>err.txt && pass \
  || bad "reduce --X: $(tail -n 2 err.txt)"
"$P" simulate-rom --model o3/rom.phgmgrom --steps 100 --out y3.npy >/dev/null 2>err.txt && pass \
  || bad "simulate-rom (no dt recorded): $(tail -n 2 err.txt)"
grep -q "steps of dt = 0.1" err.txt && grep -q "note: the model records no training step" err.txt && pass \
  || bad "a model without a recorded step: $(cat err.txt)"

# 3. a step map's step stays the default
"$P" reduce $SYS --simulate --dt 0.02 --steps 300 --method gmg-pod --r 4 --dt-map 0.04 --out o4 >/dev/null 2>err.txt \
  && pass || bad "reduce --dt-map 0.04: $(tail -n 2 err.txt)"
"$P" simulate-rom --model o4/rom.phgmgrom --steps 100 --out y4.npy >/dev/null 2>err.txt && pass \
  || bad "simulate-rom (step map): $(tail -n 2 err.txt)"
grep -q "steps of dt = 0.04 (precomputed step map)" err.txt && pass || bad "the step map's dt: $(cat err.txt)"

# 4. --degeneracy-tol
"$P" reduce $SYS --simulate --dt 0.02 --steps 300 --method gmg-pod --r 4 --degeneracy-tol 0.99 --out o5 \
  >/dev/null 2>err.txt
[ $? -eq 1 ] && pass || bad "--degeneracy-tol 0.99 did not refuse the model"
grep -q "is below --degeneracy-tol 0.99" err.txt && pass || bad "the refusal does not name the option: $(cat err.txt)"
"$P" reduce $SYS --simulate --method gmg-pod --r 4 --degeneracy-tol 0 --out o6 >/dev/null 2>err.txt
[ $? -eq 2 ] && grep -q "degeneracy-tol" err.txt && pass || bad "--degeneracy-tol 0: $(cat err.txt)"

# 5. the Newton tolerance in the log
NL="--potential toda --poly-idx idx.npy"
"$P" simulate $SYS $NL --steps 50 --out yn.npy >/dev/null 2>err.txt && pass || bad "simulate (toda): $(tail -n 2 err.txt)"
grep -q "Newton tolerance: the default, 1e-10 x max(1, |x|, |stage increment|)" err.txt \
  && grep -q "give --newton-tol" err.txt && pass || bad "the default Newton tolerance is not in the log: $(cat err.txt)"
"$P" simulate $SYS $NL --steps 50 --newton-tol 1e-13 --out yn2.npy >/dev/null 2>err.txt && pass \
  || bad "simulate --newton-tol 1e-13: $(tail -n 2 err.txt)"
grep -q "Newton tolerance 1e-13 (absolute, --newton-tol)" err.txt && pass || bad "--newton-tol not in the log: $(cat err.txt)"
"$P" reduce $SYS $NL --simulate --steps 50 --method gmg-pod --r 4 --no-hyper --out o7 >/dev/null 2>err.txt && pass \
  || bad "reduce --simulate (toda): $(tail -n 2 err.txt)"
grep -q "Newton tolerance: the default" err.txt && pass || bad "reduce's log lacks the Newton tolerance: $(cat err.txt)"
"$P" simulate $SYS --steps 50 --out yl.npy >/dev/null 2>err.txt && pass || bad "simulate (linear): $(tail -n 2 err.txt)"
grep -q "Newton tolerance" err.txt && bad "a linear model's log names a Newton tolerance: $(cat err.txt)" || pass

echo "test_rom_dt: $npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
