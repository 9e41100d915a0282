/* NumPy .npy reader/writer: round trips in memory and through files, images
   built byte by byte from the format specification, and every kind of
   malformed input (each must give PHGMG_ERR_FORMAT, leave the outputs alone
   and leak nothing). Exchange with real NumPy: tests/test_npy_numpy.py. */
#define _POSIX_C_SOURCE 200809L /* mkstemp, close */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>
#include <unistd.h>

/* ---- helpers ---- */

/* Counting allocator; fail_at > 0 makes the fail_at-th allocation fail. */
typedef struct { long live, count, fail_at; } npyt_counter;
static void *npyt_alloc(size_t n, void *u) {
  npyt_counter *c = (npyt_counter *)u;
  if (c->fail_at > 0 && ++c->count == c->fail_at) return NULL;
  if (c->fail_at <= 0) ++c->count;
  c->live++;
  return malloc(n);
}
static void npyt_free(void *p, void *u) {
  npyt_counter *c = (npyt_counter *)u;
  if (p) { c->live--; free(p); }
}
static phgmg_allocator npyt_allocator(npyt_counter *c) {
  phgmg_allocator a;
  c->live = 0; c->count = 0; c->fail_at = 0;
  a.alloc = npyt_alloc; a.free = npyt_free; a.user = c;
  return a;
}

/* An image: preamble of version major.0 with the given header text (no
   padding added) followed by nd data bytes. Returns its length. */
static size_t npyt_image(unsigned char *buf, int major, const char *hdr, const unsigned char *data,
                         size_t nd) {
  size_t hl = strlen(hdr), off;
  memcpy(buf, "\x93NUMPY", 6);
  buf[6] = (unsigned char)major; buf[7] = 0;
  if (major == 1) {
    buf[8] = (unsigned char)(hl & 255); buf[9] = (unsigned char)(hl >> 8); off = 10;
  } else {
    buf[8] = (unsigned char)(hl & 255); buf[9] = (unsigned char)((hl >> 8) & 255);
    buf[10] = (unsigned char)((hl >> 16) & 255); buf[11] = (unsigned char)(hl >> 24); off = 12;
  }
  memcpy(buf + off, hdr, hl);
  if (nd) memcpy(buf + off + hl, data, nd);
  return off + hl + nd;
}

/* Six values with exact binary patterns (IEEE 754, big-endian hex). */
static const double npyt_vals[6] = {1.0, -2.0, 0.5, 3.0, 0.25, 1.5};
static const char *npyt_f8[6] = {"3FF0000000000000", "C000000000000000", "3FE0000000000000",
                                 "4008000000000000", "3FD0000000000000", "3FF8000000000000"};
static const char *npyt_f4[6] = {"3F800000", "C0000000", "3F000000", "40400000", "3E800000",
                                 "3FC00000"};
static int npyt_hex(char c) { return c <= '9' ? c - '0' : c - 'A' + 10; }
/* The n values order[0..n) as es-byte elements, big- or little-endian. */
static size_t npyt_data(unsigned char *d, const int *order, int n, int es, int big) {
  int k, b;
  for (k = 0; k < n; ++k) {
    const char *h = es == 8 ? npyt_f8[order[k]] : npyt_f4[order[k]];
    for (b = 0; b < es; ++b) {
      unsigned char v = (unsigned char)(npyt_hex(h[2 * b]) * 16 + npyt_hex(h[2 * b + 1]));
      d[big ? b : es - 1 - b] = v;
    }
    d += es;
  }
  return (size_t)(n * es);
}

/* Parse expecting failure `expect`: outputs untouched, allocations balanced.
   `id` (a line number or case index) names the case in a failure message. */
static void npyt_expect_fail(const void *buf, size_t len, phgmg_result expect, int id) {
  npyt_counter c;
  phgmg_allocator a = npyt_allocator(&c);
  double sentinel = 42.0, *out = &sentinel;
  int r = -7, k = -8, nd = -9;
  phgmg_result rc = phgmg_npy_parse(buf, len, &out, &r, &k, &nd, &a);
  if (rc != expect || out != &sentinel || r != -7 || k != -8 || nd != -9 || c.live != 0) {
    char m[160];
    snprintf(m, sizeof m, "case %d: got %d (%s), outputs %s, %ld blocks live", id, (int)rc,
             phgmg_result_string(rc), out == &sentinel ? "untouched" : "CHANGED", c.live);
    th_fail_msg(__FILE__, __LINE__, m);
    if (rc == PHGMG_OK) phgmg_npy_free(out, &a);
  }
}
#define EXPECT_FMT(buf, len) npyt_expect_fail(buf, len, PHGMG_ERR_FORMAT, __LINE__)

