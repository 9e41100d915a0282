/* Index-one descriptor models (manual 1.8): E with k zero rows and k zero
   columns. Checked against closed forms (a three-state circuit: the condensed
   J', R', B', P', S' by hand), against an independent simulation of the same
   scheme (here: Gauss-Legendre collocation of the differential-algebraic
   system itself, the 3N stage system with the singular E solved by Gaussian
   elimination, then the algebraic variables from the constraints at the step
   end), against the invariants it claims (constraints hold at every step,
   the discrete energy balance, the dissipation block positive semidefinite,
   dense = banded), and the codes of index two, a singular pencil and E
   singular in another form. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>

/* ---- independent reference: GL3 collocation of E x' = M x + G u ----------------- */
/* Dense Gaussian elimination with partial pivoting: A (n x n) X = B (n x nr), in place. */
static int dae_gauss(int n, double *A, int nr, double *B) {
  int i, j, k, c;
  for (k = 0; k < n; ++k) {
    int p = k;
    for (i = k + 1; i < n; ++i) if (fabs(A[i + (size_t)k * n]) > fabs(A[p + (size_t)k * n])) p = i;
    if (A[p + (size_t)k * n] == 0.0) return 0;
    for (j = 0; j < n; ++j) { double t = A[k + (size_t)j * n]; A[k + (size_t)j * n] = A[p + (size_t)j * n]; A[p + (size_t)j * n] = t; }
    for (c = 0; c < nr; ++c) { double t = B[k + (size_t)c * n]; B[k + (size_t)c * n] = B[p + (size_t)c * n]; B[p + (size_t)c * n] = t; }
    for (i = k + 1; i < n; ++i) {
      const double f = A[i + (size_t)k * n] / A[k + (size_t)k * n];
      if (f == 0.0) continue;
      for (j = k; j < n; ++j) A[i + (size_t)j * n] -= f * A[k + (size_t)j * n];
      for (c = 0; c < nr; ++c) B[i + (size_t)c * n] -= f * B[k + (size_t)c * n];
    }
  }
  for (c = 0; c < nr; ++c)
    for (k = n - 1; k >= 0; --k) {
      double acc = B[k + (size_t)c * n];
      for (j = k + 1; j < n; ++j) acc -= A[k + (size_t)j * n] * B[j + (size_t)c * n];
      B[k + (size_t)c * n] = acc / A[k + (size_t)k * n];
    }
  return 1;
}

typedef struct dae_model {
  int N, m;
  double *E, *J, *R, *Q, *B, *P, *S; /* dense, column-major; P, S may be NULL */
} dae_model;

static void dae_model_alloc(dae_model *d, int N, int m) {
  d->N = N; d->m = m;
  d->E = (double *)calloc((size_t)N * N, sizeof(double));
  d->J = (double *)calloc((size_t)N * N, sizeof(double));
  d->R = (double *)calloc((size_t)N * N, sizeof(double));
  d->Q = (double *)calloc((size_t)N * N, sizeof(double));
  d->B = (double *)calloc((size_t)N * m, sizeof(double));
  d->P = NULL; d->S = NULL;
}
static void dae_model_free(dae_model *d) {
  free(d->E); free(d->J); free(d->R); free(d->Q); free(d->B); free(d->P); free(d->S);
}
static phgmg_ph_system dae_system(const dae_model *d) {
  phgmg_ph_system s;
  memset(&s, 0, sizeof s);
  s.N = d->N; s.m = d->m; s.E = d->E; s.J = d->J; s.R = d->R; s.Q = d->Q; s.B = d->B; s.P = d->P; s.S = d->S;
  return s;
}

static void dae_input(double t, double *u, void *user) {
  int k, m = user ? *(const int *)user : 1;
  for (k = 0; k < m; ++k) u[k] = sin((1.0 + 0.7 * k) * t) * exp(-0.1 * t) + 0.3 * k;
}

/* The reference scheme: stage increments Z from (I x E - h A x M) Z = h (A x I)
   (M x_n + G u(t_n + c_j h))_j, M = (J - R) Q, G = B - P; x~ = x_n + sum_i d_i
   Z_i (d = b^T A^{-1}); then x_{n+1} = x~ with the algebraic variables (zero
   columns of E) solving the algebraic rows (zero rows of E) at t_{n+1}. The
   start x0 = 0 is made consistent the same way at t_0.
   Outputs y = (B + P)^T Q x + S u. */
