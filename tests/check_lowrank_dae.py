"""`phgmg reduce --method bt` (low-rank, sparse) on descriptor models, against
an independent dense computation (NumPy/SciPy):

  rlc: an index-one RLC grid (bench/rlc_grid.py, 8 x 8 mains, N = 288, 144
     algebraic equations and variables, rows and states scrambled by
     different permutations). The reference condenses the DAE densely
     (A = (J - R) Q, the algebraic rows a = E's zero rows, the algebraic
     variables c = its zero columns: A' = A_dd - A_dc A_ac^{-1} A_ad,
     E' = E_dd, B' = B_d - A_dc A_ac^{-1} B_a, C' = C_d - C_c A_ac^{-1} A_ad,
     C = B^T Q), solves the two Lyapunov equations of E'^{-1} A' with
     scipy.linalg.solve_continuous_lyapunov and takes the Hankel singular
     values sqrt(eig(P O)).
  acoustic: the 2-D acoustic model in P1 finite elements with a consistent
     mass matrix (bench/fe_mesh.py, 9 x 9 nodes, N = 243), the same without
     algebraic lines (E^{-1} formed densely here). Its BT models are not
     passive (nor are those of the dense BT here: eig(G_r + G_r^H) < 0 on
     the grid), so they have no pH form: reduce refuses them, and the claim
     is the refusal and the H-infinity bound in its message (3 digits)
     against the reference's.

  Claims, each model: the Hankel singular values in NAME.json within 1e-8
  sigma_1 of the reference's (the first 40; the reference takes them as the
  singular values of Lo^T Lp, P = Lp Lp^T, O = Lo Lo^T), the bound
  2 sum_{i>r} sigma_i within 1e-6 of the reference's over the values the
  low-rank run computed, the written pH model (K, Qh, Bh) with Qh
  > 0 and K + K^T <= 0, and its sampled H-infinity error against the
  descriptor model's own transfer function C (i w E - A)^{-1} B (the whole
  pencil, no condensation) on 200 frequencies in [1e-2, 1e2] within that
  bound. rlc prbt: the positive-real singular values of the scrambled grid
  equal to those of the same grid in natural order (1e-8), the models pH.
  rlc with a port on an algebraic node (--port-on-constraint): the
  reference's feedthrough D = -C_c A_ac^{-1} B_a is not zero, and bt is
  refused with a message naming the feedthrough.

  --form ss (the BT model as state-space arrays, E_r = I), on the acoustic
  model and the grid with a port on a constraint, the two models without a
  pH form: the record states the form; its r Hankel values and sigma_{r+1}
  within 1e-8 sigma_1 of the reference's, its bound (a sum of the nv - r
  computed values beyond r) within 2 (nv - r) 1e-8 sigma_1; NAME_D.npy equal
  to the reference's D = -C_c A_ac^{-1} B_a (1e-10); the sampled H-infinity
  error of C (i w - A)^{-1} B + D against the descriptor model's transfer
  function (the whole pencil) on the 200 frequencies within the bound
  2 sum_{i>r} sigma_i, and, where D != 0, without D above it.
  simulate-rom --ss on the grid's model (dt = 0.01, 500 steps, input sin)
  against the exact response of x' = A x + B u from rest (steady state
  Im((i w - A)^{-1} B) plus expm(A t) of its initial defect): 1e-6 of max|y|.
  The refusals: the pH form's messages name --form ss; --form ss with
  prbt, a method list, a list of orders, a snapshot method, dense input,
  validate; --form xy; an output that would overwrite an input (the file
  unchanged); simulate-rom --model of a state-space model (naming --ss),
  --model with --ss, --out onto the model's arrays, a B of the wrong shape. One name reduced in both forms in turn: each run
  removes the other form's files; a pH run takes an input named like a
  state-space array (NAME_B.npy).

Usage: /usr/bin/python3 tests/check_lowrank_dae.py PHGMG_BINARY WORKDIR
Exits 1 when a claim fails."""
import json, os, re, subprocess, sys
import numpy as np
import scipy.linalg as sla

