#!/bin/sh
# The distributed command line on a large nonlinear model: a scrambled chain
# of NX masses (or, with NY > 1, a 2-D lattice of NX x NY masses: a 2-D mesh)
# with an on-site cosh potential (bench/lattice.py --cosh, N = 2 NX NY), 1001
# snapshots from the serial `phgmg simulate`, reduced by the
# serial `phgmg reduce` and by `mpirun -np P phgmg-mpi reduce` (gmg-pod and
# sp1, --r R, the default ECSW hyper-reduction; METHODS=gmg-qm: the greedy
# manifold with --lambda 1e-3 and the default rn) at P = 1, 2, 3, 4. Reports
# per run: the wall time (around mpirun), the CPU time (user + sys summed
# over the ranks), the largest rank's peak resident memory (each rank run
# under /usr/bin/time -v through a wrapper `sh -c`), the ECSW points (the
# same global indices as the serial run's?), K (gmg-qm: G00) and Qh
# against the serial ones after the modes' signs, and the largest difference
# of the outputs of `phgmg simulate-rom --dt DT --steps 1000` (DT 0.1, or
# ROMDT) from the serial model's, relative to their largest value. Not part
# of make test.
# From the repository's root, after make build/phgmg build/phgmg-mpi:
#   sh bench/mpi_cli_scale.sh [NX [R [DIR [NY]]]]  (defaults 100000 20 /tmp/mpi_cli_scale 1)
# DIR keeps the model, the snapshots (1.6 GB at NX = 1e5) and the outputs;
# steps whose outputs exist are not redone (delete DIR to start afresh).
# B2 (e.g. 0.5) adds a second input weight on mass 1 (bench/lattice.py --b2:
# no mirror symmetry, so that the hyper-reduction points are unique).
# METHODS (default "gmg-pod sp1") and PS (default "1 2 3 4") select the runs;
# the table lists those that were made.
# The machine may be shared: the times are those of this run.
set -e
NX=${1:-100000}
R=${2:-20}
D=${3:-/tmp/mpi_cli_scale}
NY=${4:-1}
ROOT=$(pwd)
PHGMG=$ROOT/build/phgmg
PMPI=$ROOT/build/phgmg-mpi
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
MPIRUN="mpirun --oversubscribe"
[ "$(id -u)" = 0 ] && MPIRUN="$MPIRUN --allow-run-as-root"
mkdir -p "$D"
cd "$D"
M="--J-coo J.npy --R-coo R.npy --Q-coo Q.npy --B B.npy --potential cosh:1 --poly-idx idx.npy"
now() { date +%s.%N; }
[ -e idx.npy ] || $PY "$ROOT/bench/lattice.py" . "$NX" "$NY" --cosh ${B2:+--b2 "$B2"} > /dev/null
[ -e X.npy ] || "$PHGMG" simulate $M --dt 0.1 --steps 1000 --out y_full.npy --states X.npy --quiet > /dev/null
ROMDT=${ROMDT:-0.1}
for meth in ${METHODS:-gmg-pod sp1}; do
  opt=""
  [ "$meth" = gmg-qm ] && opt="--manifold greedy --lambda 1e-3"
  if [ ! -e "y_serial_$meth.npy" ]; then
    t0=$(now)
    /usr/bin/time -v -o "time_serial_$meth.txt" "$PHGMG" reduce $M --X X.npy --method $meth $opt --r "$R" \
      --out "serial_$meth" --quiet > /dev/null
    echo "$(now) $t0" | awk '{printf "%.2f\n", $1 - $2}' > "wall_serial_$meth.txt"
    "$PHGMG" simulate-rom --model "serial_$meth/rom.phgmgrom" --dt "$ROMDT" --steps 1000 --out "y_serial_$meth.npy" --quiet > /dev/null
  fi
  for p in ${PS:-1 2 3 4}; do
    [ -e "y_p${p}_$meth.npy" ] && continue
    rm -f time_p${p}_${meth}_rank*.txt
    t0=$(now)
    $MPIRUN -np $p sh -c 'exec /usr/bin/time -v -o "$0_rank$OMPI_COMM_WORLD_RANK.txt" "$@"' "time_p${p}_$meth" \
      "$PMPI" reduce $M --X X.npy --method $meth $opt --r "$R" --out "p${p}_$meth" --quiet
    echo "$(now) $t0" | awk '{printf "%.2f\n", $1 - $2}' > "wall_p${p}_$meth.txt"
    "$PHGMG" simulate-rom --model "p${p}_$meth/rom.phgmgrom" --dt "$ROMDT" --steps 1000 --out "y_p${p}_$meth.npy" --quiet > /dev/null
  done
