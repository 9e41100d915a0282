/* phgmg.h — structure-preserving model order reduction of port-Hamiltonian
   systems by generalized manifold Galerkin (GMG) reduction. Single header, C99.
   (manual: written at the end of the first session; see README.md) */
#ifndef PHGMG_H_INCLUDED
#define PHGMG_H_INCLUDED

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

/* >>linalg ================================================================ */
/* Dense linear algebra on column-major double matrices (offline half).
   Arguments follow BLAS/LAPACK conventions: (rows, cols, pointer, leading
   dimension). trans is 'N' or 'T'. Complex matrices are stored as interleaved
   (re, im) double pairs: element (i,j) of an n x n complex matrix with leading
   dimension ld sits at A[2*(i + j*ld)] (re) and A[2*(i + j*ld) + 1] (im).
   With PHGMG_USE_CBLAS the products call cblas_dgemm/cblas_dgemv.          */
#ifndef PHGMG_NO_OFFLINE
#ifdef __cplusplus
extern "C" {
#endif

/* C = alpha*op(A)*op(B) + beta*C; op(A) is m x k, op(B) is k x n. Cache blocked. */
PHGMG_DEF void phgmg_gemm(char transa, char transb, int m, int n, int k, double alpha,
                          const double *A, int lda, const double *B, int ldb,
                          double beta, double *C, int ldc);
/* y = alpha*op(A)*x + beta*y; A is m x n. */
PHGMG_DEF void phgmg_gemv(char trans, int m, int n, double alpha, const double *A, int lda,
                          const double *x, double beta, double *y);

/* LU with partial pivoting, in place: P*A = L*U, ipiv[k] = row swapped with k.
   PHGMG_ERR_SINGULAR if a pivot is exactly zero (the factors are then not usable),
   PHGMG_ERR_NANINF if A holds NaN/Inf. */
PHGMG_DEF phgmg_result phgmg_lu_factor(int n, double *A, int lda, int *ipiv);
/* Solve A X = B (trans 'N') or A^T X = B (trans 'T') with the factors; B is n x nrhs, overwritten. */
PHGMG_DEF void phgmg_lu_solve(char trans, int n, const double *LU, int lda, const int *ipiv,
                              int nrhs, double *B, int ldb);
/* Reciprocal 1-norm condition estimate (Hager/Higham) from the factors and ||A||_1.
   Needs 2n doubles of workspace `work` and n ints `iwork`. 0 if singular. */
PHGMG_DEF double phgmg_lu_rcond(int n, const double *LU, int lda, const int *ipiv,
                                double anorm1, double *work, int *iwork);
/* 1-norm of a general m x n matrix. */
PHGMG_DEF double phgmg_norm1(int m, int n, const double *A, int lda);
/* Frobenius norm of a general m x n matrix (overflow-safe). */
PHGMG_DEF double phgmg_normf(int m, int n, const double *A, int lda);

/* Complex LU (interleaved storage, see above), partial pivoting. */
PHGMG_DEF phgmg_result phgmg_zlu_factor(int n, double *A, int lda, int *ipiv);
/* Solve A X = B, complex B (n x nrhs interleaved), overwritten. */
PHGMG_DEF void phgmg_zlu_solve(int n, const double *LU, int lda, const int *ipiv,
                               int nrhs, double *B, int ldb);

/* Householder QR, in place (LAPACK dgeqrf layout: R in the upper triangle,
   reflectors below, scalars tau[min(m,n)]). */
PHGMG_DEF phgmg_result phgmg_qr(int m, int n, double *A, int lda, double *tau);
/* QR with column pivoting (dgeqp3 semantics): A*P = Q*R; jpvt[j] = original
   index of column j (0-based). |R(k,k)| is non-increasing. work: 2n doubles. */
PHGMG_DEF phgmg_result phgmg_qrcp(int m, int n, double *A, int lda, double *tau, int *jpvt,
                                  double *work);
/* Overwrite the first k columns of the factored A (m x k, k <= min(m,n) reflectors)
   with the thin orthonormal Q (m x k). work: k doubles. */
PHGMG_DEF void phgmg_qr_form_q(int m, int k, double *A, int lda, const double *tau, double *work);
/* Apply Q^T (trans 'T') or Q ('N') of a factored A (k reflectors) to C (m x n). */
PHGMG_DEF void phgmg_qr_apply(char trans, int m, int n, int k, const double *A, int lda,
                              const double *tau, double *C, int ldc);

/* Least squares min ||A X - B||_F^2 + lambda ||X||_F^2 (A m x n, B m x nrhs,
   X n x nrhs). lambda = 0: plain least squares by Householder QR (m >= n, full
   column rank, else PHGMG_ERR_RANK); lambda > 0: ridge via QR of [A; sqrt(lambda) I]. */
PHGMG_DEF phgmg_result phgmg_lstsq(int m, int n, int nrhs, const double *A, int lda,
                                   const double *B, int ldb, double lambda,
                                   double *X, int ldx, const phgmg_allocator *alloc);

/* Thin SVD of a (possibly tall, rank-deficient) m x n matrix: Householder QR
   with column pivoting truncated at the numerical rank (trailing column norms
   <= eps*||A||_F), then one-sided Jacobi on the small triangular factor.
   Returns the k = min(kmax, numerical rank) leading triplets: S[k] descending,
   U (m x k, ldu), V (n x k, ldv; may be NULL). *k_out = k.
   *rank_out (may be NULL) = numerical rank. */
PHGMG_DEF phgmg_result phgmg_svd(int m, int n, const double *A, int lda, int kmax,
                                 double *S, double *U, int ldu, double *V, int ldv,
                                 int *k_out, int *rank_out, const phgmg_allocator *alloc);

/* Symmetric eigenvalues (ascending) and optionally eigenvectors (V, n x n) by
   cyclic Jacobi. A is n x n symmetric, destroyed. */
PHGMG_DEF phgmg_result phgmg_sym_eig(int n, double *A, int lda, double *w, double *V, int ldv);

#ifdef __cplusplus
}
#endif
#endif /* PHGMG_NO_OFFLINE */

