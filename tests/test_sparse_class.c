/* Model classes on the sparse direct LU of the GL3 stepper (manual 2.6,
   8.12): nonlinear dampers, a GENERAL Hamiltonian with a Hessian pattern
   and the shifted-solve callbacks on a sparse model. Each is checked
   against the band LU of the same model (an independent code path: band
   storage, partial pivoting), and phgmg_gl3_stats must say which solver
   ran. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>

/* An nx x ny lattice of masses in the user's order (node n: position 2n,
   momentum 2n + 1): J couples each position to its momentum, R = 0.05 I +
   0.02 Laplacian on the momenta (the momenta of neighbours coupled: the
   dampers between them stay inside the band), Q = diag(K, I) with K = 0.1 I
   + the lattice Laplacian, one force on momentum 0. The springs (x and y
   links) carry the quartic energy w/4 (q_a - q_b)^4 of the GENERAL tests. */
typedef struct spc_model {
  int nx, ny, nn, N, nlink, *la, *lb;
  int *cp[3], *ri[3];
  double *v[3], *B;
  phgmg_csc M[3];
} spc_model;

static void spc_free(spc_model *m) {
  int a;
  for (a = 0; a < 3; ++a) { free(m->cp[a]); free(m->ri[a]); free(m->v[a]); }
  free(m->B); free(m->la); free(m->lb);
}

static void spc_to_csc(spc_model *m, int a, const double *D) {
  const int N = m->N;
  int i, j, nz = 0;
  m->cp[a] = (int *)malloc(sizeof(int) * (size_t)(N + 1));
  m->ri[a] = (int *)malloc(sizeof(int) * (size_t)N * 8);
  m->v[a] = (double *)malloc(sizeof(double) * (size_t)N * 8);
  for (j = 0; j < N; ++j) {
    m->cp[a][j] = nz;
    for (i = 0; i < N; ++i)
      if (D[i + (size_t)j * N] != 0.0) { m->ri[a][nz] = i; m->v[a][nz++] = D[i + (size_t)j * N]; }
  }
  m->cp[a][N] = nz;
  m->M[a].n_rows = m->M[a].n_cols = N;
  m->M[a].colptr = m->cp[a]; m->M[a].rowidx = m->ri[a]; m->M[a].values = m->v[a];
}

static void spc_build(spc_model *m, int nx, int ny) {
  int N, x, y, k, a;
  double *D[3];
  memset(m, 0, sizeof *m);
  m->nx = nx; m->ny = ny; m->nn = nx * ny; m->N = N = 2 * m->nn;
  m->la = (int *)malloc(sizeof(int) * (size_t)(2 * m->nn));
  m->lb = (int *)malloc(sizeof(int) * (size_t)(2 * m->nn));
  for (y = 0; y < ny; ++y)
    for (x = 0; x < nx; ++x) {
      const int n = x + nx * y;
      if (x + 1 < nx) { m->la[m->nlink] = n; m->lb[m->nlink++] = n + 1; }
      if (y + 1 < ny) { m->la[m->nlink] = n; m->lb[m->nlink++] = n + nx; }
    }
  for (a = 0; a < 3; ++a) D[a] = (double *)calloc((size_t)N * N, sizeof(double));
#define SPC_AT(Mx, r, c) Mx[(size_t)(r) + (size_t)(c) * (size_t)N]
  for (k = 0; k < m->nn; ++k) {
    SPC_AT(D[0], 2 * k, 2 * k + 1) = 1.0;
    SPC_AT(D[0], 2 * k + 1, 2 * k) = -1.0;
    SPC_AT(D[1], 2 * k + 1, 2 * k + 1) = 0.05;
    SPC_AT(D[2], 2 * k + 1, 2 * k + 1) = 1.0;
    SPC_AT(D[2], 2 * k, 2 * k) = 0.1;
  }
  for (k = 0; k < m->nlink; ++k) {
    const int qa = 2 * m->la[k], qb = 2 * m->lb[k];
    SPC_AT(D[2], qa, qa) += 1.0; SPC_AT(D[2], qb, qb) += 1.0;
    SPC_AT(D[2], qa, qb) -= 1.0; SPC_AT(D[2], qb, qa) -= 1.0;
    SPC_AT(D[1], qa + 1, qa + 1) += 0.02; SPC_AT(D[1], qb + 1, qb + 1) += 0.02;
    SPC_AT(D[1], qa + 1, qb + 1) -= 0.02; SPC_AT(D[1], qb + 1, qa + 1) -= 0.02;
  }
#undef SPC_AT
  for (a = 0; a < 3; ++a) { spc_to_csc(m, a, D[a]); free(D[a]); }
  m->B = (double *)calloc((size_t)N, sizeof(double));
  m->B[1] = 1.0;
}

