/* GMG's non-degeneracy check (manual 8.9) decides on the reduced model, not
   on the units it is written in: a model whose D^T G D has a tiny rcond only
   because half of its states are in units 1e-7 of the others is accepted and
   gives the same reduced trajectory as the same model in common units, a
   finite-element model gets the same verdict on a coarse and a fine mesh, and
   a basis on which D^T G D is singular is refused in any units. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>

#define DG_N 8
#define DG_NS 24

typedef struct dg_model {
  double J[DG_N * DG_N], R[DG_N * DG_N], Q[DG_N * DG_N], E[DG_N * DG_N], B[DG_N], X[DG_N * DG_NS];
  phgmg_ph_system sys;
} dg_model;

/* Householder reflection I - 2 v v^T / v^T v acting on the 4 coordinates
   from i0 (symmetric and orthogonal), identity elsewhere, into P (N x N). */
static void dg_reflect(double *P, int i0, const double *v) {
  double vv = 0.0;
  int i, j;
  for (i = 0; i < 4; ++i) vv += v[i] * v[i];
  for (i = 0; i < 4; ++i)
    for (j = 0; j < 4; ++j) P[(i0 + i) + (size_t)(i0 + j) * DG_N] = (i == j ? 1.0 : 0.0) - 2.0 * v[i] * v[j] / vv;
}

/* C = P A P^T (N x N, P symmetric). */
static void dg_congruence(const double *P, const double *A, double *C) {
  double T[DG_N * DG_N];
  int i, j, k;
  for (j = 0; j < DG_N; ++j)
    for (i = 0; i < DG_N; ++i) {
      double t = 0.0;
      for (k = 0; k < DG_N; ++k) t += P[i + (size_t)k * DG_N] * A[k + (size_t)j * DG_N];
      T[i + (size_t)j * DG_N] = t;
    }
  for (j = 0; j < DG_N; ++j)
    for (i = 0; i < DG_N; ++i) {
      double t = 0.0;
      for (k = 0; k < DG_N; ++k) t += T[i + (size_t)k * DG_N] * P[j + (size_t)k * DG_N];
      C[i + (size_t)j * DG_N] = t;
    }
}

static double dg_t(int i, double s) { return i < 4 ? 1.0 : s; }

/* The model x' = (J - R) Q x + B u, J = P J0 P^T, R = P R0 P^T, Q = P Q0 P^T,
   B = P e0, with J0 pair blocks [[0, 1], [-1, 0]] on (0,1), (2,3), (4,5),
   (6,7) plus a coupling c between coordinates 1 and 4, R0 = diag(rdiag),
   Q0 = diag(1 + i / 8) (or I with rot), P = I or (rot) a reflection within
   each group of four coordinates. With s != 1 it is written as a mass-matrix
   model in x~ = T^-1 x, T = diag(1, 1, 1, 1, s, s, s, s), as a finite-element
   code with a mass matrix scaling like the mesh width would write it:
   E = T, E x~' = (J - R) (Q T) x~ + B u, the same outputs. The snapshots are
   P V C (divided by T) with V = [e0, ek[0], ek[1], ek[2]] and orthogonal
   coefficient rows C (cosines of 4, 1, 2, 3 periods per record, amplitudes
   4, 3, 2, 1), so that GMG-POD of order 4 takes exactly that span in either
   form. */
static void dg_build(dg_model *d, double s, int rot, double c, const double *rdiag, const int *ek) {
  static const double v1[4] = {1.0, 2.0, -1.0, 0.5}, v2[4] = {0.3, -1.0, 2.0, 1.0};
  double J[DG_N * DG_N] = {0}, R[DG_N * DG_N] = {0}, Q[DG_N * DG_N] = {0}, P[DG_N * DG_N] = {0};
  int i, j, k;
  const double pi = 3.14159265358979323846;
  for (i = 0; i < DG_N; i += 2) { J[(i + 1) + i * DG_N] = -1.0; J[i + (i + 1) * DG_N] = 1.0; }
  J[1 + 4 * DG_N] = c; J[4 + 1 * DG_N] = -c;
  for (i = 0; i < DG_N; ++i) { R[i + i * DG_N] = rdiag[i]; Q[i + i * DG_N] = rot ? 1.0 : 1.0 + i / 8.0; }
  if (rot) { dg_reflect(P, 0, v1); dg_reflect(P, 4, v2); }
  else for (i = 0; i < DG_N; ++i) P[i + i * DG_N] = 1.0;
  dg_congruence(P, J, d->J);
  dg_congruence(P, R, d->R);
  dg_congruence(P, Q, d->Q);               /* diagonal: P = I or Q0 = I */
  memset(d->E, 0, sizeof d->E);
  for (i = 0; i < DG_N; ++i) {
    d->B[i] = P[i];
    d->E[i + i * DG_N] = dg_t(i, s);
    for (j = 0; j < DG_N; ++j) d->Q[i + j * DG_N] *= dg_t(j, s);   /* Q T */
  }
  for (j = 0; j < DG_NS; ++j)
    for (i = 0; i < DG_N; ++i) {
      double x = 4.0 * cos(2.0 * pi * 4.0 * j / DG_NS) * P[i];
      for (k = 0; k < 3; ++k) x += (3.0 - k) * cos(2.0 * pi * (k + 1) * j / DG_NS) * P[i + (size_t)ek[k] * DG_N];
      d->X[i + (size_t)j * DG_N] = x / dg_t(i, s);
    }
  memset(&d->sys, 0, sizeof d->sys);
  d->sys.N = DG_N; d->sys.m = 1; d->sys.J = d->J; d->sys.R = d->R; d->sys.Q = d->Q; d->sys.B = d->B;
  if (s != 1.0) d->sys.E = d->E;
}

