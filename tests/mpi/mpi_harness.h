/* What the MPI tests share (include after phgmg.h with PHGMG_MPI): this
   process's rank and the communicator's size, the failure count, CHECK
   (prints the failed condition's place with P and the rank, and goes on),
   and the row layouts every test uses, uneven on purpose. */
#ifndef PHGMG_TEST_MPI_HARNESS_H
#define PHGMG_TEST_MPI_HARNESS_H
#include <math.h>
#include <stdio.h>

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
#endif
