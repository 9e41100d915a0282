"""A power-grid-like RLC network in nodal form: an index-one port-Hamiltonian DAE.

    /usr/bin/python3 rlc_grid.py DIR [--n 40] [--seed 1] [--port-on-constraint]
                                     [--no-scramble] [--dense] [--dt 0.02] [--steps 1000]

n x n main nodes; on every edge of the grid (a, b) a resistor from a to a mid
node and an inductor from the mid node to b; a shunt conductance from every
main node to ground (a load); a capacitor on the main nodes with i + j even.
States x = (node voltages, inductor currents), Q = I, H = x^T E x / 2,
E = diag(C on the capacitive mains, 0 on the other mains and the mid nodes,
L on the inductors):
    C_a v_a' = -g_e (v_a - v_m) - g_s v_a + sum of inductor currents into a + u
          0  =  g_e (v_a - v_m) - i_e                       (mid node m: algebraic)
    L_e i_e' =  v_m - v_b
i.e. E x' = (J - R) x + B u with J the incidence of the inductors (skew), R the
conductance Laplacian plus the shunts. The mains without capacitor and the
mid nodes are algebraic (zero rows and columns of E); the shunts make the
algebraic block -R_aa nonsingular (index one). Ports (current sources,
outputs the node voltages): port 0 at main (0, 0) (a capacitor), port 1 at
main (n-1, n-1) (i + j even: a capacitor), or with --port-on-constraint at
main (0, 1) (no capacitor: a port on a constraint, feedthrough after
condensation). Element values uniform in [0.5, 1.5], shunts in [0.05, 0.15].

Scrambled (default): the equations (rows) by a random permutation Pr and the
states (columns of E and Q) by another, Pc: J' = Pr J Pr^T, R' = Pr R Pr^T,
Q' = Pr Q Pc, E' = Pr E Pc, B' = Pr B (the same dynamics for x' = Pc^T x).

Writes DIR/J.npy, R.npy, Q.npy, E.npy (coordinate triplets, (nnz, 3)),
B.npy (N x 2), chirp.npy (the input table for --input: times and one chirp
per port, sampled at dt/16 up to steps dt) and with --dense the dense
matrices Jd.npy, Rd.npy, Qd.npy, Ed.npy. Prints N and the algebraic count."""
import sys

import os
import numpy as np
import scipy.sparse as sps


def build(n, seed, port_on_constraint):
    rng = np.random.default_rng(seed)
    main = lambda i, j: i * n + j
    edges = [(main(i, j), main(i, j + 1)) for i in range(n) for j in range(n - 1)]
    edges += [(main(i, j), main(i + 1, j)) for i in range(n - 1) for j in range(n)]
    nm, ne = n * n, len(edges)
    N = nm + 2 * ne
    e = np.zeros(N)
    rows, cols, vals = [], [], []          # J
    rr, rc, rv = [], [], []                # R
    for k, (a, b) in enumerate(edges):
        m, il = nm + k, nm + ne + k
        g = 1.0 / rng.uniform(0.5, 1.5)
        rr += [a, a, m, m]; rc += [a, m, a, m]; rv += [g, -g, -g, g]
        rows += [m, il, b, il]; cols += [il, m, il, b]; vals += [-1.0, 1.0, 1.0, -1.0]
        e[il] = rng.uniform(0.5, 1.5)
    for i in range(n):
        for j in range(n):
            a = main(i, j)
            rr.append(a); rc.append(a); rv.append(rng.uniform(0.05, 0.15))
            if (i + j) % 2 == 0:
                e[a] = rng.uniform(0.5, 1.5)
    J = sps.csr_matrix((vals, (rows, cols)), shape=(N, N))
    R = sps.csr_matrix((rv, (rr, rc)), shape=(N, N))
    B = np.zeros((N, 2))
    B[main(0, 0), 0] = 1.0
    B[main(0, 1) if port_on_constraint else main(n - 1, n - 1), 1] = 1.0
    return J, R, sps.identity(N, format="csr"), sps.diags(e).tocsr(), B


def save_coo(path, M):
    M = sps.coo_matrix(M)
    np.save(path, np.column_stack([M.row, M.col, M.data]).astype(float))


def main_(argv):
    if not argv or argv[0] in ("-h", "--help"):
        print(__doc__)
        return
    d = argv[0]
    opt = {"--n": 40, "--seed": 1, "--dt": 0.02, "--steps": 1000}
    for k in opt:
        if k in argv:
            opt[k] = type(opt[k])(argv[argv.index(k) + 1])
    J, R, Q, E, B = build(opt["--n"], opt["--seed"], "--port-on-constraint" in argv)
    N = B.shape[0]
    if "--no-scramble" not in argv:
        rng = np.random.default_rng(opt["--seed"] + 1000)
        pr, pc = rng.permutation(N), rng.permutation(N)
        Pr = sps.csr_matrix((np.ones(N), (np.arange(N), pr)), shape=(N, N))   # (Pr x)_i = x[pr[i]]
        Pc = sps.csr_matrix((np.ones(N), (pc, np.arange(N))), shape=(N, N))
        J, R, Q, E, B = Pr @ J @ Pr.T, Pr @ R @ Pr.T, Pr @ Q @ Pc, Pr @ E @ Pc, Pr @ B
    os.makedirs(d, exist_ok=True)
    for name, M in (("J", J), ("R", R), ("Q", Q), ("E", E)):
        save_coo("%s/%s.npy" % (d, name), M)
        if "--dense" in argv:
            np.save("%s/%sd.npy" % (d, name), M.toarray())
    np.save(d + "/B.npy", B)
    T = opt["--dt"] * opt["--steps"]
    t = np.arange(0.0, T + opt["--dt"], opt["--dt"] / 16.0)
    u0 = 0.1 * np.sin(2 * np.pi * (0.05 * t + 0.02 * t * t))          # chirps 0.05 -> 0.05 + 0.04 T Hz
    u1 = 0.1 * np.sin(2 * np.pi * (0.2 * t + 0.01 * t * t) + 0.3)
    np.save(d + "/chirp.npy", np.column_stack([t, u0, u1]))
    zr = int(np.sum(np.abs(E).sum(axis=1) == 0))
    print("N = %d, algebraic = %d" % (N, zr))


if __name__ == "__main__":
    main_(sys.argv[1:])
