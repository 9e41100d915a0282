
/* >>online (implementation) ============================================== */
/* Everything here is in phgmg_real, allocation-free and N-independent. */
#if PHGMG_REAL_IS_FLOAT
#define PHGMG__RABS(x) fabsf(x)
#define PHGMG__RSQRT(x) sqrtf(x)
#define PHGMG__REPS 1.1920929e-07f
#else
#define PHGMG__RABS(x) fabs(x)
#define PHGMG__RSQRT(x) sqrt(x)
#define PHGMG__REPS 2.220446049250313e-16
#endif
#define PHGMG__R(x) ((phgmg_real)(x))
#define PHGMG__ONLINE static PHGMG__UNUSED
/* base + o, or NULL when only sizes are wanted (NULL + o is undefined). */
#define PHGMG__CARVE(base, o) ((base) ? (base) + (o) : NULL)

PHGMG__ONLINE int phgmg__r_finite(const phgmg_real *a, int n) {
  phgmg_real acc = PHGMG__R(0);
  int i;
  for (i = 0; i < n; ++i) acc += a[i] * PHGMG__R(0);
  return acc == PHGMG__R(0);
}

/* y = A x (A: rows x cols, column-major, ld = rows); beta = 0 or 1 (accumulate). */
PHGMG__ONLINE void phgmg__r_gemv(int rows, int cols, const phgmg_real *A, const phgmg_real *x,
                                 int accumulate, phgmg_real *y) {
  int i, j;
  if (!accumulate) for (i = 0; i < rows; ++i) y[i] = PHGMG__R(0);
  for (j = 0; j < cols; ++j) {
    const phgmg_real xj = x[j];
    const phgmg_real *a = A + (size_t)j * (size_t)rows;
    if (xj == PHGMG__R(0)) continue;
    for (i = 0; i < rows; ++i) y[i] += a[i] * xj;
  }
}
/* y (+)= A^T x (A: rows x cols). */
PHGMG__ONLINE void phgmg__r_gemvt(int rows, int cols, const phgmg_real *A, const phgmg_real *x,
                                  int accumulate, phgmg_real *y) {
  int i, j;
  for (j = 0; j < cols; ++j) {
    const phgmg_real *a = A + (size_t)j * (size_t)rows;
    phgmg_real s = PHGMG__R(0);
    for (i = 0; i < rows; ++i) s += a[i] * x[i];
    y[j] = accumulate ? y[j] + s : s;
  }
}

/* LU with partial pivoting of an n x n matrix (ld n). 0 ok, -1 singular/non-finite. */
PHGMG__ONLINE int phgmg__r_lu(int n, phgmg_real *A, int *piv) {
  int i, j, k;
  for (k = 0; k < n; ++k) {
    int p = k;
    phgmg_real amax = PHGMG__RABS(A[k + k * n]);
    for (i = k + 1; i < n; ++i) {
      phgmg_real v = PHGMG__RABS(A[i + k * n]);
      if (v > amax) { amax = v; p = i; }
    }
    piv[k] = p;
    if (!(amax > PHGMG__R(0)) || amax - amax != PHGMG__R(0)) return -1;
    if (p != k)
      for (j = 0; j < n; ++j) { phgmg_real t = A[k + j * n]; A[k + j * n] = A[p + j * n]; A[p + j * n] = t; }
    {
      const phgmg_real inv = PHGMG__R(1) / A[k + k * n];
      for (i = k + 1; i < n; ++i) A[i + k * n] *= inv;
    }
    for (j = k + 1; j < n; ++j) {
      const phgmg_real akj = A[k + j * n];
      if (akj == PHGMG__R(0)) continue;
      for (i = k + 1; i < n; ++i) A[i + j * n] -= A[i + k * n] * akj;
    }
  }
  return 0;
}
PHGMG__ONLINE void phgmg__r_lu_solve(int n, const phgmg_real *LU, const int *piv, phgmg_real *b) {
  int i, j;
  for (i = 0; i < n; ++i)
    if (piv[i] != i) { phgmg_real t = b[i]; b[i] = b[piv[i]]; b[piv[i]] = t; }
  for (j = 0; j < n; ++j) {
    const phgmg_real bj = b[j];
    if (bj != PHGMG__R(0)) for (i = j + 1; i < n; ++i) b[i] -= LU[i + j * n] * bj;
  }
  for (j = n - 1; j >= 0; --j) {
    b[j] /= LU[j + j * n];
    if (b[j] != PHGMG__R(0)) for (i = 0; i < j; ++i) b[i] -= LU[i + j * n] * b[j];
  }
}

/* Polynomial phi(s) = sum_k c_k s^k and its first two derivatives. */
PHGMG__ONLINE void phgmg__r_poly(const phgmg_real *c, int deg, phgmg_real s, phgmg_real *v,
                                 phgmg_real *d1, phgmg_real *d2) {
  phgmg_real p0 = PHGMG__R(0), p1 = PHGMG__R(0), p2 = PHGMG__R(0);
  int k;
  for (k = deg; k >= 0; --k) {
    p2 = p2 * s + PHGMG__R(2) * p1;
    p1 = p1 * s + p0;
    p0 = p0 * s + c[k];
  }
  if (v) *v = p0;
  if (d1) *d1 = p1;
  if (d2) *d2 = p2;
}

