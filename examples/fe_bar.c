/* fe_bar.c -- a model as a finite-element code writes it: an elastic bar with
   a consistent mass matrix, given as sparse matrices in a scrambled node
   ordering, reduced by every method phgmg has, errors against r.

   The bar (length 1, fixed at the left end, n linear elements):
     stiffness K = n tridiag(-1, 2, -1) (last diagonal 1),
     consistent mass M = (1 / 6n) tridiag(1, 4, 1) (last diagonal 2),
     Rayleigh damping D = 0.05 M + 1e-3 K.
   State x = (q, v) (N = 2n), in descriptor port-Hamiltonian form
     E x' = (J - R) Q x + B u,  y = B^T Q x,
   E = diag(I, M), Q = diag(K, I), J = [[0, I], [-I, 0]], R = diag(0, D), so
   that H = q^T K q / 2 + v^T M v / 2 (E^T Q = diag(K, M)). Ports: forces at
   the tip and at the middle node, their velocities as outputs. The matrices
   are handed over as CSC in a random ordering of the states (as an assembly
   code numbers its unknowns); phgmg orders them for its solver
   (phgmg_ph_sparse_create_e) and never forms M^-1.

   Training: one run, u_a(t) = sin((1 + a/2) t), dt = 0.05, 1000 steps. Test:
   u_a(t) = 0.5 sin(0.7 t) + 0.5 cos((1.3 + a/3) t), 1000 steps (not trained
   on). Methods: GMG-POD, GMG-QM (lambda validated by simulation,
   PHGMG_LAMBDA_VALIDATED), SP1, SP2 at r = 8, 14, 20; e_y is the relative output
   error of the reduced model (phgmg_reduced_validate).
   Output: a table, and DIR/fe_bar.csv (method, r, e_y train, e_y test).
   Usage: fe_bar [--n N] [--out DIR]     (defaults: n = 400 (N = 800), results) */
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { FB_STEPS = 1000, FB_M = 2, FB_MAXNZ = 8 };
static const double fb_dt = 0.05;

static void fb_train(double t, double *u, void *user) {
  (void)user;
  u[0] = sin(t); u[1] = sin(1.5 * t);
}
static void fb_test(double t, double *u, void *user) {
  (void)user;
  u[0] = 0.5 * sin(0.7 * t) + 0.5 * cos(1.3 * t);
  u[1] = 0.5 * sin(0.7 * t) + 0.5 * cos((1.3 + 1.0 / 3.0) * t);
}

/* One sparse matrix in CSC, assembled column by column (at most FB_MAXNZ
   entries per column of the natural ordering). */
typedef struct fb_csc {
  int *cp, *ri;
  double *v;
  phgmg_csc A;
} fb_csc;

/* The bar's blocks in the natural ordering: entry (i, j) of E, J, R or Q. */
static double fb_entry(char which, int n, int i, int j) {
  const double ka = n, ma = 1.0 / (6.0 * n);
  const int N = 2 * n;
  int bi, bj, a, b, d;
  double k, m;
  if (i < 0 || j < 0 || i >= N || j >= N) return 0.0;
  bi = i >= n; bj = j >= n; a = i - bi * n; b = j - bj * n; d = a - b;
  k = d == 0 ? (a == n - 1 ? ka : 2.0 * ka) : (d == 1 || d == -1) ? -ka : 0.0;
  m = d == 0 ? (a == n - 1 ? 2.0 * ma : 4.0 * ma) : (d == 1 || d == -1) ? ma : 0.0;
  switch (which) {
    case 'E': return bi != bj ? 0.0 : bi ? m : (d == 0 ? 1.0 : 0.0);
    case 'Q': return bi != bj ? 0.0 : bi ? (d == 0 ? 1.0 : 0.0) : k;
    case 'J': return d != 0 || bi == bj ? 0.0 : bi ? -1.0 : 1.0;
    default: return bi && bj ? 0.05 * m + 1e-3 * k : 0.0;   /* 'R' */
  }
}

/* CSC of block `which` in the user's ordering: user state i is natural state
   perm[i], so entry (a, j) of the scrambled matrix is the natural entry
   (perm[a], perm[j]). Rows in increasing order; O(N^2) scan, enough here. */
