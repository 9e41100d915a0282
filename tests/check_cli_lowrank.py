"""`phgmg reduce --method bt|prbt|phbt` against an independent computation
(SciPy), on the two sparse models of bench/lowrank_models.py at small size:
an 8 x 8 mass-spring-damper lattice (N = 128, complex ADI shifts) and a
10 x 10 heat model (N = 100, J = 0), states scrambled, given as COO files
(the low-rank solvers) and as dense .npy files (the dense solvers).

  bt, both inputs: the Hankel singular values in NAME.json within 1e-8 sigma_1
     of the singular values of Lo^T Lp (P = Lp Lp^T, O = Lo Lo^T, the Gramians
     from scipy.linalg.solve_continuous_lyapunov), the bound
     equal to 2 sum_{i>r} sigma_i (1e-6 relative), the Lyapunov residuals <=
     1e-10 (low-rank) / 1e-12 (dense); the written pH model (NAME_K, NAME_Qh,
     NAME_Bh): Qh symmetric positive definite, K + K^T <= 0, its transfer
     function equal to that of the square-root BT done here (1e-6 of
     ||G||_inf on 200 frequencies in [1e-2, 1e2]) and within the bound of
     the full model's; its outputs (simulate-rom) against the full model's
     (simulate), 300 steps of dt 0.1, u_a = 0.1 sin((1 + a/2) t): the L2 norm
     of the difference within bound * ||u||_L2 (the H-infinity bound of the
     L2 gain from rest).
  prbt (lattice): the sparse two-stage run's positive-real singular values
     equal to the dense PRBT's (1e-8), the model pH (Qh > 0, K + K^T <= 0) and
     positive real on the 200 frequencies (G + G^H >= 0).
  phbt (lattice): pH structure (K + K^T <= 0, Qh > 0); the values sigma
     (NAME.json) within 1e-3 sigma_1 of sqrt(eig(P Xmin)), Xmin the minimal
     solution of the KYP inequality (SciPy's Riccati solver, D + D^T = 1e-10 I);
     the sampled H-infinity error within 2 % of that of the same balancing
     done here, and below 5 % of ||G|| (balancing against the energy Q
     instead gives 12 %); outputs following the full model (relative L2
     error < 5 % at r = 12).

Usage: /usr/bin/python3 tests/check_cli_lowrank.py PHGMG_BINARY WORKDIR
Exits 1 when a claim fails."""
import json, os, subprocess, sys
import numpy as np
import scipy.linalg as sla

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "bench"))
import lowrank_models   # noqa: E402

exe, work = sys.argv[1], sys.argv[2]
fails = []
W = np.logspace(-2, 2, 200)


def claim(ok, what):
    if not ok:
        fails.append(what)
        print("FAIL: " + what)


def run(*args):
    r = subprocess.run([exe] + list(args) + ["--quiet"], capture_output=True, text=True)
    if r.returncode != 0:
        print(r.stderr)
    return r.returncode


def tf(A, B, C, w):
    return C @ np.linalg.solve(1j * w * np.eye(A.shape[0]) - A, B)


def hinf(A1, B1, C1, A2=None, B2=None, C2=None):
    v = 0.0
    for w in W:
        G = tf(A1, B1, C1, w) - (tf(A2, B2, C2, w) if A2 is not None else 0)
        v = max(v, np.linalg.norm(G, 2))
    return v


def rom(d, name):
    K, Qh, Bh = (np.load(os.path.join(d, "%s_%s.npy" % (name, f))) for f in ("K", "Qh", "Bh"))
    return K, Qh, Bh


def ph_ok(K, Qh, tag):
    claim(np.allclose(Qh, Qh.T, atol=1e-12 * np.abs(Qh).max()) and np.linalg.eigvalsh(Qh).min() > 0,
          tag + ": Qh symmetric positive definite")
    e = np.linalg.eigvalsh(K + K.T)
    claim(e.max() <= 1e-10 * np.abs(e).max(), tag + ": K + K^T <= 0 (max eig %.3g)" % e.max())


def sqrt_bt(A, B, C, P, O, r):
    """Square-root BT from the Gramians (Cholesky-like factors by eigh)."""
    def fac(X):
        w, U = np.linalg.eigh((X + X.T) / 2)
        return U * np.sqrt(np.maximum(w, 0))
    Lp, Lo = fac(P), fac(O)
    U, s, Vt = np.linalg.svd(Lo.T @ Lp)
    T = Lp @ Vt[:r].T / np.sqrt(s[:r])
    Wm = Lo @ U[:, :r] / np.sqrt(s[:r])
    return Wm.T @ A @ T, Wm.T @ B, C @ T, s


