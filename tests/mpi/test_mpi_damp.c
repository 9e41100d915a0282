/* The distributed reduction of a model with nonlinear dampers
   (phgmg_mpi_reduce, manual 1.7 and 2.7) against the serial phgmg_reduce
   of the same model, at any number of ranks: mpirun -np P
   build/test_mpi_damp. Layouts: P = 2 and 3 uneven blocks, P = 4 with rank
   2 owning no rows. The model: a mass-spring chain with cubic dampers
   between neighbouring velocities (so that dampers cross every rank
   boundary, in both orientations, numbered in a scrambled order), a few
   one-sided dampers and a few cosh terms; snapshots from the serial
   simulation of the full model. GMG-POD, SP1 and SP2, with and without ECSW
   of the dampers: K, Qh, Bh, Cd, the kept dampers and their weights, and
   the reduced models' outputs against the serial ones, and with one law
   per damper (damp_per; the kept dampers' laws the serial rows) GMG-POD
   with ECSW; the one-sided
   dampers alone, given without damp_j and damp_id; the test catches a
   Cd that misses the cross-rank half of the dampers; the error codes of an
   energy-generating law, of dampers with GMG-QM and of duplicate damper
   numbers, alike on every rank; the number of collectives the dampers add,
   the same at two sizes N. Rank 0 runs the serial reductions and
   compares (the distributed results are replicated). Exit status 0 iff
   every check passed on every rank. Built against the library's one
   compile (PHGMG_IMPLEMENTATION_ELSEWHERE, make test-mpi). */
#define _POSIX_C_SOURCE 199309L   /* nanosleep */
#define PHGMG_MPI
#include "../../phgmg.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mpi_harness.h"

/* The rank that owns global row i. */
static int owner(const phgmg_mpi_ctx *c, long long i) {
  int q = 0;
  while (q + 1 < c->size && c->starts[q + 1] <= i) ++q;
  return q;
}



/* ---- the model ------------------------------------------------------------------ */
/* n masses, N = 2n, interleaved states (l_i, v_i) (banded, kb = 4): J = [0
   Tt; -Tt^T 0] (Tt: 1 on the diagonal, -1 above: the springs between
   neighbours), R = 0.02 on the velocities, Q = diag(k_i, 1 / m_i), B =
   e_{v_0}; cosh terms on every 25th l. Dampers, numbered in a scrambled
   order: number t < n - 1 between neighbouring velocities, c = e_{v_p} -
   e_{v_{p+1}}, p = 37 t mod (n - 1); number n - 1 + t (t < n - 2) between
   next neighbours the other way round, c = e_{v_{p+2}} - e_{v_p}, p = 37 t
   mod (n - 2) (so that at every rank boundary some dampers have their j on
   the next rank and some on the previous one); then one-sided dampers on
   v_7, v_57, ...; law rho(s) = 0.2 s + 3 s^3, or with per_law_ one law
   per damper, rho_k(s) = 0.2 (1 + 0.5 sin k) s + 3 (1 + 0.3 cos k) s^3
   (damp_nfun = nd; distributed: damp_per = 1). */
static int per_law_;
typedef struct chain {
  phgmg_ph_system sys;
  int n, N, kb, nd;
  double *J, *R, *Q, *B, *poly, *expo, *w, dpoly[4], *dlaw;
  int *idx, *di, *dj;
} chain;

