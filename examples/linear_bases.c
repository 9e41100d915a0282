/* linear_bases — linear pH systems: reduced models that hold for every input.

   What it shows: on two linear mass-spring-damper chains (the paper's, N =
   100, one port; and the two-port chain of Gugercin, Polyuga, Beattie & van
   der Schaft 2012: N = 100, m_i = k_i = 4, c_i = 1, forces on masses 1 and
   2) it compares, for r = 4..20, GMG-POD trained on u = 0.1 sin t with GMG
   on four input-independent bases (frequency-sampled, impulse responses,
   balanced right basis, and GMG-H2: for each r the basis whose GMG model has
   the least H2 error found by L-BFGS, 120 (r - m) steps from the balanced
   basis for r >= 12, 300 below, --h2-iters N for N steps; phgmg_linear_basis),
   balanced truncation (BT,
   reference, not pH) and positive-real balanced truncation (PRBT, pH form,
   exact zero-feedthrough Gramians; PRBT-LTI: the same projection W^T A T,
   W^T B, C T without the pH form: with exact Gramians the output C T equals
   the pH output Bh^T Qh x to round-off and Jh - Rh = Ar Sigma_r^-1 up to the
   Riccati residual, so the two agree to 2-3 digits).
   Every reduced model is simulated with the same GL3 scheme (dt = 0.1, 1000
   steps, x0 = 0) on the training input and five inputs no construction
   sees; e_y = sqrt(sum ||y - y_r||^2 / sum ||y||^2).

   Output: results/linear_bases_e_y.csv (r,input,method,input_independent,
   e_y,system), results/linear_bases_bode.svg (largest singular value of
   G(i w) of the two-port chain and of its r = 12 models, and of the errors
   G - G_r), results/linear_bases_structure.csv (two-port chain, every pH
   model: smallest eigenvalue of R relative to the largest, energy-balance
   error relative to max H over 1000 steps of the `mix` input), and an
   H-infinity / H2 error table on the terminal.
   Usage: linear_bases [--out DIR] [--h2-iters N] */
#define _POSIX_C_SOURCE 200809L
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "msd_models.h"
#include "demo_common.h"

/* Largest singular value of the p x m complex matrix E (interleaved re, im,
   column-major; m <= 16): the square root of the largest eigenvalue of the
   real 2m x 2m form of E^H E. */
static double zsigma_max(int p, int m, const double *E) {
  double H[2 * 16 * 2 * 16], w[32];
  int i, j, k;
  if (m > 16) return (double)NAN;
  for (i = 0; i < m; ++i)
    for (j = 0; j < m; ++j) {
      double re = 0.0, im = 0.0;   /* (E^H E)_ij = sum_k conj(E_ki) E_kj */
      for (k = 0; k < p; ++k) {
        const double ar = E[2 * (k + (size_t)i * p)], ai = E[2 * (k + (size_t)i * p) + 1];
        const double br = E[2 * (k + (size_t)j * p)], bi = E[2 * (k + (size_t)j * p) + 1];
        re += ar * br + ai * bi;
        im += ar * bi - ai * br;
      }
      H[i + j * 2 * m] = re; H[(i + m) + (j + m) * 2 * m] = re;
      H[(i + m) + j * 2 * m] = im; H[i + (j + m) * 2 * m] = -im;
    }
  if (phgmg_sym_eig(2 * m, H, 2 * m, w, NULL, 0) != PHGMG_OK) return (double)NAN;
  return sqrt(w[2 * m - 1] > 0.0 ? w[2 * m - 1] : 0.0);
}

#define NIN 6
#define NMETH 8
#define RMAX 20
static const char *in_name[NIN] = {"train_sin", "const", "sin3_alt", "chirp", "pulse", "mix"};
static const char *meth_name[NMETH] = {"GMG-POD", "GMG-FREQ", "GMG-IMPULSE", "GMG-BAL", "BT", "PRBT",
                                       "PRBT-LTI", "GMG-H2"};
