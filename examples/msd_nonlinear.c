/* msd_nonlinear — paper Section 5.3, the nonlinear mass-spring-damper chain.

   What it shows: a chain of n = 500 masses with nonlinear springs
   k1 + k2 l^2 (H has the quartic terms l^4/4) and dampers gamma = 0.3, in the
   transformed coordinates l_i = xi_i - xi_{i+1} (N = 1000; stored banded in
   the interleaved order l1, v1, l2, v2, ...), simulated with Gauss-Legendre-3
   and Newton (tol 1e-8, 20 iterations) on t in (0, 100], dt = 0.1, for
   u = 0.1 sin t and u = 0.1. For each reduced order r it builds the
   SP2-POD-ROM (gradient-POD baseline), the GMG-POD-ROM and the GMG-QM-ROM
   (r_n = 8, lambda = max(0.2 e_proj(r), 10^-2.5) with e_proj the projection
   error of the linear GMG map), all with structure-preserving DEIM for the
   quartic part (modes with sigma_k/sigma_1 > 1e-8), simulates them and
   reports e_red, e_y, e_proj, the lower bound, and at r = 16 the energy-
   balance error e_energy(t) of the FOM and the ROMs (stage quadrature).

   Output: results/nonlinear_<sin|const>_<e_red|e_y|e_proj|energy>.csv,
   results/fig3_nonlinear.svg and results/fig4_energy.svg (paper Figs. 3, 4).
   Options:
     --n N            masses (default 500)        --mass M     mass (default 1)
     --rmin/--rmax/--rstep   orders (default 6..20 step 2)
     --rn K           GMG-QM lifting dimension (default 8)
     --lambda L       fixed GMG-QM ridge parameter (default: the rule above)
     --lambda auto    the automatic-lambda study instead: GMG-POD and GMG-QM
                      with lambda chosen by validation on held-out blocks of
                      snapshots (phgmg_reduce_opts.select.lambda_mode); writes only
                      results/nonlinear_<sin|const>_lambda_auto.csv
                      (r,GMG-POD,GMG-QM-auto,lambda,lowerbound,newton_failures)
     --deim-tol T     DEIM tolerance (default 1e-8)
     --renergy R      order of the energy study (default 16)
     --out DIR        output directory (default results)  */
#define _POSIX_C_SOURCE 200809L
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "msd_models.h"
#include "demo_common.h"

#define NMETH 3
static const char *meth_name[NMETH] = {"SP2-POD", "GMG-POD", "GMG-QM"};
static const phgmg_method meth_id[NMETH] = {PHGMG_METHOD_SP2, PHGMG_METHOD_GMG_POD, PHGMG_METHOD_GMG_QM};

/* --lambda auto: GMG-POD against GMG-QM with the automatic lambda, per r
   (both with structure-preserving DEIM as in the paper tables). */
static int lambda_auto_study(msd_nonlinear *M, const char *out, int rmin, int rmax, int rstep, int rn,
                             double deim_tol, int nsteps, double dt) {
  const int N = M->sys.N;
  printf("Nonlinear MSD, N = %d, %d steps of dt = %g; r = %d..%d step %d; GMG-QM r_n = %d, lambda automatic\n",
         N, nsteps, dt, rmin, rmax, rstep, rn);
  {
    char tail[64];
    snprintf(tail, sizeof tail, "; DEIM tol %g", deim_tol);
    demo_print_lambda_defaults(tail);
  }
  {
    phgmg_reduce_opts o;
    memset(&o, 0, sizeof o);
    o.qm.rn = rn; o.hyper.on = 1; o.hyper.deim_tol = deim_tol; o.hyper.allow_negative = 1;
    demo_lambda_auto_study(&M->sys, out, "nonlinear", rmin, rmax, rstep, &o, 1e-8, 20, nsteps, dt);
  }
  return 0;
}

/* The settings of a run (command line) and the model. */
typedef struct nl_setup {
  msd_nonlinear M;
  const char *out;
  int n, rmin, rmax, rstep, nr, rn, renergy, nsteps;
  double mass, lambda_fixed, deim_tol, dt;
} nl_setup;

/* --generalization: the deployment study at the listed r */
static int generalization_main(nl_setup *S, const char *gen) {
  int rl[64], nrl = 0;
  char path[512];
  phgmg_reduce_opts o;
  svgplot_fig *gf = svgplot_new("Nonlinear chain: GMG-POD and GMG-QM (lambda validated by simulation) on inputs they were not trained on", 2);
  nrl = demo_parse_rlist(gen, rl, 64);
  memset(&o, 0, sizeof o);
  o.qm.rn = S->rn; o.hyper.on = 1; o.hyper.deim_tol = S->deim_tol; o.hyper.allow_negative = 1;
  svgplot_size(gf, 1200, 480);
  demo_generalization_study(&S->M.sys, S->out, "nonlinear", rl, nrl, &o, 1e-8, 20, S->nsteps, S->dt, gf, 0);
  snprintf(path, sizeof path, "%s/fig_generalization_nonlinear.svg", S->out);
  if (svgplot_save(gf, path) != 0) { fprintf(stderr, "cannot write %s\n", path); return 1; }
  svgplot_free(gf);
  return 0;
}

