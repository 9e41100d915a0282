
/* >>pod / >>reduce / >>deim / >>errors ====================================== */
/* Offline reduction (double). A user gives a pH system and a snapshot matrix
   X (N x ns, ns = n_t + 1 columns) and gets a reduced model that is again a
   pH system (see >>online), plus the error measures of the paper (5.1). */
#ifndef PHGMG_NO_OFFLINE
#ifdef __cplusplus
extern "C" {
#endif

/* POD: the leading left singular vectors of X (N x ns). k = kmax modes, or
   fewer: with tol > 0 only modes with sigma_k > tol * sigma_1 are kept.
   V: N x kmax (ldv), S: kmax singular values (may be NULL). *k_out = modes kept. */
PHGMG_DEF phgmg_result phgmg_pod(int N, int ns, const double *X, int ldx, int kmax, double tol,
                                 double *V, int ldv, double *S, int *k_out,
                                 const phgmg_allocator *alloc);
/* Adjusted snapshots Xa = X - B B^+ X (B: N x m full column rank). Xa may alias X. */
PHGMG_DEF phgmg_result phgmg_adjust_snapshots(int N, int m, const double *B, int ns, const double *X,
                                              int ldx, double *Xa, int ldxa, const phgmg_allocator *alloc);

typedef struct phgmg_reduce_opts {
  phgmg_method method; /* required                                                  */
  int r;               /* reduced order (GMG: includes the m port coordinates), required */
  int rn;              /* GMG-QM lifting dimension r_n (0: 8)                        */
  double lambda;       /* GMG-QM ridge parameter, applied to the un-normalised sum
                          over snapshots (0: 1e-3; < 0: exactly zero)                 */
  int deim;            /* separable nonlinear part: 1 = structure-preserving DEIM,
                          0 = keep every term (exact, but O(n_terms) online)          */
  double deim_tol;     /* DEIM modes: sigma_k / sigma_1 > deim_tol (0: 1e-8)          */
  int deim_max;        /* cap on DEIM modes (0: no cap)                               */
  int deim_allow_negative; /* 1: accept negative DEIM weights (reported in info)      */
  double dt;           /* > 0: precompute the GL3 step map for this step
                          (LINEAR map with quadratic H only)                          */
  double degeneracy_tol; /* fail with PHGMG_ERR_DEGENERATE when the reciprocal
                          condition of D^T G D at the snapshots is below this (0: 1e-12) */
  /* Optional cache for studies over many r: the leading left singular vectors
     (N x pod_cols, ld N, by descending singular value) of the matrix the
     method PODs -- GMG-POD/GMG-QM: the adjusted snapshots X - B B^+ X (from
     phgmg_adjust_snapshots + phgmg_pod); SP1/SP2: X itself. GMG-QM takes V1
     from its first r-m columns and V2 from the next r_n (the POD of the
     residual of V1 is exactly that tail). NULL: computed here. */
  const double *pod_basis;
  int pod_cols;
  const double *grad_basis; /* SP2: same for the gradient snapshots (NULL: computed) */
  int grad_cols;
  /* Optional DEIM result from phgmg_deim on the same snapshots (it does not
     depend on r or the method): term indices and weights. NULL: computed. */
  const int *deim_pts;
  const double *deim_w;
  int deim_count;
} phgmg_reduce_opts;

typedef struct phgmg_reduce_info {
  int deim_modes;          /* DEIM points kept (nd)                          */
  int deim_negative;       /* number of negative DEIM weights               */
  double deim_sigma_ratio; /* sigma_{nd+1}/sigma_1 of the nonlinear snapshots (0 if all kept) */
  double rcond_dgd;        /* smallest rcond of D^T G D seen (at x = 0 and the snapshots) */
  double rcond_jr;         /* rcond of J - R                                  */
  double pod_sigma_ratio;  /* sigma_{r'+1}/sigma_1 of the (adjusted) snapshots */
} phgmg_reduce_info;

/* The reduced model with its offline data (bases for reconstruction, double
   and phgmg_real copies of the small blocks). */
typedef struct phgmg_reduced phgmg_reduced;

/* Build a reduced model of `sys` from snapshots X (N x ns, ldx). The system must
   validate (phgmg_ph_validate); GENERAL nonlinear Hamiltonians are not supported
   (PHGMG_ERR_UNSUPPORTED); a separable nonlinear part needs the polynomial form
   (sys->poly) for the reduced model. Errors: PHGMG_ERR_SIZE (r <= m for GMG,
   r > rank of the snapshots, ...), PHGMG_ERR_RANK, PHGMG_ERR_DEGENERATE,
   PHGMG_ERR_NEGATIVE_WEIGHT, PHGMG_ERR_NANINF, PHGMG_ERR_NOMEM. info may be NULL. */
PHGMG_DEF phgmg_result phgmg_reduce(phgmg_reduced **out, const phgmg_ph_system *sys, const double *X,
                                    int ldx, int ns, const phgmg_reduce_opts *opts,
                                    phgmg_reduce_info *info, const phgmg_allocator *alloc);
PHGMG_DEF void phgmg_reduced_destroy(phgmg_reduced *red);
/* The online model (views into the reduced object; valid until destroy). */
PHGMG_DEF const phgmg_rom *phgmg_reduced_rom(const phgmg_reduced *red);
/* Offline double copy of the same model (identical layout, double arrays). */
PHGMG_DEF int phgmg_reduced_N(const phgmg_reduced *red);
/* Reconstruction x = phi(xr) (N). */
PHGMG_DEF void phgmg_reduced_lift(const phgmg_reduced *red, const double *xr, double *x);
/* Point reduction xr = rho(x) (r); rho(phi(xr)) = xr. */
PHGMG_DEF void phgmg_reduced_restrict(const phgmg_reduced *red, const double *x, double *xr);
/* Jacobian of phi at xr: D (N x r, ldd). */
PHGMG_DEF void phgmg_reduced_dphi(const phgmg_reduced *red, const double *xr, double *D, int ldd);
/* The reduction map W(xr) (N x r, ldw) in full dimension (for checks; O(N r^2)). */
PHGMG_DEF phgmg_result phgmg_reduced_W(const phgmg_reduced *red, const double *xr, double *W, int ldw);

/* Simulate the reduced model with the online GL3 stepper from xr0 over nsteps
   steps of dt (u from uf at the stage times). Outputs (each may be NULL):
   XR r x (nsteps+1), Y m x (nsteps+1), energy like phgmg_simulate (Hamiltonian
   of the reduced model). tol/max_iter: Newton settings (<= 0: defaults). */
PHGMG_DEF phgmg_result phgmg_reduced_simulate(const phgmg_reduced *red, const double *xr0, double t0,
                                              double dt, int nsteps, phgmg_input_fn uf, void *uuser,
                                              double tol, int max_iter, double *XR, double *Y,
                                              const phgmg_energy *energy, phgmg_rom_stats *stats,
                                              const phgmg_allocator *alloc);

/* --- error measures (paper 5.1) --- */
/* sqrt(sum_i ||A_i - B_i||^2 / sum_i ||A_i||^2) over ns columns of length n. */
PHGMG_DEF double phgmg_rel_error(int n, int ns, const double *A, int lda, const double *B, int ldb);
/* e_red: reduction error of a reduced trajectory XR (r x ns) against X. */
PHGMG_DEF double phgmg_err_red(const phgmg_reduced *red, const double *X, int ldx, int ns,
                               const double *XR, int ldxr);
/* e_proj: projection error sqrt(sum ||x_i - phi(rho(x_i))||^2 / sum ||x_i||^2). */
PHGMG_DEF double phgmg_err_proj(const phgmg_reduced *red, const double *X, int ldx, int ns);
/* e_lowerbound (eq. non_app_lower_bound) of a GMG-QM model: the error of the
   orthogonal projection onto span[B, V1, V2]. NaN for other kinds. */
PHGMG_DEF double phgmg_err_lowerbound(const phgmg_reduced *red, const double *X, int ldx, int ns);
/* e_energy(t_n) = |H[n] - H[0] - S[n] + D[n]| for n = 0..nsteps into e. */
PHGMG_DEF void phgmg_err_energy(const phgmg_energy *energy, int nsteps, double *e);

/* Hierarchical POD of paper 4.2.2: V1 = POD_p(X - BB^+X), V2 = POD_rn of the
   residual (I - [B,V1][B,V1]^+) X. V1: N x p, V2: N x rn. */
PHGMG_DEF phgmg_result phgmg_pod_hierarchical(int N, int m, const double *B, int ns, const double *X,
                                              int ldx, int p, int rn, double *V1, double *V2,
                                              const phgmg_allocator *alloc);

/* Structure-preserving DEIM for a separable sum: F (nterms x ns) holds the
   snapshots of the nonlinear gradient terms phi_k'(x_idx_k). Modes: sigma_k >
   tol sigma_1 (capped by kmax if > 0). Points by Q-DEIM (pivoted QR of U^T).
   Weights w = (P^T U)^{-T} U^T sw (sw = the terms' own weights, NULL = 1), so
   sum_k sw_k phi_k ~ sum_j w_j phi_{pts_j}. pts, w: room for nterms entries.
   *nd_out = points chosen, *nneg = negative weights. */
PHGMG_DEF phgmg_result phgmg_deim(int nterms, int ns, const double *F, int ldf, const double *sw,
                                  double tol, int kmax, int *pts, double *w, int *nd_out,
                                  int *nneg, double *sigma_ratio, const phgmg_allocator *alloc);

#ifdef __cplusplus
}
#endif
#endif /* PHGMG_NO_OFFLINE */
