/* The online loop shared by the controller firmware and its host-side
   reference: 1000 steps of dt = 0.1 from x = 0 with u(t) = 0.1 sin t given
   at the three Gauss-Legendre stage times, output y after every step.
   Uses only the online API: no allocation, a static workspace. */
#ifndef PHGMG_CONTROLLER_RUN_H
#define PHGMG_CONTROLLER_RUN_H
#include <math.h>
#include <string.h>

#define CTRL_STEPS 1000
#define CTRL_RMAX 16
#define CTRL_MEM_BYTES PHGMG_ROM_STEPPER_MEMSIZE_MAX(CTRL_RMAX, 1, 8, 64)
#if PHGMG_REAL_IS_FLOAT
#define PHGMG_CTRL_FMT "%.9g"
#define CTRL_SIN(x) sinf(x)
#else
#define PHGMG_CTRL_FMT "%.17g"
#define CTRL_SIN(x) sin(x)
#endif

static double ctrl_mem[CTRL_MEM_BYTES / sizeof(double) + 1]; /* static workspace, no heap */

/* y[0..CTRL_STEPS]: the output at t = 0, 0.1, ..., 100 (m = 1). */
static phgmg_result ctrl_run(const phgmg_rom *rom, phgmg_real *y) {
  phgmg_rom_stepper st;
  phgmg_real x[CTRL_RMAX], u3[3], tc[3];
  phgmg_real work[CTRL_MEM_BYTES / sizeof(phgmg_real) / 4];
  const phgmg_real dt = (phgmg_real)0.1;
  phgmg_result rc;
  int n, i;
  if (rom->r > CTRL_RMAX || rom->m != 1 || phgmg_rom_eval_work_size(rom) > sizeof work / sizeof work[0])
    return PHGMG_ERR_SIZE;
  rc = phgmg_rom_stepper_init(&st, rom, dt, (phgmg_real)0, 20, ctrl_mem, sizeof ctrl_mem);
  if (rc != PHGMG_OK) return rc;
  for (i = 0; i < rom->r; ++i) x[i] = (phgmg_real)0;
  phgmg_rom_output(rom, x, &y[0], work);
  for (n = 0; n < CTRL_STEPS; ++n) {
    phgmg_rom_stage_times((phgmg_real)n * dt, dt, tc);
    for (i = 0; i < 3; ++i) u3[i] = (phgmg_real)0.1 * CTRL_SIN(tc[i]);
    rc = phgmg_rom_step(&st, x, u3, &y[n + 1], NULL);
    if (rc != PHGMG_OK) return rc;
  }
  return PHGMG_OK;
}
#endif