/* >>ph ==================================================================== */
/* Full-order port-Hamiltonian systems (offline half, double):
       x' = (J - R) grad H(x) + B u(t),   y = B^T grad H(x),
       H(x) = 1/2 x^T Q x + H_nl(x).
   J, R, Q are given dense (N x N, column-major, ld = N) or banded (all three
   with the same half-bandwidth kb, stored as (2kb+1) x N, element (i,j) with
   |i-j| <= kb at band[(kb + i - j) + j*(2kb+1)]). B is always dense N x m. */
#ifndef PHGMG_NO_OFFLINE
#ifdef __cplusplus
extern "C" {
#endif

typedef enum phgmg_storage { PHGMG_DENSE = 0, PHGMG_BANDED = 1 } phgmg_storage;

typedef enum phgmg_nl_kind {
  PHGMG_NL_NONE = 0,      /* quadratic Hamiltonian only                          */
  PHGMG_NL_SEPARABLE = 1, /* H_nl(x) = sum_k w_k phi_k(x[idx_k])  (DEIM needs this) */
  PHGMG_NL_GENERAL = 2    /* H_nl, grad and Hessian by callbacks                 */
} phgmg_nl_kind;

/* Scalar callbacks of a separable nonlinear part: for term k (0-based, over the
   nsep terms) return phi_k(s), phi_k'(s), phi_k''(s). */
typedef double (*phgmg_phi_fn)(int k, double s, void *user);

typedef struct phgmg_ph_system {
  int N, m;
  phgmg_storage storage;   /* DENSE (default) or BANDED                      */
  int kb;                  /* half-bandwidth for BANDED                      */
  const double *J, *R, *Q; /* dense N x N or banded (2kb+1) x N              */
  const double *B;         /* N x m, ld = N                                   */
  /* nonlinear part of H */
  phgmg_nl_kind nl;
  int nsep;                /* SEPARABLE: number of terms                     */
  const int *sep_idx;      /* SEPARABLE: coordinate of term k (0-based)      */
  const double *sep_w;     /* SEPARABLE: weights (NULL = all 1)              */
  phgmg_phi_fn phi, dphi, ddphi;
  /* SEPARABLE, optional: if poly_deg > 0, phi_k(s) = sum_j poly[j] s^j for every
     k (the callbacks may then be NULL). Reduced models can be exported only
     when the nonlinearity is given this way. */
  int poly_deg;
  const double *poly;      /* poly_deg+1 coefficients, constant term first   */
  /* GENERAL */
  double (*H_nl)(const double *x, void *user);
  void (*grad_nl)(const double *x, double *g, void *user);
  /* Hessian of H_nl: dense N x N (ld N) or banded like Q. */
  void (*hess_nl)(const double *x, double *Hs, void *user);
  void *user;
} phgmg_ph_system;

/* Validation of a system. tol (<= 0: 1e-12) is relative to the matrix norms:
   ||J + J^T|| <= tol ||J||, ||R - R^T|| <= tol ||R||, lambda_min(R) >= -tol ||R||,
   B full column rank, 1/cond_1(J - R) > tol (rcond_out, may be NULL, receives
   the estimate), no NaN/Inf, sizes consistent.
   Returns PHGMG_ERR_SIZE / _NANINF / _NOT_SKEW / _NOT_SYMMETRIC / _NOT_PSD /
   _RANK / _SINGULAR / _NOMEM. */
PHGMG_DEF phgmg_result phgmg_ph_validate(const phgmg_ph_system *sys, double tol,
                                         double *rcond_out, const phgmg_allocator *alloc);

/* Hamiltonian, its gradient and the output at a state. */
PHGMG_DEF double phgmg_ph_hamiltonian(const phgmg_ph_system *sys, const double *x);
PHGMG_DEF void phgmg_ph_gradient(const phgmg_ph_system *sys, const double *x, double *g);
/* f = (J - R) grad H(x) + B u  (u may be NULL = 0). */
PHGMG_DEF void phgmg_ph_rhs(const phgmg_ph_system *sys, const double *x, const double *u, double *f);
/* y (m) = B^T grad H(x). */
PHGMG_DEF void phgmg_ph_output(const phgmg_ph_system *sys, const double *x, double *y);

/* >>gl3 =================================================================== */
/* 3-stage Gauss-Legendre (order 6), simplified Newton on the transformed stage
   system (one real and one complex N x N solve per iteration), factorization
   reuse, extrapolated starting guess. For linear systems (nl == NONE) with a
   fixed step a precomputed step map is used unless opts.no_step_map. */

/* u(t) into u[m]. */
typedef void (*phgmg_input_fn)(double t, double *u, void *user);

typedef struct phgmg_gl3_opts {
  double tol;          /* Newton tolerance on the stage residual, inf-norm (0: 1e-10) */
  int max_iter;        /* Newton iteration cap per step (0: 10)                      */
  int no_step_map;     /* 1: never use the precomputed linear step map               */
  double contraction;  /* refactor when the contraction rate exceeds this (0: 0.5)    */
} phgmg_gl3_opts;

typedef struct phgmg_gl3_stats {
  long steps, newton_iters, factorizations, rhs_evals, failures;
  double max_residual;  /* largest final stage residual over the steps */
} phgmg_gl3_stats;

/* Energy bookkeeping of one run, per grid point n = 0..nsteps:
   H[n] = H(x_n), S[n] = supplied energy up to t_n (h sum b_i y_i^T u_i),
   D[n] = dissipated energy up to t_n (h sum b_i gradH(Y_i)^T R gradH(Y_i)),
   so e_energy(t_n) = |H[n] - H[0] - S[n] + D[n]| (paper eq.
   def_energy_conserve_error, stage quadrature). */
typedef struct phgmg_energy {
  double *H, *S, *D;   /* each nsteps+1, caller-provided */
} phgmg_energy;

/* A stepper object for one system and one step size (allocates once). */
typedef struct phgmg_gl3 phgmg_gl3;
PHGMG_DEF phgmg_result phgmg_gl3_create(phgmg_gl3 **out, const phgmg_ph_system *sys, double dt,
                                        const phgmg_gl3_opts *opts, const phgmg_allocator *alloc);
PHGMG_DEF void phgmg_gl3_destroy(phgmg_gl3 *s);
/* One step from (t, x) to t + dt; x updated in place on success, untouched on
   failure (PHGMG_ERR_NOT_CONVERGED, PHGMG_ERR_NANINF, PHGMG_ERR_SINGULAR).
   uf may be NULL (u = 0). energy_inc (may be NULL) receives
   {supplied, dissipated} over the step. */
PHGMG_DEF phgmg_result phgmg_gl3_step(phgmg_gl3 *s, double t, double *x, phgmg_input_fn uf,
                                      void *uuser, double energy_inc[2]);
PHGMG_DEF const phgmg_gl3_stats *phgmg_gl3_get_stats(const phgmg_gl3 *s);

/* Simulate nsteps steps from x0 at t0. Outputs (each may be NULL):
   X: N x (nsteps+1) trajectory (ld N), Y: m x (nsteps+1) outputs (ld m),
   energy: bookkeeping as above; stats: totals. On a step failure the
   buffers hold the steps done so far and the failing code is returned;
   *steps_done (may be NULL) says how many steps succeeded. */
PHGMG_DEF phgmg_result phgmg_simulate(const phgmg_ph_system *sys, const double *x0, double t0,
                                      double dt, int nsteps, phgmg_input_fn uf, void *uuser,
                                      const phgmg_gl3_opts *opts, double *X, double *Y,
                                      const phgmg_energy *energy, phgmg_gl3_stats *stats,
                                      int *steps_done, const phgmg_allocator *alloc);

/* Gauss-Legendre coefficients (closed forms): c[3], b[3], A[9] row-major A[i*3+j]. */
PHGMG_DEF void phgmg_gl3_coefficients(double c[3], double b[3], double A[9]);

#ifdef __cplusplus
}
#endif
#endif /* PHGMG_NO_OFFLINE */
#endif /* PHGMG_H_INCLUDED */

