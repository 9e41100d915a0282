/* Balancing-based reduction to pH reduced models (phgmg_ss_to_ph,
   phgmg_balanced_reduce): the pH form of a passive state-space model exact
   (K Qh = Ar, Bh^T Qh = Cr, Qh > 0, K + K^T <= 0) and refused for a model
   that is not passive; the low-rank (sparse) and dense runs of BT and PRBT
   on the same mass-spring-damper lattice agree (transfer functions, Hankel
   and positive-real singular values); lift and restrict are inverse on the
   reduced space; bad arguments. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>

/* The n x n lattice of bench/lowrank_models.py (unscrambled), dense: x =
   (q, p), K = 2-D Laplacian + 0.01 I, D = 0.5 I + 0.01 K, forces on the
   corner masses. J, R, Q N x N, B N x 2 (N = 2 n^2), calloc'ed. */
static int bal_lattice(int n, double **J, double **R, double **Q, double **B) {
  const int n2 = n * n, N = 2 * n2;
  int a, d;
  *J = (double *)calloc((size_t)N * N, sizeof(double)); *R = (double *)calloc((size_t)N * N, sizeof(double));
  *Q = (double *)calloc((size_t)N * N, sizeof(double)); *B = (double *)calloc((size_t)N * 2, sizeof(double));
  for (a = 0; a < n2; ++a) {
    const int x = a % n, y = a / n, nb[4] = {x > 0 ? a - 1 : -1, x < n - 1 ? a + 1 : -1, y > 0 ? a - n : -1,
                                             y < n - 1 ? a + n : -1};
    (*J)[a + (size_t)(n2 + a) * N] = 1.0; (*J)[(n2 + a) + (size_t)a * N] = -1.0;
    (*Q)[a + (size_t)a * N] = 4.01; (*Q)[(n2 + a) + (size_t)(n2 + a) * N] = 1.0;
    (*R)[(n2 + a) + (size_t)(n2 + a) * N] = 0.5 + 0.0401;
    for (d = 0; d < 4; ++d)
      if (nb[d] >= 0) { (*Q)[a + (size_t)nb[d] * N] = -1.0; (*R)[(n2 + a) + (size_t)(n2 + nb[d]) * N] = -0.01; }
  }
  (*B)[n2] = 1.0; (*B)[N + n2 + n2 - 1] = 1.0;
  return N;
}

/* CSC of a dense N x N matrix (the caller frees the three arrays). */
static phgmg_csc bal_csc(int N, const double *A) {
  phgmg_csc c;
  int *cp = (int *)calloc((size_t)N + 1, sizeof(int)), *ri = (int *)malloc(sizeof(int) * (size_t)N * N + 1), i, j, k = 0;
  double *v = (double *)malloc(sizeof(double) * (size_t)N * N + 1);
  for (j = 0; j < N; ++j) {
    for (i = 0; i < N; ++i)
      if (A[i + (size_t)j * N] != 0.0) { ri[k] = i; v[k++] = A[i + (size_t)j * N]; }
    cp[j + 1] = k;
  }
  c.n_rows = c.n_cols = N; c.colptr = cp; c.rowidx = ri; c.values = v;
  return c;
}
static void bal_csc_free(phgmg_csc *c) { free((void *)c->colptr); free((void *)c->rowidx); free((void *)c->values); }

/* max over a few frequencies of ||G1 - G2||_2 / ||G1||_2, G = C (iw - A)^{-1} B
   with A = K Qh, B = Bh, C = Bh^T Qh of two reduced models of order r. */
static double bal_tf_diff(const phgmg_rom *a, const phgmg_rom *b) {
  const int r = a->r, m = a->m;
  double A[2][400], C[2][40], G[2][8], B[2][40], worst = 0.0;
  const phgmg_rom *ro[2];
  int s, k, i, j, l;
  ro[0] = a; ro[1] = b;
  for (s = 0; s < 2; ++s)
    for (j = 0; j < r; ++j) {
      for (i = 0; i < r; ++i) {
        double t = 0.0;
        for (l = 0; l < r; ++l) t += (double)ro[s]->K[i + l * r] * (double)ro[s]->Qh[l + j * r];
        A[s][i + j * r] = t;
      }
      for (i = 0; i < m; ++i) {
        double t = 0.0;
        for (l = 0; l < r; ++l) t += (double)ro[s]->Bh[l + i * r] * (double)ro[s]->Qh[l + j * r];
        C[s][i + j * m] = t;
        B[s][j + i * r] = (double)ro[s]->Bh[j + i * r];
      }
    }
  for (k = 0; k < 7; ++k) {
    const double w = pow(10.0, -2.0 + 0.6 * k);
    double d = 0.0, g = 0.0;
    for (s = 0; s < 2; ++s) phgmg_ss_transfer(r, m, m, A[s], B[s], C[s], w, G[s], NULL);
    for (i = 0; i < 2 * m * m; ++i) { d += (G[0][i] - G[1][i]) * (G[0][i] - G[1][i]); g += G[0][i] * G[0][i]; }
    if (sqrt(d / g) > worst) worst = sqrt(d / g);
  }
  return worst;
}

