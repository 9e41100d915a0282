/* morse_models.h — a damped chain of masses joined by Morse bonds, as a
   phgmg_ph_system (the non-polynomial example of examples/morse_chain.c and
   of the controller export). Include it after phgmg.h:

       #include "phgmg.h"
       #include "morse_models.h"

       morse_chain M;
       morse_opts o = {0};            // zero = the defaults below
       o.n = 100;
       if (morse_chain_build(&M, &o) == 0) { ... phgmg_simulate(&M.sys, ...) ...; morse_chain_free(&M); }

   Model. n masses m in a row, mass n tied to a wall by a bond, mass 1 free
   and driven by the force u; xi_i is the displacement of mass i measured away
   from the wall. Every bond (between masses i and i+1, and from mass n to the
   wall) has the Morse potential of its extension s,
       phi(s) = D (1 - e^{-a s})^2 = D - 2 D e^{-a s} + D e^{-2 a s},
   stiff in compression (s < 0), softening in tension, bounded by the
   dissociation energy D; its harmonic stiffness at rest is k = phi''(0) =
   2 D a^2. Every mass has a viscous damper gamma to the ground. In the
   coordinates of the paper's chain (Section 5.3), l_i = xi_i - xi_{i+1}
   (the extension of bond i, i < n), l_n = xi_n, and the momenta p_i:
       H = sum_i p_i^2 / (2 m) + sum_i phi(l_i),
       J = [0 Tt; -Tt^T 0] (Tt: 1 on the diagonal, -1 above it),
       R = diag(0, gamma I), B = e_{p_1}, y = B^T grad H = velocity of mass 1.
   The harmonic part goes into Q = diag(k I, I/m), the rest of the bond
   potential is the separable part, one term per bond,
       psi(s) = phi(s) - k s^2 / 2 = D - D a^2 s^2 - 2 D e^{-a s} + D e^{-2 a s},
   an exp-polynomial (psi(0) = psi'(0) = psi''(0) = 0). The system carries it
   twice: as phgmg's built-in exp-polynomial (poly = {D, 0, -D a^2}, expo =
   {(-2D, -a), (D, -2a)}, shared by all terms) and as the callbacks
   morse_psi / morse_dpsi / morse_ddpsi (user = the morse_chain), which compute
   the same functions (examples/morse_chain.c --callbacks uses those).
   Storage: banded, interleaved order (l_1, p_1, l_2, p_2, ...), kb = 3;
   idx_l[i], idx_p[i] give the positions of l_{i+1}, p_{i+1}.

   Each struct owns its arrays (freed by morse_chain_free); `sys` points into
   them. The builder returns 0, or -1 on bad arguments / malloc failure. */
#ifndef PHGMG_MORSE_MODELS_H
#define PHGMG_MORSE_MODELS_H
#include <math.h>
#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__) || defined(__clang__)
#define MORSE_FN static __attribute__((unused))
#else
#define MORSE_FN static
#endif

typedef struct morse_opts {
  int n;         /* number of masses (required, >= 2)                  */
  double mass;   /* 0: 1                                               */
  double gamma;  /* damper of every mass, 0: 0.3 (< 0: exactly 0)     */
  double D, a;   /* Morse depth and width, 0: D = 0.125, a = 2 (k = 1) */
} morse_opts;

typedef struct morse_chain {
  phgmg_ph_system sys;
  int n;
  double mass, gamma, D, a, k;
  double *J, *R, *Q, *B, *poly, *expo;
  int *idx_l, *idx_p; /* idx_l is sys.sep_idx */
} morse_chain;

/* psi = phi - k s^2/2 and its derivatives, written without cancellation of
   the leading terms where it matters little (double: ~1e-16 D absolute). */
MORSE_FN double morse_psi(int t, double s, void *user) {
  const morse_chain *M = (const morse_chain *)user;
  const double D = M->D, a = M->a, e = exp(-a * s);
  (void)t;
  return D - D * a * a * s * s - 2.0 * D * e + D * e * e;
}
MORSE_FN double morse_dpsi(int t, double s, void *user) {
  const morse_chain *M = (const morse_chain *)user;
  const double D = M->D, a = M->a, e = exp(-a * s);
  (void)t;
  return -2.0 * D * a * a * s + 2.0 * D * a * e - 2.0 * D * a * e * e;
}
MORSE_FN double morse_ddpsi(int t, double s, void *user) {
  const morse_chain *M = (const morse_chain *)user;
  const double D = M->D, a = M->a, e = exp(-a * s);
  (void)t;
  return -2.0 * D * a * a - 2.0 * D * a * a * e + 4.0 * D * a * a * e * e;
}

MORSE_FN void morse_chain_free(morse_chain *M) {
  if (!M) return;
  free(M->J); free(M->R); free(M->Q); free(M->B); free(M->poly); free(M->expo);
  free(M->idx_l); free(M->idx_p);
  memset(M, 0, sizeof *M);
}

