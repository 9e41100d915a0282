/* bench_lyap.c -- phgmg_lyap against SciPy's solve_continuous_lyapunov on the
   same matrices (bench/lyap_scipy.py times the SciPy side), and the dense
   kernels behind it against OpenBLAS (bench/README.md, "Dense Lyapunov").

     bench_lyap --n N [--dir D] [--runs R]
       A = (J - R) Q of the mass-spring-damper chain of bench/bench_linear.c
       with N/2 masses (m_i = k_i = 4, c_i = 1), F = B B^T (forces on masses 1
       and 2); writes D/A.npy, D/F.npy (D given), times phgmg_lyap R times
       (default 3) and prints steps, the median CPU time and
       phgmg_lyap_residual.
     bench_lyap --kernels N [--runs R]
       phgmg_gemm ('N','N' and 'N','T'), phgmg_lu_factor and the inverse the
       library's general inverse uses (factor + solve with I), the sign
       iteration's inverse (phgmg__inv_ws) and its update of E
       (phgmg__sign_sym_update) on random N x N matrices: median CPU time and
       GFLOP/s counted as 2N^3, 2N^3, 2N^3/3, 2N^3, 2N^3, 3N^3.

   CPU time (clock()), so a noisy shared machine inflates nothing but the
   wall clock. Build: make build/bench_lyap (no OpenMP: one thread). */
#include <stdio.h>
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "../examples/msd_models.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* CPU seconds. */
static double cpu(void) { return (double)clock() / (double)CLOCKS_PER_SEC; }

/* Median of t[0..k) (sorts t). */
static double median(double *t, int k) {
  int i, j;
  for (i = 1; i < k; ++i)
    for (j = i; j > 0 && t[j - 1] > t[j]; --j) { double s = t[j]; t[j] = t[j - 1]; t[j - 1] = s; }
  return (k & 1) ? t[k / 2] : 0.5 * (t[k / 2 - 1] + t[k / 2]);
}

/* The chain's A (N x N) and F = B B^T; 0 on success. */
static int chain(int N, double *A, double *F) {
  const int n = N / 2;
  double *mv = (double *)malloc(sizeof(double) * (size_t)n), *B2 = (double *)calloc((size_t)2 * N, sizeof(double));
  msd_linear M;
  int i, rc = 1;
  for (i = 0; i < n; ++i) mv[i] = 4.0;
  if (msd_linear_build(&M, n, mv, mv, NULL, PHGMG_DENSE) == 0) {
    B2[1] = 1.0; B2[N + 3] = 1.0;
    free(M.B); M.B = B2; M.sys.B = B2; M.sys.m = 2;
    if (phgmg_ph_abc(&M.sys, A, NULL, NULL) == PHGMG_OK) rc = 0;
    phgmg_gemm('N', 'T', N, N, 2, 1.0, B2, N, B2, N, 0.0, F, N);
    msd_linear_free(&M);
  } else {
    free(B2);
  }
  free(mv);
  return rc;
}

/* phgmg_lyap on the chain of order N, runs times. */
static int bench_solve(int N, const char *dir, int runs) {
  double *A = (double *)malloc(sizeof(double) * (size_t)N * N * 3), *F = A + (size_t)N * N, *X = F + (size_t)N * N;
  double t[32];
  int r, it = 0;
  char path[512];
  if (chain(N, A, F)) { fprintf(stderr, "bench_lyap: model\n"); return 1; }
  if (dir) {
    snprintf(path, sizeof path, "%s/A.npy", dir);
    if (phgmg_npy_write(path, A, N, N, N, 2, 0) != PHGMG_OK) { fprintf(stderr, "cannot write %s\n", path); return 1; }
    snprintf(path, sizeof path, "%s/F.npy", dir);
    if (phgmg_npy_write(path, F, N, N, N, 2, 0) != PHGMG_OK) { fprintf(stderr, "cannot write %s\n", path); return 1; }
  }
  for (r = 0; r < runs; ++r) {
    double t0 = cpu();
    phgmg_result rc = phgmg_lyap(N, A, F, X, &it, NULL);
    t[r] = cpu() - t0;
    if (rc != PHGMG_OK) { fprintf(stderr, "phgmg_lyap: %s\n", phgmg_result_string(rc)); return 1; }
  }
  printf("phgmg_lyap n=%d steps=%d cpu_median=%.3f s (%d runs) residual=%.2e\n", N, it, median(t, runs), runs,
         phgmg_lyap_residual(N, A, F, X, NULL));
  free(A);
  return 0;
}

