/* Index-one descriptor models on the sparse LU (manual 1.8): a power-grid-
   like RLC network in nodal form (main nodes on a grid, a resistor, a mid
   node and an inductor on every edge, shunt loads, capacitors on half the
   mains), rows and columns scrambled, stepped as the DAE on its sparse
   pencil, against the dense condensed path; a model beyond the dense
   condensation's 4096 algebraic lines; an index-two model refused. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>

typedef struct {
  int N, n, nz[4];             /* nz: entries of J, R, Q, E (triplets, duplicates summed by the CSC) */
  int *cp[4], *ri[4];
  double *cv[4], *B;
  phgmg_csc M[4];
} dsg_model;

/* Element value k in [0.5, 1.5), deterministic. */
static double dsg_val(int k) { return 0.5 + fmod(0.6180339887498949 * (double)(k + 1), 1.0); }

/* Triplets (r, c, v) of matrix a into CSC (duplicates summed, rows sorted). */
static void dsg_csc(dsg_model *g, int a, const int *r, const int *c, const double *v, int nt) {
  const int N = g->N;
  int k, j, *cnt = (int *)calloc((size_t)N + 1, sizeof(int)), *pos = (int *)calloc((size_t)N, sizeof(int));
  double *col = (double *)calloc((size_t)N, sizeof(double));
  int *mark = (int *)malloc(sizeof(int) * (size_t)N), *tp = (int *)calloc((size_t)N + 1, sizeof(int));
  int *ti = (int *)malloc(sizeof(int) * (size_t)nt + 1), nz = 0;
  for (k = 0; k < nt; ++k) tp[c[k] + 1]++;
  for (j = 0; j < N; ++j) tp[j + 1] += tp[j];
  for (k = 0; k < nt; ++k) ti[tp[c[k]] + pos[c[k]]++] = k;
  g->cp[a] = cnt;
  g->ri[a] = (int *)malloc(sizeof(int) * (size_t)nt + 1);
  g->cv[a] = (double *)malloc(sizeof(double) * (size_t)nt + 1);
  for (j = 0; j < N; ++j) mark[j] = -1;
  for (j = 0; j < N; ++j) {
    int i, p0 = nz;
    cnt[j] = nz;
    for (k = tp[j]; k < tp[j + 1]; ++k) {
      i = r[ti[k]];
      if (mark[i] != j) { mark[i] = j; g->ri[a][nz++] = i; }
      col[i] += v[ti[k]];
    }
    for (k = p0; k < nz; ++k) /* insertion sort of the rows */
      for (i = k; i > p0 && g->ri[a][i - 1] > g->ri[a][i]; --i) { int t = g->ri[a][i]; g->ri[a][i] = g->ri[a][i - 1]; g->ri[a][i - 1] = t; }
    for (k = p0; k < nz; ++k) { g->cv[a][k] = col[g->ri[a][k]]; col[g->ri[a][k]] = 0.0; }
  }
  cnt[N] = nz;
  g->nz[a] = nz;
  g->M[a].n_rows = g->M[a].n_cols = N;
  g->M[a].colptr = g->cp[a]; g->M[a].rowidx = g->ri[a]; g->M[a].values = g->cv[a];
  free(pos); free(col); free(mark); free(tp); free(ti);
}

static int dsg_gcd(int a, int b) { while (b) { int t = a % b; a = b; b = t; } return a; }

/* The n x n grid (rlc_grid.py's model, values from dsg_val): port 0 at main
   (0, 0), port 1 at main (0, 1) (no capacitor: a port on a constraint) or
   (n-1, n-1); scramble: rows by i -> (ar i + br) mod N, states (columns of
   Q and E) by another such map; index2: the corner main (n-1, n-1) without
   capacitor and shunt (its constraint acts on inductor currents only). */
