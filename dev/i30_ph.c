
/* >>ph (implementation) ================================================== */
#ifndef PHGMG_NO_OFFLINE

/* a*b + c, fused where the target has a fast fma (the hot loops of the
   stepper); plain otherwise (ISO C modes do not contract a*b + c). */
#if defined(FP_FAST_FMA)
#define PHGMG__FMA(a, b, c) fma((a), (b), (c))
#else
#define PHGMG__FMA(a, b, c) ((a) * (b) + (c))
#endif

/* Index of element (i,j), |i-j| <= kb, in the (2kb+1) x N band storage. */
#define PHGMG__PHB(kb, i, j) \
  ((size_t)((kb) + (i) - (j)) + (size_t)(j) * (size_t)(2 * (kb) + 1))

/* Above this N a banded, non-diagonal R is checked for semidefiniteness by a
   shifted band Cholesky instead of a dense eigenvalue computation. */
#define PHGMG__PH_PSD_DENSE_MAX 2000

/* Element (i,j) of J, R or Q (0 outside the band). */
PHGMG__PRIV double phgmg__ph_at(const phgmg_ph_system *s, const double *M, int i, int j) {
  if (s->storage == PHGMG_BANDED) {
    int d = i - j;
    if (d > s->kb || d < -s->kb) return 0.0;
    return M[PHGMG__PHB(s->kb, i, j)];
  }
  return M[(size_t)i + (size_t)j * (size_t)s->N];
}

/* y = M x (overwrite) for a dense or banded system matrix. */
PHGMG__PRIV void phgmg__ph_mv(const phgmg_ph_system *s, const double *M, const double *x,
                              double *y) {
  int N = s->N, i, j;
  for (i = 0; i < N; ++i) y[i] = 0.0;
  if (s->storage == PHGMG_BANDED) {
    int kb = s->kb;
    for (j = 0; j < N; ++j) {
      double xj = x[j];
      int i0 = PHGMG__MAX(0, j - kb), i1 = PHGMG__MIN(N - 1, j + kb);
      const double *col = M + PHGMG__PHB(kb, 0, j);
      if (xj == 0.0) continue;
      for (i = i0; i <= i1; ++i) y[i] += col[i] * xj;
    }
  } else {
    for (j = 0; j < N; ++j) {
      const double *col = M + (size_t)j * (size_t)N;
      double xj = x[j];
      if (xj == 0.0) continue;
      for (i = 0; i < N; ++i) y[i] += col[i] * xj;
    }
  }
}

/* x^T M y without temporaries. */
PHGMG__PRIV double phgmg__ph_quad(const phgmg_ph_system *s, const double *M, const double *x,
                                  const double *y) {
  int N = s->N, i, j;
  double acc = 0.0;
  for (j = 0; j < N; ++j) {
    double t = 0.0;
    if (s->storage == PHGMG_BANDED) {
      int kb = s->kb, i0 = PHGMG__MAX(0, j - kb), i1 = PHGMG__MIN(N - 1, j + kb);
      const double *col = M + PHGMG__PHB(kb, 0, j);
      for (i = i0; i <= i1; ++i) t += x[i] * col[i];
    } else {
      const double *col = M + (size_t)j * (size_t)N;
      for (i = 0; i < N; ++i) t += x[i] * col[i];
    }
    acc += t * y[j];
  }
  return acc;
}

/* d-th derivative (d = 0,1,2) of the scalar nonlinearity of term k at v. */
PHGMG__PRIV double phgmg__ph_phi(const phgmg_ph_system *s, int k, double v, int d) {
  if (s->poly_deg > 0) {
    int j;
    double acc = 0.0;
    for (j = s->poly_deg; j >= d; --j) {
      double c = s->poly[j];
      if (d == 1) c *= (double)j;
      else if (d == 2) c *= (double)j * (double)(j - 1);
      acc = acc * v + c;
    }
    return acc;
  }
  if (d == 0) return s->phi(k, v, s->user);
  if (d == 1) return s->dphi(k, v, s->user);
  return s->ddphi(k, v, s->user);
}

/* Structural checks shared by every entry point (no O(N^2) work). */
PHGMG__PRIV phgmg_result phgmg__ph_check(const phgmg_ph_system *s) {
  int k;
  if (!s) return PHGMG_ERR_INVALID_ARG;
  if (s->N <= 0 || s->m <= 0 || s->m > s->N) return PHGMG_ERR_SIZE;
  if (s->storage != PHGMG_DENSE && s->storage != PHGMG_BANDED) return PHGMG_ERR_INVALID_ARG;
  if (s->storage == PHGMG_BANDED && (s->kb < 0 || s->kb > s->N - 1)) return PHGMG_ERR_SIZE;
  if (!s->J || !s->R || !s->Q || !s->B) return PHGMG_ERR_INVALID_ARG;
  if ((s->shifted_factor == NULL) != (s->shifted_solve == NULL)) return PHGMG_ERR_INVALID_ARG;
  switch (s->nl) {
    case PHGMG_NL_NONE: break;
    case PHGMG_NL_SEPARABLE:
      if (s->nsep < 0 || s->poly_deg < 0) return PHGMG_ERR_SIZE;
      if (s->nsep > 0 && !s->sep_idx) return PHGMG_ERR_INVALID_ARG;
      for (k = 0; k < s->nsep; ++k)
        if (s->sep_idx[k] < 0 || s->sep_idx[k] >= s->N) return PHGMG_ERR_SIZE;
      if (s->poly_deg > 0) {
        if (!s->poly) return PHGMG_ERR_INVALID_ARG;
      } else if (s->nsep > 0 && (!s->phi || !s->dphi || !s->ddphi)) {
        return PHGMG_ERR_INVALID_ARG;
      }
      break;
    case PHGMG_NL_GENERAL:
      if (!s->H_nl || !s->grad_nl || !s->hess_nl) return PHGMG_ERR_INVALID_ARG;
      break;
    default: return PHGMG_ERR_INVALID_ARG;
  }
  return PHGMG_OK;
}

/* Finiteness of the valid entries of a dense or banded system matrix. */
PHGMG__PRIV int phgmg__ph_mat_finite(const phgmg_ph_system *s, const double *M) {
  int N = s->N, j;
  if (s->storage == PHGMG_DENSE) return phgmg__all_finite(M, (size_t)N * (size_t)N);
  for (j = 0; j < N; ++j) {
    int i0 = PHGMG__MAX(0, j - s->kb), i1 = PHGMG__MIN(N - 1, j + s->kb);
    if (!phgmg__all_finite(M + PHGMG__PHB(s->kb, i0, j), (size_t)(i1 - i0 + 1))) return 0;
  }
  return 1;
}

/* g = Q x + grad H_nl(x); tmp (N doubles) is needed for GENERAL only. */
PHGMG__PRIV void phgmg__ph_grad(const phgmg_ph_system *s, const double *x, double *g,
                                double *tmp) {
  int k, i;
  phgmg__ph_mv(s, s->Q, x, g);
  if (s->nl == PHGMG_NL_SEPARABLE) {
    for (k = 0; k < s->nsep; ++k) {
      int ix = s->sep_idx[k];
      double w = s->sep_w ? s->sep_w[k] : 1.0;
      g[ix] += w * phgmg__ph_phi(s, k, x[ix], 1);
    }
  } else if (s->nl == PHGMG_NL_GENERAL) {
    s->grad_nl(x, tmp, s->user);
    for (i = 0; i < s->N; ++i) g[i] += tmp[i];
  }
}

/* A scratch vector of N doubles for the allocation-free public evaluators:
   the stack for small N, the default allocator otherwise (NULL on failure). */
#define PHGMG__PH_STACK 256
PHGMG__PRIV double *phgmg__ph_scratch(int n, double *stackbuf) {
  if (n <= PHGMG__PH_STACK) return stackbuf;
  return phgmg__dalloc(NULL, (size_t)n);
}
PHGMG__PRIV void phgmg__ph_scratch_free(double *p, double *stackbuf) {
  if (p != stackbuf) phgmg__free(NULL, p);
}

PHGMG_DEF double phgmg_ph_hamiltonian(const phgmg_ph_system *sys, const double *x) {
  double H;
  int k;
  PHGMG_ASSERT(sys && x);
  H = 0.5 * phgmg__ph_quad(sys, sys->Q, x, x);
  if (sys->nl == PHGMG_NL_SEPARABLE) {
    for (k = 0; k < sys->nsep; ++k)
      H += (sys->sep_w ? sys->sep_w[k] : 1.0) * phgmg__ph_phi(sys, k, x[sys->sep_idx[k]], 0);
  } else if (sys->nl == PHGMG_NL_GENERAL) {
    H += sys->H_nl(x, sys->user);
  }
  return H;
}

PHGMG_DEF void phgmg_ph_gradient(const phgmg_ph_system *sys, const double *x, double *g) {
  PHGMG_ASSERT(sys && x && g);
  if (sys->nl == PHGMG_NL_GENERAL) {
    double sb[PHGMG__PH_STACK], *tmp = phgmg__ph_scratch(sys->N, sb);
    int i;
    if (!tmp) { for (i = 0; i < sys->N; ++i) g[i] = (double)NAN; return; }
    phgmg__ph_grad(sys, x, g, tmp);
    phgmg__ph_scratch_free(tmp, sb);
  } else {
    phgmg__ph_grad(sys, x, g, NULL);
  }
}

/* Public evaluators that need a gradient scratch vector take it from the stack
   (N <= 256) or the default allocator; if that fails the result is NaN. */
PHGMG_DEF void phgmg_ph_rhs(const phgmg_ph_system *sys, const double *x, const double *u,
                            double *f) {
  double sb[PHGMG__PH_STACK], *g;
  double *tmp = NULL;
  int N, i, j;
  PHGMG_ASSERT(sys && x && f);
  N = sys->N;
  g = phgmg__ph_scratch(N, sb);
  if (g && sys->nl == PHGMG_NL_GENERAL) {
    tmp = phgmg__dalloc(NULL, (size_t)N);
    if (!tmp) { phgmg__ph_scratch_free(g, sb); g = NULL; }
  }
  if (!g) { for (i = 0; i < N; ++i) f[i] = (double)NAN; return; }
  phgmg__ph_grad(sys, x, g, tmp);
  phgmg__ph_mv(sys, sys->J, g, f);
  /* f -= R g, column by column (no second scratch vector) */
  for (j = 0; j < N; ++j) {
    double gj = g[j];
    if (gj == 0.0) continue;
    if (sys->storage == PHGMG_BANDED) {
      int kb = sys->kb, i0 = PHGMG__MAX(0, j - kb), i1 = PHGMG__MIN(N - 1, j + kb);
      const double *col = sys->R + PHGMG__PHB(kb, 0, j);
      for (i = i0; i <= i1; ++i) f[i] -= col[i] * gj;
    } else {
      const double *col = sys->R + (size_t)j * (size_t)N;
      for (i = 0; i < N; ++i) f[i] -= col[i] * gj;
    }
  }
  if (u)
    for (j = 0; j < sys->m; ++j) {
      const double *bj = sys->B + (size_t)j * (size_t)N;
      for (i = 0; i < N; ++i) f[i] += bj[i] * u[j];
    }
  phgmg__free(NULL, tmp);
  phgmg__ph_scratch_free(g, sb);
}

PHGMG_DEF void phgmg_ph_output(const phgmg_ph_system *sys, const double *x, double *y) {
  double sb[PHGMG__PH_STACK], *g, *tmp = NULL;
  int N, i, j;
  PHGMG_ASSERT(sys && x && y);
  N = sys->N;
  g = phgmg__ph_scratch(N, sb);
  if (g && sys->nl == PHGMG_NL_GENERAL) {
    tmp = phgmg__dalloc(NULL, (size_t)N);
    if (!tmp) { phgmg__ph_scratch_free(g, sb); g = NULL; }
  }
  if (!g) { for (j = 0; j < sys->m; ++j) y[j] = (double)NAN; return; }
  phgmg__ph_grad(sys, x, g, tmp);
  for (j = 0; j < sys->m; ++j) {
    const double *bj = sys->B + (size_t)j * (size_t)N;
    double acc = 0.0;
    for (i = 0; i < N; ++i) acc += bj[i] * g[i];
    y[j] = acc;
  }
  phgmg__free(NULL, tmp);
  phgmg__ph_scratch_free(g, sb);
}

PHGMG_DEF void phgmg_ph_apply(const phgmg_ph_system *sys, char which, int nrhs,
                              const double *X, int ldx, double *Y, int ldy) {
  const double *M;
  int c;
  PHGMG_ASSERT(sys && X && Y && ldx >= sys->N && ldy >= sys->N);
  M = which == 'J' || which == 'j' ? sys->J : which == 'R' || which == 'r' ? sys->R : sys->Q;
  PHGMG_ASSERT(which == 'J' || which == 'j' || which == 'R' || which == 'r' || which == 'Q' ||
               which == 'q');
  if (sys->storage == PHGMG_DENSE) {
    phgmg_gemm('N', 'N', sys->N, nrhs, sys->N, 1.0, M, sys->N, X, ldx, 0.0, Y, ldy);
    return;
  }
  for (c = 0; c < nrhs; ++c)
    phgmg__ph_mv(sys, M, X + (size_t)c * (size_t)ldx, Y + (size_t)c * (size_t)ldy);
}

/* ---- banded LU with partial pivoting (LAPACK dgbtf2/dgbtrs layout) -------- */
/* ab is ldab x n, ldab >= 2kl+ku+1; A(i,j) sits at ab[(kl+ku+i-j) + j*ldab],
   the top kl rows are fill-in space and must be zero on entry. ipiv[j] = row
   swapped with j. *ue receives the actual upper bandwidth of U (<= kl+ku; ku
   when no row was swapped), dinv the reciprocals of U's diagonal. */
