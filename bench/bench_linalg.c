/* Dense kernel timings: LU (n = 1000), thin SVD of a 1000 x 1001 matrix of
   rank 90 built from random factors, GEMM (n = 1000). Each case runs once to
   warm up, then RUNS times; prints median/min/max seconds and GFLOP/s, and
   appends `case,median_s,min_s,max_s,runs` lines to the CSV file argv[1] (if
   given; a header line is written when the file is empty).
     cc -std=c99 -O2 -march=native bench/bench_linalg.c -lm && ./a.out out.csv  */
#define _POSIX_C_SOURCE 199309L
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
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
  if (argc > 1) {
    csv = fopen(argv[1], "a");
    if (!csv) { fprintf(stderr, "bench_linalg: cannot open %s\n", argv[1]); return 1; }
    fseek(csv, 0, SEEK_END);
    if (ftell(csv) == 0) fprintf(csv, "case,median_s,min_s,max_s,runs\n");
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
  if (csv) fclose(csv);
  return 0;
}
