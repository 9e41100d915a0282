/* Separable functions beyond a shared polynomial: the built-in
   exp-polynomial family of the full model and of reduced models against the same
   functions given as callbacks (closed forms), the manifold callback eta_cb
   against the built-in quadratic map and against direct N-dimensional formulas
   for a cubic manifold, the Hamiltonian callback ham_cb, and the binary format. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include <stdlib.h>
#include "sepfun_models.h"

static double maxrel(const double *a, const double *b, int n) {
  double e = 0.0, s = 0.0;
  int i;
  for (i = 0; i < n; ++i) { e = fmax(e, fabs(a[i] - b[i])); s = fmax(s, fabs(b[i])); }
  return s > 0.0 ? e / s : e;
}

/* ---- full-order model ------------------------------------------------------------ */
enum { FN = 8, FNSEP = 6 };
static const double morse_D = 0.7, morse_a = 1.3;
static int fom_kind[FNSEP];
static double phi_closed(int kind, double s, int d) {
  double e;
  switch (kind) {
    case 0: return d == 0 ? exp(s) - 1.0 - s : (d == 1 ? exp(s) - 1.0 : exp(s));
    case 1: return d == 0 ? cosh(s) - 1.0 : (d == 1 ? sinh(s) : cosh(s));
    default:
      e = exp(-morse_a * s);
      if (d == 0) return morse_D * (1.0 - e) * (1.0 - e);
      if (d == 1) return 2.0 * morse_D * morse_a * e * (1.0 - e);
      return 2.0 * morse_D * morse_a * morse_a * e * (2.0 * e - 1.0);
  }
}
static double cb_phi(int k, double s, void *u) { (void)u; return phi_closed(fom_kind[k], s, 0); }
static double cb_dphi(int k, double s, void *u) { (void)u; return phi_closed(fom_kind[k], s, 1); }
static double cb_ddphi(int k, double s, void *u) { (void)u; return phi_closed(fom_kind[k], s, 2); }
static void u_sin(double t, double *u, void *user) { (void)user; u[0] = 0.5 * sin(2.0 * t); }

typedef struct fom_data {
  double J[FN * FN], R[FN * FN], Q[FN * FN], Jb[3 * FN], Rb[3 * FN], Qb[3 * FN], B[FN];
  double poly[2 * FNSEP], expo[4 * FNSEP], w[FNSEP];
  int idx[FNSEP];
} fom_data;

/* chain: J tridiagonal skew, R, Q diagonal; dense and banded (kb = 1) copies */
static void fom_build(fom_data *F, phgmg_ph_system *s, int banded, int per_term) {
  int i, k;
  memset(F, 0, sizeof *F);
  for (i = 0; i < FN; ++i) {
    double jv = 1.0 + 0.1 * i;
    F->R[i + i * FN] = F->Rb[1 + 3 * i] = 0.05 + 0.01 * i;
    F->Q[i + i * FN] = F->Qb[1 + 3 * i] = 1.0 + 0.1 * i;
    if (i + 1 < FN) { /* J(i, i+1) = jv, J(i+1, i) = -jv; band (kb + i - j) + 3 j */
      F->J[i + (i + 1) * FN] = jv; F->J[(i + 1) + i * FN] = -jv;
      F->Jb[0 + 3 * (i + 1)] = jv; F->Jb[2 + 3 * i] = -jv;
    }
  }
  F->B[0] = 1.0;
  for (k = 0; k < FNSEP; ++k) {
    F->idx[k] = k < 4 ? k : k - 1; /* coordinate 3 carries two terms */
    F->w[k] = 0.6 + 0.1 * k;
  }
  memset(s, 0, sizeof *s);
  s->N = FN; s->m = 1;
  s->storage = banded ? PHGMG_BANDED : PHGMG_DENSE; s->kb = 1;
  s->J = banded ? F->Jb : F->J; s->R = banded ? F->Rb : F->R; s->Q = banded ? F->Qb : F->Q;
  s->B = F->B;
  s->nl = PHGMG_NL_SEPARABLE; s->nsep = FNSEP; s->sep_idx = F->idx; s->sep_w = F->w;
  s->poly_deg = 1; s->poly = F->poly; s->nexp = 2; s->expo = F->expo;
  s->phi_nfun = per_term ? FNSEP : 0;
  for (k = 0; k < (per_term ? FNSEP : 1); ++k) {
    double *c = F->poly + 2 * k, *e = F->expo + 4 * k;
    fom_kind[k] = per_term ? k % 3 : 0;
    switch (fom_kind[k]) {
      case 0: c[0] = -1; c[1] = -1; e[0] = 1; e[1] = 1; e[2] = 0; e[3] = 0; break;
      case 1: c[0] = -1; c[1] = 0; e[0] = 0.5; e[1] = 1; e[2] = 0.5; e[3] = -1; break;
      default: c[0] = morse_D; c[1] = 0; e[0] = -2 * morse_D; e[1] = -morse_a; e[2] = morse_D; e[3] = -2 * morse_a;
    }
  }
  if (!per_term) for (k = 1; k < FNSEP; ++k) fom_kind[k] = 0;
}

