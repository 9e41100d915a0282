/* Descriptor models E x' = (J - R) z(x) + B u, E^T z = grad H (phgmg_ph_system.E):
   a finite-element bar with a consistent mass matrix against the same model
   written in standard form (independent: the inverse mass matrix formed here
   by Gauss-Jordan elimination), the discrete energy balance, the result codes
   of bad input, and the reduced models (GMG-POD, SP1) against the reduction of
   the equivalent standard-form system and the closed forms of the derivation
   in the manual (W^T E D = I, Bh = [I; 0], J-check skew, R-check PSD). */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>

/* ---- model ---------------------------------------------------------------------- */
/* A bar of n linear elements (length 1, fixed at the left end), nodes 1..n:
   stiffness K = (EA/h) tridiag(-1, 2, -1) (last diagonal 1), consistent mass
   M = (rho A h / 6) tridiag(1, 4, 1) (last diagonal 2), Rayleigh damping
   D = a M + b K. State x = (q, v) (N = 2n), E = diag(I, M), Q = diag(K, I),
   J = [[0, I], [-I, 0]], R = diag(0, D), so that E^T Q = diag(K, M) and
   H = q^T K q / 2 + v^T M v / 2. Ports: forces at the tip and at node n/2
   (velocities as outputs). Nonlinear option: ground springs phi(q_k) = q_k^4/4
   at every node (coordinates where E is the identity). */
typedef struct dbar {
  int n, N, m;
  double *E, *J, *R, *Q, *B, *K, *M;
} dbar;

static void dbar_free(dbar *b) {
  free(b->E); free(b->J); free(b->R); free(b->Q); free(b->B); free(b->K); free(b->M);
  memset(b, 0, sizeof *b);
}

static void dbar_make(dbar *b, int n) {
  const int N = 2 * n;
  const double h = 1.0 / n, ka = 1.0 / h, ma = h / 6.0, ra = 0.05, rb = 2e-3;
  int i;
  b->n = n; b->N = N; b->m = 2;
  b->E = (double *)calloc((size_t)N * N, sizeof(double));
  b->J = (double *)calloc((size_t)N * N, sizeof(double));
  b->R = (double *)calloc((size_t)N * N, sizeof(double));
  b->Q = (double *)calloc((size_t)N * N, sizeof(double));
  b->B = (double *)calloc((size_t)N * 2, sizeof(double));
  b->K = (double *)calloc((size_t)n * n, sizeof(double));
  b->M = (double *)calloc((size_t)n * n, sizeof(double));
  for (i = 0; i < n; ++i) {
    const int last = i == n - 1;
    b->K[i + (size_t)i * n] = ka * (last ? 1.0 : 2.0);
    b->M[i + (size_t)i * n] = ma * (last ? 2.0 : 4.0);
    if (i + 1 < n) {
      b->K[i + (size_t)(i + 1) * n] = b->K[i + 1 + (size_t)i * n] = -ka;
      b->M[i + (size_t)(i + 1) * n] = b->M[i + 1 + (size_t)i * n] = ma;
    }
  }
  for (i = 0; i < n; ++i) {
    int j;
    b->E[i + (size_t)i * N] = 1.0;
    b->Q[n + i + (size_t)(n + i) * N] = 1.0;
    b->J[i + (size_t)(n + i) * N] = 1.0;
    b->J[n + i + (size_t)i * N] = -1.0;
    for (j = 0; j < n; ++j) {
      b->E[n + i + (size_t)(n + j) * N] = b->M[i + (size_t)j * n];
      b->Q[i + (size_t)j * N] = b->K[i + (size_t)j * n];
      b->R[n + i + (size_t)(n + j) * N] = ra * b->M[i + (size_t)j * n] + rb * b->K[i + (size_t)j * n];
    }
  }
  b->B[n + n - 1] = 1.0;
  b->B[N + n + n / 2 - 1] = 1.0;
}

static const double dbar_poly[5] = {0.0, 0.0, 0.0, 0.0, 0.25};
static int dbar_idx[512];

static phgmg_ph_system dbar_system(const dbar *b, int nonlinear) {
  phgmg_ph_system s;
  int i;
  memset(&s, 0, sizeof s);
  s.N = b->N; s.m = b->m; s.J = b->J; s.R = b->R; s.Q = b->Q; s.B = b->B; s.E = b->E;
  if (nonlinear) {
    for (i = 0; i < b->n; ++i) dbar_idx[i] = i;
    s.nl = PHGMG_NL_SEPARABLE; s.nsep = b->n; s.sep_idx = dbar_idx; s.poly_deg = 4; s.poly = dbar_poly;
  }
  return s;
}

/* Inverse of a dense n x n matrix by Gauss-Jordan elimination with partial
   pivoting (independent of the library's LU). */
static int gj_inverse(int n, const double *A, double *Ai) {
  double *T = (double *)malloc(sizeof(double) * (size_t)n * 2 * n);
  int i, j, k, ok = 1;
  for (i = 0; i < n; ++i)
    for (j = 0; j < 2 * n; ++j) T[i + (size_t)j * n] = j < n ? A[i + (size_t)j * n] : (j - n == i ? 1.0 : 0.0);
  for (k = 0; k < n && ok; ++k) {
    int p = k;
    double piv;
    for (i = k + 1; i < n; ++i) if (fabs(T[i + (size_t)k * n]) > fabs(T[p + (size_t)k * n])) p = i;
    if (T[p + (size_t)k * n] == 0.0) { ok = 0; break; }
    for (j = 0; j < 2 * n; ++j) { double t = T[k + (size_t)j * n]; T[k + (size_t)j * n] = T[p + (size_t)j * n]; T[p + (size_t)j * n] = t; }
    piv = T[k + (size_t)k * n];
    for (j = 0; j < 2 * n; ++j) T[k + (size_t)j * n] /= piv;
    for (i = 0; i < n; ++i) {
      double f = T[i + (size_t)k * n];
      if (i == k || f == 0.0) continue;
      for (j = 0; j < 2 * n; ++j) T[i + (size_t)j * n] -= f * T[k + (size_t)j * n];
    }
  }
  for (i = 0; i < n && ok; ++i)
    for (j = 0; j < n; ++j) Ai[i + (size_t)j * n] = T[i + (size_t)(n + j) * n];
  free(T);
  return ok;
}

