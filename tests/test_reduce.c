/* Reduction: at states along a trajectory, every reduced
   model is a pH system (J skew, R PSD), the GMG models have Bh = [I; 0] and
   W(x)^T Dphi(x) = I, and the reduced right-hand side equals
   W(x)^T ((J - R) grad H(phi(x)) + B u) evaluated in full dimension — an
   independent computation through phgmg_reduced_W. GMG-POD of the linear MSD
   keeps the discrete energy balance to round-off. The online path never
   calls the allocator. */
#include <stdlib.h>
static int g_alloc_fail = 0;  /* 1: every allocation fails */
static long g_alloc_calls = 0;
static void *test_malloc(size_t n) { g_alloc_calls++; return g_alloc_fail ? NULL : malloc(n); }
#define PHGMG_MALLOC(sz, user) ((void)(user), test_malloc(sz))
#define PHGMG_FREE(p, user) ((void)(user), free(p))
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"

typedef struct tmodel {
  phgmg_ph_system sys;
  double *J, *R, *Q, *B, poly[5];
  int *idx;
} tmodel;

static void tmodel_free(tmodel *t) { free(t->J); free(t->R); free(t->Q); free(t->B); free(t->idx); }

/* Linear MSD of paper 5.2, x = (q1, p1, q2, p2, ...), dense. */
static void linear_msd(tmodel *t, int n, double mass, double k, double c) {
  const int N = 2 * n;
  int i;
  memset(t, 0, sizeof *t);
  t->J = (double *)calloc((size_t)N * N, sizeof(double));
  t->R = (double *)calloc((size_t)N * N, sizeof(double));
  t->Q = (double *)calloc((size_t)N * N, sizeof(double));
  t->B = (double *)calloc((size_t)N, sizeof(double));
  for (i = 0; i < n; ++i) {
    const int q = 2 * i, p = 2 * i + 1;
    t->J[q + p * N] = 1; t->J[p + q * N] = -1;
    t->R[p + p * N] = c;
    t->Q[p + p * N] = 1.0 / mass;
    t->Q[q + q * N] = (i == 0 ? k : 2 * k);
    if (i + 1 < n) { t->Q[q + (q + 2) * N] = -k; t->Q[(q + 2) + q * N] = -k; }
  }
  t->B[1] = 1;
  t->sys.N = N; t->sys.m = 1; t->sys.J = t->J; t->sys.R = t->R; t->sys.Q = t->Q; t->sys.B = t->B;
}

/* Nonlinear MSD of paper 5.3 in l-coordinates [l_1..l_n, v_1..v_n], dense. */
static void nonlinear_msd(tmodel *t, int n, double gamma) {
  const int N = 2 * n;
  int i;
  linear_msd(t, n, 1, 1, 1);
  memset(t->J, 0, sizeof(double) * N * N); memset(t->R, 0, sizeof(double) * N * N);
  memset(t->Q, 0, sizeof(double) * N * N); memset(t->B, 0, sizeof(double) * N);
  for (i = 0; i < n; ++i) {   /* J = [[0, T],[-T^T, 0]], T = I - superdiag */
    t->J[i + (n + i) * N] = 1; t->J[(n + i) + i * N] = -1;
    if (i + 1 < n) { t->J[i + (n + i + 1) * N] = -1; t->J[(n + i + 1) + i * N] = 1; }
    t->R[(n + i) + (n + i) * N] = gamma;
    t->Q[i + i * N] = 1; t->Q[(n + i) + (n + i) * N] = 1;
  }
  t->B[n] = 1;
  t->idx = (int *)malloc(sizeof(int) * n);
  for (i = 0; i < n; ++i) t->idx[i] = i;
  memset(t->poly, 0, sizeof t->poly); t->poly[4] = 0.25;
  t->sys.nl = PHGMG_NL_SEPARABLE; t->sys.nsep = n; t->sys.sep_idx = t->idx;
  t->sys.poly = t->poly; t->sys.poly_deg = 4;
}

static void u_sin(double t, double *u, void *user) { (void)user; u[0] = 0.1 * sin(t); }

static double *snapshots(const phgmg_ph_system *sys, int nsteps, double tol, int maxit) {
  double *X = (double *)malloc(sizeof(double) * sys->N * (nsteps + 1));
  double *x0 = (double *)calloc((size_t)sys->N, sizeof(double));
  phgmg_gl3_opts o;
  memset(&o, 0, sizeof o); o.tol = tol; o.max_iter = maxit;
  if (phgmg_simulate(sys, x0, 0.0, 0.1, nsteps, u_sin, NULL, &o, X, NULL, NULL, NULL, NULL, NULL) != PHGMG_OK) {
    free(X); X = NULL;
  }
  free(x0);
  return X;
}

static double maxabs(int n, const double *a) { double s = 0; int i; for (i = 0; i < n; ++i) s = PHGMG__MAX(s, fabs(a[i])); return s; }

