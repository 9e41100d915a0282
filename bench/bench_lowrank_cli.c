/* bench_lowrank_cli.c — the sampled H-infinity error of a reduced model
   written by `phgmg reduce` (DIR/NAME_K.npy, _Qh.npy, _Bh.npy: Ar = K Qh,
   Br = Bh, Cr = Bh^T Qh) against its sparse full model (the COO files J.npy,
   R.npy, Q.npy (nnz, 3) and B.npy (N x m) of bench/lowrank_models.py), on
   --nw (200) log-spaced frequencies in [1e-2, 1e2], through the sparse
   model's shifted solves (phgmg_shifted_hinf: one complex sparse LU per
   frequency on one symbolic analysis). Prints the error, the full model's
   sampled norm and the CPU time of the sampling.

     cc -std=c99 -O2 -march=native bench/bench_lowrank_cli.c -o build/bench_lowrank_cli -lm
     ./build/bench_lowrank_cli --model MODELDIR --rom DIR/NAME [--nw 200] */
#define _POSIX_C_SOURCE 199309L
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "bench_args.h"
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double bc_cpu(void) { return (double)clock() / CLOCKS_PER_SEC; }

/* A (nnz, 3) triplet file into a CSC matrix (N x N, duplicates kept: the
   library sums them). Returns 0 or -1. */
static int bc_coo(const char *path, int N, phgmg_csc *A) {
  double *t = NULL;
  int rows, cols, nd, k, *cp, *ri, *pos;
  double *v;
  if (phgmg_npy_read(path, &t, &rows, &cols, &nd, NULL) != PHGMG_OK || (rows > 0 && cols != 3)) return -1;
  cp = (int *)calloc((size_t)N + 1, sizeof(int));
  pos = (int *)calloc((size_t)N + 1, sizeof(int));
  ri = (int *)malloc(sizeof(int) * (size_t)(rows + 1));
  v = (double *)malloc(sizeof(double) * (size_t)(rows + 1));
  for (k = 0; k < rows; ++k) cp[(int)t[k + (size_t)rows] + 1]++;
  for (k = 0; k < N; ++k) cp[k + 1] += cp[k];
  memcpy(pos, cp, sizeof(int) * (size_t)N);
  for (k = 0; k < rows; ++k) {   /* rows within a column in file order (sorted below) */
    const int c = (int)t[k + (size_t)rows], p = pos[c]++;
    ri[p] = (int)t[k]; v[p] = t[k + 2 * (size_t)rows];
  }
  for (k = 0; k < N; ++k) {   /* insertion sort of each column's rows */
    int a, b;
    for (a = cp[k] + 1; a < cp[k + 1]; ++a)
      for (b = a; b > cp[k] && ri[b - 1] > ri[b]; --b) {
        const int ti = ri[b]; const double tv = v[b];
        ri[b] = ri[b - 1]; v[b] = v[b - 1]; ri[b - 1] = ti; v[b - 1] = tv;
      }
  }
  A->n_rows = A->n_cols = N; A->colptr = cp; A->rowidx = ri; A->values = v;
  free(pos); phgmg_npy_free(t, NULL);
  return 0;
}

int main(int argc, char **argv) {
  static const char *const extra[] = {"--model", "--rom", "--nw", NULL};
  const char *vals[3] = {NULL, NULL, NULL}, *outname;
  char path[4096];
  const char *nm[3] = {"J", "R", "Q"}, *rf[3] = {"K", "Qh", "Bh"};
  double *B = NULL, *F[3], *Ar, *Cr, hinf = 0.0, href = 0.0, c0;
  phgmg_csc M[3];
  phgmg_ph_sparse *sp = NULL;
  phgmg_shifted *sh = NULL;
  int N, m, nd, r, rr, cc, i, j, k, nw;
  phgmg_result rc;
  i = bench_args(argc, argv, "bench_lowrank_cli", "Sampled H-infinity error of a reduced model written by phgmg "
                 "reduce against its sparse model.\n  --model DIR (J.npy, R.npy, Q.npy, B.npy)  --rom DIR/NAME  "
                 "--nw frequencies (200)", &outname, extra, vals);
  if (i) return i == 1 ? 0 : 2;
  if (!vals[0] || !vals[1]) { fprintf(stderr, "bench_lowrank_cli: --model and --rom are required\n"); return 2; }
  nw = vals[2] ? atoi(vals[2]) : 200;
  snprintf(path, sizeof path, "%s/B.npy", vals[0]);
  if (phgmg_npy_read(path, &B, &N, &m, &nd, NULL) != PHGMG_OK) { fprintf(stderr, "cannot read %s\n", path); return 1; }
  for (k = 0; k < 3; ++k) {
    snprintf(path, sizeof path, "%s/%s.npy", vals[0], nm[k]);
    if (bc_coo(path, N, &M[k])) { fprintf(stderr, "cannot read %s\n", path); return 1; }
    snprintf(path, sizeof path, "%s_%s.npy", vals[1], rf[k]);
    if (phgmg_npy_read(path, &F[k], &rr, &cc, &nd, NULL) != PHGMG_OK) { fprintf(stderr, "cannot read %s\n", path); return 1; }
  }
  r = rr;
  Ar = (double *)malloc(sizeof(double) * (size_t)r * (size_t)r);
  Cr = (double *)malloc(sizeof(double) * (size_t)r * (size_t)m);
  phgmg_gemm('N', 'N', r, r, r, 1.0, F[0], r, F[1], r, 0.0, Ar, r);      /* Ar = K Qh */
  phgmg_gemm('T', 'N', m, r, r, 1.0, F[2], r, F[1], r, 0.0, Cr, m);      /* Cr = Bh^T Qh */
  rc = phgmg_ph_sparse_create(&sp, N, m, &M[0], &M[1], &M[2], B, NULL, NULL, NULL);
  if (rc == PHGMG_OK) rc = phgmg_shifted_create(&sh, sp, 0, 0, NULL);
  c0 = bc_cpu();
  if (rc == PHGMG_OK) rc = phgmg_shifted_hinf(sh, r, Ar, F[2], Cr, nw, 1e-2, 1e2, &hinf, &href);
  if (rc != PHGMG_OK) { fprintf(stderr, "bench_lowrank_cli: %s\n", phgmg_result_string(rc)); return 1; }
  printf("N = %d, m = %d, r = %d: sampled H-inf error %.4g (relative %.4g), ||G|| %.4g on %d frequencies "
         "in [1e-2, 1e2]; %.1f s CPU (%d factorizations)\n", N, m, r, hinf, hinf / href, href, nw, bc_cpu() - c0,
         phgmg_shifted_factorizations(sh));
  {
    int err;
    FILE *csv = bench_open_csv("bench_lowrank_cli", outname, &err);
    if (csv) { const double t = bc_cpu() - c0; fprintf(csv, "hinf_sampled_N%d_nw%d,%.6f,%.6f,%.6f,1\n", N, nw, t, t, t); fclose(csv); }
  }
  phgmg_shifted_destroy(sh);
  phgmg_ph_sparse_destroy(sp);
  for (j = 0; j < 3; ++j) {
    free((void *)M[j].colptr); free((void *)M[j].rowidx); free((void *)M[j].values); phgmg_npy_free(F[j], NULL);
  }
  free(Ar); free(Cr); phgmg_npy_free(B, NULL);
  return 0;
}