#define AT(A, r, s) (A)[(size_t)(c->kb + (r) - (s)) + (size_t)(s) * (2 * c->kb + 1)]
static void chain_build(chain *c, int n) {
  const int N = 2 * n, kb = 4, ld = 2 * kb + 1, nt = (n + 24) / 25, nos = (n - 8) / 50 + 1;
  int i, t;
  memset(c, 0, sizeof *c);
  c->n = n; c->N = N; c->kb = kb; c->nd = 2 * n - 3 + nos;
  c->J = (double *)calloc((size_t)ld * N, sizeof(double));
  c->R = (double *)calloc((size_t)ld * N, sizeof(double));
  c->Q = (double *)calloc((size_t)ld * N, sizeof(double));
  c->B = (double *)calloc((size_t)N, sizeof(double));
  c->poly = (double *)malloc(sizeof(double) * (size_t)nt);
  c->expo = (double *)malloc(sizeof(double) * 4 * (size_t)nt);
  c->w = (double *)malloc(sizeof(double) * (size_t)nt);
  c->idx = (int *)malloc(sizeof(int) * (size_t)nt);
  c->di = (int *)malloc(sizeof(int) * (size_t)c->nd);
  c->dj = (int *)malloc(sizeof(int) * (size_t)c->nd);
  for (i = 0; i < n; ++i) {
    const int l = 2 * i, v = 2 * i + 1;
    AT(c->J, l, v) = 1.0; AT(c->J, v, l) = -1.0;
    if (i + 1 < n) { AT(c->J, l, v + 2) = -1.0; AT(c->J, v + 2, l) = 1.0; }
    AT(c->R, v, v) = 0.02;
    AT(c->Q, l, l) = 1.0 + 0.5 * cos(0.3 * i);
    AT(c->Q, v, v) = 1.0 / (1.0 + 0.3 * sin((double)i));
  }
  for (i = 0; i < nt; ++i) {
    const double a = 0.5 + 0.4 * sin((double)i);
    c->idx[i] = 2 * 25 * i;
    c->w[i] = 1.0;
    c->poly[i] = -a;
    c->expo[4 * i] = 0.5 * a; c->expo[4 * i + 1] = 1.0; c->expo[4 * i + 2] = 0.5 * a; c->expo[4 * i + 3] = -1.0;
  }
  for (t = 0; t < n - 1; ++t) {
    const int p = (int)((37LL * t) % (n - 1));
    c->di[t] = 2 * p + 1; c->dj[t] = 2 * p + 3;
  }
  for (t = 0; t < n - 2; ++t) {
    const int p = (int)((37LL * t) % (n - 2));
    c->di[n - 1 + t] = 2 * p + 5; c->dj[n - 1 + t] = 2 * p + 1;
  }
  for (t = 0; t < nos; ++t) { c->di[2 * n - 3 + t] = 2 * (7 + 50 * t) + 1; c->dj[2 * n - 3 + t] = -1; }
  c->dpoly[0] = 0.0; c->dpoly[1] = 0.2; c->dpoly[2] = 0.0; c->dpoly[3] = 3.0;
  c->B[1] = 1.0;
  c->sys.N = N; c->sys.m = 1; c->sys.storage = PHGMG_BANDED; c->sys.kb = kb;
  c->sys.J = c->J; c->sys.R = c->R; c->sys.Q = c->Q; c->sys.B = c->B;
  c->sys.nl = PHGMG_NL_SEPARABLE; c->sys.nsep = nt; c->sys.sep_idx = c->idx; c->sys.sep_w = c->w;
  c->sys.poly_deg = 0; c->sys.poly = c->poly; c->sys.nexp = 2; c->sys.expo = c->expo; c->sys.phi_nfun = nt;
  c->sys.ndamp = c->nd; c->sys.damp_i = c->di; c->sys.damp_j = c->dj;
  c->sys.damp_deg = 3; c->sys.damp_poly = c->dpoly;
  c->dlaw = (double *)malloc(sizeof(double) * 4 * (size_t)c->nd);
  for (t = 0; t < c->nd; ++t) {   /* one law per damper (used with per_law_) */
    c->dlaw[4 * t] = 0.0; c->dlaw[4 * t + 1] = 0.2 * (1.0 + 0.5 * sin((double)t));
    c->dlaw[4 * t + 2] = 0.0; c->dlaw[4 * t + 3] = 3.0 * (1.0 + 0.3 * cos((double)t));
  }
  if (per_law_) { c->sys.damp_poly = c->dlaw; c->sys.damp_nfun = c->nd; }
}

/* R + L (banded), L = rho'(0) sum_k c_k c_k^T: the user's solve is with J - (R + L). */
static double *chain_rl(const chain *c) {
  const int ld = 2 * c->kb + 1;
  double *Rl = (double *)malloc(sizeof(double) * (size_t)ld * c->N);
  int k;
  memcpy(Rl, c->R, sizeof(double) * (size_t)ld * c->N);
  for (k = 0; k < c->nd; ++k) {
    const int i = c->di[k], j = c->dj[k];
    const double c1 = per_law_ ? c->dlaw[4 * k + 1] : c->dpoly[1];
    AT(Rl, i, i) += c1;
    if (j >= 0) { AT(Rl, j, j) += c1; AT(Rl, i, j) -= c1; AT(Rl, j, i) -= c1; }
  }
  return Rl;
}
#undef AT