static void spc_u(double t, double *u, void *user) {
  (void)user;
  u[0] = 6.0 * sin(1.3 * t) + 3.0 * sin(0.4 * t);
}

/* The quartic springs of a GENERAL part, in the internal order: H_nl =
   sum_k w/4 d_k^4, d_k = x[a_k] - x[b_k]; the Hessian either in band storage
   (kb) or in the values of the pattern sys.hess_p / hess_i (pos: 4 entries
   per spring, (a,a), (b,b), (a,b), (b,a)). */
typedef struct spc_quartic {
  int n, *a, *b, kb, band, *pos;
  double w;
  long nhess;
} spc_quartic;

static double spc_q_H(const double *x, void *user) {
  const spc_quartic *q = (const spc_quartic *)user;
  double H = 0.0;
  int k;
  for (k = 0; k < q->n; ++k) {
    const double d = x[q->a[k]] - x[q->b[k]];
    H += 0.25 * q->w * d * d * d * d;
  }
  return H;
}
static void spc_q_grad(const double *x, double *g, void *user) {
  const spc_quartic *q = (const spc_quartic *)user;
  int k;
  for (k = 0; k < q->n; ++k) {
    const double d = x[q->a[k]] - x[q->b[k]], f = q->w * d * d * d;
    g[q->a[k]] += f;
    g[q->b[k]] -= f;
  }
}
/* grad_nl must fill every entry: zero the rest first (N from the user struct's caller). */
typedef struct spc_gen { spc_quartic q; int N; } spc_gen;
static void spc_g_grad(const double *x, double *g, void *user) {
  const spc_gen *G = (const spc_gen *)user;
  int i;
  for (i = 0; i < G->N; ++i) g[i] = 0.0;
  spc_q_grad(x, g, (void *)&G->q);
}
static double spc_g_H(const double *x, void *user) { return spc_q_H(x, (void *)&((const spc_gen *)user)->q); }
static void spc_g_hess(const double *x, double *Hs, void *user) {
  spc_gen *G = (spc_gen *)user;
  const spc_quartic *q = &G->q;
  const int N = G->N, kb = q->kb;
  int k, i;
  G->q.nhess++;
  if (q->band) for (i = 0; i < (2 * kb + 1) * N; ++i) Hs[i] = 0.0;
  else for (i = 0; i < 4 * q->n; ++i) Hs[q->pos[i]] = 0.0;
  for (k = 0; k < q->n; ++k) {
    const int a = q->a[k], b = q->b[k];
    const double d = x[a] - x[b], h = 3.0 * q->w * d * d;
    if (q->band) {
      Hs[PHGMG__PHB(kb, a, a)] += h; Hs[PHGMG__PHB(kb, b, b)] += h;
      Hs[PHGMG__PHB(kb, a, b)] -= h; Hs[PHGMG__PHB(kb, b, a)] -= h;
    } else {
      Hs[q->pos[4 * k]] += h; Hs[q->pos[4 * k + 1]] += h;
      Hs[q->pos[4 * k + 2]] -= h; Hs[q->pos[4 * k + 3]] -= h;
    }
  }
}

/* Entry (row, col) of a CSC pattern (-1: none). */
static int spc_find(const int *cp, const int *ci, int row, int col) {
  int p;
  for (p = cp[col]; p < cp[col + 1]; ++p) if (ci[p] == row) return p;
  return -1;
}

static double spc_maxdiff(int n, const double *a, const double *b, double *scale) {
  double d = 0.0, s = 0.0;
  int i;
  for (i = 0; i < n; ++i) {
    d = fabs(a[i] - b[i]) > d ? fabs(a[i] - b[i]) : d;
    s = fabs(b[i]) > s ? fabs(b[i]) : s;
  }
  if (scale) *scale = s;
  return d;
}

#define SPC_STEPS 60
/* Simulate sys from a displaced state (tight Newton tolerance): trajectory X, outputs Y,
   stats st, energy E. */
