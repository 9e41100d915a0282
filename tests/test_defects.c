/* Defects found by testing as a new user and as an attacker:
   one regression test per defect fixed in the library. Each fails on the code
   before the fix. The CLI's defects are checked in tests/test_cli.sh. */
#define _POSIX_C_SOURCE 200809L /* mkdtemp, symlink, pipe, lstat */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "fixture_msd.h"
static void d_u_sin(double t, double *u, void *user) { (void)user; u[0] = 0.1 * sin(t); }

/* Defects 4 and 5: Q's own codes; Q positive definite is checked (diagonal Q
   exactly, else by Cholesky, dense and banded). */
TEST(test_defect_q_checks) {
  dmodel t;
  const int n = 4, N = 8;
  double *band, q00;
  int i, j, kb = 2;
  dmodel_msd(&t, n);
  CHECK_RC(phgmg_ph_validate(&t.sys, 0.0, NULL, NULL), PHGMG_OK);
  CHECK(strstr(phgmg_result_string(PHGMG_ERR_Q_NOT_SYMMETRIC), "Q") != NULL);
  CHECK(strstr(phgmg_result_string(PHGMG_ERR_Q_NOT_PD), "Q") != NULL);
  /* Q not symmetric: Q's own code, not R's */
  t.Q[0 + 2 * N] = -0.5;
  CHECK_RC(phgmg_ph_validate(&t.sys, 0.0, NULL, NULL), PHGMG_ERR_Q_NOT_SYMMETRIC);
  t.Q[0 + 2 * N] = -1.0;
  /* non-diagonal Q: the chain Q has leading minors 1, 1, ... (positive
     definite); coupling -1.5 instead of -1 in the first spring gives the 2x2
     block [1 -1.5; -1.5 2] of determinant -0.25 (indefinite) */
  t.Q[0 + 2 * N] = t.Q[2 + 0 * N] = -1.5;
  CHECK_RC(phgmg_ph_validate(&t.sys, 0.0, NULL, NULL), PHGMG_ERR_Q_NOT_PD);
  t.Q[0 + 2 * N] = t.Q[2 + 0 * N] = -1.0;
  CHECK_RC(phgmg_ph_validate(&t.sys, 0.0, NULL, NULL), PHGMG_OK);
  /* the chain with a free end: Q(0,0) = 1 -> 1 - 1 = 0 makes it singular (PSD only) */
  q00 = t.Q[0]; t.Q[0] = 0.5;
  CHECK_RC(phgmg_ph_validate(&t.sys, 0.0, NULL, NULL), PHGMG_ERR_Q_NOT_PD);
  t.Q[0] = q00;
  /* Q = 0 and a diagonal Q with one zero / one negative entry */
  {
    double *Qs = t.Q, *Z = (double *)calloc((size_t)N * N, sizeof(double));
    t.sys.Q = Z;
    CHECK_RC(phgmg_ph_validate(&t.sys, 0.0, NULL, NULL), PHGMG_ERR_Q_NOT_PD);
    for (i = 0; i < N; ++i) Z[i + i * N] = 1.0 + i;
    CHECK_RC(phgmg_ph_validate(&t.sys, 0.0, NULL, NULL), PHGMG_OK);
    Z[5 + 5 * N] = 0.0;
    CHECK_RC(phgmg_ph_validate(&t.sys, 0.0, NULL, NULL), PHGMG_ERR_Q_NOT_PD);
    Z[5 + 5 * N] = -1e-300;
    CHECK_RC(phgmg_ph_validate(&t.sys, 0.0, NULL, NULL), PHGMG_ERR_Q_NOT_PD);
    free(Z);
    t.sys.Q = Qs;
  }
  /* banded storage (kb = 2) of the same matrices */
  {
    double *Jb, *Rb, *Qb;
    const size_t ld = (size_t)(2 * kb + 1);
    band = (double *)calloc(3 * ld * N, sizeof(double));
    Jb = band; Rb = band + ld * N; Qb = band + 2 * ld * N;
    for (j = 0; j < N; ++j)
      for (i = j - kb; i <= j + kb; ++i)
        if (i >= 0 && i < N) {
          Jb[PHGMG__PHB(kb, i, j)] = t.J[i + j * N];
          Rb[PHGMG__PHB(kb, i, j)] = t.R[i + j * N];
          Qb[PHGMG__PHB(kb, i, j)] = t.Q[i + j * N];
        }
    t.sys.storage = PHGMG_BANDED; t.sys.kb = kb;
    t.sys.J = Jb; t.sys.R = Rb; t.sys.Q = Qb;
    CHECK_RC(phgmg_ph_validate(&t.sys, 0.0, NULL, NULL), PHGMG_OK);
    Qb[PHGMG__PHB(kb, 0, 2)] = Qb[PHGMG__PHB(kb, 2, 0)] = -1.5;
    CHECK_RC(phgmg_ph_validate(&t.sys, 0.0, NULL, NULL), PHGMG_ERR_Q_NOT_PD);
    Qb[PHGMG__PHB(kb, 0, 2)] = -1.0;
    CHECK_RC(phgmg_ph_validate(&t.sys, 0.0, NULL, NULL), PHGMG_ERR_Q_NOT_SYMMETRIC);
    free(band);
  }
  dmodel_free(&t);
}

