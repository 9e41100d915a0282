/* Defects of the library's C API found by trying it as a new user and as an
   attacker would (third sweep): one regression test per defect fixed, each
   failing on the code before the fix. The command line's items are checked
   in tests/test_cli.sh. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>

#include "fixture_msd.h"
static double d3_amp = 1.0;
static void d3_u_sin(double t, double *u, void *user) { (void)user; u[0] = d3_amp * sin(t); }

/* Snapshots of the chain driven by sin (amplitude 1) and a GMG-POD model of order r. */
static phgmg_reduced *d3_reduce(dmodel *t, int n, int ns, int r, phgmg_method meth, double **Xo) {
  const int N = 2 * n;
  double *X = (double *)calloc((size_t)N * ns, sizeof(double)), *x0 = (double *)calloc((size_t)N, sizeof(double));
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  dmodel_msd(t, n);
  d3_amp = 1.0;
  CHECK_RC(phgmg_simulate(&t->sys, x0, 0.0, 0.1, ns - 1, d3_u_sin, NULL, NULL, X, NULL, NULL, NULL, NULL, NULL),
           PHGMG_OK);
  memset(&o, 0, sizeof o);
  o.method = meth; o.r = r;
  CHECK_RC(phgmg_reduce(&red, &t->sys, X, N, ns, &o, NULL, NULL), PHGMG_OK);
  free(x0);
  if (Xo) *Xo = X; else free(X);
  return red;
}

/* The error norms do not depend on the data's magnitude (the chain is
   linear and x0 = 0, so an input a times larger gives states and outputs a
   times larger: e_red, e_y, e_proj are invariant; a = 2^k keeps every
   product exact). At a = 2^-530 the plain squares underflow, at 2^510 their
   sums overflow (the energy, one column's quadratic form, still does not);
   at 2^530 the energy overflows: PHGMG_ERR_OVERFLOW, not "out of memory". */
TEST(test_defect3_validate_scaled_norms) {
  dmodel t;
  phgmg_reduced *red = d3_reduce(&t, 10, 201, 4, PHGMG_METHOD_GMG_POD, NULL);
  phgmg_run run;
  phgmg_validation v1, v;
  const int ex[3] = {-530, 510, 530};
  int k;
  memset(&run, 0, sizeof run);
  run.u = d3_u_sin; run.dt = 0.1; run.nsteps = 200;
  d3_amp = 1.0;
  CHECK_RC(phgmg_reduced_validate(red, &t.sys, &run, 0.0, 0, 0.5, &v1, NULL), PHGMG_OK);
  CHECK(v1.pass == 1 && v1.e_y > 0.0 && v1.e_red > 0.0);
  for (k = 0; k < 3; ++k) {
    d3_amp = ldexp(1.0, ex[k]);
    CHECK_RC(phgmg_reduced_validate(red, &t.sys, &run, 0.0, 0, 0.5, &v, NULL),
             (ex[k] == 530 ? PHGMG_ERR_OVERFLOW : PHGMG_OK));
    CHECK_LE(fabs(v.e_red - v1.e_red), 1e-9 * v1.e_red);
    CHECK_LE(fabs(v.e_y - v1.e_y), 1e-9 * v1.e_y);
    CHECK_LE(fabs(v.e_proj - v1.e_proj), 1e-9 * v1.e_proj);
    CHECK(v.pass == (ex[k] != 530));
  }
  /* the public measures directly: phgmg_rel_error of a and a (1 + 2^-3) is 2^-3 */
  {
    double A[3], B[3];
    const double sc[3] = {1e-300, 1.0, 1e300};
    for (k = 0; k < 3; ++k) {
      A[0] = sc[k]; A[1] = -2.0 * sc[k]; A[2] = 0.5 * sc[k];
      B[0] = A[0] * 1.125; B[1] = A[1] * 1.125; B[2] = A[2] * 1.125;
      CHECK_LE(fabs(phgmg_rel_error(3, 1, A, 3, B, 3) - 0.125), 1e-15);
    }
  }
  d3_amp = 1.0;
  phgmg_reduced_destroy(red);
  dmodel_free(&t);
}

/* A GENERAL nonlinear part whose H_nl is NaN (gradient and Hessian zero: the
   dynamics stay the chain's) must not pass validation; nor may a run of zero
   steps, which compares nothing. */