/* The largest eigenvalue of K + K^T relative to its largest modulus. */
static double bal_diss(const phgmg_rom *ro) {
  const int r = ro->r;
  double S[400], w[20];
  int i, j;
  for (j = 0; j < r; ++j)
    for (i = 0; i < r; ++i) S[i + j * r] = (double)ro->K[i + j * r] + (double)ro->K[j + i * r];
  phgmg_sym_eig(r, S, r, w, NULL, 0);
  return w[r - 1] / PHGMG__MAX(fabs(w[0]), fabs(w[r - 1]));
}

TEST(test_balanced_ss_to_ph) {
  enum { r = 6, m = 2 };
  double K0[r * r], Q0[r * r], L[r * r], B0[r * m], Ar[r * r], Cr[m * r], K[r * r], Qh[r * r], T[r * r], ch = -1.0;
  double d = 0.0, a = 0.0, w[r];
  int i, j, l;
  for (i = 0; i < r * r; ++i) L[i] = th_rand();
  for (j = 0; j < r; ++j)   /* K0 = skew - L L^T, Q0 = L^T L + I */
    for (i = 0; i < r; ++i) {
      double s = 0.0, q = 0.0;
      for (l = 0; l < r; ++l) { s += L[i + l * r] * L[j + l * r]; q += L[l + i * r] * L[l + j * r]; }
      K0[i + j * r] = (i < j ? 1.0 : i > j ? -1.0 : 0.0) * (double)(i + j) / r - s;
      Q0[i + j * r] = q + (i == j ? 1.0 : 0.0);
    }
  for (i = 0; i < r * m; ++i) B0[i] = th_rand();
  phgmg_gemm('N', 'N', r, r, r, 1.0, K0, r, Q0, r, 0.0, Ar, r);
  phgmg_gemm('T', 'N', m, r, r, 1.0, B0, r, Q0, r, 0.0, Cr, m);
  CHECK_RC(phgmg_ss_to_ph(r, m, Ar, B0, Cr, K, Qh, &ch, NULL), PHGMG_OK);
  CHECK_LE(ch, 1e-12);
  phgmg_gemm('N', 'N', r, r, r, 1.0, K, r, Qh, r, 0.0, T, r);   /* K Qh = Ar */
  for (i = 0; i < r * r; ++i) { d += (T[i] - Ar[i]) * (T[i] - Ar[i]); a += Ar[i] * Ar[i]; }
  CHECK_LE(sqrt(d / a), 1e-10);
  phgmg_gemm('T', 'N', m, r, r, 1.0, B0, r, Qh, r, 0.0, T, m);  /* Bh^T Qh = Cr */
  for (d = a = 0.0, i = 0; i < m * r; ++i) { d += (T[i] - Cr[i]) * (T[i] - Cr[i]); a += Cr[i] * Cr[i]; }
  CHECK_LE(sqrt(d / a), 1e-10);
  memcpy(T, Qh, sizeof Qh);
  phgmg_sym_eig(r, T, r, w, NULL, 0);
  CHECK(w[0] > 0.0);
  for (j = 0; j < r; ++j)
    for (i = 0; i < r; ++i) T[i + j * r] = K[i + j * r] + K[j + i * r];
  phgmg_sym_eig(r, T, r, w, NULL, 0);
  CHECK_LE(w[r - 1], 1e-12 * fabs(w[0]));
  for (i = 0; i < m * r; ++i) Cr[i] = -Cr[i];   /* y = -B^T Q x: Cr Br < 0, not passive */
  CHECK_RC(phgmg_ss_to_ph(r, m, Ar, B0, Cr, K, Qh, NULL, NULL), PHGMG_ERR_STRUCTURE);
  CHECK_RC(phgmg_ss_to_ph(m, m, Ar, B0, Cr, K, Qh, NULL, NULL), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_ss_to_ph(r, m, NULL, B0, Cr, K, Qh, NULL, NULL), PHGMG_ERR_INVALID_ARG);
}

