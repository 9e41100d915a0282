/* bench_fom.c — full-order model timings: 1000 GL3 steps (dt = 0.1,
   u(t) = 0.1 sin t, x0 = 0, trajectory stored) of
     fom_linear_N100          the paper's linear MSD, N = 100 (dense, step map)
     fom_nonlinear_N1000..8000 the paper's nonlinear MSD (banded, interleaved
                              (l_1, v_1, l_2, v_2, ...) ordering, Newton tol 1e-8,
                              at most 20 iterations, as in the paper)
     fom_nonlinear_sparse_N1000 the same model given as CSC matrices in the
                              paper's [l; v] ordering; each run converts it
                              (phgmg_ph_sparse_create: RCM, band storage, sep_idx
                              remap) and simulates; prints the ratio to
                              fom_nonlinear_N1000 and the largest relative
                              difference of the trajectory (un-permuted)
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
#include "bench_args.h"
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
static double last_median, last_cpu_median; /* of the latest run_case */

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
  last_median = med;
  last_cpu_median = cmed;
  free(x0);
  free(X);
  return 0;
}

/* The nonlinear chain (n masses) as CSC in the paper's [l; v] ordering, the
   nonzeros of the dense model taken column by column. */
typedef struct csc_chain {
  msd_nonlinear D; /* dense, paper ordering: the source and B, poly, idx_l */
  phgmg_csc J, R, Q;
  int *cp, *ri;
  double *v;
} csc_chain;
static void csc_chain_free(csc_chain *c) {
  msd_nonlinear_free(&c->D);
  free(c->cp); free(c->ri); free(c->v);
}
static int csc_chain_build(csc_chain *c, int n) {
  msd_nl_opts o;
  const double *M[3];
  phgmg_csc *A[3];
  int N = 2 * n, a, i, j, nnz = 0;
  memset(c, 0, sizeof *c);
  memset(&o, 0, sizeof o);
  o.n = n;
  if (msd_nonlinear_build(&c->D, &o) != 0) return -1;
  M[0] = c->D.J; M[1] = c->D.R; M[2] = c->D.Q;
  A[0] = &c->J; A[1] = &c->R; A[2] = &c->Q;
  c->cp = (int *)malloc(sizeof(int) * 3 * (size_t)(N + 1));
  c->ri = (int *)malloc(sizeof(int) * 6 * (size_t)N);
  c->v = (double *)malloc(sizeof(double) * 6 * (size_t)N);
  if (!c->cp || !c->ri || !c->v) { csc_chain_free(c); return -1; }
  for (a = 0; a < 3; ++a) {
    int *cp = c->cp + a * (N + 1), base = nnz;
    for (j = 0; j < N; ++j) {
      cp[j] = nnz - base;
      for (i = 0; i < N; ++i)
        if (M[a][i + (size_t)j * N] != 0.0) { c->ri[nnz] = i; c->v[nnz] = M[a][i + (size_t)j * N]; ++nnz; }
    }
    cp[N] = nnz - base;
    A[a]->n_rows = A[a]->n_cols = N;
    A[a]->colptr = cp; A[a]->rowidx = c->ri + base; A[a]->values = c->v + base;
  }
  return 0;
}

/* fom_nonlinear_sparse_N<N>: convert + simulate per run; the trajectory is
   compared (un-permuted, in the paper's ordering) with Xref in the
   interleaved ordering of the hand-banded model (idx_l, idx_v). */
