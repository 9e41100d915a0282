/* The extended Krylov solver of the low-rank Lyapunov equation
   (phgmg_lrkrylov, opts.solver = PHGMG_LYAP_EKSM; >>lowrank): its factors
   against dense solutions computed here independently (the 2-D heat model
   by the eigen-decomposition of its symmetric A, a mass-spring-damper
   lattice by phgmg_lyap), the reported residual against the residual of Z
   Z^T computed densely, the Hankel singular values of low-rank BT run on
   its factors against the dense ones and against the ADI's, the dual model
   (observability), a model with a mass matrix (a 1-D finite-element
   acoustic model, consistent mass, states scrambled; a lattice with a
   consistent-mass-like E) against the dense Gramians of its E^{-1} model,
   the codes of bad arguments and of algebraic lines, and that zeroed
   options still run the low-rank ADI. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include "lowrank_fixture.h"
#include <stdlib.h>

/* Dense model (column-major, user ordering): J, R, Q, B (N x 2), E (NULL:
   none). */
typedef struct tk_model {
  int N;
  double *J, *R, *Q, *E, *B;
} tk_model;

static void tk_alloc(tk_model *M, int N, int with_e) {
  M->N = N;
  M->J = (double *)calloc((size_t)N * N, sizeof(double));
  M->R = (double *)calloc((size_t)N * N, sizeof(double));
  M->Q = (double *)calloc((size_t)N * N, sizeof(double));
  M->B = (double *)calloc((size_t)N * 2, sizeof(double));
  M->E = with_e ? (double *)calloc((size_t)N * N, sizeof(double)) : NULL;
}

static void tk_free(tk_model *M) { free(M->J); free(M->R); free(M->Q); free(M->E); free(M->B); }

/* The 5-point Dirichlet Laplacian (+ shift on the diagonal) of an n x n
   grid into the n^2 x n^2 block of X at (off, off), leading dimension ld,
   times scale. */
static void tk_lap(double *X, int ld, int off, int n, double shift, double scale) {
  int i, j;
  for (j = 0; j < n; ++j)
    for (i = 0; i < n; ++i) {
      const int a = i + n * j;
      double *c = X + off + (size_t)(off + a) * ld;
      c[a] += scale * (4.0 + shift);
      if (i > 0) c[a - 1] -= scale;
      if (i < n - 1) c[a + 1] -= scale;
      if (j > 0) c[a - n] -= scale;
      if (j < n - 1) c[a + n] -= scale;
    }
}

/* 2-D heat model on an n x n grid: J = 0, R = Laplacian, Q = I, ports on
   the left and the bottom edge. */
static void tk_heat(tk_model *M, int n) {
  const int N = n * n;
  int a;
  tk_alloc(M, N, 0);
  tk_lap(M->R, N, 0, n, 0.0, 1.0);
  for (a = 0; a < N; ++a) M->Q[a + (size_t)a * N] = 1.0;
  for (a = 0; a < n; ++a) { M->B[a * n] = 1.0; M->B[a + (size_t)N] = 1.0; }
}

/* n x n mass-spring-damper lattice, x = (q, p): J = [0 I; -I 0], R = [0 0;
   0 D], Q = [K 0; 0 I], K = Laplacian + 0.01 I, D = d0 I + 0.01 K, forces
   on the corner masses; with_e: a consistent-mass E = [I 0; 0 Mc]. */
static void tk_lattice(tk_model *M, int n, double d0, int with_e) {
  const int n2 = n * n, N = 2 * n2;
  int a;
  tk_alloc(M, N, with_e);
  tk_lap(M->Q, N, 0, n, 0.01, 1.0);
  tk_lap(M->R, N, n2, n, 0.01, 0.01);
  for (a = 0; a < n2; ++a) {
    M->J[a + (size_t)(n2 + a) * N] = 1.0;
    M->J[n2 + a + (size_t)a * N] = -1.0;
    M->Q[n2 + a + (size_t)(n2 + a) * N] = 1.0;
    M->R[n2 + a + (size_t)(n2 + a) * N] += d0;
    if (with_e) { M->E[a + (size_t)a * N] = 1.0; M->E[n2 + a + (size_t)(n2 + a) * N] = 1.1; }
  }
  if (with_e)
    for (a = 0; a + 1 < n2; ++a) M->E[n2 + a + (size_t)(n2 + a + 1) * N] = M->E[n2 + a + 1 + (size_t)(n2 + a) * N] = 0.01;
  M->B[n2] = 1.0;
  M->B[n2 + n2 - 1 + (size_t)N] = 1.0;
}

