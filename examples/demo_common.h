/* Shared pieces of the two Section-5 demos (examples/msd_linear.c and
   examples/msd_nonlinear.c): inputs, one reduction + simulation + error
   evaluation, CSV output, timing. Include after phgmg.h. */
#ifndef PHGMG_DEMO_COMMON_H
#define PHGMG_DEMO_COMMON_H
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <time.h>
#include <sys/stat.h>
#include "svgplot.h"

#if defined(__GNUC__) || defined(__clang__)
#define DEMO_FN static __attribute__((unused))
#else
#define DEMO_FN static
#endif


DEMO_FN double demo_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The automatic lambda's settings as the library's defaults give them
   (phgmg_reduce_opts_default), then tail and a newline. */
DEMO_FN void demo_print_lambda_defaults(const char *tail) {
  phgmg_reduce_opts d;
  phgmg_reduce_opts_default(&d);
  printf("(library defaults: grid %g..%g at %d per decade, %d-fold validation over contiguous\n"
         "blocks of snapshots, conditioning guard %g)%s\n",
         d.select.lambda_min, d.select.lambda_max, d.select.per_decade, d.select.folds, d.select.rcond, tail);
}

DEMO_FN void demo_die(const char *what, phgmg_result rc) {
  fprintf(stderr, "error: %s: %s\n", what, phgmg_result_string(rc));
  exit(1);
}

/* Result of one reduced model on one snapshot set. */
typedef struct demo_rom_result {
  double e_red, e_y, e_proj, e_lower;
  phgmg_result rc;
  phgmg_reduce_info info;
  phgmg_rom_stats stats;   /* of the reduced simulation (stats.failures: failed Newton solves) */
  double t_offline, t_online;
} demo_rom_result;

/* Bases computed once per snapshot set and shared by every r and method: a
   phgmg_study (POD of the adjusted snapshots, of X, of the gradients, the
   snapshots' coordinates, G- and Q-blocks), plus the demo's DEIM points. */
typedef struct demo_cache {
  phgmg_study *st;
  const double *adj, *plain, *grad;   /* the study's bases (phgmg_study_basis) */
  double *deim_w;
  int adj_cols, plain_cols, grad_cols, *deim_pts, deim_count;
} demo_cache;

/* Reduce `sys` from snapshots X (N x ns) with `opts`, simulate the ROM from
   rho(x0) with the FOM's input, and measure e_red, e_y (against the FOM's
   output Y), e_proj and (GMG-QM) e_lowerbound. If energy is non-NULL it gets
   the ROM's energy bookkeeping. With a cache (its study made from the same
   X), the reduction and the error measures go through the study
   (phgmg_study_reduce, phgmg_study_errors): the same model and values to
   rounding, at a cost per r independent of N ns r. */
DEMO_FN demo_rom_result demo_run_rom(const demo_cache *cache, const phgmg_ph_system *sys, const double *X,
                                    const double *Y, int nsteps, double dt, phgmg_input_fn uf,
                                    const phgmg_reduce_opts *opts, double newton_tol, int newton_it,
                                    const phgmg_energy *energy) {
  demo_rom_result res;
  phgmg_reduced *red = NULL;
  const int N = sys->N, m = sys->m, ns = nsteps + 1, r = opts->r;
  double *XR, *YR, *xr0;
  double t0;
  memset(&res, 0, sizeof res);
  res.e_red = res.e_y = res.e_proj = res.e_lower = NAN;
  t0 = demo_now();
  if (cache && cache->st) res.rc = phgmg_study_reduce(cache->st, opts, &red, &res.info);
  else res.rc = phgmg_reduce(&red, sys, X, N, ns, opts, &res.info, NULL);
  res.t_offline = demo_now() - t0;
  if (res.rc != PHGMG_OK) return res;
  XR = (double *)malloc(sizeof(double) * (size_t)r * ns);
  YR = (double *)malloc(sizeof(double) * (size_t)m * ns);
  xr0 = (double *)malloc(sizeof(double) * (size_t)r);
  if (!XR || !YR || !xr0) { fprintf(stderr, "out of memory\n"); exit(1); }
  phgmg_reduced_restrict(red, X, xr0);     /* rho(x0) (phgmg.h manual 8.8) */
  t0 = demo_now();
  res.rc = phgmg_reduced_simulate(red, xr0, 0.0, dt, nsteps, uf, NULL, newton_tol, newton_it, XR, YR,
                                  energy, &res.stats, NULL);
  res.t_online = demo_now() - t0;
  if (res.rc == PHGMG_OK) res.e_y = phgmg_rel_error(m, ns, Y, m, YR, m);
  if (cache && cache->st) {
    phgmg_study_errors(cache->st, red, res.rc == PHGMG_OK ? XR : NULL, r, &res.e_red, &res.e_proj, &res.e_lower);
    if (opts->method != PHGMG_METHOD_GMG_QM) res.e_lower = NAN;
  } else {
    if (res.rc == PHGMG_OK) res.e_red = phgmg_err_red(red, X, N, ns, XR, r);
    res.e_proj = phgmg_err_proj(red, X, N, ns);
    if (opts->method == PHGMG_METHOD_GMG_QM) res.e_lower = phgmg_err_lowerbound(red, X, N, ns);
  }
  free(XR); free(YR); free(xr0);
  phgmg_reduced_destroy(red);
  return res;
}

