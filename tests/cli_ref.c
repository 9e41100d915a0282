/* cli_ref — the reference side of tests/test_cli.sh: computes with phgmg.h
   directly, along the library's own demo path (examples/msd_linear.c,
   examples/msd_nonlinear.c, examples/demo_common.h), what the `phgmg` command
   line must reproduce, and compares .npy files.

     cli_ref model DIR            the paper's linear MSD (50 masses, N = 100,
                                  examples/msd_models.h) as DIR/{J,R,B,Q}.npy
     cli_ref model-nl DIR n       the nonlinear MSD (n masses, dense, paper
                                  ordering [l, v]) as DIR/{J,R,B,Q,poly,idx}.npy
     cli_ref ref linear METHOD r OUT.npy
         FOM: phgmg_simulate, u = 0.1 sin t, dt = 0.1, 1000 steps, Newton
         1e-10 / 10; ROM: POD cache as msd_linear (kmax = 20 + 8 + 1),
         r_n = 8, lambda = 1e-3, step map for dt, then phgmg_reduce +
         phgmg_reduced_restrict(x0) + phgmg_reduced_simulate (Newton 1e-10 / 10)
         as demo_run_rom does; writes the ROM output y (1 x 1001) to OUT.npy
     cli_ref ref nonlinear METHOD r n OUT.npy
         the same for the nonlinear MSD with n masses as msd_nonlinear does it
         (Newton 1e-8 / 20, DEIM tol 1e-8 with negative weights allowed,
         cache with gradient POD), without a step map
     cli_ref csim OUT.npy         (only when built with -DCLI_REF_ROM_C='"DIR/NAME.c"'
                                  -DCLI_REF_ROM_NAME=NAME) simulate the model
         exported as C source by `phgmg reduce` (static const arrays, as
         firmware would), x0 = 0, u = 0.1 sin t, dt = 0.1, 1000 steps, with
         the online stepper in a static buffer; writes y (1 x 1001)
     cli_ref scale IN.npy OUT.npy C    OUT = C * IN (2-d), for the magnitude checks
     cli_ref compare A.npy B.npy TOL
         relative difference ||A - B||_F / ||A||_F (exit 1 if the shapes
         differ or it exceeds TOL; TOL = 0 asks for equality)
   Exit status: 0 ok, 1 failure (message on stderr), 2 bad usage.
   Build: cc -std=c99 -O2 tests/cli_ref.c -o build/cli_ref -lm */
#define _POSIX_C_SOURCE 200809L
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "../examples/msd_models.h"
#include "../examples/demo_common.h"

static int die(const char *what, phgmg_result rc) {
  fprintf(stderr, "cli_ref: %s: %s\n", what, phgmg_result_string(rc));
  return 1;
}

static int put(const char *dir, const char *name, const double *A, int rows, int cols) {
  char path[1024];
  phgmg_result rc;
  snprintf(path, sizeof path, "%s/%s.npy", dir, name);
  rc = phgmg_npy_write(path, A, rows, cols, rows, 2, 0u);
  return rc == PHGMG_OK ? 0 : die(path, rc);
}

static phgmg_method method_of(const char *s) {
  if (!strcmp(s, "gmg-pod")) return PHGMG_METHOD_GMG_POD;
  if (!strcmp(s, "gmg-qm")) return PHGMG_METHOD_GMG_QM;
  if (!strcmp(s, "sp1")) return PHGMG_METHOD_SP1;
  if (!strcmp(s, "sp2")) return PHGMG_METHOD_SP2;
  return (phgmg_method)0;
}

/* demo_run_rom's reduction and simulation, keeping the ROM output. */
static int run_rom(const phgmg_ph_system *sys, const double *X, int nsteps, double dt, phgmg_input_fn uf,
                   const phgmg_reduce_opts *o, double ntol, int nit, const char *out) {
  phgmg_reduced *red = NULL;
  const int N = sys->N, m = sys->m, ns = nsteps + 1;
  double *YR = (double *)malloc(sizeof(double) * (size_t)m * ns), *xr0 = (double *)malloc(sizeof(double) * o->r);
  phgmg_result rc;
  int st = 1;
  if (!YR || !xr0) { fprintf(stderr, "cli_ref: out of memory\n"); goto done; }
  rc = phgmg_reduce(&red, sys, X, N, ns, o, NULL, NULL);
  if (rc != PHGMG_OK) { die("phgmg_reduce", rc); goto done; }
  phgmg_reduced_restrict(red, X, xr0);
  rc = phgmg_reduced_simulate(red, xr0, 0.0, dt, nsteps, uf, NULL, ntol, nit, NULL, YR, NULL, NULL, NULL);
  if (rc != PHGMG_OK) { die("phgmg_reduced_simulate", rc); goto done; }
  rc = phgmg_npy_write(out, YR, m, ns, m, 2, 0u);
  if (rc != PHGMG_OK) { die(out, rc); goto done; }
  st = 0;
done:
  phgmg_reduced_destroy(red);
  free(YR); free(xr0);
  return st;
}

