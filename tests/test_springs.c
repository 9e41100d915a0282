/* Springs in the SEPARABLE Hamiltonian (phgmg_ph_system.sep_jdx, manual 1.9):
   H_nl = sum_k w_k phi(x[i_k] - x[j_k]) given natively against the same
   energy given as a GENERAL part whose callbacks (written here, with phi,
   phi', phi'' in closed form) evaluate the sums of 1.9 -- an independent
   path through the library's GENERAL evaluators. Dense, band and sparse
   storage (band LU and sparse LU), the energy balance, GMG-POD models from
   both forms, ECSW hyper-reduction, and the refusals. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>
#include <time.h>

/* A chain of SPR_NN masses, node n: position 2n, momentum 2n + 1 (N = 2 nn).
   J couples each position to its momentum, R = 0.05 on the momenta,
   Q = diag(K, I) with K = 0.2 I + 0.5 (chain Laplacian) -- the linear part
   of the springs, which also keeps neighbours close in a sparse model's
   ordering -- and one force on momentum 0. The nonlinear springs: term 0
   ties node 0 to the wall (one node, sep_jdx = -1), term k >= 1 joins node
   k to node k - 1: s_k = q_k - q_{k-1}, phi(s) = s^2/2 + s^4/4, weights
   w_k = 1 + 0.1 k. */
#define SPR_NN 40
#define SPR_N (2 * SPR_NN)
#define SPR_STEPS 120
#define SPR_DT 0.05
static const double spr_poly[5] = {0.0, 0.0, 0.5, 0.0, 0.25};

typedef struct spr_model {
  double J[SPR_N * SPR_N], R[SPR_N * SPR_N], Q[SPR_N * SPR_N], B[SPR_N];
  int idx[SPR_NN], jdx[SPR_NN];
  double w[SPR_NN];
} spr_model;

static void spr_build(spr_model *m) {
  int n;
  memset(m, 0, sizeof *m);
  for (n = 0; n < SPR_NN; ++n) {
    const int q = 2 * n, p = 2 * n + 1;
    m->J[q + p * SPR_N] = 1.0;
    m->J[p + q * SPR_N] = -1.0;
    m->R[p + p * SPR_N] = 0.05;
    m->Q[p + p * SPR_N] = 1.0;
    m->Q[q + q * SPR_N] += 0.2;
    if (n > 0) { /* the linear chain spring between q and q - 2 */
      m->Q[q + q * SPR_N] += 0.5; m->Q[(q - 2) + (q - 2) * SPR_N] += 0.5;
      m->Q[q + (q - 2) * SPR_N] -= 0.5; m->Q[(q - 2) + q * SPR_N] -= 0.5;
    }
    m->idx[n] = q;
    m->jdx[n] = n > 0 ? q - 2 : -1;
    m->w[n] = 1.0 + 0.1 * n;
  }
  m->B[1] = 1.0;
}

static void spr_u(double t, double *u, void *user) {
  (void)user;
  u[0] = 0.8 * sin(1.3 * t) + 0.4 * sin(2.9 * t);
}

/* The native form on sys (whose matrices are set): nodes idx/jdx (in the
   system's order), shared built-in phi. */
static void spr_native(phgmg_ph_system *sys, const int *idx, const int *jdx, const double *w) {
  sys->nl = PHGMG_NL_SEPARABLE;
  sys->nsep = SPR_NN;
  sys->sep_idx = idx;
  sys->sep_jdx = jdx;
  sys->sep_w = w;
  sys->poly_deg = 4;
  sys->poly = spr_poly;
}

/* The GENERAL form: the same sums by hand. Hessian storage: 0 dense, 1 band
   (kb), 2 the pattern hp/hi of a sparse model (all in the system's order). */
typedef struct spr_gen {
  const int *a, *b;
  const double *w;
  int N, storage, kb;
  const int *hp, *hi;
} spr_gen;
static double spr_phi0(double s) { return 0.5 * s * s + 0.25 * s * s * s * s; }
static double spr_phi1(double s) { return s + s * s * s; }
static double spr_phi2(double s) { return 1.0 + 3.0 * s * s; }
static double spr_s(const spr_gen *G, int k, const double *x) { return G->b[k] >= 0 ? x[G->a[k]] - x[G->b[k]] : x[G->a[k]]; }
static double spr_g_H(const double *x, void *user) {
  const spr_gen *G = (const spr_gen *)user;
  double H = 0.0;
  int k;
  for (k = 0; k < SPR_NN; ++k) H += G->w[k] * spr_phi0(spr_s(G, k, x));
  return H;
}
static void spr_g_grad(const double *x, double *g, void *user) {
  const spr_gen *G = (const spr_gen *)user;
  int k;
  memset(g, 0, sizeof(double) * (size_t)G->N);
  for (k = 0; k < SPR_NN; ++k) {
    const double f = G->w[k] * spr_phi1(spr_s(G, k, x));
    g[G->a[k]] += f;
    if (G->b[k] >= 0) g[G->b[k]] -= f;
  }
}
static double *spr_at(const spr_gen *G, double *Hs, int r, int c) {
  int p;
  if (G->storage == 0) return Hs + r + (size_t)c * G->N;
  if (G->storage == 1) return Hs + (G->kb + r - c) + (size_t)c * (2 * G->kb + 1);
  for (p = G->hp[c]; p < G->hp[c + 1]; ++p) if (G->hi[p] == r) return Hs + p;
  return NULL;
}
static void spr_g_hess(const double *x, double *Hs, void *user) {
  const spr_gen *G = (const spr_gen *)user;
  size_t n = G->storage == 0 ? (size_t)G->N * G->N : G->storage == 1 ? (size_t)(2 * G->kb + 1) * G->N : (size_t)G->hp[G->N];
  int k;
  memset(Hs, 0, sizeof(double) * n);
  for (k = 0; k < SPR_NN; ++k) {
    const int a = G->a[k], b = G->b[k];
    const double h = G->w[k] * spr_phi2(spr_s(G, k, x));
    *spr_at(G, Hs, a, a) += h;
    if (b < 0) continue;
    *spr_at(G, Hs, b, b) += h;
    *spr_at(G, Hs, a, b) -= h;
    *spr_at(G, Hs, b, a) -= h;
  }
}
static void spr_general(phgmg_ph_system *sys, spr_gen *G) {
  sys->nl = PHGMG_NL_GENERAL;
  sys->H_nl = spr_g_H; sys->grad_nl = spr_g_grad; sys->hess_nl = spr_g_hess; sys->user = G;
}

