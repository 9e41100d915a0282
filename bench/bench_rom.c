/* bench_rom — offline and online timings of the reduced models.

   Models: the paper's linear MSD (50 masses, N = 100, dense) and the nonlinear
   MSD chain (banded, N = 1000 and N = 4000), u = 0.1 sin t, dt = 0.1, 1000
   steps, Newton settings of the demos (linear: tol 1e-10, 10 iterations;
   nonlinear: tol 1e-8, 20 iterations). The full-order runs that produce the
   snapshots are timed too (`ref_fom_*`, the reference of the speed-ups).

   Cases (each: one warm-up run, then RUNS runs; median, min, max of the whole
   case in seconds):
     machine_fma_peak                register-only AVX2 FMA loop: the flop peak
     machine_triad_4M                STREAM-like triad a = b + s c from DRAM (3 x 32 MiB)
     machine_triad_256K_x64          the same, 64 sweeps over 3 x 2 MiB (L3-resident)
     ref_fom_linear_N100, ref_fom_nonlinear_N1000, ref_fom_nonlinear_N4000
     offline_pod_nonlinear_r20       POD (20 modes) of the N = 1000 snapshots
     offline_qmfit_nonlinear_r20     ridge fit of M (GMG-QM, r = 20, r_n = 8):
                                     reduced coordinates, Kronecker design, lstsq
     offline_deim_nonlinear          nonlinear-gradient snapshots + phgmg_deim (tol 1e-8)
     hyper_ecsw_N1000_r20            phgmg_ecsw (tol 1e-6) on the 20020 x 500 training rows
                                     of the GMG-POD basis (r = 20), rows given
     offline_hyper_nonlinear_r20  gradient snapshots + phgmg_ecsw_separable (same fit,
                                     rows never formed)
     offline_<kind>_<model>_r20      the whole phgmg_reduce, no POD cache
     rom_<model>_<kind>_r<8|16|20>   1000 steps of phgmg_rom_step, static workspace
     rom_nonlinear_<kind>_r20_N4000  the same reduced model built from the N = 4000 chain
     rom_nonlinear_interleaved_<kind>_r20_N<1000|4000>
                                     the N = 1000 and N = 4000 models run alternately
                                     (ratio of the medians: the online-cost-flat-in-N check)
   Linear kinds: sp1, gmgpod (both with the precomputed step map), gmgqm;
   nonlinear: gmgpod_deim, sp2_deim, gmgqm_deim.

   Appends `case,median_s,min_s,max_s,runs` to the CSV file of --out (header if
   the file is empty) and prints a table: microseconds per step, Newton
   iterations per step, DEIM points, the flop count per step of the algorithm
   as implemented (see rom_flops), the rate it implies, the output error e_y
   against the full-order model, and the speed-up over it.
     cc -std=c99 -O2 -march=native bench/bench_rom.c -lm && ./a.out --out out.csv */
#define _POSIX_C_SOURCE 199309L
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "../examples/msd_models.h"
#include "bench_args.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <time.h>
#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

#define RUNS_OFF 7   /* machine probes, full-order references, offline */
#define RUNS_ON 21   /* online cases (a few ms each)                    */
#define NSTEPS 1000
#define NS (NSTEPS + 1)
#define DT 0.1
#define RN 8
#define ND_MAX 2048  /* DEIM points the static workspace is sized for */

static FILE *g_csv = NULL;
/* the online stepper works in this static buffer (no allocation online) */
static phgmg_real g_ws[PHGMG_ROM_STEPPER_MEMSIZE_MAX(20, 1, RN, ND_MAX) / sizeof(phgmg_real) + 1];
static phgmg_real g_u3[3 * NSTEPS]; /* inputs at the stage times, precomputed */

/* Cases are timed with the CPU time of this thread (CLOCK_THREAD_CPUTIME_ID):
   on a shared machine it counts the time the case ran on its core, not the
   time other processes held it. The wall-clock median is shown beside it. */
static double now_cpu(void) {
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
static double now_wall(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : (x > y ? 1 : 0);
}
static void *xmalloc(size_t n) {
  void *p = malloc(n ? n : 1);
  if (!p) { fprintf(stderr, "bench_rom: out of memory\n"); exit(1); }
  return p;
}
static void die(const char *what, phgmg_result rc) {
  fprintf(stderr, "bench_rom: %s: %s\n", what, phgmg_result_string(rc));
  exit(1);
}

/* A case: fn(ctx, 0) prepares a run (untimed), fn(ctx, 1) is the timed body;
   both return 0 on success. */
typedef int (*bench_fn)(void *ctx, int phase);
typedef struct timing { double med, mn, mx, wall; int runs; } timing;

static double median_of(double *t, int n) {
  qsort(t, (size_t)n, sizeof(double), cmp_double);
  return (n & 1) ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
}

static timing bench(const char *name, int runs, bench_fn fn, void *ctx) {
  double t[64], w[64];
  timing T;
  int r;
  if (runs > 64) runs = 64;
  for (r = -1; r < runs; ++r) {
    double t0, w0;
    if (fn(ctx, 0) != 0) { fprintf(stderr, "bench_rom: %s: setup failed\n", name); exit(1); }
    w0 = now_wall();
    t0 = now_cpu();
    if (fn(ctx, 1) != 0) { fprintf(stderr, "bench_rom: %s: run failed\n", name); exit(1); }
    if (r >= 0) { t[r] = now_cpu() - t0; w[r] = now_wall() - w0; }
  }
  T.med = median_of(t, runs);
  T.mn = t[0];
  T.mx = t[runs - 1];
  T.wall = median_of(w, runs);
  T.runs = runs;
  if (g_csv) { fprintf(g_csv, "%s,%.9f,%.9f,%.9f,%d\n", name, T.med, T.mn, T.mx, runs); fflush(g_csv); }
  return T;
}

static void row_head(void) {
  printf("times: CPU time of the thread (ms), wall = wall-clock median\n");
  printf("%-36s %9s %9s %9s %9s %4s | %9s %5s %4s %4s %8s %7s %8s %8s\n", "case", "median", "min", "max", "wall",
         "runs", "us/step", "it/st", "fac", "nd", "flop/st", "GFLOP/s", "e_y", "speed-up");
}
static void row(const char *name, timing T, const char *extra) {
  printf("%-36s %9.4f %9.4f %9.4f %9.4f %4d | %s\n", name, 1e3 * T.med, 1e3 * T.mn, 1e3 * T.mx, 1e3 * T.wall,
         T.runs, extra ? extra : "");
  fflush(stdout);
}

/* ---- machine probes ------------------------------------------------------ */
typedef struct peak_ctx { long iters; double sink; } peak_ctx;
#define PEAK_ACC 12 /* independent chains: > FMA latency (4) x FMA pipes (2) */
static int peak_fn(void *vc, int phase) {
  peak_ctx *c = (peak_ctx *)vc;
  long it;
  if (phase == 0) return 0;
#if defined(__AVX2__) && defined(__FMA__)
  {
    /* named registers, not an array: an array may live in memory */
    const __m256d a = _mm256_set1_pd(0.999999), b = _mm256_set1_pd(1e-7);
    __m256d c0 = _mm256_set1_pd(1), c1 = _mm256_set1_pd(2), c2 = _mm256_set1_pd(3), c3 = _mm256_set1_pd(4);
    __m256d c4 = _mm256_set1_pd(5), c5 = _mm256_set1_pd(6), c6 = _mm256_set1_pd(7), c7 = _mm256_set1_pd(8);
    __m256d c8 = _mm256_set1_pd(9), c9 = _mm256_set1_pd(10), c10 = _mm256_set1_pd(11), c11 = _mm256_set1_pd(12);
    double out[4];
    for (it = 0; it < c->iters; ++it) {
#define PEAK_F(v) v = _mm256_fmadd_pd(v, a, b)
      PEAK_F(c0); PEAK_F(c1); PEAK_F(c2); PEAK_F(c3); PEAK_F(c4); PEAK_F(c5);
      PEAK_F(c6); PEAK_F(c7); PEAK_F(c8); PEAK_F(c9); PEAK_F(c10); PEAK_F(c11);
#undef PEAK_F
    }
    c0 = _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(c0, c1), _mm256_add_pd(c2, c3)),
                       _mm256_add_pd(_mm256_add_pd(c4, c5), _mm256_add_pd(c6, c7)));
    c0 = _mm256_add_pd(c0, _mm256_add_pd(_mm256_add_pd(c8, c9), _mm256_add_pd(c10, c11)));
    _mm256_storeu_pd(out, c0);
    c->sink += out[0] + out[1] + out[2] + out[3];
  }
