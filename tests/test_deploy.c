/* Deployment: several training runs in one snapshot set
   (phgmg_simulate_inputs), the automatic lambda validated by simulation
   (opts.select.lambda_mode = PHGMG_LAMBDA_VALIDATED), phgmg_reduced_validate, the stepper's
   training-envelope indicator and consecutive-failure counters, the greedy
   linear part of the quadratic manifold. Model: the paper's linear MSD
   (examples/msd_models.h). */
#include <stdlib.h>
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include "../examples/msd_models.h"

static void u_sin2(double t, double *u, void *p) { (void)p; u[0] = 0.1 * sin(2.0 * t); }
static void u_steps(double t, double *u, void *p) { (void)p; u[0] = ((int)(t / 7.0) % 3 - 1) * 0.08; }

static double maxabs_d(int n, const double *a) { double s = 0; int i; for (i = 0; i < n; ++i) s = PHGMG__MAX(s, fabs(a[i])); return s; }

static double *sim(const phgmg_ph_system *sys, phgmg_input_fn u, int nsteps, double *Y) {
  double *X = (double *)malloc(sizeof(double) * sys->N * (nsteps + 1));
  phgmg_run run;
  memset(&run, 0, sizeof run);
  run.u = u; run.dt = 0.1; run.nsteps = nsteps;
  if (X && phgmg_simulate_inputs(sys, 1, &run, NULL, X, sys->N, Y, NULL, NULL) != PHGMG_OK) { free(X); X = NULL; }
  return X;
}

