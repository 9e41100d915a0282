/* Nonlinear dissipation (phgmg_ph_system.ndamp: dampers c_k rho_k(c_k^T z)):
   the full-order stepper's discrete energy balance with the dampers' term,
   dense against banded storage, linear dampers against the same model with
   their c1 c c^T added to R (the linear path: the step map), the result
   codes of dampers that generate energy, and the reduced models (GMG-POD,
   SP1): their dampers W_z^T c_k, the structure of the reduced dissipation,
   their energy balance and linear dampers against the linear-R reduction. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>

/* ---- model ---------------------------------------------------------------------- */
/* A chain of n masses (m_k = 1 + k/n) and springs (k_k = 1, fixed at the
   left), x = (q, p): q the spring elongations, p the momenta, Q = diag(K, M^-1)
   (K = diag(k)), J couples elongation k with momenta k and k+1 (dq_k/dt =
   v_k - v_{k+1}, dp_k/dt = f_k - f_{k-1}), small linear damping R = 0.01 on
   every velocity, one force port at the last mass. Dampers: on the velocity
   of every third mass (s = v_k), and between masses 1 and 2 (s = v_1 - v_2). */
typedef struct dpm {
  int n, N, nd;
  double *J, *R, *Q, *B;
  int di[128], dj[128];
} dpm;

static int dpm_stride = 3;   /* a damper on every dpm_stride-th mass */

static void dpm_make(dpm *c, int n) {
  const int N = 2 * n;
  int k;
  memset(c, 0, sizeof *c);
  c->n = n; c->N = N;
  c->J = (double *)calloc((size_t)N * N, sizeof(double));
  c->R = (double *)calloc((size_t)N * N, sizeof(double));
  c->Q = (double *)calloc((size_t)N * N, sizeof(double));
  c->B = (double *)calloc((size_t)N, sizeof(double));
  for (k = 0; k < n; ++k) {
    c->Q[k + (size_t)k * N] = 1.0;
    c->Q[n + k + (size_t)(n + k) * N] = 1.0 / (1.0 + (double)k / n);
    c->R[n + k + (size_t)(n + k) * N] = 0.01;
    /* dq_k = v_{k-1} - v_k (spring k between mass k-1 and k; spring 0 to the wall) */
    c->J[k + (size_t)(n + k) * N] = -1.0;
    c->J[n + k + (size_t)k * N] = 1.0;
    if (k > 0) {
      c->J[k + (size_t)(n + k - 1) * N] = 1.0;
      c->J[n + k - 1 + (size_t)k * N] = -1.0;
    }
  }
  c->B[N - 1] = 1.0;
  for (k = 0; k < n; k += dpm_stride) { c->di[c->nd] = n + k; c->dj[c->nd] = -1; c->nd++; }
  c->di[c->nd] = n + 1; c->dj[c->nd] = n + 2; c->nd++;
}

static void dpm_free(dpm *c) { free(c->J); free(c->R); free(c->Q); free(c->B); }

static double dpm_law[4] = {0.0, 0.2, 0.0, 3.0}; /* rho(s) = 0.2 s + 3 s^3 */

static phgmg_ph_system dpm_system(const dpm *c, const double *law, int deg) {
  phgmg_ph_system s;
  memset(&s, 0, sizeof s);
  s.N = c->N; s.m = 1; s.J = c->J; s.R = c->R; s.Q = c->Q; s.B = c->B;
  if (law) {
    s.ndamp = c->nd; s.damp_i = c->di; s.damp_j = c->dj;
    s.damp_deg = deg; s.damp_poly = law;
  }
  return s;
}

static const double dp_zero[256];

static void dpm_input(double t, double *u, void *user) {
  (void)user;
  u[0] = 2.0 * sin(1.3 * t) * (t < 8.0 ? 1.0 : 0.0);
}


static double dp_maxdiff(size_t n, const double *a, const double *b) {
  double m = 0.0;
  size_t i;
  for (i = 0; i < n; ++i) m = fabs(a[i] - b[i]) > m ? fabs(a[i] - b[i]) : m;
  return m;
}

static double dp_maxabs(size_t n, const double *a) {
  double m = 0.0;
  size_t i;
  for (i = 0; i < n; ++i) m = fabs(a[i]) > m ? fabs(a[i]) : m;
  return m;
}

/* Full model: the energy balance H_n - H_0 = S_n - D_n (D with the dampers'
   stage quadrature) to round-off for this quadratic H, and the dampers do
   dissipate (D well above that of R alone); dense and banded storage give
   the same trajectory (two different Newton matrices, same stages). */
