/* Distributed GMG-POD with a real distributed solver: PETSc assembles J - R
   as an MPIAIJ matrix and MUMPS factors it (a distributed direct solve);
   phgmg_mpi_gmg_pod_linear meets it only through its solve callback. The
   header never includes PETSc: this file does.

     make build/petsc_mumps      (mpicc + PETSc with MUMPS: Debian libpetsc-real-dev)
     mpirun -np 4 build/petsc_mumps --J-coo J.npy --R-coo R.npy --Q-coo Q.npy \
         --B B.npy --X X.npy --r 20 --out rom.phgmgrom [--y y.npy] [--npy PREFIX] \
         [--dt 0.1] [--steps 300] [--amp 0.1] [PETSc options, e.g. -ksp_view]

   Inputs are the files of `phgmg reduce` (manual chapter 6): J, R, Q as
   (nnz, 3) .npy arrays of (row, col, value) triplets (0-based, duplicates
   summed), B (N,) or (N, m), the snapshots X (N, ns). Every rank keeps only
   its own rows, the contiguous block PETSc's default layout gives it
   (PetscSplitOwnership): it reads the triplet files and keeps the entries
   of its rows, and reads X a batch of columns at a time, keeping its rows.
   The program then
     1. assembles A = J - R (MPIAIJ), and a KSP of type preonly with an LU
        preconditioner by MUMPS, factored once (KSPSetUp);
     2. gives Q's rows to phgmg_mpi_op_create (CSR, global columns);
     3. calls phgmg_mpi_gmg_pod_linear, whose solve callback runs KSPSolve
        (KSPSolveTranspose for 'T') on each right-hand side;
     4. on rank 0 writes the reduced model (K, Qh, Bh: a phgmg_rom of kind
        PHGMG_ROM_LINEAR) with phgmg_rom_save, and with --y steps it from
        rest with the GL3 stepper, u_a(t) = AMP sin((1 + a/m) t) (the input
        `sin` of the command line), writing the outputs y (m x (steps+1));
        with --npy PREFIX also K, Qh, Bh as PREFIX_K.npy, _Qh.npy, _Bh.npy.
   It is the serial `phgmg reduce --X X.npy --method gmg-pod --r R` (no
   reference state, no step map) computed on P ranks. Measured with
   `make test-petsc` (tests/mpi/check_petsc.sh: a scrambled chain of 1500
   masses from bench/lattice.py, N = 3000, 301 snapshots of
   `phgmg simulate --dt 0.1 --steps 300`, r = 20): the outputs of
   `phgmg simulate-rom --dt 0.1 --steps 300` on this program's model differ
   from those on the serial model by 2.9e-15 (1 rank), 3.2e-15 (2 ranks)
   and 3.0e-15 (4 ranks) relative to the largest output, and K and Qh from
   the serial ones by at most 3.0e-15 relative after the sign of each POD
   mode (PETSc 3.18.5, MUMPS 5.5.1, Open MPI 4.1.4). */
#define _POSIX_C_SOURCE 200809L
#define PHGMG_MPI
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include <petscksp.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

typedef struct args {
  const char *J, *R, *Q, *B, *X, *out, *y, *npy;
  int r, steps;
  double dt, amp;
} args;

/* This rank's block of rows and the global size. */
typedef struct layout {
  PetscInt N, row0, nloc;
} layout;

/* The solve callback's state: the factored KSP and two work vectors. */
typedef struct petsc_solver {
  KSP ksp;
  Vec b, x;
  PetscInt nloc;
} petsc_solver;

/* An error message, printed by rank 0 only (every rank reads the same
   files, so they all find the same fault; the result is agreed over ranks). */
static void say(const char *fmt, ...) {
  int rank = 0;
  va_list ap;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  if (rank != 0) return;
  va_start(ap, fmt);
  fputs("petsc_mumps: ", stderr);
  vfprintf(stderr, fmt, ap);
  fputc('\n', stderr);
  va_end(ap);
}

