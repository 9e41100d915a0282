"""pH-preserving balancing (phbt) of a small lattice, computed densely from its
definition in NumPy/SciPy, next to BT and to the same balancing with other
Hamiltonians of the model (each a solution X of the KYP inequality
A^T X + X A <= 0, X B = C^T):

  Q      the model's own energy matrix (what `phgmg reduce --method phbt` does)
  Xmin   the minimal solution of the KYP inequality (the available storage;
         zero feedthrough: the limit eps -> 0 of the positive-real Riccati
         equation with D + D^T = eps I)

For each: sigma_i = sqrt(eig(P X)) (P the controllability Gramian), the
balancing projection (T = the leading eigenvectors of P X scaled so that
T^T X T = Sigma, test space X T), the sampled H-infinity error on 200
frequencies in [1e-2, 1e2] and the time-domain output error max|y - yr| /
max|y| over 500 steps of dt 0.1, u_a = 0.1 sin((1 + a/2) t) (exact
propagation: the input is the output of a linear oscillator appended to the
state). With --rom DIR/NAME also the library's reduced model (NAME_K.npy,
NAME_Qh.npy, NAME_Bh.npy of `phgmg reduce --out DIR --name NAME`).

    /usr/bin/python3 bench/phbt_ref.py MODELDIR R [--rom DIR/NAME ...]

MODELDIR from bench/lowrank_models.py ... lattice n --dense."""
import sys
import numpy as np
import scipy.linalg as sla

W = np.logspace(-2, 2, 200)


def load(d):
    J, R, Q = (np.load("%s/%sd.npy" % (d, x)) for x in "JRQ")
    B = np.load(d + "/B.npy")
    return J, R, Q, B


def hinf_err(A, B, C, Ar, Br, Cr):
    n, k = A.shape[0], Ar.shape[0]
    e = g = 0.0
    for w in W:
        G = C @ np.linalg.solve(1j * w * np.eye(n) - A, B)
        Gr = Cr @ np.linalg.solve(1j * w * np.eye(k) - Ar, Br)
        e = max(e, np.linalg.norm(G - Gr, 2))
        g = max(g, np.linalg.norm(G, 2))
    return e, g


def outputs(A, B, C, steps=500, dt=0.1):
    """y at t = dt .. steps dt from rest, u_a = 0.1 sin((1 + a/2) t), exact."""
    n, m = B.shape
    # oscillator a: s' = w c, c' = -w s, s(0) = 0, c(0) = 1: s = sin(w t)
    M = np.zeros((n + 2 * m, n + 2 * m))
    M[:n, :n] = A
    z = np.zeros(n + 2 * m)
    for a in range(m):
        w = 1.0 + a / 2.0
        i = n + 2 * a
        M[i, i + 1], M[i + 1, i] = w, -w
        M[:n, i] = 0.1 * B[:, a]
        z[i + 1] = 1.0
    F = sla.expm(dt * M)
    Y = np.zeros((steps, m))
    for k in range(steps):
        z = F @ z
        Y[k] = C @ z[:n]
    return Y


def kyp_min(A, B, C, eps):
    """Minimal solution of A^T X + X A + (X B - C^T)(eps I)^{-1}(B^T X - C) = 0."""
    m = B.shape[1]
    return sla.solve_continuous_are(A, B, np.zeros_like(A), -eps * np.eye(m), s=-C.T)


def balance(A, B, C, P, X, r):
    """Balancing of P against X (X a KYP solution), projection onto the r
    leading directions, test space X T."""
    # P X T = T S^2 with T^T X T = S: from the symmetric problem L^T X L
    U, s, _ = np.linalg.svd(P)
    L = U * np.sqrt(np.maximum(s, 0.0))
    w, Y = np.linalg.eigh(L.T @ X @ L)
    idx = np.argsort(w)[::-1]
    w, Y = np.maximum(w[idx], 0.0), Y[:, idx]
    sig = np.sqrt(w)
    T = L @ Y[:, :r] / np.sqrt(sig[:r])
    Wt = (X @ T) / sig[:r]          # Wt^T T = I
    return sig, Wt.T @ A @ T, Wt.T @ B, C @ T