TEST(test_fom_exppoly_vs_callbacks) {
  enum { nst = 100 };
  int banded, per_term, i, t;
  for (per_term = 0; per_term < 2; ++per_term)
    for (banded = 0; banded < 2; ++banded) {
      fom_data F;
      phgmg_ph_system sb, sc;
      double x[FN], gb[FN], gc[FN], hb, hc, d3[3];
      double *Xb = (double *)malloc(sizeof(double) * FN * (nst + 1));
      double *Xc = (double *)malloc(sizeof(double) * FN * (nst + 1));
      phgmg_gl3_opts o;
      fom_build(&F, &sb, banded, per_term);
      sc = sb; /* the same functions as callbacks */
      sc.poly_deg = 0; sc.poly = NULL; sc.nexp = 0; sc.expo = NULL; sc.phi_nfun = 0;
      sc.phi = cb_phi; sc.dphi = cb_dphi; sc.ddphi = cb_ddphi;
      CHECK_RC(phgmg_ph_validate(&sb, 0.0, NULL, NULL), PHGMG_OK);
      CHECK_RC(phgmg_ph_validate(&sc, 0.0, NULL, NULL), PHGMG_OK);
      for (t = 0; t < 5; ++t) {
        for (i = 0; i < FN; ++i) x[i] = 0.8 * th_rand();
        hb = phgmg_ph_hamiltonian(&sb, x);
        hc = phgmg_ph_hamiltonian(&sc, x);
        CHECK_LE(fabs(hb - hc), 1e-15 * fabs(hc) + 1e-300);
        phgmg_ph_gradient(&sb, x, gb);
        phgmg_ph_gradient(&sc, x, gc);
        CHECK_LE(maxrel(gb, gc, FN), 1e-15);
        for (i = 0; i < FNSEP; ++i) { /* phi3 and phi agree with the closed forms */
          phgmg__ph_phi3(&sb, i, x[i], d3);
          CHECK_LE(fabs(d3[0] - phi_closed(fom_kind[i], x[i], 0)), 4e-15 * (1.0 + fabs(d3[0])));
          CHECK_LE(fabs(d3[1] - phi_closed(fom_kind[i], x[i], 1)), 4e-15 * (1.0 + fabs(d3[1])));
          CHECK_LE(fabs(d3[2] - phi_closed(fom_kind[i], x[i], 2)), 4e-15 * (1.0 + fabs(d3[2])));
          CHECK_LE(fabs(d3[0] - phgmg__ph_phi(&sb, i, x[i], 0)), 1e-15 * (1.0 + fabs(d3[0])));
          CHECK_LE(fabs(d3[2] - phgmg__ph_phi(&sb, i, x[i], 2)), 1e-15 * (1.0 + fabs(d3[2])));
        }
      }
      for (i = 0; i < FN; ++i) x[i] = 0.5 * th_rand();
      memset(&o, 0, sizeof o);
      o.tol = 1e-13;
      CHECK_RC(phgmg_simulate(&sb, x, 0.0, 0.05, nst, u_sin, NULL, &o, Xb, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
      CHECK_RC(phgmg_simulate(&sc, x, 0.0, 0.05, nst, u_sin, NULL, &o, Xc, NULL, NULL, NULL, NULL, NULL), PHGMG_OK);
      CHECK_LE(maxrel(Xb, Xc, FN * (nst + 1)), 1e-12);
      CHECK(fabs(Xb[FN * nst]) > 1e-3); /* the run moved */
      free(Xb); free(Xc);
    }
}

TEST(test_fom_check_exppoly) {
  fom_data F;
  phgmg_ph_system s;
  fom_build(&F, &s, 0, 1);
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_OK);
  s.phi_nfun = 3; CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  s.phi_nfun = FNSEP; s.nexp = 9; CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  s.nexp = 2; s.poly_deg = 33; CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_SIZE);
  s.poly_deg = 1; s.expo = NULL; CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_INVALID_ARG);
  s.expo = F.expo; F.expo[4 * FNSEP - 1] = NAN; CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_ERR_NANINF);
  F.expo[4 * FNSEP - 1] = 0.0;
  s.poly_deg = 0; s.poly = NULL; /* exponentials only: allowed */
  CHECK_RC(phgmg_ph_validate(&s, 0.0, NULL, NULL), PHGMG_OK);
}