static int fb_csc_make(fb_csc *c, char which, int n, const int *perm) {
  const int N = 2 * n;
  int j, nz = 0, a, off[3] = {0, -1, 1};
  c->cp = (int *)malloc(sizeof(int) * (size_t)(N + 1));
  c->ri = (int *)malloc(sizeof(int) * (size_t)N * FB_MAXNZ);
  c->v = (double *)malloc(sizeof(double) * (size_t)N * FB_MAXNZ);
  if (!c->cp || !c->ri || !c->v) return 0;
  for (j = 0; j < N; ++j) {   /* user column j = natural column perm[j] */
    const int bj = perm[j];
    c->cp[j] = nz;
    for (a = 0; a < N; ++a) {   /* rows: the few natural neighbours, in user order */
      const int bi = perm[a];
      int t, near = 0;
      for (t = 0; t < 3; ++t)
        if (bi == bj + off[t] || bi == bj + off[t] + n || bi == bj + off[t] - n) near = 1;
      if (near) {
        const double v = fb_entry(which, n, bi, bj);
        if (v != 0.0) { c->ri[nz] = a; c->v[nz] = v; ++nz; }
      }
    }
  }
  c->cp[N] = nz;
  c->A.n_rows = c->A.n_cols = N; c->A.colptr = c->cp; c->A.rowidx = c->ri; c->A.values = c->v;
  return 1;
}
static void fb_csc_free(fb_csc *c) { free(c->cp); free(c->ri); free(c->v); }

/* A random ordering of 0..N-1 (a fixed linear congruential sequence). */
static void fb_scramble(int N, int *perm) {
  unsigned long s = 12345u;
  int i;
  for (i = 0; i < N; ++i) perm[i] = i;
  for (i = N - 1; i > 0; --i) {
    int j, t;
    s = (s * 1103515245u + 12345u) & 0x7fffffffu;
    j = (int)(s % (unsigned long)(i + 1));
    t = perm[i]; perm[i] = perm[j]; perm[j] = t;
  }
}

/* e_y of one method at one r on the training and the test run (Y: the full
   model's outputs of both, m x (steps + 1) each); -1 when the reduction or a
   reduced run fails (reported). */
static void fb_method(const phgmg_ph_system *sys, const double *X, const double *const Y[2], phgmg_method meth,
                      int r, double ey[2]) {
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  phgmg_reduce_info info;
  phgmg_run run;
  phgmg_sim_out so;
  phgmg_result rc;
  double Yr[FB_M * (FB_STEPS + 1)];
  int k;
  ey[0] = ey[1] = -1.0;
  phgmg_reduce_opts_default(&o);
  o.method = meth; o.r = r;
  memset(&run, 0, sizeof run);
  run.u = fb_train; run.dt = fb_dt; run.nsteps = FB_STEPS;
  if (meth == PHGMG_METHOD_GMG_QM) { o.select.lambda_mode = PHGMG_LAMBDA_VALIDATED; o.nrun = 1; o.runs = &run; }   /* lambda validated */
  rc = phgmg_reduce(&red, sys, X, sys->N, FB_STEPS + 1, &o, &info, NULL);
  if (rc != PHGMG_OK) { printf("  reduce failed: %s\n", phgmg_result_string(rc)); return; }
  if (meth == PHGMG_METHOD_GMG_QM && info.lambda == HUGE_VAL)
    printf("  GMG-QM r = %d: the validation chose M = 0 (the quadratic term does not pay on this linear model)\n", r);
  for (k = 0; k < 2; ++k) {   /* from x = 0 (rho(0) = 0), the online stepper */
    run.u = k ? fb_test : fb_train;
    memset(&so, 0, sizeof so);
    so.Y = Yr;
    rc = phgmg_reduced_simulate_run(red, &run, 0.0, 0, &so, NULL);
    if (rc == PHGMG_OK) ey[k] = phgmg_rel_error(FB_M, FB_STEPS + 1, Y[k], FB_M, Yr, FB_M);
    else printf("  %s run: %s after %d steps\n", k ? "test" : "training", phgmg_result_string(rc), so.steps_done);
  }
  phgmg_reduced_destroy(red);
}