static void npyt_tmpname(char *name) {
  int fd;
  strcpy(name, "/tmp/phgmg_npy_XXXXXX");
  fd = mkstemp(name);
  CHECK(fd >= 0);
  if (fd >= 0) close(fd);
}

/* ---- tests ---- */

/* Byte-exact images from the spec: every dtype and order, versions 1-3. */
TEST(test_npy_parse_spec_images) {
  /* logical 2 x 3 matrix M(i,j) = vals[i + 2j]; C order stores row by row */
  static const int forder[6] = {0, 1, 2, 3, 4, 5}, corder[6] = {0, 2, 4, 1, 3, 5};
  unsigned char buf[512], data[64];
  int es, big, c, major;
  for (major = 1; major <= 3; ++major)
    for (es = 4; es <= 8; es += 4)
      for (big = 0; big <= 1; ++big)
        for (c = 0; c <= 1; ++c) {
          char hdr[160];
          size_t nd, len;
          double *A = NULL;
          int r = 0, k = 0, dim = 0, i;
          snprintf(hdr, sizeof hdr,
                   "{'descr': '%cf%d', 'fortran_order': %s, 'shape': (2, 3), }          \n",
                   big ? '>' : '<', es, c ? "False" : "True");
          nd = npyt_data(data, c ? corder : forder, 6, es, big);
          len = npyt_image(buf, major, hdr, data, nd);
          CHECK_RC(phgmg_npy_parse(buf, len, &A, &r, &k, &dim, NULL), PHGMG_OK);
          CHECK(r == 2 && k == 3 && dim == 2);
          if (A)
            for (i = 0; i < 6; ++i) CHECK(A[i] == npyt_vals[i]);
          phgmg_npy_free(A, NULL);
        }
}

/* 0-d, 1-d and empty shapes; header spelling variations NumPy accepts. */
TEST(test_npy_parse_shapes_and_spellings) {
  static const int ord[6] = {0, 1, 2, 3, 4, 5};
  static const struct { const char *hdr; int n, rows, cols, ndim; } cases[] = {
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (), }\n", 1, 1, 1, 0},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (4,), }\n", 4, 4, 1, 1},
    {"{'descr': '<f8', 'fortran_order': True, 'shape': (1, 1), }\n", 1, 1, 1, 2},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (1, 5), }\n", 5, 1, 5, 2},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (0,), }\n", 0, 0, 1, 1},
    {"{'descr': '<f8', 'fortran_order': False, 'shape': (3, 0), }\n", 0, 3, 0, 2},
    {"{'descr': '<f8', 'fortran_order': True, 'shape': (0, 2), }\n", 0, 0, 2, 2},
    /* key order, quotes, whitespace, no trailing comma, Python 2 long suffix */
    {"{\"shape\": (2,3), \"fortran_order\": True, \"descr\": \"<f8\"}", 6, 2, 3, 2},
    {"  {  'fortran_order' :True ,'shape':( 6 , ),'descr':'<f8' ,}\t\r\n", 6, 6, 1, 1},
    {"{'descr': '<f8', 'fortran_order': True, 'shape': (2L, 3L), }\n", 6, 2, 3, 2},
    {"{'descr': '<f8', 'fortran_order': True, 'shape': (2, 3,), }\n", 6, 2, 3, 2},
  };
  unsigned char buf[512], data[64];
  size_t t;
  for (t = 0; t < sizeof cases / sizeof cases[0]; ++t) {
    size_t nd = npyt_data(data, ord, cases[t].n, 8, 0);
    size_t len = npyt_image(buf, 1, cases[t].hdr, data, nd);
    double *A = NULL;
    int r = -1, k = -1, dim = -1, i;
    CHECK_RC(phgmg_npy_parse(buf, len, &A, &r, &k, &dim, NULL), PHGMG_OK);
    CHECK(A != NULL);
    CHECK(r == cases[t].rows && k == cases[t].cols && dim == cases[t].ndim);
    if (A)
      for (i = 0; i < cases[t].n; ++i) CHECK(A[i] == npyt_vals[i]); /* F order = file order */
    phgmg_npy_free(A, NULL);
    /* ndim is optional; bytes after the data are ignored (as NumPy does) */
    buf[len] = 0xAB;
    CHECK_RC(phgmg_npy_parse(buf, len + 1, &A, &r, &k, NULL, NULL), PHGMG_OK);
    phgmg_npy_free(A, NULL);
  }
}

