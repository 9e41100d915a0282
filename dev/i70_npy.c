
/* >>npy (implementation) ================================================== */
#ifndef PHGMG_NO_OFFLINE
#include <limits.h>
#ifndef PHGMG_NO_STDIO
#include <stdio.h>
#endif

/* What the header says, checked: a rows x cols result with count elements of
   es bytes each (4 or 8), big-endian or not, stored in C order or not. */
typedef struct phgmg__npy_hdr {
  int rows, cols, ndim;
  int es, big, corder;
  size_t count;
} phgmg__npy_hdr;

/* 1 on a little-endian host (integers and doubles share the byte order on
   every platform the library targets). */
PHGMG__PRIV int phgmg__npy_host_little(void) {
  const unsigned int one = 1u;
  unsigned char c;
  memcpy(&c, &one, 1);
  return c == 1;
}

/* Preamble: magic, version, header length. p holds the first n bytes of the
   file (n >= 10 suffices for version 1.0, 12 for 2.0/3.0). On success
   *hoff is the offset of the header text and *hlen its length. */
PHGMG__PRIV phgmg_result phgmg__npy_preamble(const unsigned char *p, size_t n, size_t *hoff,
                                             size_t *hlen) {
  static const unsigned char magic[6] = {0x93, 'N', 'U', 'M', 'P', 'Y'};
  size_t hl;
  if (n < 10 || memcmp(p, magic, 6) != 0 || p[7] != 0) return PHGMG_ERR_FORMAT;
  if (p[6] == 1) {
    hl = (size_t)p[8] | ((size_t)p[9] << 8);
    *hoff = 10;
  } else if (p[6] == 2 || p[6] == 3) {
    unsigned long v;
    if (n < 12) return PHGMG_ERR_FORMAT;
    v = (unsigned long)p[8] | ((unsigned long)p[9] << 8) | ((unsigned long)p[10] << 16) |
        ((unsigned long)p[11] << 24);
    if (v > (unsigned long)PHGMG_NPY_MAX_HEADER) return PHGMG_ERR_FORMAT;
    hl = (size_t)v;
    *hoff = 12;
  } else {
    return PHGMG_ERR_FORMAT;
  }
  if (hl > (size_t)PHGMG_NPY_MAX_HEADER) return PHGMG_ERR_FORMAT;
  *hlen = hl;
  return PHGMG_OK;
}

PHGMG__PRIV size_t phgmg__npy_ws(const char *s, size_t n, size_t i) {
  while (i < n && (s[i] == ' ' || s[i] == '\t' || s[i] == '\n' || s[i] == '\r')) ++i;
  return i;
}

/* A quoted Python string without escapes at s[*i]: its body is s[*b .. *b+*l). */
PHGMG__PRIV int phgmg__npy_str(const char *s, size_t n, size_t *i, size_t *b, size_t *l) {
  size_t k = *i;
  char q;
  if (k >= n || (s[k] != '\'' && s[k] != '"')) return 0;
  q = s[k++];
  *b = k;
  while (k < n && s[k] != q) {
    if (s[k] == '\\' || s[k] == '\n' || s[k] == '\r') return 0;
    ++k;
  }
  if (k >= n) return 0;
  *l = k - *b;
  *i = k + 1;
  return 1;
}

/* Does s[b..b+l) equal the C string w? */
PHGMG__PRIV int phgmg__npy_is(const char *s, size_t b, size_t l, const char *w) {
  return strlen(w) == l && memcmp(s + b, w, l) == 0;
}

/* The identifier w at s[*i], not followed by another identifier character. */
PHGMG__PRIV int phgmg__npy_word(const char *s, size_t n, size_t *i, const char *w) {
  size_t l = strlen(w), e = *i + l;
  char c;
  if (n - *i < l || memcmp(s + *i, w, l) != 0) return 0;
  if (e < n) {
    c = s[e];
    if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_')
      return 0;
  }
  *i = e;
  return 1;
}

/* A non-negative decimal integer <= INT_MAX (Python 2's "L" suffix allowed). */
PHGMG__PRIV int phgmg__npy_int(const char *s, size_t n, size_t *i, int *v) {
  size_t k = *i;
  long acc = 0;
  if (k >= n || s[k] < '0' || s[k] > '9') return 0;
  while (k < n && s[k] >= '0' && s[k] <= '9') {
    int d = s[k] - '0';
    if (acc > ((long)INT_MAX - d) / 10) return 0;
    acc = acc * 10 + d;
    ++k;
  }
  if (k < n && s[k] == 'L') ++k;
  *v = (int)acc;
  *i = k;
  return 1;
}

