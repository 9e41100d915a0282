/* Reduction of SPARSE index-one descriptor models (manual 1.8): the
   condensed model built sparsely by phgmg_dae_create (per connected
   component of the algebraic block) against the dense condensation of the
   same model's dense copy (an independent path), matrix by matrix; the
   reduced models of both; a grid beyond 4096 algebraic lines; a port that
   acts only through a constraint (its condensed input column vanishes). */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>

typedef struct {
  int N, m, nm;
  phgmg_csc M[4];        /* J, R, Q, E in the user's (scrambled) order */
  double *D[4];          /* their dense copies */
  double *B, *P, S[9], Nk[9];
  int feed;              /* P, S, Nskew set */
} dsr_model;

static double dsr_val(int k) { return 0.5 + fmod(0.7548776662466927 * (double)(k + 1), 1.0); }
static int dsr_gcd(int a, int b) { while (b) { int t = a % b; a = b; b = t; } return a; }

typedef struct { int n, cap, *r[4], *c[4]; double *v[4]; int nt[4]; } dsr_trip;
static void dsr_add(dsr_trip *t, int a, int r, int c, double v) {
  t->r[a][t->nt[a]] = r; t->c[a][t->nt[a]] = c; t->v[a][t->nt[a]++] = v;
}

/* The triplets into CSC and (N <= 2000) dense copies; frees the triplets. */
static void dsr_finish(dsr_model *g, dsr_trip *t) {
  int a, k;
  for (a = 0; a < 4; ++a) {
    CHECK_RC(phgmg_csc_from_coo(&g->M[a], g->N, g->N, t->nt[a], t->r[a], t->c[a], t->v[a], NULL), PHGMG_OK);
    g->D[a] = g->N <= 2000 ? (double *)calloc((size_t)g->N * g->N, sizeof(double)) : NULL; /* small models */
    for (k = 0; g->D[a] && k < t->nt[a]; ++k) g->D[a][t->r[a][k] + (size_t)t->c[a][k] * g->N] += t->v[a][k];
    free(t->r[a]); free(t->c[a]); free(t->v[a]);
  }
}

static void dsr_trip_init(dsr_trip *t, int cap) {
  int a;
  memset(t, 0, sizeof *t);
  for (a = 0; a < 4; ++a) {
    t->r[a] = (int *)malloc(sizeof(int) * (size_t)cap); t->c[a] = (int *)malloc(sizeof(int) * (size_t)cap);
    t->v[a] = (double *)malloc(sizeof(double) * (size_t)cap);
  }
}

/* rlc_grid.py's n x n (here n x w) grid (mains, a resistor, a mid node and an inductor
   on every edge, shunts, capacitors on the mains with i + j even), rows and
   states scrambled. cport: port 1 at main (0, 1) (no capacitor) instead of
   (n-1, n-1). qmix: Q not diagonal (E Q symmetric couplings between a
   capacitive main and its inductors, Q[mid, inductor] = 0.3 (Q_ad), Q[main,
   mid] = 0.2 on the algebraic mains (Q_ac)). feed: the full model has P, S
   and Nskew. vanish: one more node with only a shunt (no capacitor, no
   other element) and a third port there: a current source on a resistor,
   whose condensed input column is zero. */