/* Every malformed case: PHGMG_ERR_FORMAT, outputs untouched, no leak. */
TEST(test_npy_parse_malformed) {
  static const int ord[6] = {0, 1, 2, 3, 4, 5};
  static const char *bad[] = {
    "", "   \n", "{", "}", "{}",
    "{'descr': '<f8', 'fortran_order': False}",                       /* no shape */
    "{'descr': '<f8', 'shape': (2, 3)}",                              /* no order */
    "{'fortran_order': False, 'shape': (2, 3)}",                      /* no descr */
    "{'descr': <f8, 'fortran_order': False, 'shape': (2, 3), }",     /* unquoted dtype */
    "{'descr': '<f8', 'fortran_order': 0, 'shape': (2, 3), }",       /* order values */
    "{'descr': '<f8', 'fortran_order': true, 'shape': (2, 3), }",
    "{'descr': '<f8', 'fortran_order': Truest, 'shape': (2, 3), }",
    "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3, 1), }", /* shapes */
    "{'descr': '<f8', 'fortran_order': False, 'shape': (6), }",
    "{'descr': '<f8', 'fortran_order': False, 'shape': 6, }",
    "{'descr': '<f8', 'fortran_order': False, 'shape': (,), }",
    "{'descr': '<f8', 'fortran_order': False, 'shape': (2,, 3), }",
    "{'descr': '<f8', 'fortran_order': False, 'shape': (2 3), }",
    "{'descr': '<f8', 'fortran_order': False, 'shape': (-2, 3), }",
    "{'descr': '<f8', 'fortran_order': False, 'shape': (2.0, 3), }",
    "{'descr': '<f8', 'fortran_order': False, 'shape': (nan, 3), }",
    "{'descr': '<f8', 'fortran_order': False, 'shape': (inf,), }",
    "{'descr': '<f8', 'fortran_order': False, 'shape': (1e3,), }",
    "{'descr': '<f8', 'fortran_order': False, 'shape': (0x6,), }",
    "{'descr': '<f8', 'fortran_order': False, 'shape': (2147483648,), }",   /* > INT_MAX */
    "{'descr': '<f8', 'fortran_order': False, 'shape': (99999999999999999999999, 1), }",
    "{'descr': '<f8', 'fortran_order': False, 'shape': (2147483647, 2147483647), }",
    "{'descr': '<f8', 'fortran_order': False, 'shape': (100000, 100000), }", /* truncated */
    "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3)",      /* unterminated */
    "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), } x", /* trailing junk */
    "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }}",
    "{'descr': '<f8' 'fortran_order': False, 'shape': (2, 3), }",    /* missing comma */
    "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), 'x': 1}", /* extra key */
    "{'descr': '<f8', 'descr': '<f8', 'fortran_order': False, 'shape': (2, 3)}",
    "{'descr: '<f8', 'fortran_order': False, 'shape': (2, 3)}",      /* bad quoting */
    "{'descr': \"<f8', 'fortran_order': False, 'shape': (2, 3)}",
    "{'de\\x73cr': '<f8', 'fortran_order': False, 'shape': (2, 3)}",
    "{descr: '<f8', 'fortran_order': False, 'shape': (2, 3)}",
    "{'descr' '<f8', 'fortran_order': False, 'shape': (2, 3)}",
    "['descr', '<f8']",
  };
  unsigned char buf[1024], data[64];
  size_t t, nd = npyt_data(data, ord, 6, 8, 0), len;
  for (t = 0; t < sizeof bad / sizeof bad[0]; ++t) {
    len = npyt_image(buf, 1, bad[t], data, nd);
    npyt_expect_fail(buf, len, PHGMG_ERR_FORMAT, (int)t); /* index into bad[] */
  }
  {
    /* unsupported dtypes: PHGMG_ERR_DTYPE */
    static const char *dt[] = {"'<f2'", "'<c16'", "'<c8'", "'=f8'", "'f8'", "'<f16'", "'|f8'",
                               "'|i2'", "'<i3'", "'<b2'", "'<U5'", "'|S3'", "'|O'", "'<M8'",
                               "'<m8'", "'|V8'", "''", "[('a', '<f8')]"};
    char hd[160];
    for (t = 0; t < sizeof dt / sizeof dt[0]; ++t) {
      snprintf(hd, sizeof hd, "{'descr': %s, 'fortran_order': False, 'shape': (2, 3), }", dt[t]);
      len = npyt_image(buf, 1, hd, data, nd);
      npyt_expect_fail(buf, len, PHGMG_ERR_DTYPE, 1000 + (int)t);
    }
  }
  {
    /* NUL inside the header */
    static const char h[] = "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }\0  ";
    size_t hl = sizeof h - 1;
    len = npyt_image(buf, 1, "", NULL, 0);
    buf[8] = (unsigned char)hl; buf[9] = 0;
    memcpy(buf + 10, h, hl);
    memcpy(buf + 10 + hl, data, nd);
    EXPECT_FMT(buf, 10 + hl + nd);
  }
  /* preamble */
  len = npyt_image(buf, 1, "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }\n",
                   data, nd);
  {
    double *A = NULL;
    int r, k;
    CHECK_RC(phgmg_npy_parse(buf, len, &A, &r, &k, NULL, NULL), PHGMG_OK); /* control */
    phgmg_npy_free(A, NULL);
  }
  {
    unsigned char b2[1024];
    memcpy(b2, buf, len); b2[0] = 0x92; EXPECT_FMT(b2, len);            /* magic */
    memcpy(b2, buf, len); b2[3] = 'm'; EXPECT_FMT(b2, len);
    memcpy(b2, buf, len); b2[6] = 4; EXPECT_FMT(b2, len);               /* version 4.0 */
    memcpy(b2, buf, len); b2[6] = 0; EXPECT_FMT(b2, len);               /* version 0.0 */
    memcpy(b2, buf, len); b2[7] = 1; EXPECT_FMT(b2, len);               /* version 1.1 */
    memcpy(b2, buf, len); b2[8] = 0xFF; b2[9] = 0xFF; EXPECT_FMT(b2, len); /* hlen past end */
    memcpy(b2, buf, len); b2[9] = 1; EXPECT_FMT(b2, len);
    memcpy(b2, buf, len); b2[8] = 0; b2[9] = 0; EXPECT_FMT(b2, len);    /* empty header */
    memcpy(b2, buf, len); b2[8] = 10; EXPECT_FMT(b2, len);              /* header cut */
  }
  /* version 2.0: 4-byte length past the end, and beyond PHGMG_NPY_MAX_HEADER */
  len = npyt_image(buf, 2, "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }\n",
                   data, nd);
  {
    unsigned char b2[1024];
    memcpy(b2, buf, len); b2[10] = 1; EXPECT_FMT(b2, len);
    memcpy(b2, buf, len); b2[11] = 0xFF; EXPECT_FMT(b2, len);
    memcpy(b2, buf, len); b2[11] = 0xFF; b2[10] = 0xFF; b2[9] = 0xFF; b2[8] = 0xF4;
    EXPECT_FMT(b2, len);
  }
  /* every proper prefix of valid images (v1 and v2, f4 and f8) is malformed */
  {
    int major, es;
    for (major = 1; major <= 2; ++major)
      for (es = 4; es <= 8; es += 4) {
        char hdr[128];
        size_t n, cut;
        snprintf(hdr, sizeof hdr, "{'descr': '>f%d', 'fortran_order': True, 'shape': (3, 2), }\n",
                 es);
        n = npyt_data(data, ord, 6, es, 1);
        len = npyt_image(buf, major, hdr, data, n);
        for (cut = 0; cut < len; ++cut) npyt_expect_fail(buf, cut, PHGMG_ERR_FORMAT, (int)cut);
      }
  }
  /* NULL arguments */
  {
    double *A = NULL;
    int r, k;
    CHECK_RC(phgmg_npy_parse(NULL, 10, &A, &r, &k, NULL, NULL), PHGMG_ERR_INVALID_ARG);
    CHECK_RC(phgmg_npy_parse(buf, len, NULL, &r, &k, NULL, NULL), PHGMG_ERR_INVALID_ARG);
    CHECK_RC(phgmg_npy_parse(buf, len, &A, NULL, &k, NULL, NULL), PHGMG_ERR_INVALID_ARG);
    CHECK_RC(phgmg_npy_parse(buf, len, &A, &r, NULL, NULL, NULL), PHGMG_ERR_INVALID_ARG);
    CHECK(A == NULL);
  }
}

