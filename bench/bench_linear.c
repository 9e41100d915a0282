/* Linear pH systems (>>linear) at N = 1000: the two-port mass-spring-damper
   chain of Gugercin et al. 2012 with 500 masses (m_i = k_i = 4, c_i = 1,
   forces on masses 1 and 2). Cases:
     lyap_N1000       controllability Gramian A P + P A^T + B B^T = 0 (sign function)
     prbt_N1000_r20   positive-real balanced truncation to r = 20 (two zero-feedthrough
                      Riccati equations, deflated to order N - m = 998: one shifted sign
                      iteration of a 1996 x 1996 Hamiltonian and its kernel each;
                      balancing, pH form, step map)
     h2basis_N1000_r20_20it  phgmg_linear_basis kind H2 for r = 20 (k = 18): the complex
                      Schur form of A once, then 20 L-BFGS steps of O(N^2 r) each
                      (measured: Schur 9.7 s, 60 ms a step, shared machine)
   Prints the relative residuals (Lyapunov; both Riccati equations) and
   appends `case,median_s,min_s,max_s,runs` to the CSV given with --out.
   BENCH_LINEAR_RUNS (default 1) runs per case; no warm-up (each run is seconds).
     cc -std=c99 -O2 -march=native bench/bench_linear.c -lm && ./a.out --out out.csv  */
#define _POSIX_C_SOURCE 199309L
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "../examples/msd_models.h"
#include "bench_args.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : (x > y ? 1 : 0);
}
static void report(FILE *csv, const char *name, double *t, int runs) {
  double med;
  qsort(t, (size_t)runs, sizeof(double), cmp_double);
  med = (runs & 1) ? t[runs / 2] : 0.5 * (t[runs / 2 - 1] + t[runs / 2]);
  printf("%-16s median %.3f s  min %.3f s  max %.3f s  (%d runs)\n", name, med, t[0], t[runs - 1], runs);
  if (csv) fprintf(csv, "%s,%.6f,%.6f,%.6f,%d\n", name, med, t[0], t[runs - 1], runs);
}

