/* The large-N paths of the reduction, exercised at moderate sizes
   with their thresholds lowered in this file:
   - ECSW with candidate screening (phgmg_ecsw / phgmg_ecsw_separable for many
     terms): w > 0, the residual recomputed here from the explicit training
     rows, against phgmg_nnls (QR-form Lawson-Hanson, an independent path) at
     the same tolerance, and at an unreachable tolerance the KKT conditions
     over ALL terms and the optimal residual of phgmg_nnls;
   - the randomized POD inside phgmg_reduce (large N*ns): the basis against
     the exact SVD of the adjusted snapshots (computed here), and the
     fallback to the exact SVD when the a-posteriori check fails (flat
     spectrum), with the basis then equal to the exact one. */
#include <stdlib.h>
#define PHGMG_ECSW_SCREEN_MIN 64
#define PHGMG_ECSW_SCREEN_ADD 8
#define PHGMG_POD_AUTO_MIN 10000
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "../examples/msd_models.h"
#include "harness.h"

/* Explicit training rows of the separable problem: G (ns r x nt), row
   i r + a = F[k, i] Vt[k, a]; target t = G 1. */
static void sc_rows(int nt, int ns, int r, const double *F, const double *Vt, double *G, double *t) {
  int i, a, k;
  const int m = ns * r;
  for (k = 0; k < nt; ++k)
    for (i = 0; i < ns; ++i)
      for (a = 0; a < r; ++a) G[i * r + a + (size_t)k * m] = F[k + (size_t)i * nt] * Vt[k + (size_t)a * nt];
  for (i = 0; i < m; ++i) {
    t[i] = 0.0;
    for (k = 0; k < nt; ++k) t[i] += G[i + (size_t)k * m];
  }
}

/* ||G x - t|| / ||t|| */
static double sc_rel(int m, int n, const double *G, const double *x, const double *t) {
  double num = 0.0, den = 0.0;
  int i, k;
  for (i = 0; i < m; ++i) {
    double s = -t[i];
    for (k = 0; k < n; ++k) s += G[i + (size_t)k * m] * x[k];
    num += s * s;
    den += t[i] * t[i];
  }
  return sqrt(num / den);
}

TEST(test_ecsw_screened_separable) {
  const int nt = 400, ns = 60, r = 5, m = ns * r;
  double *F = (double *)malloc(sizeof(double) * nt * ns), *Vt = (double *)malloc(sizeof(double) * nt * r);
  double *G = (double *)malloc(sizeof(double) * (size_t)m * nt), *t = (double *)malloc(sizeof(double) * m);
  double *w = (double *)malloc(sizeof(double) * nt), *x = (double *)malloc(sizeof(double) * nt);
  double *xn = (double *)malloc(sizeof(double) * nt), rel = -1.0, rn = 0.0, tn = 0.0;
  int *pts = (int *)malloc(sizeof(int) * nt), nd = 0, nnz = 0, i, k, a;
  const double pi = 3.14159265358979323846;
  /* a travelling smooth wave, cubed (the chain's quartic gradient): smooth in k and i */
  for (i = 0; i < ns; ++i)
    for (k = 0; k < nt; ++k) {
      const double l = sin(0.25 * i - 6.0 * k / nt) * exp(-2.0 * k / nt) + 0.3 * cos(0.11 * i + 3.0 * k / nt);
      F[k + (size_t)i * nt] = l * l * l;
    }
  for (a = 0; a < r; ++a)
    for (k = 0; k < nt; ++k) Vt[k + (size_t)a * nt] = cos(pi * a * (k + 0.5) / nt) / sqrt(0.5 * nt);
  sc_rows(nt, ns, r, F, Vt, G, t);
  CHECK_RC(phgmg_ecsw_separable(nt, ns, F, nt, r, Vt, nt, NULL, 1e-6, pts, w, &nd, &rel, NULL), PHGMG_OK);
  CHECK(nd > 0 && nd < nt / 2);
  for (k = 0; k < nt; ++k) x[k] = 0.0;
  for (i = 0; i < nd; ++i) {
    CHECK(w[i] > 0.0);
    CHECK(pts[i] >= 0 && pts[i] < nt);
    if (i > 0) CHECK(pts[i] > pts[i - 1]);
    x[pts[i]] = w[i];
  }
  /* the residual from the explicit rows: meets the tolerance, as reported */
  CHECK_LE(sc_rel(m, nt, G, x, t), 1e-6);
  CHECK_LE(fabs(sc_rel(m, nt, G, x, t) - rel), 1e-3 * rel + 1e-15);
  /* the exact path: Lawson-Hanson in QR form on the explicit rows, same tolerance */
  for (i = 0; i < m; ++i) tn += t[i] * t[i];
  CHECK_RC(phgmg_nnls(m, nt, G, m, t, 1e-6, 0, xn, &rn, &nnz, NULL), PHGMG_OK);
  CHECK_LE(rn, 1e-6 * sqrt(tn) * (1.0 + 1e-12));
  /* screening finds a quadrature as sparse (within a few points) as the full greedy */
  CHECK_LE(nd, nnz + 4);
  /* the dense-row phgmg_ecsw (also screened here) gives the same terms */
  {
    int *p2 = (int *)malloc(sizeof(int) * nt), nd2 = 0;
    double *w2 = (double *)malloc(sizeof(double) * nt), rel2 = -1.0;
    CHECK_RC(phgmg_ecsw(nt, m, G, m, t, 1e-6, p2, w2, &nd2, &rel2, NULL), PHGMG_OK);
    CHECK(nd2 == nd);
    for (i = 0; i < nd && i < nd2; ++i) {
      CHECK(p2[i] == pts[i]);
      CHECK_LE(fabs(w2[i] - w[i]), 1e-6 * fabs(w[i]));
    }
    free(p2); free(w2);
  }
  free(F); free(Vt); free(G); free(t); free(w); free(x); free(xn); free(pts);
}

