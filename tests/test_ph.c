/* Port-Hamiltonian full-order models and the GL3 stepper: validation codes,
   band LU, model evaluations against closed forms, order of convergence,
   discrete energy balance, equivalence of the dense / banded / step-map /
   callback paths, Newton failure semantics, allocation failures. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include "../examples/msd_models.h"

/* ---- helpers ------------------------------------------------------------------ */
static double max_abs_diff(const double *a, const double *b, size_t n) {
  size_t i;
  double d = 0.0;
  for (i = 0; i < n; ++i) d = fmax(d, fabs(a[i] - b[i]));
  return d;
}
static double max_abs(const double *a, size_t n) {
  size_t i;
  double d = 0.0;
  for (i = 0; i < n; ++i) d = fmax(d, fabs(a[i]));
  return d;
}
static double *dup(const double *a, size_t n) {
  double *b = (double *)malloc(n * sizeof(double));
  memcpy(b, a, n * sizeof(double));
  return b;
}

/* A small dense system owning its arrays (N <= 8, m <= 2). */
typedef struct tsys {
  phgmg_ph_system sys;
  double J[64], R[64], Q[64], B[16];
} tsys;
static void tsys_point(tsys *t) {
  t->sys.J = t->J; t->sys.R = t->R; t->sys.Q = t->Q; t->sys.B = t->B;
}
/* the paper's linear MSD with 3 masses (N = 6), dense */
static void tsys_msd6(tsys *t) {
  msd_linear M;
  memset(t, 0, sizeof *t);
  CHECK(msd_linear_build(&M, 3, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  memcpy(t->J, M.J, 36 * sizeof(double));
  memcpy(t->R, M.R, 36 * sizeof(double));
  memcpy(t->Q, M.Q, 36 * sizeof(double));
  memcpy(t->B, M.B, 6 * sizeof(double));
  t->sys = M.sys;
  tsys_point(t);
  msd_linear_free(&M);
}
/* validate and check that nothing the system points to changed */
static int validate_untouched(const tsys *t, double *rcond) {
  tsys before = *t;
  int rc = (int)phgmg_ph_validate(&t->sys, 0.0, rcond, NULL);
  CHECK(memcmp(before.J, t->J, sizeof t->J) == 0);
  CHECK(memcmp(before.R, t->R, sizeof t->R) == 0);
  CHECK(memcmp(before.Q, t->Q, sizeof t->Q) == 0);
  CHECK(memcmp(before.B, t->B, sizeof t->B) == 0);
  return rc;
}

/* ---- GL3 coefficients ---------------------------------------------------------- */
TEST(test_gl3_coefficients) {
  double c[3], b[3], A[9], T[9], Ti[9], gam, alp, bet;
  int i, j, k;
  phgmg_gl3_coefficients(c, b, A);
  CHECK(fabs(b[0] + b[1] + b[2] - 1.0) <= 1e-15);
  for (k = 0; k < 3; ++k) /* stage order: sum_j a_ij c_j^k = c_i^(k+1)/(k+1) */
    for (i = 0; i < 3; ++i) {
      double s = 0.0;
      for (j = 0; j < 3; ++j) s += A[i * 3 + j] * pow(c[j], k);
      CHECK_LE(fabs(s - pow(c[i], k + 1) / (k + 1)), 2e-16);
    }
  for (k = 0; k < 6; ++k) { /* quadrature order 6: sum b_i c_i^k = 1/(k+1), k < 6 */
    double s = b[0] * pow(c[0], k) + b[1] * pow(c[1], k) + b[2] * pow(c[2], k);
    CHECK_LE(fabs(s - 1.0 / (k + 1)), 2e-16);
  }
  /* ... and not 7 */
  CHECK(fabs(b[0] * pow(c[0], 6) + b[1] * pow(c[1], 6) + b[2] * pow(c[2], 6) - 1.0 / 7) > 1e-4);
  /* the transformation: gam and alp +- i bet are roots of z^3 - 12 z^2 + 60 z - 120,
     A T Lambda = T (Lambda = [[gam,0,0],[0,alp,bet],[0,-bet,alp]]), Ti T = I */
  phgmg__gl3_transform(A, T, Ti, &gam, &alp, &bet);
  CHECK_LE(fabs(((gam - 12) * gam + 60) * gam - 120), 1e-12);
  {
    double zr = alp, zi = bet, r2 = zr * zr - zi * zi, i2 = 2 * zr * zi;
    double r3 = r2 * zr - i2 * zi, i3 = r2 * zi + i2 * zr;
    CHECK_LE(fabs(r3 - 12 * r2 + 60 * zr - 120), 1e-11);
    CHECK_LE(fabs(i3 - 12 * i2 + 60 * zi), 1e-11);
    CHECK(bet > 1.0);
  }
  {
    double L[9] = {0}, AT[9], ATL[9];
    L[0] = gam; L[4] = alp; L[5] = bet; L[7] = -bet; L[8] = alp;
    for (i = 0; i < 3; ++i)
      for (j = 0; j < 3; ++j) {
        double s = 0, u = 0;
        for (k = 0; k < 3; ++k) {
          s += A[i * 3 + k] * T[k * 3 + j];
          u += Ti[i * 3 + k] * T[k * 3 + j];
        }
        AT[i * 3 + j] = s;
        CHECK_LE(fabs(u - (i == j)), 1e-14);
      }
    for (i = 0; i < 3; ++i)
      for (j = 0; j < 3; ++j) {
        double s = 0;
        for (k = 0; k < 3; ++k) s += AT[i * 3 + k] * L[k * 3 + j];
        ATL[i * 3 + j] = s;
      }
    CHECK_LE(max_abs_diff(ATL, T, 9), 1e-14);
  }
}

/* the starting-guess extrapolation reproduces cubics with p(0) = 0, and
   d = b^T A^{-1} */
TEST(test_gl3_extrapolation_and_weights) {
  tsys t;
  phgmg_gl3 *s = NULL;
  phgmg_gl3_opts o;
  int i, j;
  tsys_msd6(&t);
  memset(&o, 0, sizeof o);
  o.no_step_map = 1;
  CHECK_RC(phgmg_gl3_create(&s, &t.sys, 0.1, &o, NULL), PHGMG_OK);
  if (!s) return;
  for (i = 0; i < 3; ++i) {
    double g = 0.0, si = 1.0 + s->c[i];
    for (j = 0; j < 3; ++j) {
      double cj = s->c[j];
      g += s->E[i * 3 + j] * (cj + 2 * cj * cj - cj * cj * cj);
    }
    CHECK_LE(fabs(g - ((si + 2 * si * si - si * si * si) - 2.0)), 1e-13);
  }
  for (j = 0; j < 3; ++j) {
    double dA = s->d[0] * s->A[j] + s->d[1] * s->A[3 + j] + s->d[2] * s->A[6 + j];
    CHECK_LE(fabs(dA - s->b[j]), 1e-14);
  }
  phgmg_gl3_destroy(s);
}

/* ---- validation ----------------------------------------------------------------- */
static double tnan(void) { return NAN; }

TEST(test_validate_codes) {
  tsys t0, t;
  double rc0 = 0.0, rc1 = 0.0;
  int which;
  tsys_msd6(&t0);
  CHECK_RC(validate_untouched(&t0, &rc0), PHGMG_OK);
  CHECK(rc0 > 1e-3 && rc0 <= 1.0);
  /* J not skew */
  t = t0; tsys_point(&t); t.J[0 + 1 * 6] = 2.0;
  CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_NOT_SKEW);
  t = t0; tsys_point(&t); t.J[2 + 2 * 6] = 0.1; /* nonzero diagonal */
  CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_NOT_SKEW);
  /* R not symmetric, Q not symmetric */
  t = t0; tsys_point(&t); t.R[1 + 3 * 6] = 0.5;
  CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_NOT_SYMMETRIC);
  t = t0; tsys_point(&t); t.Q[0 + 4 * 6] = 0.5;
  CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_Q_NOT_SYMMETRIC);
  /* R indefinite: negative diagonal (diagonal R) and a symmetric 2x2 block
     [1 2; 2 1] with eigenvalue -1 (eigenvalue path) */
  t = t0; tsys_point(&t); t.R[3 + 3 * 6] = -0.5;
  CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_NOT_PSD);
  t = t0; tsys_point(&t); t.R[1 + 1 * 6] = 1; t.R[3 + 3 * 6] = 1;
  t.R[1 + 3 * 6] = t.R[3 + 1 * 6] = 2;
  CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_NOT_PSD);
  t.R[1 + 3 * 6] = t.R[3 + 1 * 6] = 0.9; /* eigenvalues 0.1, 1.9: fine */
  CHECK_RC(validate_untouched(&t, NULL), PHGMG_OK);
  /* J - R singular: J = 0, R = diag(0, c, 0, c, 0, c) */
  t = t0; tsys_point(&t); memset(t.J, 0, sizeof t.J);
  CHECK_RC(validate_untouched(&t, &rc1), PHGMG_ERR_SINGULAR);
  CHECK(rc1 <= 1e-12);
  /* B rank deficient: [e2, 2 e2] */
  t = t0; tsys_point(&t); t.sys.m = 2; t.B[6 + 1] = 2.0;
  CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_RANK);
  t.B[6 + 3] = 1.0; /* [e2, 2 e2 + e4]: full rank */
  CHECK_RC(validate_untouched(&t, NULL), PHGMG_OK);
  t = t0; tsys_point(&t); memset(t.B, 0, sizeof t.B);
  CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_RANK);
  /* NaN / Inf in each matrix */
  for (which = 0; which < 4; ++which) {
    double *M;
    t = t0; tsys_point(&t);
    M = which == 0 ? t.J : which == 1 ? t.R : which == 2 ? t.Q : t.B;
    M[which == 3 ? 4 : 7] = tnan();
    CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_NANINF);
    M[which == 3 ? 4 : 7] = INFINITY;
    CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_NANINF);
  }
  /* sizes and arguments */
  t = t0; tsys_point(&t); t.sys.N = 0;
  CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_SIZE);
  t = t0; tsys_point(&t); t.sys.m = 0;
  CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_SIZE);
  t = t0; tsys_point(&t); t.sys.m = 7;
  CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_SIZE);
  t = t0; tsys_point(&t); t.sys.storage = PHGMG_BANDED; t.sys.kb = 6;
  CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_SIZE);
  t.sys.kb = -1;
  CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_SIZE);
  {
    int idx[2] = {0, 6};
    double poly[3] = {0, 0, 1};
    t = t0; tsys_point(&t);
    t.sys.nl = PHGMG_NL_SEPARABLE; t.sys.nsep = 2; t.sys.sep_idx = idx;
    t.sys.poly_deg = 2; t.sys.poly = poly;
    CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_SIZE);
    idx[1] = 5;
    CHECK_RC(validate_untouched(&t, NULL), PHGMG_OK);
    t.sys.nsep = -1;
    CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_SIZE);
    t.sys.nsep = 2; t.sys.poly_deg = 0; /* no polynomial and no callbacks */
    CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_INVALID_ARG);
    t.sys.poly_deg = 2; poly[1] = tnan();
    CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_NANINF);
  }
  t = t0; tsys_point(&t); t.sys.nl = PHGMG_NL_GENERAL; /* callbacks missing */
  CHECK_RC(validate_untouched(&t, NULL), PHGMG_ERR_INVALID_ARG);
  t = t0; tsys_point(&t); t.sys.J = NULL;
  CHECK_RC(phgmg_ph_validate(&t.sys, 0.0, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_ph_validate(NULL, 0.0, NULL, NULL), PHGMG_ERR_INVALID_ARG);
}

