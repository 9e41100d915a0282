"""Finite-element port-Hamiltonian models on jittered triangulations, for the
set-up benchmarks of `phgmg simulate` / `validate` / `reduce` (bench/README.md).

    python3 fe_mesh.py acoustic OUTDIR N_SIDE [--seed S]
    python3 fe_mesh.py biot OUTDIR N_SIDE [--seed S]
    python3 fe_mesh.py chirp OUT.npy T_END M [--f0 0.2] [--f1 2] [--amp 0.1]

Mesh: the unit square with N_SIDE x N_SIDE nodes, interior nodes moved by up
to 0.3 h at random, each cell cut along a random diagonal; linear (P1)
elements, consistent mass matrix M, stiffness (Laplacian) K, the derivative
matrices Dx, Dy (Dx[i, j] = int phi_i d(phi_j)/dx).

acoustic: a 2-D acoustic wave in mixed P1 elements, state x = (p, vx, vy),
  N = 3 N_SIDE^2:
     E = blkdiag(M, M, M),  Q = I,
     J = [[0, Dx^T, Dy^T], [-Dx, 0, 0], [-Dy, 0, 0]]   (skew; natural b.c.),
     R = 0.01 E + 1e-4 blkdiag(K, K, K)                 (Rayleigh damping),
     B = two Gaussian sources in the pressure equation (M g_k).
biot: Biot poroelasticity in the port-Hamiltonian form of Altmann, Mehrmann &
  Unger, P1/P1, displacement u (2 components, clamped on the bottom edge),
  velocity w = u', pressure p (drained, p = 0, on the top edge);
  x = (u, w, p), N = 4 n_u + N_SIDE (N_SIDE - 1):
     E = blkdiag(K_u, M_u, M_p),  Q = I,
     J - R = [[0, K_u, 0], [-K_u, 0, D^T], [0, -D, -K_p]],
  K_u the plane-strain elasticity stiffness (mu = 1, lambda = 2), M_u the
  mass (rho = 1), M_p = M / 10 (the Biot modulus), K_p = 0.1 K (permeability),
  D[i, (j, c)] = alpha int phi_i d(phi_j)/dx_c (alpha = 0.8); ports: a
  vertical traction on the top edge (w equation) and a Gaussian fluid source
  (p equation).
Both: E symmetric positive definite, H = x^T E x / 2; states put in a random
order (seed S, default 3; rows and columns alike). Writes E.npy, J.npy,
R.npy, Q.npy (coordinate triplets (nnz, 3) for --E-coo, --J-coo, ...) and
B.npy (N x 2).
chirp: a table (K, 1 + M) for --input: u_a(t) = AMP sin(2 pi (f0 t +
  (f1 - f0) t^2 / (2 T_END)) + a), sampled every 0.001 (linear interpolation
  between the samples is what phgmg and fe_gl3_ref.py both use)."""
import os
import sys

import numpy as np
import scipy.sparse as sps


def mesh(n, rng):
    h = 1.0 / (n - 1)
    g = np.linspace(0.0, 1.0, n)
    X, Y = np.meshgrid(g, g)
    X, Y = X.ravel(), Y.ravel()
    inner = (X > 0) & (X < 1) & (Y > 0) & (Y < 1)
    X[inner] += rng.uniform(-0.3, 0.3, inner.sum()) * h
    Y[inner] += rng.uniform(-0.3, 0.3, inner.sum()) * h
    idx = np.arange(n * n).reshape(n, n)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    flip = rng.random(a.size) < 0.5
    t1 = np.where(flip[:, None], np.column_stack([a, b, d]), np.column_stack([a, b, c]))
    t2 = np.where(flip[:, None], np.column_stack([a, d, c]), np.column_stack([b, d, c]))
    return np.column_stack([X, Y]), np.vstack([t1, t2])