/* ---- reduced models ------------------------------------------------------------------ */
enum { R = SF_R, M = SF_M, P = SF_P, RN = SF_RN, ND = SF_ND };
static phgmg_real work_a[4096], work_b[4096];

static void rom_x(phgmg_real *x, double scale) {
  int i;
  for (i = 0; i < R; ++i) x[i] = (phgmg_real)(scale * th_rand());
}

/* closed-form phi_cb for the sf_model kinds (independent arithmetic) */
static void sf_phi_closed(int term, phgmg_real s, phgmg_real d[3], void *user) {
  const sf_model *Md = (const sf_model *)user;
  int j = (term - 10) / 7, k;
  for (k = 0; k < 3; ++k) d[k] = phi_closed(Md->kind[j], s, k);
}

/* all outputs of a model at x into out (H, g, f, H, Jf): 1 + 2r + 2r^2 values */
static int rom_all(const phgmg_rom *rom, const phgmg_real *x, const phgmg_real *u, double *out, phgmg_real *work) {
  phgmg_real g[R], f[R], Hs[R * R], Jf[R * R];
  int i, o = 0;
  if (phgmg_rom_rhs(rom, x, u, f, work) != PHGMG_OK) return 1;
  if (phgmg_rom_jacobian(rom, x, Jf, work) != PHGMG_OK) return 1;
  out[o++] = phgmg_rom_hamiltonian(rom, x, work);
  phgmg_rom_gradient(rom, x, g, work);
  phgmg_rom_hessian(rom, x, Hs, work);
  for (i = 0; i < R; ++i) out[o++] = g[i];
  for (i = 0; i < R; ++i) out[o++] = f[i];
  for (i = 0; i < R * R; ++i) out[o++] = Hs[i];
  for (i = 0; i < R * R; ++i) out[o++] = Jf[i];
  return 0;
}
enum { NALL = 1 + 2 * R + 2 * R * R };

/* 200-step stepper trajectory, outputs y into Y (m x nst) */
static int rom_run(const phgmg_rom *rom, int nst, double *Y) {
  static double mem[1 << 15];
  phgmg_rom_stepper st;
  phgmg_real x[R] = {0.3f, -0.2f, 0.25f, 0.1f, -0.3f}, u3[3 * M], y[M], tc[3];
  int n, i, k;
  if (phgmg_rom_stepper_memsize(rom) > sizeof mem) return 1;
  if (phgmg_rom_stepper_init(&st, rom, (phgmg_real)0.05, (phgmg_real)1e-13, 20, mem, sizeof mem) != PHGMG_OK) return 1;
  for (n = 0; n < nst; ++n) {
    phgmg_rom_stage_times((phgmg_real)(0.05 * n), (phgmg_real)0.05, tc);
    for (i = 0; i < 3; ++i)
      for (k = 0; k < M; ++k) u3[i * M + k] = (phgmg_real)(0.5 * sin((1.0 + k) * (double)tc[i]));
    if (phgmg_rom_step(&st, x, u3, y, NULL) != PHGMG_OK) return 1;
    for (k = 0; k < M; ++k) Y[k + n * M] = y[k];
  }
  return 0;
}

