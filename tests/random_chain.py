#!/usr/bin/env python3
import numpy as np, sys, os
# random_chain.py SEED OUTDIR [MASSES (150)]: a mass-spring-damper chain with random masses, stiffnesses and damping, its
# states in a random order (a model no test was written for)
seed, out = int(sys.argv[1]), sys.argv[2]
rng = np.random.default_rng(seed); os.makedirs(out, exist_ok=True)
n = int(sys.argv[3]) if len(sys.argv) > 3 else 150; N = 2 * n
k = rng.uniform(0.1, 10, n); mm = rng.uniform(0.1, 10, n); c = rng.uniform(0, 2, n)
J = np.zeros((N, N)); R = np.zeros((N, N)); Q = np.zeros((N, N))
for i in range(n):
    q, p = 2 * i, 2 * i + 1
    J[q, p] = 1; J[p, q] = -1
    if i + 1 < n: J[2 * (i + 1), p] = -1; J[p, 2 * (i + 1)] = 1
    R[p, p] = c[i]; Q[q, q] = k[i]; Q[p, p] = 1 / mm[i]
P = rng.permutation(N)
B = rng.standard_normal((N, 1))
for nm, M in (("J", J[np.ix_(P, P)]), ("R", R[np.ix_(P, P)]), ("Q", Q[np.ix_(P, P)]), ("B", B)):
    np.save(os.path.join(out, nm + ".npy"), M)