static void dsg_build(dsg_model *g, int n, int constraint_port, int scramble, int index2) {
  const int nm = n * n, ne = 2 * n * (n - 1), N = nm + 2 * ne, cap = 8 * ne + nm + 8;
  int *tr = (int *)malloc(sizeof(int) * (size_t)cap), *tc = (int *)malloc(sizeof(int) * (size_t)cap);
  double *tv = (double *)malloc(sizeof(double) * (size_t)cap);
  int *pr = (int *)malloc(sizeof(int) * (size_t)N), *pc = (int *)malloc(sizeof(int) * (size_t)N);
  int e = 0, i, k, nt = 0, ar = 7, ac = 11;
  memset(g, 0, sizeof *g);
  g->N = N; g->n = n;
  while (dsg_gcd(ar, N) != 1) ar += 2;   /* i -> (a i + b) mod N is a permutation for gcd(a, N) = 1 */
  while (dsg_gcd(ac, N) != 1) ac += 2;
  for (i = 0; i < N; ++i) { pr[(scramble ? ar * i + 3 : i) % N] = i; pc[(scramble ? ac * i + 5 : i) % N] = i; }
  /* pr[old] = new row, pc[old] = new column */
#define DSG_T(r, c, v) do { tr[nt] = (r); tc[nt] = (c); tv[nt] = (v); ++nt; } while (0)
  for (k = 0; k < 4; ++k) {
    nt = 0;
    for (e = 0; e < ne; ++e) {
      const int hz = e < n * (n - 1), q = hz ? e : e - n * (n - 1);
      const int a = hz ? (q / (n - 1)) * n + q % (n - 1) : q, b = hz ? a + 1 : a + n, m = nm + e, il = nm + ne + e;
      const double gg = 1.0 / dsg_val(3 * e);
      if (k == 0) { DSG_T(pr[m], pr[il], -1.0); DSG_T(pr[il], pr[m], 1.0); DSG_T(pr[b], pr[il], 1.0); DSG_T(pr[il], pr[b], -1.0); }
      if (k == 1) { DSG_T(pr[a], pr[a], gg); DSG_T(pr[a], pr[m], -gg); DSG_T(pr[m], pr[a], -gg); DSG_T(pr[m], pr[m], gg); }
      if (k == 3) DSG_T(pr[il], pc[il], dsg_val(3 * e + 1));
    }
    for (i = 0; i < nm; ++i) {
      const int corner = index2 && i == nm - 1, capd = (i / n + i % n) % 2 == 0 && !corner;
      if (k == 1 && !corner) DSG_T(pr[i], pr[i], 0.1 * dsg_val(5 * i + 2));
      if (k == 3 && capd) DSG_T(pr[i], pc[i], dsg_val(5 * i + 4));
    }
    if (k == 2) for (i = 0; i < N; ++i) DSG_T(pr[i], pc[i], 1.0);
    dsg_csc(g, k, tr, tc, tv, nt);
  }
#undef DSG_T
  g->B = (double *)calloc((size_t)N * 2, sizeof(double));
  g->B[pr[0]] = 1.0;
  g->B[N + pr[constraint_port ? 1 : nm - 1]] = 1.0;
  free(tr); free(tc); free(tv); free(pr); free(pc);
}

static void dsg_free(dsg_model *g) {
  int a;
  for (a = 0; a < 4; ++a) { free(g->cp[a]); free(g->ri[a]); free(g->cv[a]); }
  free(g->B);
}

/* Dense copy (column-major N x N) of matrix a. */
static double *dsg_dense(const dsg_model *g, int a) {
  double *D = (double *)calloc((size_t)g->N * g->N, sizeof(double));
  int j, p;
  for (j = 0; j < g->N; ++j)
    for (p = g->cp[a][j]; p < g->cp[a][j + 1]; ++p) D[g->ri[a][p] + (size_t)j * g->N] = g->cv[a][p];
  return D;
}

static void dsg_u(double t, double *u, void *user) {
  (void)user;
  u[0] = 0.1 * sin(1.3 * t + 0.4);
  u[1] = 0.1 * sin(0.7 * t + 0.3);
}

/* The DAE stepped on the sparse pencil (the sparse LU forced; states in the
   object's order, mapped back) equals the dense model's condensed path
   (GL3 on the condensed ODE, states lifted): outputs and states to 1e-10 of
   their size, on a scrambled 5 x 5 grid with a port on a constraint (the
   condensed model has feedthrough S > 0) and without. */