/* Runs laid out one after the other, each exactly as phgmg_simulate makes it. */
TEST(test_simulate_inputs_layout) {
  msd_linear M;
  enum { N1 = 30, N2 = 20, LD = 61 };
  static double X[LD * (N1 + N2 + 2)], Xs[50 * (N1 + 1)], Y[N1 + N2 + 2], Ys[N1 + 1], x0[50];
  phgmg_run run[2];
  int col[3], i, j, k;
  CHECK(msd_linear_build(&M, 25, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  for (i = 0; i < 50; ++i) x0[i] = 0.01 * th_rand();
  memset(run, 0, sizeof run);
  run[0].u = msd_input_sin; run[0].dt = 0.1; run[0].nsteps = N1;
  run[1].u = msd_input_const; run[1].dt = 0.05; run[1].t0 = 2.0; run[1].nsteps = N2; run[1].x0 = x0;
  CHECK(phgmg_runs_columns(2, run) == N1 + N2 + 2);
  CHECK_RC(phgmg_simulate_inputs(&M.sys, 2, run, NULL, X, LD, Y, col, NULL), PHGMG_OK);
  CHECK(col[0] == 0 && col[1] == N1 + 1 && col[2] == N1 + N2 + 2);
  for (k = 0; k < 2; ++k) {
    const phgmg_run *q = run + k;
    double z[50] = {0};
    CHECK_RC(phgmg_simulate(&M.sys, q->x0 ? q->x0 : z, q->t0, q->dt, q->nsteps, q->u, NULL, NULL, Xs, Ys, NULL, NULL,
                            NULL, NULL), PHGMG_OK);
    for (j = 0; j <= q->nsteps; ++j) {
      for (i = 0; i < 50; ++i) CHECK(X[i + (size_t)(col[k] + j) * LD] == Xs[i + j * 50]);
      CHECK(Y[col[k] + j] == Ys[j]);
    }
  }
  run[1].nsteps = -1;
  CHECK(phgmg_runs_columns(2, run) == -1);
  CHECK_RC(phgmg_simulate_inputs(&M.sys, 2, run, NULL, X, LD, Y, col, NULL), PHGMG_ERR_INVALID_ARG);
  run[1].nsteps = N2; run[1].dt = 0.0;
  CHECK_RC(phgmg_simulate_inputs(&M.sys, 2, run, NULL, X, LD, Y, col, NULL), PHGMG_ERR_INVALID_ARG);
  run[1].dt = 0.1;
  CHECK_RC(phgmg_simulate_inputs(&M.sys, 2, run, NULL, X, 10, Y, col, NULL), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_simulate_inputs(&M.sys, 0, run, NULL, X, LD, Y, col, NULL), PHGMG_ERR_INVALID_ARG);
  msd_linear_free(&M);
}

/* Option checks of the new fields. */
TEST(test_deploy_options) {
  msd_linear M;
  const int ns = 101;
  double *X;
  phgmg_reduce_opts o, b;
  phgmg_reduced *red = NULL;
  phgmg_run run;
  CHECK(msd_linear_build(&M, 25, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  X = sim(&M.sys, msd_input_sin, ns - 1, NULL);
  CHECK(X != NULL);
  if (!X) { msd_linear_free(&M); return; }
  memset(&run, 0, sizeof run);
  run.u = msd_input_sin; run.dt = 0.1; run.nsteps = ns - 1;
  memset(&b, 0, sizeof b);
  b.method = PHGMG_METHOD_GMG_QM; b.r = 5; b.qm.rn = 3; b.nrun = 1; b.runs = &run;
#define BAD(field, val, code) do { o = b; o.field = (val); \
    CHECK_RC(phgmg_reduce(&red, &M.sys, X, M.sys.N, ns, &o, NULL, NULL), code); CHECK(red == NULL); } while (0)
  BAD(nrun, -1, PHGMG_ERR_INVALID_ARG);
  BAD(runs, NULL, PHGMG_ERR_INVALID_ARG);
  BAD(select.tolerance, 0.5, PHGMG_ERR_INVALID_ARG);
  BAD(select.tolerance, (double)NAN, PHGMG_ERR_INVALID_ARG);
  BAD(select.newton_tol, -1.0, PHGMG_ERR_INVALID_ARG);
  BAD(select.newton_iter, -1, PHGMG_ERR_INVALID_ARG);
  BAD(qm.manifold, 3, PHGMG_ERR_INVALID_ARG);
  BAD(qm.manifold, -1, PHGMG_ERR_INVALID_ARG);
  BAD(select.train_only, 2, PHGMG_ERR_INVALID_ARG);
  BAD(select.lambda_mode, 3, PHGMG_ERR_INVALID_ARG);
#undef BAD
  {
    phgmg_run two[2];
    two[0] = two[1] = run;
    o = b; o.nrun = 2; o.runs = two;                 /* 2 x 101 columns announced, 101 given */
    CHECK_RC(phgmg_reduce(&red, &M.sys, X, M.sys.N, ns, &o, NULL, NULL), PHGMG_ERR_SIZE);
  }
  run.nsteps = ns - 2;
  o = b;
  CHECK_RC(phgmg_reduce(&red, &M.sys, X, M.sys.N, ns, &o, NULL, NULL), PHGMG_ERR_SIZE);
  free(X);
  msd_linear_free(&M);
}

/* Without runs the validation has nothing to simulate: M = 0, and the model
   is GMG-POD's (outputs equal to a separately built GMG-POD model). */
TEST(test_lambda_auto_without_runs_is_linear_limit) {
  msd_linear M;
  const int ns = 301, r = 8;
  double *X, Ya[301], Yb[301], xr0[8] = {0};
  phgmg_reduce_opts o;
  phgmg_reduce_info info;
  phgmg_reduced *qm = NULL, *pod = NULL;
  CHECK(msd_linear_build(&M, 25, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  X = sim(&M.sys, msd_input_sin, ns - 1, NULL);
  CHECK(X != NULL);
  if (!X) { msd_linear_free(&M); return; }
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_QM; o.r = r; o.qm.rn = 4; o.select.lambda_mode = PHGMG_LAMBDA_VALIDATED;
  CHECK_RC(phgmg_reduce(&qm, &M.sys, X, M.sys.N, ns, &o, &info, NULL), PHGMG_OK);
  CHECK(info.lambda == HUGE_VAL && info.lambda_candidates == 0);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = r;
  CHECK_RC(phgmg_reduce(&pod, &M.sys, X, M.sys.N, ns, &o, NULL, NULL), PHGMG_OK);
  if (qm && pod) {
    CHECK_RC(phgmg_reduced_simulate(qm, xr0, 0, 0.1, ns - 1, u_sin2, NULL, 1e-12, 20, NULL, Ya, NULL, NULL, NULL), PHGMG_OK);
    CHECK_RC(phgmg_reduced_simulate(pod, xr0, 0, 0.1, ns - 1, u_sin2, NULL, 1e-12, 20, NULL, Yb, NULL, NULL, NULL), PHGMG_OK);
    CHECK_LE(phgmg_rel_error(1, ns, Yb, 1, Ya, 1), 1e-9);
  }
  phgmg_reduced_destroy(qm);
  phgmg_reduced_destroy(pod);
  free(X);
  msd_linear_free(&M);
}

/* Paper's linear chain trained on u = 0.1 sin t: the validated lambda has no
   Newton failure and e_y within 1.2x of GMG-POD's on inputs it never saw
   (a constant, 0.1 sin 2t, a step sequence), where the regression choice
   (lambda_auto = 2) is worse than 1.2x on the constant -- so the check can fail. */
/* Progress of the validated lambda: one "lambda: candidate" call per
   candidate counted in info.lambda_candidates, and the probe runs announced
   (three probe inputs per training run unless the full model fails on one). */
typedef struct { int cand, probe, val, done; } progress_count;
static void count_phase(const char *phase, void *user) {
  progress_count *pc = (progress_count *)user;
  if (!strcmp(phase, "lambda: candidate")) pc->cand++;
  else if (!strcmp(phase, "lambda: full-model probe run")) pc->probe++;
  else if (!strcmp(phase, "lambda: validation runs")) pc->val++;
  else if (!strcmp(phase, "done")) pc->done++;
}
TEST(test_lambda_auto_progress) {
  msd_linear M;
  enum { NS = 301 };
  double *X;
  phgmg_run run;
  phgmg_reduce_info info;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  progress_count pc = {0, 0, 0, 0};
  CHECK(msd_linear_build(&M, 30, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  X = sim(&M.sys, msd_input_sin, NS - 1, NULL);
  CHECK(X != NULL);
  memset(&run, 0, sizeof run);
  run.u = msd_input_sin; run.dt = 0.1; run.nsteps = NS - 1;
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_QM; o.r = 8; o.qm.rn = 4; o.select.lambda_mode = PHGMG_LAMBDA_VALIDATED; o.nrun = 1; o.runs = &run;
  o.progress = count_phase; o.progress_user = &pc;
  if (X) {
    CHECK_RC(phgmg_reduce(&red, &M.sys, X, M.sys.N, NS, &o, &info, NULL), PHGMG_OK);
    CHECK(info.lambda_candidates >= 1);
    CHECK(pc.cand == info.lambda_candidates);
    CHECK(pc.val == 1);
    CHECK(pc.probe == 3);
    CHECK(pc.done == 1);
  }
  phgmg_reduced_destroy(red);
  free(X);
  msd_linear_free(&M);
}

TEST(test_lambda_auto_generalizes) {
  msd_linear M;
  enum { NS = 601, NT = 3 };
  const int r = 10;
  static phgmg_input_fn tin[NT] = {msd_input_const, u_sin2, u_steps};
  double *X, *Xt[NT], Yt[NT][NS], YR[NS], xr0[10] = {0}, ey[3][NT];
  phgmg_run run;
  phgmg_reduce_info info;
  int v, i;
  CHECK(msd_linear_build(&M, 50, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  X = sim(&M.sys, msd_input_sin, NS - 1, NULL);
  for (i = 0; i < NT; ++i) Xt[i] = sim(&M.sys, tin[i], NS - 1, Yt[i]);
  CHECK(X && Xt[0] && Xt[1] && Xt[2]);
  memset(&run, 0, sizeof run);
  run.u = msd_input_sin; run.dt = 0.1; run.nsteps = NS - 1;
  for (v = 0; v < 3 && X; ++v) {   /* GMG-POD, GMG-QM validated, GMG-QM regression */
    phgmg_reduce_opts o;
    phgmg_reduced *red = NULL;
    memset(&o, 0, sizeof o);
    o.method = v ? PHGMG_METHOD_GMG_QM : PHGMG_METHOD_GMG_POD; o.r = r; o.qm.rn = 8;
    o.select.lambda_mode = v; o.nrun = 1; o.runs = &run;
    CHECK_RC(phgmg_reduce(&red, &M.sys, X, M.sys.N, NS, &o, &info, NULL), PHGMG_OK);
    if (!red) continue;
    if (v == 1) {
      CHECK(info.lambda_candidates >= 1);
      CHECK_LE(info.lambda_val_ratio, 1.02);
      CHECK_RC(phgmg_reduced_simulate(red, xr0, 0, 0.1, NS - 1, msd_input_sin, NULL, 1e-10, 20, NULL, YR, NULL, NULL, NULL), PHGMG_OK);
    }
    for (i = 0; i < NT; ++i) {
      phgmg_rom_stats st;
      phgmg_result rc = phgmg_reduced_simulate(red, xr0, 0, 0.1, NS - 1, tin[i], NULL, 1e-10, 20, NULL, YR, NULL, &st, NULL);
      if (v < 2) { CHECK_RC(rc, PHGMG_OK); CHECK(st.failures == 0); }
      ey[v][i] = rc == PHGMG_OK ? phgmg_rel_error(1, NS, Yt[i], 1, YR, 1) : HUGE_VAL;
    }
    phgmg_reduced_destroy(red);
  }
  for (i = 0; i < NT; ++i) CHECK_LE(ey[1][i], 1.2 * ey[0][i]);
  CHECK_LE(1.2 * ey[0][0], ey[2][0]);
  free(X);
  for (i = 0; i < NT; ++i) free(Xt[i]);
  msd_linear_free(&M);
}

/* The lambda_auto = 1 selection recomputed from its documentation
   (phgmg_reduce_opts.runs), with every candidate evaluated in full (the
   library stops a candidate at its first inadmissible run): candidates from
   lambda_max down one per decade to the regression optimum (lambda_auto = 2's
   choice), each a GMG-QM model with that fixed lambda, simulated on the
   training run and the three probe runs (a constant at the training input's
   RMS, the input 1.5x faster, the square wave RMS * sign(u)) against the
   linear limit (GMG-POD on the same basis); admissible: every run simulates,
   <= 4 Newton iterations per step, every e_y ratio <= 1.02; the descent stops
   after two inadmissible candidates in a row; kept: the first candidate with
   at least half the best gain (sum of log ratios), none: M = 0 (HUGE_VAL). */
static double ra_rms;
static void ra_const(double t, double *u, void *p) { (void)t; (void)p; u[0] = ra_rms; }
static void ra_fast(double t, double *u, void *p) { msd_input_sin(1.5 * t, u, p); }
static void ra_square(double t, double *u, void *p) {
  msd_input_sin(t, u, p);
  u[0] = u[0] > 0.0 ? ra_rms : (u[0] < 0.0 ? -ra_rms : 0.0);
}
/* e_y of red on the four runs (HUGE_VAL where it fails); *ok = 0 on a failure
   or more than 4 Newton iterations per step */
static void ra_eval(const phgmg_reduced *red, int ns, phgmg_input_fn *u, const double *Yref, double *ey, int *ok) {
  double YR[601], xr0[32] = {0};   /* r <= 32 */
  int k;
  *ok = 1;
  for (k = 0; k < 4; ++k) {
    phgmg_rom_stats st;
    phgmg_result rc;
    memset(&st, 0, sizeof st);
    rc = phgmg_reduced_simulate(red, xr0, 0.0, 0.1, ns - 1, u[k], NULL, 0.0, 20, NULL, YR, NULL, &st, NULL);
    ey[k] = rc == PHGMG_OK ? phgmg_rel_error(1, ns, Yref + (size_t)k * ns, 1, YR, 1) : HUGE_VAL;
    if (rc != PHGMG_OK || st.newton_iters > 4 * st.steps || !(ey[k] < HUGE_VAL)) *ok = 0;
  }
}
static double ra_expected(const phgmg_ph_system *sys, const double *X, int ns, int r, const phgmg_run *run,
                          const double *Yref, phgmg_input_fn *u, int *ncand) {
  const double lo = 1e-14;
  const int pd = 4, ng = 57;   /* the default grid 1e-14 .. 1, four points per decade */
  double base[4], ey[4], lam_reg, best_score = 0.0, cs[64];
  int g, gsel, k, ok, bad = 0, nc = 0, cg[64], cok[64], best = -1;
  phgmg_reduce_opts o;
  phgmg_reduce_info info;
  phgmg_reduced *red = NULL;
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = r;
  if (phgmg_reduce(&red, sys, X, sys->N, ns, &o, NULL, NULL) != PHGMG_OK) return NAN;
  ra_eval(red, ns, u, Yref, base, &ok);
  phgmg_reduced_destroy(red);
  for (k = 0; k < 4; ++k) if (!(base[k] < HUGE_VAL)) base[k] = 1.0;
  o.method = PHGMG_METHOD_GMG_QM; o.qm.rn = 8; o.select.lambda_mode = PHGMG_LAMBDA_REGRESSION; o.nrun = 1; o.runs = run;
  if (phgmg_reduce(&red, sys, X, sys->N, ns, &o, &info, NULL) != PHGMG_OK) return NAN;
  phgmg_reduced_destroy(red);
  lam_reg = info.lambda;
  gsel = (int)floor(pd * log10(lam_reg / lo) + 0.5);
  for (g = ng - 1; g >= gsel; g = (g - pd >= gsel || g == gsel) ? g - pd : gsel) {
    double score = 0.0, worst = 0.0;
    o.select.lambda_mode = PHGMG_LAMBDA_FIXED; o.qm.lambda = lo * pow(10.0, (double)g / pd);
    if (phgmg_reduce(&red, sys, X, sys->N, ns, &o, NULL, NULL) != PHGMG_OK) return NAN;
    ra_eval(red, ns, u, Yref, ey, &ok);
    phgmg_reduced_destroy(red);
    for (k = 0; k < 4 && ok; ++k) {
      const double q = (ey[k] + 1e-14) / (base[k] + 1e-14);
      score += log(q);
      worst = PHGMG__MAX(worst, q);
    }
    ok = ok && worst <= 1.02;
    if (ok && score < best_score) { best = g; best_score = score; }
    cg[nc] = g; cok[nc] = ok; cs[nc++] = score;
    bad = ok ? 0 : bad + 1;
    if (bad >= 2 || g == gsel) break;
  }
  *ncand = nc;
  for (k = 0; k < nc && best >= 0; ++k)
    if (cok[k] && cs[k] <= 0.5 * best_score) { best = cg[k]; break; }
  return best < 0 ? HUGE_VAL : lo * pow(10.0, (double)best / pd);
}
TEST(test_lambda_auto_rule_recomputed) {
  msd_linear M;
  enum { NS = 601 };
  static double Yref[4 * NS];
  phgmg_input_fn u[4] = {msd_input_sin, ra_const, ra_fast, ra_square};
  double *X, s2 = 0.0, *Xp;
  phgmg_run run;
  /* orders with each outcome: the linear limit (8, 15), lambda 1e-2 / 1e-1 / 1
     (6, 7, 10, 18); at r = 13 the half-gain rule keeps 1e-1 where the best
     gain is at 1e-2, at r = 15 a candidate's worst ratio (1.035) is just
     above the tolerance 1.02 (the descent stops one candidate earlier) */
  static const int rs[7] = {6, 7, 8, 10, 13, 15, 18};
  int i, k, j, r, ncand = 0, finite = 0;
  CHECK(msd_linear_build(&M, 50, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  X = sim(&M.sys, msd_input_sin, NS - 1, Yref);
  for (i = 0; i < NS; ++i) { double v; msd_input_sin(0.1 * i, &v, NULL); s2 += v * v; }
  ra_rms = sqrt(s2 / NS);
  for (k = 1; k < 4; ++k) { Xp = sim(&M.sys, u[k], NS - 1, Yref + (size_t)k * NS); CHECK(Xp != NULL); free(Xp); }
  memset(&run, 0, sizeof run);
  run.u = msd_input_sin; run.dt = 0.1; run.nsteps = NS - 1;
  for (j = 0; j < 7 && X; ++j) {
    phgmg_reduce_opts o;
    phgmg_reduce_info info;
    phgmg_reduced *red = NULL;
    double want;
    r = rs[j];
    want = ra_expected(&M.sys, X, NS, r, &run, Yref, u, &ncand);
    memset(&o, 0, sizeof o);
    o.method = PHGMG_METHOD_GMG_QM; o.r = r; o.qm.rn = 8; o.select.lambda_mode = PHGMG_LAMBDA_VALIDATED; o.nrun = 1; o.runs = &run;
    CHECK_RC(phgmg_reduce(&red, &M.sys, X, M.sys.N, NS, &o, &info, NULL), PHGMG_OK);
    phgmg_reduced_destroy(red);
    CHECK(!isnan(want));
    CHECK(info.lambda_candidates == ncand);
    if (want == HUGE_VAL) CHECK(info.lambda == HUGE_VAL);
    else { CHECK_LE(fabs(info.lambda / want - 1.0), 1e-9); ++finite; }
  }
  CHECK(finite == 5);   /* the outcomes listed above */
  free(X);
  msd_linear_free(&M);
}

/* phgmg_reduced_validate against the same numbers computed directly, and the
   training-envelope indicator: silent on the training input, firing when an
   overfitted model is driven by a constant (state error above 0.3). */
TEST(test_validate_and_indicator) {
  msd_linear M;
  enum { NS = 601 };
  double *X, *XR, Y[NS], YR[NS], xr0[12] = {0};
  phgmg_reduce_opts o;
  phgmg_reduced *pod = NULL, *qm = NULL;
  phgmg_validation v;
  phgmg_run run;
  phgmg_rom_stats st;
  CHECK(msd_linear_build(&M, 50, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  X = sim(&M.sys, msd_input_sin, NS - 1, Y);
  XR = (double *)malloc(sizeof(double) * 12 * NS);
  CHECK(X && XR);
  if (!X || !XR) { free(X); free(XR); msd_linear_free(&M); return; }
  memset(&run, 0, sizeof run);
  run.u = msd_input_sin; run.dt = 0.1; run.nsteps = NS - 1;
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = 12;
  CHECK_RC(phgmg_reduce(&pod, &M.sys, X, M.sys.N, NS, &o, NULL, NULL), PHGMG_OK);
  o.method = PHGMG_METHOD_GMG_QM; o.r = 8; o.qm.rn = 8; o.qm.lambda = 1e-12;
  CHECK_RC(phgmg_reduce(&qm, &M.sys, X, M.sys.N, NS, &o, NULL, NULL), PHGMG_OK);
  if (pod && qm) {
    CHECK(phgmg_reduced_rom(pod)->env_lo != NULL && phgmg_reduced_rom(pod)->env_hi != NULL);
    CHECK_RC(phgmg_reduced_validate(pod, &M.sys, &run, 1e-10, 20, 0.1, &v, NULL), PHGMG_OK);
    CHECK_RC(phgmg_reduced_simulate(pod, xr0, 0, 0.1, NS - 1, msd_input_sin, NULL, 1e-10, 20, XR, YR, NULL, &st, NULL), PHGMG_OK);
    CHECK(v.pass == 1 && v.first_failure == -1 && v.steps_done == NS - 1 && v.rom_rc == PHGMG_OK);
    CHECK_LE(fabs(v.e_red - phgmg_err_red(pod, X, M.sys.N, NS, XR, 12)), 1e-12 * v.e_red);
    CHECK_LE(fabs(v.e_y - phgmg_rel_error(1, NS, Y, 1, YR, 1)), 1e-12 * v.e_y);
    CHECK_LE(fabs(v.e_proj - phgmg_err_proj(pod, X, M.sys.N, NS)), 1e-12 * v.e_proj);
    CHECK_LE(v.e_energy, 1e-12);          /* GMG-POD keeps the energy balance to round-off */
    CHECK_LE(v.e_energy_fom, 1e-12);
    CHECK(v.stats.outside_steps == 0);    /* silent on the training input */
    CHECK(v.stats.steps == NS - 1 && v.stats.failures == 0);
    CHECK(phgmg_reduced_rom(pod)->q_max == NULL && v.stats.q_outside_steps == 0);
    CHECK_RC(phgmg_reduced_validate(qm, &M.sys, &run, 1e-10, 20, 0.1, &v, NULL), PHGMG_OK);
    CHECK(v.pass == 1 && v.stats.outside_steps == 0 && v.stats.q_outside_steps == 0);
    CHECK(phgmg_reduced_rom(qm)->q_max != NULL);
    run.u = msd_input_const;
    CHECK_RC(phgmg_reduced_validate(qm, &M.sys, &run, 1e-10, 20, 0.1, &v, NULL), PHGMG_OK);
    CHECK_LE(0.3, v.e_red);               /* a model that left its training region ... */
    CHECK(v.stats.outside_steps > (NS - 1) / 2);  /* ... and says so */
    CHECK(v.stats.q_outside_steps > (NS - 1) / 2);
    CHECK(v.pass == 0);
    /* 0.1 sin 2t: the coordinates stay inside their ranges, the quadratic
       correction does not -- and it grows long before the Newton failure */
    run.u = u_sin2;
    CHECK_RC(phgmg_reduced_validate(qm, &M.sys, &run, 1e-10, 20, 0.1, &v, NULL), PHGMG_OK);
    CHECK_LE(0.3, v.e_red);
    CHECK(v.stats.q_outside_steps > 50);
    run.u = msd_input_const;
    run.nsteps = -1;
    CHECK_RC(phgmg_reduced_validate(qm, &M.sys, &run, 1e-10, 20, 0.1, &v, NULL), PHGMG_ERR_INVALID_ARG);
  }
  phgmg_reduced_destroy(pod);
  phgmg_reduced_destroy(qm);
  free(X); free(XR);
  msd_linear_free(&M);
}

/* Consecutive failures: a Newton cap of one iteration with an unreachable
   tolerance fails every step; a good step resets the run, not the maximum. */
TEST(test_consecutive_failures) {
  msd_linear M;
  enum { NS = 101 };
  double *X;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  phgmg_rom_stepper s;
  static double mem[4096];
  phgmg_real x[6] = {0}, u3[3] = {0.1, 0.1, 0.1};
  int k;
  CHECK(msd_linear_build(&M, 25, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  X = sim(&M.sys, msd_input_sin, NS - 1, NULL);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = 6;
  CHECK_RC(phgmg_reduce(&red, &M.sys, X, M.sys.N, NS, &o, NULL, NULL), PHGMG_OK);
  if (red) {
    CHECK(phgmg_rom_stepper_memsize(phgmg_reduced_rom(red)) <= sizeof mem);
    CHECK_RC(phgmg_rom_stepper_init(&s, phgmg_reduced_rom(red), (phgmg_real)0.1, (phgmg_real)1e-300, 1, mem, sizeof mem),
             PHGMG_OK);
    for (k = 0; k < 5; ++k) CHECK_RC(phgmg_rom_step(&s, x, u3, NULL, NULL), PHGMG_ERR_NOT_CONVERGED);
    CHECK(s.stats.consec_failures == 5 && s.stats.max_consec_failures == 5 && s.stats.failures == 5);
    s.tol = (phgmg_real)1e-10; s.max_iter = 10;
    CHECK_RC(phgmg_rom_step(&s, x, u3, NULL, NULL), PHGMG_OK);
    CHECK(s.stats.consec_failures == 0 && s.stats.max_consec_failures == 5);
  }
  phgmg_reduced_destroy(red);
  free(X);
  msd_linear_free(&M);
}

/* Greedy linear part: every column of V1 is one of the leading r - m + rn
   POD modes of the adjusted snapshots (computed here separately). */
TEST(test_greedy_manifold_picks_pod_modes) {
  msd_linear M;
  enum { NS = 401, P = 6, RN = 4, Q = P + RN };
  double *X, *Xa, *U, *D, xr0[P + 1] = {0};
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  int k = 0, j, a, i;
  CHECK(msd_linear_build(&M, 50, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  X = sim(&M.sys, msd_input_sin, NS - 1, NULL);
  Xa = (double *)malloc(sizeof(double) * 100 * NS);
  U = (double *)malloc(sizeof(double) * 100 * Q);
  D = (double *)malloc(sizeof(double) * 100 * (P + 1));
  CHECK(X && Xa && U && D);
  CHECK_RC(phgmg_adjust_snapshots(100, 1, M.sys.B, NS, X, 100, Xa, 100, NULL), PHGMG_OK);
  CHECK_RC(phgmg_pod(100, NS, Xa, 100, Q, 0.0, U, 100, NULL, &k, NULL), PHGMG_OK);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_QM; o.r = P + 1; o.qm.rn = RN; o.qm.manifold = 1; o.qm.lambda = 1e-9;
  CHECK_RC(phgmg_reduce(&red, &M.sys, X, 100, NS, &o, NULL, NULL), PHGMG_OK);
  if (red) {
    phgmg_reduced_dphi(red, xr0, D, 100);   /* Dphi(0) = V0 = [B, V1] */
    for (j = 1; j <= P; ++j) {
      double best = 0;
      for (a = 0; a < Q; ++a) {
        double d = 0;
        for (i = 0; i < 100; ++i) d += U[i + a * 100] * D[i + j * 100];
        best = PHGMG__MAX(best, fabs(d));
      }
      CHECK_LE(fabs(best - 1.0), 1e-10);
    }
  }
  phgmg_reduced_destroy(red);
  free(X); free(Xa); free(U); free(D);
  msd_linear_free(&M);
}

/* Alternating minimization (opts.qm.manifold = PHGMG_MANIFOLD_ALTMIN), with the
   exact least-squares fit (lambda = 0 both in the sweeps and in the final fit):
   - it starts from the hierarchical POD: info.manifold_obj0 equals the POD
     manifold's training error sum ||x - phi(rho(x))||^2, measured here by
     phgmg_err_proj on the published model (an independent computation);
   - the objective never increases: the altmin manifold's training error (again
     by phgmg_err_proj) is at most the POD one's, and equals info.manifold_obj;
   - GMG structure: [B, V1, V2] with V1, V2 orthonormal and orthogonal to B
     (and to each other), Bh = [I; 0], J skew and R PSD at reduced states,
     rcond(D^T G D) above the degeneracy floor. */
static double sumsq(int n, int ns, const double *X) {
  double s = 0;
  int i;
  for (i = 0; i < n * ns; ++i) s += X[i] * X[i];
  return s;
}
TEST(test_altmin_manifold) {
  msd_linear M;
  enum { NS = 401, N = 100, P = 8, RN = 4, R = P + 1 };
  double *X, G[(P + RN) * (P + RN)], Jr[R * R], Rr[R * R], ev[R], xr[R], work[8192], nx, e_pod, e_alt, d;
  phgmg_reduce_opts o;
  phgmg_reduce_info ip, ia;
  phgmg_reduced *pod = NULL, *alt = NULL;
  const phgmg_rom *rom;
  int i, j, s;
  CHECK(msd_linear_build(&M, 50, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  X = sim(&M.sys, msd_input_sin, NS - 1, NULL);
  CHECK(X != NULL);
  if (!X) { msd_linear_free(&M); return; }
  nx = sumsq(N, NS, X);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_QM; o.r = R; o.qm.rn = RN; o.qm.lambda = -1.0;   /* exactly 0 */
  o.qm.manifold = PHGMG_MANIFOLD_POD;
  CHECK_RC(phgmg_reduce(&pod, &M.sys, X, N, NS, &o, &ip, NULL), PHGMG_OK);
  o.qm.manifold = PHGMG_MANIFOLD_ALTMIN;
  CHECK_RC(phgmg_reduce(&alt, &M.sys, X, N, NS, &o, &ia, NULL), PHGMG_OK);
  if (pod && alt) {
    e_pod = phgmg_err_proj(pod, X, N, NS);
    e_alt = phgmg_err_proj(alt, X, N, NS);
    CHECK_LE(fabs(e_pod * e_pod * nx - ia.manifold_obj0), 1e-8 * ia.manifold_obj0);
    CHECK_LE(fabs(e_alt * e_alt * nx - ia.manifold_obj), 1e-8 * ia.manifold_obj);
    CHECK_LE(ia.manifold_obj, ia.manifold_obj0);
    CHECK_LE(e_alt, e_pod);
    CHECK(ia.manifold_sweeps >= 1);
    CHECK(ip.manifold_sweeps == 0 && ip.manifold_obj0 == 0.0);
    /* [V1, V2] orthonormal and orthogonal to B */
    phgmg_gemm('T', 'N', P, P, N, 1.0, alt->V0 + N, N, alt->V0 + N, N, 0.0, G, P + RN);
    phgmg_gemm('T', 'N', RN, RN, N, 1.0, alt->V2, N, alt->V2, N, 0.0, G + P + (size_t)P * (P + RN), P + RN);
    phgmg_gemm('T', 'N', RN, P, N, 1.0, alt->V2, N, alt->V0 + N, N, 0.0, G + P, P + RN);
    for (j = 0; j < P; ++j) for (i = 0; i < P + RN; ++i) {
      const double want = (i == j) ? 1.0 : 0.0;
      CHECK_LE(fabs(G[i + j * (P + RN)] - want), 1e-12);
    }
    for (j = P; j < P + RN; ++j) for (i = P; i < P + RN; ++i) CHECK_LE(fabs(G[i + j * (P + RN)] - (i == j)), 1e-12);
    phgmg_gemv('T', N, P, 1.0, alt->V0 + N, N, M.sys.B, 0.0, G);
    phgmg_gemv('T', N, RN, 1.0, alt->V2, N, M.sys.B, 0.0, G + P);
    CHECK_LE(maxabs_d(P + RN, G), 1e-12);
    rom = phgmg_reduced_rom(alt);
    for (i = 0; i < R; ++i) CHECK(rom->Bh[i] == (i == 0 ? 1.0 : 0.0));
    CHECK(ia.rcond_dgd > 1e-12);
    for (s = 1; s <= 4; ++s) {
      phgmg_reduced_restrict(alt, X + (size_t)(NS - 1) * s / 4 * N, xr);
      CHECK_RC(phgmg_rom_structure(rom, xr, Jr, Rr, work), PHGMG_OK);
      for (i = 0, d = 0; i < R; ++i) for (j = 0; j < R; ++j) d = PHGMG__MAX(d, fabs(Jr[i + j * R] + Jr[j + i * R]));
      CHECK_LE(d, 1e-12 * (maxabs_d(R * R, Jr) + 1e-300));
      CHECK_RC(phgmg_sym_eig(R, Rr, R, ev, NULL, 1), PHGMG_OK);
      CHECK_LE(-1e-12 * (fabs(ev[R - 1]) + 1e-300), ev[0]);
    }
  }
  phgmg_reduced_destroy(pod);
  phgmg_reduced_destroy(alt);
  free(X);
  msd_linear_free(&M);
}

/* Every allocation failure of the validated lambda (lambda_auto = 1 with
   runs), the envelope and the greedy manifold: PHGMG_ERR_NOMEM, nothing left. */
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

TEST(test_deploy_oom) {
  msd_linear M;
  const int ns = 81;
  double *X;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  phgmg_run run;
  phgmg_validation v;
  tcount c;
  phgmg_allocator al;
  long total, k;
  int pass;
  CHECK(msd_linear_build(&M, 15, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  X = sim(&M.sys, msd_input_sin, ns - 1, NULL);
  CHECK(X != NULL);
  if (!X) { msd_linear_free(&M); return; }
  memset(&run, 0, sizeof run);
  run.u = msd_input_sin; run.dt = 0.1; run.nsteps = ns - 1;
  al.alloc = tc_alloc; al.free = tc_free; al.user = &c;
  for (pass = 0; pass < 4; ++pass) {   /* manifold POD, greedy, altmin (fixed lambda, lambda_auto = 1) */
    memset(&o, 0, sizeof o);
    o.method = PHGMG_METHOD_GMG_QM; o.r = 5; o.qm.rn = 3; o.select.lambda_mode = PHGMG_LAMBDA_VALIDATED; o.nrun = 1; o.runs = &run;
    o.qm.manifold = pass < 3 ? pass : PHGMG_MANIFOLD_ALTMIN; o.select.train_only = pass == 1;
    if (pass == 2) { o.r = 4; o.qm.rn = 2; o.select.lambda_mode = PHGMG_LAMBDA_FIXED; }
    if (pass == 3) { o.r = 3; o.qm.rn = 1; }   /* with the GMG-POD reference and the fallback: small */
    memset(&c, 0, sizeof c);
    CHECK_RC(phgmg_reduce(&red, &M.sys, X, M.sys.N, ns, &o, NULL, &al), PHGMG_OK);
    if (red) CHECK_RC(phgmg_reduced_validate(red, &M.sys, &run, 0, 0, 0, &v, &al), PHGMG_OK);
    phgmg_reduced_destroy(red); red = NULL;
    CHECK(c.live == 0);
    total = c.calls;
    for (k = 1; k <= total; ++k) {
      phgmg_result rc;
      c.calls = 0; c.live = 0; c.fail_at = k;
      rc = phgmg_reduce(&red, &M.sys, X, M.sys.N, ns, &o, NULL, &al);
      if (rc == PHGMG_OK) {
        rc = phgmg_reduced_validate(red, &M.sys, &run, 0, 0, 0, &v, &al);
        phgmg_reduced_destroy(red); red = NULL;
      }
      CHECK_RC(rc, PHGMG_ERR_NOMEM);
      CHECK(c.live == 0 && red == NULL);
    }
  }
  free(X);
  msd_linear_free(&M);
}

SUITE(deploy) {
  RUN(test_lambda_auto_progress);
  RUN(test_deploy_oom);
  RUN(test_simulate_inputs_layout);
  RUN(test_deploy_options);
  RUN(test_lambda_auto_without_runs_is_linear_limit);
  RUN(test_lambda_auto_generalizes);
  RUN(test_lambda_auto_rule_recomputed);
  RUN(test_validate_and_indicator);
  RUN(test_consecutive_failures);
  RUN(test_greedy_manifold_picks_pod_modes);
  RUN(test_altmin_manifold);
}