static phgmg_result dg_reduce(const dg_model *d, phgmg_reduced **red, phgmg_reduce_info *info) {
  phgmg_reduce_opts o;
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = 4;
  return phgmg_reduce(red, &d->sys, d->X, DG_N, DG_NS, &o, info, NULL);
}

static void dg_u(double t, double *u, void *p) { (void)p; u[0] = sin(2.0 * t) + 0.5 * cos(0.7 * t); }

/* The damped model with a coupling between the groups, in common units and
   with the second group in units 1e-7 (D^T G D's rcond moves by 1e-14
   without the check's scaling): both are accepted, with the same measure
   within a factor 16, and the reduced outputs and lifted states agree. */
TEST(test_degen_units_accepted) {
  static const double rd[DG_N] = {0.5, 0.2, 0.3, 0.1, 0.4, 0.2, 0.3, 0.5};
  static const int ek[3] = {1, 4, 5};
  static dg_model a, b;
  enum { NT = 80 };
  const double s = 1e-7, dt = 0.05;
  double xr0[4] = {0}, Ya[NT + 1], Yb[NT + 1], XRa[4 * (NT + 1)], XRb[4 * (NT + 1)], xa[DG_N], xb[DG_N];
  phgmg_reduced *ra = NULL, *rb = NULL;
  phgmg_reduce_info ia, ib;
  int i, k;
  dg_build(&a, 1.0, 0, 0.5, rd, ek);
  dg_build(&b, s, 0, 0.5, rd, ek);
  CHECK_RC(dg_reduce(&a, &ra, &ia), PHGMG_OK);
  CHECK_RC(dg_reduce(&b, &rb, &ib), PHGMG_OK);
  if (!ra || !rb) { phgmg_reduced_destroy(ra); phgmg_reduced_destroy(rb); return; }
  CHECK(ia.rcond_dgd > 1e-4);
  CHECK_LE(ia.rcond_dgd, 16.0 * ib.rcond_dgd);
  CHECK_LE(ib.rcond_dgd, 16.0 * ia.rcond_dgd);
  CHECK_RC(phgmg_reduced_simulate(ra, xr0, 0.0, dt, NT, dg_u, NULL, 0.0, 20, XRa, Ya, NULL, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_reduced_simulate(rb, xr0, 0.0, dt, NT, dg_u, NULL, 0.0, 20, XRb, Yb, NULL, NULL, NULL), PHGMG_OK);
  CHECK(fabs(Ya[NT]) > 1e-3);
  CHECK_LE(phgmg_rel_error(1, NT + 1, Ya, 1, Yb, 1), 1e-10);
  for (k = 0; k <= NT; k += 20) {   /* T phi_b(xr_b) = phi_a(xr_a) */
    double num = 0.0, den = 0.0;
    phgmg_reduced_lift(ra, XRa + (size_t)k * 4, xa);
    phgmg_reduced_lift(rb, XRb + (size_t)k * 4, xb);
    for (i = 0; i < DG_N; ++i) {
      const double d = xb[i] * dg_t(i, s) - xa[i];
      num += d * d; den += xa[i] * xa[i];
    }
    CHECK_LE(sqrt(num), 1e-10 * sqrt(den) + 1e-300);
  }
  phgmg_reduced_destroy(ra);
  phgmg_reduced_destroy(rb);
}

/* R = 0: G = J^{-1} maps e0 <-> e1, e4 <-> e5, e6 <-> e7. On span{e0, e1, e4,
   e5} D^T G D is regular (two 2 x 2 skew blocks), on span{e0, e1, e4, e6} it
   has rank 2 (G e4, G e6 leave the span; its last two rows and columns are
   rounding errors, here of a rotated model). In common units and with the
   second group in units 1e-7 the first is accepted and the second refused
   with PHGMG_ERR_DEGENERATE (an equilibration alone would scale the rounding
   rows up to order one and accept it). */
TEST(test_degen_rank_deficient_refused) {
  static const double rz[DG_N] = {0};
  static const int ek_ok[3] = {1, 4, 5}, ek_bad[3] = {1, 4, 6};
  static const double scales[2] = {1.0, 1e-7};
  static dg_model d;
  phgmg_reduced *red = NULL;
  phgmg_reduce_info info;
  int k;
  for (k = 0; k < 2; ++k) {
    dg_build(&d, scales[k], 1, 0.0, rz, ek_ok);
    CHECK_RC(dg_reduce(&d, &red, &info), PHGMG_OK);
    CHECK(info.rcond_dgd > 1e-4);
    phgmg_reduced_destroy(red);
    red = NULL;
    dg_build(&d, scales[k], 1, 0.0, rz, ek_bad);
    CHECK_RC(dg_reduce(&d, &red, &info), PHGMG_ERR_DEGENERATE);
    CHECK(red == NULL);
    CHECK_LE(info.rcond_dgd, 1e-12);
  }
}

/* A 1-D acoustic wave in mixed finite elements (pressure P1 with the
   consistent mass matrix, velocity P0, Rayleigh damping 0.05 M on the
   pressure, a Gaussian source), interleaved so that every matrix is banded:
   E x' = J x - R x + B u. Its GMG-POD model (r = 12, 400 steps of 0.01) is
   the same reduced model on every mesh, but D^T G D with unit port columns
   has an rcond falling like h^2 (1e-9 at n = 100 elements, 3e-13 at
   n = 3000). The measure does not drift with the mesh: both meshes are
   accepted with the default tolerance and their measures agree within a
   factor 2. */
static void dg_wave_u(double t, double *u, void *p) { (void)p; u[0] = sin(10.0 * t) + sin(23.0 * t); }
static double dg_wave_measure(int n, phgmg_result *rc) {
  const int N = 2 * n + 1, ns = 401, kb = 2, ld = 2 * kb + 1;
  const double h = 1.0 / n;
  double *buf = (double *)calloc((size_t)4 * ld * N + (size_t)2 * N + (size_t)N * ns, sizeof(double));
  double *J = buf, *R = J + (size_t)ld * N, *Q = R + (size_t)ld * N, *E = Q + (size_t)ld * N;
  double *B = E + (size_t)ld * N, *x0 = B + N, *X = x0 + N, meas = -1.0;
  phgmg_ph_system s;
  phgmg_reduce_opts o;
  phgmg_reduce_info info;
  phgmg_reduced *red = NULL;
  int i, e;
#define DG_PUT(M, i_, j_, v_) ((M)[(kb + (i_) - (j_)) + (size_t)(j_) * ld] += (v_))
  for (i = 0; i < N; ++i) DG_PUT(Q, i, i, 1.0);
  for (e = 0; e < n; ++e) {   /* element e: pressure nodes 2e, 2e + 2, velocity 2e + 1 */
    const int a = 2 * e, b = 2 * e + 2, v = 2 * e + 1;
    DG_PUT(E, a, a, h / 3); DG_PUT(E, b, b, h / 3); DG_PUT(E, a, b, h / 6); DG_PUT(E, b, a, h / 6);
    DG_PUT(R, a, a, 0.05 * h / 3); DG_PUT(R, b, b, 0.05 * h / 3);
    DG_PUT(R, a, b, 0.05 * h / 6); DG_PUT(R, b, a, 0.05 * h / 6);
    DG_PUT(E, v, v, h);
    DG_PUT(J, a, v, -1.0); DG_PUT(J, v, a, 1.0); DG_PUT(J, b, v, 1.0); DG_PUT(J, v, b, -1.0);
  }
#undef DG_PUT
  for (i = 0; i <= n; ++i) B[2 * i] = h * exp(-pow((i * h - 0.3) / 0.05, 2.0));
  memset(&s, 0, sizeof s);
  s.N = N; s.m = 1; s.storage = PHGMG_BANDED; s.kb = kb; s.J = J; s.R = R; s.Q = Q; s.B = B; s.E = E;
  *rc = phgmg_simulate(&s, x0, 0.0, 0.01, ns - 1, dg_wave_u, NULL, NULL, X, NULL, NULL, NULL, NULL, NULL);
  if (*rc == PHGMG_OK) {
    memset(&o, 0, sizeof o);
    o.method = PHGMG_METHOD_GMG_POD; o.r = 12;
    *rc = phgmg_reduce(&red, &s, X, N, ns, &o, &info, NULL);
    meas = info.rcond_dgd;
  }
  phgmg_reduced_destroy(red);
  free(buf);
  return meas;
}
TEST(test_degen_mesh_width) {
  phgmg_result rc1, rc2;
  const double m1 = dg_wave_measure(100, &rc1), m2 = dg_wave_measure(3000, &rc2);
  CHECK_RC(rc1, PHGMG_OK);
  CHECK_RC(rc2, PHGMG_OK);
  CHECK(m1 >= 1e-12 && m2 >= 1e-12);
  CHECK_LE(m1, 2.0 * m2);
  CHECK_LE(m2, 2.0 * m1);
}

SUITE(degen) {
  RUN(test_degen_units_accepted);
  RUN(test_degen_rank_deficient_refused);
  RUN(test_degen_mesh_width);
}
