/* Fuzz harness for the argument handling of the `phgmg` command line
   (examples/phgmg_cli.c, compiled in with its main renamed) on a tiny model
   (N = 4, m = 1) in a scratch directory. Each input byte picks one token
   of a vocabulary (every command and option -- reduce, validate,
   simulate-rom, info --, numbers good and bad, potentials, hyper-reduction
   and manifold names, the scratch model's files dense and as coordinate
   triplets, a malformed and an integer .npy, a directory, output paths
   inside the scratch directory), at most 48 tokens; the resulting command
   line is run; the vocabulary also has simulate and the descriptor,
   feedthrough, damper and reference files (a mass matrix, an index-one E,
   E as triplets, P, S, N, dampers, a reference state, a link to the
   damper file). File mode (an input starting with 0xFF): byte 1 picks one
   of those files, the rest of the input is its content, and a fixed
   simulate or reduce that reads it runs -- the files' content fuzzed. Any
   exit status is fine (0, 1, 2); sanitizers, leaks, hangs, and a run that
   changes or removes a file named as one of its inputs are findings. Before each run the scratch directory is restored, so
   a run never sees what an earlier one wrote. The command runs with the
   scratch directory (/tmp/phgmg_fuzz_cli_XXXXXX, removed at exit) as its
   working directory, so whatever it writes -- also under a relative name
   such as "2" after --out -- stays there; the harness returns to the
   starting directory afterwards (libFuzzer's corpus paths are relative).
   run.sh passes an absolute -artifact_prefix for the same reason.

   libFuzzer (clang):
     clang -g -O1 -fsanitize=fuzzer,address,undefined tests/fuzz/fuzz_cli.c \
           -o build/fuzz_cli -lm
     ./build/fuzz_cli -max_total_time=60 -close_fd_mask=3 build/fuzz/corpus_cli tests/fuzz/corpus/cli
   Plain driver (runs every file named on the command line), as fuzz_npy.c. */
#define main phgmg_cli_main
#include "../../examples/phgmg_cli.c"
#undef main
#include <dirent.h>
#include <fcntl.h>
#include <stdint.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char g_dir[64];
static int g_home = -1; /* the starting working directory */
static char g_tok[192][128];
static int g_ntok;
static unsigned char *g_rom;
static size_t g_rom_len;

/* the tiny model: the 2-mass MSD, x = (q1, p1, q2, p2) */
static const double J4[16] = {0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0};
static const double R4[16] = {0, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0.5};
static const double Q4[16] = {2, 0, -1, 0, 0, 1, 0, 0, -1, 0, 1, 0, 0, 0, 0, 1};
static const double B4[4] = {0, 1, 0, 0};
static const double poly[5] = {0, 0, 0, 0, 0.25}, idx[2] = {0, 2};

static void fz_die(const char *what) {
  fprintf(stderr, "fuzz_cli: %s\n", what);
  abort();
}

static void put_npy(const char *name, const double *A, int rows, int cols) {
  char path[256];
  snprintf(path, sizeof path, "%s/%s", g_dir, name);
  if (phgmg_npy_write(path, A, rows, cols, rows, 2, 0u) != PHGMG_OK) fz_die("cannot write the model");
}

static void put_bytes(const char *name, const void *b, size_t n) {
  char path[256];
  FILE *f;
  snprintf(path, sizeof path, "%s/%s", g_dir, name);
  f = fopen(path, "wb");
  if (!f || (n && fwrite(b, 1, n, f) != n)) fz_die("cannot write a scratch file");
  fclose(f);
}

/* Remove everything in dir (one level of subdirectories, as the CLI makes). */
static void clear_dir(const char *dir, int depth) {
  DIR *d = opendir(dir);
  struct dirent *e;
  char path[4096 + 300];
  struct stat st;
  if (!d) return;
  while ((e = readdir(d)) != NULL) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
    if (lstat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
      if (depth < 3) clear_dir(path, depth + 1);
      rmdir(path);
    } else {
      unlink(path);
    }
  }
  closedir(d);
}

static void cleanup(void) {
  if (g_dir[0]) { clear_dir(g_dir, 0); rmdir(g_dir); }
  free(g_rom);
}

