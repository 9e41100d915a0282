/* Online reduced-model path on hand-made models whose answers are known in
   closed form: a harmonic oscillator (exact solution), energy balance of a
   damped linear pH model (exact for GL3 with quadratic H), an analytic Jacobian
   against finite differences, Newton failure leaving the state untouched, and
   the workspace contract. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include "../examples/msd_models.h"

static double osc_err(double h, double T) {
  /* x' = K Qh x with K = [[0,1],[-1,0]], Qh = I: x = (cos t, -sin t) */
  static const phgmg_real K[4] = {0, -1, 1, 0}, Qh[4] = {1, 0, 0, 1}, Bh[2] = {0, 1};
  phgmg_rom rom;
  phgmg_rom_stepper st;
  static double mem[4096];
  phgmg_real x[2] = {1, 0};
  int n, nsteps = (int)(T / h + 0.5);
  memset(&rom, 0, sizeof rom);
  rom.kind = PHGMG_ROM_LINEAR; rom.r = 2; rom.m = 1; rom.K = K; rom.Qh = Qh; rom.Bh = Bh;
  if (phgmg_rom_stepper_init(&st, &rom, (phgmg_real)h, (phgmg_real)1e-14, 10, mem, sizeof mem) != PHGMG_OK) return 1.0;
  for (n = 0; n < nsteps; ++n)
    if (phgmg_rom_step(&st, x, NULL, NULL, NULL) != PHGMG_OK) return 1.0;
  return hypot((double)x[0] - cos(nsteps * h), (double)x[1] + sin(nsteps * h));
}

TEST(test_oscillator_order6) {
  double e1 = osc_err(0.4, 8.0), e2 = osc_err(0.2, 8.0);
  /* GL3 has order 6: halving h divides the error by ~64 */
  CHECK(e1 < 1e-4);
  CHECK_LE(40.0, e1 / e2);
  CHECK_LE(e1 / e2, 90.0);
}

/* a random damped linear pH model of order r with m ports */
static void make_linear(int r, int m, phgmg_real *K, phgmg_real *Qh, phgmg_real *Bh) {
  double J[64], Rm[64], L[64], Qd[64];
  int i, j, k;
  for (i = 0; i < r * r; ++i) { J[i] = th_rand(); L[i] = 0.5 * th_rand(); Qd[i] = th_rand(); }
  for (j = 0; j < r; ++j)
    for (i = 0; i < r; ++i) {
      double s = 0, q = 0;
      for (k = 0; k < r; ++k) { s += L[i + k * r] * L[j + k * r]; q += Qd[i + k * r] * Qd[j + k * r]; }
      Rm[i + j * r] = s;
      K[i + j * r] = (phgmg_real)(0.5 * (J[i + j * r] - J[j + i * r]) - s);
      Qh[i + j * r] = (phgmg_real)(q + (i == j ? 1.0 : 0.0));
    }
  for (i = 0; i < r * m; ++i) Bh[i] = (phgmg_real)th_rand();
  (void)Rm;
}

