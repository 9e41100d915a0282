/* Library parts of a finite-element engineer's workflow: several reduced
   models of one full model validated against a single full run, and a
   sparse matrix assembled from coordinate triplets with duplicates. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>

#include "fixture_msd.h"
static void wf_u_sin(double t, double *u, void *user) { (void)user; u[0] = 0.5 * sin(1.3 * t); }

/* validate_many: each model's e_y equals the relative output error computed
   here from a full simulation and the model's own reduced simulation; the
   full model is the same for every entry (e_energy_fom equal). */
TEST(test_validate_many_matches_own_runs) {
  dmodel t;
  const int n = 20, N = 40, ns = 201, rs[3] = {6, 10, 14};
  double *X = (double *)calloc((size_t)N * ns, sizeof(double)), *x0 = (double *)calloc((size_t)N, sizeof(double));
  double *Y = (double *)malloc(sizeof(double) * ns), *YR = (double *)malloc(sizeof(double) * ns), *xr0;
  phgmg_reduced *red[3] = {NULL, NULL, NULL};
  phgmg_validation v[3];
  phgmg_run run;
  phgmg_reduce_opts o;
  int k;
  dmodel_msd(&t, n);
  CHECK_RC(phgmg_simulate(&t.sys, x0, 0.0, 0.1, ns - 1, wf_u_sin, NULL, NULL, X, Y, NULL, NULL, NULL, NULL), PHGMG_OK);
  for (k = 0; k < 3; ++k) {
    phgmg_reduce_opts_default(&o);
    o.method = k == 1 ? PHGMG_METHOD_SP1 : PHGMG_METHOD_GMG_POD;
    o.r = rs[k];
    CHECK_RC(phgmg_reduce(&red[k], &t.sys, X, N, ns, &o, NULL, NULL), PHGMG_OK);
  }
  memset(&run, 0, sizeof run);
  run.u = wf_u_sin; run.dt = 0.1; run.nsteps = ns - 1;
  CHECK_RC(phgmg_reduced_validate_many((const phgmg_reduced *const *)red, 3, &t.sys, &run, 0.0, 0, 0.0, v, NULL),
           PHGMG_OK);
  xr0 = (double *)calloc(16, sizeof(double));
  for (k = 0; k < 3; ++k) {
    double ey;
    CHECK_RC(phgmg_reduced_simulate(red[k], xr0, 0.0, 0.1, ns - 1, wf_u_sin, NULL, 0.0, 20, NULL, YR, NULL, NULL,
                                    NULL), PHGMG_OK);
    ey = phgmg_rel_error(1, ns, Y, 1, YR, 1);
    CHECK(v[k].pass == 1 && v[k].first_failure == -1 && v[k].steps_done == ns - 1);
    CHECK_LE(fabs(v[k].e_y - ey), 1e-12 * (ey + 1e-300) + 1e-15);
    CHECK(v[k].e_energy_fom == v[0].e_energy_fom);
  }
  /* the errors fall with r along the GMG-POD models */
  CHECK(v[2].e_y < v[0].e_y);
  /* bad arguments: counted, NULL model, another model's size */
  CHECK_RC(phgmg_reduced_validate_many((const phgmg_reduced *const *)red, 0, &t.sys, &run, 0.0, 0, 0.0, v, NULL),
           PHGMG_ERR_INVALID_ARG);
  {
    const phgmg_reduced *two[2];
    two[0] = red[0]; two[1] = NULL;
    CHECK_RC(phgmg_reduced_validate_many(two, 2, &t.sys, &run, 0.0, 0, 0.0, v, NULL), PHGMG_ERR_INVALID_ARG);
  }
  {
    phgmg_ph_system s2 = t.sys;
    s2.N = N - 2;
    CHECK_RC(phgmg_reduced_validate_many((const phgmg_reduced *const *)red, 3, &s2, &run, 0.0, 0, 0.0, v, NULL),
             PHGMG_ERR_SIZE);
  }
  for (k = 0; k < 3; ++k) phgmg_reduced_destroy(red[k]);
  free(X); free(x0); free(Y); free(YR); free(xr0);
  dmodel_free(&t);
}

/* A study's models report the POD's sigma_{r'+1}/sigma_1 as phgmg_reduce
   does (GMG on the adjusted snapshots, SP1 on X). */