TEST(test_dae_sparse_equals_condensed) {
  int cport;
  for (cport = 0; cport < 2; ++cport) {
    dsg_model g;
    phgmg_ph_sparse *sp = NULL;
    phgmg_ph_sparse_info inf;
    phgmg_ph_system ds, ss;
    phgmg_dae *d = NULL;
    phgmg_gl3_stats st;
    const int steps = 60;
    double *Jd, *Rd, *Qd, *Ed, *X1, *X2, *XU, *Y1, *Y2, *x0, ym = 0.0, xm = 0.0, dy = 0.0, dx = 0.0;
    size_t i;
    int N;
    dsg_build(&g, 5, cport, 1, 0);
    N = g.N;
    Jd = dsg_dense(&g, 0); Rd = dsg_dense(&g, 1); Qd = dsg_dense(&g, 2); Ed = dsg_dense(&g, 3);
    memset(&ds, 0, sizeof ds);
    ds.N = N; ds.m = 2; ds.storage = PHGMG_DENSE; ds.nl = PHGMG_NL_NONE;
    ds.J = Jd; ds.R = Rd; ds.Q = Qd; ds.E = Ed; ds.B = g.B;
    CHECK_RC(phgmg_dae_create(&d, &ds, 0.0, NULL), PHGMG_OK);
    CHECK(phgmg_dae_nalg(d) == 12 + 40);   /* the 12 mains without capacitor and the 40 mid nodes */
    CHECK(cport ? phgmg_dae_system(d)->S != NULL : phgmg_dae_system(d)->S == NULL);
    phgmg_dae_destroy(d);
    CHECK_RC(phgmg_ph_sparse_create_e(&sp, N, 2, &g.M[0], &g.M[1], &g.M[2], &g.M[3], g.B, NULL, &inf, NULL), PHGMG_OK);
    CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_SPARSE_LU, &inf), PHGMG_OK);
    ss = *phgmg_ph_sparse_system(sp);
    CHECK(ss.storage == PHGMG_SPARSE);
    CHECK_RC(phgmg_ph_validate(&ss, 0.0, NULL, NULL), PHGMG_OK);
    X1 = (double *)malloc(sizeof(double) * (size_t)N * (steps + 1)); X2 = (double *)malloc(sizeof(double) * (size_t)N * (steps + 1));
    XU = (double *)malloc(sizeof(double) * (size_t)N * (steps + 1));
    Y1 = (double *)malloc(sizeof(double) * 2 * (steps + 1)); Y2 = (double *)malloc(sizeof(double) * 2 * (steps + 1));
    x0 = (double *)calloc((size_t)N, sizeof(double));
    CHECK_RC(phgmg_simulate(&ds, x0, 0.0, 0.05, steps, dsg_u, NULL, NULL, X1, Y1, NULL, NULL, NULL, NULL), PHGMG_OK);
    CHECK_RC(phgmg_simulate(&ss, x0, 0.0, 0.05, steps, dsg_u, NULL, NULL, X2, Y2, NULL, &st, NULL, NULL), PHGMG_OK);
    CHECK(st.sparse_lu == 1 && st.band_fallback == 0);
    CHECK_RC(phgmg_ph_sparse_to_user_order(sp, steps + 1, X2, N, XU, N), PHGMG_OK);
    for (i = 0; i < 2 * (size_t)(steps + 1); ++i) { ym = PHGMG__MAX(ym, fabs(Y1[i])); dy = PHGMG__MAX(dy, fabs(Y1[i] - Y2[i])); }
    for (i = 0; i < (size_t)N * (steps + 1); ++i) { xm = PHGMG__MAX(xm, fabs(X1[i])); dx = PHGMG__MAX(dx, fabs(X1[i] - XU[i])); }
    CHECK(ym > 1e-3 && xm > 1e-3);
    CHECK_LE(dy, 1e-10 * ym);
    CHECK_LE(dx, 1e-10 * xm);
    free(Jd); free(Rd); free(Qd); free(Ed); free(X1); free(X2); free(XU); free(Y1); free(Y2); free(x0);
    phgmg_ph_sparse_destroy(sp);
    dsg_free(&g);
  }
}

/* A 41 x 41 grid: 4 120 algebraic lines, beyond the dense condensation
   (4096; the validation refused it). The sparse object takes the sparse LU
   by itself, validates, and simulates: at every step the algebraic
   equations hold (the rows of E x' = (J - R) Q x + B u where E is zero, to
   1e-10 of their terms) and the discrete energy balance H(x_n) - H(x_0) =
   supplied - dissipated holds to 1e-10 of the energies involved. */