static void dsr_build_w(dsr_model *g, int n, int w, int cport, int qmix, int feed, int vanish) {
  const int nm = n * w, nh = n * (w - 1), ne = nh + (n - 1) * w, N = nm + 2 * ne + (vanish ? 1 : 0), m = vanish ? 3 : 2;
  int *pr = (int *)malloc(sizeof(int) * (size_t)N), *pc = (int *)malloc(sizeof(int) * (size_t)N);
  double *ev = (double *)calloc((size_t)N, sizeof(double));
  int e, i, ar = 7, ac = 11;
  dsr_trip t;
  memset(g, 0, sizeof *g);
  g->N = N; g->m = m; g->nm = nm; g->feed = feed;
  while (dsr_gcd(ar, N) != 1) ar += 2;
  while (dsr_gcd(ac, N) != 1) ac += 2;
  for (i = 0; i < N; ++i) { pr[(ar * i + 3) % N] = i; pc[(ac * i + 5) % N] = i; }
  dsr_trip_init(&t, 12 * ne + 4 * nm + 16);
  for (i = 0; i < nm; ++i) if ((i / w + i % w) % 2 == 0) ev[i] = dsr_val(5 * i + 4);
  for (e = 0; e < ne; ++e) ev[nm + ne + e] = dsr_val(3 * e + 1);
  for (e = 0; e < ne; ++e) {
    const int hz = e < nh, q = hz ? e : e - nh;
    const int a = hz ? (q / (w - 1)) * w + q % (w - 1) : q, b = hz ? a + 1 : a + w, md = nm + e, il = nm + ne + e;
    const double gg = 1.0 / dsr_val(3 * e);
    dsr_add(&t, 0, pr[md], pr[il], -1.0); dsr_add(&t, 0, pr[il], pr[md], 1.0);
    dsr_add(&t, 0, pr[b], pr[il], 1.0); dsr_add(&t, 0, pr[il], pr[b], -1.0);
    dsr_add(&t, 1, pr[a], pr[a], gg); dsr_add(&t, 1, pr[a], pr[md], -gg);
    dsr_add(&t, 1, pr[md], pr[a], -gg); dsr_add(&t, 1, pr[md], pr[md], gg);
    dsr_add(&t, 3, pr[il], pc[il], ev[il]);
    dsr_add(&t, 2, pr[il], pc[il], 1.0);
    dsr_add(&t, 2, pr[md], pc[md], 1.0);
    if (qmix) {
      dsr_add(&t, 2, pr[md], pc[il], 0.3);
      if (ev[a] != 0.0) {
        const double s = 0.05 * dsr_val(7 * e);
        dsr_add(&t, 2, pr[a], pc[il], s / ev[a]); dsr_add(&t, 2, pr[il], pc[a], s / ev[il]);
      } else dsr_add(&t, 2, pr[a], pc[md], 0.2);
    }
  }
  for (i = 0; i < nm; ++i) {
    dsr_add(&t, 1, pr[i], pr[i], 0.1 * dsr_val(5 * i + 2));
    dsr_add(&t, 2, pr[i], pc[i], 1.0);
    if (ev[i] != 0.0) dsr_add(&t, 3, pr[i], pc[i], ev[i]);
  }
  if (vanish) { dsr_add(&t, 1, pr[N - 1], pr[N - 1], 0.5); dsr_add(&t, 2, pr[N - 1], pc[N - 1], 1.0); }
  dsr_finish(g, &t);
  g->B = (double *)calloc((size_t)N * m, sizeof(double));
  g->P = (double *)calloc((size_t)N * m, sizeof(double));
  g->B[pr[0]] = 1.0;
  g->B[N + pr[cport ? 1 : nm - 1]] = 1.0;
  if (vanish) g->B[2 * (size_t)N + pr[N - 1]] = 1.0;
  if (feed) {   /* [[R, P], [P^T, S]] >= 0: R >= the shunts (>= 0.05) on the mains */
    g->P[pr[0]] = 0.01;
    g->P[N + pr[cport ? 1 : nm - 1]] = 0.01;
    for (i = 0; i < m; ++i) g->S[i + i * m] = 0.3 - 0.05 * i;
    g->Nk[m] = 0.1; g->Nk[1] = -0.1;
  }
  free(pr); free(pc); free(ev);
}
static void dsr_build(dsr_model *g, int n, int cport, int qmix, int feed, int vanish) {
  dsr_build_w(g, n, n, cport, qmix, feed, vanish);
}

/* A chain of K algebraic nodes (resistors between neighbours, shunts), nc
   capacitive nodes each tied by a resistor to one chain node, inductors
   between consecutive capacitive nodes; port 0 on capacitor 0, port 1 on
   chain node K/2: one algebraic component of K lines (the sparse LU's). */
static void dsr_chain(dsr_model *g, int K, int nc) {
  const int N = K + 2 * nc - 1, m = 2;
  int i, j;
  dsr_trip t;
  memset(g, 0, sizeof *g);
  g->N = N; g->m = m;
  dsr_trip_init(&t, 6 * N + 8 * nc + 16);
  for (i = 0; i < K; ++i) {
    dsr_add(&t, 1, i, i, 0.1 * dsr_val(i));
    if (i + 1 < K) {
      const double gg = 1.0 / dsr_val(3 * i + 1);
      dsr_add(&t, 1, i, i, gg); dsr_add(&t, 1, i + 1, i + 1, gg);
      dsr_add(&t, 1, i, i + 1, -gg); dsr_add(&t, 1, i + 1, i, -gg);
    }
  }
  for (j = 0; j < nc; ++j) {
    const int c = K + j, a = (int)((long)j * K / nc), il = K + nc + j;
    const double gg = 1.0 / dsr_val(5 * j + 2);
    dsr_add(&t, 1, c, c, gg); dsr_add(&t, 1, a, a, gg); dsr_add(&t, 1, c, a, -gg); dsr_add(&t, 1, a, c, -gg);
    dsr_add(&t, 3, c, c, dsr_val(7 * j));
    if (j + 1 < nc) {
      dsr_add(&t, 0, c, il, -1.0); dsr_add(&t, 0, il, c, 1.0);
      dsr_add(&t, 0, c + 1, il, 1.0); dsr_add(&t, 0, il, c + 1, -1.0);
      dsr_add(&t, 3, il, il, dsr_val(11 * j));
    }
  }
  for (i = 0; i < N; ++i) dsr_add(&t, 2, i, i, 1.0);
  dsr_finish(g, &t);
  g->B = (double *)calloc((size_t)N * m, sizeof(double));
  g->P = (double *)calloc((size_t)N * m, sizeof(double));
  g->B[K] = 1.0;
  g->B[N + K / 2] = 1.0;
}