/* The structural checks of the acceptance list at the reduced states rho(x_i). */
static void check_structure(const phgmg_ph_system *sys, const double *X, int ns, phgmg_method meth, int r) {
  const int N = sys->N, m = sys->m;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  phgmg_reduce_info info;
  const phgmg_rom *rom;
  double *W = (double *)malloc(sizeof(double) * N * r), *D = (double *)malloc(sizeof(double) * N * r);
  double *xf = (double *)malloc(sizeof(double) * N), *g = (double *)malloc(sizeof(double) * N);
  double *f = (double *)malloc(sizeof(double) * N), *JW = (double *)malloc(sizeof(double) * N * r);
  double xr[32], fr[32], fref[32], Jr[1024], Rr[1024], Jref[1024], ev[32], work[8192], u = 0.07;
  int s, i, j;
  memset(&o, 0, sizeof o);
  o.method = meth; o.r = r; o.qm.rn = 8; o.qm.lambda = 1e-3;
  CHECK_RC(phgmg_reduce(&red, sys, X, N, ns, &o, &info, NULL), PHGMG_OK);
  if (!red) goto done;
  rom = phgmg_reduced_rom(red);
  CHECK(phgmg_rom_eval_work_size(rom) <= 8192);
  for (s = 0; s < 4; ++s) {
    const double *x = X + (size_t)(ns - 1) * (s + 1) / 4 * N;
    double nJ, nR, nf, emin;
    phgmg_reduced_restrict(red, x, xr);
    /* J skew and R PSD (the split), and both equal W^T J W, W^T R W in full dimension */
    CHECK_RC(phgmg_rom_structure(rom, xr, Jr, Rr, work), PHGMG_OK);
    CHECK_RC(phgmg_reduced_W(red, xr, W, N), PHGMG_OK);
    phgmg_ph_apply(sys, 'J', r, W, N, JW, N);
    phgmg_gemm('T', 'N', r, r, N, 1.0, W, N, JW, N, 0.0, Jref, r);
    nJ = maxabs(r * r, Jref);
    for (i = 0; i < r * r; ++i) Jref[i] -= Jr[i];
    CHECK_LE(maxabs(r * r, Jref), 1e-10 * nJ);
    for (i = 0; i < r; ++i) for (j = 0; j < r; ++j) Jref[i + j * r] = Jr[i + j * r] + Jr[j + i * r];
    CHECK_LE(maxabs(r * r, Jref), 1e-12 * nJ);
    phgmg_ph_apply(sys, 'R', r, W, N, JW, N);
    phgmg_gemm('T', 'N', r, r, N, 1.0, W, N, JW, N, 0.0, Jref, r);
    nR = maxabs(r * r, Jref);
    for (i = 0; i < r * r; ++i) Jref[i] -= Rr[i];
    CHECK_LE(maxabs(r * r, Jref), 1e-10 * nR);
    memcpy(Jref, Rr, sizeof(double) * r * r);
    CHECK_RC(phgmg_sym_eig(r, Jref, r, ev, NULL, 1), PHGMG_OK);
    emin = ev[0];
    CHECK_LE(-1e-12 * nR, emin);
    /* GMG: Bh = [I; 0] and W^T Dphi = I */
    if (meth == PHGMG_METHOD_GMG_POD || meth == PHGMG_METHOD_GMG_QM) {
      for (j = 0; j < m; ++j) for (i = 0; i < r; ++i) CHECK(rom->Bh[i + j * r] == (i == j ? 1.0 : 0.0));
      phgmg_reduced_dphi(red, xr, D, N);
      phgmg_gemm('T', 'N', r, r, N, 1.0, W, N, D, N, 0.0, Jref, r);
      for (i = 0; i < r; ++i) Jref[i + i * r] -= 1.0;
      CHECK_LE(maxabs(r * r, Jref), 1e-10);
    }
    /* reduced rhs against W^T ((J - R) grad H(phi(x)) + B u) in full dimension;
       SP2 replaces grad H by its oblique projection W V^T grad H (manual section 8) */
    CHECK_RC(phgmg_rom_rhs(rom, xr, &u, fr, work), PHGMG_OK);
    phgmg_reduced_lift(red, xr, xf);
    if (meth == PHGMG_METHOD_SP2) {
      phgmg_ph_gradient(sys, xf, g);
      phgmg_reduced_dphi(red, xr, D, N);
      phgmg_gemv('T', N, r, 1.0, D, N, g, 0.0, fref);     /* V^T grad H */
      phgmg_gemv('N', N, r, 1.0, W, N, fref, 0.0, g);      /* W V^T grad H */
      phgmg_ph_apply(sys, 'J', 1, g, N, f, N);
      phgmg_ph_apply(sys, 'R', 1, g, N, xf, N);
      for (i = 0; i < N; ++i) f[i] = f[i] - xf[i] + sys->B[i] * u;
    } else {
      phgmg_ph_rhs(sys, xf, &u, f);
    }
    phgmg_gemv('T', N, r, 1.0, W, N, f, 0.0, fref);
    nf = maxabs(r, fref);
    for (i = 0; i < r; ++i) fref[i] -= fr[i];
    CHECK_LE(maxabs(r, fref), 1e-10 * nf);
    (void)g;
  }
done:
  phgmg_reduced_destroy(red);
  free(W); free(D); free(xf); free(g); free(f); free(JW);
}

/* The analytic derivatives of the online model against central differences
   at states along the trajectory: the Newton Jacobian d f/dx against
   differences of phgmg_rom_rhs, the reduced Hessian against differences of
   phgmg_rom_gradient. The Hessian must also be symmetric to 1e-10 (it is not
   symmetrised anywhere): with DEIM this says the structure-preserving weights
   make the reduced gradient an exact gradient. Difference step h = 1e-5 (1 + |x|):
   truncation ~h^2 and cancellation ~eps/h, both far below the 1e-6 bound. */
