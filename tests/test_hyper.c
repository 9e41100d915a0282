/* Hyper-reduction kernels: phgmg_nnls, phgmg_deim_select (greedy
   DEIM), phgmg_ecsw. Expected values come from independent computations in
   this file: brute force over all active sets (NNLS), the KKT conditions, a
   plain greedy DEIM written from its definition, and the quadrature's
   residual and reduced Hamiltonian recomputed term by term. */
#include <stdlib.h>
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"

/* Solve the s x s system M y = v by Gaussian elimination with partial
   pivoting (M, v destroyed). Returns 0 if a pivot is tiny. */
static int hy_gauss(int s, double *M, double *v) {
  int i, j, k;
  for (k = 0; k < s; ++k) {
    int p = k;
    for (i = k + 1; i < s; ++i) if (fabs(M[i + k * s]) > fabs(M[p + k * s])) p = i;
    if (fabs(M[p + k * s]) < 1e-300) return 0;
    if (p != k) {
      double t;
      for (j = 0; j < s; ++j) { t = M[k + j * s]; M[k + j * s] = M[p + j * s]; M[p + j * s] = t; }
      t = v[k]; v[k] = v[p]; v[p] = t;
    }
    for (i = k + 1; i < s; ++i) {
      const double f = M[i + k * s] / M[k + k * s];
      for (j = k; j < s; ++j) M[i + j * s] -= f * M[k + j * s];
      v[i] -= f * v[k];
    }
  }
  for (k = s - 1; k >= 0; --k) {
    for (j = k + 1; j < s; ++j) v[k] -= M[k + j * s] * v[j];
    v[k] /= M[k + k * s];
  }
  return 1;
}

static double hy_resid(int m, int n, const double *A, const double *b, const double *x) {
  double s = 0.0;
  int i, j;
  for (i = 0; i < m; ++i) {
    double r = -b[i];
    for (j = 0; j < n; ++j) r += A[i + j * m] * x[j];
    s += r * r;
  }
  return sqrt(s);
}

/* Brute force NNLS for n <= 8, m >= n: every support S, least squares on S by
   the normal equations; the optimum is the best S whose solution is > 0. */
static double hy_nnls_brute(int m, int n, const double *A, const double *b, double *xbest) {
  double best, M[64], v[8], x[8];
  int S, i, j, k, idx[8];
  for (j = 0; j < n; ++j) xbest[j] = 0.0;
  best = hy_resid(m, n, A, b, xbest);
  for (S = 1; S < (1 << n); ++S) {
    int s = 0, ok = 1;
    for (j = 0; j < n; ++j) if (S & (1 << j)) idx[s++] = j;
    for (i = 0; i < s; ++i) {
      v[i] = 0.0;
      for (k = 0; k < m; ++k) v[i] += A[k + idx[i] * m] * b[k];
      for (j = 0; j < s; ++j) {
        double t = 0.0;
        for (k = 0; k < m; ++k) t += A[k + idx[i] * m] * A[k + idx[j] * m];
        M[i + j * s] = t;
      }
    }
    if (!hy_gauss(s, M, v)) continue;
    for (j = 0; j < n; ++j) x[j] = 0.0;
    for (i = 0; i < s; ++i) { if (!(v[i] > 0.0)) ok = 0; x[idx[i]] = v[i]; }
    if (ok) {
      const double r = hy_resid(m, n, A, b, x);
      if (r < best) { best = r; memcpy(xbest, x, sizeof(double) * (size_t)n); }
    }
  }
  return best;
}

TEST(test_nnls_bruteforce) {
  static const int dims[][2] = {{3, 2}, {8, 5}, {12, 8}, {8, 8}, {20, 7}, {30, 8}};
  int c, trial;
  for (c = 0; c < 6; ++c)
    for (trial = 0; trial < 6; ++trial) {
      const int m = dims[c][0], n = dims[c][1];
      double A[240], b[30], x[8], xb[8], res = -1.0, rb, bn = 0.0, anorm;
      int i, nz = -1, nzb = 0;
      for (i = 0; i < m * n; ++i) A[i] = th_rand();
      for (i = 0; i < m; ++i) { b[i] = th_rand(); bn += b[i] * b[i]; }
      bn = sqrt(bn);
      anorm = phgmg_normf(m, n, A, m);
      CHECK_RC(phgmg_nnls(m, n, A, m, b, 0.0, 0, x, &res, &nz, NULL), PHGMG_OK);
      rb = hy_nnls_brute(m, n, A, b, xb);
      CHECK_LE(fabs(res - rb), 1e-12 * bn);
      CHECK_LE(fabs(res - hy_resid(m, n, A, b, x)), 1e-12 * bn);
      for (i = 0; i < n; ++i) {
        CHECK(x[i] >= 0.0);
        CHECK_LE(fabs(x[i] - xb[i]), 1e-10 * bn / anorm * 1e2); /* full column rank: unique */
        if (xb[i] > 0.0) ++nzb;
      }
      CHECK(nz == nzb);
    }
}

