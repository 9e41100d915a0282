/* The stand-alone driver of a fuzz harness (built without libFuzzer, and by
   `sh tests/fuzz/run.sh 0` to replay a corpus): runs LLVMFuzzerTestOneInput
   once on each file named on the command line (the whole file, or its first
   FUZZ_MAX_INPUT bytes when the harness defines that). Define FUZZ_NAME (the
   harness's name for messages) before including it, after the harness. */
#ifndef PHGMG_LIBFUZZER
#if defined(__GNUC__) || defined(__clang__)
__attribute__((weak))
#endif
int main(int argc, char **argv) {
  int k, nok = 0;
  for (k = 1; k < argc; ++k) {
    FILE *f = fopen(argv[k], "rb");
    unsigned char *buf;
    long n;
    if (!f) { fprintf(stderr, "%s: cannot open %s\n", FUZZ_NAME, argv[k]); return 1; }
    if (fseek(f, 0, SEEK_END) != 0 || (n = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
      fprintf(stderr, "%s: cannot size %s\n", FUZZ_NAME, argv[k]);
      fclose(f);
      return 1;
    }
    buf = (unsigned char *)malloc((size_t)n + 1);
    if (!buf || fread(buf, 1, (size_t)n, f) != (size_t)n) {
      fprintf(stderr, "%s: cannot read %s\n", FUZZ_NAME, argv[k]);
      free(buf);
      fclose(f);
      return 1;
    }
    fclose(f);
#ifdef FUZZ_MAX_INPUT
    if (n > FUZZ_MAX_INPUT) n = FUZZ_MAX_INPUT;
#endif
    LLVMFuzzerTestOneInput(buf, (size_t)n);
    free(buf);
    ++nok;
  }
  printf("%s: %d inputs ran without findings\n", FUZZ_NAME, nok);
  return 0;
}
#endif