TEST(test_balanced_sparse_dense) {
  double *J, *R, *Q, *B, sv[2][16], xr[8], x[72], xb[8];
  const int N = bal_lattice(6, &J, &R, &Q, &B);
  phgmg_csc cJ = bal_csc(N, J), cR = bal_csc(N, R), cQ = bal_csc(N, Q);
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_system sys;
  phgmg_reduced *red[2] = {NULL, NULL}, *bad = (phgmg_reduced *)&sys;
  phgmg_balanced_info inf[2];
  int s, i, j;
  memset(&sys, 0, sizeof sys);
  sys.N = N; sys.m = 2; sys.J = J; sys.R = R; sys.Q = Q; sys.B = B;
  CHECK_RC(phgmg_ph_sparse_create(&sp, N, 2, &cJ, &cR, &cQ, B, NULL, NULL, NULL), PHGMG_OK);
  for (s = 0; s < 2; ++s)   /* BT: low-rank (sparse) and dense */
    CHECK_RC(phgmg_balanced_reduce(&red[s], &sys, s ? NULL : sp, PHGMG_METHOD_BT, 8, NULL, sv[s], 16, &inf[s], NULL),
             PHGMG_OK);
  if (red[0] && red[1]) {
    CHECK(inf[0].lowrank == 1 && inf[1].lowrank == 0 && inf[0].nsv == 16 && inf[1].nsv == 16);
    for (i = 0; i < 16; ++i) CHECK_LE(fabs(sv[0][i] - sv[1][i]), 1e-8 * sv[1][0]);
    CHECK_LE(fabs(inf[0].lr.bound - inf[1].lr.bound), 1e-6 * inf[1].lr.bound);
    CHECK_LE(inf[0].res_ctrl, 1e-10);
    CHECK_LE(bal_tf_diff(phgmg_reduced_rom(red[1]), phgmg_reduced_rom(red[0])), 1e-6);
    CHECK_LE(bal_diss(phgmg_reduced_rom(red[0])), 1e-10);
    for (j = 0; j < 8; ++j) {   /* restrict(lift(e_j)) = e_j */
      for (i = 0; i < 8; ++i) xr[i] = i == j;
      phgmg_reduced_lift(red[0], xr, x);
      phgmg_reduced_restrict(red[0], x, xb);
      for (i = 0; i < 8; ++i) CHECK_LE(fabs(xb[i] - xr[i]), 1e-8);
    }
  }
  for (s = 0; s < 2; ++s) { phgmg_reduced_destroy(red[s]); red[s] = NULL; }
  for (s = 0; s < 2; ++s)   /* PRBT: two stages (sparse) and dense */
    CHECK_RC(phgmg_balanced_reduce(&red[s], &sys, s ? NULL : sp, PHGMG_METHOD_PRBT, 8, NULL, sv[s], 16, &inf[s],
                                   NULL), PHGMG_OK);
  if (red[0] && red[1]) {
    CHECK(inf[0].stages == 2 && inf[1].stages == 1 && inf[0].inter > 8 && inf[0].nsv == 8);
    for (i = 0; i < 8; ++i) CHECK_LE(fabs(sv[0][i] - sv[1][i]), 1e-8);
    CHECK_LE(bal_tf_diff(phgmg_reduced_rom(red[1]), phgmg_reduced_rom(red[0])), 1e-6);
    CHECK_LE(bal_diss(phgmg_reduced_rom(red[0])), 1e-10);
  }
  for (s = 0; s < 2; ++s) phgmg_reduced_destroy(red[s]);
  CHECK_RC(phgmg_balanced_reduce(&bad, &sys, NULL, PHGMG_METHOD_PHBT, 8, NULL, NULL, 0, NULL, NULL),
           PHGMG_ERR_UNSUPPORTED);
  CHECK(bad == NULL);
  CHECK_RC(phgmg_balanced_reduce(&bad, NULL, sp, PHGMG_METHOD_GMG_POD, 8, NULL, NULL, 0, NULL, NULL),
           PHGMG_ERR_UNSUPPORTED);
  CHECK_RC(phgmg_balanced_reduce(&bad, NULL, sp, PHGMG_METHOD_BT, 2, NULL, NULL, 0, NULL, NULL), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_balanced_reduce(&bad, NULL, NULL, PHGMG_METHOD_BT, 8, NULL, NULL, 0, NULL, NULL),
           PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_balanced_reduce(NULL, NULL, sp, PHGMG_METHOD_BT, 8, NULL, NULL, 0, NULL, NULL),
           PHGMG_ERR_INVALID_ARG);
  phgmg_ph_sparse_destroy(sp);
  bal_csc_free(&cJ); bal_csc_free(&cR); bal_csc_free(&cQ);
  free(J); free(R); free(Q); free(B);
}