/* Terms of very different sizes: 10 large terms whose training columns lie
   in the rows of the first reduced coordinate, and 300 tiny ones (columns
   1e-9 of theirs) in the rows of the second; the target (sum of all) then
   has a part of relative size ~1e-9 * 300 / 10 that only tiny terms can
   fit. Their gradients are far below the large terms' (a threshold relative
   to the largest gradient stops with the tolerance missed), yet far above
   their own rounding level: the screened fit must take them and meet tol.
   The residual is recomputed here from the explicit rows. */
TEST(test_ecsw_screened_tiny_terms) {
  enum { NB = 10, NS = 300, NT = NB + NS, SN = 6, R = 2, M = SN * R };
  static double F[NT * SN], Vt[NT * R], G[M * NT], t[M], w[NT], x[NT];
  static int pts[NT];
  double rel = -1.0;
  int nd = 0, i, k;
  for (k = 0; k < NT; ++k) {
    const double s = k < NB ? 1.0 : 1e-9;
    for (i = 0; i < SN; ++i) F[k + i * NT] = s * (1.0 + 0.5 * sin(1.3 * k + 0.7 * i * (i + 1)));
    Vt[k] = k < NB ? 1.0 : 0.0;
    Vt[k + NT] = k < NB ? 0.0 : 1.0;
  }
  sc_rows(NT, SN, R, F, Vt, G, t);
  CHECK_RC(phgmg_ecsw_separable(NT, SN, F, NT, R, Vt, NT, NULL, 1e-12, pts, w, &nd, &rel, NULL), PHGMG_OK);
  for (k = 0; k < NT; ++k) x[k] = 0.0;
  for (i = 0; i < nd; ++i) {
    CHECK(w[i] > 0.0);
    x[pts[i]] = w[i];
  }
  CHECK_LE(sc_rel(M, NT, G, x, t), 1e-12);
  /* tiny terms were needed: some are kept */
  CHECK(nd > 0 && pts[nd - 1] >= NB);
  /* phgmg_nnls solved to optimality (tol 0) on the explicit rows: the same */
  {
    double rn = -1.0, tn = 0.0;
    int nnz = 0;
    for (i = 0; i < M; ++i) tn += t[i] * t[i];
    CHECK_RC(phgmg_nnls(M, NT, G, M, t, 0.0, 0, x, &rn, &nnz, NULL), PHGMG_OK);
    CHECK_LE(rn, 1e-12 * sqrt(tn));
    CHECK_LE(sc_rel(M, NT, G, x, t), 1e-12);
  }
}

