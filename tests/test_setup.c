/* The set-up of a SPARSE model in proportion to its simulation: the factor
   of J - R (validation's rcond, GMG's G = (J - R)^{-1}) by the sparse LU,
   without a band copy of J - R, and equal to the dense LU's results. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>
#include <string.h>

/* An allocator that counts the bytes it holds (a size header per block). */
typedef struct su_count { double live, peak; } su_count;
static void *su_count_alloc(size_t n, void *user) {
  su_count *c = (su_count *)user;
  double *p = (double *)malloc(n + sizeof(double));
  if (!p) return NULL;
  p[0] = (double)n;
  c->live += (double)n;
  if (c->live > c->peak) c->peak = c->live;
  return p + 1;
}
static void su_count_free(void *ptr, void *user) {
  double *p = (double *)ptr;
  if (!p) return;
  ((su_count *)user)->live -= p[-1];
  free(p - 1);
}

/* A dense N x N matrix as CSC (entries != 0), arrays malloc'ed into *c. */
typedef struct su_csc { phgmg_csc A; int *p, *i; double *x; } su_csc;
static void su_csc_of(su_csc *c, int N, const double *D) {
  int j, k, nz = 0;
  c->p = (int *)malloc(sizeof(int) * (size_t)(N + 1));
  c->i = (int *)malloc(sizeof(int) * (size_t)N * 12);
  c->x = (double *)malloc(sizeof(double) * (size_t)N * 12);
  for (j = 0; j < N; ++j) {
    c->p[j] = nz;
    for (k = 0; k < N; ++k)
      if (D[(size_t)k + (size_t)j * N] != 0.0) { c->i[nz] = k; c->x[nz++] = D[(size_t)k + (size_t)j * N]; }
  }
  c->p[N] = nz;
  c->A.n_rows = N; c->A.n_cols = N; c->A.colptr = c->p; c->A.rowidx = c->i; c->A.values = c->x;
}
static void su_csc_free(su_csc *c) { free(c->p); free(c->i); free(c->x); }

/* A 2-D lattice of n x n masses, state (q_k, p_k) = (2k, 2k + 1) scrambled by
   a fixed permutation: J pairs q_k with p_k, R = 0.05 I + 0.01 L on the
   momenta (L the lattice Laplacian: J - R couples neighbours), Q =
   blockdiag(L + 0.1 I, I). Dense N x N arrays J, R, Q (column-major). */
static void su_lattice(int n, double *J, double *R, double *Q, int *perm) {
  const int nn = n * n, N = 2 * nn;
  int k, a, s;
  unsigned st = 12345u;
  for (k = 0; k < N; ++k) perm[k] = k;
  for (k = N - 1; k > 0; --k) { /* Fisher-Yates with a fixed LCG */
    int j, t;
    st = st * 1103515245u + 12345u;
    j = (int)((st >> 8) % (unsigned)(k + 1));
    t = perm[k]; perm[k] = perm[j]; perm[j] = t;
  }
#define SU_AT(M, i, j) M[(size_t)perm[i] + (size_t)perm[j] * (size_t)N]
  for (k = 0; k < nn; ++k) {
    const int q = 2 * k, p = 2 * k + 1, x = k % n, y = k / n;
    const int nb[4] = {x > 0 ? k - 1 : -1, x < n - 1 ? k + 1 : -1, y > 0 ? k - n : -1, y < n - 1 ? k + n : -1};
    SU_AT(J, q, p) = 1.0; SU_AT(J, p, q) = -1.0;
    SU_AT(R, p, p) = 0.05; SU_AT(Q, q, q) = 0.1; SU_AT(Q, p, p) = 1.0;
    for (a = 0; a < 4; ++a) {
      if ((s = nb[a]) < 0) continue;
      SU_AT(R, p, p) += 0.01; SU_AT(R, p, 2 * s + 1) -= 0.01;
      SU_AT(Q, q, q) += 1.0; SU_AT(Q, q, 2 * s) -= 1.0;
    }
  }
#undef SU_AT
}

