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

/* A random sparse port-Hamiltonian model (not bipartite: J and Q have
   triangles), N states, in the slu_lat container (no masses). */
static void slu_random_build(slu_lat *L, int N) {
  int i, j, k;
  double *D[3];
  memset(L, 0, sizeof *L);
  L->N = N;
  for (k = 0; k < 3; ++k) D[k] = (double *)calloc((size_t)N * N, sizeof(double));
  for (j = 0; j < N; ++j) {
    D[2][j + (size_t)j * N] = 2.0 + th_rand();
    if (j % 3 == 0) D[1][j + (size_t)j * N] = 0.2 + 0.1 * th_rand();
    for (i = 0; i < j; ++i) {
      double r = 0.5 * (th_rand() + 1.0);
      if (r < 0.06) { double a = th_rand(); D[0][i + (size_t)j * N] = a; D[0][j + (size_t)i * N] = -a; }
      else if (r < 0.09) { double a = 0.3 * th_rand(); D[2][i + (size_t)j * N] = a; D[2][j + (size_t)i * N] = a; }
    }
  }
  for (k = 0; k < 3; ++k) { slu_to_csc(L, k, D[k]); free(D[k]); }
  L->B = (double *)calloc((size_t)N, sizeof(double));
  L->B[0] = 1.0;
}

/* Dense Gaussian elimination with partial pivoting of the real form
   [Ar -Ai; Ai Ar] [xr; xi] = [br; bi] (n complex unknowns): the independent
   reference for the sparse solves. A (2n x 2n) and b (2n) are overwritten. */
static void slu_dense_solve(int n2, double *A, double *b) {
  int k, i, j;
  for (k = 0; k < n2; ++k) {
    int p = k;
    for (i = k + 1; i < n2; ++i) if (fabs(A[i + (size_t)k * n2]) > fabs(A[p + (size_t)k * n2])) p = i;
    for (j = 0; j < n2; ++j) { double t = A[k + (size_t)j * n2]; A[k + (size_t)j * n2] = A[p + (size_t)j * n2]; A[p + (size_t)j * n2] = t; }
    { double t = b[k]; b[k] = b[p]; b[p] = t; }
    for (i = k + 1; i < n2; ++i) {
      double f = A[i + (size_t)k * n2] / A[k + (size_t)k * n2];
      if (f == 0.0) continue;
      for (j = k; j < n2; ++j) A[i + (size_t)j * n2] -= f * A[k + (size_t)j * n2];
      b[i] -= f * b[k];
    }
  }
  for (k = n2 - 1; k >= 0; --k) {
    double sm = b[k];
    for (j = k + 1; j < n2; ++j) sm -= A[k + (size_t)j * n2] * b[j];
    b[k] = sm / A[k + (size_t)k * n2];
  }
}

/* The sparse solve of K = sigma I - (J - R)(Q + diag(dd)) (internal order)
   against the dense solve, condensed (condense = 1) and not (0), real and
   complex shift; returns the relative difference of the solutions. */
