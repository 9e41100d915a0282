/* Exported C source of exp-polynomial, phi_cb and eta_cb reduced models, and of a
   linear model with dampers, feedthrough and a reference state.
   Without MODEL_HEADER: build three hand-made models (tests/sepfun_models.h), write
   them with phgmg_rom_export_c into DIR and their reference outputs into
   DIR/<name>.ref. With -DMODEL_HEADER="<name>.h" -DMODEL_NAME=<name> (and
   PHGMG_NO_OFFLINE): include the exported model, print the same outputs; the
   script tests/sepfun_export.sh compares them byte for byte (C and C++). */
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include <stdio.h>
#include <math.h>
#include "sepfun_models.h"

#ifdef MODEL_HEADER
#include MODEL_HEADER
/* firmware-supplied nonlinearity of the phi_cb model */
void sfx_cb_phi(int term, phgmg_real s, phgmg_real d[3], void *user) { sf_phi_table(term, s, d, user); }
/* firmware-supplied manifold of the eta_cb model */
void sfx_eta_eta(const phgmg_real *x2, phgmg_real *q, phgmg_real *Dq, phgmg_real *D2q, void *user) {
  sf_eta_fixed(x2, q, Dq, D2q, user);
}
#endif

static int print_outputs(const phgmg_rom *rom, FILE *f) {
  static phgmg_real work[4096];
  static double mem[1 << 14];
  phgmg_real x[SF_R] = {0.3f, -0.2f, 0.25f, 0.1f, -0.3f}, g[SF_R], fx[SF_R], Hs[SF_R * SF_R],
             Jf[SF_R * SF_R], u3[3 * SF_M], y[SF_M], tc[3];
  phgmg_rom_stepper st;
  int i, n, k;
  if (phgmg_rom_check(rom) != PHGMG_OK) return 1;
  fprintf(f, "%.17g\n", (double)phgmg_rom_hamiltonian(rom, x, work));
  phgmg_rom_gradient(rom, x, g, work);
  phgmg_rom_hessian(rom, x, Hs, work);
  if (phgmg_rom_rhs(rom, x, NULL, fx, work) != PHGMG_OK || phgmg_rom_jacobian(rom, x, Jf, work) != PHGMG_OK) return 1;
  for (i = 0; i < SF_R; ++i) fprintf(f, "%.17g %.17g\n", (double)g[i], (double)fx[i]);
  for (i = 0; i < SF_R * SF_R; ++i) fprintf(f, "%.17g %.17g\n", (double)Hs[i], (double)Jf[i]);
  if (phgmg_rom_stepper_init(&st, rom, (phgmg_real)0.05, 0, 0, mem, sizeof mem) != PHGMG_OK) return 1;
  for (n = 0; n < 100; ++n) {
    phgmg_rom_stage_times((phgmg_real)(0.05 * n), (phgmg_real)0.05, tc);
    for (i = 0; i < 3; ++i)
      for (k = 0; k < SF_M; ++k) u3[i * SF_M + k] = (phgmg_real)(0.5 * sin((1.0 + k) * (double)tc[i]));
    if (phgmg_rom_step(&st, x, u3, y, NULL) != PHGMG_OK) return 1;
    fprintf(f, "%.17g %.17g\n", (double)y[0], (double)y[1]);
  }
  return 0;
}

#ifndef MODEL_HEADER
/* A LINEAR model with every optional block that follows the separable part in
   phgmg_rom: nonlinear dampers (Cd, dw, dpoly), feedthrough (PD) and an
   affine reference state (ref_g, xr_rest); r = SF_R, m = SF_M. K = J - I
   (J skew), Qh = I + 0.1 ones, dampers rho(s) = 0.2 s + 1.5 s^3 (weights 1,
   0.5), PD = [Ph; I + N] with Ph = 0.1, N skew. */
static phgmg_real lx_Bh[SF_R * SF_M], lx_Qh[SF_R * SF_R], lx_K[SF_R * SF_R], lx_Cd[SF_R * 2],
    lx_dw[2] = {1.0f, 0.5f}, lx_dpoly[4] = {0.0f, 0.2f, 0.0f, 1.5f}, lx_PD[(SF_R + SF_M) * SF_M],
    lx_refg[SF_R + 1], lx_rest[SF_R];
