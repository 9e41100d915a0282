/* A mass-spring-damper chain with a cosh on-site potential, distributed by
   rows, for the memory measurements of the distributed offline phase
   (bench/bench_mpi_memory.c and the check in tests/mpi/test_mpi_nl.c).
   Include after phgmg.h with PHGMG_MPI.

   n = N / 2 masses in canonical coordinates, interleaved: row 2i is the
   displacement q_i, row 2i + 1 the momentum p_i. H(x) = 1/2 x^T Q x +
   sum_i w_i a (cosh q_i - 1) with Q = [springs to the neighbours (1) and to
   the ground (1) on the q's: 3 on the diagonal, -1 to q_{i-1}, q_{i+1};
   unit masses on the p's], w_i = 1 + (i mod 3) / 2, a = 0.5. J - R =
   blockdiag over the masses of [[0, 1], [-1, -c_i]], c_i = 0.3 + 0.1 sin i
   (the canonical J and a damper on each momentum): the coupling between
   the masses, and so between the ranks, is in Q (a halo exchange in every
   operator product) and the states, not in J - R. B: a force on the
   momenta, 1 + exp(-((i - 0.3 n) / (0.05 n))^2).

   The solve with J - R is therefore exact and local (each mass's 2 x 2
   block inverted in place: [[-c, -1], [1, 0]], transposed [[-c, 1], [-1, 0]]),
   and costs no memory: what the measurements see is the library's memory
   and the caller's inputs, not a solver's.

   Snapshots (nloc x ns): not a simulation but a closed form, each rank
   computing its own rows: L = 30 standing waves s_l(i) = sin(pi (l + 1)
   (i + 1/2) / n) with q = sum_l A_l s_l(i) cos(om_l t_j + ph_l), p = -sum_l
   A_l om_l s_l(i) sin(om_l t_j + ph_l), A_l = 0.8 0.7^l, om_l = 0.5 + 0.1 l,
   ph_l = 0.37 l, t_j = 0.25 j, plus 1e-9 pseudo-random noise (a function of
   the global row and column: the same matrix for every partition). */
#ifndef MEM_CHAIN_H
#define MEM_CHAIN_H
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MEM_CHAIN_L 30

typedef struct mem_chain {
  phgmg_mpi_ctx *ctx;
  long long N, row0, m0;   /* global rows, this rank's first row and first mass */
  int nloc, nm, ns;        /* rows, masses (nloc / 2), snapshots */
  phgmg_mpi_op *Q;
  double *X, *B, *w;       /* nloc x ns (ld max(1, nloc)), nloc, nm */
  phgmg_gidx *sidx;        /* nm: the terms' rows 2i */
  double poly[1], expo[4];
  phgmg_mpi_sep_model md;
} mem_chain;

/* A pseudo-random number in [-0.5, 0.5) from two integers. */
static double mem_chain_hash(long long a, long long b) {
  unsigned long long x = (unsigned long long)a * 0x9E3779B97F4A7C15ull ^ ((unsigned long long)b + 0x632BE59BD9B4E019ull);
  x ^= x >> 31; x *= 0xBF58476D1CE4E5B9ull; x ^= x >> 27; x *= 0x94D049BB133111EBull; x ^= x >> 31;
  return (double)(x >> 11) * (1.0 / 9007199254740992.0) - 0.5;
}

/* The exact solve with J - R: each mass's 2 x 2 block, in place. */
static phgmg_result mem_chain_solve(char trans, int nrhs, double *X, int ldx, void *user) {
  const mem_chain *c = (const mem_chain *)user;
  int j, i;
  if (trans != 'N' && trans != 'T') return PHGMG_ERR_INVALID_ARG;
  for (j = 0; j < nrhs; ++j)
    for (i = 0; i < c->nm; ++i) {
      double *x = X + (size_t)j * ldx + 2 * (size_t)i;
      const double ci = 0.3 + 0.1 * sin((double)(c->m0 + i)), bq = x[0], bp = x[1];
      x[0] = -ci * bq + (trans == 'N' ? -bp : bp);
      x[1] = trans == 'N' ? bq : -bq;
    }
  return PHGMG_OK;
}