static int run_sparse_case(FILE *csv, const char *name, int n, const phgmg_gl3_opts *opts, int runs,
                           const msd_nonlinear *Mb, double ref_median, double ref_cpu) {
  int N = 2 * n, r, i, j, fail = 0, kb = -1;
  csc_chain c;
  double *x0 = (double *)calloc((size_t)N, sizeof(double)), *xi = (double *)calloc((size_t)N, sizeof(double));
  double *X = (double *)malloc(sizeof(double) * (size_t)N * (NSTEPS + 1));
  double *Xu = (double *)malloc(sizeof(double) * (size_t)N * (NSTEPS + 1));
  double *Xref = (double *)malloc(sizeof(double) * (size_t)N * (NSTEPS + 1));
  double wall[MAXRUNS], cpu[MAXRUNS], med, cmed, dmax = 0.0, smax = 0.0;
  phgmg_gl3_stats st;
  if (!x0 || !xi || !X || !Xu || !Xref || csc_chain_build(&c, n) != 0) {
    free(x0); free(xi); free(X); free(Xu); free(Xref);
    fprintf(stderr, "%s: out of memory\n", name);
    return 1;
  }
  if (phgmg_simulate(&Mb->sys, x0, 0.0, 0.1, NSTEPS, msd_input_sin, NULL, opts, Xref, NULL, NULL, NULL,
                     NULL, NULL) != PHGMG_OK) fail = 1;
  for (r = -1; r < runs && !fail; ++r) { /* r = -1: warm-up */
    double w0 = clock_s(CLOCK_MONOTONIC), c0 = clock_s(CLOCK_PROCESS_CPUTIME_ID);
    phgmg_ph_sparse *sp = NULL;
    phgmg_ph_sparse_info inf;
    phgmg_ph_system sys;
    phgmg_result rc = phgmg_ph_sparse_create(&sp, N, 1, &c.J, &c.R, &c.Q, c.D.B, NULL, &inf, NULL);
    if (rc == PHGMG_OK) {
      sys = *phgmg_ph_sparse_system(sp);
      sys.nl = PHGMG_NL_SEPARABLE;
      sys.poly_deg = 4;
      sys.poly = c.D.poly;
      rc = phgmg_ph_sparse_sep_idx(sp, n, c.D.idx_l, NULL, &sys);
    }
    if (rc == PHGMG_OK) {
      phgmg_ph_sparse_to_banded_order(sp, 1, x0, N, xi, N);
      rc = phgmg_simulate(&sys, xi, 0.0, 0.1, NSTEPS, msd_input_sin, NULL, opts, X, NULL, NULL, &st, NULL, NULL);
    }
    if (rc == PHGMG_OK) phgmg_ph_sparse_to_user_order(sp, NSTEPS + 1, X, N, Xu, N);
    phgmg_ph_sparse_destroy(sp);
    {
      double w1 = clock_s(CLOCK_MONOTONIC), c1 = clock_s(CLOCK_PROCESS_CPUTIME_ID);
      if (rc != PHGMG_OK) { fprintf(stderr, "%s: %s\n", name, phgmg_result_string(rc)); fail = 1; break; }
      if (r >= 0) { wall[r] = w1 - w0; cpu[r] = c1 - c0; }
    }
    kb = inf.kb;
  }
  if (!fail) {
    for (j = 0; j <= NSTEPS; ++j)
      for (i = 0; i < n; ++i) {
        const double *xr = Xref + (size_t)j * N, *xs = Xu + (size_t)j * N;
        dmax = fmax(dmax, fmax(fabs(xs[i] - xr[Mb->idx_l[i]]), fabs(xs[n + i] - xr[Mb->idx_v[i]])));
        smax = fmax(smax, fmax(fabs(xr[Mb->idx_l[i]]), fabs(xr[Mb->idx_v[i]])));
      }
    qsort(wall, (size_t)runs, sizeof(double), cmp_double);
    qsort(cpu, (size_t)runs, sizeof(double), cmp_double);
    med = runs % 2 ? wall[runs / 2] : 0.5 * (wall[runs / 2 - 1] + wall[runs / 2]);
    cmed = runs % 2 ? cpu[runs / 2] : 0.5 * (cpu[runs / 2 - 1] + cpu[runs / 2]);
    printf("%-22s N=%5d  wall median %8.2f ms (min %8.2f, max %8.2f)  cpu median %8.2f ms"
           "  %6.1f ns/(unknown*step)  [%ld Newton it, %ld factorizations]\n",
           name, N, 1e3 * med, 1e3 * wall[0], 1e3 * wall[runs - 1], 1e3 * cmed,
           1e9 * med / ((double)N * NSTEPS), st.newton_iters, st.factorizations);
    printf("%-22s kb after RCM %d; ratio to the hand-banded case: wall %.3f, cpu %.3f;"
           " trajectory max rel. diff %.2e\n", name, kb, ref_median > 0 ? med / ref_median : 0.0,
           ref_cpu > 0 ? cmed / ref_cpu : 0.0, smax > 0 ? dmax / smax : 0.0);
    if (csv) fprintf(csv, "%s,%.6e,%.6e,%.6e,%d\n", name, med, wall[0], wall[runs - 1], runs);
  }
  csc_chain_free(&c);
  free(x0); free(xi); free(X); free(Xu); free(Xref);
  return fail;
}

int main(int argc, char **argv) {
  FILE *csv = NULL;
  int fail = 0, k;
  static const int sizes[4] = {1000, 2000, 4000, 8000};
  {
    const char *out;
    int rc = bench_args(argc, argv, "bench_fom", "Full-order GL3 simulations of the paper's chains (1000 steps).", &out,
                        NULL, NULL);
    if (rc) return rc == 1 ? 0 : 2;
    csv = bench_open_csv("bench_fom", out, &rc);
    if (rc) return 1;
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
    if (sizes[k] == 1000) {
      double ref = last_median, refc = last_cpu_median;
      fail |= run_sparse_case(csv, "fom_nonlinear_sparse_N1000", o.n, &g, 9, &M, ref, refc);
    }
    msd_nonlinear_free(&M);
  }
  if (csv) fclose(csv);
  return fail;
}