/* DEIM points and weights of a separable nonlinear part (poly form), once per
   snapshot set: they depend on neither r nor the method. */
DEMO_FN void demo_cache_deim(demo_cache *c, const phgmg_ph_system *sys, const double *X, int ns, double tol) {
  const int nt = sys->nsep;
  double *F = (double *)malloc(sizeof(double) * (size_t)nt * ns);
  int i, a, k, nneg = 0;
  phgmg_result rc;
  c->deim_pts = (int *)malloc(sizeof(int) * nt);
  c->deim_w = (double *)malloc(sizeof(double) * nt);
  if (!F || !c->deim_pts || !c->deim_w) { fprintf(stderr, "out of memory\n"); exit(1); }
  for (i = 0; i < ns; ++i)
    for (a = 0; a < nt; ++a) {
      const double s = X[sys->sep_idx[a] + (size_t)i * sys->N];
      double d = 0.0;
      for (k = sys->poly_deg; k >= 1; --k) d = d * s + k * sys->poly[k];
      F[a + (size_t)i * nt] = d;
    }
  rc = phgmg_deim(nt, ns, F, nt, sys->sep_w, tol, 0, c->deim_pts, c->deim_w, &c->deim_count, &nneg, NULL, NULL);
  if (rc != PHGMG_OK) demo_die("DEIM", rc);
  free(F);
}

/* The study of snapshot set X (N x ns, kept by the study: X must outlive
   the cache): bases of kmax modes for `what` (PHGMG_STUDY_* flags). */
DEMO_FN void demo_cache_build_what(demo_cache *c, const phgmg_ph_system *sys, const double *X, int ns, int kmax,
                                   unsigned what) {
  phgmg_study_opts so;
  phgmg_result rc;
  memset(c, 0, sizeof *c);
  memset(&so, 0, sizeof so);
  so.what = what;
  so.kmax = kmax;
  rc = phgmg_study_create(&c->st, sys, X, sys->N, ns, &so, NULL);
  if (rc != PHGMG_OK) demo_die("POD of the snapshots", rc);
  c->adj = phgmg_study_basis(c->st, 'a', &c->adj_cols);
  c->plain = phgmg_study_basis(c->st, 'p', &c->plain_cols);
  c->grad = phgmg_study_basis(c->st, 'g', &c->grad_cols);
}
/* Every method's bases (GMG and SP1), SP2's gradient basis if want_grad. */
DEMO_FN void demo_cache_build(demo_cache *c, const phgmg_ph_system *sys, const double *X, int ns, int kmax,
                             int want_grad) {
  demo_cache_build_what(c, sys, X, ns, kmax, PHGMG_STUDY_GMG | PHGMG_STUDY_SP | (want_grad ? PHGMG_STUDY_SP2 : 0u));
}
DEMO_FN void demo_cache_free(demo_cache *c) { phgmg_study_destroy(c->st); free(c->deim_pts); free(c->deim_w); }
DEMO_FN void demo_cache_use(const demo_cache *c, phgmg_reduce_opts *o) {
  o->cache.deim_pts = c->deim_pts; o->cache.deim_w = c->deim_w; o->cache.deim_count = c->deim_count;
  if (o->method == PHGMG_METHOD_GMG_POD || o->method == PHGMG_METHOD_GMG_QM) {
    o->cache.pod_basis = c->adj; o->cache.pod_cols = c->adj_cols;
  } else {
    o->cache.pod_basis = c->plain; o->cache.pod_cols = c->plain_cols;
    o->cache.grad_basis = c->grad; o->cache.grad_cols = c->grad_cols;
  }
}

