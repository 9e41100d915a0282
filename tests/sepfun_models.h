/* Hand-made reduced models for the separable-function / manifold-callback tests
   (tests/test_sepfun.c and tests/sepfun_export.c). Include after phgmg.h.

   A QUADRATIC model is built from N-dimensional data the test keeps: random
   bases V0 (N x r), V2 (N x rn), G = Jg - Rg (skew minus positive definite, so
   (D^T G D)^{-1} has a negative semidefinite symmetric part), Q SPD, and a
   random symmetric tensor Ms. Every reduced block is computed here from that
   data (G00 = V0^T G V0, ...), so a test can also evaluate the model directly
   in N dimensions. The separable part keeps nd coordinates idx of phi(x).

   The exp-polynomial family, per kept term j (t = j), with kind[j]:
     0: Toda   phi(s) = e^s - 1 - s           poly {-1, -1}, expo {(1, 1), (0, 0)}
     1: cosh   phi(s) = cosh(s) - 1          poly {-1,  0}, expo {(.5, 1), (.5, -1)}
     2: Morse  phi(s) = D (1 - e^{-a s})^2   poly { D,  0}, expo {(-2D, -a), (D, -2a)} */
#ifndef SEPFUN_MODELS_H
#define SEPFUN_MODELS_H
#include <string.h>

enum { SF_N = 12, SF_R = 5, SF_M = 2, SF_P = 3, SF_RN = 4, SF_ND = 3 };

typedef struct sf_model {
  double V0[SF_N * SF_R], V2[SF_N * SF_RN], G[SF_N * SF_N], Q[SF_N * SF_N];
  phgmg_real Bh[SF_R * SF_M], Qh[SF_R * SF_R], G00[SF_R * SF_R], G01[SF_R * SF_RN], G10[SF_RN * SF_R],
      G11[SF_RN * SF_RN], Q01[SF_R * SF_RN], Q11[SF_RN * SF_RN], Ms[SF_RN * SF_P * SF_P],
      P0[SF_ND * SF_R], P1[SF_ND * SF_RN], w[SF_ND];
  phgmg_real poly[SF_ND * 2], expo[SF_ND * 4];
  int idx[SF_ND], term[SF_ND], kind[SF_ND];
  phgmg_rom rom;
} sf_model;

#define sf_morse_D 0.7
#define sf_morse_a 1.3

/* deterministic uniform [-1, 1) (own generator: the same data in every program) */
static PHGMG__UNUSED double sf_rand(unsigned long long *s) {
  *s ^= *s >> 12; *s ^= *s << 25; *s ^= *s >> 27;
  return (double)((*s * 2685821657736338717ULL) >> 11) / 4503599627370496.0 - 1.0;
}

/* C = A^T B, A: N x a, B: N x b (double), C: a x b (phgmg_real) */
static PHGMG__UNUSED void sf_atb(int a, int b, const double *A, const double *B, const double *M, phgmg_real *C) {
  int i, j, k, l;
  for (j = 0; j < b; ++j)
    for (i = 0; i < a; ++i) {
      double s = 0.0;
      for (k = 0; k < SF_N; ++k) {
        double mb = 0.0;
        if (M) for (l = 0; l < SF_N; ++l) mb += M[k + l * SF_N] * B[l + j * SF_N];
        else mb = B[k + j * SF_N];
        s += A[k + i * SF_N] * mb;
      }
      C[i + j * a] = (phgmg_real)s;
    }
}

