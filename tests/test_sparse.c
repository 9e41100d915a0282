/* Sparse input (phgmg_csc, phgmg_rcm, phgmg_ph_sparse_*): reverse Cuthill-McKee
   on graphs with known bandwidths, the paper's nonlinear chain given as CSC in
   the paper's [l; v] ordering and in a scrambled ordering against the dense
   and hand-banded models (FOM trajectories and reduced models), bad input. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include "../examples/msd_models.h"

/* ---- helpers ------------------------------------------------------------------ */
/* A CSC matrix owning its arrays. */
typedef struct tcsc {
  phgmg_csc A;
  int *cp, *ri;
  double *v;
} tcsc;
static void tcsc_free(tcsc *t) { free(t->cp); free(t->ri); free(t->v); memset(t, 0, sizeof *t); }
/* From a dense column-major nr x nc matrix D (entry (i,j) = D[i + j nr]) whose
   rows and columns are taken through rp, cp (NULL: identity): the CSC of
   A(i,j) = D(rp[i], cp[j]), nonzeros only. */
static void tcsc_from_dense(tcsc *t, int nr, int nc, const double *D, const int *rp, const int *cpm) {
  int i, j, nnz = 0;
  t->cp = (int *)malloc(sizeof(int) * (size_t)(nc + 1));
  t->ri = (int *)malloc(sizeof(int) * (size_t)nr * (size_t)nc + 1);
  t->v = (double *)malloc(sizeof(double) * (size_t)nr * (size_t)nc + 1);
  t->cp[0] = 0;
  for (j = 0; j < nc; ++j) {
    for (i = 0; i < nr; ++i) {
      double a = D[(rp ? rp[i] : i) + (size_t)(cpm ? cpm[j] : j) * nr];
      if (a != 0.0) { t->ri[nnz] = i; t->v[nnz] = a; ++nnz; }
    }
    t->cp[j + 1] = nnz;
  }
  t->A.n_rows = nr; t->A.n_cols = nc;
  t->A.colptr = t->cp; t->A.rowidx = t->ri; t->A.values = t->v;
}
/* A symmetric 0/1 pattern from an edge list (labels 0..N-1), diagonal set. */
static void tcsc_from_edges(tcsc *t, int N, int ne, const int *e) {
  double *D = (double *)calloc((size_t)N * N, sizeof(double));
  int k;
  for (k = 0; k < N; ++k) D[k + (size_t)k * N] = 1.0;
  for (k = 0; k < ne; ++k) {
    D[e[2 * k] + (size_t)e[2 * k + 1] * N] = 1.0;
    D[e[2 * k + 1] + (size_t)e[2 * k] * N] = 1.0;
  }
  tcsc_from_dense(t, N, N, D, NULL, NULL);
  free(D);
}
static void random_perm(int n, int *p) {
  int i;
  for (i = 0; i < n; ++i) p[i] = i;
  for (i = n - 1; i > 0; --i) {
    int j = (int)((th_rand() + 1.0) * 0.5 * (i + 1)), t;
    if (j > i) j = i;
    t = p[i]; p[i] = p[j]; p[j] = t;
  }
}
/* Is p a permutation of 0..n-1? */
static int is_perm(int n, const int *p) {
  int *seen = (int *)calloc((size_t)n, sizeof(int)), i, ok = 1;
  for (i = 0; i < n; ++i) {
    if (p[i] < 0 || p[i] >= n || seen[p[i]]) ok = 0;
    else seen[p[i]] = 1;
  }
  free(seen);
  return ok;
}
/* Bandwidth of a pattern under perm, computed independently of the library. */
static int bw_under(const phgmg_csc *A, const int *perm) {
  int n = A->n_cols, *ip = (int *)malloc(sizeof(int) * (size_t)n), i, j, p, kb = 0;
  for (i = 0; i < n; ++i) ip[perm[i]] = i;
  for (j = 0; j < n; ++j)
    for (p = A->colptr[j]; p < A->colptr[j + 1]; ++p) kb = (int)fmax(kb, abs(ip[A->rowidx[p]] - ip[j]));
  free(ip);
  return kb;
}

