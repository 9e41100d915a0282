/* msd_linear — paper Section 5.2, the linear mass-spring-damper chain.

   What it shows: a 100-dimensional linear pH system (50 masses, m_i = 2,
   k_i = 1, c_i = 1, force on the first mass) is simulated with the 3-stage
   Gauss-Legendre method on t in (0, 100], dt = 0.1, for u = 0.1 sin t and
   u = 0.1. From the 1001 snapshots it builds, for every reduced order r, the
   SP1-POD-ROM (Q-weighted POD, the baseline), the GMG-POD-ROM (linear map
   [B, Vbar]) and the GMG-QM-ROM (quadratic manifold, r_n = 8,
   lambda = 1e-3), simulates each reduced model with the same integrator and
   prints/writes the relative state reduction error e_red, the output error
   e_y, the projection errors e_proj of the two GMG maps and the lower bound
   of the quadratic map (paper eqs. red_error, proj_error, output_error,
   non_app_lower_bound).

   Output: results/linear_<sin|const>_<e_red|e_y|e_proj>.csv and the figure
   results/fig2_linear.svg (paper Figure 2). Options:
     --rmin R --rmax R --rstep S   reduced orders (default 4..20 step 1)
     --rn K                         GMG-QM lifting dimension (default 8)
     --lambda L                     GMG-QM ridge parameter (default 1e-3)
     --lambda auto                  the automatic-lambda study instead: GMG-POD
                                    and GMG-QM with lambda chosen by validation on
                                    held-out blocks of snapshots
                                    (phgmg_reduce_opts.select.lambda_mode); prints the
                                    chosen lambda and writes only
                                    results/linear_<sin|const>_lambda_auto.csv
                                    (r,GMG-POD,GMG-QM-auto,lambda,lowerbound,
                                    newton_failures; e_red values)
     --out DIR                      output directory (default results)  */
#define _POSIX_C_SOURCE 200809L
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "msd_models.h"
#include "demo_common.h"

#define NMETH 3
static const char *meth_name[NMETH] = {"SP1-POD", "GMG-POD", "GMG-QM"};
static const phgmg_method meth_id[NMETH] = {PHGMG_METHOD_SP1, PHGMG_METHOD_GMG_POD, PHGMG_METHOD_GMG_QM};

/* --lambda auto: GMG-POD against GMG-QM with the automatic lambda, per r. */
static int lambda_auto_study(msd_linear *M, const char *out, int rmin, int rmax, int rstep, int rn,
                             int nsteps, double dt) {
  const int N = M->sys.N;
  printf("Linear MSD, N = %d, %d steps of dt = %g; r = %d..%d; GMG-QM r_n = %d, lambda automatic\n",
         N, nsteps, dt, rmin, rmax, rn);
  demo_print_lambda_defaults("");
  {
    phgmg_reduce_opts o;
    memset(&o, 0, sizeof o);
    o.qm.rn = rn; o.dt = dt;
    demo_lambda_auto_study(&M->sys, out, "linear", rmin, rmax, rstep, &o, 1e-10, 10, nsteps, dt);
  }
  return 0;
}