/* The scratch directory as every run starts it. */
static void restore(void) {
  static const unsigned char int_idx[] = /* np.arange(2, dtype='<i8'): [0, 1] */
    "\x93NUMPY\x01\x00\x76\x00{'descr': '<i8', 'fortran_order': False, 'shape': (2,), }"
    "                                                     \n"
    "\x00\x00\x00\x00\x00\x00\x00\x00\x01\x00\x00\x00\x00\x00\x00\x00";
  double X[4 * 8];
  int k;
  clear_dir(g_dir, 0);
  for (k = 0; k < 32; ++k) X[k] = sin(0.7 * k) + 0.1 * k; /* 8 generic snapshots */
  put_npy("J.npy", J4, 4, 4); put_npy("R.npy", R4, 4, 4); put_npy("Q.npy", Q4, 4, 4);
  put_npy("B.npy", B4, 4, 1); put_npy("X.npy", X, 4, 8); put_npy("poly.npy", poly, 5, 1);
  put_npy("idx.npy", idx, 2, 1); put_npy("u.npy", X, 8, 1);
  {   /* --poly-jdx: the second term a spring to the first term's coordinate */
    const double jdx[2] = {-1.0, idx[0]};
    put_npy("jdx.npy", jdx, 2, 1);
  }
  put_bytes("idx_i8.npy", int_idx, sizeof int_idx - 1);
  {   /* J, R, Q as (nnz, 3) coordinate triplets; one exponential pair (a, b) */
    double C[3 * 16], e2[2] = {1.0, 1.0};
    const double *const M[3] = {J4, R4, Q4};
    const char *const nm[3] = {"Jc.npy", "Rc.npy", "Qc.npy"};
    int t, i, j, n;
    for (t = 0; t < 3; ++t) {
      for (n = 0, j = 0; j < 4; ++j)
        for (i = 0; i < 4; ++i)
          if (M[t][i + 4 * j] != 0.0) { C[n] = i; C[n + 16] = j; C[n + 32] = M[t][i + 4 * j]; ++n; }
      for (i = 0; i < n; ++i) { C[n + i] = C[16 + i]; }          /* compact the columns: (n, 3) */
      for (i = 0; i < n; ++i) { C[2 * n + i] = C[32 + i]; }
      put_npy(nm[t], C, n, 3);
    }
    put_npy("exp.npy", e2, 1, 2);
  }
  {   /* the descriptor, feedthrough, damper and reference files: a mass matrix
         (p1, p2 coupled), the same with p2 massless (index one), E as triplets,
         P, S, N, two dampers, a reference state; ln_d.npy a link to d.npy */
    static const double E4[16] = {1, 0, 0, 0, 0, 1, 0, 0.1, 0, 0, 1, 0, 0, 0.1, 0, 1};
    static const double Ea[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0};
    static const double Ec[12] = {0, 1, 2, 3, 0, 1, 2, 3, 1, 1, 1, 1};
    static const double P4[4] = {0, 0.1, 0, 0}, S1[1] = {0.2}, N1[1] = {0};
    static const double D[8] = {1, 3, -1, 1, 0.1, 0.05, 1, 0.5}, ref[4] = {0.1, 0, 0.1, 0};
    char path[256];
    put_npy("E.npy", E4, 4, 4); put_npy("E_alg.npy", Ea, 4, 4); put_npy("Ec.npy", Ec, 4, 3);
    put_npy("P.npy", P4, 4, 1); put_npy("S.npy", S1, 1, 1); put_npy("N.npy", N1, 1, 1);
    put_npy("d.npy", D, 2, 4); put_npy("ref.npy", ref, 4, 1);
    snprintf(path, sizeof path, "%s/ln_d.npy", g_dir);
    if (symlink("d.npy", path) != 0) fz_die("symlink");
  }
  put_bytes("garbage.npy", "not an npy file", 15);
  if (g_rom) put_bytes("m.phgmgrom", g_rom, g_rom_len);
  {
    char path[256];
    snprintf(path, sizeof path, "%s/adir", g_dir);
    mkdir(path, 0700);
  }
}

