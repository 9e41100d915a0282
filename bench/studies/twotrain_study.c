/* twotrain_study.c -- why two training runs (0.1 sin t + the multisine
   0.05 (sin 0.5t + sin 1.5t + sin 3t)) can be worse than one (0.1 sin t) on
   held-out inputs at small r. For GMG-POD on the chosen chain, with
   every nonlinear term (deim 0) and with ECSW hyper-reduction (deim 1), per
   held-out input (0.1, 0.1 sin 2t, chirp, random pwc): e_proj of the held-out
   trajectory onto the model's basis (what the basis can represent at all)
   and e_y of the reduced model; 1 run vs 2 runs; a last summary line counts
   the (r, input) pairs and orders where the second run lowered e_y (deim 0).
   Usage: twotrain_study linear|nonlinear [--r 6,7,8,10,12] [--balance] [--second multisine|steps|mssteps]
   (--balance: run 2 scaled to run 1's norm before the POD; linear chain or deim 0 only) */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#define PHGMG_IMPLEMENTATION
#include "../../phgmg.h"
#include "../../examples/msd_models.h"
#include "../../examples/demo_common.h"

/* the inputs of make demo's generalization study (examples/demo_common.h),
   and two more candidates for the second training run */
/* random steps: another hash and hold time than the held-out pwc (7 s, not 5 s) */
static void u_steps(double t, double *u, void *p) {
  unsigned k = (unsigned)(t / 7.0) + 977u, h = k * 2246822519u;
  (void)p;
  h ^= h >> 15; h *= 0x85ebca6bu; h ^= h >> 13;
  u[0] = 0.1 * (2.0 * (double)(h % 10000u) / 9999.0 - 1.0);
}
/* half the multisine plus half the random steps: the band and the static content */
static void u_mssteps(double t, double *u, void *p) {
  double a, b;
  demo_u_multisine(t, &a, p); u_steps(t, &b, p);
  u[0] = 0.5 * (a + b);
}
#define NHO 4
static phgmg_input_fn ho[NHO] = {msd_input_const, demo_u_sin2, demo_u_chirp, demo_u_pwc};
static const char *hon[NHO] = {"0.1", "sin 2t", "chirp", "pwc"};

