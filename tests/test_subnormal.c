/* Tiny entries and the floating-point environment: the GL3 stepper and the
   reduced stepper flush tiny entries of their own vectors (>>gl3, "Tiny
   entries"), which must not change the results beyond the Newton tolerance,
   must leave no subnormal in the state, must stop subnormal arithmetic
   altogether (the hardware's underflow / denormal-operand flags stay clear),
   and must leave the caller's floating-point environment as it was. */
#if defined(__GNUC__) && !defined(__clang__)
/* GCC 12+ reports a false "may be used uninitialized" in its constant-propagated
   copy of phgmg_svd for this translation unit (the workspace is malloc'd and
   filled by memcpy just before); the other test files do not trigger it. */
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include "../examples/msd_models.h"
#include <fenv.h>
#include <float.h>
#include <stdlib.h>
#if defined(__SSE__) || defined(__x86_64__)
#include <xmmintrin.h>
#define TS_MXCSR 1
#else
#define TS_MXCSR 0
#endif

#define TS_N 400     /* nonlinear chain, 200 masses, banded */
#define TS_STEPS 300 /* the wave's tail reaches the subnormal range after a few steps */
#define TS_TOL 1e-8

static int ts_subnormal(double v) { return v != 0.0 && fabs(v) < DBL_MIN; }

static int ts_chain(msd_nonlinear *M, int N) {
  msd_nl_opts o;
  memset(&o, 0, sizeof o);
  o.n = N / 2;
  o.storage = PHGMG_BANDED;
  return msd_nonlinear_build(M, &o);
}

/* The trajectory with flushing (default) against the one without
   (opts.keep_tiny = 1, the stepper before flushing existed): the
   difference is below the Newton tolerance, every entry the flushing run
   set to zero is negligible in the other one (< 1e-50 of the largest entry at
   that time, where the threshold is 1e-60 of it), and no entry of the
   flushed trajectory is subnormal while the reference has many. */
TEST(test_gl3_flush_agrees_with_unflushed) {
  msd_nonlinear M;
  phgmg_gl3_opts g;
  double *Xf, *Xk, dmax = 0.0, worst_ratio = 0.0;
  size_t len = (size_t)TS_N * (TS_STEPS + 1), i;
  long sub_f = 0, sub_k = 0, nz_f = 0, nz_k = 0;
  int n;
  CHECK(ts_chain(&M, TS_N) == 0);
  Xf = (double *)calloc(len, sizeof(double));
  Xk = (double *)calloc(len, sizeof(double));
  memset(&g, 0, sizeof g);
  g.tol = TS_TOL;
  g.max_iter = 20;
  {
    double *x0 = (double *)calloc(TS_N, sizeof(double));
    CHECK_RC(phgmg_simulate(&M.sys, x0, 0.0, 0.1, TS_STEPS, msd_input_sin, NULL, &g, Xf, NULL, NULL,
                            NULL, NULL, NULL), PHGMG_OK);
    g.keep_tiny = 1;
    CHECK_RC(phgmg_simulate(&M.sys, x0, 0.0, 0.1, TS_STEPS, msd_input_sin, NULL, &g, Xk, NULL, NULL,
                            NULL, NULL, NULL), PHGMG_OK);
    free(x0);
  }
  for (i = 0; i < len; ++i) {
    sub_f += ts_subnormal(Xf[i]);
    sub_k += ts_subnormal(Xk[i]);
    nz_f += Xf[i] != 0.0;
    nz_k += Xk[i] != 0.0;
    dmax = fmax(dmax, fabs(Xf[i] - Xk[i]));
  }
  for (n = 0; n <= TS_STEPS; ++n) {
    const double *xf = Xf + (size_t)n * TS_N, *xk = Xk + (size_t)n * TS_N;
    double am = 0.0;
    for (i = 0; i < TS_N; ++i) am = fmax(am, fabs(xk[i]));
    for (i = 0; i < TS_N; ++i)
      if (xf[i] == 0.0 && xk[i] != 0.0) worst_ratio = fmax(worst_ratio, fabs(xk[i]) / am);
  }
  CHECK(sub_k > 100);     /* the reference does reach the subnormal range */
  CHECK(sub_f == 0);      /* the flushed run never stores a subnormal */
  CHECK(nz_f < nz_k);     /* and entries were flushed */
  CHECK_LE(dmax, TS_TOL); /* results unchanged to the Newton tolerance */
  CHECK_LE(worst_ratio, 1e-50);
  free(Xf);
  free(Xk);
  msd_nonlinear_free(&M);
}

