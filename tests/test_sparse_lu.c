/* The sparse LU of the GL3 stage systems (phgmg.h >>sparse): scrambled 2-D and
   3-D mass-spring lattices simulated with the sparse LU against the band LU
   with partial pivoting (an independent solver of the same stage systems),
   linear and with an on-site cosh potential, unconnected parts, the
   band/sparse choice, forced choices, allocation failures. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"

/* A lattice nx x ny x nz of unit masses, unit springs between neighbours
   (along x only where xlinks, so that ny nz chains are unconnected parts),
   on-site springs 0.1, damping 0.05; state (q, p) per mass, scrambled by a
   random permutation. J, R, Q as CSC, B = the momentum of mass 0. */
typedef struct slu_lat {
  int N, nn;
  int *sc;               /* state index of (mass k, q: 0 / p: 1) = sc[2k + .] */
  int *cp[3], *ri[3];
  double *v[3];
  phgmg_csc M[3];        /* J, R, Q */
  double *B;
} slu_lat;

static void slu_lat_free(slu_lat *L) {
  int a;
  for (a = 0; a < 3; ++a) { free(L->cp[a]); free(L->ri[a]); free(L->v[a]); }
  free(L->sc); free(L->B);
  memset(L, 0, sizeof *L);
}

/* Dense N x N scratch into CSC (N is small in these tests). */
static void slu_to_csc(slu_lat *L, int a, const double *D) {
  int N = L->N, i, j, nz = 0;
  L->cp[a] = (int *)malloc(sizeof(int) * (size_t)(N + 1));
  for (j = 0; j < N; ++j) for (i = 0; i < N; ++i) nz += D[i + (size_t)j * N] != 0.0;
  L->ri[a] = (int *)malloc(sizeof(int) * (size_t)nz + 1);
  L->v[a] = (double *)malloc(sizeof(double) * (size_t)nz + 1);
  nz = 0;
  for (j = 0; j < N; ++j) {
    L->cp[a][j] = nz;
    for (i = 0; i < N; ++i)
      if (D[i + (size_t)j * N] != 0.0) { L->ri[a][nz] = i; L->v[a][nz] = D[i + (size_t)j * N]; ++nz; }
  }
  L->cp[a][N] = nz;
  L->M[a].n_rows = L->M[a].n_cols = N;
  L->M[a].colptr = L->cp[a]; L->M[a].rowidx = L->ri[a]; L->M[a].values = L->v[a];
}

static void slu_lat_build(slu_lat *L, int nx, int ny, int nz, int xlinks_only) {
  int N, k, x, y, z, i;
  double *D[3];
  memset(L, 0, sizeof *L);
  L->nn = nx * ny * nz;
  L->N = N = 2 * L->nn;
  L->sc = (int *)malloc(sizeof(int) * (size_t)N);
  for (i = 0; i < N; ++i) L->sc[i] = i;
  for (i = N - 1; i > 0; --i) {
    int j = (int)((th_rand() + 1.0) * 0.5 * (i + 1)), t;
    if (j > i) j = i;
    t = L->sc[i]; L->sc[i] = L->sc[j]; L->sc[j] = t;
  }
  for (k = 0; k < 3; ++k) D[k] = (double *)calloc((size_t)N * N, sizeof(double));
#define SLU_Q(n) L->sc[2 * (n)]
#define SLU_P(n) L->sc[2 * (n) + 1]
#define SLU_AT(Mx, r, c) Mx[(size_t)(r) + (size_t)(c) * (size_t)N]
  for (z = 0; z < nz; ++z)
    for (y = 0; y < ny; ++y)
      for (x = 0; x < nx; ++x) {
        int n = x + nx * (y + ny * z), nb[3], nbn = 0;
        if (x + 1 < nx) nb[nbn++] = n + 1;
        if (!xlinks_only && y + 1 < ny) nb[nbn++] = n + nx;
        if (!xlinks_only && z + 1 < nz) nb[nbn++] = n + nx * ny;
        SLU_AT(D[0], SLU_Q(n), SLU_P(n)) = 1.0;
        SLU_AT(D[0], SLU_P(n), SLU_Q(n)) = -1.0;
        SLU_AT(D[1], SLU_P(n), SLU_P(n)) = 0.05;
        SLU_AT(D[2], SLU_P(n), SLU_P(n)) = 1.0;
        SLU_AT(D[2], SLU_Q(n), SLU_Q(n)) += 0.1;
        for (i = 0; i < nbn; ++i) {
          SLU_AT(D[2], SLU_Q(n), SLU_Q(nb[i])) -= 1.0;
          SLU_AT(D[2], SLU_Q(nb[i]), SLU_Q(n)) -= 1.0;
          SLU_AT(D[2], SLU_Q(n), SLU_Q(n)) += 1.0;
          SLU_AT(D[2], SLU_Q(nb[i]), SLU_Q(nb[i])) += 1.0;
        }
      }
  for (k = 0; k < 3; ++k) { slu_to_csc(L, k, D[k]); free(D[k]); }
  L->B = (double *)calloc((size_t)N, sizeof(double));
  L->B[SLU_P(0)] = 1.0;
}

