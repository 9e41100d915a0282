/* Dense linear algebra: products, LU (real/complex), condition estimate, QR,
   pivoted QR, least squares, thin SVD, symmetric eigenproblem. Every check is
   against a closed form, an invariant or an independent (naive) computation. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>

#define EPS PHGMG__EPS

/* ---- independent helpers (naive loops, no library calls) ------------------- */
static double *tl_new(size_t n) {
  double *p = (double *)calloc(n ? n : 1, sizeof(double));
  if (!p) { fprintf(stderr, "test_linalg: out of memory\n"); exit(2); }
  return p;
}
static void tl_rand(int m, int n, double *A, int lda) {
  int i, j;
  for (j = 0; j < n; ++j)
    for (i = 0; i < m; ++i) A[i + (size_t)j * lda] = th_rand();
}
/* C = op(A) op(B), naive triple loop. */
static void tl_mul(int ta, int tb, int m, int n, int k, const double *A, int lda,
                   const double *B, int ldb, double *C, int ldc) {
  int i, j, p;
  for (j = 0; j < n; ++j)
    for (i = 0; i < m; ++i) {
      double s = 0.0;
      for (p = 0; p < k; ++p) {
        double a = ta ? A[p + (size_t)i * lda] : A[i + (size_t)p * lda];
        double b = tb ? B[j + (size_t)p * ldb] : B[p + (size_t)j * ldb];
        s += a * b;
      }
      C[i + (size_t)j * ldc] = s;
    }
}
static double tl_maxabs(int m, int n, const double *A, int lda) {
  double r = 0.0;
  int i, j;
  for (j = 0; j < n; ++j)
    for (i = 0; i < m; ++i) r = fmax(r, fabs(A[i + (size_t)j * lda]));
  return r;
}
static double tl_norm1(int m, int n, const double *A, int lda) {
  double r = 0.0;
  int i, j;
  for (j = 0; j < n; ++j) {
    double s = 0.0;
    for (i = 0; i < m; ++i) s += fabs(A[i + (size_t)j * lda]);
    r = fmax(r, s);
  }
  return r;
}
/* max |Q^T Q - I| for Q m x k */
static double tl_orth_err(int m, int k, const double *Q, int ldq) {
  double e = 0.0;
  int i, j, p;
  for (j = 0; j < k; ++j)
    for (i = 0; i <= j; ++i) {
      double s = 0.0;
      for (p = 0; p < m; ++p) s += Q[p + (size_t)i * ldq] * Q[p + (size_t)j * ldq];
      e = fmax(e, fabs(s - (i == j ? 1.0 : 0.0)));
    }
  return e;
}
/* Random m x k matrix with orthonormal columns: modified Gram-Schmidt, twice. */
static void tl_orthonormal(int m, int k, double *Q) {
  int i, j, p, pass;
  tl_rand(m, k, Q, m);
  for (j = 0; j < k; ++j) {
    double *q = Q + (size_t)j * m;
    for (pass = 0; pass < 2; ++pass)
      for (p = 0; p < j; ++p) {
        const double *qp = Q + (size_t)p * m;
        double s = 0.0;
        for (i = 0; i < m; ++i) s += qp[i] * q[i];
        for (i = 0; i < m; ++i) q[i] -= s * qp[i];
      }
    {
      double s = 0.0;
      for (i = 0; i < m; ++i) s += q[i] * q[i];
      s = sqrt(s);
      for (i = 0; i < m; ++i) q[i] /= s;
    }
  }
}
/* Inverse of an n x n matrix by Gauss-Jordan with full pivoting (independent of
   the library's LU). Returns 0 if singular. */
static int tl_inverse(int n, const double *A, double *Ainv) {
  double *M = tl_new((size_t)n * 2 * n);
  int *rp = (int *)calloc((size_t)n, sizeof(int)), *cp = (int *)calloc((size_t)n, sizeof(int));
  int *used_r = (int *)calloc((size_t)n, sizeof(int)), *used_c = (int *)calloc((size_t)n, sizeof(int));
  int i, j, k, ok = 1, ld = n;
  /* M = [A | I], rows n, cols 2n */
  for (j = 0; j < n; ++j)
    for (i = 0; i < n; ++i) {
      M[i + (size_t)j * ld] = A[i + (size_t)j * n];
      M[i + (size_t)(n + j) * ld] = i == j ? 1.0 : 0.0;
    }
  for (k = 0; k < n; ++k) {
    int pr = -1, pc = -1;
    double best = 0.0, piv;
    for (j = 0; j < n; ++j) {
      if (used_c[j]) continue;
      for (i = 0; i < n; ++i)
        if (!used_r[i] && fabs(M[i + (size_t)j * ld]) > best) {
          best = fabs(M[i + (size_t)j * ld]); pr = i; pc = j;
        }
    }
    if (pr < 0) { ok = 0; break; }
    used_r[pr] = used_c[pc] = 1;
    rp[k] = pr; cp[k] = pc;
    piv = M[pr + (size_t)pc * ld];
    for (j = 0; j < 2 * n; ++j) M[pr + (size_t)j * ld] /= piv;
    for (i = 0; i < n; ++i) {
      double f;
      if (i == pr) continue;
      f = M[i + (size_t)pc * ld];
      if (f == 0.0) continue;
      for (j = 0; j < 2 * n; ++j) M[i + (size_t)j * ld] -= f * M[pr + (size_t)j * ld];
    }
  }
  /* row rp[k] holds x_{cp[k]}: A^{-1}(cp[k], :) = M(rp[k], n:2n) */
  if (ok)
    for (k = 0; k < n; ++k)
      for (j = 0; j < n; ++j) Ainv[cp[k] + (size_t)j * n] = M[rp[k] + (size_t)(n + j) * ld];
  free(M); free(rp); free(cp); free(used_r); free(used_c);
  return ok;
}

