/* The distributed command line: `phgmg reduce` on P MPI ranks.

     make build/phgmg-mpi        (mpicc; the library with PHGMG_MPI)
     mpirun -np P build/phgmg-mpi reduce --J-coo J.npy --R-coo R.npy --Q-coo Q.npy \
         --B B.npy --X X.npy --method gmg-pod|gmg-qm|sp1|sp2 --r R --out DIR [--name rom] [--dt DT] [--quiet]
         [--manifold pod|greedy] [--rn RN] [--lambda L] [--dampers D.npy]
         [--potential NAME | --poly c.npy [--exp e.npy]] --poly-idx idx.npy [--poly-w w.npy]
         [--hyper ecsw] [--hyper-tol T] [--no-hyper]

   It reads the files of the serial `phgmg reduce` (J, R, Q as (nnz, 3) .npy
   arrays of (row, col, value) triplets, 0-based, duplicates summed; B (N,)
   or (N, m); the snapshots X (N, ns); a separable nonlinear part
   H_nl = sum_k w_k phi_k(x[idx_k]) as the serial command takes it) and
   writes what the serial command writes for the same options:
   DIR/NAME.phgmgrom, DIR/NAME.c, DIR/NAME.json and the arrays
   DIR/NAME_Bh.npy, _Qh.npy, _K.npy, _V0.npy (with kept nonlinear terms also
   _P0.npy, _w.npy, _poly.npy, _expo.npy; gmg-qm the quadratic model's
   blocks, _V2.npy and _M.npy instead of _K.npy). Every rank reads the terms' small
   files whole and keeps the terms on its own rows, numbered as the serial
   command numbers them; the hyper-reduction (ECSW, the serial default) is
   the library's distributed one, so the kept terms are the serial run's.
   Each rank keeps its own contiguous block of rows of the state: of Q, B,
   the snapshots (read a batch of columns at a time) and, for sp1, of
   J - R. The solves with J - R that GMG-POD needs go through the library's
   sparse LU of J - R, replicated on every rank (the right-hand sides are
   gathered, solved, and each rank keeps its rows): fine while that factor
   fits on one rank; examples/petsc_mumps.c puts MUMPS (a distributed
   factor) behind the same solve callback. Rank 0 writes the outputs; V0
   (and V2) are gathered a column at a time. Manual section 2.7. */
#define _POSIX_C_SOURCE 200809L
#define PHGMG_MPI
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

/* In parts: C99 compilers need take no string longer than 4095 characters. */
static const char *const help_text[] = {
  "phgmg-mpi " PHGMG_VERSION_STRING " - the distributed `phgmg reduce` (MPI): port-Hamiltonian models\n"
  "x' = (J - R) grad H(x) + B u, y = B^T grad H(x), with H(x) = 1/2 x^T Q x (linear) or\n"
  "H(x) = 1/2 x^T Q x + sum_k w_k phi_k(x[idx_k]) (separable terms), reduced on P ranks.\n"
  "\n"
  "USAGE\n"
  "  mpirun -np P phgmg-mpi reduce --J-coo J.npy --R-coo R.npy --Q-coo Q.npy --B B.npy\n"
  "               --X X.npy --method gmg-pod|gmg-qm|sp1|sp2 --r R --out DIR [--name rom]\n"
  "               [--dt DT] [--quiet] [--manifold pod|greedy] [--rn RN] [--lambda L]\n"
  "               [--potential NAME | --poly FILE [--exp FILE]] --poly-idx FILE\n"
  "               [--poly-w FILE] [--hyper ecsw|qdeim|greedy] [--hyper-tol T]\n"
  "               [--deim-tol T] [--deim-max K] [--deim-allow-negative] [--no-hyper]\n"
  "               [--E-coo E.npy] [--dampers D.npy]\n"
  "  phgmg-mpi --help | --version\n"
  "\n",
  "OPTIONS (those of `phgmg reduce`, with the same meaning)\n"
  "  --J-coo FILE, --R-coo FILE, --Q-coo FILE   J, R, Q as (nnz, 3) .npy arrays of\n"
  "                      (row, col, value) triplets, 0-based, duplicates summed.\n"
  "  --E-coo FILE        a mass matrix E, (nnz, 3) triplets: the descriptor model\n"
  "                      E x' = (J - R) z + B u, E^T z = grad H (E^T Q symmetric; E's\n"
  "                      rows at the terms' coordinates positive multiples of unit\n"
  "                      rows); gmg-pod only. E of full rank, or of index one: zero\n"
  "                      rows (algebraic equations) and as many zero columns\n"
  "                      (algebraic variables), no port on a zero row; the model is\n"
  "                      then checked as the serial command checks it (index one)\n"
  "                      and reduced as the serial command reduces it (the condensed\n"
  "                      model; V0's rows at the algebraic variables are zero). Its\n"
  "                      solves use the library's sparse LU of E, replicated as that\n"
  "                      of J - R.\n"
  "  --dampers FILE      nonlinear dampers, a (k, 4) array with rows (i, j, c1, c3): a\n"
  "                      damper on s = z_i - z_j (j = -1: s = z_i) with the force\n"
  "                      c1 s + c3 s^3, c1, c3 >= 0; gmg-pod, sp1, sp2 without --E-coo.\n"
  "                      The reduced model keeps every damper (the hyper-reduction\n"
  "                      options apply to the nonlinear terms only); the replicated\n"
  "                      LU is then of J - R - L, L the dampers' c1 terms.\n"
  "  --B FILE            N x m port matrix, or a vector of length N for m = 1 (N is\n"
  "                      taken from B).\n"
  "  --X FILE            the snapshots, N x ns (one state per column). Every rank reads\n"
  "                      only its own rows, a batch of columns at a time.\n"
  "  --method M          gmg-pod (generalized manifold Galerkin on the POD of the\n"
  "                      snapshots adjusted by B), sp1 (structure-preserving\n"
  "                      Galerkin on the POD of the snapshots) or sp2 (sp1's trial\n"
  "                      basis, the test basis from the POD of the gradient snapshots)\n"
  "                      or gmg-qm (the quadratic manifold phi(x) = [B, V1] x +\n"
  "                      V2 M (x2 kron x2), with --lambda a fixed value or cv).\n"
  "  --r R               the reduced order (gmg-pod, gmg-qm: R > m; sp1, sp2: R <= ns).\n"
  "  --out DIR           output directory (created if missing).\n"
  "  --name NAME         base name of the outputs (default rom; a C identifier).\n"
  "  --dt DT             the snapshots' step, recorded in the model file\n"
  "                      (simulate-rom's default step).\n"
  "  --quiet             no summary line.\n"
  "\n",
  "GMG-QM (--method gmg-qm)\n"
  "  --lambda L          required here: the ridge parameter of the quadratic fit M, on the\n"
  "                      un-normalised sum over the snapshots (e.g. 1e-3, the paper's;\n"
  "                      0 means exactly zero), or cv: chosen on a grid by held-out\n"
  "                      regression error (time blocks; the serial --lambda cv, which\n"
  "                      measures the regression, not the reduced model, and can pick\n"
  "                      very small lambdas). The serial default, --lambda auto,\n"
  "                      chooses it by simulating the runs, which phgmg-mpi does not do.\n"
  "  --manifold KIND     pod (default: V1 the leading POD modes of the snapshots adjusted\n"
  "                      by B) or greedy (V1 chosen greedily among the leading modes for\n"
  "                      the quadratic fit).\n"
  "  --rn RN             the lifting dimension, 1..4096 (default min(8, N - R,\n"
  "                      4096 / (R - m))); V2 the RN leading POD modes of the snapshots'\n"
  "                      residual after [B, V1].\n"
  "\n",
  "NONLINEAR PART (optional; as `phgmg reduce` takes it)\n"
  "  --poly FILE         phi from the exp-polynomial family phi(s) = sum_j c_j s^j +\n"
  "                      sum_e a_e exp(b_e s): the coefficients c_0, ..., c_d as a vector\n"
  "                      (shared by every term) or a (terms, d+1) matrix (one row per term).\n"
  "  --exp FILE          the exponentials (a_e, b_e): (n_exp, 2) shared, or (terms, 2 n_exp)\n"
  "                      per term (a (terms, 2) matrix with up to 8 terms is per term only\n"
  "                      beside a per-term --poly).\n"
  "  --potential NAME    a named potential instead of --poly/--exp: toda (e^s - 1 - s),\n"
  "                      cosh:A ((cosh(A s) - 1)/A^2, A != 0), morse:D:A (D (1 - e^{-A s})^2,\n"
  "                      D > 0, A != 0), fpu:K3:K4 (K3 s^3/3 + K4 s^4/4, K4 > 0). An energy\n"
  "                      unbounded below is refused.\n"
  "  --poly-idx FILE     the 0-based state coordinate of each term (a vector; term k is\n"
  "                      entry k, wherever its coordinate lies among the ranks' rows).\n"
  "  --poly-w FILE       the terms' weights w_k (default all 1).\n"
  "  --hyper H           the hyper-reduction: ecsw (the default) keeps a few terms with\n"
  "                      weights >= 0; qdeim or greedy: structure-preserving DEIM on the\n"
  "                      terms' gradients with Q-DEIM or greedy points (weights of either\n"
  "                      sign). The serial run's terms and weights, in its order.\n"
  "  --hyper-tol T       ECSW's relative training residual (default 1e-6; 1e-14 <= T < 1).\n"
  "  --deim-tol T        qdeim/greedy: keep the modes with sigma_k / sigma_1 > T\n"
  "                      (default 1e-8; 0 <= T < 1).\n"
  "  --deim-max K        qdeim/greedy: at most K DEIM points (default: no cap).\n"
  "  --deim-allow-negative  qdeim/greedy: accept negative weights (else refused: the\n"
  "                      reduced energy may then not be bounded below).\n"
  "  --no-hyper          keep every term online (exact, cost O(terms)); --no-deim is the\n"
  "                      former name.\n"
  "\n",
  "CHECKS\n"
  "  As the serial command: J skew-symmetric, R symmetric positive semidefinite\n"
  "  (relative tolerance 1e-12), B of full column rank, J - R nonsingular, indices\n"
  "  in range, no NaN/Inf; the outputs must not be input files. Q's symmetry and\n"
  "  definiteness are not checked here (every rank holds only its rows of Q).\n"
  "\n"
  "OUTPUTS (written by rank 0, the files of the serial `phgmg reduce`)\n"
  "  DIR/NAME.phgmgrom   the reduced model (phgmg simulate-rom, phgmg info)\n"
  "  DIR/NAME.c          the model as C source\n"
  "  DIR/NAME.json       what was reduced and how (with \"mpi_ranks\" and the solver)\n"
  "  DIR/NAME_Bh.npy, DIR/NAME_Qh.npy, DIR/NAME_K.npy   the reduced blocks\n"
  "  DIR/NAME_V0.npy     the basis (N x r): x = V0 @ xr\n"
  "  DIR/NAME_G00.npy, _G01, _G10, _G11, _Q01, _Q11, _Ms, _P1 (gmg-qm, in place of\n"
  "                      _K) the quadratic model's blocks; DIR/NAME_V2.npy (N x RN) and\n"
  "                      DIR/NAME_M.npy (RN x (R - m)^2): x = V0 @ xr + V2 @ (M @\n"
  "                      kron(xr[m:], xr[m:]))\n"
  "  DIR/NAME_P0.npy, _w.npy, _poly.npy, _expo.npy   with nonlinear terms kept: their rows\n"
  "                      of V0, weights and functions (expo only with exponentials)\n"
  "\n"
  "DISTRIBUTION\n"
  "  Rank p keeps rows [row0, row0 + nloc) of the state, contiguous blocks of\n"
  "  N / P rows in rank order: its rows of Q, B and the snapshots (and, for sp1,\n"
  "  of J - R), and the nonlinear terms whose coordinate is one of its rows.\n"
  "  The small reduced matrices are identical on every rank.\n"
  "  The solves with J - R (gmg-pod) use the library's sparse LU of J - R,\n"
  "  REPLICATED on every rank: each rank factors the whole J - R once and the\n"
  "  right-hand sides are gathered to every rank. This is fine while that\n"
  "  factor fits in one rank's memory. For larger models use a distributed\n"
  "  direct solver behind the same solve callback: examples/petsc_mumps.c\n"
  "  (make build/petsc_mumps) does this reduction with PETSc and MUMPS.\n"
  "\n"
  "NOT SUPPORTED HERE (each is refused with a message naming it)\n"
  "  --simulate (give the snapshots with --X; make them with the serial\n"
  "  `phgmg simulate ... --states X.npy`), dense --J/--R/--Q/--E, a mass matrix\n"
  "  with sp1, sp2 or gmg-qm, a port on an algebraic equation, springs\n"
  "  (--poly-jdx), dampers with --E-coo or gmg-qm, feedthrough, --ref, gmg-qm's\n"
  "  --lambda auto, --rn wide and --manifold altmin, balancing, several --X\n"
  "  files, method or order lists, and every\n"
  "  other option of `phgmg reduce`: use the serial `phgmg` for them.\n"
  "\n"
  "EXIT STATUS\n"
  "  0 success, 1 an error in the inputs or the reduction, 2 a usage error;\n"
  "  every rank exits with the same status.\n", NULL};