static double slu_solve_check(const slu_lat *L, int condense, double sr, double si, int with_dd, int *na) {
  const int N = L->N, N2 = 2 * N;
  phgmg_ph_sparse *sp = NULL;
  phgmg__spsym *S = NULL;
  phgmg__spnum F;
  double *Ju = (double *)calloc((size_t)N * N * 3, sizeof(double)), *A = (double *)calloc((size_t)N2 * N2, sizeof(double));
  double *Mx, *w = (double *)malloc(sizeof(double) * (size_t)N), *dd = (double *)malloc(sizeof(double) * (size_t)N);
  double *x = (double *)malloc(sizeof(double) * (size_t)N2), *b = (double *)malloc(sizeof(double) * (size_t)N2), err = 1.0;
  int i, j, k, a, cp = si != 0.0;
  *na = -1;
  for (a = 0; a < 3; ++a)
    for (j = 0; j < N; ++j)
      for (k = L->M[a].colptr[j]; k < L->M[a].colptr[j + 1]; ++k)
        Ju[(size_t)a * N * N + L->M[a].rowidx[k] + (size_t)j * N] = L->M[a].values[k];
  for (i = 0; i < N; ++i) dd[i] = with_dd ? 0.5 + 0.5 * th_rand() : 0.0;
  if (phgmg_ph_sparse_create(&sp, N, 1, &L->M[0], &L->M[1], &L->M[2], L->B, NULL, NULL, NULL) != PHGMG_OK ||
      phgmg__spsym_create_sp(&S, sp, condense) != PHGMG_OK ||
      phgmg__spnum_alloc(NULL, S, cp, &F) != PHGMG_OK)
    goto done;
  *na = S->na;
  Mx = (double *)malloc(sizeof(double) * (size_t)S->k_p[N] + 1);
  phgmg__sp_stage_values(S, with_dd ? dd : NULL, Mx, w);
  phgmg__sp_factor(S, &F, Mx, sr, si, PHGMG_SPARSE_PIVTOL);
  free(Mx);
  /* dense K in the internal order: K(i, j) = sigma delta - sum_k (J - R)(pi, pk) (Q(pk, pj) + dd_j delta_kj) */
  for (i = 0; i < N; ++i)
    for (j = 0; j < N; ++j) {
      int pi = sp->perm[i], pj = sp->perm[j];
      double v = i == j ? sr : 0.0;
      for (k = 0; k < N; ++k) {
        int pk = sp->perm[k];
        double jr = Ju[pi + (size_t)pk * N] - Ju[(size_t)N * N + pi + (size_t)pk * N];
        double q = Ju[(size_t)2 * N * N + pk + (size_t)pj * N] + (k == j ? dd[j] : 0.0);
        v -= jr * q;
      }
      A[i + (size_t)j * N2] = v; A[i + N + (size_t)(j + N) * N2] = v;
      if (i == j) { A[i + (size_t)(j + N) * N2] = -si; A[i + N + (size_t)j * N2] = si; }
    }
  for (i = 0; i < N2; ++i) b[i] = cp || i < N ? th_rand() : 0.0;
  for (i = 0; i < N; ++i) { x[cp ? 2 * i : i] = b[i]; if (cp) x[2 * i + 1] = b[N + i]; }
  phgmg__sp_solve(S, &F, x);
  slu_dense_solve(N2, A, b);
  {
    double d = 0.0, m = 0.0;
    for (i = 0; i < N; ++i) {
      d = PHGMG__MAX(d, fabs(x[cp ? 2 * i : i] - b[i]));
      if (cp) d = PHGMG__MAX(d, fabs(x[2 * i + 1] - b[N + i]));
      m = PHGMG__MAX(m, PHGMG__MAX(fabs(b[i]), fabs(b[N + i])));
    }
    err = d / m;
  }
  phgmg__spnum_free(NULL, &F);
done:
  phgmg__spsym_free(NULL, S);
  phgmg_ph_sparse_destroy(sp);
  free(Ju); free(A); free(w); free(dd); free(x); free(b);
  return err;
}

/* Condensing an independent set first (Schur complement of a diagonal
   block): every solve equals the dense solve, real and complex shifts, with
   and without the Hessian diagonal; a mass-spring lattice condenses one
   whole side (its graph is bipartite), a random model part of its states. */
TEST(test_sparse_lu_condense) {
  slu_lat L;
  int m, c, z, h, na;
  for (m = 0; m < 2; ++m) {
    if (m == 0) slu_lat_build(&L, 5, 6, 1, 0);
    else slu_random_build(&L, 50);
    for (c = 0; c < 2; ++c)
      for (z = 0; z < 2; ++z)
        for (h = 0; h < 2; ++h) {
          CHECK_LE(slu_solve_check(&L, c, 3.7, z ? 1.9 : 0.0, h, &na), 1e-12);
          if (c == 0) CHECK(na == 0);
          else if (m == 0) CHECK(na == L.nn);
          else CHECK(na > 0 && na < L.N / 2);
        }
    slu_lat_free(&L);
  }
  { /* no couplings at all (M diagonal): nothing left to factor if every
       state were condensed, so none is */
    double *D[3];
    int k, i;
    memset(&L, 0, sizeof L);
    L.N = 6;
    for (k = 0; k < 3; ++k) D[k] = (double *)calloc(36, sizeof(double));
    for (i = 0; i < 6; ++i) { D[1][i * 7] = 0.1 * (i % 2); D[2][i * 7] = 1.0 + i; }
    for (k = 0; k < 3; ++k) { slu_to_csc(&L, k, D[k]); free(D[k]); }
    L.B = (double *)calloc(6, sizeof(double));
    L.B[0] = 1.0;
    CHECK_LE(slu_solve_check(&L, 1, 3.7, 1.9, 1, &na), 1e-14);
    CHECK(na == 0);
    slu_lat_free(&L);
  }
  { /* the automatic choice condenses the lattice (smaller factor) */
    phgmg_ph_sparse *sp = NULL;
    phgmg_ph_sparse_info inf;
    slu_lat_build(&L, 16, 16, 1, 0);
    CHECK_RC(phgmg_ph_sparse_create(&sp, L.N, 1, &L.M[0], &L.M[1], &L.M[2], L.B, NULL, &inf, NULL), PHGMG_OK);
    CHECK(inf.solver == PHGMG_SOLVER_SPARSE_LU && inf.condensed == L.nn);
    phgmg_ph_sparse_destroy(sp);
    slu_lat_free(&L);
  }
}