/* Any single-byte change of a valid image parses or is rejected cleanly, and
   a successful parse reports dimensions consistent with the data present. */
TEST(test_npy_parse_mutations) {
  static const int ord[6] = {0, 1, 2, 3, 4, 5};
  static const unsigned char vals[] = {0x00, 0x01, 0x09, 0x0A, 0x20, '(', ')', ',', '0', '1',
                                       '9', '\'', '"', '<', '>', 'L', 0x7F, 0x80, 0xFF};
  unsigned char buf[512], b2[512], data[64];
  size_t nd = npyt_data(data, ord, 6, 8, 0);
  size_t len = npyt_image(buf, 1,
                          "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }   \n",
                          data, nd);
  size_t pos, v;
  long okcount = 0;
  for (pos = 0; pos < len - nd; ++pos)
    for (v = 0; v < sizeof vals; ++v) {
      npyt_counter c;
      phgmg_allocator a = npyt_allocator(&c);
      double *A = NULL;
      int r = 0, k = 0, dim = 0;
      phgmg_result rc;
      memcpy(b2, buf, len);
      b2[pos] = vals[v];
      rc = phgmg_npy_parse(b2, len, &A, &r, &k, &dim, &a);
      CHECK(rc == PHGMG_OK || rc == PHGMG_ERR_FORMAT || rc == PHGMG_ERR_DTYPE);
      if (rc == PHGMG_OK) {
        ++okcount;
        CHECK(r >= 0 && k >= 0 && dim >= 0 && dim <= 2);
        CHECK((size_t)r * (size_t)k * 4 <= len); /* data must have been present */
        phgmg_npy_free(A, &a);
      }
      CHECK(c.live == 0);
    }
  CHECK(okcount > 0); /* e.g. changing a padding space to a tab is still valid */
}