PHGMG_DEF phgmg_result phgmg_rom_check(const phgmg_rom *rom) {
  if (!rom) return PHGMG_ERR_INVALID_ARG;
  if (rom->r < 1 || rom->m < 0 || rom->m > rom->r || rom->nd < 0 || rom->rn < 0)
    return PHGMG_ERR_SIZE;
  if (rom->r > 4096 || rom->nd > (1 << 24) || rom->rn > 4096) return PHGMG_ERR_SIZE;
  if (!rom->Qh || (rom->m > 0 && !rom->Bh)) return PHGMG_ERR_INVALID_ARG;
  if (rom->kind == PHGMG_ROM_LINEAR) {
    if (!rom->K || rom->rn != 0) return PHGMG_ERR_INVALID_ARG;
  } else if (rom->kind == PHGMG_ROM_QUADRATIC) {
    if (rom->rn < 1 || rom->r - rom->m < 1) return PHGMG_ERR_SIZE;
    if (!rom->G00 || !rom->G01 || !rom->G10 || !rom->G11 || !rom->Q01 || !rom->Q11 || !rom->Ms)
      return PHGMG_ERR_INVALID_ARG;
    if (rom->nd > 0 && !rom->P1) return PHGMG_ERR_INVALID_ARG;
  } else {
    return PHGMG_ERR_INVALID_ARG;
  }
  if (rom->nd > 0 && (!rom->P0 || !rom->w || !rom->poly || rom->poly_deg < 0 || rom->poly_deg > 32))
    return PHGMG_ERR_INVALID_ARG;
  if (rom->Phi && (!rom->Gam || !rom->SX || !rom->SU || !(rom->dt > PHGMG__R(0))))
    return PHGMG_ERR_INVALID_ARG;
  return PHGMG_OK;
}

/* Evaluation work: one layout function used by the size query and by every
   evaluator, so size and carving cannot drift. */
typedef struct phgmg__romw {
  phgmg_real *Lp, *q, *a1, *c, *d, *E, *t, *tmp, *xp, *fm, *g;
} phgmg__romw;

PHGMG__ONLINE size_t phgmg__romw_layout(const phgmg_rom *rom, phgmg_real *base, phgmg__romw *w) {
  const size_t r = (size_t)rom->r, rn = (size_t)rom->rn, nd = (size_t)rom->nd;
  size_t o = 0;
  phgmg__romw dummy;
  if (!w) w = &dummy;
  w->Lp = PHGMG__CARVE(base, o); o += rn * r;
  w->q = PHGMG__CARVE(base, o); o += rn;
  w->a1 = PHGMG__CARVE(base, o); o += rn;
  w->c = PHGMG__CARVE(base, o); o += nd;
  w->d = PHGMG__CARVE(base, o); o += nd;
  w->E = PHGMG__CARVE(base, o); o += r * r;
  w->t = PHGMG__CARVE(base, o); o += rn * r;
  w->tmp = PHGMG__CARVE(base, o); o += r;
  w->xp = PHGMG__CARVE(base, o); o += r;
  w->fm = PHGMG__CARVE(base, o); o += r;
  w->g = PHGMG__CARVE(base, o); o += r;
  return o;
}

PHGMG_DEF size_t phgmg_rom_eval_work_size(const phgmg_rom *rom) {
  return phgmg__romw_layout(rom, NULL, NULL);
}

/* q = M (x2 kron x2) via Lp (QUADRATIC), and the kept coordinates c. */
PHGMG__ONLINE void phgmg__rom_prep(const phgmg_rom *rom, const phgmg_real *x, const phgmg__romw *w) {
  const int r = rom->r, m = rom->m, rn = rom->rn, nd = rom->nd, p = r - m;
  int i, j, k;
  if (rom->kind == PHGMG_ROM_QUADRATIC) {
    const phgmg_real *x2 = x + m;
    for (k = 0; k < p; ++k) { /* Lp(:,k) = sum_j Ms(:, k*p + j) x2_j */
      phgmg_real *l = w->Lp + (size_t)k * rn;
      for (i = 0; i < rn; ++i) l[i] = PHGMG__R(0);
      for (j = 0; j < p; ++j) {
        const phgmg_real *ms = rom->Ms + ((size_t)k * p + j) * rn;
        const phgmg_real xj = x2[j];
        for (i = 0; i < rn; ++i) l[i] += ms[i] * xj;
      }
    }
    phgmg__r_gemv(rn, p, w->Lp, x2, 0, w->q);
    for (i = 0; i < rn; ++i) w->q[i] *= PHGMG__R(0.5);
  }
  if (nd > 0) {
    phgmg__r_gemv(nd, r, rom->P0, x, 0, w->c);
    if (rom->kind == PHGMG_ROM_QUADRATIC) phgmg__r_gemv(nd, rn, rom->P1, w->q, 1, w->c);
  }
}