PHGMG__PRIV phgmg_result phgmg__gb_factor(int n, int kl, int ku, double *ab, int ldab, int *ipiv,
                                          double *dinv, int *ue) {
  int kv = kl + ku, j, ju = 0, uext = 0;
  for (j = 0; j < n; ++j) {
    int km = PHGMG__MIN(kl, n - 1 - j), jp = 0, p, c;
    double *colj = ab + (size_t)j * (size_t)ldab + kv; /* colj[p] = A(j+p, j) */
    double amax = fabs(colj[0]);
    for (p = 1; p <= km; ++p)
      if (fabs(colj[p]) > amax) { amax = fabs(colj[p]); jp = p; }
    ipiv[j] = j + jp;
    if (!(amax > 0.0)) return amax == 0.0 ? PHGMG_ERR_SINGULAR : PHGMG_ERR_NANINF;
    if (amax == HUGE_VAL) return PHGMG_ERR_NANINF;
    ju = PHGMG__MAX(ju, PHGMG__MIN(j + ku + jp, n - 1));
    if (ju - j > uext) uext = ju - j;
    if (jp != 0)
      for (c = j; c <= ju; ++c) {
        size_t a = (size_t)(kv + j - c) + (size_t)c * (size_t)ldab, b = a + (size_t)jp;
        double t = ab[a];
        ab[a] = ab[b];
        ab[b] = t;
      }
    dinv[j] = 1.0 / colj[0];
    if (km > 0) {
      double r = dinv[j];
      for (p = 1; p <= km; ++p) colj[p] *= r;
      for (c = j + 1; c <= ju; ++c) {
        double *colc = ab + (size_t)(kv + j - c) + (size_t)c * (size_t)ldab; /* A(j+p,c) */
        double t = colc[0];
        if (t != 0.0)
          for (p = 1; p <= km; ++p) colc[p] -= colj[p] * t;
      }
    }
  }
  *ue = uext;
  return PHGMG_OK;
}

/* Solve A x = b ('N') or A^T x = b ('T') with the band factors, b overwritten. */
PHGMG__PRIV void phgmg__gb_solve(char trans, int n, int kl, int ku, int ue, const double *ab,
                                 int ldab, const int *ipiv, const double *dinv, double *b) {
  int kv = kl + ku, j, p;
  if (trans == 'N' || trans == 'n') {
    for (j = 0; j < n; ++j) {
      int km = PHGMG__MIN(kl, n - 1 - j), jp = ipiv[j];
      const double *l = ab + (size_t)j * (size_t)ldab + kv;
      double t;
      if (jp != j) { t = b[j]; b[j] = b[jp]; b[jp] = t; }
      t = b[j];
      if (t != 0.0)
        for (p = 1; p <= km; ++p) b[j + p] -= l[p] * t;
    }
    for (j = n - 1; j >= 0; --j) {
      int i0 = PHGMG__MAX(0, j - ue), i;
      size_t base = (size_t)j * (size_t)ldab + (size_t)kv - (size_t)j; /* + i = U(i,j) */
      double t = b[j] * dinv[j];
      b[j] = t;
      if (t != 0.0)
        for (i = i0; i < j; ++i) b[i] -= ab[base + (size_t)i] * t;
    }
  } else {
    for (j = 0; j < n; ++j) {
      int i0 = PHGMG__MAX(0, j - ue), i;
      size_t base = (size_t)j * (size_t)ldab + (size_t)kv - (size_t)j;
      double t = b[j];
      for (i = i0; i < j; ++i) t -= ab[base + (size_t)i] * b[i];
      b[j] = t * dinv[j];
    }
    for (j = n - 2; j >= 0; --j) {
      int km = PHGMG__MIN(kl, n - 1 - j), jp = ipiv[j];
      const double *l = ab + (size_t)j * (size_t)ldab + kv;
      double t = b[j];
      for (p = 1; p <= km; ++p) t -= l[p] * b[j + p];
      b[j] = t;
      if (jp != j) { t = b[j]; b[j] = b[jp]; b[jp] = t; }
    }
  }
}

/* Complex (interleaved) versions: element r of column j at ab[2*(r + j*ldab)]. */
PHGMG__PRIV phgmg_result phgmg__zgb_factor(int n, int kl, int ku, double *ab, int ldab,
                                           int *ipiv, double *dinv, int *ue) {
  int kv = kl + ku, j, ju = 0, uext = 0;
  for (j = 0; j < n; ++j) {
    int km = PHGMG__MIN(kl, n - 1 - j), jp = 0, p, c;
    double *colj = ab + 2 * ((size_t)j * (size_t)ldab + (size_t)kv);
    double amax = fabs(colj[0]) + fabs(colj[1]), pr, pi, rr, ri;
    for (p = 1; p <= km; ++p) {
      double v = fabs(colj[2 * p]) + fabs(colj[2 * p + 1]);
      if (v > amax) { amax = v; jp = p; }
    }
    ipiv[j] = j + jp;
    if (!(amax > 0.0)) return amax == 0.0 ? PHGMG_ERR_SINGULAR : PHGMG_ERR_NANINF;
    if (amax == HUGE_VAL) return PHGMG_ERR_NANINF;
    ju = PHGMG__MAX(ju, PHGMG__MIN(j + ku + jp, n - 1));
    if (ju - j > uext) uext = ju - j;
    if (jp != 0)
      for (c = j; c <= ju; ++c) {
        size_t a = 2 * ((size_t)(kv + j - c) + (size_t)c * (size_t)ldab), b = a + 2 * (size_t)jp;
        double t = ab[a];
        ab[a] = ab[b]; ab[b] = t;
        t = ab[a + 1]; ab[a + 1] = ab[b + 1]; ab[b + 1] = t;
      }
    /* reciprocal of the pivot (Smith) */
    pr = colj[0]; pi = colj[1];
    if (fabs(pr) >= fabs(pi)) {
      double q = pi / pr, d = pr + pi * q;
      rr = 1.0 / d; ri = -q / d;
    } else {
      double q = pr / pi, d = pr * q + pi;
      rr = q / d; ri = -1.0 / d;
    }
    dinv[2 * j] = rr; dinv[2 * j + 1] = ri;
    if (km > 0) {
      for (p = 1; p <= km; ++p) {
        double xr = colj[2 * p], xi = colj[2 * p + 1];
        colj[2 * p] = xr * rr - xi * ri;
        colj[2 * p + 1] = xr * ri + xi * rr;
      }
      for (c = j + 1; c <= ju; ++c) {
        double *colc = ab + 2 * ((size_t)(kv + j - c) + (size_t)c * (size_t)ldab);
        double tr = colc[0], ti = colc[1];
        if (tr == 0.0 && ti == 0.0) continue;
        for (p = 1; p <= km; ++p) {
          double lr = colj[2 * p], li = colj[2 * p + 1];
          colc[2 * p] -= lr * tr - li * ti;
          colc[2 * p + 1] -= lr * ti + li * tr;
        }
      }
    }
  }
  *ue = uext;
  return PHGMG_OK;
}

PHGMG__PRIV void phgmg__zgb_solve(int n, int kl, int ku, int ue, const double *ab, int ldab,
                                  const int *ipiv, const double *dinv, double *b) {
  int kv = kl + ku, j, p;
  for (j = 0; j < n; ++j) {
    int km = PHGMG__MIN(kl, n - 1 - j), jp = ipiv[j];
    const double *l = ab + 2 * ((size_t)j * (size_t)ldab + (size_t)kv);
    double tr, ti;
    if (jp != j) {
      tr = b[2 * j]; b[2 * j] = b[2 * jp]; b[2 * jp] = tr;
      ti = b[2 * j + 1]; b[2 * j + 1] = b[2 * jp + 1]; b[2 * jp + 1] = ti;
    }
    tr = b[2 * j]; ti = b[2 * j + 1];
    if (tr == 0.0 && ti == 0.0) continue;
    for (p = 1; p <= km; ++p) {
      double lr = l[2 * p], li = l[2 * p + 1];
      b[2 * (j + p)] -= lr * tr - li * ti;
      b[2 * (j + p) + 1] -= lr * ti + li * tr;
    }
  }
  for (j = n - 1; j >= 0; --j) {
    int i0 = PHGMG__MAX(0, j - ue), i;
    size_t base = (size_t)j * (size_t)ldab + (size_t)kv - (size_t)j;
    double xr = b[2 * j], xi = b[2 * j + 1], rr = dinv[2 * j], ri = dinv[2 * j + 1];
    double tr = xr * rr - xi * ri, ti = xr * ri + xi * rr;
    b[2 * j] = tr; b[2 * j + 1] = ti;
    if (tr == 0.0 && ti == 0.0) continue;
    for (i = i0; i < j; ++i) {
      const double *u = ab + 2 * (base + (size_t)i);
      b[2 * i] -= u[0] * tr - u[1] * ti;
      b[2 * i + 1] -= u[0] * ti + u[1] * tr;
    }
  }
}

/* A band LU object (real), owned by the jr factor and the validator. */
typedef struct phgmg__gbf {
  int n, kl, ku, ldab, ue;
  double *ab, *dinv;
  int *ipiv;
} phgmg__gbf;

PHGMG__PRIV void phgmg__gbf_free(const phgmg_allocator *al, phgmg__gbf *f) {
  phgmg__free(al, f->ab);
  phgmg__free(al, f->dinv);
  phgmg__free(al, f->ipiv);
  f->ab = f->dinv = NULL;
  f->ipiv = NULL;
}

/* Factor J - R of a banded system (kl = ku = kb). */
PHGMG__PRIV phgmg_result phgmg__gbf_jr(const phgmg_allocator *al, const phgmg_ph_system *s,
                                       phgmg__gbf *f) {
  int N = s->N, kb = s->kb, i, j;
  f->n = N; f->kl = kb; f->ku = kb; f->ldab = 3 * kb + 1; f->ue = 0;
  f->ab = phgmg__dalloc(al, (size_t)f->ldab * (size_t)N);
  f->dinv = phgmg__dalloc(al, (size_t)N);
  f->ipiv = phgmg__ialloc(al, (size_t)N);
  if (!f->ab || !f->dinv || !f->ipiv) { phgmg__gbf_free(al, f); return PHGMG_ERR_NOMEM; }
  memset(f->ab, 0, sizeof(double) * (size_t)f->ldab * (size_t)N);
  for (j = 0; j < N; ++j)
    for (i = PHGMG__MAX(0, j - kb); i <= PHGMG__MIN(N - 1, j + kb); ++i) {
      size_t k = PHGMG__PHB(kb, i, j);
      f->ab[(size_t)(2 * kb + i - j) + (size_t)j * (size_t)f->ldab] = s->J[k] - s->R[k];
    }
  return phgmg__gb_factor(N, kb, kb, f->ab, f->ldab, f->ipiv, f->dinv, &f->ue);
}

PHGMG__PRIV void phgmg__gbf_solve(const phgmg__gbf *f, char trans, double *b) {
  phgmg__gb_solve(trans, f->n, f->kl, f->ku, f->ue, f->ab, f->ldab, f->ipiv, f->dinv, b);
}

/* Hager/Higham estimate of ||A^{-1}||_1 from band factors (LAPACK dlacn2 logic).
   work: 2n doubles, iwork: n ints. */
PHGMG__PRIV double phgmg__gbf_inv_norm1(const phgmg__gbf *f, double *work, int *isgn) {
  int n = f->n, i, j, jlast, iter, same;
  double *x = work, est, estold, temp;
  for (i = 0; i < n; ++i) x[i] = 1.0 / (double)n;
  phgmg__gbf_solve(f, 'N', x);
  if (n == 1) return fabs(x[0]);
  est = 0.0;
  for (i = 0; i < n; ++i) est += fabs(x[i]);
  for (i = 0; i < n; ++i) { isgn[i] = x[i] >= 0.0 ? 1 : -1; x[i] = (double)isgn[i]; }
  phgmg__gbf_solve(f, 'T', x);
  j = 0;
  for (i = 1; i < n; ++i) if (fabs(x[i]) > fabs(x[j])) j = i;
  for (iter = 2;; ++iter) {
    for (i = 0; i < n; ++i) x[i] = 0.0;
    x[j] = 1.0;
    phgmg__gbf_solve(f, 'N', x);
    estold = est;
    est = 0.0;
    for (i = 0; i < n; ++i) est += fabs(x[i]);
    same = 1;
    for (i = 0; i < n; ++i)
      if ((x[i] >= 0.0 ? 1 : -1) != isgn[i]) { same = 0; break; }
    if (same || est <= estold) { if (est < estold) est = estold; break; }
    for (i = 0; i < n; ++i) { isgn[i] = x[i] >= 0.0 ? 1 : -1; x[i] = (double)isgn[i]; }
    phgmg__gbf_solve(f, 'T', x);
    jlast = j;
    j = 0;
    for (i = 1; i < n; ++i) if (fabs(x[i]) > fabs(x[j])) j = i;
    if (fabs(x[jlast]) == fabs(x[j]) || iter >= 5) break;
  }
  for (i = 0; i < n; ++i) x[i] = ((i & 1) ? -1.0 : 1.0) * (1.0 + (double)i / (double)(n - 1));
  phgmg__gbf_solve(f, 'N', x);
  temp = 0.0;
  for (i = 0; i < n; ++i) temp += fabs(x[i]);
  temp = 2.0 * temp / (3.0 * (double)n);
  return temp > est ? temp : est;
}