/* 1-D acoustic model in P1 finite elements on n nodes of [0, 1] (interior
   nodes moved by up to 0.3 h), x = (p, v): E = blkdiag(M, M) (M the
   consistent mass matrix), Q = blkdiag(2 I, 0.5 I) (E^T Q symmetric), J =
   [0, D^T; -D, 0] with D(i, j) = int phi_i phi_j', R = 0.05 E + 1e-3
   blkdiag(K, K) (K the stiffness), two ports M g in the pressure equation
   (g a hat over [0.1, 0.5] and the left half of [0.4, 1]); then the
   states put in a scrambled order (the same permutation of rows and
   columns of every matrix, of B's rows). */
static void tk_fe_acoustic(tk_model *M, int n) {
  const int N = 2 * n;
  double *x = (double *)malloc(sizeof(double) * (size_t)n), g[2];
  int *perm = (int *)malloc(sizeof(int) * (size_t)N), e, a, b, i, j, c;
  unsigned seed = 12345u;
  tk_model W;
  tk_alloc(&W, N, 1);
  for (i = 0; i < n; ++i) {
    x[i] = (double)i / (n - 1);
    seed = seed * 1103515245u + 12345u;
    if (i > 0 && i < n - 1) x[i] += 0.3 / (n - 1) * (((double)((seed >> 16) & 1023u) / 1023.0) * 2.0 - 1.0);
  }
  for (e = 0; e + 1 < n; ++e) {
    const double h = x[e + 1] - x[e], Me[2][2] = {{h / 3, h / 6}, {h / 6, h / 3}};
    const double De[2][2] = {{-0.5, 0.5}, {-0.5, 0.5}}, Ke[2][2] = {{1 / h, -1 / h}, {-1 / h, 1 / h}};
    for (a = 0; a < 2; ++a)
      for (b = 0; b < 2; ++b) {
        const int r = e + a, q = e + b;
        for (c = 0; c < 2; ++c) {
          const int o = c * n;
          W.E[o + r + (size_t)(o + q) * N] += Me[a][b];
          W.R[o + r + (size_t)(o + q) * N] += 0.05 * Me[a][b] + 1e-2 * Ke[a][b];
        }
        W.J[r + (size_t)(n + q) * N] += De[b][a];      /* D^T */
        W.J[n + r + (size_t)q * N] -= De[a][b];        /* -D  */
      }
  }
  for (i = 0; i < n; ++i) { W.Q[i + (size_t)i * N] = 2.0; W.Q[n + i + (size_t)(n + i) * N] = 0.5; }
  for (i = 0; i < n; ++i) {
    g[0] = x[i] > 0.1 && x[i] < 0.5 ? 1.0 - fabs(x[i] - 0.3) / 0.2 : 0.0;
    g[1] = x[i] > 0.4 && x[i] < 0.7 ? 1.0 - fabs(x[i] - 0.7) / 0.3 : 0.0;
    for (c = 0; c < 2; ++c)
      for (j = 0; j < n; ++j) W.B[j + (size_t)c * N] += W.E[j + (size_t)i * N] * g[c];
  }
  for (i = 0; i < N; ++i) perm[i] = i;
  for (i = N - 1; i > 0; --i) { /* Fisher-Yates with a fixed LCG */
    int t;
    seed = seed * 1103515245u + 12345u;
    j = (int)((seed >> 8) % (unsigned)(i + 1));
    t = perm[i]; perm[i] = perm[j]; perm[j] = t;
  }
  tk_alloc(M, N, 1);
  for (j = 0; j < N; ++j) {
    for (i = 0; i < N; ++i) {
      const size_t d = (size_t)i + (size_t)j * N, s0 = (size_t)perm[i] + (size_t)perm[j] * N;
      M->J[d] = W.J[s0]; M->R[d] = W.R[s0]; M->Q[d] = W.Q[s0]; M->E[d] = W.E[s0];
    }
  }
  for (c = 0; c < 2; ++c)
    for (i = 0; i < N; ++i) M->B[i + (size_t)c * N] = W.B[perm[i] + (size_t)c * N];
  tk_free(&W);
  free(x); free(perm);
}