TEST(test_dissip_fom_energy) {
  dpm c;
  const int n = 12, ns = 400;
  const double dt = 0.05;
  phgmg_ph_system s, sb, s0;
  double *X, *Xb, *X0, *H, *S, *D, *H0, *S0, *D0, *Jb, *Rb, *Qb, e = 0.0, hmax = 0.0;
  phgmg_energy en, en0;
  int i;
  dpm_make(&c, n);
  X = (double *)malloc(sizeof(double) * (size_t)c.N * (ns + 1));
  Xb = (double *)malloc(sizeof(double) * (size_t)c.N * (ns + 1));
  X0 = (double *)malloc(sizeof(double) * (size_t)c.N * (ns + 1));
  H = (double *)malloc(sizeof(double) * 6 * (ns + 1));
  S = H + (ns + 1); D = S + (ns + 1); H0 = D + (ns + 1); S0 = H0 + (ns + 1); D0 = S0 + (ns + 1);
  en.H = H; en.S = S; en.D = D;
  en0.H = H0; en0.S = S0; en0.D = D0;
  s = dpm_system(&c, dpm_law, 3);
  s0 = dpm_system(&c, NULL, 0);
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_simulate(&s, dp_zero, 0.0, dt, ns, dpm_input, NULL, NULL, X, NULL, &en, NULL, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_simulate(&s0, dp_zero, 0.0, dt, ns, dpm_input, NULL, NULL, X0, NULL, &en0, NULL, NULL, NULL), PHGMG_OK);
  for (i = 0; i <= ns; ++i) {
    e = fabs(H[i] - H[0] - S[i] + D[i]) > e ? fabs(H[i] - H[0] - S[i] + D[i]) : e;
    hmax = H[i] > hmax ? H[i] : hmax;
  }
  CHECK_LE(e, 1e-11 * hmax);
  CHECK(D[ns] > 2.0 * D0[ns]);   /* the dampers take out energy */
  CHECK(D[ns] > 0.0);
  /* banded storage, half-bandwidth n + 1 covers J's coupling (n) and the pair damper */
  Jb = th_band(c.N, n + 1, c.J); Rb = th_band(c.N, n + 1, c.R); Qb = th_band(c.N, n + 1, c.Q);
  sb = s; sb.storage = PHGMG_BANDED; sb.kb = n + 1; sb.J = Jb; sb.R = Rb; sb.Q = Qb;
  CHECK_RC(phgmg_simulate(&sb, dp_zero, 0.0, dt, ns, dpm_input, NULL, NULL, Xb, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
  CHECK_LE(dp_maxdiff((size_t)c.N * (ns + 1), X, Xb), 1e-9 * dp_maxabs((size_t)c.N * (ns + 1), X));
  free(Jb); free(Rb); free(Qb);
  free(X); free(Xb); free(X0); free(H);
  dpm_free(&c);
}

/* Linear dampers (rho = c1 s) are the linear model with R + sum c1 c c^T:
   that one runs on the precomputed step map, the damper model on Newton. */
TEST(test_dissip_fom_linear_damper) {
  dpm c;
  const int n = 10, ns = 200;
  const double dt = 0.05, law[2] = {0.0, 0.7};
  phgmg_ph_system s, sl;
  double *X, *Xl, *R2;
  int k;
  dpm_make(&c, n);
  X = (double *)malloc(sizeof(double) * (size_t)c.N * (ns + 1));
  Xl = (double *)malloc(sizeof(double) * (size_t)c.N * (ns + 1));
  R2 = (double *)malloc(sizeof(double) * (size_t)c.N * c.N);
  memcpy(R2, c.R, sizeof(double) * (size_t)c.N * c.N);
  for (k = 0; k < c.nd; ++k) {
    const int i = c.di[k], j = c.dj[k];
    R2[i + (size_t)i * c.N] += law[1];
    if (j >= 0) {
      R2[j + (size_t)j * c.N] += law[1];
      R2[i + (size_t)j * c.N] -= law[1];
      R2[j + (size_t)i * c.N] -= law[1];
    }
  }
  s = dpm_system(&c, law, 1);
  sl = dpm_system(&c, NULL, 0);
  sl.R = R2;
  CHECK_RC(phgmg_simulate(&s, dp_zero, 0.0, dt, ns, dpm_input, NULL, NULL, X, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_simulate(&sl, dp_zero, 0.0, dt, ns, dpm_input, NULL, NULL, Xl, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
  CHECK_LE(dp_maxdiff((size_t)c.N * (ns + 1), X, Xl), 1e-9 * dp_maxabs((size_t)c.N * (ns + 1), Xl));
  free(X); free(Xl); free(R2);
  dpm_free(&c);
}

static void dp_bad_law(int k, double s, double d[2], void *user) {
  (void)k; (void)user;
  d[0] = s > 0.5 ? -s : s;   /* generates energy above s = 0.5 */
  d[1] = s > 0.5 ? -1.0 : 1.0;
}

static void dp_tanh_law(int k, double s, double d[2], void *user) {
  (void)k; (void)user;
  d[0] = 0.5 * tanh(4.0 * s);
  d[1] = 2.0 / (cosh(4.0 * s) * cosh(4.0 * s));
}

/* Dampers that generate energy, and bad damper data, get named codes. */
TEST(test_dissip_bad_input) {
  dpm c;
  const double neg[4] = {0.0, -0.1, 0.0, 1.0}, neg3[4] = {0.0, 0.1, 0.0, -1.0}, a0[2] = {0.1, 1.0},
               even[3] = {0.0, 1.0, 1.0}, nan1[2] = {0.0, (double)NAN};
  phgmg_ph_system s;
  phgmg_gl3 *g = NULL;
  double x[64], *X;
  int di_bad[64], k, done = -1;
  dpm_make(&c, 8);
  X = (double *)malloc(sizeof(double) * (size_t)c.N * 401);
  s = dpm_system(&c, neg, 3);
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_DAMPER);
  CHECK_RC(phgmg_gl3_create(&g, &s, 0.1, NULL, NULL), PHGMG_ERR_DAMPER);
  CHECK(g == NULL);
  s = dpm_system(&c, neg3, 3);
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_DAMPER);
  s = dpm_system(&c, a0, 1);
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_DAMPER);
  s = dpm_system(&c, even, 2);
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_DAMPER);
  s = dpm_system(&c, nan1, 1);
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_NANINF);
  s = dpm_system(&c, dpm_law, 16);
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  for (k = 0; k < c.nd; ++k) di_bad[k] = c.di[k];
  di_bad[0] = c.N;
  s = dpm_system(&c, dpm_law, 3);
  s.damp_i = di_bad;
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  di_bad[0] = c.dj[c.nd - 1];
  s.damp_i = c.di; s.damp_j = NULL;   /* fine: single-coordinate dampers */
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_OK);
  s.damp_j = c.dj; s.damp_i = di_bad; /* damper 0 now from i to i: no direction */
  di_bad[0] = c.dj[0] < 0 ? c.di[0] : c.dj[0];
  {
    int dj2[64];
    for (k = 0; k < c.nd; ++k) dj2[k] = c.dj[k];
    dj2[0] = di_bad[0];
    s.damp_j = dj2;
    CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  }
  s = dpm_system(&c, dpm_law, 3);
  s.damp_poly = NULL;
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  /* a callback damper that generates energy at large speeds: the step that
     reaches it fails with PHGMG_ERR_DAMPER, the steps before are kept */
  s.damp_fn = dp_bad_law;
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_OK);
  for (k = 0; k < c.N; ++k) x[k] = 0.0;
  CHECK_RC(phgmg_simulate(&s, x, 0.0, 0.05, 400, dpm_input, NULL, NULL, X, NULL, NULL, NULL, &done, NULL), PHGMG_ERR_DAMPER);
  CHECK(done > 0 && done < 400);
  s.damp_fn = dp_tanh_law;   /* smooth friction: dissipative */
  CHECK_RC(phgmg_simulate(&s, x, 0.0, 0.05, 400, dpm_input, NULL, NULL, X, NULL, NULL, NULL, &done, NULL), PHGMG_OK);
  free(X);
  dpm_free(&c);
}