static void dsr_free(dsr_model *g) {
  int a;
  for (a = 0; a < 4; ++a) { phgmg_csc_free(&g->M[a], NULL); free(g->D[a]); }
  free(g->B); free(g->P);
}

static phgmg_ph_system dsr_dense(const dsr_model *g) {
  phgmg_ph_system s;
  memset(&s, 0, sizeof s);
  s.N = g->N; s.m = g->m; s.storage = PHGMG_DENSE; s.nl = PHGMG_NL_NONE;
  s.J = g->D[0]; s.R = g->D[1]; s.Q = g->D[2]; s.E = g->D[3]; s.B = g->B;
  if (g->feed) { s.P = g->P; s.S = g->S; s.Nskew = g->Nk; }
  return s;
}

/* The sparse object on the sparse LU and its system (P in its order). */
static phgmg_ph_sparse *dsr_sparse(const dsr_model *g, phgmg_ph_system *s, double *Pint) {
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_sparse_info inf;
  CHECK_RC(phgmg_ph_sparse_create_e(&sp, g->N, g->m, &g->M[0], &g->M[1], &g->M[2], &g->M[3], g->B, NULL, &inf, NULL),
           PHGMG_OK);
  if (!sp) return NULL;
  CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_SPARSE_LU, &inf), PHGMG_OK);
  *s = *phgmg_ph_sparse_system(sp);
  if (g->feed) {
    CHECK_RC(phgmg_ph_sparse_to_banded_order(sp, g->m, g->P, g->N, Pint, g->N), PHGMG_OK);
    s->P = Pint; s->S = g->S; s->Nskew = g->Nk;
  }
  return sp;
}

/* max |A - B| over n x n (or n x m) against the larger max |entry|. */
static double dsr_rel(size_t len, const double *A, const double *B) {
  double d = 0.0, s = 0.0;
  size_t i;
  for (i = 0; i < len; ++i) {
    const double a = A ? A[i] : 0.0, b = B ? B[i] : 0.0;
    d = PHGMG__MAX(d, fabs(a - b));
    s = PHGMG__MAX(s, PHGMG__MAX(fabs(a), fabs(b)));
  }
  return s > 0.0 ? d / s : d;
}

/* The sparse-condensed model (ds, of the sparse object sp) against the
   dense-condensed one (dd, of the dense copy): each matrix moved to dd's
   order through both objects' maps, worst relative difference. */