/* ---- RCM on known graphs ------------------------------------------------------------ */
TEST(test_rcm_path_scrambled) {
  enum { N = 60 };
  int lab[N], e[2 * (N - 1)], perm[N], k, kb = -1;
  tcsc t;
  const phgmg_csc *A[1];
  random_perm(N, lab);
  for (k = 0; k + 1 < N; ++k) { e[2 * k] = lab[k]; e[2 * k + 1] = lab[k + 1]; }
  tcsc_from_edges(&t, N, N - 1, e);
  CHECK(bw_under(&t.A, lab) == 1); /* the path order itself */
  A[0] = &t.A;
  CHECK_RC(phgmg_rcm(N, 1, A, perm, &kb, NULL), PHGMG_OK);
  CHECK(is_perm(N, perm));
  CHECK(kb == 1);
  CHECK(bw_under(&t.A, perm) == 1);
  tcsc_free(&t);
}

TEST(test_rcm_components) {
  /* two scrambled paths (20 and 15 nodes) and 5 isolated nodes: bandwidth 1 */
  enum { N = 40 };
  int lab[N], e[2 * N], perm[N], k, ne = 0, kb = -1;
  tcsc t;
  const phgmg_csc *A[1];
  random_perm(N, lab);
  for (k = 0; k + 1 < 20; ++k) { e[2 * ne] = lab[k]; e[2 * ne + 1] = lab[k + 1]; ++ne; }
  for (k = 20; k + 1 < 35; ++k) { e[2 * ne] = lab[k]; e[2 * ne + 1] = lab[k + 1]; ++ne; }
  tcsc_from_edges(&t, N, ne, e);
  A[0] = &t.A;
  CHECK_RC(phgmg_rcm(N, 1, A, perm, &kb, NULL), PHGMG_OK);
  CHECK(is_perm(N, perm));
  CHECK(kb == 1);
  CHECK(bw_under(&t.A, perm) == 1);
  tcsc_free(&t);
}

TEST(test_rcm_grid) {
  /* w x h grid, 5-point stencil, scrambled labels. The bandwidth of the grid
     is w (w <= h); level sets of a search from a corner are anti-diagonals of
     at most w nodes, so Cuthill-McKee gives at most 2w - 1. */
  enum { W = 7, H = 40, N = W * H };
  int lab[N], e[4 * N], perm[N], i, j, ne = 0, kb = -1;
  tcsc t;
  const phgmg_csc *A[1];
  random_perm(N, lab);
  for (j = 0; j < H; ++j)
    for (i = 0; i < W; ++i) {
      if (i + 1 < W) { e[2 * ne] = lab[i + j * W]; e[2 * ne + 1] = lab[i + 1 + j * W]; ++ne; }
      if (j + 1 < H) { e[2 * ne] = lab[i + j * W]; e[2 * ne + 1] = lab[i + (j + 1) * W]; ++ne; }
    }
  tcsc_from_edges(&t, N, ne, e);
  A[0] = &t.A;
  CHECK(bw_under(&t.A, lab) == W); /* row-by-row order */
  CHECK_RC(phgmg_rcm(N, 1, A, perm, &kb, NULL), PHGMG_OK);
  CHECK(is_perm(N, perm));
  CHECK(kb == bw_under(&t.A, perm));
  CHECK(kb >= W);
  CHECK_LE(kb, 2 * W - 1);
  tcsc_free(&t);
}

/* ---- the nonlinear chain as CSC ------------------------------------------------------ */
/* The paper's nonlinear MSD (n masses) in the user ordering sig: user index i
   is the paper's [l; v] index sig[i] (NULL: the paper's ordering). */