static PHGMG__UNUSED void sf_build(sf_model *M, unsigned long long seed) {
  unsigned long long s = seed;
  double L[SF_N * SF_N], Mr[SF_RN * SF_P * SF_P];
  int i, j, k, p = SF_P;
  memset(M, 0, sizeof *M);
  for (i = 0; i < SF_N * SF_R; ++i) M->V0[i] = sf_rand(&s) / 2.0;
  for (i = 0; i < SF_N * SF_RN; ++i) M->V2[i] = sf_rand(&s) / 4.0;
  for (i = 0; i < SF_N * SF_N; ++i) L[i] = sf_rand(&s) / 3.0;
  for (j = 0; j < SF_N; ++j)
    for (i = 0; i <= j; ++i) {
      double a = sf_rand(&s), r = 0.0, q = 0.0;
      for (k = 0; k < SF_N; ++k) { r += L[i + k * SF_N] * L[j + k * SF_N]; q += L[k + i * SF_N] * L[k + j * SF_N]; }
      if (i == j) { a = 0.0; r += 0.2; q += 1.0; }
      M->G[i + j * SF_N] = a - r; M->G[j + i * SF_N] = -a - r;
      M->Q[i + j * SF_N] = M->Q[j + i * SF_N] = q;
    }
  for (i = 0; i < SF_RN * p * p; ++i) Mr[i] = sf_rand(&s) / 2.0;
  for (k = 0; k < p; ++k)
    for (j = 0; j < p; ++j)
      for (i = 0; i < SF_RN; ++i)
        M->Ms[i + (k * p + j) * SF_RN] = (phgmg_real)(Mr[i + (k * p + j) * SF_RN] + Mr[i + (j * p + k) * SF_RN]);
  sf_atb(SF_R, SF_R, M->V0, M->V0, M->G, M->G00);
  sf_atb(SF_R, SF_RN, M->V0, M->V2, M->G, M->G01);
  sf_atb(SF_RN, SF_R, M->V2, M->V0, M->G, M->G10);
  sf_atb(SF_RN, SF_RN, M->V2, M->V2, M->G, M->G11);
  sf_atb(SF_R, SF_R, M->V0, M->V0, M->Q, M->Qh);
  sf_atb(SF_R, SF_RN, M->V0, M->V2, M->Q, M->Q01);
  sf_atb(SF_RN, SF_RN, M->V2, M->V2, M->Q, M->Q11);
  for (i = 0; i < SF_R * SF_M; ++i) M->Bh[i] = (phgmg_real)sf_rand(&s);
  for (j = 0; j < SF_ND; ++j) {
    M->idx[j] = 3 * j + 1;
    M->term[j] = 10 + 7 * j; /* full-model term index: checks the pass-through to phi_cb */
    M->kind[j] = j % 3;
    M->w[j] = (phgmg_real)(0.5 + 0.25 * j);
    for (i = 0; i < SF_R; ++i) M->P0[j + i * SF_ND] = (phgmg_real)M->V0[M->idx[j] + i * SF_N];
    for (i = 0; i < SF_RN; ++i) M->P1[j + i * SF_ND] = (phgmg_real)M->V2[M->idx[j] + i * SF_N];
  }
  for (j = 0; j < SF_ND; ++j) {
    phgmg_real *c = M->poly + 2 * j, *e = M->expo + 4 * j;
    const phgmg_real D = (phgmg_real)sf_morse_D, a = (phgmg_real)sf_morse_a;
    switch (M->kind[j]) {
      case 0: c[0] = -1; c[1] = -1; e[0] = 1; e[1] = 1; e[2] = 0; e[3] = 0; break;
      case 1: c[0] = -1; c[1] = 0; e[0] = 0.5f; e[1] = 1; e[2] = 0.5f; e[3] = -1; break;
      default: c[0] = D; c[1] = 0; e[0] = -2 * D; e[1] = -a; e[2] = D; e[3] = -2 * a; break;
    }
  }
  M->rom.kind = PHGMG_ROM_QUADRATIC;
  M->rom.method = PHGMG_METHOD_GMG_QM;
  M->rom.r = SF_R; M->rom.m = SF_M; M->rom.rn = SF_RN; M->rom.nd = SF_ND;
  M->rom.Bh = M->Bh; M->rom.Qh = M->Qh;
  M->rom.G00 = M->G00; M->rom.G01 = M->G01; M->rom.G10 = M->G10; M->rom.G11 = M->G11;
  M->rom.Q01 = M->Q01; M->rom.Q11 = M->Q11; M->rom.Ms = M->Ms;
  M->rom.P0 = M->P0; M->rom.P1 = M->P1; M->rom.w = M->w;
  M->rom.poly_deg = 1; M->rom.poly = M->poly;
  M->rom.nexp = 2; M->rom.nphi = SF_ND; M->rom.expo = M->expo;
  M->rom.term = M->term;
}

