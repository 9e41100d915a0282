
/* >>linalg (implementation) ============================================== */
#ifndef PHGMG_NO_OFFLINE

/* ---- level-1 helpers -------------------------------------------------------- */
#if (defined(__GNUC__) || defined(__clang__)) && defined(__AVX__) && !defined(PHGMG_NO_VECTOR_EXT)
#define PHGMG__VEC4 1
typedef double phgmg__v4 __attribute__((vector_size(32)));
#endif

/* x . y with several independent partial sums (a dot product is otherwise
   bound by the latency of one add chain). */
PHGMG__PRIV double phgmg__dot(int n, const double *x, const double *y) {
  int i = 0;
  double s = 0.0;
#ifdef PHGMG__VEC4
  if (n >= 16) {
    phgmg__v4 s0, s1, s2, s3, a, b;
    double t[4];
    memset(&s0, 0, sizeof s0);
    s1 = s2 = s3 = s0;
    for (; i + 16 <= n; i += 16) {
      memcpy(&a, x + i, sizeof a); memcpy(&b, y + i, sizeof b); s0 += a * b;
      memcpy(&a, x + i + 4, sizeof a); memcpy(&b, y + i + 4, sizeof b); s1 += a * b;
      memcpy(&a, x + i + 8, sizeof a); memcpy(&b, y + i + 8, sizeof b); s2 += a * b;
      memcpy(&a, x + i + 12, sizeof a); memcpy(&b, y + i + 12, sizeof b); s3 += a * b;
    }
    s0 = (s0 + s1) + (s2 + s3);
    memcpy(t, &s0, sizeof t);
    s = (t[0] + t[1]) + (t[2] + t[3]);
  }
#else
  {
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
    for (; i + 4 <= n; i += 4) {
      s0 += x[i] * y[i]; s1 += x[i + 1] * y[i + 1];
      s2 += x[i + 2] * y[i + 2]; s3 += x[i + 3] * y[i + 3];
    }
    s = (s0 + s1) + (s2 + s3);
  }
#endif
  for (; i < n; ++i) s += x[i] * y[i];
  return s;
}

/* y += a x */
PHGMG__PRIV void phgmg__axpy(int n, double a, const double *x, double *y) {
  int i = 0;
#ifdef PHGMG__VEC4
  for (; i + 8 <= n; i += 8) {
    phgmg__v4 x0, x1, y0, y1;
    memcpy(&x0, x + i, sizeof x0); memcpy(&x1, x + i + 4, sizeof x1);
    memcpy(&y0, y + i, sizeof y0); memcpy(&y1, y + i + 4, sizeof y1);
    y0 += a * x0; y1 += a * x1;
    memcpy(y + i, &y0, sizeof y0); memcpy(y + i + 4, &y1, sizeof y1);
  }
#endif
  for (; i < n; ++i) y[i] += a * x[i];
}

/* plane rotation of two vectors: (x, y) <- (c x - s y, s x + c y) */
PHGMG__PRIV void phgmg__rot(int n, double *x, double *y, double c, double s) {
  int i = 0;
#ifdef PHGMG__VEC4
  for (; i + 4 <= n; i += 4) {
    phgmg__v4 a, b, u, v;
    memcpy(&a, x + i, sizeof a); memcpy(&b, y + i, sizeof b);
    u = c * a - s * b;
    v = s * a + c * b;
    memcpy(x + i, &u, sizeof u); memcpy(y + i, &v, sizeof v);
  }
#endif
  for (; i < n; ++i) {
    double a = x[i], b = y[i];
    x[i] = c * a - s * b;
    y[i] = s * a + c * b;
  }
}

/* every entry of the m x n matrix finite */
PHGMG__PRIV int phgmg__mat_finite(int m, int n, const double *A, int lda) {
  int j;
  for (j = 0; j < n; ++j)
    if (!phgmg__all_finite(A + (size_t)j * (size_t)lda, (size_t)m)) return 0;
  return 1;
}

/* ---- norms -------------------------------------------------------------- */
PHGMG_DEF double phgmg_norm1(int m, int n, const double *A, int lda) {
  double best = 0.0;
  int i, j;
  for (j = 0; j < n; ++j) {
    const double *a = A + (size_t)j * (size_t)lda;
    double s = 0.0;
    for (i = 0; i < m; ++i) s += fabs(a[i]);
    if (s > best || s != s) best = s;
  }
  return best;
}

PHGMG_DEF double phgmg_normf(int m, int n, const double *A, int lda) {
  /* fast path: plain sum of squares when it neither overflows nor underflows */
  double scale = 0.0, ssq = 0.0;
  int i, j;
  for (j = 0; j < n; ++j) {
    const double *a = A + (size_t)j * (size_t)lda;
    ssq += phgmg__dot(m, a, a);
  }
  if (ssq == 0.0) { /* all zero, or every square underflowed: check */
    for (j = 0; j < n; ++j)
      for (i = 0; i < m; ++i)
        if (A[i + (size_t)j * (size_t)lda] != 0.0) goto scaled;
    return 0.0;
  }
  if (ssq > 1e-280 && ssq < 1e280) return sqrt(ssq);
  if (ssq != ssq) return ssq; /* NaN in A */
scaled:
  /* scaled sum of squares (LAPACK dlassq): scale^2 * ssq */
  ssq = 1.0;
  for (j = 0; j < n; ++j) {
    const double *a = A + (size_t)j * (size_t)lda;
    for (i = 0; i < m; ++i) {
      double v = fabs(a[i]);
      if (v != 0.0 || v != v) {
        if (v != v) return v;
        if (v == HUGE_VAL) return v;
        if (scale < v) {
          double r = scale / v;
          ssq = 1.0 + ssq * r * r;
          scale = v;
        } else {
          double r = v / scale;
          ssq += r * r;
        }
      }
    }
  }
  return scale * sqrt(ssq);
}

/* ---- gemv / gemm ---------------------------------------------------------- */
PHGMG_DEF void phgmg_gemv(char trans, int m, int n, double alpha, const double *A, int lda,
                          const double *x, double beta, double *y) {
  int i;
  int tr = (trans == 'T' || trans == 't');
  int ny = tr ? n : m;
  PHGMG_ASSERT(tr || trans == 'N' || trans == 'n');
  if (m <= 0 || n <= 0) {
    for (i = 0; i < ny; ++i) y[i] = (beta == 0.0) ? 0.0 : beta * y[i];
    return;
  }
#ifdef PHGMG_USE_CBLAS
  cblas_dgemv(CblasColMajor, tr ? CblasTrans : CblasNoTrans, m, n, alpha, A, lda, x, 1, beta, y, 1);
#else
  int j;
  if (beta == 0.0) {
    for (i = 0; i < ny; ++i) y[i] = 0.0;
  } else if (beta != 1.0) {
    for (i = 0; i < ny; ++i) y[i] *= beta;
  }
  if (alpha == 0.0) return;
  if (!tr) {
    /* y += alpha * A x, four columns per sweep over y */
    for (j = 0; j + 4 <= n; j += 4) {
      const double *a0 = A + (size_t)j * (size_t)lda, *a1 = a0 + lda, *a2 = a1 + lda, *a3 = a2 + lda;
      double t0 = alpha * x[j], t1 = alpha * x[j + 1], t2 = alpha * x[j + 2], t3 = alpha * x[j + 3];
      for (i = 0; i < m; ++i) y[i] += t0 * a0[i] + t1 * a1[i] + t2 * a2[i] + t3 * a3[i];
    }
    for (; j < n; ++j) {
      const double *a = A + (size_t)j * (size_t)lda;
      double t = alpha * x[j];
      phgmg__axpy(m, t, a, y);
    }
  } else {
    /* y += alpha * A^T x, dot products of columns */
    for (j = 0; j < n; ++j) y[j] += alpha * phgmg__dot(m, A + (size_t)j * (size_t)lda, x);
  }
#endif
}

/* Portable GEMM core: a block of op(A) (MC x KC) is packed into 8-row slivers
   (on the stack, MC*KC doubles), then 8 x 6 tiles of C are computed by a
   register-blocked micro-kernel that streams the matching 6 columns of op(B)
   directly from B (any strides). With GCC/Clang on an AVX target the
   micro-kernel uses vector extensions (define PHGMG_NO_VECTOR_EXT for the plain
   C version, which is the one used everywhere else). It also serves the
   complex products (interleaved storage seen as a real matrix). */
#ifndef PHGMG_GEMM_MC
#define PHGMG_GEMM_MC 64 /* multiple of 8 */
#endif
#ifndef PHGMG_GEMM_KC
#define PHGMG_GEMM_KC 256
#endif
#define PHGMG__MR 8
#define PHGMG__NR 6

/* C(0:mr, 0:nr) += alpha * Ap * op(B)(0:kc, 0:nr), Ap packed (Ap[8p + i]);
   op(B)(p, j) = B[p*bsp + j*bsj]. mr <= 8, nr <= 6. */
