/* The streaming POD (phgmg_pod_stream_*) and the reduction from it
   (phgmg_reduce_stream): the basis, values and coordinates of snapshots
   added in column blocks against a snapshot matrix of known SVD and against
   the in-core POD; the reduced models against phgmg_reduce's. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>

#include "fixture_msd.h"

/* Orthonormal columns (n x k) from a seeded generator: QR of pseudo-random entries. */
static void ps_orth(int n, int k, unsigned seed, double *Q) {
  double *tau = (double *)malloc(sizeof(double) * (size_t)(2 * k + 1));
  int i;
  for (i = 0; i < n * k; ++i) {
    seed = seed * 1103515245u + 12345u;
    Q[i] = (double)((seed >> 8) & 0xffff) / 65536.0 - 0.5;
  }
  CHECK_RC(phgmg_qr(n, k, Q, n, tau), PHGMG_OK);
  phgmg_qr_form_q(n, k, Q, n, tau, tau + k);
  free(tau);
}

/* X (N x ns) = U diag(s) W^T with s_j = 10^(-j/2), j < nr: the SVD known. */
static void ps_known(int N, int ns, int nr, double *U, double *X) {
  double *W = (double *)malloc(sizeof(double) * (size_t)ns * nr), *US = (double *)malloc(sizeof(double) * (size_t)N * nr);
  int i, j;
  ps_orth(N, nr, 17u, U);
  ps_orth(ns, nr, 91u, W);
  for (j = 0; j < nr; ++j)
    for (i = 0; i < N; ++i) US[i + (size_t)j * N] = U[i + (size_t)j * N] * pow(10.0, -0.5 * j);
  phgmg_gemm('N', 'T', N, ns, nr, 1.0, US, N, W, ns, 0.0, X, N);
  free(W);
  free(US);
}

/* ||(I - U U^T) V||_F for U (N x ku) and V (N x kv) orthonormal: the sines of
   the principal angles between span V and span U, in the Frobenius norm. */
static double ps_angle(int N, int ku, const double *U, int kv, const double *V) {
  double *C = (double *)malloc(sizeof(double) * (size_t)ku * kv), *R = (double *)malloc(sizeof(double) * (size_t)N * kv);
  double f;
  memcpy(R, V, sizeof(double) * (size_t)N * kv);
  phgmg_gemm('T', 'N', ku, kv, N, 1.0, U, N, R, N, 0.0, C, ku);
  phgmg_gemm('N', 'N', N, kv, ku, -1.0, U, N, C, ku, 1.0, R, N);
  f = phgmg_normf(N, kv, R, N);
  free(C);
  free(R);
  return f;
}

/* Stream X (N x ns) in blocks of nb columns (the last one shorter). */
static phgmg_pod_stream *ps_stream(int N, int ns, const double *X, int m, const double *B, int kmax, int nb) {
  phgmg_pod_stream *st = NULL;
  int j;
  CHECK_RC(phgmg_pod_stream_begin(&st, N, m, B, N, kmax, 0.0, NULL), PHGMG_OK);
  for (j = 0; j < ns && st; j += nb)
    CHECK_RC(phgmg_pod_stream_add(st, PHGMG__MIN(nb, ns - j), X + (size_t)j * N, N), PHGMG_OK);
  CHECK(phgmg_pod_stream_columns(st) == ns);
  return st;
}

/* A snapshot matrix of known SVD (40 values 1 ... 10^-19.5) in blocks of 7:
   without truncation the values agree with the known ones to 1e-12 sigma_1
   and the 12 leading modes span the known ones (sines <= 1e-8); kept at
   rank 25 the values stay within the stated bound and the 12 modes within
   1e-8; the coordinates are V^T X. */
