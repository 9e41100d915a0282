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
# MODELS="ac20 biot" to run a subset; PHGMG to use another binary. Each
# run is niced (nice -n 10): the figures are CPU time, not wall time.
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
    *) echo "unknown model $d"; exit 2 ;;
  esac
  [ -f "$d/B.npy" ] || $PY "$HERE/fe_mesh.py" $gen > /dev/null
  nice -n 10 /usr/bin/time -v "$PHGMG" simulate --E-coo "$d/E.npy" --J-coo "$d/J.npy" --R-coo "$d/R.npy" \
    --Q-coo "$d/Q.npy" --B "$d/B.npy" --dt 0.02 --steps $steps --input chirp.npy --out "$d.phgmg_y.npy" \
    --quiet > "$d.phgmg.log" 2>&1
  nice -n 10 /usr/bin/time -v $PY "$HERE/fe_gl3_ref.py" "$d" chirp.npy "$d.scipy_y.npy" --dt 0.02 \
    --steps $steps > "$d.scipy.log" 2>&1
  set -- $(cpu "$d.phgmg.log") $(cpu "$d.scipy.log")
  diff=$($PY -c "import numpy as np; a = np.load('$d.phgmg_y.npy'); b = np.load('$d.scipy_y.npy'); \
print('%.2e (max |y| %.2e)' % (abs(a - b).max(), abs(b).max()))")
  N=$($PY -c "import numpy as np; print(np.load('$d/B.npy').shape[0])")
  echo "$d N=$N steps=$steps: phgmg $1 s $(($2 / 1024)) MiB, scipy $3 s $(($4 / 1024)) MiB," \
    "CPU ratio $(echo "$1 $3" | awk '{printf "%.2f", $1 / $2}')," \
    "memory ratio $(echo "$2 $4" | awk '{printf "%.2f", $1 / $2}'), outputs apart $diff"
done
