/* Low-rank Gramians and balanced truncation of sparse pH models (>>lowrank):
   the shifted sparse solves against dense complex solves, LR-ADI's factors
   against the dense Lyapunov solutions (with the residual recomputed here),
   low-rank BT's Hankel singular values against the dense Gramians' and its reduced
   model's sampled H-infinity error against the bound, a model with a mass
   matrix against the dense solution of the equivalent E^{-1} model, an
   index-one model with a port on a constraint: its feedthrough against the
   closed form and the descriptor model's own transfer function. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include "lowrank_fixture.h"
#include <stdlib.h>

/* A 2-D mass-spring-damper lattice (n x n unit masses, x = (q, p), N =
   2 n^2): J = [0 I; -I 0], R = [0 0; 0 D], Q = [K 0; 0 I] with K the 2-D
   Dirichlet Laplacian + 0.01 I, D = 0.5 I + 0.01 K; ports: forces on the
   corner masses (0, 0) and (n-1, n-1). With consistent = 1 also the mass
   matrix E = [I 0; 0 Mc], Mc = I + 0.1 (4 I + the grid's adjacency) / 8 (SPD,
   the mesh's pattern; E^T Q = [K 0; 0 Mc] symmetric positive definite).
   Dense, column-major, user ordering. */
typedef struct lr_model {
  int n, N, m;
  double *J, *R, *Q, *E, *B; /* E NULL without mass matrix */
} lr_model;

static void lr_lattice(lr_model *M, int n, int consistent) {
  const int n2 = n * n, N = 2 * n2;
  int i, j, a;
  double *K = (double *)calloc((size_t)n2 * n2, sizeof(double));
  M->n = n; M->N = N; M->m = 2;
  M->J = (double *)calloc((size_t)N * N, sizeof(double));
  M->R = (double *)calloc((size_t)N * N, sizeof(double));
  M->Q = (double *)calloc((size_t)N * N, sizeof(double));
  M->B = (double *)calloc((size_t)N * 2, sizeof(double));
  M->E = consistent ? (double *)calloc((size_t)N * N, sizeof(double)) : NULL;
  for (i = 0; i < n; ++i)
    for (j = 0; j < n; ++j) {
      a = i + n * j;
      K[a + (size_t)a * n2] = 4.0 + 0.01;
      if (i > 0) K[a + (size_t)(a - 1) * n2] = -1.0;
      if (i < n - 1) K[a + (size_t)(a + 1) * n2] = -1.0;
      if (j > 0) K[a + (size_t)(a - n) * n2] = -1.0;
      if (j < n - 1) K[a + (size_t)(a + n) * n2] = -1.0;
    }
  for (a = 0; a < n2; ++a) {
    int b;
    M->J[a + (size_t)(n2 + a) * N] = 1.0;
    M->J[n2 + a + (size_t)a * N] = -1.0;
    M->Q[n2 + a + (size_t)(n2 + a) * N] = 1.0;
    if (M->E) M->E[a + (size_t)a * N] = 1.0;
    for (b = 0; b < n2; ++b) {
      double k = K[a + (size_t)b * n2];
      M->Q[a + (size_t)b * N] = k;
      M->R[n2 + a + (size_t)(n2 + b) * N] = 0.01 * k + (a == b ? 0.5 : 0.0);
      if (M->E && k != 0.0) M->E[n2 + a + (size_t)(n2 + b) * N] = (a == b ? 1.0 + 0.05 : 0.0125 * (k < 0.0));
    }
  }
  M->B[n2 + 0] = 1.0;
  M->B[n2 + n2 - 1 + (size_t)N] = 1.0;
  free(K);
}

static void lr_free(lr_model *M) { free(M->J); free(M->R); free(M->Q); free(M->E); free(M->B); }


static phgmg_ph_sparse *lr_sparse(const lr_model *M) {
  phgmg_ph_sparse *sp = NULL;
  phgmg_csc J = th_dense_csc(M->N, M->J), R = th_dense_csc(M->N, M->R), Q = th_dense_csc(M->N, M->Q), E;
  if (M->E) E = th_dense_csc(M->N, M->E);
  CHECK_RC(phgmg_ph_sparse_create_e(&sp, M->N, M->m, &J, &R, &Q, M->E ? &E : NULL, M->B, NULL, NULL, NULL),
           PHGMG_OK);
  th_csc_free(&J); th_csc_free(&R); th_csc_free(&Q);
  if (M->E) th_csc_free(&E);
  return sp;
}

/* Dense A = (J - R) Q, and for a mass matrix A' = E^{-1} A, B' = E^{-1} B
   (into A, Bp); C = B^T Q. */