static void check_derivatives(const phgmg_ph_system *sys, const double *X, int ns, phgmg_method meth, int r,
                              int deim) {
  const int N = sys->N;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  const phgmg_rom *rom;
  double xr[32], xp[32], f1[32], f2[32], Jf[1024], Hs[1024], work[8192];
  int s, a, b;
  memset(&o, 0, sizeof o);
  o.method = meth; o.r = r; o.qm.rn = 8; o.qm.lambda = 1e-3; o.hyper.on = deim; o.hyper.allow_negative = 1;
  CHECK_RC(phgmg_reduce(&red, sys, X, N, ns, &o, NULL, NULL), PHGMG_OK);
  if (!red) return;
  rom = phgmg_reduced_rom(red);
  CHECK(deim == 0 || rom->nd > 0);
  for (s = 0; s < 4; ++s) {
    double ej = 0, sj = 0, eh = 0, sh = 0, asym = 0;
    phgmg_reduced_restrict(red, X + (size_t)(ns - 1) * (s + 1) / 4 * N, xr);
    CHECK_RC(phgmg_rom_jacobian(rom, xr, Jf, work), PHGMG_OK);
    phgmg_rom_hessian(rom, xr, Hs, work);
    for (b = 0; b < r; ++b) {
      const double h = 1e-5 * (1.0 + fabs(xr[b]));
      double g1[32], g2[32];
      memcpy(xp, xr, sizeof(double) * r);
      xp[b] = xr[b] + h;
      CHECK_RC(phgmg_rom_rhs(rom, xp, NULL, f1, work), PHGMG_OK);
      phgmg_rom_gradient(rom, xp, g1, work);
      xp[b] = xr[b] - h;
      CHECK_RC(phgmg_rom_rhs(rom, xp, NULL, f2, work), PHGMG_OK);
      phgmg_rom_gradient(rom, xp, g2, work);
      for (a = 0; a < r; ++a) {
        const double fd = (f1[a] - f2[a]) / (2 * h), gd = (g1[a] - g2[a]) / (2 * h);
        ej = PHGMG__MAX(ej, fabs(fd - Jf[a + b * r])); sj = PHGMG__MAX(sj, fabs(fd));
        eh = PHGMG__MAX(eh, fabs(gd - Hs[a + b * r])); sh = PHGMG__MAX(sh, fabs(gd));
        asym = PHGMG__MAX(asym, fabs(Hs[a + b * r] - Hs[b + a * r]));
      }
    }
    CHECK(sj > 0 && sh > 0);
    CHECK_LE(ej, 1e-6 * sj);
    CHECK_LE(eh, 1e-6 * sh);
    CHECK_LE(asym, 1e-10 * sh);
  }
  phgmg_reduced_destroy(red);
}

TEST(test_derivatives_every_rom) {
  tmodel t;
  double *X;
  const int rl[3] = {4, 12, 20}, rnl[2] = {6, 16};
  int k;
  linear_msd(&t, 50, 2, 1, 1);
  X = snapshots(&t.sys, 400, 1e-10, 10);
  CHECK(X != NULL);
  for (k = 0; k < 3 && X; ++k) {
    check_derivatives(&t.sys, X, 401, PHGMG_METHOD_GMG_POD, rl[k], 0);
    check_derivatives(&t.sys, X, 401, PHGMG_METHOD_GMG_QM, rl[k], 0);
    check_derivatives(&t.sys, X, 401, PHGMG_METHOD_SP1, rl[k], 0);
  }
  free(X);
  tmodel_free(&t);
  nonlinear_msd(&t, 60, 0.3);
  X = snapshots(&t.sys, 400, 1e-8, 20);
  CHECK(X != NULL);
  for (k = 0; k < 2 && X; ++k) {
    int deim;
    for (deim = 0; deim < 2; ++deim) {
      check_derivatives(&t.sys, X, 401, PHGMG_METHOD_GMG_POD, rnl[k], deim);
      check_derivatives(&t.sys, X, 401, PHGMG_METHOD_GMG_QM, rnl[k], deim);
      check_derivatives(&t.sys, X, 401, PHGMG_METHOD_SP2, rnl[k], deim);
    }
  }
  free(X);
  tmodel_free(&t);
}

/* The online stepper of a GMG-QM model (mass-matrix Newton with frozen
   factors) against an independent GL3: full Newton on the stage equations
   Z - dt (A kron I) F(x + Z) = 0 with F = phgmg_rom_rhs (exact solves with
   D^T G D) and the Jacobian refreshed at every stage and iteration, to 1e-14.
   Both solve the same collocation equations, so after 200 steps the states
   agree to the Newton tolerances (1e-12 for the stepper). */
static void gl3_reference(const phgmg_rom *rom, double *x, double t, double dt, double *work) {
  const int r = rom->r, n3 = 3 * rom->r;
  double c[3], b[3], A[9], Z[96], F[96], Y[32], Jf[3 * 1024], M[96 * 96], Res[96], u;
  int piv[96], it, i, j, a, k;
  phgmg_gl3_coefficients(c, b, A);
  memset(Z, 0, sizeof Z);
  for (it = 0; it < 30; ++it) {
    double nrm = 0;
    for (i = 0; i < 3; ++i) {
      for (a = 0; a < r; ++a) Y[a] = x[a] + Z[i * r + a];
      u = 0.1 * sin(t + c[i] * dt);
      CHECK_RC(phgmg_rom_rhs(rom, Y, &u, F + i * r, work), PHGMG_OK);
      CHECK_RC(phgmg_rom_jacobian(rom, Y, Jf + i * r * r, work), PHGMG_OK);
    }
    for (i = 0; i < 3; ++i)
      for (a = 0; a < r; ++a) {
        double v = Z[i * r + a];
        for (j = 0; j < 3; ++j) v -= dt * A[i * 3 + j] * F[j * r + a];
        Res[i * r + a] = -v;
        nrm = PHGMG__MAX(nrm, fabs(v));
      }
    if (nrm <= 1e-14) break;
    for (j = 0; j < 3; ++j) /* block (i, j) = delta_ij I - dt A_ij Jf(Y_j) */
      for (k = 0; k < r; ++k)
        for (i = 0; i < 3; ++i)
          for (a = 0; a < r; ++a)
            M[(i * r + a) + (size_t)(j * r + k) * n3] =
                (i == j && a == k ? 1.0 : 0.0) - dt * A[i * 3 + j] * Jf[j * r * r + a + k * r];
    CHECK_RC(phgmg_lu_factor(n3, M, n3, piv), PHGMG_OK);
    phgmg_lu_solve('N', n3, M, n3, piv, 1, Res, n3);
    for (i = 0; i < n3; ++i) Z[i] += Res[i];
  }
  CHECK(it < 30);
  for (i = 0; i < 3; ++i)
    for (a = 0; a < r; ++a) x[a] += dt * b[i] * F[i * r + a];
}

