/* altmin_study.c -- the GMG-QM manifold constructions side by side:
   hierarchical POD (the paper's), greedy linear part, alternating minimization.
   Trained on u = 0.1 sin t (1000 steps of dt = 0.1; with --two also on the
   multisine 0.05 (sin 0.5t + sin 1.5t + sin 3t)), for each r: the training
   objective at the start/end of the alternating minimization, e_proj and
   e_lowerbound on the training snapshots, e_red and e_y on the training input,
   the worst e_y over four other inputs (0.1, 0.1 sin 2t, a chirp, a random
   piecewise-constant signal), Newton failures over all five, reduce time.
   GMG-POD (M = 0) on the same r for reference.
   QM-alt* = altmin fell back to the POD manifold (lambda auto, not better than GMG-POD).
   Usage: altmin_study linear|nonlinear [--lambda L|auto] [--train-only] [--r 8,10,...] [--rn 8] [--two]
   Build: cc -O2 -march=native -o build/altmin_study bench/studies/altmin_study.c -lm. */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#define PHGMG_IMPLEMENTATION
#include "../../phgmg.h"
#include "../../examples/msd_models.h"
#include "../../examples/demo_common.h"

/* the inputs of make demo's generalization study (examples/demo_common.h) */
#define NIN 5
static phgmg_input_fn inf[NIN] = {msd_input_sin, msd_input_const, demo_u_sin2, demo_u_chirp, demo_u_pwc};