static double spr_maxdiff(size_t n, const double *a, const double *b, double *scale) {
  double d = 0.0, s = 0.0;
  size_t i;
  for (i = 0; i < n; ++i) {
    d = fabs(a[i] - b[i]) > d ? fabs(a[i] - b[i]) : d;
    s = fabs(b[i]) > s ? fabs(b[i]) : s;
  }
  if (scale) *scale = s;
  return d;
}

static void spr_x0(double *x0) {
  int i;
  for (i = 0; i < SPR_N; ++i) x0[i] = 0.5 * sin(1.7 * (double)i);
}

/* Trajectory X, outputs Y and energy of nsteps steps of size h (tight Newton tolerance). */
static phgmg_result spr_sim(const phgmg_ph_system *sys, const double *x0, double h, int nsteps, double *X, double *Y,
                            const phgmg_energy *E) {
  phgmg_gl3_opts o;
  memset(&o, 0, sizeof o);
  o.tol = 1e-14;
  o.max_iter = 40;
  return phgmg_simulate(sys, x0, 0.0, h, nsteps, spr_u, NULL, &o, X, Y, E, NULL, NULL, NULL);
}

/* Native against GENERAL on one storage: trajectories and outputs to 1e-10
   (relative to their largest entry), and the energies H(x_n) equal. */
static void spr_compare(const phgmg_ph_system *nat, const phgmg_ph_system *gen, const double *x0) {
  const size_t nx = (size_t)SPR_N * (SPR_STEPS + 1);
  double *X1 = (double *)malloc(sizeof(double) * nx), *X2 = (double *)malloc(sizeof(double) * nx);
  double Y1[SPR_STEPS + 1], Y2[SPR_STEPS + 1], sc, sy, d;
  int n;
  CHECK_RC(phgmg_ph_validate(nat, 0.0, NULL, NULL), PHGMG_OK);
  CHECK_RC(spr_sim(nat, x0, SPR_DT, SPR_STEPS, X1, Y1, NULL), PHGMG_OK);
  CHECK_RC(spr_sim(gen, x0, SPR_DT, SPR_STEPS, X2, Y2, NULL), PHGMG_OK);
  d = spr_maxdiff(nx, X1, X2, &sc);
  CHECK(sc > 0.3);                 /* the springs are stretched: s^4 matters */
  CHECK_LE(d, 1e-10 * sc);
  d = spr_maxdiff(SPR_STEPS + 1, Y1, Y2, &sy);
  CHECK_LE(d, 1e-10 * sy);
  for (n = 0; n <= SPR_STEPS; n += 10) {
    const double h1 = phgmg_ph_hamiltonian(nat, X1 + (size_t)n * SPR_N), h2 = phgmg_ph_hamiltonian(gen, X1 + (size_t)n * SPR_N);
    CHECK_LE(fabs(h1 - h2), 1e-13 * fabs(h2));
  }
  free(X1); free(X2);
}

/* Dense and band storage: native = GENERAL; the gradient at a state equals
   the hand-written one. */
