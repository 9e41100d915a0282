/* Randomized POD ("a million states"): phgmg_pod_randomized against
   snapshots of the paper's nonlinear chain (exact phgmg_pod as reference),
   closed-form spectra (X = U diag(sigma) W^T with U, W orthonormal) and against
   the exact phgmg_pod; subspace angles; determinism (same seed = same bits);
   power-of-two magnitude independence; rank-deficient input; errors and
   out-of-memory; the automatic switch inside phgmg_pod (compiled on here with
   a small PHGMG_POD_RANDOMIZED_MIN) and that tol > 0 keeps the exact path. */
#include <stdlib.h>
#define PHGMG_POD_RANDOMIZED_MIN 100000
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "../examples/msd_models.h"
#include "harness.h"

/* m x n (m >= n) matrix with orthonormal columns: Q of a random matrix. */
static double *rs_orth(int m, int n) {
  double *A = (double *)malloc(sizeof(double) * (size_t)m * (size_t)n);
  double *tau = (double *)malloc(sizeof(double) * (size_t)n);
  size_t t;
  for (t = 0; t < (size_t)m * (size_t)n; ++t) A[t] = th_rand();
  phgmg_qr(m, n, A, m, tau);
  phgmg_qr_form_q(m, n, A, m, tau, NULL);
  free(tau);
  return A;
}

/* X (N x ns) = U diag(sig) W^T with rank n0; U (N x n0) returned in *Uout. */
static double *rs_build(int N, int ns, int n0, const double *sig, double **Uout) {
  double *U = rs_orth(N, n0), *W = rs_orth(ns, n0);
  double *X = (double *)malloc(sizeof(double) * (size_t)N * (size_t)ns);
  int i, j;
  for (j = 0; j < n0; ++j)
    for (i = 0; i < ns; ++i) W[i + (size_t)j * ns] *= sig[j];
  phgmg_gemm('N', 'T', N, ns, n0, 1.0, U, N, W, ns, 0.0, X, N);
  free(W);
  *Uout = U;
  return X;
}

/* || V - Uk (Uk^T V) ||_F over k columns: sine of the subspace angles (Frobenius). */
static double rs_angle(int N, int k, const double *Uk, int ldu, const double *V, int ldv) {
  double *M = (double *)malloc(sizeof(double) * (size_t)k * (size_t)k);
  double *D = (double *)malloc(sizeof(double) * (size_t)N * (size_t)k);
  double r;
  int i, j;
  for (j = 0; j < k; ++j)
    for (i = 0; i < N; ++i) D[i + (size_t)j * N] = V[i + (size_t)j * ldv];
  phgmg_gemm('T', 'N', k, k, N, 1.0, Uk, ldu, V, ldv, 0.0, M, k);
  phgmg_gemm('N', 'N', N, k, k, -1.0, Uk, ldu, M, k, 1.0, D, N);
  r = phgmg_normf(N, k, D, N);
  free(M);
  free(D);
  return r;
}

