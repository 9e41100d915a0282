#!/bin/sh
# Sparse-direct cases of make bench: `phgmg simulate` on scrambled lattices
# against the same GL3 steps in SciPy + SuperLU (bench/gl3_scipy.py).
#
#   sh bench/bench_sparse.sh build/phgmg bench/results.csv
#
# Cases (bench/lattice.py; dt = 0.1, u = 0.1 sin t, linear):
#   sim2d_N3200    40 x 40 masses, 1000 steps
#   sim2d_N7200    60 x 60 masses, 1000 steps
#   sim3d_N8192    16 x 16 x 16 masses, 1000 steps
#   sim2d_N100352  224 x 224 masses, 100 steps
# and, phgmg alone (SPARSE_RUNS runs each, median, min, max into the CSV):
#   reduce2d_N200978_gmgpod  317 x 317 masses: `phgmg reduce --simulate --steps 200
#                  --method gmg-pod --r 20` (the whole process: simulation, reduction,
#                  files); with /usr/bin/time (each run under it) the last run's
#                  peak memory is printed against the snapshot matrix (N x 201 doubles)
#   desc_febar_N10000  the finite-element bar of bench/fe_bar.py (5000 elements,
#                  consistent mass matrix: a descriptor model, --E-coo), `phgmg
#                  simulate --dt 0.05 --steps 1000 --input sin --amp 1`
# Each case runs phgmg and SciPy in turn, SPARSE_RUNS times (default 3):
# phgmg's time is the whole process (reading the .npy files, ordering, analysis,
# validation, factorization, steps, writing y); SciPy's the stepping as
# gl3_scipy.py reports it (set-up, both splu factorizations and the steps;
# without Python's start, the imports and the file reading). Lines
# <case>_phgmg and <case>_scipy (median, min, max seconds) and <case>_ratio
# (SciPy / phgmg, the median of the ratios of the pairs; > 1: phgmg faster)
# are appended to the CSV, and the largest relative difference of the two
# outputs is printed (must be <= 1e-8). SPARSE_CASES="name ..." runs only
# those cases. Without SciPy in /usr/bin/python3 the
# cases are skipped with a note.
set -u
P=${1:-build/phgmg}
CSV=${2:-bench/results.csv}
RUNS=${SPARSE_RUNS:-3}
PY=/usr/bin/python3
ROOT=$(cd "$(dirname "$0")/.." && pwd)
if ! "$PY" -c 'import numpy, scipy.sparse.linalg' 2>/dev/null; then
  echo "bench_sparse: skipped ($PY has no NumPy/SciPy)"
  exit 0
fi
W=$(mktemp -d "${TMPDIR:-/tmp}/phgmg_bsp.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT INT TERM

stats() { # name, then the values on stdin: median, min, max, count into the CSV
  sort -g | awk -v name="$1" '{ t[NR] = $1 } END { n = NR; if (n == 0) exit;
    med = (n % 2) ? t[(n + 1) / 2] : 0.5 * (t[n / 2] + t[n / 2 + 1]);
    printf "%s,%.6f,%.6f,%.6f,%d\n", name, med, t[1], t[n], n }' >> "$CSV"
}

