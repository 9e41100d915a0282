
#ifndef PHGMG_NO_OFFLINE
/* >>pod / >>reduce (implementation) ======================================= */

/* A small owner list: every array of a phgmg_reduced is allocated through it,
   so destroy (and every error path) frees exactly what was allocated. */
#define PHGMG__MAXBUF 48
struct phgmg_reduced {
  phgmg_allocator alloc;
  int use_alloc;
  void *bufs[PHGMG__MAXBUF];
  int nbufs;
  int N, m, r, p, rn, nd, method, kind;
  double *V0, *V2;     /* N x r, N x rn                        */
  double *QB, *RB;     /* thin QR of B: N x m, m x m           */
  double *W;           /* N x r point reduction for SP1/SP2    */
  double *M;           /* rn x p^2                             */
  int *coord;          /* nd: coordinates of the kept terms    */
  const phgmg_ph_system *sys;
  /* double blocks (same meaning as the phgmg_rom fields) */
  double *Bh, *Qh, *K, *G00, *G01, *G10, *G11, *Q01, *Q11, *Ms, *P0, *P1, *w, *poly;
  double *Phi, *Gam, *SX, *SU;
  double map_dt;       /* step of the precomputed map          */
  phgmg_rom rom;       /* views into the phgmg_real copies     */
};

PHGMG__PRIV void *phgmg__red_alloc(phgmg_reduced *red, size_t bytes) {
  void *p;
  if (red->nbufs >= PHGMG__MAXBUF) return NULL;
  p = phgmg__alloc(red->use_alloc ? &red->alloc : NULL, bytes);
  if (p) red->bufs[red->nbufs++] = p;
  return p;
}
PHGMG__PRIV double *phgmg__red_d(phgmg_reduced *red, size_t n) {
  double *p = PHGMG__CAST(double *, phgmg__red_alloc(red, (n ? n : 1) * sizeof(double)));
  if (p) memset(p, 0, (n ? n : 1) * sizeof(double));
  return p;
}

PHGMG_DEF void phgmg_reduced_destroy(phgmg_reduced *red) {
  int i;
  phgmg_allocator a;
  int use;
  if (!red) return;
  a = red->alloc;
  use = red->use_alloc;
  for (i = 0; i < red->nbufs; ++i) phgmg__free(use ? &a : NULL, red->bufs[i]);
  phgmg__free(use ? &a : NULL, red);
}

PHGMG_DEF const phgmg_rom *phgmg_reduced_rom(const phgmg_reduced *red) { return red ? &red->rom : NULL; }
PHGMG_DEF int phgmg_reduced_N(const phgmg_reduced *red) { return red ? red->N : 0; }

/* C (m x n) = A^T B with A: k x m, B: k x n (column-major, tight). */
PHGMG__PRIV void phgmg__atb(int k, int m, int n, const double *A, const double *B, double *C) {
  phgmg_gemm('T', 'N', m, n, k, 1.0, A, k, B, k, 0.0, C, m);
}

PHGMG_DEF phgmg_result phgmg_pod(int N, int ns, const double *X, int ldx, int kmax, double tol,
                                 double *V, int ldv, double *S, int *k_out,
                                 const phgmg_allocator *alloc) {
  double *s;
  int k = 0, rank = 0, i;
  phgmg_result rc;
  if (!X || !V || !k_out) return PHGMG_ERR_INVALID_ARG;
  if (N < 1 || ns < 1 || kmax < 1 || ldx < N || ldv < N || kmax > PHGMG__MIN(N, ns)) return PHGMG_ERR_SIZE;
  s = phgmg__dalloc(alloc, (size_t)kmax);
  if (!s) return PHGMG_ERR_NOMEM;
  rc = phgmg_svd(N, ns, X, ldx, kmax, s, V, ldv, NULL, 1, &k, &rank, alloc);
  if (rc == PHGMG_OK) {
    if (tol > 0.0)
      for (i = 0; i < k; ++i)
        if (!(s[i] > tol * s[0])) { k = i; break; }
    for (i = 0; i < k && S; ++i) S[i] = s[i];
    *k_out = k;
  }
  phgmg__free(alloc, s);
  return rc;
}

/* Thin QR of B (N x m): QB (N x m) orthonormal, RB (m x m) upper triangular.
   PHGMG_ERR_RANK if B is rank deficient. */
PHGMG__PRIV phgmg_result phgmg__thin_qr(int N, int m, const double *B, double *QB, double *RB,
                                        const phgmg_allocator *alloc) {
  double *tau, *work;
  double rmax = 0.0;
  int i, j;
  phgmg_result rc;
  tau = phgmg__dalloc(alloc, (size_t)(2 * m + 1));
  if (!tau) return PHGMG_ERR_NOMEM;
  work = tau + m;
  for (j = 0; j < m; ++j) memcpy(QB + (size_t)j * N, B + (size_t)j * N, (size_t)N * sizeof(double));
  rc = phgmg_qr(N, m, QB, N, tau);
  if (rc == PHGMG_OK) {
    for (j = 0; j < m; ++j)
      for (i = 0; i < m; ++i) RB[i + j * m] = i <= j ? QB[i + (size_t)j * N] : 0.0;
    for (j = 0; j < m; ++j) rmax = PHGMG__MAX(rmax, fabs(RB[j + j * m]));
    for (j = 0; j < m; ++j)
      if (!(fabs(RB[j + j * m]) > 1e3 * PHGMG__EPS * (double)N * rmax)) rc = PHGMG_ERR_RANK;
    if (rc == PHGMG_OK) phgmg_qr_form_q(N, m, QB, N, tau, work);
  }
  phgmg__free(alloc, tau);
  return rc;
}

/* Y = (I - Q Q^T) X for Q (N x k orthonormal), X N x ns; tmp: k x ns. */
PHGMG__PRIV void phgmg__orth_remove(int N, int k, const double *Q, int ns, double *X, int ldx, double *tmp) {
  if (k < 1) return;
  phgmg_gemm('T', 'N', k, ns, N, 1.0, Q, N, X, ldx, 0.0, tmp, k);
  phgmg_gemm('N', 'N', N, ns, k, -1.0, Q, N, tmp, k, 1.0, X, ldx);
}

PHGMG_DEF phgmg_result phgmg_adjust_snapshots(int N, int m, const double *B, int ns, const double *X,
                                              int ldx, double *Xa, int ldxa, const phgmg_allocator *alloc) {
  double *QB, *tmp;
  phgmg_result rc;
  int j;
  if (!B || !X || !Xa) return PHGMG_ERR_INVALID_ARG;
  if (N < 1 || m < 1 || m > N || ns < 1 || ldx < N || ldxa < N) return PHGMG_ERR_SIZE;
  QB = phgmg__dalloc(alloc, (size_t)N * m + (size_t)m * m + (size_t)m * ns);
  if (!QB) return PHGMG_ERR_NOMEM;
  tmp = QB + (size_t)N * m;
  rc = phgmg__thin_qr(N, m, B, QB, tmp, alloc);
  if (rc == PHGMG_OK) {
    if (Xa != X)
      for (j = 0; j < ns; ++j) memcpy(Xa + (size_t)j * ldxa, X + (size_t)j * ldx, (size_t)N * sizeof(double));
    phgmg__orth_remove(N, m, QB, ns, Xa, ldxa, tmp + (size_t)m * m);
  }
  phgmg__free(alloc, QB);
  return rc;
}

