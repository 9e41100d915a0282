/* circuit_dae.c -- a model as a circuit tool writes it: an RLC ladder in
   modified nodal analysis form, with nodes that carry no capacitor (their
   Kirchhoff current laws are algebraic constraints: E has zero rows and
   columns), reduced by every method phgmg has, errors against r.

   The ladder (n sections): nodes 0..n, inductor k (k = 1..n, L = 1) from
   node k-1 to node k; a capacitor C = 1 to ground at every even node, a
   conductance G = 1 to ground at every odd node and no capacitor there. A
   current source u drives node 0; the output is its voltage phi_0, so that
   y u is the power supplied. In port-Hamiltonian descriptor form
     E x' = (J - R) x + B u,  y = B^T x,  x = (phi_0, i_1, phi_1, i_2, ..., i_n, phi_n),
   E = diag(C at the nodes, L at the inductors) -- zero at the odd nodes --,
   J the node-branch incidence (KCL rows C phi_j' = i_j - i_{j+1} - G_j phi_j,
   inductor rows L i_k' = phi_{k-1} - phi_k), R = diag(G at the odd nodes),
   H = sum C phi_j^2 / 2 + sum L i_k^2 / 2 (the interleaved ordering keeps
   every matrix tridiagonal: banded storage, kb = 1). The odd nodes' laws
   0 = i_j - i_{j+1} - G phi_j fix their potentials: index one (a node with
   neither capacitor nor conductance would be index two: PHGMG_ERR_INDEX).
   phgmg condenses the model (phgmg_dae_create: n/2 algebraic variables
   eliminated, each a resistor 1/G in an inductor mesh), simulates it with
   consistent states (phgmg_simulate) and reduces the condensed ODE.

   Training: u(t) = sin(0.5 t) + 0.5 sin(1.3 t), dt = 0.1, 1000 steps. Test:
   u(t) = 0.8 cos(0.9 t) + 0.4 sin(0.3 t) (not trained on). Methods:
   GMG-POD, GMG-QM (lambda validated by simulation), SP1, SP2 at r = 6, 10,
   14, 18; e_y is the relative output error of the reduced model.
   Output: a table, and DIR/circuit_dae.csv (method, r, e_y train, e_y test;
   and the largest Kirchhoff residual at the algebraic nodes of the full
   simulation). Usage: circuit_dae [--n N] [--out DIR]  (defaults 100, results) */
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { CD_STEPS = 1000 };
static const double cd_dt = 0.1, cd_G = 1.0;

static void cd_train(double t, double *u, void *user) { (void)user; u[0] = sin(0.5 * t) + 0.5 * sin(1.3 * t); }
static void cd_test(double t, double *u, void *user) { (void)user; u[0] = 0.8 * cos(0.9 * t) + 0.4 * sin(0.3 * t); }

/* Band storage (kb = 1) of the ladder's E, J, R; Q = I. */
static void cd_ladder(int n, double *E, double *J, double *R, double *Q, double *B) {
  const int N = 2 * n + 1;
  int j, k;
#define CD(M, a, b) M[(size_t)(1 + (a) - (b)) + (size_t)(b) * 3]
  for (j = 0; j <= n; ++j) {   /* node j: state 2 j */
    CD(E, 2 * j, 2 * j) = j % 2 == 0 ? 1.0 : 0.0;
    CD(R, 2 * j, 2 * j) = j % 2 == 1 ? cd_G : 0.0;
  }
  for (k = 1; k <= n; ++k) {   /* inductor k: state 2 k - 1, between nodes k - 1 and k */
    CD(E, 2 * k - 1, 2 * k - 1) = 1.0;
    CD(J, 2 * k - 1, 2 * k - 2) = 1.0;  CD(J, 2 * k - 2, 2 * k - 1) = -1.0;   /* enters node k-1's law with -i_k */
    CD(J, 2 * k - 1, 2 * k) = -1.0;     CD(J, 2 * k, 2 * k - 1) = 1.0;      /* and node k's with +i_k */
  }
  for (j = 0; j < N; ++j) CD(Q, j, j) = 1.0;
#undef CD
  B[0] = 1.0;
}

