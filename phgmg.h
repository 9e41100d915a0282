/* phgmg.h -- structure-preserving model order reduction of port-Hamiltonian
   systems by generalized manifold Galerkin (GMG) reduction. Version 0.5.0.
   Single-file C99 library (also compiles as C++), no dependencies beyond libc
   and libm. The revision history and the MIT license are at the end of the
   file.

   Method: Glas & Mu, "Structure-Preserving Generalized Manifold Galerkin
   Reduction for Port-Hamiltonian Systems". A pH system
       x' = (J - R) grad H(x) + B u,   y = B^T grad H(x)
   is reduced with an approximation map phi (linear [B, Vbar] or a quadratic
   manifold) and the GMG reduction map W(xr) = F_G(Dphi(xr))^T, G = (J-R)^{-1};
   the reduced model is again a pH system, with the same output structure.

   MANUAL ======================================================================
     0. Quick start
     1. Concepts and model forms
     2. The offline pipeline
     3. Methods and options (with every default)
     4. Deployment: validation, choosing lambda, online indicators
     5. The online path and firmware
     6. The command line
     7. Errors
     8. Numerical notes: what the paper leaves open and what phgmg decided
     9. Configuration macros
    10. Index of public functions
   The header has two halves, declarations and implementation, each cut into
   sections marked >>config, >>result, >>memory, >>ph, >>dae, >>sparse, >>gl3,
   >>online, >>pod, >>hyper, >>reduce, >>deploy, >>errors, >>study, >>linear,
   >>export, >>npy and, last, >>linalg, the dense kernels (grep for them; the
   same order in both halves: the implementation declares the kernels' private
   helpers in >>linalg (prototypes) after >>memory, and its >>reduce opens with
   the reduced object the others use). The comment at each declaration states
   its contract: what it computes, units and layouts, result codes. The
   reduction methods, the GMG-QM manifold constructions and the
   hyper-reduction kinds are each described once, in a table the pipeline
   reads (phgmg__methods, phgmg__manifolds, phgmg__hypers in the
   implementation's >>reduce): a new one is a row there and its stage
   functions.


   0. QUICK START ---------------------------------------------------------------
   In exactly one .c file:
       #define PHGMG_IMPLEMENTATION
       #include "phgmg.h"
   elsewhere include "phgmg.h" plainly (or use PHGMG_STATIC for a private copy).
   Link with -lm. A complete program is examples/hello.c (also the quick start
   of README.md); in outline:

       phgmg_ph_system sys;  memset(&sys, 0, sizeof sys);  // zero: defaults
       sys.N = N; sys.m = 1; sys.J = J; sys.R = R; sys.Q = Q; sys.B = B;
       phgmg_simulate(&sys, x0, 0.0, dt, nsteps, u_fn, NULL, NULL, X, Y,
                      NULL, NULL, NULL, NULL);             // snapshots X
       phgmg_reduce_opts o;  memset(&o, 0, sizeof o);
       o.method = PHGMG_METHOD_GMG_POD;  o.r = 10;  o.dt = dt;
       phgmg_reduced *red;
       phgmg_reduce(&red, &sys, X, N, nsteps + 1, &o, NULL, NULL);
       // online, allocation-free, float or double:
       phgmg_rom_stepper st;  static double mem[8192];
       phgmg_rom_stepper_init(&st, phgmg_reduced_rom(red), dt, 0, 0, mem, sizeof mem);
       phgmg_rom_step(&st, xr, u3, y, NULL);      // u3 = u at the 3 stage times
       phgmg_rom_export_c(phgmg_reduced_rom(red), "plant", "plant.h");  // firmware


   1. CONCEPTS AND MODEL FORMS --------------------------------------------------
   1.1 The full model (phgmg_ph_system, >>ph)
       x' = (J - R) grad H(x) + B u(t),   y = B^T grad H(x),
       H(x) = 1/2 x^T Q x + H_nl(x),
   J skew-symmetric, R symmetric positive semidefinite, Q symmetric positive
   definite (only semidefinite when H_nl is present: the nonlinear part may
   carry the convexity, e.g. a Toda chain), B (N x m) of full column rank,
   J - R regular. All matrices are column-major. Storage:
     DENSE   J, R, Q N x N (ld N);
     BANDED  J, R, Q with a common half-bandwidth kb, (2kb+1) x N;
     sparse  J, R, Q as CSC in any ordering: phgmg_ph_sparse_create reorders
             the states by reverse Cuthill-McKee into a band and gives the
             banded system; snapshots and full-dimension results are mapped
             with phgmg_ph_sparse_to_banded_order / _to_user_order.
   The nonlinear part H_nl (field nl):
     PHGMG_NL_NONE       quadratic H;
     PHGMG_NL_SEPARABLE  H_nl(x) = sum_k w_k phi_k(x[idx_k]) (nsep terms),
                         phi_k either from the built-in exp-polynomial family
                         phi(s) = sum_j c_j s^j + sum_e a_e exp(b_e s)
                         (degree <= 32, at most 8 exponentials; one function
                         for all terms or one per term; covers polynomial/FPU,
                         Toda, cosh, Morse), or from callbacks phi/dphi/ddphi;
     PHGMG_NL_GENERAL    H_nl, its gradient and Hessian by callbacks.
   phgmg_ph_validate checks all of this (section 7 lists the codes); every
   reduction calls it first. A model may bring its own solver for the shifted
   Newton matrices of the GL3 stepper (shifted_factor / shifted_solve).

   1.2 Snapshots and runs
   A snapshot matrix X is N x ns (column-major, ld >= N), one state per column,
   normally a trajectory x(t_0), ..., x(t_n) from phgmg_simulate (ns = n + 1).
   Several training runs lie one after the other; phgmg_run describes one run
   (input, x0, t0, dt, nsteps), phgmg_simulate_inputs makes the snapshot set,
   phgmg_runs_columns counts its columns, and phgmg_reduce_opts.runs tells the
   reduction where the runs are and how they were made.

   1.3 The reduced model
   phgmg_reduce returns a phgmg_reduced: the online model (phgmg_rom, below)
   together with its offline data (bases, double copies). The reduced model is
       xr' = (Jr(xr) - Rr(xr)) grad Hr(xr) + Br u,   yr = Br^T grad Hr(xr),
   Jr skew, Rr symmetric positive semidefinite, with Br = [I; 0] for the GMG
   methods (the first m reduced coordinates are the port coordinates).
   phgmg_reduced_lift is phi (reduced -> full state), phgmg_reduced_restrict
   is the point reduction rho (rho(phi(xr)) = xr), phgmg_reduced_dphi its
   Jacobian, phgmg_reduced_W the reduction map. The online model phgmg_rom is a
   set of non-owning const views of small precomputed blocks (V0^T G V0, ...),
   so evaluating and stepping it never touches N-dimensional data (except a
   GENERAL nonlinear part, see 3.4).

   1.4 Error measures (phgmg_err_*, paper Section 5.1)
     e_red        sqrt(sum_i ||x_i - phi(xr_i)||^2 / sum_i ||x_i||^2), reduced
                  trajectory against the full one (phgmg_err_red);
     e_y          the same relative measure for the outputs (phgmg_rel_error);
     e_proj       sqrt(sum ||x_i - phi(rho(x_i))||^2 / sum ||x_i||^2): how well
                  the manifold represents the snapshots (phgmg_err_proj);
     e_lowerbound the orthogonal projection error onto span[B, V1, V2] of a
                  quadratic manifold (phgmg_err_lowerbound);
     e_energy(t_n) = |H_n - H_0 - S_n + D_n|, with the supplied (S) and
                  dissipated (D) energy summed by the stepper's own stage
                  quadrature (phgmg_energy, phgmg_err_energy).

   1.5 Offline and online
   The offline half (simulation, reduction, studies, linear methods, .npy,
   files) works in double, takes a `const phgmg_allocator *` (NULL: malloc/free
   or PHGMG_MALLOC/PHGMG_FREE) and frees everything on every error path. The
   online half (phgmg_rom_*) works in phgmg_real (double, or float with
   PHGMG_REAL_FLOAT), never allocates, uses no globals, no stdio and no VLAs;
   its cost does not depend on N. Instances are independent.


   1.6 Descriptor models and feedthrough (phgmg_ph_system.E, P, S, Nskew)
   Finite-element and network models come as
       E x' = (J - R) z(x) + B u,   y = B^T z(x),   E^T z(x) = grad H(x),
   E nonsingular (a consistent mass matrix, dense or banded like J, R, Q).
   phgmg takes z(x) = Q x + grad H_nl(x) (Q, the separable part as usual) and
   H(x) = 1/2 x^T E^T Q x + sum_k E(i_k,i_k) w_k phi_k(x[i_k]); E^T Q must be
   symmetric positive (semi)definite and E's rows at the nonlinear coordinates
   unit rows times E(i_k,i_k) > 0, so that E^T z is the gradient of this H.
   Energy: dH/dt = z^T E x' = -z^T R z + y^T u.
   Simulation: Gauss-Legendre with the mass matrix -- stage equations
   E (Y_i - x_n) = h sum_j a_ij f(Y_j), Newton matrices sigma E - (J - R) Hess,
   x_{n+1} = x_n + sum_i d_i (Y_i - x_n), d = b^T A^{-1}; E^{-1} is never
   formed. GL3 commutes with the linear change of variables x~ = E x, so this is
   the same scheme as on the standard form, and the energy bookkeeping (stage
   co-states z(Y_i)) keeps its meaning: H_n - H_0 = S_n - D_n to round-off for
   a quadratic H.
   Reduction. In x the model is a standard pH system,
       x' = (J_E - R_E) grad H(x) + B_E u,  J_E = E^{-1} J E^{-T}, R_E =
       E^{-1} R E^{-T}, B_E = E^{-1} B,  y = B_E^T grad H(x),
   (J_E skew, R_E PSD: congruences), with G_E = (J_E - R_E)^{-1} = E^T G E,
   G = (J - R)^{-1}. Every method is applied to this system without forming
   it; only m solves with E (B_E) and products with E are needed:
   - GMG (POD, QM, your manifold): phi(x) = [B_E, V] x (+ V2 eta), V from the
     POD of X - B_E B_E^+ X. The GMG map W^T = (D^T G_E D)^{-1} D^T G_E gives
       x' = (D^T G_E D)^{-1} grad Hr(x) + W^T B_E u,   Hr = H o phi,
     with D^T G_E D = (E D)^T G (E D): the G-blocks are those of today with
     E V0, E V2 in place of V0, V2 (solves with J - R only); the Q-blocks
     V0^T E^T Q V0 = (E V0)^T (Q V0), ...; the separable weights become
     E(i_k,i_k) w_k. W^T B_E = (D^T G_E D)^{-1} (E D)^T G B = [I; 0] because
     E D's first m columns are B: the port structure and the output
     yr = Bh^T grad Hr = B^T z(phi(xr)) (exact at the lifted state) are kept.
     In terms of the descriptor equation this is the Petrov-Galerkin
     projection with the co-state test basis W_z = E^{-T} W:
       W_z^T E D xr' = W_z^T [(J - R) z(phi(xr)) + B u],   W_z^T E D = I,
     so the reduced mass matrix is the identity and the reduced model is the
     library's standard reduced form (phgmg_rom): export, binary files and the
     allocation-free stepper are unchanged.
   - SP1: V = POD of X, Hess H = E^T Q, W = E^T Q V (V^T E^T Q V)^{-1}; with
     W_z = E^{-T} W = Q V (V^T E^T Q V)^{-1} (no solve): K = W_z^T (J - R) W_z,
     Bh = W_z^T B, Qh = V^T E^T Q V; again W_z^T E V = I. SP2: the gradient
     snapshots are grad H(x_j) = E^T z(x_j); W_z = E^{-T} W by r solves.
   Why the reduced model is port-Hamiltonian: K = W_z^T (J - R) W_z (for GMG
   this equals (D^T G_E D)^{-1} = W^T (J_E - R_E) W), so its symmetric part
   -W_z^T R W_z is negative semidefinite and its skew part W_z^T J W_z skew;
   Hr(xr) = H(phi(xr)) is its energy (Qh = D^T E^T Q D, positive definite when
   E^T Q is and D has full rank), and dHr/dt = -grad Hr^T Rr grad Hr + yr^T u
   with the same output structure. tests/test_descriptor.c checks each claim
   against the reduction of the explicitly formed J_E, R_E, Q_E = E^T Q, B_E
   and against the closed forms above.
   Not for descriptor models (PHGMG_ERR_UNSUPPORTED): a GENERAL nonlinear part,
   the shifted_* callbacks, the linear-systems toolbox (BT, PRBT, Gramian
   bases, phgmg_ph_abc) and studies. Singular E (algebraic constraints of
   index one) is the subject of 1.8, nonlinear dissipation of 1.7. Feedthrough (phgmg_ph_system.P,
   S, Nskew: E x' = (J - R) z + (B - P) u, y = (B + P)^T z + (S + N) u) is
   taken by the full model -- validation of [[R, P], [P^T, S]] >= 0 and N
   skew (PHGMG_ERR_FEEDTHROUGH), the stepper, outputs, and the energy
   balance with supply y^T u and dissipation [z; u]^T [[R, P], [P^T, S]]
   [z; u] -- and by GMG-POD, SP1 and SP2 (GMG-QM and your manifold:
   PHGMG_ERR_UNSUPPORTED). The reduced model, with z^ = W_z grad Hr as the
   co-state (1.7), is
       xr' = K grad Hr + (Bh - Ph) u,  y = (Bh + Ph)^T grad Hr + (S + N) u,
       Ph = W_z^T P,  Bh = W_z^T B,  phgmg_rom.PD = [Ph; S + N],
   its dissipation block [[Rr, Ph], [Ph^T, S]] = diag(W_z, I)^T [[R, P],
   [P^T, S]] diag(W_z, I) (Rr = W_z^T R W_z = -sym K) is positive
   semidefinite by congruence, and dHr/dt = yr^T u - [g; u]^T [[Rr, Ph],
   [Ph^T, S]] [g; u], g = grad Hr; the online stepper sums this dissipation
   and the supply yr^T u at its stages (the balance as in 1.7). The online
   output functions have no u: phgmg_rom_output and the stepper's y give
   (Bh + Ph)^T grad Hr, the caller adds (S + N) u(t) (phgmg_reduced_simulate
   and the command line do). Model files (format version 3, field PD) check
   the block on load (PHGMG_ERR_STRUCTURE); no step map with feedthrough.

   1.7 Nonlinear dissipation (phgmg_ph_system.ndamp, damp_*)
   Dampers r(z) = sum_k c_k rho_k(c_k^T z), c_k = e_i - e_j (a damper between
   two co-state components, e.g. two velocities) or e_i (one component):
       E x' = (J - R) z - r(z) + B u,   y = B^T z,
       dH/dt = z^T E x' = -z^T R z - sum_k s_k rho_k(s_k) + y^T u,  s_k = c_k^T z.
   The model dissipates iff s rho_k(s) >= 0 for every s. Laws: an odd
   polynomial sum_d a_d s^d with every a_d >= 0 (a linear plus cubic damper
   c1 s + c3 s^3 is damp_deg = 3, damp_poly = {0, c1, 0, c3}), checked when
   the model is validated; or a callback (smooth friction a tanh(b s), ...),
   whose sign is checked wherever it is evaluated. A law that generates
   energy (c1 < 0, c3 < 0, an even or constant term, a callback with
   s rho(s) < 0) is PHGMG_ERR_DAMPER. Example: a chain with cubic dampers on
   the velocities v_k = p_k / m_k (state index n + k): ndamp = n, damp_i[k]
   = n + k, damp_j = NULL, damp_deg = 3, damp_poly = {0, 0.2, 0, 3}
   (tests/test_dissip.c).
   Full model. GL3 with the dampers in the stage right-hand sides
   F_i = (J - R) z_i - r(z_i) + B u_i, z_i = z(Y_i); the simplified-Newton
   matrices take the slopes rho_k' at the factorization point,
   sigma E - (J - R - sum_k rho_k'(s_k) c_k c_k^T) Hess (dense or banded;
   the sparse stage LU and the linear step map are not used with dampers).
   Discrete energy balance: GL3 is the collocation method of the cubic p with
   p(t_n) = x_n, E p'(t_n + c_i h) = F_i. For a quadratic H,
   H(p(t))' = z(p)^T E p' is a polynomial of degree 5, integrated exactly by
   the three-point Gauss rule, so
       H(x_{n+1}) - H(x_n) = h sum_i b_i z_i^T F_i
                           = h sum_i b_i (y_i^T u_i - z_i^T R z_i - sum_k s_ik rho_k(s_ik)),
   s_ik = c_k^T z_i: the balance H_n - H_0 = S_n - D_n holds to round-off and
   the Newton tolerance whatever rho is (with E the stage residuals enter
   x_{n+1} through d = b^T A^{-1}, entries up to about 10: a tolerance of
   1e-13 gives 1e-12 over hundreds of steps, the default 1e-10 about 1e-9), where D sums the dampers' stage
   quadrature h sum_i b_i s_ik rho_k(s_ik) with that of R (phgmg_energy.D,
   energy_inc[1]). For a non-quadratic H it holds up to the error of the
   Gauss rule on H(p(t))'.
   Reduction (GMG-POD, SP1, SP2; GMG-QM and your manifold are
   PHGMG_ERR_UNSUPPORTED). With the co-state test basis W_z of 1.6 (E = I:
   W_z = W) the reduced model replaces the co-state by z^ = W_z grad Hr(xr):
       xr' = W_z^T (J - R) z^ - W_z^T r(z^) + Bh u
           = K grad Hr - sum_k Cd_k rho_k(Cd_k^T grad Hr) + Bh u,
       Cd_k = W_z^T c_k  (phgmg_rom.Cd, r x ndamp),   K = W_z^T (J - R) W_z,
   so dHr/dt = -z^^T R z^ - sum_k s^_k rho_k(s^_k) + yr^T u with
   s^_k = c_k^T z^ = Cd_k^T grad Hr: the reduced dampers are the full ones
   evaluated at the reduced co-state, each dissipative for every argument,
   and the reduced model is again port-Hamiltonian with the same laws. The
   reduced stepper is GL3 again: the discrete balance above holds for it with
   Hr (to round-off for a quadratic Hr, e.g. GMG-POD or SP1 of a quadratic
   H). Which W: SP1/SP2 as in 1.6. GMG needs a regular G; it takes
   G = (J - R - L)^{-1}, L = sum_k rho_k'(0) c_k c_k^T (rho_k'(0) >= 0 for a
   dissipative law), the linearisation of the dampers at rest: any regular G
   gives W^T D = I and Bh = [I; 0]; this one makes linear dampers
   (rho = c1 s) reproduce exactly the GMG-POD model of the linear system with
   R + L, and keeps G regular when all the damping is in the dampers. Then
   W_z^T = (D^T G_E D)^{-1} (E D)^T G and the stored K = (D^T G_E D)^{-1} +
   sum_k rho_k'(0) Cd_k Cd_k^T = W_z^T (J - R) W_z (offline: r transposed
   solves with J - R - L and O(N r^2) work).
   Online cost and hyper-reduction. Each evaluation costs O(ndamp r): free of
   N, but every damper is kept, so a model with a damper at every node has an
   O(N) online cost. opts.hyper.on = 1 hyper-reduces the dampers by empirical
   quadrature (phgmg_ecsw_separable, tolerance hyper.tol; always ECSW,
   whatever hyper.kind says): weights dw_k >= 0 on a subset of the dampers
   such that sum_k dw_k Cd_k rho_k(s_k) matches sum_k Cd_k rho_k(s_k) on the
   training forces, s_k = c_k^T z(x_j) at the snapshots. Non-negative weights
   keep every kept term dissipative, so the hyper-reduced model is
   port-Hamiltonian too.
   Not for damper models: model files and C export of a model
   with callback laws (PHGMG_ERR_UNSUPPORTED; polynomial laws are saved,
   format version 3, and exported), the step map, the studies' fast path
   (phgmg_study_reduce computes the blocks afresh).
   tests/test_dissip.c checks each claim: the full balance to 1e-11 H (and
   that it fails without the dampers' term; with a coupled mass matrix too),
   dense = banded stepper, linear
   dampers = the linear model with R + L (full and reduced, GMG-POD and SP1),
   Cd against phgmg_reduced_W, sampled s rho(s) >= 0 and g^T f <= 0 of the
   reduced model, the reduced balance, the output error falling with r, and
   the codes of energy-generating dampers.

   1.8 Algebraic constraints: singular E of index one (phgmg_dae_*)
   Circuit and network tools write Kirchhoff constraints, finite-element
   codes massless nodes, as equations without a time derivative: E has k
   zero rows (the algebraic equations, row set a) and k zero columns (the
   algebraic variables, column set c; often a = c), in any ordering. A dense
   E that is singular without zero lines (H quadratic, no dampers) is first
   brought to this form by orthogonal changes of coordinates: Qu, Qv with
   the ranges of E and E^T first (from the SVD of E; rank: singular values
   above tol times the largest), E_t = Qu^T E Qv, J_t = Qu^T J Qu, R_t =
   Qu^T R Qu, Q_t = Qu^T Q Qv, B_t = Qu^T B, P_t = Qu^T P -- a congruence,
   so the structure and E^T Q's properties are kept -- and the differential
   state is xi = (Qv^T x)[0..n). Other singular E (banded or sparse without
   zero lines, or with a nonlinear part): PHGMG_ERR_E_SINGULAR. With d the
   other rows and columns,
   E_dd nonsingular, L = J - R, G = B - P, F = B + P, z = Q x + grad H_nl:
       E_dd x_d' = L_dd z_d + L_da z_a + G_d u,     (differential)
             0   = L_ad z_d + L_aa z_a + G_a u,     (algebraic)
       z_a = Q_ad x_d + Q_ac x_c.
   E^T Q symmetric with E[:, c] = 0 forces Q_dc = 0 (the kept co-states do not
   depend on x_c: checked, PHGMG_ERR_EQ_NOT_SYMMETRIC); a separable term or
   a damper on an algebraic line is not supported. Index. The pencil
   s E - L Q is regular of index one exactly when L_aa and Q_ac are
   nonsingular (1 / ||L_aa^{-1}||_1 > tol max|L|, the same for Q_ac against
   max|Q|: a block small only by round-off counts as singular): then the
   algebraic equation fixes z_a, and z_a
   fixes x_c. Otherwise phgmg evaluates det(s E - L Q) at two unrelated s:
   nonzero at one of them means a regular pencil of index two or more
   (PHGMG_ERR_INDEX: e.g. a massless undamped node, whose constraint acts on
   positions), zero at both a singular pencil (PHGMG_ERR_PENCIL: the model
   does not determine its solution).
   Condensation. Eliminating z_a = -L_aa^{-1} (L_ad z_d + G_a u) gives a
   port-Hamiltonian ODE in x_d with nonsingular E_dd, co-state z_d and
       L' = L_dd - L_da L_aa^{-1} L_ad,   G' = G_d - L_da L_aa^{-1} G_a,
       F' = F_d - L_ad^T L_aa^{-T} F_a,   (S + N)' = S + N - F_a^T L_aa^{-1} G_a,
   read as J' = skew L', R' = -sym L', B' = (G' + F')/2, P' = (F' - G')/2,
   S' = sym (S + N)', N' = skew (S + N)'. Why it is port-Hamiltonian: the
   system matrix K = [[L, G], [-F^T, -(S + N)]] maps (z, u) to (E x', -y) and
   has the symmetric part -[[R, P], [P^T, S]] <= 0; the condensed K' is its
   Schur complement on the block L_aa, and for any w, with v = (w, z_a)
   completed by the algebraic equation, K v = (K' w, 0), so w^T K' w =
   v^T K v <= 0: the condensed dissipation block is positive semidefinite,
   and at consistent states it dissipates exactly what the full one does.
   The Hamiltonian H(x) = 1/2 x^T E^T Q x + ... does not depend on x_c
   (E^T Q x_c-columns vanish), so H restricted to x_d is the condensed
   model's energy and the outputs are the same. A port on an algebraic row
   becomes feedthrough (a resistor between the port and the constraint:
   S' > 0); a constraint away from the ports changes J and R only.
   phgmg_dae_create builds the condensed model (dense or banded like the
   input; the update is confined to the neighbours of the algebraic lines),
   phgmg_dae_lift recovers the algebraic variables (x_c = Q_ac^{-1} (z_a -
   Q_ad x_d)), phgmg_dae_restrict takes x_d.
   Simulation (phgmg_simulate; the command line's simulate and reduce
   --simulate): the scheme is Gauss-Legendre collocation of the DAE itself,
   its stage equations enforce the constraints at the stages, and the
   algebraic variables at t_{n+1} are taken from the constraints at
   t_{n+1} (the collocation polynomial's end value of an algebraic variable
   is not consistent: the Gauss methods' stability function is -1 at
   infinity). That is the same as GL3 on the condensed ODE followed by the
   lift, which is how it is computed: consistent states at every step (x0's
   algebraic part is replaced by the consistent one), the discrete energy
   balance of 1.7 (exact for a quadratic H: the lift changes only x_c, on
   which H does not depend). Reduction: reduce the condensed model,
   phgmg_dae_system(d), with snapshots restricted to x_d (phgmg_reduce of the
   full model is PHGMG_ERR_UNSUPPORTED; the command line does this by
   itself). The reduced model is a port-Hamiltonian ODE with the same
   outputs; every method takes it (GMG needs B' of full rank: a port that
   acts only through a constraint leaves B' = 0 there; SP1 and SP2 do not
   need it). tests/test_dae.c checks each claim: the condensed matrices of a
   three-state circuit against their closed forms, the simulation against
   an independent collocation of the DAE (its 3N stage system with the
   singular E solved directly), the constraints at every step, the energy
   balance, dense = banded, the dissipation block's eigenvalues, the reduced
   models' structure and balance, and the codes of index two, a singular
   pencil, E singular in another form and Q_dc != 0; and a bar with a
   massless node seen through orthogonal changes of coordinates (no zero
   lines) against the coordinate-aligned one: the same outputs, the states
   rotated, index two found as index two.

   2. THE OFFLINE PIPELINE ------------------------------------------------------
   2.1 Simulate. phgmg_simulate (or a phgmg_gl3 object: _create / _step /
   _get_stats / _destroy) integrates the full model with the 3-stage
   Gauss-Legendre method (order 6, symplectic, exact energy balance for a
   quadratic H). Inputs are evaluated at the stage times t + c_i dt. Linear
   dense models with N <= PHGMG_GL3_STEP_MAP_MAX_N use a precomputed step map;
   otherwise simplified Newton on the transformed stage system (one real and one
   complex N x N factorization, reused across steps). Optional outputs: the
   trajectory, the outputs, the energy bookkeeping, statistics; on a failure the
   steps done so far are kept.

   2.2 Reduce. phgmg_reduce(&red, &sys, X, ldx, ns, &opts, &info, alloc) runs
   named stages, each a function of its own:
     basis      POD of the snapshots (GMG: of the adjusted snapshots
                X - B B^+ X, giving V0 = [B, V1]); exact thin SVD, or for
                large N*ns the randomized POD with an a-posteriori check and
                exact fallback (info.pod_randomized, info.pod_check; GMG-POD
                then applies X - B B^+ X without copying X);
     manifold   GMG-QM: V2 = the next r_n POD modes (hierarchical POD) and
                the ridge fit of M; GMG_MANIFOLD: V2 and your eta;
     blocks     GMG: V0^T G V0, V0^T G V2, ... and the non-degeneracy check
                of D^T G D at xr = 0 and at every snapshot; SP1/SP2: W;
     terms      quadratic blocks; a separable part by hyper-reduction (or
                every term kept); a GENERAL part by callback;
     step map   LINEAR model with quadratic H and opts.dt > 0, for any
                step size: when h ||K Qh|| > 1e6 the map is formed without
                the factor h (no cancellation; it tends to -I as dt grows);
                the map of a dissipative model (Qh > 0, K + K^T <= 0) is
                checked not to grow in the energy norm (PHGMG_ERR_STEP_MAP);
     selection  GMG-QM with opts.select.lambda_mode: the choice of lambda
                (section 4).
   Progress. The library never prints; opts.progress (NULL: none) is called
   as progress(phase, opts.progress_user), from the calling thread only, as
   each stage starts: "basis" (snapshot adjustment and POD), "manifold",
   "blocks" (the reduced operators), "hamiltonian" (quadratic terms),
   "hyper-reduction" (the separable part: its gradient snapshots and
   DEIM/ECSW), "finish" (general term, step map, validation), and "done"
   after a successful reduction. GMG-QM with select.lambda_mode =
   PHGMG_LAMBDA_VALIDATED adds "lambda: validation runs" (their set-up),
   "lambda: full-model probe run" before each full-model simulation of a
   probe input and "lambda: candidate" before each lambda simulated (as many
   as info.lambda_candidates). info (may be NULL) receives the diagnostics
   (phgmg_reduce_info).

   2.3 Studies over many orders. phgmg_study_create computes, once for the
   largest basis, the PODs, the snapshots' reduced coordinates, the residual
   tails and the G- and Q-blocks; phgmg_study_reduce then builds the same model
   as phgmg_reduce in O(K ns r) instead of O(N ns r), phgmg_study_errors the
   error measures in reduced coordinates, phgmg_study_basis hands the bases to
   your own calls (opts.cache). X must stay unchanged while a study lives.
   What opts.cache holds (NULL: computed by the reduction; each from the same
   snapshots X):
     pod_basis, pod_cols    the leading left singular vectors (N x pod_cols,
                            ld N, by descending singular value) of the matrix
                            the method PODs: for GMG-POD and GMG-QM the
                            adjusted snapshots X - B B^+ X
                            (phgmg_adjust_snapshots, then phgmg_pod), for SP1
                            and SP2 X itself. GMG-QM takes V1 from the first
                            r - m columns and V2 from the next r_n (the POD of
                            what V1 leaves is exactly that tail), so one basis
                            serves every r. GMG_MANIFOLD: [V1, V2] must be
                            orthonormal and orthogonal to B (else
                            PHGMG_ERR_RANK).
     grad_basis, grad_cols  SP2: the same for the gradient snapshots.
     deim_pts, deim_w,      points and weights of phgmg_deim on these
     deim_count             snapshots (they depend on neither r nor the
                            method); with hyper.on = 1 they are used as given,
                            whatever hyper.kind says.

   2.4 Building blocks. The stages' kernels are public: phgmg_pod,
   phgmg_pod_randomized, phgmg_adjust_snapshots, phgmg_pod_hierarchical,
   phgmg_deim, phgmg_deim_select, phgmg_nnls, phgmg_ecsw, phgmg_ecsw_separable,
   and the dense kernels of >>linalg (GEMM, LU, QR, pivoted QR, least squares,
   thin SVD, symmetric eigenvalues). Argument lists. These kernels take
   their operands positionally in the LAPACK manner -- sizes, then each
   matrix as a pointer and its leading dimension, outputs last, the
   allocator at the end -- and some have ten or more arguments; the drivers
   a program calls with a model offer a struct form instead: phgmg_run with
   phgmg_simulate_run and phgmg_reduced_simulate_run (for phgmg_simulate and
   phgmg_reduced_simulate), phgmg_ss with phgmg_ss_compare (for
   phgmg_ss_error), phgmg_ph_sparse_desc with phgmg_ph_sparse_create_desc
   (for phgmg_ph_sparse_create and _create_e).

   2.5 Linear systems (>>linear, quadratic H, dense up to a few thousand
   states): Lyapunov and Riccati equations by the matrix sign function
   (phgmg_lyap, phgmg_care and their residuals), balanced truncation as a
   reference (phgmg_bt, plain Ar, Br, Cr), positive-real balanced truncation in
   pH form (phgmg_prbt, a phgmg_reduced of method PRBT), input-independent GMG
   bases (phgmg_linear_basis: frequency samples, impulse responses, balanced,
   least H2 error; pass them as opts.cache.pod_basis), transfer functions and
   H-infinity / H2 errors (phgmg_ph_abc, phgmg_ss_transfer, phgmg_reduced_abc,
   phgmg_ss_error). A system with an undamped mode has no Gramians: BT, PRBT
   and the BALANCED / H2 bases then return PHGMG_ERR_NOT_STABLE.


   2.6 Sparse models (>>ph, >>sparse). phgmg_ph_sparse_create takes J, R, Q
   (and E; or all of them in one phgmg_ph_sparse_desc:
   phgmg_ph_sparse_create_desc) as compressed sparse columns in any ordering, reorders them by
   reverse Cuthill-McKee into band storage and, for meshes (a wide band),
   also analyses a sparse LU of the GL3 stage matrices: block elimination
   of an independent set of states first (a mass-spring model's positions:
   what is left has the stiffness matrix's pattern), nested dissection of
   the symmetrised pattern, elimination tree, relaxed supernodes, a
   multifrontal LU with dense fronts, static pivoting on the fill-reducing
   order, each factorization checked (a tiny pivot or growth above
   PHGMG_SPARSE_GROWTH switches that stepper to the band LU with partial
   pivoting). The cheaper of band and sparse LU by predicted entries and
   flops is used; phgmg_ph_sparse_info reports the choice and
   phgmg_ph_sparse_set_solver forces one. Descriptor models (E, a mass
   matrix) take the same choice: their stage matrices sigma E + M are
   analysed with E's pattern joined (manual 8.12); an E with a zero row or
   column (index one, 1.8) keeps the band LU.

   3. METHODS AND OPTIONS -------------------------------------------------------
   Every option struct is "zero means default": memset it to 0 and set what you
   need. The tables give each field's default (the value a zero field takes).

   3.1 Methods (phgmg_reduce_opts.method)
     PHGMG_METHOD_GMG_POD      phi = [B, V1] xr, V1 from the POD of the
                               adjusted snapshots; GMG reduction. r includes
                               the m port coordinates (m < r <= N).
     PHGMG_METHOD_GMG_QM       quadratic manifold phi = [B, V1] xr +
                               V2 M (x2 kron x2), x2 = xr[m..r-1]; V2 the next
                               r_n modes, M a ridge fit with parameter lambda.
     PHGMG_METHOD_GMG_MANIFOLD your manifold phi = [B, V1] xr + V2 eta(x2),
                               eta and its first and second derivatives by a
                               callback (opts.qm.eta); GMG-QM is the case
                               eta = M (x2 kron x2), GMG-POD the case r_n = 0.
     PHGMG_METHOD_SP1          baseline: phi = V xr (POD of X), W = QV(V^TQV)^-1.
     PHGMG_METHOD_SP2          baseline: W from a POD of the gradient snapshots.
     PHGMG_METHOD_PRBT         positive-real balanced truncation (phgmg_prbt only).

   3.2 phgmg_reduce_opts
   phgmg_reduce_opts_default fills a struct with these defaults (the library
   applies them in that one place). The command line starts from them, with
   three choices of its own stated in its --help: --lambda auto (lambda
   validated by simulation: select.lambda_mode = PHGMG_LAMBDA_VALIDATED) for
   gmg-qm, --rn 8 with every manifold (a wide V2 only with --rn wide), and
   --lambda 0 meaning exactly zero (qm.lambda < 0).
   The options of one concern are grouped in a sub-struct: qm (the manifold
   of GMG-QM and GMG_MANIFOLD), select (choosing lambda, 4.2), hyper (a
   separable part, 3.4), cache (results reused across reductions, 2.3).
     field                default (zero)       meaning
     method               (required)           one of 3.1
     r                    (required)           reduced order (GMG: includes
                                               the m port coordinates)
     dt                   0 (no step map)      > 0: precompute the GL3 step
                                               map of a LINEAR model (2.2)
     degeneracy_tol       1e-12                least reciprocal condition of
                                               D^T G D before _ERR_DEGENERATE
                                               (below the table)
     nrun/runs            0/NULL (one run of   the training runs that made X
                          unknown input)       (4.1)
     ref / ref_x          PHGMG_REF_NONE       affine reference state (3.6):
                                               _MEAN the snapshots' mean,
                                               _GIVEN the vector ref_x
     progress/_user       NULL                 stage callback (2.2)
   qm (phgmg_qm_opts)
     qm.rn                8                    GMG-QM lifting dimension r_n
                                               with the POD manifold; with
                                               greedy or altmin, 0 resolves
                                               to PHGMG_RN_WIDE (3.3); > 0: a
                                               cap; GMG_MANIFOLD: required,
                                               <= 64
     qm.lambda            1e-3 (the paper's)   ridge parameter on the
                                               un-normalised sum over
                                               snapshots; < 0: exactly zero;
                                               used with lambda_mode FIXED
     qm.manifold          PHGMG_MANIFOLD_POD   GMG-QM construction (3.3)
     qm.greedy_window     0                    greedy / altmin with a wide
                                               V2: candidate modes (3.3)
     qm.eta/eta_user      NULL                 GMG_MANIFOLD: the manifold map
   select (phgmg_select_opts; only with lambda_mode other than FIXED)
     select.lambda_mode   PHGMG_LAMBDA_FIXED   _VALIDATED: by simulation
                                               (4.2); _REGRESSION: held-out
                                               regression error only
     select.lambda_min    1e-14                smallest lambda of the grid
     select.lambda_max    1                    largest lambda of the grid
     select.per_decade    4                    grid points per decade (1..100)
     select.folds         5                    _REGRESSION: folds (>= 2)
     select.blocks        min(ns, 100)         _REGRESSION: time blocks
     select.rcond         1e-6                 conditioning guard, relative to
                                               rcond(D^T G D) at xr = 0
     select.tolerance     1.02                 _VALIDATED: admissible e_y
                                               ratio to the linear limit
     select.train_only    0                    1: validate on the training
                                               runs alone (4.2)
     select.newton_tol    1e-10 (full), the    validation simulations
                          stepper's (reduced)
     select.newton_iter   20                   validation simulations
   hyper (phgmg_hyper_opts)
     hyper.on             0                    1: hyper-reduce a separable
                                               part (the method is hyper.kind);
                                               0: keep every term (exact,
                                               O(terms) online)
     hyper.kind           PHGMG_HYPER_ECSW     ECSW (weights >= 0), QDEIM or
                                               GREEDY (structure-preserving
                                               DEIM)
     hyper.tol            1e-6                 ECSW: relative training
                                               residual of the reduced
                                               nonlinear gradient
     hyper.deim_tol       1e-8                 DEIM modes: sigma_k/sigma_1 > tol
     hyper.deim_max       no cap               cap on DEIM modes
     hyper.allow_negative 0                    1: accept negative DEIM weights
   cache (phgmg_reduce_cache; 2.3)
     cache.pod_basis/_cols NULL (computed)     cached POD basis
     cache.grad_basis/_cols NULL (computed)    SP2: cached gradient POD basis
     cache.deim_pts/_w/_count NULL             cached DEIM result
   Bad values (NaN, out of range, unknown enums) give PHGMG_ERR_INVALID_ARG;
   sizes that do not fit the model or the snapshots' rank give PHGMG_ERR_SIZE.
   degeneracy_tol is compared with rcond(D^T G D) computed with D's port
   columns B_a scaled to unit length, so that the units of the states and of
   B do not change the verdict. Only method and r are required; every other
   field may stay zero.

   3.3 GMG-QM manifold constructions (opts.qm)
     PHGMG_MANIFOLD_POD     the paper's hierarchical POD: V1 the leading POD
                            modes of the adjusted snapshots, V2 the next r_n.
     PHGMG_MANIFOLD_GREEDY  V1 chosen column by column among the leading
                            (r - m) + r_n POD modes: each time the mode whose
                            coordinates best predict the other candidates' by
                            the quadratic ridge fit (after Schwerdtner &
                            Peherstorfer 2024; ridge 1e-9 when lambda is
                            chosen (select.lambda_mode not FIXED), else
                            qm.lambda; every ceil(ns/400)-th snapshot);
                            V2 the POD of what [B, V1] leaves. About (r - m)
                            (r - m + r_n) small least-squares solves.
     PHGMG_MANIFOLD_ALTMIN  alternating minimization (after Geelen, Balzano,
                            Wright & Willcox 2023) of the training objective
                            sum ||x - phi(rho(x))||^2 + lam ||M||^2 (lam:
                            1e-9 when lambda is chosen, else qm.lambda). It
                            keeps only what lowers the objective, so it never
                            ends above its start (info.manifold_obj0 ->
                            manifold_obj). With V2 of width r_n: V1, V2
                            rotated within the leading 2 (r - m + r_n) POD
                            modes, alternating the ridge fit of M with an
                            orthogonal Procrustes step (at most 100 sweeps).
                            With a wide V2 (its default): V2 is everything
                            V1 leaves, so for each V1 the best M is one ridge
                            fit and the objective is a function f(V1) alone.
                            The two blocks then alternate as: fit M for the
                            current V1; move V1 along the gradient of the
                            misfit with that M held fixed (which is the
                            gradient of f, because M is optimal), on the
                            orthonormal matrices within the numerical rank
                            of the adjusted snapshots (at most 256 modes),
                            step length by Barzilai-Borwein with a
                            non-monotone backtracking, the best V1 kept (at
                            most 200 steps). Why not the Procrustes step
                            here: the reduced state is the linear projection
                            V1^T x, so a rotation that fits the latent values
                            of the last sweep changes those values too; on
                            transport data it did not lower the objective
                            once. Why it helps: the POD modes V1 starts from
                            are the best linear space, not the best base for
                            a quadratic correction; the gradient turns V1
                            towards directions whose products predict the
                            rest. Advecting pulse of bench/qm_pulse.c (n = 12,
                            16, 20, lam = 1e-12): from the hierarchical POD
                            manifold's 3.4e-1, 2.1e-1, 1.2e-1 it reaches
                            1.7e-2, 3.0e-3, 1.9e-3 (the greedy manifold:
                            2.8e-2, 3.1e-3, 7.3e-4; the previous Procrustes
                            form with a wide V2: 1.0e-1, 4.1e-2, 1.2e-1),
                            10-30 s per reduction (N = 4096, 1000 snapshots).
                            Below the POD manifold's span floor it cannot
                            go; how far above it stops is set by the
                            non-convex objective (a local minimum near the
                            start) and the step budget, which binds on the
                            pulse. With qm.greedy_window > 0 it starts from
                            the greedy manifold (V1 the greedy choice, the
                            search space V1 and its complement's leading
                            modes) and improves it by 8-30 % there.
                            Under PHGMG_LAMBDA_VALIDATED GMG-POD joins the
                            validation as a second reference, and when no
                            lambda beats both the model of MANIFOLD_POD is
                            returned (info.manifold_fallback = 1).
   In every construction B stays in the span and [B, V1, V2] is orthonormal,
   so Br = [I; 0] and the GMG reduction is unchanged.
   The width of V2 (qm.rn). A cap rn > 0 takes as V2 the leading rn POD
   modes of what [B, V1] leaves of the snapshots (the paper's construction).
   PHGMG_RN_WIDE takes V2 over that whole residual up to its numerical rank
   rw, so that the quadratic term may correct in every direction the data
   has; only the part M can reach is kept, and the online width is
   rn = min(rw, (r - m)(r - m + 1)/2). Zero means 8 with the POD manifold and
   wide with the greedy and altmin manifolds. What wide costs: offline one
   SVD of the N x ns residual (the greedy construction with greedy_window > 0
   reuses its own), whose modes take N min(N, ns) doubles (as much as the
   copy of the snapshots GMG-QM keeps), and O((N + ns) rw (r - m)^2) for the
   compression; online, hyper-reduced and so independent of N, the
   quadratic terms cost O(rn (r - m)^2) per evaluation and the stepper's
   memory grows with rn r (PHGMG_ROM_STEPPER_MEMSIZE_MAX): at r - m = 20,
   rn <= 210, some 10^5 flops per right-hand side.
   The greedy window (qm.greedy_window; greedy or altmin with a wide V2).
   Zero keeps the candidates and the score described under
   PHGMG_MANIFOLD_GREEDY (the leading r - m + 8 POD modes). A window w > 0
   takes the leading r - m + w modes (up to the numerical rank) and scores
   each by the ridge objective (misfit + lam ||M||^2) over the other
   candidates not yet taken, with an incremental QR of the features that
   keeps a wide window affordable. The reference code of Schwerdtner &
   Peherstorfer uses 200, and transport data need that much: there the
   modes V1 wants lie far down the spectrum (bench/qm_pulse.c). Cost: about
   (r - m) w incremental updates of O(nsub (r - m)^3 + nsub^2 (r - m)) (at
   most nsub = 400 snapshots are used) plus one SVD of the adjusted
   snapshots: 3-10 s at r - m = 12-20, w = 200, N = 4096, ns = 1000 (two
   shared cores). With PHGMG_MANIFOLD_ALTMIN and a wide V2 the alternating
   minimization starts from this greedy manifold.
   The ridge parameter (qm.lambda, with select.lambda_mode FIXED): applied
   to the un-normalised sum over the snapshots; a negative value means
   exactly zero, and the fit of M is then the minimum-norm least-squares
   solution whatever the rank of its Kronecker matrix.
   Your own manifold (PHGMG_METHOD_GMG_MANIFOLD): qm.eta is the map
   eta: R^p -> R^rn of phi(x) = B x1 + V1 x2 + V2 eta(x2) (p = r - m,
   rn = qm.rn >= 1, required) with its first and second derivatives
   (phgmg_eta_fn, declared in >>online with the layouts of q, Dq and
   D2q), qm.eta_user its argument. V1 and V2 come from the
   hierarchical POD or from opts.cache.pod_basis (2.3); the reduced model
   calls eta online.

   3.4 Hyper-reduction (opts.hyper: on = 1, kind)
   A separable energy sum_k w_k phi(l_k) is replaced by sum_j w'_j phi(l_pj)
   over a few kept terms. Because the reduced energy itself is approximated
   (not its gradient), the reduced gradient is an exact gradient and the model
   stays pH.
     PHGMG_HYPER_ECSW   (default) empirical quadrature: weights w' >= 0 by
                        non-negative least squares on the reduced gradient
                        over the training snapshots (phgmg_ecsw_separable),
                        relative residual <= hyper.tol. Non-negative weights
                        keep a convex, bounded-below sum convex and bounded
                        below; the terms at rest in every snapshot are skipped.
     PHGMG_HYPER_QDEIM  the paper's structure-preserving DEIM with Q-DEIM
                        points (pivoted QR); weights w' = (P^T U)^{-T} U^T w
                        may be negative (refused unless hyper.allow_negative).
     PHGMG_HYPER_GREEDY the same with greedy DEIM points.
   DEIM keeps the modes with sigma_k / sigma_1 > hyper.deim_tol, at most
   hyper.deim_max of them. Online cost O(points); info.hyper_* and info.deim_*
   report the result.
   A GENERAL nonlinear part cannot be hyper-reduced (PHGMG_ERR_UNSUPPORTED):
   its reduced model evaluates H_nl in full dimension through
   phgmg_rom.ham_cb (info.online_full_dim = 1; not exportable).

   3.5 Other option structs
     phgmg_gl3_opts     tol 1e-10 (times max(1, |x|_inf, |Z|_inf); an explicit
                        tol is absolute), max_iter 10, contraction 0.5
                        (refactor above), no_step_map 0, keep_tiny 0.
     phgmg_study_opts   what = PHGMG_STUDY_GMG | PHGMG_STUDY_SP, kmax required.
     phgmg_prbt_opts    eps 0 (exact zero feedthrough; > 0: regularised
                        D = eps ||CB|| I), dt 0 (no step map), X/Y NULL.
     phgmg_basis_opts   nw 60, wmin/wmax from the system (1/(10 ||A^-1||_1),
                        2 ||A||_1), dt 0.1, nsteps 1000, maxit 1000, V0 NULL
                        (the balanced basis), h2_rel NULL.
     rom stepper        tol 1e-10 double / 1e-5 float (times max(1, |x|_inf,
                        |Z|_inf)), max_iter 10 (phgmg_rom_stepper_init).

   3.6 Affine reference state (opts.ref, opts.ref_x)
   Data that do not vary around 0 -- a pulse travelling through a domain, a
   state oscillating about a loaded equilibrium -- are represented far
   better by an affine manifold
       phi(x) = xbar + B x1 + V1 x2 + V2 eta(x2),   x = (x1, x2),
   with a reference state xbar (opts.ref = PHGMG_REF_MEAN: the mean of the
   snapshots; PHGMG_REF_GIVEN: your vector opts.ref_x, N finite values;
   PHGMG_REF_NONE, the default: none), for any method of phgmg_reduce (not
   with dampers or a feedthrough: PHGMG_ERR_UNSUPPORTED). Every basis and
   manifold (POD, hierarchical, greedy, alternating minimization; SP1/SP2's
   POD) is fitted to the snapshots minus xbar; the point reduction is
   rho(x) = rho_0(x - xbar) with rho_0 the map without reference state. On the advecting pulse of
   bench/qm_pulse.c the greedy manifold's training error at n = 20 drops from
   7.3e-4 to 7.7e-8 (lam = 1e-12; examples/README.md).
   Why the reduced model is still port-Hamiltonian. xbar is constant, so
   Dphi(x) = V0 + V2 [0, Deta(x2)] (V0 = [B, V1]) does not depend on it: the
   GMG reduction map W = F_G(Dphi)^T, W^T Dphi = I, the structure
   K(x) = (Dphi^T G Dphi)^{-1} (Jr its skew part, Rr = -sym K >= 0) and the
   port matrix W^T B = [I; 0] are those without reference state. Only the
   energy changes: the reduced Hamiltonian is Hr(x) = H(phi(x)), for
   H = 1/2 z^T Hq z + sum_k w_k phi_k(z[i_k]) (Hq = Q, E^T Q for a descriptor
   model)
       Hr(x) = 1/2 phi0^T Hq phi0 + x^T g0 + q^T g2 + h0
               + sum_k w_k phi_k(P0_k x + P1_k q + xbar[i_k]),
   phi0 = V0 x + V2 q, q = eta(x2), g0 = V0^T Hq xbar, g2 = V2^T Hq xbar,
   h0 = 1/2 xbar^T Hq xbar: a constant vector g0 in the gradient, g2 added
   to the curvature term (Deta^T (V2^T grad H)), offsets xbar[i_k] in the
   separable arguments (phgmg_rom.ref_g, ref_s). grad Hr = Dphi^T grad H(phi)
   holds as before, so dHr/dt = -grad Hr^T Rr grad Hr + yr^T u, and the
   output yr = Bh^T grad Hr = B^T grad H(phi(x)) is the full model's output at
   the lifted state (the first m columns of Dphi are B).
   A linear phi with a quadratic H: xbar is moved within the affine space
   xbar + span V0 to xbar - V0 Qh^{-1} g0, the same model in coordinates
   shifted by Qh^{-1} g0, which makes g0 = 0: the reduced model is then the
   model without reference state (step map included) plus the constant h0
   and the shifted lift.
   The initial state. A full state x0 enters as xr0 = rho(x0), the rule of
   every method; the full state 0 (a run from rest) is xr_rest = rho(0)
   (phgmg_rom.xr_rest, also in the model file and the C export), whose lift
   phi(xr_rest) is not 0 in general: the gap is the manifold's error at 0,
   small when the rest state is among the training snapshots (then it is part
   of the training projection error), and the energy starts at
   Hr(xr_rest) ~ 0. An exact shift (xr0 with phi(xr0) = 0) does not exist
   in general: 0 need not lie on the manifold. Start a deployed model from
   xr_rest, not from xr = 0 (which is the state xbar).
   Costs: one N x ns copy of the centred snapshots offline; online r + rn + 1
   more coefficients and O(r + rn) flops per gradient. Not with a study's
   cached basis (phgmg_study_reduce then takes the general path).
   tests/test_qm_ref.c checks each claim against full-dimension computations.


   4. DEPLOYMENT: VALIDATION, CHOOSING LAMBDA, ONLINE INDICATORS ----------------
   4.1 Training runs. Train on inputs that cover the levels (static content)
   and the frequency band the model will see; several runs go into one snapshot
   set (phgmg_simulate_inputs) and opts.nrun / opts.runs tell the reduction
   how they were made: 1 <= nrun <= 64 runs whose columns lie one after the other
   as phgmg_simulate_inputs lays them out (the sum of nsteps + 1 must be ns,
   else PHGMG_ERR_SIZE); 0 / NULL: X is one run of an unknown input. The
   runs are what lambda validation simulates (PHGMG_LAMBDA_VALIDATED: every
   training run and three probe runs made from runs[0]) and cuts into folds
   (PHGMG_LAMBDA_REGRESSION: one run per fold when nrun >= 2).

   4.2 GMG-QM's ridge parameter (opts.select). A fixed lambda
   (select.lambda_mode = PHGMG_LAMBDA_FIXED, the default: opts.qm.lambda, the
   paper's 1e-3 when zero) is what the paper does; on small reduced
   coordinates it shrinks M to almost zero, and a very small lambda can bend
   the manifold so much that the reduced model fails on inputs unlike the
   training one. The other modes choose lambda from a grid, and the other
   fields of opts.select are read only then.
     PHGMG_LAMBDA_VALIDATED (recommended; needs opts.runs): validation by
       simulation.
       The reduction simulates the finished reduced model, for candidate
       lambdas, on every training run (reference: the snapshots' outputs) and
       on three probe runs it was not fitted to -- the full model driven from
       runs[0].x0 by a constant at the RMS level of runs[0].u (per port), by
       runs[0].u played 1.5x faster and by the square wave RMS * sign(u(t))
       -- and compares each run's e_y with the linear limit M = 0 (GMG-POD on
       the same basis). Candidates: lambda_max, then one per decade down to
       the regression optimum of PHGMG_LAMBDA_REGRESSION; the descent stops
       after two inadmissible candidates in a row, and a candidate's
       evaluation at its first inadmissible run. Admissible: no simulation fails, at most 4
       Newton iterations per step on average, and every run's e_y at most
       select.tolerance (1.02) times the linear limit's. Kept: the largest
       admissible lambda with at least half of the best admissible gain (sum
       of log ratios); none: M = 0 (info.lambda = HUGE_VAL). Without runs
       nothing can be simulated and M = 0. Runs with the same x0 and the same
       inputs at every stage time are simulated once. Cost: three full-model
       probe runs plus (nrun + 3) reduced runs per candidate, 4-8 candidates.
       The validation simulations use select.newton_tol (0: 1e-10 for the
       full model, the stepper's default for the reduced one: 1e-10 double,
       1e-5 float) and select.newton_iter (0: 20).
       info.lambda_candidates, info.lambda_val_ratio report it.
     select.train_only = 1 (with PHGMG_LAMBDA_VALIDATED): no probe runs; from
       the regression optimum up, the first lambda whose model simulates
       every training run without Newton trouble and within select.tolerance
       of the linear limit: the most accurate model on the training inputs;
       it does not guard against unlike inputs.
     PHGMG_LAMBDA_REGRESSION: regression only. The snapshots are cut into
       select.blocks contiguous blocks in time, block j to fold j mod
       select.folds (with several runs: one run per fold). For each fold, M is
       fitted on the other snapshots for every lambda of the grid
       select.lambda_min * 10^(g / select.per_decade) <= select.lambda_max
       (one thin SVD of the training rows, then a small product per lambda)
       and predicts the held-out
       quadratic correction V2^T x. The lambda with the smallest held-out error
       summed over the folds (ties within 1e-6 relative: the larger) fits M on
       all snapshots. Guard: while rcond(D^T G D) at some snapshot is below
       select.rcond times its value at xr = 0, the next larger lambda is taken
       (info.lambda_raised); if even select.lambda_max does not help, M = 0.
       This choice measures the regression, not the reduced model, and picks
       very small lambdas that overfit (see 8.6).
   When M = 0 is chosen, info.lambda = HUGE_VAL. Result codes (checked only
   when lambda_mode is not FIXED): PHGMG_ERR_INVALID_ARG for a lambda_mode
   outside the enum, lambda_min or lambda_max negative, NaN or infinite or
   lambda_min > lambda_max, per_decade outside 1..100, folds < 2, blocks < 0,
   rcond outside [0, 1], a grid of more than 1000 points; PHGMG_ERR_SIZE for
   blocks < folds or blocks > ns. Before version 0.2.0 the value 1 meant what
   is now PHGMG_LAMBDA_REGRESSION.

   4.3 The check before shipping. phgmg_reduced_validate(red, &sys, &run, tol,
   max_iter, ey_max, &v, alloc) simulates full and reduced model on one run and
   fills phgmg_validation: e_red, e_y, e_proj, e_energy (and the full model's),
   Newton statistics, the first failing step, pass (completed, no Newton
   failure, e_y <= ey_max). A failing reduced model is a result (pass = 0), not
   an error. The command line's `phgmg validate` does the same for a list of
   test inputs and exits 1 when one fails.

   4.4 Online indicators. Every reduced model carries a training envelope
   (env_lo, env_hi: the range of the training snapshots' reduced coordinates,
   widened by 10 % of each width plus 2 % of the largest) and, for a quadratic
   manifold, q_max (1.2 times the largest quadratic correction seen in
   training). phgmg_rom_step counts stats.outside_steps (steps ending outside
   the envelope), stats.q_outside_steps (correction above q_max),
   stats.consec_failures and stats.max_consec_failures. The envelope marks
   unfamiliar states, not error; a growing q count is the warning sign of a
   quadratic manifold used outside its training.


   5. THE ONLINE PATH AND FIRMWARE ----------------------------------------------
   5.1 Stepping. phgmg_rom_stepper_memsize(rom) (or the compile-time bound
   PHGMG_ROM_STEPPER_MEMSIZE_MAX(r, m, rn, nd), _MAX_CB with callbacks) gives
   the bytes; phgmg_rom_stepper_init places the stepper in caller memory;
   phgmg_rom_step advances xr in place, with u3 = u at the three stage times
   (phgmg_rom_stage_times), stage-major: u3[i*m + a] is input a at stage
   time i (3m values), and returns the output and optionally the energy
   increments. The memory must be aligned for phgmg_real and int (malloc,
   or a static phgmg_real or double array). A LINEAR model with a quadratic H stepped at its own dt uses the
   exact step map (a matrix-vector product); otherwise GL3 with simplified
   Newton on the 3r stage system, bounded by max_iter: a failure is a result
   code, never a hang, and leaves x, y and the energy untouched; the stepper
   stays usable. Quadratic-manifold models are stepped in mass-matrix form
   (8.5). phgmg_rom_stepper_memsize_dt sizes a stepper for another dt;
   phgmg_rom_stepper_reset forgets the extrapolation history.
   Evaluators for your own integrator: phgmg_rom_hamiltonian, _gradient, _rhs,
   _output, _structure (Jr, Rr at a state), _hessian, _jacobian (analytic),
   with phgmg_rom_eval_work_size reals of workspace.

   5.2 Shipping a model. phgmg_rom_export_c writes C source (static const
   arrays and a `static const phgmg_rom`), to be compiled after phgmg.h into
   firmware; values round-trip exactly. The source is for the scalar type of
   the build that wrote it (phgmg_real; an #error guards a mismatch). For
   float firmware, export from a float build: the offline half always
   computes in double, so a program compiled with PHGMG_REAL_FLOAT builds
   the reduced model as the double build does (only a lambda validated by
   simulation sees the float reduced model) and stores it rounded to float;
   such a program can also phgmg_rom_load a model file a double build saved
   and export that. The command line has a float build for this
   (make build/phgmg-float). phgmg_rom_serialize / _save write a
   versioned, checksummed little-endian binary (format version 3 for a model
   with dampers or feedthrough, 2 for one with several separable functions,
   else 1; all three load); phgmg_rom_deserialize / _load read it into caller
   memory, checking magic, version, sizes, checksum and values; a file written
   by a double build loads into a float build and vice versa. Models that call
   back into user code cannot be serialised; the C export references the
   firmware's <name>_phi / <name>_eta instead (a GENERAL model, callback
   dampers: not at all). A loaded model with dampers must have weights >= 0
   and dissipative laws, one with feedthrough a positive semidefinite
   dissipation block (PHGMG_ERR_STRUCTURE otherwise).

   5.3 Firmware builds. PHGMG_NO_OFFLINE compiles only the online half and the
   in-memory (de)serialisation: libm only, no heap, no stdio. PHGMG_REAL_FLOAT
   makes the online scalar float. examples/controller/ steps an exported model
   on a Cortex-M4F (make embedded).


   6. THE COMMAND LINE -----------------------------------------------------------
   examples/phgmg_cli.c is a complete reducer on top of this header
   (`make build/phgmg`, or cc -std=c99 -O2 examples/phgmg_cli.c -o phgmg -lm):
     phgmg reduce       J, R, Q, B (or sparse triplets) as .npy, snapshots
                        (--X) or --simulate, --method, --r, ... --out DIR:
                        writes NAME.phgmgrom, NAME.c, NAME.json and the
                        reduced operators as NAME_*.npy;
     phgmg simulate-rom run a model file on an input, outputs (and states) as
                        .npy;
     phgmg validate     reduce, then test full against reduced model on each
                        --test-input (exit 1 if one fails);
     phgmg info         describe a model file.
   Model options shared by reduce, validate and simulate include the mass
   matrix (--E, --E-coo), feedthrough (--P, --S, --N) and nonlinear dampers:
   --dampers FILE, a (k, 4) array of rows (i, j, c1, c3), a damper on
   s = z_i - z_j (j = -1: s = z_i) with force c1 s + c3 s^3 (1.7); e.g. cubic
   dampers on the velocities of a chain (tests/test_cli.sh builds one).
   `phgmg --help` lists every option with its default, the file formats and
   examples. The reduction does not depend on the units of the states; GMG-QM's
   lambda grid and the POD itself do (with ports of very different scale,
   scale the inputs and check each port's e_y with validate).


   7. ERRORS ---------------------------------------------------------------------
   Every data-dependent failure is a negative phgmg_result (0 is success);
   phgmg_result_string gives a stable text. The library never prints, exits or
   aborts (PHGMG_ASSERT guards only contract violations of void helpers, e.g.
   a NULL factorization handed to phgmg_jr_solve). For every failing call:
   - the caller's inputs are never modified (systems, snapshots, options,
     models, file images, the state of a failed step);
   - objects returned through **out are NULL; nothing allocated stays
     allocated (each single allocation failure included);
   - caller-provided output arrays hold unspecified values, except where a
     declaration says otherwise (phgmg_simulate and phgmg_reduced_simulate
     keep the steps done);
   - stateful objects stay usable (a stepper after a failed step).
   The codes:
     PHGMG_OK (0)                   success
     PHGMG_ERR_INVALID_ARG (-1)     a NULL pointer, an unknown enum, missing
                                    callbacks, dt not positive and finite, a
                                    bad option (3.2), misaligned memory
     PHGMG_ERR_SIZE (-2)            dimensions out of range; snapshots whose
                                    numerical rank is below what the method
                                    needs (r - m modes for GMG, r_n more for
                                    GMG-QM, r for SP1/SP2)
     PHGMG_ERR_WORKSPACE (-3)       caller memory smaller than the size query
     PHGMG_ERR_NOMEM (-4)           the allocator returned NULL (offline only;
                                    the error measures return NaN instead)
     PHGMG_ERR_SINGULAR (-5)        J - R singular or too ill-conditioned; an
                                    exactly zero pivot; D^T G D singular at a
                                    state of a quadratic-manifold model
     PHGMG_ERR_NANINF (-6)          NaN or Inf in the data, the input, the
                                    state, or produced by a step
     PHGMG_ERR_NOT_CONVERGED (-7)   a Newton step (also after one retry with
                                    fresh factors), a Jacobi sweep limit, an
                                    iteration cap
     PHGMG_ERR_NOT_SKEW (-8)        ||J + J^T|| > tol ||J||
     PHGMG_ERR_NOT_SYMMETRIC (-9)   R not symmetric
     PHGMG_ERR_NOT_PSD (-10)        R not positive semidefinite
     PHGMG_ERR_RANK (-11)           B not of full column rank; a rank-deficient
                                    least-squares problem (phgmg_lstsq; GMG-QM
                                    with lambda < 0 takes the minimum-norm
                                    solution instead)
     PHGMG_ERR_DEGENERATE (-12)     GMG non-degeneracy fails: rcond(D^T G D)
                                    below degeneracy_tol at xr = 0 or (GMG-QM)
                                    at a snapshot; SP1/SP2 likewise
                                    (info->rcond_dgd says how close)
     PHGMG_ERR_NEGATIVE_WEIGHT (-13) DEIM gave a negative weight and
                                    hyper.allow_negative is 0
     PHGMG_ERR_FORMAT (-14)         a malformed model image or .npy file
     PHGMG_ERR_IO (-15)             a file cannot be opened, read or written
                                    (an existing path is never removed)
     PHGMG_ERR_UNSUPPORTED (-16)    e.g. DEIM of a GENERAL part, serialising a
                                    model with callbacks
     PHGMG_ERR_Q_NOT_SYMMETRIC (-17) Q not symmetric
     PHGMG_ERR_Q_NOT_PD (-18)       Q not positive definite (semidefinite with
                                    a nonlinear part)
     PHGMG_ERR_DTYPE (-19)          an unsupported .npy dtype
     PHGMG_ERR_INEXACT (-20)        a 64-bit integer beyond 2^53 in a .npy
     PHGMG_ERR_NOT_STABLE (-21)     an undamped mode (eigenvalue of (J - R) Q
                                    on the imaginary axis): no Gramians
     PHGMG_ERR_OVERFLOW (-22)       a result beyond the double range (e.g. an
                                    energy of states ~1e160 in
                                    phgmg_reduced_validate; the error norms
                                    themselves are scaled), ECSW weights out
                                    of range after scaling back
     PHGMG_ERR_TOL_UNREACHABLE (-23) a relative tolerance below 1e-15 (ECSW,
                                    hence hyper.tol)
     PHGMG_ERR_NOT_STABILIZABLE (-24) no stabilizing Riccati solution
                                    (phgmg_care)
     PHGMG_ERR_STALE (-25)          the system changed after
                                    phgmg_study_create (phgmg_study_reduce)
     PHGMG_ERR_STRUCTURE (-26)      an intact model file that is not a pH model
                                    of its kind (Qh not positive definite,
                                    dissipation not PSD, a step map not of its
                                    dt): phgmg_rom_deserialize / _load
     PHGMG_ERR_STEP_MAP (-27)       the step map of a dissipative model would
                                    grow in the energy norm (phgmg_reduce with
                                    opts.dt)
     PHGMG_ERR_E_SINGULAR (-28)     the mass matrix E is singular to working
                                    precision and not of the algebraic form
                                    of 1.8 (k zero rows, k zero columns)
     PHGMG_ERR_EQ_NOT_SYMMETRIC (-29) E^T Q not symmetric (descriptor models)
     PHGMG_ERR_EQ_NOT_PD (-30)      E^T Q not positive definite (semidefinite
                                    with a nonlinear part)
     PHGMG_ERR_E_COUPLED (-31)      a row of E at a nonlinear coordinate is not
                                    a positive multiple of the unit row
     PHGMG_ERR_FEEDTHROUGH (-32)    [[R, P], [P^T, S]] not symmetric PSD, or N
                                    not skew
     PHGMG_ERR_DAMPER (-33)         a damper that generates energy: a
                                    polynomial law with a constant or even
                                    term or a negative coefficient, or a
                                    callback law with s rho(s) < 0 where it
                                    was evaluated (1.7)
     PHGMG_ERR_PENCIL (-34)         singular E whose pencil s E - (J - R) Q is
                                    singular for every s (1.8)
     PHGMG_ERR_INDEX (-35)          singular E of index two or higher: the
                                    algebraic co-states are not determined by
                                    the algebraic equations (1.8)
   The declaration of each function lists the codes it returns and when.


   8. NUMERICAL NOTES: WHAT THE PAPER LEAVES OPEN AND WHAT PHGMG DECIDED -----------
   8.1 Time integration. Gauss-Legendre with three stages; its coefficients
   come from their closed forms (phgmg_gl3_coefficients), not from decimals.
   The 3N stage system is solved in the eigenbasis of A^{-1} (one real and one
   complex N x N system per simplified-Newton iteration), factors reused while
   the iteration contracts, the guess extrapolated from the last step's
   collocation polynomial. A linear model with fixed step is a linear map,
   precomputed once. Newton stops when the inf-norm of the stage residual is
   <= tol after at least one update (full and reduced steppers alike). An
   explicit tol is absolute, in the units of the state; the default (1e-10,
   1e-5 in float) is multiplied by max(1, |x|_inf, |Z|_inf), so a model whose
   states are large in its units still converges, and a small-state model is
   never accepted on the unsolved extrapolated guess.
   The full model's stepper (phgmg_gl3) in detail:
   - Newton iterates on Z_i = Y_i - x_n, always makes at least one update and
     stops when ||Z - h (A x I) F(Z)||_inf <= tol, at most max_iter updates.
     An explicit opts.tol is absolute; the default (opts.tol = 0) is 1e-10
     times max(1, ||x_n||_inf, ||Z||_inf), so that a model whose states are
     large in its units (1e9) still converges (tests/test_online.c).
     Jac = (J - R) Hess H(x_n), factored as gam/h I - Jac (real) and
     (alp - i bet)/h I - Jac (complex): dense LU, banded LU with lower/upper
     bandwidth from the nonzero diagonals of J - R and Q (plus kb for a GENERAL
     Hessian), the sparse LU of a phgmg_ph_sparse model that chose it
     (8.12), or the caller's shifted_* callbacks. Factors are reused across
     steps; the next step refactors when the largest contraction rate
     res_{k+1}/res_k of a step exceeded opts.contraction. With factors from an
     earlier state a rising residual aborts at once and the step is retried
     once with fresh factors; with fresh factors two successive rises or
     max_iter give PHGMG_ERR_NOT_CONVERGED.
   - The starting guess extrapolates the previous step's collocation polynomial
     when the call continues the previous one (same x as it returned, t = its
     end time), else Z = 0.

   8.2 Energy balance. The supplied energy h sum b_i y_i^T u_i and the
   dissipated energy h sum b_i gradH(Y_i)^T R gradH(Y_i) are summed at the
   stage values with the inputs the stepper used. For a quadratic H the
   balance H(x+) - H(x) = supplied - dissipated then holds to round-off; a
   trapezoidal rule on the time grid would measure the quadrature instead.

   8.3 Dense kernels. The thin SVD of a tall, numerically rank-deficient
   snapshot matrix is a QR with column pivoting truncated at the numerical rank
   followed by one-sided Jacobi on the small triangular factor; the Gram-matrix
   route would lose the small singular values that DEIM's 1e-8 truncation
   needs. The randomized POD is offered for large N only where the small
   values do not matter, and checked a posteriori.

   8.4 Structure and orderings. Every reduction is equivariant under a
   permutation of the states: reordering a model (e.g. into a band) changes the
   full-dimension vectors, not the reduced model. Models bring their structure
   (banded storage, a sparse reordering, or their own shifted solves).

   8.5 Quadratic manifold. The Jacobian of phi is affine in x2, so
   D^T G D, the reduced gradient of a quadratic H and the hyper-reduction rows
   are small polynomials in x2 whose coefficients (V0^T G V0, V0^T G V2,
   V2^T G V2, ...) are computed offline: the online cost is independent of N,
   and the Newton Jacobian is analytic. The ridge problem for M has equal
   columns (i, j) and (j, i) in the paper's full Kronecker form; its ridge
   solution is symmetric, so phgmg solves the same problem over the p(p+1)/2
   distinct columns and expands (same minimiser). lambda is applied to the
   un-normalised sum over the snapshots, as in the paper. The reduced stepper
   treats the stage values E(Y_i)^{-1} gradH(Y_i), E = D^T G D, as unknowns
   beside the stage increments (mass-matrix form): an iteration needs only
   products with E and solves with factors of E kept from an earlier state;
   E is refactored every 8 steps and after a step needing more than one
   iteration, and a slowly contracting step is redone with exact stage
   values (stats.exact_steps, stats.e_refreshes). The converged stages are
   those of the ordinary GL3 method.

   8.6 Choosing lambda. Held-out time blocks of the training trajectory
   measure the regression: they pick lambda around 1e-12 ... 1e-14, and the
   reduced model is excellent on the training input and fails (large e_y or a
   Newton failure) on a constant, a faster sine or a chirp. Hence
   PHGMG_LAMBDA_VALIDATED validates by simulating the reduced model on data
   it was not fitted to, with GMG-POD's linear limit as the safe fallback
   (4.2). The grid is absolute: for reduced coordinates far from unit size,
   set select.lambda_min / lambda_max to the scale of the quadratic features
   (|z|^4).

   8.7 Hyper-reduction. Approximating the gradient (plain DEIM) breaks the
   pH structure; approximating the energy keeps it. The paper's weights
   (P^T U)^{-T} U^T 1 depend on the points and can be negative (on the
   paper's nonlinear chain driven by u = 0.1 both Q-DEIM and greedy points
   give one), which can make the reduced energy unbounded below. phgmg therefore
   defaults to non-negative weights by empirical quadrature and refuses
   negative DEIM weights unless asked. DEIM's mode count is the relative
   criterion sigma_k / sigma_1 > hyper.deim_tol.
   Empirical quadrature (phgmg_ecsw) is Lawson-Hanson's active-set method
   for non-negative least squares, stopped at the tolerance: the candidate
   gradient from the Gram matrix Gm^T Gm (formed once: nrows nterms^2
   flops, the dominant cost, 0.16 s at 20020 x 500),
   the passive least squares by Cholesky of the Gram block refined once with
   the true residual, the residual itself from Gm (so the 1e-6 default is
   met where the Gram form alone stalls near 1e-5), and a claim of
   optimality checked with the true gradient Gm^T r. When the original
   weights are >= 0 they are an exact solution, so tol is reachable up to
   rounding; the points come out in Lawson-Hanson's greedy order of largest
   gradient, typically fewer than DEIM's at a comparable accuracy.
   With w >= 0 and convex phi_k the reduced sum sum_j w_j phi(l_{pts_j}(x))
   is convex in the reduced coordinates for any linear map x -> l, and bounded
   below whenever each phi_k is; negative DEIM weights give no such guarantee.
   Only Gm^T Gm, Gm^T target and ||target|| matter: rows compressed by any
   orthogonal map (Gm' = Q^T Gm, target' = Q^T target) give the same weights
   at less cost; phgmg_ecsw_separable does this for terms linear in the
   reduced coordinates.
   Many terms (nterms >= PHGMG_ECSW_SCREEN_MIN, default 4096): the n x n Gram
   matrix is never formed. Screening: the full gradient Gm^T (target - Gm w)
   (one pass over Gm) picks the PHGMG_ECSW_SCREEN_ADD (64) terms with the
   largest positive gradient into a working set W, the method above solves
   the problem restricted to W (all rows: its residual is the true one), and
   this repeats until tol is met or no term outside W has a positive
   gradient (w then optimal over all terms, as above). Same guarantees:
   w > 0 on the kept terms, residual <= tol or PHGMG_ERR_NOT_CONVERGED
   (also if W reaches 16 * PHGMG_ECSW_SCREEN_ADD terms). Memory nrows *
   |W| + O(nrows + nterms); on the paper's chain at N = 256 000 (128 000
   terms, 20 020 rows) 3 rounds, 28 points, about 2 s.

   8.8 Readings of the paper. (a) SP2's reduction matrix as printed is
   dimensionally inconsistent; phgmg takes W = V_grad (V_POD^T V_grad)^{-1}
   (so W^T V_POD = I) and the pH form xr' = W^T (J - R) W gradHr + W^T B u,
   Hr(xr) = H(V_POD xr), yr = (W^T B)^T gradHr. (b) SP1: V = V_POD,
   W = QV(V^TQV)^{-1}, Q the Hessian of the quadratic part; its point
   reduction is rho(x) = W^T x. (c) The reduced initial state is rho(x0).
   (d) The paper's nonlinear example: mass 1 in the Hamiltonian (the explicit
   decomposition's Q = blockdiag(Q0, I)) and damping 0.3, reduced and
   measured in the coordinates l_i = xi_i - xi_{i+1}, stored interleaved so
   that the Newton matrices are banded; its lambda is max(0.2 e_proj(r),
   10^-2.5), e_proj of the linear GMG map at the same r. These choices are
   the examples' (examples/msd_models.h), not the library's.

   8.9 Non-degeneracy. GMG needs det(D^T G D) != 0. phgmg estimates the
   reciprocal condition number with the port columns of D scaled to unit
   length, so the result does not depend on the units of B or of the states,
   at xr = 0 and (GMG-QM) at every snapshot. Examples: R = 0 makes G skew, so
   every odd r fails.

   8.10 Tiny numbers and the floating-point environment. The decaying tail of
   a wave through a chain at rest passes through the subnormal range, where
   some processors compute about 100x slower. The steppers set entries of
   their own vectors below max(DBL_MIN, PHGMG_GL3_FLUSH_REL |x|_inf) to zero
   (phgmg_gl3_opts.keep_tiny = 1 turns it off); the library never reads or
   changes the floating-point environment (rounding mode, FTZ/DAZ).
   In the full model's stepper:
   - a chain started at rest carries a wave whose tail decays
     through the subnormal range (|v| < DBL_MIN), where some processors compute
     ~100x slower, and a polynomial nonlinearity underflows long before that
     (y^3 for |y| < 3e-103). The stepper therefore sets to zero, in its own
     vectors, every entry below tau = max(DBL_MIN, PHGMG_GL3_FLUSH_REL ||x||_inf)
     (x: the state at the start of the step; with the step map: the new
     state relative to itself, and the map matrices relative to their largest
     entry, once at create): the new state, the converged
     stages kept for the next guess, and in the pivot-free banded solve the
     tail the substitutions carry beyond the support of the right-hand side
     (the sweeps stop after kl resp. ku zero rows, which also skips the O(N)
     work where the chain is still at rest); the other solves (dense,
     pivoting banded, callbacks) have their results flushed. On the paper's
     nonlinear chain from rest no instruction sees a subnormal operand after
     the second step (the first has no scale yet). An entry 1e-60 below the
     largest changes nothing at any Newton tolerance: the trajectory agrees
     with opts.keep_tiny = 1 (no flushing) to rounding (tests/test_subnormal.c).
     The floating-point environment (rounding mode, MXCSR/FTZ/DAZ) is neither
     read nor changed.

   8.11 Linear systems. For a linear model GMG-POD is a Petrov-Galerkin
   projection with the test space G^T V, V = orth([B, Vbar]); its model depends
   on the basis alone, which is why bases from Gramians or frequency samples
   (and the basis of least H2 error) keep the structure and can beat a
   single-trajectory POD by orders of magnitude off the training input. Zero
   feedthrough makes the positive-real Riccati equations singular; phgmg
   solves the exact limit (the constraint X B = C^T eliminated in the frame
   [B, ker C]) instead of regularising, so the pH model is the balanced
   projection itself.
   Positive-real balanced truncation (phgmg_prbt) in detail. Gramians: the
   minimal solutions X (Q-eq) and Y (P-eq) of the positive-real lemma.
   Default (opts->eps = 0): the exact limit. The lemma with D = 0 reads
   A^T X + X A <= 0, X B = C^T. In the frame T = [B, Nc] (Nc: ker C) the
   constraint fixes T^T X T = diag(C B, Z), and the Schur complement is a
   regular positive-real Riccati equation for Z (size N - m) with feedthrough
   S = 2 B^T Q R Q B (must be positive definite: every port damped). Its
   Popov function still vanishes at w = 0 on chains driven by forces (G(0) =
   0), so its Hamiltonian has Jordan pairs at 0: the solution is taken from
   the stable eigenvectors plus the cluster's eigenvectors (two shifted sign
   iteration and the kernel of the Hamiltonian, see phgmg__care_cluster). Then
   X B = C^T holds to round-off, Sigma_r Br = Cr^T, and the pH form is
   Qh = Sigma_r, Jh = skew(Ar Sigma_r^-1), Rh = Sigma_r^-1 F F^T Sigma_r^-1 / 2
   with F = Tr^T Lf and -(A^T X + X A) = Lf Lf^T (rank m, in factored form
   from the deflated equation: PSD by construction; clipping the round-off
   negative eigenvalues of -sym(Ar Sigma_r^-1) instead cost 1e-6 in e_y once
   sigma_r ~ 1e-8), Bh = Br, output Bh^T Qh x = Cr x: the balanced projection
   itself, without an output change. Cost: one sign iteration of size
   2(N - m) per equation, as the regularised path.
   Measured (examples/linear_bases.c, e_y worst unseen input, PRBT / BT):
   two-port chain r = 12/16/20: 1.7e-3/9.1e-5/2.0e-5 vs 6.5e-4/5.7e-5/1.3e-5;
   paper's chain r = 12/16/20: 1.3e-4/1.2e-6/6.1e-9 vs 3.4e-5/5.0e-7/1.7e-9.
   If S is not positive definite (or C B not symmetric), or opts->eps > 0:
   the regularised lemma with D = d I, d = eps ||C B||_F (eps 1e-10 in the
   fallback), S = 2 d I:
     Q-eq  A^T X + X A + (X B - C^T) S^-1 (X B - C^T)^T = 0,
     P-eq  A Y + Y A^T + (Y C^T - B) S^-1 (Y C^T - B)^T = 0,
   stabilizing solutions by phgmg_care; pH form Qh = Sigma_r, Jh = skew(Ar
   Sigma_r^-1), Rh = Sigma_r^-1 F S^-1 F^T Sigma_r^-1 / 2 with F = Sigma_r Br
   - Cr^T (PSD by construction), Bh = Br, output Bh^T Qh x. Its cost: the
   model drops D = d I and replaces the output Cr by Br^T Sigma_r; both
   differences are O(sqrt(eps)) relative (||X B - C^T|| / ||C||: 8e-3, 8e-4,
   8e-5 at eps = 1e-6, 1e-8, 1e-10 on the two-port chain), which is why the
   regularised PRBT levels off near 1e-5 (e_y) while BT keeps falling;
   much smaller eps makes the Hamiltonian too ill-conditioned for the sign
   function (at 1e-11 it loses the minimal solution: a positive-real
   singular value > 1, returned as PHGMG_ERR_NOT_CONVERGED).

   8.12 The sparse direct solver (>>sparse).
   The GL3 stepper solves, per Newton iteration, one real and one complex
   system with the stage matrices K(sigma) = sigma I + M, M = -(J - R)(Q + D)
   (D: the Hessian diagonal of a SEPARABLE nonlinear part, 0 for a linear
   model), sigma = gamma/h and (alpha - i beta)/h. In band storage these
   factor in O(N kl (kl + ku)) and solve in O(N (kl + ku)) with kl, ku ~ 2 kb:
   right for chains, slow for 2-D and 3-D meshes (a 40 x 40 lattice has kb ~
   80, a 16^3 one ~ 400). phgmg_ph_sparse_create therefore predicts both
   costs and picks the cheaper solver (PHGMG_SOLVER_AUTO):
   - Band: kept without analysis when kb <= PHGMG_SPARSE_MIN_KB (chains).
   - Sparse LU, own code in this file, in five steps:
     0. Condensation (block elimination): a set A of states no two of which
        are joined in the graph of M + M^T makes K_AA diagonal, so with B
        the other states
           K = [K_AA K_AB; K_BA K_BB],  S = K_BB - K_BA K_AA^{-1} K_AB,
           K x = r:  u = K_AA^{-1} r_A,  S x_B = r_B - K_BA u,
                     x_A = u - K_AA^{-1} K_AB x_B,
        and only S (order |B|) goes through steps 1-4. S's pattern is that
        of K_BB plus the product pattern of K_BA K_AB, computed from the
        unsymmetric pattern of K: for a mass-spring model x = (q, p) the
        position rows hold one entry (dq/dt = p / m), so condensing the
        positions leaves S with the pattern of the stiffness matrix (the
        symmetrised graph would have joined every two neighbours of a
        mass). A is chosen greedily in breadth-first order among the states
        of degree <= 32 (on a bipartite graph, as positions and momenta
        are, one whole side); the condensed analysis is kept when its
        predicted factor (entries of L of S, plus those of K_BA and K_AB)
        is smaller than K's own. A pivot K(a, a) is checked like the
        others (below). Lattices: the factor shrinks 2.8-3.3x (2-D 40 x 40
        1.59e5 -> 5.6e4 entries; 3-D 16^3 1.95e6 -> 6.0e5).
     1. Ordering: nested dissection of the graph of M + M^T (the pattern of
        M is that of (J - R) Q + (J - R) + I; it is symmetric when J - R and
        Q have symmetric patterns only if their product's is, so the graph is
        symmetrised). Each part is split by one level of a breadth-first
        search from a pseudo-peripheral node (George-Liu), the level where
        half of the part is reached, thinned to the nodes with a neighbour in
        the next level (still a separator); halves first, separator last,
        parts of <= 48 nodes as they come, unconnected parts one by one.
     2. Symbolic analysis: elimination tree (Liu, path compression),
        postorder, column counts from the row subtrees (O(nnz(L))),
        supernodes: fundamental ones, plus a child joined to its only-child
        parent while the block has <= 16 columns and the padded zeros stay
        below a fifth of its entries. The factor of the symmetric pattern
        needs the same structure for L and U^T.
     3. Numeric factorization, multifrontal: per supernode (postorder) a
        dense front (its columns and rows) is assembled from K and the
        children's update matrices (a stack), its columns are eliminated
        with the diagonal pivots (dense LU on the panel, a triangular solve
        for U's block, one GEMM for the update matrix), L/U panels stored.
     4. Solve: forward and backward substitution supernode by supernode.
     Pivoting is static: the pivots are the diagonal of the fill-reducing
     order. This is safe here because K = sigma I + M with Re sigma > 0 is
     dominated by its shift for the step sizes GL3 is used with, but not
     guaranteed; so each factorization checks itself: a pivot below
     PHGMG_SPARSE_PIVTOL max|K| is replaced by that value, and when any was
     replaced or the largest factor entry exceeds PHGMG_SPARSE_GROWTH
     max|K|, the stepper drops the sparse factors and uses the band LU with
     partial pivoting for the rest of its life.
   Factors are kept across steps and, in phgmg_simulate_inputs (runs of
   one dt) and the automatic lambda's three full-model probe runs, across
   runs: one stepper serves them all (a linear model factors once).
   Prediction: the band factor has N (2kl + ku + 1) entries and about
   2 N kl (kl + ku) flops (kl, ku of the stage matrix's pattern); the sparse
   one the entries and flops of its supernodes. The stepper reuses factors
   across steps (a linear model factors once), so the solve cost decides:
   sparse when its factor has fewer than half the band's entries (a solve
   through a supernodal factor costs about twice a band solve per entry)
   and its factorization takes fewer flops. The analysis itself costs about
   one factorization's memory traffic. phgmg_ph_sparse_set_solver forces a
   choice (tests, comparisons). The choice and both predictions are in
   phgmg_ph_sparse_info. The sparse solver serves the GL3 stepper of a
   system with nl NONE or SEPARABLE; a GENERAL Hessian (banded by its
   callback) keeps the band LU.
   Descriptor models. With a mass matrix E the stage matrices are
   K(sigma) = sigma E + M (E in place of I). The analysis uses the pattern
   of M, of the identity and of E; the numeric assembly adds sigma times
   E's values (kept in the pattern of K) where the plain model adds sigma
   on the diagonal, for the real and the complex shift alike. Condensation
   needs K_AA diagonal and, so that the couplings K_AB, K_BA stay real for
   the complex shift, takes only states whose row and column of E hold
   nothing but the diagonal (a mass-spring model with E = blockdiag(I, Mc):
   the positions, as without E); a state that E couples to another is never
   condensed. Static pivots are checked and fall back to the band LU as
   above. An E with a zero row or column (the index-one path of 1.8, which
   condenses the algebraic lines in band or dense storage) keeps the band
   LU (forcing the sparse LU: PHGMG_ERR_UNSUPPORTED). Measured on a 2-D
   lattice whose momenta carry a mass matrix with the mesh's pattern
   (bench/bench_desc.c, AMD EPYC, medians of 3 paired runs): N = 10 082,
   1000 steps: band 16.3 s, sparse 1.26 s (13x); N = 100 352, 20 steps:
   band 62 s, sparse 1.06 s (62x).
   Memory. With the sparse LU the system is SPARSE: J, R, Q stay in the
   object's CSC copies and no band copy is made (a band of a 2-D lattice of
   317 x 317 masses, kb = 634, would take 3 (2 kb + 1) N doubles = 6.1 GB;
   its CSC copies take 11 MB). The other operations then need no band of
   the whole model either:
   - products with J, R, Q (right-hand sides, Hamiltonian, the reduced
     operators V^T M W of every method) go through the CSC copies;
   - phgmg_jr_factor (G = (J - R)^{-1} in GMG, rcond in the validation)
     factors J - R in band storage in the reverse Cuthill-McKee order of J - R
     alone: its bandwidth, not the model's (a mass-spring model's J - R pairs
     each position with its momentum: bandwidth 1);
   - the definiteness of Q (and of R + tol ||R||_1 I, semidefiniteness of
     R, for N above the dense-eigenvalue limit) is read from the pivots of
     the sparse LU of that matrix (static pivots, no exchanges): for a
     symmetric matrix they are the D of its L D L^T, all positive exactly
     when it is definite (Sylvester's law of inertia), and the elimination
     of a definite matrix needs no pivoting to be stable. When a pivot had
     to be replaced or the growth check fails, the band Cholesky of that
     matrix alone (in its own reverse Cuthill-McKee order) decides;
   - a stepper whose static pivots fail falls back to the band LU with band
     copies made inside the stepper (the O(N kb) memory is then spent);
   - a descriptor model's E is a fourth CSC copy (sys.E points at its
     values): products with E and E^T (the stepper's E Z, the Hamiltonian,
     the reductions' E V and E^T G) go through it; the checks of
     phgmg_ph_validate (E^T Q symmetric and definite, E nonsingular) and
     the factor of E a reduction of a descriptor model keeps (B' = E^{-1} B)
     work on band copies of E (and Q) made for that call and freed after:
     O(N kb) memory while they run, none held by the object.
   Measured on a 2-D lattice with N = 200 978 (bench/bench_sparse.sh),
   `phgmg reduce --simulate --steps 200 --method gmg-pod --r 20` peaks at
   about twice the snapshot matrix.


   9. CONFIGURATION MACROS (define before including) -----------------------------
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
     PHGMG_USE_OPENMP      with -fopenmp: phgmg_gemm runs its row blocks in
                           parallel (off by default; same results; OMP_NUM_THREADS)
     PHGMG_GL3_STEP_MAP_MAX_N  largest dense linear model that gets a step map
                           in the full-order stepper (default 1000)
     PHGMG_GL3_FLUSH_REL   relative flush threshold of tiny entries (1e-60)
     PHGMG_POD_RANDOMIZED_MIN  phgmg_pod with tol <= 0 switches to the randomized
                           POD when N*ns >= this (default 0: never; see phgmg_pod)
     PHGMG_POD_OVERSAMPLE, PHGMG_POD_POWER_ITERS, PHGMG_POD_SEED  its parameters
                           (20, 2, a fixed seed)
     PHGMG_POD_AUTO_MIN    phgmg_reduce takes the randomized POD (checked, exact
                           fallback) when N*ns >= this (default 2e7; <= 0: never)
     PHGMG_POD_CHECK_TOL   its acceptance: backward error <= this * sigma_1 (1e-10)
     PHGMG_ECSW_SCREEN_MIN phgmg_ecsw(_separable) screen candidates from this many
                           terms on (default 4096; no n x n Gram matrix)
     PHGMG_ECSW_SCREEN_ADD candidates added per screening round (default 64)
     PHGMG_ECSW_SCREEN_ROUNDS  cap on screening rounds (default 200)
     PHGMG_SPARSE_MIN_KB   sparse models keep the band LU without analysis up to
                           this half-bandwidth (default 8; manual 8.12)
     PHGMG_SPARSE_PIVTOL   the sparse LU's static pivot threshold, relative to
                           max|K| (default 1e-8)
     PHGMG_SPARSE_GROWTH   largest factor entry / max|K| the sparse LU accepts
                           before the stepper falls back to the band LU (1e8)
     PHGMG_GEMM_MC, PHGMG_GEMM_KC  the dense GEMM's cache blocks (64, a
                           multiple of 8, and 256; the packed block, MC*KC
                           doubles, lives on the stack: 128 KiB by default)
     PHGMG_NO_VECTOR_EXT   the plain C GEMM micro-kernel instead of the
                           GCC/Clang vector extensions it uses on AVX targets


   10. INDEX OF PUBLIC FUNCTIONS -------------------------------------------------
   Every public function, by header section (full contract at the declaration).
   result: phgmg_result_string
   ph:     phgmg_ph_validate, phgmg_ph_hamiltonian, phgmg_ph_gradient,
           phgmg_ph_rhs, phgmg_ph_output, phgmg_ph_apply,
           phgmg_jr_factor_create, phgmg_jr_solve, phgmg_jr_factor_destroy,
           phgmg_dae_create, phgmg_dae_system, phgmg_dae_nalg,
           phgmg_dae_restrict, phgmg_dae_embed, phgmg_dae_lift,
           phgmg_dae_destroy, phgmg_rcm, phgmg_ph_sparse_create, phgmg_ph_sparse_create_e,
           phgmg_ph_sparse_create_desc,
           phgmg_ph_sparse_system,
           phgmg_ph_sparse_perm, phgmg_ph_sparse_sep_idx,
           phgmg_ph_sparse_to_banded_order, phgmg_ph_sparse_to_user_order,
           phgmg_ph_sparse_destroy, phgmg_ph_sparse_set_solver,
           phgmg_gl3_create, phgmg_gl3_destroy,
           phgmg_gl3_step, phgmg_gl3_get_stats, phgmg_simulate,
           phgmg_gl3_coefficients
   online: phgmg_rom_check, phgmg_rom_eval_work_size, phgmg_rom_hamiltonian,
           phgmg_rom_gradient, phgmg_rom_rhs, phgmg_rom_output,
           phgmg_rom_structure, phgmg_rom_hessian, phgmg_rom_jacobian,
           phgmg_rom_stepper_memsize, phgmg_rom_stepper_memsize_dt,
           phgmg_rom_stepper_init, phgmg_rom_stepper_reset,
           phgmg_rom_stage_times, phgmg_rom_step
   reduce: phgmg_pod, phgmg_pod_randomized, phgmg_adjust_snapshots,
           phgmg_runs_columns, phgmg_simulate_inputs, phgmg_simulate_run,
           phgmg_reduce_opts_default, phgmg_reduce, phgmg_reduced_destroy,
           phgmg_reduced_rom, phgmg_reduced_N, phgmg_reduced_lift,
           phgmg_reduced_restrict, phgmg_reduced_dphi, phgmg_reduced_W,
           phgmg_reduced_simulate, phgmg_reduced_simulate_run,
           phgmg_reduced_validate, phgmg_rel_error,
           phgmg_err_red, phgmg_err_proj, phgmg_err_lowerbound,
           phgmg_err_energy, phgmg_study_create, phgmg_study_destroy,
           phgmg_study_basis, phgmg_study_reduce, phgmg_study_errors,
           phgmg_pod_hierarchical, phgmg_deim, phgmg_deim_select, phgmg_nnls,
           phgmg_ecsw, phgmg_ecsw_separable
   linear: phgmg_lyap, phgmg_care, phgmg_lyap_residual, phgmg_care_residual,
           phgmg_ph_abc, phgmg_bt, phgmg_prbt_riccati, phgmg_prbt,
           phgmg_linear_basis, phgmg_ss_transfer, phgmg_reduced_abc,
           phgmg_ss_error, phgmg_ss_compare
   export: phgmg_rom_serialized_size, phgmg_rom_serialize,
           phgmg_rom_deserialize_size, phgmg_rom_deserialize, phgmg_rom_save,
           phgmg_rom_load, phgmg_rom_export_c
   npy:    phgmg_npy_parse, phgmg_npy_serialize, phgmg_npy_free,
           phgmg_npy_read, phgmg_npy_write
   linalg: phgmg_gemm, phgmg_gemv, phgmg_lu_factor, phgmg_lu_solve,
           phgmg_lu_rcond, phgmg_norm1, phgmg_normf, phgmg_zlu_factor,
           phgmg_zlu_solve, phgmg_qr, phgmg_qrcp, phgmg_qr_form_q,
           phgmg_qr_apply, phgmg_lstsq, phgmg_svd, phgmg_sym_eig
   (124 functions; also the macros PHGMG_ROM_STEPPER_MEMSIZE_MAX and _MAX_CB.)
*/
#ifndef PHGMG_H_INCLUDED
#define PHGMG_H_INCLUDED

/* >>config ================================================================ */
#define PHGMG_VERSION_MAJOR 0
#define PHGMG_VERSION_MINOR 5
#define PHGMG_VERSION_PATCH 0
#define PHGMG_VERSION_STRING "0.5.0"

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
  X(PHGMG_ERR_UNSUPPORTED,     -16, "operation not supported for this model kind")       \
  X(PHGMG_ERR_Q_NOT_SYMMETRIC, -17, "Q is not symmetric")                               \
  X(PHGMG_ERR_Q_NOT_PD,        -18, "Q is not positive definite (semidefinite for a nonlinear H)")                       \
  X(PHGMG_ERR_DTYPE,           -19, "unsupported .npy dtype (complex, object, string, ...)") \
  X(PHGMG_ERR_INEXACT,         -20, "integer beyond 2^53 in magnitude: not exact as a double") \
  X(PHGMG_ERR_NOT_STABLE,      -21, "system not asymptotically stable (an undamped mode: eigenvalue on the imaginary axis)") \
  X(PHGMG_ERR_OVERFLOW,        -22, "a result overflows the double range (values too large in their units: rescale the data)") \
  X(PHGMG_ERR_TOL_UNREACHABLE, -23, "tolerance below what double precision can reach (relative tolerance < 1e-15)") \
  X(PHGMG_ERR_NOT_STABILIZABLE, -24, "no stabilizing Riccati solution: (A, K) not stabilizable or (A, L) not detectable") \
  X(PHGMG_ERR_STALE,           -25, "the system changed since the study was created (create the study again)") \
  X(PHGMG_ERR_STRUCTURE,       -26, "model fails the structure check (Qh not positive definite, R not PSD, or a step map not of its dt)") \
  X(PHGMG_ERR_STEP_MAP,        -27, "step map not stable in double precision at this dt (use a smaller dt)") \
  X(PHGMG_ERR_E_SINGULAR,      -28, "the mass matrix E is singular to working precision") \
  X(PHGMG_ERR_EQ_NOT_SYMMETRIC, -29, "E^T Q is not symmetric (descriptor model)")          \
  X(PHGMG_ERR_EQ_NOT_PD,       -30, "E^T Q is not positive definite (semidefinite for a nonlinear H)") \
  X(PHGMG_ERR_E_COUPLED,       -31, "a row of E at a nonlinear coordinate is not a positive multiple of the unit row") \
  X(PHGMG_ERR_FEEDTHROUGH,     -32, "feedthrough: [[R, P], [P^T, S]] not symmetric positive semidefinite or N not skew") \
  X(PHGMG_ERR_DAMPER,          -33, "a damper generates energy (s rho(s) < 0 for some s)") \
  X(PHGMG_ERR_PENCIL,          -34, "the pencil (E, (J - R) Q) is singular: the model does not determine its solution") \
  X(PHGMG_ERR_INDEX,           -35, "the descriptor model has index two or higher (index one is supported)")

typedef enum phgmg_result {
#define PHGMG__X(name, val, str) name = val,
  PHGMG__RESULT_LIST(PHGMG__X)
#undef PHGMG__X
  PHGMG__RESULT_END_ = -36
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

/* Every enumerated choice ends in a _COUNT: one more than its largest value
   (not a choice itself), for range checks and tables. */
/* PHGMG_SPARSE: only the system of a phgmg_ph_sparse object that chose the
   sparse LU (phgmg_ph_sparse_system): J, R, Q are then the value arrays of the
   object's compressed (CSC) copies, not arrays a caller can index. */
typedef enum phgmg_storage { PHGMG_DENSE = 0, PHGMG_BANDED = 1, PHGMG_SPARSE = 2,
                             PHGMG_STORAGE_COUNT } phgmg_storage;

typedef enum phgmg_nl_kind {
  PHGMG_NL_NONE = 0,      /* quadratic Hamiltonian only                          */
  PHGMG_NL_SEPARABLE = 1, /* H_nl(x) = sum_k w_k phi_k(x[idx_k])  (DEIM needs this) */
  PHGMG_NL_GENERAL = 2,   /* H_nl, grad and Hessian by callbacks                 */
  PHGMG_NL_COUNT
} phgmg_nl_kind;

/* Scalar callbacks of a separable nonlinear part: for term k (0-based, over the
   nsep terms) return phi_k(s), phi_k'(s), phi_k''(s). */
typedef double (*phgmg_phi_fn)(int k, double s, void *user);

typedef struct phgmg_ph_sparse phgmg_ph_sparse; /* sparse input, below */

typedef struct phgmg_ph_system {
  int N, m;
  phgmg_storage storage;   /* DENSE (default), BANDED (or SPARSE: below)     */
  int kb;                  /* half-bandwidth for BANDED                      */
  const double *J, *R, *Q; /* dense N x N or banded (2kb+1) x N              */
  const double *B;         /* N x m, ld = N                                   */
  /* nonlinear part of H */
  phgmg_nl_kind nl;
  int nsep;                /* SEPARABLE: number of terms                     */
  const int *sep_idx;      /* SEPARABLE: coordinate of term k (0-based)      */
  const double *sep_w;     /* SEPARABLE: weights (NULL = all 1)              */
  phgmg_phi_fn phi, dphi, ddphi;
  /* SEPARABLE, optional built-in exp-polynomial family, used iff poly_deg > 0
     or nexp > 0 (the callbacks phi/dphi/ddphi may then be NULL):
         phi_k(s) = sum_{j=0}^{poly_deg} c_j s^j + sum_{e<nexp} a_e exp(b_e s),
     c = poly + t (poly_deg+1), (a_e, b_e) = expo[2 (t nexp + e)], expo[2 (t nexp + e) + 1],
     with t = 0 for every term (phi_nfun 0 or 1) or t = k (phi_nfun == nsep, one
     function per term). poly may be NULL when poly_deg == 0 (c = 0); expo is
     needed iff nexp > 0. Limits: poly_deg <= 32, nexp <= 8, finite coefficients.
     E.g. Toda phi(s) = e^s - 1 - s: poly_deg = 1, poly = {-1, -1}, nexp = 1,
     expo = {1, 1}; cosh(s) = expo {0.5, 1, 0.5, -1}. Reduced models can be
     exported only when the nonlinearity is given this way. */
  int poly_deg;
  const double *poly;      /* (phi_nfun or 1) x (poly_deg+1) coefficients, constant term first */
  int nexp;                /* SEPARABLE: exponentials per function (0: none)            */
  const double *expo;      /* pairs (a_e, b_e): expo[2*(t*nexp+e)], expo[2*(t*nexp+e)+1] */
  int phi_nfun;            /* 0 or 1: one function for every term; nsep: one per term   */
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
  /* Descriptor form (NULL: E = I, the standard form above). With a mass
     matrix E (N x N, the storage and kb of J, R, Q; nonsingular, or with k
     zero rows and k zero columns: algebraic constraints of index one, manual
     1.8) the model is
         E x' = (J - R) z(x) + B u,   y = B^T z(x),   E^T z(x) = grad H(x),
     where the co-state z(x) = Q x + grad H_nl(x) is what phgmg_ph_gradient
     returns (phgmg_ph_rhs gives E x' = (J - R) z + B u) and the Hamiltonian is
         H(x) = 1/2 x^T E^T Q x + sum_k E(i_k, i_k) w_k phi_k(x[i_k]),
     i_k = sep_idx[k] (phgmg_ph_hamiltonian). E^T Q must be symmetric positive
     definite (semidefinite with a nonlinear part) and, for a separable part,
     row i_k of E must be E(i_k, i_k) e_{i_k}^T with E(i_k, i_k) > 0 (the
     nonlinear coordinates carry no mass coupling), so that E^T z is a
     gradient. A GENERAL part and the shifted_* callbacks are not supported
     with E (PHGMG_ERR_UNSUPPORTED). The stepper never forms E^{-1}: E enters
     its Newton matrices (sigma E - (J - R) Hess) and stage residuals. See
     manual 1.6 for the reduction. */
  const double *E;
  /* Feedthrough (each NULL = 0): P (N x m, ld N), S (m x m, symmetric), Nskew
     (m x m, skew), column-major:
         E x' = (J - R) z + (B - P) u,   y = (B + P)^T z + (S + Nskew) u,
     with the dissipation block [[R, P], [P^T, S]] positive semidefinite, so
     that dH/dt = y^T u - [z; u]^T [[R, P], [P^T, S]] [z; u] <= y^T u. The full
     model (validation, stepper, outputs and energy of phgmg_simulate) takes
     them; phgmg_ph_output gives (B + P)^T z only (it has no u). GMG-POD,
     SP1 and SP2 keep the feedthrough (manual 1.6); GMG-QM and your own
     manifold give PHGMG_ERR_UNSUPPORTED. */
  const double *P, *S, *Nskew;
  /* Nonlinear dissipation (ndamp = 0: none): ndamp dampers, damper k acting
     on s_k = c_k^T z, c_k = e_i - e_j (i = damp_i[k], j = damp_j[k]; damp_j
     NULL or damp_j[k] < 0: c_k = e_i), with the force law rho_k:
         E x' = (J - R) z - sum_k c_k rho_k(c_k^T z) + (B - P) u,
     so that dH/dt = y^T u - (the dissipation of R, P, S) - sum_k s_k rho_k(s_k).
     rho_k is either the odd polynomial
         rho_k(s) = sum_{d=1}^{damp_deg} a_d s^d,  a = damp_poly + t (damp_deg + 1),
     t = 0 (damp_nfun 0 or 1: one law for all) or t = k (damp_nfun == ndamp),
     a_0 and every even a_d zero and every odd a_d >= 0 (e.g. a linear plus
     cubic damper c1 s + c3 s^3: damp_deg = 3, {0, c1, 0, c3}), checked --
     PHGMG_ERR_DAMPER otherwise -- or the callback damp_fn(k, s, d, user)
     filling d[0] = rho_k(s), d[1] = rho_k'(s) (used when damp_poly is NULL;
     s rho_k(s) >= 0 is checked wherever it is evaluated: PHGMG_ERR_DAMPER).
     damp_deg <= 15. Banded storage: |i - j| <= kb. Not with the shifted_*
     callbacks (PHGMG_ERR_UNSUPPORTED). Reduction: GMG-POD, SP1, SP2 (manual
     1.7). */
  int ndamp;
  const int *damp_i, *damp_j;
  int damp_deg, damp_nfun;
  const double *damp_poly;
  void (*damp_fn)(int k, double s, double d[2], void *user);
  void *damp_user;
  /* Set by phgmg_ph_sparse_system (NULL otherwise): the sparse model this
     system comes from. When the object chose the sparse LU (manual 8.12)
     the storage is SPARSE: J, R, Q are the object's compressed copies (not
     for indexing; the library reads them through sparse) and the GL3 stepper
     solves its stage systems with the sparse LU; else BANDED. */
  const phgmg_ph_sparse *sparse;
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
   ||R||_1 >= ||R||_2). Q positive definite when H is quadratic (nl == NONE):
   exact for a diagonal Q (every diagonal entry > 0), else a Cholesky
   factorization of Q (dense, or in band storage, O(N kb^2)) must meet only
   positive pivots (no tolerance: positive definite to working precision).
   With a nonlinear part Q need only be positive SEMIdefinite (the nonlinear
   part may carry the convexity, e.g. a Toda chain's H = |p|^2/2 + sum
   (e^l - 1 - l) has Q = 0 on the l block): the same test on Q + tol ||Q||_1 I. Checks run in this order and the first
   failure is returned: PHGMG_ERR_INVALID_ARG (NULL pointers, missing
   callbacks) / _SIZE / _NANINF / _NOT_SKEW / _NOT_SYMMETRIC (R) /
   _Q_NOT_SYMMETRIC / _NOT_PSD (R) / _Q_NOT_PD / _RANK / _SINGULAR, or _NOMEM.
   The system is never modified. */
PHGMG_DEF phgmg_result phgmg_ph_validate(const phgmg_ph_system *sys, double tol,
                                         double *rcond_out, const phgmg_allocator *alloc);

/* >>dae ------------------------------------------------------------------
   Index-one descriptor models (manual 1.8): E with k zero rows (algebraic
   equations) and k zero columns (algebraic variables). phgmg_dae_create
   checks the index (PHGMG_ERR_INDEX for index >= 2, PHGMG_ERR_PENCIL for a
   singular pencil, PHGMG_ERR_E_SINGULAR when E is singular but not of this
   form and not dense (a dense E without zero lines is rotated into it,
   manual 1.8; phgmg_dae_restrict/_embed/_lift then rotate back), PHGMG_ERR_EQ_NOT_SYMMETRIC when the kept co-states depend on the
   algebraic variables, PHGMG_ERR_UNSUPPORTED for a separable coordinate or a
   damper on an algebraic line, k > 4096, or an elimination whose dense
   blocks would exceed 1e8 doubles) and builds the condensed model: a
   port-Hamiltonian ODE in the n = N - k differential coordinates, with the
   same outputs, Hamiltonian and dissipation (phgmg_dae_system; feedthrough P,
   S, Nskew where a constraint touches a port), which it validates
   (phgmg_ph_validate's codes). Validate the full model with
   phgmg_ph_validate first (it runs this check too). With k = 0 the
   condensed model is the model itself. phgmg_simulate and
   phgmg_simulate_run take index-one models directly (consistent states);
   the stepper object (phgmg_gl3_create), phgmg_simulate_inputs and
   phgmg_reduce return PHGMG_ERR_UNSUPPORTED for them: give them
   phgmg_dae_system(d), with snapshots restricted by phgmg_dae_restrict. The object keeps pointers into sys
   (the nonlinear part's functions and weights): sys must outlive it. */
typedef struct phgmg_dae phgmg_dae;
PHGMG_DEF phgmg_result phgmg_dae_create(phgmg_dae **out, const phgmg_ph_system *sys, double tol,
                                        const phgmg_allocator *alloc);
/* The condensed model (valid while d lives); k = phgmg_dae_nalg(d). */
PHGMG_DEF const phgmg_ph_system *phgmg_dae_system(const phgmg_dae *d);
PHGMG_DEF int phgmg_dae_nalg(const phgmg_dae *d);
/* xi (n) = the differential coordinates of x (N), in their order in x. */
PHGMG_DEF void phgmg_dae_restrict(const phgmg_dae *d, const double *x, double *xi);
/* x (N) = xi at the differential coordinates, 0 at the algebraic ones (for
   a basis, whose algebraic rows follow from the constraints). */
PHGMG_DEF void phgmg_dae_embed(const phgmg_dae *d, const double *xi, double *x);
/* x (N) = the consistent state with differential part xi at input u (m; NULL
   = 0): the algebraic variables solve the constraints. Uses d's scratch
   memory: one thread per object. */
PHGMG_DEF void phgmg_dae_lift(phgmg_dae *d, const double *xi, const double *u, double *x);
PHGMG_DEF void phgmg_dae_destroy(phgmg_dae *d);

/* Hamiltonian, its gradient and the output at a state. These evaluators do
   not take an allocator: where they need a scratch vector of N doubles
   (gradient of a GENERAL part, rhs, output) it is on the stack for N <= 256
   and from the default allocator above; if that fails the result is NaN. */
PHGMG_DEF double phgmg_ph_hamiltonian(const phgmg_ph_system *sys, const double *x);
PHGMG_DEF void phgmg_ph_gradient(const phgmg_ph_system *sys, const double *x, double *g);
/* f = (J - R) grad H(x) + B u  (u may be NULL = 0); with feedthrough and
   dampers (E x' =) (J - R) z - sum_k c_k rho_k(c_k^T z) + (B - P) u (all NaN
   when a callback damper generates energy). */
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

/* --- sparse input ---------------------------------------------------------
   A matrix in compressed sparse column form (0-based, SciPy's csc_matrix
   fields indptr/indices/data): column j holds rows rowidx[colptr[j] ..
   colptr[j+1]-1], strictly increasing within the column, with values in
   `values`; colptr[0] = 0, colptr[n_cols] = nnz. Explicit zeros are allowed
   (they count in the pattern). Views: never owned. */
typedef struct phgmg_csc {
  int n_rows, n_cols;
  const int *colptr;    /* n_cols + 1 */
  const int *rowidx;    /* nnz        */
  const double *values; /* nnz        */
} phgmg_csc;

/* Reverse Cuthill-McKee ordering of the symmetric pattern of |A_0| + ... +
   |A_{na-1}| (each N x N CSC; the pattern is symmetrized, the diagonal
   ignored): per connected component a breadth-first search from a
   pseudo-peripheral node (George-Liu), neighbours visited by increasing
   degree, the whole order reversed. perm (N) receives the new order:
   position i holds original index perm[i]. kb_out (may be NULL): the
   half-bandwidth max |inv(perm)[r] - inv(perm)[c]| over every stored entry.
   O(nnz log) time, O(N + nnz) memory. PHGMG_ERR_INVALID_ARG (NULL), _SIZE
   (N < 1, na < 1, a matrix not N x N), _FORMAT (colptr not starting at 0 or
   decreasing, row index out of range, unsorted or duplicate rows), _NOMEM. */
PHGMG_DEF phgmg_result phgmg_rcm(int N, int na, const phgmg_csc *const *A, int *perm, int *kb_out,
                                 const phgmg_allocator *alloc);

/* A sparse pH system in a bandwidth-reducing order. phgmg_ph_sparse_create
   takes J, R, Q as N x N CSC matrices in the caller's ("user") ordering and B
   dense (N x m, ld N) or, if B is NULL, as the N x m CSC matrix Bcsc; it
   computes phgmg_rcm of J, R, Q, keeps the better of that order and the given
   one (smaller half-bandwidth; a tie keeps the given order), and stores
   P^T J P, P^T R P, P^T Q P as CSC matrices with that half-bandwidth kb and
   P^T B dense, where P is the permutation: state entry i of the internal
   ("banded") ordering is entry perm[i] of the user's. It then picks the
   stage-matrix solver (>>sparse). With the band LU it also stores J, R, Q
   in band storage (>>ph above); with the sparse LU it does not: memory
   O(nnz + the sparse factor), never O(N kb) (info.band_copy, info.bytes).
   phgmg_ph_sparse_system gives the ready phgmg_ph_system (nl = NONE;
   storage BANDED or SPARSE by that choice): copy it to add a SEPARABLE
   nonlinear part. A SPARSE system serves validation, simulation and every
   reduction method; it refuses (PHGMG_ERR_UNSUPPORTED) a GENERAL nonlinear
   part, dampers, feedthrough, E and the shifted-solve callbacks, which need
   band storage: call phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_BAND, ..)
   first (a copy made before that call no longer matches the object: copy
   again). Nothing is densified. Banded: the GL3 stepper, phgmg_jr_factor,
   phgmg_ph_validate cost O(N kb^2), solves O(N kb). Sparse: manual 8.12.
   Call phgmg_ph_validate on the system for the structural checks
   (skew J, symmetric PSD R, ...: the usual codes; a nonsymmetric pattern is
   fine, the band covers the symmetrized pattern). info (may be NULL): the
   half-bandwidths, and wide = 1 when kb > N/4: the banded path then costs
   about as much as dense storage or more ((2kb+1) N doubles per matrix, LU
   fill up to 3kb+1 rows) -- such a model is better given dense.
   Errors: PHGMG_ERR_INVALID_ARG (NULL out/J/R/Q, both B and Bcsc NULL),
   _SIZE (N < 1, m < 1 or m > N, a matrix of the wrong shape), _FORMAT (as
   phgmg_rcm, also for Bcsc), _NANINF (a stored value or an entry of B not
   finite), _NOMEM. *out is NULL on failure.

   Orderings. Every reduction is permutation-equivariant (manual 8.4): reduce
   the internal system with snapshots in the internal ordering
   (phgmg_ph_sparse_to_banded_order on the user's snapshot matrix, or simulate
   the internal system). The reduced model (phgmg_reduced_rom) is then the
   same as the user-ordered one; only full-dimension quantities are permuted:
   phgmg_reduced_lift/_dphi/_W give internal-order vectors and rows (map them
   with phgmg_ph_sparse_to_user_order), phgmg_reduced_restrict and the error
   measures take internal-order states. A GENERAL nonlinear part's callbacks
   receive internal-order states (and a banded Hessian in the internal order);
   a SEPARABLE one needs its coordinates remapped (phgmg_ph_sparse_sep_idx).

       phgmg_ph_sparse *sp; phgmg_ph_sparse_info inf;
       phgmg_ph_sparse_create(&sp, N, m, &J, &R, &Q, B, NULL, &inf, NULL);
       phgmg_ph_system sys = *phgmg_ph_sparse_system(sp);
       sys.nl = PHGMG_NL_SEPARABLE; ... phi, poly ...;
       phgmg_ph_sparse_sep_idx(sp, nsep, my_idx, NULL, &sys);   // remapped
       phgmg_ph_sparse_to_banded_order(sp, 1, x0_user, N, x0, N);
       phgmg_simulate(&sys, x0, ...X...);                 // internal order
       phgmg_ph_sparse_to_user_order(sp, nsteps + 1, X, N, X_user, N);
       phgmg_ph_sparse_destroy(sp);                       // after sys's last use */
typedef struct phgmg_ph_sparse_info {
  int kb;        /* half-bandwidth of the stored (internal) ordering        */
  int kb_input;  /* half-bandwidth of the given ordering                    */
  int kb_rcm;    /* half-bandwidth of the reverse Cuthill-McKee ordering    */
  int permuted;  /* 1: RCM order used, 0: the given order kept (perm = id)  */
  int wide;      /* 1: kb > N/4, banded costs about as much as dense or more */
  long nnz;      /* stored entries of J, R, Q (and E) together              */
  /* The solver of the GL3 stage systems (manual 8.12): */
  int solver;         /* PHGMG_SOLVER_BAND or PHGMG_SOLVER_SPARSE_LU           */
  int kl, ku;         /* lower/upper bandwidth of the stage matrix             */
  double lu_band;     /* predicted entries of one band factor, N (2kl + ku + 1) */
  double lu_sparse;   /* entries of one sparse factor (0: not analysed)        */
  double flops_band;  /* predicted flops of one real band factorization        */
  double flops_sparse;/* of one real sparse factorization (0: not analysed)    */
  int supernodes;     /* supernodes of the sparse factor (0: not analysed)     */
  int front_max;      /* largest dense front (order)                           */
  int condensed;      /* states eliminated first by block elimination (manual 8.12) */
  int colperm;        /* columns moved by the pivot matching of a descriptor model (manual 8.12) */
  int band_copy;      /* 1: the object holds band copies of J, R, Q (and E) (band solver) */
  double bytes;       /* memory the object holds now (its arrays, the analysis)   */
} phgmg_ph_sparse_info;
PHGMG_DEF phgmg_result phgmg_ph_sparse_create(phgmg_ph_sparse **out, int N, int m, const phgmg_csc *J,
                                              const phgmg_csc *R, const phgmg_csc *Q, const double *B,
                                              const phgmg_csc *Bcsc, phgmg_ph_sparse_info *info,
                                              const phgmg_allocator *alloc);
/* The same for a descriptor model (phgmg_ph_system.E): E (N x N CSC, the
   user's ordering) joins J, R, Q in the ordering and the band; E NULL is
   phgmg_ph_sparse_create. info->nnz counts E's entries too. */
PHGMG_DEF phgmg_result phgmg_ph_sparse_create_e(phgmg_ph_sparse **out, int N, int m, const phgmg_csc *J,
                                                const phgmg_csc *R, const phgmg_csc *Q, const phgmg_csc *E,
                                                const double *B, const phgmg_csc *Bcsc,
                                                phgmg_ph_sparse_info *info, const phgmg_allocator *alloc);
/* The same from one description (no positional argument list to get wrong):
   J, R, Q required; E optional (E.colptr NULL: E = I); B dense (N x m, ld N)
   or, if B is NULL, the CSC matrix Bcsc. Equivalent to
   phgmg_ph_sparse_create_e(out, d->N, d->m, &d->J, &d->R, &d->Q, E or NULL,
   d->B, B ? NULL : &d->Bcsc, info, alloc); PHGMG_ERR_INVALID_ARG for NULL d. */
typedef struct phgmg_ph_sparse_desc {
  int N, m;
  phgmg_csc J, R, Q;  /* N x N, the user's ordering                        */
  phgmg_csc E;        /* descriptor models; zeroed (colptr NULL): E = I      */
  const double *B;    /* N x m dense, ld N; NULL: Bcsc                       */
  phgmg_csc Bcsc;     /* N x m CSC, used when B is NULL                      */
} phgmg_ph_sparse_desc;
PHGMG_DEF phgmg_result phgmg_ph_sparse_create_desc(phgmg_ph_sparse **out, const phgmg_ph_sparse_desc *d,
                                                   phgmg_ph_sparse_info *info, const phgmg_allocator *alloc);
/* The banded, permuted system (valid until destroy; NULL for NULL). */
PHGMG_DEF const phgmg_ph_system *phgmg_ph_sparse_system(const phgmg_ph_sparse *sp);
/* The permutation (N): internal index i is user index perm[i]; NULL for NULL. */
PHGMG_DEF const int *phgmg_ph_sparse_perm(const phgmg_ph_sparse *sp);
/* Remap a separable part's coordinates: term k acts on user coordinate
   sep_idx_user[k]; stores the internal coordinates in sp (replacing an
   earlier call's array) and, if sys is not NULL, sets sys->nsep = nsep and
   sys->sep_idx to that array (term order, weights and phi_k are unchanged).
   idx_out (may be NULL) also receives the nsep internal coordinates.
   PHGMG_ERR_INVALID_ARG (NULL sp or sep_idx_user), _SIZE (nsep < 1, an
   index outside 0..N-1), _NOMEM. */
PHGMG_DEF phgmg_result phgmg_ph_sparse_sep_idx(phgmg_ph_sparse *sp, int nsep, const int *sep_idx_user,
                                               int *idx_out, phgmg_ph_system *sys);
/* Y (N x ncols, ldy) = rows of X (N x ncols, ldx) moved from the user's to
   the internal ordering: Y[i] = X[perm[i]]; _to_user_order the inverse,
   Y[perm[i]] = X[i]. Snapshot matrices, trajectories, lifted states.
   O(N ncols). In place when X == Y with ldx == ldy (one column of scratch
   from the object's allocator); any other overlap of X and Y:
   PHGMG_ERR_INVALID_ARG, Y untouched. Also _INVALID_ARG for NULL, _SIZE for
   ncols < 0 or a leading dimension < N, _NOMEM. */
PHGMG_DEF phgmg_result phgmg_ph_sparse_to_banded_order(const phgmg_ph_sparse *sp, int ncols, const double *X,
                                                       int ldx, double *Y, int ldy);
PHGMG_DEF phgmg_result phgmg_ph_sparse_to_user_order(const phgmg_ph_sparse *sp, int ncols, const double *X,
                                                     int ldx, double *Y, int ldy);
/* Frees the object and its arrays (NULL is fine). */
PHGMG_DEF void phgmg_ph_sparse_destroy(phgmg_ph_sparse *sp);

/* >>sparse ---------------------------------------------------------------
   The stage-matrix solver of a phgmg_ph_sparse model: the band LU, or the
   library's own sparse LU (condensation, nested dissection, supernodal
   multifrontal factorization with checked static pivots), chosen by
   predicted cost (PHGMG_SOLVER_AUTO) when the model is created. How to use
   it: manual 2.6; how it works, when it falls back to the band LU and what
   memory it needs: manual 8.12. */
#ifndef PHGMG_SPARSE_MIN_KB
#define PHGMG_SPARSE_MIN_KB 8      /* band without analysis up to this kb       */
#endif
#ifndef PHGMG_SPARSE_PIVTOL
#define PHGMG_SPARSE_PIVTOL 1e-8   /* static pivot threshold, relative to max|K| */
#endif
#ifndef PHGMG_SPARSE_GROWTH
#define PHGMG_SPARSE_GROWTH 1e8    /* largest factor entry / max|K| accepted     */
#endif
enum { PHGMG_SOLVER_AUTO = 0, PHGMG_SOLVER_BAND = 1, PHGMG_SOLVER_SPARSE_LU = 2 };
/* Force the stage-matrix solver of steppers created from now on:
   PHGMG_SOLVER_BAND, _SPARSE_LU (runs the analysis if not done) or _AUTO
   (the prediction). The object's system follows: BANDED with band copies of
   J, R, Q made here for the band LU, SPARSE with them freed for the sparse
   LU; a copy of phgmg_ph_sparse_system made before the call no longer
   matches (copy it again). info (may be NULL) is refreshed.
   PHGMG_ERR_INVALID_ARG (NULL sp, unknown solver), _NOMEM (the object is
   unchanged). */
PHGMG_DEF phgmg_result phgmg_ph_sparse_set_solver(phgmg_ph_sparse *sp, int solver,
                                                  phgmg_ph_sparse_info *info);

/* >>gl3 =================================================================== */
/* 3-stage Gauss-Legendre (order 6) for the full model: simplified Newton on
   the transformed stage system, factors reused across steps, a precomputed
   step map for linear models with a fixed step (unless opts.no_step_map).
   How the iteration, the starting guess and the flushing of tiny entries
   work: manual 8.1 and 8.10.
   - Tolerance: an explicit opts.tol is absolute (units of the state); the
     default (opts.tol = 0) is 1e-10 times max(1, ||x_n||_inf, ||Z||_inf).
   - Step map: nl == NONE, DENSE storage and N <= PHGMG_GL3_STEP_MAP_MAX_N
     (default 1000; 4 N^2 + 12 N m doubles, O(N^3) at create): x+ = Phi x +
     Gam [u_1; u_2; u_3] and the stage gradients by similar maps. A linear
     system otherwise factors once and converges in one update per step.
   - Stats: newton_iters counts updates (linear solves), rhs_evals counts
     evaluations of f at one state (3 per stage-system evaluation),
     factorizations counts (real + complex) factorization pairs, failures counts
     Newton attempts that failed (including ones a retry rescued) and steps that
     returned an error.
   - The floating-point environment (rounding mode, MXCSR/FTZ/DAZ) is
     neither read nor changed. */
#ifndef PHGMG_GL3_STEP_MAP_MAX_N
#define PHGMG_GL3_STEP_MAP_MAX_N 1000
#endif
#ifndef PHGMG_GL3_FLUSH_REL
#define PHGMG_GL3_FLUSH_REL 1e-60 /* relative flush threshold (manual 8.10)     */
#endif

/* u(t) into u[m]. */
typedef void (*phgmg_input_fn)(double t, double *u, void *user);

typedef struct phgmg_gl3_opts {
  double tol;          /* Newton tolerance on the stage residual, inf-norm (0: 1e-10,
                          relative to states / stage increments above 1; see above) */
  int max_iter;        /* Newton iteration cap per step (0: 10)                      */
  int no_step_map;     /* 1: never use the precomputed linear step map               */
  double contraction;  /* refactor when the contraction rate exceeds this (0: 0.5)    */
  int keep_tiny;       /* 1: never flush tiny entries (manual 8.10)                 */
} phgmg_gl3_opts;

typedef struct phgmg_gl3_stats {
  long steps, newton_iters, factorizations, rhs_evals, failures;
  double max_residual;  /* largest final stage residual over the steps */
  /* The stage-matrix solver (manual 8.12): sparse_lu = 1 while the stepper
     solves with the sparse LU; band_fallback = 1 once its checked static
     pivots failed and it switched to the band LU with partial pivoting for
     the rest of its life (slower, O(N kb) memory: sparse_lu is then 0). */
  int sparse_lu, band_fallback;
} phgmg_gl3_stats;

/* Energy bookkeeping of one run, per grid point n = 0..nsteps:
   H[n] = H(x_n), S[n] = supplied energy up to t_n (h sum b_i y_i^T u_i),
   D[n] = dissipated energy up to t_n (h sum b_i gradH(Y_i)^T R gradH(Y_i),
   plus the dampers' h sum b_i sum_k s_k rho_k(s_k), manual 1.7),
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

/* >>online ================================================================ */
/* Reduced models online: allocation-free, no globals, no stdio, no VLAs, in
   the build's scalar phgmg_real (double, or float with PHGMG_REAL_FLOAT).
   A phgmg_rom is a set of non-owning const views (so an exported model can
   sit in flash as static const arrays). The reduced model is the pH system
       x' = K(x) grad H(x) + Bh u,   y = Bh^T grad H(x),
       K(x) = J(x) - R(x)  (J skew, R symmetric positive semidefinite),
   with, for a LINEAR map phi(x) = V0 x:   K constant,
       H(x) = 1/2 x^T Qh x + sum_j w_j phi_j(P0_j x),
   and for the QUADRATIC map phi(x) = V0 x + V2 q(x2), q = M (x2 kron x2),
   x = (x1, x2), x1 in R^m, x2 in R^p, p = r - m:
       K(x) = (Dphi^T G Dphi)^{-1},  G = (J - R)^{-1},  Dphi = V0 + V2 [0, L(x2)],
       L(:,k) = sum_j Ms(:, k*p + j) x2_j,   q = L x2 / 2,
       H(x) = 1/2 phi^T Q phi + sum_j w_j phi_j(P0_j x + P1_j q),
   where every product with N-dimensional data was precomputed offline
   (G00 = V0^T G V0, ... see the fields). The online cost is independent of N.
   phi_j is an exp-polynomial (shared or one per kept term) or a callback
   (phi_cb); q may come from a callback eta_cb instead of Ms; a general
   Hamiltonian part may be added by ham_cb (see the fields at the end). */
#ifdef __cplusplus
extern "C" {
#endif

typedef enum phgmg_rom_kind { PHGMG_ROM_LINEAR = 1, PHGMG_ROM_QUADRATIC = 2, PHGMG_ROM_KIND_COUNT } phgmg_rom_kind;
typedef enum phgmg_method {
  PHGMG_METHOD_GMG_POD = 1, /* phi = [B, Vbar] x, GMG reduction (paper 4.2.1)         */
  PHGMG_METHOD_GMG_QM = 2,  /* quadratic manifold, GMG reduction (paper 4.2.2)        */
  PHGMG_METHOD_SP1 = 3,     /* SP1-POD: phi = V_POD x, W = QV(V^TQV)^-1 (eq. 5.3)     */
  PHGMG_METHOD_SP2 = 4,     /* SP2-POD: W = V_gradH (V_POD^T V_gradH)^-1 (manual 8.8) */
  PHGMG_METHOD_GMG_MANIFOLD = 5, /* your own manifold phi = [B, V1] x + V2 eta(x2), GMG reduction */
  PHGMG_METHOD_PRBT = 6,    /* positive-real balanced truncation, pH form (phgmg_prbt, >>linear) */
  PHGMG_METHOD_COUNT
} phgmg_method;

/* A manifold map eta: R^p -> R^rn (p = r - m) and its derivatives at x2:
   q = eta(x2) (rn), Dq = d eta / d x2 (rn x p, column-major), D2q (rn x p*p):
   D2q(:, k*p + j) = d^2 eta / dx2_k dx2_j. Any output may be NULL (not needed
   by the caller). Used by phgmg_reduce_opts.qm.eta and phgmg_rom.eta_cb. */
typedef void (*phgmg_eta_fn)(const phgmg_real *x2, phgmg_real *q, phgmg_real *Dq, phgmg_real *D2q, void *user);

#define PHGMG_ROM_MAGIC 0x50484731u /* "PHG1" */

typedef struct phgmg_rom {
  int kind;      /* phgmg_rom_kind                                   */
  int method;    /* phgmg_method (informative)                       */
  int r, m;      /* reduced order, ports                             */
  int rn;        /* QUADRATIC: lifting dimension r_n, else 0         */
  int nd;        /* separable nonlinear terms kept online (DEIM points), 0 = quadratic H */
  int poly_deg;  /* degree of the polynomial part of phi (nd > 0; see nexp/nphi below) */
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
  const phgmg_real *Ms;   /* rn x p*p symmetrised M: Ms(:,k*p+j) = M(:,k*p+j) + M(:,j*p+k)
                             (symmetric in (k, j); the online code may read either order) */
  /* separable nonlinear part (nd > 0) */
  const phgmg_real *P0;   /* nd x r   rows of V0 at the kept coordinates */
  const phgmg_real *P1;   /* nd x rn  rows of V2 (QUADRATIC)             */
  const phgmg_real *w;    /* nd       weights (structure-preserving DEIM) */
  const phgmg_real *poly; /* (nphi or 1) x (poly_deg+1) coefficients of phi, constant first */
  /* precomputed GL3 step map (LINEAR, nd == 0; NULL if absent) for step dt:
     x+ = Phi x + Gam u3, stage values Y = SX x + SU u3 (for the energy). */
  phgmg_real dt;
  const phgmg_real *Phi;  /* r x r    */
  const phgmg_real *Gam;  /* r x 3m   (u3 = [u(t+c1 h); u(t+c2 h); u(t+c3 h)]) */
  const phgmg_real *SX;   /* 3r x r   */
  const phgmg_real *SU;   /* 3r x 3m  */
  /* separable nonlinearity beyond a shared polynomial (nd > 0). Term j of the
     reduced Hamiltonian is w_j phi_j(s_j), s_j = P0_j x (+ P1_j q), with
         phi_j(s) = sum_{i<=poly_deg} c_i s^i + sum_{e<nexp} a_e exp(b_e s),
     c = poly + t (poly_deg+1), (a_e, b_e) = expo[2 (t nexp + e)], [... + 1],
     t = 0 (nphi 0 or 1) or t = j (nphi == nd). poly may be NULL if poly_deg == 0. */
  int nexp;                 /* separable: exponentials per function (0: none), <= 8    */
  int nphi;                 /* 0/1: one function for every kept term; nd: one per kept term
                               (then poly is nd x (poly_deg+1), row j = kept term j)  */
  const phgmg_real *expo;   /* nphi (or 1) x nexp pairs (a, b), like phgmg_ph_system */
  void (*phi_cb)(int term, phgmg_real s, phgmg_real d[3], void *user); /* if set: overrides
                               poly/expo; d = phi, phi', phi'' of full-model term `term` */
  const int *term;          /* nd: full-model index of each kept term (passed to phi_cb; NULL: j) */
  void *phi_user;
  /* QUADRATIC kind, manifold by callback instead of Ms:
     phi(x) = V0 x + V2 eta(x2), x2 = x[m..r-1] (p = r - m), eta: R^p -> R^rn.
     eta_cb fills q = eta(x2) (rn), Dq = d eta/d x2 (rn x p, col-major) and
     D2q (rn x p*p, same layout as Ms: D2q(:, k*p + j) = d^2 eta / dx2_k dx2_j);
     any output pointer may be NULL when not needed. For the built-in quadratic map
     q = M(x2 kron x2) = L x2 / 2, Dq = L, D2q = Ms. With eta_cb set, Ms is not read.
     The Jacobian / structure formulas above hold with L = Dq. */
  void (*eta_cb)(const phgmg_real *x2, phgmg_real *q, phgmg_real *Dq, phgmg_real *D2q, void *user);
  void *eta_user;
  /* general nonlinear Hamiltonian part by callback on the REDUCED state (not exportable;
     used for PHGMG_NL_GENERAL systems, whose reduced model evaluates it in full dimension):
     adds Hn(x) to H, its gradient (r) to grad H and its Hessian (r x r) to the Hessian.
     The callback WRITES (does not add to) its non-NULL outputs: *Hn, g (r), Hs
     (r x r, col-major, symmetric); the library adds them. Any output pointer may be NULL.
     Workspace: phgmg_rom_eval_work_size / the stepper memsize include the room the
     callbacks need; for static buffers use PHGMG_ROM_STEPPER_MEMSIZE_MAX_CB. */
  void (*ham_cb)(const phgmg_real *x, phgmg_real *Hn, phgmg_real *g, phgmg_real *Hs, void *user);
  void *ham_user;
  /* training envelope (optional, NULL = none): per reduced coordinate, the
     range of the training snapshots' reduced coordinates rho(x_j), widened
     on each side by 10 % of its width plus 2 % of the largest width. The stepper counts the steps that end
     outside it (phgmg_rom_stats.outside_steps): the "left the training
     region" indicator of a deployed model. */
  const phgmg_real *env_lo, *env_hi; /* r each */
  /* QUADRATIC (optional, NULL = none): 1 value, 1.2 times the largest size
     ||M (x2 kron x2)|| of the quadratic correction over the training
     snapshots; steps whose correction is larger are counted in
     phgmg_rom_stats.q_outside_steps (0 for M = 0). */
  const phgmg_real *q_max;
  /* Affine reference state xbar (optional, NULL = none; manual 3.6):
     phi(x) = xbar + V0 x (+ V2 q). The energy H(phi(x)) then gains the terms
     x^T g0 + q^T g2 + h0 of the quadratic part, the separable terms their
     arguments' offsets xbar at the kept coordinates, and the full state 0 is
     represented by the reduced state xr_rest = rho(0):
       ref_g   r + rn + 1 values [g0; g2; h0]: g0 = V0^T Q xbar (r), g2 = V2^T Q
               xbar (rn, QUADRATIC), h0 = 1/2 xbar^T Q xbar (descriptor
               models: E^T Q for Q); g0 = 0 with a step map;
       ref_s   nd values: xbar at the kept coordinates (s_j += ref_s[j]);
       xr_rest r values: the reduced state of the full state 0 (the initial
               state of a run from rest). */
  const phgmg_real *ref_g, *ref_s, *xr_rest;
  /* nonlinear dissipation (LINEAR kind; ndamp = 0: none): ndamp reduced
     dampers, f = K g - sum_j dw_j Cd_j rho_j(Cd_j^T g) + Bh u, g = grad H(x),
     with dw_j >= 0 and rho_j(s) = sum_{d=1}^{damp_deg} a_d s^d (odd, a_d >= 0;
     a = dpoly + t (damp_deg + 1), t = 0 (damp_nphi 0 or 1) or j (damp_nphi ==
     ndamp)), or damp_cb(dterm[j], s, d, damp_user): d = rho, rho' of the
     full-model damper dterm[j] (not exportable). Manual 1.7. */
  int ndamp, damp_deg, damp_nphi;
  const phgmg_real *Cd;     /* r x ndamp: the reduced damper directions W_z^T c_k */
  const phgmg_real *dw;     /* ndamp weights (NULL: all 1)                         */
  const phgmg_real *dpoly;  /* (damp_nphi or 1) x (damp_deg + 1), constant term first */
  void (*damp_cb)(int term, phgmg_real s, phgmg_real d[2], void *user);
  const int *dterm;         /* ndamp: full-model damper of each kept one (NULL: j) */
  void *damp_user;
  /* feedthrough (NULL: none; LINEAR kind): PD = [Ph; Dh], Ph = W_z^T P
     (r x m), then Dh = S + N (m x m):  x' = ... + (Bh - Ph) u,
     y = (Bh + Ph)^T grad H + Dh u, dissipation block [[-sym K, Ph],
     [Ph^T, sym Dh]] positive semidefinite (manual 1.6). phgmg_rom_output and
     the stepper's y give (Bh + Ph)^T grad H: they have no u, add Dh u(t)
     yourself (phgmg_reduced_simulate does). */
  const phgmg_real *PD;
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
/* The reduced Hessian d^2 H / dx^2 at x (r x r; symmetric -- also with DEIM,
   whose weights make the reduced gradient an exact gradient). */
PHGMG_DEF void phgmg_rom_hessian(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *H, phgmg_real *work);
/* Newton Jacobian of the right-hand side, d f / d x (r x r), analytic for both
   kinds (QUADRATIC: includes the derivative of K(x) = (D^T G D)^{-1}; independent of u).
   PHGMG_ERR_SINGULAR if D^T G D is singular at x. */
PHGMG_DEF phgmg_result phgmg_rom_jacobian(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *Jf,
                                          phgmg_real *work);

/* --- the online stepper (GL3, simplified Newton on the 3r stage system) --- */
typedef struct phgmg_rom_stats {
  long steps, newton_iters, factorizations, failures;
  long e_refreshes; /* QUADRATIC: new LU of E = D^T G D alone (after a slow step) */
  long exact_steps; /* QUADRATIC: steps solved with exact stage values (see phgmg_rom_step) */
  long outside_steps;       /* steps that ended outside the training envelope (rom->env_lo/hi) */
  long consec_failures;     /* failed steps since the last successful one */
  long max_consec_failures; /* longest run of failed steps so far */
  long q_outside_steps;     /* QUADRATIC: steps whose quadratic correction exceeded rom->q_max */
} phgmg_rom_stats;

typedef struct phgmg_rom_stepper {
  const phgmg_rom *rom;
  phgmg_real dt, tol;     /* step and Newton tolerance (inf-norm of the stage residual) */
  int max_iter;           /* Newton cap per step                                        */
  int tol_rel;            /* 1: tol is the default, scaled by max(1, |x|_inf, |Z|_inf)  */
  phgmg_real tol_step;    /* internal: the tolerance of the current step                */
  int use_map;            /* 1 if the precomputed step map is used                      */
  int have_lu, have_prev; /* internal: factors valid / extrapolation data valid        */
  int stale_e;            /* internal (QUADRATIC): refactor E = D^T G D before the next step */
  int exact_hold;         /* internal (QUADRATIC): steps left with exact stage values   */
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
  (sizeof(phgmg_real) * (size_t)(12 * (r) * (r) + 32 * (r) + 3 * (m) + 4 * (rn) * (r) + 2 * (rn) * (rn) + 6 * (rn) + 3 * (nd) + 64) \
   + sizeof(int) * (size_t)(4 * (r) + 8) + 64)
/* The same bound for a model with eta_cb and/or ham_cb set (room for D2q,
   rn x (r-m)^2 <= rn r^2, and for the ham_cb gradient and Hessian). */
#define PHGMG_ROM_STEPPER_MEMSIZE_MAX_CB(r, m, rn, nd) \
  (PHGMG_ROM_STEPPER_MEMSIZE_MAX(r, m, rn, nd) + \
   sizeof(phgmg_real) * (size_t)((rn) * (r) * (r) + (r) * (r) + (r) + 8))
/* Set up a stepper in caller memory (mem must be aligned for phgmg_real and
   int; anything from malloc or a static phgmg_real array is). tol <= 0 gives
   1e-10 (double) / 1e-5 (float) times max(1, |x|_inf, |Z|_inf) each step
   (relative for large states, see phgmg_rom_step); a tol that is NaN or infinite is
   PHGMG_ERR_INVALID_ARG; max_iter <= 0 gives 10. PHGMG_ERR_WORKSPACE if
   mem_size < phgmg_rom_stepper_memsize_dt(rom, dt) (which equals
   phgmg_rom_stepper_memsize(rom) when dt is the model's own step, or the
   model has no step map). */
PHGMG_DEF phgmg_result phgmg_rom_stepper_init(phgmg_rom_stepper *s, const phgmg_rom *rom, phgmg_real dt,
                                              phgmg_real tol, int max_iter, void *mem, size_t mem_size);
/* Forget the extrapolation history (call after changing x by hand). */
PHGMG_DEF void phgmg_rom_stepper_reset(phgmg_rom_stepper *s);
/* Stage times t + c_i dt, for evaluating u3. */
PHGMG_DEF void phgmg_rom_stage_times(phgmg_real t, phgmg_real dt, phgmg_real tc[3]);
/* One step: x (r) advanced in place. u3 = inputs at the three stage times
   (3m values, u(t+c1 dt) first; NULL = 0). y (m, may be NULL) = output at the
   new state. energy (may be NULL) += {supplied, dissipated} over the step.
   On failure (PHGMG_ERR_NOT_CONVERGED, _NANINF, _SINGULAR) x, y, energy are untouched.
   Newton: simplified (the LU of I - dt (A kron Jf) is kept across steps and
   renewed after a failure or when the contraction is slower than 1/2), started
   from the extrapolated collocation polynomial of the last step, at least one
   update per step, until the stage residual (inf-norm) is <= tol: an explicit
   tol is absolute (in the units of x), the default follows states and stage
   increments larger than 1; for tiny states (charges of 1e-12 C) the forced
   update solves a linear model exactly, a nonlinear one may want a smaller
   explicit tol. QUADRATIC
   models are solved in mass-matrix form, E(x) x' = g(x) + E(x) Bh u with
   E = D^T G D: the stage values Phi_i = E(Y_i)^{-1} g(Y_i) are unknowns beside
   the stage increments, so an iteration needs products E(Y_i) Phi_i and solves
   with frozen factors of E, never a factorisation per stage (E alone is
   refactored every 8 steps and after a step that needed more than one
   iteration). The converged
   stages are those of the usual GL3 method; tol bounds the stage residual
   linearised in Phi and the last correction of Phi (times dt A). */
PHGMG_DEF phgmg_result phgmg_rom_step(phgmg_rom_stepper *s, phgmg_real *x, const phgmg_real *u3,
                                      phgmg_real *y, phgmg_real energy[2]);

#ifdef __cplusplus
}
#endif

/* >>pod =================================================================== */
/* Offline reduction (double). A user gives a pH system and a snapshot matrix
   X (N x ns, ns = n_t + 1 columns) and gets a reduced model that is again a
   pH system (see >>online), plus the error measures of the paper (5.1). */
#ifndef PHGMG_NO_OFFLINE
#ifdef __cplusplus
extern "C" {
#endif

/* POD: the leading left singular vectors of X (N x ns). k = kmax modes, or
   fewer: with tol > 0 only modes with sigma_k > tol * sigma_1 are kept.
   V: N x kmax (ldv), S: kmax singular values (may be NULL). *k_out = modes kept.
   Independent of the magnitude of X within the floating-point range (the SVD
   scales internally by a power of two, see phgmg_svd). Exact path: the thin
   SVD of X (cost ~ N ns r with r the numerical rank, a copy of X in memory).
   Optional automatic switch (off by default): compiled with
   PHGMG_POD_RANDOMIZED_MIN = M > 0, a call with tol <= 0, N*ns >= M and
   4*(kmax + PHGMG_POD_OVERSAMPLE) <= min(N, ns) returns
   phgmg_pod_randomized(..., PHGMG_POD_POWER_ITERS (2), PHGMG_POD_SEED, ...)
   instead (same bits). tol > 0 always takes the exact path: a tolerance
   truncation (DEIM's 1e-8) needs the small singular values accurately, which
   the randomized method does not give. */
PHGMG_DEF phgmg_result phgmg_pod(int N, int ns, const double *X, int ldx, int kmax, double tol,
                                 double *V, int ldv, double *S, int *k_out,
                                 const phgmg_allocator *alloc);
/* Randomized POD (Halko, Martinsson & Tropp 2011: randomized range finder with
   power iterations, Algs. 4.4 and 5.1): the leading kmax left singular vectors
   of X (N x ns) at cost O(N ns l (2 + 2 power_iters)) with l = kmax + oversampling
   (PHGMG_POD_OVERSAMPLE, default 20; l is capped at min(N, ns)). Steps: a
   Gaussian test matrix Omega (ns x l) from a private generator seeded by `seed`
   (splitmix64 + Marsaglia polar: the same seed gives the same bits on every
   run of the same build); Y = X Omega, orthonormalised by
   Householder QR; power_iters times Z = X^T Q, QR, Y = X Z, QR; finally
   B^T = X^T Q (ns x l) and its thin SVD (phgmg_svd), V = Q * (right singular
   vectors of B^T). Extra memory: N*l + O(ns*l) doubles (X itself is not copied;
   the exact phgmg_pod copies it), so at most about twice the snapshots.
   Accuracy: the singular values are Rayleigh-Ritz values (never larger than the
   exact ones); with a decaying spectrum the error of sigma_j falls like
   (sigma_{l+1}/sigma_j)^(2(2q+1)) with q = power_iters: on the paper's chain
   (k = 40, sigma_40/sigma_1 = 5e-5) q = 2 gives all 40 values to 1e-14
   relative with oversampling 20 (5e-10 with 10; hence the default 20). With a
   slowly decaying spectrum raise power_iters. Values near or below sigma_{l+1}
   are NOT accurate, hence no tolerance argument: a truncation
   sigma_k > tol*sigma_1 with a small tol (DEIM's 1e-8) needs the exact
   phgmg_pod/phgmg_svd. *k_out = min(kmax, numerical rank of B^T); S (may be
   NULL) the k values. Magnitude-independent as phgmg_pod (power-of-two scaling
   when max|X| is outside [2^-256, 2^256]). Deterministic, single-threaded
   unless the GEMM runs with PHGMG_USE_OPENMP (the result is the same).
   PHGMG_ERR_INVALID_ARG (NULL, power_iters < 0), _SIZE, _NANINF, _NOMEM. */
PHGMG_DEF phgmg_result phgmg_pod_randomized(int N, int ns, const double *X, int ldx, int kmax,
                                            int power_iters, unsigned long seed, double *V,
                                            int ldv, double *S, int *k_out,
                                            const phgmg_allocator *alloc);
/* Adjusted snapshots Xa = X - B B^+ X (B: N x m full column rank). Xa may alias X. */
PHGMG_DEF phgmg_result phgmg_adjust_snapshots(int N, int m, const double *B, int ns, const double *X,
                                              int ldx, double *Xa, int ldxa, const phgmg_allocator *alloc);

/* Hierarchical POD of paper 4.2.2: V1 = POD_p(X - BB^+X), V2 = POD_rn of the
   residual (I - [B,V1][B,V1]^+) X. V1: N x p, V2: N x rn. */
PHGMG_DEF phgmg_result phgmg_pod_hierarchical(int N, int m, const double *B, int ns, const double *X,
                                              int ldx, int p, int rn, double *V1, double *V2,
                                              const phgmg_allocator *alloc);

/* >>hyper ================================================================= */
/* Hyper-reduction: points and weights that stand for a separable sum of
   terms (DEIM, ECSW) and the solvers behind them. */

/* Structure-preserving DEIM for a separable sum: F (nterms x ns) holds the
   snapshots of the nonlinear gradient terms phi_k'(x_idx_k). Modes: sigma_k >
   tol sigma_1 (capped by kmax if > 0). Points by Q-DEIM (pivoted QR of U^T).
   Weights w = (P^T U)^{-T} U^T sw (sw = the terms' own weights, NULL = 1), so
   sum_k sw_k phi_k ~ sum_j w_j phi_{pts_j}. pts, w: room for nterms entries.
   *nd_out = points chosen, *nneg = negative weights. */
PHGMG_DEF phgmg_result phgmg_deim(int nterms, int ns, const double *F, int ldf, const double *sw,
                                  double tol, int kmax, int *pts, double *w, int *nd_out,
                                  int *nneg, double *sigma_ratio, const phgmg_allocator *alloc);

/* DEIM point selection (phgmg_deim_select). */
typedef enum phgmg_deim_method {
  PHGMG_DEIM_QDEIM = 0,  /* pivoted QR of U^T (Drmac-Gugercin; phgmg_deim's choice) */
  PHGMG_DEIM_GREEDY = 1, /* greedy DEIM (Chaturantabut-Sorensen): point l = argmax
                            |u_l - U_{<l} (P^T U_{<l})^{-1} P^T u_l| (first index on ties) */
  PHGMG_DEIM_METHOD_COUNT
} phgmg_deim_method;
/* phgmg_deim with a choice of point selection: method PHGMG_DEIM_QDEIM or
   PHGMG_DEIM_GREEDY (else PHGMG_ERR_INVALID_ARG). Modes, weights and outputs
   as phgmg_deim; Q-DEIM points come in pivot order, greedy points in the
   order chosen. PHGMG_ERR_SINGULAR if P^T U is singular. For both: tol = 0
   gives 1e-8, kmax = 0 no cap; tol < 0, NaN or >= 1 and kmax < 0 give
   PHGMG_ERR_INVALID_ARG. */
PHGMG_DEF phgmg_result phgmg_deim_select(int nterms, int ns, const double *F, int ldf, const double *sw,
                                         double tol, int kmax, phgmg_deim_method method, int *pts, double *w,
                                         int *nd_out, int *nneg, double *sigma_ratio,
                                         const phgmg_allocator *alloc);

/* Non-negative least squares: min ||A x - b||_2 subject to x >= 0 (A m x n, lda).
   Lawson-Hanson active set on the rows compressed by one Householder QR when
   m > n (on A itself if that QR is not finite); each passive-set least
   squares by a fresh QR (k p^2 flops, k = min(m, n), p passive indices; for
   large problems see phgmg_ecsw's Gram form). Stops early once ||A x - b|| <=
   tol ||b|| (tol <= 0: solve to optimality: no free index with gradient
   [A^T (b - A x)]_j > 10 max(m,n) eps ||A||_F ||b||). max_iter (<= 0: 3n)
   caps the iterations (one per index added or dropped). Outputs: x (n),
   resid = ||A x - b|| (may be NULL), nnz_out = entries of x > 0 (may be NULL).
   Errors: PHGMG_ERR_INVALID_ARG (NULL A, b, x), PHGMG_ERR_SIZE, PHGMG_ERR_NANINF,
   PHGMG_ERR_NOT_CONVERGED (cap reached; x, resid, nnz hold the feasible
   iterate), PHGMG_ERR_NOMEM. */
PHGMG_DEF phgmg_result phgmg_nnls(int m, int n, const double *A, int lda, const double *b, double tol,
                                  int max_iter, double *x, double *resid, int *nnz_out,
                                  const phgmg_allocator *alloc);

/* Empirical quadrature with non-negative weights (ECSW, Farhat et al.;
   empirical cubature, Hernandez et al.) for a separable sum sum_k sw_k phi_k.
   Gm (nrows x nterms, ldg): column k = what term k contributes at weight 1 to
   each training quantity (e.g. rows (snapshot i, reduced coordinate a) =
   phi_k'(l_k(x_i)) [V]_{idx_k, a}, optionally energy rows phi_k(l_k(x_i)));
   target (nrows) = the full sum, Gm sw. Finds w >= 0 with few non-zeros and
   ||Gm w - target|| <= tol ||target|| (tol = 0: 1e-6; tol < 0, NaN or >= 1:
   PHGMG_ERR_INVALID_ARG; 0 < tol < 1e-15, below the rounding level of a
   relative residual: PHGMG_ERR_TOL_UNREACHABLE) by non-negative least
   squares (Lawson-Hanson) stopped at tol; with nterms >=
   PHGMG_ECSW_SCREEN_MIN (4096) the Gram matrix is never formed (screening
   in rounds of PHGMG_ECSW_SCREEN_ADD terms). The algorithm and its
   guarantees: manual 8.7.
   Outputs: pts[0..nd-1] kept terms ascending, w[0..nd-1] their weights (> 0),
   both with room for nterms; *nd_out = nd; *resid_out (may be NULL) =
   ||Gm w - target|| / ||target|| (0 when target = 0, then nd = 0).
   Scale: Gm or target whose largest |entry| is outside [2^-400, 2^400] are
   scaled by powers of two (exact) in a copy (nrows nterms more memory), so
   the points, the relative residual and the weights (scaled back) do not
   depend on the data's magnitude; weights beyond the double range give
   PHGMG_ERR_OVERFLOW.
   Errors: PHGMG_ERR_INVALID_ARG, PHGMG_ERR_SIZE, PHGMG_ERR_NANINF,
   PHGMG_ERR_TOL_UNREACHABLE, PHGMG_ERR_NOT_CONVERGED (tol not met: outputs
   hold the best found), PHGMG_ERR_OVERFLOW, PHGMG_ERR_NOMEM. */
PHGMG_DEF phgmg_result phgmg_ecsw(int nterms, int nrows, const double *Gm, int ldg, const double *target,
                                  double tol, int *pts, double *w, int *nd_out, double *resid_out,
                                  const phgmg_allocator *alloc);

/* phgmg_ecsw for the common case of terms l_k linear in the reduced
   coordinates (GMG-POD, SP1, SP2: l_k = row of the basis), without forming
   the ns r x nterms training matrix. F (nterms x ns, ldf) = phi_k'(l_k(x_i))
   as for phgmg_deim; Vt (nterms x r, ldvt): row k = d l_k / d(reduced
   coordinates) (e.g. V[idx_k, :]); sw: the terms' weights (NULL = 1). The
   training rows (i, a) = F[k, i] Vt[k, a], target = sum_k sw_k (...). Uses
   F = U S W^T: the rows (j, a) = S_j U[k, j] Vt[k, a] for the modes sigma_j >
   1e-3 tol sigma_1 have (up to that truncation) the same Gram matrix, so
   phgmg_ecsw runs on q r rows instead of ns r; the residual
   ||F^T diag(w - sw) Vt||_F / ||F^T diag(sw) Vt||_F is then computed on the
   full rows, and if it misses tol the fit is redone with every mode.
   From PHGMG_ECSW_SCREEN_MIN terms on: no SVD of F; the screening of
   phgmg_ecsw on the full ns r rows, applied as F^T diag(.) Vt products
   (gradient: one GEMM with F, 2 nterms ns r flops per round; only the
   working set's columns are formed).
   Outputs, tol and errors as phgmg_ecsw (resid_out: on the full rows). */
PHGMG_DEF phgmg_result phgmg_ecsw_separable(int nterms, int ns, const double *F, int ldf, int r,
                                            const double *Vt, int ldvt, const double *sw, double tol,
                                            int *pts, double *w, int *nd_out, double *resid_out,
                                            const phgmg_allocator *alloc);

/* Hyper-reduction of a separable part (phgmg_hyper_opts.kind, with on = 1). */
typedef enum phgmg_hyper {
  PHGMG_HYPER_ECSW = 0,   /* default: w >= 0 by NNLS fit of the reduced gradient (ECSW) */
  PHGMG_HYPER_QDEIM = 1,  /* structure-preserving DEIM, Q-DEIM points (the paper's)     */
  PHGMG_HYPER_GREEDY = 2, /* structure-preserving DEIM, greedy DEIM points             */
  PHGMG_HYPER_COUNT
} phgmg_hyper;

/* >>reduce ================================================================ */
/* The reduction: runs and snapshot sets, the options, phgmg_reduce and the
   reduced object. */

/* One run of the full model: input u (NULL: u = 0) from x0 (NULL: 0) at t0,
   nsteps steps of dt. A snapshot set of several runs keeps them one after
   the other, run k in runs[k].nsteps + 1 columns (phgmg_simulate_inputs);
   phgmg_reduce_opts.runs tells the reduction where they are and how they
   were made (validation by simulation, below). */
typedef struct phgmg_run {
  phgmg_input_fn u;
  void *user;
  const double *x0;
  double t0, dt;
  int nsteps;
} phgmg_run;

/* Where a simulation puts its results (each pointer may be NULL): X the
   N x (nsteps + 1) states (ld N; r x (nsteps + 1) for a reduced model), Y the
   m x (nsteps + 1) outputs (ld m), energy the bookkeeping of phgmg_simulate;
   steps_done (written) how many steps succeeded. stats: one of the two,
   matching the model simulated (the other is ignored). */
typedef struct phgmg_sim_out {
  double *X, *Y;
  const phgmg_energy *energy;
  phgmg_gl3_stats *stats;       /* phgmg_simulate_run                    */
  phgmg_rom_stats *rom_stats;   /* phgmg_reduced_simulate_run            */
  int steps_done;
} phgmg_sim_out;

/* phgmg_simulate with the run described by a phgmg_run (u, user, x0 (NULL:
   0), t0, dt, nsteps) and the outputs gathered in out (may be NULL: only the
   result code). Same results and codes as phgmg_simulate. */
PHGMG_DEF phgmg_result phgmg_simulate_run(const phgmg_ph_system *sys, const phgmg_run *run,
                                          const phgmg_gl3_opts *opts, phgmg_sim_out *out,
                                          const phgmg_allocator *alloc);

/* Columns of a snapshot set of nrun runs: sum of (nsteps + 1); -1 for a bad
   run (nsteps < 0, dt not positive and finite). */
PHGMG_DEF int phgmg_runs_columns(int nrun, const phgmg_run *runs);
/* Simulate the runs (phgmg_simulate with opts go, may be NULL) into one
   snapshot set: X (N x phgmg_runs_columns, ldx), Y (m x the same, may be
   NULL), col (nrun + 1, may be NULL): run k in columns col[k]..col[k+1]-1.
   Stops at the first failing run (its code; the columns before it hold data). */
PHGMG_DEF phgmg_result phgmg_simulate_inputs(const phgmg_ph_system *sys, int nrun, const phgmg_run *runs,
                                             const phgmg_gl3_opts *go, double *X, int ldx, double *Y, int *col,
                                             const phgmg_allocator *alloc);

/* GMG-QM manifold constructions (phgmg_qm_opts.manifold; manual 3.3). */
typedef enum phgmg_manifold {
  PHGMG_MANIFOLD_POD = 0,    /* the paper's hierarchical POD                       */
  PHGMG_MANIFOLD_GREEDY = 1, /* greedy linear part (Schwerdtner & Peherstorfer 2024) */
  PHGMG_MANIFOLD_ALTMIN = 2, /* alternating minimization of V1, V2 and M           */
  PHGMG_MANIFOLD_COUNT
} phgmg_manifold;

/* phgmg_qm_opts.rn: V2 over the whole residual of the snapshots (manual 3.3). */
#define PHGMG_RN_WIDE (-1)

/* phgmg_reduce_opts.ref: the affine reference state (manual 3.6). */
typedef enum phgmg_ref { PHGMG_REF_NONE = 0, PHGMG_REF_MEAN = 1, PHGMG_REF_GIVEN = 2, PHGMG_REF_COUNT } phgmg_ref;

/* phgmg_select_opts.lambda_mode: how GMG-QM's ridge parameter is chosen
   (manual 4.2). */
typedef enum phgmg_lambda_mode {
  PHGMG_LAMBDA_FIXED = 0,      /* default: qm.lambda as given                           */
  PHGMG_LAMBDA_VALIDATED = 1,  /* by simulating the reduced model (opts.runs, probes)    */
  PHGMG_LAMBDA_REGRESSION = 2, /* by held-out regression error on time blocks           */
  PHGMG_LAMBDA_MODE_COUNT
} phgmg_lambda_mode;

/* The quadratic manifold of GMG-QM and GMG_MANIFOLD (manual 3.1, 3.3). */
typedef struct phgmg_qm_opts {
  int rn;          /* width r_n of V2: > 0 a cap, PHGMG_RN_WIDE the numerical rank of the
                      residual; 0: 8 with the POD manifold, wide with GREEDY / ALTMIN;
                      GMG_MANIFOLD: required (< 1: _INVALID_ARG). < -1: _INVALID_ARG;
                      wider than N - r (GMG_MANIFOLD: 64): _SIZE                         */
  double lambda;   /* ridge parameter of the fit of M, > 0 (0: 1e-3; < 0: exactly zero,
                      minimum-norm fit; NaN: _INVALID_ARG); read when select.lambda_mode
                      is PHGMG_LAMBDA_FIXED                                              */
  phgmg_manifold manifold; /* the construction (0: PHGMG_MANIFOLD_POD; outside the enum:
                              _INVALID_ARG)                                             */
  int greedy_window;       /* GREEDY / ALTMIN with a wide V2: candidate modes beyond
                              r - m (<= 0: 8, with the construction's own score)         */
  phgmg_eta_fn eta;        /* GMG_MANIFOLD (required there, else _INVALID_ARG): eta and
                              its derivatives; called online                           */
  void *eta_user;          /* passed to eta                                            */
} phgmg_qm_opts;

/* Choosing GMG-QM's lambda (manual 4.2). lambda_min .. blocks and rcond are
   read, and checked, only when lambda_mode is not PHGMG_LAMBDA_FIXED; bad
   values give PHGMG_ERR_INVALID_ARG, except blocks < folds or > ns:
   PHGMG_ERR_SIZE. */
typedef struct phgmg_select_opts {
  phgmg_lambda_mode lambda_mode; /* 0: PHGMG_LAMBDA_FIXED                              */
  double lambda_min;   /* smallest grid lambda, > 0, finite (0: 1e-14)                   */
  double lambda_max;   /* largest grid lambda, >= lambda_min, finite (0: 1); at most
                          1000 grid points                                               */
  int per_decade;      /* grid points per decade, 1..100 (0: 4)                          */
  int folds;           /* REGRESSION: folds, >= 2 (0: 5)                                 */
  int blocks;          /* REGRESSION: contiguous time blocks, folds..ns (0: min(ns, 100))*/
  double rcond;        /* conditioning guard, relative to rcond(D^T G D) at x = 0, in
                          [0, 1] (0: 1e-6)                                               */
  double tolerance;    /* VALIDATED: admissible e_y ratio to the linear limit, >= 1 and
                          finite (0: 1.02)                                               */
  int train_only;      /* VALIDATED: 1 = training runs only, no probe runs; 0 or 1      */
  double newton_tol;   /* validation simulations' Newton tolerance, [0, 1) (0: 1e-10 for
                          the full model, the stepper's default for the reduced one)     */
  int newton_iter;     /* validation simulations' iteration cap, >= 0 (0: 20)            */
} phgmg_select_opts;

/* Hyper-reduction of a separable part, and of dampers (manual 3.4, 1.7). */
typedef struct phgmg_hyper_opts {
  int on;              /* 1: hyper-reduce; 0: keep every term (exact, O(terms) online);
                          else _INVALID_ARG; with a GENERAL part: _UNSUPPORTED           */
  phgmg_hyper kind;    /* with on = 1 (0: PHGMG_HYPER_ECSW; outside the enum: _INVALID_ARG) */
  double tol;          /* ECSW: relative training residual of the reduced gradient,
                          [0, 1) (0: 1e-6)                                               */
  double deim_tol;     /* DEIM modes kept: sigma_k / sigma_1 > deim_tol, [0, 1) (0: 1e-8) */
  int deim_max;        /* cap on DEIM modes, >= 0 (0: no cap)                            */
  int allow_negative;  /* DEIM: 1 = accept negative weights (info.deim_negative); 0:
                          a negative weight gives PHGMG_ERR_NEGATIVE_WEIGHT              */
} phgmg_hyper_opts;

/* Results of earlier work reused by a reduction (manual 2.3), each from the
   same snapshots X; NULL: computed by the reduction. */
typedef struct phgmg_reduce_cache {
  const double *pod_basis;  /* N x pod_cols, ld N: leading left singular vectors of
                               the matrix the method PODs                               */
  int pod_cols;
  const double *grad_basis; /* SP2: the same for the gradient snapshots (N x grad_cols) */
  int grad_cols;
  const int *deim_pts;      /* phgmg_deim's points and weights (deim_count of each);   */
  const double *deim_w;     /* used as given when hyper.on = 1                          */
  int deim_count;
} phgmg_reduce_cache;

typedef struct phgmg_reduce_opts {
  phgmg_method method;   /* required (manual 3.1)                                         */
  int r;                 /* reduced order, required (GMG: m < r <= N, including the m
                            port coordinates; SP: 1..min(N, ns)), else PHGMG_ERR_SIZE     */
  double dt;             /* > 0: precompute the GL3 step map for this step (LINEAR map,
                            quadratic H; manual 2.2); 0: none; < 0, NaN, Inf: _INVALID_ARG */
  double degeneracy_tol; /* least rcond of D^T G D at the snapshots (port columns at unit
                            length), in [0, 1) (0: 1e-12); below: PHGMG_ERR_DEGENERATE   */
  int nrun;              /* runs[0..nrun-1] (nrun <= 64): the runs that made X, laid   */
  const phgmg_run *runs; /* out as by phgmg_simulate_inputs (manual 4.1; columns summing
                            to ns, else _SIZE). 0/NULL: X is one run of an unknown input */
  phgmg_ref ref;         /* affine reference state (manual 3.6; 0: PHGMG_REF_NONE)        */
  const double *ref_x;   /* PHGMG_REF_GIVEN: the N values, finite (NULL: _INVALID_ARG)    */
  void (*progress)(const char *phase, void *user); /* stage callback (manual 2.2; NULL) */
  void *progress_user;
  phgmg_qm_opts qm;         /* GMG-QM / GMG_MANIFOLD: the manifold                       */
  phgmg_select_opts select; /* GMG-QM: choosing lambda                                   */
  phgmg_hyper_opts hyper;   /* a separable part (and dampers)                            */
  phgmg_reduce_cache cache; /* reuse across reductions (studies)                         */
} phgmg_reduce_opts;

/* The defaults of phgmg_reduce_opts (the table in manual 3.2): *o is zeroed
   and every field whose zero stands for a default gets that default. A zeroed
   struct and this one reduce identically (with method and r set); use it to
   show or start from the defaults. Left 0: method and r (required),
   select.blocks (min(ns, 100): needs the snapshots), select.newton_tol (the
   steppers' own defaults), the optional pointers and flags. */
PHGMG_DEF void phgmg_reduce_opts_default(phgmg_reduce_opts *o);

typedef struct phgmg_reduce_info {
  int deim_modes;          /* terms kept by the hyper-reduction (nd), ECSW or
                              DEIM; every term without hyper.on             */
  int deim_negative;       /* number of negative DEIM weights               */
  double deim_sigma_ratio; /* sigma_{nd+1}/sigma_1 of the nonlinear snapshots (0 if all kept) */
  double rcond_dgd;        /* GMG: smallest rcond of D^T G D seen (at x = 0 and the
                              snapshots; port columns of D at unit length, see
                              degeneracy_tol). SP1/SP2: rcond of V^T Vg, the matrix
                              inverted for W (no D^T G D there)                   */
  double rcond_jr;         /* rcond of J - R                                  */
  double pod_sigma_ratio;  /* sigma_{r'+1}/sigma_1 of what the method PODs (GMG:
                              the adjusted snapshots, r' = r - m; SP1/SP2: X,
                              r' = r); 0 if no further mode or a given basis */
  double lambda;           /* GMG-QM: the ridge lambda used (fixed or chosen)  */
  double lambda_cv_err;    /* lambda chosen: held-out relative error of the quadratic
                              correction at that lambda, sum ||V2^T x - M(z kron z)||^2
                              / sum ||V2^T x||^2 over the blocks (1 = no better than
                              M = 0); 0 with a fixed lambda                    */
  int lambda_grid;         /* lambda chosen: grid points tried (0 without)     */
  int lambda_raised;       /* lambda chosen: grid steps above the validated optimum
                              taken because of the non-degeneracy check         */
  int online_full_dim;     /* 1: the reduced model evaluates a GENERAL nonlinear part
                              in full dimension -- O(N) per gradient, O(N^2 r)
                              (dense) or O(N kb r) (banded) per Hessian; it cannot
                              be exported. 0: online cost independent of N. */
  int online_callbacks;    /* 1: the reduced model calls back into user code
                              (separable functions, eta or a GENERAL part)     */
  int hyper_method;        /* phgmg_hyper used (hyper.on = 1), -1 without     */
  double hyper_min_weight; /* smallest weight of the kept terms                */
  double hyper_residual;   /* ECSW: relative training residual of the reduced
                              nonlinear gradient; 0 for DEIM                   */
  int lambda_candidates;   /* VALIDATED: candidate lambdas simulated           */
  double lambda_val_ratio; /* VALIDATED: largest e_y ratio of the chosen
                              model to the linear limit over the validation runs */
  /* qm.manifold = PHGMG_MANIFOLD_ALTMIN: the objective sum_i ||x_i - phi(rho(x_i))||^2
     + lam ||M||^2 over the snapshots (lam: the ridge parameter of the sweeps) at
     the start (the hierarchical POD, or the greedy manifold) and at the end,
     and the sweeps kept (with a wide V2: the descent steps taken); the final
     M is then refitted with the lambda in force (fixed or automatic). */
  double manifold_obj0, manifold_obj;
  int manifold_sweeps;
  /* 1: altmin under PHGMG_LAMBDA_VALIDATED gave no model at least as good as GMG-POD
     on every validation run (within select.tolerance), so the returned model
     is the one of qm.manifold = PHGMG_MANIFOLD_POD (same options otherwise) */
  int manifold_fallback;
  int pod_randomized;      /* the basis POD: 0 exact SVD; 1 randomized (large
                              N*ns, see phgmg_reduce: it passed its check);
                              -1 randomized, check failed, exact SVD used     */
  double pod_check;        /* randomized POD: ||X W - V diag(S)||_F / S_1 (the
                              triplets' backward error); 0 on the exact path  */
} phgmg_reduce_info;

/* The reduced model with its offline data (bases for reconstruction, double
   and phgmg_real copies of the small blocks). */
typedef struct phgmg_reduced phgmg_reduced;

/* Build a reduced model of `sys` from snapshots X (N x ns, ldx). The system must
   validate (phgmg_ph_validate). The stages and the model kinds are described in
   the manual (2.2, 3.1-3.4): every Hamiltonian kind reduces with every method;
   a GENERAL part makes the online model evaluate in full dimension
   (info.online_full_dim = 1, not exportable, the reduced object must outlive
   the model and is not thread-safe in evaluation); separable callbacks make it
   call back (phgmg_rom.phi_cb; no binary export). For N*ns >=
   PHGMG_POD_AUTO_MIN the basis comes from the randomized POD, accepted when
   ||X W - V diag(S)||_F <= PHGMG_POD_CHECK_TOL S_1 and otherwise replaced by
   the exact SVD (info.pod_randomized, info.pod_check); smaller problems take
   the exact path bit for bit.
   Errors: PHGMG_ERR_INVALID_ARG (NULL, bad options: method, hyper.on not
   0/1, hyper.deim_tol NaN or outside [0, 1), dt NaN/Inf/negative, qm.lambda
   NaN, GMG_MANIFOLD without qm.eta or qm.rn; manual 3.2), PHGMG_ERR_SIZE (r <= m for GMG, r > rank of
   the snapshots, polynomial degree > 32, ...), PHGMG_ERR_RANK, _DEGENERATE,
   _NEGATIVE_WEIGHT, _NANINF, _NOMEM, _UNSUPPORTED. *out is NULL on every
   failure (when out itself is not NULL). info may be NULL. */
PHGMG_DEF phgmg_result phgmg_reduce(phgmg_reduced **out, const phgmg_ph_system *sys, const double *X,
                                    int ldx, int ns, const phgmg_reduce_opts *opts,
                                    phgmg_reduce_info *info, const phgmg_allocator *alloc);
PHGMG_DEF void phgmg_reduced_destroy(phgmg_reduced *red);
/* The online model (views into the reduced object; valid until destroy). */
PHGMG_DEF const phgmg_rom *phgmg_reduced_rom(const phgmg_reduced *red);
/* The full-order dimension N the model was reduced from (0 for NULL). */
PHGMG_DEF int phgmg_reduced_N(const phgmg_reduced *red);
/* Reconstruction x = phi(xr) (N). */
PHGMG_DEF void phgmg_reduced_lift(const phgmg_reduced *red, const double *xr, double *x);
/* Point reduction xr = rho(x) (r); rho(phi(xr)) = xr. */
PHGMG_DEF void phgmg_reduced_restrict(const phgmg_reduced *red, const double *x, double *xr);
/* Jacobian of phi at xr: D (N x r, ldd). */
PHGMG_DEF void phgmg_reduced_dphi(const phgmg_reduced *red, const double *xr, double *D, int ldd);
/* The reduction map W(xr) (N x r, ldw >= N) in full dimension (for checks;
   O(N r^2)), W^T Dphi = I. Descriptor model: W^T = (D^T G_E D)^{-1} D^T G_E,
   G_E = E^T G E (the map of the equivalent standard form); the test basis of
   the co-state equation is W_z = E^{-T} W (manual 1.6). */
PHGMG_DEF phgmg_result phgmg_reduced_W(const phgmg_reduced *red, const double *xr, double *W, int ldw);

/* Simulate the reduced model with the online GL3 stepper from xr0 over nsteps
   steps of dt (u from uf at the stage times). Outputs (each may be NULL):
   XR r x (nsteps+1), Y m x (nsteps+1), energy like phgmg_simulate (Hamiltonian
   of the reduced model). tol/max_iter: Newton settings (<= 0: defaults).
   The stepper memory is sized for dt (phgmg_rom_stepper_memsize_dt), so a
   model with a step map for another dt is stepped with Newton. */
PHGMG_DEF phgmg_result phgmg_reduced_simulate(const phgmg_reduced *red, const double *xr0, double t0,
                                              double dt, int nsteps, phgmg_input_fn uf, void *uuser,
                                              double tol, int max_iter, double *XR, double *Y,
                                              const phgmg_energy *energy, phgmg_rom_stats *stats,
                                              const phgmg_allocator *alloc);
/* The same with the run in a phgmg_run (run->x0: the reduced initial state
   xr0, r values; NULL: 0) and the outputs in out (out->X receives XR,
   out->rom_stats the stepper's totals; may be NULL). tol, max_iter as above. */
PHGMG_DEF phgmg_result phgmg_reduced_simulate_run(const phgmg_reduced *red, const phgmg_run *run, double tol,
                                                  int max_iter, phgmg_sim_out *out, const phgmg_allocator *alloc);

/* >>deploy ================================================================ */
/* --- a check before shipping --- */
typedef struct phgmg_validation {
  double e_red;        /* reduction error of the reduced trajectory (over the steps done) */
  double e_y;          /* relative output error (over the steps done)                     */
  double e_proj;       /* projection error of the test trajectory onto the model's manifold */
  double e_energy;     /* max_n |H_n - H_0 - S_n + D_n| of the reduced model (steps done)  */
  double e_energy_fom; /* the same for the full model (the integrator's own level)        */
  double y_scale;      /* max |y| of the full model (for reading e_y)                      */
  int nsteps;          /* steps asked for                                                 */
  int steps_done;      /* steps the reduced model completed                               */
  int first_failure;   /* index n of the first failed step (t_n -> t_n+1), -1: none      */
  phgmg_result rom_rc; /* the reduced simulation's code (PHGMG_OK if it completed)       */
  phgmg_rom_stats stats; /* Newton statistics, training-envelope count of the reduced run */
  int pass;            /* 1: completed, no Newton failure, e_y <= the limit given      */
} phgmg_validation;

/* Full model against reduced model on one run (phgmg_run: input, x0, t0, dt,
   nsteps): simulates sys (the full model the reduced one came from) and the
   reduced model from rho(x0) with the online stepper (tol/max_iter <= 0:
   defaults 1e-10 for the full model, the stepper's default for the reduced
   one (1e-10 double, 1e-5 float) / 20), and fills *v. pass = 1 when the reduced run completes
   without any failed Newton solve, every measure is finite and e_y <= ey_max
   (ey_max <= 0: no limit on e_y). The error norms are sums of squares
   scaled by a power of two when the plain sums would overflow or underflow,
   so e_red, e_y and e_proj do not depend on the data's magnitude. Returns
   PHGMG_OK when the comparison was made (a failing reduced model is a
   result, v->pass = 0, not an error); PHGMG_ERR_INVALID_ARG / _SIZE for bad
   arguments (run->nsteps < 1: nothing to compare; sys->N or m not the
   model's), the full model's code if it fails, PHGMG_ERR_NOMEM;
   PHGMG_ERR_NANINF when a Hamiltonian returns NaN at states below 1e100 in
   magnitude, PHGMG_ERR_OVERFLOW when the states are so large that an energy
   or a measure leaves the double range (e.g. |x| ~ 1e160: H ~ |x|^2). With
   these two *v holds what could be measured and pass = 0. Cost: one full
   and one reduced run. */
PHGMG_DEF phgmg_result phgmg_reduced_validate(const phgmg_reduced *red, const phgmg_ph_system *sys,
                                              const phgmg_run *run, double tol, int max_iter, double ey_max,
                                              phgmg_validation *v, const phgmg_allocator *alloc);

/* >>errors ================================================================ */
/* --- error measures (paper 5.1) --- */
/* sqrt(sum_i ||A_i - B_i||^2 / sum_i ||A_i||^2) over ns columns of length n
   (the sums scaled by a power of two when plain sums would overflow or
   underflow; the same holds for phgmg_err_red / _proj / _lowerbound). */
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

/* >>study ================================================================= */
/* --- studies over many reduced orders of one snapshot set ---------------
   phgmg_reduce alone redoes, for every call, work that grows with N ns r:
   the POD, the snapshots' coordinates, the envelope and non-degeneracy
   checks over the snapshots, the G- and Q-applications, the error measures.
   The bases of a study over r are nested (GMG: V0 = [B, Ua_1..p], V2 =
   Ua_{p+1..p+rn}; SP1/SP2: V = Up_1..r), so a study computes once, for the
   largest basis: the POD of the adjusted snapshots Xa = X - BB^+X (Ua) and
   of X (Up) (the hierarchical POD of every order from one factorisation),
   the gradient snapshots' POD (Ug, SP2), the coordinates Ua^T Xa, QB^T X,
   Up^T X, (Q Up)^T X, Ug^T X (K x ns), the residual tails
   T(k) = sum_i ||(I - P_k) x_i||^2 (the part of X outside the first k
   modes, from ||R_K||_F^2 plus sums of squared coordinates: no
   cancellation), [B, Ua]^T G [B, Ua] and [B, Ua]^T Q [B, Ua], and the DEIM
   points (at their first use). phgmg_study_reduce then builds the same
   model as phgmg_reduce with opts.cache.pod_basis (and grad_basis) set to the
   study's bases, taking every snapshot quantity from the coordinates
   (O(K ns r) per model instead of O(N ns r)), and phgmg_study_errors
   evaluates e_red, e_proj, e_lowerbound in reduced coordinates (the bases
   are orthonormal: ||x - phi||^2 = T(k) + ||coordinates - reduced
   values||^2). Results agree with phgmg_reduce + phgmg_err_* to rounding
   (tests/test_study.c). X must stay unchanged while the study lives. */
typedef struct phgmg_study phgmg_study;
#define PHGMG_STUDY_GMG 1u /* GMG-POD / GMG-QM: Ua, coordinates, tails, G- and Q-blocks */
#define PHGMG_STUDY_SP 2u  /* SP1 (and SP2's trial basis): Up, coordinates, tails    */
#define PHGMG_STUDY_SP2 4u /* SP2: Ug (POD of grad H(x_i)) and Ug^T X                  */
typedef struct phgmg_study_opts {
  unsigned what; /* PHGMG_STUDY_* flags (0: GMG | SP)                                   */
  int kmax;      /* modes per POD: the largest r - m + rn (GMG) or r (SP) to be asked,
                    <= min(N, ns) (fewer are kept if the snapshots have lower rank)   */
} phgmg_study_opts;
/* Cost: one thin SVD of N x ns per basis asked for plus O(N ns kmax).
   PHGMG_ERR_INVALID_ARG (NULL, a flag bit other than PHGMG_STUDY_*), _SIZE
   (kmax < 1 or > min(N, ns), ldx < N), _NANINF, _RANK (B), _NOMEM, a
   solve's code (G = (J - R)^{-1}). */
PHGMG_DEF phgmg_result phgmg_study_create(phgmg_study **out, const phgmg_ph_system *sys, const double *X,
                                          int ldx, int ns, const phgmg_study_opts *so,
                                          const phgmg_allocator *alloc);
PHGMG_DEF void phgmg_study_destroy(phgmg_study *st);
/* A study's basis, for phgmg_reduce_opts.cache.pod_basis / grad_basis of your own
   calls: which = 'a' (POD of the adjusted snapshots: GMG), 'p' (POD of X:
   SP1/SP2), 'g' (POD of the gradient snapshots: SP2). N x *cols, ld N,
   valid until destroy; NULL (and *cols = 0) if the study has none. */
PHGMG_DEF const double *phgmg_study_basis(const phgmg_study *st, char which, int *cols);
/* phgmg_reduce(out, sys, X, ldx, ns, opts', info, alloc) of the study's
   system and snapshots, with opts' = opts plus the study's bases where
   opts leaves cache.pod_basis / grad_basis NULL (GMG-POD, GMG-QM, SP1, SP2),
   and with opts.hyper.on = 1, hyper.kind QDEIM or GREEDY and no
   cache.deim_pts: the study's DEIM points (computed at the first such call,
   reused while hyper.deim_tol, hyper.deim_max and the point selection are
   the same). The fast path (snapshot quantities from coordinates) applies
   to GMG-POD, GMG-QM with qm.manifold = PHGMG_MANIFOLD_POD, SP1 and SP2 on the study's own bases and r - m + rn (GMG) / r (SP) within
   its modes; other models are built exactly as phgmg_reduce builds them.
   Not thread-safe on one study (the DEIM cache). The system (sizes, J, R,
   Q, B, a separable part's indices, weights and coefficients) must not
   change after phgmg_study_create: a fingerprint taken there is compared
   at every call (O(N^2) dense, O(kb N) banded), PHGMG_ERR_STALE if it
   differs (the study's blocks would be those of the old system). */
PHGMG_DEF phgmg_result phgmg_study_reduce(phgmg_study *st, const phgmg_reduce_opts *opts, phgmg_reduced **out,
                                          phgmg_reduce_info *info);
/* Error measures over the study's snapshots: e_red of a reduced trajectory
   XR (r x ns, ldxr; NULL: e_red = NaN), e_proj, e_lowerbound (NaN unless
   GMG-QM / GMG_MANIFOLD), each output may be NULL. Through coordinates
   (O(ns r^2)) for a model the study built on its bases; else
   phgmg_err_red / _proj / _lowerbound on the study's X. PHGMG_ERR_INVALID_ARG
   (NULL st or red), _SIZE (red not of the study's N, m), _NOMEM. */
PHGMG_DEF phgmg_result phgmg_study_errors(const phgmg_study *st, const phgmg_reduced *red, const double *XR,
                                          int ldxr, double *e_red, double *e_proj, double *e_lower);

#ifdef __cplusplus
}
#endif
#endif /* PHGMG_NO_OFFLINE */

/* >>linear ================================================================ */
/* Linear pH systems with a quadratic Hamiltonian (nl == NONE), dense up to a
   few thousand states: x' = A x + B u, y = C x with A = (J - R) Q, C = B^T Q
   and zero feedthrough. Matrix equations by the matrix sign function (only
   LU inverses and products; Frobenius-norm scaling while far from
   convergence; stop one unscaled step after d = ||Z+ - Z||_1 / ||Z+||_1 <=
   1e-10, or after d <= 1e-4 stops halving (round-off level of an
   ill-conditioned sign); at most 100 steps, else PHGMG_ERR_NOT_CONVERGED;
   check the residual with phgmg_lyap_residual / phgmg_care_residual), balanced
   truncation (square-root method) as reference, positive-real balanced
   truncation (PRBT) returning a pH reduced model, input-independent bases for
   GMG-POD (pass them through phgmg_reduce_opts.cache.pod_basis; kind H2: the GMG
   model of least H2 error, by L-BFGS), transfer functions
   and H-infinity / H2 errors. Cost O(n^3) per sign step (15-17 steps on the
   mass-spring-damper chains; tests/test_linear.c, bench/bench_linear.c). */
#ifndef PHGMG_NO_OFFLINE
#ifdef __cplusplus
extern "C" {
#endif

/* Lyapunov equation A X + X A^T + F = 0 (A n x n stable, F symmetric), X
   n x n (all ld = n). Sign iteration Z <- (Z/c + c Z^-1)/2, E <- (E/c + c
   Z^-1 E Z^-T)/2 from Z = A, E = F; X = E/2. *iters (may be NULL) = steps.
   PHGMG_ERR_SINGULAR (A singular, or not stable: the sign of A is not -I),
   _INVALID_ARG (F not symmetric: ||F - F^T||_F > 1e-10 ||F||_F),
   _NOT_CONVERGED, _NANINF, _NOMEM. */
PHGMG_DEF phgmg_result phgmg_lyap(int n, const double *A, const double *F, double *X, int *iters,
                                  const phgmg_allocator *alloc);
/* Riccati equation A^T X + X A - X K X + L = 0 (K, L symmetric, n x n): the
   stabilizing solution (A - K X stable) from the sign of the Hamiltonian
   matrix H = [A, -K; -L, -A^T]: [W12; W22 + I] X = -[W11 + I; W21] by least
   squares, X symmetrised. H must have no eigenvalue on the imaginary axis
   (else PHGMG_ERR_NOT_CONVERGED or _SINGULAR, or -- close to the axis -- an
   inaccurate X: check phgmg_care_residual). PHGMG_ERR_NOT_STABILIZABLE when
   the stable invariant subspace of H is not a graph [I; X] (no stabilizing
   solution: (A, K) not stabilizable or (A, L) not detectable). */
PHGMG_DEF phgmg_result phgmg_care(int n, const double *A, const double *K, const double *L, double *X,
                                  int *iters, const phgmg_allocator *alloc);
/* Relative residuals ||A X + X A^T + F||_F / (2 ||A||_F ||X||_F + ||F||_F) and
   ||A^T X + X A - X K X + L||_F / (2 ||A||_F ||X||_F + ||X||_F^2 ||K||_F + ||L||_F);
   NaN when out of memory. */
PHGMG_DEF double phgmg_lyap_residual(int n, const double *A, const double *F, const double *X,
                                     const phgmg_allocator *alloc);
PHGMG_DEF double phgmg_care_residual(int n, const double *A, const double *K, const double *L,
                                     const double *X, const phgmg_allocator *alloc);

/* Dense A = (J - R) Q (N x N) and C = B^T Q (m x N) of a system (dense or
   banded storage; nl must be NONE: PHGMG_ERR_UNSUPPORTED). Either may be NULL. */
PHGMG_DEF phgmg_result phgmg_ph_abc(const phgmg_ph_system *sys, double *A, double *C,
                                    const phgmg_allocator *alloc);

/* Balanced truncation (square-root method), reference: Gramians P, O from
   A P + P A^T + B B^T = 0, A^T O + O A + C^T C = 0; P = Lp Lp^T, O = Lo Lo^T
   (symmetric eigen-decompositions, negative round-off eigenvalues dropped),
   Lo^T Lp = U S V^T, T = Lp V_r S_r^{-1/2}, W = Lo U_r S_r^{-1/2};
   Ar = W^T A T (r x r), Br = W^T B (r x m), Cr = C T (m x r). Not a pH
   model in general (hence plain matrices). hsv (may be NULL): the first r
   Hankel singular values; T, W (N x r, may be NULL): the bases.
   A must be asymptotically stable. A pH system is stable but may be lossless
   in some mode (R = 0, or a mode the dampers do not reach: eigenvalues on the
   imaginary axis), where the Gramians do not exist: BT, PRBT,
   phgmg_prbt_riccati and the BALANCED and H2 bases of phgmg_linear_basis then
   fail with PHGMG_ERR_NOT_STABLE and write no model (after a failed Gramian
   solve the eigenvalues of A are checked: Re >= -1e-8 max |lambda|; other
   failures keep their code). GMG and SP with the data-driven bases
   (snapshots, FREQ, IMPULSE) still apply. phgmg_lyap / phgmg_care themselves
   report such an A as PHGMG_ERR_NOT_CONVERGED or PHGMG_ERR_SINGULAR. */
PHGMG_DEF phgmg_result phgmg_bt(const phgmg_ph_system *sys, int r, double *Ar, double *Br, double *Cr,
                                double *hsv, double *T, double *W, const phgmg_allocator *alloc);

typedef struct phgmg_prbt_opts {
  double eps; /* 0: zero feedthrough handled exactly (see phgmg_prbt); > 0: regularisation
                 D = eps ||C B||_F I                                              */
  double dt;  /* > 0: precompute the GL3 step map of the reduced model for this step   */
  /* Optional cache for studies over many r: the two Riccati solutions from
     phgmg_prbt_riccati with the same eps (N x N each; both or neither). */
  const double *X, *Y;
} phgmg_prbt_opts;

/* The positive-real Riccati solutions of phgmg_prbt (X: Q-eq, Y: P-eq, N x N),
   for phgmg_prbt_opts.X/Y. eps <= 0: the exact zero-feedthrough solutions (as
   phgmg_prbt with eps = 0, same fallback); eps > 0: regularised. */
PHGMG_DEF phgmg_result phgmg_prbt_riccati(const phgmg_ph_system *sys, double eps, double *X, double *Y,
                                          const phgmg_allocator *alloc);

/* Positive-real balanced truncation with a pH reduced model (method
   PHGMG_METHOD_PRBT, kind LINEAR). Gramians: the minimal solutions X (Q-eq)
   and Y (P-eq) of the positive-real lemma. A pH system has zero feedthrough,
   where the lemma's Riccati equations are singular. opts->eps = 0
   (default): their exact limit (the constraint X B = C^T eliminated; needs
   every port damped); otherwise, or when that limit does not exist, the
   regularised lemma with D = eps ||C B||_F I (eps 1e-10 in the fallback).
   Reduced model: Qh = Sigma_r, Jh = skew(Ar Sigma_r^-1), Rh >= 0 by
   construction, Bh = Br. The derivation, its accuracy and the cost of
   regularising: manual 8.11.
   Lift: x = T xr (phgmg_reduced_lift); restrict: xr = W^T x. prsv (may be
   NULL): the first r positive-real singular values; info_xb (may be NULL):
   ||X B - C^T||_F / ||C||_F. The system must outlive the model. Errors:
   PHGMG_ERR_INVALID_ARG (NULL, negative/NaN eps or dt, only one of X/Y),
   PHGMG_ERR_UNSUPPORTED (nl != NONE), the codes of phgmg_ph_validate,
   PHGMG_ERR_SIZE (r outside 1..N), PHGMG_ERR_NOT_CONVERGED / _SINGULAR,
   PHGMG_ERR_RANK (Gramian rank below r), PHGMG_ERR_NOT_STABLE (an undamped mode,
   see phgmg_bt), PHGMG_ERR_NOMEM; *out is NULL on failure. */
PHGMG_DEF phgmg_result phgmg_prbt(phgmg_reduced **out, const phgmg_ph_system *sys, int r,
                                  const phgmg_prbt_opts *opts, double *prsv, double *info_xb,
                                  const phgmg_allocator *alloc);

typedef enum phgmg_basis_kind {
  PHGMG_BASIS_FREQ = 1,     /* Re, Im of (i w I - A)^{-1} B, w log-spaced      */
  PHGMG_BASIS_IMPULSE = 2,  /* x(t) = e^{At} B sampled by GL3 steps            */
  PHGMG_BASIS_BALANCED = 3, /* balanced right basis T of phgmg_bt, in order    */
  PHGMG_BASIS_H2 = 4,       /* the GMG model of least H2 error (one order)     */
  PHGMG_BASIS_COUNT
} phgmg_basis_kind;

/* Every field 0 takes its default; a negative count, a negative, NaN or
   infinite wmin/wmax/dt, wmin >= wmax (both given, or one given beyond the
   other's default) give PHGMG_ERR_INVALID_ARG, a V0 with NaN/Inf (H2)
   PHGMG_ERR_NANINF. */
typedef struct phgmg_basis_opts {
  int nw;             /* FREQ: frequencies (0: 60)                               */
  double wmin, wmax;  /* FREQ: grid ends (0: from the system: wmin = 1 /
                         (10 ||A^-1||_1), wmax = 2 ||A||_1, which bracket every
                         eigenvalue modulus of A: |lambda| in [1/||A^-1||, ||A||];
                         each end separately)                                    */
  double dt;          /* IMPULSE: step (0: 0.1)                                   */
  int nsteps;         /* IMPULSE: steps (0: 1000)                                 */
  int maxit;          /* H2: L-BFGS iterations (0: 1000)                          */
  const double *V0;   /* H2: starting columns, N x k (NULL: the BALANCED basis)   */
  double *h2_rel;     /* H2 (may be NULL): out, ||G - G_r||_H2 / ||G||_H2 reached */
} phgmg_basis_opts;

/* An input-independent basis V (N x k, ld N) for GMG: orthonormal and
   orthogonal to B, ordered (FREQ, IMPULSE: POD of the snapshots after
   removing their B-component; BALANCED: Gram-Schmidt of [B, T] in order,
   B's part dropped). Pass it as opts.cache.pod_basis / pod_cols = k to
   phgmg_reduce (GMG-POD takes its first r - m columns). opts may be NULL.
   *k_out (may be NULL) = columns filled (fewer if the snapshots have lower
   rank; the rest is zero).
   H2: the basis for ONE order r = m + k (not nested: call once per order)
   whose GMG model has the least H2 error found: GMG's model depends on V
   alone (Ar = (V^T G V)^-1 V^T Q V, Br = [I; 0], Cr = B^T Q V for V = [B,
   Vbar], G = (J - R)^-1), so J(Vbar) = ||G - G_r||_H2^2 is minimised over
   Vbar (N x k) by L-BFGS (memory 50, Armijo backtracking) from opts->V0 or
   the BALANCED basis (also when V0 makes V^T G V singular). J and its
   gradient (Wilson's conditions chained through (V^T G V)^-1 and V^T Q V)
   come from the Gramian blocks P12, Q12, Pr, Qr of the error system: two
   N x r and two r x r Sylvester equations per step, solved in the complex
   Schur forms of A (once, O(N^3)) and of Ar (QR algorithm, per step); cost
   O(N^2 r) per step (N = 100, r = 12: 0.3-0.7 ms). Stops after opts->maxit
   steps (default 1000) or when the line search fails twice; a local
   minimum, slow to converge (measured, examples/linear_bases.c: on the
   paper's chain ||G - G_r||_H2 / ||G||_H2 at r = 12 is 1.4e-4 / 6.9e-5 /
   6.0e-5 after 300 / 1000 / 1500 steps). opts->h2_rel (may be NULL): the
   relative H2 error reached. PHGMG_ERR_SINGULAR: V^T G V singular or Ar
   unstable at the start (e.g. r = 3 with two force ports, where B^T G B = 0);
   BALANCED, H2: PHGMG_ERR_NOT_STABLE when the Gramians / the H2 norm of the
   system fail to exist because of an undamped mode (see phgmg_bt). */
PHGMG_DEF phgmg_result phgmg_linear_basis(const phgmg_ph_system *sys, phgmg_basis_kind kind, int k,
                                          const phgmg_basis_opts *opts, double *V, int *k_out,
                                          const phgmg_allocator *alloc);

/* Transfer function G(i w) = C (i w I - A)^{-1} B of a state-space model
   (A n x n, B n x m, C p x n), complex p x m interleaved (re, im) in G. */
PHGMG_DEF phgmg_result phgmg_ss_transfer(int n, int m, int p, const double *A, const double *B,
                                         const double *C, double w, double *G, const phgmg_allocator *alloc);
/* A reduced LINEAR model with quadratic H as (A, B, C) = (K Qh, Bh, Bh^T Qh)
   (r x r, r x m, m x r), from its double blocks. */
PHGMG_DEF phgmg_result phgmg_reduced_abc(const phgmg_reduced *red, double *A, double *B, double *C);
/* Errors between two models with the same ports (m inputs, p outputs):
   hinf = max over nw log-spaced w in [wmin, wmax] of sigma_max(G1 - G2),
   hinf_ref = the same of G1 (for a relative error); h2 = the H2 norm of the
   error system by one Lyapunov equation of size n1 + n2 (both stable),
   h2_ref = ||G1||_H2. Any output may be NULL. */
PHGMG_DEF phgmg_result phgmg_ss_error(int n1, const double *A1, const double *B1, const double *C1,
                                      int n2, const double *A2, const double *B2, const double *C2,
                                      int m, int p, int nw, double wmin, double wmax, double *hinf,
                                      double *hinf_ref, double *h2, double *h2_ref,
                                      const phgmg_allocator *alloc);
/* A state-space model x' = A x + B u, y = C x (A n x n, B n x m, C p x n,
   column-major, ld = rows) and the error measures of phgmg_ss_error. */
typedef struct phgmg_ss {
  int n, m, p;
  const double *A, *B, *C;
} phgmg_ss;
typedef struct phgmg_ss_errors {
  double hinf, hinf_ref; /* sampled H-infinity norm of G1 - G2 and of G1 */
  double h2, h2_ref;     /* H2 norm of G1 - G2 and of G1                 */
} phgmg_ss_errors;
/* phgmg_ss_error for two models given as phgmg_ss (PHGMG_ERR_SIZE when their
   m or p differ) on nw log-spaced frequencies in [wmin, wmax]; err (written
   on success) receives all four measures. */
PHGMG_DEF phgmg_result phgmg_ss_compare(const phgmg_ss *g1, const phgmg_ss *g2, int nw, double wmin, double wmax,
                                        phgmg_ss_errors *err, const phgmg_allocator *alloc);

#ifdef __cplusplus
}
#endif
#endif /* PHGMG_NO_OFFLINE */

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
   rounded once) and vice versa.
   Callbacks cannot be stored: phgmg_rom_serialize / _save refuse a model with
   phi_cb, eta_cb or ham_cb (PHGMG_ERR_UNSUPPORTED). phgmg_rom_export_c refuses
   ham_cb; for phi_cb / eta_cb it declares and references
       extern void <name>_phi(int term, phgmg_real s, phgmg_real d[3], void *user);
       extern void <name>_eta(const phgmg_real *x2, phgmg_real *q, phgmg_real *Dq,
                              phgmg_real *D2q, void *user);
   which the firmware supplies (user = NULL); the term indices are exported
   as `static const int <name>_term[nd]`. */
#ifdef __cplusplus
extern "C" {
#endif

/* Format versions: 1 the base model; 2 adds the exp-polynomial data (nexp,
   nphi, expo, per-term poly) and the term indices; 3 adds dampers and
   feedthrough (PD). A model is written in the lowest version that holds it,
   and all three load. */
#define PHGMG_ROM_FORMAT_VERSION 3u

/* Bytes phgmg_rom_serialize writes for this model. */
PHGMG_DEF size_t phgmg_rom_serialized_size(const phgmg_rom *rom);
/* Serialise into buf (cap bytes). *written = bytes used. PHGMG_ERR_WORKSPACE if cap is too small. */
PHGMG_DEF phgmg_result phgmg_rom_serialize(const phgmg_rom *rom, void *buf, size_t cap, size_t *written);
/* Bytes of memory phgmg_rom_deserialize needs to hold the model in buf
   (the arrays are copied, so buf may be freed afterwards; the count includes
   (r + rn)^2 + 4 r + 4 reals of scratch for the structure check). */
PHGMG_DEF phgmg_result phgmg_rom_deserialize_size(const void *buf, size_t len, size_t *need);
/* Rebuild a model from buf into caller memory mem (>= the size above, aligned
   for double); rom's views point into mem. A damaged file: PHGMG_ERR_FORMAT
   (header, sizes, checksum, NaN/Inf). Then a structure check of the values,
   since a checksum can be recomputed after an edit: Qh (QUADRATIC: with Q01,
   Q11) positive definite up to 3.5e-4 ||Qh||_1 (sqrt of float's roundoff: a
   model may have passed through float), the dissipation -(K + K^T)/2
   (QUADRATIC: of the G blocks) positive semidefinite to the same relative
   level, and a step map that satisfies the GL3 stage equations of
   x' = K Qh x + Bh u for the stored dt (within 48 (r + 1) 1.2e-7 of its
   terms' size): PHGMG_ERR_STRUCTURE otherwise (details at
   phgmg__rom_physics).
   No allocation; phgmg_rom_load returns the same codes. */
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
   Read: format versions 1.0, 2.0 and 3.0; dtypes float64/float32 ('<f8',
   '>f8', '<f4', '>f4'), the integers int8 ... int64 and uint8 ... uint64
   ('<i1' '<i2' '<i4' '<i8' '<u1' '<u2' '<u4' '<u8', big-endian '>' too, '|'
   for the one-byte ones) and bool ('|b1'); C or Fortran order; 0-d, 1-d and
   2-d shapes. The result is always a column-major double matrix: shape () is
   1 x 1, shape (n,) is n x 1, shape (r, c) is r x c. Integers convert
   exactly; an (u)int64 beyond 2^53 in magnitude is PHGMG_ERR_INEXACT. bool
   gives 0 and 1. Another dtype (complex, float16, strings, objects,
   structured, native-order '=f8') is PHGMG_ERR_DTYPE. Empty shapes such as
   (0,) or (3, 0) give a zero-size matrix (a valid pointer to no elements).
   Bytes after the data are ignored, as NumPy does. Anything else (bad magic,
   bad header dict, more than two dimensions, a dimension above INT_MAX, a
   header longer than PHGMG_NPY_MAX_HEADER, truncated data) is
   PHGMG_ERR_FORMAT.
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
   rows/cols), PHGMG_ERR_FORMAT, PHGMG_ERR_DTYPE, PHGMG_ERR_INEXACT,
   PHGMG_ERR_NOMEM; *out, *rows, *cols, *ndim are then unchanged. Safe on
   arbitrary bytes. */
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
   promises is PHGMG_ERR_FORMAT (checked before allocating for a regular file;
   from a pipe the buffer grows with the data that actually arrives). */
PHGMG_DEF phgmg_result phgmg_npy_read(const char *path, double **out, int *rows, int *cols,
                                      int *ndim, const phgmg_allocator *alloc);

/* Write A (as phgmg_npy_serialize) to the file path, streaming, without
   allocating. Errors as phgmg_npy_serialize (except WORKSPACE), plus
   PHGMG_ERR_IO. After a write error a file this call created is removed; an
   existing path (a file, a device, a pipe, a symbolic link) is never removed
   (an existing regular file may then be left partly written). */
PHGMG_DEF phgmg_result phgmg_npy_write(const char *path, const double *A, int rows, int cols,
                                       int ld, int ndim, unsigned flags);
#endif /* PHGMG_NO_STDIO */

#ifdef __cplusplus
}
#endif
#endif /* PHGMG_NO_OFFLINE */

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
   default, per thread; both macros can be set before including the
   implementation). With PHGMG_USE_OPENMP and -fopenmp, row blocks run in
   parallel for large products (bit-identical to the serial result). */
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
   kmax = 0 only computes the rank. *rank_out (may be NULL) = r. A whose
   largest |entry| is outside [2^-256, 2^256] is scaled internally by a power
   of two (exact; as LAPACK does), so the results do not depend on the data's
   magnitude anywhere in the floating-point range. Cost grows
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
#define PHGMG__DBL_MIN 2.2250738585072014e-308 /* smallest normal double */

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

/* 2^-e with amax 2^-e in [0.5, 1): a scale that is exact (a power of two),
   for data whose magnitude must not matter; 1 for amax 0, NaN or Inf. */
PHGMG__PRIV double phgmg__pow2_scale(double amax) {
  int e = 0;
  if (!(amax > 0.0) || !(amax < HUGE_VAL)) return 1.0;
  (void)frexp(amax, &e);
  return ldexp(1.0, -e);
}

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

/* >>linalg (prototypes) ================================================== */
/* The dense kernels are defined at the end of this half (>>linalg
   (implementation)), after the domain sections that call them: their
   private helpers are declared here, in the order of their definitions,
   with the vector type that >>sparse also uses. */
#ifndef PHGMG_NO_OFFLINE
#if (defined(__GNUC__) || defined(__clang__)) && defined(__AVX__) && !defined(PHGMG_NO_VECTOR_EXT)
#define PHGMG__VEC4 1
typedef double phgmg__v4 __attribute__((vector_size(32)));
#endif
PHGMG__PRIV double phgmg__dot(int n, const double *x, const double *y);
PHGMG__PRIV void phgmg__axpy(int n, double a, const double *x, double *y);
PHGMG__PRIV void phgmg__rot(int n, double *x, double *y, double c, double s);
PHGMG__PRIV int phgmg__mat_finite(int m, int n, const double *A, int lda);
PHGMG__PRIV double phgmg__sumsq(int n, int ns, const double *A, int lda);
PHGMG__PRIV void phgmg__gemm_micro(int kc, const double *Ap, const double *B, size_t bsp,
                                   size_t bsj, int mr, int nr, double alpha, double *C, int ldc);
PHGMG__PRIV void phgmg__gemm_rowblock(int ic, int mc, int pc, int kc, int n, double alpha, int amode,
                                      const double *A, int lda, const double *B, size_t bsp,
                                      size_t bsj, double *C, int ldc);
PHGMG__PRIV void phgmg__gemm_acc(int m, int n, int k, double alpha, int amode, const double *A,
                                 int lda, const double *B, size_t bsp, size_t bsj, double *C,
                                 int ldc);
PHGMG__PRIV void phgmg__zgemm_acc(int m, int n, int k, double alpha, const double *A, int lda,
                                  const double *B, int ldb, double *C, int ldc);
PHGMG__PRIV void phgmg__laswp(int ncols, double *A, int lda, int k1, int k2, const int *ipiv);
PHGMG__PRIV void phgmg__trsm_llu(int n, int nrhs, const double *L, int ldl, double *B, int ldb);
PHGMG__PRIV void phgmg__trsm_lun(int n, int nrhs, const double *U, int ldu, double *B, int ldb);
PHGMG__PRIV void phgmg__trsm_utn(int n, int nrhs, const double *U, int ldu, double *B, int ldb);
PHGMG__PRIV void phgmg__trsm_ltu(int n, int nrhs, const double *L, int ldl, double *B, int ldb);
PHGMG__PRIV int phgmg__lu_rec(int m, int n, double *A, int lda, int *ipiv);
PHGMG__PRIV void phgmg__zdiv(double ar, double ai, double br, double bi, double *cr, double *ci);
PHGMG__PRIV void phgmg__zaxpy_neg(int n, double tr, double ti, const double *x, double *y);
PHGMG__PRIV void phgmg__zlaswp(int ncols, double *A, int lda, int k1, int k2, const int *ipiv);
PHGMG__PRIV void phgmg__ztrsm_llu(int n, int nrhs, const double *L, int ldl, double *B, int ldb);
PHGMG__PRIV void phgmg__ztrsm_lun(int n, int nrhs, const double *U, int ldu, double *B, int ldb);
PHGMG__PRIV int phgmg__zlu_rec(int m, int n, double *A, int lda, int *ipiv);
PHGMG__PRIV double phgmg__asum(int n, const double *x);
PHGMG__PRIV int phgmg__iamax(int n, const double *x);
PHGMG__PRIV void phgmg__larfg(int n, double *alpha, double *x, double *tau);
PHGMG__PRIV void phgmg__larf_left(int m, int n, const double *v, double tau, double *C, int ldc);
PHGMG__PRIV void phgmg__qrcp_core(int m, int n, double *A, int lda, double *tau, int *jpvt,
                                  double *vn, double tol, int *rank);
PHGMG__PRIV void phgmg__qrcp_blocked(int m, int n, double *A, int lda, double *tau, int *jpvt,
                                     double *vn, double *F, double *aux, int *mark, double tol,
                                     int *rank);
PHGMG__PRIV void phgmg__trsv_upper(int n, const double *R, int ldr, int nrhs, double *B, int ldb);
PHGMG__PRIV phgmg_result phgmg__jacobi_1s(int r, double *X, int ldx, double *V, int ldv,
                                          double *d);
PHGMG__PRIV int phgmg__svd_scale(int m, int n, double *W);
PHGMG__PRIV phgmg_result phgmg__svd_from_qr(int m, int n, int r, const double *W, const double *tau,
                                             const int *jpvt, int *perm, double *vn, int kmax, int esc, double *S,
                                             double *U, int ldu, double *V, int ldv, int *k_out, int *rank_out,
                                             const phgmg_allocator *alloc);
PHGMG__PRIV phgmg_result phgmg__sym_jacobi(int n, double *A, int lda, double *w, double *V,
                                           int ldv);
PHGMG__PRIV void phgmg__tred2(int n, double *W, int ldw, int vec, double *d, double *e);
PHGMG__PRIV void phgmg__tred2_vectors(int n, double *W, int ldw, double *d);
PHGMG__PRIV phgmg_result phgmg__tql2(int n, double *W, int ldw, int vec, double *d, double *e);
PHGMG__PRIV phgmg_result phgmg__sym_tridiag_ql(int n, double *W, int ldw, int vec, double *d,
                                               double *e);
#endif /* PHGMG_NO_OFFLINE */

/* >>ph (implementation) ================================================== */
#ifndef PHGMG_NO_OFFLINE

/* a*b + c, fused where the target has a fast fma (the hot loops of the
   stepper); plain otherwise (ISO C modes do not contract a*b + c). */
#if defined(FP_FAST_FMA)
#define PHGMG__FMA(a, b, c) fma((a), (b), (c))
#else
#define PHGMG__FMA(a, b, c) ((a) * (b) + (c))
#endif

/* Index of element (i,j), |i-j| <= kb, in the (2kb+1) x N band storage. */
#define PHGMG__PHB(kb, i, j) \
  ((size_t)((kb) + (i) - (j)) + (size_t)(j) * (size_t)(2 * (kb) + 1))

/* Above this N a banded, non-diagonal R is checked for semidefiniteness by a
   shifted band Cholesky instead of a dense eigenvalue computation. */
#define PHGMG__PH_PSD_DENSE_MAX 2000

PHGMG__PRIV int phgmg__ph_csc_of(const phgmg_ph_system *s, const double *M, const int **cp, const int **ci,
                                 const double **cx);
PHGMG__PRIV phgmg_result phgmg__ph_sparse_own_band(const phgmg_ph_system *s, int a1, int a2, phgmg_ph_system *t,
                                                  double **bands, int **perm, const phgmg_allocator *al);
PHGMG__PRIV void phgmg__ph_own_band_free(phgmg_ph_system *t, double **bands, int *perm, const phgmg_allocator *al);

/* Element (i,j) of J, R or Q (0 outside the band or the pattern). */
PHGMG__PRIV double phgmg__ph_at(const phgmg_ph_system *s, const double *M, int i, int j) {
  const int *cp, *ci;
  const double *cx;
  if (phgmg__ph_csc_of(s, M, &cp, &ci, &cx)) { /* binary search in column j */
    int lo = cp[j], hi = cp[j + 1];
    while (lo < hi) {
      int mid = lo + (hi - lo) / 2;
      if (ci[mid] < i) lo = mid + 1; else hi = mid;
    }
    return lo < cp[j + 1] && ci[lo] == i ? cx[lo] : 0.0;
  }
  if (s->storage == PHGMG_BANDED) {
    int d = i - j;
    if (d > s->kb || d < -s->kb) return 0.0;
    return M[PHGMG__PHB(s->kb, i, j)];
  }
  return M[(size_t)i + (size_t)j * (size_t)s->N];
}

/* y = M x (overwrite) for a dense or banded system matrix. */
PHGMG__PRIV int phgmg__ph_sparse_mv(const phgmg_ph_system *s, const double *M, const double *x,
                                     double *y);
PHGMG__PRIV void phgmg__ph_mv(const phgmg_ph_system *s, const double *M, const double *x,
                              double *y) {
  int N = s->N, i, j;
  if (s->sparse && phgmg__ph_sparse_mv(s, M, x, y)) return;
  for (i = 0; i < N; ++i) y[i] = 0.0;
  if (s->storage == PHGMG_BANDED) {
    int kb = s->kb;
    for (j = 0; j < N; ++j) {
      double xj = x[j];
      int i0 = PHGMG__MAX(0, j - kb), i1 = PHGMG__MIN(N - 1, j + kb);
      const double *col = M + PHGMG__PHB(kb, 0, j);
      if (xj == 0.0) continue;
      for (i = i0; i <= i1; ++i) y[i] += col[i] * xj;
    }
  } else {
    for (j = 0; j < N; ++j) {
      const double *col = M + (size_t)j * (size_t)N;
      double xj = x[j];
      if (xj == 0.0) continue;
      for (i = 0; i < N; ++i) y[i] += col[i] * xj;
    }
  }
}

/* y = M^T x (overwrite) for a dense or banded system matrix. */
PHGMG__PRIV void phgmg__ph_mtv(const phgmg_ph_system *s, const double *M, const double *x, double *y) {
  int N = s->N, i, j;
  const int *cp, *ci;
  const double *cx;
  if (phgmg__ph_csc_of(s, M, &cp, &ci, &cx)) {
    for (j = 0; j < N; ++j) {
      double acc = 0.0;
      for (i = cp[j]; i < cp[j + 1]; ++i) acc += cx[i] * x[ci[i]];
      y[j] = acc;
    }
    return;
  }
  for (j = 0; j < N; ++j) {
    double acc = 0.0;
    if (s->storage == PHGMG_BANDED) {
      int kb = s->kb, i0 = PHGMG__MAX(0, j - kb), i1 = PHGMG__MIN(N - 1, j + kb);
      const double *col = M + PHGMG__PHB(kb, 0, j);
      for (i = i0; i <= i1; ++i) acc += col[i] * x[i];
    } else {
      const double *col = M + (size_t)j * (size_t)N;
      for (i = 0; i < N; ++i) acc += col[i] * x[i];
    }
    y[j] = acc;
  }
}

/* Y = E X ('N') or E^T X ('T') for an N x nc block (E NULL: the identity). */
PHGMG__PRIV void phgmg__ph_e_apply(const phgmg_ph_system *s, char trans, int nc, const double *X, int ldx,
                                   double *Y, int ldy) {
  int c;
  for (c = 0; c < nc; ++c) {
    const double *x = X + (size_t)c * (size_t)ldx;
    double *y = Y + (size_t)c * (size_t)ldy;
    if (!s->E) memcpy(y, x, sizeof(double) * (size_t)s->N);
    else if (trans == 'T') phgmg__ph_mtv(s, s->E, x, y);
    else phgmg__ph_mv(s, s->E, x, y);
  }
}

/* x^T M y without temporaries. */
PHGMG__PRIV double phgmg__ph_quad(const phgmg_ph_system *s, const double *M, const double *x,
                                  const double *y) {
  int N = s->N, i, j;
  double acc = 0.0;
  const int *cp, *ci;
  const double *cx;
  if (phgmg__ph_csc_of(s, M, &cp, &ci, &cx)) {
    for (j = 0; j < N; ++j) {
      double t = 0.0;
      for (i = cp[j]; i < cp[j + 1]; ++i) t += x[ci[i]] * cx[i];
      acc += t * y[j];
    }
    return acc;
  }
  for (j = 0; j < N; ++j) {
    double t = 0.0;
    if (s->storage == PHGMG_BANDED) {
      int kb = s->kb, i0 = PHGMG__MAX(0, j - kb), i1 = PHGMG__MIN(N - 1, j + kb);
      const double *col = M + PHGMG__PHB(kb, 0, j);
      for (i = i0; i <= i1; ++i) t += x[i] * col[i];
    } else {
      const double *col = M + (size_t)j * (size_t)N;
      for (i = 0; i < N; ++i) t += x[i] * col[i];
    }
    acc += t * y[j];
  }
  return acc;
}

/* Built-in exp-polynomial form of the separable nonlinearity in use? */
#define PHGMG__PH_BUILTIN(s) ((s)->poly_deg > 0 || (s)->nexp > 0)
/* Function index t of term k for the built-in form (0: shared). */
#define PHGMG__PH_FUN(s, k) ((s)->phi_nfun > 1 ? (k) : 0)

/* d-th derivative (d = 0,1,2) of the scalar nonlinearity of term k at v. */
PHGMG__PRIV double phgmg__ph_phi(const phgmg_ph_system *s, int k, double v, int d) {
  if (PHGMG__PH_BUILTIN(s)) {
    int j, e, t = PHGMG__PH_FUN(s, k);
    double acc = 0.0;
    if (s->poly) {
      const double *c = s->poly + (size_t)t * (size_t)(s->poly_deg + 1);
      for (j = s->poly_deg; j >= d; --j) {
        double cj = c[j];
        if (d == 1) cj *= (double)j;
        else if (d == 2) cj *= (double)j * (double)(j - 1);
        acc = acc * v + cj;
      }
    }
    if (s->nexp > 0) {
      const double *p = s->expo + 2 * (size_t)t * (size_t)s->nexp;
      for (e = 0; e < s->nexp; ++e) {
        double a = p[2 * e], b = p[2 * e + 1];
        if (d == 1) a *= b;
        else if (d == 2) a *= b * b;
        acc += a * exp(b * v);
      }
    }
    return acc;
  }
  if (d == 0) return s->phi(k, v, s->user);
  if (d == 1) return s->dphi(k, v, s->user);
  return s->ddphi(k, v, s->user);
}

/* phi_t'(v) of built-in function t (no branches on the derivative order). */
PHGMG__PRIV double phgmg__ph_dphi_builtin(const phgmg_ph_system *s, int t, double v) {
  const int deg = s->poly_deg, ne = s->nexp;
  double acc = 0.0;
  int j;
  if (deg > 0) {
    const double *c = s->poly + (size_t)t * (size_t)(deg + 1);
    for (j = deg; j >= 1; --j) acc = acc * v + (double)j * c[j];
  }
  if (ne > 0) {
    const double *p = s->expo + 2 * (size_t)t * (size_t)ne;
    for (j = 0; j < ne; ++j) acc += p[2 * j] * p[2 * j + 1] * exp(p[2 * j + 1] * v);
  }
  return acc;
}

/* phi_k, phi_k', phi_k'' at x at once (built-in form or callbacks). */
PHGMG__PRIV void phgmg__ph_phi3(const phgmg_ph_system *s, int k, double x, double d[3]) {
  if (PHGMG__PH_BUILTIN(s)) {
    int j, e, t = PHGMG__PH_FUN(s, k);
    double v0 = 0.0, v1 = 0.0, v2 = 0.0;
    if (s->poly) {
      const double *c = s->poly + (size_t)t * (size_t)(s->poly_deg + 1);
      for (j = s->poly_deg; j >= 0; --j) { /* Horner with derivatives */
        v2 = v2 * x + 2.0 * v1;
        v1 = v1 * x + v0;
        v0 = v0 * x + c[j];
      }
    }
    if (s->nexp > 0) {
      const double *p = s->expo + 2 * (size_t)t * (size_t)s->nexp;
      for (e = 0; e < s->nexp; ++e) {
        double b = p[2 * e + 1], ae = p[2 * e] * exp(b * x);
        v0 += ae;
        v1 += ae * b;
        v2 += ae * b * b;
      }
    }
    d[0] = v0; d[1] = v1; d[2] = v2;
    return;
  }
  d[0] = s->phi(k, x, s->user);
  d[1] = s->dphi(k, x, s->user);
  d[2] = s->ddphi(k, x, s->user);
}

/* >>dampers: nonlinear dissipation sum_k c_k rho_k(c_k^T z), c_k = e_i - e_j. */
#define PHGMG__DAMP_DEG_MAX 15
PHGMG__PRIV int phgmg__damp_j(const phgmg_ph_system *s, int k) {
  return s->damp_j ? s->damp_j[k] : -1;
}
/* s_k = c_k^T z */
PHGMG__PRIV double phgmg__damp_s(const phgmg_ph_system *s, int k, const double *z) {
  const int j = phgmg__damp_j(s, k);
  return j >= 0 ? z[s->damp_i[k]] - z[j] : z[s->damp_i[k]];
}
/* d[0] = rho_k(v), d[1] = rho_k'(v). */
PHGMG__PRIV void phgmg__damp_law(const phgmg_ph_system *s, int k, double v, double d[2]) {
  const double *a;
  int e;
  if (!s->damp_poly) { s->damp_fn(k, v, d, s->damp_user); return; }
  a = s->damp_poly + (s->damp_nfun > 1 ? (size_t)k * (size_t)(s->damp_deg + 1) : 0);
  d[0] = a[s->damp_deg];
  d[1] = (double)s->damp_deg * a[s->damp_deg];
  for (e = s->damp_deg - 1; e >= 1; --e) {
    d[0] = d[0] * v + a[e];
    d[1] = d[1] * v + (double)e * a[e];
  }
  d[0] *= v;
}
/* f += alpha sum_k c_k rho_k(c_k^T z); returns sum_k s_k rho_k(s_k), or -1
   when a callback damper generates energy (s rho(s) < 0) or gives NaN. */
PHGMG__PRIV double phgmg__damp_apply(const phgmg_ph_system *s, const double *z, double alpha, double *f) {
  double dis = 0.0, d[2];
  int k;
  for (k = 0; k < s->ndamp; ++k) {
    const double v = phgmg__damp_s(s, k, z);
    const int j = phgmg__damp_j(s, k);
    phgmg__damp_law(s, k, v, d);
    if (!(v * d[0] >= 0.0)) return -1.0;
    dis += v * d[0];
    if (f) {
      f[s->damp_i[k]] += alpha * d[0];
      if (j >= 0) f[j] -= alpha * d[0];
    }
  }
  return dis;
}
/* Damper data: sizes, indices, finite coefficients, a dissipative odd
   polynomial (PHGMG_ERR_DAMPER for a_0 != 0, an even a_d != 0 or an odd
   a_d < 0). */
PHGMG__PRIV phgmg_result phgmg__ph_check_dampers(const phgmg_ph_system *s) {
  int k, e, nf;
  if (s->ndamp < 0) return PHGMG_ERR_SIZE;
  if (!s->damp_i || (!s->damp_poly && !s->damp_fn)) return PHGMG_ERR_INVALID_ARG;
  if (s->shifted_factor) return PHGMG_ERR_UNSUPPORTED;
  for (k = 0; k < s->ndamp; ++k) {
    const int i = s->damp_i[k], j = phgmg__damp_j(s, k);
    if (i < 0 || i >= s->N || j >= s->N || i == j) return PHGMG_ERR_SIZE;
    if (s->storage == PHGMG_BANDED && j >= 0 && (i > j ? i - j : j - i) > s->kb) return PHGMG_ERR_SIZE;
  }
  if (!s->damp_poly) return PHGMG_OK;
  if (s->damp_deg < 1 || s->damp_deg > PHGMG__DAMP_DEG_MAX) return PHGMG_ERR_SIZE;
  if (s->damp_nfun < 0 || (s->damp_nfun > 1 && s->damp_nfun != s->ndamp)) return PHGMG_ERR_SIZE;
  nf = s->damp_nfun > 1 ? s->damp_nfun : 1;
  if (!phgmg__all_finite(s->damp_poly, (size_t)nf * (size_t)(s->damp_deg + 1))) return PHGMG_ERR_NANINF;
  for (k = 0; k < nf; ++k)
    for (e = 0; e <= s->damp_deg; ++e) {
      const double a = s->damp_poly[(size_t)k * (size_t)(s->damp_deg + 1) + (size_t)e];
      if ((e % 2 == 0 && a != 0.0) || a < 0.0) return PHGMG_ERR_DAMPER;
    }
  return PHGMG_OK;
}

PHGMG__PRIV phgmg_result phgmg__ph_check_sparse(const phgmg_ph_system *s);

/* Structural checks shared by every entry point (no O(N^2) work). */
PHGMG__PRIV phgmg_result phgmg__ph_check(const phgmg_ph_system *s) {
  phgmg_result rc;
  int k;
  if (!s) return PHGMG_ERR_INVALID_ARG;
  if (s->N <= 0 || s->m <= 0 || s->m > s->N) return PHGMG_ERR_SIZE;
  if (s->storage != PHGMG_DENSE && s->storage != PHGMG_BANDED && s->storage != PHGMG_SPARSE)
    return PHGMG_ERR_INVALID_ARG;
  if (s->storage == PHGMG_BANDED && (s->kb < 0 || s->kb > s->N - 1)) return PHGMG_ERR_SIZE;
  if (s->storage == PHGMG_SPARSE && (rc = phgmg__ph_check_sparse(s)) != PHGMG_OK) return rc;
  if (!s->J || !s->R || !s->Q || !s->B) return PHGMG_ERR_INVALID_ARG;
  if ((s->shifted_factor == NULL) != (s->shifted_solve == NULL)) return PHGMG_ERR_INVALID_ARG;
  if (s->E && (s->nl == PHGMG_NL_GENERAL || s->shifted_factor)) return PHGMG_ERR_UNSUPPORTED;
  switch (s->nl) {
    case PHGMG_NL_NONE: break;
    case PHGMG_NL_SEPARABLE:
      if (s->nsep < 0 || s->poly_deg < 0 || s->poly_deg > 32 || s->nexp < 0 || s->nexp > 8)
        return PHGMG_ERR_SIZE;
      if (s->phi_nfun < 0 || (s->phi_nfun > 1 && s->phi_nfun != s->nsep)) return PHGMG_ERR_SIZE;
      if (s->nsep > 0 && !s->sep_idx) return PHGMG_ERR_INVALID_ARG;
      for (k = 0; k < s->nsep; ++k)
        if (s->sep_idx[k] < 0 || s->sep_idx[k] >= s->N) return PHGMG_ERR_SIZE;
      if (PHGMG__PH_BUILTIN(s)) {
        size_t nf = (size_t)(s->phi_nfun > 1 ? s->phi_nfun : 1);
        if ((s->poly_deg > 0 && !s->poly) || (s->nexp > 0 && !s->expo)) return PHGMG_ERR_INVALID_ARG;
        if (s->poly && !phgmg__all_finite(s->poly, nf * (size_t)(s->poly_deg + 1))) return PHGMG_ERR_NANINF;
        if (s->nexp > 0 && !phgmg__all_finite(s->expo, nf * 2 * (size_t)s->nexp)) return PHGMG_ERR_NANINF;
      } else if (s->nsep > 0 && (!s->phi || !s->dphi || !s->ddphi)) {
        return PHGMG_ERR_INVALID_ARG;
      }
      break;
    case PHGMG_NL_GENERAL:
      if (!s->H_nl || !s->grad_nl || !s->hess_nl) return PHGMG_ERR_INVALID_ARG;
      break;
    default: return PHGMG_ERR_INVALID_ARG;
  }
  return s->ndamp ? phgmg__ph_check_dampers(s) : PHGMG_OK;
}

/* Finiteness of the valid entries of a dense or banded system matrix. */
PHGMG__PRIV int phgmg__ph_mat_finite(const phgmg_ph_system *s, const double *M) {
  int N = s->N, j;
  const int *cp, *ci;
  const double *cx;
  if (phgmg__ph_csc_of(s, M, &cp, &ci, &cx)) return phgmg__all_finite(cx, (size_t)cp[N]);
  if (s->storage == PHGMG_DENSE) return phgmg__all_finite(M, (size_t)N * (size_t)N);
  for (j = 0; j < N; ++j) {
    int i0 = PHGMG__MAX(0, j - s->kb), i1 = PHGMG__MIN(N - 1, j + s->kb);
    if (!phgmg__all_finite(M + PHGMG__PHB(s->kb, i0, j), (size_t)(i1 - i0 + 1))) return 0;
  }
  return 1;
}

/* g = Q x + grad H_nl(x); tmp (N doubles) is needed for GENERAL only. */
PHGMG__PRIV void phgmg__ph_grad(const phgmg_ph_system *s, const double *x, double *g,
                                double *tmp) {
  int k, i;
  phgmg__ph_mv(s, s->Q, x, g);
  if (s->nl == PHGMG_NL_SEPARABLE) {
    for (k = 0; k < s->nsep; ++k) {
      int ix = s->sep_idx[k];
      double w = s->sep_w ? s->sep_w[k] : 1.0;
      g[ix] += w * phgmg__ph_phi(s, k, x[ix], 1);
    }
  } else if (s->nl == PHGMG_NL_GENERAL) {
    s->grad_nl(x, tmp, s->user);
    for (i = 0; i < s->N; ++i) g[i] += tmp[i];
  }
}

/* A scratch vector of N doubles for the allocation-free public evaluators:
   the stack for small N, the default allocator otherwise (NULL on failure). */
#define PHGMG__PH_STACK 256
PHGMG__PRIV double *phgmg__ph_scratch(int n, double *stackbuf) {
  if (n <= PHGMG__PH_STACK) return stackbuf;
  return phgmg__dalloc(NULL, (size_t)n);
}
PHGMG__PRIV void phgmg__ph_scratch_free(double *p, double *stackbuf) {
  if (p != stackbuf) phgmg__free(NULL, p);
}

/* Descriptor Hamiltonian 1/2 (E x)^T (Q x) + sum_k E_kk w_k phi_k(x_k) (NaN
   when the scratch vectors cannot be had). */
PHGMG__PRIV double phgmg__ph_hamiltonian_e(const phgmg_ph_system *sys, const double *x) {
  double sb[2 * PHGMG__PH_STACK], *ex, H = 0.0;
  int N = sys->N, k;
  ex = N <= PHGMG__PH_STACK ? sb : phgmg__dalloc(NULL, 2 * (size_t)N);
  if (!ex) return (double)NAN;
  phgmg__ph_mv(sys, sys->E, x, ex);
  phgmg__ph_mv(sys, sys->Q, x, ex + N);
  for (k = 0; k < N; ++k) H += ex[k] * ex[N + k];
  H *= 0.5;
  if (ex != sb) phgmg__free(NULL, ex);
  if (sys->nl == PHGMG_NL_SEPARABLE)
    for (k = 0; k < sys->nsep; ++k) {
      const int ix = sys->sep_idx[k];
      H += phgmg__ph_at(sys, sys->E, ix, ix) * (sys->sep_w ? sys->sep_w[k] : 1.0) * phgmg__ph_phi(sys, k, x[ix], 0);
    }
  return H;
}

PHGMG_DEF double phgmg_ph_hamiltonian(const phgmg_ph_system *sys, const double *x) {
  double H;
  int k;
  PHGMG_ASSERT(sys && x);
  if (sys->E) return phgmg__ph_hamiltonian_e(sys, x);
  H = 0.5 * phgmg__ph_quad(sys, sys->Q, x, x);
  if (sys->nl == PHGMG_NL_SEPARABLE) {
    for (k = 0; k < sys->nsep; ++k)
      H += (sys->sep_w ? sys->sep_w[k] : 1.0) * phgmg__ph_phi(sys, k, x[sys->sep_idx[k]], 0);
  } else if (sys->nl == PHGMG_NL_GENERAL) {
    H += sys->H_nl(x, sys->user);
  }
  return H;
}

PHGMG_DEF void phgmg_ph_gradient(const phgmg_ph_system *sys, const double *x, double *g) {
  PHGMG_ASSERT(sys && x && g);
  if (sys->nl == PHGMG_NL_GENERAL) {
    double sb[PHGMG__PH_STACK], *tmp = phgmg__ph_scratch(sys->N, sb);
    int i;
    if (!tmp) { for (i = 0; i < sys->N; ++i) g[i] = (double)NAN; return; }
    phgmg__ph_grad(sys, x, g, tmp);
    phgmg__ph_scratch_free(tmp, sb);
  } else {
    phgmg__ph_grad(sys, x, g, NULL);
  }
}

/* Public evaluators that need a gradient scratch vector take it from the stack
   (N <= 256) or the default allocator; if that fails the result is NaN. */
PHGMG_DEF void phgmg_ph_rhs(const phgmg_ph_system *sys, const double *x, const double *u,
                            double *f) {
  double sb[PHGMG__PH_STACK], *g;
  double *tmp = NULL;
  int N, i, j;
  PHGMG_ASSERT(sys && x && f);
  N = sys->N;
  g = phgmg__ph_scratch(N, sb);
  if (g && sys->nl == PHGMG_NL_GENERAL) {
    tmp = phgmg__dalloc(NULL, (size_t)N);
    if (!tmp) { phgmg__ph_scratch_free(g, sb); g = NULL; }
  }
  if (!g) { for (i = 0; i < N; ++i) f[i] = (double)NAN; return; }
  phgmg__ph_grad(sys, x, g, tmp);
  phgmg__ph_mv(sys, sys->J, g, f);
  /* f -= R g, column by column (no second scratch vector) */
  for (j = 0; j < N; ++j) {
    double gj = g[j];
    const int *cp, *ci;
    const double *cx;
    if (gj == 0.0) continue;
    if (phgmg__ph_csc_of(sys, sys->R, &cp, &ci, &cx)) {
      int p;
      for (p = cp[j]; p < cp[j + 1]; ++p) f[ci[p]] -= cx[p] * gj;
    } else if (sys->storage == PHGMG_BANDED) {
      int kb = sys->kb, i0 = PHGMG__MAX(0, j - kb), i1 = PHGMG__MIN(N - 1, j + kb);
      const double *col = sys->R + PHGMG__PHB(kb, 0, j);
      for (i = i0; i <= i1; ++i) f[i] -= col[i] * gj;
    } else {
      const double *col = sys->R + (size_t)j * (size_t)N;
      for (i = 0; i < N; ++i) f[i] -= col[i] * gj;
    }
  }
  if (u)
    for (j = 0; j < sys->m; ++j) {
      const double *bj = sys->B + (size_t)j * (size_t)N;
      for (i = 0; i < N; ++i) f[i] += bj[i] * u[j];
      if (sys->P)
        for (i = 0; i < N; ++i) f[i] -= sys->P[(size_t)i + (size_t)j * (size_t)N] * u[j];
    }
  if (sys->ndamp && phgmg__damp_apply(sys, g, -1.0, f) < 0.0)
    for (i = 0; i < N; ++i) f[i] = (double)NAN;
  phgmg__free(NULL, tmp);
  phgmg__ph_scratch_free(g, sb);
}

PHGMG_DEF void phgmg_ph_output(const phgmg_ph_system *sys, const double *x, double *y) {
  double sb[PHGMG__PH_STACK], *g, *tmp = NULL;
  int N, i, j;
  PHGMG_ASSERT(sys && x && y);
  N = sys->N;
  g = phgmg__ph_scratch(N, sb);
  if (g && sys->nl == PHGMG_NL_GENERAL) {
    tmp = phgmg__dalloc(NULL, (size_t)N);
    if (!tmp) { phgmg__ph_scratch_free(g, sb); g = NULL; }
  }
  if (!g) { for (j = 0; j < sys->m; ++j) y[j] = (double)NAN; return; }
  phgmg__ph_grad(sys, x, g, tmp);
  for (j = 0; j < sys->m; ++j) {
    const double *bj = sys->B + (size_t)j * (size_t)N;
    double acc = 0.0;
    for (i = 0; i < N; ++i) acc += bj[i] * g[i];
    if (sys->P)
      for (i = 0; i < N; ++i) acc += sys->P[(size_t)i + (size_t)j * (size_t)N] * g[i];
    y[j] = acc;
  }
  phgmg__free(NULL, tmp);
  phgmg__ph_scratch_free(g, sb);
}

PHGMG_DEF void phgmg_ph_apply(const phgmg_ph_system *sys, char which, int nrhs,
                              const double *X, int ldx, double *Y, int ldy) {
  const double *M;
  int c;
  PHGMG_ASSERT(sys && X && Y && ldx >= sys->N && ldy >= sys->N);
  M = which == 'J' || which == 'j' ? sys->J : which == 'R' || which == 'r' ? sys->R : sys->Q;
  PHGMG_ASSERT(which == 'J' || which == 'j' || which == 'R' || which == 'r' || which == 'Q' ||
               which == 'q');
  if (sys->storage == PHGMG_DENSE) {
    phgmg_gemm('N', 'N', sys->N, nrhs, sys->N, 1.0, M, sys->N, X, ldx, 0.0, Y, ldy);
    return;
  }
  for (c = 0; c < nrhs; ++c)
    phgmg__ph_mv(sys, M, X + (size_t)c * (size_t)ldx, Y + (size_t)c * (size_t)ldy);
}

/* ---- banded LU with partial pivoting (LAPACK dgbtf2/dgbtrs layout) -------- */
/* ab is ldab x n, ldab >= 2kl+ku+1; A(i,j) sits at ab[(kl+ku+i-j) + j*ldab],
   the top kl rows are fill-in space and must be zero on entry. ipiv[j] = row
   swapped with j. *ue receives the actual upper bandwidth of U (<= kl+ku; ku
   when no row was swapped), dinv the reciprocals of U's diagonal. */
PHGMG__PRIV phgmg_result phgmg__gb_factor(int n, int kl, int ku, double *ab, int ldab, int *ipiv,
                                          double *dinv, int *ue) {
  int kv = kl + ku, j, ju = 0, uext = 0;
  for (j = 0; j < n; ++j) {
    int km = PHGMG__MIN(kl, n - 1 - j), jp = 0, p, c;
    double *colj = ab + (size_t)j * (size_t)ldab + kv; /* colj[p] = A(j+p, j) */
    double amax = fabs(colj[0]);
    for (p = 1; p <= km; ++p)
      if (fabs(colj[p]) > amax) { amax = fabs(colj[p]); jp = p; }
    ipiv[j] = j + jp;
    if (!(amax > 0.0)) return amax == 0.0 ? PHGMG_ERR_SINGULAR : PHGMG_ERR_NANINF;
    if (amax == HUGE_VAL) return PHGMG_ERR_NANINF;
    ju = PHGMG__MAX(ju, PHGMG__MIN(j + ku + jp, n - 1));
    if (ju - j > uext) uext = ju - j;
    if (jp != 0)
      for (c = j; c <= ju; ++c) {
        size_t a = (size_t)(kv + j - c) + (size_t)c * (size_t)ldab, b = a + (size_t)jp;
        double t = ab[a];
        ab[a] = ab[b];
        ab[b] = t;
      }
    dinv[j] = 1.0 / colj[0];
    if (km > 0) {
      double r = dinv[j];
      for (p = 1; p <= km; ++p) colj[p] *= r;
      for (c = j + 1; c <= ju; ++c) {
        double *colc = ab + (size_t)(kv + j - c) + (size_t)c * (size_t)ldab; /* A(j+p,c) */
        double t = colc[0];
        if (t != 0.0)
          for (p = 1; p <= km; ++p) colc[p] -= colj[p] * t;
      }
    }
  }
  *ue = uext;
  return PHGMG_OK;
}

/* Solve A x = b ('N') or A^T x = b ('T') with the band factors, b overwritten. */
PHGMG__PRIV void phgmg__gb_solve(char trans, int n, int kl, int ku, int ue, const double *ab,
                                 int ldab, const int *ipiv, const double *dinv, double *b) {
  int kv = kl + ku, j, p;
  if (trans == 'N' || trans == 'n') {
    for (j = 0; j < n; ++j) {
      int km = PHGMG__MIN(kl, n - 1 - j), jp = ipiv[j];
      const double *l = ab + (size_t)j * (size_t)ldab + kv;
      double t;
      if (jp != j) { t = b[j]; b[j] = b[jp]; b[jp] = t; }
      t = b[j];
      if (t != 0.0)
        for (p = 1; p <= km; ++p) b[j + p] -= l[p] * t;
    }
    for (j = n - 1; j >= 0; --j) {
      int i0 = PHGMG__MAX(0, j - ue), i;
      size_t base = (size_t)j * (size_t)ldab + (size_t)kv - (size_t)j; /* + i = U(i,j) */
      double t = b[j] * dinv[j];
      b[j] = t;
      if (t != 0.0)
        for (i = i0; i < j; ++i) b[i] -= ab[base + (size_t)i] * t;
    }
  } else {
    for (j = 0; j < n; ++j) {
      int i0 = PHGMG__MAX(0, j - ue), i;
      size_t base = (size_t)j * (size_t)ldab + (size_t)kv - (size_t)j;
      double t = b[j];
      for (i = i0; i < j; ++i) t -= ab[base + (size_t)i] * b[i];
      b[j] = t * dinv[j];
    }
    for (j = n - 2; j >= 0; --j) {
      int km = PHGMG__MIN(kl, n - 1 - j), jp = ipiv[j];
      const double *l = ab + (size_t)j * (size_t)ldab + kv;
      double t = b[j];
      for (p = 1; p <= km; ++p) t -= l[p] * b[j + p];
      b[j] = t;
      if (jp != j) { t = b[j]; b[j] = b[jp]; b[jp] = t; }
    }
  }
}

/* Complex (interleaved) versions: element r of column j at ab[2*(r + j*ldab)]. */
PHGMG__PRIV phgmg_result phgmg__zgb_factor(int n, int kl, int ku, double *ab, int ldab,
                                           int *ipiv, double *dinv, int *ue) {
  int kv = kl + ku, j, ju = 0, uext = 0;
  for (j = 0; j < n; ++j) {
    int km = PHGMG__MIN(kl, n - 1 - j), jp = 0, p, c;
    double *colj = ab + 2 * ((size_t)j * (size_t)ldab + (size_t)kv);
    double amax = fabs(colj[0]) + fabs(colj[1]), pr, pi, rr, ri;
    for (p = 1; p <= km; ++p) {
      double v = fabs(colj[2 * p]) + fabs(colj[2 * p + 1]);
      if (v > amax) { amax = v; jp = p; }
    }
    ipiv[j] = j + jp;
    if (!(amax > 0.0)) return amax == 0.0 ? PHGMG_ERR_SINGULAR : PHGMG_ERR_NANINF;
    if (amax == HUGE_VAL) return PHGMG_ERR_NANINF;
    ju = PHGMG__MAX(ju, PHGMG__MIN(j + ku + jp, n - 1));
    if (ju - j > uext) uext = ju - j;
    if (jp != 0)
      for (c = j; c <= ju; ++c) {
        size_t a = 2 * ((size_t)(kv + j - c) + (size_t)c * (size_t)ldab), b = a + 2 * (size_t)jp;
        double t = ab[a];
        ab[a] = ab[b]; ab[b] = t;
        t = ab[a + 1]; ab[a + 1] = ab[b + 1]; ab[b + 1] = t;
      }
    /* reciprocal of the pivot (Smith) */
    pr = colj[0]; pi = colj[1];
    if (fabs(pr) >= fabs(pi)) {
      double q = pi / pr, d = pr + pi * q;
      rr = 1.0 / d; ri = -q / d;
    } else {
      double q = pr / pi, d = pr * q + pi;
      rr = q / d; ri = -1.0 / d;
    }
    dinv[2 * j] = rr; dinv[2 * j + 1] = ri;
    if (km > 0) {
      for (p = 1; p <= km; ++p) {
        double xr = colj[2 * p], xi = colj[2 * p + 1];
        colj[2 * p] = xr * rr - xi * ri;
        colj[2 * p + 1] = xr * ri + xi * rr;
      }
      for (c = j + 1; c <= ju; ++c) {
        double *colc = ab + 2 * ((size_t)(kv + j - c) + (size_t)c * (size_t)ldab);
        double tr = colc[0], ti = colc[1];
        if (tr == 0.0 && ti == 0.0) continue;
        for (p = 1; p <= km; ++p) {
          double lr = colj[2 * p], li = colj[2 * p + 1];
          colc[2 * p] -= lr * tr - li * ti;
          colc[2 * p + 1] -= lr * ti + li * tr;
        }
      }
    }
  }
  *ue = uext;
  return PHGMG_OK;
}

PHGMG__PRIV void phgmg__zgb_solve(int n, int kl, int ku, int ue, const double *ab, int ldab,
                                  const int *ipiv, const double *dinv, double *b) {
  int kv = kl + ku, j, p;
  for (j = 0; j < n; ++j) {
    int km = PHGMG__MIN(kl, n - 1 - j), jp = ipiv[j];
    const double *l = ab + 2 * ((size_t)j * (size_t)ldab + (size_t)kv);
    double tr, ti;
    if (jp != j) {
      tr = b[2 * j]; b[2 * j] = b[2 * jp]; b[2 * jp] = tr;
      ti = b[2 * j + 1]; b[2 * j + 1] = b[2 * jp + 1]; b[2 * jp + 1] = ti;
    }
    tr = b[2 * j]; ti = b[2 * j + 1];
    if (tr == 0.0 && ti == 0.0) continue;
    for (p = 1; p <= km; ++p) {
      double lr = l[2 * p], li = l[2 * p + 1];
      b[2 * (j + p)] -= lr * tr - li * ti;
      b[2 * (j + p) + 1] -= lr * ti + li * tr;
    }
  }
  for (j = n - 1; j >= 0; --j) {
    int i0 = PHGMG__MAX(0, j - ue), i;
    size_t base = (size_t)j * (size_t)ldab + (size_t)kv - (size_t)j;
    double xr = b[2 * j], xi = b[2 * j + 1], rr = dinv[2 * j], ri = dinv[2 * j + 1];
    double tr = xr * rr - xi * ri, ti = xr * ri + xi * rr;
    b[2 * j] = tr; b[2 * j + 1] = ti;
    if (tr == 0.0 && ti == 0.0) continue;
    for (i = i0; i < j; ++i) {
      const double *u = ab + 2 * (base + (size_t)i);
      b[2 * i] -= u[0] * tr - u[1] * ti;
      b[2 * i + 1] -= u[0] * ti + u[1] * tr;
    }
  }
}

/* A band LU object (real), owned by the jr factor and the validator. */
typedef struct phgmg__gbf {
  int n, kl, ku, ldab, ue;
  double *ab, *dinv;
  int *ipiv;
} phgmg__gbf;

PHGMG__PRIV void phgmg__gbf_free(const phgmg_allocator *al, phgmg__gbf *f) {
  phgmg__free(al, f->ab);
  phgmg__free(al, f->dinv);
  phgmg__free(al, f->ipiv);
  f->ab = f->dinv = NULL;
  f->ipiv = NULL;
}

/* Factor J - R of a banded system (kl = ku = kb). */
PHGMG__PRIV phgmg_result phgmg__gbf_jr(const phgmg_allocator *al, const phgmg_ph_system *s,
                                       phgmg__gbf *f) {
  int N = s->N, kb = s->kb, i, j;
  f->n = N; f->kl = kb; f->ku = kb; f->ldab = 3 * kb + 1; f->ue = 0;
  f->ab = phgmg__dalloc(al, (size_t)f->ldab * (size_t)N);
  f->dinv = phgmg__dalloc(al, (size_t)N);
  f->ipiv = phgmg__ialloc(al, (size_t)N);
  if (!f->ab || !f->dinv || !f->ipiv) { phgmg__gbf_free(al, f); return PHGMG_ERR_NOMEM; }
  memset(f->ab, 0, sizeof(double) * (size_t)f->ldab * (size_t)N);
  for (j = 0; j < N; ++j)
    for (i = PHGMG__MAX(0, j - kb); i <= PHGMG__MIN(N - 1, j + kb); ++i) {
      size_t k = PHGMG__PHB(kb, i, j);
      f->ab[(size_t)(2 * kb + i - j) + (size_t)j * (size_t)f->ldab] = s->J[k] - s->R[k];
    }
  return phgmg__gb_factor(N, kb, kb, f->ab, f->ldab, f->ipiv, f->dinv, &f->ue);
}

PHGMG__PRIV void phgmg__gbf_solve(const phgmg__gbf *f, char trans, double *b) {
  phgmg__gb_solve(trans, f->n, f->kl, f->ku, f->ue, f->ab, f->ldab, f->ipiv, f->dinv, b);
}

/* Hager/Higham estimate of ||A^{-1}||_1 from band factors (LAPACK dlacn2 logic).
   work: 2n doubles, iwork: n ints. */
PHGMG__PRIV double phgmg__gbf_inv_norm1(const phgmg__gbf *f, double *work, int *isgn) {
  int n = f->n, i, j, jlast, iter, same;
  double *x = work, est, estold, temp;
  for (i = 0; i < n; ++i) x[i] = 1.0 / (double)n;
  phgmg__gbf_solve(f, 'N', x);
  if (n == 1) return fabs(x[0]);
  est = 0.0;
  for (i = 0; i < n; ++i) est += fabs(x[i]);
  for (i = 0; i < n; ++i) { isgn[i] = x[i] >= 0.0 ? 1 : -1; x[i] = (double)isgn[i]; }
  phgmg__gbf_solve(f, 'T', x);
  j = 0;
  for (i = 1; i < n; ++i) if (fabs(x[i]) > fabs(x[j])) j = i;
  for (iter = 2;; ++iter) {
    for (i = 0; i < n; ++i) x[i] = 0.0;
    x[j] = 1.0;
    phgmg__gbf_solve(f, 'N', x);
    estold = est;
    est = 0.0;
    for (i = 0; i < n; ++i) est += fabs(x[i]);
    same = 1;
    for (i = 0; i < n; ++i)
      if ((x[i] >= 0.0 ? 1 : -1) != isgn[i]) { same = 0; break; }
    if (same || est <= estold) { if (est < estold) est = estold; break; }
    for (i = 0; i < n; ++i) { isgn[i] = x[i] >= 0.0 ? 1 : -1; x[i] = (double)isgn[i]; }
    phgmg__gbf_solve(f, 'T', x);
    jlast = j;
    j = 0;
    for (i = 1; i < n; ++i) if (fabs(x[i]) > fabs(x[j])) j = i;
    if (fabs(x[jlast]) == fabs(x[j]) || iter >= 5) break;
  }
  for (i = 0; i < n; ++i) x[i] = ((i & 1) ? -1.0 : 1.0) * (1.0 + (double)i / (double)(n - 1));
  phgmg__gbf_solve(f, 'N', x);
  temp = 0.0;
  for (i = 0; i < n; ++i) temp += fabs(x[i]);
  temp = 2.0 * temp / (3.0 * (double)n);
  return temp > est ? temp : est;
}

/* ||J - R||_1 */
PHGMG__PRIV double phgmg__ph_jr_norm1(const phgmg_ph_system *s) {
  int N = s->N, i, j;
  double best = 0.0;
  const int *jp, *ji, *rp, *ri;
  const double *jx, *rx;
  if (phgmg__ph_csc_of(s, s->J, &jp, &ji, &jx) && phgmg__ph_csc_of(s, s->R, &rp, &ri, &rx)) {
    for (j = 0; j < N; ++j) { /* the two sorted columns merged */
      int p = jp[j], q = rp[j];
      double acc = 0.0;
      while (p < jp[j + 1] || q < rp[j + 1]) {
        int a = p < jp[j + 1] ? ji[p] : N, b = q < rp[j + 1] ? ri[q] : N, r = PHGMG__MIN(a, b);
        acc += fabs((a == r ? jx[p++] : 0.0) - (b == r ? rx[q++] : 0.0));
      }
      if (acc > best) best = acc;
    }
    return best;
  }
  for (j = 0; j < N; ++j) {
    double acc = 0.0;
    int i0 = 0, i1 = N - 1;
    if (s->storage == PHGMG_BANDED) {
      i0 = PHGMG__MAX(0, j - s->kb);
      i1 = PHGMG__MIN(N - 1, j + s->kb);
    }
    for (i = i0; i <= i1; ++i)
      acc += fabs(phgmg__ph_at(s, s->J, i, j) - phgmg__ph_at(s, s->R, i, j));
    if (acc > best) best = acc;
  }
  return best;
}

/* ---- factorization of J - R ------------------------------------------------ */
struct phgmg_jr_factor {
  phgmg_allocator al;
  int N;
  phgmg_storage storage;
  double *LU; /* dense */
  int *ipiv;
  phgmg__gbf gb; /* banded; SPARSE systems: in J - R's own RCM order, */
  int *perm;     /* position i holds index perm[i] (NULL: none)       */
  double *w;     /* N, the permuted right-hand side                   */
};

PHGMG_DEF void phgmg_jr_factor_destroy(phgmg_jr_factor *f) {
  phgmg_allocator al;
  if (!f) return;
  al = f->al;
  phgmg__free(&al, f->LU);
  phgmg__free(&al, f->ipiv);
  phgmg__gbf_free(&al, &f->gb);
  phgmg__free(&al, f->perm);
  phgmg__free(&al, f->w);
  phgmg__free(&al, f);
}

/* rcond of the factored J - R (0 if singular); NOMEM -> -1. */
PHGMG__PRIV double phgmg__jr_rcond(const phgmg_jr_factor *f, const phgmg_ph_system *s) {
  const phgmg_allocator *al = &f->al;
  int N = f->N;
  double anorm = phgmg__ph_jr_norm1(s), rc = 0.0;
  double *work = phgmg__dalloc(al, 2 * (size_t)N);
  int *iwork = phgmg__ialloc(al, (size_t)N);
  if (!work || !iwork) {
    phgmg__free(al, work); phgmg__free(al, iwork);
    return -1.0;
  }
  if (!(anorm > 0.0)) rc = 0.0;
  else if (f->storage == PHGMG_DENSE) {
    rc = phgmg_lu_rcond(N, f->LU, N, f->ipiv, anorm, work, iwork);
  } else {
    double est = phgmg__gbf_inv_norm1(&f->gb, work, iwork);
    rc = (est > 0.0 && est == est && est < HUGE_VAL) ? (1.0 / est) / anorm : 0.0;
  }
  phgmg__free(al, work);
  phgmg__free(al, iwork);
  return rc;
}

PHGMG_DEF phgmg_result phgmg_jr_factor_create(phgmg_jr_factor **out, const phgmg_ph_system *sys,
                                              double *rcond_out, const phgmg_allocator *alloc) {
  phgmg_jr_factor *f;
  phgmg_ph_system t;
  double *bands[2] = {NULL, NULL};
  phgmg_result rc;
  int N, i, j;
  if (!out) return PHGMG_ERR_INVALID_ARG;
  *out = NULL;
  rc = phgmg__ph_check(sys);
  if (rc != PHGMG_OK) return rc;
  if (!phgmg__ph_mat_finite(sys, sys->J) || !phgmg__ph_mat_finite(sys, sys->R))
    return PHGMG_ERR_NANINF;
  N = sys->N;
  f = PHGMG__CAST(phgmg_jr_factor *, phgmg__alloc(alloc, sizeof(phgmg_jr_factor)));
  if (!f) return PHGMG_ERR_NOMEM;
  memset(f, 0, sizeof *f);
  if (alloc) f->al = *alloc;
  f->N = N;
  f->storage = sys->storage;
  if (sys->storage == PHGMG_DENSE) {
    f->LU = phgmg__dalloc(alloc, (size_t)N * (size_t)N);
    f->ipiv = phgmg__ialloc(alloc, (size_t)N);
    if (!f->LU || !f->ipiv) { phgmg_jr_factor_destroy(f); return PHGMG_ERR_NOMEM; }
    for (j = 0; j < N; ++j)
      for (i = 0; i < N; ++i) {
        size_t k = (size_t)i + (size_t)j * (size_t)N;
        f->LU[k] = sys->J[k] - sys->R[k];
      }
    rc = phgmg_lu_factor(N, f->LU, N, f->ipiv);
  } else if (sys->storage == PHGMG_SPARSE) { /* J - R in band storage, its own RCM order */
    rc = phgmg__ph_sparse_own_band(sys, 0, 1, &t, bands, &f->perm, alloc);
    f->w = phgmg__dalloc(alloc, (size_t)N);
    if (rc == PHGMG_OK && !f->w) rc = PHGMG_ERR_NOMEM;
    if (rc == PHGMG_OK) rc = phgmg__gbf_jr(alloc, &t, &f->gb);
    if (rc == PHGMG_OK && rcond_out) *rcond_out = phgmg__jr_rcond(f, &t);
    phgmg__ph_own_band_free(&t, bands, NULL, alloc);
    if (rc == PHGMG_OK && rcond_out && *rcond_out < 0.0) rc = PHGMG_ERR_NOMEM;
    if (rc == PHGMG_OK) { *out = f; return PHGMG_OK; }
  } else {
    rc = phgmg__gbf_jr(alloc, sys, &f->gb);
  }
  if (rc != PHGMG_OK) {
    if (rcond_out) *rcond_out = 0.0;
    phgmg_jr_factor_destroy(f);
    return rc;
  }
  if (rcond_out) {
    double r = phgmg__jr_rcond(f, sys);
    if (r < 0.0) { phgmg_jr_factor_destroy(f); return PHGMG_ERR_NOMEM; }
    *rcond_out = r;
  }
  *out = f;
  return PHGMG_OK;
}

PHGMG_DEF void phgmg_jr_solve(const phgmg_jr_factor *f, char trans, int nrhs, double *X, int ldx) {
  int c;
  PHGMG_ASSERT(f && X && ldx >= f->N);
  PHGMG_ASSERT(trans == 'N' || trans == 'n' || trans == 'T' || trans == 't');
  if (f->storage == PHGMG_DENSE) {
    phgmg_lu_solve(trans, f->N, f->LU, f->N, f->ipiv, nrhs, X, ldx);
    return;
  }
  for (c = 0; c < nrhs; ++c) {
    double *x = X + (size_t)c * (size_t)ldx;
    int i;
    if (!f->perm) { phgmg__gbf_solve(&f->gb, trans, x); continue; }
    for (i = 0; i < f->N; ++i) f->w[i] = x[f->perm[i]];
    phgmg__gbf_solve(&f->gb, trans, f->w);
    for (i = 0; i < f->N; ++i) x[f->perm[i]] = f->w[i];
  }
}

/* ---- validation ------------------------------------------------------------- */
/* Frobenius norms of M and of M + sign*M^T over the valid entries. */
PHGMG__PRIV void phgmg__ph_sym_defect(const phgmg_ph_system *s, const double *M, double sign,
                                      double *norm, double *defect) {
  int N = s->N, i, j;
  double a = 0.0, d = 0.0;
  const int *cp, *ci;
  const double *cx;
  if (phgmg__ph_csc_of(s, M, &cp, &ci, &cx)) { /* stored (i,j); (j,i) counted here too when not stored */
    for (j = 0; j < N; ++j)
      for (i = cp[j]; i < cp[j + 1]; ++i) {
        double mij = cx[i], mji = phgmg__ph_at(s, M, j, ci[i]), e = mij + sign * mji;
        a += mij * mij;
        d += e * e;
        if (mji == 0.0) d += mij * mij;
      }
    *norm = sqrt(a);
    *defect = sqrt(d);
    return;
  }
  for (j = 0; j < N; ++j) {
    int i0 = 0, i1 = N - 1;
    if (s->storage == PHGMG_BANDED) {
      i0 = PHGMG__MAX(0, j - s->kb);
      i1 = PHGMG__MIN(N - 1, j + s->kb);
    }
    for (i = i0; i <= i1; ++i) {
      double mij = phgmg__ph_at(s, M, i, j), e = mij + sign * phgmg__ph_at(s, M, j, i);
      a += mij * mij;
      d += e * e;
    }
  }
  *norm = sqrt(a);
  *defect = sqrt(d);
}

/* Is the shifted banded symmetric matrix R + delta I positive definite?
   Band Cholesky on the lower band, O(N kb^2). 1 yes, 0 no, -1 out of memory. */
PHGMG__PRIV int phgmg__ph_band_chol_pd(const phgmg_ph_system *s, const double *R, double delta,
                                       const phgmg_allocator *al) {
  int N = s->N, kb = s->kb, i, j, k, ok = 1;
  size_t ld = (size_t)kb + 1;
  double *L = phgmg__dalloc(al, ld * (size_t)N); /* L(i,j) at L[(i-j) + j*ld] */
  if (!L) return -1;
  for (j = 0; j < N && ok; ++j) {
    double d = R[PHGMG__PHB(kb, j, j)] + delta;
    for (k = PHGMG__MAX(0, j - kb); k < j; ++k) {
      double l = L[(size_t)(j - k) + (size_t)k * ld];
      d -= l * l;
    }
    if (!(d > 0.0)) { ok = 0; break; }
    d = sqrt(d);
    L[(size_t)j * ld] = d;
    for (i = j + 1; i <= PHGMG__MIN(N - 1, j + kb); ++i) {
      double v = R[PHGMG__PHB(kb, i, j)];
      for (k = PHGMG__MAX(0, i - kb); k < j; ++k)
        v -= L[(size_t)(i - k) + (size_t)k * ld] * L[(size_t)(j - k) + (size_t)k * ld];
      L[(size_t)(i - j) + (size_t)j * ld] = v / d;
    }
  }
  phgmg__free(al, L);
  return ok;
}

/* R positive semidefinite within tol (see the declaration). */
PHGMG__PRIV phgmg_result phgmg__ph_check_sparse_pd(const phgmg_ph_system *s, int a, double tol,
                                                   const phgmg_allocator *al);
PHGMG__PRIV phgmg_result phgmg__ph_check_psd(const phgmg_ph_system *s, double tol,
                                             const phgmg_allocator *al) {
  int N = s->N, i, j, diag = 1;
  double dmax = 0.0, dmin = HUGE_VAL;
  if (s->storage == PHGMG_SPARSE) return phgmg__ph_check_sparse_pd(s, 1, tol, al);
  for (j = 0; j < N && diag; ++j) {
    int i0 = 0, i1 = N - 1;
    if (s->storage == PHGMG_BANDED) {
      i0 = PHGMG__MAX(0, j - s->kb);
      i1 = PHGMG__MIN(N - 1, j + s->kb);
    }
    for (i = i0; i <= i1; ++i)
      if (i != j && phgmg__ph_at(s, s->R, i, j) != 0.0) { diag = 0; break; }
  }
  if (diag) { /* the eigenvalues are the diagonal */
    for (j = 0; j < N; ++j) {
      double d = phgmg__ph_at(s, s->R, j, j);
      if (fabs(d) > dmax) dmax = fabs(d);
      if (d < dmin) dmin = d;
    }
    return dmin >= -tol * dmax ? PHGMG_OK : PHGMG_ERR_NOT_PSD;
  }
  if (s->storage == PHGMG_DENSE || N <= PHGMG__PH_PSD_DENSE_MAX) {
    double *A = phgmg__dalloc(al, (size_t)N * (size_t)N), *w = phgmg__dalloc(al, (size_t)N);
    phgmg_result rc;
    if (!A || !w) { phgmg__free(al, A); phgmg__free(al, w); return PHGMG_ERR_NOMEM; }
    for (j = 0; j < N; ++j)
      for (i = 0; i < N; ++i) A[(size_t)i + (size_t)j * (size_t)N] = phgmg__ph_at(s, s->R, i, j);
    rc = phgmg_sym_eig(N, A, N, w, NULL, 0);
    if (rc == PHGMG_OK) {
      double nrm = PHGMG__MAX(fabs(w[0]), fabs(w[N - 1]));
      if (w[0] < -tol * nrm) rc = PHGMG_ERR_NOT_PSD;
    }
    phgmg__free(al, A);
    phgmg__free(al, w);
    return rc;
  } else {
    /* large banded: R + tol*||R||_1 I must admit a Cholesky factorization
       (||R||_1 >= ||R||_2 for symmetric R, so this is slightly more lenient) */
    double n1 = 0.0;
    int r;
    for (j = 0; j < N; ++j) {
      double acc = 0.0;
      for (i = PHGMG__MAX(0, j - s->kb); i <= PHGMG__MIN(N - 1, j + s->kb); ++i)
        acc += fabs(s->R[PHGMG__PHB(s->kb, i, j)]);
      if (acc > n1) n1 = acc;
    }
    if (n1 == 0.0) return PHGMG_OK;
    r = phgmg__ph_band_chol_pd(s, s->R, tol * n1, al);
    if (r < 0) return PHGMG_ERR_NOMEM;
    return r ? PHGMG_OK : PHGMG_ERR_NOT_PSD;
  }
}

/* Q positive definite: every diagonal entry > 0 for a diagonal Q, else a
   Cholesky factorization of Q (lower triangle, band storage of half-bandwidth
   kb, N - 1 for dense) must find only positive pivots; O(N kb^2). */
PHGMG__PRIV phgmg_result phgmg__ph_check_q_pd(const phgmg_ph_system *s, double tol, const phgmg_allocator *al) {
  const int N = s->N, kb = s->storage == PHGMG_BANDED ? s->kb : N - 1;
  const size_t ld = (size_t)kb + 1;
  int i, j, diag = 1;
  double *L, shift = 0.0;
  phgmg_result rc = PHGMG_OK;
  if (s->storage == PHGMG_SPARSE) return phgmg__ph_check_sparse_pd(s, 2, tol, al);
  for (j = 0; j < N && diag; ++j)
    for (i = PHGMG__MAX(0, j - kb); i <= PHGMG__MIN(N - 1, j + kb); ++i)
      if (i != j && phgmg__ph_at(s, s->Q, i, j) != 0.0) { diag = 0; break; }
  if (s->nl != PHGMG_NL_NONE) {   /* semidefinite: Q + tol ||Q||_1 I must be definite */
    double n1 = 0.0;
    for (j = 0; j < N; ++j) {
      double cs = 0.0;
      for (i = PHGMG__MAX(0, j - kb); i <= PHGMG__MIN(N - 1, j + kb); ++i) cs += fabs(phgmg__ph_at(s, s->Q, i, j));
      n1 = PHGMG__MAX(n1, cs);
    }
    shift = PHGMG__MAX(tol * n1, 1e-300);
  }
  if (diag) {
    for (j = 0; j < N; ++j)
      if (!(phgmg__ph_at(s, s->Q, j, j) + shift > 0.0)) return PHGMG_ERR_Q_NOT_PD;
    return PHGMG_OK;
  }
  L = phgmg__dalloc(al, ld * (size_t)N); /* row i: L(i,k), i-kb <= k <= i, contiguous */
  if (!L) return PHGMG_ERR_NOMEM;
  for (i = 0; i < N && rc == PHGMG_OK; ++i) { /* row by row, inner products over contiguous rows */
    double *Li = L + (size_t)i * (size_t)kb + (size_t)kb; /* Li[k] = L(i,k) */
    const int i0 = PHGMG__MAX(0, i - kb);
    double d;
    for (j = i0; j < i; ++j) {
      const double *Lj = L + (size_t)j * (size_t)kb + (size_t)kb;
      Li[j] = (phgmg__ph_at(s, s->Q, i, j) - phgmg__dot(j - i0, Li + i0, Lj + i0)) / Lj[j];
    }
    d = phgmg__ph_at(s, s->Q, i, i) + shift - phgmg__dot(i - i0, Li + i0, Li + i0);
    if (!(d > 0.0)) rc = PHGMG_ERR_Q_NOT_PD;
    else Li[i] = sqrt(d);
  }
  phgmg__free(al, L);
  return rc;
}

PHGMG__PRIV int phgmg__sp_pd(int n, const int *cp, const int *ci, const double *cx, double shift,
                             const phgmg_allocator *al);

/* The R (a = 1) or Q (a = 2) check of a SPARSE system, with the decisions of
   the band checks above: a diagonal matrix by its diagonal; R of N <= the
   dense limit by its eigenvalues; else R + tol ||R||_1 I, Q (+ tol ||Q||_1 I
   with a nonlinear part) positive definite by the sparse LU's pivots
   (phgmg__sp_pd), and when that cannot decide, by the band Cholesky of the
   matrix alone in its own reverse Cuthill-McKee order. */
PHGMG__PRIV phgmg_result phgmg__ph_check_sparse_pd(const phgmg_ph_system *s, int a, double tol,
                                                   const phgmg_allocator *al) {
  const int N = s->N;
  const int *cp, *ci;
  const double *cx;
  double n1 = 0.0, dmax = 0.0, dmin = HUGE_VAL, shift;
  int j, p, diag = 1, r = 2;
  phgmg_result rc;
  if (!phgmg__ph_csc_of(s, a == 1 ? s->R : s->Q, &cp, &ci, &cx)) return PHGMG_ERR_INVALID_ARG;
  for (j = 0; j < N; ++j) {
    double cs = 0.0, d = 0.0;
    for (p = cp[j]; p < cp[j + 1]; ++p) {
      cs += fabs(cx[p]);
      if (ci[p] == j) d = cx[p]; else if (cx[p] != 0.0) diag = 0;
    }
    n1 = PHGMG__MAX(n1, cs);
    dmax = PHGMG__MAX(dmax, fabs(d));
    dmin = PHGMG__MIN(dmin, d);
  }
  shift = a == 1 ? tol * n1 : s->nl != PHGMG_NL_NONE ? PHGMG__MAX(tol * n1, 1e-300) : 0.0;
  if (diag) {
    if (a == 1) return dmin >= -tol * dmax ? PHGMG_OK : PHGMG_ERR_NOT_PSD;
    return dmin + shift > 0.0 ? PHGMG_OK : PHGMG_ERR_Q_NOT_PD;
  }
  if (a == 1 && n1 == 0.0) return PHGMG_OK;
  if (a == 2 || N > PHGMG__PH_PSD_DENSE_MAX) r = phgmg__sp_pd(N, cp, ci, cx, shift, al);
  if (r < 0) return PHGMG_ERR_NOMEM;
  if (r < 2) return r ? PHGMG_OK : a == 1 ? PHGMG_ERR_NOT_PSD : PHGMG_ERR_Q_NOT_PD;
  { /* the band checks on the matrix alone, in its own RCM order */
    phgmg_ph_system t;
    double *bands[2];
    int *perm = NULL;
    rc = phgmg__ph_sparse_own_band(s, a, -1, &t, bands, &perm, al);
    if (rc == PHGMG_OK) rc = a == 1 ? phgmg__ph_check_psd(&t, tol, al) : phgmg__ph_check_q_pd(&t, tol, al);
    phgmg__ph_own_band_free(&t, bands, perm, al);
  }
  return rc;
}

/* ---- descriptor models (E != NULL) -----------------------------------------
   A factorization of E by the J - R machinery (J := E, R := 0): dense LU or
   band LU; phgmg_jr_solve then applies E^{-1} ('N') or E^{-T} ('T').
   rcond_out (may be NULL): its reciprocal condition estimate. */
PHGMG__PRIV phgmg_result phgmg__ph_sparse_eq_band(const phgmg_ph_system *s, phgmg_ph_system *t, double **bufs,
                                                 const phgmg_allocator *al);
PHGMG__PRIV phgmg_result phgmg__e_factor(const phgmg_ph_system *sys, phgmg_jr_factor **f, double *rcond_out,
                                         const phgmg_allocator *alloc) {
  phgmg_ph_system t;
  if (sys->storage == PHGMG_SPARSE) { /* the band LU of E's band copy, made here and freed */
    double *bufs[2];
    phgmg_result rc = phgmg__ph_sparse_eq_band(sys, &t, bufs, alloc);
    *f = NULL;
    if (rc == PHGMG_OK) rc = phgmg__e_factor(&t, f, rcond_out, alloc);
    phgmg__free(alloc, bufs[0]); phgmg__free(alloc, bufs[1]);
    return rc;
  }
  const size_t len = sys->storage == PHGMG_BANDED ? (size_t)(2 * sys->kb + 1) * (size_t)sys->N
                                                  : (size_t)sys->N * (size_t)sys->N;
  double *zero = phgmg__dalloc(alloc, len);
  phgmg_result rc;
  *f = NULL;
  if (!zero) return PHGMG_ERR_NOMEM;
  memset(zero, 0, sizeof(double) * len);
  memset(&t, 0, sizeof t);
  t.N = sys->N; t.m = sys->m; t.storage = sys->storage; t.kb = sys->kb;
  t.J = sys->E; t.R = zero; t.Q = sys->E; t.B = sys->B;
  rc = phgmg_jr_factor_create(f, &t, rcond_out, alloc);
  phgmg__free(alloc, zero);
  return rc;
}

/* E^T Q into a system view t (only t.Q meaningful: dense N x N, or banded
   with half-bandwidth min(2 kb, N - 1)); *buf owns the storage. */
PHGMG__PRIV phgmg_result phgmg__etq_form(const phgmg_ph_system *sys, phgmg_ph_system *t, double **buf,
                                         const phgmg_allocator *alloc) {
  const int N = sys->N;
  int i, j, k;
  *t = *sys;
  t->E = NULL;
  if (sys->storage == PHGMG_DENSE) {
    *buf = phgmg__dalloc(alloc, (size_t)N * (size_t)N);
    if (!*buf) return PHGMG_ERR_NOMEM;
    phgmg_gemm('T', 'N', N, N, N, 1.0, sys->E, N, sys->Q, N, 0.0, *buf, N);
  } else {
    const int kb = sys->kb, k2 = PHGMG__MIN(2 * kb, N - 1);
    const size_t len = (size_t)(2 * k2 + 1) * (size_t)N;
    *buf = phgmg__dalloc(alloc, len);
    if (!*buf) return PHGMG_ERR_NOMEM;
    memset(*buf, 0, sizeof(double) * len);
    for (j = 0; j < N; ++j)   /* (E^T Q)(i, j) = sum_k E(k, i) Q(k, j) */
      for (i = PHGMG__MAX(0, j - k2); i <= PHGMG__MIN(N - 1, j + k2); ++i) {
        double acc = 0.0;
        for (k = PHGMG__MAX(PHGMG__MAX(0, i - kb), j - kb); k <= PHGMG__MIN(PHGMG__MIN(N - 1, i + kb), j + kb); ++k)
          acc += sys->E[PHGMG__PHB(kb, k, i)] * sys->Q[PHGMG__PHB(kb, k, j)];
        (*buf)[PHGMG__PHB(k2, i, j)] = acc;
      }
    t->kb = k2;
  }
  t->Q = *buf;
  return PHGMG_OK;
}

PHGMG__PRIV int phgmg__e_algebraic(const phgmg_ph_system *s, const phgmg_allocator *alloc);
PHGMG__PRIV phgmg_result phgmg__dae_validate(const phgmg_ph_system *sys, double tol, const phgmg_allocator *alloc);

/* The descriptor checks of phgmg_ph_validate: E finite and nonsingular,
   E^T Q symmetric and positive (semi)definite, separable coordinates free of
   mass coupling. */
PHGMG__PRIV phgmg_result phgmg__ph_validate_e(const phgmg_ph_system *sys, double tol, const phgmg_allocator *alloc) {
  phgmg_ph_system t;
  phgmg_jr_factor *f = NULL;
  double *buf = NULL, rcond = 0.0, nrm, def;
  int k, j;
  phgmg_result rc;
  if (!phgmg__ph_mat_finite(sys, sys->E)) return PHGMG_ERR_NANINF;
  if (sys->storage == PHGMG_SPARSE) { /* on band copies of E and Q, made here and freed */
    double *bufs[2];
    rc = phgmg__ph_sparse_eq_band(sys, &t, bufs, alloc);
    if (rc == PHGMG_OK) rc = phgmg__ph_validate_e(&t, tol, alloc);
    phgmg__free(alloc, bufs[0]); phgmg__free(alloc, bufs[1]);
    return rc;
  }
  k = phgmg__e_algebraic(sys, alloc);   /* zero rows or columns: index one? (1.8) */
  if (k < 0) return PHGMG_ERR_NOMEM;
  if (k > 0) return phgmg__dae_validate(sys, tol, alloc);
  rc = phgmg__etq_form(sys, &t, &buf, alloc);
  if (rc != PHGMG_OK) return rc;
  phgmg__ph_sym_defect(&t, t.Q, -1.0, &nrm, &def);
  if (def > tol * nrm) rc = PHGMG_ERR_EQ_NOT_SYMMETRIC;
  if (rc == PHGMG_OK) {
    rc = phgmg__ph_check_q_pd(&t, tol, alloc);
    if (rc == PHGMG_ERR_Q_NOT_PD) rc = PHGMG_ERR_EQ_NOT_PD;
  }
  phgmg__free(alloc, buf);
  for (k = 0; rc == PHGMG_OK && sys->nl == PHGMG_NL_SEPARABLE && k < sys->nsep; ++k) {
    const int ix = sys->sep_idx[k];
    if (!(phgmg__ph_at(sys, sys->E, ix, ix) > 0.0)) rc = PHGMG_ERR_E_COUPLED;
    for (j = 0; j < sys->N && rc == PHGMG_OK; ++j)
      if (j != ix && phgmg__ph_at(sys, sys->E, ix, j) != 0.0) rc = PHGMG_ERR_E_COUPLED;
  }
  if (rc != PHGMG_OK) return rc;
  rc = phgmg__e_factor(sys, &f, &rcond, alloc);
  phgmg_jr_factor_destroy(f);
  if (rc == PHGMG_ERR_NOMEM) return rc;
  return rc == PHGMG_OK && rcond > tol ? PHGMG_OK : PHGMG_ERR_E_SINGULAR;
}

/* Feedthrough: P, S, N finite, N skew, S symmetric and [[R, P], [P^T, S]]
   positive semidefinite (smallest eigenvalue >= -tol times the largest
   magnitude; dense eigenvalues of the (N + m) block, so banded models with
   N > PHGMG__PH_PSD_DENSE_MAX are not checked: PHGMG_ERR_UNSUPPORTED). */
PHGMG__PRIV phgmg_result phgmg__ph_validate_feedthrough(const phgmg_ph_system *sys, double tol,
                                                        const phgmg_allocator *alloc) {
  const int N = sys->N, m = sys->m, n = N + m;
  double *A, *w, a = 0.0, d = 0.0;
  int i, j;
  phgmg_result rc;
  if ((sys->P && !phgmg__all_finite(sys->P, (size_t)N * m)) || (sys->S && !phgmg__all_finite(sys->S, (size_t)m * m)) ||
      (sys->Nskew && !phgmg__all_finite(sys->Nskew, (size_t)m * m)))
    return PHGMG_ERR_NANINF;
  for (j = 0; sys->Nskew && j < m; ++j)
    for (i = 0; i < m; ++i) {
      const double v = sys->Nskew[i + (size_t)j * m], e = v + sys->Nskew[j + (size_t)i * m];
      a += v * v; d += e * e;
    }
  if (sqrt(d) > tol * sqrt(a)) return PHGMG_ERR_FEEDTHROUGH;
  if (sys->storage == PHGMG_BANDED && N > PHGMG__PH_PSD_DENSE_MAX) return PHGMG_ERR_UNSUPPORTED;
  A = phgmg__dalloc(alloc, (size_t)n * n);
  w = phgmg__dalloc(alloc, (size_t)n);
  if (!A || !w) { phgmg__free(alloc, A); phgmg__free(alloc, w); return PHGMG_ERR_NOMEM; }
  for (j = 0; j < n; ++j)
    for (i = 0; i < n; ++i) {
      double v;
      if (i < N && j < N) v = phgmg__ph_at(sys, sys->R, i, j);
      else if (i < N) v = sys->P ? sys->P[i + (size_t)(j - N) * N] : 0.0;
      else if (j < N) v = sys->P ? sys->P[j + (size_t)(i - N) * N] : 0.0;
      else v = sys->S ? sys->S[(i - N) + (size_t)(j - N) * m] : 0.0;
      A[i + (size_t)j * n] = v;
    }
  for (j = 0, a = d = 0.0; sys->S && j < m; ++j)   /* S symmetric */
    for (i = 0; i < m; ++i) {
      const double v = sys->S[i + (size_t)j * m], e = v - sys->S[j + (size_t)i * m];
      a += v * v; d += e * e;
    }
  rc = sqrt(d) > tol * sqrt(a) ? PHGMG_ERR_FEEDTHROUGH : phgmg_sym_eig(n, A, n, w, NULL, 0);
  if (rc == PHGMG_OK && w[0] < -tol * PHGMG__MAX(fabs(w[0]), fabs(w[n - 1]))) rc = PHGMG_ERR_FEEDTHROUGH;
  phgmg__free(alloc, A);
  phgmg__free(alloc, w);
  return rc;
}

/* The linearisation of the dampers at z = 0, L = sum_k rho_k'(0) c_k c_k^T,
   added to a copy of R: *Rl (dense N x N or band (2kb+1) x N, caller frees).
   PHGMG_ERR_DAMPER if some rho_k'(0) < 0 (a callback law). */
PHGMG__PRIV phgmg_result phgmg__damp_r_lin(const phgmg_ph_system *sys, double **Rl, const phgmg_allocator *alloc) {
  const int N = sys->N;
  const size_t n = sys->storage == PHGMG_DENSE ? (size_t)N * N : (size_t)(2 * sys->kb + 1) * N;
  double *R = phgmg__dalloc(alloc, n), d[2];
  int k;
  *Rl = R;
  if (!R) return PHGMG_ERR_NOMEM;
  memcpy(R, sys->R, n * sizeof(double));
  for (k = 0; k < sys->ndamp; ++k) {
    const int i = sys->damp_i[k], j = phgmg__damp_j(sys, k);
    phgmg__damp_law(sys, k, 0.0, d);
    if (!(d[1] >= 0.0) || d[1] == HUGE_VAL) return d[1] != d[1] ? PHGMG_ERR_NANINF : PHGMG_ERR_DAMPER;
#define PHGMG__RL(a, b) R[sys->storage == PHGMG_DENSE ? (size_t)(a) + (size_t)(b) * N : PHGMG__PHB(sys->kb, a, b)]
    PHGMG__RL(i, i) += d[1];
    if (j >= 0) {
      PHGMG__RL(j, j) += d[1];
      PHGMG__RL(i, j) -= d[1];
      PHGMG__RL(j, i) -= d[1];
    }
#undef PHGMG__RL
  }
  return PHGMG_OK;
}

/* phgmg_jr_factor_create of J - R, or with dampers of J - R - L. */
PHGMG__PRIV phgmg_result phgmg__damp_jr_factor(phgmg_jr_factor **f, const phgmg_ph_system *sys, double *rcond,
                                               const phgmg_allocator *alloc) {
  phgmg_ph_system lin;
  double *Rl = NULL;
  phgmg_result rc;
  if (!sys->ndamp) return phgmg_jr_factor_create(f, sys, rcond, alloc);
  rc = phgmg__damp_r_lin(sys, &Rl, alloc);
  lin = *sys;
  lin.R = Rl;
  lin.ndamp = 0;
  if (rc == PHGMG_OK) rc = phgmg_jr_factor_create(f, &lin, rcond, alloc);
  phgmg__free(alloc, Rl);
  return rc;
}

/* phgmg_ph_validate; check_rank = 0 skips the rank test of B (the condensed
   model of an index-one model may have B' = 0 where a port acts through a
   constraint only, 1.8). */
PHGMG__PRIV phgmg_result phgmg__ph_validate(const phgmg_ph_system *sys, double tol, double *rcond_out,
                                            const phgmg_allocator *alloc, int check_rank) {
  phgmg_result rc;
  double nrm, def;
  int N, m;
  if (rcond_out) *rcond_out = 0.0;
  rc = phgmg__ph_check(sys);
  if (rc != PHGMG_OK) return rc;
  if (!(tol > 0.0)) tol = 1e-12;
  N = sys->N;
  m = sys->m;
  /* NaN / Inf */
  if (!phgmg__ph_mat_finite(sys, sys->J) || !phgmg__ph_mat_finite(sys, sys->R) ||
      !phgmg__ph_mat_finite(sys, sys->Q) ||
      !phgmg__all_finite(sys->B, (size_t)N * (size_t)m))
    return PHGMG_ERR_NANINF;
  if (sys->nl == PHGMG_NL_SEPARABLE) {
    if (sys->sep_w && !phgmg__all_finite(sys->sep_w, (size_t)sys->nsep)) return PHGMG_ERR_NANINF;
    if (sys->poly_deg > 0 && !phgmg__all_finite(sys->poly, (size_t)sys->poly_deg + 1))
      return PHGMG_ERR_NANINF;
  }
  /* structure */
  phgmg__ph_sym_defect(sys, sys->J, 1.0, &nrm, &def);
  if (def > tol * nrm) return PHGMG_ERR_NOT_SKEW;
  phgmg__ph_sym_defect(sys, sys->R, -1.0, &nrm, &def);
  if (def > tol * nrm) return PHGMG_ERR_NOT_SYMMETRIC;
  if (sys->P || sys->S || sys->Nskew) {
    rc = phgmg__ph_check_psd(sys, tol, alloc);
    if (rc == PHGMG_OK) rc = phgmg__ph_validate_feedthrough(sys, tol, alloc);
    if (rc != PHGMG_OK) return rc;
  }
  if (sys->E) {   /* descriptor: E^T Q takes the place of Q */
    rc = phgmg__ph_check_psd(sys, tol, alloc);
    if (rc == PHGMG_OK) rc = phgmg__ph_validate_e(sys, tol, alloc);
    if (rc != PHGMG_OK) return rc;
  } else {
    phgmg__ph_sym_defect(sys, sys->Q, -1.0, &nrm, &def);
    if (def > tol * nrm) return PHGMG_ERR_Q_NOT_SYMMETRIC;
    rc = phgmg__ph_check_psd(sys, tol, alloc);
    if (rc != PHGMG_OK) return rc;
    rc = phgmg__ph_check_q_pd(sys, tol, alloc);
    if (rc != PHGMG_OK) return rc;
  }
  /* B full column rank: pivoted QR, |R(m-1,m-1)| > tol |R(0,0)| */
  if (check_rank) {
    double *Bc = phgmg__dalloc(alloc, (size_t)N * (size_t)m);
    double *tau = phgmg__dalloc(alloc, (size_t)m), *work = phgmg__dalloc(alloc, 2 * (size_t)m);
    int *jpvt = phgmg__ialloc(alloc, (size_t)m);
    if (!Bc || !tau || !work || !jpvt) rc = PHGMG_ERR_NOMEM;
    else {
      memcpy(Bc, sys->B, sizeof(double) * (size_t)N * (size_t)m);
      rc = phgmg_qrcp(N, m, Bc, N, tau, jpvt, work);
      if (rc == PHGMG_OK) {
        double r00 = fabs(Bc[0]), rmm = fabs(Bc[(size_t)(m - 1) * (size_t)(N + 1)]);
        if (!(r00 > 0.0) || !(rmm > tol * r00)) rc = PHGMG_ERR_RANK;
      }
    }
    phgmg__free(alloc, Bc);
    phgmg__free(alloc, tau);
    phgmg__free(alloc, work);
    phgmg__free(alloc, jpvt);
    if (rc != PHGMG_OK) return rc;
  }
  /* J - R invertible (with dampers: J - R - L, L their linearisation at 0) */
  {
    phgmg_jr_factor *f = NULL;
    double rcond = 0.0;
    rc = phgmg__damp_jr_factor(&f, sys, &rcond, alloc);
    if (rc == PHGMG_ERR_NOMEM) return rc;
    if (rc != PHGMG_OK) rcond = 0.0;
    phgmg_jr_factor_destroy(f);
    if (rcond_out) *rcond_out = rcond;
    if (!(rcond > tol)) return PHGMG_ERR_SINGULAR;
  }
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_ph_validate(const phgmg_ph_system *sys, double tol,
                                         double *rcond_out, const phgmg_allocator *alloc) {
  return phgmg__ph_validate(sys, tol, rcond_out, alloc, 1);
}

/* >>dae (implementation) ================================================== */
/* Index-one descriptor models (manual 1.8): E with k zero rows (the
   algebraic equations, row set ra) and k zero columns (the algebraic
   variables, column set ca); the rest (rows rn, columns cn) condensed into a
   port-Hamiltonian ODE by eliminating the algebraic co-states z[ra]. */
struct phgmg_dae {
  phgmg_ph_system sys;          /* the condensed model (n = N - k states)           */
  phgmg_allocator al;           /* a copy of the caller's allocator (or zeros)       */
  int N, n, k, m;
  int *rpos, *cpos;             /* N: position of row / column i in rn / cn, or -1   */
  int *ra, *ca;                 /* k: the algebraic rows / columns                   */
  int *sep_idx, *damp_i, *damp_j;
  double *mats;                 /* J', R', Q', E' of the condensed model              */
  double *Bc, *Pc, *Sc, *Nc;    /* B', P' (n x m), S', N' (m x m)                     */
  double *L22, *Q22;            /* LU factors of L[ra, ra], Q[ra, ca] (k x k)          */
  int *p22, *q22;
  int nd, nq;                   /* lift: L[ra, dcol] (k x nd), Q[ra, qcol] (k x nq)    */
  int *dcol, *qcol;             /* positions in rn / cn                               */
  double *D, *Qa, *Ga;          /* and (B - P)[ra, :] (k x m)                          */
  double *work;                 /* n + 2 k + m (+ N when rotated)                     */
  double *V;                    /* rotated (a dense E without zero lines): Qv, N x N   */
};

/* Size limits of the elimination, which is dense in the algebraic lines:
   k algebraic lines, and the blocks of the update (rows x k, k x columns,
   rows x columns) in doubles. */
#define PHGMG__DAE_KMAX 4096
#define PHGMG__DAE_BLOCK_MAX 1e8

/* Row range [a, b] of the stored entries of column (or row) i. */
PHGMG__PRIV void phgmg__ph_span(const phgmg_ph_system *s, int i, int *a, int *b) {
  *a = s->storage == PHGMG_BANDED ? PHGMG__MAX(0, i - s->kb) : 0;
  *b = s->storage == PHGMG_BANDED ? PHGMG__MIN(s->N - 1, i + s->kb) : s->N - 1;
}

/* Zero rows (zr[i] = 1) and zero columns (zc[j] = 1) of E, and their counts. */
PHGMG__PRIV void phgmg__e_zero_lines(const phgmg_ph_system *s, int *zr, int *zc, int *kr, int *kc) {
  int i, j, a, b;
  const int *cp, *ci;
  const double *cx;
  for (i = 0; i < s->N; ++i) zr[i] = zc[i] = 1;
  if (phgmg__ph_csc_of(s, s->E, &cp, &ci, &cx)) /* SPARSE: E's CSC copy */
    for (j = 0; j < s->N; ++j)
      for (a = cp[j]; a < cp[j + 1]; ++a)
        if (cx[a] != 0.0) zr[ci[a]] = zc[j] = 0;
  for (j = 0; j < s->N && s->storage != PHGMG_SPARSE; ++j) {
    phgmg__ph_span(s, j, &a, &b);
    for (i = a; i <= b; ++i)
      if (phgmg__ph_at(s, s->E, i, j) != 0.0) zr[i] = zc[j] = 0;
  }
  for (i = 0, *kr = *kc = 0; i < s->N; ++i) { *kr += zr[i]; *kc += zc[i]; }
}

PHGMG__PRIV phgmg_result phgmg__e_factor(const phgmg_ph_system *sys, phgmg_jr_factor **f, double *rcond_out,
                                         const phgmg_allocator *alloc);

/* An algebraic model? 1: E has a zero row or column; 2: E is dense without
   zero lines, singular to working precision (rcond <= 1e-12), H quadratic,
   no dampers: taken after an orthogonal change of coordinates
   (phgmg__dae_rotate); 0: neither (E regular, or singular in a form that is
   refused: PHGMG_ERR_E_SINGULAR); -1: no memory. */
PHGMG__PRIV int phgmg__e_algebraic(const phgmg_ph_system *s, const phgmg_allocator *alloc) {
  int *z, kr, kc;
  phgmg_jr_factor *f = NULL;
  double rcond = 0.0;
  phgmg_result rc;
  if (!s->E) return 0;
  z = phgmg__ialloc(alloc, 2 * (size_t)s->N);
  if (!z) return -1;
  phgmg__e_zero_lines(s, z, z + s->N, &kr, &kc);
  phgmg__free(alloc, z);
  if (kr + kc > 0) return 1;
  if (s->storage != PHGMG_DENSE || s->nl != PHGMG_NL_NONE || s->ndamp) return 0;
  rc = phgmg__e_factor(s, &f, &rcond, alloc);
  phgmg_jr_factor_destroy(f);
  if (rc == PHGMG_ERR_NOMEM) return -1;
  return rc == PHGMG_OK && rcond > 1e-12 ? 0 : 2;
}

/* The index maps from the zero lines: rpos/cpos, ra/ca. PHGMG_ERR_E_SINGULAR
   when the counts differ (the kernel of E is not spanned by coordinates). */
PHGMG__PRIV phgmg_result phgmg__dae_split(phgmg_dae *d, const phgmg_ph_system *s) {
  int *zr = d->rpos, *zc = d->cpos, kr, kc, i, a = 0, b = 0, c = 0, e = 0;
  phgmg__e_zero_lines(s, zr, zc, &kr, &kc);
  if (kr != kc) return PHGMG_ERR_E_SINGULAR;
  if (kr > PHGMG__DAE_KMAX) return PHGMG_ERR_UNSUPPORTED;
  d->k = kr; d->n = s->N - kr;
  d->ra = phgmg__ialloc(&d->al, 2 * (size_t)kr);
  if (!d->ra) return PHGMG_ERR_NOMEM;
  d->ca = d->ra + kr;
  for (i = 0; i < s->N; ++i) {
    if (zr[i]) { d->ra[a++] = i; zr[i] = -1; } else zr[i] = b++;
    if (zc[i]) { d->ca[c++] = i; zc[i] = -1; } else zc[i] = e++;
  }
  return PHGMG_OK;
}

PHGMG__PRIV double phgmg__ph_l(const phgmg_ph_system *s, int i, int j) {
  return phgmg__ph_at(s, s->J, i, j) - phgmg__ph_at(s, s->R, i, j);
}

/* det(sigma E - (J - R) Q) for one sigma: its reciprocal condition number
   (dense, or banded with half-bandwidth min(2 kb, N - 1)). */
PHGMG__PRIV phgmg_result phgmg__pencil_rcond(const phgmg_ph_system *s, double sigma, double *rcond,
                                             const phgmg_allocator *alloc) {
  const int N = s->N, kb2 = s->storage == PHGMG_BANDED ? PHGMG__MIN(2 * s->kb, N - 1) : N - 1;
  const size_t len = s->storage == PHGMG_BANDED ? (size_t)(2 * kb2 + 1) * (size_t)N : (size_t)N * (size_t)N;
  double *M = phgmg__dalloc(alloc, len);
  phgmg_ph_system t;
  phgmg_jr_factor *f = NULL;
  phgmg_result rc;
  int i, j, l, a, b;
  *rcond = 0.0;
  if (!M) return PHGMG_ERR_NOMEM;
  memset(M, 0, len * sizeof(double));
  for (j = 0; j < N; ++j) {
    const int i0 = PHGMG__MAX(0, j - kb2), i1 = PHGMG__MIN(N - 1, j + kb2);
    for (i = i0; i <= i1; ++i) {
      double acc = sigma * phgmg__ph_at(s, s->E, i, j);
      phgmg__ph_span(s, i, &a, &b);
      for (l = a; l <= b; ++l) acc -= phgmg__ph_l(s, i, l) * phgmg__ph_at(s, s->Q, l, j);
      M[s->storage == PHGMG_BANDED ? PHGMG__PHB(kb2, i, j) : (size_t)i + (size_t)j * (size_t)N] = acc;
    }
  }
  t = *s;   /* the factorization of a mass matrix, with M in its place */
  t.kb = s->storage == PHGMG_BANDED ? kb2 : 0;
  t.E = M;
  rc = phgmg__e_factor(&t, &f, rcond, alloc);
  phgmg_jr_factor_destroy(f);
  phgmg__free(alloc, M);
  if (rc != PHGMG_OK && rc != PHGMG_ERR_NOMEM) { *rcond = 0.0; rc = PHGMG_OK; }
  return rc;
}

/* The largest |entry| of E, L = J - R and Q. */
PHGMG__PRIV void phgmg__dae_scales(const phgmg_ph_system *s, double *ne, double *nl, double *nq) {
  int i, j, a, b;
  *ne = *nl = *nq = 0.0;
  for (j = 0; j < s->N; ++j) {
    phgmg__ph_span(s, j, &a, &b);
    for (i = a; i <= b; ++i) {
      *ne = PHGMG__MAX(*ne, fabs(phgmg__ph_at(s, s->E, i, j)));
      *nl = PHGMG__MAX(*nl, fabs(phgmg__ph_l(s, i, j)));
      *nq = PHGMG__MAX(*nq, fabs(phgmg__ph_at(s, s->Q, i, j)));
    }
  }
}

/* Why L[ra, ra] Q[ra, ca] is singular: a singular pencil (det(sigma E -
   (J - R) Q) = 0 at two unrelated sigma) or a regular one of index >= 2. */
PHGMG__PRIV phgmg_result phgmg__dae_classify(const phgmg_ph_system *s, double tol, const phgmg_allocator *alloc) {
  double ne, nl, nq, r1 = 0.0, r2 = 0.0;
  phgmg_result rc;
  phgmg__dae_scales(s, &ne, &nl, &nq);
  rc = phgmg__pencil_rcond(s, 0.6180339887498949 * nl * nq / ne, &r1, alloc);
  if (rc == PHGMG_OK) rc = phgmg__pencil_rcond(s, -1.7320508075688772 * nl * nq / ne, &r2, alloc);
  if (rc != PHGMG_OK) return rc;
  return r1 > tol || r2 > tol ? PHGMG_ERR_INDEX : PHGMG_ERR_PENCIL;
}

/* LU of the k x k block M[ra, cols] of L (cols = ra) or Q (cols = ca), and
   whether it is regular against the whole matrix: 1 / ||block^-1||_1 >
   tol * scale (scale = the matrix's largest |entry|), so a block that is
   small only by round-off (a rotated model) counts as singular. */
PHGMG__PRIV phgmg_result phgmg__dae_block(const phgmg_ph_system *s, const double *Mq, const int *ra,
                                          const int *cols, int k, double *A, int *piv, double tol, double scale,
                                          double *work, int *iwork) {
  int i, j;
  for (j = 0; j < k; ++j)
    for (i = 0; i < k; ++i)
      A[i + (size_t)j * k] = Mq ? phgmg__ph_at(s, Mq, ra[i], cols[j]) : phgmg__ph_l(s, ra[i], cols[j]);
  {
    const double an = phgmg_norm1(k, k, A, k);
    if (phgmg_lu_factor(k, A, k, piv) != PHGMG_OK) return PHGMG_ERR_INDEX;
    return phgmg_lu_rcond(k, A, k, piv, an, work, iwork) * an > tol * scale ? PHGMG_OK : PHGMG_ERR_INDEX;
  }
}

/* Index one: L[ra, ra] and Q[ra, ca] regular; else the pencil's class. */
PHGMG__PRIV phgmg_result phgmg__dae_index(phgmg_dae *d, const phgmg_ph_system *s, double tol) {
  const int k = d->k;
  double *w = phgmg__dalloc(&d->al, 2 * (size_t)k);
  int *iw = phgmg__ialloc(&d->al, (size_t)k);
  phgmg_result rc = PHGMG_ERR_NOMEM;
  d->L22 = phgmg__dalloc(&d->al, 2 * (size_t)k * (size_t)k);
  d->p22 = phgmg__ialloc(&d->al, 2 * (size_t)k);
  if (w && iw && d->L22 && d->p22) {
    d->Q22 = d->L22 + (size_t)k * k;
    d->q22 = d->p22 + k;
    double ne, nl, nq;
    phgmg__dae_scales(s, &ne, &nl, &nq);
    rc = phgmg__dae_block(s, NULL, d->ra, d->ra, k, d->L22, d->p22, tol, nl, w, iw);
    if (rc == PHGMG_OK) rc = phgmg__dae_block(s, s->Q, d->ra, d->ca, k, d->Q22, d->q22, tol, nq, w, iw);
    if (rc == PHGMG_ERR_INDEX) rc = phgmg__dae_classify(s, tol, &d->al);
  }
  phgmg__free(&d->al, w);
  phgmg__free(&d->al, iw);
  return rc;
}

/* The rows of L[rn, ra] and the columns of L[ra, rn] that hold entries: the
   support of the elimination's update (original indices, ascending). */
PHGMG__PRIV phgmg_result phgmg__dae_support(phgmg_dae *d, const phgmg_ph_system *s, int **ri, int *nri,
                                            int **cj, int *ncj) {
  int *mr = phgmg__ialloc(&d->al, 2 * (size_t)s->N), q, i, a, b;
  *ri = *cj = NULL; *nri = *ncj = 0;
  if (!mr) return PHGMG_ERR_NOMEM;
  memset(mr, 0, 2 * (size_t)s->N * sizeof(int));
  for (q = 0; q < d->k; ++q) {
    phgmg__ph_span(s, d->ra[q], &a, &b);
    for (i = a; i <= b; ++i) {
      if (d->rpos[i] >= 0 && phgmg__ph_l(s, i, d->ra[q]) != 0.0) mr[i] = 1;
      if (d->rpos[i] >= 0 && phgmg__ph_l(s, d->ra[q], i) != 0.0) mr[s->N + i] = 1;
    }
  }
  for (i = 0; i < s->N; ++i) { *nri += mr[i]; *ncj += mr[s->N + i]; }
  *ri = phgmg__ialloc(&d->al, (size_t)*nri + (size_t)*ncj + 1);
  if (*ri) {
    *cj = *ri + *nri;
    for (i = 0, a = b = 0; i < s->N; ++i) {
      if (mr[i]) (*ri)[a++] = i;
      if (mr[s->N + i]) (*cj)[b++] = i;
    }
  }
  phgmg__free(&d->al, mr);
  return *ri ? PHGMG_OK : PHGMG_ERR_NOMEM;
}

/* The elimination of z[ra]: U = L[ri, ra] L22^{-1} L[ra, cj] (nri x ncj),
   and the ports G' = G[rn] - L[rn, ra] L22^{-1} G[ra], F' = F[rn] - L[ra, rn]^T
   L22^{-T} F[ra], (S + N)' = S + N - F[ra]^T L22^{-1} G[ra] (G = B - P,
   F = B + P), into d->Bc (G'), d->Pc (F'), d->Sc ((S + N)'). Keeps
   D = L[ra, cj] and Ga = G[ra] for the lift. */
PHGMG__PRIV phgmg_result phgmg__dae_eliminate(phgmg_dae *d, const phgmg_ph_system *s, const int *ri, int nri,
                                              const int *cj, int ncj, double **Uo) {
  const int k = d->k, m = d->m, N = s->N, n = d->n;
  double *C, *W, *Fa, *U;
  int i, j, q;
  *Uo = NULL;
  if ((double)nri * k > PHGMG__DAE_BLOCK_MAX || (double)ncj * k > PHGMG__DAE_BLOCK_MAX ||
      (double)nri * ncj > PHGMG__DAE_BLOCK_MAX)
    return PHGMG_ERR_UNSUPPORTED;
  C = phgmg__dalloc(&d->al, (size_t)nri * k + 1); W = phgmg__dalloc(&d->al, (size_t)k * ncj + 1);
  Fa = phgmg__dalloc(&d->al, 2 * (size_t)k * m); U = phgmg__dalloc(&d->al, (size_t)nri * ncj + 1);
  *Uo = U;
  d->D = phgmg__dalloc(&d->al, (size_t)k * ncj + 1);
  d->Ga = phgmg__dalloc(&d->al, (size_t)k * m);
  if (!C || !W || !Fa || !U || !d->D || !d->Ga) {
    phgmg__free(&d->al, C); phgmg__free(&d->al, W); phgmg__free(&d->al, Fa);
    return PHGMG_ERR_NOMEM;
  }
  for (q = 0; q < k; ++q) {
    for (i = 0; i < nri; ++i) C[i + (size_t)q * nri] = phgmg__ph_l(s, ri[i], d->ra[q]);
    for (j = 0; j < ncj; ++j) d->D[q + (size_t)j * k] = phgmg__ph_l(s, d->ra[q], cj[j]);
    for (j = 0; j < m; ++j) {
      const double b = s->B[d->ra[q] + (size_t)j * N], p = s->P ? s->P[d->ra[q] + (size_t)j * N] : 0.0;
      d->Ga[q + (size_t)j * k] = b - p;
      Fa[q + (size_t)j * k] = b + p;
    }
  }
  memcpy(W, d->D, (size_t)k * ncj * sizeof(double));
  if (ncj) phgmg_lu_solve('N', k, d->L22, k, d->p22, ncj, W, k);
  if (nri && ncj) phgmg_gemm('N', 'N', nri, ncj, k, 1.0, C, nri, W, k, 0.0, U, nri);
  for (j = 0; j < m; ++j)   /* G'[rn] and F'[rn] before the update */
    for (i = 0; i < N; ++i)
      if (d->rpos[i] >= 0) {
        const double b = s->B[i + (size_t)j * N], p = s->P ? s->P[i + (size_t)j * N] : 0.0;
        d->Bc[d->rpos[i] + (size_t)j * n] = b - p;
        d->Pc[d->rpos[i] + (size_t)j * n] = b + p;
      }
  memcpy(Fa + (size_t)k * m, d->Ga, (size_t)k * m * sizeof(double)); /* X1 = L22^{-1} Ga */
  phgmg_lu_solve('N', k, d->L22, k, d->p22, m, Fa + (size_t)k * m, k);
  for (j = 0; j < m; ++j) {
    for (i = 0; i < nri; ++i) {
      double acc = 0.0;
      for (q = 0; q < k; ++q) acc += C[i + (size_t)q * nri] * Fa[(size_t)k * m + q + (size_t)j * k];
      d->Bc[d->rpos[ri[i]] + (size_t)j * n] -= acc;
    }
    for (i = 0; i < m; ++i) {   /* (S + N)' = S + N - Fa^T X1 */
      double acc = (s->S ? s->S[i + (size_t)j * m] : 0.0) + (s->Nskew ? s->Nskew[i + (size_t)j * m] : 0.0);
      for (q = 0; q < k; ++q) acc -= Fa[q + (size_t)i * k] * Fa[(size_t)k * m + q + (size_t)j * k];
      d->Sc[i + (size_t)j * m] = acc;
    }
  }
  phgmg_lu_solve('T', k, d->L22, k, d->p22, m, Fa, k);   /* X2 = L22^{-T} Fa */
  for (j = 0; j < m; ++j)
    for (i = 0; i < ncj; ++i) {
      double acc = 0.0;
      for (q = 0; q < k; ++q) acc += d->D[q + (size_t)i * k] * Fa[q + (size_t)j * k];
      d->Pc[d->rpos[cj[i]] + (size_t)j * n] -= acc;
    }
  phgmg__free(&d->al, C); phgmg__free(&d->al, W); phgmg__free(&d->al, Fa);
  return PHGMG_OK;
}

/* G', F', (S + N)' into the pH ports: B' = (G' + F')/2, P' = (F' - G')/2,
   S' and N' the symmetric and skew parts; a block that is exactly zero is
   left out (NULL), so a constraint away from the ports adds no feedthrough. */
PHGMG__PRIV void phgmg__dae_ports(phgmg_dae *d) {
  const int n = d->n, m = d->m;
  size_t i, len = (size_t)n * m;
  int a, b, anyp = 0, anys = 0, anyn = 0;
  for (i = 0; i < len; ++i) {
    const double g = d->Bc[i], f = d->Pc[i];
    d->Bc[i] = 0.5 * (g + f);
    d->Pc[i] = 0.5 * (f - g);
    anyp |= d->Pc[i] != 0.0;
  }
  for (b = 0; b < m; ++b)
    for (a = 0; a <= b; ++a) {
      const double x = d->Sc[a + (size_t)b * m], y = d->Sc[b + (size_t)a * m];
      d->Sc[a + (size_t)b * m] = d->Sc[b + (size_t)a * m] = 0.5 * (x + y);
      d->Nc[a + (size_t)b * m] = 0.5 * (x - y);
      d->Nc[b + (size_t)a * m] = -0.5 * (x - y);
      anys |= x + y != 0.0;
      anyn |= x - y != 0.0;
    }
  d->sys.B = d->Bc;
  d->sys.P = anyp ? d->Pc : NULL;
  d->sys.S = anys ? d->Sc : NULL;
  d->sys.Nskew = anyn ? d->Nc : NULL;
}

/* Half-bandwidth of the condensed matrices (banded storage). */
PHGMG__PRIV int phgmg__dae_band(const phgmg_dae *d, const phgmg_ph_system *s, const int *ri, int nri, const int *cj,
                                int ncj, const double *U) {
  int kb = 0, i, j, a, b;
  for (j = 0; j < s->N; ++j) {
    phgmg__ph_span(s, j, &a, &b);
    for (i = a; i <= b; ++i) {
      const int ir = d->rpos[i];
      if (ir < 0) continue;
      if (d->rpos[j] >= 0 && phgmg__ph_l(s, i, j) != 0.0) kb = PHGMG__MAX(kb, abs(ir - d->rpos[j]));
      if (d->cpos[j] >= 0 && (phgmg__ph_at(s, s->Q, i, j) != 0.0 || phgmg__ph_at(s, s->E, i, j) != 0.0))
        kb = PHGMG__MAX(kb, abs(ir - d->cpos[j]));
    }
  }
  for (j = 0; j < ncj; ++j)
    for (i = 0; i < nri; ++i)
      if (U[i + (size_t)j * nri] != 0.0) kb = PHGMG__MAX(kb, abs(d->rpos[ri[i]] - d->rpos[cj[j]]));
  return PHGMG__MIN(kb, d->n - 1);
}

/* J', R', Q', E' of the condensed model: the kept blocks of J, R, Q, E and
   J' = J - (U - U^T)/2, R' = R + (U + U^T)/2 (so J' - R' = L' = L - U). */
PHGMG__PRIV phgmg_result phgmg__dae_assemble(phgmg_dae *d, const phgmg_ph_system *s, const int *ri, int nri,
                                             const int *cj, int ncj, const double *U) {
  const int n = d->n, kb = s->storage == PHGMG_BANDED ? phgmg__dae_band(d, s, ri, nri, cj, ncj, U) : n - 1;
  const size_t len = s->storage == PHGMG_BANDED ? (size_t)(2 * kb + 1) * n : (size_t)n * n;
  double *Jc, *Rc, *Qc, *Ec;
  int i, j, a, b;
#define PHGMG__DX(i, j) (s->storage == PHGMG_BANDED ? PHGMG__PHB(kb, i, j) : (size_t)(i) + (size_t)(j) * (size_t)n)
  d->mats = phgmg__dalloc(&d->al, 4 * len);
  if (!d->mats) return PHGMG_ERR_NOMEM;
  memset(d->mats, 0, 4 * len * sizeof(double));
  Jc = d->mats; Rc = Jc + len; Qc = Rc + len; Ec = Qc + len;
  for (j = 0; j < s->N; ++j) {
    phgmg__ph_span(s, j, &a, &b);
    for (i = a; i <= b; ++i) {
      const int ir = d->rpos[i], jr = d->rpos[j], jc = d->cpos[j];
      if (ir < 0) continue;
      if (jr >= 0) { Jc[PHGMG__DX(ir, jr)] = phgmg__ph_at(s, s->J, i, j); Rc[PHGMG__DX(ir, jr)] = phgmg__ph_at(s, s->R, i, j); }
      if (jc >= 0) { Qc[PHGMG__DX(ir, jc)] = phgmg__ph_at(s, s->Q, i, j); Ec[PHGMG__DX(ir, jc)] = phgmg__ph_at(s, s->E, i, j); }
    }
  }
  for (j = 0; j < ncj; ++j)
    for (i = 0; i < nri; ++i) {
      const double u = 0.5 * U[i + (size_t)j * nri];
      const int p = d->rpos[ri[i]], q = d->rpos[cj[j]];
      Jc[PHGMG__DX(p, q)] -= u; Jc[PHGMG__DX(q, p)] += u;
      Rc[PHGMG__DX(p, q)] += u; Rc[PHGMG__DX(q, p)] += u;
    }
#undef PHGMG__DX
  d->sys.storage = s->storage;
  d->sys.kb = s->storage == PHGMG_BANDED ? kb : 0;
  d->sys.J = Jc; d->sys.R = Rc; d->sys.Q = Qc; d->sys.E = Ec;
  return PHGMG_OK;
}

/* Q[rn, ca] = 0 (E^T Q symmetric with E[:, ca] = 0 implies it: the kept
   co-states do not depend on the algebraic variables), and Q[ra, cn] kept
   for the lift. */
PHGMG__PRIV phgmg_result phgmg__dae_qmaps(phgmg_dae *d, const phgmg_ph_system *s, double tol) {
  const int k = d->k;
  int *mark = phgmg__ialloc(&d->al, (size_t)s->N), i, j, q, a, b;
  double qmax = 0.0, off = 0.0;
  if (!mark) return PHGMG_ERR_NOMEM;
  memset(mark, 0, (size_t)s->N * sizeof(int));
  for (j = 0; j < s->N; ++j) {
    phgmg__ph_span(s, j, &a, &b);
    for (i = a; i <= b; ++i) {
      const double v = fabs(phgmg__ph_at(s, s->Q, i, j));
      qmax = PHGMG__MAX(qmax, v);
      if (d->rpos[i] >= 0 && d->cpos[j] < 0) off = PHGMG__MAX(off, v);
      if (d->rpos[i] < 0 && d->cpos[j] >= 0 && v != 0.0) mark[j] = 1;
    }
  }
  if (off > tol * qmax) { phgmg__free(&d->al, mark); return PHGMG_ERR_EQ_NOT_SYMMETRIC; }
  for (j = 0, d->nq = 0; j < s->N; ++j) d->nq += mark[j];
  d->qcol = phgmg__ialloc(&d->al, (size_t)d->nq + 1);
  d->Qa = phgmg__dalloc(&d->al, (size_t)k * d->nq + 1);
  if (d->qcol && d->Qa)
    for (j = 0, a = 0; j < s->N; ++j)
      if (mark[j]) {
        for (q = 0; q < k; ++q) d->Qa[q + (size_t)a * k] = phgmg__ph_at(s, s->Q, d->ra[q], j);
        d->qcol[a++] = d->cpos[j];
      }
  phgmg__free(&d->al, mark);
  return d->qcol && d->Qa ? PHGMG_OK : PHGMG_ERR_NOMEM;
}

/* The nonlinear part and the dampers in condensed coordinates: a separable
   coordinate i must keep its row and column at one position (rpos = cpos),
   a damper must act on kept co-states (PHGMG_ERR_UNSUPPORTED otherwise). */
PHGMG__PRIV phgmg_result phgmg__dae_nonlinear(phgmg_dae *d, const phgmg_ph_system *s) {
  int t;
  if (s->nl == PHGMG_NL_SEPARABLE && s->nsep > 0) {
    d->sep_idx = phgmg__ialloc(&d->al, (size_t)s->nsep);
    if (!d->sep_idx) return PHGMG_ERR_NOMEM;
    for (t = 0; t < s->nsep; ++t) {
      const int i = s->sep_idx[t];
      if (d->cpos[i] < 0 || d->rpos[i] != d->cpos[i]) return PHGMG_ERR_UNSUPPORTED;
      d->sep_idx[t] = d->cpos[i];
    }
    d->sys.sep_idx = d->sep_idx;
  }
  if (s->ndamp > 0) {
    d->damp_i = phgmg__ialloc(&d->al, 2 * (size_t)s->ndamp);
    if (!d->damp_i) return PHGMG_ERR_NOMEM;
    d->damp_j = d->damp_i + s->ndamp;
    for (t = 0; t < s->ndamp; ++t) {
      const int i = s->damp_i[t], j = s->damp_j ? s->damp_j[t] : -1;
      if (d->rpos[i] < 0 || (j >= 0 && d->rpos[j] < 0)) return PHGMG_ERR_UNSUPPORTED;
      d->damp_i[t] = d->rpos[i];
      d->damp_j[t] = j >= 0 ? d->rpos[j] : -1;
    }
    d->sys.damp_i = d->damp_i;
    d->sys.damp_j = d->damp_j;
  }
  return PHGMG_OK;
}

/* The condensation proper, after the split and the index check. */
PHGMG__PRIV phgmg_result phgmg__dae_condense(phgmg_dae *d, const phgmg_ph_system *s, double tol) {
  int *ri = NULL, *cj = NULL, nri = 0, ncj = 0, i;
  double *U = NULL;
  phgmg_result rc;
  const size_t nm = (size_t)d->n * d->m, mm = (size_t)d->m * d->m;
  d->Bc = phgmg__dalloc(&d->al, 2 * nm + 2 * mm);
  if (!d->Bc) return PHGMG_ERR_NOMEM;
  d->Pc = d->Bc + nm; d->Sc = d->Pc + nm; d->Nc = d->Sc + mm;
  rc = phgmg__dae_qmaps(d, s, tol);
  if (rc == PHGMG_OK) rc = phgmg__dae_support(d, s, &ri, &nri, &cj, &ncj);
  if (rc == PHGMG_OK) rc = phgmg__dae_eliminate(d, s, ri, nri, cj, ncj, &U);
  if (rc == PHGMG_OK) rc = phgmg__dae_assemble(d, s, ri, nri, cj, ncj, U);
  if (rc == PHGMG_OK) {
    phgmg__dae_ports(d);
    d->nd = ncj;
    d->dcol = phgmg__ialloc(&d->al, (size_t)ncj + 1);
    if (!d->dcol) rc = PHGMG_ERR_NOMEM;
    for (i = 0; rc == PHGMG_OK && i < ncj; ++i) d->dcol[i] = d->rpos[cj[i]];
  }
  phgmg__free(&d->al, ri);
  phgmg__free(&d->al, U);
  return rc;
}

/* Full orthogonal Q (N x N) whose first r columns span those of A (N x r). */
PHGMG__PRIV phgmg_result phgmg__orth_complete(int N, int r, const double *A, double *Q, const phgmg_allocator *al) {
  double *F = phgmg__dalloc(al, (size_t)N * r + 1), *tau = phgmg__dalloc(al, (size_t)r + 1);
  phgmg_result rc = F && tau ? PHGMG_OK : PHGMG_ERR_NOMEM;
  int i;
  if (rc == PHGMG_OK) {
    memcpy(F, A, sizeof(double) * (size_t)N * r);
    rc = phgmg_qr(N, r, F, N, tau);
  }
  if (rc == PHGMG_OK) {
    memset(Q, 0, sizeof(double) * (size_t)N * N);
    for (i = 0; i < N; ++i) Q[i + (size_t)i * N] = 1.0;
    phgmg_qr_apply('N', N, N, r, F, N, tau, Q, N);
  }
  phgmg__free(al, F);
  phgmg__free(al, tau);
  return rc;
}

/* A dense model whose singular E has no zero lines, in rotated coordinates
   (manual 1.8): Qu, Qv orthogonal with the ranges of E and E^T first, so
   that E_t = Qu^T E Qv has k zero rows and columns (set exactly); J_t =
   Qu^T J Qu, R_t = Qu^T R Qu (a congruence: J_t skew, R_t PSD), Q_t = Qu^T Q
   Qv, B_t = Qu^T B, P_t = Qu^T P, S and N as they are: E_t^T Q_t = Qv^T E^T
   Q Qv. *buf owns t's arrays; d->V = Qv. Rank: singular values above tol
   times the largest. */
PHGMG__PRIV phgmg_result phgmg__dae_rotate(phgmg_dae *d, const phgmg_ph_system *s, double tol, phgmg_ph_system *t,
                                           double **buf) {
  const int N = s->N, m = s->m;
  const size_t NN = (size_t)N * N;
  double *b, *Qu, *T, *Sv, *U, *Vv, *E_t, *J_t, *R_t, *Q_t, *B_t;
  int r = 0, kk = 0, i, j;
  phgmg_result rc;
  *buf = b = phgmg__dalloc(&d->al, 8 * NN + 2 * (size_t)N * m + (size_t)N);
  d->V = phgmg__dalloc(&d->al, NN);
  if (!b || !d->V) return PHGMG_ERR_NOMEM;
  Qu = b; T = Qu + NN; U = T + NN; Vv = U + NN; E_t = Vv + NN; J_t = E_t + NN; R_t = J_t + NN; Q_t = R_t + NN;
  B_t = Q_t + NN; Sv = B_t + 2 * (size_t)N * m;
  rc = phgmg_svd(N, N, s->E, N, N, Sv, U, N, Vv, N, &kk, NULL, &d->al);
  for (i = 0; rc == PHGMG_OK && i < kk; ++i) r += Sv[i] > tol * Sv[0];
  if (rc == PHGMG_OK) rc = phgmg__orth_complete(N, r, U, Qu, &d->al);
  if (rc == PHGMG_OK) rc = phgmg__orth_complete(N, r, Vv, d->V, &d->al);
  if (rc != PHGMG_OK) return rc;
#define PHGMG__CONG(A, L, Rm, out)                                                   \
  do {                                                                             \
    phgmg_gemm('N', 'N', N, N, N, 1.0, (A), N, (Rm), N, 0.0, T, N);                \
    phgmg_gemm('T', 'N', N, N, N, 1.0, (L), N, T, N, 0.0, (out), N);               \
  } while (0)
  PHGMG__CONG(s->E, Qu, d->V, E_t);
  PHGMG__CONG(s->J, Qu, Qu, J_t);
  PHGMG__CONG(s->R, Qu, Qu, R_t);
  PHGMG__CONG(s->Q, Qu, d->V, Q_t);
#undef PHGMG__CONG
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) {
      if (i >= r || j >= r) E_t[i + (size_t)j * N] = 0.0;
      if (i < j) {
        const double a = 0.5 * (J_t[i + (size_t)j * N] - J_t[j + (size_t)i * N]);
        const double c = 0.5 * (R_t[i + (size_t)j * N] + R_t[j + (size_t)i * N]);
        J_t[i + (size_t)j * N] = a; J_t[j + (size_t)i * N] = -a;
        R_t[i + (size_t)j * N] = R_t[j + (size_t)i * N] = c;
      }
    }
  for (i = 0; i < N; ++i) J_t[i + (size_t)i * N] = 0.0;
  phgmg_gemm('T', 'N', N, m, N, 1.0, Qu, N, s->B, N, 0.0, B_t, N);
  if (s->P) phgmg_gemm('T', 'N', N, m, N, 1.0, Qu, N, s->P, N, 0.0, B_t + (size_t)N * m, N);
  *t = *s;
  t->E = E_t; t->J = J_t; t->R = R_t; t->Q = Q_t; t->B = B_t; t->P = s->P ? B_t + (size_t)N * m : NULL;
  return PHGMG_OK;
}

PHGMG_DEF void phgmg_dae_destroy(phgmg_dae *d) {
  phgmg_allocator al;
  if (!d) return;
  al = d->al;
  phgmg__free(&al, d->rpos); phgmg__free(&al, d->ra); phgmg__free(&al, d->sep_idx);
  phgmg__free(&al, d->damp_i); phgmg__free(&al, d->mats); phgmg__free(&al, d->Bc);
  phgmg__free(&al, d->L22); phgmg__free(&al, d->p22); phgmg__free(&al, d->dcol);
  phgmg__free(&al, d->qcol); phgmg__free(&al, d->D); phgmg__free(&al, d->Qa);
  phgmg__free(&al, d->Ga); phgmg__free(&al, d->work); phgmg__free(&al, d->V);
  phgmg__free(&al, d);
}

PHGMG_DEF phgmg_result phgmg_dae_create(phgmg_dae **out, const phgmg_ph_system *sys, double tol,
                                        const phgmg_allocator *alloc) {
  phgmg_dae *d;
  phgmg_ph_system rot;
  double *rbuf = NULL;
  phgmg_result rc;
  if (!out) return PHGMG_ERR_INVALID_ARG;
  *out = NULL;
  rc = phgmg__ph_check(sys);
  if (rc != PHGMG_OK) return rc;
  if (!sys->E) return PHGMG_ERR_INVALID_ARG;
  if (!(tol > 0.0)) tol = 1e-12;
  if (!phgmg__ph_mat_finite(sys, sys->E) || !phgmg__ph_mat_finite(sys, sys->J) ||
      !phgmg__ph_mat_finite(sys, sys->R) || !phgmg__ph_mat_finite(sys, sys->Q) ||
      !phgmg__all_finite(sys->B, (size_t)sys->N * (size_t)sys->m))
    return PHGMG_ERR_NANINF;
  d = PHGMG__CAST(phgmg_dae *, phgmg__alloc(alloc, sizeof *d));
  if (!d) return PHGMG_ERR_NOMEM;
  memset(d, 0, sizeof *d);
  if (alloc) d->al = *alloc;
  d->N = sys->N; d->m = sys->m;
  d->sys = *sys;
  if (sys->storage != PHGMG_SPARSE) d->sys.sparse = NULL; /* SPARSE: E regular (k = 0), the object's system */
  d->rpos = phgmg__ialloc(&d->al, 2 * (size_t)sys->N);
  rc = d->rpos ? PHGMG_OK : PHGMG_ERR_NOMEM;
  if (rc == PHGMG_OK) {
    const int kind = phgmg__e_algebraic(sys, &d->al);
    if (kind < 0) rc = PHGMG_ERR_NOMEM;
    else if (kind == 2) rc = phgmg__dae_rotate(d, sys, tol, &rot, &rbuf);
    if (kind == 2 && rc == PHGMG_OK) { sys = &rot; d->sys = rot; }
  }
  if (rc == PHGMG_OK) { d->cpos = d->rpos + sys->N; rc = phgmg__dae_split(d, sys); }
  if (rc == PHGMG_OK && rbuf && d->k == 0) rc = PHGMG_ERR_E_SINGULAR;   /* no singular value below tol */
  if (rc == PHGMG_OK && d->k > 0) {
    d->sys.N = d->n;
    rc = d->n > 0 && d->m <= d->n ? phgmg__dae_index(d, sys, tol) : PHGMG_ERR_SIZE;
    if (rc == PHGMG_OK) rc = phgmg__dae_condense(d, sys, tol);
    if (rc == PHGMG_OK) rc = phgmg__dae_nonlinear(d, sys);
  }
  if (rc == PHGMG_OK) rc = phgmg__ph_validate(&d->sys, tol, NULL, &d->al, d->k == 0);
  if (rc == PHGMG_OK) {
    d->work = phgmg__dalloc(&d->al, (size_t)d->n + 2 * (size_t)d->k + (size_t)d->m + (size_t)d->N + 1);
    if (!d->work) rc = PHGMG_ERR_NOMEM;
  }
  phgmg__free(&d->al, rbuf);
  if (rc != PHGMG_OK) { phgmg_dae_destroy(d); return rc; }
  *out = d;
  return PHGMG_OK;
}

PHGMG_DEF const phgmg_ph_system *phgmg_dae_system(const phgmg_dae *d) { return d ? &d->sys : NULL; }
PHGMG_DEF int phgmg_dae_nalg(const phgmg_dae *d) { return d ? d->k : 0; }

/* Rotated models keep the differential coordinates first: xi = Qv(:, 0..n)^T x. */
PHGMG_DEF void phgmg_dae_restrict(const phgmg_dae *d, const double *x, double *xi) {
  int i;
  if (d->V) { phgmg_gemv('T', d->N, d->n, 1.0, d->V, d->N, x, 0.0, xi); return; }
  for (i = 0; i < d->N; ++i)
    if (d->cpos[i] >= 0) xi[d->cpos[i]] = x[i];
}

PHGMG_DEF void phgmg_dae_embed(const phgmg_dae *d, const double *xi, double *x) {
  int i;
  if (d->V) { phgmg_gemv('N', d->N, d->n, 1.0, d->V, d->N, xi, 0.0, x); return; }
  for (i = 0; i < d->N; ++i) x[i] = d->cpos[i] >= 0 ? xi[d->cpos[i]] : 0.0;
}

PHGMG__PRIV void phgmg__dae_lift_t(phgmg_dae *d, const double *xi, const double *u, double *x);
PHGMG_DEF void phgmg_dae_lift(phgmg_dae *d, const double *xi, const double *u, double *x) {
  double *xt = d->work + d->n + 2 * d->k + d->m;
  if (!d->V) { phgmg__dae_lift_t(d, xi, u, x); return; }
  phgmg__dae_lift_t(d, xi, u, xt);
  phgmg_gemv('N', d->N, d->N, 1.0, d->V, d->N, xt, 0.0, x);
}

/* The lift in the model's own (or rotated) coordinates. */
PHGMG__PRIV void phgmg__dae_lift_t(phgmg_dae *d, const double *xi, const double *u, double *x) {
  const int n = d->n, k = d->k, m = d->m;
  double *z = d->work, *t = z + n, *r = t + k;
  int i, q;
  for (i = 0; i < d->N; ++i)
    if (d->cpos[i] >= 0) x[i] = xi[d->cpos[i]];
  if (k == 0) return;
  phgmg__ph_grad(&d->sys, xi, z, NULL);
  for (q = 0; q < k; ++q) {   /* t = L[ra, rn] z1 + G[ra] u */
    double acc = 0.0;
    for (i = 0; i < d->nd; ++i) acc += d->D[q + (size_t)i * k] * z[d->dcol[i]];
    for (i = 0; u && i < m; ++i) acc += d->Ga[q + (size_t)i * k] * u[i];
    t[q] = acc;
  }
  phgmg_lu_solve('N', k, d->L22, k, d->p22, 1, t, k);   /* z2 = -t */
  for (q = 0; q < k; ++q) {
    double acc = -t[q];
    for (i = 0; i < d->nq; ++i) acc -= d->Qa[q + (size_t)i * k] * xi[d->qcol[i]];
    r[q] = acc;
  }
  phgmg_lu_solve('N', k, d->Q22, k, d->q22, 1, r, k);
  for (q = 0; q < k; ++q) x[d->ca[q]] = r[q];
}

/* phgmg_ph_validate of a model with algebraic rows or columns of E. */
PHGMG__PRIV phgmg_result phgmg__dae_validate(const phgmg_ph_system *sys, double tol, const phgmg_allocator *alloc) {
  phgmg_dae *d = NULL;
  phgmg_result rc = phgmg_dae_create(&d, sys, tol, alloc);
  phgmg_dae_destroy(d);
  return rc;
}

/* phgmg_simulate of an index-one model: the condensed model from the
   differential part of x0, its states lifted with u(t_n). */
PHGMG__PRIV phgmg_result phgmg__simulate_dae(const phgmg_ph_system *sys, const double *x0, double t0, double dt,
                                             int nsteps, phgmg_input_fn uf, void *uuser,
                                             const phgmg_gl3_opts *opts, double *X, double *Y,
                                             const phgmg_energy *energy, phgmg_gl3_stats *stats,
                                             int *steps_done, const phgmg_allocator *alloc) {
  phgmg_dae *d = NULL;
  double *xi = NULL, *u = NULL;
  int done = 0, j;
  phgmg_result rc = phgmg_dae_create(&d, sys, 0.0, alloc);
  if (rc != PHGMG_OK) return rc;
  xi = phgmg__dalloc(alloc, (size_t)d->n * (X ? (size_t)nsteps + 1 : 1));
  u = phgmg__dalloc(alloc, (size_t)d->m);
  if (!xi || !u) rc = PHGMG_ERR_NOMEM;
  if (rc == PHGMG_OK) {
    phgmg_dae_restrict(d, x0, xi);
    rc = phgmg_simulate(&d->sys, xi, t0, dt, nsteps, uf, uuser, opts, X ? xi : NULL, Y, energy, stats, &done, alloc);
    for (j = 0; X && j <= done && j <= nsteps; ++j) {
      if (uf) uf(t0 + (double)j * dt, u, uuser);
      phgmg_dae_lift(d, xi + (size_t)j * d->n, uf ? u : NULL, X + (size_t)j * d->N);
    }
  }
  if (steps_done) *steps_done = done;
  phgmg__free(alloc, xi);
  phgmg__free(alloc, u);
  phgmg_dae_destroy(d);
  return rc;
}

/* >>sparse (implementation) ============================================== */
/* Sparse direct solver of the GL3 stage matrices K = sigma I + M,
   M = -(J - R)(Q + D) (manual 8.12): nested dissection on the
   symmetrised pattern, elimination tree, supernodes, multifrontal LU with
   dense fronts and the diagonal pivots of the ordering (static pivoting). */

/* Nested dissection workspace: the graph (CSR, symmetric, no diagonal) and
   the per-node arrays shared by the recursion. */
typedef struct phgmg__nd {
  int n;
  const int *ap, *ai;
  int *lab, *lev, *queue, *order;
  int nout, nlab;
  unsigned long long *bits; /* PHGMG__ND_LEAF^2 bits: a part's elimination graph */
  int *mate, *vis, stamp;   /* separator refinement (matching, marks)          */
} phgmg__nd;

/* Breadth-first search from root over the nodes labelled lab: levels into
   nd->lev, nodes in BFS order into queue[0..*cnt); returns the number of
   levels. */
PHGMG__PRIV int phgmg__nd_bfs(phgmg__nd *d, int root, int lab, int *cnt) {
  int head = 0, tail = 0, nl = 0, p;
  d->queue[tail++] = root;
  d->lev[root] = 0;
  d->lab[root] = -2 - lab; /* visited mark, restored below */
  while (head < tail) {
    int v = d->queue[head++];
    if (d->lev[v] + 1 > nl) nl = d->lev[v] + 1;
    for (p = d->ap[v]; p < d->ap[v + 1]; ++p) {
      int w = d->ai[p];
      if (d->lab[w] != lab) continue;
      d->lab[w] = -2 - lab;
      d->lev[w] = d->lev[v] + 1;
      d->queue[tail++] = w;
    }
  }
  for (p = 0; p < tail; ++p) d->lab[d->queue[p]] = lab;
  *cnt = tail;
  return nl;
}

/* Degree of v within the nodes labelled lab. */
PHGMG__PRIV int phgmg__nd_deg(const phgmg__nd *d, int v, int lab) {
  int p, k = 0;
  for (p = d->ap[v]; p < d->ap[v + 1]; ++p) k += d->lab[d->ai[p]] == lab;
  return k;
}

#define PHGMG__ND_LEAF 256 /* parts this small: minimum degree */

PHGMG__PRIV int phgmg__popcount64(unsigned long long x) {
  x = x - ((x >> 1) & 0x5555555555555555ULL);
  x = (x & 0x3333333333333333ULL) + ((x >> 2) & 0x3333333333333333ULL);
  x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0FULL;
  return (int)((x * 0x0101010101010101ULL) >> 56);
}

/* Minimum degree order of a small part (cnt <= PHGMG__ND_LEAF nodes, all
   labelled lab), exact, on its elimination graph as a bit matrix (degrees
   within the part; ties: the earlier node). */
PHGMG__PRIV void phgmg__nd_leaf(phgmg__nd *d, const int *list, int cnt, int lab) {
  enum { WD = PHGMG__ND_LEAF / 64 };
  unsigned long long *adj = d->bits, alive[WD];
  int i, p, k, w, nw = (cnt + 63) / 64;
  for (i = 0; i < cnt; ++i) d->lev[list[i]] = i; /* local index */
  for (i = 0; i < cnt * WD; ++i) adj[i] = 0;
  for (w = 0; w < WD; ++w) alive[w] = 0;
  for (i = 0; i < cnt; ++i) {
    int v = list[i];
    alive[i / 64] |= 1ULL << (i % 64);
    for (p = d->ap[v]; p < d->ap[v + 1]; ++p) {
      int u = d->ai[p];
      if (d->lab[u] != lab) continue;
      u = d->lev[u];
      if (u != i) adj[i * WD + u / 64] |= 1ULL << (u % 64);
    }
  }
  for (k = 0; k < cnt; ++k) {
    int best = -1, bdeg = 0;
    for (i = 0; i < cnt; ++i) {
      int g = 0;
      if (!(alive[i / 64] >> (i % 64) & 1ULL)) continue;
      for (w = 0; w < nw; ++w) g += phgmg__popcount64(adj[i * WD + w]);
      if (best < 0 || g < bdeg) { best = i; bdeg = g; }
    }
    alive[best / 64] &= ~(1ULL << (best % 64));
    for (i = 0; i < cnt; ++i) { /* neighbours of best: a clique, best removed */
      if (!(adj[best * WD + i / 64] >> (i % 64) & 1ULL)) continue;
      for (w = 0; w < nw; ++w) adj[i * WD + w] |= adj[best * WD + w];
      adj[i * WD + i / 64] &= ~(1ULL << (i % 64));
      adj[i * WD + best / 64] &= ~(1ULL << (best % 64));
    }
    d->order[d->nout++] = list[best];
    d->lab[list[best]] = -1;
  }
}

/* Augmenting path from x (level ly - 1) into level ly (Kuhn). */
PHGMG__PRIV int phgmg__nd_aug(phgmg__nd *d, int x, int lab, int ly) {
  int p;
  for (p = d->ap[x]; p < d->ap[x + 1]; ++p) {
    int y = d->ai[p];
    if (d->lab[y] != lab || d->lev[y] != ly || d->vis[y] == d->stamp) continue;
    d->vis[y] = d->stamp;
    if (d->mate[y] < 0 || phgmg__nd_aug(d, d->mate[y], lab, ly)) {
      d->mate[y] = x;
      d->mate[x] = y;
      return 1;
    }
  }
  return 0;
}

/* Minimum vertex cover of the bipartite graph between BFS levels L and L+1
   (the first cnt entries of queue, labelled lab): maximum matching by
   augmenting paths, then Koenig's construction; cover nodes get vis = -1. */
PHGMG__PRIV void phgmg__nd_cover(phgmg__nd *d, int cnt, int lab, int L) {
  int i, p, head = 0, tail = 0, *q = d->queue + cnt; /* queue has room for n: BFS of cnt used */
  for (i = 0; i < cnt; ++i) {
    int x = d->queue[i];
    if (d->lev[x] != L) continue;
    ++d->stamp;
    phgmg__nd_aug(d, x, lab, L + 1);
  }
  ++d->stamp; /* Z: reachable from unmatched X by alternating paths */
  for (i = 0; i < cnt; ++i) {
    int x = d->queue[i];
    if (d->lev[x] == L && d->mate[x] < 0) { d->vis[x] = d->stamp; q[tail++] = x; }
  }
  while (head < tail) {
    int x = q[head++];
    for (p = d->ap[x]; p < d->ap[x + 1]; ++p) {
      int y = d->ai[p], x2;
      if (d->lab[y] != lab || d->lev[y] != L + 1 || d->vis[y] == d->stamp) continue;
      d->vis[y] = d->stamp;
      x2 = d->mate[y];
      if (x2 >= 0 && d->vis[x2] != d->stamp) { d->vis[x2] = d->stamp; q[tail++] = x2; }
    }
  }
  for (i = 0; i < cnt; ++i) { /* cover: (X \ Z) + (Y & Z) */
    int v = d->queue[i], lv = d->lev[v], z = d->vis[v] == d->stamp;
    if ((lv == L && !z) || (lv == L + 1 && z)) d->vis[v] = -1;
    if (lv == L || lv == L + 1) d->mate[v] = -1;
  }
}

/* Order the nodes list[0..cnt) (all labelled lab): split by the middle level
   of a breadth-first search from a pseudo-peripheral node, the two halves
   first (recursively), the separator last. Unconnected parts one after the
   other (a loop, so that many small components do not deepen the recursion). */
PHGMG__PRIV void phgmg__nd_rec(phgmg__nd *d, int *list, int cnt, int lab);

/* A part that is not connected: its components found in one pass (each by a
   search from the first node of the list not yet reached, in search order;
   O(part), where splitting off one component at a time cost O(part) per
   component -- quadratic for the many isolated states of a diagonal block),
   a rest of at most PHGMG__ND_LEAF nodes kept as one leaf in list order,
   then each ordered in turn. */
PHGMG__PRIV void phgmg__nd_components(phgmg__nd *d, int *list, int cnt, int lab) {
  int *base = d->queue, r = 0, i, k, s;
  for (i = 0; i < cnt && r < cnt; ++i) {
    int v = list[i], c, lc;
    if (d->lab[v] != lab) continue;
    lc = ++d->nlab;
    if (r > 0 && cnt - r <= PHGMG__ND_LEAF) { /* the rest, as it comes */
      for (k = i; k < cnt; ++k)
        if (d->lab[list[k]] == lab) { d->lab[list[k]] = lc; base[r++] = list[k]; }
      break;
    }
    d->queue = base + r;
    phgmg__nd_bfs(d, v, lab, &c);
    d->queue = base;
    for (k = 0; k < c; ++k) d->lab[base[r + k]] = lc;
    r += c;
  }
  for (i = 0; i < cnt; ++i) list[i] = base[i];
  for (s = 0; s < cnt;) { /* the segments, each with its own label */
    int e = s + 1, lc = d->lab[list[s]];
    while (e < cnt && d->lab[list[e]] == lc) ++e;
    phgmg__nd_rec(d, list + s, e - s, lc);
    s = e;
  }
}

PHGMG__PRIV void phgmg__nd_rec(phgmg__nd *d, int *list, int cnt, int lab) {
  for (;;) {
    int root, nl, reach, i, it, half, sep_lev, na = 0, nb = 0, ns = 0, la, lb, ls;
    if (cnt <= PHGMG__ND_LEAF) {
      phgmg__nd_leaf(d, list, cnt, lab);
      return;
    }
    root = list[0];
    nl = phgmg__nd_bfs(d, root, lab, &reach);
    if (reach < cnt) { /* not connected: each component (roots in list order), a rest of <= leaf nodes as one */
      phgmg__nd_components(d, list, cnt, lab);
      return;
    }
    for (it = 0; it < 6; ++it) { /* pseudo-peripheral node (George-Liu) */
      int best = -1, bdeg = 0, k, nl2, r2;
      for (k = reach - 1; k >= 0 && d->lev[d->queue[k]] == nl - 1; --k) {
        int g = phgmg__nd_deg(d, d->queue[k], lab);
        if (best < 0 || g < bdeg) { best = d->queue[k]; bdeg = g; }
      }
      nl2 = phgmg__nd_bfs(d, best, lab, &r2);
      if (nl2 <= nl) { nl = phgmg__nd_bfs(d, root, lab, &reach); break; }
      root = best;
      nl = nl2;
    }
    if (nl < 3) { /* too compact to split by levels */
      for (i = 0; i < cnt; ++i) { d->order[d->nout++] = list[i]; d->lab[list[i]] = -1; }
      return;
    }
    /* the separator: a minimum vertex cover of the edges between the level
       where the count reaches half (X) and the next (Y) */
    half = 0;
    sep_lev = 0;
    for (i = 0; i < cnt; ++i) {
      sep_lev = d->lev[d->queue[i]];
      if (++half >= cnt / 2) break;
    }
    if (sep_lev < 1) sep_lev = 1;
    if (sep_lev > nl - 2) sep_lev = nl - 2;
    la = ++d->nlab;
    lb = ++d->nlab;
    ls = ++d->nlab;
    phgmg__nd_cover(d, cnt, lab, sep_lev);
    for (i = 0; i < cnt; ++i) {
      int v = d->queue[i], lv = d->lev[v];
      if (lv < sep_lev) d->lab[v] = la;
      else if (lv > sep_lev + 1) d->lab[v] = lb;
      else if (d->vis[v] == -1) d->lab[v] = ls; /* in the cover */
      else d->lab[v] = lv == sep_lev ? la : lb;
    }
    for (i = 0; i < cnt; ++i) d->vis[d->queue[i]] = 0;
    { /* list: part a, part b, separator */
      int *q = d->queue;
      for (i = 0; i < cnt; ++i) q[i] = list[i];
      for (i = 0; i < cnt; ++i) if (d->lab[q[i]] == la) list[na++] = q[i];
      for (i = 0; i < cnt; ++i) if (d->lab[q[i]] == lb) list[na + nb++] = q[i];
      for (i = 0; i < cnt; ++i) if (d->lab[q[i]] == ls) list[na + nb + ns++] = q[i];
    }
    phgmg__nd_rec(d, list, na, la);
    phgmg__nd_rec(d, list + na, nb, lb);
    for (i = 0; i < ns; ++i) { d->order[d->nout++] = list[na + nb + i]; d->lab[list[na + nb + i]] = -1; }
    return;
  }
}

/* Nested dissection order of a symmetric graph (CSR without diagonal):
   order[k] = node eliminated k-th. */
PHGMG__PRIV phgmg_result phgmg__nd_order(int n, const int *ap, const int *ai, int *order,
                                         const phgmg_allocator *al) {
  phgmg__nd d;
  int *list, i;
  d.n = n; d.ap = ap; d.ai = ai; d.order = order; d.nout = 0; d.nlab = 0;
  d.lab = phgmg__ialloc(al, (size_t)n);
  d.lev = phgmg__ialloc(al, (size_t)n);
  d.queue = phgmg__ialloc(al, 2 * (size_t)n);
  list = phgmg__ialloc(al, (size_t)n);
  d.bits = PHGMG__CAST(unsigned long long *,
                       phgmg__alloc(al, sizeof(unsigned long long) * PHGMG__ND_LEAF * (PHGMG__ND_LEAF / 64)));
  d.mate = phgmg__ialloc(al, (size_t)n);
  d.vis = phgmg__ialloc(al, (size_t)n);
  d.stamp = 0;
  if (!d.lab || !d.lev || !d.queue || !list || !d.bits || !d.mate || !d.vis) {
    phgmg__free(al, d.lab); phgmg__free(al, d.lev); phgmg__free(al, d.queue); phgmg__free(al, list);
    phgmg__free(al, d.bits); phgmg__free(al, d.mate); phgmg__free(al, d.vis);
    return PHGMG_ERR_NOMEM;
  }
  for (i = 0; i < n; ++i) { d.mate[i] = -1; d.vis[i] = 0; }
  for (i = 0; i < n; ++i) { d.lab[i] = 0; list[i] = i; d.lev[i] = 0; }
  phgmg__nd_rec(&d, list, n, 0);
  phgmg__free(al, d.bits); phgmg__free(al, d.mate); phgmg__free(al, d.vis);
  phgmg__free(al, d.lab); phgmg__free(al, d.lev); phgmg__free(al, d.queue); phgmg__free(al, list);
  return d.nout == n ? PHGMG_OK : PHGMG_ERR_INVALID_ARG;
}

/* Elimination tree of the symmetric pattern (CSR, any order of neighbours)
   in the order given by iperm (new index of node v: iperm[v]); parent in the
   new numbering, -1 for a root (Liu's algorithm, path compression). */
PHGMG__PRIV void phgmg__etree(int n, const int *ap, const int *ai, const int *perm, const int *iperm,
                              int *parent, int *anc) {
  int k, p;
  for (k = 0; k < n; ++k) {
    int v = perm[k];
    parent[k] = -1;
    anc[k] = -1;
    for (p = ap[v]; p < ap[v + 1]; ++p) {
      int r = iperm[ai[p]];
      if (r >= k) continue;
      while (anc[r] != -1 && anc[r] != k) { int t = anc[r]; anc[r] = k; r = t; }
      if (anc[r] == -1) { anc[r] = k; parent[r] = k; }
    }
  }
}

/* Postorder of a forest: post[k] = node visited k-th (children before parents). */
PHGMG__PRIV void phgmg__postorder(int n, const int *parent, int *post, int *head, int *next, int *stack) {
  int j, k = 0;
  for (j = 0; j < n; ++j) head[j] = -1;
  for (j = n - 1; j >= 0; --j)
    if (parent[j] >= 0) { next[j] = head[parent[j]]; head[parent[j]] = j; }
  for (j = 0; j < n; ++j) {
    int top = 0;
    if (parent[j] != -1) continue;
    stack[0] = j;
    while (top >= 0) {
      int p = stack[top], c = head[p];
      if (c == -1) { --top; post[k++] = p; }
      else { head[p] = next[c]; stack[++top] = c; }
    }
  }
}

/* The symbolic analysis (owned by phgmg_ph_sparse, shared by its steppers). */
typedef struct phgmg__spsym {
  int n;
  int *jr_p, *jr_i; double *jr_x; /* J - R, CSC, internal order        */
  int *q_p, *q_i; double *q_x;    /* Q, CSC, internal order            */
  int *k_p, *k_i;                 /* pattern of M plus the diagonal    */
  const int *e_p, *e_i;           /* E (descriptor; not owned), NULL   */
  const double *e_x;
  double *kex, emax;              /* E's values in the k pattern, max  */
  /* The factored matrix (order nf, pattern f_p/f_i in its own numbering:
     internal index fidx[c] for column c): K itself (na = 0, f_p = k_p), or
     the Schur complement of the condensed block (manual 8.12). */
  int nf, na;
  int *f_p, *f_i, *f_d;           /* pattern; f_d[c]: diagonal entry   */
  int *fidx, *bpos;               /* bpos[v]: f index, or -1 - a index */
  int *aidx;                      /* condensed states (internal index) */
  int *ad_k;                      /* Mx index of K(a, a)               */
  int *ca_p, *ca_i, *ca_k;        /* column a of K: rows, Mx indices   */
  int *ra_p, *ra_i, *ra_k;        /* row a of K: columns, Mx indices   */
  int *perm;                      /* fill position k: internal perm[k] */
  int *cperm;                     /* factored column j = column cperm[j] of K (NULL: identity) */
  int nsup;
  int *sfirst, *sparent, *scp, *sch, *srp, *srow; /* sch[scp[s]..scp[s+1]): children, last first */
  size_t *lptr;                   /* factor offsets (scalars)          */
  int *amp, *ami;                 /* assembly: entries of supernode s  */
  size_t *amd;                    /*   and their offsets in its front  */
  size_t front_max, stack_max, nnz_lu;
  double flops;
} phgmg__spsym;

PHGMG__PRIV void phgmg__spsym_free(const phgmg_allocator *al, phgmg__spsym *S) {
  if (!S) return;
  phgmg__free(al, S->jr_p); phgmg__free(al, S->jr_i); phgmg__free(al, S->jr_x);
  phgmg__free(al, S->q_p); phgmg__free(al, S->q_i); phgmg__free(al, S->q_x);
  phgmg__free(al, S->kex);
  if (S->f_p != S->k_p) { phgmg__free(al, S->f_p); phgmg__free(al, S->f_i); }
  phgmg__free(al, S->k_p); phgmg__free(al, S->k_i); phgmg__free(al, S->perm); phgmg__free(al, S->cperm);
  phgmg__free(al, S->f_d); phgmg__free(al, S->fidx); phgmg__free(al, S->bpos);
  phgmg__free(al, S->aidx); phgmg__free(al, S->ad_k);
  phgmg__free(al, S->ca_p); phgmg__free(al, S->ca_i); phgmg__free(al, S->ca_k);
  phgmg__free(al, S->ra_p); phgmg__free(al, S->ra_i); phgmg__free(al, S->ra_k);
  phgmg__free(al, S->sfirst); phgmg__free(al, S->sparent); phgmg__free(al, S->scp); phgmg__free(al, S->sch);
  phgmg__free(al, S->srp); phgmg__free(al, S->srow); phgmg__free(al, S->lptr);
  phgmg__free(al, S->amp); phgmg__free(al, S->ami); phgmg__free(al, S->amd);
  phgmg__free(al, S);
}

/* Sort n ints increasingly (heapsort: no libc qsort, O(n log n)). */
PHGMG__PRIV void phgmg__isort(int *a, size_t n) {
  size_t i, end;
  if (n < 2) return;
  for (i = n / 2; i-- > 0;) {
    size_t r = i;
    for (;;) {
      size_t c = 2 * r + 1;
      int t;
      if (c >= n) break;
      if (c + 1 < n && a[c + 1] > a[c]) ++c;
      if (a[r] >= a[c]) break;
      t = a[r]; a[r] = a[c]; a[c] = t; r = c;
    }
  }
  for (end = n - 1; end > 0; --end) {
    size_t r = 0;
    int t = a[0]; a[0] = a[end]; a[end] = t;
    for (;;) {
      size_t c = 2 * r + 1;
      if (c >= end) break;
      if (c + 1 < end && a[c + 1] > a[c]) ++c;
      if (a[r] >= a[c]) break;
      t = a[r]; a[r] = a[c]; a[c] = t; r = c;
    }
  }
}

/* CSC of M1 - M2 (M2 may be NULL) from band storage (kb), the nonzero
   entries only. */
PHGMG__PRIV phgmg_result phgmg__band_to_csc(int n, int kb, const double *M1, const double *M2, int **pp,
                                            int **pi, double **px, const phgmg_allocator *al) {
  int j, i, pass;
  size_t nz = 0;
  *pp = phgmg__ialloc(al, (size_t)n + 1);
  if (!*pp) return PHGMG_ERR_NOMEM;
  for (pass = 0; pass < 2; ++pass) {
    nz = 0;
    for (j = 0; j < n; ++j) {
      if (pass) (*pp)[j] = (int)nz;
      for (i = PHGMG__MAX(0, j - kb); i <= PHGMG__MIN(n - 1, j + kb); ++i) {
        size_t k = PHGMG__PHB(kb, i, j);
        double v = M1[k] - (M2 ? M2[k] : 0.0);
        if (v == 0.0) continue;
        if (pass) { (*pi)[nz] = i; (*px)[nz] = v; }
        ++nz;
      }
    }
    if (!pass) {
      *pi = phgmg__ialloc(al, nz + 1);
      *px = phgmg__dalloc(al, nz + 1);
      if (!*pi || !*px) return PHGMG_ERR_NOMEM;
    }
  }
  (*pp)[n] = (int)nz;
  return PHGMG_OK;
}

/* Pattern of M = (J - R) Q plus (J - R) plus the diagonal (and E's pattern
   for a descriptor model), CSC, sorted rows; with a column permutation
   (S->cperm) of K P: column j from column cperm[j] of M and E, plus (j, j). */
PHGMG__PRIV phgmg_result phgmg__spsym_kpattern(phgmg__spsym *S, const phgmg_allocator *al) {
  int n = S->n, j, p, q, nz = 0, pass;
  int *mark = phgmg__ialloc(al, (size_t)n);
  if (!mark) return PHGMG_ERR_NOMEM;
  S->k_p = phgmg__ialloc(al, (size_t)n + 1);
  if (!S->k_p) { phgmg__free(al, mark); return PHGMG_ERR_NOMEM; }
  for (pass = 0; pass < 2; ++pass) {
    for (j = 0; j < n; ++j) mark[j] = -1;
    nz = 0;
    for (j = 0; j < n; ++j) {
      const int c = S->cperm ? S->cperm[j] : j; /* column c of K (manual 8.12: column permutation) */
      int start = nz;
      if (pass) S->k_p[j] = nz;
#define PHGMG__KP_ADD(r) do { int r_ = (r); if (mark[r_] != j) { mark[r_] = j; if (pass) S->k_i[nz] = r_; ++nz; } } while (0)
      PHGMG__KP_ADD(j);
      for (p = S->jr_p[c]; p < S->jr_p[c + 1]; ++p) PHGMG__KP_ADD(S->jr_i[p]);
      if (S->e_p) for (p = S->e_p[c]; p < S->e_p[c + 1]; ++p) PHGMG__KP_ADD(S->e_i[p]);
      for (q = S->q_p[c]; q < S->q_p[c + 1]; ++q) {
        int k = S->q_i[q];
        for (p = S->jr_p[k]; p < S->jr_p[k + 1]; ++p) PHGMG__KP_ADD(S->jr_i[p]);
      }
#undef PHGMG__KP_ADD
      if (pass) phgmg__isort(S->k_i + start, (size_t)(nz - start));
    }
    if (!pass) {
      S->k_i = phgmg__ialloc(al, (size_t)nz);
      if (!S->k_i) { phgmg__free(al, mark); return PHGMG_ERR_NOMEM; }
    }
  }
  S->k_p[n] = nz;
  phgmg__free(al, mark);
  return PHGMG_OK;
}

/* Descriptor: E's values scattered into the k pattern (S->kex), their
   largest magnitude (S->emax). */
PHGMG__PRIV phgmg_result phgmg__spsym_kex(phgmg__spsym *S, const phgmg_allocator *al) {
  int j, p, q;
  S->kex = phgmg__dalloc(al, (size_t)S->k_p[S->n] + 1);
  if (!S->kex) return PHGMG_ERR_NOMEM;
  S->emax = 0.0;
  for (j = 0; j < S->n; ++j) {
    const int c = S->cperm ? S->cperm[j] : j;
    q = S->k_p[j];
    for (p = q; p < S->k_p[j + 1]; ++p) S->kex[p] = 0.0;
    for (p = S->e_p[c]; p < S->e_p[c + 1]; ++p) { /* both columns sorted */
      while (S->k_i[q] < S->e_i[p]) ++q;
      S->kex[q] += S->e_x[p];
      S->emax = PHGMG__MAX(S->emax, fabs(S->e_x[p]));
    }
  }
  return PHGMG_OK;
}

/* Symmetrised adjacency (CSR, no diagonal) of an n x n CSC pattern. */
PHGMG__PRIV phgmg_result phgmg__spsym_graph(int n, const int *kp, const int *ki, int **gp, int **gi,
                                            const phgmg_allocator *al) {
  int j, p, *cnt = phgmg__ialloc(al, (size_t)n + 1), *mark = phgmg__ialloc(al, (size_t)n);
  size_t nz = 0;
  *gp = NULL; *gi = NULL;
  if (!cnt || !mark) { phgmg__free(al, cnt); phgmg__free(al, mark); return PHGMG_ERR_NOMEM; }
  for (j = 0; j <= n; ++j) cnt[j] = 0;
  for (j = 0; j < n; ++j)
    for (p = kp[j]; p < kp[j + 1]; ++p)
      if (ki[p] != j) { cnt[ki[p]]++; cnt[j]++; }
  *gp = phgmg__ialloc(al, (size_t)n + 1);
  for (j = 0; j < n; ++j) nz += (size_t)cnt[j];
  *gi = phgmg__ialloc(al, nz + 1);
  if (!*gp || !*gi) { phgmg__free(al, cnt); phgmg__free(al, mark); return PHGMG_ERR_NOMEM; }
  (*gp)[0] = 0;
  for (j = 0; j < n; ++j) { (*gp)[j + 1] = (*gp)[j] + cnt[j]; cnt[j] = (*gp)[j]; }
  for (j = 0; j < n; ++j)
    for (p = kp[j]; p < kp[j + 1]; ++p) {
      int r = ki[p];
      if (r == j) continue;
      (*gi)[cnt[r]++] = j;
      (*gi)[cnt[j]++] = r;
    }
  /* remove duplicates (an entry present in both triangles) */
  for (j = 0; j < n; ++j) mark[j] = -1;
  nz = 0;
  for (j = 0; j < n; ++j) {
    int s = (*gp)[j], e = (*gp)[j + 1];
    (*gp)[j] = (int)nz;
    for (p = s; p < e; ++p) {
      int r = (*gi)[p];
      if (mark[r] == j) continue;
      mark[r] = j;
      (*gi)[nz++] = r;
    }
  }
  (*gp)[n] = (int)nz;
  phgmg__free(al, cnt);
  phgmg__free(al, mark);
  return PHGMG_OK;
}

/* Column counts of L (off-diagonal) from the row subtrees, O(nnz(L)). */
PHGMG__PRIV void phgmg__colcounts(int n, const int *ap, const int *ai, const int *perm, const int *iperm,
                                  const int *parent, int *cnt, int *mark) {
  int i, p;
  for (i = 0; i < n; ++i) { cnt[i] = 0; mark[i] = -1; }
  for (i = 0; i < n; ++i) {
    int v = perm[i];
    mark[i] = i;
    for (p = ap[v]; p < ap[v + 1]; ++p) {
      int k = iperm[ai[p]];
      if (k >= i) continue;
      while (mark[k] != i) { cnt[k]++; mark[k] = i; k = parent[k]; }
    }
  }
}

/* Relaxed supernodes: column j joins j+1's... built from the front: a chain
   j -> parent j+1 joins when j is the only child of j+1 and the counts nest
   (fundamental), or when the merged block stays small (at most
   PHGMG__SP_RELAX columns and extra zeros below a fifth of its entries). */
#define PHGMG__SP_RELAX 16

/* Supernode partition, tree and row structures (fill order). */
PHGMG__PRIV phgmg_result phgmg__spsym_supernodes(phgmg__spsym *S, const int *ap, const int *ai,
                                                 const int *iperm, const int *parent, const int *cnt,
                                                 const phgmg_allocator *al) {
  int n = S->nf, j, s, p, ns = 0;
  int *nch = phgmg__ialloc(al, (size_t)n), *sof = phgmg__ialloc(al, (size_t)n);
  int *mark = phgmg__ialloc(al, (size_t)n);
  size_t cap = 0, nz = 0, zeros = 0;
  phgmg_result rc = PHGMG_OK;
  S->sfirst = phgmg__ialloc(al, (size_t)n + 1);
  if (!nch || !sof || !mark || !S->sfirst) { rc = PHGMG_ERR_NOMEM; goto done; }
  for (j = 0; j < n; ++j) nch[j] = 0;
  for (j = 0; j < n; ++j) if (parent[j] >= 0) nch[parent[j]]++;
  for (j = 0; j < n; ++j) {
    int join = 0;
    if (j > 0 && parent[j - 1] == j && nch[j] == 1) {
      int f = S->sfirst[ns - 1], nc = j - f;  /* current supernode f..j-1 */
      if (cnt[j - 1] == cnt[j] + 1) join = 1;  /* fundamental */
      else if (nc + 1 <= PHGMG__SP_RELAX) {
        /* extra zeros: columns f..j-1 padded to the structure of j */
        size_t extra = (size_t)nc * (size_t)(cnt[j] + 1 > cnt[j - 1] ? cnt[j] + 1 - cnt[j - 1] : 0);
        size_t tot = (size_t)(nc + 1) * (size_t)(cnt[j] + 1 + nc);
        join = 5 * (zeros + extra) < tot;
        if (join) zeros += extra;
      }
    }
    if (!join) { S->sfirst[ns++] = j; zeros = 0; }
    sof[j] = ns - 1;
  }
  S->sfirst[ns] = n;
  S->nsup = ns;
  S->sparent = phgmg__ialloc(al, (size_t)ns);
  S->scp = phgmg__ialloc(al, (size_t)ns + 1);
  S->sch = phgmg__ialloc(al, (size_t)ns + 1);
  S->srp = phgmg__ialloc(al, (size_t)ns + 1);
  S->lptr = PHGMG__CAST(size_t *, phgmg__alloc(al, sizeof(size_t) * ((size_t)ns + 1)));
  if (!S->sparent || !S->scp || !S->sch || !S->srp || !S->lptr) { rc = PHGMG_ERR_NOMEM; goto done; }
  for (s = 0; s < ns; ++s) {
    int l = S->sfirst[s + 1] - 1;
    S->sparent[s] = parent[l] >= 0 ? sof[parent[l]] : -1;
    for (j = S->sfirst[s]; j <= l; ++j) cap += (size_t)cnt[j];
  }
  for (s = 0; s <= ns; ++s) S->scp[s] = 0;
  for (s = 0; s < ns; ++s) if (S->sparent[s] >= 0) S->scp[S->sparent[s] + 1]++;
  for (s = 0; s < ns; ++s) S->scp[s + 1] += S->scp[s];
  for (s = 0; s < ns; ++s) mark[s] = S->scp[s];
  for (s = ns - 1; s >= 0; --s) if (S->sparent[s] >= 0) S->sch[mark[S->sparent[s]]++] = s;
  S->srow = phgmg__ialloc(al, cap + 1);
  if (!S->srow) { rc = PHGMG_ERR_NOMEM; goto done; }
  /* rows of s: the entries below its block of its own columns and of its
     children's structures (children come first in the postorder) */
  for (j = 0; j < n; ++j) mark[j] = -1;
  {
    int *clist = nch; /* reuse: children lists by head/next over supernodes */
    int *head = sof;  /* sof no longer needed after sparent */
    for (s = 0; s < ns; ++s) head[s] = -1;
    for (s = ns - 1; s >= 0; --s)
      if (S->sparent[s] >= 0) { clist[s] = head[S->sparent[s]]; head[S->sparent[s]] = s; }
    for (s = 0; s < ns; ++s) {
      int f = S->sfirst[s], l = S->sfirst[s + 1] - 1, c;
      size_t start = nz;
      S->srp[s] = (int)nz;
      for (j = f; j <= l; ++j) {
        int v = S->perm[j];
        for (p = ap[v]; p < ap[v + 1]; ++p) {
          int r = iperm[ai[p]];
          if (r > l && mark[r] != s) { mark[r] = s; S->srow[nz++] = r; }
        }
      }
      for (c = head[s]; c != -1; c = clist[c]) {
        int q;
        for (q = S->srp[c]; q < S->srp[c + 1]; ++q) {
          int r = S->srow[q];
          if (r > l && mark[r] != s) { mark[r] = s; S->srow[nz++] = r; }
        }
      }
      phgmg__isort(S->srow + start, nz - start);
      S->srp[s + 1] = (int)nz;
    }
  }
  S->srp[ns] = (int)nz;
  /* factor offsets, front and stack sizes (push/pop in postorder), flops */
  {
    size_t off = 0, stack = 0, smax = 0, fmax = 0;
    double fl = 0.0;
    for (s = 0; s < ns; ++s) {
      size_t nc = (size_t)(S->sfirst[s + 1] - S->sfirst[s]), nr = (size_t)(S->srp[s + 1] - S->srp[s]);
      size_t nf = nc + nr;
      int c;
      S->lptr[s] = off;
      off += nc * nf + nc * nr;
      if (nf * nf > fmax) fmax = nf * nf;
      fl += (double)nc * (double)nc * (double)nf + 2.0 * (double)nc * (double)nr * (double)(nr + nc);
      for (c = S->scp[s]; c < S->scp[s + 1]; ++c) {
        size_t cn = (size_t)(S->srp[S->sch[c] + 1] - S->srp[S->sch[c]]);
        stack -= cn * cn;
      }
      stack += nr * nr;
      if (stack > smax) smax = stack;
    }
    S->lptr[ns] = off;
    S->nnz_lu = off;
    S->front_max = fmax;
    S->stack_max = smax;
    S->flops = fl;
  }
done:
  phgmg__free(al, nch); phgmg__free(al, sof); phgmg__free(al, mark);
  return rc;
}

/* Assembly map: each entry of K goes to the front of the supernode of
   min(row, column) (fill order), at its (row, column) position there. */
PHGMG__PRIV phgmg_result phgmg__spsym_assembly(phgmg__spsym *S, const int *iperm, const phgmg_allocator *al) {
  int n = S->nf, ns = S->nsup, j, p, s;
  int nz = S->f_p[n];
  int *sof = phgmg__ialloc(al, (size_t)n), *pos = phgmg__ialloc(al, (size_t)n), *fill;
  S->amp = phgmg__ialloc(al, (size_t)ns + 1);
  S->ami = phgmg__ialloc(al, (size_t)nz);
  S->amd = PHGMG__CAST(size_t *, phgmg__alloc(al, sizeof(size_t) * (size_t)nz));
  fill = phgmg__ialloc(al, (size_t)ns + 1);
  if (!sof || !pos || !S->amp || !S->ami || !S->amd || !fill) {
    phgmg__free(al, sof); phgmg__free(al, pos); phgmg__free(al, fill);
    return PHGMG_ERR_NOMEM;
  }
  for (s = 0; s < ns; ++s)
    for (j = S->sfirst[s]; j < S->sfirst[s + 1]; ++j) sof[j] = s;
  for (s = 0; s <= ns; ++s) S->amp[s] = 0;
  for (j = 0; j < n; ++j)
    for (p = S->f_p[j]; p < S->f_p[j + 1]; ++p) {
      int a = iperm[S->f_i[p]], b = iperm[j];
      S->amp[sof[a < b ? a : b] + 1]++;
    }
  for (s = 0; s < ns; ++s) S->amp[s + 1] += S->amp[s];
  for (s = 0; s < ns; ++s) fill[s] = S->amp[s];
  for (j = 0; j < n; ++j)
    for (p = S->f_p[j]; p < S->f_p[j + 1]; ++p) {
      int a = iperm[S->f_i[p]], b = iperm[j];
      S->ami[fill[sof[a < b ? a : b]]++] = p;
    }
  for (s = 0; s < ns; ++s) {
    int f = S->sfirst[s], nc = S->sfirst[s + 1] - f, q, nf = nc + S->srp[s + 1] - S->srp[s];
    for (q = 0; q < nc; ++q) pos[f + q] = q;
    for (q = S->srp[s]; q < S->srp[s + 1]; ++q) pos[S->srow[q]] = nc + q - S->srp[s];
    for (q = S->amp[s]; q < S->amp[s + 1]; ++q) {
      int e = S->ami[q], col = -1, a, b;
      /* column of entry e: binary search in k_p */
      int lo = 0, hi = n;
      while (hi - lo > 1) { int mid = (lo + hi) / 2; if (S->f_p[mid] <= e) lo = mid; else hi = mid; }
      col = lo;
      a = iperm[S->f_i[e]];
      b = iperm[col];
      S->amd[q] = (size_t)pos[a] + (size_t)pos[b] * (size_t)nf;
    }
  }
  phgmg__free(al, sof); phgmg__free(al, pos); phgmg__free(al, fill);
  return PHGMG_OK;
}

/* States condensed first (manual 8.12): an independent set of the graph
   of K (no two joined, so K's block on them is diagonal), taken greedily in
   breadth-first order (on a bipartite graph, such as positions and momenta
   of a mechanical model, one whole side), only states of degree at most
   PHGMG__SP_CONDENSE_DEG. Sets na, aidx, bpos, fidx, nf. */
#define PHGMG__SP_CONDENSE_DEG 32
PHGMG__PRIV phgmg_result phgmg__sp_condense_select(phgmg__spsym *S, const int *gp, const int *gi,
                                                   const phgmg_allocator *al) {
  int n = S->n, v, head = 0, tail = 0, r, p;
  int *q = phgmg__ialloc(al, (size_t)n), *st = phgmg__ialloc(al, (size_t)n);
  phgmg_result rc = PHGMG_ERR_NOMEM;
  S->na = 0; S->nf = 0;
  S->aidx = phgmg__ialloc(al, (size_t)n + 1);
  S->fidx = phgmg__ialloc(al, (size_t)n + 1);
  S->bpos = phgmg__ialloc(al, (size_t)n + 1);
  if (!q || !st || !S->aidx || !S->fidx || !S->bpos) goto done;
  for (v = 0; v < n; ++v) st[v] = 0; /* 0 unseen, 1 queued, 2 chosen, 3 blocked */
  for (v = 0; S->e_p && v < n; ++v) /* E (E P) couples v to another state: not condensed (real couplings) */
    for (p = S->e_p[S->cperm ? S->cperm[v] : v]; p < S->e_p[(S->cperm ? S->cperm[v] : v) + 1]; ++p)
      if (S->e_i[p] != v && S->e_x[p] != 0.0) { st[v] = st[S->e_i[p]] = 4; }
  for (r = 0; r < n; ++r) {
    if (st[r]) continue;
    st[r] = 1; q[tail++] = r;
    while (head < tail) {
      int u = q[head++], free_ = gp[u + 1] - gp[u] <= PHGMG__SP_CONDENSE_DEG;
      for (p = gp[u]; p < gp[u + 1] && free_; ++p) if (st[gi[p]] == 2) free_ = 0;
      st[u] = free_ ? 2 : 3;
      for (p = gp[u]; p < gp[u + 1]; ++p) if (!st[gi[p]]) { st[gi[p]] = 1; q[tail++] = gi[p]; }
    }
  }
  for (v = 0; v < n; ++v) {
    if (st[v] == 2) { S->bpos[v] = -1 - S->na; S->aidx[S->na++] = v; }
    else { S->bpos[v] = S->nf; S->fidx[S->nf++] = v; }
  }
  rc = PHGMG_OK;
done:
  phgmg__free(al, q); phgmg__free(al, st);
  return rc;
}

/* The condensed block's couplings (column a and row a of K outside the
   diagonal, K(a, a)) and the pattern of the Schur complement
   K_bb - K_ba K_aa^{-1} K_ab (f_p/f_i, sorted columns). */
PHGMG__PRIV phgmg_result phgmg__sp_condense_pattern(phgmg__spsym *S, const phgmg_allocator *al) {
  const int n = S->n, na = S->na, nf = S->nf;
  int t, j, p, q, pass, nz = 0, *mark = phgmg__ialloc(al, (size_t)n + 1);
  S->ad_k = phgmg__ialloc(al, (size_t)na + 1);
  S->ca_p = phgmg__ialloc(al, (size_t)na + 1);
  S->ra_p = phgmg__ialloc(al, (size_t)na + 1);
  S->f_p = phgmg__ialloc(al, (size_t)nf + 1);
  if (!mark || !S->ad_k || !S->ca_p || !S->ra_p || !S->f_p) { phgmg__free(al, mark); return PHGMG_ERR_NOMEM; }
  for (t = 0; t <= na; ++t) { S->ca_p[t] = 0; S->ra_p[t] = 0; }
  for (j = 0; j < n; ++j)
    for (p = S->k_p[j]; p < S->k_p[j + 1]; ++p) {
      int r = S->k_i[p];
      if (r == j) { if (S->bpos[j] < 0) S->ad_k[-1 - S->bpos[j]] = p; }
      else if (S->bpos[j] < 0) S->ca_p[-S->bpos[j]]++;   /* column a */
      else if (S->bpos[r] < 0) S->ra_p[-S->bpos[r]]++;   /* row a    */
    }
  for (t = 0; t < na; ++t) { S->ca_p[t + 1] += S->ca_p[t]; S->ra_p[t + 1] += S->ra_p[t]; }
  S->ca_i = phgmg__ialloc(al, (size_t)S->ca_p[na] + 1);
  S->ca_k = phgmg__ialloc(al, (size_t)S->ca_p[na] + 1);
  S->ra_i = phgmg__ialloc(al, (size_t)S->ra_p[na] + 1);
  S->ra_k = phgmg__ialloc(al, (size_t)S->ra_p[na] + 1);
  if (!S->ca_i || !S->ca_k || !S->ra_i || !S->ra_k) { phgmg__free(al, mark); return PHGMG_ERR_NOMEM; }
  for (t = 0; t < na; ++t) mark[t] = S->ra_p[t];
  for (j = 0; j < n; ++j)
    for (p = S->k_p[j]; p < S->k_p[j + 1]; ++p) {
      int r = S->k_i[p];
      if (r != j && S->bpos[j] >= 0 && S->bpos[r] < 0) {
        t = -1 - S->bpos[r];
        S->ra_i[mark[t]] = j; S->ra_k[mark[t]++] = p;
      }
    }
  for (t = 0; t < na; ++t) {
    int v = S->aidx[t], e = S->ca_p[t];
    for (p = S->k_p[v]; p < S->k_p[v + 1]; ++p)
      if (S->k_i[p] != v) { S->ca_i[e] = S->k_i[p]; S->ca_k[e++] = p; }
  }
  for (pass = 0; pass < 2; ++pass) {
    for (j = 0; j < nf; ++j) mark[j] = -1;
    nz = 0;
    for (j = 0; j < nf; ++j) {
      int v = S->fidx[j], start = nz;
      if (pass) S->f_p[j] = nz;
#define PHGMG__SC_ADD(b) do { int b_ = (b); if (mark[b_] != j) { mark[b_] = j; if (pass) S->f_i[nz] = b_; ++nz; } } while (0)
      for (p = S->k_p[v]; p < S->k_p[v + 1]; ++p) {
        int r = S->k_i[p];
        if (S->bpos[r] >= 0) PHGMG__SC_ADD(S->bpos[r]);
        else for (t = -1 - S->bpos[r], q = S->ca_p[t]; q < S->ca_p[t + 1]; ++q) PHGMG__SC_ADD(S->bpos[S->ca_i[q]]);
      }
#undef PHGMG__SC_ADD
      if (pass) phgmg__isort(S->f_i + start, (size_t)(nz - start));
    }
    if (!pass) {
      S->f_i = phgmg__ialloc(al, (size_t)nz + 1);
      if (!S->f_i) { phgmg__free(al, mark); return PHGMG_ERR_NOMEM; }
    }
  }
  S->f_p[nf] = nz;
  phgmg__free(al, mark);
  return PHGMG_OK;
}

/* Fill-reducing order of a graph: nested dissection, postordered by its
   elimination tree; returns the predicted entries of L (off-diagonal) in
   *lnz. parent, w1..w3: n ints of scratch. */
PHGMG__PRIV phgmg_result phgmg__sp_order(int n, const int *gp, const int *gi, int *perm, double *lnz,
                                         int *iord, int *parent, int *w1, int *w2, int *w3,
                                         const phgmg_allocator *al) {
  int i, *order = phgmg__ialloc(al, (size_t)n + 1);
  phgmg_result rc;
  if (!order) return PHGMG_ERR_NOMEM;
  rc = phgmg__nd_order(n, gp, gi, order, al);
  if (rc == PHGMG_OK) {
    for (i = 0; i < n; ++i) iord[order[i]] = i;
    phgmg__etree(n, gp, gi, order, iord, parent, w1);
    phgmg__postorder(n, parent, w3, w1, w2, perm);
    for (i = 0; i < n; ++i) perm[i] = order[w3[i]];
    for (i = 0; i < n; ++i) iord[perm[i]] = i;
    phgmg__etree(n, gp, gi, perm, iord, parent, w1);
    phgmg__colcounts(n, gp, gi, perm, iord, parent, w2, w1);
    *lnz = 0.0;
    for (i = 0; i < n; ++i) *lnz += (double)w2[i];
  }
  phgmg__free(al, order);
  return rc;
}

/* Symbolic analysis of the stage matrices of a system in band storage
   (J, R, Q with half-bandwidth kb): K itself, or the Schur complement after
   condensing an independent set of states, whichever predicts the smaller
   factor (condensation: its couplings, twice, plus the diagonal).
   condense: -1 that choice, 0 never, 1 whenever a state can be condensed. */
PHGMG__PRIV phgmg_result phgmg__spsym_analyse(phgmg__spsym *S, int condense, const phgmg_allocator *al);
PHGMG__PRIV phgmg_result phgmg__spsym_create(phgmg__spsym **out, int n, int kb, const double *J,
                                             const double *R, const double *Q, int condense,
                                             const phgmg_allocator *al) {
  phgmg__spsym *S = PHGMG__CAST(phgmg__spsym *, phgmg__alloc(al, sizeof(phgmg__spsym)));
  phgmg_result rc;
  *out = NULL;
  if (!S) return PHGMG_ERR_NOMEM;
  memset(S, 0, sizeof *S);
  S->n = n;
  rc = phgmg__band_to_csc(n, kb, J, R, &S->jr_p, &S->jr_i, &S->jr_x, al);
  if (rc == PHGMG_OK) rc = phgmg__band_to_csc(n, kb, Q, NULL, &S->q_p, &S->q_i, &S->q_x, al);
  if (rc == PHGMG_OK) rc = phgmg__spsym_analyse(S, condense, al);
  if (rc != PHGMG_OK) { phgmg__spsym_free(al, S); return rc; }
  *out = S;
  return PHGMG_OK;
}

/* Steps 0-2 of the analysis (manual 8.12) of S with its J - R and Q set;
   on failure the caller frees S. */
PHGMG__PRIV phgmg_result phgmg__spsym_analyse(phgmg__spsym *S, int condense, const phgmg_allocator *al) {
  const int n = S->n;
  int *gp = NULL, *gi = NULL, *hp = NULL, *hi = NULL, *iord = NULL, *parent = NULL, *w1 = NULL,
      *w2 = NULL, *w3 = NULL, *perm2 = NULL, i;
  double lnz = 0.0, lnz2 = 0.0;
  phgmg_result rc = phgmg__spsym_kpattern(S, al);
  if (rc == PHGMG_OK && S->e_p) rc = phgmg__spsym_kex(S, al);
  if (rc == PHGMG_OK) rc = phgmg__spsym_graph(n, S->k_p, S->k_i, &gp, &gi, al);
  if (rc != PHGMG_OK) goto done;
  iord = phgmg__ialloc(al, (size_t)n);
  parent = phgmg__ialloc(al, (size_t)n);
  w1 = phgmg__ialloc(al, (size_t)n);
  w2 = phgmg__ialloc(al, (size_t)n);
  w3 = phgmg__ialloc(al, (size_t)n);
  S->perm = phgmg__ialloc(al, (size_t)n);
  perm2 = phgmg__ialloc(al, (size_t)n);
  if (!iord || !parent || !w1 || !w2 || !w3 || !S->perm || !perm2) { rc = PHGMG_ERR_NOMEM; goto done; }
  rc = phgmg__sp_order(n, gp, gi, S->perm, &lnz, iord, parent, w1, w2, w3, al);
  if (rc == PHGMG_OK) rc = phgmg__sp_condense_select(S, gp, gi, al);
  if (rc == PHGMG_OK && S->na > 0 && S->nf > 0 && condense) {
    rc = phgmg__sp_condense_pattern(S, al);
    if (rc == PHGMG_OK) rc = phgmg__spsym_graph(S->nf, S->f_p, S->f_i, &hp, &hi, al);
    if (rc == PHGMG_OK) rc = phgmg__sp_order(S->nf, hp, hi, perm2, &lnz2, iord, parent, w1, w2, w3, al);
    if (rc == PHGMG_OK) lnz2 += 0.5 * ((double)S->ca_p[S->na] + (double)S->ra_p[S->na]);
  }
  if (rc != PHGMG_OK) goto done;
  if (S->na > 0 && S->nf > 0 && condense && (lnz2 < lnz || condense > 0)) { /* condensed: the Schur complement */
    int *t = S->perm; S->perm = perm2; perm2 = t;
    phgmg__free(al, gp); phgmg__free(al, gi);
    gp = hp; gi = hi; hp = hi = NULL;
  } else { /* K itself */
    S->na = 0; S->nf = n;
    for (i = 0; i < n; ++i) { S->fidx[i] = i; S->bpos[i] = i; }
    if (S->f_p) { phgmg__free(al, S->f_p); phgmg__free(al, S->f_i); }
    S->f_p = S->k_p; S->f_i = S->k_i;
  }
  S->f_d = phgmg__ialloc(al, (size_t)S->nf + 1);
  if (!S->f_d) { rc = PHGMG_ERR_NOMEM; goto done; }
  for (i = 0; i < S->nf; ++i) {
    int p;
    for (p = S->f_p[i]; p < S->f_p[i + 1]; ++p) if (S->f_i[p] == i) S->f_d[i] = p;
  }
  for (i = 0; i < S->nf; ++i) iord[S->perm[i]] = i;
  phgmg__etree(S->nf, gp, gi, S->perm, iord, parent, w1);
  phgmg__colcounts(S->nf, gp, gi, S->perm, iord, parent, w2, w1);
  rc = phgmg__spsym_supernodes(S, gp, gi, iord, parent, w2, al);
  if (rc == PHGMG_OK) rc = phgmg__spsym_assembly(S, iord, al);
  if (rc == PHGMG_OK) {
    for (i = 0; i < S->nf; ++i) S->perm[i] = S->fidx[S->perm[i]]; /* solves: internal index */
    S->nnz_lu += (size_t)(S->ca_p && S->na ? S->ca_p[S->na] + S->ra_p[S->na] + S->na : 0);
  }
done:
  phgmg__free(al, gp); phgmg__free(al, gi); phgmg__free(al, hp); phgmg__free(al, hi);
  phgmg__free(al, iord); phgmg__free(al, parent); phgmg__free(al, w1); phgmg__free(al, w2);
  phgmg__free(al, w3); phgmg__free(al, perm2);
  return rc;
}

/* Memory of an analysis (bytes). */
PHGMG__PRIV double phgmg__spsym_bytes(const phgmg__spsym *S) {
  const double n = (double)S->n, nf = (double)S->nf, na = (double)S->na, I = (double)sizeof(int);
  double b = (2.0 * n + 2.0) * I + (double)(S->jr_p[S->n] + S->q_p[S->n]) * (I + sizeof(double));
  b += (double)S->k_p[S->n] * I + (n + 1.0) * I;
  if (S->f_p != S->k_p) b += (double)S->f_p[S->nf] * I + (nf + 1.0) * I;
  b += (4.0 * n + nf + 3.0 * na + (S->cperm ? n : 0.0)) * I;
  if (S->na) b += 2.0 * (double)(S->ca_p[S->na] + S->ra_p[S->na]) * I;
  b += (double)S->nsup * (6.0 * I + sizeof(size_t)) + (double)(S->srp ? S->srp[S->nsup] : 0) * I;
  if (S->amp) b += (double)S->amp[S->nsup] * (I + sizeof(size_t));
  return b;
}

/* Numeric factors of one stage matrix (real, or complex: interleaved pairs). */
typedef struct phgmg__spnum {
  int cplx, nstatic;   /* nstatic: pivots replaced (manual 8.12) */
  double *X, *front, *stack, *y, *t;
  double *Fx;          /* values of the factored matrix (f pattern)        */
  double *dinv, *cax, *rax; /* condensed block: 1 / K(a, a), its couplings */
  int *pos;
  double growth;
} phgmg__spnum;

PHGMG__PRIV void phgmg__spnum_free(const phgmg_allocator *al, phgmg__spnum *F) {
  phgmg__free(al, F->X); phgmg__free(al, F->front); phgmg__free(al, F->stack);
  phgmg__free(al, F->y); phgmg__free(al, F->pos); phgmg__free(al, F->t);
  phgmg__free(al, F->Fx); phgmg__free(al, F->dinv); phgmg__free(al, F->cax); phgmg__free(al, F->rax);
  F->X = F->front = F->stack = F->y = F->t = NULL;
  F->Fx = F->dinv = F->cax = F->rax = NULL;
  F->pos = NULL;
}

PHGMG__PRIV phgmg_result phgmg__spnum_alloc(const phgmg_allocator *al, const phgmg__spsym *S, int cplx,
                                            phgmg__spnum *F) {
  size_t w = cplx ? 2 : 1;
  memset(F, 0, sizeof *F);
  F->cplx = cplx;
  F->X = phgmg__dalloc(al, w * S->nnz_lu + 1);
  F->front = phgmg__dalloc(al, w * S->front_max + 1);
  F->stack = phgmg__dalloc(al, w * S->stack_max + 1);
  F->y = phgmg__dalloc(al, 2 * w * (size_t)S->n); /* y, then the solves' scratch */
  F->pos = phgmg__ialloc(al, (size_t)S->n);
  F->t = phgmg__dalloc(al, w * (size_t)S->n);
  F->Fx = phgmg__dalloc(al, w * (size_t)S->f_p[S->nf] + 1);
  F->dinv = phgmg__dalloc(al, w * (size_t)S->na + 1);
  F->cax = phgmg__dalloc(al, S->na ? (size_t)S->ca_p[S->na] + 1 : 1);
  F->rax = phgmg__dalloc(al, S->na ? (size_t)S->ra_p[S->na] + 1 : 1);
  if (!F->X || !F->front || !F->stack || !F->y || !F->pos || !F->t || !F->Fx || !F->dinv || !F->cax || !F->rax) {
    phgmg__spnum_free(al, F);
    return PHGMG_ERR_NOMEM;
  }
  { size_t i; for (i = 0; i < w * (size_t)S->n; ++i) F->t[i] = 0.0; }
  return PHGMG_OK;
}

/* y -= t x for complex t = tr + i ti, interleaved x, y (n entries). */
PHGMG__PRIV void phgmg__sp_zaxpy(int n, double tr, double ti, const double *x, double *y) {
  int i = 0;
#if defined(PHGMG__VEC4) && (defined(__clang__) || defined(__GNUC__))
  {
    const phgmg__v4 vr = {tr, tr, tr, tr}, vi = {-ti, ti, -ti, ti};
    for (; i + 2 <= n; i += 2) {
      phgmg__v4 xv, yv, xs;
      memcpy(&xv, x + 2 * i, sizeof xv);
      memcpy(&yv, y + 2 * i, sizeof yv);
#ifdef __clang__
      xs = __builtin_shufflevector(xv, xv, 1, 0, 3, 2);
#else
      {
        typedef long long phgmg__v4i __attribute__((vector_size(32)));
        const phgmg__v4i sw = {1, 0, 3, 2};
        xs = __builtin_shuffle(xv, sw);
      }
#endif
      yv -= vr * xv + vi * xs;
      memcpy(y + 2 * i, &yv, sizeof yv);
    }
  }
#endif
  for (; i < n; ++i) {
    double xr = x[2 * i], xi = x[2 * i + 1];
    y[2 * i] -= tr * xr - ti * xi;
    y[2 * i + 1] -= tr * xi + ti * xr;
  }
}

/* Dense partial LU of a front (nf x nf, ld nf), the first nc pivots on the
   diagonal; a pivot below tiny in magnitude is replaced by tiny (same sign)
   and counted. Real. */
PHGMG__PRIV int phgmg__front_lu(int nf, int nc, double *F, double tiny) {
  int k, i, j, nr = nf - nc, nrep = 0;
  for (k = 0; k < nc; ++k) {
    double *ck = F + (size_t)k * (size_t)nf, p = ck[k], inv;
    if (!(fabs(p) >= tiny)) { p = p < 0.0 ? -tiny : tiny; ck[k] = p; ++nrep; }
    inv = 1.0 / p;
    for (i = k + 1; i < nf; ++i) ck[i] *= inv;
    for (j = k + 1; j < nc; ++j) {
      double *cj = F + (size_t)j * (size_t)nf, f = cj[k];
      if (f != 0.0) phgmg__axpy(nf - k - 1, -f, ck + k + 1, cj + k + 1);
    }
  }
  if (nr > 0) {
    double *F12 = F + (size_t)nc * (size_t)nf;
    phgmg__trsm_llu(nc, nr, F, nf, F12, nf);
    phgmg_gemm('N', 'N', nr, nr, nc, -1.0, F + nc, nf, F12, nf, 1.0, F12 + nc, nf);
  }
  return nrep;
}

/* The same for complex fronts (pairs). */
PHGMG__PRIV int phgmg__front_zlu(int nf, int nc, double *F, double tiny) {
  int k, i, j, nrep = 0;
  size_t ld = 2 * (size_t)nf;
  for (k = 0; k < nc; ++k) {
    double *ck = F + (size_t)k * ld, pr = ck[2 * k], pi = ck[2 * k + 1], mag = hypot(pr, pi), ir, ii, d;
    if (!(mag >= tiny)) {
      if (mag > 0.0) { pr *= tiny / mag; pi *= tiny / mag; } else { pr = tiny; pi = 0.0; }
      ck[2 * k] = pr; ck[2 * k + 1] = pi; ++nrep;
    }
    d = pr * pr + pi * pi;
    ir = pr / d; ii = -pi / d;
    for (i = k + 1; i < nf; ++i) {
      double a = ck[2 * i], b = ck[2 * i + 1];
      ck[2 * i] = a * ir - b * ii;
      ck[2 * i + 1] = a * ii + b * ir;
    }
    for (j = k + 1; j < nc; ++j) {
      double *cj = F + (size_t)j * ld, fr = cj[2 * k], fi = cj[2 * k + 1];
      if (fr == 0.0 && fi == 0.0) continue;
      phgmg__sp_zaxpy(nf - k - 1, fr, fi, ck + 2 * (k + 1), cj + 2 * (k + 1));
    }
  }
  if (nf > nc) { /* U12 = L11^{-1} F12, F22 -= L21 U12 */
    double *F12 = F + (size_t)nc * ld;
    phgmg__ztrsm_llu(nc, nf - nc, F, nf, F12, nf);
    phgmg__zgemm_acc(nf - nc, nf - nc, nc, -1.0, F + 2 * nc, nf, F12, nf, F12 + 2 * nc, nf);
  }
  return nrep;
}

/* Values of the factored matrix into F->Fx: K = shift I + M (shift E + M for
   a descriptor model: S->kex) itself, or the
   Schur complement K_bb - K_ba K_aa^{-1} K_ab (F->dinv = 1 / K(a, a), the
   couplings copied for the solves). A pivot K(a, a) below tiny is counted in
   F->nstatic. Returns the largest |K_ba(:, a) / K(a, a)|. */
PHGMG__PRIV double phgmg__sp_fvalues(const phgmg__spsym *S, phgmg__spnum *F, const double *Mx, double sr,
                                     double si, double tiny) {
  const int nf = S->nf, w = F->cplx ? 2 : 1;
  int t, c, p, q;
  double *x = F->t, lmax = 0.0;
  for (t = 0; t < S->na; ++t) { /* (a descriptor's E is diagonal in the condensed rows and columns) */
    const double e = S->kex ? S->kex[S->ad_k[t]] : 1.0;
    double dr = Mx[S->ad_k[t]] + sr * e, di = w == 2 ? si * e : 0.0, m = hypot(dr, di), d2, cm = 0.0;
    if (!(m >= tiny)) ++F->nstatic;
    d2 = dr * dr + di * di;
    F->dinv[w * t] = dr / d2;
    if (w == 2) F->dinv[2 * t + 1] = -di / d2;
    for (q = S->ca_p[t]; q < S->ca_p[t + 1]; ++q) { F->cax[q] = Mx[S->ca_k[q]]; cm = PHGMG__MAX(cm, fabs(F->cax[q])); }
    for (q = S->ra_p[t]; q < S->ra_p[t + 1]; ++q) F->rax[q] = Mx[S->ra_k[q]];
    lmax = PHGMG__MAX(lmax, cm / m);
  }
  for (c = 0; c < nf; ++c) {
    int v = S->fidx[c];
    for (p = S->k_p[v]; p < S->k_p[v + 1]; ++p) {
      int b = S->bpos[S->k_i[p]];
      if (b >= 0) {
        x[w * b] += Mx[p] + (S->kex ? sr * S->kex[p] : 0.0);
        if (w == 2 && S->kex) x[w * b + 1] += si * S->kex[p];
        continue;
      }
      t = -1 - b;
      { /* x_b -= K_ba(:, a) K(a, a)^{-1} K(a, c) */
        double gr = Mx[p] * F->dinv[w * t], gi = w == 2 ? Mx[p] * F->dinv[2 * t + 1] : 0.0;
        for (q = S->ca_p[t]; q < S->ca_p[t + 1]; ++q) {
          int r = S->bpos[S->ca_i[q]];
          x[w * r] -= F->cax[q] * gr;
          if (w == 2) x[2 * r + 1] -= F->cax[q] * gi;
        }
      }
    }
    if (!S->kex) { x[w * c] += sr; if (w == 2) x[2 * c + 1] += si; } /* shift sigma I */
    for (p = S->f_p[c]; p < S->f_p[c + 1]; ++p) {
      int r = S->f_i[p];
      F->Fx[w * p] = x[w * r]; x[w * r] = 0.0;
      if (w == 2) { F->Fx[2 * p + 1] = x[2 * r + 1]; x[2 * r + 1] = 0.0; }
    }
  }
  return lmax;
}

/* Numeric factorization of K = shift I + M (M values in S's k pattern, shift
   = sr + i si for complex factors), of its Schur complement when S condenses
   a block. tiny: the static-pivot threshold relative to max |K|. Fills
   F->X; F->nstatic counts replaced pivots; F->growth = max |factor entry| /
   max |K entry|. */
PHGMG__PRIV void phgmg__sp_factor(const phgmg__spsym *S, phgmg__spnum *F, const double *Mx, double sr,
                                  double si, double tiny) {
  const int ns = S->nsup, w = F->cplx ? 2 : 1;
  int s, q;
  size_t top = 0;
  double kmax = 0.0, fmax = 0.0;
  F->nstatic = 0;
  for (q = 0; q < S->k_p[S->n]; ++q) kmax = PHGMG__MAX(kmax, fabs(Mx[q]));
  kmax = PHGMG__MAX(kmax, hypot(sr, si) * (S->kex ? S->emax : 1.0));
  tiny *= kmax;
  fmax = phgmg__sp_fvalues(S, F, Mx, sr, si, tiny);
  for (s = 0; s < ns; ++s) {
    int f = S->sfirst[s], nc = S->sfirst[s + 1] - f, nr = S->srp[s + 1] - S->srp[s], nf = nc + nr, i, j;
    const int *rows = S->srow + S->srp[s];
    double *Fr = F->front;
    size_t len = (size_t)w * (size_t)nf * (size_t)nf, e;
    for (e = 0; e < len; ++e) Fr[e] = 0.0;
    if (w == 1)
      for (q = S->amp[s]; q < S->amp[s + 1]; ++q) Fr[S->amd[q]] += F->Fx[S->ami[q]];
    else
      for (q = S->amp[s]; q < S->amp[s + 1]; ++q) {
        Fr[2 * S->amd[q]] += F->Fx[2 * (size_t)S->ami[q]];
        Fr[2 * S->amd[q] + 1] += F->Fx[2 * (size_t)S->ami[q] + 1];
      }
    /* extend-add of the children's update matrices (top of the stack) */
    for (j = 0; j < nc; ++j) F->pos[f + j] = j;
    for (j = 0; j < nr; ++j) F->pos[rows[j]] = nc + j;
    for (q = S->scp[s]; q < S->scp[s + 1]; ++q) {
      int t = S->sch[q], cn = S->srp[t + 1] - S->srp[t], a, b;
      const int *cr = S->srow + S->srp[t];
      const double *U;
      top -= (size_t)w * (size_t)cn * (size_t)cn;
      U = F->stack + top;
      for (b = 0; b < cn; ++b) {
        size_t cb = (size_t)F->pos[cr[b]] * (size_t)nf;
        const double *ub = U + (size_t)w * (size_t)b * (size_t)cn;
        if (w == 1)
          for (a = 0; a < cn; ++a) Fr[cb + (size_t)F->pos[cr[a]]] += ub[a];
        else
          for (a = 0; a < cn; ++a) {
            size_t o = 2 * (cb + (size_t)F->pos[cr[a]]);
            Fr[o] += ub[2 * a];
            Fr[o + 1] += ub[2 * a + 1];
          }
      }
    }
    F->nstatic += w == 1 ? phgmg__front_lu(nf, nc, Fr, tiny) : phgmg__front_zlu(nf, nc, Fr, tiny);
    /* store the panel (nf x nc) and U12 (nc x nr); push F22 */
    {
      double *L = F->X + (size_t)w * S->lptr[s], *Up = L + (size_t)w * (size_t)nf * (size_t)nc;
      size_t pl = (size_t)w * (size_t)nf * (size_t)nc;
      memcpy(L, Fr, sizeof(double) * pl);
      for (e = 0; e < pl; ++e) fmax = PHGMG__MAX(fmax, fabs(L[e]));
      for (j = 0; j < nr; ++j) {
        const double *src = Fr + (size_t)w * (size_t)(nc + j) * (size_t)nf;
        for (i = 0; i < nc; ++i) { /* U12 by rows: row i contiguous over the nr columns */
          size_t o = (size_t)w * ((size_t)i * (size_t)nr + (size_t)j);
          Up[o] = src[w * i];
          fmax = PHGMG__MAX(fmax, fabs(src[w * i]));
          if (w == 2) { Up[o + 1] = src[2 * i + 1]; fmax = PHGMG__MAX(fmax, fabs(src[2 * i + 1])); }
        }
        memcpy(F->stack + top + (size_t)w * (size_t)j * (size_t)nr, src + w * nc, sizeof(double) * (size_t)(w * nr));
      }
      top += (size_t)w * (size_t)nr * (size_t)nr;
    }
  }
  F->growth = kmax > 0.0 ? fmax / kmax : 0.0;
}

/* x <- K^{-1} x (x internal order; real N or complex 2N interleaved):
   per supernode the dense triangular block, its off-diagonal block through a
   contiguous buffer (one scatter or gather per supernode). */
PHGMG__PRIV void phgmg__sp_solve_f(const phgmg__spsym *S, const phgmg__spnum *F, double *x) {
  const int n = S->nf, ns = S->nsup, w = F->cplx ? 2 : 1;
  int s, i, j, k;
  double *y = F->y, *t = F->y + (size_t)w * (size_t)n;
  for (i = 0; i < n; ++i) {
    y[w * i] = x[w * S->perm[i]];
    if (w == 2) y[2 * i + 1] = x[2 * S->perm[i] + 1];
  }
  for (s = 0; s < ns; ++s) { /* forward: L, unit diagonal */
    int f = S->sfirst[s], nc = S->sfirst[s + 1] - f, nr = S->srp[s + 1] - S->srp[s], nf = nc + nr;
    const int *rows = S->srow + S->srp[s];
    const double *L = F->X + (size_t)w * S->lptr[s];
    double *yf = y + (size_t)w * (size_t)f;
    for (i = 0; i < w * nr; ++i) t[i] = 0.0;
    for (k = 0; k < nc; ++k) {
      const double *lk = L + (size_t)w * (size_t)k * (size_t)nf;
      if (w == 1) {
        double v = yf[k];
        if (v == 0.0) continue;
        phgmg__axpy(nc - k - 1, -v, lk + k + 1, yf + k + 1);
        phgmg__axpy(nr, v, lk + nc, t);
      } else {
        double vr = yf[2 * k], vi = yf[2 * k + 1];
        if (vr == 0.0 && vi == 0.0) continue;
        phgmg__sp_zaxpy(nc - k - 1, vr, vi, lk + 2 * (k + 1), yf + 2 * (k + 1));
        phgmg__sp_zaxpy(nr, -vr, -vi, lk + 2 * nc, t);
      }
    }
    if (w == 1) for (i = 0; i < nr; ++i) y[rows[i]] -= t[i];
    else for (i = 0; i < nr; ++i) { y[2 * rows[i]] -= t[2 * i]; y[2 * rows[i] + 1] -= t[2 * i + 1]; }
  }
  for (s = ns - 1; s >= 0; --s) { /* backward: U */
    int f = S->sfirst[s], nc = S->sfirst[s + 1] - f, nr = S->srp[s + 1] - S->srp[s], nf = nc + nr;
    const int *rows = S->srow + S->srp[s];
    const double *L = F->X + (size_t)w * S->lptr[s], *Up = L + (size_t)w * (size_t)nf * (size_t)nc;
    double *yf = y + (size_t)w * (size_t)f;
    if (w == 1) {
      for (j = 0; j < nr; ++j) t[j] = y[rows[j]];
      if (nr > 0) for (k = 0; k < nc; ++k) yf[k] -= phgmg__dot(nr, Up + (size_t)k * (size_t)nr, t);
      for (k = nc - 1; k >= 0; --k) {
        const double *lk = L + (size_t)k * (size_t)nf;
        double v = yf[k] / lk[k];
        yf[k] = v;
        if (v != 0.0) phgmg__axpy(k, -v, lk, yf);
      }
    } else {
      for (j = 0; j < nr; ++j) { t[2 * j] = y[2 * rows[j]]; t[2 * j + 1] = y[2 * rows[j] + 1]; }
      for (k = 0; k < nc && nr > 0; ++k) {
        const double *u = Up + 2 * (size_t)k * (size_t)nr;
        double sr = 0.0, si = 0.0, sr2 = 0.0, si2 = 0.0;
        for (j = 0; j < nr; ++j) {
          sr += u[2 * j] * t[2 * j]; sr2 += u[2 * j + 1] * t[2 * j + 1];
          si += u[2 * j] * t[2 * j + 1]; si2 += u[2 * j + 1] * t[2 * j];
        }
        yf[2 * k] -= sr - sr2;
        yf[2 * k + 1] -= si + si2;
      }
      for (k = nc - 1; k >= 0; --k) {
        const double *lk = L + 2 * (size_t)k * (size_t)nf;
        double ar = yf[2 * k], ai = yf[2 * k + 1], pr = lk[2 * k], pi = lk[2 * k + 1];
        double d = pr * pr + pi * pi, vr = (ar * pr + ai * pi) / d, vi = (ai * pr - ar * pi) / d;
        yf[2 * k] = vr;
        yf[2 * k + 1] = vi;
        if (vr != 0.0 || vi != 0.0) phgmg__sp_zaxpy(k, vr, vi, lk, yf);
      }
    }
  }
  for (i = 0; i < n; ++i) {
    x[w * S->perm[i]] = y[w * i];
    if (w == 2) x[2 * S->perm[i] + 1] = y[2 * i + 1];
  }
}

/* x <- P x: the solution y of (K P) y = b back to that of K x = b,
   x[cperm[j]] = y[j] (F's solve scratch). */
PHGMG__PRIV void phgmg__sp_unpermute(const phgmg__spsym *S, const phgmg__spnum *F, double *x) {
  const int w = F->cplx ? 2 : 1;
  int j;
  memcpy(F->y, x, sizeof(double) * (size_t)w * (size_t)S->n);
  for (j = 0; j < S->n; ++j) {
    x[w * S->cperm[j]] = F->y[w * j];
    if (w == 2) x[2 * S->cperm[j] + 1] = F->y[2 * j + 1];
  }
}

/* x <- K^{-1} x: with a condensed block, u_a = x_a / K(a, a), x_b -= K_ba u_a,
   the Schur complement's solve, x_a = u_a - K_ab x_b / K(a, a); with a
   column permutation the solve of K P, then x <- P x. */
PHGMG__PRIV void phgmg__sp_solve_k(const phgmg__spsym *S, const phgmg__spnum *F, double *x) {
  int t, q;
  if (F->cplx) {
    for (t = 0; t < S->na; ++t) {
      int v = S->aidx[t];
      double ar = x[2 * v], ai = x[2 * v + 1], dr = F->dinv[2 * t], di = F->dinv[2 * t + 1];
      double ur = ar * dr - ai * di, ui = ar * di + ai * dr;
      x[2 * v] = ur; x[2 * v + 1] = ui;
      for (q = S->ca_p[t]; q < S->ca_p[t + 1]; ++q) {
        int r = S->ca_i[q];
        x[2 * r] -= F->cax[q] * ur; x[2 * r + 1] -= F->cax[q] * ui;
      }
    }
    phgmg__sp_solve_f(S, F, x);
    for (t = 0; t < S->na; ++t) {
      int v = S->aidx[t];
      double sr = 0.0, si = 0.0, dr = F->dinv[2 * t], di = F->dinv[2 * t + 1];
      for (q = S->ra_p[t]; q < S->ra_p[t + 1]; ++q) {
        int c = S->ra_i[q];
        sr += F->rax[q] * x[2 * c]; si += F->rax[q] * x[2 * c + 1];
      }
      x[2 * v] -= sr * dr - si * di; x[2 * v + 1] -= sr * di + si * dr;
    }
  } else {
    for (t = 0; t < S->na; ++t) {
      int v = S->aidx[t];
      double u = x[v] * F->dinv[t];
      x[v] = u;
      for (q = S->ca_p[t]; q < S->ca_p[t + 1]; ++q) x[S->ca_i[q]] -= F->cax[q] * u;
    }
    phgmg__sp_solve_f(S, F, x);
    for (t = 0; t < S->na; ++t) {
      double sm = 0.0;
      for (q = S->ra_p[t]; q < S->ra_p[t + 1]; ++q) sm += F->rax[q] * x[S->ra_i[q]];
      x[S->aidx[t]] -= sm * F->dinv[t];
    }
  }
}
PHGMG__PRIV void phgmg__sp_solve(const phgmg__spsym *S, const phgmg__spnum *F, double *x) {
  phgmg__sp_solve_k(S, F, x);
  if (S->cperm) phgmg__sp_unpermute(S, F, x);
}

/* Values of M = -(J - R)(Q + diag(dd)) (dd may be NULL) in the k pattern
   (M P with a column permutation), with a dense scratch w (n). */
PHGMG__PRIV void phgmg__sp_stage_values(const phgmg__spsym *S, const double *dd, double *Mx, double *w) {
  int n = S->n, j, p, q;
  for (j = 0; j < n; ++j) w[j] = 0.0;
  for (j = 0; j < n; ++j) {
    const int c = S->cperm ? S->cperm[j] : j; /* column c of M */
    double dj = dd ? dd[c] : 0.0;
    for (q = S->q_p[c]; q < S->q_p[c + 1]; ++q) {
      int k = S->q_i[q];
      double v = S->q_x[q];
      for (p = S->jr_p[k]; p < S->jr_p[k + 1]; ++p) w[S->jr_i[p]] -= S->jr_x[p] * v;
    }
    if (dj != 0.0)
      for (p = S->jr_p[c]; p < S->jr_p[c + 1]; ++p) w[S->jr_i[p]] -= S->jr_x[p] * dj;
    for (p = S->k_p[j]; p < S->k_p[j + 1]; ++p) { Mx[p] = w[S->k_i[p]]; w[S->k_i[p]] = 0.0; }
  }
}

/* y = Q x (internal order, CSC). */
PHGMG__PRIV void phgmg__sp_qmv(const phgmg__spsym *S, const double *x, double *y) {
  int n = S->n, j, p;
  for (j = 0; j < n; ++j) y[j] = 0.0;
  for (j = 0; j < n; ++j) {
    double xj = x[j];
    if (xj == 0.0) continue;
    for (p = S->q_p[j]; p < S->q_p[j + 1]; ++p) y[S->q_i[p]] += S->q_x[p] * xj;
  }
}

/* Is the symmetric n x n CSC matrix A + shift I positive definite? Through
   the sparse LU of >>sparse (the stage matrix of J - R = -I, Q = A, sigma =
   shift): without row exchanges the LU pivots of a symmetric matrix are the
   D of its L D L^T, all positive exactly when it is definite (Sylvester),
   and for a definite matrix the elimination is stable. 1 yes, 0 no, 2
   undecided (a pivot replaced or large growth: the caller's band Cholesky
   decides), -1 out of memory. Memory: the sparse factor, not a band. */
PHGMG__PRIV int phgmg__sp_pd(int n, const int *cp, const int *ci, const double *cx, double shift,
                             const phgmg_allocator *al) {
  phgmg__spsym *S = PHGMG__CAST(phgmg__spsym *, phgmg__alloc(al, sizeof(phgmg__spsym)));
  phgmg__spnum F;
  double *Mx = NULL, *w = NULL;
  int j, p, t, nq = 0, ok = -1;
  memset(&F, 0, sizeof F);
  if (!S) return -1;
  memset(S, 0, sizeof *S);
  S->n = n;
  S->jr_p = phgmg__ialloc(al, (size_t)n + 1); S->jr_i = phgmg__ialloc(al, (size_t)n + 1);
  S->jr_x = phgmg__dalloc(al, (size_t)n + 1); S->q_p = phgmg__ialloc(al, (size_t)n + 1);
  S->q_i = phgmg__ialloc(al, (size_t)cp[n] + 1); S->q_x = phgmg__dalloc(al, (size_t)cp[n] + 1);
  if (!S->jr_p || !S->jr_i || !S->jr_x || !S->q_p || !S->q_i || !S->q_x) goto done;
  for (j = 0; j < n; ++j) {
    S->jr_p[j] = j; S->jr_i[j] = j; S->jr_x[j] = -1.0; S->q_p[j] = nq;
    for (p = cp[j]; p < cp[j + 1]; ++p)
      if (cx[p] != 0.0) { S->q_i[nq] = ci[p]; S->q_x[nq] = cx[p]; ++nq; }
  }
  S->jr_p[n] = n; S->q_p[n] = nq;
  if (phgmg__spsym_analyse(S, -1, al) != PHGMG_OK) goto done;
  Mx = phgmg__dalloc(al, (size_t)S->k_p[n] + 1);
  w = phgmg__dalloc(al, (size_t)n);
  if (!Mx || !w || phgmg__spnum_alloc(al, S, 0, &F) != PHGMG_OK) goto done;
  phgmg__sp_stage_values(S, NULL, Mx, w);   /* M = -(J - R) Q = A */
  phgmg__sp_factor(S, &F, Mx, shift, 0.0, PHGMG_SPARSE_PIVTOL);
  ok = F.nstatic || !(F.growth <= PHGMG_SPARSE_GROWTH) ? 2 : 1;
  for (t = 0; t < S->na && ok == 1; ++t)    /* condensed block: its diagonal */
    if (!(Mx[S->ad_k[t]] + shift > 0.0)) ok = 0;
  for (t = 0; t < S->nsup && ok == 1; ++t) { /* the pivots of each front */
    const int nc = S->sfirst[t + 1] - S->sfirst[t], nf = nc + S->srp[t + 1] - S->srp[t];
    const double *L = F.X + S->lptr[t];
    for (j = 0; j < nc; ++j)
      if (!(L[(size_t)j * (size_t)nf + (size_t)j] > 0.0)) { ok = 0; break; }
  }
done:
  phgmg__spnum_free(al, &F);
  phgmg__free(al, Mx);
  phgmg__free(al, w);
  phgmg__spsym_free(al, S);
  return ok;
}

/* ---- sparse input: CSC checks, reverse Cuthill-McKee, banded conversion ---- */

/* Structure of an nr x nc CSC matrix (see phgmg_csc). */
PHGMG__PRIV phgmg_result phgmg__csc_check(const phgmg_csc *A, int nr, int nc) {
  int j, p;
  if (!A || !A->colptr) return PHGMG_ERR_INVALID_ARG;
  if (A->n_rows != nr || A->n_cols != nc) return PHGMG_ERR_SIZE;
  if (A->colptr[0] != 0) return PHGMG_ERR_FORMAT;
  for (j = 0; j < nc; ++j)
    if (A->colptr[j + 1] < A->colptr[j]) return PHGMG_ERR_FORMAT;
  if (A->colptr[nc] > 0 && (!A->rowidx || !A->values)) return PHGMG_ERR_INVALID_ARG;
  for (j = 0; j < nc; ++j)
    for (p = A->colptr[j]; p < A->colptr[j + 1]; ++p) {
      int r = A->rowidx[p];
      if (r < 0 || r >= nr) return PHGMG_ERR_FORMAT;
      if (p > A->colptr[j] && r <= A->rowidx[p - 1]) return PHGMG_ERR_FORMAT; /* unsorted/duplicate */
    }
  return PHGMG_OK;
}

/* Half-bandwidth max |ip[r] - ip[c]| of the stored entries (ip NULL: identity). */
PHGMG__PRIV int phgmg__csc_bandwidth(const phgmg_csc *A, const int *ip) {
  int j, p, kb = 0;
  for (j = 0; j < A->n_cols; ++j)
    for (p = A->colptr[j]; p < A->colptr[j + 1]; ++p) {
      int r = A->rowidx[p], d = ip ? ip[r] - ip[j] : r - j;
      if (d < 0) d = -d;
      if (d > kb) kb = d;
    }
  return kb;
}

/* Symmetrized off-diagonal pattern of na N x N CSC matrices as adjacency lists
   (xadj N+1, adj), duplicates removed. */
PHGMG__PRIV phgmg_result phgmg__sym_graph(int N, int na, const phgmg_csc *const *A, int **xadj_out,
                                          int **adj_out, const phgmg_allocator *alloc) {
  int *xadj = phgmg__ialloc(alloc, (size_t)N + 1), *pos = phgmg__ialloc(alloc, (size_t)N + 1), *adj = NULL;
  size_t total = 0;
  int a, i, j, p, w;
  *xadj_out = *adj_out = NULL;
  if (!xadj || !pos) { phgmg__free(alloc, xadj); phgmg__free(alloc, pos); return PHGMG_ERR_NOMEM; }
  memset(xadj, 0, sizeof(int) * ((size_t)N + 1));
  for (a = 0; a < na; ++a)
    for (j = 0; j < N; ++j)
      for (p = A[a]->colptr[j]; p < A[a]->colptr[j + 1]; ++p)
        if (A[a]->rowidx[p] != j) { xadj[A[a]->rowidx[p] + 1]++; xadj[j + 1]++; total += 2; }
  if (total > (size_t)0x7ffffffe) { phgmg__free(alloc, xadj); phgmg__free(alloc, pos); return PHGMG_ERR_SIZE; }
  adj = phgmg__ialloc(alloc, total);
  if (!adj) { phgmg__free(alloc, xadj); phgmg__free(alloc, pos); return PHGMG_ERR_NOMEM; }
  for (i = 0; i < N; ++i) xadj[i + 1] += xadj[i];
  memcpy(pos, xadj, sizeof(int) * ((size_t)N + 1));
  for (a = 0; a < na; ++a)
    for (j = 0; j < N; ++j)
      for (p = A[a]->colptr[j]; p < A[a]->colptr[j + 1]; ++p) {
        int r = A[a]->rowidx[p];
        if (r != j) { adj[pos[r]++] = j; adj[pos[j]++] = r; }
      }
  /* remove duplicates in place: pos[] becomes the "last seen in list" mark */
  for (i = 0; i < N; ++i) pos[i] = -1;
  for (i = 0, w = 0; i < N; ++i) {
    int start = xadj[i], end = xadj[i + 1];
    xadj[i] = w;
    for (p = start; p < end; ++p)
      if (pos[adj[p]] != i) { pos[adj[p]] = i; adj[w++] = adj[p]; }
  }
  xadj[N] = w;
  phgmg__free(alloc, pos);
  *xadj_out = xadj;
  *adj_out = adj;
  return PHGMG_OK;
}

/* Sort q[0..n) by (deg, index): insertion sort for short runs, else heapsort. */
PHGMG__PRIV int phgmg__rcm_less(const int *deg, int a, int b) {
  return deg[a] < deg[b] || (deg[a] == deg[b] && a < b);
}
PHGMG__PRIV void phgmg__rcm_sift(int *q, int start, int n, const int *deg) {
  int root = start;
  while (2 * root + 1 < n) {
    int c = 2 * root + 1, t;
    if (c + 1 < n && phgmg__rcm_less(deg, q[c], q[c + 1])) ++c;
    if (!phgmg__rcm_less(deg, q[root], q[c])) return;
    t = q[root]; q[root] = q[c]; q[c] = t;
    root = c;
  }
}
PHGMG__PRIV void phgmg__rcm_sort(int *q, int n, const int *deg) {
  int i, j, t;
  if (n <= 32) {
    for (i = 1; i < n; ++i) {
      t = q[i];
      for (j = i; j > 0 && phgmg__rcm_less(deg, t, q[j - 1]); --j) q[j] = q[j - 1];
      q[j] = t;
    }
    return;
  }
  for (i = n / 2 - 1; i >= 0; --i) phgmg__rcm_sift(q, i, n, deg);
  for (i = n - 1; i > 0; --i) {
    t = q[0]; q[0] = q[i]; q[i] = t;
    phgmg__rcm_sift(q, 0, i, deg);
  }
}

/* Breadth-first search from root over nodes with level -1 (one component):
   q receives the nodes in visiting order (neighbours by increasing degree when
   sorted), level their distance from root. Returns the count; *nlev the
   number of levels. */
PHGMG__PRIV int phgmg__rcm_bfs(const int *xadj, const int *adj, const int *deg, int root, int *level,
                               int *q, int sorted, int *nlev) {
  int head = 0, tail = 1, p;
  q[0] = root;
  level[root] = 0;
  while (head < tail) {
    int u = q[head++], t0 = tail;
    for (p = xadj[u]; p < xadj[u + 1]; ++p)
      if (level[adj[p]] < 0) { level[adj[p]] = level[u] + 1; q[tail++] = adj[p]; }
    if (sorted) phgmg__rcm_sort(q + t0, tail - t0, deg);
  }
  *nlev = level[q[tail - 1]] + 1;
  return tail;
}

/* Pseudo-peripheral node of the component of start (George-Liu): repeat a
   search from a least-degree node of the last level while the depth grows. */
PHGMG__PRIV int phgmg__rcm_peripheral(const int *xadj, const int *adj, const int *deg, int start,
                                      int *level, int *q) {
  int root = start, nlev, cnt, it, i;
  cnt = phgmg__rcm_bfs(xadj, adj, deg, root, level, q, 0, &nlev);
  for (it = 0; it < 16; ++it) {
    int best = -1, nlev2, cnt2;
    for (i = cnt - 1; i >= 0 && level[q[i]] == nlev - 1; --i)
      if (best < 0 || phgmg__rcm_less(deg, q[i], best)) best = q[i];
    for (i = 0; i < cnt; ++i) level[q[i]] = -1;
    if (best < 0 || best == root) return root;
    cnt2 = phgmg__rcm_bfs(xadj, adj, deg, best, level, q, 0, &nlev2);
    if (nlev2 <= nlev) {
      for (i = 0; i < cnt2; ++i) level[q[i]] = -1;
      return root;
    }
    root = best;
    nlev = nlev2;
    cnt = cnt2;
  }
  for (i = 0; i < cnt; ++i) level[q[i]] = -1;
  return root;
}

PHGMG_DEF phgmg_result phgmg_rcm(int N, int na, const phgmg_csc *const *A, int *perm, int *kb_out,
                                 const phgmg_allocator *alloc) {
  int *xadj = NULL, *adj = NULL, *deg = NULL, *level = NULL, *q = NULL;
  int a, i, done = 0, kb = 0;
  phgmg_result rc;
  if (kb_out) *kb_out = 0;
  if (!A || !perm) return PHGMG_ERR_INVALID_ARG;
  if (N < 1 || na < 1) return PHGMG_ERR_SIZE;
  for (a = 0; a < na; ++a)
    if ((rc = phgmg__csc_check(A[a], N, N)) != PHGMG_OK) return rc;
  rc = phgmg__sym_graph(N, na, A, &xadj, &adj, alloc);
  if (rc != PHGMG_OK) return rc;
  deg = phgmg__ialloc(alloc, (size_t)N);
  level = phgmg__ialloc(alloc, (size_t)N);
  q = phgmg__ialloc(alloc, (size_t)N);
  if (!deg || !level || !q) rc = PHGMG_ERR_NOMEM;
  else {
    for (i = 0; i < N; ++i) { deg[i] = xadj[i + 1] - xadj[i]; level[i] = -1; }
    for (i = 0; i < N; ++i) {
      int root, nlev;
      if (level[i] >= 0) continue; /* numbered in an earlier component */
      root = phgmg__rcm_peripheral(xadj, adj, deg, i, level, q);
      done += phgmg__rcm_bfs(xadj, adj, deg, root, level, perm + done, 1, &nlev);
    }
    for (i = 0; i < N / 2; ++i) { int t = perm[i]; perm[i] = perm[N - 1 - i]; perm[N - 1 - i] = t; }
    for (i = 0; i < N; ++i) q[perm[i]] = i; /* inverse */
    for (a = 0; a < na; ++a) {
      int k = phgmg__csc_bandwidth(A[a], q);
      if (k > kb) kb = k;
    }
    if (kb_out) *kb_out = kb;
  }
  phgmg__free(alloc, xadj);
  phgmg__free(alloc, adj);
  phgmg__free(alloc, deg);
  phgmg__free(alloc, level);
  phgmg__free(alloc, q);
  return rc;
}

struct phgmg_ph_sparse {
  phgmg_ph_system sys;
  phgmg_allocator a;
  const phgmg_allocator *alloc; /* &a or NULL */
  int *perm, *iperm, *sep;
  double *J, *R, *Q, *B;
  double *E;   /* descriptor models: E's band copy (band LU only), else NULL */
  int *cp[4], *ci[4];           /* J, R, Q (and E) as CSC in the internal order */
  double *cx[4];                /*   (rows sorted; nnz + 1 values each; E: NULL without) */
  phgmg__spsym *sym;            /* sparse LU analysis (NULL: not done) */
  int use_lu;                   /* 1: steppers use the sparse LU       */
  phgmg_ph_sparse_info inf;
};

/* Column permutation for the static pivots of a descriptor model (manual
   8.12): a matching of rows to columns of E that maximises the product of
   the matched magnitudes (a weighted bipartite matching, as MC64 does):
   cost c(i, j) = log max_k |E(k, j)| - log |E(i, j)| >= 0 over the nonzero
   entries, duals u (rows) and v (columns) from the row and column minima, a
   greedy start on the edges of zero reduced cost, then one Dijkstra search
   of shortest augmenting paths per unmatched column (binary heap). The
   factored matrix is K P: its column j is column cperm[j] of K, so that
   E(j, cperm[j]) sits on its diagonal. For a symmetric positive definite E
   (a mass matrix) the identity is the unique optimum (|E(i, j)|^2 <
   E(i, i) E(j, j)); for one with its columns permuted, the inverse of that
   permutation. Returns 1 (a matching other than the identity, in cperm),
   0 (the identity is optimal, or E has no perfect matching: structurally
   singular; the static pivots then decide), -1 out of memory. */
typedef struct phgmg__mt {
  int n, *rmate, *cmate, *heap, *hpos, *pred, *done, nd;
  double *u, *v, *d;
} phgmg__mt;

PHGMG__PRIV void phgmg__mt_up(phgmg__mt *m, int k) {
  int r = m->heap[k];
  while (k > 0) {
    int p = (k - 1) / 2, q = m->heap[p];
    if (!(m->d[q] > m->d[r])) break;
    m->heap[k] = q; m->hpos[q] = k; k = p;
  }
  m->heap[k] = r; m->hpos[r] = k;
}
PHGMG__PRIV int phgmg__mt_pop(phgmg__mt *m, int *len) {
  int top = m->heap[0], r, k = 0;
  m->hpos[top] = -2;
  if (--*len == 0) return top;
  r = m->heap[*len];
  for (;;) {
    int c = 2 * k + 1;
    if (c >= *len) break;
    if (c + 1 < *len && m->d[m->heap[c + 1]] < m->d[m->heap[c]]) ++c;
    if (!(m->d[m->heap[c]] < m->d[r])) break;
    m->heap[k] = m->heap[c]; m->hpos[m->heap[k]] = k; k = c;
  }
  m->heap[k] = r; m->hpos[r] = k;
  return top;
}

/* One shortest augmenting path from the free column j0 (reduced costs
   c - u - v, w[p] = c of entry p); 1 augmented, 0 none. */
PHGMG__PRIV int phgmg__mt_augment(phgmg__mt *m, const int *cp, const int *ci, const double *w, int j0) {
  int len = 0, p, i, j, found = -1, t;
  double D = 0.0;
  m->nd = 0;
  for (j = j0;;) { /* relax the entries of column j, reached at distance dj */
    const double dj = j == j0 ? 0.0 : m->d[m->cmate[j]];
    for (p = cp[j]; p < cp[j + 1]; ++p) {
      double nd;
      i = ci[p];
      if (w[p] < 0.0 || m->hpos[i] == -2) continue;
      nd = dj + PHGMG__MAX(0.0, w[p] - m->u[i] - m->v[j]);
      if (m->hpos[i] == -1) { m->d[i] = nd; m->pred[i] = j; m->heap[len] = i; m->hpos[i] = len++; phgmg__mt_up(m, len - 1); }
      else if (nd < m->d[i]) { m->d[i] = nd; m->pred[i] = j; phgmg__mt_up(m, m->hpos[i]); }
    }
    if (len == 0) break;
    i = phgmg__mt_pop(m, &len);
    m->done[m->nd++] = i;
    if (m->rmate[i] < 0) { found = i; D = m->d[i]; break; }
    j = m->rmate[i];
  }
  for (t = 0; t < len; ++t) m->hpos[m->heap[t]] = -1;
  if (found < 0) { for (t = 0; t < m->nd; ++t) m->hpos[m->done[t]] = -1; return 0; }
  m->v[j0] += D;
  for (t = 0; t < m->nd; ++t) { /* duals: the path's edges tight, every reduced cost >= 0 */
    i = m->done[t];
    m->hpos[i] = -1;
    if (i == found) continue;
    m->u[i] -= D - m->d[i];
    m->v[m->rmate[i]] += D - m->d[i];
  }
  for (i = found; i >= 0;) { /* flip the path */
    j = m->pred[i];
    t = m->cmate[j];
    m->cmate[j] = i; m->rmate[i] = j;
    i = j == j0 ? -1 : t;
  }
  return 1;
}

PHGMG__PRIV int phgmg__sp_match(int n, const int *cp, const int *ci, const double *cx, int *cperm,
                                const phgmg_allocator *al) {
  phgmg__mt m;
  double *w = phgmg__dalloc(al, (size_t)cp[n] + 1);
  int i, j, p, ok = 1, ident = 1;
  memset(&m, 0, sizeof m);
  m.n = n;
  m.rmate = phgmg__ialloc(al, (size_t)n); m.cmate = phgmg__ialloc(al, (size_t)n);
  m.heap = phgmg__ialloc(al, (size_t)n); m.hpos = phgmg__ialloc(al, (size_t)n);
  m.pred = phgmg__ialloc(al, (size_t)n); m.done = phgmg__ialloc(al, (size_t)n);
  m.u = phgmg__dalloc(al, (size_t)n); m.v = phgmg__dalloc(al, (size_t)n); m.d = phgmg__dalloc(al, (size_t)n);
  if (!w || !m.rmate || !m.cmate || !m.heap || !m.hpos || !m.pred || !m.done || !m.u || !m.v || !m.d) {
    ok = -1;
    goto done;
  }
  for (i = 0; i < n; ++i) { m.rmate[i] = m.cmate[i] = -1; m.hpos[i] = -1; m.u[i] = HUGE_VAL; }
  for (j = 0; j < n; ++j) { /* costs (-1: no edge), row minima */
    double cm = 0.0;
    for (p = cp[j]; p < cp[j + 1]; ++p) cm = PHGMG__MAX(cm, fabs(cx[p]));
    for (p = cp[j]; p < cp[j + 1]; ++p) {
      w[p] = cx[p] != 0.0 ? log(cm) - log(fabs(cx[p])) : -1.0;
      if (w[p] >= 0.0 && w[p] < m.u[ci[p]]) m.u[ci[p]] = w[p];
    }
  }
  for (i = 0; i < n; ++i) if (m.u[i] == HUGE_VAL) { ok = 0; goto done; } /* a zero row */
  for (j = 0; j < n; ++j) { /* column duals, greedy matching on tight edges */
    double vm = HUGE_VAL;
    int best = -1;
    for (p = cp[j]; p < cp[j + 1]; ++p)
      if (w[p] >= 0.0 && w[p] - m.u[ci[p]] < vm) vm = w[p] - m.u[ci[p]];
    if (vm == HUGE_VAL) { ok = 0; goto done; } /* a zero column */
    m.v[j] = vm;
    for (p = cp[j]; p < cp[j + 1]; ++p)
      if (w[p] >= 0.0 && m.rmate[ci[p]] < 0 && w[p] - m.u[ci[p]] - vm <= 0.0 && (best < 0 || ci[p] == j)) best = ci[p];
    if (best >= 0) { m.rmate[best] = j; m.cmate[j] = best; }
  }
  for (j = 0; j < n && ok == 1; ++j)
    if (m.cmate[j] < 0 && !phgmg__mt_augment(&m, cp, ci, w, j)) ok = 0; /* structurally singular */
  for (i = 0; i < n && ok == 1; ++i) { cperm[i] = m.rmate[i]; if (cperm[i] != i) ident = 0; }
  if (ok == 1 && ident) ok = 0;
done:
  phgmg__free(al, w);
  phgmg__free(al, m.rmate); phgmg__free(al, m.cmate); phgmg__free(al, m.heap); phgmg__free(al, m.hpos);
  phgmg__free(al, m.pred); phgmg__free(al, m.done); phgmg__free(al, m.u); phgmg__free(al, m.v);
  phgmg__free(al, m.d);
  return ok;
}

/* The analysis of sp's stage matrices from its CSC copies (J - R merged,
   zero values dropped, as from band storage); condense as phgmg__spsym_create. */
PHGMG__PRIV phgmg_result phgmg__spsym_create_sp(phgmg__spsym **out, const phgmg_ph_sparse *sp, int condense) {
  const phgmg_allocator *al = sp->alloc;
  const int n = sp->sys.N;
  phgmg__spsym *S = PHGMG__CAST(phgmg__spsym *, phgmg__alloc(al, sizeof(phgmg__spsym)));
  phgmg_result rc = PHGMG_OK;
  int j, p, q, pass;
  *out = NULL;
  if (!S) return PHGMG_ERR_NOMEM;
  memset(S, 0, sizeof *S);
  S->n = n;
  S->e_p = sp->cp[3]; S->e_i = sp->ci[3]; S->e_x = sp->cx[3]; /* descriptor: NULL without E */
  S->jr_p = phgmg__ialloc(al, (size_t)n + 1);
  S->q_p = phgmg__ialloc(al, (size_t)n + 1);
  if (!S->jr_p || !S->q_p) rc = PHGMG_ERR_NOMEM;
  for (pass = 0; pass < 2 && rc == PHGMG_OK; ++pass) { /* count, then fill */
    int nz = 0, nq = 0;
    for (j = 0; j < n; ++j) {
      S->jr_p[j] = nz; S->q_p[j] = nq;
      p = sp->cp[0][j]; q = sp->cp[1][j];
      while (p < sp->cp[0][j + 1] || q < sp->cp[1][j + 1]) {
        int ip = p < sp->cp[0][j + 1] ? sp->ci[0][p] : n, iq = q < sp->cp[1][j + 1] ? sp->ci[1][q] : n;
        int i = PHGMG__MIN(ip, iq);
        double v = (ip == i ? sp->cx[0][p++] : 0.0) - (iq == i ? sp->cx[1][q++] : 0.0);
        if (v == 0.0) continue;
        if (pass) { S->jr_i[nz] = i; S->jr_x[nz] = v; }
        ++nz;
      }
      for (p = sp->cp[2][j]; p < sp->cp[2][j + 1]; ++p) {
        if (sp->cx[2][p] == 0.0) continue;
        if (pass) { S->q_i[nq] = sp->ci[2][p]; S->q_x[nq] = sp->cx[2][p]; }
        ++nq;
      }
    }
    S->jr_p[n] = nz; S->q_p[n] = nq;
    if (!pass) {
      S->jr_i = phgmg__ialloc(al, (size_t)nz + 1); S->jr_x = phgmg__dalloc(al, (size_t)nz + 1);
      S->q_i = phgmg__ialloc(al, (size_t)nq + 1); S->q_x = phgmg__dalloc(al, (size_t)nq + 1);
      if (!S->jr_i || !S->jr_x || !S->q_i || !S->q_x) rc = PHGMG_ERR_NOMEM;
    }
  }
  if (rc == PHGMG_OK && S->e_p) { /* descriptor: columns matched to E's largest entries */
    int r = (S->cperm = phgmg__ialloc(al, (size_t)n)) ? phgmg__sp_match(n, S->e_p, S->e_i, S->e_x, S->cperm, al) : -1;
    if (r < 0) rc = PHGMG_ERR_NOMEM;
    else if (r == 0) { phgmg__free(al, S->cperm); S->cperm = NULL; }
  }
  if (rc == PHGMG_OK) rc = phgmg__spsym_analyse(S, condense, al);
  if (rc != PHGMG_OK) { phgmg__spsym_free(al, S); return rc; }
  *out = S;
  return PHGMG_OK;
}

PHGMG_DEF void phgmg_ph_sparse_destroy(phgmg_ph_sparse *sp) {
  const phgmg_allocator *alloc;
  int a;
  if (!sp) return;
  alloc = sp->alloc;
  phgmg__free(alloc, sp->perm);
  phgmg__free(alloc, sp->iperm);
  phgmg__free(alloc, sp->sep);
  phgmg__free(alloc, sp->J);
  phgmg__free(alloc, sp->R);
  phgmg__free(alloc, sp->Q);
  phgmg__free(alloc, sp->B);
  phgmg__free(alloc, sp->E);
  for (a = 0; a < 4; ++a) {
    phgmg__free(alloc, sp->cp[a]); phgmg__free(alloc, sp->ci[a]); phgmg__free(alloc, sp->cx[a]);
  }
  phgmg__spsym_free(alloc, sp->sym);
  phgmg__free(alloc, sp);
}

/* CSC of P A P^T (ip: the inverse permutation, new index of each old one),
   rows sorted in each column; nnz + 1 values (a distinct array also when
   A has no entry). */
PHGMG__PRIV phgmg_result phgmg__csc_permuted(const phgmg_csc *A, const int *ip, int **pp, int **pi, double **px,
                                            const phgmg_allocator *al) {
  const int n = A->n_cols;
  const size_t nz = (size_t)A->colptr[n];
  int j, p, *cnt;
  *pp = phgmg__ialloc(al, (size_t)n + 1);
  *pi = phgmg__ialloc(al, nz + 1);
  *px = phgmg__dalloc(al, nz + 1);
  cnt = phgmg__ialloc(al, (size_t)n + 1);
  if (!*pp || !*pi || !*px || !cnt) { phgmg__free(al, cnt); return PHGMG_ERR_NOMEM; }
  for (j = 0; j <= n; ++j) cnt[j] = 0;
  for (j = 0; j < n; ++j) cnt[ip[j] + 1] = A->colptr[j + 1] - A->colptr[j];
  for (j = 0; j < n; ++j) cnt[j + 1] += cnt[j];
  memcpy(*pp, cnt, sizeof(int) * ((size_t)n + 1));
  for (j = 0; j < n; ++j) {
    int c = ip[j], q = cnt[c], k;
    for (p = A->colptr[j]; p < A->colptr[j + 1]; ++p, ++q) { (*pi)[q] = ip[A->rowidx[p]]; (*px)[q] = A->values[p]; }
    for (k = cnt[c] + 1; k < q; ++k) { /* insertion sort by row (columns are short) */
      int r = (*pi)[k], t = k;
      double v = (*px)[k];
      while (t > cnt[c] && (*pi)[t - 1] > r) { (*pi)[t] = (*pi)[t - 1]; (*px)[t] = (*px)[t - 1]; --t; }
      (*pi)[t] = r; (*px)[t] = v;
    }
  }
  (*px)[nz] = 0.0;
  phgmg__free(al, cnt);
  return PHGMG_OK;
}

/* Argument and data checks of phgmg_ph_sparse_create. */
PHGMG__PRIV phgmg_result phgmg__ph_sparse_check(int N, int m, const phgmg_csc *const *A, int na, const double *B,
                                                const phgmg_csc *Bcsc) {
  int a;
  phgmg_result rc;
  if (!A[0] || !A[1] || !A[2] || (!B && !Bcsc)) return PHGMG_ERR_INVALID_ARG;
  if (N < 1 || m < 1 || m > N) return PHGMG_ERR_SIZE;
  for (a = 0; a < na; ++a)
    if ((rc = phgmg__csc_check(A[a], N, N)) != PHGMG_OK) return rc;
  if (!B && (rc = phgmg__csc_check(Bcsc, N, m)) != PHGMG_OK) return rc;
  for (a = 0; a < na; ++a)
    if (!phgmg__all_finite(A[a]->values, (size_t)A[a]->colptr[N])) return PHGMG_ERR_NANINF;
  if (B ? !phgmg__all_finite(B, (size_t)N * (size_t)m)
        : !phgmg__all_finite(Bcsc->values, (size_t)Bcsc->colptr[m]))
    return PHGMG_ERR_NANINF;
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_ph_sparse_create(phgmg_ph_sparse **out, int N, int m, const phgmg_csc *J,
                                              const phgmg_csc *R, const phgmg_csc *Q, const double *B,
                                              const phgmg_csc *Bcsc, phgmg_ph_sparse_info *info,
                                              const phgmg_allocator *alloc) {
  return phgmg_ph_sparse_create_e(out, N, m, J, R, Q, NULL, B, Bcsc, info, alloc);
}

PHGMG_DEF phgmg_result phgmg_ph_sparse_create_desc(phgmg_ph_sparse **out, const phgmg_ph_sparse_desc *d,
                                                   phgmg_ph_sparse_info *info, const phgmg_allocator *alloc) {
  if (!d) {
    if (info) memset(info, 0, sizeof *info);
    if (out) *out = NULL;
    return PHGMG_ERR_INVALID_ARG;
  }
  return phgmg_ph_sparse_create_e(out, d->N, d->m, &d->J, &d->R, &d->Q, d->E.colptr ? &d->E : NULL,
                                  d->B, d->B ? NULL : &d->Bcsc, info, alloc);
}

PHGMG_DEF phgmg_result phgmg_ph_sparse_create_e(phgmg_ph_sparse **out, int N, int m, const phgmg_csc *J,
                                                const phgmg_csc *R, const phgmg_csc *Q, const phgmg_csc *E,
                                                const double *B, const phgmg_csc *Bcsc,
                                                phgmg_ph_sparse_info *info, const phgmg_allocator *alloc) {
  const phgmg_csc *A[4];
  const int na = E ? 4 : 3;
  phgmg_ph_sparse *sp;
  phgmg_result rc;
  int a, i, j, kb_in = 0, kb_rcm = 0, kb;
  A[0] = J; A[1] = R; A[2] = Q; A[3] = E;
  if (info) memset(info, 0, sizeof *info);
  if (!out) return PHGMG_ERR_INVALID_ARG;
  *out = NULL;
  if ((rc = phgmg__ph_sparse_check(N, m, A, na, B, Bcsc)) != PHGMG_OK) return rc;
  sp = PHGMG__CAST(phgmg_ph_sparse *, phgmg__alloc(alloc, sizeof *sp));
  if (!sp) return PHGMG_ERR_NOMEM;
  memset(sp, 0, sizeof *sp);
  if (alloc) { sp->a = *alloc; sp->alloc = &sp->a; }
  sp->perm = phgmg__ialloc(alloc, (size_t)N);
  sp->iperm = phgmg__ialloc(alloc, (size_t)N);
  if (!sp->perm || !sp->iperm) { phgmg_ph_sparse_destroy(sp); return PHGMG_ERR_NOMEM; }
  rc = phgmg_rcm(N, na, A, sp->perm, &kb_rcm, alloc);
  if (rc != PHGMG_OK) { phgmg_ph_sparse_destroy(sp); return rc; }
  for (a = 0; a < na; ++a) {
    int k = phgmg__csc_bandwidth(A[a], NULL);
    if (k > kb_in) kb_in = k;
  }
  if (kb_rcm >= kb_in)
    for (i = 0; i < N; ++i) sp->perm[i] = i;
  kb = kb_rcm < kb_in ? kb_rcm : kb_in;
  for (i = 0; i < N; ++i) sp->iperm[sp->perm[i]] = i;
  for (a = 0; a < na && rc == PHGMG_OK; ++a) /* J, R, Q (E) in the internal order: no band copy yet */
    rc = phgmg__csc_permuted(A[a], sp->iperm, &sp->cp[a], &sp->ci[a], &sp->cx[a], alloc);
  sp->B = phgmg__dalloc(alloc, (size_t)N * (size_t)m);
  if (rc != PHGMG_OK || !sp->B) { phgmg_ph_sparse_destroy(sp); return rc != PHGMG_OK ? rc : PHGMG_ERR_NOMEM; }
  if (B) {
    for (j = 0; j < m; ++j)
      for (i = 0; i < N; ++i) sp->B[i + (size_t)j * N] = B[sp->perm[i] + (size_t)j * N];
  } else {
    int p;
    memset(sp->B, 0, sizeof(double) * (size_t)N * (size_t)m);
    for (j = 0; j < m; ++j)
      for (p = Bcsc->colptr[j]; p < Bcsc->colptr[j + 1]; ++p)
        sp->B[sp->iperm[Bcsc->rowidx[p]] + (size_t)j * N] = Bcsc->values[p];
  }
  sp->sys.N = N;
  sp->sys.m = m;
  sp->sys.kb = kb;
  sp->sys.B = sp->B;
  sp->sys.nl = PHGMG_NL_NONE;
  sp->sys.sparse = sp;
  sp->inf.kb = kb;
  sp->inf.kb_input = kb_in;
  sp->inf.kb_rcm = kb_rcm;
  sp->inf.permuted = kb_rcm < kb_in;
  sp->inf.wide = 4 * (long)kb > (long)N;
  sp->inf.nnz = (long)J->colptr[N] + (long)R->colptr[N] + (long)Q->colptr[N] + (E ? (long)E->colptr[N] : 0L);
  rc = phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_AUTO, info);
  if (rc != PHGMG_OK) { phgmg_ph_sparse_destroy(sp); return rc; }
  *out = sp;
  return PHGMG_OK;
}

/* Stage-matrix bandwidths (lower, upper) from the nonzero diagonals of J - R
   and Q (and E), as the band stepper computes them (from the CSC copies). */
PHGMG__PRIV void phgmg__ph_sparse_stage_bw(const phgmg_ph_sparse *sp, int *kl, int *ku) {
  const int N = sp->sys.N;
  int j, p, q, amin = 0, amax = 0, bmin = 0, bmax = 0;
  for (j = 0; j < N; ++j) {
    p = sp->cp[0][j]; q = sp->cp[1][j];
    while (p < sp->cp[0][j + 1] || q < sp->cp[1][j + 1]) { /* J - R, merged */
      int ip = p < sp->cp[0][j + 1] ? sp->ci[0][p] : N, iq = q < sp->cp[1][j + 1] ? sp->ci[1][q] : N;
      int i = PHGMG__MIN(ip, iq), o = j - i;
      double v = (ip == i ? sp->cx[0][p++] : 0.0) - (iq == i ? sp->cx[1][q++] : 0.0);
      if (v != 0.0) { amin = PHGMG__MIN(amin, o); amax = PHGMG__MAX(amax, o); }
    }
    for (p = sp->cp[2][j]; p < sp->cp[2][j + 1]; ++p)
      if (sp->cx[2][p] != 0.0) { bmin = PHGMG__MIN(bmin, j - sp->ci[2][p]); bmax = PHGMG__MAX(bmax, j - sp->ci[2][p]); }
  }
  if (sp->cp[3]) { amin = PHGMG__MIN(amin, -bmin); amax = PHGMG__MAX(amax, -bmax); } /* E's main diagonal */
  for (j = 0; sp->cp[3] && j < N; ++j) /* descriptor: E's band joins that of (J - R) Q */
    for (p = sp->cp[3][j]; p < sp->cp[3][j + 1]; ++p)
      if (sp->cx[3][p] != 0.0) {
        amin = PHGMG__MIN(amin, j - sp->ci[3][p] - bmin);
        amax = PHGMG__MAX(amax, j - sp->ci[3][p] - bmax);
      }
  *kl = PHGMG__MIN(N - 1, -(amin + bmin));
  *ku = PHGMG__MIN(N - 1, amax + bmax);
}

/* A new band copy (the object's order and half-bandwidth) of the object's
   CSC copy a (0 J, 1 R, 2 Q, 3 E); NULL when out of memory. */
PHGMG__PRIV double *phgmg__sparse_band_copy(const phgmg_ph_sparse *sp, int a, const phgmg_allocator *al) {
  const int N = sp->sys.N, kb = sp->sys.kb;
  const size_t len = (size_t)(2 * kb + 1) * (size_t)N;
  double *b = phgmg__dalloc(al, len);
  int j, p;
  if (!b) return NULL;
  memset(b, 0, sizeof(double) * len);
  for (j = 0; j < N; ++j)
    for (p = sp->cp[a][j]; p < sp->cp[a][j + 1]; ++p) b[PHGMG__PHB(kb, sp->ci[a][p], j)] = sp->cx[a][p];
  return b;
}

/* Band copies of J, R, Q (and E) (the band solver's storage) from the CSC copies;
   drop = 1 frees them. */
PHGMG__PRIV phgmg_result phgmg__ph_sparse_band(phgmg_ph_sparse *sp, int drop) {
  double **dst[4];
  int a;
  dst[0] = &sp->J; dst[1] = &sp->R; dst[2] = &sp->Q; dst[3] = &sp->E;
  for (a = 0; a < (sp->cp[3] ? 4 : 3); ++a) {
    if (drop) { phgmg__free(sp->alloc, *dst[a]); *dst[a] = NULL; continue; }
    if (*dst[a]) continue;
    if (!(*dst[a] = phgmg__sparse_band_copy(sp, a, sp->alloc))) return PHGMG_ERR_NOMEM;
  }
  return PHGMG_OK;
}

/* The object's system in the storage of the chosen solver: SPARSE (the CSC
   copies; band copies freed) for the sparse LU, else BANDED (band copies
   made before), and info's memory figures. */
PHGMG__PRIV void phgmg__ph_sparse_storage(phgmg_ph_sparse *sp) {
  phgmg_ph_sparse_info *f = &sp->inf;
  double b;
  int a;
  if (sp->use_lu) phgmg__ph_sparse_band(sp, 1);
  sp->sys.storage = sp->use_lu ? PHGMG_SPARSE : PHGMG_BANDED;
  sp->sys.J = sp->use_lu ? sp->cx[0] : sp->J;
  sp->sys.R = sp->use_lu ? sp->cx[1] : sp->R;
  sp->sys.Q = sp->use_lu ? sp->cx[2] : sp->Q;
  sp->sys.E = !sp->cp[3] ? NULL : sp->use_lu ? sp->cx[3] : sp->E;
  f->band_copy = sp->J != NULL;
  b = (double)sizeof(double) * (double)sp->sys.N * (double)sp->sys.m + 2.0 * sizeof(int) * (double)sp->sys.N;
  for (a = 0; a < 4; ++a)
    if (sp->cp[a]) b += (double)(sizeof(int) + sizeof(double)) * (double)sp->cp[a][sp->sys.N];
  if (sp->J) b += 3.0 * sizeof(double) * (double)(2 * sp->sys.kb + 1) * (double)sp->sys.N;
  if (sp->E) b += sizeof(double) * (double)(2 * sp->sys.kb + 1) * (double)sp->sys.N;
  if (sp->sym) b += phgmg__spsym_bytes(sp->sym);
  f->bytes = b;
}

/* 1: no E, or every row and column of E holds a nonzero (no algebraic
   equation); 0: E has a zero row or column; -1: no memory. */
PHGMG__PRIV int phgmg__ph_sparse_e_regular(const phgmg_ph_sparse *sp) {
  phgmg_ph_system v = sp->sys; /* a SPARSE view: phgmg__e_zero_lines reads E's CSC copy */
  int *z, kr, kc;
  if (!sp->cp[3]) return 1;
  z = phgmg__ialloc(sp->alloc, 2 * (size_t)v.N);
  if (!z) return -1;
  v.storage = PHGMG_SPARSE; v.sparse = sp; v.E = sp->cx[3];
  phgmg__e_zero_lines(&v, z, z + v.N, &kr, &kc);
  phgmg__free(sp->alloc, z);
  return kr == 0 && kc == 0;
}

PHGMG_DEF phgmg_result phgmg_ph_sparse_set_solver(phgmg_ph_sparse *sp, int solver,
                                                  phgmg_ph_sparse_info *info) {
  phgmg_ph_sparse_info *f;
  const int N = sp ? sp->sys.N : 0;
  phgmg_result rc;
  int use, j;
  if (!sp || solver < PHGMG_SOLVER_AUTO || solver > PHGMG_SOLVER_SPARSE_LU) return PHGMG_ERR_INVALID_ARG;
  f = &sp->inf;
  phgmg__ph_sparse_stage_bw(sp, &f->kl, &f->ku);
  f->lu_band = (double)N * (double)(2 * f->kl + f->ku + 1);
  f->flops_band = 2.0 * (double)N * (double)f->kl * (double)(f->kl + f->ku + 1);
  if ((use = phgmg__ph_sparse_e_regular(sp)) < 0) return PHGMG_ERR_NOMEM;
  if (!use) { /* E with zero lines (index one, manual 1.8): the band path condenses them */
    if (solver == PHGMG_SOLVER_SPARSE_LU) return PHGMG_ERR_UNSUPPORTED;
    solver = PHGMG_SOLVER_BAND;
  }
  if (!sp->sym && solver != PHGMG_SOLVER_BAND && (solver == PHGMG_SOLVER_SPARSE_LU ||
                   (solver == PHGMG_SOLVER_AUTO && sp->sys.kb > PHGMG_SPARSE_MIN_KB))) {
    rc = phgmg__spsym_create_sp(&sp->sym, sp, -1);
    if (rc != PHGMG_OK) return rc;
  }
  if (sp->sym) {
    f->lu_sparse = (double)sp->sym->nnz_lu;
    f->flops_sparse = sp->sym->flops;
    f->supernodes = sp->sym->nsup;
    f->condensed = sp->sym->na;
    f->colperm = 0;
    for (j = 0; sp->sym->cperm && j < N; ++j) f->colperm += sp->sym->cperm[j] != j;
    { size_t fm = 0; while ((fm + 1) * (fm + 1) <= sp->sym->front_max) ++fm; f->front_max = (int)fm; }
  }
  if (solver == PHGMG_SOLVER_AUTO)
    use = sp->sym && 2.0 * f->lu_sparse < f->lu_band && f->flops_sparse < f->flops_band;
  else
    use = solver == PHGMG_SOLVER_SPARSE_LU;
  /* the band solver needs band copies: made first, nothing changes on failure */
  if (!use && (rc = phgmg__ph_sparse_band(sp, 0)) != PHGMG_OK) return rc;
  sp->use_lu = use;
  if (!sp->use_lu && sp->sym) { /* not used: give the memory back */
    phgmg__spsym_free(sp->alloc, sp->sym);
    sp->sym = NULL;
  }
  f->solver = sp->use_lu ? PHGMG_SOLVER_SPARSE_LU : PHGMG_SOLVER_BAND;
  phgmg__ph_sparse_storage(sp);
  if (info) *info = *f;
  return PHGMG_OK;
}

/* The CSC copy behind M (J, R, Q or E of a SPARSE system): 1 and its arrays,
   0 if M is none of them. */
PHGMG__PRIV int phgmg__ph_csc_of(const phgmg_ph_system *s, const double *M, const int **cp, const int **ci,
                                 const double **cx) {
  const phgmg_ph_sparse *sp = s->sparse;
  int a;
  if (s->storage != PHGMG_SPARSE || !sp) return 0;
  for (a = 0; a < 4; ++a)
    if (M && M == sp->cx[a]) { *cp = sp->cp[a]; *ci = sp->ci[a]; *cx = sp->cx[a]; return 1; }
  return 0;
}

/* y = M x through the CSC copy of a SPARSE system; 0: not handled. */
PHGMG__PRIV int phgmg__ph_sparse_mv(const phgmg_ph_system *s, const double *M, const double *x,
                                     double *y) {
  const int *cp, *ci;
  const double *cx;
  int j, p;
  if (!phgmg__ph_csc_of(s, M, &cp, &ci, &cx)) return 0;
  for (j = 0; j < s->N; ++j) y[j] = 0.0;
  for (j = 0; j < s->N; ++j) {
    double xj = x[j];
    if (xj == 0.0) continue;
    for (p = cp[j]; p < cp[j + 1]; ++p) y[ci[p]] += cx[p] * xj;
  }
  return 1;
}

/* The sparse analysis a stepper may use for sys (NULL: band). */
PHGMG__PRIV const phgmg__spsym *phgmg__ph_sparse_lu(const phgmg_ph_system *sys) {
  const phgmg_ph_sparse *sp = sys->sparse;
  if (!sp || !sp->use_lu || !sp->sym || sys->E != sp->cx[3] || sys->storage != PHGMG_SPARSE || sys->N != sp->sys.N ||
      sys->J != sp->cx[0] || sys->R != sp->cx[1] || sys->Q != sp->cx[2] || sys->nl == PHGMG_NL_GENERAL)
    return NULL;
  return sp->sym;
}

/* phgmg__ph_check's part for SPARSE storage: the object's own matrices, and
   only what the sparse path serves (see phgmg_ph_sparse_system). */
PHGMG__PRIV phgmg_result phgmg__ph_check_sparse(const phgmg_ph_system *s) {
  const phgmg_ph_sparse *sp = s->sparse;
  if (!sp || s->N != sp->sys.N || s->J != sp->cx[0] || s->R != sp->cx[1] || s->Q != sp->cx[2] ||
      s->E != sp->cx[3])
    return PHGMG_ERR_INVALID_ARG;
  if (s->ndamp || s->P || s->S || s->Nskew || s->nl == PHGMG_NL_GENERAL || s->shifted_factor)
    return PHGMG_ERR_UNSUPPORTED;
  return PHGMG_OK;
}

/* A BANDED system t holding matrix a1 (0 J, 1 R, 2 Q) of the SPARSE system
   s, and a2 (-1: none) too, in the reverse Cuthill-McKee order of their own
   pattern (perm: position i holds index perm[i]): the band solves and checks
   of one or two matrices need only their own bandwidth (J - R of a
   mass-spring model pairs each position with its momentum: kb = 1), not the
   model's. t's other matrices point at a1's band. */
PHGMG__PRIV phgmg_result phgmg__ph_sparse_own_band(const phgmg_ph_system *s, int a1, int a2, phgmg_ph_system *t,
                                                  double **bands, int **perm, const phgmg_allocator *al) {
  const phgmg_ph_sparse *sp = s->sparse;
  const int N = s->N, na = a2 >= 0 ? 2 : 1;
  phgmg_csc A[2];
  const phgmg_csc *Ap[2];
  const double **slot[3];
  int k, j, p, kb = 0, *ip;
  phgmg_result rc;
  *t = *s;
  t->storage = PHGMG_BANDED;
  t->sparse = NULL;
  t->J = t->R = t->Q = NULL;
  bands[0] = bands[1] = NULL;
  *perm = phgmg__ialloc(al, (size_t)N);
  ip = phgmg__ialloc(al, (size_t)N);
  if (!*perm || !ip) { phgmg__free(al, ip); return PHGMG_ERR_NOMEM; }
  for (k = 0; k < na; ++k) {
    int a = k ? a2 : a1;
    A[k].n_rows = A[k].n_cols = N;
    A[k].colptr = sp->cp[a]; A[k].rowidx = sp->ci[a]; A[k].values = sp->cx[a];
    Ap[k] = &A[k];
  }
  rc = phgmg_rcm(N, na, Ap, *perm, &kb, al);
  slot[0] = &t->J; slot[1] = &t->R; slot[2] = &t->Q;
  for (k = 0; k < na && rc == PHGMG_OK; ++k) {
    int a = k ? a2 : a1;
    const size_t len = (size_t)(2 * kb + 1) * (size_t)N;
    double *b = phgmg__dalloc(al, len);
    if (!b) { rc = PHGMG_ERR_NOMEM; break; }
    bands[k] = b;
    memset(b, 0, sizeof(double) * len);
    if (!k) for (j = 0; j < N; ++j) ip[(*perm)[j]] = j;
    for (j = 0; j < N; ++j)
      for (p = sp->cp[a][j]; p < sp->cp[a][j + 1]; ++p) b[PHGMG__PHB(kb, ip[sp->ci[a][p]], ip[j])] = sp->cx[a][p];
    *slot[a] = b;
    if (!k) t->J = t->R = t->Q = b, *slot[a] = b;
  }
  t->kb = kb;
  phgmg__free(al, ip);
  return rc;
}

/* A BANDED view t of the SPARSE descriptor system s (the object's order and
   half-bandwidth) with band copies of Q and E in bufs[0], bufs[1] (J and R
   point at Q's copy: for the checks and factors of E and E^T Q only). */
PHGMG__PRIV phgmg_result phgmg__ph_sparse_eq_band(const phgmg_ph_system *s, phgmg_ph_system *t, double **bufs,
                                                 const phgmg_allocator *al) {
  const phgmg_ph_sparse *sp = s->sparse;
  *t = *s;
  bufs[0] = bufs[1] = NULL;
  if (!(bufs[0] = phgmg__sparse_band_copy(sp, 2, al)) || !(bufs[1] = phgmg__sparse_band_copy(sp, 3, al)))
    return PHGMG_ERR_NOMEM;
  t->storage = PHGMG_BANDED;
  t->sparse = NULL;
  t->kb = sp->sys.kb;
  t->J = t->R = t->Q = bufs[0];
  t->E = bufs[1];
  return PHGMG_OK;
}

/* Frees what phgmg__ph_sparse_own_band allocated (perm may be NULL: kept). */
PHGMG__PRIV void phgmg__ph_own_band_free(phgmg_ph_system *t, double **bands, int *perm, const phgmg_allocator *al) {
  phgmg__free(al, bands[0]);
  phgmg__free(al, bands[1]);
  bands[0] = bands[1] = NULL;
  t->J = t->R = t->Q = NULL;
  phgmg__free(al, perm);
}

PHGMG_DEF const phgmg_ph_system *phgmg_ph_sparse_system(const phgmg_ph_sparse *sp) {
  return sp ? &sp->sys : NULL;
}
PHGMG_DEF const int *phgmg_ph_sparse_perm(const phgmg_ph_sparse *sp) { return sp ? sp->perm : NULL; }

PHGMG_DEF phgmg_result phgmg_ph_sparse_sep_idx(phgmg_ph_sparse *sp, int nsep, const int *sep_idx_user,
                                               int *idx_out, phgmg_ph_system *sys) {
  int k, *s;
  if (!sp || !sep_idx_user) return PHGMG_ERR_INVALID_ARG;
  if (nsep < 1) return PHGMG_ERR_SIZE;
  for (k = 0; k < nsep; ++k)
    if (sep_idx_user[k] < 0 || sep_idx_user[k] >= sp->sys.N) return PHGMG_ERR_SIZE;
  s = phgmg__ialloc(sp->alloc, (size_t)nsep);
  if (!s) return PHGMG_ERR_NOMEM;
  for (k = 0; k < nsep; ++k) s[k] = sp->iperm[sep_idx_user[k]];
  if (idx_out) memcpy(idx_out, s, sizeof(int) * (size_t)nsep);
  phgmg__free(sp->alloc, sp->sep);
  sp->sep = s;
  if (sys) { sys->nsep = nsep; sys->sep_idx = s; }
  return PHGMG_OK;
}

#include <stdint.h> /* uintptr_t: the overlap test of the orderings' row moves */

/* The two orderings' row moves: to_user = 0: Y[i] = X[perm[i]]; 1: Y[perm[i]]
   = X[i]. In place (X == Y, ldx == ldy) through one column of scratch;
   other overlaps are refused. */
PHGMG__PRIV phgmg_result phgmg__sparse_reorder(const phgmg_ph_sparse *sp, int ncols, const double *X, int ldx,
                                              double *Y, int ldy, int to_user) {
  const double *xc;
  double *tmp = NULL;
  uintptr_t x0, x1, y0, y1;
  int i, j, N;
  if (!sp || !X || !Y) return PHGMG_ERR_INVALID_ARG;
  N = sp->sys.N;
  if (ncols < 0 || ldx < N || ldy < N) return PHGMG_ERR_SIZE;
  if (ncols == 0) return PHGMG_OK;
  x0 = (uintptr_t)(const void *)X; x1 = x0 + ((size_t)(ncols - 1) * ldx + (size_t)N) * sizeof(double);
  y0 = (uintptr_t)(const void *)Y; y1 = y0 + ((size_t)(ncols - 1) * ldy + (size_t)N) * sizeof(double);
  if (x0 < y1 && y0 < x1) {
    if (x0 != y0 || ldx != ldy) return PHGMG_ERR_INVALID_ARG;
    tmp = phgmg__dalloc(sp->alloc, (size_t)N);
    if (!tmp) return PHGMG_ERR_NOMEM;
  }
  for (j = 0; j < ncols; ++j) {
    double *yc = Y + (size_t)j * ldy;
    xc = X + (size_t)j * ldx;
    if (tmp) { memcpy(tmp, xc, (size_t)N * sizeof(double)); xc = tmp; }
    if (to_user) for (i = 0; i < N; ++i) yc[sp->perm[i]] = xc[i];
    else for (i = 0; i < N; ++i) yc[i] = xc[sp->perm[i]];
  }
  phgmg__free(sp->alloc, tmp);
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_ph_sparse_to_banded_order(const phgmg_ph_sparse *sp, int ncols, const double *X,
                                                       int ldx, double *Y, int ldy) {
  return phgmg__sparse_reorder(sp, ncols, X, ldx, Y, ldy, 0);
}

PHGMG_DEF phgmg_result phgmg_ph_sparse_to_user_order(const phgmg_ph_sparse *sp, int ncols, const double *X,
                                                     int ldx, double *Y, int ldy) {
  return phgmg__sparse_reorder(sp, ncols, X, ldx, Y, ldy, 1);
}

/* >>gl3 (implementation) ================================================= */


/* Set entries with |v_i| < tau to zero (tau >= DBL_MIN: no subnormal is left;
   see manual 8.10). Four at a time: GCC -O2 vectorises this form
   (0.06 ns per entry on the bench machine, 4x the plain loop). */
PHGMG__PRIV void phgmg__flush_tiny(double *v, size_t n, double tau) {
  size_t i;
  for (i = 0; i + 4 <= n; i += 4) {
    double a0 = v[i], a1 = v[i + 1], a2 = v[i + 2], a3 = v[i + 3];
    v[i] = fabs(a0) < tau ? 0.0 : a0;
    v[i + 1] = fabs(a1) < tau ? 0.0 : a1;
    v[i + 2] = fabs(a2) < tau ? 0.0 : a2;
    v[i + 3] = fabs(a3) < tau ? 0.0 : a3;
  }
  for (; i < n; ++i) v[i] = fabs(v[i]) < tau ? 0.0 : v[i];
}

/* Flush v relative to its own largest entry: tau = max(DBL_MIN, REL ||v||_inf). */
PHGMG__PRIV void phgmg__flush_tiny_rel(double *v, size_t n) {
  double m0 = 0.0, m1 = 0.0, m2 = 0.0, m3 = 0.0;
  size_t i;
  for (i = 0; i + 4 <= n; i += 4) {
    double a0 = fabs(v[i]), a1 = fabs(v[i + 1]), a2 = fabs(v[i + 2]), a3 = fabs(v[i + 3]);
    m0 = a0 > m0 ? a0 : m0;
    m1 = a1 > m1 ? a1 : m1;
    m2 = a2 > m2 ? a2 : m2;
    m3 = a3 > m3 ? a3 : m3;
  }
  for (; i < n; ++i) m0 = fabs(v[i]) > m0 ? fabs(v[i]) : m0;
  m0 = PHGMG__MAX(PHGMG__MAX(m0, m1), PHGMG__MAX(m2, m3));
  phgmg__flush_tiny(v, n, PHGMG__MAX(PHGMG__DBL_MIN, PHGMG_GL3_FLUSH_REL * m0));
}

PHGMG_DEF void phgmg_gl3_coefficients(double c[3], double b[3], double A[9]) {
  const double s15 = sqrt(15.0);
  c[0] = 0.5 - s15 / 10.0;
  c[1] = 0.5;
  c[2] = 0.5 + s15 / 10.0;
  b[0] = 5.0 / 18.0;
  b[1] = 4.0 / 9.0;
  b[2] = 5.0 / 18.0;
  A[0] = 5.0 / 36.0;         A[1] = 2.0 / 9.0 - s15 / 15.0; A[2] = 5.0 / 36.0 - s15 / 30.0;
  A[3] = 5.0 / 36.0 + s15 / 24.0; A[4] = 2.0 / 9.0;       A[5] = 5.0 / 36.0 - s15 / 24.0;
  A[6] = 5.0 / 36.0 + s15 / 30.0; A[7] = 2.0 / 9.0 + s15 / 15.0; A[8] = 5.0 / 36.0;
}

/* Inverse of a row-major 3x3 matrix; 0 if singular. */
PHGMG__PRIV int phgmg__inv3(const double *M, double *Mi) {
  double c00 = M[4] * M[8] - M[5] * M[7], c01 = M[5] * M[6] - M[3] * M[8],
         c02 = M[3] * M[7] - M[4] * M[6];
  double det = M[0] * c00 + M[1] * c01 + M[2] * c02, r;
  if (det == 0.0) return 0;
  r = 1.0 / det;
  Mi[0] = c00 * r;
  Mi[1] = (M[2] * M[7] - M[1] * M[8]) * r;
  Mi[2] = (M[1] * M[5] - M[2] * M[4]) * r;
  Mi[3] = c01 * r;
  Mi[4] = (M[0] * M[8] - M[2] * M[6]) * r;
  Mi[5] = (M[2] * M[3] - M[0] * M[5]) * r;
  Mi[6] = c02 * r;
  Mi[7] = (M[1] * M[6] - M[0] * M[7]) * r;
  Mi[8] = (M[0] * M[4] - M[1] * M[3]) * r;
  return 1;
}

/* Diagonalisation of A^{-1}: A^{-1} T = T [[gam,0,0],[0,alp,bet],[0,-bet,alp]],
   i.e. gam is the real eigenvalue and alp +- i bet the complex pair (the roots
   of z^3 - 12 z^2 + 60 z - 120); T = [t1, Re v, Im v] with A^{-1} v = (alp+i bet) v.
   The eigenvectors are null vectors of A^{-1} - lambda I found as (bilinear)
   cross products of two of its rows. Row-major T, Ti. */
PHGMG__PRIV void phgmg__gl3_transform(const double A[9], double T[9], double Ti[9], double *gam,
                                      double *alp, double *bet) {
  double Ai[9], z = 3.6, p, q;
  int it, a, b, k, best;
  phgmg__inv3(A, Ai);
  for (it = 0; it < 50; ++it) { /* Newton on the cubic from the right of the real root */
    double f = ((z - 12.0) * z + 60.0) * z - 120.0, df = (3.0 * z - 24.0) * z + 60.0;
    double dz = f / df;
    z -= dz;
    if (fabs(dz) <= 1e-16 * z) break;
  }
  *gam = z;
  p = z - 12.0;           /* z^3 - 12z^2 + 60z - 120 = (z - gam)(z^2 + p z + q) */
  q = 120.0 / z;
  *alp = -0.5 * p;
  *bet = sqrt(q - 0.25 * p * p);
  { /* real eigenvector */
    double M[9], v[3] = {0, 0, 0}, bestn = -1.0;
    for (k = 0; k < 9; ++k) M[k] = Ai[k];
    M[0] -= z; M[4] -= z; M[8] -= z;
    for (best = 0; best < 3; ++best) {
      double cv[3], n2;
      a = best == 2 ? 1 : 0;
      b = best == 0 ? 1 : 2;
      cv[0] = M[a * 3 + 1] * M[b * 3 + 2] - M[a * 3 + 2] * M[b * 3 + 1];
      cv[1] = M[a * 3 + 2] * M[b * 3 + 0] - M[a * 3 + 0] * M[b * 3 + 2];
      cv[2] = M[a * 3 + 0] * M[b * 3 + 1] - M[a * 3 + 1] * M[b * 3 + 0];
      n2 = cv[0] * cv[0] + cv[1] * cv[1] + cv[2] * cv[2];
      if (n2 > bestn) { bestn = n2; v[0] = cv[0]; v[1] = cv[1]; v[2] = cv[2]; }
    }
    bestn = sqrt(bestn);
    for (k = 0; k < 3; ++k) T[k * 3 + 0] = v[k] / bestn;
  }
  { /* complex eigenvector for alp + i bet */
    double Mr[9], Mi[9], vr[3] = {0, 0, 0}, vi[3] = {0, 0, 0}, bestn = -1.0, sr, si, d;
    int kk;
    for (k = 0; k < 9; ++k) { Mr[k] = Ai[k]; Mi[k] = 0.0; }
    for (k = 0; k < 3; ++k) { Mr[k * 4] -= *alp; Mi[k * 4] = -*bet; }
    for (best = 0; best < 3; ++best) {
      double cr[3], ci[3], n2 = 0.0;
      int e;
      a = best == 2 ? 1 : 0;
      b = best == 0 ? 1 : 2;
      for (e = 0; e < 3; ++e) {
        int e1 = (e + 1) % 3, e2 = (e + 2) % 3;
        /* (ra x rb)_e = ra[e1] rb[e2] - ra[e2] rb[e1], complex, no conjugation */
        double xr = Mr[a * 3 + e1] * Mr[b * 3 + e2] - Mi[a * 3 + e1] * Mi[b * 3 + e2];
        double xi = Mr[a * 3 + e1] * Mi[b * 3 + e2] + Mi[a * 3 + e1] * Mr[b * 3 + e2];
        double yr = Mr[a * 3 + e2] * Mr[b * 3 + e1] - Mi[a * 3 + e2] * Mi[b * 3 + e1];
        double yi = Mr[a * 3 + e2] * Mi[b * 3 + e1] + Mi[a * 3 + e2] * Mr[b * 3 + e1];
        cr[e] = xr - yr;
        ci[e] = xi - yi;
        n2 += cr[e] * cr[e] + ci[e] * ci[e];
      }
      if (n2 > bestn) {
        bestn = n2;
        for (e = 0; e < 3; ++e) { vr[e] = cr[e]; vi[e] = ci[e]; }
      }
    }
    /* scale so that the largest component is real and 1 */
    kk = 0;
    for (k = 1; k < 3; ++k)
      if (vr[k] * vr[k] + vi[k] * vi[k] > vr[kk] * vr[kk] + vi[kk] * vi[kk]) kk = k;
    d = vr[kk] * vr[kk] + vi[kk] * vi[kk];
    sr = vr[kk] / d;
    si = -vi[kk] / d; /* 1 / v_kk */
    for (k = 0; k < 3; ++k) {
      double xr = vr[k] * sr - vi[k] * si, xi = vr[k] * si + vi[k] * sr;
      T[k * 3 + 1] = xr;
      T[k * 3 + 2] = xi;
    }
    T[kk * 3 + 2] = 0.0;
  }
  phgmg__inv3(T, Ti);
}

/* A banded matrix by its nonzero diagonals: v[d*n + i] = A(i, i + off[d]). */
typedef struct phgmg__dia {
  int n, nd;
  int *off;
  double *v;
} phgmg__dia;

PHGMG__PRIV void phgmg__dia_free(const phgmg_allocator *al, phgmg__dia *D) {
  phgmg__free(al, D->off);
  phgmg__free(al, D->v);
  D->off = NULL;
  D->v = NULL;
  D->nd = 0;
}

/* From band storage (kb): M1 - M2 (M2 may be NULL). Keeps the diagonals with a
   nonzero entry, plus the main one if force_main, or all of them if keep_all. */
PHGMG__PRIV phgmg_result phgmg__dia_build(const phgmg_allocator *al, phgmg__dia *D, int n, int kb,
                                          const double *M1, const double *M2, int force_main,
                                          int keep_all) {
  int o, i, d = 0;
  D->n = n;
  D->nd = 0;
  D->off = phgmg__ialloc(al, (size_t)(2 * kb + 1));
  D->v = phgmg__dalloc(al, (size_t)(2 * kb + 1) * (size_t)n);
  if (!D->off || !D->v) { phgmg__dia_free(al, D); return PHGMG_ERR_NOMEM; }
  for (o = -kb; o <= kb; ++o) {
    double *vd = D->v + (size_t)d * (size_t)n;
    int nz = 0;
    for (i = 0; i < n; ++i) {
      int j = i + o;
      double val = 0.0;
      if (j >= 0 && j < n) {
        size_t k = PHGMG__PHB(kb, i, j);
        val = M1 ? M1[k] : 0.0;
        if (M2) val -= M2[k];
      }
      vd[i] = val;
      if (val != 0.0) nz = 1;
    }
    if (nz || keep_all || (force_main && o == 0)) D->off[d++] = o;
  }
  D->nd = d;
  return PHGMG_OK;
}

/* Refill all 2kb+1 diagonals of D (built with keep_all) from band storage. */
PHGMG__PRIV void phgmg__dia_refill(phgmg__dia *D, int kb, const double *M) {
  int n = D->n, d, i;
  for (d = 0; d < D->nd; ++d) {
    int o = D->off[d];
    double *vd = D->v + (size_t)d * (size_t)n;
    for (i = 0; i < n; ++i) {
      int j = i + o;
      vd[i] = (j >= 0 && j < n) ? M[PHGMG__PHB(kb, i, j)] : 0.0;
    }
  }
}

/* y = D x (overwrite) */
PHGMG__PRIV void phgmg__dia_mv(const phgmg__dia *D, const double *x, double *y) {
  int n = D->n, d, i;
  for (i = 0; i < n; ++i) y[i] = 0.0;
  for (d = 0; d < D->nd; ++d) {
    int o = D->off[d], i0 = PHGMG__MAX(0, -o), i1 = PHGMG__MIN(n, n - o);
    const double *vd = D->v + (size_t)d * (size_t)n;
    for (i = i0; i < i1; ++i) y[i] += vd[i] * x[i + o];
  }
}

/* ab (band LU layout, kv = kl+ku) += alpha * A * B for DIA A, B; if dd != NULL,
   B is the diagonal matrix diag(dd) instead. */
PHGMG__PRIV void phgmg__dia_prod_band(const phgmg__dia *A, const phgmg__dia *B, const double *dd,
                                      double alpha, double *ab, int ldab, int kv) {
  int n = A->n, da, db, i;
  for (da = 0; da < A->nd; ++da) {
    int oa = A->off[da];
    const double *va = A->v + (size_t)da * (size_t)n;
    if (dd) {
      int i0 = PHGMG__MAX(0, -oa), i1 = PHGMG__MIN(n, n - oa);
      for (i = i0; i < i1; ++i) {
        int j = i + oa;
        ab[(size_t)(kv - oa) + (size_t)j * (size_t)ldab] += alpha * va[i] * dd[j];
      }
      continue;
    }
    for (db = 0; db < B->nd; ++db) {
      int ob = B->off[db], o = oa + ob, i0, i1;
      const double *vb = B->v + (size_t)db * (size_t)n;
      if (o >= n || o <= -n) continue;
      i0 = PHGMG__MAX(0, PHGMG__MAX(-oa, -o));
      i1 = PHGMG__MIN(n, PHGMG__MIN(n - oa, n - o));
      for (i = i0; i < i1; ++i) {
        int j = i + o;
        ab[(size_t)(kv - o) + (size_t)j * (size_t)ldab] += alpha * va[i] * vb[i + oa];
      }
    }
  }
}

enum { PHGMG__GL3_DENSE = 0, PHGMG__GL3_BANDED = 1, PHGMG__GL3_CALLBACK = 2, PHGMG__GL3_MAP = 3,
       PHGMG__GL3_SPARSE = 4 };

struct phgmg_gl3 {
  phgmg_allocator al;
  phgmg_ph_system sys;
  int N, m, mode, linear;
  double h, tol, contraction;
  int max_iter, tol_rel;   /* tol_rel: the default tol, scaled by max(1, |x|_inf, |Z|_inf) */
  double c[3], b[3], A[9], T[9], Ti[9], E[9], d[3];
  double gam, alp, bet;
  /* dense operators */
  double *JR, *JRQ, *Hs, *K1, *K2;
  int *ip1, *ip2;
  /* banded operators */
  phgmg__dia djr, dq, dh;
  int kl, ku, ldab, ue1, ue2;
  double *AB1, *AB2, *dinv1, *dinv2, *hband;
  /* SEPARABLE: Hessian diagonal of the nonlinear part; derivative of poly;
     with poly: per-coordinate weights wc[i] = sum of w_k over terms on i */
  double *dd;
  double *dpoly, *wc;
  /* banded: J - R by rows (CSR) for the stage right-hand sides */
  int *jr_ptr, *jr_col;
  double *jr_val;
  int nopiv1, nopiv2; /* banded factors without row interchanges */
  int nbnz;           /* banded: the nonzero entries of B (row, column, value) */
  int *b_row, *b_col;
  double *b_val;
  /* step map (dense linear): x+ = Phi x + Gam U, g_i = GX_i x + GU_i U */
  double *Phi, *Gam, *GX, *GU;
  /* work */
  double *Z, *W, *Y, *G, *F, *U, *Zprev, *xend, *xnew, *tmp;
  /* Newton right-hand sides, zero-padded by kl before and ku after (banded) */
  double *r1buf, *rcbuf, *r1, *rc;
  /* packed row-wise factors for the pivot-free banded solve (see below) */
  double *pk;
  /* sparse LU of the stage matrices (manual 8.12): the analysis (owned by
     the phgmg_ph_sparse), the real and complex factors, M's values */
  const phgmg__spsym *sps;
  phgmg__spnum spf1, spf2;
  double *spM, *spw;
  int have_prev, need_factor;
  double tend;
  phgmg_gl3_stats st;
  /* tiny entries: flush threshold of this step, ||xend||_inf, 0 = keep_tiny */
  double ftau, xamax;
  int flush;
  /* descriptor (sys.E set): E times the stage block (3N), E's diagonals (banded) */
  double *EZ;
  phgmg__dia de;
  /* feedthrough (sys.P set): sys.B of this copy is B - P (the input matrix of
     the state equation), Bout = B + P that of the output (NULL: B) */
  double *Bin, *Bout;
  /* dampers (sys.ndamp > 0): the co-state at the factorization point (N),
     banded: the damper linearisation sum rho'(s_k) c_k c_k^T by diagonals
     (offsets -ddm_w .. ddm_w), a callback damper that generated energy */
  double *dz;
  phgmg__dia ddm;
  int ddm_w, damp_bad;
};

PHGMG_DEF void phgmg_gl3_destroy(phgmg_gl3 *s) {
  phgmg_allocator al;
  if (!s) return;
  al = s->al;
  phgmg__free(&al, s->JR); phgmg__free(&al, s->JRQ); phgmg__free(&al, s->Hs);
  phgmg__free(&al, s->K1); phgmg__free(&al, s->K2);
  phgmg__free(&al, s->ip1); phgmg__free(&al, s->ip2);
  phgmg__dia_free(&al, &s->djr); phgmg__dia_free(&al, &s->dq); phgmg__dia_free(&al, &s->dh);
  phgmg__free(&al, s->AB1); phgmg__free(&al, s->AB2);
  phgmg__free(&al, s->dinv1); phgmg__free(&al, s->dinv2); phgmg__free(&al, s->hband);
  phgmg__free(&al, s->dd);
  phgmg__free(&al, s->dpoly); phgmg__free(&al, s->wc);
  phgmg__free(&al, s->jr_ptr); phgmg__free(&al, s->jr_col); phgmg__free(&al, s->jr_val);
  phgmg__free(&al, s->b_row); phgmg__free(&al, s->b_col); phgmg__free(&al, s->b_val);
  phgmg__free(&al, s->Phi); phgmg__free(&al, s->Gam); phgmg__free(&al, s->GX);
  phgmg__free(&al, s->GU);
  phgmg__free(&al, s->Z); phgmg__free(&al, s->W); phgmg__free(&al, s->Y);
  phgmg__free(&al, s->G); phgmg__free(&al, s->F); phgmg__free(&al, s->U);
  phgmg__free(&al, s->Zprev); phgmg__free(&al, s->xend);
  phgmg__free(&al, s->xnew); phgmg__free(&al, s->r1buf); phgmg__free(&al, s->rcbuf);
  phgmg__free(&al, s->pk);
  phgmg__spnum_free(&al, &s->spf1); phgmg__spnum_free(&al, &s->spf2);
  phgmg__free(&al, s->spM); phgmg__free(&al, s->spw);
  phgmg__free(&al, s->tmp);
  phgmg__free(&al, s->EZ);
  phgmg__dia_free(&al, &s->de);
  phgmg__free(&al, s->Bin);
  phgmg__free(&al, s->Bout);
  phgmg__free(&al, s->dz);
  phgmg__dia_free(&al, &s->ddm);
  phgmg__free(&al, s);
}

PHGMG_DEF const phgmg_gl3_stats *phgmg_gl3_get_stats(const phgmg_gl3 *s) {
  return s ? &s->st : NULL;
}

/* Descriptor, dense: K1 = gam/h E - Jac and K2 = (alp - i bet)/h E - Jac from
   K1, K2 that hold sigma I - Jac. */
PHGMG__PRIV void phgmg__gl3_dense_shift_e(const phgmg_gl3 *s, double *K1, double *K2) {
  const int N = s->N;
  const double sg = s->gam / s->h, sa = s->alp / s->h, sb = -s->bet / s->h;
  const double *E = s->sys.E;
  int i, j;
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) {
      const size_t e = (size_t)i + (size_t)j * (size_t)N;
      const double d = i == j ? 1.0 : 0.0;
      K1[e] += sg * (E[e] - d);
      K2[2 * e] += sa * (E[e] - d);
      K2[2 * e + 1] = sb * E[e];
    }
}

/* Descriptor: EZ = E V for the three stage columns of V (N each). */
PHGMG__PRIV void phgmg__gl3_e_times(const phgmg_gl3 *s, const double *V, double *EZ) {
  int st;
  if (s->sys.storage == PHGMG_DENSE) {
    phgmg_gemm('N', 'N', s->N, 3, s->N, 1.0, s->sys.E, s->N, V, s->N, 0.0, EZ, s->N);
    return;
  }
  if (s->sys.storage == PHGMG_SPARSE) { /* E's CSC copy */
    for (st = 0; st < 3; ++st) phgmg__ph_mv(&s->sys, s->sys.E, V + (size_t)st * (size_t)s->N, EZ + (size_t)st * (size_t)s->N);
    return;
  }
  for (st = 0; st < 3; ++st) phgmg__dia_mv(&s->de, V + (size_t)st * (size_t)s->N, EZ + (size_t)st * (size_t)s->N);
}

/* Precompute the exact one-step map of a dense linear system (see >>gl3). */
PHGMG__PRIV phgmg_result phgmg__gl3_build_map(phgmg_gl3 *s) {
  const phgmg_allocator *al = &s->al;
  const phgmg_ph_system *sys = &s->sys;
  int N = s->N, m = s->m, nc = N + 3 * m, i, j, k, st;
  size_t NN = (size_t)N * (size_t)N, Nc = (size_t)N * (size_t)nc;
  double *M = NULL, *K1 = NULL, *K2 = NULL, *X1 = NULL, *X2 = NULL, *ZZ = NULL, *QZ = NULL;
  int *ip1 = NULL, *ip2 = NULL;
  double sum[3];
  phgmg_result rc = PHGMG_OK;
  M = phgmg__dalloc(al, NN);
  K1 = phgmg__dalloc(al, NN);
  K2 = phgmg__dalloc(al, 2 * NN);
  X1 = phgmg__dalloc(al, Nc);
  X2 = phgmg__dalloc(al, 2 * Nc);
  ZZ = phgmg__dalloc(al, Nc);
  QZ = phgmg__dalloc(al, Nc);
  ip1 = phgmg__ialloc(al, (size_t)N);
  ip2 = phgmg__ialloc(al, (size_t)N);
  s->Phi = phgmg__dalloc(al, NN);
  s->Gam = phgmg__dalloc(al, (size_t)N * 3 * (size_t)m);
  s->GX = phgmg__dalloc(al, 3 * NN);
  s->GU = phgmg__dalloc(al, 3 * (size_t)N * 3 * (size_t)m);
  if (!M || !K1 || !K2 || !X1 || !X2 || !ZZ || !QZ || !ip1 || !ip2 || !s->Phi || !s->Gam ||
      !s->GX || !s->GU) {
    rc = PHGMG_ERR_NOMEM;
    goto done;
  }
  /* M = (J - R) Q */
  {
    double *JR = K1; /* borrow K1 for J - R */
    size_t e;
    for (e = 0; e < NN; ++e) JR[e] = sys->J[e] - sys->R[e];
    phgmg_gemm('N', 'N', N, N, N, 1.0, JR, N, sys->Q, N, 0.0, M, N);
  }
  if (!phgmg__all_finite(M, NN)) { rc = PHGMG_ERR_NANINF; goto done; }
  for (k = 0; k < 3; ++k) sum[k] = s->Ti[k * 3] + s->Ti[k * 3 + 1] + s->Ti[k * 3 + 2];
  /* K1 = gam/h I - M, K2 = (alp - i bet)/h I - M */
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) {
      size_t e = (size_t)i + (size_t)j * (size_t)N;
      K1[e] = -M[e];
      K2[2 * e] = -M[e];
      K2[2 * e + 1] = 0.0;
      if (i == j) {
        K1[e] += s->gam / s->h;
        K2[2 * e] += s->alp / s->h;
        K2[2 * e + 1] = -s->bet / s->h;
      }
    }
  if (sys->E) phgmg__gl3_dense_shift_e(s, K1, K2);
  rc = phgmg_lu_factor(N, K1, N, ip1);
  if (rc == PHGMG_OK) rc = phgmg_zlu_factor(N, K2, N, ip2);
  if (rc != PHGMG_OK) goto done;
  /* right-hand sides: [sum_k M, Ti_k1 B, Ti_k2 B, Ti_k3 B] */
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) {
      size_t e = (size_t)i + (size_t)j * (size_t)N;
      X1[e] = sum[0] * M[e];
      X2[2 * e] = sum[1] * M[e];
      X2[2 * e + 1] = sum[2] * M[e];
    }
  for (st = 0; st < 3; ++st)
    for (j = 0; j < m; ++j)
      for (i = 0; i < N; ++i) {
        size_t e = (size_t)i + (size_t)(N + st * m + j) * (size_t)N;
        double bij = sys->B[(size_t)i + (size_t)j * (size_t)N];
        X1[e] = s->Ti[0 * 3 + st] * bij;
        X2[2 * e] = s->Ti[1 * 3 + st] * bij;
        X2[2 * e + 1] = s->Ti[2 * 3 + st] * bij;
      }
  phgmg_lu_solve('N', N, K1, N, ip1, nc, X1, N);
  phgmg_zlu_solve(N, K2, N, ip2, nc, X2, N);
  if (s->flush) /* solutions decay along a chain: keep the products below clear of subnormals */
    for (j = 0; j < nc; ++j) {
      phgmg__flush_tiny_rel(X1 + (size_t)j * (size_t)N, (size_t)N);
      phgmg__flush_tiny_rel(X2 + 2 * (size_t)j * (size_t)N, 2 * (size_t)N);
    }
  /* Z_i = T_i1 W1 + T_i2 Re W23 + T_i3 Im W23; Phi = I + sum d_i Zx_i, Gam = sum d_i Zu_i;
     GX_i = Q (I + Zx_i), GU_i = Q Zu_i */
  memset(s->Phi, 0, sizeof(double) * NN);
  memset(s->Gam, 0, sizeof(double) * (size_t)N * 3 * (size_t)m);
  for (st = 0; st < 3; ++st) {
    double t1 = s->T[st * 3], t2 = s->T[st * 3 + 1], t3 = s->T[st * 3 + 2], di = s->d[st];
    size_t e;
    for (e = 0; e < Nc; ++e) ZZ[e] = t1 * X1[e] + t2 * X2[2 * e] + t3 * X2[2 * e + 1];
    for (e = 0; e < NN; ++e) s->Phi[e] += di * ZZ[e];
    for (e = 0; e < (size_t)N * 3 * (size_t)m; ++e) s->Gam[e] += di * ZZ[NN + e];
    phgmg_gemm('N', 'N', N, nc, N, 1.0, sys->Q, N, ZZ, N, 0.0, QZ, N);
    for (e = 0; e < NN; ++e) s->GX[(size_t)st * NN + e] = QZ[e] + sys->Q[e];
    memcpy(s->GU + (size_t)st * (size_t)N * 3 * (size_t)m, QZ + NN,
           sizeof(double) * (size_t)N * 3 * (size_t)m);
  }
  for (i = 0; i < N; ++i) s->Phi[(size_t)i * (size_t)(N + 1)] += 1.0;
  if (!phgmg__all_finite(s->Phi, NN) || !phgmg__all_finite(s->Gam, (size_t)N * 3 * (size_t)m))
    rc = PHGMG_ERR_NANINF;
done:
  phgmg__free(al, M); phgmg__free(al, K1); phgmg__free(al, K2);
  phgmg__free(al, X1); phgmg__free(al, X2); phgmg__free(al, ZZ); phgmg__free(al, QZ);
  phgmg__free(al, ip1); phgmg__free(al, ip2);
  return rc;
}

/* GL3 coefficients, the transformation of A^{-1}, the extrapolation matrix
   of the previous collocation polynomial, and the solver mode. */
PHGMG__PRIV void phgmg__gl3_setup_method(phgmg_gl3 *s, const phgmg_gl3_opts *opts) {
  const phgmg_ph_system *sys = &s->sys;
  const int N = s->N;
  int i, j, k;
  phgmg_gl3_coefficients(s->c, s->b, s->A);
  phgmg__gl3_transform(s->A, s->T, s->Ti, &s->gam, &s->alp, &s->bet);
  {
    double Ai[9];
    phgmg__inv3(s->A, Ai);
    for (j = 0; j < 3; ++j) s->d[j] = s->b[0] * Ai[j] + s->b[1] * Ai[3 + j] + s->b[2] * Ai[6 + j];
  }
  /* extrapolation of the previous collocation polynomial p (p(0) = 0,
     p(c_j) = Zprev_j): Z_i = p(1 + c_i) - p(1) = sum_j E_ij Zprev_j */
  for (i = 0; i < 3; ++i)
    for (j = 0; j < 3; ++j) {
      double s1 = 1.0 + s->c[i], l1 = s1 / s->c[j], l0 = 1.0 / s->c[j];
      for (k = 0; k < 3; ++k) {
        if (k == j) continue;
        l1 *= (s1 - s->c[k]) / (s->c[j] - s->c[k]);
        l0 *= (1.0 - s->c[k]) / (s->c[j] - s->c[k]);
      }
      s->E[i * 3 + j] = l1 - l0;
    }
  if (s->linear && !(opts && opts->no_step_map) && sys->storage == PHGMG_DENSE &&
      N <= PHGMG_GL3_STEP_MAP_MAX_N)
    s->mode = PHGMG__GL3_MAP;
  else if (sys->shifted_factor)
    s->mode = PHGMG__GL3_CALLBACK;
  else if (!sys->ndamp && (s->sps = phgmg__ph_sparse_lu(sys)) != NULL)
    s->mode = PHGMG__GL3_SPARSE;
  else
    s->mode = sys->storage == PHGMG_DENSE ? PHGMG__GL3_DENSE : PHGMG__GL3_BANDED;
  s->st.sparse_lu = s->mode == PHGMG__GL3_SPARSE;

}

/* Linear system, dense, small: the precomputed step map (tiny entries of the
   maps flushed once). */
PHGMG__PRIV phgmg_result phgmg__gl3_setup_map(phgmg_gl3 *s) {
  const phgmg_ph_system *sys = &s->sys;
  const int N = s->N, m = s->m;
  int i;
  phgmg_result rc;
  if (!phgmg__ph_mat_finite(sys, sys->J) || !phgmg__ph_mat_finite(sys, sys->R) ||
      !phgmg__ph_mat_finite(sys, sys->Q) || !phgmg__all_finite(sys->B, (size_t)N * (size_t)m)) return PHGMG_ERR_NANINF;
  rc = phgmg__gl3_build_map(s);
  if (rc != PHGMG_OK) return rc;
  if (s->flush) { /* the maps decay along a chain: tiny entries flushed once, per column */
    for (i = 0; i < 3 * N; ++i) {
      if (i < N) phgmg__flush_tiny_rel(s->Phi + (size_t)i * (size_t)N, (size_t)N);
      phgmg__flush_tiny_rel(s->GX + (size_t)i * (size_t)N, (size_t)N);
    }
    for (i = 0; i < 9 * m; ++i) {
      if (i < 3 * m) phgmg__flush_tiny_rel(s->Gam + (size_t)i * (size_t)N, (size_t)N);
      phgmg__flush_tiny_rel(s->GU + (size_t)i * (size_t)N, (size_t)N);
    }
  }
  return PHGMG_OK;
}

/* Newton vectors, and the fast path of a shared built-in separable function. */
PHGMG__PRIV phgmg_result phgmg__gl3_setup_newton(phgmg_gl3 *s) {
  const phgmg_ph_system *sys = &s->sys;
  const int N = s->N;
  const size_t N3 = 3 * (size_t)N;
  int i, k;
  s->Z = phgmg__dalloc(&s->al, N3);
  s->W = phgmg__dalloc(&s->al, N3);
  s->Y = phgmg__dalloc(&s->al, N3);
  s->F = phgmg__dalloc(&s->al, N3);
  s->Zprev = phgmg__dalloc(&s->al, N3);
  s->xend = phgmg__dalloc(&s->al, (size_t)N);
  s->tmp = phgmg__dalloc(&s->al, (size_t)N);
  if (!s->Z || !s->W || !s->Y || !s->F || !s->Zprev || !s->xend ||
      !s->tmp) return PHGMG_ERR_NOMEM;
  if (sys->E) {
    s->EZ = phgmg__dalloc(&s->al, N3);
    if (!s->EZ) return PHGMG_ERR_NOMEM;
  }
  if (sys->ndamp) {
    s->dz = phgmg__dalloc(&s->al, (size_t)N);
    if (!s->dz) return PHGMG_ERR_NOMEM;
  }
  if (sys->nl == PHGMG_NL_SEPARABLE) {
    s->dd = phgmg__dalloc(&s->al, (size_t)N);
    if (!s->dd) return PHGMG_ERR_NOMEM;
    if (PHGMG__PH_BUILTIN(sys) && sys->phi_nfun <= 1) { /* one shared function */
      if (sys->poly_deg > 0) { /* dpoly[j] = (j+1) poly[j+1] */
        s->dpoly = phgmg__dalloc(&s->al, (size_t)sys->poly_deg);
        if (!s->dpoly) return PHGMG_ERR_NOMEM;
        for (k = 0; k < sys->poly_deg; ++k) s->dpoly[k] = (double)(k + 1) * sys->poly[k + 1];
      }
      s->wc = phgmg__dalloc(&s->al, (size_t)N);
      if (!s->wc) return PHGMG_ERR_NOMEM;
      for (i = 0; i < N; ++i) s->wc[i] = 0.0;
      for (k = 0; k < sys->nsep; ++k) s->wc[sys->sep_idx[k]] += sys->sep_w ? sys->sep_w[k] : 1.0;
    }
  }
  return PHGMG_OK;
}

/* Dense storage: J - R, the LU workspaces and (J - R) Q. */
PHGMG__PRIV phgmg_result phgmg__gl3_setup_dense(phgmg_gl3 *s) {
  const phgmg_ph_system *sys = &s->sys;
  const int N = s->N;
  const size_t NN = (size_t)N * (size_t)N;
  s->JR = phgmg__dalloc(&s->al, NN);
  if (!s->JR) return PHGMG_ERR_NOMEM;
  {
    size_t e;
    for (e = 0; e < NN; ++e) s->JR[e] = sys->J[e] - sys->R[e];
  }
  if (s->mode == PHGMG__GL3_DENSE) {
    s->K1 = phgmg__dalloc(&s->al, NN);
    s->K2 = phgmg__dalloc(&s->al, 2 * NN);
    s->ip1 = phgmg__ialloc(&s->al, (size_t)N);
    s->ip2 = phgmg__ialloc(&s->al, (size_t)N);
    if (!s->K1 || !s->K2 || !s->ip1 || !s->ip2) return PHGMG_ERR_NOMEM;
    if (sys->nl == PHGMG_NL_GENERAL) {
      s->Hs = phgmg__dalloc(&s->al, NN);
      if (!s->Hs) return PHGMG_ERR_NOMEM;
    } else {
      s->JRQ = phgmg__dalloc(&s->al, NN);
      if (!s->JRQ) return PHGMG_ERR_NOMEM;
      phgmg_gemm('N', 'N', N, N, N, 1.0, s->JR, N, sys->Q, N, 0.0, s->JRQ, N);
    }
  }
  return PHGMG_OK;
}

/* Banded storage: CSR of J - R and of B for the right-hand side. */
PHGMG__PRIV phgmg_result phgmg__gl3_csr_sparse(phgmg_gl3 *s);
PHGMG__PRIV phgmg_result phgmg__gl3_csr(phgmg_gl3 *s) {
  const phgmg_ph_system *sys = &s->sys;
  const int N = s->N, m = s->m, kb = sys->kb;
  size_t nnz = 0;
  int r, c;
  if (sys->storage == PHGMG_SPARSE) {
    phgmg_result rc = phgmg__gl3_csr_sparse(s);
    if (rc != PHGMG_OK) return rc;
  } else {
  for (r = 0; r < N; ++r)
    for (c = PHGMG__MAX(0, r - kb); c <= PHGMG__MIN(N - 1, r + kb); ++c)
      if (sys->J[PHGMG__PHB(kb, r, c)] - sys->R[PHGMG__PHB(kb, r, c)] != 0.0) ++nnz;
  s->jr_ptr = phgmg__ialloc(&s->al, (size_t)N + 1);
  s->jr_col = phgmg__ialloc(&s->al, nnz);
  s->jr_val = phgmg__dalloc(&s->al, nnz);
  if (!s->jr_ptr || !s->jr_col || !s->jr_val) return PHGMG_ERR_NOMEM;
  nnz = 0;
  for (r = 0; r < N; ++r) {
    s->jr_ptr[r] = (int)nnz;
    for (c = PHGMG__MAX(0, r - kb); c <= PHGMG__MIN(N - 1, r + kb); ++c) {
      double v = sys->J[PHGMG__PHB(kb, r, c)] - sys->R[PHGMG__PHB(kb, r, c)];
      if (v != 0.0) { s->jr_col[nnz] = c; s->jr_val[nnz] = v; ++nnz; }
    }
  }
  s->jr_ptr[N] = (int)nnz;
  }
  nnz = 0;
  for (c = 0; c < m; ++c)
    for (r = 0; r < N; ++r)
      if (sys->B[(size_t)r + (size_t)c * (size_t)N] != 0.0) ++nnz;
  s->b_row = phgmg__ialloc(&s->al, nnz);
  s->b_col = phgmg__ialloc(&s->al, nnz);
  s->b_val = phgmg__dalloc(&s->al, nnz);
  if (!s->b_row || !s->b_col || !s->b_val) return PHGMG_ERR_NOMEM;
  s->nbnz = 0;
  for (c = 0; c < m; ++c)
    for (r = 0; r < N; ++r) {
      double v = sys->B[(size_t)r + (size_t)c * (size_t)N];
      if (v == 0.0) continue;
      s->b_row[s->nbnz] = r;
      s->b_col[s->nbnz] = c;
      s->b_val[s->nbnz] = v;
      s->nbnz++;
    }
  return PHGMG_OK;
}

/* SPARSE storage: the CSR of J - R is the transpose of the analysis's CSC
   (the same entries, columns increasing in each row, as from band storage). */
PHGMG__PRIV phgmg_result phgmg__gl3_csr_sparse(phgmg_gl3 *s) {
  const phgmg__spsym *S = s->sps ? s->sps : phgmg__ph_sparse_lu(&s->sys);
  const int N = s->N;
  const size_t nnz = S ? (size_t)S->jr_p[N] : 0;
  int j, p;
  if (!S) return PHGMG_ERR_UNSUPPORTED;
  s->jr_ptr = phgmg__ialloc(&s->al, (size_t)N + 1);
  s->jr_col = phgmg__ialloc(&s->al, nnz + 1);
  s->jr_val = phgmg__dalloc(&s->al, nnz + 1);
  if (!s->jr_ptr || !s->jr_col || !s->jr_val) return PHGMG_ERR_NOMEM;
  for (j = 0; j <= N; ++j) s->jr_ptr[j] = 0;
  for (p = 0; p < (int)nnz; ++p) s->jr_ptr[S->jr_i[p] + 1]++;
  for (j = 0; j < N; ++j) s->jr_ptr[j + 1] += s->jr_ptr[j];
  for (j = 0; j < N; ++j) /* columns in order: each row's columns increase */
    for (p = S->jr_p[j]; p < S->jr_p[j + 1]; ++p) {
      int q = s->jr_ptr[S->jr_i[p]]++;
      s->jr_col[q] = j; s->jr_val[q] = S->jr_x[p];
    }
  for (j = N; j > 0; --j) s->jr_ptr[j] = s->jr_ptr[j - 1];
  s->jr_ptr[0] = 0;
  return PHGMG_OK;
}

/* The sparse LU's factors and the values of M (manual 8.12). */
PHGMG__PRIV phgmg_result phgmg__gl3_setup_sparse(phgmg_gl3 *s) {
  phgmg_result rc = phgmg__spnum_alloc(&s->al, s->sps, 0, &s->spf1);
  if (rc == PHGMG_OK) rc = phgmg__spnum_alloc(&s->al, s->sps, 1, &s->spf2);
  if (rc != PHGMG_OK) return rc;
  s->spM = phgmg__dalloc(&s->al, (size_t)s->sps->k_p[s->N] + 1);
  s->spw = phgmg__dalloc(&s->al, (size_t)s->N);
  return s->spM && s->spw ? PHGMG_OK : PHGMG_ERR_NOMEM;
}

PHGMG__PRIV phgmg_result phgmg__gl3_setup_band_lu(phgmg_gl3 *s);

/* Sparse mode: Q's diagonal as the one-diagonal form when Q is diagonal (the
   fused gradient path), else no diagonal form (Q x through the CSC copy);
   the band's diagonals are not scanned. */
PHGMG__PRIV phgmg_result phgmg__gl3_sparse_qdiag(phgmg_gl3 *s) {
  const phgmg__spsym *S = s->sps;
  int j, p, diag = 1;
  for (j = 0; j < s->N && diag; ++j)
    for (p = S->q_p[j]; p < S->q_p[j + 1]; ++p) diag &= S->q_i[p] == j;
  s->dq.n = s->N;
  s->dq.nd = 0;
  if (!diag) return PHGMG_OK;
  s->dq.off = phgmg__ialloc(&s->al, 1);
  s->dq.v = phgmg__dalloc(&s->al, (size_t)s->N);
  if (!s->dq.off || !s->dq.v) return PHGMG_ERR_NOMEM;
  s->dq.off[0] = 0;
  for (j = 0; j < s->N; ++j) s->dq.v[j] = S->q_p[j + 1] > S->q_p[j] ? S->q_x[S->q_p[j]] : 0.0;
  s->dq.nd = 1;
  return PHGMG_OK;
}

/* Banded storage: diagonals of J - R and Q, the CSR forms, and the
   workspaces of the stage solver. */
PHGMG__PRIV phgmg_result phgmg__gl3_setup_banded(phgmg_gl3 *s) {
  const phgmg_ph_system *sys = &s->sys;
  const int N = s->N;
  phgmg_result rc;
  int kb = sys->kb;
  if (s->mode == PHGMG__GL3_SPARSE) {
    rc = phgmg__gl3_sparse_qdiag(s);
  } else {
    rc = phgmg__dia_build(&s->al, &s->djr, N, kb, sys->J, sys->R, 0, 0);
    if (rc == PHGMG_OK) rc = phgmg__dia_build(&s->al, &s->dq, N, kb, sys->Q, NULL, 1, 0);
  }
  if (rc != PHGMG_OK) return rc;
  rc = phgmg__gl3_csr(s);
  if (rc != PHGMG_OK) return rc;
  if (s->mode == PHGMG__GL3_SPARSE) return phgmg__gl3_setup_sparse(s);
  return s->mode == PHGMG__GL3_BANDED ? phgmg__gl3_setup_band_lu(s) : PHGMG_OK;
}

/* Banded with dampers: the diagonals -w .. w (w = largest |i - j|) of the
   damper linearisation, refilled at every factorization. */
PHGMG__PRIV phgmg_result phgmg__gl3_setup_ddm(phgmg_gl3 *s) {
  const phgmg_ph_system *sys = &s->sys;
  int k, w = 0;
  phgmg__dia_free(&s->al, &s->ddm);
  for (k = 0; k < sys->ndamp; ++k) {
    const int j = phgmg__damp_j(sys, k), i = sys->damp_i[k];
    if (j >= 0) w = PHGMG__MAX(w, i > j ? i - j : j - i);
  }
  s->ddm_w = w;
  s->ddm.n = s->N;
  s->ddm.nd = 2 * w + 1;
  s->ddm.off = phgmg__ialloc(&s->al, (size_t)(2 * w + 1));
  s->ddm.v = phgmg__dalloc(&s->al, (size_t)(2 * w + 1) * (size_t)s->N);
  if (!s->ddm.off || !s->ddm.v) return PHGMG_ERR_NOMEM;
  for (k = 0; k <= 2 * w; ++k) s->ddm.off[k] = k - w;
  return PHGMG_OK;
}

/* The band LU workspaces (bandwidths from the nonzero diagonals). */
PHGMG__PRIV phgmg_result phgmg__gl3_setup_band_lu(phgmg_gl3 *s) {
  const phgmg_ph_system *sys = &s->sys;
  const int N = s->N;
  int k, kb = sys->kb, amin = 0, amax = 0, bmin = 0, bmax = 0;
  phgmg_result rc;
  {
    for (k = 0; k < s->djr.nd; ++k) {
      amin = PHGMG__MIN(amin, s->djr.off[k]);
      amax = PHGMG__MAX(amax, s->djr.off[k]);
    }
    for (k = 0; k < s->dq.nd; ++k) {
      bmin = PHGMG__MIN(bmin, s->dq.off[k]);
      bmax = PHGMG__MAX(bmax, s->dq.off[k]);
    }
    if (sys->nl == PHGMG_NL_GENERAL) {
      bmin = -kb;
      bmax = kb;
      rc = phgmg__dia_build(&s->al, &s->dh, N, kb, NULL, NULL, 1, 1);
      s->hband = phgmg__dalloc(&s->al, (size_t)(2 * kb + 1) * (size_t)N);
      if (rc != PHGMG_OK || !s->hband) return PHGMG_ERR_NOMEM;
    }
    if (sys->ndamp) { /* dampers: their linearisation joins J - R */
      rc = phgmg__gl3_setup_ddm(s);
      if (rc != PHGMG_OK) return rc;
      amin = PHGMG__MIN(amin, -s->ddm_w);
      amax = PHGMG__MAX(amax, s->ddm_w);
    }
    if (sys->E) { /* descriptor: the band of E joins that of (J - R) Hess */
      rc = sys->storage == PHGMG_SPARSE ? PHGMG_OK /* built by phgmg__gl3_sparse_dia */
                                        : phgmg__dia_build(&s->al, &s->de, N, kb, sys->E, NULL, 1, 0);
      if (rc != PHGMG_OK) return rc;
      for (k = 0; k < s->de.nd; ++k) {
        amin = PHGMG__MIN(amin, s->de.off[k] - bmin);
        amax = PHGMG__MAX(amax, s->de.off[k] - bmax);
      }
    }
    s->kl = PHGMG__MIN(N - 1, -(amin + bmin));
    s->ku = PHGMG__MIN(N - 1, amax + bmax);
    s->ldab = 2 * s->kl + s->ku + 1;
    s->AB1 = phgmg__dalloc(&s->al, (size_t)s->ldab * (size_t)N);
    s->AB2 = phgmg__dalloc(&s->al, 2 * (size_t)s->ldab * (size_t)N);
    s->dinv1 = phgmg__dalloc(&s->al, (size_t)N);
    s->dinv2 = phgmg__dalloc(&s->al, 2 * (size_t)N);
    s->ip1 = phgmg__ialloc(&s->al, (size_t)N);
    s->ip2 = phgmg__ialloc(&s->al, (size_t)N);
    if (!s->AB1 || !s->AB2 || !s->dinv1 || !s->dinv2 || !s->ip1 || !s->ip2) return PHGMG_ERR_NOMEM;
  }
  return PHGMG_OK;
}

/* Right-hand-side buffers of the solves (padded by the bandwidths). */
PHGMG__PRIV phgmg_result phgmg__gl3_setup_buffers(phgmg_gl3 *s) {
  const int N = s->N;
  {
    size_t len = (size_t)N + (size_t)s->kl + (size_t)s->ku;
    s->r1buf = phgmg__dalloc(&s->al, len);
    s->rcbuf = phgmg__dalloc(&s->al, 2 * len);
    if (!s->r1buf || !s->rcbuf) return PHGMG_ERR_NOMEM;
    memset(s->r1buf, 0, sizeof(double) * len);
    memset(s->rcbuf, 0, sizeof(double) * 2 * len);
    s->r1 = s->r1buf + s->kl;
    s->rc = s->rcbuf + 2 * (size_t)s->kl;
    if (s->mode == PHGMG__GL3_BANDED) {
      s->pk = phgmg__dalloc(&s->al, (size_t)3 * (size_t)(s->kl + s->ku + 1) * (size_t)N);
      if (!s->pk) return PHGMG_ERR_NOMEM;
    }
  }
  return PHGMG_OK;
}

/* Feedthrough P: the stepper's copy of the system takes B - P as its input
   matrix (every right-hand side path and the step map then use it); B + P
   is kept for the outputs of the energy bookkeeping. */
PHGMG__PRIV phgmg_result phgmg__gl3_setup_feedthrough(phgmg_gl3 *s) {
  const size_t n = (size_t)s->N * (size_t)s->m;
  size_t i;
  s->Bin = phgmg__dalloc(&s->al, n);
  s->Bout = phgmg__dalloc(&s->al, n);
  if (!s->Bin || !s->Bout) return PHGMG_ERR_NOMEM;
  for (i = 0; i < n; ++i) {
    s->Bin[i] = s->sys.B[i] - s->sys.P[i];
    s->Bout[i] = s->sys.B[i] + s->sys.P[i];
  }
  s->sys.B = s->Bin;
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_gl3_create(phgmg_gl3 **out, const phgmg_ph_system *sys, double dt,
                                        const phgmg_gl3_opts *opts, const phgmg_allocator *alloc) {
  phgmg_gl3 *s;
  phgmg_result rc;
  if (!out) return PHGMG_ERR_INVALID_ARG;
  *out = NULL;
  rc = phgmg__ph_check(sys);
  if (rc != PHGMG_OK) return rc;
  if (!(dt > 0.0) || dt == HUGE_VAL) return PHGMG_ERR_INVALID_ARG;
  if (sys->E && phgmg__e_algebraic(sys, alloc) != 0) return PHGMG_ERR_UNSUPPORTED;   /* step the condensed model (1.8) */
  if (opts && (opts->max_iter < 0 || opts->tol < 0.0 || opts->contraction < 0.0 ||
               opts->tol != opts->tol || opts->contraction != opts->contraction))
    return PHGMG_ERR_INVALID_ARG;
  s = PHGMG__CAST(phgmg_gl3 *, phgmg__alloc(alloc, sizeof(phgmg_gl3)));
  if (!s) return PHGMG_ERR_NOMEM;
  memset(s, 0, sizeof *s);
  if (alloc) s->al = *alloc;
  s->sys = *sys;
  s->N = sys->N;
  s->m = sys->m;
  s->h = dt;
  s->tol = (opts && opts->tol > 0.0) ? opts->tol : 1e-10;
  s->tol_rel = !(opts && opts->tol > 0.0);
  s->max_iter = (opts && opts->max_iter > 0) ? opts->max_iter : 10;
  s->contraction = (opts && opts->contraction > 0.0) ? opts->contraction : 0.5;
  s->flush = !(opts && opts->keep_tiny);
  s->ftau = s->flush ? PHGMG__DBL_MIN : 0.0;
  s->linear = sys->nl == PHGMG_NL_NONE && sys->ndamp == 0;
  if (sys->P && phgmg__gl3_setup_feedthrough(s) != PHGMG_OK) {
    phgmg_gl3_destroy(s);
    return PHGMG_ERR_NOMEM;
  }
  phgmg__gl3_setup_method(s, opts);
  s->U = phgmg__dalloc(&s->al, 3 * (size_t)s->m);
  s->G = phgmg__dalloc(&s->al, 3 * (size_t)s->N);
  s->xnew = phgmg__dalloc(&s->al, (size_t)s->N);
  rc = (s->U && s->G && s->xnew) ? PHGMG_OK : PHGMG_ERR_NOMEM;
  if (rc == PHGMG_OK && s->mode == PHGMG__GL3_MAP) {
    rc = phgmg__gl3_setup_map(s);
  } else if (rc == PHGMG_OK) {
    rc = phgmg__gl3_setup_newton(s);
    if (rc == PHGMG_OK) rc = sys->storage == PHGMG_DENSE ? phgmg__gl3_setup_dense(s) : phgmg__gl3_setup_banded(s);
    if (rc == PHGMG_OK) rc = phgmg__gl3_setup_buffers(s);
    s->need_factor = 1;
  }
  if (rc != PHGMG_OK) {
    phgmg_gl3_destroy(s);
    return rc;
  }
  *out = s;
  return PHGMG_OK;
}

/* Banded: F_st = (J - R) G_st row by row from the CSR copy, + B u_st over the
   nonzero entries of B. */
PHGMG__PRIV void phgmg__gl3_rhs_csr(phgmg_gl3 *s) {
  int N = s->N, m = s->m, r, k;
  const int *ptr = s->jr_ptr, *col = s->jr_col;
  const double *val = s->jr_val, *U = s->U;
  const double *G0 = s->G, *G1 = s->G + N, *G2 = s->G + 2 * (size_t)N;
  double *F0 = s->F, *F1 = s->F + N, *F2 = s->F + 2 * (size_t)N;
  for (r = 0; r < N; ++r) {
    double a0 = 0.0, a1 = 0.0, a2 = 0.0;
    for (k = ptr[r]; k < ptr[r + 1]; ++k) {
      int j = col[k];
      double v = val[k];
      a0 = PHGMG__FMA(v, G0[j], a0);
      a1 = PHGMG__FMA(v, G1[j], a1);
      a2 = PHGMG__FMA(v, G2[j], a2);
    }
    F0[r] = a0;
    F1[r] = a1;
    F2[r] = a2;
  }
  for (k = 0; k < s->nbnz; ++k) {
    int r0 = s->b_row[k], c = s->b_col[k];
    double b = s->b_val[k];
    F0[r0] += b * U[c];
    F1[r0] += b * U[m + c];
    F2[r0] += b * U[2 * m + c];
  }
  s->st.rhs_evals += 3;
}

/* Evaluate the stages at Y_i = x + Z_i: gradients G_i and right-hand sides F_i
   (Y_i is formed only where a callback or a dense product needs it). */
/* G = Q (x + Z) + grad of one shared built-in separable function, for a
   diagonal Q: coordinate-wise, the three stages in one pass. */
PHGMG__PRIV void phgmg__gl3_grad_fused(phgmg_gl3 *s, const double *x) {
  const phgmg_ph_system *sys = &s->sys;
  const int N = s->N;
  const double *qd = s->dq.v;
  int i;
  const double *wc = s->wc, *dp = s->dpoly, *ex = sys->expo;
  const double *z0 = s->Z, *z1 = s->Z + N, *z2 = s->Z + 2 * (size_t)N;
  double *g0 = s->G, *g1 = s->G + N, *g2 = s->G + 2 * (size_t)N;
  int deg = sys->poly_deg, ne = sys->nexp;
  for (i = 0; i < N; ++i) {
    double xi = x[i], q = qd[i], w = wc[i];
    double y0 = xi + z0[i], y1 = xi + z1[i], y2 = xi + z2[i];
    if (w != 0.0) {
      double p0 = deg > 0 ? dp[deg - 1] : 0.0, p1 = p0, p2 = p0;
      int j;
      for (j = deg - 2; j >= 0; --j) {
        double c = dp[j];
        p0 = PHGMG__FMA(p0, y0, c);
        p1 = PHGMG__FMA(p1, y1, c);
        p2 = PHGMG__FMA(p2, y2, c);
      }
      for (j = 0; j < ne; ++j) { /* d/ds a e^{bs} = a b e^{bs} */
        double ab = ex[2 * j] * ex[2 * j + 1], b = ex[2 * j + 1];
        p0 = PHGMG__FMA(ab, exp(b * y0), p0);
        p1 = PHGMG__FMA(ab, exp(b * y1), p1);
        p2 = PHGMG__FMA(ab, exp(b * y2), p2);
      }
      g0[i] = PHGMG__FMA(w, p0, q * y0);
      g1[i] = PHGMG__FMA(w, p1, q * y1);
      g2[i] = PHGMG__FMA(w, p2, q * y2);
    } else {
      g0[i] = q * y0;
      g1[i] = q * y1;
      g2[i] = q * y2;
    }
  }
}

/* Adds the gradient of the nonlinear part at the stage values x + Z_st to
   G_st: a shared built-in separable function (derivative coefficients
   precomputed), one built-in function per term, callbacks, or GENERAL. */
PHGMG__PRIV void phgmg__gl3_grad_nl(phgmg_gl3 *s, const double *x, int st) {
  const phgmg_ph_system *sys = &s->sys;
  const int N = s->N;
  const double *z = s->Z + (size_t)st * (size_t)N;
  double *g = s->G + (size_t)st * (size_t)N;
  int i, k;
  if (sys->nl == PHGMG_NL_SEPARABLE) {
    const int *idx = sys->sep_idx;
    const double *w = sys->sep_w;
    if (s->wc) { /* one shared built-in function: derivative coefficients precomputed */
      int deg = sys->poly_deg, ne = sys->nexp;
      const double *dp = s->dpoly, *ex = sys->expo;
      for (k = 0; k < sys->nsep; ++k) {
        int ix = idx[k], j;
        double v = x[ix] + z[ix], acc = deg > 0 ? dp[deg - 1] : 0.0;
        for (j = deg - 2; j >= 0; --j) acc = acc * v + dp[j];
        for (j = 0; j < ne; ++j) acc += ex[2 * j] * ex[2 * j + 1] * exp(ex[2 * j + 1] * v);
        g[ix] += w ? w[k] * acc : acc;
      }
    } else if (PHGMG__PH_BUILTIN(sys)) { /* one built-in function per term */
      for (k = 0; k < sys->nsep; ++k) {
        int ix = idx[k];
        double d1 = phgmg__ph_dphi_builtin(sys, k, x[ix] + z[ix]);
        g[ix] += w ? w[k] * d1 : d1;
      }
    } else { /* callbacks */
      for (k = 0; k < sys->nsep; ++k) {
        int ix = idx[k];
        double d1 = phgmg__ph_phi(sys, k, x[ix] + z[ix], 1);
        g[ix] += w ? w[k] * d1 : d1;
      }
    }
  } else if (sys->nl == PHGMG_NL_GENERAL) {
    sys->grad_nl(s->Y + (size_t)st * (size_t)N, s->tmp, sys->user);
    for (i = 0; i < N; ++i) g[i] += s->tmp[i];
  }
}

PHGMG__PRIV void phgmg__gl3_eval_jr(phgmg_gl3 *s, const double *x) {
  const phgmg_ph_system *sys = &s->sys;
  int N = s->N, m = s->m, st, i, k;
  int qdiag = sys->storage != PHGMG_DENSE && s->dq.nd == 1;
  int need_y = !qdiag || sys->nl == PHGMG_NL_GENERAL;
  if (need_y)
    for (st = 0; st < 3; ++st) {
      const double *z = s->Z + (size_t)st * (size_t)N;
      double *y = s->Y + (size_t)st * (size_t)N;
      for (i = 0; i < N; ++i) y[i] = x[i] + z[i];
    }
  if (sys->storage == PHGMG_DENSE) {
    phgmg_gemm('N', 'N', N, 3, N, 1.0, sys->Q, N, s->Y, N, 0.0, s->G, N);
  } else if (qdiag) { /* Q diagonal: G = q .* (x + Z) in one pass */
    const double *qd = s->dq.v;
    if (s->wc) { /* ... plus the shared built-in function */
      phgmg__gl3_grad_fused(s, x);
      phgmg__gl3_rhs_csr(s);
      return;
    }
    for (st = 0; st < 3; ++st) {
      const double *z = s->Z + (size_t)st * (size_t)N;
      double *g = s->G + (size_t)st * (size_t)N;
      for (i = 0; i < N; ++i) g[i] = qd[i] * (x[i] + z[i]);
    }
  } else if (s->sps) {
    for (st = 0; st < 3; ++st)
      phgmg__sp_qmv(s->sps, s->Y + (size_t)st * (size_t)N, s->G + (size_t)st * (size_t)N);
  } else {
    for (st = 0; st < 3; ++st)
      phgmg__dia_mv(&s->dq, s->Y + (size_t)st * (size_t)N, s->G + (size_t)st * (size_t)N);
  }
  if (sys->nl != PHGMG_NL_NONE)
    for (st = 0; st < 3; ++st) phgmg__gl3_grad_nl(s, x, st);
  if (sys->storage != PHGMG_DENSE) {
    phgmg__gl3_rhs_csr(s);
    return;
  }
  /* F = B U + (J - R) G */
  for (st = 0; st < 3; ++st) {
    double *f = s->F + (size_t)st * (size_t)N;
    const double *u = s->U + (size_t)st * (size_t)m;
    for (i = 0; i < N; ++i) f[i] = sys->B[i] * u[0];
    for (k = 1; k < m; ++k) {
      const double *bk = sys->B + (size_t)k * (size_t)N;
      double uk = u[k];
      if (uk == 0.0) continue;
      for (i = 0; i < N; ++i) f[i] += bk[i] * uk;
    }
  }
  phgmg_gemm('N', 'N', N, 3, N, 1.0, s->JR, N, s->G, N, 1.0, s->F, N);
  s->st.rhs_evals += 3;
}

/* Stage gradients G_i and right-hand sides F_i, with the dampers' forces
   -sum_k c_k rho_k(c_k^T G_i) (s->damp_bad: a callback damper generated
   energy). */
PHGMG__PRIV void phgmg__gl3_eval(phgmg_gl3 *s, const double *x) {
  int st;
  phgmg__gl3_eval_jr(s, x);
  if (!s->sys.ndamp) return;
  for (st = 0; st < 3; ++st)
    if (phgmg__damp_apply(&s->sys, s->G + (size_t)st * (size_t)s->N, -1.0, s->F + (size_t)st * (size_t)s->N) < 0.0)
      s->damp_bad = 1;
}

/* Both band factorizations without row interchanges: the factors are repacked
   row by row, pk + j*P (P = 3(kl+ku+1)) = [L(j, j-kl .. j-1) real (kl),
   complex (2kl) | U(j, j+1 .. j+ku) / U(j,j) real (ku), complex (2ku) | 1/U(j,j) real,
   complex (2)], zeros outside the matrix; the right-hand sides carry kl zeros
   before and ku after, so the substitutions below run without bounds tests,
   the real and the complex one in the same sweep (their dependency chains
   overlap). */
PHGMG__PRIV void phgmg__gl3_pack_nopiv(phgmg_gl3 *s) {
  int n = s->N, kl = s->kl, ku = s->ku, kv = kl + ku, j, p;
  size_t P = 3 * (size_t)(kl + ku + 1), ld = (size_t)s->ldab;
  for (j = 0; j < n; ++j) {
    double *r = s->pk + (size_t)j * P;
    double *lr = r, *lc = r + kl, *ur = r + 3 * kl, *uc = r + 3 * kl + ku, *dg = r + 3 * (kl + ku);
    for (p = 0; p < kl; ++p) {
      int i = j - kl + p; /* L(j, i) in column i at row kv + j - i */
      size_t e = (size_t)(kv + j - i) + (size_t)i * ld;
      if (i < 0) { lr[p] = 0.0; lc[2 * p] = lc[2 * p + 1] = 0.0; continue; }
      lr[p] = s->AB1[e];
      lc[2 * p] = s->AB2[2 * e];
      lc[2 * p + 1] = s->AB2[2 * e + 1];
    }
    dg[0] = s->dinv1[j];
    dg[1] = s->dinv2[2 * j];
    dg[2] = s->dinv2[2 * j + 1];
    for (p = 0; p < ku; ++p) { /* U(j, i) / U(j, j), in column i at row kv + j - i */
      int i = j + 1 + p;
      size_t e = (size_t)(kv + j - i) + (size_t)i * ld;
      double vr, vi;
      if (i >= n) { ur[p] = 0.0; uc[2 * p] = uc[2 * p + 1] = 0.0; continue; }
      ur[p] = s->AB1[e] * dg[0];
      vr = s->AB2[2 * e];
      vi = s->AB2[2 * e + 1];
      uc[2 * p] = vr * dg[1] - vi * dg[2];
      uc[2 * p + 1] = vr * dg[2] + vi * dg[1];
    }
  }
}

/* One row of the forward (L) sweep of the packed solve, into t, tr, ti. */
#define PHGMG__GL3_FWD_ROW(j)                                                   \
  do {                                                                          \
    const double *lr = r, *lc = r + kl, *bb = b + (j) - kl, *zz = z + 2 * ((j) - kl); \
    t = b[j]; tr = z[2 * (j)]; ti = z[2 * (j) + 1];                             \
    for (p = 0; p < kl; ++p) { /* the newest unknown comes last: short chains */ \
      double cr = lc[2 * p], ci = lc[2 * p + 1], xr = zz[2 * p], xi = zz[2 * p + 1]; \
      t = PHGMG__FMA(-lr[p], bb[p], t);                                         \
      tr = PHGMG__FMA(-cr, xr, tr) + ci * xi;                                   \
      ti = PHGMG__FMA(-cr, xi, ti) - ci * xr;                                   \
    }                                                                           \
  } while (0)
/* One row of the backward (U) sweep. */
#define PHGMG__GL3_BWD_ROW(j)                                                   \
  do {                                                                          \
    const double *ur = r + 3 * kl, *uc = ur + ku, *dg = uc + 2 * ku;            \
    const double *bb = b + (j) + 1, *zz = z + 2 * ((j) + 1);                    \
    double br = z[2 * (j)], bi = z[2 * (j) + 1];                                \
    t = b[j] * dg[0]; tr = br * dg[1] - bi * dg[2]; ti = br * dg[2] + bi * dg[1]; \
    for (p = ku - 1; p >= 0; --p) {                                             \
      double cr = uc[2 * p], ci = uc[2 * p + 1], xr = zz[2 * p], xi = zz[2 * p + 1]; \
      t = PHGMG__FMA(-ur[p], bb[p], t);                                         \
      tr = PHGMG__FMA(-cr, xr, tr) + ci * xi;                                   \
      ti = PHGMG__FMA(-cr, xi, ti) - ci * xr;                                   \
    }                                                                           \
  } while (0)

/* Row j of a tail sweep: the values flushed below tau, stored; 1 if all are zero. */
PHGMG__PRIV int phgmg__gl3_put_flushed(double *b, double *z, int j, double t, double tr, double ti, double tau) {
  b[j] = fabs(t) < tau ? 0.0 : t;
  z[2 * j] = fabs(tr) < tau ? 0.0 : tr;
  z[2 * j + 1] = fabs(ti) < tau ? 0.0 : ti;
  return b[j] == 0.0 && z[2 * j] == 0.0 && z[2 * j + 1] == 0.0;
}

/* The right-hand sides vanish outside rows j0..j1 (a wave still far from the
   chain's ends): the forward sweep starts at j0, and beyond j1 it only carries
   the tail that L^{-1} spreads, which decays geometrically; those entries are
   flushed below s->ftau and the sweep stops after kl zero rows (all later rows
   are zero). The backward sweep does the same below j0 with ku zero rows. */
PHGMG__PRIV void phgmg__gl3_solve_packed(const phgmg_gl3 *s, double *b, double *z) {
  int n = s->N, kl = s->kl, ku = s->ku, j, p, j0, j1, run;
  size_t P = 3 * (size_t)(kl + ku + 1);
  const double tau = s->ftau;
  const double *r;
  double t, tr, ti;
  for (j1 = n - 1; j1 >= 0 && b[j1] == 0.0 && z[2 * j1] == 0.0 && z[2 * j1 + 1] == 0.0; --j1) {}
  if (j1 < 0) return; /* zero right-hand side, zero solution */
  for (j0 = 0; b[j0] == 0.0 && z[2 * j0] == 0.0 && z[2 * j0 + 1] == 0.0; ++j0) {}
  for (j = j0, r = s->pk + (size_t)j0 * P; j <= j1; ++j, r += P) {
    PHGMG__GL3_FWD_ROW(j);
    b[j] = t;
    z[2 * j] = tr;
    z[2 * j + 1] = ti;
  }
  for (run = 0; j < n && run < kl; ++j, r += P) { /* the tail below the support */
    PHGMG__GL3_FWD_ROW(j);
    run = phgmg__gl3_put_flushed(b, z, j, t, tr, ti, tau) ? run + 1 : 0;
  }
  for (j = j - 1; j >= j0; --j) { /* rows from j on are zero */
    r = s->pk + (size_t)j * P;
    PHGMG__GL3_BWD_ROW(j);
    b[j] = t;
    z[2 * j] = tr;
    z[2 * j + 1] = ti;
  }
  for (run = 0; j >= 0 && run < ku; --j) { /* the tail above the support */
    r = s->pk + (size_t)j * P;
    PHGMG__GL3_BWD_ROW(j);
    run = phgmg__gl3_put_flushed(b, z, j, t, tr, ti, tau) ? run + 1 : 0;
  }
}
#undef PHGMG__GL3_FWD_ROW
#undef PHGMG__GL3_BWD_ROW

/* Descriptor, banded: AB1 += sg E, AB2 += (sa + i sb) E (band LU layout). */
PHGMG__PRIV void phgmg__gl3_band_shift_e(phgmg_gl3 *s, double sg, double sa, double sb) {
  const int n = s->N, kv = s->kl + s->ku, ld = s->ldab;
  int d, i;
  for (d = 0; d < s->de.nd; ++d) {
    const int o = s->de.off[d], i0 = PHGMG__MAX(0, -o), i1 = PHGMG__MIN(n, n - o);
    const double *vd = s->de.v + (size_t)d * (size_t)n;
    for (i = i0; i < i1; ++i) {
      const size_t e = (size_t)(kv - o) + (size_t)(i + o) * (size_t)ld;
      s->AB1[e] += sg * vd[i];
      s->AB2[2 * e] += sa * vd[i];
      s->AB2[2 * e + 1] += sb * vd[i];
    }
  }
}

/* Dense: K1 (= -Jac) += sum_k a_k c_k (c_k^T Hess), Hess = Q + diag(dd)
   (SEPARABLE) or s->Hs (GENERAL, formed by the caller). One damper at a
   time, rows i and j. */
PHGMG__PRIV void phgmg__gl3_damp_jac_dense(phgmg_gl3 *s, const double *x) {
  const phgmg_ph_system *sys = &s->sys;
  const int N = s->N;
  const double *H = sys->nl == PHGMG_NL_GENERAL ? s->Hs : sys->Q;
  int k, c;
  phgmg__ph_grad(sys, x, s->dz, s->tmp);   /* the co-state z(x) */
  for (k = 0; k < sys->ndamp; ++k) {
    const int i = sys->damp_i[k], j = phgmg__damp_j(sys, k);
    double d[2], v;
    phgmg__damp_law(sys, k, phgmg__damp_s(sys, k, s->dz), d);
    if (d[1] == 0.0) continue;
    for (c = 0; c < N; ++c) {
      v = H[(size_t)i + (size_t)c * N] - (j >= 0 ? H[(size_t)j + (size_t)c * N] : 0.0);
      if (sys->nl == PHGMG_NL_SEPARABLE && c == i) v += s->dd[i];
      if (sys->nl == PHGMG_NL_SEPARABLE && c == j) v -= s->dd[j];
      s->K1[(size_t)i + (size_t)c * N] += d[1] * v;
      if (j >= 0) s->K1[(size_t)j + (size_t)c * N] -= d[1] * v;
    }
  }
}

/* Banded: the diagonals of sum_k a_k c_k c_k^T into s->ddm, and
   AB1 (= -Jac) += ddm Hess (Hess = dq + diag(dd), or dq + dh). */
PHGMG__PRIV void phgmg__gl3_damp_jac_band(phgmg_gl3 *s, const double *x) {
  const phgmg_ph_system *sys = &s->sys;
  const int N = s->N, w = s->ddm_w, kv = s->kl + s->ku;
  int k;
  memset(s->ddm.v, 0, sizeof(double) * (size_t)(2 * w + 1) * (size_t)N);
  phgmg__ph_grad(sys, x, s->dz, s->tmp);
  for (k = 0; k < sys->ndamp; ++k) {
    const int i = sys->damp_i[k], j = phgmg__damp_j(sys, k);
    double d[2];
    phgmg__damp_law(sys, k, phgmg__damp_s(sys, k, s->dz), d);
    s->ddm.v[(size_t)w * N + (size_t)i] += d[1];      /* (i, i): offset 0 */
    if (j < 0) continue;
    s->ddm.v[(size_t)w * N + (size_t)j] += d[1];
    s->ddm.v[(size_t)(j - i + w) * N + (size_t)i] -= d[1];   /* (i, j) */
    s->ddm.v[(size_t)(i - j + w) * N + (size_t)j] -= d[1];   /* (j, i) */
  }
  phgmg__dia_prod_band(&s->ddm, &s->dq, NULL, 1.0, s->AB1, s->ldab, kv);
  if (sys->nl == PHGMG_NL_SEPARABLE) phgmg__dia_prod_band(&s->ddm, NULL, s->dd, 1.0, s->AB1, s->ldab, kv);
  else if (sys->nl == PHGMG_NL_GENERAL) phgmg__dia_prod_band(&s->ddm, &s->dh, NULL, 1.0, s->AB1, s->ldab, kv);
}

/* (Re)factor the shifted Newton matrices at x. */
/* Sparse LU of both stage matrices (manual 8.12); PHGMG_ERR_SINGULAR when
   a static pivot was replaced or the factors grew beyond PHGMG_SPARSE_GROWTH. */
PHGMG__PRIV phgmg_result phgmg__gl3_sparse_factor(phgmg_gl3 *s, double sg, double sa, double sb) {
  const phgmg__spsym *S = s->sps;
  phgmg__sp_stage_values(S, s->sys.nl == PHGMG_NL_SEPARABLE ? s->dd : NULL, s->spM, s->spw);
  if (!phgmg__all_finite(s->spM, (size_t)S->k_p[s->N])) return PHGMG_ERR_NANINF;
  phgmg__sp_factor(S, &s->spf1, s->spM, sg, 0.0, PHGMG_SPARSE_PIVTOL);
  if (s->spf1.nstatic || !(s->spf1.growth <= PHGMG_SPARSE_GROWTH)) return PHGMG_ERR_SINGULAR;
  phgmg__sp_factor(S, &s->spf2, s->spM, sa, sb, PHGMG_SPARSE_PIVTOL);
  if (s->spf2.nstatic || !(s->spf2.growth <= PHGMG_SPARSE_GROWTH)) return PHGMG_ERR_SINGULAR;
  return PHGMG_OK;
}

/* SPARSE storage: the diagonals of J - R and Q (and E) through band copies made
   here (the system has none) and freed after. */
PHGMG__PRIV phgmg_result phgmg__gl3_sparse_dia(phgmg_gl3 *s) {
  const phgmg_ph_sparse *sp = s->sys.sparse;
  const int N = s->N, kb = s->sys.kb;
  double *b[4] = {NULL, NULL, NULL, NULL};
  int a;
  phgmg_result rc = PHGMG_OK;
  for (a = 0; a < (sp->cp[3] ? 4 : 3); ++a)
    if (!(b[a] = phgmg__sparse_band_copy(sp, a, &s->al))) rc = PHGMG_ERR_NOMEM;
  if (rc == PHGMG_OK) rc = phgmg__dia_build(&s->al, &s->djr, N, kb, b[0], b[1], 0, 0);
  if (rc == PHGMG_OK) rc = phgmg__dia_build(&s->al, &s->dq, N, kb, b[2], NULL, 1, 0);
  if (rc == PHGMG_OK && b[3]) rc = phgmg__dia_build(&s->al, &s->de, N, kb, b[3], NULL, 1, 0);
  for (a = 0; a < 4; ++a) phgmg__free(&s->al, b[a]);
  return rc;
}

/* Give up the sparse factors for the band LU with partial pivoting. */
PHGMG__PRIV phgmg_result phgmg__gl3_sparse_fallback(phgmg_gl3 *s) {
  phgmg_result rc;
  phgmg__spnum_free(&s->al, &s->spf1);
  phgmg__spnum_free(&s->al, &s->spf2);
  s->mode = PHGMG__GL3_BANDED;
  s->sps = NULL; /* from here exactly the band stepper */
  s->st.sparse_lu = 0;
  s->st.band_fallback = 1;
  phgmg__dia_free(&s->al, &s->dq);
  if (s->sys.storage == PHGMG_SPARSE) {
    rc = phgmg__gl3_sparse_dia(s);
  } else {
    rc = phgmg__dia_build(&s->al, &s->djr, s->N, s->sys.kb, s->sys.J, s->sys.R, 0, 0);
    if (rc == PHGMG_OK) rc = phgmg__dia_build(&s->al, &s->dq, s->N, s->sys.kb, s->sys.Q, NULL, 1, 0);
  }
  if (rc == PHGMG_OK) rc = phgmg__gl3_setup_band_lu(s);
  if (rc != PHGMG_OK) return rc;
  phgmg__free(&s->al, s->r1buf);
  phgmg__free(&s->al, s->rcbuf);
  s->r1buf = s->rcbuf = NULL;
  return phgmg__gl3_setup_buffers(s);
}

PHGMG__PRIV phgmg_result phgmg__gl3_factor(phgmg_gl3 *s, const double *x) {
  const phgmg_ph_system *sys = &s->sys;
  int N = s->N, i, j, k;
  double sg = s->gam / s->h, sa = s->alp / s->h, sb = -s->bet / s->h;
  phgmg_result rc;
  s->st.factorizations++;
  if (sys->nl == PHGMG_NL_SEPARABLE) {
    for (i = 0; i < N; ++i) s->dd[i] = 0.0;
    for (k = 0; k < sys->nsep; ++k) {
      int ix = sys->sep_idx[k];
      s->dd[ix] += (sys->sep_w ? sys->sep_w[k] : 1.0) * phgmg__ph_phi(sys, k, x[ix], 2);
    }
  }
  if (s->mode == PHGMG__GL3_CALLBACK) {
    rc = sys->shifted_factor(sg, 0.0, x, sys->shifted_user);
    if (rc == PHGMG_OK) rc = sys->shifted_factor(sa, sb, x, sys->shifted_user);
    return rc;
  }
  if (s->mode == PHGMG__GL3_SPARSE) {
    rc = phgmg__gl3_sparse_factor(s, sg, sa, sb);
    if (rc != PHGMG_ERR_SINGULAR) return rc;
    rc = phgmg__gl3_sparse_fallback(s); /* static pivots not good enough: band LU */
    if (rc != PHGMG_OK) return rc;
  }
  if (s->mode == PHGMG__GL3_DENSE) {
    size_t NN = (size_t)N * (size_t)N, e;
    /* K1 = -Jac */
    if (sys->nl == PHGMG_NL_GENERAL) {
      sys->hess_nl(x, s->Hs, sys->user);
      for (e = 0; e < NN; ++e) s->Hs[e] += sys->Q[e];
      phgmg_gemm('N', 'N', N, N, N, -1.0, s->JR, N, s->Hs, N, 0.0, s->K1, N);
    } else {
      for (e = 0; e < NN; ++e) s->K1[e] = -s->JRQ[e];
      if (sys->nl == PHGMG_NL_SEPARABLE)
        for (j = 0; j < N; ++j) {
          double dj = s->dd[j];
          const double *jc = s->JR + (size_t)j * (size_t)N;
          double *kc = s->K1 + (size_t)j * (size_t)N;
          if (dj == 0.0) continue;
          for (i = 0; i < N; ++i) kc[i] -= jc[i] * dj;
        }
    }
    if (sys->ndamp) phgmg__gl3_damp_jac_dense(s, x);
    for (e = 0; e < NN; ++e) { s->K2[2 * e] = s->K1[e]; s->K2[2 * e + 1] = 0.0; }
    for (i = 0; i < N; ++i) {
      size_t d = (size_t)i * (size_t)(N + 1);
      s->K1[d] += sg;
      s->K2[2 * d] += sa;
      s->K2[2 * d + 1] = sb;
    }
    if (sys->E) phgmg__gl3_dense_shift_e(s, s->K1, s->K2);
    rc = phgmg_lu_factor(N, s->K1, N, s->ip1);
    if (rc == PHGMG_OK) rc = phgmg_zlu_factor(N, s->K2, N, s->ip2);
    return rc;
  }
  /* banded */
  {
    int kv = s->kl + s->ku, ld = s->ldab;
    size_t tot = (size_t)ld * (size_t)N, e;
    memset(s->AB1, 0, sizeof(double) * tot);
    phgmg__dia_prod_band(&s->djr, &s->dq, NULL, -1.0, s->AB1, ld, kv);
    if (sys->nl == PHGMG_NL_SEPARABLE) {
      phgmg__dia_prod_band(&s->djr, NULL, s->dd, -1.0, s->AB1, ld, kv);
    } else if (sys->nl == PHGMG_NL_GENERAL) {
      sys->hess_nl(x, s->hband, sys->user);
      phgmg__dia_refill(&s->dh, sys->kb, s->hband);
      phgmg__dia_prod_band(&s->djr, &s->dh, NULL, -1.0, s->AB1, ld, kv);
    }
    if (sys->ndamp) phgmg__gl3_damp_jac_band(s, x);
    for (e = 0; e < tot; ++e) { s->AB2[2 * e] = s->AB1[e]; s->AB2[2 * e + 1] = 0.0; }
    if (sys->E) { /* descriptor: sigma E in place of sigma I */
      phgmg__gl3_band_shift_e(s, sg, sa, sb);
    } else {
      for (j = 0; j < N; ++j) {
        size_t d = (size_t)kv + (size_t)j * (size_t)ld;
        s->AB1[d] += sg;
        s->AB2[2 * d] += sa;
        s->AB2[2 * d + 1] = sb;
      }
    }
    if (!phgmg__all_finite(s->AB1, tot)) return PHGMG_ERR_NANINF;
    rc = phgmg__gb_factor(N, s->kl, s->ku, s->AB1, ld, s->ip1, s->dinv1, &s->ue1);
    if (rc == PHGMG_OK)
      rc = phgmg__zgb_factor(N, s->kl, s->ku, s->AB2, ld, s->ip2, s->dinv2, &s->ue2);
    s->nopiv1 = s->nopiv2 = 1;
    for (j = 0; j < N && rc == PHGMG_OK; ++j) {
      if (s->ip1[j] != j) s->nopiv1 = 0;
      if (s->ip2[j] != j) s->nopiv2 = 0;
    }
    if (rc == PHGMG_OK && s->nopiv1 && s->nopiv2) phgmg__gl3_pack_nopiv(s);
    return rc;
  }
}

/* Solve with the real (K1) and the complex (K2) shifted matrix. */
PHGMG__PRIV void phgmg__gl3_solve_real(phgmg_gl3 *s, double *r) {
  if (s->mode == PHGMG__GL3_SPARSE)
    phgmg__sp_solve(s->sps, &s->spf1, r);
  else if (s->mode == PHGMG__GL3_DENSE)
    phgmg_lu_solve('N', s->N, s->K1, s->N, s->ip1, 1, r, s->N);
  else if (s->mode == PHGMG__GL3_BANDED)
    phgmg__gb_solve('N', s->N, s->kl, s->ku, s->ue1, s->AB1, s->ldab, s->ip1, s->dinv1, r);
  else
    s->sys.shifted_solve(s->gam / s->h, 0.0, r, s->sys.shifted_user);
}
PHGMG__PRIV void phgmg__gl3_solve_cplx(phgmg_gl3 *s, double *r) {
  if (s->mode == PHGMG__GL3_SPARSE)
    phgmg__sp_solve(s->sps, &s->spf2, r);
  else if (s->mode == PHGMG__GL3_DENSE)
    phgmg_zlu_solve(s->N, s->K2, s->N, s->ip2, 1, r, s->N);
  else if (s->mode == PHGMG__GL3_BANDED)
    phgmg__zgb_solve(s->N, s->kl, s->ku, s->ue2, s->AB2, s->ldab, s->ip2, s->dinv2, r);
  else
    s->sys.shifted_solve(s->alp / s->h, -s->bet / s->h, r, s->sys.shifted_user);
}

/* Simplified Newton on the transformed stage system from the guess in s->Z.
   fresh: the factors belong to this x (no early abort). On success s->Z, G, F
   hold the converged stages. */
PHGMG__PRIV phgmg_result phgmg__gl3_newton(phgmg_gl3 *s, const double *x, int fresh,
                                           double *theta_max, double *res_out) {
  int N = s->N, it = 0, ndiv = 0, i;
  double h = s->h, ih = 1.0 / s->h, res_prev = 0.0, theta = 0.0, tol = s->tol;
  double *Z0 = s->Z, *Z1 = s->Z + N, *Z2 = s->Z + 2 * (size_t)N;
  double *W0 = s->W, *W1 = s->W + N, *W2 = s->W + 2 * (size_t)N;
  const double *T = s->T, *Ti = s->Ti, *A = s->A;
  *theta_max = 0.0;
  if (s->tol_rel) {   /* the default tolerance follows states and stage increments larger than 1 */
    double xm = 1.0;
    for (i = 0; i < N; ++i) xm = PHGMG__MAX(xm, fabs(x[i]));
    tol *= xm;
  }
  for (i = 0; i < N; ++i) {
    double z0 = Z0[i], z1 = Z1[i], z2 = Z2[i];
    W0[i] = Ti[0] * z0 + Ti[1] * z1 + Ti[2] * z2;
    W1[i] = Ti[3] * z0 + Ti[4] * z1 + Ti[5] * z2;
    W2[i] = Ti[6] * z0 + Ti[7] * z1 + Ti[8] * z2;
  }
  for (;;) {
    const double *F0 = s->F, *F1 = s->F + N, *F2 = s->F + 2 * (size_t)N;
    double res = 0.0, chk = 0.0, zm = 0.0;
    double *r1 = s->r1, *rc = s->rc;
    const double a00 = h * A[0], a01 = h * A[1], a02 = h * A[2], a10 = h * A[3], a11 = h * A[4],
                 a12 = h * A[5], a20 = h * A[6], a21 = h * A[7], a22 = h * A[8];
    const double t00 = Ti[0], t01 = Ti[1], t02 = Ti[2], t10 = Ti[3], t11 = Ti[4], t12 = Ti[5],
                 t20 = Ti[6], t21 = Ti[7], t22 = Ti[8];
    const double gih = s->gam * ih, aih = s->alp * ih, bih = s->bet * ih;
    /* descriptor: E Z and E W in place of Z and W (the same vectors without E) */
    const double *M0 = Z0, *M1 = Z1, *M2 = Z2, *V0 = W0, *V1 = W1, *V2 = W2;
    phgmg__gl3_eval(s, x);
    if (s->damp_bad) { s->damp_bad = 0; return PHGMG_ERR_DAMPER; }
    if (s->EZ) {
      phgmg__gl3_e_times(s, s->Z, s->EZ);
      M0 = s->EZ; M1 = s->EZ + N; M2 = s->EZ + 2 * (size_t)N;
    }
    for (i = 0; i < N; ++i) { /* stage residual (I x E) Z - h (A x I) F */
      double f0 = F0[i], f1 = F1[i], f2 = F2[i], e0, e1, e2;
      e0 = fabs(M0[i] - PHGMG__FMA(a00, f0, PHGMG__FMA(a01, f1, a02 * f2)));
      e1 = fabs(M1[i] - PHGMG__FMA(a10, f0, PHGMG__FMA(a11, f1, a12 * f2)));
      e2 = fabs(M2[i] - PHGMG__FMA(a20, f0, PHGMG__FMA(a21, f1, a22 * f2)));
      chk += (e0 + e1) + e2; /* NaN/Inf detection */
      zm = PHGMG__MAX(zm, PHGMG__MAX(fabs(Z0[i]), PHGMG__MAX(fabs(Z1[i]), fabs(Z2[i]))));
      res = e0 > res ? e0 : res;
      res = e1 > res ? e1 : res;
      res = e2 > res ? e2 : res;
    }
    if (chk - chk != 0.0) return PHGMG_ERR_NANINF;
    if (it > 0) {
      theta = res_prev > 0.0 ? res / res_prev : 0.0;
      if (theta > *theta_max) *theta_max = theta;
      ndiv = theta >= 1.0 ? ndiv + 1 : 0;
    }
    *res_out = res;
    if (it >= 1 && res <= (s->tol_rel ? PHGMG__MAX(tol, s->tol * zm) : tol)) return PHGMG_OK;
    if (it >= s->max_iter) return PHGMG_ERR_NOT_CONVERGED;
    if (it >= 1 && theta >= 1.0 && !fresh) return PHGMG_ERR_NOT_CONVERGED;
    if (ndiv >= 2) return PHGMG_ERR_NOT_CONVERGED;
    if (s->EZ) {
      phgmg__gl3_e_times(s, s->W, s->EZ);
      V0 = s->EZ; V1 = s->EZ + N; V2 = s->EZ + 2 * (size_t)N;
    }
    for (i = 0; i < N; ++i) { /* Newton right-hand sides in the transformed variables */
      double f0 = F0[i], f1 = F1[i], f2 = F2[i], w0 = V0[i], w1 = V1[i], w2 = V2[i];
      r1[i] = PHGMG__FMA(t00, f0, PHGMG__FMA(t01, f1, PHGMG__FMA(t02, f2, -gih * w0)));
      rc[2 * i] =
          PHGMG__FMA(t10, f0, PHGMG__FMA(t11, f1, PHGMG__FMA(t12, f2, -(aih * w1 + bih * w2))));
      rc[2 * i + 1] =
          PHGMG__FMA(t20, f0, PHGMG__FMA(t21, f1, PHGMG__FMA(t22, f2, bih * w1 - aih * w2)));
    }
    if (s->mode == PHGMG__GL3_BANDED && s->nopiv1 && s->nopiv2) {
      phgmg__gl3_solve_packed(s, s->r1, s->rc);
    } else { /* (the packed solve flushes its tails itself) */
      phgmg__gl3_solve_real(s, s->r1);
      phgmg__gl3_solve_cplx(s, s->rc);
      if (s->flush) {
        phgmg__flush_tiny(s->r1, (size_t)N, s->ftau);
        phgmg__flush_tiny(s->rc, 2 * (size_t)N, s->ftau);
      }
    }
    {
      const double T00 = T[0], T01 = T[1], T02 = T[2], T10 = T[3], T11 = T[4], T12 = T[5],
                   T20 = T[6], T21 = T[7], T22 = T[8];
      const double *d1 = s->r1, *dc = s->rc;
      for (i = 0; i < N; ++i) {
        double w0 = W0[i] + d1[i], w1 = W1[i] + dc[2 * i], w2 = W2[i] + dc[2 * i + 1];
        W0[i] = w0; W1[i] = w1; W2[i] = w2;
        Z0[i] = PHGMG__FMA(T00, w0, PHGMG__FMA(T01, w1, T02 * w2));
        Z1[i] = PHGMG__FMA(T10, w0, PHGMG__FMA(T11, w1, T12 * w2));
        Z2[i] = PHGMG__FMA(T20, w0, PHGMG__FMA(T21, w1, T22 * w2));
      }
    }
    res_prev = res;
    ++it;
    s->st.newton_iters++;
  }
}

/* The same with feedthrough: y_i = (B + P)^T z_i + (S + N) u_i supplied,
   [z; u]^T [[R, P], [P^T, S]] [z; u] = z^T R z + 2 z^T P u + u^T S u dissipated. */
PHGMG__PRIV void phgmg__gl3_energy_feedthrough(phgmg_gl3 *s, double energy_inc[2]) {
  const phgmg_ph_system *sys = &s->sys;
  const int N = s->N, m = s->m;
  const double *Bo = s->Bout ? s->Bout : sys->B;
  int st, k, l, i;
  double sup = 0.0, dis = 0.0;
  for (st = 0; st < 3; ++st) {
    const double *g = s->G + (size_t)st * (size_t)N, *u = s->U + (size_t)st * (size_t)m;
    double yu = 0.0, d = phgmg__ph_quad(sys, sys->R, g, g);
    for (k = 0; k < m; ++k) {
      double yk = 0.0, pk = 0.0;
      for (i = 0; i < N; ++i) yk += Bo[(size_t)i + (size_t)k * (size_t)N] * g[i];
      if (sys->P)
        for (i = 0; i < N; ++i) pk += sys->P[(size_t)i + (size_t)k * (size_t)N] * g[i];
      for (l = 0; l < m; ++l) {
        const double sk = sys->S ? sys->S[k + (size_t)l * m] : 0.0, nk = sys->Nskew ? sys->Nskew[k + (size_t)l * m] : 0.0;
        yk += (sk + nk) * u[l];
        d += u[k] * sk * u[l];
      }
      yu += yk * u[k];
      d += 2.0 * pk * u[k];
    }
    sup += s->b[st] * yu;
    dis += s->b[st] * d;
  }
  energy_inc[0] = s->h * sup;
  energy_inc[1] = s->h * dis;
}

/* Dampers: h sum_i b_i sum_k s_k rho_k(s_k) at the stage co-states, added
   to the dissipated energy. */
PHGMG__PRIV void phgmg__gl3_energy_damp(phgmg_gl3 *s, double energy_inc[2]) {
  double dis = 0.0;
  int st;
  if (!s->sys.ndamp) return;
  for (st = 0; st < 3; ++st) dis += s->b[st] * phgmg__damp_apply(&s->sys, s->G + (size_t)st * (size_t)s->N, 0.0, NULL);
  energy_inc[1] += s->h * dis;
}

/* Supplied and dissipated energy over a step from the stage gradients s->G. */
PHGMG__PRIV void phgmg__gl3_energy(phgmg_gl3 *s, double energy_inc[2]) {
  const phgmg_ph_system *sys = &s->sys;
  int N = s->N, m = s->m, st, k, i;
  double sup = 0.0, dis = 0.0;
  if (sys->P || sys->S || sys->Nskew) { phgmg__gl3_energy_feedthrough(s, energy_inc); phgmg__gl3_energy_damp(s, energy_inc); return; }
  for (st = 0; st < 3; ++st) {
    const double *g = s->G + (size_t)st * (size_t)N, *u = s->U + (size_t)st * (size_t)m;
    double yu = 0.0;
    for (k = 0; k < m; ++k) {
      const double *bk = sys->B + (size_t)k * (size_t)N;
      double yk = 0.0;
      for (i = 0; i < N; ++i) yk += bk[i] * g[i];
      yu += yk * u[k];
    }
    sup += s->b[st] * yu;
    dis += s->b[st] * phgmg__ph_quad(sys, sys->R, g, g);
  }
  energy_inc[0] = s->h * sup;
  energy_inc[1] = s->h * dis;
  phgmg__gl3_energy_damp(s, energy_inc);
}

PHGMG__PRIV phgmg_result phgmg__gl3_step_map(phgmg_gl3 *s, const double *x, double energy_inc[2]) {
  int N = s->N, m = s->m, st;
  size_t NN = (size_t)N * (size_t)N;
  phgmg_gemv('N', N, N, 1.0, s->Phi, N, x, 0.0, s->xnew);
  phgmg_gemv('N', N, 3 * m, 1.0, s->Gam, N, s->U, 1.0, s->xnew);
  if (!phgmg__all_finite(s->xnew, (size_t)N)) return PHGMG_ERR_NANINF;
  if (energy_inc) {
    for (st = 0; st < 3; ++st) {
      double *g = s->G + (size_t)st * (size_t)N;
      phgmg_gemv('N', N, N, 1.0, s->GX + (size_t)st * NN, N, x, 0.0, g);
      phgmg_gemv('N', N, 3 * m, 1.0, s->GU + (size_t)st * (size_t)N * 3 * (size_t)m, N, s->U,
                 1.0, g);
    }
    phgmg__gl3_energy(s, energy_inc);
  }
  return PHGMG_OK;
}

/* Starting guess into s->Z: the previous step's collocation polynomial
   extrapolated to the new stage times, or zero. */
PHGMG__PRIV void phgmg__gl3_guess(phgmg_gl3 *s, int cont) {
  int N = s->N, st, i;
  if (!cont) {
    memset(s->Z, 0, sizeof(double) * 3 * (size_t)N);
    return;
  }
  for (st = 0; st < 3; ++st) {
    const double *P0 = s->Zprev, *P1 = s->Zprev + N, *P2 = s->Zprev + 2 * (size_t)N;
    double e0 = s->E[st * 3], e1 = s->E[st * 3 + 1], e2 = s->E[st * 3 + 2];
    double *z = s->Z + (size_t)st * (size_t)N;
    for (i = 0; i < N; ++i) z[i] = e0 * P0[i] + e1 * P1[i] + e2 * P2[i];
  }
}

PHGMG_DEF phgmg_result phgmg_gl3_step(phgmg_gl3 *s, double t, double *x, phgmg_input_fn uf,
                                      void *uuser, double energy_inc[2]) {
  int N, m, st, i, fresh = 0, cont;
  double theta = 0.0, res = 0.0;
  phgmg_result rc;
  if (!s || !x) return PHGMG_ERR_INVALID_ARG;
  N = s->N;
  m = s->m;
  for (st = 0; st < 3; ++st) {
    double *u = s->U + (size_t)st * (size_t)m;
    if (uf) uf(t + s->c[st] * s->h, u, uuser);
    else for (i = 0; i < m; ++i) u[i] = 0.0;
  }
  if (!phgmg__all_finite(s->U, 3 * (size_t)m)) return PHGMG_ERR_NANINF;
  if (s->mode == PHGMG__GL3_MAP) {
    rc = phgmg__gl3_step_map(s, x, energy_inc);
    if (rc != PHGMG_OK) { s->st.failures++; return rc; }
    if (s->flush) phgmg__flush_tiny_rel(s->xnew, (size_t)N); /* O(N) against the O(N^2) map */
    memcpy(x, s->xnew, sizeof(double) * (size_t)N);
    s->st.steps++;
    return PHGMG_OK;
  }
  /* starting guess: extrapolate the previous collocation polynomial when this
     step continues the previous one */
  cont = s->have_prev && fabs(t - s->tend) <= 1e-6 * s->h + 4.0 * PHGMG__EPS * fabs(t) &&
         memcmp(x, s->xend, sizeof(double) * (size_t)N) == 0;
  if (s->need_factor) {
    rc = phgmg__gl3_factor(s, x);
    if (rc != PHGMG_OK) { s->st.failures++; return rc; }
    s->need_factor = 0;
    fresh = 1;
  }
  if (s->linear) fresh = 1; /* the Jacobian does not depend on x */
  if (s->flush) { /* flush threshold from ||x||_inf (known when continuing) */
    double am = 0.0;
    if (cont) am = s->xamax;
    else
      for (i = 0; i < N; ++i) am = fabs(x[i]) > am ? fabs(x[i]) : am;
    s->ftau = PHGMG__MAX(PHGMG__DBL_MIN, PHGMG_GL3_FLUSH_REL * am);
  }
  phgmg__gl3_guess(s, cont);
  rc = phgmg__gl3_newton(s, x, fresh, &theta, &res);
  if (rc != PHGMG_OK && !fresh) {
    s->st.failures++;
    rc = phgmg__gl3_factor(s, x);
    if (rc != PHGMG_OK) { s->need_factor = 1; s->st.failures++; return rc; }
    fresh = 1;
    phgmg__gl3_guess(s, cont);
    rc = phgmg__gl3_newton(s, x, fresh, &theta, &res);
  }
  if (rc != PHGMG_OK) { s->st.failures++; return rc; }
  if (!s->linear && theta > s->contraction) s->need_factor = 1;
  {
    const double *F0 = s->F, *F1 = s->F + N, *F2 = s->F + 2 * (size_t)N;
    double hb0 = s->h * s->b[0], hb1 = s->h * s->b[1], hb2 = s->h * s->b[2], chk = 0.0, am = 0.0;
    const double tau = s->ftau; /* the new state is flushed with this step's threshold */
    const double *Z0 = s->Z, *Z1 = s->Z + N, *Z2 = s->Z + 2 * (size_t)N;
    for (i = 0; i < N; ++i) {
      /* descriptor: x + sum d_i Z_i (= x + h sum b_i E^{-1} F_i at the solution) */
      double v = s->EZ ? x[i] + (s->d[0] * Z0[i] + s->d[1] * Z1[i] + s->d[2] * Z2[i])
                       : x[i] + (hb0 * F0[i] + hb1 * F1[i] + hb2 * F2[i]),
             a = fabs(v);
      s->xnew[i] = a < tau ? 0.0 : v;
      chk += v;
      am = a > am ? a : am;
    }
    if (chk - chk != 0.0) { s->st.failures++; return PHGMG_ERR_NANINF; }
    s->xamax = am;
  }
  if (energy_inc) phgmg__gl3_energy(s, energy_inc);
  { /* keep the converged stages for the next guess (Newton updates cancel
       to tiny values at the edge of the support: flushed) */
    double *t3 = s->Zprev;
    if (s->flush) phgmg__flush_tiny(s->Z, 3 * (size_t)N, s->ftau);
    s->Zprev = s->Z;
    s->Z = t3;
  }
  memcpy(s->xend, s->xnew, sizeof(double) * (size_t)N);
  s->tend = t + s->h;
  s->have_prev = 1;
  memcpy(x, s->xnew, sizeof(double) * (size_t)N);
  s->st.steps++;
  if (res > s->st.max_residual) s->st.max_residual = res;
  return PHGMG_OK;
}

/* Feedthrough part of the output: y += P^T z + (S + N) u(t) (u into tmp, m). */
PHGMG__PRIV void phgmg__output_feedthrough(const phgmg_ph_system *sys, const double *z, double t, phgmg_input_fn uf,
                                          void *uuser, double *tmp, double *y) {
  const int N = sys->N, m = sys->m;
  int k, l, i;
  if (uf) uf(t, tmp, uuser);
  else for (k = 0; k < m; ++k) tmp[k] = 0.0;
  for (k = 0; k < m; ++k) {
    double acc = 0.0;
    if (sys->P)
      for (i = 0; i < N; ++i) acc += sys->P[(size_t)i + (size_t)k * (size_t)N] * z[i];
    for (l = 0; l < m; ++l)
      acc += ((sys->S ? sys->S[k + (size_t)l * m] : 0.0) + (sys->Nskew ? sys->Nskew[k + (size_t)l * m] : 0.0)) * tmp[l];
    y[k] += acc;
  }
}

PHGMG_DEF phgmg_result phgmg_simulate_run(const phgmg_ph_system *sys, const phgmg_run *run,
                                          const phgmg_gl3_opts *opts, phgmg_sim_out *out,
                                          const phgmg_allocator *alloc) {
  phgmg_sim_out none;
  double *z = NULL;
  phgmg_result rc;
  if (!run || !sys) return PHGMG_ERR_INVALID_ARG;
  if (!out) { memset(&none, 0, sizeof none); out = &none; }
  out->steps_done = 0;
  if (!run->x0 && sys->N > 0) {   /* x0 = 0 */
    z = phgmg__dalloc(alloc, (size_t)sys->N);
    if (!z) return PHGMG_ERR_NOMEM;
    memset(z, 0, sizeof(double) * (size_t)sys->N);
  }
  rc = phgmg_simulate(sys, run->x0 ? run->x0 : z, run->t0, run->dt, run->nsteps, run->u, run->user, opts, out->X,
                      out->Y, out->energy, out->stats, &out->steps_done, alloc);
  phgmg__free(alloc, z);
  return rc;
}

/* One run of nsteps steps from x0 at t0 on the stepper s (of sys, its step
   dt): the loop of phgmg_simulate. The run starts afresh (no extrapolation
   from an earlier run); the factors s holds are reused (a linear model
   factors once for all the runs of one stepper; a nonlinear one refactors
   by its contraction rule). stats: this run's (s's totals keep counting). */
PHGMG__PRIV phgmg_result phgmg__simulate_on(phgmg_gl3 *s, const phgmg_ph_system *sys, const double *x0,
                                            double t0, double dt, int nsteps, phgmg_input_fn uf, void *uuser,
                                            double *X, double *Y, const phgmg_energy *energy,
                                            phgmg_gl3_stats *stats, int *steps_done,
                                            const phgmg_allocator *alloc) {
  phgmg_result rc = PHGMG_OK;
  double *x = NULL, *g = NULL, *tmp = NULL;
  int N = sys->N, m = sys->m, n, i, k, done = 0;
  phgmg_gl3_stats tot = s->st;
  memset(&s->st, 0, sizeof s->st);
  s->st.sparse_lu = tot.sparse_lu;
  s->st.band_fallback = tot.band_fallback;
  s->have_prev = 0;
  x = phgmg__dalloc(alloc, (size_t)N);
  g = phgmg__dalloc(alloc, (size_t)N);
  tmp = phgmg__dalloc(alloc, (size_t)N);
  if (!x || !g || !tmp) { rc = PHGMG_ERR_NOMEM; goto done; }
  memcpy(x, x0, sizeof(double) * (size_t)N);
  for (n = 0;; ++n) {
    /* record grid point n */
    if (X) memcpy(X + (size_t)n * (size_t)N, x, sizeof(double) * (size_t)N);
    if (Y) {
      phgmg__ph_grad(sys, x, g, tmp);
      for (k = 0; k < m; ++k) {
        const double *bk = sys->B + (size_t)k * (size_t)N;
        double acc = 0.0;
        for (i = 0; i < N; ++i) acc += bk[i] * g[i];
        Y[(size_t)k + (size_t)n * (size_t)m] = acc;
      }
      if (sys->P || sys->S || sys->Nskew)
        phgmg__output_feedthrough(sys, g, t0 + (double)n * dt, uf, uuser, tmp, Y + (size_t)n * (size_t)m);
    }
    if (energy) {
      energy->H[n] = phgmg_ph_hamiltonian(sys, x);
      if (n == 0) { energy->S[0] = 0.0; energy->D[0] = 0.0; }
    }
    if (n == nsteps) break;
    {
      double inc[2] = {0.0, 0.0};
      rc = phgmg_gl3_step(s, t0 + (double)n * dt, x, uf, uuser, energy ? inc : NULL);
      if (rc != PHGMG_OK) break;
      if (energy) {
        energy->S[n + 1] = energy->S[n] + inc[0];
        energy->D[n + 1] = energy->D[n] + inc[1];
      }
      ++done;
    }
  }
done:
  if (stats) *stats = s->st;
  tot.steps += s->st.steps; tot.newton_iters += s->st.newton_iters;
  tot.factorizations += s->st.factorizations; tot.rhs_evals += s->st.rhs_evals;
  tot.failures += s->st.failures; tot.max_residual = PHGMG__MAX(tot.max_residual, s->st.max_residual);
  tot.sparse_lu = s->st.sparse_lu; tot.band_fallback = s->st.band_fallback;
  s->st = tot;
  if (steps_done) *steps_done = done;
  phgmg__free(alloc, x);
  phgmg__free(alloc, g);
  phgmg__free(alloc, tmp);
  return rc;
}

PHGMG_DEF phgmg_result phgmg_simulate(const phgmg_ph_system *sys, const double *x0, double t0,
                                      double dt, int nsteps, phgmg_input_fn uf, void *uuser,
                                      const phgmg_gl3_opts *opts, double *X, double *Y,
                                      const phgmg_energy *energy, phgmg_gl3_stats *stats,
                                      int *steps_done, const phgmg_allocator *alloc) {
  phgmg_gl3 *s = NULL;
  phgmg_result rc;
  if (steps_done) *steps_done = 0;
  if (stats) memset(stats, 0, sizeof *stats);
  if (!sys || !x0 || nsteps < 0) return PHGMG_ERR_INVALID_ARG;
  if (energy && (!energy->H || !energy->S || !energy->D)) return PHGMG_ERR_INVALID_ARG;
  if (sys->E && phgmg__e_algebraic(sys, alloc) != 0)   /* index one (1.8), or no memory */
    return phgmg__simulate_dae(sys, x0, t0, dt, nsteps, uf, uuser, opts, X, Y, energy, stats, steps_done, alloc);
  rc = phgmg_gl3_create(&s, sys, dt, opts, alloc);
  if (rc != PHGMG_OK) return rc;
  rc = phgmg__simulate_on(s, sys, x0, t0, dt, nsteps, uf, uuser, X, Y, energy, stats, steps_done, alloc);
  phgmg_gl3_destroy(s);
  return rc;
}

#endif /* PHGMG_NO_OFFLINE */

/* >>online (implementation) ============================================== */
/* Everything here is in phgmg_real, allocation-free and N-independent. */
#if PHGMG_REAL_IS_FLOAT
#define PHGMG__RABS(x) fabsf(x)
#define PHGMG__REXP(x) expf(x)
#define PHGMG__RSQRT(x) sqrtf(x)
#define PHGMG__REPS 1.1920929e-07f
#else
#define PHGMG__RABS(x) fabs(x)
#define PHGMG__REXP(x) exp(x)
#define PHGMG__RSQRT(x) sqrt(x)
#define PHGMG__REPS 2.220446049250313e-16
#endif
#define PHGMG__R(x) ((phgmg_real)(x))
#define PHGMG__ONLINE static PHGMG__UNUSED
/* base + o, or NULL when only sizes are wanted (NULL + o is undefined). */
#define PHGMG__CARVE(base, o) ((base) ? (base) + (o) : NULL)

PHGMG__ONLINE int phgmg__r_finite(const phgmg_real *a, int n) {
  phgmg_real acc = PHGMG__R(0);
  int i;
  for (i = 0; i < n; ++i) acc += a[i] * PHGMG__R(0);
  return acc == PHGMG__R(0);
}

/* y[0..n) -= a[0..n) * s. Four entries per step as straight-line code: the
   compiler's SLP vectoriser turns each group into vector operations (no
   runtime alias checks needed; the loop form stays scalar at -O2 because y
   might alias a), with the same operations per entry. */
PHGMG__ONLINE void phgmg__r_axmy(int n, phgmg_real s, const phgmg_real *a, phgmg_real *y) {
  int i = 0;
  for (; i + 4 <= n; i += 4) {
    const phgmg_real a0 = a[i], a1 = a[i + 1], a2 = a[i + 2], a3 = a[i + 3];
    const phgmg_real y0 = y[i], y1 = y[i + 1], y2 = y[i + 2], y3 = y[i + 3];
    y[i] = y0 - a0 * s; y[i + 1] = y1 - a1 * s; y[i + 2] = y2 - a2 * s; y[i + 3] = y3 - a3 * s;
  }
  for (; i < n; ++i) y[i] -= a[i] * s;
}

/* y = A x (A: rows x cols, column-major, ld = rows); beta = 0 or 1 (accumulate).
   The small online kernels take four columns per sweep: a quarter of the
   loads and stores of y, and four independent products per element (these
   sizes are latency-bound, not bandwidth-bound); four rows per step as
   straight-line code, which the SLP vectoriser turns into vector
   operations (same operations per entry as the plain loop). */
PHGMG__ONLINE void phgmg__r_gemv(int rows, int cols, const phgmg_real *A, const phgmg_real *x,
                                 int accumulate, phgmg_real *y) {
  const size_t ld = (size_t)rows;
  int i, j = 0;
  if (!accumulate) for (i = 0; i < rows; ++i) y[i] = PHGMG__R(0);
  for (; j + 4 <= cols; j += 4) {
    const phgmg_real x0 = x[j], x1 = x[j + 1], x2 = x[j + 2], x3 = x[j + 3];
    const phgmg_real *a0 = A + (size_t)j * ld, *a1 = a0 + ld, *a2 = a1 + ld, *a3 = a2 + ld;
    for (i = 0; i + 4 <= rows; i += 4) {
      const phgmg_real t0 = (a0[i] * x0 + a1[i] * x1) + (a2[i] * x2 + a3[i] * x3);
      const phgmg_real t1 = (a0[i + 1] * x0 + a1[i + 1] * x1) + (a2[i + 1] * x2 + a3[i + 1] * x3);
      const phgmg_real t2 = (a0[i + 2] * x0 + a1[i + 2] * x1) + (a2[i + 2] * x2 + a3[i + 2] * x3);
      const phgmg_real t3 = (a0[i + 3] * x0 + a1[i + 3] * x1) + (a2[i + 3] * x2 + a3[i + 3] * x3);
      const phgmg_real y0 = y[i], y1 = y[i + 1], y2 = y[i + 2], y3 = y[i + 3];
      y[i] = y0 + t0; y[i + 1] = y1 + t1; y[i + 2] = y2 + t2; y[i + 3] = y3 + t3;
    }
    for (; i < rows; ++i) y[i] += (a0[i] * x0 + a1[i] * x1) + (a2[i] * x2 + a3[i] * x3);
  }
  for (; j < cols; ++j) phgmg__r_axmy(rows, -x[j], A + (size_t)j * ld, y);
}
/* y (+)= A^T x (A: rows x cols); four dot products per sweep. */
PHGMG__ONLINE void phgmg__r_gemvt(int rows, int cols, const phgmg_real *A, const phgmg_real *x,
                                  int accumulate, phgmg_real *y) {
  const size_t ld = (size_t)rows;
  int i, j = 0;
  for (; j + 4 <= cols; j += 4) {
    const phgmg_real *a0 = A + (size_t)j * ld, *a1 = a0 + ld, *a2 = a1 + ld, *a3 = a2 + ld;
    phgmg_real s0 = PHGMG__R(0), s1 = PHGMG__R(0), s2 = PHGMG__R(0), s3 = PHGMG__R(0);
    for (i = 0; i < rows; ++i) {
      const phgmg_real xi = x[i];
      s0 += a0[i] * xi; s1 += a1[i] * xi; s2 += a2[i] * xi; s3 += a3[i] * xi;
    }
    if (accumulate) { y[j] += s0; y[j + 1] += s1; y[j + 2] += s2; y[j + 3] += s3; }
    else { y[j] = s0; y[j + 1] = s1; y[j + 2] = s2; y[j + 3] = s3; }
  }
  for (; j < cols; ++j) {
    const phgmg_real *a = A + (size_t)j * ld;
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
      phgmg__r_axmy(n - k - 1, akj, A + k + 1 + k * n, A + k + 1 + j * n);
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
    if (bj != PHGMG__R(0)) phgmg__r_axmy(n - j - 1, bj, LU + j + 1 + j * n, b + j + 1);
  }
  for (j = n - 1; j >= 0; --j) {
    b[j] /= LU[j + j * n];
    if (b[j] != PHGMG__R(0)) phgmg__r_axmy(j, b[j], LU + j * n, b);
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

/* d = phi_j, phi_j', phi_j'' at s for kept term j: phi_cb if set, else the
   exp-polynomial (shared, or row j when nphi == nd). */
PHGMG__ONLINE void phgmg__r_phi(const phgmg_rom *rom, int j, phgmg_real s, phgmg_real d[3]) {
  const int t = rom->nphi > 1 ? j : 0;
  int e;
  if (rom->phi_cb) {
    rom->phi_cb(rom->term ? rom->term[j] : j, s, d, rom->phi_user);
    return;
  }
  if (rom->poly) {
    phgmg__r_poly(rom->poly + (size_t)t * (size_t)(rom->poly_deg + 1), rom->poly_deg, s, &d[0], &d[1], &d[2]);
  } else {
    d[0] = d[1] = d[2] = PHGMG__R(0);
  }
  if (rom->nexp > 0) {
    const phgmg_real *ex = rom->expo + 2 * (size_t)t * (size_t)rom->nexp;
    for (e = 0; e < rom->nexp; ++e) {
      const phgmg_real b = ex[2 * e + 1], ae = ex[2 * e] * PHGMG__REXP(b * s);
      d[0] += ae;
      d[1] += ae * b;
      d[2] += ae * b * b;
    }
  }
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
    if (!rom->G00 || !rom->G01 || !rom->G10 || !rom->G11 || !rom->Q01 || !rom->Q11 ||
        (!rom->Ms && !rom->eta_cb))
      return PHGMG_ERR_INVALID_ARG;
    if (rom->nd > 0 && !rom->P1) return PHGMG_ERR_INVALID_ARG;
  } else {
    return PHGMG_ERR_INVALID_ARG;
  }
  if (rom->nd > 0) {
    if (!rom->P0 || !rom->w) return PHGMG_ERR_INVALID_ARG;
    if (rom->poly_deg < 0 || rom->poly_deg > 32) return PHGMG_ERR_INVALID_ARG;
    if (rom->nexp < 0 || rom->nexp > 8) return PHGMG_ERR_SIZE;
    if (rom->nphi < 0 || (rom->nphi > 1 && rom->nphi != rom->nd)) return PHGMG_ERR_SIZE;
    if (!rom->phi_cb && ((rom->poly_deg > 0 && !rom->poly) || (rom->nexp > 0 && !rom->expo) ||
                         (!rom->poly && rom->nexp == 0)))
      return PHGMG_ERR_INVALID_ARG;
  }
  if (rom->Phi && (!rom->Gam || !rom->SX || !rom->SU || !(rom->dt > PHGMG__R(0))))
    return PHGMG_ERR_INVALID_ARG;
  if (rom->ref_s && rom->nd < 1) return PHGMG_ERR_INVALID_ARG;
  if (rom->Phi && rom->ref_g) { /* the step map is of x' = K Qh x + Bh u: no constant gradient */
    int i;
    for (i = 0; i < rom->r; ++i)
      if (rom->ref_g[i] != PHGMG__R(0)) return PHGMG_ERR_INVALID_ARG;
  }
  if (rom->ndamp < 0 || rom->ndamp > (1 << 24)) return PHGMG_ERR_SIZE;
  if (rom->PD && rom->kind != PHGMG_ROM_LINEAR) return PHGMG_ERR_INVALID_ARG;
  if (rom->ndamp > 0) {
    if (rom->kind != PHGMG_ROM_LINEAR || !rom->Cd || (!rom->dpoly && !rom->damp_cb)) return PHGMG_ERR_INVALID_ARG;
    if (!rom->damp_cb && (rom->damp_deg < 1 || rom->damp_deg > 15)) return PHGMG_ERR_SIZE;
    if (rom->damp_nphi < 0 || (rom->damp_nphi > 1 && rom->damp_nphi != rom->ndamp)) return PHGMG_ERR_SIZE;
  }
  return PHGMG_OK;
}

/* d = rho_j, rho_j' of reduced damper j at s. */
PHGMG__ONLINE void phgmg__r_damp_law(const phgmg_rom *rom, int j, phgmg_real s, phgmg_real d[2]) {
  const phgmg_real *a;
  int e;
  if (rom->damp_cb) { rom->damp_cb(rom->dterm ? rom->dterm[j] : j, s, d, rom->damp_user); return; }
  a = rom->dpoly + (rom->damp_nphi > 1 ? (size_t)j * (size_t)(rom->damp_deg + 1) : 0);
  d[0] = a[rom->damp_deg];
  d[1] = (phgmg_real)rom->damp_deg * a[rom->damp_deg];
  for (e = rom->damp_deg - 1; e >= 1; --e) {
    d[0] = d[0] * s + a[e];
    d[1] = d[1] * s + (phgmg_real)e * a[e];
  }
  d[0] *= s;
}

/* f -= sum_j dw_j Cd_j rho_j(Cd_j^T g); 1 if a callback damper generated
   energy (s rho(s) < 0), else 0. */
PHGMG__ONLINE int phgmg__rom_damp(const phgmg_rom *rom, const phgmg_real *g, phgmg_real *f) {
  const int r = rom->r;
  int j, a, bad = 0;
  for (j = 0; j < rom->ndamp; ++j) {
    const phgmg_real *cj = rom->Cd + (size_t)j * r;
    phgmg_real sj = PHGMG__R(0), d[2], c;
    for (a = 0; a < r; ++a) sj += cj[a] * g[a];
    phgmg__r_damp_law(rom, j, sj, d);
    if (sj * d[0] < PHGMG__R(0)) bad = 1;
    c = (rom->dw ? rom->dw[j] : PHGMG__R(1)) * d[0];
    for (a = 0; a < r; ++a) f[a] -= c * cj[a];
  }
  return bad;
}

/* Jf -= sum_j dw_j rho_j'(s_j) Cd_j (Cd_j^T Hs), s_j = Cd_j^T g (Hs symmetric);
   t: r scratch reals. */
PHGMG__ONLINE void phgmg__rom_damp_jac(const phgmg_rom *rom, const phgmg_real *g, const phgmg_real *Hs,
                                       phgmg_real *Jf, phgmg_real *t) {
  const int r = rom->r;
  int j, a, b;
  for (j = 0; j < rom->ndamp; ++j) {
    const phgmg_real *cj = rom->Cd + (size_t)j * r;
    phgmg_real sj = PHGMG__R(0), d[2], c;
    for (a = 0; a < r; ++a) sj += cj[a] * g[a];
    phgmg__r_damp_law(rom, j, sj, d);
    c = (rom->dw ? rom->dw[j] : PHGMG__R(1)) * d[1];
    if (c == PHGMG__R(0)) continue;
    phgmg__r_gemv(r, r, Hs, cj, 0, t);
    for (b = 0; b < r; ++b)
      for (a = 0; a < r; ++a) Jf[a + (size_t)b * r] -= c * cj[a] * t[b];
  }
}

/* Evaluation work: one layout function used by the size query and by every
   evaluator, so size and carving cannot drift. */
typedef struct phgmg__romw {
  phgmg_real *Lp, *q, *a1, *b1, *b2, *c, *d, *E, *t, *tmp, *xp, *fm, *g;
  phgmg_real *D2;       /* eta_cb: D2q (rn x p*p), else NULL */
  phgmg_real *hg, *hH;  /* ham_cb: its gradient (r) and Hessian (r x r), else NULL */
  const phgmg_real *Ms; /* second derivatives of the manifold: rom->Ms or D2 */
  int d2;               /* eta_cb: prep also fills D2 (set by Hessian/Jacobian callers) */
  int *piv; /* r pivots of the LU of E, carved from the same real array */
} phgmg__romw;

PHGMG__ONLINE size_t phgmg__romw_layout(const phgmg_rom *rom, phgmg_real *base, phgmg__romw *w) {
  const size_t r = (size_t)rom->r, rn = (size_t)rom->rn, nd = (size_t)rom->nd;
  size_t o = 0;
  phgmg__romw dummy;
  if (!w) w = &dummy;
  w->Lp = PHGMG__CARVE(base, o); o += rn * r;
  w->q = PHGMG__CARVE(base, o); o += rn;
  w->a1 = PHGMG__CARVE(base, o); o += rn;
  w->b1 = PHGMG__CARVE(base, o); o += rn;
  w->b2 = PHGMG__CARVE(base, o); o += rn;
  w->c = PHGMG__CARVE(base, o); o += nd;
  w->d = PHGMG__CARVE(base, o); o += nd;
  w->E = PHGMG__CARVE(base, o); o += r * r;
  w->t = PHGMG__CARVE(base, o); o += rn * r;
  w->tmp = PHGMG__CARVE(base, o); o += r;
  w->xp = PHGMG__CARVE(base, o); o += r;
  w->fm = PHGMG__CARVE(base, o); o += r;
  w->g = PHGMG__CARVE(base, o); o += r;
  w->D2 = rom->eta_cb ? PHGMG__CARVE(base, o) : NULL;
  o += rom->eta_cb ? rn * (r - (size_t)rom->m) * (r - (size_t)rom->m) : 0;
  w->hg = rom->ham_cb ? PHGMG__CARVE(base, o) : NULL;
  o += rom->ham_cb ? r : 0;
  w->hH = rom->ham_cb ? PHGMG__CARVE(base, o) : NULL;
  o += rom->ham_cb ? r * r : 0;
  w->Ms = rom->eta_cb ? w->D2 : rom->Ms;
  w->d2 = 0;
  w->piv = base ? PHGMG__CAST(int *, PHGMG__CAST(void *, base + o)) : NULL;
  o += (r * sizeof(int) + sizeof(phgmg_real) - 1) / sizeof(phgmg_real);
  return o;
}

PHGMG_DEF size_t phgmg_rom_eval_work_size(const phgmg_rom *rom) {
  return phgmg__romw_layout(rom, NULL, NULL);
}

/* q = M (x2 kron x2) via Lp (QUADRATIC), and the kept coordinates c. With
   eta_cb: one call gives q, Lp = Dq (and D2q into w->D2 when w->d2). */
PHGMG__ONLINE void phgmg__rom_prep(const phgmg_rom *rom, const phgmg_real *x, const phgmg__romw *w) {
  const int r = rom->r, m = rom->m, rn = rom->rn, nd = rom->nd, p = r - m;
  int i;
  if (rom->kind == PHGMG_ROM_QUADRATIC && rom->eta_cb) {
    rom->eta_cb(x + m, w->q, w->Lp, w->d2 ? w->D2 : NULL, rom->eta_user);
  } else if (rom->kind == PHGMG_ROM_QUADRATIC) {
    const phgmg_real *x2 = x + m;
    /* Lp(:,k) = sum_j Ms(:, k*p + j) x2_j. Ms is symmetrised (Ms(:, k*p + j) =
       Ms(:, j*p + k)), so all of Lp (rn p) is one product of the (rn p) x p
       matrix whose column j is Ms(:, j*p .. j*p + p - 1) with x2: the same
       products in the same order as block k of Ms times x2, in one sweep. */
    phgmg__r_gemv(rn * p, p, rom->Ms, x2, 0, w->Lp);
    phgmg__r_gemv(rn, p, w->Lp, x2, 0, w->q);
    for (i = 0; i < rn; ++i) w->q[i] *= PHGMG__R(0.5);
  }
  if (nd > 0) {
    phgmg__r_gemv(nd, r, rom->P0, x, 0, w->c);
    if (rom->kind == PHGMG_ROM_QUADRATIC) phgmg__r_gemv(nd, rn, rom->P1, w->q, 1, w->c);
    if (rom->ref_s)
      for (i = 0; i < nd; ++i) w->c[i] += rom->ref_s[i];
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
  if (rom->ref_g) { /* + x^T g0 + q^T g2 + h0 (reference state) */
    const int nq = rom->kind == PHGMG_ROM_QUADRATIC ? rn : 0;
    for (j = 0; j < r; ++j) h += x[j] * rom->ref_g[j];
    for (j = 0; j < nq; ++j) h += w.q[j] * rom->ref_g[r + j];
    h += rom->ref_g[r + nq];
  }
  for (j = 0; j < rom->nd; ++j) {
    phgmg_real d[3];
    phgmg__r_phi(rom, j, w.c[j], d);
    h += rom->w[j] * d[0];
  }
  if (rom->ham_cb) {
    phgmg_real hn = PHGMG__R(0);
    rom->ham_cb(x, &hn, NULL, NULL, rom->ham_user);
    h += hn;
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
    phgmg_real d[3];
    phgmg__r_phi(rom, j, w->c[j], d);
    w->d[j] = rom->w[j] * d[1];
  }
  phgmg__r_gemv(r, r, rom->Qh, x, 0, g);
  if (rom->ref_g)
    for (j = 0; j < r; ++j) g[j] += rom->ref_g[j];
  if (rom->ham_cb) {
    rom->ham_cb(x, NULL, w->hg, NULL, rom->ham_user);
    for (j = 0; j < r; ++j) g[j] += w->hg[j];
  }
  if (nd > 0) phgmg__r_gemvt(nd, r, rom->P0, w->d, 1, g);
  if (rom->kind == PHGMG_ROM_QUADRATIC) {
    phgmg__r_gemv(r, rn, rom->Q01, w->q, 1, g);
    phgmg__r_gemvt(r, rn, rom->Q01, x, 0, w->a1); /* a1 = Q01^T x + Q11 q (+ g2) + P1^T d */
    phgmg__r_gemv(rn, rn, rom->Q11, w->q, 1, w->a1);
    if (rom->ref_g)
      for (j = 0; j < rn; ++j) w->a1[j] += rom->ref_g[r + j];
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
  if (rom->PD) phgmg__r_gemvt(rom->r, rom->m, rom->PD, w.g, 1, y);   /* + Ph^T g */
}

/* E = D^T G D = G00 + G01 L + L^T (G10 + G11 L), L = [0, Lp] (QUADRATIC; Lp current). */
PHGMG__ONLINE void phgmg__rom_dgd(const phgmg_rom *rom, const phgmg__romw *w) {
  const int r = rom->r, m = rom->m, rn = rom->rn;
  phgmg_real *E = w->E, *t = w->t;
  int b, i;
  for (b = 0; b < r; ++b) {
    phgmg_real *tb = t + (size_t)b * rn;
    for (i = 0; i < rn; ++i) tb[i] = rom->G10[i + (size_t)b * rn];
    if (b >= m) phgmg__r_gemv(rn, rn, rom->G11, w->Lp + (size_t)(b - m) * rn, 1, tb);
  }
  for (b = 0; b < r * r; ++b) E[b] = rom->G00[b];
  for (b = m; b < r; ++b) phgmg__r_gemv(r, rn, rom->G01, w->Lp + (size_t)(b - m) * rn, 1, E + (size_t)b * r);
  for (b = 0; b < r; ++b) phgmg__r_gemvt(rn, r - m, w->Lp, t + (size_t)b * rn, 1, E + (size_t)b * r + m);
}

/* f = K(x) grad H(x) + Bh u; grad H left in w->g. f must not alias work. */
PHGMG__ONLINE phgmg_result phgmg__rom_rhs(const phgmg_rom *rom, const phgmg_real *x, const phgmg_real *u,
                                          phgmg_real *f, const phgmg__romw *w) {
  const int r = rom->r;
  phgmg__rom_grad(rom, x, w->g, w);
  if (rom->kind == PHGMG_ROM_LINEAR) {
    phgmg__r_gemv(r, r, rom->K, w->g, 0, f);
    if (rom->ndamp && phgmg__rom_damp(rom, w->g, f)) return PHGMG_ERR_DAMPER;
  } else {
    int i;
    phgmg__rom_dgd(rom, w);
    for (i = 0; i < r; ++i) f[i] = w->g[i];
    if (phgmg__r_lu(r, w->E, w->piv) != 0) return PHGMG_ERR_SINGULAR;
    phgmg__r_lu_solve(r, w->E, w->piv, f);
  }
  if (u && rom->m > 0) phgmg__r_gemv(r, rom->m, rom->Bh, u, 1, f);
  if (u && rom->m > 0 && rom->PD) {   /* feedthrough: (Bh - Ph) u */
    int a, k;
    for (k = 0; k < rom->m; ++k)
      for (a = 0; a < r; ++a) f[a] -= rom->PD[a + (size_t)k * r] * u[k];
  }
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
  } else { /* K = E^{-1}: one LU, r solves */
    phgmg__rom_prep(rom, x, &w);
    phgmg__rom_dgd(rom, &w);
    if (phgmg__r_lu(r, w.E, w.piv) != 0) return PHGMG_ERR_SINGULAR;
    for (b = 0; b < r; ++b) {
      for (a = 0; a < r; ++a) Jr[a + (size_t)b * r] = (a == b) ? PHGMG__R(1) : PHGMG__R(0);
      phgmg__r_lu_solve(r, w.E, w.piv, Jr + (size_t)b * r);
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

/* The reduced Hessian H = d grad H / dx (r x r, symmetric) at x; grad H left
   in w->g. With phi(x) = V0 x + V2 q(x2), D = V0 + V2 L, L = [0, Lp]:
     H = D^T Q D + (P0 + P1 L)^T diag(w phi''(c)) (P0 + P1 L) + [0 0; 0 Hq],
   D^T Q D = Qh + Q01 L + (Q01 L)^T + L^T Q11 L and Hq(a,b) = Ms(:, a p + b)^T a1
   (the curvature of the manifold against V2^T grad H). */
PHGMG__ONLINE void phgmg__rom_hess(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *H,
                                   const phgmg__romw *w) {
  const int r = rom->r, m = rom->m, rn = rom->rn, nd = rom->nd, p = r - m;
  int a, b, j, k, i;
  phgmg__rom_grad(rom, x, w->g, w);
  for (b = 0; b < r * r; ++b) H[b] = rom->Qh[b];
  if (rom->kind == PHGMG_ROM_QUADRATIC) {
    for (k = 0; k < p; ++k) {
      const phgmg_real *lk = w->Lp + (size_t)k * rn;
      phgmg__r_gemv(r, rn, rom->Q01, lk, 0, w->tmp); /* column m+k of Q01 L */
      for (a = 0; a < r; ++a) {
        H[a + (size_t)(m + k) * r] += w->tmp[a];
        H[(m + k) + (size_t)a * r] += w->tmp[a];
      }
      phgmg__r_gemv(rn, rn, rom->Q11, lk, 0, w->b1);
      for (a = 0; a < p; ++a) {
        const phgmg_real *la = w->Lp + (size_t)a * rn, *ms = w->Ms + ((size_t)a * p + k) * rn;
        phgmg_real s = PHGMG__R(0);
        for (i = 0; i < rn; ++i) s += la[i] * w->b1[i] + ms[i] * w->a1[i];
        H[(m + a) + (size_t)(m + k) * r] += s;
      }
    }
  }
  if (rom->ham_cb) {
    rom->ham_cb(x, NULL, NULL, w->hH, rom->ham_user);
    for (b = 0; b < r * r; ++b) H[b] += w->hH[b];
  }
  for (j = 0; j < nd; ++j) {
    phgmg_real d[3], wj;
    phgmg__r_phi(rom, j, w->c[j], d);
    wj = rom->w[j] * d[2];
    if (wj == PHGMG__R(0)) continue;
    for (a = 0; a < r; ++a) w->xp[a] = rom->P0[j + (size_t)a * nd]; /* row j of P0 + P1 L */
    if (rom->kind == PHGMG_ROM_QUADRATIC)
      for (k = 0; k < p; ++k) {
        const phgmg_real *lk = w->Lp + (size_t)k * rn;
        phgmg_real s = PHGMG__R(0);
        for (i = 0; i < rn; ++i) s += rom->P1[j + (size_t)i * nd] * lk[i];
        w->xp[m + k] += s;
      }
    for (b = 0; b < r; ++b) {
      const phgmg_real wb = wj * w->xp[b];
      phgmg_real *hb = H + (size_t)b * r;
      for (a = 0; a < r; ++a) hb[a] += wb * w->xp[a];
    }
  }
}

/* w->b2 = L v and w->b1 = (G10 + G11 L) v at the point whose Lp is in w (QUADRATIC). */
PHGMG__ONLINE void phgmg__rom_lv(const phgmg_rom *rom, const phgmg__romw *w, const phgmg_real *v) {
  const int r = rom->r, m = rom->m, rn = rom->rn;
  phgmg__r_gemv(rn, r - m, w->Lp, v + m, 0, w->b2);
  phgmg__r_gemv(rn, r, rom->G10, v, 0, w->b1);
  phgmg__r_gemv(rn, rn, rom->G11, w->b2, 1, w->b1);
}

/* out = E v, E = D^T G D at the point whose Lp is in w (QUADRATIC), without
   forming E: G00 v + G01 (L v) + L^T (G10 v + G11 L v). Uses w->b1, w->b2. */
PHGMG__ONLINE void phgmg__rom_eapply(const phgmg_rom *rom, const phgmg__romw *w, const phgmg_real *v,
                                     phgmg_real *out) {
  const int r = rom->r, m = rom->m, rn = rom->rn, p = r - m;
  phgmg__rom_lv(rom, w, v);
  phgmg__r_gemv(r, r, rom->G00, v, 0, out);
  phgmg__r_gemv(r, rn, rom->G01, w->b2, 1, out);
  phgmg__r_gemvt(rn, p, w->Lp, w->b1, 1, out + m);
}

/* Newton Jacobian df/dx, analytic for both kinds.
   LINEAR: Jf = K H.  QUADRATIC: f = E^{-1} g + Bh u with E = D^T G D, so
     Jf = E^{-1} (H - C),  C(:, b) = (dE/dx_b) v,  v = E^{-1} g.
   E depends on x2 through L only: dL/dx_{m+j} = [0, Ms_j], Ms_j(:,k) = Ms(:, j p + k), and
     C(:, m+j) = (G01 + L^T G11) s_j + [0; Ms_j^T t],  s_j = Ms_j v2,  t = (G10 + G11 L) v.
   On return (QUADRATIC) w->E/w->piv hold the LU of E(x) and w->fm = v. */
PHGMG__ONLINE phgmg_result phgmg__rom_jac(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *Jf,
                                          const phgmg__romw *w) {
  const int r = rom->r, m = rom->m, rn = rom->rn, p = r - m;
  int a, b, j, k, i;
  if (rom->kind == PHGMG_ROM_LINEAR) {
    phgmg_real *Hs = w->E;
    phgmg__rom_hess(rom, x, Hs, w);
    for (b = 0; b < r; ++b) phgmg__r_gemv(r, r, rom->K, Hs + (size_t)b * r, 0, Jf + (size_t)b * r);
    if (rom->ndamp) phgmg__rom_damp_jac(rom, w->g, Hs, Jf, w->xp);
    return PHGMG_OK;
  }
  phgmg__rom_hess(rom, x, Jf, w); /* Jf = H; w->g, w->Lp at x */
  phgmg__rom_dgd(rom, w);
  if (phgmg__r_lu(r, w->E, w->piv) != 0) return PHGMG_ERR_SINGULAR;
  for (a = 0; a < r; ++a) w->fm[a] = w->g[a];
  phgmg__r_lu_solve(r, w->E, w->piv, w->fm); /* v */
  phgmg__rom_lv(rom, w, w->fm); /* t = G10 v + G11 L v in w->b1 */
  for (j = 0; j < p; ++j) {
    phgmg_real *sj = w->t; /* s_j (rn) */
    phgmg_real *cj = Jf + (size_t)(m + j) * r;
    phgmg__r_gemv(rn, p, w->Ms + (size_t)j * p * rn, w->fm + m, 0, sj);
    phgmg__r_gemv(rn, rn, rom->G11, sj, 0, w->b2);
    phgmg__r_gemv(r, rn, rom->G01, sj, 0, w->tmp);
    for (k = 0; k < p; ++k) {
      const phgmg_real *lk = w->Lp + (size_t)k * rn, *ms = w->Ms + ((size_t)j * p + k) * rn;
      phgmg_real s = PHGMG__R(0);
      for (i = 0; i < rn; ++i) s += lk[i] * w->b2[i] + ms[i] * w->b1[i];
      w->tmp[m + k] += s;
    }
    for (a = 0; a < r; ++a) cj[a] -= w->tmp[a];
  }
  for (b = 0; b < r; ++b) phgmg__r_lu_solve(r, w->E, w->piv, Jf + (size_t)b * r);
  return PHGMG_OK;
}

PHGMG_DEF void phgmg_rom_hessian(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *H, phgmg_real *work) {
  phgmg__romw w;
  phgmg__romw_layout(rom, work, &w);
  w.d2 = 1;
  phgmg__rom_hess(rom, x, H, &w);
}

PHGMG_DEF phgmg_result phgmg_rom_jacobian(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *Jf,
                                          phgmg_real *work) {
  phgmg__romw w;
  phgmg__romw_layout(rom, work, &w);
  w.d2 = 1;
  return phgmg__rom_jac(rom, x, Jf, &w);
}

/* --- online GL3 stepper ------------------------------------------------- */
typedef struct phgmg__romstep_mem {
  phgmg_real *A, *b, *c, *lag; /* GL3 tableau (row-major A), extrapolation weights 3x4 */
  phgmg_real *LU, *Jf, *Z, *F, *Res, *dZ, *Zp, *G, *Y, *work;
  /* QUADRATIC (mass-matrix form): frozen LU of E, stage values Phi = E^{-1} g,
     their extrapolation, E_f^{-1} (E Phi - g), quadratic extrapolation weights 3x3 */
  phgmg_real *Ef, *Phi, *Php, *Del, *lagq;
  int *piv, *pivf;
} phgmg__romstep_mem;

/* Two layouts: the full one for Newton, and a small one when the model is
   stepped with its precomputed step map (no stage system, no LU). */
PHGMG__ONLINE size_t phgmg__romstep_layout(const phgmg_rom *rom, int map_only, void *mem, phgmg__romstep_mem *L) {
  const size_t r = (size_t)rom->r, n3 = 3 * r;
  phgmg_real *base = PHGMG__CAST(phgmg_real *, mem);
  size_t o = 0, reals;
  phgmg__romstep_mem dummy;
  const int mm = !map_only && rom->kind == PHGMG_ROM_QUADRATIC;
  if (!L) L = &dummy;
  L->A = PHGMG__CARVE(base, o); o += 9;
  L->b = PHGMG__CARVE(base, o); o += 3;
  L->c = PHGMG__CARVE(base, o); o += 3;
  L->lag = PHGMG__CARVE(base, o); o += 12;
  L->LU = PHGMG__CARVE(base, o); o += map_only ? 0 : n3 * n3;
  L->Jf = PHGMG__CARVE(base, o); o += map_only ? 0 : r * r;
  L->Z = PHGMG__CARVE(base, o); o += n3;
  L->F = PHGMG__CARVE(base, o); o += n3;
  L->Res = PHGMG__CARVE(base, o); o += map_only ? 0 : n3;
  L->dZ = PHGMG__CARVE(base, o); o += map_only ? r : n3;
  L->Zp = PHGMG__CARVE(base, o); o += map_only ? 0 : n3;
  L->G = PHGMG__CARVE(base, o); o += n3;
  L->Y = PHGMG__CARVE(base, o); o += r;
  L->work = PHGMG__CARVE(base, o); o += map_only ? 0 : phgmg_rom_eval_work_size(rom);
  L->Ef = mm ? PHGMG__CARVE(base, o) : NULL; o += mm ? r * r : 0;
  L->Phi = mm ? PHGMG__CARVE(base, o) : NULL; o += mm ? n3 : 0;
  L->Php = mm ? PHGMG__CARVE(base, o) : NULL; o += mm ? n3 : 0;
  L->Del = mm ? PHGMG__CARVE(base, o) : NULL; o += mm ? n3 : 0;
  L->lagq = mm ? PHGMG__CARVE(base, o) : NULL; o += mm ? 9 : 0;
  reals = o;
  L->piv = mem ? PHGMG__CAST(int *, PHGMG__CAST(void *, base + reals)) : NULL;
  L->pivf = mem ? L->piv + (map_only ? 0 : n3) : NULL;
  return reals * sizeof(phgmg_real) + ((map_only ? 0 : n3) + (mm ? r : 0)) * sizeof(int);
}

/* Does stepping with dt use the model's precomputed step map? */
PHGMG__ONLINE int phgmg__rom_uses_map(const phgmg_rom *rom, phgmg_real dt) {
  return rom->Phi != NULL && rom->kind == PHGMG_ROM_LINEAR && rom->nd == 0 && rom->ndamp == 0 && !rom->PD &&
         PHGMG__RABS(rom->dt - dt) <= PHGMG__R(8) * PHGMG__REPS * dt;
}

PHGMG_DEF size_t phgmg_rom_stepper_memsize(const phgmg_rom *rom) {
  if (phgmg_rom_check(rom) != PHGMG_OK) return 0;
  return phgmg__romstep_layout(rom, phgmg__rom_uses_map(rom, rom->dt), NULL, NULL);
}

PHGMG_DEF size_t phgmg_rom_stepper_memsize_dt(const phgmg_rom *rom, phgmg_real dt) {
  if (phgmg_rom_check(rom) != PHGMG_OK) return 0;
  return phgmg__romstep_layout(rom, phgmg__rom_uses_map(rom, dt), NULL, NULL);
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
  int i, j, k, use_map;
  if (!s || !mem) return PHGMG_ERR_INVALID_ARG;
  rc = phgmg_rom_check(rom);
  if (rc != PHGMG_OK) return rc;
  if (!(dt > PHGMG__R(0)) || dt - dt != PHGMG__R(0)) return PHGMG_ERR_INVALID_ARG;
  if (tol != tol || tol - tol != PHGMG__R(0)) return PHGMG_ERR_INVALID_ARG; /* NaN, +-Inf */
  if (((size_t)mem) % sizeof(double) != 0) return PHGMG_ERR_INVALID_ARG;
  use_map = phgmg__rom_uses_map(rom, dt);
  if (mem_size < phgmg__romstep_layout(rom, use_map, NULL, NULL)) return PHGMG_ERR_WORKSPACE;
  phgmg__romstep_layout(rom, use_map, mem, &L);
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
    if (L.lagq) /* the quadratic through (c_j, Phi_j) at 1 + c_k (Phi ~ p', degree 2) */
      for (j = 0; j < 3; ++j) {
        double l = 1.0;
        for (i = 0; i < 3; ++i)
          if (i != j) l *= (tt - c[i]) / (c[j] - c[i]);
        L.lagq[k * 3 + j] = PHGMG__R(l);
      }
  }
  s->rom = rom;
  s->dt = dt;
#if PHGMG_REAL_IS_FLOAT
  s->tol = tol > PHGMG__R(0) ? tol : PHGMG__R(1e-5);
#else
  s->tol = tol > PHGMG__R(0) ? tol : PHGMG__R(1e-10);
#endif
  s->tol_rel = !(tol > PHGMG__R(0));
  s->tol_step = s->tol;
  s->max_iter = max_iter > 0 ? max_iter : 10;
  s->use_map = use_map;
  s->have_lu = 0;
  s->have_prev = 0;
  s->stale_e = 0;
  s->exact_hold = 0;
  s->ws = PHGMG__CAST(phgmg_real *, mem);
  s->ws_count = mem_size / sizeof(phgmg_real);
  memset(&s->stats, 0, sizeof s->stats);
  return PHGMG_OK;
}

PHGMG_DEF void phgmg_rom_stepper_reset(phgmg_rom_stepper *s) { s->have_prev = 0; }

/* Stage residual Res = Z - h (A kron I) F(x + Z); returns inf-norm, or -1 on
   failure (non-finite or singular). Stage gradients into G.
   QUADRATIC models are stepped in mass-matrix form: f = E(x)^{-1} g(x) + Bh u
   with E = D^T G D, and the stage values Phi_i = E(Y_i)^{-1} g(Y_i) are Newton
   unknowns beside Z (no factorisation of E(Y_i) per evaluation; E(Y_i) Phi_i
   is a product, phgmg__rom_eapply). Then F = Phi + Bh u, Del_i =
   E_f^{-1} (E(Y_i) Phi_i - g(Y_i)) with the frozen factors E_f, and
   Res = Z - h (A kron I) F + h (A kron I) Del (the right-hand side of the
   reduced Newton system). The norm is max |Z - h A F| + |h A Del| taken
   componentwise, which bounds the residual of the eliminated equations to
   first order; at convergence the solution is that of the usual GL3 stages. */
PHGMG__ONLINE phgmg_real phgmg__romstep_residual(phgmg_rom_stepper *s, const phgmg__romstep_mem *L,
                                                 const phgmg_real *x, const phgmg_real *u3, int mm,
                                                 phgmg_result *err) {
  const phgmg_rom *rom = s->rom;
  const int r = rom->r, m = rom->m;
  phgmg__romw w;
  phgmg_real nrm = PHGMG__R(0);
  int i, j, a;
  phgmg__romw_layout(rom, L->work, &w);
  for (i = 0; i < 3; ++i) {
    phgmg_real *fi = L->F + i * r;
    for (a = 0; a < r; ++a) L->Y[a] = x[a] + L->Z[i * r + a];
    if (mm) {
      phgmg_real *di = L->Del + i * r, *pi = L->Phi + i * r;
      phgmg__rom_grad(rom, L->Y, w.g, &w);
      phgmg__rom_eapply(rom, &w, pi, di);
      for (a = 0; a < r; ++a) { di[a] -= w.g[a]; fi[a] = pi[a]; }
      phgmg__r_lu_solve(r, L->Ef, L->pivf, di);
      if (u3 && m > 0) phgmg__r_gemv(r, m, rom->Bh, u3 + i * m, 1, fi);
    } else {
      phgmg_result rc = phgmg__rom_rhs(rom, L->Y, u3 ? u3 + i * m : NULL, fi, &w);
      if (rc != PHGMG_OK) { *err = rc; return PHGMG__R(-1); }
    }
    for (a = 0; a < r; ++a) L->G[i * r + a] = w.g[a];
  }
  for (i = 0; i < 3; ++i)
    for (a = 0; a < r; ++a) {
      phgmg_real v = L->Z[i * r + a], e = PHGMG__R(0);
      for (j = 0; j < 3; ++j) v -= s->dt * L->A[i * 3 + j] * L->F[j * r + a];
      if (mm) for (j = 0; j < 3; ++j) e += s->dt * L->A[i * 3 + j] * L->Del[j * r + a];
      L->Res[i * r + a] = v + e;
      if (PHGMG__RABS(v + e) > nrm) nrm = PHGMG__RABS(v + e);
      if (PHGMG__RABS(e) > nrm) nrm = PHGMG__RABS(e);
    }
  if (!phgmg__r_finite(L->Res, 3 * r) || !phgmg__r_finite(L->G, 3 * r)) { *err = PHGMG_ERR_NANINF; return PHGMG__R(-1); }
  return nrm;
}

/* Keep the LU of E in w (w->E, w->piv) as the frozen factors E_f (QUADRATIC). */
PHGMG__ONLINE void phgmg__romstep_keep_e(const phgmg__romstep_mem *L, const phgmg__romw *w, int r) {
  int i;
  for (i = 0; i < r * r; ++i) L->Ef[i] = w->E[i];
  for (i = 0; i < r; ++i) L->pivf[i] = w->piv[i];
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
  w.d2 = 1;
  rc = phgmg__rom_jac(rom, x, L->Jf, &w);
  if (rc != PHGMG_OK) { s->have_lu = 0; return rc; }
  if (!phgmg__r_finite(L->Jf, r * r)) { s->have_lu = 0; return PHGMG_ERR_NANINF; }
  if (L->Ef) phgmg__romstep_keep_e(L, &w, r); /* the LU of E(x) the Jacobian was built with */
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

/* Reduced states that decay freely pass through the subnormal range, slow on
   some processors: phgmg_rom_step sets entries below the smallest normal
   (DBL_MIN, FLT_MIN in float builds) of its new state and extrapolation data
   to zero (never touching the floating-point environment). */
#if PHGMG_REAL_IS_FLOAT
#define PHGMG__R_MINNORM 1.17549435e-38F
#else
#define PHGMG__R_MINNORM 2.2250738585072014e-308
#endif
PHGMG__ONLINE void phgmg__r_flush_subnormal(phgmg_real *v, int n) {
  int i;
  for (i = 0; i < n; ++i) v[i] = PHGMG__RABS(v[i]) < PHGMG__R_MINNORM ? PHGMG__R(0) : v[i];
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
  phgmg__r_flush_subnormal(xn, r);
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

/* Before a Newton attempt: factors of the stage matrix (kept, or fresh at x
   on a retry), a refresh of E's factors after a slow step (QUADRATIC), and the
   starting guess (extrapolated collocation polynomial, or zero; Phi at every
   stage). */
PHGMG__ONLINE phgmg_result phgmg__romstep_start(phgmg_rom_stepper *s, const phgmg__romstep_mem *L, const phgmg_real *x,
                                                int attempt, int mm, int *tried_fresh) {
  const phgmg_rom *rom = s->rom;
  const int r = rom->r, n3 = 3 * r;
  int i, a;
  phgmg_result err;
  if (!s->have_lu || (attempt > 0 && !*tried_fresh)) {
    err = phgmg__romstep_factor(s, L, x);
    if (err != PHGMG_OK) return err;
    *tried_fresh = 1;
  }
  else if (mm && s->stale_e) { /* the last step was slow: new factors of E only (r x r) */
    phgmg__romw w;
    phgmg__romw_layout(rom, L->work, &w);
    phgmg__rom_prep(rom, x, &w);
    phgmg__rom_dgd(rom, &w);
    if (phgmg__r_lu(r, w.E, w.piv) != 0) { s->have_lu = 0; return PHGMG_ERR_SINGULAR; }
    phgmg__romstep_keep_e(L, &w, r);
    s->stale_e = 0;
    s->stats.e_refreshes++;
  }
  /* starting guess: extrapolated collocation polynomial, or zero */
  for (i = 0; i < n3; ++i) L->Z[i] = (s->have_prev && attempt == 0) ? L->Zp[i] : PHGMG__R(0);
  if (mm) { /* Phi: extrapolated, or E(x)^{-1} g(x) at every stage */
    if (s->have_prev && attempt == 0) {
      for (i = 0; i < n3; ++i) L->Phi[i] = L->Php[i];
    } else {
      phgmg__romw w;
      phgmg__romw_layout(rom, L->work, &w);
      err = phgmg__rom_rhs(rom, x, NULL, L->Phi, &w);
      if (err != PHGMG_OK) return err;
      for (a = 0; a < r; ++a) L->Phi[r + a] = L->Phi[2 * r + a] = L->Phi[a];
    }
  }
  return PHGMG_OK;
}

/* The default tolerance (tol_rel) follows the stage increments too: tol
   times max(1, |x|_inf, |Z|_inf) (phgmg_rom_step starts it from x). */
PHGMG__ONLINE void phgmg__romstep_tol(phgmg_rom_stepper *s, const phgmg__romstep_mem *L) {
  int i;
  if (!s->tol_rel) return;
  for (i = 0; i < 3 * s->rom->r; ++i)
    if (PHGMG__RABS(L->Z[i]) * s->tol > s->tol_step) s->tol_step = PHGMG__RABS(L->Z[i]) * s->tol;
}

/* Simplified Newton on the stage system from the residual res; in
   mass-matrix form (mm) a slow contraction switches to exact stage values.
   Returns the final residual (negative after a failure, with *err). */
PHGMG__ONLINE phgmg_real phgmg__romstep_iterate(phgmg_rom_stepper *s, const phgmg__romstep_mem *L, const phgmg_real *x,
                                               const phgmg_real *u3, phgmg_real res, int *mm, int *exact, int *it,
                                               phgmg_real *theta_max, phgmg_result *err) {
  const int r = s->rom->r, n3 = 3 * r;
  phgmg_real res_prev = PHGMG__R(0);
  int i, a;
  /* at least one update (as the full-order stepper): tol has a floor, and a
     model whose states are tiny (SI units, e.g. charges of 1e-12 C) would
     otherwise accept the extrapolated guess unsolved */
  phgmg__romstep_tol(s, L);
  while ((res > s->tol_step || *it == 0) && *it < s->max_iter) {
    for (i = 0; i < n3; ++i) L->dZ[i] = -L->Res[i];
    phgmg__r_lu_solve(n3, L->LU, L->piv, L->dZ);
    for (i = 0; i < n3; ++i) L->Z[i] += L->dZ[i];
    phgmg__romstep_tol(s, L);
    if (*mm) /* dPhi_i = Jf dZ_i - Del_i */
      for (i = 0; i < 3; ++i) {
        phgmg__r_gemv(r, r, L->Jf, L->dZ + i * r, 1, L->Phi + i * r);
        for (a = 0; a < r; ++a) L->Phi[i * r + a] -= L->Del[i * r + a];
      }
    ++*it;
    s->stats.newton_iters++;
    res_prev = res;
    res = phgmg__romstep_residual(s, L, x, u3, *mm, err);
    if (res < PHGMG__R(0)) break;
    if (*mm && res > s->tol_step && res > PHGMG__R(0.25) * res_prev) {
      /* slow: the frozen E is too far from E(Y_i) here. Exact stage values
         from this iterate on, and for the next steps. */
      *mm = 0; *exact = 1; s->exact_hold = 16;
      res = phgmg__romstep_residual(s, L, x, u3, 0, err);
      if (res < PHGMG__R(0)) break;
      continue;
    }
    if (res_prev > PHGMG__R(0) && res / res_prev > *theta_max) *theta_max = res / res_prev;
  }
  return res;
}

/* Feedthrough at a stage: g^T Ph u + u^T Dh u (= u^T S u, N skew); t: m reals. */
PHGMG__ONLINE phgmg_real phgmg__rom_feed_energy(const phgmg_rom *rom, const phgmg_real *g, const phgmg_real *u,
                                                phgmg_real *t) {
  const int r = rom->r, m = rom->m;
  const phgmg_real *Dh = rom->PD + (size_t)r * m;
  phgmg_real v = PHGMG__R(0);
  int a, b;
  phgmg__r_gemvt(r, m, rom->PD, g, 0, t);
  for (a = 0; a < m; ++a) {
    v += t[a] * u[a];
    for (b = 0; b < m; ++b) v += u[a] * Dh[a + (size_t)b * m] * u[b];
  }
  return v;
}

/* A converged step: the stage values of the last correction, the new state,
   the energy over the step, the extrapolation data, when to refactor. */
PHGMG__ONLINE phgmg_result phgmg__romstep_accept(phgmg_rom_stepper *s, const phgmg__romstep_mem *L, phgmg_real *x,
                                                 const phgmg_real *u3, phgmg_real *y, phgmg_real energy[2], int mm,
                                                 int it, phgmg_real theta_max) {
  const phgmg_rom *rom = s->rom;
  const int r = rom->r, m = rom->m, n3 = 3 * r;
  int i, a;
  phgmg_real *xn = L->dZ;
  if (mm) { /* the last correction: Phi_i - Del_i ~ E(Y_i)^{-1} g(Y_i) */
    for (i = 0; i < n3; ++i) { L->Phi[i] -= L->Del[i]; L->F[i] -= L->Del[i]; }
  } else if (L->Phi) { /* exact stages: Phi = F - Bh u, for the extrapolation */
    int k;
    s->stats.exact_steps++;
    for (i = 0; i < n3; ++i) L->Phi[i] = L->F[i];
    if (u3)
      for (i = 0; i < 3; ++i)
        for (k = 0; k < m; ++k)
          for (a = 0; a < r; ++a) L->Phi[i * r + a] -= rom->Bh[a + (size_t)k * r] * u3[i * m + k];
    s->stale_e = 1;
  }
  for (a = 0; a < r; ++a) {
    phgmg_real v = x[a];
    for (i = 0; i < 3; ++i) v += s->dt * L->b[i] * L->F[i * r + a];
    xn[a] = v;
  }
  if (!phgmg__r_finite(xn, r)) return PHGMG_ERR_NANINF;
  if (energy) {
    phgmg_real sup = PHGMG__R(0), dis = PHGMG__R(0);
    for (i = 0; i < 3; ++i) {
      const phgmg_real *gi = L->G + i * r, *fi = L->F + i * r;
      phgmg_real si = PHGMG__R(0), di = PHGMG__R(0);
      /* dissipation rate gradH^T R gradH = -gradH^T K gradH = -g^T (f - Bh u) */
      for (a = 0; a < r; ++a) di -= gi[a] * fi[a];
      if (u3 && m > 0) {
        phgmg__r_gemvt(r, m, rom->Bh, gi, 0, L->Y);
        for (a = 0; a < m; ++a) { si += L->Y[a] * u3[i * m + a]; di += L->Y[a] * u3[i * m + a]; }
        if (rom->PD) {   /* feedthrough: g^T Ph u + u^T S u, supplied and dissipated */
          const phgmg_real pu = phgmg__rom_feed_energy(rom, gi, u3 + i * m, L->Y);
          si += pu;
          di += pu;
        }
      }
      sup += L->b[i] * si;
      dis += L->b[i] * di;
    }
    energy[0] += s->dt * sup;
    energy[1] += s->dt * dis;
  }
  /* Zp_k = p(1 + c_k) - x_new, p the collocation polynomial (nodes 0, c_i) */
  for (i = 0; i < 3; ++i)
    for (a = 0; a < r; ++a) {
      phgmg_real v = L->lag[i * 4] * x[a];
      int j;
      for (j = 0; j < 3; ++j) v += L->lag[i * 4 + 1 + j] * (x[a] + L->Z[j * r + a]);
      L->Zp[i * r + a] = v - xn[a];
      if (L->Phi)
        L->Php[i * r + a] = L->lagq[i * 3] * L->Phi[a] + L->lagq[i * 3 + 1] * L->Phi[r + a] +
                           L->lagq[i * 3 + 2] * L->Phi[2 * r + a];
    }
  phgmg__r_flush_subnormal(xn, r);
  phgmg__r_flush_subnormal(L->Zp, n3);
  if (L->Php) phgmg__r_flush_subnormal(L->Php, n3);
  for (a = 0; a < r; ++a) x[a] = xn[a];
  s->have_prev = 1;
  if (theta_max > PHGMG__R(0.5)) s->have_lu = 0; /* slow contraction: refactor next step */
  /* fresh factors of E next step after a step with more than one
     iteration, and every 8 steps: the last correction Phi - Del is exact
     up to (I - E_f^{-1} E(Y)) Del, so E_f must not drift far */
  s->stale_e = it > 1 || s->stats.steps % 8 == 7;
  s->stats.steps++;
  if (y) phgmg_rom_output(rom, x, y, L->work);
  return PHGMG_OK;
}

/* Deployment counters after a step: consecutive failures, and whether the
   state left the training envelope (rom->env_lo/hi). Returns rc. */
PHGMG__ONLINE phgmg_result phgmg__rom_track(phgmg_rom_stepper *s, const phgmg_real *x, phgmg_result rc) {
  const phgmg_rom *rom = s->rom;
  int a;
  if (rc != PHGMG_OK) {
    if (++s->stats.consec_failures > s->stats.max_consec_failures)
      s->stats.max_consec_failures = s->stats.consec_failures;
    return rc;
  }
  s->stats.consec_failures = 0;
  if (rom->env_lo && rom->env_hi)
    for (a = 0; a < rom->r; ++a)
      if (!(x[a] >= rom->env_lo[a] && x[a] <= rom->env_hi[a])) { s->stats.outside_steps++; break; }
  if (rom->q_max && rom->Ms && rom->kind == PHGMG_ROM_QUADRATIC) { /* ||q||, q = Ms (x2 kron x2) / 2 */
    const int m = rom->m, p = rom->r - rom->m, rn = rom->rn;
    phgmg_real s2 = PHGMG__R(0);
    int i, k, j;
    for (i = 0; i < rn; ++i) {
      phgmg_real qi = PHGMG__R(0);
      for (k = 0; k < p; ++k)
        for (j = 0; j < p; ++j) qi += rom->Ms[i + (size_t)(k * p + j) * rn] * x[m + k] * x[m + j];
      qi *= PHGMG__R(0.5);
      s2 += qi * qi;
    }
    if (!(s2 <= rom->q_max[0] * rom->q_max[0])) s->stats.q_outside_steps++;
  }
  return rc;
}

PHGMG_DEF phgmg_result phgmg_rom_step(phgmg_rom_stepper *s, phgmg_real *x, const phgmg_real *u3,
                                      phgmg_real *y, phgmg_real energy[2]) {
  const phgmg_rom *rom;
  phgmg__romstep_mem L;
  int r, m, attempt, tried_fresh = 0, exact = 0;
  phgmg_result err = PHGMG_OK;
  if (!s || !x || !s->rom) return PHGMG_ERR_INVALID_ARG;
  rom = s->rom;
  r = rom->r; m = rom->m;
  if (!phgmg__r_finite(x, r) || (u3 && !phgmg__r_finite(u3, 3 * m))) return PHGMG_ERR_NANINF;
  phgmg__romstep_layout(rom, s->use_map, s->ws, &L);
  if (s->use_map) return phgmg__rom_track(s, x, phgmg__romstep_map(s, &L, x, u3, y, energy));
  if (s->exact_hold > 0) { s->exact_hold--; exact = 1; }
  s->tol_step = s->tol;
  if (s->tol_rel) {   /* the default tolerance follows states larger than 1 (and, in
                         phgmg__romstep_tol, stage increments) */
    int a;
    for (a = 0; a < r; ++a)
      if (PHGMG__RABS(x[a]) * s->tol > s->tol_step) s->tol_step = PHGMG__RABS(x[a]) * s->tol;
  }
  /* attempts: (1) the kept factors; (2) fresh factors at x; (3) QUADRATIC only:
     the same Newton with exact stage values F = phgmg_rom_rhs (a factorisation
     of E per stage) -- for when E varies too fast for frozen factors. */
  for (attempt = 0; attempt < 3; ++attempt) {
    phgmg_real res, theta_max = PHGMG__R(0);
    int mm = L.Phi != NULL && !exact, it = 0;
    err = phgmg__romstep_start(s, &L, x, attempt, mm, &tried_fresh);
    if (err != PHGMG_OK) break;
    res = phgmg__romstep_residual(s, &L, x, u3, mm, &err);
    if (res < PHGMG__R(0)) {
      if (err == PHGMG_ERR_NANINF && !tried_fresh) continue; /* bad guess/factors: retry fresh */
      if (err == PHGMG_ERR_NANINF && mm) { exact = 1; continue; }
      break;
    }
    res = phgmg__romstep_iterate(s, &L, x, u3, res, &mm, &exact, &it, &theta_max, &err);
    if (res >= PHGMG__R(0) && res <= s->tol_step) {
      err = phgmg__romstep_accept(s, &L, x, u3, y, energy, mm, it, theta_max);
      if (err == PHGMG_OK) return phgmg__rom_track(s, x, PHGMG_OK);
      break;
    }
    if (res >= PHGMG__R(0)) err = PHGMG_ERR_NOT_CONVERGED;
    if (!tried_fresh) continue;      /* stale factors: retry with fresh ones */
    if (mm) { exact = 1; continue; } /* frozen E too far off: exact stages */
    break;
  }
  s->stats.failures++;
  s->have_prev = 0;
  s->have_lu = 0;
  return phgmg__rom_track(s, x, err == PHGMG_OK ? PHGMG_ERR_NOT_CONVERGED : err);
}

#ifndef PHGMG_NO_OFFLINE
/* >>reduce (implementation): the reduced object =========================== */

/* The methods, described once: what the pipeline and the checks ask of a
   method is read from this table (a new method is a row here and its stage
   functions). */
typedef struct phgmg__method_row {
  int by_reduce;     /* built by phgmg_reduce (PRBT: by phgmg_prbt, >>linear)         */
  int gmg;           /* GMG reduction: phi = [B, V1] x (+ V2 eta), W from G = (J - R)^-1 */
  int quadratic;     /* a manifold term: reduced model of kind QUADRATIC              */
  int test_w;        /* a stored test basis W (point reduction xr = W^T x)           */
  int extras;        /* takes feedthrough and dampers (linear maps, manual 1.6, 1.7) */
} phgmg__method_row;
static const phgmg__method_row phgmg__methods[PHGMG_METHOD_COUNT] = {
  {0, 0, 0, 0, 0},   /* 0: not a method */
  {1, 1, 0, 0, 1},   /* GMG_POD      */
  {1, 1, 1, 0, 0},   /* GMG_QM       */
  {1, 0, 0, 1, 1},   /* SP1          */
  {1, 0, 0, 1, 1},   /* SP2          */
  {1, 1, 1, 0, 0},   /* GMG_MANIFOLD */
  {0, 0, 0, 1, 0},   /* PRBT         */
};
PHGMG__PRIV const phgmg__method_row *phgmg__method(int method) {
  return phgmg__methods + (method > 0 && method < (int)PHGMG_METHOD_COUNT ? method : 0);
}

/* The hyper-reduction kinds (opts.hyper.kind, manual 3.4), described once:
   empirical quadrature with weights >= 0, or the paper's structure-preserving
   DEIM with its point selection (a new kind is a row here). */
typedef struct phgmg__hyper_row {
  int quadrature;                /* 1: ECSW (phgmg_ecsw_separable); 0: DEIM    */
  phgmg_deim_method points;      /* DEIM's point selection (phgmg_deim_select) */
} phgmg__hyper_row;
static const phgmg__hyper_row phgmg__hypers[PHGMG_HYPER_COUNT] = {
  {1, PHGMG_DEIM_QDEIM},   /* ECSW (points unused) */
  {0, PHGMG_DEIM_QDEIM},   /* QDEIM                */
  {0, PHGMG_DEIM_GREEDY},  /* GREEDY               */
};

/* Where a reduction takes its snapshot coordinates and blocks from when it
   runs on a study's cached bases (phgmg_study_reduce): none (computed from
   the data), the GMG basis [B, Ua], or SP1's / SP2's Up. */
enum { PHGMG__SF_NONE = 0, PHGMG__SF_GMG = 1, PHGMG__SF_SP1 = 2, PHGMG__SF_SP2 = 3 };

/* A small owner list: every array of a phgmg_reduced is allocated through it,
   so destroy (and every error path) frees exactly what was allocated. */
#define PHGMG__MAXBUF 56
struct phgmg_reduced {
  phgmg_allocator alloc;
  int use_alloc;
  void *bufs[PHGMG__MAXBUF];
  int nbufs;
  int N, m, r, p, rn, nd, method, kind;
  double *V0, *V2;     /* N x r, N x rn                        */
  double *QB, *RB;     /* thin QR of B: N x m, m x m           */
  double *W;           /* N x r point reduction for SP1/SP2    */
  double *M;           /* rn x p^2                             */
  int *coord;          /* nd: coordinates of the kept terms    */
  const phgmg_ph_system *sys;
  /* double blocks (same meaning as the phgmg_rom fields) */
  double *Bh, *Qh, *K, *G00, *G01, *G10, *G11, *Q01, *Q11, *Ms, *P0, *P1, *w;
  double *Phi, *Gam, *SX, *SU;
  double *poly, *expo; /* separable functions (built-in family): nphi rows */
  int nphi, nexp;
  int *term;           /* nd: full-model index of each kept term */
  phgmg_eta_fn eta;    /* GMG_MANIFOLD: the caller's eta          */
  void *eta_user;
  phgmg_real *rwork;   /* eta scratch: p + rn (1 + p + p^2)       */
  double *gwork;       /* GENERAL part: full-dimension workspace  */
  double map_dt;       /* step of the precomputed map          */
  phgmg_rom rom;       /* views into the phgmg_real copies     */
  double *env;         /* 2r: training envelope (lo, hi) of rho(x_j), widened */
  double *qmax;        /* 1: phgmg_rom.q_max (QUADRATIC)                       */
  double *Ainv;        /* SP1/SP2: (V^T Vg)^{-1}, r x r (W = Vg Ainv)          */
  const phgmg_study *study; /* the study that built it on its cached basis (else NULL) */
  int sbasis;          /* with study: PHGMG__SF_GMG ([B, Ua_1..p(+rn)]), _SP1, _SP2 (Up_1..r) */
  /* affine reference state (opts.ref; NULL: none): xbar (N), xbr = rho_lin(xbar)
     (r; rho(x) = rho_lin(x) - xbr), the online terms (phgmg_rom.ref_g/ref_s/xr_rest) */
  double *xbar, *xbr, *refg, *refs, *xrest;
  /* reduced dampers (manual 1.7): Cd r x ndamp, weights, laws (ndamp rows
     with one law per damper, else 1), full-model index of each kept damper */
  int ndamp;
  double *Cd, *dw, *dpoly;
  int *dterm;
  double *PD;          /* feedthrough: [W_z^T P; S + N], (r + m) x m (phgmg_rom.PD) */
};

/* A study (phgmg_study_create): what every reduction of one snapshot set
   shares, computed once. K* = modes kept; coordinates are K* x ns (ld K*). */
struct phgmg_study {
  phgmg_allocator alloc;
  int use_alloc;
  const phgmg_ph_system *sys;
  const double *X;
  int ldx, ns, N, m;
  double xx;               /* ||X||_F^2                                          */
  double *QB, *RB;         /* thin QR of B (N x m, m x m)                        */
  double *Ua, *Ca, *CB, *Ta, *Gf, *Qf; /* GMG: POD of Xa = X - BB^+X (N x ka), Ua^T Xa,
                              QB^T X (m x ns), tails Ta[k] = sum_i ||(I - P_[QB, Ua_1..k]) x_i||^2
                              (ka + 1), [B, Ua]^T G [B, Ua] and [B, Ua]^T Q [B, Ua] ((m+ka)^2) */
  int ka;
  double *Up, *Cp, *Tp, *Cq; /* SP: POD of X (N x kp), Up^T X, tails Tp (kp + 1), (Q Up)^T X */
  int kp;
  double *Ug, *Cg;         /* SP2: POD of the gradient snapshots (N x kg), Ug^T X */
  int kg;
  int deim_have, deim_method, deim_max, deim_nd, deim_nneg; /* DEIM cache (first use) */
  double deim_tol, deim_sigma;
  int *deim_pts;
  double *deim_w;
  /* PHGMG_LAMBDA_VALIDATED validation data (first use): the snapshots' outputs
     B^T grad H(x_j) (m x ns), and the probe runs' full-model outputs for
     one runs[0] (key: its input, x0 (copy), t0, dt, steps; Newton settings) */
  double *Yt, *Yp, *px0;
  double *cv;              /* lambda-selection regression errors on the grid (first use; key below) */
  int cv_p, cv_rn, cv_ng, cv_nf, cv_nb;
  double cv_lo, cv_hi;
  int pnv, pn, pit, phave;
  phgmg_input_fn pu;
  void *puser;
  double pt0, pdt, ptol;
  uint64_t fp;             /* fingerprint of the system at create (phgmg__sys_fingerprint) */
};

/* FNV-1a style hash of n doubles' bit patterns into h. */
PHGMG__PRIV uint64_t phgmg__hash_d(uint64_t h, const double *a, size_t n) {
  size_t i;
  if (!a) return (h ^ 0x9e3779b97f4a7c15ull) * 0x100000001b3ull;
  for (i = 0; i < n; ++i) {
    uint64_t w;
    memcpy(&w, a + i, sizeof w);
    h = (h ^ w) * 0x100000001b3ull;
  }
  return h;
}

/* A fingerprint of what a study precomputes from: the sizes and kinds, J,
   R, Q (dense or banded), B, and a separable part's indices, weights and
   coefficients (the callbacks themselves are not hashed). O(size of the
   system): N^2 for dense storage, (2 kb + 1) N banded. */
PHGMG__PRIV uint64_t phgmg__sys_fingerprint(const phgmg_ph_system *s) {
  const size_t N = (size_t)s->N, nm = s->storage == PHGMG_BANDED ? (size_t)(2 * s->kb + 1) * N : N * N;
  double hdr[7];
  uint64_t h = 0xcbf29ce484222325ull;
  int k;
  hdr[0] = s->N; hdr[1] = s->m; hdr[2] = (double)s->storage; hdr[3] = s->kb; hdr[4] = (double)s->nl;
  hdr[5] = s->nsep; hdr[6] = s->poly_deg + 64.0 * s->nexp + 4096.0 * s->phi_nfun;
  h = phgmg__hash_d(h, hdr, 7);
  if (s->storage == PHGMG_SPARSE) { /* the CSC copies: values, then the patterns */
    const int *cp, *ci;
    const double *cx;
    const double *M[3];
    size_t q;
    M[0] = s->J; M[1] = s->R; M[2] = s->Q;
    for (k = 0; k < 3; ++k)
      if (phgmg__ph_csc_of(s, M[k], &cp, &ci, &cx)) {
        h = phgmg__hash_d(h, cx, (size_t)cp[N]);
        for (q = 0; q < (size_t)cp[N]; ++q) { const double v = ci[q]; h = phgmg__hash_d(h, &v, 1); }
        for (q = 0; q <= N; ++q) { const double v = cp[q]; h = phgmg__hash_d(h, &v, 1); }
      }
  } else {
    h = phgmg__hash_d(h, s->J, nm);
    h = phgmg__hash_d(h, s->R, nm);
    h = phgmg__hash_d(h, s->Q, nm);
  }
  h = phgmg__hash_d(h, s->B, N * (size_t)s->m);
  if (s->nl == PHGMG_NL_SEPARABLE && s->nsep > 0) {
    const size_t nf = s->phi_nfun > 1 ? (size_t)s->phi_nfun : 1;
    for (k = 0; s->sep_idx && k < s->nsep; ++k) {
      const double v = s->sep_idx[k];
      h = phgmg__hash_d(h, &v, 1);
    }
    h = phgmg__hash_d(h, s->sep_w, (size_t)s->nsep);
    if (s->poly_deg > 0 && s->poly) h = phgmg__hash_d(h, s->poly, nf * (size_t)(s->poly_deg + 1));
    if (s->nexp > 0) h = phgmg__hash_d(h, s->expo, nf * 2 * (size_t)s->nexp);
  }
  return h;
}

PHGMG__PRIV void *phgmg__red_alloc(phgmg_reduced *red, size_t bytes) {
  void *p;
  if (red->nbufs >= PHGMG__MAXBUF) return NULL;
  p = phgmg__alloc(red->use_alloc ? &red->alloc : NULL, bytes);
  if (p) red->bufs[red->nbufs++] = p;
  return p;
}
PHGMG__PRIV double *phgmg__red_d(phgmg_reduced *red, size_t n) {
  double *p = PHGMG__CAST(double *, phgmg__red_alloc(red, (n ? n : 1) * sizeof(double)));
  if (p) memset(p, 0, (n ? n : 1) * sizeof(double));
  return p;
}

PHGMG_DEF void phgmg_reduced_destroy(phgmg_reduced *red) {
  int i;
  phgmg_allocator a;
  int use;
  if (!red) return;
  a = red->alloc;
  use = red->use_alloc;
  for (i = 0; i < red->nbufs; ++i) phgmg__free(use ? &a : NULL, red->bufs[i]);
  phgmg__free(use ? &a : NULL, red);
}

PHGMG_DEF const phgmg_rom *phgmg_reduced_rom(const phgmg_reduced *red) { return red ? &red->rom : NULL; }
PHGMG_DEF int phgmg_reduced_N(const phgmg_reduced *red) { return red ? red->N : 0; }

/* >>pod (implementation) ================================================== */
/* C (m x n) = A^T B with A: k x m, B: k x n (column-major, tight). */
PHGMG__PRIV void phgmg__atb(int k, int m, int n, const double *A, const double *B, double *C) {
  phgmg_gemm('T', 'N', m, n, k, 1.0, A, k, B, k, 0.0, C, m);
}

#ifndef PHGMG_POD_OVERSAMPLE
#define PHGMG_POD_OVERSAMPLE 20
#endif
#ifndef PHGMG_POD_RANDOMIZED_MIN
#define PHGMG_POD_RANDOMIZED_MIN 0
#endif
#ifndef PHGMG_POD_POWER_ITERS
#define PHGMG_POD_POWER_ITERS 2
#endif
#ifndef PHGMG_POD_SEED
#define PHGMG_POD_SEED 20260611ul
#endif

PHGMG_DEF phgmg_result phgmg_pod(int N, int ns, const double *X, int ldx, int kmax, double tol,
                                 double *V, int ldv, double *S, int *k_out,
                                 const phgmg_allocator *alloc) {
  double *s;
  int k = 0, rank = 0, i;
  phgmg_result rc;
  if (!X || !V || !k_out) return PHGMG_ERR_INVALID_ARG;
  if (N < 1 || ns < 1 || kmax < 1 || ldx < N || ldv < N || kmax > PHGMG__MIN(N, ns)) return PHGMG_ERR_SIZE;
#if PHGMG_POD_RANDOMIZED_MIN > 0
  if (!(tol > 0.0) && (double)N * (double)ns >= (double)(PHGMG_POD_RANDOMIZED_MIN) &&
      kmax + PHGMG_POD_OVERSAMPLE <= PHGMG__MIN(N, ns) / 4)
    return phgmg_pod_randomized(N, ns, X, ldx, kmax, PHGMG_POD_POWER_ITERS, PHGMG_POD_SEED,
                                V, ldv, S, k_out, alloc);
#endif
  s = phgmg__dalloc(alloc, (size_t)kmax);
  if (!s) return PHGMG_ERR_NOMEM;
  rc = phgmg_svd(N, ns, X, ldx, kmax, s, V, ldv, NULL, 1, &k, &rank, alloc);
  if (rc == PHGMG_OK) {
    if (tol > 0.0)
      for (i = 0; i < k; ++i)
        if (!(s[i] > tol * s[0])) { k = i; break; }
    for (i = 0; i < k && S; ++i) S[i] = s[i];
    *k_out = k;
  }
  phgmg__free(alloc, s);
  return rc;
}

/* ---- randomized POD ---------------------------------------------------- */

/* splitmix64 (Steele, Lea & Flood 2014): a full-period 64-bit generator. */
PHGMG__PRIV unsigned long long phgmg__splitmix64(unsigned long long *state) {
  unsigned long long z = (*state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/* n standard normal numbers times 2^e (Marsaglia's polar method on splitmix64). */
PHGMG__PRIV void phgmg__gauss_fill(size_t n, unsigned long long *state, int e, double *out) {
  size_t t = 0;
  while (t < n) {
    double u = (double)(phgmg__splitmix64(state) >> 11) * ldexp(1.0, -52) - 1.0;
    double v = (double)(phgmg__splitmix64(state) >> 11) * ldexp(1.0, -52) - 1.0;
    double s = u * u + v * v, f;
    if (s >= 1.0 || s == 0.0) continue;
    f = ldexp(sqrt(-2.0 * log(s) / s), e);
    out[t++] = u * f;
    if (t < n) out[t++] = v * f;
  }
}

/* Largest |entry| of X (N x ns); -1 if X holds NaN or Inf. */
PHGMG__PRIV double phgmg__absmax_finite(int N, int ns, const double *X, int ldx) {
  double amax = 0.0;
  int i, j;
  for (j = 0; j < ns; ++j) {
    const double *x = X + (size_t)j * (size_t)ldx;
    double cmax = 0.0;
    for (i = 0; i < N; ++i) {
      double a = fabs(x[i]);
      cmax = a > cmax ? a : cmax;
      if (!(a <= 1.7976931348623157e308)) return -1.0;
    }
    if (cmax > amax) amax = cmax;
  }
  return amax;
}

/* Q (m x l, ld m) <- orthonormal basis of its columns (Householder QR, thin Q). */
PHGMG__PRIV phgmg_result phgmg__orth(int m, int l, double *Q, double *tau) {
  phgmg_result rc = phgmg_qr(m, l, Q, m, tau);
  if (rc == PHGMG_OK) phgmg_qr_form_q(m, l, Q, m, tau, NULL);
  return rc;
}

/* A (m x n, tight) *= 2^e (no-op for e = 0). */
PHGMG__PRIV void phgmg__scale2(size_t cnt, double *A, int e) {
  size_t t;
  if (e != 0)
    for (t = 0; t < cnt; ++t) A[t] = ldexp(A[t], e);
}

/* Products with Xa = X - QB CB (QB N x m orthonormal, CB = QB^T X m x ns;
   QB NULL: Xa = X). t = 'N': Out (N x l, ld N) = Xa M (M ns x l, ld ns);
   t = 'T': Out (ns x l) = Xa^T M (M N x l). T: m x l scratch. */
PHGMG__PRIV void phgmg__xa_mul(char t, int N, int ns, int l, const double *X, int ldx, const double *QB, int m,
                               const double *CB, const double *M, double *Out, double *T) {
  if (t == 'N') {
    phgmg_gemm('N', 'N', N, l, ns, 1.0, X, ldx, M, ns, 0.0, Out, N);
    if (!QB) return;
    phgmg_gemm('N', 'N', m, l, ns, 1.0, CB, m, M, ns, 0.0, T, m);
    phgmg_gemm('N', 'N', N, l, m, -1.0, QB, N, T, m, 1.0, Out, N);
  } else {
    phgmg_gemm('T', 'N', ns, l, N, 1.0, X, ldx, M, N, 0.0, Out, ns);
    if (!QB) return;
    phgmg_gemm('T', 'N', m, l, N, 1.0, QB, N, M, N, 0.0, T, m);
    phgmg_gemm('T', 'N', ns, l, m, -1.0, CB, m, T, m, 1.0, Out, ns);
  }
}

/* phgmg_pod_randomized of X, or of X - QB CB (see phgmg__xa_mul; the scaling
   by 2^-e from max|X|); with chk != NULL also the a-posteriori check
   *chk = ||X W - V diag(S)||_F / S_1 (W = the right singular vectors, ns x k:
   X^T V = W diag(S) holds by construction, so the k triplets are exact for a
   perturbation of X of 2-norm at most *chk S_1). One more product with X (k columns). */
PHGMG__PRIV phgmg_result phgmg__pod_rand_core(int N, int ns, const double *X, int ldx, const double *QB, int m,
                                              const double *CB, int kmax, int power_iters,
                                              unsigned long seed, double *V, int ldv, double *S, int *k_out,
                                              double *chk, const phgmg_allocator *alloc) {
  double *Y, *Z, *Uz, *Ub, *tau, *s, *T, amax;
  int l, it, i, k = 0, e = 0;
  unsigned long long state = (unsigned long long)seed;
  size_t ny, nz;
  phgmg_result rc = PHGMG_OK;
  if (!X || !V || !k_out || power_iters < 0) return PHGMG_ERR_INVALID_ARG;
  if (N < 1 || ns < 1 || kmax < 1 || ldx < N || ldv < N || kmax > PHGMG__MIN(N, ns)) return PHGMG_ERR_SIZE;
  amax = phgmg__absmax_finite(N, ns, X, ldx);
  if (amax < 0.0) return PHGMG_ERR_NANINF;
  if (amax == 0.0) { *k_out = 0; return PHGMG_OK; }
  /* out of [2^-256, 2^256]: multiply every factor applied to X by 2^-e (exact) */
  if (amax < ldexp(1.0, -256) || amax > ldexp(1.0, 256)) {
    (void)frexp(amax, &e);
    e = PHGMG__MAX(-1000, PHGMG__MIN(1000, e));
  }
  l = PHGMG__MIN(kmax + PHGMG_POD_OVERSAMPLE, PHGMG__MIN(N, ns));
  ny = (size_t)N * (size_t)l;
  nz = (size_t)ns * (size_t)l;
  Y = phgmg__dalloc(alloc, ny);
  Z = phgmg__dalloc(alloc, 2 * nz + (size_t)l * (size_t)l + 2 * (size_t)l + (size_t)(QB ? m : 0) * (size_t)l);
  if (!Y || !Z) { phgmg__free(alloc, Y); phgmg__free(alloc, Z); return PHGMG_ERR_NOMEM; }
  Uz = Z + nz;
  Ub = Uz + nz;
  tau = Ub + (size_t)l * (size_t)l;
  s = tau + l;
  T = s + l;
  phgmg__gauss_fill(nz, &state, -e, Z);
  phgmg__xa_mul('N', N, ns, l, X, ldx, QB, m, CB, Z, Y, T);
  rc = phgmg__orth(N, l, Y, tau);
  for (it = 0; it < power_iters && rc == PHGMG_OK; ++it) {
    phgmg__scale2(ny, Y, -e);
    phgmg__xa_mul('T', N, ns, l, X, ldx, QB, m, CB, Y, Z, T);
    rc = phgmg__orth(ns, l, Z, tau);
    if (rc != PHGMG_OK) break;
    phgmg__scale2(nz, Z, -e);
    phgmg__xa_mul('N', N, ns, l, X, ldx, QB, m, CB, Z, Y, T);
    rc = phgmg__orth(N, l, Y, tau);
  }
  if (rc == PHGMG_OK) {
    /* Z = 2^-e B^T = X^T (2^-e Q); its SVD Uz diag(s) Ub^T gives U = Q Ub */
    phgmg__scale2(ny, Y, -e);
    phgmg__xa_mul('T', N, ns, l, X, ldx, QB, m, CB, Y, Z, T);
    phgmg__scale2(ny, Y, e);
    rc = phgmg_svd(ns, l, Z, ns, kmax, s, Uz, ns, Ub, l, &k, NULL, alloc);
  }
  if (rc == PHGMG_OK) {
    if (k > 0) phgmg_gemm('N', 'N', N, k, l, 1.0, Y, N, Ub, l, 0.0, V, ldv);
    for (i = 0; i < k && S; ++i) S[i] = ldexp(s[i], e);
    *k_out = k;
    if (chk && k > 0) { /* Y (N x k) = 2^-e X Uz - V diag(s) (Y is free now) */
      phgmg__scale2(nz, Uz, -e);
      phgmg__xa_mul('N', N, ns, k, X, ldx, QB, m, CB, Uz, Y, T);
      for (it = 0; it < k; ++it) phgmg__axpy(N, -s[it], V + (size_t)it * ldv, Y + (size_t)it * N);
      *chk = phgmg_normf(N, k, Y, N) / s[0];
    }
  }
  phgmg__free(alloc, Y);
  phgmg__free(alloc, Z);
  return rc;
}

PHGMG_DEF phgmg_result phgmg_pod_randomized(int N, int ns, const double *X, int ldx, int kmax,
                                            int power_iters, unsigned long seed, double *V,
                                            int ldv, double *S, int *k_out,
                                            const phgmg_allocator *alloc) {
  return phgmg__pod_rand_core(N, ns, X, ldx, NULL, 0, NULL, kmax, power_iters, seed, V, ldv, S, k_out, NULL, alloc);
}

/* The POD phgmg_reduce uses (its stage_basis). Exact (phgmg_pod) unless the
   snapshot matrix is large, N*ns >= PHGMG_POD_AUTO_MIN (default 2e7: N >= 20 000
   at 1001 snapshots), and few modes are wanted, 4 (k + PHGMG_POD_OVERSAMPLE) <=
   min(N, ns): then phgmg_pod_randomized with its default power iterations,
   accepted if the a-posteriori check ||X W - V diag(S)||_F <= PHGMG_POD_CHECK_TOL
   (default 1e-10) S_1 holds and all k modes came out, else the exact POD
   (fallback). *how: 0 exact, 1 randomized, -1 randomized rejected -> exact;
   *chk: the check's value (untouched when not tried). GMG-POD/SP at large N
   skip the N x ns copy of the adjusted snapshots (phgmg__basis_pod_implicit). PHGMG_POD_AUTO_MIN <= 0: always exact. */
#ifndef PHGMG_POD_AUTO_MIN
#define PHGMG_POD_AUTO_MIN 2e7
#endif
#ifndef PHGMG_POD_CHECK_TOL
#define PHGMG_POD_CHECK_TOL 1e-10
#endif
PHGMG__PRIV int phgmg__pod_rand_wanted(int N, int ns, int k) {
  return (double)(PHGMG_POD_AUTO_MIN) > 0.0 && (double)N * (double)ns >= (double)(PHGMG_POD_AUTO_MIN) &&
         4 * (k + PHGMG_POD_OVERSAMPLE) <= PHGMG__MIN(N, ns);
}
/* *how on entry: -1 = the randomized POD was rejected already (exact only). */
PHGMG__PRIV phgmg_result phgmg__pod_auto(int N, int ns, const double *X, int ldx, int k, double *V, int ldv,
                                         double *S, int *k_out, int *how, double *chk,
                                         const phgmg_allocator *alloc) {
  if (*how != -1 && phgmg__pod_rand_wanted(N, ns, k)) {
    phgmg_result rc = phgmg__pod_rand_core(N, ns, X, ldx, NULL, 0, NULL, k, PHGMG_POD_POWER_ITERS, PHGMG_POD_SEED, V,
                                           ldv, S, k_out, chk, alloc);
    if (rc == PHGMG_ERR_NOMEM || rc == PHGMG_ERR_NANINF) return rc;
    if (rc == PHGMG_OK && *k_out == k && *chk <= PHGMG_POD_CHECK_TOL) { *how = 1; return PHGMG_OK; }
    *how = -1;
  }
  return phgmg_pod(N, ns, X, ldx, k, 0.0, V, ldv, S, k_out, alloc);
}

/* Thin QR of B (N x m): QB (N x m) orthonormal, RB (m x m) upper triangular.
   PHGMG_ERR_RANK if B is rank deficient. */
PHGMG__PRIV phgmg_result phgmg__thin_qr(int N, int m, const double *B, double *QB, double *RB,
                                        const phgmg_allocator *alloc) {
  double *tau, *work;
  double rmax = 0.0;
  int i, j;
  phgmg_result rc;
  tau = phgmg__dalloc(alloc, (size_t)(2 * m + 1));
  if (!tau) return PHGMG_ERR_NOMEM;
  work = tau + m;
  for (j = 0; j < m; ++j) memcpy(QB + (size_t)j * N, B + (size_t)j * N, (size_t)N * sizeof(double));
  rc = phgmg_qr(N, m, QB, N, tau);
  if (rc == PHGMG_OK) {
    for (j = 0; j < m; ++j)
      for (i = 0; i < m; ++i) RB[i + j * m] = i <= j ? QB[i + (size_t)j * N] : 0.0;
    for (j = 0; j < m; ++j) rmax = PHGMG__MAX(rmax, fabs(RB[j + j * m]));
    for (j = 0; j < m; ++j)
      if (!(fabs(RB[j + j * m]) > 1e3 * PHGMG__EPS * (double)N * rmax)) rc = PHGMG_ERR_RANK;
    if (rc == PHGMG_OK) phgmg_qr_form_q(N, m, QB, N, tau, work);
  }
  phgmg__free(alloc, tau);
  return rc;
}

/* Y = (I - Q Q^T) X for Q (N x k orthonormal), X N x ns; tmp: k x ns. */
PHGMG__PRIV void phgmg__orth_remove(int N, int k, const double *Q, int ns, double *X, int ldx, double *tmp) {
  if (k < 1) return;
  phgmg_gemm('T', 'N', k, ns, N, 1.0, Q, N, X, ldx, 0.0, tmp, k);
  phgmg_gemm('N', 'N', N, ns, k, -1.0, Q, N, tmp, k, 1.0, X, ldx);
}

PHGMG_DEF phgmg_result phgmg_adjust_snapshots(int N, int m, const double *B, int ns, const double *X,
                                              int ldx, double *Xa, int ldxa, const phgmg_allocator *alloc) {
  double *QB, *tmp;
  phgmg_result rc;
  int j;
  if (!B || !X || !Xa) return PHGMG_ERR_INVALID_ARG;
  if (N < 1 || m < 1 || m > N || ns < 1 || ldx < N || ldxa < N) return PHGMG_ERR_SIZE;
  QB = phgmg__dalloc(alloc, (size_t)N * m + (size_t)m * m + (size_t)m * ns);
  if (!QB) return PHGMG_ERR_NOMEM;
  tmp = QB + (size_t)N * m;
  rc = phgmg__thin_qr(N, m, B, QB, tmp, alloc);
  if (rc == PHGMG_OK) {
    if (Xa != X)
      for (j = 0; j < ns; ++j) memcpy(Xa + (size_t)j * ldxa, X + (size_t)j * ldx, (size_t)N * sizeof(double));
    phgmg__orth_remove(N, m, QB, ns, Xa, ldxa, tmp + (size_t)m * m);
  }
  phgmg__free(alloc, QB);
  return rc;
}

/* Numerical rank floor of snapshots X: singular values at or below it are
   zero. Relative to X itself, not to the matrix being POD'd: the adjusted
   snapshots and the residual of a basis carry rounding noise of this size,
   and an SVD truncated relative to their own norm would count it as rank. */
PHGMG__PRIV double phgmg__rank_floor(int N, int ns, const double *X, int ldx) {
  return (double)PHGMG__MAX(N, ns) * PHGMG__EPS * phgmg_normf(N, ns, X, ldx);
}

PHGMG_DEF phgmg_result phgmg_pod_hierarchical(int N, int m, const double *B, int ns, const double *X,
                                              int ldx, int p, int rn, double *V1, double *V2,
                                              const phgmg_allocator *alloc) {
  double *Xa, *tmp, *S, rfloor;
  phgmg_result rc;
  int k = 0;
  if (!B || !X || !V1 || !V2) return PHGMG_ERR_INVALID_ARG;
  if (p < 1 || rn < 1 || p + rn + m > PHGMG__MIN(N, ns + m)) return PHGMG_ERR_SIZE;
  Xa = phgmg__dalloc(alloc, (size_t)N * ns + (size_t)p * ns + (size_t)p + (size_t)rn);
  if (!Xa) return PHGMG_ERR_NOMEM;
  tmp = Xa + (size_t)N * ns;
  S = tmp + (size_t)p * ns;
  rc = phgmg_adjust_snapshots(N, m, B, ns, X, ldx, Xa, N, alloc);
  rfloor = phgmg__rank_floor(N, ns, X, ldx);
  if (rc == PHGMG_OK) rc = phgmg_pod(N, ns, Xa, N, p, 0.0, V1, N, S, &k, alloc);
  if (rc == PHGMG_OK && (k < p || !(S[p - 1] > rfloor))) rc = PHGMG_ERR_SIZE;
  if (rc == PHGMG_OK) {
    phgmg__orth_remove(N, p, V1, ns, Xa, N, tmp);
    rc = phgmg_pod(N, ns, Xa, N, rn, 0.0, V2, N, S + p, &k, alloc);
    if (rc == PHGMG_OK && (k < rn || !(S[p + rn - 1] > rfloor))) rc = PHGMG_ERR_SIZE;
  }
  phgmg__free(alloc, Xa);
  return rc;
}

/* >>hyper (implementation) ================================================ */
PHGMG_DEF phgmg_result phgmg_deim(int nterms, int ns, const double *F, int ldf, const double *sw,
                                  double tol, int kmax, int *pts, double *w, int *nd_out,
                                  int *nneg, double *sigma_ratio, const phgmg_allocator *alloc) {
  return phgmg_deim_select(nterms, ns, F, ldf, sw, tol, kmax, PHGMG_DEIM_QDEIM, pts, w, nd_out, nneg,
                           sigma_ratio, alloc);
}

/* Greedy DEIM points of U (n x keep, ld n): pts[0] = argmax |u_0|, then
   pts[l] = argmax |u_l - U_{<l} c|, (P^T U_{<l}) c = P^T u_l. First index
   wins ties. A: keep x keep, c: keep doubles, ipiv: keep ints. */
PHGMG__PRIV phgmg_result phgmg__deim_greedy(int n, int keep, const double *U, int *pts, double *A, double *c,
                                            int *ipiv) {
  int i, j, l, best;
  double bmax;
  for (l = 0; l < keep; ++l) {
    const double *ul = U + (size_t)l * n;
    if (l > 0) {
      for (j = 0; j < l; ++j)
        for (i = 0; i < l; ++i) A[i + (size_t)j * l] = U[pts[i] + (size_t)j * n];
      for (i = 0; i < l; ++i) c[i] = ul[pts[i]];
      if (phgmg_lu_factor(l, A, l, ipiv) != PHGMG_OK) return PHGMG_ERR_SINGULAR;
      phgmg_lu_solve('N', l, A, l, ipiv, 1, c, l);
    }
    best = -1;
    bmax = -1.0;
    for (i = 0; i < n; ++i) {
      double r = ul[i];
      for (j = 0; j < l; ++j) r -= U[i + (size_t)j * n] * c[j];
      if (fabs(r) > bmax) { bmax = fabs(r); best = i; }
    }
    if (!(bmax > 0.0)) return PHGMG_ERR_SINGULAR;
    pts[l] = best;
  }
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_deim_select(int nterms, int ns, const double *F, int ldf, const double *sw,
                                         double tol, int kmax, phgmg_deim_method method, int *pts, double *w,
                                         int *nd_out, int *nneg, double *sigma_ratio,
                                         const phgmg_allocator *alloc) {
  double *U, *S, *Ut, *tau, *work, *PU;
  int *jpvt, *ipiv;
  int k = 0, kk, rank = 0, i, j, neg = 0;
  phgmg_result rc;
  if (!F || !pts || !w || !nd_out) return PHGMG_ERR_INVALID_ARG;
  if ((int)method < 0 || (int)method >= (int)PHGMG_DEIM_METHOD_COUNT) return PHGMG_ERR_INVALID_ARG;
  if (!(tol >= 0.0 && tol < 1.0) || kmax < 0) return PHGMG_ERR_INVALID_ARG;
  if (nterms < 1 || ns < 1 || ldf < nterms) return PHGMG_ERR_SIZE;
  if (!phgmg__mat_finite(nterms, ns, F, ldf)) return PHGMG_ERR_NANINF; /* padding rows are not data */
  if (tol == 0.0) tol = 1e-8;
  kk = PHGMG__MIN(nterms, ns);
  if (kmax > 0) kk = PHGMG__MIN(kk, kmax + 1);
  U = phgmg__dalloc(alloc, (size_t)nterms * kk + (size_t)kk + (size_t)kk * nterms + (size_t)kk +
                               2 * (size_t)nterms + (size_t)kk * kk + (size_t)kk);
  jpvt = phgmg__ialloc(alloc, (size_t)nterms + (size_t)kk);
  if (!U || !jpvt) { phgmg__free(alloc, U); phgmg__free(alloc, jpvt); return PHGMG_ERR_NOMEM; }
  S = U + (size_t)nterms * kk;
  Ut = S + kk;
  tau = Ut + (size_t)kk * nterms;
  work = tau + kk;
  PU = work + 2 * (size_t)nterms;
  ipiv = jpvt + nterms;
  rc = phgmg_svd(nterms, ns, F, ldf, kk, S, U, nterms, NULL, 1, &k, &rank, alloc);
  if (rc == PHGMG_OK) {
    int keep = 0;
    for (i = 0; i < k; ++i) if (S[i] > tol * S[0]) keep = i + 1;
    if (kmax > 0 && keep > kmax) keep = kmax;
    if (keep < 1) keep = 1;
    if (sigma_ratio) *sigma_ratio = (keep < k && S[0] > 0.0) ? S[keep] / S[0] : 0.0;
    if (method == PHGMG_DEIM_GREEDY) {
      rc = phgmg__deim_greedy(nterms, keep, U, pts, PU, tau, ipiv);
    } else { /* Q-DEIM: pivoted QR of U^T (keep x nterms); points = first keep pivots */
      for (j = 0; j < nterms; ++j)
        for (i = 0; i < keep; ++i) Ut[i + (size_t)j * keep] = U[j + (size_t)i * nterms];
      rc = phgmg_qrcp(keep, nterms, Ut, keep, tau, jpvt, work);
      for (i = 0; i < keep; ++i) pts[i] = jpvt[i];
    }
    if (rc == PHGMG_OK) {
      /* w = (P^T U)^{-T} U^T sw: solve (P^T U)^T w = U^T sw */
      for (j = 0; j < keep; ++j)       /* PU = P^T U (keep x keep) */
        for (i = 0; i < keep; ++i) PU[i + (size_t)j * keep] = U[pts[i] + (size_t)j * nterms];
      for (j = 0; j < keep; ++j) {
        double sacc = 0.0;
        for (i = 0; i < nterms; ++i) sacc += U[i + (size_t)j * nterms] * (sw ? sw[i] : 1.0);
        w[j] = sacc;
      }
      rc = phgmg_lu_factor(keep, PU, keep, ipiv);
      if (rc == PHGMG_OK) {
        phgmg_lu_solve('T', keep, PU, keep, ipiv, 1, w, keep);
        for (i = 0; i < keep; ++i) if (w[i] < 0.0) ++neg;
        if (!phgmg__all_finite(w, (size_t)keep)) rc = PHGMG_ERR_NANINF;
        *nd_out = keep;
        if (nneg) *nneg = neg;
      }
    }
  }
  phgmg__free(alloc, U);
  phgmg__free(alloc, jpvt);
  return rc;
}

/* Lawson-Hanson core shared by phgmg_nnls and phgmg_ecsw. Three forms of the
   same problem min ||C x - d||^2 + rr0 (x >= 0, n unknowns):
   QR form (C k x n and d; G NULL): passive least squares by Householder QR
   (phgmg_lstsq), gradient C^T (d - C x);
   Gram form (G = C^T C n x n, c = C^T d, dd = ||d||^2 + rr0; C NULL): passive
   normal equations by a Cholesky factor L of G_PP, extended by one row per
   added index and refactored after drops; gradient c - G x;
   hybrid (G, c and C, d): as the Gram form, but each passive solve gets one
   step of refinement with the true residual d - C_P z (corrected semi-normal
   equations: QR-like accuracy while cond(C_P) < ~1e7), the residual is
   computed from C, and a claim of optimality by the Gram gradient is checked
   with the true gradient C^T (d - C x) (one pass over C). */
typedef struct phgmg__nnls_prob {
  int n, k;
  const double *C, *d; int ldc;   /* QR form (C != NULL)  */
  const double *G, *c; int ldg;   /* Gram form            */
  double dd, rr0;                 /* ||d||^2 (Gram: + rr0), constant residual part */
  double wtol;                    /* gradient threshold for optimality */
} phgmg__nnls_prob;

typedef struct phgmg__nnls_ws {
  int *P, *flag;          /* passive list; flag: 1 passive, 2 excluded until the next step */
  int np;
  double *z, *g, *L, *Cp; /* z, gradient: n; L: n x n (Gram); Cp: k x n (QR) */
  double *r;              /* k: residual (hybrid)                              */
} phgmg__nnls_ws;

/* Cholesky of G_PP into L (lower, ld n) from scratch; 0 if not positive. */
PHGMG__PRIV int phgmg__nnls_chol(const phgmg__nnls_prob *pb, phgmg__nnls_ws *ws) {
  const int n = pb->n, np = ws->np;
  int i, j, t;
  for (j = 0; j < np; ++j)
    for (i = j; i < np; ++i) {
      double s = pb->G[ws->P[i] + (size_t)ws->P[j] * pb->ldg];
      for (t = 0; t < j; ++t) s -= ws->L[i + (size_t)t * n] * ws->L[j + (size_t)t * n];
      if (i == j) {
        if (!(s > 64.0 * PHGMG__EPS * pb->G[ws->P[j] + (size_t)ws->P[j] * pb->ldg])) return 0;
        ws->L[j + (size_t)j * n] = sqrt(s);
      } else {
        ws->L[i + (size_t)j * n] = s / ws->L[j + (size_t)j * n];
      }
    }
  return 1;
}

/* Append row np-1 of L for the index just added to P; 0 if (numerically) dependent. */
PHGMG__PRIV int phgmg__nnls_chol_add(const phgmg__nnls_prob *pb, phgmg__nnls_ws *ws) {
  const int n = pb->n, q = ws->np - 1, jn = ws->P[q];
  double s = pb->G[jn + (size_t)jn * pb->ldg], gjj = s;
  int i, t;
  for (i = 0; i < q; ++i) {
    double v = pb->G[ws->P[i] + (size_t)jn * pb->ldg];
    for (t = 0; t < i; ++t) v -= ws->L[i + (size_t)t * n] * ws->L[q + (size_t)t * n];
    v /= ws->L[i + (size_t)i * n];
    ws->L[q + (size_t)i * n] = v;
    s -= v * v;
  }
  if (!(s > 64.0 * PHGMG__EPS * gjj)) return 0;
  ws->L[q + (size_t)q * n] = sqrt(s);
  return 1;
}

/* z = (L L^T)^{-1} b_P (b gathered through P, or b itself when P is NULL; z may alias b). */
PHGMG__PRIV void phgmg__nnls_chol_solve(int n, int np, const double *L, const double *b, const int *P, double *z) {
  int i, t;
  for (i = 0; i < np; ++i) {
    double s = P ? b[P[i]] : b[i];
    for (t = 0; t < i; ++t) s -= L[i + (size_t)t * n] * z[t];
    z[i] = s / L[i + (size_t)i * n];
  }
  for (i = np - 1; i >= 0; --i) {
    double s = z[i];
    for (t = i + 1; t < np; ++t) s -= L[t + (size_t)i * n] * z[t];
    z[i] = s / L[i + (size_t)i * n];
  }
}

/* z_P = passive least-squares solution (z[i] belongs to P[i]). */
PHGMG__PRIV phgmg_result phgmg__nnls_solve(const phgmg__nnls_prob *pb, phgmg__nnls_ws *ws,
                                           const phgmg_allocator *alloc) {
  const int n = pb->n, np = ws->np;
  int i, t;
  if (!pb->G) {
    for (i = 0; i < np; ++i)
      memcpy(ws->Cp + (size_t)i * pb->k, pb->C + (size_t)ws->P[i] * pb->ldc, (size_t)pb->k * sizeof(double));
    if (np > pb->k) return PHGMG_ERR_RANK;
    return phgmg_lstsq(pb->k, np, 1, ws->Cp, pb->k, pb->d, pb->k, 0.0, ws->z, n, alloc);
  }
  phgmg__nnls_chol_solve(n, np, ws->L, pb->c, ws->P, ws->z);
  if (pb->C) { /* refinement: z += (L L^T)^{-1} C_P^T (d - C_P z) */
    double *h = ws->g; /* the gradient is recomputed after every solve */
    memcpy(ws->r, pb->d, (size_t)pb->k * sizeof(double));
    for (t = 0; t < np; ++t) phgmg__axpy(pb->k, -ws->z[t], pb->C + (size_t)ws->P[t] * pb->ldc, ws->r);
    for (i = 0; i < np; ++i) h[i] = phgmg__dot(pb->k, pb->C + (size_t)ws->P[i] * pb->ldc, ws->r);
    phgmg__nnls_chol_solve(n, np, ws->L, h, NULL, h);
    for (i = 0; i < np; ++i) ws->z[i] += h[i];
  }
  return PHGMG_OK;
}

/* Squared residual ||C x - d||^2 + rr0 at x; Gram form: dd - 2 c^T x + x^T G x
   (x supported on P), clamped at 0. Also the gradient g = C^T (d - C x). */
PHGMG__PRIV double phgmg__nnls_grad(const phgmg__nnls_prob *pb, phgmg__nnls_ws *ws, const double *x, double *tmp) {
  const int n = pb->n;
  int i, j;
  double r2 = 0.0;
  if (pb->C) { /* true residual */
    memcpy(tmp, pb->d, (size_t)pb->k * sizeof(double));
    for (j = 0; j < ws->np; ++j) phgmg__axpy(pb->k, -x[ws->P[j]], pb->C + (size_t)ws->P[j] * pb->ldc, tmp);
    for (i = 0; i < pb->k; ++i) r2 += tmp[i] * tmp[i];
    r2 += pb->rr0;
    if (!pb->G) {
      phgmg_gemv('T', pb->k, n, 1.0, pb->C, pb->ldc, tmp, 0.0, ws->g);
      return r2;
    }
  }
  memcpy(ws->g, pb->c, (size_t)n * sizeof(double));
  for (j = 0; j < ws->np; ++j) phgmg__axpy(n, -x[ws->P[j]], pb->G + (size_t)ws->P[j] * pb->ldg, ws->g);
  if (pb->C) return r2;
  r2 = pb->dd;
  for (j = 0; j < ws->np; ++j) r2 -= x[ws->P[j]] * (pb->c[ws->P[j]] + ws->g[ws->P[j]]);
  return r2 > 0.0 ? r2 : 0.0;
}

/* Drop the passive indices whose x is <= 0 (x set to exactly 0). */
PHGMG__PRIV void phgmg__nnls_drop(phgmg__nnls_ws *ws, double *x) {
  int i, q = 0;
  for (i = 0; i < ws->np; ++i) {
    const int j = ws->P[i];
    if (x[j] > 0.0) ws->P[q++] = j;
    else { x[j] = 0.0; ws->flag[j] = 0; }
  }
  ws->np = q;
}

/* Inner loop of Lawson-Hanson after an index was added: z on P until z > 0. */
PHGMG__PRIV phgmg_result phgmg__nnls_inner(const phgmg__nnls_prob *pb, phgmg__nnls_ws *ws, double *x, int *iter,
                                           int max_iter, const phgmg_allocator *alloc) {
  phgmg_result rc = phgmg__nnls_solve(pb, ws, alloc);
  int i;
  /* the new index (last in P) must enter with z > 0; if rounding says
     otherwise it is rejected (Lawson-Hanson's safeguard against cycling) */
  if (rc == PHGMG_OK && !(ws->z[ws->np - 1] > 0.0)) return PHGMG_ERR_RANK;
  while (rc == PHGMG_OK) {
    double alpha = 2.0;
    int imin = -1;
    for (i = 0; i < ws->np; ++i)
      if (ws->z[i] <= 0.0) {
        const double xi = x[ws->P[i]], a = xi / (xi - ws->z[i]);
        if (a < alpha) { alpha = a; imin = i; }
      }
    if (imin < 0) break;
    if (++*iter > max_iter) return PHGMG_ERR_NOT_CONVERGED;
    for (i = 0; i < ws->np; ++i) x[ws->P[i]] += alpha * (ws->z[i] - x[ws->P[i]]);
    x[ws->P[imin]] = 0.0;
    phgmg__nnls_drop(ws, x);
    if (pb->G && !phgmg__nnls_chol(pb, ws)) return PHGMG_ERR_NOT_CONVERGED;
    rc = phgmg__nnls_solve(pb, ws, alloc);
    if (rc == PHGMG_ERR_RANK) rc = PHGMG_ERR_NOT_CONVERGED; /* a subset of a full-rank set: rounding */
  }
  if (rc == PHGMG_OK)
    for (i = 0; i < ws->np; ++i) x[ws->P[i]] = ws->z[i];
  return rc;
}

/* Warm start (Gram form): the passive set P = the support of x; kept only
   if the least-squares solution on P is positive (x_P := it), as at a
   Lawson-Hanson step; otherwise x = 0, P empty (a cold start). */
PHGMG__PRIV void phgmg__nnls_warm(const phgmg__nnls_prob *pb, phgmg__nnls_ws *ws, double *x,
                                  const phgmg_allocator *alloc) {
  int i, ok;
  for (i = 0; i < pb->n; ++i)
    if (x[i] > 0.0) { ws->P[ws->np++] = i; ws->flag[i] = 1; }
  ok = ws->np > 0 && phgmg__nnls_chol(pb, ws) && phgmg__nnls_solve(pb, ws, alloc) == PHGMG_OK;
  for (i = 0; ok && i < ws->np; ++i) ok = ws->z[i] > 0.0;
  for (i = 0; i < ws->np; ++i) x[ws->P[i]] = ok ? ws->z[i] : 0.0;
  if (!ok) {
    for (i = 0; i < pb->n; ++i) { x[i] = 0.0; ws->flag[i] = 0; }
    ws->np = 0;
  }
}

/* Lawson-Hanson from x = 0 (warm = 0: x zeroed here) or, in the Gram form,
   from the support of the given x >= 0 (warm = 1, phgmg__nnls_warm). Stops
   when the squared residual <= stop2 (stop2 <= 0: at optimality).
   *res2 = final squared residual. */
PHGMG__PRIV phgmg_result phgmg__nnls_core(const phgmg__nnls_prob *pb, double stop2, int max_iter, int warm,
                                          double *x, double *res2, const phgmg_allocator *alloc) {
  const int n = pb->n;
  phgmg__nnls_ws ws;
  double *tmp;
  int iter = 0, i;
  phgmg_result rc = PHGMG_OK;
  ws.P = phgmg__ialloc(alloc, 2 * (size_t)n);
  ws.z = phgmg__dalloc(alloc, 2 * (size_t)n + 2 * (size_t)pb->k + (pb->G ? (size_t)n * n : (size_t)pb->k * n));
  if (!ws.P || !ws.z) { phgmg__free(alloc, ws.P); phgmg__free(alloc, ws.z); return PHGMG_ERR_NOMEM; }
  ws.flag = ws.P + n;
  ws.g = ws.z + n;
  tmp = ws.g + n;
  ws.r = tmp + pb->k;
  ws.L = ws.Cp = ws.r + pb->k;
  ws.np = 0;
  for (i = 0; i < n; ++i) ws.flag[i] = 0;
  if (warm && pb->G) phgmg__nnls_warm(pb, &ws, x, alloc);
  else for (i = 0; i < n; ++i) x[i] = 0.0;
  for (;;) {
    double r2 = phgmg__nnls_grad(pb, &ws, x, tmp), gmax = pb->wtol;
    int j = -1;
    *res2 = r2;
    if (stop2 > 0.0 && r2 <= stop2) break;
    for (i = 0; i < n; ++i)
      if (ws.flag[i] == 0 && ws.g[i] > gmax) { gmax = ws.g[i]; j = i; }
    if (j < 0 && pb->G && pb->C) { /* hybrid: confirm with the true gradient */
      phgmg_gemv('T', pb->k, n, 1.0, pb->C, pb->ldc, tmp, 0.0, ws.g);
      for (i = 0; i < n; ++i)
        if (ws.flag[i] == 0 && ws.g[i] > gmax) { gmax = ws.g[i]; j = i; }
    }
    if (j < 0) break; /* optimal */
    if (iter >= max_iter) { rc = PHGMG_ERR_NOT_CONVERGED; break; }
    ws.P[ws.np++] = j;
    ws.flag[j] = 1;
    if (pb->G && !phgmg__nnls_chol_add(pb, &ws)) { --ws.np; ws.flag[j] = 2; continue; }
    ++iter;
    rc = phgmg__nnls_inner(pb, &ws, x, &iter, max_iter, alloc);
    if (rc == PHGMG_ERR_RANK) { /* j dependent on P numerically: exclude it until the next step */
      --ws.np;                  /* j is last in P; x and the factor of P are unchanged */
      ws.flag[j] = 2;
      rc = PHGMG_OK;
      continue;
    }
    if (rc != PHGMG_OK) break;
    for (i = 0; i < n; ++i) if (ws.flag[i] == 2) ws.flag[i] = 0;
  }
  if (rc == PHGMG_ERR_NOT_CONVERGED || rc == PHGMG_OK) *res2 = phgmg__nnls_grad(pb, &ws, x, tmp);
  phgmg__free(alloc, ws.P);
  phgmg__free(alloc, ws.z);
  return rc;
}

PHGMG_DEF phgmg_result phgmg_nnls(int m, int n, const double *A, int lda, const double *b, double tol,
                                  int max_iter, double *x, double *resid, int *nnz_out,
                                  const phgmg_allocator *alloc) {
  phgmg__nnls_prob pb;
  double *Q = NULL, *tau, *qb, bn, res2 = 0.0;
  int i, j, nz = 0;
  phgmg_result rc;
  if (!A || !b || !x) return PHGMG_ERR_INVALID_ARG;
  if (m < 1 || n < 1 || lda < m) return PHGMG_ERR_SIZE;
  if (!phgmg__mat_finite(m, n, A, lda) || !phgmg__all_finite(b, (size_t)m)) return PHGMG_ERR_NANINF;
  if (tol != tol || max_iter < 0) return PHGMG_ERR_INVALID_ARG;
  memset(&pb, 0, sizeof pb);
  pb.n = n;
  bn = phgmg_normf(m, 1, b, m);
  pb.wtol = 10.0 * (double)PHGMG__MAX(m, n) * PHGMG__EPS * phgmg_normf(m, n, A, lda) * bn;
  if (m > n) { /* compress: A = Q R, min ||R x - (Q^T b)_{1:n}||^2 + ||(Q^T b)_{n+1:m}||^2 */
    Q = phgmg__dalloc(alloc, (size_t)m * n + (size_t)n + (size_t)m);
    if (!Q) return PHGMG_ERR_NOMEM;
    tau = Q + (size_t)m * n;
    qb = tau + n;
    for (j = 0; j < n; ++j) memcpy(Q + (size_t)j * m, A + (size_t)j * lda, (size_t)m * sizeof(double));
    memcpy(qb, b, (size_t)m * sizeof(double));
    rc = phgmg_qr(m, n, Q, m, tau);
    if (rc != PHGMG_OK) { phgmg__free(alloc, Q); return rc; }
    phgmg_qr_apply('T', m, 1, n, Q, m, tau, qb, m);
    for (j = 0; j < n; ++j)
      for (i = j + 1; i < n; ++i) Q[i + (size_t)j * m] = 0.0;
    for (i = n; i < m; ++i) pb.rr0 += qb[i] * qb[i];
    pb.C = Q; pb.ldc = m; pb.k = n; pb.d = qb;
    if (!phgmg__all_finite(qb, (size_t)m)) { /* a rank-deficient A can drive phgmg_qr into a
                                                subnormal pivot: work on A itself then */
      pb.C = A; pb.ldc = lda; pb.k = m; pb.d = b; pb.rr0 = 0.0;
    }
  } else {
    pb.C = A; pb.ldc = lda; pb.k = m; pb.d = b;
  }
  rc = phgmg__nnls_core(&pb, tol > 0.0 ? (tol * bn) * (tol * bn) : 0.0, max_iter > 0 ? max_iter : 3 * n, 0,
                        x, &res2, alloc);
  phgmg__free(alloc, Q);
  if (rc != PHGMG_OK && rc != PHGMG_ERR_NOT_CONVERGED) return rc;
  for (j = 0; j < n; ++j) if (x[j] > 0.0) ++nz;
  if (resid) *resid = sqrt(res2);
  if (nnz_out) *nnz_out = nz;
  return rc;
}

/* G (n x n) = Gm^T Gm: the upper triangle by column blocks, then mirrored. */
PHGMG__PRIV void phgmg__gram(int m, int n, const double *Gm, int ldg, double *G) {
  const int nb = 96;
  int j0, i, j;
  for (j0 = 0; j0 < n; j0 += nb) {
    const int jb = PHGMG__MIN(nb, n - j0);
    phgmg_gemm('T', 'N', j0 + jb, jb, m, 1.0, Gm, ldg, Gm + (size_t)j0 * ldg, ldg, 0.0, G + (size_t)j0 * n, n);
  }
  for (j = 0; j < n; ++j)
    for (i = j + 1; i < n; ++i) G[i + (size_t)j * n] = G[j + (size_t)i * n];
}

/* ||Gm x - t|| over the support of x; r: m doubles. */
PHGMG__PRIV double phgmg__ecsw_resid(int m, int n, const double *Gm, int ldg, const double *t, const double *x,
                                     double *r) {
  int i, j;
  for (i = 0; i < m; ++i) r[i] = -t[i];
  for (j = 0; j < n; ++j)
    if (x[j] != 0.0) {
      const double *g = Gm + (size_t)j * ldg, xj = x[j];
      for (i = 0; i < m; ++i) r[i] += g[i] * xj;
    }
  return phgmg_normf(m, 1, r, m);
}

/* phgmg_ecsw on checked arguments (tol > 0): Lawson-Hanson in the hybrid
   Gram form over all n columns (the Gram matrix n x n in memory); x0 (n,
   >= 0, or NULL: from zero) is a warm start (phgmg__nnls_warm). */
PHGMG__PRIV phgmg_result phgmg__ecsw_gram(int n, int m, const double *Gm, int ldg, const double *target,
                                          double tol, const double *x0, int *pts, double *w, int *nd_out,
                                          double *resid_out, const phgmg_allocator *alloc) {
  phgmg__nnls_prob pb;
  double *G, *c, *x, *r, tn, rel = 0.0, res2 = 0.0;
  int j, nd = 0;
  phgmg_result rc = PHGMG_OK;
  tn = phgmg_normf(m, 1, target, m);
  *nd_out = 0;
  if (resid_out) *resid_out = 0.0;
  if (tn == 0.0) return PHGMG_OK;
  G = phgmg__dalloc(alloc, (size_t)n * n + 2 * (size_t)n + (size_t)m);
  if (!G) return PHGMG_ERR_NOMEM;
  c = G + (size_t)n * n;
  x = c + n;
  r = x + n;
  phgmg__gram(m, n, Gm, ldg, G);
  phgmg_gemv('T', m, n, 1.0, Gm, ldg, target, 0.0, c);
  memset(&pb, 0, sizeof pb);
  pb.n = n; pb.G = G; pb.ldg = n; pb.c = c; pb.dd = tn * tn;
  pb.C = Gm; pb.ldc = ldg; pb.k = m; pb.d = target;
  for (j = 0; j < n; ++j) pb.wtol += G[j + (size_t)j * n];
  /* the true gradient is checked at the end (hybrid form), so the threshold
     only has to sit above the rounding of C^T r, not at the Gram form's level */
  pb.wtol = 10.0 * PHGMG__EPS * sqrt(pb.wtol) * tn;
  if (x0) memcpy(x, x0, (size_t)n * sizeof(double));
  rc = phgmg__nnls_core(&pb, (tol * tn) * (tol * tn), 3 * n, x0 != NULL, x, &res2, alloc);
  if (rc == PHGMG_OK || rc == PHGMG_ERR_NOT_CONVERGED) { /* residual of the weights as returned */
    rel = phgmg__ecsw_resid(m, n, Gm, ldg, target, x, r) / tn;
    rc = rel <= tol ? PHGMG_OK : PHGMG_ERR_NOT_CONVERGED; /* optimal above tol, or capped */
  }
  if (rc == PHGMG_OK || rc == PHGMG_ERR_NOT_CONVERGED) {
    for (j = 0; j < n; ++j)
      if (x[j] > 0.0) { pts[nd] = j; w[nd] = x[j]; ++nd; }
    *nd_out = nd;
    if (resid_out) *resid_out = rel;
  }
  phgmg__free(alloc, G);
  return rc;
}

/* ---- ECSW with candidate screening (many terms) ----------------------
   Lawson-Hanson over n candidate terms needs the Gram matrix n x n (the
   hybrid form above): 8 n^2 bytes and m n^2 flops, out of reach at n = 10^5.
   The points it keeps are few (tens to hundreds), so the fit is made on a
   working set W of candidates that grows by screening: the gradient of the
   full problem g = Gm^T (target - Gm w) is computed for all n terms (one
   product with the training matrix), the PHGMG_ECSW_SCREEN_ADD terms outside
   W with the largest positive g join W, and phgmg__ecsw_gram solves the
   problem restricted to W (rows = all training rows, so its residual is the
   full problem's residual, not an estimate); then W is pruned to the terms
   with w > 0 (a top-gradient batch is mostly neighbours of one another:
   without pruning W fills with terms the fit never uses). Repeated until the
   residual meets tol, or no term outside W has a positive gradient (then w
   is optimal over all n terms, as Lawson-Hanson's: PHGMG_ERR_NOT_CONVERGED
   if above tol), or after PHGMG_ECSW_SCREEN_ROUNDS (200) rounds. Each round
   continues Lawson-Hanson on W from the last round's weights (warm start:
   its support as the passive set, phgmg__nnls_warm), so w >= 0 by
   construction and a round costs the steps for the new terms only. The two ways to
   apply the training matrix are callbacks (explicit Gm; the separable
   product F^T diag(.) Vt that never forms it). */
#ifndef PHGMG_ECSW_SCREEN_MIN
#define PHGMG_ECSW_SCREEN_MIN 4096 /* terms from which phgmg_ecsw(_separable) screens */
#endif
#ifndef PHGMG_ECSW_SCREEN_ADD
#define PHGMG_ECSW_SCREEN_ADD 64   /* candidates added per round */
#endif
#ifndef PHGMG_ECSW_SCREEN_ROUNDS
#define PHGMG_ECSW_SCREEN_ROUNDS 200 /* cap on screening rounds */
#endif
typedef struct phgmg__ecsw_op {
  /* g (n) = Gm^T res (res: m training rows); h: scratch of op's own size */
  void (*grad)(const struct phgmg__ecsw_op *op, const double *res, double *g, double *h);
  /* col (m) = column j of Gm */
  void (*col)(const struct phgmg__ecsw_op *op, int j, double *col);
  int n, m;
  size_t hsize;                       /* doubles of scratch for grad */
  const double *A; int lda;           /* explicit Gm (m x n), or F (n x ns) */
  const double *Vt; int ldvt, ns, r;  /* separable: Vt (n x r); row (i, a) = a * ns + i */
} phgmg__ecsw_op;

PHGMG__PRIV void phgmg__ecsw_grad_dense(const phgmg__ecsw_op *op, const double *res, double *g, double *h) {
  (void)h;
  phgmg_gemv('T', op->m, op->n, 1.0, op->A, op->lda, res, 0.0, g);
}
PHGMG__PRIV void phgmg__ecsw_col_dense(const phgmg__ecsw_op *op, int j, double *col) {
  memcpy(col, op->A + (size_t)j * op->lda, (size_t)op->m * sizeof(double));
}
/* g_k = sum_a Vt[k, a] (F res)[k, a], res ns x r: 2 n ns r flops (one GEMM). */
PHGMG__PRIV void phgmg__ecsw_grad_sep(const phgmg__ecsw_op *op, const double *res, double *g, double *h) {
  const int n = op->n;
  int k, a;
  phgmg_gemm('N', 'N', n, op->r, op->ns, 1.0, op->A, op->lda, res, op->ns, 0.0, h, n);
  for (k = 0; k < n; ++k) g[k] = 0.0;
  for (a = 0; a < op->r; ++a)
    for (k = 0; k < n; ++k) g[k] += op->Vt[k + (size_t)a * op->ldvt] * h[k + (size_t)a * n];
}
PHGMG__PRIV void phgmg__ecsw_col_sep(const phgmg__ecsw_op *op, int j, double *col) {
  int i, a;
  for (a = 0; a < op->r; ++a) {
    const double v = op->Vt[j + (size_t)a * op->ldvt];
    for (i = 0; i < op->ns; ++i) col[i + (size_t)a * op->ns] = op->A[j + (size_t)i * op->lda] * v;
  }
}

/* Add to W (nw entries, inW flags) up to `add` terms outside W with the
   largest g > gtol (largest first). Returns the number added. */
PHGMG__PRIV int phgmg__ecsw_screen_add(int n, const double *g, double gtol, int add, int *W, int nw, char *inW) {
  int cnt = 0, k;
  while (cnt < add) {
    int best = -1;
    double gb = gtol;
    for (k = 0; k < n; ++k)
      if (!inW[k] && g[k] > gb) { gb = g[k]; best = k; }
    if (best < 0) break;
    inW[best] = 1;
    W[nw + cnt++] = best;
  }
  return cnt;
}

/* The screening driver (see above). target: m (not 0); tol > 0. */
PHGMG__PRIV phgmg_result phgmg__ecsw_screened(const phgmg__ecsw_op *op, const double *target, double tol, int *pts, double *w, int *nd_out, double *resid_out,
                                              const phgmg_allocator *alloc) {
  const int n = op->n, m = op->m;
  const int wmax = PHGMG__MIN(n, 16 * PHGMG_ECSW_SCREEN_ADD);
  double *Gw, *res, *g, *h, *ww, *x0, gtol, rel = HUGE_VAL;
  int *W, *pw, nw = 0, nd = 0, i, j, rounds = 0;
  char *inW;
  phgmg_result rc = PHGMG_ERR_NOT_CONVERGED;
  Gw = phgmg__dalloc(alloc, (size_t)m * wmax + (size_t)m + (size_t)n + op->hsize + 2 * (size_t)wmax);
  W = phgmg__ialloc(alloc, 2 * (size_t)wmax + (size_t)n);
  if (!Gw || !W) { phgmg__free(alloc, Gw); phgmg__free(alloc, W); return PHGMG_ERR_NOMEM; }
  res = Gw + (size_t)m * wmax;
  g = res + m;
  h = g + n;
  ww = h + op->hsize;
  x0 = ww + wmax;              /* the last round's weights on W: a warm start */
  pw = W + wmax;
  inW = (char *)(pw + wmax);   /* n flags in the int tail (n ints >= n chars) */
  memset(inW, 0, (size_t)n);
  memcpy(res, target, (size_t)m * sizeof(double));
  op->grad(op, target, g, h);  /* gradient at w = 0; its scale sets the threshold */
  for (gtol = 0.0, j = 0; j < n; ++j) gtol = PHGMG__MAX(gtol, fabs(g[j]));
  gtol *= 1e3 * PHGMG__EPS;
  for (;;) {
    const int add = phgmg__ecsw_screen_add(n, g, gtol, PHGMG__MIN(PHGMG_ECSW_SCREEN_ADD, wmax - nw), W, nw, inW);
    if (add == 0) break;          /* optimal over all terms (or W full) */
    for (j = nw; j < nw + add; ++j) { op->col(op, W[j], Gw + (size_t)j * m); x0[j] = 0.0; }
    nw += add;
    rc = phgmg__ecsw_gram(nw, m, Gw, m, target, tol, rounds ? x0 : NULL, pw, ww, &nd, &rel, alloc);
    if (rc != PHGMG_OK && rc != PHGMG_ERR_NOT_CONVERGED) break;
    if (rc == PHGMG_OK) break;    /* tol met on the full rows */
    memcpy(res, target, (size_t)m * sizeof(double));
    for (j = 0; j < nd; ++j) phgmg__axpy(m, -ww[j], Gw + (size_t)pw[j] * m, res);
    op->grad(op, res, g, h);
    if (++rounds >= PHGMG_ECSW_SCREEN_ROUNDS) break;
    /* prune W to the support (pw ascending): terms at weight 0 leave W and may
       return later; W stays near nd + PHGMG_ECSW_SCREEN_ADD */
    for (j = 0; j < nw; ++j) inW[W[j]] = 0;
    for (j = 0; j < nd; ++j) {
      W[j] = W[pw[j]];
      inW[W[j]] = 1;
      if (pw[j] != j) memcpy(Gw + (size_t)j * m, Gw + (size_t)pw[j] * m, (size_t)m * sizeof(double));
      pw[j] = j;
      x0[j] = ww[j];
    }
    nw = nd;
  }
  if (rc == PHGMG_OK || rc == PHGMG_ERR_NOT_CONVERGED) {
    for (j = 0; j < nd; ++j) { /* W is in screening order: insertion sort to ascending terms */
      const int pj = W[pw[j]];
      const double wj = ww[j];
      for (i = j; i > 0 && pts[i - 1] > pj; --i) { pts[i] = pts[i - 1]; w[i] = w[i - 1]; }
      pts[i] = pj;
      w[i] = wj;
    }
    *nd_out = nd;
    if (resid_out) *resid_out = rel == HUGE_VAL ? 1.0 : rel;
  }
  phgmg__free(alloc, Gw);
  phgmg__free(alloc, W);
  return rc;
}

/* phgmg_ecsw on checked arguments (tol >= PHGMG__ECSW_TOL_MIN; Gm and target
   within [2^-400, 2^400] in magnitude, so that the Gram matrix neither
   overflows nor underflows). */
PHGMG__PRIV phgmg_result phgmg__ecsw_run(int n, int m, const double *Gm, int ldg, const double *target, double tol,
                                         int *pts, double *w, int *nd_out, double *resid_out,
                                         const phgmg_allocator *alloc) {
  phgmg__ecsw_op op;
  double tn;
  if (n < PHGMG_ECSW_SCREEN_MIN)
    return phgmg__ecsw_gram(n, m, Gm, ldg, target, tol, NULL, pts, w, nd_out, resid_out, alloc);
  tn = phgmg_normf(m, 1, target, m);
  *nd_out = 0;
  if (resid_out) *resid_out = 0.0;
  if (tn == 0.0) return PHGMG_OK;
  memset(&op, 0, sizeof op);
  op.grad = phgmg__ecsw_grad_dense; op.col = phgmg__ecsw_col_dense;
  op.n = n; op.m = m; op.A = Gm; op.lda = ldg;
  return phgmg__ecsw_screened(&op, target, tol, pts, w, nd_out, resid_out, alloc);
}

/* The smallest relative residual ECSW accepts as a tolerance: below it the
   residual is not resolved by double precision (its rounding level). */
#define PHGMG__ECSW_TOL_MIN 1e-15

/* Largest |entry| of an m x n matrix (lda). */
PHGMG__PRIV double phgmg__mat_amax(int m, int n, const double *A, int lda) {
  double a = 0.0;
  int i, j;
  for (j = 0; j < n; ++j)
    for (i = 0; i < m; ++i) a = PHGMG__MAX(a, fabs(A[i + (size_t)j * lda]));
  return a;
}

PHGMG_DEF phgmg_result phgmg_ecsw(int nterms, int nrows, const double *Gm, int ldg, const double *target,
                                  double tol, int *pts, double *w, int *nd_out, double *resid_out,
                                  const phgmg_allocator *alloc) {
  const int n = nterms, m = nrows;
  const double lo = ldexp(1.0, -400), hi = ldexp(1.0, 400);
  double ag, at, sg, st, *Gc;
  int i, j, eg = 0, et = 0;
  phgmg_result rc;
  if (!Gm || !target || !pts || !w || !nd_out) return PHGMG_ERR_INVALID_ARG;
  if (!(tol >= 0.0) || !(tol < 1.0)) return PHGMG_ERR_INVALID_ARG;
  if (n < 1 || m < 1 || ldg < m) return PHGMG_ERR_SIZE;
  if (!phgmg__mat_finite(m, n, Gm, ldg) || !phgmg__all_finite(target, (size_t)m)) return PHGMG_ERR_NANINF;
  if (tol == 0.0) tol = 1e-6;
  if (tol < PHGMG__ECSW_TOL_MIN) return PHGMG_ERR_TOL_UNREACHABLE;
  ag = phgmg__mat_amax(m, n, Gm, ldg);
  at = phgmg__mat_amax(m, 1, target, m);
  sg = ag > 0.0 && (ag < lo || ag > hi) ? phgmg__pow2_scale(ag) : 1.0;
  st = at > 0.0 && (at < lo || at > hi) ? phgmg__pow2_scale(at) : 1.0;
  if (sg == 1.0 && st == 1.0) return phgmg__ecsw_run(n, m, Gm, ldg, target, tol, pts, w, nd_out, resid_out, alloc);
  /* data far from 1 in magnitude: the same problem scaled by powers of two
     (exact; the weights scale by sg / st), so that the result does not
     depend on the data's magnitude */
  Gc = phgmg__dalloc(alloc, (size_t)m * n + (size_t)m);
  if (!Gc) return PHGMG_ERR_NOMEM;
  for (j = 0; j < n; ++j)
    for (i = 0; i < m; ++i) Gc[i + (size_t)j * m] = sg * Gm[i + (size_t)j * ldg];
  for (i = 0; i < m; ++i) Gc[i + (size_t)m * n] = st * target[i];
  rc = phgmg__ecsw_run(n, m, Gc, m, Gc + (size_t)m * n, tol, pts, w, nd_out, resid_out, alloc);
  phgmg__free(alloc, Gc);
  (void)frexp(sg, &eg);
  (void)frexp(st, &et);
  for (j = 0; (rc == PHGMG_OK || rc == PHGMG_ERR_NOT_CONVERGED) && j < *nd_out; ++j) {
    w[j] = ldexp(w[j], eg - et);
    if (!(w[j] > 0.0 && w[j] < HUGE_VAL)) rc = PHGMG_ERR_OVERFLOW; /* the weights leave the double range */
  }
  return rc;
}

/* ||F^T diag(a) Vt||_F (ns x r) for a (nterms); B: nterms x r, Y: ns x r scratch. */
PHGMG__PRIV double phgmg__sep_norm(int nt, int ns, const double *F, int ldf, int r, const double *Vt, int ldvt,
                                   const double *a, double *B, double *Y) {
  int k, c;
  for (c = 0; c < r; ++c)
    for (k = 0; k < nt; ++k) B[k + (size_t)c * nt] = a[k] * Vt[k + (size_t)c * ldvt];
  phgmg_gemm('T', 'N', ns, r, nt, 1.0, F, ldf, B, nt, 0.0, Y, ns);
  return phgmg_normf(ns, r, Y, ns);
}

/* phgmg_ecsw_separable with screening (nterms >= PHGMG_ECSW_SCREEN_MIN):
   training rows (i, a) = F[k, i] Vt[k, a] in full (row a ns + i), never
   formed beyond the working set. */
PHGMG__PRIV phgmg_result phgmg__ecsw_sep_screened(int nt, int ns, const double *F, int ldf, int r, const double *Vt,
                                                  int ldvt, const double *sw, double tol, int *pts, double *w,
                                                  int *nd_out, double *resid_out, const phgmg_allocator *alloc) {
  phgmg__ecsw_op op;
  double *B, *T, tn;
  int i;
  phgmg_result rc;
  if ((double)ns * r > 2147483647.0) return PHGMG_ERR_SIZE;
  B = phgmg__dalloc(alloc, (size_t)nt * r + (size_t)ns * r + (size_t)nt);
  if (!B) return PHGMG_ERR_NOMEM;
  T = B + (size_t)nt * r;
  for (i = 0; i < nt; ++i) T[(size_t)ns * r + i] = sw ? sw[i] : 1.0;
  tn = phgmg__sep_norm(nt, ns, F, ldf, r, Vt, ldvt, T + (size_t)ns * r, B, T); /* T = F^T diag(sw) Vt */
  *nd_out = 0;
  if (resid_out) *resid_out = 0.0;
  if (tn == 0.0) { phgmg__free(alloc, B); return PHGMG_OK; }
  memset(&op, 0, sizeof op);
  op.grad = phgmg__ecsw_grad_sep; op.col = phgmg__ecsw_col_sep;
  op.n = nt; op.m = ns * r; op.hsize = (size_t)nt * r;
  op.A = F; op.lda = ldf; op.Vt = Vt; op.ldvt = ldvt; op.ns = ns; op.r = r;
  rc = phgmg__ecsw_screened(&op, T, tol, pts, w, nd_out, resid_out, alloc);
  phgmg__free(alloc, B);
  return rc;
}

PHGMG_DEF phgmg_result phgmg_ecsw_separable(int nterms, int ns, const double *F, int ldf, int r, const double *Vt,
                                            int ldvt, const double *sw, double tol, int *pts, double *w,
                                            int *nd_out, double *resid_out, const phgmg_allocator *alloc) {
  const int nt = nterms, kk = PHGMG__MIN(nterms, ns);
  double *U, *S, *Gc, *tc, *dw, *B, *Y, tn, rel = 0.0;
  int ks = 0, rank = 0, q, j, a, i, k, pass, nd = 0, mc;
  phgmg_result rc;
  if (!F || !Vt || !pts || !w || !nd_out) return PHGMG_ERR_INVALID_ARG;
  if (!(tol >= 0.0) || !(tol < 1.0)) return PHGMG_ERR_INVALID_ARG;
  if (nt < 1 || ns < 1 || r < 1 || ldf < nt || ldvt < nt) return PHGMG_ERR_SIZE;
  if (!phgmg__mat_finite(nt, ns, F, ldf) || !phgmg__mat_finite(nt, r, Vt, ldvt) ||
      (sw && !phgmg__all_finite(sw, (size_t)nt)))
    return PHGMG_ERR_NANINF;
  if (tol == 0.0) tol = 1e-6;
  if (tol < PHGMG__ECSW_TOL_MIN) return PHGMG_ERR_TOL_UNREACHABLE;
  if (nt >= PHGMG_ECSW_SCREEN_MIN) return phgmg__ecsw_sep_screened(nt, ns, F, ldf, r, Vt, ldvt, sw, tol, pts, w,
                                                                   nd_out, resid_out, alloc);
  U = phgmg__dalloc(alloc, (size_t)nt * kk + (size_t)kk + 2 * (size_t)nt + (size_t)nt * r + (size_t)ns * r);
  if (!U) return PHGMG_ERR_NOMEM;
  S = U + (size_t)nt * kk;
  dw = S + kk;            /* nt: w - sw (dense), then sw */
  B = dw + 2 * (size_t)nt;
  Y = B + (size_t)nt * r;
  for (i = 0; i < nt; ++i) dw[nt + i] = sw ? sw[i] : 1.0;
  tn = phgmg__sep_norm(nt, ns, F, ldf, r, Vt, ldvt, dw + nt, B, Y);
  *nd_out = 0;
  if (resid_out) *resid_out = 0.0;
  rc = phgmg_svd(nt, ns, F, ldf, kk, S, U, nt, NULL, 1, &ks, &rank, alloc);
  for (pass = 0; rc == PHGMG_OK && pass < 2 && tn > 0.0; ++pass) {
    /* pass 0: modes with sigma_j > 1e-3 tol sigma_1; pass 1 (if tol missed): all */
    for (q = 0; q < ks && (pass == 1 || S[q] > 1e-3 * tol * S[0]); ++q) {}
    if (q < 1) q = 1;
    mc = q * r;
    Gc = phgmg__dalloc(alloc, (size_t)mc * nt + (size_t)mc);
    if (!Gc) { rc = PHGMG_ERR_NOMEM; break; }
    tc = Gc + (size_t)mc * nt;
    for (k = 0; k < nt; ++k)
      for (j = 0; j < q; ++j)
        for (a = 0; a < r; ++a)
          Gc[j * r + a + (size_t)k * mc] = S[j] * U[k + (size_t)j * nt] * Vt[k + (size_t)a * ldvt];
    phgmg_gemv('N', mc, nt, 1.0, Gc, mc, dw + nt, 0.0, tc);
    rc = phgmg_ecsw(nt, mc, Gc, mc, tc, PHGMG__MAX(0.5 * tol, PHGMG__ECSW_TOL_MIN), pts, w, &nd, NULL, alloc);
    phgmg__free(alloc, Gc);
    if (rc != PHGMG_OK && rc != PHGMG_ERR_NOT_CONVERGED) break;
    for (i = 0; i < nt; ++i) dw[i] = -dw[nt + i];
    for (i = 0; i < nd; ++i) dw[pts[i]] += w[i];
    rel = phgmg__sep_norm(nt, ns, F, ldf, r, Vt, ldvt, dw, B, Y) / tn;
    rc = rel <= tol ? PHGMG_OK : PHGMG_ERR_NOT_CONVERGED;
    if (rc == PHGMG_OK || q >= ks) break;
  }
  if (rc == PHGMG_OK || rc == PHGMG_ERR_NOT_CONVERGED) {
    *nd_out = tn > 0.0 ? nd : 0;
    if (resid_out) *resid_out = rel;
  }
  phgmg__free(alloc, U);
  return rc;
}

/* >>reduce (implementation): manifold, GMG blocks, Hamiltonian terms, stepper  */
/* Lp (rn x p) = [sum_j Ms(:, k*p + j) x2_j]_k in double. */
PHGMG__PRIV void phgmg__lp_d(int rn, int p, const double *Ms, const double *x2, double *Lp) {
  int i, j, k;
  for (k = 0; k < p; ++k) {
    double *l = Lp + (size_t)k * rn;
    for (i = 0; i < rn; ++i) l[i] = 0.0;
    for (j = 0; j < p; ++j) {
      const double *ms = Ms + ((size_t)k * p + j) * rn;
      for (i = 0; i < rn; ++i) l[i] += ms[i] * x2[j];
    }
  }
}

/* E = G00 + G01 L + L^T (G10 + G11 L), L = [0, Lp]; tmp: rn x r. */
PHGMG__PRIV void phgmg__dgd_d(const phgmg_reduced *red, const double *Lp, double *E, double *tmp) {
  const int r = red->r, m = red->m, rn = red->rn;
  int a, b, i;
  for (b = 0; b < r; ++b) {
    for (i = 0; i < rn; ++i) tmp[i + (size_t)b * rn] = red->G10[i + (size_t)b * rn];
    if (b >= m) phgmg_gemv('N', rn, rn, 1.0, red->G11, rn, Lp + (size_t)(b - m) * rn, 1.0, tmp + (size_t)b * rn);
  }
  memcpy(E, red->G00, (size_t)r * r * sizeof(double));
  for (b = m; b < r; ++b) phgmg_gemv('N', r, rn, 1.0, red->G01, r, Lp + (size_t)(b - m) * rn, 1.0, E + (size_t)b * r);
  for (b = 0; b < r; ++b)
    for (a = m; a < r; ++a) {
      double s = 0.0;
      for (i = 0; i < rn; ++i) s += Lp[i + (size_t)(a - m) * rn] * tmp[i + (size_t)b * rn];
      E[a + (size_t)b * r] += s;
    }
}

/* rcond of an r x r matrix (copied). -1 on allocation failure. */
PHGMG__PRIV double phgmg__rcond_of(int n, const double *A, const phgmg_allocator *alloc) {
  double *LU = phgmg__dalloc(alloc, (size_t)n * n + 2 * (size_t)n);
  int *ip = phgmg__ialloc(alloc, 2 * (size_t)n);
  double rc = -1.0;
  if (LU && ip) {
    double anorm = phgmg_norm1(n, n, A, n);
    memcpy(LU, A, (size_t)n * n * sizeof(double));
    if (phgmg_lu_factor(n, LU, n, ip) == PHGMG_OK)
      rc = phgmg_lu_rcond(n, LU, n, ip, anorm, LU + (size_t)n * n, ip + n);
    else
      rc = 0.0;
  }
  phgmg__free(alloc, LU);
  phgmg__free(alloc, ip);
  return rc;
}

/* Inverse of an r x r matrix into Ainv. */
PHGMG__PRIV phgmg_result phgmg__inv(int n, const double *A, double *Ainv, const phgmg_allocator *alloc) {
  double *LU = phgmg__dalloc(alloc, (size_t)n * n);
  int *ip = phgmg__ialloc(alloc, (size_t)n);
  phgmg_result rc = PHGMG_ERR_NOMEM;
  int i;
  if (LU && ip) {
    memcpy(LU, A, (size_t)n * n * sizeof(double));
    rc = phgmg_lu_factor(n, LU, n, ip);
    if (rc == PHGMG_OK) {
      memset(Ainv, 0, (size_t)n * n * sizeof(double));
      for (i = 0; i < n; ++i) Ainv[i + (size_t)i * n] = 1.0;
      phgmg_lu_solve('N', n, LU, n, ip, n, Ainv, n);
    }
  }
  phgmg__free(alloc, LU);
  phgmg__free(alloc, ip);
  return rc;
}

/* Below this h ||Jf||_1 the step map is formed as x+ = x + h sum b_i Jf Y_i
   (rounding about eps h ||Jf||: at most 2e-10 relative here); above it in
   the form without h (see phgmg__step_map). */
#define PHGMG__STEP_MAP_STIFF 1e6

/* Is the step map Phi of a dissipative model (Qh positive definite, K + K^T
   negative semidefinite up to 1e-12 ||K||_F) a contraction in the energy
   norm, ||Qh^(1/2) Phi Qh^(-1/2)||_2 <= 1 + 1e-6, as the GL3 map of such a
   model is (the energy does not grow without input)? PHGMG_OK also for a
   model that is not dissipative in this sense (nothing to check);
   PHGMG_ERR_STEP_MAP if the map grows. w: 5 r^2 + r doubles. */
PHGMG__PRIV phgmg_result phgmg__step_map_check(int r, const double *K, const double *Qh, const double *Phi, double *w) {
  double *E = w, *V = E + (size_t)r * r, *S = V + (size_t)r * r, *T = S + (size_t)r * r, *C = T + (size_t)r * r;
  double *ev = C + (size_t)r * r, kn = phgmg_normf(r, r, K, r);
  int i, j;
  for (j = 0; j < r; ++j)
    for (i = 0; i < r; ++i) E[i + (size_t)j * r] = 0.5 * (K[i + (size_t)j * r] + K[j + (size_t)i * r]);
  if (phgmg_sym_eig(r, E, r, ev, NULL, r) != PHGMG_OK || ev[r - 1] > 1e-12 * kn) return PHGMG_OK;
  memcpy(E, Qh, (size_t)r * r * sizeof(double));
  if (phgmg_sym_eig(r, E, r, ev, V, r) != PHGMG_OK || !(ev[0] > 0.0)) return PHGMG_OK;
  for (j = 0; j < r; ++j)   /* S = V diag(sqrt q), T = V diag(1/sqrt q) */
    for (i = 0; i < r; ++i) {
      S[i + (size_t)j * r] = V[i + (size_t)j * r] * sqrt(ev[j]);
      T[i + (size_t)j * r] = V[i + (size_t)j * r] / sqrt(ev[j]);
    }
  /* C = S^T Phi T (orthogonally similar to Qh^(1/2) Phi Qh^(-1/2)), E = C^T C */
  phgmg_gemm('N', 'N', r, r, r, 1.0, Phi, r, T, r, 0.0, E, r);
  phgmg_gemm('T', 'N', r, r, r, 1.0, S, r, E, r, 0.0, C, r);
  phgmg_gemm('T', 'N', r, r, r, 1.0, C, r, C, r, 0.0, E, r);
  if (phgmg_sym_eig(r, E, r, ev, NULL, r) != PHGMG_OK) return PHGMG_ERR_STEP_MAP;
  return ev[r - 1] <= (1.0 + 1e-6) * (1.0 + 1e-6) ? PHGMG_OK : PHGMG_ERR_STEP_MAP;
}

/* The exact GL3 step map of x' = Jf x + Bh u (see phgmg_rom): stage values
   Y = (I - h A kron Jf)^{-1} (1 kron x + h (A kron Bh) u3) = SX x + SU u3 and
   x+ = x + h sum_i b_i (Jf Y_i + Bh u_i). For h ||Jf|| large the sum cancels
   (Y_i ~ x / (h ||Jf||): rounding of size eps h ||Jf|| ||x||, a map that can
   grow by orders of magnitude), so there the stage relation
   h (A kron I) F = Y - 1 kron x (F the stage derivatives) is used instead:
   x+ = (1 - b^T A^{-1} 1) x + sum_i d_i Y_i, d = A^{-T} b, 1 - b^T A^{-1} 1 =
   R(inf) = -1 for the 3-stage Gauss method -- no factor h, nothing cancels.
   The map of a dissipative model is checked to be a contraction in the
   energy norm (phgmg__step_map_check): PHGMG_ERR_STEP_MAP otherwise. */
PHGMG__PRIV phgmg_result phgmg__step_map(phgmg_reduced *red, double h, const phgmg_allocator *alloc) {
  const int r = red->r, m = red->m, n3 = 3 * r, nc = r + 3 * m;
  double c[3], b[3], A[9], d[3], rinf = 1.0;
  double *Jf = phgmg__dalloc(alloc, (size_t)r * r + (size_t)n3 * n3 + (size_t)n3 * nc + 5 * (size_t)r * r + (size_t)r);
  int *ip = phgmg__ialloc(alloc, (size_t)n3);
  double *M3, *RH;
  phgmg_result rc = PHGMG_ERR_NOMEM;
  int i, j, a, bb, stiff;
  if (!Jf || !ip) goto done;
  M3 = Jf + (size_t)r * r;
  RH = M3 + (size_t)n3 * n3;
  phgmg_gl3_coefficients(c, b, A);
  phgmg_gemm('N', 'N', r, r, r, 1.0, red->K, r, red->Qh, r, 0.0, Jf, r);
  stiff = !(h * phgmg_norm1(r, r, Jf, r) <= PHGMG__STEP_MAP_STIFF);
  for (j = 0; j < 3; ++j)
    for (bb = 0; bb < r; ++bb)
      for (i = 0; i < 3; ++i)
        for (a = 0; a < r; ++a)
          M3[(i * r + a) + (size_t)(j * r + bb) * n3] = (i == j && a == bb ? 1.0 : 0.0) - h * A[i * 3 + j] * Jf[a + (size_t)bb * r];
  /* RH = [h (A kron Jf)(1 kron I),  h (A kron Bh)]; stiff: [1 kron I, h (A kron Bh)] */
  for (i = 0; i < 3; ++i) {
    for (bb = 0; bb < r; ++bb)
      for (a = 0; a < r; ++a) {
        double s = 0.0;
        for (j = 0; j < 3; ++j) s += A[i * 3 + j];
        RH[(i * r + a) + (size_t)bb * n3] = stiff ? (a == bb ? 1.0 : 0.0) : h * s * Jf[a + (size_t)bb * r];
      }
    for (j = 0; j < 3; ++j)
      for (bb = 0; bb < m; ++bb)
        for (a = 0; a < r; ++a)
          RH[(i * r + a) + (size_t)(r + j * m + bb) * n3] = h * A[i * 3 + j] * red->Bh[a + (size_t)bb * r];
  }
  rc = phgmg_lu_factor(n3, M3, n3, ip);
  if (rc != PHGMG_OK) goto done;
  phgmg_lu_solve('N', n3, M3, n3, ip, nc, RH, n3);
  rc = PHGMG_ERR_NOMEM;
  red->SX = phgmg__red_d(red, (size_t)n3 * r);
  red->SU = phgmg__red_d(red, (size_t)n3 * 3 * m);
  red->Phi = phgmg__red_d(red, (size_t)r * r);
  red->Gam = phgmg__red_d(red, (size_t)r * 3 * m);
  if (!red->SX || !red->SU || !red->Phi || !red->Gam) goto done;
  for (bb = 0; bb < r; ++bb)
    for (a = 0; a < n3; ++a)
      red->SX[a + (size_t)bb * n3] = RH[a + (size_t)bb * n3] + (!stiff && a % r == bb ? 1.0 : 0.0);
  for (bb = 0; bb < 3 * m; ++bb)
    for (a = 0; a < n3; ++a) red->SU[a + (size_t)bb * n3] = RH[a + (size_t)(r + bb) * n3];
  if (stiff) {   /* d = A^{-T} b (the 3 x 3 system by its LU), R(inf) = 1 - d^T 1 */
    double At[9];
    int ip3[3];
    for (i = 0; i < 3; ++i)
      for (j = 0; j < 3; ++j) At[i + 3 * j] = A[j * 3 + i];   /* column-major A^T */
    for (i = 0; i < 3; ++i) d[i] = b[i];
    rc = phgmg_lu_factor(3, At, 3, ip3);
    if (rc != PHGMG_OK) goto done;
    phgmg_lu_solve('N', 3, At, 3, ip3, 1, d, 3);
    for (i = 0; i < 3; ++i) rinf -= d[i];
    for (a = 0; a < r; ++a) red->Phi[a + (size_t)a * r] = rinf;
    for (i = 0; i < 3; ++i) {   /* Phi += d_i SX_i, Gam += d_i SU_i */
      for (bb = 0; bb < r; ++bb)
        for (a = 0; a < r; ++a) red->Phi[a + (size_t)bb * r] += d[i] * red->SX[i * r + a + (size_t)bb * n3];
      for (bb = 0; bb < 3 * m; ++bb)
        for (a = 0; a < r; ++a) red->Gam[a + (size_t)bb * r] += d[i] * red->SU[i * r + a + (size_t)bb * n3];
    }
  } else {
    /* Phi = I + h sum b_i Jf SX_i ; Gam = h sum b_i Jf SU_i + h [b_1 Bh, b_2 Bh, b_3 Bh] */
    for (a = 0; a < r; ++a) red->Phi[a + (size_t)a * r] = 1.0;
    for (i = 0; i < 3; ++i) {
      phgmg_gemm('N', 'N', r, r, r, h * b[i], Jf, r, red->SX + i * r, n3, 1.0, red->Phi, r);
      if (m > 0) phgmg_gemm('N', 'N', r, 3 * m, r, h * b[i], Jf, r, red->SU + i * r, n3, 1.0, red->Gam, r);
      for (bb = 0; bb < m; ++bb)
        for (a = 0; a < r; ++a) red->Gam[a + (size_t)(i * m + bb) * r] += h * b[i] * red->Bh[a + (size_t)bb * r];
    }
  }
  rc = phgmg__step_map_check(r, red->K, red->Qh, red->Phi, RH + (size_t)n3 * nc);
done:
  phgmg__free(alloc, Jf);
  phgmg__free(alloc, ip);
  return rc;
}

/* XR (r x ns, ld r) = rho of ns snapshots at once (GEMM; phgmg_reduced_restrict
   column by column gives the same values up to rounding). */
PHGMG__PRIV void phgmg__restrict_block(const phgmg_reduced *red, int ns, const double *X, int ldx, double *XR) {
  const int N = red->N, m = red->m, r = red->r;
  int i, j, k;
  if (phgmg__method(red->method)->test_w) {
    phgmg_gemm('T', 'N', r, ns, N, 1.0, red->W, N, X, ldx, 0.0, XR, r);
    for (k = 0; red->xbr && k < ns; ++k) phgmg__axpy(r, -1.0, red->xbr, XR + (size_t)k * r);
    return;
  }
  phgmg_gemm('T', 'N', m, ns, N, 1.0, red->QB, N, X, ldx, 0.0, XR, r);
  phgmg_gemm('T', 'N', r - m, ns, N, 1.0, red->V0 + (size_t)N * m, N, X, ldx, 0.0, XR + m, r);
  for (k = 0; k < ns; ++k) {   /* RB^{-1} on the port coordinates */
    double *xr = XR + (size_t)k * r;
    for (i = m - 1; i >= 0; --i) {
      double sm = xr[i];
      for (j = i + 1; j < m; ++j) sm -= red->RB[i + j * m] * xr[j];
      xr[i] = sm / red->RB[i + i * m];
    }
    if (red->xbr) phgmg__axpy(r, -1.0, red->xbr, xr);
  }
}


/* Rows i0 .. i0 + nb - 1 of the built-in q = M (x2 kron x2) (no buffer, any rn). */
PHGMG__PRIV void phgmg__q_rows(const phgmg_reduced *red, const double *x2, int i0, int nb, double *q) {
  const int p = red->p, rn = red->rn;
  int i, a, j;
  for (i = 0; i < nb; ++i) q[i] = 0.0;
  for (a = 0; a < p; ++a)
    for (j = 0; j < p; ++j) {
      const double f = x2[a] * x2[j], *mc = red->M + (size_t)(a * p + j) * rn + i0;
      for (i = 0; i < nb; ++i) q[i] += mc[i] * f;
    }
}

/* Rows i0 .. i0 + nb - 1 of Lp = d q / d x2 (as phgmg__lp_d), ld nb. */
PHGMG__PRIV void phgmg__lp_rows(const phgmg_reduced *red, const double *x2, int i0, int nb, double *L) {
  const int p = red->p, rn = red->rn;
  int i, j, k;
  for (k = 0; k < p; ++k) {
    double *l = L + (size_t)k * nb;
    for (i = 0; i < nb; ++i) l[i] = 0.0;
    for (j = 0; j < p; ++j) {
      const double *ms = red->Ms + ((size_t)k * p + j) * rn + i0;
      for (i = 0; i < nb; ++i) l[i] += ms[i] * x2[j];
    }
  }
}

/* eta and its derivatives at x2, in double: the built-in quadratic map
   (q = M (x2 kron x2) = L x2 / 2, Dq = L, D2q = Ms) or the caller's eta
   (GMG_MANIFOLD, in phgmg_real). Outputs may be NULL. rw: phgmg_real scratch
   of p + rn (1 + p + p^2) entries, used with a callback only. */
PHGMG__PRIV void phgmg__eta_d(const phgmg_reduced *red, const double *x2, double *q, double *Dq, double *D2q,
                              phgmg_real *rw) {
  const int p = red->p, rn = red->rn;
  int i;
  if (!red->eta) {
    double Lb[64 * 64], *L = Dq ? Dq : Lb;
    if (Dq || rn * p <= 64 * 64) {
      phgmg__lp_d(rn, p, red->Ms, x2, L);
      if (q) phgmg_gemv('N', rn, p, 0.5, L, rn, x2, 0.0, q);
    } else if (q) {   /* a wide V2: q without the rn x p buffer */
      phgmg__q_rows(red, x2, 0, rn, q);
    }
    if (D2q) memcpy(D2q, red->Ms, (size_t)rn * p * p * sizeof(double));
  } else {
    phgmg_real *x2r = rw, *qr = x2r + p, *Dr = qr + rn, *D2r = Dr + (size_t)rn * p;
    for (i = 0; i < p; ++i) x2r[i] = (phgmg_real)x2[i];
    red->eta(x2r, q ? qr : NULL, Dq ? Dr : NULL, D2q ? D2r : NULL, red->eta_user);
    if (q) for (i = 0; i < rn; ++i) q[i] = (double)qr[i];
    if (Dq) for (i = 0; i < rn * p; ++i) Dq[i] = (double)Dr[i];
    if (D2q) for (i = 0; i < rn * p * p; ++i) D2q[i] = (double)D2r[i];
  }
}

/* Online callback of a separable part given by callbacks: evaluates the
   system's phi_term and its derivatives (the reduced object is the context). */
PHGMG__PRIV void phgmg__phi_tramp(int term, phgmg_real s, phgmg_real d[3], void *user) {
  const phgmg_reduced *red = PHGMG__CAST(const phgmg_reduced *, user);
  int k;
  for (k = 0; k < 3; ++k) d[k] = (phgmg_real)phgmg__ph_phi(red->sys, term, (double)s, k);
}

/* Y (N x r) = Hs X for the Hessian of a GENERAL part, dense or banded like Q. */
PHGMG__PRIV void phgmg__hess_apply(const phgmg_ph_system *sys, const double *Hs, int r, const double *X, double *Y) {
  const int N = sys->N;
  int i, j, a;
  if (sys->storage == PHGMG_DENSE) {
    phgmg_gemm('N', 'N', N, r, N, 1.0, Hs, N, X, N, 0.0, Y, N);
    return;
  }
  memset(Y, 0, (size_t)N * r * sizeof(double));
  for (a = 0; a < r; ++a)
    for (j = 0; j < N; ++j) {
      const double xj = X[j + (size_t)a * N];
      const int i0 = PHGMG__MAX(0, j - sys->kb), i1 = PHGMG__MIN(N - 1, j + sys->kb);
      for (i = i0; i <= i1; ++i) Y[i + (size_t)a * N] += Hs[PHGMG__PHB(sys->kb, i, j)] * xj;
    }
}

/* Online callback of a GENERAL nonlinear part (phgmg_rom.ham_cb): H_nl(phi(x)),
   Dphi^T grad H_nl(phi(x)) and Dphi^T Hess Dphi + sum_i (V2^T grad)_i D2eta_i,
   in full dimension with the reduced object's workspace (so one reduced model
   is not evaluated from two threads at once). */
PHGMG__PRIV void phgmg__ham_general(const phgmg_real *x, phgmg_real *Hn, phgmg_real *g, phgmg_real *Hs, void *user) {
  phgmg_reduced *red = PHGMG__CAST(phgmg_reduced *, user);
  const phgmg_ph_system *sys = red->sys;
  const int N = red->N, r = red->r, m = red->m, p = red->p, rn = red->rn;
  const size_t nh = sys->storage == PHGMG_BANDED ? (size_t)(2 * sys->kb + 1) * N : (size_t)N * N;
  double *xr = red->gwork, *xf = xr + r, *gf = xf + N, *HN = gf + N, *D = HN + nh, *T = D + (size_t)N * r;
  double *v = T + (size_t)N * r, *D2 = v + rn, *Hr = D2 + (size_t)rn * p * p;
  int a, b, i;
  for (a = 0; a < r; ++a) xr[a] = (double)x[a];
  phgmg_reduced_lift(red, xr, xf);
  if (Hn) *Hn = (phgmg_real)sys->H_nl(xf, sys->user);
  if (!g && !Hs) return;
  sys->grad_nl(xf, gf, sys->user);
  phgmg_reduced_dphi(red, xr, D, N);
  if (g) {
    phgmg_gemv('T', N, r, 1.0, D, N, gf, 0.0, Hr);
    for (a = 0; a < r; ++a) g[a] = (phgmg_real)Hr[a];
  }
  if (!Hs) return;
  sys->hess_nl(xf, HN, sys->user);
  phgmg__hess_apply(sys, HN, r, D, T);
  phgmg__atb(N, r, r, D, T, Hr);
  if (red->kind == PHGMG_ROM_QUADRATIC) {   /* curvature of the manifold */
    phgmg_gemv('T', N, rn, 1.0, red->V2, N, gf, 0.0, v);
    phgmg__eta_d(red, xr + m, NULL, NULL, D2, red->rwork);
    for (b = 0; b < p; ++b)
      for (a = 0; a < p; ++a) {
        double s = 0.0;
        for (i = 0; i < rn; ++i) s += v[i] * D2[i + ((size_t)a * p + b) * rn];
        Hr[(m + a) + (size_t)(m + b) * r] += s;
      }
  }
  for (b = 0; b < r; ++b)   /* symmetric to round-off; make it exact */
    for (a = 0; a < r; ++a) Hs[a + (size_t)b * r] = (phgmg_real)(0.5 * (Hr[a + (size_t)b * r] + Hr[b + (size_t)a * r]));
}


/* phgmg_real copy of a double array (NULL stays NULL). */
PHGMG__PRIV phgmg_result phgmg__to_real(phgmg_reduced *red, const double *src, size_t n, const phgmg_real **dst) {
  phgmg_real *d;
  size_t i;
  if (!src) { *dst = NULL; return PHGMG_OK; }
  d = PHGMG__CAST(phgmg_real *, phgmg__red_alloc(red, (n ? n : 1) * sizeof(phgmg_real)));
  if (!d) return PHGMG_ERR_NOMEM;
  for (i = 0; i < n; ++i) d[i] = (phgmg_real)src[i];
  *dst = d;
  return PHGMG_OK;
}

/* Reduced damper law by the full model's callback. */
PHGMG__PRIV void phgmg__damp_tramp(int term, phgmg_real s, phgmg_real d[2], void *user) {
  const phgmg_reduced *red = PHGMG__CAST(const phgmg_reduced *, user);
  double dd[2];
  phgmg__damp_law(red->sys, term, (double)s, dd);
  d[0] = (phgmg_real)dd[0];
  d[1] = (phgmg_real)dd[1];
}

/* The online dampers: Cd, weights, and the laws (the full model's
   polynomials, one row per kept damper when they differ, or its callback). */
PHGMG__PRIV phgmg_result phgmg__publish_dampers(phgmg_reduced *red) {
  const phgmg_ph_system *sys = red->sys;
  phgmg_rom *o = &red->rom;
  const size_t r = (size_t)red->r, nd = (size_t)red->ndamp, nc = (size_t)sys->damp_deg + 1;
  phgmg_result rc;
  size_t k;
  o->ndamp = red->ndamp;
  rc = phgmg__to_real(red, red->Cd, r * nd, &o->Cd);
  if (rc == PHGMG_OK) rc = phgmg__to_real(red, red->dw, nd, &o->dw);
  if (rc != PHGMG_OK) return rc;
  o->dterm = red->dterm;
  if (!sys->damp_poly) { o->damp_cb = phgmg__damp_tramp; o->damp_user = red; return PHGMG_OK; }
  o->damp_deg = sys->damp_deg;
  o->damp_nphi = sys->damp_nfun > 1 ? red->ndamp : 1;
  red->dpoly = phgmg__red_d(red, (size_t)o->damp_nphi * nc);
  if (!red->dpoly) return PHGMG_ERR_NOMEM;
  for (k = 0; k < (size_t)o->damp_nphi; ++k)
    memcpy(red->dpoly + k * nc, sys->damp_poly + (sys->damp_nfun > 1 ? (size_t)red->dterm[k] * nc : 0), nc * sizeof(double));
  return phgmg__to_real(red, red->dpoly, (size_t)o->damp_nphi * nc, &o->dpoly);
}

/* The online model: phgmg_real copies of the blocks, and the callbacks
   through which it evaluates what has no fixed coefficients (separable
   functions given by callbacks, the caller's eta, a GENERAL part). */
PHGMG__PRIV phgmg_result phgmg__publish(phgmg_reduced *red) {
  const size_t r = (size_t)red->r, m = (size_t)red->m, rn = (size_t)red->rn, nd = (size_t)red->nd;
  const size_t p = (size_t)red->p, nf = (size_t)(red->nphi > 1 ? red->nphi : 1);
  phgmg_rom *o = &red->rom;
  phgmg_result rc = PHGMG_OK;
  memset(o, 0, sizeof *o);
  o->kind = red->kind; o->method = red->method; o->r = red->r; o->m = red->m;
  o->rn = red->rn; o->nd = red->nd;
  o->poly_deg = red->poly ? red->sys->poly_deg : 0;
  o->nexp = red->nexp; o->nphi = red->nphi;
#define PHGMG__PUB(field, n) if (rc == PHGMG_OK) rc = phgmg__to_real(red, red->field, (n), &o->field)
  PHGMG__PUB(Bh, r * m); PHGMG__PUB(Qh, r * r); PHGMG__PUB(K, r * r);
  PHGMG__PUB(G00, r * r); PHGMG__PUB(G01, r * rn); PHGMG__PUB(G10, rn * r); PHGMG__PUB(G11, rn * rn);
  PHGMG__PUB(Q01, r * rn); PHGMG__PUB(Q11, rn * rn); PHGMG__PUB(Ms, rn * p * p);
  PHGMG__PUB(P0, nd * r); PHGMG__PUB(P1, nd * rn); PHGMG__PUB(w, nd);
  PHGMG__PUB(poly, nf * (size_t)(o->poly_deg + 1)); PHGMG__PUB(expo, nf * 2 * (size_t)red->nexp);
  PHGMG__PUB(Phi, r * r); PHGMG__PUB(Gam, r * 3 * m); PHGMG__PUB(SX, 3 * r * r); PHGMG__PUB(SU, 3 * r * 3 * m);
#undef PHGMG__PUB
  if (rc == PHGMG_OK) rc = phgmg__to_real(red, red->refg, r + (red->kind == PHGMG_ROM_QUADRATIC ? rn : 0) + 1, &o->ref_g);
  if (rc == PHGMG_OK) rc = phgmg__to_real(red, red->refs, nd, &o->ref_s);
  if (rc == PHGMG_OK) rc = phgmg__to_real(red, red->xrest, r, &o->xr_rest);
  o->dt = red->Phi ? (phgmg_real)red->map_dt : (phgmg_real)0;
  if (nd > 0 && !red->poly && !red->expo) {   /* callbacks: they need the full-model term index */
    o->phi_cb = phgmg__phi_tramp; o->phi_user = red; o->term = red->term;
  }
  if (red->eta) { o->eta_cb = red->eta; o->eta_user = red->eta_user; }
  if (red->gwork) { o->ham_cb = phgmg__ham_general; o->ham_user = red; }
  if (rc == PHGMG_OK) rc = phgmg__to_real(red, red->PD, (size_t)(r + m) * m, &o->PD);
  return rc == PHGMG_OK && red->ndamp ? phgmg__publish_dampers(red) : rc;
}

/* GMG-QM ridge validation (phgmg_select_opts.lambda_mode). The rows of K
   (ns x nc, the distinct Kronecker columns of the reduced snapshots) and Y
   (ns x rn, their V2 coordinates) are cut into nblk contiguous blocks (in
   time), block j going to fold j mod nfold. For each fold, one thin SVD
   K_tr = U S V^T of the other rows (through a QR when there are at least nc
   of them: K_tr = Q R, R = Ur S V^T, U^T Y_tr = Ur^T Q^T Y_tr) gives the
   ridge solution t(lam) = V diag(s / (s^2 + lam)) U^T Y_tr for every lam of
   the grid;
   err[g] = sum over folds ||Y_ho - K_ho t(grid[g])||_F^2 / ||Y||_F^2
   (1: no better than t = 0). Blocks, not single rows: on a fine time grid a
   snapshot is nearly a copy of its neighbours. */
PHGMG__PRIV phgmg_result phgmg__ridge_cv_runs(int ns, int nc, int rn, const double *K, int ldk, const double *Y,
                                              int ldy, int ngrid, const double *grid, int nfold, int nblk,
                                              const int *runcol, double *err, const phgmg_allocator *alloc);
PHGMG__PRIV phgmg_result phgmg__ridge_cv(int ns, int nc, int rn, const double *K, int ldk, const double *Y,
                                         int ldy, int ngrid, const double *grid, int nfold, int nblk,
                                         double *err, const phgmg_allocator *alloc) {
  return phgmg__ridge_cv_runs(ns, nc, rn, K, ldk, Y, ldy, ngrid, grid, nfold, nblk, NULL, err, alloc);
}
/* The same with runcol (nfold + 1 column offsets, or NULL): fold f = run f
   (leave one run out) instead of blocks in time. */
PHGMG__PRIV phgmg_result phgmg__ridge_cv_runs(int ns, int nc, int rn, const double *K, int ldk, const double *Y,
                                              int ldy, int ngrid, const double *grid, int nfold, int nblk,
                                              const int *runcol, double *err, const phgmg_allocator *alloc) {
  double *buf, *Kt, *Yt, *Kh, *Yh, *U, *S, *V, *C, *Wd, *P, *Pr, *Rm, *tau, den = 0.0;
  const int gb = PHGMG__MIN(ngrid, 32);
  int *fold, f, g, g0, i, j, a, k, nho_max = 0, ntr_max = 0, kk;
  phgmg_result rc = PHGMG_OK;
  fold = phgmg__ialloc(alloc, (size_t)ns);
  if (!fold) return PHGMG_ERR_NOMEM;
  for (i = 0; i < ns; ++i) fold[i] = (int)(((long)i * nblk / ns) % nfold);
  if (runcol)
    for (f = 0; f < nfold; ++f)
      for (i = runcol[f]; i < runcol[f + 1]; ++i) fold[i] = f;
  for (f = 0; f < nfold; ++f) {
    int c = 0;
    for (i = 0; i < ns; ++i) c += fold[i] == f;
    nho_max = PHGMG__MAX(nho_max, c);
    ntr_max = PHGMG__MAX(ntr_max, ns - c);
  }
  kk = PHGMG__MIN(ntr_max, nc);
  buf = phgmg__dalloc(alloc, (size_t)ntr_max * (nc + rn + kk) + (size_t)kk * (1 + nc + rn + (size_t)rn * gb) +
                                 (size_t)nho_max * (nc + rn + kk + (size_t)rn * gb) + (size_t)nc * (nc + 1));
  if (!buf) { phgmg__free(alloc, fold); return PHGMG_ERR_NOMEM; }
  Kt = buf; Yt = Kt + (size_t)ntr_max * nc; U = Yt + (size_t)ntr_max * rn; S = U + (size_t)ntr_max * kk;
  V = S + kk; C = V + (size_t)nc * kk; Wd = C + (size_t)kk * rn; Kh = Wd + (size_t)kk * rn * gb;
  Yh = Kh + (size_t)nho_max * nc; P = Yh + (size_t)nho_max * rn; Pr = P + (size_t)nho_max * kk;
  Rm = Pr + (size_t)nho_max * rn * gb; tau = Rm + (size_t)nc * nc;
  for (g = 0; g < ngrid; ++g) err[g] = 0.0;
  for (a = 0; a < rn; ++a)
    for (i = 0; i < ns; ++i) den += Y[i + (size_t)a * ldy] * Y[i + (size_t)a * ldy];
  for (f = 0; f < nfold; ++f) {
    int ntr = 0, nho = 0;
    for (i = 0; i < ns; ++i) nho += fold[i] == f;
    ntr = ns - nho;
    if (nho == 0) continue;
    for (j = 0; j < nc + rn; ++j) {
      const double *src = j < nc ? K + (size_t)j * ldk : Y + (size_t)(j - nc) * ldy;
      double *dt = j < nc ? Kt + (size_t)j * ntr : Yt + (size_t)(j - nc) * ntr;
      double *dh = j < nc ? Kh + (size_t)j * nho : Yh + (size_t)(j - nc) * nho;
      int it = 0, ih = 0;
      for (i = 0; i < ns; ++i) {
        if (fold[i] == f) dh[ih++] = src[i];
        else dt[it++] = src[i];
      }
    }
    k = 0;
    if (ntr >= nc) {
      rc = phgmg_qr(ntr, nc, Kt, ntr, tau);
      if (rc != PHGMG_OK) break;
      phgmg_qr_apply('T', ntr, rn, nc, Kt, ntr, tau, Yt, ntr);           /* Q^T Y_tr */
      for (j = 0; j < nc; ++j)
        for (i = 0; i < nc; ++i) Rm[i + (size_t)j * nc] = i <= j ? Kt[i + (size_t)j * ntr] : 0.0;
      rc = phgmg_svd(nc, nc, Rm, nc, nc, S, U, nc, V, nc, &k, NULL, alloc);
      if (rc != PHGMG_OK) break;
      if (k > 0) phgmg_gemm('T', 'N', k, rn, nc, 1.0, U, nc, Yt, ntr, 0.0, C, k);   /* U^T Y_tr */
    } else if (ntr > 0) {
      rc = phgmg_svd(ntr, nc, Kt, ntr, ntr, S, U, ntr, V, nc, &k, NULL, alloc);
      if (rc != PHGMG_OK) break;
      if (k > 0) phgmg_gemm('T', 'N', k, rn, ntr, 1.0, U, ntr, Yt, ntr, 0.0, C, k);
    }
    if (k > 0) {
      phgmg_gemm('N', 'N', nho, k, nc, 1.0, Kh, nho, V, nc, 0.0, P, nho);  /* K_ho V   */
    }
    for (g0 = 0; g0 < ngrid; g0 += gb) {   /* gb grid points per product */
      const int ng1 = PHGMG__MIN(gb, ngrid - g0);
      if (k > 0) {
        for (g = 0; g < ng1; ++g)
          for (j = 0; j < k; ++j) {
            const double w = S[j] / (S[j] * S[j] + grid[g0 + g]);
            for (a = 0; a < rn; ++a) Wd[j + (size_t)(g * rn + a) * k] = w * C[j + (size_t)a * k];
          }
        phgmg_gemm('N', 'N', nho, rn * ng1, k, 1.0, P, nho, Wd, k, 0.0, Pr, nho);
      } else {
        for (i = 0; i < nho * rn * ng1; ++i) Pr[i] = 0.0;
      }
      for (g = 0; g < ng1; ++g) {
        const double *pg = Pr + (size_t)g * rn * nho;
        double sum = 0.0;
        for (i = 0; i < nho * rn; ++i) {
          const double d = Yh[i] - pg[i];
          sum += d * d;
        }
        err[g0 + g] += sum;
      }
    }
  }
  phgmg__free(alloc, buf);
  phgmg__free(alloc, fold);
  if (rc != PHGMG_OK) return rc;
  for (g = 0; g < ngrid; ++g) {
    err[g] = den > 0.0 ? err[g] / den : 0.0;
    if (!(err[g] <= HUGE_VAL)) return PHGMG_ERR_NANINF;
  }
  return PHGMG_OK;
}

/* Grid of the automatic lambda: lo * 10^(g / pd), g = 0.. while <= hi (with
   a relative slack of 1e-9 so that hi itself is reached). grid may be NULL
   (count only). Returns the number of points, -1 for bad bounds. */
PHGMG__PRIV int phgmg__lambda_grid(double lo, double hi, int pd, double *grid) {
  int n, g;
  double span;
  if (!(lo > 0.0) || !(hi >= lo) || hi == HUGE_VAL || pd < 1 || pd > 100) return -1;
  span = log10(hi / lo) * pd;
  if (!(span < 1000.0)) return -1;
  n = (int)floor(span + 1e-9) + 1;
  if (grid)
    for (g = 0; g < n; ++g) grid[g] = lo * pow(10.0, (double)g / pd);
  return n;
}

/* Minimum-norm least squares X = A^+ B (A m x n, B m x nrhs, X n x nrhs, ld
   n) through the thin SVD A = U S V^T truncated at its numerical rank
   (phgmg_svd): the limit of the ridge solution as lambda -> 0+, defined for
   any rank. */
PHGMG__PRIV phgmg_result phgmg__lstsq_minnorm(int m, int n, int nrhs, const double *A, int lda, const double *B,
                                              int ldb, double *X, const phgmg_allocator *alloc) {
  const int kmax = PHGMG__MIN(m, n);
  double *U = phgmg__dalloc(alloc, (size_t)m * kmax + (size_t)n * kmax + (size_t)kmax + (size_t)kmax * nrhs);
  double *V, *S, *C;
  int k = 0, i, j;
  phgmg_result rc;
  if (!U) return PHGMG_ERR_NOMEM;
  V = U + (size_t)m * kmax; S = V + (size_t)n * kmax; C = S + kmax;
  rc = phgmg_svd(m, n, A, lda, kmax, S, U, m, V, n, &k, NULL, alloc);
  if (rc == PHGMG_OK) {
    if (k > 0) phgmg_gemm('T', 'N', k, nrhs, m, 1.0, U, m, B, ldb, 0.0, C, k);   /* U^T B */
    for (j = 0; j < nrhs; ++j)
      for (i = 0; i < k; ++i) C[i + (size_t)j * k] /= S[i];
    if (k > 0) phgmg_gemm('N', 'N', n, nrhs, k, 1.0, V, n, C, k, 0.0, X, n);
    else memset(X, 0, (size_t)n * nrhs * sizeof(double));
  }
  phgmg__free(alloc, U);
  return rc;
}

/* Least squares of the manifold fits: phgmg_lstsq, and for lambda = 0 (the
   caller's "exactly zero") on a rank-deficient or underdetermined matrix the
   minimum-norm solution instead of PHGMG_ERR_RANK. X: ld n. */
PHGMG__PRIV phgmg_result phgmg__lstsq_fit(int m, int n, int nrhs, const double *A, const double *B, double lambda,
                                          double *X, const phgmg_allocator *alloc) {
  phgmg_result rc = phgmg_lstsq(m, n, nrhs, A, m, B, m, lambda, X, n, alloc);
  if (rc == PHGMG_ERR_RANK && lambda == 0.0) rc = phgmg__lstsq_minnorm(m, n, nrhs, A, m, B, m, X, alloc);
  return rc;
}

/* M (and Ms = 2 M) of the quadratic manifold from the ridge problem over the
   p(p+1)/2 distinct Kronecker columns Kt (ns x nc) with right-hand sides Rqt
   (ns x rn); Mt (nc x rn) is scratch. red->M/Ms are allocated on first use. */
PHGMG__PRIV phgmg_result phgmg__qm_fit(phgmg_reduced *red, int ns, const double *Kt, const double *Rqt,
                                       double lambda, double *Mt, const phgmg_allocator *alloc) {
  const int p = red->p, rn = red->rn, nc = p * (p + 1) / 2;
  const double s2 = sqrt(2.0);
  int a, j, i, c;
  phgmg_result rc = phgmg__lstsq_fit(ns, nc, rn, Kt, Rqt, lambda, Mt, alloc);
  if (rc != PHGMG_OK) return rc;
  if (!red->M) red->M = phgmg__red_d(red, (size_t)rn * p * p);
  if (!red->Ms) red->Ms = phgmg__red_d(red, (size_t)rn * p * p);
  if (!red->M || !red->Ms) return PHGMG_ERR_NOMEM;
  for (a = 0, c = 0; a < p; ++a)
    for (j = a; j < p; ++j, ++c)
      for (i = 0; i < rn; ++i) {
        const double t = Mt[c + (size_t)i * nc];
        const double v = a == j ? t : t / s2;
        red->M[i + (size_t)(a * p + j) * rn] = v;
        red->M[i + (size_t)(j * p + a) * rn] = v;
        red->Ms[i + (size_t)(a * p + j) * rn] = 2.0 * v;
        red->Ms[i + (size_t)(j * p + a) * rn] = 2.0 * v;
      }
  return PHGMG_OK;
}

/* ---- phgmg_reduce: a pipeline of named stages ----------------------------
   basis (phgmg__stage_basis) -> manifold fit (phgmg__stage_manifold) ->
   reduction blocks (phgmg__stage_gmg_blocks / phgmg__stage_sp_blocks) ->
   Hamiltonian terms (phgmg__stage_quadratic_terms, phgmg__stage_separable_terms,
   phgmg__stage_general_term) -> step map -> publish. The stages share one
   context; each frees what it allocates for itself, the context owns what
   crosses stages (phgmg__rctx_free). */
typedef struct phgmg__rctx {
  phgmg_reduced *red;
  const phgmg_ph_system *sys;
  phgmg_reduce_opts ro;    /* the caller's options with the defaults applied */
  const phgmg_reduce_opts *o; /* &ro */
  const double *X;
  int ldx, ns;
  const phgmg_allocator *alloc;
  phgmg_reduce_info inf;
  double *Xa;              /* N x ns: X minus its part in span[B] (GMG), then minus V1 (QM) */
  double rfloor, degtol, lambda;
  int ng, gsel;            /* automatic lambda: grid size and chosen point (-1: fixed lambda) */
  double *lg;              /* grid (ng) and validation errors (ng)          */
  double *Tq;              /* ridge problem Kt, Rqt, Mt kept for a refit   */
  double *V2h;             /* hierarchical POD: modes p+1..p+rn of the basis
                              stage's factorisation (N x rn), for stage 2     */
  int v2ok;                /* V2h holds rn modes above the rank floor       */
  phgmg_jr_factor *jr;     /* factorization of J - R (GMG)                 */
  int *runcol;             /* opts.runs: nrun + 1 column offsets (NULL: one run) */
  int fallback_pod;        /* altmin under PHGMG_LAMBDA_VALIDATED found no model as good as
                              GMG-POD: phgmg_reduce redoes it with manifold = POD */
  phgmg_study *st;         /* phgmg_study_reduce: the study (else NULL)     */
  int sf;                  /* fast path on the study's basis: PHGMG__SF_* */
  /* descriptor models (sys->E set; manual 1.6):
     Bp = E^{-1} B, the port columns of the GMG basis (sys->B without E);
     sepw = E(i_k, i_k) w_k, the separable weights of H (sys->sep_w without E);
     ef = the factorization of E */
  const double *Bp, *sepw;
  double *Bp_own, *sepw_own;
  phgmg_jr_factor *ef;
  int wide;                /* GMG-QM: V2 over the whole residual (phgmg__qm_wide_v2) */
  double *Uw, *Cw;         /* greedy wide: the complement's modes (N x kw) and
                              coordinates (kw x ns; Cw lives in Uw's block)   */
  int kw;
  /* opts.ref: X above is then Xc, the snapshots minus xbar (what the bases and
     the manifold are fitted to); Xf / ldxf are always the caller's states
     (gradients, outputs, rho of a state, the validation runs' x0) */
  const double *Xf;
  int ldxf;
  double *Xc;
} phgmg__rctx;

PHGMG__PRIV void phgmg__rctx_free(phgmg__rctx *c) {
  phgmg_jr_factor_destroy(c->jr);
  phgmg__free(c->alloc, c->Xa);
  phgmg__free(c->alloc, c->lg);
  phgmg__free(c->alloc, c->Tq);
  phgmg__free(c->alloc, c->runcol);
  phgmg__free(c->alloc, c->V2h);
  phgmg__free(c->alloc, c->Bp_own);
  phgmg__free(c->alloc, c->sepw_own);
  phgmg_jr_factor_destroy(c->ef);
  phgmg__free(c->alloc, c->Uw);
  c->Uw = c->Cw = NULL;
  phgmg__free(c->alloc, c->Xc);
  c->Xc = NULL;
  c->jr = NULL; c->Xa = c->lg = c->Tq = c->V2h = NULL; c->runcol = NULL;
  c->Bp_own = c->sepw_own = NULL; c->ef = NULL;
}

/* Descriptor models: E factored, Bp = E^{-1} B, sepw = E(i_k, i_k) w_k; no
   study fast path (its cached blocks assume E = I). Without E: Bp = B,
   sepw = the system's weights. */
PHGMG__PRIV phgmg_result phgmg__reduce_descriptor_setup(phgmg__rctx *c) {
  const phgmg_ph_system *sys = c->sys;
  const int N = sys->N, m = sys->m;
  int k;
  phgmg_result rc;
  c->Bp = sys->B;
  c->sepw = sys->sep_w;
  if (!sys->E) return PHGMG_OK;
  c->sf = PHGMG__SF_NONE;
  rc = phgmg__e_factor(sys, &c->ef, NULL, c->alloc);
  if (rc != PHGMG_OK) return rc;
  c->Bp_own = phgmg__dalloc(c->alloc, (size_t)N * m);
  if (!c->Bp_own) return PHGMG_ERR_NOMEM;
  memcpy(c->Bp_own, sys->B, (size_t)N * m * sizeof(double));
  phgmg_jr_solve(c->ef, 'N', m, c->Bp_own, N);
  c->Bp = c->Bp_own;
  if (sys->nl == PHGMG_NL_SEPARABLE && sys->nsep > 0) {
    c->sepw_own = phgmg__dalloc(c->alloc, (size_t)sys->nsep);
    if (!c->sepw_own) return PHGMG_ERR_NOMEM;
    for (k = 0; k < sys->nsep; ++k)
      c->sepw_own[k] = (sys->sep_w ? sys->sep_w[k] : 1.0) * phgmg__ph_at(sys, sys->E, sys->sep_idx[k], sys->sep_idx[k]);
    c->sepw = c->sepw_own;
  }
  return phgmg__all_finite(c->Bp_own, (size_t)N * m) ? PHGMG_OK : PHGMG_ERR_NANINF;
}

PHGMG__PRIV int phgmg__is_gmg(int method) { return phgmg__method(method)->gmg; }

/* The deployment options (runs, validation, manifold). */
#define PHGMG__NVAL_MAX 67 /* training runs + 3 probes */
PHGMG__PRIV phgmg_result phgmg__deploy_check(const phgmg_reduce_opts *o, int ns) {
  if (o->nrun < 0 || (o->nrun > 0 && !o->runs) || o->nrun > PHGMG__NVAL_MAX - 3) return PHGMG_ERR_INVALID_ARG;
  if (o->nrun > 0 && phgmg_runs_columns(o->nrun, o->runs) < 0) return PHGMG_ERR_INVALID_ARG;
  if (o->nrun > 0 && phgmg_runs_columns(o->nrun, o->runs) != ns) return PHGMG_ERR_SIZE;
  if (!(o->select.tolerance >= 1.0 && o->select.tolerance < HUGE_VAL))
    return PHGMG_ERR_INVALID_ARG;
  if (!(o->select.newton_tol >= 0.0 && o->select.newton_tol < 1.0) || o->select.newton_iter < 0)
    return PHGMG_ERR_INVALID_ARG;
  if ((int)o->qm.manifold < 0 || (int)o->qm.manifold >= (int)PHGMG_MANIFOLD_COUNT) return PHGMG_ERR_INVALID_ARG;
  if (o->select.train_only != 0 && o->select.train_only != 1) return PHGMG_ERR_INVALID_ARG;
  if ((int)o->ref < 0 || (int)o->ref >= (int)PHGMG_REF_COUNT || (o->ref == PHGMG_REF_GIVEN && !o->ref_x))
    return PHGMG_ERR_INVALID_ARG;
  return PHGMG_OK;
}

/* The one place where the defaults of phgmg_reduce_opts are applied (manual
   3.2): every field left 0 takes its default; ns > 0 also resolves
   select.blocks. Invalid values are kept for phgmg__reduce_check to refuse.
   GMG_MANIFOLD has no default r_n (the caller's eta fixes it); select.newton_tol
   stays 0 (the steppers' defaults). Idempotent. */
PHGMG__PRIV void phgmg__reduce_opts_resolve(phgmg_reduce_opts *o, int ns) {
  /* rn = 0: the paper's r_n = 8 with the hierarchical POD manifold, V2 as wide
     as the data (PHGMG_RN_WIDE) with the greedy and altmin manifolds */
  if (o->qm.rn == 0 && o->method != PHGMG_METHOD_GMG_MANIFOLD)
    o->qm.rn = (o->method == PHGMG_METHOD_GMG_QM && o->qm.manifold != PHGMG_MANIFOLD_POD) ? PHGMG_RN_WIDE : 8;
  if (o->qm.lambda == 0.0) o->qm.lambda = 1e-3;
  if (o->hyper.deim_tol == 0.0) o->hyper.deim_tol = 1e-8;
  if (o->hyper.tol == 0.0) o->hyper.tol = 1e-6;
  if (o->degeneracy_tol == 0.0) o->degeneracy_tol = 1e-12;
  if (o->select.lambda_min == 0.0) o->select.lambda_min = 1e-14;
  if (o->select.lambda_max == 0.0) o->select.lambda_max = 1.0;
  if (o->select.per_decade == 0) o->select.per_decade = 4;
  if (o->select.folds == 0) o->select.folds = 5;
  if (o->select.blocks == 0 && ns > 0) o->select.blocks = PHGMG__MIN(ns, 100);
  if (o->select.rcond == 0.0) o->select.rcond = 1e-6;
  if (o->select.tolerance == 0.0) o->select.tolerance = 1.02;
  if (o->select.newton_iter == 0) o->select.newton_iter = 20;
}

PHGMG_DEF void phgmg_reduce_opts_default(phgmg_reduce_opts *o) {
  if (!o) return;
  memset(o, 0, sizeof *o);
  phgmg__reduce_opts_resolve(o, 0);
}

/* Options (resolved by phgmg__reduce_opts_resolve) and sizes; nothing
   allocated. X_checked: X is known finite (a study checked it). */
PHGMG__PRIV phgmg_result phgmg__reduce_check(const phgmg_ph_system *sys, const double *X, int ldx, int ns,
                                             const phgmg_reduce_opts *o, int X_checked) {
  const int N = sys->N, m = sys->m, r = o->r;
  if (N < 1 || m < 1 || ns < 1 || ldx < N) return PHGMG_ERR_SIZE;
  if (!phgmg__method(o->method)->by_reduce) return PHGMG_ERR_INVALID_ARG;
  if (phgmg__is_gmg(o->method)) {
    if (r <= m || r > N) return PHGMG_ERR_SIZE;
  } else if (r < 1 || r > N || r > ns) {
    return PHGMG_ERR_SIZE;
  }
  if (o->method == PHGMG_METHOD_GMG_MANIFOLD && (!o->qm.eta || o->qm.rn < 1)) return PHGMG_ERR_INVALID_ARG;
  if (o->qm.rn < PHGMG_RN_WIDE) return PHGMG_ERR_INVALID_ARG;
  if (o->hyper.on != 0 && o->hyper.on != 1) return PHGMG_ERR_INVALID_ARG;
  if ((int)o->hyper.kind < 0 || (int)o->hyper.kind >= (int)PHGMG_HYPER_COUNT) return PHGMG_ERR_INVALID_ARG;
  if (!(o->hyper.tol >= 0.0 && o->hyper.tol < 1.0)) return PHGMG_ERR_INVALID_ARG;
  if (o->hyper.on && sys->nl == PHGMG_NL_GENERAL) return PHGMG_ERR_UNSUPPORTED;
  if ((sys->P || sys->S || sys->Nskew || sys->ndamp) && !phgmg__method(o->method)->extras)
    return PHGMG_ERR_UNSUPPORTED;   /* dampers, feedthrough: linear maps only (manual 1.6, 1.7) */
  if ((sys->P || sys->S || sys->Nskew || sys->ndamp) && o->ref != PHGMG_REF_NONE)
    return PHGMG_ERR_UNSUPPORTED;   /* a reference state with dampers or feedthrough: not derived */
  if (!(o->hyper.deim_tol >= 0.0 && o->hyper.deim_tol < 1.0) || o->hyper.deim_max < 0) return PHGMG_ERR_INVALID_ARG;
  if (!(o->dt >= 0.0) || o->dt == HUGE_VAL) return PHGMG_ERR_INVALID_ARG;
  if (o->qm.lambda != o->qm.lambda || !(o->degeneracy_tol >= 0.0 && o->degeneracy_tol < 1.0)) return PHGMG_ERR_INVALID_ARG;
  if (sys->nl == PHGMG_NL_SEPARABLE && sys->poly_deg > 32) return PHGMG_ERR_SIZE;
  if (!X_checked && !phgmg__mat_finite(N, ns, X, ldx)) return PHGMG_ERR_NANINF; /* padding rows are not data */
  if (o->select.lambda_mode != PHGMG_LAMBDA_FIXED) {
    const int nf = o->select.folds, nb = o->select.blocks;
    if ((int)o->select.lambda_mode < 0 || (int)o->select.lambda_mode >= (int)PHGMG_LAMBDA_MODE_COUNT ||
        o->select.per_decade < 0 || nf < 2 || nb < 0)
      return PHGMG_ERR_INVALID_ARG;
    if (!(o->select.rcond >= 0.0 && o->select.rcond <= 1.0)) return PHGMG_ERR_INVALID_ARG;
    if (phgmg__lambda_grid(o->select.lambda_min, o->select.lambda_max, o->select.per_decade, NULL) < 1)
      return PHGMG_ERR_INVALID_ARG;
    if (nb < nf || nb > ns) return PHGMG_ERR_SIZE;
  }
  return phgmg__deploy_check(o, ns);
}

/* Column offsets of opts.runs (checked by phgmg__deploy_check). */
PHGMG__PRIV phgmg_result phgmg__runs_layout(phgmg__rctx *c) {
  int k;
  if (c->o->nrun < 1) return PHGMG_OK;
  c->runcol = phgmg__ialloc(c->alloc, (size_t)c->o->nrun + 1);
  if (!c->runcol) return PHGMG_ERR_NOMEM;
  c->runcol[0] = 0;
  for (k = 0; k < c->o->nrun; ++k) c->runcol[k + 1] = c->runcol[k] + c->o->runs[k].nsteps + 1;
  return PHGMG_OK;
}

/* The reduced object with its sizes (no data yet). */
PHGMG__PRIV phgmg_result phgmg__reduce_new(phgmg__rctx *c) {
  const phgmg_reduce_opts *o = c->o;
  phgmg_reduced *red = PHGMG__CAST(phgmg_reduced *, phgmg__alloc(c->alloc, sizeof(phgmg_reduced)));
  if (!red) return PHGMG_ERR_NOMEM;
  memset(red, 0, sizeof *red);
  c->red = red;
  if (c->alloc) { red->alloc = *c->alloc; red->use_alloc = 1; }
  red->N = c->sys->N; red->m = c->sys->m; red->r = o->r; red->method = o->method; red->sys = c->sys;
  red->kind = phgmg__method(o->method)->quadratic ? PHGMG_ROM_QUADRATIC : PHGMG_ROM_LINEAR;
  red->p = phgmg__is_gmg(o->method) ? o->r - red->m : o->r;
  if (red->kind == PHGMG_ROM_QUADRATIC) {
    c->wide = o->method == PHGMG_METHOD_GMG_QM &&
              (o->qm.rn == PHGMG_RN_WIDE || (o->qm.rn == 0 && o->qm.manifold != PHGMG_MANIFOLD_POD));
    /* resolved rn: a cap > 0, or PHGMG_RN_WIDE: then 8 is the alternating
       minimization's search width; phgmg__qm_wide_v2 sets the final one */
    red->rn = o->qm.rn > 0 ? o->qm.rn : PHGMG__MIN(8, red->N - red->r);
    if (red->rn < 1 || red->rn > red->N - red->r) return PHGMG_ERR_SIZE;
    /* your eta's q/Dq go through buffers of up to 64 x 64 (lift, dphi) */
    if (o->method == PHGMG_METHOD_GMG_MANIFOLD && (red->rn > 64 || red->rn * red->p > 64 * 64)) return PHGMG_ERR_SIZE;
  }
  if (o->method == PHGMG_METHOD_GMG_MANIFOLD) {
    const size_t p = (size_t)red->p, rn = (size_t)red->rn;
    red->eta = o->qm.eta;
    red->eta_user = o->qm.eta_user;
    red->rwork = PHGMG__CAST(phgmg_real *, phgmg__red_alloc(red, (p + rn * (1 + p + p * p)) * sizeof(phgmg_real)));
    if (!red->rwork) return PHGMG_ERR_NOMEM;
  }
  return PHGMG_OK;
}

/* A caller's basis (GMG: [V1, V2] from opts.cache.pod_basis) must be orthonormal
   and orthogonal to B; the hierarchical POD gives that by construction. */
PHGMG__PRIV phgmg_result phgmg__check_given_basis(const phgmg_reduced *red, const double *V, int k,
                                                   const phgmg_allocator *alloc) {
  const int N = red->N, m = red->m;
  double *G = phgmg__dalloc(alloc, (size_t)(k + m) * k);
  double err = 0.0;
  int i, j;
  if (!G) return PHGMG_ERR_NOMEM;
  phgmg__atb(N, k, k, V, V, G);
  for (j = 0; j < k; ++j)
    for (i = 0; i < k; ++i) err = PHGMG__MAX(err, fabs(G[i + (size_t)j * k] - (i == j ? 1.0 : 0.0)));
  phgmg__atb(N, m, k, red->QB, V, G);
  for (i = 0; i < m * k; ++i) err = PHGMG__MAX(err, fabs(G[i]));
  phgmg__free(alloc, G);
  return err <= 1e-8 ? PHGMG_OK : PHGMG_ERR_RANK;
}

/* GMG: V1 (the first p of k POD modes, N x k) and S into V0 and info. With
   c->V2h (hierarchical POD manifold), modes p+1..p+rn go there: the POD of
   (I - V1 V1^T) Xa that stage 2 needs is the rest of the same SVD. */
PHGMG__PRIV phgmg_result phgmg__basis_take(phgmg__rctx *c, const double *V1, const double *S, int k) {
  phgmg_reduced *red = c->red;
  const int N = red->N, m = red->m, p = red->p, rn = red->rn;
  if (k < p || !(S[p - 1] > c->rfloor)) return PHGMG_ERR_SIZE; /* r - m > rank */
  memcpy(red->V0 + (size_t)N * m, V1, (size_t)N * p * sizeof(double));
  c->inf.pod_sigma_ratio = (k > p && S[0] > 0.0) ? S[p] / S[0] : 0.0;
  if (c->V2h && k >= p + rn && S[p + rn - 1] > c->rfloor) {
    memcpy(c->V2h, V1 + (size_t)N * p, (size_t)N * rn * sizeof(double));
    c->v2ok = 1;
  }
  return PHGMG_OK;
}

/* Stage 2 can take V2 from the basis stage's SVD: the hierarchical POD
   manifold (GMG-QM with manifold = POD, or your own eta) without a given
   basis. */
PHGMG__PRIV int phgmg__v2_from_basis(const phgmg__rctx *c) {
  const phgmg_reduced *red = c->red;
  if (red->kind != PHGMG_ROM_QUADRATIC || c->o->cache.pod_basis || c->wide) return 0;
  return red->method == PHGMG_METHOD_GMG_MANIFOLD ||
         (red->method == PHGMG_METHOD_GMG_QM && c->o->qm.manifold == PHGMG_MANIFOLD_POD);
}

/* GMG with a linear basis (no manifold stage that needs the adjusted
   snapshots) and a large snapshot set (phgmg__pod_rand_wanted): the
   randomized POD of Xa = X - QB (QB^T X) applied as a product, without the
   N x ns copy. PHGMG_ERR_NOT_CONVERGED: not tried or its check failed (the
   caller then forms Xa and takes the exact POD). tmp: as stage_basis's. */
PHGMG__PRIV phgmg_result phgmg__basis_pod_implicit(phgmg__rctx *c, double *tmp) {
  phgmg_reduced *red = c->red;
  const int N = red->N, m = red->m, p = red->p, ns = c->ns, kk = PHGMG__MIN(p + 1, PHGMG__MIN(N, ns));
  double *V1 = tmp + (size_t)PHGMG__MAX(m, 1) * ns, *S = V1 + (size_t)N * (p + 1);
  int k = 0;
  phgmg_result rc;
  if (!phgmg__pod_rand_wanted(N, ns, kk)) return PHGMG_ERR_NOT_CONVERGED;
  phgmg_gemm('T', 'N', m, ns, N, 1.0, red->QB, N, c->X, c->ldx, 0.0, tmp, m); /* CB = QB^T X */
  rc = phgmg__pod_rand_core(N, ns, c->X, c->ldx, red->QB, m, tmp, kk, PHGMG_POD_POWER_ITERS, PHGMG_POD_SEED, V1, N, S,
                            &k, &c->inf.pod_check, c->alloc);
  if (rc == PHGMG_ERR_NOMEM || rc == PHGMG_ERR_NANINF) return rc;
  c->inf.pod_randomized = -1;
  if (rc != PHGMG_OK || k != kk || !(c->inf.pod_check <= PHGMG_POD_CHECK_TOL)) return PHGMG_ERR_NOT_CONVERGED;
  c->inf.pod_randomized = 1;
  return phgmg__basis_take(c, V1, S, k);
}

/* Stage 1, basis. GMG: V0 = [B, V1], V1 = POD of the adjusted snapshots
   X - B B^+ X (c->Xa keeps them, for the manifold stage). SP1/SP2: V0 =
   V_POD of X. opts.cache.pod_basis replaces the POD. */
PHGMG__PRIV phgmg_result phgmg__stage_basis(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int N = red->N, m = red->m, p = red->p, ns = c->ns;
  const int need = p + (red->kind == PHGMG_ROM_QUADRATIC ? red->rn : 0);
  double *S, *tmp;
  int k = 0, j, kk;
  phgmg_result rc;
  red->V0 = phgmg__red_d(red, (size_t)N * red->r);
  red->QB = phgmg__red_d(red, (size_t)N * m);
  red->RB = phgmg__red_d(red, (size_t)m * m);
  if (!red->V0 || !red->QB || !red->RB) return PHGMG_ERR_NOMEM;
  rc = phgmg__thin_qr(N, m, c->Bp, red->QB, red->RB, c->alloc);
  if (rc != PHGMG_OK) return rc;
  if (c->o->cache.pod_basis && c->o->cache.pod_cols < need) return PHGMG_ERR_SIZE;
  if (!phgmg__is_gmg(red->method)) {
    if (c->o->cache.pod_basis) {
      memcpy(red->V0, c->o->cache.pod_basis, (size_t)N * p * sizeof(double));
      return PHGMG_OK;
    }
    /* one mode more than kept when the data have it: sigma_{r+1} for info */
    kk = PHGMG__MIN(p + 1, PHGMG__MIN(N, ns));
    S = phgmg__dalloc(c->alloc, (size_t)kk + (size_t)N * kk);
    if (!S) return PHGMG_ERR_NOMEM;
    rc = phgmg__pod_auto(N, ns, c->X, c->ldx, kk, S + kk, N, S, &k, &c->inf.pod_randomized, &c->inf.pod_check,
                         c->alloc);
    if (rc == PHGMG_OK && (k < p || !(S[p - 1] > c->rfloor))) rc = PHGMG_ERR_SIZE;
    if (rc == PHGMG_OK) {
      memcpy(red->V0, S + kk, (size_t)N * p * sizeof(double));
      c->inf.pod_sigma_ratio = (k > p && S[0] > 0.0) ? S[p] / S[0] : 0.0;
    }
    phgmg__free(c->alloc, S);
    return rc;
  }
  if (c->sf == PHGMG__SF_GMG) { /* the study's basis: Xa is not needed (its coordinates are cached) */
    memcpy(red->V0, c->sys->B, (size_t)N * m * sizeof(double));
    memcpy(red->V0 + (size_t)N * m, c->o->cache.pod_basis, (size_t)N * p * sizeof(double));
    return PHGMG_OK;
  }
  kk = phgmg__v2_from_basis(c) ? p + red->rn + 1 : p + 1;
  kk = PHGMG__MIN(kk, PHGMG__MIN(N, ns));
  tmp = phgmg__dalloc(c->alloc, (size_t)PHGMG__MAX(m, 1) * ns + (size_t)N * (p + red->rn + 1) + (size_t)p + red->rn + 1);
  if (!tmp) return PHGMG_ERR_NOMEM;
  if (phgmg__v2_from_basis(c)) {
    c->V2h = phgmg__dalloc(c->alloc, (size_t)N * red->rn);
    if (!c->V2h) { phgmg__free(c->alloc, tmp); return PHGMG_ERR_NOMEM; }
  }
  memcpy(red->V0, c->Bp, (size_t)N * m * sizeof(double));
  if (!c->o->cache.pod_basis && red->kind != PHGMG_ROM_QUADRATIC) { /* large: randomized, X - QB QB^T X implicit */
    rc = phgmg__basis_pod_implicit(c, tmp);
    if (rc != PHGMG_ERR_NOT_CONVERGED) { phgmg__free(c->alloc, tmp); return rc; }
    rc = PHGMG_OK;
  }
  c->Xa = phgmg__dalloc(c->alloc, (size_t)N * ns);
  if (!c->Xa) { phgmg__free(c->alloc, tmp); return PHGMG_ERR_NOMEM; }
  for (j = 0; j < ns; ++j) memcpy(c->Xa + (size_t)j * N, c->X + (size_t)j * c->ldx, (size_t)N * sizeof(double));
  phgmg__orth_remove(N, m, red->QB, ns, c->Xa, N, tmp);
  if (c->o->cache.pod_basis) {
    memcpy(red->V0 + (size_t)N * m, c->o->cache.pod_basis, (size_t)N * p * sizeof(double));
    if (red->method == PHGMG_METHOD_GMG_MANIFOLD)
      rc = phgmg__check_given_basis(red, c->o->cache.pod_basis, need, c->alloc);
  } else {
    double *V1 = tmp + (size_t)PHGMG__MAX(m, 1) * ns;
    S = V1 + (size_t)N * (p + red->rn + 1);
    rc = phgmg__pod_auto(N, ns, c->Xa, N, kk, V1, N, S, &k, &c->inf.pod_randomized, &c->inf.pod_check, c->alloc);
    if (rc == PHGMG_OK) rc = phgmg__basis_take(c, V1, S, k);
  }
  phgmg__free(c->alloc, tmp);
  return rc;
}

/* GMG-QM ridge problem (eq. least_square_reg) over the reduced snapshot
   coordinates, in full Kronecker form. Columns (a,j) and (j,a) of x2 kron x2
   are equal, so the (unique) ridge solution has M(:,(a,j)) = M(:,(j,a)); the
   equivalent problem over the p(p+1)/2 distinct columns (off-diagonal ones
   scaled by sqrt 2, unknown t = sqrt 2 M(:,(a,j))) has the same minimiser
   with 4x fewer flops. c->Tq = [Kt (ns x nc), Rqt (ns x rn), Mt (nc x rn)]. */
/* The snapshot coordinates the quadratic fit and the checks read, from one
   provider: the V1 coordinates V1^T X (p rows) and the V2 coordinates
   V2^T Xa (rn rows) of snapshots j0 .. j0+nb-1, taken from the study's
   cache (phgmg_study_reduce on its GMG basis: columns of Ca) or computed
   into buf (p x nb, resp. rn x nb). Returns the block; *ld its leading
   dimension. */
PHGMG__PRIV const double *phgmg__snap_v1(const phgmg__rctx *c, int j0, int nb, double *buf, int *ld) {
  const phgmg_reduced *red = c->red;
  const int N = red->N, m = red->m, p = red->p;
  if (c->sf == PHGMG__SF_GMG) { *ld = c->st->ka; return c->st->Ca + (size_t)j0 * c->st->ka; }
  phgmg_gemm('T', 'N', p, nb, N, 1.0, red->V0 + (size_t)N * m, N, c->X + (size_t)j0 * c->ldx, c->ldx, 0.0, buf, p);
  *ld = p;
  return buf;
}
PHGMG__PRIV const double *phgmg__snap_v2(const phgmg__rctx *c, int j0, int nb, double *buf, int *ld) {
  const phgmg_reduced *red = c->red;
  const int N = red->N, rn = red->rn;
  if (c->sf == PHGMG__SF_GMG) { *ld = c->st->ka; return c->st->Ca + (size_t)j0 * c->st->ka + red->p; }
  phgmg_gemm('T', 'N', rn, nb, N, 1.0, red->V2, N, c->Xa + (size_t)j0 * N, N, 0.0, buf, rn);
  *ld = rn;
  return buf;
}

PHGMG__PRIV phgmg_result phgmg__qm_problem(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int p = red->p, rn = red->rn, ns = c->ns, nc = p * (p + 1) / 2;
  const double s2 = sqrt(2.0);
  double *Z2, *Rq, *Kt, *Rqt;
  int i, a, j, cc;
  Z2 = phgmg__dalloc(c->alloc, (size_t)p * ns + (size_t)rn * ns);
  c->Tq = phgmg__dalloc(c->alloc, (size_t)ns * nc + (size_t)ns * rn + (size_t)nc * rn);
  if (!Z2 || !c->Tq) { phgmg__free(c->alloc, Z2); return PHGMG_ERR_NOMEM; }
  Rq = Z2 + (size_t)p * ns; Kt = c->Tq; Rqt = Kt + (size_t)ns * nc;
  {
    int l1, l2;
    const double *z2 = phgmg__snap_v1(c, 0, ns, Z2, &l1), *rq = phgmg__snap_v2(c, 0, ns, Rq, &l2);
    for (i = 0; i < ns; ++i) {
      for (a = 0, cc = 0; a < p; ++a)
        for (j = a; j < p; ++j, ++cc)
          Kt[i + (size_t)cc * ns] = (a == j ? 1.0 : s2) * z2[a + (size_t)i * l1] * z2[j + (size_t)i * l1];
      for (a = 0; a < rn; ++a) Rqt[i + (size_t)a * ns] = rq[a + (size_t)i * l2];
    }
  }
  phgmg__free(c->alloc, Z2);
  return PHGMG_OK;
}

/* A chosen lambda (PHGMG_LAMBDA_REGRESSION, and the starting point of
   _VALIDATED): validation over contiguous blocks of snapshots picks the
   grid lambda (ties within 1e-6 relative: the largest). */
PHGMG__PRIV phgmg_result phgmg__qm_lambda_auto(phgmg__rctx *c) {
  const phgmg_reduce_opts *o = c->o;
  const int ns = c->ns, p = c->red->p, rn = c->red->rn, nc = p * (p + 1) / 2, ng = c->ng;
  const int byrun = o->nrun >= 2 && c->runcol;   /* leave one run out */
  const int nfold = byrun ? o->nrun : o->select.folds;
  const int nblk = o->select.blocks;
  double best, *lg;
  int g;
  phgmg_result rc;
  lg = c->lg = phgmg__dalloc(c->alloc, 2 * (size_t)ng);
  if (!lg) return PHGMG_ERR_NOMEM;
  phgmg__lambda_grid(o->select.lambda_min, o->select.lambda_max, o->select.per_decade, lg);
  if (c->sf == PHGMG__SF_GMG && !byrun && c->st->cv && c->st->cv_p == p && c->st->cv_rn == rn && c->st->cv_ng == ng &&
      c->st->cv_nf == nfold && c->st->cv_nb == nblk && c->st->cv_lo == lg[0] && c->st->cv_hi == lg[ng - 1]) {
    memcpy(lg + ng, c->st->cv, (size_t)ng * sizeof(double));   /* the study's: same problem, same basis */
  } else {
    rc = phgmg__ridge_cv_runs(ns, nc, rn, c->Tq, ns, c->Tq + (size_t)ns * nc, ns, ng, lg, nfold, nblk,
                              byrun ? c->runcol : NULL, lg + ng, c->alloc);
    if (rc != PHGMG_OK) return rc;
    if (c->sf == PHGMG__SF_GMG && !byrun) {
      const phgmg_allocator *sa = c->st->use_alloc ? &c->st->alloc : NULL;
      phgmg__free(sa, c->st->cv);
      c->st->cv = phgmg__dalloc(sa, (size_t)ng);
      if (c->st->cv) {
        memcpy(c->st->cv, lg + ng, (size_t)ng * sizeof(double));
        c->st->cv_p = p; c->st->cv_rn = rn; c->st->cv_ng = ng; c->st->cv_nf = nfold; c->st->cv_nb = nblk;
        c->st->cv_lo = lg[0]; c->st->cv_hi = lg[ng - 1];
      }
    }
  }
  for (c->gsel = 0, g = 1; g < ng; ++g) if (lg[ng + g] < lg[ng + c->gsel]) c->gsel = g;
  best = lg[ng + c->gsel];
  for (g = ng - 1; g > c->gsel; --g) if (lg[ng + g] <= best * (1.0 + 1e-6)) { c->gsel = g; break; }
  c->lambda = lg[c->gsel];
  c->inf.lambda_cv_err = lg[ng + c->gsel];
  c->inf.lambda_grid = ng;
  return PHGMG_OK;
}

/* opts.qm.manifold = 1, greedy linear part (Schwerdtner & Peherstorfer 2024):
   among the q = min(p + rn, available) leading POD modes U of the adjusted
   snapshots, V1 takes one mode at a time -- the one whose reduced
   coordinates z (with those already taken) best predict the remaining
   modes' coordinates by the quadratic ridge fit M (z kron z) (ridge lambda
   1e-9 when lambda is chosen, whose lambda is not known yet; else opts.qm.lambda). Works in the
   q POD coordinates S = U^T Xa of every k-th snapshot (k = ceil(ns / 400)),
   so a trial costs one small least-squares solve. Writes V1 into red->V0. */
PHGMG__PRIV phgmg_result phgmg__qm_greedy(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int N = red->N, m = red->m, p = red->p, rn = red->rn, ns = c->ns;
  const int st = (ns + 399) / 400, nsub = (ns + st - 1) / st;
  const int navail = c->o->cache.pod_basis ? c->o->cache.pod_cols : PHGMG__MIN(N, ns) - 1;
  const int q = PHGMG__MIN(p + rn, navail);
  const double lam = c->o->select.lambda_mode != PHGMG_LAMBDA_FIXED ? 1e-9 : (c->lambda > 0.0 ? c->lambda : 1e-12);
  double *U, *S, *Kt, *Rt, *T, best_err;
  int *sel, *used, j, k, a, b, i, cc, best, nc, nr, kk = 0;
  phgmg_result rc = PHGMG_OK;
  if (q <= p) return PHGMG_OK;   /* no choice: the leading modes */
  U = phgmg__dalloc(c->alloc, (size_t)N * q + (size_t)q * ns + (size_t)q);
  Kt = phgmg__dalloc(c->alloc, (size_t)nsub * (p * (p + 1) / 2) + (size_t)nsub * q + (size_t)(p * (p + 1) / 2) * q);
  sel = phgmg__ialloc(c->alloc, 2 * (size_t)q);
  if (!U || !Kt || !sel) { phgmg__free(c->alloc, U); phgmg__free(c->alloc, Kt); phgmg__free(c->alloc, sel); return PHGMG_ERR_NOMEM; }
  S = U + (size_t)N * q; Rt = Kt + (size_t)nsub * (p * (p + 1) / 2); T = Rt + (size_t)nsub * q;
  used = sel + q;
  if (c->o->cache.pod_basis) memcpy(U, c->o->cache.pod_basis, (size_t)N * q * sizeof(double));
  else {
    rc = phgmg_pod(N, ns, c->Xa, N, q, 0.0, U, N, S, &kk, c->alloc);
    if (rc == PHGMG_OK && kk < q) rc = PHGMG_ERR_SIZE;
  }
  if (rc == PHGMG_OK) phgmg_gemm('T', 'N', q, ns, N, 1.0, U, N, c->Xa, N, 0.0, S, q);
  for (k = 0; k < q; ++k) used[k] = 0;
  for (j = 0; j < p && rc == PHGMG_OK; ++j) {
    best = -1; best_err = HUGE_VAL;
    nc = (j + 1) * (j + 2) / 2; nr = q - j - 1;
    for (k = 0; k < q && rc == PHGMG_OK; ++k) {
      double err = 0.0;
      if (used[k]) continue;
      sel[j] = k;
      for (i = 0; i < nsub; ++i) {
        const double *s = S + (size_t)(i * st) * q;
        for (a = 0, cc = 0; a <= j; ++a)
          for (b = a; b <= j; ++b, ++cc) Kt[i + (size_t)cc * nsub] = (a == b ? 1.0 : sqrt(2.0)) * s[sel[a]] * s[sel[b]];
        for (a = 0, cc = 0; a < q; ++a)
          if (!used[a] && a != k) Rt[i + (size_t)(cc++) * nsub] = s[a];
      }
      if (nr > 0) {
        rc = phgmg_lstsq(nsub, nc, nr, Kt, nsub, Rt, nsub, lam, T, nc, c->alloc);
        if (rc != PHGMG_OK) break;
        for (a = 0; a < nr; ++a)
          for (i = 0; i < nsub; ++i) {
            double d = Rt[i + (size_t)a * nsub];
            for (cc = 0; cc < nc; ++cc) d -= Kt[i + (size_t)cc * nsub] * T[cc + (size_t)a * nc];
            err += d * d;
          }
      }
      if (err < best_err) { best_err = err; best = k; }
    }
    if (rc != PHGMG_OK) break;
    sel[j] = best;
    used[best] = 1;
  }
  if (rc == PHGMG_OK)
    for (j = 0; j < p; ++j) memcpy(red->V0 + (size_t)N * (m + j), U + (size_t)N * sel[j], (size_t)N * sizeof(double));
  phgmg__free(c->alloc, U);
  phgmg__free(c->alloc, Kt);
  phgmg__free(c->alloc, sel);
  return rc;
}

/* A scratch arena for the many small solves of the alternating minimization:
   allocations bump a pointer in a block allocated once (reset before each
   solve, whose allocations do not outlive it); what does not fit goes to the
   caller's allocator. Frees inside the block are no-ops. */
typedef struct phgmg__arena {
  unsigned char *base;
  size_t cap, used;
  const phgmg_allocator *up;
} phgmg__arena;
PHGMG__PRIV void *phgmg__arena_alloc(size_t n, void *u) {
  phgmg__arena *a = (phgmg__arena *)u;
  n = (n + 63) & ~(size_t)63;
  if (n <= a->cap - a->used) {
    void *p = a->base + a->used;
    a->used += n;
    return p;
  }
  return phgmg__alloc(a->up, n);
}
PHGMG__PRIV void phgmg__arena_free(void *p, void *u) {
  phgmg__arena *a = (phgmg__arena *)u;
  if (p && (unsigned char *)p >= a->base && (unsigned char *)p < a->base + a->cap) return;
  phgmg__free(a->up, p);
}

/* opts.qm.manifold = PHGMG_MANIFOLD_ALTMIN, one evaluation in the q POD
   coordinates S (q x ns) of the adjusted snapshots, for the orthonormal
   Q = [Q1, Q2] (q x (p + rn)): Z = Q1^T S, the ridge fit T (nc x rn) of
   Q2^T S over the distinct Kronecker columns Kt of Z (as phgmg__qm_problem),
   W = [Z; (Kt T)^T] ((p + rn) x ns) and the objective
   *f = ||S - Q W||_F^2 + lam ||T||_F^2. Kt (ns x nc), Yt (ns x rn) scratch. */
PHGMG__PRIV phgmg_result phgmg__altmin_eval(int q, int ns, int p, int rn, const double *S, const double *Q,
                                            double lam, double *Kt, double *Yt, double *T, double *W,
                                            double *R, double *f, const phgmg_allocator *alloc) {
  const int k = p + rn, nc = p * (p + 1) / 2;
  const double s2 = sqrt(2.0);
  double sum = 0.0;
  int i, a, j, cc;
  phgmg_result rc;
  phgmg_gemm('T', 'N', k, ns, q, 1.0, Q, q, S, q, 0.0, W, k);   /* [Z; Q2^T S] */
  for (i = 0; i < ns; ++i) {
    const double *z = W + (size_t)i * k;
    for (a = 0, cc = 0; a < p; ++a)
      for (j = a; j < p; ++j, ++cc) Kt[i + (size_t)cc * ns] = (a == j ? 1.0 : s2) * z[a] * z[j];
    for (a = 0; a < rn; ++a) Yt[i + (size_t)a * ns] = z[p + a];
  }
  if (alloc && alloc->alloc == phgmg__arena_alloc) ((phgmg__arena *)alloc->user)->used = 0;
  rc = phgmg__lstsq_fit(ns, nc, rn, Kt, Yt, lam, T, alloc);
  if (rc != PHGMG_OK) return rc;
  phgmg_gemm('N', 'N', ns, rn, nc, 1.0, Kt, ns, T, nc, 0.0, Yt, ns);   /* the fitted correction */
  for (i = 0; i < ns; ++i)
    for (a = 0; a < rn; ++a) W[p + a + (size_t)i * k] = Yt[i + (size_t)a * ns];
  memcpy(R, S, (size_t)q * ns * sizeof(double));
  phgmg_gemm('N', 'N', q, ns, k, -1.0, Q, q, W, k, 1.0, R, q);
  for (i = 0; i < q * ns; ++i) sum += R[i] * R[i];
  for (i = 0; i < nc * rn; ++i) sum += lam * T[i] * T[i];
  *f = sum;
  return sum <= HUGE_VAL ? PHGMG_OK : PHGMG_ERR_NANINF;
}

/* The orthonormal polar factor Q = U V^T of A = U Sigma V^T (q x k, thin
   SVD): the orthonormal matrix nearest to A. U (q x k), V (k x k), sv (k)
   scratch. PHGMG_ERR_RANK when A is rank deficient (not unique then). */
PHGMG__PRIV phgmg_result phgmg__polar(int q, int k, const double *A, double *U, double *V, double *sv, double *Q,
                                      const phgmg_allocator *alloc) {
  int kk = 0;
  phgmg_result rc;
  if (alloc && alloc->alloc == phgmg__arena_alloc) ((phgmg__arena *)alloc->user)->used = 0;
  rc = phgmg_svd(q, k, A, q, k, sv, U, q, V, k, &kk, NULL, alloc);
  if (rc != PHGMG_OK) return rc;
  if (kk < k) return PHGMG_ERR_RANK;
  phgmg_gemm('N', 'T', q, k, k, 1.0, U, q, V, k, 0.0, Q, q);
  return PHGMG_OK;
}

/* Workspace of the alternating minimization (phgmg__qm_altmin). */
typedef struct phgmg__altmin_ws {
  int q, ns, p, rn, k;
  double lam;
  const double *S;                    /* q x ns POD coordinates               */
  double *Q, *W, *Qn, *Wn, *Qb, *Wb;  /* current, step, trial (q x k, k x ns)  */
  double *Kt, *Yt, *T, *R, *A, *U, *V, *sv;
  phgmg_allocator al;                 /* the scratch arena (phgmg__arena)     */
} phgmg__altmin_ws;

/* One sweep from (Q, W, *f): the Procrustes step Qn = polar(S W^T), i.e. the
   orthonormal Q minimising ||S - Q W||_F for the current latent values W,
   with M refitted; then, while it lowers the objective, the extrapolation
   polar(Q + beta (Qn - Q)), beta = 2, 4, 8 (the plain step converges
   linearly and slowly). Kept (into Q, W, *f) only if the objective
   decreased: *moved = 1. */
PHGMG__PRIV phgmg_result phgmg__altmin_sweep(phgmg__altmin_ws *w, double *f, int *moved) {
  const int q = w->q, k = w->k;
  double fn, fb, beta;
  int i;
  phgmg_result rc;
  *moved = 0;
  phgmg_gemm('N', 'T', q, k, w->ns, 1.0, w->S, q, w->W, k, 0.0, w->A, q);
  rc = phgmg__polar(q, k, w->A, w->U, w->V, w->sv, w->Qn, &w->al);
  if (rc == PHGMG_OK)
    rc = phgmg__altmin_eval(q, w->ns, w->p, w->rn, w->S, w->Qn, w->lam, w->Kt, w->Yt, w->T, w->Wn, w->R, &fn, &w->al);
  if (rc != PHGMG_OK || !(fn < *f)) return rc;
  for (beta = 2.0; beta <= 8.0; beta *= 2.0) {
    for (i = 0; i < q * k; ++i) w->A[i] = w->Q[i] + beta * (w->Qn[i] - w->Q[i]);
    rc = phgmg__polar(q, k, w->A, w->U, w->V, w->sv, w->Qb, &w->al);
    if (rc == PHGMG_OK)
      rc = phgmg__altmin_eval(q, w->ns, w->p, w->rn, w->S, w->Qb, w->lam, w->Kt, w->Yt, w->T, w->Wb, w->R, &fb, &w->al);
    if (rc == PHGMG_ERR_NOMEM) return rc;
    if (rc != PHGMG_OK || !(fb < fn)) break;
    memcpy(w->Qn, w->Qb, (size_t)q * k * sizeof(double));
    memcpy(w->Wn, w->Wb, (size_t)k * w->ns * sizeof(double));
    fn = fb;
  }
  memcpy(w->Q, w->Qn, (size_t)q * k * sizeof(double));
  memcpy(w->W, w->Wn, (size_t)k * w->ns * sizeof(double));
  *f = fn;
  *moved = 1;
  return PHGMG_OK;
}

/* The search space of the alternating minimization (phgmg__qm_altmin): q
   orthonormal modes U (N x q, room for qmax) of the adjusted snapshots, in
   which V1 and V2 are rotated. Warm start (the greedy's, c->Uw): [V1, the
   leading modes of its complement]; opts.cache.pod_basis: its leading columns;
   else the leading POD modes of Xa, with a wide V2 only those above the
   rank floor (the numerical rank). Sets *q <= qmax. */
PHGMG__PRIV phgmg_result phgmg__altmin_space(phgmg__rctx *c, int qmax, double *U, int *q) {
  phgmg_reduced *red = c->red;
  const int N = red->N, m = red->m, p = red->p, ns = c->ns;
  double *sv;
  int kk = 0;
  phgmg_result rc;
  *q = qmax;
  if (c->Uw) {
    *q = PHGMG__MIN(qmax, p + c->kw);
    memcpy(U, red->V0 + (size_t)N * m, (size_t)N * p * sizeof(double));
    if (*q > p) memcpy(U + (size_t)N * p, c->Uw, (size_t)N * (*q - p) * sizeof(double));
    return PHGMG_OK;
  }
  if (c->o->cache.pod_basis) {
    memcpy(U, c->o->cache.pod_basis, (size_t)N * qmax * sizeof(double));
    return PHGMG_OK;
  }
  sv = phgmg__dalloc(c->alloc, (size_t)qmax);
  if (!sv) return PHGMG_ERR_NOMEM;
  rc = phgmg_pod(N, ns, c->Xa, N, qmax, 0.0, U, N, sv, &kk, c->alloc);
  while (rc == PHGMG_OK && c->wide && kk > 0 && !(sv[kk - 1] > c->rfloor)) --kk;
  phgmg__free(c->alloc, sv);
  *q = kk;   /* the numerical rank may cut the candidates */
  return rc;
}

PHGMG__PRIV void phgmg__qm_features(int p, int ns, const double *Z2, int ldz, double *Kt, int ldk);

/* The alternating minimization with a wide V2 (phgmg__altmin_wide): V2 is
   all of span U that V1 = U Q1 leaves, so the objective depends on Q1
   (q x p, orthonormal) alone:
     f(Q1) = min_T ||E||_F^2 + lam ||T||_F^2,  E = R - (K T)^T,
     R = (I - Q1 Q1^T) S,  K = the features of Z = Q1^T S (ns x nc).
   The ridge fit T (nc x q) is the minimization over M for the current V1;
   by the envelope theorem the gradient in Q1 is that of ||E||^2 with T held
   fixed: -2 (E Z^T + S L^T), L (p x ns) = the chain rule of the features
   through Gam = T E (the first term of the Q1-derivative of R vanishes
   because Q1^T E = 0), projected on the tangent space (I - Q1 Q1^T). */
typedef struct phgmg__awide {
  int q, ns, p, nc;
  double lam;
  const double *S;                          /* q x ns coordinates            */
  double *Z, *Kt, *Rt, *T, *E, *Gam, *L;    /* p x ns, ns x nc, ns x q, nc x q,
                                               q x ns, nc x ns, p x ns      */
  double *Pu, *Pv, *Psv;                    /* polar scratch: q x p, p x p, p */
  phgmg_allocator al;                       /* the scratch arena            */
} phgmg__awide;

/* f(Q1) into *f and, with g != NULL, its tangent gradient g (q x p). */
PHGMG__PRIV phgmg_result phgmg__awide_eval(phgmg__awide *w, const double *Q1, double *f, double *g) {
  const int q = w->q, ns = w->ns, p = w->p, nc = w->nc;
  const double s2 = sqrt(2.0);
  double sum = 0.0;
  int i, a, b, cc;
  phgmg_result rc;
  phgmg_gemm('T', 'N', p, ns, q, 1.0, Q1, q, w->S, q, 0.0, w->Z, p);
  phgmg__qm_features(p, ns, w->Z, p, w->Kt, ns);
  memcpy(w->E, w->S, (size_t)q * ns * sizeof(double));
  phgmg_gemm('N', 'N', q, ns, p, -1.0, Q1, q, w->Z, p, 1.0, w->E, q);   /* R */
  for (i = 0; i < ns; ++i)
    for (a = 0; a < q; ++a) w->Rt[i + (size_t)a * ns] = w->E[a + (size_t)i * q];
  if (w->al.alloc == phgmg__arena_alloc) ((phgmg__arena *)w->al.user)->used = 0;
  rc = phgmg__lstsq_fit(ns, nc, q, w->Kt, w->Rt, w->lam, w->T, &w->al);
  if (rc != PHGMG_OK) return rc;
  phgmg_gemm('T', 'T', q, ns, nc, -1.0, w->T, nc, w->Kt, ns, 1.0, w->E, q);   /* E = R - (K T)^T */
  sum = phgmg__sumsq(q, ns, w->E, q) + w->lam * phgmg__sumsq(nc, q, w->T, nc);
  *f = sum;
  if (!(sum <= HUGE_VAL)) return PHGMG_ERR_NANINF;
  if (!g) return PHGMG_OK;
  phgmg_gemm('N', 'N', nc, ns, q, 1.0, w->T, nc, w->E, q, 0.0, w->Gam, nc);
  memset(w->L, 0, (size_t)p * ns * sizeof(double));
  for (i = 0; i < ns; ++i) {
    const double *z = w->Z + (size_t)i * p, *gm = w->Gam + (size_t)i * nc;
    double *l = w->L + (size_t)i * p;
    for (a = 0, cc = 0; a < p; ++a)
      for (b = a; b < p; ++b, ++cc) {
        if (a == b) l[a] += 2.0 * gm[cc] * z[a];
        else { l[a] += s2 * gm[cc] * z[b]; l[b] += s2 * gm[cc] * z[a]; }
      }
  }
  phgmg_gemm('N', 'T', q, p, ns, -2.0, w->E, q, w->Z, p, 0.0, g, q);
  phgmg_gemm('N', 'T', q, p, ns, -2.0, w->S, q, w->L, p, 1.0, g, q);
  phgmg_gemm('T', 'N', p, p, q, 1.0, Q1, q, g, q, 0.0, w->Pv, p);    /* tangent: g - Q1 (Q1^T g) */
  phgmg_gemm('N', 'N', q, p, p, -1.0, Q1, q, w->Pv, p, 1.0, g, q);
  return PHGMG_OK;
}

/* The descent in Q1 (opts.qm.manifold = ALTMIN with a wide V2): from Q1 = the
   first p coordinates (the start of phgmg__qm_altmin), steps
   Q1 <- polar(Q1 - t g) along the tangent gradient g, with the
   Barzilai-Borwein step t (the plain gradient step converges slowly here)
   safeguarded by a non-monotone backtracking: t is halved until f falls
   below the largest of the last PHGMG__AW_MEM values by 1e-4 t ||g||^2 (at
   most 40 halvings). The best Q1 seen is returned, so the result is never
   worse than the start. Stops after PHGMG__AW_STEPS steps, when no step is
   accepted, or when the best f has gained less than 1e-6 of itself over
   PHGMG__AW_MEM steps. Q1 (q x p) in/out; *f0, *f the objective at the
   start and at the end. */
#define PHGMG__AW_STEPS 200
#define PHGMG__AW_MEM 8
PHGMG__PRIV phgmg_result phgmg__altmin_wide(phgmg__awide *w, double *Q1, double *f0, double *f, int *steps,
                                            const phgmg_allocator *alloc) {
  const int q = w->q, p = w->p, qp = q * p;
  double *g, *gn, *Qn, *sd, *Qc, t, gg, fn, fc, sy, ss, fref, hist[PHGMG__AW_MEM], fbest_old = HUGE_VAL;
  int it, h, i;
  phgmg_result rc;
  g = phgmg__dalloc(alloc, 5 * (size_t)qp);
  if (!g) return PHGMG_ERR_NOMEM;
  gn = g + qp; Qn = gn + qp; sd = Qn + qp; Qc = sd + qp;
  *steps = 0;
  memcpy(Qc, Q1, (size_t)qp * sizeof(double));
  rc = phgmg__awide_eval(w, Qc, &fc, g);
  *f0 = *f = fc;
  for (i = 0; i < PHGMG__AW_MEM; ++i) hist[i] = fc;
  gg = phgmg__dot(qp, g, g);
  t = gg > 0.0 ? 0.5 / sqrt(gg) : 0.0;
  for (it = 0; rc == PHGMG_OK && it < PHGMG__AW_STEPS && gg > 0.0; ++it) {
    for (i = 1, fref = hist[0]; i < PHGMG__AW_MEM; ++i) fref = PHGMG__MAX(fref, hist[i]);
    for (h = 0, fn = HUGE_VAL; h < 40; ++h, t *= 0.5) {
      for (i = 0; i < qp; ++i) sd[i] = Qc[i] - t * g[i];
      rc = phgmg__polar(q, p, sd, w->Pu, w->Pv, w->Psv, Qn, &w->al);
      if (rc == PHGMG_OK) rc = phgmg__awide_eval(w, Qn, &fn, gn);
      if (rc == PHGMG_ERR_NOMEM) break;
      if (rc == PHGMG_OK && fn <= fref - 1e-4 * t * gg) break;
      rc = PHGMG_OK;
      fn = HUGE_VAL;
    }
    if (rc != PHGMG_OK || !(fn < HUGE_VAL)) break;
    for (i = 0, sy = ss = 0.0; i < qp; ++i) {
      const double di = Qn[i] - Qc[i], yi = gn[i] - g[i];
      sy += di * yi; ss += di * di;
    }
    memcpy(Qc, Qn, (size_t)qp * sizeof(double));
    memcpy(g, gn, (size_t)qp * sizeof(double));
    fc = fn;
    gg = phgmg__dot(qp, g, g);
    hist[it % PHGMG__AW_MEM] = fc;
    ++*steps;
    if (fc < *f) { *f = fc; memcpy(Q1, Qc, (size_t)qp * sizeof(double)); }
    if (it % PHGMG__AW_MEM == PHGMG__AW_MEM - 1) {
      if (*f > fbest_old * (1.0 - 1e-6)) break;
      fbest_old = *f;
    }
    t = sy != 0.0 ? fabs(ss / sy) : 2.0 * t;   /* Barzilai-Borwein */
  }
  phgmg__free(alloc, g);
  return rc == PHGMG_ERR_NOMEM ? rc : PHGMG_OK;   /* a failed fit or step: the best Q1 so far */
}

/* opts.qm.manifold = PHGMG_MANIFOLD_ALTMIN: alternating minimization of the
   linear and quadratic parts (after Geelen, Balzano, Wright & Willcox 2023).
   In the coordinates S = U^T Xa of q orthonormal modes U of the adjusted
   snapshots Xa = X - B B^+ X (phgmg__altmin_space), with V1 = U Q1,
   V2 = U Q2 and Q = [Q1, Q2] orthonormal (so [B, V1, V2] stays orthonormal
   and B in the span, as the hierarchical POD has it), the objective is
   sum_i ||x_i - phi(rho(x_i))||^2 + lam ||M||^2 (lam as phgmg__qm_greedy).
   V2 of width rn: U = the q = min(2 (p + rn), rank) leading POD modes.
   A wide V2: U = every mode above the rank floor (at most PHGMG__ALTMIN_QMAX)
   and Q square (V2 = all of span U that V1 leaves), so that the objective
   is the one of the wide model that phgmg__qm_wide_v2 then builds.
   Start: Q = the leading p + rn coordinates (the hierarchical POD, or the
   greedy manifold as warm start). Each sweep (phgmg__altmin_sweep) moves Q by
   the orthogonal Procrustes step and refits M; a sweep is kept only if the
   objective decreases, so it never increases. Stop: no decrease, a relative
   decrease below 1e-5, or 100 sweeps. Writes V1 into red->V0 and (V2 of
   width rn) V2 into red->V2. */
#define PHGMG__ALTMIN_QMAX 256
/* phgmg__qm_altmin with a wide V2: the descent of phgmg__altmin_wide in the
   q modes U; writes V1 = U Q1 into red->V0 (V2 follows from its complement). */
PHGMG__PRIV phgmg_result phgmg__qm_altmin_wide(phgmg__rctx *c, const double *U, int q) {
  phgmg_reduced *red = c->red;
  const int N = red->N, m = red->m, p = red->p, ns = c->ns, nc = p * (p + 1) / 2;
  const size_t nar = (size_t)(ns + nc) * (nc + q) + (size_t)nc + 16 * (size_t)(q + p) * p + 4096;
  const size_t nw = (size_t)q * ns * 2 + (size_t)p * ns * 2 + (size_t)ns * nc + (size_t)ns * q + (size_t)nc * q +
                    (size_t)nc * ns + (size_t)q * p * 2 + (size_t)p * p + (size_t)p;
  double *blk, *S, *Q1, f0 = 0.0, f = 0.0, outside;
  int i, steps = 0;
  phgmg__awide w;
  phgmg__arena ar;
  phgmg_result rc;
  blk = phgmg__dalloc(c->alloc, nw + nar);
  if (!blk) return PHGMG_ERR_NOMEM;
  memset(&w, 0, sizeof w);
  S = blk; w.Z = S + (size_t)q * ns; w.Kt = w.Z + (size_t)p * ns; w.Rt = w.Kt + (size_t)ns * nc;
  w.T = w.Rt + (size_t)ns * q; w.E = w.T + (size_t)nc * q; w.Gam = w.E + (size_t)q * ns; w.L = w.Gam + (size_t)nc * ns;
  w.Pu = w.L + (size_t)p * ns; Q1 = w.Pu + (size_t)q * p; w.Pv = Q1 + (size_t)q * p; w.Psv = w.Pv + (size_t)p * p;
  ar.base = (unsigned char *)(blk + nw); ar.cap = nar * sizeof(double); ar.used = 0; ar.up = c->alloc;
  w.al.alloc = phgmg__arena_alloc; w.al.free = phgmg__arena_free; w.al.user = &ar;
  w.q = q; w.ns = ns; w.p = p; w.nc = nc; w.S = S;
  w.lam = c->o->select.lambda_mode != PHGMG_LAMBDA_FIXED ? 1e-9 : c->lambda;
  phgmg_gemm('T', 'N', q, ns, N, 1.0, U, N, c->Xa, N, 0.0, S, q);
  outside = PHGMG__MAX(phgmg__sumsq(N, ns, c->Xa, N) - phgmg__sumsq(q, ns, S, q), 0.0);
  for (i = 0; i < q * p; ++i) Q1[i] = (i % q) == (i / q) ? 1.0 : 0.0;
  rc = phgmg__altmin_wide(&w, Q1, &f0, &f, &steps, c->alloc);
  if (rc == PHGMG_OK) {
    c->inf.manifold_obj0 = f0 + outside;
    c->inf.manifold_obj = f + outside;
    c->inf.manifold_sweeps = steps;
    phgmg_gemm('N', 'N', N, p, q, 1.0, U, N, Q1, q, 0.0, red->V0 + (size_t)N * m, N);
  }
  phgmg__free(c->alloc, blk);
  return rc;
}

PHGMG__PRIV phgmg_result phgmg__qm_altmin(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int N = red->N, m = red->m, p = red->p, ns = c->ns, nc = p * (p + 1) / 2;
  const int navail = c->o->cache.pod_basis ? c->o->cache.pod_cols : PHGMG__MIN(N, ns) - 1;
  const int qmax = PHGMG__MIN(c->wide ? PHGMG__ALTMIN_QMAX : 2 * (p + red->rn), navail);
  double *U, *S, *blk, f = HUGE_VAL, f0, tot = 0.0, outside;
  int it, i, q = 0, k, rs, moved = 0;
  phgmg__altmin_ws w;
  phgmg__arena ar;
  size_t nar;
  phgmg_result rc;
  if (qmax < p + (c->wide ? 1 : red->rn)) return PHGMG_ERR_SIZE;
  U = phgmg__dalloc(c->alloc, (size_t)N * qmax);
  if (!U) return PHGMG_ERR_NOMEM;
  rc = phgmg__altmin_space(c, qmax, U, &q);
  rs = c->wide ? q - p : red->rn;   /* V2's width in the search */
  k = p + rs;
  if (rc == PHGMG_OK && (rs < 1 || q < k)) rc = PHGMG_ERR_SIZE;
  if (rc != PHGMG_OK) { phgmg__free(c->alloc, U); return rc; }
  if (c->wide) {
    rc = phgmg__qm_altmin_wide(c, U, q);
    phgmg__free(c->alloc, U);
    return rc;
  }
  /* arena: phgmg_lstsq's [K; sqrt(lam) I], [Y; 0] and tau, and room for the q x k SVDs */
  nar = (size_t)(ns + nc) * (nc + rs) + (size_t)nc + 16 * (size_t)(q + k) * k + 4096;
  blk = phgmg__dalloc(c->alloc, (size_t)q * ns * 2 + (size_t)q * k * 5 + (size_t)k * (k + 1) + (size_t)k * ns * 3 +
                                    (size_t)ns * (nc + rs) + (size_t)nc * rs + nar);
  if (!blk) { phgmg__free(c->alloc, U); return PHGMG_ERR_NOMEM; }
  memset(&w, 0, sizeof w);
  ar.base = (unsigned char *)(blk + (size_t)q * ns * 2 + (size_t)q * k * 5 + (size_t)k * (k + 1) + (size_t)k * ns * 3 +
                              (size_t)ns * (nc + rs) + (size_t)nc * rs);
  ar.cap = nar * sizeof(double); ar.used = 0; ar.up = c->alloc;
  w.al.alloc = phgmg__arena_alloc; w.al.free = phgmg__arena_free; w.al.user = &ar;
  S = blk; w.R = S + (size_t)q * ns; w.Q = w.R + (size_t)q * ns; w.Qn = w.Q + (size_t)q * k;
  w.Qb = w.Qn + (size_t)q * k; w.A = w.Qb + (size_t)q * k; w.U = w.A + (size_t)q * k; w.V = w.U + (size_t)q * k;
  w.sv = w.V + (size_t)k * k; w.W = w.sv + k; w.Wn = w.W + (size_t)k * ns; w.Wb = w.Wn + (size_t)k * ns;
  w.Kt = w.Wb + (size_t)k * ns; w.Yt = w.Kt + (size_t)ns * nc; w.T = w.Yt + (size_t)ns * rs;
  w.q = q; w.ns = ns; w.p = p; w.rn = rs; w.k = k; w.S = S;
  w.lam = c->o->select.lambda_mode != PHGMG_LAMBDA_FIXED ? 1e-9 : c->lambda;
  phgmg_gemm('T', 'N', q, ns, N, 1.0, U, N, c->Xa, N, 0.0, S, q);
  tot = phgmg__sumsq(N, ns, c->Xa, N) - phgmg__sumsq(q, ns, S, q);
  outside = PHGMG__MAX(tot, 0.0);                    /* what no Q in span U can represent */
  for (i = 0; i < q * k; ++i) w.Q[i] = (i % q) == (i / q) ? 1.0 : 0.0;
  rc = phgmg__altmin_eval(q, ns, p, rs, S, w.Q, w.lam, w.Kt, w.Yt, w.T, w.W, w.R, &f, &w.al);
  if (rc == PHGMG_OK) c->inf.manifold_obj0 = c->inf.manifold_obj = f + outside;
  for (it = 0; rc == PHGMG_OK && it < 100; ++it) {
    f0 = f;
    rc = phgmg__altmin_sweep(&w, &f, &moved);
    if (rc != PHGMG_OK || !moved) break;
    c->inf.manifold_sweeps = it + 1;
    c->inf.manifold_obj = f + outside;
    if (f > f0 * (1.0 - 1e-5)) break;
  }
  if (rc != PHGMG_ERR_NOMEM) rc = PHGMG_OK;   /* no fit or no unique step: the last Q (at worst the start) */
  if (rc == PHGMG_OK) {   /* V1 = U Q1, V2 = U Q2 (a wide V2 is built afterwards from V1's complement) */
    phgmg_gemm('N', 'N', N, p, q, 1.0, U, N, w.Q, q, 0.0, red->V0 + (size_t)N * m, N);
    if (!c->wide) phgmg_gemm('N', 'N', N, red->rn, q, 1.0, U, N, w.Q + (size_t)q * p, q, 0.0, red->V2, N);
  }
  phgmg__free(c->alloc, blk);
  phgmg__free(c->alloc, U);
  return rc;
}

/* The p(p+1)/2 distinct Kronecker features of the columns of Z2 (p x ns, ld
   ldz) as the rows of Kt (ns x nc, ld ldk): feature (a, j), a <= j, in the
   order of phgmg__qm_problem, scaled by sqrt 2 off the diagonal. */
PHGMG__PRIV void phgmg__qm_features(int p, int ns, const double *Z2, int ldz, double *Kt, int ldk) {
  const double s2 = sqrt(2.0);
  int i, a, j, cc;
  for (i = 0; i < ns; ++i) {
    const double *z = Z2 + (size_t)i * ldz;
    for (a = 0, cc = 0; a < p; ++a)
      for (j = a; j < p; ++j, ++cc) Kt[i + (size_t)cc * ldk] = (a == j ? 1.0 : s2) * z[a] * z[j];
  }
}

/* Wide V2 (opts.qm.rn = PHGMG_RN_WIDE; the default of the greedy and alternating
   minimization manifolds). V2 spans the whole residual Xres = (I - [B, V1]
   [B, V1]^+) X up to its numerical rank: kw orthonormal directions U (N x kw)
   with coordinates C = U^T Xres (kw x ns), given (the greedy's complement) or
   from the SVD of Xres (c->Xa on entry), modes above the rank floor. The
   ridge fit M = C K (K^T K + lam I)^{-1} (K: ns x nc features of x2 = V1^T x,
   nc = p(p+1)/2) lies in range(C K) for EVERY lam; when kw > nc, the thin QR
   C K = P R (P: kw x nc, untruncated, so range(P) contains range(C K)) and
   V2 = U P give the same phi for every lam with the online width
   rn = min(kw, nc). Sets red->V2 and red->rn. Cost: the SVD of Xres (N ns kw),
   C K (kw ns nc), U P (N kw nc). */
PHGMG__PRIV phgmg_result phgmg__qm_wide_v2(phgmg__rctx *c, const double *Ug, const double *Cg, int kg) {
  phgmg_reduced *red = c->red;
  const int N = red->N, m = red->m, p = red->p, ns = c->ns, nc = p * (p + 1) / 2;
  const int kmax = PHGMG__MIN(N, ns);
  double *U = NULL, *C = NULL, *W = NULL, *S = NULL, *Z2, *Kt, *A, *tau, *V2;
  const double *Uu = Ug, *Cu = Cg;
  int kw = kg, i, j, rn;
  phgmg_result rc = PHGMG_OK;
  if (!Ug) {
    U = phgmg__dalloc(c->alloc, (size_t)N * kmax + (size_t)ns * kmax + (size_t)kmax * ns + (size_t)kmax);
    if (!U) return PHGMG_ERR_NOMEM;
    W = U + (size_t)N * kmax; C = W + (size_t)ns * kmax; S = C + (size_t)kmax * ns;
    rc = phgmg_svd(N, ns, c->Xa, N, kmax, S, U, N, W, ns, &kw, NULL, c->alloc);
    while (rc == PHGMG_OK && kw > 0 && !(S[kw - 1] > c->rfloor)) --kw;
    for (j = 0; rc == PHGMG_OK && j < ns; ++j)
      for (i = 0; i < kw; ++i) C[i + (size_t)j * kw] = S[i] * W[j + (size_t)i * ns];
    Uu = U; Cu = C;
  }
  if (rc == PHGMG_OK && kw < 1) rc = PHGMG_ERR_SIZE;   /* nothing left for the quadratic term */
  if (rc != PHGMG_OK) { phgmg__free(c->alloc, U); return rc; }
  rn = PHGMG__MIN(kw, nc);
  Z2 = phgmg__dalloc(c->alloc, (size_t)p * ns + (size_t)ns * nc + (size_t)kw * nc + (size_t)nc);
  V2 = phgmg__red_d(red, (size_t)N * rn);
  if (!Z2 || !V2) { phgmg__free(c->alloc, U); phgmg__free(c->alloc, Z2); return PHGMG_ERR_NOMEM; }
  Kt = Z2 + (size_t)p * ns; A = Kt + (size_t)ns * nc; tau = A + (size_t)kw * nc;
  if (kw <= nc) {
    memcpy(V2, Uu, (size_t)N * kw * sizeof(double));
  } else {
    phgmg_gemm('T', 'N', p, ns, N, 1.0, red->V0 + (size_t)N * m, N, c->X, c->ldx, 0.0, Z2, p);
    phgmg__qm_features(p, ns, Z2, p, Kt, ns);
    phgmg_gemm('N', 'N', kw, nc, ns, 1.0, Cu, kw, Kt, ns, 0.0, A, kw);   /* C K */
    rc = phgmg_qr(kw, nc, A, kw, tau);
    if (rc == PHGMG_OK) {
      phgmg_qr_form_q(kw, nc, A, kw, tau, Kt);                          /* P (kw x nc) */
      phgmg_gemm('N', 'N', N, nc, kw, 1.0, Uu, N, A, kw, 0.0, V2, N);
    }
  }
  phgmg__free(c->alloc, Z2);
  phgmg__free(c->alloc, U);
  if (rc != PHGMG_OK) return rc;
  red->V2 = V2;
  red->rn = rn;
  return PHGMG_OK;
}

/* The greedy manifold with a wide V2 (phgmg__qm_greedy_wide): the state of
   the selection over the subsample (every st-th snapshot, nsub of them). */
typedef struct phgmg__gw {
  int q, nsub, L, nin;  /* modes, snapshots, augmented rows nsub + nc, features kept */
  const double *Cs;     /* q x nsub POD coordinates of the subsample            */
  double *G;            /* nsub x nsub Gram of the candidates not yet taken       */
  double *Qin;          /* L x nc: orthonormal basis of the kept augmented features */
  double *A, *GA, *t, *sv;
  double sl, trG, tin;  /* sqrt(lam), trace G, trace(Qin1^T G Qin1)              */
} phgmg__gw;

/* The j + 1 features that candidate k adds to the j selected modes sel --
   (k, sel_a) scaled by sqrt 2 and (k, k) -- as ridge-augmented columns
   [K_new; sqrt(lam) I] (L rows; rows nsub + nin + a), orthonormalised against
   Qin and among themselves (Gram-Schmidt, twice), into w->A. */
PHGMG__PRIV void phgmg__gw_columns(phgmg__gw *w, const int *sel, int j, int k) {
  const int q = w->q, nsub = w->nsub, L = w->L, nin = w->nin, lr = nsub + nin + j + 1;
  int a, b, i, pass;
  memset(w->A, 0, (size_t)L * (j + 1) * sizeof(double));
  for (a = 0; a <= j; ++a) {
    double *col = w->A + (size_t)a * L;
    const int o = a < j ? sel[a] : k;
    const double f = a < j ? sqrt(2.0) : 1.0;
    for (i = 0; i < nsub; ++i) col[i] = f * w->Cs[k + (size_t)i * q] * w->Cs[o + (size_t)i * q];
    col[nsub + nin + a] = w->sl;
  }
  for (pass = 0; pass < 2 && nin > 0; ++pass) {
    phgmg_gemm('T', 'N', nin, j + 1, nsub + nin, 1.0, w->Qin, L, w->A, L, 0.0, w->t, nin);
    phgmg_gemm('N', 'N', nsub + nin, j + 1, nin, -1.0, w->Qin, L, w->t, nin, 1.0, w->A, L);
  }
  for (a = 0; a <= j; ++a) {
    double *ca = w->A + (size_t)a * L, nrm;
    for (pass = 0; pass < 2; ++pass)
      for (b = 0; b < a; ++b) {
        const double *cb = w->A + (size_t)b * L, d = phgmg__dot(lr, cb, ca);
        for (i = 0; i < lr; ++i) ca[i] -= d * cb[i];
      }
    nrm = sqrt(phgmg__dot(lr, ca, ca));   /* >= sqrt(lam) > 0 in exact arithmetic */
    for (i = 0; i < lr; ++i) ca[i] = nrm > 0.0 ? ca[i] / nrm : 0.0;
  }
}

/* The ridge objective min_T ||R - K T||^2 + lam ||T||^2 over the other
   candidates R (every candidate but sel and k, as the Gram w->G - s s^T, s = the
   candidate's coordinates) with the features K of sel + k: with [K; sqrt(lam)
   I] = Q R, it is tr(R R^T) - ||Q1^T R||^2 (Q1: the first nsub rows), split
   into the kept features' part (Qin) and the new ones' (w->A). */
PHGMG__PRIV double phgmg__gw_error(phgmg__gw *w, const int *sel, int j, int k) {
  const int q = w->q, nsub = w->nsub, L = w->L, nin = w->nin;
  double e, ss, tq = 0.0, ps = 0.0;
  int i, a;
  phgmg__gw_columns(w, sel, j, k);
  for (i = 0; i < nsub; ++i) w->sv[i] = w->Cs[k + (size_t)i * q];
  ss = phgmg__dot(nsub, w->sv, w->sv);
  e = w->trG - ss - w->tin;
  if (nin > 0) {
    phgmg_gemv('T', nsub, nin, 1.0, w->Qin, L, w->sv, 0.0, w->t);
    e += phgmg__dot(nin, w->t, w->t);
  }
  phgmg_gemm('N', 'N', nsub, j + 1, nsub, 1.0, w->G, nsub, w->A, L, 0.0, w->GA, nsub);
  for (a = 0; a <= j; ++a) {
    const double *ca = w->A + (size_t)a * L, d = phgmg__dot(nsub, ca, w->sv);
    tq += phgmg__dot(nsub, ca, w->GA + (size_t)a * nsub);
    ps += d * d;
  }
  return e - tq + ps;
}

/* Keep candidate k: its features join Qin, its coordinates leave G. */
PHGMG__PRIV void phgmg__gw_take(phgmg__gw *w, const int *sel, int j, int k) {
  const int q = w->q, nsub = w->nsub, L = w->L;
  int i, a;
  phgmg__gw_columns(w, sel, j, k);
  memcpy(w->Qin + (size_t)w->nin * L, w->A, (size_t)L * (j + 1) * sizeof(double));
  w->nin += j + 1;
  for (i = 0; i < nsub; ++i) w->sv[i] = w->Cs[k + (size_t)i * q];
  w->trG -= phgmg__dot(nsub, w->sv, w->sv);
  phgmg_gemm('N', 'T', nsub, nsub, 1, -1.0, w->sv, nsub, w->sv, nsub, 1.0, w->G, nsub);
  phgmg_gemm('N', 'N', nsub, w->nin, nsub, 1.0, w->G, nsub, w->Qin, L, 0.0, w->GA, nsub);
  for (w->tin = 0.0, a = 0; a < w->nin; ++a) w->tin += phgmg__dot(nsub, w->Qin + (size_t)a * L, w->GA + (size_t)a * nsub);
}

/* opts.qm.manifold = 1 with a wide V2 (phgmg__qm_wide_v2) and qm.greedy_window > 0:
   V1 takes one POD mode of the adjusted snapshots at a time among the
   qw = p + qm.greedy_window leading ones, the one whose features (with those
   already taken) leave the smallest ridge objective (misfit + lam ||T||^2;
   phgmg__qm_greedy scores the misfit alone) over the other candidates not
   yet taken (after Schwerdtner & Peherstorfer 2024). One SVD of Xa up to its
   numerical rank q; each trial orthogonalises the j + 1 new feature columns
   against the kept ones (incremental QR of the ridge-augmented feature
   matrix) and needs one nsub x nsub x (j + 1) product: about qw p^2 (nsub^2
   + nsub p^2) / 2 flops in all. Writes V1 into red->V0; all q - p modes not
   taken and their coordinates stay in c->Uw, c->Cw for the wide V2. */
PHGMG__PRIV phgmg_result phgmg__qm_greedy_wide(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int N = red->N, m = red->m, p = red->p, ns = c->ns, nc = p * (p + 1) / 2, kmax = PHGMG__MIN(N, ns);
  const int st = (ns + 399) / 400, nsub = (ns + st - 1) / st, L = nsub + nc;
  double *U, *W, *S, *C, *Cs, *buf, best_err, e;
  int *sel, *used, q = 0, qw = 0, i, j, k, best, kc;
  phgmg__gw w;
  phgmg_result rc;
  U = phgmg__dalloc(c->alloc, (size_t)N * kmax + (size_t)ns * kmax + (size_t)kmax * ns + (size_t)kmax * nsub + kmax);
  buf = phgmg__dalloc(c->alloc, (size_t)nsub * nsub + (size_t)L * nc + (size_t)L * p + (size_t)nsub * nc + (size_t)nc * p + nsub);
  sel = phgmg__ialloc(c->alloc, (size_t)kmax + p);
  if (!U || !buf || !sel) { phgmg__free(c->alloc, U); phgmg__free(c->alloc, buf); phgmg__free(c->alloc, sel); return PHGMG_ERR_NOMEM; }
  W = U + (size_t)N * kmax; C = W + (size_t)ns * kmax; Cs = C + (size_t)kmax * ns; S = Cs + (size_t)kmax * nsub;
  used = sel + p;
  rc = phgmg_svd(N, ns, c->Xa, N, kmax, S, U, N, W, ns, &q, NULL, c->alloc);
  while (rc == PHGMG_OK && q > 0 && !(S[q - 1] > c->rfloor)) --q;
  if (rc == PHGMG_OK && q <= p) rc = PHGMG_ERR_SIZE;   /* r - m >= rank: nothing to choose or to lift */
  if (rc == PHGMG_OK) {
    for (j = 0; j < ns; ++j)
      for (i = 0; i < q; ++i) C[i + (size_t)j * q] = S[i] * W[j + (size_t)i * ns];
    for (j = 0; j < nsub; ++j) memcpy(Cs + (size_t)j * q, C + (size_t)j * st * q, (size_t)q * sizeof(double));
    memset(&w, 0, sizeof w);
    w.q = q; w.nsub = nsub; w.L = L; w.Cs = Cs;
    w.sl = sqrt(c->o->select.lambda_mode != PHGMG_LAMBDA_FIXED ? 1e-9 : (c->lambda > 0.0 ? c->lambda : 1e-12));
    w.G = buf; w.Qin = w.G + (size_t)nsub * nsub; w.A = w.Qin + (size_t)L * nc; w.GA = w.A + (size_t)L * p;
    w.t = w.GA + (size_t)nsub * nc; w.sv = w.t + (size_t)nc * p;
    qw = PHGMG__MIN(q, p + c->o->qm.greedy_window);
    phgmg_gemm('T', 'N', nsub, nsub, qw, 1.0, Cs, q, Cs, q, 0.0, w.G, nsub);   /* the candidates' Gram */
    for (i = 0; i < nsub; ++i) w.trG += w.G[i + (size_t)i * nsub];
    for (k = 0; k < q; ++k) used[k] = 0;
    for (j = 0; j < p; ++j) {
      best = -1; best_err = HUGE_VAL;
      for (k = 0; k < qw; ++k) {
        if (used[k]) continue;
        e = phgmg__gw_error(&w, sel, j, k);
        if (e < best_err) { best_err = e; best = k; }
      }
      if (best < 0) { rc = PHGMG_ERR_NANINF; break; }
      phgmg__gw_take(&w, sel, j, best);
      sel[j] = best;
      used[best] = 1;
    }
  }
  if (rc == PHGMG_OK) {   /* V1; the complement's modes and coordinates, compacted in place */
    for (j = 0; j < p; ++j) memcpy(red->V0 + (size_t)N * (m + j), U + (size_t)N * sel[j], (size_t)N * sizeof(double));
    for (k = 0, kc = 0; k < q; ++k) {
      if (used[k]) continue;
      if (kc != k) memmove(U + (size_t)N * kc, U + (size_t)N * k, (size_t)N * sizeof(double));
      for (j = 0; j < ns; ++j) W[kc + (size_t)j * (q - p)] = C[k + (size_t)j * q];
      ++kc;
    }
    c->Uw = U; c->Cw = W; c->kw = q - p;
    U = NULL;
  }
  phgmg__free(c->alloc, U);
  phgmg__free(c->alloc, buf);
  phgmg__free(c->alloc, sel);
  return rc;
}

/* The manifolds' constructions of V1 (and V2 where the construction makes
   it), described once: opts.qm.manifold indexes this table for GMG-QM. */
PHGMG__PRIV phgmg_result phgmg__v1_pod(phgmg__rctx *c) { (void)c; return PHGMG_OK; }   /* V1 = POD modes */
PHGMG__PRIV phgmg_result phgmg__v1_greedy(phgmg__rctx *c) {
  /* a wide V2 with a greedy_window: the incremental selection; else the classic one */
  return c->wide && c->o->qm.greedy_window > 0 ? phgmg__qm_greedy_wide(c) : phgmg__qm_greedy(c);
}
PHGMG__PRIV phgmg_result phgmg__v1_altmin(phgmg__rctx *c) {
  /* a wide V2 with a greedy_window: started from the greedy manifold */
  phgmg_result rc = c->wide && c->o->qm.greedy_window > 0 ? phgmg__qm_greedy_wide(c) : PHGMG_OK;
  if (rc == PHGMG_OK) rc = phgmg__qm_altmin(c);   /* V1 and V2 */
  if (rc == PHGMG_OK && c->Uw && c->inf.manifold_sweeps > 0) {   /* V1 moved: its complement anew */
    phgmg__free(c->alloc, c->Uw);
    c->Uw = c->Cw = NULL; c->kw = 0;
  }
  return rc;
}
typedef struct phgmg__manifold_row {
  phgmg_result (*v1)(phgmg__rctx *c);   /* V1 (run after the basis stage)                */
  int makes_v2;                         /* the construction leaves V2 too (unless wide)   */
} phgmg__manifold_row;
static const phgmg__manifold_row phgmg__manifolds[PHGMG_MANIFOLD_COUNT] = {
  {phgmg__v1_pod, 0},     /* POD: the paper's hierarchical manifold */
  {phgmg__v1_greedy, 0},  /* GREEDY                                  */
  {phgmg__v1_altmin, 1},  /* ALTMIN                                  */
};

/* Stage 2, manifold (QUADRATIC kind): V2 = POD of the residual of [B, V1]
   (paper 4.2.2; V1 greedy with opts.qm.manifold = 1), V1 and V2 by alternating
   minimization (opts.qm.manifold = 2), or the caller's; then GMG-QM fits M (eq. least_square_reg,
   lambda fixed or by validation); GMG_MANIFOLD takes the caller's eta. */
PHGMG__PRIV phgmg_result phgmg__stage_manifold(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int N = red->N, m = red->m, p = red->p, rn = red->rn, ns = c->ns;
  const phgmg__manifold_row *mf = red->method == PHGMG_METHOD_GMG_QM ? &phgmg__manifolds[c->o->qm.manifold] : NULL;
  phgmg_result rc = PHGMG_OK;
  int k = 0;
  if (red->kind != PHGMG_ROM_QUADRATIC) return PHGMG_OK;
  red->V2 = phgmg__red_d(red, (size_t)N * rn);
  if (!red->V2) return PHGMG_ERR_NOMEM;
  if (mf && (rc = mf->v1(c)) != PHGMG_OK) return rc;
  {
    double *tmp = phgmg__dalloc(c->alloc, (size_t)p * ns + (size_t)rn);
    if (!tmp) return PHGMG_ERR_NOMEM;
    if (c->sf != PHGMG__SF_GMG) phgmg__orth_remove(N, p, red->V0 + (size_t)N * m, ns, c->Xa, N, tmp);
    if (c->wide) {
      rc = phgmg__qm_wide_v2(c, c->Uw, c->Cw, c->kw);   /* the whole residual; sets rn */
      phgmg__free(c->alloc, c->Uw);
      c->Uw = c->Cw = NULL;
    } else if (mf && mf->makes_v2) {
      /* V2 from the construction */
    } else if (c->o->cache.pod_basis && c->o->qm.manifold == PHGMG_MANIFOLD_POD) {
      memcpy(red->V2, c->o->cache.pod_basis + (size_t)N * p, (size_t)N * rn * sizeof(double));
    } else if (c->v2ok && phgmg__v2_from_basis(c)) { /* the same SVD's next modes */
      memcpy(red->V2, c->V2h, (size_t)N * rn * sizeof(double));
    } else {
      rc = phgmg_pod(N, ns, c->Xa, N, rn, 0.0, red->V2, N, tmp, &k, c->alloc);
      if (rc == PHGMG_OK && (k < rn || !(tmp[rn - 1] > c->rfloor))) rc = PHGMG_ERR_SIZE;
    }
    phgmg__free(c->alloc, tmp);
  }
  if (rc != PHGMG_OK || red->method == PHGMG_METHOD_GMG_MANIFOLD) return rc;
  rc = phgmg__qm_problem(c);
  if (rc == PHGMG_OK && c->ng > 0) rc = phgmg__qm_lambda_auto(c);
  if (rc == PHGMG_OK) {
    const int nc = p * (p + 1) / 2;
    rc = phgmg__qm_fit(red, ns, c->Tq, c->Tq + (size_t)ns * nc, c->lambda, c->Tq + (size_t)ns * (nc + red->rn),
                       c->alloc);   /* red->rn: the wide V2 may have changed it */
    c->inf.lambda = c->lambda;
  }
  if (c->gsel < 0) { phgmg__free(c->alloc, c->Tq); c->Tq = NULL; } /* no refit without the grid */
  return rc;
}

/* rcond of E (n x n, ld n; overwritten by its LU). ip: 2n ints, work: 2n. */
PHGMG__PRIV double phgmg__rcond_inplace(int n, double *E, int *ip, double *work) {
  const double anorm = phgmg_norm1(n, n, E, n);
  if (phgmg_lu_factor(n, E, n, ip) != PHGMG_OK) return 0.0;
  return phgmg_lu_rcond(n, E, n, ip, anorm, work, ip + n);
}

/* The degeneracy check measures D^T G D with unit port columns: rows and
   columns a < m of E (r x r) scaled by 1 / ||B_a|| -- the same invertibility,
   but a condition independent of the units of B (B scaled by s while G
   scales by 1/s^2, as for states in other units, would otherwise move rcond
   by s^2 and fail a well-posed model). */
PHGMG__PRIV void phgmg__dgd_unit_ports(const phgmg_reduced *red, double *E) {
  const int r = red->r, m = red->m, N = red->N;
  int a, i;
  for (a = 0; a < m; ++a) {
    const double nb = phgmg_normf(N, 1, red->sys->B + (size_t)a * N, N), f = nb > 0.0 ? 1.0 / nb : 1.0;
    for (i = 0; i < r; ++i) { E[a + (size_t)i * r] *= f; E[i + (size_t)a * r] *= f; }
  }
}

/* Smallest rcond of D^T G D over the snapshots (QUADRATIC kind); with the
   automatic lambda, stops early at the first snapshot that would raise it.
   The snapshots' x2 = V1^T x_i come 64 at a time from one GEMM
   (or from the study's coordinates); E and its rcond per snapshot in one
   workspace. */
PHGMG__PRIV phgmg_result phgmg__dgd_rcond_snapshots(phgmg__rctx *c, double stop_below, double *rmin) {
  phgmg_reduced *red = c->red;
  const int p = red->p, rn = red->rn, r = red->r, nbmax = 64;
  double *Lp, *E, *tmp, *X2, *wk;
  int *ip, i, j0, ld2 = p;
  Lp = phgmg__dalloc(c->alloc, (size_t)rn * p + (size_t)r * r + (size_t)rn * r + (size_t)p * nbmax + 2 * (size_t)r);
  ip = phgmg__ialloc(c->alloc, 2 * (size_t)r);
  if (!Lp || !ip) { phgmg__free(c->alloc, Lp); phgmg__free(c->alloc, ip); return PHGMG_ERR_NOMEM; }
  E = Lp + (size_t)rn * p; tmp = E + (size_t)r * r; X2 = tmp + (size_t)rn * r; wk = X2 + (size_t)p * nbmax;
  for (j0 = 0; j0 < c->ns; j0 += nbmax) {
    const int nb = PHGMG__MIN(nbmax, c->ns - j0);
    const double *x2b = phgmg__snap_v1(c, j0, nb, X2, &ld2);
    for (i = 0; i < nb; ++i) {
      double rc_i;
      phgmg__eta_d(red, x2b + (size_t)i * ld2, NULL, Lp, NULL, red->rwork);
      phgmg__dgd_d(red, Lp, E, tmp);
      phgmg__dgd_unit_ports(red, E);
      rc_i = phgmg__rcond_inplace(r, E, ip, wk);
      if (rc_i < *rmin) *rmin = rc_i;
      if (!(rc_i >= stop_below)) { j0 = c->ns; break; }
    }
  }
  phgmg__free(c->alloc, Lp);
  phgmg__free(c->alloc, ip);
  return PHGMG_OK;
}

/* Non-degeneracy of D^T G D at x = 0 and (QUADRATIC) at every snapshot. With
   the automatic lambda, an M that (nearly) degenerates it (rcond below
   select.rcond times its value at x = 0) moves to the next larger grid
   lambda (M -> 0 as lambda grows, and D^T G D -> G00). */
PHGMG__PRIV double phgmg__dgd_rcond0(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const size_t rr = (size_t)red->r * red->r;
  double *E = phgmg__dalloc(c->alloc, rr), rc0;
  if (!E) return -1.0;
  memcpy(E, red->G00, rr * sizeof(double));
  phgmg__dgd_unit_ports(red, E);
  rc0 = phgmg__rcond_of(red->r, E, c->alloc);
  phgmg__free(c->alloc, E);
  return rc0;
}
PHGMG__PRIV phgmg_result phgmg__check_degeneracy(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const double rc0 = phgmg__dgd_rcond0(c);
  const double lrc = rc0 * c->o->select.rcond;
  const int can_raise = c->gsel >= 0 && rc0 >= c->degtol;
  phgmg_result rc;
  if (rc0 < 0.0) return PHGMG_ERR_NOMEM;
  c->inf.rcond_dgd = rc0;
  while (red->kind == PHGMG_ROM_QUADRATIC) {
    const int more = can_raise && c->gsel + 1 < c->ng;
    const int nc = red->p * (red->p + 1) / 2;
    rc = phgmg__dgd_rcond_snapshots(c, more ? PHGMG__MAX(c->degtol, lrc) : -1.0, &c->inf.rcond_dgd);
    if (rc != PHGMG_OK) return rc;
    if ((c->inf.rcond_dgd >= c->degtol && c->inf.rcond_dgd >= lrc) || !more) break;
    ++c->gsel;
    ++c->inf.lambda_raised;
    c->lambda = c->inf.lambda = c->lg[c->gsel];
    c->inf.lambda_cv_err = c->lg[c->ng + c->gsel];
    c->inf.rcond_dgd = rc0;
    rc = phgmg__qm_fit(red, c->ns, c->Tq, c->Tq + (size_t)c->ns * nc, c->lambda,
                       c->Tq + (size_t)c->ns * (nc + red->rn), c->alloc);
    if (rc != PHGMG_OK) return rc;
  }
  if (c->inf.rcond_dgd < c->degtol && can_raise && red->M) {
    /* automatic lambda: not even the grid's largest lambda (absolute, so
       small for states that are large in their units) keeps D^T G D
       regular -- the linear limit M = 0, regular at every state because
       G00 is (rc0 >= degtol) */
    memset(red->M, 0, (size_t)red->rn * red->p * red->p * sizeof(double));
    if (red->Ms) memset(red->Ms, 0, (size_t)red->rn * red->p * red->p * sizeof(double));
    c->gsel = -1;
    c->lambda = c->inf.lambda = HUGE_VAL;
    c->inf.lambda_cv_err = 1.0;
    c->inf.rcond_dgd = rc0;
  }
  return c->inf.rcond_dgd >= c->degtol ? PHGMG_OK : PHGMG_ERR_DEGENERATE;
}

/* ---- deployment: runs, validation by simulation, training envelope -------- */
PHGMG_DEF int phgmg_runs_columns(int nrun, const phgmg_run *runs) {
  long tot = 0;
  int k;
  if (nrun < 1 || !runs) return -1;
  for (k = 0; k < nrun; ++k) {
    if (runs[k].nsteps < 0 || !(runs[k].dt > 0.0) || runs[k].dt == HUGE_VAL || runs[k].t0 != runs[k].t0) return -1;
    tot += runs[k].nsteps + 1L;
    if (tot > 2147483647L) return -1;
  }
  return (int)tot;
}

PHGMG_DEF phgmg_result phgmg_simulate_inputs(const phgmg_ph_system *sys, int nrun, const phgmg_run *runs,
                                             const phgmg_gl3_opts *go, double *X, int ldx, double *Y, int *col,
                                             const phgmg_allocator *alloc) {
  double *z, *T = NULL, sdt = 0.0;
  int k, c0 = 0, nmax = 0, N;
  phgmg_gl3 *s = NULL; /* one stepper while dt stays: its factors serve every run */
  phgmg_result rc = PHGMG_OK;
  if (!sys || !runs || !X) return PHGMG_ERR_INVALID_ARG;
  if (phgmg_runs_columns(nrun, runs) < 0) return PHGMG_ERR_INVALID_ARG;
  N = sys->N;
  if (N < 1 || ldx < N) return PHGMG_ERR_SIZE;
  for (k = 0; k < nrun; ++k) nmax = PHGMG__MAX(nmax, runs[k].nsteps + 1);
  z = phgmg__dalloc(alloc, (size_t)N);
  if (z && ldx != N) T = phgmg__dalloc(alloc, (size_t)N * nmax);
  if (!z || (ldx != N && !T)) { phgmg__free(alloc, z); return PHGMG_ERR_NOMEM; }
  memset(z, 0, (size_t)N * sizeof(double));
  for (k = 0; k < nrun && rc == PHGMG_OK; ++k) {
    const phgmg_run *q = runs + k;
    double *dst = T ? T : X + (size_t)c0 * ldx;
    int j;
    if (col) col[k] = c0;
    if (!s || q->dt != sdt) {
      phgmg_gl3_destroy(s);
      s = NULL;
      rc = phgmg_gl3_create(&s, sys, q->dt, go, alloc);
      if (rc != PHGMG_OK) break;
      sdt = q->dt;
    }
    rc = phgmg__simulate_on(s, sys, q->x0 ? q->x0 : z, q->t0, q->dt, q->nsteps, q->u, q->user, dst,
                            Y ? Y + (size_t)c0 * sys->m : NULL, NULL, NULL, NULL, alloc);
    if (T)
      for (j = 0; j <= q->nsteps; ++j)
        memcpy(X + (size_t)(c0 + j) * ldx, T + (size_t)j * N, (size_t)N * sizeof(double));
    c0 += q->nsteps + 1;
  }
  if (col && rc == PHGMG_OK) col[nrun] = c0;
  phgmg_gl3_destroy(s);
  phgmg__free(alloc, T);
  phgmg__free(alloc, z);
  return rc;
}

/* XR (r x ns) = rho of the snapshots: from the study's coordinates on its
   bases (GMG: [RB^{-1} QB^T x; Ua_1..p^T Xa]; SP: Ainv^T Vg^T x), else
   phgmg__restrict_block. */
PHGMG__PRIV void phgmg__restrict_snapshots(const phgmg__rctx *c, double *XR) {
  const phgmg_reduced *red = c->red;
  const phgmg_study *st = c->st;
  const int r = red->r, m = red->m, ns = c->ns;
  int i, j, k;
  if (c->sf == PHGMG__SF_GMG) {
    for (k = 0; k < ns; ++k) {
      double *xr = XR + (size_t)k * r;
      memcpy(xr, st->CB + (size_t)k * m, (size_t)m * sizeof(double));
      for (i = m - 1; i >= 0; --i) {
        double sm = xr[i];
        for (j = i + 1; j < m; ++j) sm -= red->RB[i + j * m] * xr[j];
        xr[i] = sm / red->RB[i + i * m];
      }
      memcpy(xr + m, st->Ca + (size_t)k * st->ka, (size_t)(r - m) * sizeof(double));
    }
  } else if (c->sf == PHGMG__SF_SP1 || c->sf == PHGMG__SF_SP2) {
    const double *Cv = c->sf == PHGMG__SF_SP1 ? st->Cq : st->Cg;
    const int ld = c->sf == PHGMG__SF_SP1 ? st->kp : st->kg;
    phgmg_gemm('T', 'N', r, ns, r, 1.0, red->Ainv, r, Cv, ld, 0.0, XR, r);
  } else {
    phgmg__restrict_block(red, ns, c->Xf, c->ldxf, XR);
  }
}

/* phgmg_rom.q_max: 1.2 max_j ||M (x2_j kron x2_j)|| over the snapshots'
   reduced coordinates x2_j (the final M: run after the lambda validation). */
PHGMG__PRIV phgmg_result phgmg__q_envelope(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int r = red->r, m = red->m, rn = red->rn;
  double *xr, *q, qmax = 0.0;
  int j, i;
  red->qmax = phgmg__red_d(red, 1);
  xr = phgmg__dalloc(c->alloc, (size_t)r * c->ns + (size_t)rn);
  if (!red->qmax || !xr) { phgmg__free(c->alloc, xr); return PHGMG_ERR_NOMEM; }
  q = xr + (size_t)r * c->ns;
  phgmg__restrict_snapshots(c, xr);
  for (j = 0; j < c->ns; ++j) {
    double s2 = 0.0;
    phgmg__eta_d(red, xr + (size_t)j * r + m, q, NULL, NULL, red->rwork);
    for (i = 0; i < rn; ++i) s2 += q[i] * q[i];
    qmax = PHGMG__MAX(qmax, sqrt(s2));
  }
  red->qmax[0] = 1.2 * qmax;
  phgmg__free(c->alloc, xr);
  return phgmg__to_real(red, red->qmax, 1, &red->rom.q_max);
}

/* Training envelope of the reduced coordinates (phgmg_rom.env_lo/hi): the
   range of rho(x_j) over the snapshots, widened on each side by 10 % of its
   width plus 2 % of the largest width (a coordinate the training barely
   moves must not fire on the reduced model's own error). */
PHGMG__PRIV phgmg_result phgmg__stage_envelope(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int r = red->r;
  double *xr, big = 0.0;
  int j, a;
  phgmg_result rc;
  red->env = phgmg__red_d(red, 2 * (size_t)r);
  xr = phgmg__dalloc(c->alloc, (size_t)r * c->ns);
  if (!red->env || !xr) { phgmg__free(c->alloc, xr); return PHGMG_ERR_NOMEM; }
  phgmg__restrict_snapshots(c, xr);
  for (j = 0; j < c->ns; ++j) {
    const double *xj = xr + (size_t)j * r;
    for (a = 0; a < r; ++a) {
      if (j == 0 || xj[a] < red->env[a]) red->env[a] = xj[a];
      if (j == 0 || xj[a] > red->env[r + a]) red->env[r + a] = xj[a];
    }
  }
  for (a = 0; a < r; ++a) big = PHGMG__MAX(big, red->env[r + a] - red->env[a]);
  for (a = 0; a < r; ++a) {
    const double w = 0.1 * (red->env[r + a] - red->env[a]) + 0.02 * big;
    red->env[a] -= w;
    red->env[r + a] += w;
  }
  phgmg__free(c->alloc, xr);
  rc = phgmg__to_real(red, red->env, (size_t)r, &red->rom.env_lo);
  if (rc == PHGMG_OK) rc = phgmg__to_real(red, red->env + r, (size_t)r, &red->rom.env_hi);
  if (rc == PHGMG_OK && red->kind == PHGMG_ROM_QUADRATIC && red->M && !red->eta) rc = phgmg__q_envelope(c);
  return rc;
}

/* Probe inputs of the lambda validation: a constant at `level` (mode 0),
   the run's input played 1.5x faster (mode 1), a square wave level *
   sign(u(t)) (mode 2). */
typedef struct phgmg__probe {
  const phgmg_run *run;
  const double *level;
  int mode, m;
} phgmg__probe;
PHGMG__PRIV void phgmg__probe_u(double t, double *u, void *user) {
  const phgmg__probe *p = PHGMG__CAST(const phgmg__probe *, user);
  int a;
  if (p->mode == 0) {
    for (a = 0; a < p->m; ++a) u[a] = p->level[a];
  } else if (p->mode == 2 && p->run->u) {   /* square wave: level * sign(u(t)) */
    p->run->u(t, u, p->run->user);
    for (a = 0; a < p->m; ++a) u[a] = u[a] > 0.0 ? p->level[a] : (u[a] < 0.0 ? -p->level[a] : 0.0);
  } else if (p->mode == 1 && p->run->u) {
    p->run->u(p->run->t0 + 1.5 * (t - p->run->t0), u, p->run->user);
  } else {
    for (a = 0; a < p->m; ++a) u[a] = 0.0;
  }
}

/* The validation set: the training runs (reference outputs from the
   snapshots) and the two probe runs (reference outputs from the full model). */
typedef struct phgmg__vset {
  int nv, nmax;
  phgmg_input_fn u[PHGMG__NVAL_MAX];
  void *user[PHGMG__NVAL_MAX];
  const double *x0[PHGMG__NVAL_MAX];
  double t0[PHGMG__NVAL_MAX], dt[PHGMG__NVAL_MAX];
  int nsteps[PHGMG__NVAL_MAX];
  double *Yref[PHGMG__NVAL_MAX];
  double base[PHGMG__NVAL_MAX], ey[PHGMG__NVAL_MAX];
  phgmg__probe probe[3];
  double *buf;             /* every Yref, the level, zeros (x0), Yr, xr0 */
  double *Yr, *xr0;
  int rep[PHGMG__NVAL_MAX];   /* the run simulated for run k (itself, or an identical one) */
  int order[PHGMG__NVAL_MAX]; /* evaluation order: probes first (they fail first) */
} phgmg__vset;

/* Do validation runs j and k drive the reduced model identically (same x0,
   t0, dt, steps, and bit-identical inputs at every stage time, as
   phgmg_reduced_simulate samples them)? ub: 2m doubles. */
PHGMG__PRIV int phgmg__vrun_same(const phgmg__rctx *c, const phgmg__vset *v, int j, int k, double *ub) {
  const int N = c->sys->N, m = c->sys->m;
  const double s15 = sqrt(15.0) / 10.0, cs[3] = {0.5 - s15, 0.5, 0.5 + s15};
  int n, i, a;
  if (v->t0[j] != v->t0[k] || v->dt[j] != v->dt[k] || v->nsteps[j] != v->nsteps[k]) return 0;
  if (v->x0[j] != v->x0[k] && memcmp(v->x0[j], v->x0[k], (size_t)N * sizeof(double)) != 0) return 0;
  if (v->u[j] == v->u[k] && v->user[j] == v->user[k]) return 1;
  for (n = 0; n < v->nsteps[j]; ++n) {
    const double t = v->t0[j] + n * v->dt[j];
    for (i = 0; i < 3; ++i) {
      for (a = 0; a < 2 * m; ++a) ub[a] = 0.0;
      if (v->u[j]) v->u[j](t + cs[i] * v->dt[j], ub, v->user[j]);
      if (v->u[k]) v->u[k](t + cs[i] * v->dt[j], ub + m, v->user[k]);
      if (memcmp(ub, ub + m, (size_t)m * sizeof(double)) != 0) return 0;
    }
  }
  return 1;
}

/* Evaluation order (probes, then the training runs) and, for each run, the
   first run in that order that is identical to it (simulated once). */
PHGMG__PRIV phgmg_result phgmg__vset_dedupe(const phgmg__rctx *c, phgmg__vset *v) {
  const int nrun = c->o->nrun;
  double *ub = phgmg__dalloc(c->alloc, 2 * (size_t)c->sys->m);
  int i, j, n = 0;
  if (!ub) return PHGMG_ERR_NOMEM;
  for (i = nrun; i < v->nv; ++i) v->order[n++] = i;
  for (i = 0; i < nrun && i < v->nv; ++i) v->order[n++] = i;
  for (i = 0; i < v->nv; ++i) {
    const int k = v->order[i];
    v->rep[k] = k;
    for (j = 0; j < i; ++j)
      if (v->rep[v->order[j]] == v->order[j] && phgmg__vrun_same(c, v, v->order[j], k, ub)) {
        v->rep[k] = v->order[j];
        break;
      }
  }
  phgmg__free(c->alloc, ub);
  return PHGMG_OK;
}

/* A study's cache of the probe runs' reference outputs (v->Yref of runs
   nrun..nrun+2, v->nv) for one runs[0] and Newton setting. store = 0: fill
   v from the cache if it matches (returns 1); store = 1: keep v's. */
PHGMG__PRIV int phgmg__study_probes(phgmg__rctx *c, phgmg__vset *v, const double *level, const double *zero,
                                    size_t off, const phgmg_gl3_opts *go, int store) {
  phgmg_study *st = c->st;
  const phgmg_run *r0 = c->o->runs;
  const int N = c->sys->N, m = c->sys->m, nrun = c->o->nrun;
  const double *x0 = r0->x0 ? r0->x0 : zero;
  const size_t ny = (size_t)m * (r0->nsteps + 1);
  int k;
  if (!st) return 0;
  if (!store) {
    if (!st->phave || st->pu != r0->u || st->puser != r0->user || st->pt0 != r0->t0 || st->pdt != r0->dt ||
        st->pn != r0->nsteps || st->ptol != go->tol || st->pit != go->max_iter ||
        memcmp(st->px0, x0, (size_t)N * sizeof(double)) != 0)
      return 0;
    v->nv = st->pnv;
    for (k = nrun; k < nrun + 3; ++k) {
      phgmg__probe *p = v->probe + (k - nrun);
      p->run = r0; p->level = level; p->mode = k - nrun; p->m = m;
      v->u[k] = phgmg__probe_u; v->user[k] = p; v->x0[k] = x0;
      v->t0[k] = r0->t0; v->dt[k] = r0->dt; v->nsteps[k] = r0->nsteps;
      v->Yref[k] = v->buf + off + (size_t)(k - nrun) * ny;
      if (k < v->nv) memcpy(v->Yref[k], st->Yp + (size_t)(k - nrun) * ny, ny * sizeof(double));
    }
    return 1;
  }
  {
    const phgmg_allocator *sa = st->use_alloc ? &st->alloc : NULL;
    phgmg__free(sa, st->Yp);
    st->phave = 0;
    st->Yp = phgmg__dalloc(sa, 3 * ny + (size_t)N);
    if (!st->Yp) return 0;
    st->px0 = st->Yp + 3 * ny;
    memcpy(st->px0, x0, (size_t)N * sizeof(double));
    for (k = nrun; k < v->nv; ++k) memcpy(st->Yp + (size_t)(k - nrun) * ny, v->Yref[k], ny * sizeof(double));
    st->pnv = v->nv; st->pu = r0->u; st->puser = r0->user; st->pt0 = r0->t0; st->pdt = r0->dt; st->pn = r0->nsteps;
    st->ptol = go->tol; st->pit = go->max_iter; st->phave = 1;
  }
  return 1;
}

/* opts.progress, when set (the library never prints). */
PHGMG__PRIV void phgmg__progress(const phgmg_reduce_opts *o, const char *phase) {
  if (o->progress) o->progress(phase, o->progress_user);
}

PHGMG__PRIV phgmg_result phgmg__vset_build(phgmg__rctx *c, phgmg__vset *v) {
  const phgmg_ph_system *sys = c->sys;
  const phgmg_run *run = c->o->runs;
  const int N = sys->N, m = sys->m, nrun = c->o->nrun;
  size_t tot = 0, off;
  double *level, *zero, *g;
  int k, j, a;
  phgmg_gl3_opts go;
  v->nv = nrun + 3;
  v->nmax = 0;
  for (k = 0; k < nrun; ++k) { tot += (size_t)m * (run[k].nsteps + 1); v->nmax = PHGMG__MAX(v->nmax, run[k].nsteps + 1); }
  tot += 3 * (size_t)m * (run[0].nsteps + 1);
  v->buf = phgmg__dalloc(c->alloc, tot + (size_t)m + 2 * (size_t)N + (size_t)m * v->nmax + (size_t)c->red->r);
  if (!v->buf) return PHGMG_ERR_NOMEM;
  level = v->buf + tot; zero = level + m; g = zero + N; v->Yr = g + N; v->xr0 = v->Yr + (size_t)m * v->nmax;
  memset(zero, 0, (size_t)N * sizeof(double));
  if (c->st && !c->st->Yt) {   /* a study keeps the snapshots' outputs */
    const phgmg_allocator *sa = c->st->use_alloc ? &c->st->alloc : NULL;
    c->st->Yt = phgmg__dalloc(sa, (size_t)m * c->ns);
    for (j = 0; c->st->Yt && j < c->ns; ++j) {
      phgmg_ph_gradient(sys, c->Xf + (size_t)j * c->ldxf, g);
      phgmg_gemv('T', N, m, 1.0, sys->B, N, g, 0.0, c->st->Yt + (size_t)j * m);
    }
  }
  for (k = 0, off = 0; k < nrun; ++k) {   /* training runs: y = B^T grad H(x_j) */
    v->u[k] = run[k].u; v->user[k] = run[k].user; v->x0[k] = c->Xf + (size_t)c->runcol[k] * c->ldxf;
    v->t0[k] = run[k].t0; v->dt[k] = run[k].dt; v->nsteps[k] = run[k].nsteps; v->Yref[k] = v->buf + off;
    if (c->st && c->st->Yt) {
      memcpy(v->Yref[k], c->st->Yt + (size_t)c->runcol[k] * m, (size_t)m * (run[k].nsteps + 1) * sizeof(double));
    } else {
      for (j = 0; j <= run[k].nsteps; ++j) {
        phgmg_ph_gradient(sys, c->Xf + (size_t)(c->runcol[k] + j) * c->ldxf, g);
        phgmg_gemv('T', N, m, 1.0, sys->B, N, g, 0.0, v->Yref[k] + (size_t)j * m);
      }
    }
    off += (size_t)m * (run[k].nsteps + 1);
  }
  for (a = 0; a < m; ++a) {   /* RMS of runs[0].u per port at the step times */
    double s2 = 0.0;
    for (j = 0; j <= run[0].nsteps; ++j) {
      if (run[0].u) run[0].u(run[0].t0 + j * run[0].dt, g, run[0].user);
      else g[a] = 0.0;
      s2 += g[a] * g[a];
    }
    level[a] = sqrt(s2 / (run[0].nsteps + 1));
  }
  memset(&go, 0, sizeof go);
  go.tol = c->o->select.newton_tol > 0.0 ? c->o->select.newton_tol : 1e-10;
  go.max_iter = c->o->select.newton_iter;
  if (c->o->select.train_only) { v->nv = nrun; return phgmg__vset_dedupe(c, v); }
  if (phgmg__study_probes(c, v, level, zero, off, &go, 0)) return phgmg__vset_dedupe(c, v);
  {
    phgmg_gl3 *s = NULL; /* one stepper (and its factors) for the three probes */
    phgmg_result rc = phgmg_gl3_create(&s, sys, run[0].dt, &go, c->alloc);
    if (rc == PHGMG_ERR_NOMEM) return rc;
    if (rc != PHGMG_OK) v->nv = nrun;   /* the full model itself fails: no probe */
    for (k = nrun; k < v->nv; ++k) {
      phgmg__probe *p = v->probe + (k - nrun);
      p->run = run; p->level = level; p->mode = k - nrun; p->m = m;
      v->u[k] = phgmg__probe_u; v->user[k] = p; v->x0[k] = run[0].x0 ? run[0].x0 : zero;
      v->t0[k] = run[0].t0; v->dt[k] = run[0].dt; v->nsteps[k] = run[0].nsteps; v->Yref[k] = v->buf + off;
      off += (size_t)m * (run[0].nsteps + 1);
      phgmg__progress(c->o, "lambda: full-model probe run");
      rc = phgmg__simulate_on(s, sys, v->x0[k], v->t0[k], v->dt[k], v->nsteps[k], v->u[k], v->user[k], NULL,
                              v->Yref[k], NULL, NULL, NULL, c->alloc);
      if (rc == PHGMG_ERR_NOMEM) { phgmg_gl3_destroy(s); return rc; }
      if (rc != PHGMG_OK) { v->nv = k; break; }   /* the full model itself fails: no probe */
    }
    phgmg_gl3_destroy(s);
  }
  phgmg__study_probes(c, v, level, zero, 0, &go, 1);
  return phgmg__vset_dedupe(c, v);
}

/* Simulate the current reduced model on every validation run: v->ey, and
   *ok = 0 if a run fails or needs more than 4 Newton iterations per step.
   Identical runs (v->rep) are simulated once. With tolr > 0 (a candidate,
   not the linear limit), the evaluation stops at the first run that makes
   the candidate inadmissible (*ok = 0, or an e_y ratio to v->base above
   tolr): the remaining e_y are not needed (left HUGE_VAL). */
PHGMG__PRIV phgmg_result phgmg__vset_eval(phgmg__rctx *c, phgmg__vset *v, int *ok, double tolr) {
  const int m = c->sys->m;
  const double tol = c->o->select.newton_tol;   /* 0: the stepper's default (1e-10 double, 1e-5 float) */
  const int it = c->o->select.newton_iter;
  int i, k, j;
  *ok = 1;
  for (k = 0; k < v->nv; ++k) v->ey[k] = HUGE_VAL;
  for (i = 0; i < v->nv; ++i) {
    phgmg_rom_stats st;
    phgmg_result rc;
    k = v->order[i];
    if (v->rep[k] != k) continue;
    memset(&st, 0, sizeof st);
    phgmg_reduced_restrict(c->red, v->x0[k], v->xr0);
    rc = phgmg_reduced_simulate(c->red, v->xr0, v->t0[k], v->dt[k], v->nsteps[k], v->u[k], v->user[k], tol, it,
                                NULL, v->Yr, NULL, &st, c->alloc);
    if (rc == PHGMG_ERR_NOMEM) return rc;
    for (j = 0; j < v->nv; ++j) {
      if (v->rep[j] != k) continue;
      v->ey[j] = rc == PHGMG_OK ? phgmg_rel_error(m, v->nsteps[j] + 1, v->Yref[j], m, v->Yr, m) : HUGE_VAL;
      if (rc != PHGMG_OK || st.newton_iters > 4 * st.steps || !(v->ey[j] < HUGE_VAL)) *ok = 0;
      if (tolr > 0.0 && *ok && (v->ey[j] + 1e-14) / (v->base[j] + 1e-14) > tolr) *ok = -1;
    }
    if (tolr > 0.0 && *ok != 1) { *ok = *ok < 0; break; }
  }
  return PHGMG_OK;
}

/* M at grid point g (g < 0: M = 0, the linear limit), in double and in the
   online model's own copy ms. */
PHGMG__PRIV phgmg_result phgmg__qm_set(phgmg__rctx *c, int g, phgmg_real *ms) {
  phgmg_reduced *red = c->red;
  const int p = red->p, rn = red->rn, nc = p * (p + 1) / 2;
  const size_t n = (size_t)rn * p * p;
  size_t i;
  if (g < 0) {
    memset(red->M, 0, n * sizeof(double));
    memset(red->Ms, 0, n * sizeof(double));
  } else {
    phgmg_result rc = phgmg__qm_fit(red, c->ns, c->Tq, c->Tq + (size_t)c->ns * nc, c->lg[g],
                                    c->Tq + (size_t)c->ns * (nc + rn), c->alloc);
    if (rc != PHGMG_OK) return rc;
  }
  for (i = 0; i < n; ++i) ms[i] = (phgmg_real)red->Ms[i];
  return PHGMG_OK;
}

/* The validation reference of an altmin manifold (PHGMG_LAMBDA_VALIDATED): its own
   linear limit M = 0 is not GMG-POD (V1 is not the POD basis), so GMG-POD
   itself (phgmg_reduce with the same options, method GMG_POD) is simulated on
   the validation runs too and the reference becomes the smaller of the two
   errors per run: a kept lambda then also beats GMG-POD. If the altmin
   linear limit (lim_ok: it simulates) is itself not within tolr of GMG-POD on
   every run, c->fallback_pod = 1: without an admissible lambda the reduction
   is redone with the hierarchical POD manifold. */
PHGMG__PRIV phgmg_result phgmg__altmin_reference(phgmg__rctx *c, phgmg__vset *v, int lim_ok, double tolr) {
  phgmg_reduce_opts o = *c->o;
  phgmg_reduced *pod = NULL, *keep = c->red;
  int k, ok = 0;
  phgmg_result rc;
  o.method = PHGMG_METHOD_GMG_POD; o.select.lambda_mode = PHGMG_LAMBDA_FIXED; o.qm.manifold = PHGMG_MANIFOLD_POD;
  o.nrun = 0; o.runs = NULL;
  o.dt = 0.0;
  rc = phgmg_reduce(&pod, c->sys, c->Xf, c->ldxf, c->ns, &o, NULL, c->alloc);
  if (rc == PHGMG_ERR_NOMEM) return rc;
  if (rc != PHGMG_OK) return PHGMG_OK;   /* no GMG-POD to compare with: the linear limit alone */
  c->red = pod;
  rc = phgmg__vset_eval(c, v, &ok, 0.0);   /* every run: the reference */
  c->red = keep;
  phgmg_reduced_destroy(pod);
  if (rc != PHGMG_OK || !ok) return rc;
  for (k = 0; k < v->nv; ++k) {
    if (!lim_ok || v->base[k] > tolr * v->ey[k] + 1e-14) c->fallback_pod = 1;
    v->base[k] = PHGMG__MIN(v->base[k], v->ey[k]);
  }
  return PHGMG_OK;
}

/* PHGMG_LAMBDA_VALIDATED (after publish): validation by simulation, see the
   manual 4.2. Candidates from select.lambda_max down, one
   per decade, to the regression optimum; stops after two inadmissible
   candidates in a row (the error grows as lambda falls). */
PHGMG__PRIV phgmg_result phgmg__stage_lambda_validate(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const phgmg_reduce_opts *o = c->o;
  const int pd = o->select.per_decade;
  const double tolr = o->select.tolerance;
  const size_t n = (size_t)red->rn * red->p * red->p;
  phgmg__vset *v;
  phgmg_real *ms;
  double best_score = 0.0, best_ratio = 1.0, cand_score[64], cand_worst[64];
  int best = -1, g, bad = 0, ok, k, ncand = 0, cand_g[64], cand_ok[64];
  phgmg_result rc;
  if (red->method != PHGMG_METHOD_GMG_QM || o->select.lambda_mode != PHGMG_LAMBDA_VALIDATED || c->gsel < 0) return PHGMG_OK;
  ms = PHGMG__CAST(phgmg_real *, phgmg__red_alloc(red, (n ? n : 1) * sizeof(phgmg_real)));
  if (!ms) return PHGMG_ERR_NOMEM;
  red->rom.Ms = ms;
  if (o->nrun < 1) {   /* nothing to simulate: the linear limit */
    c->inf.lambda = c->lambda = HUGE_VAL;
    return phgmg__qm_set(c, -1, ms);
  }
  v = PHGMG__CAST(phgmg__vset *, phgmg__alloc(c->alloc, sizeof(phgmg__vset)));
  if (!v) return PHGMG_ERR_NOMEM;
  memset(v, 0, sizeof *v);
  phgmg__progress(o, "lambda: validation runs");
  rc = phgmg__vset_build(c, v);
  if (rc == PHGMG_OK) rc = phgmg__qm_set(c, -1, ms);
  if (rc == PHGMG_OK) rc = phgmg__vset_eval(c, v, &ok, 0.0);
  for (k = 0; k < v->nv && rc == PHGMG_OK; ++k) v->base[k] = v->ey[k] < HUGE_VAL ? v->ey[k] : 1.0;
  if (rc == PHGMG_OK && o->qm.manifold == PHGMG_MANIFOLD_ALTMIN) rc = phgmg__altmin_reference(c, v, ok, tolr);
  /* training runs alone: up from the regression optimum, the first admissible */
  for (g = c->gsel; rc == PHGMG_OK && o->select.train_only && g < c->ng; g += pd) {
    double worst = 0.0;
    phgmg__progress(o, "lambda: candidate");
    rc = phgmg__qm_set(c, g, ms);
    if (rc == PHGMG_OK) rc = phgmg__vset_eval(c, v, &ok, tolr);
    if (rc != PHGMG_OK) break;
    c->inf.lambda_candidates++;
    for (k = 0; k < v->nv && ok; ++k) worst = PHGMG__MAX(worst, (v->ey[k] + 1e-14) / (v->base[k] + 1e-14));
    if (ok && worst <= tolr) { best = g; best_ratio = worst; break; }
  }
  for (g = c->ng - 1; rc == PHGMG_OK && !o->select.train_only && g >= c->gsel;
       g = (g - pd >= c->gsel || g == c->gsel) ? g - pd : c->gsel) {
    double score = 0.0, worst = 0.0;
    phgmg__progress(o, "lambda: candidate");
    rc = phgmg__qm_set(c, g, ms);
    if (rc == PHGMG_OK) rc = phgmg__vset_eval(c, v, &ok, tolr);
    if (rc != PHGMG_OK) break;
    c->inf.lambda_candidates++;
    for (k = 0; k < v->nv && ok; ++k) {
      const double ratio = (v->ey[k] + 1e-14) / (v->base[k] + 1e-14);
      score += log(ratio);
      worst = PHGMG__MAX(worst, ratio);
    }
    ok = ok && worst <= tolr;
    if (ok && score < best_score) { best = g; best_score = score; best_ratio = worst; }
    if (ncand < 64) { cand_g[ncand] = g; cand_ok[ncand] = ok; cand_score[ncand] = score; cand_worst[ncand++] = worst; }
    bad = ok ? 0 : bad + 1;
    if (bad >= 2 || g == c->gsel) break;
  }
  /* the largest admissible lambda with at least half the best gain (a
     safety margin towards the linear limit) */
  for (k = 0; k < ncand && best >= 0 && !o->select.train_only; ++k)
    if (cand_ok[k] && cand_score[k] <= 0.5 * best_score) {
      best = cand_g[k]; best_ratio = cand_worst[k];
      break;
    }
  if (rc == PHGMG_OK && best < 0 && c->fallback_pod) rc = PHGMG_OK;   /* redone with manifold = POD */
  else c->fallback_pod = 0;
  if (rc == PHGMG_OK) rc = phgmg__qm_set(c, best, ms);
  if (rc == PHGMG_OK) {
    c->gsel = best;
    c->inf.lambda = c->lambda = best < 0 ? HUGE_VAL : c->lg[best];
    c->inf.lambda_cv_err = best < 0 ? 1.0 : c->lg[c->ng + best];
    c->inf.lambda_val_ratio = best_ratio;
  }
  phgmg__free(c->alloc, v->buf);
  phgmg__free(c->alloc, v);
  return rc;
}

/* Stage 3a, GMG blocks (paper 4.2): G = (J - R)^{-1} through a factorization,
   G00 = V0^T G V0 (and the V2 blocks), Bh = [I; 0], the non-degeneracy
   check, and K = G00^{-1} for the linear map. */
/* B (nr x ncol, ld nr) = A(i0 : i0+nr, j0 : j0+ncol) (A: ld lda). */
PHGMG__PRIV void phgmg__subblock(int nr, int ncol, const double *A, int lda, int i0, int j0, double *B) {
  int i, j;
  for (j = 0; j < ncol; ++j)
    for (i = 0; i < nr; ++i) B[i + (size_t)j * nr] = A[(i0 + i) + (size_t)(j0 + j) * lda];
}

/* The study's G-blocks: [B, V1, V2] are the first r + rn columns of [B, Ua]. */
PHGMG__PRIV phgmg_result phgmg__study_gmg_blocks(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int r = red->r, rn = red->rn, nf = red->m + c->st->ka;
  phgmg__subblock(r, r, c->st->Gf, nf, 0, 0, red->G00);
  if (rn) {
    phgmg__subblock(r, rn, c->st->Gf, nf, 0, r, red->G01);
    phgmg__subblock(rn, r, c->st->Gf, nf, r, 0, red->G10);
    phgmg__subblock(rn, rn, c->st->Gf, nf, r, r, red->G11);
  }
  return PHGMG_OK;
}

/* >>dampers (reduction, manual 1.7). The reduced dampers of the co-state test
   basis Wz (N x r): Cd(:, k) = Wz^T c_k = Wz(i_k, :) - Wz(j_k, :). GMG
   (add_lin = 1): K, built from G = (J - R - L)^{-1}, becomes Wz^T (J - R) Wz
   = K + sum_k rho_k'(0) Cd_k Cd_k^T. Then, with opts.hyper.on, the dampers are
   hyper-reduced by ECSW (weights >= 0) on the training forces
   rho_k(c_k^T z(x_j)). */
PHGMG__PRIV phgmg_result phgmg__dampers_hyper(phgmg__rctx *c);
PHGMG__PRIV phgmg_result phgmg__stage_dampers(phgmg__rctx *c, const double *Wz, int add_lin) {
  phgmg_reduced *red = c->red;
  const phgmg_ph_system *sys = c->sys;
  const int N = red->N, r = red->r, nd = sys->ndamp;
  int k, a, b;
  red->ndamp = nd;
  red->Cd = phgmg__red_d(red, (size_t)r * nd);
  red->dw = phgmg__red_d(red, (size_t)nd);
  red->dterm = PHGMG__CAST(int *, phgmg__red_alloc(red, (size_t)nd * sizeof(int)));
  if (!red->Cd || !red->dw || !red->dterm) return PHGMG_ERR_NOMEM;
  for (k = 0; k < nd; ++k) {
    const int i = sys->damp_i[k], j = phgmg__damp_j(sys, k);
    double *ck = red->Cd + (size_t)k * r, d[2];
    for (a = 0; a < r; ++a) ck[a] = Wz[i + (size_t)a * N] - (j >= 0 ? Wz[j + (size_t)a * N] : 0.0);
    red->dw[k] = 1.0;
    red->dterm[k] = k;
    if (!add_lin) continue;
    phgmg__damp_law(sys, k, 0.0, d);
    for (b = 0; b < r; ++b)
      for (a = 0; a < r; ++a) red->K[a + (size_t)b * r] += d[1] * ck[a] * ck[b];
  }
  if (!phgmg__all_finite(red->Cd, (size_t)r * nd)) return PHGMG_ERR_NANINF;
  return c->o->hyper.on ? phgmg__dampers_hyper(c) : PHGMG_OK;
}

PHGMG__PRIV int phgmg__has_feed(const phgmg_ph_system *sys) { return sys->P || sys->S || sys->Nskew; }

/* Feedthrough (manual 1.6): PD = [W_z^T P; S + N]. */
PHGMG__PRIV phgmg_result phgmg__stage_feedthrough(phgmg__rctx *c, const double *Wz) {
  phgmg_reduced *red = c->red;
  const phgmg_ph_system *sys = c->sys;
  const int N = red->N, r = red->r, m = red->m;
  int a, b;
  red->PD = phgmg__red_d(red, (size_t)(r + m) * m);
  if (!red->PD) return PHGMG_ERR_NOMEM;
  if (sys->P) {
    double *t = phgmg__dalloc(c->alloc, (size_t)r * m);
    if (!t) return PHGMG_ERR_NOMEM;
    phgmg__atb(N, r, m, Wz, sys->P, t);
    memcpy(red->PD, t, (size_t)r * m * sizeof(double));
    phgmg__free(c->alloc, t);
  }
  for (b = 0; b < m; ++b)
    for (a = 0; a < m; ++a)
      red->PD[(size_t)r * m + a + (size_t)b * m] = (sys->S ? sys->S[a + (size_t)b * m] : 0.0) +
                                                   (sys->Nskew ? sys->Nskew[a + (size_t)b * m] : 0.0);
  return phgmg__all_finite(red->PD, (size_t)(r + m) * m) ? PHGMG_OK : PHGMG_ERR_NANINF;
}

/* GMG: Wz = G^T (E V0) K^T (Wz^T = K (E V0)^T G), then the reduced dampers
   and the feedthrough. */
PHGMG__PRIV phgmg_result phgmg__gmg_dampers(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int N = red->N, r = red->r;
  double *Y = phgmg__dalloc(c->alloc, 2 * (size_t)N * r), *Wz;
  phgmg_result rc;
  if (!Y) return PHGMG_ERR_NOMEM;
  Wz = Y + (size_t)N * r;
  if (c->sys->E) phgmg__ph_e_apply(c->sys, 'N', r, red->V0, N, Y, N);
  else memcpy(Y, red->V0, (size_t)N * r * sizeof(double));
  phgmg_jr_solve(c->jr, 'T', r, Y, N);
  phgmg_gemm('N', 'T', N, r, r, 1.0, Y, N, red->K, r, 0.0, Wz, N);
  rc = c->sys->ndamp ? phgmg__stage_dampers(c, Wz, 1) : PHGMG_OK;
  if (rc == PHGMG_OK && phgmg__has_feed(c->sys)) rc = phgmg__stage_feedthrough(c, Wz);
  phgmg__free(c->alloc, Y);
  return rc;
}

/* ECSW over the dampers: F(k, j) = rho_k(c_k^T z(x_j)) (PHGMG_ERR_DAMPER if
   a callback law generates energy there), rows Cd_k; the kept dampers and
   their weights replace the full set. */
PHGMG__PRIV phgmg_result phgmg__dampers_hyper(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const phgmg_ph_system *sys = c->sys;
  const int N = red->N, r = red->r, nd = sys->ndamp, ns = c->ns;
  double *F = phgmg__dalloc(c->alloc, (size_t)nd * ns + (size_t)nd * r + (size_t)N + (size_t)nd);
  double *Vt, *z, *w, resid = 0.0, d[2];
  int *pts = phgmg__ialloc(c->alloc, (size_t)nd), j, k, a, nk = 0;
  phgmg_result rc = PHGMG_OK;
  if (!F || !pts) { phgmg__free(c->alloc, F); phgmg__free(c->alloc, pts); return PHGMG_ERR_NOMEM; }
  Vt = F + (size_t)nd * ns; z = Vt + (size_t)nd * r; w = z + N;
  for (j = 0; j < ns && rc == PHGMG_OK; ++j) {
    phgmg_ph_gradient(sys, c->X + (size_t)j * c->ldx, z);
    for (k = 0; k < nd; ++k) {
      const double v = phgmg__damp_s(sys, k, z);
      phgmg__damp_law(sys, k, v, d);
      if (!(v * d[0] >= 0.0)) { rc = d[0] != d[0] ? PHGMG_ERR_NANINF : PHGMG_ERR_DAMPER; break; }
      F[k + (size_t)j * nd] = d[0];
    }
  }
  for (k = 0; k < nd; ++k)
    for (a = 0; a < r; ++a) Vt[k + (size_t)a * nd] = red->Cd[a + (size_t)k * r];
  if (rc == PHGMG_OK)
    rc = phgmg_ecsw_separable(nd, ns, F, nd, r, Vt, nd, NULL, c->o->hyper.tol, pts, w, &nk, &resid, c->alloc);
  if (rc == PHGMG_OK) {   /* compact in place: kept dampers first (pts ascending or not, k <= pts[k] is not assumed) */
    double *C2 = Vt;      /* reuse: r x nk */
    for (k = 0; k < nk; ++k) {
      memcpy(C2 + (size_t)k * r, red->Cd + (size_t)pts[k] * r, (size_t)r * sizeof(double));
      red->dterm[k] = pts[k];
    }
    memcpy(red->Cd, C2, (size_t)nk * r * sizeof(double));
    for (k = 0; k < nk; ++k) red->dw[k] = w[k];
    red->ndamp = nk;
  }
  phgmg__free(c->alloc, F);
  phgmg__free(c->alloc, pts);
  return rc;
}

/* The G-blocks computed: r + rn solves with J - R (- L) (the factor stays in
   c->jr for the dampers and feedthrough), G00 = L0^T G [V0] and, with V2,
   G01, G10, G11; L = [V0, V2], or E [V0, V2] for a descriptor model. */
PHGMG__PRIV phgmg_result phgmg__gmg_blocks_solve(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int N = red->N, r = red->r, rn = red->rn;
  double *GV, *EV;
  const double *L0 = red->V0, *L2 = red->V2;   /* left factors: [V0, V2], or E [V0, V2] */
  phgmg_result rc = phgmg__damp_jr_factor(&c->jr, c->sys, NULL, c->alloc);   /* G = (J - R (- L))^{-1} */
  if (rc != PHGMG_OK) return rc;
  GV = phgmg__dalloc(c->alloc, (size_t)N * (r + rn) * (c->sys->E ? 2 : 1));
  if (!GV) return PHGMG_ERR_NOMEM;
  memcpy(GV, red->V0, (size_t)N * r * sizeof(double));
  if (rn) memcpy(GV + (size_t)N * r, red->V2, (size_t)N * rn * sizeof(double));
  if (c->sys->E) { /* descriptor: G_E = E^T G E, so the blocks are (E V)^T G (E V) */
    EV = GV + (size_t)N * (r + rn);
    phgmg__ph_e_apply(c->sys, 'N', r + rn, GV, N, EV, N);
    memcpy(GV, EV, (size_t)N * (r + rn) * sizeof(double));
    L0 = EV; L2 = EV + (size_t)N * r;
  }
  phgmg_jr_solve(c->jr, 'N', r + rn, GV, N);           /* GV = G [V0, V2] */
  phgmg__atb(N, r, r, L0, GV, red->G00);
  if (rn) {
    phgmg__atb(N, r, rn, L0, GV + (size_t)N * r, red->G01);
    phgmg__atb(N, rn, r, L2, GV, red->G10);
    phgmg__atb(N, rn, rn, L2, GV + (size_t)N * r, red->G11);
  }
  phgmg__free(c->alloc, GV);
  return PHGMG_OK;
}

PHGMG__PRIV phgmg_result phgmg__stage_gmg_blocks(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int m = red->m, r = red->r, rn = red->rn;
  int j;
  phgmg_result rc;
  red->G00 = phgmg__red_d(red, (size_t)r * r);
  red->Bh = phgmg__red_d(red, (size_t)r * m);
  if (rn) {
    red->G01 = phgmg__red_d(red, (size_t)r * rn);
    red->G10 = phgmg__red_d(red, (size_t)rn * r);
    red->G11 = phgmg__red_d(red, (size_t)rn * rn);
  }
  if (!red->G00 || !red->Bh || (rn && (!red->G01 || !red->G10 || !red->G11))) return PHGMG_ERR_NOMEM;
  rc = c->sf == PHGMG__SF_GMG ? phgmg__study_gmg_blocks(c) : phgmg__gmg_blocks_solve(c);
  if (rc != PHGMG_OK) return rc;
  for (j = 0; j < m; ++j) red->Bh[j + (size_t)j * r] = 1.0;
  rc = phgmg__check_degeneracy(c);
  if (rc != PHGMG_OK || red->kind != PHGMG_ROM_LINEAR) return rc;
  red->K = phgmg__red_d(red, (size_t)r * r);
  if (!red->K) return PHGMG_ERR_NOMEM;
  rc = phgmg__inv(r, red->G00, red->K, c->alloc);
  return (rc == PHGMG_OK && (c->sys->ndamp || phgmg__has_feed(c->sys))) ? phgmg__gmg_dampers(c) : rc;
}

/* Descriptor: X (N x nc, ld N) <- E^T X. */
PHGMG__PRIV phgmg_result phgmg__e_transpose_block(const phgmg__rctx *c, int nc, double *X) {
  const int N = c->sys->N;
  double *t = phgmg__dalloc(c->alloc, (size_t)N);
  int j;
  if (!t) return PHGMG_ERR_NOMEM;
  for (j = 0; j < nc; ++j) {
    phgmg__ph_mtv(c->sys, c->sys->E, X + (size_t)j * N, t);
    memcpy(X + (size_t)j * N, t, (size_t)N * sizeof(double));
  }
  phgmg__free(c->alloc, t);
  return PHGMG_OK;
}

/* The test basis of SP1 (Q V) or SP2 (POD of the gradient snapshots) into Vg. */
PHGMG__PRIV phgmg_result phgmg__sp_test_basis(phgmg__rctx *c, double *Vg) {
  phgmg_reduced *red = c->red;
  const int N = red->N, r = red->r, ns = c->ns;
  double *Fg, *S;
  int j, k = 0;
  phgmg_result rc;
  if (red->method == PHGMG_METHOD_SP1) {   /* Hess H V: Q V, or E^T Q V */
    phgmg_ph_apply(c->sys, 'Q', r, red->V0, N, Vg, N);
    return c->sys->E ? phgmg__e_transpose_block(c, r, Vg) : PHGMG_OK;
  }
  if (c->o->cache.grad_basis) {
    if (c->o->cache.grad_cols < r) return PHGMG_ERR_SIZE;
    memcpy(Vg, c->o->cache.grad_basis, (size_t)N * r * sizeof(double));
    return PHGMG_OK;
  }
  Fg = phgmg__dalloc(c->alloc, (size_t)N * ns + (size_t)r);
  if (!Fg) return PHGMG_ERR_NOMEM;
  S = Fg + (size_t)N * ns;
  for (j = 0; j < ns; ++j) phgmg_ph_gradient(c->sys, c->Xf + (size_t)j * c->ldxf, Fg + (size_t)j * N);
  rc = c->sys->E ? phgmg__e_transpose_block(c, ns, Fg) : PHGMG_OK;   /* grad H = E^T z */
  if (rc == PHGMG_OK) rc = phgmg_pod(N, ns, Fg, N, r, 0.0, Vg, N, S, &k, c->alloc);
  if (rc == PHGMG_OK && (k < r || !(S[r - 1] > phgmg__rank_floor(N, ns, Fg, N)))) rc = PHGMG_ERR_SIZE;
  phgmg__free(c->alloc, Fg);
  return rc;
}

/* Stage 3b, SP1/SP2 blocks (manual 8.8): W = Vg (V^T Vg)^{-1},
   K = W^T (J - R) W, Bh = W^T B. */
PHGMG__PRIV phgmg_result phgmg__stage_sp_blocks(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int N = red->N, r = red->r, m = red->m;
  double *Vg, *A2, *Ainv, *T;
  int i;
  phgmg_result rc;
  Vg = phgmg__dalloc(c->alloc, 2 * (size_t)N * r + 2 * (size_t)r * r);
  if (!Vg) return PHGMG_ERR_NOMEM;
  T = Vg + (size_t)N * r; A2 = T + (size_t)N * r; Ainv = A2 + (size_t)r * r;
  rc = phgmg__sp_test_basis(c, Vg);
  if (rc == PHGMG_OK) {
    phgmg__atb(N, r, r, red->V0, Vg, A2);               /* V^T Vg */
    c->inf.rcond_dgd = phgmg__rcond_of(r, A2, c->alloc);
    if (c->inf.rcond_dgd < 0.0) rc = PHGMG_ERR_NOMEM;
    else if (!(c->inf.rcond_dgd >= c->degtol)) rc = PHGMG_ERR_DEGENERATE;
  }
  if (rc == PHGMG_OK) rc = phgmg__inv(r, A2, Ainv, c->alloc);
  if (rc == PHGMG_OK) {
    red->W = phgmg__red_d(red, (size_t)N * r);
    red->K = phgmg__red_d(red, (size_t)r * r);
    red->Bh = phgmg__red_d(red, (size_t)r * m);
    red->Ainv = phgmg__red_d(red, (size_t)r * r);
    if (!red->W || !red->K || !red->Bh || !red->Ainv) rc = PHGMG_ERR_NOMEM;
  }
  if (rc == PHGMG_OK) memcpy(red->Ainv, Ainv, (size_t)r * r * sizeof(double));
  if (rc == PHGMG_OK) {
    const double *Wz = red->W;   /* the test basis of the co-state: W, or E^{-T} W */
    phgmg_gemm('N', 'N', N, r, r, 1.0, Vg, N, Ainv, r, 0.0, red->W, N);
    if (c->sys->E) {
      double *Wt = phgmg__red_d(red, (size_t)N * r);
      if (!Wt) { phgmg__free(c->alloc, Vg); return PHGMG_ERR_NOMEM; }
      memcpy(Wt, red->W, (size_t)N * r * sizeof(double));
      phgmg_jr_solve(c->ef, 'T', r, Wt, N);
      Wz = Wt;
    }
    phgmg_ph_apply(c->sys, 'J', r, Wz, N, Vg, N);
    phgmg_ph_apply(c->sys, 'R', r, Wz, N, T, N);
    for (i = 0; i < N * r; ++i) Vg[i] -= T[i];
    phgmg__atb(N, r, r, Wz, Vg, red->K);
    phgmg__atb(N, r, m, Wz, c->sys->B, red->Bh);
    if (c->sys->ndamp) rc = phgmg__stage_dampers(c, Wz, 0);
    if (rc == PHGMG_OK && phgmg__has_feed(c->sys)) rc = phgmg__stage_feedthrough(c, Wz);
  }
  phgmg__free(c->alloc, Vg);
  return rc;
}

/* A (n x n) <- (A + A^T) / 2, exactly symmetric. */
PHGMG__PRIV void phgmg__symmetrize(int n, double *A) {
  int i, j;
  for (j = 0; j < n; ++j)
    for (i = 0; i < j; ++i)
      A[i + (size_t)j * n] = A[j + (size_t)i * n] = 0.5 * (A[i + (size_t)j * n] + A[j + (size_t)i * n]);
}

/* The Q-blocks computed: Qh = L0^T Q V0, Q01 = L0^T Q V2, Q11 = L2^T Q V2
   with L = [V0, V2], or E [V0, V2] for a descriptor model (Hess H = E^T Q). */
PHGMG__PRIV phgmg_result phgmg__quadratic_terms_apply(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int N = red->N, r = red->r, rn = red->rn;
  double *QV = phgmg__dalloc(c->alloc, (size_t)N * (r + rn) * (c->sys->E ? 2 : 1));
  const double *L0 = red->V0, *L2 = red->V2;
  if (!QV) return PHGMG_ERR_NOMEM;
  phgmg_ph_apply(c->sys, 'Q', r, red->V0, N, QV, N);
  if (rn) phgmg_ph_apply(c->sys, 'Q', rn, red->V2, N, QV + (size_t)N * r, N);
  if (c->sys->E) {
    double *EV = QV + (size_t)N * (r + rn);
    phgmg__ph_e_apply(c->sys, 'N', r, red->V0, N, EV, N);
    if (rn) phgmg__ph_e_apply(c->sys, 'N', rn, red->V2, N, EV + (size_t)N * r, N);
    L0 = EV; L2 = EV + (size_t)N * r;
  }
  phgmg__atb(N, r, r, L0, QV, red->Qh);
  if (rn) {
    phgmg__atb(N, r, rn, L0, QV + (size_t)N * r, red->Q01);
    phgmg__atb(N, rn, rn, L2, QV + (size_t)N * r, red->Q11);
    if (c->sys->E) phgmg__symmetrize(rn, red->Q11);
  }
  phgmg__free(c->alloc, QV);
  return PHGMG_OK;
}

/* The study's Q-blocks: sub-blocks of its [B, Ua]^T Q [B, Ua]. */
PHGMG__PRIV phgmg_result phgmg__study_quadratic_terms(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int r = red->r, rn = red->rn, nf = red->m + c->st->ka;
  phgmg__subblock(r, r, c->st->Qf, nf, 0, 0, red->Qh);
  if (rn) {
    phgmg__subblock(r, rn, c->st->Qf, nf, 0, r, red->Q01);
    phgmg__subblock(rn, rn, c->st->Qf, nf, r, r, red->Q11);
  }
  return PHGMG_OK;
}

/* Stage 4a, quadratic part of H: Qh = V0^T Q V0 (exactly symmetric), and
   the V2 blocks Q01 = V0^T Q V2, Q11 = V2^T Q V2 -- from the study's cached
   blocks or computed. */
PHGMG__PRIV phgmg_result phgmg__stage_quadratic_terms(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int r = red->r, rn = red->rn;
  phgmg_result rc;
  red->Qh = phgmg__red_d(red, (size_t)r * r);
  if (rn) {
    red->Q01 = phgmg__red_d(red, (size_t)r * rn);
    red->Q11 = phgmg__red_d(red, (size_t)rn * rn);
  }
  if (!red->Qh || (rn && (!red->Q01 || !red->Q11))) return PHGMG_ERR_NOMEM;
  rc = c->sf == PHGMG__SF_GMG ? phgmg__study_quadratic_terms(c) : phgmg__quadratic_terms_apply(c);
  if (rc == PHGMG_OK) phgmg__symmetrize(r, red->Qh);
  return rc;
}

/* ECSW for GMG-QM / GMG_MANIFOLD: rows (i, a) of the training matrix are
   phi_k'(x_i[idx_k]) Dphi(rho(x_i))[idx_k, a] over the snapshots (every
   `stride`-th, so that it holds at most 4e6 entries), target = its columns
   times the terms' weights. */
PHGMG__PRIV phgmg_result phgmg__hyper_ecsw_manifold(phgmg__rctx *c, const double *F, int nt, const int *live,
                                                   int *pts, double *wt, int *nd) {
  const phgmg_reduced *red = c->red;
  const phgmg_ph_system *sys = c->sys;
  const int r = red->r, m = red->m, p = red->p, rn = red->rn, N = red->N;
  const int stride = (int)(((double)c->ns * r * sys->nsep) / 4e6) + 1, nsu = (c->ns + stride - 1) / stride;
  const size_t nrow = (size_t)nsu * r;
  double *Gm = phgmg__dalloc(c->alloc, nrow * nt + nrow + nrow + (size_t)rn * p);
  double *tg, *XR, *Dq;
  int i, k, a, j, u;
  phgmg_result rc;
  if (!Gm) return PHGMG_ERR_NOMEM;
  tg = Gm + nrow * nt; XR = tg + nrow; Dq = XR + nrow;
  if ((double)c->ldxf * stride <= 2147483647.0)   /* rho of the used snapshots */
    phgmg__restrict_block(red, nsu, c->Xf, c->ldxf * stride, XR);
  else
    for (u = 0; u < nsu; ++u) phgmg_reduced_restrict(red, c->Xf + (size_t)u * stride * c->ldxf, XR + (size_t)u * r);
  for (u = 0; u < nsu; ++u) {
    i = u * stride;
    phgmg__eta_d(red, XR + (size_t)u * r + m, NULL, Dq, NULL, red->rwork);
    for (k = 0; k < nt; ++k) {
      const int ix = sys->sep_idx[live[k]];
      const double f = F[k + (size_t)i * nt];
      double *g = Gm + (size_t)u * r + (size_t)k * nrow;
      for (a = 0; a < r; ++a) g[a] = f * red->V0[ix + (size_t)a * N];
      for (a = 0; a < p; ++a) {
        double s = 0.0;
        for (j = 0; j < rn; ++j) s += red->V2[ix + (size_t)j * N] * Dq[j + (size_t)a * rn];
        g[m + a] += f * s;
      }
    }
  }
  for (a = 0; a < (int)nrow; ++a) tg[a] = 0.0;
  for (k = 0; k < nt; ++k) {
    const double sw = c->sepw ? c->sepw[live[k]] : 1.0;
    for (a = 0; a < (int)nrow; ++a) tg[a] += sw * Gm[a + (size_t)k * nrow];
  }
  rc = phgmg_ecsw(nt, (int)nrow, Gm, (int)nrow, tg, c->o->hyper.tol, pts, wt, nd, &c->inf.hyper_residual, c->alloc);
  for (k = 0; rc == PHGMG_OK && k < *nd; ++k) pts[k] = live[pts[k]];   /* ascending stays ascending */
  phgmg__free(c->alloc, Gm);
  return rc;
}

/* Hyper-reduction by empirical quadrature (hyper.kind = PHGMG_HYPER_ECSW): terms and
   weights w >= 0 that reproduce the reduced gradient of the nonlinear part
   over the training snapshots to hyper.tol (phgmg_ecsw). With w >= 0 and a
   convex phi the reduced Hamiltonian stays convex and bounded below. Here
   for a linear-kind model, on the terms live[0..nl) (F: nl x ns, their
   gradients at the snapshots); pts come back as full term indices. */
PHGMG__PRIV phgmg_result phgmg__hyper_ecsw(phgmg__rctx *c, const double *F, int nl, const int *live, int *pts,
                                          double *wt, int *nd) {
  const phgmg_reduced *red = c->red;
  const int r = red->r, N = red->N;
  double *Vt, *sw;
  int k, a;
  phgmg_result rc;
  Vt = phgmg__dalloc(c->alloc, (size_t)nl * (r + 1));   /* rows of V0 at the terms, weights */
  if (!Vt) return PHGMG_ERR_NOMEM;
  sw = Vt + (size_t)nl * r;
  for (a = 0; a < r; ++a)
    for (k = 0; k < nl; ++k) Vt[k + (size_t)a * nl] = red->V0[c->sys->sep_idx[live[k]] + (size_t)a * N];
  for (k = 0; k < nl; ++k) sw[k] = c->sepw ? c->sepw[live[k]] : 1.0;
  rc = phgmg_ecsw_separable(nl, c->ns, F, nl, r, Vt, nl, sw, c->o->hyper.tol, pts, wt, nd,
                            &c->inf.hyper_residual, c->alloc);
  for (k = 0; rc == PHGMG_OK && k < *nd; ++k) pts[k] = live[pts[k]];   /* ascending stays ascending */
  phgmg__free(c->alloc, Vt);
  return rc;
}

/* The terms' gradients phi_k'(x_i[idx_k]) at the snapshots into a new F
   (nl x ns) for the terms live[0..nl). For ECSW (compact = 1) only the
   terms whose gradient is not zero at every snapshot are live: a zero column of the fit is never chosen, and in a large model
   driven locally most terms stay at rest (argument 0, phi'(0) = 0), so F
   shrinks from nsep rows to the moving ones. Otherwise every term is live. */
PHGMG__PRIV phgmg_result phgmg__separable_gradients(phgmg__rctx *c, int compact, double **Fo, int **liveo, int *nlo) {
  const phgmg_ph_system *sys = c->sys;
  const int nt = sys->nsep, ns = c->ns;
  int *live = phgmg__ialloc(c->alloc, (size_t)nt), nl = 0, a, i;
  double *F;
  if (!live) return PHGMG_ERR_NOMEM;
  for (a = 0; a < nt; ++a) live[a] = !compact || phgmg__ph_phi(sys, a, 0.0, 1) != 0.0;
  for (i = 0; compact && i < ns; ++i) {
    const double *x = c->Xf + (size_t)i * c->ldxf;
    for (a = 0; a < nt; ++a) live[a] |= x[sys->sep_idx[a]] != 0.0;
  }
  for (a = 0; a < nt; ++a) if (live[a]) live[nl++] = a;   /* in place: nl <= a */
  F = phgmg__dalloc(c->alloc, (size_t)(nl ? nl : 1) * ns);
  if (!F) { phgmg__free(c->alloc, live); return PHGMG_ERR_NOMEM; }
  for (i = 0; i < ns; ++i)
    for (a = 0; a < nl; ++a)
      F[a + (size_t)i * nl] = phgmg__ph_phi(sys, live[a], c->Xf[sys->sep_idx[live[a]] + (size_t)i * c->ldxf], 1);
  *Fo = F; *liveo = live; *nlo = nl;
  return PHGMG_OK;
}

/* Points and weights of the separable sum: the caller's (opts.cache.deim_pts),
   structure-preserving DEIM on the snapshots of the terms' gradients, or
   every term with its own weight. pts/wt have room for nsep entries. */
PHGMG__PRIV phgmg_result phgmg__separable_points(phgmg__rctx *c, int *pts, double *wt, int *nd) {
  const phgmg_ph_system *sys = c->sys;
  const phgmg_reduce_opts *o = c->o;
  const int nt = sys->nsep, ns = c->ns;
  int a, nneg = 0;
  phgmg_result rc = PHGMG_OK;
  if (o->hyper.on && o->cache.deim_pts && o->cache.deim_w) {
    if (o->cache.deim_count < 1 || o->cache.deim_count > nt) return PHGMG_ERR_SIZE;
    *nd = o->cache.deim_count;
    for (a = 0; a < *nd; ++a) {
      if (o->cache.deim_pts[a] < 0 || o->cache.deim_pts[a] >= nt) return PHGMG_ERR_INVALID_ARG;
      pts[a] = o->cache.deim_pts[a];
      wt[a] = o->cache.deim_w[a];
      if (wt[a] < 0.0) ++nneg;
    }
    if (!phgmg__all_finite(wt, (size_t)*nd)) return PHGMG_ERR_NANINF;
  } else if (o->hyper.on) {
    const phgmg__hyper_row *hk = &phgmg__hypers[o->hyper.kind];
    const int ecsw = hk->quadrature, quad = c->red->kind == PHGMG_ROM_QUADRATIC;
    double *F = NULL;
    int *live = NULL, nl = 0;
    rc = phgmg__separable_gradients(c, ecsw, &F, &live, &nl);
    if (rc != PHGMG_OK) return rc;
    if (ecsw && nl == 0)
      *nd = 0;   /* no term ever moves: nothing to keep */
    else if (ecsw && quad)
      rc = phgmg__hyper_ecsw_manifold(c, F, nl, live, pts, wt, nd);
    else if (ecsw)
      rc = phgmg__hyper_ecsw(c, F, nl, live, pts, wt, nd);
    else
      rc = phgmg_deim_select(nt, ns, F, nt, c->sepw, o->hyper.deim_tol, o->hyper.deim_max,
                             hk->points,
                             pts, wt, nd, &nneg, &c->inf.deim_sigma_ratio, c->alloc);
    phgmg__free(c->alloc, F);
    phgmg__free(c->alloc, live);
    c->inf.hyper_method = o->hyper.kind;
  } else {
    *nd = nt;
    for (a = 0; a < nt; ++a) { pts[a] = a; wt[a] = c->sepw ? c->sepw[a] : 1.0; }
  }
  c->inf.deim_modes = *nd;      /* reported on PHGMG_ERR_NEGATIVE_WEIGHT too */
  c->inf.deim_negative = nneg;
  if (rc == PHGMG_OK && *nd > 0) {
    c->inf.hyper_min_weight = wt[0];
    for (a = 1; a < *nd; ++a) c->inf.hyper_min_weight = PHGMG__MIN(c->inf.hyper_min_weight, wt[a]);
  }
  if (rc == PHGMG_OK && nneg > 0 && !o->hyper.allow_negative) rc = PHGMG_ERR_NEGATIVE_WEIGHT;
  return rc;
}

/* The scalar functions of the kept terms: the built-in exp-polynomial family
   (shared, or one row per kept term) or, for callbacks, the full-model index
   of each kept term (the online model calls back through the system). */
PHGMG__PRIV phgmg_result phgmg__separable_functions(phgmg_reduced *red, const int *pts) {
  const phgmg_ph_system *sys = red->sys;
  const int nd = red->nd, deg = sys->poly_deg, ne = sys->nexp;
  const int per = sys->phi_nfun > 1, nf = per ? nd : 1;
  int j;
  red->term = PHGMG__CAST(int *, phgmg__red_alloc(red, (size_t)nd * sizeof(int)));
  if (!red->term) return PHGMG_ERR_NOMEM;
  for (j = 0; j < nd; ++j) red->term[j] = pts[j];
  if (!PHGMG__PH_BUILTIN(sys)) return PHGMG_OK;  /* callbacks */
  red->nphi = per ? nd : 1;
  red->nexp = ne;
  red->poly = phgmg__red_d(red, (size_t)nf * (deg + 1));
  red->expo = ne ? phgmg__red_d(red, (size_t)nf * 2 * ne) : NULL;
  if (!red->poly || (ne && !red->expo)) return PHGMG_ERR_NOMEM;
  for (j = 0; j < nf; ++j) {
    const int t = per ? pts[j] : 0;
    if (sys->poly) memcpy(red->poly + (size_t)j * (deg + 1), sys->poly + (size_t)t * (deg + 1), ((size_t)deg + 1) * sizeof(double));
    if (ne) memcpy(red->expo + (size_t)j * 2 * ne, sys->expo + (size_t)t * 2 * ne, 2 * (size_t)ne * sizeof(double));
  }
  return PHGMG_OK;
}

/* Stage 4b, separable nonlinear part sum_k w_k phi_k(x_{idx_k}): kept terms
   (DEIM or all), their weights, and the rows P0 = V0(idx, :), P1 = V2(idx, :)
   through which the online model evaluates them. */
PHGMG__PRIV phgmg_result phgmg__stage_separable_terms(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int N = red->N, r = red->r, rn = red->rn, nt = c->sys->nsep;
  int *pts, nd = 0, j, a;
  double *wt;
  phgmg_result rc;
  if (c->sys->nl != PHGMG_NL_SEPARABLE || nt < 1) return PHGMG_OK;
  pts = phgmg__ialloc(c->alloc, (size_t)nt);
  wt = phgmg__dalloc(c->alloc, (size_t)nt);
  rc = (pts && wt) ? phgmg__separable_points(c, pts, wt, &nd) : PHGMG_ERR_NOMEM;
  if (rc == PHGMG_OK) {
    red->nd = nd;
    red->coord = PHGMG__CAST(int *, phgmg__red_alloc(red, (size_t)nd * sizeof(int)));
    red->w = phgmg__red_d(red, (size_t)nd);
    red->P0 = phgmg__red_d(red, (size_t)nd * r);
    red->P1 = rn ? phgmg__red_d(red, (size_t)nd * rn) : NULL;
    if (!red->coord || !red->w || !red->P0 || (rn && !red->P1)) rc = PHGMG_ERR_NOMEM;
  }
  if (rc == PHGMG_OK) {
    for (j = 0; j < nd; ++j) {
      const int cj = c->sys->sep_idx[pts[j]];
      red->coord[j] = cj;
      red->w[j] = wt[j];
      for (a = 0; a < r; ++a) red->P0[j + (size_t)a * nd] = red->V0[cj + (size_t)a * N];
      for (a = 0; a < rn; ++a) red->P1[j + (size_t)a * nd] = red->V2[cj + (size_t)a * N];
    }
    if (red->xbar && nd > 0) {   /* the kept terms' argument offsets */
      red->refs = phgmg__red_d(red, (size_t)nd);
      for (j = 0; red->refs && j < nd; ++j) red->refs[j] = red->xbar[red->coord[j]];
      if (!red->refs) rc = PHGMG_ERR_NOMEM;
    }
    if (rc == PHGMG_OK) rc = phgmg__separable_functions(red, pts);
  }
  phgmg__free(c->alloc, pts);
  phgmg__free(c->alloc, wt);
  return rc;
}

/* Stage 4c, a GENERAL nonlinear part: the reduced model evaluates
   H_nl(phi(x)), Dphi^T grad H_nl(phi(x)) and the Hessian in full dimension
   through phgmg__ham_general (O(N) per gradient; the Hessian O(N^2 r) dense,
   O(N kb r) banded). Workspace: x (N), g (N), the Hessian, Dphi (N x r). */
PHGMG__PRIV phgmg_result phgmg__stage_general_term(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int N = red->N, r = red->r;
  const size_t nh = c->sys->storage == PHGMG_BANDED ? (size_t)(2 * c->sys->kb + 1) * N : (size_t)N * N;
  const size_t rn = (size_t)red->rn, p = (size_t)red->p;
  if (c->sys->nl != PHGMG_NL_GENERAL) return PHGMG_OK;
  c->inf.online_full_dim = 1;
  red->gwork = phgmg__red_d(red, (size_t)r + 2 * (size_t)N + nh + 2 * (size_t)N * r + rn + rn * p * p + (size_t)r * r);
  return red->gwork ? PHGMG_OK : PHGMG_ERR_NOMEM;
}

/* Reference state (opts.ref), first part: xbar (the snapshots' mean or the
   caller's vector) and the centred snapshots Xc = X - xbar 1^T, which the
   basis and manifold stages fit (c->X becomes Xc; c->Xf stays X). */
PHGMG__PRIV phgmg_result phgmg__stage_reference(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int N = red->N, ns = c->ns;
  int i, j;
  if (c->o->ref == PHGMG_REF_NONE) return PHGMG_OK;
  red->xbar = phgmg__red_d(red, (size_t)N);
  c->Xc = phgmg__dalloc(c->alloc, (size_t)N * ns);
  if (!red->xbar || !c->Xc) return PHGMG_ERR_NOMEM;
  if (c->o->ref == PHGMG_REF_GIVEN) {
    memcpy(red->xbar, c->o->ref_x, (size_t)N * sizeof(double));
    if (!phgmg__all_finite(red->xbar, (size_t)N)) return PHGMG_ERR_NANINF;
  } else {   /* the mean, summed in order (the snapshots are finite) */
    memset(red->xbar, 0, (size_t)N * sizeof(double));
    for (j = 0; j < ns; ++j) phgmg__axpy(N, 1.0, c->Xf + (size_t)j * c->ldxf, red->xbar);
    for (i = 0; i < N; ++i) red->xbar[i] /= (double)ns;
  }
  for (j = 0; j < ns; ++j) {
    const double *x = c->Xf + (size_t)j * c->ldxf;
    double *y = c->Xc + (size_t)j * N;
    for (i = 0; i < N; ++i) y[i] = x[i] - red->xbar[i];
  }
  c->X = c->Xc;   /* red->xbr: phgmg__stage_reference_terms, once the basis is final */
  c->ldx = N;
  c->rfloor = phgmg__rank_floor(N, ns, c->Xc, N);   /* the rank of what the bases are fitted to */
  return PHGMG_OK;
}

/* Reference state, second part (after the quadratic terms; manual 3.6). With
   Hq = Q (E^T Q for a descriptor model) and v = Hq xbar:
     g0 = V0^T v, g2 = V2^T v, h0 = xbar^T v / 2, xr_rest = rho(0).
   A linear phi and a quadratic H: xbar is first moved within the affine
   space xbar + span V0 to xbar - V0 Qh^{-1} V0^T Hq xbar, which makes g0 = 0
   (the same model in shifted coordinates: the step map applies as is). */
PHGMG__PRIV void phgmg__ref_hq(const phgmg__rctx *c, const double *x, double *v, double *t) {
  phgmg_ph_apply(c->sys, 'Q', 1, x, c->sys->N, t, c->sys->N);
  phgmg__ph_e_apply(c->sys, 'T', 1, t, c->sys->N, v, c->sys->N);
}

PHGMG__PRIV phgmg_result phgmg__stage_reference_terms(phgmg__rctx *c) {
  phgmg_reduced *red = c->red;
  const int N = red->N, r = red->r, rn = red->kind == PHGMG_ROM_QUADRATIC ? red->rn : 0;
  double *v, *t, *A, *a, *xbr, h0 = 0.0;
  int *piv, i;
  phgmg_result rc = PHGMG_OK;
  if (!red->xbar) return PHGMG_OK;
  v = phgmg__dalloc(c->alloc, 2 * (size_t)N + (size_t)r * r + (size_t)r);
  piv = phgmg__ialloc(c->alloc, (size_t)r);
  red->refg = phgmg__red_d(red, (size_t)r + rn + 1);
  red->xrest = phgmg__red_d(red, (size_t)r);
  xbr = phgmg__red_d(red, (size_t)r);
  if (!v || !piv || !red->refg || !red->xrest || !xbr) rc = PHGMG_ERR_NOMEM;
  if (rc == PHGMG_OK) {
    t = v + N; A = t + N; a = A + (size_t)r * r;
    phgmg__ref_hq(c, red->xbar, v, t);
    phgmg_gemv('T', N, r, 1.0, red->V0, N, v, 0.0, red->refg);   /* g0 */
    if (red->kind == PHGMG_ROM_LINEAR && c->sys->nl == PHGMG_NL_NONE) {   /* shift: g0 = 0 */
      memcpy(A, red->Qh, (size_t)r * r * sizeof(double));
      memcpy(a, red->refg, (size_t)r * sizeof(double));
      if (phgmg_lu_factor(r, A, r, piv) == PHGMG_OK) {
        phgmg_lu_solve('N', r, A, r, piv, 1, a, r);
        phgmg_gemv('N', N, r, -1.0, red->V0, N, a, 1.0, red->xbar);
        phgmg__ref_hq(c, red->xbar, v, t);
        memset(red->refg, 0, (size_t)r * sizeof(double));
      }
    }
    if (rn) phgmg_gemv('T', N, rn, 1.0, red->V2, N, v, 0.0, red->refg + r);   /* g2 */
    for (i = 0; i < N; ++i) h0 += red->xbar[i] * v[i];
    red->refg[r + rn] = 0.5 * h0;
    red->xbr = NULL;                      /* rho without the shift, at xbar */
    phgmg_reduced_restrict(red, red->xbar, xbr);
    red->xbr = xbr;
    for (i = 0; i < r; ++i) red->xrest[i] = -xbr[i];   /* rho(0) */
    if (!phgmg__all_finite(red->refg, (size_t)r + rn + 1) || !phgmg__all_finite(xbr, (size_t)r)) rc = PHGMG_ERR_NANINF;
  }
  phgmg__free(c->alloc, v);
  phgmg__free(c->alloc, piv);
  return rc;
}

/* manifold = ALTMIN under PHGMG_LAMBDA_VALIDATED without a model as good as GMG-POD
   (phgmg__altmin_reference): the same reduction with the hierarchical POD
   manifold; info keeps the altmin objective and sets manifold_fallback. */
PHGMG__PRIV phgmg_result phgmg__reduce_fallback_pod(phgmg_reduced **out, const phgmg__rctx *c,
                                                    phgmg_reduce_info *info) {
  phgmg_reduce_opts o = *c->o;
  phgmg_reduce_info inf;
  phgmg_result rc;
  phgmg_reduced_destroy(c->red);
  o.qm.manifold = PHGMG_MANIFOLD_POD;
  rc = phgmg_reduce(out, c->sys, c->Xf, c->ldxf, c->ns, &o, &inf, c->alloc);
  inf.manifold_obj0 = c->inf.manifold_obj0; inf.manifold_obj = c->inf.manifold_obj;
  inf.manifold_sweeps = c->inf.manifold_sweeps; inf.manifold_fallback = 1;
  if (info) *info = inf;
  return rc;
}

/* opts->progress, if set (see phgmg_reduce_opts). */

/* Which fast path of a study applies to opts (resolved; 0: none): the study's own
   bases, orders within its modes (phgmg_study_reduce). */
PHGMG__PRIV int phgmg__study_fast(const phgmg_study *st, const phgmg_reduce_opts *o, int m) {
  if (!st) return PHGMG__SF_NONE;
  if ((o->method == PHGMG_METHOD_GMG_POD || (o->method == PHGMG_METHOD_GMG_QM && o->qm.manifold == PHGMG_MANIFOLD_POD)) && st->Ua &&
      o->cache.pod_basis == st->Ua && o->qm.rn >= 0 &&
      o->r - m + (o->method == PHGMG_METHOD_GMG_QM ? o->qm.rn : 0) <= st->ka)
    return PHGMG__SF_GMG;
  if (o->method == PHGMG_METHOD_SP1 && st->Up && st->Cq && o->cache.pod_basis == st->Up && o->r <= st->kp) return PHGMG__SF_SP1;
  if (o->method == PHGMG_METHOD_SP2 && st->Up && st->Ug && o->cache.pod_basis == st->Up && o->cache.grad_basis == st->Ug &&
      o->r <= st->kp && o->r <= st->kg)
    return PHGMG__SF_SP2;
  return PHGMG__SF_NONE;
}

/* Building one reduced model: the pipeline's stages in the paper's order
   (basis -> manifold -> GMG blocks -> Hamiltonian terms -> stepper), then
   the object published for use. */
PHGMG__PRIV phgmg_result phgmg__reduce_build(phgmg__rctx *c) {
  const phgmg_reduce_opts *opts = c->o;
  const phgmg_ph_system *sys = c->sys;
  phgmg_result rc = phgmg__reduce_new(c);
  if (rc == PHGMG_OK && c->sf) { c->red->study = c->st; c->red->sbasis = c->sf; }
  if (rc == PHGMG_OK) { phgmg__progress(opts, "basis"); rc = phgmg__stage_reference(c); }
  if (rc == PHGMG_OK) rc = phgmg__stage_basis(c);
  if (rc == PHGMG_OK) { phgmg__progress(opts, "manifold"); rc = phgmg__stage_manifold(c); }
  if (rc == PHGMG_OK) {
    phgmg__progress(opts, "blocks");
    rc = phgmg__is_gmg(opts->method) ? phgmg__stage_gmg_blocks(c) : phgmg__stage_sp_blocks(c);
  }
  if (rc == PHGMG_OK) { phgmg__progress(opts, "hamiltonian"); rc = phgmg__stage_quadratic_terms(c); }
  if (rc == PHGMG_OK) rc = phgmg__stage_reference_terms(c);
  if (rc == PHGMG_OK) { phgmg__progress(opts, "hyper-reduction"); rc = phgmg__stage_separable_terms(c); }
  if (rc == PHGMG_OK) { phgmg__progress(opts, "finish"); rc = phgmg__stage_general_term(c); }
  if (rc == PHGMG_OK && opts->dt > 0.0 && c->red->kind == PHGMG_ROM_LINEAR && c->red->nd == 0 &&
      sys->nl != PHGMG_NL_GENERAL && c->red->ndamp == 0 && !c->red->PD) {
    c->red->map_dt = opts->dt;
    rc = phgmg__step_map(c->red, opts->dt, c->alloc);
  }
  return rc == PHGMG_OK ? phgmg__publish(c->red) : rc;
}

/* Selecting among the models the options allow, after one was built: the
   validated lambda of GMG-QM (each candidate's M refitted on the built
   blocks and simulated; >>deploy), the online bounds of the chosen model, and
   the fallback to GMG-POD when no candidate is safe (c->fallback_pod, acted
   on by the caller). */
PHGMG__PRIV phgmg_result phgmg__reduce_select(phgmg__rctx *c) {
  phgmg_result rc = phgmg__stage_lambda_validate(c);
  if (rc == PHGMG_OK) rc = phgmg__stage_envelope(c);
  if (rc == PHGMG_OK) c->inf.online_callbacks = c->red->rom.phi_cb || c->red->rom.eta_cb || c->red->rom.ham_cb;
  return rc;
}

/* The options resolved and checked, the model validated, the context set. */
PHGMG__PRIV phgmg_result phgmg__reduce_setup(phgmg__rctx *c, const phgmg_ph_system *sys, const double *X, int ldx,
                                             int ns, const phgmg_reduce_opts *opts, const phgmg_allocator *alloc,
                                             phgmg_study *st) {
  phgmg_result rc;
  memset(c, 0, sizeof *c);
  c->ro = *opts;
  phgmg__reduce_opts_resolve(&c->ro, ns);
  c->sys = sys; c->o = &c->ro; c->X = X; c->ldx = ldx; c->ns = ns; c->alloc = alloc; c->gsel = -1;
  c->Xf = X; c->ldxf = ldx;
  c->st = st;
  c->inf.hyper_method = -1;
  rc = phgmg__reduce_check(sys, X, ldx, ns, c->o, st != NULL);
  if (rc == PHGMG_OK) c->sf = (c->o->ref != PHGMG_REF_NONE || sys->ndamp) ? PHGMG__SF_NONE : phgmg__study_fast(st, c->o, sys->m);
  if (rc == PHGMG_OK) rc = phgmg_ph_validate(sys, 0.0, &c->inf.rcond_jr, alloc);
  if (rc == PHGMG_OK && sys->E && phgmg__e_algebraic(sys, alloc) != 0)   /* reduce the condensed model (1.8) */
    rc = PHGMG_ERR_UNSUPPORTED;
  if (rc != PHGMG_OK) return rc;
  c->lambda = c->o->qm.lambda < 0.0 ? 0.0 : c->o->qm.lambda;   /* < 0: exactly zero */
  if (c->o->select.lambda_mode != PHGMG_LAMBDA_FIXED && c->o->method == PHGMG_METHOD_GMG_QM)
    c->ng = phgmg__lambda_grid(c->o->select.lambda_min, c->o->select.lambda_max, c->o->select.per_decade, NULL);
  c->degtol = c->o->degeneracy_tol;
  c->rfloor = phgmg__rank_floor(sys->N, ns, X, ldx);
  rc = phgmg__runs_layout(c);
  return rc == PHGMG_OK ? phgmg__reduce_descriptor_setup(c) : rc;
}

/* phgmg_reduce: set up, build one model, select (lambda, fallback). */
PHGMG__PRIV phgmg_result phgmg__reduce_run(phgmg_reduced **out, const phgmg_ph_system *sys, const double *X,
                                           int ldx, int ns, const phgmg_reduce_opts *opts,
                                           phgmg_reduce_info *info, const phgmg_allocator *alloc,
                                           phgmg_study *st) {
  phgmg__rctx c;
  phgmg_result rc;
  if (!out) return PHGMG_ERR_INVALID_ARG;
  *out = NULL;
  if (!sys || !X || !opts) return PHGMG_ERR_INVALID_ARG;
  rc = phgmg__reduce_setup(&c, sys, X, ldx, ns, opts, alloc, st);
  if (rc == PHGMG_OK) rc = phgmg__reduce_build(&c);
  if (rc == PHGMG_OK) rc = phgmg__reduce_select(&c);
  phgmg__rctx_free(&c);
  if (rc == PHGMG_OK && c.fallback_pod) return phgmg__reduce_fallback_pod(out, &c, info);
  if (info) *info = c.inf;
  if (rc != PHGMG_OK) {
    phgmg_reduced_destroy(c.red);
    return rc;
  }
  phgmg__progress(opts, "done");
  *out = c.red;
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_reduce(phgmg_reduced **out, const phgmg_ph_system *sys, const double *X,
                                    int ldx, int ns, const phgmg_reduce_opts *opts,
                                    phgmg_reduce_info *info, const phgmg_allocator *alloc) {
  return phgmg__reduce_run(out, sys, X, ldx, ns, opts, info, alloc, NULL);
}

PHGMG_DEF void phgmg_reduced_lift(const phgmg_reduced *red, const double *xr, double *x) {
  phgmg_gemv('N', red->N, red->r, 1.0, red->V0, red->N, xr, 0.0, x);
  if (red->kind == PHGMG_ROM_QUADRATIC && (red->eta || red->rn <= 64)) {   /* + V2 eta(x2); rn <= 64 for your eta */
    double q[64];
    phgmg__eta_d(red, xr + red->m, q, NULL, NULL, red->rwork);
    phgmg_gemv('N', red->N, red->rn, 1.0, red->V2, red->N, q, 1.0, x);
  } else if (red->kind == PHGMG_ROM_QUADRATIC) {   /* 64 rows of q at a time: any rn */
    double q[64];
    int i0;
    for (i0 = 0; i0 < red->rn; i0 += 64) {
      const int nb = PHGMG__MIN(64, red->rn - i0);
      phgmg__q_rows(red, xr + red->m, i0, nb, q);
      phgmg_gemv('N', red->N, nb, 1.0, red->V2 + (size_t)red->N * i0, red->N, q, 1.0, x);
    }
  }
  if (red->xbar) phgmg__axpy(red->N, 1.0, red->xbar, x);
}

PHGMG_DEF void phgmg_reduced_restrict(const phgmg_reduced *red, const double *x, double *xr) {
  const int N = red->N, m = red->m, r = red->r;
  if (phgmg__method(red->method)->test_w) {
    phgmg_gemv('T', N, r, 1.0, red->W, N, x, 0.0, xr);
  } else {
    /* [B, V1]^+ x = [RB^{-1} QB^T x; V1^T x]  (V1 is orthogonal to B) */
    int i, j;
    phgmg_gemv('T', N, m, 1.0, red->QB, N, x, 0.0, xr);
    for (i = m - 1; i >= 0; --i) {
      double s = xr[i];
      for (j = i + 1; j < m; ++j) s -= red->RB[i + j * m] * xr[j];
      xr[i] = s / red->RB[i + i * m];
    }
    phgmg_gemv('T', N, r - m, 1.0, red->V0 + (size_t)N * m, N, x, 0.0, xr + m);
  }
  if (red->xbr) phgmg__axpy(r, -1.0, red->xbr, xr);
}

PHGMG_DEF void phgmg_reduced_dphi(const phgmg_reduced *red, const double *xr, double *D, int ldd) {
  const int N = red->N, r = red->r, m = red->m;
  int j;
  for (j = 0; j < r; ++j) memcpy(D + (size_t)j * ldd, red->V0 + (size_t)j * N, (size_t)N * sizeof(double));
  if (red->kind == PHGMG_ROM_QUADRATIC) {
    double Lp[64 * 64];
    const int p = red->p, rn = red->rn;
    int i0, nb;
    if (rn * p <= 64 * 64) {   /* your eta: always (phgmg_reduce) */
      phgmg__eta_d(red, xr + m, NULL, Lp, NULL, red->rwork);
      phgmg_gemm('N', 'N', N, p, rn, 1.0, red->V2, N, Lp, rn, 1.0, D + (size_t)m * ldd, ldd);
      return;
    }
    for (i0 = 0; i0 < rn; i0 += nb) {   /* rows of Lp in blocks of <= 64 * 64 entries: any rn */
      nb = PHGMG__MIN(rn - i0, PHGMG__MAX(1, 64 * 64 / p));
      phgmg__lp_rows(red, xr + m, i0, nb, Lp);
      phgmg_gemm('N', 'N', N, p, nb, 1.0, red->V2 + (size_t)N * i0, N, Lp, nb, 1.0, D + (size_t)m * ldd, ldd);
    }
  }
}

PHGMG_DEF phgmg_result phgmg_reduced_W(const phgmg_reduced *red, const double *xr, double *W, int ldw) {
  const int N = red->N, r = red->r;
  phgmg_jr_factor *jr = NULL;
  const phgmg_allocator *alloc = red->use_alloc ? &red->alloc : NULL;
  double *D, *GtD, *E, *Einv;
  phgmg_result rc;
  int j;
  if (phgmg__method(red->method)->test_w) {
    for (j = 0; j < r; ++j) memcpy(W + (size_t)j * ldw, red->W + (size_t)j * N, (size_t)N * sizeof(double));
    return PHGMG_OK;
  }
  D = phgmg__dalloc(alloc, 2 * (size_t)N * r + 2 * (size_t)r * r);
  if (!D) return PHGMG_ERR_NOMEM;
  GtD = D + (size_t)N * r; E = GtD + (size_t)N * r; Einv = E + (size_t)r * r;
  phgmg_reduced_dphi(red, xr, D, N);
  if (red->sys->E) phgmg__ph_e_apply(red->sys, 'N', r, D, N, GtD, N);   /* descriptor: G_E = E^T G E */
  else memcpy(GtD, D, (size_t)N * r * sizeof(double));
  rc = phgmg__damp_jr_factor(&jr, red->sys, NULL, alloc);   /* dampers: G = (J - R - L)^{-1} */
  if (rc == PHGMG_OK) {
    phgmg_jr_solve(jr, 'T', r, GtD, N);                      /* G^T D */
    if (red->sys->E) {                                       /* E^T G^T E D, column by column */
      for (j = 0; j < r; ++j) {
        phgmg__ph_mtv(red->sys, red->sys->E, GtD + (size_t)j * N, W + (size_t)j * ldw);
        memcpy(GtD + (size_t)j * N, W + (size_t)j * ldw, (size_t)N * sizeof(double));
      }
    }
    phgmg__atb(N, r, r, GtD, D, E);                           /* (G^T D)^T D = D^T G D */
    rc = phgmg__inv(r, E, Einv, alloc);
    if (rc == PHGMG_OK)                                       /* W = G^T D E^{-T} */
      phgmg_gemm('N', 'T', N, r, r, 1.0, GtD, N, Einv, r, 0.0, W, ldw);
  }
  phgmg_jr_factor_destroy(jr);
  phgmg__free(alloc, D);
  return rc;
}

/* >>deploy (implementation) =============================================== */
PHGMG_DEF phgmg_result phgmg_reduced_simulate_run(const phgmg_reduced *red, const phgmg_run *run, double tol,
                                                  int max_iter, phgmg_sim_out *out, const phgmg_allocator *alloc) {
  phgmg_sim_out none;
  phgmg_rom_stats st;
  phgmg_result rc;
  if (!run) return PHGMG_ERR_INVALID_ARG;
  if (!out) { memset(&none, 0, sizeof none); out = &none; }
  memset(&st, 0, sizeof st);
  if (!run->x0 && red) {   /* xr0 = 0 */
    double *z = phgmg__dalloc(alloc, (size_t)phgmg_reduced_rom(red)->r);
    if (!z) return PHGMG_ERR_NOMEM;
    memset(z, 0, sizeof(double) * (size_t)phgmg_reduced_rom(red)->r);
    rc = phgmg_reduced_simulate(red, z, run->t0, run->dt, run->nsteps, run->u, run->user, tol, max_iter, out->X,
                                out->Y, out->energy, &st, alloc);
    phgmg__free(alloc, z);
  } else {
    rc = phgmg_reduced_simulate(red, run->x0, run->t0, run->dt, run->nsteps, run->u, run->user, tol, max_iter,
                                out->X, out->Y, out->energy, &st, alloc);
  }
  out->steps_done = (int)st.steps;   /* the successful steps */
  if (out->rom_stats) *out->rom_stats = st;
  return rc;
}

/* y += Dh u(t) (feedthrough of a reduced model; ubuf: m doubles). */
PHGMG__PRIV void phgmg__feed_out(const phgmg_rom *rom, double t, phgmg_input_fn uf, void *uuser, double *ubuf,
                                 double *y) {
  const int r = rom->r, m = rom->m;
  int a, b;
  uf(t, ubuf, uuser);
  for (a = 0; a < m; ++a)
    for (b = 0; b < m; ++b) y[a] += (double)rom->PD[(size_t)r * m + a + (size_t)b * m] * ubuf[b];
}

PHGMG_DEF phgmg_result phgmg_reduced_simulate(const phgmg_reduced *red, const double *xr0, double t0,
                                              double dt, int nsteps, phgmg_input_fn uf, void *uuser,
                                              double tol, int max_iter, double *XR, double *Y,
                                              const phgmg_energy *energy, phgmg_rom_stats *stats,
                                              const phgmg_allocator *alloc) {
  const phgmg_rom *rom;
  phgmg_rom_stepper st;
  size_t msz, nreal;
  void *mem;
  phgmg_real *x, *u3, *y, *ework, en[2];
  double *ubuf, S = 0.0, D = 0.0;
  int r, m, n, i, a;
  phgmg_result rc;
  if (!red || !xr0 || nsteps < 0 || !(dt > 0.0)) return PHGMG_ERR_INVALID_ARG;
  rom = &red->rom; r = rom->r; m = rom->m;
  msz = phgmg_rom_stepper_memsize_dt(rom, (phgmg_real)dt);
  nreal = (size_t)r + 4 * (size_t)m + phgmg_rom_eval_work_size(rom);
  mem = phgmg__alloc(alloc, ((msz + 15) / 16) * 16 + nreal * sizeof(phgmg_real) + (size_t)m * sizeof(double) + 16);
  if (!mem) return PHGMG_ERR_NOMEM;
  x = PHGMG__CAST(phgmg_real *, PHGMG__CAST(void *, PHGMG__CAST(char *, mem) + ((msz + 15) / 16) * 16));
  u3 = x + r; y = u3 + 3 * m; ework = y + m;
  ubuf = PHGMG__CAST(double *, PHGMG__CAST(void *, PHGMG__CAST(char *, mem) + ((msz + 15) / 16) * 16 +
                                                    ((nreal * sizeof(phgmg_real) + 15) / 16) * 16));
  rc = phgmg_rom_stepper_init(&st, rom, (phgmg_real)dt, (phgmg_real)tol, max_iter, mem, msz);
  if (rc != PHGMG_OK) { phgmg__free(alloc, mem); return rc; }
  for (a = 0; a < r; ++a) x[a] = (phgmg_real)xr0[a];
#define PHGMG__REC(nn) do { \
    if (XR) for (a = 0; a < r; ++a) XR[a + (size_t)(nn) * r] = (double)x[a]; \
    if (Y) { phgmg_rom_output(rom, x, y, ework); for (a = 0; a < m; ++a) Y[a + (size_t)(nn) * m] = (double)y[a]; \
             if (rom->PD && uf) phgmg__feed_out(rom, t0 + (nn) * dt, uf, uuser, ubuf, Y + (size_t)(nn) * m); } \
    if (energy) { energy->H[nn] = (double)phgmg_rom_hamiltonian(rom, x, ework); energy->S[nn] = S; energy->D[nn] = D; } \
  } while (0)
  PHGMG__REC(0);
  for (n = 0; n < nsteps; ++n) {
    const double t = t0 + n * dt;
    const double s15 = sqrt(15.0) / 10.0, cs[3] = {0.5 - s15, 0.5, 0.5 + s15};
    for (i = 0; i < 3; ++i) {
      if (uf) {
        uf(t + cs[i] * dt, ubuf, uuser);
        for (a = 0; a < m; ++a) u3[i * m + a] = (phgmg_real)ubuf[a];
      } else {
        for (a = 0; a < m; ++a) u3[i * m + a] = (phgmg_real)0;
      }
    }
    en[0] = en[1] = (phgmg_real)0;
    rc = phgmg_rom_step(&st, x, u3, NULL, energy ? en : NULL);
    if (rc != PHGMG_OK) break;
    S += (double)en[0];
    D += (double)en[1];
    PHGMG__REC(n + 1);
  }
#undef PHGMG__REC
  if (stats) *stats = st.stats;
  phgmg__free(alloc, mem);
  return rc;
}

PHGMG__PRIV phgmg_result phgmg__err_map_rc(const phgmg_reduced *red, const double *X, int ldx, int ns,
                                           const double *XR, int ldxr, int mode, double *e);

/* phgmg_reduced_validate's measures all finite? PHGMG_OK if so; else
   PHGMG_ERR_NANINF when a Hamiltonian value is NaN (full model Hf over nf
   points, reduced H over nr) at states of ordinary size (the full model's
   states X, N x nf, all below 1e100 in magnitude), PHGMG_ERR_OVERFLOW
   otherwise: the states are so large that their energies (quadratic in the
   states) or the error measures leave the double range. */
PHGMG__PRIV phgmg_result phgmg__validate_finite(const phgmg_validation *v, const double *X, int N,
                                                const double *Hf, int nf, const double *H, int nr) {
  int j, nan = 0;
  size_t q;
  if (isfinite(v->e_red) && isfinite(v->e_y) && isfinite(v->e_proj) && isfinite(v->e_energy) &&
      isfinite(v->e_energy_fom))
    return PHGMG_OK;
  for (j = 0; j < nf; ++j) nan |= Hf[j] != Hf[j];
  for (j = 0; j < nr; ++j) nan |= H[j] != H[j];
  for (q = 0; nan && q < (size_t)N * nf; ++q) if (!(fabs(X[q]) < 1e100)) nan = 0;
  return nan ? PHGMG_ERR_NANINF : PHGMG_ERR_OVERFLOW;
}

PHGMG_DEF phgmg_result phgmg_reduced_validate(const phgmg_reduced *red, const phgmg_ph_system *sys,
                                              const phgmg_run *run, double tol, int max_iter, double ey_max,
                                              phgmg_validation *v, const phgmg_allocator *alloc) {
  int N, m, r, ns, k, done, j;
  size_t nb;
  double *buf, *X, *Y, *XR, *YR, *xr0, *H, *S, *D, *Hf, *Sf, *Df;
  phgmg_energy ef, er;
  phgmg_gl3_opts go;
  phgmg_result rc;
  if (!v) return PHGMG_ERR_INVALID_ARG;
  memset(v, 0, sizeof *v);
  v->first_failure = -1;
  if (!red || !sys || !run) return PHGMG_ERR_INVALID_ARG;
  if (phgmg_runs_columns(1, run) < 0 || run->nsteps < 1 || !(tol < 1.0) || ey_max != ey_max)
    return PHGMG_ERR_INVALID_ARG;
  N = red->N; m = red->m; r = red->r; ns = run->nsteps + 1;
  if (sys->N != N || sys->m != m) return PHGMG_ERR_SIZE;
  nb = (size_t)N * ns + (size_t)m * ns * 2 + (size_t)r * ns + (size_t)r + 6 * (size_t)ns + (size_t)N;
  buf = phgmg__dalloc(alloc, nb);
  if (!buf) return PHGMG_ERR_NOMEM;
  X = buf; Y = X + (size_t)N * ns; YR = Y + (size_t)m * ns; XR = YR + (size_t)m * ns; xr0 = XR + (size_t)r * ns;
  H = xr0 + r; S = H + ns; D = S + ns; Hf = D + ns; Sf = Hf + ns; Df = Sf + ns;
  memset(Df + ns, 0, (size_t)N * sizeof(double));    /* x0 = 0 when run->x0 is NULL */
  ef.H = Hf; ef.S = Sf; ef.D = Df; er.H = H; er.S = S; er.D = D;
  memset(&go, 0, sizeof go);
  go.tol = tol > 0.0 ? tol : 1e-10;
  go.max_iter = max_iter > 0 ? max_iter : 20;
  rc = phgmg_simulate(sys, run->x0 ? run->x0 : Df + ns, run->t0, run->dt, run->nsteps, run->u, run->user, &go, X, Y,
                      &ef, NULL, NULL, alloc);
  if (rc != PHGMG_OK) { phgmg__free(alloc, buf); return rc; }
  for (k = 0; k < r * ns; ++k) XR[k] = (double)NAN;
  phgmg_reduced_restrict(red, X, xr0);
  v->rom_rc = phgmg_reduced_simulate(red, xr0, run->t0, run->dt, run->nsteps, run->u, run->user,
                                     tol > 0.0 ? tol : 0.0, go.max_iter, XR, YR, &er, &v->stats, alloc);
  if (v->rom_rc == PHGMG_ERR_NOMEM) { phgmg__free(alloc, buf); return PHGMG_ERR_NOMEM; }
  for (done = 0; done + 1 < ns && XR[(size_t)(done + 1) * r] == XR[(size_t)(done + 1) * r]; ++done) {}
  v->nsteps = run->nsteps;
  v->steps_done = v->rom_rc == PHGMG_OK ? run->nsteps : done;
  if (v->rom_rc != PHGMG_OK) v->first_failure = v->steps_done;
  rc = phgmg__err_map_rc(red, X, N, v->steps_done + 1, XR, r, 0, &v->e_red);
  if (rc == PHGMG_OK) rc = phgmg__err_map_rc(red, X, N, ns, NULL, 0, 1, &v->e_proj);
  if (rc != PHGMG_OK) { phgmg__free(alloc, buf); return rc; }
  v->e_y = phgmg_rel_error(m, v->steps_done + 1, Y, m, YR, m);
  for (j = 0; j < ns; ++j) {
    const double efj = fabs(Hf[j] - Hf[0] - Sf[j] + Df[j]);
    if (!(efj <= v->e_energy_fom)) v->e_energy_fom = efj;
    if (j <= v->steps_done) {
      const double erj = fabs(H[j] - H[0] - S[j] + D[j]);
      if (!(erj <= v->e_energy)) v->e_energy = erj;
    }
    for (k = 0; k < m; ++k) v->y_scale = PHGMG__MAX(v->y_scale, fabs(Y[k + (size_t)j * m]));
  }
  rc = phgmg__validate_finite(v, X, N, Hf, ns, H, v->steps_done + 1);
  v->pass = rc == PHGMG_OK && v->rom_rc == PHGMG_OK && v->stats.failures == 0 && (ey_max <= 0.0 || v->e_y <= ey_max);
  phgmg__free(alloc, buf);
  return rc;
}

/* --- error measures ------------------------------------------------------ */
/* Do plain sums of squares num, den need the scaled second pass (an
   overflow, or squares near the underflow threshold)? */
#define PHGMG__SSQ_RESCALE(num, den) (!((den) > 1e-280 && (den) < 1e280 && (num) < 1e280))

/* >>errors (implementation) =============================================== */
/* sqrt(num / den) of the error measures (den 0: 0 if num is 0, else Inf). */
PHGMG__PRIV double phgmg__err_ratio(double num, double den) {
  return den > 0.0 ? sqrt(num / den) : (num > 0.0 ? (double)INFINITY : 0.0);
}

PHGMG_DEF double phgmg_rel_error(int n, int ns, const double *A, int lda, const double *B, int ldb) {
  double num = 0.0, den = 0.0, amax = 0.0, s;
  int i, j;
  for (j = 0; j < ns; ++j)
    for (i = 0; i < n; ++i) {
      const double a = A[i + (size_t)j * lda], b = B[i + (size_t)j * ldb], d = a - b;
      num += d * d;
      den += a * a;
      amax = PHGMG__MAX(amax, PHGMG__MAX(fabs(a), fabs(b)));
    }
  if (!PHGMG__SSQ_RESCALE(num, den) || num != num || den != den || !(amax > 0.0 && amax < HUGE_VAL))
    return phgmg__err_ratio(num, den);
  /* second pass on the data scaled by a power of two (exact): the ratio of
     the sums does not depend on the data's magnitude */
  s = phgmg__pow2_scale(amax);
  num = den = 0.0;
  for (j = 0; j < ns; ++j)
    for (i = 0; i < n; ++i) {
      const double a = s * A[i + (size_t)j * lda], d = a - s * B[i + (size_t)j * ldb];
      num += d * d;
      den += a * a;
    }
  return phgmg__err_ratio(num, den);
}

/* Columns per block of the error measures: GEMMs of N x 64 blocks, bounded
   workspace (N x 64 + small). */
#define PHGMG__ERR_NB 64

/* Xt = g(X) for nb columns of X as block operations (mode as phgmg__err_map);
   C: (r + rn) x nb, Qb: 64 x nb. */
PHGMG__PRIV void phgmg__err_map_block(const phgmg_reduced *red, const double *X, int ldx, int nb,
                                      const double *XR, int ldxr, int mode, double *Xt, double *C,
                                      double *Qb) {
  const int N = red->N, r = red->r, m = red->m, rn = red->rn;
  int i, j, k;
  if (mode == 2) { /* x - (I - P_{V2})(I - P_{V1})(I - P_{QB}) x, as in orth_remove */
    for (k = 0; k < nb; ++k) memcpy(Xt + (size_t)k * N, X + (size_t)k * ldx, (size_t)N * sizeof(double));
    for (k = 0; red->xbar && k < nb; ++k) phgmg__axpy(N, -1.0, red->xbar, Xt + (size_t)k * N);
    phgmg__orth_remove(N, m, red->QB, nb, Xt, N, C);
    phgmg__orth_remove(N, r - m, red->V0 + (size_t)N * m, nb, Xt, N, C);
    phgmg__orth_remove(N, rn, red->V2, nb, Xt, N, C);
    for (k = 0; k < nb; ++k)
      for (i = 0; i < N; ++i) Xt[i + (size_t)k * N] = X[i + (size_t)k * ldx] - Xt[i + (size_t)k * N];
    return;
  }
  if (mode == 1) { /* C = rho(X), as phgmg_reduced_restrict */
    if (red->method == PHGMG_METHOD_SP1 || red->method == PHGMG_METHOD_SP2) {
      phgmg_gemm('T', 'N', r, nb, N, 1.0, red->W, N, X, ldx, 0.0, C, r);
    } else {
      phgmg_gemm('T', 'N', m, nb, N, 1.0, red->QB, N, X, ldx, 0.0, C, r);
      for (k = 0; k < nb; ++k) { /* RB^{-1} on the first m coordinates */
        double *xr = C + (size_t)k * r;
        for (i = m - 1; i >= 0; --i) {
          double sm = xr[i];
          for (j = i + 1; j < m; ++j) sm -= red->RB[i + j * m] * xr[j];
          xr[i] = sm / red->RB[i + i * m];
        }
      }
      phgmg_gemm('T', 'N', r - m, nb, N, 1.0, red->V0 + (size_t)N * m, N, X, ldx, 0.0, C + m, r);
    }
    for (k = 0; red->xbr && k < nb; ++k) phgmg__axpy(r, -1.0, red->xbr, C + (size_t)k * r);
    XR = C;
    ldxr = r;
  }
  /* Xt = phi(XR), as phgmg_reduced_lift */
  phgmg_gemm('N', 'N', N, nb, r, 1.0, red->V0, N, XR, ldxr, 0.0, Xt, N);
  if (red->kind == PHGMG_ROM_QUADRATIC) {
    const int p = red->p, rq = rn;
    int a;
    for (k = 0; k < nb; ++k) {
      const double *x2 = XR + (size_t)k * ldxr + m;
      if (red->eta) {   /* the caller's eta */
        phgmg__eta_d(red, x2, Qb + (size_t)k * rq, NULL, NULL, red->rwork);
        continue;
      }
      for (i = 0; i < rq; ++i) {
        double sm = 0.0;
        for (a = 0; a < p; ++a)
          for (j = 0; j < p; ++j) sm += red->M[i + (size_t)(a * p + j) * rn] * x2[a] * x2[j];
        Qb[i + (size_t)k * rq] = sm;
      }
    }
    phgmg_gemm('N', 'N', N, nb, rq, 1.0, red->V2, N, Qb, rq, 1.0, Xt, N);
  }
  for (k = 0; red->xbar && k < nb; ++k) phgmg__axpy(N, 1.0, red->xbar, Xt + (size_t)k * N);
}

/* The sums of phgmg__err_map over all blocks with the differences and
   states scaled by s (s = 1: plain); *amax = the largest |x_i|, |g(x_i)|. */
PHGMG__PRIV void phgmg__err_map_sums(const phgmg_reduced *red, const double *X, int ldx, int ns,
                                     const double *XR, int ldxr, int mode, double s, double *Xt, double *C,
                                     double *Qb, double *num, double *den, double *amax) {
  const int N = red->N, nbmax = PHGMG__MIN(ns, PHGMG__ERR_NB);
  double sn = 0.0, sd = 0.0, am = 0.0;
  int i, j0, k;
  for (j0 = 0; j0 < ns; j0 += nbmax) {
    const int nb = PHGMG__MIN(nbmax, ns - j0);
    const double *Xb = X + (size_t)j0 * ldx;
    phgmg__err_map_block(red, Xb, ldx, nb, XR ? XR + (size_t)j0 * ldxr : NULL, ldxr, mode, Xt, C, Qb);
    for (k = 0; k < nb; ++k) {
      const double *x = Xb + (size_t)k * ldx, *xt = Xt + (size_t)k * N;
      if (s == 1.0) {
        for (i = 0; i < N; ++i) {
          const double d = x[i] - xt[i];
          sn += d * d;
          sd += x[i] * x[i];
          am = PHGMG__MAX(am, PHGMG__MAX(fabs(x[i]), fabs(xt[i])));
        }
      } else {
        for (i = 0; i < N; ++i) {
          const double xs = s * x[i], d = xs - s * xt[i];
          sn += d * d;
          sd += xs * xs;
        }
      }
    }
  }
  *num = sn; *den = sd; *amax = am;
}

/* sqrt(sum ||x_i - g(x_i)||^2 / sum ||x_i||^2) with g applied column-wise,
   PHGMG__ERR_NB columns at a time (GEMM instead of per-column GEMV).
   mode 0: g(x_i) = phi(XR_i); 1: phi(rho(x_i)); 2: orthogonal projection on
   [B, V1, V2]. Plain sums of squares; when they overflow or come near the
   underflow threshold, a second pass sums the values scaled by a power of
   two (exact), so the measure does not depend on the data's magnitude.
   *e = the measure; PHGMG_ERR_NOMEM (then *e = NaN) or PHGMG_OK. */
PHGMG__PRIV phgmg_result phgmg__err_map_rc(const phgmg_reduced *red, const double *X, int ldx, int ns,
                                           const double *XR, int ldxr, int mode, double *e) {
  const int N = red->N, r = red->r, nbmax = PHGMG__MIN(ns, PHGMG__ERR_NB);
  const phgmg_allocator *alloc = red->use_alloc ? &red->alloc : NULL;
  double *Xt, *C, *Qb, num = 0.0, den = 0.0, amax = 0.0;
  *e = 0.0;
  if (ns < 1) return PHGMG_OK;
  Xt = phgmg__dalloc(alloc, (size_t)nbmax * ((size_t)N + (size_t)(r + red->rn) + (size_t)red->rn));
  if (!Xt) { *e = (double)NAN; return PHGMG_ERR_NOMEM; }
  C = Xt + (size_t)N * nbmax;
  Qb = C + (size_t)(r + red->rn) * nbmax;
  phgmg__err_map_sums(red, X, ldx, ns, XR, ldxr, mode, 1.0, Xt, C, Qb, &num, &den, &amax);
  if (PHGMG__SSQ_RESCALE(num, den) && num == num && amax > 0.0 && amax < HUGE_VAL)
    phgmg__err_map_sums(red, X, ldx, ns, XR, ldxr, mode, phgmg__pow2_scale(amax), Xt, C, Qb, &num, &den, &amax);
  phgmg__free(alloc, Xt);
  *e = den > 0.0 ? sqrt(num / den) : 0.0;
  return PHGMG_OK;
}

PHGMG__PRIV double phgmg__err_map(const phgmg_reduced *red, const double *X, int ldx, int ns,
                                  const double *XR, int ldxr, int mode) {
  double e;
  (void)phgmg__err_map_rc(red, X, ldx, ns, XR, ldxr, mode, &e);
  return e;
}

PHGMG_DEF double phgmg_err_red(const phgmg_reduced *red, const double *X, int ldx, int ns,
                               const double *XR, int ldxr) {
  return phgmg__err_map(red, X, ldx, ns, XR, ldxr, 0);
}
PHGMG_DEF double phgmg_err_proj(const phgmg_reduced *red, const double *X, int ldx, int ns) {
  return phgmg__err_map(red, X, ldx, ns, NULL, 0, 1);
}
PHGMG_DEF double phgmg_err_lowerbound(const phgmg_reduced *red, const double *X, int ldx, int ns) {
  if (red->kind != PHGMG_ROM_QUADRATIC) return (double)NAN;
  return phgmg__err_map(red, X, ldx, ns, NULL, 0, 2);
}
PHGMG_DEF void phgmg_err_energy(const phgmg_energy *energy, int nsteps, double *e) {
  int n;
  for (n = 0; n <= nsteps; ++n) e[n] = fabs(energy->H[n] - energy->H[0] - energy->S[n] + energy->D[n]);
}

/* >>study (implementation) ================================================ */
PHGMG_DEF void phgmg_study_destroy(phgmg_study *st) {
  phgmg_allocator a;
  const phgmg_allocator *al;
  if (!st) return;
  a = st->alloc;
  al = st->use_alloc ? &a : NULL;
  phgmg__free(al, st->QB); phgmg__free(al, st->Ua); phgmg__free(al, st->Up); phgmg__free(al, st->Ug);
  phgmg__free(al, st->deim_pts); phgmg__free(al, st->deim_w);
  phgmg__free(al, st->Yt); phgmg__free(al, st->Yp); phgmg__free(al, st->cv);
  phgmg__free(al, st);
}

PHGMG_DEF const double *phgmg_study_basis(const phgmg_study *st, char which, int *cols) {
  const double *b = NULL;
  int k = 0;
  if (st && which == 'a') { b = st->Ua; k = st->ka; }
  if (st && which == 'p') { b = st->Up; k = st->kp; }
  if (st && which == 'g') { b = st->Ug; k = st->kg; }
  if (cols) *cols = b ? k : 0;
  return b;
}

/* POD of T (N x ns, ld N; destroyed) into U (N x kmax): *k = modes with
   sigma > rfloor; C = U^T T (k x ns); tails Tl[j] = ||T - U_1..j C_1..j||_F^2
   (j = 0..k) from the residual of all k modes plus squared coordinates. */
PHGMG__PRIV phgmg_result phgmg__study_pod(const phgmg_study *st, double *T, int kmax, double rfloor, double *U,
                                          int *k, double *C, double *Tl, const phgmg_allocator *alloc) {
  const int N = st->N, ns = st->ns;
  double *S = phgmg__dalloc(alloc, (size_t)kmax);
  int j, i;
  phgmg_result rc;
  if (!S) return PHGMG_ERR_NOMEM;
  rc = phgmg_pod(N, ns, T, N, kmax, 0.0, U, N, S, k, alloc);
  for (j = 0; rc == PHGMG_OK && j < *k; ++j)
    if (!(S[j] > rfloor)) { *k = j; break; }
  phgmg__free(alloc, S);
  if (rc != PHGMG_OK) return rc;
  if (*k < 1) return PHGMG_ERR_SIZE;
  phgmg_gemm('T', 'N', *k, ns, N, 1.0, U, N, T, N, 0.0, C, *k);
  if (!Tl) return PHGMG_OK;
  phgmg_gemm('N', 'N', N, ns, *k, -1.0, U, N, C, *k, 1.0, T, N);   /* T = residual of all k modes */
  Tl[*k] = phgmg__sumsq(N, ns, T, N);
  for (j = *k - 1; j >= 0; --j) {
    double s = 0.0;
    for (i = 0; i < ns; ++i) s += C[j + (size_t)i * *k] * C[j + (size_t)i * *k];
    Tl[j] = Tl[j + 1] + s;
  }
  return PHGMG_OK;
}

/* GMG part: Ua, Ca = Ua^T Xa, CB = QB^T X, tails Ta, Gf, Qf. T: N x ns scratch. */
PHGMG__PRIV phgmg_result phgmg__study_gmg(phgmg_study *st, int kmax, double *T, const phgmg_allocator *alloc) {
  const int N = st->N, m = st->m, ns = st->ns;
  const size_t nf = (size_t)m + (size_t)kmax;
  double *V, *GV;
  phgmg_jr_factor *jr = NULL;
  phgmg_result rc;
  st->Ua = phgmg__dalloc(alloc, (size_t)N * kmax + (size_t)kmax * ns + (size_t)m * ns + (size_t)kmax + 1 + 2 * nf * nf);
  if (!st->Ua) return PHGMG_ERR_NOMEM;
  st->Ca = st->Ua + (size_t)N * kmax; st->CB = st->Ca + (size_t)kmax * ns; st->Ta = st->CB + (size_t)m * ns;
  st->Gf = st->Ta + kmax + 1; st->Qf = st->Gf + nf * nf;
  rc = phgmg_adjust_snapshots(N, m, st->sys->B, ns, st->X, st->ldx, T, N, alloc);
  if (rc == PHGMG_OK)
    rc = phgmg__study_pod(st, T, kmax, phgmg__rank_floor(N, ns, st->X, st->ldx), st->Ua, &st->ka, st->Ca, st->Ta, alloc);
  if (rc != PHGMG_OK) return rc;
  phgmg_gemm('T', 'N', m, ns, N, 1.0, st->QB, N, st->X, st->ldx, 0.0, st->CB, m);
  /* [B, Ua]^T G [B, Ua] and [B, Ua]^T Q [B, Ua] (ld m + ka) */
  V = phgmg__dalloc(alloc, 2 * (size_t)N * (m + st->ka));
  if (!V) return PHGMG_ERR_NOMEM;
  GV = V + (size_t)N * (m + st->ka);
  memcpy(V, st->sys->B, (size_t)N * m * sizeof(double));
  memcpy(V + (size_t)N * m, st->Ua, (size_t)N * st->ka * sizeof(double));
  memcpy(GV, V, (size_t)N * (m + st->ka) * sizeof(double));
  rc = phgmg_jr_factor_create(&jr, st->sys, NULL, alloc);
  if (rc == PHGMG_OK) {
    phgmg_jr_solve(jr, 'N', m + st->ka, GV, N);
    phgmg__atb(N, m + st->ka, m + st->ka, V, GV, st->Gf);
    phgmg_ph_apply(st->sys, 'Q', m + st->ka, V, N, GV, N);
    phgmg__atb(N, m + st->ka, m + st->ka, V, GV, st->Qf);
  }
  phgmg_jr_factor_destroy(jr);
  phgmg__free(alloc, V);
  return rc;
}

/* SP part: Up, Cp = Up^T X, tails Tp, Cq = (Q Up)^T X; with SP2 also Ug
   (POD of the gradient snapshots) and Cg = Ug^T X. T: N x ns scratch. */
PHGMG__PRIV phgmg_result phgmg__study_sp(phgmg_study *st, int kmax, int sp2, double *T, const phgmg_allocator *alloc) {
  const int N = st->N, ns = st->ns;
  int j;
  phgmg_result rc;
  st->Up = phgmg__dalloc(alloc, (size_t)N * kmax + 2 * (size_t)kmax * ns + (size_t)kmax + 1);
  if (!st->Up) return PHGMG_ERR_NOMEM;
  st->Cp = st->Up + (size_t)N * kmax; st->Cq = st->Cp + (size_t)kmax * ns; st->Tp = st->Cq + (size_t)kmax * ns;
  for (j = 0; j < ns; ++j) memcpy(T + (size_t)j * N, st->X + (size_t)j * st->ldx, (size_t)N * sizeof(double));
  rc = phgmg__study_pod(st, T, kmax, phgmg__rank_floor(N, ns, st->X, st->ldx), st->Up, &st->kp, st->Cp, st->Tp, alloc);
  if (rc != PHGMG_OK) return rc;
  phgmg_ph_apply(st->sys, 'Q', st->kp, st->Up, N, T, N);                /* Q Up */
  phgmg_gemm('T', 'N', st->kp, ns, N, 1.0, T, N, st->X, st->ldx, 0.0, st->Cq, st->kp);
  if (!sp2) return PHGMG_OK;
  st->Ug = phgmg__dalloc(alloc, (size_t)N * kmax + (size_t)kmax * ns);
  if (!st->Ug) return PHGMG_ERR_NOMEM;
  st->Cg = st->Ug + (size_t)N * kmax;
  for (j = 0; j < ns; ++j) phgmg_ph_gradient(st->sys, st->X + (size_t)j * st->ldx, T + (size_t)j * N);
  rc = phgmg__study_pod(st, T, kmax, phgmg__rank_floor(N, ns, T, N), st->Ug, &st->kg, st->Cg, NULL, alloc);
  if (rc == PHGMG_OK)   /* Cg = Ug^T X (the coordinates above were of the gradients) */
    phgmg_gemm('T', 'N', st->kg, ns, N, 1.0, st->Ug, N, st->X, st->ldx, 0.0, st->Cg, st->kg);
  return rc;
}

PHGMG_DEF phgmg_result phgmg_study_create(phgmg_study **out, const phgmg_ph_system *sys, const double *X,
                                          int ldx, int ns, const phgmg_study_opts *so,
                                          const phgmg_allocator *alloc) {
  phgmg_study *st;
  unsigned what;
  double *T;
  int N;
  phgmg_result rc;
  if (!out) return PHGMG_ERR_INVALID_ARG;
  *out = NULL;
  if (sys && (sys->E || sys->P || sys->S || sys->Nskew)) return PHGMG_ERR_UNSUPPORTED; /* standard form only */
  if (!sys || !X || !so) return PHGMG_ERR_INVALID_ARG;
  if (so->what & ~(PHGMG_STUDY_GMG | PHGMG_STUDY_SP | PHGMG_STUDY_SP2)) return PHGMG_ERR_INVALID_ARG;
  what = so->what ? so->what : (PHGMG_STUDY_GMG | PHGMG_STUDY_SP);
  if (what & PHGMG_STUDY_SP2) what |= PHGMG_STUDY_SP;
  N = sys->N;
  if (N < 1 || sys->m < 1 || ns < 1 || ldx < N || so->kmax < 1 || so->kmax > PHGMG__MIN(N, ns)) return PHGMG_ERR_SIZE;
  if (!phgmg__mat_finite(N, ns, X, ldx)) return PHGMG_ERR_NANINF;
  rc = phgmg_ph_validate(sys, 0.0, NULL, alloc);
  if (rc != PHGMG_OK) return rc;
  st = PHGMG__CAST(phgmg_study *, phgmg__alloc(alloc, sizeof(phgmg_study)));
  if (!st) return PHGMG_ERR_NOMEM;
  memset(st, 0, sizeof *st);
  if (alloc) { st->alloc = *alloc; st->use_alloc = 1; }
  st->sys = sys; st->X = X; st->ldx = ldx; st->ns = ns; st->N = N; st->m = sys->m;
  st->fp = phgmg__sys_fingerprint(sys);
  st->xx = phgmg__sumsq(N, ns, X, ldx);
  st->QB = phgmg__dalloc(alloc, (size_t)N * sys->m + (size_t)sys->m * sys->m);
  T = phgmg__dalloc(alloc, (size_t)N * ns);
  rc = st->QB && T ? PHGMG_OK : PHGMG_ERR_NOMEM;
  if (rc == PHGMG_OK) {
    st->RB = st->QB + (size_t)N * sys->m;
    rc = phgmg__thin_qr(N, sys->m, sys->B, st->QB, st->RB, alloc);
  }
  if (rc == PHGMG_OK && (what & PHGMG_STUDY_GMG)) rc = phgmg__study_gmg(st, so->kmax, T, alloc);
  if (rc == PHGMG_OK && (what & PHGMG_STUDY_SP)) rc = phgmg__study_sp(st, so->kmax, (what & PHGMG_STUDY_SP2) != 0, T, alloc);
  phgmg__free(alloc, T);
  if (rc != PHGMG_OK) { phgmg_study_destroy(st); return rc; }
  *out = st;
  return PHGMG_OK;
}

/* The study's DEIM points for opts (computed at the first use, kept while
   tol, cap and point selection are the same). 0 if not applicable or failed
   (phgmg_reduce then computes and reports). */
PHGMG__PRIV int phgmg__study_deim(phgmg_study *st, const phgmg_reduce_opts *o) {
  const phgmg_ph_system *sys = st->sys;
  const phgmg_allocator *alloc = st->use_alloc ? &st->alloc : NULL;
  const int nt = sys->nsep, ns = st->ns;
  phgmg_deim_method meth;
  double *F;
  int a, i;
  phgmg_result rc;
  if (o->hyper.on != 1 || o->cache.deim_pts || sys->nl != PHGMG_NL_SEPARABLE || nt < 1 ||
      (int)o->hyper.kind < 0 || (int)o->hyper.kind >= (int)PHGMG_HYPER_COUNT ||
      phgmg__hypers[o->hyper.kind].quadrature || !(o->hyper.deim_tol >= 0.0 && o->hyper.deim_tol < 1.0))
    return 0;
  meth = phgmg__hypers[o->hyper.kind].points;
  if (st->deim_have && st->deim_tol == o->hyper.deim_tol && st->deim_max == o->hyper.deim_max && st->deim_method == (int)meth) return 1;
  st->deim_have = 0;
  if (!st->deim_pts) st->deim_pts = phgmg__ialloc(alloc, (size_t)nt);
  if (!st->deim_w) st->deim_w = phgmg__dalloc(alloc, (size_t)nt);
  F = phgmg__dalloc(alloc, (size_t)nt * ns);
  if (!st->deim_pts || !st->deim_w || !F) { phgmg__free(alloc, F); return 0; }
  for (i = 0; i < ns; ++i)
    for (a = 0; a < nt; ++a)
      F[a + (size_t)i * nt] = phgmg__ph_phi(sys, a, st->X[sys->sep_idx[a] + (size_t)i * st->ldx], 1);
  rc = phgmg_deim_select(nt, ns, F, nt, sys->sep_w, o->hyper.deim_tol, o->hyper.deim_max, meth, st->deim_pts, st->deim_w,
                         &st->deim_nd, &st->deim_nneg, &st->deim_sigma, alloc);
  phgmg__free(alloc, F);
  if (rc != PHGMG_OK) return 0;
  st->deim_have = 1; st->deim_tol = o->hyper.deim_tol; st->deim_max = o->hyper.deim_max; st->deim_method = (int)meth;
  return 1;
}

PHGMG_DEF phgmg_result phgmg_study_reduce(phgmg_study *st, const phgmg_reduce_opts *opts, phgmg_reduced **out,
                                          phgmg_reduce_info *info) {
  phgmg_reduce_opts o;
  phgmg_result rc;
  int deim;
  if (out) *out = NULL;
  if (!st || !opts || !out) return PHGMG_ERR_INVALID_ARG;
  if (phgmg__sys_fingerprint(st->sys) != st->fp) return PHGMG_ERR_STALE;   /* the blocks would be stale */
  o = *opts;
  phgmg__reduce_opts_resolve(&o, st->ns);
  if ((o.method == PHGMG_METHOD_GMG_POD || o.method == PHGMG_METHOD_GMG_QM) && st->Ua && !o.cache.pod_basis) {
    o.cache.pod_basis = st->Ua; o.cache.pod_cols = st->ka;
  }
  if ((o.method == PHGMG_METHOD_SP1 || o.method == PHGMG_METHOD_SP2) && st->Up && !o.cache.pod_basis) {
    o.cache.pod_basis = st->Up; o.cache.pod_cols = st->kp;
  }
  if (o.method == PHGMG_METHOD_SP2 && st->Ug && !o.cache.grad_basis) { o.cache.grad_basis = st->Ug; o.cache.grad_cols = st->kg; }
  deim = phgmg__study_deim(st, &o);
  if (deim) { o.cache.deim_pts = st->deim_pts; o.cache.deim_w = st->deim_w; o.cache.deim_count = st->deim_nd; }
  rc = phgmg__reduce_run(out, st->sys, st->X, st->ldx, st->ns, &o, info, st->use_alloc ? &st->alloc : NULL, st);
  if (info && deim) { info->deim_sigma_ratio = st->deim_sigma; info->hyper_method = o.hyper.kind; }
  return rc;
}

/* Q (rn x nb) = M (x2_i kron x2_i) of the built-in quadratic map for nb
   points x2_i = X2(:, i) (ld ld2), as one GEMM; K: p^2 x nb scratch. */
PHGMG__PRIV void phgmg__q_block(const phgmg_reduced *red, int nb, const double *X2, int ld2, double *K, double *Q) {
  const int p = red->p, rn = red->rn;
  int i, a, j;
  for (i = 0; i < nb; ++i) {
    const double *x = X2 + (size_t)i * ld2;
    double *k = K + (size_t)i * p * p;
    for (a = 0; a < p; ++a)
      for (j = 0; j < p; ++j) k[a * p + j] = x[a] * x[j];
  }
  phgmg_gemm('N', 'N', rn, nb, p * p, 1.0, red->M, rn, K, p * p, 0.0, Q, rn);
}

/* Squared error sums of a fast-path GMG model, snapshots j0..j0+nb-1:
   x - phi(xr) = (I - P_k) x + QB (QB^T x - RB xr1) + V1 (Ua1^T x - xr2) +
   V2 (Ua2^T x - q(xr2)) with orthonormal [QB, V1, V2], k = p + rn (the tail
   is added by the caller); q by phgmg__q_block. w: p^2 nb + 2 rn nb. */
PHGMG__PRIV void phgmg__study_err_gmg(const phgmg_study *st, const phgmg_reduced *red, const double *XR, int ldxr,
                                      int j0, int nb, double *w, double s[2]) {
  const int m = red->m, p = red->p, rn = red->rn, ka = st->ka;
  double *K = w, *Q1 = K + (size_t)p * p * nb, *Q2 = Q1 + (size_t)rn * nb;
  int i, a, b;
  if (rn) {
    phgmg__q_block(red, nb, st->Ca + (size_t)j0 * ka, ka, K, Q1);
    if (XR) phgmg__q_block(red, nb, XR + (size_t)j0 * ldxr + m, ldxr, K, Q2);
  }
  for (i = 0; i < nb; ++i) {
    const double *ca = st->Ca + (size_t)(j0 + i) * ka, *cb = st->CB + (size_t)(j0 + i) * m;
    for (a = 0; a < rn; ++a) s[1] += (ca[p + a] - Q1[a + (size_t)i * rn]) * (ca[p + a] - Q1[a + (size_t)i * rn]);
    if (XR) {
      const double *xr = XR + (size_t)(j0 + i) * ldxr;
      for (a = 0; a < m; ++a) {
        double d = cb[a];
        for (b = a; b < m; ++b) d -= red->RB[a + b * m] * xr[b];
        s[0] += d * d;
      }
      for (a = 0; a < p; ++a) s[0] += (ca[a] - xr[m + a]) * (ca[a] - xr[m + a]);
      for (a = 0; a < rn; ++a) s[0] += (ca[p + a] - Q2[a + (size_t)i * rn]) * (ca[p + a] - Q2[a + (size_t)i * rn]);
    }
  }
}

/* Squared error sums of a fast-path model over the study's snapshots:
   s[0] (e_red; needs XR), s[1] (e_proj). GMG: phgmg__study_err_gmg; SP:
   x - V xr = (I - P_r) x + V (Up^T x - xr), rho(x) = Ainv^T Vg^T x.
   0 if the workspace cannot be allocated. */
PHGMG__PRIV int phgmg__study_err_sums(const phgmg_study *st, const phgmg_reduced *red, const double *XR, int ldxr,
                                      double s[2]) {
  const int r = red->r, ns = st->ns;
  int i, a, b;
  if (red->sbasis == PHGMG__SF_GMG) {
    const phgmg_allocator *alloc = red->use_alloc ? &red->alloc : NULL;
    const int nbmax = PHGMG__ERR_NB, p = red->p, rn = red->rn;
    double *w = phgmg__dalloc(alloc, (size_t)nbmax * ((size_t)p * p + 2 * (size_t)rn) + 1);
    int j0;
    if (!w) return 0;
    s[0] = s[1] = st->Ta[p + rn];
    for (j0 = 0; j0 < ns; j0 += nbmax)
      phgmg__study_err_gmg(st, red, XR, ldxr, j0, PHGMG__MIN(nbmax, ns - j0), w, s);
    phgmg__free(alloc, w);
    return 1;
  }
  {
    const double *Cv = red->sbasis == PHGMG__SF_SP1 ? st->Cq : st->Cg;
    const int ld = red->sbasis == PHGMG__SF_SP1 ? st->kp : st->kg, kp = st->kp;
    s[0] = s[1] = st->Tp[r];
    for (i = 0; i < ns; ++i) {
      const double *cp = st->Cp + (size_t)i * kp, *cv = Cv + (size_t)i * ld;
      for (a = 0; a < r; ++a) {
        double w = 0.0;
        for (b = 0; b < r; ++b) w += red->Ainv[b + (size_t)a * r] * cv[b];
        s[1] += (cp[a] - w) * (cp[a] - w);
        if (XR) s[0] += (cp[a] - XR[a + (size_t)i * ldxr]) * (cp[a] - XR[a + (size_t)i * ldxr]);
      }
    }
  }
  return 1;
}

PHGMG_DEF phgmg_result phgmg_study_errors(const phgmg_study *st, const phgmg_reduced *red, const double *XR,
                                          int ldxr, double *e_red, double *e_proj, double *e_lower) {
  double s[2];
  if (!st || !red) return PHGMG_ERR_INVALID_ARG;
  if (red->N != st->N || red->m != st->m || (XR && ldxr < red->r)) return PHGMG_ERR_SIZE;
  if (red->study != st || red->sbasis == PHGMG__SF_NONE || red->rn > 64) {
    if (e_red) *e_red = XR ? phgmg_err_red(red, st->X, st->ldx, st->ns, XR, ldxr) : (double)NAN;
    if (e_proj) *e_proj = phgmg_err_proj(red, st->X, st->ldx, st->ns);
    if (e_lower) *e_lower = phgmg_err_lowerbound(red, st->X, st->ldx, st->ns);
    return PHGMG_OK;
  }
  if (!phgmg__study_err_sums(st, red, XR, ldxr, s)) return PHGMG_ERR_NOMEM;
  if (e_red) *e_red = !XR ? (double)NAN : (st->xx > 0.0 ? sqrt(s[0] / st->xx) : 0.0);
  if (e_proj) *e_proj = st->xx > 0.0 ? sqrt(s[1] / st->xx) : 0.0;
  if (e_lower)
    *e_lower = red->kind != PHGMG_ROM_QUADRATIC ? (double)NAN
                                                : (st->xx > 0.0 ? sqrt(st->Ta[red->p + red->rn] / st->xx) : 0.0);
  return PHGMG_OK;
}
#endif /* PHGMG_NO_OFFLINE */

/* >>linear (implementation) ============================================== */
#ifndef PHGMG_NO_OFFLINE

/* One scaled Newton step of the sign function on Z (n x n, in place), with
   the same congruence on E (n x n symmetric, may be NULL): Zi = Z^{-1},
   Z <- (Z/c + c Zi)/2, E <- (E/c + c Zi E Zi^T)/2. *d = ||Z+ - Z||_1 / ||Z+||_1.
   scale = 0: c = 1. work: 3 n^2 doubles. */
PHGMG__PRIV phgmg_result phgmg__sign_step(int n, double *Z, double *E, int scale, double *d, double *work,
                                          const phgmg_allocator *alloc) {
  double *Zi = work, *T = Zi + (size_t)n * n, *T2 = T + (size_t)n * n, c = 1.0, num = 0.0, den = 0.0;
  const size_t nn = (size_t)n * n;
  size_t i;
  phgmg_result rc = phgmg__inv(n, Z, Zi, alloc);
  if (rc != PHGMG_OK) return rc;
  if (!phgmg__all_finite(Zi, nn)) return PHGMG_ERR_NANINF;
  if (scale) c = sqrt(phgmg_normf(n, n, Z, n) / phgmg_normf(n, n, Zi, n));
  if (!(c > 0.0) || !isfinite(c)) c = 1.0;
  if (E) {
    phgmg_gemm('N', 'N', n, n, n, 1.0, Zi, n, E, n, 0.0, T, n);
    phgmg_gemm('N', 'T', n, n, n, 1.0, T, n, Zi, n, 0.0, T2, n);
    for (i = 0; i < nn; ++i) E[i] = 0.5 * (E[i] / c + c * T2[i]);
  }
  for (i = 0; i < nn; ++i) {
    const double zn = 0.5 * (Z[i] / c + c * Zi[i]);
    T[i] = zn - Z[i];
    Z[i] = zn;
  }
  num = phgmg_norm1(n, n, T, n);
  den = phgmg_norm1(n, n, Z, n);
  *d = den > 0.0 ? num / den : (double)INFINITY;
  return PHGMG_OK;
}

/* Sign iteration driver: scaled while d > 1e-2; stop one unscaled step after
   d <= 1e-10, or after d <= 1e-4 stops halving (stagnation at the round-off
   level of an ill-conditioned problem: the callers' residuals tell). */
PHGMG__PRIV phgmg_result phgmg__sign_iter(int n, double *Z, double *E, int *iters, const phgmg_allocator *alloc) {
  double *work = phgmg__dalloc(alloc, 3 * (size_t)n * n), d = 1.0, dprev;
  phgmg_result rc = PHGMG_ERR_NOT_CONVERGED;
  int it, done = 0;
  if (!work) return PHGMG_ERR_NOMEM;
  for (it = 0; it < 100; ++it) {
    phgmg_result s;
    dprev = d;
    s = phgmg__sign_step(n, Z, E, d > 1e-2, &d, work, alloc);
    if (s != PHGMG_OK) { rc = s; break; }
    if (done) { rc = PHGMG_OK; ++it; break; }
    /* converged, or stagnating at the round-off level of an ill-conditioned sign */
    if (d <= 1e-10 || (d <= 1e-4 && dprev <= 1e-2 && d > 0.5 * dprev)) done = 1;
  }
  if (iters) *iters = it;
  phgmg__free(alloc, work);
  return rc;
}

/* ||F - F^T||_F <= tol ||F||_F (F n x n)? */
PHGMG__PRIV int phgmg__sym_within(int n, const double *F, double tol) {
  double d = 0.0;
  int i, j;
  for (j = 0; j < n; ++j)
    for (i = j + 1; i < n; ++i) {
      const double e = F[i + (size_t)j * n] - F[j + (size_t)i * n];
      d += 2.0 * e * e;
    }
  return sqrt(d) <= tol * phgmg_normf(n, n, F, n);
}

PHGMG_DEF phgmg_result phgmg_lyap(int n, const double *A, const double *F, double *X, int *iters,
                                  const phgmg_allocator *alloc) {
  const size_t nn = (size_t)n * n;
  double *Z;
  phgmg_result rc;
  size_t i;
  int j, k;
  if (!A || !F || !X) return PHGMG_ERR_INVALID_ARG;
  if (n < 1) return PHGMG_ERR_SIZE;
  if (!phgmg__all_finite(A, nn) || !phgmg__all_finite(F, nn)) return PHGMG_ERR_NANINF;
  if (!phgmg__sym_within(n, F, 1e-10)) return PHGMG_ERR_INVALID_ARG;
  Z = phgmg__dalloc(alloc, 2 * nn);
  if (!Z) return PHGMG_ERR_NOMEM;
  memcpy(Z, A, nn * sizeof(double));
  memcpy(Z + nn, F, nn * sizeof(double));
  rc = phgmg__sign_iter(n, Z, Z + nn, iters, alloc);
  if (rc == PHGMG_OK) {
    for (i = 0; i < nn; ++i)   /* sign(A) = -I for a stable A */
      if (fabs(Z[i] + ((i % (size_t)n) == i / (size_t)n ? 1.0 : 0.0)) > 1e-6) rc = PHGMG_ERR_SINGULAR;
  }
  if (rc == PHGMG_OK)
    for (k = 0; k < n; ++k)
      for (j = 0; j < n; ++j)
        X[j + (size_t)k * n] = 0.25 * (Z[nn + j + (size_t)k * n] + Z[nn + k + (size_t)j * n]);
  phgmg__free(alloc, Z);
  return rc;
}

PHGMG_DEF phgmg_result phgmg_care(int n, const double *A, const double *K, const double *L, double *X,
                                  int *iters, const phgmg_allocator *alloc) {
  const int n2 = 2 * n;
  const size_t nn = (size_t)n * n;
  double *H, *M, *Rh;
  phgmg_result rc;
  int i, j;
  if (!A || !K || !L || !X) return PHGMG_ERR_INVALID_ARG;
  if (n < 1) return PHGMG_ERR_SIZE;
  if (!phgmg__all_finite(A, nn) || !phgmg__all_finite(K, nn) || !phgmg__all_finite(L, nn)) return PHGMG_ERR_NANINF;
  H = phgmg__dalloc(alloc, 4 * nn + 2 * (size_t)n2 * n);
  if (!H) return PHGMG_ERR_NOMEM;
  M = H + 4 * nn; Rh = M + (size_t)n2 * n;
  for (j = 0; j < n; ++j)
    for (i = 0; i < n; ++i) {
      H[i + (size_t)j * n2] = A[i + (size_t)j * n];
      H[i + (size_t)(j + n) * n2] = -K[i + (size_t)j * n];
      H[(i + n) + (size_t)j * n2] = -L[i + (size_t)j * n];
      H[(i + n) + (size_t)(j + n) * n2] = -A[j + (size_t)i * n];
    }
  rc = phgmg__sign_iter(n2, H, NULL, iters, alloc);
  if (rc == PHGMG_OK) {
    for (j = 0; j < n; ++j)
      for (i = 0; i < n; ++i) {
        M[i + (size_t)j * n2] = H[i + (size_t)(j + n) * n2];                                   /* W12 */
        M[(i + n) + (size_t)j * n2] = H[(i + n) + (size_t)(j + n) * n2] + (i == j ? 1.0 : 0.0); /* W22 + I */
        Rh[i + (size_t)j * n2] = -(H[i + (size_t)j * n2] + (i == j ? 1.0 : 0.0));              /* -(W11 + I) */
        Rh[(i + n) + (size_t)j * n2] = -H[(i + n) + (size_t)j * n2];                          /* -W21 */
      }
    rc = phgmg_lstsq(n2, n, n, M, n2, Rh, n2, 0.0, H, n, alloc);
    /* [W12; W22 + I] rank deficient: the stable invariant subspace of H is
       not a graph [I; X], i.e. no stabilizing solution exists */
    if (rc == PHGMG_ERR_RANK) rc = PHGMG_ERR_NOT_STABILIZABLE;
  }
  if (rc == PHGMG_OK)
    for (j = 0; j < n; ++j)
      for (i = 0; i < n; ++i) X[i + (size_t)j * n] = 0.5 * (H[i + (size_t)j * n] + H[j + (size_t)i * n]);
  phgmg__free(alloc, H);
  return rc;
}

PHGMG_DEF double phgmg_lyap_residual(int n, const double *A, const double *F, const double *X,
                                     const phgmg_allocator *alloc) {
  double *T = phgmg__dalloc(alloc, (size_t)n * n), res;
  if (!T) return (double)NAN;
  memcpy(T, F, (size_t)n * n * sizeof(double));
  phgmg_gemm('N', 'N', n, n, n, 1.0, A, n, X, n, 1.0, T, n);
  phgmg_gemm('N', 'T', n, n, n, 1.0, X, n, A, n, 1.0, T, n);
  res = phgmg_normf(n, n, T, n) /
        (2.0 * phgmg_normf(n, n, A, n) * phgmg_normf(n, n, X, n) + phgmg_normf(n, n, F, n));
  phgmg__free(alloc, T);
  return res;
}

PHGMG_DEF double phgmg_care_residual(int n, const double *A, const double *K, const double *L,
                                     const double *X, const phgmg_allocator *alloc) {
  double *T = phgmg__dalloc(alloc, 2 * (size_t)n * n), *KX, res, nx;
  if (!T) return (double)NAN;
  KX = T + (size_t)n * n;
  memcpy(T, L, (size_t)n * n * sizeof(double));
  phgmg_gemm('T', 'N', n, n, n, 1.0, A, n, X, n, 1.0, T, n);
  phgmg_gemm('N', 'N', n, n, n, 1.0, X, n, A, n, 1.0, T, n);
  phgmg_gemm('N', 'N', n, n, n, 1.0, K, n, X, n, 0.0, KX, n);
  phgmg_gemm('N', 'N', n, n, n, -1.0, X, n, KX, n, 1.0, T, n);
  nx = phgmg_normf(n, n, X, n);
  res = phgmg_normf(n, n, T, n) / (2.0 * phgmg_normf(n, n, A, n) * nx + nx * nx * phgmg_normf(n, n, K, n) +
                                   phgmg_normf(n, n, L, n));
  phgmg__free(alloc, T);
  return res;
}

PHGMG_DEF phgmg_result phgmg_ph_abc(const phgmg_ph_system *sys, double *A, double *C,
                                    const phgmg_allocator *alloc) {
  int N, m, i;
  double *I, *Qd, *T;
  if (!sys) return PHGMG_ERR_INVALID_ARG;
  if (sys && (sys->E || sys->P || sys->S || sys->Nskew)) return PHGMG_ERR_UNSUPPORTED; /* standard form only */
  if (sys->nl != PHGMG_NL_NONE) return PHGMG_ERR_UNSUPPORTED;
  N = sys->N; m = sys->m;
  if (N < 1 || m < 1 || m > N) return PHGMG_ERR_SIZE;
  I = phgmg__dalloc(alloc, 3 * (size_t)N * N);
  if (!I) return PHGMG_ERR_NOMEM;
  Qd = I + (size_t)N * N; T = Qd + (size_t)N * N;
  memset(I, 0, (size_t)N * N * sizeof(double));
  for (i = 0; i < N; ++i) I[i + (size_t)i * N] = 1.0;
  phgmg_ph_apply(sys, 'Q', N, I, N, Qd, N);
  if (A) {
    phgmg_ph_apply(sys, 'J', N, Qd, N, A, N);
    phgmg_ph_apply(sys, 'R', N, Qd, N, T, N);
    for (i = 0; i < N * N; ++i) A[i] -= T[i];
  }
  if (C) phgmg_gemm('T', 'N', m, N, N, 1.0, sys->B, N, Qd, N, 0.0, C, m);
  phgmg__free(alloc, I);
  return PHGMG_OK;
}

/* L with X = L L^T for a symmetric PSD X (n x n): V diag(sqrt(max(w, 0))).
   X is destroyed; L needs n^2 + n doubles. */
PHGMG__PRIV phgmg_result phgmg__psd_sqrt(int n, double *X, double *L) {
  double *ev = L + (size_t)n * n; /* the caller gives L with n^2 + n doubles */
  phgmg_result rc = phgmg_sym_eig(n, X, n, ev, L, n);
  int i, j;
  if (rc != PHGMG_OK) return rc;
  for (j = 0; j < n; ++j) {
    const double s = ev[j] > 0.0 ? sqrt(ev[j]) : 0.0;
    for (i = 0; i < n; ++i) L[i + (size_t)j * n] *= s;
  }
  return PHGMG_OK;
}

/* Square-root balancing of Gramian-like P (controllability) and O: T, W
   (N x r), S (r values). P and O are destroyed. */
PHGMG__PRIV phgmg_result phgmg__balance(int N, int r, double *P, double *O, double *T, double *W, double *S,
                                        const phgmg_allocator *alloc) {
  double *Lp = phgmg__dalloc(alloc, 3 * ((size_t)N * N + N) + 2 * (size_t)N * r + r), *Lo, *M, *U, *Vv, *sv;
  phgmg_result rc;
  int k = 0, rank = 0, i, j;
  if (!Lp) return PHGMG_ERR_NOMEM;
  Lo = Lp + (size_t)N * N + N; M = Lo + (size_t)N * N + N; U = M + (size_t)N * N + N;
  Vv = U + (size_t)N * r; sv = Vv + (size_t)N * r;
  rc = phgmg__psd_sqrt(N, P, Lp);
  if (rc == PHGMG_OK) rc = phgmg__psd_sqrt(N, O, Lo);
  if (rc == PHGMG_OK) {
    memset(M, 0, (size_t)N * N * sizeof(double));
    phgmg_gemm('T', 'N', N, N, N, 1.0, Lo, N, Lp, N, 1.0, M, N);
    rc = phgmg_svd(N, N, M, N, r, sv, U, N, Vv, N, &k, &rank, alloc);
  }
  if (rc == PHGMG_OK && (k < r || !(sv[r - 1] > 0.0))) rc = PHGMG_ERR_RANK;
  if (rc == PHGMG_OK) {
    for (j = 0; j < r; ++j) {
      const double s = 1.0 / sqrt(sv[j]);
      for (i = 0; i < N; ++i) { U[i + (size_t)j * N] *= s; Vv[i + (size_t)j * N] *= s; }
      S[j] = sv[j];
    }
    phgmg_gemm('N', 'N', N, r, N, 1.0, Lp, N, Vv, N, 0.0, T, N);
    phgmg_gemm('N', 'N', N, r, N, 1.0, Lo, N, U, N, 0.0, W, N);
  }
  phgmg__free(alloc, Lp);
  return rc;
}

/* Ar = W^T A T, Br = W^T B, Cr = C T. */
PHGMG__PRIV phgmg_result phgmg__project_abc(int N, int m, int r, const double *A, const double *B, const double *C,
                                            const double *T, const double *W, double *Ar, double *Br, double *Cr,
                                            const phgmg_allocator *alloc) {
  double *AT = phgmg__dalloc(alloc, (size_t)N * r);
  if (!AT) return PHGMG_ERR_NOMEM;
  phgmg_gemm('N', 'N', N, r, N, 1.0, A, N, T, N, 0.0, AT, N);
  phgmg_gemm('T', 'N', r, r, N, 1.0, W, N, AT, N, 0.0, Ar, r);
  phgmg_gemm('T', 'N', r, m, N, 1.0, W, N, B, N, 0.0, Br, r);
  phgmg_gemm('N', 'N', m, r, N, 1.0, C, m, T, N, 0.0, Cr, m);
  phgmg__free(alloc, AT);
  return PHGMG_OK;
}

PHGMG__PRIV phgmg_result phgmg__zschur(int n, const double *A, int lda, double *T, double *Z, double *work);

/* 1 when the diagonal of a complex Schur form T (n x n, ld n) has an
   eigenvalue on the imaginary axis to working precision: Re >= -1e-8 max |lambda|. */
PHGMG__PRIV int phgmg__schur_undamped(int n, const double *T) {
  double amax = 0.0, remax = -HUGE_VAL;
  int i;
  for (i = 0; i < n; ++i) {
    const double re = T[2 * (i + (size_t)i * n)], im = T[2 * (i + (size_t)i * n) + 1];
    amax = PHGMG__MAX(amax, hypot(re, im));
    remax = PHGMG__MAX(remax, re);
  }
  return n > 0 && remax >= -1e-8 * amax;
}

/* After a failed Gramian solve (Lyapunov or Riccati: NOT_CONVERGED or
   SINGULAR) for A = (J - R) Q of a pH system: PHGMG_ERR_NOT_STABLE when A
   has an undamped mode (the eigenvalues of a pH system lie in the closed
   left half plane, so the failure comes from the imaginary axis), else rc.
   Eigenvalues from the complex Schur form, O(N^3), on the failure path only. */
PHGMG__PRIV phgmg_result phgmg__gramian_failure(int n, const double *A, phgmg_result rc, const phgmg_allocator *alloc) {
  double *T;
  if (rc != PHGMG_ERR_NOT_CONVERGED && rc != PHGMG_ERR_SINGULAR) return rc;
  T = phgmg__dalloc(alloc, 4 * (size_t)n * n + 3 * (size_t)n);
  if (!T) return rc;
  if (phgmg__zschur(n, A, n, T, T + 2 * (size_t)n * n, T + 4 * (size_t)n * n) == PHGMG_OK &&
      phgmg__schur_undamped(n, T))
    rc = PHGMG_ERR_NOT_STABLE;
  phgmg__free(alloc, T);
  return rc;
}

PHGMG_DEF phgmg_result phgmg_bt(const phgmg_ph_system *sys, int r, double *Ar, double *Br, double *Cr,
                                double *hsv, double *T, double *W, const phgmg_allocator *alloc) {
  int N, m;
  double *A, *C, *P, *O, *Tb, *Wb, *S;
  phgmg_result rc;
  if (!sys || !Ar || !Br || !Cr) return PHGMG_ERR_INVALID_ARG;
  if (sys && (sys->E || sys->P || sys->S || sys->Nskew)) return PHGMG_ERR_UNSUPPORTED; /* standard form only */
  if (sys->nl != PHGMG_NL_NONE) return PHGMG_ERR_UNSUPPORTED;
  rc = phgmg_ph_validate(sys, 0.0, NULL, alloc);
  if (rc != PHGMG_OK) return rc;
  N = sys->N; m = sys->m;
  if (r < 1 || r > N) return PHGMG_ERR_SIZE;
  A = phgmg__dalloc(alloc, 3 * (size_t)N * N + (size_t)m * N + 2 * (size_t)N * r + r);
  if (!A) return PHGMG_ERR_NOMEM;
  C = A + (size_t)N * N; P = C + (size_t)m * N; O = P + (size_t)N * N; Tb = O + (size_t)N * N;
  Wb = Tb + (size_t)N * r; S = Wb + (size_t)N * r;
  rc = phgmg_ph_abc(sys, A, C, alloc);
  if (rc == PHGMG_OK) {   /* F = B B^T into O, then P; F = C^T C into O */
    phgmg_gemm('N', 'T', N, N, m, 1.0, sys->B, N, sys->B, N, 0.0, O, N);
    rc = phgmg_lyap(N, A, O, P, NULL, alloc);
  }
  if (rc == PHGMG_OK) {
    double *At = phgmg__dalloc(alloc, 2 * (size_t)N * N);   /* A^T and C^T C */
    if (!At) rc = PHGMG_ERR_NOMEM;
    else {
      int i, j;
      for (j = 0; j < N; ++j)
        for (i = 0; i < N; ++i) At[i + (size_t)j * N] = A[j + (size_t)i * N];
      phgmg_gemm('T', 'N', N, N, m, 1.0, C, m, C, m, 0.0, At + (size_t)N * N, N);
      rc = phgmg_lyap(N, At, At + (size_t)N * N, O, NULL, alloc);
      phgmg__free(alloc, At);
    }
  }
  rc = phgmg__gramian_failure(N, A, rc, alloc);
  if (rc == PHGMG_OK) rc = phgmg__balance(N, r, P, O, Tb, Wb, S, alloc);
  if (rc == PHGMG_OK) rc = phgmg__project_abc(N, m, r, A, sys->B, C, Tb, Wb, Ar, Br, Cr, alloc);
  if (rc == PHGMG_OK) {
    if (hsv) memcpy(hsv, S, (size_t)r * sizeof(double));
    if (T) memcpy(T, Tb, (size_t)N * r * sizeof(double));
    if (W) memcpy(W, Wb, (size_t)N * r * sizeof(double));
  }
  phgmg__free(alloc, A);
  return rc;
}

/* The two positive-real Riccati solutions (minimal, stabilizing) with
   S = s I: X (Q-eq) and Y (P-eq). */
PHGMG__PRIV phgmg_result phgmg__pr_riccati(int N, int m, const double *A, const double *B, const double *C, double s,
                                           double *X, double *Y, const phgmg_allocator *alloc) {
  const size_t nn = (size_t)N * N;
  double *At = phgmg__dalloc(alloc, 4 * nn), *K, *L, *Att;
  phgmg_result rc;
  int i, j;
  if (!At) return PHGMG_ERR_NOMEM;
  K = At + nn; L = K + nn; Att = L + nn;
  memcpy(At, A, nn * sizeof(double));
  phgmg_gemm('N', 'N', N, N, m, -1.0 / s, B, N, C, m, 1.0, At, N);      /* A - B S^-1 C */
  phgmg_gemm('N', 'T', N, N, m, -1.0 / s, B, N, B, N, 0.0, K, N);       /* -B S^-1 B^T  */
  phgmg_gemm('T', 'N', N, N, m, 1.0 / s, C, m, C, m, 0.0, L, N);        /*  C^T S^-1 C  */
  rc = phgmg_care(N, At, K, L, X, NULL, alloc);
  if (rc == PHGMG_OK) {       /* dual: (A^T, C^T, B^T) */
    for (j = 0; j < N; ++j)
      for (i = 0; i < N; ++i) Att[i + (size_t)j * N] = At[j + (size_t)i * N];
    for (i = 0; i < (int)nn; ++i) { const double t = K[i]; K[i] = -L[i]; L[i] = -t; }
    rc = phgmg_care(N, Att, K, L, Y, NULL, alloc);
  }
  phgmg__free(alloc, At);
  return rc;
}


/* Orthonormal basis V (n2 x k) of the (numerical) kernel of H (n2 x n2,
   destroyed: LU factors): inverse iteration on H^T H (two solves a step, 4
   steps; convergence ratio (sigma_k+1 / sigma_k)^2 per step, sigma_k ~ eps_mach
   ||H|| for an exact kernel) from deterministic +-1 start vectors, Gram-Schmidt
   in between. A zero pivot is shifted by eps_mach ||H||_1. work: n2 ints. */
PHGMG__PRIV phgmg_result phgmg__kernel_inviter(int n2, double *H, int k, double *V, int *ipiv) {
  const double h1 = phgmg_norm1(n2, n2, H, n2);
  unsigned long seed = 12345u;
  phgmg_result rc;
  int i, j, l, it;
  for (j = 0; j < k; ++j)
    for (i = 0; i < n2; ++i) {
      seed = seed * 1103515245u + 12345u;
      V[i + (size_t)j * n2] = ((seed >> 16) & 1u) ? 1.0 : -1.0;
    }
  rc = phgmg_lu_factor(n2, H, n2, ipiv);
  if (rc == PHGMG_ERR_SINGULAR)
    for (i = 0; i < n2; ++i)
      if (H[i + (size_t)i * n2] == 0.0) H[i + (size_t)i * n2] = 2.2e-16 * h1;
  if (rc != PHGMG_OK && rc != PHGMG_ERR_SINGULAR) return rc;
  for (it = 0; it < 4; ++it) {
    phgmg_lu_solve('T', n2, H, n2, ipiv, k, V, n2);
    phgmg_lu_solve('N', n2, H, n2, ipiv, k, V, n2);
    for (j = 0; j < k; ++j) {   /* modified Gram-Schmidt, twice */
      double *v = V + (size_t)j * n2, nv;
      int pass;
      for (pass = 0; pass < 2; ++pass)
        for (l = 0; l < j; ++l) {
          const double *u = V + (size_t)l * n2;
          double d = 0.0;
          for (i = 0; i < n2; ++i) d += u[i] * v[i];
          for (i = 0; i < n2; ++i) v[i] -= d * u[i];
        }
      nv = phgmg_normf(n2, 1, v, n2);
      if (!(nv > 0.0) || !isfinite(nv)) return PHGMG_ERR_NOT_CONVERGED;
      for (i = 0; i < n2; ++i) v[i] /= nv;
    }
  }
  return PHGMG_OK;
}

/* Riccati A^T X + X A - X K X + L = 0 (n x n) whose Hamiltonian H = [A, -K;
   -L, -A^T] may have, besides eigenvalues off the imaginary axis, k Jordan
   pairs at 0 (the positive-real Riccati of a system whose Popov function
   vanishes at w = 0, e.g. a chain driven by forces with velocity outputs).
   The minimal solution X belongs to the Lagrangian subspace spanned by the
   stable eigenvectors and the eigenvectors (not the principal vectors) of the
   pairs at 0, i.e. range(P) + ker H with P = (I - sign(H + sI))/2 (the
   eigenvalues with Re < -s), s = 1e-6 ||H||_1: round-off splits a Jordan pair
   at 0 by about sqrt(eps_mach) ||H|| << s, and s must stay below the other
   eigenvalues' |Re| (1.4e-3 and 3e-4 ||H||_1 on the two chains of
   examples/linear_bases.c). k = trace(I - P) - n (a projector's trace is its
   rank); ker H by phgmg__kernel_inviter. With [M1; M2] = [P, ker H],
   X M1 = M2 by least squares. Without pairs at 0 (k = 0) X is phgmg_care's
   solution. */
PHGMG__PRIV phgmg_result phgmg__care_cluster(int n, const double *A, const double *K, const double *L, double *X,
                                             const phgmg_allocator *alloc) {
  const int n2 = 2 * n;
  const size_t q = (size_t)n2 * n2;
  double *H, *W, *Mt, sig, tr = 0.0;
  int *ipiv = phgmg__ialloc(alloc, (size_t)n2), k = 0, nr, r, c;
  phgmg_result rc;
  H = phgmg__dalloc(alloc, 2 * q + 2 * (size_t)(n2 + n) * n + (size_t)n2 * n);
  if (!H || !ipiv) { phgmg__free(alloc, H); phgmg__free(alloc, ipiv); return PHGMG_ERR_NOMEM; }
  W = H + q; Mt = W + q;
  for (c = 0; c < n; ++c)
    for (r = 0; r < n; ++r) {
      H[r + (size_t)c * n2] = A[r + (size_t)c * n];
      H[r + (size_t)(c + n) * n2] = -K[r + (size_t)c * n];
      H[(r + n) + (size_t)c * n2] = -L[r + (size_t)c * n];
      H[(r + n) + (size_t)(c + n) * n2] = -A[c + (size_t)r * n];
    }
  sig = 1e-6 * phgmg_norm1(n2, n2, H, n2);
  memcpy(W, H, q * sizeof(double));
  for (r = 0; r < n2; ++r) W[r + (size_t)r * n2] += sig;
  rc = phgmg__sign_iter(n2, W, NULL, NULL, alloc);
  if (rc == PHGMG_OK) {
    for (r = 0; r < n2; ++r) tr += 0.5 * (1.0 + W[r + (size_t)r * n2]);
    k = (int)floor(tr - n + 0.5);
    if (k < 0 || k > n) rc = PHGMG_ERR_NOT_CONVERGED;
  }
  nr = n2 + k;
  if (rc == PHGMG_OK) {   /* Mt = [M1^T, M2^T] ((n2 + k) x n each): rows of P^T, then of V^T */
    double *V = Mt + 2 * (size_t)nr * n;
    for (c = 0; c < n2; ++c)
      for (r = 0; r < n2; ++r) {
        const double p = (r == c ? 0.5 : 0.0) - 0.5 * W[r + (size_t)c * n2];   /* P(r, c) */
        Mt[c + (size_t)(r < n ? r : r - n) * nr + (r < n ? 0 : (size_t)n * nr)] = p;
      }
    if (k > 0) rc = phgmg__kernel_inviter(n2, H, k, V, ipiv);
    if (rc == PHGMG_OK)
      for (c = 0; c < k; ++c)
        for (r = 0; r < n2; ++r)
          Mt[(n2 + c) + (size_t)(r < n ? r : r - n) * nr + (r < n ? 0 : (size_t)n * nr)] = V[r + (size_t)c * n2];
  }
  if (rc == PHGMG_OK) rc = phgmg_lstsq(nr, n, n, Mt, nr, Mt + (size_t)n * nr, nr, 0.0, W, n, alloc);
  if (rc == PHGMG_OK)
    for (c = 0; c < n; ++c)
      for (r = 0; r < n; ++r) X[r + (size_t)c * n] = 0.5 * (W[r + (size_t)c * n] + W[c + (size_t)r * n]);
  phgmg__free(alloc, H);
  phgmg__free(alloc, ipiv);
  return rc;
}

/* Lower Cholesky factor of a small symmetric m x m S in place; -1 unless PD. */
PHGMG__PRIV int phgmg__chol_small(int m, double *S) {
  int i, j, k;
  for (j = 0; j < m; ++j) {
    double d = S[j + (size_t)j * m];
    for (k = 0; k < j; ++k) d -= S[j + (size_t)k * m] * S[j + (size_t)k * m];
    if (!(d > 0.0)) return -1;
    d = sqrt(d);
    S[j + (size_t)j * m] = d;
    for (i = j + 1; i < m; ++i) {
      double t = S[i + (size_t)j * m];
      for (k = 0; k < j; ++k) t -= S[i + (size_t)k * m] * S[j + (size_t)k * m];
      S[i + (size_t)j * m] = t / d;
    }
    for (i = 0; i < j; ++i) S[i + (size_t)j * m] = 0.0;
  }
  return 0;
}

/* T = [B, Nc] (N x N) with Nc an orthonormal basis of ker C (the last N - m
   columns of Q in C^T = Q R). */
PHGMG__PRIV phgmg_result phgmg__ker_frame(int N, int m, const double *B, const double *C, double *T,
                                          const phgmg_allocator *alloc) {
  double *Ct = phgmg__dalloc(alloc, (size_t)N * m + m);
  phgmg_result rc;
  int i, j;
  if (!Ct) return PHGMG_ERR_NOMEM;
  for (j = 0; j < m; ++j)
    for (i = 0; i < N; ++i) Ct[i + (size_t)j * N] = C[j + (size_t)i * m];
  rc = phgmg_qr(N, m, Ct, N, Ct + (size_t)N * m);
  if (rc == PHGMG_OK) {
    memcpy(T, B, (size_t)N * m * sizeof(double));
    memset(T + (size_t)N * m, 0, (size_t)N * (N - m) * sizeof(double));
    for (j = 0; j < N - m; ++j) T[(m + j) + (size_t)(m + j) * N] = 1.0;
    phgmg_qr_apply('N', N, N - m, m, Ct, N, Ct + (size_t)N * m, T + (size_t)N * m, N);
  }
  phgmg__free(alloc, Ct);
  return rc;
}

/* Deflated Riccati data of the zero-feedthrough positive-real problem (see
   phgmg__pr_zero_d): with At = T^-1 A T in blocks (m, n = N - m), Ls Ls^T =
   S = -(C A B + (C A B)^T), B' = A21 Ls^-T, C' = -Ls^-1 (C B) A12: Ah = A22 -
   B' C', K = -B' B'^T, L = C'^T C' (n x n each). PHGMG_ERR_SINGULAR unless
   S is positive definite. */
PHGMG__PRIV phgmg_result phgmg__pr_deflate(int N, int m, const double *At, const double *CB, double *Ah,
                                           double *K, double *L, double *work) {
  const int n = N - m;
  double *S = work, *Bp = S + (size_t)m * m, *Cp = Bp + (size_t)n * m, *CA = Cp + (size_t)m * n;
  int i, j, a, b;
  for (b = 0; b < m; ++b)   /* S = -(CB A11 + A11^T CB) */
    for (a = 0; a < m; ++a) {
      double t = 0.0;
      for (j = 0; j < m; ++j) t += CB[a + (size_t)j * m] * At[j + (size_t)b * N] + At[j + (size_t)a * N] * CB[j + (size_t)b * m];
      S[a + (size_t)b * m] = -t;
    }
  if (phgmg__chol_small(m, S) != 0) return PHGMG_ERR_SINGULAR;
  for (i = 0; i < n; ++i)   /* B' = A21 Ls^-T: row i solves Ls b = A21(i,:)^T */
    for (a = 0; a < m; ++a) {
      double t = At[(m + i) + (size_t)a * N];
      for (b = 0; b < a; ++b) t -= S[a + (size_t)b * m] * Bp[i + (size_t)b * n];
      Bp[i + (size_t)a * n] = t / S[a + (size_t)a * m];
    }
  for (j = 0; j < n; ++j) {   /* C' = -Ls^-1 CB A12 */
    for (a = 0; a < m; ++a) {
      double t = 0.0;
      for (b = 0; b < m; ++b) t += CB[a + (size_t)b * m] * At[b + (size_t)(m + j) * N];
      CA[a] = -t;
    }
    for (a = 0; a < m; ++a) {
      double t = CA[a];
      for (b = 0; b < a; ++b) t -= S[a + (size_t)b * m] * Cp[b + (size_t)j * m];
      Cp[a + (size_t)j * m] = t / S[a + (size_t)a * m];
    }
  }
  for (j = 0; j < n; ++j)
    for (i = 0; i < n; ++i) Ah[i + (size_t)j * n] = At[(m + i) + (size_t)(m + j) * N];
  phgmg_gemm('N', 'N', n, n, m, -1.0, Bp, n, Cp, m, 1.0, Ah, n);
  phgmg_gemm('N', 'T', n, n, m, -1.0, Bp, n, Bp, n, 0.0, K, n);
  phgmg_gemm('T', 'N', n, n, m, 1.0, Cp, m, Cp, m, 0.0, L, n);
  return PHGMG_OK;
}

/* Minimal solution X (N x N) of the positive-real lemma with zero
   feedthrough, the limit eps -> 0 of the regularised Riccati: A^T X + X A <= 0
   and X B = C^T. In the frame T = [B, Nc] (Nc: ker C) the constraint fixes
   T^T X T = diag(C B, Z) (C B must be symmetric positive definite, as B^T Q B
   of a pH system), and the Schur complement of the Lyapunov inequality is a
   regular positive-real Riccati inequality for Z (n = N - m) with feedthrough
   S = -(C A B + (C A B)^T) (= 2 B^T Q R Q B for a pH system; positive
   definite needed: every port damped, else PHGMG_ERR_SINGULAR); its minimal
   solution by phgmg__care_cluster, X = T^-T diag(C B, Z) T^-1. */
PHGMG__PRIV phgmg_result phgmg__pr_zero_d(int N, int m, const double *A, const double *B, const double *C,
                                          double *X, const phgmg_allocator *alloc) {
  const int n = N - m;
  const size_t nn = (size_t)N * N, qq = (size_t)n * n;
  double *T, *Ti, *At, *CB, *work, *Ah, *K, *L, *Z;
  phgmg_result rc;
  int i, j;
  if (n < 1) return PHGMG_ERR_SIZE;
  T = phgmg__dalloc(alloc, 3 * nn + 4 * qq + 2 * (size_t)m * m + 2 * (size_t)n * m + m);
  if (!T) return PHGMG_ERR_NOMEM;
  Ti = T + nn; At = Ti + nn; Ah = At + nn; K = Ah + qq; L = K + qq; Z = L + qq; CB = Z + qq;
  work = CB + (size_t)m * m;
  phgmg_gemm('N', 'N', m, m, N, 1.0, C, m, B, N, 0.0, CB, m);
  rc = PHGMG_OK;
  for (j = 0; j < m; ++j)   /* C B symmetric (X B = C^T makes B^T X B = C B) */
    for (i = 0; i < j; ++i)
      if (fabs(CB[i + (size_t)j * m] - CB[j + (size_t)i * m]) > 1e-12 * phgmg_normf(m, m, CB, m))
        rc = PHGMG_ERR_SINGULAR;
  if (rc == PHGMG_OK) rc = phgmg__ker_frame(N, m, B, C, T, alloc);
  if (rc == PHGMG_OK) rc = phgmg__inv(N, T, Ti, alloc);
  if (rc == PHGMG_OK) {   /* At = Ti A T (X as scratch) */
    phgmg_gemm('N', 'N', N, N, N, 1.0, A, N, T, N, 0.0, X, N);
    phgmg_gemm('N', 'N', N, N, N, 1.0, Ti, N, X, N, 0.0, At, N);
    rc = phgmg__pr_deflate(N, m, At, CB, Ah, K, L, work);
  }
  if (rc == PHGMG_OK) rc = phgmg__care_cluster(n, Ah, K, L, Z, alloc);
  if (rc == PHGMG_OK) {   /* X = Ti^T diag(CB, Z) Ti */
    memset(At, 0, nn * sizeof(double));
    for (j = 0; j < m; ++j)
      for (i = 0; i < m; ++i) At[i + (size_t)j * N] = CB[i + (size_t)j * m];
    for (j = 0; j < n; ++j)
      for (i = 0; i < n; ++i) At[(m + i) + (size_t)(m + j) * N] = Z[i + (size_t)j * n];
    phgmg_gemm('N', 'N', N, N, N, 1.0, At, N, Ti, N, 0.0, T, N);
    phgmg_gemm('T', 'N', N, N, N, 1.0, Ti, N, T, N, 0.0, X, N);
    for (j = 0; j < N; ++j)
      for (i = 0; i < j; ++i) {
        const double t = 0.5 * (X[i + (size_t)j * N] + X[j + (size_t)i * N]);
        X[i + (size_t)j * N] = t; X[j + (size_t)i * N] = t;
      }
  }
  phgmg__free(alloc, T);
  return rc;
}

/* The factor Lf (N x m) of -(A^T X + X A) = Lf Lf^T for the minimal
   zero-feedthrough solution X of phgmg__pr_zero_d (rank m: the Schur
   complement vanishes). In the frame T = [B, Nc], At = T^-1 A T, T^T X T =
   diag(C B, Z), Ls Ls^T = S: -(At^T Xt + Xt At) = G G^T with G = [Ls;
   -(Z A21 + A12^T C B) Ls^-T], so Lf = T^-T G: exact in the theory and PSD
   by construction (no clipping of round-off eigenvalues). */
PHGMG__PRIV phgmg_result phgmg__pr_factor(int N, int m, const double *A, const double *B, const double *C,
                                          const double *X, double *Lf, const phgmg_allocator *alloc) {
  const int n = N - m;
  const size_t nn = (size_t)N * N;
  double *T = phgmg__dalloc(alloc, 5 * nn + 2 * (size_t)m * m + 2 * (size_t)N * m), *Ti, *At, *W, *Z, *CB, *S, *G,
         *Ft;
  phgmg_result rc;
  int i, j, a, b;
  if (!T) return PHGMG_ERR_NOMEM;
  Ti = T + nn; At = Ti + nn; W = At + nn; Z = W + nn; CB = Z + nn; S = CB + (size_t)m * m; G = S + (size_t)m * m;
  Ft = G + (size_t)N * m;
  phgmg_gemm('N', 'N', m, m, N, 1.0, C, m, B, N, 0.0, CB, m);
  rc = phgmg__ker_frame(N, m, B, C, T, alloc);
  if (rc == PHGMG_OK) rc = phgmg__inv(N, T, Ti, alloc);
  if (rc == PHGMG_OK) {
    phgmg_gemm('N', 'N', N, N, N, 1.0, A, N, T, N, 0.0, W, N);
    phgmg_gemm('N', 'N', N, N, N, 1.0, Ti, N, W, N, 0.0, At, N);   /* At = Ti A T */
    for (b = 0; b < m; ++b)   /* S = -(CB A11 + A11^T CB) */
      for (a = 0; a < m; ++a) {
        double t = 0.0;
        for (j = 0; j < m; ++j) t += CB[a + (size_t)j * m] * At[j + (size_t)b * N] + At[j + (size_t)a * N] * CB[j + (size_t)b * m];
        S[a + (size_t)b * m] = -t;
      }
    if (phgmg__chol_small(m, S) != 0) rc = PHGMG_ERR_SINGULAR;
  }
  if (rc == PHGMG_OK) {
    phgmg_gemm('N', 'N', N, n, N, 1.0, X, N, T + (size_t)N * m, N, 0.0, W, N);          /* X Nc */
    phgmg_gemm('T', 'N', n, n, N, 1.0, T + (size_t)N * m, N, W, N, 0.0, Z, n);          /* Z = Nc^T X Nc */
    phgmg_gemm('N', 'N', n, m, n, 1.0, Z, n, At + m, N, 0.0, Ft, n);                    /* Z A21 */
    phgmg_gemm('T', 'N', n, m, m, 1.0, At + (size_t)m * N, N, CB, m, 1.0, Ft, n);      /* + A12^T CB */
    for (b = 0; b < m; ++b)
      for (a = 0; a < m; ++a) G[a + (size_t)b * N] = a >= b ? S[a + (size_t)b * m] : 0.0;
    for (i = 0; i < n; ++i)   /* rows m..: -Ft Ls^-T (row i solves Ls g = -Ft(i,:)^T) */
      for (a = 0; a < m; ++a) {
        double t = -Ft[i + (size_t)a * n];
        for (b = 0; b < a; ++b) t -= S[a + (size_t)b * m] * G[(m + i) + (size_t)b * N];
        G[(m + i) + (size_t)a * N] = t / S[a + (size_t)a * m];
      }
    phgmg_gemm('T', 'N', N, m, N, 1.0, Ti, N, G, N, 0.0, Lf, N);                        /* Lf = Ti^T G */
  }
  phgmg__free(alloc, T);
  return rc;
}

/* X (Q-eq) and Y (P-eq, from the dual (A^T, C^T, B^T)) by phgmg__pr_zero_d. */
PHGMG__PRIV phgmg_result phgmg__pr_zero_d_both(int N, int m, const double *A, const double *B, const double *C,
                                               double *X, double *Y, const phgmg_allocator *alloc) {
  double *At = phgmg__dalloc(alloc, (size_t)N * N + 2 * (size_t)N * m), *Ct, *Bt;
  phgmg_result rc;
  int i, j;
  if (!At) return PHGMG_ERR_NOMEM;
  Ct = At + (size_t)N * N; Bt = Ct + (size_t)N * m;
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) At[i + (size_t)j * N] = A[j + (size_t)i * N];
  for (j = 0; j < m; ++j)
    for (i = 0; i < N; ++i) { Ct[i + (size_t)j * N] = C[j + (size_t)i * m]; Bt[j + (size_t)i * m] = B[i + (size_t)j * N]; }
  rc = phgmg__pr_zero_d(N, m, A, B, C, X, alloc);
  if (rc == PHGMG_OK) rc = phgmg__pr_zero_d(N, m, At, Ct, Bt, Y, alloc);
  phgmg__free(alloc, At);
  return rc;
}
/* The pH blocks of a PR-balanced truncation (see phgmg_prbt): Qh = Sigma,
   K = skew(Ar Sigma^-1) - Sigma^-1 F F^T Sigma^-1 / (2 s). Br, Cr non-NULL:
   F = Sigma Br - Cr^T (regularised); else F (r x m) is given (exact case:
   Tr^T Lf with -(A^T X + X A) = Lf Lf^T, s = 1/2... passed as s). */
PHGMG__PRIV void phgmg__prbt_ph(int r, int m, const double *Ar, const double *Br, const double *Cr, const double *S,
                                double s, double *Qh, double *K, double *F) {
  int i, j, a;
  for (j = 0; j < r; ++j)
    for (i = 0; i < r; ++i) Qh[i + (size_t)j * r] = i == j ? S[i] : 0.0;
  if (Br && Cr)
    for (a = 0; a < m; ++a)       /* F = Sigma Br - Cr^T */
      for (i = 0; i < r; ++i) F[i + (size_t)a * r] = S[i] * Br[i + (size_t)a * r] - Cr[a + (size_t)i * m];
  for (j = 0; j < r; ++j)
    for (i = 0; i < r; ++i) {
      double rr = 0.0;
      for (a = 0; a < m; ++a) rr += F[i + (size_t)a * r] * F[j + (size_t)a * r];
      rr /= 2.0 * s * S[i] * S[j];
      K[i + (size_t)j * r] = 0.5 * (Ar[i + (size_t)j * r] / S[j] - Ar[j + (size_t)i * r] / S[i]) - rr;
    }
}

PHGMG_DEF phgmg_result phgmg_prbt(phgmg_reduced **out, const phgmg_ph_system *sys, int r,
                                  const phgmg_prbt_opts *opts, double *prsv, double *info_xb,
                                  const phgmg_allocator *alloc) {
  int N, m;
  double *A, *C, *X, *Y, *Ar, *Cr, *S, *F, *CB, *Lf, s = 1.0, eps;
  int exact;
  phgmg_reduced *red;
  phgmg_result rc;
  if (!out) return PHGMG_ERR_INVALID_ARG;
  *out = NULL;
  if (sys && (sys->E || sys->P || sys->S || sys->Nskew)) return PHGMG_ERR_UNSUPPORTED; /* standard form only */
  if (!sys) return PHGMG_ERR_INVALID_ARG;
  if (sys->nl != PHGMG_NL_NONE) return PHGMG_ERR_UNSUPPORTED;
  if (opts && (opts->eps < 0.0 || opts->dt < 0.0 || !isfinite(opts->eps) || !isfinite(opts->dt) ||
               (!opts->X) != (!opts->Y))) return PHGMG_ERR_INVALID_ARG;
  exact = !(opts && opts->eps > 0.0);
  eps = exact ? 1e-10 : opts->eps;
  rc = phgmg_ph_validate(sys, 0.0, NULL, alloc);
  if (rc != PHGMG_OK) return rc;
  N = sys->N; m = sys->m;
  if (r < 1 || r > N) return PHGMG_ERR_SIZE;
  A = phgmg__dalloc(alloc, 3 * (size_t)N * N + (size_t)m * N + 2 * (size_t)r * r + (size_t)m * r + 2 * (size_t)r * m + r + (size_t)m * m +
                          (size_t)N * m);
  red = PHGMG__CAST(phgmg_reduced *, phgmg__alloc(alloc, sizeof(phgmg_reduced)));
  if (!A || !red) { phgmg__free(alloc, A); phgmg__free(alloc, red); return PHGMG_ERR_NOMEM; }
  memset(red, 0, sizeof *red);
  if (alloc) { red->alloc = *alloc; red->use_alloc = 1; }
  red->N = N; red->m = m; red->r = r; red->p = r; red->method = PHGMG_METHOD_PRBT;
  red->kind = PHGMG_ROM_LINEAR; red->sys = sys;
  C = A + (size_t)N * N; X = C + (size_t)m * N; Y = X + (size_t)N * N; Ar = Y + (size_t)N * N;
  Cr = Ar + (size_t)r * r; S = Cr + (size_t)m * r; F = S + r; CB = F + (size_t)r * m;
  Lf = CB + (size_t)m * m;
  rc = phgmg_ph_abc(sys, A, C, alloc);
  if (rc == PHGMG_OK) {
    phgmg_gemm('N', 'N', m, m, N, 1.0, C, m, sys->B, N, 0.0, CB, m);
    s = 2.0 * eps * phgmg_normf(m, m, CB, m);
    if (opts && opts->X && opts->Y) {
      memcpy(X, opts->X, (size_t)N * N * sizeof(double));
      memcpy(Y, opts->Y, (size_t)N * N * sizeof(double));
    } else {
      if (exact) rc = phgmg__pr_zero_d_both(N, m, A, sys->B, C, X, Y, alloc);
      if (exact && rc == PHGMG_ERR_SINGULAR) { exact = 0; rc = PHGMG_OK; }   /* a port without damping */
      if (!exact) rc = phgmg__pr_riccati(N, m, A, sys->B, C, s, X, Y, alloc);
      rc = phgmg__gramian_failure(N, A, rc, alloc);
    }
  }
  if (rc == PHGMG_OK && info_xb) {   /* ||X B - C^T|| / ||C|| */
    double *XB = phgmg__dalloc(alloc, (size_t)N * m);
    int i, a;
    if (!XB) rc = PHGMG_ERR_NOMEM;
    else {
      phgmg_gemm('N', 'N', N, m, N, 1.0, X, N, sys->B, N, 0.0, XB, N);
      for (a = 0; a < m; ++a)
        for (i = 0; i < N; ++i) XB[i + (size_t)a * N] -= C[a + (size_t)i * m];
      *info_xb = phgmg_normf(N, m, XB, N) / phgmg_normf(m, N, C, m);
      phgmg__free(alloc, XB);
    }
  }
  if (rc == PHGMG_OK) {
    red->V0 = phgmg__red_d(red, (size_t)N * r);
    red->W = phgmg__red_d(red, (size_t)N * r);
    red->Bh = phgmg__red_d(red, (size_t)r * m);
    red->Qh = phgmg__red_d(red, (size_t)r * r);
    red->K = phgmg__red_d(red, (size_t)r * r);
    if (!red->V0 || !red->W || !red->Bh || !red->Qh || !red->K) rc = PHGMG_ERR_NOMEM;
  }
  if (rc == PHGMG_OK && exact) rc = phgmg__pr_factor(N, m, A, sys->B, C, X, Lf, alloc);
  if (rc == PHGMG_OK) rc = phgmg__balance(N, r, Y, X, red->V0, red->W, S, alloc);
  /* minimal solutions give positive-real singular values <= 1: a larger one
     means the Riccati solutions are not accurate (eps too small) */
  if (rc == PHGMG_OK && !(S[0] <= 1.0 + 1e-6)) rc = PHGMG_ERR_NOT_CONVERGED;
  if (rc == PHGMG_OK) rc = phgmg__project_abc(N, m, r, A, sys->B, C, red->V0, red->W, Ar, red->Bh, Cr, alloc);
  if (rc == PHGMG_OK) {
    if (exact) {   /* F = Tr^T Lf */
      phgmg_gemm('T', 'N', r, m, N, 1.0, red->V0, N, Lf, N, 0.0, F, r);
      phgmg__prbt_ph(r, m, Ar, NULL, NULL, S, 1.0, red->Qh, red->K, F);
    } else {
      phgmg__prbt_ph(r, m, Ar, red->Bh, Cr, S, s, red->Qh, red->K, F);
    }
    if (prsv) memcpy(prsv, S, (size_t)r * sizeof(double));
    if (rc == PHGMG_OK && opts && opts->dt > 0.0) {
      red->map_dt = opts->dt;
      rc = phgmg__step_map(red, opts->dt, alloc);
    }
  }
  if (rc == PHGMG_OK) rc = phgmg__publish(red);
  phgmg__free(alloc, A);
  if (rc != PHGMG_OK) { phgmg_reduced_destroy(red); return rc; }
  *out = red;
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_prbt_riccati(const phgmg_ph_system *sys, double eps, double *X, double *Y,
                                          const phgmg_allocator *alloc) {
  int N, m;
  double *A, *C, CBn;
  phgmg_result rc;
  if (!sys || !X || !Y) return PHGMG_ERR_INVALID_ARG;
  if (sys && (sys->E || sys->P || sys->S || sys->Nskew)) return PHGMG_ERR_UNSUPPORTED; /* standard form only */
  if (sys->nl != PHGMG_NL_NONE) return PHGMG_ERR_UNSUPPORTED;
  rc = phgmg_ph_validate(sys, 0.0, NULL, alloc);
  if (rc != PHGMG_OK) return rc;
  N = sys->N; m = sys->m;
  A = phgmg__dalloc(alloc, (size_t)N * N + (size_t)m * N + (size_t)m * m);
  if (!A) return PHGMG_ERR_NOMEM;
  C = A + (size_t)N * N;
  rc = phgmg_ph_abc(sys, A, C, alloc);
  if (rc == PHGMG_OK) {
    phgmg_gemm('N', 'N', m, m, N, 1.0, C, m, sys->B, N, 0.0, C + (size_t)m * N, m);
    CBn = phgmg_normf(m, m, C + (size_t)m * N, m);
    rc = eps > 0.0 ? PHGMG_ERR_SINGULAR : phgmg__pr_zero_d_both(N, m, A, sys->B, C, X, Y, alloc);
    if (rc == PHGMG_ERR_SINGULAR)
      rc = phgmg__pr_riccati(N, m, A, sys->B, C, 2.0 * (eps > 0.0 ? eps : 1e-10) * CBn, X, Y, alloc);
    rc = phgmg__gramian_failure(N, A, rc, alloc);
  }
  phgmg__free(alloc, A);
  return rc;
}

/* Frequency grid ends from the system (see phgmg_basis_opts). */
PHGMG__PRIV phgmg_result phgmg__freq_range(int N, const double *A, double *wmin, double *wmax,
                                           const phgmg_allocator *alloc) {
  double *LU = phgmg__dalloc(alloc, (size_t)N * N + 2 * (size_t)N), an, rc1;
  int *ip = phgmg__ialloc(alloc, 2 * (size_t)N);
  phgmg_result rc = PHGMG_ERR_NOMEM;
  if (LU && ip) {
    memcpy(LU, A, (size_t)N * N * sizeof(double));
    an = phgmg_norm1(N, N, A, N);
    rc = phgmg_lu_factor(N, LU, N, ip);
    if (rc == PHGMG_OK) {
      rc1 = phgmg_lu_rcond(N, LU, N, ip, an, LU + (size_t)N * N, ip + N);
      if (!(rc1 > 0.0)) rc = PHGMG_ERR_SINGULAR;
      else { *wmin = rc1 * an / 10.0; *wmax = 2.0 * an; }   /* 1/||A^-1|| = rcond ||A|| */
    }
  }
  phgmg__free(alloc, LU);
  phgmg__free(alloc, ip);
  return rc;
}

/* Snapshots for FREQ (N x 2 nw m) or IMPULSE (N x (nsteps+1) m) into *Xo. */
PHGMG__PRIV phgmg_result phgmg__basis_snapshots(const phgmg_ph_system *sys, phgmg_basis_kind kind,
                                                const phgmg_basis_opts *o, double **Xo, int *ns,
                                                const phgmg_allocator *alloc) {
  const int N = sys->N, m = sys->m;
  phgmg_result rc = PHGMG_OK;
  double *X;
  int a, i, j;
  if (kind == PHGMG_BASIS_FREQ) {
    const int nw = o && o->nw > 0 ? o->nw : 60;
    double wmin = o ? o->wmin : 0.0, wmax = o ? o->wmax : 0.0, *A, *Z, *Bz;
    int *ip;
    A = phgmg__dalloc(alloc, (size_t)N * N + 2 * (size_t)N * N + 2 * (size_t)N * m);
    ip = phgmg__ialloc(alloc, (size_t)N);
    X = phgmg__dalloc(alloc, (size_t)N * 2 * nw * m);
    if (!A || !ip || !X) { phgmg__free(alloc, A); phgmg__free(alloc, ip); phgmg__free(alloc, X); return PHGMG_ERR_NOMEM; }
    Z = A + (size_t)N * N; Bz = Z + 2 * (size_t)N * N;
    rc = phgmg_ph_abc(sys, A, NULL, alloc);
    if (rc == PHGMG_OK && !(wmin > 0.0 && wmax > 0.0)) {   /* the ends not given from the system */
      double lo = 0.0, hi = 0.0;
      rc = phgmg__freq_range(N, A, &lo, &hi, alloc);
      if (!(wmin > 0.0)) wmin = lo;
      if (!(wmax > 0.0)) wmax = hi;
      if (rc == PHGMG_OK && !(wmin < wmax)) rc = PHGMG_ERR_INVALID_ARG;   /* one end given, beyond the other */
    }
    for (j = 0; rc == PHGMG_OK && j < nw; ++j) {
      const double w = wmin * pow(wmax / wmin, nw > 1 ? (double)j / (nw - 1) : 0.0);
      for (i = 0; i < 2 * N * N; ++i) Z[i] = 0.0;
      for (i = 0; i < N * N; ++i) Z[2 * i] = -A[i];
      for (i = 0; i < N; ++i) Z[2 * (i + (size_t)i * N) + 1] = w;
      for (i = 0; i < N * m; ++i) { Bz[2 * i] = sys->B[i]; Bz[2 * i + 1] = 0.0; }
      rc = phgmg_zlu_factor(N, Z, N, ip);
      if (rc != PHGMG_OK) break;
      phgmg_zlu_solve(N, Z, N, ip, m, Bz, N);
      for (a = 0; a < m; ++a)
        for (i = 0; i < N; ++i) {
          X[i + (size_t)((2 * j) * m + a) * N] = Bz[2 * (i + (size_t)a * N)];
          X[i + (size_t)((2 * j + 1) * m + a) * N] = Bz[2 * (i + (size_t)a * N) + 1];
        }
    }
    phgmg__free(alloc, A); phgmg__free(alloc, ip);
    *ns = 2 * nw * m;
  } else {
    const int nst = o && o->nsteps > 0 ? o->nsteps : 1000;
    const double dt = o && o->dt > 0.0 ? o->dt : 0.1;
    X = phgmg__dalloc(alloc, (size_t)N * (nst + 1) * m);
    if (!X) return PHGMG_ERR_NOMEM;
    for (a = 0; a < m && rc == PHGMG_OK; ++a)   /* x(0+) = B e_a, u = 0 */
      rc = phgmg_simulate(sys, sys->B + (size_t)a * N, 0.0, dt, nst, NULL, NULL, NULL,
                          X + (size_t)a * (nst + 1) * N, NULL, NULL, NULL, NULL, alloc);
    *ns = (nst + 1) * m;
  }
  if (rc != PHGMG_OK) { phgmg__free(alloc, X); return rc; }
  *Xo = X;
  return PHGMG_OK;
}

/* ---- GMG basis of minimal H2 error (PHGMG_BASIS_H2) -----------------------
   Complex matrices are interleaved (re, im), column-major. */

/* C = op(A) op(B) (complex; op 'N' or 'C' = conjugate transpose), C m x n. */
PHGMG__PRIV void phgmg__zgemm(char ta, char tb, int m, int n, int k, const double *A, int lda, const double *B,
                              int ldb, double *C, int ldc) {
  int i, j, l;
  if (ta == 'C' && tb == 'N') {   /* C_ij = conj(A(:, i)) . B(:, j) */
    for (j = 0; j < n; ++j)
      for (i = 0; i < m; ++i) {
        const double *a = A + 2 * (size_t)i * lda, *b = B + 2 * (size_t)j * ldb;
        double si = 0.0;
        for (l = 0; l < k; ++l) si += a[2 * l] * b[2 * l + 1] - a[2 * l + 1] * b[2 * l];
        C[2 * (i + (size_t)j * ldc)] = phgmg__dot(2 * k, a, b);
        C[2 * (i + (size_t)j * ldc) + 1] = si;
      }
    return;
  }
  for (j = 0; j < n; ++j) {
    double *c = C + 2 * (size_t)j * ldc;
    for (i = 0; i < 2 * m; ++i) c[i] = 0.0;
    for (l = 0; l < k; ++l) {
      double br, bi;
      if (tb == 'N') { br = B[2 * (l + (size_t)j * ldb)]; bi = B[2 * (l + (size_t)j * ldb) + 1]; }
      else { br = B[2 * (j + (size_t)l * ldb)]; bi = -B[2 * (j + (size_t)l * ldb) + 1]; }
      if (ta == 'N') {   /* c += A(:, l) b */
        const double *a = A + 2 * (size_t)l * lda;
        for (i = 0; i < m; ++i) {
          c[2 * i] += a[2 * i] * br - a[2 * i + 1] * bi;
          c[2 * i + 1] += a[2 * i] * bi + a[2 * i + 1] * br;
        }
      } else {           /* c_i += conj(A(l, i)) b */
        for (i = 0; i < m; ++i) {
          const double ar = A[2 * (l + (size_t)i * lda)], ai = -A[2 * (l + (size_t)i * lda) + 1];
          c[2 * i] += ar * br - ai * bi;
          c[2 * i + 1] += ar * bi + ai * br;
        }
      }
    }
  }
}

/* Complex Givens rotation G = [c s; -conj(s) c] (c real) with G [a; b] = [rho; 0]. */
PHGMG__PRIV void phgmg__zgivens(const double *a, const double *b, double *c, double *s) {
  const double aa = hypot(a[0], a[1]), bb = hypot(b[0], b[1]);
  double rr;
  if (bb == 0.0) { *c = 1.0; s[0] = s[1] = 0.0; return; }
  if (aa == 0.0) { *c = 0.0; s[0] = 1.0; s[1] = 0.0; return; }
  rr = hypot(aa, bb);
  *c = aa / rr;
  s[0] = (a[0] * b[0] + a[1] * b[1]) / (aa * rr);   /* (a / |a|) conj(b) / r */
  s[1] = (a[1] * b[0] - a[0] * b[1]) / (aa * rr);
}

/* Rows i, i+1 of M (complex, ld) <- G [row i; row i+1], columns j0 .. n-1. */
PHGMG__PRIV void phgmg__zrot_rows(double *M, int ld, int i, int j0, int n, double c, const double *s) {
  int j;
  for (j = j0; j < n; ++j) {
    double *x = M + 2 * (i + (size_t)j * ld), *y = x + 2;
    const double xr = x[0], xi = x[1], yr = y[0], yi = y[1];
    x[0] = c * xr + s[0] * yr - s[1] * yi;
    x[1] = c * xi + s[0] * yi + s[1] * yr;
    y[0] = c * yr - (s[0] * xr + s[1] * xi);
    y[1] = c * yi - (s[0] * xi - s[1] * xr);
  }
}

/* Columns j, j+1 of M (complex, ld) <- [col j, col j+1] G^H, rows 0 .. i1-1. */
PHGMG__PRIV void phgmg__zrot_cols(double *M, int ld, int j, int i1, double c, const double *s) {
  double *x = M + 2 * (size_t)j * ld, *y = x + 2 * (size_t)ld;
  int i;
  for (i = 0; i < i1; ++i) {
    const double xr = x[2 * i], xi = x[2 * i + 1], yr = y[2 * i], yi = y[2 * i + 1];
    x[2 * i] = c * xr + s[0] * yr + s[1] * yi;
    x[2 * i + 1] = c * xi + s[0] * yi - s[1] * yr;
    y[2 * i] = c * yr - (s[0] * xr - s[1] * xi);
    y[2 * i + 1] = c * yi - (s[0] * xi + s[1] * xr);
  }
}

/* Householder reduction of a real n x n H (ld n) to upper Hessenberg form in
   place, H <- U^T H U, U (n x n, ld n) orthogonal; v: n doubles. */
PHGMG__PRIV void phgmg__hessenberg(int n, double *H, double *U, double *v) {
  int i, j, k;
  for (i = 0; i < n * n; ++i) U[i] = 0.0;
  for (i = 0; i < n; ++i) U[i + (size_t)i * n] = 1.0;
  for (k = 0; k + 2 < n; ++k) {
    const int len = n - k - 1;
    double al = 0.0, vtv = 0.0, s;
    for (i = 0; i < len; ++i) { v[i] = H[(k + 1 + i) + (size_t)k * n]; al += v[i] * v[i]; }
    if (al == 0.0) continue;
    al = sqrt(al);
    v[0] += v[0] >= 0.0 ? al : -al;
    for (i = 0; i < len; ++i) vtv += v[i] * v[i];
    for (j = k; j < n; ++j) {   /* H <- (I - 2 v v^T / v^T v) H, rows k+1.. */
      double *h = H + (k + 1) + (size_t)j * n;
      for (s = 0.0, i = 0; i < len; ++i) s += v[i] * h[i];
      s *= 2.0 / vtv;
      for (i = 0; i < len; ++i) h[i] -= s * v[i];
    }
    for (i = 0; i < n; ++i) {   /* H <- H (I - 2 v v^T / v^T v), U likewise */
      double sh = 0.0, su = 0.0;
      double *hr = H + i + (size_t)(k + 1) * n, *ur = U + i + (size_t)(k + 1) * n;   /* row i, from column k+1 */
      for (j = 0; j < len; ++j) { sh += hr[(size_t)j * n] * v[j]; su += ur[(size_t)j * n] * v[j]; }
      sh *= 2.0 / vtv; su *= 2.0 / vtv;
      for (j = 0; j < len; ++j) { hr[(size_t)j * n] -= sh * v[j]; ur[(size_t)j * n] -= su * v[j]; }
    }
    for (i = k + 2; i < n; ++i) H[i + (size_t)k * n] = 0.0;
  }
}

/* Complex square root (principal branch). */
PHGMG__PRIV void phgmg__zsqrt(double x, double y, double *sr, double *si) {
  const double r = hypot(x, y);
  double t;
  if (r == 0.0) { *sr = *si = 0.0; return; }
  if (x >= 0.0) { t = sqrt(0.5 * (r + x)); *sr = t; *si = y / (2.0 * t); }
  else { t = sqrt(0.5 * (r - x)); *sr = fabs(y) / (2.0 * t); *si = y < 0.0 ? -t : t; }
}

/* Wilkinson shift of the trailing 2 x 2 block [a b; c d] of T at hi: its
   eigenvalue closer to d; every 11th step an exceptional shift. */
PHGMG__PRIV void phgmg__zwilkinson(int n, const double *T, int hi, int it, double *mu) {
  const double *a = T + 2 * ((hi - 1) + (size_t)(hi - 1) * n), *b = T + 2 * ((hi - 1) + (size_t)hi * n);
  const double *c = T + 2 * (hi + (size_t)(hi - 1) * n), *d = T + 2 * (hi + (size_t)hi * n);
  double pr, pi, bcr, bci, qr, qi, d1r, d1i, d2r, d2i, tr, ti;
  if (it % 11 == 10) { mu[0] = d[0] + 0.75 * hypot(c[0], c[1]); mu[1] = d[1]; return; }
  pr = 0.5 * (a[0] - d[0]); pi = 0.5 * (a[1] - d[1]);
  bcr = b[0] * c[0] - b[1] * c[1]; bci = b[0] * c[1] + b[1] * c[0];
  phgmg__zsqrt(pr * pr - pi * pi + bcr, 2.0 * pr * pi + bci, &qr, &qi);
  d1r = pr + qr; d1i = pi + qi; d2r = pr - qr; d2i = pi - qi;
  if (hypot(d2r, d2i) > hypot(d1r, d1i)) { d1r = d2r; d1i = d2i; }
  if (d1r == 0.0 && d1i == 0.0) { mu[0] = d[0]; mu[1] = d[1]; return; }
  phgmg__zdiv(bcr, bci, d1r, d1i, &tr, &ti);
  mu[0] = d[0] - tr; mu[1] = d[1] - ti;
}

/* Complex Schur form of a real n x n A (ld lda): A = Z T Z^H, T upper
   triangular, Z unitary (both n x n complex, ld n). Hessenberg reduction,
   then the single-shift complex QR algorithm (explicit shifted QR steps by
   Givens rotations, Wilkinson shifts, deflation when |t_{l,l-1}| <=
   eps (|t_ll| + |t_{l-1,l-1}|)). work: 3 n doubles. PHGMG_ERR_NOT_CONVERGED
   after 30 n steps, _NANINF. */
PHGMG__PRIV phgmg_result phgmg__zschur(int n, const double *A, int lda, double *T, double *Z, double *work) {
  const double eps = 2.220446049250313e-16;
  double hn = 0.0, mu[2], *cs = work, *sn = work + n;
  int i, j, k, lo, hi = n - 1, it = 0, total = 0;
  for (j = 0; j < n; ++j)
    for (i = 0; i < n; ++i) {
      T[i + (size_t)j * n] = A[i + (size_t)j * lda];
      hn += A[i + (size_t)j * lda] * A[i + (size_t)j * lda];
    }
  if (!(hn < HUGE_VAL)) return PHGMG_ERR_NANINF;
  hn = sqrt(hn);
  phgmg__hessenberg(n, T, Z, work);
  for (i = n * n - 1; i >= 0; --i) { T[2 * i] = T[i]; T[2 * i + 1] = 0.0; }
  for (i = n * n - 1; i >= 0; --i) { Z[2 * i] = Z[i]; Z[2 * i + 1] = 0.0; }
  while (hi > 0) {
    for (lo = hi; lo > 0; --lo) {
      const double *t = T + 2 * (lo + (size_t)(lo - 1) * n), *u = T + 2 * ((lo - 1) + (size_t)(lo - 1) * n);
      double s = hypot(u[0], u[1]) + hypot(t[2 * n], t[2 * n + 1]);
      if (s == 0.0) s = hn;
      if (hypot(t[0], t[1]) <= eps * s) {
        T[2 * (lo + (size_t)(lo - 1) * n)] = T[2 * (lo + (size_t)(lo - 1) * n) + 1] = 0.0;
        break;
      }
    }
    if (lo == hi) { --hi; it = 0; continue; }
    if (++total > 30 * n) return PHGMG_ERR_NOT_CONVERGED;
    phgmg__zwilkinson(n, T, hi, it++, mu);
    for (k = lo; k <= hi; ++k) { T[2 * (k + (size_t)k * n)] -= mu[0]; T[2 * (k + (size_t)k * n) + 1] -= mu[1]; }
    for (k = lo; k < hi; ++k) {
      phgmg__zgivens(T + 2 * (k + (size_t)k * n), T + 2 * (k + 1 + (size_t)k * n), cs + k, sn + 2 * k);
      phgmg__zrot_rows(T, n, k, k, n, cs[k], sn + 2 * k);
    }
    for (k = lo; k < hi; ++k) {
      phgmg__zrot_cols(T, n, k, k + 2, cs[k], sn + 2 * k);
      phgmg__zrot_cols(Z, n, k, n, cs[k], sn + 2 * k);
    }
    for (k = lo; k <= hi; ++k) { T[2 * (k + (size_t)k * n)] += mu[0]; T[2 * (k + (size_t)k * n) + 1] += mu[1]; }
  }
  for (j = 0; j < n; ++j)
    for (i = j + 1; i < n; ++i) T[2 * (i + (size_t)j * n)] = T[2 * (i + (size_t)j * n) + 1] = 0.0;
  return PHGMG_OK;
}

/* Triangular Sylvester equations (complex): T n x n and S k x k upper
   triangular (ld n, k), X n x k (ld n) holds F on entry, the solution on
   return. mode 0: T X + X S^H = F (columns from the last); mode 1:
   T^H X + X S = F (columns from the first). PHGMG_ERR_SINGULAR if a pivot
   t_ii + conj(s_jj) (mode 0) or conj(t_ii) + s_jj (mode 1) is zero. */
PHGMG__PRIV phgmg_result phgmg__ztrsyl(int mode, int n, const double *T, int k, const double *S, double *X) {
  int jj, j, l, a, b;
  for (jj = 0; jj < k; ++jj) {
    double *x, dr, di;
    j = mode == 0 ? k - 1 - jj : jj;
    x = X + 2 * (size_t)j * n;
    for (l = mode == 0 ? j + 1 : 0; l < (mode == 0 ? k : j); ++l) {   /* the solved columns */
      const double *sl = mode == 0 ? S + 2 * (j + (size_t)l * k) : S + 2 * (l + (size_t)j * k);
      phgmg__zaxpy_neg(n, sl[0], mode == 0 ? -sl[1] : sl[1], X + 2 * (size_t)l * n, x);
    }
    if (mode == 0) {   /* (T + conj(s_jj)) x = rhs, back substitution by columns of T */
      for (a = n - 1; a >= 0; --a) {
        const double *tc = T + 2 * (size_t)a * n;
        dr = tc[2 * a] + S[2 * (j + (size_t)j * k)]; di = tc[2 * a + 1] - S[2 * (j + (size_t)j * k) + 1];
        if (dr == 0.0 && di == 0.0) return PHGMG_ERR_SINGULAR;
        phgmg__zdiv(x[2 * a], x[2 * a + 1], dr, di, x + 2 * a, x + 2 * a + 1);
        phgmg__zaxpy_neg(a, x[2 * a], x[2 * a + 1], tc, x);
      }
    } else {           /* (T^H + s_jj) x = rhs, forward substitution (column a of T, conjugated) */
      for (a = 0; a < n; ++a) {
        const double *tc = T + 2 * (size_t)a * n;
        double sr = x[2 * a], si = x[2 * a + 1];
        for (b = 0; b < a; ++b) {   /* -= conj(t_ba) x_b */
          sr -= tc[2 * b] * x[2 * b] + tc[2 * b + 1] * x[2 * b + 1];
          si -= tc[2 * b] * x[2 * b + 1] - tc[2 * b + 1] * x[2 * b];
        }
        dr = tc[2 * a] + S[2 * (j + (size_t)j * k)]; di = -tc[2 * a + 1] + S[2 * (j + (size_t)j * k) + 1];
        if (dr == 0.0 && di == 0.0) return PHGMG_ERR_SINGULAR;
        phgmg__zdiv(sr, si, dr, di, x + 2 * a, x + 2 * a + 1);
      }
    }
  }
  return PHGMG_OK;
}

/* Workspace of the H2 objective: the system's Schur form A = U T U^H (once),
   U^H B, U^H C^T, ||G||_H2^2, the factorization of J - R, and buffers. */
typedef struct phgmg__h2gmg {
  const phgmg_ph_system *sys;
  phgmg_jr_factor *jr;
  int N, m, k, r;
  double h2ref;
  double *T, *UB, *UC, *buf;
} phgmg__h2gmg;

PHGMG__PRIV void phgmg__h2gmg_free(phgmg__h2gmg *h, const phgmg_allocator *alloc) {
  phgmg_jr_factor_destroy(h->jr);
  phgmg__free(alloc, h->T);
  phgmg__free(alloc, h->buf);
  memset(h, 0, sizeof *h);
}

/* ||G||_H2^2 = tr(C P C^T), P from T Y + Y T^H = -U^H B B^T U (Y = U^H P U):
   tr(C P C^T) = tr((U^H C^T)^H Y (U^H C^T)). work: N x N complex. */
PHGMG__PRIV phgmg_result phgmg__h2gmg_ref(phgmg__h2gmg *h, double *Y) {
  const int N = h->N, m = h->m;
  double s = 0.0;
  int i, j, a;
  phgmg_result rc;
  phgmg__zgemm('N', 'C', N, N, m, h->UB, N, h->UB, N, Y, N);
  for (i = 0; i < 2 * N * N; ++i) Y[i] = -Y[i];
  rc = phgmg__ztrsyl(0, N, h->T, N, h->T, Y);
  if (rc != PHGMG_OK) return rc;
  for (a = 0; a < m; ++a)
    for (j = 0; j < N; ++j) {
      const double *uj = h->UC + 2 * (j + (size_t)a * N);
      double yr = 0.0, yi = 0.0;   /* (Y uc)_j ... accumulate conj(uc_i) Y_ij uc_j */
      for (i = 0; i < N; ++i) {
        const double *ui = h->UC + 2 * (i + (size_t)a * N), *y = Y + 2 * (i + (size_t)j * N);
        yr += ui[0] * y[0] + ui[1] * y[1];
        yi += ui[0] * y[1] - ui[1] * y[0];
      }
      s += yr * uj[0] - yi * uj[1];
    }
  h->h2ref = s;
  return s > 0.0 ? PHGMG_OK : PHGMG_ERR_SINGULAR;
}

PHGMG__PRIV phgmg_result phgmg__h2gmg_init(phgmg__h2gmg *h, const phgmg_ph_system *sys, int k,
                                           const phgmg_allocator *alloc) {
  const int N = sys->N, m = sys->m, r = m + k;
  double *A = NULL, *U, *C, *W;
  phgmg_result rc;
  memset(h, 0, sizeof *h);
  h->sys = sys; h->N = N; h->m = m; h->k = k; h->r = r;
  h->T = phgmg__dalloc(alloc, 2 * (size_t)N * N + 4 * (size_t)N * m);
  A = phgmg__dalloc(alloc, 3 * (size_t)N * N + (size_t)m * N + 3 * (size_t)N + 2 * (size_t)N * m);
  if (!h->T || !A) { phgmg__free(alloc, A); phgmg__h2gmg_free(h, alloc); return PHGMG_ERR_NOMEM; }
  h->UB = h->T + 2 * (size_t)N * N; h->UC = h->UB + 2 * (size_t)N * m;
  U = A + (size_t)N * N; C = U + 2 * (size_t)N * N; W = C + (size_t)m * N;
  rc = phgmg_ph_abc(sys, A, C, alloc);
  if (rc == PHGMG_OK) rc = phgmg__zschur(N, A, N, h->T, U, W);
  if (rc == PHGMG_OK) {   /* U^H B, U^H C^T (real B, C as complex) */
    int i, a;
    double *Bz = W + 3 * (size_t)N;   /* N x m complex */
    for (a = 0; a < m; ++a)
      for (i = 0; i < N; ++i) {
        Bz[2 * (i + (size_t)a * N)] = sys->B[i + (size_t)a * N]; Bz[2 * (i + (size_t)a * N) + 1] = 0.0;
      }
    phgmg__zgemm('C', 'N', N, m, N, U, N, Bz, N, h->UB, N);
    for (a = 0; a < m; ++a)
      for (i = 0; i < N; ++i) {
        Bz[2 * (i + (size_t)a * N)] = C[a + (size_t)i * m]; Bz[2 * (i + (size_t)a * N) + 1] = 0.0;
      }
    phgmg__zgemm('C', 'N', N, m, N, U, N, Bz, N, h->UC, N);
    rc = phgmg__h2gmg_ref(h, U);
    if ((rc == PHGMG_ERR_SINGULAR || rc == PHGMG_ERR_NOT_CONVERGED) && phgmg__schur_undamped(N, h->T))
      rc = PHGMG_ERR_NOT_STABLE;   /* an undamped mode: no H2 norm */
  }
  phgmg__free(alloc, A);
  if (rc == PHGMG_OK) rc = phgmg_jr_factor_create(&h->jr, sys, NULL, alloc);
  if (rc == PHGMG_OK) {
    h->buf = phgmg__dalloc(alloc, 10 * (size_t)N * r + 40 * (size_t)r * r + 8 * (size_t)r);
    if (!h->buf) rc = PHGMG_ERR_NOMEM;
  }
  if (rc != PHGMG_OK) phgmg__h2gmg_free(h, alloc);
  return rc;
}

/* Re(Z Y Z^H) (r x r real, into P) for complex Z, Y (r x r); w: 4 r^2 doubles. */
PHGMG__PRIV void phgmg__zcongr(int r, const double *Z, const double *Y, double *P, double *w) {
  int i;
  phgmg__zgemm('N', 'N', r, r, r, Z, r, Y, r, w, r);
  phgmg__zgemm('N', 'C', r, r, r, w, r, Z, r, w + 2 * (size_t)r * r, r);
  for (i = 0; i < r * r; ++i) P[i] = w[2 * r * r + 2 * i];
}

/* A Gramian of the reduced model in Ar's Schur coordinates: Re(Z Y Z^H)
   into out, where S Y + Y S^H = -F^H F (mode 0; the transposed equation for
   mode 1, as phgmg__ztrsyl) and F is m x r complex (ld ldf). Ys: 2 r^2. */
PHGMG__PRIV phgmg_result phgmg__h2gmg_small_gram(int mode, int r, int m, const double *S, const double *Z,
                                                 const double *F, int ldf, double *Ys, double *out, double *w4) {
  phgmg_result rc;
  int i;
  phgmg__zgemm('C', 'N', r, r, m, F, ldf, F, ldf, Ys, r);
  for (i = 0; i < 2 * r * r; ++i) Ys[i] = -Ys[i];
  rc = phgmg__ztrsyl(mode, r, S, r, S, Ys);
  if (rc == PHGMG_OK) phgmg__zcongr(r, Z, Ys, out, w4);
  return rc;
}

/* The Gramian blocks of the error system G - G_r for the reduced (Ar, Br =
   [I; 0], Cr) with Ar = Z S Z^H: P12 = U Yp Z^H (A P12 + P12 Ar^T + B Br^T
   = 0), Q12 = U Yq Z^H (A^T Q12 + Q12 Ar = C^T Cr), Pr, Qr; returned as
   Pr, Qr, Q12^T P12 = Re(Z Yq^H Yp Z^H) and C P12 = Re((U^H C^T)^H Yp Z^H). */
PHGMG__PRIV phgmg_result phgmg__h2gmg_gram(const phgmg__h2gmg *h, const double *Cr, const double *S, const double *Z,
                                           double *Pr, double *Qr, double *QP, double *CP, double *w) {
  const int N = h->N, m = h->m, r = h->r;
  double *Yp = w, *Yq = Yp + 2 * (size_t)N * r, *Ys = Yq + 2 * (size_t)N * r, *CrZ = Ys + 2 * (size_t)r * r;
  double *w4 = CrZ + 2 * (size_t)m * r;
  phgmg_result rc;
  int i, j, a;
  phgmg__zgemm('N', 'N', N, r, m, h->UB, N, Z, r, Yp, N);
  for (i = 0; i < 2 * N * r; ++i) Yp[i] = -Yp[i];
  rc = phgmg__ztrsyl(0, N, h->T, r, S, Yp);
  if (rc != PHGMG_OK) return rc;
  rc = phgmg__h2gmg_small_gram(0, r, m, S, Z, Z, r, Ys, Pr, w4);   /* Br^H Z = Z's first m rows */
  if (rc != PHGMG_OK) return rc;
  for (j = 0; j < r; ++j)   /* Cr Z (m x r complex) */
    for (a = 0; a < m; ++a) {
      double sr = 0.0, si = 0.0;
      for (i = 0; i < r; ++i) {
        sr += Cr[a + (size_t)i * r] * Z[2 * (i + (size_t)j * r)];
        si += Cr[a + (size_t)i * r] * Z[2 * (i + (size_t)j * r) + 1];
      }
      CrZ[2 * (a + (size_t)j * m)] = sr; CrZ[2 * (a + (size_t)j * m) + 1] = si;
    }
  phgmg__zgemm('N', 'N', N, r, m, h->UC, N, CrZ, m, Yq, N);
  rc = phgmg__ztrsyl(1, N, h->T, r, S, Yq);
  if (rc != PHGMG_OK) return rc;
  rc = phgmg__h2gmg_small_gram(1, r, m, S, Z, CrZ, m, Ys, Qr, w4);
  if (rc != PHGMG_OK) return rc;
  phgmg__zgemm('C', 'N', r, r, N, Yq, N, Yp, N, Ys, r);
  phgmg__zcongr(r, Z, Ys, QP, w4);
  phgmg__zgemm('C', 'N', m, r, N, h->UC, N, Yp, N, CrZ, m);
  phgmg__zgemm('N', 'C', m, r, r, CrZ, m, Z, r, w4, m);
  for (i = 0; i < m * r; ++i) CP[i] = w4[2 * i];
  return PHGMG_OK;
}

/* Relative squared H2 error f = ||G - G_r||_H2^2 / ||G||_H2^2 of the GMG model
   of V = [B, Vbar] (Vbar N x k, any full-rank columns) and its gradient g
   (N x k) with respect to Vbar (may be NULL). Reduced model: M = V^T G V,
   K = M^-1, Qh = V^T Q V, Ar = K Qh, Br = [I; 0] (B = V [I; 0]), Cr = B^T Q V
   (the first m rows of Qh). Gradient: Wilson's conditions dJ/dAr = 2 (Q12^T
   P12 + Qr Pr), dJ/dCr = 2 (Cr Pr - C P12), chained through K and Qh.
   f = HUGE_VAL if M is singular or Ar not stable. */
PHGMG__PRIV double phgmg__h2gmg_eval(phgmg__h2gmg *h, const double *Vbar, double *g) {
  const int N = h->N, m = h->m, k = h->k, r = h->r;
  double *V = h->buf, *GV = V + (size_t)N * r, *GtV = GV + (size_t)N * r, *QV = GtV + (size_t)N * r;
  double *gV = QV + (size_t)N * r, *M = gV + (size_t)N * r, *K = M + (size_t)r * r, *Qh = K + (size_t)r * r;
  double *Ar = Qh + (size_t)r * r, *Pr = Ar + (size_t)r * r, *Qr = Pr + (size_t)r * r, *QP = Qr + (size_t)r * r;
  double *CP = QP + (size_t)r * r, *gA = CP + (size_t)m * r, *W1 = gA + (size_t)r * r, *W2 = W1 + (size_t)r * r;
  double *S = W2 + (size_t)r * r, *Z = S + 2 * (size_t)r * r, *w = Z + 2 * (size_t)r * r;
  int *ip = (int *)(void *)(w + 4 * (size_t)N * r + 16 * (size_t)r * r + 4 * (size_t)r);
  double J, tc = 0.0, tp = 0.0;
  int i, j, a;
  memcpy(V, h->sys->B, (size_t)N * m * sizeof(double));
  memcpy(V + (size_t)N * m, Vbar, (size_t)N * k * sizeof(double));
  phgmg_ph_apply(h->sys, 'Q', r, V, N, QV, N);
  memcpy(GV, V, (size_t)N * r * sizeof(double));
  memcpy(GtV, V, (size_t)N * r * sizeof(double));
  phgmg_jr_solve(h->jr, 'N', r, GV, N);
  phgmg_jr_solve(h->jr, 'T', r, GtV, N);
  phgmg_gemm('T', 'N', r, r, N, 1.0, V, N, GV, N, 0.0, M, r);
  phgmg_gemm('T', 'N', r, r, N, 1.0, V, N, QV, N, 0.0, Qh, r);
  for (i = 0; i < r * r; ++i) K[i] = 0.0;
  for (i = 0; i < r; ++i) K[i + (size_t)i * r] = 1.0;
  if (phgmg_lu_factor(r, M, r, ip) != PHGMG_OK) return HUGE_VAL;
  phgmg_lu_solve('N', r, M, r, ip, r, K, r);
  phgmg_gemm('N', 'N', r, r, r, 1.0, K, r, Qh, r, 0.0, Ar, r);
  if (phgmg__zschur(r, Ar, r, S, Z, w) != PHGMG_OK) return HUGE_VAL;
  for (i = 0; i < r; ++i)
    if (!(S[2 * (i + (size_t)i * r)] < 0.0)) return HUGE_VAL;
  if (phgmg__h2gmg_gram(h, Qh, S, Z, Pr, Qr, QP, CP, w) != PHGMG_OK) return HUGE_VAL;
  for (a = 0; a < m; ++a)   /* tr(Cr Pr Cr^T), tr(C P12 Cr^T); Cr = Qh(0:m, :) */
    for (j = 0; j < r; ++j) {
      double s = 0.0;
      for (i = 0; i < r; ++i) s += Qh[a + (size_t)i * r] * Pr[i + (size_t)j * r];
      tc += s * Qh[a + (size_t)j * r];
      tp += CP[a + (size_t)j * m] * Qh[a + (size_t)j * r];
    }
  J = h->h2ref + tc - 2.0 * tp;
  if (!g) return J / h->h2ref;
  for (i = 0; i < r * r; ++i) gA[i] = 2.0 * QP[i];
  phgmg_gemm('N', 'N', r, r, r, 2.0, Qr, r, Pr, r, 1.0, gA, r);
  phgmg_gemm('N', 'T', r, r, r, 1.0, gA, r, Qh, r, 0.0, W1, r);        /* Z1 = gA Qh^T */
  phgmg_gemm('T', 'N', r, r, r, 1.0, K, r, W1, r, 0.0, W2, r);
  phgmg_gemm('N', 'T', r, r, r, -1.0, W2, r, K, r, 0.0, W1, r);        /* Y1 = -K^T Z1 K^T */
  phgmg_gemm('N', 'T', N, r, r, 1.0, GV, N, W1, r, 0.0, gV, N);
  phgmg_gemm('N', 'N', N, r, r, 1.0, GtV, N, W1, r, 1.0, gV, N);
  phgmg_gemm('T', 'N', r, r, r, 1.0, K, r, gA, r, 0.0, W2, r);         /* X2 = K^T gA */
  for (j = 0; j < r; ++j)
    for (i = 0; i < r; ++i) W1[i + (size_t)j * r] = W2[i + (size_t)j * r] + W2[j + (size_t)i * r];
  phgmg_gemm('N', 'N', N, r, r, 1.0, QV, N, W1, r, 1.0, gV, N);
  for (j = 0; j < r; ++j)   /* gC = 2 (Cr Pr - C P12) (m x r) into W2 */
    for (a = 0; a < m; ++a) {
      double s = 0.0;
      for (i = 0; i < r; ++i) s += Qh[a + (size_t)i * r] * Pr[i + (size_t)j * r];
      W2[a + (size_t)j * m] = 2.0 * (s - CP[a + (size_t)j * m]);
    }
  phgmg_gemm('N', 'N', N, r, m, 1.0, QV, N, W2, m, 1.0, gV, N);        /* + Q B gC */
  for (i = 0; i < N * k; ++i) g[i] = gV[(size_t)N * m + i] / h->h2ref;
  return J / h->h2ref;
}

/* Minimises f = phgmg__h2gmg_eval over x = Vbar (n = N k entries) by L-BFGS
   (memory 50, Armijo backtracking, first step of unit length); stops after
   maxit iterations or when a line search fails twice in a row (the second
   time from a steepest-descent step). *f_out: the last f. */
PHGMG__PRIV phgmg_result phgmg__h2gmg_lbfgs(phgmg__h2gmg *h, double *x, int maxit, double *f_out,
                                            const phgmg_allocator *alloc) {
  enum { MEM = 50 };
  const int n = h->N * h->k;
  double *g = phgmg__dalloc(alloc, (size_t)n * (4 + 2 * MEM)), *d, *xn, *gn, *S, *Y, rho[MEM], al[MEM], f, fn = 0.0;
  int it, nm = 0, head = 0, i, l, fails = 0;
  if (!g) return PHGMG_ERR_NOMEM;
  d = g + n; xn = d + n; gn = xn + n; S = gn + n; Y = S + (size_t)MEM * n;
  f = phgmg__h2gmg_eval(h, x, g);
  if (!(f < HUGE_VAL)) { phgmg__free(alloc, g); return PHGMG_ERR_SINGULAR; }
  for (it = 0; it < maxit; ++it) {
    double gd = 0.0, t = 1.0, gam = 1.0, sy = 0.0, yy = 0.0;
    int ls;
    for (i = 0; i < n; ++i) d[i] = -g[i];
    for (l = 0; l < nm; ++l) {   /* two-loop recursion, newest first */
      const int q = (head - 1 - l + MEM) % MEM;
      al[q] = rho[q] * phgmg__dot(n, S + (size_t)q * n, d);
      phgmg__axpy(n, -al[q], Y + (size_t)q * n, d);
    }
    if (nm) {
      const int q = (head - 1 + MEM) % MEM;
      sy = phgmg__dot(n, S + (size_t)q * n, Y + (size_t)q * n);
      yy = phgmg__dot(n, Y + (size_t)q * n, Y + (size_t)q * n);
      gam = sy / yy;
    } else {
      yy = phgmg__dot(n, g, g);
      gam = yy > 0.0 ? 1.0 / sqrt(yy) : 1.0;
    }
    for (i = 0; i < n; ++i) d[i] *= gam;
    for (l = nm - 1; l >= 0; --l) {
      const int q = (head - 1 - l + MEM) % MEM;
      phgmg__axpy(n, al[q] - rho[q] * phgmg__dot(n, Y + (size_t)q * n, d), S + (size_t)q * n, d);
    }
    gd = phgmg__dot(n, g, d);
    if (!(gd < 0.0)) { nm = 0; continue; }   /* not a descent direction: restart */
    for (ls = 0; ls < 40; ++ls, t *= 0.5) {
      for (i = 0; i < n; ++i) xn[i] = x[i] + t * d[i];
      fn = phgmg__h2gmg_eval(h, xn, gn);
      if (fn <= f + 1e-4 * t * gd) break;
    }
    if (ls == 40) {
      if (nm == 0 || ++fails > 1) break;
      nm = 0;
      continue;
    }
    fails = 0;
    sy = 0.0;
    for (i = 0; i < n; ++i) {
      S[(size_t)head * n + i] = xn[i] - x[i];
      Y[(size_t)head * n + i] = gn[i] - g[i];
      sy += S[(size_t)head * n + i] * Y[(size_t)head * n + i];
    }
    if (sy > 0.0) {
      rho[head] = 1.0 / sy;
      head = (head + 1) % MEM;
      if (nm < MEM) ++nm;
    }
    memcpy(x, xn, (size_t)n * sizeof(double));
    memcpy(g, gn, (size_t)n * sizeof(double));
    f = fn;
  }
  *f_out = f;
  phgmg__free(alloc, g);
  return PHGMG_OK;
}

/* PHGMG_BASIS_H2: start (opts->V0 or the BALANCED basis), L-BFGS, then the
   Gram-Schmidt of [B, Vbar] in order (V: N x k). */
PHGMG__PRIV phgmg_result phgmg__basis_h2(const phgmg_ph_system *sys, int k, const phgmg_basis_opts *opts,
                                         double *V, const phgmg_allocator *alloc) {
  const int N = sys->N, m = sys->m, maxit = opts && opts->maxit > 0 ? opts->maxit : 1000;
  phgmg__h2gmg h;
  double *M, f = HUGE_VAL;
  phgmg_result rc;
  M = phgmg__dalloc(alloc, (size_t)N * (m + k) + (size_t)N + 2 * (size_t)(m + k));
  if (!M) return PHGMG_ERR_NOMEM;
  if (opts && opts->V0) memcpy(M + (size_t)N * m, opts->V0, (size_t)N * k * sizeof(double));
  rc = opts && opts->V0 ? PHGMG_OK
                        : phgmg_linear_basis(sys, PHGMG_BASIS_BALANCED, k, NULL, M + (size_t)N * m, NULL, alloc);
  if (rc == PHGMG_OK) rc = phgmg__h2gmg_init(&h, sys, k, alloc);
  if (rc == PHGMG_OK) {
    rc = phgmg__h2gmg_lbfgs(&h, M + (size_t)N * m, maxit, &f, alloc);
    if (rc == PHGMG_ERR_SINGULAR && opts && opts->V0) {   /* V0 infeasible: the balanced start */
      rc = phgmg_linear_basis(sys, PHGMG_BASIS_BALANCED, k, NULL, M + (size_t)N * m, NULL, alloc);
      if (rc == PHGMG_OK) rc = phgmg__h2gmg_lbfgs(&h, M + (size_t)N * m, maxit, &f, alloc);
    }
    phgmg__h2gmg_free(&h, alloc);
  }
  if (rc == PHGMG_OK) {
    double *tau = M + (size_t)N * (m + k);
    memcpy(M, sys->B, (size_t)N * m * sizeof(double));
    rc = phgmg_qr(N, m + k, M, N, tau);
    if (rc == PHGMG_OK) {
      phgmg_qr_form_q(N, m + k, M, N, tau, tau + (m + k));
      memcpy(V, M + (size_t)N * m, (size_t)N * k * sizeof(double));
    }
  }
  if (rc == PHGMG_OK && opts && opts->h2_rel) *opts->h2_rel = sqrt(f > 0.0 ? f : 0.0);
  phgmg__free(alloc, M);
  return rc;
}

/* phgmg_basis_opts within their documented ranges (0 = the default)? */
PHGMG__PRIV int phgmg__basis_opts_ok(const phgmg_basis_opts *o) {
  if (o->nw < 0 || o->nsteps < 0 || o->maxit < 0) return 0;
  if (!(o->wmin >= 0.0 && o->wmin < HUGE_VAL) || !(o->wmax >= 0.0 && o->wmax < HUGE_VAL)) return 0;
  if (o->wmin > 0.0 && o->wmax > 0.0 && !(o->wmin < o->wmax)) return 0;
  return o->dt >= 0.0 && o->dt < HUGE_VAL;
}

PHGMG_DEF phgmg_result phgmg_linear_basis(const phgmg_ph_system *sys, phgmg_basis_kind kind, int k,
                                          const phgmg_basis_opts *opts, double *V, int *k_out,
                                          const phgmg_allocator *alloc) {
  int N, m, ns = 0, kk = 0;
  double *X = NULL;
  phgmg_result rc;
  if (!sys || !V) return PHGMG_ERR_INVALID_ARG;
  if (sys && (sys->E || sys->P || sys->S || sys->Nskew)) return PHGMG_ERR_UNSUPPORTED; /* standard form only */
  if (kind < PHGMG_BASIS_FREQ || kind > PHGMG_BASIS_H2) return PHGMG_ERR_INVALID_ARG;
  if (opts && !phgmg__basis_opts_ok(opts)) return PHGMG_ERR_INVALID_ARG;
  if (sys->nl != PHGMG_NL_NONE) return PHGMG_ERR_UNSUPPORTED;
  rc = phgmg_ph_validate(sys, 0.0, NULL, alloc);
  if (rc != PHGMG_OK) return rc;
  N = sys->N; m = sys->m;
  if (k < 1 || k > N - m) return PHGMG_ERR_SIZE;
  if (kind == PHGMG_BASIS_H2 && opts && opts->V0 && !phgmg__mat_finite(N, k, opts->V0, N)) return PHGMG_ERR_NANINF;
  memset(V, 0, (size_t)N * k * sizeof(double));
  if (kind == PHGMG_BASIS_H2) {
    rc = phgmg__basis_h2(sys, k, opts, V, alloc);
    kk = rc == PHGMG_OK ? k : 0;
  } else if (kind == PHGMG_BASIS_BALANCED) {   /* QR of [B, T_k] in order */
    double *M = phgmg__dalloc(alloc, (size_t)N * (m + k) + (size_t)k * k + 2 * (size_t)m * k + 2 * (size_t)(m + k)), *tau;
    if (!M) return PHGMG_ERR_NOMEM;
    tau = M + (size_t)N * (m + k);
    memcpy(M, sys->B, (size_t)N * m * sizeof(double));
    rc = phgmg_bt(sys, k, tau + (m + k), tau + (m + k) + (size_t)k * k, tau + (m + k) + (size_t)k * k + (size_t)k * m,
                  NULL, M + (size_t)N * m, NULL, alloc);
    if (rc == PHGMG_OK) rc = phgmg_qr(N, m + k, M, N, tau);
    if (rc == PHGMG_OK) {
      phgmg_qr_form_q(N, m + k, M, N, tau, tau + (m + k));
      memcpy(V, M + (size_t)N * m, (size_t)N * k * sizeof(double));
      kk = k;
    }
    phgmg__free(alloc, M);
  } else {
    rc = phgmg__basis_snapshots(sys, kind, opts, &X, &ns, alloc);
    if (rc == PHGMG_OK) rc = phgmg_adjust_snapshots(N, m, sys->B, ns, X, N, X, N, alloc);
    if (rc == PHGMG_OK) rc = phgmg_pod(N, ns, X, N, k, 0.0, V, N, NULL, &kk, alloc);
    phgmg__free(alloc, X);
  }
  if (k_out) *k_out = kk;
  return rc;
}

PHGMG_DEF phgmg_result phgmg_ss_transfer(int n, int m, int p, const double *A, const double *B,
                                         const double *C, double w, double *G, const phgmg_allocator *alloc) {
  double *Z, *Bz;
  int *ip, i, a, b;
  phgmg_result rc;
  if (!A || !B || !C || !G) return PHGMG_ERR_INVALID_ARG;
  if (n < 1 || m < 1 || p < 1) return PHGMG_ERR_SIZE;
  Z = phgmg__dalloc(alloc, 2 * (size_t)n * n + 2 * (size_t)n * m);
  ip = phgmg__ialloc(alloc, (size_t)n);
  if (!Z || !ip) { phgmg__free(alloc, Z); phgmg__free(alloc, ip); return PHGMG_ERR_NOMEM; }
  Bz = Z + 2 * (size_t)n * n;
  for (i = 0; i < n * n; ++i) { Z[2 * i] = -A[i]; Z[2 * i + 1] = 0.0; }
  for (i = 0; i < n; ++i) Z[2 * (i + (size_t)i * n) + 1] = w;
  for (i = 0; i < n * m; ++i) { Bz[2 * i] = B[i]; Bz[2 * i + 1] = 0.0; }
  rc = phgmg_zlu_factor(n, Z, n, ip);
  if (rc == PHGMG_OK) {
    phgmg_zlu_solve(n, Z, n, ip, m, Bz, n);
    for (b = 0; b < m; ++b)
      for (a = 0; a < p; ++a) {
        double re = 0.0, im = 0.0;
        for (i = 0; i < n; ++i) {
          re += C[a + (size_t)i * p] * Bz[2 * (i + (size_t)b * n)];
          im += C[a + (size_t)i * p] * Bz[2 * (i + (size_t)b * n) + 1];
        }
        G[2 * (a + (size_t)b * p)] = re;
        G[2 * (a + (size_t)b * p) + 1] = im;
      }
  }
  phgmg__free(alloc, Z);
  phgmg__free(alloc, ip);
  return rc;
}

PHGMG_DEF phgmg_result phgmg_reduced_abc(const phgmg_reduced *red, double *A, double *B, double *C) {
  int r, m, i, a;
  if (!red || !A || !B || !C) return PHGMG_ERR_INVALID_ARG;
  if (red->kind != PHGMG_ROM_LINEAR || red->nd != 0 || !red->K || !red->Qh) return PHGMG_ERR_UNSUPPORTED;
  r = red->r; m = red->m;
  phgmg_gemm('N', 'N', r, r, r, 1.0, red->K, r, red->Qh, r, 0.0, A, r);
  memcpy(B, red->Bh, (size_t)r * m * sizeof(double));
  for (a = 0; a < m; ++a)
    for (i = 0; i < r; ++i) {
      double s = 0.0;
      int j;
      for (j = 0; j < r; ++j) s += red->Bh[j + (size_t)a * r] * red->Qh[j + (size_t)i * r];
      C[a + (size_t)i * m] = s;
    }
  return PHGMG_OK;
}

/* Largest singular value of a complex p x m matrix (interleaved), through
   the symmetric real embedding of E^H E. */
PHGMG__PRIV double phgmg__zsigma_max(int p, int m, const double *E) {
  double H[2 * 16 * 2 * 16], w[32];
  int i, j, k;
  if (m > 16) return (double)NAN;
  for (i = 0; i < m; ++i)
    for (j = 0; j < m; ++j) {
      double re = 0.0, im = 0.0;   /* (E^H E)_ij = sum_k conj(E_ki) E_kj */
      for (k = 0; k < p; ++k) {
        const double ar = E[2 * (k + (size_t)i * p)], ai = E[2 * (k + (size_t)i * p) + 1];
        const double br = E[2 * (k + (size_t)j * p)], bi = E[2 * (k + (size_t)j * p) + 1];
        re += ar * br + ai * bi;
        im += ar * bi - ai * br;
      }
      H[i + j * 2 * m] = re; H[(i + m) + (j + m) * 2 * m] = re;
      H[(i + m) + j * 2 * m] = im; H[i + (j + m) * 2 * m] = -im;
    }
  if (phgmg_sym_eig(2 * m, H, 2 * m, w, NULL, 0) != PHGMG_OK) return (double)NAN;
  return sqrt(w[2 * m - 1] > 0.0 ? w[2 * m - 1] : 0.0);
}

PHGMG_DEF phgmg_result phgmg_ss_compare(const phgmg_ss *g1, const phgmg_ss *g2, int nw, double wmin, double wmax,
                                        phgmg_ss_errors *err, const phgmg_allocator *alloc) {
  phgmg_ss_errors e;
  phgmg_result rc;
  if (!g1 || !g2 || !err) return PHGMG_ERR_INVALID_ARG;
  if (g1->m != g2->m || g1->p != g2->p) return PHGMG_ERR_SIZE;
  rc = phgmg_ss_error(g1->n, g1->A, g1->B, g1->C, g2->n, g2->A, g2->B, g2->C, g1->m, g1->p, nw, wmin, wmax,
                      &e.hinf, &e.hinf_ref, &e.h2, &e.h2_ref, alloc);
  if (rc == PHGMG_OK) *err = e;
  return rc;
}

PHGMG_DEF phgmg_result phgmg_ss_error(int n1, const double *A1, const double *B1, const double *C1,
                                      int n2, const double *A2, const double *B2, const double *C2,
                                      int m, int p, int nw, double wmin, double wmax, double *hinf,
                                      double *hinf_ref, double *h2, double *h2_ref,
                                      const phgmg_allocator *alloc) {
  const int n = n1 + n2;
  double *G1, *G2, *Ae, *Fe, *Pe, *Ce, hi = 0.0, hr = 0.0;
  phgmg_result rc = PHGMG_OK;
  int j, i, k;
  if (!A1 || !B1 || !C1 || !A2 || !B2 || !C2) return PHGMG_ERR_INVALID_ARG;
  if (n1 < 1 || n2 < 1 || m < 1 || p < 1 || m > 16 || nw < 1 || !(wmin > 0.0) || !(wmax >= wmin)) return PHGMG_ERR_SIZE;
  G1 = phgmg__dalloc(alloc, 4 * (size_t)p * m + 3 * (size_t)n * n + (size_t)p * n);
  if (!G1) return PHGMG_ERR_NOMEM;
  G2 = G1 + 2 * (size_t)p * m; Ae = G2 + 2 * (size_t)p * m; Fe = Ae + (size_t)n * n; Pe = Fe + (size_t)n * n;
  Ce = Pe + (size_t)n * n;
  for (j = 0; j < nw && rc == PHGMG_OK; ++j) {
    const double w = wmin * pow(wmax / wmin, nw > 1 ? (double)j / (nw - 1) : 0.0);
    rc = phgmg_ss_transfer(n1, m, p, A1, B1, C1, w, G1, alloc);
    if (rc == PHGMG_OK) rc = phgmg_ss_transfer(n2, m, p, A2, B2, C2, w, G2, alloc);
    if (rc != PHGMG_OK) break;
    hr = PHGMG__MAX(hr, phgmg__zsigma_max(p, m, G1));
    for (i = 0; i < 2 * p * m; ++i) G2[i] = G1[i] - G2[i];
    hi = PHGMG__MAX(hi, phgmg__zsigma_max(p, m, G2));
  }
  if (rc == PHGMG_OK && (h2 || h2_ref)) {   /* error system: blockdiag(A1, A2), [B1; B2], [C1, -C2] */
    double *Bf = phgmg__dalloc(alloc, (size_t)n * m);
    if (!Bf) rc = PHGMG_ERR_NOMEM;
    else {
      memset(Ae, 0, (size_t)n * n * sizeof(double));
      for (j = 0; j < n1; ++j) for (i = 0; i < n1; ++i) Ae[i + (size_t)j * n] = A1[i + (size_t)j * n1];
      for (j = 0; j < n2; ++j) for (i = 0; i < n2; ++i) Ae[(n1 + i) + (size_t)(n1 + j) * n] = A2[i + (size_t)j * n2];
      for (k = 0; k < m; ++k) {
        for (i = 0; i < n1; ++i) Bf[i + (size_t)k * n] = B1[i + (size_t)k * n1];
        for (i = 0; i < n2; ++i) Bf[n1 + i + (size_t)k * n] = B2[i + (size_t)k * n2];
      }
      for (i = 0; i < n1; ++i) for (k = 0; k < p; ++k) Ce[k + (size_t)i * p] = C1[k + (size_t)i * p];
      for (i = 0; i < n2; ++i) for (k = 0; k < p; ++k) Ce[k + (size_t)(n1 + i) * p] = -C2[k + (size_t)i * p];
      phgmg_gemm('N', 'T', n, n, m, 1.0, Bf, n, Bf, n, 0.0, Fe, n);
      rc = phgmg_lyap(n, Ae, Fe, Pe, NULL, alloc);
      if (rc == PHGMG_OK) {
        double te = 0.0, t1 = 0.0;
        for (k = 0; k < p; ++k)
          for (i = 0; i < n; ++i)
            for (j = 0; j < n; ++j) {
              const double v = Ce[k + (size_t)i * p] * Pe[i + (size_t)j * n] * Ce[k + (size_t)j * p];
              te += v;
              if (i < n1 && j < n1) t1 += v;
            }
        if (h2) *h2 = sqrt(te > 0.0 ? te : 0.0);
        if (h2_ref) *h2_ref = sqrt(t1 > 0.0 ? t1 : 0.0);
      }
      phgmg__free(alloc, Bf);
    }
  }
  if (rc == PHGMG_OK) {
    if (hinf) *hinf = hi;
    if (hinf_ref) *hinf_ref = hr;
  }
  phgmg__free(alloc, G1);
  return rc;
}
#endif /* PHGMG_NO_OFFLINE */

/* >>export (implementation) ============================================== */
#include <stdint.h>

/* The arrays of a phgmg_rom in file order, with their sizes. */
#define PHGMG__NFIELDS 29
typedef struct phgmg__field { size_t off; const char *name; } phgmg__field;
static const phgmg__field phgmg__fields[PHGMG__NFIELDS] = {
  {offsetof(phgmg_rom, Bh), "Bh"},   {offsetof(phgmg_rom, Qh), "Qh"},   {offsetof(phgmg_rom, K), "K"},
  {offsetof(phgmg_rom, G00), "G00"}, {offsetof(phgmg_rom, G01), "G01"}, {offsetof(phgmg_rom, G10), "G10"},
  {offsetof(phgmg_rom, G11), "G11"}, {offsetof(phgmg_rom, Q01), "Q01"}, {offsetof(phgmg_rom, Q11), "Q11"},
  {offsetof(phgmg_rom, Ms), "Ms"},   {offsetof(phgmg_rom, P0), "P0"},   {offsetof(phgmg_rom, P1), "P1"},
  {offsetof(phgmg_rom, w), "w"},     {offsetof(phgmg_rom, poly), "poly"}, {offsetof(phgmg_rom, Phi), "Phi"},
  {offsetof(phgmg_rom, Gam), "Gam"}, {offsetof(phgmg_rom, SX), "SX"},   {offsetof(phgmg_rom, SU), "SU"},
  {offsetof(phgmg_rom, expo), "expo"},
  {offsetof(phgmg_rom, env_lo), "env_lo"}, {offsetof(phgmg_rom, env_hi), "env_hi"},
  {offsetof(phgmg_rom, q_max), "q_max"},
  {offsetof(phgmg_rom, Cd), "Cd"}, {offsetof(phgmg_rom, dw), "dw"}, {offsetof(phgmg_rom, dpoly), "dpoly"},
  {offsetof(phgmg_rom, PD), "PD"},
  {offsetof(phgmg_rom, ref_g), "ref_g"}, {offsetof(phgmg_rom, ref_s), "ref_s"},
  {offsetof(phgmg_rom, xr_rest), "xr_rest"}};

PHGMG__ONLINE const phgmg_real **phgmg__field_ptr(phgmg_rom *rom, int i) {
  return PHGMG__CAST(const phgmg_real **, PHGMG__CAST(void *, PHGMG__CAST(char *, PHGMG__CAST(void *, rom)) + phgmg__fields[i].off));
}
PHGMG__ONLINE const phgmg_real *phgmg__field_get(const phgmg_rom *rom, int i) {
  if (!phgmg__fields[i].name) return NULL;
  return *PHGMG__CAST(const phgmg_real *const *, PHGMG__CAST(const void *, PHGMG__CAST(const char *, PHGMG__CAST(const void *, rom)) + phgmg__fields[i].off));
}
/* Number of scalars of field i (0 if the field does not apply). */
PHGMG__ONLINE size_t phgmg__field_len(const phgmg_rom *rom, int i) {
  const size_t r = (size_t)rom->r, m = (size_t)rom->m, rn = (size_t)rom->rn, nd = (size_t)rom->nd;
  const size_t p = (size_t)(rom->r - rom->m), nf = (size_t)(rom->nphi > 1 ? rom->nphi : 1);
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
    case 13: return nd ? nf * ((size_t)rom->poly_deg + 1) : 0;
    case 14: return r * r;
    case 15: return r * 3 * m;
    case 16: return 3 * r * r;
    case 17: return 3 * r * 3 * m;
    case 18: return nd ? nf * 2 * (size_t)rom->nexp : 0;
    case 19: case 20: return r;   /* env_lo, env_hi */
    case 21: return 1;            /* q_max */
    case 22: return r * (size_t)rom->ndamp;   /* Cd */
    case 23: return (size_t)rom->ndamp;       /* dw */
    case 24: return rom->ndamp ? (size_t)(rom->damp_nphi > 1 ? rom->damp_nphi : 1) * ((size_t)rom->damp_deg + 1) : 0;
    case 25: return (r + m) * m;              /* PD */
    case 26: return r + (rom->kind == PHGMG_ROM_QUADRATIC ? rn : 0) + 1;   /* ref_g */
    case 27: return nd;           /* ref_s */
    case 28: return r;            /* xr_rest */
    default: return 0;
  }
}

#define PHGMG__HDR_BYTES (8 + 4 * 10 + 8)
/* Version 2 (written only when a model needs it): nexp, nphi, nterm after the
   version-1 header; the expo field (mask bit 18; the training envelope and
   q_max, bits 19-21, may sit in either version); nterm (0 or nd) uint32 term
   indices after the scalars. */
#define PHGMG__HDR2_BYTES (PHGMG__HDR_BYTES + 12)
/* Version 3 (written only for a model with dampers or feedthrough): the
   version-2 header, then ndamp, damp_deg, damp_nphi (0 without dampers);
   the fields Cd, dw, dpoly (bits 22-24, with dampers) and PD (bit 25). */
#define PHGMG__HDR3_BYTES (PHGMG__HDR2_BYTES + 12)
PHGMG__ONLINE int phgmg__rom_v3(const phgmg_rom *rom) { return rom->ndamp > 0 || rom->PD; }
PHGMG__ONLINE int phgmg__rom_v2(const phgmg_rom *rom) {
  return (rom->nd > 0 && (rom->nexp > 0 || rom->nphi > 1 || rom->term)) || phgmg__rom_v3(rom);
}
PHGMG__ONLINE size_t phgmg__rom_nterm(const phgmg_rom *rom) {
  return phgmg__rom_v2(rom) && rom->term ? (size_t)rom->nd : 0;
}

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
  if (!phgmg__rom_v2(rom)) return PHGMG__HDR_BYTES + n * sizeof(phgmg_real) + 4;
  return (phgmg__rom_v3(rom) ? PHGMG__HDR3_BYTES : PHGMG__HDR2_BYTES) + n * sizeof(phgmg_real) +
         4 * phgmg__rom_nterm(rom) + 4;
}

PHGMG_DEF phgmg_result phgmg_rom_serialize(const phgmg_rom *rom, void *buf, size_t cap, size_t *written) {
  unsigned char *b = PHGMG__CAST(unsigned char *, buf);
  size_t need, o, k;
  uint32_t mask = 0;
  int i;
  phgmg_result rc = phgmg_rom_check(rom);
  if (rc != PHGMG_OK) return rc;
  if (rom->phi_cb || rom->eta_cb || rom->ham_cb || rom->damp_cb) return PHGMG_ERR_UNSUPPORTED;
  if (!buf) return PHGMG_ERR_INVALID_ARG;
  need = phgmg_rom_serialized_size(rom);
  if (cap < need) return PHGMG_ERR_WORKSPACE;
  for (i = 0; i < PHGMG__NFIELDS; ++i)
    if (phgmg__field_get(rom, i) && phgmg__field_len(rom, i) > 0) mask |= 1u << i;
  memcpy(b, "PHGMGROM", 8);
  phgmg__put32(b + 8, phgmg__rom_v3(rom) ? 3u : phgmg__rom_v2(rom) ? 2u : 1u);
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
  if (phgmg__rom_v2(rom)) {
    phgmg__put32(b + o, (uint32_t)rom->nexp);
    phgmg__put32(b + o + 4, (uint32_t)rom->nphi);
    phgmg__put32(b + o + 8, (uint32_t)phgmg__rom_nterm(rom));
    o = PHGMG__HDR2_BYTES;
  }
  if (phgmg__rom_v3(rom)) {
    phgmg__put32(b + o, (uint32_t)rom->ndamp);
    phgmg__put32(b + o + 4, (uint32_t)rom->damp_deg);
    phgmg__put32(b + o + 8, (uint32_t)rom->damp_nphi);
    o = PHGMG__HDR3_BYTES;
  }
  for (i = 0; i < PHGMG__NFIELDS; ++i) {
    const phgmg_real *a = phgmg__field_get(rom, i);
    size_t n = phgmg__field_len(rom, i);
    if (!a) continue;
    for (k = 0; k < n; ++k, o += sizeof(phgmg_real)) {
#if PHGMG_REAL_IS_FLOAT
      phgmg__put_f32(b + o, a[k]);
#else
      phgmg__put_f64(b + o, a[k]);
#endif
    }
  }
  for (k = 0; k < phgmg__rom_nterm(rom); ++k, o += 4) phgmg__put32(b + o, (uint32_t)rom->term[k]);
  phgmg__put32(b + o, phgmg__fnv1a(b, o));
  if (written) *written = o + 4;
  return PHGMG_OK;
}

/* Parse and validate the header; fills rom's scalars and returns the scalar
   count of the payload and the file's scalar size. */
PHGMG__ONLINE phgmg_result phgmg__rom_header(const unsigned char *b, size_t len, phgmg_rom *rom,
                                             size_t *nscal, size_t *ssize, uint32_t *mask_out,
                                             size_t *nterm_out) {
  uint32_t ver, ss, mask;
  size_t n = 0, total, hdr = PHGMG__HDR_BYTES, nterm = 0;
  int i;
  if (!b) return PHGMG_ERR_INVALID_ARG;
  if (len < PHGMG__HDR_BYTES + 4 || memcmp(b, "PHGMGROM", 8) != 0) return PHGMG_ERR_FORMAT;
  ver = phgmg__get32(b + 8);
  ss = phgmg__get32(b + 12);
  if ((ver != 1u && ver != 2u && ver != 3u) || (ss != 4 && ss != 8)) return PHGMG_ERR_FORMAT;
  memset(rom, 0, sizeof *rom);
  if (ver == 3u) {
    if (len < PHGMG__HDR3_BYTES + 4) return PHGMG_ERR_FORMAT;
    if (phgmg__get32(b + 68) > (1u << 24) || phgmg__get32(b + 72) > 15u || phgmg__get32(b + 76) > (1u << 24) ||
        (phgmg__get32(b + 68) > 0u) != (phgmg__get32(b + 72) > 0u))
      return PHGMG_ERR_FORMAT;
    rom->ndamp = (int)phgmg__get32(b + 68);
    rom->damp_deg = (int)phgmg__get32(b + 72);
    rom->damp_nphi = (int)phgmg__get32(b + 76);
    if (rom->damp_nphi > 1 && rom->damp_nphi != rom->ndamp) return PHGMG_ERR_FORMAT;
  }
  if (ver >= 2u) {
    if (len < PHGMG__HDR2_BYTES + 4) return PHGMG_ERR_FORMAT;
    hdr = ver == 3u ? PHGMG__HDR3_BYTES : PHGMG__HDR2_BYTES;
    if (phgmg__get32(b + 56) > 8u || phgmg__get32(b + 60) > (1u << 24) || phgmg__get32(b + 64) > (1u << 24))
      return PHGMG_ERR_FORMAT;
    rom->nexp = (int)phgmg__get32(b + 56);
    rom->nphi = (int)phgmg__get32(b + 60);
    nterm = (size_t)phgmg__get32(b + 64);
  }
  if (phgmg__get32(b + 24) > 4096u || phgmg__get32(b + 28) > 4096u || phgmg__get32(b + 32) > 4096u ||
      phgmg__get32(b + 36) > (1u << 24) || phgmg__get32(b + 40) > 32u || phgmg__get32(b + 16) > 2u ||
      phgmg__get32(b + 20) > 6u)
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
#if PHGMG_REAL_IS_FLOAT
    if (dt > 3.4e38) return PHGMG_ERR_FORMAT; /* would be Inf as float */
#endif
    rom->dt = (phgmg_real)dt;
  }
  /* version 1: every field but expo (bit 18, which needs the version-2 header) */
  if ((mask >> PHGMG__NFIELDS) || (ver == 1u && (mask & (1u << 18)))) return PHGMG_ERR_FORMAT;
  /* dampers (bits 22-24, all three) exactly when the version-3 header has
     ndamp > 0; feedthrough (bit 25) only in version 3; version 3 has one */
  if ((rom->ndamp > 0) != ((mask & (7u << 22)) == (7u << 22)) || (rom->ndamp == 0 && (mask & (7u << 22))) ||
      (ver != 3u && (mask & (1u << 25))) || (ver == 3u && rom->ndamp == 0 && !(mask & (1u << 25))))
    return PHGMG_ERR_FORMAT;
  if (rom->m > rom->r) return PHGMG_ERR_FORMAT;
  if ((rom->nphi > 1 && rom->nphi != rom->nd) || (nterm != 0 && nterm != (size_t)rom->nd))
    return PHGMG_ERR_FORMAT;
  /* only the form the writer produces, so that a loaded model saves to the
     same bytes: version 2 exactly when the model needs it (phgmg__rom_v2),
     and no field of length 0 (the writer leaves those out) */
  if (ver == 2u && !(rom->nd > 0 && (rom->nexp > 0 || rom->nphi > 1 || nterm > 0))) return PHGMG_ERR_FORMAT;
  for (i = 0; i < PHGMG__NFIELDS; ++i)
    if (mask & (1u << i)) {
      size_t k = phgmg__field_len(rom, i);
      if (k == 0 || k > ((size_t)1 << 28)) return PHGMG_ERR_FORMAT;
      n += k;
    }
  if (n > (len / ss)) return PHGMG_ERR_FORMAT;
  {   /* the load-time structure check's scratch ((r + rn)^2 + ...) is bounded by
         the matrices a valid model holds (r x r blocks, and rn x rn blocks when
         quadratic): a small file declaring large sizes without them is refused
         here, before anyone sizes a buffer from it */
    const size_t n2 = (size_t)rom->r + (size_t)(rom->kind == PHGMG_ROM_QUADRATIC ? rom->rn : 0);
    if (n2 * n2 > 4 * n + 4) return PHGMG_ERR_FORMAT;
  }
  total = hdr + n * ss + 4 * nterm + 4;
  if (total != len) return PHGMG_ERR_FORMAT;
  if (phgmg__get32(b + total - 4) != phgmg__fnv1a(b, total - 4)) return PHGMG_ERR_FORMAT;
  *nscal = n;
  *ssize = ss;
  *mask_out = mask;
  *nterm_out = nterm;
  return PHGMG_OK;
}

/* ---- load-time structure check (phgmg_rom_deserialize) --------------------
   A file's checksum shows it arrived intact, not that its values describe a
   port-Hamiltonian model: a file rewritten with a fresh checksum could hold
   K -> -K (energy created), Qh -> -Qh (H unbounded below) or another dt than
   its step map's. On load, in phgmg_real and in the caller's memory:
   - the energy is positive: Qh (QUADRATIC: [Qh Q01; Q01^T Q11]) + d I
     positive definite (LDL^T pivots > 0), d = tol ||.||_1;
   - dissipation is not negative: LINEAR R = -(K + K^T)/2, QUADRATIC the
     negative symmetric part of [G00 G01; G10 G11] (sym(G) = -G R G^T for
     G = (J - R)^{-1}) plus d I positive definite, same d;
   - (J skew holds by construction: J = (K - K^T)/2 of the stored K;)
   - a step map is the GL3 map of x' = K Qh x + Bh u for the stored dt:
     each column s of [SX, SU] satisfies the stage equations
     s_i = e_i - h sum_j A_ij Jf s_j (e_i: 1 kron I resp. h A kron Bh) and
     [Phi, Gam] = base + h sum_i b_i Jf s_i, each residual within
     tolm (1 + |out| + (1 + h ||A|| ||K|| ||Qh||) |s|) (|.|: max-norm).
   tol = sqrt(eps), tolm = 48 (r + 1) eps with eps = 1.2e-7, float's unit
   roundoff, for every file: a model may have been rounded to float on its
   way (a float build, an f32 file) and saved again with 8-byte scalars.
   Failure: PHGMG_ERR_STRUCTURE. Work: (r + rn)^2 + 4 r + 4 reals. */
PHGMG__ONLINE size_t phgmg__rom_phys_work(const phgmg_rom *rom, uint32_t mask) {
  const size_t n2 = (size_t)rom->r + (size_t)(rom->kind == PHGMG_ROM_QUADRATIC ? rom->rn : 0);
  const size_t nf = (mask & (1u << 25)) ? (size_t)rom->r + (size_t)rom->m : 0;   /* feedthrough block */
  return (nf > n2 ? nf * nf : n2 * n2) + 4 * (size_t)rom->r + 4;
}

/* ||.||_1 of an n x n matrix. */
PHGMG__ONLINE phgmg_real phgmg__r_norm1(int n, const phgmg_real *A) {
  phgmg_real nm = PHGMG__R(0);
  int i, j;
  for (j = 0; j < n; ++j) {
    phgmg_real c = PHGMG__R(0);
    for (i = 0; i < n; ++i) c += PHGMG__RABS(A[i + (size_t)j * n]);
    if (c > nm) nm = c;
  }
  return nm;
}

/* S (n x n, symmetric, overwritten) + tol ||S||_1 I positive definite?
   LDL^T without pivoting: every pivot > 0. 1 if so (also for S = 0). */
PHGMG__ONLINE int phgmg__r_psd_shifted(int n, phgmg_real *S, phgmg_real tol) {
  const phgmg_real d = tol * phgmg__r_norm1(n, S);
  int i, j, k;
  if (d == PHGMG__R(0)) return 1;
  for (i = 0; i < n; ++i) S[i + (size_t)i * n] += d;
  for (j = 0; j < n; ++j) {   /* column j of L (unit) in S below the diagonal, D on it */
    phgmg_real djj = S[j + (size_t)j * n];
    for (k = 0; k < j; ++k) djj -= S[j + (size_t)k * n] * S[j + (size_t)k * n] * S[k + (size_t)k * n];
    if (!(djj > PHGMG__R(0))) return 0;
    S[j + (size_t)j * n] = djj;
    for (i = j + 1; i < n; ++i) {
      phgmg_real v = S[i + (size_t)j * n];
      for (k = 0; k < j; ++k) v -= S[i + (size_t)k * n] * S[j + (size_t)k * n] * S[k + (size_t)k * n];
      S[i + (size_t)j * n] = v / djj;
    }
  }
  return 1;
}

/* Residuals of one step-map column: s (3r, the column of SX or SU), out (r,
   the column of Phi or Gam), base (r) and stage right-hand sides e (3r);
   v: 4r scratch. 1 if within the bound above. */
PHGMG__ONLINE int phgmg__r_map_col(const phgmg_rom *rom, const phgmg_real *s, int lds, const phgmg_real *out,
                                   const phgmg_real *e, const phgmg_real *base, double kq, double eps,
                                   phgmg_real *v) {
  const int r = rom->r;
  const double h = (double)rom->dt, tolm = 48.0 * (r + 1) * eps, s15 = sqrt(15.0);
  const double b[3] = {5.0 / 18.0, 4.0 / 9.0, 5.0 / 18.0};
  const double A[9] = {5.0 / 36.0, 2.0 / 9.0 - s15 / 15.0, 5.0 / 36.0 - s15 / 30.0,
                       5.0 / 36.0 + s15 / 24.0, 2.0 / 9.0, 5.0 / 36.0 - s15 / 24.0,
                       5.0 / 36.0 + s15 / 30.0, 2.0 / 9.0 + s15 / 15.0, 5.0 / 36.0};
  double smax = 0.0, omax = 0.0, bound;
  int i, j, a;
  for (i = 0; i < 3; ++i) {   /* v_i = K (Qh s_i) */
    phgmg__r_gemv(r, r, rom->Qh, s + (size_t)i * r, 0, v + 3 * (size_t)r);
    phgmg__r_gemv(r, r, rom->K, v + 3 * (size_t)r, 0, v + (size_t)i * r);
    for (a = 0; a < r; ++a) smax = fmax(smax, fabs((double)s[a + (size_t)i * r]));
  }
  (void)lds;
  for (a = 0; a < r; ++a) omax = fmax(omax, fabs((double)out[a]));
  bound = tolm * (1.0 + omax + (1.0 + h * kq) * smax);   /* ||A||_inf < 1, sum b = 1 */
  for (i = 0; i < 3; ++i)
    for (a = 0; a < r; ++a) {
      double res = (double)s[a + (size_t)i * r] - (double)e[a + (size_t)i * r];
      for (j = 0; j < 3; ++j) res -= h * A[i * 3 + j] * (double)v[a + (size_t)j * r];
      if (!(fabs(res) <= bound)) return 0;
    }
  for (a = 0; a < r; ++a) {
    double res = (double)out[a] - (double)base[a];
    for (i = 0; i < 3; ++i) res -= h * b[i] * (double)v[a + (size_t)i * r];
    if (!(fabs(res) <= bound)) return 0;
  }
  return 1;
}

/* The step map's columns (see above); w: 4r + 4r scratch. */
PHGMG__ONLINE int phgmg__rom_map_ok(const phgmg_rom *rom, double eps, phgmg_real *w) {
  const int r = rom->r, m = rom->m, n3 = 3 * r;
  const double h = (double)rom->dt, s15 = sqrt(15.0);
  const double b[3] = {5.0 / 18.0, 4.0 / 9.0, 5.0 / 18.0};
  const double A[9] = {5.0 / 36.0, 2.0 / 9.0 - s15 / 15.0, 5.0 / 36.0 - s15 / 30.0,
                       5.0 / 36.0 + s15 / 24.0, 2.0 / 9.0, 5.0 / 36.0 - s15 / 24.0,
                       5.0 / 36.0 + s15 / 30.0, 2.0 / 9.0 + s15 / 15.0, 5.0 / 36.0};
  const double kq = (double)phgmg__r_norm1(r, rom->K) * (double)phgmg__r_norm1(r, rom->Qh);
  phgmg_real *e = w, *base = e + n3, *v = base + r;   /* 3r + r + 4r: the caller gives (r + rn)^2 + 4r + 4 >= 8r */
  int c, i, a, jj, bb;
  for (c = 0; c < r; ++c) {   /* SX, Phi: e = 1 kron e_c, base = e_c */
    for (i = 0; i < n3; ++i) e[i] = PHGMG__R(i % r == c ? 1 : 0);
    for (a = 0; a < r; ++a) base[a] = PHGMG__R(a == c ? 1 : 0);
    if (!phgmg__r_map_col(rom, rom->SX + (size_t)c * n3, n3, rom->Phi + (size_t)c * r, e, base, kq, eps, v)) return 0;
  }
  for (jj = 0; jj < 3; ++jj)   /* SU, Gam: column (jj, bb): e_i = h A_{i,jj} Bh_bb, base = h b_jj Bh_bb */
    for (bb = 0; bb < m; ++bb) {
      const int col = jj * m + bb;
      for (i = 0; i < 3; ++i)
        for (a = 0; a < r; ++a) e[a + (size_t)i * r] = (phgmg_real)(h * A[i * 3 + jj] * (double)rom->Bh[a + (size_t)bb * r]);
      for (a = 0; a < r; ++a) base[a] = (phgmg_real)(h * b[jj] * (double)rom->Bh[a + (size_t)bb * r]);
      if (!phgmg__r_map_col(rom, rom->SU + (size_t)col * n3, n3, rom->Gam + (size_t)col * r, e, base, kq, eps, v))
        return 0;
    }
  return 1;
}

/* The load-time structure check (see above) of a model that passed
   phgmg_rom_check; eps: the unit roundoff of the values (the larger of the
   file's scalars' and phgmg_real's); w: phgmg__rom_phys_work(rom) reals. */
/* Feedthrough of a loaded model: [[-sym K, Ph], [Ph^T, sym Dh]] + d I
   positive definite (d as for the dissipation above); w: (r + m)^2 reals. */
PHGMG__ONLINE int phgmg__rom_feed_ok(const phgmg_rom *rom, phgmg_real tol, phgmg_real *w) {
  const int r = rom->r, m = rom->m, n = r + m;
  const phgmg_real *Dh = rom->PD + (size_t)r * m;
  int i, j;
  for (j = 0; j < n; ++j)
    for (i = 0; i < n; ++i) {
      phgmg_real v;
      if (i < r && j < r) v = -PHGMG__R(0.5) * (rom->K[i + (size_t)j * r] + rom->K[j + (size_t)i * r]);
      else if (i < r) v = rom->PD[i + (size_t)(j - r) * r];
      else if (j < r) v = rom->PD[j + (size_t)(i - r) * r];
      else v = PHGMG__R(0.5) * (Dh[(i - r) + (size_t)(j - r) * m] + Dh[(j - r) + (size_t)(i - r) * m]);
      w[i + (size_t)j * n] = v;
    }
  return phgmg__r_psd_shifted(n, w, tol);
}

/* Dampers of a loaded model dissipate: weights >= 0, every law an odd
   polynomial with coefficients >= 0 (manual 1.7). */
PHGMG__ONLINE phgmg_result phgmg__rom_damp_ok(const phgmg_rom *rom) {
  const int nf = rom->damp_nphi > 1 ? rom->damp_nphi : 1;
  int j, e;
  if (!rom->dpoly || !rom->dw) return PHGMG_ERR_STRUCTURE;
  for (j = 0; j < rom->ndamp; ++j)
    if (!(rom->dw[j] >= PHGMG__R(0))) return PHGMG_ERR_STRUCTURE;
  for (j = 0; j < nf; ++j)
    for (e = 0; e <= rom->damp_deg; ++e) {
      const phgmg_real a = rom->dpoly[(size_t)j * (size_t)(rom->damp_deg + 1) + (size_t)e];
      if ((e % 2 == 0 && a != PHGMG__R(0)) || a < PHGMG__R(0)) return PHGMG_ERR_STRUCTURE;
    }
  return PHGMG_OK;
}

PHGMG__ONLINE phgmg_result phgmg__rom_physics(const phgmg_rom *rom, double eps, phgmg_real *w) {
  const int r = rom->r, quad = rom->kind == PHGMG_ROM_QUADRATIC, rn = quad ? rom->rn : 0, n2 = r + rn;
  const phgmg_real tol = (phgmg_real)sqrt(eps);
  int i, j;
  /* energy: [Qh Q01; Q01^T Q11] */
  for (j = 0; j < n2; ++j)
    for (i = 0; i < n2; ++i) {
      phgmg_real v;
      if (i < r && j < r) v = rom->Qh[i + (size_t)j * r];
      else if (i < r) v = rom->Q01[i + (size_t)(j - r) * r];
      else if (j < r) v = rom->Q01[j + (size_t)(i - r) * r];
      else v = rom->Q11[(i - r) + (size_t)(j - r) * rn];
      w[i + (size_t)j * n2] = v;
    }
  if (!phgmg__r_psd_shifted(n2, w, tol)) return PHGMG_ERR_STRUCTURE;
  if (rom->nd == 0 && phgmg__r_norm1(r, rom->Qh) == PHGMG__R(0)) return PHGMG_ERR_STRUCTURE; /* H = 0 */
  /* dissipation: -(M + M^T)/2, M = K or the G blocks */
  for (j = 0; j < n2; ++j)
    for (i = 0; i < n2; ++i) {
      phgmg_real a, b;
      if (!quad) { a = rom->K[i + (size_t)j * r]; b = rom->K[j + (size_t)i * r]; }
      else {
#define PHGMG__GIJ(ii, jj) ((ii) < r ? ((jj) < r ? rom->G00[(ii) + (size_t)(jj) * r] : rom->G01[(ii) + (size_t)((jj) - r) * r]) \
                                     : ((jj) < r ? rom->G10[((ii) - r) + (size_t)(jj) * rn] : rom->G11[((ii) - r) + (size_t)((jj) - r) * rn]))
        a = PHGMG__GIJ(i, j); b = PHGMG__GIJ(j, i);
#undef PHGMG__GIJ
      }
      w[i + (size_t)j * n2] = -PHGMG__R(0.5) * (a + b);
    }
  if (!phgmg__r_psd_shifted(n2, w, tol)) return PHGMG_ERR_STRUCTURE;
  if (rom->Phi && (!rom->K || !phgmg__rom_map_ok(rom, eps, w))) return PHGMG_ERR_STRUCTURE;
  if (rom->PD && !phgmg__rom_feed_ok(rom, tol, w)) return PHGMG_ERR_STRUCTURE;
  return rom->ndamp ? phgmg__rom_damp_ok(rom) : PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_rom_deserialize_size(const void *buf, size_t len, size_t *need) {
  phgmg_rom tmp;
  size_t n = 0, ss = 0;
  uint32_t mask = 0;
  size_t nterm = 0;
  phgmg_result rc = phgmg__rom_header(PHGMG__CAST(const unsigned char *, buf), len, &tmp, &n, &ss, &mask, &nterm);
  if (rc != PHGMG_OK) return rc;
  if (need) *need = (n + phgmg__rom_phys_work(&tmp, mask)) * sizeof(phgmg_real) + sizeof(phgmg_real) + nterm * sizeof(int);
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_rom_deserialize(const void *buf, size_t len, phgmg_rom *rom, void *mem,
                                             size_t mem_size) {
  const unsigned char *b = PHGMG__CAST(const unsigned char *, buf);
  phgmg_rom tmp;
  size_t n = 0, ss = 0, o, k, nterm = 0;
  uint32_t mask = 0;
  phgmg_real *dst = PHGMG__CAST(phgmg_real *, mem), *work;
  phgmg_result rc;
  int i;
  if (!rom || !mem) return PHGMG_ERR_INVALID_ARG;
  rc = phgmg__rom_header(b, len, &tmp, &n, &ss, &mask, &nterm);
  if (rc != PHGMG_OK) return rc;
  if (mem_size < (n + phgmg__rom_phys_work(&tmp, mask)) * sizeof(phgmg_real) + sizeof(phgmg_real) + nterm * sizeof(int))
    return PHGMG_ERR_WORKSPACE;
  o = phgmg__get32(b + 8) == 1u ? PHGMG__HDR_BYTES : phgmg__get32(b + 8) == 2u ? PHGMG__HDR2_BYTES : PHGMG__HDR3_BYTES;
  if (((size_t)mem) % sizeof(phgmg_real) != 0) return PHGMG_ERR_INVALID_ARG;
  for (i = 0; i < PHGMG__NFIELDS; ++i) {
    const size_t len_i = phgmg__field_len(&tmp, i);
    if (!(mask & (1u << i))) { if (phgmg__fields[i].name) *phgmg__field_ptr(&tmp, i) = NULL; continue; }
    for (k = 0; k < len_i; ++k, o += ss)
      dst[k] = ss == 8 ? (phgmg_real)phgmg__get_f64(b + o) : (phgmg_real)phgmg__get_f32(b + o);
    if (!phgmg__r_finite(dst, (int)len_i)) return PHGMG_ERR_FORMAT;
    *phgmg__field_ptr(&tmp, i) = dst;
    dst += len_i;
  }
  work = dst;                           /* the structure check's scratch */
  dst += phgmg__rom_phys_work(&tmp, mask);
  if (nterm) { /* the term indices follow the scalars and the scratch in mem */
    int *ti = PHGMG__CAST(int *, PHGMG__CAST(void *, dst));
    for (k = 0; k < nterm; ++k, o += 4) {
      uint32_t v = phgmg__get32(b + o);
      if (v > (1u << 30)) return PHGMG_ERR_FORMAT;
      ti[k] = (int)v;
    }
    tmp.term = ti;
  }
  rc = phgmg_rom_check(&tmp);
  if (rc != PHGMG_OK) return PHGMG_ERR_FORMAT;
  /* fields required by the kind must be present, others absent */
  if ((tmp.kind == PHGMG_ROM_QUADRATIC) != (tmp.Ms != NULL) || (tmp.nd == 0 && (tmp.P0 || tmp.w)))
    return PHGMG_ERR_FORMAT;
  rc = phgmg__rom_physics(&tmp, 1.1920929e-07, work);   /* float's roundoff for every file (see there) */
  if (rc != PHGMG_OK) return rc;
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
  if (rom->ham_cb || rom->damp_cb) return PHGMG_ERR_UNSUPPORTED;
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
    if (!a || n == 0) continue; /* no zero-length arrays in C */
    ok &= fprintf(f, "static const phgmg_real %s_%s[%lu] = {", name, phgmg__fields[i].name, (unsigned long)n) > 0;
    for (k = 0; k < n; ++k)
#if PHGMG_REAL_IS_FLOAT
      ok &= fprintf(f, "%s%#.9gf", k == 0 ? "\n  " : (k % 6 ? ", " : ",\n  "), (double)a[k]) > 0;
#else
      ok &= fprintf(f, "%s%.17g", k == 0 ? "\n  " : (k % 4 ? ", " : ",\n  "), a[k]) > 0;
#endif
    ok &= fprintf(f, "};\n") > 0;
  }
  if (rom->term && rom->nd > 0) {
    ok &= fprintf(f, "static const int %s_term[%d] = {", name, rom->nd) > 0;
    for (i = 0; i < rom->nd; ++i) ok &= fprintf(f, "%s%d", i == 0 ? "\n  " : (i % 12 ? ", " : ",\n  "), rom->term[i]) > 0;
    ok &= fprintf(f, "};\n") > 0;
  }
  if (rom->phi_cb)
    ok &= fprintf(f, "/* supplied by the firmware: phi, phi', phi'' of full-model term `term` at s */\n"
                     "extern void %s_phi(int term, phgmg_real s, phgmg_real d[3], void *user);\n", name) > 0;
  if (rom->eta_cb)
    ok &= fprintf(f, "/* supplied by the firmware: the manifold q = eta(x2), Dq, D2q (see phgmg_rom) */\n"
                     "extern void %s_eta(const phgmg_real *x2, phgmg_real *q, phgmg_real *Dq, phgmg_real *D2q,\n"
                     "                   void *user);\n", name) > 0;
  ok &= fprintf(f, "static const phgmg_rom %s = {\n  %d, %d, %d, %d, %d, %d, %d,\n ", name, rom->kind,
                rom->method, rom->r, rom->m, rom->rn, rom->nd, rom->poly_deg) > 0;
  for (i = 0; i < 14; ++i) {
    if (phgmg__field_get(rom, i) && phgmg__field_len(rom, i) > 0) ok &= fprintf(f, " %s_%s,", name, phgmg__fields[i].name) > 0;
    else ok &= fprintf(f, " NULL,") > 0;
  }
#if PHGMG_REAL_IS_FLOAT
  ok &= fprintf(f, "\n  %#.9gf,\n ", (double)rom->dt) > 0;
#else
  ok &= fprintf(f, "\n  %.17g,\n ", rom->dt) > 0;
#endif
  for (i = 14; i < 18; ++i) {
    if (phgmg__field_get(rom, i) && phgmg__field_len(rom, i) > 0) ok &= fprintf(f, " %s_%s,", name, phgmg__fields[i].name) > 0;
    else ok &= fprintf(f, " NULL,") > 0;
  }
  /* nexp, nphi, expo, phi_cb, term, phi_user, eta_cb, eta_user, (ham_cb, ham_user: 0), envelope */
  ok &= fprintf(f, "\n  %d, %d,", rom->nexp, rom->nphi) > 0;
  if (rom->expo && phgmg__field_len(rom, 18) > 0) ok &= fprintf(f, " %s_expo,", name) > 0;
  else ok &= fprintf(f, " NULL,") > 0;
  if (rom->phi_cb) ok &= fprintf(f, " %s_phi,", name) > 0;
  else ok &= fprintf(f, " 0,") > 0;
  if (rom->term && rom->nd > 0) ok &= fprintf(f, " %s_term, NULL,", name) > 0;
  else ok &= fprintf(f, " NULL, NULL,") > 0;
  if (rom->eta_cb) ok &= fprintf(f, " %s_eta, NULL,", name) > 0;
  else ok &= fprintf(f, " 0, NULL,") > 0;
  ok &= fprintf(f, " 0, NULL") > 0;
  for (i = 19; i < PHGMG__NFIELDS; ++i) { /* env_lo, env_hi, q_max, ref_g, ref_s, xr_rest (member order) */
    if (i >= 22 && i <= 25) continue;   /* the dampers and PD follow their counts below */
    if (phgmg__field_get(rom, i) && phgmg__field_len(rom, i) > 0) ok &= fprintf(f, ", %s_%s", name, phgmg__fields[i].name) > 0;
    else ok &= fprintf(f, ", NULL") > 0;
  }
  /* dampers: ndamp, damp_deg, damp_nphi, Cd, dw, dpoly (damp_cb, dterm, damp_user: 0) */
  ok &= fprintf(f, ",\n  %d, %d, %d", rom->ndamp, rom->damp_deg, rom->damp_nphi) > 0;
  for (i = 22; i < 25; ++i) {
    if (phgmg__field_get(rom, i) && phgmg__field_len(rom, i) > 0) ok &= fprintf(f, ", %s_%s", name, phgmg__fields[i].name) > 0;
    else ok &= fprintf(f, ", NULL") > 0;
  }
  ok &= fprintf(f, ", 0, NULL, NULL") > 0;
  if (rom->PD) ok &= fprintf(f, ",\n  %s_PD", name) > 0;   /* feedthrough */
  else ok &= fprintf(f, ", NULL") > 0;
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
   es bytes each (1, 2, 4 or 8) of kind 'f' (float), 'i' (signed integer),
   'u' (unsigned integer) or 'b' (bool), big-endian or not, stored in C order
   or not. */
typedef struct phgmg__npy_hdr {
  int rows, cols, ndim;
  int es, big, corder, kind;
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

/* The dtype string d[0..l) (the value of 'descr'): '<' or '>' and f4, f8,
   i1, i2, i4, i8, u1, u2, u4, u8 or b1 ('|' also for the one-byte ones, as
   NumPy writes them). Any other dtype (complex 'c16', half 'f2', strings,
   objects, dates, native '=f8', ...) is PHGMG_ERR_DTYPE. */
PHGMG__PRIV phgmg_result phgmg__npy_descr(const char *d, size_t l, phgmg__npy_hdr *h) {
  char o, k;
  int es;
  if (l != 3 || d[2] < '1' || d[2] > '8') return PHGMG_ERR_DTYPE;
  o = d[0];
  k = d[1];
  es = d[2] - '0';
  if (o != '<' && o != '>' && !(o == '|' && es == 1)) return PHGMG_ERR_DTYPE;
  if (k == 'f') {
    if (es != 4 && es != 8) return PHGMG_ERR_DTYPE;
  } else if (k == 'i' || k == 'u') {
    if (es != 1 && es != 2 && es != 4 && es != 8) return PHGMG_ERR_DTYPE;
  } else if (k != 'b' || es != 1) {
    return PHGMG_ERR_DTYPE;
  }
  h->kind = k;
  h->es = es;
  h->big = o == '>';
  return PHGMG_OK;
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
      phgmg_result rc;
      if (seen_descr++) return PHGMG_ERR_FORMAT;
      if (i < n && s[i] == '[') return PHGMG_ERR_DTYPE; /* a structured dtype */
      if (!phgmg__npy_str(s, n, &i, &vb, &vl)) return PHGMG_ERR_FORMAT;
      rc = phgmg__npy_descr(s + vb, vl, h);
      if (rc != PHGMG_OK) return rc;
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

/* One integer element (es bytes at src, big-endian or not) as a double:
   exact; *inexact is set if |value| > 2^53 (8-byte integers only). */
PHGMG__PRIV double phgmg__npy_int_elem(const phgmg__npy_hdr *h, const unsigned char *src,
                                       int *inexact) {
  const int es = h->es;
  unsigned long long u = 0, sign = 1ull << (8 * es - 1), lim = 1ull << 53;
  int b;
  for (b = 0; b < es; ++b) u |= (unsigned long long)src[h->big ? es - 1 - b : b] << (8 * b);
  if (h->kind == 'b') return u != 0 ? 1.0 : 0.0;
  if (h->kind == 'i' && (u & sign)) { /* negative: magnitude 2^(8es) - u */
    const unsigned long long mag = es == 8 ? ~u + 1 : (sign << 1) - u;
    if (mag > lim) *inexact = 1;
    return -(double)mag;
  }
  if (u > lim) *inexact = 1;
  return (double)u;
}

/* Decode n elements of file (flat) indices k0 .. k0+n-1 from src into the
   column-major rows x cols matrix out. Returns PHGMG_ERR_INEXACT if an
   integer is beyond 2^53 in magnitude, else PHGMG_OK. */
PHGMG__PRIV phgmg_result phgmg__npy_decode(const phgmg__npy_hdr *h, const unsigned char *src,
                                           size_t k0, size_t n, double *out) {
  const int es = h->es, swap = h->big == phgmg__npy_host_little();
  size_t t, i = 0, j = 0, dst = k0;
  unsigned char tmp[8];
  int b, inexact = 0;
  if (n == 0) return PHGMG_OK;
  if (h->corder) { i = k0 / (size_t)h->cols; j = k0 % (size_t)h->cols; }
  for (t = 0; t < n; ++t, src += es) {
    double v;
    if (h->kind != 'f') {
      v = phgmg__npy_int_elem(h, src, &inexact);
    } else {
      for (b = 0; b < es; ++b) tmp[b] = src[swap ? es - 1 - b : b];
      if (es == 8) {
        memcpy(&v, tmp, 8);
      } else {
        float f;
        memcpy(&f, tmp, 4);
        v = (double)f;
      }
    }
    if (h->corder) {
      dst = i + j * (size_t)h->rows;
      if (++j == (size_t)h->cols) { j = 0; ++i; }
    }
    out[dst++] = v;
  }
  return inexact ? PHGMG_ERR_INEXACT : PHGMG_OK;
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
  rc = phgmg__npy_decode(&h, p + doff, 0, h.count, A);
  if (rc != PHGMG_OK) { phgmg__free(alloc, A); return rc; }
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

/* The data of a stream of unknown length (a pipe) after its header: read into
   a byte buffer that grows with what actually arrives (64 KiB, then doubling,
   never beyond the count * es bytes the header announces), then decoded into
   a new matrix *A. A stream shorter than announced is PHGMG_ERR_FORMAT once
   its end is reached, having allocated about twice what it held. */
PHGMG__PRIV phgmg_result phgmg__npy_read_stream(FILE *f, const phgmg__npy_hdr *h, double **A,
                                                const phgmg_allocator *alloc) {
  const size_t need = h->count * (size_t)h->es;
  size_t cap = 0, have = 0;
  unsigned char *raw = NULL;
  phgmg_result rc = PHGMG_OK;
  while (have < need && rc == PHGMG_OK) {
    size_t got;
    if (have == cap) {
      const size_t ncap = cap == 0 ? PHGMG__MIN(need, (size_t)65536)
                                   : (cap > need / 2 ? need : 2 * cap);
      unsigned char *nb = PHGMG__CAST(unsigned char *, phgmg__alloc(alloc, ncap));
      if (!nb) { rc = PHGMG_ERR_NOMEM; break; }
      if (have) memcpy(nb, raw, have);
      phgmg__free(alloc, raw);
      raw = nb;
      cap = ncap;
    }
    got = fread(raw + have, 1, cap - have, f);
    have += got;
    if (have < cap) rc = ferror(f) ? PHGMG_ERR_IO : PHGMG_ERR_FORMAT; /* end of the stream */
  }
  *A = NULL;
  if (rc == PHGMG_OK) {
    *A = phgmg__dalloc(alloc, h->count);
    if (!*A) rc = PHGMG_ERR_NOMEM;
    else rc = phgmg__npy_decode(h, raw, 0, h->count, *A);
    if (rc != PHGMG_OK) { phgmg__free(alloc, *A); *A = NULL; }
  }
  phgmg__free(alloc, raw);
  return rc;
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
  if (size < 0) { /* a pipe: the buffer grows with what arrives */
    rc = phgmg__npy_read_stream(f, &h, &A, alloc);
    fclose(f);
    if (rc != PHGMG_OK) return rc;
  } else {
    A = phgmg__dalloc(alloc, h.count);
    if (!A) { fclose(f); return PHGMG_ERR_NOMEM; }
    left = h.count;
    while (left > 0 && rc == PHGMG_OK) {
      size_t n = PHGMG__MIN(left, sizeof chunk / (size_t)h.es);
      rc = phgmg__npy_fread(f, chunk, n * (size_t)h.es);
      if (rc == PHGMG_OK) rc = phgmg__npy_decode(&h, chunk, k, n, A);
      k += n;
      left -= n;
    }
    fclose(f);
    if (rc != PHGMG_OK) { phgmg__free(alloc, A); return rc; }
  }
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
  int ok, created;
  FILE *f;
  if (!path) return PHGMG_ERR_INVALID_ARG;
  rc = phgmg__npy_wcheck(A, rows, cols, ld, ndim, flags, &count);
  if (rc != PHGMG_OK) return rc;
  hl = phgmg__npy_header(head, rows, cols, ndim, flags);
  /* "x": create a new file only (fails if the name exists, also as a
     symbolic link); only a file made here is removed after an error */
  f = fopen(path, "wbx");
  created = f != NULL;
  if (!f) f = fopen(path, "wb");
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
    if (created) remove(path);
    return PHGMG_ERR_IO;
  }
  return PHGMG_OK;
}
#endif /* PHGMG_NO_STDIO */
#endif /* PHGMG_NO_OFFLINE */

/* >>linalg (implementation) ============================================== */
#ifndef PHGMG_NO_OFFLINE

/* ---- level-1 helpers -------------------------------------------------------- */

/* x . y with several independent partial sums (a dot product is otherwise
   bound by the latency of one add chain). */
PHGMG__PRIV double phgmg__dot(int n, const double *x, const double *y) {
  int i = 0;
  double s = 0.0;
#ifdef PHGMG__VEC4
  if (n >= 16) {
    phgmg__v4 s0, s1, s2, s3, a, b;
    double t[4];
    memset(&s0, 0, sizeof s0);
    s1 = s2 = s3 = s0;
    for (; i + 16 <= n; i += 16) {
      memcpy(&a, x + i, sizeof a); memcpy(&b, y + i, sizeof b); s0 += a * b;
      memcpy(&a, x + i + 4, sizeof a); memcpy(&b, y + i + 4, sizeof b); s1 += a * b;
      memcpy(&a, x + i + 8, sizeof a); memcpy(&b, y + i + 8, sizeof b); s2 += a * b;
      memcpy(&a, x + i + 12, sizeof a); memcpy(&b, y + i + 12, sizeof b); s3 += a * b;
    }
    s0 = (s0 + s1) + (s2 + s3);
    memcpy(t, &s0, sizeof t);
    s = (t[0] + t[1]) + (t[2] + t[3]);
  }
#else
  {
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
    for (; i + 4 <= n; i += 4) {
      s0 += x[i] * y[i]; s1 += x[i + 1] * y[i + 1];
      s2 += x[i + 2] * y[i + 2]; s3 += x[i + 3] * y[i + 3];
    }
    s = (s0 + s1) + (s2 + s3);
  }
#endif
  for (; i < n; ++i) s += x[i] * y[i];
  return s;
}

/* y += a x */
PHGMG__PRIV void phgmg__axpy(int n, double a, const double *x, double *y) {
  int i = 0;
#ifdef PHGMG__VEC4
  for (; i + 8 <= n; i += 8) {
    phgmg__v4 x0, x1, y0, y1;
    memcpy(&x0, x + i, sizeof x0); memcpy(&x1, x + i + 4, sizeof x1);
    memcpy(&y0, y + i, sizeof y0); memcpy(&y1, y + i + 4, sizeof y1);
    y0 += a * x0; y1 += a * x1;
    memcpy(y + i, &y0, sizeof y0); memcpy(y + i + 4, &y1, sizeof y1);
  }
#endif
  for (; i < n; ++i) y[i] += a * x[i];
}

/* plane rotation of two vectors: (x, y) <- (c x - s y, s x + c y) */
PHGMG__PRIV void phgmg__rot(int n, double *x, double *y, double c, double s) {
  int i = 0;
#ifdef PHGMG__VEC4
  for (; i + 4 <= n; i += 4) {
    phgmg__v4 a, b, u, v;
    memcpy(&a, x + i, sizeof a); memcpy(&b, y + i, sizeof b);
    u = c * a - s * b;
    v = s * a + c * b;
    memcpy(x + i, &u, sizeof u); memcpy(y + i, &v, sizeof v);
  }
#endif
  for (; i < n; ++i) {
    double a = x[i], b = y[i];
    x[i] = c * a - s * b;
    y[i] = s * a + c * b;
  }
}

/* every entry of the m x n matrix finite */
PHGMG__PRIV int phgmg__mat_finite(int m, int n, const double *A, int lda) {
  int j;
  for (j = 0; j < n; ++j)
    if (!phgmg__all_finite(A + (size_t)j * (size_t)lda, (size_t)m)) return 0;
  return 1;
}

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
  /* fast path: plain sum of squares when it neither overflows nor underflows */
  double scale = 0.0, ssq = 0.0;
  int i, j;
  for (j = 0; j < n; ++j) {
    const double *a = A + (size_t)j * (size_t)lda;
    ssq += phgmg__dot(m, a, a);
  }
  if (ssq == 0.0) { /* all zero, or every square underflowed: check */
    for (j = 0; j < n; ++j)
      for (i = 0; i < m; ++i)
        if (A[i + (size_t)j * (size_t)lda] != 0.0) goto scaled;
    return 0.0;
  }
  if (ssq > 1e-280 && ssq < 1e280) return sqrt(ssq);
  if (ssq != ssq) return ssq; /* NaN in A */
scaled:
  /* scaled sum of squares (LAPACK dlassq): scale^2 * ssq */
  ssq = 1.0;
  for (j = 0; j < n; ++j) {
    const double *a = A + (size_t)j * (size_t)lda;
    for (i = 0; i < m; ++i) {
      double v = fabs(a[i]);
      if (v != 0.0 || v != v) {
        if (v != v) return v;
        if (v == HUGE_VAL) return v;
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

/* sum of squares of an n x ns matrix (ld lda): ||A||_F^2 by phgmg_normf. */
PHGMG__PRIV double phgmg__sumsq(int n, int ns, const double *A, int lda) {
  const double f = phgmg_normf(n, ns, A, lda);
  return f * f;
}

/* ---- gemv / gemm ---------------------------------------------------------- */
PHGMG_DEF void phgmg_gemv(char trans, int m, int n, double alpha, const double *A, int lda,
                          const double *x, double beta, double *y) {
  int i;
  int tr = (trans == 'T' || trans == 't');
  int ny = tr ? n : m;
  PHGMG_ASSERT(tr || trans == 'N' || trans == 'n');
  if (m <= 0 || n <= 0) {
    for (i = 0; i < ny; ++i) y[i] = (beta == 0.0) ? 0.0 : beta * y[i];
    return;
  }
#ifdef PHGMG_USE_CBLAS
  cblas_dgemv(CblasColMajor, tr ? CblasTrans : CblasNoTrans, m, n, alpha, A, lda, x, 1, beta, y, 1);
#else
  int j;
  if (beta == 0.0) {
    for (i = 0; i < ny; ++i) y[i] = 0.0;
  } else if (beta != 1.0) {
    for (i = 0; i < ny; ++i) y[i] *= beta;
  }
  if (alpha == 0.0) return;
  if (!tr) {
    /* y += alpha * A x, four columns per sweep over y */
    for (j = 0; j + 4 <= n; j += 4) {
      const double *a0 = A + (size_t)j * (size_t)lda, *a1 = a0 + lda, *a2 = a1 + lda, *a3 = a2 + lda;
      double t0 = alpha * x[j], t1 = alpha * x[j + 1], t2 = alpha * x[j + 2], t3 = alpha * x[j + 3];
      for (i = 0; i < m; ++i) y[i] += t0 * a0[i] + t1 * a1[i] + t2 * a2[i] + t3 * a3[i];
    }
    for (; j < n; ++j) {
      const double *a = A + (size_t)j * (size_t)lda;
      double t = alpha * x[j];
      phgmg__axpy(m, t, a, y);
    }
  } else {
    /* y += alpha * A^T x, dot products of columns */
    for (j = 0; j < n; ++j) y[j] += alpha * phgmg__dot(m, A + (size_t)j * (size_t)lda, x);
  }
#endif
}

/* Portable GEMM core: a block of op(A) (MC x KC) is packed into 8-row slivers
   (on the stack, MC*KC doubles), then 8 x 6 tiles of C are computed by a
   register-blocked micro-kernel that streams the matching 6 columns of op(B)
   directly from B (any strides). With GCC/Clang on an AVX target the
   micro-kernel uses vector extensions (define PHGMG_NO_VECTOR_EXT for the plain
   C version, which is the one used everywhere else). It also serves the
   complex products (interleaved storage seen as a real matrix). */
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
#ifdef PHGMG__VEC4
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

/* C (m x n) += alpha * opA(A) * opB(B), opB(B)(p, j) = B[p*bsp + j*bsj];
   amode 0: opA(A)(i, p) = A[i + p*lda]; 1: A[p + i*lda] (transposed);
   2 (m even, A the real view of an interleaved complex matrix): rows 2r, 2r+1
   of opA are (-Im, Re) of complex row r, i.e. the real view of i*A. */
/* One row block ic:ic+mc of the product over k block pc:pc+kc (see below):
   packs its own copy of opA (stack), so row blocks are independent. */
PHGMG__PRIV void phgmg__gemm_rowblock(int ic, int mc, int pc, int kc, int n, double alpha, int amode,
                                      const double *A, int lda, const double *B, size_t bsp,
                                      size_t bsj, double *C, int ldc) {
  double Ap[PHGMG_GEMM_MC * PHGMG_GEMM_KC];
  int ir, jr, p, i;
  /* pack opA(ic:ic+mc, pc:pc+kc) into 8-row slivers, zero padded */
  for (ir = 0; ir < mc; ir += PHGMG__MR) {
    int mr = PHGMG__MIN(PHGMG__MR, mc - ir);
    double *dst = Ap + (size_t)ir * (size_t)kc;
    if (amode == 0) {
      for (p = 0; p < kc; ++p) {
        const double *src = A + (ic + ir) + (size_t)(pc + p) * (size_t)lda;
        double *d = dst + (size_t)p * PHGMG__MR;
        for (i = 0; i < mr; ++i) d[i] = src[i];
        for (; i < PHGMG__MR; ++i) d[i] = 0.0;
      }
    } else if (amode == 1) {
      for (i = 0; i < PHGMG__MR; ++i) {
        if (i < mr) {
          const double *src = A + pc + (size_t)(ic + ir + i) * (size_t)lda;
          for (p = 0; p < kc; ++p) dst[(size_t)p * PHGMG__MR + i] = src[p];
        } else {
          for (p = 0; p < kc; ++p) dst[(size_t)p * PHGMG__MR + i] = 0.0;
        }
      }
    } else {
      for (p = 0; p < kc; ++p) {
        const double *src = A + (ic + ir) + (size_t)(pc + p) * (size_t)lda;
        double *d = dst + (size_t)p * PHGMG__MR;
        for (i = 0; i + 1 < mr; i += 2) { d[i] = -src[i + 1]; d[i + 1] = src[i]; }
        for (; i < PHGMG__MR; ++i) d[i] = 0.0;
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

/* C (m x n) += alpha * opA(A) * opB(B), opB(B)(p, j) = B[p*bsp + j*bsj];
   amode 0: opA(A)(i, p) = A[i + p*lda]; 1: A[p + i*lda] (transposed);
   2 (m even, A the real view of an interleaved complex matrix): rows 2r, 2r+1
   of opA are (-Im, Re) of complex row r, i.e. the real view of i*A.
   With PHGMG_USE_OPENMP (and -fopenmp) the row blocks of one k block run in
   parallel when the block holds more than ~4 Mflop; every entry of C is still
   summed by one thread in the same order, so the result does not depend on the
   number of threads. */
PHGMG__PRIV void phgmg__gemm_acc(int m, int n, int k, double alpha, int amode, const double *A,
                                 int lda, const double *B, size_t bsp, size_t bsj, double *C,
                                 int ldc) {
  int pc, ic;
  if (m <= 0 || n <= 0 || k <= 0 || alpha == 0.0) return;
  for (pc = 0; pc < k; pc += PHGMG_GEMM_KC) {
    int kc = PHGMG__MIN(PHGMG_GEMM_KC, k - pc);
#ifdef PHGMG_USE_OPENMP
#pragma omp parallel for schedule(static) if ((double)m * (double)n * (double)kc > 2e6)
#endif
    for (ic = 0; ic < m; ic += PHGMG_GEMM_MC)
      phgmg__gemm_rowblock(ic, PHGMG__MIN(PHGMG_GEMM_MC, m - ic), pc, kc, n, alpha, amode, A, lda,
                           B, bsp, bsj, C, ldc);
  }
}

/* Complex C (m x n) += alpha * A (m x k) * B (k x n), alpha real, interleaved
   storage with leading dimensions in complex elements: Re(C) and Im(C) come
   from two real products on the interleaved views, [Re A; Im A] Re B +
   [-Im A; Re A] Im B, so no flop is wasted. */
PHGMG__PRIV void phgmg__zgemm_acc(int m, int n, int k, double alpha, const double *A, int lda,
                                  const double *B, int ldb, double *C, int ldc) {
  size_t bsj = 2 * (size_t)ldb;
  phgmg__gemm_acc(2 * m, n, k, alpha, 0, A, 2 * lda, B, 2, bsj, C, 2 * ldc);
  phgmg__gemm_acc(2 * m, n, k, alpha, 2, A, 2 * lda, B + 1, 2, bsj, C, 2 * ldc);
}

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
  phgmg__gemm_acc(m, n, k, alpha, ta, A, lda, B, tb ? (size_t)ldb : 1, tb ? 1 : (size_t)ldb, C, ldc);
}

/* ---- real LU -------------------------------------------------------------- */
/* Row interchanges k <-> ipiv[k], k in [k1, k2), applied to ncols columns of A. */
PHGMG__PRIV void phgmg__laswp(int ncols, double *A, int lda, int k1, int k2, const int *ipiv) {
  int j, k;
  for (j = 0; j < ncols; ++j) {
    double *c = A + (size_t)j * (size_t)lda;
    for (k = k1; k < k2; ++k) {
      int p = ipiv[k];
      if (p != k) { double t = c[k]; c[k] = c[p]; c[p] = t; }
    }
  }
}

/* Triangular solves with n x n factors on B (n x nrhs), in place. Recursive
   halving, the off-diagonal blocks go through gemm; small problems (n <= 32
   or fewer than 4 right-hand sides) by column substitution.
   llu: L^{-1} B, L unit lower.     lun: U^{-1} B, U upper.
   utn: U^{-T} B.                   ltu: L^{-T} B, L unit lower. */
#define PHGMG__TRSM_LEAF 32
PHGMG__PRIV void phgmg__trsm_llu(int n, int nrhs, const double *L, int ldl, double *B, int ldb) {
  int j, k, n1;
  if (n <= PHGMG__TRSM_LEAF || nrhs < 4) {
    for (j = 0; j < nrhs; ++j) {
      double *b = B + (size_t)j * (size_t)ldb;
      for (k = 0; k < n; ++k) {
        const double *l = L + (size_t)k * (size_t)ldl;
        double t = b[k];
        if (t != 0.0) phgmg__axpy(n - k - 1, -t, l + k + 1, b + k + 1);
      }
    }
    return;
  }
  n1 = n / 2;
  phgmg__trsm_llu(n1, nrhs, L, ldl, B, ldb);
  phgmg_gemm('N', 'N', n - n1, nrhs, n1, -1.0, L + n1, ldl, B, ldb, 1.0, B + n1, ldb);
  phgmg__trsm_llu(n - n1, nrhs, L + n1 + (size_t)n1 * (size_t)ldl, ldl, B + n1, ldb);
}
PHGMG__PRIV void phgmg__trsm_lun(int n, int nrhs, const double *U, int ldu, double *B, int ldb) {
  int j, k, n1;
  if (n <= PHGMG__TRSM_LEAF || nrhs < 4) {
    for (j = 0; j < nrhs; ++j) {
      double *b = B + (size_t)j * (size_t)ldb;
      for (k = n - 1; k >= 0; --k) {
        const double *u = U + (size_t)k * (size_t)ldu;
        double t = b[k] / u[k];
        b[k] = t;
        if (t != 0.0) phgmg__axpy(k, -t, u, b);
      }
    }
    return;
  }
  n1 = n / 2;
  phgmg__trsm_lun(n - n1, nrhs, U + n1 + (size_t)n1 * (size_t)ldu, ldu, B + n1, ldb);
  phgmg_gemm('N', 'N', n1, nrhs, n - n1, -1.0, U + (size_t)n1 * (size_t)ldu, ldu, B + n1, ldb,
             1.0, B, ldb);
  phgmg__trsm_lun(n1, nrhs, U, ldu, B, ldb);
}
PHGMG__PRIV void phgmg__trsm_utn(int n, int nrhs, const double *U, int ldu, double *B, int ldb) {
  int j, k, n1;
  if (n <= PHGMG__TRSM_LEAF || nrhs < 4) {
    for (j = 0; j < nrhs; ++j) {
      double *b = B + (size_t)j * (size_t)ldb;
      for (k = 0; k < n; ++k) {
        const double *u = U + (size_t)k * (size_t)ldu;
        b[k] = (b[k] - phgmg__dot(k, u, b)) / u[k];
      }
    }
    return;
  }
  n1 = n / 2;
  phgmg__trsm_utn(n1, nrhs, U, ldu, B, ldb);
  phgmg_gemm('T', 'N', n - n1, nrhs, n1, -1.0, U + (size_t)n1 * (size_t)ldu, ldu, B, ldb, 1.0,
             B + n1, ldb);
  phgmg__trsm_utn(n - n1, nrhs, U + n1 + (size_t)n1 * (size_t)ldu, ldu, B + n1, ldb);
}
PHGMG__PRIV void phgmg__trsm_ltu(int n, int nrhs, const double *L, int ldl, double *B, int ldb) {
  int j, k, n1;
  if (n <= PHGMG__TRSM_LEAF || nrhs < 4) {
    for (j = 0; j < nrhs; ++j) {
      double *b = B + (size_t)j * (size_t)ldb;
      for (k = n - 1; k >= 0; --k) {
        const double *l = L + (size_t)k * (size_t)ldl;
        b[k] -= phgmg__dot(n - k - 1, l + k + 1, b + k + 1);
      }
    }
    return;
  }
  n1 = n / 2;
  phgmg__trsm_ltu(n - n1, nrhs, L + n1 + (size_t)n1 * (size_t)ldl, ldl, B + n1, ldb);
  phgmg_gemm('T', 'N', n1, nrhs, n - n1, -1.0, L + n1, ldl, B + n1, ldb, 1.0, B, ldb);
  phgmg__trsm_ltu(n1, nrhs, L, ldl, B, ldb);
}

/* Recursive LU with partial pivoting of an m x n panel (m >= n), ipiv relative
   to the panel. Returns 1 if an exactly zero pivot column was met. */
PHGMG__PRIV int phgmg__lu_rec(int m, int n, double *A, int lda, int *ipiv) {
  int i, j, k, n1, sing = 0;
  if (n <= 16) {
    for (k = 0; k < n; ++k) {
      double *ak = A + (size_t)k * (size_t)lda, amax = fabs(ak[k]), piv;
      int p = k;
      for (i = k + 1; i < m; ++i)
        if (fabs(ak[i]) > amax) { amax = fabs(ak[i]); p = i; }
      ipiv[k] = p;
      if (amax == 0.0) { sing = 1; continue; } /* the column below is zero: L(:,k) = 0 */
      if (p != k)
        for (j = 0; j < n; ++j) {
          double *c = A + (size_t)j * (size_t)lda, t = c[k];
          c[k] = c[p]; c[p] = t;
        }
      piv = ak[k];
      if (amax >= 2.2250738585072014e-308) {
        double r = 1.0 / piv;
        for (i = k + 1; i < m; ++i) ak[i] *= r;
      } else {
        for (i = k + 1; i < m; ++i) ak[i] /= piv;
      }
      for (j = k + 1; j < n; ++j) {
        double *c = A + (size_t)j * (size_t)lda, t = c[k];
        if (t != 0.0) phgmg__axpy(m - k - 1, -t, ak + k + 1, c + k + 1);
      }
    }
    return sing;
  }
  n1 = n / 2;
  sing = phgmg__lu_rec(m, n1, A, lda, ipiv);
  phgmg__laswp(n - n1, A + (size_t)n1 * (size_t)lda, lda, 0, n1, ipiv);
  phgmg__trsm_llu(n1, n - n1, A, lda, A + (size_t)n1 * (size_t)lda, lda);
  phgmg_gemm('N', 'N', m - n1, n - n1, n1, -1.0, A + n1, lda, A + (size_t)n1 * (size_t)lda, lda,
             1.0, A + n1 + (size_t)n1 * (size_t)lda, lda);
  sing |= phgmg__lu_rec(m - n1, n - n1, A + n1 + (size_t)n1 * (size_t)lda, lda, ipiv + n1);
  for (i = n1; i < n; ++i) ipiv[i] += n1;
  phgmg__laswp(n1, A, lda, n1, n, ipiv);
  return sing;
}

PHGMG_DEF phgmg_result phgmg_lu_factor(int n, double *A, int lda, int *ipiv) {
  int j;
  if (n < 0 || lda < PHGMG__MAX(n, 1)) return PHGMG_ERR_SIZE;
  if (n == 0) return PHGMG_OK;
  if (!A || !ipiv) return PHGMG_ERR_INVALID_ARG;
  for (j = 0; j < n; ++j)
    if (!phgmg__all_finite(A + (size_t)j * (size_t)lda, (size_t)n)) return PHGMG_ERR_NANINF;
  if (phgmg__lu_rec(n, n, A, lda, ipiv)) return PHGMG_ERR_SINGULAR;
  /* finite input can still overflow (pivot growth) */
  return phgmg__mat_finite(n, n, A, lda) ? PHGMG_OK : PHGMG_ERR_NANINF;
}

PHGMG_DEF void phgmg_lu_solve(char trans, int n, const double *LU, int lda, const int *ipiv,
                              int nrhs, double *B, int ldb) {
  int j, k;
  int tr = (trans == 'T' || trans == 't');
  PHGMG_ASSERT(tr || trans == 'N' || trans == 'n');
  if (n <= 0 || nrhs <= 0) return;
  if (!tr) {
    phgmg__laswp(nrhs, B, ldb, 0, n, ipiv);
    phgmg__trsm_llu(n, nrhs, LU, lda, B, ldb);
    phgmg__trsm_lun(n, nrhs, LU, lda, B, ldb);
  } else {
    phgmg__trsm_utn(n, nrhs, LU, lda, B, ldb);
    phgmg__trsm_ltu(n, nrhs, LU, lda, B, ldb);
    for (j = 0; j < nrhs; ++j) {
      double *b = B + (size_t)j * (size_t)ldb;
      for (k = n - 1; k >= 0; --k)
        if (ipiv[k] != k) { double t = b[k]; b[k] = b[ipiv[k]]; b[ipiv[k]] = t; }
    }
  }
}

/* ---- complex LU (interleaved re,im) ----------------------------------------- */
/* (cr, ci) = (ar + i ai) / (br + i bi), Smith's algorithm */
PHGMG__PRIV void phgmg__zdiv(double ar, double ai, double br, double bi, double *cr, double *ci) {
  if (fabs(br) >= fabs(bi)) {
    double q = bi / br, d = br + bi * q;
    *cr = (ar + ai * q) / d;
    *ci = (ai - ar * q) / d;
  } else {
    double q = br / bi, d = br * q + bi;
    *cr = (ar * q + ai) / d;
    *ci = (ai * q - ar) / d;
  }
}

/* y -= (tr + i ti) x over n complex entries */
PHGMG__PRIV void phgmg__zaxpy_neg(int n, double tr, double ti, const double *x, double *y) {
  int i;
  for (i = 0; i < n; ++i) {
    double xr = x[2 * i], xi = x[2 * i + 1];
    y[2 * i] -= tr * xr - ti * xi;
    y[2 * i + 1] -= tr * xi + ti * xr;
  }
}

PHGMG__PRIV void phgmg__zlaswp(int ncols, double *A, int lda, int k1, int k2, const int *ipiv) {
  int j, k;
  for (j = 0; j < ncols; ++j) {
    double *c = A + 2 * (size_t)j * (size_t)lda, t;
    for (k = k1; k < k2; ++k) {
      int p = ipiv[k];
      if (p != k) {
        t = c[2 * k]; c[2 * k] = c[2 * p]; c[2 * p] = t;
        t = c[2 * k + 1]; c[2 * k + 1] = c[2 * p + 1]; c[2 * p + 1] = t;
      }
    }
  }
}

/* complex L^{-1} B (unit lower) and U^{-1} B, as the real ones */
PHGMG__PRIV void phgmg__ztrsm_llu(int n, int nrhs, const double *L, int ldl, double *B, int ldb) {
  int j, k, n1;
  if (n <= PHGMG__TRSM_LEAF || nrhs < 2) {
    for (j = 0; j < nrhs; ++j) {
      double *b = B + 2 * (size_t)j * (size_t)ldb;
      for (k = 0; k < n; ++k) {
        const double *l = L + 2 * (size_t)k * (size_t)ldl;
        double tr = b[2 * k], ti = b[2 * k + 1];
        if (tr != 0.0 || ti != 0.0) phgmg__zaxpy_neg(n - k - 1, tr, ti, l + 2 * (k + 1), b + 2 * (k + 1));
      }
    }
    return;
  }
  n1 = n / 2;
  phgmg__ztrsm_llu(n1, nrhs, L, ldl, B, ldb);
  phgmg__zgemm_acc(n - n1, nrhs, n1, -1.0, L + 2 * n1, ldl, B, ldb, B + 2 * n1, ldb);
  phgmg__ztrsm_llu(n - n1, nrhs, L + 2 * (n1 + (size_t)n1 * (size_t)ldl), ldl, B + 2 * n1, ldb);
}
PHGMG__PRIV void phgmg__ztrsm_lun(int n, int nrhs, const double *U, int ldu, double *B, int ldb) {
  int j, k, n1;
  if (n <= PHGMG__TRSM_LEAF || nrhs < 2) {
    for (j = 0; j < nrhs; ++j) {
      double *b = B + 2 * (size_t)j * (size_t)ldb;
      for (k = n - 1; k >= 0; --k) {
        const double *u = U + 2 * (size_t)k * (size_t)ldu;
        double tr, ti;
        phgmg__zdiv(b[2 * k], b[2 * k + 1], u[2 * k], u[2 * k + 1], &tr, &ti);
        b[2 * k] = tr;
        b[2 * k + 1] = ti;
        if (tr != 0.0 || ti != 0.0) phgmg__zaxpy_neg(k, tr, ti, u, b);
      }
    }
    return;
  }
  n1 = n / 2;
  phgmg__ztrsm_lun(n - n1, nrhs, U + 2 * (n1 + (size_t)n1 * (size_t)ldu), ldu, B + 2 * n1, ldb);
  phgmg__zgemm_acc(n1, nrhs, n - n1, -1.0, U + 2 * (size_t)n1 * (size_t)ldu, ldu, B + 2 * n1, ldb,
                   B, ldb);
  phgmg__ztrsm_lun(n1, nrhs, U, ldu, B, ldb);
}

/* Recursive complex LU of an m x n panel, as phgmg__lu_rec. */
PHGMG__PRIV int phgmg__zlu_rec(int m, int n, double *A, int lda, int *ipiv) {
  int i, k, n1, sing = 0;
  if (n <= 8) {
    for (k = 0; k < n; ++k) {
      double *ak = A + 2 * (size_t)k * (size_t)lda, rr, ri;
      double amax = fabs(ak[2 * k]) + fabs(ak[2 * k + 1]);
      int p = k, j;
      for (i = k + 1; i < m; ++i) {
        double v = fabs(ak[2 * i]) + fabs(ak[2 * i + 1]);
        if (v > amax) { amax = v; p = i; }
      }
      ipiv[k] = p;
      if (amax == 0.0) { sing = 1; continue; }
      if (p != k) phgmg__zlaswp(n, A, lda, k, k + 1, ipiv);
      phgmg__zdiv(1.0, 0.0, ak[2 * k], ak[2 * k + 1], &rr, &ri);
      for (i = k + 1; i < m; ++i) {
        double xr = ak[2 * i], xi = ak[2 * i + 1];
        ak[2 * i] = xr * rr - xi * ri;
        ak[2 * i + 1] = xr * ri + xi * rr;
      }
      for (j = k + 1; j < n; ++j) {
        double *c = A + 2 * (size_t)j * (size_t)lda, tr = c[2 * k], ti = c[2 * k + 1];
        if (tr != 0.0 || ti != 0.0) phgmg__zaxpy_neg(m - k - 1, tr, ti, ak + 2 * (k + 1), c + 2 * (k + 1));
      }
    }
    return sing;
  }
  n1 = n / 2;
  sing = phgmg__zlu_rec(m, n1, A, lda, ipiv);
  phgmg__zlaswp(n - n1, A + 2 * (size_t)n1 * (size_t)lda, lda, 0, n1, ipiv);
  phgmg__ztrsm_llu(n1, n - n1, A, lda, A + 2 * (size_t)n1 * (size_t)lda, lda);
  phgmg__zgemm_acc(m - n1, n - n1, n1, -1.0, A + 2 * n1, lda, A + 2 * (size_t)n1 * (size_t)lda, lda,
                   A + 2 * (n1 + (size_t)n1 * (size_t)lda), lda);
  sing |= phgmg__zlu_rec(m - n1, n - n1, A + 2 * (n1 + (size_t)n1 * (size_t)lda), lda, ipiv + n1);
  for (i = n1; i < n; ++i) ipiv[i] += n1;
  phgmg__zlaswp(n1, A, lda, n1, n, ipiv);
  return sing;
}

PHGMG_DEF phgmg_result phgmg_zlu_factor(int n, double *A, int lda, int *ipiv) {
  int j;
  if (n < 0 || lda < PHGMG__MAX(n, 1)) return PHGMG_ERR_SIZE;
  if (n == 0) return PHGMG_OK;
  if (!A || !ipiv) return PHGMG_ERR_INVALID_ARG;
  for (j = 0; j < n; ++j)
    if (!phgmg__all_finite(A + 2 * (size_t)j * (size_t)lda, 2 * (size_t)n)) return PHGMG_ERR_NANINF;
  if (phgmg__zlu_rec(n, n, A, lda, ipiv)) return PHGMG_ERR_SINGULAR;
  return phgmg__mat_finite(2 * n, n, A, 2 * lda) ? PHGMG_OK : PHGMG_ERR_NANINF;
}

PHGMG_DEF void phgmg_zlu_solve(int n, const double *LU, int lda, const int *ipiv,
                               int nrhs, double *B, int ldb) {
  if (n <= 0 || nrhs <= 0) return;
  phgmg__zlaswp(nrhs, B, ldb, 0, n, ipiv);
  phgmg__ztrsm_llu(n, nrhs, LU, lda, B, ldb);
  phgmg__ztrsm_lun(n, nrhs, LU, lda, B, ldb);
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
#define PHGMG__LARFG_SAFMIN (PHGMG__DBL_MIN / PHGMG__EPS)
PHGMG__PRIV void phgmg__larfg(int n, double *alpha, double *x, double *tau) {
  double xnorm, beta, r;
  int i, knt = 0;
  if (n <= 1) { *tau = 0.0; return; }
  xnorm = phgmg_normf(n - 1, 1, x, n - 1);
  if (xnorm == 0.0) { *tau = 0.0; return; }
  beta = -copysign(hypot(*alpha, xnorm), *alpha);
  /* A tiny (e.g. subnormal) column: 1 / (alpha - beta) would overflow and
     turn x into Inf/NaN. Scale the column up by powers of two (exact) until
     beta is safe, as LAPACK's dlarfg does, and scale beta back at the end;
     beta is recomputed from the scaled column so that tau = 2 / v^T v. */
  while (fabs(beta) < PHGMG__LARFG_SAFMIN && knt < 8) {
    ++knt;
    for (i = 0; i < n - 1; ++i) x[i] = ldexp(x[i], 256);
    *alpha = ldexp(*alpha, 256);
    beta = ldexp(beta, 256);
  }
  if (knt) { /* beta again from the scaled (now normal) column, as LAPACK does */
    xnorm = phgmg_normf(n - 1, 1, x, n - 1);
    beta = -copysign(hypot(*alpha, xnorm), *alpha);
  }
  *tau = (beta - *alpha) / beta;
  r = 1.0 / (*alpha - beta);
  for (i = 0; i < n - 1; ++i) x[i] *= r;
  *alpha = ldexp(beta, -256 * knt);
}

/* C (m x n) := (I - tau v v^T) C, v = (1, v[1..m-1]) (v[0] is not read). */
PHGMG__PRIV void phgmg__larf_left(int m, int n, const double *v, double tau, double *C, int ldc) {
  int j;
  if (tau == 0.0) return;
  for (j = 0; j < n; ++j) {
    double *c = C + (size_t)j * (size_t)ldc;
    double s = tau * (c[0] + phgmg__dot(m - 1, v + 1, c + 1));
    if (s == 0.0) continue;
    c[0] -= s;
    phgmg__axpy(m - 1, -s, v + 1, c + 1);
  }
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

/* Blocked QR with column pivoting (LAPACK dlaqps scheme): nb reflectors at a
   time with deferred trailing updates A -= V F^T through gemm. Stops early like
   phgmg__qrcp_core. F: n x nb (ld n), aux: nb doubles, mark: n ints. */
#define PHGMG__QRCP_NB 32
PHGMG__PRIV void phgmg__qrcp_blocked(int m, int n, double *A, int lda, double *tau, int *jpvt,
                                     double *vn, double *F, double *aux, int *mark, double tol,
                                     int *rank) {
  double *vn1 = vn, *vn2 = vn + n;
  const double tol3z = sqrt(PHGMG__EPS);
  const int ldf = PHGMG__MAX(n, 1);
  int i, j, q, s = 0, kmin = PHGMG__MIN(m, n), stop = 0;
  for (j = 0; j < n; ++j) {
    jpvt[j] = j;
    mark[j] = 0;
    vn1[j] = vn2[j] = phgmg_normf(m, 1, A + (size_t)j * (size_t)lda, lda);
  }
  while (s < kmin && !stop) {
    int nb = PHGMG__MIN(PHGMG__QRCP_NB, kmin - s), kk = 0, any_mark = 0;
    /* F rows are indexed by (global column - s) */
    while (kk < nb && !any_mark) {
      int c = s + kk, p = c + phgmg__iamax(n - c, vn1 + c);
      double *ac = A + (size_t)c * (size_t)lda, akk;
      if (tol >= 0.0 && vn1[p] <= tol) { stop = 1; break; }
      if (p != c) {
        double *ap = A + (size_t)p * (size_t)lda, t;
        int it;
        for (i = 0; i < m; ++i) { t = ac[i]; ac[i] = ap[i]; ap[i] = t; }
        for (q = 0; q < kk; ++q) {
          double *fq = F + (size_t)q * (size_t)ldf;
          t = fq[c - s]; fq[c - s] = fq[p - s]; fq[p - s] = t;
        }
        it = jpvt[p]; jpvt[p] = jpvt[c]; jpvt[c] = it;
        vn1[p] = vn1[c];
        vn2[p] = vn2[c];
      }
      /* pending updates of column c: A(c:m, c) -= A(c:m, s:c) F(c-s, 0:kk)^T */
      for (q = 0; q < kk; ++q) {
        const double *v = A + (size_t)(s + q) * (size_t)lda;
        double f = F[(c - s) + (size_t)q * (size_t)ldf];
        if (f != 0.0) phgmg__axpy(m - c, -f, v + c, ac + c);
      }
      phgmg__larfg(m - c, ac + c, ac + c + 1, &tau[c]);
      akk = ac[c];
      ac[c] = 1.0;
      /* F(c+1-s : n-s, kk) = tau A(c:m, c+1:n)^T v  (stale trailing columns) */
      if (c + 1 < n)
        phgmg_gemv('T', m - c, n - c - 1, tau[c], A + c + (size_t)(c + 1) * (size_t)lda, lda,
                   ac + c, 0.0, F + (c + 1 - s) + (size_t)kk * (size_t)ldf);
      for (j = 0; j <= c - s; ++j) F[j + (size_t)kk * (size_t)ldf] = 0.0;
      /* F(:, kk) -= tau F(:, 0:kk) (A(c:m, s:c)^T v) */
      if (kk > 0) {
        phgmg_gemv('T', m - c, kk, -tau[c], A + c + (size_t)s * (size_t)lda, lda, ac + c, 0.0, aux);
        phgmg_gemv('N', n - s, kk, 1.0, F, ldf, aux, 1.0, F + (size_t)kk * (size_t)ldf);
      }
      /* row c of the trailing matrix: A(c, c+1:n) -= A(c, s:c+1) F(c+1-s:n-s, 0:kk+1)^T */
      for (j = c + 1; j < n; ++j) {
        double t = 0.0;
        for (q = 0; q <= kk; ++q)
          t += A[c + (size_t)(s + q) * (size_t)lda] * F[(j - s) + (size_t)q * (size_t)ldf];
        A[c + (size_t)j * (size_t)lda] -= t;
      }
      /* downdate the partial column norms; a column whose norm cancelled too much
         is marked for recomputation, which ends the block */
      if (c + 1 < m) {
        for (j = c + 1; j < n; ++j) {
          if (vn1[j] != 0.0) {
            double temp = fabs(A[c + (size_t)j * (size_t)lda]) / vn1[j], temp2;
            temp = (1.0 + temp) * (1.0 - temp);
            if (temp < 0.0) temp = 0.0;
            temp2 = temp * (vn1[j] / vn2[j]) * (vn1[j] / vn2[j]);
            if (temp2 <= tol3z) { mark[j] = 1; any_mark = 1; }
            else vn1[j] *= sqrt(temp);
          }
        }
      } else {
        for (j = c + 1; j < n; ++j) vn1[j] = vn2[j] = 0.0;
      }
      ac[c] = akk;
      ++kk;
    }
    if (stop) { s += kk; break; }
    /* trailing update A(s+kk:m, s+kk:n) -= A(s+kk:m, s:s+kk) F(kk:n-s, 0:kk)^T */
    if (s + kk < m && s + kk < n)
      phgmg_gemm('N', 'T', m - s - kk, n - s - kk, kk, -1.0, A + (s + kk) + (size_t)s * (size_t)lda,
                 lda, F + kk, ldf, 1.0, A + (s + kk) + (size_t)(s + kk) * (size_t)lda, lda);
    s += kk;
    if (any_mark)
      for (j = s; j < n; ++j)
        if (mark[j]) {
          vn1[j] = vn2[j] = (s < m) ? phgmg_normf(m - s, 1, A + s + (size_t)j * (size_t)lda, m - s) : 0.0;
          mark[j] = 0;
        }
  }
  *rank = s;
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
  int j, k;
  for (j = 0; j < nrhs; ++j) {
    double *b = B + (size_t)j * (size_t)ldb;
    for (k = n - 1; k >= 0; --k) {
      const double *r = R + (size_t)k * (size_t)ldr;
      double t = b[k] / r[k];
      b[k] = t;
      if (t != 0.0) phgmg__axpy(k, -t, r, b);
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
/* One-sided (Hestenes) Jacobi on the columns of X (r x r, ldx): X V = W diag(sigma).
   V (r x r, ldv; may be NULL) accumulates the rotations. On return X holds
   W diag(sigma). Pairs are visited block by block (a cyclic ordering) so that
   2*PHGMG__JAC_BS columns stay in cache. d: r doubles. */
#define PHGMG__JAC_BS 16
PHGMG__PRIV phgmg_result phgmg__jacobi_1s(int r, double *X, int ldx, double *V, int ldv,
                                          double *d) {
  const double tol = PHGMG__EPS * sqrt((double)PHGMG__MAX(r, 1));
  int sweep, p, q, ib, jb, rotated;
  for (sweep = 0; sweep < 80; ++sweep) {
    for (p = 0; p < r; ++p) {
      const double *xp = X + (size_t)p * (size_t)ldx;
      d[p] = phgmg__dot(r, xp, xp);
    }
    rotated = 0;
    for (ib = 0; ib < r; ib += PHGMG__JAC_BS)
      for (jb = ib; jb < r; jb += PHGMG__JAC_BS)
        for (p = ib; p < PHGMG__MIN(ib + PHGMG__JAC_BS, r); ++p) {
          double *xp = X + (size_t)p * (size_t)ldx;
          for (q = PHGMG__MAX(jb, p + 1); q < PHGMG__MIN(jb + PHGMG__JAC_BS, r); ++q) {
            double *xq = X + (size_t)q * (size_t)ldx;
            double alpha = d[p], beta = d[q], gamma, zeta, t, c, s;
            if (alpha == 0.0 || beta == 0.0) continue;
            gamma = phgmg__dot(r, xp, xq);
            if (fabs(gamma) <= tol * sqrt(alpha) * sqrt(beta)) continue;
            rotated = 1;
            zeta = (beta - alpha) / (2.0 * gamma);
            t = (zeta >= 0.0 ? 1.0 : -1.0) / (fabs(zeta) + sqrt(1.0 + zeta * zeta));
            c = 1.0 / sqrt(1.0 + t * t);
            s = c * t;
            phgmg__rot(r, xp, xq, c, s);
            if (V) phgmg__rot(r, V + (size_t)p * (size_t)ldv, V + (size_t)q * (size_t)ldv, c, s);
            d[p] = alpha - t * gamma;
            d[q] = beta + t * gamma;
            if (!(d[p] >= 0.0)) d[p] = 0.0;
          }
        }
    if (!rotated) return PHGMG_OK;
  }
  return PHGMG_ERR_NOT_CONVERGED;
}

/* Scale the m x n matrix W (ld m) by a power of two into a safe range, as
   LAPACK's drivers do: if its largest |entry| lies outside [2^-256, 2^256],
   W is multiplied (exactly) by 2^-e so that it lies in [1/2, 1); returns e
   (0: not scaled). The singular values of the input are those of W times 2^e;
   the singular vectors are the same. Inside the range nothing changes, so
   results for ordinary data are bit for bit those of the unscaled code. */
PHGMG__PRIV int phgmg__svd_scale(int m, int n, double *W) {
  const size_t cnt = (size_t)m * (size_t)n;
  double amax = 0.0;
  size_t t;
  int e = 0;
  for (t = 0; t < cnt; ++t)
    if (fabs(W[t]) > amax) amax = fabs(W[t]);
  if (amax == 0.0 || (amax >= ldexp(1.0, -256) && amax <= ldexp(1.0, 256))) return 0;
  (void)frexp(amax, &e); /* amax = f 2^e, f in [1/2, 1) */
  for (t = 0; t < cnt; ++t) W[t] = ldexp(W[t], -e);
  return e;
}

/* phgmg_svd after the pivoted QR A P = Q R (W: reflectors and R, rank r):
   the one-sided Jacobi SVD of R^T's triangular factor, then U = Q [.; 0] and
   V = P Q2 [.; 0]; the singular values scaled back by 2^esc. */
PHGMG__PRIV phgmg_result phgmg__svd_from_qr(int m, int n, int r, const double *W, const double *tau,
                                             const int *jpvt, int *perm, double *vn, int kmax, int esc, double *S,
                                             double *U, int ldu, double *V, int ldv, int *k_out, int *rank_out,
                                             const phgmg_allocator *alloc) {
  const int kmin = PHGMG__MIN(m, n);
  double *Rt, *tau2, *X, *Vj, *d;
  int i, j, k, rnz;
  phgmg_result rc;
  /* second workspace: Rt (n x r), tau2 (r), X (r x r), Vj (r x r), d (r) */
  double *W2 = phgmg__dalloc(alloc, (size_t)n * (size_t)r + 2 * (size_t)r * (size_t)r +
                                        2 * (size_t)r);
  if (!W2) return PHGMG_ERR_NOMEM;
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
  rc = phgmg__jacobi_1s(r, X, r, V ? Vj : NULL, r, d);
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
      S[j] = ldexp(s, esc); /* undo the scaling of phgmg__svd_scale (exact) */
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
  return rc;
}

PHGMG_DEF phgmg_result phgmg_svd(int m, int n, const double *A, int lda, int kmax,
                                 double *S, double *U, int ldu, double *V, int ldv,
                                 int *k_out, int *rank_out, const phgmg_allocator *alloc) {
  double *W = NULL, *tau, *vn, anorm;
  int *jpvt = NULL, *perm;
  int r, j, kmin = PHGMG__MIN(m, n), esc;
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
  /* workspace: W (m x n), tau (kmin), vn (2n), F (n x nb), aux (nb);
     ints: jpvt (n), perm (kmin), mark (n) */
  nw = (size_t)m * (size_t)n + (size_t)kmin + 2 * (size_t)n +
       (size_t)(n + 1) * PHGMG__QRCP_NB;
  W = phgmg__dalloc(alloc, nw);
  jpvt = phgmg__ialloc(alloc, 2 * (size_t)n + (size_t)kmin);
  if (!W || !jpvt) { phgmg__free(alloc, W); phgmg__free(alloc, jpvt); return PHGMG_ERR_NOMEM; }
  perm = jpvt + n;
  tau = W + (size_t)m * (size_t)n;
  vn = tau + kmin;
  for (j = 0; j < n; ++j)
    memcpy(W + (size_t)j * (size_t)m, A + (size_t)j * (size_t)lda, (size_t)m * sizeof(double));
  esc = phgmg__svd_scale(m, n, W);
  anorm = phgmg_normf(m, n, W, m);
  phgmg__qrcp_blocked(m, n, W, m, tau, jpvt, vn, vn + 2 * n, vn + 2 * n + (size_t)n * PHGMG__QRCP_NB,
                      perm + kmin, PHGMG__EPS * anorm, &r);
  if (r == 0) {
    *k_out = 0;
    if (rank_out) *rank_out = 0;
    phgmg__free(alloc, W);
    phgmg__free(alloc, jpvt);
    return PHGMG_OK;
  }
  rc = phgmg__svd_from_qr(m, n, r, W, tau, jpvt, perm, vn, kmax, esc, S, U, ldu, V, ldv, k_out, rank_out, alloc);
  phgmg__free(alloc, W);
  phgmg__free(alloc, jpvt);
  return rc;
}

/* ---- symmetric eigenproblem ------------------------------------------------------ */
/* Cyclic Jacobi (small n): A symmetric, destroyed; w unsorted; V (if not NULL)
   accumulates the rotations. */
PHGMG__PRIV phgmg_result phgmg__sym_jacobi(int n, double *A, int lda, double *w, double *V,
                                           int ldv) {
  int i, j, p, q, sweep, rotated = 1;
  double anorm = phgmg_normf(n, n, A, lda);
  if (V)
    for (j = 0; j < n; ++j)
      for (i = 0; i < n; ++i) V[i + (size_t)j * (size_t)ldv] = i == j ? 1.0 : 0.0;
  for (sweep = 0; sweep < 100 && rotated; ++sweep) {
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
        phgmg__rot(n, ap, aq, c, s);
        ap[p] = app - t * apq;
        aq[q] = aqq + t * apq;
        ap[q] = aq[p] = 0.0;
        for (i = 0; i < n; ++i) { /* mirror the two columns into rows p, q */
          if (i == p || i == q) continue;
          A[p + (size_t)i * (size_t)lda] = ap[i];
          A[q + (size_t)i * (size_t)lda] = aq[i];
        }
        if (V) phgmg__rot(n, V + (size_t)p * (size_t)ldv, V + (size_t)q * (size_t)ldv, c, s);
      }
    }
  }
  if (rotated) return PHGMG_ERR_NOT_CONVERGED;
  for (i = 0; i < n; ++i) w[i] = A[i + (size_t)i * (size_t)lda];
  return PHGMG_OK;
}

/* Householder tridiagonalization and implicit QL with shifts (the EISPACK
   tred2/tql2 scheme, as in JAMA), in W (n x n, ldw): only the lower triangle
   of W is read. vec: W ends up holding the eigenvectors. d (n) receives the
   eigenvalues (unsorted), e (n) is workspace. Without vec, e may be column n-1
   of W itself (that column is then not needed). */
/* tred2: Householder reduction of the symmetric W (lower triangle) to
   tridiagonal form; d, e receive the diagonal and the subdiagonal (e[i] couples
   i-1 and i), with vec W keeps the reflectors for phgmg__tred2_vectors. */
PHGMG__PRIV void phgmg__tred2(int n, double *W, int ldw, int vec, double *d, double *e) {
#define PHGMG__W(r, c) W[(size_t)(r) + (size_t)(c) * (size_t)ldw]
  int i, j, k;
  double f, g, h;
  for (j = 0; j < n; ++j) d[j] = PHGMG__W(n - 1, j);
  for (i = n - 1; i > 0; --i) {
    double scale = 0.0;
    h = 0.0;
    for (k = 0; k < i; ++k) scale += fabs(d[k]);
    if (scale == 0.0) {
      e[i] = d[i - 1];
      for (j = 0; j < i; ++j) {
        d[j] = PHGMG__W(i - 1, j);
        PHGMG__W(i, j) = 0.0;
        if (vec) PHGMG__W(j, i) = 0.0;
      }
    } else {
      double hh;
      for (k = 0; k < i; ++k) { d[k] /= scale; h += d[k] * d[k]; }
      f = d[i - 1];
      g = sqrt(h);
      if (f > 0) g = -g;
      e[i] = scale * g;
      h -= f * g;
      d[i - 1] = f - g;
      for (j = 0; j < i; ++j) e[j] = 0.0;
      for (j = 0; j < i; ++j) {
        const double *wj = &PHGMG__W(0, j);
        f = d[j];
        if (vec) PHGMG__W(j, i) = f;
        g = e[j] + wj[j] * f + phgmg__dot(i - 1 - j, wj + j + 1, d + j + 1);
        phgmg__axpy(i - 1 - j, f, wj + j + 1, e + j + 1);
        e[j] = g;
      }
      f = 0.0;
      for (j = 0; j < i; ++j) { e[j] /= h; f += e[j] * d[j]; }
      hh = f / (h + h);
      for (j = 0; j < i; ++j) e[j] -= hh * d[j];
      for (j = 0; j < i; ++j) {
        double *wj = &PHGMG__W(0, j);
        f = d[j];
        g = e[j];
        phgmg__axpy(i - j, -f, e + j, wj + j);
        phgmg__axpy(i - j, -g, d + j, wj + j);
        d[j] = PHGMG__W(i - 1, j);
        PHGMG__W(i, j) = 0.0;
      }
    }
    d[i] = h;
  }
#undef PHGMG__W
}

/* Accumulate the reflectors tred2 left in W into the orthogonal matrix W
   (d holds the h values on entry, the tridiagonal's diagonal on exit). */
PHGMG__PRIV void phgmg__tred2_vectors(int n, double *W, int ldw, double *d) {
#define PHGMG__W(r, c) W[(size_t)(r) + (size_t)(c) * (size_t)ldw]
  int i, j, k;
  double g, h;
  for (i = 0; i < n - 1; ++i) {
    PHGMG__W(n - 1, i) = PHGMG__W(i, i);
    PHGMG__W(i, i) = 1.0;
    h = d[i + 1];
    if (h != 0.0) {
      const double *wi1 = &PHGMG__W(0, i + 1);
      for (k = 0; k <= i; ++k) d[k] = wi1[k] / h;
      for (j = 0; j <= i; ++j) {
        double *wj = &PHGMG__W(0, j);
        g = phgmg__dot(i + 1, wi1, wj);
        phgmg__axpy(i + 1, -g, d, wj);
      }
    }
    for (k = 0; k <= i; ++k) PHGMG__W(k, i + 1) = 0.0;
  }
  for (j = 0; j < n; ++j) { d[j] = PHGMG__W(n - 1, j); PHGMG__W(n - 1, j) = 0.0; }
  PHGMG__W(n - 1, n - 1) = 1.0;
#undef PHGMG__W
}

/* tql2: implicit QL iteration on the tridiagonal (d, e from tred2; e shifted
   here), rotating the columns of W when vec. */
PHGMG__PRIV phgmg_result phgmg__tql2(int n, double *W, int ldw, int vec, double *d, double *e) {
#define PHGMG__W(r, c) W[(size_t)(r) + (size_t)(c) * (size_t)ldw]
  int i, l, m;
  double f, g, h, tst1;
  for (i = 1; i < n; ++i) e[i - 1] = e[i];
  e[n - 1] = 0.0;
  f = 0.0;
  tst1 = 0.0;
  for (l = 0; l < n; ++l) {
    tst1 = PHGMG__MAX(tst1, fabs(d[l]) + fabs(e[l]));
    m = l;
    while (m < n - 1 && fabs(e[m]) > PHGMG__EPS * tst1) ++m;
    if (m > l) {
      int iter = 0;
      do {
        double p, r, dl1, c, c2, c3, el1, s, s2;
        if (++iter > 60) return PHGMG_ERR_NOT_CONVERGED;
        g = d[l];
        p = (d[l + 1] - g) / (2.0 * e[l]);
        r = hypot(p, 1.0);
        if (p < 0) r = -r;
        d[l] = e[l] / (p + r);
        d[l + 1] = e[l] * (p + r);
        dl1 = d[l + 1];
        h = g - d[l];
        for (i = l + 2; i < n; ++i) d[i] -= h;
        f += h;
        p = d[m];
        c = c2 = c3 = 1.0;
        el1 = e[l + 1];
        s = s2 = 0.0;
        for (i = m - 1; i >= l; --i) {
          c3 = c2;
          c2 = c;
          s2 = s;
          g = c * e[i];
          h = c * p;
          r = hypot(p, e[i]);
          e[i + 1] = s * r;
          s = e[i] / r;
          c = p / r;
          p = c * d[i] - s * g;
          d[i + 1] = h + s * (c * g + s * d[i]);
          if (vec) phgmg__rot(n, &PHGMG__W(0, i), &PHGMG__W(0, i + 1), c, s);
        }
        p = -s * s2 * c3 * el1 * e[l] / dl1;
        e[l] = s * p;
        d[l] = c * p;
      } while (fabs(e[l]) > PHGMG__EPS * tst1);
    }
    d[l] += f;
    e[l] = 0.0;
  }
  return PHGMG_OK;
#undef PHGMG__W
}

PHGMG__PRIV phgmg_result phgmg__sym_tridiag_ql(int n, double *W, int ldw, int vec, double *d,
                                               double *e) {
  const double dlast = W[(size_t)(n - 1) + (size_t)(n - 1) * (size_t)ldw];
  int j;
  phgmg__tred2(n, W, ldw, vec, d, e);
  if (vec) {
    phgmg__tred2_vectors(n, W, ldw, d);
  } else {
    for (j = 0; j < n - 1; ++j) d[j] = W[(size_t)j + (size_t)j * (size_t)ldw];
    d[n - 1] = dlast;
  }
  return phgmg__tql2(n, W, ldw, vec, d, e);
}

#define PHGMG__SYM_JACOBI_MAX 24
PHGMG_DEF phgmg_result phgmg_sym_eig(int n, double *A, int lda, double *w, double *V, int ldv) {
  int i, j;
  phgmg_result rc;
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
  if (n <= PHGMG__SYM_JACOBI_MAX) {
    rc = phgmg__sym_jacobi(n, A, lda, w, V, ldv);
  } else if (V) {
    for (j = 0; j < n; ++j)
      memcpy(V + (size_t)j * (size_t)ldv, A + (size_t)j * (size_t)lda, (size_t)n * sizeof(double));
    rc = phgmg__sym_tridiag_ql(n, V, ldv, 1, w, A);
  } else {
    rc = phgmg__sym_tridiag_ql(n, A, lda, 0, w, A + (size_t)(n - 1) * (size_t)lda);
  }
  if (rc != PHGMG_OK) return rc;
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
#endif /* PHGMG_IMPLEMENTATION_DONE */
#endif /* PHGMG_IMPLEMENTATION */

/*
   REVISION HISTORY
   0.5.0  (2026-11-26)
          - Changed (breaking): the options of phgmg_reduce_opts are grouped
            in sub-structs, qm (phgmg_qm_opts), select (phgmg_select_opts),
            hyper (phgmg_hyper_opts) and cache (phgmg_reduce_cache); every
            moved field has a new name, so code using an old one no longer
            compiles (nothing changes meaning silently). Old name -> new name:
              rn -> qm.rn            lambda -> qm.lambda
              manifold -> qm.manifold            eta -> qm.eta
              greedy_window -> qm.greedy_window  eta_user -> qm.eta_user
              lambda_auto -> select.lambda_mode  lambda_min -> select.lambda_min
              lambda_max -> select.lambda_max    lambda_rcond -> select.rcond
              lambda_per_decade -> select.per_decade
              lambda_folds -> select.folds       lambda_blocks -> select.blocks
              lambda_tolerance -> select.tolerance
              lambda_train_only -> select.train_only
              newton_tol -> select.newton_tol    newton_iter -> select.newton_iter
              hyper_reduce -> hyper.on           hyper -> hyper.kind
              hyper_tol -> hyper.tol             deim_tol -> hyper.deim_tol
              deim_max -> hyper.deim_max
              deim_allow_negative -> hyper.allow_negative
              pod_basis -> cache.pod_basis       pod_cols -> cache.pod_cols
              grad_basis -> cache.grad_basis     grad_cols -> cache.grad_cols
              deim_pts -> cache.deim_pts         deim_w -> cache.deim_w
              deim_count -> cache.deim_count
            Unchanged: method, r, dt, degeneracy_tol, nrun, runs, ref, ref_x,
            progress, progress_user. Zero still means the default everywhere,
            and the models are the same bit for bit.
          - Changed: lambda_auto (0, 1, 2) is select.lambda_mode of the enum
            phgmg_lambda_mode (PHGMG_LAMBDA_FIXED, _VALIDATED, _REGRESSION,
            _MODE_COUNT), same values; opts.ref has the type phgmg_ref;
            phgmg_deim_select's method is of the enum phgmg_deim_method
            (PHGMG_DEIM_QDEIM, _GREEDY, _METHOD_COUNT; same values).
          - Removed: phgmg_reduce_opts.deim, the former name of hyper_reduce
            (now hyper.on). The CLI's options keep their names.
          - New: phgmg_ph_sparse_create_desc, the sparse constructor from
            one phgmg_ph_sparse_desc (J, R, Q, optional E, dense or CSC B).
          - New: descriptor models (a mass matrix E) take the sparse LU of
            sigma E + M when it is predicted cheaper, as models without E do
            (E kept as a compressed copy, no band copies; an E with zero
            lines keeps the band LU); phgmg_dae_create accepts such a model.
          - New: make build/phgmg-float, the command line with a float
            reduced model (C source for float firmware).
          - Fixed: SP1 and SP2 report info.pod_sigma_ratio (was 0).
          - Changed: the header's layout: the dense kernels (>>linalg) follow
            the domain sections in both halves; long design notes moved from
            declaration comments into the manual (8.1, 8.7, 8.10-8.12).
   0.4.0  (2026-11-26)
          - New: algebraic constraints of index one: a singular E with zero
            rows and columns (or a dense singular E, rotated into that form)
            is checked (PHGMG_ERR_INDEX, PHGMG_ERR_PENCIL), simulated with
            consistent states by phgmg_simulate and condensed into a
            port-Hamiltonian ODE (phgmg_dae_create and friends), which every
            method reduces; the command line does it by itself.
          - New: PHGMG_SPARSE storage: a sparse model whose solver is the
            sparse LU keeps J, R, Q only as compressed copies (no band copy;
            phgmg_ph_sparse_info.band_copy, .bytes). Such a system refuses a
            GENERAL part, dampers, feedthrough and the shifted-solve
            callbacks (PHGMG_ERR_UNSUPPORTED): choose the band solver for
            them (phgmg_ph_sparse_set_solver); PHGMG_STORAGE_COUNT is 3.
          - Changed: alternating minimization with a wide V2 is a descent in
            V1 with M eliminated by its ridge fit (replaces the rotation
            sweeps); the CLI takes --ref FILE and --greedy-window.
          - Changed: phgmg_gl3_create, phgmg_simulate_inputs and phgmg_reduce
            refuse an index-one model (PHGMG_ERR_UNSUPPORTED): give them the
            condensed model.
   0.3.0  (2026-11-26)
          - New: nonlinear dissipation (phgmg_ph_system dampers c_k rho_k(c_k^T z),
            PHGMG_ERR_DAMPER), kept by GMG-POD, SP1 and SP2 (reduced dampers,
            ECSW hyper-reduction); feedthrough P, S, N kept by the same
            reductions (phgmg_rom.PD); binary model format version 3 for
            models with either (other models keep versions 1 and 2).
          - New: an affine reference state (opts.ref, phgmg_ref: none, the
            snapshot mean, or a given vector; phgmg_rom.ref_g, ref_s, xr_rest);
            alternating minimization starts from the greedy manifold when V2
            is wide and greedy_window > 0.
          - New: sparse direct solves condense an independent set of states
            first; one stepper (and its factors) serves consecutive runs.
          - New: phgmg_simulate_run, phgmg_reduced_simulate_run (phgmg_sim_out)
            and phgmg_ss_compare (phgmg_ss, phgmg_ss_errors), struct forms of
            the long-argument drivers.
          - Renamed: phgmg_reduce_opts.deim is now hyper_reduce (deim still
            works and is resolved to it; to be removed in 1.0); the CLI's
            --no-deim is now --no-hyper (the old name still works).
          - Changed: the enumerated choices are typed enums ending in a
            _COUNT (phgmg_manifold, phgmg_hyper, phgmg_ref and the others);
            phgmg_reduce_opts.manifold and .hyper have those types.
   0.2.0  (2026-11-25)
          - Meaning changed: phgmg_reduce_opts.lambda_auto = 1 now chooses
            GMG-QM's ridge parameter by simulating the reduced model on the
            training runs (opts.runs) and three probe inputs against the
            linear limit M = 0, and keeps M = 0 when nothing is safe or no
            runs are given. In 0.1.0 lambda_auto = 1 was the regression
            validation on held-out time blocks of the snapshots; that choice
            is now lambda_auto = 2.
          - New: training runs (phgmg_run, phgmg_simulate_inputs,
            phgmg_runs_columns), phgmg_reduced_validate, the training envelope
            and quadratic-correction indicators of the online stepper,
            lambda_train_only, GMG-QM manifold constructions (greedy,
            alternating minimization).
          - New: Hamiltonians beyond polynomials (exp-polynomial family,
            callbacks, GENERAL), your own manifold (PHGMG_METHOD_GMG_MANIFOLD),
            binary model format version 2.
          - New: hyper-reduction with non-negative weights (ECSW) as the
            default of opts.deim = 1 (opts.hyper; the paper's DEIM as
            PHGMG_HYPER_QDEIM / _GREEDY), phgmg_deim_select, phgmg_nnls,
            phgmg_ecsw, phgmg_ecsw_separable.
          - New: linear systems (Lyapunov, Riccati, balanced truncation,
            positive-real BT in pH form, input-independent bases, H-infinity
            and H2 errors), sparse input (phgmg_ph_sparse_*, phgmg_rcm),
            randomized POD and its automatic use for large snapshot sets,
            studies over many orders (phgmg_study_*), optional OpenMP GEMM.
          - Changed: the default Newton tolerance follows the size of the
            states (1e-10 times max(1, |x|, |Z|)) and every step makes at
            least one Newton update; the non-degeneracy check no longer
            depends on the units of B; Q need only be semidefinite when H
            has a nonlinear part; new result code PHGMG_ERR_NOT_STABLE and
            Q's own codes; tiny entries flushed in the steppers' own vectors.
          - New result codes PHGMG_ERR_OVERFLOW, _TOL_UNREACHABLE,
            _NOT_STABILIZABLE, _STALE, _STRUCTURE (a load-time structure check
            of model files) and _STEP_MAP.
          - New: phgmg_reduce_opts_default, the defaults of phgmg_reduce_opts
            as one query; the library applies them in one place.
          - The manual at the top of this file.
   0.1.0  (2026-11-21) first version: GL3 full-order stepper with energy
          bookkeeping; POD, GMG-POD, GMG-QM, SP1, SP2, structure-preserving
          DEIM and the paper's error measures; allocation-free online stepper
          in float or double; C-source and binary export; .npy files.
*/

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