typedef struct args {
  const char *J, *R, *Q, *B, *X, *out, *name;
  const char *potential, *poly, *expf, *poly_idx, *poly_w;   /* the separable nonlinear part */
  const char *E;                                             /* --E-coo: a mass matrix */
  const char *dampf;                                         /* --dampers: (k, 4) rows (i, j, c1, c3) */
  int method, r, quiet, have_dt, no_hyper, have_hyper, have_hyper_tol;
  int hyper_kind, deim_max, deim_neg, have_deim_opt;   /* --hyper (PHGMG_HYPER_*), the DEIM options */
  int manifold, rn, have_lambda, have_qm_opt, lambda_cv; /* gmg-qm: --manifold, --rn, --lambda (cv: 1) */
  double dt, hyper_tol, deim_tol, lambda;
} args;

/* This rank's block of rows, the sizes, and what was read. */
typedef struct dist {
  int rank, size, N, m, nloc, ns;
  long row0;
  double *TJ, *TR, *TQ, *TE;     /* triplets (column-major nnz x 3), whole (TE: --E-coo, else NULL) */
  long nJ, nR, nQ, nE;
  double *Bfull, *Bl, *Xl;       /* B (N x m), its rows (nloc x m), the snapshots' rows (nloc x ns) */
  int *cnt, *dsp;                /* rows per rank and their offsets */
  /* the separable terms this rank owns (those on its rows), with their
     serial term numbers; the family: poly_deg, nexp, shared or one per term */
  int nsep, poly_deg, nexp, per_term, nterms;
  phgmg_gidx *sidx, *sid;
  double *sw, *spoly, *sexpo;    /* sw NULL: weights 1 */
  double named[8];               /* --potential's coefficients (shared) */
  /* the dampers: all of them (whole file, for the solver's J - R - L) and this rank's */
  int nd_all, ndl;
  double *D;                     /* nd_all x 4 (column-major: i, j, c1, c3) */
  phgmg_gidx *dli, *dlj, *dlid;
  double *dlaw;                  /* ndl x 4: {0, c1, 0, c3} */
} dist;

/* The replicated solver of J - R. */
typedef struct solver {
  phgmg_ph_sparse *sp;
  phgmg_jr_factor *f;
  double rcond;
  double *full, *work;           /* N each */
  const dist *d;
  unsigned char *calg;           /* the solver of E: its zero columns (N; nalg of them), else NULL */
  int nalg;
  double rcond_c;                /* with algebraic lines: rcond of the condensed model's J - R */
} solver;

static int g_rank = 0;

/* An error message, printed by rank 0 only (every rank sees the same
   fault: the verdicts are agreed before anything is printed). */
static void say(const char *fmt, ...) {
  va_list ap;
  if (g_rank != 0) return;
  fputs("phgmg-mpi: error: ", stderr);
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
}

static int usage(const char *fmt, ...) {
  va_list ap;
  if (g_rank != 0) return 2;
  fputs("phgmg-mpi: ", stderr);
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputs("\n(run 'phgmg-mpi --help' for the options)\n", stderr);
  return 2;
}