static double dsr_compare(const phgmg_dae *dd, const phgmg_dae *ds, const phgmg_ph_sparse *sp) {
  const int N = dd->N, n = dd->n, m = dd->m;
  const int *pf = phgmg_ph_sparse_perm(sp);
  const phgmg_ph_sparse *cs = ds->csp;
  int *ur = (int *)malloc(sizeof(int) * (size_t)n), *uc = (int *)malloc(sizeof(int) * (size_t)n), i, j, a, p, l;
  double *T = (double *)malloc(sizeof(double) * (size_t)n * n), worst = 0.0;
  const double *dm[4];
  dm[0] = dd->sys.J; dm[1] = dd->sys.R; dm[2] = dd->sys.Q; dm[3] = dd->sys.E;
  for (i = 0; i < N; ++i) { /* full internal i is user pf[i] */
    if (ds->rpos[i] >= 0) ur[ds->rpos[i]] = pf[i];
    if (ds->cpos[i] >= 0) uc[ds->cpos[i]] = pf[i];
  }
  for (a = 0; a < 4; ++a) {
    memset(T, 0, sizeof(double) * (size_t)n * n);
    for (j = 0; j < n; ++j)
      for (p = cs->cp[a][j]; p < cs->cp[a][j + 1]; ++p) {
        const int r = dd->rpos[ur[cs->ci[a][p]]], c = a < 2 ? dd->rpos[ur[j]] : dd->cpos[uc[j]];
        T[r + (size_t)c * n] = cs->cx[a][p];
      }
    worst = PHGMG__MAX(worst, dsr_rel((size_t)n * n, T, dm[a]));
  }
  {   /* [B', P'] and [S', N'], each pair against its larger entry (P' may be round-off) */
    double *Rf = (double *)calloc(2 * (size_t)n * m, sizeof(double)), *Tf = (double *)calloc(2 * (size_t)n * m, sizeof(double));
    double ss[18], sd[18];
    for (a = 0; a < 2; ++a) {
      const double *src = a ? ds->sys.P : ds->sys.B, *ref = a ? dd->sys.P : dd->sys.B;
      for (l = 0; l < m; ++l)
        for (i = 0; i < n; ++i) {
          Tf[dd->rpos[ur[i]] + (size_t)(a * m + l) * n] = src ? src[i + (size_t)l * n] : 0.0;
          Rf[i + (size_t)(a * m + l) * n] = ref ? ref[i + (size_t)l * n] : 0.0;
        }
      for (i = 0; i < m * m; ++i) {
        const double *s1 = a ? ds->sys.Nskew : ds->sys.S, *s2 = a ? dd->sys.Nskew : dd->sys.S;
        ss[a * m * m + i] = s1 ? s1[i] : 0.0;
        sd[a * m * m + i] = s2 ? s2[i] : 0.0;
      }
    }
    worst = PHGMG__MAX(worst, dsr_rel(2 * (size_t)n * m, Tf, Rf));
    worst = PHGMG__MAX(worst, dsr_rel(2 * (size_t)m * m, ss, sd));
    free(Rf); free(Tf);
  }
  free(ur); free(uc); free(T);
  return worst;
}

/* Sparse condensation = dense condensation (J', R', Q', E', B', P', S', N'
   to 1e-12 relative) on scrambled grids with and without a port on a
   constraint, Q diagonal or not, feedthrough in the full model or not, and
   on a chain whose 300 algebraic lines form one component (the sparse LU's
   path); the condensed sparse model validates. */
TEST(test_dae_sparse_reduce_matrices) {
  int cfg;
  for (cfg = 0; cfg < 6; ++cfg) {
    dsr_model g;
    phgmg_ph_system s, ss;
    phgmg_ph_sparse *sp;
    phgmg_dae *dd = NULL, *ds = NULL;
    double *Pint;
    if (cfg < 5) dsr_build(&g, 4, cfg & 1, (cfg >> 1) & 1, cfg >= 3, cfg == 4);
    else dsr_chain(&g, 300, 12);
    Pint = (double *)calloc((size_t)g.N * g.m, sizeof(double));
    s = dsr_dense(&g);
    sp = dsr_sparse(&g, &ss, Pint);
    CHECK_RC(phgmg_dae_create(&dd, &s, 0.0, NULL), PHGMG_OK);
    CHECK_RC(phgmg_dae_create(&ds, &ss, 0.0, NULL), PHGMG_OK);
    if (dd && ds) {
      const double w = dsr_compare(dd, ds, sp);
      if (getenv("DAE_VERBOSE")) printf("cfg %d: n %d k %d worst %.3e\n", cfg, dd->n, dd->k, w);
      CHECK(phgmg_dae_nalg(ds) == phgmg_dae_nalg(dd) && phgmg_dae_system(ds)->N == phgmg_dae_system(dd)->N);
      CHECK(phgmg_dae_system(ds)->sparse != NULL && phgmg_dae_system(ds)->E != NULL);
      CHECK_LE(w, 1e-12);
      CHECK_RC(phgmg_ph_validate(phgmg_dae_system(ds), 0.0, NULL, NULL),   /* B' rank deficient alike */
               phgmg_ph_validate(phgmg_dae_system(dd), 0.0, NULL, NULL));
      CHECK(phgmg_dae_system(ds)->sparse == phgmg_ph_sparse_system(ds->csp)->sparse);
      CHECK((phgmg_dae_system(ds)->S != NULL) == (phgmg_dae_system(dd)->S != NULL));
    }
    phgmg_dae_destroy(dd); phgmg_dae_destroy(ds);
    phgmg_ph_sparse_destroy(sp);
    free(Pint);
    dsr_free(&g);
  }
}

