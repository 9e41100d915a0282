/* transport_line -- a travelling pulse in port-Hamiltonian form: a lossy
   transmission line (telegrapher's equations) on a staggered grid, driven by
   a current pulse at its open end and terminated by its characteristic
   conductance at the other, so that the pulse runs through the line and is
   absorbed. Transport is where quadratic manifolds matter (a moving pulse is
   far from any low-dimensional linear space); this program compares GMG-POD
   with GMG-QM on every manifold construction over the reduced order r.

   Model (per unit length L = C = 1, wave speed 1, impedance Z0 = 1; line
   length 1, n cells of width h = 1/n; N = 2n states, interleaved):
     x = (Q_1, Phi_1, Q_2, Phi_2, ...), Q_i the charge of cell i, Phi_i the
     flux linkage of the segment between nodes i and i + 1;
     H = sum_i (Q_i^2 / (2 C h) + Phi_i^2 / (2 L h)), grad H = (V_i, I_i);
     Q_i' = I_{i-1} - I_i (+ u at i = 1),  Phi_i' = V_i - V_{i+1} - rs h I_i,
     the last node shunted by G = 1 / Z0 (the matched termination):
       J: J(Q_i, Phi_i) = -1, J(Q_{i+1}, Phi_i) = +1 (and -J^T);
       R = diag(rs h on Phi_i; G on Q_n), B = e_{Q_1}, y = V_1.
     rs = 0.2 (series loss), n = 300 (N = 600), banded storage (half-bandwidth
     1: the interleaved states couple only neighbours).
   Inputs (current at node 1): training u(t) = exp(-((t - 0.15)/0.04)^2), one
     pulse of 0.04 time units = 12 cells; delayed: the same pulse 0.2 later
     (its states are the training states delayed: on the training manifold);
     test (unseen) u(t) = 0.7 exp(-((t - 0.1)/0.03)^2) - 0.5
     exp(-((t - 0.45)/0.06)^2) (other widths, heights and signs: states off
     the training manifold). t in (0, 1.4],
     dt = 0.004 (350 steps), from rest: the pulse crosses the line in one time
     unit and leaves through the termination.
   Methods, r = 6..30 step 6 (r includes the port coordinate):
     GMG-POD; GMG-QM with the hierarchical POD manifold (r_n = 8, the
     paper's), the greedy manifold (wide V2, candidates the leading
     r - 1 + 100 POD modes) and alternating minimization (wide V2, from the
     POD manifold), each with lambda validated by simulation
     (select.lambda_mode = PHGMG_LAMBDA_VALIDATED: the training run and
     three probes; M = 0 when no lambda is safe:
     reported as lambda = inf); and the hierarchical POD manifold with the
     snapshots' mean as affine reference state (manual 3.6).
   Measured: e_proj (training snapshots), e_red and e_y (training run), e_y
     on the delayed pulse and on the test input, the largest energy-balance error of the reduced
     training run relative to the energy scale, the lambda kept.
   Output: <out>/transport_errors.csv and a table on the terminal;
   tests/check_transport.py checks what examples/README.md claims from it.
   make demo runs r = 6, 12 (about 6 s); the table in examples/README.md
   is of r = 6..30 (about two minutes: V2 grows to 248 columns, the
   alternating minimization takes 200 descent steps at each r).
   Options: --n N (cells, 300), --rmin/--rmax/--rstep (6, 30, 6), --out DIR. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"

#define TL_T 1.4
#define TL_DT 0.004
#define TL_STEPS 350
#define TL_RS 0.2
#define TL_WINDOW 100 /* the greedy manifold's candidates: the leading r - 1 + 100 POD modes */

static void u_train(double t, double *u, void *user) {
  (void)user;
  u[0] = exp(-((t - 0.15) / 0.04) * ((t - 0.15) / 0.04));
}
/* the training pulse 0.2 time units later: its states are the training
   states delayed, on the training manifold */
static void u_delay(double t, double *u, void *user) {
  u_train(t - 0.2, u, user);
}
static void u_test(double t, double *u, void *user) {
  (void)user;
  u[0] = 0.7 * exp(-((t - 0.1) / 0.03) * ((t - 0.1) / 0.03)) - 0.5 * exp(-((t - 0.45) / 0.06) * ((t - 0.45) / 0.06));
}

typedef struct line {
  int n, N;
  double *J, *R, *Q, *B;
  phgmg_ph_system sys;
} line;

/* element (i, j), |i - j| <= 1, of a 3 x N band (half-bandwidth 1) */
#define BAND(i, j) ((size_t)(1 + (i) - (j)) + (size_t)(j) * 3)