/* C = op(A) op(B), plain loops (n x n). */
static void mm(int n, const double *A, int ta, const double *B, int tb, double *C) {
  int i, j, k;
  for (j = 0; j < n; ++j)
    for (i = 0; i < n; ++i) {
      double s = 0.0;
      for (k = 0; k < n; ++k)
        s += (ta ? A[k + (size_t)i * n] : A[i + (size_t)k * n]) * (tb ? B[j + (size_t)k * n] : B[k + (size_t)j * n]);
      C[i + (size_t)j * n] = s;
    }
}

static void dbar_input(double t, double *u, void *user) {
  (void)user;
  u[0] = sin(3.0 * t) * exp(-0.2 * t);
  u[1] = 0.5 * sin(0.7 * t) * t * exp(-0.3 * t);
}


static double max_abs(size_t n, const double *a) {
  double m = 0.0;
  size_t i;
  for (i = 0; i < n; ++i) m = fabs(a[i]) > m ? fabs(a[i]) : m;
  return m;
}

/* ---- full-order model --------------------------------------------------------- */
/* The descriptor bar against the same bar in standard form in x~ = E x
   (x~' = (J - R) z + B u, z = Q~ x~, Q~ = diag(K, M^{-1})): Gauss-Legendre is
   invariant under the linear change of variables, so E x_n = x~_n up to the
   Newton tolerance (round-off for the linear step maps). Dense with the step
   map, dense Newton, banded Newton; linear and with ground springs. */