static double max_abs_x(const double *x, size_t n) {
  double m = 0.0;
  size_t i;
  for (i = 0; i < n; ++i) m = PHGMG__MAX(m, fabs(x[i]));
  return m;
}

/* Counting shifted solver (dense LU of sigma I - (J - R) Q) for the reuse test. */
typedef struct slu_cb {
  int N;
  const double *JR, *Q;   /* dense, J - R and Q */
  double *K1, *K2;
  int *ip1, *ip2;
  long nfactor;
} slu_cb;
static phgmg_result slu_cb_factor(double sr, double si, const double *x, void *user) {
  slu_cb *c = (slu_cb *)user;
  int N = c->N, i, j, k;
  (void)x;
  c->nfactor++;
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) {
      double v = i == j ? sr : 0.0;
      for (k = 0; k < N; ++k) v -= c->JR[i + (size_t)k * N] * c->Q[k + (size_t)j * N];
      if (si == 0.0) c->K1[i + (size_t)j * N] = v;
      else { c->K2[2 * (i + (size_t)j * N)] = v; c->K2[2 * (i + (size_t)j * N) + 1] = i == j ? si : 0.0; }
    }
  return si == 0.0 ? phgmg_lu_factor(N, c->K1, N, c->ip1) : phgmg_zlu_factor(N, c->K2, N, c->ip2);
}
static void slu_cb_solve(double sr, double si, double *rhs, void *user) {
  slu_cb *c = (slu_cb *)user;
  (void)sr;
  if (si == 0.0) phgmg_lu_solve('N', c->N, c->K1, c->N, c->ip1, 1, rhs, c->N);
  else phgmg_zlu_solve(c->N, c->K2, c->N, c->ip2, 1, rhs, c->N);
}

/* The runs of phgmg_simulate_inputs share one stepper while dt stays the
   same: a linear model is factored once (one real and one complex
   factorization) for three runs, again when dt changes; the trajectories
   equal those of separate phgmg_simulate calls bit for bit. */
