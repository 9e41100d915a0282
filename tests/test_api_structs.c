/* The struct forms of the long-argument drivers: phgmg_simulate_run,
   phgmg_reduced_simulate_run and phgmg_ss_compare give bit for bit what the
   positional phgmg_simulate, phgmg_reduced_simulate and phgmg_ss_error give
   on the same arguments, report steps_done, refuse a NULL run and mismatched
   port counts, and leave err untouched on failure. Model: the paper's linear
   chain (examples/msd_models.h), 20 masses. */
#include <stdlib.h>
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"
#include "../examples/msd_models.h"

enum { AS_STEPS = 60 };

TEST(test_simulate_run_matches_positional) {
  msd_linear L;
  phgmg_run run;
  phgmg_sim_out out;
  phgmg_gl3_stats st;
  int N, done = -1;
  double *Xa, *Xb, *Ya, *Yb, *x0;
  CHECK(msd_linear_build(&L, 20, NULL, NULL, NULL, PHGMG_DENSE) == 0);
  N = L.sys.N;
  Xa = (double *)malloc(sizeof(double) * N * (AS_STEPS + 1) * 2);
  Ya = (double *)malloc(sizeof(double) * 2 * (AS_STEPS + 1) * 2);
  x0 = (double *)calloc((size_t)N, sizeof(double));
  CHECK(Xa && Ya && x0);
  if (Xa && Ya && x0) {
    Xb = Xa + N * (AS_STEPS + 1); Yb = Ya + 2 * (AS_STEPS + 1);
    memset(&run, 0, sizeof run);
    run.u = msd_input_sin; run.dt = 0.1; run.nsteps = AS_STEPS;
    CHECK_RC(phgmg_simulate(&L.sys, x0, 0.0, 0.1, AS_STEPS, msd_input_sin, NULL, NULL, Xa, Ya, NULL, NULL, &done,
                            NULL), PHGMG_OK);
    memset(&out, 0, sizeof out);
    out.X = Xb; out.Y = Yb; out.stats = &st; out.steps_done = -7;
    CHECK_RC(phgmg_simulate_run(&L.sys, &run, NULL, &out, NULL), PHGMG_OK);
    CHECK(done == AS_STEPS && out.steps_done == AS_STEPS && st.steps == AS_STEPS);
    CHECK(!memcmp(Xa, Xb, sizeof(double) * N * (AS_STEPS + 1)));
    CHECK(!memcmp(Ya, Yb, sizeof(double) * L.sys.m * (AS_STEPS + 1)));
    CHECK_RC(phgmg_simulate_run(&L.sys, &run, NULL, NULL, NULL), PHGMG_OK);
    CHECK_RC(phgmg_simulate_run(&L.sys, NULL, NULL, &out, NULL), PHGMG_ERR_INVALID_ARG);
    { /* the reduced model: struct and positional forms agree */
      phgmg_reduced *red = NULL;
      phgmg_reduce_opts o;
      phgmg_reduce_opts_default(&o);
      o.method = PHGMG_METHOD_GMG_POD; o.r = 8;
      CHECK_RC(phgmg_reduce(&red, &L.sys, Xa, N, AS_STEPS + 1, &o, NULL, NULL), PHGMG_OK);
      if (red) {
        double xr0[8] = {0};
        phgmg_rom_stats rs;
        CHECK_RC(phgmg_reduced_simulate(red, xr0, 0.0, 0.1, AS_STEPS, msd_input_sin, NULL, 0.0, 0, Xa, Ya, NULL,
                                        NULL, NULL), PHGMG_OK);
        memset(&out, 0, sizeof out);
        out.X = Xb; out.Y = Yb; out.rom_stats = &rs;
        CHECK_RC(phgmg_reduced_simulate_run(red, &run, 0.0, 0, &out, NULL), PHGMG_OK);   /* x0 NULL: 0 */
        CHECK(!memcmp(Xa, Xb, sizeof(double) * 8 * (AS_STEPS + 1)));
        CHECK(!memcmp(Ya, Yb, sizeof(double) * L.sys.m * (AS_STEPS + 1)));
        CHECK(rs.steps == AS_STEPS && out.steps_done == AS_STEPS);
        CHECK_RC(phgmg_reduced_simulate_run(red, NULL, 0.0, 0, &out, NULL), PHGMG_ERR_INVALID_ARG);
      }
      phgmg_reduced_destroy(red);
    }
  }
  free(Xa); free(Ya); free(x0);
  msd_linear_free(&L);
}

/* Two small stable models (diagonal A, closed-form data): the struct form
   equals the positional one; mismatched ports are PHGMG_ERR_SIZE. */
TEST(test_ss_compare_matches_positional) {
  static const double A1[4] = {-1, 0, 0, -2}, B1[2] = {1, 1}, C1[2] = {1, 1};
  static const double A2[1] = {-1.5}, B2[1] = {1}, C2[1] = {2};
  phgmg_ss g1 = {2, 1, 1, A1, B1, C1}, g2 = {1, 1, 1, A2, B2, C2}, g3 = {1, 2, 1, A2, B1, C2};
  phgmg_ss_errors e, keep;
  double hi, hr, h2, h2r;
  CHECK_RC(phgmg_ss_error(2, A1, B1, C1, 1, A2, B2, C2, 1, 1, 50, 1e-2, 1e2, &hi, &hr, &h2, &h2r, NULL), PHGMG_OK);
  CHECK_RC(phgmg_ss_compare(&g1, &g2, 50, 1e-2, 1e2, &e, NULL), PHGMG_OK);
  CHECK(e.hinf == hi && e.hinf_ref == hr && e.h2 == h2 && e.h2_ref == h2r);
  /* ||G1||_H2^2 = sum_ij c_i b_i c_j b_j / -(a_i + a_j) = 1/2 + 2/3 + 1/4 */
  CHECK(fabs(e.h2_ref - sqrt(0.5 + 2.0 / 3.0 + 0.25)) < 1e-12);
  keep = e;
  CHECK_RC(phgmg_ss_compare(&g1, &g3, 50, 1e-2, 1e2, &e, NULL), PHGMG_ERR_SIZE);
  CHECK(!memcmp(&e, &keep, sizeof e));
  CHECK_RC(phgmg_ss_compare(&g1, NULL, 50, 1e-2, 1e2, &e, NULL), PHGMG_ERR_INVALID_ARG);
}

SUITE(api_structs) {
  RUN(test_simulate_run_matches_positional);
  RUN(test_ss_compare_matches_positional);
}