static void dae_reference(const dae_model *d, double dt, int ns, double *X, double *Y) {
  const int N = d->N, m = d->m, n3 = 3 * N;
  double c[3], b[3], A[9], dd[3], Ai[9], *M, *K, *rhs, *x, *u, *f;
  int i, j, k, l, step, *zr, *zc, na = 0;
  int mm_ = m;
  phgmg_gl3_coefficients(c, b, A);
  for (i = 0; i < 9; ++i) Ai[i] = 0.0;
  { double T[9]; for (i = 0; i < 9; ++i) T[i] = A[(i % 3) * 3 + i / 3]; /* column-major A */
    for (i = 0; i < 3; ++i) Ai[i + 3 * i] = 1.0;
    dae_gauss(3, T, 3, Ai); }
  for (j = 0; j < 3; ++j) { dd[j] = 0.0; for (i = 0; i < 3; ++i) dd[j] += b[i] * Ai[i + 3 * j]; }
  M = (double *)calloc((size_t)N * N, sizeof(double));
  K = (double *)calloc((size_t)n3 * n3, sizeof(double));
  rhs = (double *)calloc((size_t)n3, sizeof(double));
  x = (double *)calloc((size_t)N, sizeof(double));
  f = (double *)calloc((size_t)N, sizeof(double));
  u = (double *)calloc((size_t)m, sizeof(double));
  zr = (int *)calloc((size_t)N, sizeof(int)); zc = (int *)calloc((size_t)N, sizeof(int));
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i)
      for (k = 0; k < N; ++k) M[i + (size_t)j * N] += (d->J[i + (size_t)k * N] - d->R[i + (size_t)k * N]) * d->Q[k + (size_t)j * N];
  for (i = 0; i < N; ++i) {
    zr[i] = zc[i] = 1;
    for (j = 0; j < N; ++j) { if (d->E[i + (size_t)j * N] != 0.0) zr[i] = 0; if (d->E[j + (size_t)i * N] != 0.0) zc[i] = 0; }
    na += zr[i];
  }
  for (step = 0; step <= ns; ++step) {
    const double t = step * dt;
    if (step == 0) memset(x, 0, sizeof(double) * (size_t)N);   /* x0 = 0, made consistent below */
    {
      const double t0 = t - dt;
      double *Kc = (double *)malloc(sizeof(double) * (size_t)n3 * n3);
      for (i = 0; i < 3; ++i)
        for (k = 0; k < 3; ++k)
          for (l = 0; l < N; ++l)
            for (j = 0; j < N; ++j)
              K[(size_t)(i * N + j) + (size_t)(k * N + l) * n3] = (i == k ? d->E[j + (size_t)l * N] : 0.0) - dt * A[i * 3 + k] * M[j + (size_t)l * N];
      for (i = 0; i < 3; ++i) {
        for (j = 0; j < N; ++j) rhs[i * N + j] = 0.0;
        for (k = 0; k < 3; ++k) {
          dae_input(t0 + c[k] * dt, u, &mm_);
          for (j = 0; j < N; ++j) {
            double acc = 0.0;
            for (l = 0; l < N; ++l) acc += M[j + (size_t)l * N] * x[l];
            for (l = 0; l < m; ++l) acc += (d->B[j + (size_t)l * N] - (d->P ? d->P[j + (size_t)l * N] : 0.0)) * u[l];
            rhs[i * N + j] += dt * A[i * 3 + k] * acc;
          }
        }
      }
      memcpy(Kc, K, sizeof(double) * (size_t)n3 * n3);
      if (step > 0) {
        CHECK(dae_gauss(n3, Kc, 1, rhs));
        for (i = 0; i < 3; ++i) for (j = 0; j < N; ++j) x[j] += dd[i] * rhs[i * N + j];
      }
      free(Kc);
      if (na > 0) {   /* the algebraic variables from the constraints at t */
        double *C = (double *)calloc((size_t)na * na, sizeof(double)), *r = (double *)calloc((size_t)na, sizeof(double));
        int p = 0, q;
        dae_input(t, u, &mm_);
        for (i = 0; i < N; ++i) {
          if (!zr[i]) continue;
          double acc = 0.0;
          for (l = 0; l < m; ++l) acc += (d->B[i + (size_t)l * N] - (d->P ? d->P[i + (size_t)l * N] : 0.0)) * u[l];
          for (j = 0, q = 0; j < N; ++j) {
            if (zc[j]) C[p + (size_t)(q++) * na] = M[i + (size_t)j * N];
            else acc += M[i + (size_t)j * N] * x[j];
          }
          r[p++] = -acc;
        }
        CHECK(dae_gauss(na, C, 1, r));
        for (j = 0, q = 0; j < N; ++j) if (zc[j]) x[j] = r[q++];
        free(C); free(r);
      }
    }
    if (X) memcpy(X + (size_t)step * N, x, sizeof(double) * (size_t)N);
    dae_input(t, u, &mm_);
    for (j = 0; j < N; ++j) { f[j] = 0.0; for (l = 0; l < N; ++l) f[j] += d->Q[j + (size_t)l * N] * x[l]; }
    for (k = 0; k < m; ++k) {
      double acc = 0.0;
      for (j = 0; j < N; ++j) acc += (d->B[j + (size_t)k * N] + (d->P ? d->P[j + (size_t)k * N] : 0.0)) * f[j];
      for (l = 0; l < m; ++l) acc += (d->S ? d->S[k + (size_t)l * m] : 0.0) * u[l];
      Y[k + (size_t)step * m] = acc;
    }
  }
  free(M); free(K); free(rhs); free(x); free(f); free(u); free(zr); free(zc);
}

