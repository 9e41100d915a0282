/* The distributed GMG-POD and SP1 of a nonlinear model with a separable
   Hamiltonian and ECSW hyper-reduction (phgmg_mpi_reduce) against the
   serial phgmg_reduce with the same options, at any number of ranks:
   mpirun -np P build/test_mpi_nl [DIR]. Layouts: P = 2 and 3 uneven blocks,
   P = 4 with rank 2 owning no rows. Rank 0 runs the serial reduction and
   compares (the distributed results are replicated: every rank holds them);
   with DIR it also saves, loads and exports the distributed models there.
   Exit status 0 iff every check passed on every rank. Built with mpicc
   (make test-mpi). With --scale n (last) only the GMG-POD/SP1 comparison
   runs, on a chain of n masses at r = 20, with a negative control (a
   Gram-matrix POD must miss V^T (J - R) V), then GMG-QM (POD and greedy
   manifolds, r = 8) on the linear chain of n masses; --scale-qm n: only
   the latter (bench/mpi_equivalence.sh). Built against the library's one
   compile (make test-mpi: PHGMG_IMPLEMENTATION_ELSEWHERE and build/mpi/lib.o),
   or alone with -DPHGMG_IMPLEMENTATION. */
#define _POSIX_C_SOURCE 199309L   /* nanosleep */
#define PHGMG_MPI
#include "../../phgmg.h"
#include "mem_chain.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mpi_harness.h"
static const char *dir_;   /* argv[1]: a directory for the model files (none: not written) */
static int scale_;         /* --scale n: only the comparisons at scale, n masses (GMG-POD/SP1 r = 20, GMG-QM r = 8) */
static int qm_only_;       /* --scale-qm n: only GMG-QM at scale */
static int qm_cosh_;       /* --scale-qm-cosh n: GMG-QM at scale, also on the cosh chain with ECSW */
static int qm_deim_;        /* compare_qm: DEIM weights (normwise) */
static double online_dt_ = 0.1; /* online_diff's step (the cosh chain's GMG-QM models at scale: 0.001, stiff) */
static double wtol_ = 1e-12;
static int ystep_ = 1;      /* compare_serial: 0 when the serial model itself cannot be stepped (scale mode) */ /* compare_qm: the weights' tolerance (scale mode: from the serial model's movement) */




/* ---- the model: a damped chain with an on-site cosh potential ------------- */
/* n masses, N = 2n, interleaved states (l_i, v_i) (banded, kb = 3):
   J = [0 Tt; -Tt^T 0] (Tt: 1 on the diagonal, -1 above), R = 0.3 on the
   velocities, Q = diag(1, 1), B = e_{v_1}; term i on l_i: weight
   w_i = 1 + (i mod 3) / 2, phi_i(s) = a_i (cosh s - 1), a_i = 0.5 + 0.4
   sin(i) (one function per term: poly = {-a_i}, expo = {a_i/2, 1, a_i/2, -1}). */
typedef struct chain {
  phgmg_ph_system sys;
  int n, N, kb;
  double *J, *R, *Q, *B, *poly, *expo, *w;
  int *idx;
} chain;

static void chain_build(chain *c, int n, int all) {
  const int N = 2 * n, kb = 3, ld = 2 * kb + 1, nt = all ? N : n;
  int i;
  memset(c, 0, sizeof *c);
  c->n = n; c->N = N; c->kb = kb;
  c->J = (double *)calloc((size_t)ld * N, sizeof(double));
  c->R = (double *)calloc((size_t)ld * N, sizeof(double));
  c->Q = (double *)calloc((size_t)ld * N, sizeof(double));
  c->B = (double *)calloc((size_t)N, sizeof(double));
  c->poly = (double *)malloc(sizeof(double) * (size_t)nt);
  c->expo = (double *)malloc(sizeof(double) * 4 * (size_t)nt);
  c->w = (double *)malloc(sizeof(double) * (size_t)nt);
  c->idx = (int *)malloc(sizeof(int) * (size_t)nt);
#define AT(A, r, s) (A)[(size_t)(kb + (r) - (s)) + (size_t)(s) * ld]
  for (i = 0; i < n; ++i) {
    const int l = 2 * i, v = 2 * i + 1;
    AT(c->J, l, v) = 1.0; AT(c->J, v, l) = -1.0;
    if (i + 1 < n) { AT(c->J, l, v + 2) = -1.0; AT(c->J, v + 2, l) = 1.0; }
    AT(c->R, v, v) = 0.3;
    AT(c->Q, l, l) = 1.0; AT(c->Q, v, v) = 1.0;
  }
  for (i = 0; i < nt; ++i) {
    const double a = 0.5 + 0.4 * sin((double)i);
    c->idx[i] = all ? i : 2 * i;
    c->w[i] = 1.0 + 0.5 * (i % 3);
    c->poly[i] = -a;
    c->expo[4 * i] = 0.5 * a; c->expo[4 * i + 1] = 1.0; c->expo[4 * i + 2] = 0.5 * a; c->expo[4 * i + 3] = -1.0;
  }
#undef AT
  c->B[1] = 1.0;
  c->sys.N = N; c->sys.m = 1; c->sys.storage = PHGMG_BANDED; c->sys.kb = kb;
  c->sys.J = c->J; c->sys.R = c->R; c->sys.Q = c->Q; c->sys.B = c->B;
  c->sys.nl = PHGMG_NL_SEPARABLE; c->sys.nsep = nt; c->sys.sep_idx = c->idx; c->sys.sep_w = c->w;
  c->sys.poly_deg = 0; c->sys.poly = c->poly; c->sys.nexp = 2; c->sys.expo = c->expo; c->sys.phi_nfun = nt;
}

static void chain_free(chain *c) {
  free(c->J); free(c->R); free(c->Q); free(c->B); free(c->poly); free(c->expo); free(c->w); free(c->idx);
}



/* ---- the distributed inputs ----------------------------------------------------- */
typedef struct solver {
  const phgmg_mpi_ctx *c;
  phgmg_jr_factor *f;
  int fail_rank;
} solver;

/* The user's solve: the right-hand sides gathered, the banded LU of J - R
   replicated. */
static phgmg_result solve_cb(char trans, int nrhs, double *X, int ldx, void *user) {
  solver *s = (solver *)user;
  const phgmg_mpi_ctx *c = s->c;
  const int N = (int)c->N;
  double *full = (double *)malloc(sizeof(double) * (size_t)N * nrhs), *col = (double *)malloc(sizeof(double) * ((size_t)c->nloc + 1));
  int *cnt = (int *)malloc(sizeof(int) * (size_t)size_), *dsp = (int *)malloc(sizeof(int) * (size_t)size_), q, j;
  for (q = 0; q < size_; ++q) { cnt[q] = (int)(c->starts[q + 1] - c->starts[q]); dsp[q] = (int)c->starts[q]; }
  for (j = 0; j < nrhs; ++j) {
    memcpy(col, X + (size_t)j * ldx, sizeof(double) * (size_t)c->nloc);
    MPI_Allgatherv(col, c->nloc, MPI_DOUBLE, full + (size_t)j * N, cnt, dsp, MPI_DOUBLE, MPI_COMM_WORLD);
  }
  phgmg_jr_solve(s->f, trans, nrhs, full, N);
  for (j = 0; j < nrhs; ++j) memcpy(X + (size_t)j * ldx, full + c->row0 + (size_t)j * N, sizeof(double) * (size_t)c->nloc);
  free(full); free(col); free(cnt); free(dsp);
  return rank_ == s->fail_rank ? PHGMG_ERR_SINGULAR : PHGMG_OK;
}

/* Everything a rank passes: Q's rows as CSR, B's and X's rows, its terms. */
typedef struct dist {
  phgmg_mpi_ctx *c;
  phgmg_mpi_op *Q, *JR;
  phgmg_mpi_sep_model md;
  solver sv;
  double *Bl, *Xl, *pl, *el, *wl;
  long long *sidx, *sid;
  int ld;
} dist;


static void dist_build(dist *d, const chain *ch, int ns, const double *X) {
  const int N = ch->N;
  long long row0;
  int nloc, i, j, k, nt = 0;
  layout(N, &row0, &nloc);
  memset(d, 0, sizeof *d);
  CHECK(phgmg_mpi_ctx_create(&d->c, MPI_COMM_WORLD, N, row0, nloc, NULL) == PHGMG_OK, "ctx");
  d->ld = nloc > 0 ? nloc : 1;
  d->Q = band_op_kb(d->c, ch->N, ch->kb, ch->Q, NULL, 0.0);
  d->JR = band_op_kb(d->c, ch->N, ch->kb, ch->J, ch->R, 1.0);
  d->Bl = (double *)malloc(sizeof(double) * (size_t)d->ld);
  d->Xl = (double *)malloc(sizeof(double) * (size_t)d->ld * ns);
  for (i = 0; i < nloc; ++i) d->Bl[i] = ch->B[row0 + i];
  for (j = 0; j < ns; ++j)
    for (i = 0; i < nloc; ++i) d->Xl[i + (size_t)j * d->ld] = X[row0 + i + (size_t)j * N];
  /* this rank's terms: those whose coordinate it owns, global id = serial term number */
  d->sidx = (long long *)malloc(sizeof(long long) * ((size_t)ch->sys.nsep + 1));
  d->sid = (long long *)malloc(sizeof(long long) * ((size_t)ch->sys.nsep + 1));
  d->pl = (double *)malloc(sizeof(double) * ((size_t)ch->sys.nsep + 1));
  d->el = (double *)malloc(sizeof(double) * 4 * ((size_t)ch->sys.nsep + 1));
  d->wl = (double *)malloc(sizeof(double) * ((size_t)ch->sys.nsep + 1));
  for (k = 0; k < ch->sys.nsep; ++k)
    if (ch->idx[k] >= row0 && ch->idx[k] < row0 + nloc) {
      d->sidx[nt] = ch->idx[k]; d->sid[nt] = k; d->pl[nt] = ch->poly[k]; d->wl[nt] = ch->w[k];
      memcpy(d->el + 4 * (size_t)nt, ch->expo + 4 * (size_t)k, 4 * sizeof(double));
      ++nt;
    }
  CHECK(phgmg_jr_factor_create(&d->sv.f, &ch->sys, NULL, NULL) == PHGMG_OK, "J - R factor");
  d->sv.c = d->c; d->sv.fail_rank = -1;
  d->md.lin.Q = d->Q; d->md.lin.m = 1; d->md.lin.B = d->Bl; d->md.lin.ldb = d->ld;
  d->md.lin.solve = solve_cb; d->md.lin.solve_user = &d->sv; d->md.JR = d->JR;
  d->md.nsep = nt; d->md.sep_idx = d->sidx; d->md.sep_id = d->sid; d->md.sep_w = d->wl;
  d->md.poly_deg = 0; d->md.nexp = 2; d->md.per_term = 1; d->md.poly = d->pl; d->md.expo = d->el;
}

