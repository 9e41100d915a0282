/* The affine reference state (phgmg_reduce_opts.ref, manual 3.5):
   phi(x) = xbar + V0 x (+ V2 eta(x2)). Each claim of the manual's derivation
   is checked against a computation in full dimension that does not use the
   reduced model's coefficients:
   - snapshots lying exactly on an affine quadratic manifold are reproduced
     to round-off by every construction given its xbar, not without it;
   - the reduced energy is H(phi(x)) and its gradient Dphi^T grad H(phi(x))
     (phgmg_ph_hamiltonian / phgmg_ph_gradient at the lifted state), for the
     quadratic and linear kinds, with a separable part (offsets ref_s);
   - Jr skew, Rr positive semidefinite, W^T Dphi = I at states away from 0;
   - rho(0) = xr_rest; the linear kind's shifted xbar stays in the same affine
     space and makes g0 = 0 (so the step map applies);
   - the energy balance H_n - H_0 = supplied - dissipated of the reduced run;
   - binary and C export round trips keep the new fields; bad options and a
     step map with a constant gradient are refused. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include "fixture_msd.h"

/* ---- exact affine quadratic manifold ------------------------------------ */
#define QR_N 200
#define QR_P 6
#define QR_NC (QR_P * (QR_P + 1) / 2)
#define QR_NS 300

typedef struct qr_data {
  double J[QR_N], R[QR_N], Q[QR_N], B[QR_N], c[QR_N];
  double X[QR_N * QR_NS];
  phgmg_ph_system sys;
} qr_data;

/* x = c + b u + V1 z + V2 (0.05 k(z)), [b, V1, V2, c/|c|] orthonormal, |c| = 3:
   the offset c lies outside the manifold's span; the snapshots come in
   pairs z, -z (as in test_qm_wide.c). */
static void qr_build(qr_data *d) {
  const int k = 2 + QR_P + QR_NC;
  double *A = (double *)malloc(sizeof(double) * QR_N * k), tau[2 + QR_P + QR_NC], work[2 + QR_P + QR_NC];
  int i, j, a, b, c;
  for (i = 0; i < QR_N * k; ++i) A[i] = th_rand();
  phgmg_qr(QR_N, k, A, QR_N, tau);
  phgmg_qr_form_q(QR_N, k, A, QR_N, tau, work);
  for (i = 0; i < QR_N; ++i) d->c[i] = 3.0 * A[i + (size_t)(k - 1) * QR_N];
  for (j = 0; j < QR_NS; j += 2) {   /* pairs z, -z: V1's and V2's coordinates uncorrelated */
    double z[QR_P], u = th_rand(), *x = d->X + (size_t)j * QR_N, *y = x + QR_N;
    for (a = 0; a < QR_P; ++a) z[a] = th_rand();
    for (i = 0; i < QR_N; ++i) {
      double lin = 0.0, quad = 0.0;
      for (a = 0; a < QR_P; ++a) lin += A[i + (size_t)(1 + a) * QR_N] * z[a];
      for (a = 0, c = 0; a < QR_P; ++a)
        for (b = a; b < QR_P; ++b, ++c) quad += 0.05 * A[i + (size_t)(1 + QR_P + c) * QR_N] * z[a] * z[b];
      x[i] = d->c[i] + A[i] * u + lin + quad;
      y[i] = d->c[i] - A[i] * u - lin + quad;
    }
  }
  for (i = 0; i < QR_N; ++i) { d->J[i] = 0.0; d->R[i] = 1.0; d->Q[i] = 1.0; d->B[i] = A[i]; }
  memset(&d->sys, 0, sizeof d->sys);
  d->sys.N = QR_N; d->sys.m = 1; d->sys.storage = PHGMG_BANDED; d->sys.kb = 0;
  d->sys.J = d->J; d->sys.R = d->R; d->sys.Q = d->Q; d->sys.B = d->B;
  free(A);
}