static void cd_method(const phgmg_ph_system *sys, const double *X, const double *const Y[2], phgmg_method meth,
                      int r, double ey[2]) {
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  phgmg_reduce_info info;
  phgmg_run run;
  phgmg_sim_out so;
  phgmg_result rc;
  double Yr[CD_STEPS + 1];
  int k;
  ey[0] = ey[1] = -1.0;
  phgmg_reduce_opts_default(&o);
  o.method = meth; o.r = r;
  memset(&run, 0, sizeof run);
  run.u = cd_train; run.dt = cd_dt; run.nsteps = CD_STEPS;
  if (meth == PHGMG_METHOD_GMG_QM) { o.select.lambda_mode = PHGMG_LAMBDA_VALIDATED; o.nrun = 1; o.runs = &run; }   /* lambda validated */
  rc = phgmg_reduce(&red, sys, X, sys->N, CD_STEPS + 1, &o, &info, NULL);
  if (rc != PHGMG_OK) { printf("  reduce failed: %s\n", phgmg_result_string(rc)); return; }
  if (meth == PHGMG_METHOD_GMG_QM && info.lambda == HUGE_VAL)
    printf("  GMG-QM r = %d: the validation chose M = 0 (the quadratic term does not pay on this linear model)\n", r);
  for (k = 0; k < 2; ++k) {
    run.u = k ? cd_test : cd_train;
    memset(&so, 0, sizeof so);
    so.Y = Yr;
    rc = phgmg_reduced_simulate_run(red, &run, 0.0, 0, &so, NULL);
    if (rc == PHGMG_OK) ey[k] = phgmg_rel_error(1, CD_STEPS + 1, Y[k], 1, Yr, 1);
    else printf("  %s run: %s after %d steps\n", k ? "test" : "training", phgmg_result_string(rc), so.steps_done);
  }
  phgmg_reduced_destroy(red);
}

/* The largest Kirchhoff residual |i_j - i_{j+1} - G phi_j| at the odd nodes,
   relative to the largest current, over the trajectory X (N x (steps+1)). */
static double cd_kcl(int n, const double *X) {
  const int N = 2 * n + 1;
  double res = 0.0, imax = 0.0;
  int s, j;
  for (s = 0; s <= CD_STEPS; ++s) {
    const double *x = X + (size_t)s * N;
    for (j = 1; j <= n; j += 2) {
      const double in = x[2 * j - 1], out = j < n ? x[2 * j + 1] : 0.0;
      res = fmax(res, fabs(in - out - cd_G * x[2 * j]));
      imax = fmax(imax, fabs(in));
    }
  }
  return res / imax;
}