#else
  {
    double a0 = 1, a1 = 2, a2 = 3, a3 = 4, a4 = 5, a5 = 6, a6 = 7, a7 = 8;
    for (it = 0; it < 6 * c->iters; ++it) { /* 8 chains x 2 flops x 6 = 96 flops, as the AVX2 loop */
      a0 = a0 * 0.999999 + 1e-7; a1 = a1 * 0.999999 + 1e-7; a2 = a2 * 0.999999 + 1e-7; a3 = a3 * 0.999999 + 1e-7;
      a4 = a4 * 0.999999 + 1e-7; a5 = a5 * 0.999999 + 1e-7; a6 = a6 * 0.999999 + 1e-7; a7 = a7 * 0.999999 + 1e-7;
    }
    c->sink += a0 + a1 + a2 + a3 + a4 + a5 + a6 + a7;
  }
#endif
  return 0;
}

typedef struct triad_ctx { double *a, *b, *c; long n; } triad_ctx;
static int triad_fn(void *vc, int phase) {
  triad_ctx *c = (triad_ctx *)vc;
  long i;
  if (phase == 0) return 0;
  for (i = 0; i < c->n; ++i) c->a[i] = c->b[i] + 3.0 * c->c[i];
  return 0;
}
static int triad64_fn(void *vc, int phase) {
  int k;
  for (k = 0; k < 64; ++k) { triad_fn(vc, phase); ((triad_ctx *)vc)->b[k] += 1e-300; }
  return 0;
}

/* ---- full-order reference ------------------------------------------------ */
typedef struct fom_ctx {
  const phgmg_ph_system *sys;
  phgmg_gl3_opts go;
  double *X, *Y, *x0;
  phgmg_gl3_stats st;
} fom_ctx;
static int fom_fn(void *vc, int phase) {
  fom_ctx *c = (fom_ctx *)vc;
  if (phase == 0) return 0;
  return phgmg_simulate(c->sys, c->x0, 0.0, DT, NSTEPS, msd_input_sin, NULL, &c->go, c->X, c->Y, NULL, &c->st,
                        NULL, NULL) == PHGMG_OK ? 0 : -1;
}

/* ---- offline ----------------------------------------------------------- */
typedef struct reduce_ctx {
  const phgmg_ph_system *sys;
  const double *X;
  phgmg_reduce_opts o;
  phgmg_reduced *red;
} reduce_ctx;
static int reduce_fn(void *vc, int phase) {
  reduce_ctx *c = (reduce_ctx *)vc;
  if (phase == 0) { phgmg_reduced_destroy(c->red); c->red = NULL; return 0; }
  return phgmg_reduce(&c->red, c->sys, c->X, c->sys->N, NS, &c->o, NULL, NULL) == PHGMG_OK ? 0 : -1;
}

typedef struct pod_ctx { int N, k; const double *X; double *V, *S; } pod_ctx;
static int pod_fn(void *vc, int phase) {
  pod_ctx *c = (pod_ctx *)vc;
  int kout = 0;
  if (phase == 0) return 0;
  return phgmg_pod(c->N, NS, c->X, c->N, c->k, 0.0, c->V, c->N, c->S, &kout, NULL) == PHGMG_OK && kout == c->k ? 0 : -1;
}

/* The M fit of GMG-QM as phgmg_reduce does it: Z2 = V1^T X, Rq = V2^T Xres,
   the p(p+1)/2 distinct Kronecker columns, ridge least squares. */
typedef struct qm_ctx {
  int N, p, rn;
  double lambda;
  const double *X, *V1, *V2, *Xres;
  double *Z2, *Rq, *Kt, *Rqt, *Mt;
} qm_ctx;
static int qm_fn(void *vc, int phase) {
  qm_ctx *c = (qm_ctx *)vc;
  const int p = c->p, rn = c->rn, nc = p * (p + 1) / 2;
  const double s2 = sqrt(2.0);
  int i, a, j, k;
  if (phase == 0) return 0;
  phgmg_gemm('T', 'N', p, NS, c->N, 1.0, c->V1, c->N, c->X, c->N, 0.0, c->Z2, p);
  phgmg_gemm('T', 'N', rn, NS, c->N, 1.0, c->V2, c->N, c->Xres, c->N, 0.0, c->Rq, rn);
  for (i = 0; i < NS; ++i) {
    for (a = 0, k = 0; a < p; ++a)
      for (j = a; j < p; ++j, ++k)
        c->Kt[i + (size_t)k * NS] = (a == j ? 1.0 : s2) * c->Z2[a + (size_t)i * p] * c->Z2[j + (size_t)i * p];
    for (a = 0; a < rn; ++a) c->Rqt[i + (size_t)a * NS] = c->Rq[a + (size_t)i * rn];
  }
  return phgmg_lstsq(NS, nc, rn, c->Kt, NS, c->Rqt, NS, c->lambda, c->Mt, nc, NULL) == PHGMG_OK ? 0 : -1;
}