def main(argv):
    d, r = argv[0], int(argv[1])
    roms = [argv[i + 1] for i, a in enumerate(argv) if a == "--rom"]
    J, R, Q, B = load(d)
    A, C = (J - R) @ Q, B.T @ Q
    P = sla.solve_continuous_lyapunov(A, -B @ B.T)
    O = sla.solve_continuous_lyapunov(A.T, -C.T @ C)
    print("N = %d, r = %d" % (A.shape[0], r))
    Y = outputs(A, B, C)
    ymax = np.abs(Y).max()
    res = {}
    # BT
    sig, Ar, Br, Cr = balance(A, B, C, P, O, r)
    e, g = hinf_err(A, B, C, Ar, Br, Cr)
    et = np.abs(Y - outputs(Ar, Br, Cr)).max() / ymax
    print("%-8s sigma_1..3 %s  2 sum tail %.3e  Hinf %.3e (rel %.3e)  output %.3e" %
          ("bt", np.array2string(sig[:3], precision=4), 2 * sig[r:].sum(), e, e / g, et))
    Ws = Q @ (2 * R - B @ B.T) @ Q
    print("Q a generalised observability Gramian (A^T Q + Q A + C^T C <= 0): min eig Q(2R - BB^T)Q = %.3e"
          % np.linalg.eigvalsh(Ws).min())
    for eps in (1e-4, 1e-6, 1e-8):
        Xm = kyp_min(A, B, C, eps)
        res[eps] = Xm
    Xm = res[1e-8]
    print("Xmin: ||X(1e-6) - X(1e-8)|| / ||X|| = %.2e; min eig(Q - Xmin) = %.3e; "
          "||Xmin B - C^T|| / ||C|| = %.2e; max eig(A^T X + X A) = %.2e" %
          (np.linalg.norm(res[1e-6] - Xm) / np.linalg.norm(Xm), np.linalg.eigvalsh(Q - Xm).min(),
           np.linalg.norm(Xm @ B - C.T) / np.linalg.norm(C),
           np.linalg.eigvalsh(A.T @ Xm + Xm @ A).max() / np.abs(np.linalg.eigvalsh(A.T @ Xm + Xm @ A)).max()))
    print("Xmin a generalised observability Gramian: min eig -(A^T X + X A + C^T C) = %.3e"
          % np.linalg.eigvalsh(-(A.T @ Xm + Xm @ A + C.T @ C)).min())
    for name, X in (("phbt Q", Q), ("phbt Xmin", Xm)):
        sig, Ar, Br, Cr = balance(A, B, C, P, X, r)
        e, g = hinf_err(A, B, C, Ar, Br, Cr)
        et = np.abs(Y - outputs(Ar, Br, Cr)).max() / ymax
        print("%-9s sigma_1..3 %s sigma_21 %.3e 2 sum tail %.3e  Hinf %.3e (rel %.3e)  output %.3e" %
              (name, np.array2string(sig[:3], precision=4), sig[r], 2 * sig[r:].sum(), e, e / g, et))
    for rom in roms:
        K, Qh, Bh = (np.load("%s_%s.npy" % (rom, x)) for x in ("K", "Qh", "Bh"))
        Ar, Br, Cr = K @ Qh, Bh, Bh.T @ Qh
        e, g = hinf_err(A, B, C, Ar, Br, Cr)
        et = np.abs(Y - outputs(Ar, Br, Cr)).max() / ymax
        print("%-9s (library) Hinf %.3e (rel %.3e)  output %.3e" % (rom, e, e / g, et))


if __name__ == "__main__":
    main(sys.argv[1:])