static void slu_u(double t, double *u, void *user) {
  const double a = user ? *(const double *)user : 1.0;
  u[0] = a * (0.1 * sin(t) + 0.05 * sin(3.1 * t));
}

/* Simulate nsteps steps from rest with solver forced (the cosh potential on
   every position when cosh), outputs into Y (nsteps + 1). */
static phgmg_result slu_run(const slu_lat *L, int solver, int cosh_pot, int nsteps, double *Y,
                            phgmg_ph_sparse_info *inf, phgmg_gl3_stats *st) {
  static const double expo[4] = {0.5, 1.0, 0.5, -1.0}, poly[1] = {-1.0};
  double amp = cosh_pot ? 400.0 : 1.0; /* the nonlinear runs far from the linear regime */
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_system sys;
  double *x0 = (double *)calloc((size_t)L->N, sizeof(double));
  int *idx = (int *)malloc(sizeof(int) * (size_t)L->nn), k;
  phgmg_result rc = phgmg_ph_sparse_create(&sp, L->N, 1, &L->M[0], &L->M[1], &L->M[2], L->B, NULL, inf, NULL);
  if (rc == PHGMG_OK && solver) rc = phgmg_ph_sparse_set_solver(sp, solver, inf);
  if (rc == PHGMG_OK) {
    sys = *phgmg_ph_sparse_system(sp);
    if (cosh_pot) {
      for (k = 0; k < L->nn; ++k) idx[k] = L->sc[2 * k];
      sys.nl = PHGMG_NL_SEPARABLE;
      sys.poly_deg = 0; sys.poly = poly; sys.nexp = 2; sys.expo = expo;
      rc = phgmg_ph_sparse_sep_idx(sp, L->nn, idx, NULL, &sys);
    }
    if (rc == PHGMG_OK)
      rc = phgmg_simulate(&sys, x0, 0.0, 0.1, nsteps, slu_u, &amp, NULL, NULL, Y, NULL, st, NULL, NULL);
  }
  phgmg_ph_sparse_destroy(sp);
  free(x0);
  free(idx);
  return rc;
}

static double slu_rel(int n, const double *a, const double *ref) {
  double d = 0.0, m = 0.0;
  int i;
  for (i = 0; i < n; ++i) { d = PHGMG__MAX(d, fabs(a[i] - ref[i])); m = PHGMG__MAX(m, fabs(ref[i])); }
  return m > 0.0 ? d / m : d;
}

/* Sparse LU and band LU (partial pivoting) give the same trajectory: 2-D and
   3-D lattices, linear and with the cosh potential (refactorizations). */
TEST(test_sparse_lu_lattices) {
  static const int dims[3][3] = {{10, 20, 1}, {4, 5, 6}, {3, 40, 1}};
  int c, nl;
  for (c = 0; c < 3; ++c)
    for (nl = 0; nl < 2; ++nl) {
      slu_lat L;
      const int ns = 150;
      double Ys[151], Yb[151];
      phgmg_ph_sparse_info is, ib;
      phgmg_gl3_stats ss, sb;
      slu_lat_build(&L, dims[c][0], dims[c][1], dims[c][2], 0);
      CHECK_RC(slu_run(&L, PHGMG_SOLVER_SPARSE_LU, nl, ns, Ys, &is, &ss), PHGMG_OK);
      CHECK_RC(slu_run(&L, PHGMG_SOLVER_BAND, nl, ns, Yb, &ib, &sb), PHGMG_OK);
      CHECK(is.solver == PHGMG_SOLVER_SPARSE_LU && ib.solver == PHGMG_SOLVER_BAND);
      CHECK(is.supernodes > 0 && is.lu_sparse > 0.0);
      CHECK_LE(slu_rel(ns + 1, Ys, Yb), 1e-11);
      CHECK(Yb[ns] != 0.0);
      /* the same Newton work: the solves are exact either way */
      CHECK(ss.newton_iters == sb.newton_iters && ss.factorizations == sb.factorizations);
      if (nl) CHECK(ss.factorizations > 1); /* the nonlinear runs refactor */
      slu_lat_free(&L);
    }
}