/* ---- products and norms ---------------------------------------------------- */
TEST(test_gemm_vs_naive) {
  const int sizes[][3] = {{1, 1, 1}, {3, 5, 2}, {17, 13, 9}, {70, 33, 131}, {129, 67, 300}, {5, 4, 0}};
  int s, ta, tb;
  for (s = 0; s < (int)(sizeof sizes / sizeof sizes[0]); ++s) {
    int m = sizes[s][0], n = sizes[s][1], k = sizes[s][2];
    int lda = 311, ldb = 307, ldc = m + 3;
    double *A = tl_new((size_t)lda * 311), *B = tl_new((size_t)ldb * 311);
    double *C = tl_new((size_t)ldc * n), *C0 = tl_new((size_t)ldc * n), *R = tl_new((size_t)m * n);
    tl_rand(lda, 311, A, lda);
    tl_rand(ldb, 311, B, ldb);
    tl_rand(ldc, n, C0, ldc);
    for (ta = 0; ta < 2; ++ta)
      for (tb = 0; tb < 2; ++tb) {
        int i, j;
        double err = 0.0;
        memcpy(C, C0, sizeof(double) * (size_t)ldc * n);
        phgmg_gemm(ta ? 'T' : 'N', tb ? 'T' : 'N', m, n, k, 1.5, A, lda, B, ldb, -0.5, C, ldc);
        tl_mul(ta, tb, m, n, k, A, lda, B, ldb, R, m);
        for (j = 0; j < n; ++j) {
          for (i = 0; i < m; ++i)
            err = fmax(err, fabs(C[i + (size_t)j * ldc] -
                                 (1.5 * R[i + (size_t)j * m] - 0.5 * C0[i + (size_t)j * ldc])));
          for (i = m; i < ldc; ++i) CHECK(C[i + (size_t)j * ldc] == C0[i + (size_t)j * ldc]);
        }
        CHECK_LE(err, 4.0 * (k + 2) * EPS);
        /* beta = 0 must overwrite, even NaN */
        for (j = 0; j < n; ++j)
          for (i = 0; i < m; ++i) C[i + (size_t)j * ldc] = NAN;
        phgmg_gemm(ta ? 'T' : 'N', tb ? 'T' : 'N', m, n, k, 1.0, A, lda, B, ldb, 0.0, C, ldc);
        err = 0.0;
        for (j = 0; j < n; ++j)
          for (i = 0; i < m; ++i)
            err = fmax(err, fabs(C[i + (size_t)j * ldc] - R[i + (size_t)j * m]));
        CHECK_LE(err, 4.0 * (k + 2) * EPS);
      }
    free(A); free(B); free(C); free(C0); free(R);
  }
}

TEST(test_gemv_vs_naive) {
  int m = 37, n = 23, lda = 40, i, j, t;
  double A[40 * 23], x[40], y[40], y0[40];
  tl_rand(lda, n, A, lda);
  tl_rand(40, 1, x, 40);
  tl_rand(40, 1, y0, 40);
  for (t = 0; t < 2; ++t) {
    int ny = t ? n : m, nx = t ? m : n;
    double err = 0.0;
    memcpy(y, y0, sizeof y);
    phgmg_gemv(t ? 'T' : 'N', m, n, 2.0, A, lda, x, 0.25, y);
    for (i = 0; i < ny; ++i) {
      double s = 0.0;
      for (j = 0; j < nx; ++j) s += (t ? A[j + i * lda] : A[i + j * lda]) * x[j];
      err = fmax(err, fabs(y[i] - (2.0 * s + 0.25 * y0[i])));
    }
    CHECK_LE(err, 100 * EPS);
    CHECK(y[ny] == y0[ny]);
  }
}

TEST(test_norms) {
  double A[3 * 2] = {1, -2, 3, -4, 5, 6}, big[4];
  int i;
  CHECK(phgmg_norm1(3, 2, A, 3) == 15.0);
  CHECK(phgmg_norm1(2, 2, A, 3) == 9.0); /* columns (1,-2), (-4,5) */
  CHECK_LE(fabs(phgmg_normf(3, 2, A, 3) - sqrt(91.0)), 4 * EPS * sqrt(91.0));
  for (i = 0; i < 4; ++i) big[i] = 1e300;
  CHECK_LE(fabs(phgmg_normf(2, 2, big, 2) / 2e300 - 1.0), 4 * EPS);
  for (i = 0; i < 4; ++i) big[i] = 3e-300;
  CHECK_LE(fabs(phgmg_normf(4, 1, big, 4) / 6e-300 - 1.0), 4 * EPS);
  CHECK(phgmg_normf(0, 5, A, 1) == 0.0);
  big[2] = NAN;
  CHECK(phgmg_normf(4, 1, big, 4) != phgmg_normf(4, 1, big, 4));
}

/* ---- real LU ----------------------------------------------------------------- */
/* Checks ||PA - LU||_1 <= 10 n eps ||A||_1 and the solve residuals for a matrix. */
static void lu_check(int n, const double *A) {
  int lda = n + 1, i, j, k;
  double *F = tl_new((size_t)lda * n), *PA = tl_new((size_t)n * n), *L = tl_new((size_t)n * n);
  double *U = tl_new((size_t)n * n), *LU = tl_new((size_t)n * n), *x = tl_new((size_t)n * 5);
  double *b = tl_new((size_t)n * 5), anorm = tl_norm1(n, n, A, n), r;
  int *ipiv = (int *)calloc((size_t)n, sizeof(int));
  for (j = 0; j < n; ++j) memcpy(F + (size_t)j * lda, A + (size_t)j * n, sizeof(double) * n);
  CHECK_RC(phgmg_lu_factor(n, F, lda, ipiv), PHGMG_OK);
  memcpy(PA, A, sizeof(double) * n * n);
  for (k = 0; k < n; ++k) {
    CHECK(ipiv[k] >= k && ipiv[k] < n);
    if (ipiv[k] != k)
      for (j = 0; j < n; ++j) {
        double t = PA[k + (size_t)j * n];
        PA[k + (size_t)j * n] = PA[ipiv[k] + (size_t)j * n];
        PA[ipiv[k] + (size_t)j * n] = t;
      }
  }
  for (j = 0; j < n; ++j)
    for (i = 0; i < n; ++i) {
      double f = F[i + (size_t)j * lda];
      L[i + (size_t)j * n] = i > j ? f : (i == j ? 1.0 : 0.0);
      U[i + (size_t)j * n] = i <= j ? f : 0.0;
      if (i > j) CHECK(fabs(f) <= 1.0); /* partial pivoting bounds |L| by 1 */
    }
  tl_mul(0, 0, n, n, n, L, n, U, n, LU, n);
  for (i = 0; i < n * n; ++i) LU[i] -= PA[i];
  CHECK_LE(tl_norm1(n, n, LU, n), 10.0 * n * EPS * anorm);
  /* solves, both transposes, one right-hand side (substitution) and five
     (blocked): ||A x - b||_1 <= 10 n eps ||A||_1 ||x||_1 per column */
  for (k = 0; k < 4; ++k) {
    int nr = (k & 2) ? 5 : 1, tr = k & 1;
    tl_rand(n, nr, b, n);
    memcpy(x, b, sizeof(double) * nr * n);
    phgmg_lu_solve(tr ? 'T' : 'N', n, F, lda, ipiv, nr, x, n);
    for (j = 0; j < nr; ++j) {
      double res = 0.0, xn = 0.0;
      for (i = 0; i < n; ++i) {
        double s = -b[i + j * n];
        int p;
        for (p = 0; p < n; ++p)
          s += (tr ? A[p + (size_t)i * n] : A[i + (size_t)p * n]) * x[p + j * n];
        res += fabs(s);
        xn += fabs(x[i + j * n]);
      }
      r = res / (anorm * xn);
      CHECK_LE(r, 10.0 * n * EPS);
    }
  }
  free(F); free(PA); free(L); free(U); free(LU); free(x); free(b); free(ipiv);
}