static double dae_rel(size_t n, const double *a, const double *b) {
  double num = 0.0, den = 0.0;
  size_t i;
  for (i = 0; i < n; ++i) { num += (a[i] - b[i]) * (a[i] - b[i]); den += b[i] * b[i]; }
  return sqrt(num / (den > 0.0 ? den : 1.0));
}

/* ---- the three-state circuit ----------------------------------------------------- */
/* x = (x1, x2, x3), E = diag(1, 1, 0), Q = I, J = [[0, 1, 0], [-1, 0, 1], [0, -1, 0]],
   R = diag(0, 0, r3): x3 is algebraic, 0 = -x2 - r3 x3. Condensed by hand:
   J' = [[0, 1], [-1, 0]], R' = diag(0, 1/r3); the port at x1 (B = e1) stays
   B' = e1; a port at x3 (B = e3) becomes B' = 0, P' = (0, -1/r3), S' = S + 1/r3. */
static void dae_circuit(dae_model *d, double r3, int port3) {
  dae_model_alloc(d, 3, 1);
  d->E[0] = 1.0; d->E[4] = 1.0;
  d->Q[0] = d->Q[4] = d->Q[8] = 1.0;
  d->J[0 + 3 * 1] = 1.0; d->J[1 + 3 * 0] = -1.0;
  d->J[1 + 3 * 2] = 1.0; d->J[2 + 3 * 1] = -1.0;
  d->R[8] = r3;
  d->B[port3 ? 2 : 0] = 1.0;
  if (port3) { d->S = (double *)calloc(1, sizeof(double)); d->S[0] = 0.25; }
}

TEST(test_dae_circuit_closed_form) {
  const double r3 = 0.5;
  int port3;
  for (port3 = 0; port3 < 2; ++port3) {
    dae_model d;
    phgmg_ph_system s;
    phgmg_dae *dae = NULL;
    const phgmg_ph_system *c;
    dae_circuit(&d, r3, port3);
    s = dae_system(&d);
    CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_OK);
    CHECK_RC(phgmg_dae_create(&dae, &s, 0.0, NULL), PHGMG_OK);
    if (!dae) { dae_model_free(&d); continue; }
    c = phgmg_dae_system(dae);
    CHECK(phgmg_dae_nalg(dae) == 1 && c->N == 2 && c->m == 1 && c->storage == PHGMG_DENSE);
    CHECK(c->J[2] == 1.0 && c->J[1] == -1.0 && c->J[0] == 0.0 && c->J[3] == 0.0);
    CHECK_LE(fabs(c->R[3] - 1.0 / r3), 1e-15);
    CHECK(c->R[0] == 0.0 && c->R[1] == 0.0 && c->R[2] == 0.0);
    CHECK(c->E[0] == 1.0 && c->E[3] == 1.0 && c->Q[0] == 1.0 && c->Q[3] == 1.0);
    if (!port3) {
      CHECK(c->B[0] == 1.0 && c->B[1] == 0.0 && !c->P && !c->S && !c->Nskew);
    } else {
      CHECK(c->B[0] == 0.0 && c->B[1] == 0.0 && c->P && c->S);
      if (c->P && c->S) {
        CHECK(c->P[0] == 0.0);
        CHECK_LE(fabs(c->P[1] + 1.0 / r3), 1e-15);
        CHECK_LE(fabs(c->S[0] - (0.25 + 1.0 / r3)), 1e-15);
      }
      CHECK(!c->Nskew);
    }
    { /* the lift: x3 from 0 = -x2 - r3 x3 (+ u at a port on x3) */
      double xi[2] = {0.3, -0.7}, x[3], u = 0.9;
      phgmg_dae_lift(dae, xi, &u, x);
      CHECK(x[0] == 0.3 && x[1] == -0.7);
      CHECK_LE(fabs(x[2] - (-xi[1] + (port3 ? u : 0.0)) / r3), 1e-15);
    }
    phgmg_dae_destroy(dae);
    dae_model_free(&d);
  }
}

/* Simulation: phgmg_simulate of the DAE = the reference collocation of the
   DAE (independent), the constraint at every step, and the discrete energy
   balance H_n - H_0 = S_n - D_n with H = (x1^2 + x2^2)/2. */