/* The dense kernels at order N. */
static int bench_kernels(int N, int runs) {
  const size_t nn = (size_t)N * N;
  double *A = (double *)malloc(sizeof(double) * nn * 5), *B = A + nn, *C = B + nn, *W = C + nn, t[32];
  const double n3 = (double)N * N * N;
  int *ip = (int *)malloc(sizeof(int) * (size_t)N), r, kind;
  size_t i;
  unsigned s = 12345u;
  for (i = 0; i < 2 * nn; ++i) {
    s = s * 1103515245u + 12345u;
    A[i] = (double)((s >> 8) & 0xffff) / 65536.0 - 0.5;
  }
  for (i = 0; i < (size_t)N; ++i) A[i + i * (size_t)N] += 4.0; /* well conditioned */
  for (kind = 0; kind < 6; ++kind) {
    static const char *name[6] = {"gemm_NN", "gemm_NT", "lu_factor", "inverse", "inv_sign", "sym_update"};
    static const double fl[6] = {2.0, 2.0, 2.0 / 3.0, 2.0, 2.0, 3.0};
    for (r = 0; r < runs; ++r) {
      double t0 = cpu();
      if (kind == 0) phgmg_gemm('N', 'N', N, N, N, 1.0, A, N, B, N, 0.0, C, N);
      if (kind == 1) phgmg_gemm('N', 'T', N, N, N, 1.0, A, N, B, N, 0.0, C, N);
      if (kind == 2) { memcpy(W, A, nn * sizeof(double)); phgmg_lu_factor(N, W, N, ip); }
      if (kind == 3) {
        memcpy(W, A, nn * sizeof(double));
        phgmg_lu_factor(N, W, N, ip);
        memset(C, 0, nn * sizeof(double));
        for (i = 0; i < (size_t)N; ++i) C[i + i * (size_t)N] = 1.0;
        phgmg_lu_solve('N', N, W, N, ip, N, C, N);
      }
      if (kind == 4) phgmg__inv_ws(N, A, C, W, ip);
      if (kind == 5) {
        for (i = 0; i < nn; ++i) C[i] = B[i % N + (i / N) * N] + B[i / N + (i % N) * N];
        phgmg__sign_sym_update(N, A, C, 1.0, W, W + nn, B);
      }
      t[r] = cpu() - t0;
    }
    {
      const double m = median(t, runs);
      printf("%-10s n=%d cpu_median=%.4f s  %.2f GFLOP/s (%.3g n^3 flops)\n", name[kind], N, m,
             fl[kind] * n3 / m * 1e-9, fl[kind]);
    }
  }
  free(A);
  free(ip);
  return 0;
}

int main(int argc, char **argv) {
  int N = 1000, runs = 3, kernels = 0, i;
  const char *dir = NULL;
  for (i = 1; i < argc; ++i) {
    if (!strcmp(argv[i], "--n") && i + 1 < argc) N = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--kernels") && i + 1 < argc) { N = atoi(argv[++i]); kernels = 1; }
    else if (!strcmp(argv[i], "--dir") && i + 1 < argc) dir = argv[++i];
    else if (!strcmp(argv[i], "--runs") && i + 1 < argc) runs = atoi(argv[++i]);
    else { fprintf(stderr, "usage: bench_lyap (--n N [--dir D] | --kernels N) [--runs R]\n"); return 2; }
  }
  if (N < 2 || (N & 1) || runs < 1 || runs > 32) { fprintf(stderr, "bench_lyap: N even >= 2, 1 <= R <= 32\n"); return 2; }
  return kernels ? bench_kernels(N, runs) : bench_solve(N, dir, runs);
}