/* KKT: x >= 0, g = A^T (b - A x) <= eps where x = 0 and |g| <= eps where x > 0. */
static void hy_check_kkt(int m, int n, const double *A, const double *b, const double *x, double eps) {
  int i, j, bad = 0;
  for (j = 0; j < n; ++j) {
    double g = 0.0;
    for (i = 0; i < m; ++i) {
      double r = b[i];
      int k;
      for (k = 0; k < n; ++k) r -= A[i + k * m] * x[k];
      g += A[i + j * m] * r;
    }
    if (x[j] < 0.0) ++bad;
    if (x[j] > 0.0 && fabs(g) > eps) ++bad;
    if (x[j] == 0.0 && g > eps) ++bad;
  }
  CHECK(bad == 0);
}

TEST(test_nnls_kkt) {
  static const int dims[][2] = {{60, 40}, {30, 50}, {200, 25}, {40, 40}};
  int c;
  for (c = 0; c < 4; ++c) {
    const int m = dims[c][0], n = dims[c][1];
    double *A = (double *)malloc(sizeof(double) * (size_t)(m * n + m + 2 * n + n * n + n));
    double *b = A + m * n, *x = b + m, *xg = x + n, *G = xg + n, *cg = G + n * n, res = 0.0, res2 = 0.0;
    double bn, an, eps;
    int i, nz = 0, nneg;
    phgmg__nnls_prob pb;
    for (i = 0; i < m * n; ++i) A[i] = th_rand();
    for (i = 0; i < m; ++i) b[i] = th_rand() + 0.3;
    bn = phgmg_normf(m, 1, b, m);
    an = phgmg_normf(m, n, A, m);
    eps = 1e-11 * an * bn;
    CHECK_RC(phgmg_nnls(m, n, A, m, b, 0.0, 0, x, &res, &nz, NULL), PHGMG_OK);
    hy_check_kkt(m, n, A, b, x, eps);
    for (i = 0, nneg = 0; i < n; ++i) nneg += x[i] > 0.0;
    CHECK(nneg == nz);
    CHECK(nz > 0 && nz < n); /* a genuinely constrained problem */
    CHECK_LE(fabs(res - hy_resid(m, n, A, b, x)), 1e-12 * bn);
    /* the Gram form of the same core reaches the same optimum */
    phgmg_gemm('T', 'N', n, n, m, 1.0, A, m, A, m, 0.0, G, n);
    phgmg_gemv('T', m, n, 1.0, A, m, b, 0.0, cg);
    memset(&pb, 0, sizeof pb);
    pb.n = n; pb.G = G; pb.ldg = n; pb.c = cg; pb.dd = bn * bn; pb.wtol = 1e-13 * an * bn;
    CHECK_RC(phgmg__nnls_core(&pb, 0.0, 3 * n, 0, xg, &res2, NULL), PHGMG_OK);
    hy_check_kkt(m, n, A, b, xg, 1e-9 * an * bn);
    { /* warm start from every other term of the optimum's support (the
         screened ECSW's rounds): the same optimum (KKT) */
      double *xw = (double *)malloc(sizeof(double) * (size_t)n), r2w;
      int cnt = 0;
      for (i = 0; i < n; ++i) xw[i] = (x[i] > 0.0 && (cnt++ % 2 == 0)) ? x[i] : 0.0;
      CHECK_RC(phgmg__nnls_core(&pb, 0.0, 3 * n, 1, xw, &r2w, NULL), PHGMG_OK);
      hy_check_kkt(m, n, A, b, xw, 1e-9 * an * bn);
      CHECK_LE(fabs(hy_resid(m, n, A, b, xw) - res), 1e-8 * bn);
      free(xw);
    }
    if (m >= n) /* unique optimum */
      for (i = 0; i < n; ++i) CHECK_LE(fabs(xg[i] - x[i]), 1e-7);
    CHECK_LE(fabs(hy_resid(m, n, A, b, xg) - res), 1e-8 * bn);
    free(A);
  }
}