static const int meth_indep[NMETH] = {0, 1, 1, 1, 1, 1, 1, 1};
static int g_h2_iters = 0;   /* --h2-iters N: L-BFGS steps of GMG-H2 per order r >= 12; 0: 120 per basis
                                column, 120 (r - m) (300 steps below r = 12) */
static int g_nosim;   /* 1: build the models only (H-inf table, Bode) */

typedef struct { int m, which; } input_ctx;
static void input_fn(double t, double *u, void *user) {
  const input_ctx *c = (const input_ctx *)user;
  int a;
  for (a = 0; a < c->m; ++a) {
    const double sg = (a % 2) ? -1.0 : 1.0;
    switch (c->which) {
      case 0: u[a] = 0.1 * sin(t); break;
      case 1: u[a] = 0.1; break;
      case 2: u[a] = 0.1 * sg * sin(3.0 * t); break;
      case 3: u[a] = 0.1 * sin(0.2 * t + 0.02 * t * t); break;
      case 4: u[a] = t < 5.0 ? 0.1 : 0.0; break;
      default: u[a] = a % 2 ? 0.05 * cos(2.2 * t) : 0.05 * sin(0.5 * t); break;
    }
  }
}

/* Simulate x' = A x + B u, y = C x (r x r) with the online GL3 stepper (a
   LINEAR phgmg_rom with K = A, Qh = I, Bh = B; Newton, one update per step). */
static int sim_abc(int r, int m, const double *A, const double *B, const double *C, int nsteps, double dt,
                   input_ctx *ic, double *Y) {
  phgmg_real K[RMAX * RMAX], Qh[RMAX * RMAX], Bh[RMAX * 2], x[RMAX], u3[6];
  static double mem[16384];
  double ub[2];
  phgmg_rom rom;
  phgmg_rom_stepper st;
  const double s15 = sqrt(15.0) / 10.0, cs[3] = {0.5 - s15, 0.5, 0.5 + s15};
  int i, a, n;
  memset(&rom, 0, sizeof rom);
  for (i = 0; i < r * r; ++i) { K[i] = A[i]; Qh[i] = 0.0; }
  for (i = 0; i < r; ++i) { Qh[i + i * r] = 1.0; x[i] = 0.0; }
  for (i = 0; i < r * m; ++i) Bh[i] = B[i];
  rom.kind = PHGMG_ROM_LINEAR; rom.r = r; rom.m = m; rom.K = K; rom.Qh = Qh; rom.Bh = Bh;
  if (phgmg_rom_stepper_init(&st, &rom, dt, 1e-12, 10, mem, sizeof mem) != PHGMG_OK) return -1;
  for (a = 0; a < m; ++a) Y[a] = 0.0;
  for (n = 0; n < nsteps; ++n) {
    for (i = 0; i < 3; ++i) {
      input_fn(n * dt + cs[i] * dt, ub, ic);
      for (a = 0; a < m; ++a) u3[i * m + a] = ub[a];
    }
    if (phgmg_rom_step(&st, x, u3, NULL, NULL) != PHGMG_OK) return -1;
    for (a = 0; a < m; ++a) {
      double s = 0.0;
      for (i = 0; i < r; ++i) s += C[a + i * m] * x[i];
      Y[a + (size_t)(n + 1) * m] = s;
    }
  }
  return 0;
}

typedef struct {
  const phgmg_ph_system *sys;
  double *X[NIN], *Y[NIN];   /* FOM trajectories and outputs */
  double *pod, *bas[3];      /* N x (N - m) columns (first RMAX used) */
  double *h2[RMAX + 1];      /* GMG-H2: one basis per order r (N x (r - m)) */
  double h2rel[RMAX + 1], h2time;
  double *T, *W, *A, *C;     /* BT bases (N x RMAX), full A, C */
  double *Xr, *Yr;           /* PRBT Riccati solutions */
} study;

static double e_y_of(const study *S, int in, const double *YR) {
  return phgmg_rel_error(S->sys->m, 1001, S->Y[in], S->sys->m, YR, S->sys->m);
}