static int ref(int nonlinear, phgmg_method meth, int r, int n, const char *out) {
  const int nsteps = 1000, ns = nsteps + 1, rn = 8, kmax = 20 + rn + 1;
  const double dt = 0.1;
  msd_linear ML;
  msd_nonlinear MN;
  const phgmg_ph_system *sys;
  phgmg_gl3_opts go;
  phgmg_reduce_opts o;
  demo_cache cache;
  double *X, *x0;
  phgmg_result rc;
  int st;
  memset(&go, 0, sizeof go);
  memset(&o, 0, sizeof o);
  o.method = meth; o.r = r; o.qm.rn = rn;
  if (nonlinear) {
    msd_nl_opts mo;
    memset(&mo, 0, sizeof mo);
    mo.n = n; mo.storage = PHGMG_DENSE;
    if (msd_nonlinear_build(&MN, &mo) != 0) return die("msd_nonlinear_build", PHGMG_ERR_INVALID_ARG);
    sys = &MN.sys;
    go.tol = 1e-8; go.max_iter = 20;
    o.hyper.on = 1; o.hyper.deim_tol = 1e-8; o.hyper.allow_negative = 1;
    o.qm.lambda = 1e-3;
  } else {
    if (msd_linear_build(&ML, 50, NULL, NULL, NULL, PHGMG_DENSE) != 0)
      return die("msd_linear_build", PHGMG_ERR_INVALID_ARG);
    sys = &ML.sys;
    go.tol = 1e-10; go.max_iter = 10;
    o.qm.lambda = 1e-3; o.dt = dt;
  }
  X = (double *)malloc(sizeof(double) * (size_t)sys->N * ns);
  x0 = (double *)calloc((size_t)sys->N, sizeof(double));
  if (!X || !x0) return die("allocation", PHGMG_ERR_NOMEM);
  rc = phgmg_simulate(sys, x0, 0.0, dt, nsteps, msd_input_sin, NULL, &go, X, NULL, NULL, NULL, NULL, NULL);
  if (rc != PHGMG_OK) return die("full-order simulation", rc);
  demo_cache_build(&cache, sys, X, ns, kmax, nonlinear);
  demo_cache_use(&cache, &o);
  st = run_rom(sys, X, nsteps, dt, msd_input_sin, &o, nonlinear ? 1e-8 : 1e-10, nonlinear ? 20 : 10, out);
  demo_cache_free(&cache);
  free(X); free(x0);
  if (nonlinear) msd_nonlinear_free(&MN); else msd_linear_free(&ML);
  return st;
}

#ifdef CLI_REF_ROM_C
#include CLI_REF_ROM_C
static int csim(const char *out) {
  static double mem[1 << 16];
  const phgmg_rom *rom = &CLI_REF_ROM_NAME;
  phgmg_rom_stepper st;
  phgmg_real x[64], u3[3], y[1], work[4096];
  double Y[1001], tc[3];
  const double s15 = sqrt(15.0) / 10.0;
  int n, i;
  phgmg_result rc;
  if (rom->r > 64 || rom->m != 1 || phgmg_rom_eval_work_size(rom) > 4096) return die("csim sizes", PHGMG_ERR_SIZE);
  rc = phgmg_rom_stepper_init(&st, rom, 0.1, 1e-10, 10, mem, sizeof mem);
  if (rc != PHGMG_OK) return die("phgmg_rom_stepper_init", rc);
  for (i = 0; i < rom->r; ++i) x[i] = 0.0;
  phgmg_rom_output(rom, x, y, work);
  Y[0] = y[0];
  for (n = 0; n < 1000; ++n) {
    tc[0] = 0.5 - s15; tc[1] = 0.5; tc[2] = 0.5 + s15;
    for (i = 0; i < 3; ++i) msd_input_sin(n * 0.1 + tc[i] * 0.1, &u3[i], NULL);
    rc = phgmg_rom_step(&st, x, u3, NULL, NULL);
    if (rc != PHGMG_OK) return die("phgmg_rom_step", rc);
    phgmg_rom_output(rom, x, y, work);
    Y[n + 1] = y[0];
  }
  rc = phgmg_npy_write(out, Y, 1, 1001, 1, 2, 0u);
  return rc == PHGMG_OK ? 0 : die(out, rc);
}
#endif