/* banded storage: same codes; for N > 2000 a non-diagonal R is checked by a
   shifted band Cholesky */
TEST(test_validate_banded) {
  msd_linear Md, Mb;
  double rcd = 0.0, rcb = 0.0;
  CHECK(msd_linear_build(&Md, 4, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  CHECK(msd_linear_build(&Mb, 4, NULL, NULL, NULL, PHGMG_BANDED) == 0);
  CHECK_RC(phgmg_ph_validate(&Md.sys, 0.0, &rcd, NULL), PHGMG_OK);
  CHECK_RC(phgmg_ph_validate(&Mb.sys, 0.0, &rcb, NULL), PHGMG_OK);
  CHECK_LE(fabs(rcd - rcb), 1e-12 * rcd);
  {
    double *J = dup(Mb.J, 5 * 8);
    const double *save = Mb.sys.J;
    Mb.sys.J = J;
    J[2 + 1 * 5] = 0.7; /* (i,j) = (1,1): diagonal of J */
    CHECK_RC(phgmg_ph_validate(&Mb.sys, 0.0, NULL, NULL), PHGMG_ERR_NOT_SKEW);
    J[2 + 1 * 5] = NAN;
    CHECK_RC(phgmg_ph_validate(&Mb.sys, 0.0, NULL, NULL), PHGMG_ERR_NANINF);
    Mb.sys.J = save;
    free(J);
  }
  { /* corners of the band storage outside the matrix are never read */
    double *Q = dup(Mb.Q, 5 * 8);
    const double *save = Mb.sys.Q;
    Q[0] = Q[1] = NAN; /* (i,j) with i < 0 in column 0 */
    Mb.sys.Q = Q;
    CHECK_RC(phgmg_ph_validate(&Mb.sys, 0.0, NULL, NULL), PHGMG_OK);
    Mb.sys.Q = save;
    free(Q);
  }
  msd_linear_free(&Md);
  msd_linear_free(&Mb);
  { /* N = 2002: R = tridiag(-1, d, -1) (path Laplacian when d = 2 with ends 1) */
    int N = 2002, i;
    double *J = (double *)calloc(3 * (size_t)N, sizeof(double));
    double *R = (double *)calloc(3 * (size_t)N, sizeof(double));
    double *Q = (double *)calloc(3 * (size_t)N, sizeof(double));
    double *B = (double *)calloc((size_t)N, sizeof(double));
    phgmg_ph_system s;
    memset(&s, 0, sizeof s);
    s.N = N; s.m = 1; s.storage = PHGMG_BANDED; s.kb = 1;
    s.J = J; s.R = R; s.Q = Q; s.B = B;
    B[0] = 1.0;
    for (i = 0; i < N; ++i) {
      Q[PHGMG__PHB(1, i, i)] = 1.0;
      R[PHGMG__PHB(1, i, i)] = (i == 0 || i == N - 1) ? 1.0 : 2.0;
      if (i + 1 < N) R[PHGMG__PHB(1, i, i + 1)] = R[PHGMG__PHB(1, i + 1, i)] = -1.0;
      if (i % 2 == 0) { J[PHGMG__PHB(1, i, i + 1)] = 1.0; J[PHGMG__PHB(1, i + 1, i)] = -1.0; }
    }
    CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_OK); /* singular PSD */
    for (i = 1; i < N - 1; ++i) R[PHGMG__PHB(1, i, i)] = 1.9;   /* lambda_min ~ -0.1 */
    CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_NOT_PSD);
    free(J); free(R); free(Q); free(B);
  }
}