/* BT at order r from the r = RMAX bases: Ar = W_r^T A T_r, ... */
static void bt_r(const study *S, int r, double *Ar, double *Br, double *Cr) {
  const int N = S->sys->N, m = S->sys->m;
  double *AT = (double *)malloc(sizeof(double) * N * r);
  phgmg_gemm('N', 'N', N, r, N, 1.0, S->A, N, S->T, N, 0.0, AT, N);
  phgmg_gemm('T', 'N', r, r, N, 1.0, S->W, N, AT, N, 0.0, Ar, r);
  phgmg_gemm('T', 'N', r, m, N, 1.0, S->W, N, S->sys->B, N, 0.0, Br, r);
  phgmg_gemm('N', 'N', m, r, N, 1.0, S->C, m, S->T, N, 0.0, Cr, m);
  free(AT);
}

/* The pH model of method j at order r: PRBT (j = 5) or GMG-POD on the
   snapshot POD (0), an input-independent basis (1-3) or the least-H2 basis (7). */
static phgmg_result build_model(const study *S, int j, int r, phgmg_reduced **red) {
  const int N = S->sys->N, m = S->sys->m;
  phgmg_reduce_opts o;
  if (j == 5) {
    phgmg_prbt_opts po;
    memset(&po, 0, sizeof po);
    po.dt = 0.1; po.X = S->Xr; po.Y = S->Yr;
    return phgmg_prbt(red, S->sys, r, &po, NULL, NULL, NULL);
  }
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = r; o.dt = 0.1;
  o.cache.pod_basis = j == 0 ? S->pod : j == 7 ? S->h2[r] : S->bas[j - 1]; o.cache.pod_cols = j == 7 ? r - m : RMAX;
  return o.cache.pod_basis ? phgmg_reduce(red, S->sys, S->X[0], N, 1001, &o, NULL, NULL) : PHGMG_ERR_INVALID_ARG;
}

/* One reduced model (method j, order r): its (A, B, C) and e_y on every input. */
static void run_method(const study *S, int j, int r, double ey[NIN], double *Ar, double *Br, double *Cr) {
  const int N = S->sys->N, m = S->sys->m;
  double *YR = (double *)malloc(sizeof(double) * m * 1001), xr0[RMAX] = {0};
  phgmg_reduced *red = NULL;
  phgmg_result rc = PHGMG_OK;
  int in;
  if (j == 4) {
    bt_r(S, r, Ar, Br, Cr);
  } else {
    rc = build_model(S, j == 6 ? 5 : j, r, &red);
  }
  if (red && j == 6) {   /* PRBT's projection (T, W) without the pH form: W^T A T, W^T B, C T */
    double *Tm = (double *)malloc(sizeof(double) * N * r * 2), *Wm = Tm + (size_t)N * r, e[RMAX];
    int a;
    for (a = 0; a < r; ++a) {
      memset(e, 0, sizeof e);
      e[a] = 1.0;
      phgmg_reduced_lift(red, e, Tm + (size_t)a * N);
    }
    phgmg_reduced_W(red, e, Wm, N);
    {
      double *AT = (double *)malloc(sizeof(double) * N * r);
      phgmg_gemm('N', 'N', N, r, N, 1.0, S->A, N, Tm, N, 0.0, AT, N);
      phgmg_gemm('T', 'N', r, r, N, 1.0, Wm, N, AT, N, 0.0, Ar, r);
      phgmg_gemm('T', 'N', r, m, N, 1.0, Wm, N, S->sys->B, N, 0.0, Br, r);
      phgmg_gemm('N', 'N', m, r, N, 1.0, S->C, m, Tm, N, 0.0, Cr, m);
      free(AT);
    }
    free(Tm);
    phgmg_reduced_destroy(red);
    red = NULL;
  }
  if (red) phgmg_reduced_abc(red, Ar, Br, Cr);
  for (in = 0; in < NIN; ++in) {
    input_ctx ic;
    ic.m = m; ic.which = in;
    ey[in] = NAN;
    if (rc != PHGMG_OK || g_nosim) continue;
    if (j == 4 || j == 6) {
      if (sim_abc(r, m, Ar, Br, Cr, 1000, 0.1, &ic, YR) == 0) ey[in] = e_y_of(S, in, YR);
    } else if (phgmg_reduced_simulate(red, xr0, 0.0, 0.1, 1000, input_fn, &ic, 1e-12, 10, NULL, YR, NULL, NULL,
                                      NULL) == PHGMG_OK) {
      ey[in] = e_y_of(S, in, YR);
    }
  }
  if (rc != PHGMG_OK) fprintf(stderr, "  [%s r=%d: %s]\n", meth_name[j], r, phgmg_result_string(rc));
  phgmg_reduced_destroy(red);
  free(YR);
}