PHGMG_DEF phgmg_real phgmg_rom_hamiltonian(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *work) {
  phgmg__romw w;
  phgmg_real h = PHGMG__R(0);
  const int r = rom->r, rn = rom->rn;
  int j;
  phgmg__romw_layout(rom, work, &w);
  phgmg__rom_prep(rom, x, &w);
  phgmg__r_gemv(r, r, rom->Qh, x, 0, w.tmp);
  if (rom->kind == PHGMG_ROM_QUADRATIC) {
    phgmg__r_gemv(r, rn, rom->Q01, w.q, 1, w.tmp);
    phgmg__r_gemv(r, rn, rom->Q01, w.q, 1, w.tmp); /* 2 x^T Q01 q */
    phgmg__r_gemv(rn, rn, rom->Q11, w.q, 0, w.a1);
    for (j = 0; j < rn; ++j) h += w.q[j] * w.a1[j];
  }
  for (j = 0; j < r; ++j) h += x[j] * w.tmp[j];
  h *= PHGMG__R(0.5);
  for (j = 0; j < rom->nd; ++j) {
    phgmg_real v;
    phgmg__r_poly(rom->poly, rom->poly_deg, w.c[j], &v, NULL, NULL);
    h += rom->w[j] * v;
  }
  return h;
}

/* grad H into g (g must not alias the work areas other than w->g). */
PHGMG__ONLINE void phgmg__rom_grad(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *g,
                                   const phgmg__romw *w) {
  const int r = rom->r, m = rom->m, rn = rom->rn, nd = rom->nd, p = r - m;
  int j;
  phgmg__rom_prep(rom, x, w);
  for (j = 0; j < nd; ++j) {
    phgmg_real d1;
    phgmg__r_poly(rom->poly, rom->poly_deg, w->c[j], NULL, &d1, NULL);
    w->d[j] = rom->w[j] * d1;
  }
  phgmg__r_gemv(r, r, rom->Qh, x, 0, g);
  if (nd > 0) phgmg__r_gemvt(nd, r, rom->P0, w->d, 1, g);
  if (rom->kind == PHGMG_ROM_QUADRATIC) {
    phgmg__r_gemv(r, rn, rom->Q01, w->q, 1, g);
    phgmg__r_gemvt(r, rn, rom->Q01, x, 0, w->a1); /* a1 = Q01^T x + Q11 q + P1^T d */
    phgmg__r_gemv(rn, rn, rom->Q11, w->q, 1, w->a1);
    if (nd > 0) phgmg__r_gemvt(nd, rn, rom->P1, w->d, 1, w->a1);
    phgmg__r_gemvt(rn, p, w->Lp, w->a1, 1, g + m); /* g2 += Lp^T a1 */
  }
}

PHGMG_DEF void phgmg_rom_gradient(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *g, phgmg_real *work) {
  phgmg__romw w;
  phgmg__romw_layout(rom, work, &w);
  phgmg__rom_grad(rom, x, g, &w);
}

PHGMG_DEF void phgmg_rom_output(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *y, phgmg_real *work) {
  phgmg__romw w;
  phgmg__romw_layout(rom, work, &w);
  phgmg__rom_grad(rom, x, w.g, &w);
  phgmg__r_gemvt(rom->r, rom->m, rom->Bh, w.g, 0, y);
}

/* E = D^T G D = G00 + G01 L + L^T (G10 + G11 L), L = [0, Lp] (QUADRATIC; Lp current). */
PHGMG__ONLINE void phgmg__rom_dgd(const phgmg_rom *rom, const phgmg__romw *w) {
  const int r = rom->r, m = rom->m, rn = rom->rn;
  phgmg_real *E = w->E, *t = w->t;
  int a, b, i;
  for (b = 0; b < r; ++b) {
    phgmg_real *tb = t + (size_t)b * rn;
    for (i = 0; i < rn; ++i) tb[i] = rom->G10[i + (size_t)b * rn];
    if (b >= m) phgmg__r_gemv(rn, rn, rom->G11, w->Lp + (size_t)(b - m) * rn, 1, tb);
  }
  for (b = 0; b < r * r; ++b) E[b] = rom->G00[b];
  for (b = m; b < r; ++b) phgmg__r_gemv(r, rn, rom->G01, w->Lp + (size_t)(b - m) * rn, 1, E + (size_t)b * r);
  for (b = 0; b < r; ++b)
    for (a = m; a < r; ++a) {
      const phgmg_real *la = w->Lp + (size_t)(a - m) * rn, *tb = t + (size_t)b * rn;
      phgmg_real s = PHGMG__R(0);
      for (i = 0; i < rn; ++i) s += la[i] * tb[i];
      E[a + (size_t)b * r] += s;
    }
}

