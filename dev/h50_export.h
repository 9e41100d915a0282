
/* >>export ================================================================ */
/* A reduced model leaves the workstation in two forms:
   - C source: static const arrays of phgmg_real plus a `static const phgmg_rom`
     descriptor, to be compiled into firmware (flash);
   - a binary file: magic "PHGMGROM", format version, scalar size (4 = float,
     8 = double), the sizes, then the arrays, all little-endian. Loading checks
     the magic, the version, the scalar type (it must match the build's
     phgmg_real) and the sizes; a damaged file gives PHGMG_ERR_FORMAT.
   Serialising and loading work in memory and need neither stdio nor heap;
   the file helpers are compiled out with PHGMG_NO_STDIO or PHGMG_NO_OFFLINE.
   A file written by a double build loads into a float build (values are
   rounded once) and vice versa. */
#ifdef __cplusplus
extern "C" {
#endif

#define PHGMG_ROM_FORMAT_VERSION 1u

/* Bytes phgmg_rom_serialize writes for this model. */
PHGMG_DEF size_t phgmg_rom_serialized_size(const phgmg_rom *rom);
/* Serialise into buf (cap bytes). *written = bytes used. PHGMG_ERR_WORKSPACE if cap is too small. */
PHGMG_DEF phgmg_result phgmg_rom_serialize(const phgmg_rom *rom, void *buf, size_t cap, size_t *written);
/* Bytes of memory phgmg_rom_deserialize needs to hold the model in buf
   (the arrays are copied, so buf may be freed afterwards). */
PHGMG_DEF phgmg_result phgmg_rom_deserialize_size(const void *buf, size_t len, size_t *need);
/* Rebuild a model from buf into caller memory mem (>= the size above, aligned
   for double); rom's views point into mem. */
PHGMG_DEF phgmg_result phgmg_rom_deserialize(const void *buf, size_t len, phgmg_rom *rom, void *mem,
                                             size_t mem_size);

#if !defined(PHGMG_NO_STDIO) && !defined(PHGMG_NO_OFFLINE)
/* Write the model as binary file. */
PHGMG_DEF phgmg_result phgmg_rom_save(const phgmg_rom *rom, const char *path);
/* Read a binary model file into one block allocated with alloc (NULL = default);
   *rom views into *block, which the caller frees (alloc->free or free()). */
PHGMG_DEF phgmg_result phgmg_rom_load(const char *path, phgmg_rom *rom, void **block,
                                      const phgmg_allocator *alloc);
/* Write the model as C source: arrays `<name>_<field>` and a descriptor
   `static const phgmg_rom <name>` (scalar type: this build's phgmg_real;
   values printed with enough digits to round-trip exactly). */
PHGMG_DEF phgmg_result phgmg_rom_export_c(const phgmg_rom *rom, const char *name, const char *path);
#endif

#ifdef __cplusplus
}
#endif