TEST(test_qm_ref_exact_affine_manifold) {
  static qr_data d;
  int mf, withref;
  qr_build(&d);
  for (mf = PHGMG_MANIFOLD_POD; mf <= PHGMG_MANIFOLD_ALTMIN; ++mf)
    for (withref = 0; withref < 2; ++withref) {
      phgmg_reduce_opts o;
      phgmg_reduced *red = NULL;
      double e;
      memset(&o, 0, sizeof o);
      o.method = PHGMG_METHOD_GMG_QM; o.r = 1 + QR_P; o.qm.manifold = mf; o.qm.lambda = 1e-12;
      o.qm.rn = PHGMG_RN_WIDE;
      if (withref) { o.ref = PHGMG_REF_GIVEN; o.ref_x = d.c; }
      CHECK_RC(phgmg_reduce(&red, &d.sys, d.X, QR_N, QR_NS, &o, NULL, NULL), PHGMG_OK);
      if (!red) continue;
      e = phgmg_err_proj(red, d.X, QR_N, QR_NS);
      if (withref) CHECK_LE(e, 1e-9);
      else CHECK(e > 1e-3);   /* the offset costs a linear mode and the quadratic fit */
      phgmg_reduced_destroy(red);
    }
}

/* ---- a mass-spring chain with a separable quartic part -------------------- */
#define QC_n 12
#define QC_N (2 * QC_n)
#define QC_NS 401

static void qc_u(double t, double *u, void *user) { (void)user; u[0] = 0.6 + 0.5 * sin(1.3 * t); }

typedef struct qc_model {
  dmodel t;
  int idx[QC_n];
  double poly[5];
  double X[QC_N * QC_NS], x0[QC_N];
} qc_model;

static void qc_build(qc_model *q, int nonlinear) {
  int i;
  dmodel_msd(&q->t, QC_n);
  if (nonlinear) {
    for (i = 0; i < QC_n; ++i) q->idx[i] = 2 * i;   /* the q coordinates */
    q->poly[0] = q->poly[1] = q->poly[2] = q->poly[3] = 0.0; q->poly[4] = 0.5;
    q->t.sys.nl = PHGMG_NL_SEPARABLE; q->t.sys.nsep = QC_n; q->t.sys.sep_idx = q->idx;
    q->t.sys.poly_deg = 4; q->t.sys.poly = q->poly;
  }
  memset(q->x0, 0, sizeof q->x0);   /* from rest */
  CHECK_RC(phgmg_simulate(&q->t.sys, q->x0, 0.0, 0.05, QC_NS - 1, qc_u, NULL, NULL, q->X, NULL, NULL, NULL, NULL,
                          NULL), PHGMG_OK);
}

static phgmg_reduced *qc_reduce(const qc_model *q, int method, int r, double dt) {
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  memset(&o, 0, sizeof o);
  o.method = method; o.r = r; o.qm.rn = 4; o.qm.lambda = 1e-3; o.ref = PHGMG_REF_MEAN; o.dt = dt;
  CHECK_RC(phgmg_reduce(&red, &q->t.sys, q->X, QC_N, QC_NS, &o, NULL, NULL), PHGMG_OK);
  return red;
}

/* A reduced state near the training data: rho of a snapshot plus a small
   perturbation. */
static void qc_state(const phgmg_reduced *red, const qc_model *q, int j, double *xr) {
  int a;
  phgmg_reduced_restrict(red, q->X + (size_t)j * QC_N, xr);
  for (a = 0; a < phgmg_reduced_rom(red)->r; ++a) xr[a] += 0.05 * th_rand();
}

/* H, grad H of the reduced model against H(phi(x)), Dphi^T grad H(phi(x)). */
static void qc_check_energy(const phgmg_reduced *red, const qc_model *q) {
  const phgmg_rom *rom = phgmg_reduced_rom(red);
  const int r = rom->r;
  double xr[32], x[QC_N], g[QC_N], D[QC_N * 32], gr[32], work[4096];
  phgmg_real xrr[32], grr[32];
  int j, a;
  CHECK(phgmg_rom_eval_work_size(rom) <= 4096 && r <= 32);
  for (j = 40; j < QC_NS; j += 90) {
    double h, hr, gmax = 0.0, gerr = 0.0;
    qc_state(red, q, j, xr);
    for (a = 0; a < r; ++a) xrr[a] = xr[a];
    phgmg_reduced_lift(red, xr, x);
    h = phgmg_ph_hamiltonian(&q->t.sys, x);
    hr = phgmg_rom_hamiltonian(rom, xrr, work);
    CHECK_LE(fabs(h - hr), 1e-11 * (1.0 + fabs(h)));
    phgmg_ph_gradient(&q->t.sys, x, g);
    phgmg_reduced_dphi(red, xr, D, QC_N);
    phgmg_gemv('T', QC_N, r, 1.0, D, QC_N, g, 0.0, gr);
    phgmg_rom_gradient(rom, xrr, grr, work);
    for (a = 0; a < r; ++a) { gmax = PHGMG__MAX(gmax, fabs(gr[a])); gerr = PHGMG__MAX(gerr, fabs(gr[a] - grr[a])); }
    CHECK(gmax > 1e-3);
    CHECK_LE(gerr, 1e-11 * (1.0 + gmax));
  }
}