/* ||J - R||_1 */
PHGMG__PRIV double phgmg__ph_jr_norm1(const phgmg_ph_system *s) {
  int N = s->N, i, j;
  double best = 0.0;
  for (j = 0; j < N; ++j) {
    double acc = 0.0;
    int i0 = 0, i1 = N - 1;
    if (s->storage == PHGMG_BANDED) {
      i0 = PHGMG__MAX(0, j - s->kb);
      i1 = PHGMG__MIN(N - 1, j + s->kb);
    }
    for (i = i0; i <= i1; ++i)
      acc += fabs(phgmg__ph_at(s, s->J, i, j) - phgmg__ph_at(s, s->R, i, j));
    if (acc > best) best = acc;
  }
  return best;
}

/* ---- factorization of J - R ------------------------------------------------ */
struct phgmg_jr_factor {
  phgmg_allocator al;
  int N;
  phgmg_storage storage;
  double *LU; /* dense */
  int *ipiv;
  phgmg__gbf gb; /* banded */
};

PHGMG_DEF void phgmg_jr_factor_destroy(phgmg_jr_factor *f) {
  phgmg_allocator al;
  if (!f) return;
  al = f->al;
  phgmg__free(&al, f->LU);
  phgmg__free(&al, f->ipiv);
  phgmg__gbf_free(&al, &f->gb);
  phgmg__free(&al, f);
}

/* rcond of the factored J - R (0 if singular); NOMEM -> -1. */
PHGMG__PRIV double phgmg__jr_rcond(const phgmg_jr_factor *f, const phgmg_ph_system *s) {
  const phgmg_allocator *al = &f->al;
  int N = f->N;
  double anorm = phgmg__ph_jr_norm1(s), rc = 0.0;
  double *work = phgmg__dalloc(al, 2 * (size_t)N);
  int *iwork = phgmg__ialloc(al, (size_t)N);
  if (!work || !iwork) {
    phgmg__free(al, work); phgmg__free(al, iwork);
    return -1.0;
  }
  if (!(anorm > 0.0)) rc = 0.0;
  else if (f->storage == PHGMG_DENSE) {
    rc = phgmg_lu_rcond(N, f->LU, N, f->ipiv, anorm, work, iwork);
  } else {
    double est = phgmg__gbf_inv_norm1(&f->gb, work, iwork);
    rc = (est > 0.0 && est == est && est < HUGE_VAL) ? (1.0 / est) / anorm : 0.0;
  }
  phgmg__free(al, work);
  phgmg__free(al, iwork);
  return rc;
}

PHGMG_DEF phgmg_result phgmg_jr_factor_create(phgmg_jr_factor **out, const phgmg_ph_system *sys,
                                              double *rcond_out, const phgmg_allocator *alloc) {
  phgmg_jr_factor *f;
  phgmg_result rc;
  int N, i, j;
  if (!out) return PHGMG_ERR_INVALID_ARG;
  *out = NULL;
  rc = phgmg__ph_check(sys);
  if (rc != PHGMG_OK) return rc;
  if (!phgmg__ph_mat_finite(sys, sys->J) || !phgmg__ph_mat_finite(sys, sys->R))
    return PHGMG_ERR_NANINF;
  N = sys->N;
  f = PHGMG__CAST(phgmg_jr_factor *, phgmg__alloc(alloc, sizeof(phgmg_jr_factor)));
  if (!f) return PHGMG_ERR_NOMEM;
  memset(f, 0, sizeof *f);
  if (alloc) f->al = *alloc;
  f->N = N;
  f->storage = sys->storage;
  if (sys->storage == PHGMG_DENSE) {
    f->LU = phgmg__dalloc(alloc, (size_t)N * (size_t)N);
    f->ipiv = phgmg__ialloc(alloc, (size_t)N);
    if (!f->LU || !f->ipiv) { phgmg_jr_factor_destroy(f); return PHGMG_ERR_NOMEM; }
    for (j = 0; j < N; ++j)
      for (i = 0; i < N; ++i) {
        size_t k = (size_t)i + (size_t)j * (size_t)N;
        f->LU[k] = sys->J[k] - sys->R[k];
      }
    rc = phgmg_lu_factor(N, f->LU, N, f->ipiv);
  } else {
    rc = phgmg__gbf_jr(alloc, sys, &f->gb);
  }
  if (rc != PHGMG_OK) {
    if (rcond_out) *rcond_out = 0.0;
    phgmg_jr_factor_destroy(f);
    return rc;
  }
  if (rcond_out) {
    double r = phgmg__jr_rcond(f, sys);
    if (r < 0.0) { phgmg_jr_factor_destroy(f); return PHGMG_ERR_NOMEM; }
    *rcond_out = r;
  }
  *out = f;
  return PHGMG_OK;
}

PHGMG_DEF void phgmg_jr_solve(const phgmg_jr_factor *f, char trans, int nrhs, double *X, int ldx) {
  int c;
  PHGMG_ASSERT(f && X && ldx >= f->N);
  PHGMG_ASSERT(trans == 'N' || trans == 'n' || trans == 'T' || trans == 't');
  if (f->storage == PHGMG_DENSE) {
    phgmg_lu_solve(trans, f->N, f->LU, f->N, f->ipiv, nrhs, X, ldx);
    return;
  }
  for (c = 0; c < nrhs; ++c) phgmg__gbf_solve(&f->gb, trans, X + (size_t)c * (size_t)ldx);
}

/* ---- validation ------------------------------------------------------------- */
/* Frobenius norms of M and of M + sign*M^T over the valid entries. */
PHGMG__PRIV void phgmg__ph_sym_defect(const phgmg_ph_system *s, const double *M, double sign,
                                      double *norm, double *defect) {
  int N = s->N, i, j;
  double a = 0.0, d = 0.0;
  for (j = 0; j < N; ++j) {
    int i0 = 0, i1 = N - 1;
    if (s->storage == PHGMG_BANDED) {
      i0 = PHGMG__MAX(0, j - s->kb);
      i1 = PHGMG__MIN(N - 1, j + s->kb);
    }
    for (i = i0; i <= i1; ++i) {
      double mij = phgmg__ph_at(s, M, i, j), e = mij + sign * phgmg__ph_at(s, M, j, i);
      a += mij * mij;
      d += e * e;
    }
  }
  *norm = sqrt(a);
  *defect = sqrt(d);
}

/* Is the shifted banded symmetric matrix R + delta I positive definite?
   Band Cholesky on the lower band, O(N kb^2). 1 yes, 0 no, -1 out of memory. */
PHGMG__PRIV int phgmg__ph_band_chol_pd(const phgmg_ph_system *s, const double *R, double delta,
                                       const phgmg_allocator *al) {
  int N = s->N, kb = s->kb, i, j, k, ok = 1;
  size_t ld = (size_t)kb + 1;
  double *L = phgmg__dalloc(al, ld * (size_t)N); /* L(i,j) at L[(i-j) + j*ld] */
  if (!L) return -1;
  for (j = 0; j < N && ok; ++j) {
    double d = R[PHGMG__PHB(kb, j, j)] + delta;
    for (k = PHGMG__MAX(0, j - kb); k < j; ++k) {
      double l = L[(size_t)(j - k) + (size_t)k * ld];
      d -= l * l;
    }
    if (!(d > 0.0)) { ok = 0; break; }
    d = sqrt(d);
    L[(size_t)j * ld] = d;
    for (i = j + 1; i <= PHGMG__MIN(N - 1, j + kb); ++i) {
      double v = R[PHGMG__PHB(kb, i, j)];
      for (k = PHGMG__MAX(0, i - kb); k < j; ++k)
        v -= L[(size_t)(i - k) + (size_t)k * ld] * L[(size_t)(j - k) + (size_t)k * ld];
      L[(size_t)(i - j) + (size_t)j * ld] = v / d;
    }
  }
  phgmg__free(al, L);
  return ok;
}

/* R positive semidefinite within tol (see the declaration). */
PHGMG__PRIV phgmg_result phgmg__ph_check_psd(const phgmg_ph_system *s, double tol,
                                             const phgmg_allocator *al) {
  int N = s->N, i, j, diag = 1;
  double dmax = 0.0, dmin = HUGE_VAL;
  for (j = 0; j < N && diag; ++j) {
    int i0 = 0, i1 = N - 1;
    if (s->storage == PHGMG_BANDED) {
      i0 = PHGMG__MAX(0, j - s->kb);
      i1 = PHGMG__MIN(N - 1, j + s->kb);
    }
    for (i = i0; i <= i1; ++i)
      if (i != j && phgmg__ph_at(s, s->R, i, j) != 0.0) { diag = 0; break; }
  }
  if (diag) { /* the eigenvalues are the diagonal */
    for (j = 0; j < N; ++j) {
      double d = phgmg__ph_at(s, s->R, j, j);
      if (fabs(d) > dmax) dmax = fabs(d);
      if (d < dmin) dmin = d;
    }
    return dmin >= -tol * dmax ? PHGMG_OK : PHGMG_ERR_NOT_PSD;
  }
  if (s->storage == PHGMG_DENSE || N <= PHGMG__PH_PSD_DENSE_MAX) {
    double *A = phgmg__dalloc(al, (size_t)N * (size_t)N), *w = phgmg__dalloc(al, (size_t)N);
    phgmg_result rc;
    if (!A || !w) { phgmg__free(al, A); phgmg__free(al, w); return PHGMG_ERR_NOMEM; }
    for (j = 0; j < N; ++j)
      for (i = 0; i < N; ++i) A[(size_t)i + (size_t)j * (size_t)N] = phgmg__ph_at(s, s->R, i, j);
    rc = phgmg_sym_eig(N, A, N, w, NULL, 0);
    if (rc == PHGMG_OK) {
      double nrm = PHGMG__MAX(fabs(w[0]), fabs(w[N - 1]));
      if (w[0] < -tol * nrm) rc = PHGMG_ERR_NOT_PSD;
    }
    phgmg__free(al, A);
    phgmg__free(al, w);
    return rc;
  } else {
    /* large banded: R + tol*||R||_1 I must admit a Cholesky factorization
       (||R||_1 >= ||R||_2 for symmetric R, so this is slightly more lenient) */
    double n1 = 0.0;
    int r;
    for (j = 0; j < N; ++j) {
      double acc = 0.0;
      for (i = PHGMG__MAX(0, j - s->kb); i <= PHGMG__MIN(N - 1, j + s->kb); ++i)
        acc += fabs(s->R[PHGMG__PHB(s->kb, i, j)]);
      if (acc > n1) n1 = acc;
    }
    if (n1 == 0.0) return PHGMG_OK;
    r = phgmg__ph_band_chol_pd(s, s->R, tol * n1, al);
    if (r < 0) return PHGMG_ERR_NOMEM;
    return r ? PHGMG_OK : PHGMG_ERR_NOT_PSD;
  }
}

PHGMG_DEF phgmg_result phgmg_ph_validate(const phgmg_ph_system *sys, double tol,
                                         double *rcond_out, const phgmg_allocator *alloc) {
  phgmg_result rc;
  double nrm, def;
  int N, m;
  if (rcond_out) *rcond_out = 0.0;
  rc = phgmg__ph_check(sys);
  if (rc != PHGMG_OK) return rc;
  if (!(tol > 0.0)) tol = 1e-12;
  N = sys->N;
  m = sys->m;
  /* NaN / Inf */
  if (!phgmg__ph_mat_finite(sys, sys->J) || !phgmg__ph_mat_finite(sys, sys->R) ||
      !phgmg__ph_mat_finite(sys, sys->Q) ||
      !phgmg__all_finite(sys->B, (size_t)N * (size_t)m))
    return PHGMG_ERR_NANINF;
  if (sys->nl == PHGMG_NL_SEPARABLE) {
    if (sys->sep_w && !phgmg__all_finite(sys->sep_w, (size_t)sys->nsep)) return PHGMG_ERR_NANINF;
    if (sys->poly_deg > 0 && !phgmg__all_finite(sys->poly, (size_t)sys->poly_deg + 1))
      return PHGMG_ERR_NANINF;
  }
  /* structure */
  phgmg__ph_sym_defect(sys, sys->J, 1.0, &nrm, &def);
  if (def > tol * nrm) return PHGMG_ERR_NOT_SKEW;
  phgmg__ph_sym_defect(sys, sys->R, -1.0, &nrm, &def);
  if (def > tol * nrm) return PHGMG_ERR_NOT_SYMMETRIC;
  phgmg__ph_sym_defect(sys, sys->Q, -1.0, &nrm, &def);
  if (def > tol * nrm) return PHGMG_ERR_NOT_SYMMETRIC;
  rc = phgmg__ph_check_psd(sys, tol, alloc);
  if (rc != PHGMG_OK) return rc;
  /* B full column rank: pivoted QR, |R(m-1,m-1)| > tol |R(0,0)| */
  {
    double *Bc = phgmg__dalloc(alloc, (size_t)N * (size_t)m);
    double *tau = phgmg__dalloc(alloc, (size_t)m), *work = phgmg__dalloc(alloc, 2 * (size_t)m);
    int *jpvt = phgmg__ialloc(alloc, (size_t)m);
    if (!Bc || !tau || !work || !jpvt) rc = PHGMG_ERR_NOMEM;
    else {
      memcpy(Bc, sys->B, sizeof(double) * (size_t)N * (size_t)m);
      rc = phgmg_qrcp(N, m, Bc, N, tau, jpvt, work);
      if (rc == PHGMG_OK) {
        double r00 = fabs(Bc[0]), rmm = fabs(Bc[(size_t)(m - 1) * (size_t)(N + 1)]);
        if (!(r00 > 0.0) || !(rmm > tol * r00)) rc = PHGMG_ERR_RANK;
      }
    }
    phgmg__free(alloc, Bc);
    phgmg__free(alloc, tau);
    phgmg__free(alloc, work);
    phgmg__free(alloc, jpvt);
    if (rc != PHGMG_OK) return rc;
  }
  /* J - R invertible */
  {
    phgmg_jr_factor *f = NULL;
    double rcond = 0.0;
    rc = phgmg_jr_factor_create(&f, sys, &rcond, alloc);
    if (rc == PHGMG_ERR_NOMEM) return rc;
    if (rc != PHGMG_OK) rcond = 0.0;
    phgmg_jr_factor_destroy(f);
    if (rcond_out) *rcond_out = rcond;
    if (!(rcond > tol)) return PHGMG_ERR_SINGULAR;
  }
  return PHGMG_OK;
}