TEST(test_sparse_lu_reuse_runs) {
  slu_lat L;
  slu_cb cb;
  phgmg_ph_system sys;
  phgmg_gl3_opts o;
  phgmg_run runs[3];
  double *D, *JR, *X, *Xs, x0[40], z[40], amp[3] = {1.0, 0.5, 2.0};
  int N, i, j, a, k, c0;
  slu_lat_build(&L, 4, 5, 1, 0);
  N = L.N;
  CHECK(N == 40);
  D = (double *)calloc((size_t)3 * N * N, sizeof(double)); /* dense J, R, Q */
  JR = (double *)malloc(sizeof(double) * (size_t)N * N);
  for (a = 0; a < 3; ++a)
    for (j = 0; j < N; ++j)
      for (k = L.M[a].colptr[j]; k < L.M[a].colptr[j + 1]; ++k)
        D[(size_t)a * N * N + L.M[a].rowidx[k] + (size_t)j * N] = L.M[a].values[k];
  for (i = 0; i < N * N; ++i) JR[i] = D[i] - D[(size_t)N * N + i];
  memset(&cb, 0, sizeof cb);
  cb.N = N; cb.JR = JR; cb.Q = D + (size_t)2 * N * N;
  cb.K1 = (double *)malloc(sizeof(double) * (size_t)N * N);
  cb.K2 = (double *)malloc(2 * sizeof(double) * (size_t)N * N);
  cb.ip1 = (int *)malloc(sizeof(int) * (size_t)N);
  cb.ip2 = (int *)malloc(sizeof(int) * (size_t)N);
  memset(&sys, 0, sizeof sys);
  sys.N = N; sys.m = 1; sys.storage = PHGMG_DENSE;
  sys.J = D; sys.R = D + (size_t)N * N; sys.Q = cb.Q; sys.B = L.B;
  sys.shifted_factor = slu_cb_factor; sys.shifted_solve = slu_cb_solve; sys.shifted_user = &cb;
  memset(&o, 0, sizeof o);
  o.no_step_map = 1;
  for (i = 0; i < N; ++i) { x0[i] = 0.01 * (i % 7); z[i] = 0.0; }
  memset(runs, 0, sizeof runs);
  for (k = 0; k < 3; ++k) {
    runs[k].x0 = k == 1 ? x0 : NULL; runs[k].t0 = 0.5 * k; runs[k].dt = 0.1;
    runs[k].nsteps = 30 + 5 * k; runs[k].u = slu_u; runs[k].user = &amp[k];
  }
  X = (double *)malloc(sizeof(double) * (size_t)N * 120);
  Xs = (double *)malloc(sizeof(double) * (size_t)N * 120);
  CHECK_RC(phgmg_simulate_inputs(&sys, 3, runs, &o, X, N, NULL, NULL, NULL), PHGMG_OK);
  CHECK(cb.nfactor == 2);
  for (k = 0, c0 = 0; k < 3; ++k) { /* separately: each call factors */
    long before = cb.nfactor;
    CHECK_RC(phgmg_simulate(&sys, runs[k].x0 ? runs[k].x0 : z, runs[k].t0, runs[k].dt, runs[k].nsteps, slu_u,
                            &amp[k], &o, Xs + (size_t)c0 * N, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
    CHECK(cb.nfactor == before + 2);
    c0 += runs[k].nsteps + 1;
  }
  CHECK(c0 == 108);
  CHECK(memcmp(X, Xs, sizeof(double) * (size_t)N * (size_t)c0) == 0);
  CHECK(max_abs_x(X + (size_t)N * 31, (size_t)N * 77) > 1e-3);
  cb.nfactor = 0;
  runs[2].dt = 0.05; /* a new dt: a new stepper */
  CHECK_RC(phgmg_simulate_inputs(&sys, 3, runs, &o, X, N, NULL, NULL, NULL), PHGMG_OK);
  CHECK(cb.nfactor == 4);
  free(D); free(JR); free(X); free(Xs); free(cb.K1); free(cb.K2); free(cb.ip1); free(cb.ip2);
  slu_lat_free(&L);
}

/* ---- SPARSE storage: no band copy ---------------------------------------------------- */
/* An allocator that counts the bytes it holds (a size header per block). */
typedef struct slu_count { double live, peak; } slu_count;
static void *slu_count_alloc(size_t n, void *user) {
  slu_count *c = (slu_count *)user;
  double *p = (double *)malloc(n + sizeof(double));
  if (!p) return NULL;
  p[0] = (double)n;
  c->live += (double)n;
  if (c->live > c->peak) c->peak = c->live;
  return p + 1;
}
static void slu_count_free(void *ptr, void *user) {
  double *p = (double *)ptr;
  if (!p) return;
  ((slu_count *)user)->live -= p[-1];
  free(p - 1);
}

TEST(test_sparse_storage_no_band) {
  /* The object of a lattice that chose the sparse LU holds its matrices as
     CSC and no band copy: the bytes it holds, counted by its allocator, stay
     below one band matrix ((2 kb + 1) N doubles; the band path held three);
     the band solver makes the copies, the sparse one frees them again. */
  slu_lat L;
  slu_count cnt = {0.0, 0.0};
  phgmg_allocator al;
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_sparse_info inf;
  double band1;
  al.alloc = slu_count_alloc; al.free = slu_count_free; al.user = &cnt;
  slu_lat_build(&L, 24, 24, 1, 0);
  CHECK_RC(phgmg_ph_sparse_create(&sp, L.N, 1, &L.M[0], &L.M[1], &L.M[2], L.B, NULL, &inf, &al), PHGMG_OK);
  band1 = 8.0 * (2.0 * inf.kb + 1.0) * L.N;
  CHECK(inf.solver == PHGMG_SOLVER_SPARSE_LU && inf.band_copy == 0);
  CHECK(phgmg_ph_sparse_system(sp)->storage == PHGMG_SPARSE);
  CHECK_LE(cnt.live, band1);
  CHECK_LE(cnt.peak, band1);                 /* not even for a while */
  CHECK(inf.bytes > 0.5 * cnt.live && inf.bytes < 1.5 * cnt.live); /* the report: what it holds */
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_BAND, &inf), PHGMG_OK);
  CHECK(inf.band_copy == 1 && phgmg_ph_sparse_system(sp)->storage == PHGMG_BANDED);
  CHECK(cnt.live >= 3.0 * band1);
  CHECK(inf.bytes > 0.5 * cnt.live && inf.bytes < 1.5 * cnt.live);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_AUTO, &inf), PHGMG_OK);
  CHECK(inf.band_copy == 0 && phgmg_ph_sparse_system(sp)->storage == PHGMG_SPARSE);
  CHECK_LE(cnt.live, band1);
  phgmg_ph_sparse_destroy(sp);
  CHECK(cnt.live == 0.0);
  slu_lat_free(&L);
}

