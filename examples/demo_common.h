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

/* Reduce `sys` from snapshots X (N x ns) with `opts`, simulate the ROM from
   rho(x0) with the FOM's input, and measure e_red, e_y (against the FOM's
   output Y), e_proj and (GMG-QM) e_lowerbound. If energy is non-NULL it gets
   the ROM's energy bookkeeping. */
DEMO_FN demo_rom_result demo_run_rom(const phgmg_ph_system *sys, const double *X, const double *Y,
                                    int nsteps, double dt, phgmg_input_fn uf,
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
  res.rc = phgmg_reduce(&red, sys, X, N, ns, opts, &res.info, NULL);
  res.t_offline = demo_now() - t0;
  if (res.rc != PHGMG_OK) return res;
  XR = (double *)malloc(sizeof(double) * (size_t)r * ns);
  YR = (double *)malloc(sizeof(double) * (size_t)m * ns);
  xr0 = (double *)malloc(sizeof(double) * (size_t)r);
  if (!XR || !YR || !xr0) { fprintf(stderr, "out of memory\n"); exit(1); }
  phgmg_reduced_restrict(red, X, xr0);     /* rho(x0) (NUMERICS 6.7) */
  t0 = demo_now();
  res.rc = phgmg_reduced_simulate(red, xr0, 0.0, dt, nsteps, uf, NULL, newton_tol, newton_it, XR, YR,
                                  energy, &res.stats, NULL);
  res.t_online = demo_now() - t0;
  if (res.rc == PHGMG_OK) {
    res.e_red = phgmg_err_red(red, X, N, ns, XR, r);
    res.e_y = phgmg_rel_error(m, ns, Y, m, YR, m);
  }
  res.e_proj = phgmg_err_proj(red, X, N, ns);
  if (opts->method == PHGMG_METHOD_GMG_QM) res.e_lower = phgmg_err_lowerbound(red, X, N, ns);
  free(XR); free(YR); free(xr0);
  phgmg_reduced_destroy(red);
  return res;
}

/* POD bases computed once per snapshot set and shared by every r and method
   (phgmg_reduce_opts.pod_basis / grad_basis). */
typedef struct demo_cache {
  double *adj, *plain, *grad, *deim_w;
  int adj_cols, plain_cols, grad_cols, *deim_pts, deim_count;
} demo_cache;

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