PHGMG__PRIV void phgmg__gemm_micro(int kc, const double *Ap, const double *B, size_t bsp,
                                   size_t bsj, int mr, int nr, double alpha, double *C, int ldc) {
  double tile[PHGMG__MR * PHGMG__NR];
  const double *b0 = B, *b1 = B + (nr > 1 ? bsj : 0), *b2 = B + (nr > 2 ? 2 * bsj : 0);
  const double *b3 = B + (nr > 3 ? 3 * bsj : 0), *b4 = B + (nr > 4 ? 4 * bsj : 0);
  const double *b5 = B + (nr > 5 ? 5 * bsj : 0);
  int p, i, j;
#ifdef PHGMG__VEC4
  phgmg__v4 c00, c01, c10, c11, c20, c21, c30, c31, c40, c41, c50, c51, a0, a1;
  memset(&c00, 0, sizeof c00);
  c01 = c10 = c11 = c20 = c21 = c30 = c31 = c40 = c41 = c50 = c51 = c00;
  for (p = 0; p < kc; ++p) {
    size_t o = (size_t)p * bsp;
    double x;
    memcpy(&a0, Ap, sizeof a0);
    memcpy(&a1, Ap + 4, sizeof a1);
    Ap += PHGMG__MR;
    x = b0[o]; c00 += a0 * x; c01 += a1 * x;
    x = b1[o]; c10 += a0 * x; c11 += a1 * x;
    x = b2[o]; c20 += a0 * x; c21 += a1 * x;
    x = b3[o]; c30 += a0 * x; c31 += a1 * x;
    x = b4[o]; c40 += a0 * x; c41 += a1 * x;
    x = b5[o]; c50 += a0 * x; c51 += a1 * x;
  }
  memcpy(tile + 0, &c00, sizeof c00); memcpy(tile + 4, &c01, sizeof c01);
  memcpy(tile + 8, &c10, sizeof c10); memcpy(tile + 12, &c11, sizeof c11);
  memcpy(tile + 16, &c20, sizeof c20); memcpy(tile + 20, &c21, sizeof c21);
  memcpy(tile + 24, &c30, sizeof c30); memcpy(tile + 28, &c31, sizeof c31);
  memcpy(tile + 32, &c40, sizeof c40); memcpy(tile + 36, &c41, sizeof c41);
  memcpy(tile + 40, &c50, sizeof c50); memcpy(tile + 44, &c51, sizeof c51);
#else
  for (i = 0; i < PHGMG__MR * PHGMG__NR; ++i) tile[i] = 0.0;
  for (p = 0; p < kc; ++p) {
    size_t o = (size_t)p * bsp;
    double x0 = b0[o], x1 = b1[o], x2 = b2[o], x3 = b3[o], x4 = b4[o], x5 = b5[o];
    for (i = 0; i < PHGMG__MR; ++i) {
      double a = Ap[i];
      tile[i] += a * x0; tile[8 + i] += a * x1; tile[16 + i] += a * x2;
      tile[24 + i] += a * x3; tile[32 + i] += a * x4; tile[40 + i] += a * x5;
    }
    Ap += PHGMG__MR;
  }
#endif
  for (j = 0; j < nr; ++j) {
    double *c = C + (size_t)j * (size_t)ldc;
    const double *t = tile + PHGMG__MR * j;
    for (i = 0; i < mr; ++i) c[i] += alpha * t[i];
  }
}

/* C (m x n) += alpha * opA(A) * opB(B), opB(B)(p, j) = B[p*bsp + j*bsj];
   amode 0: opA(A)(i, p) = A[i + p*lda]; 1: A[p + i*lda] (transposed);
   2 (m even, A the real view of an interleaved complex matrix): rows 2r, 2r+1
   of opA are (-Im, Re) of complex row r, i.e. the real view of i*A. */
PHGMG__PRIV void phgmg__gemm_acc(int m, int n, int k, double alpha, int amode, const double *A,
                                 int lda, const double *B, size_t bsp, size_t bsj, double *C,
                                 int ldc) {
  double Ap[PHGMG_GEMM_MC * PHGMG_GEMM_KC];
  int pc, ic, ir, jr, p, i;
  if (m <= 0 || n <= 0 || k <= 0 || alpha == 0.0) return;
  for (pc = 0; pc < k; pc += PHGMG_GEMM_KC) {
    int kc = PHGMG__MIN(PHGMG_GEMM_KC, k - pc);
    for (ic = 0; ic < m; ic += PHGMG_GEMM_MC) {
      int mc = PHGMG__MIN(PHGMG_GEMM_MC, m - ic);
      /* pack opA(ic:ic+mc, pc:pc+kc) into 8-row slivers, zero padded */
      for (ir = 0; ir < mc; ir += PHGMG__MR) {
        int mr = PHGMG__MIN(PHGMG__MR, mc - ir);
        double *dst = Ap + (size_t)ir * (size_t)kc;
        if (amode == 0) {
          for (p = 0; p < kc; ++p) {
            const double *src = A + (ic + ir) + (size_t)(pc + p) * (size_t)lda;
            double *d = dst + (size_t)p * PHGMG__MR;
            for (i = 0; i < mr; ++i) d[i] = src[i];
            for (; i < PHGMG__MR; ++i) d[i] = 0.0;
          }
        } else if (amode == 1) {
          for (i = 0; i < PHGMG__MR; ++i) {
            if (i < mr) {
              const double *src = A + pc + (size_t)(ic + ir + i) * (size_t)lda;
              for (p = 0; p < kc; ++p) dst[(size_t)p * PHGMG__MR + i] = src[p];
            } else {
              for (p = 0; p < kc; ++p) dst[(size_t)p * PHGMG__MR + i] = 0.0;
            }
          }
        } else {
          for (p = 0; p < kc; ++p) {
            const double *src = A + (ic + ir) + (size_t)(pc + p) * (size_t)lda;
            double *d = dst + (size_t)p * PHGMG__MR;
            for (i = 0; i + 1 < mr; i += 2) { d[i] = -src[i + 1]; d[i + 1] = src[i]; }
            for (; i < PHGMG__MR; ++i) d[i] = 0.0;
          }
        }
      }
      for (jr = 0; jr < n; jr += PHGMG__NR) {
        int nr = PHGMG__MIN(PHGMG__NR, n - jr);
        const double *bp = B + (size_t)pc * bsp + (size_t)jr * bsj;
        for (ir = 0; ir < mc; ir += PHGMG__MR)
          phgmg__gemm_micro(kc, Ap + (size_t)ir * (size_t)kc, bp, bsp, bsj,
                            PHGMG__MIN(PHGMG__MR, mc - ir), nr, alpha,
                            C + (ic + ir) + (size_t)jr * (size_t)ldc, ldc);
      }
    }
  }
}

/* Complex C (m x n) += alpha * A (m x k) * B (k x n), alpha real, interleaved
   storage with leading dimensions in complex elements: Re(C) and Im(C) come
   from two real products on the interleaved views, [Re A; Im A] Re B +
   [-Im A; Re A] Im B, so no flop is wasted. */
PHGMG__PRIV void phgmg__zgemm_acc(int m, int n, int k, double alpha, const double *A, int lda,
                                  const double *B, int ldb, double *C, int ldc) {
  size_t bsj = 2 * (size_t)ldb;
  phgmg__gemm_acc(2 * m, n, k, alpha, 0, A, 2 * lda, B, 2, bsj, C, 2 * ldc);
  phgmg__gemm_acc(2 * m, n, k, alpha, 2, A, 2 * lda, B + 1, 2, bsj, C, 2 * ldc);
}

PHGMG_DEF void phgmg_gemm(char transa, char transb, int m, int n, int k, double alpha,
                          const double *A, int lda, const double *B, int ldb,
                          double beta, double *C, int ldc) {
  int ta = (transa == 'T' || transa == 't');
  int tb = (transb == 'T' || transb == 't');
  int i, j;
  PHGMG_ASSERT(ta || transa == 'N' || transa == 'n');
  PHGMG_ASSERT(tb || transb == 'N' || transb == 'n');
  if (m <= 0 || n <= 0) return;
#ifdef PHGMG_USE_CBLAS
  if (k > 0 && alpha != 0.0) {
    cblas_dgemm(CblasColMajor, ta ? CblasTrans : CblasNoTrans, tb ? CblasTrans : CblasNoTrans,
                m, n, k, alpha, A, lda, B, ldb, beta, C, ldc);
    return;
  }
#endif
  for (j = 0; j < n; ++j) {
    double *c = C + (size_t)j * (size_t)ldc;
    if (beta == 0.0) for (i = 0; i < m; ++i) c[i] = 0.0;
    else if (beta != 1.0) for (i = 0; i < m; ++i) c[i] *= beta;
  }
  phgmg__gemm_acc(m, n, k, alpha, ta, A, lda, B, tb ? (size_t)ldb : 1, tb ? 1 : (size_t)ldb, C, ldc);
}

/* ---- real LU -------------------------------------------------------------- */
/* Row interchanges k <-> ipiv[k], k in [k1, k2), applied to ncols columns of A. */
PHGMG__PRIV void phgmg__laswp(int ncols, double *A, int lda, int k1, int k2, const int *ipiv) {
  int j, k;
  for (j = 0; j < ncols; ++j) {
    double *c = A + (size_t)j * (size_t)lda;
    for (k = k1; k < k2; ++k) {
      int p = ipiv[k];
      if (p != k) { double t = c[k]; c[k] = c[p]; c[p] = t; }
    }
  }
}

/* Triangular solves with n x n factors on B (n x nrhs), in place. Recursive
   halving, the off-diagonal blocks go through gemm; small problems (n <= 32
   or fewer than 4 right-hand sides) by column substitution.
   llu: L^{-1} B, L unit lower.     lun: U^{-1} B, U upper.
   utn: U^{-T} B.                   ltu: L^{-T} B, L unit lower. */
