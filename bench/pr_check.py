"""Passivity of a reduced linear model written by `phgmg reduce`, checked
independently of the library: its pH structure and its Popov function on a
frequency grid.

    /usr/bin/python3 bench/pr_check.py DIR/NAME [NW [WMIN WMAX]]

reads NAME_K.npy, NAME_Qh.npy, NAME_Bh.npy (the model x' = K Qh x + Bh u,
y = Bh^T Qh x) and prints
  - the largest eigenvalue of K + K^T against the largest |eigenvalue|
    (<= 0 up to round-off: the dissipation inequality),
  - the smallest eigenvalue of Qh against its largest (> 0: the energy is
    positive definite),
  - min over NW frequencies w, log-spaced in [WMIN, WMAX] (default 6000 in
    [1e-3, 1e3]), of the smallest eigenvalue of G(iw) + G(iw)^H, relative to
    max ||G(iw)||_2 (>= 0 up to round-off: positive real), and where.
"""
import sys

import numpy as np


def main(argv):
    base = argv[0]
    nw = int(argv[1]) if len(argv) > 1 else 6000
    wmin, wmax = (float(argv[2]), float(argv[3])) if len(argv) > 3 else (1e-3, 1e3)
    K, Qh, Bh = (np.load('%s_%s.npy' % (base, s)) for s in ('K', 'Qh', 'Bh'))
    Bh = Bh.reshape(K.shape[0], -1)
    r, m = Bh.shape
    ek = np.linalg.eigvalsh(K + K.T)
    eq = np.linalg.eigvalsh(0.5 * (Qh + Qh.T))
    A, C = K @ Qh, Bh.T @ Qh
    worst, wat, gmax = np.inf, 0.0, 0.0
    for w in np.logspace(np.log10(wmin), np.log10(wmax), nw):
        G = C @ np.linalg.solve(1j * w * np.eye(r) - A, Bh)
        lam = np.linalg.eigvalsh(G + G.conj().T)[0]
        gmax = max(gmax, np.linalg.norm(G, 2))
        if lam < worst:
            worst, wat = lam, w
    print('model %s: r = %d, m = %d' % (base, r, m))
    print('max eig(K + K^T) / max |eig| = %.2e' % (ek[-1] / np.abs(ek).max()))
    print('min eig(Qh) / max eig(Qh)    = %.2e' % (eq[0] / eq[-1]))
    print('min over %d frequencies in [%g, %g] of min eig(G + G^H) / max ||G|| = %.2e (at w = %.4g)'
          % (nw, wmin, wmax, worst / gmax, wat))
    ok = ek[-1] <= 1e-12 * np.abs(ek).max() and eq[0] > 0 and worst >= -1e-12 * gmax
    print('passive: %s' % ('yes' if ok else 'NO'))
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