TEST(test_springs_dense_band) {
  static spr_model m;
  phgmg_ph_system nat, gen;
  spr_gen G;
  double x0[SPR_N], g1[SPR_N], g2[SPR_N], q[SPR_N], *Jb, *Rb, *Qb;
  int i;
  spr_build(&m);
  spr_x0(x0);
  memset(&nat, 0, sizeof nat);
  nat.N = SPR_N; nat.m = 1; nat.J = m.J; nat.R = m.R; nat.Q = m.Q; nat.B = m.B;
  gen = nat;
  spr_native(&nat, m.idx, m.jdx, m.w);
  memset(&G, 0, sizeof G);
  G.a = m.idx; G.b = m.jdx; G.w = m.w; G.N = SPR_N; G.storage = 0;
  spr_general(&gen, &G);
  phgmg_ph_gradient(&nat, x0, g1);   /* Q x0 + sum_k w_k phi'(s_k) c_k */
  spr_g_grad(x0, q, &G);
  for (i = 0; i < SPR_N; ++i) {
    int j;
    g2[i] = q[i];
    for (j = 0; j < SPR_N; ++j) g2[i] += m.Q[i + j * SPR_N] * x0[j];
  }
  CHECK_LE(spr_maxdiff(SPR_N, g1, g2, NULL), 1e-14 * 10.0);
  spr_compare(&nat, &gen, x0);
  /* band storage, kb = 2 (a spring spans 2) */
  Jb = th_band(SPR_N, 2, m.J); Rb = th_band(SPR_N, 2, m.R); Qb = th_band(SPR_N, 2, m.Q);
  nat.storage = gen.storage = PHGMG_BANDED;
  nat.kb = gen.kb = 2;
  nat.J = gen.J = Jb; nat.R = gen.R = Rb; nat.Q = gen.Q = Qb;
  G.storage = 1; G.kb = 2;
  spr_compare(&nat, &gen, x0);
  free(Jb); free(Rb); free(Qb);
}

/* A sparse model (phgmg_ph_sparse) on the band LU and on the sparse LU:
   native (nodes remapped by phgmg_ph_sparse_sep_idx / _sep_jdx) against
   GENERAL (its Hessian pattern from phgmg_ph_sparse_hess_pattern). */
TEST(test_springs_sparse) {
  static spr_model m;
  int solver;
  spr_build(&m);
  for (solver = 0; solver < 2; ++solver) {
    phgmg_ph_sparse *sp = NULL;
    phgmg_csc A[3];
    phgmg_ph_system nat, gen;
    spr_gen G;
    int r[SPR_N * SPR_N], c[SPR_N * SPR_N], k, a, nz, ia[SPR_NN], ib[SPR_NN], cp[SPR_N + 1], ri[4 * SPR_NN];
    double v[SPR_N * SPR_N], xu[SPR_N], x0[SPR_N];
    const double *M[3] = {m.J, m.R, m.Q};
    for (a = 0; a < 3; ++a) {
      int i, j;
      nz = 0;
      for (j = 0; j < SPR_N; ++j)
        for (i = 0; i < SPR_N; ++i)
          if (M[a][i + j * SPR_N] != 0.0) { r[nz] = i; c[nz] = j; v[nz] = M[a][i + j * SPR_N]; ++nz; }
      CHECK_RC(phgmg_csc_from_coo(&A[a], SPR_N, SPR_N, nz, r, c, v, NULL), PHGMG_OK);
    }
    CHECK_RC(phgmg_ph_sparse_create(&sp, SPR_N, 1, &A[0], &A[1], &A[2], m.B, NULL, NULL, NULL), PHGMG_OK);
    if (solver) CHECK_RC(phgmg_ph_sparse_set_solver(sp, PHGMG_SOLVER_SPARSE_LU, NULL), PHGMG_OK);
    nat = *phgmg_ph_sparse_system(sp);
    CHECK(nat.storage == (solver ? PHGMG_SPARSE : PHGMG_BANDED));
    gen = nat;
    spr_native(&nat, NULL, NULL, m.w);
    CHECK_RC(phgmg_ph_sparse_sep_idx(sp, SPR_NN, m.idx, ia, &nat), PHGMG_OK);
    CHECK_RC(phgmg_ph_sparse_sep_jdx(sp, SPR_NN, m.jdx, ib, &nat), PHGMG_OK);
    for (k = 0; k < SPR_NN; ++k)   /* internal node i is user node perm[i] */
      CHECK(m.jdx[k] < 0 ? ib[k] == -1 : phgmg_ph_sparse_perm(sp)[ib[k]] == m.jdx[k]);
    memset(&G, 0, sizeof G);
    G.a = ia; G.b = ib; G.w = m.w; G.N = SPR_N; G.storage = solver ? 2 : 1; G.kb = nat.kb;
    spr_general(&gen, &G);
    if (solver) { /* the GENERAL Hessian's pattern, user order: per node q its chain neighbours */
      nz = 0;
      for (a = 0; a < SPR_N; ++a) {
        cp[a] = nz;
        if (a % 2) continue;
        if (a >= 2) ri[nz++] = a - 2;
        ri[nz++] = a;
        if (a + 2 < SPR_N) ri[nz++] = a + 2;
      }
      cp[SPR_N] = nz;
      CHECK_RC(phgmg_ph_sparse_hess_pattern(sp, cp, ri, NULL, &gen), PHGMG_OK);
      G.hp = gen.hess_p; G.hi = gen.hess_i;
    }
    spr_x0(xu);
    CHECK_RC(phgmg_ph_sparse_to_banded_order(sp, 1, xu, SPR_N, x0, SPR_N), PHGMG_OK);
    spr_compare(&nat, &gen, x0);
    phgmg_ph_sparse_destroy(sp);
    for (a = 0; a < 3; ++a) phgmg_csc_free(&A[a], NULL);
  }
}