static void init(void) {
  static const char *const words[] = {
    "reduce", "simulate-rom", "info", "--help", "--version", "--J", "--R", "--B", "--Q", "--X",
    "--simulate", "--dt", "--steps", "--input", "--amp", "--newton-tol", "--newton-iter", "--method",
    "gmg-pod", "gmg-qm", "sp1", "sp2", "--r", "--rn", "--lambda", "--poly", "--poly-idx", "--poly-w",
    "--no-deim", "--deim-tol", "--deim-max", "--deim-allow-negative", "--dt-map", "--out", "--name",
    "--save-snapshots", "--quiet", "--model", "--states", "sin", "const", "square", "0", "1", "2", "3",
    "-1", "0.1", "0.05", "1e-320", "1e999", "nan", "2147483646", "1x", "", "int", "m", NULL};
  static const char *const files[] = {"J.npy", "R.npy", "Q.npy", "B.npy", "X.npy", "poly.npy", "idx.npy",
                                      "idx_i8.npy", "u.npy", "garbage.npy", "m.phgmgrom", "adir", "o",
                                      "y.npy", "xr.npy", "nofile.npy", "o/m.phgmgrom", NULL};
  /* appended after the first vocabulary, so that the seeds written for it
     (bytes below its size) keep their meaning */
  static const char *const words2[] = {
    "validate", "--J-coo", "--R-coo", "--Q-coo", "--potential", "--exp", "--train-input", "--X-input",
    "--manifold", "--hyper", "--hyper-tol", "--test-input", "--test-amp", "--test-steps", "--max-ey",
    "toda", "fpu:1:1", "fpu::", "morse:1:2", "morse:-1:1", "cosh:1", "cosh:1e-200", "ecsw", "qdeim", "greedy",
    "pod", "altmin", "auto", "cv", "1e-300", "1e160", "1e15", "rom", "--E", "--E-coo", "--P", "--S", "--N", "--dampers", "--no-hyper", NULL};
  static const char *const files2[] = {"Jc.npy", "Rc.npy", "Qc.npy", "exp.npy", "o/rom.phgmgrom", "o/rom_V0.npy",
                                       "o/rom.json", NULL};
  static const char *const words3[] = {"--ref", "mean", "none", "wide", "--greedy-window", NULL};   /* after files2: seeds keep their meaning */
  static const char *const words4[] = {"simulate", "1e300", "1e308", NULL};   /* after words3 */
  static const char *const files4[] = {"E.npy", "E_alg.npy", "Ec.npy", "P.npy", "S.npy", "N.npy", "d.npy", "ref.npy",
                                       "ln_d.npy", NULL};
  static const char *const words5[] = {"--degeneracy-tol", NULL};   /* after files4 */
  static const char *const words6[] = {"--freq", "--freq-end", "--x0", "chirp", "gmg-pod,sp1", "4,6", "4,,6",
                                       "2,3,2", NULL};   /* after words5 */
  static const char *const words7[] = {"--stream", "bt", "prbt", "phbt", "bt,sp1", NULL};   /* after words6 */
  static const char *const words8[] = {"--poly-jdx", NULL};   /* after words7 */
  static const char *const files8[] = {"jdx.npy", NULL};
  static const char *const words9[] = {"--adi-maxit", NULL};   /* after files8 */
  static const char *const words10[] = {"--lyap", "adi", "eksm", NULL};   /* after words9 */
  static const char *const words11[] = {"--form", "ph", "ss", "--ss", NULL};   /* after words10 */
  char *argv[24];
  int k, fb, argc = 0;   /* fb: the token of files[0] */
  FILE *f;
  long n;
  char path[256];
  strcpy(g_dir, "/tmp/phgmg_fuzz_cli_XXXXXX");
  if (!mkdtemp(g_dir)) fz_die("mkdtemp");
  atexit(cleanup);
  for (k = 0; words[k]; ++k) strcpy(g_tok[g_ntok++], words[k]);
  fb = g_ntok;
  for (k = 0; files[k]; ++k) snprintf(g_tok[g_ntok++], sizeof g_tok[0], "%s/%s", g_dir, files[k]);
  for (k = 0; words2[k]; ++k) strcpy(g_tok[g_ntok++], words2[k]);
  for (k = 0; files2[k]; ++k) snprintf(g_tok[g_ntok++], sizeof g_tok[0], "%s/%s", g_dir, files2[k]);
  for (k = 0; words3[k]; ++k) strcpy(g_tok[g_ntok++], words3[k]);
  for (k = 0; words4[k]; ++k) strcpy(g_tok[g_ntok++], words4[k]);
  for (k = 0; files4[k]; ++k) snprintf(g_tok[g_ntok++], sizeof g_tok[0], "%s/%s", g_dir, files4[k]);
  for (k = 0; words5[k]; ++k) strcpy(g_tok[g_ntok++], words5[k]);
  for (k = 0; words6[k]; ++k) strcpy(g_tok[g_ntok++], words6[k]);
  for (k = 0; words7[k]; ++k) strcpy(g_tok[g_ntok++], words7[k]);
  for (k = 0; words8[k]; ++k) strcpy(g_tok[g_ntok++], words8[k]);
  for (k = 0; files8[k]; ++k) snprintf(g_tok[g_ntok++], sizeof g_tok[0], "%s/%s", g_dir, files8[k]);
  for (k = 0; words9[k]; ++k) strcpy(g_tok[g_ntok++], words9[k]);
  for (k = 0; words10[k]; ++k) strcpy(g_tok[g_ntok++], words10[k]);
  for (k = 0; words11[k]; ++k) strcpy(g_tok[g_ntok++], words11[k]);
  /* the model file, made once by the CLI itself */
  restore();
  argv[argc++] = (char *)"phgmg"; argv[argc++] = (char *)"reduce";
  argv[argc++] = (char *)"--J"; argv[argc++] = g_tok[fb + 0];
  argv[argc++] = (char *)"--R"; argv[argc++] = g_tok[fb + 1];
  argv[argc++] = (char *)"--Q"; argv[argc++] = g_tok[fb + 2];
  argv[argc++] = (char *)"--B"; argv[argc++] = g_tok[fb + 3];
  argv[argc++] = (char *)"--X"; argv[argc++] = g_tok[fb + 4];
  argv[argc++] = (char *)"--dt-map"; argv[argc++] = (char *)"0.1";
  argv[argc++] = (char *)"--method"; argv[argc++] = (char *)"gmg-pod";
  argv[argc++] = (char *)"--r"; argv[argc++] = (char *)"3";
  argv[argc++] = (char *)"--out"; argv[argc++] = g_tok[fb + 12];
  argv[argc++] = (char *)"--quiet";
  argv[argc] = NULL;
  if (chdir(g_dir) != 0) fz_die("chdir");
  if (phgmg_cli_main(argc, argv) != 0) fz_die("cannot make the scratch model");
  if (fchdir(g_home) != 0) fz_die("fchdir");
  snprintf(path, sizeof path, "%s/o/rom.phgmgrom", g_dir);
  f = fopen(path, "rb");
  if (!f || fseek(f, 0, SEEK_END) != 0 || (n = ftell(f)) <= 0 || fseek(f, 0, SEEK_SET) != 0)
    fz_die("no scratch model");
  g_rom = (unsigned char *)malloc((size_t)n);
  if (!g_rom || fread(g_rom, 1, (size_t)n, f) != (size_t)n) fz_die("cannot read the scratch model");
  g_rom_len = (size_t)n;
  fclose(f);
}