typedef struct deim_ctx {
  const msd_nonlinear *M;
  const double *X;
  double *F, *w;
  int *pts, nd, nneg;
} deim_ctx;
static int deim_fn(void *vc, int phase) {
  deim_ctx *c = (deim_ctx *)vc;
  const phgmg_ph_system *s = &c->M->sys;
  const int nt = s->nsep, N = s->N;
  int i, k;
  if (phase == 0) return 0;
  for (i = 0; i < NS; ++i)
    for (k = 0; k < nt; ++k) { /* phi'(l) = 4 (k2/4) l^3 from the polynomial */
      const double l = c->X[s->sep_idx[k] + (size_t)i * N];
      c->F[k + (size_t)i * nt] = 4.0 * s->poly[4] * l * l * l + 3.0 * s->poly[3] * l * l + 2.0 * s->poly[2] * l + s->poly[1];
    }
  return phgmg_deim(nt, NS, c->F, nt, NULL, 1e-8, 0, c->pts, c->w, &c->nd, &c->nneg, NULL, NULL) == PHGMG_OK ? 0 : -1;
}

/* Hyper-reduction with non-negative weights on the N = 1000 chain:
   GMG-POD basis V0 = [B, 19 POD modes of the adjusted snapshots] (r = 20);
   training rows (snapshot i, coordinate a) = phi'(l_k(x_i)) V0[idx_k, a]
   (ns r = 20020 rows, one column per term). sep = 0: phgmg_ecsw on the
   formed rows (Gm given, not timed); sep = 1: the gradient snapshots F and
   phgmg_ecsw_separable (rows never formed; F's construction timed). */
typedef struct ecsw_ctx {
  const msd_nonlinear *M;
  const double *X, *V0, *Gm, *t;
  double *F, *Vt, *w, rel;
  int *pts, nd, sep;
} ecsw_ctx;
static int ecsw_fn(void *vc, int phase) {
  ecsw_ctx *c = (ecsw_ctx *)vc;
  const phgmg_ph_system *s = &c->M->sys;
  const int nt = s->nsep, N = s->N;
  int i, k;
  if (phase == 0) return 0;
  if (!c->sep)
    return phgmg_ecsw(nt, NS * 20, c->Gm, NS * 20, c->t, 1e-6, c->pts, c->w, &c->nd, &c->rel, NULL) == PHGMG_OK ? 0 : -1;
  for (i = 0; i < NS; ++i)
    for (k = 0; k < nt; ++k) {
      const double l = c->X[s->sep_idx[k] + (size_t)i * N];
      c->F[k + (size_t)i * nt] = 4.0 * s->poly[4] * l * l * l;
    }
  return phgmg_ecsw_separable(nt, NS, c->F, nt, 20, c->Vt, nt, NULL, 1e-6, c->pts, c->w, &c->nd, &c->rel, NULL) ==
         PHGMG_OK ? 0 : -1;
}

/* ---- online -------------------------------------------------------------- */
typedef struct online_ctx {
  const phgmg_rom *rom;
  phgmg_rom_stepper st;
  phgmg_real tol;
  int maxit;
  phgmg_real x[64], x0[64];
  phgmg_real *y; /* NS outputs */
} online_ctx;
static int online_fn(void *vc, int phase) {
  online_ctx *c = (online_ctx *)vc;
  int n;
  if (phase == 0) {
    memcpy(c->x, c->x0, sizeof(phgmg_real) * (size_t)c->rom->r);
    return phgmg_rom_stepper_init(&c->st, c->rom, (phgmg_real)DT, c->tol, c->maxit, g_ws, sizeof g_ws) == PHGMG_OK
               ? 0 : -1;
  }
  for (n = 0; n < NSTEPS; ++n)
    if (phgmg_rom_step(&c->st, c->x, g_u3 + 3 * n, c->y + n + 1, NULL) != PHGMG_OK) return -1;
  return 0;
}

/* Flops of one run of the online stepper as implemented in the >>online section of phgmg.h
   (multiply and add counted separately; comparisons, copies and pivoting
   not counted), from the model's sizes and the stepper's statistics. */
