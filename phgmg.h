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
  /* Optional caller-supplied solver for the shifted Newton matrices of the GL3
     stepper, K(sigma) = sigma I - (J - R) Hess H(x_lin), sigma = sr + i si, so a
     model can bring its own O(N) solve. Both NULL (default): the library's
     dense or banded LU. Both set: at every (re)factorization the stepper calls
     shifted_factor twice, with the real shift (gamma/h, 0) and the complex one
     (alpha/h, -beta/h), and the linearization state x_lin (N); the callee must
     keep both systems ready. shifted_solve(sr, si, rhs, user) then overwrites
     rhs with K(sigma)^{-1} rhs, where rhs is a real N-vector if si == 0 and an
     interleaved complex N-vector (2N doubles, re/im pairs) otherwise. A
     non-PHGMG_OK return of shifted_factor (e.g. PHGMG_ERR_SINGULAR) is passed
     on by phgmg_gl3_step. Not used by the linear step map (see >>gl3). */
  phgmg_result (*shifted_factor)(double sr, double si, const double *x_lin, void *user);
  void (*shifted_solve)(double sr, double si, double *rhs, void *user);
  void *shifted_user;      /* `user` argument of the two callbacks above      */
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

/* Y = M X for M in {'J','R','Q'} ('Q': the quadratic part of H only), dense or
   banded storage; X is N x nrhs (ldx), Y is N x nrhs (ldy). */
PHGMG_DEF void phgmg_ph_apply(const phgmg_ph_system *sys, char which, int nrhs,
                              const double *X, int ldx, double *Y, int ldy);

/* A factorization of J - R (dense LU or banded LU, by the system's storage),
   for applying G = (J - R)^{-1} without forming it. */
typedef struct phgmg_jr_factor phgmg_jr_factor;
PHGMG_DEF phgmg_result phgmg_jr_factor_create(phgmg_jr_factor **out, const phgmg_ph_system *sys,
                                              double *rcond_out, const phgmg_allocator *alloc);
/* X <- (J - R)^{-1} X (trans 'N') or (J - R)^{-T} X (trans 'T'); X is N x nrhs. */
PHGMG_DEF void phgmg_jr_solve(const phgmg_jr_factor *f, char trans, int nrhs, double *X, int ldx);
PHGMG_DEF void phgmg_jr_factor_destroy(phgmg_jr_factor *f);

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

/* >>online ================================================================ */
/* Reduced models online: allocation-free, no globals, no stdio, no VLAs, in
   the build's scalar phgmg_real (double, or float with PHGMG_REAL_FLOAT).
   A phgmg_rom is a set of non-owning const views (so an exported model can
   sit in flash as static const arrays). The reduced model is the pH system
       x' = K(x) grad H(x) + Bh u,   y = Bh^T grad H(x),
       K(x) = J(x) - R(x)  (J skew, R symmetric positive semidefinite),
   with, for a LINEAR map phi(x) = V0 x:   K constant,
       H(x) = 1/2 x^T Qh x + sum_j w_j poly(P0_j x),
   and for the QUADRATIC map phi(x) = V0 x + V2 q(x2), q = M (x2 kron x2),
   x = (x1, x2), x1 in R^m, x2 in R^p, p = r - m:
       K(x) = (Dphi^T G Dphi)^{-1},  G = (J - R)^{-1},  Dphi = V0 + V2 [0, L(x2)],
       L(:,k) = sum_j Ms(:, k*p + j) x2_j,   q = L x2 / 2,
       H(x) = 1/2 phi^T Q phi + sum_j w_j poly(P0_j x + P1_j q),
   where every product with N-dimensional data was precomputed offline
   (G00 = V0^T G V0, ... see the fields). The online cost is independent of N. */
#ifdef __cplusplus
extern "C" {
#endif

typedef enum phgmg_rom_kind { PHGMG_ROM_LINEAR = 1, PHGMG_ROM_QUADRATIC = 2 } phgmg_rom_kind;
typedef enum phgmg_method {
  PHGMG_METHOD_GMG_POD = 1, /* phi = [B, Vbar] x, GMG reduction (paper 4.2.1)         */
  PHGMG_METHOD_GMG_QM = 2,  /* quadratic manifold, GMG reduction (paper 4.2.2)        */
  PHGMG_METHOD_SP1 = 3,     /* SP1-POD: phi = V_POD x, W = QV(V^TQV)^-1 (eq. 5.3)     */
  PHGMG_METHOD_SP2 = 4      /* SP2-POD: W = V_gradH (V_POD^T V_gradH)^-1 (NUMERICS 6.3) */
} phgmg_method;

#define PHGMG_ROM_MAGIC 0x50484731u /* "PHG1" */

typedef struct phgmg_rom {
  int kind;      /* phgmg_rom_kind                                   */
  int method;    /* phgmg_method (informative)                       */
  int r, m;      /* reduced order, ports                             */
  int rn;        /* QUADRATIC: lifting dimension r_n, else 0         */
  int nd;        /* separable nonlinear terms kept online (DEIM points), 0 = quadratic H */
  int poly_deg;  /* degree of the shared polynomial phi (nd > 0)     */
  const phgmg_real *Bh;   /* r x m   reduced port matrix (W^T B; [I;0] for GMG)   */
  const phgmg_real *Qh;   /* r x r   V0^T Q V0                                     */
  const phgmg_real *K;    /* r x r   LINEAR: J - R reduced (constant)              */
  /* QUADRATIC only */
  const phgmg_real *G00;  /* r x r   V0^T G V0 */
  const phgmg_real *G01;  /* r x rn  V0^T G V2 */
  const phgmg_real *G10;  /* rn x r  V2^T G V0 */
  const phgmg_real *G11;  /* rn x rn V2^T G V2 */
  const phgmg_real *Q01;  /* r x rn  V0^T Q V2 */
  const phgmg_real *Q11;  /* rn x rn V2^T Q V2 */
  const phgmg_real *Ms;   /* rn x p*p symmetrised M: Ms(:,k*p+j) = M(:,k*p+j) + M(:,j*p+k) */
  /* separable nonlinear part (nd > 0) */
  const phgmg_real *P0;   /* nd x r   rows of V0 at the kept coordinates */
  const phgmg_real *P1;   /* nd x rn  rows of V2 (QUADRATIC)             */
  const phgmg_real *w;    /* nd       weights (structure-preserving DEIM) */
  const phgmg_real *poly; /* poly_deg+1 coefficients of phi, constant first */
  /* precomputed GL3 step map (LINEAR, nd == 0; NULL if absent) for step dt:
     x+ = Phi x + Gam u3, stage values Y = SX x + SU u3 (for the energy). */
  phgmg_real dt;
  const phgmg_real *Phi;  /* r x r    */
  const phgmg_real *Gam;  /* r x 3m   (u3 = [u(t+c1 h); u(t+c2 h); u(t+c3 h)]) */
  const phgmg_real *SX;   /* 3r x r   */
  const phgmg_real *SU;   /* 3r x 3m  */
} phgmg_rom;

/* Checks a model's sizes and pointers for consistency (not its values). */
PHGMG_DEF phgmg_result phgmg_rom_check(const phgmg_rom *rom);

/* Evaluation (allocation-free; `work` must hold phgmg_rom_eval_work_size(rom) reals). */
PHGMG_DEF size_t phgmg_rom_eval_work_size(const phgmg_rom *rom);
PHGMG_DEF phgmg_real phgmg_rom_hamiltonian(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *work);
PHGMG_DEF void phgmg_rom_gradient(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *g, phgmg_real *work);
/* f = K(x) grad H(x) + Bh u (u may be NULL). PHGMG_ERR_SINGULAR if D^T G D is singular at x. */
PHGMG_DEF phgmg_result phgmg_rom_rhs(const phgmg_rom *rom, const phgmg_real *x, const phgmg_real *u,
                                     phgmg_real *f, phgmg_real *work);
/* y = Bh^T grad H(x). */
PHGMG_DEF void phgmg_rom_output(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *y, phgmg_real *work);
/* The reduced structure matrices at x: Jr = (K - K^T)/2 (skew), Rr = -(K + K^T)/2 (sym PSD), r x r. */
PHGMG_DEF phgmg_result phgmg_rom_structure(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *Jr,
                                           phgmg_real *Rr, phgmg_real *work);
/* Newton Jacobian of the right-hand side, d f / d x (r x r): analytic for LINEAR
   models; for QUADRATIC ones a central finite difference of phgmg_rom_rhs. */
PHGMG_DEF phgmg_result phgmg_rom_jacobian(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *Jf,
                                          phgmg_real *work);

/* --- the online stepper (GL3, simplified Newton on the 3r stage system) --- */
typedef struct phgmg_rom_stats {
  long steps, newton_iters, factorizations, failures;
} phgmg_rom_stats;

typedef struct phgmg_rom_stepper {
  const phgmg_rom *rom;
  phgmg_real dt, tol;     /* step and Newton tolerance (inf-norm of the stage residual) */
  int max_iter;           /* Newton cap per step                                        */
  int use_map;            /* 1 if the precomputed step map is used                      */
  int have_lu, have_prev; /* internal: factors valid / extrapolation data valid        */
  phgmg_real *ws;         /* caller memory, carved by init                              */
  size_t ws_count;
  phgmg_rom_stats stats;
} phgmg_rom_stepper;

/* Bytes of caller memory phgmg_rom_stepper_init needs for this model. */
PHGMG_DEF size_t phgmg_rom_stepper_memsize(const phgmg_rom *rom);
/* Compile-time upper bound in bytes for static buffers (r, m, rn, nd as above). */
#define PHGMG_ROM_STEPPER_MEMSIZE_MAX(r, m, rn, nd) \
  (sizeof(phgmg_real) * (size_t)(9 * (r) * (r) + 30 * (r) + 3 * (m) + 4 * (rn) * (r) + 2 * (rn) * (rn) + 6 * (rn) + 3 * (nd) + 64) \
   + sizeof(int) * (size_t)(4 * (r) + 8) + 64)
/* Set up a stepper in caller memory (mem must be aligned for phgmg_real and
   int; anything from malloc or a static phgmg_real array is). tol <= 0 gives
   1e-10 (double) / 1e-5 (float); max_iter <= 0 gives 10. PHGMG_ERR_WORKSPACE
   if mem_size < phgmg_rom_stepper_memsize(rom). */
PHGMG_DEF phgmg_result phgmg_rom_stepper_init(phgmg_rom_stepper *s, const phgmg_rom *rom, phgmg_real dt,
                                              phgmg_real tol, int max_iter, void *mem, size_t mem_size);
/* Forget the extrapolation history (call after changing x by hand). */
PHGMG_DEF void phgmg_rom_stepper_reset(phgmg_rom_stepper *s);
/* Stage times t + c_i dt, for evaluating u3. */
PHGMG_DEF void phgmg_rom_stage_times(phgmg_real t, phgmg_real dt, phgmg_real tc[3]);
/* One step: x (r) advanced in place. u3 = inputs at the three stage times
   (3m values, u(t+c1 dt) first; NULL = 0). y (m, may be NULL) = output at the
   new state. energy (may be NULL) += {supplied, dissipated} over the step.
   On failure (PHGMG_ERR_NOT_CONVERGED, _NANINF, _SINGULAR) x, y, energy are untouched. */
PHGMG_DEF phgmg_result phgmg_rom_step(phgmg_rom_stepper *s, phgmg_real *x, const phgmg_real *u3,
                                      phgmg_real *y, phgmg_real energy[2]);

#ifdef __cplusplus
}
#endif

/* >>export ================================================================ */
/* A reduced model leaves the workstation in two forms:
   - C source: static const arrays of phgmg_real plus a `static const phgmg_rom`
     descriptor, to be compiled into firmware (flash);
   - a binary file: magic "PHGMGROM", format version, scalar size (4 = float,
     8 = double), the sizes, then the arrays, all little-endian. Loading checks
     the magic, the version, the scalar type (it must match the build's
     phgmg_real) and the sizes; a damaged file gives PHGMG_ERR_FORMAT.
   Serialising and loading work in memory and need neither stdio nor heap;
   the file helpers are compiled out with PHGMG_NO_STDIO or PHGMG_NO_OFFLINE.
   A file written by a double build loads into a float build (values are
   rounded once) and vice versa. */
#ifdef __cplusplus
extern "C" {
#endif

#define PHGMG_ROM_FORMAT_VERSION 1u

/* Bytes phgmg_rom_serialize writes for this model. */
PHGMG_DEF size_t phgmg_rom_serialized_size(const phgmg_rom *rom);
/* Serialise into buf (cap bytes). *written = bytes used. PHGMG_ERR_WORKSPACE if cap is too small. */
PHGMG_DEF phgmg_result phgmg_rom_serialize(const phgmg_rom *rom, void *buf, size_t cap, size_t *written);
/* Bytes of memory phgmg_rom_deserialize needs to hold the model in buf
   (the arrays are copied, so buf may be freed afterwards). */
PHGMG_DEF phgmg_result phgmg_rom_deserialize_size(const void *buf, size_t len, size_t *need);
/* Rebuild a model from buf into caller memory mem (>= the size above, aligned
   for double); rom's views point into mem. */
PHGMG_DEF phgmg_result phgmg_rom_deserialize(const void *buf, size_t len, phgmg_rom *rom, void *mem,
                                             size_t mem_size);

#if !defined(PHGMG_NO_STDIO) && !defined(PHGMG_NO_OFFLINE)
/* Write the model as binary file. */
PHGMG_DEF phgmg_result phgmg_rom_save(const phgmg_rom *rom, const char *path);
/* Read a binary model file into one block allocated with alloc (NULL = default);
   *rom views into *block, which the caller frees (alloc->free or free()). */
PHGMG_DEF phgmg_result phgmg_rom_load(const char *path, phgmg_rom *rom, void **block,
                                      const phgmg_allocator *alloc);
/* Write the model as C source: arrays `<name>_<field>` and a descriptor
   `static const phgmg_rom <name>` (scalar type: this build's phgmg_real;
   values printed with enough digits to round-trip exactly). */
PHGMG_DEF phgmg_result phgmg_rom_export_c(const phgmg_rom *rom, const char *name, const char *path);
#endif

#ifdef __cplusplus
}
#endif

/* >>npy =================================================================== */
/* NumPy .npy files (offline half): snapshot matrices, bases and reference
   trajectories exchanged with Python.
   Read: format versions 1.0, 2.0 and 3.0; dtypes '<f8', '>f8', '<f4', '>f4';
   C or Fortran order; 0-d, 1-d and 2-d shapes. The result is always a
   column-major double matrix: shape () is 1 x 1, shape (n,) is n x 1, shape
   (r, c) is r x c. Empty shapes such as (0,) or (3, 0) give a zero-size matrix
   (a valid pointer to no elements). Bytes after the data are ignored, as NumPy
   does. Anything else (bad magic, bad header dict, other dtypes, more than two
   dimensions, a dimension above INT_MAX, a header longer than
   PHGMG_NPY_MAX_HEADER, truncated data) is PHGMG_ERR_FORMAT.
   Write: format version 1.0, '<f8' (or '<f4' with PHGMG_NPY_F32), Fortran order
   (or C order with PHGMG_NPY_C_ORDER), header padded so the data starts at a
   multiple of 64 bytes, as NumPy writes it.
   ndim selects the written shape: 2 gives (rows, cols); 1 gives (rows*cols,)
   and needs rows == 1 or cols == 1; 0 gives () and needs rows == cols == 1.
   The in-memory parser/serializer never touch files; the file functions are
   compiled out by PHGMG_NO_STDIO. On failure the output arguments are left
   unchanged and nothing stays allocated. */
