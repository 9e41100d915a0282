/* The distributed layer (PHGMG_MPI) against the serial library and closed
   forms, at any number of ranks: mpirun -np P build/test_mpi OUTDIR.
   Every run writes its replicated results to OUTDIR/res_P.bin (rank 0); a run
   with P > 1 compares them with OUTDIR/res_1.bin (run P = 1 first), so the
   results are checked to be the same for every partition. Layouts: P = 2
   and 3 uneven blocks, P = 4 with rank 2 owning no rows. Exit status 0 iff
   every check passed on every rank. Built with mpicc (make test-mpi). */
#define _POSIX_C_SOURCE 199309L   /* nanosleep (mpi_harness.h) */
#define PHGMG_MPI
#define PHGMG_IMPLEMENTATION
#include "../../phgmg.h"
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "../fixture_msd.h"

#include "mpi_harness.h"

/* ---- results shared across runs ------------------------------------------- */
static double res_[8192];
static int nres_;
static void put(const double *a, int n) {
  int i;
  for (i = 0; i < n && nres_ < 8192; ++i) res_[nres_++] = a[i];
}

/* ---- layouts and data ------------------------------------------------------- */

static unsigned long long rng_ = 88172645463325252ull;
static double urand(void) {
  rng_ ^= rng_ << 13; rng_ ^= rng_ >> 7; rng_ ^= rng_ << 17;
  return (double)(rng_ >> 11) * (1.0 / 9007199254740992.0) - 0.5;
}

/* Q (n x k) with orthonormal columns from a random matrix. */
static void rand_orth(int n, int k, double *Q) {
  double *tau = (double *)malloc(sizeof(double) * 2 * (size_t)k);
  int i;
  for (i = 0; i < n * k; ++i) Q[i] = urand();
  phgmg_qr(n, k, Q, n, tau);
  phgmg_qr_form_q(n, k, Q, n, tau, tau + k);
  free(tau);
}

/* The graded snapshot matrix X = U diag(sig) W^T (N x ns), sig_i = 10^(-13 i/(ns-1)). */
static void graded(int N, int ns, double *X, double *U, double *sig) {
  double *W = (double *)malloc(sizeof(double) * (size_t)ns * ns), *US = (double *)malloc(sizeof(double) * (size_t)N * ns);
  int i, j;
  rand_orth(N, ns, U);
  rand_orth(ns, ns, W);
  for (j = 0; j < ns; ++j) {
    sig[j] = pow(10.0, -13.0 * j / (ns - 1));
    for (i = 0; i < N; ++i) US[i + (size_t)j * N] = U[i + (size_t)j * N] * sig[j];
  }
  phgmg_gemm('N', 'T', N, ns, ns, 1.0, US, N, W, ns, 0.0, X, N);
  free(W); free(US);
}

/* The full matrix (N x k) from the row blocks (nloc x k, ld nloc) on every rank. */
static double *gather_rows(const phgmg_mpi_ctx *c, int k, const double *A) {
  double *full = (double *)calloc((size_t)c->N * k + 1, sizeof(double)), *col = (double *)calloc((size_t)c->N + 1, sizeof(double));
  int *cnt = (int *)malloc(sizeof(int) * (size_t)size_), *dsp = (int *)malloc(sizeof(int) * (size_t)size_), q, j;
  for (q = 0; q < size_; ++q) { cnt[q] = (int)(c->starts[q + 1] - c->starts[q]); dsp[q] = (int)c->starts[q]; }
  for (j = 0; j < k; ++j) {
    MPI_Allgatherv(A + (size_t)j * c->nloc, c->nloc, MPI_DOUBLE, col, cnt, dsp, MPI_DOUBLE, MPI_COMM_WORLD);
    memcpy(full + (size_t)j * c->N, col, sizeof(double) * (size_t)c->N);
  }
  free(col); free(cnt); free(dsp);
  return full;
}

/* The rows of a full matrix (N x k) owned by this rank (nloc x k). */
static double *own_rows(const phgmg_mpi_ctx *c, int k, const double *full) {
  double *A = (double *)malloc(sizeof(double) * ((size_t)c->nloc * k + 1));
  int j;
  for (j = 0; j < k; ++j) memcpy(A + (size_t)j * c->nloc, full + c->row0 + (size_t)j * c->N, sizeof(double) * (size_t)c->nloc);
  return A;
}


/* ---- the context ----------------------------------------------------------------- */
/* Bad layouts or arguments on one rank: the same code on every rank, no hang. */
static void test_ctx(void) {
  const long long N = 50;
  const int bad = size_ > 1 ? 1 : 0;
  phgmg_mpi_ctx *c = NULL;
  long long row0;
  int nloc, q;
  phgmg_result rc;
  layout(N, &row0, &nloc);
  rc = phgmg_mpi_ctx_create(&c, MPI_COMM_WORLD, N, row0, nloc, NULL);
  CHECK(rc == PHGMG_OK && c && c->N == N && c->row0 == row0 && c->nloc == nloc, "good layout");
  for (q = 0; q < size_ && c; ++q) CHECK(c->starts[q] <= c->starts[q + 1], "starts ascending");
  CHECK(c && c->starts[0] == 0 && c->starts[size_] == N, "starts tile");
  phgmg_mpi_ctx_destroy(c);
  /* rank `bad` passes nloc = -1 */
  rc = phgmg_mpi_ctx_create(&c, MPI_COMM_WORLD, N, row0, rank_ == bad ? -1 : nloc, NULL);
  CHECK(rc == PHGMG_ERR_SIZE && c == NULL && same_everywhere(rc), "nloc = -1 on one rank: %d", rc);
  /* rank `bad` owns one row too few: a gap (P > 1) or a short tiling (P = 1) */
  rc = phgmg_mpi_ctx_create(&c, MPI_COMM_WORLD, N, row0 + (rank_ == bad && size_ > 1), rank_ == bad && nloc > 0 ? nloc - 1 : nloc, NULL);
  CHECK(rc == PHGMG_ERR_SIZE && c == NULL && same_everywhere(rc), "gap in the blocks: %d", rc);
  /* a different N on one rank */
  rc = phgmg_mpi_ctx_create(&c, MPI_COMM_WORLD, rank_ == bad ? N + 1 : N, row0, nloc, NULL);
  CHECK(rc == PHGMG_ERR_SIZE && c == NULL && same_everywhere(rc), "N differs on one rank: %d", rc);
  /* a NULL output on one rank */
  rc = phgmg_mpi_ctx_create(rank_ == bad ? NULL : &c, MPI_COMM_WORLD, N, row0, nloc, NULL);
  CHECK(rc == PHGMG_ERR_INVALID_ARG && c == NULL && same_everywhere(rc), "NULL ctx on one rank: %d", rc);
}

/* Tall blocks (every rank's block factored in row chunks and the chunks'
   factors combined): Q R = X, Q^T Q = I and the POD's singular values
   equal the serial phgmg_pod's, N = 40000, 6 columns of graded scale. */