TEST(test_setup_jr_factor_sparse) {
  /* The factor of J - R of a SPARSE model (a scrambled 20 x 20 lattice whose
     damping couples neighbours) takes less memory than three bands of J - R
     at the least half-bandwidth any ordering of the lattice can have (n), solves (J - R) x = b and
     (J - R)^T x = b as the dense LU with partial pivoting does, and its rcond
     and phgmg_ph_validate's agree with the dense estimate. The band path held
     two band copies of J, R and a band LU: over 7 bands of that least width
     (1.8e6 bytes here, against 3 bands = 7.9e5; the sparse LU 5.9e5). */
  const int n = 20, N = 2 * n * n;
  double *J = (double *)calloc((size_t)N * N, sizeof(double)), *R = (double *)calloc((size_t)N * N, sizeof(double));
  double *Q = (double *)calloc((size_t)N * N, sizeof(double)), *D = (double *)malloc(sizeof(double) * (size_t)N * N);
  double *B = (double *)calloc((size_t)N, sizeof(double)), *b = (double *)malloc(sizeof(double) * (size_t)N * 2);
  double *x = (double *)malloc(sizeof(double) * (size_t)N * 2), *work = (double *)malloc(sizeof(double) * 2 * (size_t)N);
  int *perm = (int *)malloc(sizeof(int) * (size_t)N), *ipiv = (int *)malloc(sizeof(int) * (size_t)N);
  int *iwork = (int *)malloc(sizeof(int) * (size_t)N), k, t;
  su_csc cj, cr, cq;
  su_count cnt = {0.0, 0.0};
  phgmg_allocator al;
  phgmg_ph_sparse *sp = NULL;
  phgmg_jr_factor *f = NULL;
  double rc_sp = 0.0, rc_val = 0.0, rc_dense, before, band_least, err = 0.0, nrm = 0.0;
  su_lattice(n, J, R, Q, perm);
  B[perm[1]] = 1.0;
  su_csc_of(&cj, N, J); su_csc_of(&cr, N, R); su_csc_of(&cq, N, Q);
  al.alloc = su_count_alloc; al.free = su_count_free; al.user = &cnt;
  CHECK_RC(phgmg_ph_sparse_create(&sp, N, 1, &cj.A, &cr.A, &cq.A, B, NULL, NULL, &al), PHGMG_OK);
  before = cnt.live;
  cnt.peak = cnt.live;
  CHECK_RC(phgmg_jr_factor_create(&f, phgmg_ph_sparse_system(sp), &rc_sp, &al), PHGMG_OK);
  band_least = 8.0 * (2.0 * n + 1.0) * N;
  CHECK_LE(cnt.peak - before, 3.0 * band_least);
  /* the dense reference in the given order (the object's is a permutation of it) */
  for (k = 0; k < N * N; ++k) D[k] = J[k] - R[k];
  rc_dense = phgmg_norm1(N, N, D, N);
  CHECK_RC(phgmg_lu_factor(N, D, N, ipiv), PHGMG_OK);
  rc_dense = phgmg_lu_rcond(N, D, N, ipiv, rc_dense, work, iwork);
  CHECK(rc_dense > 0.0);
  CHECK(rc_sp >= rc_dense / 3.0 && rc_sp <= rc_dense * 3.0);
  for (t = 0; t < 2; ++t) {
    const int *pp = phgmg_ph_sparse_perm(sp); /* internal i = given pp[i] */
    for (k = 0; k < N; ++k) b[k] = sin(1.0 + k);
    memcpy(x, b, sizeof(double) * (size_t)N);
    phgmg_lu_solve(t ? 'T' : 'N', N, D, N, ipiv, 1, x, N);
    for (k = 0; k < N; ++k) b[N + k] = b[pp[k]];  /* b in the internal order */
    phgmg_jr_solve(f, t ? 'T' : 'N', 1, b + N, N);
    for (k = 0; k < N; ++k) {
      err = fmax(err, fabs(b[N + k] - x[pp[k]]));
      nrm = fmax(nrm, fabs(x[k]));
    }
  }
  CHECK(nrm > 0.0);
  CHECK_LE(err, 1e-12 * nrm);
  CHECK_RC(phgmg_ph_validate(phgmg_ph_sparse_system(sp), 0.0, &rc_val, &al), PHGMG_OK);
  CHECK(rc_val >= rc_dense / 3.0 && rc_val <= rc_dense * 3.0);
  phgmg_jr_factor_destroy(f);
  phgmg_ph_sparse_destroy(sp);
  CHECK(cnt.live == 0.0);
  su_csc_free(&cj); su_csc_free(&cr); su_csc_free(&cq);
  free(J); free(R); free(Q); free(D); free(B); free(b); free(x); free(work); free(perm); free(ipiv); free(iwork);
}

SUITE(setup) {
  RUN(test_setup_jr_factor_sparse);
}