/* >>gl3 (implementation) ================================================= */

PHGMG_DEF void phgmg_gl3_coefficients(double c[3], double b[3], double A[9]) {
  const double s15 = sqrt(15.0);
  c[0] = 0.5 - s15 / 10.0;
  c[1] = 0.5;
  c[2] = 0.5 + s15 / 10.0;
  b[0] = 5.0 / 18.0;
  b[1] = 4.0 / 9.0;
  b[2] = 5.0 / 18.0;
  A[0] = 5.0 / 36.0;         A[1] = 2.0 / 9.0 - s15 / 15.0; A[2] = 5.0 / 36.0 - s15 / 30.0;
  A[3] = 5.0 / 36.0 + s15 / 24.0; A[4] = 2.0 / 9.0;       A[5] = 5.0 / 36.0 - s15 / 24.0;
  A[6] = 5.0 / 36.0 + s15 / 30.0; A[7] = 2.0 / 9.0 + s15 / 15.0; A[8] = 5.0 / 36.0;
}

/* Inverse of a row-major 3x3 matrix; 0 if singular. */
PHGMG__PRIV int phgmg__inv3(const double *M, double *Mi) {
  double c00 = M[4] * M[8] - M[5] * M[7], c01 = M[5] * M[6] - M[3] * M[8],
         c02 = M[3] * M[7] - M[4] * M[6];
  double det = M[0] * c00 + M[1] * c01 + M[2] * c02, r;
  if (det == 0.0) return 0;
  r = 1.0 / det;
  Mi[0] = c00 * r;
  Mi[1] = (M[2] * M[7] - M[1] * M[8]) * r;
  Mi[2] = (M[1] * M[5] - M[2] * M[4]) * r;
  Mi[3] = c01 * r;
  Mi[4] = (M[0] * M[8] - M[2] * M[6]) * r;
  Mi[5] = (M[2] * M[3] - M[0] * M[5]) * r;
  Mi[6] = c02 * r;
  Mi[7] = (M[1] * M[6] - M[0] * M[7]) * r;
  Mi[8] = (M[0] * M[4] - M[1] * M[3]) * r;
  return 1;
}

/* Diagonalisation of A^{-1}: A^{-1} T = T [[gam,0,0],[0,alp,bet],[0,-bet,alp]],
   i.e. gam is the real eigenvalue and alp +- i bet the complex pair (the roots
   of z^3 - 12 z^2 + 60 z - 120); T = [t1, Re v, Im v] with A^{-1} v = (alp+i bet) v.
   The eigenvectors are null vectors of A^{-1} - lambda I found as (bilinear)
   cross products of two of its rows. Row-major T, Ti. */
PHGMG__PRIV void phgmg__gl3_transform(const double A[9], double T[9], double Ti[9], double *gam,
                                      double *alp, double *bet) {
  double Ai[9], z = 3.6, p, q;
  int it, a, b, k, best;
  phgmg__inv3(A, Ai);
  for (it = 0; it < 50; ++it) { /* Newton on the cubic from the right of the real root */
    double f = ((z - 12.0) * z + 60.0) * z - 120.0, df = (3.0 * z - 24.0) * z + 60.0;
    double dz = f / df;
    z -= dz;
    if (fabs(dz) <= 1e-16 * z) break;
  }
  *gam = z;
  p = z - 12.0;           /* z^3 - 12z^2 + 60z - 120 = (z - gam)(z^2 + p z + q) */
  q = 120.0 / z;
  *alp = -0.5 * p;
  *bet = sqrt(q - 0.25 * p * p);
  { /* real eigenvector */
    double M[9], v[3] = {0, 0, 0}, bestn = -1.0;
    for (k = 0; k < 9; ++k) M[k] = Ai[k];
    M[0] -= z; M[4] -= z; M[8] -= z;
    for (best = 0; best < 3; ++best) {
      double cv[3], n2;
      a = best == 2 ? 1 : 0;
      b = best == 0 ? 1 : 2;
      cv[0] = M[a * 3 + 1] * M[b * 3 + 2] - M[a * 3 + 2] * M[b * 3 + 1];
      cv[1] = M[a * 3 + 2] * M[b * 3 + 0] - M[a * 3 + 0] * M[b * 3 + 2];
      cv[2] = M[a * 3 + 0] * M[b * 3 + 1] - M[a * 3 + 1] * M[b * 3 + 0];
      n2 = cv[0] * cv[0] + cv[1] * cv[1] + cv[2] * cv[2];
      if (n2 > bestn) { bestn = n2; v[0] = cv[0]; v[1] = cv[1]; v[2] = cv[2]; }
    }
    bestn = sqrt(bestn);
    for (k = 0; k < 3; ++k) T[k * 3 + 0] = v[k] / bestn;
  }
  { /* complex eigenvector for alp + i bet */
    double Mr[9], Mi[9], vr[3] = {0, 0, 0}, vi[3] = {0, 0, 0}, bestn = -1.0, sr, si, d;
    int kk;
    for (k = 0; k < 9; ++k) { Mr[k] = Ai[k]; Mi[k] = 0.0; }
    for (k = 0; k < 3; ++k) { Mr[k * 4] -= *alp; Mi[k * 4] = -*bet; }
    for (best = 0; best < 3; ++best) {
      double cr[3], ci[3], n2 = 0.0;
      int e;
      a = best == 2 ? 1 : 0;
      b = best == 0 ? 1 : 2;
      for (e = 0; e < 3; ++e) {
        int e1 = (e + 1) % 3, e2 = (e + 2) % 3;
        /* (ra x rb)_e = ra[e1] rb[e2] - ra[e2] rb[e1], complex, no conjugation */
        double xr = Mr[a * 3 + e1] * Mr[b * 3 + e2] - Mi[a * 3 + e1] * Mi[b * 3 + e2];
        double xi = Mr[a * 3 + e1] * Mi[b * 3 + e2] + Mi[a * 3 + e1] * Mr[b * 3 + e2];
        double yr = Mr[a * 3 + e2] * Mr[b * 3 + e1] - Mi[a * 3 + e2] * Mi[b * 3 + e1];
        double yi = Mr[a * 3 + e2] * Mi[b * 3 + e1] + Mi[a * 3 + e2] * Mr[b * 3 + e1];
        cr[e] = xr - yr;
        ci[e] = xi - yi;
        n2 += cr[e] * cr[e] + ci[e] * ci[e];
      }
      if (n2 > bestn) {
        bestn = n2;
        for (e = 0; e < 3; ++e) { vr[e] = cr[e]; vi[e] = ci[e]; }
      }
    }
    /* scale so that the largest component is real and 1 */
    kk = 0;
    for (k = 1; k < 3; ++k)
      if (vr[k] * vr[k] + vi[k] * vi[k] > vr[kk] * vr[kk] + vi[kk] * vi[kk]) kk = k;
    d = vr[kk] * vr[kk] + vi[kk] * vi[kk];
    sr = vr[kk] / d;
    si = -vi[kk] / d; /* 1 / v_kk */
    for (k = 0; k < 3; ++k) {
      double xr = vr[k] * sr - vi[k] * si, xi = vr[k] * si + vi[k] * sr;
      T[k * 3 + 1] = xr;
      T[k * 3 + 2] = xi;
    }
    T[kk * 3 + 2] = 0.0;
  }
  phgmg__inv3(T, Ti);
}

/* A banded matrix by its nonzero diagonals: v[d*n + i] = A(i, i + off[d]). */
typedef struct phgmg__dia {
  int n, nd;
  int *off;
  double *v;
} phgmg__dia;

PHGMG__PRIV void phgmg__dia_free(const phgmg_allocator *al, phgmg__dia *D) {
  phgmg__free(al, D->off);
  phgmg__free(al, D->v);
  D->off = NULL;
  D->v = NULL;
  D->nd = 0;
}

/* From band storage (kb): M1 - M2 (M2 may be NULL). Keeps the diagonals with a
   nonzero entry, plus the main one if force_main, or all of them if keep_all. */
PHGMG__PRIV phgmg_result phgmg__dia_build(const phgmg_allocator *al, phgmg__dia *D, int n, int kb,
                                          const double *M1, const double *M2, int force_main,
                                          int keep_all) {
  int o, i, d = 0;
  D->n = n;
  D->nd = 0;
  D->off = phgmg__ialloc(al, (size_t)(2 * kb + 1));
  D->v = phgmg__dalloc(al, (size_t)(2 * kb + 1) * (size_t)n);
  if (!D->off || !D->v) { phgmg__dia_free(al, D); return PHGMG_ERR_NOMEM; }
  for (o = -kb; o <= kb; ++o) {
    double *vd = D->v + (size_t)d * (size_t)n;
    int nz = 0;
    for (i = 0; i < n; ++i) {
      int j = i + o;
      double val = 0.0;
      if (j >= 0 && j < n) {
        size_t k = PHGMG__PHB(kb, i, j);
        val = M1 ? M1[k] : 0.0;
        if (M2) val -= M2[k];
      }
      vd[i] = val;
      if (val != 0.0) nz = 1;
    }
    if (nz || keep_all || (force_main && o == 0)) D->off[d++] = o;
  }
  D->nd = d;
  return PHGMG_OK;
}

/* Refill all 2kb+1 diagonals of D (built with keep_all) from band storage. */
PHGMG__PRIV void phgmg__dia_refill(phgmg__dia *D, int kb, const double *M) {
  int n = D->n, d, i;
  for (d = 0; d < D->nd; ++d) {
    int o = D->off[d];
    double *vd = D->v + (size_t)d * (size_t)n;
    for (i = 0; i < n; ++i) {
      int j = i + o;
      vd[i] = (j >= 0 && j < n) ? M[PHGMG__PHB(kb, i, j)] : 0.0;
    }
  }
}

/* y = D x (overwrite) */
PHGMG__PRIV void phgmg__dia_mv(const phgmg__dia *D, const double *x, double *y) {
  int n = D->n, d, i;
  for (i = 0; i < n; ++i) y[i] = 0.0;
  for (d = 0; d < D->nd; ++d) {
    int o = D->off[d], i0 = PHGMG__MAX(0, -o), i1 = PHGMG__MIN(n, n - o);
    const double *vd = D->v + (size_t)d * (size_t)n;
    for (i = i0; i < i1; ++i) y[i] += vd[i] * x[i + o];
  }
}

/* ab (band LU layout, kv = kl+ku) += alpha * A * B for DIA A, B; if dd != NULL,
   B is the diagonal matrix diag(dd) instead. */
PHGMG__PRIV void phgmg__dia_prod_band(const phgmg__dia *A, const phgmg__dia *B, const double *dd,
                                      double alpha, double *ab, int ldab, int kv) {
  int n = A->n, da, db, i;
  for (da = 0; da < A->nd; ++da) {
    int oa = A->off[da];
    const double *va = A->v + (size_t)da * (size_t)n;
    if (dd) {
      int i0 = PHGMG__MAX(0, -oa), i1 = PHGMG__MIN(n, n - oa);
      for (i = i0; i < i1; ++i) {
        int j = i + oa;
        ab[(size_t)(kv - oa) + (size_t)j * (size_t)ldab] += alpha * va[i] * dd[j];
      }
      continue;
    }
    for (db = 0; db < B->nd; ++db) {
      int ob = B->off[db], o = oa + ob, i0, i1;
      const double *vb = B->v + (size_t)db * (size_t)n;
      if (o >= n || o <= -n) continue;
      i0 = PHGMG__MAX(0, PHGMG__MAX(-oa, -o));
      i1 = PHGMG__MIN(n, PHGMG__MIN(n - oa, n - o));
      for (i = i0; i < i1; ++i) {
        int j = i + o;
        ab[(size_t)(kv - o) + (size_t)j * (size_t)ldab] += alpha * va[i] * vb[i + oa];
      }
    }
  }
}

enum { PHGMG__GL3_DENSE = 0, PHGMG__GL3_BANDED = 1, PHGMG__GL3_CALLBACK = 2, PHGMG__GL3_MAP = 3 };