/* Target outside the cone of the columns: tol unreachable. The screened
   solution must be optimal over all n terms (KKT), with phgmg_nnls's residual. */
TEST(test_ecsw_screened_optimal) {
  const int m = 40, n = 200;
  double *G = (double *)malloc(sizeof(double) * m * n), *t = (double *)malloc(sizeof(double) * m);
  double *w = (double *)malloc(sizeof(double) * n), *x = (double *)malloc(sizeof(double) * n);
  double *xn = (double *)malloc(sizeof(double) * n), *res = (double *)malloc(sizeof(double) * m);
  double rel = 0.0, rn = 0.0, tn = 0.0, gmax = 0.0, gscale = 0.0;
  int *pts = (int *)malloc(sizeof(int) * n), nd = 0, i, k;
  for (k = 0; k < n * m; ++k) G[k] = fabs(th_rand()); /* columns in the positive orthant */
  for (i = 0; i < m; ++i) { /* target = G s with signs: entries of both signs, outside the cone */
    t[i] = 0.0;
    for (k = 0; k < n; ++k) t[i] += G[i + (size_t)k * m] * (k % 3 == 0 ? -1.0 : 0.5);
    tn += t[i] * t[i];
  }
  tn = sqrt(tn);
  CHECK_RC(phgmg_ecsw(n, m, G, m, t, 1e-14, pts, w, &nd, &rel, NULL), PHGMG_ERR_NOT_CONVERGED);
  for (k = 0; k < n; ++k) x[k] = 0.0;
  for (i = 0; i < nd; ++i) { CHECK(w[i] > 0.0); x[pts[i]] = w[i]; }
  for (i = 0; i < m; ++i) {
    res[i] = t[i];
    for (k = 0; k < n; ++k) res[i] -= G[i + (size_t)k * m] * x[k];
  }
  for (k = 0; k < n; ++k) { /* KKT: g = G^T (t - G x) <= 0 off the support, = 0 on it */
    double g = 0.0, cn = 0.0;
    for (i = 0; i < m; ++i) { g += G[i + (size_t)k * m] * res[i]; cn += G[i + (size_t)k * m] * G[i + (size_t)k * m]; }
    gscale = fmax(gscale, sqrt(cn) * tn);
    gmax = fmax(gmax, x[k] > 0.0 ? fabs(g) : g);
  }
  CHECK_LE(gmax, 1e-9 * gscale);
  CHECK_RC(phgmg_nnls(m, n, G, m, t, 0.0, 0, xn, &rn, NULL, NULL), PHGMG_OK);
  CHECK_LE(fabs(rel * tn - rn), 1e-8 * tn);
  CHECK(rel > 1e-3); /* really unreachable */
  free(G); free(t); free(w); free(x); free(xn); free(res); free(pts);
}

/* Basis columns V1 (N x p) of a GMG-POD model: lift of unit vectors m..r-1. */
static void sc_basis(const phgmg_reduced *red, int N, int r, int m, double *V1) {
  double xr[64];
  int j;
  for (j = m; j < r; ++j) {
    memset(xr, 0, sizeof xr);
    xr[j] = 1.0;
    phgmg_reduced_lift(red, xr, V1 + (size_t)(j - m) * N);
  }
}

/* ||Ve - V V^T Ve||_F for orthonormal V, Ve (N x p). */
static double sc_subspace(int N, int p, const double *V, const double *Ve) {
  double *C = (double *)malloc(sizeof(double) * p * p), *D = (double *)malloc(sizeof(double) * (size_t)N * p), e;
  memcpy(D, Ve, sizeof(double) * (size_t)N * p);
  phgmg_gemm('T', 'N', p, p, N, 1.0, V, N, Ve, N, 0.0, C, p);
  phgmg_gemm('N', 'N', N, p, p, -1.0, V, N, C, p, 1.0, D, N);
  e = phgmg_normf(N, p, D, N);
  free(C); free(D);
  return e;
}

