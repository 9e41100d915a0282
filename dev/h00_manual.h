/* phgmg.h — structure-preserving model order reduction of port-Hamiltonian
   systems by generalized manifold Galerkin (GMG) reduction.
   Single-file C99 library (also compiles as C++), no dependencies beyond libc
   and libm. MIT license at the end of the file.

   Method: Glas & Mu, "Structure-Preserving Generalized Manifold Galerkin
   Reduction for Port-Hamiltonian Systems". A pH system
       x' = (J - R) grad H(x) + B u,   y = B^T grad H(x)
   is reduced with an approximation map phi (linear [B, Vbar] or a quadratic
   manifold) and the GMG reduction map W(xr) = F_G(Dphi(xr))^T, G = (J-R)^{-1};
   the reduced model is again a pH system, with the same output structure.

   QUICK START ----------------------------------------------------------------
       #define PHGMG_IMPLEMENTATION      // in exactly one .c file
       #include "phgmg.h"

       phgmg_ph_system sys = {0};        // N, m, J, R, Q, B (column-major)
       ... fill sys ...
       phgmg_simulate(&sys, x0, 0.0, dt, nsteps, u_fn, NULL, NULL, X, Y, NULL, NULL, NULL, NULL);
       phgmg_reduce_opts o = {0};  o.method = PHGMG_METHOD_GMG_POD;  o.r = 12;  o.dt = dt;
       phgmg_reduced *red;  phgmg_reduce(&red, &sys, X, N, nsteps + 1, &o, NULL, NULL);
       // online, allocation-free, float or double:
       const phgmg_rom *rom = phgmg_reduced_rom(red);
       phgmg_rom_stepper st;  static double mem[4096];
       phgmg_rom_stepper_init(&st, rom, dt, 0, 0, mem, sizeof mem);
       phgmg_rom_step(&st, xr, u3, y, NULL);      // u3 = u at the 3 stage times
       phgmg_rom_export_c(rom, "my_model", "my_model.h");  // for firmware

   CONTENTS (grep for the >>markers; same order in both halves) ---------------
     >>config   configuration macros, version, scalar type
     >>result   phgmg_result codes and phgmg_result_string
     >>memory   allocator hooks, matrix views
     >>linalg   dense kernels: GEMM, LU (real, complex), QR, QRCP, least squares,
                thin SVD (QRCP + one-sided Jacobi), symmetric eigenvalues
     >>ph       full-order pH systems: dense/banded storage, separable or general
                nonlinear Hamiltonians, validation, J-R factorization
     >>gl3      3-stage Gauss-Legendre (order 6) + simplified Newton, energy bookkeeping
     >>online   reduced models (phgmg_rom), evaluation, allocation-free GL3 stepper
     >>pod, >>reduce, >>deim, >>errors   POD, GMG-POD, GMG-QM, SP1, SP2, DEIM, error measures
     >>export   C-source and binary export/import of reduced models
     >>npy      NumPy .npy read/write

   CONFIGURATION MACROS (define before including) ------------------------------
     PHGMG_IMPLEMENTATION  compile the implementation in this translation unit
     PHGMG_STATIC          all functions static (private copy per translation unit)
     PHGMG_DEF             storage class of the public functions (default extern)
     PHGMG_REAL_FLOAT      online scalar phgmg_real = float (default double);
                           the offline half stays double
     PHGMG_NO_OFFLINE      compile only the online half (+ export/import in memory):
                           needs libm only, no heap, no stdio
     PHGMG_NO_STDIO        no file functions (.npy files, model files, C export)
     PHGMG_NPY_MAX_HEADER  longest accepted .npy header in bytes (default 1 MiB)
     PHGMG_MALLOC(sz,u) / PHGMG_FREE(p,u)   default allocator (both or neither)
     PHGMG_ASSERT(x)       internal invariant checks (default assert)
     PHGMG_USE_CBLAS       use cblas_dgemm/cblas_dgemv (optional speed-up)

   FUNCTIONS (one line each; full comments at the declarations) ---------------
   core:    phgmg_result_string
   linalg:  phgmg_gemm, phgmg_gemv, phgmg_lu_factor, phgmg_lu_solve, phgmg_lu_rcond,
            phgmg_norm1, phgmg_normf, phgmg_zlu_factor, phgmg_zlu_solve, phgmg_qr,
            phgmg_qrcp, phgmg_qr_form_q, phgmg_qr_apply, phgmg_lstsq (plain/ridge),
            phgmg_svd (thin, rank-revealing), phgmg_sym_eig
   ph:      phgmg_ph_validate (skew J, symmetric PSD R, rank B, cond(J-R), NaN),
            phgmg_ph_hamiltonian, phgmg_ph_gradient, phgmg_ph_rhs, phgmg_ph_output,
            phgmg_ph_apply (J, R or Q times a block), phgmg_jr_factor_create /
            phgmg_jr_solve / phgmg_jr_factor_destroy (apply (J-R)^{-1} or ^{-T})
   gl3:     phgmg_gl3_coefficients, phgmg_gl3_create / _step / _get_stats / _destroy,
            phgmg_simulate (trajectory, outputs, energy H/S/D, stats)
   online:  phgmg_rom_check, phgmg_rom_eval_work_size, phgmg_rom_hamiltonian,
            phgmg_rom_gradient, phgmg_rom_rhs, phgmg_rom_output, phgmg_rom_structure
            (J and R at a state), phgmg_rom_jacobian, phgmg_rom_stepper_memsize,
            PHGMG_ROM_STEPPER_MEMSIZE_MAX, phgmg_rom_stepper_init, phgmg_rom_stepper_reset,
            phgmg_rom_stage_times, phgmg_rom_step
   reduce:  phgmg_pod, phgmg_adjust_snapshots, phgmg_pod_hierarchical, phgmg_deim,
            phgmg_reduce, phgmg_reduced_destroy, phgmg_reduced_rom, phgmg_reduced_N,
            phgmg_reduced_lift (phi), phgmg_reduced_restrict (rho), phgmg_reduced_dphi,
            phgmg_reduced_W, phgmg_reduced_simulate
   errors:  phgmg_rel_error, phgmg_err_red, phgmg_err_proj, phgmg_err_lowerbound,
            phgmg_err_energy
   export:  phgmg_rom_serialized_size, phgmg_rom_serialize, phgmg_rom_deserialize_size,
            phgmg_rom_deserialize, phgmg_rom_save, phgmg_rom_load, phgmg_rom_export_c
   npy:     phgmg_npy_parse, phgmg_npy_serialize, phgmg_npy_free, phgmg_npy_read,
            phgmg_npy_write

   OFFLINE / ONLINE, MEMORY, ERRORS -------------------------------------------
   Offline functions (double) take a `const phgmg_allocator *` (NULL = default)
   and free everything on every error path. The online half (phgmg_rom_*) never
   allocates: ask phgmg_rom_stepper_memsize (or use the compile-time bound
   PHGMG_ROM_STEPPER_MEMSIZE_MAX), hand over the memory, step; instances are
   independent. Its cost does not depend on N. Every data-dependent failure is
   a negative phgmg_result; on failure the caller's inputs (and the state of a
   stepper) are unchanged. The library never prints, exits or aborts.
*/
