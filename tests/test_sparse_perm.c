/* Descriptor models on the sparse LU whatever the order of their columns
   (the pivot matching of manual 8.12), and the validation of sparse models
   without band copies, once per model object. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>

/* An nx x nx lattice of masses, state (q, p) per mass (indices 2n, 2n+1):
   unit springs to the four neighbours, on-site springs 0.1, damping 0.05 on
   each momentum, E = blockdiag(I on the positions, Mc on the momenta) with
   Mc(n, n) = 1, Mc(n, k) = 0.1 for each neighbour (symmetric positive
   definite, a finite-element mass matrix's pattern). swap = 1: the columns
   of E and Q of the masses 2k and 2k + 1 exchanged (positions with
   positions, momenta with momenta: E P, Q P with P the pair swap j <-> j^2):
   the same dynamics for the state P x, the same outputs; the diagonal of
   sigma E P + M P is structurally zero on the positions, E P's on every
   state. */
typedef struct sp4_mat { int *cp, *ri; double *v; phgmg_csc A; } sp4_mat;
typedef struct sp4_model { int N; sp4_mat M[4]; double *B; } sp4_model;

/* The coefficients: Mc's off-diagonal (0.1), the on-site springs (0.1), a
   coupling c of the momenta's damping R = 0.05 I + c A on the momenta (A:
   the lattice's adjacency; 0). */
static double sp4_mc = 0.1, sp4_onsite = 0.1, sp4_rc = 0.0, sp4_ks = 1.0; /* sp4_ks: scales the stiffness */

static int sp4_col(int a, int nx, int j, int *ri, double *v) {
  const int n = j / 2, x = n % nx, y = n / nx, isp = j & 1;
  int k = 0, d, nb[4], nn = 0;
  if (y > 0) nb[nn++] = n - nx;
  if (x > 0) nb[nn++] = n - 1;
  if (x + 1 < nx) nb[nn++] = n + 1;
  if (y + 1 < nx) nb[nn++] = n + nx;
  if (a == 0) { ri[0] = isp ? 2 * n : 2 * n + 1; v[0] = isp ? 1.0 : -1.0; return 1; }
  if (a == 1 && !isp) return 0;
  if (a == 2 && isp) { ri[0] = j; v[0] = 1.0; return 1; }
  if (a == 3 && !isp) { ri[0] = j; v[0] = 1.0; return 1; }
  for (d = 0; d < nn; ++d) /* Q: the stiffness on the positions; E: Mc, R: the damping on the momenta */
    if (nb[d] < n) { ri[k] = 2 * nb[d] + isp; v[k++] = a == 2 ? -1.0 : a == 1 ? sp4_rc : sp4_mc; }
  ri[k] = j; v[k++] = a == 2 ? nn + sp4_onsite : a == 1 ? 0.05 : 1.0;
  for (d = 0; d < nn; ++d)
    if (nb[d] > n) { ri[k] = 2 * nb[d] + isp; v[k++] = a == 2 ? -1.0 : a == 1 ? sp4_rc : sp4_mc; }
  return k;
}

static void sp4_build(sp4_model *md, int nx, int swap) {
  const int N = 2 * nx * nx;
  int a, j;
  md->N = N;
  for (a = 0; a < 4; ++a) {
    sp4_mat *M = &md->M[a];
    int nz = 0;
    M->cp = (int *)malloc(sizeof(int) * (size_t)(N + 1));
    M->ri = (int *)malloc(sizeof(int) * (size_t)N * 5);
    M->v = (double *)malloc(sizeof(double) * (size_t)N * 5);
    for (j = 0; j < N; ++j) {
      const int src = swap && a >= 2 ? j ^ 2 : j;
      M->cp[j] = nz;
      nz += sp4_col(a, nx, src, M->ri + nz, M->v + nz);
    }
    M->cp[N] = nz;
    if (a == 2) for (j = 0; j < nz; ++j) if (!(M->ri[j] & 1)) M->v[j] *= sp4_ks;
    M->A.n_rows = M->A.n_cols = N;
    M->A.colptr = M->cp; M->A.rowidx = M->ri; M->A.values = M->v;
  }
  md->B = (double *)calloc((size_t)N, sizeof(double));
  md->B[1] = 1.0;
}