static void chain_free(chain *c) {
  free(c->J); free(c->R); free(c->Q); free(c->B); free(c->poly); free(c->expo); free(c->w); free(c->idx);
  free(c->di); free(c->dj); free(c->dlaw);
}



/* ---- the distributed inputs ------------------------------------------------------ */
typedef struct solver {
  const phgmg_mpi_ctx *c;
  phgmg_jr_factor *f;
} solver;

/* The user's solve: the right-hand sides gathered, the banded LU of
   J - R - L replicated. */
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
  return PHGMG_OK;
}

typedef struct dist {
  phgmg_mpi_ctx *c;
  phgmg_mpi_op *Q, *JR;
  phgmg_mpi_sep_model md;
  solver sv;
  double *Bl, *Xl, *pl, *el, *wl, *Rl, *dl;   /* dl: this rank's dampers' laws (per_law_) */
  long long *sidx, *sid, *di, *dj, *did;
  int ld;
} dist;


static void dist_build(dist *d, const chain *ch, int ns, const double *X) {
  const int N = ch->N;
  phgmg_ph_system sl;
  long long row0;
  int nloc, i, j, k, nt = 0, nd = 0;
  layout(N, &row0, &nloc);
  memset(d, 0, sizeof *d);
  CHECK(phgmg_mpi_ctx_create(&d->c, MPI_COMM_WORLD, N, row0, nloc, NULL) == PHGMG_OK, "ctx");
  d->ld = nloc > 0 ? nloc : 1;
  d->Q = band_op_kb(d->c, ch->N, ch->kb, ch->Q, NULL, 0.0);
  d->JR = band_op_kb(d->c, ch->N, ch->kb, ch->J, ch->R, 1.0);   /* J - R, without the dampers */
  d->Bl = (double *)malloc(sizeof(double) * (size_t)d->ld);
  d->Xl = (double *)malloc(sizeof(double) * (size_t)d->ld * ns);
  for (i = 0; i < nloc; ++i) d->Bl[i] = ch->B[row0 + i];
  for (j = 0; j < ns; ++j)
    for (i = 0; i < nloc; ++i) d->Xl[i + (size_t)j * d->ld] = X[row0 + i + (size_t)j * N];
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
  /* this rank's dampers: those whose i it owns, numbered as the serial model's (ascending) */
  d->di = (long long *)malloc(sizeof(long long) * ((size_t)ch->nd + 1));
  d->dj = (long long *)malloc(sizeof(long long) * ((size_t)ch->nd + 1));
  d->did = (long long *)malloc(sizeof(long long) * ((size_t)ch->nd + 1));
  d->dl = (double *)malloc(sizeof(double) * 4 * ((size_t)ch->nd + 1));
  for (k = 0; k < ch->nd; ++k)
    if (ch->di[k] >= row0 && ch->di[k] < row0 + nloc) {
      memcpy(d->dl + 4 * (size_t)nd, ch->dlaw + 4 * (size_t)k, 4 * sizeof(double));
      d->di[nd] = ch->di[k]; d->dj[nd] = ch->dj[k]; d->did[nd++] = k;
    }
  sl = ch->sys;   /* J - (R + L) for the user's solve */
  d->Rl = chain_rl(ch);
  sl.R = d->Rl; sl.ndamp = 0; sl.damp_i = NULL; sl.damp_j = NULL; sl.damp_poly = NULL;
  CHECK(phgmg_jr_factor_create(&d->sv.f, &sl, NULL, NULL) == PHGMG_OK, "J - R - L factor");
  d->sv.c = d->c;
  d->md.lin.Q = d->Q; d->md.lin.m = 1; d->md.lin.B = d->Bl; d->md.lin.ldb = d->ld;
  d->md.lin.solve = solve_cb; d->md.lin.solve_user = &d->sv; d->md.JR = d->JR;
  d->md.nsep = nt; d->md.sep_idx = d->sidx; d->md.sep_id = d->sid; d->md.sep_w = d->wl;
  d->md.poly_deg = 0; d->md.nexp = 2; d->md.per_term = 1; d->md.poly = d->pl; d->md.expo = d->el;
  d->md.ndamp = nd; d->md.damp_i = d->di; d->md.damp_j = d->dj; d->md.damp_id = d->did;
  d->md.damp_deg = 3; d->md.damp_poly = per_law_ ? d->dl : ch->dpoly; d->md.damp_per = per_law_;
}