#define PHGMG__TRSM_LEAF 32
PHGMG__PRIV void phgmg__trsm_llu(int n, int nrhs, const double *L, int ldl, double *B, int ldb) {
  int j, k, n1;
  if (n <= PHGMG__TRSM_LEAF || nrhs < 4) {
    for (j = 0; j < nrhs; ++j) {
      double *b = B + (size_t)j * (size_t)ldb;
      for (k = 0; k < n; ++k) {
        const double *l = L + (size_t)k * (size_t)ldl;
        double t = b[k];
        if (t != 0.0) phgmg__axpy(n - k - 1, -t, l + k + 1, b + k + 1);
      }
    }
    return;
  }
  n1 = n / 2;
  phgmg__trsm_llu(n1, nrhs, L, ldl, B, ldb);
  phgmg_gemm('N', 'N', n - n1, nrhs, n1, -1.0, L + n1, ldl, B, ldb, 1.0, B + n1, ldb);
  phgmg__trsm_llu(n - n1, nrhs, L + n1 + (size_t)n1 * (size_t)ldl, ldl, B + n1, ldb);
}
PHGMG__PRIV void phgmg__trsm_lun(int n, int nrhs, const double *U, int ldu, double *B, int ldb) {
  int j, k, n1;
  if (n <= PHGMG__TRSM_LEAF || nrhs < 4) {
    for (j = 0; j < nrhs; ++j) {
      double *b = B + (size_t)j * (size_t)ldb;
      for (k = n - 1; k >= 0; --k) {
        const double *u = U + (size_t)k * (size_t)ldu;
        double t = b[k] / u[k];
        b[k] = t;
        if (t != 0.0) phgmg__axpy(k, -t, u, b);
      }
    }
    return;
  }
  n1 = n / 2;
  phgmg__trsm_lun(n - n1, nrhs, U + n1 + (size_t)n1 * (size_t)ldu, ldu, B + n1, ldb);
  phgmg_gemm('N', 'N', n1, nrhs, n - n1, -1.0, U + (size_t)n1 * (size_t)ldu, ldu, B + n1, ldb,
             1.0, B, ldb);
  phgmg__trsm_lun(n1, nrhs, U, ldu, B, ldb);
}
PHGMG__PRIV void phgmg__trsm_utn(int n, int nrhs, const double *U, int ldu, double *B, int ldb) {
  int j, k, n1;
  if (n <= PHGMG__TRSM_LEAF || nrhs < 4) {
    for (j = 0; j < nrhs; ++j) {
      double *b = B + (size_t)j * (size_t)ldb;
      for (k = 0; k < n; ++k) {
        const double *u = U + (size_t)k * (size_t)ldu;
        b[k] = (b[k] - phgmg__dot(k, u, b)) / u[k];
      }
    }
    return;
  }
  n1 = n / 2;
  phgmg__trsm_utn(n1, nrhs, U, ldu, B, ldb);
  phgmg_gemm('T', 'N', n - n1, nrhs, n1, -1.0, U + (size_t)n1 * (size_t)ldu, ldu, B, ldb, 1.0,
             B + n1, ldb);
  phgmg__trsm_utn(n - n1, nrhs, U + n1 + (size_t)n1 * (size_t)ldu, ldu, B + n1, ldb);
}
PHGMG__PRIV void phgmg__trsm_ltu(int n, int nrhs, const double *L, int ldl, double *B, int ldb) {
  int j, k, n1;
  if (n <= PHGMG__TRSM_LEAF || nrhs < 4) {
    for (j = 0; j < nrhs; ++j) {
      double *b = B + (size_t)j * (size_t)ldb;
      for (k = n - 1; k >= 0; --k) {
        const double *l = L + (size_t)k * (size_t)ldl;
        b[k] -= phgmg__dot(n - k - 1, l + k + 1, b + k + 1);
      }
    }
    return;
  }
  n1 = n / 2;
  phgmg__trsm_ltu(n - n1, nrhs, L + n1 + (size_t)n1 * (size_t)ldl, ldl, B + n1, ldb);
  phgmg_gemm('T', 'N', n1, nrhs, n - n1, -1.0, L + n1, ldl, B + n1, ldb, 1.0, B, ldb);
  phgmg__trsm_ltu(n1, nrhs, L, ldl, B, ldb);
}

/* Recursive LU with partial pivoting of an m x n panel (m >= n), ipiv relative
   to the panel. Returns 1 if an exactly zero pivot column was met. */
PHGMG__PRIV int phgmg__lu_rec(int m, int n, double *A, int lda, int *ipiv) {
  int i, j, k, n1, sing = 0;
  if (n <= 16) {
    for (k = 0; k < n; ++k) {
      double *ak = A + (size_t)k * (size_t)lda, amax = fabs(ak[k]), piv;
      int p = k;
      for (i = k + 1; i < m; ++i)
        if (fabs(ak[i]) > amax) { amax = fabs(ak[i]); p = i; }
      ipiv[k] = p;
      if (amax == 0.0) { sing = 1; continue; } /* the column below is zero: L(:,k) = 0 */
      if (p != k)
        for (j = 0; j < n; ++j) {
          double *c = A + (size_t)j * (size_t)lda, t = c[k];
          c[k] = c[p]; c[p] = t;
        }
      piv = ak[k];
      if (amax >= 2.2250738585072014e-308) {
        double r = 1.0 / piv;
        for (i = k + 1; i < m; ++i) ak[i] *= r;
      } else {
        for (i = k + 1; i < m; ++i) ak[i] /= piv;
      }
      for (j = k + 1; j < n; ++j) {
        double *c = A + (size_t)j * (size_t)lda, t = c[k];
        if (t != 0.0) phgmg__axpy(m - k - 1, -t, ak + k + 1, c + k + 1);
      }
    }
    return sing;
  }
  n1 = n / 2;
  sing = phgmg__lu_rec(m, n1, A, lda, ipiv);
  phgmg__laswp(n - n1, A + (size_t)n1 * (size_t)lda, lda, 0, n1, ipiv);
  phgmg__trsm_llu(n1, n - n1, A, lda, A + (size_t)n1 * (size_t)lda, lda);
  phgmg_gemm('N', 'N', m - n1, n - n1, n1, -1.0, A + n1, lda, A + (size_t)n1 * (size_t)lda, lda,
             1.0, A + n1 + (size_t)n1 * (size_t)lda, lda);
  sing |= phgmg__lu_rec(m - n1, n - n1, A + n1 + (size_t)n1 * (size_t)lda, lda, ipiv + n1);
  for (i = n1; i < n; ++i) ipiv[i] += n1;
  phgmg__laswp(n1, A, lda, n1, n, ipiv);
  return sing;
}

PHGMG_DEF phgmg_result phgmg_lu_factor(int n, double *A, int lda, int *ipiv) {
  int j;
  if (n < 0 || lda < PHGMG__MAX(n, 1)) return PHGMG_ERR_SIZE;
  if (n == 0) return PHGMG_OK;
  if (!A || !ipiv) return PHGMG_ERR_INVALID_ARG;
  for (j = 0; j < n; ++j)
    if (!phgmg__all_finite(A + (size_t)j * (size_t)lda, (size_t)n)) return PHGMG_ERR_NANINF;
  if (phgmg__lu_rec(n, n, A, lda, ipiv)) return PHGMG_ERR_SINGULAR;
  /* finite input can still overflow (pivot growth) */
  return phgmg__mat_finite(n, n, A, lda) ? PHGMG_OK : PHGMG_ERR_NANINF;
}

PHGMG_DEF void phgmg_lu_solve(char trans, int n, const double *LU, int lda, const int *ipiv,
                              int nrhs, double *B, int ldb) {
  int j, k;
  int tr = (trans == 'T' || trans == 't');
  PHGMG_ASSERT(tr || trans == 'N' || trans == 'n');
  if (n <= 0 || nrhs <= 0) return;
  if (!tr) {
    phgmg__laswp(nrhs, B, ldb, 0, n, ipiv);
    phgmg__trsm_llu(n, nrhs, LU, lda, B, ldb);
    phgmg__trsm_lun(n, nrhs, LU, lda, B, ldb);
  } else {
    phgmg__trsm_utn(n, nrhs, LU, lda, B, ldb);
    phgmg__trsm_ltu(n, nrhs, LU, lda, B, ldb);
    for (j = 0; j < nrhs; ++j) {
      double *b = B + (size_t)j * (size_t)ldb;
      for (k = n - 1; k >= 0; --k)
        if (ipiv[k] != k) { double t = b[k]; b[k] = b[ipiv[k]]; b[ipiv[k]] = t; }
    }
  }
}

/* ---- complex LU (interleaved re,im) ----------------------------------------- */
/* (cr, ci) = (ar + i ai) / (br + i bi), Smith's algorithm */
PHGMG__PRIV void phgmg__zdiv(double ar, double ai, double br, double bi, double *cr, double *ci) {
  if (fabs(br) >= fabs(bi)) {
    double q = bi / br, d = br + bi * q;
    *cr = (ar + ai * q) / d;
    *ci = (ai - ar * q) / d;
  } else {
    double q = br / bi, d = br * q + bi;
    *cr = (ar * q + ai) / d;
    *ci = (ai * q - ar) / d;
  }
}