/* ---- reduction ------------------------------------------------------------------- */
static double dp_rel(int n, const double *a, const double *b) {
  double num = 0.0, den = 0.0;
  int i;
  for (i = 0; i < n; ++i) { num += (a[i] - b[i]) * (a[i] - b[i]); den += b[i] * b[i]; }
  return sqrt(num / den);
}

/* The reduced dampers are W_z^T c_k with W_z = W from phgmg_reduced_W (E = I),
   the reduced dissipation is non-negative at sampled states (every damper
   s rho(s) >= 0, and -g^T f >= 0 at u = 0), Rr = -(K + K^T)/2 is PSD, the
   online stepper's energy balance holds to round-off (quadratic H), and the
   reduced output follows the full one (e_y small, much smaller than that of
   the same reduction without the dampers). */
/* X (N x nrhs) <- A^{-1} X for a symmetric positive definite A (Cholesky,
   written here: the test's own solve). */
static void dp_spd_solve(int N, const double *A, int nrhs, double *X) {
  double *L = (double *)malloc(sizeof(double) * (size_t)N * N);
  int i, j, k, c;
  for (j = 0; j < N; ++j)
    for (i = j; i < N; ++i) {
      double v = A[i + (size_t)j * N];
      for (k = 0; k < j; ++k) v -= L[i + (size_t)k * N] * L[j + (size_t)k * N];
      L[i + (size_t)j * N] = i == j ? sqrt(v) : v / L[j + (size_t)j * N];
    }
  for (c = 0; c < nrhs; ++c) {
    double *x = X + (size_t)c * N;
    for (i = 0; i < N; ++i) {
      for (k = 0; k < i; ++k) x[i] -= L[i + (size_t)k * N] * x[k];
      x[i] /= L[i + (size_t)i * N];
    }
    for (i = N - 1; i >= 0; --i) {
      for (k = i + 1; k < N; ++k) x[i] -= L[k + (size_t)i * N] * x[k];
      x[i] /= L[i + (size_t)i * N];
    }
  }
  free(L);
}