struct phgmg_gl3 {
  phgmg_allocator al;
  phgmg_ph_system sys;
  int N, m, mode, linear;
  double h, tol, contraction;
  int max_iter;
  double c[3], b[3], A[9], T[9], Ti[9], E[9], d[3];
  double gam, alp, bet;
  /* dense operators */
  double *JR, *JRQ, *Hs, *K1, *K2;
  int *ip1, *ip2;
  /* banded operators */
  phgmg__dia djr, dq, dh;
  int kl, ku, ldab, ue1, ue2;
  double *AB1, *AB2, *dinv1, *dinv2, *hband;
  /* SEPARABLE: Hessian diagonal of the nonlinear part; derivative of poly;
     with poly: per-coordinate weights wc[i] = sum of w_k over terms on i */
  double *dd;
  double *dpoly, *wc;
  /* banded: J - R by rows (CSR) for the stage right-hand sides */
  int *jr_ptr, *jr_col;
  double *jr_val;
  int nopiv1, nopiv2; /* banded factors without row interchanges */
  int nbnz;           /* banded: the nonzero entries of B (row, column, value) */
  int *b_row, *b_col;
  double *b_val;
  /* step map (dense linear): x+ = Phi x + Gam U, g_i = GX_i x + GU_i U */
  double *Phi, *Gam, *GX, *GU;
  /* work */
  double *Z, *W, *Y, *G, *F, *U, *Zprev, *xend, *xnew, *tmp;
  /* Newton right-hand sides, zero-padded by kl before and ku after (banded) */
  double *r1buf, *rcbuf, *r1, *rc;
  /* packed row-wise factors for the pivot-free banded solve (see below) */
  double *pk;
  int have_prev, need_factor;
  double tend;
  phgmg_gl3_stats st;
};

PHGMG_DEF void phgmg_gl3_destroy(phgmg_gl3 *s) {
  phgmg_allocator al;
  if (!s) return;
  al = s->al;
  phgmg__free(&al, s->JR); phgmg__free(&al, s->JRQ); phgmg__free(&al, s->Hs);
  phgmg__free(&al, s->K1); phgmg__free(&al, s->K2);
  phgmg__free(&al, s->ip1); phgmg__free(&al, s->ip2);
  phgmg__dia_free(&al, &s->djr); phgmg__dia_free(&al, &s->dq); phgmg__dia_free(&al, &s->dh);
  phgmg__free(&al, s->AB1); phgmg__free(&al, s->AB2);
  phgmg__free(&al, s->dinv1); phgmg__free(&al, s->dinv2); phgmg__free(&al, s->hband);
  phgmg__free(&al, s->dd);
  phgmg__free(&al, s->dpoly); phgmg__free(&al, s->wc);
  phgmg__free(&al, s->jr_ptr); phgmg__free(&al, s->jr_col); phgmg__free(&al, s->jr_val);
  phgmg__free(&al, s->b_row); phgmg__free(&al, s->b_col); phgmg__free(&al, s->b_val);
  phgmg__free(&al, s->Phi); phgmg__free(&al, s->Gam); phgmg__free(&al, s->GX);
  phgmg__free(&al, s->GU);
  phgmg__free(&al, s->Z); phgmg__free(&al, s->W); phgmg__free(&al, s->Y);
  phgmg__free(&al, s->G); phgmg__free(&al, s->F); phgmg__free(&al, s->U);
  phgmg__free(&al, s->Zprev); phgmg__free(&al, s->xend);
  phgmg__free(&al, s->xnew); phgmg__free(&al, s->r1buf); phgmg__free(&al, s->rcbuf);
  phgmg__free(&al, s->pk);
  phgmg__free(&al, s->tmp);
  phgmg__free(&al, s);
}

PHGMG_DEF const phgmg_gl3_stats *phgmg_gl3_get_stats(const phgmg_gl3 *s) {
  return s ? &s->st : NULL;
}

/* Precompute the exact one-step map of a dense linear system (see >>gl3). */
PHGMG__PRIV phgmg_result phgmg__gl3_build_map(phgmg_gl3 *s) {
  const phgmg_allocator *al = &s->al;
  const phgmg_ph_system *sys = &s->sys;
  int N = s->N, m = s->m, nc = N + 3 * m, i, j, k, st;
  size_t NN = (size_t)N * (size_t)N, Nc = (size_t)N * (size_t)nc;
  double *M = NULL, *K1 = NULL, *K2 = NULL, *X1 = NULL, *X2 = NULL, *ZZ = NULL, *QZ = NULL;
  int *ip1 = NULL, *ip2 = NULL;
  double sum[3];
  phgmg_result rc = PHGMG_OK;
  M = phgmg__dalloc(al, NN);
  K1 = phgmg__dalloc(al, NN);
  K2 = phgmg__dalloc(al, 2 * NN);
  X1 = phgmg__dalloc(al, Nc);
  X2 = phgmg__dalloc(al, 2 * Nc);
  ZZ = phgmg__dalloc(al, Nc);
  QZ = phgmg__dalloc(al, Nc);
  ip1 = phgmg__ialloc(al, (size_t)N);
  ip2 = phgmg__ialloc(al, (size_t)N);
  s->Phi = phgmg__dalloc(al, NN);
  s->Gam = phgmg__dalloc(al, (size_t)N * 3 * (size_t)m);
  s->GX = phgmg__dalloc(al, 3 * NN);
  s->GU = phgmg__dalloc(al, 3 * (size_t)N * 3 * (size_t)m);
  if (!M || !K1 || !K2 || !X1 || !X2 || !ZZ || !QZ || !ip1 || !ip2 || !s->Phi || !s->Gam ||
      !s->GX || !s->GU) {
    rc = PHGMG_ERR_NOMEM;
    goto done;
  }
  /* M = (J - R) Q */
  {
    double *JR = K1; /* borrow K1 for J - R */
    size_t e;
    for (e = 0; e < NN; ++e) JR[e] = sys->J[e] - sys->R[e];
    phgmg_gemm('N', 'N', N, N, N, 1.0, JR, N, sys->Q, N, 0.0, M, N);
  }
  if (!phgmg__all_finite(M, NN)) { rc = PHGMG_ERR_NANINF; goto done; }
  for (k = 0; k < 3; ++k) sum[k] = s->Ti[k * 3] + s->Ti[k * 3 + 1] + s->Ti[k * 3 + 2];
  /* K1 = gam/h I - M, K2 = (alp - i bet)/h I - M */
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) {
      size_t e = (size_t)i + (size_t)j * (size_t)N;
      K1[e] = -M[e];
      K2[2 * e] = -M[e];
      K2[2 * e + 1] = 0.0;
      if (i == j) {
        K1[e] += s->gam / s->h;
        K2[2 * e] += s->alp / s->h;
        K2[2 * e + 1] = -s->bet / s->h;
      }
    }
  rc = phgmg_lu_factor(N, K1, N, ip1);
  if (rc == PHGMG_OK) rc = phgmg_zlu_factor(N, K2, N, ip2);
  if (rc != PHGMG_OK) goto done;
  /* right-hand sides: [sum_k M, Ti_k1 B, Ti_k2 B, Ti_k3 B] */
  for (j = 0; j < N; ++j)
    for (i = 0; i < N; ++i) {
      size_t e = (size_t)i + (size_t)j * (size_t)N;
      X1[e] = sum[0] * M[e];
      X2[2 * e] = sum[1] * M[e];
      X2[2 * e + 1] = sum[2] * M[e];
    }
  for (st = 0; st < 3; ++st)
    for (j = 0; j < m; ++j)
      for (i = 0; i < N; ++i) {
        size_t e = (size_t)i + (size_t)(N + st * m + j) * (size_t)N;
        double bij = sys->B[(size_t)i + (size_t)j * (size_t)N];
        X1[e] = s->Ti[0 * 3 + st] * bij;
        X2[2 * e] = s->Ti[1 * 3 + st] * bij;
        X2[2 * e + 1] = s->Ti[2 * 3 + st] * bij;
      }
  phgmg_lu_solve('N', N, K1, N, ip1, nc, X1, N);
  phgmg_zlu_solve(N, K2, N, ip2, nc, X2, N);
  /* Z_i = T_i1 W1 + T_i2 Re W23 + T_i3 Im W23; Phi = I + sum d_i Zx_i, Gam = sum d_i Zu_i;
     GX_i = Q (I + Zx_i), GU_i = Q Zu_i */
  memset(s->Phi, 0, sizeof(double) * NN);
  memset(s->Gam, 0, sizeof(double) * (size_t)N * 3 * (size_t)m);
  for (st = 0; st < 3; ++st) {
    double t1 = s->T[st * 3], t2 = s->T[st * 3 + 1], t3 = s->T[st * 3 + 2], di = s->d[st];
    size_t e;
    for (e = 0; e < Nc; ++e) ZZ[e] = t1 * X1[e] + t2 * X2[2 * e] + t3 * X2[2 * e + 1];
    for (e = 0; e < NN; ++e) s->Phi[e] += di * ZZ[e];
    for (e = 0; e < (size_t)N * 3 * (size_t)m; ++e) s->Gam[e] += di * ZZ[NN + e];
    phgmg_gemm('N', 'N', N, nc, N, 1.0, sys->Q, N, ZZ, N, 0.0, QZ, N);
    for (e = 0; e < NN; ++e) s->GX[(size_t)st * NN + e] = QZ[e] + sys->Q[e];
    memcpy(s->GU + (size_t)st * (size_t)N * 3 * (size_t)m, QZ + NN,
           sizeof(double) * (size_t)N * 3 * (size_t)m);
  }
  for (i = 0; i < N; ++i) s->Phi[(size_t)i * (size_t)(N + 1)] += 1.0;
  if (!phgmg__all_finite(s->Phi, NN) || !phgmg__all_finite(s->Gam, (size_t)N * 3 * (size_t)m))
    rc = PHGMG_ERR_NANINF;
done:
  phgmg__free(al, M); phgmg__free(al, K1); phgmg__free(al, K2);
  phgmg__free(al, X1); phgmg__free(al, X2); phgmg__free(al, ZZ); phgmg__free(al, QZ);
  phgmg__free(al, ip1); phgmg__free(al, ip2);
  return rc;
}