TEST(test_rsvd_known_spectrum) {
  const int N = 1200, ns = 300, n0 = 300, kmax = 20;
  double sig[300], S[20], Se[20], *U, *X, *V, *Ve, err = 0.0;
  int j, k = -1, ke = -1;
  for (j = 0; j < n0; ++j) sig[j] = exp(-0.5 * j);
  X = rs_build(N, ns, n0, sig, &U);
  V = (double *)malloc(sizeof(double) * (size_t)N * kmax);
  Ve = (double *)malloc(sizeof(double) * (size_t)N * kmax);
  CHECK_RC(phgmg_pod_randomized(N, ns, X, N, kmax, 2, 7ul, V, N, S, &k, NULL), PHGMG_OK);
  CHECK(k == kmax);
  for (j = 0; j < kmax; ++j) err = fmax(err, fabs(S[j] - sig[j]) / sig[j]);
  CHECK_LE(err, 1e-10);
  /* Rayleigh-Ritz values: never above the exact ones (up to round-off) */
  for (j = 0; j < kmax; ++j) CHECK_LE(S[j], sig[j] * (1.0 + 1e-12));
  CHECK_LE(rs_angle(N, kmax, U, N, V, N), 1e-9);
  /* against the exact POD (tol 0, so the auto switch would pick the randomized
     path here: call the exact one through phgmg_svd) */
  CHECK_RC(phgmg_svd(N, ns, X, N, kmax, Se, Ve, N, NULL, 1, &ke, NULL, NULL), PHGMG_OK);
  CHECK(ke == kmax);
  err = 0.0;
  for (j = 0; j < kmax; ++j) err = fmax(err, fabs(S[j] - Se[j]) / Se[j]);
  CHECK_LE(err, 1e-10);
  CHECK_LE(rs_angle(N, kmax, Ve, N, V, N), 1e-9);
  /* without power iterations the trailing values are visibly worse: the
     iterations are what buys the accuracy (a test that can fail) */
  CHECK_RC(phgmg_pod_randomized(N, ns, X, N, kmax, 0, 7ul, V, N, S, &k, NULL), PHGMG_OK);
  /* (sigma_41/sigma_20)^2 = exp(-21) = 8e-10 times a modest factor */
  CHECK(fabs(S[kmax - 1] - sig[kmax - 1]) / sig[kmax - 1] > 1e-11);
  free(U); free(X); free(V); free(Ve);
}

/* Slow decay (sigma_j = 1/(1+j)): the leading values still converge with q. */
TEST(test_rsvd_slow_decay_power_iters) {
  const int N = 800, ns = 200, n0 = 200, kmax = 10;
  double sig[200], S[10], *U, *X, *V, e1 = 0.0, e4 = 0.0;
  int j, k;
  for (j = 0; j < n0; ++j) sig[j] = 1.0 / (1.0 + j);
  X = rs_build(N, ns, n0, sig, &U);
  V = (double *)malloc(sizeof(double) * (size_t)N * kmax);
  CHECK_RC(phgmg_pod_randomized(N, ns, X, N, kmax, 1, 3ul, V, N, S, &k, NULL), PHGMG_OK);
  for (j = 0; j < 3; ++j) e1 = fmax(e1, fabs(S[j] - sig[j]) / sig[j]);
  CHECK_RC(phgmg_pod_randomized(N, ns, X, N, kmax, 6, 3ul, V, N, S, &k, NULL), PHGMG_OK);
  for (j = 0; j < 3; ++j) e4 = fmax(e4, fabs(S[j] - sig[j]) / sig[j]);
  CHECK(k == kmax);
  CHECK_LE(e4, 1e-6);
  CHECK_LE(e4, e1);
  free(U); free(X); free(V);
}