TEST(test_dae_circuit_simulate) {
  const int ns = 200;
  const double dt = 0.05, r3 = 0.5;
  int port3, one = 1;
  for (port3 = 0; port3 < 2; ++port3) {
    dae_model d;
    phgmg_ph_system s;
    double X[3 * 201], Y[201], Xr[3 * 201], Yr[201], H[201], Sg[201], D[201], x0[3] = {0.4, -0.2, 5.0};
    double cmax = 0.0, emax = 0.0, hmax = 0.0;
    phgmg_energy en;
    int k, done = -1;
    dae_circuit(&d, r3, port3);
    s = dae_system(&d);
    en.H = H; en.S = Sg; en.D = D;
    x0[2] = 5.0;   /* inconsistent: replaced by the constraint's value */
    CHECK_RC(phgmg_simulate(&s, x0, 0.0, dt, ns, dae_input, &one, NULL, X, Y, &en, NULL, &done, NULL), PHGMG_OK);
    CHECK(done == ns);
    CHECK(X[0] == 0.4 && X[1] == -0.2);
    for (k = 0; k <= ns; ++k) {
      double u;
      dae_input(k * dt, &u, &one);
      cmax = fmax(cmax, fabs(-X[3 * k + 1] - r3 * X[3 * k + 2] + (port3 ? u : 0.0)));
      CHECK_LE(fabs(H[k] - 0.5 * (X[3 * k] * X[3 * k] + X[3 * k + 1] * X[3 * k + 1])), 1e-15);
      emax = fmax(emax, fabs(H[k] - H[0] - Sg[k] + D[k]));
      hmax = fmax(hmax, fabs(H[k]));
    }
    CHECK_LE(cmax, 1e-14);
    CHECK_LE(emax, 1e-13 * hmax);
    dae_reference(&d, dt, ns, Xr, Yr);   /* from x0 = 0 */
    x0[0] = x0[1] = x0[2] = 0.0;
    CHECK_RC(phgmg_simulate(&s, x0, 0.0, dt, ns, dae_input, &one, NULL, X, Y, NULL, NULL, NULL,
                            NULL), PHGMG_OK);
    CHECK_LE(dae_rel(3 * (size_t)(ns + 1), X, Xr), 1e-12);
    CHECK_LE(dae_rel((size_t)(ns + 1), Y, Yr), 1e-12);
    dae_model_free(&d);
  }
}

/* Bad input: index two (no resistance at the algebraic node), a singular
   pencil, E singular in another form, and kept co-states that depend on the
   algebraic variable; simulate writes nothing. */
TEST(test_dae_bad_input) {
  dae_model d;
  phgmg_ph_system s;
  phgmg_dae *dae = NULL;
  double X[3 * 11], x0[3] = {0};
  int one = 1, i;
  dae_circuit(&d, 0.0, 0);   /* r3 = 0: 0 = -x2, a constraint on a differential variable */
  s = dae_system(&d);
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_INDEX);
  CHECK_RC(phgmg_dae_create(&dae, &s, 0.0, NULL), PHGMG_ERR_INDEX);
  CHECK(dae == NULL);
  for (i = 0; i < 33; ++i) X[i] = 7.0;
  CHECK_RC(phgmg_simulate(&s, x0, 0.0, 0.1, 10, dae_input, &one, NULL, X, NULL, NULL, NULL, NULL, NULL), PHGMG_ERR_INDEX);
  for (i = 0; i < 33; ++i) CHECK(X[i] == 7.0);
  /* x3 decoupled from everything: det(s E - (J - R) Q) = 0 for every s */
  d.J[1 + 3 * 2] = d.J[2 + 3 * 1] = 0.0;
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_PENCIL);
  dae_model_free(&d);
  /* a zero row without a zero column: E = [[1, 1, 0], [0, 0, 0], [0, 0, 1]] */
  dae_circuit(&d, 0.5, 0);
  memset(d.E, 0, 9 * sizeof(double));
  d.E[0] = d.E[3] = d.E[8] = 1.0;
  s = dae_system(&d);
  CHECK_RC(phgmg_dae_create(&dae, &s, 0.0, NULL), PHGMG_ERR_E_SINGULAR);
  dae_model_free(&d);
  /* Q couples x1's co-state to the algebraic x3: E^T Q not symmetric */
  dae_circuit(&d, 0.5, 0);
  d.Q[0 + 3 * 2] = 0.3;
  s = dae_system(&d);
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_EQ_NOT_SYMMETRIC);
  dae_model_free(&d);
}

/* ---- a finite-element bar with a massless node ---------------------------------- */
/* The bar of tests/test_descriptor.c (n linear elements, consistent mass M,
   Rayleigh damping D = a M + b K, x = (q, v), E = diag(I, M), Q = diag(K, I),
   J = [[0, I], [-I, 0]], R = diag(0, D)) with the mass of node im removed
   (row and column im of M zero): v_im is algebraic, 0 = -(K q)_im - (D v)_im
   (+ a force), index one since D_im,im = b K_im,im > 0. Ports: forces at
   the tip and at node im (a port on the algebraic row: feedthrough). */