TEST(test_pod_stream_known_svd) {
  const int N = 240, ns = 90, nr = 40, r = 12;
  double *U = (double *)malloc(sizeof(double) * (size_t)N * nr), *X = (double *)malloc(sizeof(double) * (size_t)N * ns);
  double *V = (double *)malloc(sizeof(double) * (size_t)N * ns), S[90], disc = -1.0, *Z;
  int k = 0, j, kmax, pass;
  ps_known(N, ns, nr, U, X);
  for (pass = 0; pass < 2; ++pass) {
    phgmg_pod_stream *st;
    kmax = pass ? 2 * r + 1 : ns;
    st = ps_stream(N, ns, X, 0, NULL, kmax, 7);
    CHECK_RC(phgmg_pod_stream_end(st, V, N, S, &k, &disc), PHGMG_OK);
    if (!pass) {
      /* values at or below the rounding floor max(N, ns) eps ||X||_F count as zero */
      double f2 = 0.0;
      int kf = 0;
      for (j = 0; j < nr; ++j) f2 += pow(10.0, -1.0 * j);
      while (kf < nr && pow(10.0, -0.5 * kf) > (double)N * PHGMG__EPS * sqrt(f2)) ++kf;
      CHECK(kf > 20 && (k == kf || k == kf + 1));
      CHECK_LE(disc, 1e-12);
      for (j = 0; j < k; ++j) CHECK_LE(fabs(S[j] - pow(10.0, -0.5 * j)), 1e-12);
    } else {
      CHECK(k == kmax);
      CHECK(disc > 0.0 && disc < 1e-11);
      for (j = 0; j < k; ++j) CHECK_LE(fabs(S[j] - pow(10.0, -0.5 * j)), disc + 1e-14);
    }
    CHECK_LE(ps_angle(N, r, U, r, V), 1e-8);
    /* coordinates: Z = V^T X */
    Z = (double *)malloc(sizeof(double) * (size_t)k * ns);
    phgmg_gemm('T', 'N', k, ns, N, 1.0, V, N, X, N, 0.0, Z, k);
    for (j = 0; j < ns; ++j) {
      int i;
      for (i = 0; i < k; ++i) CHECK_LE(fabs(Z[i + (size_t)j * k] - st->Z[i + (size_t)j * kmax]), 1e-12);
    }
    free(Z);
    phgmg_pod_stream_destroy(st);
  }
  free(U); free(X); free(V);
}

/* With B: the stream PODs the adjusted snapshots X - B B^+ X, as the
   in-core phgmg_adjust_snapshots + phgmg_pod do: the same values (1e-12
   sigma_1) and the same leading subspace. */
TEST(test_pod_stream_deflated) {
  const int N = 200, ns = 70, nr = 30, r = 10;
  double *U = (double *)malloc(sizeof(double) * (size_t)N * nr), *X = (double *)malloc(sizeof(double) * (size_t)N * ns);
  double *Xa = (double *)malloc(sizeof(double) * (size_t)N * ns), *V = (double *)malloc(sizeof(double) * (size_t)N * ns);
  double *Vi = (double *)malloc(sizeof(double) * (size_t)N * r), B[400], S[70], Si[10];
  phgmg_pod_stream *st;
  int k = 0, ki = 0, j;
  ps_known(N, ns, nr, U, X);
  ps_orth(N, 2, 5u, B);
  for (j = 0; j < 2 * N; ++j) B[j] = 3.0 * B[j] + 0.01 * X[j];   /* two columns, not orthonormal */
  CHECK_RC(phgmg_adjust_snapshots(N, 2, B, ns, X, N, Xa, N, NULL), PHGMG_OK);
  CHECK_RC(phgmg_pod(N, ns, Xa, N, r, 0.0, Vi, N, Si, &ki, NULL), PHGMG_OK);
  st = ps_stream(N, ns, X, 2, B, ns - 2, 16);
  CHECK_RC(phgmg_pod_stream_end(st, V, N, S, &k, NULL), PHGMG_OK);
  CHECK(k >= r && ki == r);
  for (j = 0; j < r; ++j) CHECK_LE(fabs(S[j] - Si[j]), 1e-12 * Si[0]);
  CHECK_LE(ps_angle(N, r, Vi, r, V), 1e-8);
  phgmg_pod_stream_destroy(st);
  free(U); free(X); free(Xa); free(V); free(Vi);
}

static void ps_u(double t, double *u, void *user) { (void)user; u[0] = sin(t) + 0.5 * sin(2.7 * t); }

/* phgmg_reduce_stream equals phgmg_reduce on the same snapshots (streamed in
   blocks of 13, kept at rank 100 >= their numerical rank): the chain's
   GMG-POD (r = 10) and SP1 (r = 8) models give the same outputs on a run
   (1e-10 relative), and the streamed model's training envelope is the range
   of its coordinates of the snapshots (1e-10 of the largest width). */