static void check_fom_vs_standard(int nonlinear) {
  dbar b;
  const int n = 12, ns = 200;
  const double dt = 0.05;
  phgmg_ph_system sd, ss, sb;
  phgmg_gl3_opts go;
  double *Qt, *Mi, *X, *Xs, *Xb, *Xn, *EX, *Y, *Ys, *Eb, *Jb, *Rb, *Qb;
  phgmg_energy en;
  double Hn[201], Sn[201], Dn[201], Hs[201], Ss[201], Ds[201], e, emax = 0.0, hmax = 0.0;
  phgmg_energy ens;
  int N, i, j, k;
  dbar_make(&b, n);
  N = b.N;
  Qt = (double *)calloc((size_t)N * N, sizeof(double));
  Mi = (double *)calloc((size_t)n * n, sizeof(double));
  X = (double *)calloc((size_t)N * (ns + 1), sizeof(double));
  Xs = (double *)calloc((size_t)N * (ns + 1), sizeof(double));
  Xb = (double *)calloc((size_t)N * (ns + 1), sizeof(double));
  Xn = (double *)calloc((size_t)N * (ns + 1), sizeof(double));
  EX = (double *)calloc((size_t)N, sizeof(double));
  Y = (double *)calloc((size_t)2 * (ns + 1), sizeof(double));
  Ys = (double *)calloc((size_t)2 * (ns + 1), sizeof(double));
  CHECK(gj_inverse(n, b.M, Mi));
  for (j = 0; j < n; ++j)
    for (i = 0; i < n; ++i) {
      Qt[i + (size_t)j * N] = b.K[i + (size_t)j * n];
      Qt[n + i + (size_t)(n + j) * N] = Mi[i + (size_t)j * n];
    }
  sd = dbar_system(&b, nonlinear);
  ss = sd; ss.E = NULL; ss.Q = Qt;
  CHECK_RC(phgmg_ph_validate(&sd, 0.0, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_ph_validate(&ss, 0.0, NULL, NULL), PHGMG_OK);
  memset(&go, 0, sizeof go);
  go.tol = 1e-13; go.max_iter = 30;
  en.H = Hn; en.S = Sn; en.D = Dn;
  CHECK_RC(phgmg_simulate(&sd, X, 0.0, dt, ns, dbar_input, NULL, &go, X, Y, &en, NULL, NULL, NULL), PHGMG_OK);
  ens.H = Hs; ens.S = Ss; ens.D = Ds;
  CHECK_RC(phgmg_simulate(&ss, Xs, 0.0, dt, ns, dbar_input, NULL, &go, Xs, Ys, &ens, NULL, NULL, NULL), PHGMG_OK);
  for (k = 0; k <= ns; ++k) {   /* E x_k against x~_k */
    for (i = 0; i < n; ++i) {
      double a = 0.0;
      for (j = 0; j < n; ++j) a += b.M[i + (size_t)j * n] * X[n + j + (size_t)k * N];
      EX[i] = X[i + (size_t)k * N];
      EX[n + i] = a;
    }
    for (i = 0; i < N; ++i) emax = fmax(emax, fabs(EX[i] - Xs[i + (size_t)k * N]));
  }
  CHECK(max_abs((size_t)N * (ns + 1), Xs) > 0.1);
  CHECK_LE(emax, 1e-10 * max_abs((size_t)N * (ns + 1), Xs));
  emax = 0.0;
  for (k = 0; k < 2 * (ns + 1); ++k) emax = fmax(emax, fabs(Y[k] - Ys[k]));
  CHECK_LE(emax, 1e-10 * max_abs((size_t)2 * (ns + 1), Ys));
  /* energy bookkeeping: H(x_n), supplied and dissipated energy equal those of
     the standard form (H~(x~) = H(x)); for the quadratic H the discrete
     balance H_n - H_0 = S_n - D_n holds to round-off (Gauss quadrature is
     exact for the degree-5 integrand; a quartic H leaves a quadrature error) */
  for (k = 0, emax = 0.0; k <= ns; ++k) {
    e = fabs(Hn[k] - Hn[0] - Sn[k] + Dn[k]);
    if (!nonlinear) emax = fmax(emax, e);
    emax = fmax(emax, fmax(fabs(Hn[k] - Hs[k]), fmax(fabs(Sn[k] - Ss[k]), fabs(Dn[k] - Ds[k]))));
    hmax = fmax(hmax, fabs(Hn[k]));
  }
  CHECK(hmax > 0.0);
  CHECK_LE(emax, 1e-11 * hmax);
  /* the same model through Newton (no step map) and in band storage (kb = n) */
  go.no_step_map = 1;
  CHECK_RC(phgmg_simulate(&sd, Xn, 0.0, dt, ns, dbar_input, NULL, &go, Xn, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
  Eb = th_band(N, n, b.E); Jb = th_band(N, n, b.J); Rb = th_band(N, n, b.R); Qb = th_band(N, n, b.Q);
  sb = sd; sb.storage = PHGMG_BANDED; sb.kb = n; sb.E = Eb; sb.J = Jb; sb.R = Rb; sb.Q = Qb;
  CHECK_RC(phgmg_ph_validate(&sb, 0.0, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_simulate(&sb, Xb, 0.0, dt, ns, dbar_input, NULL, &go, Xb, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
  emax = 0.0;
  for (k = 0; k < N * (ns + 1); ++k) emax = fmax(emax, fmax(fabs(Xn[k] - X[k]), fabs(Xb[k] - X[k])));
  CHECK_LE(emax, 1e-10 * max_abs((size_t)N * (ns + 1), X));
  free(Eb); free(Jb); free(Rb); free(Qb);
  free(Qt); free(Mi); free(X); free(Xs); free(Xb); free(Xn); free(EX); free(Y); free(Ys);
  dbar_free(&b);
}

TEST(test_descriptor_fom_linear) { check_fom_vs_standard(0); }
TEST(test_descriptor_fom_nonlinear) { check_fom_vs_standard(1); }

/* The Hamiltonian with E: 1/2 x^T E^T Q x + sum E_kk w_k phi_k (closed form
   for a diagonal E, Q and one weighted term). */
TEST(test_descriptor_hamiltonian) {
  double E[4] = {2.0, 0.0, 0.0, 3.0}, Q[4] = {5.0, 0.0, 0.0, 7.0}, J[4] = {0.0, 1.0, -1.0, 0.0};
  double R[4] = {0.0, 0.0, 0.0, 1.0}, B[2] = {0.0, 1.0}, x[2] = {0.5, -2.0}, w = 1.5, poly[3] = {0.0, 0.0, 1.0};
  int idx = 0;
  phgmg_ph_system s;
  memset(&s, 0, sizeof s);
  s.N = 2; s.m = 1; s.E = E; s.J = J; s.R = R; s.Q = Q; s.B = B;
  CHECK(fabs(phgmg_ph_hamiltonian(&s, x) - 0.5 * (2.0 * 5.0 * 0.25 + 3.0 * 7.0 * 4.0)) <= 1e-14);
  s.nl = PHGMG_NL_SEPARABLE; s.nsep = 1; s.sep_idx = &idx; s.sep_w = &w; s.poly_deg = 2; s.poly = poly;
  CHECK(fabs(phgmg_ph_hamiltonian(&s, x) - (0.5 * (2.0 * 5.0 * 0.25 + 3.0 * 7.0 * 4.0) + 2.0 * 1.5 * 0.25)) <= 1e-14);
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_OK);
}

/* Bad input: named result codes. */
TEST(test_descriptor_bad_input) {
  dbar b;
  phgmg_ph_system s;
  double *E2;
  int N, i;
  dbar_make(&b, 6);
  N = b.N;
  E2 = (double *)malloc(sizeof(double) * (size_t)N * N);
  s = dbar_system(&b, 0);
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_OK);
  /* E^T Q not symmetric: a mass coupling between q_0 and v_0 */
  memcpy(E2, b.E, sizeof(double) * (size_t)N * N);
  E2[0 + (size_t)b.n * N] = 0.3;
  s.E = E2;
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_EQ_NOT_SYMMETRIC);
  /* E^T Q symmetric but indefinite: a negative mass */
  memcpy(E2, b.E, sizeof(double) * (size_t)N * N);
  for (i = 0; i < N * N; ++i) if (i % N >= b.n && i / N >= b.n) E2[i] = -E2[i];
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_EQ_NOT_PD);
  /* singular E without zero rows or columns (E^T Q semidefinite is allowed
     with a nonlinear part; a zero row and column would be an index-one model,
     tests/test_dae.c): the last two masses' block c [[1, 1], [1, 1]] */
  s = dbar_system(&b, 1);
  memcpy(E2, b.E, sizeof(double) * (size_t)N * N);
  for (i = 0; i < N; ++i) E2[N - 1 + (size_t)i * N] = E2[i + (size_t)(N - 1) * N] = E2[N - 2 + (size_t)i * N] = E2[i + (size_t)(N - 2) * N] = 0.0;
  E2[N - 2 + (size_t)(N - 2) * N] = E2[N - 1 + (size_t)(N - 2) * N] = E2[N - 2 + (size_t)(N - 1) * N] = E2[N - 1 + (size_t)(N - 1) * N] = 0.01;
  s.E = E2;
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_E_SINGULAR);
  /* a separable term on a mass-coupled coordinate */
  s = dbar_system(&b, 1);
  dbar_idx[0] = b.n + 1;
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_E_COUPLED);
  /* GENERAL part, shifted callbacks: not with E */
  s = dbar_system(&b, 0);
  s.nl = PHGMG_NL_GENERAL;
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_UNSUPPORTED);
  free(E2);
  dbar_free(&b);
}

/* CSC of P^T A P for a dense N x N A (perm: new index i is old perm[i]). */
typedef struct dcsc { phgmg_csc A; int *cp, *ri; double *v; } dcsc;
static void dcsc_make(dcsc *c, int N, const double *A, const int *perm) {
  int i, j, nz = 0;
  c->cp = (int *)malloc(sizeof(int) * (size_t)(N + 1));
  c->ri = (int *)malloc(sizeof(int) * (size_t)N * N);
  c->v = (double *)malloc(sizeof(double) * (size_t)N * N);
  c->cp[0] = 0;
  for (j = 0; j < N; ++j) {
    for (i = 0; i < N; ++i) {
      double a = A[perm[i] + (size_t)perm[j] * N];
      if (a != 0.0) { c->ri[nz] = i; c->v[nz++] = a; }
    }
    c->cp[j + 1] = nz;
  }
  c->A.n_rows = c->A.n_cols = N; c->A.colptr = c->cp; c->A.rowidx = c->ri; c->A.values = c->v;
}
static void dcsc_free(dcsc *c) { free(c->cp); free(c->ri); free(c->v); }

