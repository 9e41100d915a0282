/* bench_mpi_memory — peak memory per rank of the distributed offline phase
   (manual 2.7) at a fixed global size (strong scaling): phgmg_mpi_reduce,
   GMG-POD with ECSW hyper-reduction, of a nonlinear chain of N states
   (tests/mpi/mem_chain.h: the model, its snapshots in closed form, each
   rank computing its own rows, and its exact local solve with J - R).

   Per run, one line on stdout (rank 0), the maxima and minima over the ranks:
     P, N, nloc (largest), ns, r, tol, nd (points kept), the reduce's wall time,
     rss_kb      peak resident set (VmHWM of /proc/self/status) at the end,
     rss_in_kb   the same before phgmg_mpi_reduce (MPI, the inputs, the
                 operator),
     lib_b       the peak of the bytes the library held at once (a counting
                 allocator given to phgmg_mpi_ctx_create: the context, the
                 operator's copy, every workspace of phgmg_mpi_reduce and its
                 result),
     in_b        the bytes of the caller's inputs (snapshots, B, the terms'
                 indices and weights).
   bench/mpi_memory/run.sh runs it at two sizes and P = 1, 2, 4 and forms the
   table of bench/README.md ("Memory per rank of the distributed offline
   phase").

   Usage: mpirun -np P bench_mpi_memory [--N 2000000] [--ns 40] [--r 20] [--tol 1e-2]
     make build/bench_mpi_memory (mpicc -std=c99 -O2). */
#define _POSIX_C_SOURCE 200112L
#define PHGMG_MPI
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "../tests/mpi/mem_chain.h"
#include <stdio.h>
#include <sys/resource.h>

/* Peak resident set in kB: VmHWM, else ru_maxrss (Linux: kB). */
static double peak_rss_kb(void) {
  FILE *f = fopen("/proc/self/status", "r");
  char line[256];
  double v = -1.0;
  while (f && fgets(line, sizeof line, f))
    if (!strncmp(line, "VmHWM:", 6)) { v = atof(line + 6); break; }
  if (f) fclose(f);
  if (v < 0.0) {
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    v = (double)u.ru_maxrss;
  }
  return v;
}

static void minmax(double v, double *lo, double *hi) {
  MPI_Allreduce(&v, lo, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&v, hi, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
}

static const char *arg(int argc, char **argv, const char *name, const char *def) {
  int i;
  for (i = 1; i + 1 < argc; ++i)
    if (!strcmp(argv[i], name)) return argv[i + 1];
  return def;
}

int main(int argc, char **argv) {
  mem_count cnt = {0, 0};
  phgmg_allocator al;
  mem_chain c;
  phgmg_reduce_opts o;
  phgmg_mpi_rom mr;
  phgmg_result rc;
  long long N;
  int rank, size, ns, r;
  double tol, t0, t1, v[6][2], in_b;
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  N = atoll(arg(argc, argv, "--N", "2000000"));
  ns = atoi(arg(argc, argv, "--ns", "40"));
  r = atoi(arg(argc, argv, "--r", "20"));
  tol = atof(arg(argc, argv, "--tol", "1e-2"));
  if (N < 4 * size || N % 2 || ns < 2 || r < 2 || r > ns || !(tol > 0.0 && tol < 1.0)) {
    if (rank == 0) fprintf(stderr, "usage: mpirun -np P bench_mpi_memory [--N even >= 4P] [--ns S] [--r R <= S] [--tol T]\n");
    MPI_Finalize();
    return 2;
  }
  al.alloc = mem_count_alloc; al.free = mem_count_free; al.user = &cnt;
  rc = mem_chain_create(&c, MPI_COMM_WORLD, N, ns, &al);
  if (rc != PHGMG_OK) {
    if (rank == 0) fprintf(stderr, "bench_mpi_memory: the model: %s\n", phgmg_result_string(rc));
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  in_b = 8.0 * ((double)c.nloc * (ns + 1) + 2.0 * c.nm);
  minmax(peak_rss_kb(), &v[0][0], &v[0][1]);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = r; o.hyper.on = 1; o.hyper.kind = PHGMG_HYPER_ECSW; o.hyper.tol = tol;
  MPI_Barrier(MPI_COMM_WORLD);
  t0 = MPI_Wtime();
  rc = phgmg_mpi_reduce(c.ctx, &c.md, ns, c.X, c.nloc > 0 ? c.nloc : 1, &o, &mr, NULL, 0);
  t1 = MPI_Wtime() - t0;
  if (rc != PHGMG_OK) {
    if (rank == 0) fprintf(stderr, "bench_mpi_memory: phgmg_mpi_reduce: %s\n", phgmg_result_string(rc));
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  minmax(peak_rss_kb(), &v[1][0], &v[1][1]);
  minmax((double)cnt.peak, &v[2][0], &v[2][1]);
  minmax(in_b, &v[3][0], &v[3][1]);
  minmax(t1, &v[4][0], &v[4][1]);
  minmax((double)c.nloc, &v[5][0], &v[5][1]);
  if (rank == 0)
    printf("P=%d N=%lld nloc=%.0f ns=%d r=%d tol=%g nd=%d time_s=%.2f rss_kb=%.0f rss_kb_min=%.0f rss_in_kb=%.0f "
           "lib_b=%.0f lib_b_min=%.0f in_b=%.0f\n",
           size, N, v[5][1], ns, r, tol, mr.nd, v[4][1], v[1][1], v[1][0], v[0][1], v[2][1], v[2][0], v[3][1]);
  phgmg_mpi_rom_free(&mr);
  mem_chain_free(&c);
  MPI_Finalize();
  return 0;
}