typedef struct tchain {
  msd_nonlinear D;      /* dense, paper ordering */
  tcsc J, R, Q;
  double *B;            /* user ordering */
  int *sig, *isig, *sep_user;
  phgmg_ph_sparse *sp;
  phgmg_ph_system sys;  /* banded, internal ordering, with the quartic */
  phgmg_ph_sparse_info info;
} tchain;
static void tchain_free(tchain *c) {
  msd_nonlinear_free(&c->D);
  tcsc_free(&c->J); tcsc_free(&c->R); tcsc_free(&c->Q);
  free(c->B); free(c->sig); free(c->isig); free(c->sep_user);
  phgmg_ph_sparse_destroy(c->sp);
  memset(c, 0, sizeof *c);
}
static int tchain_build(tchain *c, int n, int scrambled) {
  msd_nl_opts o;
  int N = 2 * n, i;
  memset(c, 0, sizeof *c);
  memset(&o, 0, sizeof o);
  o.n = n;
  o.storage = PHGMG_DENSE;
  if (msd_nonlinear_build(&c->D, &o) != 0) return -1;
  c->sig = (int *)malloc(sizeof(int) * N);
  c->isig = (int *)malloc(sizeof(int) * N);
  c->sep_user = (int *)malloc(sizeof(int) * n);
  c->B = (double *)malloc(sizeof(double) * N);
  if (scrambled) random_perm(N, c->sig);
  else for (i = 0; i < N; ++i) c->sig[i] = i;
  for (i = 0; i < N; ++i) c->isig[c->sig[i]] = i;
  for (i = 0; i < N; ++i) c->B[i] = c->D.B[c->sig[i]];
  for (i = 0; i < n; ++i) c->sep_user[i] = c->isig[c->D.idx_l[i]];
  tcsc_from_dense(&c->J, N, N, c->D.J, c->sig, c->sig);
  tcsc_from_dense(&c->R, N, N, c->D.R, c->sig, c->sig);
  tcsc_from_dense(&c->Q, N, N, c->D.Q, c->sig, c->sig);
  if (phgmg_ph_sparse_create(&c->sp, N, 1, &c->J.A, &c->R.A, &c->Q.A, c->B, NULL, &c->info, NULL) != PHGMG_OK)
    return -1;
  c->sys = *phgmg_ph_sparse_system(c->sp);
  c->sys.nl = PHGMG_NL_SEPARABLE;
  c->sys.poly_deg = 4;
  c->sys.poly = c->D.poly;
  return phgmg_ph_sparse_sep_idx(c->sp, n, c->sep_user, NULL, &c->sys) == PHGMG_OK ? 0 : -1;
}
/* internal -> paper ordering: paper index sig[i] holds user entry i */
static void to_paper(const tchain *c, int ncols, const double *Xint, double *Xp) {
  int N = c->D.sys.N, i, j;
  double *Xu = (double *)malloc(sizeof(double) * N * ncols);
  phgmg_ph_sparse_to_user_order(c->sp, ncols, Xint, N, Xu, N);
  for (j = 0; j < ncols; ++j)
    for (i = 0; i < N; ++i) Xp[c->sig[i] + (size_t)j * N] = Xu[i + (size_t)j * N];
  free(Xu);
}
static void from_paper(const tchain *c, int ncols, const double *Xp, double *Xint) {
  int N = c->D.sys.N, i, j;
  double *Xu = (double *)malloc(sizeof(double) * N * ncols);
  for (j = 0; j < ncols; ++j)
    for (i = 0; i < N; ++i) Xu[i + (size_t)j * N] = Xp[c->sig[i] + (size_t)j * N];
  phgmg_ph_sparse_to_banded_order(c->sp, ncols, Xu, N, Xint, N);
  free(Xu);
}
static void u_sin(double t, double *u, void *user) { (void)user; u[0] = 0.1 * sin(t); }
static double *simulate(const phgmg_ph_system *sys, int nsteps, double *Y) {
  double *X = (double *)malloc(sizeof(double) * sys->N * (nsteps + 1));
  double *x0 = (double *)calloc((size_t)sys->N, sizeof(double));
  phgmg_gl3_opts o;
  memset(&o, 0, sizeof o); o.tol = 1e-10; o.max_iter = 20;
  if (phgmg_simulate(sys, x0, 0.0, 0.1, nsteps, u_sin, NULL, &o, X, Y, NULL, NULL, NULL, NULL) != PHGMG_OK) {
    free(X); X = NULL;
  }
  free(x0);
  return X;
}
static double rel_maxdiff(size_t n, const double *a, const double *ref) {
  size_t i;
  double d = 0, s = 0;
  for (i = 0; i < n; ++i) { d = fmax(d, fabs(a[i] - ref[i])); s = fmax(s, fabs(ref[i])); }
  return d / s;
}

