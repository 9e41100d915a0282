/* Dense kernel timings: LU (n = 1000), thin SVD of a 1000 x 1001 matrix of
   rank 90 built from random factors, GEMM (n = 1000); POD of 40 modes of the
   1001 snapshots of the paper's nonlinear chain at N = 64000 (banded, u = 0.1
   sin t, dt = 0.1, x0 = 0): offline_pod_rand_N64000 = phgmg_pod_randomized
   (q = 2, oversampling 20), offline_pod_exact_N64000 = phgmg_pod (3 runs);
   the line after them shows the largest relative error of the 40 singular
   values of the randomized against the exact POD. Each case runs once to
   warm up, then RUNS times; prints median/min/max seconds and GFLOP/s, and
   appends `case,median_s,min_s,max_s,runs` lines to the CSV file given
   with --out (a header line is written when the file is empty).
     cc -std=c99 -O2 -march=native bench/bench_linalg.c -lm && ./a.out --out out.csv  */
#define _POSIX_C_SOURCE 199309L
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "../examples/msd_models.h"
#include "bench_args.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define RUNS 7

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static unsigned long long rng_state = 0x9E3779B97F4A7C15ULL;
static double rnd(void) { /* xorshift64*, uniform in [-1, 1) */
  rng_state ^= rng_state >> 12; rng_state ^= rng_state << 25; rng_state ^= rng_state >> 27;
  return (double)((rng_state * 2685821657736338717ULL) >> 11) / 4503599627370496.0 - 1.0;
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : (x > y ? 1 : 0);
}

static void report(FILE *csv, const char *name, double *t, int runs, double flops) {
  double med;
  qsort(t, (size_t)runs, sizeof(double), cmp_double);
  med = (runs & 1) ? t[runs / 2] : 0.5 * (t[runs / 2 - 1] + t[runs / 2]);
  printf("%-14s median %.4f s  min %.4f s  max %.4f s  (%d runs)", name, med, t[0], t[runs - 1], runs);
  if (flops > 0.0) printf("  %.2f GFLOP/s", flops / med * 1e-9);
  printf("\n");
  if (csv) fprintf(csv, "%s,%.6f,%.6f,%.6f,%d\n", name, med, t[0], t[runs - 1], runs);
}

static void *xmalloc(size_t n) {
  void *p = malloc(n);
  if (!p) { fprintf(stderr, "bench_linalg: out of memory\n"); exit(1); }
  return p;
}