TEST(test_linear_energy_balance) {
  enum { r = 6, m = 2 };
  phgmg_real K[r * r], Qh[r * r], Bh[r * m], x[r] = {0}, u3[3 * m], work[512], Jr[r * r], Rr[r * r];
  phgmg_rom rom;
  phgmg_rom_stepper st;
  static double mem[8192];
  double H0, S = 0, D = 0, maxrel = 0;
  int n, i;
  make_linear(r, m, K, Qh, Bh);
  memset(&rom, 0, sizeof rom);
  rom.kind = PHGMG_ROM_LINEAR; rom.r = r; rom.m = m; rom.K = K; rom.Qh = Qh; rom.Bh = Bh;
  CHECK_RC(phgmg_rom_check(&rom), PHGMG_OK);
  CHECK(phgmg_rom_eval_work_size(&rom) <= 512);
  /* structure: Jr skew, Rr symmetric with K = Jr - Rr */
  CHECK_RC(phgmg_rom_structure(&rom, x, Jr, Rr, work), PHGMG_OK);
  for (i = 0; i < r * r; ++i) {
    int a = i % r, b = i / r;
    CHECK(Jr[a + b * r] == -Jr[b + a * r]);
    CHECK(Rr[a + b * r] == Rr[b + a * r]);
    CHECK(fabs((double)(Jr[i] - Rr[i] - K[i])) < 1e-15);
  }
  CHECK_RC(phgmg_rom_stepper_init(&st, &rom, 0.1, 1e-13, 10, mem, sizeof mem), PHGMG_OK);
  for (i = 0; i < r; ++i) x[i] = (phgmg_real)th_rand();
  H0 = (double)phgmg_rom_hamiltonian(&rom, x, work);
  for (n = 0; n < 300; ++n) {
    phgmg_real tc[3], en[2] = {0, 0};
    double H;
    phgmg_rom_stage_times(n * 0.1, 0.1, tc);
    for (i = 0; i < 3; ++i) { u3[i * m] = (phgmg_real)sin((double)tc[i]); u3[i * m + 1] = (phgmg_real)0.3; }
    CHECK_RC(phgmg_rom_step(&st, x, u3, NULL, en), PHGMG_OK);
    S += (double)en[0]; D += (double)en[1];
    H = (double)phgmg_rom_hamiltonian(&rom, x, work);
    maxrel = PHGMG__MAX(maxrel, fabs(H - H0 - S + D) / (fabs(H0) + fabs(S) + fabs(D)));
  }
  /* Gauss quadrature is exact for the degree-5 integrand: round-off only */
  CHECK_LE(maxrel, 1e-12);
  CHECK(D > 0.0);
  /* linear + quadratic H: simplified Newton converges in one iteration */
  CHECK(st.stats.newton_iters <= st.stats.steps + 1);
  CHECK(st.stats.factorizations == 1);
}

TEST(test_jacobian_fd_and_newton_failure) {
  enum { r = 4, m = 1, nd = 3 };
  phgmg_real K[r * r], Qh[r * r], Bh[r * m], P0[nd * r], w[nd], x[r], x0[r], work[512];
  phgmg_real Jf[r * r], f1[r], f2[r], xp[r];
  const phgmg_real poly[5] = {0, 0, 0, 0, (phgmg_real)0.25};
  phgmg_rom rom;
  phgmg_rom_stepper st;
  static double mem[8192];
  double maxerr = 0, scale = 0;
  int a, b, i;
  make_linear(r, m, K, Qh, Bh);
  for (i = 0; i < nd * r; ++i) P0[i] = (phgmg_real)th_rand();
  for (i = 0; i < nd; ++i) w[i] = (phgmg_real)(1.0 + i);
  memset(&rom, 0, sizeof rom);
  rom.kind = PHGMG_ROM_LINEAR; rom.r = r; rom.m = m; rom.K = K; rom.Qh = Qh; rom.Bh = Bh;
  rom.nd = nd; rom.P0 = P0; rom.w = w; rom.poly = poly; rom.poly_deg = 4;
  CHECK_RC(phgmg_rom_check(&rom), PHGMG_OK);
  for (i = 0; i < r; ++i) x[i] = (phgmg_real)th_rand();
  CHECK_RC(phgmg_rom_jacobian(&rom, x, Jf, work), PHGMG_OK);
  for (b = 0; b < r; ++b) {
    const double h = 1e-5;
    for (i = 0; i < r; ++i) xp[i] = x[i];
    xp[b] = x[b] + h; phgmg_rom_rhs(&rom, xp, NULL, f1, work);
    xp[b] = x[b] - h; phgmg_rom_rhs(&rom, xp, NULL, f2, work);
    for (a = 0; a < r; ++a) {
      double fd = ((double)f1[a] - (double)f2[a]) / (2 * h);
      maxerr = PHGMG__MAX(maxerr, fabs(fd - (double)Jf[a + b * r]));
      scale = PHGMG__MAX(scale, fabs(fd));
    }
  }
  CHECK_LE(maxerr, 1e-7 * scale);
  /* Newton failure: a large state and a huge step for the quartic term */
  CHECK_RC(phgmg_rom_stepper_init(&st, &rom, 50.0, 1e-12, 3, mem, sizeof mem), PHGMG_OK);
  for (i = 0; i < r; ++i) x[i] = x0[i] = (phgmg_real)(30.0 * th_rand());
  {
    phgmg_result rc = phgmg_rom_step(&st, x, NULL, NULL, NULL);
    CHECK(rc == PHGMG_ERR_NOT_CONVERGED || rc == PHGMG_ERR_NANINF);
  }
  CHECK(memcmp(x, x0, sizeof x) == 0);
  CHECK(st.stats.failures == 1);
}