static void test_tsqr_tall(void) {
  const int N = 40000, ns = 6;
  double *X = (double *)malloc(sizeof(double) * N * ns), *Xl, *Q, *Qf, *QR = (double *)malloc(sizeof(double) * N * ns);
  double R[36], G[36], S[6], Ss[6], *Vs = (double *)malloc(sizeof(double) * N * ns), *V, e = 0.0, es = 0.0;
  phgmg_mpi_ctx *c = make_ctx(N);
  int i, j, k = 0, ks = 0, ld = c->nloc > 0 ? c->nloc : 1;
  rng_ = 99;
  for (j = 0; j < ns; ++j) for (i = 0; i < N; ++i) X[i + (size_t)j * N] = urand() * pow(10.0, -2.0 * j) + (j > 0 ? X[i] : 0.0);
  Xl = own_rows(c, ns, X);
  Q = (double *)malloc(sizeof(double) * (size_t)ld * ns);
  V = (double *)malloc(sizeof(double) * (size_t)ld * ns);
  CHECK(phgmg_mpi_tsqr(c, ns, Xl, ld, Q, ld, R, ns) == PHGMG_OK, "tsqr tall");
  Qf = gather_rows(c, ns, Q);
  phgmg_gemm('N', 'N', N, ns, ns, 1.0, Qf, N, R, ns, 0.0, QR, N);
  for (i = 0; i < N * ns; ++i) e = fmax(e, fabs(QR[i] - X[i]));
  phgmg_gemm('T', 'N', ns, ns, N, 1.0, Qf, N, Qf, N, 0.0, G, ns);
  for (j = 0; j < ns; ++j) for (i = 0; i < ns; ++i) e = fmax(e, fabs(G[i + j * ns] - (i == j)));
  CHECK(e <= 1e-13, "tall TSQR: max |QR - X|, |Q^T Q - I| = %.2e", e);
  CHECK(phgmg_mpi_pod(c, ns, Xl, ld, ns, 0.0, V, ld, S, &k) == PHGMG_OK && k == ns, "pod tall");
  CHECK(phgmg_pod(N, ns, X, N, ns, 0.0, Vs, N, Ss, &ks, NULL) == PHGMG_OK && ks == ns, "serial pod tall");
  for (i = 0; i < ns; ++i) es = fmax(es, fabs(S[i] - Ss[i]) / Ss[0]);
  CHECK(es <= 1e-14, "tall POD values against serial: %.2e", es);
  if (rank_ == 0) printf("  tall TSQR (chunked): %.2e, values against serial %.2e\n", e, es);
  put(S, ns);
  free(X); free(Xl); free(Q); free(Qf); free(QR); free(Vs); free(V);
  phgmg_mpi_ctx_destroy(c);
}

/* Blocks shorter than the number of columns (N = 45, 40 columns: every
   rank at P > 1 owns fewer rows than that): Q R = X, Q^T Q = I, and the
   POD's values and vectors equal the serial phgmg_pod's. */
static void test_pod_short_blocks(void) {
  const int N = 45, ns = 40;
  double *X = (double *)malloc(sizeof(double) * N * ns), *Xl, *Q, *Qf, *QR = (double *)malloc(sizeof(double) * N * ns);
  double R[1600], G[1600], S[40], Ss[40], *Vs = (double *)malloc(sizeof(double) * N * ns), *V, *Vf, e = 0.0, es = 0.0, ev = 0.0;
  phgmg_mpi_ctx *c = make_ctx(N);
  int i, j, k = 0, ks = 0, ld = c->nloc > 0 ? c->nloc : 1;
  rng_ = 31;
  for (j = 0; j < ns; ++j) for (i = 0; i < N; ++i) X[i + (size_t)j * N] = urand() * pow(10.0, -0.2 * j);
  Xl = own_rows(c, ns, X);
  Q = (double *)malloc(sizeof(double) * (size_t)ld * ns);
  V = (double *)malloc(sizeof(double) * (size_t)ld * ns);
  CHECK(phgmg_mpi_tsqr(c, ns, Xl, ld, Q, ld, R, ns) == PHGMG_OK, "tsqr short");
  Qf = gather_rows(c, ns, Q);
  phgmg_gemm('N', 'N', N, ns, ns, 1.0, Qf, N, R, ns, 0.0, QR, N);
  for (i = 0; i < N * ns; ++i) e = fmax(e, fabs(QR[i] - X[i]));
  phgmg_gemm('T', 'N', ns, ns, N, 1.0, Qf, N, Qf, N, 0.0, G, ns);
  for (j = 0; j < ns; ++j) for (i = 0; i < ns; ++i) e = fmax(e, fabs(G[i + j * ns] - (i == j)));
  CHECK(e <= 1e-13, "short blocks TSQR: max |QR - X|, |Q^T Q - I| = %.2e", e);
  CHECK(phgmg_mpi_pod(c, ns, Xl, ld, 10, 0.0, V, ld, S, &k) == PHGMG_OK && k == 10, "pod short");
  CHECK(phgmg_pod(N, ns, X, N, 10, 0.0, Vs, N, Ss, &ks, NULL) == PHGMG_OK && ks == 10, "serial pod short");
  Vf = gather_rows(c, 10, V);
  for (j = 0; j < 10; ++j) {
    double d = 0.0;
    es = fmax(es, fabs(S[j] - Ss[j]) / Ss[0]);
    for (i = 0; i < N; ++i) d += Vf[i + (size_t)j * N] * Vs[i + (size_t)j * N];
    for (i = 0; i < N; ++i) ev = fmax(ev, fabs(Vf[i + (size_t)j * N] - (d < 0 ? -1.0 : 1.0) * Vs[i + (size_t)j * N]));
  }
  CHECK(es <= 1e-14 && ev <= 1e-12, "short blocks POD against serial: values %.2e, vectors %.2e", es, ev);
  if (rank_ == 0) printf("  short blocks (nloc < ns): TSQR %.2e, POD values %.2e, vectors %.2e\n", e, es, ev);
  put(S, 10);
  free(X); free(Xl); free(Q); free(Qf); free(QR); free(Vs); free(V); free(Vf);
  phgmg_mpi_ctx_destroy(c);
}

/* ---- the sparse operator ----------------------------------------------------------- */
/* Row i: 4 + (i mod 7)/10 on the diagonal, -1 beside it, and a long-range
   entry (i * 37 + 11) mod N (other ranks, not only neighbours). */
static int op_row(int N, int i, long long *col, double *val) {
  int n = 0;
  col[n] = i; val[n++] = 4.0 + (i % 7) * 0.1;
  if (i > 0) { col[n] = i - 1; val[n++] = -1.0; }
  if (i + 1 < N) { col[n] = i + 1; val[n++] = -1.0; }
  col[n] = (i * 37 + 11) % N; val[n++] = 0.01 * (i % 5 + 1);
  return n;
}
static void op_csr(const phgmg_mpi_ctx *c, long long **rp, long long **col, double **val) {
  int i;
  *rp = (long long *)malloc(sizeof(long long) * ((size_t)c->nloc + 1));
  *col = (long long *)malloc(sizeof(long long) * ((size_t)c->nloc * 4 + 1));
  *val = (double *)malloc(sizeof(double) * ((size_t)c->nloc * 4 + 1));
  (*rp)[0] = 0;
  for (i = 0; i < c->nloc; ++i)
    (*rp)[i + 1] = (*rp)[i] + op_row((int)c->N, (int)c->row0 + i, *col + (*rp)[i], *val + (*rp)[i]);
}

/* ---- POD ---------------------------------------------------------------------------- */
/* The reduced operator U_r^T A U_r of the exact leading modes (r = 14,
   sigma_r / sigma_1 = 2e-5), against the one from the TSQR POD's basis Vf
   (sign-normalised, gathered): within 1e-12; and from a Gram-matrix POD
   (eigenvectors of X^T X, V = X W Lambda^{-1/2}): off by more than 1e-10,
   the negative control that shows the check can fail. */