TEST(test_lu_random) {
  const int ns[] = {1, 2, 7, 31, 32, 33, 65, 100, 130};
  int s;
  for (s = 0; s < (int)(sizeof ns / sizeof ns[0]); ++s) {
    int n = ns[s];
    double *A = tl_new((size_t)n * n);
    tl_rand(n, n, A, n);
    lu_check(n, A);
    free(A);
  }
}

TEST(test_lu_graded) {
  const int ns[] = {10, 97, 200};
  int s, i, j;
  for (s = 0; s < 3; ++s) {
    int n = ns[s];
    double *A = tl_new((size_t)n * n);
    tl_rand(n, n, A, n);
    for (i = 0; i < n; ++i)
      for (j = 0; j < n; ++j) A[i + (size_t)j * n] *= pow(10.0, -(double)i * 8.0 / n);
    lu_check(n, A);
    /* columns graded too */
    for (j = 0; j < n; ++j)
      for (i = 0; i < n; ++i) A[i + (size_t)j * n] *= pow(10.0, -(double)j * 4.0 / n);
    lu_check(n, A);
    free(A);
  }
}

TEST(test_lu_big) {
  int n = 500;
  double *A = tl_new((size_t)n * n);
  tl_rand(n, n, A, n);
  lu_check(n, A);
  free(A);
}

TEST(test_lu_singular_naninf) {
  /* exactly singular: row 2 = 2 * row 0, and every multiplier is a power of two
     (pivots 4, then 1.5) so elimination is exact and the last pivot is exactly 0 */
  double A[9] = {1, 4, 2, 2, 5, 4, 4, 7, 8}, B[9];
  double Z[4] = {1, 2, 0, 0};
  int ipiv[3];
  memcpy(B, A, sizeof A);
  CHECK_RC(phgmg_lu_factor(3, B, 3, ipiv), PHGMG_ERR_SINGULAR);
  CHECK_RC(phgmg_lu_factor(2, Z, 2, ipiv), PHGMG_ERR_SINGULAR); /* zero column */
  memcpy(B, A, sizeof A);
  B[4] = NAN;
  CHECK_RC(phgmg_lu_factor(3, B, 3, ipiv), PHGMG_ERR_NANINF);
  CHECK(B[0] == A[0] && B[1] == A[1] && B[8] == A[8]); /* input left unchanged */
  B[4] = INFINITY;
  CHECK_RC(phgmg_lu_factor(3, B, 3, ipiv), PHGMG_ERR_NANINF);
  {
    /* finite input whose elimination overflows: A = [a -a; a a], a = 1.5e308,
       multiplier 1, U(1,1) = a - (-a) = Inf */
    double G[4] = {1.5e308, 1.5e308, -1.5e308, 1.5e308};
    CHECK_RC(phgmg_lu_factor(2, G, 2, ipiv), PHGMG_ERR_NANINF);
  }
  CHECK_RC(phgmg_lu_factor(-1, B, 3, ipiv), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_lu_factor(3, B, 2, ipiv), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_lu_factor(0, B, 1, ipiv), PHGMG_OK);
  {
    /* rcond of a singular factorization is 0 */
    double w[6];
    int iw[3];
    memcpy(B, A, sizeof A);
    phgmg_lu_factor(3, B, 3, ipiv);
    CHECK(phgmg_lu_rcond(3, B, 3, ipiv, phgmg_norm1(3, 3, A, 3), w, iw) == 0.0);
  }
}

TEST(test_lu_rcond) {
  int n, trial;
  for (trial = 0; trial < 12; ++trial) {
    double *A, *F, *Ai, *work, est, truth, anorm;
    int *ipiv, *iwork, i, j;
    n = 1 + (trial * 7) % 30;
    A = tl_new((size_t)n * n); F = tl_new((size_t)n * n); Ai = tl_new((size_t)n * n);
    work = tl_new(2 * (size_t)n);
    ipiv = (int *)calloc((size_t)n, sizeof(int)); iwork = (int *)calloc((size_t)n, sizeof(int));
    tl_rand(n, n, A, n);
    if (trial % 3 == 1) /* ill conditioned: graded rows and columns */
      for (j = 0; j < n; ++j)
        for (i = 0; i < n; ++i) A[i + (size_t)j * n] *= pow(10.0, -(double)(i + 2 * j) * 6.0 / n);
    if (trial % 3 == 2) /* nearly singular: make the last column close to the first */
      for (i = 0; i < n && n > 1; ++i)
        A[i + (size_t)(n - 1) * n] = A[i] * (1.0 + 1e-9 * th_rand());
    memcpy(F, A, sizeof(double) * n * n);
    anorm = phgmg_norm1(n, n, A, n);
    CHECK_RC(phgmg_lu_factor(n, F, n, ipiv), PHGMG_OK);
    est = phgmg_lu_rcond(n, F, n, ipiv, anorm, work, iwork);
    CHECK(tl_inverse(n, A, Ai));
    truth = 1.0 / (tl_norm1(n, n, A, n) * tl_norm1(n, n, Ai, n));
    /* the estimator bounds ||A^-1|| from below, so rcond from above (to rounding) */
    CHECK_LE(truth, est * (1.0 + 1e-6));
    CHECK_LE(est, 10.0 * truth);
    free(A); free(F); free(Ai); free(work); free(ipiv); free(iwork);
  }
}