static double rom_grad_flops(const phgmg_rom *R) {
  const double r = R->r, m = R->m, rn = R->rn, nd = R->nd, p = R->r - R->m, dg = R->poly_deg;
  double f = 2 * r * r;                                   /* Qh x            */
  if (nd > 0) f += 2 * nd * r + nd * (7 * (dg + 1) + 1) + 2 * nd * r; /* P0 x, phi', P0^T d */
  if (R->kind == PHGMG_ROM_QUADRATIC) {
    f += 2 * p * p * rn + 2 * rn * p + rn;                /* Lp, q           */
    f += 2 * r * rn * 2 + 2 * rn * rn + 2 * rn * p;       /* Q01 q, Q01^T x, Q11 q, Lp^T a1 */
    if (nd > 0) f += 2 * nd * rn * 2;                     /* P1 q, P1^T d    */
  }
  (void)m;
  return f;
}
static double rom_rhs_flops(const phgmg_rom *R) {
  const double r = R->r, m = R->m, rn = R->rn, p = R->r - R->m;
  double f = rom_grad_flops(R) + 2 * r * m;
  if (R->kind == PHGMG_ROM_LINEAR) f += 2 * r * r;        /* K g             */
  else f += 2 * rn * rn * p + 4 * r * rn * p + 2.0 / 3.0 * r * r * r + 2 * r * r; /* D^T G D, solve */
  return f;
}
static double rom_flops(const phgmg_rom *R, const phgmg_rom_stats *s, int use_map) {
  const double r = R->r, m = R->m, n3 = 3.0 * R->r, nd = R->nd, rn = R->rn, p = R->r - R->m;
  const double steps = (double)s->steps, its = (double)s->newton_iters, facs = (double)s->factorizations;
  const double out = rom_grad_flops(R) + 2 * r * m;       /* y = Bh^T grad H */
  double resid, jac, upd = 0;
  if (use_map) return steps * (2 * r * r + 2 * r * 3 * m + out);
  if (R->kind == PHGMG_ROM_LINEAR) {
    resid = 3 * rom_rhs_flops(R) + 3 * r + 3 * r * 6;      /* Res = Z - h (A kron I) F(x + Z) */
    jac = rom_grad_flops(R) - 2 * r * r + nd * (7 * (R->poly_deg + 1.0) + 1) + 2 * nd * r * r + 2 * r * r * r;
  } else {
    /* mass-matrix form: per stage grad H, E Phi without forming E, one solve with E_f */
    const double eapply = 2 * (2 * rn * p + 2 * rn * r + rn * rn + r * r);
    const double dgd = 2 * rn * rn * p + 4 * r * rn * p;
    const double hess = rom_grad_flops(R) + p * (2 * r * rn + 2 * rn * rn + 4 * rn * p) +
                        nd * (7 * (R->poly_deg + 1.0) + 1 + 2 * rn * p + 2 * r * r);
    resid = 3 * (rom_grad_flops(R) + eapply + 2 * r * r + 2 * r * m + r) + 3 * r * 12;
    upd = 3 * 2 * r * r + 3 * r;                            /* Phi += Jf dZ - Del */
    jac = hess + dgd + 2.0 / 3.0 * r * r * r + 2 * r * r + 2 * (rn * p + rn * r + rn * rn) +
          p * (2 * rn * p + 2 * rn * rn + 2 * r * rn + 4 * rn * p) + 2 * r * r * r;
    return steps * (resid + 6 * r + 24 * r + 9 * r + out)
           + its * (2 * n3 * n3 + resid + upd)
           + facs * (jac + 2 * r * r * 3 + 2.0 / 3.0 * n3 * n3 * n3)
           + (double)s->e_refreshes * (2 * rn * p * p + dgd + 2.0 / 3.0 * r * r * r);
  }
  return steps * (resid + 6 * r + 24 * r + out)              /* initial residual, update, extrapolation */
         + its * (2 * n3 * n3 + resid)                       /* Newton iterations                       */
         + facs * (jac + 2 * r * r * 3 + 2.0 / 3.0 * n3 * n3 * n3); /* I - h A kron Jf, LU          */
}

typedef struct model_data {
  const char *tag;                   /* "linear" / "nonlinear" */
  const phgmg_ph_system *sys;
  double *X, *Y;                     /* snapshots N x NS, outputs NS */
  timing fom;
  double tol;
  int maxit;
} model_data;

static double g_peak = 0.0; /* GFLOP/s of machine_fma_peak */
static double g_bw_dram = 0.0, g_bw_l3 = 0.0; /* GB/s of the triads */

static const char *g_only = NULL; /* BENCH_ROM_ONLY: run only online cases containing it */
static void online_case(const char *name, const model_data *md, phgmg_reduced *red) {
  const phgmg_rom *rom = phgmg_reduced_rom(red);
  online_ctx c;
  timing T;
  size_t need = phgmg_rom_stepper_memsize(rom);
  double fl, ey;
  if (g_only && !strstr(name, g_only)) return;
  char extra[256];
  phgmg_real work[4096];
  double *yd = (double *)xmalloc(sizeof(double) * NS), xr[64];
  int n;
  if (need == 0 || need > sizeof g_ws || phgmg_rom_eval_work_size(rom) > 4096 || rom->r > 64) {
    fprintf(stderr, "bench_rom: %s: model too large for the static workspace (%zu bytes)\n", name, need);
    exit(1);
  }
  memset(&c, 0, sizeof c);
  c.rom = rom;
  c.tol = (phgmg_real)md->tol;
  c.maxit = md->maxit;
  c.y = (phgmg_real *)xmalloc(sizeof(phgmg_real) * NS);
  phgmg_reduced_restrict(red, md->X, xr); /* rho(x0) */
  for (n = 0; n < rom->r; ++n) c.x0[n] = (phgmg_real)xr[n];
  phgmg_rom_output(rom, c.x0, c.y, work);
  T = bench(name, RUNS_ON, online_fn, &c);
  /* the statistics of the last run (init resets them) */
  fl = rom_flops(rom, &c.st.stats, c.st.use_map);
  for (n = 0; n < NS; ++n) yd[n] = (double)c.y[n];
  ey = phgmg_rel_error(1, NS, md->Y, 1, yd, 1);
  snprintf(extra, sizeof extra, "%9.3f %5.2f %4ld %4d %8.0f %7.2f %8.2e %8.1f%s", 1e6 * T.med / NSTEPS,
           (double)c.st.stats.newton_iters / NSTEPS, c.st.stats.factorizations, rom->nd, fl / NSTEPS,
           fl / T.med * 1e-9, ey,
           md->fom.med / T.med, c.st.use_map ? "  (step map)" : "");
  row(name, T, extra);
  free(c.y);
  free(yd);
}

static phgmg_reduced *build(const model_data *md, phgmg_method meth, int r, double lambda, int with_map) {
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  phgmg_result rc;
  memset(&o, 0, sizeof o);
  o.method = meth; o.r = r; o.qm.rn = RN; o.qm.lambda = lambda;
  o.hyper.on = 1; o.hyper.deim_tol = 1e-8; o.hyper.allow_negative = 1;
  if (with_map) o.dt = DT;
  rc = phgmg_reduce(&red, md->sys, md->X, md->sys->N, NS, &o, NULL, NULL);
  if (rc != PHGMG_OK) die("phgmg_reduce", rc);
  return red;
}

/* GMG-QM lambda of the nonlinear demo: max(0.2 e_proj(GMG-POD, r), 10^-2.5). */
static double nl_lambda(const model_data *md, int r) {
  phgmg_reduced *red = build(md, PHGMG_METHOD_GMG_POD, r, 0.0, 0);
  double e = phgmg_err_proj(red, md->X, md->sys->N, NS);
  phgmg_reduced_destroy(red);
  return fmax(0.2 * e, pow(10.0, -2.5));
}