static void reduced_operator_check(const phgmg_mpi_ctx *c, int N, int ns, int r, const double *Xl, const double *Vf,
                                   const double *U) {
  long long *rp, *col, cc[4];
  double *val, vv[4], *A = (double *)calloc((size_t)N * N, sizeof(double)), *AU = (double *)malloc(sizeof(double) * N * r);
  double Ae[1600], At[1600], Ag[1600], G[1600], lam[40], Wg[1600], T[1600], *Vl, *Vg, *Vgf, e_t = 0.0, e_g = 0.0, sc = 0.0;
  phgmg_mpi_op *op = NULL;
  int i, j, n, ld = c->nloc > 0 ? c->nloc : 1;
  for (i = 0; i < N; ++i) {
    n = op_row(N, i, cc, vv);
    for (j = 0; j < n; ++j) A[i + (size_t)cc[j] * N] += vv[j];
  }
  phgmg_gemm('N', 'N', N, r, N, 1.0, A, N, U, N, 0.0, AU, N);
  phgmg_gemm('T', 'N', r, r, N, 1.0, U, N, AU, N, 0.0, Ae, r);
  op_csr(c, &rp, &col, &val);
  CHECK(phgmg_mpi_op_create(&op, c, rp, col, val) == PHGMG_OK, "op");
  Vl = own_rows(c, r, Vf);
  CHECK(phgmg_mpi_op_project(op, r, Vl, ld, At, r) == PHGMG_OK, "project");
  CHECK(phgmg_mpi_atb(c, ns, ns, Xl, ld, Xl, ld, G, ns) == PHGMG_OK, "gram");
  phgmg_sym_eig(ns, G, ns, lam, Wg, ns);
  for (j = 0; j < r; ++j)   /* leading eigenpairs last */
    for (i = 0; i < ns; ++i) T[i + j * ns] = Wg[i + (size_t)(ns - 1 - j) * ns] / sqrt(lam[ns - 1 - j]);
  Vg = (double *)malloc(sizeof(double) * ((size_t)ld * r));
  if (c->nloc > 0) phgmg_gemm('N', 'N', c->nloc, r, ns, 1.0, Xl, c->nloc, T, ns, 0.0, Vg, ld);
  Vgf = gather_rows(c, r, Vg);
  for (j = 0; j < r; ++j) {
    double d = 0.0;
    for (i = 0; i < N; ++i) d += Vgf[i + (size_t)j * N] * U[i + (size_t)j * N];
    if (d < 0) for (i = 0; i < c->nloc; ++i) Vg[i + (size_t)j * ld] = -Vg[i + (size_t)j * ld];
  }
  CHECK(phgmg_mpi_op_project(op, r, Vg, ld, Ag, r) == PHGMG_OK, "project gram");
  for (i = 0; i < r * r; ++i) sc = fmax(sc, fabs(Ae[i]));
  for (i = 0; i < r * r; ++i) { e_t = fmax(e_t, fabs(At[i] - Ae[i]) / sc); e_g = fmax(e_g, fabs(Ag[i] - Ae[i]) / sc); }
  CHECK(e_t <= 1e-12, "V^T A V of the TSQR basis against the exact modes: %.2e", e_t);
  CHECK(e_g > 1e-10, "the Gram basis should miss V^T A V (%.2e)", e_g);
  if (rank_ == 0) printf("  V^T A V at sigma_r/sigma_1 = 2e-5: TSQR %.2e, Gram %.2e (relative)\n", e_t, e_g);
  put(At, r * r);
  phgmg_mpi_op_destroy(op);
  free(rp); free(col); free(val); free(A); free(AU); free(Vl); free(Vg); free(Vgf);
}

/* The graded matrix (singular values 1 .. 1e-13): the TSQR POD's values equal
   the exact ones to 1e-12 sigma_1 (a Gram-matrix POD of the same data is
   shown to miss them by more than 1e-10: the negative control), equal the
   serial phgmg_pod's; the leading vectors equal the exact ones up to sign;
   the TSQR factor reproduces X. */