exe, work = sys.argv[1], sys.argv[2]
bench = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "bench")
fails = []
W = np.logspace(-2, 2, 200)


def claim(ok, what):
    if not ok:
        fails.append(what)
        print("FAIL: " + what)


def run(*args):
    r = subprocess.run([exe] + list(args) + ["--quiet"], capture_output=True, text=True)
    return r.returncode, r.stderr


def dense(path, N):
    t = np.load(path)
    M = np.zeros((N, N))
    np.add.at(M, (t[:, 0].astype(int), t[:, 1].astype(int)), t[:, 2])
    return M


def load(d):
    B = np.load(os.path.join(d, "B.npy"))
    N = B.shape[0]
    J, R, Q, E = (dense(os.path.join(d, n + ".npy"), N) for n in "JRQE")
    return (J - R) @ Q, E, B, B.T @ Q


def condense(A, E, B, C):
    """The dense condensation of an index-one descriptor model (E regular: as is)."""
    a = np.flatnonzero(np.abs(E).sum(axis=1) == 0)
    c = np.flatnonzero(np.abs(E).sum(axis=0) == 0)
    d = np.setdiff1d(np.arange(E.shape[0]), a)
    dc = np.setdiff1d(np.arange(E.shape[1]), c)
    if a.size == 0:
        return A, E, B, C, np.zeros((B.shape[1], B.shape[1]))
    Aac = A[np.ix_(a, c)]
    X = np.linalg.solve(Aac, np.hstack([A[np.ix_(a, dc)], B[a]]))
    Xa, Xb = X[:, :dc.size], X[:, dc.size:]
    Ac = A[np.ix_(d, dc)] - A[np.ix_(d, c)] @ Xa
    Bc = B[d] - A[np.ix_(d, c)] @ Xb
    Cc = C[:, dc] - C[:, c] @ Xa
    Dc = -C[:, c] @ Xb
    return Ac, E[np.ix_(d, dc)], Bc, Cc, Dc


def hsv(A, E, B, C):
    """sigma(Lo^T Lp), P = Lp Lp^T, O = Lo Lo^T (square roots by eigh): accurate
    to round-off of sigma_1 also for the small values (sqrt(eig(P O)) is not)."""
    Ad, Bd = np.linalg.solve(E, A), np.linalg.solve(E, B)
    P = sla.solve_continuous_lyapunov(Ad, -Bd @ Bd.T)
    O = sla.solve_continuous_lyapunov(Ad.T, -C.T @ C)

    def fac(X):
        w, U = np.linalg.eigh((X + X.T) / 2)
        return U * np.sqrt(np.maximum(w, 0))
    return np.linalg.svd(fac(O).T @ fac(P), compute_uv=False)