static void dist_free(dist *d) {
  phgmg_jr_factor_destroy(d->sv.f);
  phgmg_mpi_op_destroy(d->Q);
  phgmg_mpi_op_destroy(d->JR);
  free(d->Bl); free(d->Xl); free(d->pl); free(d->el); free(d->wl); free(d->sidx); free(d->sid);
  phgmg_mpi_ctx_destroy(d->c);
}


/* The serial singular values of the snapshots (adj: of the adjusted ones X - QB QB^T X). */
static void serial_sigma(const chain *ch, int ns, const double *X, int k, int adj, double *S) {
  const int N = ch->N;
  double *Xa = (double *)malloc(sizeof(double) * (size_t)N * ns), *V = (double *)malloc(sizeof(double) * (size_t)N * k);
  int j, kk = 0;
  memcpy(Xa, X, sizeof(double) * (size_t)N * ns);
  if (adj && ch->sys.E) {   /* a mass matrix: the ports' columns b = E^{-1} B, Xa = X - b (b^T X) / (b^T b) */
    double *b = (double *)calloc((size_t)N, sizeof(double)), bb = 0.0;
    phgmg_jr_factor *f = NULL;
    int i;
    b[1] = 1.0;
    CHECK(phgmg_e_factor_create(&f, &ch->sys, NULL, NULL) == PHGMG_OK, "E factor (reference)");
    if (f) phgmg_jr_solve(f, 'N', 1, b, N);
    for (i = 0; i < N; ++i) bb += b[i] * b[i];
    for (j = 0; j < ns; ++j) {
      double c = 0.0;
      for (i = 0; i < N; ++i) c += b[i] * Xa[i + (size_t)j * N];
      for (i = 0; i < N; ++i) Xa[i + (size_t)j * N] -= b[i] * c / bb;
    }
    phgmg_jr_factor_destroy(f);
    free(b);
  }
  for (j = 0; adj && !ch->sys.E && j < ns; ++j) Xa[1 + (size_t)j * N] = 0.0;   /* B = e_1: the projection removes row 1 */
  CHECK(phgmg_pod(N, ns, Xa, N, k, 0.0, V, N, S, &kk, NULL) == PHGMG_OK && kk == k, "serial POD");
  free(Xa); free(V);
}

/* Largest output difference of two reduced models stepped nsteps steps of
   online_dt_ from xa, xb under u_in, over the largest output. HUGE_VAL if a step
   fails on one model only, or on both within the first 10 steps; both
   failing at the same later step with the same code (a hyper-reduced model
   that leaves its training envelope) ends the comparison there. */
static double online_diff(const phgmg_rom *a, const phgmg_rom *b, const double *xa0, const double *xb0, int nsteps,
                          const char *tag) {
  static double m1[1 << 16], m2[1 << 16];
  phgmg_rom_stepper s1, s2;
  double u3[3], tc[3], y1 = 0.0, y2 = 0.0, ey = 0.0, sy = 0.0, xa[64], xb[64];
  int st, i, ok;
  memcpy(xa, xa0, sizeof(double) * (size_t)a->r);
  memcpy(xb, xb0, sizeof(double) * (size_t)b->r);
  CHECK(phgmg_rom_check(a) == PHGMG_OK, "%s: rom check", tag);
  ok = phgmg_rom_stepper_init(&s1, a, online_dt_, 0.0, 0, m1, sizeof m1) == PHGMG_OK &&
       phgmg_rom_stepper_init(&s2, b, online_dt_, 0.0, 0, m2, sizeof m2) == PHGMG_OK;
  CHECK(ok, "%s: steppers", tag);
  for (st = 0; ok && st < nsteps; ++st) {
    phgmg_rom_stage_times(online_dt_ * st, online_dt_, tc);
    for (i = 0; i < 3; ++i) u_in(tc[i], u3 + i, NULL);
    const phgmg_result e1 = phgmg_rom_step(&s1, xa, u3, &y1, NULL), e2 = phgmg_rom_step(&s2, xb, u3, &y2, NULL);
    if (e1 != PHGMG_OK || e2 != PHGMG_OK) {   /* a model that cannot go on: the other must stop alike */
      if (e1 != e2 || st < 10) return HUGE_VAL;
      printf(" [both stop at step %d: %s]", st, phgmg_result_string(e1));
      break;
    }
    ey = fmax(ey, fabs(y1 - y2)); sy = fmax(sy, fabs(y2));
  }
  return ok ? ey / sy : HUGE_VAL;
}


/* Scale mode: how far the serial model itself moves when every snapshot
   entry is changed by one unit in the last place (random signs), far below
   the snapshots' own error: the K difference (sign-normalised) and the
   output difference. The distributed model cannot be expected closer to the
   serial one than the serial one is to itself under rounding of its data;
   tolerances become max(default, 10 x these). Rank 0. */
static void serial_sensitivity(const chain *ch, int ns, const double *X, const double *x0, const phgmg_reduce_opts *o,
                               const phgmg_reduced *red, double *ktol, double *ytol) {
  const int N = ch->N;
  double *X2 = (double *)malloc(sizeof(double) * (size_t)N * ns), xr[64], x2[64], sg[64], *V2f, eK, ey;
  unsigned long long st = 2463534242ull;
  phgmg_reduced *red2 = NULL;
  const phgmg_rom *a, *b;
  size_t i;
  int j, r;
  for (i = 0; i < (size_t)N * ns; ++i) {
    st ^= st << 13; st ^= st >> 7; st ^= st << 17;
    X2[i] = X[i] * (1.0 + ((st >> 11) & 1 ? 1.0 : -1.0) * 2.220446049250313e-16);
  }
  CHECK(phgmg_reduce(&red2, &ch->sys, X2, N, ns, o, NULL, NULL) == PHGMG_OK, "serial reduce, perturbed");
  free(X2);
  if (!red2) return;
  a = phgmg_reduced_rom(red); b = phgmg_reduced_rom(red2); r = a->r;
  V2f = (double *)calloc((size_t)N * r, sizeof(double));
  for (j = 0; j < r; ++j) {
    memset(xr, 0, sizeof xr); xr[j] = 1.0;
    phgmg_reduced_lift(red2, xr, V2f + (size_t)j * N);
  }
  mode_signs(red, N, r, V2f, sg);
  eK = rel_diff(r, r, b->K, a->K, sg, sg);
  phgmg_reduced_restrict(red, x0, xr);
  for (j = 0; j < r; ++j) x2[j] = sg[j] * xr[j];
  ey = online_diff(b, a, x2, xr, 200, "perturbed");
  if (a->nd == b->nd && a->nd > 0 && phgmg_reduced_terms(red) && phgmg_reduced_terms(red2) &&
      !memcmp(phgmg_reduced_terms(red), phgmg_reduced_terms(red2), sizeof(int) * (size_t)a->nd)) {
    double ew = 0.0, sw = 0.0;   /* the same points: how far the weights move */
    for (j = 0; j < a->nd; ++j) { ew = fmax(ew, fabs(b->w[j] - a->w[j])); sw = fmax(sw, fabs(a->w[j])); }
    wtol_ = fmax(1e-12, 10.0 * ew / sw);
    printf("  serial model under one-ulp changes of the snapshots: the same points, weights %.1e\n", ew / sw);
  }
  ystep_ = ey < HUGE_VAL;   /* a serial model that cannot be stepped: outputs not compared */
  printf("  serial model under one-ulp changes of the snapshots: K %.1e, outputs %.1e\n", eK, ey);
  *ktol = fmax(*ktol, 10.0 * eK);
  if (ey < HUGE_VAL) *ytol = fmax(*ytol, 10.0 * ey);   /* a serial model that cannot be stepped sets no tolerance */
  free(V2f);
  phgmg_reduced_destroy(red2);
}

/* Rank 0: the distributed model against the serial one. sg: the modes'
   signs (from the bases). */