/* ---- complex LU ---------------------------------------------------------------- */
TEST(test_zlu) {
  const int ns[] = {1, 3, 40, 120};
  int s;
  for (s = 0; s < 4; ++s) {
    int n = ns[s], lda = n + 2, i, j, k;
    double *A = tl_new(2 * (size_t)n * n), *F = tl_new(2 * (size_t)lda * n);
    double *P = tl_new(2 * (size_t)n * n), *x = tl_new(6 * (size_t)n), *b = tl_new(6 * (size_t)n);
    double err = 0.0, anorm = 0.0, res = 0.0, xn = 0.0;
    int *ipiv = (int *)calloc((size_t)n, sizeof(int));
    tl_rand(2 * n, n, A, 2 * n);
    if (s == 2) /* graded rows */
      for (j = 0; j < n; ++j)
        for (i = 0; i < n; ++i) {
          double g = pow(10.0, -(double)i * 8.0 / n);
          A[2 * (i + j * n)] *= g; A[2 * (i + j * n) + 1] *= g;
        }
    for (j = 0; j < n; ++j) {
      double cs = 0.0;
      memcpy(F + 2 * (size_t)j * lda, A + 2 * (size_t)j * n, 2 * sizeof(double) * n);
      for (i = 0; i < n; ++i) cs += hypot(A[2 * (i + j * n)], A[2 * (i + j * n) + 1]);
      anorm = fmax(anorm, cs);
    }
    CHECK_RC(phgmg_zlu_factor(n, F, lda, ipiv), PHGMG_OK);
    memcpy(P, A, 2 * sizeof(double) * n * n);
    for (k = 0; k < n; ++k)
      for (j = 0; j < n && ipiv[k] != k; ++j) {
        double t;
        size_t a = 2 * (k + (size_t)j * n), c = 2 * (ipiv[k] + (size_t)j * n);
        t = P[a]; P[a] = P[c]; P[c] = t;
        t = P[a + 1]; P[a + 1] = P[c + 1]; P[c + 1] = t;
      }
    /* ||PA - LU||_1 */
    for (j = 0; j < n; ++j) {
      double cs = 0.0;
      for (i = 0; i < n; ++i) {
        double sr = -P[2 * (i + j * n)], si = -P[2 * (i + j * n) + 1];
        for (k = 0; k <= PHGMG__MIN(i, j); ++k) {
          double lr = k == i ? 1.0 : F[2 * (i + k * lda)], li = k == i ? 0.0 : F[2 * (i + k * lda) + 1];
          double ur = F[2 * (k + j * lda)], ui = F[2 * (k + j * lda) + 1];
          sr += lr * ur - li * ui;
          si += lr * ui + li * ur;
        }
        cs += hypot(sr, si);
      }
      err = fmax(err, cs);
    }
    CHECK_LE(err, 10.0 * n * EPS * anorm);
    /* one right-hand side (substitution), then three (blocked) */
    for (k = 1; k <= 3; k += 2) {
      int c;
      tl_rand(2 * n, k, b, 2 * n);
      memcpy(x, b, 2 * sizeof(double) * n * k);
      phgmg_zlu_solve(n, F, lda, ipiv, k, x, n);
      for (c = 0; c < k; ++c) {
        const double *xc = x + 2 * (size_t)c * n, *bc = b + 2 * (size_t)c * n;
        res = xn = 0.0;
        for (i = 0; i < n; ++i) {
          double sr = -bc[2 * i], si = -bc[2 * i + 1];
          for (j = 0; j < n; ++j) {
            double ar = A[2 * (i + j * n)], ai = A[2 * (i + j * n) + 1];
            sr += ar * xc[2 * j] - ai * xc[2 * j + 1];
            si += ar * xc[2 * j + 1] + ai * xc[2 * j];
          }
          res += hypot(sr, si);
          xn += hypot(xc[2 * i], xc[2 * i + 1]);
        }
        CHECK_LE(res, 10.0 * n * EPS * anorm * xn);
      }
    }
    free(A); free(F); free(P); free(x); free(b); free(ipiv);
  }
  {
    /* singular: column 1 = i * column 0 = i (1+i, 2+2i); the multiplier 1/2 is exact */
    double Z[8] = {1, 1, 2, 2, -1, 1, -2, 2};
    double Y[8];
    int ipiv[2];
    memcpy(Y, Z, sizeof Z);
    CHECK_RC(phgmg_zlu_factor(2, Y, 2, ipiv), PHGMG_ERR_SINGULAR);
    memcpy(Y, Z, sizeof Z);
    Y[5] = NAN;
    CHECK_RC(phgmg_zlu_factor(2, Y, 2, ipiv), PHGMG_ERR_NANINF);
    CHECK(Y[0] == 1 && Y[3] == 2);
  }
  {
    /* closed form: diag(i, 2) x = (1, 4) -> x = (-i, 2) */
    double D[8] = {0, 1, 0, 0, 0, 0, 2, 0}, xb[4] = {1, 0, 4, 0};
    int ipiv[2];
    CHECK_RC(phgmg_zlu_factor(2, D, 2, ipiv), PHGMG_OK);
    phgmg_zlu_solve(2, D, 2, ipiv, 1, xb, 2);
    CHECK(xb[0] == 0.0 && xb[1] == -1.0 && xb[2] == 2.0 && xb[3] == 0.0);
  }
}

/* ---- QR ------------------------------------------------------------------------ */
TEST(test_qr) {
  const int dims[][2] = {{1, 1}, {5, 3}, {60, 60}, {120, 45}, {40, 70}};
  int s;
  for (s = 0; s < 5; ++s) {
    int m = dims[s][0], n = dims[s][1], k = PHGMG__MIN(m, n), lda = m + 1, i, j;
    double *A = tl_new((size_t)m * n), *F = tl_new((size_t)lda * n), *tau = tl_new((size_t)k);
    double *Q = tl_new((size_t)lda * k), *R = tl_new((size_t)k * n), *QR = tl_new((size_t)m * n);
    double *C = tl_new((size_t)m * 3), *C2 = tl_new((size_t)m * 3), *D = tl_new((size_t)m * 3);
    double anorm, err;
    tl_rand(m, n, A, m);
    anorm = tl_norm1(m, n, A, m);
    for (j = 0; j < n; ++j) memcpy(F + (size_t)j * lda, A + (size_t)j * m, sizeof(double) * m);
    CHECK_RC(phgmg_qr(m, n, F, lda, tau), PHGMG_OK);
    for (j = 0; j < n; ++j)
      for (i = 0; i < k; ++i) R[i + (size_t)j * k] = i <= j ? F[i + (size_t)j * lda] : 0.0;
    for (j = 0; j < k; ++j) memcpy(Q + (size_t)j * lda, F + (size_t)j * lda, sizeof(double) * m);
    phgmg_qr_form_q(m, k, Q, lda, tau, C);
    CHECK_LE(tl_orth_err(m, k, Q, lda), 10.0 * PHGMG__MAX(n, 1) * EPS);
    tl_mul(0, 0, m, n, k, Q, lda, R, k, QR, m);
    for (i = 0; i < m * n; ++i) QR[i] -= A[i];
    CHECK_LE(tl_norm1(m, n, QR, m), 10.0 * m * EPS * anorm);
    /* qr_apply: Q^T C equals the explicit product on the first k rows; Q (Q^T C) = C */
    tl_rand(m, 3, C, m);
    memcpy(C2, C, sizeof(double) * m * 3);
    phgmg_qr_apply('T', m, 3, k, F, lda, tau, C2, m);
    tl_mul(1, 0, k, 3, m, Q, lda, C, m, D, k);
    err = 0.0;
    for (j = 0; j < 3; ++j)
      for (i = 0; i < k; ++i) err = fmax(err, fabs(C2[i + j * m] - D[i + j * k]));
    CHECK_LE(err, 10.0 * m * EPS);
    phgmg_qr_apply('N', m, 3, k, F, lda, tau, C2, m);
    for (i = 0; i < 3 * m; ++i) C2[i] -= C[i];
    CHECK_LE(tl_maxabs(m, 3, C2, m), 10.0 * m * EPS);
    free(A); free(F); free(tau); free(Q); free(R); free(QR); free(C); free(C2); free(D);
  }
  {
    double A[4] = {1, NAN, 0, 1}, tau[2];
    CHECK_RC(phgmg_qr(2, 2, A, 2, tau), PHGMG_ERR_NANINF);
    CHECK(A[0] == 1.0 && A[3] == 1.0);
  }
}

