/* phgmg_study: one study over many r against separate phgmg_reduce calls.
   The reference is phgmg_reduce with opts.cache.pod_basis / grad_basis set to the
   study's bases (phgmg_study_basis), i.e. the pipeline that recomputes every
   snapshot quantity in full dimension, and the error measures phgmg_err_*,
   which lift every snapshot to N dimensions (an independent computation of
   the same sums). Agreement: the reduced blocks to 1e-10 relative to their
   largest entry (both sides differ only by rounding in the order of
   summation, amplified at most by the ridge fit's conditioning), the error
   measures to 1e-9 relative plus 8 eps absolute (e = ||X - g(X)||/||X|| is
   only determined to a few eps absolute, see test_errors.c). */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include "../examples/msd_models.h"
#include <stdlib.h>

/* max |a - b| / max |b| over n entries (phgmg_real arrays of the online models) */
static double ts_reldiff(const phgmg_real *a, const phgmg_real *b, size_t n) {
  double d = 0.0, s = 0.0;
  size_t i;
  if (!a && !b) return 0.0;
  if (!a || !b) return HUGE_VAL;
  for (i = 0; i < n; ++i) {
    d = PHGMG__MAX(d, fabs((double)a[i] - (double)b[i]));
    s = PHGMG__MAX(s, fabs((double)b[i]));
  }
  return s > 0.0 ? d / s : d;
}
static int ts_err_close(double a, double b) {
  if (isnan(a) || isnan(b)) return isnan(a) && isnan(b);
  return fabs(a - b) <= 1e-9 * fabs(b) + 8.0 * PHGMG__EPS;
}

/* The online model of the study's reduction against the reference one. */
static void ts_same_rom(const phgmg_reduced *a, const phgmg_reduced *b) {
  const phgmg_rom *x = phgmg_reduced_rom(a), *y = phgmg_reduced_rom(b);
  const size_t r = (size_t)x->r, m = (size_t)x->m, rn = (size_t)x->rn, p = r - m;
  CHECK(x->r == y->r && x->m == y->m && x->rn == y->rn && x->kind == y->kind && x->nd == y->nd);
  if (x->r != y->r || x->rn != y->rn || x->nd != y->nd) return;
  CHECK_LE(ts_reldiff(x->Qh, y->Qh, r * r), 1e-10);
  CHECK_LE(ts_reldiff(x->Bh, y->Bh, r * m), 1e-10);
  if (x->kind == PHGMG_ROM_LINEAR) CHECK_LE(ts_reldiff(x->K, y->K, r * r), 1e-10);
  if (x->kind == PHGMG_ROM_QUADRATIC) {
    CHECK_LE(ts_reldiff(x->G00, y->G00, r * r), 1e-10);
    CHECK_LE(ts_reldiff(x->G01, y->G01, r * rn), 1e-10);
    CHECK_LE(ts_reldiff(x->G10, y->G10, rn * r), 1e-10);
    CHECK_LE(ts_reldiff(x->G11, y->G11, rn * rn), 1e-10);
    CHECK_LE(ts_reldiff(x->Q01, y->Q01, r * rn), 1e-10);
    CHECK_LE(ts_reldiff(x->Q11, y->Q11, rn * rn), 1e-10);
    CHECK_LE(ts_reldiff(x->Ms, y->Ms, rn * p * p), 1e-10);
  }
  if (x->nd > 0) {
    CHECK_LE(ts_reldiff(x->P0, y->P0, (size_t)x->nd * r), 1e-10);
    CHECK_LE(ts_reldiff(x->w, y->w, (size_t)x->nd), 1e-12);
  }
  CHECK_LE(ts_reldiff(x->env_lo, y->env_lo, r), 1e-10);
  CHECK_LE(ts_reldiff(x->env_hi, y->env_hi, r), 1e-10);
}

/* One method at order r: the study's model and errors against the reference.
   fast: the study's fast path is expected to apply (red->study set). */