static void test_pod(void) {
  const int N = 600, ns = 40, r = 12;
  double *X = (double *)malloc(sizeof(double) * N * ns), *U = (double *)malloc(sizeof(double) * N * ns), sig[40];
  double Ss[40], S[40], *Vs = (double *)malloc(sizeof(double) * N * ns), *V, *Xl, *Vf, G[40 * 40], lam[40], *Q, R[40 * 40];
  double e_tsqr = 0.0, e_ser = 0.0, e_gram = 0.0, e_vec = 0.0, e_qr = 0.0, dots[40];
  phgmg_mpi_ctx *c = make_ctx(N);
  int k = 0, ks = 0, i, j;
  rng_ = 12345;
  graded(N, ns, X, U, sig);
  Xl = own_rows(c, ns, X);
  V = (double *)malloc(sizeof(double) * ((size_t)c->nloc * ns + 1));
  CHECK(phgmg_mpi_pod(c, ns, Xl, c->nloc > 0 ? c->nloc : 1, ns, 0.0, V, c->nloc > 0 ? c->nloc : 1, S, &k) == PHGMG_OK, "pod");
  CHECK(phgmg_pod(N, ns, X, N, ns, 0.0, Vs, N, Ss, &ks, NULL) == PHGMG_OK, "serial pod");
  CHECK(k == ns && ks == ns && same_everywhere(k), "k = %d, serial %d", k, ks);
  for (i = 0; i < k && i < ks; ++i) {
    e_tsqr = fmax(e_tsqr, fabs(S[i] - sig[i]));
    e_ser = fmax(e_ser, fabs(S[i] - Ss[i]));
  }
  CHECK(e_tsqr <= 1e-12 && e_ser <= 1e-12, "singular values: exact %.2e, serial %.2e", e_tsqr, e_ser);
  /* negative control: the Gram matrix X^T X (same data, same reductions) */
  CHECK(phgmg_mpi_atb(c, ns, ns, Xl, c->nloc > 0 ? c->nloc : 1, Xl, c->nloc > 0 ? c->nloc : 1, G, ns) == PHGMG_OK, "gram");
  phgmg_sym_eig(ns, G, ns, lam, NULL, 1);
  for (i = 0; i < ns; ++i) e_gram = fmax(e_gram, fabs(sqrt(fmax(lam[ns - 1 - i], 0.0)) - sig[i]));
  CHECK(e_gram > 1e-10, "the Gram POD should miss the small values (error %.2e)", e_gram);
  if (rank_ == 0) printf("  pod: singular value error TSQR %.2e (serial %.2e), Gram %.2e\n", e_tsqr, e_ser, e_gram);
  /* the 14 leading vectors (sigma >= 2e-5) against the exact U, up to sign */
  Vf = gather_rows(c, k, V);
  for (j = 0; j < 14; ++j) {
    double d = 0.0;
    for (i = 0; i < N; ++i) d += Vf[i + (size_t)j * N] * U[i + (size_t)j * N];
    dots[j] = d < 0 ? -1.0 : 1.0;
    for (i = 0; i < N; ++i) e_vec = fmax(e_vec, fabs(Vf[i + (size_t)j * N] - dots[j] * U[i + (size_t)j * N]) / sig[0] * sig[j]);
  }
  CHECK(e_vec <= 1e-12, "leading vectors (weighted by sigma_j/sigma_1): %.2e", e_vec);
  for (j = 0; j < 14; ++j) for (i = 0; i < N; ++i) Vf[i + (size_t)j * N] *= dots[j];
  e_vec = 0.0;
  for (j = 0; j < 4; ++j) for (i = 0; i < N; ++i) e_vec = fmax(e_vec, fabs(Vf[i + (size_t)j * N] - U[i + (size_t)j * N]));
  CHECK(e_vec <= 1e-13, "vectors of the four leading modes: %.2e", e_vec);
  reduced_operator_check(c, N, ns, 14, Xl, Vf, U);
  put(S, k);
  put(Vf, N * r > 4000 ? 4000 : N * r);   /* the sign-normalised leading basis */
  /* TSQR: Q R = X, Q^T Q = I */
  Q = (double *)malloc(sizeof(double) * ((size_t)c->nloc * ns + 1));
  CHECK(phgmg_mpi_tsqr(c, ns, Xl, c->nloc > 0 ? c->nloc : 1, Q, c->nloc > 0 ? c->nloc : 1, R, ns) == PHGMG_OK, "tsqr");
  {
    double *Qf = gather_rows(c, ns, Q), *QR = (double *)malloc(sizeof(double) * N * ns);
    phgmg_gemm('N', 'N', N, ns, ns, 1.0, Qf, N, R, ns, 0.0, QR, N);
    for (i = 0; i < N * ns; ++i) e_qr = fmax(e_qr, fabs(QR[i] - X[i]));
    phgmg_gemm('T', 'N', ns, ns, N, 1.0, Qf, N, Qf, N, 0.0, G, ns);
    for (j = 0; j < ns; ++j) for (i = 0; i < ns; ++i) e_qr = fmax(e_qr, fabs(G[i + j * ns] - (i == j)));
    for (j = 0; j < ns; ++j) for (i = j + 1; i < ns; ++i) CHECK(R[i + j * ns] == 0.0, "R upper triangular");
    CHECK(e_qr <= 1e-13, "TSQR: max |QR - X|, |Q^T Q - I| = %.2e", e_qr);
    free(Qf); free(QR);
  }
  /* streaming in blocks of 7 columns: without truncation the exact values
     above the rounding floor max(N, ns) eps ||X||_F (sigma_40 = 1e-13 is
     below it: 39 modes); truncated at 12 modes, within the reported bound */
  {
    phgmg_mpi_pod_stream *st = NULL, *st2 = NULL;
    double S1[40], S2[40], disc = -1.0, disc2 = -1.0, e1 = 0.0, e2 = 0.0, *V1 = (double *)malloc(sizeof(double) * ((size_t)c->nloc * ns + 1));
    double fro = 0.0;
    int j0, k1 = 0, k2 = 0, kexp = 0, ld = c->nloc > 0 ? c->nloc : 1;
    for (i = 0; i < ns; ++i) fro += sig[i] * sig[i];
    for (i = 0; i < ns; ++i) kexp += sig[i] > (double)N * DBL_EPSILON * sqrt(fro);
    CHECK(phgmg_mpi_pod_stream_begin(&st, c, ns, 0.0) == PHGMG_OK, "stream begin");
    CHECK(phgmg_mpi_pod_stream_begin(&st2, c, r, 0.0) == PHGMG_OK, "stream begin");
    for (j0 = 0; j0 < ns; j0 += 7) {
      const int nb = ns - j0 < 7 ? ns - j0 : 7;
      CHECK(phgmg_mpi_pod_stream_add(st, nb, Xl + (size_t)j0 * c->nloc, ld) == PHGMG_OK, "stream add");
      CHECK(phgmg_mpi_pod_stream_add(st2, nb, Xl + (size_t)j0 * c->nloc, ld) == PHGMG_OK, "stream add");
    }
    CHECK(kexp == ns - 1, "values above the floor: %d", kexp);
    CHECK(phgmg_mpi_pod_stream_end(st, V1, ld, S1, &k1, &disc) == PHGMG_OK && k1 == kexp, "stream end k=%d", k1);
    for (i = 0; i < k1; ++i) e1 = fmax(e1, fabs(S1[i] - sig[i]));
    CHECK(e1 <= 1e-12 && disc <= 1e-12, "stream, no truncation: %.2e (discarded %.2e)", e1, disc);
    CHECK(phgmg_mpi_pod_stream_end(st2, V1, ld, S2, &k2, &disc2) == PHGMG_OK && k2 == r, "stream end k=%d", k2);
    for (i = 0; i < k2; ++i) e2 = fmax(e2, fabs(S2[i] - sig[i]));
    CHECK(disc2 > 0.0 && e2 <= disc2 + 1e-12, "stream, truncated: %.2e, bound %.2e", e2, disc2);
    if (rank_ == 0) printf("  stream: values error %.2e (no truncation), %.2e <= bound %.2e (kmax = %d)\n", e1, e2, disc2, r);
    phgmg_mpi_pod_stream_destroy(st); phgmg_mpi_pod_stream_destroy(st2);
    free(V1);
  }
  free(X); free(U); free(Vs); free(V); free(Xl); free(Vf); free(Q);
  phgmg_mpi_ctx_destroy(c);
}

/* A X and V^T A V against the dense products; the halo count against the
   columns counted directly; a bad column index on one rank gives the same
   code on every rank. */
static void test_op(void) {
  const int N = 600, k = 12;
  phgmg_mpi_ctx *c = make_ctx(N);
  long long *rp, *col, cc[4];
  double *val, vv[4], *A = (double *)calloc((size_t)N * N, sizeof(double)), *X = (double *)malloc(sizeof(double) * N * k);
  double *AX = (double *)malloc(sizeof(double) * N * k), *Xl, *Yl, *Yf, Ar[144], Ad[144], e = 0.0, e2 = 0.0, s = 0.0;
  char *seen = (char *)calloc((size_t)N, 1);
  phgmg_mpi_op *op = NULL;
  int i, j, n, nh = -1, nb = -1, nh_ref = 0, ld = c->nloc > 0 ? c->nloc : 1;
  phgmg_result rc;
  for (i = 0; i < N; ++i) {
    n = op_row(N, i, cc, vv);
    for (j = 0; j < n; ++j) A[i + (size_t)cc[j] * N] += vv[j];
    if (i >= c->row0 && i < c->row0 + c->nloc)
      for (j = 0; j < n; ++j)
        if ((cc[j] < c->row0 || cc[j] >= c->row0 + c->nloc) && !seen[cc[j]]) { seen[cc[j]] = 1; nh_ref++; }
  }
  rng_ = 777;
  rand_orth(N, k, X);
  phgmg_gemm('N', 'N', N, k, N, 1.0, A, N, X, N, 0.0, AX, N);
  op_csr(c, &rp, &col, &val);
  CHECK(phgmg_mpi_op_create(&op, c, rp, col, val) == PHGMG_OK, "op create");
  phgmg_mpi_op_info(op, &nh, &nb);
  CHECK(nh == nh_ref && nb <= size_ - 1, "halo %d (expected %d), neighbours %d", nh, nh_ref, nb);
  Xl = own_rows(c, k, X);
  Yl = (double *)malloc(sizeof(double) * ((size_t)ld * k));
  CHECK(phgmg_mpi_op_apply(op, k, Xl, ld, Yl, ld) == PHGMG_OK, "apply");
  Yf = gather_rows(c, k, Yl);
  for (i = 0; i < N * k; ++i) { e = fmax(e, fabs(Yf[i] - AX[i])); s = fmax(s, fabs(AX[i])); }
  CHECK(e <= 1e-14 * s, "A X: %.2e", e / s);
  CHECK(phgmg_mpi_op_project(op, k, Xl, ld, Ar, k) == PHGMG_OK, "project");
  phgmg_gemm('T', 'N', k, k, N, 1.0, X, N, AX, N, 0.0, Ad, k);
  s = 0.0;
  for (i = 0; i < k * k; ++i) { e2 = fmax(e2, fabs(Ar[i] - Ad[i])); s = fmax(s, fabs(Ad[i])); }
  CHECK(e2 <= 1e-13 * s, "V^T A V: %.2e", e2 / s);
  put(Ar, k * k);
  phgmg_mpi_op_destroy(op);
  /* a column index out of range on one rank only */
  if (rank_ == (size_ > 1 ? 1 : 0) && c->nloc > 0) col[0] = N;
  rc = phgmg_mpi_op_create(&op, c, rp, col, val);
  CHECK(rc == PHGMG_ERR_SIZE && op == NULL && same_everywhere(rc), "bad column on one rank: %d", rc);
  free(rp); free(col); free(val); free(A); free(X); free(AX); free(Xl); free(Yl); free(Yf); free(seen);
  phgmg_mpi_ctx_destroy(c);
}