static void sp4_free(sp4_model *md) {
  int a;
  for (a = 0; a < 4; ++a) { free(md->M[a].cp); free(md->M[a].ri); free(md->M[a].v); }
  free(md->B);
}

static void sp4_u(double t, double *u, void *user) { (void)user; u[0] = 0.1 * sin(t); }

/* Simulate steps steps with the solver forced (user-ordered states into X). */
static void sp4_run(const sp4_model *md, int solver, int steps, double *X, double *Y, phgmg_gl3_stats *st,
                    phgmg_ph_sparse_info *inf) {
  phgmg_ph_sparse *sp = NULL;
  double *x0 = (double *)calloc((size_t)md->N, sizeof(double));
  double *Xi = (double *)malloc(sizeof(double) * (size_t)md->N * (size_t)(steps + 1));
  CHECK_RC(phgmg_ph_sparse_create_e(&sp, md->N, 1, &md->M[0].A, &md->M[1].A, &md->M[2].A, &md->M[3].A, md->B, NULL,
                                    inf, NULL), PHGMG_OK);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, solver, inf), PHGMG_OK);
  CHECK_RC(phgmg_ph_validate(phgmg_ph_sparse_system(sp), 0.0, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_simulate(phgmg_ph_sparse_system(sp), x0, 0.0, 0.1, steps, sp4_u, NULL, NULL, Xi, Y, NULL, st, NULL,
                          NULL), PHGMG_OK);
  CHECK_RC(phgmg_ph_sparse_to_user_order(sp, steps + 1, Xi, md->N, X, md->N), PHGMG_OK);
  phgmg_ph_sparse_destroy(sp);
  free(x0); free(Xi);
}

TEST(test_sparse_perm_swapped_columns) {
  /* A 2-D lattice with a mass matrix whose E and Q have their columns
     swapped in pairs (every diagonal entry of E P is zero): the sparse LU
     is used from start to end (no fall-back to the band LU), the trajectory
     is the pair-swapped trajectory of the natural model and the outputs are
     equal, to round-off; the matching moves every column and the factor is
     no larger than twice the natural order's (a time comparable to it;
     without the matching the static pivots fail on the zero diagonal). */
  const int nx = 16, steps = 60, N = 2 * nx * nx;
  sp4_model nat, sw;
  double *X0 = (double *)malloc(sizeof(double) * (size_t)N * (steps + 1));
  double *X1 = (double *)malloc(sizeof(double) * (size_t)N * (steps + 1));
  double Y0[61], Y1[61], dx = 0.0, xm = 0.0, dy = 0.0, ym = 0.0;
  phgmg_gl3_stats s0, s1;
  phgmg_ph_sparse_info i0, i1;
  int j, k;
  sp4_build(&nat, nx, 0);
  sp4_build(&sw, nx, 1);
  sp4_run(&nat, PHGMG_SOLVER_SPARSE_LU, steps, X0, Y0, &s0, &i0);
  sp4_run(&sw, PHGMG_SOLVER_SPARSE_LU, steps, X1, Y1, &s1, &i1);
  CHECK(s0.sparse_lu == 1 && s0.band_fallback == 0);
  CHECK(s1.sparse_lu == 1 && s1.band_fallback == 0);
  CHECK(i0.colperm == 0 && i1.colperm == N);
  CHECK(i1.lu_sparse <= 2.0 * i0.lu_sparse);
  for (k = 0; k <= steps; ++k) {
    for (j = 0; j < N; ++j) {
      const double a = X0[(size_t)k * N + j], b = X1[(size_t)k * N + (j ^ 2)];
      dx = fmax(dx, fabs(a - b)); xm = fmax(xm, fabs(a));
    }
    dy = fmax(dy, fabs(Y0[k] - Y1[k])); ym = fmax(ym, fabs(Y0[k]));
  }
  CHECK(xm > 0.0 && ym > 0.0);
  CHECK_LE(dx, 1e-12 * xm);
  CHECK_LE(dy, 1e-12 * ym);
  sp4_free(&nat); sp4_free(&sw);
  free(X0); free(X1);
}

/* phgmg_ph_validate of the lattice (E or not, columns swapped or not) with
   the sparse LU (SPARSE storage: no band copy) and with the band LU (BANDED
   storage: band checks), and the once-per-object count of the matrix checks
   of the first. */
