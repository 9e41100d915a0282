#!/usr/bin/python3
"""make_model.py -- the paper's linear mass-spring-damper chain as .npy files.

Usage: /usr/bin/python3 make_model.py OUTDIR [--masses 50]

Builds, with NumPy only, the port-Hamiltonian model of paper Section 5.2
(the same realisation as examples/msd_models.h, msd_linear_build):
  n masses m_i = 2, springs k_i = 1 (spring i joins masses i and i+1, the
  last mass is tied to the wall), dampers c_i = 1, a force on mass 1;
  state x = (q1, p1, q2, p2, ...), N = 2n (n = 50 gives N = 100);
  J = blockdiag([0 1; -1 0]), R = diag(0, c1, 0, c2, ...), B = e_2,
  H(x) = 1/2 x^T Q x with Q(q_i,q_i) = k_{i-1} + k_i (k_0 = 0),
  Q(q_i,q_{i+1}) = Q(q_{i+1},q_i) = -k_i, Q(p_i,p_i) = 1/m_i.
Writes OUTDIR/J.npy, R.npy, B.npy (N x 1), Q.npy (float64, np.save's C order)
and prints N and the checks J = -J^T, R = R^T >= 0, Q = Q^T > 0.
"""
import os
import sys

import numpy as np


def msd_linear(n, m=2.0, k=1.0, c=1.0):
    N = 2 * n
    J = np.zeros((N, N))
    R = np.zeros((N, N))
    Q = np.zeros((N, N))
    B = np.zeros((N, 1))
    for i in range(n):
        q, p = 2 * i, 2 * i + 1
        J[q, p], J[p, q] = 1.0, -1.0
        R[p, p] = c
        Q[q, q] = (k if i > 0 else 0.0) + k
        Q[p, p] = 1.0 / m
        if i + 1 < n:
            Q[q, q + 2] = Q[q + 2, q] = -k
    B[1, 0] = 1.0
    return J, R, B, Q


def main(argv):
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print(__doc__)
        return 2 if len(argv) < 2 else 0
    out, n = argv[1], 50
    if len(argv) == 4 and argv[2] == "--masses":
        n = int(argv[3])
    elif len(argv) != 2:
        print(__doc__)
        return 2
    J, R, B, Q = msd_linear(n)
    assert np.array_equal(J, -J.T) and np.array_equal(R, R.T) and np.array_equal(Q, Q.T)
    assert np.linalg.eigvalsh(R).min() >= 0.0 and np.linalg.eigvalsh(Q).min() > 0.0
    os.makedirs(out, exist_ok=True)
    for name, A in (("J", J), ("R", R), ("B", B), ("Q", Q)):
        np.save(os.path.join(out, name + ".npy"), A)
    print("linear MSD: %d masses, N = %d, m = 1; wrote %s/{J,R,B,Q}.npy" % (n, 2 * n, out))
    print("  J skew, R symmetric PSD, Q symmetric positive definite (lambda_min(Q) = %.3e)"
          % np.linalg.eigvalsh(Q).min())
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