static void fom_reference(const char *name, model_data *md, double tol, int maxit) {
  fom_ctx c;
  char extra[160];
  memset(&c, 0, sizeof c);
  c.sys = md->sys;
  c.go.tol = tol; c.go.max_iter = maxit;
  c.X = md->X; c.Y = md->Y;
  c.x0 = (double *)xmalloc(sizeof(double) * (size_t)md->sys->N);
  memset(c.x0, 0, sizeof(double) * (size_t)md->sys->N);
  md->tol = tol; md->maxit = maxit;
  md->fom = bench(name, RUNS_OFF, fom_fn, &c);
  snprintf(extra, sizeof extra, "%9.3f %5.2f %4ld    -  (N = %d, %s; %ld rhs evaluations; %.3f us per step and unknown)",
           1e6 * md->fom.med / NSTEPS, (double)c.st.newton_iters / NSTEPS, c.st.factorizations, md->sys->N,
           md->sys->storage == PHGMG_BANDED ? "banded" : "dense", c.st.rhs_evals,
           1e6 * md->fom.med / NSTEPS / md->sys->N);
  row(name, md->fom, extra);
  free(c.x0);
}

/* Machine probes: FMA peak, DRAM and L3 triad bandwidth (g_peak, g_bw_*). */
static void bench_machine(void) {
  char extra[160];
  int i;
  peak_ctx pc;
  triad_ctx tc;
  timing T;
  pc.iters = 4000000; pc.sink = 0.0;
  T = bench("machine_fma_peak", RUNS_OFF, peak_fn, &pc);
  g_peak = (double)pc.iters * PEAK_ACC * 8.0 / T.med * 1e-9;
  snprintf(extra, sizeof extra, "%s: %.2f GFLOP/s (12 independent 4-wide FMA chains)%s",
#if defined(__AVX2__) && defined(__FMA__)
           "AVX2 FMA",
#else
           "scalar",
#endif
           g_peak, pc.sink == 12345.0 ? " " : "");
  row("machine_fma_peak", T, extra);
  tc.n = 4L << 20; /* 3 x 32 MiB: from DRAM */
  tc.a = (double *)xmalloc(sizeof(double) * (size_t)tc.n);
  tc.b = (double *)xmalloc(sizeof(double) * (size_t)tc.n);
  tc.c = (double *)xmalloc(sizeof(double) * (size_t)tc.n);
  for (i = 0; i < tc.n; ++i) { tc.a[i] = 0.0; tc.b[i] = 1.0; tc.c[i] = 2.0; }
  T = bench("machine_triad_4M", RUNS_OFF, triad_fn, &tc);
  g_bw_dram = 24.0 * (double)tc.n / T.med * 1e-9;
  snprintf(extra, sizeof extra, "a = b + s c over 3 x 32 MiB (DRAM): %.2f GB/s (24 bytes per element)", g_bw_dram);
  row("machine_triad_4M", T, extra);
  tc.n = 256L << 10; /* 3 x 2 MiB: beyond L2, inside L3; 64 sweeps per run */
  {
    triad_ctx t2 = tc;
    T = bench("machine_triad_256K_x64", RUNS_OFF, triad64_fn, &t2);
    g_bw_l3 = 64.0 * 24.0 * (double)tc.n / T.med * 1e-9;
    snprintf(extra, sizeof extra, "the same over 3 x 2 MiB (L3), 64 sweeps: %.2f GB/s", g_bw_l3);
    row("machine_triad_256K_x64", T, extra);
  }
  free(tc.a); free(tc.b); free(tc.c);
}

/* Offline: the POD of the nonlinear N = 1000 snapshots (r = 20). */
static void bench_offline_pod(const model_data *nl1) {
  const int N = nl1->sys->N;
  pod_ctx pc;
  timing T;
  int rank = 0, kk = 0;
  double s1;
  char extra[160];
  /* numerical rank of the snapshots, for the nominal POD flop count 4 N ns rank */
  {
    double *U = (double *)xmalloc(sizeof(double) * N), ss;
    if (phgmg_svd(N, NS, nl1->X, N, 1, &ss, U, N, NULL, 1, &kk, &rank, NULL) != PHGMG_OK) die("svd", PHGMG_ERR_RANK);
    s1 = ss;
    free(U);
  }
  pc.N = N; pc.k = 20; pc.X = nl1->X;
  pc.V = (double *)xmalloc(sizeof(double) * (size_t)N * 20); pc.S = (double *)xmalloc(sizeof(double) * 20);
  T = bench("offline_pod_nonlinear_r20", RUNS_OFF, pod_fn, &pc);
  snprintf(extra, sizeof extra, "numerical rank %d, sigma1 %.3e; nominal 4 N ns rank = %.2f GFLOP -> %.2f GFLOP/s",
           rank, s1, 4.0 * N * NS * rank * 1e-9, 4.0 * N * NS * rank / T.med * 1e-9);
  row("offline_pod_nonlinear_r20", T, extra);
  free(pc.V); free(pc.S);
}