static void ts_case(phgmg_study *st, const phgmg_ph_system *sys, const double *X, int ns, phgmg_reduce_opts o,
                    double dt, int nsteps, int fast) {
  phgmg_reduced *a = NULL, *b = NULL;
  phgmg_reduce_opts ob = o;
  const int N = sys->N;
  int cols = 0;
  double ea[3], eb[3], *XR, *x0r;
  phgmg_result rc;
  rc = phgmg_study_reduce(st, &o, &a, NULL);
  CHECK_RC(rc, PHGMG_OK);
  if (o.method == PHGMG_METHOD_GMG_POD || o.method == PHGMG_METHOD_GMG_QM) ob.cache.pod_basis = phgmg_study_basis(st, 'a', &cols);
  else ob.cache.pod_basis = phgmg_study_basis(st, 'p', &cols);
  ob.cache.pod_cols = cols;
  if (o.method == PHGMG_METHOD_SP2) { ob.cache.grad_basis = phgmg_study_basis(st, 'g', &cols); ob.cache.grad_cols = cols; }
  rc = phgmg_reduce(&b, sys, X, N, ns, &ob, NULL, NULL);
  CHECK_RC(rc, PHGMG_OK);
  if (!a || !b) { phgmg_reduced_destroy(a); phgmg_reduced_destroy(b); return; }
  CHECK((a->study == st) == (fast != 0));
  ts_same_rom(a, b);
  XR = (double *)malloc(sizeof(double) * (size_t)o.r * ns);
  x0r = (double *)malloc(sizeof(double) * (size_t)o.r);
  phgmg_reduced_restrict(b, X, x0r);
  rc = phgmg_reduced_simulate(b, x0r, 0.0, dt, nsteps, msd_input_sin, NULL, 1e-10, 20, XR, NULL, NULL, NULL, NULL);
  CHECK_RC(rc, PHGMG_OK);
  CHECK_RC(phgmg_study_errors(st, a, XR, o.r, &ea[0], &ea[1], &ea[2]), PHGMG_OK);
  eb[0] = phgmg_err_red(b, X, N, ns, XR, o.r);
  eb[1] = phgmg_err_proj(b, X, N, ns);
  eb[2] = phgmg_err_lowerbound(b, X, N, ns);
  CHECK(ts_err_close(ea[0], eb[0]));
  CHECK(ts_err_close(ea[1], eb[1]));
  CHECK(ts_err_close(ea[2], eb[2]));
  CHECK(eb[1] > 1e-8 && eb[1] < 1.0); /* a real error, not a trivial zero */
  if (!ts_err_close(ea[0], eb[0]) || !ts_err_close(ea[1], eb[1]) || !ts_err_close(ea[2], eb[2]))
    printf("  method %d r %d: e_red %.15e / %.15e, e_proj %.15e / %.15e, e_lb %.15e / %.15e\n", (int)o.method, o.r,
           ea[0], eb[0], ea[1], eb[1], ea[2], eb[2]);
  /* no XR: e_red is NaN, the others as before */
  CHECK_RC(phgmg_study_errors(st, a, NULL, 0, &ea[0], &ea[1], NULL), PHGMG_OK);
  CHECK(isnan(ea[0]) && ts_err_close(ea[1], eb[1]));
  free(XR); free(x0r);
  phgmg_reduced_destroy(a);
  phgmg_reduced_destroy(b);
}

/* Linear chain (N = 40): GMG-POD, GMG-QM (fixed lambda), SP1 at several r
   from one study; the greedy manifold takes the general path. */