/* ======================================================================== */
/*                              IMPLEMENTATION                              */
/* ======================================================================== */
#ifdef PHGMG_IMPLEMENTATION
#ifndef PHGMG_IMPLEMENTATION_DONE
#define PHGMG_IMPLEMENTATION_DONE

/* >>config (implementation) ============================================== */
#include <math.h>
#include <string.h>

#ifndef PHGMG_ASSERT
#include <assert.h>
#define PHGMG_ASSERT(x) assert(x)
#endif

#if defined(PHGMG_MALLOC) != defined(PHGMG_FREE)
#error "define both PHGMG_MALLOC and PHGMG_FREE, or neither"
#endif
#if !defined(PHGMG_MALLOC) && !defined(PHGMG_NO_OFFLINE)
#include <stdlib.h>
#define PHGMG_MALLOC(sz, user) ((void)(user), malloc(sz))
#define PHGMG_FREE(p, user) ((void)(user), free(p))
#endif

#ifdef PHGMG_USE_CBLAS
#include <cblas.h>
#endif

#ifdef __cplusplus
#define PHGMG__CAST(T, x) (static_cast<T>(x))
#else
#define PHGMG__CAST(T, x) ((T)(x))
#endif

#define PHGMG__MIN(a, b) ((a) < (b) ? (a) : (b))
#define PHGMG__MAX(a, b) ((a) > (b) ? (a) : (b))
#define PHGMG__EPS 2.220446049250313e-16

