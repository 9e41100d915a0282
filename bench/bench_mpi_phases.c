/* bench_mpi_phases — the distributed offline phases (manual 2.7), one at a
   time, on a model of given size per rank (weak scaling), with their
   communication: the input of the scaling model bench/mpi_scaling.py.

   Model: a linear port-Hamiltonian model x' = (J - R) Q x + B u distributed
   by rows. Q: the lattice's Laplacian plus the identity (SPD), on a chain
   (--lattice chain: rows i-1, i, i+1) or a 2-D lattice (--lattice 2d:
   nx x nx squares per rank, stacked: every rank owns a square block of
   nx = sqrt(nloc) columns and nx rows of the lattice, its neighbours the
   ranks above and below; halo 2 nx values per column). J - R: the chain's
   skew coupling 0.4 minus R = I, solved by the user's callback: the
   right-hand sides gathered and solved by the serial sparse LU of the
   library (phgmg_shifted_solve at p = 0 on a replicated copy; its time is
   reported apart as the user's solves, and its collectives are not the
   library's). Snapshots X (nloc x ns): 2 ns smooth global modes
   sin(pi (l + 1) (g + 1/2) / N) with coefficients 2^-l (pseudo-random,
   the same at every P), plus 1e-9 noise. B: one smooth column.

   Phases, in this order: tsqr (phgmg_mpi_tsqr of X, Q formed), cholqr,
   pod (kmax = r), pod_stream (blocks of nb, kmax = 2 r), deim (k = r on the
   POD basis), ecsw (terms = rows: F = tanh of the scaled snapshots, Vt =
   the POD basis' rows, tol 1e-2), op_create (the halo plan of Q), op_apply
   (Q V, r columns), op_project (V^T Q V), gmg_pod_linear (r, m = 1).

   Per phase, as JSON on stdout (rank 0): wall time (max over the ranks),
   CPU time user+sys (max over the ranks; the machine may be oversubscribed:
   then wall > CPU; with K reps the smallest of each), the wall and CPU
   time in the user's solves (solve, solve_cpu), the CPU time outside MPI
   calls and the user's solves (compute_cpu: the local work; OpenMPI
   busy-waits inside its calls, so the CPU time alone counts waiting at P >
   1), the wall time inside the library's MPI calls (mpi_wall), the library's counts
   (phgmg_mpi_counts: collectives, bytes, halo exchanges and bytes, max over
   the ranks), the MPI calls by kind as seen through the MPI profiling
   interface (count and bytes sent by this rank: allreduce, reduce, bcast,
   allgather, alltoall(v), isend; the user's solves not included), and the
   peak RSS (max over the ranks, MB) after the phase. The replicated solver
   is built after the library-only phases, so "rss_lib_mb" is the peak of
   the library's phases alone.

   Usage: mpirun -np P bench_mpi_phases [--nloc N] [--lattice chain|2d] [--ns S] [--r R] [--nb B] [--reps K]
     defaults: nloc 20000, 2d, ns 40, r 10, nb 8, reps 1 (K > 1: every
     phase run K times, the fastest wall time kept).
     make build/bench_mpi_phases (mpicc -std=c99 -O2). */
#define _POSIX_C_SOURCE 200112L
#define PHGMG_MPI
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>

/* ---- MPI calls by kind through the profiling interface ------------------- */
enum { K_ALLREDUCE, K_REDUCE, K_BCAST, K_ALLGATHER, K_ALLTOALL, K_ALLTOALLV, K_ISEND, NKIND };
static const char *kind_name[NKIND] = {"allreduce", "reduce", "bcast", "allgather", "alltoall", "alltoallv", "isend"};
static long long kcount[NKIND], kbytes[NKIND];
static int in_user_solve;
static double mpi_wall, mpi_cpu;   /* time inside the library's MPI calls (waiting included) */
static double cpu_now(void);
static void tally(int kind, int count, MPI_Datatype t) {
  int sz = 0;
  if (in_user_solve || kind < 0) return;
  PMPI_Type_size(t, &sz);
  kcount[kind]++;
  kbytes[kind] += (long long)count * sz;
}
/* Every wrapped call: counted (kind >= 0) and timed, outside the user's solves. */
#define WRAP(kind, count, type, call)                                   \
  do {                                                                  \
    double w0_ = 0.0, c0_ = 0.0;                                        \
    int rc_;                                                            \
    tally(kind, count, type);                                           \
    if (!in_user_solve) { w0_ = PMPI_Wtime(); c0_ = cpu_now(); }        \
    rc_ = call;                                                         \
    if (!in_user_solve) { mpi_wall += PMPI_Wtime() - w0_; mpi_cpu += cpu_now() - c0_; } \
    return rc_;                                                         \
  } while (0)
