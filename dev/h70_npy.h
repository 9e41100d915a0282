
/* >>npy =================================================================== */
/* NumPy .npy files (offline half): snapshot matrices, bases and reference
   trajectories exchanged with Python.
   Read: format versions 1.0, 2.0 and 3.0; dtypes '<f8', '>f8', '<f4', '>f4';
   C or Fortran order; 0-d, 1-d and 2-d shapes. The result is always a
   column-major double matrix: shape () is 1 x 1, shape (n,) is n x 1, shape
   (r, c) is r x c. Empty shapes such as (0,) or (3, 0) give a zero-size matrix
   (a valid pointer to no elements). Bytes after the data are ignored, as NumPy
   does. Anything else (bad magic, bad header dict, other dtypes, more than two
   dimensions, a dimension above INT_MAX, a header longer than
   PHGMG_NPY_MAX_HEADER, truncated data) is PHGMG_ERR_FORMAT.
   Write: format version 1.0, '<f8' (or '<f4' with PHGMG_NPY_F32), Fortran order
   (or C order with PHGMG_NPY_C_ORDER), header padded so the data starts at a
   multiple of 64 bytes, as NumPy writes it.
   ndim selects the written shape: 2 gives (rows, cols); 1 gives (rows*cols,)
   and needs rows == 1 or cols == 1; 0 gives () and needs rows == cols == 1.
   The in-memory parser/serializer never touch files; the file functions are
   compiled out by PHGMG_NO_STDIO. On failure the output arguments are left
   unchanged and nothing stays allocated. */
#ifndef PHGMG_NO_OFFLINE
#ifdef __cplusplus
extern "C" {
#endif

#ifndef PHGMG_NPY_MAX_HEADER
#define PHGMG_NPY_MAX_HEADER 1048576 /* longest accepted header, bytes */
#endif

/* Flags of the writers (combine with |). */
#define PHGMG_NPY_C_ORDER 1u /* row-major data, 'fortran_order': False       */
#define PHGMG_NPY_F32     2u /* store float32 '<f4' (rounded) instead of '<f8' */

/* Parse an in-memory .npy image buf[0..len). On success *out receives a
   column-major rows x cols matrix (ld = rows) allocated with alloc (NULL =
   default); release it with phgmg_npy_free. rows, cols and out are required,
   ndim (0, 1 or 2) may be NULL. Errors: PHGMG_ERR_INVALID_ARG (NULL buf/out/
   rows/cols), PHGMG_ERR_FORMAT, PHGMG_ERR_NOMEM. Safe on arbitrary bytes. */
PHGMG_DEF phgmg_result phgmg_npy_parse(const void *buf, size_t len, double **out, int *rows,
                                       int *cols, int *ndim, const phgmg_allocator *alloc);

/* Serialize the rows x cols matrix A (column-major, leading dimension ld >=
   max(1, rows)) as a .npy image into buf[0..cap). *len always receives the
   number of bytes needed; with buf == NULL only that size is computed.
   Errors: PHGMG_ERR_INVALID_ARG (NULL A with elements, NULL len, unknown
   flags), PHGMG_ERR_SIZE (bad dimensions/ld/ndim), PHGMG_ERR_WORKSPACE
   (cap < *len; nothing is written). */
PHGMG_DEF phgmg_result phgmg_npy_serialize(const double *A, int rows, int cols, int ld, int ndim,
                                           unsigned flags, void *buf, size_t cap, size_t *len);

/* Free a matrix returned by phgmg_npy_parse / phgmg_npy_read (same allocator;
   NULL pointer is a no-op). */
PHGMG_DEF void phgmg_npy_free(double *p, const phgmg_allocator *alloc);

#ifndef PHGMG_NO_STDIO
/* Read a .npy file; outputs and errors as phgmg_npy_parse, plus PHGMG_ERR_IO
   if the file cannot be opened or read. A file shorter than its header
   promises is PHGMG_ERR_FORMAT. */
PHGMG_DEF phgmg_result phgmg_npy_read(const char *path, double **out, int *rows, int *cols,
                                      int *ndim, const phgmg_allocator *alloc);

/* Write A (as phgmg_npy_serialize) to the file path, streaming, without
   allocating. Errors as phgmg_npy_serialize (except WORKSPACE), plus
   PHGMG_ERR_IO; a partly written file is removed. */
PHGMG_DEF phgmg_result phgmg_npy_write(const char *path, const double *A, int rows, int cols,
                                       int ld, int ndim, unsigned flags);
#endif /* PHGMG_NO_STDIO */

#ifdef __cplusplus
}
#endif
#endif /* PHGMG_NO_OFFLINE */