TEST(test_dae_sparse_beyond_condensation) {
  dsg_model g;
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_sparse_info inf;
  phgmg_ph_system ss;
  phgmg_energy en;
  const int steps = 12;
  double *X, *x0, *f, *H, *S, *D, u[2], worst = 0.0, scale = 0.0, eb = 0.0, es = 0.0;
  int N, n, i, *zr;
  dsg_build(&g, 41, 1, 0, 0);
  N = g.N;
  CHECK_RC(phgmg_ph_sparse_create_e(&sp, N, 2, &g.M[0], &g.M[1], &g.M[2], &g.M[3], g.B, NULL, &inf, NULL), PHGMG_OK);
  CHECK(inf.solver == PHGMG_SOLVER_SPARSE_LU);
  ss = *phgmg_ph_sparse_system(sp);
  CHECK_RC(phgmg_ph_validate(&ss, 0.0, NULL, NULL), PHGMG_OK);
  X = (double *)malloc(sizeof(double) * (size_t)N * (steps + 1));
  x0 = (double *)calloc((size_t)N, sizeof(double));
  f = (double *)malloc(sizeof(double) * (size_t)N);
  zr = (int *)calloc((size_t)N, sizeof(int));
  H = (double *)malloc(sizeof(double) * 3 * (steps + 1)); S = H + steps + 1; D = S + steps + 1;
  en.H = H; en.S = S; en.D = D;
  CHECK_RC(phgmg_simulate(&ss, x0, 0.0, 0.02, steps, dsg_u, NULL, NULL, X, NULL, &en, NULL, NULL, NULL), PHGMG_OK);
  for (i = 0; i < N; ++i) zr[i] = 1;
  for (i = 0; i < g.nz[3]; ++i) if (g.cv[3][i] != 0.0) zr[g.ri[3][i]] = 0;
  for (n = 0; n <= steps; ++n) {
    double *xu = (double *)malloc(sizeof(double) * (size_t)N);
    CHECK_RC(phgmg_ph_sparse_to_user_order(sp, 1, X + (size_t)n * N, N, xu, N), PHGMG_OK);
    {
      int j, p;   /* the residual in the user's order, from the model's own CSC */
      double *z = (double *)calloc((size_t)N, sizeof(double));
      dsg_u(0.02 * n, u, NULL);
      for (i = 0; i < N; ++i) f[i] = g.B[i] * u[0] + g.B[N + i] * u[1];
      for (j = 0; j < N; ++j) for (p = g.cp[2][j]; p < g.cp[2][j + 1]; ++p) z[g.ri[2][p]] += g.cv[2][p] * xu[j];
      for (j = 0; j < N; ++j) {
        for (p = g.cp[0][j]; p < g.cp[0][j + 1]; ++p) { f[g.ri[0][p]] += g.cv[0][p] * z[j]; if (zr[g.ri[0][p]]) scale = PHGMG__MAX(scale, fabs(g.cv[0][p] * z[j])); }
        for (p = g.cp[1][j]; p < g.cp[1][j + 1]; ++p) { f[g.ri[1][p]] -= g.cv[1][p] * z[j]; if (zr[g.ri[1][p]]) scale = PHGMG__MAX(scale, fabs(g.cv[1][p] * z[j])); }
      }
      for (i = 0; i < N; ++i) if (zr[i]) worst = PHGMG__MAX(worst, fabs(f[i]));
      free(z);
    }
    free(xu);
    eb = PHGMG__MAX(eb, fabs(H[n] - H[0] - (S[n] - D[n])));
    es = PHGMG__MAX(es, PHGMG__MAX(fabs(H[n]), PHGMG__MAX(fabs(S[n]), fabs(D[n]))));
  }
  CHECK(scale > 1e-4 && es > 1e-6);
  CHECK_LE(worst, 1e-10 * scale);
  CHECK_LE(eb, 1e-10 * es);
  free(X); free(x0); free(f); free(zr); free(H);
  phgmg_ph_sparse_destroy(sp);
  dsg_free(&g);
}

/* The corner main without capacitor and shunt: its constraint (the sum of
   the inductor currents into it, which is 0) acts on differential states
   only, L_aa has a zero row: index two, PHGMG_ERR_INDEX from the sparse
   validation and from the simulation, as from the dense one. */
TEST(test_dae_sparse_index_two) {
  dsg_model g;
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_sparse_info inf;
  phgmg_ph_system ss;
  double *x0;
  dsg_build(&g, 4, 0, 1, 1);
  x0 = (double *)calloc((size_t)g.N, sizeof(double));
  CHECK_RC(phgmg_ph_sparse_create_e(&sp, g.N, 2, &g.M[0], &g.M[1], &g.M[2], &g.M[3], g.B, NULL, &inf, NULL), PHGMG_OK);
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_SPARSE_LU, &inf), PHGMG_OK);
  ss = *phgmg_ph_sparse_system(sp);
  CHECK_RC(phgmg_ph_validate(&ss, 0.0, NULL, NULL), PHGMG_ERR_INDEX);
  CHECK_RC(phgmg_simulate(&ss, x0, 0.0, 0.05, 3, dsg_u, NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL),
           PHGMG_ERR_INDEX);
  free(x0);
  phgmg_ph_sparse_destroy(sp);
  dsg_free(&g);
}

SUITE(dae_sparse) {
  RUN(test_dae_sparse_equals_condensed);
  RUN(test_dae_sparse_beyond_condensation);
  RUN(test_dae_sparse_index_two);
}