static void dist_free(dist *d) {
  phgmg_jr_factor_destroy(d->sv.f);
  phgmg_mpi_op_destroy(d->Q);
  phgmg_mpi_op_destroy(d->JR);
  free(d->Bl); free(d->Xl); free(d->pl); free(d->el); free(d->wl); free(d->sidx); free(d->sid);
  free(d->di); free(d->dj); free(d->did); free(d->Rl); free(d->dl);
  phgmg_mpi_ctx_destroy(d->c);
}


/* Largest output difference of two reduced models stepped nsteps steps of
   0.1 from xa, xb under u_in, over the largest output (HUGE_VAL if a step fails). */
static double online_diff(const phgmg_rom *a, const phgmg_rom *b, const double *xa0, const double *xb0, int nsteps,
                          const char *tag) {
  static double m1[1 << 17], m2[1 << 17];
  phgmg_rom_stepper s1, s2;
  double u3[3], tc[3], y1 = 0.0, y2 = 0.0, ey = 0.0, sy = 0.0, xa[64], xb[64];
  int st, i, ok;
  memcpy(xa, xa0, sizeof(double) * (size_t)a->r);
  memcpy(xb, xb0, sizeof(double) * (size_t)b->r);
  CHECK(phgmg_rom_check(a) == PHGMG_OK, "%s: rom check", tag);
  ok = phgmg_rom_stepper_init(&s1, a, 0.1, 0.0, 0, m1, sizeof m1) == PHGMG_OK &&
       phgmg_rom_stepper_init(&s2, b, 0.1, 0.0, 0, m2, sizeof m2) == PHGMG_OK;
  CHECK(ok, "%s: steppers", tag);
  for (st = 0; ok && st < nsteps; ++st) {
    phgmg_result e1, e2;
    phgmg_rom_stage_times(0.1 * st, 0.1, tc);
    for (i = 0; i < 3; ++i) u_in(tc[i], u3 + i, NULL);
    e1 = phgmg_rom_step(&s1, xa, u3, &y1, NULL);
    e2 = phgmg_rom_step(&s2, xb, u3, &y2, NULL);
    if (e1 != PHGMG_OK || e2 != PHGMG_OK) return HUGE_VAL;
    ey = fmax(ey, fabs(y1 - y2)); sy = fmax(sy, fabs(y2));
  }
  return ok ? ey / sy : HUGE_VAL;
}



/* The control: Cd from the serial co-state test basis W (phgmg_reduced_W,
   E = I: W_z = W) matches the serial Cd, and the same with the j-half of
   every damper whose two ends lie on different ranks dropped (what a
   distributed Cd without the fetch of other ranks' rows would be) is
   further from the distributed Cd than the tolerance. Rank 0, P > 1. */
static void wrong_cd_control(const chain *ch, const dist *d, const phgmg_reduced *red, const phgmg_rom *ro,
                             const phgmg_mpi_rom *mr, const double *sg, const char *tag) {
  const int N = ch->N, r = ro->r, nd = ro->ndamp;
  double *W = (double *)malloc(sizeof(double) * (size_t)N * r), *Cr = (double *)malloc(sizeof(double) * (size_t)r * nd);
  double *Cw = (double *)malloc(sizeof(double) * (size_t)r * nd), xr[64] = {0}, one[64], er, ew;
  int k, a, cross = 0, fwd = 0;
  for (a = 0; a < r; ++a) one[a] = 1.0;
  CHECK(phgmg_reduced_W(red, xr, W, N) == PHGMG_OK, "%s: phgmg_reduced_W", tag);
  for (k = 0; k < nd; ++k) {
    const int t = ro->dterm ? ro->dterm[k] : k, i = ch->di[t], j = ch->dj[t];
    const int xs = j >= 0 && owner(d->c, i) != owner(d->c, j);
    cross += xs;
    fwd += xs && j > i;
    for (a = 0; a < r; ++a) {
      Cr[a + (size_t)k * r] = W[i + (size_t)a * N] - (j >= 0 ? W[j + (size_t)a * N] : 0.0);
      Cw[a + (size_t)k * r] = W[i + (size_t)a * N] - (j >= 0 && !xs ? W[j + (size_t)a * N] : 0.0);
    }
  }
  er = rel_diff(r, nd, Cr, ro->Cd, one, NULL);
  ew = rel_diff(r, nd, mr->rom.Cd, Cw, sg, NULL);
  CHECK(er <= 1e-10, "%s: Cd from phgmg_reduced_W against the serial Cd: %.2e", tag, er);
  CHECK(fwd > 0 && cross > fwd && ew > 1e-12, "%s: %d cross-rank dampers (%d with j on a later rank); a Cd without "
        "their j-half is off by %.2e", tag, cross, fwd, ew);
  printf("    control: %d dampers cross ranks (%d with j on a later rank); Cd without their j-half off by %.1e (serial "
         "W: %.1e)\n", cross, fwd, ew, er);
  free(W); free(Cr); free(Cw);
}

