#!/bin/sh
# Host-side checks of the embedded path (run by `make test`):
#  1. export_model (double and float builds) writes each demo model at r = 16 as
#     binary file + C source and checks the binary file reproduces the
#     in-memory outputs exactly;
#  2. controller.c, built with PHGMG_NO_OFFLINE around each exported C file,
#     prints exactly the in-memory reference outputs (same scalar type);
#  3. float against double: relative output error over 1000 steps, asserted
#     <= 1e-4 for the linear models and the Morse chain (mo_*),
#     reported for the paper's nonlinear chain.
# usage: check.sh BUILD_DIR [--fast]
set -eu
B=${1:-build}
FAST=${2:-}
CC=${CC:-cc}
MODELS="lin_sp1 lin_gmgpod lin_gmgqm nl_sp2 nl_gmgpod nl_gmgqm mo_sp2 mo_gmgpod mo_gmgqm"
W="-std=c99 -Wall -Wextra -Werror -pedantic -O1"
for t in d f; do
  mkdir -p "$B/emb_$t"
  "$B/export_model_$t" "$B/emb_$t" $FAST > "$B/emb_$t/export.log"
  for m in $MODELS; do
    if [ $t = f ]; then fl="-DPHGMG_REAL_FLOAT -Wdouble-promotion"; else fl=""; fi
    $CC $W $fl -DPHGMG_NO_OFFLINE -DMODEL_HEADER="\"$m.h\"" -DMODEL_NAME=$m -I"$B/emb_$t" \
        -o "$B/emb_$t/ctrl_$m" examples/controller/controller.c -lm
    "$B/emb_$t/ctrl_$m" > "$B/emb_$t/$m.out"
    if ! cmp -s "$B/emb_$t/$m.out" "$B/emb_$t/$m.ref"; then
      echo "FAIL: exported C model $m ($t) does not reproduce the in-memory outputs"; exit 1
    fi
  done
  echo "ok    embedded: exported C and binary models reproduce the in-memory outputs exactly ($t)"
done
fail=0
for m in $MODELS; do
  rel=$(paste -d' ' "$B/emb_d/$m.ref" "$B/emb_f/$m.ref" | awk '{ n += ($2-$1)^2; d += $1^2 } END { printf "%.3e", sqrt(n/d) }')
  case $m in
    lin_*|mo_*) ok=$(awk -v e="$rel" 'BEGIN { print (e <= 1e-4) ? "ok  " : "FAIL" }');
           [ "$ok" = "ok  " ] || fail=1
           echo "$ok  float vs double, $m: relative output error $rel (bar 1e-4)";;
    *)     echo "info  float vs double, $m: relative output error $rel";;
  esac
done
exit $fail
