/* rsvd_study — randomized POD (phgmg_pod_randomized) against the exact
   phgmg_pod on snapshots of the paper's nonlinear MSD chain.

   For each N given: the chain with N/2 masses (banded), u = 0.1 sin t,
   dt = 0.1, 1000 steps from x0 = 0 (1001 snapshots, Newton tol 1e-8); then
   POD of k = 40 modes by phgmg_pod_randomized (q = 2 power iterations, seed 1)
   and, unless --no-exact, by phgmg_pod (exact). Prints wall times, the largest
   relative error of the 40 singular values and the largest sine of the
   subspace angles between the two bases (|| V - Ve Ve^T V ||_2 estimate by the
   Frobenius norm). --q Q sets the power iterations. --reduce: also time the
   whole phgmg_reduce (GMG-POD, r = 20, deim = 1 with the default ECSW
   hyper-reduction); build with -DPHGMG_POD_RANDOMIZED_MIN=50000000 to see it
   with the randomized POD inside.
     cc -std=c99 -O2 -march=native bench/studies/rsvd_study.c -lm
     ./a.out [--no-exact] [--q 2] 4000 16000 64000                          */
#define _POSIX_C_SOURCE 199309L
#define PHGMG_IMPLEMENTATION
#include "../../phgmg.h"
#include "../../examples/msd_models.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <time.h>

#define NSTEPS 1000
#define NS (NSTEPS + 1)
#define K 40

static double now_wall(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
static void *xmalloc(size_t n) {
  void *p = malloc(n ? n : 1);
  if (!p) { fprintf(stderr, "rsvd_study: out of memory\n"); exit(1); }
  return p;
}

int main(int argc, char **argv) {
  int a, exact = 1, q = 2, red = 0;
  for (a = 1; a < argc; ++a) {
    msd_nonlinear M;
    msd_nl_opts mo;
    phgmg_gl3_opts go;
    double *X, *x0, *V, *Ve, S[K], Se[K], t0, tsim, trand, tex = 0.0, serr = 0.0, ang = 0.0;
    int N, k = 0, ke = 0, j;
    phgmg_result rc;
    if (!strcmp(argv[a], "--no-exact")) { exact = 0; continue; }
    if (!strcmp(argv[a], "--q") && a + 1 < argc) { q = atoi(argv[++a]); continue; }
    if (!strcmp(argv[a], "--reduce")) { red = 1; continue; }
    {
      char *end;
      long v = strtol(argv[a], &end, 10);
      if (end == argv[a] || *end || v < 200 || v > 100000000) {
        fprintf(stderr, "usage: rsvd_study [--no-exact] [--q Q] [--reduce] N... (N >= 200)\n");
        return strcmp(argv[a], "--help") ? 2 : 0;
      }
      N = (int)v;
    }
    memset(&mo, 0, sizeof mo);
    mo.n = N / 2;
    mo.storage = PHGMG_BANDED;
    if (msd_nonlinear_build(&M, &mo) != 0) { fprintf(stderr, "model\n"); return 1; }
    N = M.sys.N;
    X = (double *)xmalloc(sizeof(double) * (size_t)N * NS);
    x0 = (double *)xmalloc(sizeof(double) * (size_t)N);
    memset(x0, 0, sizeof(double) * (size_t)N);
    memset(&go, 0, sizeof go);
    go.tol = 1e-8; go.max_iter = 20;
    t0 = now_wall();
    rc = phgmg_simulate(&M.sys, x0, 0.0, 0.1, NSTEPS, msd_input_sin, NULL, &go, X, NULL, NULL, NULL, NULL, NULL);
    tsim = now_wall() - t0;
    if (rc != PHGMG_OK) { fprintf(stderr, "simulate: %s\n", phgmg_result_string(rc)); return 1; }
    V = (double *)xmalloc(sizeof(double) * (size_t)N * K);
    t0 = now_wall();
    rc = phgmg_pod_randomized(N, NS, X, N, K, q, 1ul, V, N, S, &k, NULL);
    trand = now_wall() - t0;
    if (rc != PHGMG_OK || k != K) { fprintf(stderr, "randomized: %s k %d\n", phgmg_result_string(rc), k); return 1; }
    if (exact) {
      double *D, *Mx;
      Ve = (double *)xmalloc(sizeof(double) * (size_t)N * K);
      t0 = now_wall();
      rc = phgmg_pod(N, NS, X, N, K, 0.0, Ve, N, Se, &ke, NULL);
      tex = now_wall() - t0;
      if (rc != PHGMG_OK || ke != K) { fprintf(stderr, "exact: %s\n", phgmg_result_string(rc)); return 1; }
      for (j = 0; j < K; ++j) serr = fmax(serr, fabs(S[j] - Se[j]) / Se[j]);
      D = (double *)xmalloc(sizeof(double) * (size_t)N * K);
      Mx = (double *)xmalloc(sizeof(double) * K * K);
      memcpy(D, V, sizeof(double) * (size_t)N * K);
      phgmg_gemm('T', 'N', K, K, N, 1.0, Ve, N, V, N, 0.0, Mx, K);
      phgmg_gemm('N', 'N', N, K, K, -1.0, Ve, N, Mx, K, 1.0, D, N);
      ang = phgmg_normf(N, K, D, N);
      free(D); free(Mx); free(Ve);
    }
    printf("N %7d  simulate %7.2f s  randomized(q=%d) %7.3f s", N, tsim, q, trand);
    if (exact) printf("  exact %7.3f s  speed-up %5.1f  max rel err sigma_1..%d %.2e  subspace (F) %.2e", tex,
                      tex / trand, K, serr, ang);
    printf("  sigma_1 %.4e sigma_%d/sigma_1 %.2e\n", S[0], K, S[K - 1] / S[0]);
    if (red) {
      phgmg_reduce_opts o;
      phgmg_reduced *rd = NULL;
      memset(&o, 0, sizeof o);
      o.method = PHGMG_METHOD_GMG_POD; o.r = 20; o.hyper.on = 1;
      t0 = now_wall();
      rc = phgmg_reduce(&rd, &M.sys, X, N, NS, &o, NULL, NULL);
      printf("  phgmg_reduce GMG-POD r 20 deim: %s, %.2f s (PHGMG_POD_RANDOMIZED_MIN %.0f)\n",
             phgmg_result_string(rc), now_wall() - t0, (double)PHGMG_POD_RANDOMIZED_MIN);
      phgmg_reduced_destroy(rd);
    }
    fflush(stdout);
    free(X); free(x0); free(V);
    msd_nonlinear_free(&M);
  }
  return 0;
}