/* Exact POD of the adjusted snapshots by phgmg_svd: Ve (N x k), s (k). */
static void sc_exact(const phgmg_ph_system *sys, int ns, const double *X, int k, double *Ve, double *s) {
  const int N = sys->N;
  double *Xa = (double *)malloc(sizeof(double) * (size_t)N * ns);
  int kk = 0, rank = 0;
  CHECK_RC(phgmg_adjust_snapshots(N, sys->m, sys->B, ns, X, N, Xa, N, NULL), PHGMG_OK);
  CHECK_RC(phgmg_svd(N, ns, Xa, N, k, s, Ve, N, NULL, 1, &kk, &rank, NULL), PHGMG_OK);
  CHECK(kk == k);
  free(Xa);
}

/* The banded nonlinear chain of n masses (into M; free it with
   msd_nonlinear_free in any case) and its ns snapshots from rest under
   u = 0.1 sin t, dt = 0.1: a malloc'ed N x ns array, NULL on failure. */
static double *sc_chain_run(msd_nonlinear *M, int n, int ns) {
  msd_nl_opts mo;
  phgmg_gl3_opts go;
  double *X, *x0;
  memset(&mo, 0, sizeof mo);
  mo.n = n;
  mo.storage = PHGMG_BANDED;
  if (msd_nonlinear_build(M, &mo) != 0) return NULL;
  X = (double *)malloc(sizeof(double) * (size_t)M->sys.N * ns);
  x0 = (double *)calloc((size_t)M->sys.N, sizeof(double));
  memset(&go, 0, sizeof go);
  go.tol = 1e-10;
  if (X && x0 && phgmg_simulate(&M->sys, x0, 0.0, 0.1, ns - 1, msd_input_sin, NULL, &go, X, NULL, NULL, NULL, NULL,
                                NULL) != PHGMG_OK) {
    free(X);
    X = NULL;
  }
  free(x0);
  return X;
}

/* The system's separable terms listed in reverse (the same model): its new
   sep_idx (malloc'ed). */
static int *sc_reversed_terms(const phgmg_ph_system *sys) {
  int *ridx = (int *)malloc(sizeof(int) * (size_t)sys->nsep), k;
  for (k = 0; ridx && k < sys->nsep; ++k) ridx[k] = sys->sep_idx[sys->nsep - 1 - k];
  return ridx;
}

TEST(test_reduce_pod_randomized_and_fallback) {
  msd_nonlinear M;
  phgmg_reduce_opts o;
  phgmg_reduce_info info;
  phgmg_reduced *red = NULL;
  const int ns = 201, r = 10, p = r - 1;
  double *X = sc_chain_run(&M, 150, ns), *Ve, *V1, s[16];
  int N = M.sys.N, pass; /* N ns = 60300 >= PHGMG_POD_AUTO_MIN here; 4 (p + 1 + 20) <= min(N, ns) */
  CHECK(X != NULL);
  Ve = (double *)malloc(sizeof(double) * (size_t)N * (p + 1));
  V1 = (double *)malloc(sizeof(double) * (size_t)N * p);
  for (pass = 0; X && pass < 2; ++pass) {
    int i;
    if (pass == 1) /* flat spectrum: the randomized range misses; the check must reject it */
      for (i = 0; i < N * ns; ++i) X[i] = th_rand();
    memset(&o, 0, sizeof o);
    o.method = PHGMG_METHOD_GMG_POD;
    o.r = r;
    o.hyper.on = 0;
    memset(&info, 0, sizeof info);
    CHECK_RC(phgmg_reduce(&red, &M.sys, X, N, ns, &o, &info, NULL), PHGMG_OK);
    if (!red) break;
    sc_exact(&M.sys, ns, X, p + 1, Ve, s);
    sc_basis(red, N, r, 1, V1);
    if (pass == 0) {
      CHECK(info.pod_randomized == 1);
      CHECK_LE(info.pod_check, 1e-10);
      CHECK(info.pod_check > 0.0);
      CHECK_LE(sc_subspace(N, p, V1, Ve), 1e-8);
      CHECK_LE(fabs(info.pod_sigma_ratio - s[p] / s[0]), 1e-9 * s[p] / s[0]);
    } else {
      CHECK(info.pod_randomized == -1);
      CHECK(info.pod_check > 1e-10);
      CHECK_LE(sc_subspace(N, p, V1, Ve), 1e-10);     /* the exact basis */
      CHECK_LE(fabs(info.pod_sigma_ratio - s[p] / s[0]), 1e-12);
    }
    phgmg_reduced_destroy(red);
    red = NULL;
  }
  free(X); free(Ve); free(V1);
  msd_nonlinear_free(&M);
}