static void sp4_validate(int nx, int withE, int swap, phgmg_result *rs, phgmg_result *rb, long *nrun) {
  sp4_model md;
  int run;
  sp4_build(&md, nx, swap);
  for (run = 0; run < 2; ++run) {
    phgmg_ph_sparse *sp = NULL;
    CHECK_RC(phgmg_ph_sparse_create_e(&sp, md.N, 1, &md.M[0].A, &md.M[1].A, &md.M[2].A, withE ? &md.M[3].A : NULL,
                                      md.B, NULL, NULL, NULL), PHGMG_OK);
    CHECK_RC(phgmg_ph_sparse_set_solver(sp, run ? PHGMG_SOLVER_BAND : PHGMG_SOLVER_SPARSE_LU, NULL), PHGMG_OK);
    CHECK(phgmg_ph_sparse_system(sp)->storage == (run ? PHGMG_BANDED : PHGMG_SPARSE));
    *(run ? rb : rs) = phgmg_ph_validate(phgmg_ph_sparse_system(sp), 0.0, NULL, NULL);
    if (!run) {
      CHECK_RC(phgmg_ph_validate(phgmg_ph_sparse_system(sp), 0.0, NULL, NULL), *rs); /* the same, not run again */
      if (withE && *rs == PHGMG_OK) { /* no algebraic line: phgmg_dae_create reuses the checks too */
        phgmg_dae *dae = NULL;
        CHECK_RC(phgmg_dae_create(&dae, phgmg_ph_sparse_system(sp), 0.0, NULL), PHGMG_OK);
        CHECK(dae && phgmg_dae_nalg(dae) == 0);
        phgmg_dae_destroy(dae);
      }
      *nrun = sp->vc->nrun;
    }
    phgmg_ph_sparse_destroy(sp);
  }
  sp4_free(&md);
}

TEST(test_sparse_perm_validate_closed_forms) {
  /* Expected results in closed form, with A the adjacency of the nx x nx
     lattice (eigenvalues 2 cos(pi i/(nx+1)) + 2 cos(pi k/(nx+1)), the
     smallest -4 cos(pi/(nx+1))) and the stiffness L + s I (L the graph
     Laplacian, smallest eigenvalue 0): E^T Q = blockdiag(L + s I, Mc) with
     Mc = I + c A on the momenta.
     - c = 0.1, s = 0.1: E^T Q positive definite, R = 0.05 I: valid;
     - c = 0.3 (1 - 1.2 cos(pi/33) < 0): E^T Q indefinite: EQ_NOT_PD;
     - s = -0.1: the stiffness has the eigenvalue -0.1: EQ_NOT_PD, and
       without E Q_NOT_PD;
     - R = 0.05 I + 0.1 A on the momenta (0.05 - 0.4 cos(pi/33) < 0): R
       not PSD (N = 2048 > the dense-eigenvalue limit: the sparse pivots).
     Each also with the columns of E and Q swapped in pairs (E P, Q P: E^T Q
     becomes P^T E^T Q P, the same inertia). The sparse checks give the
     band checks' result, and run once for two validations (and
     phgmg_dae_create of a valid model). */
  static const struct { double mc, onsite, rc; int withE; phgmg_result want; } cs[] = {
    {0.1, 0.1, 0.0, 1, PHGMG_OK},          {0.3, 0.1, 0.0, 1, PHGMG_ERR_EQ_NOT_PD},
    {0.1, -0.1, 0.0, 1, PHGMG_ERR_EQ_NOT_PD}, {0.1, -0.1, 0.0, 0, PHGMG_ERR_Q_NOT_PD},
    {0.1, 0.1, 0.1, 1, PHGMG_ERR_NOT_PSD},  {0.1, 0.1, 0.1, 0, PHGMG_ERR_NOT_PSD},
    {0.1, 0.1, 0.0, 0, PHGMG_OK}};
  int c, swap;
  for (c = 0; c < (int)(sizeof cs / sizeof cs[0]); ++c)
    for (swap = 0; swap < 1 + cs[c].withE; ++swap) {
      phgmg_result rs = PHGMG_ERR_INVALID_ARG, rb = PHGMG_ERR_INVALID_ARG;
      long nrun = 0;
      sp4_mc = cs[c].mc; sp4_onsite = cs[c].onsite; sp4_rc = cs[c].rc;
      sp4_validate(32, cs[c].withE, swap, &rs, &rb, &nrun);
      CHECK_RC(rs, cs[c].want);
      CHECK_RC(rb, cs[c].want);
      CHECK(nrun == 1);
    }
  sp4_mc = 0.1; sp4_onsite = 0.1; sp4_rc = 0.0;
}