static double d3_h_nan(const double *x, void *user) { (void)x; (void)user; return (double)NAN; }
static int d3_nN;
static void d3_g_zero(const double *x, double *g, void *user) { (void)x; (void)user; memset(g, 0, sizeof(double) * (size_t)d3_nN); }
static void d3_h_zero(const double *x, double *Hs, void *user) {
  (void)x; (void)user; memset(Hs, 0, sizeof(double) * (size_t)d3_nN * (size_t)d3_nN);
}
TEST(test_defect3_validate_nan_energy) {
  dmodel t;
  double *X;
  phgmg_reduced *red = d3_reduce(&t, 5, 101, 4, PHGMG_METHOD_GMG_POD, &X);
  phgmg_ph_system g = t.sys;
  phgmg_reduced *rg = NULL;
  phgmg_reduce_opts o;
  phgmg_run run;
  phgmg_validation v;
  memset(&run, 0, sizeof run);
  run.u = d3_u_sin; run.dt = 0.1; run.nsteps = 0;
  CHECK_RC(phgmg_reduced_validate(red, &t.sys, &run, 0.0, 0, 0.5, &v, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK(v.pass == 0);
  d3_nN = 10;
  g.nl = PHGMG_NL_GENERAL; g.H_nl = d3_h_nan; g.grad_nl = d3_g_zero; g.hess_nl = d3_h_zero;
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = 4;
  CHECK_RC(phgmg_reduce(&rg, &g, X, 10, 101, &o, NULL, NULL), PHGMG_OK);
  run.nsteps = 50;
  if (rg) {
    CHECK_RC(phgmg_reduced_validate(rg, &g, &run, 0.0, 0, 0.5, &v, NULL), PHGMG_ERR_NANINF);
    CHECK(v.pass == 0);
  }
  phgmg_reduced_destroy(rg);
  phgmg_reduced_destroy(red);
  free(X);
  dmodel_free(&t);
}

/* ECSW is scale-invariant: exact data (target = Gm w0 with w0 >= 0 on 5 of
   30 terms) times 1e-200 or 1e160 -- the Gram matrix of the scaled data
   underflows or overflows -- give the points of the unscaled problem, the
   same weights and a residual within tol; Gm alone scaled by 1e-200 gives
   the weights times 1e200. A tolerance below the rounding level is refused
   by its own code, a negative one as a bad argument. */
TEST(test_defect3_ecsw_scale) {
  enum { M = 40, NT = 30 };
  static double G[M * NT], t[M], Gs[M * NT], ts[M], w[NT], ws[NT];
  int pts[NT], pts2[NT], nd = 0, nd2 = 0, i, j, k;
  double res = 1.0, res2 = 1.0;
  const double sc[2] = {1e-200, 1e160};
  const int sup[5] = {2, 7, 11, 19, 26};
  for (i = 0; i < M * NT; ++i) G[i] = th_rand();
  for (i = 0; i < M; ++i) {
    t[i] = 0.0;
    for (k = 0; k < 5; ++k) t[i] += (1.0 + 0.5 * k) * G[i + sup[k] * M];
  }
  CHECK_RC(phgmg_ecsw(NT, M, G, M, t, 1e-10, pts, w, &nd, &res, NULL), PHGMG_OK);
  CHECK(nd >= 1 && res <= 1e-10);
  for (k = 0; k < 2; ++k) {
    for (i = 0; i < M * NT; ++i) Gs[i] = sc[k] * G[i];
    for (i = 0; i < M; ++i) ts[i] = sc[k] * t[i];
    nd2 = 0; res2 = 1.0;
    CHECK_RC(phgmg_ecsw(NT, M, Gs, M, ts, 1e-10, pts2, ws, &nd2, &res2, NULL), PHGMG_OK);
    CHECK(nd2 == nd && res2 <= 1e-10);
    for (j = 0; j < nd && j < nd2; ++j) {
      CHECK(pts2[j] == pts[j]);
      CHECK_LE(fabs(ws[j] - w[j]), 1e-8 * w[j]);
    }
  }
  for (i = 0; i < M * NT; ++i) Gs[i] = 1e-200 * G[i];
  nd2 = 0;
  CHECK_RC(phgmg_ecsw(NT, M, Gs, M, t, 1e-10, pts2, ws, &nd2, &res2, NULL), PHGMG_OK);
  CHECK(nd2 == nd);
  for (j = 0; j < nd && j < nd2; ++j) CHECK(pts2[j] == pts[j] && fabs(ws[j] * 1e-200 - w[j]) <= 1e-8 * w[j]);
  CHECK_RC(phgmg_ecsw(NT, M, G, M, t, 1e-300, pts2, ws, &nd2, &res2, NULL), PHGMG_ERR_TOL_UNREACHABLE);
  CHECK_RC(phgmg_ecsw(NT, M, G, M, t, -1e-6, pts2, ws, &nd2, &res2, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK(strstr(phgmg_result_string(PHGMG_ERR_TOL_UNREACHABLE), "tolerance") != NULL);
  /* the separable form (the reduction's default hyper-reduction): gradients
     F of 30 terms at 40 snapshots, scaled by 1e-170 -- the same points */
  {
    static double F[NT * M], Fs[NT * M], Vt[NT * 3];
    for (i = 0; i < NT * 3; ++i) Vt[i] = th_rand();
    for (i = 0; i < NT * M; ++i) { F[i] = th_rand(); Fs[i] = 1e-170 * F[i]; }
    CHECK_RC(phgmg_ecsw_separable(NT, M, F, NT, 3, Vt, NT, NULL, 1e-6, pts, w, &nd, &res, NULL), PHGMG_OK);
    CHECK_RC(phgmg_ecsw_separable(NT, M, Fs, NT, 3, Vt, NT, NULL, 1e-6, pts2, ws, &nd2, &res2, NULL), PHGMG_OK);
    CHECK(nd2 == nd && res2 <= 1e-6);
    for (j = 0; j < nd && j < nd2; ++j) CHECK(pts2[j] == pts[j] && fabs(ws[j] - w[j]) <= 1e-8 * w[j]);
    CHECK_RC(phgmg_ecsw_separable(NT, M, F, NT, 3, Vt, NT, NULL, 1e-300, pts, w, &nd, &res, NULL),
             PHGMG_ERR_TOL_UNREACHABLE);
  }
}

/* lambda exactly zero (opts.qm.lambda < 0): the unregularised quadratic fit is
   the minimum-norm least-squares solution, also when its Kronecker matrix is
   rank deficient or has fewer rows than columns, instead of "rank
   deficient". The helper against the closed form A^+ B of a rank-2 matrix
   A = Q1 diag(3, 1/2) Q2^T (Q1, Q2 orthonormal); the reduction on 21
   snapshots at r = 8 (36 Kronecker columns for 21 rows). */
TEST(test_defect3_lambda_zero) {
  double A[6 * 4], Bm[6 * 2], X[4 * 2], Xe[4 * 2];
  const double s6 = 1.0 / sqrt(6.0), q1[2][6] = {{1, 1, 1, 1, 1, 1}, {1, -1, 1, -1, 1, -1}};
  const double q2[2][4] = {{0.5, 0.5, 0.5, 0.5}, {0.5, -0.5, -0.5, 0.5}}, sg[2] = {3.0, 0.5};
  int i, j, k, c;
  dmodel t;
  double *Xs;
  phgmg_reduced *red = NULL;
  phgmg_reduce_opts o;
  for (i = 0; i < 6; ++i)
    for (j = 0; j < 4; ++j) {
      A[i + 6 * j] = 0.0;
      for (k = 0; k < 2; ++k) A[i + 6 * j] += q1[k][i] * s6 * sg[k] * q2[k][j];
    }
  for (i = 0; i < 12; ++i) Bm[i] = th_rand();
  for (c = 0; c < 2; ++c)   /* Xe = Q2 diag(1/3, 2) Q1^T B */
    for (j = 0; j < 4; ++j) {
      Xe[j + 4 * c] = 0.0;
      for (k = 0; k < 2; ++k) {
        double d = 0.0;
        for (i = 0; i < 6; ++i) d += q1[k][i] * s6 * Bm[i + 6 * c];
        Xe[j + 4 * c] += q2[k][j] * d / sg[k];
      }
    }
  CHECK_RC(phgmg_lstsq(6, 4, 2, A, 6, Bm, 6, 0.0, X, 4, NULL), PHGMG_ERR_RANK);   /* the plain solver's contract */
  CHECK_RC(phgmg__lstsq_fit(6, 4, 2, A, Bm, 0.0, X, NULL), PHGMG_OK);
  for (i = 0; i < 8; ++i) CHECK_LE(fabs(X[i] - Xe[i]), 1e-13);
  memset(&o, 0, sizeof o);
  dmodel_msd(&t, 10);
  Xs = (double *)calloc((size_t)20 * 21, sizeof(double));
  {
    double x0[20] = {0};
    CHECK_RC(phgmg_simulate(&t.sys, x0, 0.0, 0.1, 20, d3_u_sin, NULL, NULL, Xs, NULL, NULL, NULL, NULL, NULL),
             PHGMG_OK);
  }
  o.method = PHGMG_METHOD_GMG_QM; o.r = 8; o.qm.rn = 4; o.qm.lambda = -1.0;
  CHECK_RC(phgmg_reduce(&red, &t.sys, Xs, 20, 21, &o, NULL, NULL), PHGMG_OK);
  if (red) CHECK_LE(phgmg_err_proj(red, Xs, 20, 21), 1e-6);
  phgmg_reduced_destroy(red);
  free(Xs);
  dmodel_free(&t);
}

/* The exact GL3 step map of a dissipative model for a huge dt: the 3-stage
   Gauss method is A-stable, its stability function R(z) (the (3,3) Pade
   approximant of e^z) has |R(z)| <= 1 for Re z <= 0 and R(inf) = -1, so the
   map contracts in the energy norm: H(Phi x) <= H(x), H = x^T Qh x / 2, and
   tends to -I as dt -> inf (Jf = K Qh nonsingular). The old form
   x + h sum b_i Jf Y_i cancelled: a map growing by 1e84 per step at dt =
   1e100. A map that grows is refused (phgmg__step_map_check). */
TEST(test_defect3_step_map_huge_dt) {
  dmodel t;
  double *X, x[6], y[6], Phi1[36], I6[36];
  const double dts[3] = {1e15, 1e100, 1e300};
  int k, a, b, it;
  phgmg_reduced *red0 = d3_reduce(&t, 10, 301, 6, PHGMG_METHOD_GMG_POD, &X);
  phgmg_reduce_opts o;
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = 6;
  for (k = 0; k < 3; ++k) {
    phgmg_reduced *red = NULL;
    const phgmg_rom *rom;
    double worst = 0.0, dev = 0.0;
    o.dt = dts[k];
    CHECK_RC(phgmg_reduce(&red, &t.sys, X, 20, 301, &o, NULL, NULL), PHGMG_OK);
    if (!red) continue;
    rom = phgmg_reduced_rom(red);
    for (it = 0; it < 50; ++it) {   /* H(Phi x) / H(x) over random x */
      double hx = 0.0, hy = 0.0;
      for (a = 0; a < 6; ++a) x[a] = th_rand();
      for (a = 0; a < 6; ++a) { y[a] = 0.0; for (b = 0; b < 6; ++b) y[a] += rom->Phi[a + 6 * b] * x[b]; }
      for (a = 0; a < 6; ++a)
        for (b = 0; b < 6; ++b) { hx += x[a] * rom->Qh[a + 6 * b] * x[b]; hy += y[a] * rom->Qh[a + 6 * b] * y[b]; }
      worst = fmax(worst, hy / hx);
    }
    CHECK_LE(worst, 1.0 + 1e-9);
    for (a = 0; a < 36; ++a) dev = fmax(dev, fabs(rom->Phi[a] + (a % 7 == 0 ? 1.0 : 0.0)));
    CHECK_LE(dev, 1e-6);   /* Phi = R(h Jf) -> R(inf) I = -I */
    phgmg_reduced_destroy(red);
  }
  /* the check: a map 1.1 I of the same (dissipative) model grows */
  {
    const phgmg_rom *r0 = phgmg_reduced_rom(red0);
    double w[5 * 36 + 6], Kd[36], Qd[36];
    for (a = 0; a < 36; ++a) {
      Kd[a] = r0->K[a]; Qd[a] = r0->Qh[a];
      Phi1[a] = a % 7 == 0 ? 1.1 : 0.0; I6[a] = a % 7 == 0 ? 0.999 : 0.0;
    }
    CHECK_RC(phgmg__step_map_check(6, Kd, Qd, Phi1, w), PHGMG_ERR_STEP_MAP);
    CHECK_RC(phgmg__step_map_check(6, Kd, Qd, I6, w), PHGMG_OK);
  }
  phgmg_reduced_destroy(red0);
  free(X);
  dmodel_free(&t);
}

/* Option checks as strict as the other entry points': phgmg_linear_basis
   refuses what it used to replace by defaults; phgmg_deim_select tol NaN /
   >= 1 / < 0 and kmax < 0; phgmg_nnls leaves x alone when it refuses;
   phgmg_study_create refuses unknown flag bits; phgmg_lyap a non-symmetric
   right-hand side; phgmg_care on an unstabilizable pair says so. */
TEST(test_defect3_argument_checks) {
  dmodel t;
  double *V, F[6 * 4], w[6], A2[4], K2[4], L2[4], X2[4], x[3], An[6];
  int pts[6], nd, nneg, k, i;
  double sig;
  phgmg_basis_opts bo;
  phgmg_study *st = NULL;
  phgmg_study_opts so;
  double *Xs;
  phgmg_reduced *red = d3_reduce(&t, 5, 101, 4, PHGMG_METHOD_GMG_POD, &Xs);
  V = (double *)calloc((size_t)10 * 4, sizeof(double));
  CHECK_RC(phgmg_linear_basis(&t.sys, PHGMG_BASIS_FREQ, 4, NULL, V, &k, NULL), PHGMG_OK);
  memset(&bo, 0, sizeof bo); bo.nw = -1;
  CHECK_RC(phgmg_linear_basis(&t.sys, PHGMG_BASIS_FREQ, 4, &bo, V, &k, NULL), PHGMG_ERR_INVALID_ARG);
  memset(&bo, 0, sizeof bo); bo.wmin = 10.0; bo.wmax = 1.0;
  CHECK_RC(phgmg_linear_basis(&t.sys, PHGMG_BASIS_FREQ, 4, &bo, V, &k, NULL), PHGMG_ERR_INVALID_ARG);
  memset(&bo, 0, sizeof bo); bo.wmin = (double)NAN;
  CHECK_RC(phgmg_linear_basis(&t.sys, PHGMG_BASIS_FREQ, 4, &bo, V, &k, NULL), PHGMG_ERR_INVALID_ARG);
  memset(&bo, 0, sizeof bo); bo.wmax = 1e9;   /* one end given: the other from the system */
  CHECK_RC(phgmg_linear_basis(&t.sys, PHGMG_BASIS_FREQ, 4, &bo, V, &k, NULL), PHGMG_OK);
  memset(&bo, 0, sizeof bo); bo.dt = -0.1;
  CHECK_RC(phgmg_linear_basis(&t.sys, PHGMG_BASIS_IMPULSE, 4, &bo, V, &k, NULL), PHGMG_ERR_INVALID_ARG);
  memset(&bo, 0, sizeof bo); bo.nsteps = -5;
  CHECK_RC(phgmg_linear_basis(&t.sys, PHGMG_BASIS_IMPULSE, 4, &bo, V, &k, NULL), PHGMG_ERR_INVALID_ARG);
  {
    double *V0 = (double *)malloc(sizeof(double) * 40);
    for (i = 0; i < 40; ++i) V0[i] = (double)NAN;
    memset(&bo, 0, sizeof bo); bo.V0 = V0; bo.maxit = 3;
    CHECK_RC(phgmg_linear_basis(&t.sys, PHGMG_BASIS_H2, 4, &bo, V, &k, NULL), PHGMG_ERR_NANINF);
    free(V0);
  }
  /* DEIM selection */
  for (i = 0; i < 24; ++i) F[i] = th_rand();
  CHECK_RC(phgmg_deim_select(6, 4, F, 6, NULL, 1e-8, 0, PHGMG_DEIM_QDEIM, pts, w, &nd, &nneg, &sig, NULL), PHGMG_OK);
  CHECK_RC(phgmg_deim_select(6, 4, F, 6, NULL, (double)NAN, 0, PHGMG_DEIM_QDEIM, pts, w, &nd, &nneg, &sig, NULL),
           PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_deim_select(6, 4, F, 6, NULL, 1.0, 0, PHGMG_DEIM_QDEIM, pts, w, &nd, &nneg, &sig, NULL),
           PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_deim_select(6, 4, F, 6, NULL, 1e-8, -1, PHGMG_DEIM_GREEDY, pts, w, &nd, &nneg, &sig, NULL),
           PHGMG_ERR_INVALID_ARG);
  /* NNLS: refused without writing x */
  for (i = 0; i < 6; ++i) An[i] = th_rand();
  x[0] = x[1] = x[2] = 7.0;
  CHECK_RC(phgmg_nnls(2, 3, An, 2, w, (double)NAN, 0, x, NULL, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_nnls(2, 3, An, 2, w, 1e-6, -1, x, NULL, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK(x[0] == 7.0 && x[1] == 7.0 && x[2] == 7.0);
  /* study flags */
  memset(&so, 0, sizeof so);
  so.kmax = 4; so.what = PHGMG_STUDY_GMG | 64u;
  CHECK_RC(phgmg_study_create(&st, &t.sys, Xs, 10, 101, &so, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK(st == NULL);
  /* Lyapunov with F not symmetric; A = -I: X = F / 2 if F were symmetric */
  A2[0] = -1; A2[1] = 0; A2[2] = 0; A2[3] = -1;
  K2[0] = 1; K2[1] = 0.4; K2[2] = 0; K2[3] = 1;
  CHECK_RC(phgmg_lyap(2, A2, K2, X2, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  K2[2] = 0.4;
  CHECK_RC(phgmg_lyap(2, A2, K2, X2, NULL, NULL), PHGMG_OK);
  CHECK_LE(fabs(X2[2] - 0.2), 1e-12);
  /* Riccati with A = diag(1, -1) and K = diag(0, 1) (input only to the
     stable mode), L = I: the unstable mode cannot be stabilized */
  A2[0] = 1; A2[1] = 0; A2[2] = 0; A2[3] = -1;
  K2[0] = 0; K2[1] = 0; K2[2] = 0; K2[3] = 1;
  L2[0] = 1; L2[1] = 0; L2[2] = 0; L2[3] = 1;
  CHECK_RC(phgmg_care(2, A2, K2, L2, X2, NULL, NULL), PHGMG_ERR_NOT_STABILIZABLE);
  K2[0] = 1;   /* stabilizable: X = diag(1 + sqrt 2, sqrt 2 - 1) */
  CHECK_RC(phgmg_care(2, A2, K2, L2, X2, NULL, NULL), PHGMG_OK);
  CHECK_LE(fabs(X2[0] - (1.0 + sqrt(2.0))), 1e-10);
  CHECK_LE(fabs(X2[3] - (sqrt(2.0) - 1.0)), 1e-10);
  phgmg_reduced_destroy(red);
  free(V); free(Xs);
  dmodel_free(&t);
}

/* The orderings' row moves of a sparse model in place (X == Y) give what
   they give into a separate array; a partial overlap is refused with Y
   untouched. The model: 6 states whose coupling is the path 0-3-1-4-2-5 in
   the user's numbering (bandwidth 3; reverse Cuthill-McKee reorders it to
   bandwidth 1, so the permutation is not the identity). */
TEST(test_defect3_sparse_order_in_place) {
  enum { N = 6 };
  const int path[N] = {0, 3, 1, 4, 2, 5};
  double Jd[N * N] = {0}, Rd[N * N] = {0}, Qd[N * N] = {0}, B[N] = {1, 0, 0, 0, 0, 0};
  int cp[3][N + 1], ri[3][N * N], k, i, j, c;
  double va[3][N * N], X[N * 2], Yr[N * 2], Z[N * 2 + 1];
  const double *D[3];
  phgmg_csc M[3];
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_sparse_info inf;
  for (k = 0; k + 1 < N; ++k) {
    Jd[path[k] + N * path[k + 1]] = 1.0;
    Jd[path[k + 1] + N * path[k]] = -1.0;
  }
  for (i = 0; i < N; ++i) { Rd[i + N * i] = 0.1; Qd[i + N * i] = 2.0; }
  D[0] = Jd; D[1] = Rd; D[2] = Qd;
  for (c = 0; c < 3; ++c) {   /* dense -> CSC */
    int nz = 0;
    for (j = 0; j < N; ++j) {
      cp[c][j] = nz;
      for (i = 0; i < N; ++i)
        if (D[c][i + N * j] != 0.0) { ri[c][nz] = i; va[c][nz] = D[c][i + N * j]; ++nz; }
    }
    cp[c][N] = nz;
    M[c].n_rows = M[c].n_cols = N; M[c].colptr = cp[c]; M[c].rowidx = ri[c]; M[c].values = va[c];
  }
  CHECK_RC(phgmg_ph_sparse_create(&sp, N, 1, &M[0], &M[1], &M[2], B, NULL, &inf, NULL), PHGMG_OK);
  if (!sp) return;
  CHECK(inf.permuted == 1);
  for (i = 0; i < 2 * N; ++i) X[i] = (double)(i + 1);
  for (k = 0; k < 2; ++k) {
    CHECK_RC(k ? phgmg_ph_sparse_to_user_order(sp, 2, X, N, Yr, N) : phgmg_ph_sparse_to_banded_order(sp, 2, X, N, Yr, N),
             PHGMG_OK);
    memcpy(Z, X, sizeof X);
    CHECK_RC(k ? phgmg_ph_sparse_to_user_order(sp, 2, Z, N, Z, N) : phgmg_ph_sparse_to_banded_order(sp, 2, Z, N, Z, N),
             PHGMG_OK);
    CHECK(memcmp(Z, Yr, sizeof Yr) == 0);
    memcpy(Z, X, sizeof X); Z[2 * N] = -1.0;
    CHECK_RC(k ? phgmg_ph_sparse_to_user_order(sp, 2, Z, N, Z + 1, N)
               : phgmg_ph_sparse_to_banded_order(sp, 2, Z, N, Z + 1, N),
             PHGMG_ERR_INVALID_ARG);
    CHECK(memcmp(Z, X, sizeof X) == 0 && Z[2 * N] == -1.0);
  }
  for (j = 0; j < 2; ++j)   /* to_user undoes to_banded */
    for (i = 0; i < N; ++i) CHECK(Yr[phgmg_ph_sparse_perm(sp)[i] + N * j] == X[i + N * j]);
  CHECK_RC(phgmg_ph_sparse_to_banded_order(sp, -1, X, N, Yr, N), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_ph_sparse_to_banded_order(NULL, 2, X, N, Yr, N), PHGMG_ERR_INVALID_ARG);
  phgmg_ph_sparse_destroy(sp);
}

/* A study keeps blocks of the system it was created for: after Q changed,
   phgmg_study_reduce says so instead of returning a model of the old Q
   (restored, it reduces again, and gives phgmg_reduce's model). */
TEST(test_defect3_study_stale) {
  dmodel t;
  double *Xs;
  phgmg_reduced *red = d3_reduce(&t, 5, 101, 4, PHGMG_METHOD_GMG_POD, &Xs), *r2 = NULL;
  phgmg_study *st = NULL;
  phgmg_study_opts so;
  phgmg_reduce_opts o;
  memset(&so, 0, sizeof so);
  so.kmax = 6;
  CHECK_RC(phgmg_study_create(&st, &t.sys, Xs, 10, 101, &so, NULL), PHGMG_OK);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = 4;
  if (st) {
    t.Q[0] = 1.5;   /* still positive definite */
    CHECK_RC(phgmg_study_reduce(st, &o, &r2, NULL), PHGMG_ERR_STALE);
    CHECK(r2 == NULL);
    phgmg_reduced_destroy(r2); r2 = NULL;
    t.Q[0] = 1.0;
    CHECK_RC(phgmg_study_reduce(st, &o, &r2, NULL), PHGMG_OK);
    if (r2) {
      const phgmg_rom *a = phgmg_reduced_rom(red), *b = phgmg_reduced_rom(r2);
      int i;
      for (i = 0; i < 16; ++i) CHECK_LE(fabs(a->Qh[i] - b->Qh[i]), 1e-12 * (1.0 + fabs(a->Qh[i])));
    }
  }
  phgmg_reduced_destroy(r2);
  phgmg_study_destroy(st);
  phgmg_reduced_destroy(red);
  free(Xs);
  dmodel_free(&t);
}

/* Loading checks the physics, not only the checksum: a model file written
   again (fresh checksum) with K -> -K (energy created), Qh -> -Qh (H
   unbounded below), dt 0.1 -> 1e300 or 0.2 (the step map no longer of its
   dt) is refused with PHGMG_ERR_STRUCTURE; the genuine files (GMG-POD with
   a step map, GMG-QM) load. */
static phgmg_result d3_roundtrip(const phgmg_rom *rom) {
  static unsigned char buf[1 << 16];
  static double mem[1 << 14];
  size_t wr = 0, need = 0;
  phgmg_rom back;
  phgmg_result rc = phgmg_rom_serialize(rom, buf, sizeof buf, &wr);
  if (rc != PHGMG_OK) return rc;
  rc = phgmg_rom_deserialize_size(buf, wr, &need);
  if (rc != PHGMG_OK) return rc;
  if (need > sizeof mem) return PHGMG_ERR_WORKSPACE;
  return phgmg_rom_deserialize(buf, wr, &back, mem, need);
}
TEST(test_defect3_load_structure) {
  dmodel t;
  double *Xs;
  phgmg_reduced *red = NULL, *rq = NULL;
  phgmg_reduce_opts o;
  phgmg_rom cp;
  phgmg_real K2[36], Q2[36];
  int i;
  phgmg_reduced_destroy(d3_reduce(&t, 10, 201, 6, PHGMG_METHOD_GMG_POD, &Xs));   /* the snapshots */
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = 6; o.dt = 0.1;
  CHECK_RC(phgmg_reduce(&red, &t.sys, Xs, 20, 201, &o, NULL, NULL), PHGMG_OK);
  o.method = PHGMG_METHOD_GMG_QM; o.r = 6; o.qm.rn = 4; o.dt = 0.0;
  CHECK_RC(phgmg_reduce(&rq, &t.sys, Xs, 20, 201, &o, NULL, NULL), PHGMG_OK);
  if (red && rq) {
    const phgmg_rom *rom = phgmg_reduced_rom(red);
    CHECK(rom->Phi != NULL);
    CHECK_RC(d3_roundtrip(rom), PHGMG_OK);
    CHECK_RC(d3_roundtrip(phgmg_reduced_rom(rq)), PHGMG_OK);
    cp = *rom;
    for (i = 0; i < 36; ++i) K2[i] = -rom->K[i];
    cp.K = K2;
    CHECK_RC(d3_roundtrip(&cp), PHGMG_ERR_STRUCTURE);
    cp.Phi = cp.Gam = cp.SX = cp.SU = NULL; cp.dt = 0;   /* without the step map: R's check alone */
    CHECK_RC(d3_roundtrip(&cp), PHGMG_ERR_STRUCTURE);
    cp = *rom;
    for (i = 0; i < 36; ++i) Q2[i] = -rom->Qh[i];
    cp.Qh = Q2;
    CHECK_RC(d3_roundtrip(&cp), PHGMG_ERR_STRUCTURE);
    cp = *rom; cp.dt = 1e300;
    CHECK_RC(d3_roundtrip(&cp), PHGMG_ERR_STRUCTURE);
    cp.dt = 0.2;
    CHECK_RC(d3_roundtrip(&cp), PHGMG_ERR_STRUCTURE);
    {   /* GMG-QM: the G blocks' symmetric part turned positive */
      const phgmg_rom *q = phgmg_reduced_rom(rq);
      for (i = 0; i < 36; ++i) K2[i] = -q->G00[i];
      cp = *q; cp.G00 = K2;
      CHECK_RC(d3_roundtrip(&cp), PHGMG_ERR_STRUCTURE);
    }
  }
  phgmg_reduced_destroy(red);
  phgmg_reduced_destroy(rq);
  free(Xs);
  dmodel_free(&t);
}

SUITE(defects3) {
  RUN(test_defect3_validate_scaled_norms);
  RUN(test_defect3_validate_nan_energy);
  RUN(test_defect3_ecsw_scale);
  RUN(test_defect3_lambda_zero);
  RUN(test_defect3_step_map_huge_dt);
  RUN(test_defect3_argument_checks);
  RUN(test_defect3_sparse_order_in_place);
  RUN(test_defect3_study_stale);
  RUN(test_defect3_load_structure);
}