/* ---- DEIM -------------------------------------------------------------------------- */
/* Greedy points and weights of a POD basis equal the serial
   phgmg_deim_select(PHGMG_DEIM_GREEDY) on the same snapshots; an exact tie
   of the largest entry goes to the lower global index. */
static void test_deim(void) {
  const int N = 600, ns = 40, kd = 12;
  double *X = (double *)malloc(sizeof(double) * N * ns), *U = (double *)malloc(sizeof(double) * N * ns), sig[40];
  double *Xl, *V, S[40], w[12], ws[40], sr = 0.0, ew = 0.0, pd[12];
  long long pts[12];
  int ptss[40], nd = 0, nneg = 0, k = 0, i, ld;
  phgmg_mpi_ctx *c = make_ctx(N);
  ld = c->nloc > 0 ? c->nloc : 1;
  rng_ = 4242;
  graded(N, ns, X, U, sig);
  Xl = own_rows(c, ns, X);
  V = (double *)malloc(sizeof(double) * ((size_t)ld * ns));
  CHECK(phgmg_mpi_pod(c, ns, Xl, ld, kd, 0.0, V, ld, S, &k) == PHGMG_OK && k == kd, "pod for deim");
  CHECK(phgmg_mpi_deim_greedy(c, kd, V, ld, NULL, pts, w) == PHGMG_OK, "deim");
  CHECK(phgmg_deim_select(N, ns, X, N, NULL, 1e-9, kd, PHGMG_DEIM_GREEDY, ptss, ws, &nd, &nneg, &sr, NULL) == PHGMG_OK &&
            nd == kd, "serial deim nd=%d", nd);
  for (i = 0; i < kd; ++i) {
    CHECK(pts[i] == ptss[i], "point %d: %lld, serial %d", i, pts[i], ptss[i]);
    ew = fmax(ew, fabs(w[i] - ws[i]) / fmax(1.0, fabs(ws[i])));
    pd[i] = (double)pts[i];
  }
  CHECK(ew <= 1e-9, "DEIM weights against serial: %.2e", ew);
  put(pd, kd);
  /* ties: column 0 is 1 at rows 10, 300 and N - 10 (-1 there), 0.5 elsewhere at most */
  {
    double *T = (double *)malloc(sizeof(double) * N * 2), *Tl;
    long long tp[2];
    for (i = 0; i < N; ++i) { T[i] = 0.5 * urand(); T[i + N] = 0.5 * urand(); }
    T[10] = 1.0; T[300] = 1.0; T[N - 10] = -1.0;
    Tl = own_rows(c, 2, T);
    CHECK(phgmg_mpi_deim_greedy(c, 2, Tl, ld, NULL, tp, NULL) == PHGMG_OK && tp[0] == 10, "tie: %lld", tp[0]);
    free(T); free(Tl);
  }
  free(X); free(U); free(Xl); free(V);
  phgmg_mpi_ctx_destroy(c);
}

/* ---- distributed GMG-POD ------------------------------------------------------------ */
typedef struct solver {
  const phgmg_mpi_ctx *c;
  double *LU;
  int *ipiv, fail_rank;
} solver;
/* The user's solve: the right-hand sides gathered, a replicated dense LU of J - R. */
static phgmg_result solve_cb(char trans, int nrhs, double *X, int ldx, void *user) {
  solver *s = (solver *)user;
  const phgmg_mpi_ctx *c = s->c;
  const int N = (int)c->N;
  double *full = gather_rows(c, nrhs, X);
  int j;
  phgmg_lu_solve(trans, N, s->LU, N, s->ipiv, nrhs, full, N);
  for (j = 0; j < nrhs; ++j) memcpy(X + (size_t)j * ldx, full + c->row0 + (size_t)j * N, sizeof(double) * (size_t)c->nloc);
  free(full);
  return rank_ == s->fail_rank ? PHGMG_ERR_SINGULAR : PHGMG_OK;
}
static void u_sin(double t, double *u, void *user) { (void)user; u[0] = sin(t) + 0.5 * sin(2.7 * t); }

/* K, Qh, Bh of the distributed GMG-POD equal the serial phgmg_reduce's (after
   the sign of each POD mode) on the mass-spring-damper chain, and the online
   model made of them steps to the serial model's outputs; a solve failing
   on one rank only gives the same code on every rank. */
