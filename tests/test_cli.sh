#!/bin/sh
# test_cli.sh — tests of the `phgmg` command-line reducer (examples/phgmg_cli.c).
#
# Usage: sh tests/test_cli.sh build/phgmg      (from the repository root)
#
# 1. --help explains every option; bad usage exits 2.
# 2. The worked example's model (examples/npy_example/make_model.py, NumPy) is
#    exactly the paper's linear MSD of examples/msd_models.h (written by
#    tests/cli_ref.c with phgmg_npy_write).
# 3. Acceptance: the CLI's GMG-POD-ROM (r = 12, u = 0.1 sin t, dt = 0.1, 1000
#    steps, snapshots by --simulate), run by `phgmg simulate-rom`, has the same
#    output as the library's own demo path (tests/cli_ref.c: phgmg_simulate,
#    phgmg_reduce, phgmg_reduced_simulate as examples/msd_linear.c does) to
#    1e-12 relative; likewise GMG-QM and SP1, and GMG-POD with a polynomial
#    nonlinearity and DEIM (--poly) on the nonlinear MSD. A negative control
#    (r = 11 against r = 12) shows the comparison can fail.
# 4. The exported C source compiles as firmware would use it and gives the
#    same output; the .npy outputs read with NumPy have the announced shapes
#    and the pH structure (Bh = [I; 0], V0 = [B, V1], Qh > 0, sym(K) <= 0);
#    compare.py's exact (eigendecomposition) full-model response agrees with
#    phgmg's Gauss-Legendre simulation.
# 5. Input files (--input FILE.npy) and the error paths: missing file,
#    malformed and truncated .npy, wrong shapes, non-skew J, non-symmetric R,
#    NaN, bad names and options -> nonzero exit and a message naming the file.
# Parts that need NumPy are skipped (with a note) if /usr/bin/python3 has none.
# Exit status 0 if every check passed.
set -u
P=${1:-build/phgmg}
case "$P" in /*) ;; *) P="$PWD/$P" ;; esac
CC=${CC:-cc}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PY=/usr/bin/python3
T=$(mktemp -d "${TMPDIR:-/tmp}/phgmg_cli.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT INT TERM
npass=0
nfail=0
pass() { npass=$((npass + 1)); }
bad() { echo "FAIL: $*"; nfail=$((nfail + 1)); }

[ -x "$P" ] || { echo "test_cli: $P is not an executable (build it first)"; exit 1; }
cd "$T" || exit 1

# run_ok NAME CMD...: the command must exit 0
run_ok() {
  name=$1; shift
  if "$@" >"$T/out.txt" 2>"$T/err.txt"; then pass; else bad "$name: exit $? ($(tail -n 3 "$T/err.txt"))"; fi
}
# run_err NAME STATUS PATTERN CMD...: the command must exit with STATUS and
# print PATTERN (fixed string, e.g. the offending file) on stderr
run_err() {
  name=$1; want=$2; pat=$3; shift 3
  "$@" >"$T/out.txt" 2>"$T/err.txt"
  st=$?
  if [ "$st" -ne "$want" ]; then bad "$name: exit $st, expected $want ($(tail -n 2 "$T/err.txt"))"
  elif ! grep -F -q -- "$pat" "$T/err.txt"; then bad "$name: stderr does not mention '$pat': $(tail -n 2 "$T/err.txt")"
  else pass; fi
}

# ---- the reference program ------------------------------------------------
REF="$T/cli_ref"
if ! $CC -std=c99 -O0 -o "$REF" "$ROOT/tests/cli_ref.c" -lm 2>"$T/cc.txt"; then
  cat "$T/cc.txt"; echo "test_cli: cannot build tests/cli_ref.c"; exit 1
fi

# ---- 1. help and usage --------------------------------------------------------
run_ok "help" "$P" --help
for o in --J --R --B --Q --X --simulate --dt --steps --input --amp --newton-tol --newton-iter --method \
         gmg-pod gmg-qm sp1 sp2 --r --rn --lambda --poly --poly-idx --poly-w --no-deim --deim-tol --deim-max \
         --deim-allow-negative --dt-map --out --name --save-snapshots --quiet simulate-rom --model --states \
         .phgmgrom _V0.npy .json "EXIT STATUS" EXAMPLES; do
  grep -F -q -- "$o" "$T/out.txt" || bad "--help does not explain $o"
done
run_ok "reduce --help" "$P" reduce --help
run_err "no arguments" 2 "usage" "$P"
run_err "unknown command" 2 "frobnicate" "$P" frobnicate

# ---- 2. the model: make_model.py (NumPy) == msd_models.h ------------------------
mkdir -p cmodel model
run_ok "cli_ref model" "$REF" model cmodel
HAVE_NP=0
if [ -x "$PY" ] && "$PY" -c "import numpy" 2>/dev/null; then HAVE_NP=1; fi
if [ "$HAVE_NP" = 1 ]; then
  run_ok "make_model.py" "$PY" "$ROOT/examples/npy_example/make_model.py" model
  for k in J R B Q; do run_ok "make_model.py $k == msd_models.h" "$REF" compare cmodel/$k.npy model/$k.npy 0; done
else
  echo "test_cli: note: no NumPy for $PY; using the C-written model and skipping the Python parts"
  cp cmodel/*.npy model/
fi
SYS="--J model/J.npy --R model/R.npy --B model/B.npy --Q model/Q.npy"
SIM="--simulate --dt 0.1 --steps 1000 --input sin --amp 0.1"
ROMSIM="--dt 0.1 --steps 1000 --input sin --amp 0.1"

# ---- 3. acceptance: CLI == library demo path ------------------------------------
run_ok "reduce gmg-pod" "$P" reduce $SYS $SIM --method gmg-pod --r 12 --out out --name msd --save-snapshots
grep -F -q "out/msd.phgmgrom" "$T/out.txt" || bad "reduce does not report what it wrote"
grep -F -q "simulating the full model" "$T/err.txt" || bad "reduce prints no progress on stderr"
for f in msd.phgmgrom msd.c msd.json msd_Bh.npy msd_Qh.npy msd_K.npy msd_Phi.npy msd_Gam.npy msd_SX.npy \
         msd_SU.npy msd_V0.npy msd_snapshots.npy msd_fom_y.npy; do
  [ -s "out/$f" ] || bad "reduce did not write out/$f"
done
run_ok "simulate-rom gmg-pod" "$P" simulate-rom --model out/msd.phgmgrom $ROMSIM --out out/y_rom.npy --states out/xr.npy
run_ok "ref gmg-pod" "$REF" ref linear gmg-pod 12 ref_gmg-pod.npy
run_ok "ACCEPTANCE gmg-pod r=12 CLI == demo path (1e-12)" "$REF" compare ref_gmg-pod.npy out/y_rom.npy 1e-12
cat "$T/out.txt"
run_ok "info" "$P" info out/msd.phgmgrom
grep -F -q "r = 12, m = 1" "$T/out.txt" || bad "info does not print the sizes"

# the same reduction from the saved snapshots (--X) gives the same model
run_ok "reduce --X" "$P" reduce $SYS --X out/msd_snapshots.npy --dt-map 0.1 --method gmg-pod --r 12 --out ox --name m --quiet
run_ok "simulate-rom --X model" "$P" simulate-rom --model ox/m.phgmgrom $ROMSIM --out ox/y.npy --quiet
run_ok "--X snapshots == --simulate" "$REF" compare out/y_rom.npy ox/y.npy 0

for meth in gmg-qm sp1; do
  run_ok "reduce $meth" "$P" reduce $SYS $SIM --method $meth --r 12 --out o_$meth --name m --quiet
  run_ok "simulate-rom $meth" "$P" simulate-rom --model o_$meth/m.phgmgrom $ROMSIM --out o_$meth/y.npy --quiet
  run_ok "ref $meth" "$REF" ref linear $meth 12 ref_$meth.npy
  run_ok "$meth r=12 CLI == library (1e-12)" "$REF" compare ref_$meth.npy o_$meth/y.npy 1e-12
done
[ -s o_gmg-qm/m_V2.npy ] && [ -s o_gmg-qm/m_M.npy ] && [ -s o_gmg-qm/m_Ms.npy ] || bad "gmg-qm arrays missing"

# negative control: a different reduced order must not pass the comparison
run_ok "reduce r=11" "$P" reduce $SYS $SIM --method gmg-pod --r 11 --out o11 --name m --quiet
run_ok "simulate-rom r=11" "$P" simulate-rom --model o11/m.phgmgrom $ROMSIM --out o11/y.npy --quiet
if "$REF" compare ref_gmg-pod.npy o11/y.npy 1e-6 >/dev/null 2>&1; then
  bad "negative control: r = 11 output within 1e-6 of r = 12 (comparison cannot discriminate)"
else pass; fi

# nonlinear model with a separable polynomial part (quartic springs) and DEIM
mkdir -p nl
run_ok "cli_ref model-nl" "$REF" model-nl nl 20
run_ok "reduce --poly" "$P" reduce --J nl/J.npy --R nl/R.npy --B nl/B.npy --Q nl/Q.npy --poly nl/poly.npy \
  --poly-idx nl/idx.npy --deim-allow-negative $SIM --newton-tol 1e-8 --newton-iter 20 --method gmg-pod --r 10 \
  --out onl --name nlm
grep -F -q "DEIM" "$T/err.txt" || bad "reduce --poly does not report DEIM"
[ -s onl/nlm_P0.npy ] && [ -s onl/nlm_w.npy ] && [ -s onl/nlm_poly.npy ] || bad "nonlinear arrays missing"
run_ok "simulate-rom nonlinear" "$P" simulate-rom --model onl/nlm.phgmgrom $ROMSIM --newton-tol 1e-8 \
  --newton-iter 20 --out onl/y.npy --quiet
run_ok "ref nonlinear" "$REF" ref nonlinear gmg-pod 10 20 ref_nl.npy
run_ok "nonlinear gmg-pod + DEIM CLI == library (1e-12)" "$REF" compare ref_nl.npy onl/y.npy 1e-12

# ---- 4. C export, NumPy view of the outputs, compare.py ----------------------------
CSIM="$T/cli_ref_csim"
if $CC -std=c99 -O0 -DCLI_REF_ROM_C="\"$T/out/msd.c\"" -DCLI_REF_ROM_NAME=msd -o "$CSIM" "$ROOT/tests/cli_ref.c" \
     -lm 2>"$T/cc.txt"; then
  pass
  run_ok "exported C model runs" "$CSIM" csim y_c.npy
  run_ok "exported C model == model file" "$REF" compare out/y_rom.npy y_c.npy 1e-12
else
  bad "the exported C source out/msd.c does not compile: $(head -n 5 "$T/cc.txt")"
fi

if [ "$HAVE_NP" = 1 ]; then
  run_ok "outputs seen by NumPy" "$PY" - <<'EOF'
import json, sys
import numpy as np
d = "out/"
meta = json.load(open(d + "msd.json"))
assert (meta["N"], meta["m"], meta["r"], meta["method"], meta["kind"]) == (100, 1, 12, "gmg-pod", "linear"), meta
for f, shape in meta["files"]["arrays"].items():
    a = np.load(d + f)
    assert a.dtype == np.float64 and list(a.shape) == shape, (f, a.shape, shape)
Bh, Qh, K, V0 = (np.load(d + "msd_%s.npy" % k) for k in ("Bh", "Qh", "K", "V0"))
B = np.load("model/B.npy")
r = 12
assert np.array_equal(Bh, np.eye(r, 1)), Bh.ravel()                     # GMG: Bh = [I; 0]
assert np.array_equal(V0[:, :1], B)                                     # V0 = [B, V1]
assert np.abs(Qh - Qh.T).max() <= 1e-12 * np.abs(Qh).max()
assert np.linalg.eigvalsh((Qh + Qh.T) / 2).min() > 0.0                  # reduced energy positive definite
Rr = -(K + K.T) / 2
assert np.linalg.eigvalsh(Rr).min() >= -1e-12 * np.abs(K).max()         # R_r = -sym(K) >= 0
y = np.load(d + "y_rom.npy"); xr = np.load(d + "xr.npy")
assert y.shape == (1, 1001) and xr.shape == (r, 1001)
yo = Bh.T @ Qh @ xr                                                     # y = Bh^T grad H(xr)
assert np.abs(yo - y).max() <= 1e-12 * np.abs(y).max(), np.abs(yo - y).max()
print("ok")
EOF
  run_ok "compare.py" "$PY" "$ROOT/examples/npy_example/compare.py" --model model --rom-y out/y_rom.npy \
    --fom-y out/msd_fom_y.npy --V0 out/msd_V0.npy --rom-x out/xr.npy --check-fom 1e-9
  cat "$T/out.txt"
  # input files: samples/table of a constant reproduce --input const exactly
  run_ok "write input files" "$PY" -c "
import numpy as np
np.save('u_grid.npy', np.full(1001, 0.1))
np.save('u_tab.npy', np.array([[0.0, 0.1], [50.0, 0.1], [200.0, 0.1]]))
np.save('u_tabbe.npy', np.asfortranarray(np.array([[0.0, 0.1], [200.0, 0.1]], dtype='>f8')))
np.save('u_bad.npy', np.zeros((4, 3)))
np.save('u_dec.npy', np.array([[0.0, 0.1], [0.0, 0.2]]))
np.save('int.npy', np.zeros((100, 100), dtype=np.int64))
Q = np.load('model/Q.npy'); Q[3, 3] = np.nan; np.save('Q_nan.npy', Q)
np.save('J_3d.npy', np.zeros((2, 2, 2)))
"
  # explicit unit weights of the nonlinear terms == the default
  run_ok "write w1.npy" "$PY" -c "import numpy as np; np.save('w1.npy', np.ones(20))"
  run_ok "reduce --poly-w" "$P" reduce --J nl/J.npy --R nl/R.npy --B nl/B.npy --Q nl/Q.npy --poly nl/poly.npy \
    --poly-idx nl/idx.npy --poly-w w1.npy --deim-allow-negative $SIM --newton-tol 1e-8 --newton-iter 20 \
    --method gmg-pod --r 10 --out onlw --name nlm --quiet
  run_ok "simulate-rom --poly-w" "$P" simulate-rom --model onlw/nlm.phgmgrom $ROMSIM --newton-tol 1e-8 \
    --newton-iter 20 --out onlw/y.npy --quiet
  run_ok "--poly-w ones == default" "$REF" compare onl/y.npy onlw/y.npy 0
  run_err "poly-w length" 1 "w1.npy (--poly-w): expected a vector of 100 weights" "$P" reduce $SYS $SIM \
    --method gmg-pod --r 12 --out e --poly nl/poly.npy --poly-idx model/B.npy --poly-w w1.npy
  run_ok "simulate-rom const" "$P" simulate-rom --model out/msd.phgmgrom --input const --amp 0.1 --out yc.npy --quiet
  for u in u_grid u_tab u_tabbe; do
    run_ok "simulate-rom --input $u.npy" "$P" simulate-rom --model out/msd.phgmgrom --input $u.npy --out y_$u.npy --quiet
    run_ok "--input $u.npy == const" "$REF" compare yc.npy y_$u.npy 0
  done
  run_err "input table shape" 1 "u_bad.npy" "$P" simulate-rom --model out/msd.phgmgrom --input u_bad.npy --out y.npy
  run_err "input times" 1 "u_dec.npy" "$P" simulate-rom --model out/msd.phgmgrom --input u_dec.npy --out y.npy
  run_err "int64 npy" 1 "int.npy" "$P" reduce --J int.npy --R model/R.npy --B model/B.npy --Q model/Q.npy $SIM \
    --method gmg-pod --r 12 --out e
  run_err "NaN in Q" 1 "Q_nan.npy" "$P" reduce --J model/J.npy --R model/R.npy --B model/B.npy --Q Q_nan.npy $SIM \
    --method gmg-pod --r 12 --out e
  run_err "3-d npy" 1 "J_3d.npy" "$P" reduce --J J_3d.npy --R model/R.npy --B model/B.npy --Q model/Q.npy $SIM \
    --method gmg-pod --r 12 --out e
else
  echo "test_cli: note: NumPy checks of the outputs, compare.py and input files skipped"
fi

# ---- 5. error paths -------------------------------------------------------------
printf 'this is not an npy file' >garbage.npy
head -c 200 model/J.npy >trunc.npy
R_="--R model/R.npy"; B_="--B model/B.npy"; Q_="--Q model/Q.npy"; J_="--J model/J.npy"
TAIL="$SIM --method gmg-pod --r 12 --out e"
run_err "missing file" 1 "nofile.npy" "$P" reduce --J nofile.npy $R_ $B_ $Q_ $TAIL
run_err "malformed npy" 1 "garbage.npy" "$P" reduce $J_ --R garbage.npy $B_ $Q_ $TAIL
run_err "malformed npy says so" 1 "malformed" "$P" reduce $J_ --R garbage.npy $B_ $Q_ $TAIL
run_err "truncated npy" 1 "trunc.npy" "$P" reduce --J trunc.npy $R_ $B_ $Q_ $TAIL
run_err "wrong shape Q" 1 "model/B.npy (--Q): expected shape (100, 100)" "$P" reduce $J_ $R_ $B_ --Q model/B.npy $TAIL
run_err "wrong shape B" 1 "nl/B.npy (--B): expected shape (100, m)" "$P" reduce $J_ $R_ --B nl/B.npy $Q_ $TAIL
run_err "non-square J" 1 "model/B.npy (--J)" "$P" reduce --J model/B.npy $R_ $B_ $Q_ $TAIL
run_err "wrong shape X" 1 "model/B.npy (--X)" "$P" reduce $J_ $R_ $B_ $Q_ --X model/B.npy --method gmg-pod --r 12 --out e
run_err "J not skew" 1 "model/Q.npy (--J): J is not skew-symmetric" "$P" reduce --J model/Q.npy $R_ $B_ $Q_ $TAIL
run_err "R not symmetric" 1 "model/J.npy (--R): R is not symmetric" "$P" reduce $J_ --R model/J.npy $B_ $Q_ $TAIL
run_err "r too small for gmg" 2 "--r 1" "$P" reduce $J_ $R_ $B_ $Q_ $SIM --method gmg-pod --r 1 --out e
run_err "bad method" 2 "--method 'pod'" "$P" reduce $J_ $R_ $B_ $Q_ $SIM --method pod --r 12 --out e
run_err "bad integer" 2 "--r: expected an integer" "$P" reduce $J_ $R_ $B_ $Q_ $SIM --method gmg-pod --r 1x --out e
run_err "bad name" 2 "--name '1abc'" "$P" reduce $J_ $R_ $B_ $Q_ $TAIL --name 1abc
run_err "X and simulate" 2 "exactly one of --X" "$P" reduce $J_ $R_ $B_ $Q_ $TAIL --X model/J.npy
run_err "missing --out" 2 "--out DIR is required" "$P" reduce $J_ $R_ $B_ $Q_ $SIM --method gmg-pod --r 12
run_err "unknown option" 2 "--bogus" "$P" reduce $J_ $R_ $B_ $Q_ $TAIL --bogus
run_err "poly without idx" 2 "--poly-idx" "$P" reduce $J_ $R_ $B_ $Q_ $TAIL --poly nl/poly.npy
run_err "poly idx not integers" 1 "nl/poly.npy (--poly-idx): entry 4 is 0.25" "$P" reduce $J_ $R_ $B_ $Q_ $TAIL \
  --poly nl/poly.npy --poly-idx nl/poly.npy
run_err "missing input file" 1 "nofile.npy (--input)" "$P" reduce $J_ $R_ $B_ $Q_ --simulate --input nofile.npy \
  --method gmg-pod --r 12 --out e
run_err "model file missing" 1 "nomodel.phgmgrom" "$P" simulate-rom --model nomodel.phgmgrom --out y.npy
run_err "model file malformed" 1 "garbage.npy (--model)" "$P" simulate-rom --model garbage.npy --out y.npy
run_err "simulate-rom unwritable" 1 "nodir/y.npy" "$P" simulate-rom --model out/msd.phgmgrom --out nodir/y.npy
run_err "out is a file" 1 "garbage.npy (--out)" "$P" reduce $J_ $R_ $B_ $Q_ $SIM --method gmg-pod --r 12 --out garbage.npy

echo "test_cli: $npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