static phgmg_rom lx_build(void) {
  phgmg_rom r;
  int i, j;
  memset(&r, 0, sizeof r);
  for (i = 0; i < SF_R; ++i)
    for (j = 0; j < SF_R; ++j) {
      lx_Qh[i + j * SF_R] = (phgmg_real)((i == j ? 1.0 : 0.0) + 0.1);
      lx_K[i + j * SF_R] = (phgmg_real)((i == j ? -1.0 : 0.0) + (i < j ? 0.3 * (j - i) : i > j ? -0.3 * (i - j) : 0.0));
    }
  for (i = 0; i < SF_R * SF_M; ++i) lx_Bh[i] = (phgmg_real)(i % SF_R == i / SF_R ? 1.0 : 0.0);
  for (i = 0; i < SF_R * 2; ++i) lx_Cd[i] = (phgmg_real)(i % SF_R == 2 + i / SF_R ? 1.0 : i % SF_R == 1 ? -0.5 : 0.0);
  for (i = 0; i < SF_R * SF_M; ++i) lx_PD[i] = (phgmg_real)0.1;
  lx_PD[SF_R * SF_M + 0] = 1.0f; lx_PD[SF_R * SF_M + 1] = 0.2f;   /* S + N, column-major m x m */
  lx_PD[SF_R * SF_M + 2] = -0.2f; lx_PD[SF_R * SF_M + 3] = 1.0f;
  for (i = 0; i < SF_R; ++i) { lx_refg[i] = (phgmg_real)(0.05 * (i + 1)); lx_rest[i] = (phgmg_real)(-0.01 * i); }
  lx_refg[SF_R] = 0.125f;
  r.kind = PHGMG_ROM_LINEAR; r.method = PHGMG_METHOD_GMG_POD; r.r = SF_R; r.m = SF_M;
  r.Bh = lx_Bh; r.Qh = lx_Qh; r.K = lx_K;
  r.ndamp = 2; r.damp_deg = 3; r.damp_nphi = 1; r.Cd = lx_Cd; r.dw = lx_dw; r.dpoly = lx_dpoly;
  r.PD = lx_PD; r.ref_g = lx_refg; r.xr_rest = lx_rest;
  return r;
}
#endif

int main(int argc, char **argv) {
#ifdef MODEL_HEADER
  (void)argc; (void)argv;
  return print_outputs(&MODEL_NAME, stdout);
#else
  static sf_model Md;
  phgmg_rom cb, et;
  char path[512];
  FILE *f;
  int rc = 0;
  if (argc < 2) return 2;
  sf_build(&Md, 5u);
  cb = Md.rom;
  cb.phi_cb = sf_phi_table; cb.poly = NULL; cb.expo = NULL; cb.poly_deg = 0; cb.nexp = 0; cb.nphi = 0;
  et = Md.rom;
  et.Ms = NULL; et.eta_cb = sf_eta_fixed; et.term = NULL; et.nphi = 1; /* shared Toda row */
  snprintf(path, sizeof path, "%s/sfx_eta.h", argv[1]);
  if (phgmg_rom_export_c(&et, "sfx_eta", path) != PHGMG_OK) return 1;
  snprintf(path, sizeof path, "%s/sfx_eta.ref", argv[1]);
  if (!(f = fopen(path, "w"))) return 1;
  rc |= print_outputs(&et, f);
  fclose(f);
  snprintf(path, sizeof path, "%s/sfx_poly.h", argv[1]);
  if (phgmg_rom_export_c(&Md.rom, "sfx_poly", path) != PHGMG_OK) return 1;
  snprintf(path, sizeof path, "%s/sfx_cb.h", argv[1]);
  if (phgmg_rom_export_c(&cb, "sfx_cb", path) != PHGMG_OK) return 1;
  snprintf(path, sizeof path, "%s/sfx_poly.ref", argv[1]);
  if (!(f = fopen(path, "w"))) return 1;
  rc |= print_outputs(&Md.rom, f);
  fclose(f);
  snprintf(path, sizeof path, "%s/sfx_cb.ref", argv[1]);
  if (!(f = fopen(path, "w"))) return 1;
  rc |= print_outputs(&cb, f);
  fclose(f);
  { /* the blocks after the separable part, in their member order */
    const phgmg_rom lx = lx_build();
    snprintf(path, sizeof path, "%s/sfx_lin.h", argv[1]);
    if (phgmg_rom_export_c(&lx, "sfx_lin", path) != PHGMG_OK) return 1;
    snprintf(path, sizeof path, "%s/sfx_lin.ref", argv[1]);
    if (!(f = fopen(path, "w"))) return 1;
    rc |= print_outputs(&lx, f);
    fclose(f);
  }
  return rc;
#endif
}
