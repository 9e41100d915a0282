"""A finite-element bar with a consistent mass matrix as a descriptor model,
for the descriptor case of make bench (the model of examples/fe_bar.c).

    python3 fe_bar.py OUTDIR N_ELEMENTS [--seed S]

Bar of length 1, fixed at the left end, n linear elements: stiffness
K = n tridiag(-1, 2, -1), consistent mass M = tridiag(1, 4, 1) / (6 n) (last
diagonals 1 and 2 halved as at a free end), Rayleigh damping D = 0.05 M +
1e-3 K. State x = (q, v), N = 2 n:  E x' = (J - R) Q x + B u with E = diag(I, M),
Q = diag(K, I), J = [[0, I], [-I, 0]], R = diag(0, D); ports: forces at the
tip and at the middle node. The states are put in a random order (seed S,
default 7). Writes E.npy, J.npy, R.npy, Q.npy (coordinate triplets (nnz, 3),
for --E-coo, --J-coo, ...) and B.npy (N x 2); no dense N x N array."""
import os
import sys

import numpy as np


def tridiag(n, off, diag, last):
    """Triplets of the symmetric tridiagonal matrix (off, diag; last diagonal entry last)."""
    i = np.arange(n)
    d = np.full(n, float(diag))
    d[-1] = last
    rows = np.concatenate([i, i[:-1], i[1:]])
    cols = np.concatenate([i, i[1:], i[:-1]])
    vals = np.concatenate([d, np.full(n - 1, float(off)), np.full(n - 1, float(off))])
    return rows, cols, vals


def bar(n, seed=7):
    N = 2 * n
    h = 1.0 / n
    kr, kc, kv = tridiag(n, -1.0, 2.0, 1.0)
    kv = kv / h
    mr, mc, mv = tridiag(n, 1.0, 4.0, 2.0)
    mv = mv * h / 6.0
    perm = np.random.default_rng(seed).permutation(N)  # new position of old state k: inv[k]
    inv = np.empty(N, dtype=np.int64)
    inv[perm] = np.arange(N)
    ids = np.arange(n)

    def trip(r, c, v):
        return np.column_stack([inv[r], inv[c], v])

    E = np.vstack([trip(ids, ids, np.ones(n)), trip(n + mr, n + mc, mv)])
    Q = np.vstack([trip(kr, kc, kv), trip(n + ids, n + ids, np.ones(n))])
    J = np.vstack([trip(ids, n + ids, np.ones(n)), trip(n + ids, ids, -np.ones(n))])
    # D = 0.05 M + 1e-3 K on the velocities (same tridiagonal pattern)
    R = trip(n + mr, n + mc, 0.05 * mv + 1e-3 * kv)
    B = np.zeros((N, 2))
    B[inv[n + n - 1], 0] = 1.0
    B[inv[n + n // 2 - 1], 1] = 1.0
    return E, J, R, Q, B


def main(argv):
    args = [x for x in argv if not x.startswith("--")]
    seed = 7
    if "--seed" in argv:
        seed = int(argv[argv.index("--seed") + 1])
        args.remove(str(seed))
    if len(args) != 2:
        sys.stderr.write(__doc__)
        return 2
    out, n = args[0], int(args[1])
    os.makedirs(out, exist_ok=True)
    for name, A in zip("EJRQB", bar(n, seed)):
        np.save(os.path.join(out, name + ".npy"), A)
    print(2 * n)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