/* 1 if both paths name one existing file (however spelled or linked). */
static int same_file(const char *p, const char *q) {
  struct stat a, b;
  return p && q && stat(p, &a) == 0 && stat(q, &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

/* --npy PREFIX: the file of block k (0 K, 1 Qh, 2 Bh), named as the
   command line's NAME_K.npy, NAME_Qh.npy, NAME_Bh.npy. */
static void npy_name(char *buf, const char *prefix, int k) {
  static const char *const suffix[3] = {"_K.npy", "_Qh.npy", "_Bh.npy"};
  snprintf(buf, 4096, "%.4000s%s", prefix, suffix[k]);
}

/* 1 if an output (--out, --y, --npy's files) is one of the inputs or the other output:
   a run never overwrites its input files. */
static int outputs_clash(const args *a) {
  const char *in[5];
  int k, o;
  const char *out[5];
  char nm[3][4096];
  in[0] = a->J; in[1] = a->R; in[2] = a->Q; in[3] = a->B; in[4] = a->X;
  out[0] = a->out; out[1] = a->y; out[2] = out[3] = out[4] = NULL;
  for (k = 0; k < 3 && a->npy; ++k) { npy_name(nm[k], a->npy, k); out[2 + k] = nm[k]; }
  for (o = 0; o < 5; ++o)
    for (k = 0; k < 5; ++k)
      if (out[o] && (same_file(out[o], in[k]) || !strcmp(out[o], in[k]))) {
        say("%s is an input file: choose another output", out[o]);
        return 1;
      }
  if (a->y && (same_file(a->out, a->y) || !strcmp(a->out, a->y))) { say("--out and --y name one file"); return 1; }
  return 0;
}

static int parse_args(int argc, char **argv, args *a) {
  int i;
  memset(a, 0, sizeof *a);
  a->r = 0; a->steps = 300; a->dt = 0.1; a->amp = 0.1;
  for (i = 1; i < argc; ++i) {
    const char *o = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
    if (!v) break;
    if (!strcmp(o, "--J-coo")) a->J = v;
    else if (!strcmp(o, "--R-coo")) a->R = v;
    else if (!strcmp(o, "--Q-coo")) a->Q = v;
    else if (!strcmp(o, "--B")) a->B = v;
    else if (!strcmp(o, "--X")) a->X = v;
    else if (!strcmp(o, "--out")) a->out = v;
    else if (!strcmp(o, "--y")) a->y = v;
    else if (!strcmp(o, "--npy")) a->npy = v;
    else if (!strcmp(o, "--r")) a->r = atoi(v);
    else if (!strcmp(o, "--steps")) a->steps = atoi(v);
    else if (!strcmp(o, "--dt")) a->dt = atof(v);
    else if (!strcmp(o, "--amp")) a->amp = atof(v);
    else continue; /* PETSc's own options (-ksp_view, ...) */
    ++i;
  }
  if (!a->J || !a->R || !a->Q || !a->B || !a->X || !a->out || a->r < 1 || a->steps < 1 || !(a->dt > 0.0)) {
    say("usage: mpirun -np P petsc_mumps --J-coo J.npy --R-coo R.npy --Q-coo Q.npy --B B.npy --X X.npy --r R "
        "--out MODEL.phgmgrom [--y y.npy] [--npy PREFIX] [--dt 0.1] [--steps 300] [--amp 0.1] [PETSc options]");
    return 1;
  }
  return outputs_clash(a);
}

/* 1 on every rank if any rank passes bad != 0 (errors are collective). */
static int any_rank(int bad) {
  int all = 0;
  MPI_Allreduce(&bad, &all, 1, MPI_INT, MPI_MAX, PETSC_COMM_WORLD);
  return all;
}

/* The triplets of a (nnz, 3) .npy file (column-major: rows, cols, values),
   checked: integer indices in [0, N), finite values. Read whole on every
   rank; the caller keeps its rows. */
static int read_triplets(const char *path, PetscInt N, double **T, int *nnz) {
  int rows = 0, cols = 0, k;
  phgmg_result rc = phgmg_npy_read(path, T, &rows, &cols, NULL, NULL);
  if (rc != PHGMG_OK) { say("%s: %s", path, phgmg_result_string(rc)); return 1; }
  if (cols != 3) { say("%s: expected (nnz, 3) triplets", path); return 1; }
  for (k = 0; k < 2 * rows; ++k) {
    const double v = (*T)[k];
    if (!(v >= 0.0 && v < (double)N && v == floor(v))) {
      say("%s: index %g is not an integer in [0, %ld)", path, v, (long)N);
      return 1;
    }
  }
  for (k = 2 * rows; k < 3 * rows; ++k)
    if (!isfinite((*T)[k])) { say("%s: a value is NaN or infinite", path); return 1; }
  *nnz = rows;
  return 0;
}

/* B's rows of this rank (nloc x m) and the global N, m (from B's shape). */
static int read_B(const char *path, double **Bl, PetscInt *N, int *m) {
  double *B = NULL;
  int rows = 0, cols = 0;
  phgmg_result rc = phgmg_npy_read(path, &B, &rows, &cols, NULL, NULL);
  if (rc != PHGMG_OK) { say("%s: %s", path, phgmg_result_string(rc)); return 1; }
  *N = rows; *m = cols;
  *Bl = B; /* trimmed to this rank's rows by own_B once the layout is known */
  return 0;
}

static void own_B(const layout *L, int m, double **B) {
  double *Bl = (double *)malloc(sizeof(double) * (size_t)(L->nloc > 0 ? L->nloc : 1) * (size_t)m);
  int i, j;
  for (j = 0; j < m; ++j)
    for (i = 0; i < L->nloc; ++i) Bl[i + (size_t)j * L->nloc] = (*B)[L->row0 + i + (size_t)j * L->N];
  phgmg_npy_free(*B, NULL);
  *B = Bl;
}

/* Entries of J (sign +1) or R (sign -1) in this rank's rows, added to A. */
static int add_triplets(Mat A, const layout *L, const double *T, int nnz, double sign) {
  int k;
  for (k = 0; k < nnz; ++k) {
    const PetscInt i = (PetscInt)T[k], j = (PetscInt)T[nnz + k];
    if (i < L->row0 || i >= L->row0 + L->nloc) continue;
    if (MatSetValue(A, i, j, sign * T[2 * nnz + k], ADD_VALUES)) return 1;
  }
  return 0;
}

/* Nonzeros per own row in the diagonal and off-diagonal blocks (upper bounds). */
static void count_nnz(const layout *L, const double *T, int nnz, PetscInt *dnz, PetscInt *onz) {
  int k;
  for (k = 0; k < nnz; ++k) {
    const PetscInt i = (PetscInt)T[k], j = (PetscInt)T[nnz + k];
    if (i < L->row0 || i >= L->row0 + L->nloc) continue;
    if (j >= L->row0 && j < L->row0 + L->nloc) ++dnz[i - L->row0];
    else ++onz[i - L->row0];
  }
}

/* A = J - R as MPIAIJ in PETSc's default layout L. */
static int assemble_A(Mat *A, const layout *L, const double *TJ, int nJ, const double *TR, int nR) {
  PetscInt *dnz = (PetscInt *)calloc((size_t)L->nloc + 1, sizeof(PetscInt));
  PetscInt *onz = (PetscInt *)calloc((size_t)L->nloc + 1, sizeof(PetscInt));
  PetscInt i;
  int err = !dnz || !onz;
  if (!err) {
    count_nnz(L, TJ, nJ, dnz, onz); count_nnz(L, TR, nR, dnz, onz);
    for (i = 0; i < L->nloc; ++i) { dnz[i] = PetscMin(dnz[i], L->nloc); onz[i] = PetscMin(onz[i], L->N - L->nloc); }
    err = MatCreate(PETSC_COMM_WORLD, A) || MatSetSizes(*A, L->nloc, L->nloc, L->N, L->N) ||
          MatSetType(*A, MATAIJ) || MatSeqAIJSetPreallocation(*A, 0, dnz) ||
          MatMPIAIJSetPreallocation(*A, 0, dnz, 0, onz);
  }
  if (!err) err = add_triplets(*A, L, TJ, nJ, 1.0) || add_triplets(*A, L, TR, nR, -1.0);
  if (!err) err = MatAssemblyBegin(*A, MAT_FINAL_ASSEMBLY) || MatAssemblyEnd(*A, MAT_FINAL_ASSEMBLY);
  free(dnz); free(onz);
  return err;
}

/* KSP preonly + LU by MUMPS, factored once. 1 if the factorization failed. */
static int setup_ksp(KSP *ksp, Mat A) {
  PC pc;
  PCFailedReason why = PC_NOERROR;
  if (KSPCreate(PETSC_COMM_WORLD, ksp) || KSPSetOperators(*ksp, A, A) || KSPSetType(*ksp, KSPPREONLY) ||
      KSPGetPC(*ksp, &pc) || PCSetType(pc, PCLU) || PCFactorSetMatSolverType(pc, MATSOLVERMUMPS) ||
      KSPSetFromOptions(*ksp) || KSPSetUp(*ksp))
    return 1;
  if (PCGetFailedReason(pc, &why)) return 1;
  return any_rank(why != PC_NOERROR);
}

/* The solve callback: X (nloc x nrhs, ldx) <- (J - R)^{-1} X, or ^{-T} X,
   one column at a time through the MUMPS factors. Collective: every rank
   makes the same calls; a failure is agreed by phgmg_mpi_gmg_pod_linear. */
static phgmg_result petsc_solve(char trans, int nrhs, double *X, int ldx, void *user) {
  petsc_solver *s = (petsc_solver *)user;
  KSPConvergedReason reason;
  int j, bad = 0;
  for (j = 0; j < nrhs; ++j) {
    double *col = X + (size_t)j * ldx;
    PetscScalar *xb;
    const PetscScalar *xx;
    if (VecGetArray(s->b, &xb)) return PHGMG_ERR_NOT_CONVERGED;
    memcpy(xb, col, sizeof(double) * (size_t)s->nloc);
    if (VecRestoreArray(s->b, &xb)) return PHGMG_ERR_NOT_CONVERGED;
    if (trans == 'T' ? KSPSolveTranspose(s->ksp, s->b, s->x) : KSPSolve(s->ksp, s->b, s->x))
      return PHGMG_ERR_NOT_CONVERGED;
    if (KSPGetConvergedReason(s->ksp, &reason)) return PHGMG_ERR_NOT_CONVERGED;
    if (reason < 0) bad = 1;
    if (VecGetArrayRead(s->x, &xx)) return PHGMG_ERR_NOT_CONVERGED;
    memcpy(col, xx, sizeof(double) * (size_t)s->nloc);
    if (VecRestoreArrayRead(s->x, &xx)) return PHGMG_ERR_NOT_CONVERGED;
  }
  return bad ? PHGMG_ERR_SINGULAR : PHGMG_OK;
}

/* Q's entries in this rank's rows as CSR (rows sorted, global columns). */
static int q_csr(const layout *L, const double *T, int nnz, phgmg_gidx **rp, phgmg_gidx **col, double **val) {
  phgmg_gidx *pos;
  PetscInt i;
  int k;
  *rp = (phgmg_gidx *)calloc((size_t)L->nloc + 1, sizeof(phgmg_gidx));
  pos = (phgmg_gidx *)calloc((size_t)L->nloc + 1, sizeof(phgmg_gidx));
  if (!*rp || !pos) { free(pos); return 1; }
  for (k = 0; k < nnz; ++k) {
    const PetscInt r = (PetscInt)T[k];
    if (r >= L->row0 && r < L->row0 + L->nloc) ++(*rp)[r - L->row0 + 1];
  }
  for (i = 0; i < L->nloc; ++i) (*rp)[i + 1] += (*rp)[i];
  *col = (phgmg_gidx *)malloc(sizeof(phgmg_gidx) * (size_t)((*rp)[L->nloc] + 1));
  *val = (double *)malloc(sizeof(double) * (size_t)((*rp)[L->nloc] + 1));
  if (!*col || !*val) { free(pos); return 1; }
  for (i = 0; i < L->nloc; ++i) pos[i] = (*rp)[i];
  for (k = 0; k < nnz; ++k) {
    const PetscInt r = (PetscInt)T[k];
    if (r < L->row0 || r >= L->row0 + L->nloc) continue;
    (*col)[pos[r - L->row0]] = (phgmg_gidx)T[nnz + k];
    (*val)[pos[r - L->row0]++] = T[2 * nnz + k];
  }
  free(pos);
  return 0;
}

/* This rank's rows of the (N, ns) snapshots, read a batch of columns at a
   time (about 8 MB per batch): the N x ns matrix never exists on a rank. */
static int read_X_rows(const char *path, const layout *L, double **Xl, int *ns) {
  int rows = 0, cols = 0, j0, nb, i, j;
  double *buf;
  phgmg_result rc = phgmg_npy_read_cols(path, 0, 0, NULL, 0, &rows, &cols);
  if (rc != PHGMG_OK) { say("%s: %s", path, phgmg_result_string(rc)); return 1; }
  if (rows != L->N || cols < 1) { say("%s: expected (%ld, ns)", path, (long)L->N); return 1; }
  nb = (int)PetscMax(1, PetscMin(cols, 1048576 / L->N));
  buf = (double *)malloc(sizeof(double) * (size_t)rows * (size_t)nb);
  *Xl = (double *)malloc(sizeof(double) * (size_t)(L->nloc > 0 ? L->nloc : 1) * (size_t)cols);
  if (!buf || !*Xl) { free(buf); return 1; }
  for (j0 = 0; j0 < cols; j0 += nb) {
    const int k = PetscMin(nb, cols - j0);
    rc = phgmg_npy_read_cols(path, j0, k, buf, rows, NULL, NULL);
    if (rc != PHGMG_OK) { say("%s: %s", path, phgmg_result_string(rc)); free(buf); return 1; }
    for (j = 0; j < k; ++j)
      for (i = 0; i < L->nloc; ++i) (*Xl)[i + (size_t)(j0 + j) * L->nloc] = buf[L->row0 + i + (size_t)j * rows];
  }
  free(buf);
  *ns = cols;
  return 0;
}

/* Rank 0: steps the reduced model from rest with u_a = amp sin((1 + a/m) t)
   and writes y (m x (steps+1), column n = y(n dt)). */
static int run_rom(const phgmg_rom *rom, const args *a) {
  const int r = rom->r, m = rom->m;
  const size_t ms = phgmg_rom_stepper_memsize_dt(rom, a->dt);
  double *mem = (double *)malloc(ms), *x = (double *)calloc((size_t)r, sizeof(double));
  double *y = (double *)calloc((size_t)m * ((size_t)a->steps + 1), sizeof(double)), *u3 = (double *)malloc(sizeof(double) * 3 * (size_t)m);
  phgmg_rom_stepper s;
  phgmg_result rc = (!mem || !x || !y || !u3) ? PHGMG_ERR_NOMEM : phgmg_rom_stepper_init(&s, rom, a->dt, 0.0, 0, mem, ms);
  int n, c, p;
  for (n = 0; n < a->steps && rc == PHGMG_OK; ++n) {
    double tc[3];
    phgmg_rom_stage_times(a->dt * n, a->dt, tc);
    for (c = 0; c < 3; ++c)
      for (p = 0; p < m; ++p) u3[c * m + p] = a->amp * sin((1.0 + (double)p / m) * tc[c]);
    rc = phgmg_rom_step(&s, x, u3, y + (size_t)(n + 1) * m, NULL);
  }
  if (rc == PHGMG_OK) rc = phgmg_npy_write(a->y, y, m, a->steps + 1, m, 2, 0);
  if (rc != PHGMG_OK) say("test run: %s", phgmg_result_string(rc));
  else printf("test run: %d steps of %g, y(T) = %.12e (written to %s)\n", a->steps, a->dt, y[(size_t)a->steps * m], a->y);
  free(mem); free(x); free(y); free(u3);
  return rc != PHGMG_OK;
}

/* Rank 0: the reduced model as a phgmg_rom of kind LINEAR, saved (and run). */
static int write_rom(const args *a, int m, const double *K, const double *Qh, const double *Bh) {
  phgmg_rom rom;
  phgmg_result rc;
  memset(&rom, 0, sizeof rom);
  rom.kind = PHGMG_ROM_LINEAR; rom.method = PHGMG_METHOD_GMG_POD; rom.r = a->r; rom.m = m;
  rom.Bh = Bh; rom.Qh = Qh; rom.K = K; rom.dt = a->dt;
  rc = phgmg_rom_check(&rom);
  if (rc == PHGMG_OK) rc = phgmg_rom_save(&rom, a->out);
  if (rc != PHGMG_OK) { say("%s: %s", a->out, phgmg_result_string(rc)); return 1; }
  printf("reduced model (r = %d, m = %d) written to %s\n", a->r, m, a->out);
  if (a->npy) {
    const double *blk[3];
    char nm[4096];
    int k;
    blk[0] = K; blk[1] = Qh; blk[2] = Bh;
    for (k = 0; k < 3 && rc == PHGMG_OK; ++k) {
      npy_name(nm, a->npy, k);
      rc = phgmg_npy_write(nm, blk[k], a->r, k < 2 ? a->r : m, a->r, 2, 0);
      if (rc != PHGMG_OK) { say("%s: %s", nm, phgmg_result_string(rc)); return 1; }
    }
    printf("K, Qh, Bh written to %s_K.npy, %s_Qh.npy, %s_Bh.npy\n", a->npy, a->npy, a->npy);
  }
  return a->y ? run_rom(&rom, a) : 0;
}

/* Steps 2-4 once A's solver is set up: Q's operator, the reduction, the output. */
static int reduce(const args *a, const layout *L, petsc_solver *sv, const double *TQ, int nQ, const double *Bl, int m,
                  const double *Xl, int ns) {
  phgmg_mpi_ctx *ctx = NULL;
  phgmg_mpi_op *Qop = NULL;
  phgmg_mpi_linear_model md;
  phgmg_gidx *rp = NULL, *col = NULL;
  double *val = NULL, *K = (double *)malloc(sizeof(double) * (size_t)a->r * (size_t)(2 * a->r + m + 1));
  double *Qh = K + (size_t)a->r * a->r, *Bh = Qh + (size_t)a->r * a->r, *S = Bh + (size_t)a->r * m, t0;
  phgmg_result rc = phgmg_mpi_ctx_create(&ctx, PETSC_COMM_WORLD, L->N, L->row0, (int)L->nloc, NULL);
  int rank, err;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  if (rc == PHGMG_OK && any_rank(!K || q_csr(L, TQ, nQ, &rp, &col, &val))) rc = PHGMG_ERR_NOMEM;
  if (rc == PHGMG_OK) rc = phgmg_mpi_op_create(&Qop, ctx, rp, col, val);
  memset(&md, 0, sizeof md);   /* fields not set: zero (E = I) */
  md.Q = Qop; md.m = m; md.B = Bl; md.ldb = L->nloc > 0 ? (int)L->nloc : 1;
  md.solve = petsc_solve; md.solve_user = sv;
  t0 = MPI_Wtime();
  if (rc == PHGMG_OK)
    rc = phgmg_mpi_gmg_pod_linear(ctx, &md, ns, Xl, L->nloc > 0 ? (int)L->nloc : 1, a->r, K, Qh, Bh, S, NULL, 1);
  err = rc != PHGMG_OK;
  if (rank == 0 && err) say("distributed GMG-POD: %s", phgmg_result_string(rc));
  if (rank == 0 && !err) {
    int P;
    MPI_Comm_size(PETSC_COMM_WORLD, &P);
    printf("GMG-POD on %d ranks: N = %ld, %d snapshots, r = %d, %.3f s; sigma_%d / sigma_1 = %.3e\n", P,
           (long)L->N, ns, a->r, MPI_Wtime() - t0, a->r - m, a->r > m ? S[a->r - m - 1] / S[0] : 1.0);
    err = write_rom(a, m, K, Qh, Bh);
  }
  phgmg_mpi_op_destroy(Qop);
  phgmg_mpi_ctx_destroy(ctx);
  free(rp); free(col); free(val); free(K);
  return any_rank(err);
}

/* Reads the inputs, sets up PETSc's A = J - R and its MUMPS factors, reduces. */
static int run(const args *a) {
  layout L;
  double *TJ = NULL, *TR = NULL, *TQ = NULL, *Bl = NULL, *Xl = NULL;
  int nJ = 0, nR = 0, nQ = 0, m = 0, ns = 0, err;
  Mat A = NULL;
  petsc_solver sv;
  memset(&sv, 0, sizeof sv);
  err = any_rank(read_B(a->B, &Bl, &L.N, &m));
  if (!err) {
    L.nloc = PETSC_DECIDE;
    err = PetscSplitOwnership(PETSC_COMM_WORLD, &L.nloc, &L.N) != 0;
    MPI_Scan(&L.nloc, &L.row0, 1, MPIU_INT, MPI_SUM, PETSC_COMM_WORLD);
    L.row0 -= L.nloc;
    own_B(&L, m, &Bl);
  }
  if (!err) err = any_rank(read_triplets(a->J, L.N, &TJ, &nJ) || read_triplets(a->R, L.N, &TR, &nR) ||
                           read_triplets(a->Q, L.N, &TQ, &nQ) || read_X_rows(a->X, &L, &Xl, &ns));
  if (!err) err = any_rank(assemble_A(&A, &L, TJ, nJ, TR, nR));
  phgmg_npy_free(TJ, NULL); phgmg_npy_free(TR, NULL);
  if (!err && setup_ksp(&sv.ksp, A)) {
    err = 1;
    PetscPrintf(PETSC_COMM_WORLD, "petsc_mumps: the MUMPS factorization of J - R failed (singular?)\n");
  }
  if (!err) { sv.nloc = L.nloc; err = any_rank(MatCreateVecs(A, &sv.x, &sv.b) != 0); }
  if (!err) err = reduce(a, &L, &sv, TQ, nQ, Bl, m, Xl, ns);
  VecDestroy(&sv.b); VecDestroy(&sv.x); KSPDestroy(&sv.ksp); MatDestroy(&A);
  phgmg_npy_free(TQ, NULL); free(Bl); free(Xl);
  return err;
}

int main(int argc, char **argv) {
  args a;
  int err;
  if (PetscInitialize(&argc, &argv, NULL, NULL)) return 1;
  err = parse_args(argc, argv, &a);
  if (!err) err = run(&a);
  PetscFinalize();
  return err;
}