def outputs_within_bound(d, model, name, bound, tag, steps=300):
    common = ["--steps", str(steps), "--dt", "0.1"]
    yf = os.path.join(d, "yf.npy")
    if not os.path.exists(yf):
        claim(run("simulate", *model, "--out", yf, *common) == 0, tag + ": simulate")
    claim(run("simulate-rom", "--model", os.path.join(d, name + ".phgmgrom"), "--out",
              os.path.join(d, "y_" + name + ".npy"), *common) == 0, tag + ": simulate-rom")
    a, b = np.load(yf), np.load(os.path.join(d, "y_" + name + ".npy"))
    t = 0.1 * np.arange(steps + 1)
    u = np.array([0.1 * np.sin((1 + k / 2.0) * t) for k in range(2)])
    l2 = lambda x: np.sqrt(np.trapz(np.sum(x * x, axis=0), t))   # noqa: E731
    return l2(a - b), l2(u), l2(a)


def bt_case(kind, n, r):
    d = os.path.join(work, kind)
    N, trip, B = lowrank_models.model(kind, n)
    os.makedirs(d, exist_ok=True)
    Jd, Rd, Qd = (lowrank_models.dense(N, t) for t in trip)
    for name, t, D in zip("JRQ", trip, (Jd, Rd, Qd)):
        np.save(os.path.join(d, name + ".npy"), t)
        np.save(os.path.join(d, name + "d.npy"), D)
    np.save(os.path.join(d, "B.npy"), B)
    A, C = (Jd - Rd) @ Qd, B.T @ Qd
    P = sla.solve_continuous_lyapunov(A, -B @ B.T)
    O = sla.solve_continuous_lyapunov(A.T, -C.T @ C)
    Ab, Bb, Cb, hsv = sqrt_bt(A, B, C, P, O, r)
    bound = 2 * hsv[r:].sum()
    g = hinf(A, B, C)
    coo = ["--J-coo", d + "/J.npy", "--R-coo", d + "/R.npy", "--Q-coo", d + "/Q.npy", "--B", d + "/B.npy"]
    dense = ["--J", d + "/Jd.npy", "--R", d + "/Rd.npy", "--Q", d + "/Qd.npy", "--B", d + "/B.npy"]
    for model, name, res_tol in ((coo, "lr", 1e-10), (dense, "dense", 1e-12)):
        tag = "%s %s bt r=%d" % (kind, name, r)
        if run("reduce", *model, "--method", "bt", "--r", str(r), "--out", d, "--name", name) != 0:
            claim(False, tag + ": reduce")
            continue
        info = json.load(open(os.path.join(d, name + ".json")))["info"]
        s = np.array(info["hankel_singular_values"])
        k = min(len(s), 40)
        claim(info["solver"] == ("low-rank" if name == "lr" else "dense"), tag + ": solver " + info["solver"])
        err = np.abs(s[:k] - hsv[:k]).max() / hsv[0]
        claim(err <= 1e-8, tag + ": HSVs vs SciPy %.3g sigma_1" % err)
        claim(abs(info["error_bound"] - bound) <= 1e-6 * bound,
              tag + ": bound %.6g vs %.6g" % (info["error_bound"], bound))
        claim(max(info["lyapunov_residual"]) <= res_tol, tag + ": residuals %s" % info["lyapunov_residual"])
        K, Qh, Bh = rom(d, name)
        ph_ok(K, Qh, tag)
        Ar, Cr = K @ Qh, Bh.T @ Qh
        e_bt = hinf(Ar, Bh, Cr, Ab, Bb, Cb)
        claim(e_bt <= 1e-6 * g, tag + ": pH model vs BT done here %.3g of ||G||" % (e_bt / g))
        e = hinf(A, B, C, Ar, Bh, Cr)
        claim(e <= bound, tag + ": sampled H-inf error %.3g within the bound %.3g" % (e, bound))
        ey, nu, ny = outputs_within_bound(d, model, name, bound, tag)
        claim(ey <= bound * nu, tag + ": output L2 error %.3g within bound * ||u|| %.3g" % (ey, bound * nu))
        print("%s: HSV err %.2g sigma_1, H-inf err %.3g <= bound %.3g, output err %.3g <= %.3g" %
              (tag, err, e, bound, ey, bound * nu))
    return d, coo, dense, A, B, C


d, coo, dense, A, B, C = bt_case("lattice", 8, 8)
bt_case("heat", 10, 6)

