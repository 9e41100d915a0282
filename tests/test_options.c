/* The defaults of phgmg_reduce_opts in one place: a struct from
   phgmg_reduce_opts_default gives bit for bit the same reduced model as a
   zeroed one, for every method and the automatic lambda (both kinds), and
   an explicit non-default value does change the model (so the comparison is
   not vacuous). The values themselves are compared with the manual's table
   and the command line's --help by tests/docs_check.py. Models: the paper's
   chains (examples/msd_models.h), small. */
#include <stdlib.h>
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include "../examples/msd_models.h"

enum { OPT_STEPS = 200 };

/* The serialized reduced model of (sys, X) under opts (NULL on failure);
   *len its size, *lam the lambda used. */
static unsigned char *opt_model(const phgmg_ph_system *sys, const double *X, const phgmg_reduce_opts *o,
                                size_t *len, double *lam) {
  phgmg_reduced *red = NULL;
  phgmg_reduce_info info;
  unsigned char *buf = NULL;
  if (phgmg_reduce(&red, sys, X, sys->N, OPT_STEPS + 1, o, &info, NULL) == PHGMG_OK) {
    const phgmg_rom *rom = phgmg_reduced_rom(red);
    *len = phgmg_rom_serialized_size(rom);
    *lam = info.lambda;
    buf = (unsigned char *)malloc(*len);
    if (buf && phgmg_rom_serialize(rom, buf, *len, len) != PHGMG_OK) { free(buf); buf = NULL; }
  }
  phgmg_reduced_destroy(red);
  return buf;
}

/* Reduces with a zeroed struct and with the defaults, each completed by
   set(); returns 1 when both succeed and the models are identical. */
static int opt_same(const phgmg_ph_system *sys, const double *X, void (*set)(phgmg_reduce_opts *, const phgmg_run *),
                    const phgmg_run *run) {
  phgmg_reduce_opts z, d;
  unsigned char *a, *b;
  size_t la = 0, lb = 0;
  double ka = 0, kb = 0;
  int same;
  memset(&z, 0, sizeof z);
  phgmg_reduce_opts_default(&d);
  set(&z, run); set(&d, run);
  a = opt_model(sys, X, &z, &la, &ka);
  b = opt_model(sys, X, &d, &lb, &kb);
  same = a && b && la == lb && !memcmp(a, b, la) && (ka == kb || (ka != ka && kb != kb));
  free(a); free(b);
  return same;
}

/* The run the tests train on (sin input, dt 0.1, OPT_STEPS steps) and its
   snapshots of sys (NULL when the allocation or the simulation fails). */
static double *opt_snapshots(const phgmg_ph_system *sys, phgmg_run *run) {
  phgmg_gl3_opts go;
  double *X = (double *)malloc(sizeof(double) * sys->N * (OPT_STEPS + 1));
  memset(run, 0, sizeof *run);
  run->u = msd_input_sin; run->dt = 0.1; run->nsteps = OPT_STEPS;
  memset(&go, 0, sizeof go);
  go.tol = 1e-10;
  if (X && phgmg_simulate_inputs(sys, 1, run, &go, X, sys->N, NULL, NULL, NULL) != PHGMG_OK) { free(X); X = NULL; }
  return X;
}
/* The nonlinear chain of 20 masses, banded. */
static int opt_nl_build(msd_nonlinear *M) {
  msd_nl_opts mo;
  memset(&mo, 0, sizeof mo);
  mo.n = 20; mo.storage = PHGMG_BANDED;
  return msd_nonlinear_build(M, &mo);
}

