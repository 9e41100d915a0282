/* Descriptor models on the sparse LU whatever the order of their columns
   (the pivot matching of manual 8.12), and the validation of sparse models
   without band copies, once per model object. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>

/* An nx x nx lattice of masses, state (q, p) per mass (indices 2n, 2n+1):
   unit springs to the four neighbours, on-site springs 0.1, damping 0.05 on
   each momentum, E = blockdiag(I on the positions, Mc on the momenta) with
   Mc(n, n) = 1, Mc(n, k) = 0.1 for each neighbour (symmetric positive
   definite, a finite-element mass matrix's pattern). swap = 1: the columns
   of E and Q of the masses 2k and 2k + 1 exchanged (positions with
   positions, momenta with momenta: E P, Q P with P the pair swap j <-> j^2):
   the same dynamics for the state P x, the same outputs; the diagonal of
   sigma E P + M P is structurally zero on the positions, E P's on every
   state. */
typedef struct sp4_mat { int *cp, *ri; double *v; phgmg_csc A; } sp4_mat;
typedef struct sp4_model { int N; sp4_mat M[4]; double *B; } sp4_model;

static int sp4_col(int a, int nx, int j, int *ri, double *v) {
  const int n = j / 2, x = n % nx, y = n / nx, isp = j & 1;
  int k = 0, d, nb[4], nn = 0;
  if (y > 0) nb[nn++] = n - nx;
  if (x > 0) nb[nn++] = n - 1;
  if (x + 1 < nx) nb[nn++] = n + 1;
  if (y + 1 < nx) nb[nn++] = n + nx;
  if (a == 0) { ri[0] = isp ? 2 * n : 2 * n + 1; v[0] = isp ? 1.0 : -1.0; return 1; }
  if (a == 1) { if (!isp) return 0; ri[0] = j; v[0] = 0.05; return 1; }
  if (a == 2 && isp) { ri[0] = j; v[0] = 1.0; return 1; }
  if (a == 3 && !isp) { ri[0] = j; v[0] = 1.0; return 1; }
  for (d = 0; d < nn; ++d)
    if (nb[d] < n) { ri[k] = 2 * nb[d] + isp; v[k++] = a == 2 ? -1.0 : 0.1; }
  ri[k] = j; v[k++] = a == 2 ? nn + 0.1 : 1.0;
  for (d = 0; d < nn; ++d)
    if (nb[d] > n) { ri[k] = 2 * nb[d] + isp; v[k++] = a == 2 ? -1.0 : 0.1; }
  return k;
}

static void sp4_build(sp4_model *md, int nx, int swap) {
  const int N = 2 * nx * nx;
  int a, j;
  md->N = N;
  for (a = 0; a < 4; ++a) {
    sp4_mat *M = &md->M[a];
    int nz = 0;
    M->cp = (int *)malloc(sizeof(int) * (size_t)(N + 1));
    M->ri = (int *)malloc(sizeof(int) * (size_t)N * 5);
    M->v = (double *)malloc(sizeof(double) * (size_t)N * 5);
    for (j = 0; j < N; ++j) {
      const int src = swap && a >= 2 ? j ^ 2 : j;
      M->cp[j] = nz;
      nz += sp4_col(a, nx, src, M->ri + nz, M->v + nz);
    }
    M->cp[N] = nz;
    M->A.n_rows = M->A.n_cols = N;
    M->A.colptr = M->cp; M->A.rowidx = M->ri; M->A.values = M->v;
  }
  md->B = (double *)calloc((size_t)N, sizeof(double));
  md->B[1] = 1.0;
}

static void sp4_free(sp4_model *md) {
  int a;
  for (a = 0; a < 4; ++a) { free(md->M[a].cp); free(md->M[a].ri); free(md->M[a].v); }
  free(md->B);
}

static void sp4_u(double t, double *u, void *user) { (void)user; u[0] = 0.1 * sin(t); }