/* y -= (tr + i ti) x over n complex entries */
PHGMG__PRIV void phgmg__zaxpy_neg(int n, double tr, double ti, const double *x, double *y) {
  int i;
  for (i = 0; i < n; ++i) {
    double xr = x[2 * i], xi = x[2 * i + 1];
    y[2 * i] -= tr * xr - ti * xi;
    y[2 * i + 1] -= tr * xi + ti * xr;
  }
}

PHGMG__PRIV void phgmg__zlaswp(int ncols, double *A, int lda, int k1, int k2, const int *ipiv) {
  int j, k;
  for (j = 0; j < ncols; ++j) {
    double *c = A + 2 * (size_t)j * (size_t)lda, t;
    for (k = k1; k < k2; ++k) {
      int p = ipiv[k];
      if (p != k) {
        t = c[2 * k]; c[2 * k] = c[2 * p]; c[2 * p] = t;
        t = c[2 * k + 1]; c[2 * k + 1] = c[2 * p + 1]; c[2 * p + 1] = t;
      }
    }
  }
}

/* complex L^{-1} B (unit lower) and U^{-1} B, as the real ones */
PHGMG__PRIV void phgmg__ztrsm_llu(int n, int nrhs, const double *L, int ldl, double *B, int ldb) {
  int j, k, n1;
  if (n <= PHGMG__TRSM_LEAF || nrhs < 2) {
    for (j = 0; j < nrhs; ++j) {
      double *b = B + 2 * (size_t)j * (size_t)ldb;
      for (k = 0; k < n; ++k) {
        const double *l = L + 2 * (size_t)k * (size_t)ldl;
        double tr = b[2 * k], ti = b[2 * k + 1];
        if (tr != 0.0 || ti != 0.0) phgmg__zaxpy_neg(n - k - 1, tr, ti, l + 2 * (k + 1), b + 2 * (k + 1));
      }
    }
    return;
  }
  n1 = n / 2;
  phgmg__ztrsm_llu(n1, nrhs, L, ldl, B, ldb);
  phgmg__zgemm_acc(n - n1, nrhs, n1, -1.0, L + 2 * n1, ldl, B, ldb, B + 2 * n1, ldb);
  phgmg__ztrsm_llu(n - n1, nrhs, L + 2 * (n1 + (size_t)n1 * (size_t)ldl), ldl, B + 2 * n1, ldb);
}
PHGMG__PRIV void phgmg__ztrsm_lun(int n, int nrhs, const double *U, int ldu, double *B, int ldb) {
  int j, k, n1;
  if (n <= PHGMG__TRSM_LEAF || nrhs < 2) {
    for (j = 0; j < nrhs; ++j) {
      double *b = B + 2 * (size_t)j * (size_t)ldb;
      for (k = n - 1; k >= 0; --k) {
        const double *u = U + 2 * (size_t)k * (size_t)ldu;
        double tr, ti;
        phgmg__zdiv(b[2 * k], b[2 * k + 1], u[2 * k], u[2 * k + 1], &tr, &ti);
        b[2 * k] = tr;
        b[2 * k + 1] = ti;
        if (tr != 0.0 || ti != 0.0) phgmg__zaxpy_neg(k, tr, ti, u, b);
      }
    }
    return;
  }
  n1 = n / 2;
  phgmg__ztrsm_lun(n - n1, nrhs, U + 2 * (n1 + (size_t)n1 * (size_t)ldu), ldu, B + 2 * n1, ldb);
  phgmg__zgemm_acc(n1, nrhs, n - n1, -1.0, U + 2 * (size_t)n1 * (size_t)ldu, ldu, B + 2 * n1, ldb,
                   B, ldb);
  phgmg__ztrsm_lun(n1, nrhs, U, ldu, B, ldb);
}

/* Recursive complex LU of an m x n panel, as phgmg__lu_rec. */
PHGMG__PRIV int phgmg__zlu_rec(int m, int n, double *A, int lda, int *ipiv) {
  int i, k, n1, sing = 0;
  if (n <= 8) {
    for (k = 0; k < n; ++k) {
      double *ak = A + 2 * (size_t)k * (size_t)lda, rr, ri;
      double amax = fabs(ak[2 * k]) + fabs(ak[2 * k + 1]);
      int p = k, j;
      for (i = k + 1; i < m; ++i) {
        double v = fabs(ak[2 * i]) + fabs(ak[2 * i + 1]);
        if (v > amax) { amax = v; p = i; }
      }
      ipiv[k] = p;
      if (amax == 0.0) { sing = 1; continue; }
      if (p != k) phgmg__zlaswp(n, A, lda, k, k + 1, ipiv);
      phgmg__zdiv(1.0, 0.0, ak[2 * k], ak[2 * k + 1], &rr, &ri);
      for (i = k + 1; i < m; ++i) {
        double xr = ak[2 * i], xi = ak[2 * i + 1];
        ak[2 * i] = xr * rr - xi * ri;
        ak[2 * i + 1] = xr * ri + xi * rr;
      }
      for (j = k + 1; j < n; ++j) {
        double *c = A + 2 * (size_t)j * (size_t)lda, tr = c[2 * k], ti = c[2 * k + 1];
        if (tr != 0.0 || ti != 0.0) phgmg__zaxpy_neg(m - k - 1, tr, ti, ak + 2 * (k + 1), c + 2 * (k + 1));
      }
    }
    return sing;
  }
  n1 = n / 2;
  sing = phgmg__zlu_rec(m, n1, A, lda, ipiv);
  phgmg__zlaswp(n - n1, A + 2 * (size_t)n1 * (size_t)lda, lda, 0, n1, ipiv);
  phgmg__ztrsm_llu(n1, n - n1, A, lda, A + 2 * (size_t)n1 * (size_t)lda, lda);
  phgmg__zgemm_acc(m - n1, n - n1, n1, -1.0, A + 2 * n1, lda, A + 2 * (size_t)n1 * (size_t)lda, lda,
                   A + 2 * (n1 + (size_t)n1 * (size_t)lda), lda);
  sing |= phgmg__zlu_rec(m - n1, n - n1, A + 2 * (n1 + (size_t)n1 * (size_t)lda), lda, ipiv + n1);
  for (i = n1; i < n; ++i) ipiv[i] += n1;
  phgmg__zlaswp(n1, A, lda, n1, n, ipiv);
  return sing;
}

PHGMG_DEF phgmg_result phgmg_zlu_factor(int n, double *A, int lda, int *ipiv) {
  int j;
  if (n < 0 || lda < PHGMG__MAX(n, 1)) return PHGMG_ERR_SIZE;
  if (n == 0) return PHGMG_OK;
  if (!A || !ipiv) return PHGMG_ERR_INVALID_ARG;
  for (j = 0; j < n; ++j)
    if (!phgmg__all_finite(A + 2 * (size_t)j * (size_t)lda, 2 * (size_t)n)) return PHGMG_ERR_NANINF;
  if (phgmg__zlu_rec(n, n, A, lda, ipiv)) return PHGMG_ERR_SINGULAR;
  return phgmg__mat_finite(2 * n, n, A, 2 * lda) ? PHGMG_OK : PHGMG_ERR_NANINF;
}

PHGMG_DEF void phgmg_zlu_solve(int n, const double *LU, int lda, const int *ipiv,
                               int nrhs, double *B, int ldb) {
  if (n <= 0 || nrhs <= 0) return;
  phgmg__zlaswp(nrhs, B, ldb, 0, n, ipiv);
  phgmg__ztrsm_llu(n, nrhs, LU, lda, B, ldb);
  phgmg__ztrsm_lun(n, nrhs, LU, lda, B, ldb);
}

/* ---- condition estimate (Hager 1984, Higham 1988; LAPACK dlacn2) ---------- */
PHGMG__PRIV double phgmg__asum(int n, const double *x) {
  double s = 0.0;
  int i;
  for (i = 0; i < n; ++i) s += fabs(x[i]);
  return s;
}
PHGMG__PRIV int phgmg__iamax(int n, const double *x) {
  int i, j = 0;
  double m = -1.0;
  for (i = 0; i < n; ++i)
    if (fabs(x[i]) > m) { m = fabs(x[i]); j = i; }
  return j;
}