/* Jr skew, Rr PSD, and (GMG) W^T Dphi = I at states away from the origin. */
static void qc_check_structure(const phgmg_reduced *red, const qc_model *q) {
  const phgmg_rom *rom = phgmg_reduced_rom(red);
  const int r = rom->r;
  double xr[32], Rd[32 * 32], ev[32], W[QC_N * 32], D[QC_N * 32], WD[32 * 32], work[4096];
  phgmg_real xrr[32], Jr[32 * 32], Rr[32 * 32];
  int j, a, b;
  for (j = 100; j < QC_NS; j += 150) {
    double skew = 0.0, nr = 0.0, emin;
    qc_state(red, q, j, xr);
    for (a = 0; a < r; ++a) xrr[a] = xr[a];
    CHECK_RC(phgmg_rom_structure(rom, xrr, Jr, Rr, work), PHGMG_OK);
    for (a = 0; a < r * r; ++a) { Rd[a] = Rr[a]; nr = PHGMG__MAX(nr, fabs(Rd[a])); }
    for (b = 0; b < r; ++b)
      for (a = 0; a < r; ++a) skew = PHGMG__MAX(skew, fabs(Jr[a + b * r] + Jr[b + a * r]));
    CHECK(skew == 0.0);
    CHECK_RC(phgmg_sym_eig(r, Rd, r, ev, NULL, 0), PHGMG_OK);
    for (emin = ev[0], a = 1; a < r; ++a) emin = PHGMG__MIN(emin, ev[a]);
    CHECK(nr > 0.0);
    CHECK(emin >= -1e-12 * nr);
    if (rom->method == PHGMG_METHOD_SP1 || rom->method == PHGMG_METHOD_SP2) continue;
    CHECK_RC(phgmg_reduced_W(red, xr, W, QC_N), PHGMG_OK);
    phgmg_reduced_dphi(red, xr, D, QC_N);
    phgmg__atb(QC_N, r, r, W, D, WD);
    for (b = 0; b < r; ++b)
      for (a = 0; a < r; ++a) CHECK_LE(fabs(WD[a + b * r] - (a == b)), 1e-10);
  }
}

/* rho(0) = xr_rest, and a run from rest keeps the energy balance. */
static void qc_check_rest_balance(const phgmg_reduced *red, double tol) {
  const phgmg_rom *rom = phgmg_reduced_rom(red);
  const int r = rom->r;
  double zero[QC_N] = {0}, xr[32], H[201], S[201], D[201], e[201], emax = 0.0, scale = 0.0;
  phgmg_energy en;
  int a, n;
  CHECK(rom->xr_rest != NULL && rom->ref_g != NULL);
  if (!rom->xr_rest) return;
  phgmg_reduced_restrict(red, zero, xr);
  for (a = 0; a < r; ++a) CHECK_LE(fabs(xr[a] - (double)rom->xr_rest[a]), 1e-12 * (1.0 + fabs(xr[a])));
  en.H = H; en.S = S; en.D = D;
  CHECK_RC(phgmg_reduced_simulate(red, xr, 0.0, 0.05, 200, qc_u, NULL, 1e-12, 20, NULL, NULL, &en, NULL, NULL),
           PHGMG_OK);
  phgmg_err_energy(&en, 200, e);
  for (n = 0; n <= 200; ++n) {
    emax = PHGMG__MAX(emax, e[n]);
    scale = PHGMG__MAX(scale, fabs(S[n]) + fabs(D[n]) + fabs(H[n] - H[0]));
  }
  CHECK(scale > 1e-2);
  CHECK_LE(emax, tol * scale);
}