TEST(test_rsvd_deterministic_and_magnitude) {
  const int N = 500, ns = 120, n0 = 120, kmax = 8;
  double sig[120], S1[8], S2[8], S3[8], *U, *X, *V1, *V2, *V3, d = 0.0;
  int j, k1, k2, k3;
  size_t t, cnt = (size_t)N * kmax;
  for (j = 0; j < n0; ++j) sig[j] = 0.7 * pow(0.6, j);
  X = rs_build(N, ns, n0, sig, &U);
  V1 = (double *)malloc(sizeof(double) * cnt);
  V2 = (double *)malloc(sizeof(double) * cnt);
  V3 = (double *)malloc(sizeof(double) * cnt);
  CHECK_RC(phgmg_pod_randomized(N, ns, X, N, kmax, 2, 11ul, V1, N, S1, &k1, NULL), PHGMG_OK);
  CHECK_RC(phgmg_pod_randomized(N, ns, X, N, kmax, 2, 11ul, V2, N, S2, &k2, NULL), PHGMG_OK);
  CHECK(k1 == kmax && k2 == kmax);
  CHECK(memcmp(V1, V2, sizeof(double) * cnt) == 0 && memcmp(S1, S2, sizeof S1) == 0);
  /* another seed: other bits, same values and subspace */
  CHECK_RC(phgmg_pod_randomized(N, ns, X, N, kmax, 2, 12ul, V2, N, S2, &k2, NULL), PHGMG_OK);
  CHECK(memcmp(V1, V2, sizeof(double) * cnt) != 0);
  for (j = 0; j < kmax; ++j) d = fmax(d, fabs(S1[j] - S2[j]) / S1[j]);
  CHECK_LE(d, 1e-12);
  CHECK_LE(rs_angle(N, kmax, V1, N, V2, N), 1e-10);
  /* X * 2^600 and X * 2^-600: values scale exactly, vectors are the same bits
     (max |X| is in [1/2, 1) here, so the in-range run does not scale) */
  {
    double amax = 0.0;
    for (t = 0; t < (size_t)N * ns; ++t) amax = fmax(amax, fabs(X[t]));
    for (t = 0; t < (size_t)N * ns; ++t) X[t] *= 0.75 / amax;
    CHECK_RC(phgmg_pod_randomized(N, ns, X, N, kmax, 2, 5ul, V1, N, S1, &k1, NULL), PHGMG_OK);
    for (t = 0; t < (size_t)N * ns; ++t) X[t] = ldexp(X[t], 600);
    CHECK_RC(phgmg_pod_randomized(N, ns, X, N, kmax, 2, 5ul, V2, N, S2, &k2, NULL), PHGMG_OK);
    for (t = 0; t < (size_t)N * ns; ++t) X[t] = ldexp(X[t], -1200);
    CHECK_RC(phgmg_pod_randomized(N, ns, X, N, kmax, 2, 5ul, V3, N, S3, &k3, NULL), PHGMG_OK);
    CHECK(k1 == kmax && k2 == kmax && k3 == kmax);
    CHECK(memcmp(V1, V2, sizeof(double) * cnt) == 0 && memcmp(V1, V3, sizeof(double) * cnt) == 0);
    for (j = 0; j < kmax; ++j) CHECK(S2[j] == ldexp(S1[j], 600) && S3[j] == ldexp(S1[j], -600));
  }
  free(U); free(X); free(V1); free(V2); free(V3);
}

/* Rank 6 < kmax: k_out = 6 like the exact POD, and the basis spans range(X). */
TEST(test_rsvd_rank_deficient) {
  const int N = 300, ns = 80, n0 = 6, kmax = 12;
  double sig[6] = {3.0, 2.0, 1.0, 0.5, 0.25, 0.125}, S[12], *U, *X, *V;
  int j, k = -1, ke = -1;
  X = rs_build(N, ns, n0, sig, &U);
  V = (double *)malloc(sizeof(double) * (size_t)N * kmax);
  CHECK_RC(phgmg_pod_randomized(N, ns, X, N, kmax, 1, 1ul, V, N, S, &k, NULL), PHGMG_OK);
  CHECK_RC(phgmg_pod(N, ns, X, N, kmax, 1e-300, V, N, NULL, &ke, NULL), PHGMG_OK);
  CHECK(ke == n0);
  CHECK(k == n0);
  CHECK_RC(phgmg_pod_randomized(N, ns, X, N, kmax, 1, 1ul, V, N, S, &k, NULL), PHGMG_OK);
  for (j = 0; j < n0; ++j) CHECK_LE(fabs(S[j] - sig[j]), 1e-14 * sig[0]);
  CHECK_LE(rs_angle(N, n0, U, N, V, N), 1e-12);
  free(U); free(X); free(V);
}

static int rs_fail_after;
static void *rs_alloc(size_t n, void *u) {
  (void)u;
  if (rs_fail_after-- <= 0) return NULL;
  return malloc(n);
}
static void rs_free(void *p, void *u) { (void)u; free(p); }