PHGMG_DEF phgmg_result phgmg_gl3_create(phgmg_gl3 **out, const phgmg_ph_system *sys, double dt,
                                        const phgmg_gl3_opts *opts, const phgmg_allocator *alloc) {
  phgmg_gl3 *s;
  phgmg_result rc;
  int N, m, i, j, k;
  size_t NN, N3;
  if (!out) return PHGMG_ERR_INVALID_ARG;
  *out = NULL;
  rc = phgmg__ph_check(sys);
  if (rc != PHGMG_OK) return rc;
  if (!(dt > 0.0) || dt == HUGE_VAL) return PHGMG_ERR_INVALID_ARG;
  if (opts && (opts->max_iter < 0 || opts->tol < 0.0 || opts->contraction < 0.0 ||
               opts->tol != opts->tol || opts->contraction != opts->contraction))
    return PHGMG_ERR_INVALID_ARG;
  s = PHGMG__CAST(phgmg_gl3 *, phgmg__alloc(alloc, sizeof(phgmg_gl3)));
  if (!s) return PHGMG_ERR_NOMEM;
  memset(s, 0, sizeof *s);
  if (alloc) s->al = *alloc;
  s->sys = *sys;
  N = s->N = sys->N;
  m = s->m = sys->m;
  NN = (size_t)N * (size_t)N;
  N3 = 3 * (size_t)N;
  s->h = dt;
  s->tol = (opts && opts->tol > 0.0) ? opts->tol : 1e-10;
  s->max_iter = (opts && opts->max_iter > 0) ? opts->max_iter : 10;
  s->contraction = (opts && opts->contraction > 0.0) ? opts->contraction : 0.5;
  s->linear = sys->nl == PHGMG_NL_NONE;
  phgmg_gl3_coefficients(s->c, s->b, s->A);
  phgmg__gl3_transform(s->A, s->T, s->Ti, &s->gam, &s->alp, &s->bet);
  {
    double Ai[9];
    phgmg__inv3(s->A, Ai);
    for (j = 0; j < 3; ++j) s->d[j] = s->b[0] * Ai[j] + s->b[1] * Ai[3 + j] + s->b[2] * Ai[6 + j];
  }
  /* extrapolation of the previous collocation polynomial p (p(0) = 0,
     p(c_j) = Zprev_j): Z_i = p(1 + c_i) - p(1) = sum_j E_ij Zprev_j */
  for (i = 0; i < 3; ++i)
    for (j = 0; j < 3; ++j) {
      double s1 = 1.0 + s->c[i], l1 = s1 / s->c[j], l0 = 1.0 / s->c[j];
      for (k = 0; k < 3; ++k) {
        if (k == j) continue;
        l1 *= (s1 - s->c[k]) / (s->c[j] - s->c[k]);
        l0 *= (1.0 - s->c[k]) / (s->c[j] - s->c[k]);
      }
      s->E[i * 3 + j] = l1 - l0;
    }
  if (s->linear && !(opts && opts->no_step_map) && sys->storage == PHGMG_DENSE &&
      N <= PHGMG_GL3_STEP_MAP_MAX_N)
    s->mode = PHGMG__GL3_MAP;
  else if (sys->shifted_factor)
    s->mode = PHGMG__GL3_CALLBACK;
  else
    s->mode = sys->storage == PHGMG_DENSE ? PHGMG__GL3_DENSE : PHGMG__GL3_BANDED;

  s->U = phgmg__dalloc(&s->al, 3 * (size_t)m);
  s->G = phgmg__dalloc(&s->al, N3);
  s->xnew = phgmg__dalloc(&s->al, (size_t)N);
  if (!s->U || !s->G || !s->xnew) { rc = PHGMG_ERR_NOMEM; goto fail; }
  if (s->mode == PHGMG__GL3_MAP) {
    if (!phgmg__ph_mat_finite(sys, sys->J) || !phgmg__ph_mat_finite(sys, sys->R) ||
        !phgmg__ph_mat_finite(sys, sys->Q) || !phgmg__all_finite(sys->B, (size_t)N * (size_t)m)) {
      rc = PHGMG_ERR_NANINF;
      goto fail;
    }
    rc = phgmg__gl3_build_map(s);
    if (rc != PHGMG_OK) goto fail;
    *out = s;
    return PHGMG_OK;
  }
  s->Z = phgmg__dalloc(&s->al, N3);
  s->W = phgmg__dalloc(&s->al, N3);
  s->Y = phgmg__dalloc(&s->al, N3);
  s->F = phgmg__dalloc(&s->al, N3);
  s->Zprev = phgmg__dalloc(&s->al, N3);
  s->xend = phgmg__dalloc(&s->al, (size_t)N);
  s->tmp = phgmg__dalloc(&s->al, (size_t)N);
  if (!s->Z || !s->W || !s->Y || !s->F || !s->Zprev || !s->xend ||
      !s->tmp) {
    rc = PHGMG_ERR_NOMEM;
    goto fail;
  }
  if (sys->nl == PHGMG_NL_SEPARABLE) {
    s->dd = phgmg__dalloc(&s->al, (size_t)N);
    if (!s->dd) { rc = PHGMG_ERR_NOMEM; goto fail; }
    if (sys->poly_deg > 0) { /* dpoly[j] = (j+1) poly[j+1] */
      s->dpoly = phgmg__dalloc(&s->al, (size_t)sys->poly_deg);
      if (!s->dpoly) { rc = PHGMG_ERR_NOMEM; goto fail; }
      for (k = 0; k < sys->poly_deg; ++k) s->dpoly[k] = (double)(k + 1) * sys->poly[k + 1];
      s->wc = phgmg__dalloc(&s->al, (size_t)N);
      if (!s->wc) { rc = PHGMG_ERR_NOMEM; goto fail; }
      for (i = 0; i < N; ++i) s->wc[i] = 0.0;
      for (k = 0; k < sys->nsep; ++k) s->wc[sys->sep_idx[k]] += sys->sep_w ? sys->sep_w[k] : 1.0;
    }
  }
  if (sys->storage == PHGMG_DENSE) {
    s->JR = phgmg__dalloc(&s->al, NN);
    if (!s->JR) { rc = PHGMG_ERR_NOMEM; goto fail; }
    {
      size_t e;
      for (e = 0; e < NN; ++e) s->JR[e] = sys->J[e] - sys->R[e];
    }
    if (s->mode == PHGMG__GL3_DENSE) {
      s->K1 = phgmg__dalloc(&s->al, NN);
      s->K2 = phgmg__dalloc(&s->al, 2 * NN);
      s->ip1 = phgmg__ialloc(&s->al, (size_t)N);
      s->ip2 = phgmg__ialloc(&s->al, (size_t)N);
      if (!s->K1 || !s->K2 || !s->ip1 || !s->ip2) { rc = PHGMG_ERR_NOMEM; goto fail; }
      if (sys->nl == PHGMG_NL_GENERAL) {
        s->Hs = phgmg__dalloc(&s->al, NN);
        if (!s->Hs) { rc = PHGMG_ERR_NOMEM; goto fail; }
      } else {
        s->JRQ = phgmg__dalloc(&s->al, NN);
        if (!s->JRQ) { rc = PHGMG_ERR_NOMEM; goto fail; }
        phgmg_gemm('N', 'N', N, N, N, 1.0, s->JR, N, sys->Q, N, 0.0, s->JRQ, N);
      }
    }
  } else {
    int kb = sys->kb, amin = 0, amax = 0, bmin = 0, bmax = 0;
    rc = phgmg__dia_build(&s->al, &s->djr, N, kb, sys->J, sys->R, 0, 0);
    if (rc == PHGMG_OK) rc = phgmg__dia_build(&s->al, &s->dq, N, kb, sys->Q, NULL, 1, 0);
    if (rc != PHGMG_OK) goto fail;
    { /* CSR of J - R */
      size_t nnz = 0;
      int r, c;
      for (r = 0; r < N; ++r)
        for (c = PHGMG__MAX(0, r - kb); c <= PHGMG__MIN(N - 1, r + kb); ++c)
          if (sys->J[PHGMG__PHB(kb, r, c)] - sys->R[PHGMG__PHB(kb, r, c)] != 0.0) ++nnz;
      s->jr_ptr = phgmg__ialloc(&s->al, (size_t)N + 1);
      s->jr_col = phgmg__ialloc(&s->al, nnz);
      s->jr_val = phgmg__dalloc(&s->al, nnz);
      if (!s->jr_ptr || !s->jr_col || !s->jr_val) { rc = PHGMG_ERR_NOMEM; goto fail; }
      nnz = 0;
      for (r = 0; r < N; ++r) {
        s->jr_ptr[r] = (int)nnz;
        for (c = PHGMG__MAX(0, r - kb); c <= PHGMG__MIN(N - 1, r + kb); ++c) {
          double v = sys->J[PHGMG__PHB(kb, r, c)] - sys->R[PHGMG__PHB(kb, r, c)];
          if (v != 0.0) { s->jr_col[nnz] = c; s->jr_val[nnz] = v; ++nnz; }
        }
      }
      s->jr_ptr[N] = (int)nnz;
      nnz = 0;
      for (c = 0; c < m; ++c)
        for (r = 0; r < N; ++r)
          if (sys->B[(size_t)r + (size_t)c * (size_t)N] != 0.0) ++nnz;
      s->b_row = phgmg__ialloc(&s->al, nnz);
      s->b_col = phgmg__ialloc(&s->al, nnz);
      s->b_val = phgmg__dalloc(&s->al, nnz);
      if (!s->b_row || !s->b_col || !s->b_val) { rc = PHGMG_ERR_NOMEM; goto fail; }
      s->nbnz = 0;
      for (c = 0; c < m; ++c)
        for (r = 0; r < N; ++r) {
          double v = sys->B[(size_t)r + (size_t)c * (size_t)N];
          if (v == 0.0) continue;
          s->b_row[s->nbnz] = r;
          s->b_col[s->nbnz] = c;
          s->b_val[s->nbnz] = v;
          s->nbnz++;
        }
    }
    if (s->mode == PHGMG__GL3_BANDED) {
      for (k = 0; k < s->djr.nd; ++k) {
        amin = PHGMG__MIN(amin, s->djr.off[k]);
        amax = PHGMG__MAX(amax, s->djr.off[k]);
      }
      for (k = 0; k < s->dq.nd; ++k) {
        bmin = PHGMG__MIN(bmin, s->dq.off[k]);
        bmax = PHGMG__MAX(bmax, s->dq.off[k]);
      }
      if (sys->nl == PHGMG_NL_GENERAL) {
        bmin = -kb;
        bmax = kb;
        rc = phgmg__dia_build(&s->al, &s->dh, N, kb, NULL, NULL, 1, 1);
        s->hband = phgmg__dalloc(&s->al, (size_t)(2 * kb + 1) * (size_t)N);
        if (rc != PHGMG_OK || !s->hband) { rc = PHGMG_ERR_NOMEM; goto fail; }
      }
      s->kl = PHGMG__MIN(N - 1, -(amin + bmin));
      s->ku = PHGMG__MIN(N - 1, amax + bmax);
      s->ldab = 2 * s->kl + s->ku + 1;
      s->AB1 = phgmg__dalloc(&s->al, (size_t)s->ldab * (size_t)N);
      s->AB2 = phgmg__dalloc(&s->al, 2 * (size_t)s->ldab * (size_t)N);
      s->dinv1 = phgmg__dalloc(&s->al, (size_t)N);
      s->dinv2 = phgmg__dalloc(&s->al, 2 * (size_t)N);
      s->ip1 = phgmg__ialloc(&s->al, (size_t)N);
      s->ip2 = phgmg__ialloc(&s->al, (size_t)N);
      if (!s->AB1 || !s->AB2 || !s->dinv1 || !s->dinv2 || !s->ip1 || !s->ip2) {
        rc = PHGMG_ERR_NOMEM;
        goto fail;
      }
    }
  }
  {
    size_t len = (size_t)N + (size_t)s->kl + (size_t)s->ku;
    s->r1buf = phgmg__dalloc(&s->al, len);
    s->rcbuf = phgmg__dalloc(&s->al, 2 * len);
    if (!s->r1buf || !s->rcbuf) { rc = PHGMG_ERR_NOMEM; goto fail; }
    memset(s->r1buf, 0, sizeof(double) * len);
    memset(s->rcbuf, 0, sizeof(double) * 2 * len);
    s->r1 = s->r1buf + s->kl;
    s->rc = s->rcbuf + 2 * (size_t)s->kl;
    if (s->mode == PHGMG__GL3_BANDED) {
      s->pk = phgmg__dalloc(&s->al, (size_t)3 * (size_t)(s->kl + s->ku + 1) * (size_t)N);
      if (!s->pk) { rc = PHGMG_ERR_NOMEM; goto fail; }
    }
  }
  s->need_factor = 1;
  *out = s;
  return PHGMG_OK;
fail:
  phgmg_gl3_destroy(s);
  return rc;
}

/* Banded: F_st = (J - R) G_st row by row from the CSR copy, + B u_st over the
   nonzero entries of B. */
PHGMG__PRIV void phgmg__gl3_rhs_csr(phgmg_gl3 *s) {
  int N = s->N, m = s->m, r, k;
  const int *ptr = s->jr_ptr, *col = s->jr_col;
  const double *val = s->jr_val, *U = s->U;
  const double *G0 = s->G, *G1 = s->G + N, *G2 = s->G + 2 * (size_t)N;
  double *F0 = s->F, *F1 = s->F + N, *F2 = s->F + 2 * (size_t)N;
  for (r = 0; r < N; ++r) {
    double a0 = 0.0, a1 = 0.0, a2 = 0.0;
    for (k = ptr[r]; k < ptr[r + 1]; ++k) {
      int j = col[k];
      double v = val[k];
      a0 = PHGMG__FMA(v, G0[j], a0);
      a1 = PHGMG__FMA(v, G1[j], a1);
      a2 = PHGMG__FMA(v, G2[j], a2);
    }
    F0[r] = a0;
    F1[r] = a1;
    F2[r] = a2;
  }
  for (k = 0; k < s->nbnz; ++k) {
    int r0 = s->b_row[k], c = s->b_col[k];
    double b = s->b_val[k];
    F0[r0] += b * U[c];
    F1[r0] += b * U[m + c];
    F2[r0] += b * U[2 * m + c];
  }
  s->st.rhs_evals += 3;
}

/* Evaluate the stages at Y_i = x + Z_i: gradients G_i and right-hand sides F_i
   (Y_i is formed only where a callback or a dense product needs it). */
PHGMG__PRIV void phgmg__gl3_eval(phgmg_gl3 *s, const double *x) {
  const phgmg_ph_system *sys = &s->sys;
  int N = s->N, m = s->m, st, i, k;
  int qdiag = sys->storage == PHGMG_BANDED && s->dq.nd == 1;
  int need_y = !qdiag || sys->nl == PHGMG_NL_GENERAL;
  if (need_y)
    for (st = 0; st < 3; ++st) {
      const double *z = s->Z + (size_t)st * (size_t)N;
      double *y = s->Y + (size_t)st * (size_t)N;
      for (i = 0; i < N; ++i) y[i] = x[i] + z[i];
    }
  if (sys->storage == PHGMG_DENSE) {
    phgmg_gemm('N', 'N', N, 3, N, 1.0, sys->Q, N, s->Y, N, 0.0, s->G, N);
  } else if (qdiag) { /* Q diagonal: G = q .* (x + Z) in one pass */
    const double *qd = s->dq.v;
    if (s->wc) { /* ... plus the polynomial, coordinate-wise, three stages per pass */
      const double *wc = s->wc, *dp = s->dpoly;
      const double *z0 = s->Z, *z1 = s->Z + N, *z2 = s->Z + 2 * (size_t)N;
      double *g0 = s->G, *g1 = s->G + N, *g2 = s->G + 2 * (size_t)N;
      int deg = sys->poly_deg;
      for (i = 0; i < N; ++i) {
        double xi = x[i], q = qd[i], w = wc[i];
        double y0 = xi + z0[i], y1 = xi + z1[i], y2 = xi + z2[i];
        if (w != 0.0) {
          double p0 = dp[deg - 1], p1 = p0, p2 = p0;
          int j;
          for (j = deg - 2; j >= 0; --j) {
            double c = dp[j];
            p0 = PHGMG__FMA(p0, y0, c);
            p1 = PHGMG__FMA(p1, y1, c);
            p2 = PHGMG__FMA(p2, y2, c);
          }
          g0[i] = PHGMG__FMA(w, p0, q * y0);
          g1[i] = PHGMG__FMA(w, p1, q * y1);
          g2[i] = PHGMG__FMA(w, p2, q * y2);
        } else {
          g0[i] = q * y0;
          g1[i] = q * y1;
          g2[i] = q * y2;
        }
      }
      phgmg__gl3_rhs_csr(s);
      return;
    }
    for (st = 0; st < 3; ++st) {
      const double *z = s->Z + (size_t)st * (size_t)N;
      double *g = s->G + (size_t)st * (size_t)N;
      for (i = 0; i < N; ++i) g[i] = qd[i] * (x[i] + z[i]);
    }
  } else {
    for (st = 0; st < 3; ++st)
      phgmg__dia_mv(&s->dq, s->Y + (size_t)st * (size_t)N, s->G + (size_t)st * (size_t)N);
  }
  for (st = 0; st < 3; ++st) {
    const double *z = s->Z + (size_t)st * (size_t)N;
    double *g = s->G + (size_t)st * (size_t)N;
    if (sys->nl == PHGMG_NL_SEPARABLE) {
      const int *idx = sys->sep_idx;
      const double *w = sys->sep_w;
      if (sys->poly_deg > 0) {
        int deg = sys->poly_deg;
        const double *dp = s->dpoly;
        for (k = 0; k < sys->nsep; ++k) {
          int ix = idx[k], j;
          double v = x[ix] + z[ix], acc = dp[deg - 1];
          for (j = deg - 2; j >= 0; --j) acc = acc * v + dp[j];
          g[ix] += w ? w[k] * acc : acc;
        }
      } else {
        for (k = 0; k < sys->nsep; ++k) {
          int ix = idx[k];
          double d1 = sys->dphi(k, x[ix] + z[ix], sys->user);
          g[ix] += w ? w[k] * d1 : d1;
        }
      }
    } else if (sys->nl == PHGMG_NL_GENERAL) {
      sys->grad_nl(s->Y + (size_t)st * (size_t)N, s->tmp, sys->user);
      for (i = 0; i < N; ++i) g[i] += s->tmp[i];
    }
  }
  if (sys->storage == PHGMG_BANDED) {
    phgmg__gl3_rhs_csr(s);
    return;
  }
  /* F = B U + (J - R) G */
  for (st = 0; st < 3; ++st) {
    double *f = s->F + (size_t)st * (size_t)N;
    const double *u = s->U + (size_t)st * (size_t)m;
    for (i = 0; i < N; ++i) f[i] = sys->B[i] * u[0];
    for (k = 1; k < m; ++k) {
      const double *bk = sys->B + (size_t)k * (size_t)N;
      double uk = u[k];
      if (uk == 0.0) continue;
      for (i = 0; i < N; ++i) f[i] += bk[i] * uk;
    }
  }
  phgmg_gemm('N', 'N', N, 3, N, 1.0, s->JR, N, s->G, N, 1.0, s->F, N);
  s->st.rhs_evals += 3;
}