int MPI_Allreduce(const void *sb, void *rb, int n, MPI_Datatype t, MPI_Op op, MPI_Comm c) {
  WRAP(K_ALLREDUCE, n, t, PMPI_Allreduce(sb, rb, n, t, op, c));
}
int MPI_Reduce(const void *sb, void *rb, int n, MPI_Datatype t, MPI_Op op, int root, MPI_Comm c) {
  WRAP(K_REDUCE, n, t, PMPI_Reduce(sb, rb, n, t, op, root, c));
}
int MPI_Bcast(void *b, int n, MPI_Datatype t, int root, MPI_Comm c) {
  WRAP(K_BCAST, n, t, PMPI_Bcast(b, n, t, root, c));
}
int MPI_Allgather(const void *sb, int sn, MPI_Datatype st, void *rb, int rn, MPI_Datatype rt, MPI_Comm c) {
  WRAP(K_ALLGATHER, sn, st, PMPI_Allgather(sb, sn, st, rb, rn, rt, c));
}
int MPI_Alltoall(const void *sb, int sn, MPI_Datatype st, void *rb, int rn, MPI_Datatype rt, MPI_Comm c) {
  int P = 1;
  PMPI_Comm_size(c, &P);
  WRAP(K_ALLTOALL, sn * P, st, PMPI_Alltoall(sb, sn, st, rb, rn, rt, c));
}
int MPI_Alltoallv(const void *sb, const int *sn, const int *sd, MPI_Datatype st, void *rb, const int *rn,
                  const int *rd, MPI_Datatype rt, MPI_Comm c) {
  int P = 1, q, tot = 0;
  PMPI_Comm_size(c, &P);
  for (q = 0; q < P; ++q) tot += sn[q];
  WRAP(K_ALLTOALLV, tot, st, PMPI_Alltoallv(sb, sn, sd, st, rb, rn, rd, rt, c));
}
int MPI_Isend(const void *b, int n, MPI_Datatype t, int dest, int tag, MPI_Comm c, MPI_Request *req) {
  WRAP(K_ISEND, n, t, PMPI_Isend(b, n, t, dest, tag, c, req));
}
int MPI_Waitall(int n, MPI_Request *req, MPI_Status *st) { WRAP(-1, 0, MPI_INT, PMPI_Waitall(n, req, st)); }