static void compare_serial(const chain *ch, int ns, const double *X, const double *x0, const phgmg_reduced *red,
                           const phgmg_mpi_rom *mr, const double *V0f, int nsteps, double ktol, double ytol,
                           const char *tag) {
  const phgmg_rom *ro = phgmg_reduced_rom(red);
  const int r = mr->r, m = mr->m;
  double sg[64], S[64], e, xr[64], xd[64];
  int i, j, same = ro->nd == mr->nd;
  mode_signs(red, ch->N, r, V0f, sg);   /* the distributed basis's signs against the serial one's */
  const int gmg = mr->rom.method == PHGMG_METHOD_GMG_POD;
  serial_sigma(ch, ns, X, gmg ? r - m : r, gmg, S);
  for (j = 0, e = 0.0; j < (gmg ? r - m : r); ++j) e = fmax(e, fabs(mr->S[j] - S[j]) / S[0]);
  CHECK(e <= 1e-12, "%s: singular values %.2e sigma_1", tag, e);
  printf("  %s: sigma %.1e sigma_1", tag, e);
  e = rel_diff(r, r, mr->K, ro->K, sg, sg);
  CHECK(e <= ktol, "%s: K %.2e", tag, e);
  printf(", K %.1e", e);
  e = rel_diff(r, r, mr->Qh, ro->Qh, sg, sg);
  CHECK(e <= 1e-12, "%s: Qh %.2e", tag, e);
  printf(", Qh %.1e", e);
  e = rel_diff(r, m, mr->Bh, ro->Bh, sg, NULL);
  CHECK(e <= 1e-12, "%s: Bh %.2e", tag, e);
  CHECK(same, "%s: %d points, serial %d", tag, mr->nd, ro->nd);
  for (j = 0; same && j < mr->nd; ++j)   /* serial: the kept terms' numbers (every term: none stored, j) */
    same = mr->pts[j] == (phgmg_reduced_terms(red) ? phgmg_reduced_terms(red)[j] : j) && mr->coord[j] == ch->idx[mr->pts[j]];
  CHECK(same, "%s: point sets differ", tag);
  if (same) {
    double ew = 0.0, sw = 0.0;
    for (j = 0; j < mr->nd; ++j) { ew = fmax(ew, fabs(mr->w[j] - ro->w[j])); sw = fmax(sw, fabs(ro->w[j])); }
    CHECK(ew <= wtol_ * sw, "%s: weights %.2e", tag, ew / sw);
    for (j = 0, e = 0.0; j < r; ++j)   /* rows of V0: columns scaled by the signs */
      for (i = 0; i < mr->nd; ++i) e = fmax(e, fabs(sg[j] * mr->P0[i + (size_t)j * mr->nd] - ro->P0[i + (size_t)j * ro->nd]));
    CHECK(e <= 1e-12, "%s: P0 %.2e", tag, e);
    printf(", %d points, weights %.1e, P0 %.1e", mr->nd, ew / sw, e);
  }
  phgmg_reduced_restrict(red, x0, xr);
  for (j = 0; j < r; ++j) xd[j] = sg[j] * xr[j];
  e = online_diff(&mr->rom, ro, xd, xr, nsteps, tag);
  if (ystep_) {
    CHECK(e <= ytol, "%s: reduced outputs against the serial model's: %.2e", tag, e);
    printf(", outputs (%d steps) %.1e\n", nsteps, e);
  } else {
    printf(", outputs not compared (the serial model itself cannot be stepped: %s here)\n",
           e < HUGE_VAL ? "the distributed one can" : "neither can");
  }
  wtol_ = 1e-12; ystep_ = 1;   /* set per comparison by serial_sensitivity */
  if (dir_) {   /* the model file and the C export: the loaded model steps to the same outputs, bitwise */
    char path[1024];
    phgmg_rom lr;
    void *blk = NULL;
    static double m1[1 << 16], m2[1 << 16];
    phgmg_rom_stepper s1, s2;
    double x1[64] = {0}, x2[64] = {0}, u3[3] = {0.1, 0.2, 0.3}, y1 = 0.0, y2 = 0.0;
    int st, same_y = 1, loaded;
    snprintf(path, sizeof path, "%s/nl_rom.bin", dir_);
    loaded = phgmg_rom_save(&mr->rom, path) == PHGMG_OK && phgmg_rom_load(path, &lr, &blk, NULL) == PHGMG_OK;
    CHECK(loaded, "%s: save/load (%s)", tag, path);
    if (loaded) {   /* (a failed save leaves lr unset: nothing to step) */
      CHECK(phgmg_rom_stepper_init(&s1, &mr->rom, 0.1, 0.0, 0, m1, sizeof m1) == PHGMG_OK &&
                phgmg_rom_stepper_init(&s2, &lr, 0.1, 0.0, 0, m2, sizeof m2) == PHGMG_OK, "%s: steppers (file)", tag);
      for (j = 0; j < r; ++j) x1[j] = x2[j] = 0.1 * (j + 1);
      for (st = 0; st < 20; ++st) {
        same_y &= phgmg_rom_step(&s1, x1, u3, &y1, NULL) == PHGMG_OK && phgmg_rom_step(&s2, x2, u3, &y2, NULL) == PHGMG_OK;
        same_y &= y1 == y2;
      }
      CHECK(same_y, "%s: the loaded model's outputs differ", tag);
    }
    snprintf(path, sizeof path, "%s/nl_rom.h", dir_);
    CHECK(phgmg_rom_export_c(&mr->rom, "nl_rom", path) == PHGMG_OK, "%s: C export", tag);
    free(blk);
  }
}


/* The negative control at scale: the reduced operator V^T (J - R) V of the
   raw snapshots' r leading POD modes from the serial phgmg_pod (rank 0,
   broadcast), from the distributed TSQR POD (phgmg_mpi_pod) and from a
   Gram-matrix POD (eigenvectors W of X^T X, V = X W Lambda^{-1/2}), signs
   from the serial basis: TSQR within 1e-12 relative of the serial, the Gram
   basis off by more than that (it squares the condition: its vectors carry
   eps (sigma_1 / sigma_r)^2 errors), which shows the comparison can fail. */
static void gram_control(const dist *d, int N, int ns, const double *X, int r) {
  const phgmg_mpi_ctx *c = d->c;
  const int ld = d->ld, nl = c->nloc;
  double *Vs = (double *)malloc(sizeof(double) * (size_t)N * r), *Ss = (double *)malloc(sizeof(double) * ns);
  double *B[3], A[3][400], *G = (double *)malloc(sizeof(double) * ns * ns), *W = (double *)malloc(sizeof(double) * ns * ns);
  double *lam = (double *)malloc(sizeof(double) * ns), *T = (double *)malloc(sizeof(double) * ns * r), S[64];
  double e[3] = {0.0, 0.0, 0.0}, sc = 0.0;
  int i, j, b, k = 0, ok = 1;
  if (rank_ == 0) ok = phgmg_pod(N, ns, X, N, r, 0.0, Vs, N, Ss, &k, NULL) == PHGMG_OK && k == r;
  MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
  MPI_Bcast(Vs, N * r, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  MPI_Bcast(Ss, ns, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  CHECK(ok, "serial POD of the raw snapshots");
  for (b = 0; b < 3; ++b) B[b] = (double *)calloc((size_t)ld * r, sizeof(double));
  for (j = 0; j < r; ++j) for (i = 0; i < nl; ++i) B[0][i + (size_t)j * ld] = Vs[c->row0 + i + (size_t)j * N];
  CHECK(phgmg_mpi_pod(c, ns, d->Xl, ld, r, 0.0, B[1], ld, S, &k) == PHGMG_OK && k == r, "TSQR POD");
  CHECK(phgmg_mpi_atb(c, ns, ns, d->Xl, ld, d->Xl, ld, G, ns) == PHGMG_OK, "Gram matrix");
  phgmg_sym_eig(ns, G, ns, lam, W, ns);
  for (j = 0; j < r; ++j)   /* leading eigenpairs last */
    for (i = 0; i < ns; ++i) T[i + (size_t)j * ns] = W[i + (size_t)(ns - 1 - j) * ns] / sqrt(lam[ns - 1 - j]);
  if (nl > 0) phgmg_gemm('N', 'N', nl, r, ns, 1.0, d->Xl, ld, T, ns, 0.0, B[2], ld);
  for (b = 1; b < 3; ++b)
    for (j = 0; j < r; ++j) {   /* signs from the serial basis */
      double dl = 0.0, dg = 0.0;
      for (i = 0; i < nl; ++i) dl += B[b][i + (size_t)j * ld] * B[0][i + (size_t)j * ld];
      MPI_Allreduce(&dl, &dg, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
      if (dg < 0.0) for (i = 0; i < nl; ++i) B[b][i + (size_t)j * ld] = -B[b][i + (size_t)j * ld];
    }
  for (b = 0; b < 3; ++b) CHECK(phgmg_mpi_op_project(d->JR, r, B[b], ld, A[b], r) == PHGMG_OK, "project %d", b);
  for (i = 0; i < r * r; ++i) sc = fmax(sc, fabs(A[0][i]));
  for (b = 1; b < 3; ++b) for (i = 0; i < r * r; ++i) e[b] = fmax(e[b], fabs(A[b][i] - A[0][i]) / sc);
  for (j = 0; j < r; ++j) e[0] = fmax(e[0], fabs(S[j] - Ss[j]) / Ss[0]);
  CHECK(e[0] <= 1e-12, "TSQR singular values against the serial: %.2e sigma_1", e[0]);
  CHECK(e[1] <= 1e-12, "V^T (J - R) V, TSQR basis against the serial: %.2e", e[1]);
  CHECK(e[2] > 1e-12, "the Gram basis should miss V^T (J - R) V (%.2e)", e[2]);
  if (rank_ == 0)
    printf("  raw snapshots, r = %d: sigma_r/sigma_1 %.2e; sigma %.1e sigma_1; V^T (J - R) V: TSQR %.1e, Gram %.1e\n", r,
           Ss[r - 1] / Ss[0], e[0], e[1], e[2]);
  for (b = 0; b < 3; ++b) free(B[b]);
  free(Vs); free(Ss); free(G); free(W); free(lam); free(T);
}

/* Distributed GMG-POD r = 12 with ECSW (tol 1e-3) of the cosh chain (N =
   2000, 101 snapshots from a smooth initial displacement under a sine
   input: every term moves, the points lie on every rank that owns rows) against the serial phgmg_reduce with the same options; then the
   solve failing on one rank only: the same code on every rank. */
static void gram_control(const dist *d, int N, int ns, const double *X, int r);
static void test_gmg_pod_ecsw(int n, int r) {
  const int N = 2 * n, ns = 101;
  chain ch;
  dist d;
  double *X = (double *)malloc(sizeof(double) * (size_t)N * ns), *x0 = (double *)calloc((size_t)N, sizeof(double));
  double *V0, *V0f;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  phgmg_mpi_rom mr;
  phgmg_result rc;
  int i;
  chain_build(&ch, n, 0);
  for (i = 0; i < n; ++i) x0[2 * i] = 0.8 * sin(3.0 * 3.14159265358979 * i / n) + 0.3 * sin(7.0 * 3.14159265358979 * i / n);
  simulate_root(&ch.sys, x0, 0.2, ns, X);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = r; o.hyper.on = 1; o.hyper.kind = PHGMG_HYPER_ECSW; o.hyper.tol = 1e-3;
  dist_build(&d, &ch, ns, X);
  if (n != 1000) gram_control(&d, N, ns, X, r);
  V0 = (double *)malloc(sizeof(double) * (size_t)d.ld * r);
  rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, V0, d.ld);
  CHECK(rc == PHGMG_OK, "distributed GMG-POD: %d", (int)rc);
  V0f = gather_v0(d.c, r, V0, d.ld);
  CHECK(same_everywhere(mr.nd) && mr.nd > 0, "nd %d differs between ranks", mr.nd);
  if (rc == PHGMG_OK && size_ > 1) {   /* the points are spread: at least two ranks own some */
    int q, j, owners = 0;
    for (q = 0; q < size_; ++q) {
      int has = 0;
      for (j = 0; j < mr.nd; ++j) has |= mr.coord[j] >= d.c->starts[q] && mr.coord[j] < d.c->starts[q + 1];
      owners += has;
    }
    CHECK(owners >= 2, "points on %d rank(s) only", owners);
  }
  if (rank_ == 0 && rc == PHGMG_OK) {
    double ktol = 1e-12, ytol = 1e-10;
    CHECK(phgmg_reduce(&red, &ch.sys, X, N, ns, &o, NULL, NULL) == PHGMG_OK, "serial reduce");
    if (red && scale_) serial_sensitivity(&ch, ns, X, x0, &o, red, &ktol, &ytol);
    if (red) compare_serial(&ch, ns, X, x0, red, &mr, V0f, 200, ktol, ytol, "gmg-pod ecsw");
    phgmg_reduced_destroy(red);
  }
  quiet_barrier();
  phgmg_mpi_rom_free(&mr);
  /* without hyper-reduction: every term kept with its weight, as the serial
     model (not in scale mode: the online stepper's test buffer is small) */
  o.hyper.on = 0;
  rc = scale_ ? PHGMG_ERR_UNSUPPORTED : phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, NULL, 0);
  CHECK(scale_ || (rc == PHGMG_OK && mr.nd == n), "distributed GMG-POD, every term: %d, nd %d", (int)rc, mr.nd);
  if (rank_ == 0 && rc == PHGMG_OK) {
    CHECK(phgmg_reduce(&red, &ch.sys, X, N, ns, &o, NULL, NULL) == PHGMG_OK, "serial reduce, every term");
    if (red) compare_serial(&ch, ns, X, x0, red, &mr, V0f, 40, 1e-12, 1e-10, "gmg-pod, every term");
    phgmg_reduced_destroy(red);
  }
  quiet_barrier();
  if (!scale_) phgmg_mpi_rom_free(&mr);
  o.hyper.on = 1;
  /* SP1 and SP2 with ECSW (J - R as an operator; SP2's W from the POD of the
     gradient snapshots), as the serial SP1 and SP2 */
  for (i = 0; i < 2; ++i) {
    const char *tag = i ? "sp2 ecsw" : "sp1 ecsw";
    o.method = i ? PHGMG_METHOD_SP2 : PHGMG_METHOD_SP1;
    rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, V0, d.ld);
    CHECK(rc == PHGMG_OK && same_everywhere(mr.nd), "distributed %s: %d", tag, (int)rc);
    free(V0f);
    V0f = gather_v0(d.c, r, V0, d.ld);
    if (rank_ == 0 && rc == PHGMG_OK) {
      double ktol = 1e-12, ytol = 1e-10;
      CHECK(phgmg_reduce(&red, &ch.sys, X, N, ns, &o, NULL, NULL) == PHGMG_OK, "serial %s", tag);
      if (red && scale_) serial_sensitivity(&ch, ns, X, x0, &o, red, &ktol, &ytol);
      if (red) compare_serial(&ch, ns, X, x0, red, &mr, V0f, 200, ktol, ytol, tag);
      phgmg_reduced_destroy(red);
    }
    quiet_barrier();
    phgmg_mpi_rom_free(&mr);
  }
  /* DEIM hyper-reduction (Q-DEIM and greedy points) with GMG-POD and SP1:
     the same points in the same order, as global term indices, and the same
     weights as the serial DEIM (negative weights allowed on both sides: the
     comparison is of the computation; the refusal is checked below). DEIM
     modes down to 1e-4 sigma_1: the weights depend on the span of the kept
     modes, which rounding moves by about eps sigma_1 / (the gap after the
     last kept value): at the default 1e-8 that is 1e-9 of the weights for
     the serial computation itself, here 1e-13. */
  for (i = 0; i < 4; ++i) {
    char tag[64];
    o.method = i < 2 ? PHGMG_METHOD_GMG_POD : PHGMG_METHOD_SP1;
    o.hyper.kind = i % 2 ? PHGMG_HYPER_GREEDY : PHGMG_HYPER_QDEIM;
    o.hyper.allow_negative = 1; o.hyper.deim_tol = 1e-4;
    snprintf(tag, sizeof tag, "%s %s", i < 2 ? "gmg-pod" : "sp1", i % 2 ? "greedy deim" : "q-deim");
    rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, V0, d.ld);
    CHECK(rc == PHGMG_OK && same_everywhere(mr.nd) && mr.nd > 1, "distributed %s: %d", tag, (int)rc);
    CHECK(same_everywhere(mr.deim_negative), "%s: negative weights differ between ranks", tag);
    free(V0f);
    V0f = gather_v0(d.c, r, V0, d.ld);
    if (rank_ == 0 && rc == PHGMG_OK) {
      double ktol = 1e-12, ytol = 1e-10;
      phgmg_reduce_info inf;
      CHECK(phgmg_reduce(&red, &ch.sys, X, N, ns, &o, &inf, NULL) == PHGMG_OK, "serial %s", tag);
      if (red && scale_) serial_sensitivity(&ch, ns, X, x0, &o, red, &ktol, &ytol);
      if (red) {
        compare_serial(&ch, ns, X, x0, red, &mr, V0f, 200, ktol, ytol, tag);
        CHECK(mr.deim_negative == inf.deim_negative, "%s: %d negative weights, serial %d", tag, mr.deim_negative,
              inf.deim_negative);
        CHECK(fabs(mr.deim_sigma_ratio - inf.deim_sigma_ratio) <= 1e-12,
              "%s: sigma ratio %.3e, serial %.3e", tag, mr.deim_sigma_ratio, inf.deim_sigma_ratio);
      }
      phgmg_reduced_destroy(red);
    }
    if (rank_ == 0 && rc == PHGMG_OK) printf("  %s: %d negative weights\n", tag, mr.deim_negative);
    quiet_barrier();
    if (rc == PHGMG_OK && mr.deim_negative > 0) {   /* refused without allow_negative, on every rank */
      phgmg_mpi_rom m2;
      o.hyper.allow_negative = 0;
      rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &m2, NULL, 0);
      CHECK(rc == PHGMG_ERR_NEGATIVE_WEIGHT && same_everywhere(rc), "%s without allow_negative: %d", tag, (int)rc);
    }
    phgmg_mpi_rom_free(&mr);
  }
  o.hyper.kind = PHGMG_HYPER_ECSW; o.hyper.allow_negative = 0;
  o.method = PHGMG_METHOD_GMG_POD;
  /* the solve fails on one rank only */
  d.sv.fail_rank = size_ > 1 ? size_ - 1 : 0;
  rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, NULL, 0);
  CHECK(rc == PHGMG_ERR_SINGULAR && same_everywhere(rc) && mr.mem_ == NULL, "failing solve on one rank: %d", rc);
  dist_free(&d);
  chain_free(&ch);
  free(X); free(x0); free(V0); free(V0f);
}