/* Numerical rank floor of snapshots X: singular values at or below it are
   zero. Relative to X itself, not to the matrix being POD'd: the adjusted
   snapshots and the residual of a basis carry rounding noise of this size,
   and an SVD truncated relative to their own norm would count it as rank. */
PHGMG__PRIV double phgmg__rank_floor(int N, int ns, const double *X, int ldx) {
  return (double)PHGMG__MAX(N, ns) * PHGMG__EPS * phgmg_normf(N, ns, X, ldx);
}

PHGMG_DEF phgmg_result phgmg_pod_hierarchical(int N, int m, const double *B, int ns, const double *X,
                                              int ldx, int p, int rn, double *V1, double *V2,
                                              const phgmg_allocator *alloc) {
  double *Xa, *tmp, *S, rfloor;
  phgmg_result rc;
  int k = 0;
  if (!B || !X || !V1 || !V2) return PHGMG_ERR_INVALID_ARG;
  if (p < 1 || rn < 1 || p + rn + m > PHGMG__MIN(N, ns + m)) return PHGMG_ERR_SIZE;
  Xa = phgmg__dalloc(alloc, (size_t)N * ns + (size_t)p * ns + (size_t)p + (size_t)rn);
  if (!Xa) return PHGMG_ERR_NOMEM;
  tmp = Xa + (size_t)N * ns;
  S = tmp + (size_t)p * ns;
  rc = phgmg_adjust_snapshots(N, m, B, ns, X, ldx, Xa, N, alloc);
  rfloor = phgmg__rank_floor(N, ns, X, ldx);
  if (rc == PHGMG_OK) rc = phgmg_pod(N, ns, Xa, N, p, 0.0, V1, N, S, &k, alloc);
  if (rc == PHGMG_OK && (k < p || !(S[p - 1] > rfloor))) rc = PHGMG_ERR_SIZE;
  if (rc == PHGMG_OK) {
    phgmg__orth_remove(N, p, V1, ns, Xa, N, tmp);
    rc = phgmg_pod(N, ns, Xa, N, rn, 0.0, V2, N, S + p, &k, alloc);
    if (rc == PHGMG_OK && (k < rn || !(S[p + rn - 1] > rfloor))) rc = PHGMG_ERR_SIZE;
  }
  phgmg__free(alloc, Xa);
  return rc;
}

PHGMG_DEF phgmg_result phgmg_deim(int nterms, int ns, const double *F, int ldf, const double *sw,
                                  double tol, int kmax, int *pts, double *w, int *nd_out,
                                  int *nneg, double *sigma_ratio, const phgmg_allocator *alloc) {
  double *U, *S, *Ut, *tau, *work, *PU;
  int *jpvt, *ipiv;
  int k = 0, kk, rank = 0, i, j, neg = 0;
  phgmg_result rc;
  if (!F || !pts || !w || !nd_out) return PHGMG_ERR_INVALID_ARG;
  if (nterms < 1 || ns < 1 || ldf < nterms) return PHGMG_ERR_SIZE;
  if (!phgmg__mat_finite(nterms, ns, F, ldf)) return PHGMG_ERR_NANINF; /* padding rows are not data */
  if (tol <= 0.0) tol = 1e-8;
  kk = PHGMG__MIN(nterms, ns);
  if (kmax > 0) kk = PHGMG__MIN(kk, kmax + 1);
  U = phgmg__dalloc(alloc, (size_t)nterms * kk + (size_t)kk + (size_t)kk * nterms + (size_t)kk +
                               2 * (size_t)nterms + (size_t)kk * kk + (size_t)kk);
  jpvt = phgmg__ialloc(alloc, (size_t)nterms + (size_t)kk);
  if (!U || !jpvt) { phgmg__free(alloc, U); phgmg__free(alloc, jpvt); return PHGMG_ERR_NOMEM; }
  S = U + (size_t)nterms * kk;
  Ut = S + kk;
  tau = Ut + (size_t)kk * nterms;
  work = tau + kk;
  PU = work + 2 * (size_t)nterms;
  ipiv = jpvt + nterms;
  rc = phgmg_svd(nterms, ns, F, ldf, kk, S, U, nterms, NULL, 1, &k, &rank, alloc);
  if (rc == PHGMG_OK) {
    int keep = 0;
    for (i = 0; i < k; ++i) if (S[i] > tol * S[0]) keep = i + 1;
    if (kmax > 0 && keep > kmax) keep = kmax;
    if (keep < 1) keep = 1;
    if (sigma_ratio) *sigma_ratio = (keep < k && S[0] > 0.0) ? S[keep] / S[0] : 0.0;
    /* Q-DEIM: pivoted QR of U^T (keep x nterms); points = first keep pivots */
    for (j = 0; j < nterms; ++j)
      for (i = 0; i < keep; ++i) Ut[i + (size_t)j * keep] = U[j + (size_t)i * nterms];
    rc = phgmg_qrcp(keep, nterms, Ut, keep, tau, jpvt, work);
    if (rc == PHGMG_OK) {
      /* w = (P^T U)^{-T} U^T sw: solve (P^T U)^T w = U^T sw */
      for (i = 0; i < keep; ++i) pts[i] = jpvt[i];
      for (j = 0; j < keep; ++j)       /* PU = P^T U (keep x keep) */
        for (i = 0; i < keep; ++i) PU[i + (size_t)j * keep] = U[pts[i] + (size_t)j * nterms];
      for (j = 0; j < keep; ++j) {
        double sacc = 0.0;
        for (i = 0; i < nterms; ++i) sacc += U[i + (size_t)j * nterms] * (sw ? sw[i] : 1.0);
        w[j] = sacc;
      }
      rc = phgmg_lu_factor(keep, PU, keep, ipiv);
      if (rc == PHGMG_OK) {
        phgmg_lu_solve('T', keep, PU, keep, ipiv, 1, w, keep);
        for (i = 0; i < keep; ++i) if (w[i] < 0.0) ++neg;
        if (!phgmg__all_finite(w, (size_t)keep)) rc = PHGMG_ERR_NANINF;
        *nd_out = keep;
        if (nneg) *nneg = neg;
      }
    }
  }
  phgmg__free(alloc, U);
  phgmg__free(alloc, jpvt);
  return rc;
}

/* Lp (rn x p) = [sum_j Ms(:, k*p + j) x2_j]_k in double. */
PHGMG__PRIV void phgmg__lp_d(int rn, int p, const double *Ms, const double *x2, double *Lp) {
  int i, j, k;
  for (k = 0; k < p; ++k) {
    double *l = Lp + (size_t)k * rn;
    for (i = 0; i < rn; ++i) l[i] = 0.0;
    for (j = 0; j < p; ++j) {
      const double *ms = Ms + ((size_t)k * p + j) * rn;
      for (i = 0; i < rn; ++i) l[i] += ms[i] * x2[j];
    }
  }
}

/* E = G00 + G01 L + L^T (G10 + G11 L), L = [0, Lp]; tmp: rn x r. */
PHGMG__PRIV void phgmg__dgd_d(const phgmg_reduced *red, const double *Lp, double *E, double *tmp) {
  const int r = red->r, m = red->m, rn = red->rn;
  int a, b, i;
  for (b = 0; b < r; ++b) {
    for (i = 0; i < rn; ++i) tmp[i + (size_t)b * rn] = red->G10[i + (size_t)b * rn];
    if (b >= m) phgmg_gemv('N', rn, rn, 1.0, red->G11, rn, Lp + (size_t)(b - m) * rn, 1.0, tmp + (size_t)b * rn);
  }
  memcpy(E, red->G00, (size_t)r * r * sizeof(double));
  for (b = m; b < r; ++b) phgmg_gemv('N', r, rn, 1.0, red->G01, r, Lp + (size_t)(b - m) * rn, 1.0, E + (size_t)b * r);
  for (b = 0; b < r; ++b)
    for (a = m; a < r; ++a) {
      double s = 0.0;
      for (i = 0; i < rn; ++i) s += Lp[i + (size_t)(a - m) * rn] * tmp[i + (size_t)b * rn];
      E[a + (size_t)b * r] += s;
    }
}