/* Per-input result arrays of the paper study (rows of the CSVs). */
typedef struct nl_tables {
  double *tred, *ty, *tproj, *rx;   /* nr x (NMETH + 1), nr x (NMETH + 1), nr x 4, nr */
  double *eng, *ecol, *tt;          /* ns x (NMETH + 2), ns, ns: energy-balance errors */
} nl_tables;

/* One reduced order (row k, r) of the paper tables: the three methods on the
   snapshots X of input u, with the energy study at r = renergy. */
static void paper_order(nl_setup *S, demo_cache *cache, const double *X, const double *Y, phgmg_input_fn u, int k,
                        nl_tables *T) {
  const int r = S->rmin + k * S->rstep, ns = S->nsteps + 1;
  double lam = S->lambda_fixed;
  int ndeim = 0, nneg = 0, i, j;
  T->rx[k] = r;
  T->tred[k * (NMETH + 1)] = T->ty[k * (NMETH + 1)] = T->tproj[k * 4] = r;
  T->tproj[k * 4 + 1] = T->tproj[k * 4 + 2] = T->tproj[k * 4 + 3] = NAN;
  printf("  %3d", r);
  for (j = 0; j < NMETH; ++j) {
    phgmg_reduce_opts o;
    demo_rom_result res;
    phgmg_energy ren;
    double *REH = NULL;
    memset(&o, 0, sizeof o);
    o.method = meth_id[j]; o.r = r; o.qm.rn = S->rn; o.hyper.on = 1; o.hyper.deim_tol = S->deim_tol; o.hyper.allow_negative = 1;
    if (meth_id[j] == PHGMG_METHOD_GMG_QM) {
      if (!(lam > 0)) lam = fmax(0.2 * T->tproj[k * 4 + 1], pow(10.0, -2.5));
      o.qm.lambda = lam;
    }
    demo_cache_use(cache, &o);
    if (r == S->renergy) {
      REH = (double *)malloc(sizeof(double) * 3 * ns);
      ren.H = REH; ren.S = REH + ns; ren.D = REH + 2 * ns;
    }
    res = demo_run_rom(cache, &S->M.sys, X, Y, S->nsteps, S->dt, u, &o, 1e-8, 20, REH ? &ren : NULL);
    if (res.rc != PHGMG_OK) fprintf(stderr, "  [%s r=%d: %s]\n", meth_name[j], r, phgmg_result_string(res.rc));
    if (REH) {
      if (res.rc == PHGMG_OK) {
        phgmg_err_energy(&ren, S->nsteps, T->ecol);
        for (i = 0; i < ns; ++i) T->eng[i * (NMETH + 2) + 2 + j] = T->ecol[i];
      }
      free(REH);
    }
    T->tred[k * (NMETH + 1) + 1 + j] = res.e_red;
    T->ty[k * (NMETH + 1) + 1 + j] = res.e_y;
    if (meth_id[j] == PHGMG_METHOD_GMG_POD) T->tproj[k * 4 + 1] = res.e_proj;
    if (meth_id[j] == PHGMG_METHOD_GMG_QM) { T->tproj[k * 4 + 2] = res.e_proj; T->tproj[k * 4 + 3] = res.e_lower; }
    if (res.info.deim_modes > ndeim) ndeim = res.info.deim_modes;
    nneg += res.info.deim_negative;
    printf("  %9.3e / %9.3e", res.e_red, res.e_y);
  }
  printf("  %9.3e  %9.3e  %9.3e  %.2e, %d%s\n", T->tproj[k * 4 + 1], T->tproj[k * 4 + 2], T->tproj[k * 4 + 3], lam,
         ndeim, nneg ? " (negative weights!)" : "");
}

