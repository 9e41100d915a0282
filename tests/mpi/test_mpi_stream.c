/* The distributed streaming POD (phgmg_mpi_pod_stream_*) against closed
   forms and the serial phgmg_pod_stream, at any number of ranks: mpirun -np
   P build/test_mpi_stream. Layouts: P = 2 and 3 uneven blocks, P = 4 with
   rank 2 owning no rows. Also: the communication counts of the streaming
   POD, Cholesky-QR and V^T A V do not depend on N. Exit status 0 iff every
   check passed on every rank. Built with mpicc (make test-mpi). */
#define _POSIX_C_SOURCE 199309L   /* nanosleep (mpi_harness.h) */
#define PHGMG_MPI
#define PHGMG_IMPLEMENTATION
#include "../../phgmg.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpi_harness.h"



static unsigned long long rng_ = 88172645463325252ull;
static double urand(void) {
  rng_ ^= rng_ << 13; rng_ ^= rng_ >> 7; rng_ ^= rng_ << 17;
  return (double)(rng_ >> 11) * (1.0 / 9007199254740992.0) - 0.5;
}

/* Q (n x k) with orthonormal columns: random entries, modified Gram-Schmidt
   applied twice (independent of the library's QR). */
static void rand_orth(int n, int k, double *Q) {
  int i, j, l, pass;
  for (i = 0; i < n * k; ++i) Q[i] = urand();
  for (j = 0; j < k; ++j) {
    double *qj = Q + (size_t)j * n, nrm = 0.0;
    for (pass = 0; pass < 2; ++pass)
      for (l = 0; l < j; ++l) {
        const double *ql = Q + (size_t)l * n;
        double d = 0.0;
        for (i = 0; i < n; ++i) d += ql[i] * qj[i];
        for (i = 0; i < n; ++i) qj[i] -= d * ql[i];
      }
    for (i = 0; i < n; ++i) nrm += qj[i] * qj[i];
    nrm = sqrt(nrm);
    for (i = 0; i < n; ++i) qj[i] /= nrm;
  }
}

/* X (N x ns) = U diag(sig) W^T, U (N x r) and W (ns x r) orthonormal: the
   singular values are exactly sig (r of them), the left vectors U. */
static void low_rank(int N, int ns, int r, const double *sig, double *X, double *U) {
  double *W = (double *)malloc(sizeof(double) * (size_t)ns * r);
  int i, j, l;
  rand_orth(N, r, U);
  rand_orth(ns, r, W);
  for (j = 0; j < ns; ++j)
    for (i = 0; i < N; ++i) {
      double x = 0.0;
      for (l = 0; l < r; ++l) x += U[i + (size_t)l * N] * sig[l] * W[j + (size_t)l * ns];
      X[i + (size_t)j * N] = x;
    }
  free(W);
}

/* The rows of a full matrix (N x k) owned by this rank (ld max(1, nloc)). */
static double *own_rows(const phgmg_mpi_ctx *c, int k, const double *full) {
  const int ld = c->nloc > 0 ? c->nloc : 1;
  double *A = (double *)calloc((size_t)ld * k, sizeof(double));
  int j;
  for (j = 0; j < k && c->nloc > 0; ++j)
    memcpy(A + (size_t)j * ld, full + c->row0 + (size_t)j * c->N, sizeof(double) * (size_t)c->nloc);
  return A;
}