/* A shape tuple: (), (n,), (r, c) with optional trailing comma (required
   for one element, as in Python). More than two dimensions: 0. */
PHGMG__PRIV int phgmg__npy_shape(const char *s, size_t n, size_t *i, int *dims, int *nd) {
  size_t k = *i;
  int cnt = 0, comma = 0;
  if (k >= n || s[k] != '(') return 0;
  k = phgmg__npy_ws(s, n, k + 1);
  while (k < n && s[k] != ')') {
    if (cnt == 2) return 0;
    if (!phgmg__npy_int(s, n, &k, &dims[cnt])) return 0;
    ++cnt;
    k = phgmg__npy_ws(s, n, k);
    comma = 0;
    if (k < n && s[k] == ',') {
      comma = 1;
      k = phgmg__npy_ws(s, n, k + 1);
    } else if (k < n && s[k] != ')') {
      return 0;
    }
  }
  if (k >= n) return 0;
  if (cnt == 1 && !comma) return 0; /* "(5)" is an int, not a tuple */
  *nd = cnt;
  *i = k + 1;
  return 1;
}

/* The header dict {'descr': ..., 'fortran_order': ..., 'shape': ...}, keys in
   any order, each exactly once, nothing else but whitespace after it. */
PHGMG__PRIV phgmg_result phgmg__npy_dict(const char *s, size_t n, phgmg__npy_hdr *h) {
  size_t i = phgmg__npy_ws(s, n, 0), b, l;
  int seen_descr = 0, seen_fo = 0, seen_shape = 0, fortran = 0, nd = 0;
  int dims[2] = {0, 0};
  if (i >= n || s[i] != '{') return PHGMG_ERR_FORMAT;
  i = phgmg__npy_ws(s, n, i + 1);
  while (i < n && s[i] != '}') {
    if (!phgmg__npy_str(s, n, &i, &b, &l)) return PHGMG_ERR_FORMAT;
    i = phgmg__npy_ws(s, n, i);
    if (i >= n || s[i] != ':') return PHGMG_ERR_FORMAT;
    i = phgmg__npy_ws(s, n, i + 1);
    if (phgmg__npy_is(s, b, l, "descr")) {
      size_t vb, vl;
      if (seen_descr++ || !phgmg__npy_str(s, n, &i, &vb, &vl)) return PHGMG_ERR_FORMAT;
      if (vl != 3 || (s[vb] != '<' && s[vb] != '>') || s[vb + 1] != 'f' ||
          (s[vb + 2] != '8' && s[vb + 2] != '4'))
        return PHGMG_ERR_FORMAT;
      h->big = s[vb] == '>';
      h->es = s[vb + 2] - '0';
    } else if (phgmg__npy_is(s, b, l, "fortran_order")) {
      if (seen_fo++) return PHGMG_ERR_FORMAT;
      if (phgmg__npy_word(s, n, &i, "True")) fortran = 1;
      else if (phgmg__npy_word(s, n, &i, "False")) fortran = 0;
      else return PHGMG_ERR_FORMAT;
    } else if (phgmg__npy_is(s, b, l, "shape")) {
      if (seen_shape++ || !phgmg__npy_shape(s, n, &i, dims, &nd)) return PHGMG_ERR_FORMAT;
    } else {
      return PHGMG_ERR_FORMAT;
    }
    i = phgmg__npy_ws(s, n, i);
    if (i < n && s[i] == ',') i = phgmg__npy_ws(s, n, i + 1);
    else if (i < n && s[i] != '}') return PHGMG_ERR_FORMAT;
  }
  if (i >= n || !seen_descr || !seen_fo || !seen_shape) return PHGMG_ERR_FORMAT;
  if (phgmg__npy_ws(s, n, i + 1) != n) return PHGMG_ERR_FORMAT;
  h->ndim = nd;
  h->rows = nd >= 1 ? dims[0] : 1;
  h->cols = nd == 2 ? dims[1] : 1;
  h->corder = nd == 2 && !fortran;
  if (h->cols != 0 && (size_t)h->rows > ((size_t)-1) / 16 / (size_t)h->cols)
    return PHGMG_ERR_FORMAT; /* the result would not fit in memory */
  h->count = (size_t)h->rows * (size_t)h->cols;
  return PHGMG_OK;
}

