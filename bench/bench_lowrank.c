/* bench_lowrank.c — low-rank balanced truncation (phgmg_lrbt, manual 2.8,
   8.13) of large sparse linear pH models.

   heat:    J = 0, R = the 2-D Dirichlet Laplacian (5-point stencil: 4 on
            the diagonal, -1 to each neighbour) on an n x n grid, Q = I,
            N = n^2, two boundary ports: input 1 on the nodes of the left
            edge, input 2 on the nodes of the bottom edge (weights 1). J = 0:
            one Lyapunov equation (the dual model is the model), real shifts.
   lattice: an n x n mass-spring-damper lattice, x = (q, p) per mass, N =
            2 n^2: K = 2-D Dirichlet Laplacian + 0.01 I, D = 0.5 I + 0.01 K,
            unit masses, forces on the corner masses (0, 0) and (n-1, n-1)
            (collocated ports); two Lyapunov equations, complex shifts.
   DIR:     (--model with any other value) a model from COO files in DIR:
            J.npy, R.npy, Q.npy, optional E.npy (mass matrix; triplets (nnz,
            3) as the command line's --J-coo ...) and B.npy (N x m), e.g.
            bench/fe_mesh.py acoustic DIR N_SIDE (a consistent mass matrix).
   Each run: phgmg_ph_sparse_create (ordering), then phgmg_lrbt to order
   --r (default 20) with the default options (tol 1e-10). Prints the wall and
   CPU time of each, the ADI steps, the factors' columns and ranks, the
   residuals, the numeric factorizations, the first Hankel singular values
   and the bound 2 sum_{i > r} sigma_i / sigma_1; then (--nw, default 20,
   0: skip) the sampled H-infinity error of the reduced model on --nw
   log-spaced frequencies in [1e-2, 1e2] through the sparse model's shifted
   solves (phgmg_shifted_hinf: one complex factorization per frequency),
   relative to the sampled norm of G, against the bound. --lyap eksm runs
   the Lyapunov equations by the extended Krylov method (phgmg_lrkrylov,
   opts.solver = PHGMG_LYAP_EKSM; --maxit its blocks, default 100) instead
   of the low-rank ADI (--lyap adi, the default): "steps" are then blocks.

     cc -std=c99 -O2 -march=native bench/bench_lowrank.c -o build/bench_lowrank -lm
     ./build/bench_lowrank --model heat --n 100 [--r 20] [--nw 20] [--out bench/results.csv]
     ./build/bench_lowrank --model heat --n 317
     ./build/bench_lowrank --model lattice --n 71
     ./build/bench_lowrank --model heat --n 317 --lyap eksm [--maxit 200]
     ./build/bench_lowrank --model /tmp/ac82 --lyap eksm --maxit 2000 */
#define _POSIX_C_SOURCE 199309L
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "bench_args.h"
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

typedef struct bl_csc { int *cp, *ri; double *v; int nz, cap; phgmg_csc A; } bl_csc;

static double bl_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void bl_init(bl_csc *c, int N, int cap) {
  c->cp = (int *)malloc(sizeof(int) * (size_t)(N + 1));
  c->ri = (int *)malloc(sizeof(int) * (size_t)(cap + 1));
  c->v = (double *)malloc(sizeof(double) * (size_t)(cap + 1));
  c->nz = 0; c->cap = cap;
  c->A.n_rows = c->A.n_cols = N; c->A.colptr = c->cp; c->A.rowidx = c->ri; c->A.values = c->v;
}
static void bl_add(bl_csc *c, int i, double v) { c->ri[c->nz] = i; c->v[c->nz++] = v; }
static void bl_free(bl_csc *c) { free(c->cp); free(c->ri); free(c->v); }

/* Column of the 5-point Laplacian (+ shift on the diagonal, times scale) at
   node a of an n x n grid, rows increasing, offset added to the rows. */
static void bl_lap_col(bl_csc *c, int n, int a, double shift, double scale, int offset) {
  const int x = a % n, y = a / n;
  if (y > 0) bl_add(c, offset + a - n, -scale);
  if (x > 0) bl_add(c, offset + a - 1, -scale);
  bl_add(c, offset + a, scale * (4.0 + shift));
  if (x < n - 1) bl_add(c, offset + a + 1, -scale);
  if (y < n - 1) bl_add(c, offset + a + n, -scale);
}

/* A (nnz, 3) triplet file into a CSC matrix (N x N, rows sorted within
   each column; duplicates kept: the library sums them). Returns 0, or -1
   when the file cannot be read (*A untouched). */