/* ECSW inside phgmg_reduce fits only the terms that move in some snapshot
   (a zero column is never chosen): on a chain driven at one end for a short
   time most springs stay at rest, and the points and weights must equal
   phgmg_ecsw_separable's on the full gradient matrix of ALL terms, built here.
   The terms are listed in reverse (the same model), so the moving ones are
   the last indices and the compacted fit must map its points back. */
TEST(test_reduce_ecsw_skips_resting_terms) {
  msd_nonlinear M;
  phgmg_reduce_opts o;
  phgmg_reduce_info info;
  phgmg_reduced *red = NULL;
  const phgmg_rom *rom;
  const int ns = 41, r = 8;
  double *X = sc_chain_run(&M, 200, ns), *F, *Vt, *V0, *w, *sw, xr0[8] = {0}, res = 0.0;
  int N = M.sys.N, nt = M.sys.nsep, k, i, a, nd = 0, zero = 0, *pts, *ridx = sc_reversed_terms(&M.sys);
  phgmg_ph_system sys = M.sys;
  sys.sep_idx = ridx;
  CHECK(X != NULL);
  CHECK(M.sys.sep_w == NULL);   /* unit weights: nothing else to reverse */
  F = (double *)malloc(sizeof(double) * (size_t)nt * ns);
  Vt = (double *)malloc(sizeof(double) * (size_t)nt * r);
  V0 = (double *)malloc(sizeof(double) * (size_t)N * r);
  sw = (double *)malloc(sizeof(double) * (size_t)nt);
  w = (double *)malloc(sizeof(double) * (size_t)nt);
  pts = (int *)malloc(sizeof(int) * (size_t)nt);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD;
  o.r = r;
  o.hyper.on = 1;   /* ECSW, the default hyper-reduction */
  memset(&info, 0, sizeof info);
  if (X) CHECK_RC(phgmg_reduce(&red, &sys, X, N, ns, &o, &info, NULL), PHGMG_OK);
  if (red) {
    rom = phgmg_reduced_rom(red);
    phgmg_reduced_dphi(red, xr0, V0, N);
    for (k = 0; k < nt; ++k) {
      int moves = 0;
      for (i = 0; i < ns; ++i) {
        F[k + (size_t)i * nt] = phgmg__ph_phi(&sys, k, X[sys.sep_idx[k] + (size_t)i * N], 1);
        moves |= F[k + (size_t)i * nt] != 0.0;
      }
      zero += !moves;
      for (a = 0; a < r; ++a) Vt[k + (size_t)a * nt] = V0[sys.sep_idx[k] + (size_t)a * N];
      sw[k] = 1.0;
    }
    CHECK(zero > nt / 2);   /* the premise: most springs never move in 4 s */
    CHECK_RC(phgmg_ecsw_separable(nt, ns, F, nt, r, Vt, nt, sw, 0.0, pts, w, &nd, &res, NULL), PHGMG_OK);
    CHECK(rom->nd == nd);
    CHECK(rom->nd > 0);
    for (k = 0; k < nd && k < rom->nd; ++k) {
      CHECK(red->term[k] == pts[k]);   /* the kept terms (rom->term is set for callbacks only) */
      CHECK_LE(fabs((double)rom->w[k] - w[k]), 1e-10 * fabs(w[k]));
    }
    CHECK_LE(fabs(info.hyper_residual - res), 1e-8 * res + 1e-15);
    phgmg_reduced_destroy(red);
  }
  free(X); free(F); free(Vt); free(V0); free(sw); free(w); free(pts); free(ridx);
  msd_nonlinear_free(&M);
}

/* The same for GMG-QM (ECSW of the manifold's training rows): the chain with
   its terms in the given order and in reverse is one model, so both fits keep
   the same springs with the same weights -- the reversed one only through
   the map back from the moving terms (its moving terms are the last ones). */