static void dae_bar(dae_model *d, int n, int im) {
  const int N = 2 * n;
  const double h = 1.0 / n, ka = 1.0 / h, ma = h / 6.0, ra = 0.05, rb = 2e-3;
  double *K = (double *)calloc((size_t)n * n, sizeof(double)), *M = (double *)calloc((size_t)n * n, sizeof(double));
  int i, j;
  for (i = 0; i < n; ++i) {
    const int last = i == n - 1;
    K[i + (size_t)i * n] = ka * (last ? 1.0 : 2.0);
    M[i + (size_t)i * n] = ma * (last ? 2.0 : 4.0);
    if (i + 1 < n) {
      K[i + (size_t)(i + 1) * n] = K[i + 1 + (size_t)i * n] = -ka;
      M[i + (size_t)(i + 1) * n] = M[i + 1 + (size_t)i * n] = ma;
    }
  }
  for (i = 0; i < n; ++i) M[im + (size_t)i * n] = M[i + (size_t)im * n] = 0.0;
  dae_model_alloc(d, N, 2);
  for (i = 0; i < n; ++i) {
    d->E[i + (size_t)i * N] = 1.0;
    d->Q[n + i + (size_t)(n + i) * N] = 1.0;
    d->J[i + (size_t)(n + i) * N] = 1.0;
    d->J[n + i + (size_t)i * N] = -1.0;
    for (j = 0; j < n; ++j) {
      d->E[n + i + (size_t)(n + j) * N] = M[i + (size_t)j * n];
      d->Q[i + (size_t)j * N] = K[i + (size_t)j * n];
      d->R[n + i + (size_t)(n + j) * N] = ra * M[i + (size_t)j * n] + rb * K[i + (size_t)j * n];
    }
  }
  d->B[n + n - 1] = 1.0;
  d->B[N + n + im] = 1.0;
  free(K); free(M);
}


static const double dae_quartic[5] = {0.0, 0.0, 0.0, 0.0, 0.5};

/* The bar: DAE simulation = the independent reference collocation; banded =
   dense (also with a quartic ground spring at every node); the constraint at
   every step; the energy balance; the condensed dissipation block PSD. */
TEST(test_dae_bar_simulate) {
  const int n = 10, N = 20, ns = 300, two = 2, kb = n;
  const double dt = 0.05;
  dae_model d;
  phgmg_ph_system s, sb;
  double *X = (double *)calloc((size_t)N * (ns + 1), sizeof(double)), *Xr = (double *)calloc((size_t)N * (ns + 1), sizeof(double));
  double *Xb = (double *)calloc((size_t)N * (ns + 1), sizeof(double)), *x0 = (double *)calloc((size_t)N, sizeof(double));
  double Y[2 * 301], Yr[2 * 301], Yb[2 * 301], H[301], Sg[301], D[301];
  double *Eb, *Jb, *Rb, *Qb, emax = 0.0, hmax = 0.0;
  phgmg_energy en;
  int k, nl, idx[10];
  dae_bar(&d, n, 4);
  s = dae_system(&d);
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_simulate(&s, x0, 0.0, dt, ns, dae_input, (void *)&two, NULL, X, Y, NULL, NULL, NULL, NULL), PHGMG_OK);
  dae_reference(&d, dt, ns, Xr, Yr);
  CHECK_LE(dae_rel((size_t)N * (ns + 1), X, Xr), 1e-11);
  CHECK_LE(dae_rel(2 * (size_t)(ns + 1), Y, Yr), 1e-11);
  Eb = th_band(N, kb, d.E); Jb = th_band(N, kb, d.J); Rb = th_band(N, kb, d.R); Qb = th_band(N, kb, d.Q);
  sb = s;
  sb.storage = PHGMG_BANDED; sb.kb = kb; sb.E = Eb; sb.J = Jb; sb.R = Rb; sb.Q = Qb;
  for (k = 0; k < n; ++k) idx[k] = k;
  for (nl = 0; nl < 2; ++nl) {
    if (nl) {
      s.nl = sb.nl = PHGMG_NL_SEPARABLE; s.nsep = sb.nsep = n; s.sep_idx = sb.sep_idx = idx;
      s.poly_deg = sb.poly_deg = 4; s.poly = sb.poly = dae_quartic;
    }
    CHECK_RC(phgmg_ph_validate(&sb, 0.0, NULL, NULL), PHGMG_OK);
    en.H = H; en.S = Sg; en.D = D;
    CHECK_RC(phgmg_simulate(&s, x0, 0.0, dt, ns, dae_input, (void *)&two, NULL, X, Y, NULL, NULL, NULL, NULL), PHGMG_OK);
    CHECK_RC(phgmg_simulate(&sb, x0, 0.0, dt, ns, dae_input, (void *)&two, NULL, Xb, Yb, &en, NULL, NULL, NULL), PHGMG_OK);
    CHECK_LE(dae_rel((size_t)N * (ns + 1), Xb, X), 1e-10);
    CHECK_LE(dae_rel(2 * (size_t)(ns + 1), Yb, Y), 1e-10);
    for (k = 0, emax = hmax = 0.0; k <= ns; ++k) {
      const double *x = Xb + (size_t)k * N;
      double u[2], res;
      int j;
      dae_input(k * dt, u, (void *)&two);
      /* row n + 4 of E x' = L z + B u is algebraic: 0 = -(K q)_4 - (D v)_4 + u_2 */
      res = u[1];
      for (j = 0; j < N; ++j) {
        double z = 0.0;
        int l;
        for (l = 0; l < N; ++l) z += d.Q[j + (size_t)l * N] * x[l];
        if (nl && j < n) z += 2.0 * x[j] * x[j] * x[j];
        res += (d.J[n + 4 + (size_t)j * N] - d.R[n + 4 + (size_t)j * N]) * z;
      }
      CHECK_LE(fabs(res), 1e-10);
      emax = fmax(emax, fabs(H[k] - H[0] - Sg[k] + D[k]));
      hmax = fmax(hmax, fabs(H[k]));
    }
    CHECK(hmax > 0.0);
    if (!nl) CHECK_LE(emax, 1e-12 * hmax);   /* exact for a quadratic H only (manual 1.7) */
  }
  { /* the condensed dissipation block [[R', P'], [P'^T, S']] is PSD (eigenvalues) */
    phgmg_dae *dae = NULL;
    s.nl = PHGMG_NL_NONE;
    CHECK_RC(phgmg_dae_create(&dae, &s, 0.0, NULL), PHGMG_OK);
    if (dae) {
      const phgmg_ph_system *c = phgmg_dae_system(dae);
      const int nc = c->N, nn = nc + 2;
      double *A = (double *)calloc((size_t)nn * nn, sizeof(double)), w[40];
      int i, j;
      CHECK(nc == N - 1 && c->P && c->S);
      for (j = 0; j < nn; ++j)
        for (i = 0; i < nn; ++i)
          A[i + (size_t)j * nn] = i < nc && j < nc ? c->R[i + (size_t)j * nc]
                                 : i < nc ? (c->P ? c->P[i + (size_t)(j - nc) * nc] : 0.0)
                                 : j < nc ? (c->P ? c->P[j + (size_t)(i - nc) * nc] : 0.0)
                                          : (c->S ? c->S[(i - nc) + (size_t)(j - nc) * 2] : 0.0);
      CHECK_RC(phgmg_sym_eig(nn, A, nn, w, NULL, 0), PHGMG_OK);
      CHECK(w[0] >= -1e-12 * w[nn - 1]);
      free(A);
      phgmg_dae_destroy(dae);
    }
  }
  free(X); free(Xr); free(Xb); free(x0); free(Eb); free(Jb); free(Rb); free(Qb);
  dae_model_free(&d);
}

