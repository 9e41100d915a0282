/* bench_desc.c — a descriptor model on a 2-D mesh: band LU against the sparse
   LU of the GL3 stage matrices sigma E + M (manual 2.6, 8.12).

   An nx x nx lattice of masses (unit springs to the four neighbours, on-site
   springs 0.1, damping 0.05 on each momentum), state (q, p) per mass, with a
   mass matrix coupling the momenta of neighbours: E = blockdiag(I on the
   positions, Mc on the momenta), Mc(n, n) = 1, Mc(n, k) = 0.1 for each
   neighbour k (diagonally dominant: symmetric positive definite, the
   pattern of a finite-element mass matrix). B = the momentum of mass 0,
   u(t) = 0.1 sin t, dt = 0.1, x0 = 0, linear.
   Each run: phgmg_ph_sparse_create_e, phgmg_ph_sparse_set_solver (BAND or
   SPARSE_LU, forced), phgmg_simulate of --steps steps (outputs only); the
   two solvers run in turn (paired), --runs pairs. Prints the median, min and
   max wall time of each, the median of the pairs' ratios band / sparse, the
   predicted LU entries of both and the largest relative difference of the
   outputs.
   --swap 1: the columns of E and Q of the masses 2k and 2k + 1 exchanged
   (the same dynamics; sigma E + M then has zero diagonals: the sparse LU's
   column matching puts E's entries back on its diagonal).
   --setup 1: instead, the set-up of one model with the automatic solver
   choice, phase by phase: phgmg_ph_sparse_create_e (ordering, matching,
   analysis), phgmg_ph_validate (first call; a second call reuses the
   result), phgmg_dae_create (no algebraic line: reuses it too) and
   phgmg_simulate of --steps steps; and whether the sparse LU served the
   whole run (phgmg_gl3_stats).

     cc -std=c99 -O2 -march=native bench/bench_desc.c -o build/bench_desc -lm
     ./build/bench_desc --nx 71 --steps 1000 --runs 5 [--out bench/results.csv]
     ./build/bench_desc --nx 40 --steps 100 --swap 1 --setup 1 */
#define _POSIX_C_SOURCE 199309L
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "bench_args.h"
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

typedef struct bd_csc { int *cp, *ri; double *v; phgmg_csc A; } bd_csc;

static double bd_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Column j of matrix a (0 J, 1 R, 2 Q, 3 E) of the lattice: rows increasing. */
static int bd_col(int a, int nx, int j, int *ri, double *v) {
  const int n = j / 2, x = n % nx, y = n / nx, isp = j & 1;
  int k = 0, d, nb[4], nn = 0;
  if (y > 0) nb[nn++] = n - nx;
  if (x > 0) nb[nn++] = n - 1;
  if (x + 1 < nx) nb[nn++] = n + 1;
  if (y + 1 < nx) nb[nn++] = n + nx;
  if (a == 0) { ri[0] = isp ? 2 * n : 2 * n + 1; v[0] = isp ? 1.0 : -1.0; return 1; }
  if (a == 1) { if (!isp) return 0; ri[0] = j; v[0] = 0.05; return 1; }
  if (a == 2 && isp) { ri[0] = j; v[0] = 1.0; return 1; }
  if (a == 3 && !isp) { ri[0] = j; v[0] = 1.0; return 1; }
  for (d = 0; d < nn; ++d) /* Q: the stiffness on the positions; E: Mc on the momenta */
    if (nb[d] < n) { ri[k] = 2 * nb[d] + isp; v[k++] = a == 2 ? -1.0 : 0.1; }
  ri[k] = j; v[k++] = a == 2 ? nn + 0.1 : 1.0;
  for (d = 0; d < nn; ++d)
    if (nb[d] > n) { ri[k] = 2 * nb[d] + isp; v[k++] = a == 2 ? -1.0 : 0.1; }
  return k;
}

static void bd_build(bd_csc *M, int a, int nx, int swap) {
  const int N = 2 * nx * nx;
  int j, nz = 0;
  M->cp = (int *)malloc(sizeof(int) * (size_t)(N + 1));
  M->ri = (int *)malloc(sizeof(int) * (size_t)N * 5);
  M->v = (double *)malloc(sizeof(double) * (size_t)N * 5);
  for (j = 0; j < N; ++j) {
    const int src = swap && a >= 2 && (j ^ 2) < N ? j ^ 2 : j; /* E P, Q P */
    M->cp[j] = nz;
    nz += bd_col(a, nx, src, M->ri + nz, M->v + nz);
  }
  M->cp[N] = nz;
  M->A.n_rows = M->A.n_cols = N;
  M->A.colptr = M->cp; M->A.rowidx = M->ri; M->A.values = M->v;
}