/* Solve E z = b in place (E destroyed) by Gaussian elimination with partial
   pivoting, without pivot storage. 0 ok, -1 singular. */
PHGMG__ONLINE int phgmg__r_gesv1(int n, phgmg_real *E, phgmg_real *b) {
  int i, j, k;
  for (k = 0; k < n; ++k) {
    int pv = k;
    phgmg_real amax = PHGMG__RABS(E[k + k * n]);
    for (i = k + 1; i < n; ++i)
      if (PHGMG__RABS(E[i + k * n]) > amax) { amax = PHGMG__RABS(E[i + k * n]); pv = i; }
    if (!(amax > PHGMG__R(0)) || amax - amax != PHGMG__R(0)) return -1;
    if (pv != k) {
      phgmg_real tt;
      for (j = k; j < n; ++j) { tt = E[k + j * n]; E[k + j * n] = E[pv + j * n]; E[pv + j * n] = tt; }
      tt = b[k]; b[k] = b[pv]; b[pv] = tt;
    }
    for (i = k + 1; i < n; ++i) {
      const phgmg_real l = E[i + k * n] / E[k + k * n];
      if (l == PHGMG__R(0)) continue;
      for (j = k + 1; j < n; ++j) E[i + j * n] -= l * E[k + j * n];
      b[i] -= l * b[k];
    }
  }
  for (k = n - 1; k >= 0; --k) {
    phgmg_real s = b[k];
    for (j = k + 1; j < n; ++j) s -= E[k + j * n] * b[j];
    b[k] = s / E[k + k * n];
  }
  return 0;
}

