
/* >>config (implementation) ============================================== */
#include <math.h>
#include <string.h>

#ifndef PHGMG_ASSERT
#include <assert.h>
#define PHGMG_ASSERT(x) assert(x)
#endif

#if defined(PHGMG_MALLOC) != defined(PHGMG_FREE)
#error "define both PHGMG_MALLOC and PHGMG_FREE, or neither"
#endif
#if !defined(PHGMG_MALLOC) && !defined(PHGMG_NO_OFFLINE)
#include <stdlib.h>
#define PHGMG_MALLOC(sz, user) ((void)(user), malloc(sz))
#define PHGMG_FREE(p, user) ((void)(user), free(p))
#endif

#ifdef PHGMG_USE_CBLAS
#include <cblas.h>
#endif

#ifdef __cplusplus
#define PHGMG__CAST(T, x) (static_cast<T>(x))
#else
#define PHGMG__CAST(T, x) ((T)(x))
#endif

#define PHGMG__MIN(a, b) ((a) < (b) ? (a) : (b))
#define PHGMG__MAX(a, b) ((a) > (b) ? (a) : (b))
#define PHGMG__EPS 2.220446049250313e-16

/* >>result (implementation) ============================================== */
PHGMG_DEF const char *phgmg_result_string(phgmg_result r) {
  switch (r) {
#define PHGMG__X(name, val, str) case name: return str;
    PHGMG__RESULT_LIST(PHGMG__X)
#undef PHGMG__X
    default: break;
  }
  return "unknown result code";
}

/* Private helpers are `static PHGMG__UNUSED` so that a build that does not use
   every one of them stays warning-free. */
#define PHGMG__PRIV static PHGMG__UNUSED

PHGMG__PRIV int phgmg__all_finite(const double *a, size_t n) {
  size_t i;
  double acc = 0.0;
  for (i = 0; i < n; ++i) acc += a[i] * 0.0;
  return acc == 0.0; /* NaN*0 = NaN, Inf*0 = NaN */
}

#ifndef PHGMG_NO_OFFLINE
/* >>memory (implementation) ============================================== */
PHGMG__PRIV void *phgmg__alloc(const phgmg_allocator *a, size_t size) {
  if (size == 0) size = 1;
  if (a && a->alloc) return a->alloc(size, a->user);
  return PHGMG_MALLOC(size, a ? a->user : NULL);
}
PHGMG__PRIV void phgmg__free(const phgmg_allocator *a, void *p) {
  if (!p) return;
  if (a && a->free) { a->free(p, a->user); return; }
  PHGMG_FREE(p, a ? a->user : NULL);
}
/* Allocate n doubles / ints; NULL on failure or overflow. */
PHGMG__PRIV double *phgmg__dalloc(const phgmg_allocator *a, size_t n) {
  if (n > ((size_t)-1) / sizeof(double) / 2) return NULL;
  return PHGMG__CAST(double *, phgmg__alloc(a, n * sizeof(double)));
}
PHGMG__PRIV int *phgmg__ialloc(const phgmg_allocator *a, size_t n) {
  if (n > ((size_t)-1) / sizeof(int) / 2) return NULL;
  return PHGMG__CAST(int *, phgmg__alloc(a, n * sizeof(int)));
}
#endif
