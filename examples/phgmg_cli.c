/* phgmg — the command-line reducer: bring a port-Hamiltonian model as NumPy
   .npy arrays, get a structure-preserving reduced model back as .npy arrays,
   as the binary model file and as C source for firmware, without writing C.

   What it shows: the whole offline path of phgmg.h driven from files --
   reading and checking J, R, B, Q (and an optional separable polynomial
   nonlinearity), simulating the full model for snapshots (or reading them),
   phgmg_reduce, and the three export forms -- plus the online path
   (`simulate-rom`: load the model file, step it with the allocation-free GL3
   stepper, write the outputs) so the reduced model can be compared with the
   full one in Python. `phgmg --help` prints the manual (the text below in
   help_lines); examples/npy_example/ is the worked example (tests/CLI.md).

   Build: cc -std=c99 -O2 examples/phgmg_cli.c -o build/phgmg -lm
   Exit status: 0 success, 1 bad data or a failed computation/file, 2 bad usage. */
#define _POSIX_C_SOURCE 200809L
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#define CLI_MAX(a, b) ((a) > (b) ? (a) : (b))
#define CLI_MIN(a, b) ((a) < (b) ? (a) : (b))
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <time.h>
#include <unistd.h>

/* The manual, one string per line (C99 caps a single literal at 4095 bytes). */
static const char *const help_lines[] = {
  "phgmg " PHGMG_VERSION_STRING " - structure-preserving model order reduction of port-Hamiltonian\n",
  "systems (generalized manifold Galerkin), from NumPy .npy files.\n",
  "\n",
  "USAGE\n",
  "  phgmg reduce --J J.npy --R R.npy --B B.npy --Q Q.npy\n",
  "               (or --J-coo/--R-coo/--Q-coo for sparse J, R, Q; see SPARSE MATRICES)\n",
  "               (--X X.npy [--X-input KIND] ... | --simulate [--dt 0.1]\n",
  "               [--steps 1000] [--input sin] [--amp 0.1])\n",
  "               --method gmg-pod|gmg-qm|sp1|sp2 --r R [--rn 8] [--lambda auto|cv|L]\n",
  "               [--manifold pod|greedy|altmin] [--train-input KIND]...\n",
  "               [--poly coeffs.npy --poly-idx idx.npy [--poly-w w.npy]] [DEIM options]\n",
  "               --out DIR [--name rom] [--dt-map DT] [--save-snapshots] [--quiet]\n",
  "  phgmg reduce <the model options> --method bt|prbt|phbt --r R --out DIR [--name rom]\n",
  "               [--form ph|ss]  (balancing of a linear model: no snapshots; see\n",
  "               BALANCING METHODS)\n",
  "  phgmg simulate <the model options of reduce> --out y.npy [--states x.npy]\n",
  "               [--dt 0.1] [--steps 1000] [--input sin] [--amp 0.1] [--quiet]\n",
  "  phgmg simulate-rom --model DIR/NAME.phgmgrom | --ss DIR/NAME --out y.npy\n",
  "               [--states xr.npy] [--dt DT] [--steps 1000] [--input sin] [--amp 0.1]\n",
  "               [--quiet]\n",
  "  phgmg info MODEL.phgmgrom\n",
  "  phgmg validate <the options of reduce> [--test-input KIND]... [--test-amp A]\n",
  "               [--test-steps N] [--max-ey E]   (reduce, then run full and reduced\n",
  "               model on each test input: e_red, e_y, e_proj, energy, Newton, the\n",
  "               first failing step; exit 1 if one fails or e_y > E (E > 0, default\n",
  "               0.1); test amplitude A: default --amp;\n",
  "               default test inputs: the training input(s); with --X the\n",
  "               --X-input runs, else --test-input is required; each test runs\n",
  "               the training run's length unless --test-steps; the outputs are\n",
  "               written only when every test passes)\n",
  "  phgmg --help | --version\n",
  "\n",
  "THE MODEL\n",
  "  x' = (J - R) grad H(x) + B u(t),  y = B^T grad H(x),\n",
  "  H(x) = 1/2 x^T Q x + sum_k w_k phi(x[idx_k]),  phi(s) = sum_j c_j s^j (optional).\n",
  "  J (N x N) skew-symmetric, R (N x N) symmetric positive semidefinite, Q (N x N)\n",
  "  symmetric positive definite (the Hessian of the quadratic energy), B (N x m)\n",
  "  of full column rank, J - R nonsingular. The relative tolerance of these checks\n",
  "  is 1e-12; a failing check names the file and prints the measured defect.\n",
  "\n",
  "COMMAND reduce\n",
  "  --J FILE, --R FILE, --Q FILE   N x N matrices (required).\n",
  "  --B FILE            N x m port matrix, or a vector of length N for m = 1 (required).\n",
  "  --J-coo SPEC, --R-coo SPEC, --Q-coo SPEC   instead of --J, --R, --Q: sparse\n",
  "                      matrices as coordinate triplets (all three together; N from\n",
  "                      --B); see SPARSE MATRICES.\n",
  "  --E FILE, --E-coo SPEC   a mass matrix (N x N; dense with --J,\n",
  "                      coordinate triplets with --J-coo): the descriptor model\n",
  "                      E x' = (J - R) z + B u, y = B^T z, z = Q x (+ the nonlinear\n",
  "                      gradient), energy H = x^T E^T Q x / 2 (+ sum E_kk phi_k).\n",
  "                      E^T Q must be symmetric positive definite (semidefinite with\n",
  "                      --poly), and rows of E at --poly-idx coordinates unit rows\n",
  "                      times E_kk > 0. Methods gmg-pod, gmg-qm, sp1, sp2 (the\n",
  "                      reduced model is an ordinary pH model: simulate-rom, export),\n",
  "                      and bt, prbt, phbt with --E-coo (see BALANCING METHODS).\n",
  "                      Algebraic constraints: k zero rows and k zero columns of E\n",
  "                      (equations without a derivative, e.g. a massless node or a\n",
  "                      Kirchhoff law; a dense singular E is rotated into this form)\n",
  "                      are taken when they determine their variables\n",
  "                      (index one; index two or more, or a singular pencil, is an\n",
  "                      error naming the files): the model is condensed to its\n",
  "                      differential states (a port on a constraint becomes\n",
  "                      feedthrough, which gmg-qm and --ref do not take: gmg-pod,\n",
  "                      sp1, sp2 without --ref), simulated with consistent states and reduced;\n",
  "                      written states are full (basis rows of the algebraic\n",
  "                      variables zero). For dense input (--E) the condensation\n",
  "                      is dense in the algebraic lines (at most 4096); sparse\n",
  "                      input (--E-coo) is condensed sparsely, per connected group\n",
  "                      of algebraic lines, with no limit on them, and simulate\n",
  "                      of it steps the DAE itself on the sparse LU of its pencil\n",
  "                      (algebraic variables from the constraints at every step).\n",
  "                      A port that acts only through a constraint (its condensed\n",
  "                      column of B is zero: pure feedthrough) is reduced by sp1\n",
  "                      and sp2; gmg-pod and gmg-qm refuse it, naming the port.\n",
  "                      bt, prbt, phbt on --E-coo with algebraic lines: no\n",
  "                      condensation, the Gramians' solves use the whole sparse\n",
  "                      pencil; a port on a constraint is refused there (its\n",
  "                      feedthrough is not carried by their pH forms; bt --form ss\n",
  "                      writes the model with it).\n",
  "  --P FILE, --S FILE, --N FILE   feedthrough (N x m, m x m, m x m; each optional):\n",
  "                      E x' = (J - R) z + (B - P) u, y = (B + P)^T z + (S + N) u, with\n",
  "                      [[R, P], [P^T, S]] symmetric positive semidefinite and N skew.\n",
  "                      Kept by gmg-pod, sp1, sp2 (reduced P = W_z^T P, S + N; not by\n",
  "                      gmg-qm: an error names the files); simulate-rom adds (S + N) u.\n",
  "  --dampers FILE      nonlinear dampers, a (k, 4) array with rows (i, j, c1, c3):\n",
  "                      a damper on s = z_i - z_j (j = -1: s = z_i; 0-based states,\n",
  "                      z = Q x the co-state, e.g. a velocity) with the force\n",
  "                      c1 s + c3 s^3, c1, c3 >= 0 (a damper that generates energy is\n",
  "                      refused): E x' = (J - R) z - sum_k c_k (c1 s_k + c3 s_k^3) + B u.\n",
  "                      Methods gmg-pod, sp1, sp2 (without --ref); the reduced model\n",
  "                      keeps every damper (W_z^T c_k; online cost O(k r)): the\n",
  "                      hyper-reduction options apply to the --poly terms only.\n",
  "  --X FILE            snapshot matrix N x ns (ns >= 2 states, one per column; a\n",
  "                      trajectory x(t_0), ..., x(t_n), normally starting at x = 0).\n",
  "                      Repeatable (up to 16): one training run per file, the runs'\n",
  "                      boundaries known to the reduction (--lambda cv folds).\n",
  "                      --dt DT with --X: the snapshots' step, recorded in the model\n",
  "                      (simulate-rom's default step). With --stream (the default\n",
  "                      when the files hold more than 4 GiB) the files are read a\n",
  "                      block of columns at a time, never whole (see --stream).\n",
  "  --X-input KIND      the input that made each --X run (one per --X, same order;\n",
  "                      KIND as --input, sampled with --dt = the snapshots' step):\n",
  "                      --lambda auto then simulates the runs from their first\n",
  "                      snapshot, and validate tests them by default. Checked: the\n",
  "                      full model simulated from a run's first snapshot with its\n",
  "                      input must reproduce the next 5 snapshots (to 10 % of their\n",
  "                      change), else the run is refused. Without --X-input the\n",
  "                      inputs are unknown: --lambda auto is refused, and gmg-qm's\n",
  "                      default keeps M = 0 (said so).\n",
  "  --simulate          instead of --X: simulate the full model from x0 = 0 with the\n",
  "                      3-stage Gauss-Legendre method (order 6) and use the steps+1\n",
  "                      states as snapshots. Options:\n",
  "    --dt DT           step (default 0.1), recorded in the model as its training\n",
  "                      step (simulate-rom's default)\n",
  "    --steps N         number of steps (default 1000), t in [0, N*DT]\n",
  "    --stream          stream the states into an incremental POD as they are\n",
  "                      made (or read, with --X) instead of storing the N x ns\n",
  "                      snapshots; the default when they would exceed 4 GiB.\n",
  "                      Memory about N (K + 3 min(K, 64)) doubles while streaming,\n",
  "                      K = max(2 (R' + 1), R' + 41) modes kept (at most N - m),\n",
  "                      R' = R - m (gmg-pod) or R (sp1), R the largest order of\n",
  "                      --r (one stream serves a list of orders, one method).\n",
  "                      For --method gmg-pod and\n",
  "                      sp1 only, without a hyper-reduced --poly-idx part (use\n",
  "                      --no-hyper), --ref, --save-snapshots, --X-input, --E,\n",
  "                      feedthrough or --dampers (--stream then is a usage error).\n",
  "                      The model equals the stored run's when the snapshots'\n",
  "                      numerical rank is at most K (the log states the POD's\n",
  "                      error bound otherwise)\n",
  "    --input KIND      sin (default): u(t) = AMP sin(t); with m > 1 ports each port\n",
  "                      at its own frequency, u_a(t) = AMP sin((1 + a/m) t) for\n",
  "                      a = 0..m-1, so that the ports are excited independently;\n",
  "                      const: u(t) = AMP on every port (the same on all: pointed out\n",
  "                      for m > 1, as for a table whose columns are equal); or a\n",
  "                      FILE.npy (see INPUT FILES; AMP is then not used);\n",
  "                      chirp: u(t) = AMP sin(p(t)), its angular frequency p'(t)\n",
  "                      rising linearly from --freq to --freq-end over the run\n",
  "                      (t in [0, steps*DT]; port a: p(t) (1 + a/m))\n",
  "    --amp AMP         amplitude (default 0.1)\n",
  "    --freq W          angular frequency of sin (rad per unit of time; W/(2 pi) in\n",
  "                      Hz), u(t) = AMP sin(W t) (port a: W (1 + a/m)); chirp's\n",
  "                      start. Default 1\n",
  "    --freq-end W1     chirp's final angular frequency (default 10 W)\n",
  "    --x0 FILE         initial state of the training runs (N values, the files'\n",
  "                      ordering; default 0; not for a model with algebraic\n",
  "                      constraints); also for simulate\n",
  "    --newton-tol T    Newton tolerance (stage residual, inf-norm, absolute) for\n",
  "                      nonlinear models (default: the library's, 1e-10 times\n",
  "                      max(1, |x|, |stage increment|): follows large states; the log\n",
  "                      of a nonlinear model's simulation names the tolerance used.\n",
  "                      For a reference accurate to about 1e-10 give about 1e-13\n",
  "                      times the states' size)\n",
  "    --newton-iter K   Newton iteration cap per step (default 10)\n",
  "  --method M          gmg-pod: linear map phi(x) = [B, V] x, GMG reduction (paper 4.2.1)\n",
  "                      gmg-qm:  quadratic manifold phi(x) = [B, V1] x + V2 M (x2 kron x2)\n",
  "                               (paper 4.2.2)\n",
  "                      sp1:     SP1-POD, phi = V x, W = QV (V^T Q V)^-1 (baseline)\n",
  "                      sp2:     SP2-POD, W from a POD of the gradient snapshots\n",
  "                      bt, prbt, phbt: balancing of a linear model, no snapshots\n",
  "                               (see BALANCING METHODS)\n",
  "                      (required). A comma-separated list (e.g. gmg-pod,sp1) builds\n",
  "                      a model for each method (see SWEEPS).\n",
  "  --r R               reduced order (required); a list R1,R2,... (e.g. 10,20,40, up\n",
  "                      to 16 orders) builds a model for each (see SWEEPS). For gmg-pod/gmg-qm it includes the m\n",
  "                      port coordinates, so m < R <= N; R - m (gmg) or R (sp1/sp2) must\n",
  "                      not exceed the rank of the (adjusted) snapshots.\n",
  "  --rn K              gmg-qm only: lifting dimension r_n (default 8, or the largest that\n",
  "                      fits; K <= 4096, R + K <= N). Or:\n",
  "    --rn wide         V2 over the whole residual of the snapshots (up to its numerical\n",
  "                      rank and (R-m)(R-m+1)/2): what the greedy and altmin manifolds\n",
  "                      need on transport data; offline one SVD of the residual\n",
  "  --ref KIND|FILE     affine reference state xbar: none (default), mean (the mean of\n",
  "                      the snapshots) or a .npy file of N values (your state, e.g. an\n",
  "                      equilibrium; read, never written); the model is\n",
  "                      phi(x) = xbar + [B, V1] x (+ V2 q),\n",
  "                      bases and manifold fitted to the snapshots minus xbar. Every\n",
  "                      method. A run from rest starts at the model's xr_rest = rho(0)\n",
  "                      (simulate-rom does). Pays off for data not centred at 0\n",
  "                      (travelling pulses, states about a loaded equilibrium).\n",
  "  --lambda L          gmg-qm only: ridge parameter, on the un-normalised sum over the\n",
  "                      snapshots (0 = exactly zero; the paper's value is 1e-3). Or:\n",
  "    --lambda auto     the default: validated by simulation (the safe choice):\n",
  "                      the reduced model is simulated for candidate lambdas on\n",
  "                      the training runs and on three probe inputs and compared\n",
  "                      with M = 0 (GMG-POD on the same basis); no safe lambda:\n",
  "                      M = 0. Needs the training inputs (--simulate, or --X with\n",
  "                      --X-input; else M = 0). Costs seconds.\n",
  "    --lambda cv       regression only (held-out time blocks; one run per fold with\n",
  "                      several --train-input): fits the snapshots closely, but may\n",
  "                      give a model that fails on other inputs.\n",
  "  --manifold KIND     gmg-qm linear part of the manifold: pod (default, the paper's\n",
  "                      hierarchical POD), greedy (V1 chosen among POD modes by the\n",
  "                      quadratic fit), altmin (alternating minimization of V1, V2\n",
  "                      and M over the snapshots, started from pod; B stays in the\n",
  "                      span). Representation error: altmin <= pod on the snapshots.\n",
  "  --greedy-window W   with --manifold greedy or altmin and --rn wide: V1 is chosen\n",
  "                      among the leading R - m + W POD modes, each scored by the ridge\n",
  "                      fit of the other candidates (default: the leading R - m + 8,\n",
  "                      scored by the misfit). Transport data (travelling pulses) need\n",
  "                      a wide window, e.g. 200; offline cost grows with W (seconds).\n",
  "  --train-input KIND  with --simulate, instead of --input: one training run per\n",
  "                      --train-input (repeatable, up to 16; KIND as --input), each\n",
  "                      from x0 = 0 with the same --dt, --steps and --amp; the\n",
  "                      snapshots of all runs together, the run boundaries known to\n",
  "                      the reduction and to --lambda auto/cv.\n",
  "  --poly FILE         separable nonlinearity H_nl = sum_k w_k phi_k(x[idx_k]) from the\n",
  "                      exp-polynomial family phi(s) = sum_j c_j s^j + sum_e a_e exp(b_e s):\n",
  "                      the coefficients c_0, ..., c_d (constant first) as a vector\n",
  "                      (shared by every term) or a matrix (terms, d+1), one row per term.\n",
  "  --exp FILE          the exponentials (a_e, b_e): a matrix (n_exp, 2) shared by every\n",
  "                      term, or (terms, 2 n_exp) with rows a_1 b_1 a_2 b_2 ... per term\n",
  "                      (a (terms, 2) matrix with up to 8 terms is per term only beside\n",
  "                      a per-term --poly).\n",
  "  --potential NAME    a named potential instead of --poly/--exp: toda (e^s - 1 - s),\n",
  "                      cosh:A ((cosh(A s) - 1)/A^2, A != 0), morse:D:A (D (1 - e^{-A s})^2,\n",
  "                      D > 0, A != 0), fpu:K3:K4 (K3 s^3/3 + K4 s^4/4, K4 > 0). --poly,\n",
  "                      --exp or --potential need --poly-idx. An energy unbounded below\n",
  "                      (a term w phi(s) -> -inf: a negative leading power >= 3 or\n",
  "                      fastest exponential) is refused.\n",
  "  --poly-idx FILE     a vector of the 0-based state coordinates idx_k of the terms\n",
  "                      (each in [0, N); any integer dtype, e.g. np.arange, or float64).\n",
  "  --poly-w FILE       a vector of the term weights w_k (default all 1).\n",
  "  --poly-jdx FILE     springs: a vector of second coordinates j_k, one per entry of\n",
  "                      --poly-idx; term k then acts on x[idx_k] - x[j_k] (a spring\n",
  "                      between two nodes), or on x[idx_k] where j_k = -1. Each j_k in\n",
  "                      [-1, N), j_k != idx_k; with --E rows idx_k and j_k of E unit\n",
  "                      rows with E(idx_k, idx_k) = E(j_k, j_k); a sparse model's\n",
  "                      springs within its band (give their linear part in Q).\n",
  "  --no-hyper          keep every nonlinear term online (exact, cost O(terms));\n",
  "                      --no-deim is the former name. Default: the hyper-reduction\n",
  "                      (--hyper) keeps a few weighted terms.\n",
  "  --hyper H           hyper-reduction of the nonlinear terms: ecsw (default; weights\n",
  "                      >= 0 by non-negative least squares), qdeim or greedy (the\n",
  "                      paper's structure-preserving DEIM; weights may be negative)\n",
  "  --hyper-tol T       ecsw: relative training residual of the reduced gradient\n",
  "                      (default 1e-6; 1e-14 <= T < 1)\n",
  "  --deim-tol T        qdeim/greedy: keep the modes with sigma_k / sigma_1 > T\n",
  "                      (default 1e-8; 0 <= T < 1)\n",
  "  --deim-max K        qdeim/greedy: at most K DEIM points (default: no cap)\n",
  "                      The options of the hyper-reduction need a nonlinear part.\n",
  "  --deim-allow-negative  accept negative DEIM weights (the reduced energy may then\n",
  "                      lose its lower bound); default: refuse with an error.\n",
  "  --dt-map DT         precompute the exact GL3 step map for step DT in the model\n",
  "                      (linear models with quadratic H; the online stepper then needs\n",
  "                      no Newton iteration at that step). Default: the --dt of\n",
  "                      --simulate, none with --X; 0 = none. A step map with spectral\n",
  "                      radius above 1 (an amplifying step) is refused. A model that\n",
  "                      cannot have one (nonlinear terms, dampers, feedthrough, gmg-qm)\n",
  "                      gets none: a --dt-map given then draws a note saying why.\n",
  "  --degeneracy-tol T  gmg: least non-degeneracy measure of D^T G D (the reduced\n",
  "                      model's operator, measured in equilibrated coordinates against\n",
  "                      the rounding of its entries, so independent of units and mesh;\n",
  "                      reported as rcond(D^T G D)); sp1/sp2: least rcond of V^T W.\n",
  "                      Below it the reduction is refused. Default 1e-12; 0 < T < 1.\n",
  "  --out DIR           output directory (required); created if missing, before\n",
  "                      any work (and removed again if the run fails); a file is\n",
  "                      created and removed there first to see that it is writable.\n",
  "  --name NAME         base name of the outputs and C identifier prefix (default rom;\n",
  "                      letters, digits and _, not starting with a digit; not a C/C++\n",
  "                      keyword, not starting with phgmg or _, not a name of the C\n",
  "                      library headers phgmg.h includes).\n",
  "  --save-snapshots    also write NAME_snapshots.npy (N x ns) and NAME_fom_y.npy\n",
  "                      (m x ns: the full model's output at the snapshots).\n",
  "  --quiet             no progress lines on stderr.\n",
  "\n",
  "  Outputs in DIR (entries below the smallest normal number of the build's\n",
  "  scalar type, DBL_MIN or FLT_MIN, are set to 0 in every array of the reduced\n",
  "  model: no subnormal constants in the model file, C source or .npy arrays):\n",
  "    NAME.phgmgrom      the binary model file (phgmg_rom_load; for simulate-rom)\n",
  "    NAME.c             C source: static const arrays NAME_<field> and a\n",
  "                      `static const phgmg_rom NAME` (include after phgmg.h),\n",
  "                      in this build's scalar type: double; for float firmware\n",
  "                      use the float build of this program (make build/phgmg-float)\n",
  "    NAME_<field>.npy   every array of the reduced model, float64, with its matrix\n",
  "                      shape: Bh (r x m), Qh (r x r), K (r x r, = J_r - R_r), and as\n",
  "                      they apply G00 G01 G10 G11 Q01 Q11 Ms (gmg-qm), P0 P1 w poly\n",
  "                      (nonlinear), Phi Gam SX SU (step map); see phgmg.h >>online.\n",
  "    NAME_PD.npy        (feedthrough: --P, --S, --N, or a port on a constraint) the\n",
  "                      reduced feedthrough [Ph; S + N], (r + m) x m: rows 0..r-1\n",
  "                      Ph = W_z^T P (x' = ... + (Bh - Ph) u), rows r..r+m-1 S + N\n",
  "                      (y = (Bh + Ph)^T grad H + (S + N) u)\n",
  "    NAME_V0.npy        the reduction basis V0 (N x r): x ~ V0 xr (every method)\n",
  "    NAME_V2.npy, NAME_M.npy  (gmg-qm) V2 (N x r_n) and M (r_n x p^2, p = r - m):\n",
  "                      x ~ V0 xr + V2 M kron(x2, x2), x2 = xr[m:]\n",
  "    NAME.json          sizes, method, options, diagnostics and the list of files;\n",
  "                      \"kind\": linear or nonlinear (energy terms, dampers), \"map\":\n",
  "                      the reduction map, linear (x = V0 xr) or quadratic (gmg-qm);\n",
  "                      \"E\": whether the model has a mass matrix, \"N_full\": all its\n",
  "                      states (\"N\" is the number reduced: an index-one model's\n",
  "                      differential states), \"algebraic\", \"feedthrough\"\n",
  "  A run writes all of these or none: they are written under temporary names and\n",
  "  renamed at the end; the NAME_*.npy arrays that an earlier run listed in its\n",
  "  NAME.json and this run does not produce (another method) are removed. A run\n",
  "  never writes or removes one of its input files -- every file option: the\n",
  "  model's (also --E, --P, --S, --N, --dampers), --X, --ref FILE, input files --\n",
  "  compared as files (however spelled or linked): an output that would be an\n",
  "  input is refused before any work (status 2).\n",
  "  The reduced model (LINEAR kind) is x' = K grad H(x) + Bh u, y = Bh^T grad H(x),\n",
  "  H(x) = 1/2 x^T Qh x (+ sum_j w_j phi(P0_j x)); it is again port-Hamiltonian.\n",
  "\n",
  "SWEEPS (several --method and --r in one call)\n",
  "  reduce and validate with a list in --method or --r build every (method, r)\n",
  "  pair (up to 32 models) from one set-up: the files are read and checked, the\n",
  "  training runs simulated and the snapshots' bases (POD) computed once (the\n",
  "  balancing methods: the Gramian factors, once per model; the log says\n",
  "  'Gramian factors: computed' or 'reused' per model); every\n",
  "  size is checked for every pair before any work. Model (M, R) is written as\n",
  "  NAME_<M>_r<R>.* with the method's '-' as '_' (rom_gmg_pod_r20.phgmgrom,\n",
  "  rom_sp1_r40_V0.npy, rom_gmg_pod_r20.json, ...); NAME_sweep.json lists the\n",
  "  models (method, r, name, reduction seconds, written or not, and with\n",
  "  validate each test's e_y, e_red and verdict). With a single method and\n",
  "  order the names are NAME.* as above. reduce writes all models or none;\n",
  "  validate runs the full model once per test input for all models (one\n",
  "  table line per test and model), writes the models that pass every test and\n",
  "  not those that fail (exit 1 if one fails).\n",
  "\n",
  "COMMAND simulate\n",
  "  Runs the full model (the model options of reduce: --J/--R/--Q or the -coo\n",
  "  forms, --B, the nonlinear part) from x = 0 with the GL3 stepper and writes its\n",
  "  output y, an m x (steps+1) matrix (column n = y(n*DT)).\n",
  "  --out FILE          output .npy (required; never one of the input files)\n",
  "  --states FILE       also the states (N x (steps+1), the given ordering of the\n",
  "                      coordinates); written together with --out: both or neither\n",
  "  Before the run: --out and --states must be other files than every input and\n",
  "  than each other (compared as files, however spelled or linked: status 2), and\n",
  "  their directories must exist and take a new file. E goes with J, R, Q: --E with\n",
  "  --J/--R/--Q, --E-coo with --J-coo/--R-coo/--Q-coo. A step beyond what a double\n",
  "  resolves, dt max|J - R| max|Q| / max|E| > 1/eps = 4.5e15 (the stage equations\n",
  "  lose the mass term; the output would be round-off, zero or NaN), is refused\n",
  "  (also by reduce --simulate and validate).\n",
  "  --dt DT, --steps N, --input KIND, --amp AMP, --freq W, --freq-end W1, --x0 FILE,\n",
  "  --newton-tol T, --newton-iter K:  as for reduce --simulate\n",
  "  Sparse input: the log names the solver of the stage systems (band LU, or the\n",
  "  sparse LU for 2-D/3-D meshes; see phgmg.h >>sparse).\n",
  "  --quiet             no progress lines\n",
  "\n",
  "COMMAND simulate-rom\n",
  "  Runs a reduced model from rest (the full state 0: xr = 0, or the model's\n",
  "  xr_rest = rho(0) when it has a reference state, see --ref) with the online GL3\n",
  "  stepper and writes its output y, an m x (steps+1) matrix (column n = y(n*DT)).\n",
  "  --model FILE        a .phgmgrom file written by reduce (required, or --ss)\n",
  "  --ss DIR/NAME       instead of --model: the state-space model of reduce --method\n",
  "                      bt --form ss (DIR/NAME_A.npy, _B, _C, _D), stepped by the\n",
  "                      same 3-stage Gauss-Legendre method at the same input points\n",
  "                      (linear: one LU of order 3 r, no Newton), from xr = 0 or\n",
  "                      --x0; y = C xr + D u, in double (also in the float build).\n",
  "                      Default --dt 0.1 (the model records no step: a note says\n",
  "                      so). The outputs as for --model.\n",
  "  --out FILE          output .npy (required)\n",
  "  --states FILE       also write the reduced states (r x (steps+1)); written together\n",
  "                      with --out: both or neither\n",
  "  --dt DT             step (default: the model's step-map DT if it has one, else the\n",
  "                      step it was trained at (reduce records --simulate's --dt, the\n",
  "                      --dt of --X with --X-input, or --dt given with --X), else 0.1;\n",
  "                      a note on stderr when --dt differs from the model's)\n",
  "  --steps N, --input KIND, --amp AMP, --freq W, --freq-end W1, --newton-tol T,\n",
  "  --newton-iter K:    as above\n",
  "  --x0 FILE           the reduced initial state xr0 (r values; default: rest)\n",
  "  --quiet             no progress lines\n",
  "\n",
  "COMMAND info MODEL\n",
  "  Prints the sizes of a .phgmgrom file, its step map's or training dt, and the\n",
  "  bytes of stepper memory its firmware needs (phgmg_rom_stepper_memsize; with a\n",
  "  step map also the bytes for stepping with another dt,\n",
  "  phgmg_rom_stepper_memsize_dt).\n",
  "\n",
  "SPARSE MATRICES\n",
  "  SPEC is one (nnz, 3) array of rows (row, col, value), or three vectors\n",
  "  rows.npy,cols.npy,vals.npy (comma-separated, no spaces), or a SciPy sparse\n",
  "  FILE.npz (scipy.sparse.save_npz of a csr, csc or coo matrix, compressed or\n",
  "  not), or a Matrix Market FILE.mtx (scipy.io.mmwrite; coordinate, real or\n",
  "  integer, general, symmetric or skew-symmetric: the upper triangle is added,\n",
  "  negated for skew; 1-based as the format says), shape N x N: 0-based integer indices\n",
  "  in [0, N), duplicates summed (as scipy.sparse does; the library's\n",
  "  phgmg_csc_from_coo does it in C for your own code). The stepper's stage\n",
  "  systems are solved by the header's sparse direct LU (fill-reducing ordering,\n",
  "  with a mass matrix a column matching that keeps the pivots on E's large\n",
  "  entries) or, where that is predicted cheaper (narrow bands), by a band LU after\n",
  "  reverse Cuthill-McKee. Dampers take the sparse LU too; an E with zero\n",
  "  rows/columns is stepped on the sparse LU by simulate, and reduce condenses it\n",
  "  sparsely (no limit on the algebraic lines; the condensed model on the sparse LU).\n",
  "  The log names the solver and any fall-back to the band LU. V0, V2 and the\n",
  "  snapshots are written in your ordering, --poly-idx and --X are in your ordering.\n",
  "  From SciPy (A any scipy.sparse matrix):\n",
  "    c = A.tocoo(); np.save('J_rows.npy', c.row); np.save('J_cols.npy', c.col)\n",
  "    np.save('J_vals.npy', c.data)     # --J-coo J_rows.npy,J_cols.npy,J_vals.npy\n",
  "    np.save('J.npy', np.column_stack([c.row, c.col, c.data]))   # --J-coo J.npy\n",
  "    scipy.sparse.save_npz('J.npz', A)                               # --J-coo J.npz\n",
  "    scipy.io.mmwrite('J.mtx', A)                                    # --J-coo J.mtx\n",
  "\n",
  "BALANCING METHODS (--method bt, prbt, phbt)\n",
  "  Input-independent reduction of a linear model (no --X, no --simulate, no\n",
  "  nonlinear part, dampers or feedthrough) from its matrices alone. The solvers\n",
  "  follow the input's form: a model given by --J-coo/--R-coo/--Q-coo (and\n",
  "  --E-coo) goes to the low-rank solvers -- Gramian factors by low-rank ADI on\n",
  "  sparse LU factorizations (tolerance 1e-10), no N x N matrix, for N up to 10^5\n",
  "  and more -- a model given by --J/--R/--Q (dense, standard form; no --E) to the\n",
  "  dense solvers (O(N^3): up to a few thousand states). --E-coo may be a mass\n",
  "  matrix of full rank or have algebraic lines of index one (zero rows and\n",
  "  columns): then the ADI solves with the whole pencil and the Gramians are\n",
  "  those of the condensed model, which is never formed (the algebraic lines\n",
  "  are not condensed in a run of balancing methods alone); all ports must act\n",
  "  on differential rows (a port on a constraint has a feedthrough, which the\n",
  "  pH forms written here do not carry: the run fails and says so; use bt with\n",
  "  --form ss, or sp1/sp2).\n",
  "  Lightly damped models (wave equations, eigenvalues close to the imaginary\n",
  "  axis) need many ADI steps (Gramian ranks of hundreds to thousands): raise\n",
  "  --adi-maxit when the log reports no convergence.\n",
  "  --adi-maxit K       low-rank ADI steps per Gramian before giving up (default\n",
  "                      500; a complex shift pair counts two); memory grows with\n",
  "                      the steps (N m doubles per step, m the ports). With --lyap\n",
  "                      eksm: extended Krylov blocks (default 100; 4 N m doubles\n",
  "                      per block).\n",
  "  --lyap adi|eksm     the low-rank Lyapunov solver of bt, prbt and phbt: adi (the\n",
  "                      default; the low-rank ADI, one sparse LU per shift) or eksm\n",
  "                      (the extended Krylov method: one sparse LU for the whole\n",
  "                      run, and one of the mass matrix E; more columns; E of\n",
  "                      full rank only: no algebraic equations).\n",
  "                      The same relative residual 1e-10; NAME.json names it.\n",
  "    bt    balanced truncation (needs m < R); the H-infinity error bound\n",
  "          2 sum_{i>R} sigma_i (low-rank: over the values computed) in the log\n",
  "          and NAME.json. The reduced model is written in pH form (NAME_K,\n",
  "          NAME_Qh, NAME_Bh: K Qh, Bh, Bh^T Qh are the BT model's matrices, Qh a\n",
  "          solution of its positive-real lemma): that needs the BT model to be\n",
  "          passive; when it is not (it can happen near w = 0 for models whose\n",
  "          transfer function vanishes there; finite-element models with a\n",
  "          consistent mass matrix) the run fails and says so: use --form ss,\n",
  "          prbt or phbt, or another R.\n",
  "    prbt  positive-real balanced truncation (needs m < R): a passive pH\n",
  "          reduced model by construction. Sparse input: two stages, stated in\n",
  "          the log and NAME.json -- the pH Galerkin projection onto the span\n",
  "          of the controllability Gramian's low-rank factor, then the dense\n",
  "          PRBT of that model (order: the factor's rank, typically 50-200).\n",
  "    phbt  pH-preserving balancing with one Lyapunov equation (sparse input\n",
  "          only): the controllability Gramian balanced against the model's\n",
  "          minimal Hamiltonian (the least energy function among its pH forms;\n",
  "          the energy Q where none exists: a port without damping), in two\n",
  "          stages like prbt. pH by construction, no error bound; about as\n",
  "          accurate as prbt, less than bt.\n",
  "  --form ph|ss        the form of the reduced model. ph (the default): a pH\n",
  "                      model, the usual files. ss (--method bt only, sparse input\n",
  "                      --J-coo ..., one --r): balanced truncation's model as it is,\n",
  "                      xr' = A xr + B u, y = C xr + D u (Er = I), written as\n",
  "                      NAME_A.npy (r x r), NAME_B.npy (r x m), NAME_C.npy (m x r),\n",
  "                      NAME_D.npy (m x m: zero, or the feedthrough of ports on\n",
  "                      constraints), NAME_V0.npy (N x r: the balancing basis, x ~\n",
  "                      V0 xr; with a port on a constraint the algebraic variables\n",
  "                      also depend on u) and NAME.json (\"form\": \"ss\"; \"info\": the\n",
  "                      Gramian ranks, ADI steps, Lyapunov residuals, the first R\n",
  "                      Hankel singular values, \"hsv_next\" sigma_{R+1},\n",
  "                      \"error_bound\" 2 sum_{i>R} sigma_i over the values computed,\n",
  "                      \"feedthrough_max\" max |D|). It exists whether or not the\n",
  "                      model is passive, and the bound holds for it with D.\n",
  "                      No model file or C source (an earlier run's NAME.phgmgrom\n",
  "                      and NAME.c are removed); simulate-rom --ss DIR/NAME runs it.\n",
  "                      validate does not take it.\n",
  "  NAME.json's \"info\" holds the solver (low-rank or dense), the Gramian\n",
  "  factors' ranks, ADI steps and factorizations, the Lyapunov residuals\n",
  "  (relative), the singular values (first 64) and, for bt, \"error_bound\". The\n",
  "  log shows every phase (Gramians, shifts, balancing) that starts after the\n",
  "  first second. The model files are the usual ones; simulate-rom runs them\n",
  "  validate takes these methods too: --dt, --steps, --input, --amp (or\n",
  "  --test-input) then set its test runs (default: sin, 1000 steps of 0.1).\n",
  "  Example (a 2-D model with 10^5 states, one core: about 10 s for heat,\n",
  "  90 s for a mass-spring lattice):\n",
  "    phgmg reduce --J-coo J.npy --R-coo R.npy --Q-coo Q.npy --B B.npy \\\n",
  "          --method bt --r 20 --out out --name bt\n",
  "\n",
  "INPUT FILES (.npy)\n",
  "  Read: format versions 1.0-3.0, float64, float32, int8-int64, uint8-uint64 or\n",
  "  bool, little- or big-endian, C or Fortran order, 0-d/1-d/2-d. Matrices are\n",
  "  (rows, cols) as NumPy shows them, so np.save('J.npy', J) is all it takes.\n",
  "  Values must be finite; 64-bit integers at most 2^53 in magnitude (exact as\n",
  "  doubles).\n",
  "  --input FILE.npy:   either a 2-d table of shape (K, 1 + m): column 0 the times\n",
  "                      (strictly increasing), columns 1..m the inputs at those times;\n",
  "                      or, for m = 1, a vector of K samples u(k DT), k = 0..K-1.\n",
  "                      u(t) is interpolated linearly, held constant outside (a\n",
  "                      note says so when a run goes past the table's last time).\n",
  "  Written: format 1.0, '<f8', Fortran order (NumPy reads it as usual).\n",
  "\n",
  "EXAMPLES\n",
  "  /usr/bin/python3 examples/npy_example/make_model.py model  # the paper's linear MSD, N = 100\n",
  "  phgmg reduce --J model/J.npy --R model/R.npy --B model/B.npy --Q model/Q.npy \\\n",
  "        --simulate --dt 0.1 --steps 1000 --input sin --amp 0.1 \\\n",
  "        --method gmg-pod --r 12 --out out --name msd\n",
  "  phgmg simulate-rom --model out/msd.phgmgrom --dt 0.1 --steps 1000 --input sin \\\n",
  "        --amp 0.1 --out out/y_rom.npy\n",
  "  /usr/bin/python3 examples/npy_example/compare.py --model model --rom-y out/y_rom.npy\n",
  "  phgmg reduce ... --X X.npy --method gmg-qm --r 12 --rn 8 --lambda 1e-3 --out out\n",
  "  phgmg reduce ... --poly c.npy --poly-idx idx.npy --simulate --method gmg-pod --r 16 --out out\n",
  "\n",
  "OPTIONS\n",
  "  Each option may be given once; a repeated option is a usage error. Numbers\n",
  "  must be finite doubles of normal magnitude (0 or |x| >= 2.2e-308). A run whose\n",
  "  arrays would need more than 4 GiB (--steps, --simulate) is refused up front.\n",
  "\n",
  "EXIT STATUS\n",
  "  0 success; 1 a file could not be read/written, bad data, or a failed\n",
  "  computation (the message names the file and the problem); 2 bad usage.\n",
  NULL};

static void print_help(void) {
  int i;
  for (i = 0; help_lines[i]; ++i) fputs(help_lines[i], stdout);
}

/* ---- messages ------------------------------------------------------------- */
static int g_quiet = 0;

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Progress line on stderr (suppressed by --quiet). */
static void progress(const char *fmt, ...) {
  va_list ap;
  if (g_quiet) return;
  fputs("phgmg: ", stderr);
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
}

/* phgmg_reduce_opts.progress: one line per reduction phase, with the time
   since the reduction started, the lambda candidates and full-model probe
   runs numbered. Every phase of a long reduction (N * ns >= 1e7, e.g.
   N >= 10 000 with 1001 snapshots); of others, the phases that start after
   the reduction has run a second (a short reduction stays quiet). */
typedef struct phase_log {
  double t0;
  int all, ncand, nprobe, qm, hyper, quiet;
  const char *last;   /* the phase running now (a failure names it) */
} phase_log;
static void reduce_phase(const char *phase, void *user) {
  phase_log *pl = (phase_log *)user;
  const double t = now_s() - pl->t0;
  int k = 0;
  pl->last = phase;
  if (pl->quiet) return;
  if (strcmp(phase, "lambda: candidate") == 0) k = ++pl->ncand;
  if (strcmp(phase, "lambda: full-model probe run") == 0) k = ++pl->nprobe;
  if (strcmp(phase, "done") == 0 || (!pl->all && t < 1.0)) return;
  /* stages that do nothing for this model are not shown: the manifold is
     gmg-qm's, the hyper-reduction needs a hyper-reduced nonlinear part */
  if ((!pl->qm && !strcmp(phase, "manifold")) || (!pl->hyper && !strcmp(phase, "hyper-reduction"))) return;
  if (k) progress("  ... %s %d (%.1f s)", phase, k, t);
  else progress("  ... %s (%.1f s)", phase, t);
}

/* Error on stderr; returns the exit status 1 for `return fail(...)`. */
static int fail(const char *fmt, ...) {
  va_list ap;
  fputs("phgmg: error: ", stderr);
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
  return 1;
}

/* Usage error: status 2. */
static int usage_error(const char *fmt, ...) {
  va_list ap;
  fputs("phgmg: ", stderr);
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputs("\n(run 'phgmg --help' for the options)\n", stderr);
  return 2;
}

/* ---- option values ------------------------------------------------------------ */
static int parse_int(const char *opt, const char *s, int lo, int hi, int *out) {
  char *end;
  long v;
  errno = 0;
  v = strtol(s, &end, 10);
  if (errno || end == s || *end || v < lo || v > hi) {
    usage_error("%s: expected an integer in [%d, %d], got '%s'", opt, lo, hi, s);
    return 0;
  }
  *out = (int)v;
  return 1;
}
static int parse_double(const char *opt, const char *s, double lo, double *out) {
  char *end;
  double v;
  errno = 0;
  v = strtod(s, &end);
  if (end != s && !*end && errno == ERANGE) { /* a number, but out of the double range */
    if (fabs(v) <= DBL_MIN)
      usage_error("%s: '%s' is too small in magnitude for a normal double (0 or at least %g)", opt, s,
                  DBL_MIN);
    else
      usage_error("%s: '%s' is too large for a double (at most %g)", opt, s, DBL_MAX);
    return 0;
  }
  if (errno || end == s || *end || !isfinite(v) || v < lo) {
    if (lo == -HUGE_VAL) usage_error("%s: expected a finite number, got '%s'", opt, s);
    else usage_error("%s: expected a finite number >= %g, got '%s'", opt, lo, s);
    return 0;
  }
  *out = v;
  return 1;
}

/* A value the reduced model's scalar type holds: the float build's online
   path (simulate-rom, the step map) is float, so 0 or a normal float. 0, or
   1 after a usage message. */
static int real_bad(const char *opt, const char *s, double v) {
#ifdef PHGMG_REAL_FLOAT
  if (v != 0.0 && !(fabs(v) >= (double)FLT_MIN && fabs(v) <= (double)FLT_MAX)) {
    usage_error("%s: '%s' is not representable in float, the scalar type of this build's reduced model (0 or "
                "%g <= |x| <= %g)", opt, s, (double)FLT_MIN, (double)FLT_MAX);
    return 1;
  }
#else
  (void)opt; (void)s; (void)v;
#endif
  return 0;
}

/* Each option once: 1 (after a usage message) if o was seen before in this
   command line. seen[] holds up to 64 names. */
static int repeated_opt(const char *o, const char **seen, int *nseen) {
  int k;
  for (k = 0; k < *nseen; ++k)
    if (!strcmp(seen[k], o)) {
      usage_error("%s given more than once (each option may be given once)", o);
      return 1;
    }
  if (*nseen < 64) seen[(*nseen)++] = o;
  return 0;
}

/* The largest total of arrays a run may allocate up front. */
#define CLI_MAX_BYTES (4.0 * 1024.0 * 1024.0 * 1024.0)

/* 1 (after a message) if count doubles exceed CLI_MAX_BYTES. */
static int too_big(double count, const char *what) {
  if (8.0 * count <= CLI_MAX_BYTES) return 0;
  usage_error("%s would need %.3g GB (limit %.3g GB); use fewer --steps", what, 8.0 * count / 1e9,
              CLI_MAX_BYTES / 1e9);
  return 1;
}

/* ---- matrices from .npy ----------------------------------------------------- */
typedef struct mat {
  double *a; /* column-major rows x cols */
  int rows, cols, ndim;
  const char *path;
} mat;

static void mat_free(mat *m) {
  phgmg_npy_free(m->a, NULL);
  m->a = NULL;
}

/* Read path into *m: a clear message naming the file (and the option it came
   from) on failure. */
/* The dtype string of a .npy file's header ("?" if not found), for messages. */
static const char *npy_dtype_of(const char *path) {
  static char d[32];
  char head[4096], *p, *e;
  size_t n;
  FILE *f = fopen(path, "rb");
  strcpy(d, "?");
  if (!f) return d;
  n = fread(head, 1, sizeof head - 1, f);
  fclose(f);
  head[n] = '\0';
  if (n < 12) return d;
  p = strstr(head + (head[6] == 1 ? 10 : 12), "descr"); /* the header text */
  if (p) p = strchr(p, ':');
  if (!p) return d;
  p += 1 + strspn(p + 1, " ");
  if (*p != '\'' && *p != '"') { snprintf(d, sizeof d, "%.20s...", p); return d; }
  e = strchr(p + 1, *p);
  if (e && e - p - 1 < (long)sizeof d) { memcpy(d, p + 1, (size_t)(e - p - 1)); d[e - p - 1] = '\0'; }
  return d;
}

/* 1 (after a message naming the option) if path is a directory. */
static int is_dir(const char *path, const char *opt) {
  struct stat st;
  if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
    fail("%s (%s): cannot read: is a directory (I/O error)", path, opt);
    return 1;
  }
  return 0;
}

static int mat_load(mat *m, const char *opt, const char *path) {
  phgmg_result rc;
  FILE *f;
  size_t i, n;
  memset(m, 0, sizeof *m);
  m->path = path;
  if (!*path) return usage_error("%s: empty file name", opt);
  if (is_dir(path, opt)) return 1;
  f = fopen(path, "rb");
  if (!f) return fail("%s (%s): cannot open: %s", path, opt, strerror(errno));
  fclose(f);
  rc = phgmg_npy_read(path, &m->a, &m->rows, &m->cols, &m->ndim, NULL);
  if (rc == PHGMG_ERR_FORMAT)
    return fail("%s (%s): not a readable .npy array: %s (float64/float32/integer/bool, at most 2-d, "
                "format 1.0-3.0)", path, opt, phgmg_result_string(rc));
  if (rc == PHGMG_ERR_DTYPE)
    return fail("%s (%s): dtype '%s' is not supported (float64, float32, int8-int64, uint8-uint64 "
                "or bool)", path, opt, npy_dtype_of(path));
  if (rc == PHGMG_ERR_INEXACT)
    return fail("%s (%s): dtype '%s': a value beyond 2^53 in magnitude, which a double cannot "
                "hold exactly", path, opt, npy_dtype_of(path));
  if (rc != PHGMG_OK) return fail("%s (%s): %s", path, opt, phgmg_result_string(rc));
  n = (size_t)m->rows * (size_t)m->cols;
  for (i = 0; i < n; ++i)
    if (!isfinite(m->a[i])) {
      int r = (int)(i % (size_t)m->rows), c = (int)(i / (size_t)m->rows);
      fail("%s (%s): NaN or Inf at element (%d, %d)", path, opt, r, c);
      mat_free(m);
      return 1;
    }
  return 0;
}

/* "shape (100, 99)" / "shape (100,)" / "shape ()" of a loaded array. */
static const char *shape_str(const mat *m) {
  static char buf[64];
  if (m->ndim == 0) snprintf(buf, sizeof buf, "shape ()");
  else if (m->ndim == 1) snprintf(buf, sizeof buf, "shape (%d,)", m->rows);
  else snprintf(buf, sizeof buf, "shape (%d, %d)", m->rows, m->cols);
  return buf;
}

static int is_vector(const mat *m) { return m->ndim <= 1 || m->rows == 1 || m->cols == 1; }

/* ---- the input signal ------------------------------------------------------- */
enum { IN_SIN = 0, IN_CONST = 1, IN_TABLE = 2, IN_GRID = 3, IN_CHIRP = 4 };
/* --freq W (angular frequency of sin and the chirp's start, rad per unit of
   time; default 1) and --freq-end W1 (the chirp's end; 0: 10 W). */
static double g_freq = 1.0, g_freq_end = 0.0;
typedef struct cli_input {
  int kind, m;
  double amp;
  double w0, w1, T;   /* sin: w0; chirp: from w0 to w1 over the run's length T */
  mat tab;        /* IN_TABLE: K x (1+m); IN_GRID: K samples on t = k*grid_dt */
  double grid_dt;
  /* progress of a long simulation, reported from the input callback */
  int report;
  double t_end, wall0, wall_last;
} cli_input;

static void table_eval(const cli_input *in, double t, double *u) {
  const mat *T = &in->tab;
  const int K = in->kind == IN_GRID ? T->rows * T->cols : T->rows;
  int lo = 0, hi = K - 1, a;
  double t_lo, t_hi, s;
#define TIME(k) (in->kind == IN_GRID ? (double)(k) * in->grid_dt : T->a[(k)])
#define VAL(k, a) (in->kind == IN_GRID ? T->a[(k)] : T->a[(k) + (size_t)((a) + 1) * (size_t)K])
  if (K == 1 || t <= TIME(0)) { for (a = 0; a < in->m; ++a) u[a] = VAL(0, a); return; }
  if (t >= TIME(K - 1)) { for (a = 0; a < in->m; ++a) u[a] = VAL(K - 1, a); return; }
  while (hi - lo > 1) { /* TIME(lo) <= t < TIME(hi) */
    const int mid = lo + (hi - lo) / 2;
    if (TIME(mid) <= t) lo = mid; else hi = mid;
  }
  t_lo = TIME(lo); t_hi = TIME(hi);
  s = (t - t_lo) / (t_hi - t_lo);
  for (a = 0; a < in->m; ++a) u[a] = VAL(lo, a) + s * (VAL(hi, a) - VAL(lo, a));
#undef TIME
#undef VAL
}

static void input_fn(double t, double *u, void *user) {
  cli_input *in = (cli_input *)user;
  int a;
  switch (in->kind) {
    case IN_SIN: /* port a: its own frequency w (1 + a/m), so that the ports are excited independently */
      for (a = 0; a < in->m; ++a) u[a] = in->amp * sin(in->w0 * (1.0 + (double)a / in->m) * t);
      break;
    case IN_CHIRP: { /* a linear chirp w(t) = w0 + (w1 - w0) t / T, held at w1 after T; port a scaled by 1 + a/m */
      const double tc = t < in->T ? t : in->T;
      const double ph = in->w0 * tc + 0.5 * (in->w1 - in->w0) * tc * tc / (in->T > 0.0 ? in->T : 1.0) +
                        in->w1 * (t - tc);
      for (a = 0; a < in->m; ++a) u[a] = in->amp * sin((1.0 + (double)a / in->m) * ph);
      break;
    }
    case IN_CONST: for (a = 0; a < in->m; ++a) u[a] = in->amp; break;
    default: table_eval(in, t, u); break;
  }
  if (in->report) { /* at most one progress line every 2 s */
    const double w = now_s();
    if (w - in->wall_last >= 2.0) {
      in->wall_last = w;
      progress("  ... t = %g of %g (%.0f%%, %.1f s)", t, in->t_end,
               in->t_end > 0.0 ? 100.0 * t / in->t_end : 100.0, w - in->wall0);
    }
  }
}

/* Set up the input from --input/--amp for m ports and step dt. Returns 0, or
   the exit status after a message (2: neither a kind nor an existing file). */
static int input_setup(cli_input *in, const char *opt, const char *spec, double amp, int m, double dt, double T) {
  struct stat st;
  const size_t l = strlen(spec);
  memset(in, 0, sizeof *in);
  in->m = m;
  in->amp = amp;
  in->grid_dt = dt;
  in->w0 = g_freq;
  in->w1 = g_freq_end > 0.0 ? g_freq_end : 10.0 * g_freq;
  in->T = T;
  if (!strcmp(spec, "sin")) { in->kind = IN_SIN; return 0; }
  if (!strcmp(spec, "chirp")) { in->kind = IN_CHIRP; return 0; }
  if (!strcmp(spec, "const")) { in->kind = IN_CONST; return 0; }
  if (stat(spec, &st) != 0 && (l < 4 || strcmp(spec + l - 4, ".npy") != 0))
    return usage_error("%s '%s': expected sin, chirp, const or a FILE.npy, and there is no file '%s'", opt, spec, spec);
  if (mat_load(&in->tab, opt, spec)) return 1;
  if (in->tab.ndim == 2 && !(m == 1 && in->tab.cols == 1)) {
    int k;
    if (in->tab.cols != 1 + m || in->tab.rows < 1) {
      fail("%s (%s): expected a table of shape (K, %d) (times, then %d input%s), got %s",
           spec, opt, 1 + m, m, m > 1 ? "s" : "", shape_str(&in->tab));
      mat_free(&in->tab);
      return 1;
    }
    for (k = 1; k < in->tab.rows; ++k)
      if (!(in->tab.a[k] > in->tab.a[k - 1])) {
        fail("%s (%s): the times in column 0 must increase strictly (row %d: %g after %g)",
             spec, opt, k, in->tab.a[k], in->tab.a[k - 1]);
        mat_free(&in->tab);
        return 1;
      }
    in->kind = IN_TABLE;
    return 0;
  }
  if (m != 1 || in->tab.rows * in->tab.cols < 1) {
    fail("%s (%s): a vector of samples needs a model with one input (m = %d) and at least "
         "one sample; for m > 1 give a table of shape (K, %d); got %s",
         spec, opt, m, 1 + m, shape_str(&in->tab));
    mat_free(&in->tab);
    return 1;
  }
  in->kind = IN_GRID;
  return 0;
}

static const char *input_desc(const cli_input *in, const char *spec) {
  static char buf[600];
  if (in->kind == IN_SIN && in->m > 1 && in->w0 == 1.0)
    snprintf(buf, sizeof buf, "u_a(t) = %g sin((1 + a/%d) t) at port a = 0..%d", in->amp, in->m, in->m - 1);
  else if (in->kind == IN_SIN && in->m > 1)
    snprintf(buf, sizeof buf, "u_a(t) = %g sin(%g (1 + a/%d) t) at port a = 0..%d", in->amp, in->w0, in->m, in->m - 1);
  else if (in->kind == IN_SIN && in->w0 == 1.0) snprintf(buf, sizeof buf, "u(t) = %g sin(t)", in->amp);
  else if (in->kind == IN_SIN) snprintf(buf, sizeof buf, "u(t) = %g sin(%g t)", in->amp, in->w0);
  else if (in->kind == IN_CHIRP)
    snprintf(buf, sizeof buf, "u(t) = %g sin(phase), a linear chirp from %g to %g rad per unit time over t in [0, %g]%s",
             in->amp, in->w0, in->w1, in->T, in->m > 1 ? " (port a: phase times 1 + a/m)" : "");
  else if (in->kind == IN_CONST) snprintf(buf, sizeof buf, "u(t) = %g", in->amp);
  else snprintf(buf, sizeof buf, "u(t) from %s", spec);
  return buf;
}

/* A warning on stderr, also with --quiet. */
static void note(const char *fmt, ...) {
  va_list ap;
  fputs("phgmg: note: ", stderr);
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
}

/* The Newton tolerance a full-model simulation used, in the log: for a
   nonlinear model or dampers (a linear model's stage systems are solved to
   round-off in one update), with the way to tighten it. */
static void progress_newton_tol(const phgmg_ph_system *sys, double tol, const phgmg_gl3_stats *st) {
  if (sys->nl == PHGMG_NL_NONE && sys->ndamp == 0) return;
  if (tol > 0.0)
    progress("  Newton tolerance %g (absolute, --newton-tol); largest final stage residual %.2g", tol,
             st->max_residual);
  else
    progress("  Newton tolerance: the default, 1e-10 x max(1, |x|, |stage increment|) per step (largest final "
             "stage residual %.2g); for a reference accurate to about 1e-10 give --newton-tol about 1e-13 "
             "times the states' size", st->max_residual);
}

/* Say so when an input file ends before a run of length t_end: past its last
   time it is held at its last value. */
static void input_covers(const cli_input *in, const char *spec, const char *opt, double t_end) {
  double last;
  if (in->kind == IN_TABLE) last = in->tab.a[in->tab.rows - 1];
  else if (in->kind == IN_GRID) last = (double)(in->tab.rows * in->tab.cols - 1) * in->grid_dt;
  else return;
  if (last < t_end * (1.0 - 1e-12))
    note("%s (%s) ends at t = %g, the run at t = %g: from t = %g on, the input is held at its last value",
         spec, opt, last, t_end, last);
}

/* 1 if the input drives every port with the same signal (m > 1): const, or
   a table whose input columns are equal. */
static int input_same_on_ports(const cli_input *in) {
  int k, a;
  if (in->m < 2) return 0;
  if (in->kind == IN_CONST) return 1;
  if (in->kind != IN_TABLE) return 0;
  for (a = 2; a <= in->m; ++a)
    for (k = 0; k < in->tab.rows; ++k)
      if (in->tab.a[k + (size_t)a * in->tab.rows] != in->tab.a[k + (size_t)in->tab.rows]) return 0;
  return 1;
}

/* Say so when no training run excites the m > 1 ports independently. */
static void note_ports(const cli_input *const *ins, int n, int m) {
  int k;
  if (m < 2 || n < 1) return;
  for (k = 0; k < n; ++k)
    if (!input_same_on_ports(ins[k])) return;
  note("every training run drives all %d ports with the same signal: the ports are not excited independently "
       "(the snapshots cannot tell them apart; GMG may fail or the model may not follow other inputs). "
       "Use the default sin (one frequency per port) or a table with a column per port", m);
}

/* ---- files ---------------------------------------------------------------- */
/* ---- file identity: a run never writes or removes one of its inputs ----------
   Paths are compared by the file they name, not by their spelling: an existing
   file by (st_dev, st_ino) (hard links, symbolic links, "./a" and "a" are one
   file); a file not yet there by its directory's identity and its base name;
   below a directory not yet there by the absolute path with "." and ".."
   folded. */
typedef struct file_id {
  int kind;        /* 1 the file exists, 2 its directory exists, 3 neither */
  dev_t dev;
  ino_t ino;
  char *s;         /* kind 2: the base name; kind 3: the folded absolute path */
} file_id;

/* The absolute path with "//", "." and ".." folded, into out (cap bytes). */
static void path_fold(const char *path, char *out, size_t cap) {
  char buf[8192];
  size_t n = 0, k;
  const char *p;
  buf[0] = '\0';
  if (path[0] != '/' && (!getcwd(buf, sizeof buf - 1) || strlen(buf) + strlen(path) + 2 >= sizeof buf)) buf[0] = '\0';
  if (strlen(buf) + strlen(path) + 2 < sizeof buf) { strcat(buf, "/"); strcat(buf, path); }
  out[0] = '\0';
  for (p = buf; *p;) {
    size_t l;
    while (*p == '/') ++p;
    l = strcspn(p, "/");
    if (l == 0) break;
    if (l == 1 && p[0] == '.') { p += l; continue; }
    if (l == 2 && p[0] == '.' && p[1] == '.') {
      for (k = n; k > 0 && out[k - 1] != '/'; --k) {}
      n = k > 0 ? k - 1 : 0;
      out[n] = '\0';
      p += l;
      continue;
    }
    if (n + l + 2 >= cap) break;
    out[n++] = '/';
    memcpy(out + n, p, l);
    n += l;
    out[n] = '\0';
    p += l;
  }
  if (n == 0 && cap > 1) { out[0] = '/'; out[1] = '\0'; }
}

static void file_id_make(const char *path, file_id *f);

/* A symbolic link whose target does not exist yet: its target (relative to
   the link's directory), into out; 0 if path is not such a link. */
static int dangling_target(const char *path, char *out, size_t cap) {
  struct stat st;
  char t[4096];
  const char *sl = strrchr(path, '/');
  ssize_t n;
  if (lstat(path, &st) != 0 || !S_ISLNK(st.st_mode) || stat(path, &st) == 0) return 0;
  n = readlink(path, t, sizeof t - 1);
  if (n <= 0) return 0;
  t[n] = '\0';
  if (t[0] == '/' || !sl) snprintf(out, cap, "%s", t);
  else snprintf(out, cap, "%.*s/%s", (int)(sl - path), path, t);
  return 1;
}

/* file_id_make, following up to 16 dangling links to the file they will create. */
static void file_id_follow(const char *path, file_id *f, int depth) {
  char t[8192];
  if (depth < 16 && dangling_target(path, t, sizeof t)) file_id_follow(t, f, depth + 1);
  else file_id_make(path, f);
}

static void file_id_make(const char *path, file_id *f) {
  struct stat st;
  const char *sl = strrchr(path, '/');
  const char *base = sl ? sl + 1 : path;
  char dir[4096];
  memset(f, 0, sizeof *f);
  if (stat(path, &st) == 0) { f->kind = 1; f->dev = st.st_dev; f->ino = st.st_ino; return; }
  if (sl && (size_t)(sl - path) >= sizeof dir) sl = NULL, base = "";
  if (sl == path) strcpy(dir, "/");
  else if (sl) { memcpy(dir, path, (size_t)(sl - path)); dir[sl - path] = '\0'; }
  else strcpy(dir, ".");
  if (*base && strcmp(base, ".") && strcmp(base, "..") && stat(dir, &st) == 0 && S_ISDIR(st.st_mode)) {
    f->kind = 2; f->dev = st.st_dev; f->ino = st.st_ino;
    f->s = (char *)malloc(strlen(base) + 1);
    if (f->s) strcpy(f->s, base);
    return;
  }
  f->kind = 3;
  f->s = (char *)malloc(8192);
  if (f->s) path_fold(path, f->s, 8192);
}

static int file_id_same(const file_id *a, const file_id *b) {
  if (a->kind != b->kind) return 0;
  if (a->kind == 3) return a->s && b->s && !strcmp(a->s, b->s);
  if (a->dev != b->dev || a->ino != b->ino) return 0;
  return a->kind == 1 || (a->s && b->s && !strcmp(a->s, b->s));
}

/* A list of paths with the options they came from (copies). */
#define PATHS_MAX 2400
typedef struct pathset {
  char *path[PATHS_MAX];
  const char *opt[PATHS_MAX];
  file_id id[PATHS_MAX];
  int n;
} pathset;

static void paths_free(pathset *ps) {
  int k;
  for (k = 0; k < ps->n; ++k) { free(ps->path[k]); free(ps->id[k].s); }
  ps->n = 0;
}

/* Add path (and, with tmp, the temporary name path.tmp a staged write uses). */
static void paths_add(pathset *ps, const char *opt, const char *path, int tmp) {
  int t;
  for (t = 0; t <= tmp && ps->n < PATHS_MAX; ++t) {
    const size_t l = strlen(path);
    char *c = (char *)malloc(l + 5);
    if (!c) return;
    memcpy(c, path, l + 1);
    if (t) memcpy(c + l, ".tmp", 5);
    ps->path[ps->n] = c;
    ps->opt[ps->n] = opt;
    file_id_follow(c, &ps->id[ps->n], 0);
    ps->n++;
  }
}

/* An input spec that may be a file: anything but the input kinds sin, const. */
static void paths_add_input(pathset *ps, const char *opt, const char *spec) {
  if (spec && strcmp(spec, "sin") && strcmp(spec, "const") && strcmp(spec, "chirp")) paths_add(ps, opt, spec, 0);
}

/* The index in ps of the file path names, -1 if none. */
static int paths_find(const pathset *ps, const char *path) {
  file_id f;
  int k, hit = -1;
  file_id_follow(path, &f, 0);
  for (k = 0; k < ps->n && hit < 0; ++k)
    if (file_id_same(&f, &ps->id[k])) hit = k;
  free(f.s);
  return hit;
}

/* The inputs of the running command: stage_path refuses to write one, the
   removal of an earlier run's arrays skips them. */
static const pathset *g_inputs = NULL;

/* Up front: no output may be an input or another output of the same run.
   Returns 0, or the usage status 2 after a message. */
static int check_collisions(const char *cmd, const pathset *in, const pathset *out) {
  int i, k;
  for (i = 0; i < out->n; ++i) {
    for (k = 0; k < in->n; ++k)
      if (file_id_same(&out->id[i], &in->id[k]))
        return usage_error("%s: the output %s (%s) is one of the input files, %s (%s): a run never overwrites "
                           "its inputs; choose another output name", cmd, out->path[i], out->opt[i], in->path[k], in->opt[k]);
    for (k = 0; k < i; ++k)
      if (file_id_same(&out->id[i], &out->id[k]))
        return usage_error("%s: %s (%s) and %s (%s) are the same file; give each output its own name", cmd,
                           out->path[k], out->opt[k], out->path[i], out->opt[i]);
  }
  return 0;
}

/* Can a file be created in the existing directory dir? Tried, not asked
   (access() says yes to root where nothing can be written, e.g. /proc): a
   probe file of a name no one uses is created and removed again. 0, or
   errno. */
static int probe_dir(const char *dir) {
  char p[4096 + 64];
  int k, fd;
  for (k = 0; k < 100; ++k) {
    snprintf(p, sizeof p, "%s/.phgmg-probe-%ld-%d", dir, (long)getpid(), k);
    fd = open(p, O_WRONLY | O_CREAT | O_EXCL, 0600);
    if (fd >= 0) { close(fd); unlink(p); return 0; }
    if (errno != EEXIST) return errno;
  }
  return EEXIST;
}

/* Up front: can files be created in dir (its missing parents permitting,
   create = 1)? 0, or 1 after a message naming opt and path. */
static int check_writable_dir(const char *dir, const char *opt, const char *path, int create) {
  char buf[4096];
  struct stat st;
  size_t n = strlen(dir);
  int e;
  if (n == 0 || n >= sizeof buf) return fail("%s (%s): bad directory name", path, opt);
  memcpy(buf, dir, n + 1);
  for (;;) {
    if (stat(buf, &st) == 0) {
      if (!S_ISDIR(st.st_mode))
        return fail("%s (%s): cannot write there: %s is not a directory", path, opt, buf);
      if ((e = probe_dir(buf)) != 0) return fail("%s (%s): cannot write in %s: %s", path, opt, buf, strerror(e));
      return 0;
    }
    if (errno != ENOENT) return fail("%s (%s): cannot use %s: %s", path, opt, buf, strerror(errno));
    if (!create) return fail("%s (%s): cannot write: the directory %s does not exist", path, opt, buf);
    if (!strcmp(buf, ".")) return fail("%s (%s): the working directory is gone", path, opt);
    while (n > 1 && buf[n - 1] == '/') buf[--n] = '\0'; /* to the parent: drop the last component */
    while (n > 0 && buf[n - 1] != '/') buf[--n] = '\0';
    while (n > 1 && buf[n - 1] == '/') buf[--n] = '\0';
    if (n == 0) { strcpy(buf, "."); n = 1; }
  }
}

/* An output file path: its directory must exist and be writable, and the path
   must not be a directory. 0, or 1 after a message. */
static int check_out_file(const char *path, const char *opt) {
  char dir[4096];
  const char *sl = strrchr(path, '/');
  struct stat st;
  if (!*path) return fail("'' (%s): empty file name", opt);
  if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) return fail("%s (%s): cannot write: is a directory", path, opt);
  if (!sl) strcpy(dir, ".");
  else if (sl == path) strcpy(dir, "/");
  else if ((size_t)(sl - path) < sizeof dir) { memcpy(dir, path, (size_t)(sl - path)); dir[sl - path] = '\0'; }
  else return fail("%s (%s): path too long", path, opt);
  return check_writable_dir(dir, opt, path, 0);
}

/* All or none: every output of a run is written under a temporary name
   (FINAL.tmp) and renamed to its final name only when all were written
   (stage_commit); after a failure stage_abort removes the temporary files, so
   the outputs of an earlier run stay as they were. An existing final path
   that is not a regular file (a device, a pipe, a symbolic link) is written
   directly, as the user asked. */
typedef struct staged {
  char *fin[64], *tmp[64];
  int n;
  char *made[32];  /* directories this run created (mkdir_p), removed again if empty after a failure */
  int nmade;
} staged;

static void stage_free(staged *sg, int remove_tmp) {
  int k;
  for (k = 0; k < sg->n; ++k) {
    if (remove_tmp) remove(sg->tmp[k]);
    free(sg->fin[k]);
    free(sg->tmp[k]);
  }
  sg->n = 0;
  for (k = sg->nmade - 1; k >= 0; --k) {
    if (remove_tmp) rmdir(sg->made[k]); /* only if empty */
    free(sg->made[k]);
  }
  sg->nmade = 0;
}

/* After a failure: the temporary files and the directories made go. */
static void stage_abort(staged *sg) { stage_free(sg, 1); }

/* Create dir and its missing parents (noted in sg). */
static int mkdir_p(const char *dir, staged *sg) {
  char buf[4096];
  size_t n = strlen(dir), i;
  struct stat st;
  if (n == 0 || n >= sizeof buf) return fail("%s (--out): bad directory name", dir);
  memcpy(buf, dir, n + 1);
  for (i = 1; i <= n; ++i) {
    if (buf[i] == '/' || buf[i] == '\0') {
      const char c = buf[i];
      buf[i] = '\0';
      if (mkdir(buf, 0777) == 0) {
        if (sg->nmade < 32 && (sg->made[sg->nmade] = (char *)malloc(i + 1)) != NULL) memcpy(sg->made[sg->nmade++], buf, i + 1);
      } else if (errno != EEXIST) {
        return fail("%s (--out): cannot create directory %s: %s", dir, buf, strerror(errno));
      }
      buf[i] = c;
    }
  }
  if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) return fail("%s (--out): not a directory", dir);
  return 0;
}

/* The path to write for the output `path` (NULL after a message). */
static const char *stage_path(staged *sg, const char *path) {
  struct stat st;
  const size_t l = strlen(path);
  if (g_inputs) { /* the last guard; the outputs were checked against the inputs up front */
    char tmp[4096 + 260];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    if (paths_find(g_inputs, path) >= 0 || paths_find(g_inputs, tmp) >= 0) {
      fail("%s: not written: it is an input of this run", path);
      return NULL;
    }
  }
  if (lstat(path, &st) == 0) {
    if (S_ISDIR(st.st_mode)) { fail("%s: cannot write: is a directory", path); return NULL; }
    if (!S_ISREG(st.st_mode)) return path;
  }
  if (sg->n == 64) { fail("%s: too many outputs", path); return NULL; }
  sg->fin[sg->n] = (char *)malloc(l + 1);
  sg->tmp[sg->n] = (char *)malloc(l + 5);
  if (!sg->fin[sg->n] || !sg->tmp[sg->n]) {
    free(sg->fin[sg->n]); free(sg->tmp[sg->n]);
    fail("out of memory");
    return NULL;
  }
  memcpy(sg->fin[sg->n], path, l + 1);
  memcpy(sg->tmp[sg->n], path, l);
  memcpy(sg->tmp[sg->n] + l, ".tmp", 5);
  return sg->tmp[sg->n++];
}

/* Rename every staged file to its final name; 1 after a message on failure
   (the files not yet renamed are removed). */
static int stage_commit(staged *sg) {
  int k;
  for (k = 0; k < sg->n; ++k)
    if (rename(sg->tmp[k], sg->fin[k]) != 0) {
      fail("%s: cannot rename %s into place: %s", sg->fin[k], sg->tmp[k], strerror(errno));
      stage_free(sg, 1); /* removes the files not yet renamed, frees the names */
      return 1;
    }
  stage_free(sg, 0); /* frees the names; the temporary files are gone, the directories stay */
  return 0;
}

/* Write a rows x cols column-major array (ndim 2) and note it in the JSON file list. */
typedef struct outlist {
  char names[48][64];
  int rows[48], cols[48], n;
} outlist;

/* Write to wp (the staged name) the output shown to the user as path. */
static int write_npy(const char *path, const char *wp, const double *A, int rows, int cols, int ndim) {
  phgmg_result rc = phgmg_npy_write(wp, A, rows, cols, rows > 0 ? rows : 1, ndim, 0u);
  if (rc != PHGMG_OK) return fail("%s: cannot write: %s (%s)", path, phgmg_result_string(rc), strerror(errno));
  return 0;
}

static int write_field(const char *dir, const char *name, const char *field, const double *A,
                       int rows, int cols, outlist *ol, staged *sg) {
  char path[4096 + 256];
  const char *wp;
  snprintf(path, sizeof path, "%s/%s_%s.npy", dir, name, field);
  if (!(wp = stage_path(sg, path)) || write_npy(path, wp, A, rows, cols, 2)) return 1;
  if (ol->n < 48) {
    snprintf(ol->names[ol->n], sizeof ol->names[0], "%s_%s.npy", name, field);
    ol->rows[ol->n] = rows; ol->cols[ol->n] = cols; ol->n++;
  }
  return 0;
}

/* The arrays of a phgmg_rom with their matrix shapes (phgmg.h >>online). */
typedef struct rom_field { const char *name; const phgmg_real *a; int rows, cols; } rom_field;
static int rom_fields(const phgmg_rom *rom, rom_field *f) {
  const int r = rom->r, m = rom->m, rn = rom->rn, nd = rom->nd, p = rom->r - rom->m;
  int n = 0;
#define FIELD(nm, ptr, rr, cc) do { if ((ptr) && (rr) > 0 && (cc) > 0) { \
      f[n].name = nm; f[n].a = ptr; f[n].rows = rr; f[n].cols = cc; ++n; } } while (0)
  FIELD("Bh", rom->Bh, r, m);
  FIELD("Qh", rom->Qh, r, r);
  FIELD("K", rom->K, r, r);
  if (rom->kind == PHGMG_ROM_QUADRATIC) {
    FIELD("G00", rom->G00, r, r);
    FIELD("G01", rom->G01, r, rn);
    FIELD("G10", rom->G10, rn, r);
    FIELD("G11", rom->G11, rn, rn);
    FIELD("Q01", rom->Q01, r, rn);
    FIELD("Q11", rom->Q11, rn, rn);
    FIELD("Ms", rom->Ms, rn, p * p);
  }
  if (nd > 0) {
    FIELD("P0", rom->P0, nd, r);
    if (rom->kind == PHGMG_ROM_QUADRATIC) FIELD("P1", rom->P1, nd, rn);
    FIELD("w", rom->w, nd, 1);
    FIELD("poly", rom->poly, rom->nphi > 1 ? rom->nphi : 1, rom->poly_deg + 1);
    if (rom->nexp) FIELD("expo", rom->expo, rom->nphi > 1 ? rom->nphi : 1, 2 * rom->nexp);
  }
  FIELD("Phi", rom->Phi, r, r);
  FIELD("Gam", rom->Gam, r, 3 * m);
  FIELD("SX", rom->SX, 3 * r, r);
  FIELD("SU", rom->SU, 3 * r, 3 * m);
#undef FIELD
  return n;
}

static void json_str(FILE *f, const char *s) {
  fputc('"', f);
  for (; *s; ++s) {
    const unsigned char c = (unsigned char)*s;
    if (c == '"' || c == '\\') fprintf(f, "\\%c", c);
    else if (c < 0x20) fprintf(f, "\\u%04x", c);
    else fputc(c, f);
  }
  fputc('"', f);
}
/* v as the shortest of %.15g..%.17g that reads back exactly (buf: 32 chars). */
static const char *num_str(double v, char *buf) {
  int prec;
  for (prec = 15; prec < 17; ++prec) {
    snprintf(buf, 32, "%.*g", prec, v);
    if (strtod(buf, NULL) == v) return buf;
  }
  snprintf(buf, 32, "%.17g", v);
  return buf;
}
/* v as the shortest %.6g..%.9g that reads back exactly as the scalar type of
   the build (float: 0.1f is "0.1", not 0.10000000149011612). */
static const char *real_str(phgmg_real v, char *buf) {
  int prec;
  if (sizeof(phgmg_real) == sizeof(double)) return num_str((double)v, buf);
  for (prec = 6; prec < 9; ++prec) {
    snprintf(buf, 32, "%.*g", prec, (double)v);
    if ((phgmg_real)strtod(buf, NULL) == v) return buf;
  }
  snprintf(buf, 32, "%.9g", (double)v);
  return buf;
}
/* A JSON number; null for NaN/Inf. */
static void json_num(FILE *f, double v) {
  char buf[32];
  fputs(isfinite(v) ? num_str(v, buf) : "null", f);
}

/* Identifiers the exported C source (NAME, NAME_<field>) must not take: C
   (C89-C23) and C++ keywords, and names the C library headers that phgmg.h
   includes (math.h, string.h, stdlib.h, stdio.h, stdint.h, limits.h,
   assert.h, stddef.h, float.h) declare or define. */
static const char *const reserved_kw[] = {
  /* C keywords */
  "auto", "break", "case", "char", "const", "continue", "default", "do", "double", "else", "enum",
  "extern", "float", "for", "goto", "if", "inline", "int", "long", "register", "restrict", "return",
  "short", "signed", "sizeof", "static", "struct", "switch", "typedef", "union", "unsigned", "void",
  "volatile", "while", "bool", "true", "false", "alignas", "alignof", "constexpr", "nullptr",
  "static_assert", "thread_local", "typeof", "typeof_unqual",
  /* C++ keywords */
  "and", "and_eq", "asm", "bitand", "bitor", "catch", "char8_t", "char16_t", "char32_t", "class",
  "compl", "concept", "consteval", "constinit", "const_cast", "co_await", "co_return", "co_yield",
  "decltype", "delete", "dynamic_cast", "explicit", "export", "friend", "mutable", "namespace", "new",
  "noexcept", "not", "not_eq", "operator", "or", "or_eq", "private", "protected", "public",
  "reinterpret_cast", "requires", "static_cast", "template", "this", "throw", "try", "typeid",
  "typename", "using", "virtual", "wchar_t", "xor", "xor_eq",
  /* library types and macros */
  "size_t", "ptrdiff_t", "max_align_t", "wint_t", "FILE", "fpos_t", "div_t", "ldiv_t", "lldiv_t",
  "float_t", "double_t", "int8_t", "int16_t", "int32_t", "int64_t", "uint8_t", "uint16_t", "uint32_t",
  "uint64_t", "intptr_t", "uintptr_t", "intmax_t", "uintmax_t", "NULL", "EOF", "BUFSIZ", "stdin",
  "stdout", "stderr", "errno", "assert", "offsetof", "INFINITY", "NAN", "HUGE_VAL", "HUGE_VALF",
  "HUGE_VALL", "EXIT_SUCCESS", "EXIT_FAILURE", "RAND_MAX", "MB_CUR_MAX", "SEEK_SET", "SEEK_CUR",
  "SEEK_END", "TMP_MAX", "FILENAME_MAX", "FOPEN_MAX", "L_tmpnam", "CHAR_BIT", "NDEBUG",
  NULL};
static const char *const math_names[] = { /* math.h (also with the suffixes f and l) */
  "acos", "asin", "atan", "atan2", "cos", "sin", "tan", "acosh", "asinh", "atanh", "cosh", "sinh",
  "tanh", "exp", "exp2", "expm1", "frexp", "ilogb", "ldexp", "log", "log10", "log1p", "log2", "logb",
  "modf", "scalbn", "scalbln", "cbrt", "fabs", "hypot", "pow", "sqrt", "erf", "erfc", "lgamma",
  "tgamma", "ceil", "floor", "nearbyint", "rint", "lrint", "llrint", "round", "lround", "llround",
  "trunc", "fmod", "remainder", "remquo", "copysign", "nan", "nextafter", "nexttoward", "fdim",
  "fmax", "fmin", "fma", "isfinite", "isinf", "isnan", "isnormal", "signbit", "fpclassify",
  "isgreater", "isless", "isunordered", "gamma", "j0", "j1", "jn", "y0", "y1", "yn",
  NULL};
static const char *const reserved_names[] = {
  /* string.h */
  "memcpy", "memmove", "memset", "memcmp", "memchr", "strcpy", "strncpy", "strcat", "strncat",
  "strcmp", "strncmp", "strcoll", "strxfrm", "strchr", "strrchr", "strspn", "strcspn", "strpbrk",
  "strstr", "strtok", "strerror", "strlen", "strdup", "strndup",
  /* stdlib.h */
  "malloc", "calloc", "realloc", "free", "abort", "exit", "atexit", "at_quick_exit", "quick_exit",
  "_Exit", "getenv", "system", "abs", "labs", "llabs", "div", "ldiv", "lldiv", "atof", "atoi", "atol",
  "atoll", "strtod", "strtof", "strtold", "strtol", "strtoll", "strtoul", "strtoull", "rand", "srand",
  "qsort", "bsearch", "aligned_alloc", "mblen", "mbtowc", "wctomb", "mbstowcs", "wcstombs",
  /* stdio.h */
  "fopen", "freopen", "fclose", "fflush", "remove", "rename", "tmpfile", "tmpnam", "setbuf",
  "setvbuf", "fprintf", "fscanf", "printf", "scanf", "snprintf", "sprintf", "sscanf", "vfprintf",
  "vfscanf", "vprintf", "vscanf", "vsnprintf", "vsprintf", "vsscanf", "fgetc", "fgets", "fputc",
  "fputs", "getc", "getchar", "gets", "putc", "putchar", "puts", "ungetc", "fread", "fwrite",
  "fgetpos", "fseek", "fsetpos", "ftell", "rewind", "clearerr", "feof", "ferror", "perror",
  "main",
  NULL};

/* A name usable as the C identifier prefix of the exported source: NULL if
   fine, else why not. */
static const char *name_problem(const char *s) {
  const char *p;
  int k;
  if (!s[0] || (s[0] >= '0' && s[0] <= '9') || strlen(s) > 40)
    return "must be a C identifier (letters, digits, _; not starting with a digit; at most 40 characters)";
  for (p = s; *p; ++p)
    if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') || *p == '_'))
      return "must be a C identifier (letters, digits, _; not starting with a digit; at most 40 characters)";
  if (s[0] == '_') return "must not start with _ (reserved identifiers)";
  if ((s[0] == 'p' || s[0] == 'P') && (s[1] == 'h' || s[1] == 'H') && (s[2] == 'g' || s[2] == 'G') &&
      (s[3] == 'm' || s[3] == 'M') && (s[4] == 'g' || s[4] == 'G'))
    return "must not start with phgmg (the library's names)";
  if (strlen(s) > 4 && (!strcmp(s + strlen(s) - 4, "_MAX") || !strcmp(s + strlen(s) - 4, "_MIN")))
    return "must not end in _MAX or _MIN (macros of <limits.h>, <float.h>, <stdint.h>)";
  for (k = 0; reserved_kw[k]; ++k)
    if (!strcmp(s, reserved_kw[k])) return "is a C/C++ keyword or a type or macro of the C library";
  for (k = 0; reserved_names[k]; ++k)
    if (!strcmp(s, reserved_names[k])) return "is a function of the C library headers phgmg.h includes";
  for (k = 0; math_names[k]; ++k) {
    const size_t l = strlen(math_names[k]);
    if (!strncmp(s, math_names[k], l) && (s[l] == '\0' || ((s[l] == 'f' || s[l] == 'l') && s[l + 1] == '\0')))
      return "is a function of <math.h>";
  }
  return NULL;
}

/* ---- validation messages ---------------------------------------------------- */
/* ||A + s A^T||_F / ||A||_F (s = +1: skew defect, s = -1: symmetry defect). */
static double sym_defect(const double *A, int N, double s) {
  double num = 0.0, den = 0.0;
  int i, j;
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) {
      const double d = A[i + (size_t)j * N] + s * A[j + (size_t)i * N];
      num += d * d;
      den += A[i + (size_t)j * N] * A[i + (size_t)j * N];
    }
  return den > 0.0 ? sqrt(num / den) : 0.0;
}

/* Explain a failed phgmg_ph_validate in terms of the files. */
static int explain_validate(phgmg_result rc, const mat *J, const mat *R, const mat *B, const mat *Q,
                            double rcond) {
  const int N = J->rows;
  switch (rc) {
    case PHGMG_ERR_NOT_SKEW:
      return fail("%s (--J): %s: ||J + J^T||_F / ||J||_F = %.3g (tolerance 1e-12)", J->path,
                  phgmg_result_string(rc), sym_defect(J->a, N, 1.0));
    case PHGMG_ERR_NOT_SYMMETRIC:
      return fail("%s (--R): %s: ||R - R^T||_F / ||R||_F = %.3g (tolerance 1e-12)", R->path,
                  phgmg_result_string(rc), sym_defect(R->a, N, -1.0));
    case PHGMG_ERR_Q_NOT_SYMMETRIC:
      return fail("%s (--Q): %s: ||Q - Q^T||_F / ||Q||_F = %.3g (tolerance 1e-12)", Q->path,
                  phgmg_result_string(rc), sym_defect(Q->a, N, -1.0));
    case PHGMG_ERR_NOT_PSD:
      return fail("%s (--R): %s (an eigenvalue below -1e-12 ||R||)", R->path, phgmg_result_string(rc));
    case PHGMG_ERR_Q_NOT_PD:
      return fail("%s (--Q): %s (its Cholesky factorization meets a pivot <= 0)", Q->path,
                  phgmg_result_string(rc));
    case PHGMG_ERR_RANK:
      return fail("%s (--B): %s: the %d columns of B are linearly dependent", B->path,
                  phgmg_result_string(rc), B->cols);
    case PHGMG_ERR_SINGULAR:
      return fail("%s, %s (--J, --R): J - R is singular to working precision (rcond %.3g)", J->path,
                  R->path, rcond);
    default:
      return fail("%s, %s, %s, %s: the system does not validate: %s", J->path, R->path, B->path,
                  Q->path, phgmg_result_string(rc));
  }
}

/* ---- reduce ------------------------------------------------------------------- */
typedef struct reduce_args {
  const char *J, *R, *B, *Q, *X, *poly, *poly_idx, *poly_w, *poly_jdx, *out, *name, *input, *method;
  const char *Jcoo, *Rcoo, *Qcoo; /* sparse J, R, Q as coordinate triplets */
  const char *E, *Ecoo;            /* descriptor models: the mass matrix, dense or sparse */
  const char *Pf, *Sf, *Nf;        /* feedthrough P, S, N */
  const char *dampf;               /* --dampers: nonlinear dampers (k x 4: i, j, c1, c3) */
  const char *x0f;                 /* --x0: the initial state of simulate and of reduce's training runs */
  const char *expf, *potential, *hyper;
  double hyper_tol;
  int simulate, steps, r, rn, no_deim, deim_max, deim_neg, save_snap, have_dt_map, newton_iter;
  int stream;                      /* --stream: the simulated snapshots streamed, never stored */
  int have_dt;                  /* --dt given (with --X alone: the snapshots' step) */
  double dt, amp, lambda, deim_tol, dt_map, newton_tol;
  double degeneracy_tol;        /* --degeneracy-tol (0: the library's default) */
  int have_lambda;
  int lambda_auto;              /* --lambda auto (1) / cv (2) */
  int manifold;                 /* --manifold pod (0) / greedy (1) / altmin (2) */
  const char *manifold_s;
  int ref;                      /* --ref none (0) / mean (PHGMG_REF_MEAN) / FILE (PHGMG_REF_GIVEN) */
  const char *ref_file;         /* --ref FILE: the reference state, N values */
  int greedy_window;            /* --greedy-window W (0: the library's default) */
  int adi_maxit;                /* --adi-maxit K: low-rank ADI steps (0: the library's default) */
  int lyap;                     /* --lyap adi (PHGMG_LYAP_ADI) | eksm (PHGMG_LYAP_EKSM)        */
  const char *form_s;           /* --form ph | ss as given (NULL: not given)                    */
  int form_ss;                  /* --form ss: bt's reduced model as state-space arrays A, B, C, D */
  const char *train[16];        /* --train-input KIND, repeatable */
  int ntrain;
  const char *xs[16];           /* --X FILE, repeatable: one run each (X = xs[0]) */
  int nx;
  const char *xin[16];          /* --X-input KIND, repeatable: the input of each --X run */
  int nxin;
  int rlist[16], nrl;           /* --r R1,R2,...: the orders of a sweep (r = the one being built) */
  int mlist[8], nml;            /* --method M1,M2,...: the methods of a sweep (method = the one built) */
  const char *name0;            /* --name as given (name: the model being built, see sweep_name) */
} reduce_args;

/* ---- the input files of reduce, validate and simulate: ONE list -----------
   Every option whose value names a file the run reads is here (the
   repeatable --X, --X-input, --train-input in input_lists). The parsers take
   these options from this table, and register_inputs registers every file
   they name, so that no output (--out's arrays, --states, the clean-up of an
   earlier run's arrays) can be one of them. kind: a file; a coordinate SPEC
   (one file or rows,cols,vals); an input KIND (sin, const or a file). */
enum { OPTF_FILE = 0, OPTF_COO = 1, OPTF_KIND = 2 };
enum { OPTF_SIMULATE = 1, OPTF_SPECIAL = 2 };  /* taken by simulate too; parsed by its own code (--ref) */
typedef struct input_opt { const char *opt; size_t off; int kind, flags; } input_opt;
#define IOPT(o, f, k, fl) {o, offsetof(reduce_args, f), k, fl}
static const input_opt input_opts[] = {
  IOPT("--J", J, OPTF_FILE, OPTF_SIMULATE), IOPT("--R", R, OPTF_FILE, OPTF_SIMULATE),
  IOPT("--B", B, OPTF_FILE, OPTF_SIMULATE), IOPT("--Q", Q, OPTF_FILE, OPTF_SIMULATE),
  IOPT("--J-coo", Jcoo, OPTF_COO, OPTF_SIMULATE), IOPT("--R-coo", Rcoo, OPTF_COO, OPTF_SIMULATE),
  IOPT("--Q-coo", Qcoo, OPTF_COO, OPTF_SIMULATE), IOPT("--E", E, OPTF_FILE, OPTF_SIMULATE),
  IOPT("--E-coo", Ecoo, OPTF_COO, OPTF_SIMULATE), IOPT("--P", Pf, OPTF_FILE, OPTF_SIMULATE),
  IOPT("--S", Sf, OPTF_FILE, OPTF_SIMULATE), IOPT("--N", Nf, OPTF_FILE, OPTF_SIMULATE),
  IOPT("--dampers", dampf, OPTF_FILE, OPTF_SIMULATE), IOPT("--poly", poly, OPTF_FILE, OPTF_SIMULATE),
  IOPT("--poly-idx", poly_idx, OPTF_FILE, OPTF_SIMULATE), IOPT("--poly-w", poly_w, OPTF_FILE, OPTF_SIMULATE),
  IOPT("--poly-jdx", poly_jdx, OPTF_FILE, OPTF_SIMULATE),
  IOPT("--exp", expf, OPTF_FILE, OPTF_SIMULATE), IOPT("--input", input, OPTF_KIND, OPTF_SIMULATE),
  IOPT("--x0", x0f, OPTF_FILE, OPTF_SIMULATE),
  IOPT("--ref", ref_file, OPTF_FILE, OPTF_SPECIAL),
  {NULL, 0, 0, 0}};
#undef IOPT
/* The repeatable ones: up to 16 values each, their count in cnt. */
typedef struct input_list { const char *opt; size_t off, cnt; int kind; } input_list;
static const input_list input_lists[] = {
  {"--X", offsetof(reduce_args, xs), offsetof(reduce_args, nx), OPTF_FILE},
  {"--X-input", offsetof(reduce_args, xin), offsetof(reduce_args, nxin), OPTF_KIND},
  {"--train-input", offsetof(reduce_args, train), offsetof(reduce_args, ntrain), OPTF_KIND},
  {NULL, 0, 0, 0}};

/* The field of input_opts[k] in A. */
static const char **input_field(reduce_args *A, int k) { return (const char **)(void *)((char *)A + input_opts[k].off); }

/* The index in input_opts of option o that the parser takes by the table
   (simulate: only those marked OPTF_SIMULATE), or -1. */
static int input_opt_find(const char *o, int simulate) {
  int k;
  for (k = 0; input_opts[k].opt; ++k)
    if (!strcmp(input_opts[k].opt, o) && !(input_opts[k].flags & OPTF_SPECIAL) &&
        (!simulate || (input_opts[k].flags & OPTF_SIMULATE)))
      return k;
  return -1;
}

static const char *method_name(int m) {
  switch (m) {
    case PHGMG_METHOD_BT: return "bt";
    case PHGMG_METHOD_PRBT: return "prbt";
    case PHGMG_METHOD_PHBT: return "phbt";
    case PHGMG_METHOD_GMG_POD: return "gmg-pod";
    case PHGMG_METHOD_GMG_QM: return "gmg-qm";
    case PHGMG_METHOD_SP1: return "sp1";
    case PHGMG_METHOD_SP2: return "sp2";
    default: return "unknown";
  }
}

/* The value of option argv[*i] (advancing *i), or NULL after a usage message. */
static const char *optval(int argc, char **argv, int *i) {
  if (*i + 1 >= argc) { usage_error("%s needs a value", argv[*i]); return NULL; }
  if (!argv[*i + 1][0]) { usage_error("%s: empty value (a file name, a number or a word expected)", argv[*i]); return NULL; }
  return argv[++*i];
}

/* --freq W / --freq-end W1 (argv[*i]): a finite angular frequency > 0 into
   g_freq / g_freq_end. 0, or 1 after a usage message. */
static int parse_freq(int argc, char **argv, int *i) {
  const char *o = argv[*i], *v;
  double w;
  if (!(v = optval(argc, argv, i)) || !parse_double(o, v, 0.0, &w)) return 1;
  if (!(w > 0.0)) { usage_error("%s: expected an angular frequency > 0 (rad per unit of time), got '%s'", o, v); return 1; }
  if (!strcmp(o, "--freq")) g_freq = w; else g_freq_end = w;
  return 0;
}

/* A named potential (--potential NAME[:P1[:P2]]) as exp-polynomial
   coefficients into c (the polynomial c_0..c_deg, then the pairs (a_e, b_e)).
   Returns 0, or 1 after a message: an unknown name, a field that is empty or
   not a finite number, the wrong number of fields, a parameter out of range,
   coefficients beyond the double range. */
static int named_potential(const char *spec, double *c, int *deg, int *nexp) {
  double p[2] = {1.0, 1.0};
  int n = 0, k;
  const char *colon = strchr(spec, ':');
  const size_t len = colon ? (size_t)(colon - spec) : strlen(spec);
  const char *what = "expected toda, cosh:A (A != 0), morse:D:A (D > 0, A != 0) or fpu:K3:K4 (K4 > 0)";
  while (colon) { /* each field a whole finite number */
    char *end;
    if (n == 2) return usage_error("--potential '%s': too many fields; %s", spec, what);
    errno = 0;
    p[n] = strtod(colon + 1, &end);
    if (end == colon + 1 || (*end && *end != ':') || errno == ERANGE || !isfinite(p[n]))
      return usage_error("--potential '%s': field %d is %s; %s", spec, n + 1,
                         end == colon + 1 ? "empty or not a number" : "not a finite double", what);
    ++n;
    colon = *end == ':' ? end : NULL;
  }
  memset(c, 0, 8 * sizeof(double));
  if (len == 4 && !strncmp(spec, "toda", 4) && n == 0) {        /* e^s - 1 - s */
    c[0] = -1.0; c[1] = -1.0; *deg = 1; *nexp = 1; c[2] = 1.0; c[3] = 1.0;
  } else if (len == 4 && !strncmp(spec, "cosh", 4) && n <= 1 && p[0] != 0.0) { /* (cosh(a s) - 1)/a^2 */
    c[0] = -1.0 / (p[0] * p[0]); *deg = 0; *nexp = 2;
    c[1] = 0.5 / (p[0] * p[0]); c[2] = p[0]; c[3] = 0.5 / (p[0] * p[0]); c[4] = -p[0];
  } else if (len == 5 && !strncmp(spec, "morse", 5) && n == 2 && p[0] > 0.0 && p[1] != 0.0) { /* D (1 - e^{-a s})^2 */
    c[0] = p[0]; *deg = 0; *nexp = 2; c[1] = -2.0 * p[0]; c[2] = -p[1]; c[3] = p[0]; c[4] = -2.0 * p[1];
  } else if (len == 3 && !strncmp(spec, "fpu", 3) && n == 2 && p[1] > 0.0) {  /* k3 s^3/3 + k4 s^4/4 */
    c[3] = p[0] / 3.0; c[4] = p[1] / 4.0; *deg = 4; *nexp = 0;
  } else {
    return usage_error("--potential '%s': %s%s", spec, what,
                       (len == 5 && !strncmp(spec, "morse", 5) && n == 2 && p[0] <= 0.0) ||
                       (len == 3 && !strncmp(spec, "fpu", 3) && n == 2 && p[1] <= 0.0)
                           ? " (else the energy is unbounded below)" : "");
  }
  for (k = 0; k < 8; ++k)
    if (!isfinite(c[k]) || (c[k] != 0.0 && fabs(c[k]) < DBL_MIN))
      return usage_error("--potential '%s': its coefficients leave the double range (%g); use parameters "
                         "of moderate size", spec, c[k]);
  return 0;
}

/* 1 if option o is among the seen ones. */
static int given(const char *o, const char *const *seen, int nseen) {
  int k;
  for (k = 0; k < nseen; ++k)
    if (!strcmp(seen[k], o)) return 1;
  return 0;
}

/* The hyper-reduction options: each applies to a nonlinear part, and only
   to the method that reads it. 0 or the usage status 2. */
static int check_hyper_opts(const reduce_args *A, const char *const *seen, int nseen) {
  static const char *const all[] = {"--hyper", "--hyper-tol", "--deim-tol", "--deim-max", "--no-deim",
                                    "--no-hyper", "--deim-allow-negative", NULL};
  const int ecsw = !A->hyper || !strcmp(A->hyper, "ecsw");
  int k;
  for (k = 0; all[k]; ++k)
    if (given(all[k], seen, nseen) && !A->poly_idx)
      return usage_error("reduce: %s applies to a nonlinear part (--poly, --exp or --potential with --poly-idx); "
                         "this model has none%s", all[k],
                         A->dampf ? " (the dampers of --dampers are not hyper-reduced: every damper is kept)" : "");
  for (k = 0; k < 4; ++k)
    if (A->no_deim && given(all[k], seen, nseen))
      return usage_error("reduce: --no-hyper keeps every nonlinear term: %s does not apply", all[k]);
  if (given("--hyper-tol", seen, nseen)) {
    if (!ecsw) return usage_error("--hyper-tol applies to --hyper ecsw (the tolerance of %s is --deim-tol)", A->hyper);
    if (!(A->hyper_tol > 0.0 && A->hyper_tol < 1.0))
      return usage_error("--hyper-tol %g: expected 0 < T < 1 (a relative residual)", A->hyper_tol);
    if (A->hyper_tol < 1e-14)
      return usage_error("--hyper-tol %g: below what double precision resolves in a relative residual (1e-14); "
                         "for every term exactly, use --no-hyper", A->hyper_tol);
  }
  if (ecsw && (given("--deim-tol", seen, nseen) || given("--deim-max", seen, nseen)))
    return usage_error("reduce: --deim-tol and --deim-max apply to --hyper qdeim or greedy (ecsw's tolerance is "
                       "--hyper-tol)");
  if (!(A->deim_tol < 1.0))
    return usage_error("--deim-tol %g: expected 0 <= T < 1 (DEIM keeps the modes with sigma_k / sigma_1 > T)",
                       A->deim_tol);
  return 0;
}

/* --r R or a comma-separated list R1,R2,... (up to 16 distinct orders, a
   sweep): into A->rlist; A->r is the first. 0, or 1 after a usage message. */
static int parse_r_list(const char *v, reduce_args *A) {
  const char *p = v;
  char buf[32];
  int k;
  A->nrl = 0;
  while (*p) {
    const size_t l = strcspn(p, ",");
    int r;
    if (l == 0 || l >= sizeof buf) { usage_error("--r '%s': expected an order R or a list R1,R2,... (no spaces)", v); return 1; }
    memcpy(buf, p, l); buf[l] = '\0';
    if (!parse_int("--r", buf, 1, INT_MAX, &r)) return 1;
    for (k = 0; k < A->nrl; ++k)
      if (A->rlist[k] == r) { usage_error("--r '%s': the order %d is listed twice", v, r); return 1; }
    if (A->nrl == 16) { usage_error("--r '%s': at most 16 orders", v); return 1; }
    A->rlist[A->nrl++] = r;
    p += l;
    if (*p == ',') { ++p; if (!*p) { usage_error("--r '%s': a trailing comma", v); return 1; } }
  }
  A->r = A->rlist[0];
  return 0;
}

static int method_code(const char *m);
/* --method M or a comma-separated list (each of gmg-pod, gmg-qm, sp1, sp2,
   bt, prbt, phbt once) into A->mlist; A->method is the first's name. 0 or the usage status 2. */
static int parse_method_list(reduce_args *A) {
  const char *p = A->method, *v = A->method;
  char buf[16];
  int k;
  A->nml = 0;
  while (*p) {
    const size_t l = strcspn(p, ",");
    int c;
    if (l == 0 || l >= sizeof buf) c = -1;
    else { memcpy(buf, p, l); buf[l] = '\0'; c = method_code(buf); }
    if (c < 0) return usage_error("--method '%s': expected gmg-pod, gmg-qm, sp1, sp2, bt, prbt or phbt, or a list of "
                                  "them (e.g. gmg-pod,sp1)", v);
    if (A->nml == (int)(sizeof A->mlist / sizeof A->mlist[0]))
      return usage_error("--method '%s': more methods than there are", v);
    for (k = 0; k < A->nml; ++k)
      if (A->mlist[k] == c) return usage_error("--method '%s': %s is listed twice", v, buf);
    A->mlist[A->nml++] = c;
    p += l;
    if (*p == ',') { ++p; if (!*p) return usage_error("--method '%s': a trailing comma", v); }
  }
  return 0;
}

static const char *method_name(int m);
/* 1 if method code c is among the methods of the run. */
static int has_method(const reduce_args *A, int c) {
  int k;
  for (k = 0; k < A->nml; ++k)
    if (A->mlist[k] == c) return 1;
  return 0;
}

/* The number of models a run builds: every (method, r) of the lists. */
static int sweep_count(const reduce_args *A) { return A->nml * A->nrl; }
static int is_balancing(int method) {
  return method == PHGMG_METHOD_BT || method == PHGMG_METHOD_PRBT || method == PHGMG_METHOD_PHBT;
}
/* Does any model of the sweep need snapshots (a method other than balancing)? */
static int sweep_needs_snapshots(const reduce_args *A) {
  int k;
  for (k = 0; k < A->nml; ++k)
    if (!is_balancing(A->mlist[k])) return 1;
  return 0;
}

/* Model k of a sweep (methods outer, orders inner): its method and order
   into A, and its name: --name for a single model, else
   NAME_<method>_r<R> with the method's '-' as '_' (rom_gmg_pod_r20). */
static void sweep_set(reduce_args *A, int k, char *name, size_t cap) {
  const int mc = A->mlist[k / A->nrl];
  char mn[16];
  size_t i;
  A->r = A->rlist[k % A->nrl];
  A->method = method_name(mc);
  snprintf(mn, sizeof mn, "%s", A->method);
  for (i = 0; mn[i]; ++i) if (mn[i] == '-') mn[i] = '_';
  if (sweep_count(A) == 1) snprintf(name, cap, "%s", A->name0);
  else snprintf(name, cap, "%s_%s_r%d", A->name0, mn, A->r);
  A->name = name;
}

/* Returns 0, the usage status 2, or -1 after printing --help. */
static int check_reduce_args(reduce_args *A, const char *const *seen, int nseen);
static int parse_reduce(int argc, char **argv, reduce_args *A) {
  const char *seen[64];
  int i, k, nseen = 0;
  phgmg_reduce_opts def;   /* the library's defaults of the options it shares */
  phgmg_reduce_opts_default(&def);
  memset(A, 0, sizeof *A);
  A->dt = 0.1; A->steps = 1000; A->amp = 0.1; A->rn = 0; A->lambda = def.qm.lambda;
  A->deim_tol = def.hyper.deim_tol; A->name = "rom"; A->newton_tol = 0.0; A->newton_iter = 10;
  for (i = 2; i < argc; ++i) {
    const char *o = argv[i], *v;
#define STR(opt, field) else if (!strcmp(o, opt)) { if (!(v = optval(argc, argv, &i))) return 2; A->field = v; }
#define INT(opt, field, lo, hi) else if (!strcmp(o, opt)) { if (!(v = optval(argc, argv, &i)) || !parse_int(o, v, lo, hi, &A->field)) return 2; }
#define DBL(opt, field, lo) else if (!strcmp(o, opt)) { if (!(v = optval(argc, argv, &i)) || !parse_double(o, v, lo, &A->field)) return 2; }
    if (!strcmp(o, "--help") || !strcmp(o, "-h")) { print_help(); return -1; }
    if (!strcmp(o, "--train-input")) {   /* repeatable: one training run each */
      if (!(v = optval(argc, argv, &i))) return 2;
      if (A->ntrain >= 16) return usage_error("reduce: at most 16 --train-input");
      A->train[A->ntrain++] = v;
      continue;
    }
    if (!strcmp(o, "--X") || !strcmp(o, "--X-input")) {   /* repeatable: one run each */
      const int isx = o[3] == 0;
      if (!(v = optval(argc, argv, &i))) return 2;
      if ((isx ? A->nx : A->nxin) >= 16) return usage_error("reduce: at most 16 %s", o);
      if (isx) A->xs[A->nx++] = v; else A->xin[A->nxin++] = v;
      A->X = A->xs[0];
      continue;
    }
    if (repeated_opt(o, seen, &nseen)) return 2;
    else if ((k = input_opt_find(o, 0)) >= 0) { if (!(v = optval(argc, argv, &i))) return 2; *input_field(A, k) = v; }
    STR("--potential", potential) STR("--hyper", hyper)
    DBL("--hyper-tol", hyper_tol, 0.0)
    STR("--out", out) STR("--name", name) STR("--method", method)
    INT("--steps", steps, 1, INT_MAX - 1)
    else if (!strcmp(o, "--r")) { if (!(v = optval(argc, argv, &i)) || parse_r_list(v, A)) return 2; }
    INT("--deim-max", deim_max, 1, INT_MAX) INT("--newton-iter", newton_iter, 1, 1000)
    DBL("--amp", amp, -HUGE_VAL) DBL("--deim-tol", deim_tol, 0.0) DBL("--newton-tol", newton_tol, 0.0)
    else if (!strcmp(o, "--dt")) {
      if (!(v = optval(argc, argv, &i)) || !parse_double(o, v, 0.0, &A->dt)) return 2;
      if (!(A->dt > 0.0)) return usage_error("--dt must be > 0");
      A->have_dt = 1;
    }
    else if (!strcmp(o, "--lambda")) {
      if (!(v = optval(argc, argv, &i))) return 2;
      if (!strcmp(v, "auto")) A->lambda_auto = 1;
      else if (!strcmp(v, "cv")) A->lambda_auto = 2;
      else if (!parse_double(o, v, 0.0, &A->lambda)) return 2;
      A->have_lambda = 1;
    }
    else if (!strcmp(o, "--rn")) {
      if (!(v = optval(argc, argv, &i))) return 2;
      if (!strcmp(v, "wide")) A->rn = PHGMG_RN_WIDE;
      else if (!parse_int(o, v, 1, 4096, &A->rn)) return 2;
    }
    else if (!strcmp(o, "--ref")) {
      if (!(v = optval(argc, argv, &i))) return 2;
      if (!strcmp(v, "none")) A->ref = PHGMG_REF_NONE;
      else if (!strcmp(v, "mean")) A->ref = PHGMG_REF_MEAN;
      else if (!*v) return usage_error("--ref: expected none, mean or a .npy file, got an empty name");
      else {
        FILE *f = fopen(v, "rb");
        if (!f) return usage_error("--ref '%s': expected none, mean or a .npy file (cannot open: %s)", v, strerror(errno));
        fclose(f);
        A->ref = PHGMG_REF_GIVEN; A->ref_file = v;
      }
    }
    else if (!strcmp(o, "--adi-maxit")) {
      if (!(v = optval(argc, argv, &i)) || !parse_int(o, v, 1, 1000000, &A->adi_maxit)) return 2;
    } else if (!strcmp(o, "--lyap")) {
      if (!(v = optval(argc, argv, &i))) return 2;
      if (!strcmp(v, "adi")) A->lyap = PHGMG_LYAP_ADI;
      else if (!strcmp(v, "eksm")) A->lyap = PHGMG_LYAP_EKSM;
      else return usage_error("--lyap: expected adi or eksm, got '%s'", v);
    } else if (!strcmp(o, "--form")) {
      if (!(v = optval(argc, argv, &i))) return 2;
      if (strcmp(v, "ph") && strcmp(v, "ss")) return usage_error("--form: expected ph or ss, got '%s'", v);
      A->form_s = v;
      A->form_ss = !strcmp(v, "ss");
    } else if (!strcmp(o, "--greedy-window")) {
      if (!(v = optval(argc, argv, &i)) || !parse_int(o, v, 1, 100000, &A->greedy_window)) return 2;
    }
    else if (!strcmp(o, "--manifold")) {
      if (!(v = optval(argc, argv, &i))) return 2;
      A->manifold_s = v;
      if (!strcmp(v, "pod")) A->manifold = PHGMG_MANIFOLD_POD;
      else if (!strcmp(v, "greedy")) A->manifold = PHGMG_MANIFOLD_GREEDY;
      else if (!strcmp(v, "altmin")) A->manifold = PHGMG_MANIFOLD_ALTMIN;
      else return usage_error("--manifold '%s': expected pod, greedy or altmin", v);
    }
    else if (!strcmp(o, "--dt-map")) {
      if (!(v = optval(argc, argv, &i)) || !parse_double(o, v, 0.0, &A->dt_map) || real_bad(o, v, A->dt_map)) return 2;
      A->have_dt_map = 1;
    }
    else if (!strcmp(o, "--freq") || !strcmp(o, "--freq-end")) { if (parse_freq(argc, argv, &i)) return 2; }
    else if (!strcmp(o, "--degeneracy-tol")) {
      if (!(v = optval(argc, argv, &i)) || !parse_double(o, v, 0.0, &A->degeneracy_tol)) return 2;
      if (!(A->degeneracy_tol > 0.0 && A->degeneracy_tol < 1.0))
        return usage_error("--degeneracy-tol: expected a number with 0 < T < 1, got '%s'", v);
    }
    else if (!strcmp(o, "--simulate")) A->simulate = 1;
    else if (!strcmp(o, "--stream")) A->stream = 1;
    else if (!strcmp(o, "--no-deim") || !strcmp(o, "--no-hyper")) A->no_deim = 1;
    else if (!strcmp(o, "--deim-allow-negative")) A->deim_neg = 1;
    else if (!strcmp(o, "--save-snapshots")) A->save_snap = 1;
    else if (!strcmp(o, "--quiet")) g_quiet = 1;
    else return usage_error("reduce: unknown option '%s'", o);
#undef STR
#undef INT
#undef DBL
  }
  return check_reduce_args(A, seen, nseen);
}

/* The checks of reduce's arguments as a whole (after parsing): required and
   exclusive options, the model's files, the nonlinear part, the training
   inputs; resolves the CLI's own defaults (input, gmg-qm's lambda, dt-map).
   0, or the usage status 2. */
/* The model's options as a whole, for reduce, validate and simulate (cmd):
   dense or sparse J, R, Q and E in the same form, the triplet SPECs, the
   nonlinear part's options together. 0, or the usage status 2. */
static int check_model_opts(const char *cmd, const reduce_args *A) {
  int i;
  if ((A->E && A->Jcoo) || (A->Ecoo && !A->Jcoo))
    return usage_error("%s: give E like J, R, Q: --E with --J/--R/--Q, --E-coo with --J-coo/--R-coo/--Q-coo", cmd);
  if ((A->J || A->R || A->Q) && (A->Jcoo || A->Rcoo || A->Qcoo))
    return usage_error("%s: give J, R, Q either dense (--J, --R, --Q) or sparse (--J-coo, --R-coo, --Q-coo)", cmd);
  if (A->Jcoo || A->Rcoo || A->Qcoo) {
    const char *const spec[4] = {A->Jcoo, A->Rcoo, A->Qcoo, A->Ecoo};
    const char *const opt[4] = {"--J-coo", "--R-coo", "--Q-coo", "--E-coo"};
    if (!A->Jcoo || !A->Rcoo || !A->Qcoo || !A->B)
      return usage_error("%s: --J-coo, --R-coo, --Q-coo and --B are required together", cmd);
    for (i = 0; i < 4; ++i) {
      const char *c1 = spec[i] ? strchr(spec[i], ',') : NULL, *c2 = c1 ? strchr(c1 + 1, ',') : NULL;
      if (c1 && (!c2 || strchr(c2 + 1, ',') || c1 == spec[i] || c2 == c1 + 1 || !c2[1]))
        return usage_error("%s '%s': expected rows.npy,cols.npy,vals.npy (three non-empty names) or one (nnz, 3) "
                           "FILE.npy", opt[i], spec[i]);
    }
  } else if (!A->J || !A->R || !A->B || !A->Q) return usage_error("%s: --J, --R, --B and --Q are required", cmd);
  if (A->potential && (A->poly || A->expf)) return usage_error("%s: --potential replaces --poly and --exp", cmd);
  if (!!(A->poly || A->expf || A->potential) != !!A->poly_idx)
    return usage_error("%s: --poly/--exp/--potential and --poly-idx go together", cmd);
  if (A->poly_w && !A->poly_idx) return usage_error("%s: --poly-w needs a nonlinear part (--poly-idx)", cmd);
  if (A->poly_jdx && !A->poly_idx) return usage_error("%s: --poly-jdx needs a nonlinear part (--poly-idx)", cmd);
  if (A->potential) {
    double c[8];
    int d, ne;
    if (named_potential(A->potential, c, &d, &ne)) return 2;
  }
  return 0;
}

/* 1 while validate parses its reduce options: a balancing method then takes
   --dt, --steps, --input and --amp (the test runs' step, length, input). */
static int g_validating;

/* --method bt, prbt or phbt: balancing, computed from the matrices alone. */
static int balancing_method(const char *m) { return !strcmp(m, "bt") || !strcmp(m, "prbt") || !strcmp(m, "phbt"); }

/* The options of a balancing method: a linear model and the outputs; every
   option about snapshots, training runs or nonlinear terms is refused. 0 or
   the usage status 2. */
static int check_balancing_args(reduce_args *A, const char *const *seen, int nseen) {
  static const char *const refused[] = {"--simulate", "--input", "--steps",
                                        "--amp", "--dt", "--dt-map", "--save-snapshots", "--poly-idx", "--dampers",
                                        "--P", "--S", "--N", "--ref", "--rn", "--lambda", "--manifold", "--hyper",
                                        "--no-hyper", "--greedy-window", "--degeneracy-tol", NULL};
  int k;
  if (A->X || A->nxin || A->ntrain)
    return usage_error("reduce: --method %s computes the reduced model from the linear model's matrices: %s "
                       "does not apply (no snapshots)", A->method, A->X ? "--X" : A->nxin ? "--X-input" : "--train-input");
  for (k = 0; refused[k]; ++k)
    if (given(refused[k], seen, nseen) &&
        !(g_validating && (k == 1 || k == 2 || k == 3 || k == 4)))   /* --input, --steps, --amp, --dt */
      return usage_error("reduce: --method %s computes the reduced model from the linear model's matrices: %s "
                         "does not apply (no snapshots, no nonlinear part, dampers or feedthrough)", A->method,
                         refused[k]);
  if (name_problem(A->name)) return usage_error("--name '%s': %s", A->name, name_problem(A->name));
  A->input = "sin";
  return 0;
}

/* 1 if a method of the run is a balancing one. */
static int sweep_has_balancing(const reduce_args *A) {
  int k;
  for (k = 0; k < A->nml; ++k)
    if (is_balancing(A->mlist[k])) return 1;
  return 0;
}

/* 1 if the methods of the run mix balancing (no snapshots) and snapshot methods. */
static int mixes_balancing(const reduce_args *A) {
  int k, nb = 0;
  for (k = 0; k < A->nml; ++k) nb += is_balancing(A->mlist[k]);
  return nb > 0 && nb < A->nml;
}

/* --form ss: balanced truncation's model as state-space arrays, which only
   the low-rank BT of one sparse model to one order gives (reduce only). 0 or
   the usage status 2. */
static int check_form(const reduce_args *A) {
  if (!A->form_ss) return 0;
  if (A->nml != 1 || A->mlist[0] != PHGMG_METHOD_BT)
    return usage_error("--form ss: the state-space model is balanced truncation's: give --method bt (not '%s'); "
                       "the other methods give port-Hamiltonian models (--form ph)", A->method);
  if (g_validating)
    return usage_error("validate: --form ss is not taken (validate runs port-Hamiltonian models); reduce with "
                       "--form ss, then run the model with simulate-rom --ss DIR/NAME");
  if (A->nrl != 1) return usage_error("--form ss: one order per run (--r R, not a list)");
  if (!A->Jcoo)
    return usage_error("--form ss: the state-space model comes from the low-rank BT of a sparse model: give J, R, "
                       "Q (and E) as --J-coo, --R-coo, --Q-coo (--E-coo)");
  return 0;
}

static int check_reduce_args(reduce_args *A, const char *const *seen, int nseen) {
  int e;
  if ((e = check_model_opts("reduce", A)) != 0) return e;
  if (!A->method) return usage_error("reduce: --method is required (gmg-pod, gmg-qm, sp1, sp2, bt, prbt or phbt)");
  if (!A->r) return usage_error("reduce: --r is required");
  if ((e = parse_method_list(A)) != 0) return e;
  if (mixes_balancing(A))
    return usage_error("--method '%s': the balancing methods (bt, prbt, phbt: no snapshots) and the snapshot "
                       "methods cannot be mixed in one run; give them in two runs", A->method);
  if ((e = check_form(A)) != 0) return e;
  A->method = method_name(A->mlist[0]);
  if (!A->out) return usage_error("reduce: --out DIR is required");
  if (name_problem(A->name)) return usage_error("--name '%s': %s", A->name, name_problem(A->name));
  A->name0 = A->name;
  if (balancing_method(A->method)) return check_balancing_args(A, seen, nseen);
  if (!!A->X == !!A->simulate) return usage_error("reduce: give exactly one of --X FILE and --simulate");
  if (A->hyper && strcmp(A->hyper, "ecsw") && strcmp(A->hyper, "qdeim") && strcmp(A->hyper, "greedy"))
    return usage_error("--hyper '%s': expected ecsw, qdeim or greedy", A->hyper);
  if ((e = check_hyper_opts(A, seen, nseen)) != 0) return e;
  if (sweep_count(A) > 32)
    return usage_error("reduce: %d methods x %d orders = %d models; a sweep builds at most 32", A->nml, A->nrl,
                       sweep_count(A));
  {   /* every model's name of a sweep (NAME_<method>_r<R>) a C identifier too */
    char nm[128];
    int k;
    reduce_args T = *A;
    for (k = 0; k < sweep_count(A); ++k) {
      sweep_set(&T, k, nm, sizeof nm);
      if (name_problem(nm))
        return usage_error("--name '%s': the name %s of the sweep's model (%s, r = %d) %s", A->name, nm, T.method, T.r,
                           name_problem(nm));
    }
  }
  if (A->ntrain && !A->simulate) return usage_error("reduce: --train-input needs --simulate");
  if (A->nxin && A->nxin != A->nx)
    return usage_error("reduce: %d --X-input for %d --X files: give one input per --X file, in the same order",
                       A->nxin, A->nx);
  if (A->ntrain && A->input)
    return usage_error("reduce: give the training input either by --input or by --train-input, not both");
  if (!A->input) A->input = A->ntrain ? A->train[0] : "sin";
  if ((A->have_lambda || A->manifold_s || A->rn) && !has_method(A, PHGMG_METHOD_GMG_QM))
    return usage_error("reduce: --lambda, --rn and --manifold apply to --method gmg-qm only (not %s)", A->method);
  if (A->adi_maxit && !sweep_has_balancing(A))
    return usage_error("reduce: --adi-maxit applies to --method bt, prbt and phbt (the low-rank ADI)");
  if (A->lyap && !sweep_has_balancing(A))
    return usage_error("reduce: --lyap applies to --method bt, prbt and phbt (the low-rank Lyapunov solver)");
  if (A->greedy_window && (A->manifold != PHGMG_MANIFOLD_GREEDY && A->manifold != PHGMG_MANIFOLD_ALTMIN))
    return usage_error("reduce: --greedy-window applies to --method gmg-qm with --manifold greedy or altmin");
  if (A->greedy_window && A->rn != PHGMG_RN_WIDE)
    return usage_error("reduce: --greedy-window needs --rn wide (the candidates are scored against the whole "
                       "residual)");
  /* gmg-qm without --lambda: the validated choice (a fixed lambda can give a
     model whose Newton solve fails on inputs unlike the training run) */
  if (!A->have_lambda && has_method(A, PHGMG_METHOD_GMG_QM)) A->lambda_auto = 1;
  if (A->lambda_auto == 1 && A->have_lambda && A->X && !A->nxin)
    return usage_error("reduce: --lambda auto with --X needs the inputs of the runs (--X-input, one per --X): it "
                       "simulates them; or give a fixed --lambda, or --lambda cv");
  if (!A->have_dt_map) A->dt_map = A->simulate ? A->dt : 0.0;
  if (A->simulate && too_big((double)A->steps + 1.0, "--simulate --steps: the snapshots (N x (steps+1)) alone"))
    return 2; /* N >= 1: a first check before reading J */
  return 0;
}

/* ---- sparse matrices from coordinate triplets ------------------------------------ */
typedef struct cli_csc {
  phgmg_csc A;      /* phgmg_csc_from_coo's; cp, v its colptr and values (NULL: none) */
  const int *cp;
  const double *v;
} cli_csc;
static void cli_csc_free(cli_csc *c) { phgmg_csc_free(&c->A, NULL); memset(c, 0, sizeof *c); }

/* Entry k of a triplet source: rows/cols/vals three vectors, or one (nnz, 3) array. */
static int coo_index(const mat *M, int k, int which, int nnz, const char *spec, const char *opt, int N, int *out,
                     int is_col) {
  const double v = M->a[(size_t)k + (size_t)which * (size_t)nnz];
  if (!(v >= 0.0 && v < (double)N && v == floor(v)))
    return fail("%s (%s): entry %d: %s index %g; expected an integer in [0, %d) (N from --B)", spec, opt, k,
                is_col ? "column" : "row", v, N);
  *out = (int)v;
  return 0;
}

/* The triplets (the index columns ci of rows and cols, the value column cv)
   checked and summed into c by phgmg_csc_from_coo (duplicates summed, rows
   sorted in each column). 0, or 1 after a message naming the entry. */
static int coo_assemble(cli_csc *c, const mat *rows, const mat *cols, const mat *vals, int ci, int cv, int nnz,
                        const char *spec, const char *opt, int N) {
  int *ri = (int *)malloc(sizeof(int) * ((size_t)nnz + 1)), *cj = (int *)malloc(sizeof(int) * ((size_t)nnz + 1));
  double *v = (double *)malloc(sizeof(double) * ((size_t)nnz + 1));
  phgmg_result rc;
  int k, err = 0;
  if (!ri || !cj || !v) err = fail("out of memory");
  for (k = 0; k < nnz && !err; ++k) {
    if ((err = coo_index(rows, k, 0, nnz, spec, opt, N, &ri[k], 0)) == 0)
      err = coo_index(cols, k, ci, nnz, spec, opt, N, &cj[k], 1);
    v[k] = vals->a[(size_t)k + (size_t)cv * (size_t)nnz];
  }
  if (!err && (rc = phgmg_csc_from_coo(&c->A, N, N, nnz, ri, cj, v, NULL)) != PHGMG_OK)
    err = fail("%s (%s): %s", spec, opt, phgmg_result_string(rc));
  if (!err) { c->cp = c->A.colptr; c->v = c->A.values; }
  free(ri); free(cj); free(v);
  return err;
}

/* ---- sparse matrices from SciPy .npz and Matrix Market .mtx files ----------
   A small inflate (RFC 1951: stored, fixed and dynamic Huffman blocks) for
   the members of a .npz (a zip archive; scipy.sparse.save_npz compresses by
   default), a zip reader of the central directory, and a Matrix Market
   coordinate reader. Both give coordinate triplets (0-based) that
   coo_assemble sums into a CSC matrix. Every read is bounds-checked: a
   malformed file is an error naming it, never a crash. */
typedef struct inf_state {
  const unsigned char *in;
  size_t n, pos;      /* input bytes, the next byte */
  unsigned bits, nb;  /* bit buffer, bits in it */
  unsigned char *out;
  size_t cap, len;    /* the expected output size, bytes written */
  int err;
} inf_state;
typedef struct inf_huff { unsigned short count[16], sym[320]; } inf_huff;

static unsigned inf_bits(inf_state *s, unsigned need) {
  unsigned v;
  while (s->nb < need) {
    if (s->pos >= s->n) { s->err = 1; return 0; }
    s->bits |= (unsigned)s->in[s->pos++] << s->nb;
    s->nb += 8;
  }
  v = s->bits & ((1u << need) - 1u);
  s->bits >>= need;
  s->nb -= need;
  return v;
}

/* Canonical Huffman table from n code lengths; 0, or 1 if over-subscribed. */
static int inf_build(inf_huff *h, const unsigned char *len, int n) {
  unsigned short offs[16];
  int k, left = 1;
  memset(h->count, 0, sizeof h->count);
  for (k = 0; k < n; ++k) h->count[len[k]]++;
  h->count[0] = 0;
  for (k = 1; k < 16; ++k) { left <<= 1; left -= h->count[k]; if (left < 0) return 1; }
  offs[1] = 0;
  for (k = 1; k < 15; ++k) offs[k + 1] = (unsigned short)(offs[k] + h->count[k]);
  for (k = 0; k < n; ++k)
    if (len[k]) h->sym[offs[len[k]]++] = (unsigned short)k;
  return 0;
}

static int inf_decode(inf_state *s, const inf_huff *h) {
  int code = 0, first = 0, index = 0, l;
  for (l = 1; l < 16; ++l) {
    code |= (int)inf_bits(s, 1);
    if (s->err) return -1;
    if (code - h->count[l] < first) return h->sym[index + (code - first)];
    index += h->count[l];
    first += h->count[l];
    first <<= 1;
    code <<= 1;
  }
  s->err = 1;
  return -1;
}

static const unsigned short inf_lbase[29] = {3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 15, 17, 19, 23, 27, 31, 35, 43, 51, 59,
                                             67, 83, 99, 115, 131, 163, 195, 227, 258};
static const unsigned char inf_lext[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
static const unsigned short inf_dbase[30] = {1, 2, 3, 4, 5, 7, 9, 13, 17, 25, 33, 49, 65, 97, 129, 193, 257, 385, 513,
                                             769, 1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
static const unsigned char inf_dext[30] = {0, 0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11,
                                           12, 12, 13, 13};

/* The symbols of one Huffman-coded block until end-of-block. */
static int inf_codes(inf_state *s, const inf_huff *lh, const inf_huff *dh) {
  for (;;) {
    int sym = inf_decode(s, lh);
    if (sym < 0) return 1;
    if (sym < 256) {
      if (s->len >= s->cap) return 1;
      s->out[s->len++] = (unsigned char)sym;
    } else if (sym == 256) {
      return 0;
    } else {
      size_t len, dist;
      sym -= 257;
      if (sym >= 29) return 1;
      len = inf_lbase[sym] + inf_bits(s, inf_lext[sym]);
      sym = inf_decode(s, dh);
      if (sym < 0 || sym >= 30) return 1;
      dist = inf_dbase[sym] + inf_bits(s, inf_dext[sym]);
      if (s->err || dist > s->len || len > s->cap - s->len) return 1;
      for (; len; --len, ++s->len) s->out[s->len] = s->out[s->len - dist];
    }
  }
}

/* The code lengths of a dynamic block into lh, dh. */
static int inf_dynamic(inf_state *s, inf_huff *lh, inf_huff *dh) {
  static const unsigned char order[19] = {16, 17, 18, 0, 8, 7, 9, 6, 10, 5, 11, 4, 12, 3, 13, 2, 14, 1, 15};
  unsigned char len[320];
  const int nlen = (int)inf_bits(s, 5) + 257, ndist = (int)inf_bits(s, 5) + 1, ncode = (int)inf_bits(s, 4) + 4;
  int k = 0;
  if (s->err || nlen > 286 || ndist > 30) return 1;
  memset(len, 0, sizeof len);
  for (k = 0; k < ncode; ++k) len[order[k]] = (unsigned char)inf_bits(s, 3);
  if (s->err || inf_build(lh, len, 19)) return 1;
  for (k = 0; k < nlen + ndist;) {
    int sym = inf_decode(s, lh), rep = 0;
    unsigned char v = 0;
    if (sym < 0) return 1;
    if (sym < 16) { len[k++] = (unsigned char)sym; continue; }
    if (sym == 16) { if (k == 0) return 1; v = len[k - 1]; rep = 3 + (int)inf_bits(s, 2); }
    else if (sym == 17) rep = 3 + (int)inf_bits(s, 3);
    else rep = 11 + (int)inf_bits(s, 7);
    if (s->err || k + rep > nlen + ndist) return 1;
    while (rep--) len[k++] = v;
  }
  if (len[256] == 0) return 1;
  return inf_build(lh, len, nlen) || inf_build(dh, len + nlen, ndist);
}

/* Inflate n bytes into out (exactly cap bytes expected). 0, or 1 if the
   data are not a valid deflate stream of that size. */
static int inflate_buf(const unsigned char *in, size_t n, unsigned char *out, size_t cap) {
  inf_state s;
  inf_huff lh, dh;
  unsigned last = 0;
  memset(&s, 0, sizeof s);
  s.in = in; s.n = n; s.out = out; s.cap = cap;
  while (!last) {
    unsigned type;
    last = inf_bits(&s, 1);
    type = inf_bits(&s, 2);
    if (s.err) return 1;
    if (type == 0) {   /* stored: LEN, NLEN after the byte boundary */
      size_t len;
      s.bits = 0; s.nb = 0;
      if (s.pos + 4 > s.n) return 1;
      len = (size_t)s.in[s.pos] | (size_t)s.in[s.pos + 1] << 8;
      if ((len ^ ((size_t)s.in[s.pos + 2] | (size_t)s.in[s.pos + 3] << 8)) != 0xffffu) return 1;
      s.pos += 4;
      if (len > s.n - s.pos || len > s.cap - s.len) return 1;
      memcpy(s.out + s.len, s.in + s.pos, len);
      s.pos += len; s.len += len;
    } else if (type == 1) {   /* fixed codes */
      unsigned char len[320];
      int k;
      for (k = 0; k < 144; ++k) len[k] = 8;
      for (; k < 256; ++k) len[k] = 9;
      for (; k < 280; ++k) len[k] = 7;
      for (; k < 288; ++k) len[k] = 8;
      for (k = 0; k < 30; ++k) len[288 + k] = 5;
      inf_build(&lh, len, 288);
      inf_build(&dh, len + 288, 30);
      if (inf_codes(&s, &lh, &dh)) return 1;
    } else if (type == 2) {
      if (inf_dynamic(&s, &lh, &dh) || inf_codes(&s, &lh, &dh)) return 1;
    } else {
      return 1;
    }
  }
  return s.len == s.cap ? 0 : 1;
}

static unsigned long rd16(const unsigned char *p) { return (unsigned long)p[0] | (unsigned long)p[1] << 8; }
static unsigned long rd32(const unsigned char *p) { return rd16(p) | rd16(p + 2) << 16; }

/* Member `name` of the zip archive z[0..n) into a new buffer *out (*len
   bytes): stored or deflated. 0; 1 not found; 2 malformed or unsupported
   (the reason in *why). */
static int zip_member(const unsigned char *z, size_t n, const char *name, unsigned char **out, size_t *len,
                      const char **why) {
  size_t e, cd, k, nent, i;
  const size_t nl = strlen(name);
  *why = "not a zip archive (no end of central directory)";
  if (n < 22) return 2;
  for (e = n - 22;; --e) {   /* the end of central directory record, from the back */
    if (rd32(z + e) == 0x06054b50ul) break;
    if (e == 0 || n - e > 22 + 65535) return 2;
  }
  nent = rd16(z + e + 10);
  cd = rd32(z + e + 16);
  *why = "a zip central directory outside the file";
  for (k = 0, i = cd; k < nent; ++k) {
    unsigned long meth, csz, usz, off, fl, xl, cl;
    if (i > n || n - i < 46 || rd32(z + i) != 0x02014b50ul) return 2;
    meth = rd16(z + i + 10); csz = rd32(z + i + 20); usz = rd32(z + i + 24);
    fl = rd16(z + i + 28); xl = rd16(z + i + 30); cl = rd16(z + i + 32); off = rd32(z + i + 42);
    if (n - i - 46 < fl) return 2;
    if (fl == nl && !memcmp(z + i + 46, name, nl)) {
      size_t d;
      *why = "a member's data outside the file (or a zip64 archive over 4 GB)";
      if (csz == 0xfffffffful || usz == 0xfffffffful || off == 0xfffffffful) return 2;
      if (off > n || n - off < 30 || rd32(z + off) != 0x04034b50ul) return 2;
      d = off + 30 + rd16(z + off + 26) + rd16(z + off + 28);
      if (d > n || n - d < csz) return 2;
      *why = "out of memory";
      if (!(*out = (unsigned char *)malloc(usz + 1))) return 2;
      *len = usz;
      if (meth == 0 && csz == usz) { memcpy(*out, z + d, usz); return 0; }
      *why = meth == 8 ? "a deflate stream that does not decode" : "a compression other than stored or deflate";
      if (meth == 8 && !inflate_buf(z + d, csz, *out, usz)) return 0;
      free(*out);
      *out = NULL;
      return 2;
    }
    i += 46 + fl + xl + cl;
  }
  return 1;
}

/* A whole file into memory (up to 2 GiB). NULL after a message. */
static unsigned char *read_file_bytes(const char *path, const char *opt, size_t *n) {
  FILE *f = fopen(path, "rb");
  unsigned char *b;
  long l;
  if (!f) { fail("%s (%s): cannot open: %s", path, opt, strerror(errno)); return NULL; }
  if (fseek(f, 0, SEEK_END) != 0 || (l = ftell(f)) < 0 || l > 0x7fffffffL || fseek(f, 0, SEEK_SET) != 0) {
    fclose(f);
    fail("%s (%s): cannot read (not a regular file, or over 2 GiB)", path, opt);
    return NULL;
  }
  b = (unsigned char *)malloc((size_t)l + 1);
  if (!b || fread(b, 1, (size_t)l, f) != (size_t)l) { fclose(f); free(b); fail("%s (%s): cannot read", path, opt); return NULL; }
  fclose(f);
  *n = (size_t)l;
  return b;
}

/* Array `key`.npy of the .npz image into *M (a vector or matrix, as mat_load
   gives). 0; 1 after a message (missing: only when need). */
static int npz_array(const unsigned char *z, size_t n, const char *path, const char *opt, const char *key, mat *M,
                     int need) {
  char nm[32];
  unsigned char *b = NULL;
  size_t len = 0, i;
  const char *why = "";
  int e;
  phgmg_result rc;
  memset(M, 0, sizeof *M);
  M->path = path;
  snprintf(nm, sizeof nm, "%s.npy", key);
  e = zip_member(z, n, nm, &b, &len, &why);
  if (e == 1) return need ? fail("%s (%s): no array '%s' in the .npz (expected scipy.sparse.save_npz's csr, csc or "
                                 "coo arrays)", path, opt, key) : 1;
  if (e) return fail("%s (%s): %s: %s", path, opt, nm, why);
  rc = phgmg_npy_parse(b, len, &M->a, &M->rows, &M->cols, &M->ndim, NULL);
  free(b);
  if (rc != PHGMG_OK) return fail("%s (%s): %s: %s", path, opt, nm, phgmg_result_string(rc));
  for (i = 0; i < (size_t)M->rows * (size_t)M->cols; ++i)
    if (!isfinite(M->a[i])) { mat_free(M); return fail("%s (%s): %s: NaN or Inf at entry %lu", path, opt, nm, (unsigned long)i); }
  return 0;
}

/* The format string of a save_npz file ("csr", "csc", "coo", ...) from its
   format.npy (a 0-d '|S3' or '<U3' array) into fmt (4 bytes). */
static int npz_format(const unsigned char *z, size_t n, const char *path, const char *opt, char *fmt) {
  unsigned char *b = NULL;
  size_t len = 0, hl, i, k = 0;
  const char *why = "";
  int e = zip_member(z, n, "format.npy", &b, &len, &why);
  if (e == 1) return fail("%s (%s): no format.npy: not a scipy.sparse.save_npz file", path, opt);
  if (e) return fail("%s (%s): format.npy: %s", path, opt, why);
  hl = len >= 10 && b[6] == 1 ? 10 + rd16(b + 8) : len >= 12 ? 12 + rd32(b + 8) : len + 1;
  for (i = hl; i < len && k < 3; ++i)
    if (b[i]) fmt[k++] = (char)b[i];
  fmt[k] = '\0';
  free(b);
  if (hl > len || k != 3) return fail("%s (%s): format.npy does not hold a sparse format name", path, opt);
  return 0;
}

/* A scipy.sparse .npz (csr, csc or coo) as triplets: rows, cols, vals (nnz)
   allocated here; the shape must be N x N. */
static int load_npz(const char *path, const char *opt, int N, int **ri, int **cj, double **v, int *nnz) {
  size_t n = 0;
  unsigned char *z = read_file_bytes(path, opt, &n);
  mat sh, a, b, d;
  char fmt[4];
  int err = 0, k, j, p, cnt;
  if (!z) return 1;
  memset(&a, 0, sizeof a); memset(&b, 0, sizeof b); memset(&d, 0, sizeof d); memset(&sh, 0, sizeof sh);
  if ((err = npz_format(z, n, path, opt, fmt)) != 0) goto done;
  if (strcmp(fmt, "csr") && strcmp(fmt, "csc") && strcmp(fmt, "coo")) {
    err = fail("%s (%s): sparse format '%s'; expected csr, csc or coo", path, opt, fmt);
    goto done;
  }
  if ((err = npz_array(z, n, path, opt, "shape", &sh, 1)) != 0) goto done;
  if (sh.rows * sh.cols != 2 || sh.a[0] != N || sh.a[1] != N) {
    err = fail("%s (%s): shape %s (from its shape.npy), expected (%d, %d) (N from --B)", path, opt,
               sh.rows * sh.cols == 2 ? "not N x N" : "not 2-d", N, N);
    goto done;
  }
  if ((err = npz_array(z, n, path, opt, "data", &d, 1)) != 0) goto done;
  cnt = d.rows * d.cols;
  if (!strcmp(fmt, "coo")) err = npz_array(z, n, path, opt, "row", &a, 1) || npz_array(z, n, path, opt, "col", &b, 1);
  else err = npz_array(z, n, path, opt, "indices", &a, 1) || npz_array(z, n, path, opt, "indptr", &b, 1);
  if (err) goto done;
  if (a.rows * a.cols != cnt || (!strcmp(fmt, "coo") ? b.rows * b.cols != cnt : b.rows * b.cols != N + 1)) {
    err = fail("%s (%s): the arrays' lengths do not match (%s format, %d values)", path, opt, fmt, cnt);
    goto done;
  }
  *ri = (int *)malloc(sizeof(int) * ((size_t)cnt + 1)); *cj = (int *)malloc(sizeof(int) * ((size_t)cnt + 1));
  *v = (double *)malloc(sizeof(double) * ((size_t)cnt + 1));
  if (!*ri || !*cj || !*v) { err = fail("out of memory"); goto done; }
  for (k = 0; k < cnt; ++k) (*v)[k] = d.a[k];
  if (!strcmp(fmt, "coo")) {
    for (k = 0; k < cnt && !err; ++k) {
      if (!(a.a[k] == floor(a.a[k]) && b.a[k] == floor(b.a[k]) && a.a[k] >= 0 && b.a[k] >= 0 && a.a[k] < N && b.a[k] < N))
        err = fail("%s (%s): entry %d at (%g, %g) outside the %d x %d matrix", path, opt, k, a.a[k], b.a[k], N, N);
      else { (*ri)[k] = (int)a.a[k]; (*cj)[k] = (int)b.a[k]; }
    }
  } else {   /* compressed: indptr b (N + 1), indices a */
    const int csr = !strcmp(fmt, "csr");
    if (b.a[0] != 0 || b.a[N] != cnt) err = fail("%s (%s): indptr does not run from 0 to %d", path, opt, cnt);
    for (j = 0; j < N && !err; ++j)   /* indptr whole: integers, non-decreasing (so within [0, cnt]) */
      if (!(b.a[j + 1] >= b.a[j] && b.a[j + 1] == floor(b.a[j + 1])))
        err = fail("%s (%s): indptr decreases or is not an integer at %d", path, opt, j + 1);
    for (j = 0; j < N && !err; ++j) {
      for (p = (int)b.a[j]; p < (int)b.a[j + 1]; ++p) {
        if (!(a.a[p] >= 0 && a.a[p] < N && a.a[p] == floor(a.a[p]))) {
          err = fail("%s (%s): index %g at position %d outside [0, %d)", path, opt, a.a[p], p, N);
          break;
        }
        (*ri)[p] = csr ? j : (int)a.a[p];
        (*cj)[p] = csr ? (int)a.a[p] : j;
      }
    }
  }
  *nnz = cnt;
done:
  mat_free(&sh); mat_free(&a); mat_free(&b); mat_free(&d);
  free(z);
  return err;
}

/* A Matrix Market file (coordinate; real or integer; general, symmetric or
   skew-symmetric: the other triangle added, negated for skew) as triplets,
   N x N. */
static int load_mtx(const char *path, const char *opt, int N, int **ri, int **cj, double **v, int *nnz) {
  FILE *f = fopen(path, "r");
  char line[1024], obj[64], fmtw[64], field[64], sym[64];
  long M = 0, C = 0, L = 0, k;
  int skew, symm, cnt = 0, err = 0, lineno = 1;
  if (!f) return fail("%s (%s): cannot open: %s", path, opt, strerror(errno));
  if (!fgets(line, sizeof line, f) || sscanf(line, "%%%%MatrixMarket %63s %63s %63s %63s", obj, fmtw, field, sym) != 4) {
    fclose(f);
    return fail("%s (%s): not a Matrix Market file (the first line must be '%%%%MatrixMarket matrix coordinate "
                "real general' or similar)", path, opt);
  }
  for (k = 0; obj[k]; ++k) obj[k] = (char)tolower((unsigned char)obj[k]);
  for (k = 0; fmtw[k]; ++k) fmtw[k] = (char)tolower((unsigned char)fmtw[k]);
  for (k = 0; field[k]; ++k) field[k] = (char)tolower((unsigned char)field[k]);
  for (k = 0; sym[k]; ++k) sym[k] = (char)tolower((unsigned char)sym[k]);
  skew = !strcmp(sym, "skew-symmetric");
  symm = !strcmp(sym, "symmetric");
  if (strcmp(obj, "matrix") || strcmp(fmtw, "coordinate") || (strcmp(field, "real") && strcmp(field, "integer")) ||
      (!skew && !symm && strcmp(sym, "general"))) {
    fclose(f);
    return fail("%s (%s): Matrix Market '%s %s %s %s' is not supported: expected matrix coordinate real|integer "
                "general|symmetric|skew-symmetric", path, opt, obj, fmtw, field, sym);
  }
  do { ++lineno; } while (fgets(line, sizeof line, f) && (line[0] == '%' || strspn(line, " \t\r\n") == strlen(line)));
  if (sscanf(line, "%ld %ld %ld", &M, &C, &L) != 3 || M != N || C != N || L < 0 || L > 1000000000L) {
    fclose(f);
    return fail("%s (%s): line %d: expected the size line 'rows cols entries' of a %d x %d matrix (N from --B)",
                path, opt, lineno, N, N);
  }
  *ri = (int *)malloc(sizeof(int) * (2 * (size_t)L + 1)); *cj = (int *)malloc(sizeof(int) * (2 * (size_t)L + 1));
  *v = (double *)malloc(sizeof(double) * (2 * (size_t)L + 1));
  if (!*ri || !*cj || !*v) { fclose(f); return fail("out of memory for %ld entries", L); }
  for (k = 0; k < L && !err; ++k) {
    long i, j;
    double x;
    char *end;
    ++lineno;
    if (!fgets(line, sizeof line, f)) { err = fail("%s (%s): %ld entries announced, %ld found", path, opt, L, k); break; }
    if (sscanf(line, "%ld %ld %n", &i, &j, &cnt) < 2) { err = fail("%s (%s): line %d: expected 'row col value'", path, opt, lineno); break; }
    x = strtod(line + cnt, &end);
    if (end == line + cnt || !isfinite(x)) { err = fail("%s (%s): line %d: the value is not a finite number", path, opt, lineno); break; }
    if (i < 1 || i > N || j < 1 || j > N) { err = fail("%s (%s): line %d: entry (%ld, %ld) outside 1..%d", path, opt, lineno, i, j, N); break; }
    if ((symm || skew) && i < j) { err = fail("%s (%s): line %d: (%ld, %ld) above the diagonal in a %s file (only the lower triangle is stored)", path, opt, lineno, i, j, sym); break; }
    if (skew && i == j) { err = fail("%s (%s): line %d: a diagonal entry in a skew-symmetric file", path, opt, lineno); break; }
    (*ri)[*nnz] = (int)i - 1; (*cj)[*nnz] = (int)j - 1; (*v)[(*nnz)++] = x;
    if ((symm || skew) && i != j) { (*ri)[*nnz] = (int)j - 1; (*cj)[*nnz] = (int)i - 1; (*v)[(*nnz)++] = skew ? -x : x; }
  }
  fclose(f);
  return err;
}

/* 1 if path ends in ext (".npz", ".mtx"). */
static int has_ext(const char *path, const char *ext) {
  const size_t l = strlen(path), e = strlen(ext);
  return l > e && !strcmp(path + l - e, ext);
}

/* A .npz or .mtx SPEC into c (N x N, duplicates summed). */
static int load_sparse_file(cli_csc *c, const char *opt, const char *spec, int N) {
  int *ri = NULL, *cj = NULL, nnz = 0, err;
  double *v = NULL;
  phgmg_result rc;
  if (is_dir(spec, opt)) return 1;
  err = has_ext(spec, ".npz") ? load_npz(spec, opt, N, &ri, &cj, &v, &nnz) : load_mtx(spec, opt, N, &ri, &cj, &v, &nnz);
  if (!err && (rc = phgmg_csc_from_coo(&c->A, N, N, nnz, ri, cj, v, NULL)) != PHGMG_OK)
    err = fail("%s (%s): %s", spec, opt, phgmg_result_string(rc));
  if (!err) { c->cp = c->A.colptr; c->v = c->A.values; }
  free(ri); free(cj); free(v);
  return err;
}

/* --X-coo SPEC into an N x N CSC matrix (columns sorted, duplicates summed). */
static int load_coo(cli_csc *c, const char *opt, const char *spec, int N) {
  mat M[3];
  int nf = 1, nnz, k, j, err = 0;
  const mat *rows, *cols, *vals;
  char buf[3][4096];
  memset(M, 0, sizeof M);
  memset(c, 0, sizeof *c);
  if (!strchr(spec, ',') && (has_ext(spec, ".npz") || has_ext(spec, ".mtx"))) return load_sparse_file(c, opt, spec, N);
  if (strchr(spec, ',')) {
    const char *a = spec, *b = strchr(a, ','), *e = b ? strchr(b + 1, ',') : NULL;
    if (!b || !e || strchr(e + 1, ',') || b - a >= 4096 || e - b - 1 >= 4096 || strlen(e + 1) >= 4096 ||
        b == a || e == b + 1 || !e[1])
      return usage_error("%s '%s': expected rows.npy,cols.npy,vals.npy or one (nnz, 3) FILE.npy", opt, spec);
    memcpy(buf[0], a, (size_t)(b - a)); buf[0][b - a] = '\0';
    memcpy(buf[1], b + 1, (size_t)(e - b - 1)); buf[1][e - b - 1] = '\0';
    strcpy(buf[2], e + 1);
    nf = 3;
  } else {
    strcpy(buf[0], "");
  }
  for (k = 0; k < nf; ++k)
    if (mat_load(&M[k], opt, nf == 3 ? buf[k] : spec)) { for (j = 0; j < k; ++j) mat_free(&M[j]); return 1; }
  if (nf == 1) {
    if (M[0].ndim != 2 || M[0].cols != 3) {
      err = fail("%s (%s): expected an (nnz, 3) array of (row, col, value), got %s", spec, opt, shape_str(&M[0]));
      goto done;
    }
    rows = cols = vals = &M[0];
    nnz = M[0].rows;
  } else {
    nnz = M[0].rows * M[0].cols;
    for (k = 0; k < 3; ++k)
      if (!is_vector(&M[k]) || M[k].rows * M[k].cols != nnz) {
        err = fail("%s (%s): rows, cols and vals must be vectors of one length (%d), got %s for %s", spec, opt, nnz,
                   shape_str(&M[k]), buf[k]);
        goto done;
      }
    rows = &M[0]; cols = &M[1]; vals = &M[2];
  }
  err = coo_assemble(c, rows, cols, vals, nf == 3 ? 0 : 1, nf == 3 ? 0 : 2, nnz, spec, opt, N);
done:
  for (k = 0; k < nf; ++k) mat_free(&M[k]);
  return err;
}

/* One model of a run (a sweep builds several): its outputs staged under
   temporary names until the run commits them. */
typedef struct sweep_model {
  staged sg;             /* its files */
  outlist ol;            /* its arrays */
  char name[64];
  int method, r, rr, m, pass;
  int ss;                /* written in state-space form (--form ss) */
  double t_red;
  double ey[16], ered[16];   /* validate: each test's e_y, e_red */
  int tpass[16];
  phgmg_reduced *red;    /* kept by validate for its tests */
} sweep_model;

/* --form ss: balanced truncation's reduced model x_r' = A x_r + B u, y = C x_r
   + D u (phgmg_lrbt, phgmg_lrbt_feedthrough), its first r Hankel singular
   values and its basis T (N x r, the sparse object's internal order). */
typedef struct ss_model {
  double *A, *B, *C, *D, *hsv, *T;
  phgmg_lrbt_info inf;
} ss_model;

typedef struct reduce_state {
  mat J, R, B, Q, X, poly, pidx, pw, ex, pjdx;
  sweep_model *models;    /* every (method, r) of the run, sweep_count of them */
  int nmodels;
  staged dirs;            /* the directories --out made (removed again if nothing is written) */
  staged sweep_sg;        /* NAME_sweep.json of a sweep */
  phgmg_study *study;     /* a sweep's shared bases (NULL: each model computes its own) */
  double t_sim;
  int *idx, *jdx;         /* --poly-idx, --poly-jdx */
  double *fpoly, *fexp, named[8]; /* the family's coefficients as phgmg_ph_system wants them */
  double *Xsim, *Ysim, *V0;
  cli_csc cJ, cR, cQ, cE; /* sparse input (--J-coo ..., --E-coo) */
  mat E;                  /* --E (dense) */
  mat Pm, Sm, Nm;         /* --P, --S, --N */
  mat refm;               /* --ref FILE (internal ordering) */
  mat Dm;                 /* --dampers */
  int *di, *dj;           /* the dampers' state indices (internal ordering) */
  double *dlaw;           /* their laws: k x 4 coefficients {0, c1, 0, c3} */
  phgmg_ph_sparse *sp;    /* its banded, RCM-ordered system; NULL for dense input */
  double *Xperm, *Uord;   /* snapshots in the internal order; un-permuted output */
  cli_input in;
  cli_input tin[16];      /* --train-input 2..: the further training inputs */
  phgmg_run runs[16];     /* the training runs (--simulate, several --X), for phgmg_reduce */
  int nrun;
  mat Xs[16];             /* --X files 2..16 (the first is X) */
  double *Xcat;           /* several --X: their columns one after the other */
  cli_input xinp[16];     /* --X-input: the input of each --X run */
  phgmg_ph_system sys;    /* the model as reduced (internal ordering for sparse input; an
                             index-one model's condensed ODE) */
  phgmg_ph_system full;   /* the full model (= sys unless E has algebraic lines) */
  phgmg_dae *dae;         /* an index-one model's condensation, else NULL */
  int dae_direct;         /* simulate: a sparse index-one model is stepped as the DAE (no condensation) */
  const double *Xgiven;   /* --X of an index-one model: the given states (internal order) */
  double *Xres;           /* ... and their differential part */
  phgmg_reduced *red;
  int method;
  const double *Xd;       /* --X: the snapshots (internal ordering), ns columns */
  int ns;
  staged sg; /* the outputs, renamed into place at the end */
  outlist ol; /* the arrays written */
  pathset pin, pout; /* the files read; the files the run may write */
  int bal_on;               /* --method bt, prbt, phbt: what the balancing did */
  phgmg_balanced_info bal;
  double bal_sv[64];        /* its first values (bal.nsv) */
  phgmg_balanced_cache bcache; /* the Gramian factors, shared by a sweep's balancing models */
  ss_model ss;              /* --form ss: the state-space BT model */
} reduce_state;

/* Is w phi(s), phi(s) = sum_j c_j s^j + sum_e a_e exp(b_e s), bounded below
   as s -> dir * inf (dir = +1 or -1)? The fastest-growing exponential decides
   when there is one, else the polynomial's leading power of degree >= 3 (a
   degree up to 2 is left to the quadratic energy). 1 bounded, 0 not. */
static int phi_bounded(const double *c, int deg, const double *ex, int ne, double w, double dir) {
  double bmax = 0.0, amax = 0.0;
  int e, f, j;
  for (e = 0; e < ne; ++e) { /* the largest rate dir * b > 0 with a nonzero net coefficient */
    double a = 0.0;
    const double rate = dir * ex[2 * e + 1];
    if (!(rate > bmax)) continue;
    for (f = 0; f < ne; ++f)
      if (ex[2 * f + 1] == ex[2 * e + 1]) a += ex[2 * f];
    if (a != 0.0) { bmax = rate; amax = a; }
  }
  if (bmax > 0.0) return w * amax > 0.0;
  for (j = deg; j >= 3; --j)
    if (c[j] != 0.0) return w * c[j] * ((j % 2 && dir < 0.0) ? -1.0 : 1.0) > 0.0;
  return 1;
}

/* Every term w_k phi_k of sys bounded below (both directions); 0, or 1 after
   a message naming the source (--potential, --poly/--exp, --poly-w). */
static int check_bounded_below(const reduce_args *A, const phgmg_ph_system *sys) {
  int k, d;
  for (k = 0; k < sys->nsep; ++k) {
    const int f = sys->phi_nfun > 0 ? k : 0;
    const double w = sys->sep_w ? sys->sep_w[k] : 1.0;
    const double *c = sys->poly + (size_t)f * (sys->poly_deg + 1);
    const double *ex = sys->nexp ? sys->expo + (size_t)f * 2 * sys->nexp : NULL;
    if (w == 0.0) continue;
    for (d = -1; d <= 1; d += 2)
      if (!phi_bounded(c, sys->poly_deg, ex, sys->nexp, w, (double)d))
        return fail("%s: term %d (weight %g): w phi(s) -> -inf as s -> %cinf, so the energy H is unbounded below "
                    "and the model is not a passive port-Hamiltonian system (check the sign of the leading "
                    "coefficient%s)", A->potential ? A->potential : A->poly ? A->poly : A->expf, k, w,
                    d > 0 ? '+' : '-', A->poly_w ? " and of the weights in --poly-w" : "");
  }
  return 0;
}

/* --poly-jdx: the springs' second coordinates (-1: a one-node term), checked
   here with messages that name the file and entry; a sparse model's are
   remapped to its internal order. 0, or 1 after a message. */
static int load_springs(const reduce_args *A, reduce_state *S, phgmg_ph_system *sys, int nt) {
  phgmg_result rc;
  int k;
  if (mat_load(&S->pjdx, "--poly-jdx", A->poly_jdx)) return 1;
  if (!is_vector(&S->pjdx) || S->pjdx.rows * S->pjdx.cols != nt)
    return fail("%s (--poly-jdx): expected a vector of %d coordinates (one per entry of %s), got %s", A->poly_jdx,
                nt, A->poly_idx, shape_str(&S->pjdx));
  S->jdx = (int *)malloc(sizeof(int) * (size_t)nt);
  if (!S->jdx) return fail("out of memory");
  for (k = 0; k < nt; ++k) {
    const double v = S->pjdx.a[k];
    if (!(v >= -1.0 && v < (double)sys->N && v == floor(v)) || (int)v == S->idx[k])
      return fail("%s (--poly-jdx): entry %d is %g; expected an integer coordinate in [-1, %d) other than "
                  "entry %d of %s (%d)", A->poly_jdx, k, v, sys->N, k, A->poly_idx, S->idx[k]);
    S->jdx[k] = (int)v;
  }
  sys->sep_jdx = S->jdx;
  if (S->sp && (rc = phgmg_ph_sparse_sep_jdx(S->sp, nt, S->jdx, NULL, sys)) != PHGMG_OK)
    return fail("%s (--poly-jdx): %s%s", A->poly_jdx, phgmg_result_string(rc),
                rc == PHGMG_ERR_SIZE ? " (a spring's two coordinates lie farther apart than the sparse model's band: "
                                       "give the spring's linear stiffness in --Q so that the ordering keeps them close)" : "");
  return 0;
}

/* The exp-polynomial family of the separable part from --potential, or
   --poly (vector: shared; (terms, d+1): per term) and --exp ((n_exp, 2):
   shared; (terms, 2 n_exp): per term), into sys (row-major per term). */
static int load_family(const reduce_args *A, reduce_state *S, phgmg_ph_system *sys, int nt) {
  int deg = 0, ne = 0, per_p = 0, per_e = 0, t, j, k;
  if (A->potential) {
    named_potential(A->potential, S->named, &deg, &ne); /* checked by parse_reduce */
    sys->poly_deg = deg; sys->poly = S->named; sys->nexp = ne; sys->expo = S->named + deg + 1;
    return 0;
  }
  if (A->poly) {
    if (mat_load(&S->poly, "--poly", A->poly)) return 1;
    per_p = !is_vector(&S->poly);
    if (per_p && S->poly.rows != nt)
      return fail("%s (--poly): expected a vector of d+1 coefficients or a (%d, d+1) matrix, got %s", A->poly, nt,
                  shape_str(&S->poly));
    deg = (per_p ? S->poly.cols : S->poly.rows * S->poly.cols) - 1;
    if (deg < 0 || deg > 32) return fail("%s (--poly): degree %d; expected 0..32", A->poly, deg);
  }
  if (A->expf) {
    if (mat_load(&S->ex, "--exp", A->expf)) return 1;
    /* (terms, 2 n_exp) is per term; a (terms, 2) matrix is ambiguous for up to 8
       terms and is then per term only beside a per-term --poly */
    per_e = S->ex.rows == nt && S->ex.cols % 2 == 0 && (S->ex.cols != 2 || nt > 8 || per_p);
    ne = per_e ? S->ex.cols / 2 : S->ex.rows;
    if ((!per_e && S->ex.cols != 2) || ne < 1 || ne > 8)
      return fail("%s (--exp): expected (n_exp, 2) pairs (a, b) or a (%d, 2 n_exp) matrix, 1 <= n_exp <= 8, got %s",
                  A->expf, nt, shape_str(&S->ex));
  }
  sys->phi_nfun = (per_p || per_e) ? nt : 0;
  t = sys->phi_nfun ? nt : 1;
  S->fpoly = (double *)calloc((size_t)t * (size_t)(deg + 1), sizeof(double));
  S->fexp = (double *)calloc((size_t)t * 2 * (size_t)(ne ? ne : 1), sizeof(double));
  if (!S->fpoly || !S->fexp) return fail("out of memory");
  for (k = 0; k < t; ++k) {   /* row-major per function: mat is column-major */
    for (j = 0; A->poly && j <= deg; ++j)
      S->fpoly[(size_t)k * (deg + 1) + j] = per_p ? S->poly.a[k + (size_t)j * S->poly.rows] : S->poly.a[j];
    for (j = 0; j < ne; ++j) {
      S->fexp[(size_t)k * 2 * ne + 2 * j] = per_e ? S->ex.a[k + (size_t)(2 * j) * S->ex.rows] : S->ex.a[j];
      S->fexp[(size_t)k * 2 * ne + 2 * j + 1] =
          per_e ? S->ex.a[k + (size_t)(2 * j + 1) * S->ex.rows] : S->ex.a[j + S->ex.rows];
    }
  }
  if (deg < 1 && ne == 0) return fail("--poly: a nonlinear part needs degree >= 1 or --exp");
  sys->poly_deg = deg; sys->poly = S->fpoly; sys->nexp = ne; sys->expo = ne ? S->fexp : NULL;
  return 0;
}

static void reduce_cleanup(reduce_state *S) {
  phgmg_balanced_cache_free(&S->bcache, NULL);
  free(S->ss.A); free(S->ss.B); free(S->ss.C); free(S->ss.D); free(S->ss.hsv); free(S->ss.T);
  mat_free(&S->J); mat_free(&S->R); mat_free(&S->B); mat_free(&S->Q); mat_free(&S->E); mat_free(&S->Pm); mat_free(&S->Sm); mat_free(&S->Nm); mat_free(&S->Dm); mat_free(&S->refm);
  free(S->di); free(S->dj); free(S->dlaw); mat_free(&S->X);
  mat_free(&S->poly); mat_free(&S->pidx); mat_free(&S->pjdx); mat_free(&S->pw); mat_free(&S->ex); mat_free(&S->in.tab);
  { int k; for (k = 0; k < 16; ++k) { mat_free(&S->tin[k].tab); mat_free(&S->Xs[k]); mat_free(&S->xinp[k].tab); } }
  free(S->Xcat);
  free(S->idx); free(S->jdx); free(S->fpoly); free(S->fexp); free(S->Xsim); free(S->Ysim); free(S->V0);
  cli_csc_free(&S->cJ); cli_csc_free(&S->cR); cli_csc_free(&S->cQ); cli_csc_free(&S->cE);
  phgmg_ph_sparse_destroy(S->sp); free(S->Xperm); free(S->Uord);
  phgmg_dae_destroy(S->dae); free(S->Xres);
  phgmg_reduced_destroy(S->red);
  stage_abort(&S->sg); /* after a failure: no output of this run stays */
  if (S->models) {
    int k;
    for (k = 0; k < S->nmodels; ++k) { phgmg_reduced_destroy(S->models[k].red); stage_abort(&S->models[k].sg); }
    free(S->models);
  }
  stage_abort(&S->sweep_sg);
  stage_abort(&S->dirs);
  phgmg_study_destroy(S->study);
  g_inputs = NULL;
  paths_free(&S->pin); paths_free(&S->pout);
}

/* The fields NAME_<field>.npy a run may write. */
static const char *const all_fields[] = {"Bh", "Qh", "K", "G00", "G01", "G10", "G11", "Q01", "Q11", "Ms",
                                         "P0", "P1", "w", "poly", "expo", "Phi", "Gam", "SX", "SU", "PD", "V0", "V2",
                                         "M", "A", "B", "C", "D", "snapshots", "fom_y", NULL};

/* 1 for the arrays of the state-space form (--form ss) among all_fields. */
static int ss_field(const char *f) { return f[0] >= 'A' && f[0] <= 'D' && !f[1]; }

/* The arrays an earlier run recorded as its own in DIR/NAME.json ("arrays":
   {"NAME_<field>.npy": [rows, cols], ...}), those of the form NAME_<field>.npy
   with a known field only, into rec. Nothing when there is no such record. */
static void read_record(const char *dir, const char *name, outlist *rec) {
  char path[4096 + 256], *text, *p, *end;
  FILE *f;
  long n;
  memset(rec, 0, sizeof *rec);
  snprintf(path, sizeof path, "%s/%s.json", dir, name);
  if (!(f = fopen(path, "rb"))) return;
  if (fseek(f, 0, SEEK_END) != 0 || (n = ftell(f)) <= 0 || n > (1L << 20) || fseek(f, 0, SEEK_SET) != 0 ||
      !(text = (char *)malloc((size_t)n + 1))) { fclose(f); return; }
  n = (long)fread(text, 1, (size_t)n, f);
  fclose(f);
  text[n] = '\0';
  p = strstr(text, "\"arrays\": {");
  end = p ? strchr(p, '}') : NULL;
  if (p) p = strchr(p, '{');
  while (p && end && rec->n < 48) { /* "key": [rows, cols], ... up to the closing brace */
    char *q = strchr(p, '"'), *e;
    int k;
    if (!q || q > end || !(e = strchr(q + 1, '"')) || e > end) break;
    *e = '\0';
    ++q;
    for (k = 0; all_fields[k]; ++k) {
      char want[128];
      snprintf(want, sizeof want, "%s_%s.npy", name, all_fields[k]);
      if (!strcmp(q, want) && strlen(want) < sizeof rec->names[0]) { strcpy(rec->names[rec->n++], want); break; }
    }
    p = strchr(e + 1, ']');
  }
  free(text);
}

/* Remove the arrays an earlier run recorded (rec, read before this run's
   record replaced it) that this run (ol) did not write, e.g. after another
   method -- never an input of this run, only regular files. */
static void remove_stale(const char *dir, const outlist *rec, const outlist *ol) {
  char path[4096 + 256];
  struct stat st;
  int k, i, mine;
  for (k = 0; k < rec->n; ++k) {
    for (i = 0, mine = 0; i < ol->n && !mine; ++i) mine = !strcmp(ol->names[i], rec->names[k]);
    snprintf(path, sizeof path, "%s/%s", dir, rec->names[k]);
    if (mine || (g_inputs && paths_find(g_inputs, path) >= 0)) continue;
    if (lstat(path, &st) == 0 && S_ISREG(st.st_mode) && remove(path) == 0)
      progress("removed %s (an array of an earlier run, not written by this one)", path);
  }
}

/* The GL3 stage-matrix solver phgmg_ph_sparse_create chose, for the log. */
static const char *sparse_solver_desc(const phgmg_ph_sparse_info *inf) {
  static char buf[256];
  if (inf->solver == PHGMG_SOLVER_SPARSE_LU && inf->colperm > 0)
    snprintf(buf, sizeof buf, "sparse LU (%d columns matched to large entries of E, and of (J - R) Q on "
             "algebraic rows; %d states condensed, nested dissection, %d supernodes, %.3g factor entries vs "
             "%.3g banded)", inf->colperm, inf->condensed,
             inf->supernodes, inf->lu_sparse, inf->lu_band);
  else if (inf->solver == PHGMG_SOLVER_SPARSE_LU)
    snprintf(buf, sizeof buf, "sparse LU (%d states condensed, nested dissection, %d supernodes, %.3g factor "
             "entries vs %.3g banded)", inf->condensed, inf->supernodes, inf->lu_sparse, inf->lu_band);
  else if (inf->lu_sparse > 0.0)
    snprintf(buf, sizeof buf, "band LU (%.3g factor entries; sparse LU would need %.3g)", inf->lu_band, inf->lu_sparse);
  else
    snprintf(buf, sizeof buf, "band LU (%.3g factor entries)", inf->lu_band);
  return buf;
}

/* A simulation whose sparse LU gave up its static pivots for the band LU says so. */
static void note_band_fallback(const phgmg_gl3_stats *st) {
  if (st->band_fallback)
    progress("  note: the sparse LU's static pivots failed on this model; the stage systems were solved by the "
             "band LU with partial pivoting instead (slower, memory O(N kb))");
}

static int e_zero_lines(const reduce_state *S, int N, int *zr, int *zc, int *dk, int *dl);

/* An index-one sparse model (zero rows and columns of --E-coo): simulate
   steps the DAE on the sparse pencil (the sparse LU, S->dae_direct); reduce
   condenses the algebraic lines sparsely (phgmg_dae_create on the sparse LU,
   no limit on them). */
static int sparse_dae_solver(const reduce_args *A, reduce_state *S, phgmg_ph_sparse_info *inf) {
  int zr = 0, zc = 0, want;
  phgmg_result rc;
  if (!A->Ecoo || A->dampf || e_zero_lines(S, phgmg_ph_sparse_system(S->sp)->N, &zr, &zc, NULL, NULL) == 0) {
    S->dae_direct = 0;
    return 0;
  }
  want = PHGMG_SOLVER_SPARSE_LU;
  if (inf->solver != want && (rc = phgmg_ph_sparse_set_solver(S->sp, want, inf)) != PHGMG_OK)
    return fail("sparse J, R, Q, E: %s solver: %s", want == PHGMG_SOLVER_BAND ? "band" : "sparse LU",
                phgmg_result_string(rc));
  S->dae_direct = S->dae_direct && inf->solver == PHGMG_SOLVER_SPARSE_LU;
  return 0;
}

/* The sparse system (--J-coo, --R-coo, --Q-coo, --B) into S->sp and sys. */
static int load_sparse_system(const reduce_args *A, reduce_state *S, phgmg_ph_system *sys) {
  phgmg_ph_sparse_info inf;
  phgmg_result rc;
  double t0;
  int N, m;
  if (mat_load(&S->B, "--B", A->B)) return 1;
  N = S->B.rows;
  if (S->B.ndim == 0 || N < 1 || S->B.cols < 1 || S->B.cols > N)
    return fail("%s (--B): expected shape (N, m) with 1 <= m <= N, or (N,), got %s", A->B, shape_str(&S->B));
  m = S->B.cols;
  if (load_coo(&S->cJ, "--J-coo", A->Jcoo, N) || load_coo(&S->cR, "--R-coo", A->Rcoo, N) ||
      load_coo(&S->cQ, "--Q-coo", A->Qcoo, N) || (A->Ecoo && load_coo(&S->cE, "--E-coo", A->Ecoo, N)))
    return 1;
  if ((double)N >= 20000.0) progress("ordering the sparse system (N = %d) and analysing its stage solver", N);
  t0 = now_s();
  rc = phgmg_ph_sparse_create_e(&S->sp, N, m, &S->cJ.A, &S->cR.A, &S->cQ.A, A->Ecoo ? &S->cE.A : NULL, S->B.a,
                                NULL, &inf, NULL);
  if (now_s() - t0 >= 1.0) progress("  done in %.1f s", now_s() - t0);
  if (rc != PHGMG_OK) return fail("sparse J, R, Q%s: %s", A->Ecoo ? ", E" : "", phgmg_result_string(rc));
  if (sparse_dae_solver(A, S, &inf)) return 1;
  *sys = *phgmg_ph_sparse_system(S->sp);
  progress("sparse J, R, Q: N = %d, %ld stored entries; half-bandwidth %d (given order %d, reverse "
           "Cuthill-McKee %d)%s", N, inf.nnz, inf.kb, inf.kb_input, inf.kb_rcm,
           inf.wide && inf.solver != PHGMG_SOLVER_SPARSE_LU ? "; wide band (kb > N/4): dense .npy input would be as fast" : "");
  progress("  stage solver: %s", sparse_solver_desc(&inf));
  return 0;
}

/* An index-one model's n x cols array in the full coordinates (N x cols, into
   *buf): snapshots as consistent states (lifted with the runs' inputs, or
   the given --X states), bases with zero rows at the algebraic variables
   (they follow from the constraints, not from the basis). */
static const double *full_rows(reduce_state *S, const double *M, int cols, int lift, double **buf) {
  const int N = S->full.N, n = S->sys.N;
  double *u = NULL;
  int j, r = 0, j0 = 0;
  if (lift && S->Xgiven) return S->Xgiven;
  *buf = (double *)calloc((size_t)N * (size_t)cols + 1, sizeof(double));
  u = (double *)calloc((size_t)S->sys.m, sizeof(double));
  if (!*buf || !u) { free(u); return NULL; }
  for (j = 0; j < cols; ++j) {
    double *x = *buf + (size_t)j * N;
    if (lift) {   /* column j of run r: t = (j - j0) dt */
      while (r + 1 < S->nrun && j - j0 > S->runs[r].nsteps) { j0 += S->runs[r].nsteps + 1; ++r; }
      if (S->runs[r].u) S->runs[r].u((j - j0) * S->runs[r].dt, u, S->runs[r].user);
      phgmg_dae_lift(S->dae, M + (size_t)j * n, u, x);
    } else {
      phgmg_dae_embed(S->dae, M + (size_t)j * n, x);
    }
  }
  free(u);
  return *buf;
}

/* write_field of an N x cols full-dimension array, in the user's ordering. */
static int write_user_field_full(const reduce_args *A, reduce_state *S, const char *field, const double *M, int cols,
                                 outlist *ol) {
  const int N = S->sp ? phgmg_ph_sparse_system(S->sp)->N : 0;
  if (!S->sp) return write_field(A->out, A->name, field, M, S->J.rows, cols, ol, &S->sg);
  free(S->Uord);
  S->Uord = (double *)malloc(sizeof(double) * (size_t)N * (size_t)cols + 1);
  if (!S->Uord) return fail("out of memory");
  phgmg_ph_sparse_to_user_order(S->sp, cols, M, N, S->Uord, N);
  return write_field(A->out, A->name, field, S->Uord, N, cols, ol, &S->sg);
}

static int write_user_field(const reduce_args *A, reduce_state *S, const char *field, const double *M, int cols,
                            outlist *ol) {
  double *ex = NULL;
  if (S->dae) {
    int st;
    if (!(M = full_rows(S, M, cols, !strcmp(field, "snapshots"), &ex))) { free(ex); return fail("out of memory"); }
    st = write_user_field_full(A, S, field, M, cols, ol);
    free(ex);
    return st;
  }
  return write_user_field_full(A, S, field, M, cols, ol);
}

/* The first steps of each --X run must follow from its first snapshot and
   its --X-input: the full model is simulated over up to X_CHECK_STEPS steps
   and compared with the snapshots. The mismatch is measured relative to the
   change of the snapshots over those steps; above X_CHECK_TOL (loose enough
   for snapshots from another integrator of moderate accuracy, far below the
   mismatch of another input or another step) the run is refused. */
#define X_CHECK_STEPS 5
#define X_CHECK_TOL 0.1
static int check_x_inputs(const reduce_args *A, reduce_state *S, int N, int m) {
  double *W = (double *)malloc(sizeof(double) * ((size_t)N + (size_t)m) * (X_CHECK_STEPS + 1));
  phgmg_gl3_opts go;
  int k, j, i, rc = 0;
  if (!W) return fail("out of memory");
  memset(&go, 0, sizeof go);
  go.tol = A->newton_tol; go.max_iter = A->newton_iter;
  for (k = 0; k < A->nx && !rc; ++k) {
    const phgmg_run *run = &S->runs[k];
    const int n = CLI_MIN(X_CHECK_STEPS, run->nsteps);
    const double *X = run->x0;
    double num = 0.0, den = 0.0, x0n = 0.0;
    phgmg_result r = phgmg_simulate(&S->sys, X, 0.0, A->dt, n, input_fn, run->user, &go, W, W + (size_t)N * (n + 1),
                                    NULL, NULL, NULL, NULL);
    if (r != PHGMG_OK) {
      rc = fail("%s (--X-input %s): the full model cannot be simulated from the run's first snapshot: %s",
                A->xs[k], A->xin[k], phgmg_result_string(r));
      break;
    }
    for (i = 0; i < N; ++i) x0n = CLI_MAX(x0n, fabs(X[i]));
    for (j = 1; j <= n; ++j) {
      double dn = 0.0, dd = 0.0;
      for (i = 0; i < N; ++i) {
        const double xs = X[i + (size_t)j * N];
        dn = CLI_MAX(dn, fabs(W[i + (size_t)j * N] - xs));
        dd = CLI_MAX(dd, fabs(xs - X[i]));
      }
      num = CLI_MAX(num, dn);
      den = CLI_MAX(den, dd);
    }
    if (den == 0.0) den = x0n > 0.0 ? x0n : DBL_MIN;
    progress("--X-input check: %s from its first snapshot with %s: %d steps reproduced to %.2g (relative to the "
             "states' change)", A->xs[k], A->xin[k], n, num / den);
    if (!(num <= X_CHECK_TOL * den))
      rc = fail("%s (--X-input %s): the declared input does not reproduce the run: simulated from the first "
                "snapshot with --dt %g, the next %d states differ from the snapshots by %.3g of their change "
                "(limit %g). Give the input (and --dt) that made this run", A->xs[k], A->xin[k], A->dt, n,
                num / den, X_CHECK_TOL);
  }
  free(W);
  return rc;
}

/* The --X files (one run each) as one snapshot set in the internal ordering,
   with the runs' boundaries (and, with --X-input, their inputs) in S->runs. */
static int load_snapshot_files(const reduce_args *A, reduce_state *S, int N, int m, const double **Xo, int *nso) {
  double *X;
  size_t col = 0;
  int k, ns = 0;
  const int n = N;   /* the states reduced: an index-one model's differential part */
  N = S->dae ? S->full.N : N;
  for (k = 0; k < A->nx; ++k) {
    mat *F = k ? &S->Xs[k] : &S->X;
    if (mat_load(F, "--X", A->xs[k])) return 1;
    if (F->ndim != 2 || F->rows != N || F->cols < 2)
      return fail("%s (--X): expected shape (%d, ns), ns >= 2 snapshots as columns (N = %d from %s), got %s",
                  A->xs[k], N, N, A->J ? A->J : A->B, shape_str(F));
    if (F->cols > INT_MAX - ns) return fail("%s (--X): too many snapshots in all", A->xs[k]);
    ns += F->cols;
  }
  if (A->nx == 1) X = S->X.a;
  else {   /* the runs one after the other */
    S->Xcat = X = (double *)malloc(sizeof(double) * (size_t)N * (size_t)ns);
    if (!X) return fail("out of memory for %d snapshots of size %d", ns, N);
    for (k = 0; k < A->nx; ++k) {
      const mat *F = k ? &S->Xs[k] : &S->X;
      memcpy(X + col * (size_t)N, F->a, sizeof(double) * (size_t)N * (size_t)F->cols);
      col += (size_t)F->cols;
    }
  }
  if (S->sp) { /* into the internal (banded) ordering */
    S->Xperm = (double *)malloc(sizeof(double) * (size_t)N * (size_t)ns);
    if (!S->Xperm) return fail("out of memory");
    phgmg_ph_sparse_to_banded_order(S->sp, ns, X, N, S->Xperm, N);
    X = S->Xperm;
  }
  if (S->dae) {   /* the given states are kept for --save-snapshots */
    S->Xgiven = X;
    S->Xres = (double *)malloc(sizeof(double) * (size_t)n * (size_t)ns + 1);
    if (!S->Xres) return fail("out of memory");
    for (k = 0; k < ns; ++k) phgmg_dae_restrict(S->dae, X + (size_t)k * N, S->Xres + (size_t)k * n);
    X = S->Xres;
  }
  N = n;
  /* Run boundaries: with the inputs known (--X-input) every use (--lambda auto
     simulates the runs from their first snapshot); without, only the folds of
     --lambda cv (a run with an unknown input must not be simulated as u = 0). */
  if (A->nxin || (A->nx > 1 && A->lambda_auto != 1)) {
    col = 0;
    for (k = 0; k < A->nx; ++k) {
      const int c = k ? S->Xs[k].cols : S->X.cols;
      memset(&S->runs[k], 0, sizeof S->runs[k]);
      if (A->nxin) {
        int e = input_setup(&S->xinp[k], "--X-input", A->xin[k], A->amp, m, A->dt, (c - 1) * A->dt);
        if (e) return e;
        S->runs[k].u = input_fn; S->runs[k].user = &S->xinp[k];
        S->runs[k].x0 = X + col * (size_t)N;
      }
      S->runs[k].dt = A->dt; S->runs[k].nsteps = c - 1;
      col += (size_t)c;
    }
    S->nrun = A->nx;
  }
  if (A->nxin) {
    const cli_input *ins[16];
    for (k = 0; k < A->nx; ++k) {
      ins[k] = &S->xinp[k];
      input_covers(&S->xinp[k], A->xin[k], "--X-input", S->runs[k].nsteps * A->dt);
    }
    note_ports(ins, A->nx, m);
    if ((k = check_x_inputs(A, S, N, m)) != 0) return k;
  }
  for (k = 0; k < A->nx; ++k)
    progress("snapshots: %s, %d states%s%s", A->xs[k], k ? S->Xs[k].cols : S->X.cols, A->nxin ? ", input " : "",
             A->nxin ? A->xin[k] : "");
  *Xo = X;
  *nso = ns;
  return 0;
}

/* --P (N x m), --S, --N (m x m) into sys; with sparse input P's rows are
   moved to the internal ordering. */
static int load_feedthrough(const reduce_args *A, reduce_state *S, phgmg_ph_system *sys) {
  const int N = sys->N, m = sys->m;
  if (A->Pf) {
    if (mat_load(&S->Pm, "--P", A->Pf)) return 1;
    if (S->Pm.ndim == 0 || S->Pm.rows != N || S->Pm.cols != m)
      return fail("%s (--P): expected shape (%d, %d) (N x m, like B), got %s", A->Pf, N, m, shape_str(&S->Pm));
    if (S->sp) {
      double *t = (double *)malloc(sizeof(double) * (size_t)N * m + 1);
      if (!t) return fail("out of memory");
      phgmg_ph_sparse_to_banded_order(S->sp, m, S->Pm.a, N, t, N);
      memcpy(S->Pm.a, t, sizeof(double) * (size_t)N * m);
      free(t);
    }
    sys->P = S->Pm.a;
  }
  if (A->Sf) {
    if (mat_load(&S->Sm, "--S", A->Sf)) return 1;
    if (S->Sm.rows * S->Sm.cols != m * m || (m > 1 && (S->Sm.rows != m || S->Sm.cols != m)))
      return fail("%s (--S): expected shape (%d, %d) (m x m), got %s", A->Sf, m, m, shape_str(&S->Sm));
    sys->S = S->Sm.a;
  }
  if (A->Nf) {
    if (mat_load(&S->Nm, "--N", A->Nf)) return 1;
    if (S->Nm.rows * S->Nm.cols != m * m || (m > 1 && (S->Nm.rows != m || S->Nm.cols != m)))
      return fail("%s (--N): expected shape (%d, %d) (m x m), got %s", A->Nf, m, m, shape_str(&S->Nm));
    sys->Nskew = S->Nm.a;
  }
  return 0;
}

/* --ref FILE: the reference state xbar, N values (shape (N,) or (N, 1)), in
   the files' ordering (sparse input: mapped to the internal one). */
static int load_ref(const reduce_args *A, reduce_state *S, int N) {
  if (!A->ref_file) return 0;
  if (mat_load(&S->refm, "--ref", A->ref_file)) return 1;
  if (S->refm.ndim == 0 || S->refm.rows != N || S->refm.cols != 1)
    return fail("%s (--ref): expected shape (%d,) or (%d, 1) (one value per state), got %s", A->ref_file, N, N,
                shape_str(&S->refm));
  if (S->sp) {
    double *t = (double *)malloc(sizeof(double) * (size_t)N + 1);
    if (!t) return fail("out of memory");
    phgmg_ph_sparse_to_banded_order(S->sp, 1, S->refm.a, N, t, N);
    memcpy(S->refm.a, t, sizeof(double) * (size_t)N);
    free(t);
  }
  return 0;
}

/* A state index of the user's ordering in the internal one (sparse input:
   the RCM reordering, found by mapping the unit vector). */
static int cli_internal_index(const reduce_state *S, int N, int i, double *e, double *t) {
  int k;
  if (!S->sp) return i;
  for (k = 0; k < N; ++k) e[k] = k == i ? 1.0 : 0.0;
  phgmg_ph_sparse_to_banded_order(S->sp, 1, e, N, t, N);
  for (k = 0; k < N; ++k) if (t[k] != 0.0) return k;
  return -1;
}

/* --dampers FILE: k x 4 (or 4 values for one damper), rows (i, j, c1, c3):
   a damper on s = z_i - z_j (j = -1: s = z_i), force c1 s + c3 s^3,
   0-based state indices (of the files' ordering). */
static int load_dampers(const reduce_args *A, reduce_state *S, phgmg_ph_system *sys) {
  const int N = sys->N;
  double *e, *t;
  int k, nd;
  if (!A->dampf) return 0;
  if (mat_load(&S->Dm, "--dampers", A->dampf)) return 1;
  nd = S->Dm.rows * S->Dm.cols == 4 ? 1 : S->Dm.rows;
  if (S->Dm.rows * S->Dm.cols != 4 * nd || (nd > 1 && S->Dm.cols != 4) || nd < 1)
    return fail("%s (--dampers): expected shape (k, 4), rows (i, j, c1, c3), got %s", A->dampf, shape_str(&S->Dm));
  S->di = (int *)malloc(sizeof(int) * (size_t)nd);
  S->dj = (int *)malloc(sizeof(int) * (size_t)nd);
  S->dlaw = (double *)malloc(sizeof(double) * 4 * (size_t)nd);
  e = (double *)malloc(sizeof(double) * 2 * (size_t)N);
  if (!S->di || !S->dj || !S->dlaw || !e) { free(e); return fail("out of memory"); }
  t = e + N;
  for (k = 0; k < nd; ++k) {
    const double *row = S->Dm.a, vi = row[k], vj = row[k + nd], c1 = row[k + 2 * nd], c3 = row[k + 3 * nd];
    if (!(vi >= 0.0 && vi < N && vi == floor(vi)) || !(vj >= -1.0 && vj < N && vj == floor(vj)) || vi == vj) {
      free(e);
      return fail("%s (--dampers): row %d: i = %g, j = %g; expected integer states in [0, %d), j = -1 for one state, i != j",
                  A->dampf, k, vi, vj, N);
    }
    S->di[k] = cli_internal_index(S, N, (int)vi, e, t);
    S->dj[k] = vj < 0.0 ? -1 : cli_internal_index(S, N, (int)vj, e, t);
    S->dlaw[4 * k] = 0.0; S->dlaw[4 * k + 1] = c1; S->dlaw[4 * k + 2] = 0.0; S->dlaw[4 * k + 3] = c3;
  }
  free(e);
  sys->ndamp = nd; sys->damp_i = S->di; sys->damp_j = S->dj;
  sys->damp_deg = 3; sys->damp_nfun = nd; sys->damp_poly = S->dlaw;
  progress("dampers: %s, %d (force c1 s + c3 s^3)", A->dampf, nd);
  return 0;
}

/* Which condition of the feedthrough failed (rc: phgmg_ph_validate's code),
   naming the files given: N not skew, S not symmetric or not positive
   semidefinite, or P too large for R and S. 1 after the message. */
static int explain_feedthrough(const reduce_args *A, const reduce_state *S, phgmg_result rc) {
  char files[3 * 4096 + 8] = "", opts[32] = "", why[256];
  const char *const fl[3] = {A->Pf, A->Sf, A->Nf}, *const ol[3] = {"--P", "--S", "--N"};
  const int m = S->B.cols;
  int k;
  for (k = 0; k < 3; ++k)
    if (fl[k]) {
      snprintf(files + strlen(files), sizeof files - strlen(files), "%s%s", files[0] ? ", " : "", fl[k]);
      snprintf(opts + strlen(opts), sizeof opts - strlen(opts), "%s%s", opts[0] ? ", " : "", ol[k]);
    }
  if (rc != PHGMG_ERR_FEEDTHROUGH) return fail("%s (%s): %s", files, opts, phgmg_result_string(rc));
  if (A->Nf && sym_defect(S->Nm.a, m, 1.0) > 1e-12)
    snprintf(why, sizeof why, "N is not skew-symmetric (||N + N^T||_F / ||N||_F = %.3g)", sym_defect(S->Nm.a, m, 1.0));
  else if (A->Sf && sym_defect(S->Sm.a, m, -1.0) > 1e-12)
    snprintf(why, sizeof why, "S is not symmetric (||S - S^T||_F / ||S||_F = %.3g)", sym_defect(S->Sm.a, m, -1.0));
  else {
    double w[64], c[64 * 64];
    int i;
    if (A->Sf && m <= 64) {
      for (i = 0; i < m * m; ++i) c[i] = S->Sm.a[i];
      if (phgmg_sym_eig(m, c, m, w, NULL, 0) == PHGMG_OK && w[0] < -1e-12 * CLI_MAX(fabs(w[0]), fabs(w[m - 1]))) {
        snprintf(why, sizeof why, "S is not positive semidefinite (smallest eigenvalue %.3g)", w[0]);
        return fail("%s (%s): the feedthrough is not valid: %s", files, opts, why);
      }
    }
    snprintf(why, sizeof why, "[[R, P], [P^T, S]] is not positive semidefinite: P is too large for the "
             "dissipation R and S (a port's P needs damping R where P acts and S on the port)");
  }
  return fail("%s (%s): the feedthrough is not valid: %s", files, opts, why);
}

static int e_zero_lines(const reduce_state *S, int N, int *zr, int *zc, int *dk, int *dl);

/* A failed validation whose cause is the dampers (1: reported): a damper
   on an algebraic line of E, or J - R - L singular (L the dampers'
   linearisation at 0) while J - R alone is not. */
static int explain_dampers(const reduce_args *A, const reduce_state *S, const phgmg_ph_system *sys,
                           phgmg_result rc) {
  int zr = 0, zc = 0, dk = -1, dl = -1;
  if (rc == PHGMG_ERR_SINGULAR) {
    phgmg_ph_system t = *sys;
    double rc0 = 0.0;
    t.ndamp = 0;
    if (phgmg_ph_validate(&t, 0.0, &rc0, NULL) != PHGMG_OK) return 0;
    fail("%s (--dampers): J - R minus the dampers' linear part at 0 (their c1 terms) is singular to working "
         "precision (J - R alone: rcond %.3g): a damper's c1 is out of scale with the model", A->dampf, rc0);
    return 1;
  }
  if (rc != PHGMG_ERR_UNSUPPORTED || !sys->E) return 0;
  e_zero_lines(S, sys->N, &zr, &zc, &dk, &dl);
  if (dk < 0) return 0;
  fail("%s (--dampers): row %d: the damper acts on state %d, an algebraic line of E (a zero row or column of "
       "%s): dampers must act on differential states only", A->dampf, dk, dl, A->E ? A->E : A->Ecoo);
  return 1;
}

/* The algebraic lines of a linear model exceed what the (dense) condensation takes. */
static int unsupported_algebraic(const reduce_args *A, const reduce_state *S, int N) {
  int zr = 0, zc = 0;
  e_zero_lines(S, N, &zr, &zc, NULL, NULL);
  if (A->Ecoo)   /* sparse input is condensed sparsely, without a limit: not the cause */
    return fail("%s (--E-coo): %d algebraic equations and variables (zero rows and columns of E): %s",
                A->Ecoo, zr, phgmg_result_string(PHGMG_ERR_UNSUPPORTED));
  return fail("%s (--E): %d algebraic equations and variables (zero rows and columns of E): the condensation to "
              "the differential states of a dense model (reduce, validate, simulate) is dense in the algebraic "
              "lines and takes at most 4096 of them; give the model as sparse COO files (--J-coo ... --E-coo): "
              "reduce then condenses it sparsely and simulate steps the DAE itself, without that limit", A->E, zr);
}

/* A failed validation of a descriptor model explained in terms of E (1:
   reported, 0: not a cause this explains). */
static int explain_descriptor(const reduce_args *A, const reduce_state *S, const phgmg_ph_system *sys,
                              phgmg_result rc) {
  const char *ef = A->E ? A->E : A->Ecoo, *qf = A->Q ? A->Q : A->Qcoo;
  int zr = 0, zc = 0;
  switch (rc) {
    case PHGMG_ERR_E_SINGULAR:
      return fail("%s (%s): %s%s", ef, A->E ? "--E" : "--E-coo", phgmg_result_string(rc),
                  e_zero_lines(S, sys->N, &zr, &zc, NULL, NULL) == sys->N
                      ? " (every row and column of E is zero: no differential state)"
                  : A->Ecoo && zr + zc == 0 ? " (a singular E without zero rows and columns is taken in dense "
                                              "form only: give it as --E)"
                  : zr + zc == 0 && (sys->ndamp || sys->nl != PHGMG_NL_NONE)
                      ? " (a singular E without zero rows and columns is taken with a quadratic energy and no "
                        "dampers only)"
                  : zr != zc ? " (its zero rows and zero columns differ in number)" : "");
    case PHGMG_ERR_EQ_NOT_SYMMETRIC:
    case PHGMG_ERR_EQ_NOT_PD: return fail("%s, %s (--E, --Q): %s", ef, qf, phgmg_result_string(rc));
    case PHGMG_ERR_E_COUPLED: return fail("%s, %s (--E, --poly-idx): %s", ef, A->poly_idx, phgmg_result_string(rc));
    case PHGMG_ERR_UNSUPPORTED:
      if (sys->nl != PHGMG_NL_NONE || sys->ndamp)
        return fail("%s (--E): %s (a descriptor model takes a separable nonlinear part only; with algebraic lines "
                    "of E, none on them)", ef, phgmg_result_string(rc));
      return unsupported_algebraic(A, S, sys->N);
    case PHGMG_ERR_INDEX:
    case PHGMG_ERR_PENCIL:
      return fail("%s, %s, %s, %s (--E, --J, --R, --Q): %s: %s, and the equations must determine the variables "
                  "(index one)", ef, A->J ? A->J : A->Jcoo, A->R ? A->R : A->Rcoo, qf, phgmg_result_string(rc),
                  e_zero_lines(S, sys->N, &zr, &zc, NULL, NULL) > 0
                      ? "the zero rows and columns of E are algebraic equations and variables"
                      : "E is singular without zero rows or columns: the directions of its null spaces (left: "
                        "equations, right: variables) are algebraic");
    default: break;
  }
  return 0;
}

/* rz[i] = 1 for a zero row i, cz[j] = 1 for a zero column j of the given E
   (--E or --E-coo, the files' order). */
static void e_zero_masks(const reduce_state *S, int N, char *rz, char *cz) {
  int i, j;
  memset(rz, 1, (size_t)N); memset(cz, 1, (size_t)N);
  if (S->E.a) {
    for (j = 0; j < N; ++j)
      for (i = 0; i < N; ++i)
        if (S->E.a[i + (size_t)j * N] != 0.0) rz[i] = cz[j] = 0;
  } else if (S->cE.A.colptr) {
    for (j = 0; j < N; ++j)
      for (i = S->cE.A.colptr[j]; i < S->cE.A.colptr[j + 1]; ++i)
        if (S->cE.A.values[i] != 0.0) rz[S->cE.A.rowidx[i]] = cz[j] = 0;
  }
}

/* Zero rows (*zr) and zero columns (*zc) of the given E; returns the smaller
   count. With dampers, *dk = the first damper (row of --dampers) with a state
   on a zero line of E, *dl = that state (-1: none). */
static int e_zero_lines(const reduce_state *S, int N, int *zr, int *zc, int *dk, int *dl) {
  char *rz = (char *)malloc((size_t)N), *cz = (char *)malloc((size_t)N);
  int i, k;
  *zr = *zc = 0;
  if (dk) *dk = *dl = -1;
  if (!rz || !cz) { free(rz); free(cz); return 0; }
  e_zero_masks(S, N, rz, cz);
  for (i = 0; i < N; ++i) { *zr += rz[i]; *zc += cz[i]; }
  for (k = 0; dk && S->Dm.a && *dk < 0 && k < S->Dm.rows * S->Dm.cols / 4; ++k) {
    const int nd = S->Dm.rows * S->Dm.cols / 4, vi = (int)S->Dm.a[k], vj = (int)S->Dm.a[k + nd];
    if (rz[vi] || cz[vi]) { *dk = k; *dl = vi; }
    else if (vj >= 0 && (rz[vj] || cz[vj])) { *dk = k; *dl = vj; }
  }
  free(rz); free(cz);
  return *zr < *zc ? *zr : *zc;
}

/* The full model from the files: dense or sparse J, R, Q, B and the nonlinear
   part, checked (phgmg_ph_validate), into S->sys. */
static int condense_algebraic(const reduce_args *A, reduce_state *S);
static int load_system(const reduce_args *A, reduce_state *S) {
  phgmg_ph_system sys;
  phgmg_result rc;
  double rcond = 0.0, t_chk;
  int N, m, k;
  /* --- the system --- */
  if (A->Jcoo) {
    if (load_sparse_system(A, S, &sys)) return 1;
    N = sys.N;
    m = sys.m;
  } else {
    if (mat_load(&S->J, "--J", A->J)) return 1;
    N = S->J.rows;
    if (S->J.ndim != 2 || S->J.cols != N || N < 1)
      return fail("%s (--J): J must be a square N x N matrix, got %s", A->J, shape_str(&S->J));
    progress("J: %s, N = %d", A->J, N);
    if (mat_load(&S->R, "--R", A->R)) return 1;
    if (S->R.ndim != 2 || S->R.rows != N || S->R.cols != N)
      return fail("%s (--R): expected shape (%d, %d) (N x N, N = %d from %s), got %s", A->R, N, N, N, A->J,
                  shape_str(&S->R));
    if (mat_load(&S->Q, "--Q", A->Q)) return 1;
    if (S->Q.ndim != 2 || S->Q.rows != N || S->Q.cols != N)
      return fail("%s (--Q): expected shape (%d, %d) (N x N, N = %d from %s), got %s", A->Q, N, N, N, A->J,
                  shape_str(&S->Q));
    if (mat_load(&S->B, "--B", A->B)) return 1;
    if (S->B.ndim == 0 || S->B.rows != N || S->B.cols < 1 || S->B.cols > N)
      return fail("%s (--B): expected shape (%d, m) with 1 <= m <= %d, or (%d,), got %s", A->B, N, N, N,
                  shape_str(&S->B));
    m = S->B.cols;
    memset(&sys, 0, sizeof sys);
    sys.N = N; sys.m = m; sys.storage = PHGMG_DENSE;
    sys.J = S->J.a; sys.R = S->R.a; sys.Q = S->Q.a; sys.B = S->B.a;
    sys.nl = PHGMG_NL_NONE;
    if (A->E) {
      if (mat_load(&S->E, "--E", A->E)) return 1;
      if (S->E.ndim != 2 || S->E.rows != N || S->E.cols != N)
        return fail("%s (--E): E must be a square N x N matrix (N = %d from %s), got %s", A->E, N, A->J,
                    shape_str(&S->E));
      sys.E = S->E.a;
      progress("E: %s (descriptor model)", A->E);
    }
  }
  if (A->poly_idx) {
    int nt;
    if (mat_load(&S->pidx, "--poly-idx", A->poly_idx)) return 1;
    nt = S->pidx.rows * S->pidx.cols;
    if (!is_vector(&S->pidx) || nt < 1)
      return fail("%s (--poly-idx): expected a non-empty vector of coordinates, got %s", A->poly_idx,
                  shape_str(&S->pidx));
    S->idx = (int *)malloc(sizeof(int) * (size_t)nt);
    if (!S->idx) return fail("out of memory");
    for (k = 0; k < nt; ++k) {
      const double v = S->pidx.a[k];
      if (!(v >= 0.0 && v < (double)N && v == floor(v)))
        return fail("%s (--poly-idx): entry %d is %g; expected an integer coordinate in [0, %d)", A->poly_idx,
                    k, v, N);
      S->idx[k] = (int)v;
    }
    if (A->poly_w) {
      if (mat_load(&S->pw, "--poly-w", A->poly_w)) return 1;
      if (!is_vector(&S->pw) || S->pw.rows * S->pw.cols != nt)
        return fail("%s (--poly-w): expected a vector of %d weights (one per entry of %s), got %s", A->poly_w,
                    nt, A->poly_idx, shape_str(&S->pw));
    }
    sys.nl = PHGMG_NL_SEPARABLE;
    sys.nsep = nt;
    sys.sep_idx = S->idx;
    if (S->sp && (rc = phgmg_ph_sparse_sep_idx(S->sp, nt, S->idx, NULL, &sys)) != PHGMG_OK)
      return fail("%s (--poly-idx): %s", A->poly_idx, phgmg_result_string(rc));
    sys.sep_w = A->poly_w ? S->pw.a : NULL;
    if (A->poly_jdx && load_springs(A, S, &sys, nt)) return 1;
    if (load_family(A, S, &sys, nt) || check_bounded_below(A, &sys)) return 1;
    progress("nonlinear part: %d terms, %s, polynomial degree %d, %d exponentials%s", nt,
             A->potential ? A->potential : "exp-polynomial", sys.poly_deg, sys.nexp,
             sys.phi_nfun > 1 ? " (one function per term)" : "");
  }
  if (load_feedthrough(A, S, &sys) || load_dampers(A, S, &sys) || load_ref(A, S, sys.N)) return 1;
  if ((double)N >= 20000.0)   /* seconds of sparse factorizations: say so first */
    progress("checking the system (N = %d): symmetry, definiteness and regularity by sparse factorizations", N);
  t_chk = now_s();
  rc = phgmg_ph_validate(&sys, 0.0, &rcond, NULL);
  t_chk = now_s() - t_chk;
  if (t_chk >= 1.0) progress("  checks done in %.1f s", t_chk);
  if (sys.ndamp && rc != PHGMG_OK && explain_dampers(A, S, &sys, rc)) return 1;
  if (sys.ndamp && (rc == PHGMG_ERR_DAMPER || rc == PHGMG_ERR_SIZE || rc == PHGMG_ERR_NANINF))
    return fail("%s (--dampers): %s%s", A->dampf, phgmg_result_string(rc),
                rc == PHGMG_ERR_DAMPER ? " (c1 and c3 must be >= 0)" : rc == PHGMG_ERR_SIZE ? " (banded storage: |i - j| beyond the band)" : "");
  if (rc == PHGMG_ERR_FEEDTHROUGH || (rc == PHGMG_ERR_UNSUPPORTED && (sys.P || sys.S || sys.Nskew)))
    return explain_feedthrough(A, S, rc);
  if (rc != PHGMG_OK && sys.E && explain_descriptor(A, S, &sys, rc)) return 1;
  if (rc != PHGMG_OK && S->sp)
    return fail("the sparse system (%s, %s, %s, %s) is not valid: %s%s", A->Jcoo, A->Rcoo, A->Qcoo, A->B,
                phgmg_result_string(rc), rc == PHGMG_ERR_SINGULAR ? " (J - R singular)" : "");
  if (rc != PHGMG_OK) return explain_validate(rc, &S->J, &S->R, &S->B, &S->Q, rcond);
  progress("system: N = %d, m = %d, valid port-Hamiltonian (rcond(J - R) = %.3g)", N, m, rcond);
  S->sys = S->full = sys;
  return sys.E ? condense_algebraic(A, S) : 0;
}

/* An index-one model (E with zero rows and columns): S->sys becomes its
   condensed ODE in the differential coordinates, which is what is simulated
   for training and reduced; states written out are lifted back. */
static int condense_algebraic(const reduce_args *A, reduce_state *S) {
  phgmg_result rc;
  if (S->dae_direct) {
    int zr = 0, zc = 0;
    e_zero_lines(S, S->full.N, &zr, &zc, NULL, NULL);
    progress("algebraic constraints: E singular, %d algebraic equations and variables (index one); %s", zr,
             A->nml > 0 && !sweep_needs_snapshots(A) ? "the Gramians' solves use the whole sparse pencil (the "
             "condensed model is never formed)" : "the DAE is stepped on the sparse pencil");
    return 0;
  }
  rc = phgmg_dae_create(&S->dae, &S->full, 0.0, NULL);
  if (rc == PHGMG_ERR_UNSUPPORTED && S->full.nl == PHGMG_NL_NONE && !S->full.ndamp && !S->sp)
    return unsupported_algebraic(A, S, S->full.N);
  if (rc != PHGMG_OK) return fail("the algebraic part of the descriptor model: %s", phgmg_result_string(rc));
  if (phgmg_dae_nalg(S->dae) == 0) {
    phgmg_dae_destroy(S->dae);
    S->dae = NULL;
    return 0;
  }
  S->sys = *phgmg_dae_system(S->dae);
  if (S->refm.a) { /* --ref FILE holds full states: its differential part (rotated like the snapshots) */
    double *t = (double *)malloc(sizeof(double) * (size_t)S->sys.N + 1);
    if (!t) return fail("out of memory");
    phgmg_dae_restrict(S->dae, S->refm.a, t);
    memcpy(S->refm.a, t, sizeof(double) * (size_t)S->sys.N);
    free(t);
  }
  progress("algebraic constraints: E singular, %d algebraic equations and variables (index one); condensed to "
           "N = %d differential states%s", phgmg_dae_nalg(S->dae), S->sys.N,
           (S->sys.P || S->sys.S) && !(S->full.P || S->full.S || S->full.Nskew)
               ? " with feedthrough (a port on a constraint)" : "");

  return 0;
}

/* The largest |entry| of a loaded dense matrix or of a sparse one's values. */
static double max_abs_entry(const mat *M, const cli_csc *C) {
  double v = 0.0;
  size_t k, n = M->a ? (size_t)M->rows * (size_t)M->cols : C->cp ? (size_t)C->cp[C->A.n_cols] : 0;
  const double *a = M->a ? M->a : C->v;
  for (k = 0; k < n; ++k) v = CLI_MAX(v, fabs(a[k]));
  return v;
}

/* The step against the model's time scale, before a full-model run. GL3's
   stage matrices are sigma E - (J - R) Q with sigma ~ 1/dt: beyond
   dt max|J - R| max|Q| / max|E| = 1/eps the mass term is below round-off
   (the step resolves nothing; further on the stage equations leave the
   double range and the output is flushed to zero or NaN), and the times
   t = n dt must stay in the double range. 0, or 1 after a message. */
#define DT_SCALE_MAX (1.0 / DBL_EPSILON)
static int check_dt_scale(const reduce_args *A, const reduce_state *S) {
  const double jr = CLI_MAX(max_abs_entry(&S->J, &S->cJ), max_abs_entry(&S->R, &S->cR));
  const double q = max_abs_entry(&S->Q, &S->cQ);
  const double e = (A->E || A->Ecoo) ? max_abs_entry(&S->E, &S->cE) : 1.0;
  const double scale = e > 0.0 ? jr * q / e : 0.0;
  if (!((double)A->steps * A->dt < DBL_MAX / 4.0))
    return fail("--dt %g with --steps %d: the times t = n dt leave the double range", A->dt, A->steps);
  if (scale > 0.0 && !(A->dt <= DT_SCALE_MAX / scale))
    return fail("--dt %g: the step is %.3g times the model's time scale 1 / (max|J - R| max|Q| / max|E|) = %.3g, "
                "beyond what a double resolves (1/eps = %.3g): the stage equations lose the mass term, and the "
                "output is round-off, flushed to zero or NaN; use --dt <= %.3g", A->dt, A->dt * scale, 1.0 / scale,
                DT_SCALE_MAX, DT_SCALE_MAX / scale);
  return 0;
}

/* What the reduction does not take, explained up front: feedthrough or
   dampers with gmg-qm or with a reference state (--ref). The feedthrough may
   be the user's (--P, --S, --N) or come from a port on an algebraic line of
   E (the condensed model's). 0, or 1 after a message. */
static int check_extras(const reduce_args *A, const reduce_state *S) {
  const phgmg_ph_system *c = &S->sys;
  const int feed = c->P || c->S || c->Nskew, mine = A->Pf || A->Sf || A->Nf;
  char what[4096 + 160];
  if (!feed && !c->ndamp) return 0;
  if (feed && !mine)
    snprintf(what, sizeof what, "feedthrough from a port on an algebraic line of E (%s: the condensed model "
             "carries (S + N) u)", A->E ? A->E : A->Ecoo);
  else if (feed)
    snprintf(what, sizeof what, "feedthrough (--P, --S, --N)");
  else
    snprintf(what, sizeof what, "dampers (--dampers %s)", A->dampf);
  if (S->method == PHGMG_METHOD_GMG_QM)
    return fail("gmg-qm does not take %s; use gmg-pod, sp1 or sp2%s", what, A->ref ? " (without --ref)" : "");
  if (A->ref != PHGMG_REF_NONE)
    return fail("--ref %s does not go with %s: the reference state's terms are not derived for them; use "
                "--ref none", A->ref == PHGMG_REF_MEAN ? "mean" : A->ref_file, what);
  return 0;
}

/* 1 if the n values of a are all zero. */
static int all_zero(const double *a, size_t n) {
  size_t i;
  for (i = 0; i < n; ++i)
    if (a[i] != 0.0) return 0;
  return 1;
}

/* The largest |entry| of n doubles. */
static double max_abs_n(const double *a, size_t n) {
  double v = 0.0;
  size_t k;
  for (k = 0; k < n; ++k) v = CLI_MAX(v, fabs(a[k]));
  return v;
}

/* phgmg_reduce's PHGMG_ERR_RANK explained: every port through a constraint
   (an index-one model's condensed B = 0), one port through a constraint (its
   condensed column of B zero to round-off: info->rank_port) or another port
   dependent, a --lambda too small for the quadratic fit, else the snapshots
   (src) or B. */
static int explain_rank(const reduce_args *A, const reduce_state *S, int method, const char *src,
                        const phgmg_reduce_info *info) {
  const char *what = phgmg_result_string(PHGMG_ERR_RANK);
  const int p = info->rank_port;
  if (S->dae && all_zero(S->sys.B, (size_t)S->sys.N * (size_t)S->sys.m))
    return fail("reduction failed: %s: every port of %s acts through an algebraic constraint, so the condensed "
                "model's port matrix B is zero (the ports act only through its feedthrough terms) and the "
                "reduction has no port direction to keep", what, A->B);
  if (S->dae && p >= 0 && p < S->sys.m && max_abs_n(S->sys.B + (size_t)p * S->sys.N, (size_t)S->sys.N) <=
                                               1e-12 * max_abs_n(S->sys.B, (size_t)S->sys.N * (size_t)S->sys.m))
    return fail("reduction failed: --method %s: port %d (column %d of %s, counted from 0) acts only through a "
                "constraint (its condensed input column vanishes: it enters only through the feedthrough terms): "
                "use sp1 or sp2",
                method == PHGMG_METHOD_GMG_QM ? "gmg-qm" : "gmg-pod", p, p, A->B);
  if (p >= 0)
    return fail("reduction failed: %s: port %d (column %d of %s, counted from 0) %s: gmg-pod and gmg-qm keep "
                "B in their basis and need it of full column rank (sp1 and sp2 do not)", what, p, p, A->B,
                S->dae ? "depends on the other ports after the condensation" : "depends on the other ports");
  if (method == PHGMG_METHOD_GMG_QM && A->have_lambda && !A->lambda_auto && A->lambda > 0.0)
    return fail("reduction failed: %s: --lambda %g, the ridge parameter of the quadratic fit, is too small to "
                "regularise it against the scale of the quadratic features (give a larger --lambda, or leave "
                "it out)", what, A->lambda);
  return fail("reduction failed: %s (%s, or the port matrix %s)", what, src, A->B);
}

/* Sizes that phgmg_reduce would refuse, explained up front. N: the states
   reduced (an index-one model's differential states: k algebraic ones
   left out of its N + k). */
static int check_sizes(const reduce_args *A, int method, int N, int m, int k) {
  char nd[128];
  if (k > 0) snprintf(nd, sizeof nd, "%d differential states (the model's %d states less %d algebraic)", N, N + k, k);
  else snprintf(nd, sizeof nd, "%d", N);
  if (method == PHGMG_METHOD_GMG_POD || method == PHGMG_METHOD_GMG_QM) {
    if (A->r <= m || A->r > N)
      return usage_error("--r %d: %s needs m < r <= N (m = %d ports from %s, N = %s)", A->r, A->method, m, A->B, nd);
    if (method == PHGMG_METHOD_GMG_QM && A->rn > 0 && A->rn > N - A->r)
      return usage_error("--rn %d: gmg-qm needs r + r_n <= N (N = %s)", A->rn, nd);
    if (method == PHGMG_METHOD_GMG_QM && A->r >= N)
      return usage_error("--r %d: gmg-qm needs r < N (N = %s): room for at least one quadratic mode", A->r, nd);
  } else if ((method == PHGMG_METHOD_BT || method == PHGMG_METHOD_PRBT) && (A->r <= m || A->r > N)) {
    return usage_error("--r %d: %s needs m < r <= N (m = %d ports from %s, N = %s)", A->r, A->method, m, A->B, nd);
  } else if (A->r > N) {
    return usage_error("--r %d: needs r <= N = %s", A->r, nd);
  }

  return 0;
}

/* --x0 FILE into x0 (the N states the run simulates, zero without --x0):
   N values in the files' ordering (sparse input: moved to the internal one).
   Not for a model with algebraic constraints (its initial state must be
   consistent). 0, or 1 after a message. */
static int load_x0(const reduce_args *A, const reduce_state *S, int N, double *x0) {
  mat M;
  if (!A->x0f) return 0;
  if (S->dae) return fail("%s (--x0): a model with algebraic constraints starts at rest (x = 0); --x0 is for "
                          "models without zero rows of E", A->x0f);
  if (mat_load(&M, "--x0", A->x0f)) return 1;
  if (M.ndim == 0 || M.rows != N || M.cols != 1) {
    fail("%s (--x0): expected shape (%d,) or (%d, 1) (one value per state), got %s", A->x0f, N, N, shape_str(&M));
    mat_free(&M);
    return 1;
  }
  if (S->sp) phgmg_ph_sparse_to_banded_order(S->sp, 1, M.a, N, x0, N);
  else memcpy(x0, M.a, sizeof(double) * (size_t)N);
  mat_free(&M);
  return 0;
}

/* --simulate: the training runs (--input, or each --train-input) from x0 = 0,
   one after the other in S->Xsim, their outputs in S->Ysim, S->runs. */
static int simulate_training_runs(const reduce_args *A, reduce_state *S, const double **Xo, int *nso, double *t_sim) {
  const int N = S->sys.N, m = S->sys.m;
  phgmg_result rc;
  double t0;
  int ns, i, k;
  phgmg_gl3_opts go;
  phgmg_gl3_stats st;
  double *x0;
  int done = 0;
  const int nrun = A->ntrain ? A->ntrain : 1;
  if ((k = input_setup(&S->in, A->ntrain ? "--train-input" : "--input", A->input, A->amp, m, A->dt, A->steps * A->dt)) != 0)
    return k;
  for (i = 1; i < nrun; ++i)
    if ((k = input_setup(&S->tin[i], "--train-input", A->train[i], A->amp, m, A->dt, A->steps * A->dt)) != 0) return k;
  {
    const cli_input *ins[16];
    for (i = 0; i < nrun; ++i) ins[i] = i ? &S->tin[i] : &S->in;
    note_ports(ins, nrun, m);
  }
  ns = nrun * (A->steps + 1);
  if (too_big(((double)N + (double)m) * (double)ns, "--simulate: the snapshots (N x (steps+1)) and outputs"))
    return 2;
  S->Xsim = (double *)malloc(sizeof(double) * (size_t)N * (size_t)ns);
  S->Ysim = (double *)malloc(sizeof(double) * (size_t)m * (size_t)ns);
  x0 = (double *)calloc((size_t)N, sizeof(double));
  if (!S->Xsim || !S->Ysim || !x0) { free(x0); return fail("out of memory for %d snapshots of size %d", ns, N); }
  if (load_x0(A, S, N, x0)) { free(x0); return 1; }
  memset(&go, 0, sizeof go);
  go.tol = A->newton_tol; go.max_iter = A->newton_iter;
  t0 = now_s();
  for (i = 0; i < nrun; ++i) {   /* run i in columns i (steps + 1) ..; from x0 = 0 */
    cli_input *in = i ? &S->tin[i] : &S->in;
    const size_t c0 = (size_t)i * (size_t)(A->steps + 1);
    input_covers(in, i ? A->train[i] : A->input, A->ntrain ? "--train-input" : "--input", A->steps * A->dt);
    progress("simulating the full model: %d steps of dt = %g, %s", A->steps, A->dt,
             input_desc(in, i ? A->train[i] : A->input));
    in->report = 1;
    in->t_end = A->steps * A->dt;
    in->wall0 = in->wall_last = now_s();
    rc = phgmg_simulate(&S->sys, x0, 0.0, A->dt, A->steps, input_fn, in, &go, S->Xsim + c0 * (size_t)N,
                        S->Ysim + c0 * (size_t)m, NULL, &st, &done, NULL);
    in->report = 0;
    if (rc != PHGMG_OK) {
      free(x0);
      return fail("full-order simulation failed at step %d of %d (t = %g): %s%s", done + 1, A->steps,
                  done * A->dt, phgmg_result_string(rc),
                  rc == PHGMG_ERR_NOT_CONVERGED ? " (try a smaller --dt or more --newton-iter)" : "");
    }
    progress("  done (%ld Newton iterations, %ld factorizations)", st.newton_iters, st.factorizations);
    progress_newton_tol(&S->sys, A->newton_tol, &st);
    note_band_fallback(&st);
    memset(&S->runs[i], 0, sizeof S->runs[i]);
    S->runs[i].u = input_fn; S->runs[i].user = in; S->runs[i].dt = A->dt; S->runs[i].nsteps = A->steps;
  }
  S->nrun = nrun;
  free(x0);
  *t_sim = now_s() - t0;
  *Xo = S->Xsim;
  *nso = ns;
  return 0;
}

/* gmg-qm's r_n without --rn: 8, or what fits (r + r_n <= N, r_n (r - m) <= 4096). */
static int default_rn(int N, int r, int m) {
  phgmg_reduce_opts def;
  int rn;
  phgmg_reduce_opts_default(&def);
  rn = CLI_MIN(def.qm.rn, N - r);
  if (r > m) rn = CLI_MIN(rn, 4096 / (r - m));
  return CLI_MAX(rn, 1);
}

/* The spectral radius of the step map Phi (r x r), from above:
   ||Phi^k||_F^(1/k) for k = 2^30 by repeated squaring, normalised at every
   square (no overflow). For a pH model the eigenvalues of modulus 1 are
   semisimple, so the estimate exceeds the radius by at most a factor
   cond^(1/k) ~ 1 + 1e-8. INFINITY if Phi holds NaN/Inf. */
static double step_map_radius(const phgmg_rom *rom) {
  const int r = rom->r;
  double *A = (double *)malloc(sizeof(double) * 2 * (size_t)r * (size_t)r), *B, L = 0.0, s;
  int it, i, j, k;
  if (!A) return NAN;
  B = A + (size_t)r * r;
  for (i = 0; i < r * r; ++i) A[i] = (double)rom->Phi[i];
  for (it = 0; it <= 30; ++it) {
    double f = 0.0;
    for (s = 0.0, i = 0; i < r * r; ++i) s = CLI_MAX(s, fabs(A[i])); /* scale first: no overflow in the norm */
    if (!isfinite(s)) { free(A); return INFINITY; }
    if (s == 0.0) { free(A); return 0.0; }
    for (i = 0; i < r * r; ++i) { A[i] /= s; f += A[i] * A[i]; }
    f = sqrt(f);
    for (i = 0; i < r * r; ++i) A[i] /= f;   /* A = Phi^(2^it) / ||Phi^(2^it)||_F */
    L += log(s * f) / ldexp(1.0, it);       /* L = log ||Phi^(2^it)||_F / 2^it */
    if (it == 30) break;
    for (j = 0; j < r; ++j) /* B = A A */
      for (i = 0; i < r; ++i) {
        double t = 0.0;
        for (k = 0; k < r; ++k) t += A[i + (size_t)k * r] * A[k + (size_t)j * r];
        B[i + (size_t)j * r] = t;
      }
    memcpy(A, B, sizeof(double) * (size_t)r * r);
  }
  free(A);
  return exp(L);
}

/* ---- reduce --simulate, streamed: the snapshots never stored ------------------ */
/* The stream phgmg_reduce_stream reduces from (run_reduction uses it when set). */
static phgmg_pod_stream *g_stream;

/* 1 if this run streams its snapshots: --stream, or --simulate whose
   snapshots exceed CLI_MAX_BYTES, for a method and model the stream serves
   (gmg-pod or sp1; no hyper-reduced --poly, --ref mean, --save-snapshots,
   descriptor, feedthrough or dampers). --stream otherwise: a usage error
   (2); *why names the reason. */
/* The columns of the --X files (0 if a shape cannot be read: the in-core
   reader reports it). */
static double stream_x_columns(const reduce_args *A) {
  double t = 0.0;
  int k, rows = 0, cols = 0;
  for (k = 0; k < A->nx; ++k) {
    if (phgmg_npy_read_cols(A->xs[k], 0, 0, NULL, 1, &rows, &cols) != PHGMG_OK) return 0.0;
    t += cols;
  }
  return t;
}

static int stream_use(const reduce_args *A, const reduce_state *S, const char **why) {
  const double cols = A->X ? stream_x_columns(A) : (double)(A->ntrain ? A->ntrain : 1) * ((double)A->steps + 1.0);
  *why = NULL;
  if (!A->stream && !(8.0 * (double)S->sys.N * cols > CLI_MAX_BYTES)) return 0;
  if (S->method != PHGMG_METHOD_GMG_POD && S->method != PHGMG_METHOD_SP1) *why = "--method gmg-qm or sp2";
  else if (A->poly_idx && !A->no_deim) *why = "a hyper-reduced --poly-idx part (add --no-hyper)";
  else if (A->ref != PHGMG_REF_NONE) *why = "--ref";
  else if (A->save_snap) *why = "--save-snapshots";
  else if (S->dae || A->E || A->Ecoo || A->Pf || A->Sf || A->Nf || A->dampf) *why = "--E, feedthrough or --dampers";
  else if (A->nxin) *why = "--X-input";
  return *why ? 0 : 1;
}

/* Run i of the training runs (from --x0, else 0) on a stepper, each state into
   the column block blk (N x nb), each full block into g_stream. */
static int stream_run(const reduce_args *A, reduce_state *S, cli_input *in, const char *spec, double *blk, int nb,
                      int *fill) {
  const int N = S->sys.N;
  phgmg_gl3_opts go;
  phgmg_gl3 *g = NULL;
  double *x = (double *)calloc((size_t)N, sizeof(double));
  phgmg_result rc;
  int n;
  memset(&go, 0, sizeof go);
  go.tol = A->newton_tol; go.max_iter = A->newton_iter;
  if (!x) return fail("out of memory");
  if (load_x0(A, S, N, x)) { free(x); return 1; }   /* --x0 (else 0) */
  rc = phgmg_gl3_create(&g, &S->sys, A->dt, &go, NULL);
  input_covers(in, spec, A->ntrain ? "--train-input" : "--input", A->steps * A->dt);
  progress("simulating the full model (streamed): %d steps of dt = %g, %s", A->steps, A->dt, input_desc(in, spec));
  in->report = 1;   /* progress lines from the input callback, as the stored run's */
  in->t_end = A->steps * A->dt;
  in->wall0 = in->wall_last = now_s();
  for (n = 0; rc == PHGMG_OK; ++n) {   /* the loop of phgmg_simulate: t_n = n dt */
    memcpy(blk + (size_t)*fill * N, x, sizeof(double) * (size_t)N);
    if (++*fill == nb) { rc = phgmg_pod_stream_add(g_stream, nb, blk, N); *fill = 0; }
    if (n == A->steps || rc != PHGMG_OK) break;
    rc = phgmg_gl3_step(g, n * A->dt, x, input_fn, in, NULL);
  }
  in->report = 0;
  phgmg_gl3_destroy(g);
  free(x);
  if (rc != PHGMG_OK)
    return fail("streamed simulation failed at step %d of %d: %s", n + 1, A->steps, phgmg_result_string(rc));
  return 0;
}

/* The largest order of the run's --r list. */
static int max_order(const reduce_args *A) {
  int k, r = A->r;
  for (k = 0; k < A->nrl; ++k) r = CLI_MAX(r, A->rlist[k]);
  return r;
}

/* g_stream begun (kept at rank max(2(r'+1), r'+41) with r' = r - m
   (gmg-pod) or r (sp1), r the largest order asked, at most N - m) and a
   block of *nb columns. */
static int stream_begin(const reduce_args *A, const reduce_state *S, double **blk, int *nb) {
  const int N = S->sys.N, m = S->sys.m, gmg = S->method == PHGMG_METHOD_GMG_POD, rmax = max_order(A);
  const int p = gmg ? rmax - m : rmax, kmax = CLI_MIN(N - (gmg ? m : 0), CLI_MAX(2 * (p + 1), p + 41));
  phgmg_result rc = phgmg_pod_stream_begin(&g_stream, N, gmg ? m : 0, gmg ? S->sys.B : NULL, N, kmax, 0.0, NULL);
  if (rc != PHGMG_OK) return fail("streamed POD: %s", phgmg_result_string(rc));
  *nb = CLI_MAX(16, CLI_MIN(64, kmax));
  if (!(*blk = (double *)malloc(sizeof(double) * (size_t)N * (size_t)*nb))) return fail("out of memory");
  return 0;
}

/* The last block into the stream, the log line, the column count. */
static int stream_finish(const reduce_state *S, double *blk, int fill, int *nso) {
  double disc = 0.0;
  int k = 0;
  phgmg_result rc = fill > 0 ? phgmg_pod_stream_add(g_stream, fill, blk, S->sys.N) : PHGMG_OK;
  free(blk);
  if (rc != PHGMG_OK) return fail("streamed POD: %s", phgmg_result_string(rc));
  phgmg_pod_stream_end(g_stream, NULL, S->sys.N, NULL, &k, &disc);
  progress("  streamed POD: %d modes kept of %d snapshots (error bound %.3g)", k, phgmg_pod_stream_columns(g_stream), disc);
  *nso = phgmg_pod_stream_columns(g_stream);
  return 0;
}

/* The training runs streamed into g_stream. */
static int stream_training_runs(const reduce_args *A, reduce_state *S, int *nso, double *t_sim) {
  const int m = S->sys.m, nrun = A->ntrain ? A->ntrain : 1;
  double *blk = NULL, t0 = now_s();
  int i, k, nb = 0, fill = 0;
  if ((k = input_setup(&S->in, A->ntrain ? "--train-input" : "--input", A->input, A->amp, m, A->dt, A->steps * A->dt)) != 0)
    return k;
  for (i = 1; i < nrun; ++i)
    if ((k = input_setup(&S->tin[i], "--train-input", A->train[i], A->amp, m, A->dt, A->steps * A->dt)) != 0) return k;
  if ((k = stream_begin(A, S, &blk, &nb)) != 0) { free(blk); return k; }
  for (i = 0, k = 0; i < nrun && !k; ++i) k = stream_run(A, S, i ? &S->tin[i] : &S->in, i ? A->train[i] : A->input, blk, nb, &fill);
  if (k) { free(blk); return k; }
  *t_sim = now_s() - t0;
  return stream_finish(S, blk, fill, nso);
}

/* The --X files read in blocks of columns into g_stream (in the model's
   internal order for a sparse model). */
static int stream_x_files(const reduce_args *A, reduce_state *S, int *nso) {
  const int N = S->sys.N;
  double *blk = NULL, *perm = NULL;
  int f, j, nb = 0, k, rows = 0, cols = 0;
  phgmg_result rc = PHGMG_OK;
  if ((k = stream_begin(A, S, &blk, &nb)) != 0) { free(blk); return k; }
  if (S->sp && !(perm = (double *)malloc(sizeof(double) * (size_t)N * (size_t)nb))) { free(blk); return fail("out of memory"); }
  for (f = 0; f < A->nx && rc == PHGMG_OK; ++f) {
    if ((rc = phgmg_npy_read_cols(A->xs[f], 0, 0, NULL, 1, &rows, &cols)) != PHGMG_OK) break;
    if (rows != N || cols < 2) {
      free(blk); free(perm);
      return fail("%s (--X): expected shape (%d, ns), ns >= 2 snapshots as columns, got (%d, %d)", A->xs[f], N, rows, cols);
    }
    progress("streaming %s: %d snapshots in blocks of %d", A->xs[f], cols, nb);
    for (j = 0; j < cols && rc == PHGMG_OK; j += nb) {
      const int c = CLI_MIN(nb, cols - j);
      rc = phgmg_npy_read_cols(A->xs[f], j, c, blk, N, NULL, NULL);
      if (rc == PHGMG_OK && S->sp) phgmg_ph_sparse_to_banded_order(S->sp, c, blk, N, perm, N);
      if (rc == PHGMG_OK) rc = phgmg_pod_stream_add(g_stream, c, S->sp ? perm : blk, N);
    }
  }
  free(perm);
  if (rc != PHGMG_OK) { free(blk); return fail("%s (--X): %s", A->xs[CLI_MIN(f, A->nx - 1)], phgmg_result_string(rc)); }
  return stream_finish(S, blk, 0, nso);
}

/* phgmg_reduce with the options of the command line; reports what it did. */
static int run_reduction(const reduce_args *A, reduce_state *S, int method, const double *X, int ns,
                         phgmg_reduce_opts *op, phgmg_reduce_info *ip, double *t_red) {
  const int N = S->sys.N;
  phgmg_reduce_opts o;
  phgmg_reduce_info info;
  phgmg_result rc;
  const phgmg_rom *rom;
  double t0;
  phase_log plog;
  /* --- reduce --- */
  phgmg_reduce_opts_default(&o);
  o.method = (phgmg_method)method;
  o.r = A->r;
  o.qm.rn = A->rn ? A->rn : default_rn(N, A->r, S->sys.m);
  o.qm.lambda = A->lambda > 0.0 ? A->lambda : -1.0; /* 0 on the command line = exactly zero */
  o.hyper.on = A->poly_idx && !A->no_deim;
  o.hyper.kind = !A->hyper || !strcmp(A->hyper, "ecsw") ? PHGMG_HYPER_ECSW
                 : !strcmp(A->hyper, "qdeim") ? PHGMG_HYPER_QDEIM : PHGMG_HYPER_GREEDY;
  if (A->hyper_tol > 0.0) o.hyper.tol = A->hyper_tol;
  o.hyper.deim_tol = A->deim_tol > 0.0 ? A->deim_tol : 1e-300;
  o.hyper.deim_max = A->deim_max;
  o.hyper.allow_negative = A->deim_neg;
  o.hyper.keep_dampers = 1;   /* --dampers: every damper kept (the options above apply to the terms) */
  o.dt = A->dt_map;
  o.select.lambda_mode = method == PHGMG_METHOD_GMG_QM ? A->lambda_auto : 0;
  o.qm.manifold = A->manifold;
  o.ref = A->ref;
  o.ref_x = A->ref == PHGMG_REF_GIVEN ? S->refm.a : NULL;
  o.qm.greedy_window = A->greedy_window;
  o.degeneracy_tol = A->degeneracy_tol;   /* 0: the library's 1e-12 */
  if (S->nrun > 0) { o.nrun = S->nrun; o.runs = S->runs; } /* --simulate: the runs are known */
  if (A->lambda_auto == 1) { o.select.newton_tol = A->newton_tol; o.select.newton_iter = A->newton_iter; }
  memset(&info, 0, sizeof info);
  info.rank_port = -1;
  progress("reducing: %s, r = %d%s", A->method, A->r, method == PHGMG_METHOD_GMG_QM ? " (quadratic manifold)" : "");
  t0 = now_s();
  plog.t0 = t0; plog.all = (double)N * (double)ns >= 1e7; plog.ncand = plog.nprobe = 0;
  plog.qm = method == PHGMG_METHOD_GMG_QM; plog.hyper = o.hyper.on;
  plog.quiet = g_quiet; plog.last = NULL;
  o.progress = reduce_phase; o.progress_user = &plog;
  rc = g_stream ? phgmg_reduce_stream(&S->red, &S->sys, g_stream, &o, &info, NULL)
       : S->study ? phgmg_study_reduce(S->study, &o, &S->red, &info)
                  : phgmg_reduce(&S->red, &S->sys, X, N, ns, &o, &info, NULL);
  *t_red = now_s() - t0;
  if (rc != PHGMG_OK) {
    const char *src = A->X ? A->X : "the simulated snapshots";
    switch (rc) {
      case PHGMG_ERR_SIZE:
        return fail("reduction failed: %s: r = %d%s exceeds the rank of %s (%d snapshots of size %d%s)",
                    phgmg_result_string(rc), A->r, method == PHGMG_METHOD_GMG_QM ? " plus r_n" : "", src, ns, N,
                    S->dae ? ": the differential states" : "");
      case PHGMG_ERR_RANK: return explain_rank(A, S, method, src, &info);
      case PHGMG_ERR_DEGENERATE:
        if (method == PHGMG_METHOD_SP1 || method == PHGMG_METHOD_SP2)
          return fail("reduction failed: %s: rcond(V^T W) = %.3g is below --degeneracy-tol %g (try another --r or "
                      "more varied snapshots)", phgmg_result_string(rc), info.rcond_dgd,
                      A->degeneracy_tol > 0.0 ? A->degeneracy_tol : 1e-12);
        return fail("reduction failed: %s: D^T G D's non-degeneracy measure %.3g is below --degeneracy-tol %g. "
                    "Try another --r (with R = 0, an even --r), snapshots that excite more of the model, %s"
                    "or, only if the reduced model is known to be fine, a smaller --degeneracy-tol (down to "
                    "about 1e-15; below, D^T G D is singular to rounding)", phgmg_result_string(rc),
                    info.rcond_dgd, A->degeneracy_tol > 0.0 ? A->degeneracy_tol : 1e-12,
                    method == PHGMG_METHOD_GMG_QM ? "a larger --lambda, " : "");
      case PHGMG_ERR_STEP_MAP:
        return fail("reduction failed: --dt-map %g: %s (or --dt-map 0: none)", A->dt_map, phgmg_result_string(rc));
      case PHGMG_ERR_TOL_UNREACHABLE:
        return fail("reduction failed: --hyper-tol %g: %s", A->hyper_tol, phgmg_result_string(rc));
      case PHGMG_ERR_NOT_CONVERGED:
        if (plog.last && !strcmp(plog.last, "hyper-reduction") && o.hyper.kind == PHGMG_HYPER_ECSW)
          return fail("reduction failed: the ECSW hyper-reduction did not reach --hyper-tol %g on these snapshots "
                      "(%s); a larger --hyper-tol, or --no-hyper, reduces without it",
                      o.hyper.tol > 0.0 ? o.hyper.tol : 1e-6, phgmg_result_string(rc));
        return fail("reduction failed: %s", phgmg_result_string(rc));
      case PHGMG_ERR_NEGATIVE_WEIGHT:
        return fail("reduction failed: %s (use --deim-allow-negative, a smaller --deim-tol, or --no-hyper)",
                    phgmg_result_string(rc));
      case PHGMG_ERR_UNSUPPORTED:
        if (check_extras(A, S)) return 1;   /* feedthrough or dampers with gmg-qm or --ref */
        return fail("reduction failed: %s", phgmg_result_string(rc));
      default:
        return fail("reduction failed: %s", phgmg_result_string(rc));
    }
  }
  rom = phgmg_reduced_rom(S->red);
  /* GMG reports rcond(D^T G D); SP1/SP2 have no D^T G D (their rcond_dgd is V^T Vg's) */
  if (method == PHGMG_METHOD_SP1 || method == PHGMG_METHOD_SP2)
    progress("  done in %.2f s: r = %d, m = %d%s; sigma_{r+1}/sigma_1 = %.3g", *t_red, rom->r, rom->m,
             rom->nd ? "" : ", quadratic energy", info.pod_sigma_ratio);
  else
    progress("  done in %.2f s: r = %d, m = %d%s; sigma_{r'+1}/sigma_1 = %.3g, rcond(D^T G D) = %.3g", *t_red,
             rom->r, rom->m, rom->nd ? "" : ", quadratic energy", info.pod_sigma_ratio, info.rcond_dgd);
  if (method == PHGMG_METHOD_GMG_QM && A->lambda_auto == 1 && A->X && !A->nxin)
    note("gmg-qm with --X and no --X-input: the inputs of the runs are unknown, so no lambda can be validated "
         "by simulation: M = 0 (the GMG-POD model on the same basis). Give --X-input for the validated "
         "choice, or a fixed --lambda");
  else if (method == PHGMG_METHOD_GMG_QM && (A->lambda_auto || A->manifold))
    progress("  manifold %s, lambda %s: %.3g%s", A->manifold_s ? A->manifold_s : "pod",
             A->lambda_auto == 1 ? "auto" : A->lambda_auto == 2 ? "cv" : "fixed", info.lambda,
             info.lambda == HUGE_VAL ? " (M = 0: no safe quadratic correction found)" : "");
  if (!rom->Phi && A->have_dt_map && A->dt_map > 0.0)   /* asked for, not built: say why */
    note("--dt-map %g has no effect: a step map is built for a linear reduced model with a quadratic energy and "
         "no feedthrough or dampers, and this model has %s; the online stepper solves each step (Newton)",
         A->dt_map, rom->kind == PHGMG_ROM_QUADRATIC ? "a quadratic manifold" : rom->nd ? "nonlinear energy terms"
         : rom->ndamp ? "dampers" : rom->PD ? "feedthrough" : "a nonlinear part");
  if (rom->Phi) { /* the precomputed step map must not amplify: spectral radius <= 1 */
    const double rho = step_map_radius(rom);
    progress("  step map for dt = %g: spectral radius %.6g", A->dt_map, rho);
    if (!(rho <= 1.0 + 1e-6))
      return fail("--dt-map %g: the step map is unstable (spectral radius %.3g > 1), while the model never gains "
                  "energy; use a smaller --dt-map (or --dt-map 0: none, the stepper then solves each step)",
                  A->dt_map, rho);
  }
  if (info.pod_randomized)
    progress("  POD: %s (a-posteriori check %.2g)", info.pod_randomized > 0 ? "randomized (large snapshot set)"
             : "exact SVD (the randomized POD failed its check)", info.pod_check);
  if (rom->nd && o.hyper.on)
    progress("  hyper-reduction %s: %d points, %d negative weights, smallest weight %.3g, training residual %.2g",
             A->hyper ? A->hyper : "ecsw", info.deim_modes, info.deim_negative, info.hyper_min_weight,
             info.hyper_residual);

  *op = o;
  *ip = info;
  return 0;
}

/* Entries of the reduced model's arrays below the smallest normal number of
   its scalar type (DBL_MIN, or FLT_MIN in the float build) -- rounding
   residue, e.g. of Qh = V^T Q V of a badly scaled Q -- set to 0 before
   anything is written: subnormal constants slow down firmware (and some
   compilers and processors flush them anyway). In place, so that the
   model validate tests is the model written. Returns the count. */
static long flush_subnormal_entries(const phgmg_reduced *red) {
  const phgmg_rom *rom = phgmg_reduced_rom(red);
#ifdef PHGMG_REAL_FLOAT
  const phgmg_real tiny = FLT_MIN;
#else
  const phgmg_real tiny = DBL_MIN;
#endif
  rom_field f[24];
  long cnt = 0;
  int nf = rom_fields(rom, f), i;
  size_t q, n;
  if (rom->PD && nf < 24) {
    f[nf].name = "PD"; f[nf].a = rom->PD; f[nf].rows = rom->r + rom->m; f[nf].cols = rom->m; ++nf;
  }
  for (i = 0; i < nf; ++i) {
    phgmg_real *a = (phgmg_real *)(void *)(size_t)f[i].a;   /* the CLI owns the reduced object */
    n = (size_t)f[i].rows * (size_t)f[i].cols;
    for (q = 0; q < n; ++q)
      if (a[q] != (phgmg_real)0 && fabs((double)a[q]) < (double)tiny) { a[q] = (phgmg_real)0; ++cnt; }
  }
  return cnt;
}

/* NAME_PD.npy: the reduced feedthrough as one (r + m) x m matrix [Ph; S + N]
   (rows 0..r-1: Ph = W_z^T P; rows r..r+m-1: S + N), from phgmg_rom.PD's two
   column-major blocks. */
static int write_feedthrough(const reduce_args *A, reduce_state *S, const phgmg_rom *rom, outlist *ol) {
  const int r = rom->r, m = rom->m;
  double *D = (double *)malloc(sizeof(double) * (size_t)(r + m) * (size_t)m);
  int a, b, e;
  if (!D) return fail("out of memory");
  for (b = 0; b < m; ++b) {
    for (a = 0; a < r; ++a) D[a + (size_t)b * (r + m)] = (double)rom->PD[a + (size_t)b * r];
    for (a = 0; a < m; ++a) D[r + a + (size_t)b * (r + m)] = (double)rom->PD[(size_t)r * m + a + (size_t)b * m];
  }
  e = write_field(A->out, A->name, "PD", D, r + m, m, ol, &S->sg);
  free(D);
  return e;
}

/* The reduced model's arrays (NAME_*.npy), V0 = Dphi(0), V2 and M of a
   quadratic map, and with --save-snapshots the snapshots and their outputs. */
static int write_arrays(const reduce_args *A, reduce_state *S, const double *X, int ns, outlist *ol) {
  const phgmg_rom *rom = phgmg_reduced_rom(S->red);
  const int N = S->sys.N, m = S->sys.m;
  rom_field fields[24];
  int i, k, nf;
  /* --- outputs --- */
  if (mkdir_p(A->out, &S->sg)) return 1;
  {
    const long nt = flush_subnormal_entries(S->red);
    if (nt) progress("  %ld entries of the reduced model's arrays below the smallest normal number set to 0", nt);
  }
  memset(ol, 0, sizeof *ol);
  nf = rom_fields(rom, fields);
  {
    double *buf = NULL;
    size_t cap = 0;
    for (i = 0; i < nf; ++i) {
      const size_t n = (size_t)fields[i].rows * (size_t)fields[i].cols;
      size_t q;
      if (n > cap) {
        double *nb = (double *)realloc(buf, n * sizeof(double));
        if (!nb) { free(buf); return fail("out of memory"); }
        buf = nb; cap = n;
      }
      for (q = 0; q < n; ++q) buf[q] = (double)fields[i].a[q];
      if (write_field(A->out, A->name, fields[i].name, buf, fields[i].rows, fields[i].cols, ol, &S->sg)) { free(buf); return 1; }
    }
    free(buf);
  }
  if (rom->PD && write_feedthrough(A, S, rom, ol)) return 1;
  {
    /* V0 = Dphi(0), the linear part of the reduction map (exactly V0 for every method). */
    double *xr0 = (double *)calloc((size_t)rom->r, sizeof(double));
    free(S->V0);
    S->V0 = (double *)malloc(sizeof(double) * (size_t)N * (size_t)rom->r);
    if (!xr0 || !S->V0) { free(xr0); return fail("out of memory"); }
    phgmg_reduced_dphi(S->red, xr0, S->V0, N);
    free(xr0);
    if (write_user_field(A, S, "V0", S->V0, rom->r, ol)) return 1;
  }
  if (rom->kind == PHGMG_ROM_QUADRATIC) {
    /* V2 and M of the quadratic map */
    const int p = rom->r - rom->m;
    const double *V2 = NULL, *M = NULL;
    phgmg_reduced_qm(S->red, &V2, &M);
    if (!V2 || !M) return fail("the quadratic manifold's arrays are not available");
    if (write_user_field(A, S, "V2", V2, rom->rn, ol)) return 1;
    if (write_field(A->out, A->name, "M", M, rom->rn, p * p, ol, &S->sg)) return 1;
  }
  if (A->save_snap) {
    double *Y = S->Ysim;
    if (!Y) { /* --X: the full model's output at the given snapshots */
      S->Ysim = Y = (double *)malloc(sizeof(double) * (size_t)m * (size_t)ns);
      if (!Y) return fail("out of memory");
      for (k = 0; k < ns; ++k) phgmg_ph_output(&S->sys, X + (size_t)k * N, Y + (size_t)k * m);
    }
    if (write_user_field(A, S, "snapshots", X, ns, ol)) return 1;
    if (write_field(A->out, A->name, "fom_y", Y, m, ns, ol, &S->sg)) return 1;
  }
  return 0;
}

/* The hyper-reduction of the run: ecsw, qdeim, greedy, or none (no nonlinear
   part, or --no-deim: every term kept). */
static const char *hyper_name(const reduce_args *A, const phgmg_reduce_opts *o) {
  if (!A->poly_idx || !o->hyper.on) return "none";
  return o->hyper.kind == PHGMG_HYPER_ECSW ? "ecsw" : o->hyper.kind == PHGMG_HYPER_QDEIM ? "qdeim" : "greedy";
}

/* NAME.json: what was reduced, how, and where the outputs are. */
/* The json record's "snapshots" object (opened after "system"). */
static void json_snapshots(FILE *jf, const reduce_args *A, int ns, double t_sim) {
  int i;
  fprintf(jf, "},\n  \"snapshots\": {\"count\": %d, ", ns);
  if (A->X) {
    fprintf(jf, "\"file\": "); json_str(jf, A->X);
    if (A->nx > 1 || A->nxin) {
      fprintf(jf, ", \"files\": [");
      for (i = 0; i < A->nx; ++i) { if (i) fprintf(jf, ", "); json_str(jf, A->xs[i]); }
      fprintf(jf, "]");
    }
    if (A->nxin) {
      fprintf(jf, ", \"inputs\": [");
      for (i = 0; i < A->nxin; ++i) { if (i) fprintf(jf, ", "); json_str(jf, A->xin[i]); }
      fprintf(jf, "], \"dt\": "); json_num(jf, A->dt);
    }
    else if (A->have_dt) { fprintf(jf, ", \"dt\": "); json_num(jf, A->dt); }
  }
  else {
    fprintf(jf, "\"simulate\": {\"dt\": "); json_num(jf, A->dt);
    fprintf(jf, ", \"steps\": %d, \"input\": ", A->steps); json_str(jf, A->input);
    if (A->ntrain) {
      fprintf(jf, ", \"train_inputs\": [");
      for (i = 0; i < A->ntrain; ++i) { if (i) fprintf(jf, ", "); json_str(jf, A->train[i]); }
      fprintf(jf, "]");
    }
    fprintf(jf, ", \"amp\": "); json_num(jf, A->amp);
    fprintf(jf, ", \"newton_tol\": "); json_num(jf, A->newton_tol);
    fprintf(jf, ", \"newton_iter\": %d, \"seconds\": ", A->newton_iter); json_num(jf, t_sim);
    fprintf(jf, "}");
  }
}

/* The json record's "options" object. */
static void json_options(FILE *jf, const reduce_args *A, const reduce_state *S, int method,
                         const phgmg_reduce_opts *o, const phgmg_reduce_info *info) {
  fprintf(jf, "},\n  \"options\": {");
  if (method == PHGMG_METHOD_GMG_QM) { /* lambda, r_n and the manifold are gmg-qm's */
    fprintf(jf, "\"rn\": %d, \"lambda\": ", o->qm.rn);
    if (A->lambda_auto) json_str(jf, A->lambda_auto == 1 ? "auto" : "cv");
    else json_num(jf, A->lambda);
    fprintf(jf, ", \"lambda_used\": ");
    json_num(jf, info->lambda == HUGE_VAL ? -1.0 : info->lambda);
    if (A->lambda_auto == 1 && A->X && !A->nxin)
      fprintf(jf, ", \"lambda_note\": \"M = 0: the inputs of the --X runs are unknown (no --X-input)\"");
    fprintf(jf, ", \"manifold\": ");
    json_str(jf, A->manifold_s ? A->manifold_s : "pod");
    if (A->greedy_window) fprintf(jf, ", \"greedy_window\": %d", A->greedy_window);
    fprintf(jf, ", ");
  }
  fprintf(jf, "\"training_runs\": %d", S->nrun);
  fprintf(jf, ", \"ref\": ");
  json_str(jf, A->ref == PHGMG_REF_MEAN ? "mean" : A->ref == PHGMG_REF_GIVEN ? A->ref_file : "none");
  fprintf(jf, ", \"hyper\": ");
  json_str(jf, hyper_name(A, o));
  if (o->hyper.on && o->hyper.kind == PHGMG_HYPER_ECSW) {
    fprintf(jf, ", \"hyper_tol\": ");
    json_num(jf, A->hyper_tol > 0.0 ? A->hyper_tol : 1e-6);
  }
  fprintf(jf, ", \"deim\": %s", o->hyper.on && o->hyper.kind != PHGMG_HYPER_ECSW ? "true" : "false");
  if (o->hyper.on && o->hyper.kind != PHGMG_HYPER_ECSW) {
    fprintf(jf, ", \"deim_tol\": ");
    json_num(jf, A->deim_tol);
    fprintf(jf, ", \"deim_max\": %d, \"deim_allow_negative\": %s", A->deim_max, A->deim_neg ? "true" : "false");
  }
  fprintf(jf, "},\n");
}

/* The json record's "info" of a balancing method (opened, not closed): the
   solvers, the Gramian factors' ranks and residuals, the values, the bound. */
static void json_balancing(FILE *jf, const reduce_state *S, int method) {
  const phgmg_balanced_info *b = &S->bal;
  int i;
  fprintf(jf, "{\"solver\": \"%s\", \"stages\": %d", b->lowrank ? "low-rank" : "dense", b->stages);
  if (b->stages == 2) fprintf(jf, ", \"intermediate_order\": %d", b->inter);
  if (b->lowrank) {   /* one Lyapunov equation for prbt and phbt: the second entries 0 */
    fprintf(jf, ", \"lyapunov_solver\": \"%s\"", b->lr.ctrl.solver == PHGMG_LYAP_EKSM ? "eksm" : "adi");
    fprintf(jf, ", \"gramian_rank\": [%d, %d], \"adi_steps\": [%d, %d], \"factorizations\": [%d, %d]",
            b->lr.ctrl.rank, b->lr.obs.rank, b->lr.ctrl.iters, b->lr.obs.iters, b->lr.ctrl.factorizations,
            b->lr.obs.factorizations);
  }
  if (method != PHGMG_METHOD_PRBT || b->lowrank) {
    fprintf(jf, ", \"lyapunov_residual\": ["); json_num(jf, b->res_ctrl);
    fprintf(jf, ", "); json_num(jf, b->res_obs); fprintf(jf, "]");
  }
  if (method != PHGMG_METHOD_PRBT) fprintf(jf, ", \"values_computed\": %d", b->lr.nhsv);
  if (method == PHGMG_METHOD_PHBT) fprintf(jf, ", \"hamiltonian\": \"%s\"", b->hmin ? "minimal" : "energy");
  fprintf(jf, ", \"%s\": [", method == PHGMG_METHOD_BT ? "hankel_singular_values"
                            : method == PHGMG_METHOD_PRBT ? "positive_real_singular_values" : "energy_singular_values");
  for (i = 0; i < b->nsv; ++i) { if (i) fprintf(jf, ", "); json_num(jf, S->bal_sv[i]); }
  fprintf(jf, "]");
  if (method == PHGMG_METHOD_BT) {
    fprintf(jf, ", \"error_bound\": ");
    json_num(jf, b->lr.bound);
    fprintf(jf, ", \"ph_form_change\": "); json_num(jf, b->ph_change);
  }
}

/* The json record's "system" object, opened and not closed: the files of the
   model as given (a model rebuilt from the record is this model). */
static void json_system(FILE *jf, const reduce_args *A, const reduce_state *S) {
  fprintf(jf, ",\n  \"system\": {\"J\": ");
  json_str(jf, A->J ? A->J : A->Jcoo); fprintf(jf, ", \"R\": "); json_str(jf, A->R ? A->R : A->Rcoo);
  fprintf(jf, ", \"B\": "); json_str(jf, A->B); fprintf(jf, ", \"Q\": "); json_str(jf, A->Q ? A->Q : A->Qcoo);
  if (S->sp) fprintf(jf, ", \"sparse\": true, \"kb\": %d", S->sys.kb);
  { /* the descriptor, feedthrough and damper files: a model rebuilt from this record is this model */
    const char *const v[5] = {A->E ? A->E : A->Ecoo, A->Pf, A->Sf, A->Nf, A->dampf};
    const char *const key[5] = {"E", "P", "S", "N", "dampers"};
    int k;
    for (k = 0; k < 5; ++k)
      if (v[k]) { fprintf(jf, ", \"%s\": ", key[k]); json_str(jf, v[k]); }
  }
  if (A->poly_idx) {
    if (A->poly) { fprintf(jf, ", \"poly\": "); json_str(jf, A->poly); }
    if (A->expf) { fprintf(jf, ", \"exp\": "); json_str(jf, A->expf); }
    if (A->potential) { fprintf(jf, ", \"potential\": "); json_str(jf, A->potential); }
    fprintf(jf, ", \"poly_idx\": "); json_str(jf, A->poly_idx);
    if (A->poly_w) { fprintf(jf, ", \"poly_w\": "); json_str(jf, A->poly_w); }
    if (A->poly_jdx) { fprintf(jf, ", \"poly_jdx\": "); json_str(jf, A->poly_jdx); }
  }
}

static int write_json_tail(FILE *jf, const reduce_args *A, reduce_state *S, const outlist *ol, const char *path);
static int write_json(const reduce_args *A, reduce_state *S, int method, int ns, double t_sim, double t_red,
                      const phgmg_reduce_opts *o, const phgmg_reduce_info *info, const outlist *ol) {
  const phgmg_rom *rom = phgmg_reduced_rom(S->red);
  const int N = S->sys.N, m = S->sys.m;
  char path[4096 + 256];
  const char *wp;
  FILE *jf;
  int nalg = 0, zc = 0;
  snprintf(path, sizeof path, "%s/%s.json", A->out, A->name);
  if (!(wp = stage_path(&S->sg, path))) return 1;
  jf = fopen(wp, "w");
  if (!jf) return fail("%s: cannot write: %s", path, strerror(errno));
  fprintf(jf, "{\n  \"phgmg_version\": \"%s\",\n  \"name\": ", PHGMG_VERSION_STRING);
  json_str(jf, A->name);
  /* kind: the model's (nonlinear: energy terms or dampers); map: the reduction map's (phgmg_rom.kind) */
  fprintf(jf, ",\n  \"method\": \"%s\",\n  \"kind\": \"%s\",\n  \"map\": \"%s\",\n", method_name(method),
          rom->nd || rom->ndamp || S->sys.nl != PHGMG_NL_NONE ? "nonlinear" : "linear",
          rom->kind == PHGMG_ROM_QUADRATIC ? "quadratic" : "linear");
  fprintf(jf, "  \"N\": %d, \"m\": %d, \"r\": %d, \"rn\": %d, \"nd\": %d, \"poly_deg\": %d,\n", N, m, rom->r,
          rom->rn, rom->nd, rom->nd ? rom->poly_deg : 0);
  /* the model as given: its mass matrix, all its states (an index-one model is reduced on its differential
     ones: N above), the reduced feedthrough */
  if (S->dae) nalg = phgmg_dae_nalg(S->dae);
  else if (S->dae_direct && S->sp && S->full.E) e_zero_lines(S, S->full.N, &nalg, &zc, NULL, NULL); /* the whole pencil */
  fprintf(jf, "  \"E\": %s, \"N_full\": %d, \"algebraic\": %d, \"feedthrough\": %s,\n",
          S->full.E ? "true" : "false", S->full.N, nalg, rom->PD ? "true" : "false");
  fprintf(jf, "  \"dt_map\": ");
  if (rom->Phi) { char buf[32]; fputs(isfinite((double)rom->dt) ? real_str(rom->dt, buf) : "null", jf); }   /* float: "0.1" */
  else fputs("0", jf);
  json_system(jf, A, S);
  if (S->bal_on) {   /* balancing: no snapshots, its own info */
    fprintf(jf, "},\n  \"snapshots\": {\"count\": 0},\n  \"info\": ");
    json_balancing(jf, S, method);
    fprintf(jf, ", \"reduce_seconds\": "); json_num(jf, t_red);
    return write_json_tail(jf, A, S, ol, path);
  }
  json_snapshots(jf, A, ns, t_sim);
  json_options(jf, A, S, method, o, info);
  fprintf(jf, "  \"info\": {\"pod_sigma_ratio\": ");
  json_num(jf, info->pod_sigma_ratio);
  fprintf(jf, ", \"rcond_jr\": "); json_num(jf, info->rcond_jr);
  if (o->method != PHGMG_METHOD_SP1 && o->method != PHGMG_METHOD_SP2) { /* GMG only */
    fprintf(jf, ", \"rcond_dgd\": "); json_num(jf, info->rcond_dgd);
    fprintf(jf, ", \"degeneracy_tol\": "); json_num(jf, A->degeneracy_tol > 0.0 ? A->degeneracy_tol : 1e-12);
  }
  if (o->hyper.on && A->poly_idx) { /* the hyper-reduction's result */
    fprintf(jf, ", \"hyper\": {\"method\": ");
    json_str(jf, hyper_name(A, o));
    fprintf(jf, ", \"points\": %d, \"negative_weights\": %d, \"min_weight\": ", info->deim_modes, info->deim_negative);
    json_num(jf, info->hyper_min_weight);
    if (o->hyper.kind == PHGMG_HYPER_ECSW) {
      fprintf(jf, ", \"tol\": "); json_num(jf, A->hyper_tol > 0.0 ? A->hyper_tol : 1e-6);
      fprintf(jf, ", \"residual\": "); json_num(jf, info->hyper_residual);
    } else {
      fprintf(jf, ", \"tol\": "); json_num(jf, A->deim_tol);
      fprintf(jf, ", \"sigma_ratio\": "); json_num(jf, info->deim_sigma_ratio);
    }
    fprintf(jf, "}");
  }
  fprintf(jf, ", \"reduce_seconds\": "); json_num(jf, t_red);
  return write_json_tail(jf, A, S, ol, path);
}

/* The json record's end: the stepper's memory, the reconstruction and the
   files; closes jf. */
static int write_json_tail(FILE *jf, const reduce_args *A, reduce_state *S, const outlist *ol, const char *path) {
  const phgmg_rom *rom = phgmg_reduced_rom(S->red);
  int i;
  fprintf(jf, "},\n  \"stepper_memsize_bytes\": %lu,\n", (unsigned long)phgmg_rom_stepper_memsize(rom));
  fprintf(jf, "  \"reconstruction\": \"%s\",\n",
          rom->kind == PHGMG_ROM_QUADRATIC ? "x = V0 @ xr + V2 @ (M @ kron(xr[m:], xr[m:]))" : "x = V0 @ xr");
  fprintf(jf, "  \"files\": {\n    \"model\": \"%s.phgmgrom\",\n    \"c_source\": \"%s.c\",\n    \"arrays\": {",
          A->name, A->name);
  for (i = 0; i < ol->n; ++i)
    fprintf(jf, "%s\n      \"%s\": [%d, %d]", i ? "," : "", ol->names[i], ol->rows[i], ol->cols[i]);
  fprintf(jf, "\n    }\n  }\n}\n");
  if (fclose(jf) != 0) return fail("%s: write error", path);
  return 0;
}

/* The model file, its C source and the json record (written last: it lists
   the arrays); then every output of this run moves into place. */
/* The step the snapshots were taken at: --simulate's, the --X-input runs', or
   --dt given with --X; 0 if unknown. */
static double train_dt(const reduce_args *A) { return A->simulate || A->nxin || A->have_dt ? A->dt : 0.0; }

static int write_model_files(const reduce_args *A, reduce_state *S, int method, int ns, double t_sim, double t_red,
                             const phgmg_reduce_opts *o, const phgmg_reduce_info *info, const outlist *ol) {
  phgmg_rom rs = *phgmg_reduced_rom(S->red);
  const phgmg_rom *rom = &rs;
  phgmg_result rc;
  char path[4096 + 256];
  const char *wp;
  if (!rs.Phi) rs.dt = (phgmg_real)train_dt(A);   /* no step map: dt records the training step */
  snprintf(path, sizeof path, "%s/%s.phgmgrom", A->out, A->name);
  if (!(wp = stage_path(&S->sg, path))) return 1;
  rc = phgmg_rom_save(rom, wp);
  if (rc != PHGMG_OK) return fail("%s: cannot write the model file: %s", path, phgmg_result_string(rc));
  snprintf(path, sizeof path, "%s/%s.c", A->out, A->name);
  if (!(wp = stage_path(&S->sg, path))) return 1;
  rc = phgmg_rom_export_c(rom, A->name, wp);
  if (rc != PHGMG_OK) return fail("%s: cannot write the C source: %s", path, phgmg_result_string(rc));
  return write_json(A, S, method, ns, t_sim, t_red, o, info, ol);
}

/* After a state-space model is written as DIR/NAME: the model file and C
   source of an earlier run under that name (rec: its record held arrays)
   are removed -- never an input of this run, only regular files. */
static void remove_stale_model(const char *dir, const char *name, const outlist *rec) {
  static const char *const ext[2] = {"phgmgrom", "c"};
  char path[4096 + 256];
  struct stat st;
  int k;
  if (rec->n == 0) return;
  for (k = 0; k < 2; ++k) {
    snprintf(path, sizeof path, "%s/%s.%s", dir, name, ext[k]);
    if (g_inputs && paths_find(g_inputs, path) >= 0) continue;
    if (lstat(path, &st) == 0 && S_ISREG(st.st_mode) && remove(path) == 0)
      progress("removed %s (of an earlier run's model under this name)", path);
  }
}

/* Model k's outputs move into place; then the arrays an earlier run
   recorded under its name and this one did not write are removed. */
static int commit_model(const reduce_args *A, reduce_state *S, sweep_model *M) {
  outlist rec;
  char nfull[64] = "";
  read_record(A->out, M->name, &rec); /* before this run's record replaces it */
  if (stage_commit(&M->sg)) return 1;
  remove_stale(A->out, &rec, &M->ol);
  if (M->ss) {   /* no model file: an earlier run's NAME.phgmgrom and NAME.c are of another model */
    remove_stale_model(A->out, M->name, &rec);
    printf("wrote %s/%s.json and %d arrays %s/%s_*.npy (bt, state-space form A, B, C, D, r = %d, m = %d, N = %d)\n",
           A->out, M->name, M->ol.n, A->out, M->name, M->rr, M->m, S->full.N);
    return 0;
  }
  if (S->dae) /* the arrays are full-size; the reduction ran on the differential states */
    snprintf(nfull, sizeof nfull, ", of which %d differential", S->sys.N);
  printf("wrote %s/%s.phgmgrom, %s/%s.c, %s/%s.json and %d arrays %s/%s_*.npy (%s, r = %d, m = %d, N = %d%s)\n",
         A->out, M->name, A->out, M->name, A->out, M->name, M->ol.n, A->out, M->name, method_name(M->method),
         M->rr, M->m, S->full.N, nfull);
  return 0;
}

/* NAME_sweep.json of a sweep: every model with its method, order, name,
   reduction time, whether it was written, and validate's tests (nt, names). */
static int write_sweep_json(const reduce_args *A, reduce_state *S, const char *const *tests, int nt) {
  char path[4096 + 256];
  const char *wp;
  FILE *jf;
  int k, t;
  snprintf(path, sizeof path, "%s/%s_sweep.json", A->out, A->name0);
  if (!(wp = stage_path(&S->sweep_sg, path))) return 1;
  if (!(jf = fopen(wp, "w"))) return fail("%s: cannot write: %s", path, strerror(errno));
  fprintf(jf, "{\n  \"phgmg_version\": \"%s\",\n  \"name\": ", PHGMG_VERSION_STRING);
  json_str(jf, A->name0);
  fprintf(jf, ",\n  \"naming\": \"NAME_<method>_r<R>, method with '-' as '_'\",\n");
  fprintf(jf, "  \"shared_bases\": %s,\n  \"snapshot_seconds\": ", S->study ? "true" : "false");
  json_num(jf, S->t_sim);
  fprintf(jf, ",\n  \"models\": [");
  for (k = 0; k < S->nmodels; ++k) {
    const sweep_model *M = &S->models[k];
    fprintf(jf, "%s\n    {\"name\": ", k ? "," : "");
    json_str(jf, M->name);
    fprintf(jf, ", \"method\": \"%s\", \"r\": %d, \"json\": ", method_name(M->method), M->r);
    {
      char f[128];
      snprintf(f, sizeof f, "%s.json", M->name);
      json_str(jf, f);
    }
    fprintf(jf, ", \"reduce_seconds\": "); json_num(jf, M->t_red);
    fprintf(jf, ", \"written\": %s", M->pass ? "true" : "false");
    if (nt > 0) {
      fprintf(jf, ", \"tests\": [");
      for (t = 0; t < nt; ++t) {
        fprintf(jf, "%s{\"input\": ", t ? ", " : "");
        json_str(jf, tests[t]);
        fprintf(jf, ", \"e_y\": "); json_num(jf, M->ey[t]);
        fprintf(jf, ", \"e_red\": "); json_num(jf, M->ered[t]);
        fprintf(jf, ", \"pass\": %s}", M->tpass[t] ? "true" : "false");
      }
      fprintf(jf, "]");
    }
    fprintf(jf, "}");
  }
  fprintf(jf, "\n  ]\n}\n");
  if (fclose(jf) != 0) return fail("%s: write error", path);
  return 0;
}

/* Every model marked pass moves into place (reduce: all of them), then a
   sweep's record. 1 if a commit failed. */
static int reduce_commit(const reduce_args *A, reduce_state *S, const char *const *tests, int nt) {
  int k, any = 0;
  if (S->nmodels > 1 && write_sweep_json(A, S, tests, nt)) return 1;
  for (k = 0; k < S->nmodels; ++k) {
    if (!S->models[k].pass) { stage_abort(&S->models[k].sg); continue; }
    if (commit_model(A, S, &S->models[k])) return 1;
    any = 1;
  }
  if (S->nmodels > 1) {
    if (stage_commit(&S->sweep_sg)) return 1;
    any = 1;
    printf("wrote %s/%s_sweep.json (%d models)\n", A->out, A->name0, S->nmodels);
  }
  if (any) stage_free(&S->dirs, 0);   /* the directories stay */
  return 0;
}

/* A coordinate SPEC's files (FILE or rows,cols,vals) into ps. */
static void paths_add_coo(pathset *ps, const char *opt, const char *spec) {
  char path[4096];
  const char *a = spec;
  while (a) {
    const char *c = strchr(a, ',');
    const size_t l = c ? (size_t)(c - a) : strlen(a);
    if (l < sizeof path) { memcpy(path, a, l); path[l] = '\0'; paths_add(ps, opt, path, 0); }
    a = c ? c + 1 : NULL;
  }
}

/* Every file a run reads -- each option of input_opts and input_lists that
   was given, and validate's test inputs -- into ps. */
static void register_inputs(const reduce_args *A, pathset *ps, const char *const *tests, int nt) {
  int k, i;
  for (k = 0; input_opts[k].opt; ++k) {
    const char *v = *input_field((reduce_args *)A, k);
    if (!v) continue;
    if (input_opts[k].kind == OPTF_COO) paths_add_coo(ps, input_opts[k].opt, v);
    else if (input_opts[k].kind == OPTF_KIND) paths_add_input(ps, input_opts[k].opt, v);
    else paths_add(ps, input_opts[k].opt, v, 0);
  }
  for (k = 0; input_lists[k].opt; ++k) {
    const char *const *vals = (const char *const *)(const void *)((const char *)A + input_lists[k].off);
    const int n = *(const int *)(const void *)((const char *)A + input_lists[k].cnt);
    for (i = 0; i < n; ++i)
      if (input_lists[k].kind == OPTF_KIND) paths_add_input(ps, input_lists[k].opt, vals[i]);
      else paths_add(ps, input_lists[k].opt, vals[i], 0);
  }
  for (k = 0; k < nt; ++k) paths_add_input(ps, "--test-input", tests[k]);
}

/* The files a run reads (register_inputs) and the files it may write (every
   output its options can produce, with the temporary names of the staged
   writes) into S->pin, S->pout. */
static void reduce_paths(const reduce_args *A, reduce_state *S, const char *const *tests, int nt) {
  char path[4096 + 256];
  int k;
  reduce_args T = *A;
  char nm[128];
  int j;
  register_inputs(A, &S->pin, tests, nt);
  if (sweep_count(A) > 1) {
    snprintf(path, sizeof path, "%s/%s_sweep.json", A->out, A->name0); paths_add(&S->pout, "--out/--name", path, 1);
  }
  for (j = 0; j < sweep_count(A); ++j) {
    sweep_set(&T, j, nm, sizeof nm);
    snprintf(path, sizeof path, "%s/%s.phgmgrom", T.out, T.name); paths_add(&S->pout, "--out/--name", path, 1);
    snprintf(path, sizeof path, "%s/%s.c", T.out, T.name); paths_add(&S->pout, "--out/--name", path, 1);
    snprintf(path, sizeof path, "%s/%s.json", T.out, T.name); paths_add(&S->pout, "--out/--name", path, 1);
    for (k = 0; all_fields[k]; ++k) {
      if (!T.save_snap && (!strcmp(all_fields[k], "snapshots") || !strcmp(all_fields[k], "fom_y"))) continue;
      if (!T.form_ss != !ss_field(all_fields[k]) && strcmp(all_fields[k], "V0")) continue;   /* the other form's */
      snprintf(path, sizeof path, "%s/%s_%s.npy", T.out, T.name, all_fields[k]);
      paths_add(&S->pout, "--out/--name", path, 1);
    }
  }
}

/* The method code of --method, or -1. */
static int method_code(const char *m) {
  if (!strcmp(m, "gmg-pod")) return PHGMG_METHOD_GMG_POD;
  if (!strcmp(m, "gmg-qm")) return PHGMG_METHOD_GMG_QM;
  if (!strcmp(m, "sp1")) return PHGMG_METHOD_SP1;
  if (!strcmp(m, "sp2")) return PHGMG_METHOD_SP2;
  if (!strcmp(m, "bt")) return PHGMG_METHOD_BT;
  if (!strcmp(m, "prbt")) return PHGMG_METHOD_PRBT;
  if (!strcmp(m, "phbt")) return PHGMG_METHOD_PHBT;
  return -1;
}

/* Everything that can be checked before any computation: the method, no
   output an input or another output, the output directory usable, the files
   read and the system valid, the sizes. */
static int reduce_prepare(const reduce_args *A, reduce_state *S, const char *const *tests, int nt) {
  int e, k;
  reduce_args T = *A;
  char nm[128];
  const char *why;
  if ((S->method = method_code(A->method)) < 0)
    return usage_error("--method '%s': expected gmg-pod, gmg-qm, sp1, sp2, bt, prbt or phbt", A->method);
  reduce_paths(A, S, tests, nt);
  if ((e = check_collisions("reduce", &S->pin, &S->pout)) != 0) return e;
  g_inputs = &S->pin;
  /* the directory made now (removed again if the run fails) and a file tried in it */
  if (check_writable_dir(A->out, "--out", A->out, 1) || mkdir_p(A->out, &S->sg) ||
      check_writable_dir(A->out, "--out", A->out, 0))
    return 1;
  if ((e = load_system(A, S)) != 0) return e;
  if ((A->simulate || A->nxin || nt) && check_dt_scale(A, S)) return 1;
  for (k = 0; k < sweep_count(A); ++k) {   /* every model of a sweep, before any of them is built */
    sweep_set(&T, k, nm, sizeof nm);
    S->method = method_code(T.method);
    if (check_extras(&T, S)) return 1;
    if ((e = check_sizes(&T, S->method, S->sys.N, S->sys.m, S->dae ? phgmg_dae_nalg(S->dae) : 0)) != 0) return e;
  }
  S->method = method_code(A->method);
  if (A->X && stream_use(A, S, &why) && A->nml == 1) return 0;   /* read in blocks by reduce_build */
  return A->X ? load_snapshot_files(A, S, S->sys.N, S->sys.m, &S->Xd, &S->ns) : 0;
}

/* The error of a balancing method, explained. */
static int explain_balancing(const reduce_args *A, const reduce_state *S, phgmg_result rc) {
  const phgmg_balanced_info *b = &S->bal;
  switch (rc) {
    case PHGMG_ERR_STRUCTURE:
      return fail("reduction failed: the balanced truncation model of order %d is not passive, so it has no "
                  "port-Hamiltonian form (K + K^T <= 0); use --form ss for it as a state-space model (A, B, C, "
                  "D), --method prbt or phbt (pH by construction), or another --r (H-infinity error bound %.3g)",
                  A->r, b->lr.bound);
    case PHGMG_ERR_RANK:
      return fail("reduction failed: --r %d exceeds the %d singular values computed (the Gramian factors "
                  "have ranks %d and %d): use a smaller --r", A->r, b->lr.nhsv, b->lr.ctrl.rank, b->lr.obs.rank);
    case PHGMG_ERR_NOT_CONVERGED:
      return fail("reduction failed: %s (%s: residual %.3g after %d %s)", phgmg_result_string(rc),
                  A->lyap == PHGMG_LYAP_EKSM ? "extended Krylov" : "low-rank ADI",
                  b->lr.obs.iters ? b->lr.obs.res : b->lr.ctrl.res,
                  b->lr.obs.iters ? b->lr.obs.iters : b->lr.ctrl.iters,
                  A->lyap == PHGMG_LYAP_EKSM ? "blocks" : "steps");
    case PHGMG_ERR_UNSUPPORTED:
      if (S->sp && A->lyap == PHGMG_LYAP_EKSM && A->Ecoo && S->full.E) {
        int zr = 0, zc = 0;
        if (e_zero_lines(S, S->full.N, &zr, &zc, NULL, NULL) > 0)
          return fail("reduction failed: --lyap eksm takes a mass matrix of full rank only (--E-coo %s has %d "
                      "zero rows: algebraic equations); use --lyap adi", A->Ecoo, zr);
      }
      if (S->sp && S->dae_direct && A->Ecoo)
        return fail("reduction failed: a port acts on an algebraic equation (a zero row of E, %s): through the "
                    "constraint it has a feedthrough D, which the port-Hamiltonian forms of --method bt, prbt "
                    "and phbt do not carry; use --method bt --form ss for the state-space model with D, or "
                    "--method sp1 or sp2 (snapshots)", A->Ecoo);
      if (S->method == PHGMG_METHOD_PHBT && !S->sp)
        return fail("reduction failed: --method phbt needs the sparse model (--J-coo, --R-coo, --Q-coo)");
      return fail("reduction failed: %s (dense BT and PRBT take standard-form models: give a mass matrix as "
                  "--E-coo with --J-coo, --R-coo, --Q-coo for the low-rank solvers)", phgmg_result_string(rc));
    default:
      return fail("reduction failed: %s", phgmg_result_string(rc));
  }
}

/* --method bt, prbt, phbt: phgmg_balanced_reduce on the sparse model (COO
   input: the low-rank solvers) or the dense one (dense input: the dense
   solvers), with a progress line per phase after the first second. */
static int run_balancing(const reduce_args *A, reduce_state *S, double *t_red) {
  const phgmg_balanced_info *b = &S->bal;
  phgmg_lradi_opts lo;
  phase_log plog;
  phgmg_result rc;
  double t0;
  int runs0;
  if (S->dae && !S->sp)
    return fail("--method %s on an index-one descriptor model (E with zero rows): the dense solvers take "
                "standard-form models; give the model as COO files (--J-coo, --R-coo, --Q-coo, --E-coo) for the "
                "low-rank solvers", A->method);
  if (S->dae) return fail("--method %s on an index-one descriptor model (E with zero rows): not in one run with "
                          "snapshot methods; reduce with the balancing methods in a run of their own", A->method);
  memset(&lo, 0, sizeof lo);
  lo.maxit = A->adi_maxit;
  lo.solver = A->lyap;
  progress("reducing: %s, r = %d (%s solvers)", A->method, A->r, S->sp ? "low-rank, sparse" : "dense");
  t0 = now_s();
  plog.t0 = t0; plog.all = 0; plog.ncand = plog.nprobe = 0; plog.quiet = 0; plog.last = NULL;
  if (!g_quiet) { lo.progress = reduce_phase; lo.progress_user = &plog; }
  S->bal_on = 1;
  runs0 = S->bcache.adi_runs;
  rc = phgmg_balanced_reduce_cached(&S->red, S->sp ? NULL : &S->sys, S->sp, S->method, A->r, &lo, S->bal_sv, 64,
                                    &S->bal, &S->bcache, NULL);
  *t_red = now_s() - t0;
  if (rc != PHGMG_OK) return explain_balancing(A, S, rc);
  if (b->lowrank)
    progress("  Gramian factors: %s", S->bcache.adi_runs > runs0 ? (A->lyap == PHGMG_LYAP_EKSM ?
                                       "computed (extended Krylov, EKSM)" : "computed (low-rank ADI)")
                                       : "reused (computed once for this model in this run)");
  if (b->lowrank)
    progress("  done in %.2f s: Gramian factor ranks %d / %d, %s %d / %d, Lyapunov residuals %.2g / %.2g",
             *t_red, b->lr.ctrl.rank, b->lr.obs.rank, b->lr.ctrl.solver == PHGMG_LYAP_EKSM ? "EKSM blocks" : "ADI steps",
             b->lr.ctrl.iters, b->lr.obs.iters, b->res_ctrl, b->res_obs);
  else
    progress("  done in %.2f s: Lyapunov residuals %.2g / %.2g", *t_red, b->res_ctrl, b->res_obs);
  if (S->method == PHGMG_METHOD_BT)
    progress("  Hankel singular values: sigma_1 = %.6g, sigma_{r+1} = %.3g; H-infinity error bound 2 sum_{i>r} "
             "sigma_i = %.3g%s", S->bal_sv[0], b->lr.hsv_tail, b->lr.bound,
             b->ph_change > 0.0 ? "" : "");
  if (S->bal.stages == 2)
    progress("  two stages: the pH Galerkin projection onto the controllability factor (order %d), then the "
             "dense %s; %s singular values %.6g ... %.3g", b->inter,
             S->method == PHGMG_METHOD_PRBT ? "PRBT" : b->hmin ? "pH balancing against the minimal Hamiltonian"
                                                            : "pH balancing against the energy (no minimal Hamiltonian)",
             S->method == PHGMG_METHOD_PRBT ? "positive-real" : "pH", S->bal_sv[0],
             S->bal_sv[b->nsv > 0 ? b->nsv - 1 : 0]);
  return 0;
}

/* --method bt --form ss: phgmg_lrbt and phgmg_lrbt_feedthrough on the sparse
   model into S->ss, with the progress lines of run_balancing. */
static int run_ss_bt(const reduce_args *A, reduce_state *S, double *t_red) {
  const phgmg_ph_system *sy = phgmg_ph_sparse_system(S->sp);
  const int N = sy->N, m = sy->m, r = A->r;
  ss_model *M = &S->ss;
  phgmg_lradi_opts lo;
  phase_log plog;
  phgmg_result rc;
  double t0;
  memset(&lo, 0, sizeof lo);
  lo.maxit = A->adi_maxit;
  lo.solver = A->lyap;
  M->A = (double *)malloc(sizeof(double) * (size_t)r * (size_t)r);
  M->B = (double *)malloc(sizeof(double) * (size_t)r * (size_t)m);
  M->C = (double *)malloc(sizeof(double) * (size_t)m * (size_t)r);
  M->D = (double *)malloc(sizeof(double) * (size_t)m * (size_t)m);
  M->hsv = (double *)malloc(sizeof(double) * (size_t)r);
  M->T = (double *)malloc(sizeof(double) * (size_t)N * (size_t)r);
  if (!M->A || !M->B || !M->C || !M->D || !M->hsv || !M->T) return fail("out of memory");
  progress("reducing: bt, r = %d (low-rank, sparse), state-space form", r);
  t0 = now_s();
  plog.t0 = t0; plog.all = 0; plog.ncand = plog.nprobe = 0; plog.quiet = 0; plog.last = NULL;
  if (!g_quiet) { lo.progress = reduce_phase; lo.progress_user = &plog; }
  rc = phgmg_lrbt(S->sp, r, &lo, M->A, M->B, M->C, M->hsv, M->T, NULL, &M->inf, NULL);
  if (rc == PHGMG_OK) rc = phgmg_lrbt_feedthrough(S->sp, M->D, NULL);
  *t_red = now_s() - t0;
  if (rc != PHGMG_OK) {   /* the messages of the pH form's failures (ranks, steps, residuals) */
    S->bal.lr = M->inf;
    return explain_balancing(A, S, rc);
  }
  progress("  done in %.2f s: Gramian factor ranks %d / %d, %s %d / %d, Lyapunov residuals %.2g / %.2g", *t_red,
           M->inf.ctrl.rank, M->inf.obs.rank, M->inf.ctrl.solver == PHGMG_LYAP_EKSM ? "EKSM blocks" : "ADI steps",
           M->inf.ctrl.iters, M->inf.obs.iters, M->inf.ctrl.res, M->inf.obs.res);
  progress("  Hankel singular values: sigma_1 = %.6g, sigma_{r+1} = %.3g; H-infinity error bound 2 sum_{i>r} "
           "sigma_i = %.3g%s", M->hsv[0], M->inf.hsv_tail, M->inf.bound,
           M->inf.dmax > 0.0 ? "; feedthrough D (a port on a constraint)" : "");
  return 0;
}

/* The json record of a state-space model (--form ss): the model's files, the
   form, the solvers' ranks, steps and residuals, the values and the bound. */
static int write_ss_json(const reduce_args *A, reduce_state *S, double t_red, const outlist *ol) {
  const ss_model *M = &S->ss;
  const phgmg_ph_system *sy = phgmg_ph_sparse_system(S->sp);
  char path[4096 + 256];
  const char *wp;
  FILE *jf;
  int i, nalg = 0, zc = 0;
  snprintf(path, sizeof path, "%s/%s.json", A->out, A->name);
  if (!(wp = stage_path(&S->sg, path))) return 1;
  if (!(jf = fopen(wp, "w"))) return fail("%s: cannot write: %s", path, strerror(errno));
  if (S->full.E) e_zero_lines(S, S->full.N, &nalg, &zc, NULL, NULL);
  fprintf(jf, "{\n  \"phgmg_version\": \"%s\",\n  \"name\": ", PHGMG_VERSION_STRING);
  json_str(jf, A->name);
  fprintf(jf, ",\n  \"method\": \"bt\",\n  \"form\": \"ss\",\n  \"kind\": \"linear\",\n"
              "  \"model\": \"xr' = A xr + B u, y = C xr + D u\",\n");
  fprintf(jf, "  \"N\": %d, \"m\": %d, \"r\": %d,\n", sy->N, sy->m, A->r);
  fprintf(jf, "  \"E\": %s, \"N_full\": %d, \"algebraic\": %d, \"feedthrough\": %s", S->full.E ? "true" : "false",
          S->full.N, nalg, M->inf.dmax > 0.0 ? "true" : "false");
  json_system(jf, A, S);
  fprintf(jf, "},\n  \"info\": {\"solver\": \"low-rank\", \"lyapunov_solver\": \"%s\"",
          M->inf.ctrl.solver == PHGMG_LYAP_EKSM ? "eksm" : "adi");
  fprintf(jf, ", \"gramian_rank\": [%d, %d], \"adi_steps\": [%d, %d], \"factorizations\": [%d, %d]",
          M->inf.ctrl.rank, M->inf.obs.rank, M->inf.ctrl.iters, M->inf.obs.iters, M->inf.ctrl.factorizations,
          M->inf.obs.factorizations);
  fprintf(jf, ", \"lyapunov_residual\": ["); json_num(jf, M->inf.ctrl.res);
  fprintf(jf, ", "); json_num(jf, M->inf.obs.res);
  fprintf(jf, "], \"values_computed\": %d, \"hankel_singular_values\": [", M->inf.nhsv);
  for (i = 0; i < A->r; ++i) { if (i) fprintf(jf, ", "); json_num(jf, M->hsv[i]); }
  fprintf(jf, "], \"hsv_next\": "); json_num(jf, M->inf.hsv_tail);
  fprintf(jf, ", \"error_bound\": "); json_num(jf, M->inf.bound);
  fprintf(jf, ", \"feedthrough_max\": "); json_num(jf, M->inf.dmax);
  fprintf(jf, ", \"reduce_seconds\": "); json_num(jf, t_red);
  fprintf(jf, "},\n  \"reconstruction\": \"x = V0 @ xr\",\n  \"files\": {\n    \"arrays\": {");
  for (i = 0; i < ol->n; ++i)
    fprintf(jf, "%s\n      \"%s\": [%d, %d]", i ? "," : "", ol->names[i], ol->rows[i], ol->cols[i]);
  fprintf(jf, "\n    }\n  }\n}\n");
  if (fclose(jf) != 0) return fail("%s: write error", path);
  return 0;
}

/* --form ss's files: NAME_A, _B, _C, _D, the basis NAME_V0 (your ordering)
   and NAME.json, under their temporary names. */
static int write_ss_model(const reduce_args *A, reduce_state *S, double t_red) {
  const ss_model *M = &S->ss;
  const int r = A->r, m = phgmg_ph_sparse_system(S->sp)->m;
  outlist *ol = &S->ol;
  if (mkdir_p(A->out, &S->sg)) return 1;
  memset(ol, 0, sizeof *ol);
  if (write_field(A->out, A->name, "A", M->A, r, r, ol, &S->sg) ||
      write_field(A->out, A->name, "B", M->B, r, m, ol, &S->sg) ||
      write_field(A->out, A->name, "C", M->C, m, r, ol, &S->sg) ||
      write_field(A->out, A->name, "D", M->D, m, m, ol, &S->sg) ||
      write_user_field(A, S, "V0", M->T, r, ol))
    return 1;
  return write_ss_json(A, S, t_red, ol);
}

/* A sweep's shared bases: a study over the snapshots for the largest order
   asked (phgmg_study_create), so that each model's reduction works in the
   study's coordinates. A model class the study does not take (a mass
   matrix, feedthrough) or a study that fails: each model computes its own
   bases (said in the log). */
static void sweep_study(const reduce_args *A, reduce_state *S, const double *X, int ns) {
  const int N = S->sys.N, m = S->sys.m;
  phgmg_study_opts so;
  phgmg_result rc;
  int k, kmax = 0;
  unsigned what = 0;
  if (sweep_count(A) < 2) return;
  for (k = 0; k < sweep_count(A); ++k) {
    const int mc = A->mlist[k / A->nrl], r = A->rlist[k % A->nrl];
    if (mc == PHGMG_METHOD_GMG_POD || (mc == PHGMG_METHOD_GMG_QM && A->rn != PHGMG_RN_WIDE)) {
      const int rn = mc == PHGMG_METHOD_GMG_QM ? (A->rn ? A->rn : default_rn(N, r, m)) : 0;
      what |= PHGMG_STUDY_GMG;
      kmax = CLI_MAX(kmax, r - m + rn);
    } else if (mc == PHGMG_METHOD_SP1 || mc == PHGMG_METHOD_SP2) {
      what |= mc == PHGMG_METHOD_SP2 ? PHGMG_STUDY_SP2 : PHGMG_STUDY_SP;
      kmax = CLI_MAX(kmax, r);
    }
  }
  kmax = CLI_MIN(kmax + 1, CLI_MIN(N, ns));   /* one mode more: sigma_{r'+1} for the log */
  if (!what || kmax < 1) return;
  memset(&so, 0, sizeof so);
  so.what = what; so.kmax = kmax;
  progress("sweep of %d models: the snapshots' bases once, for up to %d modes", sweep_count(A), kmax);
  rc = phgmg_study_create(&S->study, &S->sys, X, N, ns, &so, NULL);
  if (rc != PHGMG_OK) {
    S->study = NULL;
    progress("  shared bases not available for this model (%s): each model computes its own",
             phgmg_result_string(rc));
  }
}

/* Model k of a run (one of a sweep): reduced, its arrays and files written
   under their temporary names, kept (keep) or destroyed. X NULL: the
   streamed snapshots (g_stream) or none (balancing). */
static int sweep_build_model(const reduce_args *A, reduce_state *S, int k, const double *X, int ns, int keep) {
  sweep_model *M = &S->models[k];
  reduce_args T = *A;
  phgmg_reduce_opts o;
  phgmg_reduce_info info;
  const phgmg_rom *rom;
  int e;
  memset(&o, 0, sizeof o);
  memset(&info, 0, sizeof info);
  sweep_set(&T, k, M->name, sizeof M->name);
  M->method = S->method = method_code(T.method);
  M->r = T.r;
  if (T.form_ss) {   /* bt as a state-space model: no phgmg_reduced (check_form: one model) */
    if ((e = run_ss_bt(&T, S, &M->t_red)) != 0 || (e = write_ss_model(&T, S, M->t_red)) != 0) return e;
    M->rr = T.r; M->m = S->sys.m; M->pass = 1; M->ss = 1;
    M->sg = S->sg; M->ol = S->ol;
    memset(&S->sg, 0, sizeof S->sg);
    return 0;
  }
  if (is_balancing(S->method)) {   /* no snapshots */
    if ((e = run_balancing(&T, S, &M->t_red)) != 0) return e;
    if ((e = write_arrays(&T, S, NULL, 0, &S->ol)) != 0) return e;
    if ((e = write_model_files(&T, S, S->method, 0, 0.0, M->t_red, &o, &info, &S->ol)) != 0) return e;
  } else {
    if ((e = run_reduction(&T, S, S->method, X, ns, &o, &info, &M->t_red)) != 0) return e;
    if ((e = write_arrays(&T, S, X, ns, &S->ol)) != 0) return e;
    if ((e = write_model_files(&T, S, S->method, ns, S->t_sim, M->t_red, &o, &info, &S->ol)) != 0) return e;
  }
  rom = phgmg_reduced_rom(S->red);
  M->rr = rom->r; M->m = rom->m; M->pass = 1;
  M->sg = S->sg; M->ol = S->ol;
  memset(&S->sg, 0, sizeof S->sg);
  if (keep) M->red = S->red;
  else phgmg_reduced_destroy(S->red);
  S->red = NULL;
  return 0;
}

/* The snapshots, the reduction and every output written under its temporary
   name (reduce_commit moves them into place). */
static int reduce_build(const reduce_args *A, reduce_state *S, int keep) {
  const double *X = S->Xd;
  int ns = S->ns, e, k;
  const char *why;
  const int stream = stream_use(A, S, &why);
  S->dirs = S->sg;   /* the directories made; each model stages its own files */
  memset(&S->sg, 0, sizeof S->sg);
  S->nmodels = sweep_count(A);
  S->models = (sweep_model *)calloc((size_t)S->nmodels, sizeof(sweep_model));
  if (!S->models) return fail("out of memory");
  if (stream && A->nml > 1)
    return usage_error("--stream: one method per run (the stream keeps one method's basis; a list of --r is fine)");
  if (!stream && A->stream) return usage_error("--stream: not with %s", why);
  if (stream) {   /* streamed: no snapshot matrix (run_reduction reduces from g_stream) */
    if ((e = A->X ? stream_x_files(A, S, &ns) : stream_training_runs(A, S, &ns, &S->t_sim)) != 0) return e;
  } else if (sweep_needs_snapshots(A) && !A->X && (e = simulate_training_runs(A, S, &X, &ns, &S->t_sim)) != 0)
    return e;
  if (!stream) sweep_study(A, S, X, ns);
  for (k = 0; k < S->nmodels; ++k)
    if ((e = sweep_build_model(A, S, k, stream ? NULL : X, ns, keep)) != 0) break;
  phgmg_pod_stream_destroy(g_stream);
  g_stream = NULL;
  return e;
}

static int cmd_reduce_impl(const reduce_args *A, reduce_state *S) {
  int e;
  if ((e = reduce_prepare(A, S, NULL, 0)) != 0) return e;
  if ((e = reduce_build(A, S, 0)) != 0) return e;
  return reduce_commit(A, S, NULL, 0);
}

static int cmd_reduce(int argc, char **argv) {
  reduce_args A;
  reduce_state S;
  int rc = parse_reduce(argc, argv, &A);
  if (rc) return rc < 0 ? 0 : rc;
  memset(&S, 0, sizeof S);
  S.dae_direct = A.Jcoo && !sweep_needs_snapshots(&A);   /* balancing only: a sparse index-one model on its pencil */
  rc = cmd_reduce_impl(&A, &S);
  reduce_cleanup(&S);
  return rc;
}

/* ---- simulate-rom --------------------------------------------------------------- */
/* opt names where the path came from ("--model", or "info" for the argument). */
static int load_model(const char *path, const char *opt, phgmg_rom *rom, void **block) {
  phgmg_result rc;
  FILE *f;
  if (is_dir(path, opt)) return 1;
  f = fopen(path, "rb");
  if (!f) return fail("%s (%s): cannot open: %s", path, opt, strerror(errno));
  fclose(f);
  rc = phgmg_rom_load(path, rom, block, NULL);
  if (rc != PHGMG_OK)
    return fail("%s (%s): not a usable phgmg model file: %s%s", path, opt, phgmg_result_string(rc),
                rc == PHGMG_ERR_DAMPER ? " (the file's damper weights or laws)"
                : rc == PHGMG_ERR_FEEDTHROUGH ? " (the file's feedthrough block)" : "");
  return 0;
}

/* Feedthrough of a reduced model: y += (S + N) u(t) (rom->PD's last m x m block). */
static void rom_feed_out(const phgmg_rom *rom, double t, cli_input *in, double *y) {
  double ub[64];
  int a, b;
  if (rom->m > 64) return;
  input_fn(t, ub, in);
  for (a = 0; a < rom->m; ++a)
    for (b = 0; b < rom->m; ++b) y[a] += (double)rom->PD[(size_t)rom->r * rom->m + a + (size_t)b * rom->m] * ub[b];
}

/* simulate-rom's options (0 / NULL: not given). */
typedef struct simrom_args {
  const char *model, *out, *states, *inspec, *x0;   /* x0: --x0, the reduced initial state */
  const char *ss;               /* --ss DIR/NAME: a state-space model (reduce --form ss) */
  double dt, amp, newton_tol;   /* newton_tol 0: the library's default */
  int steps, newton_iter, have_dt;
} simrom_args;

/* Parses simulate-rom's options into P: 0, -1 after --help, or the usage
   status 2. */
static int parse_simulate_rom(int argc, char **argv, simrom_args *P) {
  const char *seen[64];
  int nseen = 0, i;
  memset(P, 0, sizeof *P);
  P->inspec = "sin"; P->amp = 0.1; P->steps = 1000; P->newton_iter = 10;
  for (i = 2; i < argc; ++i) {
    const char *o = argv[i], *v;
    if (!strcmp(o, "--help") || !strcmp(o, "-h")) { print_help(); return -1; }
    if (repeated_opt(o, seen, &nseen)) return 2;
    else if (!strcmp(o, "--model")) { if (!(P->model = optval(argc, argv, &i))) return 2; }
    else if (!strcmp(o, "--ss")) { if (!(P->ss = optval(argc, argv, &i))) return 2; }
    else if (!strcmp(o, "--out")) { if (!(P->out = optval(argc, argv, &i))) return 2; }
    else if (!strcmp(o, "--states")) { if (!(P->states = optval(argc, argv, &i))) return 2; }
    else if (!strcmp(o, "--input")) { if (!(P->inspec = optval(argc, argv, &i))) return 2; }
    else if (!strcmp(o, "--dt")) {
      if (!(v = optval(argc, argv, &i)) || !parse_double(o, v, 0.0, &P->dt) || real_bad(o, v, P->dt)) return 2;
      if (!(P->dt > 0.0)) return usage_error("--dt must be > 0");
      P->have_dt = 1;
    }
    else if (!strcmp(o, "--amp")) { if (!(v = optval(argc, argv, &i)) || !parse_double(o, v, -HUGE_VAL, &P->amp) || real_bad(o, v, P->amp)) return 2; }
    else if (!strcmp(o, "--newton-tol")) { if (!(v = optval(argc, argv, &i)) || !parse_double(o, v, 0.0, &P->newton_tol) || real_bad(o, v, P->newton_tol)) return 2; }
    else if (!strcmp(o, "--steps")) { if (!(v = optval(argc, argv, &i)) || !parse_int(o, v, 1, INT_MAX - 1, &P->steps)) return 2; }
    else if (!strcmp(o, "--newton-iter")) { if (!(v = optval(argc, argv, &i)) || !parse_int(o, v, 1, 1000, &P->newton_iter)) return 2; }
    else if (!strcmp(o, "--quiet")) g_quiet = 1;
    else if (!strcmp(o, "--freq") || !strcmp(o, "--freq-end")) { if (parse_freq(argc, argv, &i)) return 2; }
    else if (!strcmp(o, "--x0")) { if (!(P->x0 = optval(argc, argv, &i))) return 2; }
    else return usage_error("simulate-rom: unknown option '%s'", o);
  }
  if (P->model && P->ss)
    return usage_error("simulate-rom: give one model: --model FILE (port-Hamiltonian) or --ss DIR/NAME (state-space)");
  if (P->ss && (!*P->ss || P->ss[strlen(P->ss) - 1] == '/'))
    return usage_error("--ss '%s': expected DIR/NAME, the prefix of NAME_A.npy, NAME_B.npy, NAME_C.npy and "
                       "NAME_D.npy", P->ss);
  if (!(P->model || P->ss) || !P->out)
    return usage_error("simulate-rom: --model FILE (or --ss DIR/NAME) and --out FILE are required");
  return 0;
}

/* simulate-rom's step: --dt, else the model's dt (its step map's, or the
   step it was trained at), else 0.1; a note when they differ or the model
   records none. 0 (never fails). */
/* The shortest decimal (as a double) that the build's phgmg_real rounds to v:
   a float build's 0.02f reads back as 0.02, as the user wrote it. */
static double real_decimal(phgmg_real v) {
  char b[40];
  int p;
  for (p = 6; p <= 17; ++p) {
    double d;
    snprintf(b, sizeof b, "%.*g", p, (double)v);
    d = strtod(b, NULL);
    if ((phgmg_real)d == v) return d;
  }
  return (double)v;
}

static int simrom_dt(const phgmg_rom *rom, int have_dt, double *dt) {
  const double mdt = real_decimal(rom->dt);
  const int what_ok = rom->Phi != NULL;
  const char *what = what_ok ? "step map's" : "training";
  if (!have_dt) {
    *dt = mdt > 0.0 ? mdt : 0.1;
    if (!(mdt > 0.0))
      note("the model records no training step: stepping at dt = 0.1; give the --dt of its training run");
    return 0;
  }
  if (mdt > 0.0 && fabs(*dt - mdt) > 1e-6 * mdt)
    note("--dt %g differs from the model's %s dt %g%s", *dt, what, mdt,
         what_ok ? " (the stepper then solves each step instead of applying the map)"
                 : " (a model follows its full model best at the step it was trained at)");
  return 0;
}

/* ---- simulate-rom --ss: a state-space model ------------------------------------- */
/* The model xr' = A xr + B u, y = C xr + D u of reduce --form ss, read from
   PREFIX_A.npy ... PREFIX_D.npy, and the 3-stage Gauss-Legendre step of it:
   the stage equations (I - dt (a (x) A)) K = [A x + B u(t + c_i dt)]_i
   factored once (LU of order 3 r), x <- x + dt sum_i b_i K_i. */
typedef struct ss_sim {
  mat A, B, C, D;
  int r, m;
  double *LU, *K, *x;   /* 3r x 3r factors, 3r stage values, r states */
  int *piv;
} ss_sim;

static void ss_sim_free(ss_sim *M) {
  mat_free(&M->A); mat_free(&M->B); mat_free(&M->C); mat_free(&M->D);
  free(M->LU); free(M->K); free(M->x); free(M->piv);
}

/* The four arrays' paths (path[k], k = A, B, C, D) of --ss PREFIX. */
static void ss_paths(const char *prefix, char path[4][4096 + 16]) {
  static const char *const f[4] = {"A", "B", "C", "D"};
  int k;
  for (k = 0; k < 4; ++k) snprintf(path[k], sizeof path[k], "%s_%s.npy", prefix, f[k]);
}

/* Reads the four arrays and checks their shapes (A r x r, B r x m, C m x r,
   D m x m). 0 or 1 after a message. */
static int ss_load(ss_sim *M, char path[4][4096 + 16]) {
  mat *a[4];
  int k, r, m;
  a[0] = &M->A; a[1] = &M->B; a[2] = &M->C; a[3] = &M->D;
  for (k = 0; k < 4; ++k)
    if (mat_load(a[k], "--ss", path[k])) return 1;
  r = M->A.rows; m = M->B.cols;
  if (M->A.cols != r || r < 1)
    return fail("%s (--ss): A must be square (r x r), got %s", path[0], shape_str(&M->A));
  if (M->B.rows != r || m < 1 || m > 64)
    return fail("%s (--ss): B must be r x m (r = %d, 1 <= m <= 64), got %s", path[1], r, shape_str(&M->B));
  if (M->C.rows != m || M->C.cols != r)
    return fail("%s (--ss): C must be m x r = %d x %d, got %s", path[2], m, r, shape_str(&M->C));
  if (M->D.rows != m || M->D.cols != m)
    return fail("%s (--ss): D must be m x m = %d x %d, got %s", path[3], m, m, shape_str(&M->D));
  M->r = r; M->m = m;
  return 0;
}

/* The Gauss-Legendre stage matrix I - dt (a (x) A), factored. 0 or 1. */
static int ss_gl3_setup(ss_sim *M, double dt, const char *prefix) {
  const double s = sqrt(15.0);
  const double a[3][3] = {{5.0 / 36, 2.0 / 9 - s / 15, 5.0 / 36 - s / 30},
                          {5.0 / 36 + s / 24, 2.0 / 9, 5.0 / 36 - s / 24},
                          {5.0 / 36 + s / 30, 2.0 / 9 + s / 15, 5.0 / 36}};
  const int r = M->r, n = 3 * r;
  int i, j, p, q;
  M->LU = (double *)calloc((size_t)n * (size_t)n, sizeof(double));
  M->K = (double *)malloc(sizeof(double) * (size_t)n);
  M->x = (double *)calloc((size_t)r, sizeof(double));
  M->piv = (int *)malloc(sizeof(int) * (size_t)n);
  if (!M->LU || !M->K || !M->x || !M->piv) return fail("out of memory");
  for (i = 0; i < 3; ++i)
    for (j = 0; j < 3; ++j)
      for (q = 0; q < r; ++q)
        for (p = 0; p < r; ++p)
          M->LU[(size_t)(i * r + p) + (size_t)(j * r + q) * n] = -dt * a[i][j] * M->A.a[p + (size_t)q * r];
  for (p = 0; p < n; ++p) M->LU[(size_t)p + (size_t)p * n] += 1.0;
  if (phgmg_lu_factor(n, M->LU, n, M->piv) != PHGMG_OK)
    return fail("%s: the stage equations of dt = %g are singular (A has an eigenvalue 1 / (dt a) for a stage "
                "weight a): try another --dt", prefix, dt);
  return 0;
}

/* y = C x + D u. */
static void ss_output(const ss_sim *M, const double *u, double *y) {
  int a, k;
  for (a = 0; a < M->m; ++a) {
    double acc = 0.0;
    for (k = 0; k < M->r; ++k) acc += M->C.a[a + (size_t)k * M->m] * M->x[k];
    for (k = 0; k < M->m; ++k) acc += M->D.a[a + (size_t)k * M->m] * u[k];
    y[a] = acc;
  }
}

/* One step from t: the stage values K_i = A (x + dt sum_j a_ij K_j) + B u_i, then x. */
static void ss_step(ss_sim *M, double t, double dt, cli_input *in) {
  const double s15 = sqrt(15.0) / 10.0, cs[3] = {0.5 - s15, 0.5, 0.5 + s15};
  const double b[3] = {5.0 / 18, 4.0 / 9, 5.0 / 18};
  const int r = M->r, m = M->m;
  double u[64];
  int i, p, k;
  for (i = 0; i < 3; ++i) {
    input_fn(t + cs[i] * dt, u, in);
    for (p = 0; p < r; ++p) {
      double acc = 0.0;
      for (k = 0; k < r; ++k) acc += M->A.a[p + (size_t)k * r] * M->x[k];
      for (k = 0; k < m; ++k) acc += M->B.a[p + (size_t)k * r] * u[k];
      M->K[i * r + p] = acc;
    }
  }
  phgmg_lu_solve('N', 3 * r, M->LU, 3 * r, M->piv, 1, M->K, 3 * r);
  for (p = 0; p < r; ++p) M->x[p] += dt * (b[0] * M->K[p] + b[1] * M->K[r + p] + b[2] * M->K[2 * r + p]);
}

/* --x0 for a state-space model: r values into M->x. 0 or 1. */
static int ss_x0(ss_sim *M, const char *file) {
  mat X;
  int a;
  if (mat_load(&X, "--x0", file)) return 1;
  if (X.ndim == 0 || X.rows != M->r || X.cols != 1) {
    fail("%s (--x0): expected the reduced initial state, shape (%d,) (r = %d values), got %s", file, M->r, M->r,
         shape_str(&X));
    mat_free(&X);
    return 1;
  }
  for (a = 0; a < M->r; ++a) M->x[a] = X.a[a];
  mat_free(&X);
  return 0;
}

/* The run: steps of dt from x0 (rest or --x0), the outputs (and states) into Y (XR). */
static void ss_run(ss_sim *M, const simrom_args *P, double dt, cli_input *in, double *Y, double *XR) {
  double u[64], t0 = now_s(), wall_last = t0;
  int n, a;
  for (n = 0; n <= P->steps; ++n) {
    if (n > 0) ss_step(M, (double)(n - 1) * dt, dt, in);
    input_fn((double)n * dt, u, in);
    ss_output(M, u, Y + (size_t)n * M->m);
    if (XR) for (a = 0; a < M->r; ++a) XR[a + (size_t)n * M->r] = M->x[a];
    if (!g_quiet && (n & 255) == 255 && now_s() - wall_last >= 2.0) {
      wall_last = now_s();
      progress("  ... step %d of %d (%.1f s)", n, P->steps, wall_last - t0);
    }
  }
  progress("  done in %.3f s (one LU of order %d)", now_s() - t0, 3 * M->r);
}

/* simulate-rom's outputs, both or neither (staged, then moved into place):
   the outputs y (m x steps + 1) to out and, if states is given, the reduced
   states (r x steps + 1). 0, or 1 after a message. */
static int write_rom_outputs(staged *sg, const char *out, const double *Y, int m, const char *states,
                             const double *XR, int r, int steps) {
  const char *wp;
  if (!(wp = stage_path(sg, out)) || write_npy(out, wp, Y, m, steps + 1, 2)) return 1;
  if (states && (!(wp = stage_path(sg, states)) || write_npy(states, wp, XR, r, steps + 1, 2))) return 1;
  if (stage_commit(sg)) return 1;
  printf("wrote %s (%d x %d)%s%s\n", out, m, steps + 1, states ? " and " : "", states ? states : "");
  return 0;
}

/* simulate-rom --ss DIR/NAME: the state-space model stepped by the same
   3-stage Gauss-Legendre method as the port-Hamiltonian models (at the same
   input points), the outputs as theirs: y (m x (steps+1)), --states xr. */
static int simulate_ss(const simrom_args *P) {
  char path[4][4096 + 16];
  pathset pin, pout;
  staged sg;
  cli_input in;
  ss_sim M;
  double dt = P->dt, *Y = NULL, *XR = NULL;
  int k, status = 1;
  memset(&pin, 0, sizeof pin); memset(&pout, 0, sizeof pout); memset(&sg, 0, sizeof sg);
  memset(&in, 0, sizeof in); memset(&M, 0, sizeof M);
  ss_paths(P->ss, path);
  for (k = 0; k < 4; ++k) paths_add(&pin, "--ss", path[k], 0);
  paths_add_input(&pin, "--input", P->inspec);
  if (P->x0) paths_add(&pin, "--x0", P->x0, 0);
  paths_add(&pout, "--out", P->out, 1);
  if (P->states) paths_add(&pout, "--states", P->states, 1);
  if ((status = check_collisions("simulate-rom", &pin, &pout)) != 0) goto done;
  status = 1;
  if (check_out_file(P->out, "--out") || (P->states && check_out_file(P->states, "--states"))) goto done;
  g_inputs = &pin;
  if (ss_load(&M, path)) goto done;
  if (!P->have_dt) {
    dt = 0.1;
    note("a state-space model records no step: stepping at dt = 0.1; give --dt");
  }
  if (P->newton_tol > 0.0 || P->newton_iter != 10)
    note("--newton-tol and --newton-iter do not apply to a state-space model (linear: one LU, no Newton)");
  if (too_big(((double)M.m + (P->states ? (double)M.r : 0.0)) * ((double)P->steps + 1.0),
               "--steps: the outputs (m x (steps+1), states r x (steps+1))")) { status = 2; goto done; }
  if ((status = input_setup(&in, "--input", P->inspec, P->amp, M.m, dt, P->steps * dt)) != 0) goto done;
  input_covers(&in, P->inspec, "--input", P->steps * dt);
  status = 1;
  Y = (double *)malloc(sizeof(double) * (size_t)M.m * ((size_t)P->steps + 1));
  if (P->states) XR = (double *)malloc(sizeof(double) * (size_t)M.r * ((size_t)P->steps + 1));
  if (!Y || (P->states && !XR)) { fail("out of memory for %d steps", P->steps); goto done; }
  if (ss_gl3_setup(&M, dt, P->ss) || (P->x0 && ss_x0(&M, P->x0))) goto done;
  progress("simulating %s (state-space, r = %d, m = %d): %d steps of dt = %g, %s", P->ss, M.r, M.m, P->steps, dt,
           input_desc(&in, P->inspec));
  ss_run(&M, P, dt, &in, Y, XR);
  status = write_rom_outputs(&sg, P->out, Y, M.m, P->states, XR, M.r, P->steps);
done:
  stage_abort(&sg);
  g_inputs = NULL;
  paths_free(&pin); paths_free(&pout);
  mat_free(&in.tab);
  ss_sim_free(&M);
  free(Y); free(XR);
  return status;
}

/* --model DIR/NAME.phgmgrom that does not exist where DIR/NAME_A.npy does (a
   model of reduce --form ss): the option to use instead. 0 or 1 after a message. */
static int model_is_ss(const char *model) {
  char pre[4096], a[4096 + 16];
  const size_t l = strlen(model);
  struct stat st;
  if (l < 9 || l >= sizeof pre || strcmp(model + l - 9, ".phgmgrom") != 0 || stat(model, &st) == 0) return 0;
  memcpy(pre, model, l - 9);
  pre[l - 9] = '\0';
  snprintf(a, sizeof a, "%s_A.npy", pre);
  if (stat(a, &st) != 0) return 0;
  return fail("%s (--model): no such file, but %s is there: a state-space model (reduce --form ss) has no model "
              "file; run it with simulate-rom --ss %s", model, a, pre);
}

static int cmd_simulate_rom(int argc, char **argv) {
  simrom_args P;
  const char *model, *out, *states, *inspec;
  double dt, amp, newton_tol, t0;
  int steps, newton_iter, have_dt, a, n, status = parse_simulate_rom(argc, argv, &P);
  phgmg_rom rom;
  void *block = NULL, *mem = NULL;
  phgmg_real *x = NULL, *u3, *y, *ework;
  double *Y = NULL, *XR = NULL, wall_last;
  phgmg_rom_stepper st;
  phgmg_result rc;
  cli_input in;
  size_t msz, nreal;
  staged sg;
  pathset pin, pout; /* the files read; the files written */
  if (status != 0) return status < 0 ? 0 : status;
  if (P.ss) return simulate_ss(&P);
  if (model_is_ss(P.model)) return 1;
  model = P.model; out = P.out; states = P.states; inspec = P.inspec;
  dt = P.dt; amp = P.amp; newton_tol = P.newton_tol;
  steps = P.steps; newton_iter = P.newton_iter; have_dt = P.have_dt;
  status = 1;
  memset(&in, 0, sizeof in);
  memset(&sg, 0, sizeof sg);
  memset(&pin, 0, sizeof pin);
  memset(&pout, 0, sizeof pout);
  paths_add(&pin, "--model", model, 0);
  paths_add_input(&pin, "--input", inspec);
  if (P.x0) paths_add(&pin, "--x0", P.x0, 0);
  paths_add(&pout, "--out", out, 1);
  if (states) paths_add(&pout, "--states", states, 1);
  if ((status = check_collisions("simulate-rom", &pin, &pout)) != 0) goto done;
  status = 1;
  if (check_out_file(out, "--out") || (states && check_out_file(states, "--states"))) goto done;
  g_inputs = &pin;
  if (load_model(model, "--model", &rom, &block)) goto done;
  if (simrom_dt(&rom, have_dt, &dt)) goto done;
  if (too_big(((double)rom.m + (states ? (double)rom.r : 0.0)) * ((double)steps + 1.0),
              "--steps: the outputs (m x (steps+1), states r x (steps+1))")) {
    status = 2;
    goto done;
  }
  if ((status = input_setup(&in, "--input", inspec, amp, rom.m, dt, steps * dt)) != 0) goto done;
  input_covers(&in, inspec, "--input", steps * dt);
  status = 1;
  msz = phgmg_rom_stepper_memsize_dt(&rom, (phgmg_real)dt);
  nreal = (size_t)rom.r + 4 * (size_t)rom.m + phgmg_rom_eval_work_size(&rom);
  mem = malloc(msz);
  x = (phgmg_real *)malloc(nreal * sizeof(phgmg_real));
  Y = (double *)malloc(sizeof(double) * (size_t)rom.m * ((size_t)steps + 1));
  if (states) XR = (double *)malloc(sizeof(double) * (size_t)rom.r * ((size_t)steps + 1));
  if (!mem || !x || !Y || (states && !XR)) { fail("out of memory for %d steps", steps); goto done; }
  u3 = x + rom.r; y = u3 + 3 * rom.m; ework = y + rom.m;
  rc = phgmg_rom_stepper_init(&st, &rom, (phgmg_real)dt, (phgmg_real)newton_tol, newton_iter, mem, msz);
  if (rc != PHGMG_OK) { fail("%s: cannot set up the stepper: %s", model, phgmg_result_string(rc)); goto done; }
  progress("simulating %s (r = %d, m = %d%s): %d steps of dt = %g%s, %s", model, rom.r, rom.m,
           rom.kind == PHGMG_ROM_QUADRATIC ? ", quadratic manifold" : "", steps, dt,
           st.use_map ? " (precomputed step map)" : "", input_desc(&in, inspec));
  for (a = 0; a < rom.r; ++a) x[a] = rom.xr_rest ? rom.xr_rest[a] : (phgmg_real)0;   /* from rest: rho(0) */
  if (P.x0) {   /* --x0: the reduced state xr0, r values */
    mat M;
    if (mat_load(&M, "--x0", P.x0)) goto done;
    if (M.ndim == 0 || M.rows != rom.r || M.cols != 1) {
      fail("%s (--x0): expected the reduced initial state, shape (%d,) (r = %d values), got %s", P.x0, rom.r, rom.r,
           shape_str(&M));
      mat_free(&M);
      goto done;
    }
    for (a = 0; a < rom.r; ++a) x[a] = (phgmg_real)M.a[a];
    mat_free(&M);
  }
  /* the same sequence of operations as phgmg_reduced_simulate */
#define RECORD(nn) do { \
    if (XR) for (a = 0; a < rom.r; ++a) XR[a + (size_t)(nn) * rom.r] = (double)x[a]; \
    phgmg_rom_output(&rom, x, y, ework); \
    for (a = 0; a < rom.m; ++a) Y[a + (size_t)(nn) * rom.m] = (double)y[a]; \
    if (rom.PD) rom_feed_out(&rom, (double)(nn) * dt, &in, Y + (size_t)(nn) * rom.m); \
  } while (0)
  RECORD(0);
  t0 = wall_last = now_s();
  for (n = 0; n < steps; ++n) {
    const double t = (double)n * dt;
    const double s15 = sqrt(15.0) / 10.0, cs[3] = {0.5 - s15, 0.5, 0.5 + s15};
    double ubuf[64], *ub = rom.m <= 64 ? ubuf : NULL;
    int s;
    if (!ub) { fail("%s: more than 64 inputs are not supported here", model); goto done; }
    for (s = 0; s < 3; ++s) {
      input_fn(t + cs[s] * dt, ub, &in);
      for (a = 0; a < rom.m; ++a) u3[s * rom.m + a] = (phgmg_real)ub[a];
    }
    rc = phgmg_rom_step(&st, x, u3, NULL, NULL);
    if (rc != PHGMG_OK) {
      fail("%s: step %d (t = %g) failed: %s%s", model, n + 1, t, phgmg_result_string(rc),
           rc == PHGMG_ERR_NOT_CONVERGED ? " (try a smaller --dt or more --newton-iter)" : "");
      goto done;
    }
    RECORD(n + 1);
    if (!g_quiet && (n & 255) == 255 && now_s() - wall_last >= 2.0) {
      wall_last = now_s();
      progress("  ... step %d of %d (%.1f s)", n + 1, steps, wall_last - t0);
    }
  }
#undef RECORD
  progress("  done in %.3f s (%ld Newton iterations, %ld factorizations)", now_s() - t0, st.stats.newton_iters,
           st.stats.factorizations);
  status = write_rom_outputs(&sg, out, Y, rom.m, states, XR, rom.r, steps);
done:
  stage_abort(&sg);
  g_inputs = NULL;
  paths_free(&pin); paths_free(&pout);
  mat_free(&in.tab);
  free(mem); free(x); free(Y); free(XR); free(block);
  return status;
}

/* ---- simulate (full model) ----------------------------------------------------- */
/* The options of `simulate`: the model options of reduce, --dt, --steps,
   --input, --amp, --newton-tol, --newton-iter, --out, --states, --quiet.
   Returns 0, the usage status 2, or -1 after --help. */
static int parse_simulate(int argc, char **argv, reduce_args *A, const char **states) {
  const char *seen[64];
  int i, k, nseen = 0;
  memset(A, 0, sizeof *A);
  A->dt = 0.1; A->steps = 1000; A->amp = 0.1; A->newton_iter = 10; A->input = "sin";
  *states = NULL;
  for (i = 2; i < argc; ++i) {
    const char *o = argv[i], *v;
    if (!strcmp(o, "--help") || !strcmp(o, "-h")) { print_help(); return -1; }
    if (repeated_opt(o, seen, &nseen)) return 2;
#define STR(opt, field) else if (!strcmp(o, opt)) { if (!(v = optval(argc, argv, &i))) return 2; A->field = v; }
    if (!strcmp(o, "--quiet")) g_quiet = 1;
    else if ((k = input_opt_find(o, 1)) >= 0) { if (!(v = optval(argc, argv, &i))) return 2; *input_field(A, k) = v; }
    STR("--potential", potential) STR("--out", out)
#undef STR
    else if (!strcmp(o, "--states")) { if (!(*states = optval(argc, argv, &i))) return 2; }
    else if (!strcmp(o, "--dt")) {
      if (!(v = optval(argc, argv, &i)) || !parse_double(o, v, 0.0, &A->dt)) return 2;
      if (!(A->dt > 0.0)) return usage_error("--dt must be > 0");
    }
    else if (!strcmp(o, "--steps")) { if (!(v = optval(argc, argv, &i)) || !parse_int(o, v, 1, INT_MAX - 1, &A->steps)) return 2; }
    else if (!strcmp(o, "--newton-iter")) { if (!(v = optval(argc, argv, &i)) || !parse_int(o, v, 1, 1000, &A->newton_iter)) return 2; }
    else if (!strcmp(o, "--amp")) { if (!(v = optval(argc, argv, &i)) || !parse_double(o, v, -HUGE_VAL, &A->amp)) return 2; }
    else if (!strcmp(o, "--newton-tol")) { if (!(v = optval(argc, argv, &i)) || !parse_double(o, v, 0.0, &A->newton_tol)) return 2; }
    else if (!strcmp(o, "--freq") || !strcmp(o, "--freq-end")) { if (parse_freq(argc, argv, &i)) return 2; }
    else return usage_error("simulate: unknown option '%s'", o);
  }
  if ((k = check_model_opts("simulate", A)) != 0) return k;
  if (!A->out) return usage_error("simulate: --out FILE is required");
  return 0;
}

/* simulate's outputs, before any work: neither --out nor --states is an
   input or the other output (compared as files), and each can be written.
   0, the usage status 2, or 1 after a message. */
static int simulate_outputs_ok(const reduce_args *A, reduce_state *S, const char *states) {
  int e;
  register_inputs(A, &S->pin, NULL, 0);
  paths_add(&S->pout, "--out", A->out, 1);
  if (states) paths_add(&S->pout, "--states", states, 1);
  if ((e = check_collisions("simulate", &S->pin, &S->pout)) != 0) return e;
  g_inputs = &S->pin;
  return check_out_file(A->out, "--out") || (states && check_out_file(states, "--states"));
}

/* phgmg simulate: the full model from x0 = 0 with the GL3 stepper; writes y
   (m x (steps+1)) and, with --states, x (N x (steps+1), the user's ordering). */
static int cmd_simulate(int argc, char **argv) {
  reduce_args A;
  reduce_state S;
  const char *states, *wp;
  phgmg_gl3_opts go;
  phgmg_gl3_stats st;
  phgmg_result rc;
  double *x0 = NULL, *X = NULL, *XU = NULL, *Y = NULL, t0;
  int status, N, m, done = 0;
  if ((status = parse_simulate(argc, argv, &A, &states)) != 0) return status < 0 ? 0 : status;
  memset(&S, 0, sizeof S);
  S.dae_direct = 1;   /* a sparse index-one model: no condensation */
  if ((status = simulate_outputs_ok(&A, &S, states)) != 0) goto out;
  status = 1;
  if (load_system(&A, &S) || check_dt_scale(&A, &S)) goto out;
  N = S.full.N;   /* an index-one model: phgmg_simulate gives consistent full states */
  m = S.full.m;
  if (too_big(((double)m + (states ? 2.0 * (double)N : 0.0)) * ((double)A.steps + 1.0),
              "--steps: the outputs (m x (steps+1), states N x (steps+1))")) {
    status = 2;
    goto out;
  }
  if ((status = input_setup(&S.in, "--input", A.input, A.amp, m, A.dt, A.steps * A.dt)) != 0) goto out;
  status = 1;
  x0 = (double *)calloc((size_t)N, sizeof(double));
  if (x0 && load_x0(&A, &S, N, x0)) goto out;
  Y = (double *)malloc(sizeof(double) * (size_t)m * ((size_t)A.steps + 1));
  if (states) X = (double *)malloc(sizeof(double) * (size_t)N * ((size_t)A.steps + 1));
  if (!x0 || !Y || (states && !X)) { fail("out of memory for %d steps", A.steps); goto out; }
  memset(&go, 0, sizeof go);
  go.tol = A.newton_tol;
  go.max_iter = A.newton_iter;
  progress("simulating the full model: %d steps of dt = %g, %s", A.steps, A.dt, input_desc(&S.in, A.input));
  S.in.report = 1;
  S.in.t_end = A.steps * A.dt;
  S.in.wall0 = S.in.wall_last = t0 = now_s();
  rc = phgmg_simulate(&S.full, x0, 0.0, A.dt, A.steps, input_fn, &S.in, &go, X, Y, NULL, &st, &done, NULL);
  S.in.report = 0;
  if (rc != PHGMG_OK) {
    fail("full-order simulation failed at step %d of %d (t = %g): %s%s", done + 1, A.steps, done * A.dt,
         phgmg_result_string(rc), rc == PHGMG_ERR_NOT_CONVERGED ? " (try a smaller --dt or more --newton-iter)" : "");
    goto out;
  }
  progress("  done in %.3f s (%ld Newton iterations, %ld factorizations)", now_s() - t0, st.newton_iters,
           st.factorizations);
  progress_newton_tol(&S.full, A.newton_tol, &st);
  note_band_fallback(&st);
  if (X && S.sp) { /* states back into the user's ordering */
    XU = (double *)malloc(sizeof(double) * (size_t)N * ((size_t)A.steps + 1));
    if (!XU) { fail("out of memory"); goto out; }
    phgmg_ph_sparse_to_user_order(S.sp, A.steps + 1, X, N, XU, N);
  }
  if (!(wp = stage_path(&S.sg, A.out)) || write_npy(A.out, wp, Y, m, A.steps + 1, 2)) goto out;
  if (states && (!(wp = stage_path(&S.sg, states)) || write_npy(states, wp, XU ? XU : X, N, A.steps + 1, 2))) goto out;
  if (stage_commit(&S.sg)) goto out;
  printf("wrote %s (%d x %d)%s%s\n", A.out, m, A.steps + 1, states ? " and " : "", states ? states : "");
  status = 0;
out:
  free(x0); free(X); free(XU); free(Y);
  reduce_cleanup(&S);
  return status;
}

/* ---- info --------------------------------------------------------------------- */
static int cmd_info(int argc, char **argv) {
  phgmg_rom rom;
  void *block = NULL;
  rom_field f[24];
  int nf, i;
  if (argc != 3) return usage_error("usage: phgmg info MODEL.phgmgrom");
  if (load_model(argv[2], "info", &rom, &block)) return 1;
  printf("%s: %s reduced model (%s), r = %d, m = %d", argv[2],
         rom.kind == PHGMG_ROM_QUADRATIC ? "quadratic-manifold"
         : rom.nd || rom.ndamp           ? "nonlinear (linear subspace)"
                                         : "linear",
         method_name(rom.method), rom.r, rom.m);
  if (rom.kind == PHGMG_ROM_QUADRATIC) printf(", r_n = %d", rom.rn);
  if (rom.nd) printf(", %d nonlinear terms (polynomial degree %d, %d exponentials%s)", rom.nd, rom.poly_deg, rom.nexp,
                     rom.nphi > 1 ? ", one function per term" : "");
  if (rom.Phi || rom.dt > 0) {
    char buf[32];
    printf(rom.Phi ? ", step map for dt = %s" : ", trained at dt = %s", num_str(real_decimal(rom.dt), buf));
  }
  if (rom.ndamp) printf(", %d nonlinear dampers (force law degree %d)", rom.ndamp, rom.damp_deg);
  if (rom.PD) printf(", feedthrough (S + N, %d x %d)", rom.m, rom.m);
  if (rom.PD)
    printf("\nfeedthrough: the output y of phgmg_rom_step and phgmg_rom_output leaves out (S + N) u; firmware "
           "adds (S + N) u(t) (phgmg_rom_output_u does); S + N is the %d x %d column-major block at PD + r m, "
           "after Ph (r x m) (simulate-rom adds it)", rom.m, rom.m);
  if (rom.ndamp)
    printf("\ndampers: the model keeps all %d (each evaluation of the reduced forces costs O(%d r)); "
           "phgmg_rom_step applies them", rom.ndamp, rom.ndamp);
  printf("\nstepper memory: %lu bytes", (unsigned long)phgmg_rom_stepper_memsize(&rom));
  if (rom.Phi) { /* the step map serves its own dt only; another dt needs the Newton workspace */
    const phgmg_real other = rom.dt * (phgmg_real)2;
    printf(" (at the step map's dt; %lu bytes for another dt)",
           (unsigned long)phgmg_rom_stepper_memsize_dt(&rom, other));
  }
  printf("; arrays:");
  nf = rom_fields(&rom, f);
  for (i = 0; i < nf; ++i) printf(" %s %dx%d", f[i].name, f[i].rows, f[i].cols);
  printf("\n");
  free(block);
  return 0;
}

/* ---- validate: reduce, then check the reduced model against the full one ----
   phgmg validate <every option of reduce> [--test-input KIND]... [--test-amp A]
                  [--test-steps N] [--max-ey E]
   Builds (and writes, as reduce does) the reduced model, then runs full and
   reduced model on each test input (KIND as --input; default: the training
   input) with phgmg_reduced_validate and prints e_red, e_y, e_proj, the energy
   error, Newton statistics (iterations per step), the steps outside the
   training envelope (outside) and with a quadratic correction above the
   training maximum (q-out), and the first failing step. Exit status 1 if any test fails (a Newton failure in the reduced run,
   or e_y above --max-ey, default 0.1); 0 if all pass; 2 bad usage. */
/* validate's own options, taken out of the command line (the rest is
   reduce's). Returns 0 or the usage status 2. */
typedef struct validate_args {
  const char *tests[16];
  int nt, steps_t, have_amp;
  double amp_t, max_ey;
} validate_args;

static int parse_validate(int argc, char **argv, validate_args *V, const char **reduce_argv, int *rargc) {
  const char *seen[8];
  int i, nseen = 0;
  memset(V, 0, sizeof *V);
  V->max_ey = 0.1;
  *rargc = 0;
  for (i = 0; i < argc; ++i) {
    const char *o = argv[i], *v;
    const int mine = i >= 2 && (!strcmp(o, "--test-input") || !strcmp(o, "--test-amp") ||
                                !strcmp(o, "--test-steps") || !strcmp(o, "--max-ey"));
    if (!mine) {
      if (*rargc >= 255) return usage_error("validate: too many arguments");
      reduce_argv[(*rargc)++] = o;
      continue;
    }
    if (!(v = optval(argc, argv, &i))) return 2;
    if (!strcmp(o, "--test-input")) {   /* repeatable: one test each */
      if (V->nt >= 16) return usage_error("validate: at most 16 --test-input");
      V->tests[V->nt++] = v;
      continue;
    }
    if (repeated_opt(o, seen, &nseen)) return 2;
    if (!strcmp(o, "--test-amp")) {
      if (!parse_double(o, v, -HUGE_VAL, &V->amp_t)) return 2;
      V->have_amp = 1;
    } else if (!strcmp(o, "--test-steps")) {
      if (!parse_int(o, v, 1, INT_MAX - 1, &V->steps_t)) return 2;
      if (too_big((double)V->steps_t + 1.0, "--test-steps: the full model's trajectory (N x (steps+1)) alone"))
        return 2; /* N >= 1: a first check before reading J */
    } else { /* --max-ey */
      if (!parse_double(o, v, 0.0, &V->max_ey)) return 2;
      if (!(V->max_ey > 0.0)) return usage_error("--max-ey %s: the bound on e_y must be > 0", v);
    }
  }
  reduce_argv[*rargc] = NULL;
  return 0;
}

/* A test that could not be made: the reason in the user's terms. */
static int validate_error(const char *spec, phgmg_result rc, const reduce_state *S, int nsteps) {
  if (rc == PHGMG_ERR_OVERFLOW)
    return fail("validate: %s: the states or the error norms overflow the double range (try a smaller "
                "--test-amp)", spec);
  if (rc == PHGMG_ERR_NANINF)
    return fail("validate: %s: the full model's run overflows or meets NaN (states beyond the double range; "
                "try a smaller --test-amp)", spec);
  if (rc == PHGMG_ERR_NOMEM) { /* the library's error norms gave NaN, or memory is short: tell which */
    const phgmg_rom *rom = phgmg_reduced_rom(S->red);
    void *p = malloc(sizeof(double) * ((size_t)S->sys.N + 2 * (size_t)S->sys.m + (size_t)rom->r + 8) *
                     ((size_t)nsteps + 1));
    free(p);
    if (p)
      return fail("validate: %s: the error norms overflow the double range (states of magnitude 1e154 or more: "
                  "try a smaller --test-amp)", spec);
  }
  if (rc == PHGMG_ERR_NOT_CONVERGED)
    return fail("validate: %s: the full model's run failed: %s (try a smaller --dt or more --newton-iter)", spec,
                phgmg_result_string(rc));
  return fail("validate: %s: %s", spec, phgmg_result_string(rc));
}

/* One test of validate: the full model and every model of the run on input
   `spec` over nsteps from x0 (NULL: 0), one full run for all of them
   (phgmg_reduced_validate_many); prints a line per model; a model that fails
   loses its pass mark. Test t of the run. 0 all pass, 1 a fail or an error. */
static int validate_test(const reduce_args *A, reduce_state *S, cli_input *in, const char *spec, int nsteps,
                         const double *x0, double max_ey, int t) {
  const phgmg_ph_system sys = S->sys;   /* as reduced: any potential, sparse input in its internal order */
  const phgmg_reduced *reds[32];
  phgmg_validation vs[32];
  phgmg_run run;
  phgmg_result rc;
  int k, bad = 0;
  memset(&run, 0, sizeof run);
  run.u = input_fn; run.user = in; run.dt = A->dt; run.nsteps = nsteps; run.x0 = x0;
  for (k = 0; k < S->nmodels; ++k) reds[k] = S->models[k].red;
  /* progress of the runs (full, then each reduced one) every 2 s, from the input callback */
  in->report = 1; in->t_end = nsteps * A->dt; in->wall0 = in->wall_last = now_s();
  rc = phgmg_reduced_validate_many(reds, S->nmodels, &sys, &run, A->newton_tol, A->newton_iter, max_ey, vs, NULL);
  in->report = 0;
  if (rc != PHGMG_OK) {
    for (k = 0; k < S->nmodels; ++k) S->models[k].pass = 0;
    S->red = S->models[0].red;
    validate_error(spec, rc, S, nsteps);
    S->red = NULL;
    return 1;
  }
  for (k = 0; k < S->nmodels; ++k) {
    const phgmg_validation *v = &vs[k];
    sweep_model *M = &S->models[k];
    char label[160];
    if (S->nmodels > 1) snprintf(label, sizeof label, "%s [%s r=%d]", spec, method_name(M->method), M->r);
    else snprintf(label, sizeof label, "%s", spec);
    M->ey[t] = v->e_y; M->ered[t] = v->e_red; M->tpass[t] = 0;
    printf("%-24s %10.3e %10.3e %10.3e %10.3e %10.3e %8.2f %8ld %8ld %8d  %s\n", label, v->e_red, v->e_y, v->e_proj,
           v->e_energy, v->e_energy_fom, v->stats.steps ? (double)v->stats.newton_iters / v->stats.steps : 0.0,
           v->stats.outside_steps, v->stats.q_outside_steps, v->first_failure, v->pass ? "pass" : "FAIL");
    if (v->first_failure >= 0)
      printf("  first failing step: %d (t = %g -> %g): %s\n", v->first_failure, v->first_failure * A->dt,
             (v->first_failure + 1) * A->dt, phgmg_result_string(v->rom_rc));
    else if (!(isfinite(v->e_y) && isfinite(v->e_red) && isfinite(v->e_proj)))
      printf("  the error norms overflow the double range (states too large; try a smaller --test-amp)\n");
    else if (!v->pass)
      printf("  e_y %.3e above --max-ey %g\n", v->e_y, max_ey);
    if (v->pass && v->first_failure < 0 && isfinite(v->e_y) && isfinite(v->e_red) && isfinite(v->e_proj))
      M->tpass[t] = 1;
    else { M->pass = 0; bad = 1; }
  }
  return bad;
}

/* ---- validate: reduce, then check the reduced model against the full one ----
   phgmg validate <every option of reduce> [--test-input KIND]... [--test-amp A]
                  [--test-steps N] [--max-ey E]
   Builds the reduced model as reduce does, then runs full and reduced model on
   each test input (KIND as --input; default: the training input(s), with --X
   the --X-input runs from their first snapshot) with phgmg_reduced_validate
   and prints e_red, e_y, e_proj, the energy error, Newton statistics
   (iterations per step), the steps outside the training envelope (outside)
   and with a quadratic correction above the training maximum (q-out), and
   the first failing step. Each test runs --test-steps steps, default the
   length of the training run. The outputs are written (as reduce writes
   them) only when every test passes: a failing model never replaces the one
   under --out. Exit status 1 if any test fails (a Newton failure in the
   reduced run, or e_y above --max-ey, default 0.1); 0 if all pass; 2 bad
   usage. Every option and test input is checked before any computation. */
static int cmd_validate(int argc, char **argv) {
  const char *reduce_argv[256];
  validate_args V;
  cli_input tin[16];
  int steps[16], from_x[16];
  int rargc = 0, i, k, status = 0, nt;
  reduce_args A;
  reduce_state S;
  if ((i = parse_validate(argc, argv, &V, reduce_argv, &rargc)) != 0) return i;
  g_validating = 1;
  i = parse_reduce(rargc, (char **)reduce_argv, &A);
  g_validating = 0;
  if (i != 0) return i;
  nt = V.nt;
  memset(from_x, 0, sizeof from_x);
  if (nt == 0 && A.ntrain)   /* default: the training inputs */
    for (i = 0; i < A.ntrain; ++i) V.tests[nt++] = A.train[i];
  if (nt == 0 && A.nxin)     /* --X: the inputs of the snapshot runs, from their first snapshot */
    for (i = 0; i < A.nxin; ++i) { from_x[nt] = 1; V.tests[nt++] = A.xin[i]; }
  if (nt == 0 && !A.simulate && !balancing_method(A.method))
    return usage_error("validate: with --X give --test-input (or --X-input): the inputs that made the snapshots are unknown");
  if (nt == 0) V.tests[nt++] = A.input;
  memset(&S, 0, sizeof S);
  S.dae_direct = A.Jcoo && !sweep_needs_snapshots(&A);   /* balancing only: a sparse index-one model on its pencil */
  memset(tin, 0, sizeof tin);
  status = reduce_prepare(&A, &S, V.tests, nt);
  for (k = 0; k < nt && !status; ++k) { /* every test input and run length, up front */
    /* the training run's length: --steps, or the --X run's (the first run's for a --test-input) */
    const int run = from_x[k] ? k : 0;
    steps[k] = V.steps_t ? V.steps_t : !A.X ? A.steps : (run ? S.Xs[run].cols : S.X.cols) - 1;
    status = input_setup(&tin[k], "--test-input", V.tests[k], V.have_amp ? V.amp_t : A.amp, S.sys.m, A.dt,
                         steps[k] * A.dt);
    if (!status) input_covers(&tin[k], V.tests[k], "--test-input", steps[k] * A.dt);
    if (!status && too_big(((double)S.sys.N + 2.0 * S.sys.m + max_order(&A) + 8.0) * ((double)steps[k] + 1.0),
                           "validate: a test run (the full model's states and outputs, N x (steps+1))"))
      status = 2;
  }
  if (!status) status = reduce_build(&A, &S, 1);
  if (status == 0) {
    printf("%-24s %10s %10s %10s %10s %10s %8s %8s %8s %8s  %s\n", "test input", "e_red", "e_y", "e_proj", "e_energy",
           "(FOM)", "newton", "outside", "q-out", "fail@", "verdict");
    for (k = 0; k < nt; ++k)
      if (validate_test(&A, &S, &tin[k], V.tests[k], steps[k], from_x[k] ? S.runs[k].x0 : NULL, V.max_ey, k))
        status = 1;
    printf("validate: %s\n", status ? "FAILED" : "passed");
    for (k = 0; k < S.nmodels; ++k)
      if (!S.models[k].pass)
        printf("validate: the model was not written: %s/%s.* is unchanged (the same options with `phgmg reduce` "
               "write the failing model)\n", A.out, S.models[k].name);
    if (reduce_commit(&A, &S, V.tests, nt)) status = 1;
  }
  for (k = 0; k < 16; ++k) mat_free(&tin[k].tab);
  reduce_cleanup(&S);
  return status;
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fputs("usage: phgmg reduce ... | phgmg validate ... | phgmg simulate ... | phgmg simulate-rom ... | phgmg info MODEL"
          " | phgmg --help | phgmg --version\n", stderr);
    return 2;
  }
  if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) {
    print_help();
    return 0;
  }
  if (!strcmp(argv[1], "--version")) { printf("phgmg %s\n", PHGMG_VERSION_STRING); return 0; }
  if (!strcmp(argv[1], "reduce")) return cmd_reduce(argc, argv);
  if (!strcmp(argv[1], "simulate-rom")) return cmd_simulate_rom(argc, argv);
  if (!strcmp(argv[1], "simulate")) return cmd_simulate(argc, argv);
  if (!strcmp(argv[1], "info")) return cmd_info(argc, argv);
  if (!strcmp(argv[1], "validate")) return cmd_validate(argc, argv);
  return usage_error("unknown command '%s' (expected reduce, validate, simulate, simulate-rom, info, --help or --version)",
                     argv[1]);
}