/* Q's rows as CSR, handed to phgmg_mpi_op_create (which copies them). */
static phgmg_result mem_chain_operator(mem_chain *c) {
  const long long n = c->N / 2;
  phgmg_gidx *rp = (phgmg_gidx *)malloc(sizeof(phgmg_gidx) * ((size_t)c->nloc + 1));
  phgmg_gidx *col = (phgmg_gidx *)malloc(sizeof(phgmg_gidx) * (2 * (size_t)c->nloc + 1));
  double *val = (double *)malloc(sizeof(double) * (2 * (size_t)c->nloc + 1));
  phgmg_result rc = PHGMG_ERR_NOMEM;
  long long nz = 0;
  int i;
  if (rp && col && val) {
    rp[0] = 0;
    for (i = 0; i < c->nm; ++i) {
      const long long g = c->m0 + i;   /* the mass; its rows 2g (q), 2g + 1 (p) */
      if (g > 0) { col[nz] = 2 * g - 2; val[nz++] = -1.0; }
      col[nz] = 2 * g; val[nz++] = 3.0;
      if (g + 1 < n) { col[nz] = 2 * g + 2; val[nz++] = -1.0; }
      rp[2 * i + 1] = nz;
      col[nz] = 2 * g + 1; val[nz++] = 1.0;
      rp[2 * i + 2] = nz;
    }
    rc = phgmg_mpi_op_create(&c->Q, c->ctx, rp, col, val);
  }
  free(rp); free(col); free(val);
  return rc;
}

/* The snapshots' rows of this rank, by blocks of masses: S (blk x L) times
   the time coefficients (L x ns) for q and for p. */
static int mem_chain_snapshots(mem_chain *c) {
  enum { BLK = 512 };
  const int L = MEM_CHAIN_L, ns = c->ns, ld = c->nloc > 0 ? c->nloc : 1;
  const double n = (double)(c->N / 2);
  double *S = (double *)malloc(sizeof(double) * (size_t)BLK * L), *Cq = (double *)malloc(sizeof(double) * (size_t)L * ns);
  double *Cp = (double *)malloc(sizeof(double) * (size_t)L * ns), *T = (double *)malloc(sizeof(double) * (size_t)BLK * ns * 2);
  int l, j, i0, i, ok = S && Cq && Cp && T;
  for (l = 0; ok && l < L; ++l)
    for (j = 0; j < ns; ++j) {
      const double A = 0.8 * pow(0.7, l), om = 0.5 + 0.1 * l, ph = om * 0.25 * j + 0.37 * l;
      Cq[l + (size_t)j * L] = A * cos(ph);
      Cp[l + (size_t)j * L] = -A * om * sin(ph);
    }
  for (i0 = 0; ok && i0 < c->nm; i0 += BLK) {
    const int nb = c->nm - i0 < BLK ? c->nm - i0 : BLK;
    for (l = 0; l < L; ++l)
      for (i = 0; i < nb; ++i) S[i + (size_t)l * nb] = sin(3.141592653589793 * (l + 1) * ((double)(c->m0 + i0 + i) + 0.5) / n);
    phgmg_gemm('N', 'N', nb, ns, L, 1.0, S, nb, Cq, L, 0.0, T, nb);
    phgmg_gemm('N', 'N', nb, ns, L, 1.0, S, nb, Cp, L, 0.0, T + (size_t)nb * ns, nb);
    for (j = 0; j < ns; ++j)
      for (i = 0; i < nb; ++i) {
        const size_t q = 2 * (size_t)(i0 + i) + (size_t)j * ld;
        c->X[q] = T[i + (size_t)j * nb] + 1e-9 * mem_chain_hash(c->row0 + 2 * (i0 + i), j);
        c->X[q + 1] = T[i + (size_t)(ns + j) * nb] + 1e-9 * mem_chain_hash(c->row0 + 2 * (i0 + i) + 1, j);
      }
  }
  free(S); free(Cq); free(Cp); free(T);
  return ok;
}