/* CSV: header, then rows of numbers (first column printed as an integer or a
   time). NaN is written as "nan" (a failed or non-applicable entry). */
DEMO_FN void demo_write_csv(const char *path, const char *header, int nrows, int ncols,
                           const double *data /* row-major nrows x ncols */, int first_int) {
  FILE *f = fopen(path, "w");
  int i, j;
  if (!f) { fprintf(stderr, "error: cannot write %s\n", path); exit(1); }
  fprintf(f, "%s\n", header);
  for (i = 0; i < nrows; ++i) {
    for (j = 0; j < ncols; ++j) {
      const double v = data[i * ncols + j];
      if (j == 0 && first_int) fprintf(f, "%d", (int)v);
      else if (isnan(v)) fprintf(f, "%snan", j ? "," : "");
      else fprintf(f, "%s%.6e", j ? "," : "", v);
    }
    fprintf(f, "\n");
  }
  fclose(f);
}

DEMO_FN void demo_mkdir(const char *dir) { mkdir(dir, 0777); }

/* --lambda L|auto: a number (fixed GMG-QM ridge parameter) or "auto"
   (phgmg_reduce_opts.select.lambda_mode with the default grid and folds). Returns
   1 for auto, 0 for a number (stored in *lambda), -1 for anything else. */
DEMO_FN int demo_parse_lambda(const char *arg, double *lambda) {
  char *end;
  double v;
  if (!strcmp(arg, "auto")) return 1;
  v = strtod(arg, &end);
  if (end == arg || *end != '\0') return -1;
  *lambda = v;
  return 0;
}

/* A comma-separated list of orders ("8,12,16") into rl (at most max);
   returns how many were read (stops at the first non-number). */
DEMO_FN int demo_parse_rlist(const char *arg, int *rl, int max) {
  const char *q = arg;
  char *end;
  int n = 0;
  while (*q && n < max) {
    rl[n++] = (int)strtol(q, &end, 10);
    if (end == q) break;
    q = *end == ',' ? end + 1 : end;
  }
  return n;
}

/* The automatic-lambda study of one example and input: rows
   "r, GMG-POD e_red, GMG-QM-auto e_red, lambda chosen, e_lowerbound, Newton
   failures" (nr x 6, row-major) into <out>/<example>_<input>_lambda_auto.csv. */
#define DEMO_LA_COLS 10
DEMO_FN void demo_write_lambda_auto(const char *out, const char *example, const char *input, int nr,
                                    const double *rows) {
  char path[512];
  snprintf(path, sizeof path, "%s/%s_%s_lambda_auto.csv", out, example, input);
  demo_write_csv(path, "r,GMG-POD,GMG-QM-auto,lambda,lowerbound,newton_failures,GMG-QM-best,lambda_best,"
                 "newton_failures_best,best_is_greedy", nr, DEMO_LA_COLS, rows, 1);
}

/* Newton failures of one reduced simulation: the stepper's count, at least 1
   when the simulation stopped on PHGMG_ERR_NOT_CONVERGED. */
DEMO_FN double demo_newton_failures(const demo_rom_result *res) {
  long f = res->stats.failures;
  if (res->rc == PHGMG_ERR_NOT_CONVERGED && f < 1) f = 1;
  return (double)f;
}

