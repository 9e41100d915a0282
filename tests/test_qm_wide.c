/* Quadratic manifolds with a wide V2 (opts.qm.rn = PHGMG_RN_WIDE, the default of
   the greedy and alternating-minimization manifolds), on snapshots that lie
   exactly on a quadratic manifold whose quadratic part spans 78 directions
   (more than the 64 an older cap allowed; 240 snapshots): every construction with a wide V2
   reproduces them to round-off, a capped one cannot; the online model (rn =
   78) agrees with H(phi(x)) and D phi^T grad H(phi(x)) computed in full
   dimension, and D phi with central differences of phi (exact for a
   quadratic map); the incremental greedy selection against a direct one. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"

#define QW_N 300
#define QW_P 12
#define QW_NC (QW_P * (QW_P + 1) / 2)
#define QW_NS 240

typedef struct qw_data {
  double J[QW_N], R[QW_N], Q[QW_N], B[QW_N];
  double X[QW_N * QW_NS];
  phgmg_ph_system sys;
} qw_data;

/* x = b u + V1 z + V2 (d .* k(z)): [b, V1, V2] orthonormal (QR of a random
   matrix), k(z) the 78 distinct products z_a z_j, d = 0.02; the snapshots
   come in pairs z, -z (so V1's and V2's coordinates are uncorrelated and the
   leading 12 POD modes of X - b b^T X span V1). */
static void qw_build(qw_data *d) {
  const int k = 1 + QW_P + QW_NC;
  double *A = (double *)malloc(sizeof(double) * QW_N * k), tau[1 + QW_P + QW_NC], work[1 + QW_P + QW_NC];
  int i, j, a, b, c;
  for (i = 0; i < QW_N * k; ++i) A[i] = th_rand();
  phgmg_qr(QW_N, k, A, QW_N, tau);
  phgmg_qr_form_q(QW_N, k, A, QW_N, tau, work);
  for (j = 0; j < QW_NS; j += 2) {
    double z[QW_P], u = th_rand(), *x = d->X + (size_t)j * QW_N, *y = x + QW_N;
    for (a = 0; a < QW_P; ++a) z[a] = th_rand();
    for (i = 0; i < QW_N; ++i) {
      double lin = 0.0, quad = 0.0;
      for (a = 0; a < QW_P; ++a) lin += A[i + (size_t)(1 + a) * QW_N] * z[a];
      for (a = 0, c = 0; a < QW_P; ++a)
        for (b = a; b < QW_P; ++b, ++c) quad += 0.02 * A[i + (size_t)(1 + QW_P + c) * QW_N] * z[a] * z[b];
      x[i] = A[i] * u + lin + quad;
      y[i] = -A[i] * u - lin + quad;
    }
  }
  for (i = 0; i < QW_N; ++i) { d->J[i] = 0.0; d->R[i] = 1.0; d->Q[i] = 1.0; d->B[i] = A[i]; }
  memset(&d->sys, 0, sizeof d->sys);
  d->sys.N = QW_N; d->sys.m = 1; d->sys.storage = PHGMG_BANDED; d->sys.kb = 0;
  d->sys.J = d->J; d->sys.R = d->R; d->sys.Q = d->Q; d->sys.B = d->B;
  free(A);
}

static phgmg_reduced *qw_reduce(const qw_data *d, int manifold, int rn, int window) {
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  phgmg_result rc;
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_QM; o.r = 1 + QW_P; o.qm.rn = rn; o.qm.manifold = manifold; o.qm.lambda = 1e-12;
  o.qm.greedy_window = window;
  rc = phgmg_reduce(&red, &d->sys, d->X, QW_N, QW_NS, &o, NULL, NULL);
  CHECK_RC(rc, PHGMG_OK);
  return rc == PHGMG_OK ? red : NULL;
}