TEST(test_sparse_chain_structure) {
  /* [l; v] ordering: the chain's graph is the path v1-l1-v2-l2-...-vn-ln, so
     RCM finds bandwidth 1 (the given order has n + 1); scrambled the same. */
  int s;
  for (s = 0; s < 2; ++s) {
    tchain c;
    const int n = 25, N = 50;
    double rc = 0;
    CHECK(tchain_build(&c, n, s) == 0);
    CHECK(c.info.kb == 1 && c.info.kb_rcm == 1 && c.info.permuted == 1 && c.info.wide == 0);
    if (!s) CHECK(c.info.kb_input == n + 1); /* J(l_1, v_2): rows 0 and n + 1 */
    CHECK(c.info.nnz == (2 * n - 1) * 2 + n + N);
    CHECK(is_perm(N, phgmg_ph_sparse_perm(c.sp)));
    CHECK_RC(phgmg_ph_validate(&c.sys, 0, &rc, NULL), PHGMG_OK);
    CHECK_RC(phgmg_ph_validate(phgmg_ph_sparse_system(c.sp), 0, NULL, NULL), PHGMG_OK);
    tchain_free(&c);
  }
  { /* the hand-banded interleaved order (kb 3) given as CSC: RCM still wins (1) */
    msd_nonlinear M;
    msd_nl_opts o;
    tcsc J, R, Q;
    phgmg_ph_sparse *sp = NULL;
    phgmg_ph_sparse_info inf;
    memset(&o, 0, sizeof o); o.n = 10; o.storage = PHGMG_DENSE;
    CHECK(msd_nonlinear_build(&M, &o) == 0);
    { /* interleaved: position 2i is l_i, 2i+1 is v_i */
      int p[20], i;
      for (i = 0; i < 10; ++i) { p[2 * i] = i; p[2 * i + 1] = 10 + i; }
      tcsc_from_dense(&J, 20, 20, M.J, p, p);
      tcsc_from_dense(&R, 20, 20, M.R, p, p);
      tcsc_from_dense(&Q, 20, 20, M.Q, p, p);
    }
    CHECK_RC(phgmg_ph_sparse_create(&sp, 20, 1, &J.A, &R.A, &Q.A, M.B, NULL, &inf, NULL), PHGMG_OK);
    CHECK(inf.kb_input == 3 && inf.kb == 1);
    phgmg_ph_sparse_destroy(sp);
    /* a diagonal model keeps the given order (tie) */
    CHECK_RC(phgmg_ph_sparse_create(&sp, 20, 1, &Q.A, &Q.A, &Q.A, M.B, NULL, &inf, NULL), PHGMG_OK);
    CHECK(inf.kb == 0 && inf.permuted == 0 && phgmg_ph_sparse_perm(sp)[7] == 7);
    phgmg_ph_sparse_destroy(sp);
    tcsc_free(&J); tcsc_free(&R); tcsc_free(&Q);
    msd_nonlinear_free(&M);
  }
}

TEST(test_sparse_chain_fom) {
  /* same trajectory as the dense ([l; v]) and hand-banded (interleaved) models */
  const int n = 30, N = 60, ns = 300;
  double *Xd, *Yd = (double *)malloc(sizeof(double) * (ns + 1)), *Xb;
  double *Yb = (double *)malloc(sizeof(double) * (ns + 1)), *Ys = (double *)malloc(sizeof(double) * (ns + 1));
  double *Xp = (double *)malloc(sizeof(double) * N * (ns + 1)), *Xbp = (double *)malloc(sizeof(double) * N * (ns + 1));
  msd_nonlinear Mb;
  msd_nl_opts o;
  int s, i, j;
  tchain c0;
  CHECK(tchain_build(&c0, n, 0) == 0);
  Xd = simulate(&c0.D.sys, ns, Yd);
  memset(&o, 0, sizeof o); o.n = n; o.storage = PHGMG_BANDED;
  CHECK(msd_nonlinear_build(&Mb, &o) == 0);
  Xb = simulate(&Mb.sys, ns, Yb);
  CHECK(Xd && Xb);
  if (Xb && Xd) { /* hand-banded vs dense, for the scale of the comparison */
    for (j = 0; j <= ns; ++j)
      for (i = 0; i < n; ++i) {
        Xbp[i + (size_t)j * N] = Xb[Mb.idx_l[i] + (size_t)j * N];
        Xbp[n + i + (size_t)j * N] = Xb[Mb.idx_v[i] + (size_t)j * N];
      }
    CHECK_LE(rel_maxdiff((size_t)N * (ns + 1), Xbp, Xd), 1e-12);
    CHECK(fabs(Xd[(size_t)ns * N + n]) > 1e-3); /* v_1 moves */
  }
  tchain_free(&c0);
  for (s = 0; s < 2 && Xd; ++s) {
    tchain c;
    double *Xs;
    CHECK(tchain_build(&c, n, s) == 0);
    Xs = simulate(&c.sys, ns, Ys);
    CHECK(Xs != NULL);
    if (Xs) {
      to_paper(&c, ns + 1, Xs, Xp);
      CHECK_LE(rel_maxdiff((size_t)N * (ns + 1), Xp, Xd), 1e-12);
      CHECK_LE(rel_maxdiff((size_t)ns + 1, Ys, Yd), 1e-12);
      CHECK_LE(rel_maxdiff((size_t)N * (ns + 1), Xp, Xbp), 1e-12);
    }
    free(Xs);
    tchain_free(&c);
  }
  free(Xd); free(Xb); free(Yd); free(Yb); free(Ys); free(Xp); free(Xbp);
  msd_nonlinear_free(&Mb);
}