TEST(test_rom_exppoly_vs_phi_cb) {
  static sf_model Md;
  phgmg_rom rc, rs;
  phgmg_real x[R], u[M] = {0.3f, -0.1f};
  double a[NALL], b[NALL], c[NALL], Ya[400], Yb[400];
  int t;
  sf_build(&Md, 7u);
  CHECK_RC(phgmg_rom_check(&Md.rom), PHGMG_OK);
  rs = Md.rom; rs.phi_cb = sf_phi_same; rs.phi_user = &Md; rs.poly = NULL; rs.expo = NULL;
  rs.poly_deg = 0; rs.nexp = 0; rs.nphi = 0;
  rc = rs; rc.phi_cb = sf_phi_closed;
  CHECK_RC(phgmg_rom_check(&rs), PHGMG_OK);
  for (t = 0; t < 4; ++t) {
    rom_x(x, 0.6);
    CHECK(rom_all(&Md.rom, x, u, a, work_a) == 0);
    CHECK(rom_all(&rs, x, u, b, work_b) == 0);
    CHECK(rom_all(&rc, x, u, c, work_b) == 0);
    CHECK_LE(maxrel(a, b, NALL), 1e-14);
    CHECK_LE(maxrel(a, c, NALL), 1e-13); /* closed forms: other rounding */
  }
  CHECK(rom_run(&Md.rom, 200, Ya) == 0);
  CHECK(rom_run(&rs, 200, Yb) == 0);
  CHECK_LE(maxrel(Ya, Yb, 2 * 200), 1e-14);
  /* shared function (nphi = 0): the first row for every term */
  {
    phgmg_rom r1 = Md.rom;
    double e[NALL];
    int j;
    r1.nphi = 0;
    for (j = 0; j < ND; ++j) Md.kind[j] = 0;
    rc.phi_user = &Md;
    CHECK(rom_all(&r1, x, u, e, work_a) == 0);
    CHECK(rom_all(&rc, x, u, c, work_b) == 0);
    CHECK_LE(maxrel(e, c, NALL), 1e-13);
    CHECK(maxrel(e, a, NALL) > 1e-6); /* the per-term model was different */
  }
}

/* Hessian and Jacobian of the exp-polynomial model against central differences */
TEST(test_rom_exppoly_fd) {
  static sf_model Md;
  phgmg_real x[R], xp[R], gp[R], gm[R], Hs[R * R], Jf[R * R], fp[R], fm[R];
  double err = 0, errj = 0, sc = 0, scj = 0;
  const double h = 1e-5;
  int i, k;
  sf_build(&Md, 11u);
  rom_x(x, 0.7);
  phgmg_rom_hessian(&Md.rom, x, Hs, work_a);
  CHECK_RC(phgmg_rom_jacobian(&Md.rom, x, Jf, work_a), PHGMG_OK);
  for (k = 0; k < R; ++k) {
    for (i = 0; i < R; ++i) xp[i] = x[i];
    xp[k] = x[k] + h; phgmg_rom_gradient(&Md.rom, xp, gp, work_a);
    CHECK_RC(phgmg_rom_rhs(&Md.rom, xp, NULL, fp, work_a), PHGMG_OK);
    xp[k] = x[k] - h; phgmg_rom_gradient(&Md.rom, xp, gm, work_a);
    CHECK_RC(phgmg_rom_rhs(&Md.rom, xp, NULL, fm, work_a), PHGMG_OK);
    for (i = 0; i < R; ++i) {
      err = fmax(err, fabs((gp[i] - gm[i]) / (2 * h) - Hs[i + k * R]));
      errj = fmax(errj, fabs((fp[i] - fm[i]) / (2 * h) - Jf[i + k * R]));
      sc = fmax(sc, fabs(Hs[i + k * R]));
      scj = fmax(scj, fabs(Jf[i + k * R]));
      CHECK_LE(fabs(Hs[i + k * R] - Hs[k + i * R]), 1e-14 * (1.0 + fabs(Hs[i + k * R])));
    }
  }
  CHECK_LE(err, 1e-7 * sc);
  CHECK_LE(errj, 1e-6 * scj);
}