static void dsr_u(double t, double *u, void *user) {
  const int m = *(const int *)user;
  u[0] = 0.5 * sin(1.3 * t + 0.4) + 0.3 * sin(3.1 * t);
  u[1] = 0.5 * sin(0.7 * t + 0.3) + 0.2 * cos(2.3 * t);
  if (m > 2) u[2] = 0.4 * sin(1.9 * t + 0.1);
}

/* The full model's outputs and states (user order) from the dense copy. */
static void dsr_run(const dsr_model *g, int ns, double dt, double *X, double *Y) {
  phgmg_ph_system s = dsr_dense(g);
  double *x0 = (double *)calloc((size_t)g->N, sizeof(double));
  CHECK_RC(phgmg_simulate(&s, x0, 0.0, dt, ns, dsr_u, (void *)&g->m, NULL, X, Y, NULL, NULL, NULL, NULL), PHGMG_OK);
  free(x0);
}

/* A reduced model's structure: J skew, R >= 0 (K + K^T <= 0), Qh > 0. */
static void dsr_check_ph(const phgmg_reduced *red, int r) {
  const phgmg_rom *rom = phgmg_reduced_rom(red);
  phgmg_real *work = (phgmg_real *)calloc(phgmg_rom_eval_work_size(rom) + 1, sizeof(phgmg_real));
  double *Jr = (double *)malloc(sizeof(double) * 3 * (size_t)r * r), *Rr = Jr + (size_t)r * r, *H = Rr + (size_t)r * r;
  double *w = (double *)malloc(sizeof(double) * (size_t)r), *x = (double *)calloc((size_t)r, sizeof(double));
  int i, j;
  CHECK_RC(phgmg_rom_structure(rom, x, Jr, Rr, work), PHGMG_OK);
  phgmg_rom_hessian(rom, x, H, work);
  for (j = 0; j < r; ++j)
    for (i = 0; i < r; ++i) CHECK_LE(fabs(Jr[i + j * r] + Jr[j + i * r]), 1e-12 * (1.0 + fabs(Jr[i + j * r])));
  CHECK_RC(phgmg_sym_eig(r, Rr, r, w, NULL, 0), PHGMG_OK);
  CHECK(w[0] >= -1e-10 * PHGMG__MAX(1.0, w[r - 1]));
  CHECK_RC(phgmg_sym_eig(r, H, r, w, NULL, 0), PHGMG_OK);
  CHECK(w[0] > 0.0);
  free(work); free(Jr); free(w); free(x);
}

/* Output error of red against Y (relative, max norm), and its outputs. */
static double dsr_red_err(const phgmg_reduced *red, int ns, double dt, int m, const double *Y, double *YR) {
  double xr[64] = {0};
  CHECK_RC(phgmg_reduced_simulate(red, xr, 0.0, dt, ns, dsr_u, (void *)&m, 0.0, 0, NULL, YR, NULL, NULL, NULL),
           PHGMG_OK);
  return dsr_rel((size_t)m * (ns + 1), YR, Y);
}

/* GMG-POD and SP1 reduced models built from the sparse-condensed model
   equal those from the dense-condensed one (outputs to 1e-10 of their size
   over the training run), are port-Hamiltonian, and their output error
   against the full model falls with r. Scrambled 5 x 5 grid, port on a
   constraint, Q not diagonal, feedthrough. */