TEST(test_qm_wide_exact_manifold) {
  static qw_data d;
  phgmg_reduced *red;
  int mf;
  qw_build(&d);
  for (mf = PHGMG_MANIFOLD_POD; mf <= PHGMG_MANIFOLD_ALTMIN + 1; ++mf) {   /* + 1: greedy, window 200 */
    red = mf > PHGMG_MANIFOLD_ALTMIN ? qw_reduce(&d, PHGMG_MANIFOLD_GREEDY, 0, 200)
                                     : qw_reduce(&d, mf, mf == PHGMG_MANIFOLD_POD ? PHGMG_RN_WIDE : 0, 0);
    if (!red) continue;
    CHECK(phgmg_reduced_rom(red)->rn == QW_NC);   /* min(rank of the residual, p(p+1)/2) = 78 */
    CHECK_LE(phgmg_err_proj(red, d.X, QW_N, QW_NS), 1e-9);
    phgmg_reduced_destroy(red);
  }
  /* the cap: 8 of the 78 directions -- the orthogonal projection onto
     [B, V1, V2] already misses the rest */
  red = qw_reduce(&d, PHGMG_MANIFOLD_POD, 8, 0);
  if (red) {
    CHECK(phgmg_reduced_rom(red)->rn == 8);
    CHECK(phgmg_err_lowerbound(red, d.X, QW_N, QW_NS) > 1e-3);
    phgmg_reduced_destroy(red);
  }
}

/* rn = 78 > 64: D phi against central differences of phi (exact for a
   quadratic map up to round-off), the online H and gradient against
   H(phi(x)) = |phi(x)|^2 / 2 and D phi^T phi(x) in full dimension. */
TEST(test_qm_wide_online_consistent) {
  static qw_data d;
  static double D[QW_N * (1 + QW_P)], xp[QW_N], xm[QW_N], xf[QW_N];
  phgmg_reduced *red;
  const phgmg_rom *rom;
  double xr[1 + QW_P], h = 1e-3, err = 0.0, sc = 0.0, H = 0.0, gf[1 + QW_P];
  phgmg_real xrr[1 + QW_P], g[1 + QW_P], *work;
  int i, a;
  qw_build(&d);
  red = qw_reduce(&d, PHGMG_MANIFOLD_GREEDY, 0, 0);
  if (!red) return;
  rom = phgmg_reduced_rom(red);
  CHECK(rom->rn == QW_NC);
  for (a = 0; a < 1 + QW_P; ++a) xr[a] = 0.8 * th_rand();
  phgmg_reduced_dphi(red, xr, D, QW_N);
  for (a = 0; a < 1 + QW_P; ++a) {
    const double x0 = xr[a];
    xr[a] = x0 + h; phgmg_reduced_lift(red, xr, xp);
    xr[a] = x0 - h; phgmg_reduced_lift(red, xr, xm);
    xr[a] = x0;
    for (i = 0; i < QW_N; ++i) {
      err = PHGMG__MAX(err, fabs((xp[i] - xm[i]) / (2 * h) - D[i + (size_t)a * QW_N]));
      sc = PHGMG__MAX(sc, fabs(D[i + (size_t)a * QW_N]));
    }
  }
  CHECK_LE(err, 1e-9 * sc);
  phgmg_reduced_lift(red, xr, xf);
  for (i = 0; i < QW_N; ++i) H += 0.5 * xf[i] * xf[i];
  for (a = 0; a < 1 + QW_P; ++a) {
    gf[a] = 0.0;
    for (i = 0; i < QW_N; ++i) gf[a] += D[i + (size_t)a * QW_N] * xf[i];
    xrr[a] = (phgmg_real)xr[a];
  }
  work = (phgmg_real *)malloc(sizeof(phgmg_real) * phgmg_rom_eval_work_size(rom));
  if (!work) { phgmg_reduced_destroy(red); return; }
  CHECK_LE(fabs((double)phgmg_rom_hamiltonian(rom, xrr, work) - H), 1e-10 * H + 1e-12);
  phgmg_rom_gradient(rom, xrr, g, work);
  for (a = 0, err = sc = 0.0; a < 1 + QW_P; ++a) {
    err = PHGMG__MAX(err, fabs((double)g[a] - gf[a]));
    sc = PHGMG__MAX(sc, fabs(gf[a]));
  }
  CHECK_LE(err, 1e-10 * sc);
  free(work);
  phgmg_reduced_destroy(red);
}