static int line_build(line *L, int n) {
  const int N = 2 * n;
  const double h = 1.0 / n;
  int i;
  L->n = n; L->N = N;
  L->J = (double *)calloc((size_t)3 * N, sizeof(double));
  L->R = (double *)calloc((size_t)3 * N, sizeof(double));
  L->Q = (double *)calloc((size_t)3 * N, sizeof(double));
  L->B = (double *)calloc((size_t)N, sizeof(double));
  if (!L->J || !L->R || !L->Q || !L->B) return 1;
  for (i = 0; i < n; ++i) {
    const int q = 2 * i, f = 2 * i + 1;
    L->Q[BAND(q, q)] = 1.0 / h;   /* V = Q / (C h) */
    L->Q[BAND(f, f)] = 1.0 / h;   /* I = Phi / (L h) */
    L->J[BAND(q, f)] = -1.0; L->J[BAND(f, q)] = 1.0;
    if (i + 1 < n) { L->J[BAND(q + 2, f)] = 1.0; L->J[BAND(f, q + 2)] = -1.0; }
    L->R[BAND(f, f)] = TL_RS * h;
  }
  L->R[BAND(N - 2, N - 2)] = 1.0;   /* G = 1 / Z0 at the last node */
  L->B[0] = 1.0;
  memset(&L->sys, 0, sizeof L->sys);
  L->sys.N = N; L->sys.m = 1; L->sys.storage = PHGMG_BANDED; L->sys.kb = 1;
  L->sys.J = L->J; L->sys.R = L->R; L->sys.Q = L->Q; L->sys.B = L->B;
  return 0;
}

/* one row of the study */
typedef struct row {
  int r, rc;
  double e_proj, e_red, e_y, e_y_delay, e_y_test, energy, lambda;
  int rn;
} row;

#define NM 5
static const char *mname[NM] = {"GMG-POD", "GMG-QM-pod", "GMG-QM-greedy", "GMG-QM-altmin", "GMG-QM-pod-mean"};

/* The largest |H_n - H_0 - S_n + D_n| over the run, relative to the energy scale. */
static double energy_rel(const phgmg_energy *en, int ns) {
  double e = 0.0, sc = 0.0;
  int k;
  for (k = 0; k < ns; ++k) {
    e = fmax(e, fabs(en->H[k] - en->H[0] - en->S[k] + en->D[k]));
    sc = fmax(sc, fabs(en->S[k]) + fabs(en->D[k]) + fabs(en->H[k]));
  }
  return sc > 0.0 ? e / sc : e;
}

static row study_one(const line *L, int meth, int r, const double *X, const double *Y, const double *Yt,
                     double *XR, double *Yr, double *work) {
  const int N = L->N, ns = TL_STEPS + 1;
  phgmg_reduce_opts o;
  phgmg_reduce_info inf;
  phgmg_reduced *red = NULL;
  phgmg_run run;
  phgmg_energy en;
  double zero[1] = {0}, *xr0 = work, *H = work + r + 1, *S = H + ns, *D = S + ns;
  row w;
  (void)zero;
  memset(&w, 0, sizeof w);
  w.r = r; w.lambda = 0.0;
  memset(&run, 0, sizeof run);
  run.u = u_train; run.dt = TL_DT; run.nsteps = TL_STEPS;
  memset(&o, 0, sizeof o);
  o.r = r;
  o.method = meth == 0 ? PHGMG_METHOD_GMG_POD : PHGMG_METHOD_GMG_QM;
  if (meth > 0) {
    o.qm.manifold = meth == 1 || meth == 4 ? PHGMG_MANIFOLD_POD : meth == 3 ? PHGMG_MANIFOLD_ALTMIN : PHGMG_MANIFOLD_GREEDY;
    o.select.lambda_mode = PHGMG_LAMBDA_VALIDATED; o.nrun = 1; o.runs = &run;
    if (meth == 4) o.ref = PHGMG_REF_MEAN;
    if (meth == 2) o.qm.greedy_window = TL_WINDOW;
  }
  w.rc = phgmg_reduce(&red, &L->sys, X, N, ns, &o, &inf, NULL);
  if (w.rc != PHGMG_OK) return w;
  w.rn = phgmg_reduced_rom(red)->rn;
  w.lambda = meth > 0 ? inf.lambda : 0.0;
  w.e_proj = phgmg_err_proj(red, X, N, ns);
  phgmg_reduced_restrict(red, X, xr0);   /* x0 = 0: rho(0) */
  en.H = H; en.S = S; en.D = D;
  w.rc = phgmg_reduced_simulate(red, xr0, 0.0, TL_DT, TL_STEPS, u_train, NULL, 0.0, 20, XR, Yr, &en, NULL, NULL);
  if (w.rc == PHGMG_OK) {
    w.e_red = phgmg_err_red(red, X, N, ns, XR, r);
    w.e_y = phgmg_rel_error(1, ns, Y, 1, Yr, 1);
    w.energy = energy_rel(&en, ns);
    w.rc = phgmg_reduced_simulate(red, xr0, 0.0, TL_DT, TL_STEPS, u_delay, NULL, 0.0, 20, NULL, Yr, NULL, NULL, NULL);
    if (w.rc == PHGMG_OK) w.e_y_delay = phgmg_rel_error(1, ns, Yt + ns, 1, Yr, 1);
    if (w.rc == PHGMG_OK)
      w.rc = phgmg_reduced_simulate(red, xr0, 0.0, TL_DT, TL_STEPS, u_test, NULL, 0.0, 20, NULL, Yr, NULL, NULL, NULL);
    if (w.rc == PHGMG_OK) w.e_y_test = phgmg_rel_error(1, ns, Yt, 1, Yr, 1);
  }
  phgmg_reduced_destroy(red);
  return w;
}

