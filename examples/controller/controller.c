/* controller — firmware-style use of an exported reduced model.

   The model is C source written by export_model (phgmg_rom_export_c): static
   const arrays that sit in flash and a `static const phgmg_rom` descriptor.
   This program includes it, steps it 1000 times against u = 0.1 sin t with a
   static workspace (no heap, no offline code: built with PHGMG_NO_OFFLINE),
   and prints the output after every step, one number per line. Build:
     cc -DPHGMG_NO_OFFLINE -DMODEL_HEADER='"lin_gmgpod.h"' -DMODEL_NAME=lin_gmgpod \
        -I build/embedded controller.c -lm
   (add -DPHGMG_REAL_FLOAT for float). On a Cortex-M4F it is built by
   `make embedded` (semihosting printf). */
#define PHGMG_IMPLEMENTATION
#include "../../phgmg.h"
#include <stdio.h>
#include "controller_run.h"
#include MODEL_HEADER

static phgmg_real y[CTRL_STEPS + 1];

int main(void) {
  int i;
  phgmg_result rc = ctrl_run(&MODEL_NAME, y);
  if (rc != PHGMG_OK) {
    printf("error: %s\n", phgmg_result_string(rc));
    return 1;
  }
  for (i = 0; i <= CTRL_STEPS; ++i) printf(PHGMG_CTRL_FMT "\n", (double)y[i]);
  return 0;
}