/* ---- eta_cb ------------------------------------------------------------------------- */
/* the built-in quadratic map as a callback: q = L x2 / 2, Dq = L, D2q = Ms */
static void eta_builtin(const phgmg_real *x2, phgmg_real *q, phgmg_real *Dq, phgmg_real *D2q, void *user) {
  const sf_model *Md = (const sf_model *)user;
  phgmg_real L[RN * P];
  int i, j, k;
  for (k = 0; k < P; ++k)
    for (i = 0; i < RN; ++i) {
      phgmg_real s = 0;
      for (j = 0; j < P; ++j) s += Md->Ms[i + (k * P + j) * RN] * x2[j];
      L[i + k * RN] = s;
    }
  if (q)
    for (i = 0; i < RN; ++i) {
      phgmg_real s = 0;
      for (k = 0; k < P; ++k) s += L[i + k * RN] * x2[k];
      q[i] = s / 2;
    }
  if (Dq) memcpy(Dq, L, sizeof L);
  if (D2q) memcpy(D2q, Md->Ms, sizeof(phgmg_real) * RN * P * P);
}

TEST(test_rom_eta_builtin_equals_ms) {
  static sf_model Md;
  phgmg_rom re;
  phgmg_real x[R], u[M] = {0.2f, 0.4f};
  double a[NALL], b[NALL], Ya[400], Yb[400];
  int t;
  sf_build(&Md, 23u);
  re = Md.rom; re.Ms = NULL; re.eta_cb = eta_builtin; re.eta_user = &Md;
  CHECK_RC(phgmg_rom_check(&re), PHGMG_OK);
  CHECK(phgmg_rom_eval_work_size(&re) > phgmg_rom_eval_work_size(&Md.rom));
  for (t = 0; t < 4; ++t) {
    rom_x(x, 0.6);
    CHECK(rom_all(&Md.rom, x, u, a, work_a) == 0);
    CHECK(rom_all(&re, x, u, b, work_b) == 0);
    CHECK_LE(maxrel(a, b, NALL), 1e-12);
  }
  CHECK(rom_run(&Md.rom, 200, Ya) == 0);
  CHECK(rom_run(&re, 200, Yb) == 0);
  CHECK_LE(maxrel(Ya, Yb, 2 * 200), 1e-12);
  CHECK(phgmg_rom_stepper_memsize(&re) <= PHGMG_ROM_STEPPER_MEMSIZE_MAX_CB(R, M, RN, ND));
  re.Ms = NULL; re.eta_cb = NULL;
  CHECK_RC(phgmg_rom_check(&re), PHGMG_ERR_INVALID_ARG);
}

/* a cubic manifold: eta_i = 1/2 x2^T A_i x2 + c_i (a_i^T x2)^3 */
typedef struct cubic_eta { double A[RN * P * P], a[RN * P], c[RN]; } cubic_eta;
static void eta_cubic(const phgmg_real *x2, phgmg_real *q, phgmg_real *Dq, phgmg_real *D2q, void *user) {
  const cubic_eta *C = (const cubic_eta *)user;
  int i, k, j;
  for (i = 0; i < RN; ++i) {
    double s = 0, qa = 0;
    const double *ai = C->a + i * P, *Ai = C->A + i * P * P;
    for (k = 0; k < P; ++k) s += ai[k] * x2[k];
    for (k = 0; k < P; ++k)
      for (j = 0; j < P; ++j) qa += 0.5 * Ai[k + j * P] * x2[k] * x2[j];
    if (q) q[i] = (phgmg_real)(qa + C->c[i] * s * s * s);
    for (k = 0; k < P; ++k) {
      double dk = 3.0 * C->c[i] * s * s * ai[k];
      for (j = 0; j < P; ++j) dk += Ai[k + j * P] * x2[j];
      if (Dq) Dq[i + k * RN] = (phgmg_real)dk;
      if (D2q)
        for (j = 0; j < P; ++j)
          D2q[i + (k * P + j) * RN] = (phgmg_real)(Ai[k + j * P] + 6.0 * C->c[i] * s * ai[k] * ai[j]);
    }
  }
}