TEST(test_qm_stepper_matches_reference_gl3) {
  tmodel t;
  double *X;
  int pass;
  nonlinear_msd(&t, 40, 0.3);
  X = snapshots(&t.sys, 300, 1e-10, 20);
  CHECK(X != NULL);
  for (pass = 0; pass < 2 && X; ++pass) {
    phgmg_reduce_opts o;
    phgmg_reduced *red = NULL;
    const phgmg_rom *rom;
    static double mem[1 << 16];
    double work[8192], x[32], xref[32], dmax = 0, xmax = 0;
    phgmg_rom_stepper st;
    int n, a;
    memset(&o, 0, sizeof o);
    o.method = PHGMG_METHOD_GMG_QM; o.r = pass ? 16 : 8; o.qm.rn = 8; o.qm.lambda = 1e-6; o.hyper.on = pass;
    o.hyper.allow_negative = 1;
    CHECK_RC(phgmg_reduce(&red, &t.sys, X, t.sys.N, 301, &o, NULL, NULL), PHGMG_OK);
    if (!red) continue;
    rom = phgmg_reduced_rom(red);
    phgmg_reduced_restrict(red, X + (size_t)40 * t.sys.N, x);
    memcpy(xref, x, sizeof(double) * rom->r);
    CHECK_RC(phgmg_rom_stepper_init(&st, rom, 0.1, 1e-12, 20, mem, sizeof mem), PHGMG_OK);
    for (n = 0; n < 200; ++n) {
      double u3[3], tc[3];
      phgmg_rom_stage_times(4.0 + n * 0.1, 0.1, tc);
      for (a = 0; a < 3; ++a) u3[a] = 0.1 * sin(tc[a]);
      if (phgmg_rom_step(&st, x, u3, NULL, NULL) != PHGMG_OK) break;
      gl3_reference(rom, xref, 4.0 + n * 0.1, 0.1, work);
    }
    CHECK(n == 200);
    for (a = 0; a < rom->r; ++a) {
      dmax = PHGMG__MAX(dmax, fabs(x[a] - xref[a]));
      xmax = PHGMG__MAX(xmax, fabs(xref[a]));
    }
    CHECK(xmax > 1e-3);
    CHECK_LE(dmax, 1e-9 * xmax);
    phgmg_reduced_destroy(red);
  }
  free(X);
  tmodel_free(&t);
}

TEST(test_structure_linear) {
  tmodel t;
  double *X;
  const int rs[3] = {4, 12, 20};
  int k;
  linear_msd(&t, 50, 2, 1, 1);
  X = snapshots(&t.sys, 400, 1e-10, 10);
  CHECK(X != NULL);
  if (X)
    for (k = 0; k < 3; ++k) {
      check_structure(&t.sys, X, 401, PHGMG_METHOD_GMG_POD, rs[k]);
      check_structure(&t.sys, X, 401, PHGMG_METHOD_GMG_QM, rs[k]);
      check_structure(&t.sys, X, 401, PHGMG_METHOD_SP1, rs[k]);
    }
  free(X);
  tmodel_free(&t);
}

TEST(test_structure_nonlinear) {
  tmodel t;
  double *X;
  const int rs[2] = {6, 16};
  int k;
  nonlinear_msd(&t, 60, 0.3);
  X = snapshots(&t.sys, 400, 1e-8, 20);
  CHECK(X != NULL);
  if (X)
    for (k = 0; k < 2; ++k) {
      check_structure(&t.sys, X, 401, PHGMG_METHOD_GMG_POD, rs[k]);
      check_structure(&t.sys, X, 401, PHGMG_METHOD_GMG_QM, rs[k]);
      check_structure(&t.sys, X, 401, PHGMG_METHOD_SP2, rs[k]);
    }
  free(X);
  tmodel_free(&t);
}

/* GMG-POD of the linear MSD: H(x_n) - H(x_0) = supplied - dissipated to round-off,
   for the Newton path and the precomputed step map. */
TEST(test_energy_balance_gmgpod) {
  tmodel t;
  double *X, H[401], S[401], D[401], e[401];
  phgmg_energy en;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  int pass;
  linear_msd(&t, 50, 2, 1, 1);
  X = snapshots(&t.sys, 400, 1e-10, 10);
  en.H = H; en.S = S; en.D = D;
  for (pass = 0; pass < 2 && X; ++pass) {
    double xr[12] = {0}, emax, scale = 0;
    int n;
    memset(&o, 0, sizeof o);
    o.method = PHGMG_METHOD_GMG_POD; o.r = 12; o.dt = pass ? 0.1 : 0.0;
    CHECK_RC(phgmg_reduce(&red, &t.sys, X, t.sys.N, 401, &o, NULL, NULL), PHGMG_OK);
    if (!red) break;
    CHECK((phgmg_reduced_rom(red)->Phi != NULL) == (pass == 1));
    CHECK_RC(phgmg_reduced_simulate(red, xr, 0.0, 0.1, 400, u_sin, NULL, 1e-12, 10, NULL, NULL, &en, NULL, NULL), PHGMG_OK);
    phgmg_err_energy(&en, 400, e);
    emax = maxabs(401, e);
    for (n = 0; n <= 400; ++n) scale = PHGMG__MAX(scale, fabs(S[n]) + fabs(D[n]) + fabs(H[n]));
    CHECK(scale > 1e-4);
    CHECK_LE(emax, 1e-13 * scale);
    phgmg_reduced_destroy(red); red = NULL;
  }
  free(X);
  tmodel_free(&t);
}

/* Every ROM kind steps through the online API while the allocator fails on any
   call: it is never called. Also the reduction error is small and decreasing. */
