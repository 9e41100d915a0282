#!/bin/sh
# Short fuzzing run of every reader of outside data in phgmg.h:
#   npy         phgmg_npy_parse                    (tests/fuzz/fuzz_npy.c)
#   npy_stream  phgmg_npy_read from a file and a pipe against phgmg_npy_parse
#               on the same bytes                  (tests/fuzz/fuzz_npy_stream.c)
#   rom         phgmg_rom_deserialize + online path (tests/fuzz/fuzz_rom.c)
#   rom_f32     the same in a PHGMG_REAL_FLOAT build
#   cli         the argument handling of the phgmg command line on a tiny model
#               in a scratch directory              (tests/fuzz/fuzz_cli.c)
# Usage: sh tests/fuzz/run.sh [SECONDS]   (per target, default 60; 0 = only
#        replay the corpus, a quick regression check)
# With clang's libFuzzer: builds each harness with
# -fsanitize=fuzzer,address,undefined and runs it for SECONDS
# (-max_total_time), starting from the seed corpus in tests/fuzz/corpus/<name>;
# new inputs go to build/fuzz/corpus_<target> (the repository's corpus is not
# touched), crashes to build/fuzz/crash-<target>-*. Without libFuzzer: builds
# the plain drivers with gcc (or cc) + ASan/UBSan and runs the seed corpus
# once. Exit status 1 on any crash, hang, leak or sanitizer report.
set -u
secs=${1:-60}
case "$secs" in ''|*[!0-9]*) echo "usage: $0 [SECONDS]" >&2; exit 2 ;; esac
cd "$(dirname "$0")/../.." || exit 2
MAKEFLAGS= make -s phgmg.h || exit 2   # alone: not a job of a calling make -j
out=build/fuzz
mkdir -p "$out"

# libFuzzer dictionary of the binary model format: magic, versions, scalar
# sizes, kinds, a field mask with every bit.
printf '%s\n' '"PHGMGROM"' '"\x01\x00\x00\x00"' '"\x02\x00\x00\x00"' '"\x04\x00\x00\x00"' \
  '"\x08\x00\x00\x00"' '"\xff\xff\x03\x00"' '"\x00\x00\x00\x00\x00\x00\xf0\x7f"' > "$out/rom.dict"

have_libfuzzer=0
if command -v clang >/dev/null 2>&1; then
  printf '#include <stdint.h>\n#include <stddef.h>\nint LLVMFuzzerTestOneInput(const uint8_t *d, size_t n) { (void)d; (void)n; return 0; }\n' \
    > "$out/probe.c"
  if clang -fsanitize=fuzzer,address,undefined "$out/probe.c" -o "$out/probe" >/dev/null 2>&1; then
    have_libfuzzer=1
  fi
fi

fail=0
# target  source  extra-flags  corpus  dictionary  libFuzzer-flags ('-': none)
targets='npy tests/fuzz/fuzz_npy.c - npy tests/fuzz/npy.dict -
npy_stream tests/fuzz/fuzz_npy_stream.c - npy tests/fuzz/npy.dict -
rom tests/fuzz/fuzz_rom.c - rom build/fuzz/rom.dict -
rom_f32 tests/fuzz/fuzz_rom.c -DPHGMG_REAL_FLOAT rom build/fuzz/rom.dict -
cli tests/fuzz/fuzz_cli.c - cli - -close_fd_mask=3'

if [ $have_libfuzzer = 1 ]; then
  if [ "$secs" = 0 ]; then echo "fuzz: clang libFuzzer + ASan + UBSan, replaying the corpus only"
  else echo "fuzz: clang libFuzzer + ASan + UBSan, ${secs} s per target"; fi
  opt=-O1   # fuzzing: -O1; a replay runs each input once: -O0 builds in half the time
  [ "$secs" = 0 ] && opt=-O0
  echo "$targets" | while read -r t src flags corpus dict rflags; do
    [ "$flags" = - ] && flags=
    [ "$rflags" = - ] && rflags=
    dictopt=
    [ "$dict" = - ] || dictopt="-dict=$dict"
    bin="$out/fuzz_$t"
    # shellcheck disable=SC2086
    if ! clang -g $opt -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all $flags "$src" -o "$bin" -lm; then
      echo "fuzz: $t: build failed"; exit 1
    fi
    mkdir -p "$out/corpus_$t"
    log="$out/fuzz_$t.log"
    if [ "$secs" = 0 ]; then
      # shellcheck disable=SC2086
      ASAN_OPTIONS=detect_leaks=1 "$bin" -runs=0 -print_final_stats=1 -artifact_prefix="$PWD/$out/crash-$t-" \
        $rflags "tests/fuzz/corpus/$corpus" </dev/null >"$log" 2>&1
    else
      # shellcheck disable=SC2086
      ASAN_OPTIONS=detect_leaks=1 "$bin" -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 \
        -print_final_stats=1 $dictopt $rflags -artifact_prefix="$PWD/$out/crash-$t-" \
        "$out/corpus_$t" "tests/fuzz/corpus/$corpus" </dev/null >"$log" 2>&1
    fi
    rc=$?
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -n 1)
    files=$(find "$out/corpus_$t" -type f | wc -l)
    if [ $rc -ne 0 ]; then
      echo "fuzz: $t: FINDING (exit $rc) after ${runs:-?} runs; see $log and $out/crash-$t-*"
      # what failed (the harness's invariant, the sanitizer's report) and the
      # input itself, so that a finding on another machine can be replayed
      grep -m 5 -e 'invariant violated' -e 'ERROR:' -e 'runtime error' -e 'SUMMARY' "$log"
      tail -n 40 "$log"
      for c in "$out"/crash-"$t"-*; do
        [ -f "$c" ] || continue
        echo "fuzz: $t: input $c (base64, replay: base64 -d > f; $bin f):"
        base64 "$c" | head -c 12000; echo
      done
      exit 1
    fi
    if [ "$secs" = 0 ]; then echo "fuzz: $t: ${runs:-?} corpus inputs replayed, ${cov:-cov: ?}, no finding"
    else echo "fuzz: $t: ${runs:-?} runs in ${secs} s, ${cov:-cov: ?}, work corpus $files files, no finding"; fi
  done || fail=1
else
  cc=gcc
  command -v gcc >/dev/null 2>&1 || cc=cc
  echo "fuzz: clang's libFuzzer is not available; building the plain drivers with $cc + ASan/UBSan" \
       "and running the seed corpus only (no fuzzing)"
  echo "$targets" | while read -r t src flags corpus dict rflags; do
    [ "$flags" = - ] && flags=
    bin="$out/fuzz_${t}_run"
    # shellcheck disable=SC2086
    if ! $cc -std=c99 -g -O1 -fsanitize=address,undefined -fno-sanitize-recover=all $flags "$src" -o "$bin" -lm; then
      echo "fuzz: $t: build failed"; exit 1
    fi
    printf 'fuzz: %s: ' "$t"
    log="$out/fuzz_${t}_run.log"
    # shellcheck disable=SC2046
    if ! ASAN_OPTIONS=detect_leaks=1 "$bin" $(ls -d "tests/fuzz/corpus/$corpus"/[!.]*) </dev/null >"$log" 2>&1; then
      tail -n 40 "$log"
      echo "fuzz: $t: FINDING on the seed corpus"; exit 1
    fi
    tail -n 1 "$log"
  done || fail=1
fi
exit $fail