/* Rank 0: the distributed model against the serial one (tolerances 1e-12 on
   the blocks, the weights and Cd, 1e-10 on the outputs). idmap: the
   distributed number of each serial damper (NULL: the same). */
static void compare_serial(const chain *ch, const dist *d, const double *x0, const phgmg_reduced *red,
                           const phgmg_mpi_rom *mr, const double *V0f, const char *tag, int control,
                           const int *idmap) {
  const phgmg_rom *ro = phgmg_reduced_rom(red);
  const int r = mr->r, m = mr->m, nd = ro->ndamp;
  double sg[64], e[5] = {0.0, 0.0, 0.0, 0.0, 0.0}, xr[64], xd[64], sw = 0.0;
  int j, same = ro->ndamp == mr->rom.ndamp && mr->rom.dterm != NULL;
  mode_signs(red, ch->N, r, V0f, sg);
  e[0] = rel_diff(r, r, mr->K, ro->K, sg, sg);
  e[1] = rel_diff(r, r, mr->Qh, ro->Qh, sg, sg);
  e[2] = rel_diff(r, m, mr->Bh, ro->Bh, sg, NULL);
  CHECK(e[0] <= 1e-12 && e[1] <= 1e-12 && e[2] <= 1e-12, "%s: K %.2e, Qh %.2e, Bh %.2e", tag, e[0], e[1], e[2]);
  CHECK(same, "%s: %d dampers kept, serial %d", tag, mr->rom.ndamp, ro->ndamp);
  for (j = 0; same && j < nd; ++j) {
    const int t = ro->dterm ? ro->dterm[j] : j;
    same = mr->rom.dterm[j] == (idmap ? idmap[t] : t);
  }
  CHECK(same, "%s: the kept dampers differ", tag);
  if (same) {
    for (j = 0; j < nd; ++j) {
      e[3] = fmax(e[3], fabs((mr->rom.dw ? mr->rom.dw[j] : 1.0) - (ro->dw ? ro->dw[j] : 1.0)));
      sw = fmax(sw, fabs(ro->dw ? ro->dw[j] : 1.0));
    }
    e[3] /= sw;
    e[4] = rel_diff(r, nd, mr->rom.Cd, ro->Cd, sg, NULL);
    CHECK(e[3] <= 1e-12 && e[4] <= 1e-12, "%s: damper weights %.2e, Cd %.2e", tag, e[3], e[4]);
  }
  {   /* the laws: the serial model's (one row, or one per kept damper), exactly */
    const int nphi = ro->damp_nphi > 1 ? ro->damp_nphi : 1;
    int same_law = mr->rom.damp_deg == ro->damp_deg && (mr->rom.damp_nphi > 1 ? mr->rom.damp_nphi : 1) == nphi &&
                   mr->rom.dpoly != NULL;
    for (j = 0; same_law && j < nphi * (ro->damp_deg + 1); ++j) same_law = mr->rom.dpoly[j] == ro->dpoly[j];
    CHECK(same_law, "%s: the damper laws differ from the serial model's", tag);
  }
  phgmg_reduced_restrict(red, x0, xr);
  for (j = 0; j < r; ++j) xd[j] = sg[j] * xr[j];
  e[0] = fmax(e[0], fmax(e[1], e[2]));
  e[1] = online_diff(&mr->rom, ro, xd, xr, 200, tag);
  CHECK(e[1] <= 1e-10, "%s: reduced outputs against the serial model's: %.2e", tag, e[1]);
  printf("  %-16s K/Qh/Bh %.1e, %4d of %d dampers kept, weights %.1e, Cd %.1e, outputs (200 steps) %.1e\n", tag,
         e[0], nd, ch->nd, e[3], e[4], e[1]);
  if (control && size_ > 1) wrong_cd_control(ch, d, red, ro, mr, sg, tag);
}