/* The chain of N rows (N even) on comm, the masses spread evenly over the
   ranks; al: the allocator given to the context (the library's allocations
   go through it). Collective; PHGMG_OK or an error on every rank. */
static phgmg_result mem_chain_create(mem_chain *c, MPI_Comm comm, long long N, int ns, const phgmg_allocator *al) {
  int rank, size, i, ok;
  long long n = N / 2, m1;
  phgmg_result rc;
  memset(c, 0, sizeof *c);
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  if (N < 2 || N % 2 || ns < 1) return PHGMG_ERR_SIZE;
  c->N = N; c->ns = ns;
  c->m0 = n * rank / size; m1 = n * (rank + 1) / size;
  c->nm = (int)(m1 - c->m0); c->nloc = 2 * c->nm; c->row0 = 2 * c->m0;
  rc = phgmg_mpi_ctx_create(&c->ctx, comm, N, c->row0, c->nloc, al);
  if (rc != PHGMG_OK) return rc;
  c->X = (double *)malloc(sizeof(double) * ((size_t)c->nloc * ns + 1));
  c->B = (double *)malloc(sizeof(double) * ((size_t)c->nloc + 1));
  c->w = (double *)malloc(sizeof(double) * ((size_t)c->nm + 1));
  c->sidx = (phgmg_gidx *)malloc(sizeof(phgmg_gidx) * ((size_t)c->nm + 1));
  ok = c->X && c->B && c->w && c->sidx && mem_chain_snapshots(c);
  rc = phgmg_mpi_agree(comm, ok ? PHGMG_OK : PHGMG_ERR_NOMEM);
  if (rc == PHGMG_OK) rc = mem_chain_operator(c);
  if (rc != PHGMG_OK) return rc;
  for (i = 0; i < c->nm; ++i) {
    const long long g = c->m0 + i;
    const double z = ((double)g - 0.3 * (double)n) / (0.05 * (double)n);
    c->B[2 * i] = 0.0;
    c->B[2 * i + 1] = 1.0 + exp(-z * z);
    c->w[i] = 1.0 + 0.5 * (double)(g % 3);
    c->sidx[i] = 2 * g;
  }
  c->poly[0] = -0.5;
  c->expo[0] = 0.25; c->expo[1] = 1.0; c->expo[2] = 0.25; c->expo[3] = -1.0;   /* 0.5 (cosh s - 1) */
  c->md.lin.Q = c->Q; c->md.lin.m = 1; c->md.lin.B = c->B; c->md.lin.ldb = c->nloc > 0 ? c->nloc : 1;
  c->md.lin.solve = mem_chain_solve; c->md.lin.solve_user = c;
  c->md.nsep = c->nm; c->md.sep_idx = c->sidx; c->md.sep_w = c->w;
  c->md.poly_deg = 0; c->md.nexp = 2; c->md.per_term = 0; c->md.poly = c->poly; c->md.expo = c->expo;
  return PHGMG_OK;
}

static void mem_chain_free(mem_chain *c) {
  phgmg_mpi_op_destroy(c->Q);
  phgmg_mpi_ctx_destroy(c->ctx);
  free(c->X); free(c->B); free(c->w); free(c->sidx);
  memset(c, 0, sizeof *c);
}

/* A counting allocator: every block carries its size in front, so the bytes
   in use and their peak are exact. */
typedef struct mem_count {
  size_t cur, peak;
} mem_count;
static void *mem_count_alloc(size_t size, void *user) {
  mem_count *m = (mem_count *)user;
  double *p = (double *)malloc(size + 2 * sizeof(double));   /* 16 bytes: the size, alignment kept */
  if (!p) return NULL;
  memcpy(p, &size, sizeof size);
  m->cur += size;
  if (m->cur > m->peak) m->peak = m->cur;
  return p + 2;
}
static void mem_count_free(void *ptr, void *user) {
  mem_count *m = (mem_count *)user;
  size_t size;
  double *p;
  if (!ptr) return;
  p = (double *)ptr - 2;
  memcpy(&size, p, sizeof size);
  m->cur -= size;
  free(p);
}
#endif
