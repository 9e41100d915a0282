
/* >>config ================================================================ */
#define PHGMG_VERSION_MAJOR 0
#define PHGMG_VERSION_MINOR 1
#define PHGMG_VERSION_PATCH 0
#define PHGMG_VERSION_STRING "0.1.0"

#include <stddef.h>

#if defined(__GNUC__) || defined(__clang__)
#define PHGMG__UNUSED __attribute__((unused))
#else
#define PHGMG__UNUSED
#endif

#ifndef PHGMG_DEF
#ifdef PHGMG_STATIC
#define PHGMG_DEF static PHGMG__UNUSED
#else
#define PHGMG_DEF extern
#endif
#endif

/* Online scalar: double unless PHGMG_REAL_FLOAT. The offline half is double. */
#ifdef PHGMG_REAL_FLOAT
typedef float phgmg_real;
#define PHGMG_REAL_IS_FLOAT 1
#else
typedef double phgmg_real;
#define PHGMG_REAL_IS_FLOAT 0
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* >>result ================================================================ */
/* One result enum; 0 is success, every failure is negative.
   phgmg_result_string() gives a stable text for each value. */
#define PHGMG__RESULT_LIST(X)                                                            \
  X(PHGMG_OK,                    0, "success")                                          \
  X(PHGMG_ERR_INVALID_ARG,      -1, "invalid argument (NULL pointer, bad option)")      \
  X(PHGMG_ERR_SIZE,             -2, "size mismatch or dimension out of range")          \
  X(PHGMG_ERR_WORKSPACE,        -3, "workspace too small")                              \
  X(PHGMG_ERR_NOMEM,            -4, "out of memory (the allocator returned NULL)")      \
  X(PHGMG_ERR_SINGULAR,         -5, "matrix is singular to working precision")          \
  X(PHGMG_ERR_NANINF,           -6, "NaN or Inf in the input or during the computation") \
  X(PHGMG_ERR_NOT_CONVERGED,    -7, "iteration did not converge")                       \
  X(PHGMG_ERR_NOT_SKEW,         -8, "J is not skew-symmetric")                          \
  X(PHGMG_ERR_NOT_SYMMETRIC,    -9, "R is not symmetric")                               \
  X(PHGMG_ERR_NOT_PSD,         -10, "R is not positive semidefinite")                   \
  X(PHGMG_ERR_RANK,            -11, "rank deficient (B, snapshots, or a basis)")        \
  X(PHGMG_ERR_DEGENERATE,      -12, "GMG non-degeneracy condition det(D^T G D) != 0 fails") \
  X(PHGMG_ERR_NEGATIVE_WEIGHT, -13, "DEIM produced a negative weight")                   \
  X(PHGMG_ERR_FORMAT,          -14, "malformed or unsupported file/data format")         \
  X(PHGMG_ERR_IO,              -15, "I/O error")                                         \
  X(PHGMG_ERR_UNSUPPORTED,     -16, "operation not supported for this model kind")

typedef enum phgmg_result {
#define PHGMG__X(name, val, str) name = val,
  PHGMG__RESULT_LIST(PHGMG__X)
#undef PHGMG__X
  PHGMG__RESULT_END_ = -17
} phgmg_result;

/* A stable, human-readable description of a result code (never NULL). */
PHGMG_DEF const char *phgmg_result_string(phgmg_result r);

/* >>memory ================================================================ */
/* Allocator hooks with a user context. Offline entry points take a
   `const phgmg_allocator *`; NULL means the default (PHGMG_MALLOC/PHGMG_FREE,
   i.e. malloc/free unless overridden). The online path never allocates. */
typedef struct phgmg_allocator {
  void *(*alloc)(size_t size, void *user); /* NULL return = out of memory */
  void (*free)(void *ptr, void *user);      /* must accept NULL            */
  void *user;
} phgmg_allocator;

/* A column-major matrix view, BLAS compatible: element (i,j) is
   data[i + j*ld], ld >= rows. Views never own their data. */
typedef struct phgmg_matview {
  double *data;
  int rows, cols, ld;
} phgmg_matview;

#ifdef __cplusplus
}
#endif
