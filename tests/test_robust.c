/* Bad input and faults. Every case asserts the exact result code
   and that the caller's data is unchanged (memcmp against a copy taken before
   the call): wrong or zero dimensions, NaN/Inf in every input and in the
   state, non-physical J, R, Q, B, J - R singular, the GMG non-degeneracy
   condition failing, snapshots of too low rank, negative DEIM weights, Newton
   failure of the full-order and the reduced stepper, too-small workspaces,
   damaged model images, and an allocator that fails at each of its calls in
   turn for every offline entry point (PHGMG_ERR_NOMEM, nothing leaked: the
   test counts live blocks, and `make test-asan` runs it under LSan too).

   With the environment variable PHGMG_ROM_CORPUS=<dir>, test_rom_images also
   writes its real and damaged model images there (the seed corpus of
   tests/fuzz/fuzz_rom.c: `PHGMG_ROM_CORPUS=tests/fuzz/corpus/rom
   ./build/test_run robust/test_rom_images`). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
/* The default allocator goes through a counter (blocks alive), so the calls
   that take no allocator are checked for leaks as well. (Routing it through a
   volatile function pointer also keeps GCC 12 -O2 from a false
   maybe-uninitialized warning on malloc'd workspace inside phgmg_svd.) */
static long g_default_live = 0;
static void *(*volatile rb_sys_malloc)(size_t) = malloc;
static void *rb_malloc(size_t n) { void *p = rb_sys_malloc(n); if (p) g_default_live++; return p; }
static void rb_free(void *p) { if (p) { g_default_live--; free(p); } }
#define PHGMG_MALLOC(sz, user) ((void)(user), rb_malloc(sz))
#define PHGMG_FREE(p, user) ((void)(user), rb_free(p))
/* every sparse LU factorization counts as too much growth: the band fallback */
#define PHGMG_SPARSE_GROWTH 0.5
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include "../examples/msd_models.h"

/* A scratch file name under build/, distinct between concurrent runs (the
   plain and the sanitizer build of the suite). Tests that need a file skip
   that part when it cannot be written. */
static const char *tmp_path(const char *ext) {
  static char buf[4][96];
  static int k = 0;
  char *b = buf[k++ & 3];
  snprintf(b, sizeof buf[0], "build/robust_tmp_%lx_%d.%s",
           (unsigned long)((uintptr_t)&k ^ (uintptr_t)time(NULL) ^ (uintptr_t)clock()), k, ext);
  return b;
}

/* ---- guards: copies of the caller's data, compared after the call ------- */
#define RB_NGUARD 32
static struct { const void *p; size_t n; unsigned char *copy; } rb_g[RB_NGUARD];
static int rb_ng = 0;

static void guard(const void *p, size_t n) {
  if (!p || n == 0) return;
  if (rb_ng >= RB_NGUARD) { th_fail_msg(__FILE__, __LINE__, "too many guards (missing intact())"); return; }
  rb_g[rb_ng].p = p;
  rb_g[rb_ng].n = n;
  rb_g[rb_ng].copy = (unsigned char *)malloc(n);
  if (!rb_g[rb_ng].copy) return;
  memcpy(rb_g[rb_ng].copy, p, n);
  ++rb_ng;
}
/* Structs are compared member by member (their padding bytes are not data). */
static const phgmg_ph_system *rb_sysp = NULL;
static phgmg_ph_system rb_sys;
static const phgmg_reduce_opts *rb_optp = NULL;
static phgmg_reduce_opts rb_opt;
#define RB_NE(a, b, f) ((a)->f != (b)->f)
static int sys_same(const phgmg_ph_system *a, const phgmg_ph_system *b) {
  return !(RB_NE(a, b, N) || RB_NE(a, b, m) || RB_NE(a, b, storage) || RB_NE(a, b, kb) || RB_NE(a, b, J) ||
           RB_NE(a, b, R) || RB_NE(a, b, Q) || RB_NE(a, b, B) || RB_NE(a, b, nl) || RB_NE(a, b, nsep) ||
           RB_NE(a, b, sep_idx) || RB_NE(a, b, sep_w) || RB_NE(a, b, phi) || RB_NE(a, b, dphi) ||
           RB_NE(a, b, ddphi) || RB_NE(a, b, poly_deg) || RB_NE(a, b, poly) || RB_NE(a, b, H_nl) ||
           RB_NE(a, b, grad_nl) || RB_NE(a, b, hess_nl) || RB_NE(a, b, user) || RB_NE(a, b, shifted_factor) ||
           RB_NE(a, b, shifted_solve) || RB_NE(a, b, shifted_user));
}
static int opts_same(const phgmg_reduce_opts *a, const phgmg_reduce_opts *b) {
  return !(RB_NE(a, b, method) || RB_NE(a, b, r) || RB_NE(a, b, qm.rn) || RB_NE(a, b, qm.lambda) || RB_NE(a, b, hyper.on) ||
           RB_NE(a, b, hyper.deim_tol) || RB_NE(a, b, hyper.deim_max) || RB_NE(a, b, hyper.allow_negative) || RB_NE(a, b, dt) ||
           RB_NE(a, b, degeneracy_tol) || RB_NE(a, b, cache.pod_basis) || RB_NE(a, b, cache.pod_cols) ||
           RB_NE(a, b, cache.grad_basis) || RB_NE(a, b, cache.grad_cols) || RB_NE(a, b, cache.deim_pts) || RB_NE(a, b, cache.deim_w) ||
           RB_NE(a, b, cache.deim_count));
}
#undef RB_NE
static void guard_opts(const phgmg_reduce_opts *o) { rb_optp = o; rb_opt = *o; }

/* 1 if every guarded buffer still holds its bytes; drops the guards. */
static int intact(void) {
  int ok = 1, i;
  for (i = 0; i < rb_ng; ++i) {
    if (memcmp(rb_g[i].p, rb_g[i].copy, rb_g[i].n) != 0) ok = 0;
    free(rb_g[i].copy);
  }
  rb_ng = 0;
  if (rb_sysp && !sys_same(rb_sysp, &rb_sys)) ok = 0;
  if (rb_optp && !opts_same(rb_optp, &rb_opt)) ok = 0;
  rb_sysp = NULL;
  rb_optp = NULL;
  return ok;
}
/* The system struct and every array it points to (sizes permitting). */
static void guard_sys(const phgmg_ph_system *s) {
  size_t len;
  rb_sysp = s;
  rb_sys = *s;
  if (s->N < 1 || s->m < 1 || s->m > s->N) return;
  len = s->storage == PHGMG_BANDED && s->kb >= 0 && s->kb < s->N ? (size_t)(2 * s->kb + 1) * (size_t)s->N
                                                                 : (size_t)s->N * (size_t)s->N;
  guard(s->J, len * sizeof(double));
  guard(s->R, len * sizeof(double));
  guard(s->Q, len * sizeof(double));
  guard(s->B, (size_t)s->N * (size_t)s->m * sizeof(double));
  if (s->nl == PHGMG_NL_SEPARABLE && s->nsep > 0) {
    guard(s->sep_idx, (size_t)s->nsep * sizeof(int));
    if (s->sep_w) guard(s->sep_w, (size_t)s->nsep * sizeof(double));
    if (s->poly) guard(s->poly, ((size_t)s->poly_deg + 1) * sizeof(double));
  }
}

/* Expect an exact code and intact guarded data. */
#define EXPECT(call, code) do { phgmg_result rb_rc_ = (call); CHECK_RC(rb_rc_, code); CHECK(intact()); } while (0)

/* ---- a counting allocator that can fail at its k-th call ----------------- */
typedef struct falloc { long calls, fail_at, live, peak; } falloc;
static void *fa_alloc(size_t n, void *u) {
  falloc *f = (falloc *)u;
  void *p;
  f->calls++;
  if (f->fail_at > 0 && f->calls == f->fail_at) return NULL;
  p = malloc(n);
  if (p) { f->live++; if (f->live > f->peak) f->peak = f->live; }
  return p;
}
static void fa_free(void *p, void *u) {
  falloc *f = (falloc *)u;
  if (!p) return;
  f->live--;
  free(p);
}

/* An offline operation under test: runs with allocator a, registers guards
   for its inputs, returns the code; undo() releases what a success produced. */
typedef phgmg_result (*oom_op)(const phgmg_allocator *a, void *ctx);
typedef void (*oom_undo)(void *ctx);

/* Count the allocations of a successful run, then fail the 1st, 2nd, ...
   one: each run must return PHGMG_ERR_NOMEM, leave no block alive and the
   inputs unchanged. Returns the number of allocator calls of the good run. */
static falloc g_fa;  /* the sweep's counter (global: objects made earlier may use it) */
static const phgmg_allocator g_fa_alloc = {fa_alloc, fa_free, &g_fa};

static long oom_sweep(const char *name, oom_op op, oom_undo undo, void *ctx) {
  falloc f;
  phgmg_allocator a;
  long total, k;
  phgmg_result rc;
  char msg[200];
  (void)f;
#define f g_fa
  memset(&f, 0, sizeof f);
  a = g_fa_alloc;
  rc = op(&a, ctx);
  CHECK(intact());
  if (rc != PHGMG_OK) {
    snprintf(msg, sizeof msg, "%s: the run without failures gave %s", name, phgmg_result_string(rc));
    th_fail_msg(__FILE__, __LINE__, msg);
    return 0;
  }
  if (undo) undo(ctx);
  CHECK(f.live == 0);
  total = f.calls;
  CHECK(total > 0);
  for (k = 1; k <= total; ++k) {
    int ok_in;
    f.calls = 0; f.live = 0; f.fail_at = k;
    rc = op(&a, ctx);
    ok_in = intact();
    if (rc == PHGMG_OK && undo) undo(ctx);
    if (rc != PHGMG_ERR_NOMEM || f.live != 0 || !ok_in) {
      snprintf(msg, sizeof msg, "%s: allocation %ld of %ld failed: got %s, %ld blocks alive, inputs %s",
               name, k, total, phgmg_result_string(rc), f.live, ok_in ? "intact" : "CHANGED");
      th_fail_msg(__FILE__, __LINE__, msg);
    }
  }
  f.fail_at = 0;
#undef f
  return total;
}

/* ---- small models --------------------------------------------------------- */
static double *rand_mat(int rows, int cols, double scale) {
  double *A = (double *)malloc(sizeof(double) * (size_t)rows * (size_t)(cols ? cols : 1));
  int i;
  for (i = 0; i < rows * cols; ++i) A[i] = scale * th_rand();
  return A;
}

static void u_sin(double t, double *u, void *user) { (void)user; u[0] = 0.1 * sin(t); }

/* A small dense system with J canonical (pairs), R = diag(r_diag) on the
   second of each pair, Q = I, B = e_2: N even. All arrays owned. */
typedef struct hsys { phgmg_ph_system sys; double *J, *R, *Q, *B; } hsys;
static void hsys_make(hsys *h, int N, double rdiag) {
  int i;
  memset(h, 0, sizeof *h);
  h->J = (double *)calloc((size_t)N * N, sizeof(double));
  h->R = (double *)calloc((size_t)N * N, sizeof(double));
  h->Q = (double *)calloc((size_t)N * N, sizeof(double));
  h->B = (double *)calloc((size_t)N * 2, sizeof(double));
  for (i = 0; i + 1 < N; i += 2) {
    h->J[i + (i + 1) * N] = 1.0;
    h->J[(i + 1) + i * N] = -1.0;
    h->R[(i + 1) + (i + 1) * N] = rdiag;
  }
  for (i = 0; i < N; ++i) h->Q[i + i * N] = 1.0;
  h->B[1] = 1.0;
  h->sys.N = N; h->sys.m = 1;
  h->sys.J = h->J; h->sys.R = h->R; h->sys.Q = h->Q; h->sys.B = h->B;
}
static void hsys_free(hsys *h) { free(h->J); free(h->R); free(h->Q); free(h->B); }

static phgmg_reduce_opts ropts(phgmg_method meth, int r) {
  phgmg_reduce_opts o;
  memset(&o, 0, sizeof o);
  o.method = meth; o.r = r; o.qm.rn = 2;
  return o;
}

/* phgmg_reduce with guards on every input; *out must stay NULL on failure. */
static phgmg_result reduce_g(const phgmg_ph_system *sys, const double *X, int ldx, int ns,
                             const phgmg_reduce_opts *o, phgmg_reduce_info *info) {
  phgmg_reduced *red = NULL;
  phgmg_result rc;
  guard_sys(sys);
  if (X && sys->N > 0 && ns > 0 && ldx >= sys->N) guard(X, sizeof(double) * (size_t)ldx * (size_t)ns);
  guard_opts(o);
  rc = phgmg_reduce(&red, sys, X, ldx, ns, o, info, NULL);
  if (rc != PHGMG_OK) CHECK(red == NULL);
  phgmg_reduced_destroy(red);
  return rc;
}