/* f = K(x) grad H(x) + Bh u; grad H left in w->g. f must not alias work. */
PHGMG__ONLINE phgmg_result phgmg__rom_rhs(const phgmg_rom *rom, const phgmg_real *x, const phgmg_real *u,
                                          phgmg_real *f, const phgmg__romw *w) {
  const int r = rom->r;
  phgmg__rom_grad(rom, x, w->g, w);
  if (rom->kind == PHGMG_ROM_LINEAR) {
    phgmg__r_gemv(r, r, rom->K, w->g, 0, f);
  } else {
    int i;
    phgmg__rom_dgd(rom, w);
    for (i = 0; i < r; ++i) f[i] = w->g[i];
    if (phgmg__r_gesv1(r, w->E, f) != 0) return PHGMG_ERR_SINGULAR;
  }
  if (u && rom->m > 0) phgmg__r_gemv(r, rom->m, rom->Bh, u, 1, f);
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_rom_rhs(const phgmg_rom *rom, const phgmg_real *x, const phgmg_real *u,
                                     phgmg_real *f, phgmg_real *work) {
  phgmg__romw w;
  phgmg__romw_layout(rom, work, &w);
  return phgmg__rom_rhs(rom, x, u, f, &w);
}

PHGMG_DEF phgmg_result phgmg_rom_structure(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *Jr,
                                           phgmg_real *Rr, phgmg_real *work) {
  const int r = rom->r;
  int a, b;
  phgmg__romw w;
  phgmg__romw_layout(rom, work, &w);
  if (rom->kind == PHGMG_ROM_LINEAR) {
    for (b = 0; b < r * r; ++b) Jr[b] = rom->K[b];
  } else { /* K = E^{-1}, column by column */
    phgmg__rom_prep(rom, x, &w);
    for (b = 0; b < r; ++b) {
      phgmg__rom_dgd(rom, &w);
      for (a = 0; a < r; ++a) Jr[a + (size_t)b * r] = (a == b) ? PHGMG__R(1) : PHGMG__R(0);
      if (phgmg__r_gesv1(r, w.E, Jr + (size_t)b * r) != 0) return PHGMG_ERR_SINGULAR;
    }
  }
  for (b = 0; b < r; ++b)
    for (a = 0; a <= b; ++a) {
      const phgmg_real kab = Jr[a + (size_t)b * r], kba = Jr[b + (size_t)a * r];
      Rr[a + (size_t)b * r] = Rr[b + (size_t)a * r] = -PHGMG__R(0.5) * (kab + kba);
      Jr[a + (size_t)b * r] = PHGMG__R(0.5) * (kab - kba);
      Jr[b + (size_t)a * r] = -Jr[a + (size_t)b * r];
    }
  return PHGMG_OK;
}

/* Newton Jacobian df/dx. */
PHGMG__ONLINE phgmg_result phgmg__rom_jac(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *Jf,
                                          const phgmg__romw *w) {
  const int r = rom->r;
  int a, b, j;
  if (rom->kind == PHGMG_ROM_LINEAR) {
    /* Jf = K (Qh + P0^T diag(w phi''(c)) P0) */
    phgmg_real *Hs = w->E;
    phgmg__rom_prep(rom, x, w);
    for (j = 0; j < rom->nd; ++j) {
      phgmg_real d2;
      phgmg__r_poly(rom->poly, rom->poly_deg, w->c[j], NULL, NULL, &d2);
      w->d[j] = rom->w[j] * d2;
    }
    for (b = 0; b < r; ++b)
      for (a = 0; a < r; ++a) {
        phgmg_real s = rom->Qh[a + (size_t)b * r];
        for (j = 0; j < rom->nd; ++j)
          s += rom->P0[j + (size_t)a * rom->nd] * w->d[j] * rom->P0[j + (size_t)b * rom->nd];
        Hs[a + (size_t)b * r] = s;
      }
    for (b = 0; b < r; ++b) phgmg__r_gemv(r, r, rom->K, Hs + (size_t)b * r, 0, Jf + (size_t)b * r);
  } else {
    /* central differences of the right-hand side (u = 0; f is affine in u) */
#if PHGMG_REAL_IS_FLOAT
    const phgmg_real hrel = PHGMG__R(4.9e-3);
#else
    const phgmg_real hrel = PHGMG__R(6.06e-6);
#endif
    for (b = 0; b < r; ++b) {
      const phgmg_real hb = hrel * (PHGMG__R(1) + PHGMG__RABS(x[b]));
      phgmg_real *col = Jf + (size_t)b * r;
      phgmg_result rc;
      for (a = 0; a < r; ++a) w->xp[a] = x[a];
      w->xp[b] = x[b] + hb;
      rc = phgmg__rom_rhs(rom, w->xp, NULL, col, w);
      if (rc != PHGMG_OK) return rc;
      w->xp[b] = x[b] - hb;
      rc = phgmg__rom_rhs(rom, w->xp, NULL, w->fm, w);
      if (rc != PHGMG_OK) return rc;
      for (a = 0; a < r; ++a) col[a] = (col[a] - w->fm[a]) / (PHGMG__R(2) * hb);
    }
  }
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_rom_jacobian(const phgmg_rom *rom, const phgmg_real *x, phgmg_real *Jf,
                                          phgmg_real *work) {
  phgmg__romw w;
  phgmg__romw_layout(rom, work, &w);
  return phgmg__rom_jac(rom, x, Jf, &w);
}

/* --- online GL3 stepper ------------------------------------------------- */
typedef struct phgmg__romstep_mem {
  phgmg_real *A, *b, *c, *lag; /* GL3 tableau (row-major A), extrapolation weights 3x4 */
  phgmg_real *LU, *Jf, *Z, *F, *Res, *dZ, *Zp, *G, *Y, *work;
  int *piv;
} phgmg__romstep_mem;

/* Two layouts: the full one for Newton, and a small one when the model is
   stepped with its precomputed step map (no stage system, no LU). */
PHGMG__ONLINE size_t phgmg__romstep_layout(const phgmg_rom *rom, int map_only, void *mem, phgmg__romstep_mem *L) {
  const size_t r = (size_t)rom->r, n3 = 3 * r;
  phgmg_real *base = PHGMG__CAST(phgmg_real *, mem);
  size_t o = 0, reals;
  phgmg__romstep_mem dummy;
  if (!L) L = &dummy;
  L->A = PHGMG__CARVE(base, o); o += 9;
  L->b = PHGMG__CARVE(base, o); o += 3;
  L->c = PHGMG__CARVE(base, o); o += 3;
  L->lag = PHGMG__CARVE(base, o); o += 12;
  L->LU = PHGMG__CARVE(base, o); o += map_only ? 0 : n3 * n3;
  L->Jf = PHGMG__CARVE(base, o); o += map_only ? 0 : r * r;
  L->Z = PHGMG__CARVE(base, o); o += n3;
  L->F = PHGMG__CARVE(base, o); o += n3;
  L->Res = PHGMG__CARVE(base, o); o += map_only ? 0 : n3;
  L->dZ = PHGMG__CARVE(base, o); o += map_only ? r : n3;
  L->Zp = PHGMG__CARVE(base, o); o += map_only ? 0 : n3;
  L->G = PHGMG__CARVE(base, o); o += n3;
  L->Y = PHGMG__CARVE(base, o); o += r;
  L->work = PHGMG__CARVE(base, o); o += map_only ? 0 : phgmg_rom_eval_work_size(rom);
  reals = o;
  L->piv = mem ? PHGMG__CAST(int *, PHGMG__CAST(void *, base + reals)) : NULL;
  return reals * sizeof(phgmg_real) + (map_only ? 0 : n3 * sizeof(int));
}

/* Does stepping with dt use the model's precomputed step map? */
PHGMG__ONLINE int phgmg__rom_uses_map(const phgmg_rom *rom, phgmg_real dt) {
  return rom->Phi != NULL && rom->kind == PHGMG_ROM_LINEAR && rom->nd == 0 &&
         PHGMG__RABS(rom->dt - dt) <= PHGMG__R(8) * PHGMG__REPS * dt;
}

PHGMG_DEF size_t phgmg_rom_stepper_memsize(const phgmg_rom *rom) {
  if (phgmg_rom_check(rom) != PHGMG_OK) return 0;
  return phgmg__romstep_layout(rom, phgmg__rom_uses_map(rom, rom->dt), NULL, NULL);
}

PHGMG_DEF size_t phgmg_rom_stepper_memsize_dt(const phgmg_rom *rom, phgmg_real dt) {
  if (phgmg_rom_check(rom) != PHGMG_OK) return 0;
  return phgmg__romstep_layout(rom, phgmg__rom_uses_map(rom, dt), NULL, NULL);
}

PHGMG_DEF void phgmg_rom_stage_times(phgmg_real t, phgmg_real dt, phgmg_real tc[3]) {
  const double s = sqrt(15.0) / 10.0;
  tc[0] = t + dt * PHGMG__R(0.5 - s);
  tc[1] = t + dt * PHGMG__R(0.5);
  tc[2] = t + dt * PHGMG__R(0.5 + s);
}

PHGMG_DEF phgmg_result phgmg_rom_stepper_init(phgmg_rom_stepper *s, const phgmg_rom *rom, phgmg_real dt,
                                              phgmg_real tol, int max_iter, void *mem, size_t mem_size) {
  phgmg__romstep_mem L;
  phgmg_result rc;
  double A[9], c[3], b[3], s15 = sqrt(15.0);
  int i, j, k, use_map;
  if (!s || !mem) return PHGMG_ERR_INVALID_ARG;
  rc = phgmg_rom_check(rom);
  if (rc != PHGMG_OK) return rc;
  if (!(dt > PHGMG__R(0)) || dt - dt != PHGMG__R(0)) return PHGMG_ERR_INVALID_ARG;
  if (((size_t)mem) % sizeof(double) != 0) return PHGMG_ERR_INVALID_ARG;
  use_map = phgmg__rom_uses_map(rom, dt);
  if (mem_size < phgmg__romstep_layout(rom, use_map, NULL, NULL)) return PHGMG_ERR_WORKSPACE;
  phgmg__romstep_layout(rom, use_map, mem, &L);
  /* Gauss-Legendre 3 from the closed forms */
  c[0] = 0.5 - s15 / 10.0; c[1] = 0.5; c[2] = 0.5 + s15 / 10.0;
  b[0] = 5.0 / 18.0; b[1] = 4.0 / 9.0; b[2] = 5.0 / 18.0;
  A[0] = 5.0 / 36.0;             A[1] = 2.0 / 9.0 - s15 / 15.0; A[2] = 5.0 / 36.0 - s15 / 30.0;
  A[3] = 5.0 / 36.0 + s15 / 24.0; A[4] = 2.0 / 9.0;            A[5] = 5.0 / 36.0 - s15 / 24.0;
  A[6] = 5.0 / 36.0 + s15 / 30.0; A[7] = 2.0 / 9.0 + s15 / 15.0; A[8] = 5.0 / 36.0;
  for (i = 0; i < 9; ++i) L.A[i] = PHGMG__R(A[i]);
  for (i = 0; i < 3; ++i) { L.b[i] = PHGMG__R(b[i]); L.c[i] = PHGMG__R(c[i]); }
  /* Lagrange weights of the collocation polynomial (nodes 0, c1, c2, c3)
     evaluated at 1 + c_k: lag[k*4 + j] */
  for (k = 0; k < 3; ++k) {
    const double nodes[4] = {0.0, c[0], c[1], c[2]};
    const double tt = 1.0 + c[k];
    for (j = 0; j < 4; ++j) {
      double l = 1.0;
      for (i = 0; i < 4; ++i)
        if (i != j) l *= (tt - nodes[i]) / (nodes[j] - nodes[i]);
      L.lag[k * 4 + j] = PHGMG__R(l);
    }
  }
  s->rom = rom;
  s->dt = dt;
#if PHGMG_REAL_IS_FLOAT
  s->tol = tol > PHGMG__R(0) ? tol : PHGMG__R(1e-5);
#else
  s->tol = tol > PHGMG__R(0) ? tol : PHGMG__R(1e-10);
#endif
  s->max_iter = max_iter > 0 ? max_iter : 10;
  s->use_map = use_map;
  s->have_lu = 0;
  s->have_prev = 0;
  s->ws = PHGMG__CAST(phgmg_real *, mem);
  s->ws_count = mem_size / sizeof(phgmg_real);
  memset(&s->stats, 0, sizeof s->stats);
  return PHGMG_OK;
}

PHGMG_DEF void phgmg_rom_stepper_reset(phgmg_rom_stepper *s) { s->have_prev = 0; }

/* Stage residual Res = Z - h (A kron I) F(x + Z); returns inf-norm, or -1 on
   failure (non-finite or singular). Stage gradients into G. */
PHGMG__ONLINE phgmg_real phgmg__romstep_residual(phgmg_rom_stepper *s, const phgmg__romstep_mem *L,
                                                 const phgmg_real *x, const phgmg_real *u3,
                                                 phgmg_result *err) {
  const phgmg_rom *rom = s->rom;
  const int r = rom->r, m = rom->m;
  phgmg__romw w;
  phgmg_real nrm = PHGMG__R(0);
  int i, j, a;
  phgmg__romw_layout(rom, L->work, &w);
  for (i = 0; i < 3; ++i) {
    phgmg_result rc;
    for (a = 0; a < r; ++a) L->Y[a] = x[a] + L->Z[i * r + a];
    rc = phgmg__rom_rhs(rom, L->Y, u3 ? u3 + i * m : NULL, L->F + i * r, &w);
    if (rc != PHGMG_OK) { *err = rc; return PHGMG__R(-1); }
    for (a = 0; a < r; ++a) L->G[i * r + a] = w.g[a];
  }
  for (i = 0; i < 3; ++i)
    for (a = 0; a < r; ++a) {
      phgmg_real v = L->Z[i * r + a];
      for (j = 0; j < 3; ++j) v -= s->dt * L->A[i * 3 + j] * L->F[j * r + a];
      L->Res[i * r + a] = v;
      if (PHGMG__RABS(v) > nrm) nrm = PHGMG__RABS(v);
    }
  if (!phgmg__r_finite(L->Res, 3 * r) || !phgmg__r_finite(L->G, 3 * r)) { *err = PHGMG_ERR_NANINF; return PHGMG__R(-1); }
  return nrm;
}

/* Factor I - h (A kron Jf(x)). */
PHGMG__ONLINE phgmg_result phgmg__romstep_factor(phgmg_rom_stepper *s, const phgmg__romstep_mem *L,
                                                 const phgmg_real *x) {
  const phgmg_rom *rom = s->rom;
  const int r = rom->r, n3 = 3 * r;
  phgmg__romw w;
  phgmg_result rc;
  int i, j, a, b;
  phgmg__romw_layout(rom, L->work, &w);
  rc = phgmg__rom_jac(rom, x, L->Jf, &w);
  if (rc != PHGMG_OK) return rc;
  if (!phgmg__r_finite(L->Jf, r * r)) return PHGMG_ERR_NANINF;
  for (j = 0; j < 3; ++j)
    for (b = 0; b < r; ++b)
      for (i = 0; i < 3; ++i)
        for (a = 0; a < r; ++a)
          L->LU[(i * r + a) + (size_t)(j * r + b) * n3] =
              ((i == j && a == b) ? PHGMG__R(1) : PHGMG__R(0)) - s->dt * L->A[i * 3 + j] * L->Jf[a + (size_t)b * r];
  s->stats.factorizations++;
  if (phgmg__r_lu(n3, L->LU, L->piv) != 0) { s->have_lu = 0; return PHGMG_ERR_SINGULAR; }
  s->have_lu = 1;
  return PHGMG_OK;
}

PHGMG__ONLINE phgmg_result phgmg__romstep_map(phgmg_rom_stepper *s, const phgmg__romstep_mem *L, phgmg_real *x,
                                              const phgmg_real *u3, phgmg_real *y, phgmg_real energy[2]) {
  const phgmg_rom *rom = s->rom;
  const int r = rom->r, m = rom->m, n3 = 3 * r;
  phgmg_real *xn = L->dZ;
  int i, a;
  phgmg__r_gemv(r, r, rom->Phi, x, 0, xn);
  if (u3 && m > 0) phgmg__r_gemv(r, 3 * m, rom->Gam, u3, 1, xn);
  if (!phgmg__r_finite(xn, r)) return PHGMG_ERR_NANINF;
  if (energy) {
    phgmg_real sup = PHGMG__R(0), dis = PHGMG__R(0);
    phgmg__r_gemv(n3, r, rom->SX, x, 0, L->Z);             /* stage values */
    if (u3 && m > 0) phgmg__r_gemv(n3, 3 * m, rom->SU, u3, 1, L->Z);
    for (i = 0; i < 3; ++i) {
      phgmg_real *gi = L->G + i * r, *ki = L->F + i * r, si = PHGMG__R(0), di = PHGMG__R(0);
      phgmg__r_gemv(r, r, rom->Qh, L->Z + i * r, 0, gi);
      phgmg__r_gemv(r, r, rom->K, gi, 0, ki);
      for (a = 0; a < r; ++a) di -= gi[a] * ki[a];
      if (u3 && m > 0) {
        phgmg__r_gemvt(r, m, rom->Bh, gi, 0, L->Y);
        for (a = 0; a < m; ++a) si += L->Y[a] * u3[i * m + a];
      }
      sup += L->b[i] * si;
      dis += L->b[i] * di;
    }
    energy[0] += s->dt * sup;
    energy[1] += s->dt * dis;
  }
  for (a = 0; a < r; ++a) x[a] = xn[a];
  if (y) {
    phgmg__r_gemv(r, r, rom->Qh, x, 0, L->Y);
    phgmg__r_gemvt(r, m, rom->Bh, L->Y, 0, y);
  }
  (void)n3;
  s->stats.steps++;
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_rom_step(phgmg_rom_stepper *s, phgmg_real *x, const phgmg_real *u3,
                                      phgmg_real *y, phgmg_real energy[2]) {
  const phgmg_rom *rom;
  phgmg__romstep_mem L;
  int r, m, n3, attempt, i, a;
  phgmg_result err = PHGMG_OK;
  if (!s || !x || !s->rom) return PHGMG_ERR_INVALID_ARG;
  rom = s->rom;
  r = rom->r; m = rom->m; n3 = 3 * r;
  if (!phgmg__r_finite(x, r) || (u3 && !phgmg__r_finite(u3, 3 * m))) return PHGMG_ERR_NANINF;
  phgmg__romstep_layout(rom, s->use_map, s->ws, &L);
  if (s->use_map) return phgmg__romstep_map(s, &L, x, u3, y, energy);

  for (attempt = 0; attempt < 2; ++attempt) {
    phgmg_real res, res_prev = PHGMG__R(0), theta_max = PHGMG__R(0);
    int it = 0, fresh = 0, ok = 0;
    if (!s->have_lu || attempt > 0) {
      err = phgmg__romstep_factor(s, &L, x);
      if (err != PHGMG_OK) break;
      fresh = 1;
    }
    /* starting guess: extrapolated collocation polynomial, or zero */
    for (i = 0; i < n3; ++i) L.Z[i] = (s->have_prev && attempt == 0) ? L.Zp[i] : PHGMG__R(0);
    res = phgmg__romstep_residual(s, &L, x, u3, &err);
    if (res < PHGMG__R(0)) {
      if (err == PHGMG_ERR_NANINF && !fresh) continue; /* bad guess/factors: retry fresh */
      break;
    }
    while (res > s->tol && it < s->max_iter) {
      for (i = 0; i < n3; ++i) L.dZ[i] = -L.Res[i];
      phgmg__r_lu_solve(n3, L.LU, L.piv, L.dZ);
      for (i = 0; i < n3; ++i) L.Z[i] += L.dZ[i];
      ++it;
      s->stats.newton_iters++;
      res_prev = res;
      res = phgmg__romstep_residual(s, &L, x, u3, &err);
      if (res < PHGMG__R(0)) break;
      if (res_prev > PHGMG__R(0) && res / res_prev > theta_max) theta_max = res / res_prev;
    }
    if (res >= PHGMG__R(0) && res <= s->tol) ok = 1;
    if (!ok) {
      if (res >= PHGMG__R(0)) err = PHGMG_ERR_NOT_CONVERGED;
      s->have_lu = 0;
      if (fresh) break;   /* fresh factors did not help: give up */
      continue;           /* stale factors: retry once with fresh ones */
    }
    /* converged: energy, new state, extrapolation data */
    {
      phgmg_real *xn = L.dZ;
      for (a = 0; a < r; ++a) {
        phgmg_real v = x[a];
        for (i = 0; i < 3; ++i) v += s->dt * L.b[i] * L.F[i * r + a];
        xn[a] = v;
      }
      if (!phgmg__r_finite(xn, r)) { err = PHGMG_ERR_NANINF; break; }
      if (energy) {
        phgmg_real sup = PHGMG__R(0), dis = PHGMG__R(0);
        for (i = 0; i < 3; ++i) {
          const phgmg_real *gi = L.G + i * r, *fi = L.F + i * r;
          phgmg_real si = PHGMG__R(0), di = PHGMG__R(0);
          /* dissipation rate gradH^T R gradH = -gradH^T K gradH = -g^T (f - Bh u) */
          for (a = 0; a < r; ++a) di -= gi[a] * fi[a];
          if (u3 && m > 0) {
            phgmg__r_gemvt(r, m, rom->Bh, gi, 0, L.Y);
            for (a = 0; a < m; ++a) { si += L.Y[a] * u3[i * m + a]; di += L.Y[a] * u3[i * m + a]; }
          }
          sup += L.b[i] * si;
          dis += L.b[i] * di;
        }
        energy[0] += s->dt * sup;
        energy[1] += s->dt * dis;
      }
      /* Zp_k = p(1 + c_k) - x_new, p the collocation polynomial (nodes 0, c_i) */
      for (i = 0; i < 3; ++i)
        for (a = 0; a < r; ++a) {
          phgmg_real v = L.lag[i * 4] * x[a];
          int j;
          for (j = 0; j < 3; ++j) v += L.lag[i * 4 + 1 + j] * (x[a] + L.Z[j * r + a]);
          L.Zp[i * r + a] = v - xn[a];
        }
      for (a = 0; a < r; ++a) x[a] = xn[a];
      s->have_prev = 1;
      if (theta_max > PHGMG__R(0.5)) s->have_lu = 0; /* slow contraction: refactor next step */
      s->stats.steps++;
      if (y) phgmg_rom_output(rom, x, y, L.work);
      return PHGMG_OK;
    }
  }
  s->stats.failures++;
  s->have_prev = 0;
  return err == PHGMG_OK ? PHGMG_ERR_NOT_CONVERGED : err;
}