/* Reduction of the condensed model (GMG-POD, SP1) from the restricted
   snapshots: the reduced models are port-Hamiltonian (J skew, R PSD), their
   energy balance holds, and the output error against the DAE falls with r. */
TEST(test_dae_bar_reduce) {
  const int n = 30, N = 60, ns = 400, two = 2;
  const double dt = 0.05;
  dae_model d;
  phgmg_ph_system s;
  phgmg_dae *dae = NULL;
  double *X = (double *)calloc((size_t)N * (ns + 1), sizeof(double)), *Xi, *x0 = (double *)calloc((size_t)N, sizeof(double));
  double Y[2 * 401], YR[2 * 401], H[401], Sg[401], D[401];
  int meth, ri, k, nc;
  dae_bar(&d, n, 11);
  d.B[N - 1 + N] = 0.0;   /* second port at node 25: away from the massless node */
  d.B[n + 25 + N] = 1.0;
  d.B[n + 11 + N] = 0.0;
  s = dae_system(&d);
  CHECK_RC(phgmg_simulate(&s, x0, 0.0, dt, ns, dae_input, (void *)&two, NULL, X, Y, NULL, NULL, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_dae_create(&dae, &s, 0.0, NULL), PHGMG_OK);
  if (!dae) { free(X); free(x0); dae_model_free(&d); return; }
  nc = phgmg_dae_system(dae)->N;
  CHECK(nc == N - 1 && !phgmg_dae_system(dae)->P);
  Xi = (double *)calloc((size_t)nc * (ns + 1), sizeof(double));
  for (k = 0; k <= ns; ++k) phgmg_dae_restrict(dae, X + (size_t)k * N, Xi + (size_t)k * nc);
  for (meth = 0; meth < 2; ++meth) {
    double prev = HUGE_VAL, e6 = HUGE_VAL;
    for (ri = 0; ri < 3; ++ri) {
      const int rr[3] = {6, 12, 18};
      phgmg_reduce_opts o;
      phgmg_reduced *red = NULL;
      phgmg_energy en;
      double xr0[32] = {0}, ey, emax = 0.0, hmax = 0.0;
      phgmg_real Jr[18 * 18], Rr[18 * 18];
      double A[18 * 18], w[18];
      phgmg_real *work;
      const phgmg_rom *rom;
      int r = rr[ri], i, j;
      phgmg_reduce_opts_default(&o);
      o.method = meth ? PHGMG_METHOD_SP1 : PHGMG_METHOD_GMG_POD;
      o.r = r;
      CHECK_RC(phgmg_reduce(&red, phgmg_dae_system(dae), Xi, nc, ns + 1, &o, NULL, NULL), PHGMG_OK);
      if (!red) continue;
      en.H = H; en.S = Sg; en.D = D;
      CHECK_RC(phgmg_reduced_simulate(red, xr0, 0.0, dt, ns, dae_input, (void *)&two, 0.0, 0, NULL, YR, &en, NULL, NULL),
               PHGMG_OK);
      for (k = 0; k <= ns; ++k) { emax = fmax(emax, fabs(H[k] - H[0] - Sg[k] + D[k])); hmax = fmax(hmax, fabs(H[k])); }
      CHECK(hmax > 0.0);
      CHECK_LE(emax, 1e-11 * hmax);
      rom = phgmg_reduced_rom(red);
      work = (phgmg_real *)calloc(phgmg_rom_eval_work_size(rom) + 1, sizeof(phgmg_real));
      CHECK_RC(phgmg_rom_structure(rom, NULL, Jr, Rr, work), PHGMG_OK);
      for (j = 0; j < r; ++j)
        for (i = 0; i < r; ++i) {
          CHECK_LE(fabs(Jr[i + j * r] + Jr[j + i * r]), 1e-12);
          A[i + j * r] = Rr[i + j * r];
        }
      CHECK_RC(phgmg_sym_eig(r, A, r, w, NULL, 0), PHGMG_OK);
      CHECK(w[0] >= -1e-10 * fmax(1.0, w[r - 1]));
      free(work);
      ey = dae_rel(2 * (size_t)(ns + 1), YR, Y);
      if (getenv("DAE_VERBOSE")) printf("method %d r %d e_y %.3e\n", meth, r, ey);
      CHECK_LE(ey, prev);
      if (ri == 0) e6 = ey;
      if (ri == 2) CHECK_LE(ey, 0.35 * e6);   /* r = 18 at least 3x better than r = 6 */
      prev = ey;
      phgmg_reduced_destroy(red);
    }
  }
  free(X); free(Xi); free(x0);
  phgmg_dae_destroy(dae);
  dae_model_free(&d);
}

/* More algebraic lines than the dense elimination takes (k > 4096): an RLC
   ladder in nodal form (examples/circuit_dae.c) with 10000 sections, half of
   its nodes without capacitor: PHGMG_ERR_UNSUPPORTED up front, no memory
   beyond the index maps. */
TEST(test_dae_too_many_constraints) {
  const int n = 10000, N = 2 * n + 1;
  double *E = (double *)calloc((size_t)3 * N, sizeof(double)), *J = (double *)calloc((size_t)3 * N, sizeof(double));
  double *R = (double *)calloc((size_t)3 * N, sizeof(double)), *Q = (double *)calloc((size_t)3 * N, sizeof(double));
  double *B = (double *)calloc((size_t)N, sizeof(double));
  phgmg_ph_system s;
  phgmg_dae *dae = NULL;
  int j;
#define DAE_B(M, a, b) M[(size_t)(1 + (a) - (b)) + (size_t)(b) * 3]
  for (j = 0; j <= n; ++j) { DAE_B(E, 2 * j, 2 * j) = j % 2 ? 0.0 : 1.0; DAE_B(R, 2 * j, 2 * j) = j % 2 ? 1.0 : 0.0; }
  for (j = 1; j <= n; ++j) {
    DAE_B(E, 2 * j - 1, 2 * j - 1) = 1.0;
    DAE_B(J, 2 * j - 1, 2 * j - 2) = 1.0; DAE_B(J, 2 * j - 2, 2 * j - 1) = -1.0;
    DAE_B(J, 2 * j - 1, 2 * j) = -1.0; DAE_B(J, 2 * j, 2 * j - 1) = 1.0;
  }
  for (j = 0; j < N; ++j) DAE_B(Q, j, j) = 1.0;
#undef DAE_B
  B[0] = 1.0;
  memset(&s, 0, sizeof s);
  s.N = N; s.m = 1; s.storage = PHGMG_BANDED; s.kb = 1; s.E = E; s.J = J; s.R = R; s.Q = Q; s.B = B;
  CHECK_RC(phgmg_dae_create(&dae, &s, 0.0, NULL), PHGMG_ERR_UNSUPPORTED);
  CHECK(dae == NULL);
  free(E); free(J); free(R); free(Q); free(B);
}

/* A singular E without zero rows or columns (dense): the bar with a massless
   node seen through orthogonal changes of coordinates, E' = P E T, J' = P J
   P^T, R' = P R P^T, Q' = P Q T, B' = P B (P, T Householder reflections, so
   every entry mixes): the same outputs as the coordinate-aligned model and
   the states x' = T^T x, the index found the same way (index two stays
   index two). */
static void dae_reflect(int N, double *H, unsigned seed) {
  double v[64], vv = 0.0;
  int i, j;
  for (i = 0; i < N; ++i) { v[i] = sin(1.7 * (i + 1) * (seed + 1)) + 0.3; vv += v[i] * v[i]; }
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) H[i + (size_t)j * N] = (i == j ? 1.0 : 0.0) - 2.0 * v[i] * v[j] / vv;
}
static void dae_mm(int N, const double *A, int ta, const double *B, int tb, double *C) {
  int i, j, k;
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) {
      double acc = 0.0;
      for (k = 0; k < N; ++k) acc += (ta ? A[k + (size_t)i * N] : A[i + (size_t)k * N]) * (tb ? B[j + (size_t)k * N] : B[k + (size_t)j * N]);
      C[i + (size_t)j * N] = acc;
    }
}
TEST(test_dae_rotated) {
  const int n = 10, N = 20, ns = 200, two = 2;
  const double dt = 0.05;
  dae_model d, w;
  phgmg_ph_system s, sw;
  double P[400], T[400], tmp[400], X[20 * 201], Xw[20 * 201], Y[2 * 201], Yw[2 * 201], x0[20] = {0}, dx = 0.0, xm = 0.0;
  int i, j, k;
  dae_bar(&d, n, 4);
  dae_model_alloc(&w, N, 2);
  dae_reflect(N, P, 1); dae_reflect(N, T, 2);
  dae_mm(N, P, 0, d.E, 0, tmp); dae_mm(N, tmp, 0, T, 0, w.E);
  dae_mm(N, P, 0, d.J, 0, tmp); dae_mm(N, tmp, 0, P, 1, w.J);
  dae_mm(N, P, 0, d.R, 0, tmp); dae_mm(N, tmp, 0, P, 1, w.R);
  dae_mm(N, P, 0, d.Q, 0, tmp); dae_mm(N, tmp, 0, T, 0, w.Q);
  for (j = 0; j < N; ++j)   /* the products' round-off: J' skew, R' symmetric exactly */
    for (i = 0; i < j; ++i) {
      const double a = 0.5 * (w.J[i + (size_t)j * N] - w.J[j + (size_t)i * N]), c = 0.5 * (w.R[i + (size_t)j * N] + w.R[j + (size_t)i * N]);
      w.J[i + (size_t)j * N] = a; w.J[j + (size_t)i * N] = -a; w.R[i + (size_t)j * N] = w.R[j + (size_t)i * N] = c;
    }
  for (i = 0; i < N; ++i) w.J[i + (size_t)i * N] = 0.0;
  for (k = 0; k < 2; ++k)
    for (i = 0; i < N; ++i) {
      double acc = 0.0;
      for (j = 0; j < N; ++j) acc += P[i + (size_t)j * N] * d.B[j + (size_t)k * N];
      w.B[i + (size_t)k * N] = acc;
    }
  for (i = 0; i < N; ++i) {   /* no zero row or column: the rotation route, not the zero-line one */
    double rmax = 0.0, cmax = 0.0;
    for (j = 0; j < N; ++j) { rmax = fmax(rmax, fabs(w.E[i + (size_t)j * N])); cmax = fmax(cmax, fabs(w.E[j + (size_t)i * N])); }
    CHECK(rmax > 1e-3 && cmax > 1e-3);
  }
  s = dae_system(&d); sw = dae_system(&w);
  CHECK_RC(phgmg_ph_validate(&sw, 0.0, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_simulate(&s, x0, 0.0, dt, ns, dae_input, (void *)&two, NULL, X, Y, NULL, NULL, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_simulate(&sw, x0, 0.0, dt, ns, dae_input, (void *)&two, NULL, Xw, Yw, NULL, NULL, NULL, NULL), PHGMG_OK);
  CHECK_LE(dae_rel(2 * (size_t)(ns + 1), Yw, Y), 1e-10);
  for (k = 0; k <= ns; ++k)   /* x' = T^T x */
    for (i = 0; i < N; ++i) {
      double acc = 0.0;
      for (j = 0; j < N; ++j) acc += T[j + (size_t)i * N] * X[j + (size_t)k * N];
      dx = fmax(dx, fabs(acc - Xw[i + (size_t)k * N]));
      xm = fmax(xm, fabs(acc));
    }
  CHECK_LE(dx, 1e-10 * xm);
  /* index two: no damping at the massless node (D row zero there) */
  for (j = 0; j < n; ++j) d.R[n + 4 + (size_t)(n + j) * N] = d.R[n + j + (size_t)(n + 4) * N] = 0.0;
  dae_mm(N, P, 0, d.R, 0, tmp); dae_mm(N, tmp, 0, P, 1, w.R);
  for (j = 0; j < N; ++j)
    for (i = 0; i < j; ++i) w.R[i + (size_t)j * N] = w.R[j + (size_t)i * N] = 0.5 * (w.R[i + (size_t)j * N] + w.R[j + (size_t)i * N]);
  s = dae_system(&d);
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_INDEX);
  CHECK_RC(phgmg_ph_validate(&sw, 0.0, NULL, NULL), PHGMG_ERR_INDEX);
  dae_model_free(&d);
  dae_model_free(&w);
}

SUITE(dae) {
  RUN(test_dae_circuit_closed_form);
  RUN(test_dae_circuit_simulate);
  RUN(test_dae_bad_input);
  RUN(test_dae_bar_simulate);
  RUN(test_dae_bar_reduce);
  RUN(test_dae_too_many_constraints);
  RUN(test_dae_rotated);
}
