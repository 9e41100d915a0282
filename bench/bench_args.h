/* bench_args.h -- the command line of the bench programs that write CSV rows.

     PROG [--out FILE] [--help]      (bench_scale also takes --n N and --runs R)

   --out FILE appends `case,median_s,min_s,max_s,runs` rows to FILE (a header
   line first when FILE is empty); without it only the terminal table is
   printed. Any other argument is refused with exit status 2, so a mistyped
   option never becomes the name of a file. */
#ifndef BENCH_ARGS_H
#define BENCH_ARGS_H
#include <stdio.h>
#include <string.h>

/* Parses argv[1..]: options listed in extra[] (each taking one value, NULL-
   terminated, may be NULL) are stored in extra_val[] in the same order.
   Returns 0 to go on, 1 after printing the help (exit 0), 2 after a usage
   error (exit 2). */
static int bench_args(int argc, char **argv, const char *prog, const char *what, const char **out,
                      const char *const *extra, const char **extra_val) {
  int i, k;
  *out = NULL;
  for (i = 1; i < argc; ++i) {
    const char *a = argv[i];
    if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
      printf("usage: %s [--out FILE]", prog);
      for (k = 0; extra && extra[k]; ++k) printf(" [%s VALUE]", extra[k]);
      printf(" [--help]\n%s\n  --out FILE  append the CSV rows case,median_s,min_s,max_s,runs to FILE\n", what);
      return 1;
    }
    if (!strcmp(a, "--out")) {
      if (i + 1 >= argc || !argv[i + 1][0]) { fprintf(stderr, "%s: --out needs a file name\n", prog); return 2; }
      if (*out) { fprintf(stderr, "%s: --out given more than once\n", prog); return 2; }
      *out = argv[++i];
      continue;
    }
    for (k = 0; extra && extra[k]; ++k)
      if (!strcmp(a, extra[k])) break;
    if (extra && extra[k]) {
      if (i + 1 >= argc) { fprintf(stderr, "%s: %s needs a value\n", prog, a); return 2; }
      extra_val[k] = argv[++i];
      continue;
    }
    fprintf(stderr, "%s: unknown argument '%s' (try --help)\n", prog, a);
    return 2;
  }
  return 0;
}

/* Opens the CSV named by --out for appending (NULL name: no CSV); writes the
   header line when the file is empty. */
static FILE *bench_open_csv(const char *prog, const char *name, int *err) {
  FILE *f;
  *err = 0;
  if (!name) return NULL;
  f = fopen(name, "a");
  if (!f) { fprintf(stderr, "%s: cannot open %s\n", prog, name); *err = 1; return NULL; }
  fseek(f, 0, SEEK_END);
  if (ftell(f) == 0) fprintf(f, "case,median_s,min_s,max_s,runs\n");
  return f;
}
#endif