/* Rank-deficient A (every third column twice the one before it, one zero
   column), over- and underdetermined: still the KKT point. */
TEST(test_nnls_rank_deficient) {
  static const int dims[][2] = {{40, 30}, {25, 40}, {60, 12}};
  int c, i, j;
  for (c = 0; c < 3; ++c) {
    const int m = dims[c][0], n = dims[c][1];
    double *A = (double *)malloc(sizeof(double) * (size_t)(m * n + m + n)), *b = A + m * n, *x = b + m, res = 0.0;
    int nz = 0;
    for (i = 0; i < m * n; ++i) A[i] = th_rand();
    for (j = 1; j < n; j += 3)
      for (i = 0; i < m; ++i) A[i + j * m] = 2.0 * A[i + (j - 1) * m];
    for (i = 0; i < m; ++i) { A[i + 3 * m] = 0.0; b[i] = th_rand() + 0.2; }
    CHECK_RC(phgmg_nnls(m, n, A, m, b, 0.0, 0, x, &res, &nz, NULL), PHGMG_OK);
    hy_check_kkt(m, n, A, b, x, 1e-11 * phgmg_normf(m, n, A, m) * phgmg_normf(m, 1, b, m));
    CHECK(x[3] == 0.0);
    free(A);
  }
}

TEST(test_nnls_stop_and_errors) {
  const int m = 50, n = 30;
  double A[1500], b[50], x[30], res = 0.0, bn, nanv = 0.0;
  int i, nz = 0, nzopt = 0;
  for (i = 0; i < m * n; ++i) A[i] = th_rand();
  for (i = 0; i < n; ++i) x[i] = 1.0 + th_rand(); /* b = A x+ + small noise: optimum near x+ > 0 */
  phgmg_gemv('N', m, n, 1.0, A, m, x, 0.0, b);
  for (i = 0; i < m; ++i) b[i] += 0.01 * th_rand();
  bn = phgmg_normf(m, 1, b, m);
  CHECK_RC(phgmg_nnls(m, n, A, m, b, 0.0, 0, x, &res, &nzopt, NULL), PHGMG_OK);
  CHECK_LE(res, 0.01 * bn);
  CHECK_RC(phgmg_nnls(m, n, A, m, b, 0.3, 0, x, &res, &nz, NULL), PHGMG_OK);
  CHECK_LE(res, 0.3 * bn);
  CHECK_LE(fabs(res - hy_resid(m, n, A, b, x)), 1e-12 * bn);
  CHECK(nz < nzopt);
  CHECK_RC(phgmg_nnls(m, n, A, m, b, 0.0, 2, x, &res, &nz, NULL), PHGMG_ERR_NOT_CONVERGED);
  for (i = 0; i < n; ++i) CHECK(x[i] >= 0.0);
  CHECK(nz <= 2);
  CHECK_LE(fabs(res - hy_resid(m, n, A, b, x)), 1e-12 * bn);
  CHECK_RC(phgmg_nnls(m, n, NULL, m, b, 0.0, 0, x, NULL, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_nnls(m, n, A, m, b, 0.0, 0, NULL, NULL, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_nnls(0, n, A, m, b, 0.0, 0, x, NULL, NULL, NULL), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_nnls(m, n, A, m - 1, b, 0.0, 0, x, NULL, NULL, NULL), PHGMG_ERR_SIZE);
  b[3] = nanv / nanv;
  CHECK_RC(phgmg_nnls(m, n, A, m, b, 0.0, 0, x, NULL, NULL, NULL), PHGMG_ERR_NANINF);
  /* b = 0: x = 0 */
  for (i = 0; i < m; ++i) b[i] = 0.0;
  CHECK_RC(phgmg_nnls(m, n, A, m, b, 0.0, 0, x, &res, &nz, NULL), PHGMG_OK);
  CHECK(nz == 0 && res == 0.0);
}

/* Greedy DEIM from its definition, on U (n x k): returns 0 on a singular step. */
static int hy_greedy(int n, int k, const double *U, int *pts) {
  double M[400], c[20];
  int l, i, j;
  for (l = 0; l < k; ++l) {
    double best = -1.0;
    for (i = 0; i < l; ++i) {
      c[i] = U[pts[i] + l * n];
      for (j = 0; j < l; ++j) M[i + j * l] = U[pts[i] + j * n];
    }
    if (l > 0 && !hy_gauss(l, M, c)) return 0;
    for (i = 0; i < n; ++i) {
      double r = U[i + l * n];
      for (j = 0; j < l; ++j) r -= U[i + j * n] * c[j];
      if (fabs(r) > best) { best = fabs(r); pts[l] = i; }
    }
  }
  return 1;
}

TEST(test_deim_greedy) {
  enum { NT = 80, NS = 40, RK = 9 };
  static double F[NT * NS], A[NT * RK], B[RK * NS], U[NT * RK], S[RK], sw[NT];
  int i, j, k, meth, pts[NT], ref[RK], pq[NT], nd = 0, nq = 0, neg = 0, kk = 0, rank = 0;
  double w[NT], wq[NT], sr = -1.0;
  for (i = 0; i < NT * RK; ++i) A[i] = th_rand();
  for (i = 0; i < RK * NS; ++i) B[i] = th_rand() * pow(0.5, (double)(i % RK));
  phgmg_gemm('N', 'N', NT, NS, RK, 1.0, A, NT, B, RK, 0.0, F, NT);
  for (i = 0; i < NT; ++i) sw[i] = 0.5 + 0.5 * (th_rand() + 1.0);
  /* the basis: leading left singular vectors (signs do not change the points) */
  CHECK_RC(phgmg_svd(NT, NS, F, NT, RK, S, U, NT, NULL, 1, &kk, &rank, NULL), PHGMG_OK);
  CHECK(kk == RK);
  CHECK(hy_greedy(NT, RK, U, ref));
  CHECK_RC(phgmg_deim_select(NT, NS, F, NT, sw, 1e-10, 0, PHGMG_DEIM_GREEDY, pts, w, &nd, &neg, &sr, NULL),
           PHGMG_OK);
  CHECK(nd == RK);
  for (i = 0; i < RK && nd == RK; ++i) CHECK(pts[i] == ref[i]);
  /* Q-DEIM through the selector is phgmg_deim itself */
  CHECK_RC(phgmg_deim(NT, NS, F, NT, sw, 1e-10, 0, pq, wq, &nq, NULL, NULL, NULL), PHGMG_OK);
  {
    int p2[NT], n2 = 0;
    double w2[NT];
    CHECK_RC(phgmg_deim_select(NT, NS, F, NT, sw, 1e-10, 0, PHGMG_DEIM_QDEIM, p2, w2, &n2, NULL, NULL, NULL),
             PHGMG_OK);
    CHECK(n2 == nq);
    for (i = 0; i < nq; ++i) CHECK(p2[i] == pq[i] && w2[i] == wq[i]);
  }
  /* both: the weights reproduce sum_k sw_k f_k on every snapshot (F in span U) */
  for (meth = 0; meth < 2; ++meth) {
    const int *p = meth ? pts : pq;
    const double *ww = meth ? w : wq;
    const int np = meth ? nd : nq;
    double e = 0.0, s = 0.0;
    for (j = 0; j < NS; ++j) {
      double full = 0.0, red = 0.0;
      for (k = 0; k < NT; ++k) full += sw[k] * F[k + j * NT];
      for (k = 0; k < np; ++k) red += ww[k] * F[p[k] + j * NT];
      e += (full - red) * (full - red);
      s += full * full;
    }
    CHECK_LE(sqrt(e / s), 1e-11);
  }
  CHECK_RC(phgmg_deim_select(NT, NS, F, NT, sw, 1e-10, 0, 2, pts, w, &nd, NULL, NULL, NULL),
           PHGMG_ERR_INVALID_ARG);
}

TEST(test_ecsw_exact_sparse) {
  enum { M = 200, N = 80, K = 10 };
  static double Gm[M * N], t[M], r[M];
  double w[N], wt[N], rel = -1.0, tn = 0.0, e = 0.0;
  int pts[N], nd = 0, i, j, supp[K];
  for (i = 0; i < M * N; ++i) Gm[i] = th_rand();
  for (j = 0; j < N; ++j) wt[j] = 0.0;
  for (i = 0; i < K; ++i) { supp[i] = 7 * i + 3; wt[supp[i]] = 0.5 + (double)i * 0.25; }
  phgmg_gemv('N', M, N, 1.0, Gm, M, wt, 0.0, t);
  CHECK_RC(phgmg_ecsw(N, M, Gm, M, t, 1e-9, pts, w, &nd, &rel, NULL), PHGMG_OK);
  CHECK(nd == K);
  for (i = 0; i < nd; ++i) {
    CHECK(w[i] > 0.0);
    if (i > 0) CHECK(pts[i] > pts[i - 1]);
  }
  for (i = 0; i < M; ++i) {
    r[i] = -t[i];
    for (j = 0; j < nd; ++j) r[i] += Gm[i + pts[j] * M] * w[j];
    e += r[i] * r[i];
    tn += t[i] * t[i];
  }
  CHECK_LE(sqrt(e / tn), 1e-9);
  CHECK_LE(fabs(sqrt(e / tn) - rel), 1e-12);
  for (i = 0; i < K && nd == K; ++i) { CHECK(pts[i] == supp[i]); CHECK_LE(fabs(w[i] - wt[supp[i]]), 1e-8); }
}

/* The separable convex example: N coordinates, term k: phi(l_k), l_k = x_k,
   phi(l) = l^2/2 + l^4/4; reduced basis V (N x R, orthonormal columns). */
static double hy_phi(double l) { return 0.5 * l * l + 0.25 * l * l * l * l; }
static double hy_dphi(double l) { return l + l * l * l; }
/* relative error of the quadrature's reduced gradient over the training
   snapshots Z (R x NSN), recomputed term by term */
static double hy_grad_err(int N, int R, int NSN, const double *V, const double *Z, int nd, const int *pts,
                          const double *w) {
  double e = 0.0, s = 0.0;
  int i, a, b, j, k;
  for (i = 0; i < NSN; ++i)
    for (a = 0; a < R; ++a) {
      double full = 0.0, red = 0.0;
      for (k = 0; k < N; ++k) {
        double l = 0.0;
        for (b = 0; b < R; ++b) l += V[k + b * N] * Z[b + i * R];
        full += hy_dphi(l) * V[k + a * N];
      }
      for (j = 0; j < nd; ++j) {
        double l = 0.0;
        for (b = 0; b < R; ++b) l += V[pts[j] + b * N] * Z[b + i * R];
        red += w[j] * hy_dphi(l) * V[pts[j] + a * N];
      }
      e += (full - red) * (full - red);
      s += full * full;
    }
  return sqrt(e / s);
}

/* H_r(z) = sum_j w_j phi((V z)_{pts_j}) */
static double hy_hred(int N, int R, const double *V, const double *z, int nd, const int *pts, const double *w) {
  double h = 0.0;
  int j, a;
  for (j = 0; j < nd; ++j) {
    double l = 0.0;
    for (a = 0; a < R; ++a) l += V[pts[j] + a * N] * z[a];
    h += w[j] * hy_phi(l);
  }
  (void)N;
  return h;
}

TEST(test_ecsw_convex_bounded) {
  enum { N = 300, R = 6, NSN = 50, M = NSN * R + NSN };
  static double V[N * R], tau[R], wk[R], Z[R * NSN], Gm[M * N], t[M];
  double w[N], rel = -1.0, e = 0.0, s = 0.0;
  int pts[N], nd = 0, i, j, k, a, ray;
  for (i = 0; i < N * R; ++i) V[i] = th_rand();
  CHECK_RC(phgmg_qr(N, R, V, N, tau), PHGMG_OK);
  phgmg_qr_form_q(N, R, V, N, tau, wk);
  for (i = 0; i < NSN; ++i) /* reduced snapshots: a smooth closed curve, |l| ~ 0.3..1 */
    for (a = 0; a < R; ++a) Z[a + i * R] = 8.0 * sin(0.13 * (double)(i + 1) * (double)(a + 1) + (double)a);
  for (k = 0; k < N; ++k)
    for (i = 0; i < NSN; ++i) {
      double l = 0.0;
      for (a = 0; a < R; ++a) l += V[k + a * N] * Z[a + i * R];
      for (a = 0; a < R; ++a) Gm[i * R + a + (size_t)k * M] = hy_dphi(l) * V[k + a * N]; /* gradient rows */
      Gm[NSN * R + i + (size_t)k * M] = hy_phi(l);                                      /* energy rows   */
    }
  for (i = 0; i < M; ++i) { t[i] = 0.0; for (k = 0; k < N; ++k) t[i] += Gm[i + (size_t)k * M]; }
  /* energy rows included: the whole residual meets tol */
  CHECK_RC(phgmg_ecsw(N, M, Gm, M, t, 1e-6, pts, w, &nd, &rel, NULL), PHGMG_OK);
  CHECK(nd > 0 && nd < N / 2);
  CHECK_LE(rel, 1e-6);
  for (j = 0; j < nd; ++j) CHECK(w[j] > 0.0);
  /* gradient rows only (the first NSN R rows): the checks below use these weights */
  CHECK_RC(phgmg_ecsw(N, NSN * R, Gm, M, t, 1e-6, pts, w, &nd, &rel, NULL), PHGMG_OK);
  CHECK(nd > 0 && nd < N / 2);
  CHECK_LE(rel, 1e-6);
  for (j = 0; j < nd; ++j) CHECK(w[j] > 0.0);
  /* the reduced gradient on the training snapshots, term by term */
  CHECK_LE(hy_grad_err(N, R, NSN, V, Z, nd, pts, w), 1e-6);
  /* the separable entry point (rows never formed) on the same data */
  {
    static double F[N * NSN];
    double w2[N], rel2 = -1.0;
    int p2[N], nd2 = 0;
    for (k = 0; k < N; ++k)
      for (i = 0; i < NSN; ++i) {
        double l = 0.0;
        for (a = 0; a < R; ++a) l += V[k + a * N] * Z[a + i * R];
        F[k + i * N] = hy_dphi(l);
      }
    CHECK_RC(phgmg_ecsw_separable(N, NSN, F, N, R, V, N, NULL, 1e-6, p2, w2, &nd2, &rel2, NULL), PHGMG_OK);
    CHECK(nd2 > 0 && nd2 < N / 2);
    for (j = 0; j < nd2; ++j) CHECK(w2[j] > 0.0 && (j == 0 || p2[j] > p2[j - 1]));
    CHECK_LE(rel2, 1e-6);
    CHECK_LE(fabs(hy_grad_err(N, R, NSN, V, Z, nd2, p2, w2) - rel2), 1e-9);
  }
  for (i = 0; i < NSN; ++i)
    for (a = 0; a < R; ++a) {
      double full = 0.0, red = 0.0;
      for (k = 0; k < N; ++k) {
        double l = 0.0;
        int b;
        for (b = 0; b < R; ++b) l += V[k + b * N] * Z[b + i * R];
        full += hy_dphi(l) * V[k + a * N];
      }
      for (j = 0; j < nd; ++j) {
        double l = 0.0;
        int b;
        for (b = 0; b < R; ++b) l += V[pts[j] + b * N] * Z[b + i * R];
        red += w[j] * hy_dphi(l) * V[pts[j] + a * N];
      }
      e += (full - red) * (full - red);
      s += full * full;
    }
  CHECK_LE(sqrt(e / s), 1e-6);
  /* rays far outside the data (|z| up to 1e4 x the snapshots): H_r >= 0 = H_r(0)
     and convex (midpoint inequality at every pair of neighbouring ray points) */
  for (ray = 0; ray < 20; ++ray) {
    double d[R], z0[R], zb[R], zm[R], h0, hb, hm, tt;
    for (a = 0; a < R; ++a) { d[a] = th_rand(); z0[a] = 20.0 * th_rand(); }
    for (tt = 1.0; tt < 2e5; tt *= 3.0) {
      for (a = 0; a < R; ++a) {
        zb[a] = z0[a] + tt * d[a];
        zm[a] = z0[a] + 2.0 * tt * d[a];
      }
      h0 = hy_hred(N, R, V, zb, nd, pts, w);
      for (a = 0; a < R; ++a) zb[a] = z0[a] + 3.0 * tt * d[a];
      hb = hy_hred(N, R, V, zb, nd, pts, w);
      hm = hy_hred(N, R, V, zm, nd, pts, w);
      CHECK(h0 >= 0.0 && hb >= 0.0 && hm >= 0.0);
      CHECK(hm <= 0.5 * (h0 + hb) * (1.0 + 1e-12));
      if (tt > 100.0) CHECK(hb >= h0); /* far out along the ray the quartic grows */
    }
  }
}

TEST(test_ecsw_errors) {
  double Gm[12] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}, t[4] = {1, 1, 1, 1}, w[3], rel = -1.0, nanv = 0.0;
  int pts[3], nd = -1;
  CHECK_RC(phgmg_ecsw(3, 4, NULL, 4, t, 0.0, pts, w, &nd, &rel, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_ecsw(3, 4, Gm, 4, t, 0.0, NULL, w, &nd, &rel, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_ecsw(3, 4, Gm, 3, t, 0.0, pts, w, &nd, &rel, NULL), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_ecsw(0, 4, Gm, 4, t, 0.0, pts, w, &nd, &rel, NULL), PHGMG_ERR_SIZE);
  t[2] = nanv / nanv;
  CHECK_RC(phgmg_ecsw(3, 4, Gm, 4, t, 0.0, pts, w, &nd, &rel, NULL), PHGMG_ERR_NANINF);
  t[0] = t[1] = t[2] = t[3] = 0.0;
  CHECK_RC(phgmg_ecsw(3, 4, Gm, 4, t, 0.0, pts, w, &nd, &rel, NULL), PHGMG_OK);
  CHECK(nd == 0 && rel == 0.0);
  /* target outside the cone of the columns: tol cannot be met */
  t[0] = -1.0; t[1] = -2.0; t[2] = -3.0; t[3] = -4.0;
  CHECK_RC(phgmg_ecsw(3, 4, Gm, 4, t, 0.0, pts, w, &nd, &rel, NULL), PHGMG_ERR_NOT_CONVERGED);
  CHECK(nd == 0 && fabs(rel - 1.0) < 1e-15);
}

/* An allocator that fails at call number `fail_at` and counts live blocks. */
typedef struct hy_fail { int calls, fail_at, live; } hy_fail;
static void *hy_alloc(size_t n, void *u) {
  hy_fail *f = (hy_fail *)u;
  void *p;
  if (f->calls++ == f->fail_at) return NULL;
  p = malloc(n);
  if (p) f->live++;
  return p;
}
static void hy_free(void *p, void *u) {
  if (p) { ((hy_fail *)u)->live--; free(p); }
}

TEST(test_hyper_nomem) {
  enum { M = 40, N = 20 };
  static double A[M * N], b[M], x[N], w[N], w2[M];
  int pts[N], pts2[M], nd, fn, k, i;
  for (i = 0; i < M * N; ++i) A[i] = th_rand();
  for (i = 0; i < M; ++i) b[i] = th_rand();
  for (fn = 0; fn < 4; ++fn)
    for (k = 0; k < 50; ++k) {
      hy_fail f = {0, 0, 0};
      phgmg_allocator al;
      phgmg_result rc;
      f.fail_at = k;
      al.alloc = hy_alloc; al.free = hy_free; al.user = &f;
      if (fn == 0) rc = phgmg_nnls(M, N, A, M, b, 0.0, 0, x, NULL, NULL, &al);
      else if (fn == 1) rc = phgmg_ecsw(N, M, A, M, b, 0.0, pts, w, &nd, NULL, &al);
      else if (fn == 2) rc = phgmg_deim_select(M, N, A, M, NULL, 1e-8, 0, PHGMG_DEIM_GREEDY, pts, w, &nd, NULL, NULL, &al);
      else rc = phgmg_ecsw_separable(M, N, A, M, 5, A, M, NULL, 0.0, pts2, w2, &nd, NULL, &al);
      CHECK(f.live == 0);
      if (f.calls <= k) { CHECK(rc != PHGMG_ERR_NOMEM); break; } /* every call site was hit */
      CHECK_RC(rc, PHGMG_ERR_NOMEM);
    }
}

SUITE(hyper) {
  RUN(test_nnls_bruteforce);
  RUN(test_nnls_kkt);
  RUN(test_nnls_rank_deficient);
  RUN(test_nnls_stop_and_errors);
  RUN(test_deim_greedy);
  RUN(test_ecsw_exact_sparse);
  RUN(test_ecsw_convex_bounded);
  RUN(test_ecsw_errors);
  RUN(test_hyper_nomem);
}