static int compare(const char *a, const char *b, double tol) {
  double *A = NULL, *B = NULL, num = 0.0, den = 0.0, d;
  int ra, ca, rb, cb, st = 1;
  size_t i;
  phgmg_result rc = phgmg_npy_read(a, &A, &ra, &ca, NULL, NULL);
  if (rc != PHGMG_OK) return die(a, rc);
  rc = phgmg_npy_read(b, &B, &rb, &cb, NULL, NULL);
  if (rc != PHGMG_OK) { phgmg_npy_free(A, NULL); return die(b, rc); }
  if (ra != rb || ca != cb) {
    fprintf(stderr, "cli_ref: %s is %d x %d but %s is %d x %d\n", a, ra, ca, b, rb, cb);
    goto done;
  }
  for (i = 0; i < (size_t)ra * ca; ++i) {
    num += (A[i] - B[i]) * (A[i] - B[i]);
    den += A[i] * A[i];
    if (tol == 0.0 && A[i] != B[i]) num = num > 0.0 ? num : 1.0; /* exact: any difference fails */
  }
  d = den > 0.0 ? sqrt(num / den) : sqrt(num);
  printf("relative difference %s vs %s: %.3e (tolerance %.1e)\n", a, b, d, tol);
  st = (d <= tol && isfinite(d)) ? 0 : 1;
  if (st) fprintf(stderr, "cli_ref: FAILED: %s and %s differ by %.3e > %.1e\n", a, b, d, tol);
done:
  phgmg_npy_free(A, NULL);
  phgmg_npy_free(B, NULL);
  return st;
}

static int scale(const char *in, const char *out, double c) {
  double *A = NULL;
  int r, k;
  size_t i;
  phgmg_result rc = phgmg_npy_read(in, &A, &r, &k, NULL, NULL);
  if (rc != PHGMG_OK) return die(in, rc);
  for (i = 0; i < (size_t)r * (size_t)k; ++i) A[i] *= c;
  rc = phgmg_npy_write(out, A, r, k, r > 0 ? r : 1, 2, 0u);
  phgmg_npy_free(A, NULL);
  return rc == PHGMG_OK ? 0 : die(out, rc);
}

int main(int argc, char **argv) {
  if (argc == 5 && !strcmp(argv[1], "scale")) return scale(argv[2], argv[3], atof(argv[4]));
  if (argc == 3 && !strcmp(argv[1], "model")) {
    msd_linear M;
    int st;
    if (msd_linear_build(&M, 50, NULL, NULL, NULL, PHGMG_DENSE) != 0) return 1;
    st = put(argv[2], "J", M.J, 100, 100) || put(argv[2], "R", M.R, 100, 100) ||
         put(argv[2], "B", M.B, 100, 1) || put(argv[2], "Q", M.Q, 100, 100);
    msd_linear_free(&M);
    return st;
  }
  if (argc == 4 && !strcmp(argv[1], "model-nl")) {
    msd_nonlinear M;
    msd_nl_opts mo;
    double *idx;
    int st, i, N;
    memset(&mo, 0, sizeof mo);
    mo.n = atoi(argv[3]); mo.storage = PHGMG_DENSE;
    if (msd_nonlinear_build(&M, &mo) != 0) return 1;
    N = M.sys.N;
    idx = (double *)malloc(sizeof(double) * (size_t)mo.n);
    if (!idx) return 1;
    for (i = 0; i < mo.n; ++i) idx[i] = M.idx_l[i];
    st = put(argv[2], "J", M.J, N, N) || put(argv[2], "R", M.R, N, N) || put(argv[2], "B", M.B, N, 1) ||
         put(argv[2], "Q", M.Q, N, N) || put(argv[2], "poly", M.poly, 5, 1) || put(argv[2], "idx", idx, mo.n, 1);
    free(idx);
    msd_nonlinear_free(&M);
    return st;
  }
  if (argc == 6 && !strcmp(argv[1], "ref") && !strcmp(argv[2], "linear") && method_of(argv[3]))
    return ref(0, method_of(argv[3]), atoi(argv[4]), 0, argv[5]);
  if (argc == 7 && !strcmp(argv[1], "ref") && !strcmp(argv[2], "nonlinear") && method_of(argv[3]))
    return ref(1, method_of(argv[3]), atoi(argv[4]), atoi(argv[5]), argv[6]);
#ifdef CLI_REF_ROM_C
  if (argc == 3 && !strcmp(argv[1], "csim")) return csim(argv[2]);
#endif
  if (argc == 5 && !strcmp(argv[1], "compare")) return compare(argv[2], argv[3], atof(argv[4]));
  fprintf(stderr, "usage: cli_ref model DIR | model-nl DIR n | ref linear METHOD r OUT.npy |\n"
                  "       ref nonlinear METHOD r n OUT.npy | compare A.npy B.npy TOL\n");
  return 2;
}