static phgmg_result spc_sim(const phgmg_ph_system *sys, double *X, double *Y, phgmg_gl3_stats *st,
                            const phgmg_energy *E) {
  phgmg_gl3_opts o;
  double *x0 = (double *)calloc((size_t)sys->N, sizeof(double));
  phgmg_result rc;
  int i;
  for (i = 0; i < sys->N; ++i) x0[i] = 0.6 * sin(1.7 * (double)i); /* away from rest: curvature at x0 */
  memset(&o, 0, sizeof o);
  o.tol = 1e-13;
  o.max_iter = 30;
  rc = phgmg_simulate(sys, x0, 0.0, 0.1, SPC_STEPS, spc_u, NULL, &o, X, Y, E, st, NULL, NULL);
  free(x0);
  return rc;
}

/* A reduced model of order 8 (method meth; spc_reduce: GMG-POD) from the
   snapshots X (SPC_STEPS + 1 columns) and its outputs from rest under spc_u
   (NULL on failure). */
static phgmg_reduced *spc_reduce_m(const phgmg_ph_system *sys, const double *X, double *Yr, phgmg_method meth) {
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  double xr0[8] = {0};
  memset(&o, 0, sizeof o);
  o.method = meth; o.r = 8;
  if (phgmg_reduce(&red, sys, X, sys->N, SPC_STEPS + 1, &o, NULL, NULL) != PHGMG_OK) return NULL;
  if (phgmg_reduced_simulate(red, xr0, 0.0, 0.1, SPC_STEPS, spc_u, NULL, 1e-13, 30, NULL, Yr, NULL, NULL, NULL) !=
      PHGMG_OK) { phgmg_reduced_destroy(red); return NULL; }
  return red;
}
static phgmg_reduced *spc_reduce(const phgmg_ph_system *sys, const double *X, double *Yr) {
  return spc_reduce_m(sys, X, Yr, PHGMG_METHOD_GMG_POD);
}

/* Dampers between the momenta (co-states: velocities) of x-neighbours,
   linear plus cubic law, in the internal order of sp. */
static void spc_dampers(const spc_model *m, const phgmg_ph_sparse *sp, phgmg_ph_system *sys, int *di, int *dj) {
  static const double law[4] = {0.0, 0.3, 0.0, 4.0};
  const int *perm = phgmg_ph_sparse_perm(sp);
  int *ip = (int *)malloc(sizeof(int) * (size_t)m->N), k, n = 0;
  for (k = 0; k < m->N; ++k) ip[perm[k]] = k;
  for (k = 0; k < m->nlink; ++k) {
    if (m->lb[k] != m->la[k] + 1) continue;   /* x-links */
    di[n] = ip[2 * m->la[k] + 1];
    dj[n] = (n % 3 == 2) ? -1 : ip[2 * m->lb[k] + 1];   /* some dampers to ground (c = e_i) */
    ++n;
  }
  sys->ndamp = n; sys->damp_i = di; sys->damp_j = dj;
  sys->damp_deg = 3; sys->damp_poly = law;
  free(ip);
}

/* Nonlinear dampers on the sparse LU: the stepper keeps the sparse LU
   (stats), its trajectory and outputs equal the band LU's to 1e-10 of their
   scale with the same Newton iterations (the same Jacobian), the energy
   balance H_n - H_0 = S_n - D_n holds for a quadratic H, the validation
   (J - R - L regular, through the sparse copies) passes, and the GMG-POD
   and SP1 models reduced from the sparse system (GMG: G = (J - R - L)^{-1}
   on the sparse copies) simulate as those reduced from the band system. */