/* One row of the automatic-lambda study at order `base->r`: GMG-POD and
   GMG-QM with lambda validated by simulation (select.lambda_mode; both
   with the other settings of `base`), the row
   "r, GMG-POD e_red, GMG-QM-auto e_red, lambda, e_lowerbound, Newton
   failures" into row[6], and one line on the terminal. */
DEMO_FN void demo_lambda_auto_row(const phgmg_ph_system *sys, const double *X, const double *Y, int nsteps,
                                  double dt, phgmg_input_fn uf, const demo_cache *cache,
                                  const phgmg_reduce_opts *base, double newton_tol, int newton_it, double *row) {
  phgmg_reduce_opts o = *base;
  demo_rom_result res;
  phgmg_run run;
  memset(&run, 0, sizeof run);
  run.u = uf; run.dt = dt; run.nsteps = nsteps;
  /* the better manifold's best case on the training input: lambda validated
     on the training run alone, for the hierarchical POD and the greedy linear
     part; kept: the one with the smaller training state error e_red (model
     selection on the training run -- what this column reports; no claim on
     other inputs) */
  {
    demo_rom_result rm[2];
    int g, pick;
    for (g = 0; g < 2; ++g) {
      o = *base;
      o.method = PHGMG_METHOD_GMG_QM; o.select.lambda_mode = PHGMG_LAMBDA_VALIDATED; o.select.train_only = 1; o.qm.manifold = g;
      o.nrun = 1; o.runs = &run; o.select.newton_tol = newton_tol; o.select.newton_iter = newton_it;
      demo_cache_use(cache, &o);
      rm[g] = demo_run_rom(cache, sys, X, Y, nsteps, dt, uf, &o, newton_tol, newton_it, NULL);
    }
    /* a tie within rounding (greedy took the leading modes: the same model)
       keeps the hierarchical POD */
    pick = rm[1].rc == PHGMG_OK && (rm[0].rc != PHGMG_OK || rm[1].e_red < rm[0].e_red * (1.0 - 1e-9));
    res = rm[pick];
    row[9] = pick;
  }
  row[6] = res.e_red; row[7] = res.info.lambda < HUGE_VAL ? res.info.lambda : NAN; row[8] = demo_newton_failures(&res);
  o = *base;
  o.method = PHGMG_METHOD_GMG_POD; o.select.lambda_mode = PHGMG_LAMBDA_FIXED;
  demo_cache_use(cache, &o);
  res = demo_run_rom(cache, sys, X, Y, nsteps, dt, uf, &o, newton_tol, newton_it, NULL);
  if (res.rc != PHGMG_OK) fprintf(stderr, "  [GMG-POD r=%d: %s]\n", o.r, phgmg_result_string(res.rc));
  row[0] = o.r; row[1] = res.e_red;
  o = *base;
  o.method = PHGMG_METHOD_GMG_QM; o.select.lambda_mode = PHGMG_LAMBDA_VALIDATED;
  o.nrun = 1; o.runs = &run; o.select.newton_tol = newton_tol; o.select.newton_iter = newton_it;
  demo_cache_use(cache, &o);
  res = demo_run_rom(cache, sys, X, Y, nsteps, dt, uf, &o, newton_tol, newton_it, NULL);
  if (res.rc != PHGMG_OK) fprintf(stderr, "  [GMG-QM r=%d: %s]\n", o.r, phgmg_result_string(res.rc));
  row[2] = res.e_red; row[3] = res.info.lambda > 0.0 && res.info.lambda < HUGE_VAL ? res.info.lambda : NAN;
  row[4] = res.e_lower;
  row[5] = demo_newton_failures(&res);
  printf("  %3d  %9.3e  %9.3e  %6.2f  %8.2e%-3s %9.3e  %6.2f  %.0f   %9.3e%s %6.2f  %8.2e  %.0f\n", o.r, row[1], row[2],
         row[1] / row[2], row[3], res.info.lambda_raised ? " +" : "", row[4], row[2] / row[4], row[5], row[6],
         row[9] > 0 ? "g" : " ", row[1] / row[6], row[7], row[8]);
}