static phgmg_ph_sparse *tk_sparse(const tk_model *M) {
  phgmg_ph_sparse *sp = NULL;
  phgmg_csc J = th_dense_csc(M->N, M->J), R = th_dense_csc(M->N, M->R), Q = th_dense_csc(M->N, M->Q), E;
  if (M->E) E = th_dense_csc(M->N, M->E);
  CHECK_RC(phgmg_ph_sparse_create_e(&sp, M->N, 2, &J, &R, &Q, M->E ? &E : NULL, M->B, NULL, NULL, NULL), PHGMG_OK);
  th_csc_free(&J); th_csc_free(&R); th_csc_free(&Q);
  if (M->E) th_csc_free(&E);
  return sp;
}

/* A = (J - R) Q (dense). */
static double *tk_dense_a(const tk_model *M) {
  const int N = M->N;
  double *JR = (double *)malloc(sizeof(double) * (size_t)N * N), *A = (double *)malloc(sizeof(double) * (size_t)N * N);
  int i;
  for (i = 0; i < N * N; ++i) JR[i] = M->J[i] - M->R[i];
  phgmg_gemm('N', 'N', N, N, N, 1.0, JR, N, M->Q, N, 0.0, A, N);
  free(JR);
  return A;
}

/* The dense Gramians of a model with a mass matrix through its E^{-1}
   model (A' = E^{-1} A, B' = E^{-1} B, C = B^T Q; phgmg_lyap): P solves A
   P E^T + E P A^T + B B^T = 0, O' = E^T O E the E^{-1} model's
   observability Gramian, so that the Hankel singular values are sqrt(eig(P
   O')); A (N x N) returns (J - R) Q. */
static void tk_dense_e_gramians(const tk_model *M, double *A, double *P, double *O) {
  const int N = M->N;
  double *Ap = (double *)malloc(sizeof(double) * (size_t)N * N), *F = (double *)malloc(sizeof(double) * (size_t)N * N);
  double *LU = (double *)malloc(sizeof(double) * (size_t)N * N), *Bp = (double *)malloc(sizeof(double) * (size_t)N * 2);
  double *C = (double *)malloc(sizeof(double) * (size_t)N * 2), *A0 = tk_dense_a(M);
  int *ip = (int *)malloc(sizeof(int) * (size_t)N), i, j;
  memcpy(A, A0, sizeof(double) * (size_t)N * N);
  memcpy(Ap, A0, sizeof(double) * (size_t)N * N);
  memcpy(Bp, M->B, sizeof(double) * (size_t)N * 2);
  memcpy(LU, M->E, sizeof(double) * (size_t)N * N);
  CHECK_RC(phgmg_lu_factor(N, LU, N, ip), PHGMG_OK);
  phgmg_lu_solve('N', N, LU, N, ip, N, Ap, N);
  phgmg_lu_solve('N', N, LU, N, ip, 2, Bp, N);
  phgmg_gemm('N', 'T', N, N, 2, 1.0, Bp, N, Bp, N, 0.0, F, N);
  CHECK_RC(phgmg_lyap(N, Ap, F, P, NULL, NULL), PHGMG_OK);
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) A0[i + (size_t)j * N] = Ap[j + (size_t)i * N];
  phgmg_gemm('T', 'N', N, 2, N, 1.0, M->Q, N, M->B, N, 0.0, C, N);   /* C^T = Q^T B */
  phgmg_gemm('N', 'T', N, N, 2, 1.0, C, N, C, N, 0.0, F, N);
  CHECK_RC(phgmg_lyap(N, A0, F, O, NULL, NULL), PHGMG_OK);
  free(Ap); free(F); free(LU); free(Bp); free(C); free(A0); free(ip);
}

/* The heat model's Gramian by the eigen-decomposition of R = U diag(l) U^T
   (A = -R symmetric): P = U Pt U^T, Pt_ij = (U^T B B^T U)_ij / (l_i + l_j). */
