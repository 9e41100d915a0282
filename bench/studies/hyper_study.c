/* hyper_study: the hyper-reduction choices of phgmg_reduce side by side on
   the paper's nonlinear chain (N = 1000, 1001 snapshots, dt = 0.1, r = 20):
   every term kept, ECSW (the default, weights >= 0), Q-DEIM and greedy DEIM
   (the paper's structure-preserving DEIM, tol 1e-8), for every method and two
   training inputs (u = 0.1 and u = 0.1 sin t). Prints points, negative
   weights, smallest weight, ECSW training residual, e_red, e_y (on the
   training input) and the CPU time of the whole phgmg_reduce.
   Build and run: cc -std=c99 -O2 -march=native -o build/hyper_study bench/studies/hyper_study.c -lm
   && ./build/hyper_study   (also run by make bench) */
#define PHGMG_IMPLEMENTATION
#include "../../phgmg.h"
#include "../../examples/msd_models.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static void u_const(double t, double *u, void *p) { (void)t; (void)p; u[0] = 0.1; }
static void u_sin(double t, double *u, void *p) { (void)p; u[0] = 0.1 * sin(t); }

int main(void) {
  static const char *mname[5] = {"", "GMG-POD", "GMG-QM", "SP1", "SP2"};
  static const char *hname[4] = {"all terms", "ECSW", "Q-DEIM", "greedy DEIM"};
  msd_nonlinear M;
  msd_nl_opts no;
  const int ns = 1001, r = 20;
  int N, inp, meth, h;
  double *X, *Y, *x0, XR[20 * 1001], YR[1001], xr0[20];
  memset(&no, 0, sizeof no);
  no.n = 500;
  if (msd_nonlinear_build(&M, &no)) return 1;
  N = M.sys.N;
  X = (double *)malloc(sizeof(double) * (size_t)N * ns);
  Y = (double *)malloc(sizeof(double) * ns);
  x0 = (double *)calloc((size_t)N, sizeof(double));
  if (!X || !Y || !x0) return 1;
  memset(xr0, 0, sizeof xr0);
  printf("paper's nonlinear chain, N = %d, %d snapshots, r = %d (GMG-QM r_n = 8, lambda 1e-3)\n", N, ns, r);
  printf("%-14s %-8s %-12s %5s %4s %9s %9s %10s %10s %8s\n", "training u", "method", "hyper", "terms", "neg",
         "min w", "resid", "e_red", "e_y", "t [s]");
  for (inp = 0; inp < 2; ++inp) {
    phgmg_input_fn uf = inp ? u_sin : u_const;
    if (phgmg_simulate(&M.sys, x0, 0, 0.1, ns - 1, uf, NULL, NULL, X, Y, NULL, NULL, NULL, NULL) != PHGMG_OK) return 1;
    for (meth = 1; meth <= 4; ++meth)
      for (h = 0; h < 4; ++h) {
        phgmg_reduce_opts o;
        phgmg_reduce_info info;
        phgmg_reduced *red = NULL;
        clock_t t0;
        double tt;
        phgmg_result rc;
        memset(&o, 0, sizeof o);
        o.method = (phgmg_method)meth; o.r = r; o.hyper.on = h > 0; o.hyper.allow_negative = 1;
        o.hyper.kind = h == 1 ? PHGMG_HYPER_ECSW : h == 2 ? PHGMG_HYPER_QDEIM : PHGMG_HYPER_GREEDY;
        t0 = clock();
        rc = phgmg_reduce(&red, &M.sys, X, N, ns, &o, &info, NULL);
        tt = (double)(clock() - t0) / CLOCKS_PER_SEC;
        if (rc == PHGMG_OK)
          rc = phgmg_reduced_simulate(red, xr0, 0, 0.1, ns - 1, uf, NULL, 0, 0, XR, YR, NULL, NULL, NULL);
        if (rc != PHGMG_OK) {
          printf("%-14s %-8s %-12s failed: %s\n", inp ? "0.1 sin t" : "0.1", mname[meth], hname[h], phgmg_result_string(rc));
        } else {
          printf("%-14s %-8s %-12s %5d %4d %9.3f %9.1e %10.3e %10.3e %8.3f\n", inp ? "0.1 sin t" : "0.1", mname[meth],
                 hname[h], info.deim_modes ? info.deim_modes : M.sys.nsep, info.deim_negative,
                 h ? info.hyper_min_weight : 1.0, info.hyper_residual, phgmg_err_red(red, X, N, ns, XR, r),
                 phgmg_rel_error(1, ns, Y, 1, YR, 1), tt);
        }
        phgmg_reduced_destroy(red);
      }
  }
  free(X); free(Y); free(x0);
  msd_nonlinear_free(&M);
  return 0;
}