/* Largest |H_n - H_0 - S_n + D_n| / max |H_n| of a run of n steps of size h. */
static double spr_balance(const phgmg_ph_system *sys, double h, int n) {
  phgmg_energy E;
  double x0[SPR_N], bal = 0.0, Hm = 0.0;
  int i;
  spr_x0(x0);
  E.H = (double *)malloc(sizeof(double) * (size_t)(n + 1));
  E.S = (double *)malloc(sizeof(double) * (size_t)(n + 1));
  E.D = (double *)malloc(sizeof(double) * (size_t)(n + 1));
  if (spr_sim(sys, x0, h, n, NULL, NULL, &E) != PHGMG_OK) bal = 1e300;
  for (i = 0; i <= n; ++i) {
    const double d = fabs(E.H[i] - E.H[0] - E.S[i] + E.D[i]);
    bal = d > bal ? d : bal;
    Hm = fabs(E.H[i]) > Hm ? fabs(E.H[i]) : Hm;
  }
  free(E.H); free(E.S); free(E.D);
  return bal / Hm;
}

/* The energy balance (manual 1.9): exact to round-off for quadratic phi
   (grad H(p)^T p' of degree 5, integrated exactly by the Gauss rule), and
   for the quartic phi falling like h^6 (halving h: about 64; at least 32
   asserted). */
TEST(test_springs_balance) {
  static spr_model m;
  static const double quad[3] = {0.0, 0.0, 0.5};
  phgmg_ph_system sys;
  double b1, b2;
  spr_build(&m);
  memset(&sys, 0, sizeof sys);
  sys.N = SPR_N; sys.m = 1; sys.J = m.J; sys.R = m.R; sys.Q = m.Q; sys.B = m.B;
  spr_native(&sys, m.idx, m.jdx, m.w);
  b1 = spr_balance(&sys, 0.1, 40);
  b2 = spr_balance(&sys, 0.05, 80);
  CHECK(b1 > 0.0);
  CHECK_LE(32.0 * b2, b1);
  sys.poly_deg = 2; sys.poly = quad;
  CHECK_LE(spr_balance(&sys, 0.1, 40), 1e-13);
}

/* GMG-POD (r = 10) from the native and the GENERAL form on the same
   snapshots (a run from rest under the input: the motion spreads from node
   0, so a few springs carry the training set): the reduced outputs equal to
   1e-10; the native model is port-Hamiltonian (Rr >= 0: K + K^T <= 0) with
   Hr = H o phi. ECSW hyper-reduction at fit tolerance tau = 1e-6 keeps
   fewer terms and Rr >= 0, and its outputs follow the exact reduced
   model's: the fit reproduces the reduced gradient of the nonlinear part
   to tau relative on the training states; a perturbation of relative size
   tau in the vector field moves a stable, damped run of length T = 6 by
   about T L tau (L: the field's Lipschitz constant relative to its size,
   a few units here), so 100 tau is asserted for the relative output
   difference (measured: 4.5e-8). */