/* A subnormal matrix: the reflectors must not overflow (1 / (alpha - beta)
   with a subnormal beta is Inf). Entries are small integers times 2^-1050,
   exact as subnormals; R must be 2^-1050 R(A) up to the subnormal resolution
   2^-1074 (relative 2^-24 of the entries), and Q orthonormal to round-off. */
TEST(test_qr_subnormal) {
  const int m = 12, n = 5, k = 5;
  double A[60], F[60], tau[5], Q[60], work[5];
  int i, j;
  unsigned s = 7u;
  for (i = 0; i < m * n; ++i) {
    s = s * 1103515245u + 12345u;
    A[i] = (double)((int)((s >> 16) % 17u) - 8);
    F[i] = ldexp(A[i], -1050);
  }
  CHECK_RC(phgmg_qr(m, n, A, m, tau), PHGMG_OK);
  CHECK_RC(phgmg_qr(m, n, F, m, tau), PHGMG_OK);
  for (j = 0; j < n; ++j)
    for (i = 0; i <= j; ++i) {
      double r = ldexp(F[i + j * m], 1050);
      CHECK(isfinite(r));
      CHECK_LE(fabs(fabs(r) - fabs(A[i + j * m])), 1e-5 * 8.0 * m);
    }
  memcpy(Q, F, sizeof Q);
  phgmg_qr_form_q(m, k, Q, m, tau, work);
  CHECK_LE(tl_orth_err(m, k, Q, m), 100.0 * EPS);
}

TEST(test_qrcp_rank) {
  const int dims[][3] = {{80, 60, 17}, {50, 90, 30}, {40, 40, 1}};
  int s;
  for (s = 0; s < 3; ++s) {
    int m = dims[s][0], n = dims[s][1], r = dims[s][2], k = PHGMG__MIN(m, n), i, j;
    double *X = tl_new((size_t)m * r), *Y = tl_new((size_t)n * r), *A = tl_new((size_t)m * n);
    double *F = tl_new((size_t)m * n), *tau = tl_new((size_t)k), *work = tl_new(2 * (size_t)n);
    double *Q = tl_new((size_t)m * k), *R = tl_new((size_t)k * n), *AP = tl_new((size_t)m * n);
    int *jpvt = (int *)calloc((size_t)n, sizeof(int)), *seen = (int *)calloc((size_t)n, sizeof(int));
    double anorm;
    tl_rand(m, r, X, m);
    tl_rand(n, r, Y, n);
    tl_mul(0, 1, m, n, r, X, m, Y, n, A, m);
    /* scale columns over 4 decades so pivoting matters */
    for (j = 0; j < n; ++j)
      for (i = 0; i < m; ++i) A[i + (size_t)j * m] *= pow(10.0, -4.0 * (double)((j * 7) % n) / n);
    anorm = tl_norm1(m, n, A, m);
    memcpy(F, A, sizeof(double) * m * n);
    CHECK_RC(phgmg_qrcp(m, n, F, m, tau, jpvt, work), PHGMG_OK);
    for (j = 0; j < n; ++j) {
      CHECK(jpvt[j] >= 0 && jpvt[j] < n);
      if (jpvt[j] >= 0 && jpvt[j] < n) seen[jpvt[j]]++;
    }
    for (j = 0; j < n; ++j) CHECK(seen[j] == 1);
    for (j = 1; j < k; ++j)
      CHECK_LE(fabs(F[j + (size_t)j * m]), fabs(F[j - 1 + (size_t)(j - 1) * m]) * (1 + 1e-14));
    /* rank revealed: R(r,r) drops by more than 1e10 relative to R(r-1,r-1) */
    CHECK_LE(fabs(F[r + (size_t)r * m]), 1e-10 * fabs(F[r - 1 + (size_t)(r - 1) * m]));
    CHECK(fabs(F[r - 1 + (size_t)(r - 1) * m]) > 1e-6 * fabs(F[0]));
    /* A P = Q R */
    for (j = 0; j < n; ++j)
      for (i = 0; i < k; ++i) R[i + (size_t)j * k] = i <= j ? F[i + (size_t)j * m] : 0.0;
    memcpy(Q, F, sizeof(double) * m * k);
    phgmg_qr_form_q(m, k, Q, m, tau, work);
    CHECK_LE(tl_orth_err(m, k, Q, m), 10.0 * n * EPS);
    tl_mul(0, 0, m, n, k, Q, m, R, k, AP, m);
    for (j = 0; j < n; ++j)
      for (i = 0; i < m; ++i) AP[i + (size_t)j * m] -= A[i + (size_t)jpvt[j] * m];
    CHECK_LE(tl_norm1(m, n, AP, m), 10.0 * m * EPS * anorm);
    free(X); free(Y); free(A); free(F); free(tau); free(work); free(Q); free(R); free(AP);
    free(jpvt); free(seen);
  }
}

/* The blocked pivoted QR used by the SVD (private): A P = Q R across several
   32-column blocks, non-increasing |R(k,k)|, and early stop at the rank. */
