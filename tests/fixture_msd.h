/* Test fixture shared by the defect suites: the linear mass-spring-damper
   chain of paper 5.2 (n masses, N = 2n, one force port at the first mass),
   x = (q1, p1, q2, p2, ...), dense. Include after phgmg.h, <stdlib.h>, <string.h>. */
#ifndef TESTS_FIXTURE_MSD_H
#define TESTS_FIXTURE_MSD_H
typedef struct dmodel {
  phgmg_ph_system sys;
  double *J, *R, *Q, *B;
} dmodel;
static void dmodel_msd(dmodel *t, int n) {
  const int N = 2 * n;
  int i;
  memset(t, 0, sizeof *t);
  t->J = (double *)calloc((size_t)N * N, sizeof(double));
  t->R = (double *)calloc((size_t)N * N, sizeof(double));
  t->Q = (double *)calloc((size_t)N * N, sizeof(double));
  t->B = (double *)calloc((size_t)N, sizeof(double));
  for (i = 0; i < n; ++i) {
    const int q = 2 * i, p = 2 * i + 1;
    t->J[q + p * N] = 1; t->J[p + q * N] = -1;
    t->R[p + p * N] = 0.5;
    t->Q[p + p * N] = 1.0;
    t->Q[q + q * N] = (i == 0 ? 1.0 : 2.0);
    if (i + 1 < n) { t->Q[q + (q + 2) * N] = -1.0; t->Q[(q + 2) + q * N] = -1.0; }
  }
  t->B[1] = 1;
  t->sys.N = N; t->sys.m = 1; t->sys.J = t->J; t->sys.R = t->R; t->sys.Q = t->Q; t->sys.B = t->B;
}
static void dmodel_free(dmodel *t) { free(t->J); free(t->R); free(t->Q); free(t->B); }
#endif