TEST(test_pod_stream_reduce) {
  const int n = 60, N = 2 * n, ns = 301;
  dmodel t;
  double *X = (double *)calloc((size_t)N * ns, sizeof(double)), *x0 = (double *)calloc((size_t)N, sizeof(double));
  double *Y1 = (double *)malloc(sizeof(double) * 401), *Y2 = (double *)malloc(sizeof(double) * 401), xr0[10] = {0};
  int meth;
  dmodel_msd(&t, n);
  CHECK_RC(phgmg_simulate(&t.sys, x0, 0.0, 0.1, ns - 1, ps_u, NULL, NULL, X, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
  for (meth = 0; meth < 2; ++meth) {
    const int gmg = meth == 0, r = gmg ? 10 : 8;
    phgmg_reduce_opts o;
    phgmg_reduced *a = NULL, *b = NULL;
    phgmg_pod_stream *st = ps_stream(N, ns, X, gmg, gmg ? t.B : NULL, 100, 13);
    double ymax = 0.0, err = 0.0, wmax = 0.0, eerr = 0.0;
    int j;
    memset(&o, 0, sizeof o);
    o.method = gmg ? PHGMG_METHOD_GMG_POD : PHGMG_METHOD_SP1; o.r = r;
    CHECK_RC(phgmg_reduce(&a, &t.sys, X, N, ns, &o, NULL, NULL), PHGMG_OK);
    CHECK_RC(phgmg_reduce_stream(&b, &t.sys, st, &o, NULL, NULL), PHGMG_OK);
    if (a && b) {
      const phgmg_rom *ra = phgmg_reduced_rom(a), *rb = phgmg_reduced_rom(b);
      CHECK_RC(phgmg_reduced_simulate(a, xr0, 0.0, 0.1, 400, ps_u, NULL, 0.0, 0, NULL, Y1, NULL, NULL, NULL), PHGMG_OK);
      CHECK_RC(phgmg_reduced_simulate(b, xr0, 0.0, 0.1, 400, ps_u, NULL, 0.0, 0, NULL, Y2, NULL, NULL, NULL), PHGMG_OK);
      for (j = 0; j <= 400; ++j) { ymax = PHGMG__MAX(ymax, fabs(Y1[j])); err = PHGMG__MAX(err, fabs(Y1[j] - Y2[j])); }
      CHECK(ymax > 0.1);
      CHECK_LE(err, 1e-10 * ymax);
      /* the envelope: the range of the model's own rho(x_j) over the snapshots,
         widened by 10 % of each width plus 2 % of the largest */
      {
        double lo[10], hi[10], xr[10];
        int i;
        for (j = 0; j < ns; ++j) {
          phgmg_reduced_restrict(b, X + (size_t)j * N, xr);
          for (i = 0; i < r; ++i) {
            if (!j || xr[i] < lo[i]) lo[i] = xr[i];
            if (!j || xr[i] > hi[i]) hi[i] = xr[i];
          }
        }
        for (i = 0; i < r; ++i) wmax = PHGMG__MAX(wmax, hi[i] - lo[i]);
        for (i = 0; i < r; ++i) {
          const double w = 0.1 * (hi[i] - lo[i]) + 0.02 * wmax;
          eerr = PHGMG__MAX(eerr, fabs(lo[i] - w - (double)rb->env_lo[i]));
          eerr = PHGMG__MAX(eerr, fabs(hi[i] + w - (double)rb->env_hi[i]));
        }
        CHECK(wmax > 0.1 && ra->env_lo && rb->env_lo);
        CHECK_LE(eerr, 1e-10 * wmax);
      }
    }
    phgmg_reduced_destroy(a);
    phgmg_reduced_destroy(b);
    phgmg_pod_stream_destroy(st);
  }
  free(X); free(x0); free(Y1); free(Y2);
  dmodel_free(&t);
}

/* Bad arguments: clear codes; a block with NaN is refused whole (the stream
   unchanged); methods and options that need the snapshots themselves are
   refused by phgmg_reduce_stream. */
TEST(test_pod_stream_errors) {
  dmodel t;
  phgmg_pod_stream *st = NULL;
  phgmg_reduced *red = NULL;
  phgmg_reduce_opts o;
  double X[40 * 3], B2[40];
  int i, k = -1;
  dmodel_msd(&t, 20);
  for (i = 0; i < 120; ++i) X[i] = sin(0.3 * i);
  CHECK_RC(phgmg_pod_stream_begin(NULL, 40, 0, NULL, 40, 5, 0.0, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_pod_stream_begin(&st, 40, 1, NULL, 40, 5, 0.0, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_pod_stream_begin(&st, 40, 0, NULL, 40, 0, 0.0, NULL), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_pod_stream_begin(&st, 40, 0, NULL, 40, 5, 1.0, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_pod_stream_begin(&st, 40, 1, t.B, 39, 5, 0.0, NULL), PHGMG_ERR_SIZE);
  memset(B2, 0, sizeof B2);
  CHECK_RC(phgmg_pod_stream_begin(&st, 40, 1, B2, 40, 5, 0.0, NULL), PHGMG_ERR_RANK);
  CHECK(st == NULL);
  CHECK_RC(phgmg_pod_stream_begin(&st, 40, 1, t.B, 40, 5, 0.0, NULL), PHGMG_OK);
  CHECK_RC(phgmg_pod_stream_add(st, 3, X, 39), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_pod_stream_add(st, 0, X, 40), PHGMG_ERR_SIZE);
  X[50] = NAN;
  CHECK_RC(phgmg_pod_stream_add(st, 3, X, 40), PHGMG_ERR_NANINF);
  CHECK(phgmg_pod_stream_columns(st) == 0);
  CHECK_RC(phgmg_pod_stream_end(st, NULL, 0, NULL, &k, NULL), PHGMG_OK);
  CHECK(k == 0);
  X[50] = 0.0;
  CHECK_RC(phgmg_pod_stream_add(st, 3, X, 40), PHGMG_OK);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_QM; o.r = 3;
  CHECK_RC(phgmg_reduce_stream(&red, &t.sys, st, &o, NULL, NULL), PHGMG_ERR_UNSUPPORTED);
  o.method = PHGMG_METHOD_SP1;
  CHECK_RC(phgmg_reduce_stream(&red, &t.sys, st, &o, NULL, NULL), PHGMG_ERR_INVALID_ARG);  /* stream has B */
  o.method = PHGMG_METHOD_GMG_POD; o.ref = PHGMG_REF_MEAN;
  CHECK_RC(phgmg_reduce_stream(&red, &t.sys, st, &o, NULL, NULL), PHGMG_ERR_UNSUPPORTED);
  o.ref = PHGMG_REF_NONE; o.r = 6;   /* r - m = 5 modes > the 3 the stream holds */
  CHECK_RC(phgmg_reduce_stream(&red, &t.sys, st, &o, NULL, NULL), PHGMG_ERR_SIZE);
  CHECK(red == NULL);
  t.B[0] = 0.5;   /* not the stream's B */
  o.r = 3;
  CHECK_RC(phgmg_reduce_stream(&red, &t.sys, st, &o, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  phgmg_pod_stream_destroy(st);
  dmodel_free(&t);
}

/* phgmg_npy_read_cols: columns 3..6 of a 9 x 8 file written in Fortran and
   in C order are those columns exactly; the shape alone with out NULL;
   columns beyond the file: PHGMG_ERR_SIZE; no file: PHGMG_ERR_IO. */
TEST(test_pod_stream_npy_cols) {
  const char *path = "build/test_npy_cols.npy";
  double A[72], out[9 * 4 + 5];
  int i, ord, rows = 0, cols = 0;
  for (i = 0; i < 72; ++i) A[i] = 0.25 * i - 3.0;
  for (ord = 0; ord < 2; ++ord) {
    CHECK_RC(phgmg_npy_write(path, A, 9, 8, 9, 2, ord ? PHGMG_NPY_C_ORDER : 0u), PHGMG_OK);
    CHECK_RC(phgmg_npy_read_cols(path, 0, 0, NULL, 1, &rows, &cols), PHGMG_OK);
    CHECK(rows == 9 && cols == 8);
    for (i = 0; i < 9 * 4 + 5; ++i) out[i] = -1.0;
    CHECK_RC(phgmg_npy_read_cols(path, 3, 4, out, 10, NULL, NULL), PHGMG_OK);
    for (i = 0; i < 9 * 4; ++i) CHECK(out[(i / 9) * 10 + i % 9] == A[27 + i]);
    CHECK(out[9] == -1.0);   /* ldo 10: the gap untouched */
    CHECK_RC(phgmg_npy_read_cols(path, 5, 4, out, 9, NULL, NULL), PHGMG_ERR_SIZE);
    CHECK_RC(phgmg_npy_read_cols(path, 0, 1, out, 8, NULL, NULL), PHGMG_ERR_SIZE);
  }
  remove(path);
  CHECK_RC(phgmg_npy_read_cols(path, 0, 0, NULL, 1, &rows, &cols), PHGMG_ERR_IO);
}

SUITE(pod_stream) {
  RUN(test_pod_stream_known_svd);
  RUN(test_pod_stream_deflated);
  RUN(test_pod_stream_reduce);
  RUN(test_pod_stream_errors);
  RUN(test_pod_stream_npy_cols);
}