done

$PY - "$D" "$NX" "$R" "$NY" <<'PYEOF'
import glob
import os
import re
import sys
import numpy as np
d, nx, r, ny = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])

def tv(path):
    t = open(path).read()
    g = lambda k: float(re.search(k + r':\s*([0-9.:]+)', t).group(1))
    return g('User time \\(seconds\\)') + g('System time \\(seconds\\)'), g('Maximum resident set size \\(kbytes\\)') / 1024.0

def opdiff(sd, pd):   # K and Qh of run pd against the serial sd, the modes' signs matched through V0
    Vs, Vp = np.load(sd + '/rom_V0.npy', mmap_mode='r'), np.load(pd + '/rom_V0.npy', mmap_mode='r')
    sg = np.array([1.0 if float(np.dot(Vs[:, j], Vp[:, j])) >= 0 else -1.0 for j in range(Vs.shape[1])])
    out = []
    for name in ('K' if os.path.exists(sd + '/rom_K.npy') else 'G00', 'Qh'):
        As, Ap = np.load('%s/rom_%s.npy' % (sd, name)), np.load('%s/rom_%s.npy' % (pd, name))
        out.append(np.abs(sg[:, None] * Ap * sg[None, :] - As).max() / np.abs(As).max())
    return out

def coords(P0, V0):   # the state coordinates of the kept terms: their rows of V0
    return [int(np.argmin(np.abs(V0 - row).max(axis=1))) for row in P0]

shape = 'chain of %d masses' % nx if ny == 1 else '2-D lattice of %d x %d masses' % (nx, ny)
print('%s, N = %d, %d snapshots, r = %d, cosh:1 on every position, ECSW tol 1e-6' % (shape, 2 * nx * ny, 1001, r))
print()
print('| method | run | wall [s] | CPU [s] | peak RSS, largest rank [MB] | vs the first P | ECSW points | same points as serial | K (gmg-qm: G00), Qh rel. diff | simulate-rom max rel. diff |')
print('|---|---|---|---|---|---|---|---|---|---|')
for meth in ('gmg-pod', 'sp1', 'gmg-qm'):
    sd = '%s/serial_%s' % (d, meth)
    if not os.path.exists('%s/y_serial_%s.npy' % (d, meth)):
        continue
    V0s = np.load(sd + '/rom_V0.npy', mmap_mode='r')
    P0s = np.load(sd + '/rom_P0.npy')
    cs = coords(P0s, np.asarray(V0s))
    ys = np.load('%s/y_serial_%s.npy' % (d, meth))
    cpu, rss = tv('%s/time_serial_%s.txt' % (d, meth))
    wall = float(open('%s/wall_serial_%s.txt' % (d, meth)).read())
    print('| %s | serial | %.1f | %.1f | %.0f | | %d | | | |' % (meth, wall, cpu, rss, len(cs)))
    rss1 = None
    for p in (1, 2, 3, 4):
        pd = '%s/p%d_%s' % (d, p, meth)
        if not os.path.exists('%s/y_p%d_%s.npy' % (d, p, meth)):
            continue
        ranks = sorted(glob.glob('%s/time_p%d_%s_rank*.txt' % (d, p, meth)))
        vals = [tv(f) for f in ranks]
        cpu = sum(v[0] for v in vals)
        rss = max(v[1] for v in vals)
        rss1 = rss if rss1 is None else rss1
        wall = float(open('%s/wall_p%d_%s.txt' % (d, p, meth)).read())
        cd = coords(np.load(pd + '/rom_P0.npy'), np.asarray(np.load(pd + '/rom_V0.npy', mmap_mode='r')))
        y = np.load('%s/y_p%d_%s.npy' % (d, p, meth))
        ey = np.abs(y - ys).max() / np.abs(ys).max()
        dk, dq = opdiff(sd, pd)
        print('| %s | P = %d | %.1f | %.1f | %.0f | %.3f | %d | %s | %.1e, %.1e | %.1e |' % (meth, p, wall, cpu, rss, rss / rss1,
              len(cd), 'yes' if cd == cs else 'NO', dk, dq, ey))
PYEOF