TEST(test_springs_reduce) {
  static spr_model m;
  phgmg_ph_system nat, gen;
  spr_gen G;
  phgmg_reduce_opts o;
  phgmg_reduced *r1 = NULL, *r2 = NULL, *r3 = NULL;
  phgmg_reduce_info inf;
  const size_t nx = (size_t)SPR_N * (SPR_STEPS + 1);
  double *X = (double *)malloc(sizeof(double) * nx), x0[SPR_N], xr0[10] = {0}, XR[10 * (SPR_STEPS + 1)];
  double Y1[SPR_STEPS + 1], Y2[SPR_STEPS + 1], Y3[SPR_STEPS + 1], sy, Jr[100], Rr[100], ev[10], *work, xf[SPR_N];
  int n, pass;
  spr_build(&m);
  spr_x0(x0);
  memset(&nat, 0, sizeof nat);
  nat.N = SPR_N; nat.m = 1; nat.J = m.J; nat.R = m.R; nat.Q = m.Q; nat.B = m.B;
  gen = nat;
  spr_native(&nat, m.idx, m.jdx, m.w);
  memset(&G, 0, sizeof G);
  G.a = m.idx; G.b = m.jdx; G.w = m.w; G.N = SPR_N;
  spr_general(&gen, &G);
  memset(x0, 0, sizeof x0);
  CHECK_RC(spr_sim(&nat, x0, SPR_DT, SPR_STEPS, X, NULL, NULL), PHGMG_OK);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = 10;
  CHECK_RC(phgmg_reduce(&r1, &nat, X, SPR_N, SPR_STEPS + 1, &o, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_reduce(&r2, &gen, X, SPR_N, SPR_STEPS + 1, &o, NULL, NULL), PHGMG_OK);
  o.hyper.on = 1; o.hyper.kind = PHGMG_HYPER_ECSW; o.hyper.tol = 1e-6;
  CHECK_RC(phgmg_reduce(&r3, &nat, X, SPR_N, SPR_STEPS + 1, &o, &inf, NULL), PHGMG_OK);
  if (!r1 || !r2 || !r3) { free(X); phgmg_reduced_destroy(r1); phgmg_reduced_destroy(r2); phgmg_reduced_destroy(r3); return; }
  CHECK(phgmg_reduced_rom(r1)->nd == SPR_NN);    /* every term kept online */
  CHECK(phgmg_reduced_rom(r3)->nd < SPR_NN / 2 && phgmg_reduced_rom(r3)->nd >= 1);   /* measured: 11 of 40 */
  CHECK_LE(inf.hyper_residual, 1e-6);
  CHECK_RC(phgmg_reduced_simulate(r1, xr0, 0.0, SPR_DT, SPR_STEPS, spr_u, NULL, 1e-13, 30, XR, Y1, NULL, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_reduced_simulate(r2, xr0, 0.0, SPR_DT, SPR_STEPS, spr_u, NULL, 1e-13, 30, NULL, Y2, NULL, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_reduced_simulate(r3, xr0, 0.0, SPR_DT, SPR_STEPS, spr_u, NULL, 1e-13, 30, NULL, Y3, NULL, NULL, NULL), PHGMG_OK);
  CHECK_LE(spr_maxdiff(SPR_STEPS + 1, Y1, Y2, &sy), 1e-10 * sy);
  CHECK(sy > 0.05);
  CHECK_LE(spr_maxdiff(SPR_STEPS + 1, Y3, Y1, NULL), 100.0 * 1e-6 * sy);
  for (pass = 0; pass < 2; ++pass) {   /* Rr >= 0 at a state of the run: exact and hyper-reduced */
    const phgmg_rom *rom = phgmg_reduced_rom(pass ? r3 : r1);
    work = (double *)malloc(sizeof(double) * (phgmg_rom_eval_work_size(rom) + 1));
    CHECK_RC(phgmg_rom_structure(rom, XR + 10 * 60, Jr, Rr, work), PHGMG_OK);
    CHECK_RC(phgmg_sym_eig(10, Rr, 10, ev, NULL, 10), PHGMG_OK);
    CHECK(ev[0] >= -1e-12 * fabs(ev[9]) && ev[9] > 0.0);
    if (!pass)
      for (n = 0; n <= SPR_STEPS; n += 20) {   /* Hr = H o phi */
        const double Hr = phgmg_rom_hamiltonian(rom, XR + (size_t)n * 10, work);
        double H;
        phgmg_reduced_lift(r1, XR + (size_t)n * 10, xf);
        H = phgmg_ph_hamiltonian(&nat, xf);
        CHECK_LE(fabs(Hr - H), 1e-12 * (fabs(H) + 1e-300) + 1e-15);
      }
    free(work);
  }
  { /* the hyper-reduced model through a model file: the same energy and gradient (nothing of N online) */
    const phgmg_rom *rom = phgmg_reduced_rom(r3);
    phgmg_rom ld;
    void *blk = NULL;
    char path[96];
    double g1[10], g2[10], w1[4096], w2[4096];
    CHECK(phgmg_rom_eval_work_size(rom) <= 4096);
    snprintf(path, sizeof path, "build/springs_tmp_%lx.phgmgrom", (unsigned long)time(NULL) ^ (unsigned long)clock());
    CHECK_RC(phgmg_rom_save(rom, path), PHGMG_OK);
    CHECK_RC(phgmg_rom_load(path, &ld, &blk, NULL), PHGMG_OK);
    if (blk) {
      CHECK(ld.nd == rom->nd && ld.r == rom->r);
      CHECK(phgmg_rom_hamiltonian(&ld, XR + 10 * 60, w2) == phgmg_rom_hamiltonian(rom, XR + 10 * 60, w1));
      phgmg_rom_gradient(&ld, XR + 10 * 60, g2, w2);
      phgmg_rom_gradient(rom, XR + 10 * 60, g1, w1);
      CHECK(memcmp(g1, g2, sizeof g1) == 0);
      free(blk);
    }
    remove(path);
  }
  phgmg_reduced_destroy(r1); phgmg_reduced_destroy(r2); phgmg_reduced_destroy(r3);
  free(X);
}

/* Refusals: a second node out of range or equal to the first, a spring
   wider than the band, a sparse model's spring farther apart than its band,
   a mass matrix that weighs a spring's two nodes differently; springs with
   E = I pass. */
TEST(test_springs_refused) {
  static spr_model m;
  static double E[SPR_N * SPR_N], Qd[SPR_N * SPR_N];
  phgmg_ph_system sys;
  int jb[SPR_NN], k;
  double *Jb, *Rb, *Qb;
  spr_build(&m);
  memset(&sys, 0, sizeof sys);
  sys.N = SPR_N; sys.m = 1; sys.J = m.J; sys.R = m.R; sys.Q = m.Q; sys.B = m.B;
  spr_native(&sys, m.idx, jb, m.w);
  for (k = 0; k < SPR_NN; ++k) jb[k] = m.jdx[k];
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_OK);
  jb[3] = SPR_N;
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  jb[3] = -2;
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  jb[3] = m.idx[3];
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  jb[3] = 0;   /* node 3 to node 0: |6 - 0| = 6; fine for dense storage */
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_OK);
  Jb = th_band(SPR_N, 2, m.J); Rb = th_band(SPR_N, 2, m.R); Qb = th_band(SPR_N, 2, m.Q);
  sys.storage = PHGMG_BANDED; sys.kb = 2; sys.J = Jb; sys.R = Rb; sys.Q = Qb;
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_ERR_SIZE);   /* wider than the band */
  {
    phgmg_gl3 *s = NULL;
    CHECK_RC(phgmg_gl3_create(&s, &sys, 0.1, NULL, NULL), PHGMG_ERR_SIZE);
    CHECK(s == NULL);
  }
  jb[3] = m.jdx[3];
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_OK);
  free(Jb); free(Rb); free(Qb);
  /* the mass matrix (with the diagonal of Q, so that E^T Q stays symmetric
     for a diagonal E): E = I passes; E(2, 2) = 2 while E(0, 0) = E(4, 4) = 1
     on springs 1 and 2 is refused (no Hamiltonian, manual 1.9) */
  for (k = 0; k < SPR_N; ++k) { Qd[k + k * SPR_N] = m.Q[k + k * SPR_N]; E[k + k * SPR_N] = 1.0; }
  sys.storage = PHGMG_DENSE; sys.kb = 0; sys.J = m.J; sys.R = m.R; sys.Q = Qd;
  sys.E = E;
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_OK);
  E[2 + 2 * SPR_N] = 2.0;
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_ERR_E_COUPLED);
  sys.sep_jdx = NULL;   /* the same E without springs: one-node terms, E(i, i) > 0 suffices */
  CHECK_RC(phgmg_ph_validate(&sys, 0.0, NULL, NULL), PHGMG_OK);
  sys.sep_jdx = jb;
  sys.E = NULL;
  /* a sparse model: a spring between chain ends is far outside its band */
  {
    phgmg_ph_sparse *sp = NULL;
    phgmg_csc A[3];
    phgmg_ph_system s2;
    int r[SPR_N * SPR_N], c[SPR_N * SPR_N], a, nz;
    double v[SPR_N * SPR_N];
    const double *M[3] = {m.J, m.R, m.Q};
    for (a = 0; a < 3; ++a) {
      int i, j;
      nz = 0;
      for (j = 0; j < SPR_N; ++j)
        for (i = 0; i < SPR_N; ++i)
          if (M[a][i + j * SPR_N] != 0.0) { r[nz] = i; c[nz] = j; v[nz] = M[a][i + j * SPR_N]; ++nz; }
      CHECK_RC(phgmg_csc_from_coo(&A[a], SPR_N, SPR_N, nz, r, c, v, NULL), PHGMG_OK);
    }
    CHECK_RC(phgmg_ph_sparse_create(&sp, SPR_N, 1, &A[0], &A[1], &A[2], m.B, NULL, NULL, NULL), PHGMG_OK);
    s2 = *phgmg_ph_sparse_system(sp);
    spr_native(&s2, NULL, NULL, m.w);
    CHECK_RC(phgmg_ph_sparse_sep_idx(sp, SPR_NN, m.idx, NULL, &s2), PHGMG_OK);
    for (k = 0; k < SPR_NN; ++k) jb[k] = m.jdx[k];
    jb[SPR_NN - 1] = 0;   /* the last node to the first */
    CHECK_RC(phgmg_ph_sparse_sep_jdx(sp, SPR_NN, jb, NULL, &s2), PHGMG_ERR_SIZE);
    jb[SPR_NN - 1] = SPR_N;
    CHECK_RC(phgmg_ph_sparse_sep_jdx(sp, SPR_NN, jb, NULL, &s2), PHGMG_ERR_SIZE);
    CHECK_RC(phgmg_ph_sparse_sep_jdx(sp, SPR_NN, m.jdx, NULL, &s2), PHGMG_OK);
    CHECK_RC(phgmg_ph_validate(&s2, 0.0, NULL, NULL), PHGMG_OK);
    phgmg_ph_sparse_destroy(sp);
    for (a = 0; a < 3; ++a) phgmg_csc_free(&A[a], NULL);
  }
}