TEST(test_sparse_storage_equals_band) {
  /* The same lattice with SPARSE storage (sparse LU) and with BANDED storage
     (band LU with partial pivoting, an independent solver): validation,
     J - R solves, trajectories and a GMG-POD reduction agree to 1e-10. */
  slu_lat L;
  phgmg_ph_sparse *sp[2] = {NULL, NULL};
  phgmg_ph_sparse_info inf;
  const int ns = 201;
  double *X[2], *Y[2], *YR[2], rc_v[2], *x0, *b, *x, *r1, *r2, res = 0.0, bn = 0.0;
  int run, i;
  slu_lat_build(&L, 12, 12, 1, 0);
  x0 = (double *)calloc((size_t)L.N, sizeof(double));
  b = (double *)malloc(sizeof(double) * (size_t)L.N); x = (double *)malloc(sizeof(double) * (size_t)L.N);
  r1 = (double *)malloc(sizeof(double) * (size_t)L.N); r2 = (double *)malloc(sizeof(double) * (size_t)L.N);
  for (run = 0; run < 2; ++run) {
    phgmg_reduce_opts o;
    phgmg_reduced *red = NULL;
    const phgmg_ph_system *sys;
    phgmg_jr_factor *f = NULL;
    double xr0[16];
    X[run] = (double *)malloc(sizeof(double) * (size_t)L.N * ns);
    Y[run] = (double *)malloc(sizeof(double) * ns);
    YR[run] = (double *)malloc(sizeof(double) * ns);
    CHECK_RC(phgmg_ph_sparse_create(&sp[run], L.N, 1, &L.M[0], &L.M[1], &L.M[2], L.B, NULL, &inf, NULL), PHGMG_OK);
    if (run) CHECK_RC(phgmg_ph_sparse_set_solver(sp[run], PHGMG_SOLVER_BAND, &inf), PHGMG_OK);
    sys = phgmg_ph_sparse_system(sp[run]);
    CHECK(sys->storage == (run ? PHGMG_BANDED : PHGMG_SPARSE));
    CHECK_RC(phgmg_ph_validate(sys, 0.0, &rc_v[run], NULL), PHGMG_OK);
    /* (J - R) x = b by the factor, checked by the products J x - R x */
    CHECK_RC(phgmg_jr_factor_create(&f, sys, NULL, NULL), PHGMG_OK);
    for (i = 0; i < L.N; ++i) { b[i] = th_rand(); x[i] = b[i]; }
    if (f) phgmg_jr_solve(f, 'N', 1, x, L.N);
    phgmg_ph_apply(sys, 'J', 1, x, L.N, r1, L.N);
    phgmg_ph_apply(sys, 'R', 1, x, L.N, r2, L.N);
    for (i = 0; i < L.N; ++i) { res = fmax(res, fabs(r1[i] - r2[i] - b[i])); bn = fmax(bn, fabs(b[i])); }
    phgmg_jr_factor_destroy(f);
    CHECK_RC(phgmg_simulate(sys, x0, 0.0, 0.1, ns - 1, slu_u, NULL, NULL, X[run], Y[run], NULL, NULL, NULL, NULL),
             PHGMG_OK);
    phgmg_reduce_opts_default(&o);
    o.method = PHGMG_METHOD_GMG_POD;
    o.r = 12;
    CHECK_RC(phgmg_reduce(&red, sys, X[run], L.N, ns, &o, NULL, NULL), PHGMG_OK);
    if (red) {
      phgmg_reduced_restrict(red, x0, xr0);
      CHECK_RC(phgmg_reduced_simulate(red, xr0, 0.0, 0.1, ns - 1, slu_u, NULL, 1e-12, 30, NULL, YR[run], NULL, NULL,
                                      NULL), PHGMG_OK);
    }
    phgmg_reduced_destroy(red);
  }
  CHECK_LE(res, 1e-12 * bn);
  CHECK(rc_v[0] > 0.1 && rc_v[1] > 0.1); /* J - R is well conditioned here (block diagonal, R small) */
  CHECK_LE(slu_rel(L.N * ns, X[0], X[1]), 1e-10);
  CHECK_LE(slu_rel(ns, Y[0], Y[1]), 1e-10);
  CHECK_LE(slu_rel(ns, YR[0], YR[1]), 1e-10);
  CHECK(fabs(Y[1][ns - 1]) > 0.0);
  for (run = 0; run < 2; ++run) { phgmg_ph_sparse_destroy(sp[run]); free(X[run]); free(Y[run]); free(YR[run]); }
  free(x0); free(b); free(x); free(r1); free(r2);
  slu_lat_free(&L);
}