/* e_red and e_y of one reduction of sys with snapshots X (300 steps from 0). */
static int reduce_errors(const phgmg_ph_system *sys, const double *X, const double *Y, int ns,
                         const phgmg_reduce_opts *o, double *ered, double *ey) {
  phgmg_reduced *red = NULL;
  double *XR, *YR, xr0[64], *z = (double *)calloc((size_t)sys->N, sizeof(double));
  int rc = phgmg_reduce(&red, sys, X, sys->N, ns, o, NULL, NULL);
  if (rc != PHGMG_OK) { free(z); return rc; }
  XR = (double *)malloc(sizeof(double) * o->r * ns);
  YR = (double *)malloc(sizeof(double) * ns);
  phgmg_reduced_restrict(red, z, xr0);
  rc = phgmg_reduced_simulate(red, xr0, 0.0, 0.1, ns - 1, u_sin, NULL, 1e-12, 30, XR, YR, NULL, NULL, NULL);
  if (rc == PHGMG_OK) {
    *ered = phgmg_err_red(red, X, sys->N, ns, XR, o->r);
    *ey = phgmg_rel_error(1, ns, Y, 1, YR, 1);
  }
  free(XR); free(YR); free(z);
  phgmg_reduced_destroy(red);
  return rc;
}

TEST(test_sparse_chain_reduce) {
  /* every method on the scrambled sparse model and the dense one: the same
     e_red and e_y (reductions are permutation-equivariant) */
  const int n = 30, N = 60, ns = 301;
  static const phgmg_method meth[5] = {PHGMG_METHOD_GMG_POD, PHGMG_METHOD_GMG_POD, PHGMG_METHOD_GMG_QM,
                                       PHGMG_METHOD_SP1, PHGMG_METHOD_SP2};
  double *Yd = (double *)malloc(sizeof(double) * ns), *Xd, *Xs = (double *)malloc(sizeof(double) * N * ns);
  tchain c;
  int k;
  CHECK(tchain_build(&c, n, 1) == 0);
  Xd = simulate(&c.D.sys, ns - 1, Yd);
  CHECK(Xd != NULL);
  if (Xd) from_paper(&c, ns, Xd, Xs);
  for (k = 0; k < 5 && Xd; ++k) {
    phgmg_reduce_opts o;
    double ed = -1, eyd = -1, es = -2, eys = -2;
    memset(&o, 0, sizeof o);
    o.method = meth[k];
    o.r = 8;
    o.qm.rn = 4;
    o.qm.lambda = 1e-6;
    o.hyper.on = k == 1;
    o.hyper.allow_negative = 1;
    CHECK_RC(reduce_errors(&c.D.sys, Xd, Yd, ns, &o, &ed, &eyd), PHGMG_OK);
    CHECK_RC(reduce_errors(&c.sys, Xs, Yd, ns, &o, &es, &eys), PHGMG_OK);
    CHECK(ed > 0 && ed < 1 && eyd > 0 && eyd < 1);
    CHECK_LE(fabs(es - ed), 1e-10 * ed);
    CHECK_LE(fabs(eys - eyd), 1e-10 * eyd);
  }
  free(Xd); free(Xs); free(Yd);
  tchain_free(&c);
}