/* Panel `in` of the energy figure (paper Fig. 4): e_energy(t) of the FOM and the ROMs. */
static void energy_panel(svgplot_fig *fige, int in, int renergy, int ns, nl_tables *T) {
  static const char *en_name[4] = {"FOM", "SP2-POD", "GMG-POD", "GMG-QM"};
  static const int en_style[4] = {3, 0, 1, 2};
  char title[128];
  int i, j;
  snprintf(title, sizeof title, "(%c) u = %s, r = %d", 'a' + in, in ? "0.1" : "0.1 sin t", renergy);
  svgplot_panel(fige, in, title, "time t", "e_energy(t)");
  for (j = 0; j < NMETH + 1; ++j) {
    for (i = 0; i < ns; ++i) T->ecol[i] = T->eng[i * (NMETH + 2) + 1 + j];
    svgplot_series(fige, in, en_name[j], ns, T->tt, T->ecol, en_style[j]);
  }
}

/* One input of the paper study (in = 0: u = 0.1 sin t, 1: u = 0.1): the FOM
   with its energy balance, every order, the CSVs and figure panels. */
static void paper_input(nl_setup *S, int in, svgplot_fig *fig, svgplot_fig *fige) {
  static const char *inname[2] = {"sin", "const"};
  static phgmg_input_fn inf[2] = {msd_input_sin, msd_input_const};
  const int N = S->M.sys.N, ns = S->nsteps + 1, nr = S->nr;
  double *X = (double *)malloc(sizeof(double) * N * ns), *Y = (double *)malloc(sizeof(double) * ns);
  double *x0 = (double *)calloc((size_t)N, sizeof(double));
  double *EH = (double *)malloc(sizeof(double) * 3 * ns), t0 = demo_now();
  nl_tables T;
  phgmg_energy en;
  phgmg_gl3_opts go;
  phgmg_gl3_stats gs;
  phgmg_result rc;
  demo_cache cache;
  char path[512];
  int k, j;
  T.tred = (double *)malloc(sizeof(double) * nr * (NMETH + 1));
  T.ty = (double *)malloc(sizeof(double) * nr * (NMETH + 1));
  T.tproj = (double *)malloc(sizeof(double) * nr * 4);
  T.rx = (double *)malloc(sizeof(double) * nr);
  T.eng = (double *)malloc(sizeof(double) * ns * (NMETH + 2));
  T.ecol = (double *)malloc(sizeof(double) * ns); T.tt = (double *)malloc(sizeof(double) * ns);
  if (!X || !Y || !x0 || !EH || !T.tred || !T.ty || !T.tproj || !T.rx || !T.eng || !T.ecol || !T.tt)
    demo_die("allocation", PHGMG_ERR_NOMEM);
  en.H = EH; en.S = EH + ns; en.D = EH + 2 * ns;
  memset(&go, 0, sizeof go); go.tol = 1e-8; go.max_iter = 20;
  rc = phgmg_simulate(&S->M.sys, x0, 0.0, S->dt, S->nsteps, inf[in], NULL, &go, X, Y, &en, &gs, NULL, NULL);
  if (rc != PHGMG_OK) demo_die("full-order simulation", rc);
  phgmg_err_energy(&en, S->nsteps, T.ecol);
  for (k = 0; k < ns; ++k) {
    T.eng[k * (NMETH + 2)] = T.tt[k] = k * S->dt;
    T.eng[k * (NMETH + 2) + 1] = T.ecol[k];
    for (j = 0; j < NMETH; ++j) T.eng[k * (NMETH + 2) + 2 + j] = NAN;
  }
  printf("\nu = %s: FOM %.3f s (%ld Newton iterations, %ld factorizations), max e_energy %.2e\n",
         in ? "0.1" : "0.1 sin t", demo_now() - t0, gs.newton_iters, gs.factorizations, T.ecol[S->nsteps]);
  demo_cache_build(&cache, &S->M.sys, X, ns, S->rmax + S->rn + 1, 1);
  demo_cache_deim(&cache, &S->M.sys, X, ns, S->deim_tol);
  printf("  %3s  %-22s %-22s %-22s %-10s %-10s %-10s %s\n", "r", "SP2-POD e_red / e_y",
         "GMG-POD e_red / e_y", "GMG-QM e_red / e_y", "proj POD", "proj QM", "lowerbnd", "lambda, DEIM pts");
  for (k = 0; k < nr; ++k) paper_order(S, &cache, X, Y, inf[in], k, &T);
  demo_tables_and_panels(S->out, "nonlinear", inname[in], in, "r,SP2-POD,GMG-POD,GMG-QM", meth_name, NMETH, nr,
                         T.rx, T.tred, T.ty, T.tproj, fig);
  snprintf(path, sizeof path, "%s/nonlinear_%s_energy.csv", S->out, inname[in]);
  demo_write_csv(path, "t,FOM,SP2-POD,GMG-POD,GMG-QM", ns, NMETH + 2, T.eng, 0);
  energy_panel(fige, in, S->renergy, ns, &T);
  demo_cache_free(&cache);
  free(X); free(Y); free(x0); free(EH);
  free(T.tred); free(T.ty); free(T.tproj); free(T.rx); free(T.eng); free(T.ecol); free(T.tt);
}