static void compare_qm(const chain *ch, const double *x0, const phgmg_reduced *red, const phgmg_mpi_rom *mr,
                       const double *V0f, int nsteps, double btol, double ytol, double *diffs, const char *tag);
static void qm_sensitivity(const chain *ch, int ns, const double *X, const double *x0, const phgmg_reduce_opts *o,
                           const phgmg_reduced *red, double *btol, double *ytol);
/* From PHGMG_ECSW_SCREEN_MIN (4096) moving terms the serial ECSW screens
   candidates in rounds: the same points (as global indices) and weights
   from the distributed screening. A cosh term on every coordinate of a
   chain of 2100 masses (4200 terms), 31 snapshots, r = 8: GMG-POD, then
   GMG-QM (POD manifold, rn = 4) with the screened fit on its training
   columns. */
static void test_screened(void) {
  const int n = 2100, N = 2 * n, ns = 31, r = 8;
  chain ch;
  dist d;
  double *X = (double *)malloc(sizeof(double) * (size_t)N * ns), *x0 = (double *)calloc((size_t)N, sizeof(double));
  double *V0, *V0f;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  phgmg_mpi_rom mr;
  phgmg_result rc;
  int i;
  chain_build(&ch, n, 1);
  for (i = 0; i < n; ++i) x0[2 * i] = 0.8 * sin(3.0 * 3.14159265358979 * i / n);
  simulate_root(&ch.sys, x0, 0.2, ns, X);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = r; o.hyper.on = 1; o.hyper.tol = 1e-3;
  dist_build(&d, &ch, ns, X);
  V0 = (double *)malloc(sizeof(double) * (size_t)d.ld * r);
  rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, V0, d.ld);
  CHECK(rc == PHGMG_OK && same_everywhere(mr.nd), "distributed GMG-POD, screened: %d", (int)rc);
  V0f = gather_v0(d.c, r, V0, d.ld);
  if (rank_ == 0 && rc == PHGMG_OK) {
    CHECK(phgmg_reduce(&red, &ch.sys, X, N, ns, &o, NULL, NULL) == PHGMG_OK, "serial reduce, screened");
    /* K = G00^{-1} with cond(G00) = 1e6 here (5e5 in test_gmg_pod_ecsw):
       its forward error bound is cond eps ~ 2e-10; measured 6e-13 .. 2e-12 */
    if (red) compare_serial(&ch, ns, X, x0, red, &mr, V0f, 100, 1e-11, 1e-10, "gmg-pod ecsw, 4200 terms");
    phgmg_reduced_destroy(red);
    red = NULL;
  }
  quiet_barrier();
  phgmg_mpi_rom_free(&mr);
  /* GMG-QM (POD manifold, rn = 4) with the screened ECSW on the manifold's
     training columns (its greedy manifold's model, serial and distributed
     alike, stops at step 2 on this data: not compared) */
  o.method = PHGMG_METHOD_GMG_QM; o.qm.rn = 4; o.qm.manifold = PHGMG_MANIFOLD_POD;
  rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, V0, d.ld);
  CHECK(rc == PHGMG_OK && same_everywhere(mr.nd) && mr.nd > 0, "distributed GMG-QM, screened ECSW: %d", (int)rc);
  free(V0f);
  V0f = gather_v0(d.c, r, V0, d.ld);
  if (rank_ == 0 && rc == PHGMG_OK) {
    double btol = 1e-11, ytol = 1e-10;
    CHECK(phgmg_reduce(&red, &ch.sys, X, N, ns, &o, NULL, NULL) == PHGMG_OK, "serial GMG-QM, screened ECSW");
    /* the weights (each to its own size) held to ten times the serial
       model's own movement under one-ulp changes of the snapshots */
    if (red) qm_sensitivity(&ch, ns, X, x0, &o, red, &btol, &ytol);
    if (red) compare_qm(&ch, x0, red, &mr, V0f, 100, btol, ytol, NULL, "gmg-qm pod ecsw, 4200 terms");
    wtol_ = 1e-12;
    phgmg_reduced_destroy(red);
  }
  quiet_barrier();
  phgmg_mpi_rom_free(&mr);
  dist_free(&d);
  chain_free(&ch);
  free(X); free(x0); free(V0); free(V0f);
}

/* Largest |si_i sj_j A - B| / max(sc, max |B|) (A, B: r x c; si, sj the
   rows' and columns' signs; sc: the scale of the operator B is a block of). */
static double qm_diff(int r, int c, const phgmg_real *A, const phgmg_real *B, const double *si, const double *sj,
                      double sc) {
  double e = 0.0, s = 0.0;
  int i, j;
  for (j = 0; j < c; ++j)
    for (i = 0; i < r; ++i) {
      e = fmax(e, fabs(si[i] * sj[j] * (double)A[i + (size_t)j * r] - (double)B[i + (size_t)j * r]));
      s = fmax(s, fabs((double)B[i + (size_t)j * r]));
    }
  s = fmax(s, sc);
  return s > 0.0 ? e / s : e;
}

/* Rank 0: a distributed GMG-QM model against the serial one. The basis
   [B, V1] (the same selected modes: each column of V0f against the serial
   V0 = lift(e_j) - V2 M(e_j kron e_j)), signs sg of V0's columns; the signs
   sg2 of V2's modes from G01 (V2 itself stays distributed); then every
   block of the quadratic model (G00, G01, G10, G11, Qh, Q01, Q11, Ms, Bh,
   the kept terms' P0, P1, w), q_max and the outputs over nsteps steps. */