static int bl_coo(const char *path, int N, bl_csc *c) {
  double *t = NULL;
  int rows, cols, nd, k, *pos;
  if (phgmg_npy_read(path, &t, &rows, &cols, &nd, NULL) != PHGMG_OK || (rows > 0 && cols != 3)) return -1;
  bl_init(c, N, rows);
  pos = (int *)calloc((size_t)N + 1, sizeof(int));
  for (k = 0; k <= N; ++k) c->cp[k] = 0;
  for (k = 0; k < rows; ++k) c->cp[(int)t[k + (size_t)rows] + 1]++;
  for (k = 0; k < N; ++k) c->cp[k + 1] += c->cp[k];
  for (k = 0; k < N; ++k) pos[k] = c->cp[k];
  for (k = 0; k < rows; ++k) {
    const int col = (int)t[k + (size_t)rows], p = pos[col]++;
    c->ri[p] = (int)t[k]; c->v[p] = t[k + 2 * (size_t)rows];
  }
  for (k = 0; k < N; ++k) { /* insertion sort of each column's rows */
    int a, b;
    for (a = c->cp[k] + 1; a < c->cp[k + 1]; ++a)
      for (b = a; b > c->cp[k] && c->ri[b - 1] > c->ri[b]; --b) {
        const int ti = c->ri[b]; const double tv = c->v[b];
        c->ri[b] = c->ri[b - 1]; c->v[b] = c->v[b - 1]; c->ri[b - 1] = ti; c->v[b - 1] = tv;
      }
  }
  c->nz = rows;
  free(pos); phgmg_npy_free(t, NULL);
  return 0;
}

/* The COO model of directory dir (J, R, Q, E if E.npy exists, B): N, *m;
   *hase 1 with E. Returns N, or -1. */
static int bl_model_dir(const char *dir, bl_csc *J, bl_csc *R, bl_csc *Q, bl_csc *E, int *hase, double **B,
                        int *m) {
  char path[4096];
  int N, nd;
  snprintf(path, sizeof path, "%s/B.npy", dir);
  if (phgmg_npy_read(path, B, &N, m, &nd, NULL) != PHGMG_OK) { fprintf(stderr, "cannot read %s\n", path); return -1; }
  snprintf(path, sizeof path, "%s/J.npy", dir);
  if (bl_coo(path, N, J)) { fprintf(stderr, "cannot read %s\n", path); return -1; }
  snprintf(path, sizeof path, "%s/R.npy", dir);
  if (bl_coo(path, N, R)) { fprintf(stderr, "cannot read %s\n", path); return -1; }
  snprintf(path, sizeof path, "%s/Q.npy", dir);
  if (bl_coo(path, N, Q)) { fprintf(stderr, "cannot read %s\n", path); return -1; }
  snprintf(path, sizeof path, "%s/E.npy", dir);
  *hase = bl_coo(path, N, E) == 0;
  return N;
}

/* opts.progress: each phase with the CPU time so far on stderr (a long run
   shows where it is). */
static void bl_progress(const char *phase, void *user) {
  (void)user;
  fprintf(stderr, "  [%.1f s CPU] %s\n", (double)clock() / CLOCKS_PER_SEC, phase);
}

/* The model's J, R, Q and B (dense N x 2). Returns N. */
static int bl_model(int lattice, int n, bl_csc *J, bl_csc *R, bl_csc *Q, double **B) {
  const int n2 = n * n, N = lattice ? 2 * n2 : n2;
  int a;
  bl_init(J, N, lattice ? N : 0); bl_init(R, N, 5 * n2); bl_init(Q, N, 5 * n2 + n2);
  *B = (double *)calloc((size_t)N * 2, sizeof(double));
  for (a = 0; a < N; ++a) {
    J->cp[a] = J->nz; R->cp[a] = R->nz; Q->cp[a] = Q->nz;
    if (!lattice) {
      bl_lap_col(R, n, a, 0.0, 1.0, 0);
      bl_add(Q, a, 1.0);
      continue;
    }
    if (a < n2) { /* position column: J(p_a, q_a) = -1, Q = K */
      bl_add(J, n2 + a, -1.0);
      bl_lap_col(Q, n, a, 0.01, 1.0, 0);
    } else {      /* momentum column: J(q_a, p_a) = 1, R = D, Q = I */
      const int b = a - n2, x = b % n, y = b / n;
      bl_add(J, b, 1.0);
      if (y > 0) bl_add(R, a - n, -0.01);
      if (x > 0) bl_add(R, a - 1, -0.01);
      bl_add(R, a, 0.5 + 0.01 * 4.01);
      if (x < n - 1) bl_add(R, a + 1, -0.01);
      if (y < n - 1) bl_add(R, a + n, -0.01);
      bl_add(Q, a, 1.0);
    }
  }
  J->cp[N] = J->nz; R->cp[N] = R->nz; Q->cp[N] = Q->nz;
  if (!lattice)
    for (a = 0; a < n; ++a) { (*B)[a * n] = 1.0; (*B)[a + (size_t)N] = 1.0; } /* left edge (x = 0), bottom edge (y = 0) */
  else { (*B)[n2] = 1.0; (*B)[n2 + n2 - 1 + (size_t)N] = 1.0; }
  return N;
}