/* The incremental greedy selection (greedy_window > 0) against a direct one:
   the same candidates (the leading p + window POD modes of X - b b^T X) and
   the same score -- min_T ||R - K T||_F^2 + lam ||T||_F^2 over the other
   candidates R, by phgmg_lstsq on the features K of the modes taken plus
   the candidate -- computed here from scratch for every trial. */
#define GB_N 60
#define GB_NS 90
#define GB_P 4
#define GB_W 10
TEST(test_qm_greedy_window_matches_direct) {
  static double X[GB_N * GB_NS], Xa[GB_N * GB_NS], U[GB_N * GB_NS], W[GB_NS * GB_NS], S[GB_NS], C[GB_NS * GB_NS];
  static double K[GB_NS * 10], Rt[GB_NS * GB_NS], T[10 * GB_NS];
  double J[GB_N], Rm[GB_N], Qm[GB_N], B[GB_N], lam = 1e-3;
  const int q = GB_P + GB_W;
  int sel[GB_P], used[GB_NS] = {0}, i, j, k, a, b, cc, kk = 0, nr;
  phgmg_ph_system sys;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  for (i = 0; i < GB_N; ++i) { J[i] = 0.0; Rm[i] = 1.0; Qm[i] = 1.0; B[i] = i == 0 ? 1.0 : 0.0; }
  for (j = 0; j < GB_NS; ++j) {   /* harmonics cos(h t), sin(h t), h = 1..12 (a travelling wave's
                                     coordinates: the higher ones are quadratic in the lower), noise */
    const double t = 6.283185307179586 * (j + 0.5) / GB_NS;
    for (i = 0; i < GB_N; ++i) X[i + (size_t)j * GB_N] = 1e-3 * th_rand();
    for (k = 1; k <= 12; ++k) {
      X[2 * k - 1 + (size_t)j * GB_N] += pow(0.93, k) * cos(k * t);
      X[2 * k + (size_t)j * GB_N] += pow(0.93, k) * sin(k * t);
    }
  }
  memcpy(Xa, X, sizeof X);
  for (j = 0; j < GB_NS; ++j) Xa[(size_t)j * GB_N] = 0.0;   /* b = e_1 */
  CHECK_RC(phgmg_svd(GB_N, GB_NS, Xa, GB_N, GB_N, S, U, GB_N, W, GB_NS, &kk, NULL, NULL), PHGMG_OK);
  for (j = 0; j < GB_NS; ++j)
    for (i = 0; i < q; ++i) C[i + (size_t)j * q] = S[i] * W[j + (size_t)i * GB_NS];
  for (j = 0; j < GB_P; ++j) {
    double best = HUGE_VAL;
    int kb = -1;
    for (k = 0; k < q; ++k) {
      double e = 0.0;
      if (used[k]) continue;
      sel[j] = k;
      for (i = 0; i < GB_NS; ++i) {
        const double *c = C + (size_t)i * q;
        for (a = 0, cc = 0; a <= j; ++a)
          for (b = a; b <= j; ++b, ++cc) K[i + (size_t)cc * GB_NS] = (a == b ? 1.0 : sqrt(2.0)) * c[sel[a]] * c[sel[b]];
        for (a = 0, nr = 0; a < q; ++a)
          if (!used[a] && a != k) Rt[i + (size_t)(nr++) * GB_NS] = c[a];
      }
      CHECK_RC(phgmg_lstsq(GB_NS, cc, nr, K, GB_NS, Rt, GB_NS, lam, T, cc, NULL), PHGMG_OK);
      for (a = 0; a < nr; ++a)
        for (i = 0; i < GB_NS; ++i) {
          double d = Rt[i + (size_t)a * GB_NS];
          for (b = 0; b < cc; ++b) d -= K[i + (size_t)b * GB_NS] * T[b + (size_t)a * cc];
          e += d * d;
        }
      for (a = 0; a < cc * nr; ++a) e += lam * T[a] * T[a];
      if (e < best) { best = e; kb = k; }
    }
    sel[j] = kb;
    used[kb] = 1;
  }
  CHECK(sel[0] + sel[1] + sel[2] + sel[3] > 6);   /* not simply the leading modes */
  memset(&sys, 0, sizeof sys);
  sys.N = GB_N; sys.m = 1; sys.storage = PHGMG_BANDED; sys.kb = 0; sys.J = J; sys.R = Rm; sys.Q = Qm; sys.B = B;
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_QM; o.r = 1 + GB_P; o.qm.manifold = PHGMG_MANIFOLD_GREEDY; o.qm.lambda = lam;
  o.qm.greedy_window = GB_W; o.degeneracy_tol = 1e-300;
  CHECK_RC(phgmg_reduce(&red, &sys, X, GB_N, GB_NS, &o, NULL, NULL), PHGMG_OK);
  if (!red) return;
  for (j = 0; j < GB_P; ++j) {   /* V1's column j is +-U(:, sel_j) */
    double d = 0.0;
    for (i = 0; i < GB_N; ++i) d += red->V0[i + (size_t)(1 + j) * GB_N] * U[i + (size_t)sel[j] * GB_N];
    CHECK_LE(1.0 - fabs(d), 1e-8);
  }
  phgmg_reduced_destroy(red);
}