/* Offline: the GMG-QM ridge fit at r = 20 (V1, V2 from the hierarchical POD, untimed). */
static void bench_offline_qmfit(const model_data *nl1, double lam20) {
  const int N = nl1->sys->N, p = 20 - 1;
  qm_ctx qc;
  timing T;
  char extra[160];
  /* QM fit: V1 (p modes) and V2 (r_n modes) from the hierarchical POD, untimed */
  memset(&qc, 0, sizeof qc);
  qc.N = N; qc.p = p; qc.rn = RN; qc.lambda = lam20; qc.X = nl1->X;
  {
    double *V1 = (double *)xmalloc(sizeof(double) * (size_t)N * p), *V2 = (double *)xmalloc(sizeof(double) * (size_t)N * RN);
    double *Xr = (double *)xmalloc(sizeof(double) * (size_t)N * NS), *B0 = (double *)xmalloc(sizeof(double) * (size_t)N * (p + 1));
    double *C = (double *)xmalloc(sizeof(double) * (size_t)(p + 1) * NS);
    phgmg_result prc = phgmg_pod_hierarchical(N, 1, nl1->sys->B, NS, nl1->X, N, p, RN, V1, V2, NULL);
    if (prc != PHGMG_OK) die("phgmg_pod_hierarchical", prc);
    /* residual (I - P) X with P the orthogonal projector onto [B, V1] (B is a unit vector orthogonal to V1) */
    memcpy(B0, nl1->sys->B, sizeof(double) * (size_t)N);
    memcpy(B0 + N, V1, sizeof(double) * (size_t)N * p);
    memcpy(Xr, nl1->X, sizeof(double) * (size_t)N * NS);
    phgmg_gemm('T', 'N', p + 1, NS, N, 1.0, B0, N, nl1->X, N, 0.0, C, p + 1);
    phgmg_gemm('N', 'N', N, NS, p + 1, -1.0, B0, N, C, p + 1, 1.0, Xr, N);
    qc.V1 = V1; qc.V2 = V2; qc.Xres = Xr;
    qc.Z2 = (double *)xmalloc(sizeof(double) * (size_t)p * NS);
    qc.Rq = (double *)xmalloc(sizeof(double) * (size_t)RN * NS);
    qc.Kt = (double *)xmalloc(sizeof(double) * (size_t)NS * (p * (p + 1) / 2));
    qc.Rqt = (double *)xmalloc(sizeof(double) * (size_t)NS * RN);
    qc.Mt = (double *)xmalloc(sizeof(double) * (size_t)(p * (p + 1) / 2) * RN);
    T = bench("offline_qmfit_nonlinear_r20", RUNS_OFF, qm_fn, &qc);
    {
      const double nc = p * (p + 1) / 2.0, mm = NS + nc;
      const double fl = 2.0 * (p + RN) * NS * N + 2.0 * mm * nc * nc - 2.0 / 3.0 * nc * nc * nc + 4.0 * mm * nc * RN;
      snprintf(extra, sizeof extra, "lambda %.3e, %d x %d ridge LS, %d rhs; nominal %.3f GFLOP -> %.2f GFLOP/s",
               lam20, NS, (int)nc, RN, fl * 1e-9, fl / T.med * 1e-9);
    }
    row("offline_qmfit_nonlinear_r20", T, extra);
    free(V1); free(V2); free(Xr); free(B0); free(C);
    free(qc.Z2); free(qc.Rq); free(qc.Kt); free(qc.Rqt); free(qc.Mt);
  }
}

/* Offline: DEIM of the quartic terms, and ECSW on the same gradient snapshots. */
static void bench_offline_hyper(const msd_nonlinear *MN1, const model_data *nl1) {
  const int N = nl1->sys->N, r = 20;
  deim_ctx dc;
  timing T;
  int rank = 0, kk = 0, i, k;
  char extra[160];
  memset(&dc, 0, sizeof dc);
  dc.M = MN1; dc.X = nl1->X;
  dc.F = (double *)xmalloc(sizeof(double) * (size_t)MN1->sys.nsep * NS);
  dc.w = (double *)xmalloc(sizeof(double) * (size_t)MN1->sys.nsep);
  dc.pts = (int *)xmalloc(sizeof(int) * (size_t)MN1->sys.nsep);
  T = bench("offline_deim_nonlinear", RUNS_OFF, deim_fn, &dc);
  { /* numerical rank of the gradient snapshots, for the nominal 4 nterms ns rank */
    double *U = (double *)xmalloc(sizeof(double) * (size_t)MN1->sys.nsep), ss;
    if (phgmg_svd(MN1->sys.nsep, NS, dc.F, MN1->sys.nsep, 1, &ss, U, MN1->sys.nsep, NULL, 1, &kk, &rank, NULL) != PHGMG_OK)
      die("svd", PHGMG_ERR_RANK);
    free(U);
  }
  snprintf(extra, sizeof extra, "%d x %d gradient snapshots, rank %d (nominal %.2f GFLOP), %d DEIM points, %d negative weights",
           MN1->sys.nsep, NS, rank, 4.0 * MN1->sys.nsep * NS * rank * 1e-9, dc.nd, dc.nneg);
  row("offline_deim_nonlinear", T, extra);
  if (!g_only || strstr("hyper_ecsw_N1000_r20 offline_hyper_nonlinear_r20", g_only)) {
    const int nt = MN1->sys.nsep, m = NS * r; /* r = 20 */
    ecsw_ctx ec;
    double *V0 = (double *)xmalloc(sizeof(double) * (size_t)N * r), *Xa = (double *)xmalloc(sizeof(double) * (size_t)N * NS);
    double *Gm = (double *)xmalloc(sizeof(double) * (size_t)m * nt), *tg = (double *)xmalloc(sizeof(double) * (size_t)m);
    double wmin;
    int a, sep;
    phgmg_result prc = phgmg_adjust_snapshots(N, 1, MN1->sys.B, NS, nl1->X, N, Xa, N, NULL);
    memcpy(V0, MN1->sys.B, sizeof(double) * (size_t)N); /* B is a unit vector orthogonal to the adjusted snapshots */
    if (prc == PHGMG_OK) prc = phgmg_pod(N, NS, Xa, N, r - 1, 0.0, V0 + N, N, NULL, &kk, NULL);
    if (prc != PHGMG_OK) die("hyper basis", prc);
    memset(&ec, 0, sizeof ec);
    ec.M = MN1; ec.X = nl1->X; ec.V0 = V0; ec.Gm = Gm; ec.t = tg;
    ec.F = (double *)xmalloc(sizeof(double) * (size_t)nt * NS);
    ec.Vt = (double *)xmalloc(sizeof(double) * (size_t)nt * r);
    ec.w = (double *)xmalloc(sizeof(double) * (size_t)nt);
    ec.pts = (int *)xmalloc(sizeof(int) * (size_t)nt);
    for (k = 0; k < nt; ++k)
      for (a = 0; a < r; ++a) ec.Vt[k + (size_t)a * nt] = V0[MN1->sys.sep_idx[k] + (size_t)a * N];
    for (i = 0; i < m; ++i) tg[i] = 0.0;
    for (k = 0; k < nt; ++k) {
      for (i = 0; i < NS; ++i) {
        const double l = nl1->X[MN1->sys.sep_idx[k] + (size_t)i * N], d = 4.0 * MN1->sys.poly[4] * l * l * l;
        for (a = 0; a < r; ++a) Gm[i * r + a + (size_t)k * m] = d * ec.Vt[k + (size_t)a * nt];
      }
      for (i = 0; i < m; ++i) tg[i] += Gm[i + (size_t)k * m];
    }
    for (sep = 0; sep < 2; ++sep) {
      const char *nm = sep ? "offline_hyper_nonlinear_r20" : "hyper_ecsw_N1000_r20";
      ec.sep = sep;
      T = bench(nm, RUNS_OFF, ecsw_fn, &ec);
      for (wmin = 1e300, i = 0; i < ec.nd; ++i) if (ec.w[i] < wmin) wmin = ec.w[i];
      snprintf(extra, sizeof extra, "%s: %d x %d, tol 1e-6: %d points (DEIM 1e-8: %d), residual %.2e, min weight %.3f",
               sep ? "F + phgmg_ecsw_separable" : "phgmg_ecsw", sep ? nt : m, sep ? NS : nt, ec.nd, dc.nd, ec.rel, wmin);
      row(nm, T, extra);
    }
    free(V0); free(Xa); free(Gm); free(tg); free(ec.F); free(ec.Vt); free(ec.w); free(ec.pts);
  }
  free(dc.F); free(dc.w); free(dc.pts);
}