/* Sum over the ranks. */
static double gsum(double v) {
  double out = 0.0;
  MPI_Allreduce(&v, &out, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  return out;
}

/* ||A - B (B^T A)||_F for the row-distributed A (nloc x ka) and the full B
   (N x kb, orthonormal columns): the distance of A's columns from span(B)
   (for orthonormal A it bounds the sines of the angles between the spaces). */
static double dist_from_span(const phgmg_mpi_ctx *c, int ka, const double *A, int kb, const double *B) {
  const int n = c->nloc, ld = n > 0 ? n : 1;
  double *G = (double *)calloc((size_t)ka * kb + 1, sizeof(double)), *Gs = (double *)calloc((size_t)ka * kb + 1, sizeof(double));
  double s = 0.0;
  int i, j, l;
  for (j = 0; j < ka; ++j)
    for (l = 0; l < kb; ++l) {
      double d = 0.0;
      for (i = 0; i < n; ++i) d += B[c->row0 + i + (size_t)l * c->N] * A[i + (size_t)j * ld];
      G[l + (size_t)j * kb] = d;
    }
  MPI_Allreduce(G, Gs, ka * kb, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  for (j = 0; j < ka; ++j)
    for (i = 0; i < n; ++i) {
      double x = A[i + (size_t)j * ld];
      for (l = 0; l < kb; ++l) x -= B[c->row0 + i + (size_t)l * c->N] * Gs[l + (size_t)j * kb];
      s += x * x;
    }
  free(G); free(Gs);
  return sqrt(gsum(s));
}

/* max |V^T V - I| of the row-distributed V (nloc x k). */
static double orth_error(const phgmg_mpi_ctx *c, int k, const double *V) {
  const int n = c->nloc, ld = n > 0 ? n : 1;
  double *G = (double *)calloc((size_t)k * k + 1, sizeof(double)), *Gs = (double *)calloc((size_t)k * k + 1, sizeof(double));
  double e = 0.0;
  int i, j, l;
  for (j = 0; j < k; ++j)
    for (l = 0; l < k; ++l)
      for (i = 0; i < n; ++i) G[l + (size_t)j * k] += V[i + (size_t)l * ld] * V[i + (size_t)j * ld];
  MPI_Allreduce(G, Gs, k * k, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  for (j = 0; j < k; ++j)
    for (l = 0; l < k; ++l) e = fmax(e, fabs(Gs[l + (size_t)j * k] - (l == j)));
  free(G); free(Gs);
  return e;
}

/* The distributed stream over X's columns in blocks of nb, and the serial
   stream over the same blocks. Outputs: V (this rank's rows), S, k,
   discarded; the serial Ss, ks. */
static void run_streams(const phgmg_mpi_ctx *c, int N, int ns, const double *X, const double *Xl, int kmax, int nb,
                        double *V, double *S, int *k, double *disc, double *Ss, int *ks) {
  const int ld = c->nloc > 0 ? c->nloc : 1;
  phgmg_mpi_pod_stream *st = NULL;
  phgmg_pod_stream *ss = NULL;
  int j0;
  *k = *ks = -1;
  CHECK(phgmg_mpi_pod_stream_begin(&st, c, kmax, 0.0) == PHGMG_OK, "stream begin");
  CHECK(phgmg_pod_stream_begin(&ss, N, 0, NULL, N, kmax, 0.0, NULL) == PHGMG_OK, "serial stream begin");
  for (j0 = 0; j0 < ns && st && ss; j0 += nb) {
    const int b = ns - j0 < nb ? ns - j0 : nb;
    CHECK(phgmg_mpi_pod_stream_add(st, b, Xl + (size_t)j0 * ld, ld) == PHGMG_OK, "stream add");
    CHECK(phgmg_pod_stream_add(ss, b, X + (size_t)j0 * N, N) == PHGMG_OK, "serial stream add");
  }
  if (st) CHECK(phgmg_mpi_pod_stream_end(st, V, ld, S, k, disc) == PHGMG_OK, "stream end");
  if (ss) CHECK(phgmg_pod_stream_end(ss, NULL, N, Ss, ks, NULL) == PHGMG_OK, "serial stream end");
  phgmg_mpi_pod_stream_destroy(st);
  phgmg_pod_stream_destroy(ss);
}

/* Exact rank-10 data (N = 3000, 70 columns, singular values 1 .. 1e-6
   geometric, orthonormal factors) in blocks of 7 with room for 30 modes:
   exactly 10 modes kept (the residuals of the later blocks are rounding
   noise and count as zero), the values within 1e-12 sigma_1 of the exact
   ones and of the serial stream's, the basis orthonormal and spanning the
   exact one (sines <= 1e-8), and the reported bound at the rounding level.
   Two data sets (seeds): the rounding noise of the later blocks differs. */
static void test_rank_deficient(unsigned long long seed) {
  enum { N = 3000, NS = 70, R = 10, KMAX = 30 };
  double sig[R], S[KMAX], Ss[KMAX], disc = -1.0, ev = 0.0, es = 0.0, eo, sines;
  double *X = (double *)malloc(sizeof(double) * N * NS), *U = (double *)malloc(sizeof(double) * N * R), *Xl, *V;
  phgmg_mpi_ctx *c = make_ctx(N);
  int i, k = 0, ks = 0;
  for (i = 0; i < R; ++i) sig[i] = pow(10.0, -6.0 * i / (R - 1));
  rng_ = seed;
  low_rank(N, NS, R, sig, X, U);
  Xl = own_rows(c, NS, X);
  V = (double *)calloc((size_t)(c->nloc > 0 ? c->nloc : 1) * KMAX, sizeof(double));
  run_streams(c, N, NS, X, Xl, KMAX, 7, V, S, &k, &disc, Ss, &ks);
  CHECK(k == R && ks == R, "rank-10 data: %d modes kept (serial stream %d), expected 10", k, ks);
  for (i = 0; i < k && i < R; ++i) ev = fmax(ev, fabs(S[i] - sig[i]) / sig[0]);
  for (i = 0; i < k && i < ks; ++i) es = fmax(es, fabs(S[i] - Ss[i]) / sig[0]);
  CHECK(ev <= 1e-12, "rank-10 data: values off the exact ones by %.2e sigma_1", ev);
  CHECK(es <= 1e-12, "rank-10 data: values off the serial stream's by %.2e sigma_1", es);
  eo = orth_error(c, k, V);
  CHECK(eo <= 1e-12, "rank-10 data: ||V^T V - I|| = %.2e", eo);
  sines = dist_from_span(c, k < R ? k : R, V, R, U);
  CHECK(sines <= 1e-8, "rank-10 data: basis off the exact span by %.2e", sines);
  CHECK(disc >= 0.0 && disc <= 1e-12, "rank-10 data: bound %.2e (rounding level expected)", disc);
  if (rank_ == 0)
    printf("  rank 10 (seed %llu): k = %d, values %.2e (exact), %.2e (serial), V^T V - I %.2e, sines %.2e, bound %.2e\n",
           seed, k, ev, es, eo, sines, disc);
  free(X); free(U); free(Xl); free(V);
  phgmg_mpi_ctx_destroy(c);
}

/* Full-rank data with a gap (70 columns: 10 values 1 .. 1e-2, 60 values
   1e-7 .. 1e-9) streamed in blocks of 7 at kmax = 12 (every block truncates):
   the stated bound d = discarded holds -- each value within d of the exact
   one (Weyl) and ||X - V V^T X||_F <= d -- the 10 leading values match the
   serial stream's within 1e-12 sigma_1, and d is far below the gap. */
static void test_gap_bound(void) {
  enum { N = 3000, NS = 70, KMAX = 12 };
  double sig[NS], S[KMAX], Ss[KMAX], disc = -1.0, ew = 0.0, es = 0.0, proj;
  double *X = (double *)malloc(sizeof(double) * N * NS), *U = (double *)malloc(sizeof(double) * N * NS), *Xl, *V;
  phgmg_mpi_ctx *c = make_ctx(N);
  int i, k = 0, ks = 0;
  for (i = 0; i < NS; ++i) sig[i] = i < 10 ? pow(10.0, -2.0 * i / 9) : 1e-7 * pow(10.0, -2.0 * (i - 10) / 59);
  rng_ = 777;
  low_rank(N, NS, NS, sig, X, U);
  Xl = own_rows(c, NS, X);
  V = (double *)calloc((size_t)(c->nloc > 0 ? c->nloc : 1) * KMAX, sizeof(double));
  run_streams(c, N, NS, X, Xl, KMAX, 7, V, S, &k, &disc, Ss, &ks);
  CHECK(k == KMAX && ks == KMAX, "gap data: %d modes (serial %d), expected %d", k, ks, KMAX);
  for (i = 0; i < k; ++i) ew = fmax(ew, fabs(S[i] - sig[i]));
  for (i = 0; i < 10 && i < k && i < ks; ++i) es = fmax(es, fabs(S[i] - Ss[i]) / sig[0]);
  /* ||X - V V^T X||_F from the rows: X's rows minus V (V^T X) */
  {
    const int ld = c->nloc > 0 ? c->nloc : 1;
    double *C = (double *)calloc((size_t)k * NS + 1, sizeof(double));
    double loc = 0.0;
    int j, l;
    phgmg_mpi_atb(c, k, NS, V, ld, Xl, ld, C, k);
    for (j = 0; j < NS; ++j)
      for (i = 0; i < c->nloc; ++i) {
        double x = Xl[i + (size_t)j * ld];
        for (l = 0; l < k; ++l) x -= V[i + (size_t)l * ld] * C[l + (size_t)j * k];
        loc += x * x;
      }
    proj = sqrt(gsum(loc));
    free(C);
  }
  CHECK(disc > 0.0 && disc < 1e-4 * sig[9], "gap data: bound %.2e not in (0, 1e-4 sigma_10)", disc);
  CHECK(ew <= disc * (1.0 + 1e-6) + 1e-14, "gap data: values off by %.2e > bound %.2e", ew, disc);
  CHECK(proj <= disc * (1.0 + 1e-6) + 1e-14, "gap data: ||X - V V^T X|| = %.2e > bound %.2e", proj, disc);
  CHECK(es <= 1e-12, "gap data: leading values off the serial stream's by %.2e sigma_1", es);
  if (rank_ == 0)
    printf("  gap: bound %.2e, values off by %.2e, projection error %.2e, serial %.2e\n", disc, ew, proj, es);
  free(X); free(U); free(Xl); free(V);
  phgmg_mpi_ctx_destroy(c);
}

/* The communication of the streaming POD (blocks of 7, kmax 12), of
   Cholesky-QR and of V^T A V (a chain's tridiagonal operator) does not
   depend on N: the same collective calls and bytes, the same halo
   exchanges and bytes, at N = 600 and 2400. */
static void test_counts_stream(void) {
  enum { NS = 21 };
  phgmg_mpi_counts cnt[2][3];
  int pass, a;
  for (pass = 0; pass < 2; ++pass) {
    const int N = pass ? 2400 : 600;
    phgmg_mpi_ctx *c = make_ctx(N);
    const int ld = c->nloc > 0 ? c->nloc : 1;
    double *X = (double *)malloc(sizeof(double) * (size_t)N * NS), *U = (double *)malloc(sizeof(double) * (size_t)N * NS);
    double sig[NS], S[NS], Ar[144], *Xl, *V = (double *)calloc((size_t)ld * NS, sizeof(double)), R[NS * NS], disc;
    long long *rp = (long long *)malloc(sizeof(long long) * ((size_t)ld + 1)), *col = (long long *)malloc(sizeof(long long) * 3 * (size_t)ld);
    double *val = (double *)malloc(sizeof(double) * 3 * (size_t)ld);
    phgmg_mpi_pod_stream *st = NULL;
    phgmg_mpi_op *op = NULL;
    int i, j0, k = 0, nz = 0;
    for (i = 0; i < NS; ++i) sig[i] = pow(10.0, -0.3 * i);
    rng_ = 31;
    low_rank(N, NS, NS, sig, X, U);
    Xl = own_rows(c, NS, X);
    phgmg_mpi_counts_reset(c);
    CHECK(phgmg_mpi_pod_stream_begin(&st, c, 12, 0.0) == PHGMG_OK, "stream begin");
    for (j0 = 0; j0 < NS; j0 += 7) CHECK(phgmg_mpi_pod_stream_add(st, 7, Xl + (size_t)j0 * ld, ld) == PHGMG_OK, "add");
    CHECK(phgmg_mpi_pod_stream_end(st, V, ld, S, &k, &disc) == PHGMG_OK && k == 12, "stream end k = %d", k);
    phgmg_mpi_pod_stream_destroy(st);
    phgmg_mpi_counts_get(c, &cnt[pass][0]);
    phgmg_mpi_counts_reset(c);
    CHECK(phgmg_mpi_cholqr(c, NS, Xl, ld, U, ld, R, NS) == PHGMG_OK, "cholqr");
    phgmg_mpi_counts_get(c, &cnt[pass][1]);
    rp[0] = 0;
    for (i = 0; i < c->nloc; ++i) {
      const long long g = c->row0 + i;
      col[nz] = g; val[nz++] = 3.0;
      if (g > 0) { col[nz] = g - 1; val[nz++] = -1.0; }
      if (g + 1 < N) { col[nz] = g + 1; val[nz++] = -1.0; }
      rp[i + 1] = nz;
    }
    CHECK(phgmg_mpi_op_create(&op, c, rp, col, val) == PHGMG_OK, "op");
    phgmg_mpi_counts_reset(c);
    CHECK(phgmg_mpi_op_project(op, 12, V, ld, Ar, 12) == PHGMG_OK, "project");
    phgmg_mpi_counts_get(c, &cnt[pass][2]);
    phgmg_mpi_op_destroy(op);
    free(X); free(U); free(Xl); free(V); free(rp); free(col); free(val);
    phgmg_mpi_ctx_destroy(c);
  }
  for (a = 0; a < 3; ++a)
    CHECK(cnt[0][a].collectives > 0 && cnt[0][a].collectives == cnt[1][a].collectives &&
              cnt[0][a].bytes == cnt[1][a].bytes && cnt[0][a].exchanges == cnt[1][a].exchanges &&
              cnt[0][a].exchange_bytes == cnt[1][a].exchange_bytes,
          "phase %d: counts depend on N: %lld/%lld collectives, %lld/%lld bytes, %lld/%lld halo bytes", a,
          cnt[0][a].collectives, cnt[1][a].collectives, cnt[0][a].bytes, cnt[1][a].bytes, cnt[0][a].exchange_bytes,
          cnt[1][a].exchange_bytes);
  if (rank_ == 0)
    printf("  counts (N = 600 and 2400 alike): stream %lld / %lld bytes, cholqr %lld / %lld, V^T A V %lld / %lld + %lld halo\n",
           cnt[0][0].collectives, cnt[0][0].bytes, cnt[0][1].collectives, cnt[0][1].bytes, cnt[0][2].collectives,
           cnt[0][2].bytes, cnt[0][2].exchange_bytes);
}

int main(int argc, char **argv) {
  int total = 0;
  double t0;
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  t0 = MPI_Wtime();
  if (rank_ == 0) printf("test_mpi_stream: P = %d\n", size_);
  test_rank_deficient(15);
  test_rank_deficient(4242);
  test_gap_bound();
  test_counts_stream();
  MPI_Allreduce(&fails_, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (rank_ == 0)
    printf("test_mpi_stream: P = %d: %s (%d failed checks, %.2f s)\n", size_, total ? "FAILED" : "passed", total,
           MPI_Wtime() - t0);
  MPI_Finalize();
  return total ? 1 : 0;
}