# prbt: the sparse two-stage run against the dense PRBT; passivity
r = 8
ok = run("reduce", *coo, "--method", "prbt", "--r", str(r), "--out", d, "--name", "prbt") == 0
ok = run("reduce", *dense, "--method", "prbt", "--r", str(r), "--out", d, "--name", "dprbt") == 0 and ok
claim(ok, "lattice prbt: reduce")
if ok:
    i1 = json.load(open(os.path.join(d, "prbt.json")))["info"]
    i2 = json.load(open(os.path.join(d, "dprbt.json")))["info"]
    claim(i1["stages"] == 2 and i2["stages"] == 1, "lattice prbt: two stages (sparse), one (dense)")
    e = np.abs(np.array(i1["positive_real_singular_values"]) - np.array(i2["positive_real_singular_values"])).max()
    claim(e <= 1e-8, "lattice prbt: PR singular values sparse vs dense %.3g" % e)
    K, Qh, Bh = rom(d, "prbt")
    ph_ok(K, Qh, "lattice prbt")
    pmin = min(np.linalg.eigvalsh(G + G.conj().T).min() for G in (tf(K @ Qh, Bh, Bh.T @ Qh, w) for w in W))
    claim(pmin >= -1e-12, "lattice prbt: positive real on the grid (min eig %.3g)" % pmin)
    ey, nu, ny = outputs_within_bound(d, coo, "prbt", 0, "lattice prbt")
    print("lattice prbt r=%d: PR values sparse vs dense %.2g, relative output error %.3g" % (r, e, ey / ny))

ok = run("reduce", *coo, "--method", "phbt", "--r", "12", "--out", d, "--name", "phbt") == 0
claim(ok, "lattice phbt: reduce")
if ok:
    K, Qh, Bh = rom(d, "phbt")
    ph_ok(K, Qh, "lattice phbt")
    # the balancing of the controllability Gramian against the minimal
    # Hamiltonian Xm (the minimal solution of the KYP inequality, here the
    # limit eps -> 0 of the positive-real Riccati equation with D + D^T = eps I)
    P = sla.solve_continuous_lyapunov(A, -B @ B.T)
    Xm = sla.solve_continuous_are(A, B, np.zeros_like(A), -1e-10 * np.eye(B.shape[1]), s=-C.T)
    w, U = np.linalg.eigh(P)
    L = U * np.sqrt(np.maximum(w, 0))
    sw, Y = np.linalg.eigh(L.T @ Xm @ L)
    sw, Y = np.sqrt(np.maximum(sw[::-1], 0)), Y[:, ::-1]
    info = json.load(open(os.path.join(d, "phbt.json")))["info"]
    sl = np.array(info["energy_singular_values"])[:12]
    claim(info.get("hamiltonian") == "minimal", "lattice phbt: the minimal Hamiltonian")
    es = np.abs(sl - sw[:12]).max() / sw[0]
    claim(es <= 1e-3, "lattice phbt: values vs sqrt(eig(P Xmin)) %.3g sigma_1" % es)
    T = L @ Y[:, :12] / np.sqrt(sw[:12])
    Wt = Xm @ T / sw[:12]
    e_ref = hinf(A, B, C, Wt.T @ A @ T, Wt.T @ B, C @ T)
    e = hinf(A, B, C, K @ Qh, Bh, Bh.T @ Qh)
    g = hinf(A, B, C)
    claim(abs(e - e_ref) <= 0.02 * e_ref and e <= 0.05 * g,
          "lattice phbt: sampled H-inf error %.4g vs %.4g (SciPy), %.3g of ||G||" % (e, e_ref, e / g))
    ey, nu, ny = outputs_within_bound(d, coo, "phbt", 0, "lattice phbt")
    claim(ey < 0.05 * ny, "lattice phbt: relative output error %.3g" % (ey / ny))
    print("lattice phbt r=12: relative output error %.3g" % (ey / ny))
# phbt needs sparse input; bt needs m < r
claim(run("reduce", *dense, "--method", "phbt", "--r", "8", "--out", d, "--name", "x") == 1,
      "phbt on dense input: an error")
claim(run("reduce", *coo, "--method", "bt", "--r", "2", "--out", d, "--name", "x") == 2,
      "bt with r = m: a usage error")
claim(run("reduce", *coo, "--method", "bt", "--r", "8", "--simulate", "--out", d, "--name", "x") == 2,
      "bt with --simulate: a usage error")
print("check_cli_lowrank: %d failed" % len(fails))
sys.exit(1 if fails else 0)
