"""Hankel singular values of `phgmg reduce --method bt` (low-rank solvers, COO input, the scrambled
models of bench/lowrank_models.py) against a reference built from the models' eigenmodes, so that
it reaches N = 10^4 without a dense N^3 solver:

heat     A = -L (L the 2-D Dirichlet Laplacian, eigenpairs in closed form: sine modes), C = B^T.
         In modal coordinates the Gramians are equal, P_kl = (b_k . b_l) / (lambda_k + lambda_l),
         and the Hankel singular values are the eigenvalues of P (Lanczos, scipy eigsh).
lattice  A = [[0, I], [-K, -D]], K = L + 0.01 I, D = 0.5 I + 0.01 K share the sine modes: each mode
         k is a 2 x 2 block A_k = [[0, 1], [-kappa_k, -d_k]]. The Gramians' 2 x 2 blocks solve
         A_k P_kl + P_kl A_l^T + b_k b_l^T = 0 (and the dual for O) in closed form (a 4 x 4 solve
         per pair of modes); the Hankel singular values are the square roots of the eigenvalues
         of P O (Arnoldi, scipy eigs).
The modal transform is orthogonal and the scrambling a permutation, so both leave the Hankel
singular values unchanged. With --check the reference is first compared with SciPy's dense
solve_continuous_lyapunov on small grids (it must agree to rounding).

    /usr/bin/python3 bench/lowrank_hsv_modal.py build/phgmg WORKDIR [HEAT_N LATTICE_N] [--check]

(defaults 100 and 71: N = 10 000 and 10 082). Prints max_{i <= 25} |sigma_i - ref_i| / sigma_1."""
import os
import sys
import time

import numpy as np
import scipy.sparse.linalg as spla

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from lowrank_hsv_ref import dense_reference, reduce_bt   # noqa: E402


def sine_modes(n):
    """Eigenvalues (n^2) and orthonormal eigenvectors' grid factors of the n x n Dirichlet
    Laplacian: L = sum lam_ab phi_ab phi_ab^T, phi_ab[y, x] = s_a[x] s_b[y]."""
    j = np.arange(1, n + 1)
    mu = 2.0 - 2.0 * np.cos(j * np.pi / (n + 1))
    S = np.sqrt(2.0 / (n + 1)) * np.sin(np.outer(np.arange(1, n + 1), j) * np.pi / (n + 1))  # S[x, a]
    lam = (mu[None, :] + mu[:, None]).ravel()   # index b * n + a  (b: y mode, a: x mode)
    return lam, S


def heat_reference(n, k=25):
    lam, S = sine_modes(n)
    # ports: left edge (x = 0, all y) and bottom edge (y = 0, all x), weights 1
    col = S.sum(axis=0)                         # sum over grid points of s_a
    b1 = (S[0, :][None, :] * col[:, None]).ravel()     # phi_ab over x = 0: s_a(0) sum_y s_b(y); [b, a]
    b2 = (col[None, :] * S[0, :][:, None]).ravel()     # over y = 0: s_b(0) sum_x s_a(x)
    Bm = np.column_stack([b1, b2])
    P = (Bm @ Bm.T) / (lam[:, None] + lam[None, :])
    w = spla.eigsh(P, k=k + 5, which="LA", tol=0, return_eigenvectors=False)
    return np.sort(w)[::-1][:k]


def lattice_reference(n, k=25):
    lam, S = sine_modes(n)
    kap = lam + 0.01
    d = 0.5 + 0.01 * kap
    nm = n * n
    # ports: forces on the p of masses (0, 0) and (n-1, n-1) (x, y); C = B^T
    bb = np.column_stack([(S[0, :][None, :] * S[0, :][:, None]).ravel(),
                          (S[n - 1, :][None, :] * S[n - 1, :][:, None]).ravel()])   # mode weights (nm x 2)
    Ak = np.zeros((nm, 2, 2))
    Ak[:, 0, 1] = 1.0
    Ak[:, 1, 0] = -kap
    Ak[:, 1, 1] = -d
    P = np.zeros((2 * nm, 2 * nm))
    O = np.zeros((2 * nm, 2 * nm))
    I2 = np.eye(2)
    blk = 256
    for k0 in range(0, nm, blk):
        ks = np.arange(k0, min(nm, k0 + blk))
        # vec(X) column-major: (I (x) A_k + A_l (x) I) vec X = -vec(b_k b_l^T); b_k = [0; bb_k]
        M = (np.einsum("ij,kab->kiajb", I2, Ak[ks])[:, None] +
             np.einsum("lij,ab->liajb", Ak, I2)[None, :]).reshape(len(ks), nm, 4, 4)
        # rhs: b_k b_l^T has only the (1, 1) entry bb_k . bb_l; vec index (row 1, col 1) = 3
        g = bb[ks] @ bb.T
        rhs = np.zeros((len(ks), nm, 4))
        rhs[:, :, 3] = -g
        X = np.linalg.solve(M, rhs[..., None])[..., 0]        # vec X = [x00, x10, x01, x11]
        # O: A_k^T Y + Y A_l + c_k^T c_l = 0 with c_k = b_k^T
        Mo = (np.einsum("ij,kba->kiajb", I2, Ak[ks])[:, None] +
              np.einsum("lji,ab->liajb", Ak, I2)[None, :]).reshape(len(ks), nm, 4, 4)
        Y = np.linalg.solve(Mo, rhs[..., None])[..., 0]
        for Z, T in ((X, P), (Y, O)):
            Zb = Z.reshape(len(ks), nm, 2, 2, order="C")   # [.., col, row] after the vec order
            T.reshape(nm, 2, nm, 2)[ks] = np.transpose(Zb, (0, 3, 1, 2))
    op = spla.LinearOperator(P.shape, matvec=lambda v: P @ (O @ v))
    w = spla.eigs(op, k=k + 5, which="LM", tol=0, return_eigenvectors=False)
    return np.sort(np.sqrt(np.abs(w.real)))[::-1][:k]


def main(argv):
    check = "--check" in argv
    args = [a for a in argv if not a.startswith("--")]
    exe, work = args[0], args[1]
    sizes = (int(args[2]), int(args[3])) if len(args) > 3 else (100, 71)
    ref_fn = {"heat": heat_reference, "lattice": lattice_reference}
    if check:   # the modal reference against the dense one on small grids
        for kind, n in (("heat", 12), ("lattice", 9)):
            a, b = ref_fn[kind](n, 20), dense_reference(kind, n)[:20]
            e = np.abs(a - b).max() / b[0]
            print("check %s n=%d: modal against dense SciPy: %.2e sigma_1" % (kind, n, e))
            if not e <= 1e-12:
                sys.exit("lowrank_hsv_modal.py: the modal reference disagrees with the dense one")
    for kind, n in zip(("heat", "lattice"), sizes):
        t0 = time.time()
        N, s = reduce_bt(exe, work, kind, n)
        t1 = time.time()
        c0 = time.process_time()
        ref = ref_fn[kind](n)
        print("%s n=%d N=%d: max_{i<=25} |sigma_i - ref_i| / sigma_1 = %.2e (sigma_25/sigma_1 = %.1e; "
              "phgmg %.1f s wall, modal reference %.1f s CPU)" %
              (kind, n, N, np.abs(s[:25] - ref[:25]).max() / ref[0], ref[24] / ref[0], t1 - t0,
               time.process_time() - c0))


if __name__ == "__main__":
    main(sys.argv[1:])