def bt_case(tag, d, r, passive=True):
    A, E, B, C = load(d)
    Ac, Ec, Bc, Cc, Dc = condense(A, E, B, C)
    s_ref = hsv(Ac, Ec, Bc, Cc)
    bound = 2 * s_ref[r:].sum()
    coo = ["--J-coo", d + "/J.npy", "--R-coo", d + "/R.npy", "--Q-coo", d + "/Q.npy", "--E-coo", d + "/E.npy",
           "--B", d + "/B.npy"]
    rc, err = run("reduce", *coo, "--method", "bt", "--r", str(r), "--out", d, "--name", "bt")
    if not passive:   # the BT model has no pH form: refused, the bound (3 digits) in the message
        m = re.search(r"not passive.*error bound ([0-9.e+-]+)\)", err)
        claim(rc == 1 and m is not None, "%s: refused as not passive (%d: %s)" % (tag, rc, err.strip()))
        if m:
            claim(abs(float(m.group(1)) - bound) <= 5e-3 * bound,
                  "%s: bound in the message %s vs %.6g" % (tag, m.group(1), bound))
            print("%s: N = %d, BT model not passive (as the dense BT's: %s), bound %s vs SciPy %.6g" %
                  (tag, A.shape[0], "min eig(G_r + G_r^H) %.3g" % dense_bt_pr(Ac, Ec, Bc, Cc, r), m.group(1), bound))
        return
    if rc != 0:
        claim(False, "%s: reduce --method bt failed: %s" % (tag, err.strip()))
        return
    info = json.load(open(os.path.join(d, "bt.json")))["info"]
    s = np.array(info["hankel_singular_values"])
    k = min(len(s), 40)
    e_s = np.abs(s[:k] - s_ref[:k]).max() / s_ref[0]
    claim(e_s <= 1e-8, "%s: HSVs vs SciPy %.3g sigma_1" % (tag, e_s))
    nv = info["values_computed"]   # the low-rank bound sums the computed values (manual 2.8)
    bound_k = 2 * s_ref[r:nv].sum()
    claim(abs(info["error_bound"] - bound_k) <= 1e-6 * bound_k,
          "%s: bound %.6g vs %.6g (the first %d values)" % (tag, info["error_bound"], bound_k, nv))
    K, Qh, Bh = (np.load(os.path.join(d, "bt_%s.npy" % f)) for f in ("K", "Qh", "Bh"))
    claim(np.allclose(Qh, Qh.T, atol=1e-12 * np.abs(Qh).max()) and np.linalg.eigvalsh(Qh).min() > 0,
          tag + ": Qh symmetric positive definite")
    ek = np.linalg.eigvalsh(K + K.T)
    claim(ek.max() <= 1e-10 * np.abs(ek).max(), tag + ": K + K^T <= 0 (max eig %.3g)" % ek.max())
    Ar, Cr = K @ Qh, Bh.T @ Qh
    e = 0.0
    for w in W:
        G = C @ np.linalg.solve(1j * w * E - A, B)
        Gr = Cr @ np.linalg.solve(1j * w * np.eye(r) - Ar, Bh)
        e = max(e, np.linalg.norm(G - Gr, 2))
    claim(e <= bound, "%s: sampled H-inf error %.3g within the bound %.3g" % (tag, e, bound))
    print("%s: N = %d (%d algebraic), HSVs vs SciPy %.2g sigma_1, sampled H-inf error %.3g <= bound %.3g" %
          (tag, A.shape[0], A.shape[0] - Ac.shape[0], e_s, e, bound))


def dense_bt_pr(A, E, B, C, r):
    """min over the grid of eig(G_r + G_r^H) of the dense square-root BT model."""
    Ad, Bd = np.linalg.solve(E, A), np.linalg.solve(E, B)
    P = sla.solve_continuous_lyapunov(Ad, -Bd @ Bd.T)
    O = sla.solve_continuous_lyapunov(Ad.T, -C.T @ C)

    def fac(X):
        w, U = np.linalg.eigh((X + X.T) / 2)
        return U * np.sqrt(np.maximum(w, 0))
    Lp, Lo = fac(P), fac(O)
    U, s, Vt = np.linalg.svd(Lo.T @ Lp)
    T, Wm = Lp @ Vt[:r].T / np.sqrt(s[:r]), Lo @ U[:, :r] / np.sqrt(s[:r])
    Ar, Br, Cr = Wm.T @ Ad @ T, Wm.T @ Bd, C @ T
    return min(np.linalg.eigvalsh(G + G.conj().T).min()
               for G in (Cr @ np.linalg.solve(1j * w * np.eye(r) - Ar, Br) for w in np.r_[0.0, W]))


def gen(script, *args):
    subprocess.run(["/usr/bin/python3", os.path.join(bench, script)] + list(args), check=True,
                   capture_output=True)


d = os.path.join(work, "rlc")
gen("rlc_grid.py", d, "--n", "8", "--seed", "4")
bt_case("rlc 8 x 8 bt r=10", d, 10)