TEST(test_sparse_storage_checks) {
  /* Definiteness through the sparse LU's pivots (phgmg__sp_pd) against closed
     forms: the 1-D Laplacian tridiag(-1, 2, -1) of order n has eigenvalues
     2 - 2 cos(k pi / (n + 1)), so A + c I is definite exactly for c > -lambda_1;
     then validation of a SPARSE system with a Q that has a negative diagonal
     entry (e^T Q e < 0: not definite), and the refusals of the SPARSE kind. */
  const int n = 200;
  const double pi = 3.14159265358979323846, l1 = 2.0 - 2.0 * cos(pi / (n + 1)), l2 = 2.0 - 2.0 * cos(2.0 * pi / (n + 1));
  int *cp = (int *)malloc(sizeof(int) * (n + 1)), *ci = (int *)malloc(sizeof(int) * 3 * n), j, nz = 0;
  double *cx = (double *)malloc(sizeof(double) * 3 * n);
  slu_lat L;
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_system sys;
  for (j = 0; j < n; ++j) {
    cp[j] = nz;
    if (j > 0) { ci[nz] = j - 1; cx[nz++] = -1.0; }
    ci[nz] = j; cx[nz++] = 2.0;
    if (j + 1 < n) { ci[nz] = j + 1; cx[nz++] = -1.0; }
  }
  cp[n] = nz;
  CHECK(phgmg__sp_pd(n, cp, ci, cx, 0.0, NULL) == 1);
  CHECK(phgmg__sp_pd(n, cp, ci, cx, -0.5 * l1, NULL) == 1);
  CHECK(phgmg__sp_pd(n, cp, ci, cx, -0.5 * (l1 + l2), NULL) == 0);
  CHECK(phgmg__sp_pd(n, cp, ci, cx, -3.0, NULL) != 1); /* 0, or 2: undecided (large growth) */
  free(cp); free(ci); free(cx);
  slu_lat_build(&L, 14, 14, 1, 0);
  for (j = L.M[2].colptr[L.sc[0]]; j < L.M[2].colptr[L.sc[0] + 1]; ++j)
    if (L.M[2].rowidx[j] == L.sc[0]) L.v[2][j] = -1.0; /* Q(q_0, q_0) < 0 */
  CHECK_RC(phgmg_ph_sparse_create(&sp, L.N, 1, &L.M[0], &L.M[1], &L.M[2], L.B, NULL, NULL, NULL), PHGMG_OK);
  sys = *phgmg_ph_sparse_system(sp);
  CHECK(sys.storage == PHGMG_SPARSE);
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_ERR_Q_NOT_PD);
  sys.nl = PHGMG_NL_GENERAL;  /* the band Hessian of a GENERAL part: the band solver's storage */
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_ERR_UNSUPPORTED);
  sys = *phgmg_ph_sparse_system(sp);
  sys.Q = sys.J;               /* not the object's own matrices */
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  phgmg_ph_sparse_destroy(sp);
  slu_lat_free(&L);
}

/* ---- descriptor models: sigma E + M on the sparse LU ------------------------------- */
/* A consistent-mass-like E = blockdiag(I on the positions, Mc on the
   momenta) of an nx x ny lattice built by slu_lat_build: Mc(n, n) = 1,
   Mc(n, k) = 0.1 for neighbours (diagonally dominant: SPD), scrambled with
   the lattice's states. E^T Q = blockdiag(K, Mc) is symmetric. */
typedef struct slu_mass { int *cp, *ri; double *v; phgmg_csc E; } slu_mass;
static void slu_mass_build(slu_mass *m, const slu_lat *L, int nx, int ny) {
  const int N = L->N;
  int n, x, y, i, j, nz = 0;
  double *D = (double *)calloc((size_t)N * N, sizeof(double));
  for (y = 0; y < ny; ++y)
    for (x = 0; x < nx; ++x) {
      int nb[2], nbn = 0;
      n = x + nx * y;
      if (x + 1 < nx) nb[nbn++] = n + 1;
      if (y + 1 < ny) nb[nbn++] = n + nx;
      D[(size_t)L->sc[2 * n] * (N + 1)] = 1.0;
      D[(size_t)L->sc[2 * n + 1] * (N + 1)] = 1.0;
      for (i = 0; i < nbn; ++i) {
        D[L->sc[2 * n + 1] + (size_t)L->sc[2 * nb[i] + 1] * N] = 0.1;
        D[L->sc[2 * nb[i] + 1] + (size_t)L->sc[2 * n + 1] * N] = 0.1;
      }
    }
  m->cp = (int *)malloc(sizeof(int) * (size_t)(N + 1));
  for (j = 0; j < N * N; ++j) nz += D[j] != 0.0;
  m->ri = (int *)malloc(sizeof(int) * (size_t)nz);
  m->v = (double *)malloc(sizeof(double) * (size_t)nz);
  for (j = 0, nz = 0; j < N; ++j) {
    m->cp[j] = nz;
    for (i = 0; i < N; ++i)
      if (D[i + (size_t)j * N] != 0.0) { m->ri[nz] = i; m->v[nz++] = D[i + (size_t)j * N]; }
  }
  m->cp[N] = nz;
  m->E.n_rows = m->E.n_cols = N;
  m->E.colptr = m->cp; m->E.rowidx = m->ri; m->E.values = m->v;
  free(D);
}
static void slu_mass_free(slu_mass *m) { free(m->cp); free(m->ri); free(m->v); }

