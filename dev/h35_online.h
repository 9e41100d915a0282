
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

/* Bytes of caller memory phgmg_rom_stepper_init needs for this model, stepped
   with its own step (rom->dt) -- small when the model carries a step map. */
PHGMG_DEF size_t phgmg_rom_stepper_memsize(const phgmg_rom *rom);
/* The same for stepping with dt (a model with a step map for another dt
   needs the Newton workspace). */
PHGMG_DEF size_t phgmg_rom_stepper_memsize_dt(const phgmg_rom *rom, phgmg_real dt);
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
