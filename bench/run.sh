#!/bin/sh
# make bench: build and run the benchmarks, write bench/results.csv.
#
#   sh bench/run.sh
#
# 1. prints the machine line (CPU model, cores, compiler and flags, load);
# 2. builds bench/bench_linalg.c, bench/bench_fom.c, bench/bench_rom.c,
#    bench/bench_linear.c (lyap_N1000, prbt_N1000_r20, h2basis_N1000_r20_20it: about a minute and a half),
#    bench/bench_scale.c (offline_gmgpod_N256000: the whole reduction of the
#    nonlinear chain at N = 256 000, 3 runs after a ~30 s full-order run for
#    the snapshots; about 2 minutes and 5 GB of memory),
#    bench/bench_desc.c (desc2d_N10082_band / _sparse: a 2-D lattice with a
#    mass matrix, 1000 steps with the band LU and with the sparse LU, 3
#    paired runs; about a minute),
#    bench/bench_lowrank.c (lrbt_heat_N10000_r20: low-rank BT of a 2-D heat
#    model, one run, about a second) into
#    build/ (a missing or broken source is skipped with a warning) and runs
#    each, appending `case,median_s,min_s,max_s,runs` lines to the CSV;
# 2b. bench/bench_sparse.sh: `phgmg simulate` on scrambled 2-D/3-D lattices
#    against the same GL3 steps in SciPy + SuperLU (ratio cases), a GMG-POD
#    reduction of a 2-D lattice with N = 200 978 (time, and peak memory against
#    the snapshot matrix) and a descriptor finite-element bar (a few minutes);
# 3. if a CBLAS is installed, builds bench_linalg again with -DPHGMG_USE_CBLAS
#    and records its cases with a `_cblas` suffix (one BLAS thread);
# 3b. runs bench/studies/hyper_study.c, bench/studies/altmin_study.c and
#     bench/qm_pulse.c (tables, no CSV cases);
# 4. builds the examples (`make examples`; if that fails, the two demo
#    programs directly, without -Werror) and times the whole demo (the three
#    runs `make demo` makes, with its arguments: linear, nonlinear, linear with
#    --lambda auto --rmin 8 --rmax 14 --rstep 6; wall
#    clock, one warm-up, then DEMO_RUNS runs) as case `demo_total`, and its
#    CPU time (user + sys of the two programs; robust to other load on the
#    machine) as `demo_total_cpu`;
# 5. prints the CSV as a table.
# Environment: CC (default cc), BENCH_CSV (default bench/results.csv),
# DEMO_RUNS (default 5).
set -u
cd "$(dirname "$0")/.." || exit 1

CC=${CC:-cc}
CFLAGS="-std=c99 -O2 -march=native"
LIBS="-lm"
BUILD=build
CSV=${BENCH_CSV:-bench/results.csv}
DEMO_RUNS=${DEMO_RUNS:-5}
mkdir -p "$BUILD"
cpu=$(grep -m1 'model name' /proc/cpuinfo 2>/dev/null | sed 's/^[^:]*: *//')
[ -n "$cpu" ] || cpu=$(uname -m)
mhz=$(grep -m1 'cpu MHz' /proc/cpuinfo 2>/dev/null | sed 's/^[^:]*: *//')
cores=$(grep -c '^processor' /proc/cpuinfo 2>/dev/null || echo '?')
# one core: no BLAS threads (set after counting: nproc honours OMP_NUM_THREADS)
OPENBLAS_NUM_THREADS=1; OMP_NUM_THREADS=1; export OPENBLAS_NUM_THREADS OMP_NUM_THREADS
ccver=$($CC --version 2>/dev/null | head -n 1)
load=$(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null)
machine="machine: $cpu (${mhz:-?} MHz), $cores cores; $ccver; flags $CFLAGS; load average $load; $(date -u +%Y-%m-%dT%H:%MZ)"
echo "$machine"
echo "$machine" > "$BUILD/bench_machine.txt"

make phgmg.h >/dev/null || { echo "run.sh: cannot build phgmg.h" >&2; exit 1; }
echo "case,median_s,min_s,max_s,runs" > "$CSV"

for prog in bench_linalg bench_fom bench_rom bench_linear bench_scale bench_desc bench_lowrank; do
  src=bench/$prog.c
  if [ ! -f "$src" ]; then
    echo "run.sh: warning: $src is missing, skipped" >&2
    continue
  fi
  echo
  echo "== $prog"
  if ! $CC $CFLAGS -o "$BUILD/$prog" "$src" $LIBS; then
    echo "run.sh: warning: $src does not build, skipped" >&2
    continue
  fi
  "./$BUILD/$prog" --out "$CSV" || echo "run.sh: warning: $prog failed (exit $?)" >&2
done

# sparse lattices: phgmg simulate against SciPy + SuperLU (bench/bench_sparse.sh)
echo
echo "== bench_sparse"
if make "$BUILD/phgmg" >/dev/null; then
  sh bench/bench_sparse.sh "$BUILD/phgmg" "$CSV" || echo "run.sh: warning: bench_sparse failed" >&2
fi

# the hyper-reduction choices side by side (a table, not timing cases)
echo
echo "== hyper_study"
if $CC $CFLAGS -o "$BUILD/hyper_study" bench/studies/hyper_study.c $LIBS; then
  "./$BUILD/hyper_study" | tee "$BUILD/hyper_study.txt"
fi

# the GMG-QM manifold constructions side by side (tables, not timing cases)
echo
echo "== altmin_study"
if $CC $CFLAGS -o "$BUILD/altmin_study" bench/studies/altmin_study.c $LIBS; then
  for chain in linear nonlinear; do
    "./$BUILD/altmin_study" $chain --lambda 1e-9 --r 8,12,16,20
  done | tee "$BUILD/altmin_study.txt"
