"""The GL3 steps of `phgmg simulate` for a descriptor model in SciPy (SuperLU).

    python3 fe_gl3_ref.py DIR INPUT.npy OUT.npy [--dt 0.02] [--steps 1000]

DIR holds E.npy, J.npy, R.npy, Q.npy (coordinate triplets) and B.npy (N x m),
as bench/fe_mesh.py writes them; INPUT.npy a table (K, 1 + m) of times and
inputs, interpolated linearly (held outside), as `phgmg simulate --input
INPUT.npy` reads it. The model E x' = (J - R) Q x + B u, y = B^T Q x from
x0 = 0, by the scheme of phgmg's stepper (bench/gl3_scipy.py, with E): the
3-stage Gauss-Legendre stages Z_i, E Z_i = h sum_j a_ij F(x + Z_j), simplified
Newton transformed by the eigenvectors of A^{-1} (one real and one complex
sparse LU of gamma/h E - (J - R) Q and (alpha - i beta)/h E - (J - R) Q,
scipy.sparse.linalg.splu, factored once), at least one update per step, stop
when max |E Z - h (A x I) F(Z)| <= 1e-10 max(1, |x|_inf, |Z|_inf), the
starting guess extrapolated from the previous step's collocation polynomial.
Writes y (m x (steps+1)); prints the seconds of set-up and stepping."""
import sys
import time

import numpy as np
import scipy.sparse as sps
import scipy.sparse.linalg as spl


def coo(path, N):
    t = np.load(path)
    return sps.csc_matrix((t[:, 2], (t[:, 0].astype(np.int64), t[:, 1].astype(np.int64))), shape=(N, N))


def gl3_tableau():
    s = np.sqrt(15.0)
    c = np.array([0.5 - s / 10, 0.5, 0.5 + s / 10])
    b = np.array([5 / 18, 4 / 9, 5 / 18])
    A = np.array([[5 / 36, 2 / 9 - s / 15, 5 / 36 - s / 30],
                  [5 / 36 + s / 24, 2 / 9, 5 / 36 - s / 24],
                  [5 / 36 + s / 30, 2 / 9 + s / 15, 5 / 36]])
    return c, b, A


def transform(A):
    lam, V = np.linalg.eig(np.linalg.inv(A))
    ir = int(np.argmin(np.abs(lam.imag)))
    ic = [k for k in range(3) if k != ir and lam[k].imag > 0][0]
    T = np.column_stack([V[:, ir].real, V[:, ic].real, V[:, ic].imag])
    return lam[ir].real, lam[ic].real, lam[ic].imag, T, np.linalg.inv(T)


def extrapolation(c):
    """Z_next = Zprev @ X.T: the collocation polynomial p (p(0) = 0, p(c_j) = Zprev_j) at 1 + c_i, minus p(1)."""
    X = np.zeros((3, 3))
    for i in range(3):
        for j in range(3):
            s1, l1, l0 = 1 + c[i], (1 + c[i]) / c[j], 1 / c[j]
            for k in range(3):
                if k != j:
                    l1 *= (s1 - c[k]) / (c[j] - c[k])
                    l0 *= (1 - c[k]) / (c[j] - c[k])
            X[i, j] = l1 - l0
    return X


def main(argv):
    d, inp, out = argv[0], argv[1], argv[2]
    opt = {"--dt": 0.02, "--steps": 1000}
    for k in opt:
        if k in argv:
            opt[k] = float(argv[argv.index(k) + 1])
    h, nsteps = opt["--dt"], int(opt["--steps"])
    B = np.load(d + "/B.npy")
    if B.ndim == 1:
        B = B[:, None]
    N, m = B.shape
    E, J, R, Q = (coo(d + "/%s.npy" % k, N) for k in "EJRQ")
    tab = np.load(inp)
    t0 = time.perf_counter()
    c, b, A = gl3_tableau()
    gam, alp, bet, T, Ti = transform(A)
    X = extrapolation(c)
    JR = (J - R).tocsr()
    JRQ = (JR @ Q).tocsc()
    Er = E.tocsr()
    lu1 = spl.splu((gam / h * E - JRQ).tocsc())
    lu2 = spl.splu(((alp - 1j * bet) / h * E - JRQ).astype(complex).tocsc())
    Qr = Q.tocsr()
    x = np.zeros(N)
    Y = np.zeros((m, nsteps + 1))
    Y[:, 0] = B.T @ (Qr @ x)
    dinv = np.linalg.solve(A.T, b)                   # x+ = x + sum_j d_j Z_j
    Zp = None
    for n in range(nsteps):
        ts = n * h + c * h
        U = np.array([np.interp(ts, tab[:, 0], tab[:, 1 + a]) for a in range(m)])   # m x 3
        BU = B @ U                                       # N x 3
        Z = np.zeros((N, 3)) if Zp is None else Zp @ X.T
        W = Z @ Ti.T
        xm = max(1.0, np.abs(x).max())
        it = 0
        while True:
            F = JR @ (Qr @ (x[:, None] + Z)) + BU
            EW = Er @ W
            res = np.abs(Er @ Z - h * F @ A.T).max()
            if it >= 1 and res <= 1e-10 * max(xm, np.abs(Z).max()):
                break
            if it >= 10:
                raise SystemExit("Newton did not converge at step %d" % n)
            TF = F @ Ti.T
            r1 = TF[:, 0] - gam / h * EW[:, 0]
            rc = (TF[:, 1] - (alp * EW[:, 1] + bet * EW[:, 2]) / h) + 1j * (TF[:, 2] + (bet * EW[:, 1] - alp * EW[:, 2]) / h)
            W[:, 0] += lu1.solve(r1)
            dc = lu2.solve(rc)
            W[:, 1] += dc.real
            W[:, 2] += dc.imag
            Z = W @ T.T
            it += 1
        x = x + Z @ dinv
        Zp = Z
        Y[:, n + 1] = B.T @ (Qr @ x)
    el = time.perf_counter() - t0
    np.save(out, Y)
    print("%.6f" % el)


if __name__ == "__main__":
    main(sys.argv[1:])