TEST(test_spclass_dampers) {
  spc_model m;
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_system sys;
  phgmg_gl3_stats st1, st2;
  phgmg_energy E;
  int di[64], dj[64], N, n;
  double *X1, *X2, *Y1, *Y2, sc, bal = 0.0, Hmax = 0.0, Yr1[SPC_STEPS + 1], Yr2[SPC_STEPS + 1];
  double Ys1[SPC_STEPS + 1], Ys2[SPC_STEPS + 1];
  phgmg_reduced *red1, *red2, *sp1, *sp2;
  spc_build(&m, 6, 5);
  N = m.N;
  X1 = (double *)malloc(sizeof(double) * (size_t)N * (SPC_STEPS + 1));
  X2 = (double *)malloc(sizeof(double) * (size_t)N * (SPC_STEPS + 1));
  Y1 = (double *)malloc(sizeof(double) * (SPC_STEPS + 1));
  Y2 = (double *)malloc(sizeof(double) * (SPC_STEPS + 1));
  E.H = (double *)malloc(sizeof(double) * (SPC_STEPS + 1));
  E.S = (double *)malloc(sizeof(double) * (SPC_STEPS + 1));
  E.D = (double *)malloc(sizeof(double) * (SPC_STEPS + 1));
  CHECK_RC(phgmg_ph_sparse_create(&sp, N, 1, &m.M[0], &m.M[1], &m.M[2], m.B, NULL, NULL, NULL),
           PHGMG_OK);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_SPARSE_LU, NULL), PHGMG_OK);
  sys = *phgmg_ph_sparse_system(sp);
  CHECK(sys.storage == PHGMG_SPARSE);
  spc_dampers(&m, sp, &sys, di, dj);
  CHECK(sys.ndamp > 10);
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_OK);
  CHECK_RC(spc_sim(&sys, X1, Y1, &st1, &E), PHGMG_OK);
  CHECK(st1.sparse_lu == 1 && st1.band_fallback == 0);
  for (n = 0; n <= SPC_STEPS; ++n) {
    const double d = fabs(E.H[n] - E.H[0] - E.S[n] + E.D[n]);
    bal = d > bal ? d : bal;
    Hmax = fabs(E.H[n]) > Hmax ? fabs(E.H[n]) : Hmax;
  }
  CHECK(E.D[SPC_STEPS] > 0.0);
  CHECK_LE(bal, 1e-10 * Hmax);
  red1 = spc_reduce(&sys, X1, Yr1);
  sp1 = spc_reduce_m(&sys, X1, Ys1, PHGMG_METHOD_SP1);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_BAND, NULL), PHGMG_OK);
  sys = *phgmg_ph_sparse_system(sp);
  CHECK(sys.storage == PHGMG_BANDED);
  spc_dampers(&m, sp, &sys, di, dj);
  CHECK_RC(spc_sim(&sys, X2, Y2, &st2, NULL), PHGMG_OK);
  red2 = spc_reduce(&sys, X1, Yr2);   /* the same snapshots: only the solver of J - R - L differs */
  sp2 = spc_reduce_m(&sys, X1, Ys2, PHGMG_METHOD_SP1);
  CHECK(red1 && red2 && sp1 && sp2);
  CHECK_LE(spc_maxdiff(SPC_STEPS + 1, Yr1, Yr2, &sc), 1e-9 * sc);
  CHECK(sc > 0.1);
  CHECK_LE(spc_maxdiff(SPC_STEPS + 1, Ys1, Ys2, &sc), 1e-9 * sc);
  CHECK(sc > 0.1);
  phgmg_reduced_destroy(red1);
  phgmg_reduced_destroy(red2);
  phgmg_reduced_destroy(sp1);
  phgmg_reduced_destroy(sp2);
  CHECK(st2.sparse_lu == 0);
  CHECK_LE(labs(st1.newton_iters - st2.newton_iters), 2 + st2.newton_iters / 100); /* the same Jacobian */
  CHECK_LE(spc_maxdiff(N * (SPC_STEPS + 1), X1, X2, &sc), 1e-10 * sc);
  CHECK(sc > 0.1);
  CHECK_LE(spc_maxdiff(SPC_STEPS + 1, Y1, Y2, &sc), 1e-10 * sc);
  phgmg_ph_sparse_destroy(sp);
  free(X1); free(X2); free(Y1); free(Y2); free(E.H); free(E.S); free(E.D);
  spc_free(&m);
}

/* The quartic springs in the internal order of sp (a[k], b[k] positions). */
static void spc_springs(const spc_model *m, const phgmg_ph_sparse *sp, spc_gen *G, int *a, int *b) {
  const int *perm = phgmg_ph_sparse_perm(sp);
  int *ip = (int *)malloc(sizeof(int) * (size_t)m->N), k;
  for (k = 0; k < m->N; ++k) ip[perm[k]] = k;
  memset(G, 0, sizeof *G);
  G->N = m->N;
  G->q.n = m->nlink; G->q.a = a; G->q.b = b; G->q.w = 20.0;
  for (k = 0; k < m->nlink; ++k) { a[k] = ip[2 * m->la[k]]; b[k] = ip[2 * m->lb[k]]; }
  free(ip);
}

/* A GENERAL Hamiltonian (quartic springs between the nodes) on the sparse
   LU: its Hessian pattern (that of the springs, given in the user's order
   and mapped by phgmg_ph_sparse_hess_pattern: map[e] is the internal entry
   of user entry e), the stepper on the sparse LU calling the Hessian in
   that pattern, trajectory and outputs equal to the band LU's (band
   Hessian) to 1e-10 of their scale with the same Newton iterations, a
   GMG-POD model reduced from the sparse system (its reduced Hessian from
   the pattern's values) simulating as the one from the band system; a
   malformed or missing pattern is refused with its code. */