/* ---- band LU with pivoting against the dense LU ---------------------------------- */
TEST(test_band_lu) {
  enum { n = 40, kl = 2, ku = 3 };
  int ldab = 2 * kl + ku + 1, i, j, ue = -1, ipiv[n], ipd[n], trial;
  double ab[(2 * kl + ku + 1) * n], A[n * n], LU[n * n], dinv[n], b[n], x[n], xd[n];
  double zab[2 * (2 * kl + ku + 1) * n], zA[2 * n * n], zdinv[2 * n], zb[2 * n], zx[2 * n];
  for (trial = 0; trial < 2; ++trial) {
    char tr = trial ? 'T' : 'N';
    memset(ab, 0, sizeof ab);
    memset(A, 0, sizeof A);
    for (j = 0; j < n; ++j)
      for (i = PHGMG__MAX(0, j - ku); i <= PHGMG__MIN(n - 1, j + kl); ++i) {
        double v = th_rand();
        A[i + j * n] = v;
        ab[(kl + ku + i - j) + j * ldab] = v;
      }
    CHECK_RC(phgmg__gb_factor(n, kl, ku, ab, ldab, ipiv, dinv, &ue), PHGMG_OK);
    CHECK(ue > ku); /* random entries: rows were interchanged */
    for (i = 0; i < n; ++i) b[i] = x[i] = xd[i] = th_rand();
    phgmg__gb_solve(tr, n, kl, ku, ue, ab, ldab, ipiv, dinv, x);
    memcpy(LU, A, sizeof A);
    CHECK_RC(phgmg_lu_factor(n, LU, n, ipd), PHGMG_OK);
    phgmg_lu_solve(tr, n, LU, n, ipd, 1, xd, n);
    CHECK_LE(max_abs_diff(x, xd, n), 1e-11 * max_abs(xd, n));
    for (i = 0; i < n; ++i) { /* residual, computed directly */
      double r = -b[i];
      for (j = 0; j < n; ++j) r += (tr == 'N' ? A[i + j * n] : A[j + i * n]) * x[j];
      CHECK_LE(fabs(r), 1e-14 * n * max_abs(x, n));
    }
  }
  /* complex */
  memset(zab, 0, sizeof zab);
  memset(zA, 0, sizeof zA);
  for (j = 0; j < n; ++j)
    for (i = PHGMG__MAX(0, j - ku); i <= PHGMG__MIN(n - 1, j + kl); ++i) {
      double vr = th_rand(), vi = th_rand();
      zA[2 * (i + j * n)] = vr; zA[2 * (i + j * n) + 1] = vi;
      zab[2 * ((kl + ku + i - j) + j * ldab)] = vr;
      zab[2 * ((kl + ku + i - j) + j * ldab) + 1] = vi;
    }
  CHECK_RC(phgmg__zgb_factor(n, kl, ku, zab, ldab, ipiv, zdinv, &ue), PHGMG_OK);
  for (i = 0; i < 2 * n; ++i) zb[i] = zx[i] = th_rand();
  phgmg__zgb_solve(n, kl, ku, ue, zab, ldab, ipiv, zdinv, zx);
  for (i = 0; i < n; ++i) {
    double rr = -zb[2 * i], ri = -zb[2 * i + 1];
    for (j = 0; j < n; ++j) {
      double ar = zA[2 * (i + j * n)], ai = zA[2 * (i + j * n) + 1];
      rr += ar * zx[2 * j] - ai * zx[2 * j + 1];
      ri += ar * zx[2 * j + 1] + ai * zx[2 * j];
    }
    CHECK_LE(fabs(rr) + fabs(ri), 1e-14 * n * max_abs(zx, 2 * n));
  }
  /* an exactly singular band matrix (zero column) */
  memset(ab, 0, sizeof ab);
  for (j = 0; j < n; ++j)
    if (j != 7) ab[(kl + ku) + j * ldab] = 1.0;
  CHECK_RC(phgmg__gb_factor(n, kl, ku, ab, ldab, ipiv, dinv, &ue), PHGMG_ERR_SINGULAR);
}

/* ---- factorization of J - R --------------------------------------------------------- */
TEST(test_jr_factor) {
  int st;
  for (st = 0; st < 2; ++st) {
    msd_linear M;
    phgmg_jr_factor *f = NULL;
    double rc = 0.0, X[2 * 10], X0[2 * 10], Y1[2 * 10], Y2[2 * 10];
    int N = 10, i, tr;
    CHECK(msd_linear_build(&M, 5, NULL, NULL, NULL, st ? PHGMG_BANDED : PHGMG_DENSE) == 0);
    CHECK_RC(phgmg_jr_factor_create(&f, &M.sys, &rc, NULL), PHGMG_OK);
    CHECK(rc > 1e-3 && rc <= 1.0);
    for (tr = 0; tr < 2; ++tr) {
      for (i = 0; i < 2 * N; ++i) X0[i] = X[i] = th_rand();
      phgmg_jr_solve(f, tr ? 'T' : 'N', 2, X, N);
      /* (J - R) X = X0, or (J - R)^T X = (-J - R) X = X0 */
      phgmg_ph_apply(&M.sys, 'J', 2, X, N, Y1, N);
      phgmg_ph_apply(&M.sys, 'R', 2, X, N, Y2, N);
      for (i = 0; i < 2 * N; ++i)
        CHECK_LE(fabs((tr ? -Y1[i] : Y1[i]) - Y2[i] - X0[i]), 1e-13 * (1 + max_abs(X, 2 * N)));
    }
    phgmg_jr_factor_destroy(f);
    { /* singular: J = 0 */
      double *J = (double *)calloc(st ? 5 * 10 : 100, sizeof(double));
      const double *save = M.sys.J;
      M.sys.J = J;
      f = NULL;
      CHECK_RC(phgmg_jr_factor_create(&f, &M.sys, NULL, NULL), PHGMG_ERR_SINGULAR);
      CHECK(f == NULL);
      M.sys.J = save;
      free(J);
    }
    msd_linear_free(&M);
  }
}

/* ---- model evaluations against the paper's original coordinates --------------------- */
/* H, grad H and f of the nonlinear MSD in the original coordinates (xi, v). */
static double msd_orig_H(int n, const double *xi, const double *v, double k1, double k2,
                         double mass) {
  double H = 0.0;
  int i;
  for (i = 0; i < n; ++i) H += 0.5 * mass * v[i] * v[i];
  for (i = 0; i < n; ++i) {
    double d = i + 1 < n ? xi[i + 1] - xi[i] : xi[i];
    H += 0.5 * k1 * d * d + 0.25 * k2 * d * d * d * d;
  }
  return H;
}