d = os.path.join(work, "acoustic")
gen("fe_mesh.py", "acoustic", d, "9")
bt_case("acoustic 9 x 9 bt r=10", d, 10, passive=False)

# prbt on the index-one grid: the same model with rows and states in their
# natural order (--no-scramble) must give the same positive-real singular
# values (the energy matrix is E^T Q, not Q E, where the orders differ), and
# a pH, positive-real model
pr = []
for sub, extra in (("rlc", []), ("rlc_u", ["--no-scramble"])):
    d = os.path.join(work, sub)
    if extra:
        gen("rlc_grid.py", d, "--n", "8", "--seed", "4", *extra)
    rc, err = run("reduce", "--J-coo", d + "/J.npy", "--R-coo", d + "/R.npy", "--Q-coo", d + "/Q.npy",
                  "--E-coo", d + "/E.npy", "--B", d + "/B.npy", "--method", "prbt", "--r", "10", "--out", d,
                  "--name", "prbt")
    claim(rc == 0, "rlc %s prbt: reduce (%s)" % (sub, err.strip()))
    if rc == 0:
        pr.append(np.array(json.load(open(os.path.join(d, "prbt.json")))["info"]["positive_real_singular_values"]))
        K, Qh, Bh = (np.load(os.path.join(d, "prbt_%s.npy" % f)) for f in ("K", "Qh", "Bh"))
        ek = np.linalg.eigvalsh(K + K.T)
        claim(ek.max() <= 1e-10 * np.abs(ek).max() and np.linalg.eigvalsh((Qh + Qh.T) / 2).min() > 0,
              "rlc %s prbt: pH (K + K^T <= 0, Qh > 0)" % sub)
if len(pr) == 2:
    e = np.abs(pr[0] - pr[1]).max() / pr[0][0]
    claim(e <= 1e-8, "rlc prbt: scrambled vs natural order %.3g" % e)
    print("rlc 8 x 8 prbt r=10: positive-real singular values scrambled vs natural order %.2g" % e)

d = os.path.join(work, "rlc_pc")
gen("rlc_grid.py", d, "--n", "8", "--seed", "4", "--port-on-constraint")
A, E, B, C = load(d)
Dc = condense(A, E, B, C)[4]
claim(np.abs(Dc).max() > 1e-3, "rlc port on a constraint: the reference feedthrough is not zero")
rc, err = run("reduce", "--J-coo", d + "/J.npy", "--R-coo", d + "/R.npy", "--Q-coo", d + "/Q.npy",
              "--E-coo", d + "/E.npy", "--B", d + "/B.npy", "--method", "bt", "--r", "10", "--out", d)
claim(rc == 1 and "feedthrough" in err, "rlc port on a constraint: bt refused naming the feedthrough (%d: %s)" %
      (rc, err.strip()))

# --form ss: the BT model as state-space arrays A, B, C, D (x_r' = A x_r + B u,
# y = C x_r + D u), for the two models that have no pH form above: the
# acoustic model (not passive) and the grid with a port on a constraint
# (feedthrough D).


def coo_args(d, B=None):
    return ["--J-coo", d + "/J.npy", "--R-coo", d + "/R.npy", "--Q-coo", d + "/Q.npy", "--E-coo", d + "/E.npy",
            "--B", B or d + "/B.npy"]


