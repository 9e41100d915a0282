/* What the MPI tests share (include after phgmg.h with PHGMG_MPI): this
   process's rank and the communicator's size, the failure count, CHECK
   (prints the failed condition's place with P and the rank, and goes on),
   the row layouts every test uses, uneven on purpose, and helpers of the
   comparisons (a value the same on every rank, a basis gathered, a banded
   matrix's rows as an operator). */
#ifndef PHGMG_TEST_MPI_HARNESS_H
#define PHGMG_TEST_MPI_HARNESS_H
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static int rank_, size_, fails_;
#define CHECK(cond, ...)                                                            \
  do {                                                                              \
    if (!(cond)) {                                                                  \
      fails_++;                                                                     \
      printf("[P=%d rank %d] FAIL %s:%d: ", size_, rank_, __FILE__, __LINE__);       \
      printf(__VA_ARGS__);                                                          \
      printf("\n");                                                                 \
      fflush(stdout);                                                               \
    }                                                                               \
  } while (0)

/* This rank's block of N rows: P = 2: 60/40 %, P = 3: 50/30/20 %, P = 4:
   40/35/0/25 % (rank 2 empty); else even. */
static void layout(long long N, long long *row0, int *nloc) {
  static const double w2[] = {0.6, 0.4}, w3[] = {0.5, 0.3, 0.2}, w4[] = {0.4, 0.35, 0.0, 0.25};
  const double *w = size_ == 2 ? w2 : size_ == 3 ? w3 : size_ == 4 ? w4 : NULL;
  double c0 = 0.0, c1;
  int q;
  for (q = 0; q < rank_; ++q) c0 += w ? w[q] : 1.0 / size_;
  c1 = c0 + (w ? w[rank_] : 1.0 / size_);
  *row0 = (long long)floor(c0 * (double)N + 0.5);
  *nloc = rank_ == size_ - 1 ? (int)(N - *row0) : (int)((long long)floor(c1 * (double)N + 0.5) - *row0);
}