/* The bar given as CSC in a scrambled ordering (phgmg_ph_sparse_create_e):
   reverse Cuthill-McKee brings it back to a narrow band; the banded
   simulation in the internal order, mapped back, equals the dense one. */
TEST(test_descriptor_sparse_scrambled) {
  dbar b;
  const int n = 25, ns = 100;
  const double dt = 0.05;
  phgmg_ph_system sd, sp_sys;
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_sparse_info inf;
  dcsc cE, cJ, cR, cQ;
  double *Bp, *X, *XU, *XI, *Y, *Yi, emax = 0.0;
  int N, perm[64], i, j, k;
  dbar_make(&b, n);
  N = b.N;
  for (i = 0; i < N; ++i) perm[i] = i;
  for (i = N - 1; i > 0; --i) { j = (int)((th_rand() + 1.0) * 0.5 * (i + 1)); if (j > i) j = i; k = perm[i]; perm[i] = perm[j]; perm[j] = k; }
  dcsc_make(&cE, N, b.E, perm); dcsc_make(&cJ, N, b.J, perm); dcsc_make(&cR, N, b.R, perm); dcsc_make(&cQ, N, b.Q, perm);
  Bp = (double *)malloc(sizeof(double) * (size_t)N * 2);
  for (j = 0; j < 2; ++j) for (i = 0; i < N; ++i) Bp[i + (size_t)j * N] = b.B[perm[i] + (size_t)j * N];
  X = (double *)calloc((size_t)N * (ns + 1), sizeof(double));
  XU = (double *)calloc((size_t)N * (ns + 1), sizeof(double));
  XI = (double *)calloc((size_t)N * (ns + 1), sizeof(double));
  Y = (double *)calloc((size_t)2 * (ns + 1), sizeof(double));
  Yi = (double *)calloc((size_t)2 * (ns + 1), sizeof(double));
  CHECK_RC(phgmg_ph_sparse_create_e(&sp, N, 2, &cJ.A, &cR.A, &cQ.A, &cE.A, Bp, NULL, &inf, NULL), PHGMG_OK);
  if (sp) {
    phgmg_gl3_opts go;
    memset(&go, 0, sizeof go);
    go.tol = 1e-13;
    sp_sys = *phgmg_ph_sparse_system(sp);
    CHECK(sp_sys.E != NULL);
    CHECK(inf.kb < N / 2);
    CHECK_RC(phgmg_ph_validate(&sp_sys, 0.0, NULL, NULL), PHGMG_OK);
    sd = dbar_system(&b, 0);
    CHECK_RC(phgmg_simulate(&sd, X, 0.0, dt, ns, dbar_input, NULL, &go, X, Y, NULL, NULL, NULL, NULL), PHGMG_OK);
    CHECK_RC(phgmg_simulate(&sp_sys, XI, 0.0, dt, ns, dbar_input, NULL, &go, XI, Yi, NULL, NULL, NULL, NULL), PHGMG_OK);
    phgmg_ph_sparse_to_user_order(sp, ns + 1, XI, N, XU, N);   /* the scrambled user order */
    for (k = 0; k <= ns; ++k)
      for (i = 0; i < N; ++i) emax = fmax(emax, fabs(XU[i + (size_t)k * N] - X[perm[i] + (size_t)k * N]));
    CHECK_LE(emax, 1e-10 * max_abs((size_t)N * (ns + 1), X));
    emax = 0.0;
    for (k = 0; k < 2 * (ns + 1); ++k) emax = fmax(emax, fabs(Y[k] - Yi[k]));
    CHECK_LE(emax, 1e-10 * max_abs((size_t)2 * (ns + 1), Y));
  }
  /* The description form builds the same object: the same ordering and the
     same trajectory bit for bit; without E it is the plain phgmg_ph_sparse_create. */
  if (sp) {
    phgmg_ph_sparse_desc d;
    phgmg_ph_sparse *sq = (phgmg_ph_sparse *)1, *sr = NULL;
    phgmg_ph_sparse_info inq;
    memset(&d, 0, sizeof d);
    d.N = N; d.m = 2; d.J = cJ.A; d.R = cR.A; d.Q = cQ.A; d.E = cE.A; d.B = Bp;
    CHECK_RC(phgmg_ph_sparse_create_desc(NULL, &d, &inq, NULL), PHGMG_ERR_INVALID_ARG);
    CHECK_RC(phgmg_ph_sparse_create_desc(&sq, NULL, &inq, NULL), PHGMG_ERR_INVALID_ARG);
    CHECK(sq == NULL);
    CHECK_RC(phgmg_ph_sparse_create_desc(&sq, &d, &inq, NULL), PHGMG_OK);
    if (sq) {
      phgmg_ph_system s2 = *phgmg_ph_sparse_system(sq);
      CHECK(memcmp(phgmg_ph_sparse_perm(sq), phgmg_ph_sparse_perm(sp), sizeof(int) * (size_t)N) == 0);
      CHECK(inq.kb == inf.kb && inq.nnz == inf.nnz && s2.E != NULL);
      CHECK_RC(phgmg_simulate(&s2, X, 0.0, dt, ns, dbar_input, NULL, NULL, X, Y, NULL, NULL, NULL, NULL), PHGMG_OK);
      CHECK_RC(phgmg_simulate(&sp_sys, XU, 0.0, dt, ns, dbar_input, NULL, NULL, XU, Yi, NULL, NULL, NULL, NULL), PHGMG_OK);
      CHECK(memcmp(X, XU, sizeof(double) * (size_t)N * (ns + 1)) == 0);
    }
    memset(&d.E, 0, sizeof d.E);
    CHECK_RC(phgmg_ph_sparse_create_desc(&sr, &d, &inq, NULL), PHGMG_OK);
    CHECK(sr != NULL && phgmg_ph_sparse_system(sr)->E == NULL);
    phgmg_ph_sparse_destroy(sq);
    phgmg_ph_sparse_destroy(sr);
  }
  phgmg_ph_sparse_destroy(sp);
  dcsc_free(&cE); dcsc_free(&cJ); dcsc_free(&cR); dcsc_free(&cQ);
  free(Bp); free(X); free(XU); free(XI); free(Y); free(Yi);
  dbar_free(&b);
}