int main(int argc, char **argv) {
  static const char *const extra[] = {"--model", "--n", "--r", "--nw", "--lyap", "--maxit", NULL};
  const char *vals[6] = {NULL, NULL, NULL, NULL, NULL, NULL}, *outname;
  phgmg_lradi_opts lo;
  const char *steps;
  bl_csc J, R, Q, E;
  double *B, *Ar, *Br, *Cr, *hsv, t0, t1, t2, c0, c1, c2;
  phgmg_ph_sparse *sp = NULL;
  phgmg_ph_sparse_info si;
  phgmg_lrbt_info inf;
  memset(&inf, 0, sizeof inf);
  phgmg_result rc;
  int lattice, n, r, N, i, nw, err = 0, m = 2, hase = 0;
  const char *dir = NULL, *mname;
  FILE *csv;
  i = bench_args(argc, argv, "bench_lowrank", "Low-rank BT of a 2-D heat model or a 2-D mass-spring-damper lattice.\n"
                 "  --model heat|lattice (heat)  --n grid side (100)  --r order (20)\n"
                 "  --nw frequencies of the sampled H-infinity error (20; 0: none)\n"
                 "  --lyap adi|eksm Lyapunov solver (adi)  --maxit ADI steps / EKSM blocks (0: default)",
                 &outname, extra, vals);
  if (i) return i == 1 ? 0 : 2;
  memset(&lo, 0, sizeof lo);
  if (vals[4] && strcmp(vals[4], "adi") && strcmp(vals[4], "eksm")) {
    fprintf(stderr, "bench_lowrank: --lyap adi|eksm\n");
    return 2;
  }
  lo.solver = vals[4] && !strcmp(vals[4], "eksm") ? PHGMG_LYAP_EKSM : PHGMG_LYAP_ADI;
  lo.maxit = vals[5] ? atoi(vals[5]) : 0;
  lo.progress = bl_progress;
  steps = lo.solver == PHGMG_LYAP_EKSM ? "EKSM blocks" : "ADI steps";
  if (lo.maxit < 0) { fprintf(stderr, "bench_lowrank: --maxit >= 0\n"); return 2; }
  lattice = vals[0] && !strcmp(vals[0], "lattice");
  if (vals[0] && !lattice && strcmp(vals[0], "heat")) dir = vals[0];   /* a directory of COO files */
  mname = dir ? dir : lattice ? "lattice" : "heat";
  n = vals[1] ? atoi(vals[1]) : 100;
  r = vals[2] ? atoi(vals[2]) : 20;
  nw = vals[3] ? atoi(vals[3]) : 20;
  if (n < 4 || r < 1 || nw < 0) { fprintf(stderr, "bench_lowrank: --n >= 4, --r >= 1, --nw >= 0\n"); return 2; }
  csv = bench_open_csv("bench_lowrank", outname, &err);
  if (err) return 1;
  if (dir) {
    if ((N = bl_model_dir(dir, &J, &R, &Q, &E, &hase, &B, &m)) < 0) return 1;
  } else {
    N = bl_model(lattice, n, &J, &R, &Q, &B);
  }
  Ar = (double *)malloc(sizeof(double) * (size_t)r * r); Br = (double *)malloc(sizeof(double) * (size_t)r * m);
  Cr = (double *)malloc(sizeof(double) * (size_t)r * m); hsv = (double *)malloc(sizeof(double) * (size_t)r);
  t0 = bl_now(); c0 = (double)clock() / CLOCKS_PER_SEC;
  rc = phgmg_ph_sparse_create_e(&sp, N, m, &J.A, &R.A, &Q.A, hase ? &E.A : NULL, B, NULL, &si, NULL);
  t1 = bl_now(); c1 = (double)clock() / CLOCKS_PER_SEC;
  if (rc == PHGMG_OK) rc = phgmg_lrbt(sp, r, &lo, Ar, Br, Cr, hsv, NULL, NULL, &inf, NULL);
  t2 = bl_now(); c2 = (double)clock() / CLOCKS_PER_SEC;
  if (rc != PHGMG_OK) {
    fprintf(stderr, "bench_lowrank: %s (controllability: %d steps, residual %.2e; observability: %d steps, "
            "residual %.2e; %.2f s CPU)\n", phgmg_result_string(rc), inf.ctrl.iters, inf.ctrl.res, inf.obs.iters,
            inf.obs.res, c2 - c1);
    return 1;
  }
  printf("%s n = %d, N = %d, m = %d%s, r = %d, Lyapunov solver %s\n", mname, n, N, m, hase ? ", mass matrix E" : "",
         r, lo.solver == PHGMG_LYAP_EKSM ? "eksm (steps: blocks)" : "adi");
  printf("  create (ordering)  %.2f s wall, %.2f s CPU\n", t1 - t0, c1 - c0);
  printf("  lrbt               %.2f s wall, %.2f s CPU\n", t2 - t1, c2 - c1);
  printf("  controllability: %d %s, %d columns -> rank %d, residual %.2e, %d factorizations, %d shift sets\n",
         inf.ctrl.iters, steps, inf.ctrl.cols, inf.ctrl.rank, inf.ctrl.res, inf.ctrl.factorizations,
         inf.ctrl.shift_sets);
  printf("  observability:   %d %s, %d columns -> rank %d, residual %.2e, %d factorizations%s\n",
         inf.obs.iters, steps, inf.obs.cols, inf.obs.rank, inf.obs.res, inf.obs.factorizations,
         lattice || dir ? "" : " (J = 0: the same run)");
  if (lo.solver == PHGMG_LYAP_EKSM)
    printf("  EKSM inverse directions: (A + p E)^{-1} E with p = %.4g (controllability), %.4g (observability)\n",
           inf.ctrl.shift, inf.obs.shift);
  printf("  Hankel singular values computed %d; sigma_1 %.6e, sigma_r %.6e, sigma_r+1 %.6e; bound 2 sum_{i>r} / sigma_1 = %.2e\n",
         inf.nhsv, hsv[0], hsv[r - 1], inf.hsv_tail, inf.bound / hsv[0]);
  if (nw > 0) {
    phgmg_shifted *s = NULL;
    double hinf = 0.0, href = 0.0;
    t0 = bl_now(); c0 = (double)clock() / CLOCKS_PER_SEC;
    rc = phgmg_shifted_create(&s, sp, 0, 1, NULL);
    if (rc == PHGMG_OK) rc = phgmg_shifted_hinf(s, r, Ar, Br, Cr, nw, 1e-2, 1e2, &hinf, &href);
    t1 = bl_now(); c1 = (double)clock() / CLOCKS_PER_SEC;
    phgmg_shifted_destroy(s);
    if (rc != PHGMG_OK) { fprintf(stderr, "bench_lowrank: sampled error: %s\n", phgmg_result_string(rc)); return 1; }
    printf("  sampled H-infinity error on %d frequencies in [1e-2, 1e2]: %.3e (relative to the sampled ||G|| %.3e: %.2e), "
           "bound %.3e: %s; %.2f s wall, %.2f s CPU\n", nw, hinf, href, hinf / href, inf.bound,
           hinf <= inf.bound ? "within" : "ABOVE", t1 - t0, c1 - c0);
    printf("  sampling (%d factorizations) %.2f s wall, %.2f s CPU; hinf %.17g, hinf_ref %.17g\n", nw, t1 - t0,
           c1 - c0, hinf, href);
  }
  if (csv) {
    fprintf(csv, "lrbt_%s_N%d_r%d,%.6f,%.6f,%.6f,1\n", dir ? "coo" : lattice ? "lattice" : "heat", N, r, t2 - t1,
            t2 - t1, t2 - t1);
    fclose(csv);
  }
  phgmg_ph_sparse_destroy(sp);
  bl_free(&J); bl_free(&R); bl_free(&Q);
  if (hase) bl_free(&E);
  if (dir) phgmg_npy_free(B, NULL); else free(B);
  free(Ar); free(Br); free(Cr); free(hsv);
  return 0;
}