def ss_case(tag, d, r):
    """reduce --method bt --form ss against the dense reference: the Hankel
    values, the bound, D against the closed form, the sampled H-infinity error
    within the bound; returns (A, B, C, D) or None."""
    A, E, B, C = load(d)
    Ac, Ec, Bc, Cc, Dc = condense(A, E, B, C)
    s_ref = hsv(Ac, Ec, Bc, Cc)
    rc, err = run("reduce", *coo_args(d), "--method", "bt", "--form", "ss", "--r", str(r), "--out", d + "/ss",
                  "--name", "ss")
    if rc != 0:
        claim(False, "%s: reduce --form ss failed: %s" % (tag, err.strip()))
        return None
    rec = json.load(open(os.path.join(d, "ss", "ss.json")))
    info = rec["info"]
    claim(rec["form"] == "ss" and rec["method"] == "bt" and rec["r"] == r, tag + ": the record states the form")
    claim(not os.path.exists(os.path.join(d, "ss", "ss.phgmgrom")), tag + ": no pH model file written")
    s = np.array(info["hankel_singular_values"])
    claim(len(s) == r, "%s: %d Hankel values recorded (r = %d)" % (tag, len(s), r))
    e_s = np.abs(s - s_ref[:len(s)]).max() / s_ref[0]
    claim(e_s <= 1e-8, "%s: HSVs vs SciPy %.3g sigma_1" % (tag, e_s))
    claim(abs(info["hsv_next"] - s_ref[r]) <= 1e-8 * s_ref[0], "%s: sigma_{r+1}" % tag)
    nv = info["values_computed"]
    bound_k = 2 * s_ref[r:nv].sum()   # a sum of nv - r values, each to 1e-8 sigma_1 as the first r above
    claim(abs(info["error_bound"] - bound_k) <= 2 * (nv - r) * 1e-8 * s_ref[0],
          "%s: bound %.6g vs %.6g (the first %d values)" % (tag, info["error_bound"], bound_k, nv))
    claim(min(info["lyapunov_residual"]) > 0 and max(info["lyapunov_residual"]) <= 1e-10 and
          min(info["gramian_rank"]) >= nv, "%s: ranks and residuals recorded %s" % (tag, info))
    Ar, Br, Cr, Dr = (np.load(os.path.join(d, "ss", "ss_%s.npy" % f)) for f in "ABCD")
    m = B.shape[1]
    claim(Ar.shape == (r, r) and Br.shape == (r, m) and Cr.shape == (m, r) and Dr.shape == (m, m),
          tag + ": shapes of A, B, C, D")
    e_d = np.abs(Dr - Dc).max()
    claim(e_d <= 1e-10 * max(1.0, np.abs(Dc).max()), "%s: D vs the closed form -C_c A_ac^-1 B_a: %.3g" % (tag, e_d))
    bound = 2 * s_ref[r:].sum()
    e = e0 = 0.0
    for w in W:
        G = C @ np.linalg.solve(1j * w * E - A, B)
        Gr = Cr @ np.linalg.solve(1j * w * np.eye(r) - Ar, Br)
        e = max(e, np.linalg.norm(G - Gr - Dr, 2))
        e0 = max(e0, np.linalg.norm(G - Gr, 2))
    claim(e <= bound, "%s: sampled H-inf error %.3g within the bound %.3g" % (tag, e, bound))
    if np.abs(Dc).max() > 0:   # the feedthrough is needed: without D the error exceeds the bound
        claim(e0 > bound, "%s: without D the error %.3g exceeds the bound %.3g" % (tag, e0, bound))
    print("%s: N = %d (%d algebraic), --form ss: HSVs vs SciPy %.2g sigma_1, max|D| %.3g, sampled H-inf error "
          "%.3g <= bound %.3g" % (tag, A.shape[0], A.shape[0] - Ac.shape[0], e_s, np.abs(Dr).max(), e, bound))
    return Ar, Br, Cr, Dr


