"""What a low-rank Newton-Kleinman solver would face on PRBT of a pH model
without feedthrough: an independent dense computation with SciPy.

    /usr/bin/python3 bench/prbt_riccati_rank.py [N]      (default N = 12: n = 288)

PRBT's Gramians solve the positive-real lemma's Riccati equation

    A^T X + X A + (X B - C^T)(D + D^T)^{-1}(B^T X - C) = 0,

which a pH model (D = 0) makes singular: the solution of D = 0 is the limit
eps -> 0 of the regularised equation with D + D^T = 2 eps ||C B|| I. A
low-rank Newton-Kleinman solver works on the regularised equation; each
Newton step is a Lyapunov equation with the closed-loop matrix
A - B K, K = (D + D^T)^{-1} (B^T X - C). On the 2-D mass-spring-damper
lattice of the low-rank benchmarks (bench/lowrank_models.py, N x N masses,
n = 2 N^2) this prints, for eps = 1 ... 1e-8 (SciPy's dense solver):
  - the residual, and ||X B - C^T|| / ||C||: how far X_eps is from the D = 0
    solution, whose X B = C^T holds exactly;
  - the numerical rank of X_eps (singular values above 1e-10 and 1e-6 of the
    largest) against the controllability Gramian P's (LR-ADI's target);
  - ||K|| and the largest |eigenvalue| of A - B K over that of A: the spread
    of the spectrum the inner ADI's shifts must cover.
What it shows: X_eps is as numerically low-rank as P (a low-rank factor
exists), but it approaches the D = 0 solution only like sqrt(eps) while ||K||
and the closed-loop spectrum grow like 1/sqrt(eps): accuracy at the level of
the dense PRBT (which takes the D = 0 limit exactly) needs eps so small that
the inner Lyapunov equations become badly scaled. The library's low-rank PRBT
therefore reduces in two stages: low-rank BT to an intermediate order, then
the exact D = 0 limit by the dense PRBT of that pH model.
"""
import sys

import numpy as np
import scipy.linalg as sla

sys.path.insert(0, __file__.rsplit('/', 1)[0])
from lowrank_models import dense, model   # noqa: E402


def ranks(M):
    s = np.linalg.svd(M, compute_uv=False)
    return int((s > 1e-10 * s[0]).sum()), int((s > 1e-6 * s[0]).sum())


def main(argv):
    nside = int(argv[0]) if argv else 12
    N, (Jt, Rt, Qt), B = model('lattice', nside)
    J, R, Q = dense(N, Jt), dense(N, Rt), dense(N, Qt)
    A = (J - R) @ Q
    C = B.T @ Q
    m = B.shape[1]
    c = np.linalg.norm(C @ B)
    P = sla.solve_continuous_lyapunov(A, -B @ B.T)
    r10, r6 = ranks(P)
    print('lattice %d x %d masses, n = %d, m = %d' % (nside, nside, N, m))
    print()
    rho = np.abs(np.linalg.eigvals(A)).max()
    print('| matrix | residual (rel.) | X B - C^T (rel.) | rank at 1e-10 | rank at 1e-6 | norm of K | spectral radius of A - B K over A\'s |')
    print('|---|---|---|---|---|---|---|')
    res = np.linalg.norm(A @ P + P @ A.T + B @ B.T) / np.linalg.norm(B @ B.T)
    print('| Gramian P (Lyapunov) | %.1e | | %d | %d | | |' % (res, r10, r6))
    for eps in (1.0, 1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-8):
        Rm = 2.0 * eps * c * np.eye(m)
        X = sla.solve_continuous_are(A, B, np.zeros_like(A), -Rm, s=-C.T)
        X = 0.5 * (X + X.T)
        G = X @ B - C.T
        res = np.linalg.norm(A.T @ X + X @ A + G @ np.linalg.solve(Rm, G.T)) / np.linalg.norm(C.T @ np.linalg.solve(Rm, C))
        r10, r6 = ranks(X)
        K = np.linalg.solve(Rm, G.T)
        rk = np.abs(np.linalg.eigvals(A - B @ K)).max() / rho
        print('| X, eps = %.0e | %.1e | %.1e | %d | %d | %.1e | %.1e |' % (eps, res, np.linalg.norm(G) / np.linalg.norm(C),
                                                                 r10, r6, np.linalg.norm(K, 2), rk))


if __name__ == '__main__':
    main(sys.argv[1:])