/* The invariant checked after every run: no file the command line names as
   an input (the value after an input option: input_opts, input_lists,
   --model, --test-input) is changed or removed by the run. */
#define SNAP_MAX 24
typedef struct snap { const char *path; unsigned char *b; long n; } snap;

static int is_input_opt(const char *o) {
  int k;
  if (input_opt_find(o, 0) >= 0 || !strcmp(o, "--ref") || !strcmp(o, "--model") || !strcmp(o, "--test-input")) return 1;
  for (k = 0; input_lists[k].opt; ++k)
    if (!strcmp(o, input_lists[k].opt)) return 1;
  return 0;
}

/* The bytes of a regular file (up to 1 MB), -1 if there is none. */
static long read_all(const char *path, unsigned char **b) {
  struct stat st;
  FILE *f;
  long n;
  *b = NULL;
  if (stat(path, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size > (1L << 20)) return -1;
  if (!(f = fopen(path, "rb"))) return -1;
  n = (long)st.st_size;
  *b = (unsigned char *)malloc((size_t)n + 1);
  if (!*b || (long)fread(*b, 1, (size_t)n, f) != n) { fclose(f); free(*b); *b = NULL; return -1; }
  fclose(f);
  return n;
}

static int snap_inputs(int argc, char **argv, snap *sn) {
  int i, n = 0;
  for (i = 1; i + 1 < argc && n < SNAP_MAX; ++i)
    if (is_input_opt(argv[i]) && (sn[n].n = read_all(argv[i + 1], &sn[n].b)) >= 0) sn[n++].path = argv[i + 1];
  return n;
}

static void check_inputs(snap *sn, int n) {
  int k;
  for (k = 0; k < n; ++k) {
    unsigned char *now;
    const long m = read_all(sn[k].path, &now);
    if (m != sn[k].n || (m > 0 && memcmp(now, sn[k].b, (size_t)m) != 0)) {
      fprintf(stderr, "fuzz_cli: invariant violated: the input %s was changed or removed by the run\n", sn[k].path);
      abort();
    }
    free(now);
    free(sn[k].b);
  }
}

/* File mode (an input starting with 0xFF): byte 1 picks one of the files
   below, the rest of the input is its new content, and the command line
   that reads it runs -- the content of the descriptor, feedthrough, damper
   and reference files fuzzed. */
static int file_mode_argv(const uint8_t *data, size_t size, char **argv) {
  static const char *const target[] = {"d.npy", "E.npy", "Ec.npy", "P.npy", "S.npy", "N.npy", "ref.npy", "E.npy",
                                       "d.npy"};
  static const char *const extra[] = {"--dampers", "--E", "--E-coo", "--P", "--S", "--N", "--ref", "--E", "--dampers"};
  const int k = data[1] % 9, red = k >= 6;
  static char file[256], jc[256], rc[256], qc[256], cj[256], cr[256], cq[256], cb[256], cx[256], co[256];
  int argc = 0;
  snprintf(file, sizeof file, "%s/%s", g_dir, target[k]);
  put_bytes(target[k], data + 2, size - 2);
  snprintf(cj, sizeof cj, "%s/J.npy", g_dir); snprintf(cr, sizeof cr, "%s/R.npy", g_dir);
  snprintf(cq, sizeof cq, "%s/Q.npy", g_dir); snprintf(cb, sizeof cb, "%s/B.npy", g_dir);
  snprintf(jc, sizeof jc, "%s/Jc.npy", g_dir); snprintf(rc, sizeof rc, "%s/Rc.npy", g_dir);
  snprintf(qc, sizeof qc, "%s/Qc.npy", g_dir); snprintf(cx, sizeof cx, "%s/X.npy", g_dir);
  snprintf(co, sizeof co, "%s/o", g_dir);
  argv[argc++] = (char *)"phgmg";
  argv[argc++] = (char *)(red ? "reduce" : "simulate");
  argv[argc++] = (char *)(k == 2 ? "--J-coo" : "--J"); argv[argc++] = k == 2 ? jc : cj;
  argv[argc++] = (char *)(k == 2 ? "--R-coo" : "--R"); argv[argc++] = k == 2 ? rc : cr;
  argv[argc++] = (char *)(k == 2 ? "--Q-coo" : "--Q"); argv[argc++] = k == 2 ? qc : cq;
  argv[argc++] = (char *)"--B"; argv[argc++] = cb;
  argv[argc++] = (char *)extra[k]; argv[argc++] = file;
  if (red) {
    argv[argc++] = (char *)(k == 8 ? "--simulate" : "--X");
    if (k != 8) argv[argc++] = cx;
    argv[argc++] = (char *)"--method"; argv[argc++] = (char *)(k == 7 ? "sp1" : "gmg-pod");
    argv[argc++] = (char *)"--r"; argv[argc++] = (char *)"3";
  }
  argv[argc++] = (char *)"--steps"; argv[argc++] = (char *)"3";
  argv[argc++] = (char *)"--out"; argv[argc++] = red ? co : (char *)"y.npy";
  if (!red) { argv[argc++] = (char *)"--states"; argv[argc++] = (char *)"x.npy"; }
  argv[argc] = NULL;
  return argc;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  char *argv[50];
  snap sn[SNAP_MAX];
  int argc = 0, nsn;
  size_t i;
  if (g_home < 0 && (g_home = open(".", O_RDONLY)) < 0) fz_die("cannot open the working directory");
  if (!g_dir[0]) init();
  restore();
  if (size >= 2 && data[0] == 0xFF) {
    argc = file_mode_argv(data, size, argv);
  } else {
    argv[argc++] = (char *)"phgmg";
    for (i = 0; i < size && argc < 49; ++i) argv[argc++] = g_tok[data[i] % g_ntok];
    argv[argc] = NULL;
  }
  g_quiet = 0;
  fflush(stdout);
  if (chdir(g_dir) != 0) fz_die("chdir");
  nsn = snap_inputs(argc, argv, sn);
  (void)phgmg_cli_main(argc, argv);
  check_inputs(sn, nsn);
  if (fchdir(g_home) != 0) fz_die("fchdir");
  fflush(stdout);
  return 0;
}

#define FUZZ_NAME "fuzz_cli"
#define FUZZ_MAX_INPUT 1024   /* the replay reads at most this much of a corpus file (file mode: a .npy) */
#include "fuzz_main.h"