/* A model with a step map for dt = 0.1, simulated with dt = 0.05
   (needs the Newton workspace, not the step-map one); the stepper refuses
   tol = +Inf / NaN. */
TEST(test_defect_other_dt) {
  dmodel t;
  const int n = 10, N = 20, ns = 201;
  double *X = (double *)malloc(sizeof(double) * N * ns), *x0 = (double *)calloc(N, sizeof(double));
  double Ya[41], Yb[21], xr0[8] = {0}, d = 0.0, ymax = 0.0;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  int k;
  dmodel_msd(&t, n);
  CHECK_RC(phgmg_simulate(&t.sys, x0, 0.0, 0.1, ns - 1, d_u_sin, NULL, NULL, X, NULL, NULL, NULL, NULL, NULL),
           PHGMG_OK);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = 8; o.dt = 0.1;
  CHECK_RC(phgmg_reduce(&red, &t.sys, X, N, ns, &o, NULL, NULL), PHGMG_OK);
  if (red) {
    const phgmg_rom *rom = phgmg_reduced_rom(red);
    phgmg_rom_stepper st;
    size_t msz = phgmg_rom_stepper_memsize_dt(rom, (phgmg_real)0.05);
    void *mem = malloc(msz);
    CHECK(rom->Phi != NULL);
    CHECK(msz > phgmg_rom_stepper_memsize(rom));
    CHECK_RC(phgmg_reduced_simulate(red, xr0, 0.0, 0.05, 40, d_u_sin, NULL, 1e-12, 10, NULL, Ya, NULL, NULL, NULL),
             PHGMG_OK);
    CHECK_RC(phgmg_reduced_simulate(red, xr0, 0.0, 0.1, 20, d_u_sin, NULL, 1e-12, 10, NULL, Yb, NULL, NULL, NULL),
             PHGMG_OK);
    /* the same trajectory at t = 0.1 k (GL3, order 6: the two steps agree to ~1e-8) */
    for (k = 0; k <= 20; ++k) { d = fmax(d, fabs(Ya[2 * k] - Yb[k])); ymax = fmax(ymax, fabs(Yb[k])); }
    CHECK(ymax > 1e-3);
    CHECK_LE(d, 1e-6 * ymax);
    CHECK_RC(phgmg_rom_stepper_init(&st, rom, (phgmg_real)0.05, (phgmg_real)1e-10, 10, mem, msz), PHGMG_OK);
    CHECK_RC(phgmg_rom_stepper_init(&st, rom, (phgmg_real)0.05, (phgmg_real)INFINITY, 10, mem, msz),
             PHGMG_ERR_INVALID_ARG);
    CHECK_RC(phgmg_rom_stepper_init(&st, rom, (phgmg_real)0.05, (phgmg_real)NAN, 10, mem, msz),
             PHGMG_ERR_INVALID_ARG);
    CHECK_RC(phgmg_rom_stepper_init(&st, rom, (phgmg_real)0.05, (phgmg_real)0, 10, mem, msz), PHGMG_OK);
    free(mem);
  }
  phgmg_reduced_destroy(red);
  free(X); free(x0);
  dmodel_free(&t);
}

/* POD (and the SVD under it) do not depend on the magnitude of the
   data: X c for c = 1e-300 ... 1e200 gives the basis of X and c times its
   singular values (before the fix: wrong bases at 1e-170 .. 1e-220,
   PHGMG_ERR_NOT_CONVERGED at 1e-150 and >= 1e160). */