TEST(test_qrcp_blocked) {
  const int m = 130, n = 110, r = 70;
  double *X = tl_new((size_t)m * r), *Y = tl_new((size_t)n * r), *A = tl_new((size_t)m * n);
  double *F = tl_new((size_t)m * n), *tau = tl_new((size_t)n), *vn = tl_new(2 * (size_t)n);
  double *Fw = tl_new((size_t)(n + 1) * PHGMG__QRCP_NB), *Q = tl_new((size_t)m * n);
  double *R = tl_new((size_t)n * n), *AP = tl_new((size_t)m * n), anorm;
  int *jpvt = (int *)calloc((size_t)n, sizeof(int)), *mark = (int *)calloc((size_t)n, sizeof(int));
  int pass, i, j, rank;
  tl_rand(m, r, X, m);
  tl_rand(n, r, Y, n);
  tl_mul(0, 1, m, n, r, X, m, Y, n, A, m);
  for (j = 0; j < n; ++j) /* columns over 6 decades: pivoting and norm downdating matter */
    for (i = 0; i < m; ++i) A[i + (size_t)j * m] *= pow(10.0, -6.0 * (double)((j * 37) % n) / n);
  anorm = phgmg_normf(m, n, A, m);
  for (pass = 0; pass < 2; ++pass) {
    int k;
    memcpy(F, A, sizeof(double) * m * n);
    phgmg__qrcp_blocked(m, n, F, m, tau, jpvt, vn, Fw, Fw + (size_t)n * PHGMG__QRCP_NB, mark,
                        pass ? PHGMG__EPS * anorm : -1.0, &rank);
    CHECK(rank == (pass ? r : n));
    k = rank;
    for (j = 1; j < k; ++j)
      CHECK_LE(fabs(F[j + (size_t)j * m]), fabs(F[j - 1 + (size_t)(j - 1) * m]) * (1 + 1e-13));
    if (!pass) CHECK_LE(fabs(F[r + (size_t)r * m]), 1e-12 * fabs(F[0]));
    for (j = 0; j < n; ++j)
      for (i = 0; i < k; ++i) R[i + (size_t)j * k] = i <= j ? F[i + (size_t)j * m] : 0.0;
    memcpy(Q, F, sizeof(double) * m * k);
    phgmg_qr_form_q(m, k, Q, m, tau, NULL);
    CHECK_LE(tl_orth_err(m, k, Q, m), 10.0 * n * EPS);
    tl_mul(0, 0, m, n, k, Q, m, R, k, AP, m);
    for (j = 0; j < n; ++j)
      for (i = 0; i < m; ++i) AP[i + (size_t)j * m] -= A[i + (size_t)jpvt[j] * m];
    CHECK_LE(phgmg_normf(m, n, AP, m), 10.0 * m * EPS * anorm);
  }
  free(X); free(Y); free(A); free(F); free(tau); free(vn); free(Fw); free(Q); free(R); free(AP);
  free(jpvt); free(mark);
}

/* ---- least squares ----------------------------------------------------------------- */
/* Solve the SPD system M x = y (n x n) by Cholesky, independent of the library. */
static void tl_chol_solve(int n, double *M, int nrhs, double *Y) {
  int i, j, k, c;
  for (j = 0; j < n; ++j) {
    double s = M[j + j * n];
    for (k = 0; k < j; ++k) s -= M[j + k * n] * M[j + k * n];
    s = sqrt(s);
    M[j + j * n] = s;
    for (i = j + 1; i < n; ++i) {
      double t = M[i + j * n];
      for (k = 0; k < j; ++k) t -= M[i + k * n] * M[j + k * n];
      M[i + j * n] = t / s;
    }
  }
  for (c = 0; c < nrhs; ++c) {
    double *y = Y + c * n;
    for (i = 0; i < n; ++i) {
      for (k = 0; k < i; ++k) y[i] -= M[i + k * n] * y[k];
      y[i] /= M[i + i * n];
    }
    for (i = n - 1; i >= 0; --i) {
      for (k = i + 1; k < n; ++k) y[i] -= M[k + i * n] * y[k];
      y[i] /= M[i + i * n];
    }
  }
}

TEST(test_lstsq) {
  const int m = 50, n = 12, nrhs = 2;
  const double lambdas[] = {0.0, 1e-3, 0.7, 25.0};
  double A[50 * 12], B[50 * 2], X[14 * 2], M[12 * 12], Y[12 * 2], X0[14 * 2];
  int l, i, j;
  tl_rand(m, n, A, m);
  tl_rand(m, nrhs, B, m);
  for (l = 0; l < 4; ++l) {
    double lam = lambdas[l], err = 0.0, xn = 0.0;
    tl_mul(1, 0, n, n, m, A, m, A, m, M, n);
    for (i = 0; i < n; ++i) M[i + i * n] += lam;
    tl_mul(1, 0, n, nrhs, m, A, m, B, m, Y, n);
    tl_chol_solve(n, M, nrhs, Y);
    for (i = 0; i < 28; ++i) X[i] = X0[i] = -7.0;
    CHECK_RC(phgmg_lstsq(m, n, nrhs, A, m, B, m, lam, X, n + 2, NULL), PHGMG_OK);
    for (j = 0; j < nrhs; ++j) {
      for (i = 0; i < n; ++i) {
        err = fmax(err, fabs(X[i + j * (n + 2)] - Y[i + j * n]));
        xn = fmax(xn, fabs(Y[i + j * n]));
      }
      CHECK(X[n + j * (n + 2)] == -7.0 && X[n + 1 + j * (n + 2)] == -7.0);
    }
    CHECK_LE(err, 1e-12 * xn);
  }
  {
    /* ridge on a wide problem: closed form via the normal equations */
    double Aw[6 * 10], Bw[6], Xw[10], Mw[100], Yw[10], err = 0.0;
    tl_rand(6, 10, Aw, 6);
    tl_rand(6, 1, Bw, 6);
    tl_mul(1, 0, 10, 10, 6, Aw, 6, Aw, 6, Mw, 10);
    for (i = 0; i < 10; ++i) Mw[i + i * 10] += 0.3;
    tl_mul(1, 0, 10, 1, 6, Aw, 6, Bw, 6, Yw, 10);
    tl_chol_solve(10, Mw, 1, Yw);
    CHECK_RC(phgmg_lstsq(6, 10, 1, Aw, 6, Bw, 6, 0.3, Xw, 10, NULL), PHGMG_OK);
    for (i = 0; i < 10; ++i) err = fmax(err, fabs(Xw[i] - Yw[i]));
    CHECK_LE(err, 1e-12);
    CHECK_RC(phgmg_lstsq(6, 10, 1, Aw, 6, Bw, 6, 0.0, Xw, 10, NULL), PHGMG_ERR_RANK);
  }
  /* rank deficient: a repeated column */
  memcpy(A + 3 * m, A + 5 * m, sizeof(double) * m);
  for (i = 0; i < 28; ++i) X[i] = X0[i];
  CHECK_RC(phgmg_lstsq(m, n, nrhs, A, m, B, m, 0.0, X, n + 2, NULL), PHGMG_ERR_RANK);
  CHECK(X[0] == -7.0);
  CHECK_RC(phgmg_lstsq(m, n, nrhs, A, m, B, m, 1e-2, X, n + 2, NULL), PHGMG_OK);
  CHECK_RC(phgmg_lstsq(m, n, nrhs, A, m, B, m, -1.0, X, n + 2, NULL), PHGMG_ERR_INVALID_ARG);
  B[7] = NAN;
  CHECK_RC(phgmg_lstsq(m, n, nrhs, A, m, B, m, 1.0, X, n + 2, NULL), PHGMG_ERR_NANINF);
}