static void compare_qm(const chain *ch, const double *x0, const phgmg_reduced *red, const phgmg_mpi_rom *mr,
                       const double *V0f, int nsteps, double btol, double ytol, double *diffs, const char *tag) {
  const phgmg_rom *ro = phgmg_reduced_rom(red), *rd = &mr->rom;
  const int N = ch->N, r = mr->r, m = mr->m, p = r - m, rn = ro->rn;
  const double *V2s = NULL, *Ms = NULL;
  double sg[64], sg2[64], sgm[64 * 64], one = 1.0, e = 0.0, eb = 0.0, ew = 0.0, wmax = 0.0, gsc = 0.0, xr[64], xd[64], *col = (double *)malloc(sizeof(double) * (size_t)N);
  int i, j, a, same;
  CHECK(rd->kind == PHGMG_ROM_QUADRATIC && rd->rn == rn && phgmg_reduced_qm(red, &V2s, &Ms) == rn, "%s: kind/rn", tag);
  mode_signs(red, N, r, V0f, sg);
  for (j = 0; j < r; ++j) {   /* the basis: the same modes */
    double cm = 0.0, em = 0.0;
    memset(xr, 0, sizeof xr); xr[j] = 1.0;
    phgmg_reduced_lift(red, xr, col);
    for (i = 0; j >= m && i < N; ++i)
      for (a = 0; a < rn; ++a) col[i] -= V2s[i + (size_t)a * N] * Ms[a + (size_t)((j - m) * p + (j - m)) * rn];
    for (i = 0; i < N; ++i) { em = fmax(em, fabs(sg[j] * V0f[i + (size_t)j * N] - col[i])); cm = fmax(cm, fabs(col[i])); }
    eb = fmax(eb, em / cm);
  }
  CHECK(eb <= 100.0 * btol, "%s: basis [B, V1] %.2e (not the same modes)", tag, eb);
  for (a = 0; a < rn; ++a) {   /* V2's signs */
    double dt = 0.0;
    for (i = 0; i < r; ++i) dt += sg[i] * (double)rd->G01[i + (size_t)a * r] * (double)ro->G01[i + (size_t)a * r];
    sg2[a] = dt < 0.0 ? -1.0 : 1.0;
  }
  for (a = 0; a < p; ++a)
    for (j = 0; j < p; ++j) sgm[a * p + j] = sg[m + a] * sg[m + j];
  {   /* G01, G10, G11 on the scale of G = [V0, V2]^T (J - R)^{-1} [V0, V2] they are blocks of */
    const phgmg_real *gb[4];
    const int gn[4] = {r * r, r * rn, rn * r, rn * rn};
    gb[0] = ro->G00; gb[1] = ro->G01; gb[2] = ro->G10; gb[3] = ro->G11;
    for (a = 0; a < 4; ++a)
      for (i = 0; i < gn[a]; ++i) gsc = fmax(gsc, fabs((double)gb[a][i]));
  }
#define QD(A, rr, cc, si, sj, sc) do { double t_ = qm_diff(rr, cc, rd->A, ro->A, si, sj, sc); \
    CHECK(t_ <= btol, "%s: " #A " %.2e", tag, t_); e = fmax(e, t_); } while (0)
  QD(G00, r, r, sg, sg, 0.0); QD(G01, r, rn, sg, sg2, gsc); QD(G10, rn, r, sg2, sg, gsc);
  QD(G11, rn, rn, sg2, sg2, gsc); QD(Qh, r, r, sg, sg, 0.0); QD(Q11, rn, rn, sg2, sg2, 0.0);
  QD(Ms, rn, p * p, sg2, sgm, 0.0); QD(Bh, r, m, sg, &one, 0.0);
  {   /* Q01 = V0^T Q V2 is rounding for Q = I (V2 orthogonal to B and V1): on the scale of Qh */
    double t_ = 0.0, s_ = 0.0;
    for (i = 0; i < r * rn; ++i) t_ = fmax(t_, fabs(sg[i % r] * sg2[i / r] * rd->Q01[i] - ro->Q01[i]));
    for (i = 0; i < r * r; ++i) s_ = fmax(s_, fabs(ro->Qh[i]));
    CHECK(t_ <= btol * s_, "%s: Q01 %.2e", tag, t_ / s_);
  }
#undef QD
  CHECK(fabs(rd->q_max[0] - ro->q_max[0]) <= btol * ro->q_max[0], "%s: q_max %.17g, serial %.17g", tag,
        (double)rd->q_max[0], (double)ro->q_max[0]);
  same = rd->nd == ro->nd && (rd->nd == 0 || (rd->P1 && ro->P1));
  CHECK(same, "%s: %d terms, serial %d", tag, rd->nd, ro->nd);
  for (j = 0, wmax = 0.0; same && j < rd->nd; ++j) wmax = fmax(wmax, fabs(ro->w[j]));
  for (j = 0; same && j < rd->nd; ++j) {   /* serial: the kept terms' numbers (every term: none stored, j) */
    const int tj = phgmg_reduced_terms(red) ? phgmg_reduced_terms(red)[j] : j;
    /* ECSW's weights (> 0) each to 1e-12; DEIM's, the solution of a linear
       system with weights of both signs, to 1e-12 of the largest */
    const double wref = ro->nd > 0 && qm_deim_ ? wmax : fabs(ro->w[j]);
    same = mr->pts[j] == tj && mr->coord[j] == ch->idx[tj] && (diffs || fabs(rd->w[j] - ro->w[j]) <= wtol_ * wref);
    ew = fmax(ew, fabs(rd->w[j] - ro->w[j]) / wref);
  }
  if (diffs) { diffs[2] = ew; diffs[3] = same; }
  CHECK(same || diffs, "%s: the kept terms or their weights differ", tag);
  for (j = 0; same && j < rd->nd; ++j) {
    for (a = 0; a < r; ++a) e = fmax(e, fabs(sg[a] * rd->P0[j + (size_t)a * rd->nd] - ro->P0[j + (size_t)a * rd->nd]));
    for (a = 0; a < rn; ++a) e = fmax(e, fabs(sg2[a] * rd->P1[j + (size_t)a * rd->nd] - ro->P1[j + (size_t)a * rd->nd]));
  }
  CHECK(e <= btol, "%s: blocks/rows %.2e", tag, e);
  phgmg_reduced_restrict(red, x0, xr);
  for (j = 0; j < r; ++j) xd[j] = sg[j] * xr[j];
  {
    const double ey = online_diff(rd, ro, xd, xr, nsteps, tag);
    CHECK(ey <= ytol, "%s: reduced outputs against the serial model's: %.2e", tag, ey);
    if (diffs) { diffs[0] = e; diffs[1] = ey; }
    printf("  %s: basis %.1e, blocks %.1e, q_max %.1e, %d terms (weights %.1e), outputs (%d steps) %.1e\n", tag, eb,
           e, fabs(rd->q_max[0] - ro->q_max[0]) / ro->q_max[0], rd->nd, ew, nsteps, ey);
  }
  free(col);
}

/* Rank 0: the lift x = V0 xr + V2 M kron(x2, x2) of the distributed model
   (V0f, V2f gathered, mr->M) against the serial phgmg_reduced_lift at a
   few reduced states (the distributed one at the sign-adjusted xr: V2 M
   does not depend on V2's signs), relative to the lift's size. */
static void compare_lift(const phgmg_reduced *red, const phgmg_mpi_rom *mr, const double *V0f, const double *V2f,
                         int N, double tol, const char *tag) {
  const int r = mr->r, m = mr->m, p = r - m, rn = mr->rn;
  double sg[64], xr[64], xd[64], *col = (double *)malloc(sizeof(double) * 2 * (size_t)N), *x = col + N;
  double *q = (double *)malloc(sizeof(double) * (size_t)(rn > 0 ? rn : 1)), e = 0.0;
  int i, j, k, a, t;
  CHECK(rn > 0 && mr->M && (N == 0 || V2f), "%s: the lift's V2 and M not returned", tag);
  mode_signs(red, N, r, V0f, sg);
  for (t = 0; rn > 0 && t < 3; ++t) {
    double em = 0.0, cm = 0.0;
    for (j = 0; j < r; ++j) { xr[j] = 0.3 * sin(1.7 * (j + 1) * (t + 1)); xd[j] = sg[j] * xr[j]; }
    phgmg_reduced_lift(red, xr, col);
    for (a = 0; a < rn; ++a) {   /* q = M kron(x2, x2) at the distributed coordinates */
      q[a] = 0.0;
      for (j = 0; j < p; ++j)
        for (k = 0; k < p; ++k) q[a] += mr->M[a + (size_t)(j * p + k) * rn] * xd[m + j] * xd[m + k];
    }
    for (i = 0; i < N; ++i) {
      x[i] = 0.0;
      for (j = 0; j < r; ++j) x[i] += V0f[i + (size_t)j * N] * xd[j];
      for (a = 0; a < rn; ++a) x[i] += V2f[i + (size_t)a * N] * q[a];
      em = fmax(em, fabs(x[i] - col[i]));
      cm = fmax(cm, fabs(col[i]));
    }
    e = fmax(e, em / cm);
  }
  CHECK(e <= tol, "%s: the lift V0 xr + V2 M kron(x2, x2) against the serial one: %.2e", tag, e);
  printf("  %s: lift with V2 and M %.1e\n", tag, e);
  free(col); free(q);
}

/* Scale mode: how far the serial GMG-QM model itself moves when every
   snapshot entry changes by one unit in the last place (as
   serial_sensitivity): the blocks and outputs of compare_qm between the two
   serial models; the tolerances become max(default, 10 x these). Rank 0. */
static void qm_sensitivity(const chain *ch, int ns, const double *X, const double *x0, const phgmg_reduce_opts *o,
                           const phgmg_reduced *red, double *btol, double *ytol) {
  const int N = ch->N, r = o->r, m = 1, p = r - m;
  double *X2 = (double *)malloc(sizeof(double) * (size_t)N * ns), *V0f, xr[64], d[4] = {0.0, 0.0, 0.0, 1.0};
  phgmg_gidx *pc = NULL;
  const double *V2s = NULL, *Ms = NULL;
  unsigned long long st = 2463534242ull;
  phgmg_reduced *red2 = NULL;
  phgmg_mpi_rom fake;
  size_t i;
  int j, a, rn;
  for (i = 0; i < (size_t)N * ns; ++i) {
    st ^= st << 13; st ^= st >> 7; st ^= st << 17;
    X2[i] = X[i] * (1.0 + ((st >> 11) & 1 ? 1.0 : -1.0) * 2.220446049250313e-16);
  }
  CHECK(phgmg_reduce(&red2, &ch->sys, X2, N, ns, o, NULL, NULL) == PHGMG_OK, "serial GMG-QM, perturbed");
  free(X2);
  if (!red2) return;
  rn = phgmg_reduced_qm(red2, &V2s, &Ms);
  V0f = (double *)calloc((size_t)N * r, sizeof(double));
  for (j = 0; j < r; ++j) {   /* the perturbed model's V0 = lift(e_j) - V2 M (e_j kron e_j) */
    memset(xr, 0, sizeof xr); xr[j] = 1.0;
    phgmg_reduced_lift(red2, xr, V0f + (size_t)j * N);
    for (i = 0; j >= m && i < (size_t)N; ++i)
      for (a = 0; a < rn; ++a) V0f[i + (size_t)j * N] -= V2s[i + (size_t)a * N] * Ms[a + (size_t)((j - m) * p + (j - m)) * rn];
  }
  memset(&fake, 0, sizeof fake);
  fake.rom = *phgmg_reduced_rom(red2); fake.r = r; fake.m = m; fake.nd = fake.rom.nd;
  if (fake.nd > 0) {   /* the kept terms as the distributed result holds them */
    pc = (phgmg_gidx *)malloc(sizeof(phgmg_gidx) * 2 * (size_t)fake.nd);
    for (j = 0; j < fake.nd; ++j) {
      pc[j] = phgmg_reduced_terms(red2) ? phgmg_reduced_terms(red2)[j] : j;
      pc[fake.nd + j] = ch->idx[pc[j]];
    }
    fake.pts = pc; fake.coord = pc + fake.nd;
  }
  compare_qm(ch, x0, red, &fake, V0f, 100, HUGE_VAL, HUGE_VAL, d, "serial, perturbed");
  *btol = fmax(*btol, 10.0 * d[0]);
  if (d[1] < HUGE_VAL) *ytol = fmax(*ytol, 10.0 * d[1]);   /* a serial model that cannot be stepped sets no tolerance */
  if (fake.nd > 0) {
    printf("  serial, perturbed: %s points, weights moved by %.1e\n", d[3] != 0.0 ? "the same" : "OTHER", d[2]);
    wtol_ = fmax(1e-12, 10.0 * d[2]);
  }
  free(pc);
  free(V0f);
  phgmg_reduced_destroy(red2);
}

/* Distributed GMG-QM (r = 8, rn = 4, 3 on the linear chain; manifold POD
   and GREEDY) of the linear chain (no terms) and of the cosh chain (every
   term kept, and ECSW at hyper.tol 1e-3) against the serial phgmg_reduce
   with the same options; then unsupported options (the wide V2, ALTMIN, a
   chosen lambda) refused on every rank, bad input on one rank and a solve
   failing on one rank only. Scale mode (n masses): the linear chain, r =
   8, rn = 3, and with --scale-qm-cosh the cosh chain with ECSW (r = 8, rn
   = 4; stepped at 0.001: its reduced models are stiff), without the error
   cases. */
static void test_gmg_qm(int n, int r) {
  const int N = 2 * n, ns = 81;
  chain ch;
  dist d;
  double *X = (double *)malloc(sizeof(double) * (size_t)N * ns), *x0 = (double *)calloc((size_t)N, sizeof(double));
  double *V0 = NULL, *V0f, *V2f, *Vpod = NULL;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  phgmg_mpi_rom mr;
  phgmg_result rc;
  int i, lin, mf;
  for (lin = 1; lin >= (scale_ && !qm_cosh_ ? 1 : 0); --lin) {
    online_dt_ = scale_ && !lin ? 0.001 : 0.1;   /* the cosh chain's reduced models at scale are stiff: Newton needs 0.001 at N = 2e5 */
    chain_build(&ch, n, 0);
    if (lin) { ch.sys.nl = PHGMG_NL_NONE; ch.sys.nsep = 0; }
    for (i = 0; i < n; ++i) x0[2 * i] = 0.8 * sin(3.0 * 3.14159265358979 * i / n) + 0.3 * sin(7.0 * 3.14159265358979 * i / n);
    simulate_root(&ch.sys, x0, 0.2, ns, X);
    dist_build(&d, &ch, ns, X);
    if (lin) d.md.nsep = 0;
    V0 = (double *)malloc(sizeof(double) * (size_t)d.ld * r);
    /* the cosh chain: mf 2, 3 with ECSW, 4, 5 with greedy DEIM; at scale
       (--scale-qm-cosh) ECSW only: every term online would cost O(terms) */
    for (mf = scale_ && !lin ? 2 : 0; mf < (lin ? 2 : scale_ ? 4 : 6); ++mf) {
      char tag[64];
      snprintf(tag, sizeof tag, "gmg-qm %s, %s chain%s", mf % 2 ? "greedy" : "pod", lin ? "linear" : "cosh",
               mf > 3 ? ", deim" : mf > 1 ? ", ecsw" : "");
      memset(&o, 0, sizeof o);
      if (mf > 1) { o.hyper.on = 1; o.hyper.kind = PHGMG_HYPER_ECSW; o.hyper.tol = 1e-3; }
      if (mf > 3) { o.hyper.kind = PHGMG_HYPER_GREEDY; o.hyper.deim_tol = 1e-4; o.hyper.allow_negative = 1; }
      qm_deim_ = mf > 3;
      o.method = PHGMG_METHOD_GMG_QM; o.r = r; o.qm.rn = lin ? 3 : 4;   /* the linear chain's spectrum falls faster: V2's modes as well conditioned */
      o.qm.manifold = mf % 2 ? PHGMG_MANIFOLD_GREEDY : PHGMG_MANIFOLD_POD;
      rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, V0, d.ld);
      CHECK(rc == PHGMG_OK && same_everywhere(mr.nd), "distributed %s: %d", tag, (int)rc);
      V0f = gather_v0(d.c, r, V0, d.ld);
      V2f = rc == PHGMG_OK ? gather_v0(d.c, mr.rn, mr.V2, d.ld) : NULL;
      if (rank_ == 0 && rc == PHGMG_OK) {
        CHECK(phgmg_reduce(&red, &ch.sys, X, N, ns, &o, NULL, NULL) == PHGMG_OK, "serial %s", tag);
        double btol = 1e-12, ytol = 1e-10;
        if (red && scale_) qm_sensitivity(&ch, ns, X, x0, &o, red, &btol, &ytol);
        if (red) compare_qm(&ch, x0, red, &mr, V0f, 100, btol, ytol, NULL, tag);
        if (red && V2f) compare_lift(red, &mr, V0f, V2f, N, 100.0 * btol, tag);
        phgmg_reduced_destroy(red);
        red = NULL;
      }
      if (rank_ == 0 && mf == 1 && Vpod && rc == PHGMG_OK) {   /* the greedy's modes outside the POD's leading p */
        int j, k, out = 0;
        for (j = 1; j < r; ++j) {
          double best = 0.0;
          for (k = 1; k < r; ++k) {
            double dt = 0.0;
            for (i = 0; i < N; ++i) dt += V0f[i + (size_t)j * N] * Vpod[i + (size_t)k * N];
            best = fmax(best, fabs(dt));
          }
          out += best < 0.5;
        }
        printf("  %s: %d of the %d modes of V1 beyond the POD's leading ones\n", tag, out, r - 1);
        CHECK(lin || out > 0, "%s: the greedy took the leading modes (a weak test)", tag);
      }
      quiet_barrier();
      phgmg_mpi_rom_free(&mr);
      free(V2f);
      if (mf == 0) { free(Vpod); Vpod = V0f; } else free(V0f);
    }
    free(Vpod);
    Vpod = NULL;
    if (!scale_) {   /* lambda chosen by held-out regression (manual 4.2): the serial choice and model */
      phgmg_reduce_info inf;
      memset(&o, 0, sizeof o);
      o.method = PHGMG_METHOD_GMG_QM; o.r = r; o.qm.rn = lin ? 3 : 4;
      o.qm.manifold = lin ? PHGMG_MANIFOLD_POD : PHGMG_MANIFOLD_GREEDY;
      o.select.lambda_mode = PHGMG_LAMBDA_REGRESSION;
      if (!lin) { o.hyper.on = 1; o.hyper.kind = PHGMG_HYPER_ECSW; o.hyper.tol = 1e-3; }
      rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, V0, d.ld);
      CHECK(rc == PHGMG_OK && same_everywhere(mr.nd), "distributed gmg-qm, lambda by regression: %d", (int)rc);
      V0f = gather_v0(d.c, r, V0, d.ld);
      if (rank_ == 0 && rc == PHGMG_OK) {
        memset(&inf, 0, sizeof inf);
        CHECK(phgmg_reduce(&red, &ch.sys, X, N, ns, &o, &inf, NULL) == PHGMG_OK, "serial gmg-qm, lambda by regression");
        CHECK(mr.qm_lambda == inf.lambda, "lambda by regression: %.17g, serial %.17g", mr.qm_lambda, inf.lambda);
        printf("  gmg-qm %s chain, lambda by regression: %g (serial %g, raised %d)\n", lin ? "linear" : "cosh",
               mr.qm_lambda, inf.lambda, inf.lambda_raised);
        {   /* lambda 1e-12 (the linear chain) fits M at a condition that amplifies rounding: the
               tolerances from the serial model's own movement under one-ulp changes of X */
          double btol = 1e-12, ytol = 1e-10;
          if (red) qm_sensitivity(&ch, ns, X, x0, &o, red, &btol, &ytol);
          if (red) compare_qm(&ch, x0, red, &mr, V0f, 100, btol, ytol, NULL, lin ? "gmg-qm pod, lambda cv" : "gmg-qm greedy ecsw, lambda cv");
        }
        phgmg_reduced_destroy(red);
        red = NULL;
      }
      quiet_barrier();
      phgmg_mpi_rom_free(&mr);
      free(V0f);
    }
    if (!lin && !scale_) {   /* what the distributed GMG-QM does not take: refused everywhere */
      for (i = 0; i < 3; ++i) {
        memset(&o, 0, sizeof o);
        o.method = PHGMG_METHOD_GMG_QM; o.r = r; o.qm.rn = 6; o.qm.manifold = PHGMG_MANIFOLD_GREEDY;
        if (i == 0) o.qm.rn = 0;                                 /* greedy's default: the wide V2 */
        if (i == 1) o.qm.manifold = PHGMG_MANIFOLD_ALTMIN;
        if (i == 2) o.select.lambda_mode = PHGMG_LAMBDA_VALIDATED;   /* simulates: not distributed */
        memset(&mr, 1, sizeof mr);
        rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, NULL, 0);
        CHECK(rc == PHGMG_ERR_UNSUPPORTED && same_everywhere(rc) && mr.mem_ == NULL, "gmg-qm unsupported %d: %d", i, rc);
      }
      memset(&o, 0, sizeof o);   /* bad input on one rank: an rn beyond N - r there, the solve failing on another */
      o.method = PHGMG_METHOD_GMG_QM; o.r = r; o.qm.rn = 6;
      if (rank_ == 0) o.qm.rn = N;
      rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, NULL, 0);
      CHECK(rc == PHGMG_ERR_SIZE && same_everywhere(rc) && mr.mem_ == NULL, "gmg-qm rn beyond N - r on rank 0: %d", rc);
      o.qm.rn = 6;
      d.sv.fail_rank = size_ > 1 ? size_ - 1 : 0;
      rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, NULL, 0);
      CHECK(rc == PHGMG_ERR_SINGULAR && same_everywhere(rc) && mr.mem_ == NULL, "gmg-qm failing solve on one rank: %d", rc);
    }
    dist_free(&d);
    chain_free(&ch);
    free(V0);
  }
  online_dt_ = 0.1;
  qm_deim_ = 0;   /* compare_qm's weights: each to its own size again */
  free(X); free(x0);
}

