/* Fuzz harness for the binary model format (phgmg_rom_deserialize_size,
   phgmg_rom_deserialize), the other reader of outside data in phgmg.h, and
   for the online path on whatever it accepts. For each input:
   - the size query and the loader must agree, and only PHGMG_ERR_FORMAT (or
     PHGMG_ERR_WORKSPACE when the model does not fit the harness's static
     memory; from the loader also PHGMG_ERR_STRUCTURE, _DAMPER or
     _FEEDTHROUGH, the load-time physics check of an intact file) may come back on failure, with the output model
     untouched;
   - a loaded model must pass phgmg_rom_check, serialise back to the same
     bytes when the file's scalar size is the build's, and reload identically;
   - every online evaluator and a few phgmg_rom_step calls run on it, with the
     model, the evaluation work and the stepper memory in heap blocks of
     exactly the size the size queries give (so ASan sees any overrun of
     them), with the model's own dt and with another one: no crash, no
     sanitizer report; a failed step leaves x untouched, a successful one gives
     a finite x.
   Every input is also tried with its trailing checksum recomputed, so that
   mutations get past the FNV-1a check to the header and value checks.

   libFuzzer (clang; tests/fuzz/run.sh does this):
     clang -g -O1 -fsanitize=fuzzer,address,undefined tests/fuzz/fuzz_rom.c \
           -o build/fuzz_rom -lm
     ./build/fuzz_rom -max_total_time=600 build/fuzz/corpus_rom tests/fuzz/corpus/rom
   Add -DPHGMG_REAL_FLOAT for the float build (files with 8-byte scalars are
   then rounded once while loading).
   Plain driver (any C compiler; runs every file named on the command line):
     gcc -std=c99 -g -O1 -fsanitize=address,undefined tests/fuzz/fuzz_rom.c \
           -o build/fuzz_rom_run -lm
     ./build/fuzz_rom_run $(ls -d tests/fuzz/corpus/rom/[!.]*)
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

#define FZ_HDR 56                 /* header bytes of the format        */
#define FZ_MAXLEN (1u << 20)      /* inputs longer than this: checksum left as is */
#define FZ_MAXMEM ((size_t)1 << 22) /* larger models are only loaded       */
static double fz_model2[1 << 16]; /* the reloaded copy                 */
static phgmg_real fz_x[4096], fz_x0[4096], fz_v[4096], fz_u3[3 * 4096], fz_y[4096];
static phgmg_real fz_M1[1 << 14], fz_M2[1 << 14];
static unsigned char fz_buf[FZ_MAXLEN], fz_out[FZ_MAXLEN];

static void fuzz_check(int ok, const char *what) {
  if (!ok) {
    fprintf(stderr, "fuzz_rom: invariant violated: %s\n", what);
    abort();
  }
}

static int fz_finite(const phgmg_real *a, int n) {
  int i;
  for (i = 0; i < n; ++i)
    if (!(a[i] - a[i] == (phgmg_real)0)) return 0;
  return 1;
}

/* A few steps of dt from a small and from a large state, with exactly
   phgmg_rom_stepper_memsize_dt bytes: Newton may fail, nothing may break. */
static void fz_steps(const phgmg_rom *rom, phgmg_real dt) {
  const int r = rom->r, m = rom->m;
  const size_t msz = phgmg_rom_stepper_memsize_dt(rom, dt);
  phgmg_rom_stepper st;
  void *mem;
  int i, n, start;
  fuzz_check(msz > 0, "stepper memsize of a checked model");
  fuzz_check(msz <= PHGMG_ROM_STEPPER_MEMSIZE_MAX(r, m, rom->rn, rom->nd), "memsize above the compile-time bound");
  if (msz > FZ_MAXMEM) return;
  mem = malloc(msz);
  fuzz_check(mem != NULL, "malloc");
  for (start = 0; start < 2; ++start) {
    phgmg_real en[2] = {0, 0};
    phgmg_result rc = phgmg_rom_stepper_init(&st, rom, dt, 0, 4, mem, msz);
    if (rc != PHGMG_OK) {
      fuzz_check(rc == PHGMG_ERR_INVALID_ARG && !(dt - dt == (phgmg_real)0 && dt > (phgmg_real)0),
                 "stepper init refused a checked model");
      break;
    }
    for (i = 0; i < r; ++i) fz_x[i] = (phgmg_real)((start ? 100.0 : 0.01) * (i % 5 - 2));
    for (n = 0; n < 3; ++n) {
      memcpy(fz_x0, fz_x, sizeof(phgmg_real) * (size_t)r);
      rc = phgmg_rom_step(&st, fz_x, fz_u3, m > 0 ? fz_y : NULL, en);
      if (rc == PHGMG_OK) {
        fuzz_check(fz_finite(fz_x, r), "a successful step gave a non-finite state");
      } else {
        fuzz_check(rc == PHGMG_ERR_NOT_CONVERGED || rc == PHGMG_ERR_NANINF || rc == PHGMG_ERR_SINGULAR,
                   "unexpected step result");
        fuzz_check(memcmp(fz_x0, fz_x, sizeof(phgmg_real) * (size_t)r) == 0, "a failed step changed x");
        break;
      }
    }
  }
  free(mem);
}

