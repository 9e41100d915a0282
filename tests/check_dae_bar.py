"""The descriptor finite-element bar through the command line, against an
independent computation (SciPy): a bar of n linear elements with consistent
mass (N = 2n states, E = diag(I, M), Q = diag(K, I), Rayleigh damping), two
force ports (tip, middle) with feedthrough S, the states in a scrambled
order, given as sparse COO files.

  1. `phgmg simulate` against Gauss-Legendre 3 done here: the 3N stage system
     (I x E - h A x (J - R) Q) Z = ... solved by SuperLU, y = B^T Q x + S u;
  2. the same bar with the mass of one node removed (a zero row and column
     of E: index one) against the collocation of the DAE done the same way,
     the algebraic variable then taken from the constraint at each step;
  3. GMG-POD and SP1 from `phgmg reduce --simulate` at r = 8, 14, 20, run by
     `phgmg simulate-rom`: e_y against the full model's output, and a plain
     POD-Galerkin projection (V^T E V, V^T (J - R) Q V, ...) for scale.

Usage: /usr/bin/python3 tests/check_dae_bar.py PHGMG_BINARY [n] [workdir]
Exits 1 when a claim fails: (1) to 1e-8, (2) to 1e-5 relative; (3) e_y <= 1e-2
at r = 20 and falling from r = 8 to 14 to 20, for both bars and both methods."""
import os, subprocess, sys, time
import numpy as np
try:
    import scipy.sparse as sp, scipy.sparse.linalg as sla
except ImportError:   # a small dense stand-in (enough for n <= 200)
    sp = sla = None

exe = sys.argv[1] if len(sys.argv) > 1 else "build/phgmg"
n = int(sys.argv[2]) if len(sys.argv) > 2 else 400
if sp is None and n > 200:
    raise SystemExit("check_dae_bar: n = %d needs SciPy (python3-scipy)" % n)
work = sys.argv[3] if len(sys.argv) > 3 else "/tmp/phgmg_dae_bar"
dt, steps, amp = 0.05, 1000, 0.1
N, h = 2 * n, 1.0 / n
os.makedirs(work, exist_ok=True)

class Dense:
    """The few scipy.sparse calls used here, on dense arrays."""
    @staticmethod
    def diags(ds, offs):
        m = len(ds[list(offs).index(0)])
        A = np.zeros((m, m))
        for d, o in zip(ds, offs):
            A += np.diag(d, o)
        return A
    @staticmethod
    def identity(m):
        return np.eye(m)
    @staticmethod
    def bmat(blocks):
        rows = []
        for row in blocks:
            sz = [b.shape for b in row if b is not None][0][0]
            rows.append([b if b is not None else np.zeros((sz, sz)) for b in row])
        return np.block(rows)
    @staticmethod
    def kron(a, b):
        return np.kron(np.asarray(a), np.asarray(b))
    @staticmethod
    def csr_matrix(a):
        return np.zeros(a) if isinstance(a, tuple) else np.asarray(a)

def dense(A):
    return A.toarray() if hasattr(A, "toarray") else np.asarray(A)