static double *tk_heat_gramian(const tk_model *M) {
  const int N = M->N;
  double *U = (double *)malloc(sizeof(double) * (size_t)N * N), *T = (double *)malloc(sizeof(double) * (size_t)N * N);
  double *P = (double *)malloc(sizeof(double) * (size_t)N * N), *l = (double *)malloc(sizeof(double) * (size_t)N);
  double *C = (double *)malloc(sizeof(double) * (size_t)N * 2);
  int i, j;
  memcpy(T, M->R, sizeof(double) * (size_t)N * N);
  CHECK_RC(phgmg_sym_eig(N, T, N, l, U, N), PHGMG_OK);
  phgmg_gemm('T', 'N', N, 2, N, 1.0, U, N, M->B, N, 0.0, C, N);
  phgmg_gemm('N', 'T', N, N, 2, 1.0, C, N, C, N, 0.0, P, N);
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) P[i + (size_t)j * N] /= l[i] + l[j];
  phgmg_gemm('N', 'N', N, N, N, 1.0, U, N, P, N, 0.0, T, N);
  phgmg_gemm('N', 'T', N, N, N, 1.0, T, N, U, N, 0.0, P, N);
  free(U); free(T); free(l); free(C);
  return P;
}

/* Low-rank BT's first r Hankel singular values with the solver `solver`. */
static void tk_lrbt_hsv(phgmg_ph_sparse *sp, int solver, int r, double *hsv, phgmg_lrbt_info *inf) {
  double *Ar = (double *)malloc(sizeof(double) * (size_t)r * r), *Br = (double *)malloc(sizeof(double) * (size_t)r * 2);
  double *Cr = (double *)malloc(sizeof(double) * (size_t)r * 2);
  phgmg_lradi_opts o;
  memset(&o, 0, sizeof o);
  o.solver = solver;
  CHECK_RC(phgmg_lrbt(sp, r, &o, Ar, Br, Cr, hsv, NULL, NULL, inf, NULL), PHGMG_OK);
  free(Ar); free(Br); free(Cr);
}

/* The residual EKSM reports (phgmg_lradi with solver EKSM) at a tolerance
   tol well above round-off, against the dense residual of its Z Z^T in
   A P E^T + E P A^T + B B^T = 0 (A dense, E = M->E or I): within 2 %. */
static void tk_check_residual(phgmg_shifted *s, phgmg_ph_sparse *sp, const tk_model *M, const double *A, double tol) {
  phgmg_lradi_opts o;
  phgmg_lradi_info inf;
  double *Z = NULL, *Plr, res;
  int k = 0;
  memset(&o, 0, sizeof o);
  o.solver = PHGMG_LYAP_EKSM; o.tol = tol;
  CHECK_RC(phgmg_lradi(s, 2, phgmg_ph_sparse_system(sp)->B, M->N, &o, &Z, &k, &inf, NULL), PHGMG_OK);
  CHECK(inf.solver == PHGMG_LYAP_EKSM && inf.res <= tol && inf.res > 1e-12);
  if (!Z) return;
  Plr = th_gram_user(sp, M->N, Z, k);
  res = th_lyap_res(M->N, 2, A, M->E, M->B, Plr);
  CHECK_LE(fabs(res - inf.res), 0.02 * inf.res);
  free(Plr);
  phgmg_lowrank_free(Z, NULL);
}

/* Low-rank BT's first r (<= 32) Hankel singular values by EKSM against
   ref (dense, descending) and against the ADI's, each within 1e-8 of the
   largest; the two runs' infos in bi, ba for the caller's checks. */
static void tk_check_bt(phgmg_ph_sparse *sp, int r, const double *ref, phgmg_lrbt_info *bi, phgmg_lrbt_info *ba) {
  double hsv[32], hsva[32];
  int i;
  tk_lrbt_hsv(sp, PHGMG_LYAP_EKSM, r, hsv, bi);
  tk_lrbt_hsv(sp, PHGMG_LYAP_ADI, r, hsva, ba);
  for (i = 0; i < r; ++i) {
    CHECK_LE(fabs(hsv[i] - ref[i]), 1e-8 * ref[0]);
    CHECK_LE(fabs(hsv[i] - hsva[i]), 1e-8 * hsva[0]);
  }
}

/* EKSM on the 16 x 16 heat model (N = 256; A = -R is regular: the inverse
   directions are A^{-1}, one factorization): Z Z^T against the dense
   Gramian, the reported residual (a run at tol 1e-7, so that it stands
   above the dense computation's round-off) against the dense residual of
   its Z Z^T; BT's Hankel singular values (J = 0, Q = I: O = P, sigma =
   eig(P)) against the dense values and the ADI's. */