/* direct N-dimensional Hamiltonian of the cubic-manifold model */
static double direct_H(const sf_model *Md, const cubic_eta *C, const phgmg_real *x) {
  phgmg_real q[RN];
  double ph[SF_N], H = 0;
  int i, k;
  eta_cubic(x + M, q, NULL, NULL, (void *)C);
  for (i = 0; i < SF_N; ++i) {
    double s = 0;
    for (k = 0; k < R; ++k) s += Md->V0[i + k * SF_N] * x[k];
    for (k = 0; k < RN; ++k) s += Md->V2[i + k * SF_N] * q[k];
    ph[i] = s;
  }
  for (i = 0; i < SF_N; ++i)
    for (k = 0; k < SF_N; ++k) H += 0.5 * ph[i] * Md->Q[i + k * SF_N] * ph[k];
  for (k = 0; k < ND; ++k) H += Md->w[k] * phi_closed(Md->kind[k], ph[Md->idx[k]], 0);
  return H;
}

TEST(test_rom_eta_cubic) {
  static sf_model Md;
  static cubic_eta C;
  unsigned long long s = 99u;
  phgmg_rom re;
  phgmg_real x[R], xp[R], g[R], gp[R], gm[R], Hs[R * R], Jf[R * R], fp[R], fm[R], Jr[R * R], Rr[R * R];
  double Rd[R * R], ev[R], V[R * R], errg = 0, errh = 0, errj = 0, sg = 0, sh = 0, sj = 0, Hd;
  const double h = 1e-5;
  int i, k, j, t;
  sf_build(&Md, 31u);
  for (i = 0; i < RN; ++i) {
    for (k = 0; k < P; ++k) {
      C.a[i * P + k] = sf_rand(&s);
      for (j = 0; j <= k; ++j) C.A[i * P * P + k + j * P] = C.A[i * P * P + j + k * P] = sf_rand(&s);
    }
    C.c[i] = 0.5 * sf_rand(&s);
  }
  re = Md.rom; re.Ms = NULL; re.eta_cb = eta_cubic; re.eta_user = &C;
  CHECK_RC(phgmg_rom_check(&re), PHGMG_OK);
  for (t = 0; t < 3; ++t) {
    rom_x(x, 0.6);
    Hd = direct_H(&Md, &C, x);
    CHECK_LE(fabs(phgmg_rom_hamiltonian(&re, x, work_a) - Hd), 1e-13 * fabs(Hd));
    phgmg_rom_gradient(&re, x, g, work_a);
    phgmg_rom_hessian(&re, x, Hs, work_a);
    CHECK_RC(phgmg_rom_jacobian(&re, x, Jf, work_a), PHGMG_OK);
    for (k = 0; k < R; ++k) {
      for (i = 0; i < R; ++i) xp[i] = x[i];
      xp[k] = x[k] + h;
      phgmg_rom_gradient(&re, xp, gp, work_a);
      CHECK_RC(phgmg_rom_rhs(&re, xp, NULL, fp, work_a), PHGMG_OK);
      {
        double hp = direct_H(&Md, &C, xp), hm;
        xp[k] = x[k] - h;
        hm = direct_H(&Md, &C, xp);
        errg = fmax(errg, fabs((hp - hm) / (2 * h) - g[k]));
        sg = fmax(sg, fabs(g[k]));
      }
      phgmg_rom_gradient(&re, xp, gm, work_a);
      CHECK_RC(phgmg_rom_rhs(&re, xp, NULL, fm, work_a), PHGMG_OK);
      for (i = 0; i < R; ++i) {
        errh = fmax(errh, fabs((gp[i] - gm[i]) / (2 * h) - Hs[i + k * R]));
        errj = fmax(errj, fabs((fp[i] - fm[i]) / (2 * h) - Jf[i + k * R]));
        sh = fmax(sh, fabs(Hs[i + k * R]));
        sj = fmax(sj, fabs(Jf[i + k * R]));
        CHECK_LE(fabs(Hs[i + k * R] - Hs[k + i * R]), 1e-13 * sh);
      }
    }
    CHECK_RC(phgmg_rom_structure(&re, x, Jr, Rr, work_a), PHGMG_OK);
    for (i = 0; i < R * R; ++i) Rd[i] = Rr[i];
    for (i = 0; i < R; ++i)
      for (k = 0; k < R; ++k) CHECK(Jr[i + k * R] == -Jr[k + i * R]);
    CHECK_RC(phgmg_sym_eig(R, Rd, R, ev, V, R), PHGMG_OK);
    for (i = 0; i < R; ++i) CHECK_LE(-1e-12 * fabs(ev[R - 1] + ev[0]) - 1e-14, ev[i]);
  }
  CHECK_LE(errg, 1e-7 * sg);
  CHECK_LE(errh, 1e-6 * sh);
  CHECK_LE(errj, 1e-6 * sj);
}