/* ---- bad input ------------------------------------------------------------------------ */
TEST(test_sparse_bad_input) {
  /* 3 x 3: J = [0 1 0; -1 0 0; 0 0 0], R = diag(0, 1, 1), Q = I */
  int jcp[4] = {0, 1, 2, 2}, jri[2] = {1, 0};
  double jv[2] = {-1.0, 1.0};
  int rcp[4] = {0, 0, 1, 2}, rri[2] = {1, 2};
  double rv[2] = {1.0, 1.0};
  int qcp[4] = {0, 1, 2, 3}, qri[3] = {0, 1, 2};
  double qv[3] = {1.0, 1.0, 1.0};
  double B[3] = {0.0, 1.0, 0.0};
  phgmg_csc J = {3, 3, jcp, jri, jv}, R = {3, 3, rcp, rri, rv}, Q = {3, 3, qcp, qri, qv}, X;
  phgmg_ph_sparse *sp = (phgmg_ph_sparse *)&J;
  int bcp[2] = {0, 1}, bri[1] = {1};
  double bv[1] = {1.0};
  phgmg_csc Bc = {3, 1, bcp, bri, bv};
  const phgmg_csc *A[1];
  int perm[3];
  CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 1, &J, &R, &Q, B, NULL, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_ph_validate(phgmg_ph_sparse_system(sp), 0, NULL, NULL), PHGMG_OK);
  phgmg_ph_sparse_destroy(sp);
  CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 1, &J, &R, &Q, NULL, &Bc, NULL, NULL), PHGMG_OK);
  { /* B from CSC equals B dense, in the internal ordering */
    const int *p = phgmg_ph_sparse_perm(sp);
    int i;
    for (i = 0; i < 3; ++i) CHECK(phgmg_ph_sparse_system(sp)->B[i] == B[p[i]]);
  }
  phgmg_ph_sparse_destroy(sp);
  /* arguments */
  CHECK_RC(phgmg_ph_sparse_create(NULL, 3, 1, &J, &R, &Q, B, NULL, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 1, NULL, &R, &Q, B, NULL, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK(sp == NULL);
  CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 1, &J, &R, &Q, NULL, NULL, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 4, &J, &R, &Q, B, NULL, NULL, NULL), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_ph_sparse_create(&sp, 4, 1, &J, &R, &Q, B, NULL, NULL, NULL), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 1, &J, &R, &Q, NULL, &J, NULL, NULL), PHGMG_ERR_SIZE);
  /* structure */
  X = J; { int cp[4] = {1, 1, 2, 2}; X.colptr = cp;
    CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 1, &X, &R, &Q, B, NULL, NULL, NULL), PHGMG_ERR_FORMAT); }
  X = J; { int cp[4] = {0, 2, 1, 2}; X.colptr = cp;
    CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 1, &X, &R, &Q, B, NULL, NULL, NULL), PHGMG_ERR_FORMAT); }
  X = Q; { int ri[3] = {0, 1, 3}; X.rowidx = ri; /* out of range */
    CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 1, &J, &R, &X, B, NULL, NULL, NULL), PHGMG_ERR_FORMAT); }
  X = Q; { int ri[3] = {0, 1, -1}; X.rowidx = ri;
    CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 1, &J, &R, &X, B, NULL, NULL, NULL), PHGMG_ERR_FORMAT); }
  { /* unsorted and duplicate rows in one column */
    int cp[4] = {0, 2, 2, 2}, ri[2] = {2, 0}, rd[2] = {1, 1};
    double v[2] = {1.0, 1.0};
    phgmg_csc U = {3, 3, cp, ri, v};
    CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 1, &J, &U, &Q, B, NULL, NULL, NULL), PHGMG_ERR_FORMAT);
    U.rowidx = rd;
    CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 1, &J, &U, &Q, B, NULL, NULL, NULL), PHGMG_ERR_FORMAT);
    A[0] = &U;
    CHECK_RC(phgmg_rcm(3, 1, A, perm, NULL, NULL), PHGMG_ERR_FORMAT);
  }
  X = R; { double v[2] = {1.0, NAN}; X.values = v;
    CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 1, &J, &X, &Q, B, NULL, NULL, NULL), PHGMG_ERR_NANINF); }
  { double Bn[3] = {0.0, INFINITY, 0.0};
    CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 1, &J, &R, &Q, Bn, NULL, NULL, NULL), PHGMG_ERR_NANINF); }
  CHECK(sp == NULL);
  /* nonsymmetric R pattern is accepted by create, rejected by validation */
  { int cp[4] = {0, 0, 2, 3}, ri[3] = {1, 2, 2};
    double v[3] = {1.0, 0.5, 1.0};
    phgmg_csc U = {3, 3, cp, ri, v};
    CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 1, &J, &U, &Q, B, NULL, NULL, NULL), PHGMG_OK);
    CHECK_RC(phgmg_ph_validate(phgmg_ph_sparse_system(sp), 0, NULL, NULL), PHGMG_ERR_NOT_SYMMETRIC);
    phgmg_ph_sparse_destroy(sp); sp = NULL; }
  { /* J not skew */
    double v[2] = {-1.0, 0.5};
    X = J; X.values = v;
    CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 1, &X, &R, &Q, B, NULL, NULL, NULL), PHGMG_OK);
    CHECK_RC(phgmg_ph_validate(phgmg_ph_sparse_system(sp), 0, NULL, NULL), PHGMG_ERR_NOT_SKEW);
    phgmg_ph_sparse_destroy(sp); sp = NULL; }
  /* sep_idx */
  CHECK_RC(phgmg_ph_sparse_create(&sp, 3, 1, &J, &R, &Q, B, NULL, NULL, NULL), PHGMG_OK);
  { int bad[2] = {0, 3}, ok[2] = {2, 0}, out[2];
    phgmg_ph_system s = *phgmg_ph_sparse_system(sp);
    const int *p = phgmg_ph_sparse_perm(sp);
    CHECK_RC(phgmg_ph_sparse_sep_idx(sp, 2, bad, NULL, &s), PHGMG_ERR_SIZE);
    CHECK_RC(phgmg_ph_sparse_sep_idx(sp, 0, ok, NULL, &s), PHGMG_ERR_SIZE);
    CHECK_RC(phgmg_ph_sparse_sep_idx(NULL, 2, ok, NULL, &s), PHGMG_ERR_INVALID_ARG);
    CHECK_RC(phgmg_ph_sparse_sep_idx(sp, 2, ok, out, &s), PHGMG_OK);
    CHECK(s.nsep == 2 && p[s.sep_idx[0]] == 2 && p[s.sep_idx[1]] == 0 && out[1] == s.sep_idx[1]);
    CHECK_RC(phgmg_ph_sparse_sep_idx(sp, 2, ok, NULL, &s), PHGMG_OK); /* replaces, no leak */
  }
  phgmg_ph_sparse_destroy(sp);
  phgmg_ph_sparse_destroy(NULL);
  CHECK(phgmg_ph_sparse_system(NULL) == NULL && phgmg_ph_sparse_perm(NULL) == NULL);
  A[0] = &J;
  CHECK_RC(phgmg_rcm(3, 1, NULL, perm, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_rcm(0, 1, A, perm, NULL, NULL), PHGMG_ERR_SIZE);
}