int main(int argc, char **argv) {
  static const phgmg_method meths[4] = {PHGMG_METHOD_GMG_POD, PHGMG_METHOD_GMG_QM, PHGMG_METHOD_SP1,
                                        PHGMG_METHOD_SP2};
  static const char *const names[4] = {"GMG-POD", "GMG-QM", "SP1", "SP2"};
  static const int rs[3] = {8, 14, 20};
  const char *out = "results";
  int n = 400, N, i, j, k, *perm, ok;
  fb_csc cE, cJ, cR, cQ;
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_sparse_info inf;
  phgmg_ph_system sys;
  phgmg_run run;
  phgmg_sim_out so;
  double *B, *X, *Yf, ey[2];
  const double *Y[2];
  char path[512];
  FILE *f;
  for (i = 1; i < argc; ++i) {
    if (!strcmp(argv[i], "--n") && i + 1 < argc) n = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
    else { fprintf(stderr, "usage: %s [--n N] [--out DIR]\n", argv[0]); return 2; }
  }
  if (n < 12 || n > 100000) { fprintf(stderr, "fe_bar: --n must be in 12..100000\n"); return 2; }
  N = 2 * n;
  perm = (int *)malloc(sizeof(int) * (size_t)N);
  B = (double *)calloc((size_t)N * FB_M, sizeof(double));
  X = (double *)malloc(sizeof(double) * (size_t)N * (FB_STEPS + 1));
  Yf = (double *)malloc(sizeof(double) * 2 * FB_M * (FB_STEPS + 1));
  if (!perm || !B || !X || !Yf) { fprintf(stderr, "fe_bar: out of memory\n"); return 1; }
  fb_scramble(N, perm);
  ok = fb_csc_make(&cE, 'E', n, perm) && fb_csc_make(&cJ, 'J', n, perm) && fb_csc_make(&cR, 'R', n, perm) &&
       fb_csc_make(&cQ, 'Q', n, perm);
  for (i = 0; i < N; ++i) {   /* forces on the velocities of the tip and the middle node */
    if (perm[i] == n + n - 1) B[i] = 1.0;
    if (perm[i] == n + n / 2 - 1) B[i + N] = 1.0;
  }
  if (!ok || phgmg_ph_sparse_create_e(&sp, N, FB_M, &cJ.A, &cR.A, &cQ.A, &cE.A, B, NULL, &inf, NULL) != PHGMG_OK) {
    fprintf(stderr, "fe_bar: model setup failed\n");
    return 1;
  }
  sys = *phgmg_ph_sparse_system(sp);
  printf("fe_bar: bar with consistent mass, n = %d elements, N = %d, scrambled ordering; "
         "solver half-bandwidth %d after reordering\n", n, N, inf.kb);
  memset(&run, 0, sizeof run);   /* the full model: training snapshots, test outputs */
  run.u = fb_train; run.dt = fb_dt; run.nsteps = FB_STEPS;
  Y[0] = Yf; Y[1] = Yf + FB_M * (FB_STEPS + 1);
  ok = phgmg_simulate_inputs(&sys, 1, &run, NULL, X, N, Yf, NULL, NULL) == PHGMG_OK;
  run.u = fb_test;
  memset(&so, 0, sizeof so);
  so.Y = Yf + FB_M * (FB_STEPS + 1);
  ok = ok && phgmg_simulate_run(&sys, &run, NULL, &so, NULL) == PHGMG_OK;
  if (!ok) { fprintf(stderr, "fe_bar: full-model simulation failed\n"); return 1; }
  snprintf(path, sizeof path, "%s/fe_bar.csv", out);
  f = fopen(path, "w");
  if (!f) { fprintf(stderr, "fe_bar: cannot write %s\n", path); return 1; }
  fprintf(f, "method,r,ey_train,ey_test\n");
  printf("%-8s %4s %12s %12s\n", "method", "r", "e_y train", "e_y test");
  for (j = 0; j < 4; ++j)
    for (k = 0; k < 3; ++k) {
      fb_method(&sys, X, Y, meths[j], rs[k], ey);
      printf("%-8s %4d %12.3e %12.3e\n", names[j], rs[k], ey[0], ey[1]);
      fprintf(f, "%s,%d,%.6e,%.6e\n", names[j], rs[k], ey[0], ey[1]);
    }
  fclose(f);
  printf("fe_bar: wrote %s\n", path);
  phgmg_ph_sparse_destroy(sp);
  fb_csc_free(&cE); fb_csc_free(&cJ); fb_csc_free(&cR); fb_csc_free(&cQ);
  free(perm); free(B); free(X); free(Yf);
  return 0;
}