/* ---- ham_cb ------------------------------------------------------------------------ */
static phgmg_real ham_Qd[R * R];
static void ham_quad(const phgmg_real *x, phgmg_real *Hn, phgmg_real *g, phgmg_real *Hs, void *user) {
  int i, k;
  (void)user;
  if (Hn) {
    double s = 0;
    for (i = 0; i < R; ++i)
      for (k = 0; k < R; ++k) s += 0.5 * x[i] * ham_Qd[i + k * R] * x[k];
    *Hn = (phgmg_real)s;
  }
  if (g)
    for (i = 0; i < R; ++i) {
      double s = 0;
      for (k = 0; k < R; ++k) s += ham_Qd[i + k * R] * x[k];
      g[i] = (phgmg_real)s;
    }
  if (Hs) memcpy(Hs, ham_Qd, sizeof ham_Qd);
}

TEST(test_rom_ham_cb) {
  static sf_model Md;
  static phgmg_real Qa[R * R];
  phgmg_rom rh;
  phgmg_real x[R], u[M] = {0.1f, 0.2f};
  double a[NALL], b[NALL], Ya[400], Yb[400];
  int i, t;
  sf_build(&Md, 41u);
  for (i = 0; i < R * R; ++i) { Qa[i] = Md.Qh[i] / 2; ham_Qd[i] = Md.Qh[i] - Qa[i]; }
  rh = Md.rom; rh.Qh = Qa; rh.ham_cb = ham_quad;
  for (t = 0; t < 3; ++t) {
    rom_x(x, 0.6);
    CHECK(rom_all(&Md.rom, x, u, a, work_a) == 0);
    CHECK(rom_all(&rh, x, u, b, work_b) == 0);
    CHECK_LE(maxrel(a, b, NALL), 1e-13);
  }
  CHECK(rom_run(&Md.rom, 200, Ya) == 0);
  CHECK(rom_run(&rh, 200, Yb) == 0);
  CHECK_LE(maxrel(Ya, Yb, 2 * 200), 1e-12);
  CHECK(phgmg_rom_stepper_memsize(&rh) <= PHGMG_ROM_STEPPER_MEMSIZE_MAX_CB(R, M, RN, ND));
}