/* >>result (implementation) ============================================== */
PHGMG_DEF const char *phgmg_result_string(phgmg_result r) {
  switch (r) {
#define PHGMG__X(name, val, str) case name: return str;
    PHGMG__RESULT_LIST(PHGMG__X)
#undef PHGMG__X
    default: break;
  }
  return "unknown result code";
}

/* Private helpers are `static PHGMG__UNUSED` so that a build that does not use
   every one of them stays warning-free. */
#define PHGMG__PRIV static PHGMG__UNUSED

PHGMG__PRIV int phgmg__all_finite(const double *a, size_t n) {
  size_t i;
  double acc = 0.0;
  for (i = 0; i < n; ++i) acc += a[i] * 0.0;
  return acc == 0.0; /* NaN*0 = NaN, Inf*0 = NaN */
}

#ifndef PHGMG_NO_OFFLINE
/* >>memory (implementation) ============================================== */
PHGMG__PRIV void *phgmg__alloc(const phgmg_allocator *a, size_t size) {
  if (size == 0) size = 1;
  if (a && a->alloc) return a->alloc(size, a->user);
  return PHGMG_MALLOC(size, a ? a->user : NULL);
}
PHGMG__PRIV void phgmg__free(const phgmg_allocator *a, void *p) {
  if (!p) return;
  if (a && a->free) { a->free(p, a->user); return; }
  PHGMG_FREE(p, a ? a->user : NULL);
}
/* Allocate n doubles / ints; NULL on failure or overflow. */
PHGMG__PRIV double *phgmg__dalloc(const phgmg_allocator *a, size_t n) {
  if (n > ((size_t)-1) / sizeof(double) / 2) return NULL;
  return PHGMG__CAST(double *, phgmg__alloc(a, n * sizeof(double)));
}
PHGMG__PRIV int *phgmg__ialloc(const phgmg_allocator *a, size_t n) {
  if (n > ((size_t)-1) / sizeof(int) / 2) return NULL;
  return PHGMG__CAST(int *, phgmg__alloc(a, n * sizeof(int)));
}
#endif
#endif /* PHGMG_IMPLEMENTATION_DONE */
#endif /* PHGMG_IMPLEMENTATION */

/*
------------------------------------------------------------------------------
phgmg is available under the MIT License.
Copyright (c) 2026 the phgmg authors.

Permission is hereby granted, free of charge, to any person obtaining a copy of
this software and associated documentation files (the "Software"), to deal in
the Software without restriction, including without limitation the rights to
use, copy, modify, merge, publish, distribute, sublicense, and/or sell copies
of the Software, and to permit persons to whom the Software is furnished to do
so, subject to the following conditions:

The above copyright notice and this permission notice shall be included in all
copies or substantial portions of the Software.

THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY,
FITNESS FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE
AUTHORS OR COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER
LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM,
OUT OF OR IN CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE
SOFTWARE.
------------------------------------------------------------------------------
*/