/* Round trips through the serializer: every shape kind, order and ld;
   float32 rounds like a C cast. */
TEST(test_npy_roundtrip_memory) {
  static const int shapes[][3] = {{7, 3, 2}, {1, 1, 2}, {1, 1, 0}, {1, 1, 1}, {5, 1, 1},
                                  {1, 6, 1}, {1, 6, 2}, {4, 0, 2}, {0, 3, 2}, {0, 1, 1},
                                  {33, 17, 2}, {200, 1, 2}};
  double A[40 * 20];
  size_t s;
  int i, fl;
  for (i = 0; i < 40 * 20; ++i) A[i] = th_rand() * pow(10.0, 6.0 * th_rand());
  for (s = 0; s < sizeof shapes / sizeof shapes[0]; ++s)
    for (fl = 0; fl < 4; ++fl) {
      int m = shapes[s][0], n = shapes[s][1], nd = shapes[s][2], ld = m + 3;
      unsigned flags = (unsigned)fl;
      size_t need = 0, need2 = 0;
      unsigned char *buf;
      double *B = NULL;
      int r = -1, k = -1, dim = -1, ii, jj;
      CHECK_RC(phgmg_npy_serialize(A, m, n, ld, nd, flags, NULL, 0, &need), PHGMG_OK);
      buf = (unsigned char *)malloc(need);
      CHECK_RC(phgmg_npy_serialize(A, m, n, ld, nd, flags, buf, need, &need2), PHGMG_OK);
      CHECK(need2 == need);
      /* header: version 1.0, data aligned to 64 bytes, newline-terminated */
      CHECK(buf[6] == 1 && buf[7] == 0);
      {
        size_t hl = (size_t)buf[8] + 256u * buf[9];
        CHECK((10 + hl) % 64 == 0);
        CHECK(buf[10 + hl - 1] == '\n');
        CHECK(need == 10 + hl + (size_t)m * (size_t)n * ((flags & PHGMG_NPY_F32) ? 4u : 8u));
      }
      CHECK_RC(phgmg_npy_parse(buf, need, &B, &r, &k, &dim, NULL), PHGMG_OK);
      CHECK(dim == nd);
      if (nd == 1) CHECK(r == m * n && k == 1);
      else CHECK(r == m && k == n);
      if (B)
        for (jj = 0; jj < n; ++jj)
          for (ii = 0; ii < m; ++ii) {
            double a = A[ii + jj * ld];
            double want = (flags & PHGMG_NPY_F32) ? (double)(float)a : a;
            double got = nd == 1 ? B[ii + jj * m] : B[ii + jj * r];
            CHECK(got == want);
          }
      phgmg_npy_free(B, NULL);
      free(buf);
    }
}