/* 1 on every rank if any rank passes bad != 0. */
static int any_rank(int bad) {
  int all = 0;
  MPI_Allreduce(&bad, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return all;
}

/* The names of a method and of a hyper-reduction, as the serial command writes them. */
static const char *method_name(int method) {
  return method == PHGMG_METHOD_SP1 ? "sp1" : method == PHGMG_METHOD_SP2 ? "sp2"
         : method == PHGMG_METHOD_GMG_QM ? "gmg-qm" : "gmg-pod";
}
static const char *hyper_name(int kind) {
  return kind == PHGMG_HYPER_QDEIM ? "qdeim" : kind == PHGMG_HYPER_GREEDY ? "greedy" : "ecsw";
}

/* ---- arguments --------------------------------------------------------------- */

/* Options of the serial `phgmg reduce` that this program refuses, with the reason. */
static const char *refused_reason(const char *o) {
  if (!strcmp(o, "--simulate") || !strcmp(o, "--steps") || !strcmp(o, "--input") || !strcmp(o, "--amp") ||
      !strcmp(o, "--train-input") || !strcmp(o, "--newton-tol") || !strcmp(o, "--newton-iter"))
    return "the distributed build does not simulate: give the snapshots with --X (make them with the serial "
           "`phgmg simulate <model options> --out y.npy --states X.npy`)";
  if (!strcmp(o, "--J") || !strcmp(o, "--R") || !strcmp(o, "--Q") || !strcmp(o, "--E"))
    return "dense matrices are not read by the distributed build: give J, R, Q (and E) as triplets with "
           "--J-coo, --R-coo, --Q-coo (--E-coo)";
  if (!strcmp(o, "--poly-jdx"))
    return "springs (terms on the difference of two coordinates) are not distributed: phgmg-mpi takes terms on "
           "one coordinate each (--poly-idx); use the serial `phgmg reduce`";
  return "not supported by the distributed build (gmg-pod, gmg-qm, sp1 or sp2 of a linear model or one with "
         "separable terms, snapshots from --X); use the serial `phgmg reduce`";
}

/* A named potential (--potential NAME[:P1[:P2]]) as exp-polynomial
   coefficients into c (the polynomial c_0..c_deg, then the pairs (a_e,
   b_e)), as the serial command reads it: toda, cosh:A, morse:D:A,
   fpu:K3:K4. 0, or the usage status 2 after a message. */
static int named_potential(const char *spec, double *c, int *deg, int *nexp) {
  double p[2] = {1.0, 1.0};
  int n = 0, k;
  const char *colon = strchr(spec, ':');
  const size_t len = colon ? (size_t)(colon - spec) : strlen(spec);
  const char *what = "expected toda, cosh:A (A != 0), morse:D:A (D > 0, A != 0) or fpu:K3:K4 (K4 > 0)";
  while (colon) {   /* each field a whole finite number */
    char *end;
    if (n == 2) return usage("--potential '%s': too many fields; %s", spec, what);
    errno = 0;
    p[n] = strtod(colon + 1, &end);
    if (end == colon + 1 || (*end && *end != ':') || errno == ERANGE || !isfinite(p[n]))
      return usage("--potential '%s': field %d is %s; %s", spec, n + 1,
                   end == colon + 1 ? "empty or not a number" : "not a finite double", what);
    ++n;
    colon = *end == ':' ? end : NULL;
  }
  memset(c, 0, 8 * sizeof(double));
  if (len == 4 && !strncmp(spec, "toda", 4) && n == 0) {   /* e^s - 1 - s */
    c[0] = -1.0; c[1] = -1.0; *deg = 1; *nexp = 1; c[2] = 1.0; c[3] = 1.0;
  } else if (len == 4 && !strncmp(spec, "cosh", 4) && n <= 1 && p[0] != 0.0) {   /* (cosh(a s) - 1)/a^2 */
    c[0] = -1.0 / (p[0] * p[0]); *deg = 0; *nexp = 2;
    c[1] = 0.5 / (p[0] * p[0]); c[2] = p[0]; c[3] = 0.5 / (p[0] * p[0]); c[4] = -p[0];
  } else if (len == 5 && !strncmp(spec, "morse", 5) && n == 2 && p[0] > 0.0 && p[1] != 0.0) {   /* D (1 - e^{-a s})^2 */
    c[0] = p[0]; *deg = 0; *nexp = 2; c[1] = -2.0 * p[0]; c[2] = -p[1]; c[3] = p[0]; c[4] = -2.0 * p[1];
  } else if (len == 3 && !strncmp(spec, "fpu", 3) && n == 2 && p[1] > 0.0) {   /* k3 s^3/3 + k4 s^4/4 */
    c[3] = p[0] / 3.0; c[4] = p[1] / 4.0; *deg = 4; *nexp = 0;
  } else {
    return usage("--potential '%s': %s%s", spec, what,
                 (len == 5 && !strncmp(spec, "morse", 5) && n == 2 && p[0] <= 0.0) ||
                 (len == 3 && !strncmp(spec, "fpu", 3) && n == 2 && p[1] <= 0.0)
                     ? " (else the energy is unbounded below)" : "");
  }
  for (k = 0; k < 8; ++k)
    if (!isfinite(c[k]) || (c[k] != 0.0 && fabs(c[k]) < DBL_MIN))
      return usage("--potential '%s': its coefficients leave the double range (%g); use parameters of moderate "
                   "size", spec, c[k]);
  return 0;
}

/* gmg-qm's options: --manifold pod|greedy, --rn N, --lambda L (a fixed
   ridge parameter; 0 exactly zero). */
static int parse_qm_value(const char *o, const char *v, args *a) {
  char *end;
  a->have_qm_opt = 1;
  if (!strcmp(o, "--manifold")) {
    if (!strcmp(v, "pod")) a->manifold = PHGMG_MANIFOLD_POD;
    else if (!strcmp(v, "greedy")) a->manifold = PHGMG_MANIFOLD_GREEDY;
    else if (!strcmp(v, "altmin"))
      return usage("--manifold altmin: not distributed (phgmg-mpi fits the pod and greedy manifolds); use the "
                   "serial `phgmg reduce`");
    else return usage("--manifold '%s': expected pod or greedy", v);
  } else if (!strcmp(o, "--rn")) {
    long k;
    if (!strcmp(v, "wide"))
      return usage("--rn wide: not distributed (phgmg-mpi takes a fixed width 1 <= rn <= 4096); use the serial "
                   "`phgmg reduce`");
    errno = 0;
    k = strtol(v, &end, 10);
    if (errno || end == v || *end || k < 1 || k > 4096) return usage("--rn: expected an integer in [1, 4096], got '%s'", v);
    a->rn = (int)k;
  } else if (!strcmp(o, "--lambda")) {
    a->have_lambda = 1;
    if (!strcmp(v, "cv")) { a->lambda_cv = 1; return 0; }
    if (!strcmp(v, "auto"))
      return usage("--lambda auto: phgmg-mpi does not simulate, so it cannot validate lambda by simulating the "
                   "runs: give --lambda cv (chosen by held-out regression) or a fixed --lambda L (e.g. 1e-3; 0 "
                   "means exactly zero), or use the serial `phgmg reduce`");
    errno = 0;
    a->lambda = strtod(v, &end);
    if (errno || end == v || *end || !(a->lambda >= 0.0) || !isfinite(a->lambda))
      return usage("--lambda: expected a number >= 0, got '%s'", v);
    a->have_lambda = 1;
  }
  return 0;
}

static int parse_value(const char *o, const char *v, args *a) {
  char *end;
  if (!strcmp(o, "--r")) {
    long r;
    errno = 0;
    r = strtol(v, &end, 10);
    if (errno || end == v || *end || r < 1 || r > 100000)
      return usage("--r: expected an integer in [1, 100000], got '%s'%s", v,
                   strchr(v, ',') ? " (lists of orders are not supported by phgmg-mpi)" : "");
    a->r = (int)r;
  } else if (!strcmp(o, "--dt")) {
    errno = 0;
    a->dt = strtod(v, &end);
    if (errno || end == v || *end || !(a->dt > 0.0) || !isfinite(a->dt))
      return usage("--dt: expected a positive number, got '%s'", v);
    a->have_dt = 1;
  } else if (!strcmp(o, "--hyper")) {
    if (!strcmp(v, "ecsw")) a->hyper_kind = PHGMG_HYPER_ECSW;
    else if (!strcmp(v, "qdeim")) a->hyper_kind = PHGMG_HYPER_QDEIM;
    else if (!strcmp(v, "greedy")) a->hyper_kind = PHGMG_HYPER_GREEDY;
    else return usage("--hyper '%s': expected ecsw, qdeim or greedy", v);
    a->have_hyper = 1;
  } else if (!strcmp(o, "--deim-tol")) {
    errno = 0;
    a->deim_tol = strtod(v, &end);
    if (errno || end == v || *end || !(a->deim_tol >= 0.0 && a->deim_tol < 1.0))
      return usage("--deim-tol %s: expected 0 <= T < 1 (DEIM keeps the modes with sigma_k / sigma_1 > T)", v);
    a->have_deim_opt = 1;
  } else if (!strcmp(o, "--deim-max")) {
    long k;
    errno = 0;
    k = strtol(v, &end, 10);
    if (errno || end == v || *end || k < 1 || k > 100000000)
      return usage("--deim-max: expected an integer in [1, 100000000], got '%s'", v);
    a->deim_max = (int)k;
    a->have_deim_opt = 1;
  } else if (!strcmp(o, "--hyper-tol")) {
    errno = 0;
    a->hyper_tol = strtod(v, &end);
    if (errno || end == v || *end || !(a->hyper_tol > 0.0 && a->hyper_tol < 1.0))
      return usage("--hyper-tol %s: expected 0 < T < 1 (a relative residual)", v);
    if (a->hyper_tol < 1e-14)
      return usage("--hyper-tol %g: below what double precision resolves in a relative residual (1e-14); for "
                   "every term exactly, use --no-hyper", a->hyper_tol);
    a->have_hyper_tol = 1;
  } else if (!strcmp(o, "--potential")) {
    double c[8];
    int deg, ne;
    a->potential = v;
    return named_potential(v, c, &deg, &ne);
  } else if (!strcmp(o, "--method")) {
    if (!strcmp(v, "gmg-pod")) a->method = PHGMG_METHOD_GMG_POD;
    else if (!strcmp(v, "gmg-qm")) a->method = PHGMG_METHOD_GMG_QM;
    else if (!strcmp(v, "sp1")) a->method = PHGMG_METHOD_SP1;
    else if (!strcmp(v, "sp2")) a->method = PHGMG_METHOD_SP2;
    else
      return usage("--method %s: phgmg-mpi reduces with gmg-pod, gmg-qm, sp1 or sp2 only%s", v,
                   strchr(v, ',') ? " (no lists of methods)" : "; use the serial `phgmg reduce` for the others");
  } else {
    return parse_qm_value(o, v, a);
  }
  return 0;
}

/* 1 if NAME is a C identifier of at most 64 characters (NAME.c exports it). */
static int name_ok(const char *s) {
  size_t i, n = strlen(s);
  if (n < 1 || n > 64 || !(s[0] == '_' || (s[0] >= 'A' && s[0] <= 'Z') || (s[0] >= 'a' && s[0] <= 'z'))) return 0;
  for (i = 1; i < n; ++i)
    if (!(s[i] == '_' || (s[i] >= 'A' && s[i] <= 'Z') || (s[i] >= 'a' && s[i] <= 'z') || (s[i] >= '0' && s[i] <= '9')))
      return 0;
  return 1;
}

/* argv[2..]: the options of reduce. 0 ok, 2 a usage error (the same on every rank: the same argv). */
#define NVOPT 25   /* options with a value; the first NSOPT are file or name strings */
#define NSOPT 13
static int parse_args(int argc, char **argv, args *a) {
  static const char *const with_value[NVOPT] = {"--J-coo", "--R-coo", "--Q-coo", "--B", "--X", "--out", "--name",
                                                "--poly", "--exp", "--poly-idx", "--poly-w", "--E-coo", "--dampers",
                                                "--method", "--r",
                                                "--dt", "--potential", "--hyper", "--hyper-tol", "--deim-tol",
                                                "--deim-max", "--manifold", "--rn", "--lambda", ""};
  const char **slot[NSOPT];
  int seen[NVOPT], i, k, rc;
  memset(a, 0, sizeof *a);
  memset(seen, 0, sizeof seen);
  a->name = "rom"; a->method = -1;
  slot[0] = &a->J; slot[1] = &a->R; slot[2] = &a->Q; slot[3] = &a->B; slot[4] = &a->X; slot[5] = &a->out;
  slot[6] = &a->name; slot[7] = &a->poly; slot[8] = &a->expf; slot[9] = &a->poly_idx; slot[10] = &a->poly_w;
  slot[11] = &a->E; slot[12] = &a->dampf;
  for (i = 2; i < argc; ++i) {
    const char *o = argv[i];
    if (!strcmp(o, "--quiet")) { a->quiet = 1; continue; }
    if (!strcmp(o, "--no-hyper") || !strcmp(o, "--no-deim")) { a->no_hyper = 1; continue; }
    if (!strcmp(o, "--deim-allow-negative")) { a->deim_neg = a->have_deim_opt = 1; continue; }
    for (k = 0; k < NVOPT - 1 && strcmp(o, with_value[k]); ++k) {}
    if (k == NVOPT - 1) return usage("%s: %s", o, o[0] == '-' ? refused_reason(o) : "unexpected argument");
    if (i + 1 >= argc) return usage("%s needs a value", o);
    if (seen[k]++)
      return usage("%s given twice%s", o, k == 4 ? " (several --X files are not supported by phgmg-mpi)" : "");
    if (k < NSOPT) {
      *slot[k] = argv[++i];
    } else if ((rc = parse_value(o, argv[++i], a)) != 0) {
      return rc;
    }
  }
  if (a->potential && (a->poly || a->expf)) return usage("--potential replaces --poly and --exp");
  if (!!(a->poly || a->expf || a->potential) != !!a->poly_idx)
    return usage("--poly/--exp/--potential and --poly-idx go together");
  if (a->poly_w && !a->poly_idx) return usage("--poly-w needs a nonlinear part (--poly-idx)");
  if ((a->have_hyper || a->have_hyper_tol || a->no_hyper || a->have_deim_opt) && !a->poly_idx)
    return usage("%s applies to a nonlinear part (--poly, --exp or --potential with --poly-idx); this model has "
                 "none", a->have_hyper ? "--hyper" : a->have_hyper_tol ? "--hyper-tol" : a->no_hyper ? "--no-hyper"
                 : "--deim-tol/--deim-max/--deim-allow-negative");
  if (a->no_hyper && (a->have_hyper || a->have_hyper_tol || a->have_deim_opt))
    return usage("--no-hyper keeps every nonlinear term: %s does not apply",
                 a->have_hyper ? "--hyper" : a->have_hyper_tol ? "--hyper-tol" : "the DEIM options");
  if (a->have_hyper_tol && a->hyper_kind != PHGMG_HYPER_ECSW)
    return usage("--hyper-tol applies to --hyper ecsw (DEIM's tolerance is --deim-tol)");
  if (a->have_deim_opt && a->hyper_kind == PHGMG_HYPER_ECSW)
    return usage("--deim-tol, --deim-max and --deim-allow-negative apply to --hyper qdeim or greedy (ecsw's "
                 "tolerance is --hyper-tol)");
  if (!a->J || !a->R || !a->Q) return usage("--J-coo, --R-coo and --Q-coo are required");
  if (!a->B) return usage("--B is required");
  if (!a->X) return usage("--X is required (the snapshots; phgmg-mpi does not simulate)");
  if (a->method < 0) return usage("--method is required (gmg-pod, gmg-qm, sp1 or sp2)");
  if (a->have_qm_opt && a->method != PHGMG_METHOD_GMG_QM)
    return usage("--lambda, --rn and --manifold apply to --method gmg-qm only (not %s)", method_name(a->method));
  if (a->method == PHGMG_METHOD_GMG_QM && !a->have_lambda)
    return usage("gmg-qm needs --lambda here: cv (chosen by held-out regression) or a fixed value (e.g. 1e-3; 0 "
                 "means exactly zero); the serial default, --lambda auto, validates lambda by simulating the runs, "
                 "which phgmg-mpi does not do");
  if (a->dampf && (a->E || a->method == PHGMG_METHOD_GMG_QM))
    return usage("--dampers: phgmg-mpi reduces models with dampers by gmg-pod, sp1 or sp2 without a mass matrix "
                 "(for %s use the serial `phgmg reduce`)", a->E ? "--E-coo" : "gmg-qm");
  if (a->E && a->method != PHGMG_METHOD_GMG_POD)
    return usage("--E-coo: phgmg-mpi reduces models with a mass matrix by gmg-pod (for %s use the serial `phgmg "
                 "reduce`)", method_name(a->method));
  if (a->r < 1) return usage("--r is required");
  if (!a->out) return usage("--out is required");
  if (!name_ok(a->name)) return usage("--name %s: expected a C identifier of at most 64 characters", a->name);
  return 0;
}

/* ---- inputs -------------------------------------------------------------------- */

/* 1 if both paths name one existing file (however spelled or linked). */
static int same_file(const char *p, const char *q) {
  struct stat a, b;
  return stat(p, &a) == 0 && stat(q, &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

/* The message of a failed .npy read: for an I/O error the system's reason. */
static void npy_fail(const char *opt, const char *path, phgmg_result rc) {
  FILE *f = NULL;
  if (rc == PHGMG_ERR_IO && !(f = fopen(path, "rb"))) say("%s %s: cannot read: %s", opt, path, strerror(errno));
  else say("%s %s: %s", opt, path, phgmg_result_string(rc));
  if (rc == PHGMG_ERR_IO && f) fclose(f);
}

/* B whole (N x m; N and m from its shape), then the layout: contiguous
   blocks of N / P rows in rank order (the first N mod P ranks one more). */
static int read_B_layout(const args *a, dist *d) {
  int rows = 0, cols = 0, nd = 0, p;
  phgmg_result rc = phgmg_npy_read(a->B, &d->Bfull, &rows, &cols, &nd, NULL);
  if (rc != PHGMG_OK) { npy_fail("--B", a->B, rc); return 1; }
  if (nd == 2 && rows == 1 && cols > 1) { rows = cols; cols = 1; }   /* a (1, N) row: one port */
  if (rows < 1 || cols < 1 || cols > rows) { say("--B %s: expected (N,) or (N, m) with 1 <= m <= N", a->B); return 1; }
  d->N = rows; d->m = cols;
  d->cnt = (int *)malloc(sizeof(int) * 2 * (size_t)d->size);
  if (!d->cnt) { say("out of memory"); return 1; }
  d->dsp = d->cnt + d->size;
  for (p = 0; p < d->size; ++p) {
    d->cnt[p] = d->N / d->size + (p < d->N % d->size);
    d->dsp[p] = p == 0 ? 0 : d->dsp[p - 1] + d->cnt[p - 1];
  }
  d->nloc = d->cnt[d->rank]; d->row0 = d->dsp[d->rank];
  return 0;
}

/* This rank's rows of B (nloc x m). */
static int own_B(dist *d) {
  int i, j;
  d->Bl = (double *)malloc(sizeof(double) * ((size_t)d->nloc * d->m + 1));
  if (!d->Bl) { say("out of memory"); return 1; }
  for (j = 0; j < d->m; ++j)
    for (i = 0; i < d->nloc; ++i) d->Bl[i + (size_t)j * d->nloc] = d->Bfull[d->row0 + i + (size_t)j * d->N];
  return 0;
}

/* The triplets of a (nnz, 3) .npy file (column-major: rows, cols, values),
   checked: integer indices in [0, N), finite values. */
static int read_triplets(const char *opt, const char *path, int N, double **T, long *nnz) {
  int rows = 0, cols = 0;
  long k;
  const size_t n = strlen(path);
  phgmg_result rc;
  if (strchr(path, ',') || (n > 4 && (!strcmp(path + n - 4, ".npz") || !strcmp(path + n - 4, ".mtx")))) {
    say("%s %s: phgmg-mpi reads one (nnz, 3) .npy file of (row, col, value) triplets per matrix (not three "
        "files, .npz or .mtx: the serial `phgmg reduce` reads those)", opt, path);
    return 1;
  }
  rc = phgmg_npy_read(path, T, &rows, &cols, NULL, NULL);
  if (rc != PHGMG_OK) { npy_fail(opt, path, rc); return 1; }
  if (cols != 3) {
    say("%s %s: expected an (nnz, 3) array of (row, col, value) triplets, got %d columns (phgmg-mpi reads "
        "one .npy file per matrix)", opt, path, cols);
    return 1;
  }
  for (k = 0; k < 2 * (long)rows; ++k) {
    const double v = (*T)[k];
    if (!(v >= 0.0 && v < (double)N && v == floor(v))) {
      say("%s %s: index %g (triplet %ld) is not an integer in [0, %d) (N = %d from --B)", opt, path, v,
          k % rows, N, N);
      return 1;
    }
  }
  for (k = 2 * (long)rows; k < 3 * (long)rows; ++k)
    if (!isfinite((*T)[k])) { say("%s %s: a value is NaN or infinite (triplet %ld)", opt, path, k - 2 * (long)rows); return 1; }
  *nnz = rows;
  return 0;
}

/* This rank's rows of the (N, ns) snapshots, read a batch of columns at a
   time (about 8 MB per batch): the N x ns matrix never exists on a rank. */
static int read_X_rows(const args *a, dist *d) {
  int rows = 0, cols = 0, j0, nb, i, j;
  double *buf;
  phgmg_result rc = phgmg_npy_read_cols(a->X, 0, 0, NULL, 0, &rows, &cols);
  if (rc != PHGMG_OK) { npy_fail("--X", a->X, rc); return 1; }
  if (rows != d->N || cols < 2) {
    say("--X %s: expected (%d, ns) snapshots with ns >= 2 (N from --B), got (%d, %d)", a->X, d->N, rows, cols);
    return 1;
  }
  nb = cols < 1048576 / d->N ? cols : 1048576 / d->N;
  if (nb < 1) nb = 1;
  buf = (double *)malloc(sizeof(double) * (size_t)rows * (size_t)nb);
  d->Xl = (double *)malloc(sizeof(double) * ((size_t)d->nloc * (size_t)cols + 1));
  if (!buf || !d->Xl) { free(buf); say("out of memory"); return 1; }
  for (j0 = 0; j0 < cols; j0 += nb) {
    const int k = nb < cols - j0 ? nb : cols - j0;
    rc = phgmg_npy_read_cols(a->X, j0, k, buf, rows, NULL, NULL);
    if (rc != PHGMG_OK) { npy_fail("--X", a->X, rc); free(buf); return 1; }
    for (j = 0; j < k; ++j)
      for (i = 0; i < d->nloc; ++i) {
        const double v = buf[d->row0 + i + (size_t)j * rows];
        if (!isfinite(v)) { say("--X %s: a snapshot entry is NaN or infinite", a->X); free(buf); return 1; }
        d->Xl[i + (size_t)(j0 + j) * d->nloc] = v;
      }
  }
  free(buf);
  d->ns = cols;
  return 0;
}

/* A vector or matrix of finite numbers (an .npy file, column-major), or 1 after a message. */
static int read_array(const char *opt, const char *path, double **v, int *rows, int *cols, int *vec) {
  int nd = 0;
  long k;
  phgmg_result rc = phgmg_npy_read(path, v, rows, cols, &nd, NULL);
  if (rc != PHGMG_OK) { npy_fail(opt, path, rc); return 1; }
  for (k = 0; k < (long)*rows * *cols; ++k)
    if (!isfinite((*v)[k])) { say("%s %s: entry %ld is NaN or infinite", opt, path, k); return 1; }
  *vec = nd <= 1 || *rows == 1 || *cols == 1;
  return 0;
}

/* Is w phi(s), phi(s) = sum_j c_j s^j + sum_e a_e exp(b_e s), bounded below
   as s -> dir * inf (dir = +1 or -1)? The fastest-growing exponential
   decides when there is one, else the leading power of degree >= 3 (the
   serial command's test). 1 bounded, 0 not. */
static int phi_bounded(const double *c, int deg, const double *ex, int ne, double w, double dir) {
  double bmax = 0.0, amax = 0.0;
  int e, f, j;
  for (e = 0; e < ne; ++e) {   /* the largest rate dir * b > 0 with a nonzero net coefficient */
    double s = 0.0;
    const double rate = dir * ex[2 * e + 1];
    if (!(rate > bmax)) continue;
    for (f = 0; f < ne; ++f)
      if (ex[2 * f + 1] == ex[2 * e + 1]) s += ex[2 * f];
    if (s != 0.0) { bmax = rate; amax = s; }
  }
  if (bmax > 0.0) return w * amax > 0.0;
  for (j = deg; j >= 3; --j)
    if (c[j] != 0.0) return w * c[j] * ((j % 2 && dir < 0.0) ? -1.0 : 1.0) > 0.0;
  return 1;
}

/* The separable nonlinear part, as the serial command reads it: --poly-idx
   (the terms' coordinates), --poly-w (weights), the family from --potential
   or --poly (a vector: shared; (terms, d+1): one per term) and --exp
   ((n_exp, 2): shared; (terms, 2 n_exp): one per term). Every rank reads
   the whole (small) files and checks every term (the same verdict and
   message everywhere), then keeps the terms on its own rows with their
   serial term numbers. 0, or 1 after a message. */
static int read_terms(const args *a, dist *d) {
  double *idx = NULL, *w = NULL, *P = NULL, *E = NULL, *fp = NULL, *fe = NULL;
  int nt, rows, cols, vec, prow = 0, pcol = 0, erow = 0, ecol = 0, per_p = 0, per_e = 0, deg = 0, ne = 0, t, j, k;
  int bad = 1, own = 0;
  if (!a->poly_idx) return 0;
  if (read_array("--poly-idx", a->poly_idx, &idx, &rows, &cols, &vec)) goto done;
  nt = rows * cols;
  if (!vec || nt < 1) { say("--poly-idx %s: expected a non-empty vector of coordinates, got (%d, %d)", a->poly_idx, rows, cols); goto done; }
  for (k = 0; k < nt; ++k)
    if (!(idx[k] >= 0.0 && idx[k] < (double)d->N && idx[k] == floor(idx[k]))) {
      say("--poly-idx %s: entry %d is %g; expected an integer coordinate in [0, %d)", a->poly_idx, k, idx[k], d->N);
      goto done;
    }
  if (a->poly_w) {
    if (read_array("--poly-w", a->poly_w, &w, &rows, &cols, &vec)) goto done;
    if (!vec || rows * cols != nt) {
      say("--poly-w %s: expected a vector of %d weights (one per entry of %s), got (%d, %d)", a->poly_w, nt,
          a->poly_idx, rows, cols);
      goto done;
    }
  }
  if (a->potential) {
    named_potential(a->potential, d->named, &deg, &ne);   /* checked by parse_args */
    fp = d->named; fe = d->named + deg + 1;
  } else {
    if (a->poly) {
      if (read_array("--poly", a->poly, &P, &prow, &pcol, &vec)) goto done;
      per_p = !vec;
      if (per_p && prow != nt) {
        say("--poly %s: expected a vector of d+1 coefficients or a (%d, d+1) matrix, got (%d, %d)", a->poly, nt, prow, pcol);
        goto done;
      }
      deg = (per_p ? pcol : prow * pcol) - 1;
      if (deg < 0 || deg > 32) { say("--poly %s: degree %d; expected 0..32", a->poly, deg); goto done; }
    }
    if (a->expf) {
      if (read_array("--exp", a->expf, &E, &erow, &ecol, &vec)) goto done;
      /* (terms, 2 n_exp) is per term; a (terms, 2) matrix with up to 8 terms is per term only beside a per-term --poly */
      per_e = erow == nt && ecol % 2 == 0 && (ecol != 2 || nt > 8 || per_p);
      ne = per_e ? ecol / 2 : erow;
      if ((!per_e && ecol != 2) || ne < 1 || ne > 8) {
        say("--exp %s: expected (n_exp, 2) pairs (a, b) or a (%d, 2 n_exp) matrix, 1 <= n_exp <= 8, got (%d, %d)",
            a->expf, nt, erow, ecol);
        goto done;
      }
    }
    if (deg < 1 && ne == 0) { say("--poly: a nonlinear part needs degree >= 1 or --exp"); goto done; }
    t = per_p || per_e ? nt : 1;   /* the functions, row-major (the files are column-major) */
    fp = (double *)calloc((size_t)t * (size_t)(deg + 1), sizeof(double));
    fe = (double *)calloc((size_t)t * 2 * (size_t)(ne ? ne : 1), sizeof(double));
    if (!fp || !fe) { say("out of memory"); goto done; }
    for (k = 0; k < t; ++k) {
      for (j = 0; P && j <= deg; ++j) fp[(size_t)k * (deg + 1) + j] = per_p ? P[k + (size_t)j * prow] : P[j];
      for (j = 0; j < ne; ++j) {
        fe[(size_t)k * 2 * ne + 2 * j] = per_e ? E[k + (size_t)(2 * j) * erow] : E[j];
        fe[(size_t)k * 2 * ne + 2 * j + 1] = per_e ? E[k + (size_t)(2 * j + 1) * erow] : E[j + erow];
      }
    }
  }
  d->per_term = per_p || per_e; d->poly_deg = deg; d->nexp = ne; d->nterms = nt;
  for (k = 0; k < nt; ++k) {   /* every term bounded below, as the serial command checks */
    const double wk = w ? w[k] : 1.0, *c = fp + (size_t)(d->per_term ? k : 0) * (deg + 1);
    const double *ex = fe + (size_t)(d->per_term ? k : 0) * 2 * ne;
    int dir;
    if (wk == 0.0) continue;
    for (dir = -1; dir <= 1; dir += 2)
      if (!phi_bounded(c, deg, ex, ne, wk, (double)dir)) {
        say("%s: term %d (weight %g): w phi(s) -> -inf as s -> %cinf, so the energy H is unbounded below and the "
            "model is not a passive port-Hamiltonian system (check the sign of the leading coefficient%s)",
            a->potential ? a->potential : a->poly ? a->poly : a->expf, k, wk, dir > 0 ? '+' : '-',
            a->poly_w ? " and of the weights in --poly-w" : "");
        goto done;
      }
  }
  for (k = 0; k < nt; ++k) own += idx[k] >= (double)d->row0 && idx[k] < (double)(d->row0 + d->nloc);
  d->sidx = (phgmg_gidx *)malloc(sizeof(phgmg_gidx) * 2 * ((size_t)own + 1));
  d->sw = w ? (double *)malloc(sizeof(double) * ((size_t)own + 1)) : NULL;
  d->spoly = (double *)malloc(sizeof(double) * ((size_t)(d->per_term ? own : 1) * (deg + 1) + 1));
  d->sexpo = (double *)malloc(sizeof(double) * ((size_t)(d->per_term ? own : 1) * 2 * ne + 1));
  if (!d->sidx || (w && !d->sw) || !d->spoly || !d->sexpo) { say("out of memory"); goto done; }
  d->sid = d->sidx + own + 1;
  if (!d->per_term) {
    memcpy(d->spoly, fp, sizeof(double) * (size_t)(deg + 1));
    memcpy(d->sexpo, fe, sizeof(double) * 2 * (size_t)ne);
  }
  for (k = 0; k < nt; ++k) {   /* this rank's terms, ascending serial term numbers */
    const int s = d->nsep;
    if (!(idx[k] >= (double)d->row0 && idx[k] < (double)(d->row0 + d->nloc))) continue;
    d->sidx[s] = (phgmg_gidx)idx[k]; d->sid[s] = k;
    if (w) d->sw[s] = w[k];
    if (d->per_term) {
      memcpy(d->spoly + (size_t)s * (deg + 1), fp + (size_t)k * (deg + 1), sizeof(double) * (size_t)(deg + 1));
      memcpy(d->sexpo + (size_t)s * 2 * ne, fe + (size_t)k * 2 * ne, sizeof(double) * 2 * (size_t)ne);
    }
    ++d->nsep;
  }
  bad = 0;
done:
  phgmg_npy_free(idx, NULL); phgmg_npy_free(w, NULL); phgmg_npy_free(P, NULL); phgmg_npy_free(E, NULL);
  if (fp != d->named) { free(fp); free(fe); }
  return bad;
}

/* --dampers FILE, as the serial command reads it: a (k, 4) array (or 4
   values for one damper) of rows (i, j, c1, c3), a damper on s = z_i - z_j
   (j = -1: z_i) with the force c1 s + c3 s^3, c1, c3 >= 0. Every rank reads
   the whole (small) file and checks every row, keeps all of it (the solver
   of J - R - L needs every damper's c1) and its own dampers (i on its rows)
   with their row numbers as global ids. 0, or 1 after a message. */
static int read_dampers(const args *a, dist *d) {
  int rows, cols, vec, k, n;
  if (!a->dampf) return 0;
  if (read_array("--dampers", a->dampf, &d->D, &rows, &cols, &vec)) return 1;
  n = rows * cols == 4 ? 1 : rows;
  if (rows * cols != 4 * n || (n > 1 && cols != 4) || n < 1) {
    say("--dampers %s: expected shape (k, 4), rows (i, j, c1, c3), got (%d, %d)", a->dampf, rows, cols);
    return 1;
  }
  d->nd_all = n;
  for (k = 0; k < n; ++k) {
    const double vi = d->D[k], vj = d->D[k + n], c1 = d->D[k + 2 * n], c3 = d->D[k + 3 * n];
    if (!(vi >= 0.0 && vi < d->N && vi == floor(vi)) || !(vj >= -1.0 && vj < d->N && vj == floor(vj)) || vi == vj) {
      say("--dampers %s: row %d: i = %g, j = %g; expected integer states in [0, %d), j = -1 for one state, i != j",
          a->dampf, k, vi, vj, d->N);
      return 1;
    }
    if (!(c1 >= 0.0 && c3 >= 0.0)) {
      say("--dampers %s: row %d: c1 = %g, c3 = %g: the damper generates energy (c1, c3 >= 0 needed)", a->dampf, k, c1,
          c3);
      return 1;
    }
    d->ndl += vi >= (double)d->row0 && vi < (double)(d->row0 + d->nloc);
  }
  d->dli = (phgmg_gidx *)malloc(sizeof(phgmg_gidx) * 3 * ((size_t)d->ndl + 1));
  d->dlaw = (double *)malloc(sizeof(double) * 4 * ((size_t)d->ndl + 1));
  if (!d->dli || !d->dlaw) { say("out of memory"); return 1; }
  d->dlj = d->dli + d->ndl + 1; d->dlid = d->dlj + d->ndl + 1;
  for (k = 0, d->ndl = 0; k < n; ++k) {   /* this rank's, ascending row numbers */
    const double vi = d->D[k];
    if (!(vi >= (double)d->row0 && vi < (double)(d->row0 + d->nloc))) continue;
    d->dli[d->ndl] = (phgmg_gidx)vi; d->dlj[d->ndl] = (phgmg_gidx)d->D[k + n]; d->dlid[d->ndl] = k;
    d->dlaw[4 * d->ndl] = 0.0; d->dlaw[4 * d->ndl + 1] = d->D[k + 2 * n];
    d->dlaw[4 * d->ndl + 2] = 0.0; d->dlaw[4 * d->ndl + 3] = d->D[k + 3 * n];
    ++d->ndl;
  }
  return 0;
}

/* The inputs, each step agreed over the ranks (a fault on one rank stops all). */
static int read_inputs(const args *a, dist *d) {
  if (any_rank(read_B_layout(a, d))) return 1;
  if (any_rank(own_B(d))) return 1;
  if (any_rank(read_triplets("--J-coo", a->J, d->N, &d->TJ, &d->nJ))) return 1;
  if (any_rank(read_triplets("--R-coo", a->R, d->N, &d->TR, &d->nR))) return 1;
  if (any_rank(read_triplets("--Q-coo", a->Q, d->N, &d->TQ, &d->nQ))) return 1;
  if (a->E && any_rank(read_triplets("--E-coo", a->E, d->N, &d->TE, &d->nE))) return 1;
  if (any_rank(read_terms(a, d))) return 1;
  if (any_rank(read_dampers(a, d))) return 1;
  return any_rank(read_X_rows(a, d));
}

static void dist_free(dist *d) {
  phgmg_npy_free(d->TJ, NULL); phgmg_npy_free(d->TR, NULL); phgmg_npy_free(d->TQ, NULL);
  phgmg_npy_free(d->TE, NULL);
  phgmg_npy_free(d->Bfull, NULL);
  free(d->Bl); free(d->Xl); free(d->cnt);
  free(d->sidx); free(d->sw); free(d->spoly); free(d->sexpo);
  phgmg_npy_free(d->D, NULL); free(d->dli); free(d->dlaw);
}

/* ---- the operators ------------------------------------------------------------ */

/* This rank's rows of sJ J + sR R (sJ or sR 0: left out) as CSR with global
   columns (duplicates kept: the products sum them). */
static int own_csr(const dist *d, const double *T1, long n1, double s1, const double *T2, long n2, double s2,
                   phgmg_gidx **rp, phgmg_gidx **col, double **val) {
  const double *T[2];
  long n[2], k;
  double s[2];
  phgmg_gidx *pos;
  int t, i;
  T[0] = T1; T[1] = T2; n[0] = s1 != 0.0 ? n1 : 0; n[1] = s2 != 0.0 ? n2 : 0; s[0] = s1; s[1] = s2;
  *rp = (phgmg_gidx *)calloc((size_t)d->nloc + 1, sizeof(phgmg_gidx));
  pos = (phgmg_gidx *)calloc((size_t)d->nloc + 1, sizeof(phgmg_gidx));
  if (!*rp || !pos) { free(pos); return 1; }
  for (t = 0; t < 2; ++t)
    for (k = 0; k < n[t]; ++k) {
      const long r = (long)T[t][k] - d->row0;
      if (r >= 0 && r < d->nloc) ++(*rp)[r + 1];
    }
  for (i = 0; i < d->nloc; ++i) (*rp)[i + 1] += (*rp)[i];
  *col = (phgmg_gidx *)malloc(sizeof(phgmg_gidx) * (size_t)((*rp)[d->nloc] + 1));
  *val = (double *)malloc(sizeof(double) * (size_t)((*rp)[d->nloc] + 1));
  if (!*col || !*val) { free(pos); return 1; }
  for (i = 0; i < d->nloc; ++i) pos[i] = (*rp)[i];
  for (t = 0; t < 2; ++t)
    for (k = 0; k < n[t]; ++k) {
      const long r = (long)T[t][k] - d->row0;
      if (r < 0 || r >= d->nloc) continue;
      (*col)[pos[r]] = (phgmg_gidx)T[t][n[t] + k];
      (*val)[pos[r]++] = s[t] * T[t][2 * n[t] + k];
    }
  free(pos);
  return 0;
}

/* A distributed operator from this rank's rows of s1 T1 + s2 T2. Collective. */
static phgmg_result make_op(const phgmg_mpi_ctx *ctx, const dist *d, const double *T1, long n1, double s1,
                            const double *T2, long n2, double s2, phgmg_mpi_op **op) {
  phgmg_gidx *rp = NULL, *col = NULL;
  double *val = NULL;
  phgmg_result rc = any_rank(own_csr(d, T1, n1, s1, T2, n2, s2, &rp, &col, &val)) ? PHGMG_ERR_NOMEM : PHGMG_OK;
  if (rc == PHGMG_OK) rc = phgmg_mpi_op_create(op, ctx, rp, col, val);
  free(rp); free(col); free(val);
  return rc;
}

/* A CSC matrix (N x N) from triplets (indices checked by read_triplets). */
static phgmg_result triplets_csc(int N, const double *T, long nnz, phgmg_csc *out) {
  int *ri = (int *)malloc(sizeof(int) * (size_t)(2 * nnz + 1)), *ci = ri + nnz;
  long k;
  phgmg_result rc;
  if (!ri) return PHGMG_ERR_NOMEM;
  for (k = 0; k < nnz; ++k) { ri[k] = (int)T[k]; ci[k] = (int)T[nnz + k]; }
  rc = phgmg_csc_from_coo(out, N, N, nnz, ri, ci, T + 2 * nnz, NULL);
  free(ri);
  return rc;
}

/* R + L as triplets (*T, *n; allocated), L = sum_k c1_k c_k c_k^T the
   dampers' linearisation at rest (c_k = e_i - e_j, or e_i). */
static phgmg_result r_plus_l(const dist *d, double **T, long *n) {
  const long nd = d->nd_all, nn = d->nR + 4 * nd;
  long k, q = d->nR;
  *n = nn;
  *T = (double *)malloc(sizeof(double) * 3 * (size_t)(nn + 1));
  if (!*T) return PHGMG_ERR_NOMEM;
  for (k = 0; k < d->nR; ++k) {
    (*T)[k] = d->TR[k]; (*T)[nn + k] = d->TR[d->nR + k]; (*T)[2 * nn + k] = d->TR[2 * d->nR + k];
  }
  for (k = 0; k < nd; ++k) {
    const double i = d->D[k], j = d->D[k + nd], c1 = d->D[k + 2 * nd];
    const double ti[4] = {i, j, i, j}, tj[4] = {i, j, j, i}, tv[4] = {c1, c1, -c1, -c1};
    int e;
    for (e = 0; e < (j >= 0.0 ? 4 : 1); ++e, ++q) { (*T)[q] = ti[e]; (*T)[nn + q] = tj[e]; (*T)[2 * nn + q] = tv[e]; }
  }
  for (; q < nn; ++q) { (*T)[q] = 0.0; (*T)[nn + q] = 0.0; (*T)[2 * nn + q] = 0.0; }   /* one-sided: unused slots */
  return PHGMG_OK;
}

/* The replicated solver: J - R (with Q = I, which the solve with J - R does
   not see) as a sparse model, checked as the serial command checks J, R
   and B, factored once by the library's sparse LU (band LU fall-back;
   manual 8.12); with dampers the factor is of J - R - L (the library's
   solve for a model with dampers). Every rank does the same. */
static phgmg_result solver_create(const dist *d, solver *s) {
  phgmg_csc J, R, I;
  phgmg_result rc;
  double one = 1.0, *TL = NULL;
  long nL = 0;
  int *idx = (int *)malloc(sizeof(int) * (size_t)d->N), i;
  double *ones = (double *)malloc(sizeof(double) * (size_t)d->N);
  memset(s, 0, sizeof *s);
  memset(&J, 0, sizeof J); memset(&R, 0, sizeof R); memset(&I, 0, sizeof I);
  s->d = d;
  s->full = (double *)malloc(sizeof(double) * 2 * (size_t)d->N);
  if (!idx || !ones || !s->full) { free(idx); free(ones); return PHGMG_ERR_NOMEM; }
  s->work = s->full + d->N;
  for (i = 0; i < d->N; ++i) { idx[i] = i; ones[i] = one; }
  rc = triplets_csc(d->N, d->TJ, d->nJ, &J);
  if (rc == PHGMG_OK) rc = triplets_csc(d->N, d->TR, d->nR, &R);
  if (rc == PHGMG_OK) rc = phgmg_csc_from_coo(&I, d->N, d->N, d->N, idx, idx, ones, NULL);
  if (rc == PHGMG_OK) rc = phgmg_ph_sparse_create(&s->sp, d->N, d->m, &J, &R, &I, d->Bfull, NULL, NULL, NULL);
  /* the serial checks of J, R, B and J - R (relative tolerance 1e-12); Q here is I, so Q's are not made */
  if (rc == PHGMG_OK) rc = phgmg_ph_validate(phgmg_ph_sparse_system(s->sp), 1e-12, NULL, NULL);
  if (rc == PHGMG_OK && d->nd_all) {   /* dampers: the model again with R + L, for the factor */
    phgmg_ph_sparse_destroy(s->sp);
    s->sp = NULL;
    phgmg_csc_free(&R, NULL);
    memset(&R, 0, sizeof R);
    rc = r_plus_l(d, &TL, &nL);
    if (rc == PHGMG_OK) rc = triplets_csc(d->N, TL, nL, &R);
    if (rc == PHGMG_OK) rc = phgmg_ph_sparse_create(&s->sp, d->N, d->m, &J, &R, &I, d->Bfull, NULL, NULL, NULL);
    if (rc == PHGMG_ERR_NOT_PSD || rc == PHGMG_ERR_NOT_SYMMETRIC) rc = PHGMG_ERR_DAMPER;
  }
  if (rc == PHGMG_OK) rc = phgmg_jr_factor_create(&s->f, phgmg_ph_sparse_system(s->sp), &s->rcond, NULL);
  phgmg_csc_free(&J, NULL); phgmg_csc_free(&R, NULL); phgmg_csc_free(&I, NULL);
  free(idx); free(ones); free(TL);
  return rc;
}

/* E's algebraic lines from its triplets: *k zero rows (the algebraic
   equations) and as many zero columns (the algebraic variables, marked in
   calg, N entries); PHGMG_ERR_E_SINGULAR if the counts differ,
   PHGMG_ERR_UNSUPPORTED for a port on a zero row (its condensation is a
   feedthrough). */
static phgmg_result e_lines(const dist *d, unsigned char *calg, int *k) {
  unsigned char *rnz = (unsigned char *)calloc((size_t)d->N + 1, 1);
  int i, kc = 0, port = 0;
  long q;
  if (!rnz) return PHGMG_ERR_NOMEM;
  memset(calg, 1, (size_t)d->N);
  for (q = 0; q < d->nE; ++q)
    if (d->TE[2 * d->nE + q] != 0.0) { rnz[(int)d->TE[q]] = 1; calg[(int)d->TE[d->nE + q]] = 0; }
  *k = 0;
  for (i = 0; i < d->N; ++i) {
    int j;
    *k += !rnz[i]; kc += calg[i];
    for (j = 0; !rnz[i] && j < d->m; ++j) port += d->Bfull[i + (size_t)j * d->N] != 0.0;
  }
  free(rnz);
  return *k != kc ? PHGMG_ERR_E_SINGULAR : port ? PHGMG_ERR_UNSUPPORTED : PHGMG_OK;   /* a port on a constraint */
}

/* An index-one E: the serial checks of the whole model (J, R, Q, E, B:
   phgmg_ph_validate on the sparse model, which checks the index and E^T Q's
   symmetry), replicated like the solver; *rcond that of the condensed
   model's J - R (the serial record's rcond_jr). */
static phgmg_result e_index_check(const dist *d, double *rcond) {
  phgmg_csc J, R, Q, E;
  phgmg_ph_sparse *sp = NULL;
  phgmg_dae *dae = NULL;
  phgmg_result rc;
  memset(&J, 0, sizeof J); memset(&R, 0, sizeof R); memset(&Q, 0, sizeof Q); memset(&E, 0, sizeof E);
  rc = triplets_csc(d->N, d->TJ, d->nJ, &J);
  if (rc == PHGMG_OK) rc = triplets_csc(d->N, d->TR, d->nR, &R);
  if (rc == PHGMG_OK) rc = triplets_csc(d->N, d->TQ, d->nQ, &Q);
  if (rc == PHGMG_OK) rc = triplets_csc(d->N, d->TE, d->nE, &E);
  if (rc == PHGMG_OK) rc = phgmg_ph_sparse_create_e(&sp, d->N, d->m, &J, &R, &Q, &E, d->Bfull, NULL, NULL, NULL);
  if (rc == PHGMG_OK) rc = phgmg_ph_validate(phgmg_ph_sparse_system(sp), 1e-12, NULL, NULL);
  if (rc == PHGMG_OK) rc = phgmg_dae_create(&dae, phgmg_ph_sparse_system(sp), 0.0, NULL);
  if (rc == PHGMG_OK) rc = phgmg_ph_validate(phgmg_dae_system(dae), 0.0, rcond, NULL);
  phgmg_dae_destroy(dae);
  phgmg_ph_sparse_destroy(sp);
  phgmg_csc_free(&J, NULL); phgmg_csc_free(&R, NULL); phgmg_csc_free(&Q, NULL); phgmg_csc_free(&E, NULL);
  return rc;
}

/* The replicated solver of the mass matrix (--E-coo): E joins J, R and
   (here) Q = I in a sparse model, whose factor of E (phgmg_e_factor_create)
   solve_replicated then applies. With algebraic lines (s->nalg zero rows
   and columns, s->calg marking the columns) the model is first checked as
   the serial command checks it (index one), and E is completed by a 1
   pairing the i-th zero row with the i-th zero column: a nonsingular
   matrix whose solve, on a right-hand side zero in the zero rows, gives
   E_dd's solution and zero algebraic variables (the library's solve_E). */
static phgmg_result solver_e_create(const dist *d, solver *s) {
  phgmg_csc J, R, I, E;
  phgmg_result rc;
  int *idx = (int *)malloc(sizeof(int) * (size_t)d->N), i, ia = 0, ic = 0;
  double *ones = (double *)malloc(sizeof(double) * (size_t)d->N), *T = NULL;
  long k, n;
  memset(s, 0, sizeof *s);
  memset(&J, 0, sizeof J); memset(&R, 0, sizeof R); memset(&I, 0, sizeof I); memset(&E, 0, sizeof E);
  s->d = d;
  s->full = (double *)malloc(sizeof(double) * 2 * (size_t)d->N);
  s->calg = (unsigned char *)malloc((size_t)d->N + 1);
  rc = idx && ones && s->full && s->calg ? PHGMG_OK : PHGMG_ERR_NOMEM;
  if (rc == PHGMG_OK) rc = e_lines(d, s->calg, &s->nalg);
  if (rc == PHGMG_OK && s->nalg) rc = e_index_check(d, &s->rcond_c);
  n = d->nE + s->nalg;
  if (rc == PHGMG_OK && !(T = (double *)malloc(sizeof(double) * 3 * (size_t)n))) rc = PHGMG_ERR_NOMEM;
  if (rc == PHGMG_OK) {   /* E's triplets, then the pairs (a_i, c_i, 1) */
    unsigned char *rz = (unsigned char *)calloc((size_t)d->N + 1, 1);
    for (k = 0; rz && k < d->nE; ++k) {
      T[k] = d->TE[k]; T[n + k] = d->TE[d->nE + k]; T[2 * n + k] = d->TE[2 * d->nE + k];
      if (d->TE[2 * d->nE + k] != 0.0) rz[(int)d->TE[k]] = 1;
    }
    for (k = d->nE; rz && k < n; ++k, ++ia, ++ic) {
      while (rz[ia]) ++ia;
      while (!s->calg[ic]) ++ic;
      T[k] = ia; T[n + k] = ic; T[2 * n + k] = 1.0;
    }
    if (!rz) rc = PHGMG_ERR_NOMEM;
    free(rz);
  }
  if (rc == PHGMG_OK) {
    s->work = s->full + d->N;
    for (i = 0; i < d->N; ++i) { idx[i] = i; ones[i] = 1.0; }
    rc = triplets_csc(d->N, d->TJ, d->nJ, &J);
  }
  if (rc == PHGMG_OK) rc = triplets_csc(d->N, d->TR, d->nR, &R);
  if (rc == PHGMG_OK) rc = triplets_csc(d->N, T, n, &E);
  if (rc == PHGMG_OK) rc = phgmg_csc_from_coo(&I, d->N, d->N, d->N, idx, idx, ones, NULL);
  if (rc == PHGMG_OK) rc = phgmg_ph_sparse_create_e(&s->sp, d->N, d->m, &J, &R, &I, &E, d->Bfull, NULL, NULL, NULL);
  if (rc == PHGMG_OK) rc = phgmg_e_factor_create(&s->f, phgmg_ph_sparse_system(s->sp), &s->rcond, NULL);
  if (rc == PHGMG_ERR_SINGULAR) rc = PHGMG_ERR_E_SINGULAR;   /* the message names E, not J - R */
  phgmg_csc_free(&J, NULL); phgmg_csc_free(&R, NULL); phgmg_csc_free(&I, NULL); phgmg_csc_free(&E, NULL);
  free(idx); free(ones); free(T);
  return rc;
}

static void solver_free(solver *s) {
  phgmg_jr_factor_destroy(s->f);
  phgmg_ph_sparse_destroy(s->sp);
  free(s->full);
  free(s->calg);
}

/* The solve callback: each column of X (this rank's rows) gathered to every
   rank, solved with the replicated factor of J - R (or its transpose), and
   this rank's rows kept. Collective. */
static phgmg_result solve_replicated(char trans, int nrhs, double *X, int ldx, void *user) {
  solver *s = (solver *)user;
  const dist *d = s->d;
  phgmg_result rc = PHGMG_OK;
  int j;
  for (j = 0; j < nrhs; ++j) {
    double *x = X + (size_t)j * ldx;
    MPI_Allgatherv(x, d->nloc, MPI_DOUBLE, s->full, d->cnt, d->dsp, MPI_DOUBLE, MPI_COMM_WORLD);
    if (rc == PHGMG_OK) rc = phgmg_ph_sparse_to_banded_order(s->sp, 1, s->full, d->N, s->work, d->N);
    if (rc == PHGMG_OK) {
      phgmg_jr_solve(s->f, trans, 1, s->work, d->N);
      rc = phgmg_ph_sparse_to_user_order(s->sp, 1, s->work, d->N, s->full, d->N);
    }
    if (rc == PHGMG_OK && d->nloc > 0) memcpy(x, s->full + d->row0, sizeof(double) * (size_t)d->nloc);
  }
  return rc;
}

/* ---- the reduction ------------------------------------------------------------ */

/* What the reduction gives rank 0 to write: the model, the basis rows, the info. */
typedef struct result {
  phgmg_mpi_rom mr;
  double *V0;                    /* this rank's rows (nloc x r) */
  double sigma_ratio, rcond_jr, seconds;
  int nalg;                      /* E's algebraic lines (zero rows and columns) */
} result;

/* sigma_{p+1} / sigma_1 of what the method PODs (the serial info's
   pod_sigma_ratio): GMG-POD the snapshots adjusted by B (X - QB QB^T X,
   QB an orthonormal basis of B's columns), p = r - m; SP1 the snapshots,
   p = r. 0 if there is no further mode. Collective. */
static phgmg_result sigma_ratio(const phgmg_mpi_ctx *ctx, const dist *d, const args *a, solver *se, double *ratio) {
  const int ld = d->nloc > 0 ? d->nloc : 1, m = d->m, ns = d->ns;
  const int gmg = a->method == PHGMG_METHOD_GMG_POD || a->method == PHGMG_METHOD_GMG_QM;
  const int p = gmg ? a->r - m : a->r;
  int kmax = p + 1, k = 0, i, j;
  double *Xa = (double *)malloc(sizeof(double) * ((size_t)ld * ns + (size_t)ld * (m + kmax) + (size_t)(m + kmax) * ns + 1));
  double *QB = Xa + (size_t)ld * ns, *V = QB + (size_t)ld * m, *C = V + (size_t)ld * kmax, *S = C;
  phgmg_result rc = any_rank(!Xa) ? PHGMG_ERR_NOMEM : PHGMG_OK;
  *ratio = 0.0;
  if (kmax > ns) kmax = ns;
  if ((long)kmax > (long)d->N) kmax = d->N;
  if (rc == PHGMG_OK && d->nloc > 0) memcpy(Xa, d->Xl, sizeof(double) * (size_t)d->nloc * ns);
  if (rc == PHGMG_OK && gmg) {   /* Xa = X - QB (QB^T X); with a mass matrix QB from E^{-1} B */
    double *Bp = (double *)malloc(sizeof(double) * (size_t)ld * m);
    if (any_rank(!Bp)) rc = PHGMG_ERR_NOMEM;
    for (j = 0; rc == PHGMG_OK && j < m && d->nloc > 0; ++j)
      memcpy(Bp + (size_t)j * ld, d->Bl + (size_t)j * ld, sizeof(double) * (size_t)d->nloc);
    if (rc == PHGMG_OK && se) rc = phgmg_mpi_agree(MPI_COMM_WORLD, solve_replicated('N', m, Bp, ld, se));
    for (i = 0; rc == PHGMG_OK && se && se->calg && i < d->nloc; ++i)   /* E_dd^{-1} B: 0 at the algebraic variables */
      for (j = 0; se->calg[d->row0 + i] && j < m; ++j) Bp[i + (size_t)j * ld] = 0.0;
    if (rc == PHGMG_OK) rc = phgmg_mpi_tsqr(ctx, m, Bp, ld, QB, ld, C, m);
    free(Bp);
    if (rc == PHGMG_OK) rc = phgmg_mpi_atb(ctx, m, ns, QB, ld, Xa, ld, C, m);
    for (j = 0; rc == PHGMG_OK && j < ns; ++j)
      for (i = 0; i < d->nloc; ++i) {
        double s = 0.0;
        int q;
        for (q = 0; q < m; ++q) s += QB[i + (size_t)q * ld] * C[q + (size_t)j * m];
        Xa[i + (size_t)j * ld] -= s;
      }
  }
  for (i = 0; rc == PHGMG_OK && gmg && se && se->calg && i < d->nloc; ++i)   /* the differential part only */
    for (j = 0; se->calg[d->row0 + i] && j < ns; ++j) Xa[i + (size_t)j * ld] = 0.0;
  if (rc == PHGMG_OK && kmax > p) rc = phgmg_mpi_pod(ctx, ns, Xa, ld, kmax, 0.0, V, ld, S, &k);
  if (rc == PHGMG_OK && k > p && S[0] > 0.0) *ratio = S[p] / S[0];
  free(Xa);
  return rc;
}

static int res_nalg_ = 0;   /* explain: the model's algebraic lines */

/* The message of a failed reduction. */
static void explain(const args *a, const dist *d, phgmg_result rc) {
  const char *meth = method_name(a->method);
  if (rc == PHGMG_ERR_SIZE)
    say("%s: --r %d does not fit: %s (N = %d, m = %d, %d snapshots; the order must not exceed the snapshots' "
        "numerical rank%s)", meth, a->r, phgmg_result_string(rc), d->N, d->m, d->ns,
        a->method == PHGMG_METHOD_SP1 || a->method == PHGMG_METHOD_SP2 ? "" : " plus m, and must exceed m");
  else if (rc == PHGMG_ERR_SINGULAR && a->dampf)
    say("--dampers %s: J - R minus the dampers' linear part at 0 (their c1 terms) is singular or its LU needs "
        "pivoting the sparse LU does not do: %s", a->dampf, phgmg_result_string(rc));
  else if (rc == PHGMG_ERR_SINGULAR)
    say("%s: J - R (--J-coo %s, --R-coo %s) is singular or its LU needs pivoting the sparse LU does not do: %s",
        meth, a->J, a->R, phgmg_result_string(rc));
  else if (rc == PHGMG_ERR_DAMPER)
    say("--dampers %s: %s", a->dampf ? a->dampf : "", phgmg_result_string(rc));
  else if (rc == PHGMG_ERR_RANK)
    say("%s: --B %s is rank deficient: %s", meth, a->B, phgmg_result_string(rc));
  else if (rc == PHGMG_ERR_NOT_SKEW)
    say("--J-coo %s: J is not skew-symmetric (relative tolerance 1e-12): %s", a->J, phgmg_result_string(rc));
  else if (rc == PHGMG_ERR_NOT_SYMMETRIC || rc == PHGMG_ERR_NOT_PSD)
    say("--R-coo %s: R is not symmetric positive semidefinite (relative tolerance 1e-12): %s", a->R,
        phgmg_result_string(rc));
  else if (rc == PHGMG_ERR_E_COUPLED)
    say("--E-coo %s: %s (E's row at a nonlinear term's coordinate must be a positive multiple of the unit row)",
        a->E, phgmg_result_string(rc));
  else if (rc == PHGMG_ERR_E_SINGULAR)
    say("--E-coo %s: %s (phgmg-mpi takes a mass matrix of full rank, or one of index one: as many zero rows as "
        "zero columns, the rest nonsingular)", a->E, phgmg_result_string(rc));
  else if ((rc == PHGMG_ERR_INDEX || rc == PHGMG_ERR_PENCIL || rc == PHGMG_ERR_EQ_NOT_SYMMETRIC) && a->E)
    say("--E-coo %s: %s", a->E, phgmg_result_string(rc));
  else if (rc == PHGMG_ERR_UNSUPPORTED && res_nalg_ > 0)
    say("--B %s: a port on an algebraic equation (a zero row of --E-coo %s) becomes a feedthrough when the "
        "constraints are condensed, which phgmg-mpi does not take: use the serial `phgmg reduce`", a->B, a->E);
  else if (rc == PHGMG_ERR_NEGATIVE_WEIGHT)
    say("%s: %s (use --deim-allow-negative, a smaller --deim-tol, or --hyper ecsw)", meth, phgmg_result_string(rc));
  else if (rc == PHGMG_ERR_NOT_CONVERGED && a->poly_idx)
    say("%s: the ECSW hyper-reduction misses --hyper-tol %g: %s (a larger --hyper-tol, or --no-hyper)", meth,
        a->have_hyper_tol ? a->hyper_tol : 1e-6, phgmg_result_string(rc));
  else if (rc == PHGMG_ERR_TOL_UNREACHABLE)
    say("%s: --hyper-tol %g: %s", meth, a->hyper_tol, phgmg_result_string(rc));
  else if ((rc == PHGMG_ERR_INVALID_ARG || rc == PHGMG_ERR_SIZE || rc == PHGMG_ERR_NANINF) && a->poly_idx)
    say("%s: the nonlinear terms (--poly-idx %s): %s", meth, a->poly_idx, phgmg_result_string(rc));
  else
    say("%s: %s", meth, phgmg_result_string(rc));
}

/* gmg-qm's lifting dimension when --rn is not given: the serial command's
   min(8, N - r, 4096 / (r - m)), at least 1. */
static int default_rn(int N, int r, int m) {
  phgmg_reduce_opts def;
  int rn;
  phgmg_reduce_opts_default(&def);
  rn = def.qm.rn < N - r ? def.qm.rn : N - r;
  if (r > m && rn > 4096 / (r - m)) rn = 4096 / (r - m);
  return rn > 1 ? rn : 1;
}

/* The reduction on every rank: the context, Q (and for sp1 J - R) as
   distributed operators, the replicated solver, phgmg_mpi_reduce. */
static int reduce(const args *a, dist *d, result *res) {
  phgmg_mpi_ctx *ctx = NULL;
  phgmg_mpi_op *Qop = NULL, *JRop = NULL, *Eop = NULL;
  phgmg_mpi_sep_model md;
  phgmg_reduce_opts o;
  solver sv, svE;
  const int ld = d->nloc > 0 ? d->nloc : 1;
  double t0;
  phgmg_result rc = phgmg_mpi_ctx_create(&ctx, MPI_COMM_WORLD, d->N, d->row0, d->nloc, NULL);
  memset(&sv, 0, sizeof sv);
  memset(&svE, 0, sizeof svE);
  memset(&md, 0, sizeof md);
  t0 = MPI_Wtime();
  if (rc == PHGMG_OK) rc = make_op(ctx, d, d->TQ, d->nQ, 1.0, NULL, 0, 0.0, &Qop);
  if (rc == PHGMG_OK && (a->method == PHGMG_METHOD_SP1 || a->method == PHGMG_METHOD_SP2))   /* J - R as an operator */
    rc = make_op(ctx, d, d->TJ, d->nJ, 1.0, d->TR, d->nR, -1.0, &JRop);
  if (rc == PHGMG_OK) rc = phgmg_mpi_agree(MPI_COMM_WORLD, solver_create(d, &sv));
  if (rc == PHGMG_OK && a->E) {   /* the mass matrix: its rows as an operator, its replicated solver */
    rc = make_op(ctx, d, d->TE, d->nE, 1.0, NULL, 0, 0.0, &Eop);
    if (rc == PHGMG_OK) rc = phgmg_mpi_agree(MPI_COMM_WORLD, solver_e_create(d, &svE));
    res->nalg = svE.nalg;
  }
  phgmg_npy_free(d->TQ, NULL);   /* Q lives in its operator now */
  d->TQ = NULL;
  phgmg_npy_free(d->TE, NULL);
  d->TE = NULL;
  phgmg_npy_free(d->TJ, NULL); phgmg_npy_free(d->TR, NULL); phgmg_npy_free(d->Bfull, NULL);
  d->TJ = d->TR = d->Bfull = NULL;   /* J - R and B live in the solver (and the operators) now */
  res->V0 = (double *)malloc(sizeof(double) * ((size_t)ld * a->r + 1));
  if (rc == PHGMG_OK && any_rank(!res->V0)) rc = PHGMG_ERR_NOMEM;
  if (rc == PHGMG_OK) {
    md.lin.Q = Qop; md.lin.m = d->m; md.lin.B = d->Bl; md.lin.ldb = ld;
    md.lin.solve = solve_replicated; md.lin.solve_user = &sv;
    if (Eop) { md.lin.E = Eop; md.lin.solve_E = solve_replicated; md.lin.solve_E_user = &svE; }
    md.JR = JRop;
    if (a->poly_idx) {   /* this rank's terms, their serial term numbers as global ids */
      md.nsep = d->nsep; md.sep_idx = d->sidx; md.sep_id = d->sid; md.sep_w = d->sw;
      md.poly_deg = d->poly_deg; md.nexp = d->nexp; md.per_term = d->per_term;
      md.poly = d->spoly; md.expo = d->sexpo;
    } else {
      md.poly_deg = 1;   /* no separable terms (nsep = 0): a linear model */
    }
    if (a->dampf) {   /* this rank's dampers, one law each (the serial command's c1 s + c3 s^3 per row) */
      md.ndamp = d->ndl; md.damp_i = d->dli; md.damp_j = d->dlj; md.damp_id = d->dlid;
      md.damp_deg = 3; md.damp_poly = d->dlaw; md.damp_per = 1;
    }
    memset(&o, 0, sizeof o);
    o.method = (phgmg_method)a->method; o.r = a->r;
    /* the serial default: ECSW (tolerance 1e-6 unless --hyper-tol) on a nonlinear part, --no-hyper keeps every term */
    o.hyper.on = a->poly_idx && !a->no_hyper;
    o.hyper.kind = (phgmg_hyper)a->hyper_kind;
    o.hyper.tol = a->have_hyper_tol ? a->hyper_tol : 0.0;
    o.hyper.deim_tol = a->deim_tol; o.hyper.deim_max = a->deim_max; o.hyper.allow_negative = a->deim_neg;
    o.hyper.keep_dampers = 1;   /* as the serial command: every damper kept, the options apply to the terms */
    if (a->method == PHGMG_METHOD_GMG_QM) {   /* the serial command's gmg-qm options (a fixed lambda) */
      o.qm.manifold = (phgmg_manifold)a->manifold;
      o.qm.rn = a->rn ? a->rn : default_rn(d->N, a->r, d->m);
      o.qm.lambda = a->lambda > 0.0 ? a->lambda : -1.0;   /* 0 on the command line: exactly zero */
      if (a->lambda_cv) o.select.lambda_mode = PHGMG_LAMBDA_REGRESSION;   /* the serial --lambda cv */
    }
    rc = phgmg_mpi_reduce(ctx, &md, d->ns, d->Xl, ld, &o, &res->mr, res->V0, ld);
  }
  res->seconds = MPI_Wtime() - t0;
  res_nalg_ = res->nalg;
  res->rcond_jr = svE.nalg ? svE.rcond_c : sv.rcond;   /* the serial record's: the condensed model's */
  if (rc == PHGMG_OK) rc = sigma_ratio(ctx, d, a, Eop ? &svE : NULL, &res->sigma_ratio);
  if (rc != PHGMG_OK) explain(a, d, rc);
  solver_free(&sv);
  solver_free(&svE);
  phgmg_mpi_op_destroy(Eop);
  phgmg_mpi_op_destroy(Qop);
  phgmg_mpi_op_destroy(JRop);
  phgmg_mpi_ctx_destroy(ctx);
  return rc != PHGMG_OK;
}

/* ---- outputs (rank 0) ---------------------------------------------------------- */

/* The outputs: DIR/NAME.phgmgrom, .c, .json, then arrays DIR/NAME_<array>.npy,
   each array one the serial command writes, in its order: the blocks of the
   reduced model (those it has), then the basis V0 and, for gmg-qm, V2 and M
   of the lift. Output k < 3 is a file, k >= 3 the array arr_name[k - 3]. */
#define NARR 18
static const char *const arr_name[NARR] = {"Bh", "Qh", "K", "G00", "G01", "G10", "G11", "Q01", "Q11", "Ms",
                                           "P0", "P1", "w", "poly", "expo", "V0", "V2", "M"};
enum { ARR_V0 = 15, ARR_V2 = 16, ARR_M = 17 };

/* An array to write: its name (arr_name index), its values (phgmg_real of
   the model, or double), its shape (rows x cols, column-major, ld rows). */
typedef struct outarr {
  int k, rows, cols;
  const phgmg_real *re;
  const double *d;
} outarr;
static outarr g_arr[NARR];
static int g_narr = 0;

/* The output path of output k (4096 + 96 chars). */
static void out_path(const args *a, int k, char *buf, size_t cap) {
  static const char *const file_suffix[3] = {".phgmgrom", ".c", ".json"};
  if (k < 3) snprintf(buf, cap, "%.4000s/%s%s", a->out, a->name, file_suffix[k]);
  else snprintf(buf, cap, "%.4000s/%s_%s.npy", a->out, a->name, arr_name[k - 3]);
}

/* 1 if an output is one of the input files: a run never overwrites its inputs. */
static int outputs_clash(const args *a) {
  const char *in[11];
  const char *opt[11] = {"--J-coo", "--R-coo", "--Q-coo", "--B", "--X", "--poly-idx", "--poly-w", "--poly", "--exp",
                         "--E-coo", "--dampers"};
  char p[4200];
  int k, i;
  in[0] = a->J; in[1] = a->R; in[2] = a->Q; in[3] = a->B; in[4] = a->X;
  in[5] = a->poly_idx; in[6] = a->poly_w; in[7] = a->poly; in[8] = a->expf; in[9] = a->E; in[10] = a->dampf;
  for (k = 0; k < 3 + NARR; ++k) {
    out_path(a, k, p, sizeof p);
    for (i = 0; i < 11; ++i)
      if (in[i] && (same_file(p, in[i]) || !strcmp(p, in[i]))) {
        say("--out %s: the output %s is the input file of %s; choose another --out or --name", a->out, p, opt[i]);
        return 1;
      }
  }
  return 0;
}

/* 1 if --out names something that is not a directory (checked before the
   work; the directory itself is made when the outputs are written). */
static int out_not_dir(const args *a) {
  struct stat st;
  if (stat(a->out, &st) != 0 || S_ISDIR(st.st_mode)) return 0;
  say("--out %s: exists and is not a directory", a->out);
  return 1;
}

/* mkdir -p DIR. */
static int make_dir(const char *dir) {
  char buf[4096];
  size_t i, n = strlen(dir);
  struct stat st;
  if (n == 0 || n >= sizeof buf) { say("--out: the path is empty or too long"); return 1; }
  memcpy(buf, dir, n + 1);
  for (i = 1; i <= n; ++i) {
    if (buf[i] != '/' && buf[i] != '\0') continue;
    buf[i] = '\0';
    if (mkdir(buf, 0777) != 0 && errno != EEXIST) { say("--out %s: cannot create %s: %s", dir, buf, strerror(errno)); return 1; }
    buf[i] = i < n ? '/' : '\0';
  }
  if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) { say("--out %s: not a directory", dir); return 1; }
  return 0;
}

/* Every output is written to PATH.part and renamed at the end (a failed run
   leaves the previous outputs as they were). Output j < 3 is file j, j >= 3
   the array g_arr[j - 3]. */
static int out_index(int j) { return j < 3 ? j : 3 + g_arr[j - 3].k; }

static void part_path(const args *a, int k, char *buf, size_t cap) {
  char p[4200];
  out_path(a, k, p, sizeof p);
  snprintf(buf, cap, "%s.part", p);
}

static void parts_remove(const args *a) {
  char p[4300];
  int j;
  for (j = 0; j < 3 + g_narr; ++j) { part_path(a, out_index(j), p, sizeof p); remove(p); }
}

static int parts_commit(const args *a) {
  char p[4300], q[4200];
  int j;
  for (j = 0; j < 3 + g_narr; ++j) {
    part_path(a, out_index(j), p, sizeof p);
    out_path(a, out_index(j), q, sizeof q);
    if (rename(p, q) != 0) { say("%s: cannot move into place: %s", q, strerror(errno)); return 1; }
  }
  return 0;
}

/* A .npy header (version 1.0, '<f8', Fortran order) for rows x cols, padded
   to a multiple of 64 bytes as NumPy pads it. */
static int npy_header(FILE *f, long rows, long cols) {
  char dict[128];
  unsigned char pre[10] = {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0, 0, 0};
  int n = snprintf(dict, sizeof dict, "{'descr': '<f8', 'fortran_order': True, 'shape': (%ld, %ld), }", rows, cols);
  int total = ((10 + n + 1 + 63) / 64) * 64, hl = total - 10, i;
  pre[8] = (unsigned char)(hl & 0xff); pre[9] = (unsigned char)(hl >> 8);
  if (fwrite(pre, 1, 10, f) != 10 || fwrite(dict, 1, (size_t)n, f) != (size_t)n) return 1;
  for (i = 10 + n; i < total - 1; ++i) fputc(' ', f);
  return fputc('\n', f) == EOF;
}

/* A distributed array (N x cols, this rank's rows in A, ld): rank 0 writes
   the header, then each column gathered from the ranks' rows. Collective;
   the verdict is agreed. */
static int write_rows(const args *a, const dist *d, int k, const double *A, int cols) {
  const int ld = d->nloc > 0 ? d->nloc : 1;
  char p[4300];
  FILE *f = NULL;
  double *col = NULL;
  int j, bad = 0;
  if (d->rank == 0) {
    part_path(a, 3 + k, p, sizeof p);
    f = fopen(p, "wb");
    col = (double *)malloc(sizeof(double) * (size_t)d->N);
    bad = !f || !col || npy_header(f, d->N, cols);
  }
  if (any_rank(bad)) {
    if (f) fclose(f);
    free(col);
    say("%s: cannot write: %s", p, strerror(errno));
    return 1;
  }
  for (j = 0; j < cols; ++j) {
    MPI_Gatherv(A + (size_t)j * ld, d->nloc, MPI_DOUBLE, col, d->cnt, d->dsp, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    if (d->rank == 0 && !bad) bad = fwrite(col, sizeof(double), (size_t)d->N, f) != (size_t)d->N;
  }
  if (d->rank == 0) {
    bad |= fclose(f) != 0;
    if (bad) say("%s: write error", p);
  }
  free(col);
  return any_rank(bad);
}

/* The arrays of the model in the serial command's order (g_arr). */
static void list_arrays(const args *a, const dist *d, const result *res) {
  const phgmg_rom *rom = &res->mr.rom;
  const int r = rom->r, m = rom->m, rn = rom->rn, nd = rom->nd, p = r - m, nf = rom->nphi > 1 ? rom->nphi : 1;
  const int qm = rom->kind == PHGMG_ROM_QUADRATIC;
  const phgmg_real *re[15];
  const int shape[15][2] = {{r, m}, {r, r}, {r, r}, {r, r}, {r, rn}, {rn, r}, {rn, rn}, {r, rn}, {rn, rn},
                            {rn, p * p}, {nd, r}, {nd, rn}, {nd, 1}, {nf, rom->poly_deg + 1}, {nf, 2 * rom->nexp}};
  int k;
  re[0] = rom->Bh; re[1] = rom->Qh; re[2] = rom->K; re[3] = rom->G00; re[4] = rom->G01; re[5] = rom->G10;
  re[6] = rom->G11; re[7] = rom->Q01; re[8] = rom->Q11; re[9] = rom->Ms; re[10] = rom->P0; re[11] = rom->P1;
  re[12] = rom->w; re[13] = rom->poly; re[14] = rom->expo;
  g_narr = 0;
  for (k = 0; k < 15; ++k) {
    if (!re[k] || shape[k][0] < 1 || shape[k][1] < 1 || (k >= 3 && k <= 9 && !qm) || (k >= 10 && nd < 1)) continue;
    g_arr[g_narr].k = k; g_arr[g_narr].re = re[k]; g_arr[g_narr].d = NULL;
    g_arr[g_narr].rows = shape[k][0]; g_arr[g_narr].cols = shape[k][1];
    ++g_narr;
  }
  g_arr[g_narr].k = ARR_V0; g_arr[g_narr].rows = d->N; g_arr[g_narr].cols = a->r; ++g_narr;
  if (qm) {
    g_arr[g_narr].k = ARR_V2; g_arr[g_narr].rows = d->N; g_arr[g_narr].cols = rn; ++g_narr;
    g_arr[g_narr].k = ARR_M; g_arr[g_narr].d = res->mr.M; g_arr[g_narr].re = NULL;
    g_arr[g_narr].rows = rn; g_arr[g_narr].cols = p * p; ++g_narr;
  }
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

/* A JSON number: the shortest of %.15g..%.17g that reads back exactly; null for NaN/Inf. */
static void json_num(FILE *f, double v) {
  char buf[32];
  int prec;
  if (!isfinite(v)) { fputs("null", f); return; }
  for (prec = 15; prec < 17; ++prec) {
    snprintf(buf, sizeof buf, "%.*g", prec, v);
    if (strtod(buf, NULL) == v) break;
  }
  fputs(buf, f);
}

/* The json record's "system" object: the input files. */
static void json_system(FILE *f, const args *a) {
  fprintf(f, "  \"system\": {\"J\": "); json_str(f, a->J);
  fprintf(f, ", \"R\": "); json_str(f, a->R);
  fprintf(f, ", \"B\": "); json_str(f, a->B);
  fprintf(f, ", \"Q\": "); json_str(f, a->Q);
  fprintf(f, ", \"sparse\": true");
  if (a->E) { fprintf(f, ", \"E\": "); json_str(f, a->E); }
  if (a->dampf) { fprintf(f, ", \"dampers\": "); json_str(f, a->dampf); }
  if (a->poly_idx) {
    if (a->poly) { fprintf(f, ", \"poly\": "); json_str(f, a->poly); }
    if (a->expf) { fprintf(f, ", \"exp\": "); json_str(f, a->expf); }
    if (a->potential) { fprintf(f, ", \"potential\": "); json_str(f, a->potential); }
    fprintf(f, ", \"poly_idx\": "); json_str(f, a->poly_idx);
    if (a->poly_w) { fprintf(f, ", \"poly_w\": "); json_str(f, a->poly_w); }
  }
  fprintf(f, "},\n");
}

/* The "options" object, as the serial command writes it (gmg-qm: its
   lifting dimension, the fixed lambda and the manifold first). */
static void json_options(FILE *f, const args *a, const result *res) {
  const int hyper = a->poly_idx && !a->no_hyper, deim = hyper && a->hyper_kind != PHGMG_HYPER_ECSW;
  fprintf(f, "  \"options\": {");
  if (a->method == PHGMG_METHOD_GMG_QM) {
    fprintf(f, "\"rn\": %d, \"lambda\": ", res->mr.rn);
    if (a->lambda_cv) json_str(f, "cv");
    else json_num(f, a->lambda);
    fprintf(f, ", \"lambda_used\": "); json_num(f, res->mr.qm_lambda == HUGE_VAL ? -1.0 : res->mr.qm_lambda);
    fprintf(f, ", \"manifold\": \"%s\", ", a->manifold == PHGMG_MANIFOLD_GREEDY ? "greedy" : "pod");
  }
  fprintf(f, "\"training_runs\": 0, \"ref\": \"none\", \"hyper\": \"%s\"", hyper ? hyper_name(a->hyper_kind) : "none");
  if (hyper && !deim) { fprintf(f, ", \"hyper_tol\": "); json_num(f, a->have_hyper_tol ? a->hyper_tol : 1e-6); }
  fprintf(f, ", \"deim\": %s", deim ? "true" : "false");
  if (deim) {
    fprintf(f, ", \"deim_tol\": "); json_num(f, a->deim_tol);
    fprintf(f, ", \"deim_max\": %d, \"deim_allow_negative\": %s", a->deim_max, a->deim_neg ? "true" : "false");
  }
  fprintf(f, "},\n");
}

/* The "info" object: the serial command's diagnostics, the ranks and the solver. */
static void json_info(FILE *f, const args *a, const dist *d, const result *res) {
  const int nd = res->mr.nd, hyper = a->poly_idx && !a->no_hyper, deim = hyper && a->hyper_kind != PHGMG_HYPER_ECSW;
  int j, nneg = 0;
  double wmin = HUGE_VAL;
  for (j = 0; j < nd; ++j) { wmin = fmin(wmin, res->mr.w[j]); nneg += res->mr.w[j] < 0.0; }
  fprintf(f, "  \"info\": {\"pod_sigma_ratio\": "); json_num(f, res->sigma_ratio);
  fprintf(f, ", \"rcond_jr\": "); json_num(f, res->rcond_jr);
  if (a->method == PHGMG_METHOD_GMG_POD || a->method == PHGMG_METHOD_GMG_QM) fprintf(f, ", \"degeneracy_tol\": 1e-12");
  if (hyper) {
    fprintf(f, ", \"hyper\": {\"method\": \"%s\", \"points\": %d, \"negative_weights\": %d, \"min_weight\": ",
            hyper_name(a->hyper_kind), nd, nneg);
    json_num(f, nd ? wmin : 0.0);
    if (deim) {
      fprintf(f, ", \"tol\": "); json_num(f, a->deim_tol);
      fprintf(f, ", \"sigma_ratio\": "); json_num(f, res->mr.deim_sigma_ratio);
    } else {
      fprintf(f, ", \"tol\": "); json_num(f, a->have_hyper_tol ? a->hyper_tol : 1e-6);
      fprintf(f, ", \"residual\": "); json_num(f, res->mr.hyper_residual);
    }
    fprintf(f, "}");
  }
  fprintf(f, ", \"reduce_seconds\": "); json_num(f, res->seconds);
  fprintf(f, ", \"mpi_ranks\": %d, \"jr_solver\": \"sparse LU of J - R replicated on every rank\"},\n", d->size);
}

/* NAME.json: the record of the serial command (what was reduced, how, and
   where the outputs are), with the ranks and the solver of J - R. */
static int write_json(const args *a, const dist *d, const result *res) {
  const phgmg_rom *rom = &res->mr.rom;
  const int qm = rom->kind == PHGMG_ROM_QUADRATIC, nd = res->mr.nd;
  char p[4300];
  FILE *f;
  int j;
  part_path(a, 2, p, sizeof p);
  if (!(f = fopen(p, "w"))) { say("%s: cannot write: %s", p, strerror(errno)); return 1; }
  fprintf(f, "{\n  \"phgmg_version\": \"%s\",\n  \"name\": ", PHGMG_VERSION_STRING);
  json_str(f, a->name);
  fprintf(f, ",\n  \"method\": \"%s\",\n  \"kind\": \"%s\",\n  \"map\": \"%s\",\n", method_name(a->method),
          a->poly_idx || a->dampf ? "nonlinear" : "linear", qm ? "quadratic" : "linear");
  fprintf(f, "  \"N\": %d, \"m\": %d, \"r\": %d, \"rn\": %d, \"nd\": %d, \"poly_deg\": %d,\n", d->N - res->nalg,
          d->m, a->r, res->mr.rn, nd, nd ? rom->poly_deg : 0);
  fprintf(f, "  \"E\": %s, \"N_full\": %d, \"algebraic\": %d, \"feedthrough\": false,\n  \"dt_map\": 0,\n",
          a->E ? "true" : "false", d->N, res->nalg);
  json_system(f, a);
  fprintf(f, "  \"snapshots\": {\"count\": %d, \"file\": ", d->ns); json_str(f, a->X);
  if (a->have_dt) { fprintf(f, ", \"dt\": "); json_num(f, a->dt); }
  fprintf(f, "},\n");
  json_options(f, a, res);
  json_info(f, a, d, res);
  fprintf(f, "  \"stepper_memsize_bytes\": %lu,\n", (unsigned long)phgmg_rom_stepper_memsize(rom));
  fprintf(f, "  \"reconstruction\": \"%s\",\n", qm ? "x = V0 @ xr + V2 @ (M @ kron(xr[m:], xr[m:]))" : "x = V0 @ xr");
  fprintf(f, "  \"files\": {\n    \"model\": \"%s.phgmgrom\",\n    \"c_source\": \"%s.c\",\n    \"arrays\": {", a->name,
          a->name);
  for (j = 0; j < g_narr; ++j)
    fprintf(f, "%s\n      \"%s_%s.npy\": [%d, %d]", j ? "," : "", a->name, arr_name[g_arr[j].k], g_arr[j].rows,
            g_arr[j].cols);
  fprintf(f, "\n    }\n  }\n}\n");
  if (fclose(f) != 0) { say("%s: write error", p); return 1; }
  return 0;
}

/* Rank 0: the replicated arrays (the model's, as double, and M). */
static int write_small(const args *a) {
  double *buf = NULL;
  size_t cap = 0;
  char p[4300];
  phgmg_result rc = PHGMG_OK;
  int j;
  for (j = 0; j < g_narr && rc == PHGMG_OK; ++j) {
    const outarr *o = &g_arr[j];
    const size_t n = (size_t)o->rows * (size_t)o->cols;
    size_t q;
    if (o->k == ARR_V0 || o->k == ARR_V2) continue;   /* distributed: write_rows */
    if (n > cap) {
      double *nb = (double *)realloc(buf, n * sizeof(double));
      if (!nb) { rc = PHGMG_ERR_NOMEM; break; }
      buf = nb; cap = n;
    }
    for (q = 0; q < n; ++q) buf[q] = o->re ? (double)o->re[q] : o->d[q];
    part_path(a, 3 + o->k, p, sizeof p);
    rc = phgmg_npy_write(p, buf, o->rows, o->cols, o->rows, 2, 0u);
  }
  free(buf);
  if (rc != PHGMG_OK) { say("%s: cannot write: %s", p, phgmg_result_string(rc)); return 1; }
  return 0;
}

/* Rank 0: the model file, its C source and the replicated arrays. */
static int write_model(const args *a, result *res) {
  phgmg_rom rom = res->mr.rom;
  char p[4300];
  phgmg_result rc;
  rom.dt = a->have_dt ? a->dt : 0.0;   /* the snapshots' step, if known (simulate-rom's default) */
  part_path(a, 0, p, sizeof p);
  rc = phgmg_rom_save(&rom, p);
  if (rc != PHGMG_OK) { say("%s: cannot write the model file: %s", p, phgmg_result_string(rc)); return 1; }
  part_path(a, 1, p, sizeof p);
  rc = phgmg_rom_export_c(&rom, a->name, p);
  if (rc != PHGMG_OK) { say("%s: cannot write the C source: %s", p, phgmg_result_string(rc)); return 1; }
  return write_small(a);
}

/* Every output: the distributed arrays gathered (collective), then rank 0
   writes the rest and moves everything into place. */
static int write_outputs(const args *a, const dist *d, result *res) {
  int bad = 0;
  list_arrays(a, d, res);
  if (any_rank(d->rank == 0 && make_dir(a->out))) return 1;
  bad = write_rows(a, d, ARR_V0, res->V0, a->r);
  if (!bad && res->mr.rom.kind == PHGMG_ROM_QUADRATIC) bad = write_rows(a, d, ARR_V2, res->mr.V2, res->mr.rn);
  if (!bad && d->rank == 0) bad = write_model(a, res) || write_json(a, d, res) || parts_commit(a);
  if (bad && d->rank == 0) parts_remove(a);
  if (any_rank(bad)) return 1;
  if (d->rank == 0 && !a->quiet) {
    char dif[64] = "";
    if (res->nalg) snprintf(dif, sizeof dif, ", of which %d differential", d->N - res->nalg);
    printf("wrote %s/%s.phgmgrom, %s/%s.c, %s/%s.json and %d arrays %s/%s_*.npy (%s, r = %d, m = %d, N = %d%s, "
           "%d rank%s)\n", a->out, a->name, a->out, a->name, a->out, a->name, g_narr, a->out, a->name,
           method_name(a->method), a->r, d->m, d->N, dif, d->size, d->size > 1 ? "s" : "");
  }
  return 0;
}

/* ---- main ---------------------------------------------------------------------- */

static int run(const args *a, int size) {
  dist d;
  result res;
  int err;
  memset(&d, 0, sizeof d);
  memset(&res, 0, sizeof res);
  d.rank = g_rank; d.size = size;
  err = any_rank(g_rank == 0 && (outputs_clash(a) || out_not_dir(a)));
  if (!err) err = read_inputs(a, &d);
  if (!err) err = any_rank(reduce(a, &d, &res));
  if (!err) err = write_outputs(a, &d, &res);
  phgmg_mpi_rom_free(&res.mr);
  free(res.V0);
  dist_free(&d);
  return err;
}

int main(int argc, char **argv) {
  args a;
  int size = 1, status;
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (argc >= 2 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))) {
    int k;
    for (k = 0; g_rank == 0 && help_text[k]; ++k) fputs(help_text[k], stdout);
    status = 0;
  } else if (argc >= 2 && !strcmp(argv[1], "--version")) {
    if (g_rank == 0) printf("phgmg-mpi %s\n", PHGMG_VERSION_STRING);
    status = 0;
  } else if (argc < 2 || strcmp(argv[1], "reduce")) {
    status = usage(argc < 2 ? "a command is needed: reduce" : "%s: phgmg-mpi has one command, reduce "
                   "(simulate, simulate-rom, info, validate: the serial `phgmg`)", argv[1]);
  } else {
    status = parse_args(argc, argv, &a);
    if (status == 0) status = run(&a, size);
  }
  MPI_Finalize();
  return status;
}