TEST(test_online_never_allocates) {
  tmodel t;
  double *X;
  const phgmg_method meths[4] = {PHGMG_METHOD_GMG_POD, PHGMG_METHOD_GMG_QM, PHGMG_METHOD_SP2, PHGMG_METHOD_SP1};
  int k;
  nonlinear_msd(&t, 40, 0.3);
  X = snapshots(&t.sys, 300, 1e-8, 20);
  for (k = 0; k < 4 && X; ++k) {
    phgmg_reduce_opts o;
    phgmg_reduced *red = NULL;
    static double mem[1 << 16];
    phgmg_rom_stepper st;
    phgmg_real x[16] = {0}, u3[3], y[1], en[2] = {0, 0};
    long calls;
    int n, i;
    memset(&o, 0, sizeof o);
    o.method = meths[k]; o.r = 12; o.hyper.on = 1; o.hyper.allow_negative = 1; o.qm.lambda = 1e-3;
    CHECK_RC(phgmg_reduce(&red, &t.sys, X, t.sys.N, 301, &o, NULL, NULL), PHGMG_OK);
    if (!red) continue;
    CHECK(phgmg_rom_stepper_memsize(phgmg_reduced_rom(red)) <= sizeof mem);
    calls = g_alloc_calls;
    g_alloc_fail = 1;
    CHECK_RC(phgmg_rom_stepper_init(&st, phgmg_reduced_rom(red), 0.1, 1e-8, 20, mem, sizeof mem), PHGMG_OK);
    for (n = 0; n < 200; ++n) {
      phgmg_real tc[3];
      phgmg_rom_stage_times(n * 0.1, 0.1, tc);
      for (i = 0; i < 3; ++i) u3[i] = (phgmg_real)(0.1 * sin((double)tc[i]));
      if (phgmg_rom_step(&st, x, u3, y, en) != PHGMG_OK) break;
    }
    g_alloc_fail = 0;
    CHECK(n == 200);
    CHECK(g_alloc_calls == calls);
    phgmg_reduced_destroy(red);
  }
  free(X);
  tmodel_free(&t);
}

/* ---- automatic ridge parameter of GMG-QM (opts.select) ------------------- */

/* The multi-lambda validation of phgmg__ridge_cv (one SVD per fold) against
   the definition computed another way: for every fold (block j of nblk
   contiguous row blocks goes to fold j mod nfold) and lambda, the ridge
   solution on the other rows by phgmg_lstsq (QR of [A; sqrt(lambda) I]) and
   its squared error on the fold's rows, summed and divided by ||Y||_F^2. */
TEST(test_lambda_cv_against_lstsq) {
  enum { NS = 90, NC = 7, RN = 3, NG = 6, NF = 3, NB = 12 };
  static double K[NS * NC], Y[NS * RN], Kt[NS * NC], Yt[NS * RN], T[NC * RN];
  const double grid[NG] = {1e-12, 1e-8, 1e-4, 1e-2, 1.0, 1e6};
  double err[NG], den = 0.0;
  int i, j, a, g, f;
  for (i = 0; i < NS; ++i) {   /* smooth "trajectory" features, noisy targets */
    const double t = 0.1 * i;
    for (j = 0; j < NC; ++j) K[i + j * NS] = sin((j + 1) * 0.37 * t + j) + 0.05 * th_rand();
    for (a = 0; a < RN; ++a) {
      Y[i + a * NS] = 0.02 * th_rand();
      for (j = 0; j < NC; ++j) Y[i + a * NS] += (0.3 * (a + 1) - 0.1 * j) * K[i + j * NS];
      den += Y[i + a * NS] * Y[i + a * NS];
    }
  }
  CHECK_RC(phgmg__ridge_cv(NS, NC, RN, K, NS, Y, NS, NG, grid, NF, NB, err, NULL), PHGMG_OK);
  for (g = 0; g < NG; ++g) {
    double sum = 0.0;
    for (f = 0; f < NF; ++f) {
      int ntr = 0;
      for (i = 0; i < NS; ++i)
        if ((i * NB / NS) % NF != f) {
          for (j = 0; j < NC; ++j) Kt[ntr + j * NS] = K[i + j * NS];
          for (a = 0; a < RN; ++a) Yt[ntr + a * NS] = Y[i + a * NS];
          ++ntr;
        }
      CHECK(ntr > NC && ntr < NS);
      CHECK_RC(phgmg_lstsq(ntr, NC, RN, Kt, NS, Yt, NS, grid[g], T, NC, NULL), PHGMG_OK);
      for (i = 0; i < NS; ++i)
        if ((i * NB / NS) % NF == f)
          for (a = 0; a < RN; ++a) {
            double d = Y[i + a * NS];
            for (j = 0; j < NC; ++j) d -= K[i + j * NS] * T[j + a * NC];
            sum += d * d;
          }
    }
    CHECK_LE(fabs(err[g] - sum / den), 1e-9 * (sum / den) + 1e-15);
  }
  /* large lambda: no better than t = 0; the noise level bounds the best one */
  CHECK_LE(fabs(err[NG - 1] - 1.0), 0.05);
  CHECK_LE(err[1], 0.01);
}

/* Snapshots exactly on a quadratic manifold x = B u + V1 z + V2 M (z kron z)
   (V1, V2 orthonormal, orthogonal to B; the set is symmetric under z -> -z, so
   the POD of the adjusted snapshots separates span V1 from span V2 exactly).
   The automatic lambda must find a small lambda, predict held-out blocks
   almost exactly, and reproduce the manifold at fresh points (so M is
   recovered), where the paper's lambda = 1e-3 cannot. */