TEST(test_defect_pod_scaling) {
  enum { N = 40, NS = 25, K = 6 };
  static const double cs[] = {1e-300, 1e-220, 1e-200, 1e-170, 1e-150, 1e160, 1e200, 1e300};
  double X[N * NS], Xc[N * NS], V[N * K], Vc[N * K], S[K], Sc[K];
  int i, j, c, k = 0, kc = 0;
  for (i = 0; i < N * NS; ++i) X[i] = th_rand();
  CHECK_RC(phgmg_pod(N, NS, X, N, K, 0.0, V, N, S, &k, NULL), PHGMG_OK);
  CHECK(k == K);
  for (c = 0; c < (int)(sizeof cs / sizeof cs[0]); ++c) {
    double worst_s = 0.0, worst_v = 0.0;
    for (i = 0; i < N * NS; ++i) Xc[i] = X[i] * cs[c];
    kc = 0;
    CHECK_RC(phgmg_pod(N, NS, Xc, N, K, 0.0, Vc, N, Sc, &kc, NULL), PHGMG_OK);
    CHECK(kc == K);
    if (kc != K) continue;
    for (j = 0; j < K; ++j) {
      double dot = 0.0;
      for (i = 0; i < N; ++i) dot += V[i + j * N] * Vc[i + j * N];
      worst_v = fmax(worst_v, 1.0 - fabs(dot));
      worst_s = fmax(worst_s, fabs(Sc[j] / cs[c] - S[j]) / S[j]);
    }
    CHECK_LE(worst_v, 1e-10);
    CHECK_LE(worst_s, 1e-12);
  }
}

/* ---- .npy ---- */
/* Counting allocator that records the largest single request. */
typedef struct { long live; size_t biggest; } dcount;
static void *d_alloc(size_t n, void *u) {
  dcount *c = (dcount *)u;
  c->live++;
  if (n > c->biggest) c->biggest = n;
  return malloc(n);
}
static void d_free(void *p, void *u) { if (p) { ((dcount *)u)->live--; free(p); } }

/* A version 1.0 image of header text hdr followed by nd data bytes. */
static size_t d_image(unsigned char *buf, const char *hdr, const unsigned char *data, size_t nd) {
  const size_t hl = strlen(hdr);
  memcpy(buf, "\x93NUMPY\x01\x00", 8);
  buf[8] = (unsigned char)(hl & 255); buf[9] = (unsigned char)(hl >> 8);
  memcpy(buf + 10, hdr, hl);
  if (nd) memcpy(buf + 10 + hl, data, nd);
  return 10 + hl + nd;
}
/* v (two's complement for negative) as es bytes, little- or big-endian */
static void d_put(unsigned char *d, unsigned long long v, int es, int big) {
  int b;
  for (b = 0; b < es; ++b) d[big ? es - 1 - b : b] = (unsigned char)((v >> (8 * b)) & 255u);
}

/* Parse buf, then read the same bytes from a file and from a pipe: the three
   must agree (result code and values). Returns the parse result. */
static phgmg_result d_parse3(const unsigned char *buf, size_t len, double *vals, int *rows, int *cols) {
  double *A = NULL, *B = NULL;
  int r = 0, c = 0, r2 = 0, c2 = 0, fds[2], way;
  char path[64];
  phgmg_result rc = phgmg_npy_parse(buf, len, &A, &r, &c, NULL, NULL), rc2;
  if (rc == PHGMG_OK) { memcpy(vals, A, sizeof(double) * (size_t)r * (size_t)c); *rows = r; *cols = c; }
  for (way = 0; way < 2; ++way) {
    if (way == 0) {
      FILE *f;
      strcpy(path, "/tmp/phgmg_dft_XXXXXX");
      CHECK(mkstemp(path) >= 0);
      f = fopen(path, "wb");
      CHECK(f && fwrite(buf, 1, len, f) == len);
      if (f) fclose(f);
    } else { /* a pipe (len < 4096 fits its buffer) */
      CHECK(pipe(fds) == 0);
      CHECK(write(fds[1], buf, len) == (ssize_t)len);
      close(fds[1]);
      snprintf(path, sizeof path, "/dev/fd/%d", fds[0]);
    }
    B = NULL;
    rc2 = phgmg_npy_read(path, &B, &r2, &c2, NULL, NULL);
    CHECK_RC(rc2, rc);
    if (rc == PHGMG_OK && rc2 == PHGMG_OK) {
      CHECK(r2 == r && c2 == c);
      if (r2 == r && c2 == c) CHECK(memcmp(A, B, sizeof(double) * (size_t)r * (size_t)c) == 0);
    }
    phgmg_npy_free(B, NULL);
    if (way == 0) remove(path); else close(fds[0]);
  }
  phgmg_npy_free(A, NULL);
  return rc;
}

/* Integer and bool dtypes read exactly, both byte orders, through
   parse, a file and a pipe; int64 beyond 2^53: PHGMG_ERR_INEXACT; complex:
   PHGMG_ERR_DTYPE. */