TEST(test_sparse_perm_fallback_reported) {
  /* Springs so stiff (stiffness times 1e10) that sigma E is below the
     static-pivot threshold next to M on the momenta's rows: the checked
     pivots fail and the stepper switches to the band LU; the statistics
     say so (sparse_lu 0, band_fallback 1), and the states equal those of
     the band solver's run. The unscaled model keeps the sparse LU. */
  const int nx = 8, steps = 3, N = 2 * nx * nx;
  sp4_model md;
  double *x0 = (double *)calloc((size_t)N, sizeof(double)), *X[2], d = 0.0, xm = 0.0;
  int run, k;
  sp4_ks = 1e10;
  sp4_build(&md, nx, 0);
  sp4_ks = 1.0;
  for (run = 0; run < 2; ++run) {
    phgmg_ph_sparse *sp = NULL;
    phgmg_gl3_stats st;
    X[run] = (double *)malloc(sizeof(double) * (size_t)N * (steps + 1));
    CHECK_RC(phgmg_ph_sparse_create_e(&sp, N, 1, &md.M[0].A, &md.M[1].A, &md.M[2].A, &md.M[3].A, md.B, NULL, NULL,
                                      NULL), PHGMG_OK);
    CHECK_RC(phgmg_ph_sparse_set_solver(sp, run ? PHGMG_SOLVER_BAND : PHGMG_SOLVER_SPARSE_LU, NULL), PHGMG_OK);
    CHECK_RC(phgmg_simulate(phgmg_ph_sparse_system(sp), x0, 0.0, 0.1, steps, sp4_u, NULL, NULL, X[run], NULL, NULL,
                            &st, NULL, NULL), PHGMG_OK);
    if (!run) CHECK(st.sparse_lu == 0 && st.band_fallback == 1);
    else CHECK(st.sparse_lu == 0 && st.band_fallback == 0);
    phgmg_ph_sparse_destroy(sp);
  }
  {
    sp4_model m1;
    phgmg_ph_sparse *sp = NULL;
    phgmg_gl3_stats st;
    sp4_build(&m1, nx, 0);
    CHECK_RC(phgmg_ph_sparse_create_e(&sp, N, 1, &m1.M[0].A, &m1.M[1].A, &m1.M[2].A, &m1.M[3].A, m1.B, NULL, NULL,
                                      NULL), PHGMG_OK);
    CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_SPARSE_LU, NULL), PHGMG_OK);
    CHECK_RC(phgmg_simulate(phgmg_ph_sparse_system(sp), x0, 0.0, 0.1, steps, sp4_u, NULL, NULL, NULL, NULL, NULL,
                            &st, NULL, NULL), PHGMG_OK);
    CHECK(st.sparse_lu == 1 && st.band_fallback == 0);
    phgmg_ph_sparse_destroy(sp);
    sp4_free(&m1);
  }
  for (k = 0; k < N * (steps + 1); ++k) { d = fmax(d, fabs(X[0][k] - X[1][k])); xm = fmax(xm, fabs(X[1][k])); }
  CHECK(xm > 0.0);
  CHECK_LE(d, 1e-10 * xm);
  free(X[0]); free(X[1]); free(x0);
  sp4_free(&md);
}

/* The lattice with E and feedthrough P = p e_1 (the driven momentum), S = 1:
   validation and a run of steps steps on the solver given; outputs into Y. */