TEST(test_workspace_contract) {
  static const phgmg_real K[4] = {0, -1, 1, 0}, Qh[4] = {1, 0, 0, 1}, Bh[2] = {0, 1};
  phgmg_rom rom;
  phgmg_rom_stepper st;
  static double mem[4096];
  size_t need;
  memset(&rom, 0, sizeof rom);
  rom.kind = PHGMG_ROM_LINEAR; rom.r = 2; rom.m = 1; rom.K = K; rom.Qh = Qh; rom.Bh = Bh;
  need = phgmg_rom_stepper_memsize(&rom);
  CHECK(need > 0);
  CHECK(need <= PHGMG_ROM_STEPPER_MEMSIZE_MAX(2, 1, 0, 0));
  { /* the compile-time bound covers every size and kind (Newton workspace) */
    static phgmg_real big[64 * 64 * 64];
    const phgmg_real poly[3] = {0, 0, 1};
    phgmg_rom q;
    int r, rn, nd, bad = 0;
    for (r = 2; r <= 40; ++r)
      for (rn = 0; rn <= 12; rn += 4)
        for (nd = 0; nd <= 50; nd += 25) {
          memset(&q, 0, sizeof q);
          q.kind = rn ? PHGMG_ROM_QUADRATIC : PHGMG_ROM_LINEAR; q.r = r; q.m = 1; q.rn = rn; q.nd = nd;
          q.Bh = q.Qh = q.K = q.G00 = q.G01 = q.G10 = q.G11 = q.Q01 = q.Q11 = q.Ms = big;
          if (nd) { q.P0 = q.P1 = q.w = big; q.poly = poly; q.poly_deg = 2; }
          if (phgmg_rom_stepper_memsize(&q) == 0 ||
              phgmg_rom_stepper_memsize(&q) > PHGMG_ROM_STEPPER_MEMSIZE_MAX(r, 1, rn, nd)) bad++;
        }
    CHECK(bad == 0);
  }
  CHECK_RC(phgmg_rom_stepper_init(&st, &rom, 0.1, 0, 0, mem, need - 1), PHGMG_ERR_WORKSPACE);
  CHECK_RC(phgmg_rom_stepper_init(&st, &rom, 0.1, 0, 0, mem, need), PHGMG_OK);
  CHECK_RC(phgmg_rom_stepper_init(&st, &rom, -0.1, 0, 0, mem, need), PHGMG_ERR_INVALID_ARG);
  rom.r = 0;
  CHECK_RC(phgmg_rom_check(&rom), PHGMG_ERR_SIZE);
  rom.r = 2; rom.K = NULL;
  CHECK_RC(phgmg_rom_check(&rom), PHGMG_ERR_INVALID_ARG);
  rom.K = K;
  {
    phgmg_real x[2] = {1, 0};
    phgmg_real u3[3] = {0, (phgmg_real)NAN, 0};
    CHECK_RC(phgmg_rom_stepper_init(&st, &rom, 0.1, 0, 0, mem, need), PHGMG_OK);
    CHECK_RC(phgmg_rom_step(&st, x, u3, NULL, NULL), PHGMG_ERR_NANINF);
    CHECK(x[0] == 1 && x[1] == 0);
  }
}

/* The same RLC ladder in two unit systems: capacitances 1e-9 F / inductances
   1e-6 H (MHz) and 1e-12 F / 1e-9 H (GHz). The GHz ladder is the MHz one with
   time and states scaled by 1e-3 (same impedance sqrt(L/C), same R), so a
   reduced model (GMG-POD, r = 10, no step map: the Newton stepper) must give
   the same outputs at the corresponding steps, and follow the full model as
   closely. With the absolute stage tolerance 1e-10 above the size of these
   states, a stepper that accepts the extrapolated guess without an update
   drifts (before: e_y 3.4e-3 MHz, 2.8 GHz; now 3.4e-4 both). */