TEST(test_defect_npy_int_dtypes) {
  static const char kinds[] = "iiiiuuuu";
  static const int sizes[] = {1, 2, 4, 8, 1, 2, 4, 8};
  unsigned char buf[512], data[64];
  double v[8];
  char hdr[128];
  int t, big, i, r = 0, c = 0;
  for (t = 0; t < 8; ++t)
    for (big = 0; big < 2; ++big) {
      const int es = sizes[t], sgn = kinds[t] == 'i';
      /* (2, 3) C order: 0, 1, max, min, 7, 100 (max/min of the type, within 2^53) */
      const long long hi = es == 8 ? (1LL << 53) : sgn ? (long long)((1ULL << (8 * es - 1)) - 1)
                                                       : (long long)((1ULL << (8 * es)) - 1);
      const long long lo = !sgn ? 0 : es == 8 ? -(1LL << 53) : -(long long)(1ULL << (8 * es - 1));
      const long long x[6] = {0, 1, hi, lo, 7, 100};
      for (i = 0; i < 6; ++i) d_put(data + i * es, (unsigned long long)x[i], es, big);
      snprintf(hdr, sizeof hdr, "{'descr': '%c%c%d', 'fortran_order': False, 'shape': (2, 3), }",
               es == 1 && big ? '|' : big ? '>' : '<', kinds[t], es);
      CHECK_RC(d_parse3(buf, d_image(buf, hdr, data, (size_t)(6 * es)), v, &r, &c), PHGMG_OK);
      CHECK(r == 2 && c == 3);
      /* column-major: v[i + 2 j] = x[3 i + j] */
      for (i = 0; i < 6; ++i) CHECK(v[(i / 3) + 2 * (i % 3)] == (double)x[i]);
      if (es == 8) { /* one beyond 2^53 in magnitude */
        d_put(data + 2 * es, sgn ? (unsigned long long)(-(1LL << 53) - 1) : (1ULL << 53) + 1, es, big);
        CHECK_RC(d_parse3(buf, d_image(buf, hdr, data, (size_t)(6 * es)), v, &r, &c), PHGMG_ERR_INEXACT);
        d_put(data + 2 * es, sgn ? 0x8000000000000000ULL : ~0ULL, es, big);
        CHECK_RC(d_parse3(buf, d_image(buf, hdr, data, (size_t)(6 * es)), v, &r, &c), PHGMG_ERR_INEXACT);
      }
    }
  /* bool, shape (4,) */
  data[0] = 0; data[1] = 1; data[2] = 1; data[3] = 0;
  CHECK_RC(d_parse3(buf, d_image(buf, "{'descr': '|b1', 'fortran_order': False, 'shape': (4,), }", data, 4),
                    v, &r, &c), PHGMG_OK);
  CHECK(r == 4 && c == 1 && v[0] == 0.0 && v[1] == 1.0 && v[2] == 1.0 && v[3] == 0.0);
  /* complex and float16: named as an unsupported dtype */
  memset(data, 0, sizeof data);
  CHECK_RC(d_parse3(buf, d_image(buf, "{'descr': '<c16', 'fortran_order': False, 'shape': (2,), }", data, 32),
                    v, &r, &c), PHGMG_ERR_DTYPE);
  CHECK_RC(d_parse3(buf, d_image(buf, "{'descr': '<f2', 'fortran_order': False, 'shape': (2,), }", data, 4),
                    v, &r, &c), PHGMG_ERR_DTYPE);
}

/* 128 bytes through a pipe claiming shape (200000, 200000):
   PHGMG_ERR_FORMAT without a 320 GB allocation (before: the buffer was sized
   from the header, "out of memory"). */
TEST(test_defect_npy_pipe_growth) {
  unsigned char buf[256];
  size_t len;
  int fds[2];
  char path[32];
  double *A = NULL;
  int r = -1, c = -1;
  dcount cnt = {0, 0};
  phgmg_allocator al;
  al.alloc = d_alloc; al.free = d_free; al.user = &cnt;
  memset(buf, 0, sizeof buf);
  len = d_image(buf, "{'descr': '<f8', 'fortran_order': False, 'shape': (200000, 200000), }   \n", NULL, 0);
  len = 128 > len ? 128 : len; /* some data bytes */
  CHECK(pipe(fds) == 0);
  CHECK(write(fds[1], buf, len) == (ssize_t)len);
  close(fds[1]);
  snprintf(path, sizeof path, "/dev/fd/%d", fds[0]);
  CHECK_RC(phgmg_npy_read(path, &A, &r, &c, NULL, &al), PHGMG_ERR_FORMAT);
  close(fds[0]);
  CHECK(A == NULL && r == -1 && c == -1 && cnt.live == 0);
  CHECK_LE((double)cnt.biggest, 65536.0 * 2);
}

