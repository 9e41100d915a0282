/* The distributed offline phase as a PETSc-, hypre- or MFEM-based code would
   call it: everything passes through plain arrays of this rank's rows (what
   VecGetArray, MatGetRow and VecGetOwnershipRange give), no PETSc here.

     mpicc -std=c99 -O2 -o build/mpi_pod examples/mpi_pod.c -lm
     mpirun -np 2 build/mpi_pod [--N 100000] [--ns 40] [--weak] [--batch 10] [--serial]

   The "solver" is a 1-D diffusion chain x' = -A x on N points whose
   snapshots are known in closed form (sine modes with decaying amplitudes),
   so every rank produces its own rows without communication, as a
   distributed time stepper would. The program then
     1. describes the row distribution (phgmg_mpi_ctx_create),
     2. takes the POD of the snapshots by TSQR (phgmg_mpi_pod), and once more
        streamed in column batches as a time stepper would deliver them
        (phgmg_mpi_pod_stream_*: the N x ns matrix is never stored),
     3. picks DEIM points (phgmg_mpi_deim_greedy: global indices, the same
        for any number of ranks),
     4. hands A's rows over as CSR with global column indices
        (phgmg_mpi_op_create, from a MatGetRow-like callback) and projects
        it, Ar = V^T A V, replicated on every rank,
   and prints the wall-clock times of each step and the CPU time of the
   busiest rank in the two PODs (the work per rank, which is what scales
   when other processes share the cores). --weak: N rows per rank (weak
   scaling) instead of N in total (strong scaling). --serial (one rank):
   also the time of the serial phgmg_pod on the same snapshots. */
#define PHGMG_MPI
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* A MatGetRow-like callback: the nonzeros of global row i of the N x N
   matrix A = tridiag(-1, 2, -1) (N + 1)^2 (the discrete -d^2/ds^2). */
static int get_row(long long N, long long i, long long *col, double *val) {
  const double h2 = (double)(N + 1) * (double)(N + 1);
  int n = 0;
  if (i > 0) { col[n] = i - 1; val[n++] = -h2; }
  col[n] = i; val[n++] = 2.0 * h2;
  if (i + 1 < N) { col[n] = i + 1; val[n++] = -h2; }
  return n;
}

/* The solver's snapshot j on this rank's rows: x(s, t_j) = sum_k exp(-(k pi)^2 t_j) sin(k pi s) / k. */
static void snapshot(long long N, long long row0, int nloc, int j, double *x) {
  const double pi = 3.14159265358979323846, t = 1e-3 * j;
  int i, k;
  for (i = 0; i < nloc; ++i) {
    const double s = (double)(row0 + i + 1) / (double)(N + 1);
    double v = 0.0;
    for (k = 1; k <= 12; ++k) v += exp(-(k * pi) * (k * pi) * t) * sin(k * pi * s) / k;
    x[i] = v;
  }
}

