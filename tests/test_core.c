/* Core: result strings, version, allocator plumbing. */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include "harness.h"

TEST(test_result_strings) {
  int v;
  for (v = 0; v > PHGMG__RESULT_END_; --v) {
    const char *s = phgmg_result_string((phgmg_result)v);
    CHECK(s != NULL && strlen(s) > 3);
    CHECK(strcmp(s, "unknown result code") != 0);
  }
  CHECK(strcmp(phgmg_result_string((phgmg_result)-999), "unknown result code") == 0);
}

TEST(test_finite_check) {
  double a[4] = {1, 2, 3, 4};
  CHECK(phgmg__all_finite(a, 4));
  a[2] = NAN; CHECK(!phgmg__all_finite(a, 4));
  a[2] = INFINITY; CHECK(!phgmg__all_finite(a, 4));
}

SUITE(core) {
  RUN(test_result_strings);
  RUN(test_finite_check);
}