/* Both band factorizations without row interchanges: the factors are repacked
   row by row, pk + j*P (P = 3(kl+ku+1)) = [L(j, j-kl .. j-1) real (kl),
   complex (2kl) | U(j, j+1 .. j+ku) / U(j,j) real (ku), complex (2ku) | 1/U(j,j) real,
   complex (2)], zeros outside the matrix; the right-hand sides carry kl zeros
   before and ku after, so the substitutions below run without bounds tests,
   the real and the complex one in the same sweep (their dependency chains
   overlap). */
PHGMG__PRIV void phgmg__gl3_pack_nopiv(phgmg_gl3 *s) {
  int n = s->N, kl = s->kl, ku = s->ku, kv = kl + ku, j, p;
  size_t P = 3 * (size_t)(kl + ku + 1), ld = (size_t)s->ldab;
  for (j = 0; j < n; ++j) {
    double *r = s->pk + (size_t)j * P;
    double *lr = r, *lc = r + kl, *ur = r + 3 * kl, *uc = r + 3 * kl + ku, *dg = r + 3 * (kl + ku);
    for (p = 0; p < kl; ++p) {
      int i = j - kl + p; /* L(j, i) in column i at row kv + j - i */
      size_t e = (size_t)(kv + j - i) + (size_t)i * ld;
      if (i < 0) { lr[p] = 0.0; lc[2 * p] = lc[2 * p + 1] = 0.0; continue; }
      lr[p] = s->AB1[e];
      lc[2 * p] = s->AB2[2 * e];
      lc[2 * p + 1] = s->AB2[2 * e + 1];
    }
    dg[0] = s->dinv1[j];
    dg[1] = s->dinv2[2 * j];
    dg[2] = s->dinv2[2 * j + 1];
    for (p = 0; p < ku; ++p) { /* U(j, i) / U(j, j), in column i at row kv + j - i */
      int i = j + 1 + p;
      size_t e = (size_t)(kv + j - i) + (size_t)i * ld;
      double vr, vi;
      if (i >= n) { ur[p] = 0.0; uc[2 * p] = uc[2 * p + 1] = 0.0; continue; }
      ur[p] = s->AB1[e] * dg[0];
      vr = s->AB2[2 * e];
      vi = s->AB2[2 * e + 1];
      uc[2 * p] = vr * dg[1] - vi * dg[2];
      uc[2 * p + 1] = vr * dg[2] + vi * dg[1];
    }
  }
}

PHGMG__PRIV void phgmg__gl3_solve_packed(const phgmg_gl3 *s, double *b, double *z) {
  int n = s->N, kl = s->kl, ku = s->ku, j, p;
  size_t P = 3 * (size_t)(kl + ku + 1);
  const double *r = s->pk;
  for (j = 0; j < n; ++j, r += P) {
    const double *lr = r, *lc = r + kl, *bb = b + j - kl, *zz = z + 2 * (j - kl);
    double t = b[j], tr = z[2 * j], ti = z[2 * j + 1];
    for (p = 0; p < kl; ++p) { /* the newest unknown comes last: short chains */
      double cr = lc[2 * p], ci = lc[2 * p + 1], xr = zz[2 * p], xi = zz[2 * p + 1];
      t = PHGMG__FMA(-lr[p], bb[p], t);
      tr = PHGMG__FMA(-cr, xr, tr) + ci * xi;
      ti = PHGMG__FMA(-cr, xi, ti) - ci * xr;
    }
    b[j] = t;
    z[2 * j] = tr;
    z[2 * j + 1] = ti;
  }
  r = s->pk + (size_t)(n - 1) * P;
  for (j = n - 1; j >= 0; --j, r -= P) {
    const double *ur = r + 3 * kl, *uc = ur + ku, *dg = uc + 2 * ku;
    const double *bb = b + j + 1, *zz = z + 2 * (j + 1);
    double br = z[2 * j], bi = z[2 * j + 1];
    double t = b[j] * dg[0], tr = br * dg[1] - bi * dg[2], ti = br * dg[2] + bi * dg[1];
    for (p = ku - 1; p >= 0; --p) {
      double cr = uc[2 * p], ci = uc[2 * p + 1], xr = zz[2 * p], xi = zz[2 * p + 1];
      t = PHGMG__FMA(-ur[p], bb[p], t);
      tr = PHGMG__FMA(-cr, xr, tr) + ci * xi;
      ti = PHGMG__FMA(-cr, xi, ti) - ci * xr;
    }
    b[j] = t;
    z[2 * j] = tr;
    z[2 * j + 1] = ti;
    if (j == 0) break; /* r would step before the array */
  }
}

/* (Re)factor the shifted Newton matrices at x. */
PHGMG__PRIV phgmg_result phgmg__gl3_factor(phgmg_gl3 *s, const double *x) {
  const phgmg_ph_system *sys = &s->sys;
  int N = s->N, i, j, k;
  double sg = s->gam / s->h, sa = s->alp / s->h, sb = -s->bet / s->h;
  phgmg_result rc;
  s->st.factorizations++;
  if (sys->nl == PHGMG_NL_SEPARABLE) {
    for (i = 0; i < N; ++i) s->dd[i] = 0.0;
    for (k = 0; k < sys->nsep; ++k) {
      int ix = sys->sep_idx[k];
      s->dd[ix] += (sys->sep_w ? sys->sep_w[k] : 1.0) * phgmg__ph_phi(sys, k, x[ix], 2);
    }
  }
  if (s->mode == PHGMG__GL3_CALLBACK) {
    rc = sys->shifted_factor(sg, 0.0, x, sys->shifted_user);
    if (rc == PHGMG_OK) rc = sys->shifted_factor(sa, sb, x, sys->shifted_user);
    return rc;
  }
  if (s->mode == PHGMG__GL3_DENSE) {
    size_t NN = (size_t)N * (size_t)N, e;
    /* K1 = -Jac */
    if (sys->nl == PHGMG_NL_GENERAL) {
      sys->hess_nl(x, s->Hs, sys->user);
      for (e = 0; e < NN; ++e) s->Hs[e] += sys->Q[e];
      phgmg_gemm('N', 'N', N, N, N, -1.0, s->JR, N, s->Hs, N, 0.0, s->K1, N);
    } else {
      for (e = 0; e < NN; ++e) s->K1[e] = -s->JRQ[e];
      if (sys->nl == PHGMG_NL_SEPARABLE)
        for (j = 0; j < N; ++j) {
          double dj = s->dd[j];
          const double *jc = s->JR + (size_t)j * (size_t)N;
          double *kc = s->K1 + (size_t)j * (size_t)N;
          if (dj == 0.0) continue;
          for (i = 0; i < N; ++i) kc[i] -= jc[i] * dj;
        }
    }
    for (e = 0; e < NN; ++e) { s->K2[2 * e] = s->K1[e]; s->K2[2 * e + 1] = 0.0; }
    for (i = 0; i < N; ++i) {
      size_t d = (size_t)i * (size_t)(N + 1);
      s->K1[d] += sg;
      s->K2[2 * d] += sa;
      s->K2[2 * d + 1] = sb;
    }
    rc = phgmg_lu_factor(N, s->K1, N, s->ip1);
    if (rc == PHGMG_OK) rc = phgmg_zlu_factor(N, s->K2, N, s->ip2);
    return rc;
  }
  /* banded */
  {
    int kv = s->kl + s->ku, ld = s->ldab;
    size_t tot = (size_t)ld * (size_t)N, e;
    memset(s->AB1, 0, sizeof(double) * tot);
    phgmg__dia_prod_band(&s->djr, &s->dq, NULL, -1.0, s->AB1, ld, kv);
    if (sys->nl == PHGMG_NL_SEPARABLE) {
      phgmg__dia_prod_band(&s->djr, NULL, s->dd, -1.0, s->AB1, ld, kv);
    } else if (sys->nl == PHGMG_NL_GENERAL) {
      sys->hess_nl(x, s->hband, sys->user);
      phgmg__dia_refill(&s->dh, sys->kb, s->hband);
      phgmg__dia_prod_band(&s->djr, &s->dh, NULL, -1.0, s->AB1, ld, kv);
    }
    for (e = 0; e < tot; ++e) { s->AB2[2 * e] = s->AB1[e]; s->AB2[2 * e + 1] = 0.0; }
    for (j = 0; j < N; ++j) {
      size_t d = (size_t)kv + (size_t)j * (size_t)ld;
      s->AB1[d] += sg;
      s->AB2[2 * d] += sa;
      s->AB2[2 * d + 1] = sb;
    }
    if (!phgmg__all_finite(s->AB1, tot)) return PHGMG_ERR_NANINF;
    rc = phgmg__gb_factor(N, s->kl, s->ku, s->AB1, ld, s->ip1, s->dinv1, &s->ue1);
    if (rc == PHGMG_OK)
      rc = phgmg__zgb_factor(N, s->kl, s->ku, s->AB2, ld, s->ip2, s->dinv2, &s->ue2);
    s->nopiv1 = s->nopiv2 = 1;
    for (j = 0; j < N && rc == PHGMG_OK; ++j) {
      if (s->ip1[j] != j) s->nopiv1 = 0;
      if (s->ip2[j] != j) s->nopiv2 = 0;
    }
    if (rc == PHGMG_OK && s->nopiv1 && s->nopiv2) phgmg__gl3_pack_nopiv(s);
    return rc;
  }
}

/* Solve with the real (K1) and the complex (K2) shifted matrix. */
PHGMG__PRIV void phgmg__gl3_solve_real(phgmg_gl3 *s, double *r) {
  if (s->mode == PHGMG__GL3_DENSE)
    phgmg_lu_solve('N', s->N, s->K1, s->N, s->ip1, 1, r, s->N);
  else if (s->mode == PHGMG__GL3_BANDED)
    phgmg__gb_solve('N', s->N, s->kl, s->ku, s->ue1, s->AB1, s->ldab, s->ip1, s->dinv1, r);
  else
    s->sys.shifted_solve(s->gam / s->h, 0.0, r, s->sys.shifted_user);
}
PHGMG__PRIV void phgmg__gl3_solve_cplx(phgmg_gl3 *s, double *r) {
  if (s->mode == PHGMG__GL3_DENSE)
    phgmg_zlu_solve(s->N, s->K2, s->N, s->ip2, 1, r, s->N);
  else if (s->mode == PHGMG__GL3_BANDED)
    phgmg__zgb_solve(s->N, s->kl, s->ku, s->ue2, s->AB2, s->ldab, s->ip2, s->dinv2, r);
  else
    s->sys.shifted_solve(s->alp / s->h, -s->bet / s->h, r, s->sys.shifted_user);
}

/* Simplified Newton on the transformed stage system from the guess in s->Z.
   fresh: the factors belong to this x (no early abort). On success s->Z, G, F
   hold the converged stages. */