/* Offline: whole phgmg_reduce of every method at r = 20. */
static void bench_offline_reduce(const model_data *lin, const model_data *nl1, double lam20) {
  reduce_ctx rc;
  timing T;
  int i;
  char extra[160];
  {
    static const struct { const char *name; phgmg_method m; int lin, map; } oc[] = {
      {"offline_gmgpod_nonlinear_r20", PHGMG_METHOD_GMG_POD, 0, 0},
      {"offline_sp2_nonlinear_r20", PHGMG_METHOD_SP2, 0, 0},
      {"offline_gmgqm_nonlinear_r20", PHGMG_METHOD_GMG_QM, 0, 0},
      {"offline_sp1_linear_r20", PHGMG_METHOD_SP1, 1, 1},
      {"offline_gmgpod_linear_r20", PHGMG_METHOD_GMG_POD, 1, 1},
      {"offline_gmgqm_linear_r20", PHGMG_METHOD_GMG_QM, 1, 0},
    };
    for (i = 0; i < (int)(sizeof oc / sizeof oc[0]); ++i) {
      const model_data *md = oc[i].lin ? lin : nl1;
      memset(&rc, 0, sizeof rc);
      rc.sys = md->sys; rc.X = md->X;
      rc.o.method = oc[i].m; rc.o.r = 20; rc.o.qm.rn = RN;
      rc.o.qm.lambda = oc[i].lin ? 1e-3 : lam20;
      rc.o.hyper.on = 1; rc.o.hyper.deim_tol = 1e-8; rc.o.hyper.allow_negative = 1;
      if (oc[i].map) rc.o.dt = DT;
      T = bench(oc[i].name, RUNS_OFF, reduce_fn, &rc);
      snprintf(extra, sizeof extra, "whole phgmg_reduce, N = %d%s", md->sys->N,
               oc[i].map ? ", with the GL3 step map" : (oc[i].lin ? "" : ", DEIM"));
      row(oc[i].name, T, extra);
      phgmg_reduced_destroy(rc.red);
    }
  }
}

/* Online: every method at r = 8, 16, 20 on the linear and the nonlinear chain,
   and the r = 20 models of the N = 4000 chain (online cost must not depend on N). */
static void bench_online(const model_data *lin, const model_data *nl1, const model_data *nl4) {
  static const int rs[3] = {8, 16, 20};
  char name[96];
  int k;
  for (k = 0; k < 3; ++k) {
    const int r = rs[k];
    phgmg_reduced *red;
    snprintf(name, sizeof name, "rom_linear_sp1_r%d", r);
    red = build(lin, PHGMG_METHOD_SP1, r, 0.0, 1);
    online_case(name, lin, red);
    phgmg_reduced_destroy(red);
    snprintf(name, sizeof name, "rom_linear_gmgpod_r%d", r);
    red = build(lin, PHGMG_METHOD_GMG_POD, r, 0.0, 1);
    online_case(name, lin, red);
    phgmg_reduced_destroy(red);
    snprintf(name, sizeof name, "rom_linear_gmgqm_r%d", r);
    red = build(lin, PHGMG_METHOD_GMG_QM, r, 1e-3, 0);
    online_case(name, lin, red);
    phgmg_reduced_destroy(red);
  }
  for (k = 0; k < 3; ++k) {
    const int r = rs[k];
    phgmg_reduced *red;
    snprintf(name, sizeof name, "rom_nonlinear_gmgpod_deim_r%d", r);
    red = build(nl1, PHGMG_METHOD_GMG_POD, r, 0.0, 0);
    online_case(name, nl1, red);
    phgmg_reduced_destroy(red);
    snprintf(name, sizeof name, "rom_nonlinear_sp2_deim_r%d", r);
    red = build(nl1, PHGMG_METHOD_SP2, r, 0.0, 0);
    online_case(name, nl1, red);
    phgmg_reduced_destroy(red);
    snprintf(name, sizeof name, "rom_nonlinear_gmgqm_deim_r%d", r);
    red = build(nl1, PHGMG_METHOD_GMG_QM, r, nl_lambda(nl1, r), 0);
    online_case(name, nl1, red);
    phgmg_reduced_destroy(red);
  }
    phgmg_reduced *red;
    red = build(nl4, PHGMG_METHOD_GMG_POD, 20, 0.0, 0);
    online_case("rom_nonlinear_gmgpod_deim_r20_N4000", nl4, red);
    phgmg_reduced_destroy(red);
    red = build(nl4, PHGMG_METHOD_SP2, 20, 0.0, 0);
    online_case("rom_nonlinear_sp2_deim_r20_N4000", nl4, red);
    phgmg_reduced_destroy(red);
    red = build(nl4, PHGMG_METHOD_GMG_QM, 20, nl_lambda(nl4, 20), 0);
    online_case("rom_nonlinear_gmgqm_deim_r20_N4000", nl4, red);
    phgmg_reduced_destroy(red);
}

/* Online, interleaved: the N = 1000 and N = 4000 models alternate run by run,
   so that slow phases of a shared machine hit both alike. */