/* manifold = ALTMIN with a wide V2 descends in V1 with V2 = all that V1
   leaves (manual 3.3); it keeps the best V1 seen, so its objective never
   ends above its start. On an advecting pulse (where the hierarchical POD
   manifold is far from what the data allow): started from the POD manifold
   it closes most of the gap to the greedy manifold by itself, and started
   from the greedy manifold (greedy_window > 0) it ends at least as good as
   that -- the same model when no step is kept. */
#define QP_N 400
#define QP_NS 200
TEST(test_qm_altmin_greedy_start) {
  static double X[QP_N * QP_NS], J[QP_N], R[QP_N], Q[QP_N], B[QP_N];
  phgmg_ph_system sys;
  double e[4];
  int i, j, k, sweeps = -1;
  for (j = 0; j < QP_NS; ++j) {
    const double t = 0.08 * j / (QP_NS - 1.0);
    for (i = 0; i < QP_N; ++i) {
      const double x = (double)i / (QP_N - 1), d = x - 0.1 - 10.0 * t;
      X[i + (size_t)j * QP_N] = exp(-d * d / 2e-3);
    }
  }
  for (i = 0; i < QP_N; ++i) { J[i] = 0.0; R[i] = 1.0; Q[i] = 1.0; B[i] = 0.0; }
  B[0] = 1.0;
  memset(&sys, 0, sizeof sys);
  sys.N = QP_N; sys.m = 1; sys.storage = PHGMG_BANDED; sys.kb = 0; sys.J = J; sys.R = R; sys.Q = Q; sys.B = B;
  for (k = 0; k < 4; ++k) {   /* POD manifold, altmin cold, greedy window 40, altmin window 40 */
    phgmg_reduce_opts o;
    phgmg_reduce_info inf;
    phgmg_reduced *red = NULL;
    memset(&o, 0, sizeof o);
    o.method = PHGMG_METHOD_GMG_QM; o.r = 10; o.qm.rn = PHGMG_RN_WIDE; o.qm.lambda = 1e-9; o.degeneracy_tol = 1e-300;
    o.qm.manifold = k == 0 ? PHGMG_MANIFOLD_POD : k == 2 ? PHGMG_MANIFOLD_GREEDY : PHGMG_MANIFOLD_ALTMIN;
    o.qm.greedy_window = k >= 2 ? 40 : 0;
    CHECK_RC(phgmg_reduce(&red, &sys, X, QP_N, QP_NS, &o, &inf, NULL), PHGMG_OK);
    e[k] = red ? phgmg_err_proj(red, X, QP_N, QP_NS) : 1.0;
    if (k == 1 || k == 3) CHECK(inf.manifold_obj <= inf.manifold_obj0);
    if (k == 1) CHECK(inf.manifold_sweeps > 0);
    if (k == 3) sweeps = inf.manifold_sweeps;
    phgmg_reduced_destroy(red);
  }
  CHECK_LE(e[2], 0.05 * e[0]);        /* the greedy manifold: far below the POD manifold */
  CHECK_LE(e[1], 0.01 * e[0]);        /* from the POD manifold: most of the gap closed (measured 1e-4 x) */
  CHECK_LE(e[1], e[2]);               /* ... and below the greedy manifold (measured 0.008 x) */
  if (sweeps == 0) CHECK(e[3] == e[2]);
  else CHECK_LE(e[3], e[2]);
}

