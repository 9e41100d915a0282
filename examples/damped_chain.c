/* damped_chain.c -- nonlinear dissipation: the paper's mass-spring chain
   (Section 5.2: n masses m = 2, springs k = 1, force on the first mass) with
   its linear dampers weakened to c = 0.05 and a nonlinear damper on every
   mass, force rho(v) = 0.1 v + 2 v^3 on its velocity v = p / m (a co-state
   component: damp_i = 2i + 1, manual 1.7). The dampers dissipate for every
   velocity (s rho(s) >= 0), so does every reduced model: its dampers are
   W_z^T c_k with the same law, hyper-reduced by non-negative weights.

   Training: u(t) = sin(t), dt = 0.1, 1000 steps (amplitude 1: the cubic
   term matters). Test: u(t) = 0.7 sin(0.6 t) + 0.5 cos(1.4 t). Methods:
   GMG-POD, SP1, SP2 at r = 6, 10, 14, 18 (GMG-QM does not take dampers);
   e_y is the relative output error of the reduced model; the energy column
   is the largest |H_n - H_0 - S_n + D_n| / max |H| of the reduced model's
   discrete energy balance (supply S, dissipation D of R and the dampers).
   Output: a table, and DIR/damped_chain.csv (method, r, e_y train, e_y test,
   energy, dampers kept). Usage: damped_chain [--n N] [--out DIR]
   (defaults: n = 100 masses (N = 200), results). */
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "msd_models.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { DC_STEPS = 1000 };
static const double dc_dt = 0.1;
static const double dc_law[4] = {0.0, 0.1, 0.0, 2.0};   /* rho(s) = 0.1 s + 2 s^3 */

static void dc_train(double t, double *u, void *user) { (void)user; u[0] = sin(t); }
static void dc_test(double t, double *u, void *user) { (void)user; u[0] = 0.7 * sin(0.6 * t) + 0.5 * cos(1.4 * t); }

static void dc_method(const phgmg_ph_system *sys, const double *X, const double *const Y[2], phgmg_method meth,
                      int r, double res[4]) {
  static double H[DC_STEPS + 1], S[DC_STEPS + 1], D[DC_STEPS + 1];
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  phgmg_energy en;
  double Yr[DC_STEPS + 1], xr0[64] = {0};
  phgmg_result rc;
  int k, n;
  res[0] = res[1] = res[2] = -1.0; res[3] = 0.0;
  phgmg_reduce_opts_default(&o);
  o.method = meth; o.r = r;
  rc = phgmg_reduce(&red, sys, X, sys->N, DC_STEPS + 1, &o, NULL, NULL);
  if (rc != PHGMG_OK) { printf("  reduce failed: %s\n", phgmg_result_string(rc)); return; }
  res[3] = phgmg_reduced_rom(red)->ndamp;
  for (k = 0; k < 2; ++k) {
    en.H = H; en.S = S; en.D = D;
    rc = phgmg_reduced_simulate(red, xr0, 0.0, dc_dt, DC_STEPS, k ? dc_test : dc_train, NULL, 0.0, 0, NULL, Yr,
                                k ? NULL : &en, NULL, NULL);
    if (rc != PHGMG_OK) { printf("  %s run: %s\n", k ? "test" : "training", phgmg_result_string(rc)); continue; }
    res[k] = phgmg_rel_error(1, DC_STEPS + 1, Y[k], 1, Yr, 1);
    if (!k) {
      double e = 0.0, h = 0.0;
      for (n = 0; n <= DC_STEPS; ++n) { e = fmax(e, fabs(H[n] - H[0] - S[n] + D[n])); h = fmax(h, fabs(H[n])); }
      res[2] = e / h;
    }
  }
  phgmg_reduced_destroy(red);
}

