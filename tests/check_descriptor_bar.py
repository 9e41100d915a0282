# FEM bar with consistent mass (descriptor pH), N = 2n, scrambled ordering;
# independent GL3 (sparse direct) reference and plain POD-Galerkin.
import numpy as np, scipy.sparse as sp, scipy.sparse.linalg as sla, sys, os
n = int(sys.argv[1]) if len(sys.argv) > 1 else 400
out = sys.argv[2] if len(sys.argv) > 2 else '/tmp/dbar'
dt, steps, amp = 0.05, 1000, 1.0
N = 2 * n; h = 1.0 / n
K = sp.diags([-np.ones(n-1), np.r_[2*np.ones(n-1), 1.0], -np.ones(n-1)], [-1, 0, 1]) / h
M = sp.diags([np.ones(n-1), np.r_[4*np.ones(n-1), 2.0], np.ones(n-1)], [-1, 0, 1]) * h / 6
D = 0.05 * M + 1e-3 * K
I = sp.identity(n); Z = sp.csr_matrix((n, n))
E = sp.bmat([[I, None], [None, M]]).tocsc()
Q = sp.bmat([[K, None], [None, I]]).tocsc()
J = sp.bmat([[Z, I], [-I, Z]]).tocsc()
R = sp.bmat([[Z, None], [None, D]]).tocsc()
B = np.zeros((N, 2)); B[n + n - 1, 0] = 1.0; B[n + n // 2 - 1, 1] = 1.0
rng = np.random.default_rng(7); p = rng.permutation(N)      # scrambled: new i = old p[i]
P = sp.identity(N).tocsr()[p, :]
Es, Js, Rs, Qs, Bs = [(P @ A @ P.T).tocoo() for A in (E, J, R, Q)] + [B[p, :]]
for name, A in zip('EJRQ', (Es, Js, Rs, Qs)):
    np.save(os.path.join(out, name + '_coo.npy'), np.column_stack([A.row, A.col, A.data]))
    np.save(os.path.join(out, name + '.npy'), A.toarray())
np.save(os.path.join(out, 'B.npy'), Bs)
# GL3 with the mass matrix, the 3N stage system solved by sparse LU
s15 = np.sqrt(15.0)
A3 = np.array([[5/36, 2/9 - s15/15, 5/36 - s15/30], [5/36 + s15/24, 2/9, 5/36 - s15/24],
               [5/36 + s15/30, 2/9 + s15/15, 5/36]])
c = np.array([0.5 - s15/10, 0.5, 0.5 + s15/10]); b = np.array([5/18, 4/9, 5/18])
d = b @ np.linalg.inv(A3)
def gl3(Em, Mm, Bm, Cm, x0):
    Nn = Em.shape[0]
    big = sp.kron(sp.identity(3), sp.csc_matrix(Em)) - dt * sp.kron(sp.csc_matrix(A3), sp.csc_matrix(Mm))
    lu = sla.splu(big.tocsc())
    x = x0.copy(); X = [x.copy()]; Y = [Cm @ x]
    for k in range(steps):
        t = k * dt
        F = np.concatenate([Mm @ x + Bm @ (amp * np.sin(t + ci * dt) * np.ones(2)) for ci in c])
        rhs = dt * (np.kron(A3, np.eye(1)) @ F.reshape(3, Nn)).reshape(-1)
        Zs = lu.solve(rhs).reshape(3, Nn)
        x = x + d @ Zs
        X.append(x.copy()); Y.append(Cm @ x)
    return np.array(X).T, np.array(Y).T
Ms = (Js - Rs) @ Qs
X, Y = gl3(Es, Ms, Bs, Bs.T @ Qs, np.zeros(N))
np.save(os.path.join(out, 'Yfull.npy'), Y); np.save(os.path.join(out, 'Xfull.npy'), X)
# plain POD-Galerkin: V = POD of X, V^T E V x' = V^T (J - R) Q V x + V^T B u, y = B^T Q V x
U, S, _ = np.linalg.svd(X, full_matrices=False)
for r in (8, 14, 20):
    V = U[:, :r]
    Xr, Yr = gl3(V.T @ (Es @ V), V.T @ (Ms @ V), V.T @ Bs, Bs.T @ (Qs @ V), np.zeros(r))
    print('POD-Galerkin r = %d  e_y = %.3e' % (r, np.linalg.norm(Y - Yr) / np.linalg.norm(Y)))
