/* bench_fom.c — full-order model timings: 1000 GL3 steps (dt = 0.1,
   u(t) = 0.1 sin t, x0 = 0, trajectory stored) of
     fom_linear_N100          the paper's linear MSD, N = 100 (dense, step map)
     fom_nonlinear_N1000..8000 the paper's nonlinear MSD (banded, interleaved
                              (l_1, v_1, l_2, v_2, ...) ordering, Newton tol 1e-8,
                              at most 20 iterations, as in the paper)
   One warm-up run, then >= 5 timed runs each; prints median/min/max wall time,
   the CPU time of the process (robust when the machine is shared) and the time
   per unknown and step. With a file name argument, appends
   `case,median_s,min_s,max_s,runs` lines to it (a header line if the file is new).

     cc -std=c99 -O2 -march=native bench/bench_fom.c -o build/bench_fom -lm
     ./build/bench_fom bench/results.csv                                        */
#define _POSIX_C_SOURCE 199309L
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "../examples/msd_models.h"
#include <stdio.h>
#include <time.h>

static double clock_s(clockid_t id) {
  struct timespec ts;
  clock_gettime(id, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

enum { NSTEPS = 1000, MAXRUNS = 9 };

/* Times phgmg_simulate on sys; returns 0 on success. */
static int run_case(FILE *csv, const char *name, const phgmg_ph_system *sys,
                    const phgmg_gl3_opts *opts, int runs) {
  int N = sys->N, r;
  double *x0 = (double *)calloc((size_t)N, sizeof(double));
  double *X = (double *)malloc(sizeof(double) * (size_t)N * (NSTEPS + 1));
  double wall[MAXRUNS], cpu[MAXRUNS], med, cmed;
  phgmg_gl3_stats st;
  if (!x0 || !X) { free(x0); free(X); fprintf(stderr, "%s: out of memory\n", name); return 1; }
  for (r = -1; r < runs; ++r) { /* r = -1: warm-up */
    double w0 = clock_s(CLOCK_MONOTONIC), c0 = clock_s(CLOCK_PROCESS_CPUTIME_ID);
    phgmg_result rc = phgmg_simulate(sys, x0, 0.0, 0.1, NSTEPS, msd_input_sin, NULL, opts, X,
                                     NULL, NULL, &st, NULL, NULL);
    double w1 = clock_s(CLOCK_MONOTONIC), c1 = clock_s(CLOCK_PROCESS_CPUTIME_ID);
    if (rc != PHGMG_OK) {
      fprintf(stderr, "%s: %s\n", name, phgmg_result_string(rc));
      free(x0); free(X);
      return 1;
    }
    if (r >= 0) { wall[r] = w1 - w0; cpu[r] = c1 - c0; }
  }
  qsort(wall, (size_t)runs, sizeof(double), cmp_double);
  qsort(cpu, (size_t)runs, sizeof(double), cmp_double);
  med = runs % 2 ? wall[runs / 2] : 0.5 * (wall[runs / 2 - 1] + wall[runs / 2]);
  cmed = runs % 2 ? cpu[runs / 2] : 0.5 * (cpu[runs / 2 - 1] + cpu[runs / 2]);
  printf("%-22s N=%5d  wall median %8.2f ms (min %8.2f, max %8.2f)  cpu median %8.2f ms"
         "  %6.1f ns/(unknown*step)  [%ld Newton it, %ld factorizations]\n",
         name, N, 1e3 * med, 1e3 * wall[0], 1e3 * wall[runs - 1], 1e3 * cmed,
         1e9 * med / ((double)N * NSTEPS), st.newton_iters, st.factorizations);
  if (csv) fprintf(csv, "%s,%.6e,%.6e,%.6e,%d\n", name, med, wall[0], wall[runs - 1], runs);
  free(x0);
  free(X);
  return 0;
}

int main(int argc, char **argv) {
  FILE *csv = NULL;
  int fail = 0, k;
  static const int sizes[4] = {1000, 2000, 4000, 8000};
  if (argc > 1) {
    csv = fopen(argv[1], "a");
    if (!csv) { perror(argv[1]); return 1; }
    if (ftell(csv) == 0) fprintf(csv, "case,median_s,min_s,max_s,runs\n");
  }
  { /* linear MSD, N = 100: m_i = 2, k_i = 1, c_i = 1 */
    msd_linear M;
    if (msd_linear_build(&M, 50, NULL, NULL, NULL, PHGMG_DENSE) != 0) return 1;
    fail |= run_case(csv, "fom_linear_N100", &M.sys, NULL, 9);
    msd_linear_free(&M);
  }
  for (k = 0; k < 4; ++k) {
    msd_nonlinear M;
    msd_nl_opts o;
    phgmg_gl3_opts g;
    char name[64];
    memset(&o, 0, sizeof o);
    o.n = sizes[k] / 2;
    o.storage = PHGMG_BANDED;
    memset(&g, 0, sizeof g);
    g.tol = 1e-8;
    g.max_iter = 20;
    if (msd_nonlinear_build(&M, &o) != 0) return 1;
    snprintf(name, sizeof name, "fom_nonlinear_N%d", sizes[k]);
    fail |= run_case(csv, name, &M.sys, &g, sizes[k] <= 2000 ? 9 : 5);
    msd_nonlinear_free(&M);
  }
  if (csv) fclose(csv);
  return fail;
}