TEST(test_dae_sparse_reduce_roms) {
  const int ns = 240, rr[3] = {6, 12, 20};
  const double dt = 0.05;
  dsr_model g;
  phgmg_ph_system s, ss;
  phgmg_ph_sparse *sp;
  phgmg_dae *dd = NULL, *ds = NULL;
  double *X, *XI, *Xd, *Xs, *Y, *Y1, *Y2, *Pint;
  int meth, ri, k, n;
  dsr_build(&g, 5, 1, 1, 1, 0);
  X = (double *)malloc(sizeof(double) * (size_t)g.N * (ns + 1)); XI = (double *)malloc(sizeof(double) * (size_t)g.N * (ns + 1));
  Y = (double *)malloc(sizeof(double) * 3 * (size_t)g.m * (ns + 1)); Y1 = Y + (size_t)g.m * (ns + 1); Y2 = Y1 + (size_t)g.m * (ns + 1);
  Pint = (double *)calloc((size_t)g.N * g.m, sizeof(double));
  dsr_run(&g, ns, dt, X, Y);
  s = dsr_dense(&g);
  sp = dsr_sparse(&g, &ss, Pint);
  CHECK_RC(phgmg_dae_create(&dd, &s, 0.0, NULL), PHGMG_OK);
  CHECK_RC(phgmg_dae_create(&ds, &ss, 0.0, NULL), PHGMG_OK);
  if (!dd || !ds || !sp) { free(X); free(XI); free(Y); free(Pint); dsr_free(&g); return; }
  n = phgmg_dae_system(dd)->N;
  Xd = (double *)malloc(sizeof(double) * (size_t)n * (ns + 1)); Xs = (double *)malloc(sizeof(double) * (size_t)n * (ns + 1));
  CHECK_RC(phgmg_ph_sparse_to_banded_order(sp, ns + 1, X, g.N, XI, g.N), PHGMG_OK);
  for (k = 0; k <= ns; ++k) {
    phgmg_dae_restrict(dd, X + (size_t)k * g.N, Xd + (size_t)k * n);
    phgmg_dae_restrict(ds, XI + (size_t)k * g.N, Xs + (size_t)k * n);
  }
  {   /* the lift of a restricted (consistent) state is the state; embed puts x_d back, 0 elsewhere */
    double *xl = (double *)malloc(sizeof(double) * (size_t)g.N), u[3], dl = 0.0, xm = 0.0;
    int i, nz = 0;
    for (k = 0; k <= ns; k += 40) {
      dsr_u(dt * k, u, (void *)&g.m);
      CHECK_RC(phgmg_dae_lift(ds, Xs + (size_t)k * n, u, xl), PHGMG_OK);
      for (i = 0; i < g.N; ++i) {
        dl = PHGMG__MAX(dl, fabs(xl[i] - XI[i + (size_t)k * g.N]));
        xm = PHGMG__MAX(xm, fabs(XI[i + (size_t)k * g.N]));
      }
    }
    CHECK(xm > 1e-3);
    CHECK_LE(dl, 1e-10 * xm);
    CHECK_RC(phgmg_dae_embed(ds, Xs + (size_t)ns * n, xl), PHGMG_OK);
    for (i = 0; i < g.N; ++i) nz += xl[i] != 0.0 && xl[i] == XI[i + (size_t)ns * g.N];
    CHECK(nz == n);
    free(xl);
  }
  for (meth = 0; meth < 2; ++meth) {
    double e[3];
    for (ri = 0; ri < 3; ++ri) {
      phgmg_reduce_opts o;
      phgmg_reduced *r1 = NULL, *r2 = NULL;
      phgmg_reduce_opts_default(&o);
      o.method = meth ? PHGMG_METHOD_SP1 : PHGMG_METHOD_GMG_POD;
      o.r = rr[ri];
      CHECK_RC(phgmg_reduce(&r1, phgmg_dae_system(dd), Xd, n, ns + 1, &o, NULL, NULL), PHGMG_OK);
      CHECK_RC(phgmg_reduce(&r2, phgmg_dae_system(ds), Xs, n, ns + 1, &o, NULL, NULL), PHGMG_OK);
      e[ri] = HUGE_VAL;
      if (r1 && r2) {
        e[ri] = dsr_red_err(r1, ns, dt, g.m, Y, Y1);
        dsr_red_err(r2, ns, dt, g.m, Y, Y2);
        if (getenv("DAE_VERBOSE")) printf("method %d r %d e %.3e d %.3e\n", meth, rr[ri], e[ri], dsr_rel((size_t)g.m * (ns + 1), Y1, Y2));
        CHECK_LE(dsr_rel((size_t)g.m * (ns + 1), Y1, Y2), 1e-10);
        dsr_check_ph(r2, rr[ri]);
      }
      phgmg_reduced_destroy(r1); phgmg_reduced_destroy(r2);
    }
    CHECK(e[1] <= e[0] && e[2] <= e[1] && e[2] < 0.5 * e[0]);
  }
  free(X); free(XI); free(Y); free(Xd); free(Xs); free(Pint);
  phgmg_dae_destroy(dd); phgmg_dae_destroy(ds);
  phgmg_ph_sparse_destroy(sp);
  dsr_free(&g);
}

/* A 3 x 701 grid: 4 553 algebraic lines (1 051 mains without capacitor,
   3 502 mid nodes), beyond the dense condensation's 4 096, condensed
   sparsely by phgmg_dae_create; GMG-POD with r = 10 from 40 steps of the
   DAE on its sparse pencil (the snapshots restricted to x_d) follows the
   full model's outputs (1e-2 of their size), is port-Hamiltonian, and the
   lift of the restricted final state is the final state (consistent). */