TEST(test_spclass_general) {
  spc_model m;
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_system sys;
  phgmg_gl3_stats st1, st2;
  spc_gen G;
  int a[128], b[128], pos[512], *cp, *ri, *map, N, i, j, k, nz = 0, bad;
  const int *perm;
  double *X1, *X2, *Y1, *Y2, sc, Yr1[SPC_STEPS + 1], Yr2[SPC_STEPS + 1];
  phgmg_reduced *red1, *red2;
  spc_build(&m, 6, 5);
  N = m.N;
  X1 = (double *)malloc(sizeof(double) * (size_t)N * (SPC_STEPS + 1));
  X2 = (double *)malloc(sizeof(double) * (size_t)N * (SPC_STEPS + 1));
  Y1 = (double *)malloc(sizeof(double) * (SPC_STEPS + 1));
  Y2 = (double *)malloc(sizeof(double) * (SPC_STEPS + 1));
  cp = (int *)malloc(sizeof(int) * (size_t)(N + 1));
  ri = (int *)malloc(sizeof(int) * (size_t)N * 8);
  map = (int *)malloc(sizeof(int) * (size_t)N * 8);
  for (j = 0; j < N; ++j) { /* the springs' pattern in the user's order: Q's position block */
    cp[j] = nz;
    if (j % 2) continue;
    for (k = m.cp[2][j]; k < m.cp[2][j + 1]; ++k) ri[nz++] = m.ri[2][k];
  }
  cp[N] = nz;
  CHECK_RC(phgmg_ph_sparse_create(&sp, N, 1, &m.M[0], &m.M[1], &m.M[2], m.B, NULL, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_SPARSE_LU, NULL), PHGMG_OK);
  sys = *phgmg_ph_sparse_system(sp);
  spc_springs(&m, sp, &G, a, b);
  sys.nl = PHGMG_NL_GENERAL;
  sys.H_nl = spc_g_H; sys.grad_nl = spc_g_grad; sys.hess_nl = spc_g_hess; sys.user = &G;
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_ERR_UNSUPPORTED);   /* no pattern */
  ri[1] = ri[0];   /* rows not increasing */
  CHECK_RC(phgmg_ph_sparse_hess_pattern(sp, cp, ri, map, &sys), PHGMG_ERR_FORMAT);
  ri[1] = m.ri[2][1];
  CHECK_RC(phgmg_ph_sparse_hess_pattern(sp, cp, ri, map, &sys), PHGMG_OK);
  perm = phgmg_ph_sparse_perm(sp);
  for (j = 0, bad = 0; j < N; ++j) /* user entry (ri[e], j) sits at map[e]: row perm^-1(ri[e]), column perm^-1(j) */
    for (k = cp[j]; k < cp[j + 1]; ++k) {
      const int e = map[k];
      int c = 0;
      while (sys.hess_p[c + 1] <= e) ++c;
      bad += perm[c] != j || perm[sys.hess_i[e]] != ri[k];
    }
  CHECK(bad == 0);
  for (k = 0; k < m.nlink; ++k) {
    pos[4 * k] = spc_find(sys.hess_p, sys.hess_i, a[k], a[k]);
    pos[4 * k + 1] = spc_find(sys.hess_p, sys.hess_i, b[k], b[k]);
    pos[4 * k + 2] = spc_find(sys.hess_p, sys.hess_i, a[k], b[k]);
    pos[4 * k + 3] = spc_find(sys.hess_p, sys.hess_i, b[k], a[k]);
  }
  for (i = 0, bad = 0; i < 4 * m.nlink; ++i) bad += pos[i] < 0;
  CHECK(bad == 0);
  G.q.pos = pos; G.q.band = 0;
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_OK);
  CHECK_RC(spc_sim(&sys, X1, Y1, &st1, NULL), PHGMG_OK);
  CHECK(st1.sparse_lu == 1 && st1.band_fallback == 0);
  CHECK(G.q.nhess > 0);
  red1 = spc_reduce(&sys, X1, Yr1);   /* the reduced Hessian through the pattern's values */
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_BAND, NULL), PHGMG_OK);
  sys = *phgmg_ph_sparse_system(sp);
  sys.nl = PHGMG_NL_GENERAL;
  sys.H_nl = spc_g_H; sys.grad_nl = spc_g_grad; sys.hess_nl = spc_g_hess; sys.user = &G;
  G.q.band = 1; G.q.kb = sys.kb; G.q.nhess = 0;
  CHECK_RC(spc_sim(&sys, X2, Y2, &st2, NULL), PHGMG_OK);
  CHECK(st2.sparse_lu == 0 && G.q.nhess > 0);
  red2 = spc_reduce(&sys, X1, Yr2);
  CHECK(red1 && red2);
  CHECK_LE(spc_maxdiff(SPC_STEPS + 1, Yr1, Yr2, &sc), 1e-9 * sc);
  CHECK(sc > 0.1);
  phgmg_reduced_destroy(red1);
  phgmg_reduced_destroy(red2);
  CHECK_LE(labs(st1.newton_iters - st2.newton_iters), 2 + st2.newton_iters / 100); /* the same Jacobian */
  CHECK_LE(spc_maxdiff(N * (SPC_STEPS + 1), X1, X2, &sc), 1e-10 * sc);
  CHECK(sc > 0.1);
  CHECK_LE(spc_maxdiff(SPC_STEPS + 1, Y1, Y2, &sc), 1e-10 * sc);
  phgmg_ph_sparse_destroy(sp);
  free(X1); free(X2); free(Y1); free(Y2); free(cp); free(ri); free(map);
  spc_free(&m);
}