TEST(test_eksm_heat) {
  enum { r = 12 };
  tk_model M;
  phgmg_ph_sparse *sp;
  phgmg_shifted *s = NULL;
  phgmg_lradi_info inf;
  phgmg_lradi_opts o;
  phgmg_lrbt_info bi, ba;
  double *A, *P, *Plr, *Z = NULL, *w, hsvd[r];
  int N, k = 0, i;
  tk_heat(&M, 16);
  N = M.N;
  A = tk_dense_a(&M);
  P = tk_heat_gramian(&M);
  sp = tk_sparse(&M);
  memset(&o, 0, sizeof o);
  o.solver = PHGMG_LYAP_EKSM;
  CHECK_RC(phgmg_shifted_create(&s, sp, 0, 0, NULL), PHGMG_OK);
  CHECK_RC(phgmg_lrkrylov(s, 2, phgmg_ph_sparse_system(sp)->B, N, NULL, &Z, &k, &inf, NULL), PHGMG_OK);
  CHECK(inf.solver == PHGMG_LYAP_EKSM && inf.shift == 0.0 && inf.factorizations == 1);
  CHECK(inf.res <= 1e-10 && inf.iters > 1 && inf.rank == k && k <= inf.cols && k < N);
  Plr = th_gram_user(sp, N, Z, k);
  CHECK_LE(th_reldiff(N * N, Plr, P), 1e-8);
  free(Plr); phgmg_lowrank_free(Z, NULL); Z = NULL;
  /* the residual, at a tolerance whose residual is far above round-off */
  tk_check_residual(s, sp, &M, A, 1e-7);
  /* BT: sigma = eig(P) */
  w = (double *)malloc(sizeof(double) * (size_t)N);
  CHECK_RC(phgmg_sym_eig(N, P, N, w, NULL, N), PHGMG_OK);
  for (i = 0; i < r; ++i) hsvd[i] = w[N - 1 - i];
  tk_check_bt(sp, r, hsvd, &bi, &ba);
  CHECK(bi.ctrl.solver == PHGMG_LYAP_EKSM && ba.ctrl.solver == PHGMG_LYAP_ADI && bi.nhsv > r);
  free(w);
  phgmg_shifted_destroy(s); phgmg_ph_sparse_destroy(sp);
  free(A); free(P);
  tk_free(&M);
}

/* EKSM on the 7 x 7 lattice (N = 98, J != 0, Q != I; complex spectrum):
   the static pivots refuse A itself (zero diagonal on the positions), so
   the inverse directions use a real shift p < 0; Z Z^T and the dual
   model's Q Zy Zy^T Q against phgmg_lyap's dense Gramians, the residual
   (tol 1e-4 run) against the dense one, BT's Hankel singular values
   against the dense ones and the ADI's. */