/* ---- the setup -------------------------------------------------------------------- */
static int rank_, size_;
static double cpu_now(void) {
  struct rusage u;
  getrusage(RUSAGE_SELF, &u);
  return (double)u.ru_utime.tv_sec + 1e-6 * (double)u.ru_utime.tv_usec + (double)u.ru_stime.tv_sec +
         1e-6 * (double)u.ru_stime.tv_usec;
}
static double rss_mb(void) {
  struct rusage u;
  getrusage(RUSAGE_SELF, &u);
  return (double)u.ru_maxrss / 1024.0;   /* Linux: kB */
}
static double gmax(double v) {
  double o = v;
  PMPI_Allreduce(&v, &o, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return o;
}
static void fail(const char *what, phgmg_result rc) {
  if (rank_ == 0) fprintf(stderr, "bench_mpi_phases: %s failed: %s\n", what, phgmg_result_string(rc));
  MPI_Abort(MPI_COMM_WORLD, 1);
}

typedef struct bench {
  int nloc, ns, r, nb, m, reps, lattice2d, nx;
  long long N, row0;
  phgmg_mpi_ctx *ctx;
  double *X, *B, *V, *W;   /* nloc x ns, nloc x m, nloc x 2r, nloc x ns scratch */
  phgmg_mpi_op *Q;
  /* the user's solve */
  phgmg_ph_sparse *sp;
  phgmg_shifted *sh;
  double *full, *full2, solve_time, solve_cpu;
  int *cnt, *dsp;
} bench;

/* A pseudo-random number in [-0.5, 0.5) from two integers (the same at every P). */
static double hash01(long long a, long long b) {
  unsigned long long x = (unsigned long long)a * 0x9E3779B97F4A7C15ull ^ ((unsigned long long)b + 0x632BE59BD9B4E019ull);
  x ^= x >> 31; x *= 0xBF58476D1CE4E5B9ull; x ^= x >> 27; x *= 0x94D049BB133111EBull; x ^= x >> 31;
  return (double)(x >> 11) * (1.0 / 9007199254740992.0) - 0.5;
}

static void make_snapshots(bench *b) {
  const int L = 2 * b->ns, n = b->nloc;
  double *F = (double *)malloc(sizeof(double) * (size_t)n * L), *C = (double *)malloc(sizeof(double) * (size_t)L * b->ns);
  int i, j, l;
  for (l = 0; l < L; ++l) {
    for (i = 0; i < n; ++i) F[i + (size_t)l * n] = sin(3.141592653589793 * (l + 1) * ((double)(b->row0 + i) + 0.5) / (double)b->N);
    for (j = 0; j < b->ns; ++j) C[l + (size_t)j * L] = ldexp(hash01(l, j), -l);
  }
  phgmg_gemm('N', 'N', n, b->ns, L, 1.0, F, n, C, L, 0.0, b->X, n);
  for (j = 0; j < b->ns; ++j)
    for (i = 0; i < n; ++i) b->X[i + (size_t)j * n] += 1e-9 * hash01(b->row0 + i, j + 1000);
  for (i = 0; i < n; ++i) b->B[i] = 1.0 + exp(-pow(((double)(b->row0 + i) - 0.3 * (double)b->N) / (0.05 * (double)b->N), 2));
  free(F); free(C);
}

/* Q's rows: the lattice Laplacian + I (chain: 3 -1; 2-D: 5 -1, Dirichlet). */
static void make_operator(bench *b) {
  const int n = b->nloc;
  long long *rp = (long long *)malloc(sizeof(long long) * ((size_t)n + 1)), *col = (long long *)malloc(sizeof(long long) * 5 * (size_t)n);
  double *val = (double *)malloc(sizeof(double) * 5 * (size_t)n);
  long long nz = 0;
  int i;
  phgmg_result rc;
  rp[0] = 0;
  for (i = 0; i < n; ++i) {
    const long long g = b->row0 + i;
    if (b->lattice2d) {
      const long long x = g % b->nx, y = g / b->nx, ny = b->N / b->nx;
      col[nz] = g; val[nz++] = 5.0;
      if (x > 0) { col[nz] = g - 1; val[nz++] = -1.0; }
      if (x + 1 < b->nx) { col[nz] = g + 1; val[nz++] = -1.0; }
      if (y > 0) { col[nz] = g - b->nx; val[nz++] = -1.0; }
      if (y + 1 < ny) { col[nz] = g + b->nx; val[nz++] = -1.0; }
    } else {
      col[nz] = g; val[nz++] = 3.0;
      if (g > 0) { col[nz] = g - 1; val[nz++] = -1.0; }
      if (g + 1 < b->N) { col[nz] = g + 1; val[nz++] = -1.0; }
    }
    rp[i + 1] = nz;
  }
  rc = phgmg_mpi_op_create(&b->Q, b->ctx, rp, col, val);
  if (rc != PHGMG_OK) fail("phgmg_mpi_op_create", rc);
  free(rp); free(col); free(val);
}

/* The user's side: J - R (chain: J(g, g+1) = 0.4 = -J(g+1, g), R = I) as a
   replicated sparse model with Q = I, solved at p = 0. */
static void make_solver(bench *b) {
  const int N = (int)b->N;
  int *ri = (int *)calloc(2 * (size_t)N, sizeof(int)), *ci = (int *)calloc(2 * (size_t)N, sizeof(int)), i, q, nz = 0;
  double *v = (double *)calloc(2 * (size_t)N, sizeof(double)), *Bf = (double *)malloc(sizeof(double) * (size_t)N);
  phgmg_csc J, R, I;
  phgmg_result rc;
  for (i = 0; i + 1 < N; ++i) {
    ri[nz] = i; ci[nz] = i + 1; v[nz++] = 0.4;
    ri[nz] = i + 1; ci[nz] = i; v[nz++] = -0.4;
  }
  rc = phgmg_csc_from_coo(&J, N, N, nz, ri, ci, v, NULL);
  for (i = 0; i < N; ++i) { ri[i] = i; ci[i] = i; v[i] = 1.0; Bf[i] = 1.0; }
  if (rc == PHGMG_OK) rc = phgmg_csc_from_coo(&R, N, N, N, ri, ci, v, NULL);
  if (rc == PHGMG_OK) rc = phgmg_csc_from_coo(&I, N, N, N, ri, ci, v, NULL);
  if (rc == PHGMG_OK) rc = phgmg_ph_sparse_create(&b->sp, N, 1, &J, &R, &I, Bf, NULL, NULL, NULL);
  if (rc == PHGMG_OK) rc = phgmg_shifted_create(&b->sh, b->sp, 0, 1, NULL);
  if (rc != PHGMG_OK) fail("the user's solver", rc);
  phgmg_csc_free(&J, NULL); phgmg_csc_free(&R, NULL); phgmg_csc_free(&I, NULL);
  free(ri); free(ci); free(v); free(Bf);
  b->full = (double *)malloc(sizeof(double) * (size_t)N * b->r);
  b->full2 = (double *)malloc(sizeof(double) * (size_t)N * b->r);
  b->cnt = (int *)malloc(sizeof(int) * (size_t)size_); b->dsp = (int *)malloc(sizeof(int) * (size_t)size_);
  for (q = 0; q < size_; ++q) { b->cnt[q] = (int)(b->ctx->starts[q + 1] - b->ctx->starts[q]); b->dsp[q] = (int)b->ctx->starts[q]; }
}

static phgmg_result solve_cb(char trans, int nrhs, double *X, int ldx, void *user) {
  bench *b = (bench *)user;
  const int N = (int)b->N;
  const double t0 = MPI_Wtime(), c0 = cpu_now();
  phgmg_result rc = PHGMG_OK;
  int j;
  if (trans != 'N' || nrhs > b->r) return PHGMG_ERR_UNSUPPORTED;
  in_user_solve = 1;
  for (j = 0; j < nrhs; ++j)
    MPI_Allgatherv(X + (size_t)j * ldx, b->nloc, MPI_DOUBLE, b->full + (size_t)j * N, b->cnt, b->dsp, MPI_DOUBLE, MPI_COMM_WORLD);
  rc = phgmg_ph_sparse_to_banded_order(b->sp, nrhs, b->full, N, b->full2, N);
  if (rc == PHGMG_OK) rc = phgmg_shifted_solve(b->sh, 0.0, 0.0, nrhs, b->full2, N, b->full2, N);
  if (rc == PHGMG_OK) rc = phgmg_ph_sparse_to_user_order(b->sp, nrhs, b->full2, N, b->full, N);
  for (j = 0; j < nrhs && rc == PHGMG_OK; ++j)
    memcpy(X + (size_t)j * ldx, b->full + b->row0 + (size_t)j * N, sizeof(double) * (size_t)b->nloc);
  in_user_solve = 0;
  b->solve_time += MPI_Wtime() - t0;
  b->solve_cpu += cpu_now() - c0;
  return rc;
}

/* ---- the phases ------------------------------------------------------------------------ */
static phgmg_result run_phase(bench *b, int ph) {
  const int n = b->nloc, r = b->r, ns = b->ns;
  double *Rm = (double *)malloc(sizeof(double) * (size_t)ns * ns), S[512], *tmp = NULL;
  phgmg_result rc = PHGMG_OK;
  int k = 0, i, j0;
  switch (ph) {
  case 0: rc = phgmg_mpi_tsqr(b->ctx, ns, b->X, n, b->W, n, Rm, ns); break;
  case 1: rc = phgmg_mpi_cholqr(b->ctx, ns, b->X, n, b->W, n, Rm, ns); break;
  case 2: rc = phgmg_mpi_pod(b->ctx, ns, b->X, n, r, 0.0, b->V, n, S, &k); break;
  case 3: {
    phgmg_mpi_pod_stream *st = NULL;
    double disc;
    rc = phgmg_mpi_pod_stream_begin(&st, b->ctx, 2 * r, 0.0);
    for (j0 = 0; j0 < ns && rc == PHGMG_OK; j0 += b->nb)
      rc = phgmg_mpi_pod_stream_add(st, ns - j0 < b->nb ? ns - j0 : b->nb, b->X + (size_t)j0 * n, n);
    if (rc == PHGMG_OK) rc = phgmg_mpi_pod_stream_end(st, b->W, n, S, &k, &disc);
    phgmg_mpi_pod_stream_destroy(st);
    break;
  }
  case 4: {
    phgmg_gidx pts[512];
    rc = phgmg_mpi_deim_greedy(b->ctx, r, b->V, n, NULL, pts, S);
    break;
  }
  case 5: {
    phgmg_gidx *gid = (phgmg_gidx *)malloc(sizeof(phgmg_gidx) * (size_t)n), *pts = (phgmg_gidx *)malloc(sizeof(phgmg_gidx) * (size_t)ns * r);
    double *w = (double *)malloc(sizeof(double) * (size_t)ns * r), res;
    int nd = 0;
    for (i = 0; i < n; ++i) gid[i] = b->row0 + i;
    for (i = 0; i < n * ns; ++i) b->W[i] = tanh(2.0 * b->X[i]);
    rc = phgmg_mpi_ecsw(b->ctx, n, ns, b->W, n, r, b->V, n, NULL, gid, 1e-2, ns * r, pts, w, &nd, &res);
    free(gid); free(pts); free(w);
    break;
  }
  case 6: phgmg_mpi_op_destroy(b->Q); b->Q = NULL; make_operator(b); break;
  case 7: rc = phgmg_mpi_op_apply(b->Q, r, b->V, n, b->W, n); break;
  case 8: rc = phgmg_mpi_op_project(b->Q, r, b->V, n, Rm, r); break;
  case 9: {
    phgmg_mpi_linear_model md;
    double *K = (double *)malloc(sizeof(double) * (size_t)r * r * 3), *Qh = K + (size_t)r * r, *Bh = Qh + (size_t)r * r;
    memset(&md, 0, sizeof md);
    md.Q = b->Q; md.m = b->m; md.B = b->B; md.ldb = n; md.solve = solve_cb; md.solve_user = b;
    rc = phgmg_mpi_gmg_pod_linear(b->ctx, &md, ns, b->X, n, r, K, Qh, Bh, S, b->W, n);
    free(K);
    break;
  }
  default: break;
  }
  free(Rm); free(tmp);
  return rc;
}

static const char *phase_name[] = {"tsqr", "cholqr", "pod", "pod_stream", "deim", "ecsw", "op_create",
                                   "op_apply", "op_project", "gmg_pod_linear"};
#define NPHASE 10

/* One phase timed (the fastest of reps), counted, printed as a JSON object. */
static void measure(bench *b, int ph, int last) {
  phgmg_mpi_counts cn;
  double wall = 1e300, cpu = 0.0, solve = 0.0, solve_cpu = 0.0, comp = 0.0, mwall = 0.0, v[8];
  long long kc[NKIND], kb[NKIND];
  int rep, q;
  for (rep = 0; rep < b->reps; ++rep) {
    double t0, c0, t1, lc;
    phgmg_result rc;
    MPI_Barrier(MPI_COMM_WORLD);
    phgmg_mpi_counts_reset(b->ctx);
    memset(kcount, 0, sizeof kcount); memset(kbytes, 0, sizeof kbytes);
    b->solve_time = 0.0; b->solve_cpu = 0.0; mpi_wall = 0.0; mpi_cpu = 0.0;
    c0 = cpu_now(); t0 = MPI_Wtime();
    rc = run_phase(b, ph);
    t1 = MPI_Wtime() - t0;
    if (rc != PHGMG_OK) fail(phase_name[ph], rc);
    phgmg_mpi_counts_get(b->ctx, &cn);
    memcpy(kc, kcount, sizeof kc); memcpy(kb, kbytes, sizeof kb);
    c0 = cpu_now() - c0;
    lc = c0 - b->solve_cpu - mpi_cpu;   /* this rank's CPU time outside MPI and the user's solves */
    c0 = gmax(c0); lc = gmax(lc); t1 = gmax(t1);
    if (t1 < wall) { wall = t1; solve = gmax(b->solve_time); mwall = gmax(mpi_wall); }
    if (rep == 0 || c0 < cpu) { cpu = c0; solve_cpu = gmax(b->solve_cpu); } else gmax(0.0);
    if (rep == 0 || lc < comp) comp = lc;
  }
  v[0] = gmax((double)cn.collectives); v[1] = gmax((double)cn.bytes); v[2] = gmax((double)cn.exchanges);
  v[3] = gmax((double)cn.exchange_bytes); v[4] = gmax(rss_mb());
  for (q = 0; q < NKIND; ++q) { kc[q] = (long long)gmax((double)kc[q]); kb[q] = (long long)gmax((double)kb[q]); }
  if (rank_ != 0) return;
  printf("    {\"name\": \"%s\", \"wall\": %.6e, \"cpu\": %.6e, \"solve\": %.6e, \"solve_cpu\": %.6e, \"compute_cpu\": %.6e, \"mpi_wall\": %.6e,\n      \"collectives\": %.0f, \"bytes\": %.0f, "
         "\"exchanges\": %.0f, \"exchange_bytes\": %.0f, \"rss_mb\": %.1f,\n      \"calls\": {",
         phase_name[ph], wall, cpu, solve, solve_cpu, comp, mwall, v[0], v[1], v[2], v[3], v[4]);
  for (q = 0; q < NKIND; ++q) printf("%s\"%s\": [%lld, %lld]", q ? ", " : "", kind_name[q], kc[q], kb[q]);
  printf("}}%s\n", last ? "" : ",");
}

static int arg_int(int argc, char **argv, const char *name, int def) {
  int i;
  for (i = 1; i + 1 < argc; ++i)
    if (!strcmp(argv[i], name)) return atoi(argv[i + 1]);
  return def;
}

int main(int argc, char **argv) {
  bench b;
  int ph, i;
  double rss_lib;
  phgmg_result rc;
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  memset(&b, 0, sizeof b);
  b.nloc = arg_int(argc, argv, "--nloc", 20000);
  b.ns = arg_int(argc, argv, "--ns", 40);
  b.r = arg_int(argc, argv, "--r", 10);
  b.nb = arg_int(argc, argv, "--nb", 8);
  b.reps = arg_int(argc, argv, "--reps", 1);
  b.m = 1;
  b.lattice2d = 1;
  for (i = 1; i + 1 < argc; ++i)
    if (!strcmp(argv[i], "--lattice")) b.lattice2d = strcmp(argv[i + 1], "chain") != 0;
  for (i = 1; i < argc; ++i)
    if (!strcmp(argv[i], "--help")) {
      if (rank_ == 0) printf("usage: mpirun -np P bench_mpi_phases [--nloc N] [--lattice chain|2d] [--ns S] [--r R] [--nb B] [--reps K]\n");
      MPI_Finalize();
      return 0;
    }
  if (b.nloc < 100 || b.ns < 2 || b.r < 2 || b.r > b.ns / 2 || b.nb < 1 || b.reps < 1 || b.ns > 512) {
    if (rank_ == 0) fprintf(stderr, "bench_mpi_phases: need nloc >= 100, 2 <= r <= ns/2, ns <= 512, nb >= 1, reps >= 1\n");
    MPI_Finalize();
    return 2;
  }
  if (b.lattice2d) { b.nx = (int)floor(sqrt((double)b.nloc)); b.nloc = b.nx * b.nx; }
  b.N = (long long)b.nloc * size_;
  b.row0 = (long long)b.nloc * rank_;
  rc = phgmg_mpi_ctx_create(&b.ctx, MPI_COMM_WORLD, b.N, b.row0, b.nloc, NULL);
  if (rc != PHGMG_OK) fail("phgmg_mpi_ctx_create", rc);
  b.X = (double *)malloc(sizeof(double) * (size_t)b.nloc * b.ns);
  b.W = (double *)malloc(sizeof(double) * (size_t)b.nloc * b.ns);
  b.V = (double *)malloc(sizeof(double) * (size_t)b.nloc * 2 * b.r);
  b.B = (double *)malloc(sizeof(double) * (size_t)b.nloc * b.m);
  make_snapshots(&b);
  make_operator(&b);
  if (rank_ == 0)
    printf("{\"P\": %d, \"nloc\": %d, \"N\": %lld, \"lattice\": \"%s\", \"ns\": %d, \"r\": %d, \"nb\": %d, \"m\": %d, \"reps\": %d,\n"
           "  \"phases\": [\n", size_, b.nloc, b.N, b.lattice2d ? "2d" : "chain", b.ns, b.r, b.nb, b.m, b.reps);
  for (ph = 0; ph < NPHASE - 1; ++ph) measure(&b, ph, 0);
  rss_lib = gmax(rss_mb());
  make_solver(&b);
  measure(&b, NPHASE - 1, 1);
  if (rank_ == 0) printf("  ],\n  \"rss_lib_mb\": %.1f, \"rss_total_mb\": %.1f}\n", rss_lib, gmax(rss_mb()));
  else gmax(rss_mb());
  phgmg_mpi_op_destroy(b.Q);
  phgmg_shifted_destroy(b.sh);
  phgmg_ph_sparse_destroy(b.sp);
  phgmg_mpi_ctx_destroy(b.ctx);
  free(b.X); free(b.W); free(b.V); free(b.B); free(b.full); free(b.full2); free(b.cnt); free(b.dsp);
  MPI_Finalize();
  return 0;
}
