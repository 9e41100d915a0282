
/* >>export (implementation) ============================================== */
#include <stdint.h>

/* The arrays of a phgmg_rom in file order, with their sizes. */
#define PHGMG__NFIELDS 18
typedef struct phgmg__field { size_t off; const char *name; } phgmg__field;
static const phgmg__field phgmg__fields[PHGMG__NFIELDS] = {
  {offsetof(phgmg_rom, Bh), "Bh"},   {offsetof(phgmg_rom, Qh), "Qh"},   {offsetof(phgmg_rom, K), "K"},
  {offsetof(phgmg_rom, G00), "G00"}, {offsetof(phgmg_rom, G01), "G01"}, {offsetof(phgmg_rom, G10), "G10"},
  {offsetof(phgmg_rom, G11), "G11"}, {offsetof(phgmg_rom, Q01), "Q01"}, {offsetof(phgmg_rom, Q11), "Q11"},
  {offsetof(phgmg_rom, Ms), "Ms"},   {offsetof(phgmg_rom, P0), "P0"},   {offsetof(phgmg_rom, P1), "P1"},
  {offsetof(phgmg_rom, w), "w"},     {offsetof(phgmg_rom, poly), "poly"}, {offsetof(phgmg_rom, Phi), "Phi"},
  {offsetof(phgmg_rom, Gam), "Gam"}, {offsetof(phgmg_rom, SX), "SX"},   {offsetof(phgmg_rom, SU), "SU"}};

PHGMG__ONLINE const phgmg_real **phgmg__field_ptr(phgmg_rom *rom, int i) {
  return PHGMG__CAST(const phgmg_real **, PHGMG__CAST(void *, PHGMG__CAST(char *, PHGMG__CAST(void *, rom)) + phgmg__fields[i].off));
}
PHGMG__ONLINE const phgmg_real *phgmg__field_get(const phgmg_rom *rom, int i) {
  return *PHGMG__CAST(const phgmg_real *const *, PHGMG__CAST(const void *, PHGMG__CAST(const char *, PHGMG__CAST(const void *, rom)) + phgmg__fields[i].off));
}
/* Number of scalars of field i (0 if the field does not apply). */
PHGMG__ONLINE size_t phgmg__field_len(const phgmg_rom *rom, int i) {
  const size_t r = (size_t)rom->r, m = (size_t)rom->m, rn = (size_t)rom->rn, nd = (size_t)rom->nd;
  const size_t p = (size_t)(rom->r - rom->m);
  switch (i) {
    case 0: return r * m;
    case 1: return r * r;
    case 2: return r * r;
    case 3: return r * r;
    case 4: return r * rn;
    case 5: return rn * r;
    case 6: return rn * rn;
    case 7: return r * rn;
    case 8: return rn * rn;
    case 9: return rn * p * p;
    case 10: return nd * r;
    case 11: return nd * rn;
    case 12: return nd;
    case 13: return nd ? (size_t)rom->poly_deg + 1 : 0;
    case 14: return r * r;
    case 15: return r * 3 * m;
    case 16: return 3 * r * r;
    default: return 3 * r * 3 * m;
  }
}

#define PHGMG__HDR_BYTES (8 + 4 * 10 + 8)