TEST(test_lambda_auto_exact_manifold) {
  enum { P = 4, RN = 3, NH = 150, NSN = 2 * NH };
  tmodel t;
  const int r = P + 1;
  int N, i, j, a, b, pass;
  double *V = NULL, *X = NULL, Mt[RN * P * P], z[P], x2[P * P], xr[8];
  double err_fresh[2] = {0, 0};
  phgmg_reduce_info info;
  linear_msd(&t, 20, 2, 1, 1);
  N = t.sys.N;
  V = (double *)malloc(sizeof(double) * N * (P + RN));
  X = (double *)malloc(sizeof(double) * N * NSN);
  /* orthonormal V = [V1, V2], orthogonal to B = e_2 (Gram-Schmidt twice) */
  for (j = 0; j < P + RN; ++j) {
    int pass2;
    for (i = 0; i < N; ++i) V[i + j * N] = th_rand();
    for (pass2 = 0; pass2 < 2; ++pass2) {
      double nrm = 0;
      V[1 + j * N] = 0.0;
      for (b = 0; b < j; ++b) {
        double d = 0;
        for (i = 0; i < N; ++i) d += V[i + b * N] * V[i + j * N];
        for (i = 0; i < N; ++i) V[i + j * N] -= d * V[i + b * N];
      }
      for (i = 0; i < N; ++i) nrm += V[i + j * N] * V[i + j * N];
      for (i = 0; i < N; ++i) V[i + j * N] /= sqrt(nrm);
    }
  }
  /* M symmetric in the Kronecker sense: M(:,(a,b)) = M(:,(b,a)) */
  for (a = 0; a < P; ++a)
    for (b = a; b < P; ++b)
      for (i = 0; i < RN; ++i) Mt[i + (a * P + b) * RN] = Mt[i + (b * P + a) * RN] = 0.05 * th_rand();
#define ON_MANIFOLD(zz, u, x) do { \
    for (i = 0; i < N; ++i) (x)[i] = 0.0; \
    (x)[1] = (u); \
    for (a = 0; a < P; ++a) for (b = 0; b < P; ++b) x2[a * P + b] = (zz)[a] * (zz)[b]; \
    for (a = 0; a < P; ++a) for (i = 0; i < N; ++i) (x)[i] += V[i + a * N] * (zz)[a]; \
    for (a = 0; a < RN; ++a) { double q = 0; for (b = 0; b < P * P; ++b) q += Mt[a + b * RN] * x2[b]; \
      for (i = 0; i < N; ++i) (x)[i] += V[i + (P + a) * N] * q; } } while (0)
  for (j = 0; j < NH; ++j) {   /* a smooth trajectory and its mirror image */
    /* frequencies not in arithmetic progression: with equally spaced ones
       the products z_a z_b along the trajectory are linearly dependent and M
       is not determined by the data (the minimum-norm M misses fresh points) */
    static const double om[P] = {0.7, 1.9, 1.1, 2.9};
    const double tt = 0.1 * j;
    for (a = 0; a < P; ++a) z[a] = (1.0 - 0.2 * a) * sin(om[a] * tt + 0.7 * a);
    ON_MANIFOLD(z, 0.3 * cos(tt), X + (size_t)j * N);
    for (a = 0; a < P; ++a) z[a] = -z[a];
    ON_MANIFOLD(z, -0.3 * cos(tt), X + (size_t)(NH + j) * N);
  }
  for (pass = 0; pass < 2; ++pass) {
    phgmg_reduce_opts o;
    phgmg_reduced *red = NULL;
    double xf[64], xl[64];
    int g, on_grid = 0;
    memset(&o, 0, sizeof o);
    o.method = PHGMG_METHOD_GMG_QM; o.r = r; o.qm.rn = RN; o.select.lambda_mode = pass == 0 ? 2 : 0;
    CHECK_RC(phgmg_reduce(&red, &t.sys, X, N, NSN, &o, &info, NULL), PHGMG_OK);
    if (!red) break;
    if (pass == 0) {
      CHECK(info.lambda_grid == 57);               /* 1e-14 .. 1 at 4 per decade */
      for (g = 0; g < 57; ++g) on_grid |= fabs(info.lambda - 1e-14 * pow(10.0, g / 4.0)) <= 1e-9 * info.lambda;
      CHECK(on_grid);
      CHECK_LE(info.lambda, 1e-8);
      CHECK_LE(info.lambda_cv_err, 1e-12);
      CHECK(info.lambda_raised == 0);
    } else {
      CHECK(info.lambda == 1e-3 && info.lambda_grid == 0 && info.lambda_cv_err == 0.0);
    }
    for (j = 0; j < 20; ++j) {   /* fresh points on the manifold, inside the data range */
      double num = 0, dd = 0;
      for (a = 0; a < P; ++a) z[a] = 0.8 * (1.0 - 0.2 * a) * th_rand();
      ON_MANIFOLD(z, 0.1 * th_rand(), xf);
      phgmg_reduced_restrict(red, xf, xr);
      phgmg_reduced_lift(red, xr, xl);
      for (i = 0; i < N; ++i) { num += (xl[i] - xf[i]) * (xl[i] - xf[i]); dd += xf[i] * xf[i]; }
      err_fresh[pass] = PHGMG__MAX(err_fresh[pass], sqrt(num / dd));
    }
    phgmg_reduced_destroy(red);
  }
#undef ON_MANIFOLD
  CHECK_LE(err_fresh[0], 1e-10);
  CHECK_LE(1e-7, err_fresh[1]);   /* the paper's lambda shrinks M visibly */
  free(V); free(X);
  tmodel_free(&t);
}

/* Linear MSD snapshots: the chosen lambda is a grid point whose held-out
   error is no worse than at either end of the grid (each end evaluated by a
   one-point grid), the guard moves up the grid by whole steps, and the
   in-sample projection error is below the paper's lambda = 1e-3. */
/* GMG-QM's V2 is the POD of (I - V1 V1^T) Xa (paper 4.2.2), which
   phgmg_reduce takes from the basis stage's SVD of Xa (modes p+1..p+rn).
   Independent check: the POD of the explicitly deflated snapshots spans the
   same space, to the perturbation bound eps sigma_1 / gap (Wedin). */
