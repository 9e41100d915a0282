"""Scrambled mass-spring lattices for the sparse benchmarks and tests.

    python3 lattice.py OUTDIR NX NY [NZ] [--seed S] [--cosh] [--b2 W]

A lattice of NX x NY (x NZ) masses, nearest neighbours joined by unit springs,
each mass also held by an on-site spring 0.1 and damped (0.05). State per
mass: position q and momentum p; H = 1/2 q^T K q + 1/2 |p|^2 (K: the spring
Laplacian + 0.1 I), J = [[0, I], [-I, 0]] per mass, R = 0.05 on each p,
B = the momentum of mass 0 (with --b2 W also W times that of mass 1, the
neighbour along x: the input then has no mirror symmetry (x, y) <-> (y, x)).
The N = 2 NX NY NZ state coordinates are put in a
random order (seed S, default 1), so that the given order has no band.
Writes J.npy, R.npy, Q.npy (coordinate triplets (nnz, 3) for --J-coo ...),
B.npy (N), and with --cosh idx.npy: the position coordinates of the masses
(for --potential cosh:1 --poly-idx idx.npy, an on-site cosh potential)."""
import os
import sys

import numpy as np


def lattice(nx, ny, nz=1, seed=1):
    nn = nx * ny * nz
    N = 2 * nn
    perm = np.random.default_rng(seed).permutation(N)
    q = perm[0::2]
    p = perm[1::2]
    node = np.arange(nn).reshape(nz, ny, nx)
    pairs = []
    if nx > 1:
        pairs.append((node[:, :, :-1].ravel(), node[:, :, 1:].ravel()))
    if ny > 1:
        pairs.append((node[:, :-1, :].ravel(), node[:, 1:, :].ravel()))
    if nz > 1:
        pairs.append((node[:-1, :, :].ravel(), node[1:, :, :].ravel()))
    a = np.concatenate([x for x, _ in pairs]) if pairs else np.zeros(0, int)
    b = np.concatenate([y for _, y in pairs]) if pairs else np.zeros(0, int)
    deg = np.bincount(a, minlength=nn) + np.bincount(b, minlength=nn)
    ids = np.arange(nn)
    Jt = np.vstack([np.column_stack([q, p, np.ones(nn)]), np.column_stack([p, q, -np.ones(nn)])])
    Rt = np.column_stack([p, p, 0.05 * np.ones(nn)])
    Qt = np.vstack([np.column_stack([q[ids], q[ids], deg + 0.1]),
                    np.column_stack([p, p, np.ones(nn)]),
                    np.column_stack([q[a], q[b], -np.ones(len(a))]),
                    np.column_stack([q[b], q[a], -np.ones(len(a))])])
    B = np.zeros(N)
    B[p[0]] = 1.0
    return N, Jt, Rt, Qt, B, q


def main(argv):
    args = [x for x in argv if not x.startswith("--")]
    seed, b2 = 1, 0.0
    if "--seed" in argv:
        seed = int(argv[argv.index("--seed") + 1])
        args.remove(argv[argv.index("--seed") + 1])
    if "--b2" in argv:
        b2 = float(argv[argv.index("--b2") + 1])
        args.remove(argv[argv.index("--b2") + 1])
    out, nx, ny = args[0], int(args[1]), int(args[2])
    nz = int(args[3]) if len(args) > 3 else 1
    N, Jt, Rt, Qt, B, q = lattice(nx, ny, nz, seed)
    if b2 != 0.0:   # the momentum of mass 1: the p coordinate next to mass 1's q in the permutation
        B[np.random.default_rng(seed).permutation(N)[3]] = b2
    os.makedirs(out, exist_ok=True)
    for name, t in (("J", Jt), ("R", Rt), ("Q", Qt)):
        np.save(os.path.join(out, name + ".npy"), t)
    np.save(os.path.join(out, "B.npy"), B)
    if "--cosh" in argv:
        np.save(os.path.join(out, "idx.npy"), q.astype(np.int64))
    print(N)


if __name__ == "__main__":
    main(sys.argv[1:])
