#!/bin/sh
# test_cli.sh — tests of the `phgmg` command-line reducer (examples/phgmg_cli.c).
#
# Usage: sh tests/test_cli.sh build/phgmg [build/phgmg-float]   (from the repository root)
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
PF=${2:-}   # optional: the command line built with -DPHGMG_REAL_FLOAT
case "$PF" in /*|"") ;; *) PF="$PWD/$PF" ;; esac
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
         gmg-pod gmg-qm sp1 sp2 --r --rn wide --ref --greedy-window --lambda --poly --poly-idx --poly-w --no-deim --deim-tol --deim-max \
         --deim-allow-negative --dt-map --out --name --save-snapshots --quiet simulate-rom --model --states \
         .phgmgrom _V0.npy .json "EXIT STATUS" EXAMPLES --J-coo --R-coo --Q-coo "SPARSE MATRICES" tocoo; do
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
grep -F -q "msd.phgmgrom: linear reduced model" "$T/out.txt" || bad "info does not call a linear model linear"

# the same reduction from the saved snapshots (--X) gives the same model
run_ok "reduce --X" "$P" reduce $SYS --X out/msd_snapshots.npy --dt-map 0.1 --method gmg-pod --r 12 --out ox --name m --quiet
run_ok "simulate-rom --X model" "$P" simulate-rom --model ox/m.phgmgrom $ROMSIM --out ox/y.npy --quiet
run_ok "--X snapshots == --simulate" "$REF" compare out/y_rom.npy ox/y.npy 0

for meth in gmg-qm sp1; do
  lam=""; [ $meth = gmg-qm ] && lam="--lambda 1e-3"   # the reference program's (the paper's) lambda
  run_ok "reduce $meth" "$P" reduce $SYS $SIM --method $meth $lam --r 12 --out o_$meth --name m --quiet
  run_ok "simulate-rom $meth" "$P" simulate-rom --model o_$meth/m.phgmgrom $ROMSIM --out o_$meth/y.npy --quiet
  run_ok "ref $meth" "$REF" ref linear $meth 12 ref_$meth.npy
  run_ok "$meth r=12 CLI == library (1e-12)" "$REF" compare ref_$meth.npy o_$meth/y.npy 1e-12
done
# an affine reference state and a wide V2 (--ref mean --rn wide): the model file
# carries xr_rest, simulate-rom starts there; output within 1e-2 of the full
# model's (measured 8.1e-4, as without --ref)
run_ok "reduce gmg-qm --ref mean --rn wide" "$P" reduce $SYS $SIM --method gmg-qm --lambda 1e-3 --r 12 --rn wide \
  --manifold greedy --ref mean --out o_ref --name m --save-snapshots --quiet
run_ok "simulate-rom --ref mean" "$P" simulate-rom --model o_ref/m.phgmgrom $ROMSIM --out o_ref/y.npy --quiet
run_ok "--ref mean model against the full model (1e-2)" "$REF" compare o_ref/m_fom_y.npy o_ref/y.npy 1e-2
run_err "--ref bad" 2 "--ref" "$P" reduce $SYS $SIM --method gmg-pod --r 12 --ref median --out o_bad --name m
# --ref FILE: the snapshots' mean written by NumPy gives the model of --ref mean
# (same output to 1e-8: only the mean's rounding differs); the file is an input
# (an output of that name is refused, the file stays as it was); its shape is
# checked against N
if [ "$HAVE_NP" = 1 ]; then
  mkdir -p o_rf
  "$PY" -c "import numpy as np; X = np.load('o_ref/m_snapshots.npy'); np.save('o_rf/xbar.npy', X.mean(axis=1))"
  run_ok "reduce --ref FILE" "$P" reduce $SYS $SIM --method gmg-qm --lambda 1e-3 --r 12 --rn wide \
    --manifold greedy --ref o_rf/xbar.npy --out o_rf --name m --quiet
  grep -F -q '"ref": "o_rf/xbar.npy"' o_rf/m.json || bad "json does not name the --ref file"
  grep -F -q '"ref": "mean"' o_ref/m.json || bad "json does not say --ref mean"
  run_ok "simulate-rom --ref FILE" "$P" simulate-rom --model o_rf/m.phgmgrom $ROMSIM --out o_rf/y.npy --quiet
  run_ok "--ref FILE (the mean) == --ref mean (1e-8)" "$REF" compare o_ref/y.npy o_rf/y.npy 1e-8
  run_err "--ref FILE against the zero reference (negative control)" 1 "" "$REF" compare o_gmg-qm/y.npy o_rf/y.npy 1e-8
  cp o_rf/xbar.npy o_rf/m_V0.npy && cp o_rf/xbar.npy o_rf/keep.npy
  run_err "--ref FILE is an output" 2 "never overwrites its inputs" "$P" reduce $SYS $SIM --method gmg-pod --r 12 \
    --ref o_rf/m_V0.npy --out o_rf --name m --quiet
  cmp -s o_rf/m_V0.npy o_rf/keep.npy || bad "--ref FILE was overwritten"
  "$PY" -c "import numpy as np; np.save('o_rf/short.npy', np.zeros(99)); np.save('o_rf/nan.npy', np.full(100, np.nan))"
  run_err "--ref wrong shape" 1 "o_rf/short.npy (--ref): expected shape (100,)" "$P" reduce $SYS $SIM \
    --method gmg-pod --r 12 --ref o_rf/short.npy --out o_bad --name m
  run_err "--ref NaN" 1 "o_rf/nan.npy (--ref): NaN" "$P" reduce $SYS $SIM --method gmg-pod --r 12 \
    --ref o_rf/nan.npy --out o_bad --name m
fi
run_err "--ref missing file" 2 "--ref 'no_such.npy'" "$P" reduce $SYS $SIM --method gmg-pod --r 12 \
  --ref no_such.npy --out o_bad --name m
# --greedy-window: recorded in the json; only with gmg-qm, --manifold greedy or altmin, --rn wide
run_ok "reduce --greedy-window" "$P" reduce $SYS $SIM --method gmg-qm --lambda 1e-3 --r 12 --rn wide \
  --manifold greedy --greedy-window 40 --out o_gw --name m --quiet
grep -F -q '"greedy_window": 40' o_gw/m.json || bad "json does not record --greedy-window"
run_err "--greedy-window without --rn wide" 2 "needs --rn wide" "$P" reduce $SYS $SIM --method gmg-qm \
  --lambda 1e-3 --r 12 --manifold greedy --greedy-window 40 --out o_bad --name m
run_err "--greedy-window with the pod manifold" 2 "--manifold greedy or altmin" "$P" reduce $SYS $SIM \
  --method gmg-qm --lambda 1e-3 --r 12 --rn wide --greedy-window 40 --out o_bad --name m
run_err "--greedy-window 0" 2 "--greedy-window" "$P" reduce $SYS $SIM --method gmg-qm --lambda 1e-3 --r 12 \
  --rn wide --manifold greedy --greedy-window 0 --out o_bad --name m
run_err "--rn 0" 2 "--rn" "$P" reduce $SYS $SIM --method gmg-qm --r 12 --rn 0 --out o_bad --name m
[ -s o_gmg-qm/m_V2.npy ] && [ -s o_gmg-qm/m_M.npy ] && [ -s o_gmg-qm/m_Ms.npy ] || bad "gmg-qm arrays missing"
# SP1/SP2 have no D^T G D: their log and record name no GMG diagnostic
run_ok "reduce sp2 (log)" "$P" reduce $SYS $SIM --method sp2 --r 12 --out o_sp2 --name m
if grep -F -q "D^T G D" "$T/err.txt" "$T/out.txt"; then bad "sp2 progress prints a GMG diagnostic (rcond(D^T G D))"; else pass; fi
if grep -F -q "rcond_dgd" o_sp2/m.json o_sp1/m.json; then bad "sp1/sp2 record carries rcond_dgd"; else pass; fi
run_ok "reduce gmg-pod (log)" "$P" reduce $SYS $SIM --method gmg-pod --r 12 --out o_gp --name m
grep -F -q "rcond(D^T G D)" "$T/err.txt" "$T/out.txt" && pass || bad "gmg-pod progress lacks rcond(D^T G D)"

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
grep -F -q "hyper-reduction ecsw" "$T/err.txt" || bad "reduce --poly does not report the hyper-reduction"
[ -s onl/nlm_P0.npy ] && [ -s onl/nlm_w.npy ] && [ -s onl/nlm_poly.npy ] || bad "nonlinear arrays missing"
run_ok "simulate-rom nonlinear" "$P" simulate-rom --model onl/nlm.phgmgrom $ROMSIM --newton-tol 1e-8 \
  --newton-iter 20 --out onl/y.npy --quiet
run_ok "ref nonlinear" "$REF" ref nonlinear gmg-pod 10 20 ref_nl.npy
run_ok "nonlinear gmg-pod + DEIM CLI == library (1e-12)" "$REF" compare ref_nl.npy onl/y.npy 1e-12

# sparse input (--J-coo ...): the same nonlinear model in a scrambled ordering as
# coordinate triplets (J one (nnz, 3) array, R and Q three vectors each): the
# ROM output equals the library's dense path, V0 (written in the user's
# ordering) equals the dense run's V0 up to column signs.
if [ "$HAVE_NP" = 1 ]; then
  run_ok "write sparse model" "$PY" -c "
import numpy as np
J, R, Q, B = (np.load('nl/%s.npy' % k) for k in 'JRQB')
idx = np.load('nl/idx.npy').astype(int).ravel()
N = J.shape[0]; p = np.random.default_rng(7).permutation(N); ip = np.argsort(p)
np.save('sp_p.npy', p)
def coo(A):
    A = A[np.ix_(p, p)]; r, c = np.nonzero(A); return r, c, A[r, c]
r, c, v = coo(J); np.save('sp_J.npy', np.column_stack([r, c, v]))
for k, A in (('R', R), ('Q', Q)):
    r, c, v = coo(A); np.save('sp_%s_r.npy' % k, r.astype(np.int64)); np.save('sp_%s_c.npy' % k, c.astype(np.int32)); np.save('sp_%s_v.npy' % k, v)
np.save('sp_B.npy', B.reshape(N, -1)[p]); np.save('sp_idx.npy', ip[idx])
"
  SPJ="--J-coo sp_J.npy --R-coo sp_R_r.npy,sp_R_c.npy,sp_R_v.npy --Q-coo sp_Q_r.npy,sp_Q_c.npy,sp_Q_v.npy --B sp_B.npy"
  run_ok "reduce --J-coo" "$P" reduce $SPJ --poly nl/poly.npy --poly-idx sp_idx.npy --deim-allow-negative $SIM \
    --newton-tol 1e-8 --newton-iter 20 --method gmg-pod --r 10 --out osp --name nlm
  grep -F -q "half-bandwidth 1 " "$T/err.txt" || bad "reduce --J-coo does not report half-bandwidth 1 ($(grep -F sparse "$T/err.txt"))"
  run_ok "simulate-rom sparse" "$P" simulate-rom --model osp/nlm.phgmgrom $ROMSIM --newton-tol 1e-8 \
    --newton-iter 20 --out osp/y.npy --quiet
  run_ok "sparse gmg-pod + DEIM CLI == library (1e-10)" "$REF" compare ref_nl.npy osp/y.npy 1e-10
  run_ok "sparse V0 in the user ordering" "$PY" -c "
import numpy as np, sys
p = np.load('sp_p.npy'); Vs = np.load('osp/nlm_V0.npy'); Vd = np.load('onl/nlm_V0.npy')
V = np.empty_like(Vs); V[p] = Vs
d = max(min(np.abs(V[:, j] - Vd[:, j]).max(), np.abs(V[:, j] + Vd[:, j]).max()) for j in range(V.shape[1]))
sys.exit(0 if d <= 1e-8 * np.abs(Vd).max() else 1)
"
  # validate on sparse input checks against the sparse model (it used to read
  # the dense J, R, Q, absent here): the same e_y as the dense input's run
  # (the orderings differ, so equal to the 4 printed digits)
  for src in dense sparse; do
    if [ $src = dense ]; then SYSA="--J nl/J.npy --R nl/R.npy --Q nl/Q.npy --B nl/B.npy --poly-idx nl/idx.npy"
    else SYSA="$SPJ --poly-idx sp_idx.npy"; fi
    "$P" validate $SYSA --poly nl/poly.npy --deim-allow-negative $SIM --newton-tol 1e-8 --newton-iter 20 \
      --method gmg-pod --r 10 --out oval_$src --quiet --test-input const > val_$src.txt 2>&1 || bad "validate $src: exit $?"
  done
  a=$(awk '$1 == "const" {print $3}' val_dense.txt); b=$(awk '$1 == "const" {print $3}' val_sparse.txt)
  [ -n "$a" ] && [ "$a" = "$b" ] && pass || bad "validate on sparse input: e_y '$b', dense input '$a'"
  run_ok "write bad triplets" "$PY" -c "
import numpy as np; a = np.load('sp_J.npy'); a[3, 0] = a.shape[0] + 500; np.save('sp_Jbad.npy', a)"
  run_err "coo index out of range" 1 "sp_Jbad.npy (--J-coo): entry 3: row index" "$P" reduce --J-coo sp_Jbad.npy \
    --R-coo sp_R_r.npy,sp_R_c.npy,sp_R_v.npy --Q-coo sp_Q_r.npy,sp_Q_c.npy,sp_Q_v.npy --B sp_B.npy $SIM \
    --method gmg-pod --r 10 --out e
  run_err "coo shape" 1 "expected an (nnz, 3) array" "$P" reduce --J-coo sp_B.npy \
    --R-coo sp_R_r.npy,sp_R_c.npy,sp_R_v.npy --Q-coo sp_Q_r.npy,sp_Q_c.npy,sp_Q_v.npy --B sp_B.npy $SIM \
    --method gmg-pod --r 10 --out e
  run_ok "write nonsymmetric R" "$PY" -c "
import numpy as np
r, c, v = (np.load('sp_R_%s.npy' % k) for k in 'rcv')
np.save('sp_Rbad.npy', np.column_stack([np.r_[r, 0], np.r_[c, 1], np.r_[v, 0.5]]))"
  run_err "coo R not symmetric" 1 "R is not symmetric" "$P" reduce --J-coo sp_J.npy \
    --R-coo sp_Rbad.npy --Q-coo sp_Q_r.npy,sp_Q_c.npy,sp_Q_v.npy --B sp_B.npy $SIM \
    --method gmg-pod --r 10 --out e
  run_err "coo and dense mixed" 2 "either dense" "$P" reduce --J nl/J.npy --R-coo sp_R_r.npy,sp_R_c.npy,sp_R_v.npy \
    --Q-coo x --B sp_B.npy $SIM --method gmg-pod --r 10 --out e
else
  echo "test_cli: NumPy missing, sparse (--J-coo) checks skipped"
fi

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

# ---- 4b. float firmware source: the command line built with PHGMG_REAL_FLOAT ------
# (its offline work is double; the reduced model and its C export are float).
# The exported source compiles in a float PHGMG_NO_OFFLINE build and follows
# the double model (out/y_rom.npy) to the float stepper's accuracy.
if [ -n "$PF" ]; then
  run_ok "float CLI: reduce gmg-pod" "$PF" reduce $SYS $SIM --method gmg-pod --r 12 --out outf --name msdf --quiet
  grep -F -q 'exported for phgmg_real = float' outf/msdf.c && pass || bad "the float CLI did not export float source"
  cat >fw_float.c <<FWEOF
#define PHGMG_REAL_FLOAT
#define PHGMG_NO_OFFLINE
#define PHGMG_IMPLEMENTATION
#include "phgmg.h"
#include <math.h>
#include <stdio.h>
#include "$T/outf/msdf.c"
int main(void) {
  static double mem[1 << 14];
  phgmg_rom_stepper st;
  phgmg_real x[16] = {0}, u3[3], tc[3], y[1];
  int n, i;
  if (phgmg_rom_stepper_init(&st, &msdf, (phgmg_real)0.1, 0, 0, mem, sizeof mem) != PHGMG_OK) return 1;
  printf("%.9g\\n", 0.0);
  for (n = 0; n < 1000; ++n) {
    phgmg_rom_stage_times((phgmg_real)(0.1 * n), (phgmg_real)0.1, tc);
    for (i = 0; i < 3; ++i) u3[i] = (phgmg_real)(0.1 * sin((double)tc[i]));
    if (phgmg_rom_step(&st, x, u3, y, NULL) != PHGMG_OK) return 1;
    printf("%.9g\\n", (double)y[0]);
  }
  return 0;
}
FWEOF
  if $CC -std=c99 -Wall -Wextra -Werror -pedantic -Wdouble-promotion -I"$ROOT" -o fw_float fw_float.c -lm 2>"$T/cc.txt"; then
    pass
    run_ok "float firmware runs" sh -c "./fw_float > y_f.txt"
    if [ "$HAVE_NP" = 1 ]; then
      "$PY" -c "
import numpy as np
yd = np.load('out/y_rom.npy').ravel(); yf = np.loadtxt('y_f.txt')
assert yd.shape == yf.shape, (yd.shape, yf.shape)
e = np.linalg.norm(yf - yd) / np.linalg.norm(yd)
assert e <= 1e-5, e   # float rounding: about 2e-7 on this model; 1e-5 is the float stepper's tolerance
" && pass || bad "float firmware output does not follow the double model"
    fi
  else
    bad "the float export outf/msdf.c does not compile as float firmware: $(head -n 5 "$T/cc.txt")"
  fi
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
np.save('cplx.npy', np.zeros((100, 100), dtype=complex))
np.save('idx64.npy', np.arange(20))
np.save('idx32be.npy', np.arange(20, dtype='>i4'))
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
  run_err "complex npy names its dtype" 1 "cplx.npy (--J): dtype '<c16' is not supported" "$P" reduce \
    --J cplx.npy --R model/R.npy --B model/B.npy --Q model/Q.npy $SIM --method gmg-pod --r 12 --out e
  # NumPy's default int64 index array (np.arange) and an int32 one load
  run_ok "reduce --poly-idx int64" "$P" reduce --J nl/J.npy --R nl/R.npy --B nl/B.npy --Q nl/Q.npy --poly nl/poly.npy \
    --poly-idx idx64.npy --deim-allow-negative $SIM --newton-tol 1e-8 --newton-iter 20 --method gmg-pod --r 10 \
    --out onli --name nlm --quiet
  run_ok "simulate-rom --poly-idx int64" "$P" simulate-rom --model onli/nlm.phgmgrom $ROMSIM --newton-tol 1e-8 \
    --newton-iter 20 --out onli/y.npy --quiet
  run_ok "int64 idx == float64 idx" "$REF" compare onl/y.npy onli/y.npy 0
  run_ok "reduce --poly-idx int32" "$P" reduce --J nl/J.npy --R nl/R.npy --B nl/B.npy --Q nl/Q.npy --poly nl/poly.npy \
    --poly-idx idx32be.npy --deim-allow-negative $SIM --newton-tol 1e-8 --newton-iter 20 --method gmg-pod --r 10 \
    --out onli32 --name nlm --quiet
  run_ok "int32 idx == float64 idx (model files)" cmp onli/nlm.phgmgrom onli32/nlm.phgmgrom
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

# ---- 6. defects found by testing as a new user and as an attacker ---------
# 1: a model with a step map (dt 0.1) stepped with another dt
run_ok "D1 simulate-rom --dt 0.05 on a dt-0.1 step-map model" "$P" simulate-rom --model out/msd.phgmgrom --dt 0.05 \
  --steps 200 --out y_d1.npy --quiet
run_ok "D1 info" "$P" info out/msd.phgmgrom
grep -F -q "for another dt" "$T/out.txt" || bad "D1: info does not give the stepper memory for another dt"
# 2: --out through a symbolic link to a device: the write fails, the link stays
if [ -w /dev/full ]; then
  ln -s /dev/full full_link.npy
  run_err "D2 write to a link to /dev/full fails" 1 "full_link.npy" "$P" simulate-rom --model out/msd.phgmgrom \
    --steps 10 --out full_link.npy --quiet
  [ -L full_link.npy ] && pass || bad "D2: the symbolic link full_link.npy was removed"
fi
# 3: the snapshots times 1e-200 give the same model (POD invariant to magnitude)
run_ok "D3 scale X" "$REF" scale out/msd_snapshots.npy x_tiny.npy 1e-200
run_ok "D3 reduce --X tiny" "$P" reduce $SYS --X x_tiny.npy --dt-map 0.1 --method gmg-pod --r 12 --out o_tiny --name m --quiet
run_ok "D3 simulate-rom tiny" "$P" simulate-rom --model o_tiny/m.phgmgrom $ROMSIM --out o_tiny/y.npy --quiet
run_ok "D3 X*1e-200 gives the model of X (1e-9)" "$REF" compare ox/y.npy o_tiny/y.npy 1e-9
# 4, 5: Q's own culprit; Q positive definite checked
run_err "D4 Q not symmetric names Q" 1 "model/J.npy (--Q): Q is not symmetric" "$P" reduce --J model/J.npy \
  --R model/R.npy --B model/B.npy --Q model/J.npy $SIM --method gmg-pod --r 12 --out e
run_err "D5 Q singular (Q = R)" 1 "model/R.npy (--Q): Q is not positive definite" "$P" reduce --J model/J.npy \
  --R model/R.npy --B model/B.npy --Q model/R.npy $SIM --method gmg-pod --r 12 --out e
[ -e e ] && bad "D5: a failed run left the output directory e" || pass
# 7: all outputs or none
run_ok "D7 gmg-qm into o7" "$P" reduce $SYS $SIM --method gmg-qm --r 12 --out o7 --name m --quiet
run_ok "D7 gmg-pod into o7" "$P" reduce $SYS $SIM --method gmg-pod --r 12 --out o7 --name m --quiet
[ -e o7/m_V2.npy ] || [ -e o7/m_M.npy ] || [ -e o7/m_G00.npy ] && bad "D7: gmg-qm arrays left beside gmg-pod ones" || pass
rm o7/m.json && mkdir o7/m.json
(cd o7 && cksum m.phgmgrom m.c m_*.npy) >sums_before.txt
run_err "D7 failing run (m.json is a directory)" 1 "m.json" "$P" reduce $SYS $SIM --method gmg-pod --r 14 --out o7 \
  --name m --quiet
(cd o7 && cksum m.phgmgrom m.c m_*.npy) >sums_after.txt
cmp -s sums_before.txt sums_after.txt && pass || bad "D7: a failed r = 14 run changed the r = 12 outputs"
ls o7 | grep -q '\.tmp$' && bad "D7: temporary files left in o7" || pass
run_err "D7 failing --states" 1 "nodir/xr.npy" "$P" simulate-rom --model out/msd.phgmgrom --steps 10 --out y7.npy \
  --states nodir/xr.npy --quiet
[ -e y7.npy ] && bad "D7: a failing --states left y7.npy behind" || pass
# 11: names the exported C cannot take
for n in int while class phgmg_x PHGMGrom _x sqrt sqrtf memcpy NULL INT_MAX; do
  run_err "D11 --name $n refused" 2 "--name '$n'" "$P" reduce $SYS $SIM --method gmg-pod --r 12 --out e --name $n
done
# 12: CLI details
run_err "D12 --steps cap" 2 "would need" "$P" simulate-rom --model out/msd.phgmgrom --steps 2147483646 --out y12.npy
run_err "D12 --simulate --steps cap" 2 "would need" "$P" reduce $SYS --simulate --steps 2000000000 \
  --method gmg-pod --r 12 --out e
run_err "D12 --dt 1e-320" 2 "too small in magnitude" "$P" simulate-rom --model out/msd.phgmgrom --dt 1e-320 --out y12.npy
run_err "D12 --dt 1e999" 2 "too large" "$P" simulate-rom --model out/msd.phgmgrom --dt 1e999 --out y12.npy
run_err "D12 --input square" 2 "expected sin, chirp, const or a FILE.npy" "$P" simulate-rom --model out/msd.phgmgrom \
  --input square --out y12.npy
run_err "D12 info names no option" 1 "nomodel.phgmgrom (info)" "$P" info nomodel.phgmgrom
run_err "D12 directory as model" 1 "is a directory" "$P" simulate-rom --model out --out y12.npy
run_err "D12 directory as info model" 1 "is a directory" "$P" info out
run_err "D12 directory as npy" 1 "model (--J): cannot read: is a directory" "$P" reduce --J model $R_ $B_ $Q_ $TAIL
run_err "D12 repeated option" 2 "--dt given more than once" "$P" simulate-rom --model out/msd.phgmgrom --dt 0.1 \
  --dt 0.2 --out y12.npy
run_err "D12 repeated reduce option" 2 "--r given more than once" "$P" reduce $SYS $SIM --method gmg-pod --r 12 --r 14 \
  --out e
[ -e y12.npy ] && bad "D12: a refused run wrote y12.npy" || pass
# 13: --help calls the Python that has NumPy, as the README does
run_ok "D13 help" "$P" --help
grep -F -q "/usr/bin/python3 examples/npy_example/make_model.py" "$T/out.txt" || bad "D13: --help examples do not use /usr/bin/python3"
grep -E -q "^  python3 " "$T/out.txt" && bad "D13: --help still calls plain python3" || pass

# ---- 7. the exp-polynomial family on the command line -------------------
# A Toda chain (phi(s) = e^s - 1 - s on every spring, Q = blockdiag(0, I)):
# --potential toda, the same coefficients by --poly/--exp (shared), and one
# row per term give identical reduced outputs; --potential morse:D:A equals
# its explicit coefficients; the Toda ROM follows the full model (e_y < 1e-2).
if [ "$HAVE_NP" = 1 ]; then
  mkdir -p toda
  "$PY" - toda <<'PYEOF'
import sys, numpy as np
d = sys.argv[1]; n = 40; N = 2 * n
J = np.zeros((N, N)); R = np.zeros((N, N)); Q = np.zeros((N, N)); B = np.zeros((N, 1))
for i in range(n):
    J[i, n + i] = 1; J[n + i, i] = -1
    if i + 1 < n: J[i, n + i + 1] = -1; J[n + i + 1, i] = 1
    R[n + i, n + i] = 0.3; Q[n + i, n + i] = 1
B[n, 0] = 1
for k, v in (("J", J), ("R", R), ("Q", Q), ("B", B)): np.save(f"{d}/{k}.npy", v)
np.save(f"{d}/idx.npy", np.arange(n))                       # int64, NumPy's default
np.save(f"{d}/poly.npy", np.array([-1.0, -1.0])); np.save(f"{d}/exp.npy", np.array([[1.0, 1.0]]))
np.save(f"{d}/polyt.npy", np.tile([-1.0, -1.0], (n, 1))); np.save(f"{d}/expt.npy", np.tile([1.0, 1.0], (n, 1)))
np.save(f"{d}/mpoly.npy", np.array([0.5])); np.save(f"{d}/mexp.npy", np.array([[-1.0, -2.0], [0.5, -4.0]]))
PYEOF
  TSYS="--J toda/J.npy --R toda/R.npy --Q toda/Q.npy --B toda/B.npy --poly-idx toda/idx.npy"
  TRUN="--simulate --dt 0.1 --steps 300 --method gmg-pod --r 16 --quiet"
  run_ok "toda --potential" "$P" reduce $TSYS --potential toda $TRUN --out toda/a --name m --save-snapshots
  run_ok "toda --poly --exp" "$P" reduce $TSYS --poly toda/poly.npy --exp toda/exp.npy $TRUN --out toda/b --name m
  run_ok "toda per term" "$P" reduce $TSYS --poly toda/polyt.npy --exp toda/expt.npy $TRUN --out toda/c --name m
  run_ok "morse named" "$P" reduce $TSYS --potential morse:0.5:2 $TRUN --out toda/d --name m
  run_ok "morse explicit" "$P" reduce $TSYS --poly toda/mpoly.npy --exp toda/mexp.npy $TRUN --out toda/e --name m
  for v in a b c d e; do
    run_ok "toda simulate-rom $v" "$P" simulate-rom --model toda/$v/m.phgmgrom --dt 0.1 --steps 300 --out toda/y$v.npy --quiet
  done
  run_ok "toda info" "$P" info toda/c/m.phgmgrom
  grep -F -q "1 exponentials, one function per term" "$T/out.txt" || bad "info does not describe the per-term family"
  grep -F -q "nonlinear (linear subspace) reduced model" "$T/out.txt" || bad "info calls a model with nonlinear terms linear"
  run_ok "toda outputs" "$PY" - <<'PYEOF'
import numpy as np
y = {v: np.load(f"toda/y{v}.npy").ravel() for v in "abcde"}
assert np.array_equal(y["a"], y["b"]), "--potential toda != --poly/--exp"
assert np.max(np.abs(y["a"] - y["c"])) <= 1e-14 * np.max(np.abs(y["a"])), "per term != shared"
assert np.max(np.abs(y["d"] - y["e"])) <= 1e-14 * np.max(np.abs(y["d"])), "morse named != explicit"
f = np.load("toda/a/m_fom_y.npy").ravel()
e = np.linalg.norm(f - y["a"]) / np.linalg.norm(f)
assert e < 1e-2, f"Toda ROM e_y = {e}"
PYEOF
  run_err "potential unknown" 2 "--potential 'tode'" "$P" reduce $TSYS --potential tode $TRUN --out toda/f
  run_err "potential and poly" 2 "replaces --poly" "$P" reduce $TSYS --potential toda --poly toda/poly.npy $TRUN --out toda/f
  run_err "hyper unknown" 2 "expected ecsw, qdeim or greedy" "$P" reduce $TSYS --potential toda --hyper nnls $TRUN --out toda/f
else
  echo "test_cli: section 7 skipped (no NumPy for $PY)"
fi

# ---- 8. --lambda auto|cv, --manifold, --train-input ----------------------
# --manifold altmin: the training representation error sum ||x - phi(rho(x))||^2
# (computed here with NumPy from the written V0, V2, M and the snapshots, the
# ridge lambda 1e-10 for both, negligible here) is at most the hierarchical POD's; --train-input
# twice simulates two runs (2 (steps + 1) snapshots, both in the json) and
# `validate` then checks both training inputs by default; --lambda auto writes
# the chosen lambda; bad combinations are usage errors (exit 2).
for o in --manifold altmin greedy --train-input "--lambda auto" "lambda cv"; do
  "$P" --help | grep -F -q -- "$o" || bad "--help does not explain $o"
done
QSIM="--simulate --dt 0.1 --steps 300 --quiet"
run_ok "reduce --manifold pod" "$P" reduce $SYS $QSIM --method gmg-qm --r 10 --rn 4 --lambda 1e-10 --manifold pod --out q8 --name p --save-snapshots
run_ok "reduce --manifold altmin" "$P" reduce $SYS $QSIM --method gmg-qm --r 10 --rn 4 --lambda 1e-10 --manifold altmin --out q8 --name a
grep -F -q '"manifold": "altmin"' q8/a.json || bad "json does not name the altmin manifold"
if [ "$HAVE_NP" = 1 ]; then
  run_ok "altmin representation error <= POD" "$PY" - <<'PYEOF'
import numpy as np
X = np.load("q8/p_snapshots.npy"); m = 1
def err(n):
    V0, V2, M = (np.load(f"q8/{n}_{k}.npy") for k in ("V0", "V2", "M"))
    xr = np.linalg.lstsq(V0, X, rcond=None)[0]          # rho(x) = [B, V1]^+ x
    x2 = xr[m:]
    q = np.einsum("ik,jk->ijk", x2, x2).reshape(x2.shape[0] ** 2, -1)
    return np.sum((X - V0 @ xr - V2 @ (M @ q)) ** 2)
ep, ea = err("p"), err("a")
V0 = np.load("q8/a_V0.npy"); V2 = np.load("q8/a_V2.npy"); V = np.hstack([V0[:, m:], V2])
assert np.max(np.abs(V.T @ V - np.eye(V.shape[1]))) < 1e-12, "altmin [V1, V2] not orthonormal"
assert np.max(np.abs(V.T @ V0[:, :m])) < 1e-12, "altmin [V1, V2] not orthogonal to B"
assert ea <= ep, f"altmin training error {ea} above POD's {ep}"
assert ea < 0.99 * ep, f"altmin did not improve on POD ({ea} vs {ep})"
PYEOF
fi
run_ok "reduce --train-input x2 --lambda auto" "$P" reduce $SYS $QSIM --method gmg-qm --r 10 --rn 4 --lambda auto --train-input sin --train-input const --out q8 --name t
grep -F -q '"count": 602' q8/t.json || bad "two training runs: expected 602 snapshots in the json"
grep -F -q '"training_runs": 2' q8/t.json || bad "json does not count the training runs"
grep -F -q '"train_inputs": ["sin", "const"]' q8/t.json || bad "json does not list the training inputs"
grep -F -q '"lambda": "auto"' q8/t.json || bad "json does not record --lambda auto"
grep -q '"lambda_used": [-0-9]' q8/t.json || bad "json has no lambda_used"
"$P" validate $SYS $QSIM --method gmg-pod --r 10 --train-input sin --train-input const --out q8v > val.txt 2>&1
[ $? -eq 0 ] && pass || bad "validate with two training inputs: nonzero exit"
[ "$(grep -c ' pass$' val.txt)" -eq 2 ] && pass || bad "validate did not check both training inputs by default"
run_ok "reduce --lambda cv" "$P" reduce $SYS $QSIM --method gmg-qm --r 10 --rn 4 --lambda cv --out q8 --name c
grep -F -q '"lambda": "cv"' q8/c.json || bad "json does not record --lambda cv"
run_err "manifold unknown" 2 "expected pod, greedy or altmin" "$P" reduce $SYS $QSIM --method gmg-qm --r 10 --manifold best --out q8
run_err "manifold with gmg-pod" 2 "gmg-qm only" "$P" reduce $SYS $QSIM --method gmg-pod --r 10 --manifold altmin --out q8
run_err "lambda auto with sp1" 2 "gmg-qm only" "$P" reduce $SYS $QSIM --method sp1 --r 10 --lambda auto --out q8
run_err "lambda word" 2 "--lambda" "$P" reduce $SYS $QSIM --method gmg-qm --r 10 --lambda often --out q8
run_err "train-input with --X" 2 "needs --simulate" "$P" reduce $SYS --X out/msd_snapshots.npy --train-input sin --method gmg-qm --r 10 --out q8
run_err "train-input with --input" 2 "not both" "$P" reduce $SYS $QSIM --input sin --train-input const --method gmg-qm --r 10 --out q8

# ---- descriptor models (--E): E = I gives the model without E; bad E named ----
if [ "$HAVE_NP" = 1 ]; then
  "$PY" -c "
import numpy as np
J = np.load('model/J.npy'); N = J.shape[0]
np.save('E_id.npy', np.eye(N)); np.save('E_rect.npy', np.eye(N)[:, :N - 1])
np.save('E_nonsym.npy', np.eye(N) + 0.1 * J)
np.save('E_neg.npy', -np.eye(N))
" && pass || bad "descriptor files"
  run_ok "reduce --E identity" "$P" reduce $SYS --E E_id.npy $SIM --method gmg-pod --r 12 --out oE --name m --quiet
  run_ok "simulate-rom --E identity" "$P" simulate-rom --model oE/m.phgmgrom $ROMSIM --out oE/y.npy --quiet
  run_ok "--E identity == no E (1e-9)" "$REF" compare out/y_rom.npy oE/y.npy 1e-9
  run_err "E not square" 1 "E_rect.npy (--E)" "$P" reduce $SYS --E E_rect.npy $SIM --method gmg-pod --r 12 --out oEr
  [ ! -e oEr ] && pass || bad "E not square: output written"
  run_err "E^T Q not symmetric" 1 "E^T Q is not symmetric" "$P" reduce $SYS --E E_nonsym.npy $SIM --method gmg-pod --r 12 --out oEn
  [ ! -e oEn ] && pass || bad "E^T Q not symmetric: output written"
  run_err "E^T Q not PD" 1 "E_neg.npy, model/Q.npy (--E, --Q)" "$P" reduce $SYS --E E_neg.npy $SIM --method gmg-pod --r 12 --out oEp
  "$PY" -c "
import numpy as np
np.save('S_ok.npy', 0.1 * np.eye(1)); np.save('S_neg.npy', -0.1 * np.eye(1))
" && pass || bad "feedthrough files"
  run_err "feedthrough S not PSD" 1 "S_neg.npy (--S): the feedthrough is not valid: S is not positive semidefinite" "$P" reduce $SYS --S S_neg.npy $SIM --method gmg-pod --r 12 --out oSn
  [ ! -e oSn ] && pass || bad "feedthrough not PSD: output written"
  run_err "feedthrough: gmg-qm refused" 1 "gmg-qm does not take feedthrough" "$P" reduce $SYS --S S_ok.npy $SIM --method gmg-qm --r 12 --out oSo
  [ ! -e oSo ] && pass || bad "feedthrough refused: output written"
  run_ok "reduce --S (gmg-pod)" "$P" reduce $SYS --S S_ok.npy $SIM --method gmg-pod --r 12 --out oSf --name m --quiet
  run_ok "simulate-rom with feedthrough" "$P" simulate-rom --model oSf/m.phgmgrom $ROMSIM --out oSf/y.npy --quiet
  run_ok "simulate --S" "$P" simulate $SYS --S S_ok.npy $ROMSIM --out ySf.npy --quiet
  run_ok "feedthrough ROM follows the full model (1e-2)" "$REF" compare ySf.npy oSf/y.npy 1e-2
  run_err "--E with --J-coo" 2 "--E-coo" "$P" reduce --J-coo J.npy --R-coo R.npy --Q-coo Q.npy --B model/B.npy --E E_id.npy $SIM --method gmg-pod --r 12 --out oEc
fi

# ---- algebraic constraints: a massless mass (zero row and column of E) is an
# index-one model; without its damper the constraint acts on a position (index two)
if [ "$HAVE_NP" = 1 ]; then
  "$PY" -c "
import numpy as np
J = np.load('model/J.npy'); R = np.load('model/R.npy'); Q = np.load('model/Q.npy'); N = J.shape[0]
E = np.eye(N); E[N - 1, N - 1] = 0.0
np.save('E_alg.npy', E)
R2 = R.copy(); R2[N - 1, :] = 0.0; R2[:, N - 1] = 0.0
np.save('R_noalg.npy', R2)
print(N, np.count_nonzero(R[N - 1, :]))
" >dae_info.txt && pass || bad "algebraic files"
  run_ok "simulate: index one" "$P" simulate $SYS --E E_alg.npy $ROMSIM --out yA.npy --states xA.npy --quiet
  run_ok "reduce: index one" "$P" reduce $SYS --E E_alg.npy $SIM --method sp1 --r 10 --out oA --name m --save-snapshots --quiet
  nA=$(cut -d' ' -f1 dae_info.txt)
  grep -q "N = $nA, of which $((nA - 1)) differential)" "$T/out.txt" && pass \
    || bad "reduce: index one: the closing line does not give the full N = $nA ($(tail -n 1 "$T/out.txt"))"
  run_ok "simulate-rom: index one" "$P" simulate-rom --model oA/m.phgmgrom $ROMSIM --out oA/y.npy --quiet
  run_ok "index-one ROM follows the full model (5e-2)" "$REF" compare yA.npy oA/y.npy 5e-2
  "$PY" -c "
import numpy as np
X = np.load('oA/m_snapshots.npy'); J = np.load('model/J.npy'); R = np.load('model/R.npy'); Q = np.load('model/Q.npy')
N = J.shape[0]
assert X.shape[0] == N, X.shape
res = ((J - R) @ Q @ X)[N - 1]    # the algebraic row (no input there): 0 = ((J - R) Q x)_{N-1}
assert np.max(np.abs(res)) <= 1e-10 * np.max(np.abs(X)), np.max(np.abs(res))
" && pass || bad "index one: saved snapshots are not consistent states"
  run_err "index two" 1 "index two or higher" "$P" simulate --J model/J.npy --R R_noalg.npy --Q model/Q.npy --B model/B.npy --E E_alg.npy $ROMSIM --out yI.npy
  [ ! -e yI.npy ] && pass || bad "index two: output written"
  run_err "index two names the files" 1 "E_alg.npy, model/J.npy, R_noalg.npy, model/Q.npy (--E, --J, --R, --Q)" "$P" reduce --J model/J.npy --R R_noalg.npy --Q model/Q.npy --B model/B.npy --E E_alg.npy $SIM --method sp1 --r 10 --out oI
  [ ! -e oI ] && pass || bad "index two: output written"
fi

# ---- nonlinear dampers (--dampers): linear dampers == R + c1 c c^T; energy-generating refused ----
if [ "$HAVE_NP" = 1 ]; then
  "$PY" -c "
import numpy as np
R = np.load('model/R.npy'); N = R.shape[0]
D = np.array([[N - 1, -1, 0.05, 0.0], [N - 3, N - 5, 0.02, 0.0]])
np.save('d_lin.npy', D)
R2 = R.copy()
for i, j, c1, c3 in D:
    i = int(i); j = int(j)
    c = np.zeros(N); c[i] = 1.0
    if j >= 0: c[j] = -1.0
    R2 += c1 * np.outer(c, c)
np.save('R_damp.npy', R2)
Dc = D.copy(); Dc[:, 3] = 5.0; np.save('d_cub.npy', Dc)
Dn = D.copy(); Dn[0, 2] = -0.05; np.save('d_neg.npy', Dn)
np.save('d_bad.npy', np.array([[N, -1, 0.1, 0.0]]))
" && pass || bad "damper files"
  DSIM="--dt 0.1 --steps 300 --input sin --amp 0.5 --quiet"
  run_ok "simulate --dampers linear" "$P" simulate $SYS --dampers d_lin.npy $DSIM --out yd.npy
  run_ok "simulate R + c1 c c^T" "$P" simulate --J model/J.npy --R R_damp.npy --B model/B.npy --Q model/Q.npy $DSIM --out yr.npy
  run_ok "linear dampers == R + c1 c c^T (1e-9)" "$REF" compare yr.npy yd.npy 1e-9
  run_ok "reduce --dampers cubic" "$P" reduce $SYS --dampers d_cub.npy --simulate $DSIM --method gmg-pod --r 12 --out oD --name m
  run_ok "simulate-rom of a damper model" "$P" simulate-rom --model oD/m.phgmgrom $DSIM --out oD/y.npy
  run_ok "simulate --dampers cubic" "$P" simulate $SYS --dampers d_cub.npy $DSIM --out yc.npy
  run_ok "damper ROM follows the full model (1e-2)" "$REF" compare yc.npy oD/y.npy 1e-2
  run_err "damper that generates energy" 1 "d_neg.npy (--dampers)" "$P" reduce $SYS --dampers d_neg.npy --simulate $DSIM --method gmg-pod --r 12 --out oDn
  [ ! -e oDn ] && pass || bad "energy-generating damper: output written"
  run_err "damper index out of range" 1 "d_bad.npy (--dampers)" "$P" simulate $SYS --dampers d_bad.npy $DSIM --out ydb.npy
  [ ! -e ydb.npy ] && pass || bad "bad damper index: output written"
  # with a nonlinear part the hyper-reduction (ECSW, the default) applies to its terms only: every damper kept
  nd=$("$PY" -c "
import numpy as np
N = np.load('toda/J.npy').shape[0]
np.save('d_all.npy', np.array([[i, -1, 0.01, 0.1] for i in range(N)]))
print(N)")
  run_ok "reduce --potential toda --dampers (every state)" "$P" reduce $TSYS --potential toda --dampers d_all.npy $TRUN --out oDh --name m
  run_ok "info of the toda model with dampers" "$P" info oDh/m.phgmgrom
  grep -F -q "dampers: the model keeps all $nd " "$T/out.txt" || bad "the hyper-reduction of the terms dropped dampers (expected all $nd kept)"
fi

# ---- 9. a run never removes or overwrites its inputs; outputs checked up front ----
# Files are compared by identity (device and inode), however they are spelled.
sums() { cksum "$@" 2>/dev/null; }
run_ok "S1 snapshots into ds" "$P" reduce $SYS $QSIM --method gmg-pod --r 10 --out ds --name rom --save-snapshots
sums ds/rom_snapshots.npy >s1_before.txt
run_ok "S1 reduce --X ds/rom_snapshots.npy into ds" "$P" reduce $SYS --X ds/rom_snapshots.npy --X-input sin \
  --method gmg-pod --r 10 --out ds --name rom
sums ds/rom_snapshots.npy >s1_after.txt
cmp -s s1_before.txt s1_after.txt && pass || bad "S1: reduce removed or changed its input ds/rom_snapshots.npy"
grep -F -q "removed ds/rom_snapshots.npy" "$T/err.txt" && bad "S1: reduce says it removed its input" || pass
# the arrays an earlier run recorded and this one does not write still go (fom_y), not the input
[ -e ds/rom_fom_y.npy ] && bad "S1: the earlier run's rom_fom_y.npy was not removed" || pass
# a file the user put beside the outputs, never recorded by a run, stays
mkdir -p du && cp out/msd_V0.npy du/rom_M.npy
run_ok "S1 user file beside" "$P" reduce $SYS $QSIM --method gmg-pod --r 10 --out du --name rom
[ -e du/rom_M.npy ] && pass || bad "S1: reduce removed du/rom_M.npy, a file no run recorded as its output"
# outputs that would overwrite inputs: refused up front (exit 2), the inputs unchanged
mkdir -p dp && cp nl/poly.npy dp/model_poly.npy && cp nl/idx.npy dp/idx.npy
if [ "$HAVE_NP" = 1 ]; then "$PY" -c "import numpy as np; np.save('dp/model_w.npy', np.ones(20))"
else cp nl/idx.npy dp/model_w.npy; fi
sums dp/model_poly.npy dp/model_w.npy >s2_before.txt
run_err "S1 --poly-w is an output" 2 "dp/model_w.npy (--poly-w)" "$P" reduce --J nl/J.npy --R nl/R.npy --B nl/B.npy \
  --Q nl/Q.npy --poly dp/model_poly.npy --poly-idx dp/idx.npy --poly-w dp/model_w.npy --deim-allow-negative $QSIM \
  --method gmg-pod --r 10 --out dp --name model
grep -F -q "reducing" "$T/err.txt" && bad "S1: the collision was found after the reduction" || pass
ln -s dp dp_link
run_err "S1 --poly-w through a symbolic link" 2 "(--poly-w)" "$P" reduce --J nl/J.npy --R nl/R.npy --B nl/B.npy \
  --Q nl/Q.npy --poly nl/poly.npy --poly-idx dp/idx.npy --poly-w ./dp_link/../dp/model_w.npy --deim-allow-negative \
  $QSIM --method gmg-pod --r 10 --out dp --name model
ln dp/model_poly.npy dp/hard.npy
run_err "S1 a hard link to an output" 2 "dp/hard.npy (--poly)" "$P" reduce --J nl/J.npy --R nl/R.npy --B nl/B.npy \
  --Q nl/Q.npy --poly dp/hard.npy --poly-idx dp/idx.npy --deim-allow-negative $QSIM --method gmg-pod --r 10 \
  --out dp --name model
sums dp/model_poly.npy dp/model_w.npy >s2_after.txt
cmp -s s2_before.txt s2_after.txt && pass || bad "S1: a refused run changed dp/model_poly.npy or dp/model_w.npy"
run_err "S1 --X is --save-snapshots' output" 2 "(--X)" "$P" reduce $SYS --X ds/rom_snapshots.npy --method gmg-pod \
  --r 10 --out ds/. --name rom --save-snapshots
# 4: simulate-rom's outputs: not the model, not each other
cp out/msd.phgmgrom sm.phgmgrom
sums sm.phgmgrom >s4_before.txt
run_err "S4 --out is --model" 2 "(--model)" "$P" simulate-rom --model sm.phgmgrom --steps 10 --out ./sm.phgmgrom
run_err "S4 --states is --model" 2 "(--model)" "$P" simulate-rom --model sm.phgmgrom --steps 10 --out y4.npy \
  --states sm.phgmgrom
sums sm.phgmgrom >s4_after.txt
cmp -s s4_before.txt s4_after.txt && pass || bad "S4: simulate-rom overwrote its --model"
run_err "S4 --out is --states" 2 "the same file" "$P" simulate-rom --model sm.phgmgrom --steps 10 --out y4.npy \
  --states ./y4.npy
run_err "S4 --out is the --input file" 2 "(--input)" "$P" simulate-rom --model sm.phgmgrom --steps 10 \
  --input u.npy --out u.npy
[ -e y4.npy ] && bad "S4: a refused run wrote y4.npy" || pass
# 13: unusable outputs are found before any computation
run_err "S13 --out below a file" 1 "garbage.npy/sub (--out)" "$P" reduce $SYS $SIM --method gmg-pod --r 12 \
  --out garbage.npy/sub
grep -F -q "simulating" "$T/err.txt" && bad "S13: --out below a file found after the computation" || pass
run_err "S13 simulate-rom --out nodir/y.npy" 1 "nodir/y.npy (--out)" "$P" simulate-rom --model out/msd.phgmgrom \
  --out nodir/y.npy
grep -F -q "simulating" "$T/err.txt" && bad "S13: simulate-rom --out nodir/ found after the simulation" || pass
run_err "S13 simulate-rom --states nodir/x.npy" 1 "nodir/x.npy (--states)" "$P" simulate-rom --model out/msd.phgmgrom \
  --out y13.npy --states nodir/x.npy
grep -F -q "simulating" "$T/err.txt" && bad "S13: simulate-rom --states nodir/ found after the simulation" || pass

# ---- 10. option values refused up front, messages naming the right option ----
if [ "$HAVE_NP" = 1 ]; then
  TS="--J toda/J.npy --R toda/R.npy --Q toda/Q.npy --B toda/B.npy --poly-idx toda/idx.npy"
  TR="--simulate --dt 0.1 --steps 100 --method gmg-pod --r 16"
  # 8: --potential fields: empty or not a number, energies unbounded below, coefficient overflow
  for pot in "fpu::" "fpu:1:" "morse::1" "fpu:1:x" "cosh:1:2" "fpu:1:-1" "morse:-1:1" "fpu:1:0" "cosh:1e-200" \
             "morse:1e308:1"; do
    run_err "P8 --potential $pot refused" 2 "--potential '$pot'" "$P" reduce $TS --potential "$pot" $TR --out p8
    grep -F -q "simulating" "$T/err.txt" && bad "P8: --potential $pot found after the simulation" || pass
  done
  grep -F -q "double range" "$T/err.txt" || bad "P8: morse:1e308:1 not reported as an overflow"
  "$PY" -c "import numpy as np; np.save('toda/neg.npy', np.array([0, 0, 0, 0, -0.25])); np.save('toda/negw.npy', -np.ones(40))"
  run_err "P8 --poly with a negative leading coefficient" 1 "unbounded below" "$P" reduce $TS --poly toda/neg.npy \
    $TR --out p8
  grep -F -q "simulating" "$T/err.txt" && bad "P8: the unbounded --poly found after the simulation" || pass
  run_err "P8 --potential toda with negative --poly-w" 1 "unbounded below" "$P" reduce $TS --potential toda \
    --poly-w toda/negw.npy $TR --out p8
  run_ok "P8 --potential fpu:-1:1 (bounded)" "$P" reduce $TS --potential fpu:-1:1 --simulate --steps 300 \
    --method gmg-pod --r 12 --out p8 --quiet
  # 10: options that do not apply are refused, not ignored
  run_err "P10 --deim-tol 1" 2 "--deim-tol 1" "$P" reduce $TS --potential toda --hyper qdeim --deim-tol 1 $TR --out p10
  run_err "P10 --hyper-tol with qdeim" 2 "--hyper-tol applies to --hyper ecsw" "$P" reduce $TS --potential toda \
    --hyper qdeim --hyper-tol 1e-3 $TR --out p10
  run_err "P10 --deim-tol with ecsw" 2 "apply to --hyper qdeim or greedy" "$P" reduce $TS --potential toda \
    --deim-tol 1e-6 $TR --out p10
  run_err "P10 --hyper without a nonlinear part" 2 "--hyper applies to a nonlinear part" "$P" reduce $SYS $QSIM \
    --method gmg-pod --r 10 --hyper ecsw --out p10
  run_err "P10 --lambda with gmg-pod" 2 "apply to --method gmg-qm only" "$P" reduce $SYS $QSIM --method gmg-pod \
    --r 10 --lambda 1e-3 --out p10
  run_err "P10 --rn with sp1" 2 "apply to --method gmg-qm only" "$P" reduce $SYS $QSIM --method sp1 --r 10 --rn 4 \
    --out p10
  [ -e p10 ] && bad "P10: a refused run wrote p10" || pass
  # 7: an ECSW tolerance below double precision
  run_err "P7 --hyper-tol 1e-300" 2 "below what double precision resolves" "$P" reduce $TS --potential toda \
    --hyper-tol 1e-300 $TR --out p7
  run_err "P7 --hyper-tol 0" 2 "--hyper-tol 0" "$P" reduce $TS --potential toda --hyper-tol 0 $TR --out p7
  # an ECSW tolerance the fit cannot reach on these snapshots: the message names ECSW and the way out
  run_err "P7 --hyper-tol 1e-14 unreachable" 1 "the ECSW hyper-reduction did not reach --hyper-tol 1e-14" "$P" reduce \
    $TS --potential toda --hyper-tol 1e-14 $TR --out p7 --quiet
fi
# 23: messages name the option the value came from; every command listed
run_err "P23 --train-input file" 1 "nofile.npy (--train-input)" "$P" reduce $SYS $QSIM --train-input sin \
  --train-input nofile.npy --method gmg-pod --r 10 --out p23
run_err "P23 --X-input file" 1 "nofile.npy (--X-input)" "$P" reduce $SYS --X out/msd_snapshots.npy \
  --X-input nofile.npy --method gmg-pod --r 10 --out p23
run_err "P23 --X-input kind" 2 "--X-input 'square'" "$P" reduce $SYS --X out/msd_snapshots.npy --X-input square \
  --method gmg-pod --r 10 --out p23
run_err "P23 empty --J-coo" 2 "--J-coo: empty value" "$P" reduce --J-coo "" --R-coo a.npy --Q-coo b.npy \
  --B model/B.npy $QSIM --method gmg-pod --r 10 --out p23
run_err "P23 empty name in --R-coo" 2 "--R-coo 'r.npy,,v.npy'" "$P" reduce --J-coo a.npy --R-coo r.npy,,v.npy \
  --Q-coo b.npy --B model/B.npy $QSIM --method gmg-pod --r 10 --out p23
run_err "P23 unknown command lists validate" 2 "validate" "$P" frobnicate

# 26: the fuzz harness of the command line knows every command and option of
#     --help (the lines calling Python name compare.py's options, not phgmg's)
missing=
for o in reduce validate simulate-rom info $("$P" --help | grep -v python3 | grep -o -- '--[a-zA-Z][a-zA-Z0-9-]*' | sort -u); do
  grep -F -q -- "\"$o\"" "$ROOT/tests/fuzz/fuzz_cli.c" || missing="$missing $o"
done
[ -z "$missing" ] && pass || bad "P26: tests/fuzz/fuzz_cli.c does not know:$missing"

echo "test_cli: $npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
