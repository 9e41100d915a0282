
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
   ||J + J^T|| <= tol ||J||, ||R - R^T|| <= tol ||R||, ||Q - Q^T|| <= tol ||Q||
   (Frobenius), lambda_min(R) >= -tol ||R||_2, B full column rank (pivoted QR:
   |R_mm| > tol |R_11|), 1/cond_1(J - R) > tol (rcond_out, may be NULL, receives
   the estimate), no NaN/Inf (only entries inside the band are read for BANDED
   storage), sizes consistent (N >= 1, 1 <= m <= N, 0 <= kb < N, sep_idx in
   range), the callbacks the nonlinear kind needs are set. lambda_min(R): exact
   for a diagonal R, else phgmg_sym_eig on a dense copy (dense R, or banded with
   N <= 2000); a larger banded R must admit a Cholesky factorization of
   R + tol ||R||_1 I in band storage (O(N kb^2), a slightly looser bound since
   ||R||_1 >= ||R||_2). Checks run in this order and the first failure is
   returned: PHGMG_ERR_INVALID_ARG (NULL pointers, missing callbacks) / _SIZE /
   _NANINF / _NOT_SKEW / _NOT_SYMMETRIC (R or Q) / _NOT_PSD / _RANK / _SINGULAR,
   or _NOMEM. The system is never modified. */
PHGMG_DEF phgmg_result phgmg_ph_validate(const phgmg_ph_system *sys, double tol,
                                         double *rcond_out, const phgmg_allocator *alloc);

/* Hamiltonian, its gradient and the output at a state. These evaluators do
   not take an allocator: where they need a scratch vector of N doubles
   (gradient of a GENERAL part, rhs, output) it is on the stack for N <= 256
   and from the default allocator above; if that fails the result is NaN. */
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
   for applying G = (J - R)^{-1} without forming it. PHGMG_ERR_SINGULAR for an
   exactly zero pivot, PHGMG_ERR_NANINF, _NOMEM; rcond_out (may be NULL): the
   reciprocal 1-norm condition estimate. */
typedef struct phgmg_jr_factor phgmg_jr_factor;
PHGMG_DEF phgmg_result phgmg_jr_factor_create(phgmg_jr_factor **out, const phgmg_ph_system *sys,
                                              double *rcond_out, const phgmg_allocator *alloc);
/* X <- (J - R)^{-1} X (trans 'N') or (J - R)^{-T} X (trans 'T'); X is N x nrhs. */
PHGMG_DEF void phgmg_jr_solve(const phgmg_jr_factor *f, char trans, int nrhs, double *X, int ldx);
/* Frees the factorization (NULL is fine). */
PHGMG_DEF void phgmg_jr_factor_destroy(phgmg_jr_factor *f);

/* >>gl3 =================================================================== */
/* 3-stage Gauss-Legendre (order 6), simplified Newton on the transformed stage
   system (one real and one complex N x N solve per iteration), factorization
   reuse, extrapolated starting guess. For linear systems (nl == NONE) with a
   fixed step a precomputed step map is used unless opts.no_step_map.
   Details:
   - Newton iterates on Z_i = Y_i - x_n, always makes at least one update and
     stops when ||Z - h (A x I) F(Z)||_inf <= tol (absolute), at most max_iter
     updates. Jac = (J - R) Hess H(x_n), factored as gam/h I - Jac (real) and
     (alp - i bet)/h I - Jac (complex): dense LU, banded LU with lower/upper
     bandwidth from the nonzero diagonals of J - R and Q (plus kb for a GENERAL
     Hessian), or the caller's shifted_* callbacks. Factors are reused across
     steps; the next step refactors when the largest contraction rate
     res_{k+1}/res_k of a step exceeded opts.contraction. With factors from an
     earlier state a rising residual aborts at once and the step is retried
     once with fresh factors; with fresh factors two successive rises or
     max_iter give PHGMG_ERR_NOT_CONVERGED.
   - The starting guess extrapolates the previous step's collocation polynomial
     when the call continues the previous one (same x as it returned, t = its
     end time), else Z = 0.
   - Step map: nl == NONE, DENSE storage and N <= PHGMG_GL3_STEP_MAP_MAX_N
     (default 1000; 4 N^2 + 12 N m doubles, O(N^3) at create): x+ = Phi x +
     Gam [u_1; u_2; u_3] and the stage gradients by similar maps. A linear
     system otherwise factors once and converges in one update per step.
   - Stats: newton_iters counts updates (linear solves), rhs_evals counts
     evaluations of f at one state (3 per stage-system evaluation),
     factorizations counts (real + complex) factorization pairs, failures counts
     Newton attempts that failed (including ones a retry rescued) and steps that
     returned an error. */
#ifndef PHGMG_GL3_STEP_MAP_MAX_N
#define PHGMG_GL3_STEP_MAP_MAX_N 1000
#endif

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

/* A stepper object for one system and one step size (allocates once). The
   system's matrices are read at create (and, for callbacks and B, while
   stepping), so they must outlive the stepper. Checks sizes and arguments
   only (PHGMG_ERR_INVALID_ARG for dt <= 0 or bad options); call
   phgmg_ph_validate for the structure. */
typedef struct phgmg_gl3 phgmg_gl3;
PHGMG_DEF phgmg_result phgmg_gl3_create(phgmg_gl3 **out, const phgmg_ph_system *sys, double dt,
                                        const phgmg_gl3_opts *opts, const phgmg_allocator *alloc);
/* Frees the stepper (NULL is fine). */
PHGMG_DEF void phgmg_gl3_destroy(phgmg_gl3 *s);
/* One step from (t, x) to t + dt; x updated in place on success, untouched on
   failure (PHGMG_ERR_NOT_CONVERGED, PHGMG_ERR_NANINF, PHGMG_ERR_SINGULAR, or a
   shifted_factor code). u is evaluated at the stage times t + c_i dt; uf may be
   NULL (u = 0). energy_inc (may be NULL) receives {supplied, dissipated} over
   the step, at the stage values. */
PHGMG_DEF phgmg_result phgmg_gl3_step(phgmg_gl3 *s, double t, double *x, phgmg_input_fn uf,
                                      void *uuser, double energy_inc[2]);
/* Totals since create (see the details above). */
PHGMG_DEF const phgmg_gl3_stats *phgmg_gl3_get_stats(const phgmg_gl3 *s);

/* Simulate nsteps steps from x0 at t0 (t_n = t0 + n dt). Outputs (each may be NULL):
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