MORSE_FN int morse_chain_build(morse_chain *M, const morse_opts *o) {
  int n, N, i;
  const int kb = 3, ld = 2 * 3 + 1;
  size_t len;
  if (!M) return -1;
  memset(M, 0, sizeof *M);
  if (!o || o->n < 2) return -1;
  n = o->n;
  N = 2 * n;
  M->mass = o->mass > 0.0 ? o->mass : 1.0;
  M->gamma = o->gamma > 0.0 ? o->gamma : o->gamma < 0.0 ? 0.0 : 0.3;
  M->D = o->D > 0.0 ? o->D : 0.125;
  M->a = o->a > 0.0 ? o->a : 2.0;
  M->k = 2.0 * M->D * M->a * M->a;
  len = (size_t)ld * (size_t)N;
  M->J = (double *)calloc(len, sizeof(double));
  M->R = (double *)calloc(len, sizeof(double));
  M->Q = (double *)calloc(len, sizeof(double));
  M->B = (double *)calloc((size_t)N, sizeof(double));
  M->poly = (double *)calloc(3, sizeof(double));
  M->expo = (double *)calloc(4, sizeof(double));
  M->idx_l = (int *)malloc(sizeof(int) * (size_t)n);
  M->idx_p = (int *)malloc(sizeof(int) * (size_t)n);
  if (!M->J || !M->R || !M->Q || !M->B || !M->poly || !M->expo || !M->idx_l || !M->idx_p) {
    morse_chain_free(M);
    return -1;
  }
  M->n = n;
  for (i = 0; i < n; ++i) { M->idx_l[i] = 2 * i; M->idx_p[i] = 2 * i + 1; }
#define MORSE_AT(A, r, s) (A)[(size_t)(kb + (r) - (s)) + (size_t)(s) * (size_t)ld]
  for (i = 0; i < n; ++i) {
    const int l = M->idx_l[i], p = M->idx_p[i];
    MORSE_AT(M->J, l, p) = 1.0;   /* Tt(i,i) = 1: dl_i/dt = v_i - v_{i+1} */
    MORSE_AT(M->J, p, l) = -1.0;
    if (i + 1 < n) {              /* Tt(i,i+1) = -1 */
      const int p1 = M->idx_p[i + 1];
      MORSE_AT(M->J, l, p1) = -1.0;
      MORSE_AT(M->J, p1, l) = 1.0;
    }
    MORSE_AT(M->R, p, p) = M->gamma;
    MORSE_AT(M->Q, l, l) = M->k;
    MORSE_AT(M->Q, p, p) = 1.0 / M->mass;
  }
#undef MORSE_AT
  M->B[M->idx_p[0]] = 1.0;
  M->poly[0] = M->D;
  M->poly[2] = -M->D * M->a * M->a;
  M->expo[0] = -2.0 * M->D; M->expo[1] = -M->a;
  M->expo[2] = M->D;        M->expo[3] = -2.0 * M->a;
  M->sys.N = N;
  M->sys.m = 1;
  M->sys.storage = PHGMG_BANDED;
  M->sys.kb = kb;
  M->sys.J = M->J; M->sys.R = M->R; M->sys.Q = M->Q; M->sys.B = M->B;
  M->sys.nl = PHGMG_NL_SEPARABLE;
  M->sys.nsep = n;
  M->sys.sep_idx = M->idx_l;
  M->sys.sep_w = NULL;
  M->sys.phi = morse_psi; M->sys.dphi = morse_dpsi; M->sys.ddphi = morse_ddpsi;
  M->sys.user = M;
  M->sys.poly_deg = 2;
  M->sys.poly = M->poly;
  M->sys.nexp = 2;
  M->sys.expo = M->expo;
  M->sys.phi_nfun = 0;
  return 0;
}

/* Energy of the bonds alone, sum_i phi(l_i) (for checks and plots). */
MORSE_FN double morse_bond_energy(const morse_chain *M, const double *x) {
  double E = 0.0;
  int i;
  for (i = 0; i < M->n; ++i) {
    const double e = 1.0 - exp(-M->a * x[M->idx_l[i]]);
    E += M->D * e * e;
  }
  return E;
}

/* Inputs (m = 1): training u = 0.1 sin t; unseen test input, a two-tone
   force u = 0.06 sin(0.6 t) + 0.06 sin(1.5 t) (other frequencies, inside the
   chain's pass band [0, 2 sqrt(k/m)], larger peak amplitude). */
MORSE_FN void morse_input_train(double t, double *u, void *user) { (void)user; u[0] = 0.1 * sin(t); }
MORSE_FN void morse_input_test(double t, double *u, void *user) {
  (void)user;
  u[0] = 0.06 * sin(0.6 * t) + 0.06 * sin(1.5 * t);
}

#endif /* PHGMG_MORSE_MODELS_H */