TEST(test_study_reports_sigma_ratio) {
  dmodel t;
  const int n = 20, N = 40, ns = 201;
  const phgmg_method meth[2] = {PHGMG_METHOD_GMG_POD, PHGMG_METHOD_SP1};
  double *X = (double *)calloc((size_t)N * ns, sizeof(double)), *x0 = (double *)calloc((size_t)N, sizeof(double));
  phgmg_study *st = NULL;
  phgmg_study_opts so;
  int k;
  dmodel_msd(&t, n);
  CHECK_RC(phgmg_simulate(&t.sys, x0, 0.0, 0.1, ns - 1, wf_u_sin, NULL, NULL, X, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
  memset(&so, 0, sizeof so);
  so.kmax = 14;
  CHECK_RC(phgmg_study_create(&st, &t.sys, X, N, ns, &so, NULL), PHGMG_OK);
  for (k = 0; k < 2; ++k) {
    phgmg_reduce_opts o;
    phgmg_reduce_info i1, i2;
    phgmg_reduced *a = NULL, *b = NULL;
    phgmg_reduce_opts_default(&o);
    o.method = meth[k]; o.r = 8;
    CHECK_RC(phgmg_reduce(&a, &t.sys, X, N, ns, &o, &i1, NULL), PHGMG_OK);
    CHECK_RC(phgmg_study_reduce(st, &o, &b, &i2), PHGMG_OK);
    CHECK(i1.pod_sigma_ratio > 0.0);
    CHECK_LE(fabs(i2.pod_sigma_ratio - i1.pod_sigma_ratio), 1e-8 * i1.pod_sigma_ratio);
    phgmg_reduced_destroy(a);
    phgmg_reduced_destroy(b);
  }
  phgmg_study_destroy(st);
  free(X); free(x0);
  dmodel_free(&t);
}

/* phgmg_csc_from_coo against a dense accumulation of the same triplets:
   every entry the sum of its duplicates, rows strictly increasing in each
   column, the pattern exactly the positions that occur; the errors. */
TEST(test_csc_from_coo_sums_duplicates) {
  enum { NR = 7, NC = 5, NZ = 60 };
  int rows[NZ], cols[NZ], k, j, p, seen[NR * NC];
  double vals[NZ], D[NR * NC];
  unsigned s = 12345u;
  phgmg_csc A;
  memset(D, 0, sizeof D);
  memset(seen, 0, sizeof seen);
  for (k = 0; k < NZ; ++k) {   /* a small generator: many duplicates, one empty column (3) */
    s = s * 1103515245u + 12345u; rows[k] = (int)((s >> 16) % NR);
    s = s * 1103515245u + 12345u; cols[k] = (int)((s >> 16) % NC);
    if (cols[k] == 3) cols[k] = 4;
    vals[k] = (double)((int)((s >> 8) % 17) - 8) / 4.0;
    D[rows[k] + NR * cols[k]] += vals[k];
    seen[rows[k] + NR * cols[k]] = 1;
  }
  CHECK_RC(phgmg_csc_from_coo(&A, NR, NC, NZ, rows, cols, vals, NULL), PHGMG_OK);
  CHECK(A.n_rows == NR && A.n_cols == NC && A.colptr[0] == 0);
  CHECK(A.colptr[3] == A.colptr[4]);
  for (j = 0; j < NC; ++j)
    for (p = A.colptr[j]; p < A.colptr[j + 1]; ++p) {
      CHECK(p == A.colptr[j] || A.rowidx[p] > A.rowidx[p - 1]);
      CHECK(seen[A.rowidx[p] + NR * j] == 1);
      CHECK(A.values[p] == D[A.rowidx[p] + NR * j]);   /* sums of quarters: exact */
      seen[A.rowidx[p] + NR * j] = 2;
    }
  for (k = 0; k < NR * NC; ++k) CHECK(seen[k] != 1);   /* every position that occurs is stored once */
  phgmg_csc_free(&A, NULL);
  CHECK(A.values == NULL && A.colptr == NULL);
  phgmg_csc_free(&A, NULL);   /* twice: fine */
  /* no entries: an all-zero matrix */
  CHECK_RC(phgmg_csc_from_coo(&A, 3, 2, 0, NULL, NULL, NULL, NULL), PHGMG_OK);
  CHECK(A.colptr[0] == 0 && A.colptr[2] == 0);
  phgmg_csc_free(&A, NULL);
  /* errors: an index outside, a value not finite, bad sizes, NULL */
  rows[5] = NR;
  CHECK_RC(phgmg_csc_from_coo(&A, NR, NC, NZ, rows, cols, vals, NULL), PHGMG_ERR_SIZE);
  CHECK(A.colptr == NULL);
  rows[5] = 0; cols[7] = -1;
  CHECK_RC(phgmg_csc_from_coo(&A, NR, NC, NZ, rows, cols, vals, NULL), PHGMG_ERR_SIZE);
  cols[7] = 0; vals[9] = (double)NAN;
  CHECK_RC(phgmg_csc_from_coo(&A, NR, NC, NZ, rows, cols, vals, NULL), PHGMG_ERR_NANINF);
  vals[9] = 1.0;
  CHECK_RC(phgmg_csc_from_coo(&A, 0, NC, NZ, rows, cols, vals, NULL), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_csc_from_coo(&A, NR, NC, -1, rows, cols, vals, NULL), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_csc_from_coo(&A, NR, NC, NZ, NULL, cols, vals, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_csc_from_coo(NULL, NR, NC, NZ, rows, cols, vals, NULL), PHGMG_ERR_INVALID_ARG);
}

SUITE(workflow) {
  RUN(test_csc_from_coo_sums_duplicates);
  RUN(test_study_reports_sigma_ratio);
  RUN(test_validate_many_matches_own_runs);
}