int main(int argc, char **argv) {
  int rmin = 4, rmax = 20, rstep = 1, rn = 8, i, in, nr, k, lauto = 0;
  double lambda = 1e-3, t_start = demo_now();
  const char *out = "results", *gen = NULL;
  const int nsteps = 1000, ns = nsteps + 1;
  const double dt = 0.1;
  const char *inname[2] = {"sin", "const"};
  phgmg_input_fn inf[2] = {msd_input_sin, msd_input_const};
  char path[512];
  svgplot_fig *fig;
  msd_linear M;
  for (i = 1; i < argc; ++i) {
    if (!strcmp(argv[i], "--rmin") && i + 1 < argc) rmin = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--rmax") && i + 1 < argc) rmax = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--rstep") && i + 1 < argc) rstep = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--rn") && i + 1 < argc) rn = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--lambda") && i + 1 < argc && (lauto = demo_parse_lambda(argv[i + 1], &lambda)) >= 0) ++i;
    else if (!strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
    else if (!strcmp(argv[i], "--generalization") && i + 1 < argc) gen = argv[++i];
    else { fprintf(stderr, "usage: %s [--rmin R] [--rmax R] [--rstep S] [--rn K] [--lambda L|auto] [--generalization R,R,...] [--out DIR]\n", argv[0]); return 2; }
  }
  if (rmin < 2 || rmax < rmin || rstep < 1) { fprintf(stderr, "bad r range\n"); return 2; }
  nr = (rmax - rmin) / rstep + 1;
  demo_mkdir(out);
  if (msd_linear_build(&M, 50, NULL, NULL, NULL, PHGMG_DENSE) != 0) { fprintf(stderr, "model\n"); return 1; }
  if (gen) { /* --generalization: the deployment study at the listed r */
    int rl[64], nrl = 0;
    phgmg_reduce_opts o;
    svgplot_fig *gf = svgplot_new("Linear chain: GMG-POD and GMG-QM (lambda validated by simulation) on inputs they were not trained on", 2);
    nrl = demo_parse_rlist(gen, rl, 64);
    memset(&o, 0, sizeof o);
    o.qm.rn = rn; o.dt = dt;
    svgplot_size(gf, 1200, 480);
    demo_generalization_study(&M.sys, out, "linear", rl, nrl, &o, 1e-10, 10, nsteps, dt, gf, 0);
    snprintf(path, sizeof path, "%s/fig_generalization_linear.svg", out);
    if (svgplot_save(gf, path) != 0) { fprintf(stderr, "cannot write %s\n", path); return 1; }
    svgplot_free(gf);
    msd_linear_free(&M);
    printf("linear generalization demo wall time: %.2f s\n", demo_now() - t_start);
    return 0;
  }
  if (lauto) {
    int rc_all = lambda_auto_study(&M, out, rmin, rmax, rstep, rn, nsteps, dt);
    msd_linear_free(&M);
    printf("linear lambda-auto demo wall time: %.2f s\n", demo_now() - t_start);
    return rc_all;
  }
  fig = svgplot_new("Linear mass-spring-damper (paper Fig. 2): relative errors against the reduced order", 4);
  svgplot_size(fig, 1760, 480);
  printf("Linear MSD, N = %d, %d steps of dt = %g; r = %d..%d; GMG-QM r_n = %d, lambda = %g\n",
         M.sys.N, nsteps, dt, rmin, rmax, rn, lambda);
  for (in = 0; in < 2; ++in) {
    const int N = M.sys.N;
    double *X = (double *)malloc(sizeof(double) * N * ns), *Y = (double *)malloc(sizeof(double) * ns);
    double *x0 = (double *)calloc((size_t)N, sizeof(double));
    double *tred = (double *)malloc(sizeof(double) * nr * (NMETH + 1));
    double *ty = (double *)malloc(sizeof(double) * nr * (NMETH + 1));
    double *tproj = (double *)malloc(sizeof(double) * nr * 4);
    double *rx = (double *)malloc(sizeof(double) * nr), *col = (double *)malloc(sizeof(double) * nr);
    phgmg_gl3_opts go;
    phgmg_result rc;
    demo_cache cache;
    memset(&go, 0, sizeof go); go.tol = 1e-10; go.max_iter = 10;
    rc = phgmg_simulate(&M.sys, x0, 0.0, dt, nsteps, inf[in], NULL, &go, X, Y, NULL, NULL, NULL, NULL);
    if (rc != PHGMG_OK) demo_die("full-order simulation", rc);
    demo_cache_build(&cache, &M.sys, X, ns, rmax + rn + 1, 0);
    printf("\nu = %s\n  %3s  %-22s %-22s %-22s %-11s %-11s %-11s\n", in ? "0.1" : "0.1 sin t", "r",
           "SP1-POD e_red / e_y", "GMG-POD e_red / e_y", "GMG-QM e_red / e_y", "proj POD", "proj QM", "lowerbound");
    for (k = 0; k < nr; ++k) {
      const int r = rmin + k * rstep;
      int j;
      rx[k] = r;
      tred[k * (NMETH + 1)] = ty[k * (NMETH + 1)] = tproj[k * 4] = r;
      tproj[k * 4 + 1] = tproj[k * 4 + 2] = tproj[k * 4 + 3] = NAN;
      printf("  %3d", r);
      for (j = 0; j < NMETH; ++j) {
        phgmg_reduce_opts o;
        demo_rom_result res;
        memset(&o, 0, sizeof o);
        o.method = meth_id[j]; o.r = r; o.qm.rn = rn; o.qm.lambda = lambda; o.dt = dt;
        demo_cache_use(&cache, &o);
        res = demo_run_rom(&cache, &M.sys, X, Y, nsteps, dt, inf[in], &o, 1e-10, 10, NULL);
        if (res.rc != PHGMG_OK) fprintf(stderr, "  [%s r=%d: %s]\n", meth_name[j], r, phgmg_result_string(res.rc));
        tred[k * (NMETH + 1) + 1 + j] = res.e_red;
        ty[k * (NMETH + 1) + 1 + j] = res.e_y;
        if (meth_id[j] == PHGMG_METHOD_GMG_POD) tproj[k * 4 + 1] = res.e_proj;
        if (meth_id[j] == PHGMG_METHOD_GMG_QM) { tproj[k * 4 + 2] = res.e_proj; tproj[k * 4 + 3] = res.e_lower; }
        printf("  %9.3e / %9.3e", res.e_red, res.e_y);
      }
      printf("  %9.3e  %9.3e  %9.3e\n", tproj[k * 4 + 1], tproj[k * 4 + 2], tproj[k * 4 + 3]);
    }
    demo_tables_and_panels(out, "linear", inname[in], in, "r,SP1-POD,GMG-POD,GMG-QM", meth_name, NMETH, nr, rx,
                           tred, ty, tproj, fig);
    demo_cache_free(&cache);
    free(X); free(Y); free(x0); free(tred); free(ty); free(tproj); free(rx); free(col);
  }
  snprintf(path, sizeof path, "%s/fig2_linear.svg", out);
  if (svgplot_save(fig, path) != 0) { fprintf(stderr, "cannot write %s\n", path); return 1; }
  svgplot_free(fig);
  msd_linear_free(&M);
  printf("\nwrote %s/linear_*.csv and %s\nlinear demo wall time: %.2f s\n", out, path, demo_now() - t_start);
  return 0;
}