static phgmg_result sp4_feed(int nx, double pv, int solver, int steps, double *Y, phgmg_gl3_stats *st) {
  sp4_model md;
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_system sys;
  double *P, *Pi, *x0, S1 = 1.0;
  phgmg_result rc;
  sp4_build(&md, nx, 0);
  P = (double *)calloc((size_t)md.N, sizeof(double));
  Pi = (double *)calloc((size_t)md.N, sizeof(double));
  x0 = (double *)calloc((size_t)md.N, sizeof(double));
  P[1] = pv;
  CHECK_RC(phgmg_ph_sparse_create_e(&sp, md.N, 1, &md.M[0].A, &md.M[1].A, &md.M[2].A, &md.M[3].A, md.B, NULL, NULL,
                                    NULL), PHGMG_OK);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, solver, NULL), PHGMG_OK);
  CHECK_RC(phgmg_ph_sparse_to_banded_order(sp, 1, P, md.N, Pi, md.N), PHGMG_OK);
  sys = *phgmg_ph_sparse_system(sp);
  sys.P = Pi; sys.S = &S1;
  rc = phgmg_ph_validate(&sys, 0.0, NULL, NULL);
  if (rc == PHGMG_OK && Y)
    CHECK_RC(phgmg_simulate(&sys, x0, 0.0, 0.1, steps, sp4_u, NULL, NULL, NULL, Y, NULL, st, NULL, NULL), PHGMG_OK);
  phgmg_ph_sparse_destroy(sp);
  free(P); free(Pi); free(x0);
  sp4_free(&md);
  return rc;
}

TEST(test_sparse_perm_feedthrough) {
  /* Feedthrough on the sparse LU: P only changes the input matrix (B - P)
     and the outputs, not the stage matrices. [[R, P], [P^T, S]] with R =
     0.05 on the momenta, P = p e_1, S = 1 is PSD iff p^2 <= 0.05: p = 0.2
     valid, p = 0.3 not (PHGMG_ERR_FEEDTHROUGH), by the band solver's dense
     check (N = 512) and the sparse one, also above the dense limit (N = 2048,
     the sparse pivots; the band storage cannot check it there). The run
     with p = 0.2 takes the sparse LU throughout and its outputs equal the
     band solver's to 1e-10. */
  const int steps = 40;
  double Ys[41], Yb[41], d = 0.0, ym = 0.0;
  phgmg_gl3_stats ss, sb;
  int k;
  CHECK_RC(sp4_feed(16, 0.2, PHGMG_SOLVER_SPARSE_LU, steps, Ys, &ss), PHGMG_OK);
  CHECK_RC(sp4_feed(16, 0.2, PHGMG_SOLVER_BAND, steps, Yb, &sb), PHGMG_OK);
  CHECK(ss.sparse_lu == 1 && ss.band_fallback == 0 && sb.sparse_lu == 0);
  for (k = 0; k <= steps; ++k) { d = fmax(d, fabs(Ys[k] - Yb[k])); ym = fmax(ym, fabs(Yb[k])); }
  CHECK(ym > 0.0);
  CHECK_LE(d, 1e-10 * ym);
  CHECK_RC(sp4_feed(16, 0.3, PHGMG_SOLVER_SPARSE_LU, 0, NULL, NULL), PHGMG_ERR_FEEDTHROUGH);
  CHECK_RC(sp4_feed(16, 0.3, PHGMG_SOLVER_BAND, 0, NULL, NULL), PHGMG_ERR_FEEDTHROUGH);
  CHECK_RC(sp4_feed(32, 0.2, PHGMG_SOLVER_SPARSE_LU, 0, NULL, NULL), PHGMG_OK);
  CHECK_RC(sp4_feed(32, 0.3, PHGMG_SOLVER_SPARSE_LU, 0, NULL, NULL), PHGMG_ERR_FEEDTHROUGH);
}