DEMO_FN void demo_lambda_auto_header(const char *input) {
  printf("\nu = %s  (e_red; QM-auto: lambda validated by simulation on the training run and probe runs;\n"
         "QM-best: lambda validated on the training run alone, hierarchical POD or greedy linear part\n"
         "(opts.qm.manifold = 1, marked g), whichever has the smaller training e_red;\n"
         "lambda nan = the linear limit M = 0; "
         "+ = raised by the conditioning guard)\n  %3s  %-10s %-10s %-7s %-11s %-10s %-7s %-4s %-10s %-7s %-9s %s\n",
         input, "r", "GMG-POD", "QM-auto", "ratio", "lambda", "lowerbnd", "QM/lb", "fail", "QM-best", "ratio",
         "lambda", "fail");
}

/* --lambda auto, one example: for u = 0.1 sin t and u = 0.1, the full-order
   trajectory, then GMG-POD against GMG-QM with the automatic lambda for
   r = rmin, rmin + rstep, ..., rmax (a table and a CSV per input).
   base: the reduce options shared by every r (rn, DEIM, step map). */
DEMO_FN void demo_lambda_auto_study(const phgmg_ph_system *sys, const char *out, const char *example,
                                    int rmin, int rmax, int rstep, const phgmg_reduce_opts *base,
                                    double newton_tol, int newton_it, int nsteps, double dt) {
  const int N = sys->N, ns = nsteps + 1, nr = (rmax - rmin) / rstep + 1;
  const char *inname[2] = {"sin", "const"};
  phgmg_input_fn inf[2] = {msd_input_sin, msd_input_const};
  int in, k;
  for (in = 0; in < 2; ++in) {
    double *X = (double *)malloc(sizeof(double) * N * ns), *Y = (double *)malloc(sizeof(double) * ns);
    double *x0 = (double *)calloc((size_t)N, sizeof(double));
    double *rows = (double *)malloc(sizeof(double) * nr * DEMO_LA_COLS);
    phgmg_gl3_opts go;
    phgmg_result rc;
    demo_cache cache;
    if (!X || !Y || !x0 || !rows) { fprintf(stderr, "out of memory\n"); exit(1); }
    memset(&go, 0, sizeof go); go.tol = newton_tol; go.max_iter = newton_it;
    rc = phgmg_simulate(sys, x0, 0.0, dt, nsteps, inf[in], NULL, &go, X, Y, NULL, NULL, NULL, NULL);
    if (rc != PHGMG_OK) demo_die("full-order simulation", rc);
    demo_cache_build_what(&cache, sys, X, ns, rmax + base->qm.rn + 1, PHGMG_STUDY_GMG); /* GMG-POD, GMG-QM only */
    if (base->hyper.on && base->hyper.kind != PHGMG_HYPER_ECSW) demo_cache_deim(&cache, sys, X, ns, base->hyper.deim_tol);
    demo_lambda_auto_header(in ? "0.1" : "0.1 sin t");
    for (k = 0; k < nr; ++k) {
      phgmg_reduce_opts o = *base;
      o.r = rmin + k * rstep;
      demo_lambda_auto_row(sys, X, Y, nsteps, dt, inf[in], &cache, &o, newton_tol, newton_it, rows + k * DEMO_LA_COLS);
    }
    demo_write_lambda_auto(out, example, inname[in], nr, rows);
    demo_cache_free(&cache);
    free(X); free(Y); free(x0); free(rows);
  }
  printf("\nwrote %s/%s_sin_lambda_auto.csv and %s/%s_const_lambda_auto.csv\n", out, example, out, example);
}

/* Writes the three error tables of one example and input
   (<out>/<example>_<input>_{e_red,e_y,e_proj}.csv) and draws its state panel
   (methods, projection errors, lower bound) and output panel into fig
   (panels in and 2 + in). tred/ty: nr x (nmeth+1) rows "r, method...";
   tproj: nr x 4 rows "r, GMG-POD, GMG-QM, lowerbound". */