/* The paper tables and Figs. 3 and 4 (both inputs). */
static int paper_main(nl_setup *S) {
  char path[512];
  int in;
  svgplot_fig *fig = svgplot_new("Nonlinear mass-spring-damper (paper Fig. 3): relative errors against the reduced order", 4);
  svgplot_fig *fige = svgplot_new("Energy-balance error e_energy(t) (paper Fig. 4)", 2);
  svgplot_size(fig, 1760, 480);
  printf("Nonlinear MSD, n = %d masses (N = %d), mass %g, %d steps of dt = %g; r = %d..%d step %d;\n"
         "GMG-QM r_n = %d, lambda = %s; DEIM tol %g\n", S->n, S->M.sys.N, S->mass, S->nsteps, S->dt,
         S->rmin, S->rmax, S->rstep, S->rn, S->lambda_fixed > 0 ? "fixed" : "max(0.2 e_proj, 10^-2.5)", S->deim_tol);
  for (in = 0; in < 2; ++in) paper_input(S, in, fig, fige);
  snprintf(path, sizeof path, "%s/fig3_nonlinear.svg", S->out);
  if (svgplot_save(fig, path) != 0) { fprintf(stderr, "cannot write %s\n", path); return 1; }
  snprintf(path, sizeof path, "%s/fig4_energy.svg", S->out);
  if (svgplot_save(fige, path) != 0) { fprintf(stderr, "cannot write %s\n", path); return 1; }
  svgplot_free(fig);
  svgplot_free(fige);
  printf("\nwrote %s/nonlinear_*.csv, %s/fig3_nonlinear.svg, %s/fig4_energy.svg\n", S->out, S->out, S->out);
  return 0;
}

int main(int argc, char **argv) {
  int i, lauto = 0, rc;
  double t_start = demo_now();
  const char *gen = NULL;
  nl_setup S;
  msd_nl_opts mo;
  memset(&S, 0, sizeof S);
  S.n = 500; S.mass = 1.0; S.out = "results"; S.rmin = 6; S.rmax = 20; S.rstep = 2; S.rn = 8; S.renergy = 16; S.deim_tol = 1e-8;
  S.nsteps = 1000; S.dt = 0.1;
  for (i = 1; i < argc; ++i) {
    if (!strcmp(argv[i], "--n") && i + 1 < argc) S.n = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--mass") && i + 1 < argc) S.mass = atof(argv[++i]);
    else if (!strcmp(argv[i], "--rmin") && i + 1 < argc) S.rmin = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--rmax") && i + 1 < argc) S.rmax = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--rstep") && i + 1 < argc) S.rstep = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--rn") && i + 1 < argc) S.rn = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--lambda") && i + 1 < argc && (lauto = demo_parse_lambda(argv[i + 1], &S.lambda_fixed)) >= 0) ++i;
    else if (!strcmp(argv[i], "--deim-tol") && i + 1 < argc) S.deim_tol = atof(argv[++i]);
    else if (!strcmp(argv[i], "--renergy") && i + 1 < argc) S.renergy = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--out") && i + 1 < argc) S.out = argv[++i];
    else if (!strcmp(argv[i], "--generalization") && i + 1 < argc) gen = argv[++i];
    else {
      fprintf(stderr, "usage: %s [--n N] [--mass M] [--rmin R] [--rmax R] [--rstep S] [--rn K] [--lambda L|auto] [--generalization R,R,...]\n"
                      "          [--deim-tol T] [--renergy R] [--out DIR]\n", argv[0]);
      return 2;
    }
  }
  if (S.rmin < 2 || S.rmax < S.rmin || S.rstep < 1 || S.n < 4) { fprintf(stderr, "bad arguments\n"); return 2; }
  S.nr = (S.rmax - S.rmin) / S.rstep + 1;
  demo_mkdir(S.out);
  memset(&mo, 0, sizeof mo);
  mo.n = S.n; mo.mass = S.mass; mo.storage = PHGMG_BANDED;
  if (msd_nonlinear_build(&S.M, &mo) != 0) { fprintf(stderr, "model\n"); return 1; }
  if (gen) rc = generalization_main(&S, gen);
  else if (lauto) rc = lambda_auto_study(&S.M, S.out, S.rmin, S.rmax, S.rstep, S.rn, S.deim_tol, S.nsteps, S.dt);
  else rc = paper_main(&S);
  msd_nonlinear_free(&S.M);
  printf("nonlinear %sdemo wall time: %.2f s\n", gen ? "generalization " : lauto ? "lambda-auto " : "",
         demo_now() - t_start);
  return rc;
}
