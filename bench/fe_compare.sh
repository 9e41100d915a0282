#!/bin/sh
# `phgmg simulate` against SciPy + SuperLU doing the same GL3 steps, on the
# finite-element models of bench/fe_mesh.py: whole-process CPU time
# (user + sys) and peak resident memory of each (/usr/bin/time -v), and the
# largest difference of the outputs.
#
#   sh bench/fe_compare.sh [WORKDIR]      (default /tmp/phgmg_fe)
#
# Models (rows and columns scrambled): acoustic N = 20 667 (83 x 83 nodes)
# and N = 100 467 (183 x 183; 300 steps), Biot N = 14 850 (55 x 55);
# dt 0.02, 1000 steps, a chirp on both ports (fe_mesh.py chirp). Set
# MODELS="ac20 biot" to run a subset (rlc40: the index-one RLC grid of
# bench/rlc_grid.py, 40 x 40 mains, N = 7 840, against bench/dae_scipy.py);
# PHGMG to use another binary. REPEAT=n runs the two programs n times in
# turn (phgmg, SciPy, phgmg, ...) and prints the medians and the median of
# the pairwise CPU ratios (one figure that a drifting machine load moves
# little). Each run is niced (nice -n 10): the figures are CPU time, not
# wall time.
set -e
HERE=$(cd "$(dirname "$0")" && pwd)
W=${1:-/tmp/phgmg_fe}
PY=/usr/bin/python3
PHGMG=${PHGMG:-$HERE/../build/phgmg}
MODELS=${MODELS:-"ac20 biot ac100"}
mkdir -p "$W"
cd "$W"
[ -f chirp.npy ] || $PY "$HERE/fe_mesh.py" chirp chirp.npy 20 2

cpu() { # user + sys seconds and peak KiB from a /usr/bin/time -v log
  awk -F': ' '/User time/ {u = $2} /System time/ {s = $2} /Maximum resident/ {m = $2}
              END {printf "%.2f %d", u + s, m}' "$1"
}

for d in $MODELS; do
  case $d in
    ac20) gen="acoustic ac20 83"; steps=1000 ;;
    ac100) gen="acoustic ac100 183"; steps=300 ;;
    biot) gen="biot biot 55"; steps=1000 ;;
    rlc40) gen=""; steps=1000 ;;
    *) echo "unknown model $d"; exit 2 ;;
  esac
  if [ "$d" = rlc40 ]; then
    mkdir -p "$d"; [ -f "$d/B.npy" ] || $PY "$HERE/rlc_grid.py" "$d" --n 40 > /dev/null
    inp="$d/chirp.npy"; eopt="--E-coo $d/E.npy"
    ref="exec $PY '$HERE/dae_scipy.py' '$d' '$d.scipy_y.npy' --steps $steps --dt 0.02"
  else
    [ -f "$d/B.npy" ] || $PY "$HERE/fe_mesh.py" $gen > /dev/null
    inp=chirp.npy; eopt="--E-coo $d/E.npy"
    ref="exec $PY '$HERE/fe_gl3_ref.py' '$d' chirp.npy '$d.scipy_y.npy' --dt 0.02 --steps $steps"
  fi
  : > "$d.runs"
  k=0
  while [ $k -lt "${REPEAT:-1}" ]; do
    nice -n 10 /usr/bin/time -v "$PHGMG" simulate $eopt --J-coo "$d/J.npy" --R-coo "$d/R.npy" \
      --Q-coo "$d/Q.npy" --B "$d/B.npy" --dt 0.02 --steps $steps --input "$inp" --out "$d.phgmg_y.npy" \
      --quiet > "$d.phgmg.log" 2>&1
    nice -n 10 /usr/bin/time -v sh -c "$ref" > "$d.scipy.log" 2>&1
    echo "$(cpu "$d.phgmg.log") $(cpu "$d.scipy.log")" >> "$d.runs"
    k=$((k + 1))
  done
  set -- $($PY -c "
import numpy as np
r = np.loadtxt('$d.runs', ndmin=2)
print('%.2f %d %.2f %d %.3f %.3f %.3f' % (np.median(r[:, 0]), np.median(r[:, 1]), np.median(r[:, 2]),
      np.median(r[:, 3]), np.median(r[:, 0] / r[:, 2]), (r[:, 0] / r[:, 2]).min(), (r[:, 0] / r[:, 2]).max()))")
  diff=$($PY -c "import numpy as np; a = np.load('$d.phgmg_y.npy'); b = np.load('$d.scipy_y.npy'); \
print('%.2e (max |y| %.2e)' % (abs(a - b).max(), abs(b).max()))")
  N=$($PY -c "import numpy as np; print(np.load('$d/B.npy').shape[0])")
  echo "$d N=$N steps=$steps runs=${REPEAT:-1}: phgmg $1 s $(($2 / 1024)) MiB, scipy $3 s $(($4 / 1024)) MiB," \
    "CPU ratio $5 ($6 - $7)," \
    "memory ratio $(echo "$2 $4" | awk '{printf "%.2f", $1 / $2}'), outputs apart $diff"
done
