/* Test helpers of the low-rank solvers' tests (test_lowrank.c, test_eksm.c):
   the CSC of a dense fixture matrix, and the dense references a low-rank
   factor is checked against (its Gramian in the user's order, the relative
   difference, the Lyapunov residual, Hankel singular values). Include after
   phgmg.h and harness.h. */
#ifndef PHGMG_TEST_LOWRANK_FIXTURE_H
#define PHGMG_TEST_LOWRANK_FIXTURE_H
#include <stdlib.h>
#include <string.h>
#include <math.h>

static phgmg_csc th_dense_csc(int N, const double *A) {
  phgmg_csc c;
  int j, i, nz = 0;
  int *cp = (int *)malloc(sizeof(int) * (size_t)(N + 1)), *ri;
  double *v;
  for (j = 0; j < N * N; ++j) nz += A[j] != 0.0;
  ri = (int *)malloc(sizeof(int) * (size_t)(nz + 1));
  v = (double *)malloc(sizeof(double) * (size_t)(nz + 1));
  nz = 0;
  for (j = 0; j < N; ++j) {
    cp[j] = nz;
    for (i = 0; i < N; ++i)
      if (A[i + (size_t)j * N] != 0.0) { ri[nz] = i; v[nz++] = A[i + (size_t)j * N]; }
  }
  cp[N] = nz;
  c.n_rows = c.n_cols = N; c.colptr = cp; c.rowidx = ri; c.values = v;
  return c;
}

static void th_csc_free(phgmg_csc *c) { free((void *)c->colptr); free((void *)c->rowidx); free((void *)c->values); }

/* Z (internal order, N x k) -> Z Z^T in the user's order. */
static double *th_gram_user(phgmg_ph_sparse *sp, int N, const double *Z, int k) {
  double *Zu = (double *)malloc(sizeof(double) * (size_t)N * k), *P = (double *)malloc(sizeof(double) * (size_t)N * N);
  CHECK_RC(phgmg_ph_sparse_to_user_order(sp, k, Z, N, Zu, N), PHGMG_OK);
  phgmg_gemm('N', 'T', N, N, k, 1.0, Zu, N, Zu, N, 0.0, P, N);
  free(Zu);
  return P;
}

static double th_reldiff(int n, const double *X, const double *Y) {
  double d = 0.0, y = 0.0;
  int i;
  for (i = 0; i < n; ++i) { d += (X[i] - Y[i]) * (X[i] - Y[i]); y += Y[i] * Y[i]; }
  return sqrt(d / y);
}

/* ||A P E^T + E P A^T + B B^T||_2 / ||B^T B||_2 (dense, E NULL = I). */
static double th_lyap_res(int N, int m, const double *A, const double *E, const double *B, const double *P) {
  double *T = (double *)malloc(sizeof(double) * (size_t)N * N), *Rr = (double *)malloc(sizeof(double) * (size_t)N * N);
  double *w = (double *)malloc(sizeof(double) * (size_t)N), G[4], g[2], r;
  int i, j;
  phgmg_gemm('N', 'N', N, N, N, 1.0, A, N, P, N, 0.0, T, N);                    /* A P */
  if (E) phgmg_gemm('N', 'T', N, N, N, 1.0, T, N, E, N, 0.0, Rr, N);             /* A P E^T */
  else memcpy(Rr, T, sizeof(double) * (size_t)N * N);
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) T[i + (size_t)j * N] = Rr[i + (size_t)j * N] + Rr[j + (size_t)i * N];
  phgmg_gemm('N', 'T', N, N, m, 1.0, B, N, B, N, 1.0, T, N);
  CHECK_RC(phgmg_sym_eig(N, T, N, w, NULL, N), PHGMG_OK);
  r = PHGMG__MAX(fabs(w[0]), fabs(w[N - 1]));
  phgmg_gemm('T', 'N', m, m, N, 1.0, B, N, B, N, 0.0, G, m);
  CHECK_RC(phgmg_sym_eig(m, G, m, g, NULL, m), PHGMG_OK);
  free(T); free(Rr); free(w);
  return r / g[m - 1];
}

/* Dense Hankel singular values (descending, n of them) from the Gramians:
   P = L L^T (eigen-decomposition), sigma^2 = eig(L^T O L). */
static void th_dense_hsv(int N, const double *P, const double *O, double *hsv, int n) {
  double *V = (double *)malloc(sizeof(double) * (size_t)N * N), *W = (double *)malloc(sizeof(double) * (size_t)N * N);
  double *T = (double *)malloc(sizeof(double) * (size_t)N * N), *w = (double *)malloc(sizeof(double) * (size_t)N);
  int i, j;
  memcpy(T, P, sizeof(double) * (size_t)N * N);
  CHECK_RC(phgmg_sym_eig(N, T, N, w, V, N), PHGMG_OK);
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) V[i + (size_t)j * N] *= sqrt(w[j] > 0.0 ? w[j] : 0.0);
  phgmg_gemm('N', 'N', N, N, N, 1.0, O, N, V, N, 0.0, W, N);
  phgmg_gemm('T', 'N', N, N, N, 1.0, V, N, W, N, 0.0, T, N);
  CHECK_RC(phgmg_sym_eig(N, T, N, w, NULL, N), PHGMG_OK);
  for (i = 0; i < n; ++i) hsv[i] = sqrt(w[N - 1 - i] > 0.0 ? w[N - 1 - i] : 0.0);
  free(V); free(W); free(T); free(w);
}

#endif