static void lr_dense_abc(const lr_model *M, double *A, double *Bp, double *C) {
  const int N = M->N, m = M->m;
  double *JR = (double *)malloc(sizeof(double) * (size_t)N * N);
  int i;
  for (i = 0; i < N * N; ++i) JR[i] = M->J[i] - M->R[i];
  phgmg_gemm('N', 'N', N, N, N, 1.0, JR, N, M->Q, N, 0.0, A, N);
  memcpy(Bp, M->B, sizeof(double) * (size_t)N * m);
  if (M->E) {
    int *ip = (int *)malloc(sizeof(int) * (size_t)N);
    memcpy(JR, M->E, sizeof(double) * (size_t)N * N);
    CHECK_RC(phgmg_lu_factor(N, JR, N, ip), PHGMG_OK);
    phgmg_lu_solve('N', N, JR, N, ip, N, A, N);
    phgmg_lu_solve('N', N, JR, N, ip, m, Bp, N);
    free(ip);
  }
  phgmg_gemm('T', 'N', m, N, N, 1.0, M->B, N, M->Q, N, 0.0, C, m);
  free(JR);
}

/* Dense Gramians P (A P + P A^T + B B^T = 0) and O (A^T O + O A + C^T C = 0)
   of the (E^{-1}) model. */
static void lr_dense_gramians(const lr_model *M, double *A, double *Bp, double *C, double *P, double *O) {
  const int N = M->N, m = M->m;
  double *F = (double *)malloc(sizeof(double) * (size_t)N * N), *At = (double *)malloc(sizeof(double) * (size_t)N * N);
  int i, j;
  lr_dense_abc(M, A, Bp, C);
  phgmg_gemm('N', 'T', N, N, m, 1.0, Bp, N, Bp, N, 0.0, F, N);
  CHECK_RC(phgmg_lyap(N, A, F, P, NULL, NULL), PHGMG_OK);
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) At[i + (size_t)j * N] = A[j + (size_t)i * N];
  phgmg_gemm('T', 'N', N, N, m, 1.0, C, m, C, m, 0.0, F, N);
  CHECK_RC(phgmg_lyap(N, At, F, O, NULL, NULL), PHGMG_OK);
  free(F); free(At);
}

/* The reduced model's sampled H-infinity error against the full (E^{-1})
   model's, by dense complex solves (phgmg_ss_error), on nw frequencies in
   [1e-2, 1e2]; the same through the sparse model's shifted solves
   (phgmg_shifted_hinf) must agree, error and norm. */
static double lr_hinf(const lr_model *M, phgmg_ph_sparse *sp, int r, const double *Ar, const double *Br,
                      const double *Cr, int nw) {
  const int N = M->N;
  double *A = (double *)malloc(sizeof(double) * (size_t)N * N), *Bp = (double *)malloc(sizeof(double) * (size_t)N * 2);
  double *C = (double *)malloc(sizeof(double) * (size_t)N * 2), hinf = 0.0, href = 0.0, hs = 0.0, hsr = 0.0;
  phgmg_shifted *s = NULL;
  lr_dense_abc(M, A, Bp, C);
  CHECK_RC(phgmg_ss_error(N, A, Bp, C, r, Ar, Br, Cr, 2, 2, nw, 1e-2, 1e2, &hinf, &href, NULL, NULL, NULL),
           PHGMG_OK);
  CHECK_RC(phgmg_shifted_create(&s, sp, 0, 0, NULL), PHGMG_OK);
  CHECK_RC(phgmg_shifted_hinf(s, r, Ar, Br, Cr, nw, 1e-2, 1e2, &hs, &hsr), PHGMG_OK);
  CHECK_LE(fabs(hs - hinf), 1e-9 * href);
  CHECK_LE(fabs(hsr - href), 1e-10 * href);
  CHECK(phgmg_shifted_factorizations(s) == nw);
  phgmg_shifted_destroy(s);
  free(A); free(Bp); free(C);
  return hinf;
}

/* pH-preserving low-rank balancing of the model: the values against sd,
   the dense Gramian's sqrt(eig(P E^T Q)) (the first r), the structure (Jr
   skew exactly, Rr symmetric positive semidefinite, Qr diagonal positive),
   the reduced model passive on sampled frequencies; returns its sampled
   H-infinity error relative to the model's norm. */
