/* bench_scale — the offline reduction at large N.

   Case (appended to the CSV of --out as `case,median_s,min_s,max_s,runs`):
     offline_gmgpod_N256000   the paper's nonlinear chain (examples/msd_models.h:
                              quartic springs, banded storage, N = 256 000 =
                              128 000 masses), 1001 snapshots (1000 steps of
                              dt = 0.1, u = 0.1 sin t, from x = 0; simulated once
                              with phgmg_simulate, not timed), the whole
                              phgmg_reduce: GMG-POD, r = 20, deim = 1 with the
                              default hyper-reduction (ECSW, tol 1e-6).
   Timing: wall clock and CPU time of the process (the reduction is
   single-threaded unless built with PHGMG_USE_OPENMP); RUNS runs after no
   warm-up (each run is ~10 s and touches every page anyway); median, min, max
   of the CPU time go to the CSV. The acceptance target is 15 s.

   Usage: bench_scale [out.csv] [N] [runs]
     out.csv "" (empty): no CSV. N (default 256000, even), runs (default 3). With N other than 256000 the
     case is named offline_gmgpod_N<N>. BENCH_SCALE_SNAP=file caches the
     snapshots in a raw file (read if it exists with the right size, else
     written), to skip the full-order run on repeated calls.
     cc -std=c99 -O2 -march=native bench/bench_scale.c -lm */
#define _POSIX_C_SOURCE 199309L
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "../examples/msd_models.h"
#include "bench_args.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define NSTEPS 1000
#define NS (NSTEPS + 1)
#define DT 0.1

static double now_wall(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
static double now_cpu(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : (x > y ? 1 : 0);
}

/* Snapshots from the cache file (1 if read), or 0. */
static int snap_read(const char *path, double *X, size_t cnt) {
  FILE *f = path ? fopen(path, "rb") : NULL;
  size_t got;
  if (!f) return 0;
  got = fread(X, sizeof(double), cnt, f);
  fclose(f);
  return got == cnt;
}
static void snap_write(const char *path, const double *X, size_t cnt) {
  FILE *f = path ? fopen(path, "wb") : NULL;
  if (!f) return;
  if (fwrite(X, sizeof(double), cnt, f) != cnt) fprintf(stderr, "bench_scale: cannot write %s\n", path);
  fclose(f);
}

/* Wall-clock and CPU seconds since the reduction started, per phase
   (opts.progress; BENCH_SCALE_PROGRESS set). */
static double g_t0, g_c0;
static void progress(const char *phase, void *user) {
  (void)user;
  fprintf(stderr, "  wall %7.2f s, CPU %7.2f s: %s\n", now_wall() - g_t0, now_cpu() - g_c0, phase);
}

int main(int argc, char **argv) {
  msd_nonlinear M;
  msd_nl_opts mo;
  phgmg_gl3_opts go;
  phgmg_reduce_opts o;
  phgmg_reduce_info info;
  static const char *const extra[] = {"--n", "--runs", NULL};
  const char *csv, *cache = getenv("BENCH_SCALE_SNAP"), *val[2] = {NULL, NULL};
  const int arc = bench_args(argc, argv, "bench_scale", "The whole phgmg_reduce at large N (default N = 256000, 3 runs).",
                             &csv, extra, val);
  const int N = val[0] ? atoi(val[0]) : 256000;
  int runs = val[1] ? atoi(val[1]) : 3, i;
  double *X, *x0, t[16], w[16], t0, c0;
  char name[64];
  phgmg_result rc;
  if (arc) return arc == 1 ? 0 : 2;
  if (N < 200 || N % 2 || runs < 1) { fprintf(stderr, "usage: bench_scale [--out FILE] [--n N even >= 200] [--runs R]\n"); return 2; }
  if (runs > 16) runs = 16;
  snprintf(name, sizeof name, "offline_gmgpod_N%d", N);
  memset(&mo, 0, sizeof mo);
  mo.n = N / 2;
  mo.storage = PHGMG_BANDED;
  if (msd_nonlinear_build(&M, &mo) != 0) { fprintf(stderr, "bench_scale: model\n"); return 1; }
  X = (double *)malloc(sizeof(double) * (size_t)N * NS);
  x0 = (double *)calloc((size_t)N, sizeof(double));
  if (!X || !x0) { fprintf(stderr, "bench_scale: out of memory\n"); return 1; }
  t0 = now_wall();
  if (!snap_read(cache, X, (size_t)N * NS)) {
    memset(&go, 0, sizeof go);
    go.tol = 1e-8; go.max_iter = 20;
    rc = phgmg_simulate(&M.sys, x0, 0.0, DT, NSTEPS, msd_input_sin, NULL, &go, X, NULL, NULL, NULL, NULL, NULL);
    if (rc != PHGMG_OK) { fprintf(stderr, "bench_scale: simulate: %s\n", phgmg_result_string(rc)); return 1; }
    snap_write(cache, X, (size_t)N * NS);
    printf("%s: snapshots simulated in %.1f s (N = %d, %d steps; not timed)\n", name, now_wall() - t0, N, NSTEPS);
  } else {
    printf("%s: snapshots read from %s\n", name, cache);
  }
  fflush(stdout);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD;
  o.r = 20;
  o.hyper.on = 1; /* hyper = 0: ECSW, hyper_tol 0: 1e-6 */
  if (getenv("BENCH_SCALE_PROGRESS")) o.progress = progress;
  for (i = 0; i < runs; ++i) {
    phgmg_reduced *red = NULL;
    memset(&info, 0, sizeof info);
    g_t0 = w[i] = now_wall();
    g_c0 = c0 = now_cpu();
    rc = phgmg_reduce(&red, &M.sys, X, N, NS, &o, &info, NULL);
    t[i] = now_cpu() - c0;
    w[i] = now_wall() - w[i];
    if (rc != PHGMG_OK) { fprintf(stderr, "bench_scale: phgmg_reduce: %s\n", phgmg_result_string(rc)); return 1; }
    printf("  run %d: wall %.3f s, CPU %.3f s; POD %s (check %.2e), sigma_r/sigma_1 %.2e; %d ECSW points, "
           "training residual %.2e\n", i + 1, w[i], t[i],
           info.pod_randomized == 1 ? "randomized" : info.pod_randomized ? "exact (randomized rejected)" : "exact",
           info.pod_check, info.pod_sigma_ratio, info.deim_modes, info.hyper_residual);
    fflush(stdout);
    phgmg_reduced_destroy(red);
  }
  qsort(t, (size_t)runs, sizeof(double), cmp_double);
  qsort(w, (size_t)runs, sizeof(double), cmp_double);
  printf("%-28s CPU median %.3f s (min %.3f, max %.3f), wall median %.3f s, %d runs; target 15 s\n", name,
         t[runs / 2], t[0], t[runs - 1], w[runs / 2], runs);
  if (csv) {
    int err;
    FILE *f = bench_open_csv("bench_scale", csv, &err);
    if (!f) return 1;
    fprintf(f, "%s,%.9f,%.9f,%.9f,%d\n", name, t[runs / 2], t[0], t[runs - 1], runs);
    fclose(f);
  }
  free(X); free(x0);
  msd_nonlinear_free(&M);
  return 0;
}