def sim_check(tag, d, abcd, dt, steps, amp=0.5):
    """simulate-rom --ss against the exact response from rest to the CLI's
    input sin (port a: amp sin((1 + a/m) t)): the steady state
    Im((i w - A)^-1 B_a) plus expm(A t) times minus its value at 0."""
    Ar, Br, Cr, Dr = abcd
    r, m = Br.shape
    y_out, x_out = os.path.join(d, "ss_y.npy"), os.path.join(d, "ss_x.npy")
    rc, err = run("simulate-rom", "--ss", d + "/ss/ss", "--out", y_out, "--states", x_out, "--dt", str(dt),
                  "--steps", str(steps), "--amp", str(amp))
    if rc != 0:
        claim(False, "%s: simulate-rom --ss failed: %s" % (tag, err.strip()))
        return
    Y, X = np.load(y_out), np.load(x_out)
    claim(Y.shape == (m, steps + 1) and X.shape == (r, steps + 1), tag + ": simulate-rom --ss output shapes")
    t = dt * np.arange(steps + 1)
    wa = 1.0 + np.arange(m) / m
    xp = lambda tt: sum(amp * np.imag(np.linalg.solve(1j * wa[a] * np.eye(r) - Ar, Br[:, a]) *
                                      np.exp(1j * wa[a] * tt)) for a in range(m))
    Phi = sla.expm(Ar * dt)
    h = -xp(0.0)
    Yx = np.zeros_like(Y)
    for n in range(steps + 1):
        Yx[:, n] = Cr @ (xp(t[n]) + h) + Dr @ (amp * np.sin(wa * t[n]))
        h = Phi @ h
    e = np.abs(Y - Yx).max() / np.abs(Yx).max()
    claim(e <= 1e-6, "%s: simulate-rom --ss vs the exact response %.3g (relative)" % (tag, e))
    print("%s: simulate-rom --ss (Gauss-Legendre, dt = %g) vs the exact response: %.2g of max|y| = %.3g" %
          (tag, dt, e, np.abs(Yx).max()))


d = os.path.join(work, "acoustic")
ss_case("acoustic 9 x 9 bt --form ss r=10", d, 10)
d = os.path.join(work, "rlc_pc")
abcd = ss_case("rlc port on a constraint bt --form ss r=10", d, 10)
if abcd is not None:
    sim_check("rlc port on a constraint", d, abcd, 0.01, 500)

# the refusals: --form ph (the default) names --form ss; --form ss with other
# methods, dense input, a list of orders, validate; no input overwritten; a
# state-space model given to simulate-rom as a model file
rc, err = run("reduce", *coo_args(os.path.join(work, "acoustic")), "--method", "bt", "--r", "10", "--out",
              os.path.join(work, "acoustic"), "--name", "ph")
claim(rc == 1 and "not passive" in err and "--form ss" in err, "acoustic --form ph: refusal names --form ss (%s)" %
      err.strip())
rc, err = run("reduce", *coo_args(d), "--method", "bt", "--r", "10", "--out", d, "--name", "ph")
claim(rc == 1 and "feedthrough" in err and "--form ss" in err, "rlc_pc --form ph: refusal names --form ss (%s)" %
      err.strip())
for extra, want in ((["--method", "prbt"], "--method bt"), (["--method", "bt,prbt"], "--method bt"),
                    (["--method", "bt", "--r", "4,6"], "one order"), (["--method", "sp1", "--simulate"], "--method bt")):
    args = coo_args(d) + extra + (["--r", "10"] if "--r" not in extra else []) + ["--form", "ss", "--out", d + "/x"]
    rc, err = run("reduce", *args)
    claim(rc == 2 and want in err and not os.path.exists(d + "/x"),
          "--form ss with %s refused (%d: %s)" % (" ".join(extra), rc, err.strip()))
rc, err = run("reduce", "--form", "xy", *coo_args(d), "--method", "bt", "--r", "10", "--out", d + "/x")
claim(rc == 2 and "expected ph or ss" in err, "--form xy refused (%s)" % err.strip())
rc, err = run("validate", *coo_args(d), "--method", "bt", "--r", "10", "--form", "ss", "--out", d + "/x",
              "--test-input", "sin")
claim(rc == 2 and "--form ss" in err and "simulate-rom --ss" in err, "validate --form ss refused (%s)" % err.strip())
np.save(d + "/Jd.npy", dense(d + "/J.npy", 288))
rc, err = run("reduce", "--J", d + "/Jd.npy", "--R", d + "/Jd.npy", "--Q", d + "/Jd.npy", "--B", d + "/B.npy",
              "--method", "bt", "--r", "10", "--form", "ss", "--out", d + "/x")