/* ---- SVD ------------------------------------------------------------------------- */
/* A = Uo diag(s) Vo^T with random orthonormal Uo, Vo and the given s (r values). */
static void svd_case(int m, int n, int r, const double *s, int kmax) {
  double *Uo = tl_new((size_t)m * r), *Vo = tl_new((size_t)n * r), *A = tl_new((size_t)m * n);
  double *US = tl_new((size_t)m * r), *S = tl_new((size_t)kmax + 1), *U = tl_new((size_t)(m + 1) * kmax);
  double *V = tl_new((size_t)n * kmax), *AV = tl_new((size_t)m * kmax);
  double err = 0.0;
  int i, j, k = -1, rank = -1, kexp = PHGMG__MIN(kmax, r);
  tl_orthonormal(m, r, Uo);
  tl_orthonormal(n, r, Vo);
  for (j = 0; j < r; ++j)
    for (i = 0; i < m; ++i) US[i + (size_t)j * m] = Uo[i + (size_t)j * m] * s[j];
  tl_mul(0, 1, m, n, r, US, m, Vo, n, A, m);
  CHECK_RC(phgmg_svd(m, n, A, m, kmax, S, U, m + 1, V, n, &k, &rank, NULL), PHGMG_OK);
  CHECK(rank == r);
  CHECK(k == kexp);
  if (k != kexp) goto done;
  for (j = 0; j < k; ++j) err = fmax(err, fabs(S[j] - s[j]));
  CHECK_LE(err, 1e-12 * s[0]);
  CHECK_LE(tl_orth_err(m, k, U, m + 1), 1e-13);
  CHECK_LE(tl_orth_err(n, k, V, n), 1e-13);
  /* ||A V - U S||_max relative to s_1 */
  tl_mul(0, 0, m, k, n, A, m, V, n, AV, m);
  err = 0.0;
  for (j = 0; j < k; ++j)
    for (i = 0; i < m; ++i) err = fmax(err, fabs(AV[i + (size_t)j * m] - U[i + (size_t)j * (m + 1)] * S[j]));
  CHECK_LE(err, 1e-13 * s[0]);
done:
  free(Uo); free(Vo); free(A); free(US); free(S); free(U); free(V); free(AV);
}

TEST(test_svd_known) {
  double s[60];
  int i;
  /* full rank 80 x 60, singular values 1 .. 1e-10 (geometric) */
  for (i = 0; i < 60; ++i) s[i] = pow(10.0, -10.0 * i / 59.0);
  svd_case(80, 60, 60, s, 60);
  /* square, with repeated singular values */
  for (i = 0; i < 30; ++i) s[i] = i < 10 ? 2.0 : (i < 20 ? 1.0 : 0.5);
  svd_case(30, 30, 30, s, 30);
  /* wide 300 x 301, rank 40; and tall 301 x 300 rank 40 truncated to 25 */
  for (i = 0; i < 40; ++i) s[i] = 3.0 * pow(10.0, -9.0 * i / 39.0);
  svd_case(300, 301, 40, s, 40);
  svd_case(301, 300, 40, s, 25);
  /* wide and short */
  for (i = 0; i < 20; ++i) s[i] = 1.0 / (1.0 + i);
  svd_case(20, 150, 20, s, 30);
  /* rank one */
  s[0] = 5.0;
  svd_case(17, 9, 1, s, 4);
}

TEST(test_svd_edge) {
  double Z[12] = {0}, S[3], U[12], V[9];
  int k = -1, rank = -1;
  CHECK_RC(phgmg_svd(4, 3, Z, 4, 3, S, U, 4, V, 3, &k, &rank, NULL), PHGMG_OK);
  CHECK(k == 0 && rank == 0);
  Z[5] = NAN;
  CHECK_RC(phgmg_svd(4, 3, Z, 4, 3, S, U, 4, V, 3, &k, &rank, NULL), PHGMG_ERR_NANINF);
  {
    /* closed form: diag(3, -4) -> S = (4, 3), V may be NULL */
    double D[4] = {3, 0, 0, -4};
    CHECK_RC(phgmg_svd(2, 2, D, 2, 2, S, U, 2, NULL, 0, &k, NULL, NULL), PHGMG_OK);
    CHECK(k == 2);
    CHECK_LE(fabs(S[0] - 4.0), 4 * EPS);
    CHECK_LE(fabs(S[1] - 3.0), 4 * EPS);
    CHECK_LE(fabs(fabs(U[1]) - 1.0), 4 * EPS); /* u1 = +-e2 */
  }
  {
    /* a column and a row: sigma = ||a||, the singular vector is a / ||a|| */
    double a[5] = {3, -4, 12, 0, 84}, Uc[5], Vc[5], nrm = 85.0; /* 9+16+144+7056 = 85^2 */
    int i;
    CHECK_RC(phgmg_svd(5, 1, a, 5, 1, S, Uc, 5, Vc, 1, &k, &rank, NULL), PHGMG_OK);
    CHECK(k == 1 && rank == 1);
    CHECK_LE(fabs(S[0] - nrm), 4 * EPS * nrm);
    for (i = 0; i < 5; ++i) CHECK_LE(fabs(Uc[i] * Vc[0] - a[i] / nrm), 4 * EPS);
    CHECK_RC(phgmg_svd(1, 5, a, 1, 3, S, Uc, 1, Vc, 5, &k, &rank, NULL), PHGMG_OK);
    CHECK(k == 1 && rank == 1);
    CHECK_LE(fabs(S[0] - nrm), 4 * EPS * nrm);
    for (i = 0; i < 5; ++i) CHECK_LE(fabs(Vc[i] * Uc[0] - a[i] / nrm), 4 * EPS);
    /* kmax = 0: rank only */
    CHECK_RC(phgmg_svd(1, 5, a, 1, 0, NULL, NULL, 1, NULL, 5, &k, &rank, NULL), PHGMG_OK);
    CHECK(k == 0 && rank == 1);
  }
}