/* rcond of an r x r matrix (copied). -1 on allocation failure. */
PHGMG__PRIV double phgmg__rcond_of(int n, const double *A, const phgmg_allocator *alloc) {
  double *LU = phgmg__dalloc(alloc, (size_t)n * n + 2 * (size_t)n);
  int *ip = phgmg__ialloc(alloc, 2 * (size_t)n);
  double rc = -1.0;
  if (LU && ip) {
    double anorm = phgmg_norm1(n, n, A, n);
    memcpy(LU, A, (size_t)n * n * sizeof(double));
    if (phgmg_lu_factor(n, LU, n, ip) == PHGMG_OK)
      rc = phgmg_lu_rcond(n, LU, n, ip, anorm, LU + (size_t)n * n, ip + n);
    else
      rc = 0.0;
  }
  phgmg__free(alloc, LU);
  phgmg__free(alloc, ip);
  return rc;
}

/* Inverse of an r x r matrix into Ainv. */
PHGMG__PRIV phgmg_result phgmg__inv(int n, const double *A, double *Ainv, const phgmg_allocator *alloc) {
  double *LU = phgmg__dalloc(alloc, (size_t)n * n);
  int *ip = phgmg__ialloc(alloc, (size_t)n);
  phgmg_result rc = PHGMG_ERR_NOMEM;
  int i;
  if (LU && ip) {
    memcpy(LU, A, (size_t)n * n * sizeof(double));
    rc = phgmg_lu_factor(n, LU, n, ip);
    if (rc == PHGMG_OK) {
      memset(Ainv, 0, (size_t)n * n * sizeof(double));
      for (i = 0; i < n; ++i) Ainv[i + (size_t)i * n] = 1.0;
      phgmg_lu_solve('N', n, LU, n, ip, n, Ainv, n);
    }
  }
  phgmg__free(alloc, LU);
  phgmg__free(alloc, ip);
  return rc;
}

PHGMG__PRIV double phgmg__poly_d1(const double *c, int deg, double s) {
  double p1 = 0.0, p0 = 0.0;
  int k;
  for (k = deg; k >= 0; --k) { p1 = p1 * s + p0; p0 = p0 * s + c[k]; }
  return p1;
}

/* The exact GL3 step map of x' = Jf x + Bh u (see phgmg_rom). */
PHGMG__PRIV phgmg_result phgmg__step_map(phgmg_reduced *red, double h, const phgmg_allocator *alloc) {
  const int r = red->r, m = red->m, n3 = 3 * r, nc = r + 3 * m;
  double c[3], b[3], A[9];
  double *Jf = phgmg__dalloc(alloc, (size_t)r * r + (size_t)n3 * n3 + (size_t)n3 * nc);
  int *ip = phgmg__ialloc(alloc, (size_t)n3);
  double *M3, *RH;
  phgmg_result rc = PHGMG_ERR_NOMEM;
  int i, j, a, bb;
  if (!Jf || !ip) goto done;
  M3 = Jf + (size_t)r * r;
  RH = M3 + (size_t)n3 * n3;
  phgmg_gl3_coefficients(c, b, A);
  phgmg_gemm('N', 'N', r, r, r, 1.0, red->K, r, red->Qh, r, 0.0, Jf, r);
  for (j = 0; j < 3; ++j)
    for (bb = 0; bb < r; ++bb)
      for (i = 0; i < 3; ++i)
        for (a = 0; a < r; ++a)
          M3[(i * r + a) + (size_t)(j * r + bb) * n3] = (i == j && a == bb ? 1.0 : 0.0) - h * A[i * 3 + j] * Jf[a + (size_t)bb * r];
  /* RH = [h (A kron Jf)(1 kron I),  h (A kron Bh)] */
  for (i = 0; i < 3; ++i) {
    for (bb = 0; bb < r; ++bb)
      for (a = 0; a < r; ++a) {
        double s = 0.0;
        for (j = 0; j < 3; ++j) s += A[i * 3 + j];
        RH[(i * r + a) + (size_t)bb * n3] = h * s * Jf[a + (size_t)bb * r];
      }
    for (j = 0; j < 3; ++j)
      for (bb = 0; bb < m; ++bb)
        for (a = 0; a < r; ++a)
          RH[(i * r + a) + (size_t)(r + j * m + bb) * n3] = h * A[i * 3 + j] * red->Bh[a + (size_t)bb * r];
  }
  rc = phgmg_lu_factor(n3, M3, n3, ip);
  if (rc != PHGMG_OK) goto done;
  phgmg_lu_solve('N', n3, M3, n3, ip, nc, RH, n3);
  rc = PHGMG_ERR_NOMEM;
  red->SX = phgmg__red_d(red, (size_t)n3 * r);
  red->SU = phgmg__red_d(red, (size_t)n3 * 3 * m);
  red->Phi = phgmg__red_d(red, (size_t)r * r);
  red->Gam = phgmg__red_d(red, (size_t)r * 3 * m);
  if (!red->SX || !red->SU || !red->Phi || !red->Gam) goto done;
  for (bb = 0; bb < r; ++bb)
    for (a = 0; a < n3; ++a) red->SX[a + (size_t)bb * n3] = RH[a + (size_t)bb * n3] + (a % r == bb ? 1.0 : 0.0);
  for (bb = 0; bb < 3 * m; ++bb)
    for (a = 0; a < n3; ++a) red->SU[a + (size_t)bb * n3] = RH[a + (size_t)(r + bb) * n3];
  /* Phi = I + h sum b_i Jf SX_i ; Gam = h sum b_i Jf SU_i + h [b_1 Bh, b_2 Bh, b_3 Bh] */
  for (a = 0; a < r; ++a) red->Phi[a + (size_t)a * r] = 1.0;
  for (i = 0; i < 3; ++i) {
    phgmg_gemm('N', 'N', r, r, r, h * b[i], Jf, r, red->SX + i * r, n3, 1.0, red->Phi, r);
    if (m > 0) phgmg_gemm('N', 'N', r, 3 * m, r, h * b[i], Jf, r, red->SU + i * r, n3, 1.0, red->Gam, r);
    for (bb = 0; bb < m; ++bb)
      for (a = 0; a < r; ++a) red->Gam[a + (size_t)(i * m + bb) * r] += h * b[i] * red->Bh[a + (size_t)bb * r];
  }
  rc = PHGMG_OK;
done:
  phgmg__free(alloc, Jf);
  phgmg__free(alloc, ip);
  return rc;
}

/* phgmg_real copy of a double array (NULL stays NULL). */
PHGMG__PRIV phgmg_result phgmg__to_real(phgmg_reduced *red, const double *src, size_t n, const phgmg_real **dst) {
  phgmg_real *d;
  size_t i;
  if (!src) { *dst = NULL; return PHGMG_OK; }
  d = PHGMG__CAST(phgmg_real *, phgmg__red_alloc(red, (n ? n : 1) * sizeof(phgmg_real)));
  if (!d) return PHGMG_ERR_NOMEM;
  for (i = 0; i < n; ++i) d[i] = (phgmg_real)src[i];
  *dst = d;
  return PHGMG_OK;
}

