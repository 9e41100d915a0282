/* The second translation unit of default-configuration test files (see
   tests/unity_a.c): test_ph (its test_alloc_failures and dup() would collide
   with test_linalg and <unistd.h>) and test_sepfun (its globals M, R and
   callbacks collide with test_general, test_sparse and test_study). */
#include "test_ph.c"
#include "test_sepfun.c"