DEMO_FN void demo_tables_and_panels(const char *out, const char *example, const char *input, int in,
                                    const char *methods_header, const char *const *meth_name, int nmeth,
                                    int nr, const double *rx, const double *tred, const double *ty,
                                    const double *tproj, svgplot_fig *fig) {
  static const char *pn[3] = {"e_proj GMG-POD", "e_proj GMG-QM", "e_lowerbound"};
  char path[512], title[128];
  double *col = (double *)malloc(sizeof(double) * (size_t)nr);
  int j, k;
  if (!col) { fprintf(stderr, "out of memory\n"); exit(1); }
  snprintf(path, sizeof path, "%s/%s_%s_e_red.csv", out, example, input);
  demo_write_csv(path, methods_header, nr, nmeth + 1, tred, 1);
  snprintf(path, sizeof path, "%s/%s_%s_e_y.csv", out, example, input);
  demo_write_csv(path, methods_header, nr, nmeth + 1, ty, 1);
  snprintf(path, sizeof path, "%s/%s_%s_e_proj.csv", out, example, input);
  demo_write_csv(path, "r,GMG-POD,GMG-QM,lowerbound", nr, 4, tproj, 1);
  snprintf(title, sizeof title, "(%c) state error, u = %s", 'a' + in, in ? "0.1" : "0.1 sin t");
  svgplot_panel(fig, in, title, "reduced order r", "relative state error");
  snprintf(title, sizeof title, "(%c) output error, u = %s", 'c' + in, in ? "0.1" : "0.1 sin t");
  svgplot_panel(fig, 2 + in, title, "reduced order r", "relative output error e_y");
  for (j = 0; j < nmeth; ++j) {
    for (k = 0; k < nr; ++k) col[k] = tred[k * (nmeth + 1) + 1 + j];
    svgplot_series(fig, in, meth_name[j], nr, rx, col, j | SVGPLOT_MARKERS);
    for (k = 0; k < nr; ++k) col[k] = ty[k * (nmeth + 1) + 1 + j];
    svgplot_series(fig, 2 + in, meth_name[j], nr, rx, col, j | SVGPLOT_MARKERS);
  }
  for (j = 0; j < 3; ++j) {
    for (k = 0; k < nr; ++k) col[k] = tproj[k * 4 + 1 + j];
    svgplot_series(fig, in, pn[j], nr, rx, col, 4 + j);
  }
  free(col);
}
/* ---- generalization study: train on one run (u = 0.1 sin t) or
   two (plus a multisine), test on five inputs ---------------------------- */
DEMO_FN void demo_u_sin2(double t, double *u, void *p) { (void)p; u[0] = 0.1 * sin(2.0 * t); }
DEMO_FN void demo_u_chirp(double t, double *u, void *p) { (void)p; u[0] = 0.1 * sin(0.2 * t + 0.01 * t * t); }
/* random piecewise constant: a new level in [-0.1, 0.1] every 5 time units (hash of the interval index) */
DEMO_FN void demo_u_pwc(double t, double *u, void *p) {
  unsigned k = (unsigned)(t / 5.0), h = k * 2654435761u;
  (void)p;
  h ^= h >> 13; h *= 0x5bd1e995u; h ^= h >> 15;
  u[0] = 0.1 * (2.0 * (double)(h % 10000u) / 9999.0 - 1.0);
}
/* the second training input: a multisine 0.05 (sin 0.5t + sin 1.5t + sin 3t) (not a test input) */
DEMO_FN void demo_u_multisine(double t, double *u, void *p) {
  (void)p;
  u[0] = 0.05 * (sin(0.5 * t) + sin(1.5 * t) + sin(3.0 * t));
}
#define DEMO_NIN 5
static const char *const demo_in_name[DEMO_NIN] = {"0.1 sin t", "0.1", "0.1 sin 2t", "chirp", "random pwc"};
#define DEMO_GEN_COLS 11
/* rows: r, training runs (1|2), method (1 GMG-POD, 2 GMG-QM lambda_auto = 1),
   e_y on the five inputs, Newton failures over the five, lambda (nan: M = 0 or POD). */