TEST(test_eksm_lattice) {
  enum { r = 8 };
  tk_model M;
  phgmg_ph_sparse *sp;
  phgmg_shifted *s = NULL, *sd = NULL;
  phgmg_lradi_info inf;
  phgmg_lradi_opts o;
  phgmg_lrbt_info bi, ba;
  double *A, *At, *F, *P, *O, *T, *Plr, *Z = NULL, hsvd[r];
  int N, k = 0, i, j;
  tk_lattice(&M, 7, 0.5, 0);
  N = M.N;
  A = tk_dense_a(&M);
  At = (double *)malloc(sizeof(double) * (size_t)N * N); F = (double *)malloc(sizeof(double) * (size_t)N * N);
  P = (double *)malloc(sizeof(double) * (size_t)N * N); O = (double *)malloc(sizeof(double) * (size_t)N * N);
  T = (double *)malloc(sizeof(double) * (size_t)N * N);
  phgmg_gemm('N', 'T', N, N, 2, 1.0, M.B, N, M.B, N, 0.0, F, N);
  CHECK_RC(phgmg_lyap(N, A, F, P, NULL, NULL), PHGMG_OK);
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) At[i + (size_t)j * N] = A[j + (size_t)i * N];
  phgmg_gemm('N', 'N', N, 2, N, 1.0, M.Q, N, M.B, N, 0.0, T, N);      /* C^T = Q B */
  phgmg_gemm('N', 'T', N, N, 2, 1.0, T, N, T, N, 0.0, F, N);
  CHECK_RC(phgmg_lyap(N, At, F, O, NULL, NULL), PHGMG_OK);
  sp = tk_sparse(&M);
  memset(&o, 0, sizeof o);
  o.solver = PHGMG_LYAP_EKSM;
  CHECK_RC(phgmg_shifted_create(&s, sp, 0, 0, NULL), PHGMG_OK);
  CHECK_RC(phgmg_lradi(s, 2, phgmg_ph_sparse_system(sp)->B, N, &o, &Z, &k, &inf, NULL), PHGMG_OK);
  CHECK(inf.solver == PHGMG_LYAP_EKSM && inf.shift < 0.0 && inf.res <= 1e-10 && inf.rank == k && k < N);
  Plr = th_gram_user(sp, N, Z, k);
  CHECK_LE(th_reldiff(N * N, Plr, P), 1e-8);
  free(Plr); phgmg_lowrank_free(Z, NULL); Z = NULL;
  /* observability: the dual model's factor, O = Q Zy Zy^T Q */
  CHECK_RC(phgmg_shifted_create(&sd, sp, 1, 0, NULL), PHGMG_OK);
  CHECK_RC(phgmg_lradi(sd, 2, phgmg_ph_sparse_system(sp)->B, N, &o, &Z, &k, &inf, NULL), PHGMG_OK);
  Plr = th_gram_user(sp, N, Z, k);
  phgmg_gemm('N', 'N', N, N, N, 1.0, M.Q, N, Plr, N, 0.0, T, N);
  phgmg_gemm('N', 'N', N, N, N, 1.0, T, N, M.Q, N, 0.0, Plr, N);
  CHECK_LE(th_reldiff(N * N, Plr, O), 1e-8);
  free(Plr); phgmg_lowrank_free(Z, NULL); Z = NULL;
  /* the residual at tol 1e-4 */
  tk_check_residual(s, sp, &M, A, 1e-4);
  /* balanced truncation */
  th_dense_hsv(N, P, O, hsvd, r);
  tk_check_bt(sp, r, hsvd, &bi, &ba);
  CHECK(bi.ctrl.solver == PHGMG_LYAP_EKSM && bi.obs.solver == PHGMG_LYAP_EKSM && bi.obs.res <= 1e-10);
  phgmg_shifted_destroy(s); phgmg_shifted_destroy(sd); phgmg_ph_sparse_destroy(sp);
  free(A); free(At); free(F); free(P); free(O); free(T);
  tk_free(&M);
}

/* A mass matrix: the P1 acoustic model (N = 160, consistent mass, Q != I,
   states scrambled; A regular, so the inverse directions are A^{-1} E: one
   factorization of A, one of E). Z Z^T against the dense Gramian of the
   E^{-1} model, the residual of the generalized equation (tol 1e-7 run)
   against the dense one with E, BT's Hankel singular values against the
   dense ones and the ADI's. */
TEST(test_eksm_mass_fe) {
  enum { r = 10 };
  tk_model M;
  phgmg_ph_sparse *sp;
  phgmg_shifted *s = NULL;
  phgmg_lradi_info inf;
  phgmg_lradi_opts o;
  phgmg_lrbt_info bi, ba;
  double *A, *P, *O, *Plr, *Z = NULL, hsvd[r];
  int N, k = 0;
  tk_fe_acoustic(&M, 80);
  N = M.N;
  A = (double *)malloc(sizeof(double) * (size_t)N * N);
  P = (double *)malloc(sizeof(double) * (size_t)N * N); O = (double *)malloc(sizeof(double) * (size_t)N * N);
  tk_dense_e_gramians(&M, A, P, O);
  sp = tk_sparse(&M);
  memset(&o, 0, sizeof o);
  o.solver = PHGMG_LYAP_EKSM;
  CHECK_RC(phgmg_shifted_create(&s, sp, 0, 0, NULL), PHGMG_OK);
  CHECK_RC(phgmg_lradi(s, 2, phgmg_ph_sparse_system(sp)->B, N, &o, &Z, &k, &inf, NULL), PHGMG_OK);
  CHECK(inf.solver == PHGMG_LYAP_EKSM && inf.shift == 0.0 && inf.factorizations == 2);
  CHECK(inf.res <= 1e-10 && inf.rank == k && k <= inf.cols && inf.cols < N);
  Plr = th_gram_user(sp, N, Z, k);
  CHECK_LE(th_reldiff(N * N, Plr, P), 1e-8);
  free(Plr); phgmg_lowrank_free(Z, NULL); Z = NULL;
  /* the residual of A P E^T + E P A^T + B B^T (tol 1e-5: far above round-off) */
  tk_check_residual(s, sp, &M, A, 1e-5);
  /* balanced truncation (two EKSM runs: J != 0) */
  th_dense_hsv(N, P, O, hsvd, r);
  tk_check_bt(sp, r, hsvd, &bi, &ba);
  CHECK(bi.ctrl.solver == PHGMG_LYAP_EKSM && bi.obs.solver == PHGMG_LYAP_EKSM && bi.obs.res <= 1e-10);
  phgmg_shifted_destroy(s); phgmg_ph_sparse_destroy(sp);
  free(A); free(P); free(O);
  tk_free(&M);
}