static double rlc_w0;
static void rlc_u(double t, double *u, void *p) { (void)p; u[0] = sin(rlc_w0 * t); }
enum { RLC_N = 100, RLC_NS = 1001 };
static double rlc_J[RLC_N * RLC_N], rlc_R[RLC_N * RLC_N], rlc_Q[RLC_N * RLC_N], rlc_B[RLC_N], rlc_X[RLC_N * RLC_NS];
/* The ladder (x = (q1, phi1, q2, phi2, ...): node charges, inductor fluxes;
   a voltage source in series with the first inductor), its training run
   u = sin(0.3 t / sqrt(LC)) into rlc_X and Yf. sc != 1: the states in other
   units, x' = sc x (J, R times sc^2, Q / sc^2, B times sc): the same outputs;
   the full model then takes its Newton path (no step map). */
static phgmg_ph_system rlc_build(double C, double L, double sc, phgmg_run *run, double *Yf, phgmg_result *rc) {
  const int n = RLC_N / 2, N = RLC_N;
  phgmg_ph_system s;
  phgmg_gl3_opts go;
  int i;
  memset(rlc_J, 0, sizeof rlc_J); memset(rlc_R, 0, sizeof rlc_R); memset(rlc_Q, 0, sizeof rlc_Q);
  memset(rlc_B, 0, sizeof rlc_B);
  for (i = 0; i < n; ++i) {
    const int q = 2 * i, f = q + 1;
    rlc_J[q + f * N] = 1.0; rlc_J[f + q * N] = -1.0;
    if (i + 1 < n) { rlc_J[f + (q + 2) * N] = 1.0; rlc_J[(q + 2) + f * N] = -1.0; }
    rlc_R[f + f * N] = 50.0; rlc_Q[q + q * N] = 1.0 / C; rlc_Q[f + f * N] = 1.0 / L;
  }
  rlc_B[1] = 1.0;
  for (i = 0; i < N * N; ++i) { rlc_J[i] *= sc * sc; rlc_R[i] *= sc * sc; rlc_Q[i] /= sc * sc; }
  rlc_B[1] *= sc;
  rlc_w0 = 0.3 / sqrt(L * C);
  memset(&s, 0, sizeof s);
  s.N = N; s.m = 1; s.J = rlc_J; s.R = rlc_R; s.Q = rlc_Q; s.B = rlc_B;
  memset(run, 0, sizeof *run);
  run->u = rlc_u; run->dt = 6.283185307179586 / rlc_w0 / 100.0; run->nsteps = RLC_NS - 1;
  memset(&go, 0, sizeof go);
  go.no_step_map = sc != 1.0;
  *rc = phgmg_simulate_inputs(&s, 1, run, &go, rlc_X, N, Yf, NULL, NULL);
  return s;
}
/* A reduced model of the ladder (r = 10, no step map: the Newton stepper)
   simulated on the training input into Yr; its e_y (NaN on failure, *rrc). */