/* Decode n elements of file (flat) indices k0 .. k0+n-1 from src into the
   column-major rows x cols matrix out. */
PHGMG__PRIV void phgmg__npy_decode(const phgmg__npy_hdr *h, const unsigned char *src, size_t k0,
                                   size_t n, double *out) {
  const int es = h->es, swap = h->big == phgmg__npy_host_little();
  size_t t, i = 0, j = 0, dst = k0;
  unsigned char tmp[8];
  int b;
  if (n == 0) return;
  if (h->corder) { i = k0 / (size_t)h->cols; j = k0 % (size_t)h->cols; }
  for (t = 0; t < n; ++t, src += es) {
    double v;
    for (b = 0; b < es; ++b) tmp[b] = src[swap ? es - 1 - b : b];
    if (es == 8) {
      memcpy(&v, tmp, 8);
    } else {
      float f;
      memcpy(&f, tmp, 4);
      v = (double)f;
    }
    if (h->corder) {
      dst = i + j * (size_t)h->rows;
      if (++j == (size_t)h->cols) { j = 0; ++i; }
    }
    out[dst++] = v;
  }
}

PHGMG_DEF phgmg_result phgmg_npy_parse(const void *buf, size_t len, double **out, int *rows,
                                       int *cols, int *ndim, const phgmg_allocator *alloc) {
  const unsigned char *p = PHGMG__CAST(const unsigned char *, buf);
  phgmg__npy_hdr h;
  size_t hoff = 0, hlen = 0, doff;
  memset(&h, 0, sizeof h);
  double *A;
  phgmg_result rc;
  if (!buf || !out || !rows || !cols) return PHGMG_ERR_INVALID_ARG;
  rc = phgmg__npy_preamble(p, len, &hoff, &hlen);
  if (rc != PHGMG_OK) return rc;
  if (hlen > len - hoff) return PHGMG_ERR_FORMAT;
  rc = phgmg__npy_dict(PHGMG__CAST(const char *, buf) + hoff, hlen, &h);
  if (rc != PHGMG_OK) return rc;
  doff = hoff + hlen;
  if (h.count > (len - doff) / (size_t)h.es) return PHGMG_ERR_FORMAT; /* truncated */
  A = phgmg__dalloc(alloc, h.count);
  if (!A) return PHGMG_ERR_NOMEM;
  phgmg__npy_decode(&h, p + doff, 0, h.count, A);
  *out = A;
  *rows = h.rows;
  *cols = h.cols;
  if (ndim) *ndim = h.ndim;
  return PHGMG_OK;
}

PHGMG_DEF void phgmg_npy_free(double *p, const phgmg_allocator *alloc) { phgmg__free(alloc, p); }

/* ---- writing ---- */

/* Checks the writer arguments; *count receives rows*cols. */
PHGMG__PRIV phgmg_result phgmg__npy_wcheck(const double *A, int rows, int cols, int ld, int ndim,
                                           unsigned flags, size_t *count) {
  if (flags & ~(PHGMG_NPY_C_ORDER | PHGMG_NPY_F32)) return PHGMG_ERR_INVALID_ARG;
  if (rows < 0 || cols < 0 || ld < PHGMG__MAX(1, rows)) return PHGMG_ERR_SIZE;
  if (ndim == 0) {
    if (rows != 1 || cols != 1) return PHGMG_ERR_SIZE;
  } else if (ndim == 1) {
    if (rows != 1 && cols != 1) return PHGMG_ERR_SIZE;
  } else if (ndim != 2) {
    return PHGMG_ERR_SIZE;
  }
  if (cols != 0 && (size_t)rows > ((size_t)-1) / 16 / (size_t)cols) return PHGMG_ERR_SIZE;
  *count = (size_t)rows * (size_t)cols;
  if (!A && *count > 0) return PHGMG_ERR_INVALID_ARG;
  return PHGMG_OK;
}

PHGMG__PRIV char *phgmg__npy_puts(char *d, const char *s) {
  while (*s) *d++ = *s++;
  return d;
}
PHGMG__PRIV char *phgmg__npy_putint(char *d, size_t v) {
  char t[24];
  int n = 0;
  do { t[n++] = (char)('0' + (int)(v % 10)); v /= 10; } while (v);
  while (n) *d++ = t[--n];
  return d;
}

/* The complete version 1.0 preamble + header into dst (room for 256 bytes);
   returns its length, a multiple of 64. */