fi

# transport data: the greedy manifold with a wide V2 on an advecting pulse
# against the greedy reference code's projection errors (table, not timing cases)
echo
echo "== qm_pulse"
if $CC $CFLAGS -o "$BUILD/qm_pulse" bench/qm_pulse.c $LIBS; then
  "./$BUILD/qm_pulse" --n 12,16,20 | tee "$BUILD/qm_pulse.txt"
fi

# CBLAS: the first of these libraries that links and runs a 1x1 dgemm
if [ -f bench/bench_linalg.c ]; then
  printf '#include <cblas.h>\nint main(void) { double a = 2, b = 3, c = 0;\n  cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, 1, 1, 1, 1.0, &a, 1, &b, 1, 0.0, &c, 1);\n  return c == 6.0 ? 0 : 1; }\n' > "$BUILD/cblas_probe.c"
  cblas=""
  for lib in -lopenblas -lcblas -lblas; do
    if $CC -o "$BUILD/cblas_probe" "$BUILD/cblas_probe.c" $lib $LIBS >/dev/null 2>&1 && "./$BUILD/cblas_probe"; then
      cblas=$lib
      break
    fi
  done
  if [ -n "$cblas" ]; then
    echo
    echo "== bench_linalg with -DPHGMG_USE_CBLAS ($cblas, 1 thread)"
    tmp="$BUILD/bench_cblas.csv"
    rm -f "$tmp"
    if $CC $CFLAGS -DPHGMG_USE_CBLAS -o "$BUILD/bench_linalg_cblas" bench/bench_linalg.c $cblas $LIBS &&
       "./$BUILD/bench_linalg_cblas" --out "$tmp"; then
      awk -F, 'NR > 1 && NF == 5 { printf "%s_cblas,%s,%s,%s,%s\n", $1, $2, $3, $4, $5 }' "$tmp" >> "$CSV"
    else
      echo "run.sh: warning: the CBLAS build of bench_linalg failed" >&2
    fi
  else
    echo "run.sh: no CBLAS found (cblas.h with -lopenblas, -lcblas or -lblas); _cblas cases skipped" >&2
  fi
fi

# the whole demo, wall clock
echo
echo "== demo_total (make examples; the three runs of make demo, 1 warm-up + $DEMO_RUNS runs)"
demo_lin="$BUILD/msd_linear"
demo_nl="$BUILD/msd_nonlinear"
if ! make examples >/dev/null; then
  # timing the demo must not depend on a -Werror warning: build the two programs directly
  echo "run.sh: warning: make examples failed; building the demo programs with $CFLAGS (no -Werror)" >&2
  demo_lin="$BUILD/bench_msd_linear"
  demo_nl="$BUILD/bench_msd_nonlinear"
  $CC $CFLAGS -o "$demo_lin" examples/msd_linear.c $LIBS && $CC $CFLAGS -o "$demo_nl" examples/msd_nonlinear.c $LIBS ||
    rm -f "$demo_lin" "$demo_nl"
fi
if [ -x "$demo_lin" ] && [ -x "$demo_nl" ]; then
  mkdir -p "$BUILD/bench_results"
  walls=""
  cpus=""
  i=0
  ok=1
  while [ $i -le "$DEMO_RUNS" ]; do
    times > "$BUILD/bench_times0"   # CPU time of the children so far (no subshell: a builtin)
    t0=$(date +%s.%N)
    if ! { "./$demo_lin" --out "$BUILD/bench_results" && "./$demo_nl" --out "$BUILD/bench_results" &&
           "./$demo_lin" --lambda auto --rmin 8 --rmax 14 --rstep 6 --out "$BUILD/bench_results"; } >/dev/null; then
      echo "run.sh: warning: the demo failed" >&2
      ok=0
      break
    fi
    t1=$(date +%s.%N)
    times > "$BUILD/bench_times1"
    dt=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.6f", b - a }')
    dc=$(awk 'FNR == 2 { split($1, u, /[ms]/); split($2, s, /[ms]/); t[++n] = u[1] * 60 + u[2] + s[1] * 60 + s[2] }
              END { printf "%.6f", t[2] - t[1] }' "$BUILD/bench_times0" "$BUILD/bench_times1")
    if [ $i -eq 0 ]; then
      echo "  warm-up: wall ${dt} s, CPU ${dc} s"
    else
      echo "  run $i: wall ${dt} s, CPU ${dc} s"
      walls="$walls $dt"
      cpus="$cpus $dc"
    fi
    i=$((i + 1))
  done
  if [ $ok -eq 1 ]; then
    for pair in "demo_total:$walls" "demo_total_cpu:$cpus"; do
      echo ${pair#*:} | tr ' ' '\n' | sort -g | awk -v n="$DEMO_RUNS" -v name="${pair%%:*}" '
        { t[NR] = $1 }
        END { med = (n % 2) ? t[(n + 1) / 2] : 0.5 * (t[n / 2] + t[n / 2 + 1]);
              printf "%s,%.6f,%.6f,%.6f,%d\n", name, med, t[1], t[n], n }' >> "$CSV"
    done
  fi
else
  echo "run.sh: warning: the demo programs do not build, demo_total skipped" >&2
fi

echo
echo "$machine"
awk -F, 'NR == 1 { printf "%-40s %12s %12s %12s %8s %5s\n", "case", "median_s", "min_s", "max_s", "spread", "runs"; next }
         NF == 5 { sp = $2 > 0 ? 100 * ($4 - $3) / $2 : 0;
                   printf "%-40s %12.6f %12.6f %12.6f %7.1f%% %5d\n", $1, $2, $3, $4, sp, $5 }' "$CSV"
echo "(spread = (max - min) / median; written to $CSV)"
