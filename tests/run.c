/* Test runner: runs every suite (or those whose "suite/test" name contains
   argv[1]) and ends with "N passed, N failed". Exit status 0 iff none failed.
   A test that takes a second of CPU time or more shows it after its name. */
#include "harness.h"
#include <stdlib.h>
#include <time.h>

int th_cur_failed = 0;
const char *th_filter = NULL;
static int th_passed = 0, th_failed = 0;

void th_fail_msg(const char *file, int line, const char *expr) {
  th_cur_failed++;
  if (th_cur_failed <= 5) printf("    FAIL %s:%d: %s\n", file, line, expr);
}

void th_run(const char *suite, const char *name, void (*fn)(void)) {
  char full[256], took[32];
  clock_t t0;
  double sec;
  snprintf(full, sizeof full, "%s/%s", suite, name);
  if (th_filter && !strstr(full, th_filter)) return;
  th_cur_failed = 0;
  t0 = clock();
  fn();
  sec = (double)(clock() - t0) / CLOCKS_PER_SEC;
  if (sec >= 1.0) snprintf(took, sizeof took, "  (%.1f s CPU)", sec);
  else took[0] = 0;
  if (th_cur_failed) { th_failed++; printf("FAIL  %s (%d checks failed)%s\n", full, th_cur_failed, took); }
  else { th_passed++; printf("ok    %s%s\n", full, took); }
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