static void set_pod(phgmg_reduce_opts *o, const phgmg_run *r) { (void)r; o->method = PHGMG_METHOD_GMG_POD; o->r = 8; o->dt = 0.1; }
static void set_qm(phgmg_reduce_opts *o, const phgmg_run *r) { (void)r; o->method = PHGMG_METHOD_GMG_QM; o->r = 8; }
static void set_qm_cv(phgmg_reduce_opts *o, const phgmg_run *r) { set_qm(o, r); o->select.lambda_mode = PHGMG_LAMBDA_REGRESSION; }
static void set_qm_auto(phgmg_reduce_opts *o, const phgmg_run *r) {
  set_qm(o, r); o->select.lambda_mode = PHGMG_LAMBDA_VALIDATED; o->nrun = 1; o->runs = r;
}
static void set_sp1(phgmg_reduce_opts *o, const phgmg_run *r) { (void)r; o->method = PHGMG_METHOD_SP1; o->r = 8; }
static void set_pod_ecsw(phgmg_reduce_opts *o, const phgmg_run *r) { (void)r; o->method = PHGMG_METHOD_GMG_POD; o->r = 8; o->hyper.on = 1; }
static void set_sp2_qdeim(phgmg_reduce_opts *o, const phgmg_run *r) {
  (void)r; o->method = PHGMG_METHOD_SP2; o->r = 8; o->hyper.on = 1; o->hyper.kind = PHGMG_HYPER_QDEIM; o->hyper.allow_negative = 1;
}
static void set_qm_other(phgmg_reduce_opts *o, const phgmg_run *r) { set_qm(o, r); o->qm.lambda = 1e-9; }