/* GMG-H2 bases for r = 4 .. RMAX, each from the balanced start with 120
   L-BFGS steps per basis column for r >= 12 (the acceptance range; 1320 at r
   = 12, 2280 at r = 20 on the paper's chain; --h2-iters N: N steps), 300 below
   (phgmg_linear_basis, kind H2). With 1000 steps for every order the paper's
   chain met the 10x target in 40-42 of 45 cases, with 80 per column
   in 44. (Starting from
   the order r - 1 optimum plus one balanced column was tried: at the same
   iteration count it ended 2-3x higher in H2 error on the paper's chain.) */
static void study_h2(study *S) {
  const int N = S->sys->N, m = S->sys->m;
  double t0 = demo_now();
  int r;
  for (r = 4; r <= RMAX; ++r) {
    phgmg_basis_opts bo;
    phgmg_result rc;
    memset(&bo, 0, sizeof bo);
    bo.maxit = r >= 12 ? (g_h2_iters > 0 ? g_h2_iters : 120 * (r - m)) : 300;
    bo.h2_rel = &S->h2rel[r];
    S->h2[r] = (double *)malloc(sizeof(double) * N * (r - m));
    rc = phgmg_linear_basis(S->sys, PHGMG_BASIS_H2, r - m, &bo, S->h2[r], NULL, NULL);
    if (rc != PHGMG_OK) {   /* reported; its rows get NaN and check_linear.py fails */
      fprintf(stderr, "  [GMG-H2 basis r=%d: %s]\n", r, phgmg_result_string(rc));
      free(S->h2[r]);
      S->h2[r] = NULL;
    }
  }
  S->h2time = demo_now() - t0;
}

static void study_setup(study *S, const phgmg_ph_system *sys) {
  const int N = sys->N, m = sys->m;
  double *x0 = (double *)calloc((size_t)N, sizeof(double)), hsv[RMAX], Ab[RMAX * RMAX], Bb[RMAX * 2], Cb[RMAX * 2];
  int in, k;
  phgmg_result rc;
  memset(S, 0, sizeof *S);
  S->sys = sys;
  for (in = 0; in < NIN; ++in) {
    input_ctx ic;
    ic.m = m; ic.which = in;
    S->X[in] = (double *)malloc(sizeof(double) * N * 1001);
    S->Y[in] = (double *)malloc(sizeof(double) * m * 1001);
    rc = phgmg_simulate(sys, x0, 0.0, 0.1, 1000, input_fn, &ic, NULL, S->X[in], S->Y[in], NULL, NULL, NULL, NULL);
    if (rc != PHGMG_OK) demo_die("full-order simulation", rc);
  }
  S->pod = (double *)malloc(sizeof(double) * N * RMAX);
  {
    double *Xa = (double *)malloc(sizeof(double) * N * 1001);
    rc = phgmg_adjust_snapshots(N, m, sys->B, 1001, S->X[0], N, Xa, N, NULL);
    if (rc == PHGMG_OK) rc = phgmg_pod(N, 1001, Xa, N, RMAX, 0.0, S->pod, N, NULL, &k, NULL);
    if (rc != PHGMG_OK) demo_die("POD", rc);
    free(Xa);
  }
  for (k = 0; k < 3; ++k) {
    S->bas[k] = (double *)malloc(sizeof(double) * N * RMAX);
    rc = phgmg_linear_basis(sys, (phgmg_basis_kind)(PHGMG_BASIS_FREQ + k), RMAX, NULL, S->bas[k], NULL, NULL);
    if (rc != PHGMG_OK) demo_die("input-independent basis", rc);
  }
  study_h2(S);
  S->T = (double *)malloc(sizeof(double) * N * RMAX);
  S->W = (double *)malloc(sizeof(double) * N * RMAX);
  S->A = (double *)malloc(sizeof(double) * N * N);
  S->C = (double *)malloc(sizeof(double) * N * m);
  S->Xr = (double *)malloc(sizeof(double) * N * N);
  S->Yr = (double *)malloc(sizeof(double) * N * N);
  rc = phgmg_bt(sys, RMAX, Ab, Bb, Cb, hsv, S->T, S->W, NULL);
  if (rc == PHGMG_OK) rc = phgmg_ph_abc(sys, S->A, S->C, NULL);
  if (rc == PHGMG_OK) rc = phgmg_prbt_riccati(sys, 0.0, S->Xr, S->Yr, NULL);
  if (rc != PHGMG_OK) demo_die("BT / PRBT setup", rc);
  free(x0);
}