/* The exact bytes the writer produces for a small case, from the spec. */
TEST(test_npy_serialize_bytes) {
  static const char want_f[] = "{'descr': '<f8', 'fortran_order': True, 'shape': (2, 3), }";
  static const char want_c[] = "{'descr': '<f4', 'fortran_order': False, 'shape': (6,), }";
  static const int ford[6] = {0, 1, 2, 3, 4, 5}, cord[6] = {0, 2, 4, 1, 3, 5};
  double A[6];
  unsigned char buf[256], data[64];
  size_t len = 0, i;
  for (i = 0; i < 6; ++i) A[i] = npyt_vals[i];
  CHECK_RC(phgmg_npy_serialize(A, 2, 3, 2, 2, 0, buf, sizeof buf, &len), PHGMG_OK);
  /* 10 + 58 + newline > 64: the header is padded to 128 bytes, length 118 */
  CHECK(len == 128 + 48);
  CHECK(memcmp(buf, "\x93NUMPY\x01\x00\x76\x00", 10) == 0);
  CHECK(memcmp(buf + 10, want_f, sizeof want_f - 1) == 0);
  for (i = 10 + sizeof want_f - 1; i < 127; ++i) CHECK(buf[i] == ' ');
  CHECK(buf[127] == '\n');
  npyt_data(data, ford, 6, 8, 0);
  CHECK(memcmp(buf + 128, data, 48) == 0);
  /* C order: data row by row; here a 1-d float32 vector from a 1 x 6 row */
  CHECK_RC(phgmg_npy_serialize(A, 1, 6, 1, 1, PHGMG_NPY_F32 | PHGMG_NPY_C_ORDER, buf,
                               sizeof buf, &len), PHGMG_OK);
  CHECK(len == 128 + 24);
  CHECK(memcmp(buf + 10, want_c, sizeof want_c - 1) == 0);
  npyt_data(data, ford, 6, 4, 0);
  CHECK(memcmp(buf + 128, data, 24) == 0);
  /* 2 x 3 in C order */
  CHECK_RC(phgmg_npy_serialize(A, 2, 3, 2, 2, PHGMG_NPY_C_ORDER, buf, sizeof buf, &len),
           PHGMG_OK);
  npyt_data(data, cord, 6, 8, 0);
  CHECK(memcmp(buf + 128, data, 48) == 0);
}

/* Special values keep their bits in f8; f4 keeps NaN/Inf/-0 and overflows
   to Inf like a C cast. */
TEST(test_npy_special_values) {
  double A[6], *B = NULL;
  unsigned char buf[256];
  size_t len;
  int r, k, fl;
  A[0] = NAN; A[1] = INFINITY; A[2] = -INFINITY; A[3] = -0.0; A[4] = 4.9e-324; A[5] = 1e300;
  for (fl = 0; fl < 4; ++fl) {
    CHECK_RC(phgmg_npy_serialize(A, 3, 2, 3, 2, (unsigned)fl, buf, sizeof buf, &len), PHGMG_OK);
    CHECK_RC(phgmg_npy_parse(buf, len, &B, &r, &k, NULL, NULL), PHGMG_OK);
    if (!B) continue;
    CHECK(isnan(B[0]) && B[1] == INFINITY && B[2] == -INFINITY);
    CHECK(B[3] == 0.0 && signbit(B[3]));
    if (fl & 2) { CHECK(B[4] == 0.0); CHECK(B[5] == INFINITY); }
    else { CHECK(B[4] == A[4]); CHECK(B[5] == 1e300); }
    phgmg_npy_free(B, NULL);
    B = NULL;
  }
}

