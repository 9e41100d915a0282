"""qm_greedy_ref.py -- an independent NumPy implementation of the greedy
quadratic manifold of Schwerdtner & Peherstorfer (2024, arXiv:2403.06732),
written from the paper's description, to give phgmg's greedy manifold
reference values on the advecting Gaussian pulse.

The method, as the paper describes it:
  1. SVD of the (optionally centred) snapshots: X - xbar = Phi Sigma Psi^T.
  2. The linear basis V takes n columns of Phi, chosen one at a time. At each
     step every candidate among the first `window` columns not yet taken is
     tried: with the taken columns plus the candidate as V, the reduced
     coordinates are Z = Sigma_in Psi_in^T, the features are the products
     z_i z_j (i >= j), and the complement Phi_out is fitted by ridge least
     squares, W = argmin ||Sigma_out Psi_out^T - W H(Z)||^2 + reg^2 ||W||^2
     (solved through the SVD of H^T). The candidate with the least residual
     is taken.
  3. The manifold is x = xbar + V z + Phi_out W h(z); on the training data
     its projection error ||X - phi(V^T (X - xbar))||_F / ||X||_F is the
     residual of the last fit over ||X||_F (V^T (X - xbar) = Z exactly).

The greedy choice at step k does not depend on the final n, so one run to
n = nmax gives the manifold (and its error) for every n <= nmax.

Data: u(x, t) = exp(-(x - 0.1 - 10 t)^2 / w) / sqrt(pi w), w = 2e-4, on 4096
points of [0, 1] at 2000 times of [0, 0.1]; the training snapshots are the
1000 even-numbered times (the data of the paper's code and of
bench/qm_pulse.c).

Usage: /usr/bin/python3 bench/qm_greedy_ref.py [--centre] [--nmax 20]
           [--window 200] [--reg 1e-6]
Prints one line per n: n, the chosen SVD index, the training error.
"""
import argparse
import time

import numpy as np


def pulse_snapshots(nx=4096, nt=2000, w=2e-4, x0=0.1, c=10.0, T=0.1):
    x = np.linspace(0.0, 1.0, nx)
    t = np.linspace(0.0, T, nt)[::2]
    d = x[:, None] - x0 - c * t[None, :]
    return np.exp(-d * d / w) / np.sqrt(np.pi * w)


def features(Z):
    """Rows z_i z_j, j <= i (p(p+1)/2 of them) of the p x ns coordinates."""
    return np.concatenate([Z[i] * Z[: i + 1] for i in range(Z.shape[0])], axis=0)


def ridge_residual(A, B, reg):
    """||B - A x||_F with x = argmin ||B - A x||^2 + reg^2 ||x||^2 (via the SVD
    of A); the residual is formed, not taken from a difference of squares."""
    P, s, _ = np.linalg.svd(A, full_matrices=False)
    d = s * s / (s * s + reg * reg)
    C = P.T @ B
    return np.linalg.norm(B - P @ (d[:, None] * C))


def greedy(X, nmax, window, reg, centre):
    xbar = X.mean(axis=1, keepdims=True) if centre else np.zeros((X.shape[0], 1))
    _, sig, Psit = np.linalg.svd(X - xbar, full_matrices=False)
    Zall = sig[:, None] * Psit              # every mode's coordinates (k x ns)
    norm_x = np.linalg.norm(X)
    taken, left, rows = [], list(range(len(sig))), []
    for _ in range(nmax):
        best, best_err = None, np.inf
        for c in left[:window]:
            inn = taken + [c]
            out = [i for i in left if i != c]
            e = ridge_residual(features(Zall[inn]).T, Zall[out].T, reg)
            if e < best_err:
                best, best_err = c, e
        taken.append(best)
        left.remove(best)
        rows.append((len(taken), best, best_err / norm_x))
        yield rows[-1]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--centre", action="store_true", help="subtract the snapshot mean")
    ap.add_argument("--nmax", type=int, default=20)
    ap.add_argument("--window", type=int, default=200)
    ap.add_argument("--reg", type=float, default=1e-6)
    a = ap.parse_args()
    X = pulse_snapshots()
    t0 = time.time()
    print("advecting pulse %d x %d, %s, window %d, reg %g" % (X.shape + ("centred" if a.centre else "not centred", a.window, a.reg)))
    print("%4s %6s %12s %8s" % ("n", "index", "e_proj", "time_s"))
    for n, idx, e in greedy(X, a.nmax, a.window, a.reg, a.centre):
        print("%4d %6d %12.3e %8.1f" % (n, idx, e, time.time() - t0), flush=True)


if __name__ == "__main__":
    main()
