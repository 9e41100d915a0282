/* export_model — the workstation half of the controller example.

   Builds the demo's reduced models at r = 16 (linear MSD: SP1-POD, GMG-POD
   with its step map, GMG-QM; nonlinear MSD, n = 500: SP2-POD, GMG-POD and
   GMG-QM with structure-preserving DEIM; the Morse chain of
   examples/morse_chain.c, n = 100, whose Hamiltonian is an exp-polynomial:
   SP2-POD, GMG-POD and GMG-QM with structure-preserving DEIM), then for each
   model:
     - steps it in memory for 1000 steps of dt = 0.1 with u = 0.1 sin t and
       writes the outputs to <dir>/<name>.ref (the reference);
     - saves it as a binary model file <dir>/<name>.phgmgrom, loads that file
       back and checks that the loaded model reproduces the reference exactly;
     - exports it as C source <dir>/<name>.h for firmware (see controller.c).
   The scalar type is this build's phgmg_real: build once plain (double) and
   once with -DPHGMG_REAL_FLOAT (float). Exit status 1 on any mismatch.
   usage: export_model DIR [--fast]  (--fast: smaller nonlinear chain) */
#define _POSIX_C_SOURCE 200809L
#define PHGMG_IMPLEMENTATION
#include "../../phgmg.h"
#include "../msd_models.h"
#include "../morse_models.h"
#include <stdio.h>
#include "controller_run.h"

static int write_ref(const char *path, const phgmg_real *y, int n) {
  FILE *f = fopen(path, "w");
  int i;
  if (!f) return -1;
  for (i = 0; i < n; ++i) fprintf(f, PHGMG_CTRL_FMT "\n", (double)y[i]);
  return fclose(f);
}

static int do_model(const char *dir, const char *name, const phgmg_ph_system *sys, const double *X, int ns,
                    phgmg_method meth, int deim, double lambda) {
  phgmg_reduce_opts o;
  phgmg_reduced *red = NULL;
  phgmg_result rc;
  static phgmg_real y[CTRL_STEPS + 1], y2[CTRL_STEPS + 1];
  char path[512];
  phgmg_rom loaded;
  void *block = NULL;
  int bad = 0;
  memset(&o, 0, sizeof o);
  o.method = meth; o.r = 16; o.qm.rn = 8; o.qm.lambda = lambda; o.hyper.on = deim; o.hyper.allow_negative = 1;
  o.dt = 0.1;
  rc = phgmg_reduce(&red, sys, X, sys->N, ns, &o, NULL, NULL);
  if (rc != PHGMG_OK) { fprintf(stderr, "%s: reduce: %s\n", name, phgmg_result_string(rc)); return 1; }
  rc = ctrl_run(phgmg_reduced_rom(red), y);
  if (rc != PHGMG_OK) { fprintf(stderr, "%s: online run: %s\n", name, phgmg_result_string(rc)); bad = 1; }
  snprintf(path, sizeof path, "%s/%s.ref", dir, name);
  if (write_ref(path, y, CTRL_STEPS + 1) != 0) bad = 1;
  snprintf(path, sizeof path, "%s/%s.phgmgrom", dir, name);
  rc = phgmg_rom_save(phgmg_reduced_rom(red), path);
  if (rc == PHGMG_OK) rc = phgmg_rom_load(path, &loaded, &block, NULL);
  if (rc == PHGMG_OK) rc = ctrl_run(&loaded, y2);
  if (rc != PHGMG_OK || memcmp(y, y2, sizeof y) != 0) {
    fprintf(stderr, "%s: binary file does not reproduce the in-memory model (%s)\n", name, phgmg_result_string(rc));
    bad = 1;
  }
  free(block);
  snprintf(path, sizeof path, "%s/%s.h", dir, name);
  rc = phgmg_rom_export_c(phgmg_reduced_rom(red), name, path);
  if (rc != PHGMG_OK) { fprintf(stderr, "%s: export: %s\n", name, phgmg_result_string(rc)); bad = 1; }
  printf("%-12s r = %d, %s, stepper memory %lu bytes, binary file %lu bytes%s\n", name, 16,
         PHGMG_REAL_IS_FLOAT ? "float" : "double",
         (unsigned long)phgmg_rom_stepper_memsize(phgmg_reduced_rom(red)),
         (unsigned long)phgmg_rom_serialized_size(phgmg_reduced_rom(red)), bad ? "  MISMATCH" : "");
  phgmg_reduced_destroy(red);
  return bad;
}