TEST(test_rsvd_errors) {
  enum { N = 60, NS = 30 };
  static double X[N * NS], V[N * 5], S[5], Vk[N * 5], V20[N * 20], Vk20[N * 20];
  int k = -7, i;
  phgmg_allocator al;
  for (i = 0; i < N * NS; ++i) X[i] = th_rand();
  CHECK_RC(phgmg_pod_randomized(N, NS, NULL, N, 5, 2, 1ul, V, N, S, &k, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_pod_randomized(N, NS, X, N, 5, -1, 1ul, V, N, S, &k, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_pod_randomized(N, NS, X, N, 5, 2, 1ul, V, N, S, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_pod_randomized(N, NS, X, N, NS + 1, 2, 1ul, V, N, S, &k, NULL), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_pod_randomized(N, NS, X, N - 1, 5, 2, 1ul, V, N, S, &k, NULL), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_pod_randomized(N, NS, X, N, 0, 2, 1ul, V, N, S, &k, NULL), PHGMG_ERR_SIZE);
  CHECK(k == -7);
  /* kmax = 20: l = min(kmax + 20, N, ns) = 30 = ns, the range finder is then exact */
  {
    double Se[20], S20[20];
    int ke;
    CHECK_RC(phgmg_pod_randomized(N, NS, X, N, 20, 0, 1ul, V20, N, S20, &k, NULL), PHGMG_OK);
    CHECK_RC(phgmg_svd(N, NS, X, N, 20, Se, Vk20, N, NULL, 1, &ke, NULL, NULL), PHGMG_OK);
    CHECK(k == 20 && ke == 20);
    for (i = 0; i < 20; ++i) CHECK_LE(fabs(S20[i] - Se[i]), 1e-13 * Se[0]);
    CHECK_LE(rs_angle(N, 20, Vk20, N, V20, N), 1e-12);
  }
  CHECK_RC(phgmg_pod_randomized(N, NS, X, N, 5, 2, 1ul, V, N, S, &k, NULL), PHGMG_OK);
  memcpy(Vk, V, sizeof V);
  /* every allocation failure: PHGMG_ERR_NOMEM, V and k untouched */
  al.alloc = rs_alloc; al.free = rs_free; al.user = NULL;
  for (i = 0; i < 8; ++i) {
    phgmg_result rc;
    k = -7;
    rs_fail_after = i;
    rc = phgmg_pod_randomized(N, NS, X, N, 5, 2, 9ul, V, N, S, &k, &al);
    if (rc == PHGMG_OK) break;
    CHECK_RC(rc, PHGMG_ERR_NOMEM);
    CHECK(k == -7);
    CHECK(memcmp(Vk, V, sizeof V) == 0);
  }
  CHECK(i > 0 && i < 8);
  X[17] = NAN;
  CHECK_RC(phgmg_pod_randomized(N, NS, X, N, 5, 2, 1ul, V, N, S, &k, NULL), PHGMG_ERR_NANINF);
  X[17] = INFINITY;
  CHECK_RC(phgmg_pod_randomized(N, NS, X, N, 5, 2, 1ul, V, N, S, &k, NULL), PHGMG_ERR_NANINF);
  for (i = 0; i < N * NS; ++i) X[i] = 0.0;
  CHECK_RC(phgmg_pod_randomized(N, NS, X, N, 5, 2, 1ul, V, N, S, &k, NULL), PHGMG_OK);
  CHECK(k == 0);
}

/* PHGMG_POD_RANDOMIZED_MIN = 1e5 in this file: phgmg_pod with tol <= 0 on
   N*ns >= 1e5 and kmax small is the randomized POD (same bits); tol > 0 and
   small matrices stay exact. */
TEST(test_rsvd_pod_auto_switch) {
  const int N = 1000, ns = 200, n0 = 200, kmax = 10;
  double sig[200], S1[10], S2[10], *U, *X, *V1, *V2;
  int j, k1, k2;
  size_t cnt = (size_t)N * kmax;
  for (j = 0; j < n0; ++j) sig[j] = exp(-0.3 * j);
  X = rs_build(N, ns, n0, sig, &U);
  V1 = (double *)malloc(sizeof(double) * cnt);
  V2 = (double *)malloc(sizeof(double) * cnt);
  CHECK_RC(phgmg_pod(N, ns, X, N, kmax, 0.0, V1, N, S1, &k1, NULL), PHGMG_OK);
  CHECK_RC(phgmg_pod_randomized(N, ns, X, N, kmax, PHGMG_POD_POWER_ITERS, PHGMG_POD_SEED, V2, N, S2,
                                &k2, NULL), PHGMG_OK);
  CHECK(k1 == kmax && k2 == kmax);
  CHECK(memcmp(V1, V2, sizeof(double) * cnt) == 0 && memcmp(S1, S2, sizeof S1) == 0);
  /* tol > 0: the exact path (bits of phgmg_svd) */
  CHECK_RC(phgmg_pod(N, ns, X, N, kmax, 1e-12, V1, N, S1, &k1, NULL), PHGMG_OK);
  CHECK_RC(phgmg_svd(N, ns, X, N, kmax, S2, V2, N, NULL, 1, &k2, NULL, NULL), PHGMG_OK);
  CHECK(k1 == kmax && k2 == kmax);
  CHECK(memcmp(V1, V2, sizeof(double) * cnt) == 0 && memcmp(S1, S2, sizeof S1) == 0);
  /* below the size threshold: exact too */
  CHECK_RC(phgmg_pod(N, 90, X, N, kmax, 0.0, V1, N, S1, &k1, NULL), PHGMG_OK);
  CHECK_RC(phgmg_svd(N, 90, X, N, kmax, S2, V2, N, NULL, 1, &k2, NULL, NULL), PHGMG_OK);
  CHECK(memcmp(V1, V2, sizeof(double) * cnt) == 0 && memcmp(S1, S2, sizeof S1) == 0);
  free(U); free(X); free(V1); free(V2);
}

/* The paper's nonlinear chain, N = 1000, 1001 snapshots (u = 0.1 sin t,
   dt = 0.1): 40 modes (sigma_40/sigma_1 ~ 5e-5) against the exact POD. */
TEST(test_rsvd_paper_chain) {
  enum { NS = 1001, KP = 40 };
  msd_nonlinear M;
  msd_nl_opts mo;
  phgmg_gl3_opts go;
  double *X, *x0, *V, *Ve, S[KP], Se[KP], err = 0.0;
  int N, k = 0, ke = 0, j;
  memset(&mo, 0, sizeof mo);
  mo.n = 500;
  mo.storage = PHGMG_BANDED;
  CHECK(msd_nonlinear_build(&M, &mo) == 0);
  N = M.sys.N;
  X = (double *)malloc(sizeof(double) * (size_t)N * NS);
  x0 = (double *)calloc((size_t)N, sizeof(double));
  V = (double *)malloc(sizeof(double) * (size_t)N * KP);
  Ve = (double *)malloc(sizeof(double) * (size_t)N * KP);
  memset(&go, 0, sizeof go);
  go.tol = 1e-8; go.max_iter = 20;
  CHECK_RC(phgmg_simulate(&M.sys, x0, 0.0, 0.1, NS - 1, msd_input_sin, NULL, &go, X, NULL, NULL, NULL, NULL,
                          NULL), PHGMG_OK);
  CHECK_RC(phgmg_pod_randomized(N, NS, X, N, KP, 2, 1ul, V, N, S, &k, NULL), PHGMG_OK);
  CHECK_RC(phgmg_svd(N, NS, X, N, KP, Se, Ve, N, NULL, 1, &ke, NULL, NULL), PHGMG_OK);
  CHECK(k == KP && ke == KP);
  CHECK_LE(Se[KP - 1] / Se[0], 1e-3); /* a decaying spectrum (the premise) */
  for (j = 0; j < KP; ++j) err = fmax(err, fabs(S[j] - Se[j]) / Se[j]);
  CHECK_LE(err, 1e-10);
  CHECK_LE(rs_angle(N, KP, Ve, N, V, N), 1e-6);
  CHECK_LE(rs_angle(N, 20, Ve, N, V, N), 1e-9);
  free(X); free(x0); free(V); free(Ve);
  msd_nonlinear_free(&M);
}

SUITE(rsvd) {
  RUN(test_rsvd_paper_chain);
  RUN(test_rsvd_known_spectrum);
  RUN(test_rsvd_slow_decay_power_iters);
  RUN(test_rsvd_deterministic_and_magnitude);
  RUN(test_rsvd_rank_deficient);
  RUN(test_rsvd_errors);
  RUN(test_rsvd_pod_auto_switch);
}