int main(int argc, char **argv) {
  int n = 300, rmin = 6, rmax = 30, rstep = 6, i, r, m, nr;
  const char *out = "results";
  char path[1024];
  line L;
  double *X, *Y, *Yt, *XR, *Yr, *work, *x0;
  row *rows;
  FILE *f;
  for (i = 1; i < argc; ++i) {
    if (!strcmp(argv[i], "--n") && i + 1 < argc) n = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--rmin") && i + 1 < argc) rmin = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--rmax") && i + 1 < argc) rmax = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--rstep") && i + 1 < argc) rstep = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
    else {
      fprintf(stderr, "usage: %s [--n N] [--rmin R] [--rmax R] [--rstep S] [--out DIR]\n", argv[0]);
      return 2;
    }
  }
  if (n < 20 || n > 500 || rmin < 2 || rmax < rmin || rstep < 1 || rmax > 60) {
    fprintf(stderr, "transport_line: need 20 <= n <= 500, 2 <= rmin <= rmax <= 60, rstep >= 1\n");
    return 2;
  }
  if (line_build(&L, n)) return 1;
  nr = (rmax - rmin) / rstep + 1;
  X = (double *)malloc(sizeof(double) * (size_t)L.N * (TL_STEPS + 1));
  Y = (double *)malloc(sizeof(double) * 5 * (TL_STEPS + 1));
  XR = (double *)malloc(sizeof(double) * 64 * (TL_STEPS + 1));
  work = (double *)malloc(sizeof(double) * (64 + 4 * (TL_STEPS + 1)));
  x0 = (double *)calloc((size_t)L.N, sizeof(double));
  rows = (row *)calloc((size_t)nr * NM, sizeof(row));
  if (!X || !Y || !XR || !work || !x0 || !rows) return 1;
  Yt = Y + (TL_STEPS + 1); Yr = Yt + 2 * (TL_STEPS + 1);   /* Yt: the test, then the delayed pulse */
  if (phgmg_simulate(&L.sys, x0, 0.0, TL_DT, TL_STEPS, u_train, NULL, NULL, X, Y, NULL, NULL, NULL, NULL) != PHGMG_OK ||
      phgmg_simulate(&L.sys, x0, 0.0, TL_DT, TL_STEPS, u_test, NULL, NULL, NULL, Yt, NULL, NULL, NULL, NULL) != PHGMG_OK ||
      phgmg_simulate(&L.sys, x0, 0.0, TL_DT, TL_STEPS, u_delay, NULL, NULL, NULL, Yt + TL_STEPS + 1, NULL, NULL, NULL,
                     NULL) != PHGMG_OK) {
    fprintf(stderr, "transport_line: the full model failed\n");
    return 1;
  }
  printf("transmission line, N = %d, %d steps of %g, pulse through the line and out (matched end)\n", L.N, TL_STEPS, TL_DT);
  printf("%-19s %3s %4s %10s %10s %10s %10s %10s %9s %9s\n", "method", "r", "rn", "e_proj", "e_red", "e_y", "e_y_delay",
         "e_y_test", "energy", "lambda");
  for (m = 0; m < NM; ++m)
    for (i = 0; i < nr; ++i) {
      row *w;
      r = rmin + i * rstep;
      w = &rows[m * nr + i];
      *w = study_one(&L, m, r, X, Y, Yt, XR, Yr, work);
      if (w->rc != PHGMG_OK)
        printf("%-19s %3d  failed: %s\n", mname[m], r, phgmg_result_string((phgmg_result)w->rc));
      else
        printf("%-19s %3d %4d %10.3e %10.3e %10.3e %10.3e %10.3e %9.1e %9.1e\n", mname[m], r, w->rn, w->e_proj, w->e_red,
               w->e_y, w->e_y_delay, w->e_y_test, w->energy, w->lambda);
    }
  snprintf(path, sizeof path, "%s/transport_errors.csv", out);
  f = fopen(path, "w");
  if (!f) { fprintf(stderr, "transport_line: cannot write %s\n", path); return 1; }
  fprintf(f, "method,r,rn,rc,e_proj,e_red,e_y,e_y_delay,e_y_test,energy,lambda\n");
  for (m = 0; m < NM; ++m)
    for (i = 0; i < nr; ++i) {
      const row *w = &rows[m * nr + i];
      fprintf(f, "%s,%d,%d,%d,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e\n", mname[m], w->r, w->rn, w->rc, w->e_proj, w->e_red,
              w->e_y, w->e_y_delay, w->e_y_test, w->energy, w->lambda);
    }
  fclose(f);
  printf("wrote %s\n", path);
  free(X); free(Y); free(XR); free(work); free(x0); free(rows);
  free(L.J); free(L.R); free(L.Q); free(L.B);
  return 0;
}