static void dp_check_reduced(const dpm *c, const phgmg_ph_system *s, const phgmg_reduced *red, const double *Y,
                             int ns, double dt, double ey_max) {
  const phgmg_rom *rom = phgmg_reduced_rom(red);
  const int N = c->N, r = rom->r;
  double *W = (double *)malloc(sizeof(double) * (size_t)N * r), xr[64], g[64], f[64], work[4096], Rr[64 * 64],
         Jr[64 * 64], ev[64], cmax = 0.0, dmax = 0.0;
  double *YR = (double *)malloc(sizeof(double) * (ns + 1)), *EH = (double *)malloc(sizeof(double) * 3 * (ns + 1));
  phgmg_energy en;
  int k, a, t, ok = 1;
  CHECK(rom->ndamp == c->nd);
  CHECK_RC(phgmg_reduced_W(red, xr, W, N), PHGMG_OK);
  if (s->E) dp_spd_solve(N, s->E, r, W);   /* the co-state test basis W_z = E^{-T} W (E symmetric here) */
  for (k = 0; k < rom->ndamp; ++k)
    for (a = 0; a < r; ++a) {
      const double v = W[c->di[k] + (size_t)a * N] - (c->dj[k] >= 0 ? W[c->dj[k] + (size_t)a * N] : 0.0);
      cmax = fabs(v) > cmax ? fabs(v) : cmax;
      dmax = fabs(v - rom->Cd[a + (size_t)k * r]) > dmax ? fabs(v - rom->Cd[a + (size_t)k * r]) : dmax;
    }
  CHECK_LE(dmax, 1e-10 * cmax);
  for (t = 0; t < 200; ++t) {   /* sampled states: dissipation >= 0 */
    double gf = 0.0, gg = 0.0;
    for (a = 0; a < r; ++a) xr[a] = 3.0 * th_rand();
    phgmg_rom_gradient(rom, xr, g, work);
    CHECK_RC(phgmg_rom_rhs(rom, xr, NULL, f, work), PHGMG_OK);
    for (a = 0; a < r; ++a) { gf += g[a] * f[a]; gg += g[a] * g[a]; }
    if (!(gf <= 1e-12 * gg)) ok = 0;
    for (k = 0; k < rom->ndamp; ++k) {
      double sk = 0.0, d[2];
      for (a = 0; a < r; ++a) sk += rom->Cd[a + (size_t)k * r] * g[a];
      phgmg__r_damp_law(rom, k, sk, d);
      if (!(sk * d[0] >= 0.0) || !(rom->dw[k] >= 0.0)) ok = 0;
    }
  }
  CHECK(ok);
  CHECK_RC(phgmg_rom_structure(rom, xr, Jr, Rr, work), PHGMG_OK);
  CHECK_RC(phgmg_sym_eig(r, Rr, r, ev, NULL, 0), PHGMG_OK);
  CHECK(ev[0] >= -1e-12 * fabs(ev[r - 1]));
  /* reduced run on the training input: energy balance and output error */
  for (a = 0; a < r; ++a) xr[a] = 0.0;
  en.H = EH; en.S = EH + ns + 1; en.D = EH + 2 * (ns + 1);
  CHECK_RC(phgmg_reduced_simulate(red, xr, 0.0, dt, ns, dpm_input, NULL, 1e-13, 20, NULL, YR, &en, NULL, NULL), PHGMG_OK);
  {
    double e = 0.0, hm = 0.0;
    for (t = 0; t <= ns; ++t) {
      e = fabs(EH[t] - EH[0] - en.S[t] + en.D[t]) > e ? fabs(EH[t] - EH[0] - en.S[t] + en.D[t]) : e;
      hm = EH[t] > hm ? EH[t] : hm;
    }
    CHECK_LE(e, 1e-11 * hm);
    CHECK(en.D[ns] > 0.0);
  }
  CHECK_LE(dp_rel(ns + 1, YR, Y), ey_max);
  free(W); free(YR); free(EH);
}

TEST(test_dissip_reduce) {
  dpm c;
  const int n = 30, ns = 600, rs[2] = {22, 38};
  const double eys[2] = {1e-2, 1e-5};
  const double dt = 0.05;
  const int methods[2] = {PHGMG_METHOD_GMG_POD, PHGMG_METHOD_SP1};
  phgmg_ph_system s, s0;
  double *X, *Y;
  int mi;
  dpm_make(&c, n);
  X = (double *)malloc(sizeof(double) * (size_t)c.N * (ns + 1));
  Y = (double *)malloc(sizeof(double) * (ns + 1));
  s = dpm_system(&c, dpm_law, 3);
  s0 = dpm_system(&c, NULL, 0);
  CHECK_RC(phgmg_simulate(&s, dp_zero, 0.0, dt, ns, dpm_input, NULL, NULL, X, Y, NULL, NULL, NULL, NULL), PHGMG_OK);
  for (mi = 0; mi < 4; ++mi) {
    const int r = rs[mi / 2];
    phgmg_reduce_opts o;
    phgmg_reduced *red = NULL, *red0 = NULL;
    double *YR0 = (double *)malloc(sizeof(double) * (ns + 1)), xr[64] = {0};
    memset(&o, 0, sizeof o);
    o.method = methods[mi % 2]; o.r = r;
    CHECK_RC(phgmg_reduce(&red, &s, X, c.N, ns + 1, &o, NULL, NULL), PHGMG_OK);
    if (red) dp_check_reduced(&c, &s, red, Y, ns, dt, eys[mi / 2]);
    /* without the dampers the reduced model misses them by far */
    CHECK_RC(phgmg_reduce(&red0, &s0, X, c.N, ns + 1, &o, NULL, NULL), PHGMG_OK);
    CHECK_RC(phgmg_reduced_simulate(red0, xr, 0.0, dt, ns, dpm_input, NULL, 0.0, 0, NULL, YR0, NULL, NULL, NULL), PHGMG_OK);
    CHECK(dp_rel(ns + 1, YR0, Y) > 0.1);
    phgmg_reduced_destroy(red);
    phgmg_reduced_destroy(red0);
    free(YR0);
  }
  {   /* GMG-QM: not supported with dampers */
    phgmg_reduce_opts o;
    phgmg_reduced *red = NULL;
    memset(&o, 0, sizeof o);
    o.method = PHGMG_METHOD_GMG_QM; o.r = 14;
    CHECK_RC(phgmg_reduce(&red, &s, X, c.N, ns + 1, &o, NULL, NULL), PHGMG_ERR_UNSUPPORTED);
    CHECK(red == NULL);
  }
  free(X); free(Y);
  dpm_free(&c);
}