/* The error measures and phgmg_reduced_validate of balanced models (a stored
   test basis W, no GMG basis): e_proj equals the same sum formed column by
   column through phgmg_reduced_restrict / _lift, and the validation's e_red
   and e_y equal those of the reduced model simulated separately. */
static void bal_u(double t, double *u, void *p) { (void)p; u[0] = 0.1 * sin(t); u[1] = 0.05 * cos(0.7 * t); }
TEST(test_balanced_validate) {
  enum { NS = 81 };
  double *J, *R, *Q, *B, *X, *Y, *XR, *YR, xr[8], xp[72], num = 0.0, den = 0.0;
  const int N = bal_lattice(6, &J, &R, &Q, &B);
  phgmg_ph_system sys;
  phgmg_reduced *red = NULL;
  phgmg_validation v;
  phgmg_run run;
  int meth, i, j;
  memset(&sys, 0, sizeof sys);
  sys.N = N; sys.m = 2; sys.J = J; sys.R = R; sys.Q = Q; sys.B = B;
  X = (double *)calloc((size_t)N * NS, sizeof(double)); Y = (double *)calloc(2 * NS, sizeof(double));
  XR = (double *)calloc(8 * NS, sizeof(double)); YR = (double *)calloc(2 * NS, sizeof(double));
  memset(&run, 0, sizeof run); run.u = bal_u; run.dt = 0.1; run.nsteps = NS - 1;
  memset(xp, 0, sizeof xp);
  CHECK_RC(phgmg_simulate(&sys, xp, 0.0, 0.1, NS - 1, bal_u, NULL, NULL, X, Y, NULL, NULL, NULL, NULL), PHGMG_OK);
  for (meth = 0; meth < 2; ++meth) {
    if (meth == 0) CHECK_RC(phgmg_prbt(&red, &sys, 8, NULL, NULL, NULL, NULL), PHGMG_OK);
    else CHECK_RC(phgmg_balanced_reduce(&red, &sys, NULL, PHGMG_METHOD_BT, 8, NULL, NULL, 0, NULL, NULL),
                  PHGMG_OK);
    if (!red) continue;
    for (j = 0, num = den = 0.0; j < NS; ++j) {   /* e_proj column by column */
      phgmg_reduced_restrict(red, X + (size_t)j * N, xr);
      phgmg_reduced_lift(red, xr, xp);
      for (i = 0; i < N; ++i) {
        const double d = X[i + (size_t)j * N] - xp[i];
        num += d * d; den += X[i + (size_t)j * N] * X[i + (size_t)j * N];
      }
    }
    CHECK_LE(fabs(phgmg_err_proj(red, X, N, NS) - sqrt(num / den)), 1e-12 * sqrt(num / den) + 1e-300);
    memset(xr, 0, sizeof xr);
    CHECK_RC(phgmg_reduced_simulate(red, xr, 0.0, 0.1, NS - 1, bal_u, NULL, 1e-10, 20, XR, YR, NULL, NULL, NULL),
             PHGMG_OK);
    CHECK_RC(phgmg_reduced_validate(red, &sys, &run, 1e-10, 20, 0.0, &v, NULL), PHGMG_OK);
    CHECK(v.rom_rc == PHGMG_OK && v.steps_done == NS - 1);
    CHECK_LE(fabs(v.e_red - phgmg_err_red(red, X, N, NS, XR, 8)), 1e-12 * v.e_red + 1e-300);
    CHECK_LE(fabs(v.e_y - phgmg_rel_error(2, NS, Y, 2, YR, 2)), 1e-12 * v.e_y + 1e-300);
    CHECK(v.e_y < 0.5);
    phgmg_reduced_destroy(red); red = NULL;
  }
  free(X); free(Y); free(XR); free(YR); free(J); free(R); free(Q); free(B);
}

SUITE(balanced) {
  RUN(test_balanced_ss_to_ph);
  RUN(test_balanced_sparse_dense);
  RUN(test_balanced_validate);
}