int main(int argc, char **argv) {
  const int nsteps = 1000, ns = nsteps + 1;
  const double dt = 0.1;
  int rl[64], nr = 0, i, k, tr, dm, nonlin, N, balance = 0, nimp = 0, ncmp = 0, ngm = 0;
  double ey2[64][2][NHO], lsum = 0;   /* e_y without hyper-reduction, 1 and 2 runs */
  phgmg_input_fn second = demo_u_multisine;
  const char *rs = "6,7,8,10,12";
  double tol = 1e-10, *X, *Y, *YR, xr0[64] = {0};
  msd_linear L;
  msd_nonlinear NL;
  const phgmg_ph_system *sys;
  phgmg_run runs[2];
  phgmg_gl3_opts go;
  if (argc < 2 || (strcmp(argv[1], "linear") && strcmp(argv[1], "nonlinear"))) {
    fprintf(stderr, "usage: %s linear|nonlinear [--r LIST] [--balance] [--second multisine|steps|mssteps]\n", argv[0]);
    return argc >= 2 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) ? 0 : 2;
  }
  for (k = 0; k < 64; ++k)
    for (i = 0; i < 2 * NHO; ++i) ey2[k][i / NHO][i % NHO] = NAN;
  nonlin = !strcmp(argv[1], "nonlinear");
  for (i = 2; i < argc; ++i) {
    if (!strcmp(argv[i], "--r") && i + 1 < argc) rs = argv[++i];
    else if (!strcmp(argv[i], "--balance")) balance = 1;
    else if (!strcmp(argv[i], "--second") && i + 1 < argc) {
      ++i;
      second = !strcmp(argv[i], "steps") ? u_steps : !strcmp(argv[i], "mssteps") ? u_mssteps : demo_u_multisine;
    } else { fprintf(stderr, "twotrain_study: unknown argument '%s'\n", argv[i]); return 2; }
  }
  nr = demo_parse_rlist(rs, rl, 64);
  if (nonlin) {
    msd_nl_opts mo;
    memset(&mo, 0, sizeof mo);
    mo.n = 500; mo.storage = PHGMG_BANDED;
    if (msd_nonlinear_build(&NL, &mo) != 0) return 1;
    sys = &NL.sys; tol = 1e-8;
  } else {
    if (msd_linear_build(&L, 50, NULL, NULL, NULL, PHGMG_DENSE) != 0) return 1;
    sys = &L.sys;
  }
  N = sys->N;
  X = (double *)malloc(sizeof(double) * (size_t)N * ns * (2 + NHO));
  Y = (double *)malloc(sizeof(double) * (size_t)ns * (2 + NHO));
  YR = (double *)malloc(sizeof(double) * ns);
  if (!X || !Y || !YR) return 1;
  memset(&go, 0, sizeof go); go.tol = tol; go.max_iter = 20;
  memset(runs, 0, sizeof runs);
  for (i = 0; i < 2; ++i) { runs[i].u = i ? second : msd_input_sin; runs[i].dt = dt; runs[i].nsteps = nsteps; }
  if (phgmg_simulate_inputs(sys, 2, runs, &go, X, N, Y, NULL, NULL) != PHGMG_OK) return 1;
  for (i = 0; i < NHO; ++i) {
    phgmg_run run;
    memset(&run, 0, sizeof run);
    run.u = ho[i]; run.dt = dt; run.nsteps = nsteps;
    if (phgmg_simulate_inputs(sys, 1, &run, &go, X + (size_t)(2 + i) * N * ns, N, Y + (size_t)(2 + i) * ns, NULL, NULL) != PHGMG_OK) return 1;
  }
  if (balance) {   /* scale run 2 to the Frobenius norm of run 1 (equal weight in the POD) */
    double n1 = 0, n2 = 0;
    for (i = 0; i < N * ns; ++i) { n1 += X[i] * X[i]; n2 += X[(size_t)N * ns + i] * X[(size_t)N * ns + i]; }
    printf("run norms: sin %.4g, multisine %.4g; run 2 scaled by %.4g\n", sqrt(n1), sqrt(n2), sqrt(n1 / n2));
    for (i = 0; i < N * ns; ++i) X[(size_t)N * ns + i] *= sqrt(n1 / n2);
  }
  printf("%s chain, GMG-POD; per held-out input: e_proj of its trajectory onto the basis / e_y\n", nonlin ? "nonlinear" : "linear");
  printf("%3s %4s %4s", "r", "runs", "deim");
  for (i = 0; i < NHO; ++i) printf(" %9s-proj %9s-e_y", hon[i], hon[i]);
  printf(" %8s\n", "ecsw_pts");
  for (k = 0; k < nr; ++k)
    for (dm = 0; dm <= nonlin; ++dm)
      for (tr = 1; tr <= 2; ++tr) {
        phgmg_reduce_opts o;
        phgmg_reduce_info info;
        phgmg_reduced *red = NULL;
        phgmg_result rc;
        memset(&o, 0, sizeof o);
        o.method = PHGMG_METHOD_GMG_POD; o.r = rl[k]; o.hyper.on = nonlin && dm; o.hyper.deim_tol = 1e-8; o.hyper.allow_negative = 1;
        rc = phgmg_reduce(&red, sys, X, N, tr * ns, &o, &info, NULL);
        if (rc != PHGMG_OK) { printf("%3d %4d reduce: %s\n", o.r, tr, phgmg_result_string(rc)); continue; }
        printf("%3d %4d %4d", o.r, tr, o.hyper.on);
        for (i = 0; i < NHO; ++i) {
          const double *Xi = X + (size_t)(2 + i) * N * ns;
          double ey;
          rc = phgmg_reduced_simulate(red, xr0, 0.0, dt, nsteps, ho[i], NULL, tol, 20, NULL, YR, NULL, NULL, NULL);
          ey = rc == PHGMG_OK ? phgmg_rel_error(1, ns, Y + (size_t)(2 + i) * ns, 1, YR, 1) : NAN;
          printf(" %14.3e %13.3e", phgmg_err_proj(red, Xi, N, ns), ey);
          if (dm == 0) ey2[k][tr - 1][i] = ey;
        }
        printf(" %8d\n", info.deim_modes);
        fflush(stdout);
        phgmg_reduced_destroy(red);
      }
  /* summary (every term, no hyper-reduction): ratio one run / two runs per
     (r, held-out input); > 1: the second run helped */
  for (k = 0; k < nr; ++k) {
    double l = 0;
    for (i = 0; i < NHO; ++i) {
      double q = ey2[k][0][i] / ey2[k][1][i];
      if (!(q > 0.0 && q < HUGE_VAL)) continue;   /* a failed reduction or simulation */
      nimp += q > 1.0; ++ncmp; l += log(q);
    }
    ngm += l >= 0.0; lsum += l;
  }
  if (ncmp > 0)
    printf("summary (deim 0): the second run lowers e_y at %d of %d (r, held-out input) pairs; "
           "geometric mean over the %d inputs lower at %d of %d orders; overall ratio 1 run / 2 runs %.3f\n",
           nimp, ncmp, NHO, ngm, nr, exp(lsum / ncmp));
  free(X); free(Y); free(YR);
  if (nonlin) msd_nonlinear_free(&NL); else msd_linear_free(&L);
  return 0;
}