static double lr_check_phbt(phgmg_ph_sparse *sp, const double *sd, int r) {
  double *Jr = (double *)malloc(sizeof(double) * (size_t)r * r), *Rr = (double *)malloc(sizeof(double) * (size_t)r * r);
  double *Qr = (double *)malloc(sizeof(double) * (size_t)r * r), *Br = (double *)malloc(sizeof(double) * (size_t)r * 2);
  double *Ar = (double *)malloc(sizeof(double) * (size_t)r * r), *Cr = (double *)malloc(sizeof(double) * (size_t)r * 2);
  double *sg = (double *)malloc(sizeof(double) * (size_t)r);
  double *w = (double *)malloc(sizeof(double) * (size_t)r), *T = (double *)malloc(sizeof(double) * (size_t)r * r);
  double hinf = 0.0, href = 0.0, rmax = 0.0;
  phgmg_shifted *s = NULL;
  phgmg_lrbt_info inf;
  int i, j;
  CHECK_RC(phgmg_lrphbt(sp, r, NULL, Jr, Rr, Qr, Br, sg, NULL, &inf, NULL), PHGMG_OK);
  for (i = 0; i < r; ++i) CHECK_LE(fabs(sg[i] - sd[i]), 1e-8 * sd[0]);
  for (j = 0; j < r; ++j)
    for (i = 0; i < r; ++i) {
      CHECK(Jr[i + (size_t)j * r] == -Jr[j + (size_t)i * r]);
      CHECK(Rr[i + (size_t)j * r] == Rr[j + (size_t)i * r]);
      CHECK(i == j ? Qr[i + (size_t)j * r] > 0.0 : Qr[i + (size_t)j * r] == 0.0);
      rmax = PHGMG__MAX(rmax, fabs(Rr[i + (size_t)j * r]));
    }
  memcpy(T, Rr, sizeof(double) * (size_t)r * r);
  CHECK_RC(phgmg_sym_eig(r, T, r, w, NULL, r), PHGMG_OK);
  CHECK(w[0] >= -1e-13 * rmax && w[r - 1] > 0.0);
  for (i = 0; i < r * r; ++i) T[i] = Jr[i] - Rr[i];
  phgmg_gemm('N', 'N', r, r, r, 1.0, T, r, Qr, r, 0.0, Ar, r);             /* A = (Jr - Rr) Qr */
  phgmg_gemm('T', 'N', 2, r, r, 1.0, Br, r, Qr, r, 0.0, Cr, 2);            /* C = Br^T Qr      */
  for (j = 0; j < 9; ++j) { /* passive: G_r(i w) + G_r(i w)^H positive semidefinite */
    double G[8], H[16], e[4];
    int a, b;
    CHECK_RC(phgmg_ss_transfer(r, 2, 2, Ar, Br, Cr, pow(10.0, -2.0 + 0.5 * j), G, NULL), PHGMG_OK);
    for (a = 0; a < 2; ++a)
      for (b = 0; b < 2; ++b) { /* H = [[Re, -Im], [Im, Re]] of G + G^H */
        const double re = G[2 * (a + 2 * b)] + G[2 * (b + 2 * a)], im = G[2 * (a + 2 * b) + 1] - G[2 * (b + 2 * a) + 1];
        H[a + 4 * b] = H[(a + 2) + 4 * (b + 2)] = re;
        H[(a + 2) + 4 * b] = im; H[a + 4 * (b + 2)] = -im;
      }
    CHECK_RC(phgmg_sym_eig(4, H, 4, e, NULL, 4), PHGMG_OK);
    CHECK(e[0] >= -1e-12 * fabs(e[3]));
  }
  CHECK_RC(phgmg_shifted_create(&s, sp, 0, 1, NULL), PHGMG_OK);
  CHECK_RC(phgmg_shifted_hinf(s, r, Ar, Br, Cr, 12, 1e-2, 1e2, &hinf, &href), PHGMG_OK);
  phgmg_shifted_destroy(s);
  free(Jr); free(Rr); free(Qr); free(Br); free(Ar); free(Cr); free(sg); free(w); free(T);
  return hinf / href;
}

/* LR-ADI on the lattice (complex shifts): Z Z^T against the dense Gramian,
   the reported residual against the residual of Z Z^T computed here, the
   observability factor of the dual model (O = Q Zy Zy^T Q); low-rank BT:
   the Hankel singular values against the dense Gramians' sqrt(eig(P O)),
   the reduced model's sampled H-infinity error below the bound. */