TEST(test_sparse_lu_descriptor) {
  /* A 2-D lattice with a coupled mass matrix E simulated with the sparse LU
     of sigma E + M (forced; the old code refused it) and with the band LU
     with partial pivoting (an independent solver of the same stage systems):
     validation (and phgmg_dae_create: no algebraic line), trajectories,
     outputs, the energy bookkeeping and a GMG-POD
     reduction agree to 1e-10, linear and with the cosh potential on the
     positions (refactorizations); the discrete energy balance
     H_n - H_0 = S_n - D_n holds to round-off (quadratic H, Gauss
     collocation). */
  static const double expo[4] = {0.5, 1.0, 0.5, -1.0}, poly[1] = {-1.0};
  const int nx = 12, ny = 12, ns = 151;
  slu_lat L;
  slu_mass M;
  double *X[2], *Y[2], *YR[2], *H[2], *S[2], *D[2], *x0, amp = 400.0, bal = 0.0, hm = 0.0;
  int run, nl, k, *idx;
  slu_lat_build(&L, nx, ny, 1, 0);
  slu_mass_build(&M, &L, nx, ny);
  x0 = (double *)calloc((size_t)L.N, sizeof(double));
  idx = (int *)malloc(sizeof(int) * (size_t)L.nn);
  for (nl = 0; nl < 2; ++nl) {
    for (run = 0; run < 2; ++run) {
      phgmg_ph_sparse *sp = NULL;
      phgmg_ph_sparse_info inf;
      phgmg_ph_system sys;
      phgmg_energy en;
      X[run] = (double *)malloc(sizeof(double) * (size_t)L.N * ns);
      Y[run] = (double *)malloc(sizeof(double) * ns); YR[run] = (double *)calloc((size_t)ns, sizeof(double));
      H[run] = (double *)malloc(sizeof(double) * ns); S[run] = (double *)malloc(sizeof(double) * ns);
      D[run] = (double *)malloc(sizeof(double) * ns);
      en.H = H[run]; en.S = S[run]; en.D = D[run];
      CHECK_RC(phgmg_ph_sparse_create_e(&sp, L.N, 1, &L.M[0], &L.M[1], &L.M[2], &M.E, L.B, NULL, &inf, NULL), PHGMG_OK);
      CHECK_RC(phgmg_ph_sparse_set_solver(sp, run ? PHGMG_SOLVER_BAND : PHGMG_SOLVER_SPARSE_LU, &inf), PHGMG_OK);
      CHECK(inf.solver == (run ? PHGMG_SOLVER_BAND : PHGMG_SOLVER_SPARSE_LU));
      sys = *phgmg_ph_sparse_system(sp);
      CHECK(sys.E != NULL && sys.storage == (run ? PHGMG_BANDED : PHGMG_SPARSE));
      CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_OK);
      if (!nl) { /* no algebraic lines: the index-one path has nothing to condense (as the CLI asks) */
        phgmg_dae *dae = NULL;
        CHECK_RC(phgmg_dae_create(&dae, &sys, 0.0, NULL), PHGMG_OK);
        CHECK(dae && phgmg_dae_nalg(dae) == 0);
        phgmg_dae_destroy(dae);
      }
      if (nl) {
        for (k = 0; k < L.nn; ++k) idx[k] = L.sc[2 * k];
        sys.nl = PHGMG_NL_SEPARABLE;
        sys.poly_deg = 0; sys.poly = poly; sys.nexp = 2; sys.expo = expo;
        CHECK_RC(phgmg_ph_sparse_sep_idx(sp, L.nn, idx, NULL, &sys), PHGMG_OK);
      }
      CHECK_RC(phgmg_simulate(&sys, x0, 0.0, 0.1, ns - 1, slu_u, nl ? &amp : NULL, NULL, X[run], Y[run], &en, NULL,
                              NULL, NULL), PHGMG_OK);
      if (!nl) {
        phgmg_reduce_opts o;
        phgmg_reduced *red = NULL;
        double xr0[16];
        phgmg_reduce_opts_default(&o);
        o.method = PHGMG_METHOD_GMG_POD;
        o.r = 12;
        CHECK_RC(phgmg_reduce(&red, &sys, X[run], L.N, ns, &o, NULL, NULL), PHGMG_OK);
        if (red) {
          phgmg_reduced_restrict(red, x0, xr0);
          CHECK_RC(phgmg_reduced_simulate(red, xr0, 0.0, 0.1, ns - 1, slu_u, NULL, 1e-12, 30, NULL, YR[run], NULL,
                                          NULL, NULL), PHGMG_OK);
        }
        phgmg_reduced_destroy(red);
        for (k = 0; k < ns; ++k) { /* quadratic H: the discrete balance is exact up to round-off */
          bal = fmax(bal, fabs(H[run][k] - H[run][0] - (S[run][k] - D[run][k])));
          hm = fmax(hm, fabs(H[run][k]));
        }
      }
      phgmg_ph_sparse_destroy(sp);
    }
    CHECK_LE(slu_rel(L.N * ns, X[0], X[1]), 1e-10);
    CHECK_LE(slu_rel(ns, Y[0], Y[1]), 1e-10);
    CHECK_LE(slu_rel(ns, H[0], H[1]), 1e-10);
    CHECK_LE(slu_rel(ns, D[0], D[1]), 1e-10);
    CHECK_LE(slu_rel(ns, YR[0], YR[1]), 1e-10);
    CHECK(fabs(Y[1][ns - 1]) > 0.0 && H[1][ns - 1] > 0.0);
    for (run = 0; run < 2; ++run) { free(X[run]); free(Y[run]); free(YR[run]); free(H[run]); free(S[run]); free(D[run]); }
  }
  CHECK(hm > 0.0);
  CHECK_LE(bal, 1e-10 * hm);
  free(x0); free(idx);
  slu_mass_free(&M);
  slu_lat_free(&L);
}