/* A context over MPI_COMM_WORLD with that layout (NULL after a failed CHECK). */
static inline phgmg_mpi_ctx *make_ctx(long long N) {
  phgmg_mpi_ctx *c = NULL;
  long long row0;
  int nloc;
  layout(N, &row0, &nloc);
  CHECK(phgmg_mpi_ctx_create(&c, MPI_COMM_WORLD, N, row0, nloc, NULL) == PHGMG_OK, "ctx N=%lld", N);
  return c;
}
/* 1 if v is the same on every rank. Collective. */
static inline int same_everywhere(int v) {
  int lo, hi;
  MPI_Allreduce(&v, &lo, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&v, &hi, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return lo == hi;
}

/* The distributed V0 (N x r) on every rank from the ranks' rows (ld). Collective. */
static inline double *gather_v0(const phgmg_mpi_ctx *c, int r, const double *V0, int ld) {
  const int N = (int)c->N;
  double *full = (double *)calloc((size_t)N * r + 1, sizeof(double)), *col = (double *)malloc(sizeof(double) * ((size_t)c->nloc + 1));
  int *cnt = (int *)malloc(sizeof(int) * (size_t)size_), *dsp = (int *)malloc(sizeof(int) * (size_t)size_), q, j;
  for (q = 0; q < size_; ++q) { cnt[q] = (int)(c->starts[q + 1] - c->starts[q]); dsp[q] = (int)c->starts[q]; }
  for (j = 0; j < r; ++j) {
    memcpy(col, V0 + (size_t)j * ld, sizeof(double) * (size_t)c->nloc);
    MPI_Allgatherv(col, c->nloc, MPI_DOUBLE, full + (size_t)j * N, cnt, dsp, MPI_DOUBLE, MPI_COMM_WORLD);
  }
  free(col); free(cnt); free(dsp);
  return full;
}

/* This rank's rows of A - s C (N x N banded, half-bandwidth kb, LAPACK-style
   storage with ld 2 kb + 1; C may be NULL) as a distributed operator. */
static inline phgmg_mpi_op *band_op_kb(const phgmg_mpi_ctx *c, int N, int kb, const double *A, const double *C, double s) {
  const int nloc = c->nloc;
  long long *rp = (long long *)malloc(sizeof(long long) * ((size_t)nloc + 1));
  long long *cols = (long long *)malloc(sizeof(long long) * ((size_t)nloc * (2 * kb + 1) + 1));
  double *vals = (double *)malloc(sizeof(double) * ((size_t)nloc * (2 * kb + 1) + 1));
  phgmg_mpi_op *op = NULL;
  int i, j, nz = 0;
  rp[0] = 0;
  for (i = 0; i < nloc; ++i) {
    const int g = (int)c->row0 + i;
    for (j = g - kb; j <= g + kb; ++j) {
      const size_t at = (size_t)(kb + g - j) + (size_t)j * (2 * kb + 1);
      const double v = (j >= 0 && j < N) ? A[at] - (C ? s * C[at] : 0.0) : 0.0;
      if (v != 0.0) { cols[nz] = j; vals[nz++] = v; }
    }
    rp[i + 1] = nz;
  }
  CHECK(phgmg_mpi_op_create(&op, c, rp, cols, vals) == PHGMG_OK, "operator");
  free(rp); free(cols); free(vals);
  return op;
}
/* Wait for rank 0's serial comparisons without spinning (the other ranks
   sleep between tests of a non-blocking barrier: the cores stay free).
   Needs _POSIX_C_SOURCE >= 199309L (nanosleep) from the test file. */
static inline void quiet_barrier(void) {
  MPI_Request rq;
  int done = 0;
  MPI_Ibarrier(MPI_COMM_WORLD, &rq);
  while (!done) {
    struct timespec ts;
    MPI_Test(&rq, &done, MPI_STATUS_IGNORE);
    ts.tv_sec = 0; ts.tv_nsec = 2000000;
    if (!done && rank_ != 0) nanosleep(&ts, NULL);
  }
}

/* The tests' input, u(t) = 0.5 sin(0.7 t) on one port. */
static inline void u_in(double t, double *u, void *user) { (void)user; u[0] = 0.5 * sin(0.7 * t); }

/* The serial simulation (rank 0, input u_in) broadcast to every rank: X (N x ns). */
static inline void simulate_root(const phgmg_ph_system *sys, const double *x0, double dt, int ns, double *X) {
  int ok = 1;
  if (rank_ == 0)
    ok = phgmg_simulate(sys, x0, 0.0, dt, ns - 1, u_in, NULL, NULL, X, NULL, NULL, NULL, NULL, NULL) == PHGMG_OK;
  MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
  MPI_Bcast(X, sys->N * ns, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  CHECK(ok, "simulate");
}

/* Largest |d_i d_j A - B| / max |B| over r x c (d: the modes' signs; dj NULL: 1). */
static inline double rel_diff(int r, int c, const double *A, const double *B, const double *di, const double *dj) {
  double e = 0.0, s = 0.0;
  int i, j;
  for (j = 0; j < c; ++j)
    for (i = 0; i < r; ++i) {
      e = fmax(e, fabs(di[i] * (dj ? dj[j] : 1.0) * A[i + (size_t)j * r] - B[i + (size_t)j * r]));
      s = fmax(s, fabs(B[i + (size_t)j * r]));
    }
  return s > 0.0 ? e / s : e;
}

/* The signs of the modes of a basis V0f (N x r) against a serial model's
   (lifts of unit vectors). */
static inline void mode_signs(const phgmg_reduced *red, int N, int r, const double *V0f, double *sg) {
  double *col = (double *)malloc(sizeof(double) * (size_t)N), xr[64];
  int i, j;
  for (j = 0; j < r; ++j) {
    double dot = 0.0;
    memset(xr, 0, sizeof xr); xr[j] = 1.0;
    phgmg_reduced_lift(red, xr, col);
    for (i = 0; i < N; ++i) dot += col[i] * V0f[i + (size_t)j * N];
    sg[j] = dot < 0.0 ? -1.0 : 1.0;
  }
  free(col);
}
#endif