PHGMG__PRIV size_t phgmg__npy_header(unsigned char *dst, int rows, int cols, int ndim,
                                     unsigned flags) {
  char *s = PHGMG__CAST(char *, PHGMG__CAST(void *, dst)), *d = s + 10;
  size_t used, total;
  d = phgmg__npy_puts(d, (flags & PHGMG_NPY_F32) ? "{'descr': '<f4', " : "{'descr': '<f8', ");
  d = phgmg__npy_puts(d, (flags & PHGMG_NPY_C_ORDER) ? "'fortran_order': False, "
                                                     : "'fortran_order': True, ");
  d = phgmg__npy_puts(d, "'shape': (");
  if (ndim == 1) {
    d = phgmg__npy_putint(d, (size_t)rows * (size_t)cols);
    *d++ = ',';
  } else if (ndim == 2) {
    d = phgmg__npy_putint(d, (size_t)rows);
    d = phgmg__npy_puts(d, ", ");
    d = phgmg__npy_putint(d, (size_t)cols);
  }
  d = phgmg__npy_puts(d, "), }");
  used = (size_t)(d - s) + 1; /* + the final newline */
  total = (used + 63) / 64 * 64;
  while ((size_t)(d - s) < total - 1) *d++ = ' ';
  *d = '\n';
  memcpy(s, "\x93NUMPY", 6);
  dst[6] = 1;
  dst[7] = 0;
  dst[8] = (unsigned char)((total - 10) & 0xff);
  dst[9] = (unsigned char)((total - 10) >> 8);
  return total;
}

/* Encode n elements, continuing at element (*i, *j) of A in file order, as
   little-endian f8 or f4 into dst; advances (*i, *j). */
PHGMG__PRIV void phgmg__npy_encode(const double *A, int rows, int cols, int ld, unsigned flags,
                                   size_t *i, size_t *j, size_t n, unsigned char *dst) {
  const int f32 = (flags & PHGMG_NPY_F32) != 0, corder = (flags & PHGMG_NPY_C_ORDER) != 0;
  const int es = f32 ? 4 : 8, swap = !phgmg__npy_host_little();
  size_t t;
  unsigned char tmp[8];
  int b;
  for (t = 0; t < n; ++t, dst += es) {
    double v = A[*i + *j * (size_t)ld];
    if (f32) {
      float f = (float)v;
      memcpy(tmp, &f, 4);
    } else {
      memcpy(tmp, &v, 8);
    }
    for (b = 0; b < es; ++b) dst[b] = tmp[swap ? es - 1 - b : b];
    if (corder) {
      if (++*j == (size_t)cols) { *j = 0; ++*i; }
    } else {
      if (++*i == (size_t)rows) { *i = 0; ++*j; }
    }
  }
}

PHGMG_DEF phgmg_result phgmg_npy_serialize(const double *A, int rows, int cols, int ld, int ndim,
                                           unsigned flags, void *buf, size_t cap, size_t *len) {
  unsigned char head[256];
  size_t count = 0, hl, es = (flags & PHGMG_NPY_F32) ? 4 : 8, need, i = 0, j = 0;
  phgmg_result rc;
  if (!len) return PHGMG_ERR_INVALID_ARG;
  rc = phgmg__npy_wcheck(A, rows, cols, ld, ndim, flags, &count);
  if (rc != PHGMG_OK) return rc;
  hl = phgmg__npy_header(head, rows, cols, ndim, flags);
  need = hl + count * es;
  *len = need;
  if (!buf) return PHGMG_OK;
  if (cap < need) return PHGMG_ERR_WORKSPACE;
  memcpy(buf, head, hl);
  phgmg__npy_encode(A, rows, cols, ld, flags, &i, &j, count,
                    PHGMG__CAST(unsigned char *, buf) + hl);
  return PHGMG_OK;
}

#ifndef PHGMG_NO_STDIO
/* fread of exactly n bytes: PHGMG_OK, PHGMG_ERR_FORMAT at end of file,
   PHGMG_ERR_IO on a read error. */
PHGMG__PRIV phgmg_result phgmg__npy_fread(FILE *f, void *dst, size_t n) {
  if (n == 0 || fread(dst, 1, n, f) == n) return PHGMG_OK;
  return ferror(f) ? PHGMG_ERR_IO : PHGMG_ERR_FORMAT;
}

