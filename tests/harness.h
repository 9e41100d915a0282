/* Minimal test harness for phgmg (no external framework).
   A test is `TEST(name) { ... CHECK(cond); ... }`, registered in a suite:
       SUITE(linalg) { RUN(test_lu_random); RUN(test_qr); }
   Suites are collected by the Makefile into tests/suites.inc. The runner ends
   with the line "N passed, N failed". Each test file defines PHGMG_STATIC and
   PHGMG_IMPLEMENTATION itself, so it can reach private helpers. */
#ifndef PHGMG_TEST_HARNESS_H
#define PHGMG_TEST_HARNESS_H
#include <stdio.h>
#include <math.h>
#include <string.h>
#include <stdlib.h>

extern int th_cur_failed;    /* checks failed in the current test */
extern const char *th_filter;
void th_run(const char *suite, const char *name, void (*fn)(void));
void th_fail_msg(const char *file, int line, const char *expr);

#define TEST(name) static void name(void)
#define RUN(name) th_run(th_suite_name_, #name, name)
/* A suite's body gets its name as a parameter (no file-level static), so that
   several test files can share one translation unit (tests/unit_*.c); the
   random numbers below restart at each suite, as in a file of its own. */
#define SUITE(s) \
  static void th_suite_body_##s(const char *th_suite_name_); \
  void suite_##s(void); \
  void suite_##s(void) { th_rand_reset(); th_suite_body_##s(#s); } \
  static void th_suite_body_##s(const char *th_suite_name_)
#define CHECK(cond) do { if (!(cond)) th_fail_msg(__FILE__, __LINE__, #cond); } while (0)
/* a <= b with both printed on failure */
#define CHECK_LE(a, b) do { double th_a_ = (double)(a), th_b_ = (double)(b); \
    if (!(th_a_ <= th_b_)) { char th_m_[256]; \
      snprintf(th_m_, sizeof th_m_, "%s <= %s  (%.3e vs %.3e)", #a, #b, th_a_, th_b_); \
      th_fail_msg(__FILE__, __LINE__, th_m_); } } while (0)
#define CHECK_RC(rc, expect) do { int th_r_ = (int)(rc), th_e_ = (int)(expect); \
    if (th_r_ != th_e_) { char th_m_[256]; \
      snprintf(th_m_, sizeof th_m_, "%s == %s  (got %d: %s)", #rc, #expect, th_r_, \
               phgmg_result_string((phgmg_result)th_r_)); \
      th_fail_msg(__FILE__, __LINE__, th_m_); } } while (0)

/* Deterministic random numbers for tests (xorshift64*), uniform in [-1, 1). */
static inline unsigned long long *th_rand_state(void) {
  static unsigned long long s = 0x9E3779B97F4A7C15ULL;
  return &s;
}
static inline void th_rand_reset(void) { *th_rand_state() = 0x9E3779B97F4A7C15ULL; }
/* Band storage (half-bandwidth kb, (2 kb + 1) x N, the library's layout) of a
   dense N x N matrix; calloc'ed, the caller frees. */
static inline double *th_band(int N, int kb, const double *A) {
  double *b = (double *)calloc((size_t)(2 * kb + 1) * (size_t)N, sizeof(double));
  int i, j;
  for (j = 0; b && j < N; ++j)
    for (i = (j - kb > 0 ? j - kb : 0); i <= (j + kb < N - 1 ? j + kb : N - 1); ++i)
      b[(kb + i - j) + (size_t)j * (size_t)(2 * kb + 1)] = A[i + (size_t)j * N];
  return b;
}

static inline double th_rand(void) {
  unsigned long long *p = th_rand_state(), s = *p;
  s ^= s >> 12; s ^= s << 25; s ^= s >> 27;
  *p = s;
  return (double)((s * 2685821657736338717ULL) >> 11) / 4503599627370496.0 - 1.0;
}
#endif
