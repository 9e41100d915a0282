"""The two sparse linear pH models of the low-rank balancing runs, scrambled.

    /usr/bin/python3 bench/lowrank_models.py OUTDIR heat|lattice N [--seed S] [--dense]

heat:    J = 0, R = the 2-D Dirichlet Laplacian (5-point stencil: 4 on the
         diagonal, -1 to each neighbour) on an N x N grid, Q = I, n = N^2
         states, two boundary ports: input 1 on the nodes of the left edge,
         input 2 on the nodes of the bottom edge (weights 1).
lattice: an N x N mass-spring-damper lattice, x = (q, p) per mass, n = 2 N^2:
         K = the 2-D Dirichlet Laplacian + 0.01 I, D = 0.5 I + 0.01 K, unit
         masses; forces on the corner masses (0, 0) and (N-1, N-1), collocated
         (velocity outputs). J = [[0, I], [-I, 0]], R = diag(0, D), Q =
         diag(K, I).
The n state coordinates are put in a random order (seed S, default 1). Writes
J.npy, R.npy, Q.npy as coordinate triplets (nnz, 3) for --J-coo/--R-coo/--Q-coo
and B.npy (n x 2); with --dense also Jd.npy, Rd.npy, Qd.npy (n x n, for the
dense solvers and for checks)."""
import os
import sys

import numpy as np


def laplacian(n, shift=0.0, scale=1.0):
    """(rows, cols, vals) of scale * (2-D Dirichlet Laplacian + shift I), n x n grid."""
    idx = np.arange(n * n).reshape(n, n)   # idx[y, x]
    r = [idx.ravel()]
    c = [idx.ravel()]
    v = [np.full(n * n, scale * (4.0 + shift))]
    for a, b in ((idx[:, :-1], idx[:, 1:]), (idx[:-1, :], idx[1:, :])):
        r += [a.ravel(), b.ravel()]
        c += [b.ravel(), a.ravel()]
        v += [np.full(a.size, -scale), np.full(a.size, -scale)]
    return np.concatenate(r), np.concatenate(c), np.concatenate(v)


def model(kind, n, seed=1):
    n2 = n * n
    if kind == "heat":
        N = n2
        J = (np.zeros(0, int), np.zeros(0, int), np.zeros(0))
        R = laplacian(n)
        Q = (np.arange(N), np.arange(N), np.ones(N))
        B = np.zeros((N, 2))
        B[np.arange(n) * n, 0] = 1.0       # left edge: x = 0
        B[np.arange(n), 1] = 1.0           # bottom edge: y = 0
    else:
        N = 2 * n2
        q, p = np.arange(n2), n2 + np.arange(n2)
        J = (np.concatenate([q, p]), np.concatenate([p, q]), np.concatenate([np.ones(n2), -np.ones(n2)]))
        kr, kc, kv = laplacian(n, 0.01)
        dr, dc, dv = laplacian(n, 0.01, 0.01)
        dv = dv + np.where(dr == dc, 0.5, 0.0)
        R = (n2 + dr, n2 + dc, dv)
        Q = (np.concatenate([kr, p]), np.concatenate([kc, p]), np.concatenate([kv, np.ones(n2)]))
        B = np.zeros((N, 2))
        B[n2, 0] = 1.0
        B[n2 + n2 - 1, 1] = 1.0
    perm = np.random.default_rng(seed).permutation(N)   # state i -> coordinate perm[i]
    trip = [np.column_stack([perm[r], perm[c], v]).astype(float) for r, c, v in (J, R, Q)]
    Bs = np.zeros_like(B)
    Bs[perm] = B
    return N, trip, Bs


def dense(N, t):
    M = np.zeros((N, N))
    np.add.at(M, (t[:, 0].astype(int), t[:, 1].astype(int)), t[:, 2])
    return M


def main(argv):
    args = [x for x in argv if not x.startswith("--")]
    seed = 1
    if "--seed" in argv:
        seed = int(argv[argv.index("--seed") + 1])
        args.remove(argv[argv.index("--seed") + 1])
    out, kind, n = args[0], args[1], int(args[2])
    if kind not in ("heat", "lattice"):
        sys.exit("lowrank_models.py: the model is heat or lattice")
    N, trip, B = model(kind, n, seed)
    os.makedirs(out, exist_ok=True)
    for name, t in zip("JRQ", trip):
        np.save(os.path.join(out, name + ".npy"), t)
        if "--dense" in argv:
            np.save(os.path.join(out, name + "d.npy"), dense(N, t))
    np.save(os.path.join(out, "B.npy"), B)
    print("%s %d: N = %d, nnz J/R/Q = %d/%d/%d" % (kind, n, N, len(trip[0]), len(trip[1]), len(trip[2])))


if __name__ == "__main__":
    main(sys.argv[1:])