TEST(test_sparse_perm_e_factor_solves) {
  /* The sparse LU of E with its columns swapped in pairs (zero diagonal;
     the matching restores it), as validation and reductions use it: x =
     E^{-1} b and E^{-T} b satisfy E x = b, E^T x = b to round-off
     (residuals by products with the CSC matrix, an independent
     computation), and the rcond estimate is the band LU's (both Hager's
     estimate of the same norm) within a factor 2. */
  sp4_model md;
  phgmg_ph_sparse *sp = NULL;
  phgmg_jr_factor *f = NULL;
  const phgmg_ph_system *sys;
  double *b, *x, *r, rs = 0.0, rb = 0.0, res, bn;
  int N, t, j, p;
  sp4_build(&md, 12, 1);
  N = md.N;
  CHECK_RC(phgmg_ph_sparse_create_e(&sp, N, 1, &md.M[0].A, &md.M[1].A, &md.M[2].A, &md.M[3].A, md.B, NULL, NULL,
                                    NULL), PHGMG_OK);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_SPARSE_LU, NULL), PHGMG_OK);
  sys = phgmg_ph_sparse_system(sp);
  CHECK_RC(phgmg__e_factor(sys, &f, &rs, NULL), PHGMG_OK);
  CHECK(f && f->sps != NULL && f->sps->cperm != NULL);
  b = (double *)malloc(sizeof(double) * (size_t)N); x = (double *)malloc(sizeof(double) * (size_t)N);
  r = (double *)malloc(sizeof(double) * (size_t)N);
  for (t = 0; t < 2 && f; ++t) {
    for (j = 0; j < N; ++j) b[j] = x[j] = sin(1.0 + 0.37 * j);
    phgmg_jr_solve(f, t ? 'T' : 'N', 1, x, N);
    for (j = 0; j < N; ++j) r[j] = -b[j];
    for (j = 0; j < N; ++j) /* r += E x (t = 0) or E^T x (t = 1) */
      for (p = sp->cp[3][j]; p < sp->cp[3][j + 1]; ++p) {
        if (!t) r[sp->ci[3][p]] += sp->cx[3][p] * x[j];
        else r[j] += sp->cx[3][p] * x[sp->ci[3][p]];
      }
    res = 0.0; bn = 0.0;
    for (j = 0; j < N; ++j) { res = fmax(res, fabs(r[j])); bn = fmax(bn, fabs(b[j])); }
    CHECK_LE(res, 1e-13 * bn);
  }
  phgmg_jr_factor_destroy(f);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_BAND, NULL), PHGMG_OK);
  f = NULL;
  CHECK_RC(phgmg__e_factor(phgmg_ph_sparse_system(sp), &f, &rb, NULL), PHGMG_OK);
  CHECK(f && f->sps == NULL);
  CHECK(rs > 0.0 && rb > 0.0);
  CHECK_LE(rs, 2.0 * rb);
  CHECK_LE(rb, 2.0 * rs);
  phgmg_jr_factor_destroy(f);
  phgmg_ph_sparse_destroy(sp);
  free(b); free(x); free(r);
  sp4_free(&md);
}

static double sp4_phi(int k, double v, void *user) { (void)k; (void)user; return cosh(v); }

TEST(test_sparse_perm_separable_coupling) {
  /* A separable term on a position (E's row: the identity's) is accepted; on
     a momentum (E's row holds the mass matrix's couplings to the
     neighbours) it is refused with PHGMG_ERR_E_COUPLED, by the sparse checks
     (one pass over E's entries) as by the band ones. */
  sp4_model md;
  int run, c;
  sp4_build(&md, 8, 0);
  for (run = 0; run < 2; ++run)
    for (c = 0; c < 2; ++c) {
      phgmg_ph_sparse *sp = NULL;
      phgmg_ph_system sys;
      const int idx = c ? 11 : 10;   /* the momentum, the position of mass 5 */
      CHECK_RC(phgmg_ph_sparse_create_e(&sp, md.N, 1, &md.M[0].A, &md.M[1].A, &md.M[2].A, &md.M[3].A, md.B, NULL,
                                        NULL, NULL), PHGMG_OK);
      CHECK_RC(phgmg_ph_sparse_set_solver(sp, run ? PHGMG_SOLVER_BAND : PHGMG_SOLVER_SPARSE_LU, NULL), PHGMG_OK);
      sys = *phgmg_ph_sparse_system(sp);
      sys.nl = PHGMG_NL_SEPARABLE;
      sys.phi = sys.dphi = sys.ddphi = sp4_phi;
      CHECK_RC(phgmg_ph_sparse_sep_idx(sp, 1, &idx, NULL, &sys), PHGMG_OK);
      CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), c ? PHGMG_ERR_E_COUPLED : PHGMG_OK);
      phgmg_ph_sparse_destroy(sp);
    }
  sp4_free(&md);
}

SUITE(sparse_perm) {
  RUN(test_sparse_perm_separable_coupling);
  RUN(test_sparse_perm_e_factor_solves);
  RUN(test_sparse_perm_feedthrough);
  RUN(test_sparse_perm_fallback_reported);
  RUN(test_sparse_perm_swapped_columns);
  RUN(test_sparse_perm_validate_closed_forms);
}