static void study_free(study *S) {
  int k;
  for (k = 0; k < NIN; ++k) { free(S->X[k]); free(S->Y[k]); }
  for (k = 0; k < 3; ++k) free(S->bas[k]);
  for (k = 0; k <= RMAX; ++k) free(S->h2[k]);
  free(S->pod); free(S->T); free(S->W); free(S->A); free(S->C); free(S->Xr); free(S->Yr);
}

/* Structure and passivity of a pH model (methods 0-3 GMG, 5 PRBT): the
   smallest eigenvalue of R = -(K + K^T)/2 relative to the largest, and the
   largest energy-balance error |H_n - H_0 - S_n + D_n| / max H over 1000
   steps of the `mix` input with the step map. */
static void structure_row(const study *S, int j, int r, FILE *f) {
  const int m = S->sys->m;
  static double H[1001], Su[1001], D[1001];
  double Rr[RMAX * RMAX], w[RMAX], xr0[RMAX] = {0}, e = 0.0, hmax = 0.0;
  phgmg_energy en;
  phgmg_reduced *red = NULL;
  phgmg_result rc;
  input_ctx ic;
  int a, b;
  rc = build_model(S, j, r, &red);
  if (rc != PHGMG_OK) { phgmg_reduced_destroy(red); return; }
  {
    const phgmg_rom *rom = phgmg_reduced_rom(red);
    for (b = 0; b < r; ++b)
      for (a = 0; a < r; ++a) Rr[a + b * r] = -0.5 * ((double)rom->K[a + b * r] + (double)rom->K[b + a * r]);
  }
  phgmg_sym_eig(r, Rr, r, w, NULL, 0);
  ic.m = m; ic.which = 5;
  en.H = H; en.S = Su; en.D = D;
  rc = phgmg_reduced_simulate(red, xr0, 0.0, 0.1, 1000, input_fn, &ic, 1e-12, 10, NULL, NULL, &en, NULL, NULL);
  for (a = 0; a <= 1000 && rc == PHGMG_OK; ++a) {
    e = fmax(e, fabs(H[a] - H[0] - Su[a] + D[a]));
    hmax = fmax(hmax, fabs(H[a]));
  }
  fprintf(f, "%d,%s,%.3e,%.3e\n", r, meth_name[j], w[0] / fmax(fabs(w[r - 1]), 1e-300),
          rc == PHGMG_OK ? e / hmax : NAN);
  phgmg_reduced_destroy(red);
}