/* The same for the linear dense chain stepped by the precomputed map (its
   matrices and the state flushed): agreement to far below the tolerance. */
TEST(test_gl3_map_flush_agrees) {
  msd_linear L;
  phgmg_gl3_opts g;
  enum { NL = 300, NSL = 200 };
  size_t len = (size_t)NL * (NSL + 1), i;
  double *Xf = (double *)calloc(len, sizeof(double)), *Xk = (double *)calloc(len, sizeof(double));
  double x0[NL], dmax = 0.0;
  long sub_f = 0, sub_k = 0;
  CHECK(msd_linear_build(&L, NL / 2, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  memset(&g, 0, sizeof g);
  memset(x0, 0, sizeof x0);
  CHECK_RC(phgmg_simulate(&L.sys, x0, 0.0, 0.1, NSL, msd_input_sin, NULL, &g, Xf, NULL, NULL, NULL,
                          NULL, NULL), PHGMG_OK);
  g.keep_tiny = 1;
  CHECK_RC(phgmg_simulate(&L.sys, x0, 0.0, 0.1, NSL, msd_input_sin, NULL, &g, Xk, NULL, NULL, NULL,
                          NULL, NULL), PHGMG_OK);
  for (i = 0; i < len; ++i) {
    sub_f += ts_subnormal(Xf[i]);
    sub_k += ts_subnormal(Xk[i]);
    dmax = fmax(dmax, fabs(Xf[i] - Xk[i]));
  }
  CHECK(sub_k > 100);
  CHECK(sub_f == 0);
  CHECK_LE(dmax, 1e-14); /* rounding: the map is exact, only 1e-60-relative entries differ */
  msd_linear_free(&L);
  free(Xf);
  free(Xk);
}

#if TS_MXCSR
#define TS_DE 0x0002u /* MXCSR denormal-operand flag */
#endif

/* The flags say whether any instruction had a subnormal operand (x86 DE) or
   produced a tiny inexact result (FE_UNDERFLOW): after the first two steps
   from rest (whose flush threshold cannot know the state's scale yet), the
   chain runs without either; without flushing (keep_tiny) both are raised. */
static int ts_tiny_arith(int keep_tiny, int linear, int *de) {
  msd_nonlinear M;
  msd_linear L;
  phgmg_gl3_opts g;
  phgmg_gl3 *s = NULL;
  double x[TS_N];
  int n, uf = -1;
  *de = -1;
  if (ts_chain(&M, TS_N) != 0) return -1;
  /* linear: the dense chain with N = 300, stepped by the precomputed map */
  if (msd_linear_build(&L, 150, NULL, NULL, NULL, PHGMG_DENSE) != 0) { msd_nonlinear_free(&M); return -1; }
  memset(&g, 0, sizeof g);
  g.tol = TS_TOL;
  g.max_iter = 20;
  g.keep_tiny = keep_tiny;
  memset(x, 0, sizeof x);
  if (phgmg_gl3_create(&s, linear ? &L.sys : &M.sys, 0.1, &g, NULL) == PHGMG_OK) {
    for (n = 0; n < 2; ++n) phgmg_gl3_step(s, 0.1 * n, x, msd_input_sin, NULL, NULL);
    feclearexcept(FE_ALL_EXCEPT);
#if TS_MXCSR
    _mm_setcsr(_mm_getcsr() & ~0x3Fu);
#endif
    for (n = 2; n < TS_STEPS; ++n)
      if (phgmg_gl3_step(s, 0.1 * n, x, msd_input_sin, NULL, NULL) != PHGMG_OK) break;
#if TS_MXCSR
    *de = (_mm_getcsr() & TS_DE) != 0;
#endif
    uf = fetestexcept(FE_UNDERFLOW) != 0;
    if (n < TS_STEPS) uf = -1;
  }
  phgmg_gl3_destroy(s);
  msd_nonlinear_free(&M);
  msd_linear_free(&L);
  return uf;
}

TEST(test_gl3_no_subnormal_arithmetic) {
  int de_f, de_k, uf_f, uf_k, lin;
  for (lin = 0; lin < 2; ++lin) { /* nonlinear banded (Newton), linear dense (step map) */
    uf_f = ts_tiny_arith(0, lin, &de_f);
    uf_k = ts_tiny_arith(1, lin, &de_k);
    CHECK(uf_k == 1); /* the check can fail: without flushing the tail underflows */
    CHECK(uf_f == 0);
#if TS_MXCSR
    CHECK(de_k == 1);
    CHECK(de_f == 0);
#endif
  }
  feclearexcept(FE_ALL_EXCEPT);
}

/* ---- the floating-point environment ------------------------------------------ */

/* The control part of the environment: rounding mode, and on x86-64 glibc the
   x87 control word and the MXCSR control bits (masks, rounding, FTZ, DAZ). */
typedef struct ts_fpctl {
  int round;
  unsigned cw, mxcsr;
} ts_fpctl;
static ts_fpctl ts_fpctl_get(void) {
  ts_fpctl c;
  memset(&c, 0, sizeof c);
  c.round = fegetround();
#if defined(__x86_64__) && defined(__GLIBC__)
  {
    fenv_t e;
    fegetenv(&e);
    c.cw = e.__control_word;
    c.mxcsr = e.__mxcsr & ~0x3Fu;
  }
#endif
  return c;
}
static int ts_fpctl_same(ts_fpctl a, ts_fpctl b) {
  return a.round == b.round && a.cw == b.cw && a.mxcsr == b.mxcsr;
}

/* A small chain, its GMG-POD and GMG-QM models, stepped a few times (the
   environment is set by the caller). Returns 0 when everything ran. */
static int ts_run_all(void) {
  enum { N = 40, NS = 121 };
  msd_nonlinear M;
  phgmg_gl3_opts g;
  double *X = (double *)calloc((size_t)N * NS, sizeof(double)), x0[N];
  int bad = 0, meth;
  static double mem[1 << 15];
  if (!X || ts_chain(&M, N) != 0) { free(X); return -1; }
  memset(&g, 0, sizeof g);
  g.tol = TS_TOL;
  g.max_iter = 20;
  memset(x0, 0, sizeof x0);
  if (phgmg_simulate(&M.sys, x0, 0.0, 0.1, NS - 1, msd_input_sin, NULL, &g, X, NULL, NULL, NULL,
                     NULL, NULL) != PHGMG_OK)
    bad = 1;
  for (meth = PHGMG_METHOD_GMG_POD; meth <= PHGMG_METHOD_GMG_QM && !bad; ++meth) {
    phgmg_reduce_opts o;
    phgmg_reduced *red = NULL;
    phgmg_rom_stepper st;
    phgmg_real x[8], u3[3];
    int n, k;
    memset(&o, 0, sizeof o);
    o.method = (phgmg_method)meth;
    o.r = 6;
    o.qm.rn = 4;
    if (phgmg_reduce(&red, &M.sys, X, N, NS, &o, NULL, NULL) != PHGMG_OK) { bad = 1; break; }
    memset(x, 0, sizeof x);
    if (phgmg_rom_stepper_init(&st, phgmg_reduced_rom(red), 0.1, 1e-8, 20, mem, sizeof mem) != PHGMG_OK)
      bad = 1;
    for (n = 0; n < 50 && !bad; ++n) {
      phgmg_real tc[3];
      phgmg_rom_stage_times((phgmg_real)(0.1 * n), (phgmg_real)0.1, tc);
      for (k = 0; k < 3; ++k) u3[k] = (phgmg_real)(0.1 * sin((double)tc[k]));
      if (phgmg_rom_step(&st, x, u3, NULL, NULL) != PHGMG_OK) bad = 1;
    }
    phgmg_reduced_destroy(red);
  }
  msd_nonlinear_free(&M);
  free(X);
  return bad ? -1 : 0;
}

/* phgmg_simulate, phgmg_reduce and phgmg_rom_step under a non-default
   rounding mode, and (x86) with FTZ/DAZ set by the caller: the control part
   of the environment is the same afterwards. */
TEST(test_fenv_unchanged) {
  static const int modes[2] = {FE_TOWARDZERO, FE_UPWARD};
  int k;
  for (k = 0; k < 2; ++k) {
    ts_fpctl before, after;
    if (fesetround(modes[k]) != 0) continue; /* mode not supported here */
    before = ts_fpctl_get();
    CHECK(ts_run_all() == 0);
    after = ts_fpctl_get();
    CHECK(before.round == modes[k]);
    CHECK(ts_fpctl_same(before, after));
    fesetenv(FE_DFL_ENV);
  }
#if TS_MXCSR
  {
    unsigned saved = _mm_getcsr();
    ts_fpctl before, after;
    _mm_setcsr(saved | 0x8040u); /* FTZ | DAZ, the caller's choice */
    before = ts_fpctl_get();
    CHECK(ts_run_all() == 0);
    after = ts_fpctl_get();
    CHECK((_mm_getcsr() & 0x8040u) == 0x8040u);
    CHECK(ts_fpctl_same(before, after));
    _mm_setcsr(saved);
  }
#endif
  fesetenv(FE_DFL_ENV);
  CHECK(fegetround() == FE_TONEAREST);
}

/* The reduced stepper started from a state with subnormal entries: one step
   without input leaves exactly zero (the new state is O(dt) times the old one,
   all below the smallest normal); with input, the trajectory equals the one
   from x0 = 0 to within the smallest normal (both far below the tolerance). */
TEST(test_rom_step_flushes_subnormal) {
  enum { N = 40, NS = 121 };
  msd_nonlinear M;
  phgmg_gl3_opts g;
  double *X = (double *)calloc((size_t)N * NS, sizeof(double)), x0[N];
  static double mem[1 << 15];
  int meth;
  CHECK(X != NULL);
  CHECK(ts_chain(&M, N) == 0);
  memset(&g, 0, sizeof g);
  g.tol = TS_TOL;
  g.max_iter = 20;
  memset(x0, 0, sizeof x0);
  CHECK_RC(phgmg_simulate(&M.sys, x0, 0.0, 0.1, NS - 1, msd_input_sin, NULL, &g, X, NULL, NULL,
                          NULL, NULL, NULL), PHGMG_OK);
  for (meth = PHGMG_METHOD_GMG_POD; meth <= PHGMG_METHOD_GMG_QM; ++meth) {
    phgmg_reduce_opts o;
    phgmg_reduced *red = NULL;
    phgmg_rom_stepper st;
    double x[6], xr[6], u3[3], d = 0.0;
    int n, a, k, sub = 0;
    memset(&o, 0, sizeof o);
    o.method = (phgmg_method)meth;
    o.r = 6;
    o.qm.rn = 4;
    CHECK_RC(phgmg_reduce(&red, &M.sys, X, N, NS, &o, NULL, NULL), PHGMG_OK);
    if (!red) continue;
    for (a = 0; a < 6; ++a) x[a] = (a % 2 ? -0.25 : 0.5) * DBL_MIN; /* subnormal */
    CHECK_RC(phgmg_rom_stepper_init(&st, phgmg_reduced_rom(red), 0.1, 1e-8, 20, mem, sizeof mem), PHGMG_OK);
    CHECK_RC(phgmg_rom_step(&st, x, NULL, NULL, NULL), PHGMG_OK);
    for (a = 0; a < 6; ++a) CHECK(x[a] == 0.0);
    for (a = 0; a < 6; ++a) { x[a] = (a % 2 ? -0.25 : 0.5) * DBL_MIN; xr[a] = 0.0; }
    phgmg_rom_stepper_reset(&st);
    for (n = 0; n < 100; ++n) {
      phgmg_real tc[3];
      phgmg_rom_stage_times(0.1 * n, 0.1, tc);
      for (k = 0; k < 3; ++k) u3[k] = 0.1 * sin(tc[k]);
      CHECK_RC(phgmg_rom_step(&st, x, u3, NULL, NULL), PHGMG_OK);
      for (a = 0; a < 6; ++a) sub += ts_subnormal(x[a]);
    }
    CHECK_RC(phgmg_rom_stepper_init(&st, phgmg_reduced_rom(red), 0.1, 1e-8, 20, mem, sizeof mem), PHGMG_OK);
    for (n = 0; n < 100; ++n) {
      phgmg_real tc[3];
      phgmg_rom_stage_times(0.1 * n, 0.1, tc);
      for (k = 0; k < 3; ++k) u3[k] = 0.1 * sin(tc[k]);
      CHECK_RC(phgmg_rom_step(&st, xr, u3, NULL, NULL), PHGMG_OK);
    }
    for (a = 0; a < 6; ++a) d = fmax(d, fabs(x[a] - xr[a]));
    CHECK(sub == 0);
    CHECK_LE(d, TS_TOL);
    phgmg_reduced_destroy(red);
  }
  msd_nonlinear_free(&M);
  free(X);
}

SUITE(subnormal) {
  RUN(test_gl3_flush_agrees_with_unflushed);
  RUN(test_gl3_map_flush_agrees);
  RUN(test_gl3_no_subnormal_arithmetic);
  RUN(test_fenv_unchanged);
  RUN(test_rom_step_flushes_subnormal);
}