#ifndef PHGMG_NO_OFFLINE
#ifdef __cplusplus
extern "C" {
#endif

#ifndef PHGMG_NPY_MAX_HEADER
#define PHGMG_NPY_MAX_HEADER 1048576 /* longest accepted header, bytes */
#endif

/* Flags of the writers (combine with |). */
#define PHGMG_NPY_C_ORDER 1u /* row-major data, 'fortran_order': False       */
#define PHGMG_NPY_F32     2u /* store float32 '<f4' (rounded) instead of '<f8' */

/* Parse an in-memory .npy image buf[0..len). On success *out receives a
   column-major rows x cols matrix (ld = rows) allocated with alloc (NULL =
   default); release it with phgmg_npy_free. rows, cols and out are required,
   ndim (0, 1 or 2) may be NULL. Errors: PHGMG_ERR_INVALID_ARG (NULL buf/out/
   rows/cols), PHGMG_ERR_FORMAT, PHGMG_ERR_NOMEM. Safe on arbitrary bytes. */
PHGMG_DEF phgmg_result phgmg_npy_parse(const void *buf, size_t len, double **out, int *rows,
                                       int *cols, int *ndim, const phgmg_allocator *alloc);

/* Serialize the rows x cols matrix A (column-major, leading dimension ld >=
   max(1, rows)) as a .npy image into buf[0..cap). *len always receives the
   number of bytes needed; with buf == NULL only that size is computed.
   Errors: PHGMG_ERR_INVALID_ARG (NULL A with elements, NULL len, unknown
   flags), PHGMG_ERR_SIZE (bad dimensions/ld/ndim), PHGMG_ERR_WORKSPACE
   (cap < *len; nothing is written). */
PHGMG_DEF phgmg_result phgmg_npy_serialize(const double *A, int rows, int cols, int ld, int ndim,
                                           unsigned flags, void *buf, size_t cap, size_t *len);

/* Free a matrix returned by phgmg_npy_parse / phgmg_npy_read (same allocator;
   NULL pointer is a no-op). */
PHGMG_DEF void phgmg_npy_free(double *p, const phgmg_allocator *alloc);

#ifndef PHGMG_NO_STDIO
/* Read a .npy file; outputs and errors as phgmg_npy_parse, plus PHGMG_ERR_IO
   if the file cannot be opened or read. A file shorter than its header
   promises is PHGMG_ERR_FORMAT. */
PHGMG_DEF phgmg_result phgmg_npy_read(const char *path, double **out, int *rows, int *cols,
                                      int *ndim, const phgmg_allocator *alloc);

/* Write A (as phgmg_npy_serialize) to the file path, streaming, without
   allocating. Errors as phgmg_npy_serialize (except WORKSPACE), plus
   PHGMG_ERR_IO; a partly written file is removed. */
PHGMG_DEF phgmg_result phgmg_npy_write(const char *path, const double *A, int rows, int cols,
                                       int ld, int ndim, unsigned flags);
#endif /* PHGMG_NO_STDIO */

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

/* >>linalg (implementation) ============================================== */
#ifndef PHGMG_NO_OFFLINE

/* ---- norms -------------------------------------------------------------- */
PHGMG_DEF double phgmg_norm1(int m, int n, const double *A, int lda) {
  double best = 0.0;
  int i, j;
  for (j = 0; j < n; ++j) {
    const double *a = A + (size_t)j * (size_t)lda;
    double s = 0.0;
    for (i = 0; i < m; ++i) s += fabs(a[i]);
    if (s > best || s != s) best = s;
  }
  return best;
}

PHGMG_DEF double phgmg_normf(int m, int n, const double *A, int lda) {
  /* scaled sum of squares (LAPACK dlassq): scale^2 * ssq */
  double scale = 0.0, ssq = 1.0;
  int i, j;
  for (j = 0; j < n; ++j) {
    const double *a = A + (size_t)j * (size_t)lda;
    for (i = 0; i < m; ++i) {
      double v = fabs(a[i]);
      if (v != 0.0 || v != v) {
        if (v != v) return v;
        if (scale < v) {
          double r = scale / v;
          ssq = 1.0 + ssq * r * r;
          scale = v;
        } else {
          double r = v / scale;
          ssq += r * r;
        }
      }
    }
  }
  return scale * sqrt(ssq);
}

/* ---- gemv / gemm ---------------------------------------------------------- */
PHGMG_DEF void phgmg_gemv(char trans, int m, int n, double alpha, const double *A, int lda,
                          const double *x, double beta, double *y) {
  int i, j;
  int ny = (trans == 'N' || trans == 'n') ? m : n;
  PHGMG_ASSERT(trans == 'N' || trans == 'n' || trans == 'T' || trans == 't');
  if (m <= 0 || n <= 0) {
    for (i = 0; i < ny; ++i) y[i] = (beta == 0.0) ? 0.0 : beta * y[i];
    return;
  }
#ifdef PHGMG_USE_CBLAS
  cblas_dgemv(CblasColMajor, (ny == m) ? CblasNoTrans : CblasTrans, m, n, alpha, A, lda, x, 1,
              beta, y, 1);
#else
  if (beta == 0.0) {
    for (i = 0; i < ny; ++i) y[i] = 0.0;
  } else if (beta != 1.0) {
    for (i = 0; i < ny; ++i) y[i] *= beta;
  }
  if (alpha == 0.0) return;
  if (trans == 'N' || trans == 'n') {
    /* y += alpha * A x, column sweeps (axpy) */
    for (j = 0; j < n; ++j) {
      const double *a = A + (size_t)j * (size_t)lda;
      double t = alpha * x[j];
      if (t == 0.0) continue;
      for (i = 0; i < m; ++i) y[i] += t * a[i];
    }
  } else {
    /* y += alpha * A^T x, dot products of columns */
    for (j = 0; j < n; ++j) {
      const double *a = A + (size_t)j * (size_t)lda;
      double s0 = 0.0, s1 = 0.0;
      for (i = 0; i + 1 < m; i += 2) { s0 += a[i] * x[i]; s1 += a[i + 1] * x[i + 1]; }
      if (i < m) s0 += a[i] * x[i];
      y[j] += alpha * (s0 + s1);
    }
  }
#endif
}

#ifndef PHGMG_USE_CBLAS
/* Portable GEMM: a block of op(A) (MC x KC) is packed into 8-row slivers (on
   the stack, MC*KC doubles), then 8 x 6 tiles of C are computed by a
   register-blocked micro-kernel that streams the matching 6 columns of op(B)
   directly from B. With GCC/Clang the micro-kernel uses vector extensions
   (define PHGMG_NO_VECTOR_EXT to get the plain C version). */
#ifndef PHGMG_GEMM_MC
#define PHGMG_GEMM_MC 64 /* multiple of 8 */
#endif
#ifndef PHGMG_GEMM_KC
#define PHGMG_GEMM_KC 256
#endif
#define PHGMG__MR 8
#define PHGMG__NR 6

/* C(0:mr, 0:nr) += alpha * Ap * op(B)(0:kc, 0:nr), Ap packed (Ap[8p + i]);
   op(B)(p, j) = B[p*bsp + j*bsj]. mr <= 8, nr <= 6. */
PHGMG__PRIV void phgmg__gemm_micro(int kc, const double *Ap, const double *B, size_t bsp,
                                   size_t bsj, int mr, int nr, double alpha, double *C, int ldc) {
  double tile[PHGMG__MR * PHGMG__NR];
  const double *b0 = B, *b1 = B + (nr > 1 ? bsj : 0), *b2 = B + (nr > 2 ? 2 * bsj : 0);
  const double *b3 = B + (nr > 3 ? 3 * bsj : 0), *b4 = B + (nr > 4 ? 4 * bsj : 0);
  const double *b5 = B + (nr > 5 ? 5 * bsj : 0);
  int p, i, j;
#if (defined(__GNUC__) || defined(__clang__)) && !defined(PHGMG_NO_VECTOR_EXT)
  typedef double phgmg__v4 __attribute__((vector_size(32)));
  phgmg__v4 c00, c01, c10, c11, c20, c21, c30, c31, c40, c41, c50, c51, a0, a1;
  memset(&c00, 0, sizeof c00);
  c01 = c10 = c11 = c20 = c21 = c30 = c31 = c40 = c41 = c50 = c51 = c00;
  for (p = 0; p < kc; ++p) {
    size_t o = (size_t)p * bsp;
    double x;
    memcpy(&a0, Ap, sizeof a0);
    memcpy(&a1, Ap + 4, sizeof a1);
    Ap += PHGMG__MR;
    x = b0[o]; c00 += a0 * x; c01 += a1 * x;
    x = b1[o]; c10 += a0 * x; c11 += a1 * x;
    x = b2[o]; c20 += a0 * x; c21 += a1 * x;
    x = b3[o]; c30 += a0 * x; c31 += a1 * x;
    x = b4[o]; c40 += a0 * x; c41 += a1 * x;
    x = b5[o]; c50 += a0 * x; c51 += a1 * x;
  }
  memcpy(tile + 0, &c00, sizeof c00); memcpy(tile + 4, &c01, sizeof c01);
  memcpy(tile + 8, &c10, sizeof c10); memcpy(tile + 12, &c11, sizeof c11);
  memcpy(tile + 16, &c20, sizeof c20); memcpy(tile + 20, &c21, sizeof c21);
  memcpy(tile + 24, &c30, sizeof c30); memcpy(tile + 28, &c31, sizeof c31);
  memcpy(tile + 32, &c40, sizeof c40); memcpy(tile + 36, &c41, sizeof c41);
  memcpy(tile + 40, &c50, sizeof c50); memcpy(tile + 44, &c51, sizeof c51);
#else
  for (i = 0; i < PHGMG__MR * PHGMG__NR; ++i) tile[i] = 0.0;
  for (p = 0; p < kc; ++p) {
    size_t o = (size_t)p * bsp;
    double x0 = b0[o], x1 = b1[o], x2 = b2[o], x3 = b3[o], x4 = b4[o], x5 = b5[o];
    for (i = 0; i < PHGMG__MR; ++i) {
      double a = Ap[i];
      tile[i] += a * x0; tile[8 + i] += a * x1; tile[16 + i] += a * x2;
      tile[24 + i] += a * x3; tile[32 + i] += a * x4; tile[40 + i] += a * x5;
    }
    Ap += PHGMG__MR;
  }
#endif
  for (j = 0; j < nr; ++j) {
    double *c = C + (size_t)j * (size_t)ldc;
    const double *t = tile + PHGMG__MR * j;
    for (i = 0; i < mr; ++i) c[i] += alpha * t[i];
  }
}
#endif

PHGMG_DEF void phgmg_gemm(char transa, char transb, int m, int n, int k, double alpha,
                          const double *A, int lda, const double *B, int ldb,
                          double beta, double *C, int ldc) {
  int ta = (transa == 'T' || transa == 't');
  int tb = (transb == 'T' || transb == 't');
  int i, j;
  PHGMG_ASSERT(ta || transa == 'N' || transa == 'n');
  PHGMG_ASSERT(tb || transb == 'N' || transb == 'n');
  if (m <= 0 || n <= 0) return;
#ifdef PHGMG_USE_CBLAS
  if (k > 0 && alpha != 0.0) {
    cblas_dgemm(CblasColMajor, ta ? CblasTrans : CblasNoTrans, tb ? CblasTrans : CblasNoTrans,
                m, n, k, alpha, A, lda, B, ldb, beta, C, ldc);
    return;
  }
#endif
  for (j = 0; j < n; ++j) {
    double *c = C + (size_t)j * (size_t)ldc;
    if (beta == 0.0) for (i = 0; i < m; ++i) c[i] = 0.0;
    else if (beta != 1.0) for (i = 0; i < m; ++i) c[i] *= beta;
  }
  if (alpha == 0.0 || k <= 0) return;
#ifndef PHGMG_USE_CBLAS
  {
    double Ap[PHGMG_GEMM_MC * PHGMG_GEMM_KC];
    size_t bsp = tb ? (size_t)ldb : 1, bsj = tb ? 1 : (size_t)ldb;
    int pc, ic, ir, jr, p;
    for (pc = 0; pc < k; pc += PHGMG_GEMM_KC) {
      int kc = PHGMG__MIN(PHGMG_GEMM_KC, k - pc);
      for (ic = 0; ic < m; ic += PHGMG_GEMM_MC) {
        int mc = PHGMG__MIN(PHGMG_GEMM_MC, m - ic);
        /* pack op(A)(ic:ic+mc, pc:pc+kc) into 8-row slivers, zero padded */
        for (ir = 0; ir < mc; ir += PHGMG__MR) {
          int mr = PHGMG__MIN(PHGMG__MR, mc - ir);
          double *dst = Ap + (size_t)ir * (size_t)kc;
          if (!ta) {
            for (p = 0; p < kc; ++p) {
              const double *src = A + (ic + ir) + (size_t)(pc + p) * (size_t)lda;
              double *d = dst + (size_t)p * PHGMG__MR;
              for (i = 0; i < mr; ++i) d[i] = src[i];
              for (; i < PHGMG__MR; ++i) d[i] = 0.0;
            }
          } else {
            for (i = 0; i < PHGMG__MR; ++i) {
              if (i < mr) {
                const double *src = A + pc + (size_t)(ic + ir + i) * (size_t)lda;
                for (p = 0; p < kc; ++p) dst[(size_t)p * PHGMG__MR + i] = src[p];
              } else {
                for (p = 0; p < kc; ++p) dst[(size_t)p * PHGMG__MR + i] = 0.0;
              }
            }
          }
        }
        for (jr = 0; jr < n; jr += PHGMG__NR) {
          int nr = PHGMG__MIN(PHGMG__NR, n - jr);
          const double *bp = B + (size_t)pc * bsp + (size_t)jr * bsj;
          for (ir = 0; ir < mc; ir += PHGMG__MR)
            phgmg__gemm_micro(kc, Ap + (size_t)ir * (size_t)kc, bp, bsp, bsj,
                              PHGMG__MIN(PHGMG__MR, mc - ir), nr, alpha,
                              C + (ic + ir) + (size_t)jr * (size_t)ldc, ldc);
        }
      }
    }
  }
#endif
}

/* ---- real LU -------------------------------------------------------------- */
PHGMG_DEF phgmg_result phgmg_lu_factor(int n, double *A, int lda, int *ipiv) {
  int i, j, k;
  phgmg_result rc = PHGMG_OK;
  if (n < 0 || lda < PHGMG__MAX(n, 1)) return PHGMG_ERR_SIZE;
  if (n == 0) return PHGMG_OK;
  if (!A || !ipiv) return PHGMG_ERR_INVALID_ARG;
  for (j = 0; j < n; ++j)
    if (!phgmg__all_finite(A + (size_t)j * (size_t)lda, (size_t)n)) return PHGMG_ERR_NANINF;
  for (k = 0; k < n; ++k) {
    double *ak = A + (size_t)k * (size_t)lda;
    int p = k;
    double amax = fabs(ak[k]);
    for (i = k + 1; i < n; ++i)
      if (fabs(ak[i]) > amax) { amax = fabs(ak[i]); p = i; }
    ipiv[k] = p;
    if (amax == 0.0) { rc = PHGMG_ERR_SINGULAR; continue; }
    if (p != k)
      for (j = 0; j < n; ++j) {
        double *c = A + (size_t)j * (size_t)lda, t = c[k];
        c[k] = c[p]; c[p] = t;
      }
    {
      double r = 1.0 / ak[k];
      for (i = k + 1; i < n; ++i) ak[i] *= r;
    }
    for (j = k + 1; j < n; ++j) {
      double *c = A + (size_t)j * (size_t)lda;
      double t = c[k];
      if (t == 0.0) continue;
      for (i = k + 1; i < n; ++i) c[i] -= t * ak[i];
    }
  }
  return rc;
}

PHGMG_DEF void phgmg_lu_solve(char trans, int n, const double *LU, int lda, const int *ipiv,
                              int nrhs, double *B, int ldb) {
  int i, j, k;
  int tr = (trans == 'T' || trans == 't');
  PHGMG_ASSERT(tr || trans == 'N' || trans == 'n');
  for (j = 0; j < nrhs; ++j) {
    double *b = B + (size_t)j * (size_t)ldb;
    if (!tr) {
      for (k = 0; k < n; ++k)
        if (ipiv[k] != k) { double t = b[k]; b[k] = b[ipiv[k]]; b[ipiv[k]] = t; }
      /* L y = b (unit lower), column oriented */
      for (k = 0; k < n; ++k) {
        const double *l = LU + (size_t)k * (size_t)lda;
        double t = b[k];
        if (t != 0.0) for (i = k + 1; i < n; ++i) b[i] -= t * l[i];
      }
      /* U x = y */
      for (k = n - 1; k >= 0; --k) {
        const double *u = LU + (size_t)k * (size_t)lda;
        double t = b[k] / u[k];
        b[k] = t;
        if (t != 0.0) for (i = 0; i < k; ++i) b[i] -= t * u[i];
      }
    } else {
      /* U^T y = b: dot products with columns of U */
      for (k = 0; k < n; ++k) {
        const double *u = LU + (size_t)k * (size_t)lda;
        double s = b[k];
        for (i = 0; i < k; ++i) s -= u[i] * b[i];
        b[k] = s / u[k];
      }
      /* L^T z = y */
      for (k = n - 1; k >= 0; --k) {
        const double *l = LU + (size_t)k * (size_t)lda;
        double s = b[k];
        for (i = k + 1; i < n; ++i) s -= l[i] * b[i];
        b[k] = s;
      }
      for (k = n - 1; k >= 0; --k)
        if (ipiv[k] != k) { double t = b[k]; b[k] = b[ipiv[k]]; b[ipiv[k]] = t; }
    }
  }
}

/* ---- complex LU (interleaved re,im) ----------------------------------------- */
PHGMG_DEF phgmg_result phgmg_zlu_factor(int n, double *A, int lda, int *ipiv) {
  int i, j, k;
  phgmg_result rc = PHGMG_OK;
  if (n < 0 || lda < PHGMG__MAX(n, 1)) return PHGMG_ERR_SIZE;
  if (n == 0) return PHGMG_OK;
  if (!A || !ipiv) return PHGMG_ERR_INVALID_ARG;
  for (j = 0; j < n; ++j)
    if (!phgmg__all_finite(A + 2 * (size_t)j * (size_t)lda, 2 * (size_t)n)) return PHGMG_ERR_NANINF;
  for (k = 0; k < n; ++k) {
    double *ak = A + 2 * (size_t)k * (size_t)lda;
    int p = k;
    double amax = fabs(ak[2 * k]) + fabs(ak[2 * k + 1]);
    for (i = k + 1; i < n; ++i) {
      double v = fabs(ak[2 * i]) + fabs(ak[2 * i + 1]);
      if (v > amax) { amax = v; p = i; }
    }
    ipiv[k] = p;
    if (amax == 0.0) { rc = PHGMG_ERR_SINGULAR; continue; }
    if (p != k)
      for (j = 0; j < n; ++j) {
        double *c = A + 2 * (size_t)j * (size_t)lda, t;
        t = c[2 * k]; c[2 * k] = c[2 * p]; c[2 * p] = t;
        t = c[2 * k + 1]; c[2 * k + 1] = c[2 * p + 1]; c[2 * p + 1] = t;
      }
    {
      /* r = 1 / pivot (Smith's division) */
      double pr = ak[2 * k], pi = ak[2 * k + 1], rr, ri;
      if (fabs(pr) >= fabs(pi)) {
        double q = pi / pr, d = pr + pi * q;
        rr = 1.0 / d; ri = -q / d;
      } else {
        double q = pr / pi, d = pr * q + pi;
        rr = q / d; ri = -1.0 / d;
      }
      for (i = k + 1; i < n; ++i) {
        double xr = ak[2 * i], xi = ak[2 * i + 1];
        ak[2 * i] = xr * rr - xi * ri;
        ak[2 * i + 1] = xr * ri + xi * rr;
      }
    }
    for (j = k + 1; j < n; ++j) {
      double *c = A + 2 * (size_t)j * (size_t)lda;
      double tr = c[2 * k], ti = c[2 * k + 1];
      if (tr == 0.0 && ti == 0.0) continue;
      for (i = k + 1; i < n; ++i) {
        double lr = ak[2 * i], li = ak[2 * i + 1];
        c[2 * i] -= tr * lr - ti * li;
        c[2 * i + 1] -= tr * li + ti * lr;
      }
    }
  }
  return rc;
}

PHGMG_DEF void phgmg_zlu_solve(int n, const double *LU, int lda, const int *ipiv,
                               int nrhs, double *B, int ldb) {
  int i, j, k;
  for (j = 0; j < nrhs; ++j) {
    double *b = B + 2 * (size_t)j * (size_t)ldb;
    for (k = 0; k < n; ++k) {
      int p = ipiv[k];
      if (p != k) {
        double t = b[2 * k]; b[2 * k] = b[2 * p]; b[2 * p] = t;
        t = b[2 * k + 1]; b[2 * k + 1] = b[2 * p + 1]; b[2 * p + 1] = t;
      }
    }
    for (k = 0; k < n; ++k) {
      const double *l = LU + 2 * (size_t)k * (size_t)lda;
      double tr = b[2 * k], ti = b[2 * k + 1];
      if (tr == 0.0 && ti == 0.0) continue;
      for (i = k + 1; i < n; ++i) {
        double lr = l[2 * i], li = l[2 * i + 1];
        b[2 * i] -= tr * lr - ti * li;
        b[2 * i + 1] -= tr * li + ti * lr;
      }
    }
    for (k = n - 1; k >= 0; --k) {
      const double *u = LU + 2 * (size_t)k * (size_t)lda;
      double pr = u[2 * k], pi = u[2 * k + 1], xr = b[2 * k], xi = b[2 * k + 1], tr, ti;
      if (fabs(pr) >= fabs(pi)) {
        double q = pi / pr, d = pr + pi * q;
        tr = (xr + xi * q) / d; ti = (xi - xr * q) / d;
      } else {
        double q = pr / pi, d = pr * q + pi;
        tr = (xr * q + xi) / d; ti = (xi * q - xr) / d;
      }
      b[2 * k] = tr; b[2 * k + 1] = ti;
      if (tr == 0.0 && ti == 0.0) continue;
      for (i = 0; i < k; ++i) {
        double ur = u[2 * i], ui = u[2 * i + 1];
        b[2 * i] -= tr * ur - ti * ui;
        b[2 * i + 1] -= tr * ui + ti * ur;
      }
    }
  }
}


/* ---- condition estimate (Hager 1984, Higham 1988; LAPACK dlacn2) ---------- */
PHGMG__PRIV double phgmg__asum(int n, const double *x) {
  double s = 0.0;
  int i;
  for (i = 0; i < n; ++i) s += fabs(x[i]);
  return s;
}
PHGMG__PRIV int phgmg__iamax(int n, const double *x) {
  int i, j = 0;
  double m = -1.0;
  for (i = 0; i < n; ++i)
    if (fabs(x[i]) > m) { m = fabs(x[i]); j = i; }
  return j;
}

PHGMG_DEF double phgmg_lu_rcond(int n, const double *LU, int lda, const int *ipiv,
                                double anorm1, double *work, int *iwork) {
  double *x = work, est, estold, temp;
  int *isgn = iwork;
  int i, j, jlast, iter, same;
  if (n <= 0) return 1.0;
  if (!(anorm1 > 0.0) || anorm1 == HUGE_VAL) return 0.0;
  for (i = 0; i < n; ++i) {
    double d = LU[i + (size_t)i * (size_t)lda];
    if (d == 0.0 || d != d) return 0.0;
  }
  for (i = 0; i < n; ++i) x[i] = 1.0 / (double)n;
  phgmg_lu_solve('N', n, LU, lda, ipiv, 1, x, n);
  if (n == 1) {
    est = fabs(x[0]);
  } else {
    est = phgmg__asum(n, x);
    for (i = 0; i < n; ++i) { isgn[i] = x[i] >= 0.0 ? 1 : -1; x[i] = (double)isgn[i]; }
    phgmg_lu_solve('T', n, LU, lda, ipiv, 1, x, n);
    j = phgmg__iamax(n, x);
    for (iter = 2;; ++iter) {
      for (i = 0; i < n; ++i) x[i] = 0.0;
      x[j] = 1.0;
      phgmg_lu_solve('N', n, LU, lda, ipiv, 1, x, n);
      estold = est;
      est = phgmg__asum(n, x);
      same = 1;
      for (i = 0; i < n; ++i)
        if ((x[i] >= 0.0 ? 1 : -1) != isgn[i]) { same = 0; break; }
      if (same || est <= estold) { if (est < estold) est = estold; break; }
      for (i = 0; i < n; ++i) { isgn[i] = x[i] >= 0.0 ? 1 : -1; x[i] = (double)isgn[i]; }
      phgmg_lu_solve('T', n, LU, lda, ipiv, 1, x, n);
      jlast = j;
      j = phgmg__iamax(n, x);
      if (fabs(x[jlast]) == fabs(x[j]) || iter >= 5) break;
    }
    /* alternating-sign test vector */
    for (i = 0; i < n; ++i)
      x[i] = ((i & 1) ? -1.0 : 1.0) * (1.0 + (double)i / (double)(n - 1));
    phgmg_lu_solve('N', n, LU, lda, ipiv, 1, x, n);
    temp = 2.0 * phgmg__asum(n, x) / (3.0 * (double)n);
    if (temp > est) est = temp;
  }
  if (!(est > 0.0) || est != est) return 0.0;
  return (1.0 / est) / anorm1;
}

/* ---- Householder QR ---------------------------------------------------------- */
/* Generate H = I - tau v v^T with v = (1, x) such that H (alpha; x) = (beta; 0).
   n is the length including alpha. x is overwritten by v(1:). */
PHGMG__PRIV void phgmg__larfg(int n, double *alpha, double *x, double *tau) {
  double xnorm, beta, r;
  int i;
  if (n <= 1) { *tau = 0.0; return; }
  xnorm = phgmg_normf(n - 1, 1, x, n - 1);
  if (xnorm == 0.0) { *tau = 0.0; return; }
  beta = -copysign(hypot(*alpha, xnorm), *alpha);
  *tau = (beta - *alpha) / beta;
  r = 1.0 / (*alpha - beta);
  for (i = 0; i < n - 1; ++i) x[i] *= r;
  *alpha = beta;
}

/* C (m x n) := (I - tau v v^T) C, v = (1, v[1..m-1]) (v[0] is not read). */
PHGMG__PRIV void phgmg__larf_left(int m, int n, const double *v, double tau, double *C, int ldc) {
  int i, j;
  if (tau == 0.0) return;
  for (j = 0; j < n; ++j) {
    double *c = C + (size_t)j * (size_t)ldc;
    double s = c[0];
    for (i = 1; i < m; ++i) s += v[i] * c[i];
    s *= tau;
    if (s == 0.0) continue;
    c[0] -= s;
    for (i = 1; i < m; ++i) c[i] -= s * v[i];
  }
}

PHGMG__PRIV int phgmg__mat_finite(int m, int n, const double *A, int lda) {
  int j;
  for (j = 0; j < n; ++j)
    if (!phgmg__all_finite(A + (size_t)j * (size_t)lda, (size_t)m)) return 0;
  return 1;
}

PHGMG_DEF phgmg_result phgmg_qr(int m, int n, double *A, int lda, double *tau) {
  int k, kmin = PHGMG__MIN(m, n);
  if (m < 0 || n < 0 || lda < PHGMG__MAX(m, 1)) return PHGMG_ERR_SIZE;
  if (kmin == 0) return PHGMG_OK;
  if (!A || !tau) return PHGMG_ERR_INVALID_ARG;
  if (!phgmg__mat_finite(m, n, A, lda)) return PHGMG_ERR_NANINF;
  for (k = 0; k < kmin; ++k) {
    double *akk = A + k + (size_t)k * (size_t)lda;
    phgmg__larfg(m - k, akk, akk + 1, &tau[k]);
    if (k + 1 < n) phgmg__larf_left(m - k, n - k - 1, akk, tau[k], akk + lda, lda);
  }
  return PHGMG_OK;
}

/* QR with column pivoting, stopping early (at step k = *rank) once every
   trailing column norm is <= tol (tol < 0: never). vn: 2n doubles. */
PHGMG__PRIV void phgmg__qrcp_core(int m, int n, double *A, int lda, double *tau, int *jpvt,
                                  double *vn, double tol, int *rank) {
  double *vn1 = vn, *vn2 = vn + n;
  const double tol3z = sqrt(PHGMG__EPS);
  int i, j, k, kmin = PHGMG__MIN(m, n);
  for (j = 0; j < n; ++j) {
    jpvt[j] = j;
    vn1[j] = vn2[j] = phgmg_normf(m, 1, A + (size_t)j * (size_t)lda, lda);
  }
  for (k = 0; k < kmin; ++k) {
    int p = k + phgmg__iamax(n - k, vn1 + k);
    double *ak = A + (size_t)k * (size_t)lda;
    if (tol >= 0.0 && vn1[p] <= tol) break;
    if (p != k) {
      double *ap = A + (size_t)p * (size_t)lda, t;
      int it;
      for (i = 0; i < m; ++i) { t = ak[i]; ak[i] = ap[i]; ap[i] = t; }
      it = jpvt[p]; jpvt[p] = jpvt[k]; jpvt[k] = it;
      vn1[p] = vn1[k];
      vn2[p] = vn2[k];
    }
    phgmg__larfg(m - k, ak + k, ak + k + 1, &tau[k]);
    if (k + 1 < n) phgmg__larf_left(m - k, n - k - 1, ak + k, tau[k], ak + k + lda, lda);
    /* downdate the trailing column norms (LAPACK dlaqp2 safeguard) */
    for (j = k + 1; j < n; ++j) {
      if (vn1[j] != 0.0) {
        double *aj = A + (size_t)j * (size_t)lda;
        double temp = fabs(aj[k]) / vn1[j], temp2;
        temp = 1.0 - temp * temp;
        if (temp < 0.0) temp = 0.0;
        temp2 = temp * (vn1[j] / vn2[j]) * (vn1[j] / vn2[j]);
        if (temp2 <= tol3z) {
          vn1[j] = (k + 1 < m) ? phgmg_normf(m - k - 1, 1, aj + k + 1, m) : 0.0;
          vn2[j] = vn1[j];
        } else {
          vn1[j] *= sqrt(temp);
        }
      }
    }
  }
  *rank = k;
}

PHGMG_DEF phgmg_result phgmg_qrcp(int m, int n, double *A, int lda, double *tau, int *jpvt,
                                  double *work) {
  int r;
  if (m < 0 || n < 0 || lda < PHGMG__MAX(m, 1)) return PHGMG_ERR_SIZE;
  if (n == 0) return PHGMG_OK;
  if (!A || !jpvt || !work || (m > 0 && !tau)) return PHGMG_ERR_INVALID_ARG;
  if (!phgmg__mat_finite(m, n, A, lda)) return PHGMG_ERR_NANINF;
  phgmg__qrcp_core(m, n, A, lda, tau, jpvt, work, -1.0, &r);
  return PHGMG_OK;
}

PHGMG_DEF void phgmg_qr_form_q(int m, int k, double *A, int lda, const double *tau, double *work) {
  int i, j;
  (void)work;
  for (i = k - 1; i >= 0; --i) {
    double *ai = A + (size_t)i * (size_t)lda;
    if (i + 1 < k) {
      ai[i] = 1.0;
      phgmg__larf_left(m - i, k - i - 1, ai + i, tau[i], ai + i + lda, lda);
    }
    for (j = i + 1; j < m; ++j) ai[j] *= -tau[i];
    ai[i] = 1.0 - tau[i];
    for (j = 0; j < i; ++j) ai[j] = 0.0;
  }
}

PHGMG_DEF void phgmg_qr_apply(char trans, int m, int n, int k, const double *A, int lda,
                              const double *tau, double *C, int ldc) {
  int i;
  int tr = (trans == 'T' || trans == 't');
  PHGMG_ASSERT(tr || trans == 'N' || trans == 'n');
  if (tr) {
    for (i = 0; i < k; ++i)
      phgmg__larf_left(m - i, n, A + i + (size_t)i * (size_t)lda, tau[i], C + i, ldc);
  } else {
    for (i = k - 1; i >= 0; --i)
      phgmg__larf_left(m - i, n, A + i + (size_t)i * (size_t)lda, tau[i], C + i, ldc);
  }
}

/* Solve R X = B, R n x n upper triangular (ldr), B n x nrhs (ldb), in place. */
PHGMG__PRIV void phgmg__trsv_upper(int n, const double *R, int ldr, int nrhs, double *B, int ldb) {
  int i, j, k;
  for (j = 0; j < nrhs; ++j) {
    double *b = B + (size_t)j * (size_t)ldb;
    for (k = n - 1; k >= 0; --k) {
      const double *r = R + (size_t)k * (size_t)ldr;
      double t = b[k] / r[k];
      b[k] = t;
      if (t != 0.0) for (i = 0; i < k; ++i) b[i] -= t * r[i];
    }
  }
}

PHGMG_DEF phgmg_result phgmg_lstsq(int m, int n, int nrhs, const double *A, int lda,
                                   const double *B, int ldb, double lambda,
                                   double *X, int ldx, const phgmg_allocator *alloc) {
  int mm, i, j;
  double *W, *tau, *C, anorm;
  if (m < 0 || n < 0 || nrhs < 0 || lda < PHGMG__MAX(m, 1) || ldb < PHGMG__MAX(m, 1) ||
      ldx < PHGMG__MAX(n, 1))
    return PHGMG_ERR_SIZE;
  if (!(lambda >= 0.0)) return lambda != lambda ? PHGMG_ERR_NANINF : PHGMG_ERR_INVALID_ARG;
  if (lambda == HUGE_VAL) return PHGMG_ERR_NANINF;
  if (lambda == 0.0 && m < n) return PHGMG_ERR_RANK;
  if (n == 0 || nrhs == 0) return PHGMG_OK;
  if (!A || !B || !X) return PHGMG_ERR_INVALID_ARG;
  if (!phgmg__mat_finite(m, n, A, lda) || !phgmg__mat_finite(m, nrhs, B, ldb))
    return PHGMG_ERR_NANINF;
  mm = lambda > 0.0 ? m + n : m;
  W = phgmg__dalloc(alloc, (size_t)mm * (size_t)(n + nrhs) + (size_t)n);
  if (!W) return PHGMG_ERR_NOMEM;
  C = W + (size_t)mm * (size_t)n;
  tau = C + (size_t)mm * (size_t)nrhs;
  /* W = [A; sqrt(lambda) I], C = [B; 0] */
  for (j = 0; j < n; ++j) {
    double *w = W + (size_t)j * (size_t)mm;
    memcpy(w, A + (size_t)j * (size_t)lda, (size_t)m * sizeof(double));
    if (mm > m) {
      for (i = m; i < mm; ++i) w[i] = 0.0;
      w[m + j] = sqrt(lambda);
    }
  }
  for (j = 0; j < nrhs; ++j) {
    double *c = C + (size_t)j * (size_t)mm;
    memcpy(c, B + (size_t)j * (size_t)ldb, (size_t)m * sizeof(double));
    for (i = m; i < mm; ++i) c[i] = 0.0;
  }
  anorm = phgmg_normf(mm, n, W, mm);
  phgmg_qr(mm, n, W, mm, tau);
  for (j = 0; j < n; ++j) {
    double d = fabs(W[j + (size_t)j * (size_t)mm]);
    if (d <= (double)PHGMG__MAX(mm, n) * PHGMG__EPS * anorm || d == 0.0) {
      phgmg__free(alloc, W);
      return PHGMG_ERR_RANK;
    }
  }
  phgmg_qr_apply('T', mm, nrhs, n, W, mm, tau, C, mm);
  phgmg__trsv_upper(n, W, mm, nrhs, C, mm);
  for (j = 0; j < nrhs; ++j)
    memcpy(X + (size_t)j * (size_t)ldx, C + (size_t)j * (size_t)mm, (size_t)n * sizeof(double));
  phgmg__free(alloc, W);
  return PHGMG_OK;
}

/* ---- thin SVD: QRCP + second QR + one-sided Jacobi ----------------------------- */
/* One-sided (Hestenes) Jacobi on the columns of X (r x r, ldx): X V = W diag(sigma),
   V accumulated (r x r, ldv). On return X holds W diag(sigma). */
PHGMG__PRIV phgmg_result phgmg__jacobi_1s(int r, double *X, int ldx, double *V, int ldv,
                                          double *d) {
  const double tol = PHGMG__EPS * sqrt((double)PHGMG__MAX(r, 1));
  int sweep, p, q, i, rotated;
  for (sweep = 0; sweep < 80; ++sweep) {
    for (p = 0; p < r; ++p) {
      double *xp = X + (size_t)p * (size_t)ldx, s = 0.0;
      for (i = 0; i < r; ++i) s += xp[i] * xp[i];
      d[p] = s;
    }
    rotated = 0;
    for (p = 0; p < r - 1; ++p) {
      double *xp = X + (size_t)p * (size_t)ldx, *vp = V + (size_t)p * (size_t)ldv;
      for (q = p + 1; q < r; ++q) {
        double *xq = X + (size_t)q * (size_t)ldx, *vq = V + (size_t)q * (size_t)ldv;
        double alpha = d[p], beta = d[q], gamma = 0.0, zeta, t, c, s;
        if (alpha == 0.0 || beta == 0.0) continue;
        for (i = 0; i < r; ++i) gamma += xp[i] * xq[i];
        if (fabs(gamma) <= tol * sqrt(alpha) * sqrt(beta)) continue;
        rotated = 1;
        zeta = (beta - alpha) / (2.0 * gamma);
        t = (zeta >= 0.0 ? 1.0 : -1.0) / (fabs(zeta) + sqrt(1.0 + zeta * zeta));
        c = 1.0 / sqrt(1.0 + t * t);
        s = c * t;
        for (i = 0; i < r; ++i) {
          double a = xp[i], b = xq[i];
          xp[i] = c * a - s * b;
          xq[i] = s * a + c * b;
        }
        for (i = 0; i < r; ++i) {
          double a = vp[i], b = vq[i];
          vp[i] = c * a - s * b;
          vq[i] = s * a + c * b;
        }
        d[p] = alpha - t * gamma;
        d[q] = beta + t * gamma;
        if (!(d[p] >= 0.0)) d[p] = 0.0;
      }
    }
    if (!rotated) return PHGMG_OK;
  }
  return PHGMG_ERR_NOT_CONVERGED;
}

PHGMG_DEF phgmg_result phgmg_svd(int m, int n, const double *A, int lda, int kmax,
                                 double *S, double *U, int ldu, double *V, int ldv,
                                 int *k_out, int *rank_out, const phgmg_allocator *alloc) {
  double *W = NULL, *tau, *vn, *Rt, *tau2, *X, *Vj, *d, anorm;
  int *jpvt = NULL, *perm;
  int r, rnz, k, i, j, kmin = PHGMG__MIN(m, n);
  phgmg_result rc;
  size_t nw;
  if (m < 0 || n < 0 || kmax < 0 || lda < PHGMG__MAX(m, 1)) return PHGMG_ERR_SIZE;
  if (kmax > 0 && (ldu < PHGMG__MAX(m, 1) || (V && ldv < PHGMG__MAX(n, 1)))) return PHGMG_ERR_SIZE;
  if (!k_out || (kmin > 0 && !A) || (kmax > 0 && (!S || !U))) return PHGMG_ERR_INVALID_ARG;
  if (kmin == 0) {
    *k_out = 0;
    if (rank_out) *rank_out = 0;
    return PHGMG_OK;
  }
  if (!phgmg__mat_finite(m, n, A, lda)) return PHGMG_ERR_NANINF;
  /* workspace: W (m x n), tau (kmin), vn (2n) */
  nw = (size_t)m * (size_t)n + (size_t)kmin + 2 * (size_t)n;
  W = phgmg__dalloc(alloc, nw);
  jpvt = phgmg__ialloc(alloc, (size_t)n + (size_t)kmin);
  if (!W || !jpvt) { phgmg__free(alloc, W); phgmg__free(alloc, jpvt); return PHGMG_ERR_NOMEM; }
  perm = jpvt + n;
  tau = W + (size_t)m * (size_t)n;
  vn = tau + kmin;
  for (j = 0; j < n; ++j)
    memcpy(W + (size_t)j * (size_t)m, A + (size_t)j * (size_t)lda, (size_t)m * sizeof(double));
  anorm = phgmg_normf(m, n, W, m);
  phgmg__qrcp_core(m, n, W, m, tau, jpvt, vn, PHGMG__EPS * anorm, &r);
  if (r == 0) {
    *k_out = 0;
    if (rank_out) *rank_out = 0;
    phgmg__free(alloc, W);
    phgmg__free(alloc, jpvt);
    return PHGMG_OK;
  }
  {
    /* second workspace: Rt (n x r), tau2 (r), X (r x r), Vj (r x r), d (r) */
    double *W2 = phgmg__dalloc(alloc, (size_t)n * (size_t)r + 2 * (size_t)r * (size_t)r +
                                          2 * (size_t)r);
    if (!W2) { phgmg__free(alloc, W); phgmg__free(alloc, jpvt); return PHGMG_ERR_NOMEM; }
    Rt = W2;
    tau2 = Rt + (size_t)n * (size_t)r;
    X = tau2 + r;
    Vj = X + (size_t)r * (size_t)r;
    d = Vj + (size_t)r * (size_t)r;
    /* Rt = R^T, R = W(0:r, 0:n) upper trapezoidal */
    for (i = 0; i < r; ++i) {
      double *rt = Rt + (size_t)i * (size_t)n;
      for (j = 0; j < i; ++j) rt[j] = 0.0;
      for (j = i; j < n; ++j) rt[j] = W[i + (size_t)j * (size_t)m];
    }
    phgmg_qr(n, r, Rt, n, tau2);
    /* X = R2^T (lower triangular), Vj = I */
    for (j = 0; j < r; ++j) {
      double *x = X + (size_t)j * (size_t)r, *v = Vj + (size_t)j * (size_t)r;
      for (i = 0; i < r; ++i) {
        x[i] = i >= j ? Rt[j + (size_t)i * (size_t)n] : 0.0;
        v[i] = i == j ? 1.0 : 0.0;
      }
    }
    rc = phgmg__jacobi_1s(r, X, r, Vj, r, d);
    if (rc == PHGMG_OK) {
      /* sigma_j = ||X(:,j)||, order descending */
      for (j = 0; j < r; ++j) {
        d[j] = phgmg_normf(r, 1, X + (size_t)j * (size_t)r, r);
        perm[j] = j;
      }
      for (i = 1; i < r; ++i) { /* insertion sort, r is small */
        int pj = perm[i];
        for (j = i - 1; j >= 0 && d[perm[j]] < d[pj]; --j) perm[j + 1] = perm[j];
        perm[j + 1] = pj;
      }
      rnz = r; /* an exactly zero singular value has no singular vector: drop it */
      while (rnz > 0 && !(d[perm[rnz - 1]] > 0.0)) --rnz;
      k = PHGMG__MIN(kmax, rnz);
      for (j = 0; j < k; ++j) {
        int c = perm[j];
        double s = d[c], *u = U + (size_t)j * (size_t)ldu;
        const double *x = X + (size_t)c * (size_t)r;
        S[j] = s;
        for (i = 0; i < r; ++i) u[i] = x[i] / s;
        for (i = r; i < m; ++i) u[i] = 0.0;
      }
      /* U = Q [W; 0] with the r reflectors of the pivoted QR */
      if (k > 0) phgmg_qr_apply('N', m, k, PHGMG__MIN(r, kmin), W, m, tau, U, ldu);
      if (V && k > 0) {
        /* V = P Q2 [Vj; 0]; Rt's reflectors give Q2 (n x r) */
        int r2 = PHGMG__MIN(n, r);
        for (j = 0; j < k; ++j) {
          double *v = V + (size_t)j * (size_t)ldv, *y = vn;
          const double *vj = Vj + (size_t)perm[j] * (size_t)r;
          for (i = 0; i < r; ++i) y[i] = vj[i];
          for (i = r; i < n; ++i) y[i] = 0.0;
          phgmg_qr_apply('N', n, 1, r2, Rt, n, tau2, y, n);
          for (i = 0; i < n; ++i) v[jpvt[i]] = y[i];
        }
      }
      *k_out = k;
      if (rank_out) *rank_out = rnz;
    }
    phgmg__free(alloc, W2);
  }
  phgmg__free(alloc, W);
  phgmg__free(alloc, jpvt);
  return rc;
}

/* ---- symmetric eigenproblem: cyclic Jacobi ------------------------------------ */
PHGMG_DEF phgmg_result phgmg_sym_eig(int n, double *A, int lda, double *w, double *V, int ldv) {
  int i, j, p, q, sweep, rotated;
  double anorm;
  if (n < 0 || lda < PHGMG__MAX(n, 1) || (V && ldv < PHGMG__MAX(n, 1))) return PHGMG_ERR_SIZE;
  if (n == 0) return PHGMG_OK;
  if (!A || !w) return PHGMG_ERR_INVALID_ARG;
  if (!phgmg__mat_finite(n, n, A, lda)) return PHGMG_ERR_NANINF;
  /* symmetrize: A := (A + A^T)/2 */
  for (j = 0; j < n; ++j)
    for (i = j + 1; i < n; ++i) {
      double *aij = A + i + (size_t)j * (size_t)lda, *aji = A + j + (size_t)i * (size_t)lda;
      double s = 0.5 * (*aij + *aji);
      *aij = *aji = s;
    }
  if (V)
    for (j = 0; j < n; ++j)
      for (i = 0; i < n; ++i) V[i + (size_t)j * (size_t)ldv] = i == j ? 1.0 : 0.0;
  anorm = phgmg_normf(n, n, A, lda);
  for (sweep = 0; sweep < 100; ++sweep) {
    rotated = 0;
    for (p = 0; p < n - 1; ++p) {
      double *ap = A + (size_t)p * (size_t)lda;
      for (q = p + 1; q < n; ++q) {
        double *aq = A + (size_t)q * (size_t)lda;
        double apq = aq[p], app = ap[p], aqq = aq[q], theta, t, c, s;
        if (fabs(apq) <= PHGMG__EPS * sqrt(fabs(app)) * sqrt(fabs(aqq)) ||
            fabs(apq) <= PHGMG__EPS * PHGMG__EPS * anorm)
          continue;
        rotated = 1;
        theta = (aqq - app) / (2.0 * apq);
        t = (theta >= 0.0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(1.0 + theta * theta));
        c = 1.0 / sqrt(1.0 + t * t);
        s = c * t;
        for (i = 0; i < n; ++i) {
          double a = ap[i], b = aq[i];
          ap[i] = c * a - s * b;
          aq[i] = s * a + c * b;
        }
        ap[p] = app - t * apq;
        aq[q] = aqq + t * apq;
        ap[q] = aq[p] = 0.0;
        for (i = 0; i < n; ++i) { /* mirror the two columns into rows p, q */
          if (i == p || i == q) continue;
          A[p + (size_t)i * (size_t)lda] = ap[i];
          A[q + (size_t)i * (size_t)lda] = aq[i];
        }
        if (V) {
          double *vp = V + (size_t)p * (size_t)ldv, *vq = V + (size_t)q * (size_t)ldv;
          for (i = 0; i < n; ++i) {
            double a = vp[i], b = vq[i];
            vp[i] = c * a - s * b;
            vq[i] = s * a + c * b;
          }
        }
      }
    }
    if (!rotated) break;
  }
  if (rotated) return PHGMG_ERR_NOT_CONVERGED;
  for (i = 0; i < n; ++i) w[i] = A[i + (size_t)i * (size_t)lda];
  /* selection sort ascending, swapping eigenvector columns */
  for (i = 0; i < n - 1; ++i) {
    int kmin = i;
    for (j = i + 1; j < n; ++j)
      if (w[j] < w[kmin]) kmin = j;
    if (kmin != i) {
      double t = w[i];
      w[i] = w[kmin]; w[kmin] = t;
      if (V) {
        double *vi = V + (size_t)i * (size_t)ldv, *vk = V + (size_t)kmin * (size_t)ldv;
        for (j = 0; j < n; ++j) { t = vi[j]; vi[j] = vk[j]; vk[j] = t; }
      }
    }
  }
  return PHGMG_OK;
}

#endif /* PHGMG_NO_OFFLINE */

/* >>online (implementation) ============================================== */
/* Everything here is in phgmg_real, allocation-free and N-independent. */
#if PHGMG_REAL_IS_FLOAT
#define PHGMG__RABS(x) fabsf(x)
#define PHGMG__RSQRT(x) sqrtf(x)
#define PHGMG__REPS 1.1920929e-07f
#else
#define PHGMG__RABS(x) fabs(x)
#define PHGMG__RSQRT(x) sqrt(x)
#define PHGMG__REPS 2.220446049250313e-16
#endif
#define PHGMG__R(x) ((phgmg_real)(x))
#define PHGMG__ONLINE static PHGMG__UNUSED

PHGMG__ONLINE int phgmg__r_finite(const phgmg_real *a, int n) {
  phgmg_real acc = PHGMG__R(0);
  int i;
  for (i = 0; i < n; ++i) acc += a[i] * PHGMG__R(0);
  return acc == PHGMG__R(0);
}

/* y = A x (A: rows x cols, column-major, ld = rows); beta = 0 or 1 (accumulate). */
PHGMG__ONLINE void phgmg__r_gemv(int rows, int cols, const phgmg_real *A, const phgmg_real *x,
                                 int accumulate, phgmg_real *y) {
  int i, j;
  if (!accumulate) for (i = 0; i < rows; ++i) y[i] = PHGMG__R(0);
  for (j = 0; j < cols; ++j) {
    const phgmg_real xj = x[j];
    const phgmg_real *a = A + (size_t)j * (size_t)rows;
    if (xj == PHGMG__R(0)) continue;
    for (i = 0; i < rows; ++i) y[i] += a[i] * xj;
  }
}
/* y (+)= A^T x (A: rows x cols). */
PHGMG__ONLINE void phgmg__r_gemvt(int rows, int cols, const phgmg_real *A, const phgmg_real *x,
                                  int accumulate, phgmg_real *y) {
  int i, j;
  for (j = 0; j < cols; ++j) {
    const phgmg_real *a = A + (size_t)j * (size_t)rows;
    phgmg_real s = PHGMG__R(0);
    for (i = 0; i < rows; ++i) s += a[i] * x[i];
    y[j] = accumulate ? y[j] + s : s;
  }
}

/* LU with partial pivoting of an n x n matrix (ld n). 0 ok, -1 singular/non-finite. */
PHGMG__ONLINE int phgmg__r_lu(int n, phgmg_real *A, int *piv) {
  int i, j, k;
  for (k = 0; k < n; ++k) {
    int p = k;
    phgmg_real amax = PHGMG__RABS(A[k + k * n]);
    for (i = k + 1; i < n; ++i) {
      phgmg_real v = PHGMG__RABS(A[i + k * n]);
      if (v > amax) { amax = v; p = i; }
    }
    piv[k] = p;
    if (!(amax > PHGMG__R(0)) || amax - amax != PHGMG__R(0)) return -1;
    if (p != k)
      for (j = 0; j < n; ++j) { phgmg_real t = A[k + j * n]; A[k + j * n] = A[p + j * n]; A[p + j * n] = t; }
    {
      const phgmg_real inv = PHGMG__R(1) / A[k + k * n];
      for (i = k + 1; i < n; ++i) A[i + k * n] *= inv;
    }
    for (j = k + 1; j < n; ++j) {
      const phgmg_real akj = A[k + j * n];
      if (akj == PHGMG__R(0)) continue;
      for (i = k + 1; i < n; ++i) A[i + j * n] -= A[i + k * n] * akj;
    }
  }
  return 0;
}
PHGMG__ONLINE void phgmg__r_lu_solve(int n, const phgmg_real *LU, const int *piv, phgmg_real *b) {
  int i, j;
  for (i = 0; i < n; ++i)
    if (piv[i] != i) { phgmg_real t = b[i]; b[i] = b[piv[i]]; b[piv[i]] = t; }
  for (j = 0; j < n; ++j) {
    const phgmg_real bj = b[j];
    if (bj != PHGMG__R(0)) for (i = j + 1; i < n; ++i) b[i] -= LU[i + j * n] * bj;
  }
  for (j = n - 1; j >= 0; --j) {
    b[j] /= LU[j + j * n];
    if (b[j] != PHGMG__R(0)) for (i = 0; i < j; ++i) b[i] -= LU[i + j * n] * b[j];
  }
}

/* Polynomial phi(s) = sum_k c_k s^k and its first two derivatives. */
PHGMG__ONLINE void phgmg__r_poly(const phgmg_real *c, int deg, phgmg_real s, phgmg_real *v,
                                 phgmg_real *d1, phgmg_real *d2) {
  phgmg_real p0 = PHGMG__R(0), p1 = PHGMG__R(0), p2 = PHGMG__R(0);
  int k;
  for (k = deg; k >= 0; --k) {
    p2 = p2 * s + PHGMG__R(2) * p1;
    p1 = p1 * s + p0;
    p0 = p0 * s + c[k];
  }
  if (v) *v = p0;
  if (d1) *d1 = p1;
  if (d2) *d2 = p2;
}

PHGMG_DEF phgmg_result phgmg_rom_check(const phgmg_rom *rom) {
  if (!rom) return PHGMG_ERR_INVALID_ARG;
  if (rom->r < 1 || rom->m < 0 || rom->m > rom->r || rom->nd < 0 || rom->rn < 0)
    return PHGMG_ERR_SIZE;
  if (rom->r > 4096 || rom->nd > (1 << 24) || rom->rn > 4096) return PHGMG_ERR_SIZE;
  if (!rom->Qh || (rom->m > 0 && !rom->Bh)) return PHGMG_ERR_INVALID_ARG;
  if (rom->kind == PHGMG_ROM_LINEAR) {
    if (!rom->K || rom->rn != 0) return PHGMG_ERR_INVALID_ARG;
  } else if (rom->kind == PHGMG_ROM_QUADRATIC) {
    if (rom->rn < 1 || rom->r - rom->m < 1) return PHGMG_ERR_SIZE;
    if (!rom->G00 || !rom->G01 || !rom->G10 || !rom->G11 || !rom->Q01 || !rom->Q11 || !rom->Ms)
      return PHGMG_ERR_INVALID_ARG;
    if (rom->nd > 0 && !rom->P1) return PHGMG_ERR_INVALID_ARG;
  } else {
    return PHGMG_ERR_INVALID_ARG;
  }
  if (rom->nd > 0 && (!rom->P0 || !rom->w || !rom->poly || rom->poly_deg < 0 || rom->poly_deg > 32))
    return PHGMG_ERR_INVALID_ARG;
  if (rom->Phi && (!rom->Gam || !rom->SX || !rom->SU || !(rom->dt > PHGMG__R(0))))
    return PHGMG_ERR_INVALID_ARG;
  return PHGMG_OK;
}

/* Evaluation work: one layout function used by the size query and by every
   evaluator, so size and carving cannot drift. */
typedef struct phgmg__romw {
  phgmg_real *Lp, *q, *a1, *c, *d, *E, *t, *tmp, *xp, *fm, *g;
} phgmg__romw;

PHGMG__ONLINE size_t phgmg__romw_layout(const phgmg_rom *rom, phgmg_real *base, phgmg__romw *w) {
  const size_t r = (size_t)rom->r, rn = (size_t)rom->rn, nd = (size_t)rom->nd;
  size_t o = 0;
  phgmg__romw dummy;
  if (!w) w = &dummy;
  w->Lp = base + o; o += rn * r;
  w->q = base + o; o += rn;
  w->a1 = base + o; o += rn;
  w->c = base + o; o += nd;
  w->d = base + o; o += nd;
  w->E = base + o; o += r * r;
  w->t = base + o; o += rn * r;
  w->tmp = base + o; o += r;
  w->xp = base + o; o += r;
  w->fm = base + o; o += r;
  w->g = base + o; o += r;
  return o;
}

PHGMG_DEF size_t phgmg_rom_eval_work_size(const phgmg_rom *rom) {
  return phgmg__romw_layout(rom, NULL, NULL);
}

/* q = M (x2 kron x2) via Lp (QUADRATIC), and the kept coordinates c. */
PHGMG__ONLINE void phgmg__rom_prep(const phgmg_rom *rom, const phgmg_real *x, const phgmg__romw *w) {
  const int r = rom->r, m = rom->m, rn = rom->rn, nd = rom->nd, p = r - m;
  int i, j, k;
  if (rom->kind == PHGMG_ROM_QUADRATIC) {
    const phgmg_real *x2 = x + m;
    for (k = 0; k < p; ++k) { /* Lp(:,k) = sum_j Ms(:, k*p + j) x2_j */
      phgmg_real *l = w->Lp + (size_t)k * rn;
      for (i = 0; i < rn; ++i) l[i] = PHGMG__R(0);
      for (j = 0; j < p; ++j) {
        const phgmg_real *ms = rom->Ms + ((size_t)k * p + j) * rn;
        const phgmg_real xj = x2[j];
        for (i = 0; i < rn; ++i) l[i] += ms[i] * xj;
      }
    }
    phgmg__r_gemv(rn, p, w->Lp, x2, 0, w->q);
    for (i = 0; i < rn; ++i) w->q[i] *= PHGMG__R(0.5);
  }
  if (nd > 0) {
    phgmg__r_gemv(nd, r, rom->P0, x, 0, w->c);
    if (rom->kind == PHGMG_ROM_QUADRATIC) phgmg__r_gemv(nd, rn, rom->P1, w->q, 1, w->c);
  }
}

PHGMG_DEF phgmg_real phgmg_rom_hamiltonian(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *work) {
  phgmg__romw w;
  phgmg_real h = PHGMG__R(0);
  const int r = rom->r, rn = rom->rn;
  int j;
  phgmg__romw_layout(rom, work, &w);
  phgmg__rom_prep(rom, x, &w);
  phgmg__r_gemv(r, r, rom->Qh, x, 0, w.tmp);
  if (rom->kind == PHGMG_ROM_QUADRATIC) {
    phgmg__r_gemv(r, rn, rom->Q01, w.q, 1, w.tmp);
    phgmg__r_gemv(r, rn, rom->Q01, w.q, 1, w.tmp); /* 2 x^T Q01 q */
    phgmg__r_gemv(rn, rn, rom->Q11, w.q, 0, w.a1);
    for (j = 0; j < rn; ++j) h += w.q[j] * w.a1[j];
  }
  for (j = 0; j < r; ++j) h += x[j] * w.tmp[j];
  h *= PHGMG__R(0.5);
  for (j = 0; j < rom->nd; ++j) {
    phgmg_real v;
    phgmg__r_poly(rom->poly, rom->poly_deg, w.c[j], &v, NULL, NULL);
    h += rom->w[j] * v;
  }
  return h;
}

/* grad H into g (g must not alias the work areas other than w->g). */
PHGMG__ONLINE void phgmg__rom_grad(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *g,
                                   const phgmg__romw *w) {
  const int r = rom->r, m = rom->m, rn = rom->rn, nd = rom->nd, p = r - m;
  int j;
  phgmg__rom_prep(rom, x, w);
  for (j = 0; j < nd; ++j) {
    phgmg_real d1;
    phgmg__r_poly(rom->poly, rom->poly_deg, w->c[j], NULL, &d1, NULL);
    w->d[j] = rom->w[j] * d1;
  }
  phgmg__r_gemv(r, r, rom->Qh, x, 0, g);
  if (nd > 0) phgmg__r_gemvt(nd, r, rom->P0, w->d, 1, g);
  if (rom->kind == PHGMG_ROM_QUADRATIC) {
    phgmg__r_gemv(r, rn, rom->Q01, w->q, 1, g);
    phgmg__r_gemvt(r, rn, rom->Q01, x, 0, w->a1); /* a1 = Q01^T x + Q11 q + P1^T d */
    phgmg__r_gemv(rn, rn, rom->Q11, w->q, 1, w->a1);
    if (nd > 0) phgmg__r_gemvt(nd, rn, rom->P1, w->d, 1, w->a1);
    phgmg__r_gemvt(rn, p, w->Lp, w->a1, 1, g + m); /* g2 += Lp^T a1 */
  }
}

PHGMG_DEF void phgmg_rom_gradient(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *g, phgmg_real *work) {
  phgmg__romw w;
  phgmg__romw_layout(rom, work, &w);
  phgmg__rom_grad(rom, x, g, &w);
}

PHGMG_DEF void phgmg_rom_output(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *y, phgmg_real *work) {
  phgmg__romw w;
  phgmg__romw_layout(rom, work, &w);
  phgmg__rom_grad(rom, x, w.g, &w);
  phgmg__r_gemvt(rom->r, rom->m, rom->Bh, w.g, 0, y);
}

/* E = D^T G D = G00 + G01 L + L^T (G10 + G11 L), L = [0, Lp] (QUADRATIC; Lp current). */
PHGMG__ONLINE void phgmg__rom_dgd(const phgmg_rom *rom, const phgmg__romw *w) {
  const int r = rom->r, m = rom->m, rn = rom->rn;
  phgmg_real *E = w->E, *t = w->t;
  int a, b, i;
  for (b = 0; b < r; ++b) {
    phgmg_real *tb = t + (size_t)b * rn;
    for (i = 0; i < rn; ++i) tb[i] = rom->G10[i + (size_t)b * rn];
    if (b >= m) phgmg__r_gemv(rn, rn, rom->G11, w->Lp + (size_t)(b - m) * rn, 1, tb);
  }
  for (b = 0; b < r * r; ++b) E[b] = rom->G00[b];
  for (b = m; b < r; ++b) phgmg__r_gemv(r, rn, rom->G01, w->Lp + (size_t)(b - m) * rn, 1, E + (size_t)b * r);
  for (b = 0; b < r; ++b)
    for (a = m; a < r; ++a) {
      const phgmg_real *la = w->Lp + (size_t)(a - m) * rn, *tb = t + (size_t)b * rn;
      phgmg_real s = PHGMG__R(0);
      for (i = 0; i < rn; ++i) s += la[i] * tb[i];
      E[a + (size_t)b * r] += s;
    }
}

/* Solve E z = b in place (E destroyed) by Gaussian elimination with partial
   pivoting, without pivot storage. 0 ok, -1 singular. */
PHGMG__ONLINE int phgmg__r_gesv1(int n, phgmg_real *E, phgmg_real *b) {
  int i, j, k;
  for (k = 0; k < n; ++k) {
    int pv = k;
    phgmg_real amax = PHGMG__RABS(E[k + k * n]);
    for (i = k + 1; i < n; ++i)
      if (PHGMG__RABS(E[i + k * n]) > amax) { amax = PHGMG__RABS(E[i + k * n]); pv = i; }
    if (!(amax > PHGMG__R(0)) || amax - amax != PHGMG__R(0)) return -1;
    if (pv != k) {
      phgmg_real tt;
      for (j = k; j < n; ++j) { tt = E[k + j * n]; E[k + j * n] = E[pv + j * n]; E[pv + j * n] = tt; }
      tt = b[k]; b[k] = b[pv]; b[pv] = tt;
    }
    for (i = k + 1; i < n; ++i) {
      const phgmg_real l = E[i + k * n] / E[k + k * n];
      if (l == PHGMG__R(0)) continue;
      for (j = k + 1; j < n; ++j) E[i + j * n] -= l * E[k + j * n];
      b[i] -= l * b[k];
    }
  }
  for (k = n - 1; k >= 0; --k) {
    phgmg_real s = b[k];
    for (j = k + 1; j < n; ++j) s -= E[k + j * n] * b[j];
    b[k] = s / E[k + k * n];
  }
  return 0;
}

/* f = K(x) grad H(x) + Bh u; grad H left in w->g. f must not alias work. */
PHGMG__ONLINE phgmg_result phgmg__rom_rhs(const phgmg_rom *rom, const phgmg_real *x, const phgmg_real *u,
                                          phgmg_real *f, const phgmg__romw *w) {
  const int r = rom->r;
  phgmg__rom_grad(rom, x, w->g, w);
  if (rom->kind == PHGMG_ROM_LINEAR) {
    phgmg__r_gemv(r, r, rom->K, w->g, 0, f);
  } else {
    int i;
    phgmg__rom_dgd(rom, w);
    for (i = 0; i < r; ++i) f[i] = w->g[i];
    if (phgmg__r_gesv1(r, w->E, f) != 0) return PHGMG_ERR_SINGULAR;
  }
  if (u && rom->m > 0) phgmg__r_gemv(r, rom->m, rom->Bh, u, 1, f);
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_rom_rhs(const phgmg_rom *rom, const phgmg_real *x, const phgmg_real *u,
                                     phgmg_real *f, phgmg_real *work) {
  phgmg__romw w;
  phgmg__romw_layout(rom, work, &w);
  return phgmg__rom_rhs(rom, x, u, f, &w);
}

PHGMG_DEF phgmg_result phgmg_rom_structure(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *Jr,
                                           phgmg_real *Rr, phgmg_real *work) {
  const int r = rom->r;
  int a, b;
  phgmg__romw w;
  phgmg__romw_layout(rom, work, &w);
  if (rom->kind == PHGMG_ROM_LINEAR) {
    for (b = 0; b < r * r; ++b) Jr[b] = rom->K[b];
  } else { /* K = E^{-1}, column by column */
    phgmg__rom_prep(rom, x, &w);
    for (b = 0; b < r; ++b) {
      phgmg__rom_dgd(rom, &w);
      for (a = 0; a < r; ++a) Jr[a + (size_t)b * r] = (a == b) ? PHGMG__R(1) : PHGMG__R(0);
      if (phgmg__r_gesv1(r, w.E, Jr + (size_t)b * r) != 0) return PHGMG_ERR_SINGULAR;
    }
  }
  for (b = 0; b < r; ++b)
    for (a = 0; a <= b; ++a) {
      const phgmg_real kab = Jr[a + (size_t)b * r], kba = Jr[b + (size_t)a * r];
      Rr[a + (size_t)b * r] = Rr[b + (size_t)a * r] = -PHGMG__R(0.5) * (kab + kba);
      Jr[a + (size_t)b * r] = PHGMG__R(0.5) * (kab - kba);
      Jr[b + (size_t)a * r] = -Jr[a + (size_t)b * r];
    }
  return PHGMG_OK;
}

/* Newton Jacobian df/dx. */
PHGMG__ONLINE phgmg_result phgmg__rom_jac(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *Jf,
                                          const phgmg__romw *w) {
  const int r = rom->r;
  int a, b, j;
  if (rom->kind == PHGMG_ROM_LINEAR) {
    /* Jf = K (Qh + P0^T diag(w phi''(c)) P0) */
    phgmg_real *Hs = w->E;
    phgmg__rom_prep(rom, x, w);
    for (j = 0; j < rom->nd; ++j) {
      phgmg_real d2;
      phgmg__r_poly(rom->poly, rom->poly_deg, w->c[j], NULL, NULL, &d2);
      w->d[j] = rom->w[j] * d2;
    }
    for (b = 0; b < r; ++b)
      for (a = 0; a < r; ++a) {
        phgmg_real s = rom->Qh[a + (size_t)b * r];
        for (j = 0; j < rom->nd; ++j)
          s += rom->P0[j + (size_t)a * rom->nd] * w->d[j] * rom->P0[j + (size_t)b * rom->nd];
        Hs[a + (size_t)b * r] = s;
      }
    for (b = 0; b < r; ++b) phgmg__r_gemv(r, r, rom->K, Hs + (size_t)b * r, 0, Jf + (size_t)b * r);
  } else {
    /* central differences of the right-hand side (u = 0; f is affine in u) */
#if PHGMG_REAL_IS_FLOAT
    const phgmg_real hrel = PHGMG__R(4.9e-3);
#else
    const phgmg_real hrel = PHGMG__R(6.06e-6);
#endif
    for (b = 0; b < r; ++b) {
      const phgmg_real hb = hrel * (PHGMG__R(1) + PHGMG__RABS(x[b]));
      phgmg_real *col = Jf + (size_t)b * r;
      phgmg_result rc;
      for (a = 0; a < r; ++a) w->xp[a] = x[a];
      w->xp[b] = x[b] + hb;
      rc = phgmg__rom_rhs(rom, w->xp, NULL, col, w);
      if (rc != PHGMG_OK) return rc;
      w->xp[b] = x[b] - hb;
      rc = phgmg__rom_rhs(rom, w->xp, NULL, w->fm, w);
      if (rc != PHGMG_OK) return rc;
      for (a = 0; a < r; ++a) col[a] = (col[a] - w->fm[a]) / (PHGMG__R(2) * hb);
    }
  }
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_rom_jacobian(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *Jf,
                                          phgmg_real *work) {
  phgmg__romw w;
  phgmg__romw_layout(rom, work, &w);
  return phgmg__rom_jac(rom, x, Jf, &w);
}

/* --- online GL3 stepper ------------------------------------------------- */
typedef struct phgmg__romstep_mem {
  phgmg_real *A, *b, *c, *lag; /* GL3 tableau (row-major A), extrapolation weights 3x4 */
  phgmg_real *LU, *Jf, *Z, *F, *Res, *dZ, *Zp, *G, *Y, *work;
  int *piv;
} phgmg__romstep_mem;

PHGMG__ONLINE size_t phgmg__romstep_layout(const phgmg_rom *rom, void *mem, phgmg__romstep_mem *L) {
  const size_t r = (size_t)rom->r, n3 = 3 * r;
  phgmg_real *base = PHGMG__CAST(phgmg_real *, mem);
  size_t o = 0, reals;
  phgmg__romstep_mem dummy;
  if (!L) L = &dummy;
  L->A = base + o; o += 9;
  L->b = base + o; o += 3;
  L->c = base + o; o += 3;
  L->lag = base + o; o += 12;
  L->LU = base + o; o += n3 * n3;
  L->Jf = base + o; o += r * r;
  L->Z = base + o; o += n3;
  L->F = base + o; o += n3;
  L->Res = base + o; o += n3;
  L->dZ = base + o; o += n3;
  L->Zp = base + o; o += n3;
  L->G = base + o; o += n3;
  L->Y = base + o; o += r;
  L->work = base + o; o += phgmg_rom_eval_work_size(rom);
  reals = o;
  L->piv = mem ? PHGMG__CAST(int *, PHGMG__CAST(void *, base + reals)) : NULL;
  return reals * sizeof(phgmg_real) + n3 * sizeof(int);
}

PHGMG_DEF size_t phgmg_rom_stepper_memsize(const phgmg_rom *rom) {
  if (phgmg_rom_check(rom) != PHGMG_OK) return 0;
  return phgmg__romstep_layout(rom, NULL, NULL);
}

PHGMG_DEF void phgmg_rom_stage_times(phgmg_real t, phgmg_real dt, phgmg_real tc[3]) {
  const double s = sqrt(15.0) / 10.0;
  tc[0] = t + dt * PHGMG__R(0.5 - s);
  tc[1] = t + dt * PHGMG__R(0.5);
  tc[2] = t + dt * PHGMG__R(0.5 + s);
}

PHGMG_DEF phgmg_result phgmg_rom_stepper_init(phgmg_rom_stepper *s, const phgmg_rom *rom, phgmg_real dt,
                                              phgmg_real tol, int max_iter, void *mem, size_t mem_size) {
  phgmg__romstep_mem L;
  phgmg_result rc;
  double A[9], c[3], b[3], s15 = sqrt(15.0);
  int i, j, k;
  if (!s || !mem) return PHGMG_ERR_INVALID_ARG;
  rc = phgmg_rom_check(rom);
  if (rc != PHGMG_OK) return rc;
  if (!(dt > PHGMG__R(0)) || dt - dt != PHGMG__R(0)) return PHGMG_ERR_INVALID_ARG;
  if (((size_t)mem) % sizeof(double) != 0) return PHGMG_ERR_INVALID_ARG;
  if (mem_size < phgmg__romstep_layout(rom, NULL, NULL)) return PHGMG_ERR_WORKSPACE;
  phgmg__romstep_layout(rom, mem, &L);
  /* Gauss-Legendre 3 from the closed forms */
  c[0] = 0.5 - s15 / 10.0; c[1] = 0.5; c[2] = 0.5 + s15 / 10.0;
  b[0] = 5.0 / 18.0; b[1] = 4.0 / 9.0; b[2] = 5.0 / 18.0;
  A[0] = 5.0 / 36.0;             A[1] = 2.0 / 9.0 - s15 / 15.0; A[2] = 5.0 / 36.0 - s15 / 30.0;
  A[3] = 5.0 / 36.0 + s15 / 24.0; A[4] = 2.0 / 9.0;            A[5] = 5.0 / 36.0 - s15 / 24.0;
  A[6] = 5.0 / 36.0 + s15 / 30.0; A[7] = 2.0 / 9.0 + s15 / 15.0; A[8] = 5.0 / 36.0;
  for (i = 0; i < 9; ++i) L.A[i] = PHGMG__R(A[i]);
  for (i = 0; i < 3; ++i) { L.b[i] = PHGMG__R(b[i]); L.c[i] = PHGMG__R(c[i]); }
  /* Lagrange weights of the collocation polynomial (nodes 0, c1, c2, c3)
     evaluated at 1 + c_k: lag[k*4 + j] */
  for (k = 0; k < 3; ++k) {
    const double nodes[4] = {0.0, c[0], c[1], c[2]};
    const double tt = 1.0 + c[k];
    for (j = 0; j < 4; ++j) {
      double l = 1.0;
      for (i = 0; i < 4; ++i)
        if (i != j) l *= (tt - nodes[i]) / (nodes[j] - nodes[i]);
      L.lag[k * 4 + j] = PHGMG__R(l);
    }
  }
  s->rom = rom;
  s->dt = dt;
#if PHGMG_REAL_IS_FLOAT
  s->tol = tol > PHGMG__R(0) ? tol : PHGMG__R(1e-5);
#else
  s->tol = tol > PHGMG__R(0) ? tol : PHGMG__R(1e-10);
#endif
  s->max_iter = max_iter > 0 ? max_iter : 10;
  s->use_map = (rom->Phi != NULL && rom->kind == PHGMG_ROM_LINEAR && rom->nd == 0 &&
                PHGMG__RABS(rom->dt - dt) <= PHGMG__R(8) * PHGMG__REPS * dt);
  s->have_lu = 0;
  s->have_prev = 0;
  s->ws = PHGMG__CAST(phgmg_real *, mem);
  s->ws_count = mem_size / sizeof(phgmg_real);
  memset(&s->stats, 0, sizeof s->stats);
  return PHGMG_OK;
}

PHGMG_DEF void phgmg_rom_stepper_reset(phgmg_rom_stepper *s) { s->have_prev = 0; }

/* Stage residual Res = Z - h (A kron I) F(x + Z); returns inf-norm, or -1 on
   failure (non-finite or singular). Stage gradients into G. */
PHGMG__ONLINE phgmg_real phgmg__romstep_residual(phgmg_rom_stepper *s, const phgmg__romstep_mem *L,
                                                 const phgmg_real *x, const phgmg_real *u3,
                                                 phgmg_result *err) {
  const phgmg_rom *rom = s->rom;
  const int r = rom->r, m = rom->m;
  phgmg__romw w;
  phgmg_real nrm = PHGMG__R(0);
  int i, j, a;
  phgmg__romw_layout(rom, L->work, &w);
  for (i = 0; i < 3; ++i) {
    phgmg_result rc;
    for (a = 0; a < r; ++a) L->Y[a] = x[a] + L->Z[i * r + a];
    rc = phgmg__rom_rhs(rom, L->Y, u3 ? u3 + i * m : NULL, L->F + i * r, &w);
    if (rc != PHGMG_OK) { *err = rc; return PHGMG__R(-1); }
    for (a = 0; a < r; ++a) L->G[i * r + a] = w.g[a];
  }
  for (i = 0; i < 3; ++i)
    for (a = 0; a < r; ++a) {
      phgmg_real v = L->Z[i * r + a];
      for (j = 0; j < 3; ++j) v -= s->dt * L->A[i * 3 + j] * L->F[j * r + a];
      L->Res[i * r + a] = v;
      if (PHGMG__RABS(v) > nrm) nrm = PHGMG__RABS(v);
    }
  if (!phgmg__r_finite(L->Res, 3 * r) || !phgmg__r_finite(L->G, 3 * r)) { *err = PHGMG_ERR_NANINF; return PHGMG__R(-1); }
  return nrm;
}

/* Factor I - h (A kron Jf(x)). */
PHGMG__ONLINE phgmg_result phgmg__romstep_factor(phgmg_rom_stepper *s, const phgmg__romstep_mem *L,
                                                 const phgmg_real *x) {
  const phgmg_rom *rom = s->rom;
  const int r = rom->r, n3 = 3 * r;
  phgmg__romw w;
  phgmg_result rc;
  int i, j, a, b;
  phgmg__romw_layout(rom, L->work, &w);
  rc = phgmg__rom_jac(rom, x, L->Jf, &w);
  if (rc != PHGMG_OK) return rc;
  if (!phgmg__r_finite(L->Jf, r * r)) return PHGMG_ERR_NANINF;
  for (j = 0; j < 3; ++j)
    for (b = 0; b < r; ++b)
      for (i = 0; i < 3; ++i)
        for (a = 0; a < r; ++a)
          L->LU[(i * r + a) + (size_t)(j * r + b) * n3] =
              ((i == j && a == b) ? PHGMG__R(1) : PHGMG__R(0)) - s->dt * L->A[i * 3 + j] * L->Jf[a + (size_t)b * r];
  s->stats.factorizations++;
  if (phgmg__r_lu(n3, L->LU, L->piv) != 0) { s->have_lu = 0; return PHGMG_ERR_SINGULAR; }
  s->have_lu = 1;
  return PHGMG_OK;
}

PHGMG__ONLINE phgmg_result phgmg__romstep_map(phgmg_rom_stepper *s, const phgmg__romstep_mem *L, phgmg_real *x,
                                              const phgmg_real *u3, phgmg_real *y, phgmg_real energy[2]) {
  const phgmg_rom *rom = s->rom;
  const int r = rom->r, m = rom->m, n3 = 3 * r;
  phgmg_real *xn = L->dZ;
  int i, a;
  phgmg__r_gemv(r, r, rom->Phi, x, 0, xn);
  if (u3 && m > 0) phgmg__r_gemv(r, 3 * m, rom->Gam, u3, 1, xn);
  if (!phgmg__r_finite(xn, r)) return PHGMG_ERR_NANINF;
  if (energy) {
    phgmg_real sup = PHGMG__R(0), dis = PHGMG__R(0);
    phgmg__r_gemv(n3, r, rom->SX, x, 0, L->Z);             /* stage values */
    if (u3 && m > 0) phgmg__r_gemv(n3, 3 * m, rom->SU, u3, 1, L->Z);
    for (i = 0; i < 3; ++i) {
      phgmg_real *gi = L->G + i * r, *ki = L->F + i * r, si = PHGMG__R(0), di = PHGMG__R(0);
      phgmg__r_gemv(r, r, rom->Qh, L->Z + i * r, 0, gi);
      phgmg__r_gemv(r, r, rom->K, gi, 0, ki);
      for (a = 0; a < r; ++a) di -= gi[a] * ki[a];
      if (u3 && m > 0) {
        phgmg__r_gemvt(r, m, rom->Bh, gi, 0, L->Y);
        for (a = 0; a < m; ++a) si += L->Y[a] * u3[i * m + a];
      }
      sup += L->b[i] * si;
      dis += L->b[i] * di;
    }
    energy[0] += s->dt * sup;
    energy[1] += s->dt * dis;
  }
  for (a = 0; a < r; ++a) x[a] = xn[a];
  if (y) {
    phgmg__r_gemv(r, r, rom->Qh, x, 0, L->Y);
    phgmg__r_gemvt(r, m, rom->Bh, L->Y, 0, y);
  }
  (void)n3;
  s->stats.steps++;
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_rom_step(phgmg_rom_stepper *s, phgmg_real *x, const phgmg_real *u3,
                                      phgmg_real *y, phgmg_real energy[2]) {
  const phgmg_rom *rom;
  phgmg__romstep_mem L;
  int r, m, n3, attempt, i, a;
  phgmg_result err = PHGMG_OK;
  if (!s || !x || !s->rom) return PHGMG_ERR_INVALID_ARG;
  rom = s->rom;
  r = rom->r; m = rom->m; n3 = 3 * r;
  if (!phgmg__r_finite(x, r) || (u3 && !phgmg__r_finite(u3, 3 * m))) return PHGMG_ERR_NANINF;
  phgmg__romstep_layout(rom, s->ws, &L);
  if (s->use_map) return phgmg__romstep_map(s, &L, x, u3, y, energy);

  for (attempt = 0; attempt < 2; ++attempt) {
    phgmg_real res, res_prev = PHGMG__R(0), theta_max = PHGMG__R(0);
    int it = 0, fresh = 0, ok = 0;
    if (!s->have_lu || attempt > 0) {
      err = phgmg__romstep_factor(s, &L, x);
      if (err != PHGMG_OK) break;
      fresh = 1;
    }
    /* starting guess: extrapolated collocation polynomial, or zero */
    for (i = 0; i < n3; ++i) L.Z[i] = (s->have_prev && attempt == 0) ? L.Zp[i] : PHGMG__R(0);
    res = phgmg__romstep_residual(s, &L, x, u3, &err);
    if (res < PHGMG__R(0)) {
      if (err == PHGMG_ERR_NANINF && !fresh) continue; /* bad guess/factors: retry fresh */
      break;
    }
    while (res > s->tol && it < s->max_iter) {
      for (i = 0; i < n3; ++i) L.dZ[i] = -L.Res[i];
      phgmg__r_lu_solve(n3, L.LU, L.piv, L.dZ);
      for (i = 0; i < n3; ++i) L.Z[i] += L.dZ[i];
      ++it;
      s->stats.newton_iters++;
      res_prev = res;
      res = phgmg__romstep_residual(s, &L, x, u3, &err);
      if (res < PHGMG__R(0)) break;
      if (res_prev > PHGMG__R(0) && res / res_prev > theta_max) theta_max = res / res_prev;
    }
    if (res >= PHGMG__R(0) && res <= s->tol) ok = 1;
    if (!ok) {
      if (res >= PHGMG__R(0)) err = PHGMG_ERR_NOT_CONVERGED;
      s->have_lu = 0;
      if (fresh) break;   /* fresh factors did not help: give up */
      continue;           /* stale factors: retry once with fresh ones */
    }
    /* converged: energy, new state, extrapolation data */
    {
      phgmg_real *xn = L.dZ;
      for (a = 0; a < r; ++a) {
        phgmg_real v = x[a];
        for (i = 0; i < 3; ++i) v += s->dt * L.b[i] * L.F[i * r + a];
        xn[a] = v;
      }
      if (!phgmg__r_finite(xn, r)) { err = PHGMG_ERR_NANINF; break; }
      if (energy) {
        phgmg_real sup = PHGMG__R(0), dis = PHGMG__R(0);
        for (i = 0; i < 3; ++i) {
          const phgmg_real *gi = L.G + i * r, *fi = L.F + i * r;
          phgmg_real si = PHGMG__R(0), di = PHGMG__R(0);
          /* dissipation rate gradH^T R gradH = -gradH^T K gradH = -g^T (f - Bh u) */
          for (a = 0; a < r; ++a) di -= gi[a] * fi[a];
          if (u3 && m > 0) {
            phgmg__r_gemvt(r, m, rom->Bh, gi, 0, L.Y);
            for (a = 0; a < m; ++a) { si += L.Y[a] * u3[i * m + a]; di += L.Y[a] * u3[i * m + a]; }
          }
          sup += L.b[i] * si;
          dis += L.b[i] * di;
        }
        energy[0] += s->dt * sup;
        energy[1] += s->dt * dis;
      }
      /* Zp_k = p(1 + c_k) - x_new, p the collocation polynomial (nodes 0, c_i) */
      for (i = 0; i < 3; ++i)
        for (a = 0; a < r; ++a) {
          phgmg_real v = L.lag[i * 4] * x[a];
          int j;
          for (j = 0; j < 3; ++j) v += L.lag[i * 4 + 1 + j] * (x[a] + L.Z[j * r + a]);
          L.Zp[i * r + a] = v - xn[a];
        }
      for (a = 0; a < r; ++a) x[a] = xn[a];
      s->have_prev = 1;
      if (theta_max > PHGMG__R(0.5)) s->have_lu = 0; /* slow contraction: refactor next step */
      s->stats.steps++;
      if (y) phgmg_rom_output(rom, x, y, L.work);
      return PHGMG_OK;
    }
  }
  s->stats.failures++;
  s->have_prev = 0;
  return err == PHGMG_OK ? PHGMG_ERR_NOT_CONVERGED : err;
}

/* >>export (implementation) ============================================== */
#include <stdint.h>

/* The arrays of a phgmg_rom in file order, with their sizes. */
#define PHGMG__NFIELDS 18
typedef struct phgmg__field { size_t off; const char *name; } phgmg__field;
static const phgmg__field phgmg__fields[PHGMG__NFIELDS] = {
  {offsetof(phgmg_rom, Bh), "Bh"},   {offsetof(phgmg_rom, Qh), "Qh"},   {offsetof(phgmg_rom, K), "K"},
  {offsetof(phgmg_rom, G00), "G00"}, {offsetof(phgmg_rom, G01), "G01"}, {offsetof(phgmg_rom, G10), "G10"},
  {offsetof(phgmg_rom, G11), "G11"}, {offsetof(phgmg_rom, Q01), "Q01"}, {offsetof(phgmg_rom, Q11), "Q11"},
  {offsetof(phgmg_rom, Ms), "Ms"},   {offsetof(phgmg_rom, P0), "P0"},   {offsetof(phgmg_rom, P1), "P1"},
  {offsetof(phgmg_rom, w), "w"},     {offsetof(phgmg_rom, poly), "poly"}, {offsetof(phgmg_rom, Phi), "Phi"},
  {offsetof(phgmg_rom, Gam), "Gam"}, {offsetof(phgmg_rom, SX), "SX"},   {offsetof(phgmg_rom, SU), "SU"}};

PHGMG__ONLINE const phgmg_real **phgmg__field_ptr(phgmg_rom *rom, int i) {
  return PHGMG__CAST(const phgmg_real **, PHGMG__CAST(void *, PHGMG__CAST(char *, PHGMG__CAST(void *, rom)) + phgmg__fields[i].off));
}
PHGMG__ONLINE const phgmg_real *phgmg__field_get(const phgmg_rom *rom, int i) {
  return *PHGMG__CAST(const phgmg_real *const *, PHGMG__CAST(const void *, PHGMG__CAST(const char *, PHGMG__CAST(const void *, rom)) + phgmg__fields[i].off));
}
/* Number of scalars of field i (0 if the field does not apply). */
PHGMG__ONLINE size_t phgmg__field_len(const phgmg_rom *rom, int i) {
  const size_t r = (size_t)rom->r, m = (size_t)rom->m, rn = (size_t)rom->rn, nd = (size_t)rom->nd;
  const size_t p = (size_t)(rom->r - rom->m);
  switch (i) {
    case 0: return r * m;
    case 1: return r * r;
    case 2: return r * r;
    case 3: return r * r;
    case 4: return r * rn;
    case 5: return rn * r;
    case 6: return rn * rn;
    case 7: return r * rn;
    case 8: return rn * rn;
    case 9: return rn * p * p;
    case 10: return nd * r;
    case 11: return nd * rn;
    case 12: return nd;
    case 13: return nd ? (size_t)rom->poly_deg + 1 : 0;
    case 14: return r * r;
    case 15: return r * 3 * m;
    case 16: return 3 * r * r;
    default: return 3 * r * 3 * m;
  }
}

#define PHGMG__HDR_BYTES (8 + 4 * 10 + 8)

PHGMG__ONLINE void phgmg__put32(unsigned char *b, uint32_t v) {
  b[0] = (unsigned char)(v & 255u); b[1] = (unsigned char)((v >> 8) & 255u);
  b[2] = (unsigned char)((v >> 16) & 255u); b[3] = (unsigned char)((v >> 24) & 255u);
}
PHGMG__ONLINE uint32_t phgmg__get32(const unsigned char *b) {
  return (uint32_t)b[0] | ((uint32_t)b[1] << 8) | ((uint32_t)b[2] << 16) | ((uint32_t)b[3] << 24);
}
PHGMG__ONLINE void phgmg__put_f64(unsigned char *b, double v) {
  uint64_t u;
  int i;
  memcpy(&u, &v, 8);
  for (i = 0; i < 8; ++i) b[i] = (unsigned char)((u >> (8 * i)) & 255u);
}
PHGMG__ONLINE double phgmg__get_f64(const unsigned char *b) {
  uint64_t u = 0;
  double v;
  int i;
  for (i = 0; i < 8; ++i) u |= (uint64_t)b[i] << (8 * i);
  memcpy(&v, &u, 8);
  return v;
}
PHGMG__ONLINE void phgmg__put_f32(unsigned char *b, float v) {
  uint32_t u;
  memcpy(&u, &v, 4);
  phgmg__put32(b, u);
}
PHGMG__ONLINE float phgmg__get_f32(const unsigned char *b) {
  uint32_t u = phgmg__get32(b);
  float v;
  memcpy(&v, &u, 4);
  return v;
}
PHGMG__ONLINE uint32_t phgmg__fnv1a(const unsigned char *b, size_t n) {
  uint32_t h = 2166136261u;
  size_t i;
  for (i = 0; i < n; ++i) { h ^= b[i]; h *= 16777619u; }
  return h;
}

PHGMG_DEF size_t phgmg_rom_serialized_size(const phgmg_rom *rom) {
  size_t n = 0;
  int i;
  for (i = 0; i < PHGMG__NFIELDS; ++i)
    if (phgmg__field_get(rom, i)) n += phgmg__field_len(rom, i);
  return PHGMG__HDR_BYTES + n * sizeof(phgmg_real) + 4;
}

PHGMG_DEF phgmg_result phgmg_rom_serialize(const phgmg_rom *rom, void *buf, size_t cap, size_t *written) {
  unsigned char *b = PHGMG__CAST(unsigned char *, buf);
  size_t need, o;
  uint32_t mask = 0;
  int i;
  phgmg_result rc = phgmg_rom_check(rom);
  if (rc != PHGMG_OK) return rc;
  if (!buf) return PHGMG_ERR_INVALID_ARG;
  need = phgmg_rom_serialized_size(rom);
  if (cap < need) return PHGMG_ERR_WORKSPACE;
  for (i = 0; i < PHGMG__NFIELDS; ++i)
    if (phgmg__field_get(rom, i)) mask |= 1u << i;
  memcpy(b, "PHGMGROM", 8);
  phgmg__put32(b + 8, PHGMG_ROM_FORMAT_VERSION);
  phgmg__put32(b + 12, (uint32_t)sizeof(phgmg_real));
  phgmg__put32(b + 16, (uint32_t)rom->kind);
  phgmg__put32(b + 20, (uint32_t)rom->method);
  phgmg__put32(b + 24, (uint32_t)rom->r);
  phgmg__put32(b + 28, (uint32_t)rom->m);
  phgmg__put32(b + 32, (uint32_t)rom->rn);
  phgmg__put32(b + 36, (uint32_t)rom->nd);
  phgmg__put32(b + 40, (uint32_t)rom->poly_deg);
  phgmg__put32(b + 44, mask);
  phgmg__put_f64(b + 48, (double)rom->dt);
  o = PHGMG__HDR_BYTES;
  for (i = 0; i < PHGMG__NFIELDS; ++i) {
    const phgmg_real *a = phgmg__field_get(rom, i);
    size_t k, n = phgmg__field_len(rom, i);
    if (!a) continue;
    for (k = 0; k < n; ++k, o += sizeof(phgmg_real)) {
#if PHGMG_REAL_IS_FLOAT
      phgmg__put_f32(b + o, a[k]);
#else
      phgmg__put_f64(b + o, a[k]);
#endif
    }
  }
  phgmg__put32(b + o, phgmg__fnv1a(b, o));
  if (written) *written = o + 4;
  return PHGMG_OK;
}

/* Parse and validate the header; fills rom's scalars and returns the scalar
   count of the payload and the file's scalar size. */
PHGMG__ONLINE phgmg_result phgmg__rom_header(const unsigned char *b, size_t len, phgmg_rom *rom,
                                             size_t *nscal, size_t *ssize, uint32_t *mask_out) {
  uint32_t ver, ss, mask;
  size_t n = 0, total;
  int i;
  if (!b) return PHGMG_ERR_INVALID_ARG;
  if (len < PHGMG__HDR_BYTES + 4 || memcmp(b, "PHGMGROM", 8) != 0) return PHGMG_ERR_FORMAT;
  ver = phgmg__get32(b + 8);
  ss = phgmg__get32(b + 12);
  if (ver != PHGMG_ROM_FORMAT_VERSION || (ss != 4 && ss != 8)) return PHGMG_ERR_FORMAT;
  memset(rom, 0, sizeof *rom);
  if (phgmg__get32(b + 24) > 4096u || phgmg__get32(b + 28) > 4096u || phgmg__get32(b + 32) > 4096u ||
      phgmg__get32(b + 36) > (1u << 24) || phgmg__get32(b + 40) > 32u || phgmg__get32(b + 16) > 2u ||
      phgmg__get32(b + 20) > 4u)
    return PHGMG_ERR_FORMAT;
  rom->kind = (int)phgmg__get32(b + 16);
  rom->method = (int)phgmg__get32(b + 20);
  rom->r = (int)phgmg__get32(b + 24);
  rom->m = (int)phgmg__get32(b + 28);
  rom->rn = (int)phgmg__get32(b + 32);
  rom->nd = (int)phgmg__get32(b + 36);
  rom->poly_deg = (int)phgmg__get32(b + 40);
  mask = phgmg__get32(b + 44);
  {
    double dt = phgmg__get_f64(b + 48);
    if (!(dt >= 0.0) || dt > 1e300) return PHGMG_ERR_FORMAT;
    rom->dt = (phgmg_real)dt;
  }
  if (mask >> PHGMG__NFIELDS) return PHGMG_ERR_FORMAT;
  if (rom->m > rom->r) return PHGMG_ERR_FORMAT;
  for (i = 0; i < PHGMG__NFIELDS; ++i)
    if (mask & (1u << i)) {
      size_t k = phgmg__field_len(rom, i);
      if (k > ((size_t)1 << 40)) return PHGMG_ERR_FORMAT;
      n += k;
    }
  if (n > (len / ss)) return PHGMG_ERR_FORMAT;
  total = PHGMG__HDR_BYTES + n * ss + 4;
  if (total != len) return PHGMG_ERR_FORMAT;
  if (phgmg__get32(b + total - 4) != phgmg__fnv1a(b, total - 4)) return PHGMG_ERR_FORMAT;
  *nscal = n;
  *ssize = ss;
  *mask_out = mask;
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_rom_deserialize_size(const void *buf, size_t len, size_t *need) {
  phgmg_rom tmp;
  size_t n = 0, ss = 0;
  uint32_t mask = 0;
  phgmg_result rc = phgmg__rom_header(PHGMG__CAST(const unsigned char *, buf), len, &tmp, &n, &ss, &mask);
  if (rc != PHGMG_OK) return rc;
  if (need) *need = n * sizeof(phgmg_real) + sizeof(phgmg_real);
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_rom_deserialize(const void *buf, size_t len, phgmg_rom *rom, void *mem,
                                             size_t mem_size) {
  const unsigned char *b = PHGMG__CAST(const unsigned char *, buf);
  phgmg_rom tmp;
  size_t n = 0, ss = 0, o = PHGMG__HDR_BYTES, k;
  uint32_t mask = 0;
  phgmg_real *dst = PHGMG__CAST(phgmg_real *, mem);
  phgmg_result rc;
  int i;
  if (!rom || !mem) return PHGMG_ERR_INVALID_ARG;
  rc = phgmg__rom_header(b, len, &tmp, &n, &ss, &mask);
  if (rc != PHGMG_OK) return rc;
  if (mem_size < n * sizeof(phgmg_real) + sizeof(phgmg_real)) return PHGMG_ERR_WORKSPACE;
  if (((size_t)mem) % sizeof(phgmg_real) != 0) return PHGMG_ERR_INVALID_ARG;
  for (i = 0; i < PHGMG__NFIELDS; ++i) {
    const size_t len_i = phgmg__field_len(&tmp, i);
    if (!(mask & (1u << i))) { *phgmg__field_ptr(&tmp, i) = NULL; continue; }
    for (k = 0; k < len_i; ++k, o += ss)
      dst[k] = ss == 8 ? (phgmg_real)phgmg__get_f64(b + o) : (phgmg_real)phgmg__get_f32(b + o);
    if (!phgmg__r_finite(dst, (int)len_i)) return PHGMG_ERR_FORMAT;
    *phgmg__field_ptr(&tmp, i) = dst;
    dst += len_i;
  }
  rc = phgmg_rom_check(&tmp);
  if (rc != PHGMG_OK) return PHGMG_ERR_FORMAT;
  /* fields required by the kind must be present, others absent */
  if ((tmp.kind == PHGMG_ROM_QUADRATIC) != (tmp.Ms != NULL) || (tmp.nd == 0 && (tmp.P0 || tmp.w)))
    return PHGMG_ERR_FORMAT;
  *rom = tmp;
  return PHGMG_OK;
}

#if !defined(PHGMG_NO_STDIO) && !defined(PHGMG_NO_OFFLINE)
#include <stdio.h>
PHGMG_DEF phgmg_result phgmg_rom_save(const phgmg_rom *rom, const char *path) {
  size_t n, w = 0;
  void *buf;
  FILE *f;
  phgmg_result rc = phgmg_rom_check(rom);
  if (rc != PHGMG_OK) return rc;
  if (!path) return PHGMG_ERR_INVALID_ARG;
  n = phgmg_rom_serialized_size(rom);
  buf = phgmg__alloc(NULL, n);
  if (!buf) return PHGMG_ERR_NOMEM;
  rc = phgmg_rom_serialize(rom, buf, n, &w);
  if (rc == PHGMG_OK) {
    f = fopen(path, "wb");
    if (!f) rc = PHGMG_ERR_IO;
    else {
      if (fwrite(buf, 1, w, f) != w) rc = PHGMG_ERR_IO;
      if (fclose(f) != 0) rc = PHGMG_ERR_IO;
    }
  }
  phgmg__free(NULL, buf);
  return rc;
}

PHGMG_DEF phgmg_result phgmg_rom_load(const char *path, phgmg_rom *rom, void **block,
                                      const phgmg_allocator *alloc) {
  FILE *f;
  long len;
  unsigned char *buf = NULL;
  void *mem = NULL;
  size_t need = 0;
  phgmg_result rc;
  if (!path || !rom || !block) return PHGMG_ERR_INVALID_ARG;
  *block = NULL;
  f = fopen(path, "rb");
  if (!f) return PHGMG_ERR_IO;
  if (fseek(f, 0, SEEK_END) != 0 || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) { fclose(f); return PHGMG_ERR_IO; }
  if (len > (1L << 30)) { fclose(f); return PHGMG_ERR_FORMAT; }
  buf = PHGMG__CAST(unsigned char *, phgmg__alloc(alloc, (size_t)len));
  if (!buf) { fclose(f); return PHGMG_ERR_NOMEM; }
  if (fread(buf, 1, (size_t)len, f) != (size_t)len) { fclose(f); phgmg__free(alloc, buf); return PHGMG_ERR_IO; }
  fclose(f);
  rc = phgmg_rom_deserialize_size(buf, (size_t)len, &need);
  if (rc == PHGMG_OK) {
    mem = phgmg__alloc(alloc, need);
    if (!mem) rc = PHGMG_ERR_NOMEM;
    else rc = phgmg_rom_deserialize(buf, (size_t)len, rom, mem, need);
  }
  phgmg__free(alloc, buf);
  if (rc != PHGMG_OK) { phgmg__free(alloc, mem); return rc; }
  *block = mem;
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_rom_export_c(const phgmg_rom *rom, const char *name, const char *path) {
  FILE *f;
  int i, ok = 1;
  size_t k;
  phgmg_result rc = phgmg_rom_check(rom);
  if (rc != PHGMG_OK) return rc;
  if (!name || !path) return PHGMG_ERR_INVALID_ARG;
  f = fopen(path, "w");
  if (!f) return PHGMG_ERR_IO;
  ok &= fprintf(f, "/* Reduced port-Hamiltonian model exported by phgmg %s.\n"
                   "   kind %d, method %d, r = %d, m = %d, r_n = %d, DEIM points = %d.\n"
                   "   Include after phgmg.h; build with the same scalar type. */\n",
                PHGMG_VERSION_STRING, rom->kind, rom->method, rom->r, rom->m, rom->rn, rom->nd) > 0;
  ok &= fprintf(f, "#if PHGMG_REAL_IS_FLOAT != %d\n#error \"%s was exported for phgmg_real = %s\"\n#endif\n",
                PHGMG_REAL_IS_FLOAT, name, PHGMG_REAL_IS_FLOAT ? "float" : "double") > 0;
  for (i = 0; i < PHGMG__NFIELDS; ++i) {
    const phgmg_real *a = phgmg__field_get(rom, i);
    const size_t n = phgmg__field_len(rom, i);
    if (!a) continue;
    ok &= fprintf(f, "static const phgmg_real %s_%s[%lu] = {", name, phgmg__fields[i].name, (unsigned long)n) > 0;
    for (k = 0; k < n; ++k)
#if PHGMG_REAL_IS_FLOAT
      ok &= fprintf(f, "%s%.9gf", k % 6 ? ", " : "\n  ", (double)a[k]) > 0;
#else
      ok &= fprintf(f, "%s%.17g", k % 4 ? ", " : "\n  ", a[k]) > 0;
#endif
    ok &= fprintf(f, "};\n") > 0;
  }
  ok &= fprintf(f, "static const phgmg_rom %s = {\n  %d, %d, %d, %d, %d, %d, %d,\n ", name, rom->kind,
                rom->method, rom->r, rom->m, rom->rn, rom->nd, rom->poly_deg) > 0;
  for (i = 0; i < 14; ++i) {
    if (phgmg__field_get(rom, i)) ok &= fprintf(f, " %s_%s,", name, phgmg__fields[i].name) > 0;
    else ok &= fprintf(f, " NULL,") > 0;
  }
#if PHGMG_REAL_IS_FLOAT
  ok &= fprintf(f, "\n  %.9gf,\n ", (double)rom->dt) > 0;
#else
  ok &= fprintf(f, "\n  %.17g,\n ", rom->dt) > 0;
#endif
  for (i = 14; i < PHGMG__NFIELDS; ++i) {
    if (phgmg__field_get(rom, i)) ok &= fprintf(f, " %s_%s%s", name, phgmg__fields[i].name, i + 1 < PHGMG__NFIELDS ? "," : "") > 0;
    else ok &= fprintf(f, " NULL%s", i + 1 < PHGMG__NFIELDS ? "," : "") > 0;
  }
  ok &= fprintf(f, "\n};\n") > 0;
  if (fclose(f) != 0) ok = 0;
  return ok ? PHGMG_OK : PHGMG_ERR_IO;
}
#endif

/* >>npy (implementation) ================================================== */
#ifndef PHGMG_NO_OFFLINE
#include <limits.h>
#ifndef PHGMG_NO_STDIO
#include <stdio.h>
#endif

/* What the header says, checked: a rows x cols result with count elements of
   es bytes each (4 or 8), big-endian or not, stored in C order or not. */
typedef struct phgmg__npy_hdr {
  int rows, cols, ndim;
  int es, big, corder;
  size_t count;
} phgmg__npy_hdr;

/* 1 on a little-endian host (integers and doubles share the byte order on
   every platform the library targets). */
PHGMG__PRIV int phgmg__npy_host_little(void) {
  const unsigned int one = 1u;
  unsigned char c;
  memcpy(&c, &one, 1);
  return c == 1;
}

/* Preamble: magic, version, header length. p holds the first n bytes of the
   file (n >= 10 suffices for version 1.0, 12 for 2.0/3.0). On success
   *hoff is the offset of the header text and *hlen its length. */
PHGMG__PRIV phgmg_result phgmg__npy_preamble(const unsigned char *p, size_t n, size_t *hoff,
                                             size_t *hlen) {
  static const unsigned char magic[6] = {0x93, 'N', 'U', 'M', 'P', 'Y'};
  size_t hl;
  if (n < 10 || memcmp(p, magic, 6) != 0 || p[7] != 0) return PHGMG_ERR_FORMAT;
  if (p[6] == 1) {
    hl = (size_t)p[8] | ((size_t)p[9] << 8);
    *hoff = 10;
  } else if (p[6] == 2 || p[6] == 3) {
    unsigned long v;
    if (n < 12) return PHGMG_ERR_FORMAT;
    v = (unsigned long)p[8] | ((unsigned long)p[9] << 8) | ((unsigned long)p[10] << 16) |
        ((unsigned long)p[11] << 24);
    if (v > (unsigned long)PHGMG_NPY_MAX_HEADER) return PHGMG_ERR_FORMAT;
    hl = (size_t)v;
    *hoff = 12;
  } else {
    return PHGMG_ERR_FORMAT;
  }
  if (hl > (size_t)PHGMG_NPY_MAX_HEADER) return PHGMG_ERR_FORMAT;
  *hlen = hl;
  return PHGMG_OK;
}

PHGMG__PRIV size_t phgmg__npy_ws(const char *s, size_t n, size_t i) {
  while (i < n && (s[i] == ' ' || s[i] == '\t' || s[i] == '\n' || s[i] == '\r')) ++i;
  return i;
}

/* A quoted Python string without escapes at s[*i]: its body is s[*b .. *b+*l). */
PHGMG__PRIV int phgmg__npy_str(const char *s, size_t n, size_t *i, size_t *b, size_t *l) {
  size_t k = *i;
  char q;
  if (k >= n || (s[k] != '\'' && s[k] != '"')) return 0;
  q = s[k++];
  *b = k;
  while (k < n && s[k] != q) {
    if (s[k] == '\\' || s[k] == '\n' || s[k] == '\r') return 0;
    ++k;
  }
  if (k >= n) return 0;
  *l = k - *b;
  *i = k + 1;
  return 1;
}

/* Does s[b..b+l) equal the C string w? */
PHGMG__PRIV int phgmg__npy_is(const char *s, size_t b, size_t l, const char *w) {
  return strlen(w) == l && memcmp(s + b, w, l) == 0;
}

/* The identifier w at s[*i], not followed by another identifier character. */
PHGMG__PRIV int phgmg__npy_word(const char *s, size_t n, size_t *i, const char *w) {
  size_t l = strlen(w), e = *i + l;
  char c;
  if (n - *i < l || memcmp(s + *i, w, l) != 0) return 0;
  if (e < n) {
    c = s[e];
    if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_')
      return 0;
  }
  *i = e;
  return 1;
}

/* A non-negative decimal integer <= INT_MAX (Python 2's "L" suffix allowed). */
PHGMG__PRIV int phgmg__npy_int(const char *s, size_t n, size_t *i, int *v) {
  size_t k = *i;
  long acc = 0;
  if (k >= n || s[k] < '0' || s[k] > '9') return 0;
  while (k < n && s[k] >= '0' && s[k] <= '9') {
    int d = s[k] - '0';
    if (acc > ((long)INT_MAX - d) / 10) return 0;
    acc = acc * 10 + d;
    ++k;
  }
  if (k < n && s[k] == 'L') ++k;
  *v = (int)acc;
  *i = k;
  return 1;
}

/* A shape tuple: (), (n,), (r, c) with optional trailing comma (required
   for one element, as in Python). More than two dimensions: 0. */
PHGMG__PRIV int phgmg__npy_shape(const char *s, size_t n, size_t *i, int *dims, int *nd) {
  size_t k = *i;
  int cnt = 0, comma = 0;
  if (k >= n || s[k] != '(') return 0;
  k = phgmg__npy_ws(s, n, k + 1);
  while (k < n && s[k] != ')') {
    if (cnt == 2) return 0;
    if (!phgmg__npy_int(s, n, &k, &dims[cnt])) return 0;
    ++cnt;
    k = phgmg__npy_ws(s, n, k);
    comma = 0;
    if (k < n && s[k] == ',') {
      comma = 1;
      k = phgmg__npy_ws(s, n, k + 1);
    } else if (k < n && s[k] != ')') {
      return 0;
    }
  }
  if (k >= n) return 0;
  if (cnt == 1 && !comma) return 0; /* "(5)" is an int, not a tuple */
  *nd = cnt;
  *i = k + 1;
  return 1;
}

/* The header dict {'descr': ..., 'fortran_order': ..., 'shape': ...}, keys in
   any order, each exactly once, nothing else but whitespace after it. */
PHGMG__PRIV phgmg_result phgmg__npy_dict(const char *s, size_t n, phgmg__npy_hdr *h) {
  size_t i = phgmg__npy_ws(s, n, 0), b, l;
  int seen_descr = 0, seen_fo = 0, seen_shape = 0, fortran = 0, nd = 0;
  int dims[2] = {0, 0};
  if (i >= n || s[i] != '{') return PHGMG_ERR_FORMAT;
  i = phgmg__npy_ws(s, n, i + 1);
  while (i < n && s[i] != '}') {
    if (!phgmg__npy_str(s, n, &i, &b, &l)) return PHGMG_ERR_FORMAT;
    i = phgmg__npy_ws(s, n, i);
    if (i >= n || s[i] != ':') return PHGMG_ERR_FORMAT;
    i = phgmg__npy_ws(s, n, i + 1);
    if (phgmg__npy_is(s, b, l, "descr")) {
      size_t vb, vl;
      if (seen_descr++ || !phgmg__npy_str(s, n, &i, &vb, &vl)) return PHGMG_ERR_FORMAT;
      if (vl != 3 || (s[vb] != '<' && s[vb] != '>') || s[vb + 1] != 'f' ||
          (s[vb + 2] != '8' && s[vb + 2] != '4'))
        return PHGMG_ERR_FORMAT;
      h->big = s[vb] == '>';
      h->es = s[vb + 2] - '0';
    } else if (phgmg__npy_is(s, b, l, "fortran_order")) {
      if (seen_fo++) return PHGMG_ERR_FORMAT;
      if (phgmg__npy_word(s, n, &i, "True")) fortran = 1;
      else if (phgmg__npy_word(s, n, &i, "False")) fortran = 0;
      else return PHGMG_ERR_FORMAT;
    } else if (phgmg__npy_is(s, b, l, "shape")) {
      if (seen_shape++ || !phgmg__npy_shape(s, n, &i, dims, &nd)) return PHGMG_ERR_FORMAT;
    } else {
      return PHGMG_ERR_FORMAT;
    }
    i = phgmg__npy_ws(s, n, i);
    if (i < n && s[i] == ',') i = phgmg__npy_ws(s, n, i + 1);
    else if (i < n && s[i] != '}') return PHGMG_ERR_FORMAT;
  }
  if (i >= n || !seen_descr || !seen_fo || !seen_shape) return PHGMG_ERR_FORMAT;
  if (phgmg__npy_ws(s, n, i + 1) != n) return PHGMG_ERR_FORMAT;
  h->ndim = nd;
  h->rows = nd >= 1 ? dims[0] : 1;
  h->cols = nd == 2 ? dims[1] : 1;
  h->corder = nd == 2 && !fortran;
  if (h->cols != 0 && (size_t)h->rows > ((size_t)-1) / 16 / (size_t)h->cols)
    return PHGMG_ERR_FORMAT; /* the result would not fit in memory */
  h->count = (size_t)h->rows * (size_t)h->cols;
  return PHGMG_OK;
}

/* Decode n elements of file (flat) indices k0 .. k0+n-1 from src into the
   column-major rows x cols matrix out. */
PHGMG__PRIV void phgmg__npy_decode(const phgmg__npy_hdr *h, const unsigned char *src, size_t k0,
                                   size_t n, double *out) {
  const int es = h->es, swap = h->big == phgmg__npy_host_little();
  size_t t, i = 0, j = 0, dst = k0;
  unsigned char tmp[8];
  int b;
  if (n == 0) return;
  if (h->corder) { i = k0 / (size_t)h->cols; j = k0 % (size_t)h->cols; }
  for (t = 0; t < n; ++t, src += es) {
    double v;
    for (b = 0; b < es; ++b) tmp[b] = src[swap ? es - 1 - b : b];
    if (es == 8) {
      memcpy(&v, tmp, 8);
    } else {
      float f;
      memcpy(&f, tmp, 4);
      v = (double)f;
    }
    if (h->corder) {
      dst = i + j * (size_t)h->rows;
      if (++j == (size_t)h->cols) { j = 0; ++i; }
    }
    out[dst++] = v;
  }
}

PHGMG_DEF phgmg_result phgmg_npy_parse(const void *buf, size_t len, double **out, int *rows,
                                       int *cols, int *ndim, const phgmg_allocator *alloc) {
  const unsigned char *p = PHGMG__CAST(const unsigned char *, buf);
  phgmg__npy_hdr h;
  size_t hoff = 0, hlen = 0, doff;
  memset(&h, 0, sizeof h);
  double *A;
  phgmg_result rc;
  if (!buf || !out || !rows || !cols) return PHGMG_ERR_INVALID_ARG;
  rc = phgmg__npy_preamble(p, len, &hoff, &hlen);
  if (rc != PHGMG_OK) return rc;
  if (hlen > len - hoff) return PHGMG_ERR_FORMAT;
  rc = phgmg__npy_dict(PHGMG__CAST(const char *, buf) + hoff, hlen, &h);
  if (rc != PHGMG_OK) return rc;
  doff = hoff + hlen;
  if (h.count > (len - doff) / (size_t)h.es) return PHGMG_ERR_FORMAT; /* truncated */
  A = phgmg__dalloc(alloc, h.count);
  if (!A) return PHGMG_ERR_NOMEM;
  phgmg__npy_decode(&h, p + doff, 0, h.count, A);
  *out = A;
  *rows = h.rows;
  *cols = h.cols;
  if (ndim) *ndim = h.ndim;
  return PHGMG_OK;
}

PHGMG_DEF void phgmg_npy_free(double *p, const phgmg_allocator *alloc) { phgmg__free(alloc, p); }

/* ---- writing ---- */

/* Checks the writer arguments; *count receives rows*cols. */
PHGMG__PRIV phgmg_result phgmg__npy_wcheck(const double *A, int rows, int cols, int ld, int ndim,
                                           unsigned flags, size_t *count) {
  if (flags & ~(PHGMG_NPY_C_ORDER | PHGMG_NPY_F32)) return PHGMG_ERR_INVALID_ARG;
  if (rows < 0 || cols < 0 || ld < PHGMG__MAX(1, rows)) return PHGMG_ERR_SIZE;
  if (ndim == 0) {
    if (rows != 1 || cols != 1) return PHGMG_ERR_SIZE;
  } else if (ndim == 1) {
    if (rows != 1 && cols != 1) return PHGMG_ERR_SIZE;
  } else if (ndim != 2) {
    return PHGMG_ERR_SIZE;
  }
  if (cols != 0 && (size_t)rows > ((size_t)-1) / 16 / (size_t)cols) return PHGMG_ERR_SIZE;
  *count = (size_t)rows * (size_t)cols;
  if (!A && *count > 0) return PHGMG_ERR_INVALID_ARG;
  return PHGMG_OK;
}

PHGMG__PRIV char *phgmg__npy_puts(char *d, const char *s) {
  while (*s) *d++ = *s++;
  return d;
}
PHGMG__PRIV char *phgmg__npy_putint(char *d, size_t v) {
  char t[24];
  int n = 0;
  do { t[n++] = (char)('0' + (int)(v % 10)); v /= 10; } while (v);
  while (n) *d++ = t[--n];
  return d;
}

/* The complete version 1.0 preamble + header into dst (room for 256 bytes);
   returns its length, a multiple of 64. */
PHGMG__PRIV size_t phgmg__npy_header(unsigned char *dst, int rows, int cols, int ndim,
                                     unsigned flags) {
  char *s = PHGMG__CAST(char *, PHGMG__CAST(void *, dst)), *d = s + 10;
  size_t used, total;
  d = phgmg__npy_puts(d, (flags & PHGMG_NPY_F32) ? "{'descr': '<f4', " : "{'descr': '<f8', ");
  d = phgmg__npy_puts(d, (flags & PHGMG_NPY_C_ORDER) ? "'fortran_order': False, "
                                                     : "'fortran_order': True, ");
  d = phgmg__npy_puts(d, "'shape': (");
  if (ndim == 1) {
    d = phgmg__npy_putint(d, (size_t)rows * (size_t)cols);
    *d++ = ',';
  } else if (ndim == 2) {
    d = phgmg__npy_putint(d, (size_t)rows);
    d = phgmg__npy_puts(d, ", ");
    d = phgmg__npy_putint(d, (size_t)cols);
  }
  d = phgmg__npy_puts(d, "), }");
  used = (size_t)(d - s) + 1; /* + the final newline */
  total = (used + 63) / 64 * 64;
  while ((size_t)(d - s) < total - 1) *d++ = ' ';
  *d = '\n';
  memcpy(s, "\x93NUMPY", 6);
  dst[6] = 1;
  dst[7] = 0;
  dst[8] = (unsigned char)((total - 10) & 0xff);
  dst[9] = (unsigned char)((total - 10) >> 8);
  return total;
}

/* Encode n elements, continuing at element (*i, *j) of A in file order, as
   little-endian f8 or f4 into dst; advances (*i, *j). */
PHGMG__PRIV void phgmg__npy_encode(const double *A, int rows, int cols, int ld, unsigned flags,
                                   size_t *i, size_t *j, size_t n, unsigned char *dst) {
  const int f32 = (flags & PHGMG_NPY_F32) != 0, corder = (flags & PHGMG_NPY_C_ORDER) != 0;
  const int es = f32 ? 4 : 8, swap = !phgmg__npy_host_little();
  size_t t;
  unsigned char tmp[8];
  int b;
  for (t = 0; t < n; ++t, dst += es) {
    double v = A[*i + *j * (size_t)ld];
    if (f32) {
      float f = (float)v;
      memcpy(tmp, &f, 4);
    } else {
      memcpy(tmp, &v, 8);
    }
    for (b = 0; b < es; ++b) dst[b] = tmp[swap ? es - 1 - b : b];
    if (corder) {
      if (++*j == (size_t)cols) { *j = 0; ++*i; }
    } else {
      if (++*i == (size_t)rows) { *i = 0; ++*j; }
    }
  }
}

PHGMG_DEF phgmg_result phgmg_npy_serialize(const double *A, int rows, int cols, int ld, int ndim,
                                           unsigned flags, void *buf, size_t cap, size_t *len) {
  unsigned char head[256];
  size_t count = 0, hl, es = (flags & PHGMG_NPY_F32) ? 4 : 8, need, i = 0, j = 0;
  phgmg_result rc;
  if (!len) return PHGMG_ERR_INVALID_ARG;
  rc = phgmg__npy_wcheck(A, rows, cols, ld, ndim, flags, &count);
  if (rc != PHGMG_OK) return rc;
  hl = phgmg__npy_header(head, rows, cols, ndim, flags);
  need = hl + count * es;
  *len = need;
  if (!buf) return PHGMG_OK;
  if (cap < need) return PHGMG_ERR_WORKSPACE;
  memcpy(buf, head, hl);
  phgmg__npy_encode(A, rows, cols, ld, flags, &i, &j, count,
                    PHGMG__CAST(unsigned char *, buf) + hl);
  return PHGMG_OK;
}

#ifndef PHGMG_NO_STDIO
/* fread of exactly n bytes: PHGMG_OK, PHGMG_ERR_FORMAT at end of file,
   PHGMG_ERR_IO on a read error. */
PHGMG__PRIV phgmg_result phgmg__npy_fread(FILE *f, void *dst, size_t n) {
  if (n == 0 || fread(dst, 1, n, f) == n) return PHGMG_OK;
  return ferror(f) ? PHGMG_ERR_IO : PHGMG_ERR_FORMAT;
}

PHGMG_DEF phgmg_result phgmg_npy_read(const char *path, double **out, int *rows, int *cols,
                                      int *ndim, const phgmg_allocator *alloc) {
  unsigned char pre[12], chunk[4096];
  size_t hoff = 0, hlen = 0, left, k = 0;
  phgmg__npy_hdr h;
  phgmg_result rc;
  char *text;
  double *A;
  long size;
  FILE *f;
  memset(&h, 0, sizeof h);
  if (!path || !out || !rows || !cols) return PHGMG_ERR_INVALID_ARG;
  f = fopen(path, "rb");
  if (!f) return PHGMG_ERR_IO;
  /* preamble: 10 bytes, 12 for versions 2.0 and 3.0 */
  rc = phgmg__npy_fread(f, pre, 10);
  if (rc == PHGMG_OK && (pre[6] == 2 || pre[6] == 3)) rc = phgmg__npy_fread(f, pre + 10, 2);
  if (rc == PHGMG_OK) rc = phgmg__npy_preamble(pre, (pre[6] == 2 || pre[6] == 3) ? 12 : 10,
                                               &hoff, &hlen);
  if (rc != PHGMG_OK) { fclose(f); return rc; }
  /* a file shorter than the header it announces is malformed: check before
     allocating (when the size is known) */
  size = -1; /* unknown (not seekable): read on */
  if (fseek(f, 0, SEEK_END) == 0) {
    size = ftell(f);
    if (fseek(f, (long)hoff, SEEK_SET) != 0) { fclose(f); return PHGMG_ERR_IO; }
  }
  if (size >= 0 && ((size_t)size < hoff || hlen > (size_t)size - hoff)) {
    fclose(f);
    return PHGMG_ERR_FORMAT;
  }
  text = PHGMG__CAST(char *, phgmg__alloc(alloc, hlen));
  if (!text) { fclose(f); return PHGMG_ERR_NOMEM; }
  rc = phgmg__npy_fread(f, text, hlen);
  if (rc == PHGMG_OK) rc = phgmg__npy_dict(text, hlen, &h);
  phgmg__free(alloc, text);
  if (rc != PHGMG_OK) { fclose(f); return rc; }
  if (size >= 0 && h.count > ((size_t)size - hoff - hlen) / (size_t)h.es) {
    fclose(f);
    return PHGMG_ERR_FORMAT; /* truncated data */
  }
  A = phgmg__dalloc(alloc, h.count);
  if (!A) { fclose(f); return PHGMG_ERR_NOMEM; }
  left = h.count;
  while (left > 0 && rc == PHGMG_OK) {
    size_t n = PHGMG__MIN(left, sizeof chunk / (size_t)h.es);
    rc = phgmg__npy_fread(f, chunk, n * (size_t)h.es);
    if (rc == PHGMG_OK) phgmg__npy_decode(&h, chunk, k, n, A);
    k += n;
    left -= n;
  }
  fclose(f);
  if (rc != PHGMG_OK) { phgmg__free(alloc, A); return rc; }
  *out = A;
  *rows = h.rows;
  *cols = h.cols;
  if (ndim) *ndim = h.ndim;
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_npy_write(const char *path, const double *A, int rows, int cols,
                                       int ld, int ndim, unsigned flags) {
  unsigned char head[256], chunk[4096];
  size_t count = 0, hl, es = (flags & PHGMG_NPY_F32) ? 4 : 8, i = 0, j = 0, left;
  phgmg_result rc;
  int ok;
  FILE *f;
  if (!path) return PHGMG_ERR_INVALID_ARG;
  rc = phgmg__npy_wcheck(A, rows, cols, ld, ndim, flags, &count);
  if (rc != PHGMG_OK) return rc;
  hl = phgmg__npy_header(head, rows, cols, ndim, flags);
  f = fopen(path, "wb");
  if (!f) return PHGMG_ERR_IO;
  ok = fwrite(head, 1, hl, f) == hl;
  for (left = count; ok && left > 0;) {
    size_t n = PHGMG__MIN(left, sizeof chunk / es);
    phgmg__npy_encode(A, rows, cols, ld, flags, &i, &j, n, chunk);
    ok = fwrite(chunk, 1, n * es, f) == n * es;
    left -= n;
  }
  if (fclose(f) != 0) ok = 0;
  if (!ok) {
    remove(path);
    return PHGMG_ERR_IO;
  }
  return PHGMG_OK;
}
#endif /* PHGMG_NO_STDIO */
#endif /* PHGMG_NO_OFFLINE */
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