/* Bode: sigma_max(G(i w)) of the full model and of the r = 12 models. */
static void bode(const study *S, const char *path) {
  const int N = S->sys->N, m = S->sys->m, nw = 80, r = 12;
  double lw[80], sg[80], G[8], Ar[RMAX * RMAX], Br[RMAX * 2], Cr[RMAX * 2], ey[NIN];
  static double Gf[80 * 8];
  double se[80];
  svgplot_fig *fig = svgplot_new("Two-port chain, r = 12: largest singular value of G(i w) and of the error", 2);
  int j, k, q;
  svgplot_size(fig, 1500, 520);
  svgplot_panel(fig, 0, "(a) sigma_max G(i w)", "log10 w", "sigma_max");
  svgplot_panel(fig, 1, "(b) sigma_max (G - G_r)(i w)", "log10 w", "sigma_max");
  for (j = -1; j < NMETH; ++j) {
    if (j >= 0) run_method(S, j, r, ey, Ar, Br, Cr);
    for (k = 0; k < nw; ++k) {
      lw[k] = -2.0 + 3.5 * k / (nw - 1);
      if (j < 0) {
        phgmg_ss_transfer(N, m, m, S->A, S->sys->B, S->C, pow(10.0, lw[k]), Gf + 8 * k, NULL);
        sg[k] = zsigma_max(m, m, Gf + 8 * k);
      } else {
        phgmg_ss_transfer(r, m, m, Ar, Br, Cr, pow(10.0, lw[k]), G, NULL);
        sg[k] = zsigma_max(m, m, G);
        for (q = 0; q < 8; ++q) G[q] = Gf[8 * k + q] - G[q];
        se[k] = zsigma_max(m, m, G);
      }
    }
    svgplot_series(fig, 0, j < 0 ? "full model" : meth_name[j], nw, lw, sg, j + 1);
    if (j >= 0) svgplot_series(fig, 1, meth_name[j], nw, lw, se, j + 1);
  }
  if (svgplot_save(fig, path) != 0) fprintf(stderr, "cannot write %s\n", path);
  svgplot_free(fig);
}

