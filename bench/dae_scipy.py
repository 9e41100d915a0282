"""The GL3 steps of `phgmg simulate` on an index-one descriptor model, in SciPy (SuperLU).

    /usr/bin/python3 dae_scipy.py DIR OUT.npy [--dt 0.02] [--steps 1000] [--input chirp.npy]

DIR holds J.npy, R.npy, Q.npy, E.npy (coordinate triplets) and B.npy
(bench/rlc_grid.py). E x' = (J - R) Q x + B u with E having k zero rows (the
algebraic equations a) and k zero columns (the algebraic variables c);
y = B^T Q x. The input: the table DIR/chirp.npy (times, one column per port),
linearly interpolated, as `phgmg simulate --input chirp.npy` does. The scheme
of phgmg's stepper (phgmg.h, manual 1.8): the 3-stage Gauss-Legendre stages
Z_i, simplified Newton on the stage system (I x E) Z = h (A x I) F transformed
by the eigenvectors of A^{-1} (one real and one complex sparse LU of
sigma E - (J - R) Q, splu, factored once), at least one update per step,
stop when max |E Z - h (A x I) F| <= 1e-10 max(1, |x|_inf, |Z|_inf), the
starting guess extrapolated from the previous step's collocation
polynomial; x+ = x + sum_i d_i Z_i (d = A^{-T} b), then the algebraic
variables from the constraints at t_{n+1}: z_a = -L_aa^{-1} (L_ad z_d +
B_a u), x_c = Q_ac^{-1} (z_a - Q_ad x_d) (splu of L_aa and Q_ac); x0 = 0 made
consistent the same way. Writes y (m x (steps+1)) and prints the seconds of
the stepping (set-up and factorizations included, file reading excluded)."""
import sys
import time

import numpy as np
import scipy.sparse as sps
import scipy.sparse.linalg as spl

from gl3_scipy import coo, gl3_tableau


def main(argv):
    d, out = argv[0], argv[1]
    opt = {"--dt": 0.02, "--steps": 1000}
    for k in opt:
        if k in argv:
            opt[k] = float(argv[argv.index(k) + 1])
    h, nsteps = opt["--dt"], int(opt["--steps"])
    tab = np.load(argv[argv.index("--input") + 1] if "--input" in argv else d + "/chirp.npy")
    B = np.load(d + "/B.npy")
    N, m = B.shape
    J, R, Q, E = (coo("%s/%s.npy" % (d, n), N) for n in "JRQE")
    uf = lambda t: np.array([np.interp(t, tab[:, 0], tab[:, 1 + a]) for a in range(m)])
    t0 = time.perf_counter()
    c, b, A = gl3_tableau()
    lam, V = np.linalg.eig(np.linalg.inv(A))
    ir = int(np.argmin(np.abs(lam.imag)))
    ic = [k for k in range(3) if k != ir and lam[k].imag > 0][0]
    gam, alp, bet = lam[ir].real, lam[ic].real, lam[ic].imag
    T = np.column_stack([V[:, ir].real, V[:, ic].real, V[:, ic].imag])
    Ti = np.linalg.inv(T)
    Ex = np.zeros((3, 3))
    for i in range(3):
        for j in range(3):
            s1, l1, l0 = 1 + c[i], (1 + c[i]) / c[j], 1 / c[j]
            for k in range(3):
                if k != j:
                    l1 *= (s1 - c[k]) / (c[j] - c[k])
                    l0 *= (1 - c[k]) / (c[j] - c[k])
            Ex[i, j] = l1 - l0
    JR = (J - R).tocsr()
    JRQ = (JR @ Q).tocsc()
    lu1 = spl.splu((gam / h * E - JRQ).tocsc())
    lu2 = spl.splu(((alp - 1j * bet) / h * E - JRQ).astype(complex).tocsc())
    Er, Qr = E.tocsr(), Q.tocsr()
    a = np.flatnonzero(np.abs(E).sum(axis=1).A1 == 0)       # algebraic rows
    cc = np.flatnonzero(np.abs(E).sum(axis=0).A1 == 0)      # algebraic columns
    nota = np.setdiff1d(np.arange(N), a)
    notc = np.setdiff1d(np.arange(N), cc)
    Lad, Laa = JR[a][:, nota], JR[a][:, a].tocsc()
    Qad, Qac = Qr[a][:, notc], Qr[a][:, cc].tocsc()
    luL, luQ = spl.splu(Laa), spl.splu(Qac)
    Ba = B[a]

    def consistent(x, u):
        za = luL.solve(-(Lad @ (Qr[nota] @ x) + Ba @ u))
        x[cc] = luQ.solve(za - Qad @ x[notc])
        return x

    dinv = np.linalg.solve(A.T, b)
    x = consistent(np.zeros(N), uf(0.0))
    Y = np.zeros((m, nsteps + 1))
    Y[:, 0] = B.T @ (Qr @ x)
    Zp = None
    for n in range(nsteps):
        t = n * h
        BU = B @ np.column_stack([uf(t + ci * h) for ci in c])   # N x 3
        Z = np.zeros((N, 3)) if Zp is None else Zp @ Ex.T
        W = Z @ Ti.T
        xm = max(1.0, np.abs(x).max())
        it = 0
        while True:
            F = JR @ (Qr @ (x[:, None] + Z)) + BU
            res = np.abs(Er @ Z - h * F @ A.T).max()
            if it >= 1 and res <= 1e-10 * max(xm, np.abs(Z).max()):
                break
            if it >= 10:
                raise SystemExit("Newton did not converge at step %d" % n)
            TF, EW = F @ Ti.T, Er @ W
            r1 = TF[:, 0] - gam / h * EW[:, 0]
            rc = (TF[:, 1] - (alp * EW[:, 1] + bet * EW[:, 2]) / h) + 1j * (TF[:, 2] + (bet * EW[:, 1] - alp * EW[:, 2]) / h)
            W[:, 0] += lu1.solve(r1)
            dc = lu2.solve(rc)
            W[:, 1] += dc.real
            W[:, 2] += dc.imag
            Z = W @ T.T
            it += 1
        x = consistent(x + Z @ dinv, uf(t + h))
        Zp = Z
        Y[:, n + 1] = B.T @ (Qr @ x)
    el = time.perf_counter() - t0
    np.save(out, Y)
    print("%.6f" % el)


if __name__ == "__main__":
    main(sys.argv[1:])