TEST(test_ph_eval_msd) {
  enum { n = 7, N = 14 };
  const double k1 = 1.3, k2 = 0.7, mass = 1.5, gam = 0.4;
  double xi[n], v[n], xd[N], xb[N], gd[N], gb[N], fd[N], fb[N], gxi[n], f_orig[N], u = 0.37;
  int i, k;
  msd_nonlinear Md, Mb;
  msd_nl_opts o;
  memset(&o, 0, sizeof o);
  o.n = n; o.k1 = k1; o.k2 = k2; o.mass = mass; o.gamma = gam;
  CHECK(msd_nonlinear_build(&Md, &o) == 0);
  o.storage = PHGMG_BANDED;
  CHECK(msd_nonlinear_build(&Mb, &o) == 0);
  CHECK_RC(phgmg_ph_validate(&Md.sys, 0.0, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_ph_validate(&Mb.sys, 0.0, NULL, NULL), PHGMG_OK);
  CHECK(Mb.sys.kb == 3);
  for (i = 0; i < n; ++i) { xi[i] = 0.8 * th_rand(); v[i] = th_rand(); }
  /* transformed state: l_i = xi_i - xi_{i+1}, l_n = xi_n */
  for (i = 0; i < n; ++i) {
    double l = i + 1 < n ? xi[i] - xi[i + 1] : xi[i];
    xd[Md.idx_l[i]] = l; xd[Md.idx_v[i]] = v[i];
    xb[Mb.idx_l[i]] = l; xb[Mb.idx_v[i]] = v[i];
  }
  {
    double H = msd_orig_H(n, xi, v, k1, k2, mass);
    CHECK_LE(fabs(phgmg_ph_hamiltonian(&Md.sys, xd) - H), 1e-14 * H);
    CHECK_LE(fabs(phgmg_ph_hamiltonian(&Mb.sys, xb) - H), 1e-14 * H);
  }
  /* original dynamics: xi' = dH/dv, v' = -dH/dxi - gam dH/dv + e1 u; the
     transformed right-hand side must be T f_orig */
  for (i = 0; i < n; ++i) { /* dH/dxi_i by hand */
    double g = 0.0;
    if (i + 1 < n) { double d = xi[i + 1] - xi[i]; g -= k1 * d + k2 * d * d * d; }
    if (i >= 1) { double d = xi[i] - xi[i - 1]; g += k1 * d + k2 * d * d * d; }
    if (i == n - 1) { double d = xi[i]; g += k1 * d + k2 * d * d * d; }
    gxi[i] = g;
  }
  for (i = 0; i < n; ++i) {
    f_orig[i] = mass * v[i];
    f_orig[n + i] = -gxi[i] - gam * mass * v[i] + (i == 0 ? u : 0.0);
  }
  phgmg_ph_rhs(&Md.sys, xd, &u, fd);
  phgmg_ph_rhs(&Mb.sys, xb, &u, fb);
  for (i = 0; i < n; ++i) {
    double fl = i + 1 < n ? f_orig[i] - f_orig[i + 1] : f_orig[i];
    CHECK_LE(fabs(fd[Md.idx_l[i]] - fl), 1e-13);
    CHECK_LE(fabs(fd[Md.idx_v[i]] - f_orig[n + i]), 1e-13);
    CHECK_LE(fabs(fb[Mb.idx_l[i]] - fl), 1e-13);
    CHECK_LE(fabs(fb[Mb.idx_v[i]] - f_orig[n + i]), 1e-13);
  }
  /* gradient against central differences of H; output y = mass v_1 */
  phgmg_ph_gradient(&Md.sys, xd, gd);
  phgmg_ph_gradient(&Mb.sys, xb, gb);
  for (k = 0; k < N; ++k) {
    double e = 1e-5, xp[N], xm[N], fdiff;
    memcpy(xp, xd, sizeof xp); memcpy(xm, xd, sizeof xm);
    xp[k] += e; xm[k] -= e;
    fdiff = (phgmg_ph_hamiltonian(&Md.sys, xp) - phgmg_ph_hamiltonian(&Md.sys, xm)) / (2 * e);
    CHECK_LE(fabs(gd[k] - fdiff), 1e-8);
  }
  for (i = 0; i < n; ++i) {
    CHECK_LE(fabs(gd[Md.idx_l[i]] - gb[Mb.idx_l[i]]), 1e-15);
    CHECK_LE(fabs(gd[Md.idx_v[i]] - gb[Mb.idx_v[i]]), 1e-15);
  }
  {
    double yd, yb;
    phgmg_ph_output(&Md.sys, xd, &yd);
    phgmg_ph_output(&Mb.sys, xb, &yb);
    CHECK_LE(fabs(yd - mass * v[0]), 1e-15);
    CHECK_LE(fabs(yb - mass * v[0]), 1e-15);
  }
  { /* apply: dense and banded agree up to the permutation */
    const char *w = "JRQ";
    int c;
    for (c = 0; c < 3; ++c) {
      double Yd[N], Yb[N];
      phgmg_ph_apply(&Md.sys, w[c], 1, xd, N, Yd, N);
      phgmg_ph_apply(&Mb.sys, w[c], 1, xb, N, Yb, N);
      for (i = 0; i < n; ++i) {
        CHECK_LE(fabs(Yd[Md.idx_l[i]] - Yb[Mb.idx_l[i]]), 1e-15);
        CHECK_LE(fabs(Yd[Md.idx_v[i]] - Yb[Mb.idx_v[i]]), 1e-15);
      }
    }
  }
  msd_nonlinear_free(&Md);
  msd_nonlinear_free(&Mb);
}

/* ---- the same quartic as a GENERAL nonlinearity ------------------------------------ */
typedef struct quart_ctx {
  int n, N, banded, kb;
  const int *idx;
  double k2;
} quart_ctx;
static double quart_H(const double *x, void *user) {
  quart_ctx *q = (quart_ctx *)user;
  double H = 0.0;
  int i;
  for (i = 0; i < q->n; ++i) { double l = x[q->idx[i]]; H += 0.25 * q->k2 * l * l * l * l; }
  return H;
}
static void quart_grad(const double *x, double *g, void *user) {
  quart_ctx *q = (quart_ctx *)user;
  int i;
  memset(g, 0, sizeof(double) * (size_t)q->N);
  for (i = 0; i < q->n; ++i) { double l = x[q->idx[i]]; g[q->idx[i]] = q->k2 * l * l * l; }
}
static void quart_hess(const double *x, double *Hs, void *user) {
  quart_ctx *q = (quart_ctx *)user;
  int i;
  size_t len = q->banded ? (size_t)(2 * q->kb + 1) * (size_t)q->N : (size_t)q->N * (size_t)q->N;
  memset(Hs, 0, sizeof(double) * len);
  for (i = 0; i < q->n; ++i) {
    int j = q->idx[i];
    double l = x[j], v = 3.0 * q->k2 * l * l;
    if (q->banded) Hs[PHGMG__PHB(q->kb, j, j)] = v;
    else Hs[(size_t)j + (size_t)j * (size_t)q->N] = v;
  }
}
static phgmg_ph_system quart_general(const msd_nonlinear *M, quart_ctx *q, double k2) {
  phgmg_ph_system s = M->sys;
  q->n = M->n; q->N = M->sys.N; q->banded = M->sys.storage == PHGMG_BANDED; q->kb = M->sys.kb;
  q->idx = M->idx_l; q->k2 = k2;
  s.nl = PHGMG_NL_GENERAL;
  s.nsep = 0; s.sep_idx = NULL; s.poly_deg = 0; s.poly = NULL;
  s.H_nl = quart_H; s.grad_nl = quart_grad; s.hess_nl = quart_hess; s.user = q;
  return s;
}

/* ---- order of convergence ---------------------------------------------------------- */
/* damped oscillator x = (q, p), H = k q^2/2 + p^2/(2m), R = diag(0, c):
   x(t) = e^{-at} (cos(wt) I + sin(wt)/w (M + aI)) x0, M = [0 1/m; -k -c/m] */
TEST(test_gl3_linear_order6) {
  const double k = 2.0, m = 1.0, c = 0.2, Tend = 10.0;
  double J[4] = {0, -1, 1, 0}, R[4] = {0, 0, 0, c}, Q[4] = {k, 0, 0, 1 / m}, B[2] = {0, 1};
  double a = c / (2 * m), w = sqrt(k / m - a * a), ex[2];
  phgmg_ph_system s;
  int map, lev;
  memset(&s, 0, sizeof s);
  s.N = 2; s.m = 1; s.J = J; s.R = R; s.Q = Q; s.B = B;
  {
    double e = exp(-a * Tend), cs = cos(w * Tend), sn = sin(w * Tend) / w;
    /* x0 = (1, 0): column 1 of the propagator */
    ex[0] = e * (cs + sn * (0.0 + a));
    ex[1] = e * (sn * (-k));
  }
  for (map = 0; map < 2; ++map) {
    double err[3];
    phgmg_gl3_opts o;
    memset(&o, 0, sizeof o);
    o.no_step_map = !map;
    for (lev = 0; lev < 3; ++lev) {
      int nsteps = 25 << lev;
      double x[2] = {1.0, 0.0};
      phgmg_gl3 *g = NULL;
      int i;
      CHECK_RC(phgmg_gl3_create(&g, &s, Tend / nsteps, &o, NULL), PHGMG_OK);
      if (!g) return;
      CHECK(g->mode == (map ? PHGMG__GL3_MAP : PHGMG__GL3_DENSE));
      for (i = 0; i < nsteps; ++i)
        CHECK_RC(phgmg_gl3_step(g, i * (Tend / nsteps), x, NULL, NULL, NULL), PHGMG_OK);
      err[lev] = fmax(fabs(x[0] - ex[0]), fabs(x[1] - ex[1]));
      phgmg_gl3_destroy(g);
    }
    CHECK(err[2] > 1e-14); /* still above round-off */
    CHECK_LE(5.6, log2(err[0] / err[1]));
    CHECK_LE(log2(err[0] / err[1]), 6.4);
    CHECK_LE(5.6, log2(err[1] / err[2]));
    CHECK_LE(log2(err[1] / err[2]), 6.4);
  }
}

/* Duffing-type pH system with input: q' = p, p' = -(q + q^3) - 0.1 p + u(t) */
static void u_cos(double t, double *u, void *user) { (void)user; u[0] = 0.5 * cos(1.3 * t); }

static void duffing_sys(phgmg_ph_system *s, double *J, double *R, double *Q, double *B,
                        int *idx, double *poly) {
  J[0] = 0; J[1] = -1; J[2] = 1; J[3] = 0;
  R[0] = 0; R[1] = 0; R[2] = 0; R[3] = 0.1;
  Q[0] = 1; Q[1] = 0; Q[2] = 0; Q[3] = 1;
  B[0] = 0; B[1] = 1;
  idx[0] = 0;
  poly[0] = poly[1] = poly[2] = poly[3] = 0; poly[4] = 0.25;
  memset(s, 0, sizeof *s);
  s->N = 2; s->m = 1; s->J = J; s->R = R; s->Q = Q; s->B = B;
  s->nl = PHGMG_NL_SEPARABLE; s->nsep = 1; s->sep_idx = idx; s->poly_deg = 4; s->poly = poly;
}

TEST(test_gl3_nonlinear_order6) {
  double J[4], R[4], Q[4], B[2], poly[5], xref[2], err[3];
  int idx[1], lev;
  const double Tend = 4.0;
  phgmg_ph_system s;
  phgmg_gl3_opts o;
  duffing_sys(&s, J, R, Q, B, idx, poly);
  memset(&o, 0, sizeof o);
  o.tol = 1e-14; o.max_iter = 50;
  for (lev = -1; lev < 3; ++lev) {
    int nsteps = lev < 0 ? 320 : 10 << lev, i;
    double x[2] = {1.0, 0.0};
    phgmg_gl3 *g = NULL;
    CHECK_RC(phgmg_gl3_create(&g, &s, Tend / nsteps, &o, NULL), PHGMG_OK);
    if (!g) return;
    for (i = 0; i < nsteps; ++i)
      CHECK_RC(phgmg_gl3_step(g, i * (Tend / nsteps), x, u_cos, NULL, NULL), PHGMG_OK);
    if (lev < 0) memcpy(xref, x, sizeof x);
    else err[lev] = fmax(fabs(x[0] - xref[0]), fabs(x[1] - xref[1]));
    phgmg_gl3_destroy(g);
  }
  CHECK(err[2] > 1e-12);
  CHECK_LE(5.5, log2(err[0] / err[1]));
  CHECK_LE(log2(err[0] / err[1]), 6.6);
  CHECK_LE(5.5, log2(err[1] / err[2]));
  CHECK_LE(log2(err[1] / err[2]), 6.6);
}

/* the linear step map with an input: order 6 against a fine reference too
   (inputs must be taken at the stage times) */
TEST(test_gl3_linear_input_order6) {
  msd_linear M;
  double xref[6], err[3];
  int lev, map;
  const double Tend = 6.0;
  CHECK(msd_linear_build(&M, 3, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  for (map = 0; map < 2; ++map) {
    phgmg_gl3_opts o;
    memset(&o, 0, sizeof o);
    o.no_step_map = !map;
    for (lev = -1; lev < 3; ++lev) {
      int nsteps = lev < 0 ? 480 : 15 << lev, i;
      double x[6] = {0.1, 0.2, -0.3, 0.0, 0.5, -0.1};
      phgmg_gl3 *g = NULL;
      CHECK_RC(phgmg_gl3_create(&g, &M.sys, Tend / nsteps, &o, NULL), PHGMG_OK);
      if (!g) break;
      for (i = 0; i < nsteps; ++i)
        CHECK_RC(phgmg_gl3_step(g, i * (Tend / nsteps), x, u_cos, NULL, NULL), PHGMG_OK);
      if (lev < 0) memcpy(xref, x, sizeof x);
      else err[lev] = max_abs_diff(x, xref, 6);
      phgmg_gl3_destroy(g);
    }
    CHECK(err[2] > 1e-13);
    CHECK_LE(5.5, log2(err[0] / err[1]));
    CHECK_LE(log2(err[0] / err[1]), 6.6);
    CHECK_LE(5.5, log2(err[1] / err[2]));
    CHECK_LE(log2(err[1] / err[2]), 6.6);
  }
  msd_linear_free(&M);
}

/* ---- energy balance, quadratic Hamiltonian ------------------------------------------ */
static void u_sin1(double t, double *u, void *user) { (void)user; u[0] = sin(t); }

/* max_n |H_n - H_0 - S_n + D_n| / max(|H|, S, D) */
static double energy_defect(const phgmg_energy *e, int nsteps) {
  double emax = 0.0, scale = 0.0;
  int i;
  for (i = 0; i <= nsteps; ++i) {
    emax = fmax(emax, fabs(e->H[i] - e->H[0] - e->S[i] + e->D[i]));
    scale = fmax(scale, fmax(fabs(e->H[i]), fmax(fabs(e->S[i]), fabs(e->D[i]))));
  }
  return emax / scale;
}

TEST(test_gl3_energy_quadratic) {
  enum { nst = 300 };
  int variant;
  for (variant = 0; variant < 3; ++variant) { /* step map, dense Newton, banded Newton */
    msd_linear M;
    double x0[20], H[nst + 1], S[nst + 1], D[nst + 1], rel;
    phgmg_energy e;
    phgmg_gl3_opts o;
    phgmg_gl3_stats st;
    int i, done = -1;
    CHECK(msd_linear_build(&M, 10, NULL, NULL, NULL,
                           variant == 2 ? PHGMG_BANDED : PHGMG_DENSE) == 0);
    for (i = 0; i < 20; ++i) x0[i] = 0.5 * th_rand();
    e.H = H; e.S = S; e.D = D;
    memset(&o, 0, sizeof o);
    o.no_step_map = variant != 0;
    CHECK_RC(phgmg_simulate(&M.sys, x0, 0.0, 0.1, nst, u_sin1, NULL, &o, NULL, NULL, &e, &st,
                            &done, NULL), PHGMG_OK);
    CHECK(done == nst);
    CHECK(st.steps == nst);
    rel = energy_defect(&e, nst);
    CHECK_LE(rel, 1e-13);
    CHECK(S[nst] != 0.0 && D[nst] > 0.0);
    if (variant) { /* linear: factored once, exact Jacobian: one Newton update per step */
      CHECK(st.factorizations == 1);
      CHECK(st.newton_iters == nst);
    }
    msd_linear_free(&M);
  }
}

/* ---- the three linear paths give the same trajectory --------------------------------- */
TEST(test_gl3_map_equals_newton) {
  enum { nst = 200, N = 20 };
  msd_linear Md, Mb;
  double x0[N], *X[3], Hs[3][nst + 1], Ss[3][nst + 1], Ds[3][nst + 1];
  int v, i;
  CHECK(msd_linear_build(&Md, 10, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  CHECK(msd_linear_build(&Mb, 10, NULL, NULL, NULL, PHGMG_BANDED) == 0);
  for (i = 0; i < N; ++i) x0[i] = th_rand();
  for (v = 0; v < 3; ++v) {
    phgmg_gl3_opts o;
    phgmg_energy e;
    memset(&o, 0, sizeof o);
    o.no_step_map = v != 0;
    e.H = Hs[v]; e.S = Ss[v]; e.D = Ds[v];
    X[v] = (double *)malloc(sizeof(double) * N * (nst + 1));
    CHECK_RC(phgmg_simulate(v == 2 ? &Mb.sys : &Md.sys, x0, 0.0, 0.1, nst, u_sin1, NULL, &o,
                            X[v], NULL, &e, NULL, NULL, NULL), PHGMG_OK);
  }
  for (v = 1; v < 3; ++v) {
    double sc = max_abs(X[0], (size_t)N * (nst + 1));
    CHECK_LE(max_abs_diff(X[0], X[v], (size_t)N * (nst + 1)), 1e-13 * sc);
    CHECK_LE(max_abs_diff(Ss[0], Ss[v], nst + 1), 1e-13 * max_abs(Ss[0], nst + 1));
    CHECK_LE(max_abs_diff(Ds[0], Ds[v], nst + 1), 1e-13 * max_abs(Ds[0], nst + 1));
  }
  for (v = 0; v < 3; ++v) free(X[v]);
  msd_linear_free(&Md);
  msd_linear_free(&Mb);
}

/* ---- nonlinear MSD: dense, banded, callback solver, GENERAL kind ------------------------ */
/* Caller-supplied shifted solver for tests: forms K(sigma) = sigma I - (J - R)
   Hess H(x) densely from the model (Hess = Q + diag(3 k2 l^2)) and uses the
   dense LU. */
typedef struct cb_ctx {
  const msd_nonlinear *M;
  double k2;
  double *K1, *K2;
  int *ip1, *ip2;
  long nfactor, nsolve;
  double sr_real, sr_c, si_c;
} cb_ctx;
static phgmg_result cb_factor(double sr, double si, const double *x, void *user) {
  cb_ctx *c = (cb_ctx *)user;
  const msd_nonlinear *M = c->M;
  int N = M->sys.N, i, j, k;
  double *Hd = (double *)calloc((size_t)N, sizeof(double));
  phgmg_result rc;
  c->nfactor++;
  for (i = 0; i < N; ++i) Hd[i] = M->Q[(size_t)i * (N + 1)]; /* Q is diagonal */
  for (k = 0; k < M->n; ++k) { double l = x[M->idx_l[k]]; Hd[M->idx_l[k]] += 3 * c->k2 * l * l; }
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) {
      size_t e = (size_t)i + (size_t)j * N;
      double jac = (M->J[e] - M->R[e]) * Hd[j];
      if (si == 0.0) c->K1[e] = (i == j ? sr : 0.0) - jac;
      else { c->K2[2 * e] = (i == j ? sr : 0.0) - jac; c->K2[2 * e + 1] = i == j ? si : 0.0; }
    }
  free(Hd);
  if (si == 0.0) { c->sr_real = sr; rc = phgmg_lu_factor(N, c->K1, N, c->ip1); }
  else { c->sr_c = sr; c->si_c = si; rc = phgmg_zlu_factor(N, c->K2, N, c->ip2); }
  return rc;
}
static void cb_solve(double sr, double si, double *rhs, void *user) {
  cb_ctx *c = (cb_ctx *)user;
  int N = c->M->sys.N;
  c->nsolve++;
  if (si == 0.0) { CHECK(sr == c->sr_real); phgmg_lu_solve('N', N, c->K1, N, c->ip1, 1, rhs, N); }
  else { CHECK(sr == c->sr_c && si == c->si_c); phgmg_zlu_solve(N, c->K2, N, c->ip2, 1, rhs, N); }
}
static void u_sin_big(double t, double *u, void *user) { (void)user; u[0] = 1.5 * sin(t); }

TEST(test_gl3_msd_paths_agree) {
  enum { n = 20, N = 40, nst = 150 };
  msd_nonlinear Md, Mb;
  msd_nl_opts op;
  quart_ctx qd, qb;
  cb_ctx cb;
  phgmg_ph_system sys[5];
  double *X[5], x0[N], sc;
  phgmg_gl3_stats st[5];
  phgmg_gl3_opts o;
  int v, i, k;
  memset(&op, 0, sizeof op);
  op.n = n; op.k2 = 2.0;
  CHECK(msd_nonlinear_build(&Md, &op) == 0);
  op.storage = PHGMG_BANDED;
  CHECK(msd_nonlinear_build(&Mb, &op) == 0);
  sys[0] = Md.sys;                         /* dense LU                     */
  sys[1] = Mb.sys;                         /* banded LU                    */
  sys[2] = Md.sys;                         /* caller-supplied solver       */
  memset(&cb, 0, sizeof cb);
  cb.M = &Md; cb.k2 = 2.0;
  cb.K1 = (double *)malloc(sizeof(double) * N * N);
  cb.K2 = (double *)malloc(2 * sizeof(double) * N * N);
  cb.ip1 = (int *)malloc(sizeof(int) * N);
  cb.ip2 = (int *)malloc(sizeof(int) * N);
  sys[2].shifted_factor = cb_factor; sys[2].shifted_solve = cb_solve; sys[2].shifted_user = &cb;
  sys[3] = quart_general(&Md, &qd, 2.0);   /* GENERAL, dense               */
  sys[4] = quart_general(&Mb, &qb, 2.0);   /* GENERAL, banded              */
  memset(&o, 0, sizeof o);
  o.tol = 1e-12; o.max_iter = 20;
  for (v = 0; v < 5; ++v) {
    const msd_nonlinear *M = (v == 1 || v == 4) ? &Mb : &Md;
    double *Xv;
    int done = -1;
    for (k = 0; k < n; ++k) { /* the same physical state in either ordering */
      x0[M->idx_l[k]] = 0.3 * sin(0.7 * k);
      x0[M->idx_v[k]] = 0.2 * cos(1.1 * k);
    }
    Xv = (double *)malloc(sizeof(double) * N * (nst + 1));
    CHECK_RC(phgmg_simulate(&sys[v], x0, 0.0, 0.1, nst, u_sin_big, NULL, &o, Xv, NULL, NULL,
                            &st[v], &done, NULL), PHGMG_OK);
    CHECK(done == nst);
    /* back to the dense ordering */
    X[v] = (double *)malloc(sizeof(double) * N * (nst + 1));
    for (i = 0; i <= nst; ++i)
      for (k = 0; k < n; ++k) {
        X[v][(size_t)i * N + Md.idx_l[k]] = Xv[(size_t)i * N + M->idx_l[k]];
        X[v][(size_t)i * N + Md.idx_v[k]] = Xv[(size_t)i * N + M->idx_v[k]];
      }
    free(Xv);
  }
  sc = max_abs(X[0], (size_t)N * (nst + 1));
  CHECK(sc > 0.5); /* the quartic matters at this amplitude */
  for (v = 1; v < 5; ++v) {
    CHECK_LE(max_abs_diff(X[0], X[v], (size_t)N * (nst + 1)), 1e-12 * sc);
    CHECK(st[v].newton_iters == st[0].newton_iters);
  }
  CHECK(st[0].factorizations >= 1);
  CHECK(cb.nfactor == 2 * st[2].factorizations);
  CHECK(cb.nsolve == 2 * st[2].newton_iters);
  for (v = 0; v < 5; ++v) free(X[v]);
  free(cb.K1); free(cb.K2); free(cb.ip1); free(cb.ip2);
  msd_nonlinear_free(&Md);
  msd_nonlinear_free(&Mb);
}

/* ---- the shifted Newton solves against matrices formed independently --------------- */
TEST(test_gl3_shifted_solves) {
  enum { n = 10, N = 20 };
  msd_nonlinear M;
  msd_nl_opts op;
  int hv;
  memset(&op, 0, sizeof op);
  op.n = n; op.storage = PHGMG_BANDED; op.k2 = 3.0;
  CHECK(msd_nonlinear_build(&M, &op) == 0);
  for (hv = 0; hv < 2; ++hv) { /* h = 0.1: no pivoting (packed solve); h = 50: pivoting */
    double h = hv ? 50.0 : 0.1, x[N], Hd[N], r[N], r0[N], z[2 * N], z0[2 * N];
    phgmg_gl3 *g = NULL;
    int i, j, k;
    CHECK_RC(phgmg_gl3_create(&g, &M.sys, h, NULL, NULL), PHGMG_OK);
    if (!g) break;
    for (i = 0; i < N; ++i) x[i] = th_rand();
    CHECK_RC(phgmg__gl3_factor(g, x), PHGMG_OK);
    CHECK(g->mode == PHGMG__GL3_BANDED);
    CHECK((g->nopiv1 && g->nopiv2) == !hv);
    for (i = 0; i < N; ++i) {
      r[i] = r0[i] = th_rand();
      z[2 * i] = z0[2 * i] = th_rand();
      z[2 * i + 1] = z0[2 * i + 1] = th_rand();
    }
    /* the stepper's own (zero-padded) right-hand side buffers */
    memcpy(g->r1, r, sizeof r);
    memcpy(g->rc, z, sizeof z);
    if (g->nopiv1 && g->nopiv2) phgmg__gl3_solve_packed(g, g->r1, g->rc);
    else { phgmg__gl3_solve_real(g, g->r1); phgmg__gl3_solve_cplx(g, g->rc); }
    memcpy(r, g->r1, sizeof r);
    memcpy(z, g->rc, sizeof z);
    /* Hess H = diag(Q) + 3 k2 l^2 on the l coordinates */
    for (i = 0; i < N; ++i) Hd[i] = M.Q[PHGMG__PHB(3, i, i)];
    for (k = 0; k < n; ++k) { double l = x[M.idx_l[k]]; Hd[M.idx_l[k]] += 3.0 * op.k2 * l * l; }
    for (i = 0; i < N; ++i) {
      double a = g->gam / h * r[i] - r0[i];
      double br = g->alp / h * z[2 * i] + g->bet / h * z[2 * i + 1] - z0[2 * i];
      double bi = g->alp / h * z[2 * i + 1] - g->bet / h * z[2 * i] - z0[2 * i + 1];
      for (j = PHGMG__MAX(0, i - 3); j <= PHGMG__MIN(N - 1, i + 3); ++j) {
        double jac = (M.J[PHGMG__PHB(3, i, j)] - M.R[PHGMG__PHB(3, i, j)]) * Hd[j];
        a -= jac * r[j];
        br -= jac * z[2 * j];
        bi -= jac * z[2 * j + 1];
      }
      CHECK_LE(fabs(a), 1e-13 * (1 + max_abs(r, N) / h));
      CHECK_LE(fabs(br) + fabs(bi), 1e-13 * (1 + max_abs(z, 2 * N) / h));
    }
    phgmg_gl3_destroy(g);
  }
  msd_nonlinear_free(&M);
}

/* ---- factor reuse: any refactoring policy gives the same trajectory ------------------- */
TEST(test_gl3_refactor_policy) {
  double J[4], R[4], Q[4], B[2], poly[5], X[3][2 * 101];
  int idx[1], p;
  long fac[3];
  const double contr[3] = {0.01, 0.0, 0.999}; /* 0: the default 0.5 */
  phgmg_ph_system s;
  duffing_sys(&s, J, R, Q, B, idx, poly);
  for (p = 0; p < 3; ++p) { /* large amplitude: the Jacobian changes a lot */
    double x0[2] = {6.0, 0.0};
    phgmg_gl3_opts o;
    phgmg_gl3_stats st;
    memset(&o, 0, sizeof o);
    o.tol = 1e-12; o.max_iter = 30; o.contraction = contr[p];
    CHECK_RC(phgmg_simulate(&s, x0, 0.0, 0.1, 100, u_cos, NULL, &o, X[p], NULL, NULL, &st,
                            NULL, NULL), PHGMG_OK);
    fac[p] = st.factorizations;
  }
  CHECK(fac[0] > fac[1] && fac[1] > fac[2] && fac[2] >= 1);
  CHECK_LE(max_abs_diff(X[0], X[1], 202), 1e-10 * max_abs(X[0], 202));
  CHECK_LE(max_abs_diff(X[0], X[2], 202), 1e-10 * max_abs(X[0], 202));
}

/* ---- N = 1, kb = 0: x' = -r q x, the GL3 stability function exactly ------------------ */
TEST(test_gl3_scalar) {
  double J = 0.0, R = 0.5, Q = 2.0, B = 1.0, z = -1.0 * 0.3; /* h lambda, lambda = -R Q */
  /* Gauss-Legendre s = 3 is the (3,3) Pade approximant of exp */
  double Rz = (1 + z / 2 + z * z / 10 + z * z * z / 120) /
              (1 - z / 2 + z * z / 10 - z * z * z / 120);
  int v;
  for (v = 0; v < 3; ++v) {
    phgmg_ph_system s;
    phgmg_gl3 *g = NULL;
    phgmg_gl3_opts o;
    double x = 1.0;
    int i;
    memset(&s, 0, sizeof s);
    s.N = 1; s.m = 1; s.J = &J; s.R = &R; s.Q = &Q; s.B = &B;
    s.storage = v == 2 ? PHGMG_BANDED : PHGMG_DENSE;
    memset(&o, 0, sizeof o);
    o.no_step_map = v == 1;
    CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_OK);
    CHECK_RC(phgmg_gl3_create(&g, &s, 0.3, &o, NULL), PHGMG_OK);
    if (!g) return;
    for (i = 0; i < 10; ++i) CHECK_RC(phgmg_gl3_step(g, 0.3 * i, &x, NULL, NULL, NULL), PHGMG_OK);
    CHECK_LE(fabs(x - pow(Rz, 10)), 1e-15);
    phgmg_gl3_destroy(g);
  }
}

/* ---- failures: state untouched ------------------------------------------------------- */
static void u_nan_late(double t, double *u, void *user) {
  (void)user;
  u[0] = t > 0.55 ? tnan() : 0.1;
}

TEST(test_gl3_failures) {
  double J[4], R[4], Q[4], B[2], poly[5];
  int idx[1];
  phgmg_ph_system s;
  phgmg_gl3 *g = NULL;
  phgmg_gl3_opts o;
  double x[2], x0[2];
  duffing_sys(&s, J, R, Q, B, idx, poly);
  /* stiff quartic, huge step: simplified Newton cannot converge */
  poly[4] = 250.0;
  R[3] = 1.0;
  memset(&o, 0, sizeof o);
  CHECK_RC(phgmg_gl3_create(&g, &s, 5.0, &o, NULL), PHGMG_OK);
  if (!g) return;
  x0[0] = x[0] = 2.0; x0[1] = x[1] = -1.0;
  CHECK_RC(phgmg_gl3_step(g, 0.0, x, NULL, NULL, NULL), PHGMG_ERR_NOT_CONVERGED);
  CHECK(memcmp(x, x0, sizeof x) == 0);
  CHECK(phgmg_gl3_get_stats(g)->failures >= 1);
  CHECK(phgmg_gl3_get_stats(g)->steps == 0);
  phgmg_gl3_destroy(g);
  /* a tolerance below round-off with few iterations: NOT_CONVERGED after max_iter */
  poly[4] = 0.25; R[3] = 0.1;
  o.tol = 1e-300; o.max_iter = 3;
  CHECK_RC(phgmg_gl3_create(&g, &s, 0.1, &o, NULL), PHGMG_OK);
  if (!g) return;
  x0[0] = x[0] = 0.5; x0[1] = x[1] = 0.1;
  CHECK_RC(phgmg_gl3_step(g, 0.0, x, NULL, NULL, NULL), PHGMG_ERR_NOT_CONVERGED);
  CHECK(memcmp(x, x0, sizeof x) == 0);
  CHECK(phgmg_gl3_get_stats(g)->newton_iters <= 3);
  phgmg_gl3_destroy(g);
  /* NaN in the input or the state */
  memset(&o, 0, sizeof o);
  CHECK_RC(phgmg_gl3_create(&g, &s, 0.1, &o, NULL), PHGMG_OK);
  if (!g) return;
  CHECK_RC(phgmg_gl3_step(g, 1.0, x, u_nan_late, NULL, NULL), PHGMG_ERR_NANINF);
  CHECK(memcmp(x, x0, sizeof x) == 0);
  x[1] = NAN;
  CHECK_RC(phgmg_gl3_step(g, 0.0, x, NULL, NULL, NULL), PHGMG_ERR_NANINF);
  CHECK(x[0] == x0[0] && x[1] != x[1]);
  phgmg_gl3_destroy(g);
  /* simulate stops at the failing step and says how far it got */
  {
    double X[2 * 11], Y[11];
    int done = -1;
    x[0] = 0.5; x[1] = 0.1;
    memset(X, 0, sizeof X);
    CHECK_RC(phgmg_simulate(&s, x, 0.0, 0.1, 10, u_nan_late, NULL, NULL, X, Y, NULL, NULL,
                            &done, NULL), PHGMG_ERR_NANINF);
    CHECK(done == 5); /* the step from t = 0.5 samples u after 0.55 */
    CHECK(X[2 * 5] != 0.0 && X[2 * 6] == 0.0);
  }
  /* bad arguments */
  CHECK_RC(phgmg_gl3_create(&g, &s, 0.0, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  s.shifted_factor = cb_factor; /* without shifted_solve */
  CHECK_RC(phgmg_gl3_create(&g, &s, 0.1, NULL, NULL), PHGMG_ERR_INVALID_ARG);
}

/* ---- the paper's nonlinear MSD FOM (n = 500, dt = 0.1, t in (0, 100]) ------------------- */
TEST(test_gl3_msd_paper_energy) {
  enum { nst = 1000 };
  msd_nonlinear M;
  msd_nl_opts op;
  phgmg_gl3_opts o;
  phgmg_gl3_stats st;
  phgmg_energy e;
  double *X, *Y, H[nst + 1], S[nst + 1], D[nst + 1], x0[1000], emax = 0.0;
  int i, done = -1, N;
  memset(&op, 0, sizeof op);
  op.n = 500; op.storage = PHGMG_BANDED;
  CHECK(msd_nonlinear_build(&M, &op) == 0);
  N = M.sys.N;
  X = (double *)malloc(sizeof(double) * (size_t)N * (nst + 1));
  Y = (double *)malloc(sizeof(double) * (nst + 1));
  memset(x0, 0, sizeof x0);
  memset(&o, 0, sizeof o);
  o.tol = 1e-8; o.max_iter = 20;
  e.H = H; e.S = S; e.D = D;
  CHECK_RC(phgmg_simulate(&M.sys, x0, 0.0, 0.1, nst, msd_input_sin, NULL, &o, X, Y, &e, &st,
                          &done, NULL), PHGMG_OK);
  CHECK(done == nst);
  for (i = 0; i <= nst; ++i) emax = fmax(emax, fabs(H[i] - H[0] - S[i] + D[i]));
  printf("    [msd n=500 FOM] max e_energy = %.3e (S = %.4f, D = %.4f, H = %.4f), "
         "%ld Newton iterations, %ld factorizations, max residual %.2e\n",
         emax, S[nst], D[nst], H[nst], st.newton_iters, st.factorizations, st.max_residual);
  /* Newton stops at a stage residual <= 1e-8 and the quartic makes Gauss
     quadrature inexact, so the balance is not round-off; it stays far below the
     energies exchanged (S ~ 0.4) */
  CHECK_LE(emax, 1e-8);
  CHECK(S[nst] > 0.1 && D[nst] > 0.1);
  CHECK_LE(st.max_residual, 1e-8);
  /* the extrapolated guess keeps it at about one update per step (about two
     without it) */
  CHECK_LE(st.newton_iters, 1.2 * nst);
  for (i = 0; i <= nst; i += 100) { /* outputs and energies are those of the states */
    double y;
    phgmg_ph_output(&M.sys, X + (size_t)i * N, &y);
    CHECK(y == Y[i]);
    CHECK(H[i] == phgmg_ph_hamiltonian(&M.sys, X + (size_t)i * N));
  }
  free(X);
  free(Y);
  msd_nonlinear_free(&M);
}

/* ---- allocation failures: every path returns NOMEM and frees what it took ---------------- */
typedef struct fail_alloc { long count, fail_at, live; } fail_alloc;
static void *fa_alloc(size_t n, void *user) {
  fail_alloc *f = (fail_alloc *)user;
  if (f->count++ == f->fail_at) return NULL;
  f->live++;
  return malloc(n);
}
static void fa_free(void *p, void *user) {
  fail_alloc *f = (fail_alloc *)user;
  if (p) { f->live--; free(p); }
}

TEST(test_alloc_failures) {
  msd_nonlinear Mb, Md;
  msd_linear Ml;
  msd_nl_opts op;
  const phgmg_ph_system *sys[3];
  int v;
  memset(&op, 0, sizeof op);
  op.n = 5;
  CHECK(msd_nonlinear_build(&Md, &op) == 0);
  op.storage = PHGMG_BANDED;
  CHECK(msd_nonlinear_build(&Mb, &op) == 0);
  CHECK(msd_linear_build(&Ml, 5, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  sys[0] = &Md.sys; sys[1] = &Mb.sys; sys[2] = &Ml.sys;
  for (v = 0; v < 3; ++v) {
    long k;
    int seen_ok = 0;
    for (k = 0; k < 200 && !seen_ok; ++k) {
      fail_alloc fa = {0, 0, 0};
      phgmg_allocator al;
      double x0[10] = {0.1, 0.2, 0.3, 0, 0, 0, 0, 0, 0, 0.1}, X[10 * 4], H[4], S[4], D[4];
      phgmg_energy e;
      phgmg_result r1, r2, r3;
      phgmg_jr_factor *f = NULL;
      e.H = H; e.S = S; e.D = D;
      fa.fail_at = k;
      al.alloc = fa_alloc; al.free = fa_free; al.user = &fa;
      r1 = phgmg_simulate(sys[v], x0, 0.0, 0.1, 3, msd_input_sin, NULL, NULL, X, NULL, &e,
                          NULL, NULL, &al);
      CHECK(fa.live == 0);
      fa.count = 0;
      r2 = phgmg_ph_validate(sys[v], 0.0, NULL, &al);
      CHECK(fa.live == 0);
      fa.count = 0;
      r3 = phgmg_jr_factor_create(&f, sys[v], NULL, &al);
      phgmg_jr_factor_destroy(f);
      CHECK(fa.live == 0);
      CHECK(r1 == PHGMG_OK || r1 == PHGMG_ERR_NOMEM);
      CHECK(r2 == PHGMG_OK || r2 == PHGMG_ERR_NOMEM);
      CHECK(r3 == PHGMG_OK || r3 == PHGMG_ERR_NOMEM);
      seen_ok = r1 == PHGMG_OK && r2 == PHGMG_OK && r3 == PHGMG_OK;
    }
    CHECK(seen_ok);
  }
  msd_nonlinear_free(&Md);
  msd_nonlinear_free(&Mb);
  msd_linear_free(&Ml);
}

/* ---- simulate bookkeeping ---------------------------------------------------------------- */
TEST(test_simulate_outputs) {
  enum { nst = 40, N = 8 };
  msd_linear M;
  double x0[N], X[N * (nst + 1)], Y[nst + 1], H[nst + 1], S[nst + 1], D[nst + 1];
  phgmg_energy e;
  phgmg_gl3_stats st;
  phgmg_gl3 *g = NULL;
  double x[N];
  int i, done = -1;
  CHECK(msd_linear_build(&M, 4, NULL, NULL, NULL, PHGMG_BANDED) == 0);
  for (i = 0; i < N; ++i) x[i] = x0[i] = th_rand();
  e.H = H; e.S = S; e.D = D;
  CHECK_RC(phgmg_simulate(&M.sys, x0, 2.0, 0.05, nst, msd_input_sin, NULL, NULL, X, Y, &e,
                          &st, &done, NULL), PHGMG_OK);
  CHECK(done == nst && st.steps == nst && S[0] == 0.0 && D[0] == 0.0);
  CHECK(memcmp(X, x0, sizeof x0) == 0);
  /* the same steps by hand, starting at t0 = 2 */
  CHECK_RC(phgmg_gl3_create(&g, &M.sys, 0.05, NULL, NULL), PHGMG_OK);
  if (!g) return;
  for (i = 0; i < nst; ++i) {
    double inc[2], y;
    CHECK_RC(phgmg_gl3_step(g, 2.0 + i * 0.05, x, msd_input_sin, NULL, inc), PHGMG_OK);
    CHECK_LE(max_abs_diff(x, X + (size_t)(i + 1) * N, N), 1e-15);
    CHECK_LE(fabs(S[i + 1] - S[i] - inc[0]), 1e-15);
    CHECK_LE(fabs(D[i + 1] - D[i] - inc[1]), 1e-15);
    phgmg_ph_output(&M.sys, X + (size_t)(i + 1) * N, &y);
    CHECK_LE(fabs(y - Y[i + 1]), 1e-15);
  }
  CHECK(phgmg_gl3_get_stats(g)->steps == nst);
  phgmg_gl3_destroy(g);
  msd_linear_free(&M);
}

SUITE(ph) {
  RUN(test_gl3_coefficients);
  RUN(test_gl3_extrapolation_and_weights);
  RUN(test_validate_codes);
  RUN(test_validate_banded);
  RUN(test_band_lu);
  RUN(test_jr_factor);
  RUN(test_ph_eval_msd);
  RUN(test_gl3_linear_order6);
  RUN(test_gl3_nonlinear_order6);
  RUN(test_gl3_linear_input_order6);
  RUN(test_gl3_energy_quadratic);
  RUN(test_gl3_map_equals_newton);
  RUN(test_gl3_msd_paths_agree);
  RUN(test_gl3_shifted_solves);
  RUN(test_gl3_refactor_policy);
  RUN(test_gl3_scalar);
  RUN(test_gl3_failures);
  RUN(test_gl3_msd_paper_energy);
  RUN(test_alloc_failures);
  RUN(test_simulate_outputs);
}