/* SP1, SP2 and GMG-QM (r = 10; QM: its default manifold) from the native
   and the GENERAL form on the same snapshots: the reduced outputs equal to
   1e-10 (every term kept: the reduced arguments c_k^T V0 xr (+ c_k^T V2
   eta) against the GENERAL part's full-dimension evaluation). */
TEST(test_springs_methods) {
  static spr_model m;
  static const phgmg_method meth[3] = {PHGMG_METHOD_SP1, PHGMG_METHOD_SP2, PHGMG_METHOD_GMG_QM};
  phgmg_ph_system nat, gen;
  spr_gen G;
  const size_t nx = (size_t)SPR_N * (SPR_STEPS + 1);
  double *X = (double *)malloc(sizeof(double) * nx), x0[SPR_N], xr0[10] = {0}, Y1[SPR_STEPS + 1], Y2[SPR_STEPS + 1], sy;
  int a;
  spr_build(&m);
  memset(x0, 0, sizeof x0);
  memset(&nat, 0, sizeof nat);
  nat.N = SPR_N; nat.m = 1; nat.J = m.J; nat.R = m.R; nat.Q = m.Q; nat.B = m.B;
  gen = nat;
  spr_native(&nat, m.idx, m.jdx, m.w);
  memset(&G, 0, sizeof G);
  G.a = m.idx; G.b = m.jdx; G.w = m.w; G.N = SPR_N;
  spr_general(&gen, &G);
  CHECK_RC(spr_sim(&nat, x0, SPR_DT, SPR_STEPS, X, NULL, NULL), PHGMG_OK);
  for (a = 0; a < 3; ++a) {
    phgmg_reduce_opts o;
    phgmg_reduced *r1 = NULL, *r2 = NULL;
    memset(&o, 0, sizeof o);
    o.method = meth[a]; o.r = 10;
    CHECK_RC(phgmg_reduce(&r1, &nat, X, SPR_N, SPR_STEPS + 1, &o, NULL, NULL), PHGMG_OK);
    CHECK_RC(phgmg_reduce(&r2, &gen, X, SPR_N, SPR_STEPS + 1, &o, NULL, NULL), PHGMG_OK);
    if (r1 && r2) {
      const int r = phgmg_reduced_rom(r1)->r;
      CHECK(r == phgmg_reduced_rom(r2)->r && r <= 10);
      CHECK_RC(phgmg_reduced_simulate(r1, xr0, 0.0, SPR_DT, SPR_STEPS, spr_u, NULL, 1e-13, 30, NULL, Y1, NULL, NULL, NULL), PHGMG_OK);
      CHECK_RC(phgmg_reduced_simulate(r2, xr0, 0.0, SPR_DT, SPR_STEPS, spr_u, NULL, 1e-13, 30, NULL, Y2, NULL, NULL, NULL), PHGMG_OK);
      CHECK_LE(spr_maxdiff(SPR_STEPS + 1, Y1, Y2, &sy), 1e-10 * sy);
      CHECK(sy > 0.05);
    }
    if (r1 && meth[a] == PHGMG_METHOD_GMG_QM) {   /* ECSW on the manifold's rows c_k^T V0, c_k^T V2 */
      phgmg_reduced *r3 = NULL;
      o.hyper.on = 1; o.hyper.kind = PHGMG_HYPER_ECSW; o.hyper.tol = 1e-6;
      CHECK_RC(phgmg_reduce(&r3, &nat, X, SPR_N, SPR_STEPS + 1, &o, NULL, NULL), PHGMG_OK);
      CHECK(r3 && phgmg_reduced_rom(r3)->nd < SPR_NN && phgmg_reduced_rom(r3)->nd >= 1);
      if (r3)
        CHECK_RC(phgmg_reduced_simulate(r3, xr0, 0.0, SPR_DT, SPR_STEPS, spr_u, NULL, 1e-13, 30, NULL, Y2, NULL, NULL, NULL), PHGMG_OK);
      CHECK_LE(spr_maxdiff(SPR_STEPS + 1, Y2, Y1, NULL), 100.0 * 1e-6 * sy);   /* as in test_springs_reduce */
      phgmg_reduced_destroy(r3);
    }
    phgmg_reduced_destroy(r1); phgmg_reduced_destroy(r2);
  }
  free(X);
}