int main(int argc, char **argv) {
  const int nsteps = 1000, ns = nsteps + 1;
  msd_linear L;
  msd_nonlinear M;
  msd_nl_opts mo;
  morse_chain C;
  morse_opts co;
  phgmg_gl3_opts go;
  double *X, *x0;
  int bad = 0;
  if (argc < 2) { fprintf(stderr, "usage: %s DIR [--fast]\n", argv[0]); return 2; }
  memset(&go, 0, sizeof go);
  /* linear MSD of paper 5.2 */
  if (msd_linear_build(&L, 50, NULL, NULL, NULL, PHGMG_DENSE) != 0) return 1;
  X = (double *)malloc(sizeof(double) * L.sys.N * ns);
  x0 = (double *)calloc((size_t)L.sys.N, sizeof(double));
  go.tol = 1e-10; go.max_iter = 10;
  if (phgmg_simulate(&L.sys, x0, 0, 0.1, nsteps, msd_input_sin, NULL, &go, X, NULL, NULL, NULL, NULL, NULL) != PHGMG_OK) return 1;
  bad |= do_model(argv[1], "lin_sp1", &L.sys, X, ns, PHGMG_METHOD_SP1, 0, 0);
  bad |= do_model(argv[1], "lin_gmgpod", &L.sys, X, ns, PHGMG_METHOD_GMG_POD, 0, 0);
  bad |= do_model(argv[1], "lin_gmgqm", &L.sys, X, ns, PHGMG_METHOD_GMG_QM, 0, 1e-3);
  free(X); free(x0);
  /* nonlinear MSD of paper 5.3 */
  memset(&mo, 0, sizeof mo);
  mo.n = (argc > 2 && !strcmp(argv[2], "--fast")) ? 100 : 500; mo.storage = PHGMG_BANDED;
  if (msd_nonlinear_build(&M, &mo) != 0) return 1;
  X = (double *)malloc(sizeof(double) * M.sys.N * ns);
  x0 = (double *)calloc((size_t)M.sys.N, sizeof(double));
  go.tol = 1e-8; go.max_iter = 20;
  if (phgmg_simulate(&M.sys, x0, 0, 0.1, nsteps, msd_input_sin, NULL, &go, X, NULL, NULL, NULL, NULL, NULL) != PHGMG_OK) return 1;
  bad |= do_model(argv[1], "nl_sp2", &M.sys, X, ns, PHGMG_METHOD_SP2, 1, 0);
  bad |= do_model(argv[1], "nl_gmgpod", &M.sys, X, ns, PHGMG_METHOD_GMG_POD, 1, 0);
  bad |= do_model(argv[1], "nl_gmgqm", &M.sys, X, ns, PHGMG_METHOD_GMG_QM, 1, 5e-3);
  free(X); free(x0);
  /* Morse chain: exp-polynomial separable part, training input
     u = 0.1 sin t, Newton tol 1e-10 as in examples/morse_chain.c; GMG-QM with
     that example's lambda rule max(0.2 e_proj(16), 10^-2.5) = 10^-2.5 */
  memset(&co, 0, sizeof co);
  co.n = 100;
  if (morse_chain_build(&C, &co) != 0) return 1;
  X = (double *)malloc(sizeof(double) * C.sys.N * ns);
  x0 = (double *)calloc((size_t)C.sys.N, sizeof(double));
  go.tol = 1e-10; go.max_iter = 20;
  if (phgmg_simulate(&C.sys, x0, 0, 0.1, nsteps, morse_input_train, NULL, &go, X, NULL, NULL, NULL, NULL, NULL) != PHGMG_OK) return 1;
  bad |= do_model(argv[1], "mo_sp2", &C.sys, X, ns, PHGMG_METHOD_SP2, 1, 0);
  bad |= do_model(argv[1], "mo_gmgpod", &C.sys, X, ns, PHGMG_METHOD_GMG_POD, 1, 0);
  bad |= do_model(argv[1], "mo_gmgqm", &C.sys, X, ns, PHGMG_METHOD_GMG_QM, 1, pow(10.0, -2.5));
  free(X); free(x0);
  morse_chain_free(&C);
  msd_linear_free(&L);
  msd_nonlinear_free(&M);
  return bad;
}
