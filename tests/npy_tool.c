/* npy_tool — a small CLI over the .npy reader/writer of phgmg.h, used by
   tests/test_npy_numpy.py to exchange files with real NumPy.
     npy_tool copy in.npy out.npy [--c-order] [--f32]
         read in.npy, write it back (same ndim) as '<f8' Fortran order, or
         C order / float32 with the options
     npy_tool info in.npy
         print "rows cols ndim" of the column-major result
   Exit status 0 on success, 1 on a library error (its text on stderr),
   2 on bad usage. Build: cc -std=c99 tests/npy_tool.c -o build/npy_tool -lm */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../phgmg.h"
#include <stdio.h>
#include <string.h>

static int usage(void) {
  fprintf(stderr, "usage: npy_tool copy in.npy out.npy [--c-order] [--f32]\n"
                  "       npy_tool info in.npy\n");
  return 2;
}

int main(int argc, char **argv) {
  double *A = NULL;
  int rows = 0, cols = 0, ndim = 0, i;
  unsigned flags = 0;
  phgmg_result rc;
  if (argc == 3 && strcmp(argv[1], "info") == 0) {
    rc = phgmg_npy_read(argv[2], &A, &rows, &cols, &ndim, NULL);
    if (rc != PHGMG_OK) {
      fprintf(stderr, "npy_tool: %s: %s\n", argv[2], phgmg_result_string(rc));
      return 1;
    }
    printf("%d %d %d\n", rows, cols, ndim);
    phgmg_npy_free(A, NULL);
    return 0;
  }
  if (argc < 4 || strcmp(argv[1], "copy") != 0) return usage();
  for (i = 4; i < argc; ++i) {
    if (strcmp(argv[i], "--c-order") == 0) flags |= PHGMG_NPY_C_ORDER;
    else if (strcmp(argv[i], "--f32") == 0) flags |= PHGMG_NPY_F32;
    else return usage();
  }
  rc = phgmg_npy_read(argv[2], &A, &rows, &cols, &ndim, NULL);
  if (rc != PHGMG_OK) {
    fprintf(stderr, "npy_tool: reading %s: %s\n", argv[2], phgmg_result_string(rc));
    return 1;
  }
  rc = phgmg_npy_write(argv[3], A, rows, cols, rows > 0 ? rows : 1, ndim, flags);
  phgmg_npy_free(A, NULL);
  if (rc != PHGMG_OK) {
    fprintf(stderr, "npy_tool: writing %s: %s\n", argv[3], phgmg_result_string(rc));
    return 1;
  }
  return 0;
}
