/* Reduced port-Hamiltonian model exported by phgmg 0.1.0.
   kind 1, method 1, r = 3, m = 1, r_n = 0, DEIM points = 0.
   Include after phgmg.h; build with the same scalar type. */
#if PHGMG_REAL_IS_FLOAT != 0
#error "rom was exported for phgmg_real = double"
#endif
static const phgmg_real rom_Bh[3] = {
  1, 0, 0};
static const phgmg_real rom_Qh[9] = {
  1, -4.163336342344337e-17, 0, -4.163336342344337e-17,
  0.63948618852668804, 0.011280748075015667, 0, 0.011280748075015667,
  1.8814775058699831};
static const phgmg_real rom_K[9] = {
  -0.93181093812466154, -1.578555317867393, 0.23342636433125422, -1.1168901355557594,
  -4.2063699358410265, -2.6367725184101536, -1.9230724498790597, -2.636772518410154,
  -1.6528668233867354};
static const phgmg_real rom_G00[9] = {
  0, 0.51257502588668091, -0.81769669688937863, -0.51257502588668091,
  -0.31617232793403877, 0.43199244520829927, 0.81769669688937863, -0.091988297695361487,
  -0.34278370738911546};
static const phgmg_rom rom = {
  1, 1, 3, 1, 0, 0, 0,
  rom_Bh, rom_Qh, rom_K, rom_G00, NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL,
  0,
  NULL, NULL, NULL, NULL
};