TEST(test_reduce_opts_default_same_model) {
  msd_linear L;
  msd_nonlinear M;
  phgmg_run run;
  phgmg_reduce_opts d, z;
  double *X = NULL, *XN = NULL;
  CHECK(msd_linear_build(&L, 20, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  CHECK(opt_nl_build(&M) == 0);
  X = opt_snapshots(&L.sys, &run);
  XN = opt_snapshots(&M.sys, &run);
  CHECK(X && XN);
  if (X && XN) {
    CHECK(opt_same(&L.sys, X, set_pod, &run));
    CHECK(opt_same(&L.sys, X, set_qm, &run));
    CHECK(opt_same(&L.sys, X, set_qm_cv, &run));
    CHECK(opt_same(&L.sys, X, set_qm_auto, &run));
    CHECK(opt_same(&L.sys, X, set_sp1, &run));
    CHECK(opt_same(&M.sys, XN, set_pod_ecsw, &run));
    CHECK(opt_same(&M.sys, XN, set_sp2_qdeim, &run));
    { /* negative control: a lambda other than the default is another model */
      unsigned char *a, *b;
      size_t la = 0, lb = 0;
      double ka, kb;
      phgmg_reduce_opts_default(&d); set_qm(&d, &run);
      memset(&z, 0, sizeof z); set_qm_other(&z, &run);
      a = opt_model(&L.sys, X, &d, &la, &ka);
      b = opt_model(&L.sys, X, &z, &lb, &kb);
      CHECK(a && b && ka != kb && (la != lb || memcmp(a, b, la) != 0));
      free(a); free(b);
    }
  }
  /* the query is idempotent and leaves the required fields to the caller */
  phgmg_reduce_opts_default(&d);
  z = d;
  phgmg_reduce_opts_default(&z);
  CHECK(!memcmp(&d, &z, sizeof d));
  CHECK(d.method == 0 && d.r == 0 && d.select.blocks == 0 && d.select.newton_tol == 0.0 && !d.runs && !d.qm.eta);
  phgmg_reduce_opts_default(NULL);
  free(X); free(XN);
  msd_linear_free(&L);
  msd_nonlinear_free(&M);
}

/* hyper.on = 1 hyper-reduces; hyper.on = 0 keeps every term (another, larger
   model: the negative control); a struct with every other field left zero
   and one from phgmg_reduce_opts_default give the same model; values outside
   the enums and flags (hyper.on 2, PHGMG_HYPER_COUNT, PHGMG_MANIFOLD_COUNT,
   PHGMG_LAMBDA_MODE_COUNT, PHGMG_REF_COUNT) are refused. */
TEST(test_reduce_opts_hyper_on_and_enums) {
  msd_nonlinear M;
  phgmg_run run;
  phgmg_reduce_opts a, b;
  phgmg_reduced *red = NULL;
  unsigned char *ma, *mb, *mc;
  size_t la = 0, lb = 0, lc = 0;
  double ka, kb, kc;
  double *X;
  CHECK(opt_nl_build(&M) == 0);
  X = opt_snapshots(&M.sys, &run);
  CHECK(X != NULL);
  if (X) {
    memset(&a, 0, sizeof a); set_pod_ecsw(&a, &run);
    phgmg_reduce_opts_default(&b); set_pod_ecsw(&b, &run);
    ma = opt_model(&M.sys, X, &a, &la, &ka);
    mb = opt_model(&M.sys, X, &b, &lb, &kb);
    CHECK(ma && mb && la == lb && !memcmp(ma, mb, la));
    b.hyper.on = 0;   /* every term kept, a larger model */
    mc = opt_model(&M.sys, X, &b, &lc, &kc);
    CHECK(mc && lc != la);
    free(ma); free(mb); free(mc);
    {   /* phgmg_reduced_terms: the kept terms' indices, each kept row of P0 the basis's row at its coordinate */
      const int *t;
      CHECK_RC(phgmg_reduce(&red, &M.sys, X, M.sys.N, OPT_STEPS + 1, &a, NULL, NULL), PHGMG_OK);
      t = phgmg_reduced_terms(red);
      if (red && t) {
        const phgmg_rom *rom = phgmg_reduced_rom(red);
        double xr[16], *col = (double *)malloc(sizeof(double) * (size_t)M.sys.N);
        int k, j, ok = rom->nd > 0 && rom->nd < M.sys.nsep && col;
        for (j = 0; ok && j < rom->r; ++j) {
          memset(xr, 0, sizeof xr); xr[j] = 1.0;
          phgmg_reduced_lift(red, xr, col);   /* column j of the linear basis */
          for (k = 0; k < rom->nd; ++k)
            ok &= t[k] >= 0 && t[k] < M.sys.nsep && fabs((double)rom->P0[k + (size_t)j * rom->nd] - col[M.sys.sep_idx[t[k]]]) <= 1e-14;
        }
        CHECK(ok);
        free(col);
      } else {
        CHECK(red && t);
      }
      phgmg_reduced_destroy(red);
      red = NULL;
      CHECK_RC(phgmg_reduce(&red, &M.sys, X, M.sys.N, OPT_STEPS + 1, &b, NULL, NULL), PHGMG_OK);
      if (red) {   /* every term, in order: NULL or 0, 1, ... */
        const int *all = phgmg_reduced_terms(red);
        int k, ok = phgmg_reduced_rom(red)->nd == M.sys.nsep;
        for (k = 0; all && ok && k < M.sys.nsep; ++k) ok = all[k] == k;
        CHECK(ok && phgmg_reduced_terms(NULL) == NULL);
      }
      phgmg_reduced_destroy(red);
      red = NULL;
    }
    a.hyper.on = 2;
    CHECK_RC(phgmg_reduce(&red, &M.sys, X, M.sys.N, OPT_STEPS + 1, &a, NULL, NULL), PHGMG_ERR_INVALID_ARG);
    a.hyper.on = 1; a.hyper.kind = PHGMG_HYPER_COUNT;
    CHECK_RC(phgmg_reduce(&red, &M.sys, X, M.sys.N, OPT_STEPS + 1, &a, NULL, NULL), PHGMG_ERR_INVALID_ARG);
    a.hyper.kind = PHGMG_HYPER_ECSW; a.method = PHGMG_METHOD_GMG_QM; a.qm.manifold = PHGMG_MANIFOLD_COUNT;
    CHECK_RC(phgmg_reduce(&red, &M.sys, X, M.sys.N, OPT_STEPS + 1, &a, NULL, NULL), PHGMG_ERR_INVALID_ARG);
    a.qm.manifold = PHGMG_MANIFOLD_POD; a.select.lambda_mode = PHGMG_LAMBDA_MODE_COUNT;
    CHECK_RC(phgmg_reduce(&red, &M.sys, X, M.sys.N, OPT_STEPS + 1, &a, NULL, NULL), PHGMG_ERR_INVALID_ARG);
    a.select.lambda_mode = PHGMG_LAMBDA_FIXED; a.ref = PHGMG_REF_COUNT;
    CHECK_RC(phgmg_reduce(&red, &M.sys, X, M.sys.N, OPT_STEPS + 1, &a, NULL, NULL), PHGMG_ERR_INVALID_ARG);
    CHECK(red == NULL);
  }
  free(X);
  msd_nonlinear_free(&M);
}

SUITE(options) {
  RUN(test_reduce_opts_default_same_model);
  RUN(test_reduce_opts_hyper_on_and_enums);
}