/* The gradient of the wide alternating minimization's objective
   (phgmg__awide_eval: the ridge fit eliminated, envelope theorem) against
   central differences of f along tangent directions D = (I - Q1 Q1^T) Y:
   d/ds f(orth(Q1 + s D)) at s = 0 is <g, D> (the polar retraction agrees with
   Q1 + s D to second order). Random coordinates S, lam = 1e-3 (a smooth f). */
TEST(test_qm_altmin_wide_gradient) {
  enum { q = 14, ns = 60, p = 4, nc = p * (p + 1) / 2 };
  static double S[q * ns], Q1[q * p], g[q * p], D[q * p], Qs[q * p], Pu[q * p], Pv[p * p], Psv[p], t[p * p];
  static double Z[p * ns], Kt[ns * nc], Rt[ns * q], T[nc * q], E[q * ns], Gam[nc * ns], L[p * ns];
  phgmg__awide w;
  double f, fp, fm, dd;
  int i, trial;
  for (i = 0; i < q * ns; ++i) S[i] = th_rand() * (1.0 + (i % q));
  for (i = 0; i < q * p; ++i) D[i] = th_rand();
  CHECK_RC(phgmg__polar(q, p, D, Pu, Pv, Psv, Q1, NULL), PHGMG_OK);
  memset(&w, 0, sizeof w);
  w.q = q; w.ns = ns; w.p = p; w.nc = nc; w.lam = 1e-3; w.S = S;
  w.Z = Z; w.Kt = Kt; w.Rt = Rt; w.T = T; w.E = E; w.Gam = Gam; w.L = L; w.Pu = Pu; w.Pv = Pv; w.Psv = Psv;
  CHECK_RC(phgmg__awide_eval(&w, Q1, &f, g), PHGMG_OK);
  for (trial = 0; trial < 3; ++trial) {
    const double h = 1e-5;
    for (i = 0; i < q * p; ++i) D[i] = th_rand();
    phgmg_gemm('T', 'N', p, p, q, 1.0, Q1, q, D, q, 0.0, t, p);
    phgmg_gemm('N', 'N', q, p, p, -1.0, Q1, q, t, p, 1.0, D, q);
    dd = phgmg__dot(q * p, g, D);
    for (i = 0; i < q * p; ++i) Qs[i] = Q1[i] + h * D[i];
    CHECK_RC(phgmg__polar(q, p, Qs, Pu, Pv, Psv, Qs, NULL), PHGMG_OK);
    CHECK_RC(phgmg__awide_eval(&w, Qs, &fp, NULL), PHGMG_OK);
    for (i = 0; i < q * p; ++i) Qs[i] = Q1[i] - h * D[i];
    CHECK_RC(phgmg__polar(q, p, Qs, Pu, Pv, Psv, Qs, NULL), PHGMG_OK);
    CHECK_RC(phgmg__awide_eval(&w, Qs, &fm, NULL), PHGMG_OK);
    CHECK_LE(fabs((fp - fm) / (2.0 * h) - dd), 1e-6 * fabs(dd) + 1e-9 * f);
    CHECK(fabs(dd) > 1e-3 * f);   /* a direction along which f does change */
  }
}

TEST(test_qm_wide_bad_rn) {
  static qw_data d;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  qw_build(&d);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_QM; o.r = 1 + QW_P; o.qm.rn = -2;
  CHECK_RC(phgmg_reduce(&red, &d.sys, d.X, QW_N, QW_NS, &o, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK(red == NULL);
}

SUITE(qm_wide) {
  RUN(test_qm_wide_exact_manifold);
  RUN(test_qm_wide_online_consistent);
  RUN(test_qm_greedy_window_matches_direct);
  RUN(test_qm_wide_bad_rn);
  RUN(test_qm_altmin_greedy_start);
  RUN(test_qm_altmin_wide_gradient);
}
