/* Fuzz harness for the .npy parser (phgmg_npy_parse), the reader of outside
   data in phgmg.h. Each input is parsed; on success the result must satisfy
   the documented shape rules, every element is read (so ASan sees any bad
   bound), and serializing it (with each writer option) and parsing again
   must give back the same bits.
   Anything else than PHGMG_OK / PHGMG_ERR_FORMAT / PHGMG_ERR_DTYPE /
   PHGMG_ERR_INEXACT / PHGMG_ERR_NOMEM aborts.

   libFuzzer (clang):
     clang -g -O1 -fsanitize=fuzzer,address,undefined tests/fuzz/fuzz_npy.c \
           -o build/fuzz_npy -lm
     ./build/fuzz_npy -max_total_time=600 -jobs=1 -dict=tests/fuzz/npy.dict \
           build/fuzz_corpus tests/fuzz/corpus/npy
   Plain driver (any C compiler; runs every file named on the command line):
     gcc -std=c99 -g -O1 -fsanitize=address,undefined tests/fuzz/fuzz_npy.c \
           -o build/fuzz_npy_run -lm
     ./build/fuzz_npy_run $(ls -d tests/fuzz/corpus/npy/[!.]*)
   The driver's main() is weak under GCC/Clang, so libFuzzer's own main wins
   when linked with -fsanitize=fuzzer; define PHGMG_LIBFUZZER to leave it out
   altogether (e.g. for other fuzzing engines). */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../../phgmg.h"
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void fuzz_check(int ok, const char *what) {
  if (!ok) {
    fprintf(stderr, "fuzz_npy: invariant violated: %s\n", what);
    abort();
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static const uint8_t empty[1] = {0};
  double *A = NULL, *B = NULL, sum = 0.0;
  int rows = -1, cols = -1, ndim = -1, r2 = -1, c2 = -1, n2 = -1;
  size_t i, count, len = 0;
  unsigned flags;
  unsigned char *img;
  phgmg_result rc = phgmg_npy_parse(data ? (const void *)data : (const void *)empty, size, &A,
                                    &rows, &cols, &ndim, NULL);
  if (rc != PHGMG_OK) {
    fuzz_check(rc == PHGMG_ERR_FORMAT || rc == PHGMG_ERR_DTYPE || rc == PHGMG_ERR_INEXACT ||
                   rc == PHGMG_ERR_NOMEM,
               "unexpected result code");
    fuzz_check(A == NULL && rows == -1 && cols == -1 && ndim == -1, "outputs changed on failure");
    return 0;
  }
  fuzz_check(A != NULL && rows >= 0 && cols >= 0 && ndim >= 0 && ndim <= 2, "shape");
  fuzz_check(ndim != 0 || (rows == 1 && cols == 1), "0-d is 1 x 1");
  fuzz_check(ndim != 1 || cols == 1, "1-d is n x 1");
  count = (size_t)rows * (size_t)cols;
  fuzz_check(count <= size, "more elements than bytes"); /* 1-byte integer dtypes */
  for (i = 0; i < count; ++i) sum += A[i] * 0.0; /* touch every element */
  (void)sum;
  /* round trip with every writer option: serialize, parse again, same bits
     (float32: the same values as a C cast to float) */
  for (flags = 0; flags < 4; ++flags) {
    const int ld = rows > 0 ? rows : 1;
    rc = phgmg_npy_serialize(A, rows, cols, ld, ndim, flags, NULL, 0, &len);
    fuzz_check(rc == PHGMG_OK, "serialize size");
    img = (unsigned char *)malloc(len);
    fuzz_check(img != NULL, "malloc");
    rc = phgmg_npy_serialize(A, rows, cols, ld, ndim, flags, img, len, &len);
    fuzz_check(rc == PHGMG_OK, "serialize");
    rc = phgmg_npy_parse(img, len, &B, &r2, &c2, &n2, NULL);
    fuzz_check(rc == PHGMG_OK && r2 == rows && c2 == cols && n2 == ndim, "re-parse shape");
    for (i = 0; i < count; ++i) {
      double want = (flags & PHGMG_NPY_F32) ? (double)(float)A[i] : A[i];
      fuzz_check(memcmp(&want, &B[i], sizeof want) == 0, "re-parse values");
    }
    free(img);
    phgmg_npy_free(B, NULL);
    B = NULL;
  }
  phgmg_npy_free(A, NULL);
  return 0;
}

#define FUZZ_NAME "fuzz_npy"
#include "fuzz_main.h"