int main(int argc, char **argv) {
  FILE *csv = NULL;
  double t[RUNS];
  int r, i;
  {
    const char *out;
    int rc = bench_args(argc, argv, "bench_linalg", "Dense kernel timings (LU, SVD, GEMM, POD).", &out, NULL, NULL);
    if (rc) return rc == 1 ? 0 : 2;
    csv = bench_open_csv("bench_linalg", out, &rc);
    if (rc) return 1;
  }
#ifdef PHGMG_USE_CBLAS
  printf("(PHGMG_USE_CBLAS: products through cblas)\n");
#endif

  { /* LU, n = 1000 */
    const int n = 1000;
    double *A = (double *)xmalloc(sizeof(double) * n * n), *F = (double *)xmalloc(sizeof(double) * n * n);
    int *ipiv = (int *)xmalloc(sizeof(int) * n);
    for (i = 0; i < n * n; ++i) A[i] = rnd();
    for (r = -1; r < RUNS; ++r) {
      double t0;
      memcpy(F, A, sizeof(double) * n * n);
      t0 = now();
      if (phgmg_lu_factor(n, F, n, ipiv) != PHGMG_OK) { fprintf(stderr, "LU failed\n"); return 1; }
      if (r >= 0) t[r] = now() - t0;
    }
    report(csv, "lu_1000", t, RUNS, 2.0 / 3.0 * n * (double)n * n);
    free(A); free(F); free(ipiv);
  }

  { /* thin SVD of X = L R^T, X 1000 x 1001, rank 90 */
    const int m = 1000, n = 1001, rk = 90;
    double *L = (double *)xmalloc(sizeof(double) * m * rk), *R = (double *)xmalloc(sizeof(double) * n * rk);
    double *X = (double *)xmalloc(sizeof(double) * m * n), *S = (double *)xmalloc(sizeof(double) * rk);
    double *U = (double *)xmalloc(sizeof(double) * m * rk), *V = (double *)xmalloc(sizeof(double) * n * rk);
    int k = 0, rank = 0;
    for (i = 0; i < m * rk; ++i) L[i] = rnd();
    for (i = 0; i < n * rk; ++i) R[i] = rnd();
    phgmg_gemm('N', 'T', m, n, rk, 1.0, L, m, R, n, 0.0, X, m);
    for (r = -1; r < RUNS; ++r) {
      double t0 = now();
      if (phgmg_svd(m, n, X, m, rk, S, U, m, V, n, &k, &rank, NULL) != PHGMG_OK) {
        fprintf(stderr, "SVD failed\n");
        return 1;
      }
      if (r >= 0) t[r] = now() - t0;
    }
    printf("svd: numerical rank %d, k %d, s1 %.4e, s%d %.4e\n", rank, k, S[0], k, S[k - 1]);
    /* nominal flops: pivoted QR truncated at rank k, 4 m n k */
    report(csv, "svd_1000x1001", t, RUNS, 4.0 * m * (double)n * rk);
    free(L); free(R); free(X); free(S); free(U); free(V);
  }

  { /* GEMM, n = 1000 */
    const int n = 1000;
    double *A = (double *)xmalloc(sizeof(double) * n * n), *B = (double *)xmalloc(sizeof(double) * n * n);
    double *C = (double *)xmalloc(sizeof(double) * n * n);
    for (i = 0; i < n * n; ++i) { A[i] = rnd(); B[i] = rnd(); }
    for (r = -1; r < RUNS; ++r) {
      double t0 = now();
      phgmg_gemm('N', 'N', n, n, n, 1.0, A, n, B, n, 0.0, C, n);
      if (r >= 0) t[r] = now() - t0;
    }
    report(csv, "gemm_1000", t, RUNS, 2.0 * n * (double)n * n);
    free(A); free(B); free(C);
  }
  { /* POD of 40 modes, 1001 snapshots of the nonlinear chain, N = 64000 */
    enum { NSNAP = 1001, KP = 40 };
    msd_nonlinear M;
    msd_nl_opts mo;
    phgmg_gl3_opts go;
    double *X, *x0, *V, S[KP], Se[KP], err = 0.0, te[3];
    int N, k = 0;
    memset(&mo, 0, sizeof mo);
    mo.n = 32000;
    mo.storage = PHGMG_BANDED;
    if (msd_nonlinear_build(&M, &mo) != 0) { fprintf(stderr, "chain model failed\n"); return 1; }
    N = M.sys.N;
    X = (double *)xmalloc(sizeof(double) * (size_t)N * NSNAP);
    x0 = (double *)xmalloc(sizeof(double) * (size_t)N);
    V = (double *)xmalloc(sizeof(double) * (size_t)N * KP);
    memset(x0, 0, sizeof(double) * (size_t)N);
    memset(&go, 0, sizeof go);
    go.tol = 1e-8; go.max_iter = 20;
    if (phgmg_simulate(&M.sys, x0, 0.0, 0.1, NSNAP - 1, msd_input_sin, NULL, &go, X, NULL, NULL, NULL, NULL,
                       NULL) != PHGMG_OK) { fprintf(stderr, "chain simulation failed\n"); return 1; }
    for (r = -1; r < RUNS; ++r) {
      double t0 = now();
      if (phgmg_pod_randomized(N, NSNAP, X, N, KP, 2, 1ul, V, N, S, &k, NULL) != PHGMG_OK || k != KP) {
        fprintf(stderr, "randomized POD failed\n");
        return 1;
      }
      if (r >= 0) t[r] = now() - t0;
    }
    /* nominal flops: 6 products with X (q = 2), l = 60 columns */
    report(csv, "offline_pod_rand_N64000", t, RUNS, 6.0 * 2.0 * N * (double)NSNAP * (KP + 20));
    for (r = -1; r < 3; ++r) {
      double t0 = now();
      if (phgmg_pod(N, NSNAP, X, N, KP, 0.0, V, N, Se, &k, NULL) != PHGMG_OK || k != KP) {
        fprintf(stderr, "exact POD failed\n");
        return 1;
      }
      if (r >= 0) te[r] = now() - t0;
    }
    report(csv, "offline_pod_exact_N64000", te, 3, 0.0);
    for (i = 0; i < KP; ++i) err = fmax(err, fabs(S[i] - Se[i]) / Se[i]);
    printf("pod N %d: sigma_40/sigma_1 %.2e, randomized vs exact: max rel error of sigma_1..40 %.2e\n", N,
           Se[KP - 1] / Se[0], err);
    free(X); free(x0); free(V);
    msd_nonlinear_free(&M);
  }
  if (csv) fclose(csv);
  return 0;
}
