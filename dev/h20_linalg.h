
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

/* C = alpha*op(A)*op(B) + beta*C; op(A) is m x k, op(B) is k x n. beta = 0
   overwrites C (NaN in C is not propagated). Cache blocked with a register-tiled
   micro-kernel; uses PHGMG_GEMM_MC*PHGMG_GEMM_KC doubles of stack (128 KiB by
   default; both macros can be set before including the implementation). */
PHGMG_DEF void phgmg_gemm(char transa, char transb, int m, int n, int k, double alpha,
                          const double *A, int lda, const double *B, int ldb,
                          double beta, double *C, int ldc);
/* y = alpha*op(A)*x + beta*y; A is m x n (beta = 0 overwrites y). */
PHGMG_DEF void phgmg_gemv(char trans, int m, int n, double alpha, const double *A, int lda,
                          const double *x, double beta, double *y);

/* LU with partial pivoting, in place: P*A = L*U, ipiv[k] = row swapped with k
   (0-based, applied in order k = 0..n-1). Recursive, blocked through gemm.
   PHGMG_ERR_SINGULAR if a pivot is exactly zero (the factors are then not usable),
   PHGMG_ERR_NANINF if A holds NaN/Inf (A is then left unchanged). */
PHGMG_DEF phgmg_result phgmg_lu_factor(int n, double *A, int lda, int *ipiv);
/* Solve A X = B (trans 'N') or A^T X = B (trans 'T') with the factors; B is n x nrhs,
   overwritten. Four or more right-hand sides go through blocked (gemm) solves. */
PHGMG_DEF void phgmg_lu_solve(char trans, int n, const double *LU, int lda, const int *ipiv,
                              int nrhs, double *B, int ldb);
/* Reciprocal 1-norm condition estimate (Hager/Higham, LAPACK dlacn2) from the
   factors and ||A||_1: an upper bound of 1/(||A||_1 ||A^-1||_1), in practice
   within a small factor of it. Needs 2n doubles of workspace `work` and n ints
   `iwork`. 0 if a pivot is zero (or anorm1 is 0, NaN or Inf); 1 for n = 0. */
PHGMG_DEF double phgmg_lu_rcond(int n, const double *LU, int lda, const int *ipiv,
                                double anorm1, double *work, int *iwork);
/* 1-norm of a general m x n matrix. */
PHGMG_DEF double phgmg_norm1(int m, int n, const double *A, int lda);
/* Frobenius norm of a general m x n matrix (overflow-safe). */
PHGMG_DEF double phgmg_normf(int m, int n, const double *A, int lda);

/* Complex LU (interleaved storage, see above), partial pivoting (pivot = largest
   |re| + |im|), in place, recursive and blocked. Results as phgmg_lu_factor. */
PHGMG_DEF phgmg_result phgmg_zlu_factor(int n, double *A, int lda, int *ipiv);
/* Solve A X = B, complex B (n x nrhs interleaved), overwritten. */
PHGMG_DEF void phgmg_zlu_solve(int n, const double *LU, int lda, const int *ipiv,
                               int nrhs, double *B, int ldb);

/* Householder QR, in place (LAPACK dgeqrf layout: R in the upper triangle,
   reflectors below, scalars tau[min(m,n)]). */
PHGMG_DEF phgmg_result phgmg_qr(int m, int n, double *A, int lda, double *tau);
/* QR with column pivoting (dgeqp3 semantics): A*P = Q*R; on return jpvt[j] =
   original index of column j (0-based; jpvt is output only, every column is
   free). |R(k,k)| is non-increasing. work: 2n doubles. */
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
   column rank, else PHGMG_ERR_RANK: some |R(j,j)| <= max(m,n) eps ||A||_F);
   lambda > 0: ridge via QR of [A; sqrt(lambda) I] (any m). X is written only on
   success. lambda < 0: PHGMG_ERR_INVALID_ARG. */
PHGMG_DEF phgmg_result phgmg_lstsq(int m, int n, int nrhs, const double *A, int lda,
                                   const double *B, int ldb, double lambda,
                                   double *X, int ldx, const phgmg_allocator *alloc);

/* Thin SVD of a (possibly tall, rank-deficient) m x n matrix: Householder QR
   with column pivoting truncated at the numerical rank r (every trailing column
   norm <= eps*||A||_F), then a second QR of R^T (n x r) and one-sided Jacobi on
   the r x r triangular factor (Drmac-Veselic), U = Q*W, V = P*Q2*Vj.
   Returns the k = min(kmax, r) leading triplets: S[k] descending, U (m x k,
   ldu), V (n x k, ldv; may be NULL, which also saves time). *k_out = k;
   kmax = 0 only computes the rank. *rank_out (may be NULL) = r. Cost grows
   with r^3 (about 1 s for r ~ 800 on one core), A is not modified.
   PHGMG_ERR_NANINF / _NOMEM / _NOT_CONVERGED (Jacobi, not seen in practice). */
PHGMG_DEF phgmg_result phgmg_svd(int m, int n, const double *A, int lda, int kmax,
                                 double *S, double *U, int ldu, double *V, int ldv,
                                 int *k_out, int *rank_out, const phgmg_allocator *alloc);

/* Symmetric eigenvalues (ascending) and optionally eigenvectors (V, n x n, may
   be NULL; V = A's eigenvectors in the order of w). A is n x n, used as
   (A + A^T)/2, destroyed. n <= 24: cyclic Jacobi; larger n: Householder
   tridiagonalization + implicit QL (EISPACK tred2/tql2), about 0.4 s (values
   only) / 1 s (with vectors) at n = 1000. No allocation. */
PHGMG_DEF phgmg_result phgmg_sym_eig(int n, double *A, int lda, double *w, double *V, int ldv);

#ifdef __cplusplus
}
#endif
#endif /* PHGMG_NO_OFFLINE */