PHGMG__PRIV phgmg_result phgmg__publish(phgmg_reduced *red) {
  const size_t r = (size_t)red->r, m = (size_t)red->m, rn = (size_t)red->rn, nd = (size_t)red->nd;
  const size_t p = (size_t)red->p;
  phgmg_rom *o = &red->rom;
  phgmg_result rc = PHGMG_OK;
  memset(o, 0, sizeof *o);
  o->kind = red->kind; o->method = red->method; o->r = red->r; o->m = red->m;
  o->rn = red->rn; o->nd = red->nd; o->poly_deg = red->nd > 0 ? red->sys->poly_deg : 0;
#define PHGMG__PUB(field, n) if (rc == PHGMG_OK) rc = phgmg__to_real(red, red->field, (n), &o->field)
  PHGMG__PUB(Bh, r * m); PHGMG__PUB(Qh, r * r); PHGMG__PUB(K, r * r);
  PHGMG__PUB(G00, r * r); PHGMG__PUB(G01, r * rn); PHGMG__PUB(G10, rn * r); PHGMG__PUB(G11, rn * rn);
  PHGMG__PUB(Q01, r * rn); PHGMG__PUB(Q11, rn * rn); PHGMG__PUB(Ms, rn * p * p);
  PHGMG__PUB(P0, nd * r); PHGMG__PUB(P1, nd * rn); PHGMG__PUB(w, nd);
  PHGMG__PUB(poly, (size_t)(o->poly_deg + 1));
  PHGMG__PUB(Phi, r * r); PHGMG__PUB(Gam, r * 3 * m); PHGMG__PUB(SX, 3 * r * r); PHGMG__PUB(SU, 3 * r * 3 * m);
#undef PHGMG__PUB
  o->dt = red->Phi ? (phgmg_real)red->map_dt : (phgmg_real)0;
  return rc;
}

