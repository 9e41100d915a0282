/* Test helper: the CSC of a dense N x N matrix (its nonzero entries), for
   building small phgmg_ph_sparse models from dense fixtures. Arrays
   malloc'ed; th_csc_free releases them. Include after phgmg.h. */
#ifndef PHGMG_TEST_DENSE_CSC_H
#define PHGMG_TEST_DENSE_CSC_H
#include <stdlib.h>

static phgmg_csc th_dense_csc(int N, const double *A) {
  phgmg_csc c;
  int j, i, nz = 0;
  int *cp = (int *)malloc(sizeof(int) * (size_t)(N + 1)), *ri;
  double *v;
  for (j = 0; j < N * N; ++j) nz += A[j] != 0.0;
  ri = (int *)malloc(sizeof(int) * (size_t)(nz + 1));
  v = (double *)malloc(sizeof(double) * (size_t)(nz + 1));
  nz = 0;
  for (j = 0; j < N; ++j) {
    cp[j] = nz;
    for (i = 0; i < N; ++i)
      if (A[i + (size_t)j * N] != 0.0) { ri[nz] = i; v[nz++] = A[i + (size_t)j * N]; }
  }
  cp[N] = nz;
  c.n_rows = c.n_cols = N; c.colptr = cp; c.rowidx = ri; c.values = v;
  return c;
}

static void th_csc_free(phgmg_csc *c) { free((void *)c->colptr); free((void *)c->rowidx); free((void *)c->values); }
#endif
