# a chain of n masses as an FE code assembles it: element by element, triplets with duplicates
import numpy as np, scipy.sparse as sp
n = 200; N = 2 * n
rows, cols, vals = [], [], []
for e in range(n):                     # stiffness of spring e between masses e-1 and e (fixed at the left)
    for a in (e - 1, e):
        for b in (e - 1, e):
            if a >= 0 and b >= 0:
                rows.append(a); cols.append(b); vals.append(1.0 if a == b else -1.0)
K = sp.coo_matrix((vals, (rows, cols)), shape=(n, n))          # duplicates on the diagonal: summed later
Q = sp.block_diag([K, sp.identity(n) / 2.0])                    # positions, momenta (mass 2)
J = sp.bmat([[None, sp.identity(n)], [-sp.identity(n), None]])
R = sp.block_diag([sp.csr_matrix((n, n)), 0.5 * sp.identity(n)])
sp.save_npz("Q.npz", Q.tocoo(), compressed=True)                # coo with its duplicates
sp.save_npz("J.npz", J.tocsr()); sp.save_npz("R.npz", R.tocsc())
B = np.zeros(N); B[n + n - 1] = 1.0                             # a force on the last mass
np.save("B.npy", B)
print("N = %d, Q: %d triplets (%d after summing duplicates)" % (N, K.nnz + n, Q.tocsr().nnz))