TEST(test_npy_serialize_errors) {
  double A[6] = {1, 2, 3, 4, 5, 6};
  unsigned char buf[256];
  size_t len = 7, need = 0;
  memset(buf, 0xCD, sizeof buf);
  CHECK_RC(phgmg_npy_serialize(A, 2, 3, 2, 2, 0, buf, 100, &len), PHGMG_ERR_WORKSPACE);
  CHECK(len == 128 + 48);
  CHECK(buf[0] == 0xCD && buf[99] == 0xCD); /* nothing written */
  CHECK_RC(phgmg_npy_serialize(A, 2, 3, 1, 2, 0, NULL, 0, &need), PHGMG_ERR_SIZE);   /* ld */
  CHECK_RC(phgmg_npy_serialize(A, 0, 3, 0, 2, 0, NULL, 0, &need), PHGMG_ERR_SIZE);   /* ld 0 */
  CHECK_RC(phgmg_npy_serialize(A, -1, 3, 2, 2, 0, NULL, 0, &need), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_npy_serialize(A, 2, 3, 2, 3, 0, NULL, 0, &need), PHGMG_ERR_SIZE);   /* ndim */
  CHECK_RC(phgmg_npy_serialize(A, 2, 3, 2, 1, 0, NULL, 0, &need), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_npy_serialize(A, 2, 1, 2, 0, 0, NULL, 0, &need), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_npy_serialize(A, 2, 3, 2, 2, 4, NULL, 0, &need), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_npy_serialize(NULL, 2, 3, 2, 2, 0, NULL, 0, &need), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_npy_serialize(A, 2, 3, 2, 2, 0, NULL, 0, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK(need == 0);
  CHECK_RC(phgmg_npy_serialize(NULL, 0, 0, 1, 2, 0, NULL, 0, &need), PHGMG_OK); /* empty */
  CHECK(need == 128);
}

/* Allocation failure: PHGMG_ERR_NOMEM, outputs untouched, nothing leaked. */
TEST(test_npy_nomem) {
  double A[6] = {1, 2, 3, 4, 5, 6}, sentinel = 0, *out = &sentinel;
  unsigned char buf[256];
  char name[64];
  size_t len;
  npyt_counter c;
  phgmg_allocator a = npyt_allocator(&c);
  int r = -1, k = -1, fail;
  CHECK_RC(phgmg_npy_serialize(A, 2, 3, 2, 2, 0, buf, sizeof buf, &len), PHGMG_OK);
  c.fail_at = 1;
  CHECK_RC(phgmg_npy_parse(buf, len, &out, &r, &k, NULL, &a), PHGMG_ERR_NOMEM);
  CHECK(out == &sentinel && r == -1 && k == -1 && c.live == 0);
  npyt_tmpname(name);
  CHECK_RC(phgmg_npy_write(name, A, 2, 3, 2, 2, 0), PHGMG_OK);
  for (fail = 1; fail <= 2; ++fail) { /* the header text, then the matrix */
    a = npyt_allocator(&c);
    c.fail_at = fail;
    CHECK_RC(phgmg_npy_read(name, &out, &r, &k, NULL, &a), PHGMG_ERR_NOMEM);
    CHECK(out == &sentinel && r == -1 && k == -1 && c.live == 0);
  }
  a = npyt_allocator(&c);
  CHECK_RC(phgmg_npy_read(name, &out, &r, &k, NULL, &a), PHGMG_OK);
  CHECK(r == 2 && k == 3 && c.count == 2 && c.live == 1);
  if (out != &sentinel) phgmg_npy_free(out, &a);
  CHECK(c.live == 0);
  remove(name);
}

/* Files: the writer streams exactly the serializer's bytes; read returns them;
   file errors, truncation and junk are reported. */
TEST(test_npy_files) {
  double A[12 * 9], *B = NULL, sentinel = 0, *out = &sentinel;
  unsigned char mem[2048], disk[2048];
  char name[64];
  size_t len, got;
  int i, j, r, k, dim, fl;
  FILE *f;
  for (i = 0; i < 12 * 9; ++i) A[i] = th_rand();
  npyt_tmpname(name);
  for (fl = 0; fl < 4; ++fl) {
    CHECK_RC(phgmg_npy_write(name, A, 11, 9, 12, 2, (unsigned)fl), PHGMG_OK);
    CHECK_RC(phgmg_npy_serialize(A, 11, 9, 12, 2, (unsigned)fl, mem, sizeof mem, &len), PHGMG_OK);
    f = fopen(name, "rb");
    CHECK(f != NULL);
    if (!f) continue;
    got = fread(disk, 1, sizeof disk, f);
    fclose(f);
    CHECK(got == len && memcmp(mem, disk, len) == 0);
    CHECK_RC(phgmg_npy_read(name, &B, &r, &k, &dim, NULL), PHGMG_OK);
    CHECK(r == 11 && k == 9 && dim == 2);
    if (B)
      for (j = 0; j < 9; ++j)
        for (i = 0; i < 11; ++i)
          CHECK(B[i + j * 11] == ((fl & 2) ? (double)(float)A[i + j * 12] : A[i + j * 12]));
    phgmg_npy_free(B, NULL);
    B = NULL;
  }
  /* a big file, more than one 4 KiB chunk, C order, version 2.0 header */
  {
    static double big[300 * 7];
    unsigned char *img;
    size_t n = 0;
    for (i = 0; i < 300 * 7; ++i) big[i] = th_rand();
    CHECK_RC(phgmg_npy_serialize(big, 300, 7, 300, 2, PHGMG_NPY_C_ORDER, NULL, 0, &n), PHGMG_OK);
    img = (unsigned char *)malloc(n + 2);
    CHECK_RC(phgmg_npy_serialize(big, 300, 7, 300, 2, PHGMG_NPY_C_ORDER, img + 2, n, &n),
             PHGMG_OK);
    /* turn it into version 2.0: 4-byte length, same header text */
    memmove(img, img + 2, 8);
    img[6] = 2;
    img[8] = img[10]; img[9] = img[11]; img[10] = 0; img[11] = 0;
    f = fopen(name, "wb");
    CHECK(f != NULL);
    if (f) { CHECK(fwrite(img, 1, n + 2, f) == n + 2); fclose(f); }
    CHECK_RC(phgmg_npy_read(name, &B, &r, &k, &dim, NULL), PHGMG_OK);
    CHECK(r == 300 && k == 7 && dim == 2);
    if (B) for (i = 0; i < 300 * 7; ++i) CHECK(B[i] == big[i]);
    phgmg_npy_free(B, NULL);
    B = NULL;
    /* truncated at several places: header, data start, one byte short */
    {
      size_t cuts[5];
      int t;
      cuts[0] = 5; cuts[1] = 11; cuts[2] = 40;    /* in the preamble/header */
      cuts[3] = n + 2 - sizeof big;                 /* exactly at the data start */
      cuts[4] = n + 1;                              /* one byte short */
      for (t = 0; t < 5; ++t) {
        npyt_counter c;
        phgmg_allocator a = npyt_allocator(&c);
        f = fopen(name, "wb");
        if (f) { CHECK(fwrite(img, 1, cuts[t], f) == cuts[t]); fclose(f); }
        CHECK_RC(phgmg_npy_read(name, &out, &r, &k, &dim, &a), PHGMG_ERR_FORMAT);
        CHECK(out == &sentinel && c.live == 0);
      }
    }
    free(img);
  }
  /* an empty file, and a junk file */
  f = fopen(name, "wb");
  if (f) fclose(f);
  CHECK_RC(phgmg_npy_read(name, &out, &r, &k, &dim, NULL), PHGMG_ERR_FORMAT);
  f = fopen(name, "wb");
  if (f) { fputs("not a numpy file at all, just text\n", f); fclose(f); }
  CHECK_RC(phgmg_npy_read(name, &out, &r, &k, &dim, NULL), PHGMG_ERR_FORMAT);
  CHECK(out == &sentinel);
  remove(name);
  /* I/O errors */
  CHECK_RC(phgmg_npy_read(name, &out, &r, &k, &dim, NULL), PHGMG_ERR_IO); /* removed */
  CHECK_RC(phgmg_npy_read("/tmp", &out, &r, &k, &dim, NULL), PHGMG_ERR_IO); /* directory */
  CHECK_RC(phgmg_npy_write("/nonexistent-dir/x.npy", A, 2, 2, 2, 2, 0), PHGMG_ERR_IO);
  CHECK_RC(phgmg_npy_write(NULL, A, 2, 2, 2, 2, 0), PHGMG_ERR_INVALID_ARG);
  CHECK_RC(phgmg_npy_write(name, A, 2, 2, 1, 2, 0), PHGMG_ERR_SIZE);
  CHECK_RC(phgmg_npy_read(NULL, &out, &r, &k, &dim, NULL), PHGMG_ERR_INVALID_ARG);
  CHECK(out == &sentinel);
  f = fopen(name, "rb");
  CHECK(f == NULL); /* the failed write did not create the file */
  if (f) { fclose(f); remove(name); }
}

SUITE(npy) {
  RUN(test_npy_parse_spec_images);
  RUN(test_npy_parse_shapes_and_spellings);
  RUN(test_npy_parse_malformed);
  RUN(test_npy_parse_mutations);
  RUN(test_npy_roundtrip_memory);
  RUN(test_npy_serialize_bytes);
  RUN(test_npy_special_values);
  RUN(test_npy_serialize_errors);
  RUN(test_npy_nomem);
  RUN(test_npy_files);
}
