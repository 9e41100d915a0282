/* Balancing of sparse models (phgmg_balanced_reduce_cached, PHBT): a cache
   shared by several methods and orders runs the ADI once per Gramian factor
   and gives the same models as separate calls (bit for bit); a cache bound
   to one model refuses another; the pH balancing (PHBT) uses the minimal
   Hamiltonian, whose values sqrt(eig(P X_min)) are at most those against
   the energy Q (X_min <= Q), strictly below for the first, with a pH model. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>

/* The n x n lattice of bench/lowrank_models.py (unscrambled) as a sparse
   object: x = (q, p), K = 2-D Laplacian + 0.01 I, D = 0.5 I + 0.01 K, forces
   on two corner masses. Dense copies in *J, *R, *Q, *B (freed by the caller,
   after the object). */
static phgmg_ph_sparse *b2_lattice(int n, double **J, double **R, double **Q, double **B, phgmg_csc c[3]) {
  const int n2 = n * n, N = 2 * n2;
  phgmg_ph_sparse *sp = NULL;
  double *M[3];
  int a, d, s, i, j;
  *J = (double *)calloc((size_t)N * N, sizeof(double)); *R = (double *)calloc((size_t)N * N, sizeof(double));
  *Q = (double *)calloc((size_t)N * N, sizeof(double)); *B = (double *)calloc((size_t)N * 2, sizeof(double));
  for (a = 0; a < n2; ++a) {
    const int x = a % n, y = a / n, nb[4] = {x > 0 ? a - 1 : -1, x < n - 1 ? a + 1 : -1, y > 0 ? a - n : -1,
                                             y < n - 1 ? a + n : -1};
    (*J)[a + (size_t)(n2 + a) * N] = 1.0; (*J)[(n2 + a) + (size_t)a * N] = -1.0;
    (*Q)[a + (size_t)a * N] = 4.01; (*Q)[(n2 + a) + (size_t)(n2 + a) * N] = 1.0;
    (*R)[(n2 + a) + (size_t)(n2 + a) * N] = 0.5 + 0.0401;
    for (d = 0; d < 4; ++d)
      if (nb[d] >= 0) { (*Q)[a + (size_t)nb[d] * N] = -1.0; (*R)[(n2 + a) + (size_t)(n2 + nb[d]) * N] = -0.01; }
  }
  (*B)[n2] = 1.0; (*B)[N + n2 + n2 - 1] = 1.0;
  M[0] = *J; M[1] = *R; M[2] = *Q;
  for (s = 0; s < 3; ++s) {
    int *cp = (int *)calloc((size_t)N + 1, sizeof(int)), *ri = (int *)malloc(sizeof(int) * (size_t)N * N), k = 0;
    double *v = (double *)malloc(sizeof(double) * (size_t)N * N);
    for (j = 0; j < N; ++j) {
      for (i = 0; i < N; ++i)
        if (M[s][i + (size_t)j * N] != 0.0) { ri[k] = i; v[k++] = M[s][i + (size_t)j * N]; }
      cp[j + 1] = k;
    }
    c[s].n_rows = c[s].n_cols = N; c[s].colptr = cp; c[s].rowidx = ri; c[s].values = v;
  }
  CHECK_RC(phgmg_ph_sparse_create(&sp, N, 2, &c[0], &c[1], &c[2], *B, NULL, NULL, NULL), PHGMG_OK);
  return sp;
}
static void b2_free(phgmg_ph_sparse *sp, double *J, double *R, double *Q, double *B, phgmg_csc c[3]) {
  int s;
  phgmg_ph_sparse_destroy(sp);
  for (s = 0; s < 3; ++s) { free((void *)c[s].colptr); free((void *)c[s].rowidx); free((void *)c[s].values); }
  free(J); free(R); free(Q); free(B);
}

/* 1 iff the two models' K, Qh, Bh and V0 are equal bit for bit. */
static int b2_same(const phgmg_reduced *a, const phgmg_reduced *b) {
  const size_t rr = (size_t)a->r * a->r;
  return a->r == b->r && !memcmp(a->K, b->K, sizeof(double) * rr) && !memcmp(a->Qh, b->Qh, sizeof(double) * rr) &&
         !memcmp(a->Bh, b->Bh, sizeof(double) * (size_t)a->r * a->m) &&
         !memcmp(a->V0, b->V0, sizeof(double) * (size_t)a->N * a->r);
}