static void fz_online(const phgmg_rom *rom) {
  const int r = rom->r, m = rom->m;
  const size_t wsz = phgmg_rom_eval_work_size(rom);
  int i;
  for (i = 0; i < 3 * m; ++i) fz_u3[i] = (phgmg_real)(0.1 * (i % 3 - 1));
  if (wsz * sizeof(phgmg_real) <= FZ_MAXMEM && (size_t)r * (size_t)r <= sizeof fz_M1 / sizeof fz_M1[0]) {
    phgmg_real h, *work = (phgmg_real *)malloc((wsz ? wsz : 1) * sizeof(phgmg_real));
    fuzz_check(work != NULL, "malloc");
    for (i = 0; i < r; ++i) fz_x[i] = (phgmg_real)(0.1 * (i + 1));
    h = phgmg_rom_hamiltonian(rom, fz_x, work);
    (void)h;
    phgmg_rom_gradient(rom, fz_x, fz_v, work);
    (void)phgmg_rom_rhs(rom, fz_x, fz_u3, fz_v, work);
    if (m > 0) phgmg_rom_output(rom, fz_x, fz_v, work);
    (void)phgmg_rom_structure(rom, fz_x, fz_M1, fz_M2, work);
    (void)phgmg_rom_jacobian(rom, fz_x, fz_M1, work);
    free(work);
  }
  /* with the model's own step (its step map, if any) and with another one */
  fz_steps(rom, rom->Phi ? rom->dt : (phgmg_real)0.1);
  fz_steps(rom, rom->Phi ? rom->dt * (phgmg_real)0.5 : (phgmg_real)0.05);
}

static void fz_one(const uint8_t *data, size_t size) {
  size_t need = 0, w = 0;
  void *model;
  phgmg_rom rom, back, keep;
  phgmg_result rc, rc2;
  memset(&rom, 0xa5, sizeof rom);
  keep = rom;
  rc = phgmg_rom_deserialize_size(data, size, &need);
  if (rc != PHGMG_OK) {
    fuzz_check(rc == PHGMG_ERR_FORMAT, "size query: unexpected result");
    rc2 = phgmg_rom_deserialize(data, size, &rom, fz_model2, sizeof fz_model2);
    fuzz_check(rc2 == rc, "size query and loader disagree");
    fuzz_check(memcmp(&rom, &keep, sizeof rom) == 0, "model changed on failure");
    return;
  }
  /* the model's values (at most size / 4 reals) plus the structure check's
     scratch ((r + rn)^2 + 4 r + 4 reals, at most about 5 times the values) */
  fuzz_check(need >= sizeof(phgmg_real) && need <= (6 * (size / 4 + 1) + 8) * sizeof(phgmg_real),
             "size query: implausible size");
  model = malloc(need);
  fuzz_check(model != NULL, "malloc");
  rc = phgmg_rom_deserialize(data, size, &rom, model, need - 1);
  fuzz_check(rc == PHGMG_ERR_WORKSPACE && memcmp(&rom, &keep, sizeof rom) == 0, "too small memory not reported");
  rc = phgmg_rom_deserialize(data, size, &rom, model, need);
  if (rc != PHGMG_OK) {
    fuzz_check(rc == PHGMG_ERR_FORMAT || rc == PHGMG_ERR_STRUCTURE || rc == PHGMG_ERR_DAMPER ||
               rc == PHGMG_ERR_FEEDTHROUGH, "loader: unexpected result");
    fuzz_check(memcmp(&rom, &keep, sizeof rom) == 0, "model changed on failure");
    free(model);
    return;
  }
  fuzz_check(phgmg_rom_check(&rom) == PHGMG_OK, "a loaded model fails phgmg_rom_check");
  /* round trip */
  fuzz_check(phgmg_rom_serialized_size(&rom) <= sizeof fz_out, "serialized size");
  rc = phgmg_rom_serialize(&rom, fz_out, sizeof fz_out, &w);
  fuzz_check(rc == PHGMG_OK && w == phgmg_rom_serialized_size(&rom), "re-serialize");
  /* same scalar size: the same bytes (in a float build the header's double dt
     is rounded to float once, so bytes 48..55 may differ there) */
  if (data[12] == sizeof(phgmg_real)) {
    fuzz_check(w == size && memcmp(fz_out, data, 48) == 0 && memcmp(fz_out + 56, data + 56, size - 60) == 0,
               "round trip bytes");
    if (!PHGMG_REAL_IS_FLOAT) fuzz_check(memcmp(fz_out, data, size) == 0, "round trip bytes (dt, checksum)");
  }
  rc = phgmg_rom_deserialize(fz_out, w, &back, fz_model2, sizeof fz_model2);
  fuzz_check(rc == PHGMG_OK, "reload of a re-serialized model");
  fuzz_check(back.kind == rom.kind && back.r == rom.r && back.m == rom.m && back.rn == rom.rn && back.nd == rom.nd,
             "reloaded sizes");
  fz_online(&rom);
  free(model);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static const uint8_t empty[1] = {0};
  if (!data) data = empty;
  fz_one(data, size);
  if (size >= FZ_HDR + 4 && size <= FZ_MAXLEN) {
    /* the same bytes with a valid checksum (FNV-1a over all but the last 4) */
    uint32_t h = 2166136261u;
    size_t i;
    memcpy(fz_buf, data, size);
    for (i = 0; i + 4 < size; ++i) { h ^= fz_buf[i]; h *= 16777619u; }
    for (i = 0; i < 4; ++i) fz_buf[size - 4 + i] = (unsigned char)(h >> (8 * i));
    if (memcmp(fz_buf + size - 4, data + size - 4, 4) != 0) fz_one(fz_buf, size);
  }
  return 0;
}

#define FUZZ_NAME "fuzz_rom"
#include "fuzz_main.h"
