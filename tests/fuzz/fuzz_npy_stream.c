/* Fuzz harness for the streaming .npy reader (phgmg_npy_read) against the
   in-memory parser (phgmg_npy_parse) on the same bytes: each input is parsed,
   then read from a regular file and from a pipe (inputs up to 60000 bytes, so
   they fit the pipe's buffer). The three must return the same result code
   and, on success, the same shape and the same bits; on failure the outputs
   stay untouched. Nothing else than PHGMG_OK / _FORMAT / _DTYPE / _INEXACT /
   _NOMEM may come back (a pipe's buffer grows with the data that
   actually arrives, so a short stream claiming a huge shape is _FORMAT).

   libFuzzer (clang):
     clang -g -O1 -fsanitize=fuzzer,address,undefined tests/fuzz/fuzz_npy_stream.c \
           -o build/fuzz_npy_stream -lm
     ./build/fuzz_npy_stream -max_total_time=60 -dict=tests/fuzz/npy.dict \
           build/fuzz/corpus_npy_stream tests/fuzz/corpus/npy_stream
   Plain driver (runs every file named on the command line), as fuzz_npy.c. */
#define _POSIX_C_SOURCE 200809L /* mkstemp, pipe, close */
#define PHGMG_STATIC
#define PHGMG_IMPLEMENTATION
#include "../../phgmg.h"
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char g_file[64];

static void fuzz_check(int ok, const char *what) {
  if (!ok) {
    fprintf(stderr, "fuzz_npy_stream: invariant violated: %s\n", what);
    abort();
  }
}

static void cleanup(void) {
  if (g_file[0]) unlink(g_file);
}

/* Read path with phgmg_npy_read; compare with the parse result. */
static void check_read(const char *path, phgmg_result want, const double *A, int rows, int cols,
                       int ndim, const char *how) {
  double *B = NULL;
  int r = -1, c = -1, nd = -1;
  size_t n;
  phgmg_result rc = phgmg_npy_read(path, &B, &r, &c, &nd, NULL);
  if (rc != want) {
    fprintf(stderr, "fuzz_npy_stream: %s: read gives %d, parse %d\n", how, (int)rc, (int)want);
    fuzz_check(0, "read and parse disagree");
  }
  if (rc != PHGMG_OK) {
    fuzz_check(B == NULL && r == -1 && c == -1 && nd == -1, "outputs changed on failure");
    return;
  }
  fuzz_check(r == rows && c == cols && nd == ndim, "shape differs");
  n = (size_t)rows * (size_t)cols;
  fuzz_check(n == 0 || memcmp(A, B, n * sizeof(double)) == 0, "values differ");
  phgmg_npy_free(B, NULL);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static const uint8_t empty[1] = {0};
  double *A = NULL;
  int rows = -1, cols = -1, ndim = -1, fds[2];
  char path[32];
  FILE *f;
  phgmg_result rc = phgmg_npy_parse(data ? (const void *)data : (const void *)empty, size, &A, &rows,
                                    &cols, &ndim, NULL);
  fuzz_check(rc == PHGMG_OK || rc == PHGMG_ERR_FORMAT || rc == PHGMG_ERR_DTYPE ||
                 rc == PHGMG_ERR_INEXACT || rc == PHGMG_ERR_NOMEM,
             "unexpected result code");
  if (rc == PHGMG_ERR_NOMEM) return 0; /* the reader may fail elsewhere: nothing to compare */
  if (!g_file[0]) {
    int fd;
    strcpy(g_file, "/tmp/phgmg_fuzz_npy_XXXXXX");
    fd = mkstemp(g_file);
    fuzz_check(fd >= 0, "mkstemp");
    close(fd);
    atexit(cleanup);
  }
  /* a regular file */
  f = fopen(g_file, "wb");
  fuzz_check(f != NULL, "fopen");
  fuzz_check(size == 0 || fwrite(data, 1, size, f) == size, "fwrite");
  fclose(f);
  check_read(g_file, rc, A, rows, cols, ndim, "file");
  /* a pipe (fits its buffer) */
  if (size <= 60000) {
    fuzz_check(pipe(fds) == 0, "pipe");
    fuzz_check(size == 0 || write(fds[1], data, size) == (ssize_t)size, "write to the pipe");
    close(fds[1]);
    snprintf(path, sizeof path, "/dev/fd/%d", fds[0]);
    check_read(path, rc, A, rows, cols, ndim, "pipe");
    close(fds[0]);
  }
  phgmg_npy_free(A, NULL);
  return 0;
}

#define FUZZ_NAME "fuzz_npy_stream"
#include "fuzz_main.h"