PHGMG__PRIV phgmg_result phgmg__gl3_newton(phgmg_gl3 *s, const double *x, int fresh,
                                           double *theta_max, double *res_out) {
  int N = s->N, it = 0, ndiv = 0, i;
  double h = s->h, ih = 1.0 / s->h, res_prev = 0.0, theta = 0.0;
  double *Z0 = s->Z, *Z1 = s->Z + N, *Z2 = s->Z + 2 * (size_t)N;
  double *W0 = s->W, *W1 = s->W + N, *W2 = s->W + 2 * (size_t)N;
  const double *T = s->T, *Ti = s->Ti, *A = s->A;
  *theta_max = 0.0;
  for (i = 0; i < N; ++i) {
    double z0 = Z0[i], z1 = Z1[i], z2 = Z2[i];
    W0[i] = Ti[0] * z0 + Ti[1] * z1 + Ti[2] * z2;
    W1[i] = Ti[3] * z0 + Ti[4] * z1 + Ti[5] * z2;
    W2[i] = Ti[6] * z0 + Ti[7] * z1 + Ti[8] * z2;
  }
  for (;;) {
    const double *F0 = s->F, *F1 = s->F + N, *F2 = s->F + 2 * (size_t)N;
    double res = 0.0, chk = 0.0;
    double *r1 = s->r1, *rc = s->rc;
    const double a00 = h * A[0], a01 = h * A[1], a02 = h * A[2], a10 = h * A[3], a11 = h * A[4],
                 a12 = h * A[5], a20 = h * A[6], a21 = h * A[7], a22 = h * A[8];
    const double t00 = Ti[0], t01 = Ti[1], t02 = Ti[2], t10 = Ti[3], t11 = Ti[4], t12 = Ti[5],
                 t20 = Ti[6], t21 = Ti[7], t22 = Ti[8];
    const double gih = s->gam * ih, aih = s->alp * ih, bih = s->bet * ih;
    phgmg__gl3_eval(s, x);
    for (i = 0; i < N; ++i) { /* stage residual Z - h (A x I) F */
      double f0 = F0[i], f1 = F1[i], f2 = F2[i], e0, e1, e2;
      e0 = fabs(Z0[i] - PHGMG__FMA(a00, f0, PHGMG__FMA(a01, f1, a02 * f2)));
      e1 = fabs(Z1[i] - PHGMG__FMA(a10, f0, PHGMG__FMA(a11, f1, a12 * f2)));
      e2 = fabs(Z2[i] - PHGMG__FMA(a20, f0, PHGMG__FMA(a21, f1, a22 * f2)));
      chk += (e0 + e1) + e2; /* NaN/Inf detection */
      res = e0 > res ? e0 : res;
      res = e1 > res ? e1 : res;
      res = e2 > res ? e2 : res;
    }
    if (chk - chk != 0.0) return PHGMG_ERR_NANINF;
    if (it > 0) {
      theta = res_prev > 0.0 ? res / res_prev : 0.0;
      if (theta > *theta_max) *theta_max = theta;
      ndiv = theta >= 1.0 ? ndiv + 1 : 0;
    }
    *res_out = res;
    if (it >= 1 && res <= s->tol) return PHGMG_OK;
    if (it >= s->max_iter) return PHGMG_ERR_NOT_CONVERGED;
    if (it >= 1 && theta >= 1.0 && !fresh) return PHGMG_ERR_NOT_CONVERGED;
    if (ndiv >= 2) return PHGMG_ERR_NOT_CONVERGED;
    for (i = 0; i < N; ++i) { /* Newton right-hand sides in the transformed variables */
      double f0 = F0[i], f1 = F1[i], f2 = F2[i], w0 = W0[i], w1 = W1[i], w2 = W2[i];
      r1[i] = PHGMG__FMA(t00, f0, PHGMG__FMA(t01, f1, PHGMG__FMA(t02, f2, -gih * w0)));
      rc[2 * i] =
          PHGMG__FMA(t10, f0, PHGMG__FMA(t11, f1, PHGMG__FMA(t12, f2, -(aih * w1 + bih * w2))));
      rc[2 * i + 1] =
          PHGMG__FMA(t20, f0, PHGMG__FMA(t21, f1, PHGMG__FMA(t22, f2, bih * w1 - aih * w2)));
    }
    if (s->mode == PHGMG__GL3_BANDED && s->nopiv1 && s->nopiv2) {
      phgmg__gl3_solve_packed(s, s->r1, s->rc);
    } else {
      phgmg__gl3_solve_real(s, s->r1);
      phgmg__gl3_solve_cplx(s, s->rc);
    }
    {
      const double T00 = T[0], T01 = T[1], T02 = T[2], T10 = T[3], T11 = T[4], T12 = T[5],
                   T20 = T[6], T21 = T[7], T22 = T[8];
      const double *d1 = s->r1, *dc = s->rc;
      for (i = 0; i < N; ++i) {
        double w0 = W0[i] + d1[i], w1 = W1[i] + dc[2 * i], w2 = W2[i] + dc[2 * i + 1];
        W0[i] = w0; W1[i] = w1; W2[i] = w2;
        Z0[i] = PHGMG__FMA(T00, w0, PHGMG__FMA(T01, w1, T02 * w2));
        Z1[i] = PHGMG__FMA(T10, w0, PHGMG__FMA(T11, w1, T12 * w2));
        Z2[i] = PHGMG__FMA(T20, w0, PHGMG__FMA(T21, w1, T22 * w2));
      }
    }
    res_prev = res;
    ++it;
    s->st.newton_iters++;
  }
}

/* Supplied and dissipated energy over a step from the stage gradients s->G. */
PHGMG__PRIV void phgmg__gl3_energy(phgmg_gl3 *s, double energy_inc[2]) {
  const phgmg_ph_system *sys = &s->sys;
  int N = s->N, m = s->m, st, k, i;
  double sup = 0.0, dis = 0.0;
  for (st = 0; st < 3; ++st) {
    const double *g = s->G + (size_t)st * (size_t)N, *u = s->U + (size_t)st * (size_t)m;
    double yu = 0.0;
    for (k = 0; k < m; ++k) {
      const double *bk = sys->B + (size_t)k * (size_t)N;
      double yk = 0.0;
      for (i = 0; i < N; ++i) yk += bk[i] * g[i];
      yu += yk * u[k];
    }
    sup += s->b[st] * yu;
    dis += s->b[st] * phgmg__ph_quad(sys, sys->R, g, g);
  }
  energy_inc[0] = s->h * sup;
  energy_inc[1] = s->h * dis;
}

PHGMG__PRIV phgmg_result phgmg__gl3_step_map(phgmg_gl3 *s, const double *x, double energy_inc[2]) {
  int N = s->N, m = s->m, st;
  size_t NN = (size_t)N * (size_t)N;
  phgmg_gemv('N', N, N, 1.0, s->Phi, N, x, 0.0, s->xnew);
  phgmg_gemv('N', N, 3 * m, 1.0, s->Gam, N, s->U, 1.0, s->xnew);
  if (!phgmg__all_finite(s->xnew, (size_t)N)) return PHGMG_ERR_NANINF;
  if (energy_inc) {
    for (st = 0; st < 3; ++st) {
      double *g = s->G + (size_t)st * (size_t)N;
      phgmg_gemv('N', N, N, 1.0, s->GX + (size_t)st * NN, N, x, 0.0, g);
      phgmg_gemv('N', N, 3 * m, 1.0, s->GU + (size_t)st * (size_t)N * 3 * (size_t)m, N, s->U,
                 1.0, g);
    }
    phgmg__gl3_energy(s, energy_inc);
  }
  return PHGMG_OK;
}

/* Starting guess into s->Z: the previous step's collocation polynomial
   extrapolated to the new stage times, or zero. */
PHGMG__PRIV void phgmg__gl3_guess(phgmg_gl3 *s, int cont) {
  int N = s->N, st, i;
  if (!cont) {
    memset(s->Z, 0, sizeof(double) * 3 * (size_t)N);
    return;
  }
  for (st = 0; st < 3; ++st) {
    const double *P0 = s->Zprev, *P1 = s->Zprev + N, *P2 = s->Zprev + 2 * (size_t)N;
    double e0 = s->E[st * 3], e1 = s->E[st * 3 + 1], e2 = s->E[st * 3 + 2];
    double *z = s->Z + (size_t)st * (size_t)N;
    for (i = 0; i < N; ++i) z[i] = e0 * P0[i] + e1 * P1[i] + e2 * P2[i];
  }
}

PHGMG_DEF phgmg_result phgmg_gl3_step(phgmg_gl3 *s, double t, double *x, phgmg_input_fn uf,
                                      void *uuser, double energy_inc[2]) {
  int N, m, st, i, fresh = 0, cont;
  double theta = 0.0, res = 0.0;
  phgmg_result rc;
  if (!s || !x) return PHGMG_ERR_INVALID_ARG;
  N = s->N;
  m = s->m;
  for (st = 0; st < 3; ++st) {
    double *u = s->U + (size_t)st * (size_t)m;
    if (uf) uf(t + s->c[st] * s->h, u, uuser);
    else for (i = 0; i < m; ++i) u[i] = 0.0;
  }
  if (!phgmg__all_finite(s->U, 3 * (size_t)m)) return PHGMG_ERR_NANINF;
  if (s->mode == PHGMG__GL3_MAP) {
    rc = phgmg__gl3_step_map(s, x, energy_inc);
    if (rc != PHGMG_OK) { s->st.failures++; return rc; }
    memcpy(x, s->xnew, sizeof(double) * (size_t)N);
    s->st.steps++;
    return PHGMG_OK;
  }
  /* starting guess: extrapolate the previous collocation polynomial when this
     step continues the previous one */
  cont = s->have_prev && fabs(t - s->tend) <= 1e-6 * s->h + 4.0 * PHGMG__EPS * fabs(t) &&
         memcmp(x, s->xend, sizeof(double) * (size_t)N) == 0;
  if (s->need_factor) {
    rc = phgmg__gl3_factor(s, x);
    if (rc != PHGMG_OK) { s->st.failures++; return rc; }
    s->need_factor = 0;
    fresh = 1;
  }
  if (s->linear) fresh = 1; /* the Jacobian does not depend on x */
  phgmg__gl3_guess(s, cont);
  rc = phgmg__gl3_newton(s, x, fresh, &theta, &res);
  if (rc != PHGMG_OK && !fresh) {
    s->st.failures++;
    rc = phgmg__gl3_factor(s, x);
    if (rc != PHGMG_OK) { s->need_factor = 1; s->st.failures++; return rc; }
    fresh = 1;
    phgmg__gl3_guess(s, cont);
    rc = phgmg__gl3_newton(s, x, fresh, &theta, &res);
  }
  if (rc != PHGMG_OK) { s->st.failures++; return rc; }
  if (!s->linear && theta > s->contraction) s->need_factor = 1;
  {
    const double *F0 = s->F, *F1 = s->F + N, *F2 = s->F + 2 * (size_t)N;
    double hb0 = s->h * s->b[0], hb1 = s->h * s->b[1], hb2 = s->h * s->b[2], chk = 0.0;
    for (i = 0; i < N; ++i) {
      double v = x[i] + (hb0 * F0[i] + hb1 * F1[i] + hb2 * F2[i]);
      s->xnew[i] = v;
      chk += v;
    }
    if (chk - chk != 0.0) { s->st.failures++; return PHGMG_ERR_NANINF; }
  }
  if (energy_inc) phgmg__gl3_energy(s, energy_inc);
  { /* keep the converged stages for the next guess */
    double *t3 = s->Zprev;
    s->Zprev = s->Z;
    s->Z = t3;
  }
  memcpy(s->xend, s->xnew, sizeof(double) * (size_t)N);
  s->tend = t + s->h;
  s->have_prev = 1;
  memcpy(x, s->xnew, sizeof(double) * (size_t)N);
  s->st.steps++;
  if (res > s->st.max_residual) s->st.max_residual = res;
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_simulate(const phgmg_ph_system *sys, const double *x0, double t0,
                                      double dt, int nsteps, phgmg_input_fn uf, void *uuser,
                                      const phgmg_gl3_opts *opts, double *X, double *Y,
                                      const phgmg_energy *energy, phgmg_gl3_stats *stats,
                                      int *steps_done, const phgmg_allocator *alloc) {
  phgmg_gl3 *s = NULL;
  phgmg_result rc;
  double *x = NULL, *g = NULL, *tmp = NULL;
  int N, m, n, i, k, done = 0;
  if (steps_done) *steps_done = 0;
  if (stats) memset(stats, 0, sizeof *stats);
  if (!sys || !x0 || nsteps < 0) return PHGMG_ERR_INVALID_ARG;
  if (energy && (!energy->H || !energy->S || !energy->D)) return PHGMG_ERR_INVALID_ARG;
  rc = phgmg_gl3_create(&s, sys, dt, opts, alloc);
  if (rc != PHGMG_OK) return rc;
  N = sys->N;
  m = sys->m;
  x = phgmg__dalloc(alloc, (size_t)N);
  g = phgmg__dalloc(alloc, (size_t)N);
  tmp = phgmg__dalloc(alloc, (size_t)N);
  if (!x || !g || !tmp) { rc = PHGMG_ERR_NOMEM; goto done; }
  memcpy(x, x0, sizeof(double) * (size_t)N);
  for (n = 0;; ++n) {
    /* record grid point n */
    if (X) memcpy(X + (size_t)n * (size_t)N, x, sizeof(double) * (size_t)N);
    if (Y) {
      phgmg__ph_grad(sys, x, g, tmp);
      for (k = 0; k < m; ++k) {
        const double *bk = sys->B + (size_t)k * (size_t)N;
        double acc = 0.0;
        for (i = 0; i < N; ++i) acc += bk[i] * g[i];
        Y[(size_t)k + (size_t)n * (size_t)m] = acc;
      }
    }
    if (energy) {
      energy->H[n] = phgmg_ph_hamiltonian(sys, x);
      if (n == 0) { energy->S[0] = 0.0; energy->D[0] = 0.0; }
    }
    if (n == nsteps) break;
    {
      double inc[2] = {0.0, 0.0};
      rc = phgmg_gl3_step(s, t0 + (double)n * dt, x, uf, uuser, energy ? inc : NULL);
      if (rc != PHGMG_OK) break;
      if (energy) {
        energy->S[n + 1] = energy->S[n] + inc[0];
        energy->D[n + 1] = energy->D[n] + inc[1];
      }
      ++done;
    }
  }
done:
  if (stats) *stats = s->st;
  if (steps_done) *steps_done = done;
  phgmg__free(alloc, x);
  phgmg__free(alloc, g);
  phgmg__free(alloc, tmp);
  phgmg_gl3_destroy(s);
  return rc;
}

#endif /* PHGMG_NO_OFFLINE */