/* GMG-POD, SP1 and SP2, with and without ECSW of the dampers. */
static void test_methods(int n, int r) {
  const int N = 2 * n, ns = 81;
  static const phgmg_method meth[3] = {PHGMG_METHOD_GMG_POD, PHGMG_METHOD_SP1, PHGMG_METHOD_SP2};
  static const char *name[3] = {"gmg-pod", "sp1", "sp2"};
  chain ch;
  dist d;
  double *X = (double *)malloc(sizeof(double) * (size_t)N * ns), *x0 = (double *)calloc((size_t)N, sizeof(double));
  double *V0, *V0f;
  int i, mi, hy;
  chain_build(&ch, n);
  for (i = 0; i < n; ++i) x0[2 * i] = 0.6 * sin(3.0 * 3.14159265358979 * i / n) + 0.3 * sin(7.0 * 3.14159265358979 * i / n);
  simulate_root(&ch.sys, x0, 0.2, ns, X);
  dist_build(&d, &ch, ns, X);
  V0 = (double *)malloc(sizeof(double) * (size_t)d.ld * r);
  for (mi = 0; mi < (per_law_ ? 1 : 3); ++mi)   /* one law per damper: GMG-POD with ECSW (rho_k'(0) in K, kept laws) */
    for (hy = per_law_; hy < 2; ++hy) {
      phgmg_reduce_opts o;
      phgmg_reduced *red = NULL;
      phgmg_mpi_rom mr;
      phgmg_result rc;
      char tag[64];
      snprintf(tag, sizeof tag, "%s%s%s", name[mi], hy ? " ecsw" : "", per_law_ ? ", a law per damper" : "");
      memset(&o, 0, sizeof o);
      o.method = meth[mi]; o.r = r; o.hyper.on = hy; o.hyper.kind = PHGMG_HYPER_ECSW; o.hyper.tol = 1e-3;
      rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, V0, d.ld);
      CHECK(rc == PHGMG_OK && same_everywhere(mr.rom.ndamp), "distributed %s: %d", tag, (int)rc);
      V0f = gather_v0(d.c, r, V0, d.ld);
      if (rank_ == 0 && rc == PHGMG_OK) {
        CHECK(phgmg_reduce(&red, &ch.sys, X, N, ns, &o, NULL, NULL) == PHGMG_OK, "serial %s", tag);
        if (red) compare_serial(&ch, &d, x0, red, &mr, V0f, tag, !hy && mi < 2, NULL);
        phgmg_reduced_destroy(red);
      }
      quiet_barrier();
      free(V0f);
      phgmg_mpi_rom_free(&mr);
    }
  free(V0); free(X); free(x0);
  dist_free(&d);
  chain_free(&ch);
}

/* One-sided dampers only, given with damp_j and damp_id NULL (the damper
   numbers are then the state indices): GMG-POD and SP1 with ECSW, against
   the serial model of the same dampers. */