TEST(test_lowrank_lradi_lattice) {
  enum { r = 8 };
  lr_model M;
  phgmg_lrbt_info binf;
  double Ar[r * r], Br[r * 2], Cr[2 * r], hsv[r], hsvd[r], hinf;
  phgmg_ph_sparse *sp;
  phgmg_shifted *s = NULL, *sd = NULL;
  phgmg_lradi_info inf, infd;
  double *A, *Bp, *C, *P, *O, *Z = NULL, *Zy = NULL, *Plr, *Olr, *T, res;
  int N, k = 0, ky = 0, i;
  lr_lattice(&M, 8, 0);
  N = M.N;
  A = (double *)malloc(sizeof(double) * (size_t)N * N); Bp = (double *)malloc(sizeof(double) * (size_t)N * 2);
  C = (double *)malloc(sizeof(double) * (size_t)N * 2); P = (double *)malloc(sizeof(double) * (size_t)N * N);
  O = (double *)malloc(sizeof(double) * (size_t)N * N); T = (double *)malloc(sizeof(double) * (size_t)N * N);
  lr_dense_gramians(&M, A, Bp, C, P, O);
  sp = lr_sparse(&M);
  CHECK_RC(phgmg_shifted_create(&s, sp, 0, 0, NULL), PHGMG_OK);
  CHECK_RC(phgmg_lradi(s, 2, phgmg_ph_sparse_system(sp)->B, N, NULL, &Z, &k, &inf, NULL), PHGMG_OK);
  CHECK(inf.res <= 1e-10 && inf.iters > 0 && inf.rank == k && k <= inf.cols && k < N);
  Plr = th_gram_user(sp, N, Z, k);
  CHECK_LE(th_reldiff(N * N, Plr, P), 1e-8);
  res = th_lyap_res(N, 2, A, NULL, M.B, Plr);
  CHECK_LE(fabs(res - inf.res), 0.05 * inf.res + 1e-13);
  /* observability: the dual model's factor, O = Q Zy Zy^T Q */
  CHECK_RC(phgmg_shifted_create(&sd, sp, 1, 0, NULL), PHGMG_OK);
  CHECK_RC(phgmg_lradi(sd, 2, phgmg_ph_sparse_system(sp)->B, N, NULL, &Zy, &ky, &infd, NULL), PHGMG_OK);
  Olr = th_gram_user(sp, N, Zy, ky);
  phgmg_gemm('N', 'N', N, N, N, 1.0, M.Q, N, Olr, N, 0.0, T, N);
  phgmg_gemm('N', 'N', N, N, N, 1.0, T, N, M.Q, N, 0.0, Olr, N);
  CHECK_LE(th_reldiff(N * N, Olr, O), 1e-8);
  /* balanced truncation */
  th_dense_hsv(N, P, O, hsvd, r);
  CHECK_RC(phgmg_lrbt(sp, r, NULL, Ar, Br, Cr, hsv, NULL, NULL, &binf, NULL), PHGMG_OK);
  for (i = 0; i < r; ++i) CHECK_LE(fabs(hsv[i] - hsvd[i]), 1e-8 * hsvd[0]);
  CHECK(binf.nhsv > r && binf.bound > 0.0 && binf.hsv_tail <= hsv[r - 1]);
  hinf = lr_hinf(&M, sp, r, Ar, Br, Cr, 12);
  CHECK(hinf > 0.0);
  CHECK_LE(hinf, binf.bound);
  /* pH-preserving balancing: the values sqrt(eig(P Q)), the structure,
     passivity, an error that falls with the order */
  {
    double sq[12], e4, e12;
    th_dense_hsv(N, P, M.Q, sq, 12);
    e4 = lr_check_phbt(sp, sq, 4);
    e12 = lr_check_phbt(sp, sq, 12);
    CHECK(e12 < e4);
  }
  phgmg_lowrank_free(Z, NULL); phgmg_lowrank_free(Zy, NULL);
  phgmg_shifted_destroy(s); phgmg_shifted_destroy(sd); phgmg_ph_sparse_destroy(sp);
  free(A); free(Bp); free(C); free(P); free(O); free(T); free(Plr); free(Olr);
  lr_free(&M);
}

/* A mass matrix E: LR-ADI's Z Z^T and low-rank BT's Hankel singular values
   against the dense Gramians of the equivalent model (E^{-1} A, E^{-1} B,
   B^T Q), the residual with E recomputed here, the reduced model's sampled
   H-infinity error against the full model's below the bound (sampled by
   dense solves and by the sparse model's shifted solves); the pH-preserving
   balancing against E^T Q. */