/* Feedthrough P, S, N on the descriptor bar: P = R C (so P^T R^+ P = C^T R C),
   S = C^T R C + 0.1 I, N skew. Against the independent forms: the states of
   the model without feedthrough and input matrix B - P (bit for bit: the same
   arithmetic), outputs (B + P)^T z + (S + N) u formed here, and the discrete
   energy balance H_n - H_0 = S_n - D_n with supply y^T u and dissipation
   [z; u]^T [[R, P], [P^T, S]] [z; u] to round-off (quadratic H). Bad blocks
   get PHGMG_ERR_FEEDTHROUGH; GMG-QM PHGMG_ERR_UNSUPPORTED, GMG-POD keeps it (more in tests/test_dissip.c). */
TEST(test_descriptor_feedthrough) {
  dbar b;
  const int n = 10, ns = 150;
  const double dt = 0.05;
  phgmg_ph_system sf, sb;
  phgmg_energy en;
  phgmg_reduce_opts o;
  phgmg_reduced *red = (phgmg_reduced *)1;
  double *C, *P, *Bm, *X, *Xb, *Y, z[64], u[2], S[4], Nk[4] = {0.0, -0.3, 0.3, 0.0}, Hn[151], Sn[151], Dn[151];
  double emax = 0.0, hmax = 0.0, ymax = 0.0;
  int N, i, j, k;
  dbar_make(&b, n);
  N = b.N;
  C = (double *)malloc(sizeof(double) * (size_t)N * 2); P = (double *)calloc((size_t)N * 2, sizeof(double));
  Bm = (double *)malloc(sizeof(double) * (size_t)N * 2);
  X = (double *)calloc((size_t)N * (ns + 1), sizeof(double)); Xb = (double *)calloc((size_t)N * (ns + 1), sizeof(double));
  Y = (double *)calloc((size_t)2 * (ns + 1), sizeof(double));
  for (k = 0; k < N * 2; ++k) C[k] = 0.5 * th_rand();
  for (j = 0; j < 2; ++j)
    for (i = 0; i < N; ++i)
      for (k = 0; k < N; ++k) P[i + (size_t)j * N] += b.R[i + (size_t)k * N] * C[k + (size_t)j * N];
  for (j = 0; j < 2; ++j)
    for (i = 0; i < 2; ++i) {
      double acc = i == j ? 0.1 : 0.0;
      for (k = 0; k < N; ++k) acc += C[k + (size_t)i * N] * P[k + (size_t)j * N];
      S[i + 2 * j] = acc;
    }
  S[2] = S[1] = 0.5 * (S[1] + S[2]);
  for (k = 0; k < N * 2; ++k) Bm[k] = b.B[k] - P[k];
  sf = dbar_system(&b, 0); sf.P = P; sf.S = S; sf.Nskew = Nk;
  sb = dbar_system(&b, 0); sb.B = Bm;
  CHECK_RC(phgmg_ph_validate(&sf, 0.0, NULL, NULL), PHGMG_OK);
  en.H = Hn; en.S = Sn; en.D = Dn;
  CHECK_RC(phgmg_simulate(&sf, X, 0.0, dt, ns, dbar_input, NULL, NULL, X, Y, &en, NULL, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_simulate(&sb, Xb, 0.0, dt, ns, dbar_input, NULL, NULL, Xb, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
  CHECK(memcmp(X, Xb, sizeof(double) * (size_t)N * (ns + 1)) == 0);
  for (k = 0; k <= ns; ++k) {
    phgmg_ph_gradient(&sf, X + (size_t)k * N, z);
    dbar_input(k * dt, u, NULL);
    for (j = 0; j < 2; ++j) {
      double y = 0.0;
      for (i = 0; i < N; ++i) y += (b.B[i + (size_t)j * N] + P[i + (size_t)j * N]) * z[i];
      y += (S[j] + Nk[j]) * u[0] + (S[j + 2] + Nk[j + 2]) * u[1];
      emax = fmax(emax, fabs(y - Y[j + 2 * k]));
      ymax = fmax(ymax, fabs(y));
    }
  }
  CHECK(ymax > 0.0);
  CHECK_LE(emax, 1e-13 * ymax);
  for (k = 0, emax = 0.0; k <= ns; ++k) {
    emax = fmax(emax, fabs(Hn[k] - Hn[0] - Sn[k] + Dn[k]));
    hmax = fmax(hmax, fabs(Hn[k]));
  }
  CHECK(hmax > 0.0 && Dn[ns] > 0.0);
  CHECK_LE(emax, 1e-12 * hmax);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_QM; o.r = 6;   /* feedthrough: linear maps only (tests/test_dissip.c) */
  CHECK_RC(phgmg_reduce(&red, &sf, X, N, ns + 1, &o, NULL, NULL), PHGMG_ERR_UNSUPPORTED);
  CHECK(red == NULL);
  o.method = PHGMG_METHOD_GMG_POD;
  CHECK_RC(phgmg_reduce(&red, &sf, X, N, ns + 1, &o, NULL, NULL), PHGMG_OK);
  CHECK(red && phgmg_reduced_rom(red)->PD != NULL);
  phgmg_reduced_destroy(red);
  red = NULL;
  S[0] = -S[0];   /* indefinite S */
  CHECK_RC(phgmg_ph_validate(&sf, 0.0, NULL, NULL), PHGMG_ERR_FEEDTHROUGH);
  S[0] = -S[0];
  Nk[1] = 0.3;    /* N not skew */
  CHECK_RC(phgmg_ph_validate(&sf, 0.0, NULL, NULL), PHGMG_ERR_FEEDTHROUGH);
  Nk[1] = -0.3;
  S[0] = 1e-3;    /* S below P^T R^+ P: the block is indefinite */
  CHECK_RC(phgmg_ph_validate(&sf, 0.0, NULL, NULL), PHGMG_ERR_FEEDTHROUGH);
  free(C); free(P); free(Bm); free(X); free(Xb); free(Y);
  dbar_free(&b);
}

/* ---- reduced models ------------------------------------------------------------- */
static double rel_err_y(int m, int ns, const double *Y, const double *Yr) {
  double a = 0.0, d = 0.0;
  int k;
  for (k = 0; k < m * ns; ++k) { a += Y[k] * Y[k]; d += (Y[k] - Yr[k]) * (Y[k] - Yr[k]); }
  return sqrt(d / a);
}

/* GMG-POD and SP1 of the descriptor bar: (1) the same reduced outputs as the
   reduction of the equivalent standard system in the same coordinates
   (J_s = E^{-1} J E^{-T}, R_s = E^{-1} R E^{-T}, Q_s = E^T Q, B_s = E^{-1} B,
   formed here with the Gauss-Jordan inverse); (2) the closed forms of the
   derivation: with the co-state test basis W_z^T = (D^T E^T G E D)^{-1}
   (E D)^T G (GMG) resp. W_z = Q V (V^T E^T Q V)^{-1} (SP1): W_z^T E D = I,
   K = W_z^T (J - R) W_z, Bh = W_z^T B (= [I; 0] for GMG), Qh = D^T E^T Q D;
   (3) J-check skew, R-check PSD; (4) the discrete energy balance of the
   reduced model; (5) e_y falls with r. */
static void check_rom_closed_forms(const dbar *b, const phgmg_reduced *red, int gmg) {
  const int N = b->N, m = b->m;
  const phgmg_rom *rom = phgmg_reduced_rom(red);
  const int r = rom->r;
  double *D = (double *)malloc(sizeof(double) * (size_t)N * r), *ED = (double *)malloc(sizeof(double) * (size_t)N * r);
  double *G = (double *)malloc(sizeof(double) * (size_t)N * N), *JR = (double *)malloc(sizeof(double) * (size_t)N * N);
  double *Wz = (double *)malloc(sizeof(double) * (size_t)N * r), *T = (double *)malloc(sizeof(double) * (size_t)N * r);
  double *A = (double *)malloc(sizeof(double) * (size_t)r * r), *Ai = (double *)malloc(sizeof(double) * (size_t)r * r);
  double *Rr = (double *)malloc(sizeof(double) * (size_t)r * r), w[64], xr0[64] = {0};
  double dev = 0.0, kn = 0.0, qn = 0.0;
  int i, j, k;
  for (i = 0; i < N * N; ++i) JR[i] = b->J[i] - b->R[i];
  CHECK(gj_inverse(N, JR, G));
  phgmg_reduced_dphi(red, xr0, D, N);
  for (j = 0; j < r; ++j)
    for (i = 0; i < N; ++i) {
      double s = 0.0;
      for (k = 0; k < N; ++k) s += b->E[i + (size_t)k * N] * D[k + (size_t)j * N];
      ED[i + (size_t)j * N] = s;
    }
  if (gmg) { /* Wz = G^T E D (D^T E^T G E D)^{-T} */
    for (j = 0; j < r; ++j)
      for (i = 0; i < N; ++i) {
        double s = 0.0;
        for (k = 0; k < N; ++k) s += G[k + (size_t)i * N] * ED[k + (size_t)j * N];
        T[i + (size_t)j * N] = s;
      }
    for (j = 0; j < r; ++j)
      for (i = 0; i < r; ++i) {
        double s = 0.0;
        for (k = 0; k < N; ++k) s += T[k + (size_t)i * N] * ED[k + (size_t)j * N];
        A[j + (size_t)i * r] = s;   /* (ED)^T G (ED) */
      }
  } else { /* Wz = Q V (V^T E^T Q V)^{-1} */
    for (j = 0; j < r; ++j)
      for (i = 0; i < N; ++i) {
        double s = 0.0;
        for (k = 0; k < N; ++k) s += b->Q[i + (size_t)k * N] * D[k + (size_t)j * N];
        T[i + (size_t)j * N] = s;
      }
    for (j = 0; j < r; ++j)
      for (i = 0; i < r; ++i) {
        double s = 0.0;
        for (k = 0; k < N; ++k) s += ED[k + (size_t)i * N] * T[k + (size_t)j * N];
        A[j + (size_t)i * r] = s;   /* transposed: (V^T E^T Q V)^T */
      }
  }
  CHECK(gj_inverse(r, A, Ai));
  for (j = 0; j < r; ++j) /* Wz = T A^{-T}, A^{-T} = (A^T)^{-1}: Ai is the inverse of the transposed block */
    for (i = 0; i < N; ++i) {
      double s = 0.0;
      for (k = 0; k < r; ++k) s += T[i + (size_t)k * N] * Ai[k + (size_t)j * r];
      Wz[i + (size_t)j * N] = s;
    }
  for (i = 0; i < r; ++i) /* Wz^T E D = I */
    for (j = 0; j < r; ++j) {
      double s = 0.0;
      for (k = 0; k < N; ++k) s += Wz[k + (size_t)i * N] * ED[k + (size_t)j * N];
      dev = fmax(dev, fabs(s - (i == j ? 1.0 : 0.0)));
    }
  CHECK_LE(dev, 1e-8);
  if (gmg) { /* phgmg_reduced_W: the x-space map W = E^T Wz */
    double *W = (double *)malloc(sizeof(double) * (size_t)N * r), wn = 0.0;
    CHECK_RC(phgmg_reduced_W(red, xr0, W, N), PHGMG_OK);
    dev = 0.0;
    for (j = 0; j < r; ++j)
      for (i = 0; i < N; ++i) {
        double s = 0.0;
        for (k = 0; k < N; ++k) s += b->E[k + (size_t)i * N] * Wz[k + (size_t)j * N];
        dev = fmax(dev, fabs(W[i + (size_t)j * N] - s));
        wn = fmax(wn, fabs(s));
      }
    CHECK_LE(dev, 1e-8 * wn);
    free(W);
  }
  dev = 0.0;
  for (i = 0; i < r; ++i) /* K = Wz^T (J - R) Wz, Qh = D^T E^T Q D */
    for (j = 0; j < r; ++j) {
      double s = 0.0, q = 0.0;
      int l;
      for (k = 0; k < N; ++k) {
        double t1 = 0.0, t2 = 0.0;
        for (l = 0; l < N; ++l) {
          t1 += JR[k + (size_t)l * N] * Wz[l + (size_t)j * N];
          t2 += b->Q[k + (size_t)l * N] * D[l + (size_t)j * N];
        }
        s += Wz[k + (size_t)i * N] * t1;
        q += ED[k + (size_t)i * N] * t2;
      }
      kn = fmax(kn, fabs(s)); qn = fmax(qn, fabs(q));
      dev = fmax(dev, fmax(fabs(rom->K[i + (size_t)j * r] - s), fabs(rom->Qh[i + (size_t)j * r] - q)));
    }
  CHECK_LE(dev, 1e-7 * fmax(kn, qn));
  dev = 0.0;
  for (i = 0; i < r; ++i) /* Bh = Wz^T B */
    for (j = 0; j < m; ++j) {
      double s = 0.0;
      for (k = 0; k < N; ++k) s += Wz[k + (size_t)i * N] * b->B[k + (size_t)j * N];
      dev = fmax(dev, fabs(rom->Bh[i + (size_t)j * r] - s));
      if (gmg) dev = fmax(dev, fabs(rom->Bh[i + (size_t)j * r] - (i == j ? 1.0 : 0.0)));
    }
  CHECK_LE(dev, 1e-8);
  /* J-check skew by construction of the split; R-check = -(K + K^T)/2 PSD */
  for (i = 0; i < r * r; ++i) Rr[i] = -0.5 * (rom->K[i] + rom->K[(i % r) * r + i / r]);
  CHECK_RC(phgmg_sym_eig(r, Rr, r, w, NULL, 0), PHGMG_OK);
  CHECK(w[0] >= -1e-10 * fmax(fabs(w[r - 1]), 1e-300));
  for (i = 0; i < r * r; ++i) Rr[i] = rom->Qh[i];
  CHECK_RC(phgmg_sym_eig(r, Rr, r, w, NULL, 0), PHGMG_OK);
  CHECK(w[0] > 0.0);
  free(D); free(ED); free(G); free(JR); free(Wz); free(T); free(A); free(Ai); free(Rr);
}

TEST(test_descriptor_reduce) {
  dbar b;
  const int n = 30, ns = 400;
  const double dt = 0.05;
  phgmg_ph_system sd, ss;
  double *X, *Y, *Ei, *Js, *Rs, *Qs, *Bs, *T, *YR, *YS;
  double Hn[401], Sn[401], Dn[401];
  phgmg_energy en;
  int N, meth, ri, i, j, k;
  dbar_make(&b, n);
  N = b.N;
  X = (double *)calloc((size_t)N * (ns + 1), sizeof(double));
  Y = (double *)calloc((size_t)2 * (ns + 1), sizeof(double));
  YR = (double *)calloc((size_t)2 * (ns + 1), sizeof(double));
  YS = (double *)calloc((size_t)2 * (ns + 1), sizeof(double));
  Ei = (double *)malloc(sizeof(double) * (size_t)N * N); Js = (double *)malloc(sizeof(double) * (size_t)N * N);
  Rs = (double *)malloc(sizeof(double) * (size_t)N * N); Qs = (double *)malloc(sizeof(double) * (size_t)N * N);
  T = (double *)malloc(sizeof(double) * (size_t)N * N); Bs = (double *)calloc((size_t)N * 2, sizeof(double));
  sd = dbar_system(&b, 0);
  CHECK_RC(phgmg_simulate(&sd, X, 0.0, dt, ns, dbar_input, NULL, NULL, X, Y, NULL, NULL, NULL, NULL), PHGMG_OK);
  /* the equivalent standard system in x */
  CHECK(gj_inverse(N, b.E, Ei));
  mm(N, b.J, 0, Ei, 1, T); mm(N, Ei, 0, T, 0, Js);
  mm(N, b.R, 0, Ei, 1, T); mm(N, Ei, 0, T, 0, Rs);
  mm(N, b.E, 1, b.Q, 0, Qs);
  for (j = 0; j < N; ++j) /* symmetric parts (the products carry round-off) */
    for (i = 0; i < j; ++i) {
      double a = 0.5 * (Js[i + (size_t)j * N] - Js[j + (size_t)i * N]), c = 0.5 * (Rs[i + (size_t)j * N] + Rs[j + (size_t)i * N]);
      double q = 0.5 * (Qs[i + (size_t)j * N] + Qs[j + (size_t)i * N]);
      Js[i + (size_t)j * N] = a; Js[j + (size_t)i * N] = -a;
      Rs[i + (size_t)j * N] = Rs[j + (size_t)i * N] = c;
      Qs[i + (size_t)j * N] = Qs[j + (size_t)i * N] = q;
    }
  for (i = 0; i < N; ++i) Js[i + (size_t)i * N] = 0.0;
  for (j = 0; j < 2; ++j)
    for (i = 0; i < N; ++i)
      for (k = 0; k < N; ++k) Bs[i + (size_t)j * N] += Ei[i + (size_t)k * N] * b.B[k + (size_t)j * N];
  memset(&ss, 0, sizeof ss);
  ss.N = N; ss.m = 2; ss.J = Js; ss.R = Rs; ss.Q = Qs; ss.B = Bs;
  CHECK_RC(phgmg_ph_validate(&ss, 1e-10, NULL, NULL), PHGMG_OK);
  for (meth = 0; meth < 2; ++meth) {
    double prev = HUGE_VAL, e6 = HUGE_VAL;
    for (ri = 0; ri < 3; ++ri) {
      const int rr[3] = {6, 10, 14};
      phgmg_reduce_opts o;
      phgmg_reduced *red = NULL, *res = NULL;
      double ey, xr0[32] = {0};
      memset(&o, 0, sizeof o);
      o.method = meth == 0 ? PHGMG_METHOD_GMG_POD : PHGMG_METHOD_SP1;
      o.r = rr[ri];
      CHECK_RC(phgmg_reduce(&red, &sd, X, N, ns + 1, &o, NULL, NULL), PHGMG_OK);
      CHECK_RC(phgmg_reduce(&res, &ss, X, N, ns + 1, &o, NULL, NULL), PHGMG_OK);
      if (!red || !res) { phgmg_reduced_destroy(red); phgmg_reduced_destroy(res); continue; }
      en.H = Hn; en.S = Sn; en.D = Dn;
      CHECK_RC(phgmg_reduced_simulate(red, xr0, 0.0, dt, ns, dbar_input, NULL, 0.0, 0, NULL, YR, &en, NULL, NULL),
               PHGMG_OK);
      CHECK_RC(phgmg_reduced_simulate(res, xr0, 0.0, dt, ns, dbar_input, NULL, 0.0, 0, NULL, YS, NULL, NULL, NULL),
               PHGMG_OK);
      CHECK_LE(rel_err_y(2, ns + 1, YS, YR), 1e-8);   /* the same model as the standard form's */
      {
        double emax = 0.0, hmax = 0.0;
        for (k = 0; k <= ns; ++k) {
          emax = fmax(emax, fabs(Hn[k] - Hn[0] - Sn[k] + Dn[k]));
          hmax = fmax(hmax, fabs(Hn[k]));
        }
        CHECK(hmax > 0.0);
        CHECK_LE(emax, 1e-11 * hmax);
      }
      check_rom_closed_forms(&b, red, meth == 0);
      ey = rel_err_y(2, ns + 1, Y, YR);
      if (getenv("DESC_VERBOSE")) printf("method %d r %d e_y %.3e\n", meth, rr[ri], ey);
      CHECK_LE(ey, prev);
      if (ri == 0) e6 = ey;
      if (ri == 2) CHECK_LE(ey, 0.35 * e6);   /* r = 14 at least 3x better than r = 6 */
      prev = ey;
      phgmg_reduced_destroy(red);
      phgmg_reduced_destroy(res);
    }
  }
  free(X); free(Y); free(YR); free(YS); free(Ei); free(Js); free(Rs); free(Qs); free(T); free(Bs);
  dbar_free(&b);
}

/* phgmg_e_factor_create: E^{-1} and E^{-T} applied by phgmg_jr_solve, for
   the bar's dense model and for its scrambled sparse form (vectors in the
   sparse model's banded order); the residual ||E x - b|| against ||b||;
   no E, or NULL: PHGMG_ERR_INVALID_ARG. */
TEST(test_descriptor_e_factor) {
  dbar b;
  phgmg_ph_system sd;
  phgmg_ph_sparse *sp = NULL;
  phgmg_jr_factor *f = NULL;
  dcsc cE, cJ, cR, cQ;
  double rhs[64], x[64], xb[64], eN = 0.0, eT = 0.0, bn = 0.0, rcond = 0.0;
  int N, perm[64], i, j, k, t;
  dbar_make(&b, 20);
  N = b.N;
  sd = dbar_system(&b, 0);
  for (i = 0; i < N; ++i) { rhs[i] = sin(1.0 + i); bn = fmax(bn, fabs(rhs[i])); }
  CHECK_RC(phgmg_e_factor_create(&f, &sd, &rcond, NULL), PHGMG_OK);
  CHECK(rcond > 0.0 && rcond <= 1.0);
  for (t = 0; f && t < 2; ++t) {   /* E x = b, E^T x = b */
    memcpy(x, rhs, sizeof(double) * (size_t)N);
    phgmg_jr_solve(f, t ? 'T' : 'N', 1, x, N);
    for (i = 0; i < N; ++i) {
      double r = -rhs[i];
      for (j = 0; j < N; ++j) r += (t ? b.E[j + (size_t)i * N] : b.E[i + (size_t)j * N]) * x[j];
      if (t) eT = fmax(eT, fabs(r)); else eN = fmax(eN, fabs(r));
    }
  }
  CHECK_LE(eN, 1e-13 * bn);
  CHECK_LE(eT, 1e-13 * bn);
  phgmg_jr_factor_destroy(f);
  f = NULL;
  /* the scrambled sparse model: user order -> banded order, solve, back */
  for (i = 0; i < N; ++i) perm[i] = i;
  for (i = N - 1; i > 0; --i) { j = (int)((th_rand() + 1.0) * 0.5 * (i + 1)); if (j > i) j = i; k = perm[i]; perm[i] = perm[j]; perm[j] = k; }
  dcsc_make(&cE, N, b.E, perm); dcsc_make(&cJ, N, b.J, perm); dcsc_make(&cR, N, b.R, perm); dcsc_make(&cQ, N, b.Q, perm);
  {
    double Bp[128];
    for (j = 0; j < 2; ++j) for (i = 0; i < N; ++i) Bp[i + (size_t)j * N] = b.B[perm[i] + (size_t)j * N];
    CHECK_RC(phgmg_ph_sparse_create_e(&sp, N, 2, &cJ.A, &cR.A, &cQ.A, &cE.A, Bp, NULL, NULL, NULL), PHGMG_OK);
  }
  if (sp) {
    CHECK_RC(phgmg_e_factor_create(&f, phgmg_ph_sparse_system(sp), NULL, NULL), PHGMG_OK);
    CHECK_RC(phgmg_ph_sparse_to_banded_order(sp, 1, rhs, N, xb, N), PHGMG_OK);
    if (f) phgmg_jr_solve(f, 'N', 1, xb, N);
    CHECK_RC(phgmg_ph_sparse_to_user_order(sp, 1, xb, N, x, N), PHGMG_OK);
    eN = 0.0;   /* the scrambled E: E_u(i, j) = E(perm[i], perm[j]) */
    for (i = 0; i < N; ++i) {
      double r = -rhs[i];
      for (j = 0; j < N; ++j) r += b.E[perm[i] + (size_t)perm[j] * N] * x[j];
      eN = fmax(eN, fabs(r));
    }
    CHECK_LE(eN, 1e-13 * bn);
  }
  phgmg_jr_factor_destroy(f);
  phgmg_ph_sparse_destroy(sp);
  /* no mass matrix, or no output pointer */
  sd.E = NULL;
  f = (phgmg_jr_factor *)&sd;   /* must come back NULL */
  CHECK_RC(phgmg_e_factor_create(&f, &sd, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK(f == NULL);
  CHECK_RC(phgmg_e_factor_create(NULL, &sd, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  dcsc_free(&cE); dcsc_free(&cJ); dcsc_free(&cR); dcsc_free(&cQ);
  dbar_free(&b);
}

SUITE(descriptor) {
  RUN(test_descriptor_fom_linear);
  RUN(test_descriptor_fom_nonlinear);
  RUN(test_descriptor_hamiltonian);
  RUN(test_descriptor_bad_input);
  RUN(test_descriptor_sparse_scrambled);
  RUN(test_descriptor_feedthrough);
  RUN(test_descriptor_reduce);
  RUN(test_descriptor_e_factor);
}