static void bd_u(double t, double *u, void *user) { (void)user; u[0] = 0.1 * sin(t); }

/* One run with the solver forced: wall seconds, outputs into Y. */
static double bd_run(const bd_csc *M, const double *B, int N, int solver, int steps, double *Y,
                     phgmg_ph_sparse_info *inf) {
  phgmg_ph_sparse *sp = NULL;
  double *x0 = (double *)calloc((size_t)N, sizeof(double)), t0 = bd_now(), t1;
  phgmg_result rc = phgmg_ph_sparse_create_e(&sp, N, 1, &M[0].A, &M[1].A, &M[2].A, &M[3].A, B, NULL, inf, NULL);
  if (rc == PHGMG_OK) rc = phgmg_ph_sparse_set_solver(sp, solver, inf);
  if (rc == PHGMG_OK)
    rc = phgmg_simulate(phgmg_ph_sparse_system(sp), x0, 0.0, 0.1, steps, bd_u, NULL, NULL, NULL, Y, NULL, NULL,
                        NULL, NULL);
  t1 = bd_now();
  phgmg_ph_sparse_destroy(sp);
  free(x0);
  if (rc != PHGMG_OK) { fprintf(stderr, "bench_desc: %s\n", phgmg_result_string(rc)); exit(1); }
  return t1 - t0;
}

/* --setup: the phases of one model's set-up and run, timed. */
static void bd_setup(const bd_csc *M, const double *B, int N, int steps) {
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_sparse_info inf;
  phgmg_gl3_stats st;
  phgmg_dae *dae = NULL;
  double *x0 = (double *)calloc((size_t)N, sizeof(double)), *Y = (double *)malloc(sizeof(double) * (size_t)(steps + 1));
  double t[6];
  phgmg_result rc, rv, rv2;
  t[0] = bd_now();
  rc = phgmg_ph_sparse_create_e(&sp, N, 1, &M[0].A, &M[1].A, &M[2].A, &M[3].A, B, NULL, &inf, NULL);
  t[1] = bd_now();
  if (rc != PHGMG_OK) { fprintf(stderr, "bench_desc: %s\n", phgmg_result_string(rc)); exit(1); }
  rv = phgmg_ph_validate(phgmg_ph_sparse_system(sp), 0.0, NULL, NULL);
  t[2] = bd_now();
  rv2 = phgmg_ph_validate(phgmg_ph_sparse_system(sp), 0.0, NULL, NULL);
  t[3] = bd_now();
  rc = phgmg_dae_create(&dae, phgmg_ph_sparse_system(sp), 0.0, NULL);
  phgmg_dae_destroy(dae);
  t[4] = bd_now();
  if (rc == PHGMG_OK)
    rc = phgmg_simulate(phgmg_ph_sparse_system(sp), x0, 0.0, 0.1, steps, bd_u, NULL, NULL, NULL, Y, NULL, &st, NULL,
                        NULL);
  t[5] = bd_now();
  if (rc != PHGMG_OK || rv != PHGMG_OK || rv2 != PHGMG_OK) {
    fprintf(stderr, "bench_desc: %s\n", phgmg_result_string(rc != PHGMG_OK ? rc : rv != PHGMG_OK ? rv : rv2));
    exit(1);
  }
  printf("setup N = %d (kb %d): solver %s (%d columns matched, %d condensed)\n", N, inf.kb,
         inf.solver == PHGMG_SOLVER_SPARSE_LU ? "sparse LU" : "band LU", inf.colperm, inf.condensed);
  printf("  create %.3f s, validate %.3f s, validate again %.3f s, dae_create %.3f s, simulate %d steps %.3f s "
         "(sparse LU throughout: %s)\n", t[1] - t[0], t[2] - t[1], t[3] - t[2], t[4] - t[3], steps, t[5] - t[4],
         st.sparse_lu && !st.band_fallback ? "yes" : "no, band LU fall-back");
  phgmg_ph_sparse_destroy(sp);
  free(x0); free(Y);
}