/* ---- symmetric eigenproblem ---------------------------------------------------------- */
TEST(test_sym_eig) {
  /* n <= 24: cyclic Jacobi; larger: tridiagonalization + implicit QL */
  const int ns[] = {1, 2, 9, 24, 25, 40, 150};
  int s;
  for (s = 0; s < 7; ++s) {
    int n = ns[s], i, j, ld = n + 1;
    double *Q = tl_new((size_t)n * n), *QL = tl_new((size_t)n * n), *A = tl_new((size_t)ld * n);
    double *A0 = tl_new((size_t)n * n), *lam = tl_new((size_t)n), *w = tl_new((size_t)n);
    double *V = tl_new((size_t)n * n), *AV = tl_new((size_t)n * n), err = 0.0, amax = 0.0;
    tl_orthonormal(n, n, Q);
    for (i = 0; i < n; ++i) { /* known spectrum, ascending, with a repeated pair and 0 */
      lam[i] = -3.0 + 6.0 * i / (n > 1 ? n - 1 : 1);
      if (i == 1 && n > 3) lam[i] = lam[0];
      if (i == n / 2 && n > 3) lam[i] = 0.0;
      amax = fmax(amax, fabs(lam[i]));
    }
    for (j = 0; j < n; ++j)
      for (i = 0; i < n; ++i) QL[i + (size_t)j * n] = Q[i + (size_t)j * n] * lam[j];
    tl_mul(0, 1, n, n, n, QL, n, Q, n, A0, n);
    for (j = 0; j < n; ++j) /* exactly symmetric */
      for (i = 0; i < j; ++i) A0[j + (size_t)i * n] = A0[i + (size_t)j * n];
    for (j = 0; j < n; ++j) memcpy(A + (size_t)j * ld, A0 + (size_t)j * n, sizeof(double) * n);
    CHECK_RC(phgmg_sym_eig(n, A, ld, w, V, n), PHGMG_OK);
    for (i = 0; i < n; ++i) {
      err = fmax(err, fabs(w[i] - lam[i]));
      if (i) CHECK(w[i] >= w[i - 1]);
    }
    CHECK_LE(err, 10.0 * n * EPS * amax);
    CHECK_LE(tl_orth_err(n, n, V, n), 10.0 * n * EPS);
    tl_mul(0, 0, n, n, n, A0, n, V, n, AV, n);
    err = 0.0;
    for (j = 0; j < n; ++j)
      for (i = 0; i < n; ++i) err = fmax(err, fabs(AV[i + (size_t)j * n] - V[i + (size_t)j * n] * w[j]));
    CHECK_LE(err, 10.0 * n * EPS * amax);
    /* eigenvalues only */
    for (j = 0; j < n; ++j) memcpy(A + (size_t)j * ld, A0 + (size_t)j * n, sizeof(double) * n);
    CHECK_RC(phgmg_sym_eig(n, A, ld, w + 0, NULL, 0), PHGMG_OK);
    err = 0.0;
    for (i = 0; i < n; ++i) err = fmax(err, fabs(w[i] - lam[i]));
    CHECK_LE(err, 10.0 * n * EPS * amax);
    free(Q); free(QL); free(A); free(A0); free(lam); free(w); free(V); free(AV);
  }
  {
    /* diagonal (every Householder step degenerate) with a zero block: the
       eigenvalues are the sorted diagonal, V a permutation */
    const int n = 30;
    double *A = tl_new((size_t)n * n), *V = tl_new((size_t)n * n), w[30];
    int i, j;
    for (i = 0; i < n; ++i) A[i + i * n] = (i % 3 == 0) ? 0.0 : (double)((i * 7) % n) - 10.0;
    CHECK_RC(phgmg_sym_eig(n, A, n, w, V, n), PHGMG_OK);
    for (i = 1; i < n; ++i) CHECK(w[i] >= w[i - 1]);
    for (j = 0; j < n; ++j) {
      int nz = 0, row = -1;
      for (i = 0; i < n; ++i)
        if (V[i + j * n] != 0.0) { nz++; row = i; }
      CHECK(nz == 1 && fabs(V[row + j * n]) == 1.0);
      if (nz == 1) CHECK(w[j] == ((row % 3 == 0) ? 0.0 : (double)((row * 7) % n) - 10.0));
    }
    free(A); free(V);
  }
  {
    /* closed form: [[2,1],[1,2]] has eigenvalues 1, 3 */
    double A[4] = {2, 1, 1, 2}, w[2], V[4];
    CHECK_RC(phgmg_sym_eig(2, A, 2, w, V, 2), PHGMG_OK);
    CHECK_LE(fabs(w[0] - 1.0), 4 * EPS);
    CHECK_LE(fabs(w[1] - 3.0), 4 * EPS);
    CHECK_LE(fabs(fabs(V[0]) - sqrt(0.5)), 4 * EPS);
    CHECK_LE(fabs(V[0] + V[1]), 4 * EPS); /* (1,-1)/sqrt2 */
    A[2] = INFINITY;
    CHECK_RC(phgmg_sym_eig(2, A, 2, w, V, 2), PHGMG_ERR_NANINF);
  }
}

/* ---- allocator: failures return NOMEM and leak nothing -------------------------------- */
typedef struct { int live, calls, fail_at; } tl_alloc_state;
static void *tl_alloc(size_t sz, void *user) {
  tl_alloc_state *st = (tl_alloc_state *)user;
  if (st->calls++ == st->fail_at) return NULL;
  st->live++;
  return malloc(sz);
}
static void tl_free(void *p, void *user) {
  tl_alloc_state *st = (tl_alloc_state *)user;
  if (p) st->live--;
  free(p);
}

TEST(test_alloc_failures) {
  double A[30 * 20], B[30], X[20], S[20], U[30 * 20], V[20 * 20];
  int f, k, r;
  tl_rand(30, 20, A, 30);
  tl_rand(30, 1, B, 30);
  for (f = 0; f < 4; ++f) {
    tl_alloc_state st = {0, 0, 0};
    phgmg_allocator al;
    phgmg_result rc;
    st.fail_at = f;
    al.alloc = tl_alloc; al.free = tl_free; al.user = &st;
    rc = phgmg_svd(30, 20, A, 30, 20, S, U, 30, V, 20, &k, &r, &al);
    CHECK(rc == PHGMG_ERR_NOMEM || (rc == PHGMG_OK && f >= st.calls));
    CHECK(st.live == 0);
    st.calls = 0;
    rc = phgmg_lstsq(30, 20, 1, A, 30, B, 30, f * 0.5, X, 20, &al);
    CHECK(rc == PHGMG_ERR_NOMEM || (rc == PHGMG_OK && f >= st.calls));
    CHECK(st.live == 0);
  }
}

SUITE(linalg) {
  RUN(test_gemm_vs_naive);
  RUN(test_gemv_vs_naive);
  RUN(test_norms);
  RUN(test_lu_random);
  RUN(test_lu_graded);
  RUN(test_lu_big);
  RUN(test_lu_singular_naninf);
  RUN(test_lu_rcond);
  RUN(test_zlu);
  RUN(test_qr);
  RUN(test_qr_subnormal);
  RUN(test_qrcp_rank);
  RUN(test_qrcp_blocked);
  RUN(test_lstsq);
  RUN(test_svd_known);
  RUN(test_svd_edge);
  RUN(test_sym_eig);
  RUN(test_alloc_failures);
}