static void test_gmg(void) {
  const int n = 100, N = 200, ns = 201, r = 10, m = 1;
  dmodel t;
  double *X = (double *)calloc((size_t)N * ns, sizeof(double)), *x0 = (double *)calloc(N, sizeof(double));
  double K[100], Qh[100], Bh[10], S[10], *V0, *V0f, *Xl, *Bl, d[10], e = 0.0, sK = 0.0, xr[10], *col;
  long long *rp, *cols;
  double *vals;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  const phgmg_rom *rom;
  phgmg_mpi_ctx *c = make_ctx(N);
  phgmg_mpi_op *Qop = NULL;
  phgmg_mpi_linear_model md;
  solver sv;
  int i, j, ld = c->nloc > 0 ? c->nloc : 1, nz = 0;
  phgmg_result rc;
  dmodel_msd(&t, n);
  CHECK(phgmg_simulate(&t.sys, x0, 0.0, 0.1, ns - 1, u_sin, NULL, NULL, X, NULL, NULL, NULL, NULL, NULL) == PHGMG_OK, "sim");
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = r;
  CHECK(phgmg_reduce(&red, &t.sys, X, N, ns, &o, NULL, NULL) == PHGMG_OK, "serial reduce");
  rom = phgmg_reduced_rom(red);
  /* distributed inputs: Q's rows as CSR, B's and X's rows, the solve */
  rp = (long long *)malloc(sizeof(long long) * ((size_t)c->nloc + 1));
  cols = (long long *)malloc(sizeof(long long) * ((size_t)c->nloc * N + 1));
  vals = (double *)malloc(sizeof(double) * ((size_t)c->nloc * N + 1));
  rp[0] = 0;
  for (i = 0; i < c->nloc; ++i) {
    for (j = 0; j < N; ++j)
      if (t.Q[(c->row0 + i) + (size_t)j * N] != 0.0) { cols[nz] = j; vals[nz++] = t.Q[(c->row0 + i) + (size_t)j * N]; }
    rp[i + 1] = nz;
  }
  CHECK(phgmg_mpi_op_create(&Qop, c, rp, cols, vals) == PHGMG_OK, "Q op");
  sv.c = c; sv.fail_rank = -1;
  sv.LU = (double *)malloc(sizeof(double) * N * N); sv.ipiv = (int *)malloc(sizeof(int) * N);
  for (i = 0; i < N * N; ++i) sv.LU[i] = t.J[i] - t.R[i];
  CHECK(phgmg_lu_factor(N, sv.LU, N, sv.ipiv) == PHGMG_OK, "LU");
  Xl = own_rows(c, ns, X); Bl = own_rows(c, m, t.B);
  memset(&md, 0, sizeof md);   /* fields not set: zero (E = I) */
  md.Q = Qop; md.m = m; md.B = Bl; md.ldb = ld; md.solve = solve_cb; md.solve_user = &sv;
  V0 = (double *)malloc(sizeof(double) * ((size_t)ld * r));
  CHECK(phgmg_mpi_gmg_pod_linear(c, &md, ns, Xl, ld, r, K, Qh, Bh, S, V0, ld) == PHGMG_OK, "distributed GMG-POD");
  /* signs of the modes: V0's columns against the serial basis (lift of unit vectors) */
  V0f = gather_rows(c, r, V0);
  col = (double *)malloc(sizeof(double) * N);
  for (j = 0; j < r; ++j) {
    double dot = 0.0;
    memset(xr, 0, sizeof xr); xr[j] = 1.0;
    phgmg_reduced_lift(red, xr, col);
    for (i = 0; i < N; ++i) dot += col[i] * V0f[i + (size_t)j * N];
    d[j] = dot < 0 ? -1.0 : 1.0;
  }
  for (j = 0; j < r; ++j)
    for (i = 0; i < r; ++i) {
      K[i + j * r] *= d[i] * d[j]; Qh[i + j * r] *= d[i] * d[j];
      sK = fmax(sK, fabs(rom->K[i + j * r]));
    }
  for (i = 0; i < r * r; ++i) e = fmax(e, fabs(K[i] - rom->K[i]) / sK);
  CHECK(e <= 1e-10, "K against serial: %.2e", e);
  if (rank_ == 0) printf("  gmg-pod: K against serial %.2e", e);
  e = 0.0; sK = 0.0;
  for (i = 0; i < r * r; ++i) sK = fmax(sK, fabs(rom->Qh[i]));
  for (i = 0; i < r * r; ++i) e = fmax(e, fabs(Qh[i] - rom->Qh[i]) / sK);
  CHECK(e <= 1e-10, "Qh against serial: %.2e", e);
  if (rank_ == 0) printf(", Qh %.2e, sigma_r/sigma_1 %.1e\n", e, S[r - m - 1] / S[0]);
  for (i = 0; i < r * m; ++i) CHECK(Bh[i] == rom->Bh[i], "Bh");
  put(K, r * r); put(Qh, r * r);
  {   /* the blocks make a valid online model whose outputs are the serial model's */
    phgmg_rom ro;
    static double m1[16384], m2[16384];
    phgmg_rom_stepper s1, s2;
    double x1[10] = {0}, x2[10] = {0}, u3[3], tc[3], y1 = 0.0, y2 = 0.0, ey = 0.0, sy = 0.0;
    int st;
    memset(&ro, 0, sizeof ro);
    ro.kind = PHGMG_ROM_LINEAR; ro.method = PHGMG_METHOD_GMG_POD; ro.r = r; ro.m = m; ro.Bh = Bh; ro.Qh = Qh; ro.K = K;
    CHECK(phgmg_rom_check(&ro) == PHGMG_OK, "rom check");
    CHECK(phgmg_rom_stepper_init(&s1, &ro, 0.1, 0.0, 0, m1, sizeof m1) == PHGMG_OK &&
              phgmg_rom_stepper_init(&s2, rom, 0.1, 0.0, 0, m2, sizeof m2) == PHGMG_OK, "steppers");
    for (st = 0; st < 200; ++st) {
      phgmg_rom_stage_times(0.1 * st, 0.1, tc);
      for (i = 0; i < 3; ++i) u_sin(tc[i], u3 + i, NULL);
      CHECK(phgmg_rom_step(&s1, x1, u3, &y1, NULL) == PHGMG_OK && phgmg_rom_step(&s2, x2, u3, &y2, NULL) == PHGMG_OK, "step");
      ey = fmax(ey, fabs(y1 - y2)); sy = fmax(sy, fabs(y2));
    }
    CHECK(ey <= 1e-10 * sy, "reduced outputs against the serial model's: %.2e", ey / sy);
    if (rank_ == 0) printf("  gmg-pod: reduced outputs (200 steps) against the serial model's %.2e\n", ey / sy);
  }
  /* the solve fails on one rank only */
  sv.fail_rank = size_ > 1 ? 1 : 0;
  rc = phgmg_mpi_gmg_pod_linear(c, &md, ns, Xl, ld, r, K, Qh, Bh, S, NULL, ld);
  CHECK(rc == PHGMG_ERR_SINGULAR && same_everywhere(rc), "failing solve on one rank: %d", rc);
  phgmg_mpi_op_destroy(Qop);
  phgmg_reduced_destroy(red);
  dmodel_free(&t);
  free(X); free(x0); free(V0); free(V0f); free(Xl); free(Bl); free(col); free(rp); free(cols); free(vals);
  free(sv.LU); free(sv.ipiv);
  phgmg_mpi_ctx_destroy(c);
}

/* ---- errors on one rank ------------------------------------------------------------ */
/* A bad input on one rank only (NaN, a bad size or leading dimension, a
   rank-deficient B): the same code on every rank, never a hang. */