/* Shifted-solve callbacks: a dense LU of sigma I - (J - R) Q in the
   internal order, counting its factorizations. */
typedef struct spc_cb {
  int N;
  double *JR, *Q, *K1, *K2;
  int *ip1, *ip2;
  long nfactor;
} spc_cb;
static phgmg_result spc_cb_factor(double sr, double si, const double *x, void *user) {
  spc_cb *c = (spc_cb *)user;
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
static void spc_cb_solve(double sr, double si, double *rhs, void *user) {
  spc_cb *c = (spc_cb *)user;
  (void)sr;
  if (si == 0.0) phgmg_lu_solve('N', c->N, c->K1, c->N, c->ip1, 1, rhs, c->N);
  else phgmg_zlu_solve(c->N, c->K2, c->N, c->ip2, 1, rhs, c->N);
}

/* The shifted-solve callbacks with a sparse model (SPARSE storage): the
   stepper solves with the callbacks (they are called; the sparse LU is not
   used: stats), the right-hand sides come from the sparse copies, and the
   trajectory equals the band LU's to 1e-10 of its scale. */
TEST(test_spclass_shifted_callbacks) {
  spc_model m;
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_system sys;
  phgmg_gl3_stats st1, st2;
  spc_cb cb;
  int N, i, j, k, a;
  const int *perm;
  double *X1, *X2, *Y1, *Y2, *D[3], sc;
  spc_build(&m, 5, 4);
  N = m.N;
  X1 = (double *)malloc(sizeof(double) * (size_t)N * (SPC_STEPS + 1));
  X2 = (double *)malloc(sizeof(double) * (size_t)N * (SPC_STEPS + 1));
  Y1 = (double *)malloc(sizeof(double) * (SPC_STEPS + 1));
  Y2 = (double *)malloc(sizeof(double) * (SPC_STEPS + 1));
  CHECK_RC(phgmg_ph_sparse_create(&sp, N, 1, &m.M[0], &m.M[1], &m.M[2], m.B, NULL, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_SPARSE_LU, NULL), PHGMG_OK);
  perm = phgmg_ph_sparse_perm(sp);
  for (a = 0; a < 3; ++a) { /* dense J, R, Q in the internal order */
    D[a] = (double *)calloc((size_t)N * N, sizeof(double));
    for (j = 0; j < N; ++j)
      for (k = m.cp[a][j]; k < m.cp[a][j + 1]; ++k) {
        int r = 0, c = 0;
        while (perm[r] != m.ri[a][k]) ++r;
        while (perm[c] != j) ++c;
        D[a][r + (size_t)c * N] = m.v[a][k];
      }
  }
  memset(&cb, 0, sizeof cb);
  cb.N = N; cb.JR = D[0]; cb.Q = D[2];
  for (i = 0; i < N * N; ++i) D[0][i] -= D[1][i];
  cb.K1 = (double *)malloc(sizeof(double) * (size_t)N * N);
  cb.K2 = (double *)malloc(2 * sizeof(double) * (size_t)N * N);
  cb.ip1 = (int *)malloc(sizeof(int) * (size_t)N);
  cb.ip2 = (int *)malloc(sizeof(int) * (size_t)N);
  sys = *phgmg_ph_sparse_system(sp);
  CHECK(sys.storage == PHGMG_SPARSE);
  sys.shifted_factor = spc_cb_factor; sys.shifted_solve = spc_cb_solve; sys.shifted_user = &cb;
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_OK);
  CHECK_RC(spc_sim(&sys, X1, Y1, &st1, NULL), PHGMG_OK);
  CHECK(cb.nfactor >= 2);
  CHECK(st1.sparse_lu == 0 && st1.band_fallback == 0);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_BAND, NULL), PHGMG_OK);
  sys = *phgmg_ph_sparse_system(sp);
  CHECK_RC(spc_sim(&sys, X2, Y2, &st2, NULL), PHGMG_OK);
  CHECK_LE(labs(st1.newton_iters - st2.newton_iters), 2 + st2.newton_iters / 100); /* the same Jacobian */
  CHECK_LE(spc_maxdiff(N * (SPC_STEPS + 1), X1, X2, &sc), 1e-10 * sc);
  CHECK(sc > 0.1);
  CHECK_LE(spc_maxdiff(SPC_STEPS + 1, Y1, Y2, &sc), 1e-10 * sc);
  phgmg_ph_sparse_destroy(sp);
  for (a = 0; a < 3; ++a) free(D[a]);
  free(cb.K1); free(cb.K2); free(cb.ip1); free(cb.ip2);
  free(X1); free(X2); free(Y1); free(Y2);
  spc_free(&m);
}