static double rlc_rom(const phgmg_ph_system *s, const phgmg_run *run, phgmg_method meth, int lambda_auto,
                      const double *Yf, double *Yr, phgmg_result *rrc, double *lambda) {
  double xr0[10] = {0};
  phgmg_reduce_opts o;
  phgmg_reduce_info info;
  phgmg_reduced *red = NULL;
  phgmg_result rc;
  memset(&o, 0, sizeof o);
  o.method = meth; o.r = 10; o.qm.rn = 6; o.select.lambda_mode = lambda_auto; o.nrun = 1; o.runs = run;
  *rrc = phgmg_reduce(&red, s, rlc_X, RLC_N, RLC_NS, &o, &info, NULL);
  if (*rrc != PHGMG_OK) return NAN;
  if (lambda) *lambda = info.lambda;
  rc = phgmg_reduced_simulate(red, xr0, 0.0, run->dt, RLC_NS - 1, rlc_u, NULL, 0.0, 20, NULL, Yr, NULL, NULL, NULL);
  phgmg_reduced_destroy(red);
  return rc == PHGMG_OK ? phgmg_rel_error(1, RLC_NS, Yf, 1, Yr, 1) : NAN;
}
static double rlc_rom_run(double C, double L, double *Yf, double *Yr) {
  phgmg_run run;
  phgmg_result rc;
  const phgmg_ph_system s = rlc_build(C, L, 1.0, &run, Yf, &rc);
  return rc == PHGMG_OK ? rlc_rom(&s, &run, PHGMG_METHOD_GMG_POD, 0, Yf, Yr, &rc, NULL) : NAN;
}
TEST(test_rom_tiny_state_scale) {
  static double Yf1[RLC_NS], Yr1[RLC_NS], Yf2[RLC_NS], Yr2[RLC_NS];
  const double e1 = rlc_rom_run(1e-9, 1e-6, Yf1, Yr1), e2 = rlc_rom_run(1e-12, 1e-9, Yf2, Yr2);
  CHECK(e1 == e1 && e2 == e2);
  CHECK_LE(phgmg_rel_error(1, RLC_NS, Yf1, 1, Yf2, 1), 1e-10);   /* the full models agree */
  CHECK_LE(phgmg_rel_error(1, RLC_NS, Yr1, 1, Yr2, 1), 1e-8);    /* and so must the reduced ones */
  CHECK_LE(e2, 2.0 * e1);
  CHECK_LE(e1, 1e-3);
}

/* Reduction and both steppers do not depend on the units of the states:
   the MHz ladder with charges and fluxes in units 1e-12 and 1e-18 of the SI
   ones (states ~6e3 and ~6e9, B ~1e12 and 1e18) gives the same full and
   reduced outputs with the default tolerances. Before: rcond of D^T G D
   moved by 1/s^2 with B's scale (PHGMG_ERR_DEGENERATE), and the absolute
   Newton tolerance 1e-10 was below the round-off of states ~1e9
   (PHGMG_ERR_NOT_CONVERGED in both steppers). GMG-QM with the automatic
   lambda, whose grid (1e-14..1) is absolute, falls back to the linear limit
   M = 0 there (it failed with PHGMG_ERR_DEGENERATE). */
TEST(test_reduce_state_units) {
  static double Yf1[RLC_NS], Yr1[RLC_NS], Yf2[RLC_NS], Yr2[RLC_NS], Yq[RLC_NS];
  static const double scale[2] = {1e12, 1e18};
  phgmg_result rc1, rc2;
  phgmg_run run;
  double lam = 0.0;
  int k;
  const double e1 = rlc_rom_run(1e-9, 1e-6, Yf1, Yr1);
  CHECK(e1 == e1);
  for (k = 0; k < 2; ++k) {
    const phgmg_ph_system s = rlc_build(1e-9, 1e-6, scale[k], &run, Yf2, &rc1);
    const double e2 = rlc_rom(&s, &run, PHGMG_METHOD_GMG_POD, 0, Yf2, Yr2, &rc2, NULL);
    CHECK_RC(rc1, PHGMG_OK);
    CHECK_RC(rc2, PHGMG_OK);
    CHECK(e2 == e2);
    CHECK_LE(phgmg_rel_error(1, RLC_NS, Yf1, 1, Yf2, 1), 1e-8);
    CHECK_LE(phgmg_rel_error(1, RLC_NS, Yr1, 1, Yr2, 1), 1e-8);
    if (k == 1) {
      const double eq = rlc_rom(&s, &run, PHGMG_METHOD_GMG_QM, 1, Yf2, Yq, &rc2, &lam);
      CHECK_RC(rc2, PHGMG_OK);
      CHECK(eq == eq && lam == HUGE_VAL);
      CHECK_LE(phgmg_rel_error(1, RLC_NS, Yr2, 1, Yq, 1), 1e-9);
    }
  }
}

/* A nonlinear chain with Toda springs phi(l) = e^l - 1 - l, written in
   units x' = s x (J, R times s^2, Q / s^2, B times s, phi(l'/s) as the
   exp-polynomial {-1, -1/s}, (1, 1/s)): GMG-POD with DEIM gives the same
   outputs at s = 1e-6, 1, 1e6; GMG-QM with the automatic lambda succeeds
   at every s and is never worse than 1.02x GMG-POD (its absolute lambda
   grid makes it the linear limit at s = 1e6). */