static void test_errors(void) {
  const int N = 300, ns = 8, bad = size_ > 1 ? 1 : 0;
  phgmg_mpi_ctx *c = make_ctx(N);
  const int ld = c->nloc > 0 ? c->nloc : 1, nb = c->nloc > 0 ? 1 : 0;   /* the bad rank owns rows */
  double *X = (double *)malloc(sizeof(double) * (size_t)ld * ns), *V = (double *)malloc(sizeof(double) * (size_t)ld * ns);
  double S[8], C[64], K[16], Qh[16], Bh[4];
  long long pts[8];
  phgmg_mpi_pod_stream *st = NULL;
  phgmg_mpi_op *op = NULL;
  phgmg_mpi_linear_model md;
  phgmg_result rc;
  int i, k = 0;
  rng_ = 5;
  for (i = 0; i < ld * ns; ++i) X[i] = urand();
  if (rank_ == bad && nb) X[0] = NAN;
  rc = phgmg_mpi_pod(c, ns, X, ld, 4, 0.0, V, ld, S, &k);
  CHECK(rc == PHGMG_ERR_NANINF && same_everywhere(rc), "pod, NaN on one rank: %d", rc);
  rc = phgmg_mpi_deim_greedy(c, 4, X, ld, NULL, pts, NULL);
  CHECK(rc == PHGMG_ERR_NANINF && same_everywhere(rc), "deim, NaN on one rank: %d", rc);
  CHECK(phgmg_mpi_pod_stream_begin(&st, c, 4, 0.0) == PHGMG_OK, "stream begin");
  rc = phgmg_mpi_pod_stream_add(st, ns, X, ld);
  CHECK(rc == PHGMG_ERR_NANINF && same_everywhere(rc), "stream, NaN on one rank: %d", rc);
  phgmg_mpi_pod_stream_destroy(st);
  X[0] = 0.25;
  rc = phgmg_mpi_pod(c, ns, X, ld, rank_ == bad ? ns + 1 : 4, 0.0, V, ld, S, &k);
  CHECK(rc == PHGMG_ERR_SIZE && same_everywhere(rc), "pod, kmax > ns on one rank: %d", rc);
  rc = phgmg_mpi_atb(c, ns, ns, X, rank_ == bad ? 0 : ld, X, ld, C, ns);
  CHECK(rc == PHGMG_ERR_SIZE && same_everywhere(rc), "atb, bad ld on one rank: %d", rc);
  rc = phgmg_mpi_deim_greedy(c, 4, X, ld, NULL, rank_ == bad ? NULL : pts, NULL);
  CHECK(rc == PHGMG_ERR_INVALID_ARG && same_everywhere(rc), "deim, NULL output on one rank: %d", rc);
  /* the identity as an operator (empty rows on the bad rank would be fine) */
  {
    long long *rpi = (long long *)malloc(sizeof(long long) * ((size_t)c->nloc + 1)), *ci = (long long *)malloc(sizeof(long long) * (size_t)ld);
    double *vi = (double *)malloc(sizeof(double) * (size_t)ld);
    rpi[0] = 0;
    for (i = 0; i < c->nloc; ++i) { rpi[i + 1] = i + 1; ci[i] = c->row0 + i; vi[i] = 1.0; }
    CHECK(phgmg_mpi_op_create(&op, c, rpi, ci, vi) == PHGMG_OK, "identity op");
    rc = phgmg_mpi_op_apply(op, 2, X, ld, V, rank_ == bad ? 0 : ld);
    CHECK(rc == PHGMG_ERR_SIZE && same_everywhere(rc), "apply, bad ld on one rank: %d", rc);
    if (rank_ == bad && nb) vi[0] = INFINITY;
    phgmg_mpi_op_destroy(op); op = NULL;
    rc = phgmg_mpi_op_create(&op, c, rpi, ci, vi);
    CHECK(rc == PHGMG_ERR_NANINF && op == NULL && same_everywhere(rc), "op, Inf on one rank: %d", rc);
    vi[0] = 1.0;
    CHECK(phgmg_mpi_op_create(&op, c, rpi, ci, vi) == PHGMG_OK, "identity op");
    /* B = 0: rank deficient (every rank sees the same R factor) */
    {
      double *Bz = (double *)calloc((size_t)ld, sizeof(double));
      memset(&md, 0, sizeof md);
      md.Q = op; md.m = 1; md.B = Bz; md.ldb = ld; md.solve = solve_cb; md.solve_user = NULL;
      rc = phgmg_mpi_gmg_pod_linear(c, &md, ns, X, ld, 3, K, Qh, Bh, NULL, NULL, ld);
      CHECK(rc == PHGMG_ERR_RANK && same_everywhere(rc), "gmg, B = 0: %d", rc);
      md.B = rank_ == bad ? NULL : Bz;
      rc = phgmg_mpi_gmg_pod_linear(c, &md, ns, X, ld, 3, K, Qh, Bh, NULL, NULL, ld);
      CHECK((nb == 0 || rc == PHGMG_ERR_INVALID_ARG) && same_everywhere(rc), "gmg, NULL B on one rank: %d", rc);
      free(Bz);
    }
    phgmg_mpi_op_destroy(op);
    free(rpi); free(ci); free(vi);
  }
  free(X); free(V);
  phgmg_mpi_ctx_destroy(c);
}

/* ---- across runs ----------------------------------------------------------------------- */
static void compare_runs(const char *dir) {
  char path[1024];
  FILE *f;
  if (rank_ != 0 || !dir) return;
  snprintf(path, sizeof path, "%s/res_%d.bin", dir, size_);
  f = fopen(path, "wb");
  CHECK(f && fwrite(res_, sizeof(double), (size_t)nres_, f) == (size_t)nres_, "write %s", path);
  if (f) fclose(f);
  if (size_ == 1) return;
  snprintf(path, sizeof path, "%s/res_1.bin", dir);
  f = fopen(path, "rb");
  CHECK(f != NULL, "no %s (run with one rank first)", path);
  if (f) {
    static double ref[8192];
    const size_t got = fread(ref, sizeof(double), 8192, f);
    double e = 0.0;
    int i;
    fclose(f);
    CHECK(got == (size_t)nres_, "result count %d, one rank %d", nres_, (int)got);
    for (i = 0; i < nres_ && i < (int)got; ++i) e = fmax(e, fabs(res_[i] - ref[i]) / fmax(1.0, fabs(ref[i])));
    CHECK(e <= 1e-12, "results differ from one rank's by %.2e", e);
    printf("  P = %d against P = 1: largest difference %.2e over %d values (DEIM points included)\n", size_, e, nres_);
  }
}

/* ---- distributed ECSW ----------------------------------------------------------- */
/* Terms distributed by rows (term k at row k, 600 terms): F = tanh of the
   graded snapshots, Vt = the leading 6 POD modes' rows. The point set, as
   global indices, and the weights are the same at every P (compare_runs,
   1e-12; P = 4 with a rank owning no terms); on every rank the relative
   residual, recomputed from the full data on rank 0, meets tol and equals
   the one returned; a tie between two equal terms goes to the lower index. */
static void test_ecsw(void) {
  const int N = 600, ns = 30, r = 6;
  double *X = (double *)malloc(sizeof(double) * N * ns), *U = (double *)malloc(sizeof(double) * N * ns), sig[30];
  double *Fl, *Vl, w[600], res = -1.0, pd[600];
  long long *gid, pts[600];
  int nd = 0, i, j, a;
  phgmg_result rc;
  phgmg_mpi_ctx *c = make_ctx(N);
  rng_ = 777;
  graded(N, ns, X, U, sig);
  for (i = 0; i < N * ns; ++i) X[i] = tanh(30.0 * X[i]);
  Fl = own_rows(c, ns, X);
  Vl = own_rows(c, r, U);
  gid = (long long *)malloc(sizeof(long long) * ((size_t)c->nloc + 1));
  for (i = 0; i < c->nloc; ++i) gid[i] = c->row0 + i;
  rc = phgmg_mpi_ecsw(c, c->nloc, ns, Fl, c->nloc > 0 ? c->nloc : 1, r, Vl, c->nloc > 0 ? c->nloc : 1, NULL, gid,
                      1e-4, N, pts, w, &nd, &res);
  CHECK(rc == PHGMG_OK && nd > r && nd < N / 2, "ecsw rc %d nd %d", (int)rc, nd);
  CHECK(same_everywhere(nd), "ecsw: nd differs between ranks");
  if (rank_ == 0 && rc == PHGMG_OK) {   /* the residual from the full data */
    double *T = (double *)calloc((size_t)ns * r, sizeof(double)), num = 0.0, den = 0.0;
    int q = 0;
    for (i = 0; i < N; ++i) {
      const double d = (q < nd && pts[q] == i) ? w[q++] - 1.0 : -1.0;
      for (a = 0; a < r; ++a)
        for (j = 0; j < ns; ++j) T[j + a * ns] += d * X[i + (size_t)j * N] * U[i + (size_t)a * N];
    }
    for (j = 0; j < ns * r; ++j) num += T[j] * T[j];
    memset(T, 0, sizeof(double) * (size_t)ns * r);
    for (i = 0; i < N; ++i)
      for (a = 0; a < r; ++a)
        for (j = 0; j < ns; ++j) T[j + a * ns] += X[i + (size_t)j * N] * U[i + (size_t)a * N];
    for (j = 0; j < ns * r; ++j) den += T[j] * T[j];
    CHECK(q == nd && sqrt(num / den) <= 1e-4 && fabs(sqrt(num / den) - res) <= 1e-10,
          "ecsw residual %.3e (returned %.3e)", sqrt(num / den), res);
    for (i = 1; i < nd; ++i) CHECK(pts[i - 1] < pts[i], "ecsw points not ascending");
    for (i = 0; i < nd; ++i) CHECK(w[i] > 0.0, "ecsw weight %d = %g", i, w[i]);
    free(T);
  }
  for (i = 0; i < nd; ++i) pd[i] = (double)pts[i];
  put(pd, nd);
  put(w, nd);
  if (rank_ == 0) printf("  ecsw: %d points of %d terms, residual %.2e\n", nd, N, res);
  /* a tie: two identical terms, 150 and 450 (other ranks at P > 1): the lower one is taken */
  {
    double Ft[2 * 3] = {1, 1, 2, 2, 3, 3}, Vt2[2] = {1, 1};
    long long gt[2] = {450, 150}, pt[2];
    const int nloc2 = rank_ == 0 ? 2 : 0;
    double wt[2];
    int n2 = 0;
    rc = phgmg_mpi_ecsw(c, nloc2, 3, Ft, 2, 1, Vt2, 2, NULL, gt, 1e-6, 2, pt, wt, &n2, NULL);
    CHECK(rc == PHGMG_OK && n2 == 1 && pt[0] == 150 && fabs(wt[0] - 2.0) <= 1e-12, "ecsw tie: %d %lld %g", n2, pt[0], wt[0]);
  }
  free(X); free(U); free(Fl); free(Vl); free(gid);
  phgmg_mpi_ctx_destroy(c);
}

