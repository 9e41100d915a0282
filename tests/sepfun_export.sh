#!/bin/sh
# Exported C source of an exp-polynomial model, a phi_cb and an eta_cb model, and a
# linear model with dampers, feedthrough and a reference state:
# compiled with PHGMG_NO_OFFLINE as C99 and as C++, they must print exactly the
# in-memory reference outputs. usage: sepfun_export.sh BUILD_DIR
set -eu
B=${1:-build}
CC=${CC:-cc}
CXX=${CXX:-c++}
D="$B/sepfun_export"
mkdir -p "$D"
W="-Wall -Wextra -Werror"
if [ -f "$B/phgmg_impl.o" ]; then   # the implementation compiled once by the Makefile
  $CC -std=c99 $W -pedantic -O1 -DPHGMG_IMPLEMENTATION_ELSEWHERE -o "$D/gen" tests/sepfun_export.c "$B/phgmg_impl.o" -lm
else
  $CC -std=c99 $W -pedantic -O1 -o "$D/gen" tests/sepfun_export.c -lm
fi
"$D/gen" "$D"
for m in sfx_poly sfx_cb sfx_eta sfx_lin; do
  $CC -std=c99 $W -pedantic -O1 -DPHGMG_NO_OFFLINE -DMODEL_HEADER="\"$m.h\"" -DMODEL_NAME=$m -I"$D" \
      -o "$D/use_$m" tests/sepfun_export.c -lm
  "$D/use_$m" > "$D/$m.out"
  cmp -s "$D/$m.out" "$D/$m.ref" || { echo "FAIL: exported C model $m does not reproduce the in-memory outputs"; exit 1; }
  $CXX -std=c++11 $W -O1 -DPHGMG_NO_OFFLINE -DMODEL_HEADER="\"$m.h\"" -DMODEL_NAME=$m -I"$D" \
      -x c++ -o "$D/usexx_$m" tests/sepfun_export.c -lm
  "$D/usexx_$m" > "$D/$m.outxx"
  cmp -s "$D/$m.outxx" "$D/$m.ref" || { echo "FAIL: exported C model $m (C++) does not reproduce the in-memory outputs"; exit 1; }
done
echo "ok    sepfun export: exp-polynomial, phi_cb, eta_cb and linear damper/feedthrough/reference-state models exported as C reproduce the in-memory outputs (C99, C++)"