/* Largest |H_n - H_0 - S_n + D_n| over a run of n steps of size h (final
   time fixed), relative to max |H_n|. */
static double spc_balance(const phgmg_ph_system *sys, double h, int n) {
  phgmg_gl3_opts o;
  phgmg_energy E;
  double *x0 = (double *)calloc((size_t)sys->N, sizeof(double)), bal = 0.0, Hm = 0.0;
  int i;
  for (i = 0; i < sys->N; ++i) x0[i] = 0.6 * sin(1.7 * (double)i);
  E.H = (double *)malloc(sizeof(double) * (size_t)(n + 1));
  E.S = (double *)malloc(sizeof(double) * (size_t)(n + 1));
  E.D = (double *)malloc(sizeof(double) * (size_t)(n + 1));
  memset(&o, 0, sizeof o);
  o.tol = 1e-14; o.max_iter = 40;
  if (phgmg_simulate(sys, x0, 0.0, h, n, spc_u, NULL, &o, NULL, NULL, &E, NULL, NULL, NULL) != PHGMG_OK) bal = 1e300;
  for (i = 0; i <= n; ++i) {
    const double d = fabs(E.H[i] - E.H[0] - E.S[i] + E.D[i]);
    bal = d > bal ? d : bal;
    Hm = fabs(E.H[i]) > Hm ? fabs(E.H[i]) : Hm;
  }
  free(x0); free(E.H); free(E.S); free(E.D);
  return bal / Hm;
}

/* Nonlinear energies of finite-element form, sum_k w/4 (c_k^T x)^4 with
   c_k = e_i - e_j (springs between nodes), as a GENERAL part with its
   Hessian pattern on the sparse LU (manual 1.9): the full model's energy
   balance holds up to the error of the Gauss rule on H(p(t))' (H quartic:
   not exact), which falls like h^6 (halving h divides it by about 64; at
   least 32 asserted); the GMG-POD model's energy is H o phi (Hr(xr) =
   H(lift(xr)) at states along the reduced run), its structure matrix Rr
   is positive semidefinite (a port-Hamiltonian reduced model), and its
   own balance holds likewise. */