TEST(test_reduce_ecsw_qm_skips_resting_terms) {
  msd_nonlinear M;
  phgmg_reduce_opts o;
  phgmg_reduced *red[2] = {NULL, NULL};
  const int ns = 41;
  double *X = sc_chain_run(&M, 200, ns);
  int N = M.sys.N, nt = M.sys.nsep, k, v, *ridx = sc_reversed_terms(&M.sys);
  phgmg_ph_system sys[2];
  sys[0] = sys[1] = M.sys;
  sys[1].sep_idx = ridx;
  CHECK(X != NULL);
  for (v = 0; X && v < 2; ++v) {
    memset(&o, 0, sizeof o);
    o.method = PHGMG_METHOD_GMG_QM;
    o.r = 8;
    o.qm.rn = 4;
    o.hyper.on = 1;
    CHECK_RC(phgmg_reduce(&red[v], &sys[v], X, N, ns, &o, NULL, NULL), PHGMG_OK);
  }
  if (red[0] && red[1]) {
    const phgmg_rom *a = phgmg_reduced_rom(red[0]), *b = phgmg_reduced_rom(red[1]);
    CHECK(a->nd == b->nd && a->nd > 0);
    CHECK(red[0]->term[a->nd - 1] < nt / 2);   /* the premise: the moving springs are the first ones */
    for (k = 0; k < a->nd && a->nd == b->nd; ++k) {
      const int kb = b->nd - 1 - k;             /* reversed listing, ascending order */
      CHECK(red[1]->term[kb] == nt - 1 - red[0]->term[k]);
      CHECK_LE(fabs((double)b->w[kb] - (double)a->w[k]), 1e-8 * fabs((double)a->w[k]));
    }
  }
  phgmg_reduced_destroy(red[0]);
  phgmg_reduced_destroy(red[1]);
  free(X); free(ridx);
  msd_nonlinear_free(&M);
}


/* info.pod_sigma_ratio of SP1 and SP2 is sigma_{r+1}/sigma_1 of the snapshot
   matrix X itself, against the square roots of the eigenvalues of X X^T (a
   symmetric eigensolver, not the SVD the reduction uses). */
TEST(test_reduce_sp_sigma_ratio) {
  msd_nonlinear M;
  phgmg_reduce_opts o;
  phgmg_reduce_info info;
  phgmg_reduced *red = NULL;
  const int ns = 101, r = 5;
  double *X = sc_chain_run(&M, 30, ns), *G = NULL, w[64];
  int N = M.sys.N, i, j, k, pass;
  CHECK(X != NULL && N <= 64);
  if (X) G = (double *)calloc((size_t)N * N, sizeof(double));
  for (j = 0; G && j < N; ++j)
    for (i = 0; i < N; ++i)
      for (k = 0; k < ns; ++k) G[i + (size_t)j * N] += X[i + (size_t)k * N] * X[j + (size_t)k * N];
  if (G) {
    CHECK_RC(phgmg_sym_eig(N, G, N, w, NULL, N), PHGMG_OK);
    for (i = 1; i < N; ++i) /* descending */
      for (j = i; j > 0 && w[j] > w[j - 1]; --j) { double t = w[j]; w[j] = w[j - 1]; w[j - 1] = t; }
  }
  for (pass = 0; G && pass < 2; ++pass) {
    const double want = sqrt(w[r] / w[0]);
    memset(&o, 0, sizeof o);
    o.method = pass ? PHGMG_METHOD_SP2 : PHGMG_METHOD_SP1;
    o.r = r;
    memset(&info, 0, sizeof info);
    CHECK_RC(phgmg_reduce(&red, &M.sys, X, N, ns, &o, &info, NULL), PHGMG_OK);
    CHECK(want > 1e-6);
    CHECK_LE(fabs(info.pod_sigma_ratio - want), 1e-6 * want);
    phgmg_reduced_destroy(red);
    red = NULL;
  }
  free(G); free(X);
  msd_nonlinear_free(&M);
}

SUITE(scale) {
  RUN(test_reduce_ecsw_skips_resting_terms);
  RUN(test_reduce_ecsw_qm_skips_resting_terms);
  RUN(test_ecsw_screened_separable);
  RUN(test_ecsw_screened_optimal);
  RUN(test_ecsw_screened_tiny_terms);
  RUN(test_reduce_pod_randomized_and_fallback);
  RUN(test_reduce_sp_sigma_ratio);
}