TEST(test_dae_sparse_reduce_large) {
  const int ns = 40;
  const double dt = 0.05;
  dsr_model g;
  phgmg_ph_system ss;
  phgmg_ph_sparse *sp;
  phgmg_dae *ds = NULL;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  double *X, *Xs = NULL, *Y, *YR, *x0, *Pint, u[2];
  int k, n;
  dsr_build_w(&g, 3, 701, 0, 0, 0, 0);
  X = (double *)malloc(sizeof(double) * (size_t)g.N * (ns + 1));
  Y = (double *)malloc(sizeof(double) * 4 * (ns + 1)); YR = Y + 2 * (ns + 1);
  x0 = (double *)calloc((size_t)g.N, sizeof(double));
  Pint = (double *)calloc((size_t)g.N * g.m, sizeof(double));
  sp = dsr_sparse(&g, &ss, Pint);
  CHECK_RC(phgmg_simulate(&ss, x0, 0.0, dt, ns, dsr_u, (void *)&g.m, NULL, X, Y, NULL, NULL, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_dae_create(&ds, &ss, 0.0, NULL), PHGMG_OK);
  if (ds) {
    n = phgmg_dae_system(ds)->N;
    CHECK(phgmg_dae_nalg(ds) == 4553 && n == g.N - 4553);
    Xs = (double *)malloc(sizeof(double) * (size_t)n * (ns + 1));
    for (k = 0; k <= ns; ++k) phgmg_dae_restrict(ds, X + (size_t)k * g.N, Xs + (size_t)k * n);
    phgmg_reduce_opts_default(&o);
    o.method = PHGMG_METHOD_GMG_POD;
    o.r = 10;
    CHECK_RC(phgmg_reduce(&red, phgmg_dae_system(ds), Xs, n, ns + 1, &o, NULL, NULL), PHGMG_OK);
    if (red) {
      const double e = dsr_red_err(red, ns, dt, 2, Y, YR);
      if (getenv("DAE_VERBOSE")) printf("large: e %.3e\n", e);
      CHECK_LE(e, 1e-2);
      dsr_check_ph(red, 10);
    }
    dsr_u(dt * ns, u, (void *)&g.m);
    CHECK_RC(phgmg_dae_lift(ds, Xs + (size_t)ns * n, u, x0), PHGMG_OK);
    CHECK_LE(dsr_rel((size_t)g.N, x0, X + (size_t)ns * g.N), 1e-10);
  }
  phgmg_reduced_destroy(red);
  phgmg_dae_destroy(ds);
  phgmg_ph_sparse_destroy(sp);
  free(X); free(Xs); free(Y); free(x0); free(Pint);
  dsr_free(&g);
}

/* A port that acts only through a constraint: a current source on a node
   with only a shunt conductance 0.5 (no capacitor, no other element). Its
   condensed input column vanishes and it becomes pure feedthrough, S'(2, 2)
   = 1/0.5 = 2. GMG-POD refuses (PHGMG_ERR_RANK, info.rank_port = 2: the
   port named); SP1 and SP2 reduce it: their models are port-Hamiltonian and
   follow the full model's three outputs (1e-5 of their size at r = 20). */
TEST(test_dae_sparse_reduce_vanishing_port) {
  const int ns = 200, m = 3;
  const double dt = 0.05;
  dsr_model g;
  phgmg_ph_system ss;
  phgmg_ph_sparse *sp;
  phgmg_dae *ds = NULL;
  double *X, *XI, *Xs = NULL, *Y, *YR, *Pint;
  int k, n, i, meth;
  dsr_build(&g, 5, 0, 0, 0, 1);
  X = (double *)malloc(sizeof(double) * (size_t)g.N * (ns + 1)); XI = (double *)malloc(sizeof(double) * (size_t)g.N * (ns + 1));
  Y = (double *)malloc(sizeof(double) * 2 * m * (ns + 1)); YR = Y + (size_t)m * (ns + 1);
  Pint = (double *)calloc((size_t)g.N * g.m, sizeof(double));
  dsr_run(&g, ns, dt, X, Y);
  sp = dsr_sparse(&g, &ss, Pint);
  CHECK_RC(phgmg_dae_create(&ds, &ss, 0.0, NULL), PHGMG_OK);
  if (ds && sp) {
    const phgmg_ph_system *c = phgmg_dae_system(ds);
    double bmax = 0.0, b2 = 0.0;
    n = c->N;
    for (i = 0; i < n; ++i) {
      bmax = PHGMG__MAX(bmax, PHGMG__MAX(fabs(c->B[i]), fabs(c->B[i + n])));
      b2 = PHGMG__MAX(b2, fabs(c->B[i + 2 * (size_t)n]));
    }
    CHECK(bmax > 0.5 && b2 == 0.0);
    CHECK(c->S != NULL);
    if (c->S) CHECK_LE(fabs(c->S[8] - 2.0), 1e-14);
    Xs = (double *)malloc(sizeof(double) * (size_t)n * (ns + 1));
    CHECK_RC(phgmg_ph_sparse_to_banded_order(sp, ns + 1, X, g.N, XI, g.N), PHGMG_OK);
    for (k = 0; k <= ns; ++k) phgmg_dae_restrict(ds, XI + (size_t)k * g.N, Xs + (size_t)k * n);
    for (meth = 0; meth < 3; ++meth) {
      phgmg_reduce_opts o;
      phgmg_reduce_info inf;
      phgmg_reduced *red = NULL;
      phgmg_reduce_opts_default(&o);
      o.method = meth == 0 ? PHGMG_METHOD_GMG_POD : meth == 1 ? PHGMG_METHOD_SP1 : PHGMG_METHOD_SP2;
      o.r = 20;
      memset(&inf, 0, sizeof inf);
      CHECK_RC(phgmg_reduce(&red, c, Xs, n, ns + 1, &o, &inf, NULL), meth == 0 ? PHGMG_ERR_RANK : PHGMG_OK);
      CHECK(inf.rank_port == (meth == 0 ? 2 : -1));
      if (red) {
        const double e = dsr_red_err(red, ns, dt, m, Y, YR);
        if (getenv("DAE_VERBOSE")) printf("vanishing port: method %d e %.3e\n", meth, e);
        CHECK_LE(e, 1e-5);
        dsr_check_ph(red, 20);
      }
      phgmg_reduced_destroy(red);
    }
  }
  phgmg_dae_destroy(ds);
  phgmg_ph_sparse_destroy(sp);
  free(X); free(XI); free(Xs); free(Y); free(Pint);
  dsr_free(&g);
}

/* An allocator that fails after a given number of allocations and counts
   the blocks still held. */
typedef struct { int left; long live; } dsr_fail_alloc;
static void *dsr_falloc(size_t size, void *user) {
  dsr_fail_alloc *f = (dsr_fail_alloc *)user;
  void *p;
  if (f->left-- <= 0) return NULL;
  p = malloc(size);
  if (p) f->live++;
  return p;
}
static void dsr_ffree(void *p, void *user) {
  if (!p) return;
  ((dsr_fail_alloc *)user)->live--;
  free(p);
}

/* Out of memory at every allocation of the sparse condensation in turn:
   PHGMG_ERR_NOMEM, no object, every block returned; with enough memory the
   same call succeeds (scrambled 3 x 3 grid, port on a constraint, Q not
   diagonal, feedthrough). */
TEST(test_dae_sparse_reduce_nomem) {
  dsr_model g;
  phgmg_ph_system ss;
  phgmg_ph_sparse *sp;
  double *Pint;
  int k, done = 0;
  dsr_build(&g, 3, 1, 1, 1, 0);
  Pint = (double *)calloc((size_t)g.N * g.m, sizeof(double));
  sp = dsr_sparse(&g, &ss, Pint);
  CHECK_RC(phgmg_ph_validate(&ss, 0.0, NULL, NULL), PHGMG_OK);   /* the object's checks cached first */
  for (k = 0; k < 5000 && !done; ++k) {
    dsr_fail_alloc f;
    phgmg_allocator al;
    phgmg_dae *d = NULL;
    phgmg_result rc;
    f.left = k; f.live = 0;
    al.alloc = dsr_falloc; al.free = dsr_ffree; al.user = &f;
    rc = phgmg_dae_create(&d, &ss, 0.0, &al);
    if (rc == PHGMG_OK) done = 1;
    else {
      CHECK_RC(rc, PHGMG_ERR_NOMEM);
      CHECK(d == NULL);
    }
    phgmg_dae_destroy(d);
    CHECK(f.live == 0);
    if (f.live != 0 || (rc != PHGMG_OK && rc != PHGMG_ERR_NOMEM)) break;
  }
  CHECK(done && k > 20);
  phgmg_ph_sparse_destroy(sp);
  free(Pint);
  dsr_free(&g);
}

SUITE(dae_sparse_reduce) {
  RUN(test_dae_sparse_reduce_matrices);
  RUN(test_dae_sparse_reduce_roms);
  RUN(test_dae_sparse_reduce_large);
  RUN(test_dae_sparse_reduce_vanishing_port);
  RUN(test_dae_sparse_reduce_nomem);
}