/* Bad input on one rank only (a term outside its rows, ids not ascending,
   another function family, a NaN coefficient) and options this function
   does not take: the same code on every rank, never a hang, *out zeroed. */
static void test_errors(void) {
  const int n = 60, N = 2 * n, ns = 21, r = 4, bad = size_ > 1 ? size_ - 1 : 0;
  chain ch;
  dist d;
  double *X = (double *)malloc(sizeof(double) * (size_t)N * ns), *x0 = (double *)calloc((size_t)N, sizeof(double));
  phgmg_reduce_opts o;
  phgmg_mpi_rom mr;
  phgmg_result rc;
  int i, kase;
  chain_build(&ch, n, 0);
  for (i = 0; i < n; ++i) x0[2 * i] = 0.5 * sin(0.1 * i);
  simulate_root(&ch.sys, x0, 0.2, ns, X);
  dist_build(&d, &ch, ns, X);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = r; o.hyper.on = 1;
  rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, NULL, 0);
  CHECK(rc == PHGMG_OK && mr.nd > 0, "small model: %d", (int)rc);
  phgmg_mpi_rom_free(&mr);
  for (kase = 0; kase < 5; ++kase) {
    phgmg_mpi_sep_model md = d.md;
    phgmg_reduce_opts ob = o;
    long long sidx[2];
    double pn[2];
    phgmg_result want = PHGMG_ERR_SIZE;
    if (rank_ == bad && d.md.nsep >= 2) {
      if (kase == 0) { sidx[0] = d.c->row0 + d.c->nloc; md.sep_idx = sidx; md.nsep = 1; }   /* outside its rows */
      if (kase == 1) { sidx[0] = d.md.sep_id[1]; sidx[1] = d.md.sep_id[0]; md.sep_id = sidx; md.sep_idx = d.md.sep_idx; md.nsep = 2; }
      if (kase == 2) md.nexp = 1;                            /* another family than the other ranks' */
      if (kase == 3) { pn[0] = NAN; pn[1] = 0.0; md.poly = pn; md.nsep = 2; }
      if (kase == 4) { ob.method = PHGMG_METHOD_GMG_QM; ob.qm.manifold = PHGMG_MANIFOLD_ALTMIN; }   /* not distributed */
    }
    if (kase == 1 || kase == 2) want = PHGMG_ERR_INVALID_ARG;
    if (kase == 2 && size_ == 1) continue;   /* one rank: nothing to disagree with */
    if (kase == 3) want = PHGMG_ERR_NANINF;
    if (kase == 4) want = PHGMG_ERR_UNSUPPORTED;
    memset(&mr, 1, sizeof mr);
    rc = phgmg_mpi_reduce(d.c, &md, ns, d.Xl, d.ld, &ob, &mr, NULL, 0);
    CHECK(rc == want && same_everywhere(rc) && mr.mem_ == NULL && mr.nd == 0, "bad input %d on one rank: %d", kase, rc);
  }
  dist_free(&d);
  chain_free(&ch);
  free(X); free(x0);
}