PHGMG_DEF double phgmg_lu_rcond(int n, const double *LU, int lda, const int *ipiv,
                                double anorm1, double *work, int *iwork) {
  double *x = work, est, estold, temp;
  int *isgn = iwork;
  int i, j, jlast, iter, same;
  if (n <= 0) return 1.0;
  if (!(anorm1 > 0.0) || anorm1 == HUGE_VAL) return 0.0;
  for (i = 0; i < n; ++i) {
    double d = LU[i + (size_t)i * (size_t)lda];
    if (d == 0.0 || d != d) return 0.0;
  }
  for (i = 0; i < n; ++i) x[i] = 1.0 / (double)n;
  phgmg_lu_solve('N', n, LU, lda, ipiv, 1, x, n);
  if (n == 1) {
    est = fabs(x[0]);
  } else {
    est = phgmg__asum(n, x);
    for (i = 0; i < n; ++i) { isgn[i] = x[i] >= 0.0 ? 1 : -1; x[i] = (double)isgn[i]; }
    phgmg_lu_solve('T', n, LU, lda, ipiv, 1, x, n);
    j = phgmg__iamax(n, x);
    for (iter = 2;; ++iter) {
      for (i = 0; i < n; ++i) x[i] = 0.0;
      x[j] = 1.0;
      phgmg_lu_solve('N', n, LU, lda, ipiv, 1, x, n);
      estold = est;
      est = phgmg__asum(n, x);
      same = 1;
      for (i = 0; i < n; ++i)
        if ((x[i] >= 0.0 ? 1 : -1) != isgn[i]) { same = 0; break; }
      if (same || est <= estold) { if (est < estold) est = estold; break; }
      for (i = 0; i < n; ++i) { isgn[i] = x[i] >= 0.0 ? 1 : -1; x[i] = (double)isgn[i]; }
      phgmg_lu_solve('T', n, LU, lda, ipiv, 1, x, n);
      jlast = j;
      j = phgmg__iamax(n, x);
      if (fabs(x[jlast]) == fabs(x[j]) || iter >= 5) break;
    }
    /* alternating-sign test vector */
    for (i = 0; i < n; ++i)
      x[i] = ((i & 1) ? -1.0 : 1.0) * (1.0 + (double)i / (double)(n - 1));
    phgmg_lu_solve('N', n, LU, lda, ipiv, 1, x, n);
    temp = 2.0 * phgmg__asum(n, x) / (3.0 * (double)n);
    if (temp > est) est = temp;
  }
  if (!(est > 0.0) || est != est) return 0.0;
  return (1.0 / est) / anorm1;
}

/* ---- Householder QR ---------------------------------------------------------- */
/* Generate H = I - tau v v^T with v = (1, x) such that H (alpha; x) = (beta; 0).
   n is the length including alpha. x is overwritten by v(1:). */
PHGMG__PRIV void phgmg__larfg(int n, double *alpha, double *x, double *tau) {
  double xnorm, beta, r;
  int i;
  if (n <= 1) { *tau = 0.0; return; }
  xnorm = phgmg_normf(n - 1, 1, x, n - 1);
  if (xnorm == 0.0) { *tau = 0.0; return; }
  beta = -copysign(hypot(*alpha, xnorm), *alpha);
  *tau = (beta - *alpha) / beta;
  r = 1.0 / (*alpha - beta);
  for (i = 0; i < n - 1; ++i) x[i] *= r;
  *alpha = beta;
}

/* C (m x n) := (I - tau v v^T) C, v = (1, v[1..m-1]) (v[0] is not read). */
PHGMG__PRIV void phgmg__larf_left(int m, int n, const double *v, double tau, double *C, int ldc) {
  int j;
  if (tau == 0.0) return;
  for (j = 0; j < n; ++j) {
    double *c = C + (size_t)j * (size_t)ldc;
    double s = tau * (c[0] + phgmg__dot(m - 1, v + 1, c + 1));
    if (s == 0.0) continue;
    c[0] -= s;
    phgmg__axpy(m - 1, -s, v + 1, c + 1);
  }
}

PHGMG_DEF phgmg_result phgmg_qr(int m, int n, double *A, int lda, double *tau) {
  int k, kmin = PHGMG__MIN(m, n);
  if (m < 0 || n < 0 || lda < PHGMG__MAX(m, 1)) return PHGMG_ERR_SIZE;
  if (kmin == 0) return PHGMG_OK;
  if (!A || !tau) return PHGMG_ERR_INVALID_ARG;
  if (!phgmg__mat_finite(m, n, A, lda)) return PHGMG_ERR_NANINF;
  for (k = 0; k < kmin; ++k) {
    double *akk = A + k + (size_t)k * (size_t)lda;
    phgmg__larfg(m - k, akk, akk + 1, &tau[k]);
    if (k + 1 < n) phgmg__larf_left(m - k, n - k - 1, akk, tau[k], akk + lda, lda);
  }
  return PHGMG_OK;
}

/* QR with column pivoting, stopping early (at step k = *rank) once every
   trailing column norm is <= tol (tol < 0: never). vn: 2n doubles. */
PHGMG__PRIV void phgmg__qrcp_core(int m, int n, double *A, int lda, double *tau, int *jpvt,
                                  double *vn, double tol, int *rank) {
  double *vn1 = vn, *vn2 = vn + n;
  const double tol3z = sqrt(PHGMG__EPS);
  int i, j, k, kmin = PHGMG__MIN(m, n);
  for (j = 0; j < n; ++j) {
    jpvt[j] = j;
    vn1[j] = vn2[j] = phgmg_normf(m, 1, A + (size_t)j * (size_t)lda, lda);
  }
  for (k = 0; k < kmin; ++k) {
    int p = k + phgmg__iamax(n - k, vn1 + k);
    double *ak = A + (size_t)k * (size_t)lda;
    if (tol >= 0.0 && vn1[p] <= tol) break;
    if (p != k) {
      double *ap = A + (size_t)p * (size_t)lda, t;
      int it;
      for (i = 0; i < m; ++i) { t = ak[i]; ak[i] = ap[i]; ap[i] = t; }
      it = jpvt[p]; jpvt[p] = jpvt[k]; jpvt[k] = it;
      vn1[p] = vn1[k];
      vn2[p] = vn2[k];
    }
    phgmg__larfg(m - k, ak + k, ak + k + 1, &tau[k]);
    if (k + 1 < n) phgmg__larf_left(m - k, n - k - 1, ak + k, tau[k], ak + k + lda, lda);
    /* downdate the trailing column norms (LAPACK dlaqp2 safeguard) */
    for (j = k + 1; j < n; ++j) {
      if (vn1[j] != 0.0) {
        double *aj = A + (size_t)j * (size_t)lda;
        double temp = fabs(aj[k]) / vn1[j], temp2;
        temp = 1.0 - temp * temp;
        if (temp < 0.0) temp = 0.0;
        temp2 = temp * (vn1[j] / vn2[j]) * (vn1[j] / vn2[j]);
        if (temp2 <= tol3z) {
          vn1[j] = (k + 1 < m) ? phgmg_normf(m - k - 1, 1, aj + k + 1, m) : 0.0;
          vn2[j] = vn1[j];
        } else {
          vn1[j] *= sqrt(temp);
        }
      }
    }
  }
  *rank = k;
}

/* Blocked QR with column pivoting (LAPACK dlaqps scheme): nb reflectors at a
   time with deferred trailing updates A -= V F^T through gemm. Stops early like
   phgmg__qrcp_core. F: n x nb (ld n), aux: nb doubles, mark: n ints. */
#define PHGMG__QRCP_NB 32
PHGMG__PRIV void phgmg__qrcp_blocked(int m, int n, double *A, int lda, double *tau, int *jpvt,
                                     double *vn, double *F, double *aux, int *mark, double tol,
                                     int *rank) {
  double *vn1 = vn, *vn2 = vn + n;
  const double tol3z = sqrt(PHGMG__EPS);
  const int ldf = PHGMG__MAX(n, 1);
  int i, j, q, s = 0, kmin = PHGMG__MIN(m, n), stop = 0;
  for (j = 0; j < n; ++j) {
    jpvt[j] = j;
    mark[j] = 0;
    vn1[j] = vn2[j] = phgmg_normf(m, 1, A + (size_t)j * (size_t)lda, lda);
  }
  while (s < kmin && !stop) {
    int nb = PHGMG__MIN(PHGMG__QRCP_NB, kmin - s), kk = 0, any_mark = 0;
    /* F rows are indexed by (global column - s) */
    while (kk < nb && !any_mark) {
      int c = s + kk, p = c + phgmg__iamax(n - c, vn1 + c);
      double *ac = A + (size_t)c * (size_t)lda, akk;
      if (tol >= 0.0 && vn1[p] <= tol) { stop = 1; break; }
      if (p != c) {
        double *ap = A + (size_t)p * (size_t)lda, t;
        int it;
        for (i = 0; i < m; ++i) { t = ac[i]; ac[i] = ap[i]; ap[i] = t; }
        for (q = 0; q < kk; ++q) {
          double *fq = F + (size_t)q * (size_t)ldf;
          t = fq[c - s]; fq[c - s] = fq[p - s]; fq[p - s] = t;
        }
        it = jpvt[p]; jpvt[p] = jpvt[c]; jpvt[c] = it;
        vn1[p] = vn1[c];
        vn2[p] = vn2[c];
      }
      /* pending updates of column c: A(c:m, c) -= A(c:m, s:c) F(c-s, 0:kk)^T */
      for (q = 0; q < kk; ++q) {
        const double *v = A + (size_t)(s + q) * (size_t)lda;
        double f = F[(c - s) + (size_t)q * (size_t)ldf];
        if (f != 0.0) phgmg__axpy(m - c, -f, v + c, ac + c);
      }
      phgmg__larfg(m - c, ac + c, ac + c + 1, &tau[c]);
      akk = ac[c];
      ac[c] = 1.0;
      /* F(c+1-s : n-s, kk) = tau A(c:m, c+1:n)^T v  (stale trailing columns) */
      if (c + 1 < n)
        phgmg_gemv('T', m - c, n - c - 1, tau[c], A + c + (size_t)(c + 1) * (size_t)lda, lda,
                   ac + c, 0.0, F + (c + 1 - s) + (size_t)kk * (size_t)ldf);
      for (j = 0; j <= c - s; ++j) F[j + (size_t)kk * (size_t)ldf] = 0.0;
      /* F(:, kk) -= tau F(:, 0:kk) (A(c:m, s:c)^T v) */
      if (kk > 0) {
        phgmg_gemv('T', m - c, kk, -tau[c], A + c + (size_t)s * (size_t)lda, lda, ac + c, 0.0, aux);
        phgmg_gemv('N', n - s, kk, 1.0, F, ldf, aux, 1.0, F + (size_t)kk * (size_t)ldf);
      }
      /* row c of the trailing matrix: A(c, c+1:n) -= A(c, s:c+1) F(c+1-s:n-s, 0:kk+1)^T */
      for (j = c + 1; j < n; ++j) {
        double t = 0.0;
        for (q = 0; q <= kk; ++q)
          t += A[c + (size_t)(s + q) * (size_t)lda] * F[(j - s) + (size_t)q * (size_t)ldf];
        A[c + (size_t)j * (size_t)lda] -= t;
      }
      /* downdate the partial column norms; a column whose norm cancelled too much
         is marked for recomputation, which ends the block */
      if (c + 1 < m) {
        for (j = c + 1; j < n; ++j) {
          if (vn1[j] != 0.0) {
            double temp = fabs(A[c + (size_t)j * (size_t)lda]) / vn1[j], temp2;
            temp = (1.0 + temp) * (1.0 - temp);
            if (temp < 0.0) temp = 0.0;
            temp2 = temp * (vn1[j] / vn2[j]) * (vn1[j] / vn2[j]);
            if (temp2 <= tol3z) { mark[j] = 1; any_mark = 1; }
            else vn1[j] *= sqrt(temp);
          }
        }
      } else {
        for (j = c + 1; j < n; ++j) vn1[j] = vn2[j] = 0.0;
      }
      ac[c] = akk;
      ++kk;
    }
    if (stop) { s += kk; break; }
    /* trailing update A(s+kk:m, s+kk:n) -= A(s+kk:m, s:s+kk) F(kk:n-s, 0:kk)^T */
    if (s + kk < m && s + kk < n)
      phgmg_gemm('N', 'T', m - s - kk, n - s - kk, kk, -1.0, A + (s + kk) + (size_t)s * (size_t)lda,
                 lda, F + kk, ldf, 1.0, A + (s + kk) + (size_t)(s + kk) * (size_t)lda, lda);
    s += kk;
    if (any_mark)
      for (j = s; j < n; ++j)
        if (mark[j]) {
          vn1[j] = vn2[j] = (s < m) ? phgmg_normf(m - s, 1, A + s + (size_t)j * (size_t)lda, m - s) : 0.0;
          mark[j] = 0;
        }
  }
  *rank = s;
}

