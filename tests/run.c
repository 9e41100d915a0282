/* Test runner: runs every suite (or those whose "suite/test" name contains
   argv[1]) and ends with "N passed, N failed". Exit status 0 iff none failed. */
#include "harness.h"
#include <stdlib.h>

int th_cur_failed = 0;
const char *th_filter = NULL;
static int th_passed = 0, th_failed = 0;

void th_fail_msg(const char *file, int line, const char *expr) {
  th_cur_failed++;
  if (th_cur_failed <= 5) printf("    FAIL %s:%d: %s\n", file, line, expr);
}

void th_run(const char *suite, const char *name, void (*fn)(void)) {
  char full[256];
  snprintf(full, sizeof full, "%s/%s", suite, name);
  if (th_filter && !strstr(full, th_filter)) return;
  th_cur_failed = 0;
  fn();
  if (th_cur_failed) { th_failed++; printf("FAIL  %s (%d checks failed)\n", full, th_cur_failed); }
  else { th_passed++; printf("ok    %s\n", full); }
  fflush(stdout);
}

#define SUITE_DECL(s) void suite_##s(void);
#include "suites.inc"
#undef SUITE_DECL

int main(int argc, char **argv) {
  if (argc > 1) th_filter = argv[1];
#define SUITE_DECL(s) suite_##s();
#include "suites.inc"
#undef SUITE_DECL
  printf("%d passed, %d failed\n", th_passed, th_failed);
  return th_failed ? 1 : 0;
}