static void bench_online_interleaved(const model_data *nl1, const model_data *nl4) {
  static const phgmg_method km[3] = {PHGMG_METHOD_GMG_POD, PHGMG_METHOD_SP2, PHGMG_METHOD_GMG_QM};
  static const char *kn[3] = {"gmgpod_deim", "sp2_deim", "gmgqm_deim"};
  char extra[160];
  int k;
  for (k = 0; k < 3; ++k) if (!g_only || strstr("rom_nonlinear_interleaved", g_only)) {
    phgmg_reduced *r1 = build(nl1, km[k], 20, km[k] == PHGMG_METHOD_GMG_QM ? nl_lambda(nl1, 20) : 0.0, 0);
    phgmg_reduced *r4 = build(nl4, km[k], 20, km[k] == PHGMG_METHOD_GMG_QM ? nl_lambda(nl4, 20) : 0.0, 0);
    online_ctx c[2];
    double t[2][RUNS_ON];
    timing T[2];
    int run, j;
    for (j = 0; j < 2; ++j) {
      const model_data *md = j ? nl4 : nl1;
      double xr[64];
      int a;
      memset(&c[j], 0, sizeof c[j]);
      c[j].rom = phgmg_reduced_rom(j ? r4 : r1);
      c[j].tol = (phgmg_real)md->tol;
      c[j].maxit = md->maxit;
      c[j].y = (phgmg_real *)xmalloc(sizeof(phgmg_real) * NS);
      phgmg_reduced_restrict(j ? r4 : r1, md->X, xr);
      for (a = 0; a < c[j].rom->r; ++a) c[j].x0[a] = (phgmg_real)xr[a];
    }
    for (run = -1; run < RUNS_ON; ++run)
      for (j = 0; j < 2; ++j) {
        double t0;
        if (online_fn(&c[j], 0) != 0) die("interleaved setup", PHGMG_ERR_INVALID_ARG);
        t0 = now_cpu();
        if (online_fn(&c[j], 1) != 0) die("interleaved run", PHGMG_ERR_NOT_CONVERGED);
        if (run >= 0) t[j][run] = now_cpu() - t0;
      }
    for (j = 0; j < 2; ++j) {
      char nm[96];
      T[j].med = median_of(t[j], RUNS_ON);
      T[j].mn = t[j][0]; T[j].mx = t[j][RUNS_ON - 1]; T[j].wall = T[j].med; T[j].runs = RUNS_ON;
      snprintf(nm, sizeof nm, "rom_nonlinear_interleaved_%s_r20_N%d", kn[k], j ? 4000 : 1000);
      if (g_csv) { fprintf(g_csv, "%s,%.9f,%.9f,%.9f,%d\n", nm, T[j].med, T[j].mn, T[j].mx, RUNS_ON); fflush(g_csv); }
      snprintf(extra, sizeof extra, "%9.3f  interleaved%s", 1e6 * T[j].med / NSTEPS,
               j ? "" : "  (N = 4000 / N = 1000 on the next line)");
      if (j) snprintf(extra, sizeof extra, "%9.3f  interleaved; N = 4000 / N = 1000 = %.3f", 1e6 * T[j].med / NSTEPS,
                      T[1].med / T[0].med);
      row(nm, T[j], extra);
    }
    free(c[0].y); free(c[1].y);
    phgmg_reduced_destroy(r1);
    phgmg_reduced_destroy(r4);
  }
}

int main(int argc, char **argv) {
  msd_linear ML;
  msd_nonlinear MN1, MN4;
  msd_nl_opts mo;
  model_data lin, nl1, nl4;
  int i, k;
  g_only = getenv("BENCH_ROM_ONLY");
  {
    const char *out;
    int rc = bench_args(argc, argv, "bench_rom",
                        "Offline and online timings of the reduced models (BENCH_ROM_ONLY=case runs one case).", &out,
                        NULL, NULL);
    if (rc) return rc == 1 ? 0 : 2;
    g_csv = bench_open_csv("bench_rom", out, &rc);
    if (rc) return 1;
  }
  for (i = 0; i < NSTEPS; ++i) {
    phgmg_real tc[3];
    phgmg_rom_stage_times((phgmg_real)(i * DT), (phgmg_real)DT, tc);
    for (k = 0; k < 3; ++k) g_u3[3 * i + k] = (phgmg_real)(0.1 * sin((double)tc[k]));
  }
  row_head();

  bench_machine();

  /* models and full-order references (their trajectories are the snapshots) */
  if (msd_linear_build(&ML, 50, NULL, NULL, NULL, PHGMG_DENSE) != 0) die("linear model", PHGMG_ERR_NOMEM);
  memset(&mo, 0, sizeof mo);
  mo.n = 500; mo.storage = PHGMG_BANDED;
  if (msd_nonlinear_build(&MN1, &mo) != 0) die("nonlinear model", PHGMG_ERR_NOMEM);
  mo.n = 2000;
  if (msd_nonlinear_build(&MN4, &mo) != 0) die("nonlinear model", PHGMG_ERR_NOMEM);
  memset(&lin, 0, sizeof lin); memset(&nl1, 0, sizeof nl1); memset(&nl4, 0, sizeof nl4);
  lin.tag = "linear"; lin.sys = &ML.sys;
  nl1.tag = "nonlinear"; nl1.sys = &MN1.sys;
  nl4.tag = "nonlinear"; nl4.sys = &MN4.sys;
  lin.X = (double *)xmalloc(sizeof(double) * (size_t)lin.sys->N * NS); lin.Y = (double *)xmalloc(sizeof(double) * NS);
  nl1.X = (double *)xmalloc(sizeof(double) * (size_t)nl1.sys->N * NS); nl1.Y = (double *)xmalloc(sizeof(double) * NS);
  nl4.X = (double *)xmalloc(sizeof(double) * (size_t)nl4.sys->N * NS); nl4.Y = (double *)xmalloc(sizeof(double) * NS);
  fom_reference("ref_fom_linear_N100", &lin, 1e-10, 10);
  fom_reference("ref_fom_nonlinear_N1000", &nl1, 1e-8, 20);
  fom_reference("ref_fom_nonlinear_N4000", &nl4, 1e-8, 20);

  {
    const double lam20 = nl_lambda(&nl1, 20);
    bench_offline_pod(&nl1);
    bench_offline_qmfit(&nl1, lam20);
    bench_offline_hyper(&MN1, &nl1);
    bench_offline_reduce(&lin, &nl1, lam20);
  }
  bench_online(&lin, &nl1, &nl4);
  bench_online_interleaved(&nl1, &nl4);
  printf("flop/st: flops per step of the algorithm as implemented (bench_rom.c: rom_flops); "
         "machine peaks: %.2f GFLOP/s (machine_fma_peak), triad %.2f GB/s DRAM, %.2f GB/s L3\n", g_peak, g_bw_dram,
         g_bw_l3);

  free(lin.X); free(lin.Y); free(nl1.X); free(nl1.Y); free(nl4.X); free(nl4.Y);
  msd_linear_free(&ML);
  msd_nonlinear_free(&MN1);
  msd_nonlinear_free(&MN4);
  if (g_csv) fclose(g_csv);
  return 0;
}