TEST(test_lowrank_mass_matrix) {
  enum { r = 6 };
  lr_model M;
  phgmg_ph_sparse *sp;
  phgmg_shifted *s = NULL;
  phgmg_lradi_info inf;
  phgmg_lrbt_info binf;
  double *A, *Bp, *C, *P, *O, *Z = NULL, *Plr, *A0, *C0, res, hsv[r], hsvd[r], Ar[r * r], Br[2 * r], Cr[2 * r];
  int N, k = 0, i;
  lr_lattice(&M, 7, 1);
  N = M.N;
  A = (double *)malloc(sizeof(double) * (size_t)N * N); Bp = (double *)malloc(sizeof(double) * (size_t)N * 2);
  C = (double *)malloc(sizeof(double) * (size_t)N * 2); P = (double *)malloc(sizeof(double) * (size_t)N * N);
  O = (double *)malloc(sizeof(double) * (size_t)N * N);
  A0 = (double *)malloc(sizeof(double) * (size_t)N * N); C0 = (double *)malloc(sizeof(double) * (size_t)N * 2);
  lr_dense_gramians(&M, A, Bp, C, P, O);
  sp = lr_sparse(&M);
  CHECK_RC(phgmg_shifted_create(&s, sp, 0, 0, NULL), PHGMG_OK);
  CHECK_RC(phgmg_lradi(s, 2, phgmg_ph_sparse_system(sp)->B, N, NULL, &Z, &k, &inf, NULL), PHGMG_OK);
  Plr = th_gram_user(sp, N, Z, k);
  CHECK_LE(th_reldiff(N * N, Plr, P), 1e-8);
  { /* the residual of the generalized equation, with A = (J - R) Q and E */
    lr_model M0 = M;
    double *Bq = (double *)malloc(sizeof(double) * (size_t)N * 2);
    M0.E = NULL;
    lr_dense_abc(&M0, A0, Bq, C0);
    res = th_lyap_res(N, 2, A0, M.E, M.B, Plr);
    CHECK(inf.res <= 1e-10);
    CHECK_LE(fabs(res - inf.res), 0.05 * inf.res + 1e-13);
    free(Bq);
  }
  th_dense_hsv(N, P, O, hsvd, r);
  CHECK_RC(phgmg_lrbt(sp, r, NULL, Ar, Br, Cr, hsv, NULL, NULL, &binf, NULL), PHGMG_OK);
  for (i = 0; i < r; ++i) CHECK_LE(fabs(hsv[i] - hsvd[i]), 1e-8 * hsvd[0]);
  res = lr_hinf(&M, sp, r, Ar, Br, Cr, 24);
  CHECK(res > 0.0);
  CHECK_LE(res, binf.bound);
  { /* pH-preserving balancing against E^T Q */
    double *EQ = (double *)malloc(sizeof(double) * (size_t)N * N), sd[r];
    phgmg_gemm('T', 'N', N, N, N, 1.0, M.E, N, M.Q, N, 0.0, EQ, N);
    th_dense_hsv(N, P, EQ, sd, r);
    lr_check_phbt(sp, sd, r);
    free(EQ);
  }
  phgmg_lowrank_free(Z, NULL);
  phgmg_shifted_destroy(s); phgmg_ph_sparse_destroy(sp);
  free(A); free(Bp); free(C); free(P); free(O); free(Plr); free(A0); free(C0);
  lr_free(&M);
}

/* Shifted solves (A + p E) X = F on the model with a mass matrix: a complex
   and a real shift against dense solves done here (user order, permuted),
   a repeated shift served by the kept factors, bad arguments refused; the
   transfer function through them against dense solves. */