TEST(test_study_linear) {
  msd_linear M;
  const int nsteps = 300, ns = nsteps + 1;
  const double dt = 0.1;
  double *X, *x0;
  phgmg_gl3_opts go;
  phgmg_study *st = NULL;
  phgmg_study_opts so;
  int r, j;
  CHECK(msd_linear_build(&M, 20, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  X = (double *)malloc(sizeof(double) * (size_t)M.sys.N * ns);
  x0 = (double *)calloc((size_t)M.sys.N, sizeof(double));
  memset(&go, 0, sizeof go); go.tol = 1e-12; go.max_iter = 10;
  CHECK_RC(phgmg_simulate(&M.sys, x0, 0.0, dt, nsteps, msd_input_sin, NULL, &go, X, NULL, NULL, NULL, NULL, NULL),
           PHGMG_OK);
  memset(&so, 0, sizeof so);
  so.kmax = 16;
  CHECK_RC(phgmg_study_create(&st, &M.sys, X, M.sys.N, ns, &so, NULL), PHGMG_OK);
  for (r = 4; r <= 10; r += 3) {
    for (j = 0; j < 3; ++j) {
      static const phgmg_method meth[3] = {PHGMG_METHOD_GMG_POD, PHGMG_METHOD_GMG_QM, PHGMG_METHOD_SP1};
      phgmg_reduce_opts o;
      memset(&o, 0, sizeof o);
      o.method = meth[j]; o.r = r; o.qm.rn = 4; o.qm.lambda = 1e-6;
      ts_case(st, &M.sys, X, ns, o, dt, nsteps, 1);
    }
  }
  { /* greedy linear part: the study supplies the basis, the model is built as phgmg_reduce builds it */
    phgmg_reduce_opts o;
    memset(&o, 0, sizeof o);
    o.method = PHGMG_METHOD_GMG_QM; o.r = 7; o.qm.rn = 4; o.qm.lambda = 1e-6; o.qm.manifold = 1;
    ts_case(st, &M.sys, X, ns, o, dt, nsteps, 0);
  }
  { /* orders beyond the study's modes: not the fast path, and an error (r - m + rn > kmax) */
    phgmg_reduce_opts o;
    phgmg_reduced *red = (phgmg_reduced *)1;
    memset(&o, 0, sizeof o);
    o.method = PHGMG_METHOD_GMG_QM; o.r = 16; o.qm.rn = 4;
    CHECK_RC(phgmg_study_reduce(st, &o, &red, NULL), PHGMG_ERR_SIZE);
    CHECK(red == NULL);
  }
  phgmg_study_destroy(st);
  free(X); free(x0);
  msd_linear_free(&M);
}

/* Nonlinear chain (N = 40, banded, quartic springs): SP2 and GMG-QM with
   structure-preserving DEIM; the study's DEIM points (Q-DEIM, computed once)
   equal phgmg_reduce's own. */
TEST(test_study_nonlinear) {
  msd_nonlinear M;
  msd_nl_opts mo;
  const int nsteps = 300, ns = nsteps + 1;
  const double dt = 0.1;
  double *X, *x0;
  phgmg_gl3_opts go;
  phgmg_study *st = NULL;
  phgmg_study_opts so;
  int j;
  memset(&mo, 0, sizeof mo);
  mo.n = 20; mo.mass = 1.0; mo.storage = PHGMG_BANDED;
  CHECK(msd_nonlinear_build(&M, &mo) == 0);
  X = (double *)malloc(sizeof(double) * (size_t)M.sys.N * ns);
  x0 = (double *)calloc((size_t)M.sys.N, sizeof(double));
  memset(&go, 0, sizeof go); go.tol = 1e-12; go.max_iter = 20;
  CHECK_RC(phgmg_simulate(&M.sys, x0, 0.0, dt, nsteps, msd_input_sin, NULL, &go, X, NULL, NULL, NULL, NULL, NULL),
           PHGMG_OK);
  memset(&so, 0, sizeof so);
  so.what = PHGMG_STUDY_GMG | PHGMG_STUDY_SP2;
  so.kmax = 14;
  CHECK_RC(phgmg_study_create(&st, &M.sys, X, M.sys.N, ns, &so, NULL), PHGMG_OK);
  for (j = 0; j < 3; ++j) {
    static const phgmg_method meth[3] = {PHGMG_METHOD_SP2, PHGMG_METHOD_GMG_POD, PHGMG_METHOD_GMG_QM};
    phgmg_reduce_opts o;
    memset(&o, 0, sizeof o);
    o.method = meth[j]; o.r = 8; o.qm.rn = 4; o.qm.lambda = 1e-4;
    o.hyper.on = 1; o.hyper.kind = PHGMG_HYPER_QDEIM; o.hyper.deim_tol = 1e-8; o.hyper.allow_negative = 1;
    ts_case(st, &M.sys, X, ns, o, dt, nsteps, 1);
  }
  phgmg_study_destroy(st);
  free(X); free(x0);
  msd_nonlinear_free(&M);
}

/* The tails T(k) of a study equal the squared norms of the residuals of the
   first k modes computed directly (orthogonal projection in N dimensions). */
TEST(test_study_tails) {
  const int N = 30, ns = 50, m = 1, K = 12;
  msd_linear M;
  double *X = (double *)malloc(sizeof(double) * (size_t)N * ns), *R = (double *)malloc(sizeof(double) * (size_t)N * ns);
  double *tmp = (double *)malloc(sizeof(double) * (size_t)(K + 1) * ns);
  phgmg_study *st = NULL;
  phgmg_study_opts so;
  int i, k;
  CHECK(msd_linear_build(&M, N / 2, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  for (i = 0; i < N * ns; ++i) X[i] = th_rand() * (1.0 + (double)(i % N)); /* rank min(N, ns), graded columns */
  memset(&so, 0, sizeof so);
  so.kmax = K;
  CHECK_RC(phgmg_study_create(&st, &M.sys, X, N, ns, &so, NULL), PHGMG_OK);
  CHECK(st && st->ka == K && st->kp == K);
  for (k = 0; st && k <= K; k += 3) {
    double t = 0.0;
    memcpy(R, X, sizeof(double) * (size_t)N * ns);
    phgmg__orth_remove(N, m, st->QB, ns, R, N, tmp);
    phgmg__orth_remove(N, k, st->Ua, ns, R, N, tmp);
    for (i = 0; i < N * ns; ++i) t += R[i] * R[i];
    CHECK_LE(fabs(st->Ta[k] - t), 1e-12 * st->xx);
    memcpy(R, X, sizeof(double) * (size_t)N * ns);
    phgmg__orth_remove(N, k, st->Up, ns, R, N, tmp);
    for (t = 0.0, i = 0; i < N * ns; ++i) t += R[i] * R[i];
    CHECK_LE(fabs(st->Tp[k] - t), 1e-12 * st->xx);
  }
  phgmg_study_destroy(st);
  free(X); free(R); free(tmp);
  msd_linear_free(&M);
}

TEST(test_study_args) {
  msd_linear M, M2;
  const int ns = 40;
  double *X;
  phgmg_study *st = (phgmg_study *)1;
  phgmg_study_opts so;
  phgmg_reduced *red = NULL;
  phgmg_reduce_opts o;
  double e = 0.0;
  int i, cols = -1;
  CHECK(msd_linear_build(&M, 5, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  CHECK(msd_linear_build(&M2, 6, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  X = (double *)malloc(sizeof(double) * (size_t)M2.sys.N * ns);
  for (i = 0; i < M2.sys.N * ns; ++i) X[i] = th_rand();
  memset(&so, 0, sizeof so);
  so.kmax = 4;
  CHECK_RC(phgmg_study_create(NULL, &M.sys, X, M.sys.N, ns, &so, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_study_create(&st, &M.sys, X, M.sys.N, ns, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK(st == NULL);
  so.kmax = M.sys.N + 1;
  CHECK_RC(phgmg_study_create(&st, &M.sys, X, M.sys.N, ns, &so, NULL), PHGMG_ERR_SIZE);
  so.kmax = 4;
  CHECK_RC(phgmg_study_create(&st, &M.sys, X, M.sys.N - 1, ns, &so, NULL), PHGMG_ERR_SIZE);
  X[3] = NAN;
  CHECK_RC(phgmg_study_create(&st, &M.sys, X, M.sys.N, ns, &so, NULL), PHGMG_ERR_NANINF);
  X[3] = 0.5;
  so.what = PHGMG_STUDY_GMG;   /* no SP basis */
  CHECK_RC(phgmg_study_create(&st, &M.sys, X, M.sys.N, ns, &so, NULL), PHGMG_OK);
  CHECK(phgmg_study_basis(st, 'p', &cols) == NULL && cols == 0);
  CHECK(phgmg_study_basis(st, 'a', &cols) != NULL && cols == 4);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = 3;
  CHECK_RC(phgmg_study_reduce(NULL, &o, &red, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_study_reduce(st, &o, &red, NULL), PHGMG_OK);
  CHECK_RC(phgmg_study_errors(NULL, red, NULL, 0, &e, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  phgmg_reduced_destroy(red);
  red = NULL;
  /* a model of another system (N = 12) does not belong to this study (N = 10) */
  CHECK_RC(phgmg_reduce(&red, &M2.sys, X, M2.sys.N, ns, &o, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_study_errors(st, red, NULL, 0, &e, NULL, NULL), PHGMG_ERR_SIZE);
  phgmg_reduced_destroy(red);
  phgmg_study_destroy(st);
  phgmg_study_destroy(NULL);
  free(X);
  msd_linear_free(&M);
  msd_linear_free(&M2);
}

/* The validation set's duplicate detection (lambda_auto = 1): runs with the
   same start and bit-identical inputs at every stage time are simulated once;
   a different x0, step, or one differing input sample keeps them apart. */
static void ts_u_const(double t, double *u, void *p) { (void)t; (void)p; u[0] = 0.1; }
static void ts_u_const_b(double t, double *u, void *p) { (void)p; u[0] = t > 9.95 && t < 10.0 ? 0.1000001 : 0.1; }
TEST(test_study_vrun_same) {
  msd_linear M;
  phgmg__rctx c;
  phgmg__vset *v = (phgmg__vset *)calloc(1, sizeof(phgmg__vset));
  double x0a[10], x0b[10], ub[2];
  int i;
  CHECK(msd_linear_build(&M, 5, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  memset(&c, 0, sizeof c);
  c.sys = &M.sys;
  for (i = 0; i < 10; ++i) x0a[i] = x0b[i] = 0.01 * i;
  for (i = 0; i < 3; ++i) { v->t0[i] = 0.0; v->dt[i] = 0.1; v->nsteps[i] = 200; }
  v->u[0] = ts_u_const; v->x0[0] = x0a;
  v->u[1] = msd_input_const; v->x0[1] = x0b;  /* another function, the same values */
  v->u[2] = ts_u_const_b; v->x0[2] = x0a;     /* one stage time differs (t in (9.95, 10)) */
  CHECK(phgmg__vrun_same(&c, v, 0, 1, ub) == 1);
  CHECK(phgmg__vrun_same(&c, v, 0, 2, ub) == 0);
  x0b[3] = nextafter(x0b[3], 1.0); /* one ulp */
  CHECK(phgmg__vrun_same(&c, v, 0, 1, ub) == 0);
  x0b[3] = x0a[3];
  v->nsteps[1] = 199;
  CHECK(phgmg__vrun_same(&c, v, 0, 1, ub) == 0);
  v->nsteps[1] = 200;
  v->nsteps[2] = 99; v->nsteps[0] = 99;       /* the differing sample lies beyond step 99 */
  CHECK(phgmg__vrun_same(&c, v, 0, 2, ub) == 1);
  free(v);
  msd_linear_free(&M);
}

SUITE(study) {
  RUN(test_study_linear);
  RUN(test_study_nonlinear);
  RUN(test_study_tails);
  RUN(test_study_args);
  RUN(test_study_vrun_same);
}