/* Simulate steps steps with the solver forced (user-ordered states into X). */
static void sp4_run(const sp4_model *md, int solver, int steps, double *X, double *Y, phgmg_gl3_stats *st,
                    phgmg_ph_sparse_info *inf) {
  phgmg_ph_sparse *sp = NULL;
  double *x0 = (double *)calloc((size_t)md->N, sizeof(double));
  double *Xi = (double *)malloc(sizeof(double) * (size_t)md->N * (size_t)(steps + 1));
  CHECK_RC(phgmg_ph_sparse_create_e(&sp, md->N, 1, &md->M[0].A, &md->M[1].A, &md->M[2].A, &md->M[3].A, md->B, NULL,
                                    inf, NULL), PHGMG_OK);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, solver, inf), PHGMG_OK);
  CHECK_RC(phgmg_ph_validate(phgmg_ph_sparse_system(sp), 0.0, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_simulate(phgmg_ph_sparse_system(sp), x0, 0.0, 0.1, steps, sp4_u, NULL, NULL, Xi, Y, NULL, st, NULL,
                          NULL), PHGMG_OK);
  CHECK_RC(phgmg_ph_sparse_to_user_order(sp, steps + 1, Xi, md->N, X, md->N), PHGMG_OK);
  phgmg_ph_sparse_destroy(sp);
  free(x0); free(Xi);
}

TEST(test_sparse_perm_swapped_columns) {
  /* A 2-D lattice with a mass matrix whose E and Q have their columns
     swapped in pairs (every diagonal entry of E P is zero): the sparse LU
     is used from start to end (no fall-back to the band LU), the trajectory
     is the pair-swapped trajectory of the natural model and the outputs are
     equal, to round-off; the matching moves every column and the factor is
     no larger than twice the natural order's (a time comparable to it;
     without the matching the static pivots fail on the zero diagonal). */
  const int nx = 16, steps = 60, N = 2 * nx * nx;
  sp4_model nat, sw;
  double *X0 = (double *)malloc(sizeof(double) * (size_t)N * (steps + 1));
  double *X1 = (double *)malloc(sizeof(double) * (size_t)N * (steps + 1));
  double Y0[61], Y1[61], dx = 0.0, xm = 0.0, dy = 0.0, ym = 0.0;
  phgmg_gl3_stats s0, s1;
  phgmg_ph_sparse_info i0, i1;
  int j, k;
  sp4_build(&nat, nx, 0);
  sp4_build(&sw, nx, 1);
  sp4_run(&nat, PHGMG_SOLVER_SPARSE_LU, steps, X0, Y0, &s0, &i0);
  sp4_run(&sw, PHGMG_SOLVER_SPARSE_LU, steps, X1, Y1, &s1, &i1);
  CHECK(s0.sparse_lu == 1 && s0.band_fallback == 0);
  CHECK(s1.sparse_lu == 1 && s1.band_fallback == 0);
  CHECK(i0.colperm == 0 && i1.colperm == N);
  CHECK(i1.lu_sparse <= 2.0 * i0.lu_sparse);
  for (k = 0; k <= steps; ++k) {
    for (j = 0; j < N; ++j) {
      const double a = X0[(size_t)k * N + j], b = X1[(size_t)k * N + (j ^ 2)];
      dx = fmax(dx, fabs(a - b)); xm = fmax(xm, fabs(a));
    }
    dy = fmax(dy, fabs(Y0[k] - Y1[k])); ym = fmax(ym, fabs(Y0[k]));
  }
  CHECK(xm > 0.0 && ym > 0.0);
  CHECK_LE(dx, 1e-12 * xm);
  CHECK_LE(dy, 1e-12 * ym);
  sp4_free(&nat); sp4_free(&sw);
  free(X0); free(X1);
}

SUITE(sparse_perm) {
  RUN(test_sparse_perm_swapped_columns);
}