int main(int argc, char **argv) {
  const int nsteps = 1000, ns = nsteps + 1;
  const double dt = 0.1;
  int rl[64], nr = 0, i, k, me, lauto = 0, two = 0, tonly = 0, rn = 8, nonlin, N, ntr;
  double lambda = 0.0, tol = 1e-10;
  const char *rs = "8,10,12,14,16,18,20";
  msd_linear L;
  msd_nonlinear NL;
  const phgmg_ph_system *sys;
  double *X, *Y, *XR, *YR, xr0[64] = {0};
  phgmg_run runs[2];
  phgmg_gl3_opts go;
  if (argc < 2 || (strcmp(argv[1], "linear") && strcmp(argv[1], "nonlinear"))) { fprintf(stderr, "usage: %s linear|nonlinear [--lambda L|auto] [--r LIST] [--two]\n", argv[0]); return 2; }
  nonlin = !strcmp(argv[1], "nonlinear");
  for (i = 2; i < argc; ++i) {
    if (!strcmp(argv[i], "--lambda") && i + 1 < argc) { ++i; if (!strcmp(argv[i], "auto")) lauto = 1; else lambda = atof(argv[i]); }
    else if (!strcmp(argv[i], "--r") && i + 1 < argc) rs = argv[++i];
    else if (!strcmp(argv[i], "--two")) two = 1;
    else if (!strcmp(argv[i], "--train-only")) tonly = 1;
    else if (!strcmp(argv[i], "--rn") && i + 1 < argc) rn = atoi(argv[++i]);
    else { fprintf(stderr, "bad argument %s\n", argv[i]); return 2; }
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
  ntr = two ? 2 : 1;
  X = (double *)malloc(sizeof(double) * (size_t)N * ns * (NIN + 1));
  Y = (double *)malloc(sizeof(double) * (size_t)ns * (NIN + 1));
  XR = (double *)malloc(sizeof(double) * 64 * ns);
  YR = (double *)malloc(sizeof(double) * ns);
  if (!X || !Y || !XR || !YR) return 1;
  memset(&go, 0, sizeof go); go.tol = tol; go.max_iter = 20;
  memset(runs, 0, sizeof runs);
  for (i = 0; i < 2; ++i) { runs[i].u = i ? demo_u_multisine : msd_input_sin; runs[i].dt = dt; runs[i].nsteps = nsteps; }
  /* columns: run sin, [multisine], then the four other inputs */
  if (phgmg_simulate_inputs(sys, ntr, runs, &go, X, N, Y, NULL, NULL) != PHGMG_OK) return 1;
  for (i = 1; i < NIN; ++i) {
    phgmg_run run;
    memset(&run, 0, sizeof run);
    run.u = inf[i]; run.dt = dt; run.nsteps = nsteps;
    if (phgmg_simulate_inputs(sys, 1, &run, &go, X + (size_t)(ntr + i - 1) * N * ns, N, Y + (size_t)(ntr + i - 1) * ns, NULL, NULL) != PHGMG_OK) return 1;
  }
  printf("%s chain, N = %d, trained on %s, lambda %s\n", nonlin ? "nonlinear" : "linear", N,
         two ? "0.1 sin t + multisine" : "0.1 sin t", lauto ? "auto (validated by simulation)" : argv[0] ? (lambda > 0 ? "fixed" : lambda < 0 ? "0" : "1e-3") : "");
  if (tonly) printf("lambda_train_only = 1 (validated on the training run(s) alone)\n");
  printf("%3s %-7s %5s %9s %9s %9s %9s %9s %9s %9s %4s %8s %6s\n", "r", "method", "sweep", "obj0", "obj", "e_proj", "e_lowb",
         "e_red", "e_y(tr)", "e_y(oth)", "fail", "lambda", "t[s]");
  for (k = 0; k < nr; ++k)
    for (me = -1; me < 3; ++me) {
      phgmg_reduce_opts o;
      phgmg_reduce_info info;
      phgmg_reduced *red = NULL;
      phgmg_result rc;
      double t0, tred, ered = NAN, eytr = NAN, eyo = 0, fails = 0, eproj, elb;
      memset(&o, 0, sizeof o);
      o.method = me < 0 ? PHGMG_METHOD_GMG_POD : PHGMG_METHOD_GMG_QM;
      o.r = rl[k]; o.qm.rn = rn; o.qm.manifold = me < 0 ? 0 : me; o.qm.lambda = lambda;
      o.select.lambda_mode = me >= 0 && lauto; o.select.train_only = tonly; o.nrun = ntr; o.runs = runs; o.select.newton_tol = tol; o.select.newton_iter = 20;
      if (nonlin) { o.hyper.on = 1; o.hyper.deim_tol = 1e-8; o.hyper.allow_negative = 1; }
      t0 = demo_now();
      rc = phgmg_reduce(&red, sys, X, N, ntr * ns, &o, &info, NULL);
      tred = demo_now() - t0;
      if (rc != PHGMG_OK) { printf("%3d %-7s reduce: %s\n", o.r, me < 0 ? "POD" : me == 0 ? "QM-pod" : me == 1 ? "QM-grdy" : "QM-alt", phgmg_result_string(rc)); continue; }
      eproj = phgmg_err_proj(red, X, N, ntr * ns);
      elb = me < 0 ? NAN : phgmg_err_lowerbound(red, X, N, ntr * ns);
      for (i = 0; i < NIN; ++i) {
        phgmg_rom_stats st;
        const size_t c0 = i == 0 ? 0 : (size_t)(ntr + i - 1) * ns;
        rc = phgmg_reduced_simulate(red, xr0, 0.0, dt, nsteps, inf[i], NULL, tol, 20, XR, YR, NULL, &st, NULL);
        fails += (double)st.failures + (rc != PHGMG_OK && st.failures == 0);
        if (i == 0) {
          if (rc == PHGMG_OK) { ered = phgmg_err_red(red, X, N, ns, XR, o.r); eytr = phgmg_rel_error(1, ns, Y, 1, YR, 1); }
        } else {
          const double e = rc == PHGMG_OK ? phgmg_rel_error(1, ns, Y + c0, 1, YR, 1) : NAN;
          eyo = (e != e || eyo != eyo) ? NAN : (e > eyo ? e : eyo);
        }
      }
      printf("%3d %-7s %5d %9.2e %9.2e %9.2e %9.2e %9.2e %9.2e %9.2e %4.0f %8.1e %6.2f\n", o.r,
             me < 0 ? "POD" : me == 0 ? "QM-pod" : me == 1 ? "QM-grdy" : info.manifold_fallback ? "QM-alt*" : "QM-alt",
             info.manifold_sweeps,
             sqrt(info.manifold_obj0), sqrt(info.manifold_obj), eproj, elb, ered, eytr, eyo, fails,
             me < 0 ? 0.0 : info.lambda, tred);
      fflush(stdout);
      phgmg_reduced_destroy(red);
    }
  free(X); free(Y); free(XR); free(YR);
  if (nonlin) msd_nonlinear_free(&NL); else msd_linear_free(&L);
  return 0;
}