/* ---- binary format ------------------------------------------------------------------ */
TEST(test_rom_binary_exppoly) {
  static sf_model Md;
  static unsigned char buf[1 << 16];
  static double mem[1 << 13];
  phgmg_rom back, cb;
  phgmg_real x[R], u[M] = {0.3f, 0.1f};
  double a[NALL], b[NALL];
  size_t n = 0, need = 0;
  int j, shared;
  sf_build(&Md, 53u);
  for (shared = 0; shared < 2; ++shared) {
    phgmg_rom src = Md.rom;
    if (shared) { src.nphi = 1; src.term = NULL; }
    CHECK_RC(phgmg_rom_serialize(&src, buf, sizeof buf, &n), PHGMG_OK);
    CHECK(n == phgmg_rom_serialized_size(&src));
    CHECK(buf[8] == 2);
    CHECK_RC(phgmg_rom_deserialize_size(buf, n, &need), PHGMG_OK);
    CHECK(need <= sizeof mem);
    CHECK_RC(phgmg_rom_deserialize(buf, n, &back, mem, sizeof mem), PHGMG_OK);
    CHECK(back.nexp == 2 && back.nphi == src.nphi && back.poly_deg == 1);
    if (!shared) for (j = 0; j < ND; ++j) CHECK(back.term && back.term[j] == Md.term[j]);
    else CHECK(back.term == NULL);
    rom_x(x, 0.6);
    CHECK(rom_all(&src, x, u, a, work_a) == 0);
    CHECK(rom_all(&back, x, u, b, work_b) == 0);
    CHECK(maxrel(a, b, NALL) == 0.0);
    buf[n - 9] ^= 1; /* damaged: checksum */
    CHECK_RC(phgmg_rom_deserialize(buf, n, &back, mem, sizeof mem), PHGMG_ERR_FORMAT);
  }
  /* a plain polynomial model is still written as version 1 */
  {
    phgmg_rom p1 = Md.rom;
    p1.nexp = 0; p1.expo = NULL; p1.nphi = 0; p1.term = NULL;
    CHECK_RC(phgmg_rom_serialize(&p1, buf, sizeof buf, &n), PHGMG_OK);
    CHECK(buf[8] == 1);
    CHECK_RC(phgmg_rom_deserialize(buf, n, &back, mem, sizeof mem), PHGMG_OK);
    CHECK(back.nexp == 0 && back.nphi == 0 && back.term == NULL);
  }
  cb = Md.rom; cb.phi_cb = sf_phi_same; cb.phi_user = &Md;
  CHECK_RC(phgmg_rom_serialize(&cb, buf, sizeof buf, &n), PHGMG_ERR_UNSUPPORTED);
  cb = Md.rom; cb.Ms = NULL; cb.eta_cb = eta_builtin; cb.eta_user = &Md;
  CHECK_RC(phgmg_rom_serialize(&cb, buf, sizeof buf, &n), PHGMG_ERR_UNSUPPORTED);
  cb = Md.rom; cb.ham_cb = ham_quad;
  CHECK_RC(phgmg_rom_serialize(&cb, buf, sizeof buf, &n), PHGMG_ERR_UNSUPPORTED);
  CHECK_RC(phgmg_rom_export_c(&cb, "m", "build/sepfun_never.h"), PHGMG_ERR_UNSUPPORTED);
  /* rom_check of the new fields */
  cb = Md.rom; cb.nphi = 2; CHECK_RC(phgmg_rom_check(&cb), PHGMG_ERR_SIZE);
  cb = Md.rom; cb.nexp = 9; CHECK_RC(phgmg_rom_check(&cb), PHGMG_ERR_SIZE);
  cb = Md.rom; cb.expo = NULL; CHECK_RC(phgmg_rom_check(&cb), PHGMG_ERR_INVALID_ARG);
  cb.phi_cb = sf_phi_same; CHECK_RC(phgmg_rom_check(&cb), PHGMG_OK);
}

SUITE(sepfun) {
  RUN(test_fom_exppoly_vs_callbacks);
  RUN(test_fom_check_exppoly);
  RUN(test_rom_exppoly_vs_phi_cb);
  RUN(test_rom_exppoly_fd);
  RUN(test_rom_eta_builtin_equals_ms);
  RUN(test_rom_eta_cubic);
  RUN(test_rom_ham_cb);
  RUN(test_rom_binary_exppoly);
}
