"""The GL3 steps of `phgmg simulate` in SciPy (SuperLU), for comparison.

    python3 gl3_scipy.py DIR OUT.npy [--dt 0.1] [--steps 1000] [--amp 0.1]

DIR holds J.npy, R.npy, Q.npy (coordinate triplets) and B.npy (bench/lattice.py).
A linear model x' = (J - R) Q x + B u, u(t) = AMP sin(t) on every port, from
x0 = 0, y = B^T Q x. The same scheme as phgmg's stepper (phgmg.h >>gl3): the
3-stage Gauss-Legendre stages Z_i = Y_i - x_n, simplified Newton on the stage
system transformed by the eigenvectors of A^{-1} (one real and one complex
sparse LU, scipy.sparse.linalg.splu, factored once: the model is linear), at
least one update per step, stop when max |Z - h (A x I) F(Z)| <= 1e-10 max(1,
|x|_inf, |Z|_inf), the starting guess extrapolated from the previous step's
collocation polynomial. Writes y (m x (steps+1)) and prints the seconds of
the stepping (set-up and factorization included, file reading excluded)."""
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


def main(argv):
    d, out = argv[0], argv[1]
    opt = {"--dt": 0.1, "--steps": 1000, "--amp": 0.1}
    for k in opt:
        if k in argv:
            opt[k] = float(argv[argv.index(k) + 1])
    h, nsteps, amp = opt["--dt"], int(opt["--steps"]), opt["--amp"]
    B = np.load(d + "/B.npy")
    if B.ndim == 1:
        B = B[:, None]
    N, m = B.shape
    J, R, Q = coo(d + "/J.npy", N), coo(d + "/R.npy", N), coo(d + "/Q.npy", N)
    t0 = time.perf_counter()
    c, b, A = gl3_tableau()
    lam, V = np.linalg.eig(np.linalg.inv(A))
    ir = int(np.argmin(np.abs(lam.imag)))
    ic = [k for k in range(3) if k != ir and lam[k].imag > 0][0]
    gam, alp, bet = lam[ir].real, lam[ic].real, lam[ic].imag
    T = np.column_stack([V[:, ir].real, V[:, ic].real, V[:, ic].imag])
    Ti = np.linalg.inv(T)
    # extrapolation of the collocation polynomial p (p(0) = 0, p(c_j) = Zprev_j)
    E = np.zeros((3, 3))
    for i in range(3):
        for j in range(3):
            s1, l1, l0 = 1 + c[i], (1 + c[i]) / c[j], 1 / c[j]
            for k in range(3):
                if k != j:
                    l1 *= (s1 - c[k]) / (c[j] - c[k])
                    l0 *= (1 - c[k]) / (c[j] - c[k])
            E[i, j] = l1 - l0
    JR = (J - R).tocsr()
    JRQ = (JR @ Q).tocsc()
    I = sps.identity(N, format="csc")
    lu1 = spl.splu((gam / h * I - JRQ).tocsc())
    lu2 = spl.splu(((alp - 1j * bet) / h * I - JRQ).astype(complex).tocsc())
    Qr = Q.tocsr()
    x = np.zeros(N)
    Y = np.zeros((m, nsteps + 1))
    Y[:, 0] = B.T @ (Qr @ x)
    Zp = None
    for n in range(nsteps):
        t = n * h
        U = amp * np.sin(t + c * h)                      # u at the stage times
        BU = B.sum(axis=1)[:, None] * U[None, :]         # N x 3 (every port the same input)
        Z = np.zeros((N, 3)) if Zp is None else Zp @ E.T
        W = Z @ Ti.T
        xm = max(1.0, np.abs(x).max())
        it = 0
        while True:
            G = Qr @ (x[:, None] + Z)
            F = JR @ G + BU
            res = np.abs(Z - h * F @ A.T).max()
            if it >= 1 and res <= 1e-10 * max(xm, np.abs(Z).max()):
                break
            if it >= 10:
                raise SystemExit("Newton did not converge at step %d" % n)
            TF = F @ Ti.T
            r1 = TF[:, 0] - gam / h * W[:, 0]
            rc = (TF[:, 1] - (alp * W[:, 1] + bet * W[:, 2]) / h) + 1j * (TF[:, 2] + (bet * W[:, 1] - alp * W[:, 2]) / h)
            W[:, 0] += lu1.solve(r1)
            dc = lu2.solve(rc)
            W[:, 1] += dc.real
            W[:, 2] += dc.imag
            Z = W @ T.T
            it += 1
        dinv = np.linalg.solve(A.T, b)                   # x+ = x + sum_j d_j Z_j
        x = x + Z @ dinv
        Zp = Z
        Y[:, n + 1] = B.T @ (Qr @ x)
    el = time.perf_counter() - t0
    np.save(out, Y)
    print("%.6f" % el)


if __name__ == "__main__":
    main(sys.argv[1:])