def p1(pts, tri):
    """Element quantities: area, gradients of the 3 hat functions (T, 3, 2)."""
    P = pts[tri]
    d1, d2 = P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]
    det = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    area = 0.5 * np.abs(det)
    inv = np.empty((tri.shape[0], 2, 2))
    inv[:, 0, 0], inv[:, 0, 1] = d2[:, 1] / det, -d2[:, 0] / det
    inv[:, 1, 0], inv[:, 1, 1] = -d1[:, 1] / det, d1[:, 0] / det
    ref = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])
    grad = np.einsum("ak,tkc->tac", ref, inv)   # d phi_a / d x_c
    return area, grad


def assemble(tri, loc, n):
    r = np.repeat(tri, 3, axis=1).ravel()
    c = np.tile(tri, (1, 3)).ravel()
    return sps.csr_matrix((loc.ravel(), (r, c)), shape=(n, n))


def fe_matrices(pts, tri):
    n = pts.shape[0]
    area, grad = p1(pts, tri)
    mloc = area[:, None, None] * (np.ones((3, 3)) + np.eye(3)) / 12.0
    kloc = area[:, None, None] * np.einsum("tac,tbc->tab", grad, grad)
    # Dx[i, j] = int phi_i dphi_j/dx = area/3 * grad_j
    dx = area[:, None, None] / 3.0 * np.repeat(grad[:, None, :, 0], 3, axis=1)
    dy = area[:, None, None] / 3.0 * np.repeat(grad[:, None, :, 1], 3, axis=1)
    return (assemble(tri, mloc, n), assemble(tri, kloc, n),
            assemble(tri, dx, n), assemble(tri, dy, n))


def gauss(pts, x0, y0, w=0.08):
    return np.exp(-((pts[:, 0] - x0) ** 2 + (pts[:, 1] - y0) ** 2) / (2 * w * w))


def acoustic(n, rng):
    pts, tri = mesh(n, rng)
    M, K, Dx, Dy = fe_matrices(pts, tri)
    Z = None
    E = sps.block_diag([M, M, M])
    J = sps.bmat([[Z, Dx.T, Dy.T], [-Dx, Z, Z], [-Dy, Z, Z]])
    R = 0.01 * E + 1e-4 * sps.block_diag([K, K, K])
    nn = n * n
    B = np.zeros((3 * nn, 2))
    B[:nn, 0] = M @ gauss(pts, 0.3, 0.35)
    B[:nn, 1] = M @ gauss(pts, 0.7, 0.6)
    return E, J, R, sps.identity(3 * nn), B


def elasticity(grad, area, mu=1.0, lam=2.0):
    """Plane-strain stiffness of the element (T, 6, 6), dofs (node a, comp c) -> 2a + c."""
    T = grad.shape[0]
    Bm = np.zeros((T, 3, 6))
    Bm[:, 0, 0::2] = grad[:, :, 0]
    Bm[:, 1, 1::2] = grad[:, :, 1]
    Bm[:, 2, 0::2] = grad[:, :, 1]
    Bm[:, 2, 1::2] = grad[:, :, 0]
    C = np.array([[lam + 2 * mu, lam, 0], [lam, lam + 2 * mu, 0], [0, 0, mu]])
    return area[:, None, None] * np.einsum("tia,ij,tjb->tab", Bm, C, Bm)