PHGMG_DEF phgmg_result phgmg_qrcp(int m, int n, double *A, int lda, double *tau, int *jpvt,
                                  double *work) {
  int r;
  if (m < 0 || n < 0 || lda < PHGMG__MAX(m, 1)) return PHGMG_ERR_SIZE;
  if (n == 0) return PHGMG_OK;
  if (!A || !jpvt || !work || (m > 0 && !tau)) return PHGMG_ERR_INVALID_ARG;
  if (!phgmg__mat_finite(m, n, A, lda)) return PHGMG_ERR_NANINF;
  phgmg__qrcp_core(m, n, A, lda, tau, jpvt, work, -1.0, &r);
  return PHGMG_OK;
}

PHGMG_DEF void phgmg_qr_form_q(int m, int k, double *A, int lda, const double *tau, double *work) {
  int i, j;
  (void)work;
  for (i = k - 1; i >= 0; --i) {
    double *ai = A + (size_t)i * (size_t)lda;
    if (i + 1 < k) {
      ai[i] = 1.0;
      phgmg__larf_left(m - i, k - i - 1, ai + i, tau[i], ai + i + lda, lda);
    }
    for (j = i + 1; j < m; ++j) ai[j] *= -tau[i];
    ai[i] = 1.0 - tau[i];
    for (j = 0; j < i; ++j) ai[j] = 0.0;
  }
}

PHGMG_DEF void phgmg_qr_apply(char trans, int m, int n, int k, const double *A, int lda,
                              const double *tau, double *C, int ldc) {
  int i;
  int tr = (trans == 'T' || trans == 't');
  PHGMG_ASSERT(tr || trans == 'N' || trans == 'n');
  if (tr) {
    for (i = 0; i < k; ++i)
      phgmg__larf_left(m - i, n, A + i + (size_t)i * (size_t)lda, tau[i], C + i, ldc);
  } else {
    for (i = k - 1; i >= 0; --i)
      phgmg__larf_left(m - i, n, A + i + (size_t)i * (size_t)lda, tau[i], C + i, ldc);
  }
}

/* Solve R X = B, R n x n upper triangular (ldr), B n x nrhs (ldb), in place. */
PHGMG__PRIV void phgmg__trsv_upper(int n, const double *R, int ldr, int nrhs, double *B, int ldb) {
  int j, k;
  for (j = 0; j < nrhs; ++j) {
    double *b = B + (size_t)j * (size_t)ldb;
    for (k = n - 1; k >= 0; --k) {
      const double *r = R + (size_t)k * (size_t)ldr;
      double t = b[k] / r[k];
      b[k] = t;
      if (t != 0.0) phgmg__axpy(k, -t, r, b);
    }
  }
}

PHGMG_DEF phgmg_result phgmg_lstsq(int m, int n, int nrhs, const double *A, int lda,
                                   const double *B, int ldb, double lambda,
                                   double *X, int ldx, const phgmg_allocator *alloc) {
  int mm, i, j;
  double *W, *tau, *C, anorm;
  if (m < 0 || n < 0 || nrhs < 0 || lda < PHGMG__MAX(m, 1) || ldb < PHGMG__MAX(m, 1) ||
      ldx < PHGMG__MAX(n, 1))
    return PHGMG_ERR_SIZE;
  if (!(lambda >= 0.0)) return lambda != lambda ? PHGMG_ERR_NANINF : PHGMG_ERR_INVALID_ARG;
  if (lambda == HUGE_VAL) return PHGMG_ERR_NANINF;
  if (lambda == 0.0 && m < n) return PHGMG_ERR_RANK;
  if (n == 0 || nrhs == 0) return PHGMG_OK;
  if (!A || !B || !X) return PHGMG_ERR_INVALID_ARG;
  if (!phgmg__mat_finite(m, n, A, lda) || !phgmg__mat_finite(m, nrhs, B, ldb))
    return PHGMG_ERR_NANINF;
  mm = lambda > 0.0 ? m + n : m;
  W = phgmg__dalloc(alloc, (size_t)mm * (size_t)(n + nrhs) + (size_t)n);
  if (!W) return PHGMG_ERR_NOMEM;
  C = W + (size_t)mm * (size_t)n;
  tau = C + (size_t)mm * (size_t)nrhs;
  /* W = [A; sqrt(lambda) I], C = [B; 0] */
  for (j = 0; j < n; ++j) {
    double *w = W + (size_t)j * (size_t)mm;
    memcpy(w, A + (size_t)j * (size_t)lda, (size_t)m * sizeof(double));
    if (mm > m) {
      for (i = m; i < mm; ++i) w[i] = 0.0;
      w[m + j] = sqrt(lambda);
    }
  }
  for (j = 0; j < nrhs; ++j) {
    double *c = C + (size_t)j * (size_t)mm;
    memcpy(c, B + (size_t)j * (size_t)ldb, (size_t)m * sizeof(double));
    for (i = m; i < mm; ++i) c[i] = 0.0;
  }
  anorm = phgmg_normf(mm, n, W, mm);
  phgmg_qr(mm, n, W, mm, tau);
  for (j = 0; j < n; ++j) {
    double d = fabs(W[j + (size_t)j * (size_t)mm]);
    if (d <= (double)PHGMG__MAX(mm, n) * PHGMG__EPS * anorm || d == 0.0) {
      phgmg__free(alloc, W);
      return PHGMG_ERR_RANK;
    }
  }
  phgmg_qr_apply('T', mm, nrhs, n, W, mm, tau, C, mm);
  phgmg__trsv_upper(n, W, mm, nrhs, C, mm);
  for (j = 0; j < nrhs; ++j)
    memcpy(X + (size_t)j * (size_t)ldx, C + (size_t)j * (size_t)mm, (size_t)n * sizeof(double));
  phgmg__free(alloc, W);
  return PHGMG_OK;
}

/* ---- thin SVD: QRCP + second QR + one-sided Jacobi ----------------------------- */
/* One-sided (Hestenes) Jacobi on the columns of X (r x r, ldx): X V = W diag(sigma).
   V (r x r, ldv; may be NULL) accumulates the rotations. On return X holds
   W diag(sigma). Pairs are visited block by block (a cyclic ordering) so that
   2*PHGMG__JAC_BS columns stay in cache. d: r doubles. */
