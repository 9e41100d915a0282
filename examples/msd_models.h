/* msd_models.h — the two mass-spring-damper models of the paper (Section 5.2
   and 5.3) as phgmg_ph_system values, for the tests, the examples and the
   benchmarks. Include it after phgmg.h (it uses only the declarations):

       #include "phgmg.h"
       #include "msd_models.h"

       msd_nonlinear M;
       msd_nl_opts o = {0};          // zero = the paper's values
       o.n = 500; o.storage = PHGMG_BANDED;
       if (msd_nonlinear_build(&M, &o) == 0) {
         ... phgmg_simulate(&M.sys, ...) ...
         msd_nonlinear_free(&M);
       }

   Each struct owns its arrays (freed by the matching *_free); `sys` points into
   them, so do not free them while the system is in use. The builders return 0
   on success, -1 on bad arguments or when malloc fails (nothing is leaked). */
#ifndef PHGMG_MSD_MODELS_H
#define PHGMG_MSD_MODELS_H
#include <math.h>
#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__) || defined(__clang__)
#define MSD_FN static __attribute__((unused))
#else
#define MSD_FN static
#endif

/* ---- linear MSD (paper 5.2) -------------------------------------------------
   n masses, N = 2n, x = (q1, p1, q2, p2, ...): spring k_i between masses i and
   i+1 (i < n), the last mass tied to the wall by k_n, damper c_i on mass i,
   force input on mass 1:
     J = blockdiag([0 1; -1 0]), R = diag(0, c1, 0, c2, ...), B = e_2,
     H = 1/2 x^T Q x,  Q(q_i,q_i) = k_{i-1} + k_i (k_0 = 0), Q(q_i,q_{i+1}) = -k_i,
     Q(p_i,p_i) = 1/m_i
   (the paper's printed N = 6 realisation, generalised). DENSE, or BANDED with
   kb = 2 (same ordering). */
typedef struct msd_linear {
  phgmg_ph_system sys;
  int n_masses;
  double *J, *R, *Q, *B;
} msd_linear;

MSD_FN void msd_linear_free(msd_linear *M) {
  if (!M) return;
  free(M->J); free(M->R); free(M->Q); free(M->B);
  memset(M, 0, sizeof *M);
}

/* m, k, c: n_masses values each, or NULL for the paper's m_i = 2, k_i = 1, c_i = 1. */
MSD_FN int msd_linear_build(msd_linear *M, int n_masses, const double *m, const double *k,
                            const double *c, phgmg_storage storage) {
  int n = n_masses, N = 2 * n_masses, i, kb = 2;
  size_t len;
  if (!M) return -1;
  memset(M, 0, sizeof *M);
  if (n < 1 || (storage != PHGMG_DENSE && storage != PHGMG_BANDED)) return -1;
  if (storage == PHGMG_BANDED && kb > N - 1) kb = N - 1;
  len = storage == PHGMG_DENSE ? (size_t)N * (size_t)N : (size_t)(2 * kb + 1) * (size_t)N;
  M->J = (double *)calloc(len, sizeof(double));
  M->R = (double *)calloc(len, sizeof(double));
  M->Q = (double *)calloc(len, sizeof(double));
  M->B = (double *)calloc((size_t)N, sizeof(double));
  if (!M->J || !M->R || !M->Q || !M->B) { msd_linear_free(M); return -1; }
  M->n_masses = n;
#define MSD_AT(A, r, s) \
  (A)[storage == PHGMG_DENSE ? (size_t)(r) + (size_t)(s) * (size_t)N \
                             : (size_t)(kb + (r) - (s)) + (size_t)(s) * (size_t)(2 * kb + 1)]
  for (i = 0; i < n; ++i) {
    double mi = m ? m[i] : 2.0, ki = k ? k[i] : 1.0, ci = c ? c[i] : 1.0;
    double kprev = i > 0 ? (k ? k[i - 1] : 1.0) : 0.0;
    int q = 2 * i, p = 2 * i + 1;
    MSD_AT(M->J, q, p) = 1.0;
    MSD_AT(M->J, p, q) = -1.0;
    MSD_AT(M->R, p, p) = ci;
    MSD_AT(M->Q, q, q) = kprev + ki;
    MSD_AT(M->Q, p, p) = 1.0 / mi;
    if (i + 1 < n) {
      MSD_AT(M->Q, q, q + 2) = -ki;
      MSD_AT(M->Q, q + 2, q) = -ki;
    }
  }
#undef MSD_AT
  M->B[1] = 1.0;
  M->sys.N = N;
  M->sys.m = 1;
  M->sys.storage = storage;
  M->sys.kb = storage == PHGMG_BANDED ? kb : 0;
  M->sys.J = M->J; M->sys.R = M->R; M->sys.Q = M->Q; M->sys.B = M->B;
  M->sys.nl = PHGMG_NL_NONE;
  return 0;
}

/* ---- nonlinear MSD (paper 5.3) in the transformed l-coordinates ---------------
   n masses, N = 2n. With l_i = xi_i - xi_{i+1} (i < n), l_n = xi_n and the
   velocities v_i, the paper's Section 5.3 system becomes
     Jhat = T J T^T = [0 Tt; -Tt^T 0],  Rhat = diag(0, gamma I),  Bhat = T B = e_{v_1},
     Hhat = 1/2 k1 sum l_i^2 + 1/2 mass sum v_i^2 + sum k2 l_i^4 / 4,
   (Tt: 1 on the diagonal, -1 above it). The quadratic part is Qhat =
   diag(k1 I, mass I) (phgmg.h manual 8.8: mass 1 by default, as the paper's Q; the
   paper's text writes the kinetic term as 1/2 m x_{n+i}^2, so `mass` scales it
   the same way). The quartic is the separable part in polynomial form,
   poly = {0, 0, 0, 0, k2/4}, one term per l_i.
   Orderings: DENSE uses the paper's [l_1..l_n, v_1..v_n]; BANDED the interleaved
   (l_1, v_1, l_2, v_2, ...) with kb = 3. idx_l[i], idx_v[i] give the position
   of l_{i+1}, v_{i+1} in the state either way. */