TEST(test_lowrank_shifted_solve) {
  lr_model M;
  phgmg_ph_sparse *sp;
  phgmg_shifted *s = NULL;
  const double pr = -0.3, pi = 1.7;
  double *Kz, *F, *X, *Fu, *A0, *B0, *C0, err = 0.0, nrm = 0.0;
  int N, i, j, *ip;
  const int *perm;
  lr_lattice(&M, 6, 1);
  N = M.N;
  sp = lr_sparse(&M);
  perm = phgmg_ph_sparse_perm(sp);
  A0 = (double *)malloc(sizeof(double) * (size_t)N * N); B0 = (double *)malloc(sizeof(double) * (size_t)N * 2);
  C0 = (double *)malloc(sizeof(double) * (size_t)N * 2);
  { lr_model M0 = M; M0.E = NULL; lr_dense_abc(&M0, A0, B0, C0); }
  Kz = (double *)malloc(sizeof(double) * 2 * (size_t)N * N); Fu = (double *)malloc(sizeof(double) * 4 * (size_t)N);
  F = (double *)malloc(sizeof(double) * 4 * (size_t)N); X = (double *)malloc(sizeof(double) * 4 * (size_t)N);
  ip = (int *)malloc(sizeof(int) * (size_t)N);
  for (i = 0; i < N * N; ++i) { Kz[2 * i] = A0[i] + pr * M.E[i]; Kz[2 * i + 1] = pi * M.E[i]; }
  for (i = 0; i < 4 * N; ++i) Fu[i] = sin(0.37 * i + 1.0);
  for (j = 0; j < 2; ++j) /* F = Fu in the internal order */
    for (i = 0; i < N; ++i) {
      F[2 * (i + (size_t)j * N)] = Fu[2 * (perm[i] + (size_t)j * N)];
      F[2 * (i + (size_t)j * N) + 1] = Fu[2 * (perm[i] + (size_t)j * N) + 1];
    }
  CHECK_RC(phgmg_shifted_create(&s, sp, 0, 1, NULL), PHGMG_OK);
  CHECK_RC(phgmg_shifted_solve(s, pr, pi, 2, F, N, X, N), PHGMG_OK);
  CHECK_RC(phgmg_zlu_factor(N, Kz, N, ip), PHGMG_OK);
  phgmg_zlu_solve(N, Kz, N, ip, 2, Fu, N);
  for (j = 0; j < 2; ++j)
    for (i = 0; i < N; ++i) {
      double dr = X[2 * (i + (size_t)j * N)] - Fu[2 * (perm[i] + (size_t)j * N)];
      double di = X[2 * (i + (size_t)j * N) + 1] - Fu[2 * (perm[i] + (size_t)j * N) + 1];
      err += dr * dr + di * di;
      nrm += Fu[2 * (perm[i] + (size_t)j * N)] * Fu[2 * (perm[i] + (size_t)j * N)] +
             Fu[2 * (perm[i] + (size_t)j * N) + 1] * Fu[2 * (perm[i] + (size_t)j * N) + 1];
    }
  CHECK_LE(sqrt(err / nrm), 1e-12);
  CHECK(phgmg_shifted_factorizations(s) == 1);
  CHECK_RC(phgmg_shifted_solve(s, pr, pi, 2, F, N, F, N), PHGMG_OK); /* in place, kept factors */
  CHECK(phgmg_shifted_factorizations(s) == 1);
  for (i = 0; i < 4 * N; ++i) CHECK(F[i] == X[i]);
  { /* a real shift: residual (A + p E) x - f with the dense matrices */
    double *f = (double *)malloc(sizeof(double) * (size_t)N), *x = (double *)malloc(sizeof(double) * (size_t)N);
    double *xu = (double *)malloc(sizeof(double) * (size_t)N), rn = 0.0, fn = 0.0;
    for (i = 0; i < N; ++i) f[i] = cos(0.11 * i);
    CHECK_RC(phgmg_shifted_solve(s, -2.5, 0.0, 1, f, N, x, N), PHGMG_OK);
    CHECK(phgmg_shifted_factorizations(s) == 2);
    for (i = 0; i < N; ++i) xu[perm[i]] = x[i];
    for (i = 0; i < N; ++i) {
      double t = 0.0;
      int ii;
      for (j = 0; j < N; ++j) t += (A0[i + (size_t)j * N] - 2.5 * M.E[i + (size_t)j * N]) * xu[j];
      for (ii = 0; ii < N; ++ii) if (perm[ii] == i) break;
      rn += (t - f[ii]) * (t - f[ii]);
      fn += f[ii] * f[ii];
    }
    CHECK_LE(sqrt(rn / fn), 1e-12);
    free(f); free(x); free(xu);
  }
  CHECK_RC(phgmg_shifted_solve(s, NAN, 0.0, 1, F, N, X, N), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_shifted_solve(s, pr, 0.0, 1, F, N - 1, X, N), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_shifted_solve(s, pr, 0.0, 1, F, N + 1, F, N), PHGMG_ERR_INVALID_ARG); /* in place, other ld */
  F[3] = NAN;
  CHECK_RC(phgmg_shifted_solve(s, pr, pi, 1, F, N, X, N), PHGMG_ERR_NANINF);
  CHECK_RC(phgmg_shifted_create(NULL, sp, 0, 0, NULL), PHGMG_ERR_INVALID_ARG);
  { /* the transfer function at w = 0.7 and 2.3 against dense solves: G = B^T Q (i w E - A)^{-1} B */
    double G[8], w = 0.7;
    int t;
    for (t = 0; t < 2; ++t, w = 2.3) {
      double gd[8] = {0}, e2 = 0.0, n2 = 0.0, *Bz = (double *)malloc(sizeof(double) * 4 * (size_t)N);
      int a, b;
      for (i = 0; i < N * N; ++i) { Kz[2 * i] = -A0[i]; Kz[2 * i + 1] = w * M.E[i]; }
      for (i = 0; i < 2 * N; ++i) { Bz[2 * i] = M.B[i]; Bz[2 * i + 1] = 0.0; }
      CHECK_RC(phgmg_zlu_factor(N, Kz, N, ip), PHGMG_OK);
      phgmg_zlu_solve(N, Kz, N, ip, 2, Bz, N);
      for (a = 0; a < 2; ++a)
        for (b = 0; b < 2; ++b)
          for (i = 0; i < N; ++i) { /* C = B^T Q: row a */
            double c = 0.0;
            for (j = 0; j < N; ++j) c += M.B[j + (size_t)a * N] * M.Q[j + (size_t)i * N];
            gd[2 * (a + 2 * b)] += c * Bz[2 * (i + (size_t)b * N)];
            gd[2 * (a + 2 * b) + 1] += c * Bz[2 * (i + (size_t)b * N) + 1];
          }
      CHECK_RC(phgmg_shifted_transfer(s, w, G), PHGMG_OK);
      for (i = 0; i < 8; ++i) { e2 += (G[i] - gd[i]) * (G[i] - gd[i]); n2 += gd[i] * gd[i]; }
      CHECK_LE(sqrt(e2 / n2), 1e-12);
      free(Bz);
    }
    CHECK_RC(phgmg_shifted_transfer(s, NAN, G), PHGMG_ERR_INVALID_ARG);
    CHECK_RC(phgmg_shifted_hinf(s, 0, NULL, NULL, NULL, 0, 1.0, 2.0, NULL, NULL), PHGMG_ERR_SIZE);
    CHECK_RC(phgmg_shifted_hinf(s, 2, G, NULL, NULL, 1, 1.0, 2.0, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  }
  phgmg_shifted_destroy(s); phgmg_ph_sparse_destroy(sp);
  free(Kz); free(F); free(X); free(Fu); free(ip); free(A0); free(B0); free(C0);
  lr_free(&M);
}

/* Progress phases seen (a bit per phase name) and calls. */
static int lr_phase_bits, lr_phase_calls;
static void lr_progress(const char *phase, void *user) {
  static const char *const names[] = {"lradi: shifts", "controllability Gramian", "observability Gramian",
                                      "balancing", "done"};
  int i;
  (void)user;
  ++lr_phase_calls;
  for (i = 0; i < 5; ++i)
    if (!strcmp(phase, names[i])) lr_phase_bits |= 1 << i;
}

/* Argument checks and refusals: bad options, the iteration cap (residual
   reported, no factor), a zero B, orders out of range or beyond the
   computed Hankel singular values, an E with a zero row and column (index
   one), the progress phases. */
TEST(test_lowrank_arguments) {
  lr_model M;
  phgmg_ph_sparse *sp, *sp1 = NULL;
  phgmg_shifted *s = NULL;
  phgmg_lradi_opts o;
  phgmg_lradi_info inf;
  phgmg_lrbt_info binf;
  double *Z = NULL, *B0, Ar[64 * 64], Br[128], Cr[128];
  const double *B;
  int N, k = 7;
  lr_lattice(&M, 4, 0);
  N = M.N;
  sp = lr_sparse(&M);
  B = phgmg_ph_sparse_system(sp)->B;
  CHECK_RC(phgmg_shifted_create(&s, sp, 0, 0, NULL), PHGMG_OK);
  memset(&o, 0, sizeof o);
  CHECK_RC(phgmg_lradi(NULL, 2, B, N, NULL, &Z, &k, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_lradi(s, 0, B, N, NULL, &Z, &k, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_lradi(s, 2, B, N - 1, NULL, &Z, &k, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  o.tol = 1.0;
  CHECK_RC(phgmg_lradi(s, 2, B, N, &o, &Z, &k, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  o.tol = 0.0; o.maxit = -1;
  CHECK_RC(phgmg_lradi(s, 2, B, N, &o, &Z, &k, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  o.maxit = 3;
  CHECK_RC(phgmg_lradi(s, 2, B, N, &o, &Z, &k, &inf, NULL), PHGMG_ERR_NOT_CONVERGED);
  CHECK(Z == NULL && k == 0 && inf.iters >= 3 && inf.res > 1e-10 && inf.res < 1.0 && inf.rank == 0);
  B0 = (double *)calloc((size_t)N * 2, sizeof(double));
  CHECK_RC(phgmg_lradi(s, 2, B0, N, NULL, &Z, &k, NULL, NULL), PHGMG_ERR_RANK);
  B0[0] = NAN;
  CHECK_RC(phgmg_lradi(s, 2, B0, N, NULL, &Z, &k, NULL, NULL), PHGMG_ERR_NANINF);
  CHECK(Z == NULL);
  /* the progress phases of a whole low-rank BT */
  memset(&o, 0, sizeof o);
  o.progress = lr_progress;
  lr_phase_bits = lr_phase_calls = 0;
  CHECK_RC(phgmg_lrbt(sp, 4, &o, Ar, Br, Cr, NULL, NULL, NULL, &binf, NULL), PHGMG_OK);
  CHECK(lr_phase_bits == 31 && lr_phase_calls >= 6);
  CHECK_RC(phgmg_lrbt(sp, 0, NULL, Ar, Br, Cr, NULL, NULL, NULL, NULL, NULL), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_lrbt(sp, N + 1, NULL, Ar, Br, Cr, NULL, NULL, NULL, NULL, NULL), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_lrbt(sp, binf.nhsv + 1, NULL, Ar, Br, Cr, NULL, NULL, NULL, &binf, NULL), PHGMG_ERR_RANK);
  CHECK_RC(phgmg_lrbt(NULL, 4, NULL, Ar, Br, Cr, NULL, NULL, NULL, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  { /* an E with a zero row but no zero column: not of the index-one form */
    lr_model M1 = M;
    M1.E = (double *)calloc((size_t)N * N, sizeof(double));
    for (k = 0; k < N - 1; ++k) M1.E[k + (size_t)k * N] = 1.0;
    M1.E[N - 2 + (size_t)(N - 1) * N] = 0.1;
    sp1 = lr_sparse(&M1);
    free(M1.E);
  }
  phgmg_shifted_destroy(s);
  s = NULL;
  CHECK_RC(phgmg_shifted_create(&s, sp1, 0, 0, NULL), PHGMG_ERR_E_SINGULAR);
  CHECK(s == NULL);
  CHECK_RC(phgmg_lrbt(sp1, 4, NULL, Ar, Br, Cr, NULL, NULL, NULL, NULL, NULL), PHGMG_ERR_E_SINGULAR);
  phgmg_ph_sparse_destroy(sp); phgmg_ph_sparse_destroy(sp1);
  free(B0);
  lr_free(&M);
}


/* sigma_max of a complex 2 x 2 matrix (interleaved re, im; column-major). */
static double lr_smax2(const double *M) {
  double a = 0.0, d = 0.0, br = 0.0, bi = 0.0;
  int i;
  for (i = 0; i < 2; ++i) { /* H = M^H M: a = |col 0|^2, d = |col 1|^2, b = col0^H col1 */
    const double xr = M[2 * i], xi = M[2 * i + 1], yr = M[4 + 2 * i], yi = M[4 + 2 * i + 1];
    a += xr * xr + xi * xi; d += yr * yr + yi * yi;
    br += xr * yr + xi * yi; bi += xr * yi - xi * yr;
  }
  return sqrt(0.5 * (a + d) + sqrt(0.25 * (a - d) * (a - d) + br * br + bi * bi));
}

/* An index-one model: the 4 x 4 lattice with three massless nodes (E = I
   but zero rows and columns at the momenta of masses 0, 5, 10: algebraic
   equations 0 = -(K q)_a - (R z)_a + B_a u), the port of mass 0 on a
   constraint. Closed form of the feedthrough: the three are not
   neighbours, so L_aa = -R_aa = -(0.01 K_aa + 0.5) I = -0.5401 I and D =
   -B_a^T L_aa^{-1} B_a = diag(1 / 0.5401, 0). Checked: phgmg_lrbt_feedthrough
   against it; the descriptor model's own transfer function (phgmg_shifted_
   transfer: the whole pencil, no condensation) tends to D (w = 1e8); the
   reduced model Cr (i w - Ar)^{-1} Br + D within the BT bound of it on 60
   frequencies in [1e-2, 1e2], and without D not (D is carried). */
TEST(test_lowrank_index_one) {
  static const int massless[3] = {0, 5, 10};
  const int r = 8, n2 = 16;
  const double d00 = 1.0 / (0.01 * 4.01 + 0.5);
  lr_model M;
  phgmg_ph_sparse *sp;
  phgmg_shifted *s = NULL;
  phgmg_lrbt_info inf;
  double Ar[64], Br[16], Cr[16], D[4], hsv[8], G[8], Gr[8], e = 0.0, e0 = 0.0;
  int N, k;
  lr_lattice(&M, 4, 0);
  N = M.N;
  M.E = (double *)calloc((size_t)N * N, sizeof(double));
  for (k = 0; k < N; ++k) M.E[k + (size_t)k * N] = 1.0;
  for (k = 0; k < 3; ++k) M.E[n2 + massless[k] + (size_t)(n2 + massless[k]) * N] = 0.0;
  sp = lr_sparse(&M);
  CHECK_RC(phgmg_lrbt(sp, r, NULL, Ar, Br, Cr, hsv, NULL, NULL, &inf, NULL), PHGMG_OK);
  CHECK(inf.nalg == 3 && inf.ctrl.res <= 1e-10 && inf.obs.res <= 1e-10 && inf.bound > 0.0);
  CHECK_RC(phgmg_lrbt_feedthrough(sp, D, NULL), PHGMG_OK);
  CHECK_LE(fabs(D[0] - d00), 1e-14 * d00);
  CHECK(D[1] == 0.0 && D[2] == 0.0 && D[3] == 0.0);
  CHECK_LE(fabs(inf.dmax - d00), 1e-14 * d00);
  CHECK_RC(phgmg_shifted_create(&s, sp, 0, 0, NULL), PHGMG_OK);
  CHECK_RC(phgmg_shifted_transfer(s, 1e5, G), PHGMG_OK);   /* G - D = O(1 / w) */
  for (k = 0; k < 4; ++k) CHECK_LE(hypot(G[2 * k] - D[k], G[2 * k + 1]), 1e-4 * d00);
  for (k = 0; k < 60; ++k) {
    const double w = pow(10.0, -2.0 + 4.0 * k / 59.0);
    int i;
    CHECK_RC(phgmg_shifted_transfer(s, w, G), PHGMG_OK);
    CHECK_RC(phgmg_ss_transfer(r, 2, 2, Ar, Br, Cr, w, Gr, NULL), PHGMG_OK);
    for (i = 0; i < 8; ++i) Gr[i] = G[i] - Gr[i];
    e0 = PHGMG__MAX(e0, lr_smax2(Gr));
    for (i = 0; i < 4; ++i) Gr[2 * i] -= D[i];
    e = PHGMG__MAX(e, lr_smax2(Gr));
  }
  CHECK_LE(e, inf.bound);
  CHECK(e0 > inf.bound);
  phgmg_shifted_destroy(s);
  phgmg_ph_sparse_destroy(sp);
  lr_free(&M);
}

SUITE(lowrank) {
  RUN(test_lowrank_shifted_solve);
  RUN(test_lowrank_lradi_lattice);
  RUN(test_lowrank_mass_matrix);
  RUN(test_lowrank_arguments);
  RUN(test_lowrank_index_one);
}