PHGMG_DEF phgmg_result phgmg_reduce(phgmg_reduced **out, const phgmg_ph_system *sys, const double *X,
                                    int ldx, int ns, const phgmg_reduce_opts *opts,
                                    phgmg_reduce_info *info, const phgmg_allocator *alloc) {
  phgmg_reduced *red = NULL;
  phgmg_jr_factor *jr = NULL;
  phgmg_reduce_info inf;
  phgmg_result rc;
  double *T1 = NULL, *T2 = NULL, *T3 = NULL; /* temporaries */
  int *pts = NULL;
  int N, m, r, p, rn = 0, k = 0, i, j, a;
  double lambda, degtol, rfloor;
  if (!out || !sys || !X || !opts) return PHGMG_ERR_INVALID_ARG;
  *out = NULL;
  memset(&inf, 0, sizeof inf);
  N = sys->N; m = sys->m; r = opts->r;
  if (N < 1 || m < 1 || ns < 1 || ldx < N) return PHGMG_ERR_SIZE;
  if (opts->method < PHGMG_METHOD_GMG_POD || opts->method > PHGMG_METHOD_SP2) return PHGMG_ERR_INVALID_ARG;
  if (opts->method == PHGMG_METHOD_GMG_POD || opts->method == PHGMG_METHOD_GMG_QM) {
    if (r <= m || r > N) return PHGMG_ERR_SIZE;
  } else if (r < 1 || r > N || r > ns) {
    return PHGMG_ERR_SIZE;
  }
  if (sys->nl == PHGMG_NL_GENERAL) return PHGMG_ERR_UNSUPPORTED;
  if (sys->nl == PHGMG_NL_SEPARABLE && (sys->poly_deg < 1 || !sys->poly)) return PHGMG_ERR_UNSUPPORTED;
  if (!phgmg__mat_finite(N, ns, X, ldx)) return PHGMG_ERR_NANINF; /* padding rows are not data */
  rc = phgmg_ph_validate(sys, 0.0, &inf.rcond_jr, alloc);
  if (rc != PHGMG_OK) return rc;
  lambda = opts->lambda == 0.0 ? 1e-3 : (opts->lambda < 0.0 ? 0.0 : opts->lambda);
  degtol = opts->degeneracy_tol > 0.0 ? opts->degeneracy_tol : 1e-12;
  rfloor = phgmg__rank_floor(N, ns, X, ldx);

  red = PHGMG__CAST(phgmg_reduced *, phgmg__alloc(alloc, sizeof(phgmg_reduced)));
  if (!red) return PHGMG_ERR_NOMEM;
  memset(red, 0, sizeof *red);
  if (alloc) { red->alloc = *alloc; red->use_alloc = 1; }
  red->N = N; red->m = m; red->r = r; red->method = opts->method; red->sys = sys;
  red->kind = opts->method == PHGMG_METHOD_GMG_QM ? PHGMG_ROM_QUADRATIC : PHGMG_ROM_LINEAR;
  p = (opts->method == PHGMG_METHOD_GMG_POD || opts->method == PHGMG_METHOD_GMG_QM) ? r - m : r;
  red->p = p;
  if (red->kind == PHGMG_ROM_QUADRATIC) {
    rn = opts->rn > 0 ? opts->rn : 8;
    /* the online q/Lp buffers of lift/dphi hold up to 64 x 64 */
    if (rn > N - r || rn > 64 || rn * p > 64 * 64) { rc = PHGMG_ERR_SIZE; goto fail; }
  }
  red->rn = rn;

#define PHGMG__NEED(ptr) do { if (!(ptr)) { rc = PHGMG_ERR_NOMEM; goto fail; } } while (0)
#define PHGMG__TRY(expr) do { rc = (expr); if (rc != PHGMG_OK) goto fail; } while (0)
  red->V0 = phgmg__red_d(red, (size_t)N * r); PHGMG__NEED(red->V0);
  red->QB = phgmg__red_d(red, (size_t)N * m); PHGMG__NEED(red->QB);
  red->RB = phgmg__red_d(red, (size_t)m * m); PHGMG__NEED(red->RB);
  PHGMG__TRY(phgmg__thin_qr(N, m, sys->B, red->QB, red->RB, alloc));
  T1 = phgmg__dalloc(alloc, (size_t)N * ns); PHGMG__NEED(T1);

  if (red->method == PHGMG_METHOD_GMG_POD || red->method == PHGMG_METHOD_GMG_QM) {
    double *S = NULL;
    /* V0 = [B, V1], V1 = POD of the adjusted snapshots X - B B^+ X */
    for (j = 0; j < ns; ++j) memcpy(T1 + (size_t)j * N, X + (size_t)j * ldx, (size_t)N * sizeof(double));
    T2 = phgmg__dalloc(alloc, (size_t)PHGMG__MAX(m, p + 1) * ns + (size_t)p + 2 + (size_t)rn); PHGMG__NEED(T2);
    phgmg__orth_remove(N, m, red->QB, ns, T1, N, T2);
    memcpy(red->V0, sys->B, (size_t)N * m * sizeof(double));
    S = T2 + (size_t)PHGMG__MAX(m, p + 1) * ns;
    if (opts->pod_basis) {
      if (opts->pod_cols < p + rn) { rc = PHGMG_ERR_SIZE; goto fail; }
      memcpy(red->V0 + (size_t)N * m, opts->pod_basis, (size_t)N * p * sizeof(double));
    } else {
      T3 = phgmg__dalloc(alloc, (size_t)N * (p + 1)); PHGMG__NEED(T3);
      PHGMG__TRY(phgmg_pod(N, ns, T1, N, PHGMG__MIN(p + 1, PHGMG__MIN(N, ns)), 0.0, T3, N, S, &k, alloc));
      if (k < p || !(S[p - 1] > rfloor)) { rc = PHGMG_ERR_SIZE; goto fail; } /* r - m > rank of the adjusted snapshots */
      memcpy(red->V0 + (size_t)N * m, T3, (size_t)N * p * sizeof(double));
      inf.pod_sigma_ratio = (k > p && S[0] > 0.0) ? S[p] / S[0] : 0.0;
      phgmg__free(alloc, T3); T3 = NULL;
    }
    if (red->kind == PHGMG_ROM_QUADRATIC) {
      double *Z2, *Rq, *Kt, *Rqt, *Mt;
      const int pp = p * p;
      /* residual of the linear part, then V2 = POD of it */
      phgmg__orth_remove(N, p, red->V0 + (size_t)N * m, ns, T1, N, T2);
      red->V2 = phgmg__red_d(red, (size_t)N * rn); PHGMG__NEED(red->V2);
      if (opts->pod_basis) {
        memcpy(red->V2, opts->pod_basis + (size_t)N * p, (size_t)N * rn * sizeof(double));
      } else {
        PHGMG__TRY(phgmg_pod(N, ns, T1, N, rn, 0.0, red->V2, N, S + p + 2, &k, alloc));
        if (k < rn || !(S[p + 1 + rn] > rfloor)) { rc = PHGMG_ERR_SIZE; goto fail; }
      }
      /* M by the ridge problem (eq. least_square_reg) over the reduced snapshot
         coordinates, in full Kronecker form. Columns (a,j) and (j,a) of
         x2 kron x2 are equal, so the (unique) ridge solution has
         M(:,(a,j)) = M(:,(j,a)); we solve the equivalent problem over the
         p(p+1)/2 distinct columns (off-diagonal ones scaled by sqrt 2, unknown
         t = sqrt 2 M(:,(a,j))) and expand. Same minimiser, 4x fewer flops. */
      {
        const int nc = p * (p + 1) / 2;
        const double s2 = sqrt(2.0);
        int c;
        T3 = phgmg__dalloc(alloc, (size_t)p * ns + (size_t)rn * ns + (size_t)ns * nc + (size_t)ns * rn + (size_t)nc * rn);
        PHGMG__NEED(T3);
        Z2 = T3; Rq = Z2 + (size_t)p * ns; Kt = Rq + (size_t)rn * ns; Rqt = Kt + (size_t)ns * nc; Mt = Rqt + (size_t)ns * rn;
        phgmg_gemm('T', 'N', p, ns, N, 1.0, red->V0 + (size_t)N * m, N, X, ldx, 0.0, Z2, p);
        phgmg_gemm('T', 'N', rn, ns, N, 1.0, red->V2, N, T1, N, 0.0, Rq, rn);
        for (i = 0; i < ns; ++i) {
          for (a = 0, c = 0; a < p; ++a)
            for (j = a; j < p; ++j, ++c)
              Kt[i + (size_t)c * ns] = (a == j ? 1.0 : s2) * Z2[a + (size_t)i * p] * Z2[j + (size_t)i * p];
          for (a = 0; a < rn; ++a) Rqt[i + (size_t)a * ns] = Rq[a + (size_t)i * rn];
        }
        PHGMG__TRY(phgmg_lstsq(ns, nc, rn, Kt, ns, Rqt, ns, lambda, Mt, nc, alloc));
        red->M = phgmg__red_d(red, (size_t)rn * pp); PHGMG__NEED(red->M);
        red->Ms = phgmg__red_d(red, (size_t)rn * pp); PHGMG__NEED(red->Ms);
        for (a = 0, c = 0; a < p; ++a)
          for (j = a; j < p; ++j, ++c)
            for (i = 0; i < rn; ++i) {
              const double t = Mt[c + (size_t)i * nc];
              const double v = a == j ? t : t / s2;
              red->M[i + (size_t)(a * p + j) * rn] = v;
              red->M[i + (size_t)(j * p + a) * rn] = v;
              red->Ms[i + (size_t)(a * p + j) * rn] = 2.0 * v;
              red->Ms[i + (size_t)(j * p + a) * rn] = 2.0 * v;
            }
      }
      phgmg__free(alloc, T3); T3 = NULL;
    }
    /* G-blocks through a factorization of J - R */
    PHGMG__TRY(phgmg_jr_factor_create(&jr, sys, NULL, alloc));
    phgmg__free(alloc, T2);
    T2 = phgmg__dalloc(alloc, (size_t)N * (r + rn)); PHGMG__NEED(T2);
    memcpy(T2, red->V0, (size_t)N * r * sizeof(double));
    if (rn) memcpy(T2 + (size_t)N * r, red->V2, (size_t)N * rn * sizeof(double));
    phgmg_jr_solve(jr, 'N', r + rn, T2, N);           /* T2 = G [V0, V2] */
    red->G00 = phgmg__red_d(red, (size_t)r * r); PHGMG__NEED(red->G00);
    phgmg__atb(N, r, r, red->V0, T2, red->G00);
    if (rn) {
      red->G01 = phgmg__red_d(red, (size_t)r * rn); PHGMG__NEED(red->G01);
      red->G10 = phgmg__red_d(red, (size_t)rn * r); PHGMG__NEED(red->G10);
      red->G11 = phgmg__red_d(red, (size_t)rn * rn); PHGMG__NEED(red->G11);
      phgmg__atb(N, r, rn, red->V0, T2 + (size_t)N * r, red->G01);
      phgmg__atb(N, rn, r, red->V2, T2, red->G10);
      phgmg__atb(N, rn, rn, red->V2, T2 + (size_t)N * r, red->G11);
    }
    red->Bh = phgmg__red_d(red, (size_t)r * m); PHGMG__NEED(red->Bh);
    for (j = 0; j < m; ++j) red->Bh[j + (size_t)j * r] = 1.0;
    /* non-degeneracy of D^T G D: at x = 0 and (QM) at every snapshot */
    inf.rcond_dgd = phgmg__rcond_of(r, red->G00, alloc);
    if (inf.rcond_dgd < 0.0) { rc = PHGMG_ERR_NOMEM; goto fail; }
    if (red->kind == PHGMG_ROM_QUADRATIC) {
      double *Lp, *E, *tmp, *x2;
      T3 = phgmg__dalloc(alloc, (size_t)rn * p + (size_t)r * r + (size_t)rn * r + (size_t)p); PHGMG__NEED(T3);
      Lp = T3; E = Lp + (size_t)rn * p; tmp = E + (size_t)r * r; x2 = tmp + (size_t)rn * r;
      for (i = 0; i < ns; ++i) {
        double rc_i;
        phgmg_gemv('T', N, p, 1.0, red->V0 + (size_t)N * m, N, X + (size_t)i * ldx, 0.0, x2);
        phgmg__lp_d(rn, p, red->Ms, x2, Lp);
        phgmg__dgd_d(red, Lp, E, tmp);
        rc_i = phgmg__rcond_of(r, E, alloc);
        if (rc_i < 0.0) { rc = PHGMG_ERR_NOMEM; goto fail; }
        if (rc_i < inf.rcond_dgd) inf.rcond_dgd = rc_i;
      }
      phgmg__free(alloc, T3); T3 = NULL;
    }
    if (!(inf.rcond_dgd >= degtol)) { rc = PHGMG_ERR_DEGENERATE; goto fail; }
    if (red->kind == PHGMG_ROM_LINEAR) {
      red->K = phgmg__red_d(red, (size_t)r * r); PHGMG__NEED(red->K);
      PHGMG__TRY(phgmg__inv(r, red->G00, red->K, alloc));
    }
  } else {
    /* SP1 / SP2: V0 = V_POD (r modes of X), W as in NUMERICS 6.3-6.4 */
    double *Vg, *Ainv, *A2;
    T3 = phgmg__dalloc(alloc, (size_t)N * r * 2 + 2 * (size_t)r * r + (size_t)r + 1); PHGMG__NEED(T3);
    Vg = T3; A2 = Vg + (size_t)N * r; Ainv = A2 + (size_t)r * r;
    if (opts->pod_basis) {
      if (opts->pod_cols < r) { rc = PHGMG_ERR_SIZE; goto fail; }
      memcpy(red->V0, opts->pod_basis, (size_t)N * r * sizeof(double));
    } else {
      PHGMG__TRY(phgmg_pod(N, ns, X, ldx, r, 0.0, red->V0, N, Ainv + (size_t)r * r, &k, alloc));
      if (k < r || !(Ainv[(size_t)r * r + r - 1] > rfloor)) { rc = PHGMG_ERR_SIZE; goto fail; }
    }
    if (red->method == PHGMG_METHOD_SP1) {
      phgmg_ph_apply(sys, 'Q', r, red->V0, N, Vg, N);   /* Vg := Q V */
    } else if (opts->grad_basis) {
      if (opts->grad_cols < r) { rc = PHGMG_ERR_SIZE; goto fail; }
      memcpy(Vg, opts->grad_basis, (size_t)N * r * sizeof(double));
    } else {
      for (j = 0; j < ns; ++j) phgmg_ph_gradient(sys, X + (size_t)j * ldx, T1 + (size_t)j * N);
      PHGMG__TRY(phgmg_pod(N, ns, T1, N, r, 0.0, Vg, N, Ainv + (size_t)r * r, &k, alloc));
      if (k < r || !(Ainv[(size_t)r * r + r - 1] > phgmg__rank_floor(N, ns, T1, N))) { rc = PHGMG_ERR_SIZE; goto fail; }
    }
    phgmg__atb(N, r, r, red->V0, Vg, A2);               /* V^T Vg */
    inf.rcond_dgd = phgmg__rcond_of(r, A2, alloc);
    if (inf.rcond_dgd < 0.0) { rc = PHGMG_ERR_NOMEM; goto fail; }
    if (!(inf.rcond_dgd >= degtol)) { rc = PHGMG_ERR_DEGENERATE; goto fail; }
    PHGMG__TRY(phgmg__inv(r, A2, Ainv, alloc));
    red->W = phgmg__red_d(red, (size_t)N * r); PHGMG__NEED(red->W);
    phgmg_gemm('N', 'N', N, r, r, 1.0, Vg, N, Ainv, r, 0.0, red->W, N); /* W = Vg (V^T Vg)^{-1} */
    /* K = W^T (J - R) W, Bh = W^T B */
    phgmg_ph_apply(sys, 'J', r, red->W, N, Vg, N);
    phgmg_ph_apply(sys, 'R', r, red->W, N, T1, N);
    for (i = 0; i < N * r; ++i) Vg[i] -= T1[i];
    red->K = phgmg__red_d(red, (size_t)r * r); PHGMG__NEED(red->K);
    phgmg__atb(N, r, r, red->W, Vg, red->K);
    red->Bh = phgmg__red_d(red, (size_t)r * m); PHGMG__NEED(red->Bh);
    phgmg__atb(N, r, m, red->W, sys->B, red->Bh);
    phgmg__free(alloc, T3); T3 = NULL;
  }

  /* quadratic part of H: Qh = V0^T Q V0 (and the V2 blocks) */
  phgmg__free(alloc, T2);
  T2 = phgmg__dalloc(alloc, (size_t)N * (r + rn)); PHGMG__NEED(T2);
  phgmg_ph_apply(sys, 'Q', r, red->V0, N, T2, N);
  if (rn) phgmg_ph_apply(sys, 'Q', rn, red->V2, N, T2 + (size_t)N * r, N);
  red->Qh = phgmg__red_d(red, (size_t)r * r); PHGMG__NEED(red->Qh);
  phgmg__atb(N, r, r, red->V0, T2, red->Qh);
  for (j = 0; j < r; ++j)   /* exact symmetry */
    for (i = 0; i < j; ++i) red->Qh[i + (size_t)j * r] = red->Qh[j + (size_t)i * r] = 0.5 * (red->Qh[i + (size_t)j * r] + red->Qh[j + (size_t)i * r]);
  if (rn) {
    red->Q01 = phgmg__red_d(red, (size_t)r * rn); PHGMG__NEED(red->Q01);
    red->Q11 = phgmg__red_d(red, (size_t)rn * rn); PHGMG__NEED(red->Q11);
    phgmg__atb(N, r, rn, red->V0, T2 + (size_t)N * r, red->Q01);
    phgmg__atb(N, rn, rn, red->V2, T2 + (size_t)N * r, red->Q11);
  }

  /* separable nonlinear part: structure-preserving DEIM or every term */
  if (sys->nl == PHGMG_NL_SEPARABLE && sys->nsep > 0) {
    const int nt = sys->nsep;
    int nd = 0, nneg = 0;
    double *wt;
    pts = phgmg__ialloc(alloc, (size_t)nt); PHGMG__NEED(pts);
    wt = phgmg__dalloc(alloc, (size_t)nt); PHGMG__NEED(wt);
    if (opts->deim && opts->deim_pts && opts->deim_w) {
      if (opts->deim_count < 1 || opts->deim_count > nt) { phgmg__free(alloc, wt); rc = PHGMG_ERR_SIZE; goto fail; }
      nd = opts->deim_count;
      for (a = 0; a < nd; ++a) {
        if (opts->deim_pts[a] < 0 || opts->deim_pts[a] >= nt) { phgmg__free(alloc, wt); rc = PHGMG_ERR_INVALID_ARG; goto fail; }
        pts[a] = opts->deim_pts[a];
        wt[a] = opts->deim_w[a];
        if (wt[a] < 0.0) ++nneg;
      }
      inf.deim_modes = nd;
      inf.deim_negative = nneg;
      if (!phgmg__all_finite(wt, (size_t)nd)) { phgmg__free(alloc, wt); rc = PHGMG_ERR_NANINF; goto fail; }
      if (nneg > 0 && !opts->deim_allow_negative) { phgmg__free(alloc, wt); rc = PHGMG_ERR_NEGATIVE_WEIGHT; goto fail; }
    } else if (opts->deim) {
      double *F = phgmg__dalloc(alloc, (size_t)nt * ns);
      if (!F) { phgmg__free(alloc, wt); rc = PHGMG_ERR_NOMEM; goto fail; }
      for (i = 0; i < ns; ++i)
        for (a = 0; a < nt; ++a)
          F[a + (size_t)i * nt] = phgmg__poly_d1(sys->poly, sys->poly_deg, X[sys->sep_idx[a] + (size_t)i * ldx]);
      rc = phgmg_deim(nt, ns, F, nt, sys->sep_w, opts->deim_tol, opts->deim_max, pts, wt, &nd, &nneg,
                      &inf.deim_sigma_ratio, alloc);
      phgmg__free(alloc, F);
      inf.deim_modes = nd;      /* reported on PHGMG_ERR_NEGATIVE_WEIGHT too */
      inf.deim_negative = nneg;
      if (rc == PHGMG_OK && nneg > 0 && !opts->deim_allow_negative) rc = PHGMG_ERR_NEGATIVE_WEIGHT;
      if (rc != PHGMG_OK) { phgmg__free(alloc, wt); goto fail; }
    } else {
      nd = nt;
      for (a = 0; a < nt; ++a) { pts[a] = a; wt[a] = sys->sep_w ? sys->sep_w[a] : 1.0; }
    }
    inf.deim_modes = nd;
    inf.deim_negative = nneg;
    red->nd = nd;
    red->coord = PHGMG__CAST(int *, phgmg__red_alloc(red, (size_t)nd * sizeof(int)));
    red->w = phgmg__red_d(red, (size_t)nd);
    red->P0 = phgmg__red_d(red, (size_t)nd * r);
    red->P1 = rn ? phgmg__red_d(red, (size_t)nd * rn) : NULL;
    red->poly = phgmg__red_d(red, (size_t)sys->poly_deg + 1);
    if (!red->coord || !red->w || !red->P0 || (rn && !red->P1) || !red->poly) {
      phgmg__free(alloc, wt); rc = PHGMG_ERR_NOMEM; goto fail;
    }
    for (j = 0; j < nd; ++j) {
      const int cj = sys->sep_idx[pts[j]];
      red->coord[j] = cj;
      red->w[j] = wt[j];
      for (a = 0; a < r; ++a) red->P0[j + (size_t)a * nd] = red->V0[cj + (size_t)a * N];
      for (a = 0; a < rn; ++a) red->P1[j + (size_t)a * nd] = red->V2[cj + (size_t)a * N];
    }
    memcpy(red->poly, sys->poly, ((size_t)sys->poly_deg + 1) * sizeof(double));
    phgmg__free(alloc, wt);
  }
  if (opts->dt > 0.0 && red->kind == PHGMG_ROM_LINEAR && red->nd == 0) {
    red->map_dt = opts->dt;
    PHGMG__TRY(phgmg__step_map(red, opts->dt, alloc));
  }
  PHGMG__TRY(phgmg__publish(red));
#undef PHGMG__NEED
#undef PHGMG__TRY
  phgmg_jr_factor_destroy(jr);
  phgmg__free(alloc, T1); phgmg__free(alloc, T2); phgmg__free(alloc, T3); phgmg__free(alloc, pts);
  if (info) *info = inf;
  *out = red;
  return PHGMG_OK;
fail:
  phgmg_jr_factor_destroy(jr);
  phgmg__free(alloc, T1); phgmg__free(alloc, T2); phgmg__free(alloc, T3); phgmg__free(alloc, pts);
  phgmg_reduced_destroy(red);
  if (info) *info = inf;
  return rc;
}