PHGMG__ONLINE void phgmg__put32(unsigned char *b, uint32_t v) {
  b[0] = (unsigned char)(v & 255u); b[1] = (unsigned char)((v >> 8) & 255u);
  b[2] = (unsigned char)((v >> 16) & 255u); b[3] = (unsigned char)((v >> 24) & 255u);
}
PHGMG__ONLINE uint32_t phgmg__get32(const unsigned char *b) {
  return (uint32_t)b[0] | ((uint32_t)b[1] << 8) | ((uint32_t)b[2] << 16) | ((uint32_t)b[3] << 24);
}
PHGMG__ONLINE void phgmg__put_f64(unsigned char *b, double v) {
  uint64_t u;
  int i;
  memcpy(&u, &v, 8);
  for (i = 0; i < 8; ++i) b[i] = (unsigned char)((u >> (8 * i)) & 255u);
}
PHGMG__ONLINE double phgmg__get_f64(const unsigned char *b) {
  uint64_t u = 0;
  double v;
  int i;
  for (i = 0; i < 8; ++i) u |= (uint64_t)b[i] << (8 * i);
  memcpy(&v, &u, 8);
  return v;
}
PHGMG__ONLINE void phgmg__put_f32(unsigned char *b, float v) {
  uint32_t u;
  memcpy(&u, &v, 4);
  phgmg__put32(b, u);
}
PHGMG__ONLINE float phgmg__get_f32(const unsigned char *b) {
  uint32_t u = phgmg__get32(b);
  float v;
  memcpy(&v, &u, 4);
  return v;
}
PHGMG__ONLINE uint32_t phgmg__fnv1a(const unsigned char *b, size_t n) {
  uint32_t h = 2166136261u;
  size_t i;
  for (i = 0; i < n; ++i) { h ^= b[i]; h *= 16777619u; }
  return h;
}

PHGMG_DEF size_t phgmg_rom_serialized_size(const phgmg_rom *rom) {
  size_t n = 0;
  int i;
  for (i = 0; i < PHGMG__NFIELDS; ++i)
    if (phgmg__field_get(rom, i)) n += phgmg__field_len(rom, i);
  return PHGMG__HDR_BYTES + n * sizeof(phgmg_real) + 4;
}

PHGMG_DEF phgmg_result phgmg_rom_serialize(const phgmg_rom *rom, void *buf, size_t cap, size_t *written) {
  unsigned char *b = PHGMG__CAST(unsigned char *, buf);
  size_t need, o;
  uint32_t mask = 0;
  int i;
  phgmg_result rc = phgmg_rom_check(rom);
  if (rc != PHGMG_OK) return rc;
  if (!buf) return PHGMG_ERR_INVALID_ARG;
  need = phgmg_rom_serialized_size(rom);
  if (cap < need) return PHGMG_ERR_WORKSPACE;
  for (i = 0; i < PHGMG__NFIELDS; ++i)
    if (phgmg__field_get(rom, i)) mask |= 1u << i;
  memcpy(b, "PHGMGROM", 8);
  phgmg__put32(b + 8, PHGMG_ROM_FORMAT_VERSION);
  phgmg__put32(b + 12, (uint32_t)sizeof(phgmg_real));
  phgmg__put32(b + 16, (uint32_t)rom->kind);
  phgmg__put32(b + 20, (uint32_t)rom->method);
  phgmg__put32(b + 24, (uint32_t)rom->r);
  phgmg__put32(b + 28, (uint32_t)rom->m);
  phgmg__put32(b + 32, (uint32_t)rom->rn);
  phgmg__put32(b + 36, (uint32_t)rom->nd);
  phgmg__put32(b + 40, (uint32_t)rom->poly_deg);
  phgmg__put32(b + 44, mask);
  phgmg__put_f64(b + 48, (double)rom->dt);
  o = PHGMG__HDR_BYTES;
  for (i = 0; i < PHGMG__NFIELDS; ++i) {
    const phgmg_real *a = phgmg__field_get(rom, i);
    size_t k, n = phgmg__field_len(rom, i);
    if (!a) continue;
    for (k = 0; k < n; ++k, o += sizeof(phgmg_real)) {
#if PHGMG_REAL_IS_FLOAT
      phgmg__put_f32(b + o, a[k]);
#else
      phgmg__put_f64(b + o, a[k]);
#endif
    }
  }
  phgmg__put32(b + o, phgmg__fnv1a(b, o));
  if (written) *written = o + 4;
  return PHGMG_OK;
}

/* Parse and validate the header; fills rom's scalars and returns the scalar
   count of the payload and the file's scalar size. */