claim(rc == 2 and "--J-coo" in err, "--form ss with dense input refused (%s)" % err.strip())
b_in = os.path.join(d, "ss", "in_B.npy")   # the input B where the model's B would go
np.save(b_in, np.load(d + "/B.npy"))
before = open(b_in, "rb").read()
rc, err = run("reduce", *coo_args(d, b_in), "--method", "bt", "--form", "ss", "--r", "10", "--out", d + "/ss",
              "--name", "in")
claim(rc == 2 and open(b_in, "rb").read() == before, "--form ss never overwrites an input (%d: %s)" %
      (rc, err.strip()))
rc, err = run("simulate-rom", "--model", d + "/ss/ss.phgmgrom", "--out", d + "/y.npy")
claim(rc == 1 and "--ss " + d + "/ss/ss" in err, "simulate-rom --model of a state-space model names --ss (%s)" %
      err.strip())
rc, err = run("simulate-rom", "--model", d + "/ss/ss.phgmgrom", "--ss", d + "/ss/ss", "--out", d + "/y.npy")
claim(rc == 2, "simulate-rom --model with --ss refused (%s)" % err.strip())
rc, err = run("simulate-rom", "--ss", d + "/ss/ss", "--out", d + "/ss/ss_A.npy")
claim(rc == 2 and "never overwrites" in err, "simulate-rom --ss: --out onto the model's A refused (%s)" % err.strip())
os.makedirs(d + "/bad", exist_ok=True)
for f, g in (("A", "A"), ("B", "C"), ("C", "C"), ("D", "D")):   # B of C's shape (m x r)
    np.save(d + "/bad/m_%s.npy" % f, np.load(d + "/ss/ss_%s.npy" % g))
rc, err = run("simulate-rom", "--ss", d + "/bad/m", "--out", d + "/bad/y.npy")
claim(rc == 1 and "B must be r x m" in err and not os.path.exists(d + "/bad/y.npy"),
      "simulate-rom --ss: a B of the wrong shape refused (%s)" % err.strip())

# one name, two forms: each run removes the other form's files of that name
d = os.path.join(work, "rlc")
rc1, _ = run("reduce", *coo_args(d), "--method", "bt", "--r", "10", "--out", d + "/two", "--name", "m")
rc2, _ = run("reduce", *coo_args(d), "--method", "bt", "--form", "ss", "--r", "10", "--out", d + "/two", "--name", "m")
left = sorted(os.listdir(d + "/two"))
claim(rc1 == 0 and rc2 == 0 and left == ["m.json", "m_A.npy", "m_B.npy", "m_C.npy", "m_D.npy", "m_V0.npy"],
      "ph then ss under one name: the pH files removed (%s)" % left)
rc3, _ = run("reduce", *coo_args(d), "--method", "bt", "--r", "10", "--out", d + "/two", "--name", "m")
left = sorted(os.listdir(d + "/two"))
claim(rc3 == 0 and "m_A.npy" not in left and "m.phgmgrom" in left, "ss then ph: the state-space arrays removed (%s)" %
      left)
# a pH run does not write NAME_B.npy: an input of that name is no collision there
os.makedirs(d + "/phB", exist_ok=True)
np.save(d + "/phB/q_B.npy", np.load(d + "/B.npy"))
rc, err = run("reduce", *coo_args(d, d + "/phB/q_B.npy"), "--method", "bt", "--r", "10", "--out", d + "/phB",
              "--name", "q")
claim(rc == 0 and os.path.exists(d + "/phB/q_B.npy"), "pH run with an input named NAME_B.npy (%s)" % err.strip())

if fails:
    print("check_lowrank_dae: %d claims failed" % len(fails))
    sys.exit(1)
print("check_lowrank_dae: all claims hold")
