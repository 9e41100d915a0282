/* The ports of a condensed index-one model given with a dense singular E
   without zero lines (the rotation route of manual 1.8): a port that acts
   on no constraint gives no feedthrough (the rotation's round-off in the
   algebraic rows of the rotated B is not a port on a constraint), so
   gmg-qm and a reference state take the model; a port on the constraint
   still gives S' > 0. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>

/* H = I - 2 v v^T / v^T v (4 x 4), an orthogonal reflection mixing every entry. */
static void drp_reflect(double *H, unsigned seed) {
  double v[4], vv = 0.0;
  int i, j;
  for (i = 0; i < 4; ++i) { v[i] = sin(1.3 * (i + 1) * (seed + 1)) + 0.4; vv += v[i] * v[i]; }
  for (j = 0; j < 4; ++j)
    for (i = 0; i < 4; ++i) H[i + 4 * j] = (i == j ? 1.0 : 0.0) - 2.0 * v[i] * v[j] / vv;
}
/* C = op(A) op(B), 4 x 4, op = transpose when t. */
static void drp_mm(const double *A, int ta, const double *B, int tb, double *C) {
  int i, j, k;
  for (j = 0; j < 4; ++j)
    for (i = 0; i < 4; ++i) {
      double acc = 0.0;
      for (k = 0; k < 4; ++k) acc += (ta ? A[k + 4 * i] : A[i + 4 * k]) * (tb ? B[j + 4 * k] : B[k + 4 * j]);
      C[i + 4 * j] = acc;
    }
}

/* The two-mass chain x = (q1, p1, q2, p2) with p2 massless and damped (index
   one), rotated: E' = P E T, J' = P J P^T, R' = P R P^T, Q' = P Q T, B' = P b. */
static const phgmg_ph_system *drp_condensed(phgmg_dae **d, int port) {
  static const double J[16] = {0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0};
  static const double R[16] = {0, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0.5};
  static const double Q[16] = {2, 0, -1, 0, 0, 1, 0, 0, -1, 0, 1, 0, 0, 0, 0, 1};
  static const double E[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0};
  static double Er[16], Jr[16], Rr[16], Qr[16], Br[4];
  double P[16], T[16], t[16];
  phgmg_ph_system s;
  int i, j;
  drp_reflect(P, 1); drp_reflect(T, 2);
  drp_mm(P, 0, E, 0, t); drp_mm(t, 0, T, 0, Er);
  drp_mm(P, 0, J, 0, t); drp_mm(t, 0, P, 1, Jr);
  drp_mm(P, 0, R, 0, t); drp_mm(t, 0, P, 1, Rr);
  drp_mm(P, 0, Q, 0, t); drp_mm(t, 0, T, 0, Qr);
  for (j = 0; j < 4; ++j)   /* the products' round-off: J' skew, R' symmetric exactly */
    for (i = 0; i <= j; ++i) {
      const double a = 0.5 * (Jr[i + 4 * j] - Jr[j + 4 * i]), c = 0.5 * (Rr[i + 4 * j] + Rr[j + 4 * i]);
      Jr[i + 4 * j] = a; Jr[j + 4 * i] = -a; Rr[i + 4 * j] = Rr[j + 4 * i] = c;
    }
  for (i = 0; i < 4; ++i) Br[i] = P[i + 4 * port];   /* P e_port */
  memset(&s, 0, sizeof s);
  s.N = 4; s.m = 1; s.storage = PHGMG_DENSE; s.E = Er; s.J = Jr; s.R = Rr; s.Q = Qr; s.B = Br;
  *d = NULL;
  if (phgmg_dae_create(d, &s, 0.0, NULL) != PHGMG_OK || phgmg_dae_nalg(*d) != 1) return NULL;
  return phgmg_dae_system(*d);
}

TEST(test_dae_ports_rotated) {
  phgmg_dae *d;
  const phgmg_ph_system *c = drp_condensed(&d, 1);   /* the port on p1: away from the constraint */
  CHECK(c != NULL);
  if (c) CHECK(c->P == NULL && c->S == NULL && c->Nskew == NULL);
  phgmg_dae_destroy(d);
  c = drp_condensed(&d, 3);                          /* the port on p2, the massless one: feedthrough */
  CHECK(c != NULL);
  if (c) CHECK(c->S != NULL && fabs(c->S[0] - 2.0) <= 1e-12);   /* S' = 1 / R(p2, p2) = 2 (a resistor) */
  phgmg_dae_destroy(d);
}

SUITE(dae_ports) {
  RUN(test_dae_ports_rotated);
}