def biot(n, rng, alpha=0.8):
    pts, tri = mesh(n, rng)
    nn = n * n
    M, K, Dx, Dy = fe_matrices(pts, tri)
    area, grad = p1(pts, tri)
    dof = np.empty((tri.shape[0], 6), dtype=np.int64)
    dof[:, 0::2], dof[:, 1::2] = 2 * tri, 2 * tri + 1
    ke = elasticity(grad, area)
    Ku = sps.csr_matrix((ke.ravel(), (np.repeat(dof, 6, axis=1).ravel(), np.tile(dof, (1, 6)).ravel())),
                        shape=(2 * nn, 2 * nn))
    Ku = (Ku + Ku.T) / 2   # exactly symmetric, so that J is exactly skew
    Mu = sps.kron(M, sps.identity(2)).tocsr()
    # D[i, 2j + c] = alpha int phi_i dphi_j/dx_c
    D = alpha * sps.hstack([Dx, Dy]).tocsr()[:, np.argsort(np.r_[2 * np.arange(nn), 2 * np.arange(nn) + 1])]
    free = np.flatnonzero(np.repeat(pts[:, 1] > 1e-12, 2))   # clamped on the bottom edge
    Ku, Mu, D = Ku[free][:, free], Mu[free][:, free], D[:, free]
    nu = free.size
    pf = np.flatnonzero(pts[:, 1] < 1.0 - 1e-12)             # drained (p = 0) on the top edge
    Mp, Kp, D = (M / 10.0)[pf][:, pf], (0.1 * K)[pf][:, pf], D[pf]
    npf = pf.size
    Z = None
    E = sps.block_diag([Ku, Mu, Mp])
    J = sps.bmat([[Z, Ku, Z], [-Ku, Z, D.T], [Z, -D, Z]])
    R = sps.block_diag([sps.csr_matrix((2 * nu, 2 * nu)), Kp])
    N = 2 * nu + npf
    B = np.zeros((N, 2))
    top = np.flatnonzero(np.abs(pts[:, 1] - 1.0) < 1e-12)
    ftop = np.zeros(2 * nn)
    order = top[np.argsort(pts[top, 0])]
    seg = np.diff(pts[order, 0])
    ftop[2 * order[:-1] + 1] += seg / 2
    ftop[2 * order[1:] + 1] += seg / 2
    B[nu:2 * nu, 0] = -ftop[free]
    B[2 * nu:, 1] = (M @ gauss(pts, 0.5, 0.5, 0.1))[pf]
    return E, J, R, sps.identity(N), B


def scrambled(mats, B, seed):
    N = B.shape[0]
    perm = np.random.default_rng(seed).permutation(N)
    inv = np.empty(N, dtype=np.int64)
    inv[perm] = np.arange(N)
    out = []
    for A in mats:
        c = sps.coo_matrix(A)
        c.sum_duplicates()
        c.eliminate_zeros()
        out.append(np.column_stack([inv[c.row], inv[c.col], c.data]))
    Bs = np.zeros_like(B)
    Bs[inv] = B
    return out, Bs


def chirp(out, tend, m, f0=0.2, f1=2.0, amp=0.1):
    t = np.arange(0.0, tend + 1e-9, 0.001)
    cols = [amp * np.sin(2 * np.pi * (f0 * t + (f1 - f0) * t * t / (2 * tend)) + a) for a in range(m)]
    np.save(out, np.column_stack([t] + cols))


def main(argv):
    opt = {"--seed": "3", "--f0": "0.2", "--f1": "2", "--amp": "0.1"}
    for k in opt:
        if k in argv:
            i = argv.index(k)
            opt[k] = argv[i + 1]
            argv = argv[:i] + argv[i + 2:]
    kind = argv[0]
    if kind == "chirp":
        chirp(argv[1], float(argv[2]), int(argv[3]), float(opt["--f0"]), float(opt["--f1"]), float(opt["--amp"]))
        return
    out, n = argv[1], int(argv[2])
    rng = np.random.default_rng(int(opt["--seed"]))
    E, J, R, Q, B = (acoustic if kind == "acoustic" else biot)(n, rng)
    trips, Bs = scrambled([E, J, R, Q], B, int(opt["--seed"]) + 100)
    os.makedirs(out, exist_ok=True)
    for name, t in zip("EJRQ", trips):
        np.save(os.path.join(out, name + ".npy"), t)
    np.save(os.path.join(out, "B.npy"), Bs)
    print("N = %d, nnz(E) = %d, nnz(J) = %d" % (B.shape[0], trips[0].shape[0], trips[1].shape[0]))


if __name__ == "__main__":
    main(sys.argv[1:])