TEST(test_spclass_fe_springs) {
  spc_model m;
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_system sys;
  spc_gen G;
  phgmg_energy E;
  phgmg_reduced *red = NULL;
  phgmg_reduce_opts o;
  const phgmg_rom *rom;
  int a[128], b[128], pos[512], *cp, *ri, N, j, k, nz = 0, n;
  double b1, b2, *X, XR[8 * 61], Jr[64], Rr[64], ev[8], *xf, *work, xr0[8] = {0}, dmax = 0.0, hmax = 0.0, bal = 0.0;
  double Hd[SPC_STEPS + 1], Sd[SPC_STEPS + 1], Dd[SPC_STEPS + 1];
  spc_build(&m, 6, 5);
  N = m.N;
  cp = (int *)malloc(sizeof(int) * (size_t)(N + 1));
  ri = (int *)malloc(sizeof(int) * (size_t)N * 8);
  for (j = 0; j < N; ++j) {
    cp[j] = nz;
    if (j % 2) continue;
    for (k = m.cp[2][j]; k < m.cp[2][j + 1]; ++k) ri[nz++] = m.ri[2][k];
  }
  cp[N] = nz;
  CHECK_RC(phgmg_ph_sparse_create(&sp, N, 1, &m.M[0], &m.M[1], &m.M[2], m.B, NULL, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_SPARSE_LU, NULL), PHGMG_OK);
  sys = *phgmg_ph_sparse_system(sp);
  spc_springs(&m, sp, &G, a, b);
  sys.nl = PHGMG_NL_GENERAL;
  sys.H_nl = spc_g_H; sys.grad_nl = spc_g_grad; sys.hess_nl = spc_g_hess; sys.user = &G;
  CHECK_RC(phgmg_ph_sparse_hess_pattern(sp, cp, ri, NULL, &sys), PHGMG_OK);
  for (k = 0; k < m.nlink; ++k) {
    pos[4 * k] = spc_find(sys.hess_p, sys.hess_i, a[k], a[k]);
    pos[4 * k + 1] = spc_find(sys.hess_p, sys.hess_i, b[k], b[k]);
    pos[4 * k + 2] = spc_find(sys.hess_p, sys.hess_i, a[k], b[k]);
    pos[4 * k + 3] = spc_find(sys.hess_p, sys.hess_i, b[k], a[k]);
  }
  G.q.pos = pos; G.q.band = 0;
  b1 = spc_balance(&sys, 0.1, 30);
  b2 = spc_balance(&sys, 0.05, 60);
  CHECK_LE(b1, 1e-3);          /* measured 1.4e-4 and 2.3e-6: a ratio of 60 */
  CHECK_LE(32.0 * b2, b1);
  X = (double *)malloc(sizeof(double) * (size_t)N * (SPC_STEPS + 1));
  CHECK_RC(spc_sim(&sys, X, NULL, NULL, NULL), PHGMG_OK);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = 8;
  CHECK_RC(phgmg_reduce(&red, &sys, X, N, SPC_STEPS + 1, &o, NULL, NULL), PHGMG_OK);
  rom = phgmg_reduced_rom(red);
  work = (double *)malloc(sizeof(double) * (phgmg_rom_eval_work_size(rom) + 1));
  xf = (double *)malloc(sizeof(double) * (size_t)N);
  E.H = Hd; E.S = Sd; E.D = Dd;
  CHECK_RC(phgmg_reduced_simulate(red, xr0, 0.0, 0.1, SPC_STEPS, spc_u, NULL, 1e-13, 30, XR, NULL, &E, NULL, NULL),
           PHGMG_OK);
  for (n = 0; n <= SPC_STEPS; n += 6) { /* Hr = H o phi along the reduced run */
    const double *xr = XR + (size_t)n * 8;
    double Hr = phgmg_rom_hamiltonian(rom, xr, work), H;
    phgmg_reduced_lift(red, xr, xf);
    H = phgmg_ph_hamiltonian(&sys, xf);
    dmax = fabs(Hr - H) > dmax ? fabs(Hr - H) : dmax;
    hmax = fabs(H) > hmax ? fabs(H) : hmax;
  }
  CHECK(hmax > 0.1);
  CHECK_LE(dmax, 1e-10 * hmax);
  CHECK_RC(phgmg_rom_structure(rom, XR + 8 * 10, Jr, Rr, work), PHGMG_OK);
  CHECK_RC(phgmg_sym_eig(8, Rr, 8, ev, NULL, 8), PHGMG_OK);
  CHECK(ev[0] >= -1e-12 * fabs(ev[7]) && ev[7] > 0.0);
  for (n = 0; n <= SPC_STEPS; ++n) bal = fabs(Hd[n] - Hd[0] - Sd[n] + Dd[n]) > bal ? fabs(Hd[n] - Hd[0] - Sd[n] + Dd[n]) : bal;
  CHECK_LE(bal, 1e-5 * hmax);
  phgmg_reduced_destroy(red);
  phgmg_ph_sparse_destroy(sp);
  free(cp); free(ri); free(X); free(work); free(xf);
  spc_free(&m);
}

SUITE(sparse_class) {
  RUN(test_spclass_fe_springs);
  RUN(test_spclass_dampers);
  RUN(test_spclass_general);
  RUN(test_spclass_shifted_callbacks);
}