static void toda_u(double t, double *u, void *p) { (void)p; u[0] = 0.5 * sin(t); }
static double toda_rom(double sc, phgmg_method meth, double *Yf, double *Yr, double *lambda) {
  enum { NS = 301 };
  msd_nonlinear M;
  msd_nl_opts mo;
  double poly[2], expo[2], xr0[10] = {0}, *X, e = NAN;
  phgmg_run run;
  phgmg_reduce_opts o;
  phgmg_reduce_info info;
  phgmg_reduced *red = NULL;
  size_t i, len;
  poly[0] = -1.0; poly[1] = -1.0 / sc; expo[0] = 1.0; expo[1] = 1.0 / sc;
  memset(&mo, 0, sizeof mo);
  mo.n = 50; mo.storage = PHGMG_BANDED; mo.k2 = -1.0;
  if (msd_nonlinear_build(&M, &mo) != 0) return NAN;
  len = (size_t)(2 * M.sys.kb + 1) * (size_t)M.sys.N;
  for (i = 0; i < len; ++i) { M.J[i] *= sc * sc; M.R[i] *= sc * sc; M.Q[i] /= sc * sc; }
  for (i = 0; i < (size_t)M.sys.N; ++i) M.B[i] *= sc;
  M.sys.poly = poly; M.sys.poly_deg = 1; M.sys.nexp = 1; M.sys.expo = expo;
  X = (double *)malloc(sizeof(double) * (size_t)M.sys.N * NS);
  memset(&run, 0, sizeof run);
  run.u = toda_u; run.dt = 0.1; run.nsteps = NS - 1;
  memset(&o, 0, sizeof o);
  o.method = meth; o.r = 10; o.qm.rn = 6; o.hyper.on = 1; o.hyper.allow_negative = 1;
  o.select.lambda_mode = meth == PHGMG_METHOD_GMG_QM; o.nrun = 1; o.runs = &run;
  if (X && phgmg_simulate_inputs(&M.sys, 1, &run, NULL, X, M.sys.N, Yf, NULL, NULL) == PHGMG_OK &&
      phgmg_reduce(&red, &M.sys, X, M.sys.N, NS, &o, &info, NULL) == PHGMG_OK &&
      phgmg_reduced_simulate(red, xr0, 0.0, 0.1, NS - 1, toda_u, NULL, 0.0, 20, NULL, Yr, NULL, NULL, NULL) == PHGMG_OK) {
    e = phgmg_rel_error(1, NS, Yf, 1, Yr, 1);
    if (lambda) *lambda = info.lambda;
  }
  phgmg_reduced_destroy(red);
  free(X);
  msd_nonlinear_free(&M);
  return e;
}
TEST(test_toda_state_units) {
  static double Yf[3][301], Yr[3][301], Yq[301], Yfq[301];
  static const double sc[3] = {1.0, 1e-6, 1e6};
  double ep[3], lam = 0.0;
  int k;
  for (k = 0; k < 3; ++k) {
    double eq;
    ep[k] = toda_rom(sc[k], PHGMG_METHOD_GMG_POD, Yf[k], Yr[k], NULL);
    CHECK(ep[k] == ep[k]);
    eq = toda_rom(sc[k], PHGMG_METHOD_GMG_QM, Yfq, Yq, &lam);
    CHECK(eq == eq);
    CHECK_LE(eq, 1.02 * ep[k]);
    if (k > 0) {
      CHECK_LE(phgmg_rel_error(1, 301, Yf[0], 1, Yf[k], 1), 1e-6);
      CHECK_LE(phgmg_rel_error(1, 301, Yr[0], 1, Yr[k], 1), 1e-6);
    }
  }
}

SUITE(online) {
  RUN(test_oscillator_order6);
  RUN(test_linear_energy_balance);
  RUN(test_jacobian_fd_and_newton_failure);
  RUN(test_workspace_contract);
  RUN(test_rom_tiny_state_scale);
  RUN(test_reduce_state_units);
  RUN(test_toda_state_units);
}