static void test_one_sided(int n, int r) {
  const int N = 2 * n, ns = 61;
  chain ch;
  dist d;
  double *X = (double *)malloc(sizeof(double) * (size_t)N * ns), *x0 = (double *)calloc((size_t)N, sizeof(double));
  double *V0 = NULL, *V0f;
  int i, mi, off, nos;
  chain_build(&ch, n);
  off = 2 * n - 3; nos = ch.nd - off;
  memmove(ch.di, ch.di + off, sizeof(int) * (size_t)nos);
  memmove(ch.dj, ch.dj + off, sizeof(int) * (size_t)nos);
  ch.nd = ch.sys.ndamp = nos;
  for (i = 0; i < n; ++i) x0[2 * i] = 0.6 * sin(3.0 * 3.14159265358979 * i / n);
  simulate_root(&ch.sys, x0, 0.2, ns, X);
  dist_build(&d, &ch, ns, X);
  d.md.damp_j = NULL; d.md.damp_id = NULL;
  V0 = (double *)malloc(sizeof(double) * (size_t)d.ld * r);
  for (mi = 0; mi < 2; ++mi) {
    phgmg_reduce_opts o;
    phgmg_reduced *red = NULL;
    phgmg_mpi_rom mr;
    phgmg_result rc;
    const char *tag = mi ? "sp1 ecsw, e_i" : "gmg-pod ecsw, e_i";
    memset(&o, 0, sizeof o);
    o.method = mi ? PHGMG_METHOD_SP1 : PHGMG_METHOD_GMG_POD; o.r = r;
    o.hyper.on = 1; o.hyper.kind = PHGMG_HYPER_ECSW; o.hyper.tol = 1e-3;
    rc = phgmg_mpi_reduce(d.c, &d.md, ns, d.Xl, d.ld, &o, &mr, V0, d.ld);
    CHECK(rc == PHGMG_OK && same_everywhere(mr.rom.ndamp), "distributed %s: %d", tag, (int)rc);
    V0f = gather_v0(d.c, r, V0, d.ld);
    if (rank_ == 0 && rc == PHGMG_OK) {
      CHECK(phgmg_reduce(&red, &ch.sys, X, N, ns, &o, NULL, NULL) == PHGMG_OK, "serial %s", tag);
      if (red) compare_serial(&ch, &d, x0, red, &mr, V0f, tag, 0, ch.di);
      phgmg_reduced_destroy(red);
    }
    quiet_barrier();
    free(V0f);
    phgmg_mpi_rom_free(&mr);
  }
  free(V0); free(X); free(x0);
  dist_free(&d);
  chain_free(&ch);
}

/* The error codes, alike on every rank: an energy-generating law
   (PHGMG_ERR_DAMPER), dampers with GMG-QM (PHGMG_ERR_UNSUPPORTED), two
   dampers of a rank with the same i and no damp_id, and the same damper
   number on two ranks (PHGMG_ERR_INVALID_ARG). */
static void test_errors(int n) {
  const int N = 2 * n, ns = 41;
  chain ch;
  dist d;
  double *X = (double *)malloc(sizeof(double) * (size_t)N * ns), *x0 = (double *)calloc((size_t)N, sizeof(double));
  double bad[4] = {0.0, -0.2, 0.0, 3.0};
  long long di[2], dj[2] = {-1, -1}, did[2] = {0, 1};
  phgmg_reduce_opts o;
  phgmg_mpi_rom mr;
  phgmg_mpi_sep_model md;
  phgmg_result rc;
  int i;
  chain_build(&ch, n);
  for (i = 0; i < n; ++i) x0[2 * i] = 0.5 * sin(2.0 * 3.14159265358979 * i / n);
  simulate_root(&ch.sys, x0, 0.2, ns, X);
  dist_build(&d, &ch, ns, X);
  memset(&o, 0, sizeof o);
  o.method = PHGMG_METHOD_GMG_POD; o.r = 8;
  md = d.md; md.damp_poly = bad;
  rc = phgmg_mpi_reduce(d.c, &md, ns, d.Xl, d.ld, &o, &mr, NULL, 0);
  CHECK(rc == PHGMG_ERR_DAMPER && same_everywhere(rc), "energy-generating law: %d", (int)rc);
  md = d.md;
  o.method = PHGMG_METHOD_GMG_QM; o.qm.rn = 4; o.qm.manifold = PHGMG_MANIFOLD_POD;
  rc = phgmg_mpi_reduce(d.c, &md, ns, d.Xl, d.ld, &o, &mr, NULL, 0);
  CHECK(rc == PHGMG_ERR_UNSUPPORTED && same_everywhere(rc), "dampers with GMG-QM: %d", (int)rc);
  memset(&o.qm, 0, sizeof o.qm);
  o.method = PHGMG_METHOD_GMG_POD;
  md.ndamp = 0;   /* the rank owning row 1: two dampers on v_0, damp_id NULL */
  if (d.c->row0 <= 1 && 1 < d.c->row0 + d.c->nloc) {
    di[0] = di[1] = 1; dj[0] = 3;
    md.ndamp = 2; md.damp_i = di; md.damp_j = dj; md.damp_id = NULL;
  }
  rc = phgmg_mpi_reduce(d.c, &md, ns, d.Xl, d.ld, &o, &mr, NULL, 0);
  CHECK(rc == PHGMG_ERR_INVALID_ARG && same_everywhere(rc), "two dampers on the same i: %d", (int)rc);
  md = d.md;   /* every rank with rows: one-sided dampers numbered 0 and 1 */
  md.ndamp = d.c->nloc > 0 ? 2 : 0;
  di[0] = d.c->row0; di[1] = d.c->row0 + (d.c->nloc > 1 ? 1 : 0); dj[0] = dj[1] = -1;
  md.damp_i = di; md.damp_j = dj; md.damp_id = did;
  rc = phgmg_mpi_reduce(d.c, &md, ns, d.Xl, d.ld, &o, &mr, NULL, 0);
  CHECK(size_ == 1 ? rc == PHGMG_OK || rc == PHGMG_ERR_SIZE : rc == PHGMG_ERR_INVALID_ARG,
        "the same damper numbers on several ranks: %d", (int)rc);
  CHECK(same_everywhere(rc), "duplicate numbers: the codes differ between ranks");
  if (rc == PHGMG_OK) phgmg_mpi_rom_free(&mr);
  if (rank_ == 0) printf("  errors: energy-generating law, GMG-QM, duplicate dampers: the codes on every rank\n");
  free(X); free(x0);
  dist_free(&d);
  chain_free(&ch);
}