PHGMG_DEF phgmg_result phgmg_npy_read(const char *path, double **out, int *rows, int *cols,
                                      int *ndim, const phgmg_allocator *alloc) {
  unsigned char pre[12], chunk[4096];
  size_t hoff = 0, hlen = 0, left, k = 0;
  phgmg__npy_hdr h;
  phgmg_result rc;
  char *text;
  double *A;
  long size;
  FILE *f;
  memset(&h, 0, sizeof h);
  if (!path || !out || !rows || !cols) return PHGMG_ERR_INVALID_ARG;
  f = fopen(path, "rb");
  if (!f) return PHGMG_ERR_IO;
  /* preamble: 10 bytes, 12 for versions 2.0 and 3.0 */
  rc = phgmg__npy_fread(f, pre, 10);
  if (rc == PHGMG_OK && (pre[6] == 2 || pre[6] == 3)) rc = phgmg__npy_fread(f, pre + 10, 2);
  if (rc == PHGMG_OK) rc = phgmg__npy_preamble(pre, (pre[6] == 2 || pre[6] == 3) ? 12 : 10,
                                               &hoff, &hlen);
  if (rc != PHGMG_OK) { fclose(f); return rc; }
  /* a file shorter than the header it announces is malformed: check before
     allocating (when the size is known) */
  size = -1; /* unknown (not seekable): read on */
  if (fseek(f, 0, SEEK_END) == 0) {
    size = ftell(f);
    if (fseek(f, (long)hoff, SEEK_SET) != 0) { fclose(f); return PHGMG_ERR_IO; }
  }
  if (size >= 0 && ((size_t)size < hoff || hlen > (size_t)size - hoff)) {
    fclose(f);
    return PHGMG_ERR_FORMAT;
  }
  text = PHGMG__CAST(char *, phgmg__alloc(alloc, hlen));
  if (!text) { fclose(f); return PHGMG_ERR_NOMEM; }
  rc = phgmg__npy_fread(f, text, hlen);
  if (rc == PHGMG_OK) rc = phgmg__npy_dict(text, hlen, &h);
  phgmg__free(alloc, text);
  if (rc != PHGMG_OK) { fclose(f); return rc; }
  if (size >= 0 && h.count > ((size_t)size - hoff - hlen) / (size_t)h.es) {
    fclose(f);
    return PHGMG_ERR_FORMAT; /* truncated data */
  }
  A = phgmg__dalloc(alloc, h.count);
  if (!A) { fclose(f); return PHGMG_ERR_NOMEM; }
  left = h.count;
  while (left > 0 && rc == PHGMG_OK) {
    size_t n = PHGMG__MIN(left, sizeof chunk / (size_t)h.es);
    rc = phgmg__npy_fread(f, chunk, n * (size_t)h.es);
    if (rc == PHGMG_OK) phgmg__npy_decode(&h, chunk, k, n, A);
    k += n;
    left -= n;
  }
  fclose(f);
  if (rc != PHGMG_OK) { phgmg__free(alloc, A); return rc; }
  *out = A;
  *rows = h.rows;
  *cols = h.cols;
  if (ndim) *ndim = h.ndim;
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_npy_write(const char *path, const double *A, int rows, int cols,
                                       int ld, int ndim, unsigned flags) {
  unsigned char head[256], chunk[4096];
  size_t count = 0, hl, es = (flags & PHGMG_NPY_F32) ? 4 : 8, i = 0, j = 0, left;
  phgmg_result rc;
  int ok;
  FILE *f;
  if (!path) return PHGMG_ERR_INVALID_ARG;
  rc = phgmg__npy_wcheck(A, rows, cols, ld, ndim, flags, &count);
  if (rc != PHGMG_OK) return rc;
  hl = phgmg__npy_header(head, rows, cols, ndim, flags);
  f = fopen(path, "wb");
  if (!f) return PHGMG_ERR_IO;
  ok = fwrite(head, 1, hl, f) == hl;
  for (left = count; ok && left > 0;) {
    size_t n = PHGMG__MIN(left, sizeof chunk / es);
    phgmg__npy_encode(A, rows, cols, ld, flags, &i, &j, n, chunk);
    ok = fwrite(chunk, 1, n * es, f) == n * es;
    left -= n;
  }
  if (fclose(f) != 0) ok = 0;
  if (!ok) {
    remove(path);
    return PHGMG_ERR_IO;
  }
  return PHGMG_OK;
}
#endif /* PHGMG_NO_STDIO */
#endif /* PHGMG_NO_OFFLINE */