static int bd_cmp(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}
static double bd_median(double *t, int n) {
  qsort(t, (size_t)n, sizeof(double), bd_cmp);
  return n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
}

int main(int argc, char **argv) {
  static const char *const extra[] = {"--nx", "--steps", "--runs", "--swap", "--setup", NULL};
  const char *val[5] = {NULL, NULL, NULL, NULL, NULL}, *out;
  int nx, steps, runs, N, a, r, i, err;
  double *tb, *ts, *tr, *Yb, *Ys, *B, d = 0.0, ym = 0.0, mb, ms, mr;
  bd_csc M[4];
  phgmg_ph_sparse_info ib, is;
  FILE *csv;
  if ((r = bench_args(argc, argv, "bench_desc", "a 2-D descriptor lattice: band LU vs sparse LU", &out, extra, val)))
    return r == 1 ? 0 : 2;
  nx = val[0] ? atoi(val[0]) : 71;
  steps = val[1] ? atoi(val[1]) : 1000;
  runs = val[2] ? atoi(val[2]) : 3;
  if (nx < 2 || steps < 1 || runs < 1) { fprintf(stderr, "bench_desc: bad --nx, --steps or --runs\n"); return 2; }
  N = 2 * nx * nx;
  for (a = 0; a < 4; ++a) bd_build(&M[a], a, nx, val[3] && atoi(val[3]));
  B = (double *)calloc((size_t)N, sizeof(double));
  B[1] = 1.0;
  if (val[4] && atoi(val[4])) {
    bd_setup(M, B, N, steps);
    for (a = 0; a < 4; ++a) { free(M[a].cp); free(M[a].ri); free(M[a].v); }
    free(B);
    return 0;
  }
  csv = bench_open_csv("bench_desc", out, &err);
  if (err) return 1;
  tb = (double *)malloc(sizeof(double) * (size_t)runs); ts = (double *)malloc(sizeof(double) * (size_t)runs);
  tr = (double *)malloc(sizeof(double) * (size_t)runs);
  Yb = (double *)malloc(sizeof(double) * (size_t)(steps + 1)); Ys = (double *)malloc(sizeof(double) * (size_t)(steps + 1));
  for (r = 0; r < runs; ++r) {
    tb[r] = bd_run(M, B, N, PHGMG_SOLVER_BAND, steps, Yb, &ib);
    ts[r] = bd_run(M, B, N, PHGMG_SOLVER_SPARSE_LU, steps, Ys, &is);
    tr[r] = tb[r] / ts[r];
    printf("  run %d: band %.3f s, sparse %.3f s\n", r + 1, tb[r], ts[r]);
    fflush(stdout);
  }
  for (i = 0; i <= steps; ++i) { d = fmax(d, fabs(Yb[i] - Ys[i])); ym = fmax(ym, fabs(Yb[i])); }
  printf("desc2d nx = %d, N = %d, %d steps: kb %d, LU entries band %.3g sparse %.3g (%d condensed), "
         "flops band %.3g sparse %.3g\n", nx, N, steps, ib.kb, ib.lu_band, is.lu_sparse, is.condensed,
         ib.flops_band, is.flops_sparse);
  printf("  max |y_band - y_sparse| / max |y_band| = %.2e\n", ym > 0.0 ? d / ym : d);
  mb = bd_median(tb, runs); ms = bd_median(ts, runs); mr = bd_median(tr, runs); /* (sorted) */
  printf("  median band %.3f s (%.3f - %.3f), sparse %.3f s (%.3f - %.3f), ratio band / sparse %.1f\n", mb, tb[0],
         tb[runs - 1], ms, ts[0], ts[runs - 1], mr);
  if (csv) {
    fprintf(csv, "desc2d_N%d_band,%.6f,%.6f,%.6f,%d\n", N, mb, tb[0], tb[runs - 1], runs);
    fprintf(csv, "desc2d_N%d_sparse,%.6f,%.6f,%.6f,%d\n", N, ms, ts[0], ts[runs - 1], runs);
    fclose(csv);
  }
  for (a = 0; a < 4; ++a) { free(M[a].cp); free(M[a].ri); free(M[a].v); }
  free(B); free(tb); free(ts); free(tr); free(Yb); free(Ys);
  return 0;
}