/* The dampers' communication: the collectives phgmg_mpi_reduce makes with
   the dampers less those it makes without them (GMG-POD and SP1, no
   hyper-reduction), for chains of n and 2 n masses: the same count (the
   rows of other ranks come in a fixed number of all-to-all exchanges,
   whatever N). */
static long long damper_collectives(int n, phgmg_method method) {
  const int N = 2 * n, ns = 31;
  chain ch;
  dist d;
  double *X = (double *)malloc(sizeof(double) * (size_t)N * ns), *x0 = (double *)calloc((size_t)N, sizeof(double));
  phgmg_reduce_opts o;
  phgmg_mpi_rom mr;
  phgmg_mpi_counts c[2];
  int i, pass;
  chain_build(&ch, n);
  for (i = 0; i < n; ++i) x0[2 * i] = 0.5 * sin(2.0 * 3.14159265358979 * i / n);
  simulate_root(&ch.sys, x0, 0.2, ns, X);
  dist_build(&d, &ch, ns, X);
  memset(&o, 0, sizeof o);
  o.method = method; o.r = 8;
  for (pass = 0; pass < 2; ++pass) {
    phgmg_mpi_sep_model md = d.md;
    if (pass) md.ndamp = 0;
    phgmg_mpi_counts_reset(d.c);
    CHECK(phgmg_mpi_reduce(d.c, &md, ns, d.Xl, d.ld, &o, &mr, NULL, 0) == PHGMG_OK, "counts: reduce, pass %d", pass);
    phgmg_mpi_counts_get(d.c, &c[pass]);
    phgmg_mpi_rom_free(&mr);
  }
  free(X); free(x0);
  dist_free(&d);
  chain_free(&ch);
  return c[0].collectives - c[1].collectives;
}

static void test_counts(void) {
  int mi;
  for (mi = 0; mi < 2; ++mi) {
    const phgmg_method me = mi ? PHGMG_METHOD_SP1 : PHGMG_METHOD_GMG_POD;
    const long long a = damper_collectives(100, me), b = damper_collectives(200, me);
    CHECK(a > 0 && a == b, "%s: the dampers' collectives %lld at N = 200, %lld at N = 400", mi ? "sp1" : "gmg-pod", a, b);
    if (rank_ == 0)
      printf("  counts: the dampers add %lld collectives to %s at N = 200 and %lld at N = 400\n", a,
             mi ? "sp1" : "gmg-pod", b);
  }
}

int main(int argc, char **argv) {
  int total = 0;
  double t0;
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  t0 = MPI_Wtime();
  if (rank_ == 0) printf("test_mpi_damp: P = %d\n", size_);
  test_methods(500, 10);
  per_law_ = 1;   /* the same with one law per damper */
  test_methods(500, 10);
  per_law_ = 0;
  test_one_sided(500, 10);
  test_errors(60);
  test_counts();
  MPI_Allreduce(&fails_, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (rank_ == 0)
    printf("test_mpi_damp: P = %d: %s (%d failed checks, %.2f s)\n", size_, total ? "FAILED" : "passed", total,
           MPI_Wtime() - t0);
  MPI_Finalize();
  return total ? 1 : 0;
}