TEST(test_sparse_lu_descriptor_choice) {
  /* A 24 x 24 lattice with a mass matrix: the sparse LU is predicted cheaper
     and chosen (the old code kept the band LU), the object holds no band
     copy (its bytes stay below one band matrix of (2 kb + 1) N doubles) and
     the band solver makes the copies of J, R, Q and E; an E with a zero row
     and column (an algebraic equation) is chosen by the same prediction and
     takes either solver (the index-one path of the sparse LU, manual 1.8). */
  slu_lat L;
  slu_mass M;
  slu_count cnt = {0.0, 0.0};
  phgmg_allocator al;
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_sparse_info inf;
  double band1, keep;
  int p;
  al.alloc = slu_count_alloc; al.free = slu_count_free; al.user = &cnt;
  slu_lat_build(&L, 24, 24, 1, 0);
  slu_mass_build(&M, &L, 24, 24);
  CHECK_RC(phgmg_ph_sparse_create_e(&sp, L.N, 1, &L.M[0], &L.M[1], &L.M[2], &M.E, L.B, NULL, &inf, &al), PHGMG_OK);
  band1 = 8.0 * (2.0 * inf.kb + 1.0) * L.N;
  CHECK(inf.solver == PHGMG_SOLVER_SPARSE_LU && inf.band_copy == 0);
  CHECK(2.0 * inf.lu_sparse < inf.lu_band && inf.flops_sparse < inf.flops_band);
  CHECK(phgmg_ph_sparse_system(sp)->storage == PHGMG_SPARSE && phgmg_ph_sparse_system(sp)->E != NULL);
  CHECK_LE(cnt.live, band1);
  CHECK_LE(cnt.peak, band1);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_BAND, &inf), PHGMG_OK);
  CHECK(inf.band_copy == 1 && phgmg_ph_sparse_system(sp)->storage == PHGMG_BANDED);
  CHECK(cnt.live >= 4.0 * band1);
  phgmg_ph_sparse_destroy(sp);
  CHECK(cnt.live == 0.0);
  keep = M.v[M.cp[1] - 1];
  for (p = M.cp[0]; p < M.cp[1]; ++p) M.v[p] = 0.0; /* state 0: zero column and (E symmetric: its only entry) row */
  sp = NULL;
  CHECK_RC(phgmg_ph_sparse_create_e(&sp, L.N, 1, &L.M[0], &L.M[1], &L.M[2], &M.E, L.B, NULL, &inf, NULL), PHGMG_OK);
  CHECK(inf.solver == PHGMG_SOLVER_SPARSE_LU && inf.band_copy == 0);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_BAND, &inf), PHGMG_OK);
  CHECK(phgmg_ph_sparse_system(sp)->storage == PHGMG_BANDED);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_SPARSE_LU, &inf), PHGMG_OK);
  CHECK(phgmg_ph_sparse_system(sp)->storage == PHGMG_SPARSE && inf.band_copy == 0);
  phgmg_ph_sparse_destroy(sp);
  (void)keep;
  slu_mass_free(&M);
  slu_lat_free(&L);
}

SUITE(sparse_lu) {
  RUN(test_sparse_lu_lattices);
  RUN(test_sparse_lu_components);
  RUN(test_sparse_lu_choice);
  RUN(test_sparse_lu_alloc_failures);
  RUN(test_sparse_lu_condense);
  RUN(test_sparse_lu_reuse_runs);
  RUN(test_sparse_storage_no_band);
  RUN(test_sparse_storage_equals_band);
  RUN(test_sparse_storage_checks);
  RUN(test_sparse_lu_descriptor);
  RUN(test_sparse_lu_descriptor_choice);
}