int main(int argc, char **argv) {
  long long N = 100000, row0, *rp, *col;
  int ns = 40, batch = 10, weak = 0, serial = 0, rank, size, nloc, i, j, k = 0, kst = 0, kmax = 12, ld;
  double *X, *V, *Vs, *val, S[64], Ss[64], Ar[144], disc = 0.0, t[8], cpu[2], cpumax[2];
  clock_t c0;
  phgmg_mpi_ctx *ctx = NULL;
  phgmg_mpi_pod_stream *st = NULL;
  phgmg_mpi_op *A = NULL;
  phgmg_gidx pts[12];
  phgmg_result rc;
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  for (i = 1; i < argc; ++i) {
    if (!strcmp(argv[i], "--N") && i + 1 < argc) N = atoll(argv[++i]);
    else if (!strcmp(argv[i], "--ns") && i + 1 < argc) ns = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--batch") && i + 1 < argc) batch = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--weak")) weak = 1;
    else if (!strcmp(argv[i], "--serial")) serial = 1;
  }
  if (ns < kmax || ns > 64 || batch < 1 || N < 2 * kmax) {
    if (rank == 0) fprintf(stderr, "mpi_pod: need 12 <= --ns <= 64, --batch >= 1, --N >= 24\n");
    MPI_Finalize();
    return 2;
  }
  if (weak) N *= size;
  /* 1. the row distribution: an even split, as PETSC_DECIDE makes it */
  row0 = N * rank / size;
  nloc = (int)(N * (rank + 1) / size - row0);
  rc = phgmg_mpi_ctx_create(&ctx, MPI_COMM_WORLD, N, row0, nloc, NULL);
  if (rc != PHGMG_OK) {
    if (rank == 0) fprintf(stderr, "mpi_pod: %s\n", phgmg_result_string(rc));
    MPI_Finalize();
    return 1;
  }
  ld = nloc > 0 ? nloc : 1;
  X = (double *)malloc(sizeof(double) * (size_t)ld * ns);
  V = (double *)malloc(sizeof(double) * (size_t)ld * kmax);
  Vs = (double *)malloc(sizeof(double) * (size_t)ld * kmax);
  for (j = 0; j < ns; ++j) snapshot(N, row0, nloc, j, X + (size_t)j * ld);
  /* 2. POD by TSQR, then streamed in batches */
  MPI_Barrier(MPI_COMM_WORLD); t[0] = MPI_Wtime(); c0 = clock();
  rc = phgmg_mpi_pod(ctx, ns, X, ld, kmax, 0.0, V, ld, S, &k);
  cpu[0] = (double)(clock() - c0) / CLOCKS_PER_SEC;
  MPI_Barrier(MPI_COMM_WORLD); t[1] = MPI_Wtime(); c0 = clock();
  if (rc == PHGMG_OK) rc = phgmg_mpi_pod_stream_begin(&st, ctx, kmax, 0.0);
  for (j = 0; j < ns && rc == PHGMG_OK; j += batch)
    rc = phgmg_mpi_pod_stream_add(st, ns - j < batch ? ns - j : batch, X + (size_t)j * ld, ld);
  if (rc == PHGMG_OK) rc = phgmg_mpi_pod_stream_end(st, Vs, ld, Ss, &kst, &disc);
  cpu[1] = (double)(clock() - c0) / CLOCKS_PER_SEC;
  MPI_Barrier(MPI_COMM_WORLD); t[2] = MPI_Wtime();
  MPI_Reduce(cpu, cpumax, 2, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  /* 3. DEIM points of the basis */
  if (rc == PHGMG_OK) rc = phgmg_mpi_deim_greedy(ctx, k, V, ld, NULL, pts, NULL);
  MPI_Barrier(MPI_COMM_WORLD); t[3] = MPI_Wtime();
  /* 4. A's rows as CSR with global columns, its halo plan, Ar = V^T A V */
  rp = (long long *)malloc(sizeof(long long) * ((size_t)nloc + 1));
  col = (long long *)malloc(sizeof(long long) * (3 * (size_t)nloc + 1));
  val = (double *)malloc(sizeof(double) * (3 * (size_t)nloc + 1));
  rp[0] = 0;
  for (i = 0; i < nloc; ++i) rp[i + 1] = rp[i] + get_row(N, row0 + i, col + rp[i], val + rp[i]);
  if (rc == PHGMG_OK) rc = phgmg_mpi_op_create(&A, ctx, rp, col, val);
  if (rc == PHGMG_OK) rc = phgmg_mpi_op_project(A, k, V, ld, Ar, k);
  MPI_Barrier(MPI_COMM_WORLD); t[4] = MPI_Wtime();
  if (serial && size == 1 && rc == PHGMG_OK) {   /* the serial POD of the same snapshots, for comparison */
    int ks = 0;
    rc = phgmg_pod(nloc, ns, X, ld, kmax, 0.0, Vs, ld, Ss, &ks, NULL);
  }
  t[5] = MPI_Wtime();
  if (rank == 0) {
    if (rc != PHGMG_OK) fprintf(stderr, "mpi_pod: %s\n", phgmg_result_string(rc));
    else {
      printf("N = %lld on %d ranks (%s), %d snapshots, %d modes\n", N, size, weak ? "weak" : "strong", ns, k);
      printf("sigma_1 = %.6e, sigma_%d / sigma_1 = %.3e; streamed (batches of %d): %.6e, %.3e, bound %.1e\n",
             S[0], k, S[k - 1] / S[0], batch, Ss[0], Ss[kst - 1] / Ss[0], disc);
      printf("DEIM points:");
      for (i = 0; i < k; ++i) printf(" %lld", pts[i]);
      printf("\nV^T A V: diagonal %.6e %.6e %.6e ...\n", Ar[0], Ar[1 + k], Ar[2 + 2 * k]);
      printf("time [s]: POD (TSQR) %.3f, streamed POD %.3f, DEIM %.3f, operator plan + V^T A V %.3f\n",
             t[1] - t[0], t[2] - t[1], t[3] - t[2], t[4] - t[3]);
      printf("CPU time of the busiest rank [s]: POD (TSQR) %.3f, streamed POD %.3f\n", cpumax[0], cpumax[1]);
      if (serial && size == 1) printf("time [s]: serial phgmg_pod %.3f\n", t[5] - t[4]);
    }
  }
  phgmg_mpi_op_destroy(A);
  phgmg_mpi_pod_stream_destroy(st);
  phgmg_mpi_ctx_destroy(ctx);
  free(X); free(V); free(Vs); free(rp); free(col); free(val);
  MPI_Finalize();
  return rc == PHGMG_OK ? 0 : 1;
}
