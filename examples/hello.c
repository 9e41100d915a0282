/* hello.c -- phgmg in one page: a damped chain of 50 masses (N = 100 states),
   simulated for snapshots, reduced to r = 10 by GMG-POD, the reduced model
   stepped online and compared with the full model's output.
   Build: cc -std=c99 -O2 examples/hello.c -o build/hello -lm */
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

enum { NM = 50, N = 2 * NM, R_ORDER = 10, STEPS = 500 };  /* x = (q_1..q_50, p_1..p_50) */
static void u_sin(double t, double *u, void *user) { (void)user; u[0] = 0.1 * sin(t); }

int main(void) {
  static double J[N * N], R[N * N], Q[N * N], B[N], X[N * (STEPS + 1)], Y[STEPS + 1], x0[N];
  static double mem[8192];                   /* the online stepper's memory */
  phgmg_ph_system sys;
  phgmg_reduce_opts o;
  phgmg_reduced *red;
  phgmg_rom_stepper st;
  phgmg_real xr[R_ORDER] = {0}, u3[3], tc[3], y[1];
  double num = 0, den = 0;
  int i, n, rc;
  memset(&sys, 0, sizeof sys);               /* zero fields: defaults */
  memset(&o, 0, sizeof o);
  for (i = 0; i < NM; ++i) {                 /* H = q^T K q / 2 + |p|^2 / 2 */
    J[i + (NM + i) * N] = 1; J[NM + i + i * N] = -1;   /* q' = p, p' = -K q - c p + B u */
    R[(NM + i) * (N + 1)] = 1;                           /* a damper on every mass */
    Q[i * (N + 1)] = 2; Q[(NM + i) * (N + 1)] = 1;       /* K = tridiag(-1, 2, -1) */
    if (i + 1 < NM) Q[i + 1 + i * N] = Q[i + (i + 1) * N] = -1;
  }
  B[NM] = 1;                                 /* force on mass 1; y = its velocity */
  sys.N = N; sys.m = 1; sys.J = J; sys.R = R; sys.Q = Q; sys.B = B;
  rc = phgmg_simulate(&sys, x0, 0.0, 0.1, STEPS, u_sin, NULL, NULL, X, Y, NULL, NULL, NULL, NULL);
  if (rc != PHGMG_OK) { printf("simulate: %s\n", phgmg_result_string((phgmg_result)rc)); return 1; }

  o.method = PHGMG_METHOD_GMG_POD; o.r = R_ORDER; o.dt = 0.1;   /* dt: exact linear step map */
  rc = phgmg_reduce(&red, &sys, X, N, STEPS + 1, &o, NULL, NULL);
  if (rc != PHGMG_OK) { printf("reduce: %s\n", phgmg_result_string((phgmg_result)rc)); return 1; }

  /* online: no allocation, cost independent of N */
  rc = phgmg_rom_stepper_init(&st, phgmg_reduced_rom(red), (phgmg_real)0.1, 0, 0, mem, sizeof mem);
  for (n = 0; rc == PHGMG_OK && n < STEPS; ++n) {
    phgmg_rom_stage_times((phgmg_real)(0.1 * n), (phgmg_real)0.1, tc);
    for (i = 0; i < 3; ++i) u3[i] = (phgmg_real)(0.1 * sin((double)tc[i]));
    rc = phgmg_rom_step(&st, xr, u3, y, NULL);
    num += ((double)y[0] - Y[n + 1]) * ((double)y[0] - Y[n + 1]);
    den += Y[n + 1] * Y[n + 1];
  }
  phgmg_reduced_destroy(red);
  if (rc != PHGMG_OK) { printf("online: %s\n", phgmg_result_string((phgmg_result)rc)); return 1; }
  printf("N = %d -> r = %d: relative output error e_y = %.2e\n", N, R_ORDER, sqrt(num / den));
  return sqrt(num / den) < 1e-2 ? 0 : 1;
}