/* A mass matrix and a refused A: the 8 x 8 lattice with E = [I 0; 0 Mc]
   (Mc tridiagonal): the inverse directions (A + p E)^{-1} E with the
   pencil's Ritz value p < 0; Z Z^T and the Hankel singular values against
   the dense E^{-1} model's, and the values against the ADI's. */
TEST(test_eksm_mass_lattice) {
  enum { r = 8 };
  tk_model M;
  phgmg_ph_sparse *sp;
  phgmg_shifted *s = NULL;
  phgmg_lradi_info inf;
  phgmg_lradi_opts o;
  phgmg_lrbt_info bi, ba;
  double *A, *P, *O, *Plr, *Z = NULL, hsvd[r];
  int N, k = 0;
  tk_lattice(&M, 8, 0.5, 1);
  N = M.N;
  A = (double *)malloc(sizeof(double) * (size_t)N * N);
  P = (double *)malloc(sizeof(double) * (size_t)N * N); O = (double *)malloc(sizeof(double) * (size_t)N * N);
  tk_dense_e_gramians(&M, A, P, O);
  sp = tk_sparse(&M);
  memset(&o, 0, sizeof o);
  o.solver = PHGMG_LYAP_EKSM;
  CHECK_RC(phgmg_shifted_create(&s, sp, 0, 0, NULL), PHGMG_OK);
  CHECK_RC(phgmg_lradi(s, 2, phgmg_ph_sparse_system(sp)->B, N, &o, &Z, &k, &inf, NULL), PHGMG_OK);
  CHECK(inf.solver == PHGMG_LYAP_EKSM && inf.shift < 0.0 && inf.factorizations == 3 && inf.res <= 1e-10);
  CHECK(inf.rank == k && inf.cols < N); /* converged before the basis filled the space */
  Plr = th_gram_user(sp, N, Z, k);
  CHECK_LE(th_reldiff(N * N, Plr, P), 1e-8);
  free(Plr); phgmg_lowrank_free(Z, NULL);
  th_dense_hsv(N, P, O, hsvd, r);
  tk_check_bt(sp, r, hsvd, &bi, &ba);
  CHECK(bi.ctrl.solver == PHGMG_LYAP_EKSM && bi.obs.res <= 1e-10);
  phgmg_shifted_destroy(s); phgmg_ph_sparse_destroy(sp);
  free(A); free(P); free(O);
  tk_free(&M);
}

/* Bad arguments and the documented codes: NULL, m < 1, ldb < N, a solver
   value out of range, B = 0 (_RANK), NaN in B (_NANINF), maxit blocks too
   few (_NOT_CONVERGED, the residual reached in info, no factor), an E
   with algebraic lines (a massless node: index one, _UNSUPPORTED); zeroed
   options run the ADI (the same factor as NULL options). */