/* The binary format keeps ref_g, ref_s, xr_rest (same bits, same steps); the
   C export names them. */
static void qc_check_export(const phgmg_reduced *red) {
  const phgmg_rom *rom = phgmg_reduced_rom(red);
  static unsigned char buf[1 << 16];
  static double mem[1 << 14], sm1[1 << 13], sm2[1 << 13];
  phgmg_rom back;
  phgmg_rom_stepper s1, s2;
  phgmg_real x1[32], x2[32], u3[3] = {0.3, 0.4, 0.5}, y1[1], y2[1];
  size_t n = 0, need = 0;
  int a, k, same = 1;
  CHECK_RC(phgmg_rom_serialize(rom, buf, sizeof buf, &n), PHGMG_OK);
  CHECK_RC(phgmg_rom_deserialize_size(buf, n, &need), PHGMG_OK);
  CHECK(need <= sizeof mem);
  CHECK_RC(phgmg_rom_deserialize(buf, n, &back, mem, sizeof mem), PHGMG_OK);
  CHECK((back.ref_g != NULL) == (rom->ref_g != NULL) && (back.ref_s != NULL) == (rom->ref_s != NULL) &&
        (back.xr_rest != NULL) == (rom->xr_rest != NULL));
  for (k = 26; k <= 28; ++k) {
    const phgmg_real *p = phgmg__field_get(rom, k), *q = phgmg__field_get(&back, k);
    if (p && q) CHECK(memcmp(p, q, phgmg__field_len(rom, k) * sizeof(phgmg_real)) == 0);
  }
  CHECK_RC(phgmg_rom_stepper_init(&s1, rom, 0.05, 0, 0, sm1, sizeof sm1), PHGMG_OK);
  CHECK_RC(phgmg_rom_stepper_init(&s2, &back, 0.05, 0, 0, sm2, sizeof sm2), PHGMG_OK);
  for (a = 0; a < rom->r; ++a) x1[a] = x2[a] = rom->xr_rest[a];
  for (k = 0; k < 20; ++k) {
    CHECK_RC(phgmg_rom_step(&s1, x1, u3, y1, NULL), PHGMG_OK);
    CHECK_RC(phgmg_rom_step(&s2, x2, u3, y2, NULL), PHGMG_OK);
    same &= memcmp(x1, x2, sizeof(phgmg_real) * (size_t)rom->r) == 0 && y1[0] == y2[0];
  }
  CHECK(same);
#ifndef PHGMG_NO_STDIO
  {
    FILE *f;
    char text[1 << 15];
    size_t len;
    const char *path = "build/test_qm_ref_export.h";
    CHECK_RC(phgmg_rom_export_c(rom, "qref", path), PHGMG_OK);
    f = fopen(path, "r");
    CHECK(f != NULL);
    if (!f) return;
    len = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    remove(path);
    text[len] = 0;
    CHECK(strstr(text, "qref_ref_g[") != NULL && strstr(text, "qref_xr_rest[") != NULL);
    CHECK((strstr(text, "qref_ref_s[") != NULL) == (rom->ref_s != NULL));
    CHECK(strstr(text, ", qref_ref_g") != NULL);
  }
#endif
}

TEST(test_qm_ref_gmg_qm_separable) {
  static qc_model q;
  phgmg_reduced *red;
  qc_build(&q, 1);
  red = qc_reduce(&q, PHGMG_METHOD_GMG_QM, 7, 0.0);
  if (red) {
    CHECK(phgmg_reduced_rom(red)->ref_s != NULL && phgmg_reduced_rom(red)->nd == QC_n);
    qc_check_energy(red, &q);
    qc_check_structure(red, &q);
    qc_check_rest_balance(red, 1e-8);
    qc_check_export(red);
    phgmg_reduced_destroy(red);
  }
  red = qc_reduce(&q, PHGMG_METHOD_GMG_POD, 7, 0.0);   /* linear kind, separable: g0 kept */
  if (red) {
    qc_check_energy(red, &q);
    qc_check_structure(red, &q);
    qc_check_rest_balance(red, 1e-8);
    phgmg_reduced_destroy(red);
  }
  dmodel_free(&q.t);
}

