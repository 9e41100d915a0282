#!/bin/sh
# test_cli_workflow.sh — the command line in a finite-element engineer's
# workflow.
#
# Usage: sh tests/test_cli_workflow.sh build/phgmg      (from the repository root)
#
# A damped mass-spring chain of 12 masses (N = 24, one force port):
# 1. a sweep in one call: reduce --method gmg-pod,sp1 --r 4,6,8 writes
#    NAME_<method>_r<R>.* for every pair and NAME_sweep.json listing them;
#    each model equals the model a single-model reduce builds (to 1e-12);
#    validate --r 2,16 (one full run per test for both) writes the models that pass, not those that
#    fail (exit 1), and records every test in NAME_sweep.json.
# 2. cheap checks before any work: a malformed list, an order too large for
#    one of the models, an unknown method in a list -- status 2, nothing
#    simulated, nothing written.
# 3. --J-coo triplets with duplicates (split entries, a cancelling pair) give
#    the dense model's output (phgmg_csc_from_coo sums them).
# 4. NAME_PD.npy ([Ph; S + N]) of a model with feedthrough; NAME.json's E,
#    N_full and feedthrough.
# 5. --input sin --freq, --input chirp, --x0 against SciPy (solve_ivp, expm).
# 6. SciPy .npz (save_npz) and Matrix Market .mtx (mmwrite) as --X-coo specs;
#    malformed ones refused with a message naming the file.
# 7. subnormal entries flushed in the written model; --dt-map's note; the
#    record's kind and map.
# 8. a progress line before a large model's set-up (ordering, checks).
# 9. springs (--poly-jdx) against the same chain in relative coordinates.
# Needs NumPy/SciPy (/usr/bin/python3) to write the inputs (skipped otherwise).
set -u
P=${1:-build/phgmg}
case "$P" in /*) ;; *) P="$PWD/$P" ;; esac
PY=/usr/bin/python3
T=$(mktemp -d "${TMPDIR:-/tmp}/phgmg_wf.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT INT TERM
npass=0
nfail=0
pass() { npass=$((npass + 1)); }
bad() { echo "FAIL: $*"; nfail=$((nfail + 1)); }
[ -x "$P" ] || { echo "test_cli_workflow: $P is not an executable (build it first)"; exit 1; }
cd "$T" || exit 1
if ! "$PY" -c 'import numpy, scipy' 2>/dev/null; then
  echo "test_cli_workflow: skipped ($PY has no NumPy/SciPy)"
  exit 0
fi
"$PY" - <<'PYEOF' || bad "writing the chain"
import numpy as np
n = 12
K = 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
Z = np.zeros((n, n))
J = np.block([[Z, np.eye(n)], [-np.eye(n), Z]])
R = np.block([[Z, Z], [Z, 0.1 * np.eye(n)]])
Q = np.block([[K, Z], [Z, np.eye(n)]])
B = np.zeros(2 * n); B[n] = 1.0
for k, v in dict(J=J, R=R, Q=Q, B=B).items():
    np.save(k + ".npy", v)
PYEOF
SYS="--J J.npy --R R.npy --Q Q.npy --B B.npy"
TRAIN="--simulate --steps 200 --dt 0.1"
close() { "$PY" -c "
import numpy as np, sys
a, b = np.load('$1'), np.load('$2')
sys.exit(0 if a.shape == b.shape and np.abs(a - b).max() <= 1e-12 * max(1.0, np.abs(b).max()) else 1)"; }

# 1. reduce: a sweep over two methods and three orders
"$P" reduce $SYS $TRAIN --method gmg-pod,sp1 --r 4,6,8 --out sw >out.txt 2>err.txt && pass \
  || bad "reduce sweep: $(tail -n 2 err.txt)"
for m in gmg_pod sp1; do for r in 4 6 8; do
  for f in rom_${m}_r$r.phgmgrom rom_${m}_r$r.c rom_${m}_r$r.json rom_${m}_r${r}_Qh.npy rom_${m}_r${r}_V0.npy; do
    [ -f "sw/$f" ] && pass || bad "sweep: sw/$f missing"
  done
done; done
[ -f sw/rom.phgmgrom ] && bad "a sweep wrote the single-model name rom.phgmgrom" || pass
"$PY" - <<'PYEOF' && pass || bad "rom_sweep.json does not list the six models"
import json
d = json.load(open("sw/rom_sweep.json"))
got = sorted((m["method"], m["r"], m["name"], m["written"]) for m in d["models"])
want = sorted((me, r, "rom_%s_r%d" % (me.replace("-", "_"), r), True) for me in ("gmg-pod", "sp1") for r in (4, 6, 8))
assert got == want, got
for m in d["models"]:
    j = json.load(open("sw/" + m["json"]))
    assert j["method"] == m["method"] and j["r"] == m["r"], j
PYEOF
grep -c "^phgmg: simulating the full model" err.txt | grep -qx 1 && pass \
  || bad "the sweep did not simulate the training run once: $(grep -c simulating err.txt)"
# each model of the sweep is the model a reduce of that (method, r) alone builds
"$P" reduce $SYS $TRAIN --method gmg-pod --r 6 --out one --name g6 >/dev/null 2>err.txt && pass || bad "reduce r 6"
"$P" reduce $SYS $TRAIN --method sp1 --r 8 --out one --name s8 >/dev/null 2>err.txt && pass || bad "reduce sp1 r 8"
for f in Qh K Bh V0; do
  close sw/rom_gmg_pod_r6_$f.npy one/g6_$f.npy && pass || bad "sweep gmg-pod r 6: $f differs from the single model's"
  close sw/rom_sp1_r8_$f.npy one/s8_$f.npy && pass || bad "sweep sp1 r 8: $f differs from the single model's"
done
"$PY" -c "
import json, sys
a, b = json.load(open('sw/rom_gmg_pod_r6.json')), json.load(open('one/g6.json'))
x, y = a['info']['pod_sigma_ratio'], b['info']['pod_sigma_ratio']
sys.exit(0 if y > 0 and abs(x - y) <= 1e-8 * y else 1)" && pass || bad "the sweep's sigma ratio is not the single model's"

# validate: a sweep whose small order fails --max-ey
"$P" validate $SYS $TRAIN --method gmg-pod --r 2,16 --max-ey 0.05 --out va >vout.txt 2>verr.txt
[ $? -eq 1 ] && pass || bad "validate sweep with a failing model: status not 1: $(tail -n 3 vout.txt verr.txt)"
[ -f va/rom_gmg_pod_r16.phgmgrom ] && pass || bad "validate sweep: the passing model r = 16 was not written"
[ -f va/rom_gmg_pod_r2.phgmgrom ] && bad "validate sweep: the failing model r = 2 was written" || pass
grep -q "sin \[gmg-pod r=2\]" vout.txt && grep -q "sin \[gmg-pod r=16\]" vout.txt && pass \
  || bad "validate sweep: no line per model: $(cat vout.txt)"
"$PY" - <<'PYEOF' && pass || bad "va/rom_sweep.json does not record the tests"
import json
d = json.load(open("va/rom_sweep.json"))
m = {x["r"]: x for x in d["models"]}
assert m[2]["written"] is False and m[16]["written"] is True
assert m[2]["tests"][0]["input"] == "sin" and m[2]["tests"][0]["pass"] is False
assert m[16]["tests"][0]["e_y"] < 0.05 < m[2]["tests"][0]["e_y"]
PYEOF

# 2. cheap checks first
for spec in "4,,6" "4,4" "0" "4," "a"; do
  "$P" reduce $SYS $TRAIN --method gmg-pod --r "$spec" --out bad1 >/dev/null 2>err.txt
  [ $? -eq 2 ] && pass || bad "--r '$spec': status not 2"
done
"$P" reduce $SYS $TRAIN --method gmg-pod,sp3 --r 4 --out bad1 >/dev/null 2>err.txt
[ $? -eq 2 ] && grep -q "sp3\|gmg-pod,sp3" err.txt && pass || bad "--method gmg-pod,sp3: $(cat err.txt)"
"$P" reduce $SYS $TRAIN --method gmg-pod,sp1 --r 4,30 --out bad2 >/dev/null 2>err.txt
st=$?
[ $st -eq 2 ] && grep -q -- "--r 30" err.txt && pass || bad "--r 4,30 with N = 24: status $st: $(cat err.txt)"
grep -q "simulating" err.txt && bad "--r 4,30: simulated before refusing" || pass
[ -e bad2 ] && bad "--r 4,30: the output directory was left behind" || pass

# 3. coordinate triplets as FE assembly writes them: each entry split into
#    two parts and a pair that cancels -- the model is the dense one
"$PY" - <<'PYEOF' || bad "writing the triplets"
import numpy as np
for k in "JRQ":
    A = np.load(k + ".npy")
    r, c = np.nonzero(A)
    v = A[r, c]
    rows = np.concatenate([r, r, [0, 0]]); cols = np.concatenate([c, c, [1, 1]])
    vals = np.concatenate([0.25 * v, 0.75 * v, [0.5, -0.5]])
    p = np.random.default_rng(1).permutation(len(rows))
    np.save(k + "_coo.npy", np.column_stack([rows[p], cols[p], vals[p]]))
PYEOF
"$P" simulate $SYS --steps 100 --out yd.npy >/dev/null 2>err.txt && pass || bad "simulate dense: $(tail -n 2 err.txt)"
"$P" simulate --J-coo J_coo.npy --R-coo R_coo.npy --Q-coo Q_coo.npy --B B.npy --steps 100 --out yc.npy >/dev/null \
  2>err.txt && pass || bad "simulate from triplets with duplicates: $(tail -n 2 err.txt)"
"$PY" -c "
import numpy as np, sys
a, b = np.load('yd.npy'), np.load('yc.npy')
sys.exit(0 if np.abs(a - b).max() <= 1e-12 * np.abs(a).max() else 1)" && pass \
  || bad "the model from triplets with duplicates differs from the dense one"

# 4. feedthrough where users read the model: NAME_PD.npy is [Ph; S + N]
#    ((r + m) x m, the last m rows S + N exactly); NAME.json records E and
#    the model's whole N
"$PY" - <<'PYEOF' || bad "writing P, S, E"
import numpy as np
n = 12
P = np.zeros(2 * n); P[n + 3] = 0.05
np.save("P.npy", P); np.save("S.npy", np.array([[0.5]])); np.save("E.npy", 2.0 * np.eye(2 * n))
PYEOF
"$P" reduce $SYS --P P.npy --S S.npy $TRAIN --method gmg-pod --r 6 --out fd >/dev/null 2>err.txt && pass \
  || bad "reduce with feedthrough: $(tail -n 2 err.txt)"
"$PY" - <<'PYEOF' && pass || bad "fd/rom_PD.npy or fd/rom.json"
import json, numpy as np
D = np.load("fd/rom_PD.npy")
assert D.shape == (7, 1), D.shape
assert D[6, 0] == 0.5 and np.abs(D[:6]).max() > 0
j = json.load(open("fd/rom.json"))
assert j["E"] is False and j["N_full"] == 24 and j["feedthrough"] is True
assert "rom_PD.npy" in j["files"]["arrays"]
PYEOF
"$P" reduce $SYS --E E.npy $TRAIN --method gmg-pod --r 6 --out fe >/dev/null 2>err.txt && pass \
  || bad "reduce with E: $(tail -n 2 err.txt)"
"$PY" -c "
import json, sys
j = json.load(open('fe/rom.json'))
sys.exit(0 if j['E'] is True and j['feedthrough'] is False and j['N_full'] == 24 else 1)" && pass \
  || bad "fe/rom.json does not record the mass matrix"
[ -f fe/rom_PD.npy ] && bad "a model without feedthrough has rom_PD.npy" || pass

# 5. inputs: --input sin --freq 2 and --input chirp (--freq 1 --freq-end 4)
#    against SciPy's solve_ivp; --x0 (simulate: N states; simulate-rom: r
#    reduced states) against the matrix exponential with u = 0
"$P" simulate $SYS --steps 200 --dt 0.05 --input sin --freq 2 --amp 0.3 --out ysin.npy >/dev/null 2>err.txt && pass \
  || bad "simulate --freq: $(tail -n 2 err.txt)"
"$P" simulate $SYS --steps 200 --dt 0.05 --input chirp --freq 1 --freq-end 4 --amp 0.3 --out ych.npy >/dev/null \
  2>err.txt && pass || bad "simulate --input chirp: $(tail -n 2 err.txt)"
grep -q "chirp from 1 to 4" err.txt && pass || bad "the log does not describe the chirp: $(cat err.txt)"
"$PY" -c "import numpy as np; x = np.zeros(24); x[3] = 0.2; x[15] = -0.1; np.save('x0.npy', x)"
"$P" simulate $SYS --steps 100 --dt 0.05 --amp 0 --x0 x0.npy --out yx0.npy >/dev/null 2>err.txt && pass \
  || bad "simulate --x0: $(tail -n 2 err.txt)"
"$PY" - <<'PYEOF' && pass || bad "sin --freq / chirp / --x0 differ from SciPy"
import numpy as np
from scipy.integrate import solve_ivp
from scipy.linalg import expm
J, R, Q, B = (np.load(k + ".npy") for k in "JRQB")
A = (J - R) @ Q
def run(u, T):
    f = lambda t, x: A @ x + B * u(t)
    t = np.arange(0, T + 1e-12, 0.05)
    s = solve_ivp(f, (0, t[-1]), np.zeros(24), t_eval=t, method="DOP853", rtol=1e-12, atol=1e-14)
    return B @ Q @ s.y
T = 10.0
ys = run(lambda t: 0.3 * np.sin(2 * t), T)
yc = run(lambda t: 0.3 * np.sin(1 * t + 0.5 * (4 - 1) * t * t / T), T)
for f, yr in (("ysin.npy", ys), ("ych.npy", yc)):
    y = np.load(f)[0]
    assert np.abs(y - yr).max() <= 1e-6 * np.abs(yr).max(), (f, np.abs(y - yr).max())
x0 = np.load("x0.npy")
y = np.load("yx0.npy")[0]
ye = np.array([B @ Q @ expm(A * 0.05 * n) @ x0 for n in range(101)])
assert np.abs(y - ye).max() <= 1e-8 * np.abs(ye).max(), np.abs(y - ye).max()
PYEOF
"$P" reduce $SYS $TRAIN --method gmg-pod --r 16 --dt-map 0 --out rx >/dev/null 2>err.txt && pass || bad "reduce r 16"
"$PY" -c "import numpy as np; x = np.zeros(16); x[2] = 0.3; x[5] = -0.2; np.save('xr0.npy', x)"
RT=1e-8   # the reduced model's scalar: float in build/phgmg-float
case "$P" in *float*) RT=1e-5 ;; esac
"$P" simulate-rom --model rx/rom.phgmgrom --steps 60 --dt 0.05 --amp 0 --x0 xr0.npy --out yrx.npy >/dev/null 2>err.txt \
  && pass || bad "simulate-rom --x0: $(tail -n 2 err.txt)"
RT=$RT "$PY" - <<'PYEOF' && pass || bad "simulate-rom --x0 differs from the reduced model's exponential"
import numpy as np, os
from scipy.linalg import expm
K, Qh, Bh = (np.load("rx/rom_%s.npy" % k) for k in ("K", "Qh", "Bh"))
x0 = np.load("xr0.npy")
y = np.load("yrx.npy")[0]
ye = np.array([(Bh.T @ Qh @ expm(K @ Qh * 0.05 * n) @ x0)[0] for n in range(61)])
assert np.abs(y - ye).max() <= float(os.environ["RT"]) * np.abs(ye).max(), np.abs(y - ye).max()
PYEOF
"$P" simulate-rom --model rx/rom.phgmgrom --steps 10 --x0 x0.npy --out bad.npy >/dev/null 2>err.txt
[ $? -eq 1 ] && grep -q "reduced initial state" err.txt && pass || bad "simulate-rom --x0 of the wrong size: $(cat err.txt)"
"$P" simulate $SYS --steps 10 --freq 0 --out bad.npy >/dev/null 2>err.txt
[ $? -eq 2 ] && pass || bad "--freq 0 accepted"

# 6. SciPy's sparse files wherever a coordinate SPEC is taken: save_npz csr
#    (deflate), csc, coo (stored) and Matrix Market general, symmetric and
#    skew-symmetric (mmwrite) give the dense model's output; a random J of
#    N = 400 (about 8 000 entries: dynamic Huffman blocks) too; malformed
#    files: status 1 and a message naming the file
"$PY" - <<'PYEOF' || bad "writing the .npz / .mtx files"
import numpy as np, scipy.sparse as sp, scipy.io as sio
J, R, Q = (np.load(k + ".npy") for k in "JRQ")
for k, A in (("J", J), ("R", R), ("Q", Q)):
    S = sp.csr_matrix(A)
    sp.save_npz(k + "_csr.npz", S)
    sp.save_npz(k + "_csc.npz", S.tocsc())
    sp.save_npz(k + "_coo.npz", S.tocoo(), compressed=False)
    sio.mmwrite(k + "_gen.mtx", sp.coo_matrix(A))
    sio.mmwrite(k + "_sym.mtx", sp.coo_matrix(A), symmetry="skew-symmetric" if k == "J" else "symmetric")
rng = np.random.default_rng(3)
W = sp.random(400, 400, density=0.025, random_state=4, format="csr")
JJ = (W - W.T).tocsr()
sp.save_npz("J400.npz", JJ)
np.save("J400.npy", JJ.toarray())
np.save("R400.npy", 0.1 * np.eye(400)); np.save("Q400.npy", np.eye(400))
b = np.zeros(400); b[7] = 1.0; np.save("B400.npy", b)
sp.save_npz("R400.npz", sp.csr_matrix(0.1 * np.eye(400))); sp.save_npz("Q400.npz", sp.identity(400, format="csr"))
raw = open("J_csr.npz", "rb").read()
open("trunc.npz", "wb").write(raw[: len(raw) // 2])
bad = bytearray(raw); i = raw.find(b"indices.npy") + 11 + 30; bad[i:i + 8] = b"\xff" * 8
open("corrupt.npz", "wb").write(bytes(bad))
open("bad_head.mtx", "w").write("%%MatrixMarket matrix array real general\n24 24\n")
open("bad_idx.mtx", "w").write("%%MatrixMarket matrix coordinate real general\n24 24 1\n25 1 1.0\n")
open("bad_size.mtx", "w").write("%%MatrixMarket matrix coordinate real general\n23 23 0\n")
PYEOF
for f in csr csc coo gen sym; do
  ext=npz; case $f in gen|sym) ext=mtx ;; esac
  "$P" simulate --J-coo J_$f.$ext --R-coo R_$f.$ext --Q-coo Q_$f.$ext --B B.npy --steps 100 --out y_$f.npy >/dev/null \
    2>err.txt && pass || bad "simulate from $f.$ext: $(tail -n 2 err.txt)"
  "$PY" -c "
import numpy as np, sys
a, b = np.load('yd.npy'), np.load('y_$f.npy')
sys.exit(0 if np.abs(a - b).max() <= 1e-12 * np.abs(a).max() else 1)" && pass || bad "$f.$ext: not the dense model"
done
"$P" simulate --J J400.npy --R R400.npy --Q Q400.npy --B B400.npy --steps 20 --out y4d.npy >/dev/null 2>&1 && pass \
  || bad "simulate N = 400 dense"
"$P" simulate --J-coo J400.npz --R-coo R400.npz --Q-coo Q400.npz --B B400.npy --steps 20 --out y4s.npy >/dev/null \
  2>err.txt && pass || bad "simulate N = 400 from .npz: $(tail -n 2 err.txt)"
"$PY" -c "
import numpy as np, sys
a, b = np.load('y4d.npy'), np.load('y4s.npy')
sys.exit(0 if np.abs(a - b).max() <= 1e-12 * np.abs(a).max() else 1)" && pass || bad "N = 400 .npz: not the dense model"
for f in trunc.npz corrupt.npz bad_head.mtx bad_idx.mtx bad_size.mtx; do
  "$P" simulate --J-coo $f --R-coo R_gen.mtx --Q-coo Q_gen.mtx --B B.npy --steps 5 --out yb.npy >/dev/null 2>err.txt
  st=$?
  [ $st -eq 1 ] && grep -q "$f (--J-coo)" err.txt && pass || bad "malformed $f: status $st: $(cat err.txt)"
done

# 7. the log and the record: a badly scaled Q (1e-300, J and R 1e300) leaves
#    rounding residue below DBL_MIN in Qh: set to 0 in rom_Qh.npy and rom.c;
#    --dt-map on a model that cannot have a step map draws a note; "kind" is
#    the model's (nonlinear for Toda springs), "map" the reduction map's
"$PY" -c "
import numpy as np
np.save('Qt.npy', 1e-300 * np.load('Q.npy'))
for k in 'JR': np.save(k + 't.npy', 1e300 * np.load(k + '.npy'))
np.save('idx.npy', np.arange(12))"
"$P" reduce --J Jt.npy --R Rt.npy --Q Qt.npy --B B.npy $TRAIN --method gmg-pod --r 8 --dt-map 0 --out sub >/dev/null \
  2>err.txt && pass || bad "reduce of the badly scaled model: $(tail -n 2 err.txt)"
"$PY" -c "
import numpy as np, sys
a = np.load('sub/rom_Qh.npy')
sys.exit(0 if np.abs(a).max() > 0 and not ((a != 0) & (np.abs(a) < sys.float_info.min)).any() else 1)" && pass \
  || bad "rom_Qh.npy holds subnormal entries"
grep -q "below the smallest normal number set to 0" err.txt && pass || bad "no log line on the flushed entries"
grep -Eq "e-3(0[89]|[1-2][0-9])[^0-9]" sub/rom.c && bad "rom.c holds subnormal constants" || pass
"$P" reduce $SYS --potential toda --poly-idx idx.npy $TRAIN --method gmg-pod --r 8 --dt-map 0.1 --out tn >/dev/null \
  2>err.txt && pass || bad "reduce Toda: $(tail -n 2 err.txt)"
grep -q "note: --dt-map 0.1 has no effect" err.txt && pass || bad "--dt-map ignored without a word: $(cat err.txt)"
"$PY" -c "
import json, sys
a, b = json.load(open('tn/rom.json')), json.load(open('one/g6.json'))
sys.exit(0 if (a['kind'], a['map'], b['kind'], b['map']) == ('nonlinear', 'linear', 'linear', 'linear') else 1)" \
  && pass || bad "rom.json's kind/map"
"$P" reduce $SYS $TRAIN --method gmg-pod --r 6 --dt-map 0.1 --out tl >/dev/null 2>err.txt && pass || bad "reduce r 6"
grep -q "note: --dt-map" err.txt && bad "a note on --dt-map where the map is built: $(cat err.txt)" || pass

# 8. a large model's set-up is announced before it starts (N >= 20 000)
"$PY" - <<'PYEOF' || bad "writing the large chain"
import numpy as np, scipy.sparse as sp
n = 10000
K = sp.diags([2.0 * np.ones(n), -np.ones(n - 1), -np.ones(n - 1)], [0, 1, -1])
I = sp.identity(n)
sp.save_npz("Jb.npz", sp.bmat([[None, I], [-I, None]]).tocsr())
sp.save_npz("Rb.npz", sp.block_diag([sp.csr_matrix((n, n)), 0.1 * I]).tocsr())
sp.save_npz("Qb.npz", sp.block_diag([K, I]).tocsr())
b = np.zeros(2 * n); b[n] = 1.0; np.save("Bb.npy", b)
PYEOF
"$P" simulate --J-coo Jb.npz --R-coo Rb.npz --Q-coo Qb.npz --B Bb.npy --steps 2 --out yb.npy >/dev/null 2>err.txt \
  && pass || bad "simulate N = 20000: $(tail -n 2 err.txt)"
grep -q "ordering the sparse system (N = 20000)" err.txt && grep -q "checking the system (N = 20000)" err.txt && pass \
  || bad "no progress line before a large model's set-up: $(cat err.txt)"

# 9. springs (--poly-jdx): a chain with cosh springs between neighbouring
#    positions, phi(q_k - q_{k-1}) (node 0 to the wall: j = -1), against the
#    same model in relative coordinates l = D q (NumPy: T = blockdiag(D, I),
#    J~ = T J T^T, R~ = T R T^T, Q~ = T^-T Q T^-1, B~ = T B), where every
#    term acts on one coordinate l_k (--poly-idx alone). The outputs are
#    invariant and GL3 is covariant under linear maps, so both runs give
#    the same y up to the Newton tolerance (1e-13 absolute here): 1e-10
#    relative asserted. reduce takes the springs (hyper-reduced, rom.c
#    written, poly_jdx recorded); a bad entry is refused naming the file.
"$PY" - <<'PYEOF' || bad "writing the spring chain"
import numpy as np
n = 12
D = np.eye(n) - np.eye(n, k=-1)                   # l = D q, l_0 = q_0 (the wall)
Z, I = np.zeros((n, n)), np.eye(n)
J = np.block([[Z, I], [-I, Z]])
R = np.block([[Z, Z], [Z, 0.05 * I]])
Q = np.block([[0.5 * D.T @ D, Z], [Z, I]])
B = np.zeros(2 * n); B[n] = 1.0
T = np.block([[D, Z], [Z, I]])
Ti = np.linalg.inv(T)
for k, v in dict(Js=J, Rs=R, Qs=Q, Bs=B, Jl=T @ J @ T.T, Rl=T @ R @ T.T, Ql=Ti.T @ Q @ Ti, Bl=T @ B).items():
    np.save(k + ".npy", v)
np.save("sidx.npy", np.arange(n)); np.save("sjdx.npy", np.arange(n) - 1)
np.save("sjbad.npy", np.where(np.arange(n) == 5, 5, np.arange(n) - 1))
PYEOF
SPR="--potential cosh:1 --poly-idx sidx.npy --input sin --amp 1.5 --dt 0.05 --steps 200 --newton-tol 1e-13"
"$P" simulate --J Js.npy --R Rs.npy --Q Qs.npy --B Bs.npy $SPR --poly-jdx sjdx.npy --out ys.npy >/dev/null 2>err.txt \
  && pass || bad "simulate with --poly-jdx: $(tail -n 2 err.txt)"
"$P" simulate --J Jl.npy --R Rl.npy --Q Ql.npy --B Bl.npy $SPR --out yl.npy >/dev/null 2>err.txt \
  && pass || bad "simulate in relative coordinates: $(tail -n 2 err.txt)"
"$PY" -c "
import numpy as np, sys
a, b = np.load('ys.npy'), np.load('yl.npy')
sys.exit(0 if a.shape == b.shape and np.abs(b).max() > 0.5 and np.abs(a - b).max() <= 1e-10 * np.abs(b).max() else 1)" \
  && pass || bad "springs (--poly-jdx) against the same chain in relative coordinates"
"$P" reduce --J Js.npy --R Rs.npy --Q Qs.npy --B Bs.npy --potential cosh:1 --poly-idx sidx.npy --poly-jdx sjdx.npy \
  --simulate --steps 200 --dt 0.05 --amp 1.5 --method gmg-pod --r 8 --out spr >/dev/null 2>err.txt \
  && [ -s spr/rom.c ] && grep -q '"poly_jdx"' spr/rom.json && pass || bad "reduce with --poly-jdx: $(tail -n 2 err.txt)"
"$P" simulate --J Js.npy --R Rs.npy --Q Qs.npy --B Bs.npy $SPR --poly-jdx sjbad.npy --out yb2.npy >/dev/null 2>err.txt
[ $? -eq 1 ] && grep -q "sjbad.npy (--poly-jdx): entry 5" err.txt && [ ! -e yb2.npy ] && pass \
  || bad "a spring from a node to itself not refused by name: $(tail -n 2 err.txt)"

echo "test_cli_workflow: $npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