for spec in "sim2d_N3200 40 40 1 1000" "sim2d_N7200 60 60 1 1000" "sim3d_N8192 16 16 16 1000" \
            "sim2d_N100352 224 224 1 100"; do
  set -- $spec
  name=$1 steps=$5
  case " ${SPARSE_CASES:-$name} " in *" $name "*) ;; *) continue ;; esac
  "$PY" "$ROOT/bench/lattice.py" "$W/$name" "$2" "$3" "$4" >/dev/null || { echo "bench_sparse: lattice.py failed" >&2; continue; }
  sys="--J-coo $W/$name/J.npy --R-coo $W/$name/R.npy --Q-coo $W/$name/Q.npy --B $W/$name/B.npy"
  : > "$W/tp"; : > "$W/ts"; : > "$W/tr"
  i=0
  while [ $i -lt "$RUNS" ]; do
    t0=$(date +%s.%N)
    "$P" simulate $sys --steps "$steps" --out "$W/y.npy" 2> "$W/log" >/dev/null || { echo "bench_sparse: phgmg failed: $(tail -n 2 "$W/log")" >&2; break; }
    t1=$(date +%s.%N)
    ts=$("$PY" "$ROOT/bench/gl3_scipy.py" "$W/$name" "$W/ys.npy" --steps "$steps") || { echo "bench_sparse: gl3_scipy.py failed" >&2; break; }
    tp=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.6f", b - a }')
    echo "$tp" >> "$W/tp"; echo "$ts" >> "$W/ts"
    awk -v a="$tp" -v b="$ts" 'BEGIN { printf "%.6f\n", b / a }' >> "$W/tr"
    echo "  $name run $((i + 1)): phgmg $tp s, SciPy $ts s"
    i=$((i + 1))
  done
  [ $i -eq "$RUNS" ] || continue
  grep 'stage solver' "$W/log" | sed 's/^phgmg: */  /'
  stats "${name}_phgmg" < "$W/tp"
  stats "${name}_scipy" < "$W/ts"
  stats "${name}_ratio" < "$W/tr"
  "$PY" -c "
import numpy as np
a, b = np.load('$W/y.npy'), np.load('$W/ys.npy')
print('  $name: max |y_phgmg - y_scipy| / max |y_scipy| = %.2e' % (np.abs(a - b).max() / np.abs(b).max()))"
done

# phgmg alone: name, SPARSE_RUNS timed runs of the command "$@" (stderr into $W/log)
alone() {
  name=$1; shift
  : > "$W/tp"
  i=0
  while [ $i -lt "$RUNS" ]; do
    t0=$(date +%s.%N)
    "$@" 2> "$W/log" >/dev/null || { echo "bench_sparse: $name failed: $(tail -n 2 "$W/log")" >&2; return 1; }
    t1=$(date +%s.%N)
    tp=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.6f", b - a }')
    echo "$tp" >> "$W/tp"
    echo "  $name run $((i + 1)): phgmg $tp s"
    i=$((i + 1))
  done
  stats "$name" < "$W/tp"
}

name=reduce2d_N200978_gmgpod
case " ${SPARSE_CASES:-$name} " in *" $name "*)
  if "$PY" "$ROOT/bench/lattice.py" "$W/$name" 317 317 1 >/dev/null; then
    L="$W/$name"
    set -- "$P" reduce --J-coo "$L/J.npy" --R-coo "$L/R.npy" --Q-coo "$L/Q.npy" --B "$L/B.npy" \
      --simulate --steps 200 --method gmg-pod --r 20 --out "$W/rom"
    : > "$W/rss"
    [ -x /usr/bin/time ] && set -- /usr/bin/time -f '%M' -o "$W/rss" "$@" # peak memory of each run
    if alone "$name" "$@"; then
      grep 'stage solver' "$W/log" | sed 's/^phgmg: */  /'
      [ -s "$W/rss" ] && awk -v kb="$(tail -n 1 "$W/rss")" 'BEGIN { s = 200978 * 201 * 8 / 1024;
        printf "  %s: peak memory %.0f MiB, %.2f x the snapshot matrix (%.0f MiB)\n", "'"$name"'", kb / 1024, kb / s, s / 1024 }'
    fi
    rm -rf "$L" "$W/rom"
  fi ;;
esac

name=desc_febar_N10000
case " ${SPARSE_CASES:-$name} " in *" $name "*)
  if "$PY" "$ROOT/bench/fe_bar.py" "$W/$name" 5000 >/dev/null; then
    L="$W/$name"
    alone "$name" "$P" simulate --J-coo "$L/J.npy" --R-coo "$L/R.npy" --Q-coo "$L/Q.npy" --E-coo "$L/E.npy" \
      --B "$L/B.npy" --dt 0.05 --steps 1000 --input sin --amp 1 --out "$W/y.npy" &&
      grep 'stage solver' "$W/log" | sed 's/^phgmg: */  /'
  fi ;;
esac