/* A linear model: xbar is moved within xbar + span V0 so that g0 = 0, and the
   model with a step map steps like the one without. */
TEST(test_qm_ref_linear_shift_step_map) {
  static qc_model q;
  const int meth[3] = {PHGMG_METHOD_GMG_POD, PHGMG_METHOD_SP1, PHGMG_METHOD_GMG_QM};
  int k;
  qc_build(&q, 0);
  for (k = 0; k < 3; ++k) {
    phgmg_reduced *red = qc_reduce(&q, meth[k], 7, 0.0), *map = qc_reduce(&q, meth[k], 7, 0.05);
    if (red && map) {
      const phgmg_rom *rom = phgmg_reduced_rom(red);
      double xs[QC_N], mean[QC_N] = {0}, d[QC_N], res = 0.0, g0 = 0.0;
      int i, j;
      qc_check_energy(red, &q);
      qc_check_structure(red, &q);
      qc_check_rest_balance(red, k == 2 ? 1e-8 : 1e-12);
      if (k < 2) {
        CHECK(phgmg_reduced_rom(map)->Phi != NULL);
        for (i = 0; i < rom->r; ++i) g0 = PHGMG__MAX(g0, fabs(rom->ref_g[i]));
        CHECK(g0 == 0.0);
        qc_check_rest_balance(map, 1e-12);
        qc_check_export(map);
        /* xbar - mean lies in span V0: the lift of rho(mean) is the mean */
        for (j = 0; j < QC_NS; ++j)
          for (i = 0; i < QC_N; ++i) mean[i] += q.X[i + (size_t)j * QC_N] / QC_NS;
        {
          double xr[32];
          phgmg_reduced_restrict(red, mean, xr);
          phgmg_reduced_lift(red, xr, xs);
        }
        for (i = 0; i < QC_N; ++i) { d[i] = xs[i] - mean[i]; res = PHGMG__MAX(res, fabs(d[i])); }
        CHECK_LE(res, 1e-12);
      }
    }
    phgmg_reduced_destroy(red);
    phgmg_reduced_destroy(map);
  }
  dmodel_free(&q.t);
}

TEST(test_qm_ref_bad_input) {
  static qc_model q;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  double xb[QC_N] = {0};
  qc_build(&q, 0);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_QM; o.r = 5; o.qm.rn = 3;
  o.ref = 3;
  CHECK_RC(phgmg_reduce(&red, &q.t.sys, q.X, QC_N, QC_NS, &o, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  o.ref = PHGMG_REF_GIVEN;
  CHECK_RC(phgmg_reduce(&red, &q.t.sys, q.X, QC_N, QC_NS, &o, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  xb[3] = (double)NAN; o.ref_x = xb;
  CHECK_RC(phgmg_reduce(&red, &q.t.sys, q.X, QC_N, QC_NS, &o, NULL, NULL), PHGMG_ERR_NANINF);
  CHECK(red == NULL);
  /* a step map next to a constant gradient is no valid model */
  o.method = PHGMG_METHOD_GMG_POD; o.ref = PHGMG_REF_MEAN; o.dt = 0.05;
  CHECK_RC(phgmg_reduce(&red, &q.t.sys, q.X, QC_N, QC_NS, &o, NULL, NULL), PHGMG_OK);
  if (red) {
    phgmg_rom bad = *phgmg_reduced_rom(red);
    phgmg_real g[64];
    int i;
    for (i = 0; i < bad.r + 1; ++i) g[i] = bad.ref_g[i];
    g[0] = (phgmg_real)0.5;
    bad.ref_g = g;
    CHECK_RC(phgmg_rom_check(&bad), PHGMG_ERR_INVALID_ARG);
    phgmg_reduced_destroy(red);
  }
  dmodel_free(&q.t);
}

SUITE(qm_ref) {
  RUN(test_qm_ref_exact_affine_manifold);
  RUN(test_qm_ref_gmg_qm_separable);
  RUN(test_qm_ref_linear_shift_step_map);
  RUN(test_qm_ref_bad_input);
}