TEST(test_eksm_arguments) {
  tk_model M, Me;
  phgmg_ph_sparse *sp, *spe;
  phgmg_shifted *s = NULL, *se = NULL;
  phgmg_lradi_info inf;
  phgmg_lradi_opts o;
  double *Z = NULL, *Z2 = NULL, *B0;
  const double *B, *Be;
  int N, k = 0, k2 = 0;
  size_t i;
  tk_lattice(&M, 4, 0.5, 0);
  tk_lattice(&Me, 4, 0.5, 1);
  N = M.N;
  for (i = 0; i < (size_t)N; ++i) /* the momentum of node 5 without mass: an algebraic line */
    Me.E[i + (size_t)(16 + 5) * N] = Me.E[16 + 5 + i * N] = 0.0;
  sp = tk_sparse(&M);
  spe = tk_sparse(&Me);
  CHECK_RC(phgmg_shifted_create(&s, sp, 0, 0, NULL), PHGMG_OK);
  CHECK_RC(phgmg_shifted_create(&se, spe, 0, 0, NULL), PHGMG_OK);
  B = phgmg_ph_sparse_system(sp)->B;     /* internal order */
  Be = phgmg_ph_sparse_system(spe)->B;
  memset(&o, 0, sizeof o);
  o.solver = PHGMG_LYAP_EKSM;
  CHECK_RC(phgmg_lrkrylov(NULL, 2, B, N, NULL, &Z, &k, &inf, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_lrkrylov(s, 0, B, N, NULL, &Z, &k, &inf, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_lrkrylov(s, 2, B, N - 1, NULL, &Z, &k, &inf, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_lrkrylov(s, 2, NULL, N, NULL, &Z, &k, &inf, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_lrkrylov(s, 2, B, N, NULL, NULL, &k, &inf, NULL), PHGMG_ERR_INVALID_ARG);
  o.solver = 2;
  CHECK_RC(phgmg_lradi(s, 2, B, N, &o, &Z, &k, &inf, NULL), PHGMG_ERR_INVALID_ARG);
  o.solver = -1;
  CHECK_RC(phgmg_lradi(s, 2, B, N, &o, &Z, &k, &inf, NULL), PHGMG_ERR_INVALID_ARG);
  o.solver = PHGMG_LYAP_EKSM;
  o.tol = 1.0;
  CHECK_RC(phgmg_lradi(s, 2, B, N, &o, &Z, &k, &inf, NULL), PHGMG_ERR_INVALID_ARG);
  o.tol = 0.0;
  B0 = (double *)calloc((size_t)N * 2, sizeof(double));
  CHECK_RC(phgmg_lrkrylov(s, 2, B0, N, NULL, &Z, &k, &inf, NULL), PHGMG_ERR_RANK);
  B0[3] = NAN;
  CHECK_RC(phgmg_lrkrylov(s, 2, B0, N, NULL, &Z, &k, &inf, NULL), PHGMG_ERR_NANINF);
  o.maxit = 2;
  CHECK_RC(phgmg_lrkrylov(s, 2, B, N, &o, &Z, &k, &inf, NULL), PHGMG_ERR_NOT_CONVERGED);
  CHECK(Z == NULL && k == 0 && inf.iters == 2 && inf.res > 1e-10 && inf.rank == 0);
  o.maxit = 0;
  CHECK_RC(phgmg_lrkrylov(se, 2, Be, N, &o, &Z, &k, &inf, NULL), PHGMG_ERR_UNSUPPORTED);
  CHECK(Z == NULL && k == 0);
  CHECK_RC(phgmg_lradi(se, 2, Be, N, &o, &Z, &k, &inf, NULL), PHGMG_ERR_UNSUPPORTED);
  /* zeroed options: the ADI, as with NULL */
  memset(&o, 0, sizeof o);
  CHECK_RC(phgmg_lradi(s, 2, B, N, &o, &Z, &k, &inf, NULL), PHGMG_OK);
  CHECK(inf.solver == PHGMG_LYAP_ADI && inf.shift_sets > 0);
  CHECK_RC(phgmg_lradi(s, 2, B, N, NULL, &Z2, &k2, NULL, NULL), PHGMG_OK);
  CHECK(k == k2);
  for (i = 0; k == k2 && i < (size_t)N * (size_t)k; ++i) CHECK(Z[i] == Z2[i]);
  phgmg_lowrank_free(Z, NULL); phgmg_lowrank_free(Z2, NULL);
  free(B0);
  phgmg_shifted_destroy(s); phgmg_shifted_destroy(se);
  phgmg_ph_sparse_destroy(sp); phgmg_ph_sparse_destroy(spe);
  tk_free(&M); tk_free(&Me);
}

SUITE(eksm) {
  RUN(test_eksm_heat);
  RUN(test_eksm_lattice);
  RUN(test_eksm_mass_fe);
  RUN(test_eksm_mass_lattice);
  RUN(test_eksm_arguments);
}