int main(int argc, char **argv) {
  const char *out = "results";
  char path[512];
  double t0 = demo_now();
  msd_linear M1, M2;
  double m2[50], k2[50], c2[50], *B2;
  study S;
  FILE *f;
  int i, sysk;
  for (i = 1; i < argc; ++i) {
    if (!strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
    else if (!strcmp(argv[i], "--h2-iters") && i + 1 < argc) g_h2_iters = atoi(argv[++i]);
    else { fprintf(stderr, "usage: %s [--out DIR] [--h2-iters N]\n", argv[0]); return 2; }
  }
  demo_mkdir(out);
  for (i = 0; i < 50; ++i) { m2[i] = 4.0; k2[i] = 4.0; c2[i] = 1.0; }
  if (msd_linear_build(&M1, 50, NULL, NULL, NULL, PHGMG_DENSE) != 0 ||
      msd_linear_build(&M2, 50, m2, k2, c2, PHGMG_DENSE) != 0) { fprintf(stderr, "model\n"); return 1; }
  B2 = (double *)calloc(200, sizeof(double));
  B2[1] = 1.0; B2[100 + 3] = 1.0;   /* forces on masses 1 and 2 */
  M2.sys.B = B2; M2.sys.m = 2;
  snprintf(path, sizeof path, "%s/linear_bases_e_y.csv", out);
  f = fopen(path, "w");
  if (!f) { fprintf(stderr, "cannot write %s\n", path); return 1; }
  fprintf(f, "r,input,method,input_independent,e_y,system\n");
  for (sysk = 0; sysk < 2; ++sysk) {
    const phgmg_ph_system *sys = sysk ? &M2.sys : &M1.sys;
    const char *sname = sysk ? "two_port_chain" : "paper_chain";
    int r, j, in;
    study_setup(&S, sys);
    printf("\n%s: GMG-H2 bases (r = 4..%d; L-BFGS steps for r >= 12: %s) in %.2f s; ||G - G_r||_H2 / ||G||_H2 at "
           "r = 12, 16, 20: %.2e, %.2e, %.2e\n", sname, RMAX, g_h2_iters > 0 ? "--h2-iters" : "120 (r - m)", S.h2time, S.h2rel[12],
           S.h2rel[16], S.h2rel[20]);
    printf("\n%s (N = %d, m = %d): e_y on the unseen input sin3_alt / worst unseen input\n  r", sname, sys->N, sys->m);
    for (j = 0; j < NMETH; ++j) printf("  %-21s", meth_name[j]);
    printf("\n");
    for (r = 4; r <= RMAX; ++r) {
      printf("  %2d", r);
      for (j = 0; j < NMETH; ++j) {
        double ey[NIN], Ar[RMAX * RMAX], Br[RMAX * 2], Cr[RMAX * 2], worst = 0.0;
        if (r <= sys->m) { printf("  %-21s", "-"); continue; }
        run_method(&S, j, r, ey, Ar, Br, Cr);
        for (in = 0; in < NIN; ++in) {
          fprintf(f, "%d,%s,%s,%d,%.6e,%s\n", r, in_name[in], meth_name[j], meth_indep[j], ey[in], sname);
          if (in > 0 && !(ey[in] <= worst)) worst = ey[in];
        }
        printf("  %9.2e / %9.2e", ey[2], worst);
      }
      printf("\n");
    }
    if (sysk == 1) {
      g_nosim = 1;
      printf("\ntwo-port chain: H-infinity (grid of 400 log-spaced w in [1e-3, 1e2]) and H2 errors, relative\n"
             "  r  method        Hinf_rel    H2_rel\n");
      /* the full model's G(i w) once on the grid; H2 by phgmg_ss_error (one Lyapunov equation) */
      static double Gf[400 * 8];
      double hr = 0.0;
      int k;
      for (k = 0; k < 400; ++k) {
        phgmg_ss_transfer(sys->N, sys->m, sys->m, S.A, sys->B, S.C, pow(10.0, -3.0 + 5.0 * k / 399.0), Gf + 8 * k, NULL);
        hr = fmax(hr, zsigma_max(sys->m, sys->m, Gf + 8 * k));
      }
      for (r = 12; r <= RMAX; r += 4)
        for (j = 0; j < NMETH; ++j) {
          double ey[NIN], Ar[RMAX * RMAX], Br[RMAX * 2], Cr[RMAX * 2], hi = 0.0, h2 = NAN, h2r = NAN, G[8];
          int q;
          run_method(&S, j, r, ey, Ar, Br, Cr);
          for (k = 0; k < 400; ++k) {
            phgmg_ss_transfer(r, sys->m, sys->m, Ar, Br, Cr, pow(10.0, -3.0 + 5.0 * k / 399.0), G, NULL);
            for (q = 0; q < 8; ++q) G[q] = Gf[8 * k + q] - G[q];
            hi = fmax(hi, zsigma_max(sys->m, sys->m, G));
          }
          phgmg_ss_error(sys->N, S.A, sys->B, S.C, r, Ar, Br, Cr, sys->m, sys->m, 1, 1.0, 1.0, NULL, NULL, &h2,
                         &h2r, NULL);
          printf("  %2d %-12s %9.2e  %9.2e\n", r, meth_name[j], hi / hr, h2 / h2r);
        }
      {
        FILE *fs;
        snprintf(path, sizeof path, "%s/linear_bases_structure.csv", out);
        fs = fopen(path, "w");
        if (!fs) { fprintf(stderr, "cannot write %s\n", path); return 1; }
        fprintf(fs, "r,method,min_eig_R_rel,energy_err_rel\n");
        for (r = 4; r <= RMAX; ++r)
          for (j = 0; j < NMETH; ++j)
            if (j != 4 && j != 6) structure_row(&S, j, r, fs);
        fclose(fs);
      }
      snprintf(path, sizeof path, "%s/linear_bases_bode.svg", out);
      bode(&S, path);
      g_nosim = 0;
    }
    study_free(&S);
  }
  fclose(f);
  M2.sys.B = M2.B; free(B2);
  msd_linear_free(&M1); msd_linear_free(&M2);
  printf("\nwrote %s/linear_bases_e_y.csv and %s/linear_bases_bode.svg\nlinear_bases wall time: %.2f s\n", out, out,
         demo_now() - t0);
  return 0;
}