def bar(massless):
    if sp is None:
        return bar_dense(massless)
    K = sp.diags([-np.ones(n - 1), np.r_[2 * np.ones(n - 1), 1.0], -np.ones(n - 1)], [-1, 0, 1]) / h
    M = (sp.diags([np.ones(n - 1), np.r_[4 * np.ones(n - 1), 2.0], np.ones(n - 1)], [-1, 0, 1]) * h / 6).tolil()
    if massless is not None:
        M[massless, :] = 0.0
        M[:, massless] = 0.0
    M = M.tocsr()
    D = 0.05 * M + 2e-3 * K
    I, Z = sp.identity(n), sp.csr_matrix((n, n))
    E = sp.bmat([[I, None], [None, M]]).tocsr()
    Q = sp.bmat([[K, None], [None, I]]).tocsr()
    J = sp.bmat([[Z, I], [-I, Z]]).tocsr()
    R = sp.bmat([[Z, None], [None, D]]).tocsr()
    B = np.zeros((N, 2)); B[2 * n - 1, 0] = 1.0; B[n + n // 2 - 1, 1] = 1.0
    p = np.random.default_rng(7).permutation(N)       # scrambled: new i = old p[i]
    P = sp.identity(N).tocsr()[p, :]
    E, J, R, Q = [(P @ A @ P.T).tocsr() for A in (E, J, R, Q)]
    E.eliminate_zeros()
    return E, J, R, Q, B[p, :]

def bar_dense(massless):
    K = Dense.diags([-np.ones(n - 1), np.r_[2 * np.ones(n - 1), 1.0], -np.ones(n - 1)], [-1, 0, 1]) / h
    M = Dense.diags([np.ones(n - 1), np.r_[4 * np.ones(n - 1), 2.0], np.ones(n - 1)], [-1, 0, 1]) * h / 6
    if massless is not None:
        M[massless, :] = 0.0
        M[:, massless] = 0.0
    D = 0.05 * M + 2e-3 * K
    I, Z = np.eye(n), np.zeros((n, n))
    E = np.block([[I, Z], [Z, M]]); Q = np.block([[K, Z], [Z, I]])
    J = np.block([[Z, I], [-I, Z]]); R = np.block([[Z, Z], [Z, D]])
    B = np.zeros((N, 2)); B[2 * n - 1, 0] = 1.0; B[n + n // 2 - 1, 1] = 1.0
    p = np.random.default_rng(7).permutation(N)
    return E[np.ix_(p, p)], J[np.ix_(p, p)], R[np.ix_(p, p)], Q[np.ix_(p, p)], B[p, :]

S = np.array([[0.2, 0.05], [0.05, 0.1]])
def u_of(t):
    return amp * np.array([np.sin(t), np.sin(1.5 * t)])

def reference(E, J, R, Q, B):
    """GL3 collocation of E x' = (J - R) Q x + B u; algebraic variables (zero
    columns of E) from the algebraic rows (zero rows of E) at each step."""
    s15 = np.sqrt(15.0)
    A3 = np.array([[5/36, 2/9 - s15/15, 5/36 - s15/30], [5/36 + s15/24, 2/9, 5/36 - s15/24],
                   [5/36 + s15/30, 2/9 + s15/15, 5/36]])
    c = np.array([0.5 - s15/10, 0.5, 0.5 + s15/10]); b = np.array([5/18, 4/9, 5/18])
    d = b @ np.linalg.inv(A3)
    if sp is not None:
        Mm = ((J - R) @ Q).tocsr()
        lu = sla.splu((sp.kron(sp.identity(3), E) - dt * sp.kron(sp.csr_matrix(A3), Mm)).tocsc())
        solve = lu.solve
    else:
        Mm = (J - R) @ Q
        Ki = np.linalg.inv(np.kron(np.eye(3), E) - dt * np.kron(A3, Mm))
        solve = lambda v: Ki @ v
    Ed, Md = dense(E), dense(Mm)
    zr = np.flatnonzero(np.abs(Ed).sum(axis=1) == 0); zc = np.flatnonzero(np.abs(Ed).sum(axis=0) == 0)
    dc = np.setdiff1d(np.arange(N), zc)
    Maa = Md[np.ix_(zr, zc)] if len(zr) else None
    x = np.zeros(N); Y = np.zeros((2, steps + 1)); Y[:, 0] = B.T @ (Q @ x) + S @ u_of(0.0)
    for k in range(steps):
        t = k * dt
        F = np.stack([Mm @ x + B @ u_of(t + ci * dt) for ci in c])
        Zs = solve(dt * (A3 @ F).reshape(-1)).reshape(3, N)
        x = x + d @ Zs
        if len(zr):
            rhs = -(Md[np.ix_(zr, dc)] @ x[dc] + B[zr] @ u_of(t + dt))
            x[zc] = np.linalg.solve(Maa, rhs)
        Y[:, k + 1] = B.T @ (Q @ x) + S @ u_of(t + dt)
    return Y

def write_model(tag, E, J, R, Q, B):
    files = {}
    for name, A in zip("EJRQ", (E, J, R, Q)):
        A = dense(A)
        row, col = np.nonzero(A)
        files[name] = os.path.join(work, "%s_%s_coo.npy" % (tag, name))
        np.save(files[name], np.column_stack([row, col, A[row, col]]).astype(float))
    files["B"] = os.path.join(work, tag + "_B.npy"); np.save(files["B"], B)
    files["S"] = os.path.join(work, tag + "_S.npy"); np.save(files["S"], S)
    return ["--J-coo", files["J"], "--R-coo", files["R"], "--Q-coo", files["Q"], "--E-coo", files["E"],
            "--B", files["B"], "--S", files["S"]]

def run(args):
    r = subprocess.run([exe] + args, capture_output=True, text=True)
    if r.returncode != 0:
        print(r.stdout + r.stderr)
        raise SystemExit("check_dae_bar: FAIL %s exited %d" % (" ".join([exe] + args[:1]), r.returncode))
    return r

def rel(a, b):
    return np.linalg.norm(a - b) / np.linalg.norm(b)

bad = []
common = ["--dt", str(dt), "--steps", str(steps), "--amp", str(amp), "--quiet"]
for tag, massless, tol in (("bar", None, 1e-8), ("bar_massless", n // 4, 1e-5)):
    E, J, R, Q, B = bar(massless)
    model = write_model(tag, E, J, R, Q, B)
    t0 = time.time(); Yref = reference(E, J, R, Q, B); t_ref = time.time() - t0
    yf = os.path.join(work, tag + "_y.npy")
    t0 = time.time(); run(["simulate"] + model + common + ["--out", yf]); t_ph = time.time() - t0
    Y = np.load(yf)
    e = rel(Y, Yref)
    print("%-13s N = %d: phgmg simulate vs independent GL3 %.2e (limit %.0e); %.2f s vs the reference %.2f s"
          % (tag, N, e, tol, t_ph, t_ref))
    if not e <= tol:
        bad.append("%s: simulate differs from the reference by %.3g > %g" % (tag, e, tol))
    for meth in ("gmg-pod", "sp1"):
        errs = []
        for r in (8, 14, 20):
            out = os.path.join(work, "%s_%s_%d" % (tag, meth, r))
            run(["reduce"] + model + common + ["--simulate", "--method", meth, "--r", str(r), "--out", out,
                 "--name", "rom"])
            yr = os.path.join(out, "y_rom.npy")
            run(["simulate-rom", "--model", os.path.join(out, "rom.phgmgrom"), "--out", yr] + common)
            errs.append(rel(np.load(yr), Y))
        print("%-13s %-7s e_y at r = 8, 14, 20: %s" % (tag, meth, "  ".join("%.2e" % x for x in errs)))
        if not (errs[2] <= 1e-2 and errs[0] > errs[1] > errs[2]):
            bad.append("%s %s: e_y %s (want <= 1e-2 at r = 20, falling)" % (tag, meth, errs))
for b in bad:
    print("check_dae_bar: FAIL " + b)
if bad:
    sys.exit(1)
print("check_dae_bar: the descriptor bar and its index-one variant: claims hold")
