/* FOM GL3 stepping of a Toda chain, H_nl = sum_k (e^{x_k} - 1 - x_k): the built-in
   exp-polynomial family (shared, and one function per term) against the same
   function as callbacks. N = 2000, banded (kb = 1), diagonal Q, 200 steps.
   cc -std=c99 -O2 -march=native -o build/bench_sepfun bench/bench_sepfun.c -lm && build/bench_sepfun */
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

enum { N = 2000, NST = 200 };
static double toda(int k, double s, void *u) { (void)k; (void)u; return exp(s) - 1.0 - s; }
static double dtoda(int k, double s, void *u) { (void)k; (void)u; return exp(s) - 1.0; }
static double ddtoda(int k, double s, void *u) { (void)k; (void)u; return exp(s); }
static void uin(double t, double *u, void *user) { (void)user; u[0] = sin(t); }

int main(void) {
  static double Jb[3 * N], Rb[3 * N], Qb[3 * N], B[N], x0[N], poly[2 * N], expo[2 * N], X[N];
  static int idx[N];
  int i, v;
  for (i = 0; i < N; ++i) {
    Rb[1 + 3 * i] = 0.01; Qb[1 + 3 * i] = 1.0; idx[i] = i; x0[i] = 0.3 * sin(0.01 * i);
    if (i + 1 < N) { Jb[3 * (i + 1)] = 1.0; Jb[2 + 3 * i] = -1.0; }
    poly[2 * i] = -1.0; poly[2 * i + 1] = -1.0; expo[2 * i] = 1.0; expo[2 * i + 1] = 1.0;
  }
  B[0] = 1.0;
  for (v = 0; v < 3; ++v) {
    phgmg_ph_system s;
    phgmg_gl3_stats st;
    clock_t t0;
    double sec;
    memset(&s, 0, sizeof s);
    s.N = N; s.m = 1; s.storage = PHGMG_BANDED; s.kb = 1; s.J = Jb; s.R = Rb; s.Q = Qb; s.B = B;
    s.nl = PHGMG_NL_SEPARABLE; s.nsep = N; s.sep_idx = idx;
    if (v < 2) { s.poly_deg = 1; s.poly = poly; s.nexp = 1; s.expo = expo; s.phi_nfun = v ? N : 0; }
    else { s.phi = toda; s.dphi = dtoda; s.ddphi = ddtoda; }
    t0 = clock();
    if (phgmg_simulate(&s, x0, 0.0, 0.01, NST, uin, NULL, NULL, NULL, NULL, NULL, &st, NULL, NULL) != PHGMG_OK) return 1;
    sec = (double)(clock() - t0) / CLOCKS_PER_SEC;
    printf("%-22s %8.2f ms  (%ld Newton iterations, %ld factorizations)\n",
           v == 0 ? "exp-poly shared" : (v == 1 ? "exp-poly per term" : "callbacks"), 1e3 * sec,
           st.newton_iters, st.factorizations);
  }
  (void)X;
  return 0;
}