int main(int argc, char **argv) {
  const int n = 500, N = 2 * n;
  double *mv = (double *)malloc(sizeof(double) * n), *A, *C, *F, *X, *Y, *K, *L, t[16];
  const char *env = getenv("BENCH_LINEAR_RUNS");
  int runs = env ? atoi(env) : 1, i, it = 0;
  msd_linear M;
  FILE *csv = NULL;
  phgmg_result rc;
  if (runs < 1 || runs > 16) runs = 1;
  {
    const char *out;
    int arc = bench_args(argc, argv, "bench_linear", "Lyapunov, PRBT and least-H2 basis at N = 1000.", &out, NULL, NULL);
    if (arc) { free(mv); return arc == 1 ? 0 : 2; }
    csv = bench_open_csv("bench_linear", out, &arc);
    if (arc) { free(mv); return 1; }
  }
  for (i = 0; i < n; ++i) mv[i] = 4.0;
  if (msd_linear_build(&M, n, mv, mv, NULL, PHGMG_DENSE) != 0) return 1;
  {
    double *B2 = (double *)calloc((size_t)2 * N, sizeof(double));
    B2[1] = 1.0; B2[N + 3] = 1.0;
    free(M.B); M.B = B2; M.sys.B = B2; M.sys.m = 2;
  }
  A = (double *)malloc(sizeof(double) * N * N * 6 + sizeof(double) * 2 * N);
  C = A + (size_t)N * N; F = C + 2 * (size_t)N; X = F + (size_t)N * N; Y = X + (size_t)N * N;
  K = Y + (size_t)N * N; L = K + (size_t)N * N;
  if (phgmg_ph_abc(&M.sys, A, C, NULL) != PHGMG_OK) return 1;
  phgmg_gemm('N', 'T', N, N, 2, 1.0, M.sys.B, N, M.sys.B, N, 0.0, F, N);
  for (i = 0; i < runs; ++i) {
    double t0 = now();
    rc = phgmg_lyap(N, A, F, X, &it, NULL);
    t[i] = now() - t0;
    if (rc != PHGMG_OK) { fprintf(stderr, "lyap: %s\n", phgmg_result_string(rc)); return 1; }
  }
  printf("lyap_N1000: %d sign steps, relative residual %.2e\n", it, phgmg_lyap_residual(N, A, F, X, NULL));
  report(csv, "lyap_N1000", t, runs);
  for (i = 0; i < runs; ++i) {
    phgmg_reduced *red = NULL;
    phgmg_prbt_opts o;
    double t0 = now(), xb = 0.0;
    memset(&o, 0, sizeof o);
    o.dt = 0.1;
    rc = phgmg_prbt(&red, &M.sys, 20, &o, NULL, &xb, NULL);
    t[i] = now() - t0;
    if (rc != PHGMG_OK) { fprintf(stderr, "prbt: %s\n", phgmg_result_string(rc)); return 1; }
    if (i == 0) printf("prbt_N1000_r20: ||X B - C^T|| / ||C|| = %.2e\n", xb);
    phgmg_reduced_destroy(red);
  }
  report(csv, "prbt_N1000_r20", t, runs);
  /* residuals of the two zero-feedthrough Riccati equations (outside the
     timing): the constraint X B = C^T and the equation itself, which says
     that M = A^T X + X A (Schur complement zero) has rank m:
     ||M - (its rank-m part)||_F over ||M||_F (strict: M is a difference of
     two products of norm ||A|| ||X|| >> ||M|| for Y) and over 2 ||A||_F
     ||X||_F (the scale of phgmg_care_residual); the same for Y (A Y + Y A^T). */
  rc = phgmg_prbt_riccati(&M.sys, 0.0, X, Y, NULL);
  if (rc == PHGMG_OK) {
    double rx[2], rn[2], xbc[2];
    int e;
    for (e = 0; e < 2; ++e) {
      const double *Z = e ? Y : X, *P = e ? C : M.sys.B;   /* X B = C^T, Y C^T = B */
      double num = 0.0, den = 0.0, *w = K;
      int a, k;
      for (a = 0; a < 2; ++a)
        for (i = 0; i < N; ++i) {
          double v = e ? -M.sys.B[i + (size_t)a * N] : -C[a + (size_t)i * 2];
          for (k = 0; k < N; ++k) v += Z[i + (size_t)k * N] * (e ? P[a + (size_t)k * 2] : P[k + (size_t)a * N]);
          num += v * v;
          den += e ? M.sys.B[i + (size_t)a * N] * M.sys.B[i + (size_t)a * N] : C[a + (size_t)i * 2] * C[a + (size_t)i * 2];
        }
      xbc[e] = sqrt(num / den);
      if (e) {
        phgmg_gemm('N', 'N', N, N, N, 1.0, A, N, Z, N, 0.0, L, N);
        phgmg_gemm('N', 'T', N, N, N, 1.0, Z, N, A, N, 0.0, F, N);
      } else {
        phgmg_gemm('T', 'N', N, N, N, 1.0, A, N, Z, N, 0.0, L, N);
        phgmg_gemm('N', 'N', N, N, N, 1.0, Z, N, A, N, 0.0, F, N);
      }
      for (i = 0; i < N * N; ++i) L[i] += F[i];
      if (phgmg_sym_eig(N, L, N, w, NULL, 0) != PHGMG_OK) return 1;
      num = den = 0.0;   /* ascending: the m = 2 of largest modulus are the two most negative */
      for (i = 0; i < N; ++i) { den += w[i] * w[i]; if (i >= 2) num += w[i] * w[i]; }
      rx[e] = sqrt(num / den);
      rn[e] = sqrt(num) / (2.0 * phgmg_normf(N, N, A, N) * phgmg_normf(N, N, Z, N));
    }
    printf("prbt_N1000_r20: ||X B - C^T||/||C|| %.1e, ||Y C^T - B||/||B|| %.1e; Riccati residuals: "
           "rank-m defect of A^T X + X A, A Y + Y A^T over their norms %.2e, %.2e; over 2 ||A||_F ||X||_F "
           "(phgmg_care_residual's scale) %.2e, %.2e\n", xbc[0], xbc[1], rx[0], rx[1], rn[0], rn[1]);
  }
  {   /* GMG-H2 basis, r = 20: the Schur form of A once, then 20 L-BFGS steps of O(N^2 r) */
    double *V = (double *)malloc(sizeof(double) * N * 18), h2 = NAN;
    phgmg_basis_opts bo;
    memset(&bo, 0, sizeof bo);
    bo.maxit = 20; bo.h2_rel = &h2;
    for (i = 0; i < runs; ++i) {
      double t0 = now();
      rc = phgmg_linear_basis(&M.sys, PHGMG_BASIS_H2, 18, &bo, V, NULL, NULL);
      t[i] = now() - t0;
      if (rc != PHGMG_OK) { fprintf(stderr, "h2 basis: %s\n", phgmg_result_string(rc)); return 1; }
    }
    printf("h2basis_N1000_r20_20it: ||G - G_r||_H2 / ||G||_H2 = %.2e after 20 L-BFGS steps\n", h2);
    report(csv, "h2basis_N1000_r20_20it", t, runs);
    free(V);
  }
  if (csv) fclose(csv);
  free(A); free(mv);
  msd_linear_free(&M);
  return 0;
}
