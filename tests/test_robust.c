/* Bad input and faults (issue 8). Every case asserts the exact result code
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
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include "../examples/msd_models.h"

/* ---- guards: copies of the caller's data, compared after the call ------- */
#define RB_NGUARD 32
static struct { const void *p; size_t n; unsigned char *copy; } rb_g[RB_NGUARD];
static int rb_ng = 0;

static void guard(const void *p, size_t n) {
  if (!p || n == 0 || rb_ng >= RB_NGUARD) return;
  rb_g[rb_ng].p = p;
  rb_g[rb_ng].n = n;
  rb_g[rb_ng].copy = (unsigned char *)malloc(n);
  if (!rb_g[rb_ng].copy) return;
  memcpy(rb_g[rb_ng].copy, p, n);
  ++rb_ng;
}
/* 1 if every guarded buffer still holds its bytes; drops the guards. */
static int intact(void) {
  int ok = 1, i;
  for (i = 0; i < rb_ng; ++i) {
    if (memcmp(rb_g[i].p, rb_g[i].copy, rb_g[i].n) != 0) ok = 0;
    free(rb_g[i].copy);
  }
  rb_ng = 0;
  return ok;
}
/* The system struct and every array it points to (sizes permitting). */
static void guard_sys(const phgmg_ph_system *s) {
  size_t len;
  guard(s, sizeof *s);
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
static long oom_sweep(const char *name, oom_op op, oom_undo undo, void *ctx) {
  falloc f;
  phgmg_allocator a;
  long total, k;
  phgmg_result rc;
  char msg[200];
  memset(&f, 0, sizeof f);
  a.alloc = fa_alloc; a.free = fa_free; a.user = &f;
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
  o.method = meth; o.r = r; o.rn = 2;
  return o;
}

/* phgmg_reduce with guards on every input; *out must stay NULL on failure. */
static phgmg_result reduce_g(const phgmg_ph_system *sys, const double *X, int ldx, int ns,
                             const phgmg_reduce_opts *o, phgmg_reduce_info *info) {
  phgmg_reduced *red = NULL;
  phgmg_result rc;
  guard_sys(sys);
  if (X && sys->N > 0 && ns > 0 && ldx >= sys->N) guard(X, sizeof(double) * (size_t)ldx * (size_t)ns);
  guard(o, sizeof *o);
  rc = phgmg_reduce(&red, sys, X, ldx, ns, o, info, NULL);
  if (rc != PHGMG_OK) CHECK(red == NULL);
  phgmg_reduced_destroy(red);
  return rc;
}

/* ========================================================================== */
TEST(test_dims_reduce) {
  msd_linear M;
  phgmg_reduce_opts o;
  phgmg_reduced *red = (phgmg_reduced *)&o;
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
  o.r = 4; o.rn = N - 3;   /* r + rn > N */
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
  o.rn = 65;               /* beyond the online buffers */
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
    o = ropts(PHGMG_METHOD_GMG_POD, 5); o.pod_basis = V; o.pod_cols = 3; /* needs r - m = 4 */
    EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
    o = ropts(PHGMG_METHOD_SP1, 4); o.pod_basis = V; o.pod_cols = 3;
    EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_SIZE);
    free(V);
  }
  /* bad options and unsupported model kinds */
  o = ropts((phgmg_method)0, 4);
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_INVALID_ARG);
  o = ropts((phgmg_method)5, 4);
  EXPECT(reduce_g(&M.sys, X, N, ns, &o, NULL), PHGMG_ERR_INVALID_ARG);
  o = ropts(PHGMG_METHOD_GMG_POD, 4);
  s = M.sys; s.nl = PHGMG_NL_GENERAL;
  EXPECT(reduce_g(&s, X, N, ns, &o, NULL), PHGMG_ERR_UNSUPPORTED);
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
  double x0[12], X[12 * 6], Y[6], xs[12];
  int done = -1, k, i;
  CHECK(msd_linear_build(&L, 6, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  memset(&no, 0, sizeof no); no.n = 6;
  CHECK(msd_nonlinear_build(&M, &no) == 0);
  for (i = 0; i < 12; ++i) x0[i] = 0.1 * th_rand();
  for (k = 0; k < 3; ++k) {
    const phgmg_ph_system *s = k == 0 ? &L.sys : &M.sys;
    phgmg_gl3_opts go;
    memset(&go, 0, sizeof go);
    go.no_step_map = k == 2; /* k = 0: linear step map; 1, 2: Newton */
    if (k == 2) s = &L.sys;
    /* a NaN input at the third step: two steps recorded, the rest untouched */
    memset(X, 0x5a, sizeof X); memcpy(xs, X, sizeof xs);
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
  (void)xs;
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

SUITE(robust) {
  RUN(test_dims_reduce);
  RUN(test_dims_validate);
  RUN(test_dims_simulate);
  RUN(test_dims_rom_stepper_init);
  RUN(test_naninf_system);
  RUN(test_naninf_input_and_state);
}