TEST(test_balanced2_cache) {
  static const int meth[3] = {PHGMG_METHOD_BT, PHGMG_METHOD_PRBT, PHGMG_METHOD_PHBT}, ord[2] = {8, 12};
  double *J, *R, *Q, *B, *J2, *R2, *Q2, *B2;
  phgmg_csc c[3], c2[3];
  phgmg_ph_sparse *sp = b2_lattice(6, &J, &R, &Q, &B, c), *sp2 = b2_lattice(5, &J2, &R2, &Q2, &B2, c2);
  phgmg_balanced_cache cache;
  phgmg_reduced *a = NULL, *b = NULL;
  int i, k;
  memset(&cache, 0, sizeof cache);
  for (i = 0; i < 3; ++i)
    for (k = 0; k < 2; ++k) {
      CHECK_RC(phgmg_balanced_reduce_cached(&a, NULL, sp, meth[i], ord[k], NULL, NULL, 0, NULL, &cache, NULL),
               PHGMG_OK);
      CHECK_RC(phgmg_balanced_reduce(&b, NULL, sp, meth[i], ord[k], NULL, NULL, 0, NULL, NULL), PHGMG_OK);
      CHECK(a && b && b2_same(a, b));
      phgmg_reduced_destroy(a); phgmg_reduced_destroy(b); a = b = NULL;
    }
  CHECK(cache.adi_runs == 2);   /* the controllability and the observability factor, once each */
  CHECK(cache.Zc && cache.Zo && cache.kc > 0 && cache.ko > 0);
  CHECK_RC(phgmg_balanced_reduce_cached(&a, NULL, sp2, PHGMG_METHOD_BT, 8, NULL, NULL, 0, NULL, &cache, NULL),
           PHGMG_ERR_INVALID_ARG);
  CHECK(a == NULL);
  phgmg_balanced_cache_free(&cache, NULL);
  CHECK(cache.Zc == NULL && cache.sp == NULL && cache.adi_runs == 0);
  b2_free(sp, J, R, Q, B, c); b2_free(sp2, J2, R2, Q2, B2, c2);
}

TEST(test_balanced2_phbt_minimal_hamiltonian) {
  enum { r = 8 };
  double *J, *R, *Q, *B, sv[16], se[r], Jr[r * r], Rr[r * r], Qr[r * r], Br[r * 2], S[r * r], w[r];
  phgmg_csc c[3];
  phgmg_ph_sparse *sp = b2_lattice(6, &J, &R, &Q, &B, c);
  phgmg_balanced_info inf;
  phgmg_reduced *a = NULL;
  int i, j;
  CHECK_RC(phgmg_balanced_reduce(&a, NULL, sp, PHGMG_METHOD_PHBT, r, NULL, sv, 16, &inf, NULL), PHGMG_OK);
  CHECK_RC(phgmg_lrphbt(sp, r, NULL, Jr, Rr, Qr, Br, se, NULL, NULL, NULL), PHGMG_OK);   /* against Q */
  CHECK(inf.hmin == 1);
  CHECK(inf.nsv >= r);
  for (i = 0; i < r; ++i) CHECK_LE(sv[i], se[i] * (1.0 + 1e-10));
  CHECK_LE(sv[0], 0.95 * se[0]);   /* 0.7957 against 0.8783 on this lattice (SciPy) */
  if (a) {
    for (j = 0; j < r; ++j)
      for (i = 0; i < r; ++i) S[i + j * r] = a->K[i + j * r] + a->K[j + i * r];
    phgmg_sym_eig(r, S, r, w, NULL, 0);
    CHECK_LE(w[r - 1], 1e-12 * fabs(w[0]));
    for (i = 0; i < r; ++i) CHECK(fabs(a->Qh[i + i * r] * sv[i] - 1.0) <= 1e-12);
  }
  phgmg_reduced_destroy(a);
  b2_free(sp, J, R, Q, B, c);
}

SUITE(balanced2) {
  RUN(test_balanced2_cache);
  RUN(test_balanced2_phbt_minimal_hamiltonian);
}