/* A failed write through a symbolic link (to /dev/full, where every
   write fails) leaves the link alone; before, remove(path) deleted it. */
TEST(test_defect_npy_write_keeps_link) {
  char dir[64], link_path[96];
  double A[4] = {1, 2, 3, 4};
  struct stat st;
  FILE *probe = fopen("/dev/full", "wb");
  if (!probe) return; /* no /dev/full: nothing to check */
  fclose(probe);
  strcpy(dir, "/tmp/phgmg_dft_XXXXXX");
  CHECK(mkdtemp(dir) != NULL);
  snprintf(link_path, sizeof link_path, "%s/link.npy", dir);
  CHECK(symlink("/dev/full", link_path) == 0);
  CHECK_RC(phgmg_npy_write(link_path, A, 2, 2, 2, 2, 0u), PHGMG_ERR_IO);
  CHECK(lstat(link_path, &st) == 0 && S_ISLNK(st.st_mode));
  remove(link_path);
  rmdir(dir);
}

/* Defects 6, 8, 9 (phgmg_reduce): a polynomial degree the reduced model cannot
   hold is refused up front; *out is NULL after every failure, also for NULL
   sys/X/opts; NaN deim_tol and NaN/Inf/negative opts.dt are refused. */
TEST(test_defect_reduce_options) {
  dmodel t;
  const int n = 10, N = 20, ns = 41;
  double *X = (double *)malloc(sizeof(double) * N * ns), x0[20], poly[34];
  int idx[10], i;
  phgmg_reduce_opts o;
  phgmg_reduced *red = (phgmg_reduced *)&t;   /* a non-NULL sentinel */
  phgmg_ph_system s;
  dmodel_msd(&t, n);
  memset(x0, 0, sizeof x0);
  CHECK_RC(phgmg_simulate(&t.sys, x0, 0.0, 0.1, ns - 1, d_u_sin, NULL, NULL, X, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = 4;
  /* 8: NULL arguments leave *out NULL */
  CHECK_RC(phgmg_reduce(&red, NULL, X, N, ns, &o, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK(red == NULL);
  red = (phgmg_reduced *)&t;
  CHECK_RC(phgmg_reduce(&red, &t.sys, NULL, N, ns, &o, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK(red == NULL);
  red = (phgmg_reduced *)&t;
  CHECK_RC(phgmg_reduce(&red, &t.sys, X, N, ns, NULL, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK(red == NULL);
  /* 9: NaN deim_tol, NaN / Inf / negative dt */
  o.hyper.deim_tol = (double)NAN;
  CHECK_RC(phgmg_reduce(&red, &t.sys, X, N, ns, &o, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  o.hyper.deim_tol = 0.0; o.dt = (double)NAN;
  CHECK_RC(phgmg_reduce(&red, &t.sys, X, N, ns, &o, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  o.dt = (double)INFINITY;
  CHECK_RC(phgmg_reduce(&red, &t.sys, X, N, ns, &o, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  o.dt = -0.1;
  CHECK_RC(phgmg_reduce(&red, &t.sys, X, N, ns, &o, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  o.dt = 0.0;
  CHECK(red == NULL);
  /* 6: degree 33 is refused by phgmg_reduce (phgmg_rom_check's limit is 32) */
  memset(poly, 0, sizeof poly);
  poly[33] = 1e-30; poly[4] = 0.25;
  for (i = 0; i < n; ++i) idx[i] = 2 * i;
  s = t.sys; s.nl = PHGMG_NL_SEPARABLE; s.nsep = n; s.sep_idx = idx; s.poly = poly; s.poly_deg = 33;
  CHECK(phgmg_reduce(&red, &s, X, N, ns, &o, NULL, NULL) != PHGMG_OK);
  CHECK(red == NULL);
  s.poly_deg = 32; poly[32] = 1e-30; poly[33] = 0.0;   /* the largest degree a model holds */
  CHECK_RC(phgmg_reduce(&red, &s, X, N, ns, &o, NULL, NULL), PHGMG_OK);
  if (red) CHECK_RC(phgmg_rom_check(phgmg_reduced_rom(red)), PHGMG_OK);
  phgmg_reduced_destroy(red);
  free(X);
  dmodel_free(&t);
}

SUITE(defects) {
  RUN(test_defect_q_checks);
  RUN(test_defect_other_dt);
  RUN(test_defect_pod_scaling);
  RUN(test_defect_npy_int_dtypes);
  RUN(test_defect_npy_pipe_growth);
  RUN(test_defect_npy_write_keeps_link);
  RUN(test_defect_reduce_options);
}