PHGMG_DEF void phgmg_reduced_lift(const phgmg_reduced *red, const double *xr, double *x) {
  phgmg_gemv('N', red->N, red->r, 1.0, red->V0, red->N, xr, 0.0, x);
  if (red->kind == PHGMG_ROM_QUADRATIC) {
    /* q = M (x2 kron x2) */
    const int p = red->p, rn = red->rn;
    const double *x2 = xr + red->m;
    double q[64];
    int i, a, j;
    for (i = 0; i < rn && i < 64; ++i) {
      double s = 0.0;
      for (a = 0; a < p; ++a)
        for (j = 0; j < p; ++j) s += red->M[i + (size_t)(a * p + j) * rn] * x2[a] * x2[j];
      q[i] = s;
    }
    phgmg_gemv('N', red->N, PHGMG__MIN(rn, 64), 1.0, red->V2, red->N, q, 1.0, x);
  }
}

PHGMG_DEF void phgmg_reduced_restrict(const phgmg_reduced *red, const double *x, double *xr) {
  const int N = red->N, m = red->m, r = red->r;
  if (red->method == PHGMG_METHOD_SP1 || red->method == PHGMG_METHOD_SP2) {
    phgmg_gemv('T', N, r, 1.0, red->W, N, x, 0.0, xr);
  } else {
    /* [B, V1]^+ x = [RB^{-1} QB^T x; V1^T x]  (V1 is orthogonal to B) */
    int i, j;
    phgmg_gemv('T', N, m, 1.0, red->QB, N, x, 0.0, xr);
    for (i = m - 1; i >= 0; --i) {
      double s = xr[i];
      for (j = i + 1; j < m; ++j) s -= red->RB[i + j * m] * xr[j];
      xr[i] = s / red->RB[i + i * m];
    }
    phgmg_gemv('T', N, r - m, 1.0, red->V0 + (size_t)N * m, N, x, 0.0, xr + m);
  }
}