/* DEIM on springs: the terms' gradient snapshots phi'(c_k^T x_i) are built
   by phgmg_reduce and, once per study, by phgmg_study_reduce (two code
   paths); both pick the same points and weights, so the two models give the
   same outputs, and the model (allow_negative) simulates. */
TEST(test_springs_deim) {
  static spr_model m;
  phgmg_ph_system nat;
  phgmg_reduce_opts o;
  phgmg_reduced *r1 = NULL, *r2 = NULL;
  phgmg_study *st = NULL;
  phgmg_study_opts so;
  const size_t nx = (size_t)SPR_N * (SPR_STEPS + 1);
  double *X = (double *)malloc(sizeof(double) * nx), x0[SPR_N], xr0[10] = {0}, Y1[SPR_STEPS + 1], Y2[SPR_STEPS + 1], sy;
  spr_build(&m);
  memset(x0, 0, sizeof x0);
  memset(&nat, 0, sizeof nat);
  nat.N = SPR_N; nat.m = 1; nat.J = m.J; nat.R = m.R; nat.Q = m.Q; nat.B = m.B;
  spr_native(&nat, m.idx, m.jdx, m.w);
  CHECK_RC(spr_sim(&nat, x0, SPR_DT, SPR_STEPS, X, NULL, NULL), PHGMG_OK);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = 10;
  o.hyper.on = 1; o.hyper.kind = PHGMG_HYPER_QDEIM; o.hyper.allow_negative = 1;
  CHECK_RC(phgmg_reduce(&r1, &nat, X, SPR_N, SPR_STEPS + 1, &o, NULL, NULL), PHGMG_OK);
  so.what = 0; so.kmax = 10;
  CHECK_RC(phgmg_study_create(&st, &nat, X, SPR_N, SPR_STEPS + 1, &so, NULL), PHGMG_OK);
  if (st) CHECK_RC(phgmg_study_reduce(st, &o, &r2, NULL), PHGMG_OK);
  if (r1 && r2) {
    const phgmg_rom *a = phgmg_reduced_rom(r1), *b = phgmg_reduced_rom(r2);
    CHECK(a->nd == b->nd && a->nd >= 1 && a->nd < SPR_NN);
    CHECK_RC(phgmg_reduced_simulate(r1, xr0, 0.0, SPR_DT, SPR_STEPS, spr_u, NULL, 1e-13, 30, NULL, Y1, NULL, NULL, NULL), PHGMG_OK);
    CHECK_RC(phgmg_reduced_simulate(r2, xr0, 0.0, SPR_DT, SPR_STEPS, spr_u, NULL, 1e-13, 30, NULL, Y2, NULL, NULL, NULL), PHGMG_OK);
    CHECK_LE(spr_maxdiff(SPR_STEPS + 1, Y1, Y2, &sy), 1e-10 * sy);
    CHECK(sy > 0.05);
  }
  phgmg_reduced_destroy(r1); phgmg_reduced_destroy(r2); phgmg_study_destroy(st);
  free(X);
}