typedef struct msd_nl_opts {
  int n;                 /* number of masses (required, >= 1)            */
  double mass;           /* 0: 1                                         */
  double gamma;          /* damping of every mass, 0: 0.3 (< 0: exactly 0) */
  double k1, k2;         /* 0: 1 each (< 0: exactly 0)                   */
  phgmg_storage storage; /* DENSE (default) or BANDED                    */
} msd_nl_opts;

typedef struct msd_nonlinear {
  phgmg_ph_system sys;
  int n;
  double *J, *R, *Q, *B, *poly;
  int *idx_l, *idx_v; /* positions of l_i and v_i (n each); idx_l is sys.sep_idx */
} msd_nonlinear;

MSD_FN void msd_nonlinear_free(msd_nonlinear *M) {
  if (!M) return;
  free(M->J); free(M->R); free(M->Q); free(M->B); free(M->poly);
  free(M->idx_l); free(M->idx_v);
  memset(M, 0, sizeof *M);
}

MSD_FN int msd_nonlinear_build(msd_nonlinear *M, const msd_nl_opts *o) {
  int n, N, i, kb = 0, banded;
  double mass, gam, k1, k2;
  size_t len;
  if (!M) return -1;
  memset(M, 0, sizeof *M);
  if (!o || o->n < 1 || (o->storage != PHGMG_DENSE && o->storage != PHGMG_BANDED)) return -1;
  n = o->n;
  N = 2 * n;
  banded = o->storage == PHGMG_BANDED;
  mass = o->mass > 0.0 ? o->mass : 1.0;
  gam = o->gamma > 0.0 ? o->gamma : o->gamma < 0.0 ? 0.0 : 0.3;
  k1 = o->k1 > 0.0 ? o->k1 : o->k1 < 0.0 ? 0.0 : 1.0;
  k2 = o->k2 > 0.0 ? o->k2 : o->k2 < 0.0 ? 0.0 : 1.0;
  if (banded) kb = N - 1 < 3 ? N - 1 : 3;
  len = banded ? (size_t)(2 * kb + 1) * (size_t)N : (size_t)N * (size_t)N;
  M->J = (double *)calloc(len, sizeof(double));
  M->R = (double *)calloc(len, sizeof(double));
  M->Q = (double *)calloc(len, sizeof(double));
  M->B = (double *)calloc((size_t)N, sizeof(double));
  M->poly = (double *)calloc(5, sizeof(double));
  M->idx_l = (int *)malloc(sizeof(int) * (size_t)n);
  M->idx_v = (int *)malloc(sizeof(int) * (size_t)n);
  if (!M->J || !M->R || !M->Q || !M->B || !M->poly || !M->idx_l || !M->idx_v) {
    msd_nonlinear_free(M);
    return -1;
  }
  M->n = n;
  for (i = 0; i < n; ++i) {
    M->idx_l[i] = banded ? 2 * i : i;
    M->idx_v[i] = banded ? 2 * i + 1 : n + i;
  }
#define MSD_AT(A, r, s) \
  (A)[banded ? (size_t)(kb + (r) - (s)) + (size_t)(s) * (size_t)(2 * kb + 1) \
             : (size_t)(r) + (size_t)(s) * (size_t)N]
  for (i = 0; i < n; ++i) {
    int l = M->idx_l[i], v = M->idx_v[i];
    MSD_AT(M->J, l, v) = 1.0;  /* Tt(i,i) = 1 */
    MSD_AT(M->J, v, l) = -1.0;
    if (i + 1 < n) {           /* Tt(i,i+1) = -1 */
      int v1 = M->idx_v[i + 1];
      MSD_AT(M->J, l, v1) = -1.0;
      MSD_AT(M->J, v1, l) = 1.0;
    }
    MSD_AT(M->R, v, v) = gam;
    MSD_AT(M->Q, l, l) = k1;
    MSD_AT(M->Q, v, v) = mass;
  }
#undef MSD_AT
  M->B[M->idx_v[0]] = 1.0;
  M->poly[4] = 0.25 * k2;
  M->sys.N = N;
  M->sys.m = 1;
  M->sys.storage = o->storage;
  M->sys.kb = kb;
  M->sys.J = M->J; M->sys.R = M->R; M->sys.Q = M->Q; M->sys.B = M->B;
  M->sys.nl = PHGMG_NL_SEPARABLE;
  M->sys.nsep = n;
  M->sys.sep_idx = M->idx_l;
  M->sys.sep_w = NULL;
  M->sys.poly_deg = 4;
  M->sys.poly = M->poly;
  return 0;
}

/* The paper's inputs (m = 1): u(t) = 0.1 sin t and u(t) = 0.1. */
MSD_FN void msd_input_sin(double t, double *u, void *user) { (void)user; u[0] = 0.1 * sin(t); }
MSD_FN void msd_input_const(double t, double *u, void *user) { (void)user; (void)t; u[0] = 0.1; }

#endif /* PHGMG_MSD_MODELS_H */