int main(int argc, char **argv) {
  static const phgmg_method meths[3] = {PHGMG_METHOD_GMG_POD, PHGMG_METHOD_SP1, PHGMG_METHOD_SP2};
  static const char *const names[3] = {"GMG-POD", "SP1", "SP2"};
  static const int rs[4] = {10, 18, 26, 34};
  const char *out = "results";
  int n = 30, i, j, k, *di = NULL;
  msd_linear M;
  double *c = NULL, *X = NULL, *Yf = NULL, *x0 = NULL, res[4];
  const double *Y[2];
  phgmg_result rc;
  char path[512];
  FILE *f;
  for (i = 1; i < argc; ++i) {
    if (!strcmp(argv[i], "--n") && i + 1 < argc) n = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
    else { fprintf(stderr, "usage: %s [--n N] [--out DIR]\n", argv[0]); return 2; }
  }
  if (n < 10 || n > 100000) { fprintf(stderr, "damped_chain: --n must be in 10..100000\n"); return 2; }
  c = (double *)malloc(sizeof(double) * (size_t)n);
  di = (int *)malloc(sizeof(int) * (size_t)n);
  X = (double *)malloc(sizeof(double) * 2 * (size_t)n * (DC_STEPS + 1));
  Yf = (double *)malloc(sizeof(double) * 2 * (DC_STEPS + 1));
  x0 = (double *)calloc(2 * (size_t)n, sizeof(double));
  if (!c || !di || !X || !Yf || !x0) { fprintf(stderr, "damped_chain: out of memory\n"); return 1; }
  for (i = 0; i < n; ++i) { c[i] = 0.05; di[i] = 2 * i + 1; }
  if (msd_linear_build(&M, n, NULL, NULL, c, PHGMG_BANDED) != 0) { fprintf(stderr, "damped_chain: model\n"); return 1; }
  M.sys.ndamp = n; M.sys.damp_i = di; M.sys.damp_j = NULL; M.sys.damp_deg = 3; M.sys.damp_poly = dc_law;
  rc = phgmg_ph_validate(&M.sys, 0.0, NULL, NULL);
  Y[0] = Yf; Y[1] = Yf + DC_STEPS + 1;
  if (rc == PHGMG_OK)
    rc = phgmg_simulate(&M.sys, x0, 0.0, dc_dt, DC_STEPS, dc_train, NULL, NULL, X, Yf, NULL, NULL, NULL, NULL);
  if (rc == PHGMG_OK)
    rc = phgmg_simulate(&M.sys, x0, 0.0, dc_dt, DC_STEPS, dc_test, NULL, NULL, NULL, Yf + DC_STEPS + 1, NULL, NULL,
                        NULL, NULL);
  if (rc != PHGMG_OK) { fprintf(stderr, "damped_chain: full model: %s\n", phgmg_result_string(rc)); return 1; }
  printf("damped_chain: %d masses (N = %d), a cubic damper on every mass\n", n, 2 * n);
  snprintf(path, sizeof path, "%s/damped_chain.csv", out);
  f = fopen(path, "w");
  if (!f) { fprintf(stderr, "damped_chain: cannot write %s\n", path); return 1; }
  fprintf(f, "method,r,ey_train,ey_test,energy,dampers\n");
  printf("%-8s %4s %12s %12s %12s %8s\n", "method", "r", "e_y train", "e_y test", "energy", "dampers");
  for (j = 0; j < 3; ++j)
    for (k = 0; k < 4; ++k) {
      dc_method(&M.sys, X, Y, meths[j], rs[k], res);
      printf("%-8s %4d %12.3e %12.3e %12.3e %8d\n", names[j], rs[k], res[0], res[1], res[2], (int)res[3]);
      fprintf(f, "%s,%d,%.6e,%.6e,%.6e,%d\n", names[j], rs[k], res[0], res[1], res[2], (int)res[3]);
    }
  fclose(f);
  printf("damped_chain: wrote %s\n", path);
  msd_linear_free(&M);
  free(c); free(di); free(X); free(Yf); free(x0);
  return 0;
}
