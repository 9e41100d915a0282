#!/bin/sh
# test_cli_lowrank.sh — reduce --method bt|prbt|phbt (balancing, no snapshots)
# through the command line, against an independent computation (SciPy):
# tests/check_cli_lowrank.py (what it checks is described there) on a small
# lattice and heat model, as COO files (the low-rank solvers) and dense .npy
# files (the dense solvers); and the log of a low-rank run (the solver, the
# Gramian ranks and residuals, the bound); --lyap eksm against the ADI run,
# also on a model with a mass matrix (--E-coo).
# Usage: sh tests/test_cli_lowrank.sh build/phgmg      (from the repository root)
# Needs NumPy and SciPy in /usr/bin/python3 (skipped with a note otherwise).
set -u
P=${1:-build/phgmg}
case "$P" in /*) ;; *) P="$PWD/$P" ;; esac
PY=/usr/bin/python3
ROOT=$PWD
T=$(mktemp -d "${TMPDIR:-/tmp}/phgmg_lowrank.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT INT TERM
[ -x "$P" ] || { echo "test_cli_lowrank: $P is not an executable (build it first)"; exit 1; }
if ! "$PY" -c 'import numpy, scipy' 2>/dev/null; then
  echo "test_cli_lowrank: skipped ($PY has no NumPy/SciPy)"
  exit 0
fi
nfail=0
"$PY" "$ROOT/tests/check_cli_lowrank.py" "$P" "$T" > "$T/check.txt" 2>&1 || { cat "$T/check.txt"; nfail=$((nfail + 1)); }
D="$T/lattice"
"$P" reduce --J-coo "$D/J.npy" --R-coo "$D/R.npy" --Q-coo "$D/Q.npy" --B "$D/B.npy" --method bt --r 8 \
  --out "$T/log" --name bt > "$T/log.txt" 2>&1 || { echo "FAIL: bt run"; nfail=$((nfail + 1)); }
for w in "reducing: bt, r = 8 (low-rank, sparse solvers)" "Gramian factor ranks" "Lyapunov residuals" \
         "H-infinity error bound"; do
  grep -F -q "$w" "$T/log.txt" || { echo "FAIL: the log lacks '$w'"; cat "$T/log.txt"; nfail=$((nfail + 1)); }
done
grep -q '"gramian_rank": \[[1-9]' "$T/log/bt.json" || { echo "FAIL: bt.json lacks the Gramian ranks"; nfail=$((nfail + 1)); }
# The extended Krylov solver (--lyap eksm) on the same lattice: its Hankel
# singular values against the ADI run's above (within 1e-8 sigma_1), the
# solver named in the log and in the json records; a bad value is a usage error.
"$P" reduce --J-coo "$D/J.npy" --R-coo "$D/R.npy" --Q-coo "$D/Q.npy" --B "$D/B.npy" --method bt --r 8 \
  --lyap eksm --out "$T/log" --name bteksm > "$T/logk.txt" 2>&1 || { echo "FAIL: bt --lyap eksm run"; cat "$T/logk.txt"; nfail=$((nfail + 1)); }
grep -F -q "computed (extended Krylov, EKSM)" "$T/logk.txt" || { echo "FAIL: the eksm log lacks its solver"; cat "$T/logk.txt"; nfail=$((nfail + 1)); }
"$PY" - "$T/log/bt.json" "$T/log/bteksm.json" <<'EOF_PY' || nfail=$((nfail + 1))
import json, sys
a, k = (json.load(open(f))["info"] for f in sys.argv[1:3])
sa, sk = a["hankel_singular_values"], k["hankel_singular_values"]
n = min(len(sa), len(sk))
err = max(abs(x - y) for x, y in zip(sa[:n], sk[:n])) / sa[0]
ok = a["lyapunov_solver"] == "adi" and k["lyapunov_solver"] == "eksm" and n >= 8 and err <= 1e-8 and \
     max(k["lyapunov_residual"]) <= 1e-10
print("test_cli_lowrank: --lyap eksm vs adi: %d Hankel singular values within %.2g sigma_1, residuals %s%s"
      % (n, err, k["lyapunov_residual"], "" if ok else "  FAIL"))
sys.exit(0 if ok else 1)
EOF_PY
# A mass matrix (--E-coo): a 1-D heat model in P1 finite elements (150 nodes,
# consistent mass E = M, R = K + 0.1 M, J = 0, Q = I, two ports M g, states
# scrambled): --lyap eksm and --lyap adi, their Hankel singular values against
# each other and against SciPy's dense ones (the E^{-1} model's Gramians by
# solve_continuous_lyapunov), both within 1e-8 sigma_1.
M="$T/mass"
"$PY" - "$M" <<'EOF_PY' || { echo "FAIL: the mass-matrix model"; nfail=$((nfail + 1)); }
import os, sys
import numpy as np
import scipy.sparse as sps
out, n = sys.argv[1], 150
rng = np.random.default_rng(5)
x = np.linspace(0.0, 1.0, n)
x[1:-1] += rng.uniform(-0.3, 0.3, n - 2) / (n - 1)
M = np.zeros((n, n)); K = np.zeros((n, n))
for e in range(n - 1):
    h = x[e + 1] - x[e]
    M[e:e + 2, e:e + 2] += h * np.array([[1 / 3, 1 / 6], [1 / 6, 1 / 3]])
    K[e:e + 2, e:e + 2] += np.array([[1, -1], [-1, 1]]) / h
g = [np.maximum(0, 1 - np.abs(x - 0.2) / 0.15), np.maximum(0, 1 - np.abs(x - 0.75) / 0.2)]
B = np.column_stack([M @ g[0], M @ g[1]])
p = rng.permutation(n)
os.makedirs(out, exist_ok=True)
for name, A in (("E", M), ("R", K + 0.1 * M), ("J", np.zeros((n, n))), ("Q", np.eye(n))):
    c = sps.coo_matrix(A[np.ix_(p, p)])
    np.save("%s/%s.npy" % (out, name), np.column_stack([c.row, c.col, c.data]).astype(float))
np.save(out + "/B.npy", B[p])
EOF_PY
for s in adi eksm; do
  "$P" reduce --J-coo "$M/J.npy" --R-coo "$M/R.npy" --Q-coo "$M/Q.npy" --E-coo "$M/E.npy" --B "$M/B.npy" \
    --method bt --r 8 --lyap $s --out "$T/log" --name btm$s > "$T/logm$s.txt" 2>&1 ||
    { echo "FAIL: bt --E-coo --lyap $s run"; cat "$T/logm$s.txt"; nfail=$((nfail + 1)); }
done
"$PY" - "$M" "$T/log/btmadi.json" "$T/log/btmeksm.json" <<'EOF_PY' || nfail=$((nfail + 1))
import json, sys
import numpy as np
import scipy.linalg as sla
d = sys.argv[1]
a, k = (json.load(open(f))["info"] for f in sys.argv[2:4])
B = np.load(d + "/B.npy")
N = B.shape[0]
def dense(name):
    t = np.load("%s/%s.npy" % (d, name))
    X = np.zeros((N, N))
    np.add.at(X, (t[:, 0].astype(int), t[:, 1].astype(int)), t[:, 2])
    return X
E, J, R, Q = (dense(x) for x in "EJRQ")
Ai = np.linalg.solve(E, (J - R) @ Q)
Bi = np.linalg.solve(E, B)
C = B.T @ Q
P = sla.solve_continuous_lyapunov(Ai, -Bi @ Bi.T)
O = sla.solve_continuous_lyapunov(Ai.T, -C.T @ C)
ref = np.sort(np.sqrt(np.abs(np.linalg.eigvals(P @ O))))[::-1]
sa, sk = a["hankel_singular_values"], k["hankel_singular_values"]
n = min(len(sa), len(sk), 8)
e_ak = max(abs(x - y) for x, y in zip(sa[:n], sk[:n])) / sa[0]
e_ref = max(abs(x - y) for x, y in zip(sk[:n], ref[:n])) / ref[0]
ok = a["lyapunov_solver"] == "adi" and k["lyapunov_solver"] == "eksm" and n == 8 and e_ak <= 1e-8 and \
     e_ref <= 1e-8 and max(k["lyapunov_residual"]) <= 1e-10
print("test_cli_lowrank: mass matrix, --lyap eksm vs adi: %d Hankel singular values within %.2g sigma_1, vs "
      "SciPy %.2g; residuals %s%s" % (n, e_ak, e_ref, k["lyapunov_residual"], "" if ok else "  FAIL"))
sys.exit(0 if ok else 1)
EOF_PY
# Algebraic equations (an index-one RLC grid, bench/rlc_grid.py): --lyap eksm
# refuses them (exit 1), naming the zero rows of E.
"$PY" "$ROOT/bench/rlc_grid.py" "$T/rlc" --n 6 > /dev/null 2>&1 || { echo "FAIL: rlc_grid.py"; nfail=$((nfail + 1)); }
"$P" reduce --J-coo "$T/rlc/J.npy" --R-coo "$T/rlc/R.npy" --Q-coo "$T/rlc/Q.npy" --E-coo "$T/rlc/E.npy" \
  --B "$T/rlc/B.npy" --method bt --r 6 --lyap eksm --out "$T/log" --name btrlc > "$T/logr.txt" 2>&1
[ $? -eq 1 ] && grep -F -q "mass matrix of full rank only" "$T/logr.txt" && grep -F -q "zero rows" "$T/logr.txt" ||
  { echo "FAIL: --lyap eksm on algebraic equations"; cat "$T/logr.txt"; nfail=$((nfail + 1)); }
"$P" reduce --J-coo "$D/J.npy" --R-coo "$D/R.npy" --Q-coo "$D/Q.npy" --B "$D/B.npy" --method bt --r 8 \
  --lyap krylov --out "$T/log" --name bad > "$T/logb.txt" 2>&1
[ $? -eq 2 ] || { echo "FAIL: --lyap krylov is not a usage error"; nfail=$((nfail + 1)); }
if [ "$nfail" -eq 0 ]; then echo "test_cli_lowrank: all passed"; else echo "test_cli_lowrank: $nfail failed"; exit 1; fi