#define PHGMG__JAC_BS 16
PHGMG__PRIV phgmg_result phgmg__jacobi_1s(int r, double *X, int ldx, double *V, int ldv,
                                          double *d) {
  const double tol = PHGMG__EPS * sqrt((double)PHGMG__MAX(r, 1));
  int sweep, p, q, ib, jb, rotated;
  for (sweep = 0; sweep < 80; ++sweep) {
    for (p = 0; p < r; ++p) {
      const double *xp = X + (size_t)p * (size_t)ldx;
      d[p] = phgmg__dot(r, xp, xp);
    }
    rotated = 0;
    for (ib = 0; ib < r; ib += PHGMG__JAC_BS)
      for (jb = ib; jb < r; jb += PHGMG__JAC_BS)
        for (p = ib; p < PHGMG__MIN(ib + PHGMG__JAC_BS, r); ++p) {
          double *xp = X + (size_t)p * (size_t)ldx;
          for (q = PHGMG__MAX(jb, p + 1); q < PHGMG__MIN(jb + PHGMG__JAC_BS, r); ++q) {
            double *xq = X + (size_t)q * (size_t)ldx;
            double alpha = d[p], beta = d[q], gamma, zeta, t, c, s;
            if (alpha == 0.0 || beta == 0.0) continue;
            gamma = phgmg__dot(r, xp, xq);
            if (fabs(gamma) <= tol * sqrt(alpha) * sqrt(beta)) continue;
            rotated = 1;
            zeta = (beta - alpha) / (2.0 * gamma);
            t = (zeta >= 0.0 ? 1.0 : -1.0) / (fabs(zeta) + sqrt(1.0 + zeta * zeta));
            c = 1.0 / sqrt(1.0 + t * t);
            s = c * t;
            phgmg__rot(r, xp, xq, c, s);
            if (V) phgmg__rot(r, V + (size_t)p * (size_t)ldv, V + (size_t)q * (size_t)ldv, c, s);
            d[p] = alpha - t * gamma;
            d[q] = beta + t * gamma;
            if (!(d[p] >= 0.0)) d[p] = 0.0;
          }
        }
    if (!rotated) return PHGMG_OK;
  }
  return PHGMG_ERR_NOT_CONVERGED;
}

PHGMG_DEF phgmg_result phgmg_svd(int m, int n, const double *A, int lda, int kmax,
                                 double *S, double *U, int ldu, double *V, int ldv,
                                 int *k_out, int *rank_out, const phgmg_allocator *alloc) {
  double *W = NULL, *tau, *vn, *Rt, *tau2, *X, *Vj, *d, anorm;
  int *jpvt = NULL, *perm;
  int r, rnz, k, i, j, kmin = PHGMG__MIN(m, n);
  phgmg_result rc;
  size_t nw;
  if (m < 0 || n < 0 || kmax < 0 || lda < PHGMG__MAX(m, 1)) return PHGMG_ERR_SIZE;
  if (kmax > 0 && (ldu < PHGMG__MAX(m, 1) || (V && ldv < PHGMG__MAX(n, 1)))) return PHGMG_ERR_SIZE;
  if (!k_out || (kmin > 0 && !A) || (kmax > 0 && (!S || !U))) return PHGMG_ERR_INVALID_ARG;
  if (kmin == 0) {
    *k_out = 0;
    if (rank_out) *rank_out = 0;
    return PHGMG_OK;
  }
  if (!phgmg__mat_finite(m, n, A, lda)) return PHGMG_ERR_NANINF;
  /* workspace: W (m x n), tau (kmin), vn (2n), F (n x nb), aux (nb);
     ints: jpvt (n), perm (kmin), mark (n) */
  nw = (size_t)m * (size_t)n + (size_t)kmin + 2 * (size_t)n +
       (size_t)(n + 1) * PHGMG__QRCP_NB;
  W = phgmg__dalloc(alloc, nw);
  jpvt = phgmg__ialloc(alloc, 2 * (size_t)n + (size_t)kmin);
  if (!W || !jpvt) { phgmg__free(alloc, W); phgmg__free(alloc, jpvt); return PHGMG_ERR_NOMEM; }
  perm = jpvt + n;
  tau = W + (size_t)m * (size_t)n;
  vn = tau + kmin;
  for (j = 0; j < n; ++j)
    memcpy(W + (size_t)j * (size_t)m, A + (size_t)j * (size_t)lda, (size_t)m * sizeof(double));
  anorm = phgmg_normf(m, n, W, m);
  phgmg__qrcp_blocked(m, n, W, m, tau, jpvt, vn, vn + 2 * n, vn + 2 * n + (size_t)n * PHGMG__QRCP_NB,
                      perm + kmin, PHGMG__EPS * anorm, &r);
  if (r == 0) {
    *k_out = 0;
    if (rank_out) *rank_out = 0;
    phgmg__free(alloc, W);
    phgmg__free(alloc, jpvt);
    return PHGMG_OK;
  }
  {
    /* second workspace: Rt (n x r), tau2 (r), X (r x r), Vj (r x r), d (r) */
    double *W2 = phgmg__dalloc(alloc, (size_t)n * (size_t)r + 2 * (size_t)r * (size_t)r +
                                          2 * (size_t)r);
    if (!W2) { phgmg__free(alloc, W); phgmg__free(alloc, jpvt); return PHGMG_ERR_NOMEM; }
    Rt = W2;
    tau2 = Rt + (size_t)n * (size_t)r;
    X = tau2 + r;
    Vj = X + (size_t)r * (size_t)r;
    d = Vj + (size_t)r * (size_t)r;
    /* Rt = R^T, R = W(0:r, 0:n) upper trapezoidal */
    for (i = 0; i < r; ++i) {
      double *rt = Rt + (size_t)i * (size_t)n;
      for (j = 0; j < i; ++j) rt[j] = 0.0;
      for (j = i; j < n; ++j) rt[j] = W[i + (size_t)j * (size_t)m];
    }
    phgmg_qr(n, r, Rt, n, tau2);
    /* X = R2^T (lower triangular), Vj = I */
    for (j = 0; j < r; ++j) {
      double *x = X + (size_t)j * (size_t)r, *v = Vj + (size_t)j * (size_t)r;
      for (i = 0; i < r; ++i) {
        x[i] = i >= j ? Rt[j + (size_t)i * (size_t)n] : 0.0;
        v[i] = i == j ? 1.0 : 0.0;
      }
    }
    rc = phgmg__jacobi_1s(r, X, r, V ? Vj : NULL, r, d);
    if (rc == PHGMG_OK) {
      /* sigma_j = ||X(:,j)||, order descending */
      for (j = 0; j < r; ++j) {
        d[j] = phgmg_normf(r, 1, X + (size_t)j * (size_t)r, r);
        perm[j] = j;
      }
      for (i = 1; i < r; ++i) { /* insertion sort, r is small */
        int pj = perm[i];
        for (j = i - 1; j >= 0 && d[perm[j]] < d[pj]; --j) perm[j + 1] = perm[j];
        perm[j + 1] = pj;
      }
      rnz = r; /* an exactly zero singular value has no singular vector: drop it */
      while (rnz > 0 && !(d[perm[rnz - 1]] > 0.0)) --rnz;
      k = PHGMG__MIN(kmax, rnz);
      for (j = 0; j < k; ++j) {
        int c = perm[j];
        double s = d[c], *u = U + (size_t)j * (size_t)ldu;
        const double *x = X + (size_t)c * (size_t)r;
        S[j] = s;
        for (i = 0; i < r; ++i) u[i] = x[i] / s;
        for (i = r; i < m; ++i) u[i] = 0.0;
      }
      /* U = Q [W; 0] with the r reflectors of the pivoted QR */
      if (k > 0) phgmg_qr_apply('N', m, k, PHGMG__MIN(r, kmin), W, m, tau, U, ldu);
      if (V && k > 0) {
        /* V = P Q2 [Vj; 0]; Rt's reflectors give Q2 (n x r) */
        int r2 = PHGMG__MIN(n, r);
        for (j = 0; j < k; ++j) {
          double *v = V + (size_t)j * (size_t)ldv, *y = vn;
          const double *vj = Vj + (size_t)perm[j] * (size_t)r;
          for (i = 0; i < r; ++i) y[i] = vj[i];
          for (i = r; i < n; ++i) y[i] = 0.0;
          phgmg_qr_apply('N', n, 1, r2, Rt, n, tau2, y, n);
          for (i = 0; i < n; ++i) v[jpvt[i]] = y[i];
        }
      }
      *k_out = k;
      if (rank_out) *rank_out = rnz;
    }
    phgmg__free(alloc, W2);
  }
  phgmg__free(alloc, W);
  phgmg__free(alloc, jpvt);
  return rc;
}

/* ---- symmetric eigenproblem ------------------------------------------------------ */
/* Cyclic Jacobi (small n): A symmetric, destroyed; w unsorted; V (if not NULL)
   accumulates the rotations. */