/* phi_cb evaluating the same exp-polynomial rows with the same arithmetic as the
   library (Horner, then a e^{bs} per exponential): results equal bit for bit. */
static PHGMG__UNUSED void sf_phi_same(int term, phgmg_real s, phgmg_real d[3], void *user) {
  const sf_model *M = (const sf_model *)user;
  int j = (term - 10) / 7, k, e;
  const phgmg_real *c = M->poly + 2 * j, *ex = M->expo + 4 * j;
  phgmg_real p0 = 0, p1 = 0, p2 = 0;
  for (k = 1; k >= 0; --k) { p2 = p2 * s + 2 * p1; p1 = p1 * s + p0; p0 = p0 * s + c[k]; }
  for (e = 0; e < 2; ++e) {
    const phgmg_real b = ex[2 * e + 1], ae = ex[2 * e] * (phgmg_real)exp((double)(b * s));
    p0 += ae; p1 += ae * b; p2 += ae * b * b;
  }
  d[0] = p0; d[1] = p1; d[2] = p2;
}

/* The same functions without user data, by full-model term index (term = 10 + 7 j,
   kind j % 3): what firmware supplies as <name>_phi for an exported model. */
static PHGMG__UNUSED void sf_phi_table(int term, phgmg_real s, phgmg_real d[3], void *user) {
  int j = (term - 10) / 7, k, e;
  const phgmg_real D = (phgmg_real)sf_morse_D, a = (phgmg_real)sf_morse_a;
  phgmg_real c[2], ex[4], p0 = 0, p1 = 0, p2 = 0;
  (void)user;
  switch (j % 3) {
    case 0: c[0] = -1; c[1] = -1; ex[0] = 1; ex[1] = 1; ex[2] = 0; ex[3] = 0; break;
    case 1: c[0] = -1; c[1] = 0; ex[0] = 0.5f; ex[1] = 1; ex[2] = 0.5f; ex[3] = -1; break;
    default: c[0] = D; c[1] = 0; ex[0] = -2 * D; ex[1] = -a; ex[2] = D; ex[3] = -2 * a; break;
  }
  for (k = 1; k >= 0; --k) { p2 = p2 * s + 2 * p1; p1 = p1 * s + p0; p0 = p0 * s + c[k]; }
  for (e = 0; e < 2; ++e) {
    const phgmg_real b = ex[2 * e + 1], ae = ex[2 * e] * (phgmg_real)exp((double)(b * s));
    p0 += ae; p1 += ae * b; p2 += ae * b * b;
  }
  d[0] = p0; d[1] = p1; d[2] = p2;
}
/* A fixed cubic manifold without user data (what firmware supplies as <name>_eta):
   eta_i = 1/2 sum_k a_ik x_k^2 + c_i S^3, S = sum_k x_k,
   a_ik = 0.3 (1 + i + k) / (1 + i), c_i = 0.05 (i + 1). */
static PHGMG__UNUSED void sf_eta_fixed(const phgmg_real *x2, phgmg_real *q, phgmg_real *Dq, phgmg_real *D2q,
                                      void *user) {
  int i, k, j;
  phgmg_real S = 0;
  (void)user;
  for (k = 0; k < SF_P; ++k) S += x2[k];
  for (i = 0; i < SF_RN; ++i) {
    const phgmg_real c = (phgmg_real)0.05 * (phgmg_real)(i + 1);
    phgmg_real qi = c * S * S * S;
    for (k = 0; k < SF_P; ++k) {
      const phgmg_real a = (phgmg_real)0.3 * (phgmg_real)(1 + i + k) / (phgmg_real)(1 + i);
      qi += a * x2[k] * x2[k] / 2;
      if (Dq) Dq[i + k * SF_RN] = a * x2[k] + 3 * c * S * S;
      if (D2q)
        for (j = 0; j < SF_P; ++j) D2q[i + (k * SF_P + j) * SF_RN] = (j == k ? a : (phgmg_real)0) + 6 * c * S;
    }
    if (q) q[i] = qi;
  }
}
#endif