TEST(test_qm_v2_is_hierarchical_pod) {
  tmodel t;
  double *X, *Xa, *U, *S, *P;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  const int r = 12, rn = 8, ns = 401;
  int N, m, p, k = 0, i, j;
  linear_msd(&t, 50, 2, 1, 1);
  N = t.sys.N; m = t.sys.m; p = r - m;
  X = snapshots(&t.sys, ns - 1, 1e-10, 10);
  CHECK(X != NULL);
  if (!X) { tmodel_free(&t); return; }
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_QM; o.r = r; o.qm.rn = rn;
  CHECK_RC(phgmg_reduce(&red, &t.sys, X, N, ns, &o, NULL, NULL), PHGMG_OK);
  Xa = (double *)malloc(sizeof(double) * (size_t)N * ns);
  U = (double *)malloc(sizeof(double) * (size_t)N * (rn + 1));
  S = (double *)malloc(sizeof(double) * (size_t)(rn + 1 + p + 1));
  P = (double *)malloc(sizeof(double) * (size_t)rn * rn);
  if (red && Xa && U && S && P) {
    double s1, gap, err = 0.0;
    CHECK_RC(phgmg_adjust_snapshots(N, m, t.sys.B, ns, X, N, Xa, N, NULL), PHGMG_OK);
    CHECK_RC(phgmg_pod(N, ns, Xa, N, 1, 0.0, U, N, S, &k, NULL), PHGMG_OK);
    s1 = S[0];
    for (j = 0; j < ns; ++j) { /* Xa := (I - V1 V1^T) Xa, V1 = the model's */
      double c[64];
      phgmg_gemv('T', N, p, 1.0, red->V0 + (size_t)N * m, N, Xa + (size_t)j * N, 0.0, c);
      phgmg_gemv('N', N, p, -1.0, red->V0 + (size_t)N * m, N, c, 1.0, Xa + (size_t)j * N);
    }
    CHECK_RC(phgmg_pod(N, ns, Xa, N, rn + 1, 0.0, U, N, S, &k, NULL), PHGMG_OK);
    CHECK(k == rn + 1);
    gap = S[rn - 1] - S[rn];
    CHECK(gap > 0.0);
    /* || U_rn^T V2 || singular values ~ 1: || V2 - U U^T V2 ||_F */
    phgmg_gemm('T', 'N', rn, rn, N, 1.0, U, N, red->V2, N, 0.0, P, rn);
    for (j = 0; j < rn; ++j)
      for (i = 0; i < N; ++i) {
        double v = red->V2[i + (size_t)j * N];
        int a;
        for (a = 0; a < rn; ++a) v -= U[i + (size_t)a * N] * P[a + (size_t)j * rn];
        err += v * v;
      }
    CHECK_LE(sqrt(err), 1e3 * 2.220446049250313e-16 * s1 / gap);
  }
  free(Xa); free(U); free(S); free(P); free(X);
  phgmg_reduced_destroy(red);
  tmodel_free(&t);
}

TEST(test_lambda_auto_linear_msd) {
  tmodel t;
  double *X;
  phgmg_reduce_opts o;
  phgmg_reduce_info info, ilo, ihi, ig, ipod;
  phgmg_reduced *red = NULL;
  double ep_auto = 1, ep_paper = 0;
  const int r = 12, ns = 401;
  linear_msd(&t, 50, 2, 1, 1);
  X = snapshots(&t.sys, ns - 1, 1e-10, 10);
  CHECK(X != NULL);
  if (!X) { tmodel_free(&t); return; }
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_QM; o.r = r; o.qm.rn = 8; o.select.lambda_mode = PHGMG_LAMBDA_REGRESSION; o.select.rcond = 1e-300; /* no guard */
  CHECK_RC(phgmg_reduce(&red, &t.sys, X, t.sys.N, ns, &o, &info, NULL), PHGMG_OK);
  if (red) { ep_auto = phgmg_err_proj(red, X, t.sys.N, ns); phgmg_reduced_destroy(red); red = NULL; }
  CHECK(info.lambda_raised == 0);
  CHECK(info.lambda >= 1e-14 * (1 - 1e-12) && info.lambda <= 1.0);
  CHECK_LE(fabs(4.0 * log10(info.lambda / 1e-14) - floor(4.0 * log10(info.lambda / 1e-14) + 0.5)), 1e-9);
  o.select.lambda_min = o.select.lambda_max = 1e-14;
  CHECK_RC(phgmg_reduce(&red, &t.sys, X, t.sys.N, ns, &o, &ilo, NULL), PHGMG_OK);
  phgmg_reduced_destroy(red); red = NULL;
  o.select.lambda_min = o.select.lambda_max = 1.0;
  CHECK_RC(phgmg_reduce(&red, &t.sys, X, t.sys.N, ns, &o, &ihi, NULL), PHGMG_OK);
  phgmg_reduced_destroy(red); red = NULL;
  CHECK(ilo.lambda_grid == 1 && ihi.lambda_grid == 1 && ilo.lambda == 1e-14 && ihi.lambda == 1.0);
  CHECK_LE(info.lambda_cv_err, ilo.lambda_cv_err);
  CHECK_LE(info.lambda_cv_err, ihi.lambda_cv_err);
  CHECK_LE(info.lambda_cv_err, 0.5);          /* the quadratic term predicts held-out blocks */
  CHECK_LE(0.9, ihi.lambda_cv_err);           /* lambda = 1: M ~ 0 */
  /* against the paper's fixed lambda: the ridge residual on the training data
     grows with lambda, so a smaller lambda projects the snapshots better */
  CHECK(info.lambda < 1e-3);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_QM; o.r = r; o.qm.rn = 8;
  CHECK_RC(phgmg_reduce(&red, &t.sys, X, t.sys.N, ns, &o, NULL, NULL), PHGMG_OK);
  if (red) { ep_paper = phgmg_err_proj(red, X, t.sys.N, ns); phgmg_reduced_destroy(red); red = NULL; }
  CHECK_LE(ep_auto, ep_paper);
  /* a strict guard (rcond at every snapshot >= 0.5 x its value at x = 0, which
     is GMG-POD's rcond at the same r) moves lambda up by whole grid steps */
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = r;
  CHECK_RC(phgmg_reduce(&red, &t.sys, X, t.sys.N, ns, &o, &ipod, NULL), PHGMG_OK);
  phgmg_reduced_destroy(red); red = NULL;
  o.method = PHGMG_METHOD_GMG_QM; o.qm.rn = 8; o.select.lambda_mode = PHGMG_LAMBDA_REGRESSION; o.select.rcond = 0.5;
  CHECK_RC(phgmg_reduce(&red, &t.sys, X, t.sys.N, ns, &o, &ig, NULL), PHGMG_OK);
  phgmg_reduced_destroy(red); red = NULL;
  CHECK(ig.lambda_raised > 0);
  CHECK_LE(fabs(ig.lambda / info.lambda - pow(10.0, ig.lambda_raised / 4.0)), 1e-9 * ig.lambda / info.lambda);
  CHECK(ig.rcond_dgd >= 0.5 * ipod.rcond_dgd * (1 - 1e-12) || ig.lambda == 1.0);
  free(X);
  tmodel_free(&t);
}