/* Memory per rank falls as 1/P: the library's peak allocation (a counting
   allocator on the context) in phgmg_mpi_reduce (GMG-POD r = 12, ECSW, 24
   snapshots) of the chain of tests/mpi/mem_chain.h at N = 1e5 above its
   peak at N = 1e4, on P ranks against the same on rank 0 alone (MPI_COMM_SELF),
   divided by P: within 1.15 times. Every byte is freed again. */
static double mem_peak(MPI_Comm comm, long long N) {
  mem_count cnt = {0, 0};
  phgmg_allocator al;
  mem_chain c;
  phgmg_reduce_opts o;
  phgmg_mpi_rom mr;
  phgmg_result rc;
  double peak, out = 0.0;
  al.alloc = mem_count_alloc; al.free = mem_count_free; al.user = &cnt;
  rc = mem_chain_create(&c, comm, N, 24, &al);
  CHECK(rc == PHGMG_OK, "memory chain N = %lld: %d", N, (int)rc);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = 12; o.hyper.on = 1; o.hyper.kind = PHGMG_HYPER_ECSW; o.hyper.tol = 1e-2;
  if (rc == PHGMG_OK) {
    rc = phgmg_mpi_reduce(c.ctx, &c.md, 24, c.X, c.nloc > 0 ? c.nloc : 1, &o, &mr, NULL, 0);
    CHECK(rc == PHGMG_OK && mr.nd > 0, "memory chain N = %lld: reduce %d", N, (int)rc);
    phgmg_mpi_rom_free(&mr);
  }
  mem_chain_free(&c);
  CHECK(cnt.cur == 0, "memory chain N = %lld: %lu bytes not freed", N, (unsigned long)cnt.cur);
  peak = (double)cnt.peak;
  MPI_Allreduce(&peak, &out, 1, MPI_DOUBLE, MPI_MAX, comm);
  return out;
}

/* A descriptor model (manual 1.6): the chain with a mass matrix E (banded,
   symmetric positive definite): E(l_i, l_i) = 1 + 0.3 sin(i) on the
   positions (unit rows there: the terms' coordinates), a consistent-mass
   pattern on the velocities (2/3 on the diagonal, 1/6 between neighbours);
   E^T Q = E symmetric. GMG-POD r = 12 with ECSW against the serial
   phgmg_reduce of the same model; E (and E^{-1} through the user's solve)
   distributed. SP1 with E: PHGMG_ERR_UNSUPPORTED; a coupled row of E at a
   term's coordinate: PHGMG_ERR_E_COUPLED, on every rank. */
static solver esv_;
static phgmg_result solve_e_cb(char trans, int nrhs, double *X, int ldx, void *user) {
  (void)user;
  return solve_cb(trans, nrhs, X, ldx, &esv_);
}
static void test_descriptor(void) {
  const int n = 600, N = 2 * n, ns = 101, r = 12, kb = 3, ld = 2 * kb + 1;
  chain ch;
  dist d;
  double *X = (double *)malloc(sizeof(double) * (size_t)N * ns), *x0 = (double *)calloc((size_t)N, sizeof(double));
  double *E = (double *)calloc((size_t)ld * N, sizeof(double)), *V0, *V0f;
  phgmg_mpi_op *Eop;
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  phgmg_mpi_rom mr;
  phgmg_result rc;
  int i;
  chain_build(&ch, n, 0);
#define AT(A, r, s) (A)[(size_t)(kb + (r) - (s)) + (size_t)(s) * ld]
  for (i = 0; i < n; ++i) {
    const int l = 2 * i, v = 2 * i + 1;
    AT(E, l, l) = 1.0 + 0.3 * sin((double)i);
    AT(E, v, v) = 2.0 / 3.0;
    if (i + 1 < n) { AT(E, v, v + 2) = 1.0 / 6.0; AT(E, v + 2, v) = 1.0 / 6.0; }
  }
  ch.sys.E = E;
  for (i = 0; i < n; ++i) x0[2 * i] = 0.8 * sin(3.0 * 3.14159265358979 * i / n) + 0.3 * sin(7.0 * 3.14159265358979 * i / n);
  simulate_root(&ch.sys, x0, 0.2, ns, X);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = r; o.hyper.on = 1; o.hyper.kind = PHGMG_HYPER_ECSW; o.hyper.tol = 1e-3;
  dist_build(&d, &ch, ns, X);
  Eop = band_op_kb(d.c, ch.N, ch.kb, E, NULL, 0.0);
  esv_.c = d.c; esv_.fail_rank = -1;
  CHECK(phgmg_e_factor_create(&esv_.f, &ch.sys, NULL, NULL) == PHGMG_OK, "E factor");
  d.md.lin.E = Eop; d.md.lin.solve_E = solve_e_cb;
  V0 = (double *)malloc(sizeof(double) * (size_t)d.ld * r);
  rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, V0, d.ld);
  CHECK(rc == PHGMG_OK && same_everywhere(mr.nd) && mr.nd > 0, "distributed GMG-POD, mass matrix: %d", (int)rc);
  V0f = gather_v0(d.c, r, V0, d.ld);
  if (rank_ == 0 && rc == PHGMG_OK) {
    double ktol = 1e-12, ytol = 1e-10;
    CHECK(phgmg_reduce(&red, &ch.sys, X, N, ns, &o, NULL, NULL) == PHGMG_OK, "serial reduce, mass matrix");
    /* K = G00^{-1}: the serial model's own movement under one-ulp changes of
       the snapshots sets its tolerance (as at scale) */
    if (red) serial_sensitivity(&ch, ns, X, x0, &o, red, &ktol, &ytol);
    if (red) compare_serial(&ch, ns, X, x0, red, &mr, V0f, 200, ktol, ytol, "gmg-pod ecsw, mass matrix");
    phgmg_reduced_destroy(red);
  }
  quiet_barrier();
  phgmg_mpi_rom_free(&mr);
  o.method = PHGMG_METHOD_SP1;
  rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, NULL, 0);
  CHECK(rc == PHGMG_ERR_UNSUPPORTED && same_everywhere(rc), "sp1 with a mass matrix: %d", (int)rc);
  o.method = PHGMG_METHOD_GMG_POD;
  phgmg_mpi_op_destroy(Eop);   /* a coupling at the last term's coordinate l_{n-1}, owned by one rank */
  AT(E, 2 * n - 2, 2 * n - 1) = 0.05; AT(E, 2 * n - 1, 2 * n - 2) = 0.05;
  Eop = band_op_kb(d.c, ch.N, ch.kb, E, NULL, 0.0);
  d.md.lin.E = Eop;
  rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, NULL, 0);
  CHECK(rc == PHGMG_ERR_E_COUPLED && same_everywhere(rc) && mr.mem_ == NULL, "coupled row of E: %d", (int)rc);