PHGMG__ONLINE phgmg_result phgmg__rom_header(const unsigned char *b, size_t len, phgmg_rom *rom,
                                             size_t *nscal, size_t *ssize, uint32_t *mask_out) {
  uint32_t ver, ss, mask;
  size_t n = 0, total;
  int i;
  if (!b) return PHGMG_ERR_INVALID_ARG;
  if (len < PHGMG__HDR_BYTES + 4 || memcmp(b, "PHGMGROM", 8) != 0) return PHGMG_ERR_FORMAT;
  ver = phgmg__get32(b + 8);
  ss = phgmg__get32(b + 12);
  if (ver != PHGMG_ROM_FORMAT_VERSION || (ss != 4 && ss != 8)) return PHGMG_ERR_FORMAT;
  memset(rom, 0, sizeof *rom);
  if (phgmg__get32(b + 24) > 4096u || phgmg__get32(b + 28) > 4096u || phgmg__get32(b + 32) > 4096u ||
      phgmg__get32(b + 36) > (1u << 24) || phgmg__get32(b + 40) > 32u || phgmg__get32(b + 16) > 2u ||
      phgmg__get32(b + 20) > 4u)
    return PHGMG_ERR_FORMAT;
  rom->kind = (int)phgmg__get32(b + 16);
  rom->method = (int)phgmg__get32(b + 20);
  rom->r = (int)phgmg__get32(b + 24);
  rom->m = (int)phgmg__get32(b + 28);
  rom->rn = (int)phgmg__get32(b + 32);
  rom->nd = (int)phgmg__get32(b + 36);
  rom->poly_deg = (int)phgmg__get32(b + 40);
  mask = phgmg__get32(b + 44);
  {
    double dt = phgmg__get_f64(b + 48);
    if (!(dt >= 0.0) || dt > 1e300) return PHGMG_ERR_FORMAT;
#if PHGMG_REAL_IS_FLOAT
    if (dt > 3.4e38) return PHGMG_ERR_FORMAT; /* would be Inf as float */
#endif
    rom->dt = (phgmg_real)dt;
  }
  if (mask >> PHGMG__NFIELDS) return PHGMG_ERR_FORMAT;
  if (rom->m > rom->r) return PHGMG_ERR_FORMAT;
  for (i = 0; i < PHGMG__NFIELDS; ++i)
    if (mask & (1u << i)) {
      size_t k = phgmg__field_len(rom, i);
      if (k > ((size_t)1 << 28)) return PHGMG_ERR_FORMAT;
      n += k;
    }
  if (n > (len / ss)) return PHGMG_ERR_FORMAT;
  total = PHGMG__HDR_BYTES + n * ss + 4;
  if (total != len) return PHGMG_ERR_FORMAT;
  if (phgmg__get32(b + total - 4) != phgmg__fnv1a(b, total - 4)) return PHGMG_ERR_FORMAT;
  *nscal = n;
  *ssize = ss;
  *mask_out = mask;
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_rom_deserialize_size(const void *buf, size_t len, size_t *need) {
  phgmg_rom tmp;
  size_t n = 0, ss = 0;
  uint32_t mask = 0;
  phgmg_result rc = phgmg__rom_header(PHGMG__CAST(const unsigned char *, buf), len, &tmp, &n, &ss, &mask);
  if (rc != PHGMG_OK) return rc;
  if (need) *need = n * sizeof(phgmg_real) + sizeof(phgmg_real);
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_rom_deserialize(const void *buf, size_t len, phgmg_rom *rom, void *mem,
                                             size_t mem_size) {
  const unsigned char *b = PHGMG__CAST(const unsigned char *, buf);
  phgmg_rom tmp;
  size_t n = 0, ss = 0, o = PHGMG__HDR_BYTES, k;
  uint32_t mask = 0;
  phgmg_real *dst = PHGMG__CAST(phgmg_real *, mem);
  phgmg_result rc;
  int i;
  if (!rom || !mem) return PHGMG_ERR_INVALID_ARG;
  rc = phgmg__rom_header(b, len, &tmp, &n, &ss, &mask);
  if (rc != PHGMG_OK) return rc;
  if (mem_size < n * sizeof(phgmg_real) + sizeof(phgmg_real)) return PHGMG_ERR_WORKSPACE;
  if (((size_t)mem) % sizeof(phgmg_real) != 0) return PHGMG_ERR_INVALID_ARG;
  for (i = 0; i < PHGMG__NFIELDS; ++i) {
    const size_t len_i = phgmg__field_len(&tmp, i);
    if (!(mask & (1u << i))) { *phgmg__field_ptr(&tmp, i) = NULL; continue; }
    for (k = 0; k < len_i; ++k, o += ss)
      dst[k] = ss == 8 ? (phgmg_real)phgmg__get_f64(b + o) : (phgmg_real)phgmg__get_f32(b + o);
    if (!phgmg__r_finite(dst, (int)len_i)) return PHGMG_ERR_FORMAT;
    *phgmg__field_ptr(&tmp, i) = dst;
    dst += len_i;
  }
  rc = phgmg_rom_check(&tmp);
  if (rc != PHGMG_OK) return PHGMG_ERR_FORMAT;
  /* fields required by the kind must be present, others absent */
  if ((tmp.kind == PHGMG_ROM_QUADRATIC) != (tmp.Ms != NULL) || (tmp.nd == 0 && (tmp.P0 || tmp.w)))
    return PHGMG_ERR_FORMAT;
  *rom = tmp;
  return PHGMG_OK;
}

#if !defined(PHGMG_NO_STDIO) && !defined(PHGMG_NO_OFFLINE)
#include <stdio.h>
PHGMG_DEF phgmg_result phgmg_rom_save(const phgmg_rom *rom, const char *path) {
  size_t n, w = 0;
  void *buf;
  FILE *f;
  phgmg_result rc = phgmg_rom_check(rom);
  if (rc != PHGMG_OK) return rc;
  if (!path) return PHGMG_ERR_INVALID_ARG;
  n = phgmg_rom_serialized_size(rom);
  buf = phgmg__alloc(NULL, n);
  if (!buf) return PHGMG_ERR_NOMEM;
  rc = phgmg_rom_serialize(rom, buf, n, &w);
  if (rc == PHGMG_OK) {
    f = fopen(path, "wb");
    if (!f) rc = PHGMG_ERR_IO;
    else {
      if (fwrite(buf, 1, w, f) != w) rc = PHGMG_ERR_IO;
      if (fclose(f) != 0) rc = PHGMG_ERR_IO;
    }
  }
  phgmg__free(NULL, buf);
  return rc;
}

PHGMG_DEF phgmg_result phgmg_rom_load(const char *path, phgmg_rom *rom, void **block,
                                      const phgmg_allocator *alloc) {
  FILE *f;
  long len;
  unsigned char *buf = NULL;
  void *mem = NULL;
  size_t need = 0;
  phgmg_result rc;
  if (!path || !rom || !block) return PHGMG_ERR_INVALID_ARG;
  *block = NULL;
  f = fopen(path, "rb");
  if (!f) return PHGMG_ERR_IO;
  if (fseek(f, 0, SEEK_END) != 0 || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) { fclose(f); return PHGMG_ERR_IO; }
  if (len > (1L << 30)) { fclose(f); return PHGMG_ERR_FORMAT; }
  buf = PHGMG__CAST(unsigned char *, phgmg__alloc(alloc, (size_t)len));
  if (!buf) { fclose(f); return PHGMG_ERR_NOMEM; }
  if (fread(buf, 1, (size_t)len, f) != (size_t)len) { fclose(f); phgmg__free(alloc, buf); return PHGMG_ERR_IO; }
  fclose(f);
  rc = phgmg_rom_deserialize_size(buf, (size_t)len, &need);
  if (rc == PHGMG_OK) {
    mem = phgmg__alloc(alloc, need);
    if (!mem) rc = PHGMG_ERR_NOMEM;
    else rc = phgmg_rom_deserialize(buf, (size_t)len, rom, mem, need);
  }
  phgmg__free(alloc, buf);
  if (rc != PHGMG_OK) { phgmg__free(alloc, mem); return rc; }
  *block = mem;
  return PHGMG_OK;
}

PHGMG_DEF phgmg_result phgmg_rom_export_c(const phgmg_rom *rom, const char *name, const char *path) {
  FILE *f;
  int i, ok = 1;
  size_t k;
  phgmg_result rc = phgmg_rom_check(rom);
  if (rc != PHGMG_OK) return rc;
  if (!name || !path) return PHGMG_ERR_INVALID_ARG;
  f = fopen(path, "w");
  if (!f) return PHGMG_ERR_IO;
  ok &= fprintf(f, "/* Reduced port-Hamiltonian model exported by phgmg %s.\n"
                   "   kind %d, method %d, r = %d, m = %d, r_n = %d, DEIM points = %d.\n"
                   "   Include after phgmg.h; build with the same scalar type. */\n",
                PHGMG_VERSION_STRING, rom->kind, rom->method, rom->r, rom->m, rom->rn, rom->nd) > 0;
  ok &= fprintf(f, "#if PHGMG_REAL_IS_FLOAT != %d\n#error \"%s was exported for phgmg_real = %s\"\n#endif\n",
                PHGMG_REAL_IS_FLOAT, name, PHGMG_REAL_IS_FLOAT ? "float" : "double") > 0;
  for (i = 0; i < PHGMG__NFIELDS; ++i) {
    const phgmg_real *a = phgmg__field_get(rom, i);
    const size_t n = phgmg__field_len(rom, i);
    if (!a) continue;
    ok &= fprintf(f, "static const phgmg_real %s_%s[%lu] = {", name, phgmg__fields[i].name, (unsigned long)n) > 0;
    for (k = 0; k < n; ++k)
#if PHGMG_REAL_IS_FLOAT
      ok &= fprintf(f, "%s%#.9gf", k == 0 ? "\n  " : (k % 6 ? ", " : ",\n  "), (double)a[k]) > 0;
#else
      ok &= fprintf(f, "%s%.17g", k == 0 ? "\n  " : (k % 4 ? ", " : ",\n  "), a[k]) > 0;
#endif
    ok &= fprintf(f, "};\n") > 0;
  }
  ok &= fprintf(f, "static const phgmg_rom %s = {\n  %d, %d, %d, %d, %d, %d, %d,\n ", name, rom->kind,
                rom->method, rom->r, rom->m, rom->rn, rom->nd, rom->poly_deg) > 0;
  for (i = 0; i < 14; ++i) {
    if (phgmg__field_get(rom, i)) ok &= fprintf(f, " %s_%s,", name, phgmg__fields[i].name) > 0;
    else ok &= fprintf(f, " NULL,") > 0;
  }
#if PHGMG_REAL_IS_FLOAT
  ok &= fprintf(f, "\n  %#.9gf,\n ", (double)rom->dt) > 0;
#else
  ok &= fprintf(f, "\n  %.17g,\n ", rom->dt) > 0;
#endif
  for (i = 14; i < PHGMG__NFIELDS; ++i) {
    if (phgmg__field_get(rom, i)) ok &= fprintf(f, " %s_%s%s", name, phgmg__fields[i].name, i + 1 < PHGMG__NFIELDS ? "," : "") > 0;
    else ok &= fprintf(f, " NULL%s", i + 1 < PHGMG__NFIELDS ? "," : "") > 0;
  }
  ok &= fprintf(f, "\n};\n") > 0;
  if (fclose(f) != 0) ok = 0;
  return ok ? PHGMG_OK : PHGMG_ERR_IO;
}
#endif