PHGMG_DEF void phgmg_reduced_dphi(const phgmg_reduced *red, const double *xr, double *D, int ldd) {
  const int N = red->N, r = red->r, m = red->m;
  int j;
  for (j = 0; j < r; ++j) memcpy(D + (size_t)j * ldd, red->V0 + (size_t)j * N, (size_t)N * sizeof(double));
  if (red->kind == PHGMG_ROM_QUADRATIC) {
    double Lp[64 * 64];
    const int p = red->p, rn = red->rn;
    if (rn * p > 64 * 64) return;
    phgmg__lp_d(rn, p, red->Ms, xr + m, Lp);
    phgmg_gemm('N', 'N', N, p, rn, 1.0, red->V2, N, Lp, rn, 1.0, D + (size_t)m * ldd, ldd);
  }
}

PHGMG_DEF phgmg_result phgmg_reduced_W(const phgmg_reduced *red, const double *xr, double *W, int ldw) {
  const int N = red->N, r = red->r;
  phgmg_jr_factor *jr = NULL;
  const phgmg_allocator *alloc = red->use_alloc ? &red->alloc : NULL;
  double *D, *GtD, *E, *Einv;
  phgmg_result rc;
  int j;
  if (red->method == PHGMG_METHOD_SP1 || red->method == PHGMG_METHOD_SP2) {
    for (j = 0; j < r; ++j) memcpy(W + (size_t)j * ldw, red->W + (size_t)j * N, (size_t)N * sizeof(double));
    return PHGMG_OK;
  }
  D = phgmg__dalloc(alloc, 2 * (size_t)N * r + 2 * (size_t)r * r);
  if (!D) return PHGMG_ERR_NOMEM;
  GtD = D + (size_t)N * r; E = GtD + (size_t)N * r; Einv = E + (size_t)r * r;
  phgmg_reduced_dphi(red, xr, D, N);
  memcpy(GtD, D, (size_t)N * r * sizeof(double));
  rc = phgmg_jr_factor_create(&jr, red->sys, NULL, alloc);
  if (rc == PHGMG_OK) {
    phgmg_jr_solve(jr, 'T', r, GtD, N);                      /* G^T D */
    phgmg__atb(N, r, r, GtD, D, E);                           /* (G^T D)^T D = D^T G D */
    rc = phgmg__inv(r, E, Einv, alloc);
    if (rc == PHGMG_OK)                                       /* W = G^T D E^{-T} */
      phgmg_gemm('N', 'T', N, r, r, 1.0, GtD, N, Einv, r, 0.0, W, ldw);
  }
  phgmg_jr_factor_destroy(jr);
  phgmg__free(alloc, D);
  return rc;
}