#undef AT
  phgmg_mpi_op_destroy(Eop);
  phgmg_jr_factor_destroy(esv_.f);
  dist_free(&d);
  chain_free(&ch);
  free(E); free(X); free(x0); free(V0); free(V0f);
}

/* An index-one descriptor model (manual 1.8): the chain with a diagonal
   mass E(l_i, l_i) = 1 + 0.3 sin(i) on the positions and a consistent-mass
   pattern on the velocities (2/3 + 0.1 sin(2i) on the diagonal, 1/6
   between neighbours), except that every fifth velocity v_i (i = 3 mod 5)
   is massless: a zero row and column of E, an algebraic line (its damping
   0.3 makes L_aa = -0.3 I: index one). The lines' equations couple
   neighbouring positions, and E's neighbour entries cross the ranks' row
   blocks. The distributed GMG-POD with ECSW (E and E_dd^{-1} through the
   user's solve) against the serial reduction of the condensed model
   (phgmg_dae_create, snapshots restricted, phgmg_reduce): the basis's rows
   at the algebraic variables exactly zero, K, Qh, Bh, the points, weights
   and outputs as compare_serial. A port on an algebraic equation:
   PHGMG_ERR_UNSUPPORTED; a zero row of E whose column is not zero:
   PHGMG_ERR_E_SINGULAR; on every rank. */
static void test_algebraic(void) {
  const int n = 600, N = 2 * n, ns = 101, r = 12, kb = 3, ld = 2 * kb + 1;
  chain ch, chd;
  dist d;
  double *X = (double *)malloc(sizeof(double) * (size_t)N * ns), *x0 = (double *)calloc((size_t)N, sizeof(double));
  double *E = (double *)calloc((size_t)ld * N, sizeof(double)), *Ef = (double *)calloc((size_t)ld * N, sizeof(double));
  double *V0, *V0f;
  phgmg_mpi_op *Eop;
  phgmg_ph_system sf;
  phgmg_reduce_opts o;
  phgmg_mpi_rom mr;
  phgmg_result rc;
  int i, nalg = 0;
  chain_build(&ch, n, 0);
#define AT(A, r, s) (A)[(size_t)(kb + (r) - (s)) + (size_t)(s) * ld]
#define ALG(i) ((i) % 5 == 3)
  for (i = 0; i < n; ++i) {
    const int l = 2 * i, v = 2 * i + 1;
    AT(E, l, l) = 1.0 + 0.3 * sin((double)i);
    if (ALG(i)) { ++nalg; continue; }
    AT(E, v, v) = 2.0 / 3.0 + 0.1 * sin(2.0 * i);
    if (i + 1 < n && !ALG(i + 1)) { AT(E, v, v + 2) = 1.0 / 6.0; AT(E, v + 2, v) = 1.0 / 6.0; }
  }
  memcpy(Ef, E, sizeof(double) * (size_t)ld * N);   /* E_dd's solve: 1 on the algebraic lines' diagonal */
  for (i = 0; i < n; ++i)
    if (ALG(i)) AT(Ef, 2 * i + 1, 2 * i + 1) = 1.0;
  ch.sys.E = E;
  for (i = 0; i < n; ++i) x0[2 * i] = 0.8 * sin(3.0 * 3.14159265358979 * i / n) + 0.3 * sin(7.0 * 3.14159265358979 * i / n);
  simulate_root(&ch.sys, x0, 0.2, ns, X);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = r; o.hyper.on = 1; o.hyper.kind = PHGMG_HYPER_ECSW; o.hyper.tol = 1e-3;
  dist_build(&d, &ch, ns, X);
  Eop = band_op_kb(d.c, ch.N, ch.kb, E, NULL, 0.0);
  sf = ch.sys; sf.E = Ef;
  esv_.c = d.c; esv_.fail_rank = -1;
  CHECK(phgmg_e_factor_create(&esv_.f, &sf, NULL, NULL) == PHGMG_OK, "E_dd factor");
  d.md.lin.E = Eop; d.md.lin.solve_E = solve_e_cb;
  V0 = (double *)malloc(sizeof(double) * (size_t)d.ld * r);
  rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, V0, d.ld);
  CHECK(rc == PHGMG_OK && same_everywhere(mr.nd) && mr.nd > 0, "distributed GMG-POD, index-one E: %d", (int)rc);
  V0f = gather_v0(d.c, r, V0, d.ld);
  if (rank_ == 0 && rc == PHGMG_OK) {
    phgmg_dae *dae = NULL;
    phgmg_reduced *red = NULL;
    int nd, j, zero = 1;
    double ktol = 1e-12, ytol = 1e-10, *Xd, *V0d, *x0d;
    CHECK(phgmg_dae_create(&dae, &ch.sys, 0.0, NULL) == PHGMG_OK && phgmg_dae_nalg(dae) == nalg, "serial condensation");
    nd = N - nalg;
    Xd = (double *)malloc(sizeof(double) * (size_t)nd * ns);
    V0d = (double *)malloc(sizeof(double) * (size_t)nd * r);
    x0d = (double *)malloc(sizeof(double) * (size_t)nd);
    for (j = 0; dae && j < ns; ++j) phgmg_dae_restrict(dae, X + (size_t)j * N, Xd + (size_t)j * nd);
    for (j = 0; dae && j < r; ++j) phgmg_dae_restrict(dae, V0f + (size_t)j * N, V0d + (size_t)j * nd);
    for (j = 0; j < r; ++j)
      for (i = 0; i < n; ++i) zero &= !ALG(i) || V0f[2 * i + 1 + (size_t)j * N] == 0.0;
    CHECK(zero, "index-one E: the basis's rows at the algebraic variables are not zero");
    if (dae) phgmg_dae_restrict(dae, x0, x0d);
    chd = ch; chd.N = nd;   /* the condensed model (idx: the terms' full coordinates, as mr.coord) */
    if (dae) chd.sys = *phgmg_dae_system(dae);
    CHECK(dae && phgmg_reduce(&red, &chd.sys, Xd, nd, ns, &o, NULL, NULL) == PHGMG_OK, "serial reduce, condensed");
    if (red) serial_sensitivity(&chd, ns, Xd, x0d, &o, red, &ktol, &ytol);
    if (red) compare_serial(&chd, ns, Xd, x0d, red, &mr, V0d, 200, ktol, ytol, "gmg-pod ecsw, index-one E");
    phgmg_reduced_destroy(red);
    phgmg_dae_destroy(dae);
    free(Xd); free(V0d); free(x0d);
  }
  quiet_barrier();
  phgmg_mpi_rom_free(&mr);
  {   /* a port on an algebraic equation (v_3's row, owned by one rank) */
    const long long at = 2 * 3 + 1;
    double keep = 0.0;
    if (at >= d.c->row0 && at < d.c->row0 + d.c->nloc) { keep = d.Bl[at - d.c->row0]; d.Bl[at - d.c->row0] = 0.5; }
    rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, NULL, 0);
    CHECK(rc == PHGMG_ERR_UNSUPPORTED && same_everywhere(rc) && mr.mem_ == NULL, "port on a constraint: %d", (int)rc);
    if (at >= d.c->row0 && at < d.c->row0 + d.c->nloc) d.Bl[at - d.c->row0] = keep;
  }
  phgmg_mpi_op_destroy(Eop);   /* E(v_4, v_3) != 0: v_3's row zero, its column not */
  AT(E, 2 * 4 + 1, 2 * 3 + 1) = 0.05;
  Eop = band_op_kb(d.c, ch.N, ch.kb, E, NULL, 0.0);
  d.md.lin.E = Eop;
  rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, NULL, 0);
  CHECK(rc == PHGMG_ERR_E_SINGULAR && same_everywhere(rc) && mr.mem_ == NULL, "zero row, nonzero column: %d", (int)rc);
#undef ALG
#undef AT
  phgmg_mpi_op_destroy(Eop);
  phgmg_jr_factor_destroy(esv_.f);
  dist_free(&d);
  chain_free(&ch);
  free(E); free(Ef); free(X); free(x0); free(V0); free(V0f);
}

static void test_memory(void) {
  const long long N = 100000, NB = 10000;
  double one[2] = {0.0, 0.0}, gp, g1, t0 = MPI_Wtime();
  if (size_ == 1) return;   /* the comparison needs P > 1 */
  if (rank_ == 0) { one[0] = mem_peak(MPI_COMM_SELF, N); one[1] = mem_peak(MPI_COMM_SELF, NB); }
  quiet_barrier();
  MPI_Bcast(one, 2, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  gp = mem_peak(MPI_COMM_WORLD, N) - mem_peak(MPI_COMM_WORLD, NB);
  g1 = one[0] - one[1];
  CHECK(g1 > 0.0 && gp <= 1.15 * g1 / size_, "library memory per rank above the baseline %.3g B, one rank's / P %.3g B",
        gp, g1 / size_);
  if (rank_ == 0) printf("  memory: library peak per rank above N = %lld's, N = %lld: %.1f MB, one rank's / P %.1f MB (%.3f; %.2f s)\n",
                         NB, N, gp / 1048576.0, g1 / size_ / 1048576.0, gp / (g1 / size_), MPI_Wtime() - t0);
}

int main(int argc, char **argv) {
  int total = 0;
  double t0;
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  if (argc > 2 && (!strcmp(argv[argc - 2], "--scale") || !strcmp(argv[argc - 2], "--scale-qm") ||
                   !strcmp(argv[argc - 2], "--scale-qm-cosh"))) {
    qm_cosh_ = !strcmp(argv[argc - 2], "--scale-qm-cosh");
    qm_only_ = qm_cosh_ || !strcmp(argv[argc - 2], "--scale-qm");
    scale_ = atoi(argv[argc - 1]);
    argc -= 2;
  }
  dir_ = argc > 1 ? argv[1] : NULL;
  t0 = MPI_Wtime();
  if (rank_ == 0) printf("test_mpi_nl: P = %d\n", size_);
  if (scale_ > 0) {
    if (!qm_only_) test_gmg_pod_ecsw(scale_, 20);
    test_gmg_qm(scale_, 8);
  }
  else {
    test_gmg_pod_ecsw(1000, 12);
    test_screened();
    test_gmg_qm(300, 8);
    test_descriptor();
    test_algebraic();
    test_errors();
    test_memory();
  }
  MPI_Allreduce(&fails_, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (rank_ == 0)
    printf("test_mpi_nl: P = %d: %s (%d failed checks, %.2f s)\n", size_, total ? "FAILED" : "passed", total,
           MPI_Wtime() - t0);
  MPI_Finalize();
  return total ? 1 : 0;
}