/* ========================================================================== */
TEST(test_dims_reduce) {
  msd_linear M;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  phgmg_ph_system s;
  double *X;
  const int N = 12, ns = 20;
  CHECK(msd_linear_build(&M, 6, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  X = rand_mat(N, ns, 1.0);
  o = ropts(PHGMG_METHOD_GMG_POD, 4);
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_OK); /* control */
  /* NULL arguments */
  CHECK_RC(phgmg_reduce(NULL, &M.sys, X, N, ns, &o, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_reduce(&red, NULL, X, N, ns, &o, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_reduce(&red, &M.sys, NULL, N, ns, &o, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_reduce(&red, &M.sys, X, N, ns, NULL, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  /* zero / wrong dimensions of the data */
  EXPECT(reduce_g(&M.sys, X, N, 0, &o, NULL), PHGMG_ERR_SIZE);
  EXPECT(reduce_g(&M.sys, X, N, -3, &o, NULL), PHGMG_ERR_SIZE);
  EXPECT(reduce_g(&M.sys, X, N - 1, ns, &o, NULL), PHGMG_ERR_SIZE);
  s = M.sys; s.N = 0;
  EXPECT(reduce_g(&s, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  s = M.sys; s.m = 0;
  EXPECT(reduce_g(&s, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  s = M.sys; s.m = N + 1;
  EXPECT(reduce_g(&s, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  /* r out of range: GMG needs m < r <= N */
  o.r = 1;  EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);  /* r == m */
  o.r = 0;  EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  o.r = -2; EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  o.r = N + 1; EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  o = ropts(PHGMG_METHOD_GMG_QM, 1);
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  o.r = 4; o.qm.rn = N - 3;   /* r + rn > N */
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  o.qm.rn = 65;               /* beyond the online buffers */
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  /* SP methods: 1 <= r <= min(N, ns) */
  o = ropts(PHGMG_METHOD_SP1, 0);
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  o.r = N + 1; EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  o.r = 6;     EXPECT(reduce_g(&M.sys, X, N, 5, &o, NULL), PHGMG_ERR_SIZE); /* r > ns */
  o = ropts(PHGMG_METHOD_SP2, N + 1);
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  /* a cached POD basis with too few columns */
  {
    double *V = rand_mat(N, 3, 1.0);
    o = ropts(PHGMG_METHOD_GMG_POD, 5); o.cache.pod_basis = V; o.cache.pod_cols = 3; /* needs r - m = 4 */
    EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
    o = ropts(PHGMG_METHOD_SP1, 4); o.cache.pod_basis = V; o.cache.pod_cols = 3;
    EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
    free(V);
  }
  /* bad options and unsupported model kinds */
  o = ropts((phgmg_method)0, 4);
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_INVALID_ARG);
  o = ropts((phgmg_method)6, 4);
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_INVALID_ARG);
  o = ropts(PHGMG_METHOD_GMG_MANIFOLD, 4);   /* needs its eta */
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_INVALID_ARG);
  o = ropts(PHGMG_METHOD_GMG_POD, 4);        /* GENERAL without its callbacks */
  s = M.sys; s.nl = PHGMG_NL_GENERAL;
  EXPECT(reduce_g(&s, X, N, ns, &o, NULL), PHGMG_ERR_INVALID_ARG);
  free(X);
  msd_linear_free(&M);
}

TEST(test_dims_validate) {
  msd_linear M;
  phgmg_ph_system s;
  double rc_out = 7.0;
  int bad_idx[2] = {0, 12};
  double poly[3] = {0, 0, 1};
  CHECK(msd_linear_build(&M, 6, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  guard_sys(&M.sys);
  EXPECT(phgmg_ph_validate(&M.sys, 0.0, &rc_out, NULL), PHGMG_OK);
  CHECK(rc_out > 1e-6 && rc_out <= 1.0);
  CHECK_RC(phgmg_ph_validate(NULL, 0.0, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  s = M.sys; s.N = 0;  guard_sys(&s); EXPECT(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  s = M.sys; s.N = -4; guard_sys(&s); EXPECT(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  s = M.sys; s.m = 0;  guard_sys(&s); EXPECT(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  s = M.sys; s.m = 13; guard_sys(&s); EXPECT(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  s = M.sys; s.storage = (phgmg_storage)3; guard_sys(&s);
  EXPECT(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  s = M.sys; s.storage = PHGMG_BANDED; s.kb = 12; guard_sys(&s);  /* kb > N - 1 */
  EXPECT(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  s = M.sys; s.storage = PHGMG_BANDED; s.kb = -1; guard_sys(&s);
  EXPECT(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  s = M.sys; s.J = NULL; guard_sys(&s); EXPECT(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  s = M.sys; s.B = NULL; guard_sys(&s); EXPECT(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  /* separable part: an index outside 0..N-1, a negative count */
  s = M.sys; s.nl = PHGMG_NL_SEPARABLE; s.nsep = 2; s.sep_idx = bad_idx; s.poly = poly; s.poly_deg = 2;
  guard_sys(&s); EXPECT(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  bad_idx[1] = -1;
  guard_sys(&s); EXPECT(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  bad_idx[1] = 3;
  guard_sys(&s); EXPECT(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_OK);
  s.nsep = -1;
  guard_sys(&s); EXPECT(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  s.nsep = 2; s.poly = NULL;
  guard_sys(&s); EXPECT(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  msd_linear_free(&M);
}

TEST(test_dims_simulate) {
  msd_linear M;
  phgmg_ph_system s;
  double x0[12] = {0}, X[12 * 4], H[4], S[4], D[4];
  phgmg_energy en;
  phgmg_gl3_opts go;
  int done = 77;
  CHECK(msd_linear_build(&M, 6, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  memset(X, 0x5a, sizeof X);
  en.H = H; en.S = S; en.D = NULL;
#define SIM(sysp, dt, nst, opts, enp) \
  phgmg_simulate(sysp, x0, 0.0, dt, nst, u_sin, NULL, opts, X, NULL, enp, NULL, &done, NULL)
  guard(x0, sizeof x0); guard(X, sizeof X); guard_sys(&M.sys);
  EXPECT(SIM(&M.sys, 0.1, -1, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK(done == 0);
  guard(X, sizeof X); EXPECT(SIM(&M.sys, 0.0, 3, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  guard(X, sizeof X); EXPECT(SIM(&M.sys, -0.1, 3, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  guard(X, sizeof X); EXPECT(SIM(&M.sys, (double)NAN, 3, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  guard(X, sizeof X); EXPECT(SIM(&M.sys, (double)INFINITY, 3, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  guard(X, sizeof X); EXPECT(SIM(&M.sys, 0.1, 3, NULL, &en), PHGMG_ERR_INVALID_ARG); /* en.D NULL */
  memset(&go, 0, sizeof go); go.max_iter = -1;
  guard(X, sizeof X); EXPECT(SIM(&M.sys, 0.1, 3, &go, NULL), PHGMG_ERR_INVALID_ARG);
  memset(&go, 0, sizeof go); go.tol = (double)NAN;
  guard(X, sizeof X); EXPECT(SIM(&M.sys, 0.1, 3, &go, NULL), PHGMG_ERR_INVALID_ARG);
  s = M.sys; s.N = 0; guard(X, sizeof X); EXPECT(SIM(&s, 0.1, 3, NULL, NULL), PHGMG_ERR_SIZE);
  s = M.sys; s.m = 0; guard(X, sizeof X); EXPECT(SIM(&s, 0.1, 3, NULL, NULL), PHGMG_ERR_SIZE);
  s = M.sys; s.m = 20; guard(X, sizeof X); EXPECT(SIM(&s, 0.1, 3, NULL, NULL), PHGMG_ERR_SIZE);
  /* control: nsteps = 0 records x0 only */
  en.D = D;
  CHECK_RC(SIM(&M.sys, 0.1, 0, NULL, &en), PHGMG_OK);
  CHECK(done == 0 && X[0] == 0.0 && H[0] == 0.0 && S[0] == 0.0 && D[0] == 0.0);
#undef SIM
  {
    phgmg_gl3 *g = (phgmg_gl3 *)&go;
    s = M.sys; s.N = 0;
    CHECK_RC(phgmg_gl3_create(&g, &s, 0.1, NULL, NULL), PHGMG_ERR_SIZE);
    CHECK(g == NULL);
    CHECK_RC(phgmg_gl3_create(NULL, &M.sys, 0.1, NULL, NULL), PHGMG_ERR_INVALID_ARG);
    CHECK_RC(phgmg_gl3_step(NULL, 0.0, x0, NULL, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  }
  msd_linear_free(&M);
}

/* a random stable linear ROM of order r with m ports */
static void lin_rom(phgmg_rom *rom, int r, int m, phgmg_real *K, phgmg_real *Qh, phgmg_real *Bh) {
  int i, j;
  for (j = 0; j < r; ++j)
    for (i = 0; i < r; ++i) {
      K[i + j * r] = (phgmg_real)(i == j ? -0.2 : (i < j ? 1.0 : -1.0) / (1.0 + i + j));
      Qh[i + j * r] = (phgmg_real)(i == j ? 2.0 : 0.0);
    }
  for (i = 0; i < r * m; ++i) Bh[i] = (phgmg_real)(i % 3 == 0 ? 1.0 : 0.0);
  memset(rom, 0, sizeof *rom);
  rom->kind = PHGMG_ROM_LINEAR; rom->r = r; rom->m = m; rom->K = K; rom->Qh = Qh; rom->Bh = Bh;
}

TEST(test_dims_rom_stepper_init) {
  static double mem[4096];
  phgmg_real K[16], Qh[16], Bh[8];
  phgmg_rom rom, bad;
  phgmg_rom_stepper st;
  size_t need;
  lin_rom(&rom, 4, 2, K, Qh, Bh);
  need = phgmg_rom_stepper_memsize(&rom);
  CHECK(need > 0 && need <= sizeof mem);
  memset(mem, 0x3c, sizeof mem);
  memset(&st, 0x11, sizeof st);
#define INIT(romp, dt, msz) phgmg_rom_stepper_init(&st, romp, (phgmg_real)(dt), 0, 0, mem, msz)
#define G() do { guard(&st, sizeof st); guard(mem, sizeof mem); guard(&rom, sizeof rom); } while (0)
  G(); EXPECT(INIT(&rom, 0.1, need - 1), PHGMG_ERR_WORKSPACE);
  G(); EXPECT(INIT(&rom, 0.1, 0), PHGMG_ERR_WORKSPACE);
  G(); EXPECT(INIT(&rom, 0.0, need), PHGMG_ERR_INVALID_ARG);
  G(); EXPECT(INIT(&rom, -1.0, need), PHGMG_ERR_INVALID_ARG);
  G(); EXPECT(INIT(&rom, NAN, need), PHGMG_ERR_INVALID_ARG);
  G(); EXPECT(INIT(&rom, INFINITY, need), PHGMG_ERR_INVALID_ARG);
  G(); EXPECT(INIT(NULL, 0.1, need), PHGMG_ERR_INVALID_ARG);
  G(); EXPECT(phgmg_rom_stepper_init(&st, &rom, (phgmg_real)0.1, 0, 0, NULL, need), PHGMG_ERR_INVALID_ARG);
  G(); EXPECT(phgmg_rom_stepper_init(&st, &rom, (phgmg_real)0.1, 0, 0, (char *)mem + 1, need), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_rom_stepper_init(NULL, &rom, (phgmg_real)0.1, 0, 0, mem, need), PHGMG_ERR_INVALID_ARG);
  bad = rom; bad.r = 0;     G(); EXPECT(INIT(&bad, 0.1, sizeof mem), PHGMG_ERR_SIZE);
  bad = rom; bad.r = -1;    G(); EXPECT(INIT(&bad, 0.1, sizeof mem), PHGMG_ERR_SIZE);
  bad = rom; bad.m = 5;     G(); EXPECT(INIT(&bad, 0.1, sizeof mem), PHGMG_ERR_SIZE);
  bad = rom; bad.m = -1;    G(); EXPECT(INIT(&bad, 0.1, sizeof mem), PHGMG_ERR_SIZE);
  bad = rom; bad.nd = -1;   G(); EXPECT(INIT(&bad, 0.1, sizeof mem), PHGMG_ERR_SIZE);
  bad = rom; bad.rn = -1;   G(); EXPECT(INIT(&bad, 0.1, sizeof mem), PHGMG_ERR_SIZE);
  bad = rom; bad.r = 5000;  G(); EXPECT(INIT(&bad, 0.1, sizeof mem), PHGMG_ERR_SIZE);
  bad = rom; bad.kind = 3;  G(); EXPECT(INIT(&bad, 0.1, sizeof mem), PHGMG_ERR_INVALID_ARG);
  bad = rom; bad.K = NULL;  G(); EXPECT(INIT(&bad, 0.1, sizeof mem), PHGMG_ERR_INVALID_ARG);
  bad = rom; bad.Bh = NULL; G(); EXPECT(INIT(&bad, 0.1, sizeof mem), PHGMG_ERR_INVALID_ARG);
  bad = rom; bad.nd = 2;    G(); EXPECT(INIT(&bad, 0.1, sizeof mem), PHGMG_ERR_INVALID_ARG); /* no P0/w/poly */
  bad = rom; bad.kind = PHGMG_ROM_QUADRATIC; /* rn = 0 */
  G(); EXPECT(INIT(&bad, 0.1, sizeof mem), PHGMG_ERR_SIZE);
  bad = rom; bad.Phi = K;   /* a step map without Gam/SX/SU/dt */
  G(); EXPECT(INIT(&bad, 0.1, sizeof mem), PHGMG_ERR_INVALID_ARG);
  CHECK(phgmg_rom_stepper_memsize(&bad) == 0);
  guard(&rom, sizeof rom);   /* a successful init writes st and mem, never the model */
  EXPECT(INIT(&rom, 0.1, need), PHGMG_OK);
  {
    phgmg_real x[4] = {1, 2, 3, 4};
    CHECK_RC(phgmg_rom_step(&st, NULL, NULL, NULL, NULL), PHGMG_ERR_INVALID_ARG);
    CHECK_RC(phgmg_rom_step(NULL, x, NULL, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  }
#undef INIT
#undef G
}

/* ---- NaN / Inf ------------------------------------------------------------ */
static void u_nan_late(double t, double *u, void *user) { (void)user; u[0] = t > 0.25 ? (double)NAN : 0.1; }
static void u_inf(double t, double *u, void *user) { (void)user; (void)t; u[0] = (double)INFINITY; }

TEST(test_naninf_system) {
  const double bad[3] = {(double)NAN, (double)INFINITY, -(double)INFINITY};
  int st, which, b;
  for (st = 0; st < 2; ++st) {
    msd_linear M;
    const phgmg_storage sto = st ? PHGMG_BANDED : PHGMG_DENSE;
    const int N = 12, ns = 20;
    double *X = rand_mat(N, ns, 1.0);
    CHECK(msd_linear_build(&M, 6, NULL, NULL, NULL, sto) == 0);
    for (which = 0; which < 4; ++which)
      for (b = 0; b < 3; ++b) {
        double *A = which == 0 ? M.J : which == 1 ? M.R : which == 2 ? M.Q : M.B;
        /* entry (4,5) of J, R, Q (inside the band), or B(4) */
        const size_t at = which == 3 ? 4 : (st ? (size_t)(2 + 4 - 5) + 5 * 5 : (size_t)4 + 5 * 12);
        const double keep = A[at];
        phgmg_reduce_opts o = ropts(PHGMG_METHOD_GMG_POD, 4);
        phgmg_jr_factor *f = NULL;
        phgmg_gl3 *g = NULL;
        A[at] = bad[b];
        guard_sys(&M.sys);
        EXPECT(phgmg_ph_validate(&M.sys, 0.0, NULL, NULL), PHGMG_ERR_NANINF);
        EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_NANINF);
        if (which < 2) {
          guard_sys(&M.sys);
          EXPECT(phgmg_jr_factor_create(&f, &M.sys, NULL, NULL), PHGMG_ERR_NANINF);
          CHECK(f == NULL);
        }
        if (!st) { /* the linear step map checks every matrix */
          guard_sys(&M.sys);
          EXPECT(phgmg_gl3_create(&g, &M.sys, 0.1, NULL, NULL), PHGMG_ERR_NANINF);
          CHECK(g == NULL);
        }
        A[at] = keep;
      }
    EXPECT(phgmg_ph_validate(&M.sys, 0.0, NULL, NULL), PHGMG_OK);
    if (st) {
      /* the unused corners of banded storage are not data: NaN there is fine */
      M.J[0] = M.R[1] = M.Q[0] = (double)NAN;               /* (i,0) for i = -2, -1 */
      M.J[(size_t)(2 + 2) + 11 * 5] = (double)NAN;         /* (13, 11): below the matrix */
      guard_sys(&M.sys);
      EXPECT(phgmg_ph_validate(&M.sys, 0.0, NULL, NULL), PHGMG_OK);
    }
    /* snapshots: NaN/Inf anywhere in the used rows; padding rows are not data */
    {
      double *Xp = rand_mat(N + 2, ns, 1.0);
      phgmg_reduce_opts o = ropts(PHGMG_METHOD_SP1, 4);
      for (b = 0; b < 3; ++b) {
        const double keep = X[5 + 7 * N];
        X[5 + 7 * N] = bad[b];
        EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_NANINF);
        X[5 + 7 * N] = keep;
        X[(ns - 1) * N + N - 1] = bad[b];      /* the very last element */
        EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_NANINF);
        X[(ns - 1) * N + N - 1] = 0.5;
      }
      Xp[N + 0 * (N + 2)] = (double)NAN; /* padding of columns 0 and 3 */
      Xp[N + 1 + 3 * (N + 2)] = (double)INFINITY;
      EXPECT(reduce_g(&M.sys, Xp, N + 2, ns, &o, NULL), PHGMG_OK);
      free(Xp);
    }
    free(X);
    msd_linear_free(&M);
  }
  /* the separable part: weights and polynomial coefficients */
  {
    msd_nonlinear M;
    msd_nl_opts no;
    double w[4] = {1, 1, 1, 1};
    memset(&no, 0, sizeof no); no.n = 4;
    CHECK(msd_nonlinear_build(&M, &no) == 0);
    guard_sys(&M.sys); EXPECT(phgmg_ph_validate(&M.sys, 0.0, NULL, NULL), PHGMG_OK);
    M.poly[4] = (double)NAN;
    guard_sys(&M.sys); EXPECT(phgmg_ph_validate(&M.sys, 0.0, NULL, NULL), PHGMG_ERR_NANINF);
    M.poly[4] = 0.25;
    w[2] = (double)INFINITY; M.sys.sep_w = w;
    guard_sys(&M.sys); EXPECT(phgmg_ph_validate(&M.sys, 0.0, NULL, NULL), PHGMG_ERR_NANINF);
    msd_nonlinear_free(&M);
  }
}

TEST(test_naninf_input_and_state) {
  msd_linear L;
  msd_nonlinear M;
  msd_nl_opts no;
  double x0[12], X[12 * 6], Y[6];
  int done = -1, k, i;
  CHECK(msd_linear_build(&L, 6, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  memset(&no, 0, sizeof no); no.n = 6;
  CHECK(msd_nonlinear_build(&M, &no) == 0);
  for (i = 0; i < 12; ++i) x0[i] = 0.1 * th_rand();
  for (k = 0; k < 3; ++k) {
    /* k = 0: linear, step map; 1: nonlinear, Newton; 2: linear, Newton */
    const phgmg_ph_system *s = k == 1 ? &M.sys : &L.sys;
    phgmg_gl3_opts go;
    memset(&go, 0, sizeof go);
    go.no_step_map = k == 2;
    /* a NaN input at the third step: two steps recorded, the rest untouched */
    memset(X, 0x5a, sizeof X);
    guard(x0, sizeof x0); guard(X + 3 * 12, sizeof(double) * 3 * 12);
    EXPECT(phgmg_simulate(s, x0, 0.0, 0.1, 5, u_nan_late, NULL, &go, X, Y, NULL, NULL, &done, NULL), PHGMG_ERR_NANINF);
    CHECK(done == 2);
    CHECK(memcmp(X, x0, sizeof x0) == 0);
    guard(x0, sizeof x0);
    EXPECT(phgmg_simulate(s, x0, 0.0, 0.1, 5, u_inf, NULL, &go, NULL, NULL, NULL, NULL, &done, NULL), PHGMG_ERR_NANINF);
    CHECK(done == 0);
    /* a NaN / Inf in the state */
    {
      phgmg_gl3 *g = NULL;
      double x[12], inc[2] = {3, 4};
      CHECK_RC(phgmg_gl3_create(&g, s, 0.1, &go, NULL), PHGMG_OK);
      for (i = 0; i < 2 && g; ++i) {
        memcpy(x, x0, sizeof x);
        x[7] = i ? (double)INFINITY : (double)NAN;
        guard(x, sizeof x); guard(inc, sizeof inc);
        EXPECT(phgmg_gl3_step(g, 0.0, x, u_sin, NULL, inc), PHGMG_ERR_NANINF);
      }
      /* the stepper still works afterwards */
      memcpy(x, x0, sizeof x);
      CHECK_RC(phgmg_gl3_step(g, 0.0, x, u_sin, NULL, inc), PHGMG_OK);
      phgmg_gl3_destroy(g);
      x[3] = (double)NAN;
      guard(x, sizeof x);
      EXPECT(phgmg_simulate(s, x, 0.0, 0.1, 5, u_sin, NULL, &go, NULL, NULL, NULL, NULL, &done, NULL), PHGMG_ERR_NANINF);
      CHECK(done == 0);
    }
  }
  /* the online stepper: NaN / Inf in x or in u3; x, y, energy untouched */
  {
    static double mem[4096];
    phgmg_real K[16], Qh[16], Bh[8], x[4] = {1, -1, 0.5, 2}, y[2] = {7, 8}, en[2] = {1, 2};
    phgmg_real u3[6] = {0, 0, 0, 0, 0, 0};
    phgmg_rom rom;
    phgmg_rom_stepper st;
    lin_rom(&rom, 4, 2, K, Qh, Bh);
    CHECK_RC(phgmg_rom_stepper_init(&st, &rom, (phgmg_real)0.1, 0, 0, mem, sizeof mem), PHGMG_OK);
    for (i = 0; i < 4; ++i) {
      phgmg_real xb[4];
      memcpy(xb, x, sizeof x);
      if (i < 2) xb[2] = i ? (phgmg_real)INFINITY : (phgmg_real)NAN;
      else u3[4] = i == 3 ? -(phgmg_real)INFINITY : (phgmg_real)NAN;
      guard(xb, sizeof xb); guard(y, sizeof y); guard(en, sizeof en); guard(u3, sizeof u3);
      EXPECT(phgmg_rom_step(&st, xb, u3, y, en), PHGMG_ERR_NANINF);
      u3[4] = 0;
    }
    CHECK_RC(phgmg_rom_step(&st, x, u3, y, en), PHGMG_OK);
  }
  /* phgmg_reduced_simulate: a NaN initial state and a NaN input */
  {
    double *Xs = rand_mat(12, 30, 1.0), xr[4] = {0, 0, 0, 0}, XR[4 * 6];
    phgmg_reduce_opts o = ropts(PHGMG_METHOD_GMG_POD, 4);
    phgmg_reduced *red = NULL;
    CHECK_RC(phgmg_reduce(&red, &L.sys, Xs, 12, 30, &o, NULL, NULL), PHGMG_OK);
    if (red) {
      xr[1] = (double)NAN;
      guard(xr, sizeof xr);
      EXPECT(phgmg_reduced_simulate(red, xr, 0.0, 0.1, 5, u_sin, NULL, 0, 0, XR, NULL, NULL, NULL, NULL), PHGMG_ERR_NANINF);
      xr[1] = 0;
      EXPECT(phgmg_reduced_simulate(red, xr, 0.0, 0.1, 5, u_nan_late, NULL, 0, 0, XR, NULL, NULL, NULL, NULL), PHGMG_ERR_NANINF);
      CHECK_RC(phgmg_reduced_simulate(red, xr, 0.0, 0.0, 5, u_sin, NULL, 0, 0, XR, NULL, NULL, NULL, NULL), PHGMG_ERR_INVALID_ARG);
      CHECK_RC(phgmg_reduced_simulate(red, xr, 0.0, 0.1, -1, u_sin, NULL, 0, 0, XR, NULL, NULL, NULL, NULL), PHGMG_ERR_INVALID_ARG);
    }
    phgmg_reduced_destroy(red);
    free(Xs);
  }
  msd_linear_free(&L);
  msd_nonlinear_free(&M);
}


/* ---- non-physical systems ------------------------------------------------- */
/* validate and reduce must both give `code` for the system. */
static void expect_sys(const phgmg_ph_system *s, double tol, phgmg_result code, int line) {
  const int N = s->N, ns = 16;
  double *X = rand_mat(N, ns, 1.0), rc_out = 5.0;
  phgmg_reduce_opts o = ropts(PHGMG_METHOD_GMG_POD, 3);
  phgmg_result rc;
  char msg[160];
  guard_sys(s);
  rc = phgmg_ph_validate(s, tol, &rc_out, NULL);
  if (rc != code || !intact()) {
    snprintf(msg, sizeof msg, "line %d: validate gave %s, inputs %s", line, phgmg_result_string(rc),
             "compared");
    th_fail_msg(__FILE__, line, msg);
  }
  if (code != PHGMG_ERR_SINGULAR && code != PHGMG_OK) CHECK(rc_out == 0.0 || rc_out == 5.0);
  if (tol == 0.0) { /* phgmg_reduce validates with the default tolerance */
    rc = reduce_g(s, X, N, ns, &o, NULL);
    if (!intact() || rc != code) {
      snprintf(msg, sizeof msg, "line %d: reduce gave %s", line, phgmg_result_string(rc));
      th_fail_msg(__FILE__, line, msg);
    }
  }
  free(X);
}
#define EXPECT_SYS(s, tol, code) expect_sys(s, tol, code, __LINE__)

TEST(test_structure_violations) {
  hsys h;
  const int N = 8;
  double keep;
  hsys_make(&h, N, 0.5);
  EXPECT_SYS(&h.sys, 0.0, PHGMG_OK);
  /* J not skew: a broken pair, a diagonal entry; a defect at 1e-14 relative
     passes the default tol 1e-12 but not tol 1e-15 */
  h.J[1 + 0 * N] = -0.5;                EXPECT_SYS(&h.sys, 0.0, PHGMG_ERR_NOT_SKEW);
  h.J[1 + 0 * N] = -1.0;
  h.J[3 + 3 * N] = 1e-3;                EXPECT_SYS(&h.sys, 0.0, PHGMG_ERR_NOT_SKEW);
  h.J[3 + 3 * N] = 0.0;
  h.J[1 + 0 * N] = -1.0 - 1e-14;
  EXPECT_SYS(&h.sys, 0.0, PHGMG_OK);
  EXPECT_SYS(&h.sys, 1e-15, PHGMG_ERR_NOT_SKEW);
  h.J[1 + 0 * N] = -1.0;
  /* R not symmetric; Q not symmetric */
  h.R[1 + 3 * N] = 0.1;                 EXPECT_SYS(&h.sys, 0.0, PHGMG_ERR_NOT_SYMMETRIC);
  h.R[3 + 1 * N] = 0.1;                 EXPECT_SYS(&h.sys, 0.0, PHGMG_OK);
  h.R[1 + 3 * N] = h.R[3 + 1 * N] = 0.0;
  h.Q[0 + 2 * N] = 0.2;                 EXPECT_SYS(&h.sys, 0.0, PHGMG_ERR_Q_NOT_SYMMETRIC);
  h.Q[0 + 2 * N] = 0.0;
  /* R indefinite: diagonal, and non-diagonal with eigenvalues 0.5 +- 2 */
  h.R[5 + 5 * N] = -1e-3;               EXPECT_SYS(&h.sys, 0.0, PHGMG_ERR_NOT_PSD);
  h.R[5 + 5 * N] = 0.5;
  h.R[1 + 3 * N] = h.R[3 + 1 * N] = 2.0; EXPECT_SYS(&h.sys, 0.0, PHGMG_ERR_NOT_PSD);
  h.R[1 + 3 * N] = h.R[3 + 1 * N] = 0.5; EXPECT_SYS(&h.sys, 0.0, PHGMG_OK); /* eigenvalues 0, 1 */
  h.R[1 + 3 * N] = h.R[3 + 1 * N] = 0.0;
  /* J - R singular: one pair decoupled (J = 0, R = 0 there), then nearly so */
  h.J[6 + 7 * N] = h.J[7 + 6 * N] = 0.0;
  h.R[7 + 7 * N] = 0.0;
  EXPECT_SYS(&h.sys, 0.0, PHGMG_ERR_SINGULAR);
  {
    phgmg_jr_factor *f = NULL;
    double rc_out = 3.0;
    phgmg_result rc = phgmg_jr_factor_create(&f, &h.sys, &rc_out, NULL);
    CHECK(rc == PHGMG_ERR_SINGULAR);
    CHECK(f == NULL);
  }
  h.J[6 + 7 * N] = 1e-14; h.J[7 + 6 * N] = -1e-14;       /* cond ~ 1e14 */
  EXPECT_SYS(&h.sys, 0.0, PHGMG_ERR_SINGULAR);
  h.J[6 + 7 * N] = 1.0; h.J[7 + 6 * N] = -1.0; h.R[7 + 7 * N] = 0.5;
  EXPECT_SYS(&h.sys, 0.0, PHGMG_OK);
  /* B rank deficient: zero, two equal columns, nearly dependent columns */
  keep = h.B[1];
  h.B[1] = 0.0;                          EXPECT_SYS(&h.sys, 0.0, PHGMG_ERR_RANK);
  h.B[1] = keep;
  h.sys.m = 2;
  h.B[N + 1] = 1.0;                      EXPECT_SYS(&h.sys, 0.0, PHGMG_ERR_RANK);
  h.B[N + 2] = 1e-14;                    EXPECT_SYS(&h.sys, 0.0, PHGMG_ERR_RANK);
  h.B[N + 2] = 1.0;                      EXPECT_SYS(&h.sys, 0.0, PHGMG_OK);
  h.sys.m = 1;
  hsys_free(&h);
  /* banded, N above the dense-eigenvalue limit: R tridiagonal, the band
     Cholesky decides. tridiag(-1, 2, -1) is PSD, tridiag(-1, 1, -1) is not. */
  {
    const int Nb = 2002, kb = 1;
    double *J = (double *)calloc((size_t)3 * Nb, sizeof(double)), *R = (double *)calloc((size_t)3 * Nb, sizeof(double));
    double *Q = (double *)calloc((size_t)3 * Nb, sizeof(double)), *B = (double *)calloc((size_t)Nb, sizeof(double));
    phgmg_ph_system s;
    int j;
    for (j = 0; j < Nb; ++j) {
      Q[kb + j * 3] = 1.0;
      R[kb + j * 3] = 2.0;
      if (j > 0) R[(kb - 1) + j * 3] = -1.0;      /* (j-1, j) */
      if (j + 1 < Nb) R[(kb + 1) + j * 3] = -1.0; /* (j+1, j) */
      if (j % 2 == 1) { J[(kb - 1) + j * 3] = 1.0; J[(kb + 1) + (j - 1) * 3] = -1.0; }
    }
    B[0] = 1.0;
    memset(&s, 0, sizeof s);
    s.N = Nb; s.m = 1; s.storage = PHGMG_BANDED; s.kb = kb; s.J = J; s.R = R; s.Q = Q; s.B = B;
    guard_sys(&s); EXPECT(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_OK);
    for (j = 0; j < Nb; ++j) R[kb + j * 3] = 1.0;
    guard_sys(&s); EXPECT(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_NOT_PSD);
    free(J); free(R); free(Q); free(B);
  }
}

/* GMG non-degeneracy (paper Thm 3.1 / Sec. 3): D^T (J - R)^{-1} D must be
   invertible. With R = 0, G = J^{-1} is skew-symmetric, so V^T G V is a skew
   r x r matrix: singular for every odd r, whatever the basis. J - R = J stays
   invertible, so the system itself validates. */
TEST(test_gmg_degenerate) {
  hsys h;
  const int N = 10, ns = 24;
  double *X = rand_mat(N, ns, 1.0);
  phgmg_reduce_opts o;
  phgmg_reduce_info info;
  hsys_make(&h, N, 0.0);
  guard_sys(&h.sys); EXPECT(phgmg_ph_validate(&h.sys, 0.0, NULL, NULL), PHGMG_OK);
  o = ropts(PHGMG_METHOD_GMG_POD, 3);
  EXPECT(reduce_g(&h.sys, X, N, ns, &o, &info), PHGMG_ERR_DEGENERATE);
  CHECK_LE(info.rcond_dgd, 1e-12);
  o.r = 5;
  EXPECT(reduce_g(&h.sys, X, N, ns, &o, &info), PHGMG_ERR_DEGENERATE);
  o = ropts(PHGMG_METHOD_GMG_QM, 3); o.qm.rn = 2;
  EXPECT(reduce_g(&h.sys, X, N, ns, &o, &info), PHGMG_ERR_DEGENERATE);
  /* even r: a generic skew matrix is invertible */
  o = ropts(PHGMG_METHOD_GMG_POD, 4);
  EXPECT(reduce_g(&h.sys, X, N, ns, &o, &info), PHGMG_OK);
  CHECK(info.rcond_dgd > 1e-6);
  /* the threshold is the caller's: above the measured rcond it fails */
  o.degeneracy_tol = 2.0 * info.rcond_dgd;
  EXPECT(reduce_g(&h.sys, X, N, ns, &o, &info), PHGMG_ERR_DEGENERATE);
  /* with damping on every second coordinate odd r works too (the paper's point) */
  hsys_free(&h);
  hsys_make(&h, N, 0.5);
  o = ropts(PHGMG_METHOD_GMG_POD, 3);
  EXPECT(reduce_g(&h.sys, X, N, ns, &o, &info), PHGMG_OK);
  CHECK(info.rcond_dgd > 1e-6);
  /* SP1: W = Q V (V^T Q V)^{-1} needs V^T Q V invertible, which a positive
     definite Q guarantees; a singular Q is refused up front by the validation,
     whatever r */
  h.Q[9 + 9 * N] = 0.0;
  o = ropts(PHGMG_METHOD_SP1, N);
  EXPECT(reduce_g(&h.sys, X, N, ns, &o, &info), PHGMG_ERR_Q_NOT_PD);
  o.r = N - 1;
  EXPECT(reduce_g(&h.sys, X, N, ns, &o, &info), PHGMG_ERR_Q_NOT_PD);
  hsys_free(&h);
  free(X);
  /* The nonlinear MSD in l-coordinates: J - R = [[0, T], [-T^T, -gamma I]],
     so G = (J - R)^{-1} = [[-gamma T^-T T^-1, -T^-T], [T^-1, 0]]: the
     velocity block of G vanishes. Snapshots whose l-part has rank one give a
     basis D = [B, V1] (B = e_v1) whose span meets the velocity space in two
     dimensions once r >= 3, and D^T G D has a 2 x 2 zero block in a 3 x 3
     matrix: singular. r = 2 is fine. */
  {
    msd_nonlinear M;
    msd_nl_opts no;
    double Xl[6 * 12];
    int i, j;
    memset(&no, 0, sizeof no); no.n = 3;
    CHECK(msd_nonlinear_build(&M, &no) == 0);
    for (j = 0; j < 12; ++j)
      for (i = 0; i < 6; ++i) Xl[i + j * 6] = i < 3 ? (0.5 + 0.1 * j) * (1.0 + i) : th_rand();
    o = ropts(PHGMG_METHOD_GMG_POD, 3);
    EXPECT(reduce_g(&M.sys, Xl, 6, 12, &o, &info), PHGMG_ERR_DEGENERATE);
    o.r = 2;
    EXPECT(reduce_g(&M.sys, Xl, 6, 12, &o, &info), PHGMG_OK);
    CHECK(info.rcond_dgd > 1e-6);
    msd_nonlinear_free(&M);
  }
}

/* Snapshots whose rank is below what the method needs: PHGMG_ERR_SIZE. */
TEST(test_snapshot_rank) {
  msd_linear M;
  const int N = 12, ns = 20;
  double X[12 * 20], Z[12 * 20];
  phgmg_reduce_opts o;
  int i, j;
  CHECK(msd_linear_build(&M, 6, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  /* rank 3, exactly: integer combinations of three integer vectors with no
     component along B = e_2, so the adjusted snapshots keep rank 3 */
  for (j = 0; j < ns; ++j)
    for (i = 0; i < N; ++i) {
      const double v1 = (double)((i * 7) % 5 - 2), v2 = (double)((i * 3) % 4 - 1), v3 = (double)(i % 2 ? i : -1);
      X[i + j * N] = i == 1 ? 0.0 : (double)(j % 3 - 1) * v1 + (double)((j * j) % 5 - 2) * v2 + (double)(j % 4) * v3;
    }
  o = ropts(PHGMG_METHOD_SP1, 3); EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_OK);
  o.r = 4;                        EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  o = ropts(PHGMG_METHOD_SP2, 3); EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_OK);
  o.r = 4;                        EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  o = ropts(PHGMG_METHOD_GMG_POD, 4); /* r - m = 3 = rank */
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_OK);
  o.r = 5;                        EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  /* GMG-QM: V1 takes r - m = 2 of the 3 directions, V2 needs rn from the rest */
  o = ropts(PHGMG_METHOD_GMG_QM, 3); o.qm.rn = 1;
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_OK);
  o.qm.rn = 2;                       EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  /* snapshots along B only: the adjusted snapshots vanish */
  memset(Z, 0, sizeof Z);
  for (j = 0; j < ns; ++j) Z[1 + j * N] = 1.0 + j;
  o = ropts(PHGMG_METHOD_GMG_POD, 2); EXPECT(reduce_g(&M.sys, Z, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  o = ropts(PHGMG_METHOD_SP1, 1);     EXPECT(reduce_g(&M.sys, Z, N, ns, &o, NULL), PHGMG_OK);
  o.r = 2;                            EXPECT(reduce_g(&M.sys, Z, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  /* all zero */
  memset(Z, 0, sizeof Z);
  o = ropts(PHGMG_METHOD_SP1, 1);     EXPECT(reduce_g(&M.sys, Z, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  o = ropts(PHGMG_METHOD_GMG_POD, 2); EXPECT(reduce_g(&M.sys, Z, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  /* the building blocks say the same */
  {
    double V[12 * 4], S[4];
    int k = -1;
    guard(X, sizeof X);
    EXPECT(phgmg_pod(N, ns, X, N, 4, 0.0, V, N, S, &k, NULL), PHGMG_OK);
    CHECK(k == 3);
    guard(X, sizeof X);
    EXPECT(phgmg_pod_hierarchical(N, 1, M.B, ns, X, N, 2, 2, V, V + 2 * N, NULL), PHGMG_ERR_SIZE);
  }
  msd_linear_free(&M);
}

/* Structure-preserving DEIM with a negative weight. The nonlinear MSD in
   l-coordinates with n = 3: the quartic's gradient terms are l_k^3. Snapshots
   with l = c_j z make the gradient snapshots rank one, U ~ z.^3 = (1, -0.6,
   -0.6); Q-DEIM picks the largest entry (term 0) and the weight is
   w = (P^T U)^{-T} U^T 1 = (1 - 0.6 - 0.6) / 1 = -0.2. (r = 2: with a rank-one
   l-part, any GMG basis of r >= 3 is degenerate, see test_gmg_degenerate.) */
TEST(test_deim_negative_weight) {
  msd_nonlinear M;
  msd_nl_opts no;
  const int n = 3, N = 6, ns = 12;
  double X[6 * 12], z[3];
  phgmg_reduce_opts o;
  phgmg_reduce_info info;
  phgmg_reduced *red = NULL;
  int j, i;
  memset(&no, 0, sizeof no); no.n = n;
  CHECK(msd_nonlinear_build(&M, &no) == 0);
  z[0] = 1.0; z[1] = z[2] = cbrt(-0.6);
  for (j = 0; j < ns; ++j) {
    const double c = 0.3 + 0.1 * j;
    for (i = 0; i < n; ++i) X[i + j * N] = c * z[i];
    for (i = n; i < N; ++i) X[i + j * N] = th_rand();
  }
  /* the default hyper-reduction (ECSW) keeps every weight >= 0 here */
  o = ropts(PHGMG_METHOD_GMG_POD, 2); o.hyper.on = 1;
  memset(&info, 0, sizeof info);
  CHECK_RC(phgmg_reduce(&red, &M.sys, X, N, ns, &o, &info, NULL), PHGMG_OK);
  CHECK(info.hyper_method == PHGMG_HYPER_ECSW && info.deim_negative == 0 && info.hyper_min_weight > 0.0);
  CHECK(info.hyper_residual <= 1e-6);
  phgmg_reduced_destroy(red); red = NULL;
  /* the paper's DEIM gives one negative weight */
  o.hyper.kind = PHGMG_HYPER_QDEIM;
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, &info), PHGMG_ERR_NEGATIVE_WEIGHT);
  CHECK(info.deim_negative == 1 && info.deim_modes == 1);
  o.hyper.allow_negative = 1;
  CHECK_RC(phgmg_reduce(&red, &M.sys, X, N, ns, &o, &info, NULL), PHGMG_OK);
  if (red) {
    const phgmg_rom *rom = phgmg_reduced_rom(red);
    CHECK(rom->nd == 1 && info.deim_negative == 1);
    CHECK_LE(fabs((double)rom->w[0] + 0.2), 1e-12);
  }
  phgmg_reduced_destroy(red);
  /* GMG-QM and SP2 see the same gradient snapshots */
  o = ropts(PHGMG_METHOD_GMG_QM, 2); o.qm.rn = 1; o.hyper.on = 1; o.hyper.kind = PHGMG_HYPER_QDEIM;
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, &info), PHGMG_ERR_NEGATIVE_WEIGHT);
  o = ropts(PHGMG_METHOD_SP2, 3); o.hyper.on = 1; o.hyper.kind = PHGMG_HYPER_QDEIM;
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, &info), PHGMG_ERR_NEGATIVE_WEIGHT);
  /* a cached DEIM result (opts.cache.deim_pts/deim_w) is checked the same way */
  {
    int cpts[2] = {0, 2};
    double cw[2] = {1.5, -0.2};
    o = ropts(PHGMG_METHOD_GMG_POD, 2); o.hyper.on = 1;
    o.cache.deim_pts = cpts; o.cache.deim_w = cw; o.cache.deim_count = 2;
    guard(cpts, sizeof cpts); guard(cw, sizeof cw);
    EXPECT(reduce_g(&M.sys, X, N, ns, &o, &info), PHGMG_ERR_NEGATIVE_WEIGHT);
    CHECK(info.deim_negative == 1 && info.deim_modes == 2);
    cw[1] = (double)NAN;
    EXPECT(reduce_g(&M.sys, X, N, ns, &o, &info), PHGMG_ERR_NANINF);
    cw[1] = 0.2; cpts[1] = 3;   /* only 3 terms */
    EXPECT(reduce_g(&M.sys, X, N, ns, &o, &info), PHGMG_ERR_INVALID_ARG);
    cpts[1] = 2; o.cache.deim_count = 4;
    EXPECT(reduce_g(&M.sys, X, N, ns, &o, &info), PHGMG_ERR_SIZE);
    o.cache.deim_count = 2;
    EXPECT(reduce_g(&M.sys, X, N, ns, &o, &info), PHGMG_OK);
  }
  /* without DEIM every term is kept with its own weight: no failure */
  o = ropts(PHGMG_METHOD_SP2, 3);
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, &info), PHGMG_OK);
  /* phgmg_deim itself reports the weight (its caller decides) */
  {
    const double u[3] = {1.0, -0.6, -0.6}, c[4] = {1, 2, 3, -1};
    double F[12], w[3] = {9, 9, 9}, ratio = -1;
    int pts[3] = {-1, -1, -1}, nd = -1, nneg = -1;
    for (j = 0; j < 4; ++j) for (i = 0; i < 3; ++i) F[i + 3 * j] = u[i] * c[j];
    guard(F, sizeof F);
    EXPECT(phgmg_deim(3, 4, F, 3, NULL, 0.0, 0, pts, w, &nd, &nneg, &ratio, NULL), PHGMG_OK);
    CHECK(nd == 1 && nneg == 1 && pts[0] == 0);
    CHECK_LE(fabs(w[0] + 0.2), 1e-14);
    F[4] = (double)NAN;
    guard(F, sizeof F); guard(w, sizeof w); guard(pts, sizeof pts);
    EXPECT(phgmg_deim(3, 4, F, 3, NULL, 0.0, 0, pts, w, &nd, &nneg, &ratio, NULL), PHGMG_ERR_NANINF);
    guard(F, sizeof F);
    EXPECT(phgmg_deim(0, 4, F, 3, NULL, 0.0, 0, pts, w, &nd, &nneg, &ratio, NULL), PHGMG_ERR_SIZE);
    EXPECT(phgmg_deim(3, 4, F, 2, NULL, 0.0, 0, pts, w, &nd, &nneg, &ratio, NULL), PHGMG_ERR_SIZE);
  }
  msd_nonlinear_free(&M);
}

/* Newton failure: a stiff quartic model, a large state and a huge step. The
   stepper returns the failure and leaves the state bit for bit as it was. */
TEST(test_newton_failure) {
  int st;
  for (st = 0; st < 2; ++st) {
    msd_nonlinear M;
    msd_nl_opts no;
    phgmg_gl3 *g = NULL;
    phgmg_gl3_opts go;
    double x[8], inc[2] = {1.5, 2.5}, X[8 * 3];
    int i, done = -1;
    memset(&no, 0, sizeof no); no.n = 4; no.storage = st ? PHGMG_BANDED : PHGMG_DENSE;
    CHECK(msd_nonlinear_build(&M, &no) == 0);
    memset(&go, 0, sizeof go); go.max_iter = 4;
    CHECK_RC(phgmg_gl3_create(&g, &M.sys, 50.0, &go, NULL), PHGMG_OK);
    for (i = 0; i < 8; ++i) x[i] = 30.0 * th_rand();
    guard(x, sizeof x); guard(inc, sizeof inc);
    EXPECT(phgmg_gl3_step(g, 0.0, x, u_sin, NULL, inc), PHGMG_ERR_NOT_CONVERGED);
    CHECK(phgmg_gl3_get_stats(g)->failures >= 1 && phgmg_gl3_get_stats(g)->steps == 0);
    /* the same stepper still takes a step where Newton can converge */
    for (i = 0; i < 8; ++i) x[i] = 1e-3 * th_rand();
    CHECK_RC(phgmg_gl3_step(g, 0.0, x, NULL, NULL, inc), PHGMG_OK);
    phgmg_gl3_destroy(g);
    /* phgmg_simulate reports it too, with the first column recorded */
    for (i = 0; i < 8; ++i) x[i] = 30.0 * th_rand();
    memset(X, 0, sizeof X);
    guard(x, sizeof x); guard(X + 8, sizeof(double) * 16);
    EXPECT(phgmg_simulate(&M.sys, x, 0.0, 50.0, 2, u_sin, NULL, &go, X, NULL, NULL, NULL, &done, NULL),
           PHGMG_ERR_NOT_CONVERGED);
    CHECK(done == 0 && memcmp(X, x, sizeof x) == 0);
    msd_nonlinear_free(&M);
  }
  /* the online stepper on a reduced model of the same kind */
  {
    msd_nonlinear M;
    msd_nl_opts no;
    phgmg_reduce_opts o;
    phgmg_reduced *red = NULL;
    const int N = 16, ns = 40;
    double *X = rand_mat(N, ns, 1.0);
    memset(&no, 0, sizeof no); no.n = 8;
    CHECK(msd_nonlinear_build(&M, &no) == 0);
    o = ropts(PHGMG_METHOD_GMG_POD, 4);
    CHECK_RC(phgmg_reduce(&red, &M.sys, X, N, ns, &o, NULL, NULL), PHGMG_OK);
    if (red) {
      static double mem[1 << 14];
      phgmg_rom_stepper rs;
      phgmg_real xr[4] = {40, -30, 35, 25}, y[1] = {3}, en[2] = {1, 2};
      CHECK_RC(phgmg_rom_stepper_init(&rs, phgmg_reduced_rom(red), (phgmg_real)50.0, (phgmg_real)1e-12, 4, mem, sizeof mem), PHGMG_OK);
      guard(xr, sizeof xr); guard(y, sizeof y); guard(en, sizeof en);
      EXPECT(phgmg_rom_step(&rs, xr, NULL, y, en), PHGMG_ERR_NOT_CONVERGED);
      CHECK(rs.stats.failures == 1 && rs.stats.steps == 0);
    }
    phgmg_reduced_destroy(red);
    free(X);
    msd_nonlinear_free(&M);
  }
}


/* ---- model images: workspace, damage, round trips ------------------------- */
static uint32_t rb_fnv(const unsigned char *b, size_t n) {
  uint32_t h = 2166136261u;
  size_t i;
  for (i = 0; i < n; ++i) { h ^= b[i]; h *= 16777619u; }
  return h;
}
static void rb_put32(unsigned char *b, uint32_t v) {
  b[0] = (unsigned char)v; b[1] = (unsigned char)(v >> 8); b[2] = (unsigned char)(v >> 16); b[3] = (unsigned char)(v >> 24);
}
static uint32_t rb_get32(const unsigned char *b) {
  return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}
/* recompute the trailing checksum (the file format: FNV-1a over all but it) */
static void reseal(unsigned char *b, size_t len) { rb_put32(b + len - 4, rb_fnv(b, len - 4)); }

/* The header is 56 bytes: magic (8), version, scalar size, kind, method, r, m,
   rn, nd, poly_deg, field mask (4 each), dt (8); then the scalars, then the
   checksum. A copy of an image with 8-byte scalars re-encoded as float32. */
static unsigned char *to_f32(const unsigned char *b, size_t len, size_t *len32) {
  const size_t hdr = 56, n = (len - hdr - 4) / 8;
  unsigned char *o = (unsigned char *)malloc(hdr + 4 * n + 4);
  size_t i;
  memcpy(o, b, hdr);
  rb_put32(o + 12, 4);
  for (i = 0; i < n; ++i) {
    uint64_t u = 0;
    double d;
    float f;
    uint32_t v;
    int k;
    for (k = 0; k < 8; ++k) u |= (uint64_t)b[hdr + 8 * i + k] << (8 * k);
    memcpy(&d, &u, 8);
    f = (float)d;
    memcpy(&v, &f, 4);
    rb_put32(o + hdr + 4 * i, v);
  }
  *len32 = hdr + 4 * n + 4;
  reseal(o, *len32);
  return o;
}

static void write_seed(const char *dir, const char *name, const void *b, size_t n) {
  char path[512];
  FILE *f;
  if (!dir) return;
  snprintf(path, sizeof path, "%s/%s", dir, name);
  f = fopen(path, "wb");
  if (!f) return;
  if (fwrite(b, 1, n, f) != n) th_fail_msg(__FILE__, __LINE__, "writing a corpus file");
  fclose(f);
}

/* Two models are the same if every field has the same length and values. */
static int same_rom(const phgmg_rom *a, const phgmg_rom *b) {
  int i;
  if (a->kind != b->kind || a->method != b->method || a->r != b->r || a->m != b->m || a->rn != b->rn ||
      a->nd != b->nd || a->poly_deg != b->poly_deg || a->dt != b->dt)
    return 0;
  for (i = 0; i < PHGMG__NFIELDS; ++i) {
    const phgmg_real *x = phgmg__field_get(a, i), *y = phgmg__field_get(b, i);
    const size_t n = phgmg__field_len(a, i);
    if ((x == NULL) != (y == NULL)) return 0;
    if (x && n && memcmp(x, y, n * sizeof(phgmg_real)) != 0) return 0;
  }
  return 1;
}

/* A few online steps from a fixed state; 0 on any failure. */
static int rom_run(const phgmg_rom *rom, phgmg_real *x, int nsteps) {
  static double mem[1 << 15];
  phgmg_rom_stepper st;
  phgmg_real u3[3 * 4] = {0};
  int n, i;
  if (phgmg_rom_stepper_memsize(rom) > sizeof mem || rom->m > 4) return 0;
  if (phgmg_rom_stepper_init(&st, rom, rom->Phi ? rom->dt : (phgmg_real)0.1, 0, 0, mem, sizeof mem) != PHGMG_OK) return 0;
  for (i = 0; i < rom->r; ++i) x[i] = (phgmg_real)(0.01 * (i + 1));
  for (n = 0; n < nsteps; ++n) {
    for (i = 0; i < 3 * rom->m; ++i) u3[i] = (phgmg_real)(0.1 * sin(0.3 * n + i));
    if (phgmg_rom_step(&st, x, u3, NULL, NULL) != PHGMG_OK) return 0;
  }
  return 1;
}

/* Every check of one model's image; damaged variants go to the corpus too. */
static void check_image(const phgmg_rom *rom, const char *name, const char *dir) {
  static double mem[1 << 15], mem2[1 << 15];
  const size_t len = phgmg_rom_serialized_size(rom);
  unsigned char *b = (unsigned char *)malloc(len + 8), *d = (unsigned char *)malloc(len + 8);
  size_t w = 0, need = 0, i, len32 = 0;
  phgmg_rom r1, r2;
  phgmg_real x1[64], x2[64];
  char fname[96];
  if (!b || !d) { free(b); free(d); CHECK(0); return; }
  /* too small a buffer: nothing written */
  memset(b, 0xee, len + 8);
  guard(b, len + 8); guard(rom, sizeof *rom);
  EXPECT(phgmg_rom_serialize(rom, b, len - 1, &w), PHGMG_ERR_WORKSPACE);
  CHECK_RC(phgmg_rom_serialize(rom, b, len, &w), PHGMG_OK);
  CHECK(w == len);
  snprintf(fname, sizeof fname, "seed_%s.rom", name);
  write_seed(dir, fname, b, len);
  /* round trip, in too small and in enough memory */
  CHECK_RC(phgmg_rom_deserialize_size(b, len, &need), PHGMG_OK);
  CHECK(need <= sizeof mem);
  memset(&r1, 0x77, sizeof r1);
  guard(&r1, sizeof r1); guard(b, len);
  EXPECT(phgmg_rom_deserialize(b, len, &r1, mem, need - 1), PHGMG_ERR_WORKSPACE);
  CHECK_RC(phgmg_rom_deserialize(b, len, &r1, mem, need), PHGMG_OK);
  CHECK(same_rom(rom, &r1));
  CHECK_RC(phgmg_rom_serialize(&r1, d, len, &w), PHGMG_OK);
  CHECK(w == len && memcmp(b, d, len) == 0);
  /* the loaded model steps exactly like the original */
  CHECK(rom_run(rom, x1, 5) && rom_run(&r1, x2, 5) && memcmp(x1, x2, sizeof(phgmg_real) * (size_t)rom->r) == 0);
  /* every truncation, one extra byte, every single-byte change: FORMAT */
  for (i = 0; i < len; ++i) {
    phgmg_result rc = phgmg_rom_deserialize_size(b, i, &need);
    if (rc != PHGMG_ERR_FORMAT) { CHECK_RC(rc, PHGMG_ERR_FORMAT); break; }
  }
  memcpy(d, b, len); d[len] = 0;
  CHECK_RC(phgmg_rom_deserialize_size(d, len + 1, &need), PHGMG_ERR_FORMAT);
  for (i = 0; i < len; ++i) {
    phgmg_result rc;
    d[i] ^= (unsigned char)(1u << (i % 8));
    rc = phgmg_rom_deserialize(d, len, &r2, mem2, sizeof mem2);
    d[i] = b[i];
    if (rc != PHGMG_ERR_FORMAT) { CHECK_RC(rc, PHGMG_ERR_FORMAT); break; }
  }
  memcpy(d, b, len); d[len / 2] ^= 0x10;
  snprintf(fname, sizeof fname, "bad_checksum_%s.rom", name);
  write_seed(dir, fname, d, len);
  /* damage behind a valid checksum: the header and the values are checked */
  {
    struct { size_t at; uint32_t v; const char *what; } hd[] = {
      {8, 2, "version"}, {12, 2, "scalar"}, {16, 0, "kind0"}, {16, 3, "kind3"}, {20, 9, "method"},
      {24, 0, "r0"}, {24, 5000, "rhuge"}, {28, 999, "m_gt_r"}, {40, 33, "polydeg"}, {44, 1u << 20, "mask"}};
    size_t k;
    for (k = 0; k < sizeof hd / sizeof hd[0]; ++k) {
      phgmg_result rc;
      memcpy(d, b, len);
      rb_put32(d + hd[k].at, hd[k].v);
      reseal(d, len);
      memset(&r2, 0x55, sizeof r2);
      guard(&r2, sizeof r2);
      rc = phgmg_rom_deserialize(d, len, &r2, mem2, sizeof mem2);
      CHECK(intact());
      if (rc != PHGMG_ERR_FORMAT) {
        char msg[128];
        snprintf(msg, sizeof msg, "%s: header field %s: got %s", name, hd[k].what, phgmg_result_string(rc));
        th_fail_msg(__FILE__, __LINE__, msg);
      }
      if (rom->kind == PHGMG_ROM_LINEAR && rom->nd > 0 && (k == 0 || k == 9 || k == 6)) {
        snprintf(fname, sizeof fname, "bad_%s_%s.rom", hd[k].what, name);
        write_seed(dir, fname, d, len);
      }
    }
    /* the field mask without a required field (Qh): the sizes no longer add up;
       with the length adjusted too it is caught by the model check */
    memcpy(d, b, len);
    rb_put32(d + 44, rb_get32(d + 44) & ~2u);
    reseal(d, len);
    CHECK_RC(phgmg_rom_deserialize(d, len, &r2, mem2, sizeof mem2), PHGMG_ERR_FORMAT);
    /* a dt that is negative or NaN */
    {
      const double bad_dt[2] = {-1.0, (double)NAN};
      for (k = 0; k < 2; ++k) {
        uint64_t u;
        int j;
        memcpy(d, b, len);
        memcpy(&u, &bad_dt[k], 8);
        for (j = 0; j < 8; ++j) d[48 + j] = (unsigned char)(u >> (8 * j));
        reseal(d, len);
        CHECK_RC(phgmg_rom_deserialize(d, len, &r2, mem2, sizeof mem2), PHGMG_ERR_FORMAT);
      }
    }
    /* NaN / Inf in the first, a middle and the last value */
    if (rb_get32(b + 12) == 8) {
      const size_t nval = (len - 60) / 8, at[3] = {0, nval / 2, nval - 1};
      const uint64_t bits[2] = {0x7ff8000000000000ull, 0xfff0000000000000ull};
      size_t a;
      for (a = 0; a < 3; ++a)
        for (k = 0; k < 2; ++k) {
          int j;
          memcpy(d, b, len);
          for (j = 0; j < 8; ++j) d[56 + 8 * at[a] + j] = (unsigned char)(bits[k] >> (8 * j));
          reseal(d, len);
          CHECK_RC(phgmg_rom_deserialize(d, len, &r2, mem2, sizeof mem2), PHGMG_ERR_FORMAT);
          if (a == 1 && k == 0 && rom->kind == PHGMG_ROM_QUADRATIC) {
            snprintf(fname, sizeof fname, "bad_nan_%s.rom", name);
            write_seed(dir, fname, d, len);
          }
        }
    }
  }
  /* the same model with float32 scalars loads with the values rounded once */
  if (rb_get32(b + 12) == 8) {
    unsigned char *f = to_f32(b, len, &len32);
    const unsigned char *src = b + 56;
    size_t k, fld = 0;
    int ok = 1, fi;
    CHECK_RC(phgmg_rom_deserialize(f, len32, &r2, mem2, sizeof mem2), PHGMG_OK);
    for (fi = 0; fi < PHGMG__NFIELDS; ++fi) {
      const phgmg_real *a = phgmg__field_get(&r2, fi);
      const size_t n = phgmg__field_len(&r2, fi);
      if (!a) continue;
      for (k = 0; k < n; ++k, ++fld) {
        uint64_t u = 0;
        double v;
        int j;
        for (j = 0; j < 8; ++j) u |= (uint64_t)src[8 * fld + j] << (8 * j);
        memcpy(&v, &u, 8);
        if (a[k] != (phgmg_real)(float)v) ok = 0;
      }
    }
    CHECK(ok && 56 + 8 * fld + 4 == len);
    if (rom->m == 1) {
      snprintf(fname, sizeof fname, "seed_f32_%s.rom", name);
      write_seed(dir, fname, f, len32);
    }
    free(f);
  }
  free(b);
  free(d);
}

TEST(test_rom_images) {
  const char *dir = getenv("PHGMG_ROM_CORPUS");
  static const phgmg_real K[4] = {0, -1, 1, (phgmg_real)-0.1}, Qh[4] = {1, 0, 0, 2}, Bh[2] = {0, 1};
  phgmg_rom osc;
  int pass;
  memset(&osc, 0, sizeof osc);
  osc.kind = PHGMG_ROM_LINEAR; osc.r = 2; osc.m = 1; osc.K = K; osc.Qh = Qh; osc.Bh = Bh;
  check_image(&osc, "osc", dir);
  osc.m = 0; osc.Bh = NULL;
  check_image(&osc, "osc_noport", dir);
  for (pass = 0; pass < 2; ++pass) {
    /* reduced models of both MSD examples from short simulations */
    msd_linear L;
    msd_nonlinear M;
    msd_nl_opts no;
    const phgmg_ph_system *s;
    double *X, *x0;
    int N, k;
    const int ns = 61;
    memset(&no, 0, sizeof no); no.n = 6;
    if (pass == 0) { CHECK(msd_linear_build(&L, 8, NULL, NULL, NULL, PHGMG_DENSE) == 0); s = &L.sys; }
    else { CHECK(msd_nonlinear_build(&M, &no) == 0); s = &M.sys; }
    N = s->N;
    X = (double *)malloc(sizeof(double) * (size_t)N * ns);
    x0 = (double *)calloc((size_t)N, sizeof(double));
    CHECK_RC(phgmg_simulate(s, x0, 0.0, 0.1, ns - 1, u_sin, NULL, NULL, X, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
    for (k = 0; k < 3; ++k) {
      static const char *names[2][3] = {{"lin_gmgpod_map", "lin_gmgqm", "lin_sp1"}, {"nl_gmgpod_deim", "nl_gmgqm_deim", "nl_sp2"}};
      static const phgmg_method meth[2][3] = {{PHGMG_METHOD_GMG_POD, PHGMG_METHOD_GMG_QM, PHGMG_METHOD_SP1},
                                             {PHGMG_METHOD_GMG_POD, PHGMG_METHOD_GMG_QM, PHGMG_METHOD_SP2}};
      phgmg_reduce_opts o = ropts(meth[pass][k], 3);
      phgmg_reduced *red = NULL;
      o.dt = 0.1; o.hyper.on = pass && k < 2; o.hyper.allow_negative = 1;
      CHECK_RC(phgmg_reduce(&red, s, X, N, ns, &o, NULL, NULL), PHGMG_OK);
      if (red) check_image(phgmg_reduced_rom(red), names[pass][k], dir);
      if (red && pass == 0 && k == 0) CHECK(phgmg_reduced_rom(red)->Phi != NULL);
      if (red && pass == 1 && k == 1) CHECK(phgmg_reduced_rom(red)->P1 != NULL);
      phgmg_reduced_destroy(red);
    }
    free(X); free(x0);
    if (pass == 0) msd_linear_free(&L); else msd_nonlinear_free(&M);
  }
  /* files: a missing file, a damaged one; nothing allocated stays */
  {
    const char *path = tmp_path("rom");
    phgmg_rom r1;
    void *block = (void *)&r1;
    long live = g_default_live;
    memset(&r1, 0x42, sizeof r1);
    guard(&r1, sizeof r1);
    EXPECT(phgmg_rom_load("build/no/such/dir/model.rom", &r1, &block, NULL), PHGMG_ERR_IO);
    CHECK(block == NULL);
    if (phgmg_rom_save(&osc, path) == PHGMG_OK) {
      FILE *f;
      CHECK_RC(phgmg_rom_load(path, &r1, &block, NULL), PHGMG_OK);
      CHECK(block != NULL && same_rom(&osc, &r1));
      phgmg__free(NULL, block);
      f = fopen(path, "r+b");
      if (f) { fseek(f, 20, SEEK_SET); fputc(0x7f, f); fclose(f); }
      memset(&r1, 0x42, sizeof r1);
      guard(&r1, sizeof r1);
      EXPECT(phgmg_rom_load(path, &r1, &block, NULL), PHGMG_ERR_FORMAT);
      CHECK(block == NULL);
      remove(path);
    }
    CHECK(g_default_live == live);
  }
}


/* ---- out of memory: every offline entry point ----------------------------- */
typedef struct octx {
  const phgmg_ph_system *sys;
  const double *X;
  int N, ns, variant;
  phgmg_reduce_opts o;
  phgmg_reduced *red;
  phgmg_gl3 *g;
  phgmg_jr_factor *jr;
  double *A, *B, *out, *out2;
  const char *path;
  const void *img;
  size_t img_len;
  double x0[32], xr[8];  /* inputs guarded across the call: they live here */
} octx;

static void guard_in(const octx *c) {
  guard_sys(c->sys);
  if (c->X) guard(c->X, sizeof(double) * (size_t)c->N * (size_t)c->ns);
}
static phgmg_result op_reduce(const phgmg_allocator *a, void *v) {
  octx *c = (octx *)v;
  phgmg_result rc;
  guard_in(c); guard_opts(&c->o);
  c->red = NULL;
  rc = phgmg_reduce(&c->red, c->sys, c->X, c->N, c->ns, &c->o, NULL, a);
  if (rc != PHGMG_OK && c->red) { th_fail_msg(__FILE__, __LINE__, "reduce: *out set on failure"); c->red = NULL; }
  return rc;
}
static void undo_reduce(void *v) { octx *c = (octx *)v; phgmg_reduced_destroy(c->red); c->red = NULL; }

static phgmg_result op_simulate(const phgmg_allocator *a, void *v) {
  octx *c = (octx *)v;
  double H[21], S[21], D[21], Y[21];
  phgmg_energy en;
  phgmg_gl3_opts go;
  int i;
  for (i = 0; i < c->N; ++i) c->x0[i] = 0.05 * sin(1.0 + i);
  en.H = H; en.S = S; en.D = D;
  memset(&go, 0, sizeof go); go.no_step_map = c->variant == 1;
  guard_sys(c->sys); guard(c->x0, sizeof c->x0);
  return phgmg_simulate(c->sys, c->x0, 0.0, 0.1, 20, u_sin, NULL, &go, c->out, Y, &en, NULL, NULL, a);
}
static phgmg_result op_gl3_create(const phgmg_allocator *a, void *v) {
  octx *c = (octx *)v;
  phgmg_gl3_opts go;
  phgmg_result rc;
  memset(&go, 0, sizeof go); go.no_step_map = c->variant == 1;
  guard_sys(c->sys);
  c->g = NULL;
  rc = phgmg_gl3_create(&c->g, c->sys, 0.1, &go, a);
  if (rc != PHGMG_OK && c->g) { th_fail_msg(__FILE__, __LINE__, "gl3_create: *out set on failure"); c->g = NULL; }
  return rc;
}
static void undo_gl3(void *v) { octx *c = (octx *)v; phgmg_gl3_destroy(c->g); c->g = NULL; }
static phgmg_result op_jr(const phgmg_allocator *a, void *v) {
  octx *c = (octx *)v;
  double rc_out = 0;
  phgmg_result rc;
  guard_sys(c->sys);
  c->jr = NULL;
  rc = phgmg_jr_factor_create(&c->jr, c->sys, &rc_out, a);
  if (rc != PHGMG_OK && c->jr) { th_fail_msg(__FILE__, __LINE__, "jr_factor_create: *out set on failure"); c->jr = NULL; }
  return rc;
}
static void undo_jr(void *v) { octx *c = (octx *)v; phgmg_jr_factor_destroy(c->jr); c->jr = NULL; }
static phgmg_result op_validate(const phgmg_allocator *a, void *v) {
  octx *c = (octx *)v;
  double rc_out;
  guard_sys(c->sys);
  return phgmg_ph_validate(c->sys, 0.0, &rc_out, a);
}
/* dense kernels on a 20 x 12 matrix A and right-hand sides B (20 x 2) */
static phgmg_result op_svd(const phgmg_allocator *a, void *v) {
  octx *c = (octx *)v;
  double S[12], U[20 * 12], V[12 * 12];
  int k, rank;
  guard(c->A, sizeof(double) * 240);
  return phgmg_svd(20, 12, c->A, 20, 12, S, U, 20, V, 12, &k, &rank, a);
}
static phgmg_result op_lstsq(const phgmg_allocator *a, void *v) {
  octx *c = (octx *)v;
  double Xs[12 * 2];
  guard(c->A, sizeof(double) * 240); guard(c->B, sizeof(double) * 40);
  return phgmg_lstsq(20, 12, 2, c->A, 20, c->B, 20, c->variant ? 0.1 : 0.0, Xs, 12, a);
}
static phgmg_result op_pod(const phgmg_allocator *a, void *v) {
  octx *c = (octx *)v;
  double V[20 * 5], S[5];
  int k;
  guard(c->A, sizeof(double) * 240);
  return phgmg_pod(20, 12, c->A, 20, 5, 1e-12, V, 20, S, &k, a);
}
static phgmg_result op_deim(const phgmg_allocator *a, void *v) {
  octx *c = (octx *)v;
  double w[20], ratio;
  int pts[20], nd, nneg;
  guard(c->A, sizeof(double) * 240);
  return phgmg_deim(20, 12, c->A, 20, NULL, 1e-8, 0, pts, w, &nd, &nneg, &ratio, a);
}
static phgmg_result op_adjust(const phgmg_allocator *a, void *v) {
  octx *c = (octx *)v;
  double Xa[240];
  guard(c->A, sizeof(double) * 240); guard(c->B, sizeof(double) * 40);
  return phgmg_adjust_snapshots(20, 2, c->B, 12, c->A, 20, Xa, 20, a);
}
static phgmg_result op_podh(const phgmg_allocator *a, void *v) {
  octx *c = (octx *)v;
  double V1[20 * 4], V2[20 * 3];
  guard(c->A, sizeof(double) * 240); guard(c->B, sizeof(double) * 40);
  return phgmg_pod_hierarchical(20, 2, c->B, 12, c->A, 20, 4, 3, V1, V2, a);
}
static phgmg_result op_red_sim(const phgmg_allocator *a, void *v) {
  octx *c = (octx *)v;
  double XR[8 * 11], H[11], S[11], D[11], Y[11];
  phgmg_energy en;
  en.H = H; en.S = S; en.D = D;
  memset(c->xr, 0, sizeof c->xr);
  guard(c->xr, sizeof c->xr);
  return phgmg_reduced_simulate(c->red, c->xr, 0.0, 0.1, 10, u_sin, NULL, 0, 0, XR, Y, &en, NULL, a);
}
static phgmg_result op_red_W(const phgmg_allocator *a, void *v) {
  octx *c = (octx *)v;
  int i;
  (void)a; /* the model's own allocator (given to phgmg_reduce) */
  for (i = 0; i < 8; ++i) c->xr[i] = 0.01 * (i % 3 - 1);
  guard(c->xr, sizeof c->xr);
  return phgmg_reduced_W(c->red, c->xr, c->out, c->N);
}
static phgmg_result op_npy_parse(const phgmg_allocator *a, void *v) {
  octx *c = (octx *)v;
  int rows, cols, nd;
  guard(c->img, c->img_len);
  c->out2 = NULL;
  return phgmg_npy_parse(c->img, c->img_len, &c->out2, &rows, &cols, &nd, a);
}
static phgmg_result op_npy_read(const phgmg_allocator *a, void *v) {
  octx *c = (octx *)v;
  int rows, cols, nd;
  c->out2 = NULL;
  return phgmg_npy_read(c->path, &c->out2, &rows, &cols, &nd, a);
}
static void undo_npy(void *v) { octx *c = (octx *)v; phgmg_npy_free(c->out2, &g_fa_alloc); c->out2 = NULL; }
static phgmg_result op_rom_load(const phgmg_allocator *a, void *v) {
  octx *c = (octx *)v;
  phgmg_rom rom;
  void *block = NULL;
  phgmg_result rc = phgmg_rom_load(c->path, &rom, &block, a);
  if (rc == PHGMG_OK) phgmg__free(a, block);
  else if (block) th_fail_msg(__FILE__, __LINE__, "rom_load: block set on failure");
  return rc;
}

TEST(test_oom_reduce) {
  msd_linear L;
  msd_nonlinear M;
  msd_nl_opts no;
  octx c;
  double *XL, *XM, *x0;
  const int ns = 41;
  int k;
  CHECK(msd_linear_build(&L, 8, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  memset(&no, 0, sizeof no); no.n = 6;
  CHECK(msd_nonlinear_build(&M, &no) == 0);
  XL = (double *)malloc(sizeof(double) * 16 * ns);
  XM = (double *)malloc(sizeof(double) * 12 * ns);
  x0 = (double *)calloc(16, sizeof(double));
  CHECK_RC(phgmg_simulate(&L.sys, x0, 0.0, 0.1, ns - 1, u_sin, NULL, NULL, XL, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
  CHECK_RC(phgmg_simulate(&M.sys, x0, 0.0, 0.1, ns - 1, u_sin, NULL, NULL, XM, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
  for (k = 0; k < 7; ++k) {
    static const phgmg_method meth[7] = {PHGMG_METHOD_GMG_POD, PHGMG_METHOD_GMG_QM, PHGMG_METHOD_SP1,
                                         PHGMG_METHOD_GMG_POD, PHGMG_METHOD_GMG_QM, PHGMG_METHOD_SP2, PHGMG_METHOD_SP2};
    static const char *name[7] = {"reduce GMG-POD + step map", "reduce GMG-QM", "reduce SP1", "reduce GMG-POD + DEIM",
                                  "reduce GMG-QM + DEIM", "reduce SP2 + DEIM", "reduce SP2, all terms"};
    memset(&c, 0, sizeof c);
    c.sys = k < 3 ? &L.sys : &M.sys; c.X = k < 3 ? XL : XM; c.N = c.sys->N; c.ns = ns;
    c.o = ropts(meth[k], 4);
    c.o.dt = 0.1; c.o.hyper.on = k >= 3 && k < 6; c.o.hyper.allow_negative = 1;
    CHECK(oom_sweep(name[k], op_reduce, undo_reduce, &c) > 5);
  }
  /* the reduced model's own evaluations that allocate */
  memset(&c, 0, sizeof c);
  c.sys = &M.sys; c.X = XM; c.N = 12; c.ns = ns;
  c.o = ropts(PHGMG_METHOD_GMG_QM, 4); c.o.hyper.on = 1; c.o.hyper.allow_negative = 1;
  CHECK_RC(phgmg_reduce(&c.red, &M.sys, XM, 12, ns, &c.o, NULL, &g_fa_alloc), PHGMG_OK);
  if (c.red) {
    c.out = (double *)malloc(sizeof(double) * 12 * 4);
    oom_sweep("reduced_simulate", op_red_sim, NULL, &c);
    oom_sweep("reduced_W", op_red_W, NULL, &c);
    g_fa.calls = 0; g_fa.fail_at = 1;
    CHECK(phgmg_err_proj(c.red, XM, 12, ns) != phgmg_err_proj(c.red, XM, 12, ns)); /* NaN */
    g_fa.fail_at = 0;
    CHECK(phgmg_err_proj(c.red, XM, 12, ns) >= 0.0);
    phgmg_reduced_destroy(c.red);
    free(c.out);
  }
  free(XL); free(XM); free(x0);
  msd_linear_free(&L);
  msd_nonlinear_free(&M);
}

TEST(test_oom_simulate_and_factor) {
  msd_linear L, Lb;
  msd_nonlinear M, Mb;
  msd_nl_opts no;
  octx c;
  double Xo[16 * 21];
  int k;
  CHECK(msd_linear_build(&L, 8, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  CHECK(msd_linear_build(&Lb, 8, NULL, NULL, NULL, PHGMG_BANDED) == 0);
  memset(&no, 0, sizeof no); no.n = 6;
  CHECK(msd_nonlinear_build(&M, &no) == 0);
  no.storage = PHGMG_BANDED;
  CHECK(msd_nonlinear_build(&Mb, &no) == 0);
  for (k = 0; k < 5; ++k) {
    static const char *name[5] = {"simulate linear (step map)", "simulate linear (Newton)", "simulate nonlinear dense",
                                  "simulate nonlinear banded", "simulate linear banded"};
    const phgmg_ph_system *s[5] = {&L.sys, &L.sys, &M.sys, &Mb.sys, &Lb.sys};
    memset(&c, 0, sizeof c);
    c.sys = s[k]; c.N = s[k]->N; c.variant = k == 1; c.out = Xo;
    CHECK(oom_sweep(name[k], op_simulate, NULL, &c) > 0);
    c.variant = k == 1;
    CHECK(oom_sweep("gl3_create", op_gl3_create, undo_gl3, &c) > 0);
    CHECK(oom_sweep("jr_factor_create", op_jr, undo_jr, &c) > 0);
  }
  /* validation: R diagonal (no allocation for the PSD test), R full (dense
     eigenvalues), R banded beyond the dense limit (band Cholesky) */
  memset(&c, 0, sizeof c);
  c.sys = &L.sys; c.N = 16;
  CHECK(oom_sweep("validate, diagonal R", op_validate, NULL, &c) > 0);
  L.R[1 + 3 * 16] = L.R[3 + 1 * 16] = 0.5;
  CHECK(oom_sweep("validate, full R", op_validate, NULL, &c) > 0);
  {
    const int Nb = 2002;
    double *J = (double *)calloc((size_t)3 * Nb, sizeof(double)), *R = (double *)calloc((size_t)3 * Nb, sizeof(double));
    double *Q = (double *)calloc((size_t)3 * Nb, sizeof(double)), *B = (double *)calloc((size_t)Nb, sizeof(double));
    phgmg_ph_system sb;
    int j;
    for (j = 0; j < Nb; ++j) {
      Q[1 + j * 3] = 1.0; R[1 + j * 3] = 2.0;
      if (j > 0) R[j * 3] = -1.0;
      if (j + 1 < Nb) R[2 + j * 3] = -1.0;
      if (j % 2 == 1) { J[j * 3] = 1.0; J[2 + (j - 1) * 3] = -1.0; }
    }
    B[0] = 1.0;
    memset(&sb, 0, sizeof sb);
    sb.N = Nb; sb.m = 1; sb.storage = PHGMG_BANDED; sb.kb = 1; sb.J = J; sb.R = R; sb.Q = Q; sb.B = B;
    c.sys = &sb; c.N = Nb;
    CHECK(oom_sweep("validate, banded R (Cholesky)", op_validate, NULL, &c) > 0);
    free(J); free(R); free(Q); free(B);
  }
  msd_linear_free(&L); msd_linear_free(&Lb);
  msd_nonlinear_free(&M); msd_nonlinear_free(&Mb);
}

TEST(test_oom_kernels_and_readers) {
  octx c;
  double A[240], B[40];
  int i;
  memset(&c, 0, sizeof c);
  for (i = 0; i < 240; ++i) A[i] = th_rand();
  for (i = 0; i < 40; ++i) B[i] = th_rand();
  c.A = A; c.B = B;
  CHECK(oom_sweep("svd", op_svd, NULL, &c) > 0);
  CHECK(oom_sweep("lstsq", op_lstsq, NULL, &c) > 0);
  c.variant = 1;
  CHECK(oom_sweep("lstsq ridge", op_lstsq, NULL, &c) > 0);
  CHECK(oom_sweep("pod", op_pod, NULL, &c) > 0);
  CHECK(oom_sweep("deim", op_deim, NULL, &c) > 0);
  CHECK(oom_sweep("adjust_snapshots", op_adjust, NULL, &c) > 0);
  CHECK(oom_sweep("pod_hierarchical", op_podh, NULL, &c) > 0);
  /* readers of outside data */
  {
    size_t len = 0;
    unsigned char *img;
    CHECK_RC(phgmg_npy_serialize(A, 20, 12, 20, 2, 0, NULL, 0, &len), PHGMG_OK);
    img = (unsigned char *)malloc(len);
    CHECK_RC(phgmg_npy_serialize(A, 20, 12, 20, 2, 0, img, len, &len), PHGMG_OK);
    c.img = img; c.img_len = len;
    CHECK(oom_sweep("npy_parse", op_npy_parse, undo_npy, &c) > 0);
    c.path = tmp_path("npy");
    if (phgmg_npy_write(c.path, A, 20, 12, 20, 2, 0) == PHGMG_OK) {
      CHECK(oom_sweep("npy_read", op_npy_read, undo_npy, &c) > 0);
      remove(c.path);
    }
    free(img);
  }
  {
    static const phgmg_real K[4] = {0, -1, 1, 0}, Qh[4] = {1, 0, 0, 1}, Bh[2] = {0, 1};
    phgmg_rom rom;
    memset(&rom, 0, sizeof rom);
    rom.kind = PHGMG_ROM_LINEAR; rom.r = 2; rom.m = 1; rom.K = K; rom.Qh = Qh; rom.Bh = Bh;
    c.path = tmp_path("rom");
    if (phgmg_rom_save(&rom, c.path) == PHGMG_OK) {
      CHECK(oom_sweep("rom_load", op_rom_load, NULL, &c) > 0);
      remove(c.path);
    }
  }
}

/* Everything allocated through the default allocator was freed. */
TEST(test_default_allocator_balanced) { CHECK(g_default_live == 0); }

/* The sparse LU's fallback: with PHGMG_SPARSE_GROWTH = 0.5 (above) every
   sparse factorization is rejected, the stepper switches to the band LU with
   partial pivoting and gives the band run's states bit for bit (a 2-D
   lattice, 7 x 7 masses, (q, p) per mass, in a shuffled order; without the
   fallback the sparse LU's states differ in the last bits). The same with a
   mass matrix E = blockdiag(I, Mc) (Mc(n, n) = 1, 0.1 between neighbouring
   momenta): the fallback's band LU of sigma E + M gives the band run's
   states to round-off (E Z there comes from E's CSC copy, summed in another
   order than the band run's diagonals: not bit for bit). */
static void rb_fb_u(double t, double *u, void *user) { (void)user; u[0] = 0.1 * sin(t); }
TEST(test_sparse_lu_fallback) {
  enum { NX = 7, NN = NX * NX, N = 2 * NN };
  static double Jd[N * N], Rd[N * N], Qd[N * N], Ed[N * N], B[N], Y[2][41], X[2][N * 41];
  static int cp[4][N + 1], ri[4][N * N];
  static double vv[4][N * N];
  int sc[N], i, j, a, k, run, withe;
  double d = 0.0, xm = 0.0;
  phgmg_csc M[4];
  for (i = 0; i < N; ++i) sc[i] = (5 * i + 3) % N; /* a fixed shuffle (5 and N = 98 coprime: a permutation) */
  memset(Jd, 0, sizeof Jd); memset(Rd, 0, sizeof Rd); memset(Qd, 0, sizeof Qd); memset(B, 0, sizeof B);
  memset(Ed, 0, sizeof Ed);
  for (k = 0; k < NN; ++k) {
    int q = sc[2 * k], p = sc[2 * k + 1], nb[2], nn = 0;
    if (k % NX + 1 < NX) nb[nn++] = k + 1;
    if (k + NX < NN) nb[nn++] = k + NX;
    Jd[q + p * N] = 1.0; Jd[p + q * N] = -1.0; Rd[p + p * N] = 0.05; Qd[p + p * N] = 1.0;
    Qd[q + q * N] += 0.1;
    Ed[q + q * N] = Ed[p + p * N] = 1.0;
    for (i = 0; i < nn; ++i) {
      int q2 = sc[2 * nb[i]], p2 = sc[2 * nb[i] + 1];
      Ed[p + p2 * N] = Ed[p2 + p * N] = 0.1;
      Qd[q + q2 * N] -= 1.0; Qd[q2 + q * N] -= 1.0; Qd[q + q * N] += 1.0; Qd[q2 + q2 * N] += 1.0;
    }
  }
  B[sc[1]] = 1.0;
  for (a = 0; a < 4; ++a) {
    const double *D = a == 0 ? Jd : a == 1 ? Rd : a == 2 ? Qd : Ed;
    int nz = 0;
    for (j = 0; j < N; ++j) {
      cp[a][j] = nz;
      for (i = 0; i < N; ++i) if (D[i + j * N] != 0.0) { ri[a][nz] = i; vv[a][nz] = D[i + j * N]; ++nz; }
    }
    cp[a][N] = nz;
    M[a].n_rows = M[a].n_cols = N; M[a].colptr = cp[a]; M[a].rowidx = ri[a]; M[a].values = vv[a];
  }
  for (withe = 0; withe < 2; ++withe) {
  for (run = 0; run < 2; ++run) {
    phgmg_ph_sparse *sp = NULL;
    phgmg_ph_sparse_info inf;
    phgmg_gl3_stats st;
    double x0[N];
    memset(x0, 0, sizeof x0);
    CHECK_RC(phgmg_ph_sparse_create_e(&sp, N, 1, &M[0], &M[1], &M[2], withe ? &M[3] : NULL, B, NULL, &inf, NULL),
             PHGMG_OK);
    CHECK_RC(phgmg_ph_sparse_set_solver(sp, run ? PHGMG_SOLVER_BAND : PHGMG_SOLVER_SPARSE_LU, &inf), PHGMG_OK);
    CHECK_RC(phgmg_simulate(phgmg_ph_sparse_system(sp), x0, 0.0, 0.1, 40, rb_fb_u, NULL, NULL, X[run], Y[run], NULL,
                            &st, NULL, NULL), PHGMG_OK);
    CHECK(st.factorizations == 1);
    phgmg_ph_sparse_destroy(sp);
  }
  for (i = 0, k = 0; i < N * 41; ++i) {
    k += X[0][i] != X[1][i];
    d = fmax(d, fabs(X[0][i] - X[1][i])); xm = fmax(xm, fabs(X[1][i]));
  }
  if (!withe) CHECK(k == 0);
  CHECK_LE(d, 1e-13 * xm);
  for (i = 0; i <= 40; ++i) CHECK_LE(fabs(Y[0][i] - Y[1][i]), 1e-14 * fabs(Y[1][40]));
  CHECK(Y[1][40] != 0.0);
  }
}

SUITE(robust) {
  RUN(test_sparse_lu_fallback);
  RUN(test_dims_reduce);
  RUN(test_dims_validate);
  RUN(test_dims_simulate);
  RUN(test_dims_rom_stepper_init);
  RUN(test_naninf_system);
  RUN(test_naninf_input_and_state);
  RUN(test_structure_violations);
  RUN(test_gmg_degenerate);
  RUN(test_snapshot_rank);
  RUN(test_deim_negative_weight);
  RUN(test_newton_failure);
  RUN(test_rom_images);
  RUN(test_oom_reduce);
  RUN(test_oom_simulate_and_factor);
  RUN(test_oom_kernels_and_readers);
  RUN(test_default_allocator_balanced);
}