PHGMG_DEF phgmg_result phgmg_reduced_simulate(const phgmg_reduced *red, const double *xr0, double t0,
                                              double dt, int nsteps, phgmg_input_fn uf, void *uuser,
                                              double tol, int max_iter, double *XR, double *Y,
                                              const phgmg_energy *energy, phgmg_rom_stats *stats,
                                              const phgmg_allocator *alloc) {
  const phgmg_rom *rom;
  phgmg_rom_stepper st;
  size_t msz, nreal;
  void *mem;
  phgmg_real *x, *u3, *y, *ework, en[2];
  double *ubuf, S = 0.0, D = 0.0;
  int r, m, n, i, a;
  phgmg_result rc;
  if (!red || !xr0 || nsteps < 0 || !(dt > 0.0)) return PHGMG_ERR_INVALID_ARG;
  rom = &red->rom; r = rom->r; m = rom->m;
  msz = phgmg_rom_stepper_memsize(rom);
  nreal = (size_t)r + 4 * (size_t)m + phgmg_rom_eval_work_size(rom);
  mem = phgmg__alloc(alloc, ((msz + 15) / 16) * 16 + nreal * sizeof(phgmg_real) + (size_t)m * sizeof(double) + 16);
  if (!mem) return PHGMG_ERR_NOMEM;
  x = PHGMG__CAST(phgmg_real *, PHGMG__CAST(void *, PHGMG__CAST(char *, mem) + ((msz + 15) / 16) * 16));
  u3 = x + r; y = u3 + 3 * m; ework = y + m;
  ubuf = PHGMG__CAST(double *, PHGMG__CAST(void *, PHGMG__CAST(char *, mem) + ((msz + 15) / 16) * 16 +
                                                    ((nreal * sizeof(phgmg_real) + 15) / 16) * 16));
  rc = phgmg_rom_stepper_init(&st, rom, (phgmg_real)dt, (phgmg_real)tol, max_iter, mem, msz);
  if (rc != PHGMG_OK) { phgmg__free(alloc, mem); return rc; }
  for (a = 0; a < r; ++a) x[a] = (phgmg_real)xr0[a];
#define PHGMG__REC(nn) do { \
    if (XR) for (a = 0; a < r; ++a) XR[a + (size_t)(nn) * r] = (double)x[a]; \
    if (Y) { phgmg_rom_output(rom, x, y, ework); for (a = 0; a < m; ++a) Y[a + (size_t)(nn) * m] = (double)y[a]; } \
    if (energy) { energy->H[nn] = (double)phgmg_rom_hamiltonian(rom, x, ework); energy->S[nn] = S; energy->D[nn] = D; } \
  } while (0)
  PHGMG__REC(0);
  for (n = 0; n < nsteps; ++n) {
    const double t = t0 + n * dt;
    const double s15 = sqrt(15.0) / 10.0, cs[3] = {0.5 - s15, 0.5, 0.5 + s15};
    for (i = 0; i < 3; ++i) {
      if (uf) {
        uf(t + cs[i] * dt, ubuf, uuser);
        for (a = 0; a < m; ++a) u3[i * m + a] = (phgmg_real)ubuf[a];
      } else {
        for (a = 0; a < m; ++a) u3[i * m + a] = (phgmg_real)0;
      }
    }
    en[0] = en[1] = (phgmg_real)0;
    rc = phgmg_rom_step(&st, x, u3, NULL, energy ? en : NULL);
    if (rc != PHGMG_OK) break;
    S += (double)en[0];
    D += (double)en[1];
    PHGMG__REC(n + 1);
  }
#undef PHGMG__REC
  if (stats) *stats = st.stats;
  phgmg__free(alloc, mem);
  return rc;
}

/* --- error measures ------------------------------------------------------ */
PHGMG_DEF double phgmg_rel_error(int n, int ns, const double *A, int lda, const double *B, int ldb) {
  double num = 0.0, den = 0.0;
  int i, j;
  for (j = 0; j < ns; ++j)
    for (i = 0; i < n; ++i) {
      const double a = A[i + (size_t)j * lda], d = a - B[i + (size_t)j * ldb];
      num += d * d;
      den += a * a;
    }
  return den > 0.0 ? sqrt(num / den) : (num > 0.0 ? (double)INFINITY : 0.0);
}

/* sqrt(sum ||x_i - g(x_i)||^2 / sum ||x_i||^2) with g applied column-wise. */
PHGMG__PRIV double phgmg__err_map(const phgmg_reduced *red, const double *X, int ldx, int ns,
                                  const double *XR, int ldxr, int mode) {
  const int N = red->N, r = red->r;
  const phgmg_allocator *alloc = red->use_alloc ? &red->alloc : NULL;
  double *xt = phgmg__dalloc(alloc, (size_t)N + (size_t)r + (size_t)(r + red->rn)), *xr;
  double num = 0.0, den = 0.0;
  int i, j;
  if (!xt) return (double)NAN;
  xr = xt + N;
  for (j = 0; j < ns; ++j) {
    const double *x = X + (size_t)j * ldx;
    if (mode == 0) {            /* reduction error: phi(XR_j) */
      phgmg_reduced_lift(red, XR + (size_t)j * ldxr, xt);
    } else if (mode == 1) {     /* projection error: phi(rho(x)) */
      phgmg_reduced_restrict(red, x, xr);
      phgmg_reduced_lift(red, xr, xt);
    } else {                    /* lower bound: orthogonal projection on [B, V1, V2] */
      double *c = xr;
      memcpy(xt, x, (size_t)N * sizeof(double));
      phgmg__orth_remove(N, red->m, red->QB, 1, xt, N, c);
      phgmg__orth_remove(N, red->r - red->m, red->V0 + (size_t)N * red->m, 1, xt, N, c);
      phgmg__orth_remove(N, red->rn, red->V2, 1, xt, N, c);
      for (i = 0; i < N; ++i) xt[i] = x[i] - xt[i];
    }
    for (i = 0; i < N; ++i) {
      const double d = x[i] - xt[i];
      num += d * d;
      den += x[i] * x[i];
    }
  }
  phgmg__free(alloc, xt);
  return den > 0.0 ? sqrt(num / den) : 0.0;
}

PHGMG_DEF double phgmg_err_red(const phgmg_reduced *red, const double *X, int ldx, int ns,
                               const double *XR, int ldxr) {
  return phgmg__err_map(red, X, ldx, ns, XR, ldxr, 0);
}
PHGMG_DEF double phgmg_err_proj(const phgmg_reduced *red, const double *X, int ldx, int ns) {
  return phgmg__err_map(red, X, ldx, ns, NULL, 0, 1);
}
PHGMG_DEF double phgmg_err_lowerbound(const phgmg_reduced *red, const double *X, int ldx, int ns) {
  if (red->kind != PHGMG_ROM_QUADRATIC) return (double)NAN;
  return phgmg__err_map(red, X, ldx, ns, NULL, 0, 2);
}
PHGMG_DEF void phgmg_err_energy(const phgmg_energy *energy, int nsteps, double *e) {
  int n;
  for (n = 0; n <= nsteps; ++n) e[n] = fabs(energy->H[n] - energy->H[0] - energy->S[n] + energy->D[n]);
}
#endif /* PHGMG_NO_OFFLINE */