/* Springs with a mass matrix E = blockdiag(I, c I) (c = 2.5 on the momenta;
   E = I on the positions, where the springs act: the rule of 1.9) against
   the standard model of x~ = E x: Q~ = Q E^-1, the same springs (x~ = x on
   the positions). The co-states, so the outputs, agree: 1e-10 relative.
   GMG-POD reduces the descriptor model to a port-Hamiltonian one with
   Hr = H o phi (H with E: 1/2 x^T E^T Q x + sum_k E(i, i) w_k phi(s_k)). */
TEST(test_springs_mass) {
  static spr_model m;
  static double E[SPR_N * SPR_N], Qt[SPR_N * SPR_N];
  const double c = 2.5;
  phgmg_ph_system de, st;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  const size_t nx = (size_t)SPR_N * (SPR_STEPS + 1);
  double *X = (double *)malloc(sizeof(double) * nx), x0[SPR_N], xt0[SPR_N], Y1[SPR_STEPS + 1], Y2[SPR_STEPS + 1], sy;
  double xr0[10] = {0}, XR[10 * (SPR_STEPS + 1)], xf[SPR_N], Jr[100], Rr[100], ev[10], *work;
  int i, j, n;
  spr_build(&m);
  for (j = 0; j < SPR_N; ++j) {
    E[j + j * SPR_N] = j % 2 ? c : 1.0;
    for (i = 0; i < SPR_N; ++i) Qt[i + j * SPR_N] = m.Q[i + j * SPR_N] / E[j + j * SPR_N];
  }
  memset(&de, 0, sizeof de);
  de.N = SPR_N; de.m = 1; de.J = m.J; de.R = m.R; de.Q = m.Q; de.B = m.B; de.E = E;
  st = de;
  st.E = NULL; st.Q = Qt;
  spr_native(&de, m.idx, m.jdx, m.w);
  spr_native(&st, m.idx, m.jdx, m.w);
  CHECK_RC(phgmg_ph_validate(&de, 0.0, NULL, NULL), PHGMG_OK);
  spr_x0(x0);
  for (i = 0; i < SPR_N; ++i) xt0[i] = E[i + i * SPR_N] * x0[i];
  CHECK_RC(spr_sim(&de, x0, SPR_DT, SPR_STEPS, X, Y1, NULL), PHGMG_OK);
  CHECK_RC(spr_sim(&st, xt0, SPR_DT, SPR_STEPS, NULL, Y2, NULL), PHGMG_OK);
  CHECK_LE(spr_maxdiff(SPR_STEPS + 1, Y1, Y2, &sy), 1e-10 * sy);
  CHECK(sy > 0.05);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = 10;
  CHECK_RC(phgmg_reduce(&red, &de, X, SPR_N, SPR_STEPS + 1, &o, NULL, NULL), PHGMG_OK);
  if (red) {
    const phgmg_rom *rom = phgmg_reduced_rom(red);
    work = (double *)malloc(sizeof(double) * (phgmg_rom_eval_work_size(rom) + 1));
    for (i = 0; i < 10; ++i) xr0[i] = 0.0;
    CHECK_RC(phgmg_reduced_simulate(red, xr0, 0.0, SPR_DT, SPR_STEPS, spr_u, NULL, 1e-13, 30, XR, NULL, NULL, NULL, NULL), PHGMG_OK);
    for (n = 0; n <= SPR_STEPS; n += 20) {
      const double Hr = phgmg_rom_hamiltonian(rom, XR + (size_t)n * 10, work);
      double H;
      phgmg_reduced_lift(red, XR + (size_t)n * 10, xf);
      H = phgmg_ph_hamiltonian(&de, xf);
      CHECK_LE(fabs(Hr - H), 1e-12 * fabs(H) + 1e-15);
    }
    CHECK_RC(phgmg_rom_structure(rom, XR + 10 * 60, Jr, Rr, work), PHGMG_OK);
    CHECK_RC(phgmg_sym_eig(10, Rr, 10, ev, NULL, 10), PHGMG_OK);
    CHECK(ev[0] >= -1e-12 * fabs(ev[9]) && ev[9] > 0.0);
    free(work);
  }
  phgmg_reduced_destroy(red);
  free(X);
}

SUITE(springs) {
  RUN(test_springs_mass);
  RUN(test_springs_deim);
  RUN(test_springs_methods);
  RUN(test_springs_dense_band);
  RUN(test_springs_sparse);
  RUN(test_springs_balance);
  RUN(test_springs_reduce);
  RUN(test_springs_refused);
}