PHGMG__PRIV phgmg_result phgmg__sym_jacobi(int n, double *A, int lda, double *w, double *V,
                                           int ldv) {
  int i, j, p, q, sweep, rotated = 1;
  double anorm = phgmg_normf(n, n, A, lda);
  if (V)
    for (j = 0; j < n; ++j)
      for (i = 0; i < n; ++i) V[i + (size_t)j * (size_t)ldv] = i == j ? 1.0 : 0.0;
  for (sweep = 0; sweep < 100 && rotated; ++sweep) {
    rotated = 0;
    for (p = 0; p < n - 1; ++p) {
      double *ap = A + (size_t)p * (size_t)lda;
      for (q = p + 1; q < n; ++q) {
        double *aq = A + (size_t)q * (size_t)lda;
        double apq = aq[p], app = ap[p], aqq = aq[q], theta, t, c, s;
        if (fabs(apq) <= PHGMG__EPS * sqrt(fabs(app)) * sqrt(fabs(aqq)) ||
            fabs(apq) <= PHGMG__EPS * PHGMG__EPS * anorm)
          continue;
        rotated = 1;
        theta = (aqq - app) / (2.0 * apq);
        t = (theta >= 0.0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(1.0 + theta * theta));
        c = 1.0 / sqrt(1.0 + t * t);
        s = c * t;
        phgmg__rot(n, ap, aq, c, s);
        ap[p] = app - t * apq;
        aq[q] = aqq + t * apq;
        ap[q] = aq[p] = 0.0;
        for (i = 0; i < n; ++i) { /* mirror the two columns into rows p, q */
          if (i == p || i == q) continue;
          A[p + (size_t)i * (size_t)lda] = ap[i];
          A[q + (size_t)i * (size_t)lda] = aq[i];
        }
        if (V) phgmg__rot(n, V + (size_t)p * (size_t)ldv, V + (size_t)q * (size_t)ldv, c, s);
      }
    }
  }
  if (rotated) return PHGMG_ERR_NOT_CONVERGED;
  for (i = 0; i < n; ++i) w[i] = A[i + (size_t)i * (size_t)lda];
  return PHGMG_OK;
}

/* Householder tridiagonalization and implicit QL with shifts (the EISPACK
   tred2/tql2 scheme, as in JAMA), in W (n x n, ldw): only the lower triangle
   of W is read. vec: W ends up holding the eigenvectors. d (n) receives the
   eigenvalues (unsorted), e (n) is workspace. Without vec, e may be column n-1
   of W itself (that column is then not needed). */
PHGMG__PRIV phgmg_result phgmg__sym_tridiag_ql(int n, double *W, int ldw, int vec, double *d,
                                               double *e) {
#define PHGMG__W(r, c) W[(size_t)(r) + (size_t)(c) * (size_t)ldw]
  int i, j, k, l, m;
  double f, g, h, tst1, dlast;
  for (j = 0; j < n; ++j) d[j] = PHGMG__W(n - 1, j);
  dlast = d[n - 1];
  for (i = n - 1; i > 0; --i) {
    double scale = 0.0;
    h = 0.0;
    for (k = 0; k < i; ++k) scale += fabs(d[k]);
    if (scale == 0.0) {
      e[i] = d[i - 1];
      for (j = 0; j < i; ++j) {
        d[j] = PHGMG__W(i - 1, j);
        PHGMG__W(i, j) = 0.0;
        if (vec) PHGMG__W(j, i) = 0.0;
      }
    } else {
      double hh;
      for (k = 0; k < i; ++k) { d[k] /= scale; h += d[k] * d[k]; }
      f = d[i - 1];
      g = sqrt(h);
      if (f > 0) g = -g;
      e[i] = scale * g;
      h -= f * g;
      d[i - 1] = f - g;
      for (j = 0; j < i; ++j) e[j] = 0.0;
      for (j = 0; j < i; ++j) {
        const double *wj = &PHGMG__W(0, j);
        f = d[j];
        if (vec) PHGMG__W(j, i) = f;
        g = e[j] + wj[j] * f + phgmg__dot(i - 1 - j, wj + j + 1, d + j + 1);
        phgmg__axpy(i - 1 - j, f, wj + j + 1, e + j + 1);
        e[j] = g;
      }
      f = 0.0;
      for (j = 0; j < i; ++j) { e[j] /= h; f += e[j] * d[j]; }
      hh = f / (h + h);
      for (j = 0; j < i; ++j) e[j] -= hh * d[j];
      for (j = 0; j < i; ++j) {
        double *wj = &PHGMG__W(0, j);
        f = d[j];
        g = e[j];
        phgmg__axpy(i - j, -f, e + j, wj + j);
        phgmg__axpy(i - j, -g, d + j, wj + j);
        d[j] = PHGMG__W(i - 1, j);
        PHGMG__W(i, j) = 0.0;
      }
    }
    d[i] = h;
  }
  if (vec) {
    /* accumulate the transformations */
    for (i = 0; i < n - 1; ++i) {
      PHGMG__W(n - 1, i) = PHGMG__W(i, i);
      PHGMG__W(i, i) = 1.0;
      h = d[i + 1];
      if (h != 0.0) {
        const double *wi1 = &PHGMG__W(0, i + 1);
        for (k = 0; k <= i; ++k) d[k] = wi1[k] / h;
        for (j = 0; j <= i; ++j) {
          double *wj = &PHGMG__W(0, j);
          g = phgmg__dot(i + 1, wi1, wj);
          phgmg__axpy(i + 1, -g, d, wj);
        }
      }
      for (k = 0; k <= i; ++k) PHGMG__W(k, i + 1) = 0.0;
    }
    for (j = 0; j < n; ++j) { d[j] = PHGMG__W(n - 1, j); PHGMG__W(n - 1, j) = 0.0; }
    PHGMG__W(n - 1, n - 1) = 1.0;
  } else {
    for (j = 0; j < n - 1; ++j) d[j] = PHGMG__W(j, j);
    d[n - 1] = dlast;
  }
  /* implicit QL on the tridiagonal (d, e) */
  for (i = 1; i < n; ++i) e[i - 1] = e[i];
  e[n - 1] = 0.0;
  f = 0.0;
  tst1 = 0.0;
  for (l = 0; l < n; ++l) {
    tst1 = PHGMG__MAX(tst1, fabs(d[l]) + fabs(e[l]));
    m = l;
    while (m < n - 1 && fabs(e[m]) > PHGMG__EPS * tst1) ++m;
    if (m > l) {
      int iter = 0;
      do {
        double p, r, dl1, c, c2, c3, el1, s, s2;
        if (++iter > 60) return PHGMG_ERR_NOT_CONVERGED;
        g = d[l];
        p = (d[l + 1] - g) / (2.0 * e[l]);
        r = hypot(p, 1.0);
        if (p < 0) r = -r;
        d[l] = e[l] / (p + r);
        d[l + 1] = e[l] * (p + r);
        dl1 = d[l + 1];
        h = g - d[l];
        for (i = l + 2; i < n; ++i) d[i] -= h;
        f += h;
        p = d[m];
        c = c2 = c3 = 1.0;
        el1 = e[l + 1];
        s = s2 = 0.0;
        for (i = m - 1; i >= l; --i) {
          c3 = c2;
          c2 = c;
          s2 = s;
          g = c * e[i];
          h = c * p;
          r = hypot(p, e[i]);
          e[i + 1] = s * r;
          s = e[i] / r;
          c = p / r;
          p = c * d[i] - s * g;
          d[i + 1] = h + s * (c * g + s * d[i]);
          if (vec) phgmg__rot(n, &PHGMG__W(0, i), &PHGMG__W(0, i + 1), c, s);
        }
        p = -s * s2 * c3 * el1 * e[l] / dl1;
        e[l] = s * p;
        d[l] = c * p;
      } while (fabs(e[l]) > PHGMG__EPS * tst1);
    }
    d[l] += f;
    e[l] = 0.0;
  }
  return PHGMG_OK;
#undef PHGMG__W
}

#define PHGMG__SYM_JACOBI_MAX 24
PHGMG_DEF phgmg_result phgmg_sym_eig(int n, double *A, int lda, double *w, double *V, int ldv) {
  int i, j;
  phgmg_result rc;
  if (n < 0 || lda < PHGMG__MAX(n, 1) || (V && ldv < PHGMG__MAX(n, 1))) return PHGMG_ERR_SIZE;
  if (n == 0) return PHGMG_OK;
  if (!A || !w) return PHGMG_ERR_INVALID_ARG;
  if (!phgmg__mat_finite(n, n, A, lda)) return PHGMG_ERR_NANINF;
  /* symmetrize: A := (A + A^T)/2 */
  for (j = 0; j < n; ++j)
    for (i = j + 1; i < n; ++i) {
      double *aij = A + i + (size_t)j * (size_t)lda, *aji = A + j + (size_t)i * (size_t)lda;
      double s = 0.5 * (*aij + *aji);
      *aij = *aji = s;
    }
  if (n <= PHGMG__SYM_JACOBI_MAX) {
    rc = phgmg__sym_jacobi(n, A, lda, w, V, ldv);
  } else if (V) {
    for (j = 0; j < n; ++j)
      memcpy(V + (size_t)j * (size_t)ldv, A + (size_t)j * (size_t)lda, (size_t)n * sizeof(double));
    rc = phgmg__sym_tridiag_ql(n, V, ldv, 1, w, A);
  } else {
    rc = phgmg__sym_tridiag_ql(n, A, lda, 0, w, A + (size_t)(n - 1) * (size_t)lda);
  }
  if (rc != PHGMG_OK) return rc;
  /* selection sort ascending, swapping eigenvector columns */
  for (i = 0; i < n - 1; ++i) {
    int kmin = i;
    for (j = i + 1; j < n; ++j)
      if (w[j] < w[kmin]) kmin = j;
    if (kmin != i) {
      double t = w[i];
      w[i] = w[kmin]; w[kmin] = t;
      if (V) {
        double *vi = V + (size_t)i * (size_t)ldv, *vk = V + (size_t)kmin * (size_t)ldv;
        for (j = 0; j < n; ++j) { t = vi[j]; vi[j] = vk[j]; vk[j] = t; }
      }
    }
  }
  return PHGMG_OK;
}

#endif /* PHGMG_NO_OFFLINE */