int main(int argc, char **argv) {
  static const phgmg_method meths[4] = {PHGMG_METHOD_GMG_POD, PHGMG_METHOD_GMG_QM, PHGMG_METHOD_SP1,
                                        PHGMG_METHOD_SP2};
  static const char *const names[4] = {"GMG-POD", "GMG-QM", "SP1", "SP2"};
  static const int rs[4] = {6, 10, 14, 18};
  const char *out = "results";
  int n = 100, N, i, j, k;
  phgmg_ph_system sys;
  phgmg_dae *dae = NULL;
  const phgmg_ph_system *cs;
  double *E, *J, *R, *Q, *B, *X, *Xi, *Yf, ey[2], kcl;
  const double *Y[2];
  phgmg_result rc;
  char path[512];
  FILE *f;
  for (i = 1; i < argc; ++i) {
    if (!strcmp(argv[i], "--n") && i + 1 < argc) n = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
    else { fprintf(stderr, "usage: %s [--n N] [--out DIR]\n", argv[0]); return 2; }
  }
  if (n < 12 || n > 100000) { fprintf(stderr, "circuit_dae: --n must be in 12..100000\n"); return 2; }
  N = 2 * n + 1;
  E = (double *)calloc((size_t)3 * N, sizeof(double)); J = (double *)calloc((size_t)3 * N, sizeof(double));
  R = (double *)calloc((size_t)3 * N, sizeof(double)); Q = (double *)calloc((size_t)3 * N, sizeof(double));
  B = (double *)calloc((size_t)N, sizeof(double));
  X = (double *)malloc(sizeof(double) * (size_t)N * (CD_STEPS + 1));
  Xi = (double *)malloc(sizeof(double) * (size_t)N * (CD_STEPS + 1));
  Yf = (double *)malloc(sizeof(double) * 2 * (CD_STEPS + 1));
  if (!E || !J || !R || !Q || !B || !X || !Xi || !Yf) { fprintf(stderr, "circuit_dae: out of memory\n"); return 1; }
  cd_ladder(n, E, J, R, Q, B);
  memset(&sys, 0, sizeof sys);
  sys.N = N; sys.m = 1; sys.storage = PHGMG_BANDED; sys.kb = 1;
  sys.E = E; sys.J = J; sys.R = R; sys.Q = Q; sys.B = B;
  rc = phgmg_ph_validate(&sys, 0.0, NULL, NULL);
  if (rc == PHGMG_OK) rc = phgmg_dae_create(&dae, &sys, 0.0, NULL);
  if (rc != PHGMG_OK) { fprintf(stderr, "circuit_dae: the model: %s\n", phgmg_result_string(rc)); return 1; }
  cs = phgmg_dae_system(dae);
  printf("circuit_dae: RLC ladder, %d sections, N = %d (%d nodes without capacitor: algebraic); condensed to "
         "N = %d differential states, half-bandwidth %d%s\n", n, N, phgmg_dae_nalg(dae), cs->N, cs->kb,
         cs->P || cs->S ? ", with feedthrough" : "");
  /* the full model: training trajectory (consistent states), outputs of both inputs */
  memset(Xi, 0, sizeof(double) * (size_t)N);
  Y[0] = Yf; Y[1] = Yf + CD_STEPS + 1;
  rc = phgmg_simulate(&sys, Xi, 0.0, cd_dt, CD_STEPS, cd_train, NULL, NULL, X, Yf, NULL, NULL, NULL, NULL);
  if (rc == PHGMG_OK)
    rc = phgmg_simulate(&sys, Xi, 0.0, cd_dt, CD_STEPS, cd_test, NULL, NULL, NULL, Yf + CD_STEPS + 1, NULL, NULL, NULL, NULL);
  if (rc != PHGMG_OK) { fprintf(stderr, "circuit_dae: full-model simulation failed: %s\n", phgmg_result_string(rc)); return 1; }
  kcl = cd_kcl(n, X);
  printf("circuit_dae: largest Kirchhoff residual at the algebraic nodes (relative): %.2e\n", kcl);
  for (k = 0; k <= CD_STEPS; ++k) phgmg_dae_restrict(dae, X + (size_t)k * N, Xi + (size_t)k * cs->N);
  snprintf(path, sizeof path, "%s/circuit_dae.csv", out);
  f = fopen(path, "w");
  if (!f) { fprintf(stderr, "circuit_dae: cannot write %s\n", path); return 1; }
  fprintf(f, "method,r,ey_train,ey_test\nKCL,0,%.6e,%.6e\n", kcl, kcl);
  printf("%-8s %4s %12s %12s\n", "method", "r", "e_y train", "e_y test");
  for (j = 0; j < 4; ++j)
    for (k = 0; k < 4; ++k) {
      cd_method(cs, Xi, Y, meths[j], rs[k], ey);
      printf("%-8s %4d %12.3e %12.3e\n", names[j], rs[k], ey[0], ey[1]);
      fprintf(f, "%s,%d,%.6e,%.6e\n", names[j], rs[k], ey[0], ey[1]);
    }
  fclose(f);
  printf("circuit_dae: wrote %s\n", path);
  phgmg_dae_destroy(dae);
  free(E); free(J); free(R); free(Q); free(B); free(X); free(Xi); free(Yf);
  return 0;
}