/* Unconnected parts (chains side by side, scrambled): the ordering's
   component loop; the result again equals the band LU's. */
TEST(test_sparse_lu_components) {
  slu_lat L;
  const int ns = 60;
  double Ys[61], Yb[61];
  phgmg_ph_sparse_info is, ib;
  phgmg_gl3_stats ss, sb;
  slu_lat_build(&L, 6, 30, 1, 1);
  CHECK_RC(slu_run(&L, PHGMG_SOLVER_SPARSE_LU, 0, ns, Ys, &is, &ss), PHGMG_OK);
  CHECK_RC(slu_run(&L, PHGMG_SOLVER_BAND, 0, ns, Yb, &ib, &sb), PHGMG_OK);
  CHECK_LE(slu_rel(ns + 1, Ys, Yb), 1e-11);
  slu_lat_free(&L);
}

/* The automatic choice: a 2-D lattice goes sparse (its factor far smaller than
   the band's), a chain stays banded without analysis. */
TEST(test_sparse_lu_choice) {
  slu_lat L;
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_sparse_info inf;
  slu_lat_build(&L, 16, 16, 1, 0);
  CHECK_RC(phgmg_ph_sparse_create(&sp, L.N, 1, &L.M[0], &L.M[1], &L.M[2], L.B, NULL, &inf, NULL), PHGMG_OK);
  CHECK(inf.solver == PHGMG_SOLVER_SPARSE_LU);
  CHECK(2.0 * inf.lu_sparse < inf.lu_band && inf.flops_sparse < inf.flops_band);
  CHECK(inf.kl >= inf.kb && inf.ku >= inf.kb);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, 7, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_ph_sparse_set_solver(NULL, PHGMG_SOLVER_AUTO, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_BAND, &inf), PHGMG_OK);
  CHECK(inf.solver == PHGMG_SOLVER_BAND);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_AUTO, &inf), PHGMG_OK);
  CHECK(inf.solver == PHGMG_SOLVER_SPARSE_LU);
  phgmg_ph_sparse_destroy(sp);
  slu_lat_free(&L);
  slu_lat_build(&L, 40, 1, 1, 0); /* a chain: kb small */
  CHECK_RC(phgmg_ph_sparse_create(&sp, L.N, 1, &L.M[0], &L.M[1], &L.M[2], L.B, NULL, &inf, NULL), PHGMG_OK);
  CHECK(inf.solver == PHGMG_SOLVER_BAND && inf.lu_sparse == 0.0 && inf.kb <= PHGMG_SPARSE_MIN_KB);
  phgmg_ph_sparse_destroy(sp);
  slu_lat_free(&L);
}

/* Allocation failures anywhere in the analysis and in the stepper's factors:
   a clean PHGMG_ERR_NOMEM, no leak (ASan), then success. */
static int slu_fail_after;
static void *slu_alloc(size_t n, void *u) { (void)u; return slu_fail_after-- > 0 ? malloc(n) : NULL; }
static void slu_free(void *p, void *u) { (void)u; free(p); }
TEST(test_sparse_lu_alloc_failures) {
  slu_lat L;
  phgmg_allocator a = {slu_alloc, slu_free, NULL};
  int k, ok = 0;
  slu_lat_build(&L, 12, 12, 1, 0);
  for (k = 0; k < 200 && !ok; ++k) {
    phgmg_ph_sparse *sp = NULL;
    phgmg_gl3 *g = NULL;
    phgmg_result rc;
    slu_fail_after = k;
    rc = phgmg_ph_sparse_create(&sp, L.N, 1, &L.M[0], &L.M[1], &L.M[2], L.B, NULL, NULL, &a);
    if (rc == PHGMG_OK) rc = phgmg_gl3_create(&g, phgmg_ph_sparse_system(sp), 0.1, NULL, &a);
    if (rc == PHGMG_OK) {
      double x[288];
      memset(x, 0, sizeof x);
      CHECK(L.N == 288);
      rc = phgmg_gl3_step(g, 0.0, x, slu_u, NULL, NULL);
      if (rc == PHGMG_OK) ok = 1;
    }
    if (!ok) CHECK_RC(rc, PHGMG_ERR_NOMEM);
    phgmg_gl3_destroy(g);
    phgmg_ph_sparse_destroy(sp);
  }
  CHECK(ok && k > 20);
  slu_lat_free(&L);
}

SUITE(sparse_lu) {
  RUN(test_sparse_lu_lattices);
  RUN(test_sparse_lu_components);
  RUN(test_sparse_lu_choice);
  RUN(test_sparse_lu_alloc_failures);
}