DEMO_FN void demo_cache_build(demo_cache *c, const phgmg_ph_system *sys, const double *X, int ns, int kmax,
                             int want_grad) {
  const int N = sys->N;
  double *T = (double *)malloc(sizeof(double) * (size_t)N * ns);
  phgmg_result rc;
  int j;
  memset(c, 0, sizeof *c);
  c->adj = (double *)malloc(sizeof(double) * (size_t)N * kmax);
  c->plain = (double *)malloc(sizeof(double) * (size_t)N * kmax);
  if (!T || !c->adj || !c->plain) { fprintf(stderr, "out of memory\n"); exit(1); }
  rc = phgmg_adjust_snapshots(N, sys->m, sys->B, ns, X, N, T, N, NULL);
  if (rc == PHGMG_OK) rc = phgmg_pod(N, ns, T, N, kmax, 0.0, c->adj, N, NULL, &c->adj_cols, NULL);
  if (rc == PHGMG_OK) rc = phgmg_pod(N, ns, X, N, kmax, 0.0, c->plain, N, NULL, &c->plain_cols, NULL);
  if (rc == PHGMG_OK && want_grad) {
    c->grad = (double *)malloc(sizeof(double) * (size_t)N * kmax);
    if (!c->grad) { fprintf(stderr, "out of memory\n"); exit(1); }
    for (j = 0; j < ns; ++j) phgmg_ph_gradient(sys, X + (size_t)j * N, T + (size_t)j * N);
    rc = phgmg_pod(N, ns, T, N, kmax, 0.0, c->grad, N, NULL, &c->grad_cols, NULL);
  }
  if (rc != PHGMG_OK) demo_die("POD of the snapshots", rc);
  free(T);
}
DEMO_FN void demo_cache_free(demo_cache *c) { free(c->adj); free(c->plain); free(c->grad); free(c->deim_pts); free(c->deim_w); }
DEMO_FN void demo_cache_use(const demo_cache *c, phgmg_reduce_opts *o) {
  o->deim_pts = c->deim_pts; o->deim_w = c->deim_w; o->deim_count = c->deim_count;
  if (o->method == PHGMG_METHOD_GMG_POD || o->method == PHGMG_METHOD_GMG_QM) {
    o->pod_basis = c->adj; o->pod_cols = c->adj_cols;
  } else {
    o->pod_basis = c->plain; o->pod_cols = c->plain_cols;
    o->grad_basis = c->grad; o->grad_cols = c->grad_cols;
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
   (phgmg_reduce_opts.lambda_auto with the default grid and folds). Returns
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

/* The automatic-lambda study of one example and input: rows
   "r, GMG-POD e_red, GMG-QM-auto e_red, lambda chosen, e_lowerbound, Newton
   failures" (nr x 6, row-major) into <out>/<example>_<input>_lambda_auto.csv. */
DEMO_FN void demo_write_lambda_auto(const char *out, const char *example, const char *input, int nr,
                                    const double *rows) {
  char path[512];
  snprintf(path, sizeof path, "%s/%s_%s_lambda_auto.csv", out, example, input);
  demo_write_csv(path, "r,GMG-POD,GMG-QM-auto,lambda,lowerbound,newton_failures", nr, 6, rows, 1);
}

/* Newton failures of one reduced simulation: the stepper's count, at least 1
   when the simulation stopped on PHGMG_ERR_NOT_CONVERGED. */
DEMO_FN double demo_newton_failures(const demo_rom_result *res) {
  long f = res->stats.failures;
  if (res->rc == PHGMG_ERR_NOT_CONVERGED && f < 1) f = 1;
  return (double)f;
}

/* One row of the automatic-lambda study at order `base->r`: GMG-POD and
   GMG-QM with lambda_auto (both with the other settings of `base`), the row
   "r, GMG-POD e_red, GMG-QM-auto e_red, lambda, e_lowerbound, Newton
   failures" into row[6], and one line on the terminal. */
DEMO_FN void demo_lambda_auto_row(const phgmg_ph_system *sys, const double *X, const double *Y, int nsteps,
                                  double dt, phgmg_input_fn uf, const demo_cache *cache,
                                  const phgmg_reduce_opts *base, double newton_tol, int newton_it, double *row) {
  phgmg_reduce_opts o = *base;
  demo_rom_result res;
  o.method = PHGMG_METHOD_GMG_POD; o.lambda_auto = 0;
  demo_cache_use(cache, &o);
  res = demo_run_rom(sys, X, Y, nsteps, dt, uf, &o, newton_tol, newton_it, NULL);
  if (res.rc != PHGMG_OK) fprintf(stderr, "  [GMG-POD r=%d: %s]\n", o.r, phgmg_result_string(res.rc));
  row[0] = o.r; row[1] = res.e_red;
  o = *base;
  o.method = PHGMG_METHOD_GMG_QM; o.lambda_auto = 1;
  demo_cache_use(cache, &o);
  res = demo_run_rom(sys, X, Y, nsteps, dt, uf, &o, newton_tol, newton_it, NULL);
  if (res.rc != PHGMG_OK) fprintf(stderr, "  [GMG-QM r=%d: %s]\n", o.r, phgmg_result_string(res.rc));
  row[2] = res.e_red; row[3] = res.info.lambda > 0.0 ? res.info.lambda : NAN; row[4] = res.e_lower;
  row[5] = demo_newton_failures(&res);
  printf("  %3d  %9.3e  %9.3e  %6.2f  %8.2e%-3s %8.2e  %9.3e  %6.2f  %.0f\n", o.r, row[1], row[2], row[1] / row[2],
         row[3], res.info.lambda_raised ? " +" : "", res.info.lambda_cv_err, row[4], row[2] / row[4], row[5]);
}

DEMO_FN void demo_lambda_auto_header(const char *input) {
  printf("\nu = %s  (lambda: + = raised by the conditioning guard)\n  %3s  %-10s %-10s %-7s %-11s %-9s %-10s %-7s %s\n",
         input, "r", "GMG-POD", "QM-auto", "ratio", "lambda", "val.err", "lowerbnd", "QM/lb", "Newton failures");
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
    double *rows = (double *)malloc(sizeof(double) * nr * 6);
    phgmg_gl3_opts go;
    phgmg_result rc;
    demo_cache cache;
    if (!X || !Y || !x0 || !rows) { fprintf(stderr, "out of memory\n"); exit(1); }
    memset(&go, 0, sizeof go); go.tol = newton_tol; go.max_iter = newton_it;
    rc = phgmg_simulate(sys, x0, 0.0, dt, nsteps, inf[in], NULL, &go, X, Y, NULL, NULL, NULL, NULL);
    if (rc != PHGMG_OK) demo_die("full-order simulation", rc);
    demo_cache_build(&cache, sys, X, ns, rmax + base->rn + 1, 0);
    if (base->deim) demo_cache_deim(&cache, sys, X, ns, base->deim_tol);
    demo_lambda_auto_header(in ? "0.1" : "0.1 sin t");
    for (k = 0; k < nr; ++k) {
      phgmg_reduce_opts o = *base;
      o.r = rmin + k * rstep;
      demo_lambda_auto_row(sys, X, Y, nsteps, dt, inf[in], &cache, &o, newton_tol, newton_it, rows + k * 6);
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
#endif