/* ---- shifted Cholesky-QR ----------------------------------------------------- */
/* On the graded matrix (singular values 1 ... 1e-13): Q orthonormal to 1e-13,
   X = Q R to 1e-14 relative, R's singular values the exact ones to 1e-12
   (what the Gram matrix alone cannot give: test_pod's negative control), and
   the same at every P (compare_runs). */
static void test_cholqr(void) {
  const int N = 600, ns = 40;
  double *X = (double *)malloc(sizeof(double) * N * ns), *U = (double *)malloc(sizeof(double) * N * ns), sig[40];
  double *Xl, *Ql, R[40 * 40], G[40 * 40], sv[40], eo = 0.0, es = 0.0, rl[2] = {0.0, 0.0}, rg[2];
  int ld, i, j, l, k = 0, rank = 0;
  phgmg_mpi_ctx *c = make_ctx(N);
  rng_ = 12345;
  graded(N, ns, X, U, sig);
  Xl = own_rows(c, ns, X);
  ld = c->nloc > 0 ? c->nloc : 1;
  Ql = (double *)malloc(sizeof(double) * ((size_t)ld * ns));
  CHECK(phgmg_mpi_cholqr(c, ns, Xl, ld, Ql, ld, R, ns) == PHGMG_OK, "cholqr");
  CHECK(phgmg_mpi_atb(c, ns, ns, Ql, ld, Ql, ld, G, ns) == PHGMG_OK, "Q^T Q");
  for (j = 0; j < ns; ++j) for (i = 0; i < ns; ++i) eo = fmax(eo, fabs(G[i + j * ns] - (i == j)));
  for (j = 0; j < ns; ++j)
    for (i = 0; i < c->nloc; ++i) {
      double t = Xl[i + (size_t)j * c->nloc];
      for (l = 0; l <= j; ++l) t -= Ql[i + (size_t)l * ld] * R[l + j * ns];
      rl[0] += t * t;
      rl[1] += Xl[i + (size_t)j * c->nloc] * Xl[i + (size_t)j * c->nloc];
    }
  MPI_Allreduce(rl, rg, 2, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  CHECK(phgmg_svd(ns, ns, R, ns, ns, sv, G, ns, NULL, 1, &k, &rank, NULL) == PHGMG_OK && k == ns, "svd of R");
  for (i = 0; i < k; ++i) es = fmax(es, fabs(sv[i] - sig[i]));
  CHECK(eo <= 1e-13 && sqrt(rg[0] / rg[1]) <= 1e-14 && es <= 1e-12,
        "cholqr: orthogonality %.2e, residual %.2e, singular values %.2e", eo, sqrt(rg[0] / rg[1]), es);
  if (rank_ == 0) printf("  cholqr: orthogonality %.2e, residual %.2e, singular values %.2e\n", eo, sqrt(rg[0] / rg[1]), es);
  put(sv, k);
  free(X); free(U); free(Xl); free(Ql);
  phgmg_mpi_ctx_destroy(c);
}

/* ---- communication counts ---------------------------------------------------- */
/* The counts of a POD (TSQR) and of greedy DEIM on graded snapshots do not
   depend on N (600 and 2400 rows, the same ns and k): the same number of
   collectives and bytes; a POD makes some, and a fresh context none. */
static void test_counts(void) {
  const int ns = 20, kd = 8;
  phgmg_mpi_counts cnt[2][2];
  int pass;
  for (pass = 0; pass < 2; ++pass) {
    const int N = pass ? 2400 : 600;
    double *X = (double *)malloc(sizeof(double) * N * ns), *U = (double *)malloc(sizeof(double) * N * ns), sig[20];
    double *Xl, *V, S[20];
    long long pts[8];
    int k = 0, ld;
    phgmg_mpi_ctx *c = make_ctx(N);
    phgmg_mpi_counts z;
    ld = c->nloc > 0 ? c->nloc : 1;
    phgmg_mpi_counts_get(c, &z);
    CHECK(z.collectives == 0 && z.bytes == 0 && z.exchanges == 0, "fresh context counts %lld", z.collectives);
    rng_ = 99;
    graded(N, ns, X, U, sig);
    Xl = own_rows(c, ns, X);
    V = (double *)malloc(sizeof(double) * ((size_t)ld * ns));
    CHECK(phgmg_mpi_pod(c, ns, Xl, ld, kd, 0.0, V, ld, S, &k) == PHGMG_OK && k == kd, "pod for counts");
    phgmg_mpi_counts_get(c, &cnt[pass][0]);
    phgmg_mpi_counts_reset(c);
    CHECK(phgmg_mpi_deim_greedy(c, kd, V, ld, NULL, pts, NULL) == PHGMG_OK, "deim for counts");
    phgmg_mpi_counts_get(c, &cnt[pass][1]);
    free(X); free(U); free(Xl); free(V);
    phgmg_mpi_ctx_destroy(c);
  }
  CHECK(cnt[0][0].collectives > 0 && cnt[0][0].bytes >= 8LL * ns * ns && cnt[0][1].collectives >= kd, "counts made");
  CHECK(cnt[0][0].collectives == cnt[1][0].collectives && cnt[0][0].bytes == cnt[1][0].bytes &&
            cnt[0][1].collectives == cnt[1][1].collectives && cnt[0][1].bytes == cnt[1][1].bytes,
        "counts depend on N: pod %lld/%lld, deim %lld/%lld", cnt[0][0].collectives, cnt[1][0].collectives,
        cnt[0][1].collectives, cnt[1][1].collectives);
  if (rank_ == 0)
    printf("  counts: pod %lld collectives / %lld bytes, deim %lld / %lld (N = 600 and 2400 alike)\n",
           cnt[0][0].collectives, cnt[0][0].bytes, cnt[0][1].collectives, cnt[0][1].bytes);
}

int main(int argc, char **argv) {
  int total = 0;
  double t0;
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  t0 = MPI_Wtime();
  if (rank_ == 0) printf("test_mpi: P = %d\n", size_);
  test_ctx();
  test_pod();
  test_tsqr_tall();
  test_pod_short_blocks();
  test_op();
  test_deim();
  test_gmg();
  test_errors();
  test_ecsw();
  test_cholqr();
  test_counts();
  compare_runs(argc > 1 ? argv[1] : NULL);
  MPI_Allreduce(&fails_, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (rank_ == 0) printf("test_mpi: P = %d: %s (%d failed checks, %.2f s)\n", size_, total ? "FAILED" : "passed", total, MPI_Wtime() - t0);
  MPI_Finalize();
  return total ? 1 : 0;
}