/* Linear dampers: the reduced model equals (to round-off) the reduction of
   the linear model with R + sum c1 c c^T on the same snapshots -- GMG-POD
   (whose G is then the same) and SP1. */
TEST(test_dissip_reduce_linear_damper) {
  dpm c;
  const int n = 20, ns = 300, r = 10;
  const double dt = 0.05, law[2] = {0.0, 0.4};
  const int methods[2] = {PHGMG_METHOD_GMG_POD, PHGMG_METHOD_SP1};
  phgmg_ph_system s, sl;
  double *X, *R2, work[4096];
  int k, mi, t, a;
  dpm_make(&c, n);
  X = (double *)malloc(sizeof(double) * (size_t)c.N * (ns + 1));
  R2 = (double *)malloc(sizeof(double) * (size_t)c.N * c.N);
  memcpy(R2, c.R, sizeof(double) * (size_t)c.N * c.N);
  for (k = 0; k < c.nd; ++k) {
    const int i = c.di[k], j = c.dj[k];
    R2[i + (size_t)i * c.N] += law[1];
    if (j >= 0) {
      R2[j + (size_t)j * c.N] += law[1];
      R2[i + (size_t)j * c.N] -= law[1];
      R2[j + (size_t)i * c.N] -= law[1];
    }
  }
  s = dpm_system(&c, law, 1);
  sl = dpm_system(&c, NULL, 0);
  sl.R = R2;
  CHECK_RC(phgmg_simulate(&sl, dp_zero, 0.0, dt, ns, dpm_input, NULL, NULL, X, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
  for (mi = 0; mi < 2; ++mi) {
    phgmg_reduce_opts o;
    phgmg_reduced *rd = NULL, *rl = NULL;
    double dm = 0.0, fm = 0.0;
    memset(&o, 0, sizeof o);
    o.method = methods[mi]; o.r = r;
    CHECK_RC(phgmg_reduce(&rd, &s, X, c.N, ns + 1, &o, NULL, NULL), PHGMG_OK);
    CHECK_RC(phgmg_reduce(&rl, &sl, X, c.N, ns + 1, &o, NULL, NULL), PHGMG_OK);
    if (rd && rl)
      for (t = 0; t < 50; ++t) {
        double xr[64], fd[64], fl[64], u = th_rand();
        for (a = 0; a < r; ++a) xr[a] = th_rand();
        CHECK_RC(phgmg_rom_rhs(phgmg_reduced_rom(rd), xr, &u, fd, work), PHGMG_OK);
        CHECK_RC(phgmg_rom_rhs(phgmg_reduced_rom(rl), xr, &u, fl, work), PHGMG_OK);
        for (a = 0; a < r; ++a) {
          dm = fabs(fd[a] - fl[a]) > dm ? fabs(fd[a] - fl[a]) : dm;
          fm = fabs(fl[a]) > fm ? fabs(fl[a]) : fm;
        }
      }
    CHECK_LE(dm, 1e-11 * fm);
    phgmg_reduced_destroy(rd);
    phgmg_reduced_destroy(rl);
  }
  free(X); free(R2);
  dpm_free(&c);
}

/* Hyper-reduced dampers (opts.hyper.on = 1, ECSW): a damper on every mass, a
   few kept with weights >= 0, the reduced model still dissipative, its
   energy balance exact, its output close to the full one; with
   hyper.keep_dampers = 1 every damper kept (the blocks those of the model
   without hyper-reduction), 2 refused. */
TEST(test_dissip_reduce_hyper) {
  dpm c;
  const int n = 30, ns = 600, r = 22;
  const double dt = 0.05;
  phgmg_ph_system s;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL, *rh = NULL;
  double *X, *Y, *YR, xr[64] = {0}, ey, eyh;
  int k;
  dpm_stride = 1;
  dpm_make(&c, n);
  dpm_stride = 3;
  X = (double *)malloc(sizeof(double) * (size_t)c.N * (ns + 1));
  Y = (double *)malloc(sizeof(double) * (ns + 1));
  YR = (double *)malloc(sizeof(double) * (ns + 1));
  s = dpm_system(&c, dpm_law, 3);
  CHECK_RC(phgmg_simulate(&s, dp_zero, 0.0, dt, ns, dpm_input, NULL, NULL, X, Y, NULL, NULL, NULL, NULL), PHGMG_OK);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = r;
  CHECK_RC(phgmg_reduce(&red, &s, X, c.N, ns + 1, &o, NULL, NULL), PHGMG_OK);
  o.hyper.on = 1;
  CHECK_RC(phgmg_reduce(&rh, &s, X, c.N, ns + 1, &o, NULL, NULL), PHGMG_OK);
  if (red && rh) {
    const phgmg_rom *rom = phgmg_reduced_rom(rh);
    CHECK(rom->ndamp >= 1 && rom->ndamp < c.nd);
    for (k = 0; k < rom->ndamp; ++k) CHECK(rom->dw[k] >= 0.0);
    CHECK_RC(phgmg_reduced_simulate(red, xr, 0.0, dt, ns, dpm_input, NULL, 0.0, 0, NULL, YR, NULL, NULL, NULL), PHGMG_OK);
    ey = dp_rel(ns + 1, YR, Y);
    CHECK_RC(phgmg_reduced_simulate(rh, xr, 0.0, dt, ns, dpm_input, NULL, 0.0, 0, NULL, YR, NULL, NULL, NULL), PHGMG_OK);
    eyh = dp_rel(ns + 1, YR, Y);
    CHECK_LE(eyh, 2.0 * ey + 1e-3);
  }
  phgmg_reduced_destroy(rh);
  rh = NULL;
  o.hyper.keep_dampers = 1;   /* every damper kept: the model without hyper-reduction, bit for bit */
  CHECK_RC(phgmg_reduce(&rh, &s, X, c.N, ns + 1, &o, NULL, NULL), PHGMG_OK);
  if (red && rh) {
    const phgmg_rom *a = phgmg_reduced_rom(red), *b = phgmg_reduced_rom(rh);
    CHECK(b->ndamp == c.nd && a->ndamp == c.nd);
    CHECK(!memcmp(a->Cd, b->Cd, sizeof(phgmg_real) * (size_t)r * c.nd) && !memcmp(a->K, b->K, sizeof(phgmg_real) * r * r));
  }
  phgmg_reduced_destroy(rh);
  rh = NULL;
  o.hyper.keep_dampers = 2;
  CHECK_RC(phgmg_reduce(&rh, &s, X, c.N, ns + 1, &o, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  phgmg_reduced_destroy(red);
  phgmg_reduced_destroy(rh);
  free(X); free(Y); free(YR);
  dpm_free(&c);
}

/* Model files: a damper model round-trips (format version 3) and steps to
   the same bits; a file whose damper law was rewritten to generate energy
   (checksum recomputed) is refused with PHGMG_ERR_DAMPER; callback
   dampers cannot be saved. */
TEST(test_dissip_rom_file) {
  dpm c;
  const int n = 12, ns = 200, r = 8;
  const double dt = 0.05;
  phgmg_ph_system s;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  double *X;
  dpm_make(&c, n);
  X = (double *)malloc(sizeof(double) * (size_t)c.N * (ns + 1));
  s = dpm_system(&c, dpm_law, 3);
  CHECK_RC(phgmg_simulate(&s, dp_zero, 0.0, dt, ns, dpm_input, NULL, NULL, X, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_SP1; o.r = r;
  CHECK_RC(phgmg_reduce(&red, &s, X, c.N, ns + 1, &o, NULL, NULL), PHGMG_OK);
  if (red) {
    const phgmg_rom *rom = phgmg_reduced_rom(red);
    size_t sz = phgmg_rom_serialized_size(rom), w = 0, need = 0;
    unsigned char *buf = (unsigned char *)malloc(sz);
    double *mem = NULL, mem1[4096], mem2[4096], x1[16] = {0}, x2[16] = {0}, u3[3];
    phgmg_rom lr;
    phgmg_rom_stepper s1, s2;
    int t, a, same = 1;
    CHECK_RC(phgmg_rom_serialize(rom, buf, sz, &w), PHGMG_OK);
    CHECK(w == sz);
    CHECK(buf[8] == 3);
    CHECK_RC(phgmg_rom_deserialize_size(buf, w, &need), PHGMG_OK);
    mem = (double *)malloc(need);
    CHECK_RC(phgmg_rom_deserialize(buf, w, &lr, mem, need), PHGMG_OK);
    CHECK(lr.ndamp == rom->ndamp && lr.damp_deg == 3);
    CHECK_RC(phgmg_rom_stepper_init(&s1, rom, dt, 0.0, 0, mem1, sizeof mem1), PHGMG_OK);
    CHECK_RC(phgmg_rom_stepper_init(&s2, &lr, dt, 0.0, 0, mem2, sizeof mem2), PHGMG_OK);
    for (t = 0; t < 100; ++t) {
      u3[0] = u3[1] = u3[2] = sin(0.1 * t);
      CHECK_RC(phgmg_rom_step(&s1, x1, u3, NULL, NULL), PHGMG_OK);
      CHECK_RC(phgmg_rom_step(&s2, x2, u3, NULL, NULL), PHGMG_OK);
      for (a = 0; a < r; ++a) if (x1[a] != x2[a]) same = 0;
    }
    CHECK(same);
    {   /* the cubic coefficient made negative, checksum fixed: refused */
      const size_t o3 = w - 4 - 8 * 1;   /* dpoly is the last field: a_3 its last scalar */
      double v;
      uint32_t h;
      memcpy(&v, buf + o3, 8);
      CHECK(v == 3.0);
      v = -3.0;
      memcpy(buf + o3, &v, 8);
      h = phgmg__fnv1a(buf, w - 4);
      phgmg__put32(buf + w - 4, h);
      CHECK_RC(phgmg_rom_deserialize(buf, w, &lr, mem, need), PHGMG_ERR_DAMPER);
    }
    free(buf);
    free(mem);
  }
  phgmg_reduced_destroy(red);
  s.damp_poly = NULL; s.damp_fn = dp_tanh_law;
  red = NULL;
  CHECK_RC(phgmg_reduce(&red, &s, X, c.N, ns + 1, &o, NULL, NULL), PHGMG_OK);
  if (red) {
    unsigned char b2[64];
    CHECK_RC(phgmg_rom_serialize(phgmg_reduced_rom(red), b2, sizeof b2, NULL), PHGMG_ERR_UNSUPPORTED);
  }
  phgmg_reduced_destroy(red);
  free(X);
  dpm_free(&c);
}

/* A descriptor model with dampers: the chain in (q, v) with a coupled mass
   matrix E = diag(I, M) (M tridiagonal, SPD), Q = diag(K, I), dampers on the
   velocities. The full balance (Newton tolerance 1e-13), dense = banded, and
   the reduced models (GMG-POD, SP1: dampers W_z^T c_k with W_z = E^{-T} W,
   dissipation, balance, e_y falling with r). */
TEST(test_dissip_descriptor) {
  dpm c;
  const int n = 30, ns = 600, rs[2] = {22, 38};
  const double dt = 0.05, eys[2] = {5e-2, 1e-5};
  const int methods[2] = {PHGMG_METHOD_GMG_POD, PHGMG_METHOD_SP1};
  phgmg_ph_system s, sb;
  phgmg_gl3_opts go;
  phgmg_energy en;
  double *E, *Q2, *X, *Xb, *Y, *EH, *Jb, *Rb, *Qb, *Eb, e = 0.0, hm = 0.0;
  int k, N, t, mi;
  dpm_make(&c, n);
  N = c.N;
  E = (double *)calloc((size_t)N * N, sizeof(double));
  Q2 = (double *)calloc((size_t)N * N, sizeof(double));
  for (k = 0; k < N; ++k) E[k + (size_t)k * N] = 1.0;
  for (k = 0; k < n; ++k) {
    E[n + k + (size_t)(n + k) * N] = 1.0 + (double)k / n;
    if (k + 1 < n) E[n + k + (size_t)(n + k + 1) * N] = E[n + k + 1 + (size_t)(n + k) * N] = 0.2;
    Q2[k + (size_t)k * N] = 1.0;
    Q2[n + k + (size_t)(n + k) * N] = 1.0;
  }
  X = (double *)malloc(sizeof(double) * (size_t)N * (ns + 1));
  Xb = (double *)malloc(sizeof(double) * (size_t)N * (ns + 1));
  Y = (double *)malloc(sizeof(double) * (ns + 1));
  EH = (double *)malloc(sizeof(double) * 3 * (ns + 1));
  en.H = EH; en.S = EH + ns + 1; en.D = EH + 2 * (ns + 1);
  s = dpm_system(&c, dpm_law, 3);
  s.E = E; s.Q = Q2;
  memset(&go, 0, sizeof go);
  go.tol = 1e-13;
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_simulate(&s, dp_zero, 0.0, dt, ns, dpm_input, NULL, &go, X, Y, &en, NULL, NULL, NULL), PHGMG_OK);
  for (t = 0; t <= ns; ++t) {
    e = fabs(EH[t] - EH[0] - en.S[t] + en.D[t]) > e ? fabs(EH[t] - EH[0] - en.S[t] + en.D[t]) : e;
    hm = EH[t] > hm ? EH[t] : hm;
  }
  CHECK_LE(e, 1e-11 * hm);
  Jb = th_band(N, n + 1, c.J); Rb = th_band(N, n + 1, c.R); Qb = th_band(N, n + 1, Q2); Eb = th_band(N, n + 1, E);
  sb = s; sb.storage = PHGMG_BANDED; sb.kb = n + 1; sb.J = Jb; sb.R = Rb; sb.Q = Qb; sb.E = Eb;
  CHECK_RC(phgmg_simulate(&sb, dp_zero, 0.0, dt, ns, dpm_input, NULL, &go, Xb, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
  CHECK_LE(dp_maxdiff((size_t)N * (ns + 1), X, Xb), 1e-9 * dp_maxabs((size_t)N * (ns + 1), X));
  for (mi = 0; mi < 4; ++mi) {
    phgmg_reduce_opts o;
    phgmg_reduced *red = NULL;
    memset(&o, 0, sizeof o);
    o.method = methods[mi % 2]; o.r = rs[mi / 2];
    CHECK_RC(phgmg_reduce(&red, &s, X, N, ns + 1, &o, NULL, NULL), PHGMG_OK);
    if (red) dp_check_reduced(&c, &s, red, Y, ns, dt, eys[mi / 2]);
    phgmg_reduced_destroy(red);
  }
  free(Jb); free(Rb); free(Qb); free(Eb);
  free(E); free(Q2); free(X); free(Xb); free(Y); free(EH);
  dpm_free(&c);
}

/* Feedthrough kept by the reductions (with dampers): Ph = W_z^T P against
   phgmg_reduced_W, Dh = S, the reduced balance with supply y^T u and the
   dissipation [g; u]^T [[Rr, Ph], [Ph^T, S]] [g; u], the output (with
   (S + N) u added) against the full model's, files (a tampered Ph that
   breaks the PSD block is refused), GMG-QM refused. */
TEST(test_dissip_feedthrough) {
  dpm c;
  const int n = 30, ns = 600, rs[2] = {22, 38};
  const double dt = 0.05, eys[2] = {5e-2, 1e-5}, Sv = 0.02;
  const int methods[2] = {PHGMG_METHOD_GMG_POD, PHGMG_METHOD_SP1};
  phgmg_ph_system s;
  double *X, *Y, *P, *W, *YR, *EH, xr[64] = {0};
  phgmg_energy en;
  int mi, a, t, N;
  dpm_make(&c, n);
  N = c.N;
  X = (double *)malloc(sizeof(double) * (size_t)N * (ns + 1));
  W = (double *)malloc(sizeof(double) * (size_t)N * 64);
  Y = (double *)malloc(sizeof(double) * (ns + 1));
  YR = (double *)malloc(sizeof(double) * (ns + 1));
  EH = (double *)malloc(sizeof(double) * 3 * (ns + 1));
  P = (double *)calloc((size_t)N, sizeof(double));
  P[N - 1] = 0.01;   /* [[0.01, 0.01], [0.01, 0.02]] on (v_last, u): PSD */
  P[N - 2] = -0.002;
  en.H = EH; en.S = EH + ns + 1; en.D = EH + 2 * (ns + 1);
  s = dpm_system(&c, dpm_law, 3);
  s.P = P; s.S = &Sv;
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_simulate(&s, dp_zero, 0.0, dt, ns, dpm_input, NULL, NULL, X, Y, NULL, NULL, NULL, NULL), PHGMG_OK);
  for (mi = 0; mi < 4; ++mi) {
    phgmg_reduce_opts o;
    phgmg_reduced *red = NULL;
    const int r = rs[mi / 2];
    memset(&o, 0, sizeof o);
    o.method = methods[mi % 2]; o.r = r;
    CHECK_RC(phgmg_reduce(&red, &s, X, N, ns + 1, &o, NULL, NULL), PHGMG_OK);
    if (red) {
      const phgmg_rom *rom = phgmg_reduced_rom(red);
      double dm = 0.0, pm = 0.0, e = 0.0, hm = 0.0;
      CHECK(rom->PD != NULL);
      CHECK_RC(phgmg_reduced_W(red, xr, W, N), PHGMG_OK);
      for (a = 0; a < r; ++a) {
        double v = 0.0;
        int i;
        for (i = 0; i < N; ++i) v += W[i + (size_t)a * N] * P[i];
        dm = fabs(v - rom->PD[a]) > dm ? fabs(v - rom->PD[a]) : dm;
        pm = fabs(v) > pm ? fabs(v) : pm;
      }
      CHECK_LE(dm, 1e-10 * pm);
      CHECK(rom->PD[r] == Sv);
      CHECK_RC(phgmg_reduced_simulate(red, xr, 0.0, dt, ns, dpm_input, NULL, 1e-13, 20, NULL, YR, &en, NULL, NULL), PHGMG_OK);
      for (t = 0; t <= ns; ++t) {
        e = fabs(EH[t] - EH[0] - en.S[t] + en.D[t]) > e ? fabs(EH[t] - EH[0] - en.S[t] + en.D[t]) : e;
        hm = EH[t] > hm ? EH[t] : hm;
      }
      CHECK_LE(e, 1e-11 * hm);
      CHECK_LE(dp_rel(ns + 1, YR, Y), eys[mi / 2]);
      if (mi == 0) {   /* file round trip; a Ph that breaks the PSD block is refused */
        size_t sz = phgmg_rom_serialized_size(rom), w = 0, need = 0;
        unsigned char *buf = (unsigned char *)malloc(sz);
        double *mem;
        phgmg_rom lr;
        CHECK_RC(phgmg_rom_serialize(rom, buf, sz, &w), PHGMG_OK);
        CHECK_RC(phgmg_rom_deserialize_size(buf, w, &need), PHGMG_OK);
        mem = (double *)malloc(need);
        CHECK_RC(phgmg_rom_deserialize(buf, w, &lr, mem, need), PHGMG_OK);
        CHECK(lr.PD && lr.PD[0] == rom->PD[0] && lr.PD[r] == Sv);
        {   /* PD is the last field: (r + 1) scalars before the checksum; Ph[0] *= 1e6 */
          const size_t o0 = w - 4 - 8 * (size_t)(r + 1);
          double v;
          memcpy(&v, buf + o0, 8);
          CHECK(v == rom->PD[0]);
          v = (v == 0.0 ? 1.0 : v) * 1e6;
          memcpy(buf + o0, &v, 8);
          phgmg__put32(buf + w - 4, phgmg__fnv1a(buf, w - 4));
          CHECK_RC(phgmg_rom_deserialize(buf, w, &lr, mem, need), PHGMG_ERR_FEEDTHROUGH);
        }
        free(buf);
        free(mem);
      }
    }
    phgmg_reduced_destroy(red);
  }
  {
    phgmg_reduce_opts o;
    phgmg_reduced *red = NULL;
    s.ndamp = 0;
    memset(&o, 0, sizeof o);
    o.method = PHGMG_METHOD_GMG_QM; o.r = 14;
    CHECK_RC(phgmg_reduce(&red, &s, X, N, ns + 1, &o, NULL, NULL), PHGMG_ERR_UNSUPPORTED);
  }
  free(X); free(W); free(Y); free(YR); free(EH); free(P);
  dpm_free(&c);
}

SUITE(dissip) {
  RUN(test_dissip_fom_energy);
  RUN(test_dissip_fom_linear_damper);
  RUN(test_dissip_bad_input);
  RUN(test_dissip_reduce);
  RUN(test_dissip_reduce_linear_damper);
  RUN(test_dissip_reduce_hyper);
  RUN(test_dissip_rom_file);
  RUN(test_dissip_descriptor);
  RUN(test_dissip_feedthrough);
}
