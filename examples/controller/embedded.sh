#!/bin/sh
# `make embedded`: cross-compiles the controller for a Cortex-M4F
# (arm-none-eabi-gcc -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16
# -Os, newlib, semihosting), for every exported demo model in float and in
# double, prints arm-none-eabi-size for each, and, when qemu-system-arm is
# installed, runs each image on the emulated MPS2-AN386 board and compares its
# printed outputs with the host's in-memory reference.
# usage: embedded.sh BUILD_DIR   (expects BUILD_DIR/emb_{d,f} from check.sh)
set -eu
B=${1:-build}
ARMF="-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 -Os"
MODELS="lin_gmgpod lin_gmgqm lin_sp1 nl_gmgpod nl_gmgqm nl_sp2 mo_gmgpod mo_gmgqm mo_sp2"
mkdir -p "$B/cm4"
command -v arm-none-eabi-gcc >/dev/null || { echo "arm-none-eabi-gcc not found (apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi)"; exit 1; }
echo "Cortex-M4F images (text = code + constant model data in flash, bss = static workspace):"
for t in f d; do
  if [ $t = f ]; then fl="-DPHGMG_REAL_FLOAT"; ty=float; else fl=""; ty=double; fi
  for m in $MODELS; do
    elf="$B/cm4/ctrl_${m}_$t.elf"
    arm-none-eabi-gcc $ARMF -std=c99 -Wall -Wextra -Werror $fl -DPHGMG_NO_OFFLINE \
      -DMODEL_HEADER="\"$m.h\"" -DMODEL_NAME=$m -I"$B/emb_$t" --specs=rdimon.specs \
      -T examples/controller/mps2_an386.ld examples/controller/controller.c \
      examples/controller/cm4_startup.c -lm -o "$elf"
    printf '%-7s %-11s ' "$ty" "$m"; arm-none-eabi-size "$elf" | tail -n 1 | awk '{ printf "text %7d  data %5d  bss %6d\n", $1, $2, $3 }'
  done
done
echo "Online code alone (PHGMG_STATIC, -ffunction-sections -fdata-sections -Wl,--gc-sections):"
echo "bytes of the phgmg_* functions and ctrl_run (init + step + output loop) in the linked image"
for t in f d; do
  if [ $t = f ]; then fl="-DPHGMG_REAL_FLOAT"; ty=float; else fl=""; ty=double; fi
  for m in $MODELS; do
    elf="$B/cm4/code_${m}_$t.elf"
    arm-none-eabi-gcc $ARMF -std=c99 -Wall -Wextra -Werror $fl -DPHGMG_NO_OFFLINE -DPHGMG_STATIC \
      -ffunction-sections -fdata-sections -Wl,--gc-sections \
      -DMODEL_HEADER="\"$m.h\"" -DMODEL_NAME=$m -I"$B/emb_$t" --specs=rdimon.specs \
      -T examples/controller/mps2_an386.ld examples/controller/controller.c \
      examples/controller/cm4_startup.c -lm -o "$elf"
    arm-none-eabi-nm -S -t d "$elf" | awk -v ty="$ty" -v m="$m" '
      ($3 == "t" || $3 == "T") && $4 ~ /^(phgmg|ctrl_run)/ { code += $2 }
      ($3 == "r" || $3 == "R") && $4 ~ /^ph_/ { data += $2 }
      END { printf "%-7s %-11s online code %6d bytes (%.1f KiB)\n", ty, m, code, code / 1024 }'
  done
done
if command -v qemu-system-arm >/dev/null; then
  echo "Running under qemu-system-arm -M mps2-an386 (semihosting), compared with the host reference:"
  for t in f d; do
    for m in $MODELS; do
      out="$B/cm4/ctrl_${m}_$t.out"
      timeout 300 qemu-system-arm -M mps2-an386 -nographic -semihosting-config enable=on,target=native \
        -kernel "$B/cm4/ctrl_${m}_$t.elf" > "$out" 2>/dev/null || { echo "FAIL: $m ($t) did not run"; exit 1; }
      paste -d' ' "$B/emb_$t/$m.ref" "$out" | awk -v m="$m" -v t="$t" '
        { n += ($2-$1)^2; d += $1^2; if ($1 != $2) k++ }
        END { printf "  %-6s %-11s %4d outputs, %4d differ from the host in the last digits, relative difference %.2e\n",
              (t == "f" ? "float" : "double"), m, NR, k, sqrt(n/d) }'
    done
  done
else
  echo "qemu-system-arm not installed: images built, not run"
fi