DEMO_FN void demo_generalization_study(const phgmg_ph_system *sys, const char *out, const char *example,
                                       const int *rlist, int nr, const phgmg_reduce_opts *base, double tol, int it,
                                       int nsteps, double dt, svgplot_fig *fig, int panel0) {
  static phgmg_input_fn inf[DEMO_NIN] = {msd_input_sin, msd_input_const, demo_u_sin2, demo_u_chirp, demo_u_pwc};
  static phgmg_input_fn train2 = demo_u_multisine;
  const int N = sys->N, m = sys->m, ns = nsteps + 1;
  double *X = (double *)malloc(sizeof(double) * (size_t)N * ns * (DEMO_NIN + 1));
  double *Y = (double *)malloc(sizeof(double) * (size_t)m * ns * DEMO_NIN);
  double *YR = (double *)malloc(sizeof(double) * (size_t)m * ns), *xr0 = (double *)calloc(64, sizeof(double));
  double *rows = (double *)calloc((size_t)(nr > 0 ? nr : 1) * 4 * DEMO_GEN_COLS, sizeof(double));
  double rx[64], col[4][64], t_study = demo_now();
  phgmg_run runs[2];
  phgmg_gl3_opts go;
  char path[512], title[160];
  int i, k, tr, me, nrow = 0;
  if (!X || !Y || !YR || !xr0 || !rows || nr > 64) { fprintf(stderr, "out of memory\n"); exit(1); }
  memset(&go, 0, sizeof go); go.tol = tol; go.max_iter = it;
  memset(runs, 0, sizeof runs);
  for (i = 0; i < 2; ++i) { runs[i].u = i ? train2 : inf[0]; runs[i].dt = dt; runs[i].nsteps = nsteps; }
  /* training snapshots: columns 0..2ns-1 of Xt (run 1, then run 2); test runs: X */
  if (phgmg_simulate_inputs(sys, 2, runs, &go, X, N, NULL, NULL, NULL) != PHGMG_OK)
    demo_die("full-order simulation (training runs)", PHGMG_ERR_NOT_CONVERGED);
  for (i = 1; i < DEMO_NIN; ++i) {
    phgmg_run run;
    phgmg_result rc;
    memset(&run, 0, sizeof run);
    run.u = inf[i]; run.dt = dt; run.nsteps = nsteps;
    rc = phgmg_simulate_inputs(sys, 1, &run, &go, X + (size_t)(i + 1) * N * ns, N, Y + (size_t)i * m * ns, NULL, NULL);
    if (rc != PHGMG_OK) demo_die("full-order simulation (generalization study)", rc);
  }
  for (i = 0; i < ns; ++i) phgmg_ph_output(sys, X + (size_t)i * N, Y + (size_t)i * m);   /* input 0 = run 1 */
  printf("\nGeneralization (%s): e_y on each input; trained on u = 0.1 sin t alone (1 run) or on\n"
         "0.1 sin t and 0.05 (sin 0.5t + sin 1.5t + sin 3t) (2 runs); GMG-QM with lambda_auto = 1\n"
         "  %3s %-4s %-8s %10s %10s %10s %10s %10s %5s %9s\n", example, "r", "runs", "method", demo_in_name[0],
         demo_in_name[1], demo_in_name[2], demo_in_name[3], demo_in_name[4], "fail", "lambda");
  for (k = 0; k < nr; ++k)
    for (tr = 1; tr <= 2; ++tr)
      for (me = 1; me <= 2; ++me) {
        phgmg_reduce_opts o = *base;
        phgmg_reduce_info info;
        phgmg_reduced *red = NULL;
        phgmg_result rc;
        double *row = rows + (size_t)nrow++ * DEMO_GEN_COLS, fails = 0;
        o.r = rlist[k];
        o.method = me == 1 ? PHGMG_METHOD_GMG_POD : PHGMG_METHOD_GMG_QM;
        o.select.lambda_mode = me == 2; o.nrun = tr; o.runs = runs; o.select.newton_tol = tol; o.select.newton_iter = it;
        row[0] = o.r; row[1] = tr; row[2] = me; row[10] = NAN;
        rc = phgmg_reduce(&red, sys, X, N, tr * ns, &o, &info, NULL);
        if (rc != PHGMG_OK) { fprintf(stderr, "  [%s r=%d: %s]\n", example, o.r, phgmg_result_string(rc)); for (i = 3; i < 10; ++i) row[i] = NAN; continue; }
        if (me == 2 && info.lambda < HUGE_VAL) row[10] = info.lambda;
        for (i = 0; i < DEMO_NIN; ++i) {
          phgmg_rom_stats st;
          rc = phgmg_reduced_simulate(red, xr0, 0.0, dt, nsteps, inf[i], NULL, tol, it, NULL, YR, NULL, &st, NULL);
          fails += (double)st.failures + (rc == PHGMG_ERR_NOT_CONVERGED && st.failures == 0);
          row[3 + i] = rc == PHGMG_OK ? phgmg_rel_error(m, ns, Y + (size_t)i * m * ns, m, YR, m) : NAN;
        }
        row[8] = fails; row[9] = 0;
        phgmg_reduced_destroy(red);
        printf("  %3d %-4d %-8s %10.3e %10.3e %10.3e %10.3e %10.3e %5.0f %9.2e\n", o.r, tr, me == 1 ? "GMG-POD" : "GMG-QM",
               row[3], row[4], row[5], row[6], row[7], row[8], row[10]);
      }
  snprintf(path, sizeof path, "%s/%s_generalization.csv", out, example);
  demo_write_csv(path, "r,runs,method,sin,const,sin2,chirp,pwc,newton_failures,unused,lambda", nrow, DEMO_GEN_COLS,
                 rows, 1);
  /* figure: (a) worst e_y over the four other inputs, one training run; (b)
     worst e_y over the four other inputs, 1 and 2 runs */
  for (k = 0; k < nr; ++k) {
    rx[k] = rlist[k];
    for (tr = 0; tr < 2; ++tr)
      for (me = 0; me < 2; ++me) {
        const double *row = rows + (size_t)(k * 4 + tr * 2 + me) * DEMO_GEN_COLS;
        double w = 0;
        for (i = 1; i < DEMO_NIN; ++i) w = isnan(row[3 + i]) || isnan(w) ? NAN : (row[3 + i] > w ? row[3 + i] : w);
        col[tr * 2 + me][k] = w;
      }
  }
  snprintf(title, sizeof title, "(%c) %s, trained on 0.1 sin t: worst e_y on 4 other inputs", 'a' + panel0, example);
  svgplot_panel(fig, panel0, title, "reduced order r", "relative output error e_y");
  svgplot_series(fig, panel0, "GMG-POD", nr, rx, col[0], 0 | SVGPLOT_MARKERS);
  svgplot_series(fig, panel0, "GMG-QM (lambda auto)", nr, rx, col[1], 1 | SVGPLOT_MARKERS);
  for (k = 0; k < nr; ++k) { /* held-out inputs only, one run */
    for (me = 0; me < 2; ++me) {
      const double *row = rows + (size_t)(k * 4 + me) * DEMO_GEN_COLS;
      double w = 0;
      for (i = 1; i < DEMO_NIN; ++i) w = isnan(row[3 + i]) || isnan(w) ? NAN : (row[3 + i] > w ? row[3 + i] : w);
      col[me][k] = w;
    }
  }
  snprintf(title, sizeof title, "(%c) %s: worst e_y on the 4 held-out inputs", 'a' + panel0 + 1, example);
  svgplot_panel(fig, panel0 + 1, title, "reduced order r", "relative output error e_y");
  svgplot_series(fig, panel0 + 1, "GMG-POD, 1 run", nr, rx, col[0], 0 | SVGPLOT_MARKERS);
  svgplot_series(fig, panel0 + 1, "GMG-QM, 1 run", nr, rx, col[1], 1 | SVGPLOT_MARKERS);
  svgplot_series(fig, panel0 + 1, "GMG-POD, 2 runs", nr, rx, col[2], 2 | SVGPLOT_MARKERS);
  svgplot_series(fig, panel0 + 1, "GMG-QM, 2 runs", nr, rx, col[3], 3 | SVGPLOT_MARKERS);
  printf("wrote %s (study %.2f s)\n", path, demo_now() - t_study);
  free(X); free(Y); free(YR); free(xr0); free(rows);
}
#endif