/* Allocation failures at every allocation of create: clean error, no leak. */
static int fail_after;
static void *count_alloc(size_t n, void *u) { (void)u; return fail_after-- > 0 ? malloc(n) : NULL; }
static void count_free(void *p, void *u) { (void)u; free(p); }
TEST(test_sparse_alloc_failures) {
  tchain c;
  phgmg_allocator a = {count_alloc, count_free, NULL};
  int k, ok = 0;
  CHECK(tchain_build(&c, 6, 1) == 0);
  for (k = 0; k < 40 && !ok; ++k) {
    phgmg_ph_sparse *sp = NULL;
    phgmg_result rc;
    fail_after = k;
    rc = phgmg_ph_sparse_create(&sp, 12, 1, &c.J.A, &c.R.A, &c.Q.A, c.B, NULL, NULL, &a);
    if (rc == PHGMG_OK) { ok = 1; CHECK(sp != NULL); phgmg_ph_sparse_destroy(sp); }
    else { CHECK_RC(rc, PHGMG_ERR_NOMEM); CHECK(sp == NULL); }
  }
  CHECK(ok && k > 5);
  tchain_free(&c);
}

SUITE(sparse) {
  RUN(test_rcm_path_scrambled);
  RUN(test_rcm_components);
  RUN(test_rcm_grid);
  RUN(test_sparse_chain_structure);
  RUN(test_sparse_chain_fom);
  RUN(test_sparse_chain_reduce);
  RUN(test_sparse_bad_input);
  RUN(test_sparse_alloc_failures);
}