/* Bad grid options and sizes, and every allocation failure of the automatic
   path: PHGMG_ERR_NOMEM with nothing left allocated. */
typedef struct tcount { long calls, fail_at, live; } tcount;
static void *tc_alloc(size_t n, void *u) {
  tcount *c = (tcount *)u;
  void *p;
  if (++c->calls == c->fail_at) return NULL;
  p = malloc(n);
  if (p) c->live++;
  return p;
}
static void tc_free(void *p, void *u) { if (p) { ((tcount *)u)->live--; free(p); } }

TEST(test_lambda_auto_options_and_oom) {
  tmodel t;
  double *X;
  phgmg_reduce_opts o, b;
  phgmg_reduce_info info;
  phgmg_reduced *red = NULL;
  tcount c;
  phgmg_allocator al;
  long total, k;
  const int ns = 121;
  linear_msd(&t, 15, 2, 1, 1);
  X = snapshots(&t.sys, ns - 1, 1e-10, 10);
  CHECK(X != NULL);
  if (!X) { tmodel_free(&t); return; }
  memset(&b, 0, sizeof b);
  b.method = PHGMG_METHOD_GMG_QM; b.r = 5; b.qm.rn = 3; b.select.lambda_mode = PHGMG_LAMBDA_REGRESSION;
#define BAD(field, val, code) do { o = b; o.field = (val); \
    CHECK_RC(phgmg_reduce(&red, &t.sys, X, t.sys.N, ns, &o, NULL, NULL), code); CHECK(red == NULL); } while (0)
  BAD(select.lambda_mode, 3, PHGMG_ERR_INVALID_ARG);
  BAD(select.lambda_mode, -1, PHGMG_ERR_INVALID_ARG);
  BAD(select.lambda_min, -1e-6, PHGMG_ERR_INVALID_ARG);
  BAD(select.lambda_min, (double)NAN, PHGMG_ERR_INVALID_ARG);
  BAD(select.lambda_min, 2.0, PHGMG_ERR_INVALID_ARG);          /* above lambda_max = 1 */
  BAD(select.lambda_max, (double)INFINITY, PHGMG_ERR_INVALID_ARG);
  BAD(select.lambda_max, -1.0, PHGMG_ERR_INVALID_ARG);
  BAD(select.per_decade, -1, PHGMG_ERR_INVALID_ARG);
  BAD(select.per_decade, 101, PHGMG_ERR_INVALID_ARG);
  BAD(select.folds, 1, PHGMG_ERR_INVALID_ARG);
  BAD(select.folds, -2, PHGMG_ERR_INVALID_ARG);
  BAD(select.blocks, -1, PHGMG_ERR_INVALID_ARG);
  BAD(select.rcond, -0.5, PHGMG_ERR_INVALID_ARG);
  BAD(select.rcond, 1.5, PHGMG_ERR_INVALID_ARG);
  BAD(select.rcond, (double)NAN, PHGMG_ERR_INVALID_ARG);
  o = b; o.select.lambda_min = 1e-300; o.select.per_decade = 100;  /* 30000 points */
  CHECK_RC(phgmg_reduce(&red, &t.sys, X, t.sys.N, ns, &o, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  BAD(select.blocks, 4, PHGMG_ERR_SIZE);                   /* fewer blocks than the 5 folds */
  BAD(select.blocks, ns + 1, PHGMG_ERR_SIZE);
  BAD(select.folds, ns + 1, PHGMG_ERR_SIZE);
  /* the options are ignored when lambda_auto is off */
  o = b; o.select.lambda_mode = PHGMG_LAMBDA_FIXED; o.select.lambda_min = -1.0; o.select.folds = 1;
  CHECK_RC(phgmg_reduce(&red, &t.sys, X, t.sys.N, ns, &o, NULL, NULL), PHGMG_OK);
  phgmg_reduced_destroy(red); red = NULL;
#undef BAD
  /* allocation failures (with a guard that raises lambda, so the refit path runs) */
  o = b; o.select.rcond = 0.5;
  memset(&c, 0, sizeof c);
  al.alloc = tc_alloc; al.free = tc_free; al.user = &c;
  CHECK_RC(phgmg_reduce(&red, &t.sys, X, t.sys.N, ns, &o, &info, &al), PHGMG_OK);
  phgmg_reduced_destroy(red); red = NULL;
  CHECK(info.lambda_grid == 57 && info.lambda_raised > 0);
  CHECK(c.live == 0);
  total = c.calls;
  for (k = 1; k <= total; ++k) {
    phgmg_result rc;
    c.calls = 0; c.live = 0; c.fail_at = k;
    rc = phgmg_reduce(&red, &t.sys, X, t.sys.N, ns, &o, NULL, &al);
    if (rc == PHGMG_OK) { phgmg_reduced_destroy(red); red = NULL; }
    CHECK_RC(rc, PHGMG_ERR_NOMEM);
    CHECK(c.live == 0 && red == NULL);
  }
  free(X);
  tmodel_free(&t);
}

SUITE(reduce) {
  RUN(test_structure_linear);
  RUN(test_structure_nonlinear);
  RUN(test_derivatives_every_rom);
  RUN(test_qm_stepper_matches_reference_gl3);
  RUN(test_energy_balance_gmgpod);
  RUN(test_online_never_allocates);
  RUN(test_lambda_cv_against_lstsq);
  RUN(test_lambda_auto_exact_manifold);
  RUN(test_qm_v2_is_hierarchical_pod);
  RUN(test_lambda_auto_linear_msd);
  RUN(test_lambda_auto_options_and_oom);
}
