#!/usr/bin/python3
"""compare.py -- the full model's response in Python against a phgmg reduced model.

Usage:
  /usr/bin/python3 compare.py --model DIR --rom-y y_rom.npy
        [--dt 0.1] [--steps 1000] [--input sin|const] [--amp 0.1]
        [--fom-y fom_y.npy] [--V0 V0.npy --rom-x xr.npy] [--check-fom TOL]

Reads the full model DIR/{J,R,B,Q}.npy (x' = (J - R) Q x + B u, y = B^T Q x,
x(0) = 0) and computes its output on the grid t_n = n dt, n = 0..steps, with
NumPy only, *exactly* up to rounding: in the eigenbasis of A = (J - R) Q each
coordinate solves z' = lambda z + c u(t), whose solution for u = amp sin t and
u = amp is written in closed form (no time stepping). Then it prints the
relative output error of the reduced model's output y_rom (an m x (steps+1)
array written by `phgmg simulate-rom`):
    e_y = sqrt(sum_n |y_full(t_n) - y_rom(t_n)|^2 / sum_n |y_full(t_n)|^2).
Options:
  --fom-y F      phgmg's own full-order simulation (NAME_fom_y.npy from
                 `phgmg reduce --simulate --save-snapshots`, Gauss-Legendre 3):
                 also prints its relative difference from the exact solution.
  --V0 F --rom-x F   the basis NAME_V0.npy and the reduced states (simulate-rom
                 --states): prints the relative state error of x ~ V0 xr
                 against the exact full state.
  --check-fom T  exit status 1 if that GL3-vs-exact difference exceeds T.
Exit status 0 on success, 1 on a failed check, 2 on bad usage.
"""
import argparse
import os
import sys

import numpy as np


def rel(a, b):
    return float(np.sqrt(np.sum((a - b) ** 2) / np.sum(a ** 2)))


def exact_response(J, R, B, Q, t, kind, amp):
    """States X (N x nt) and outputs Y (m x nt) of x' = (J-R)Q x + B u, x(0) = 0,
    by eigendecomposition: u_a(t) = amp sin(w_a t), w_a = 1 + a/m at port
    a = 0..m-1 (phgmg's sin; amp sin t for m = 1), or amp on every port."""
    A = (J - R) @ Q
    lam, V = np.linalg.eig(A)
    m = B.shape[1]
    L, T = lam[:, None], t[None, :]
    eL = np.exp(L * T)
    if kind == "sin":   # sin wt = (e^{iwt} - e^{-iwt}) / 2i
        Z = 0
        for a in range(m):
            c = np.linalg.solve(V, B[:, a])  # z' = lam z + c u_a(t)
            w = 1.0 + a / m
            zp = (np.exp(1j * w * T) - eL) / (1j * w - L)
            zm = (np.exp(-1j * w * T) - eL) / (-1j * w - L)
            Z = Z + amp * c[:, None] * (zp - zm) / 2j
    elif kind == "const":
        c = np.linalg.solve(V, B @ np.ones(m))
        Z = amp * c[:, None] * (eL - 1.0) / L
    else:
        raise ValueError(kind)
    X = np.real(V @ Z)
    return X, B.T @ Q @ X


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", required=True, help="directory with J.npy R.npy B.npy Q.npy")
    ap.add_argument("--rom-y", required=True, help="reduced output, m x (steps+1)")
    ap.add_argument("--dt", type=float, default=0.1)
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--input", default="sin", choices=("sin", "const"))
    ap.add_argument("--amp", type=float, default=0.1)
    ap.add_argument("--fom-y")
    ap.add_argument("--V0")
    ap.add_argument("--rom-x")
    ap.add_argument("--check-fom", type=float)
    a = ap.parse_args()
    M = {k: np.load(os.path.join(a.model, k + ".npy")) for k in ("J", "R", "B", "Q")}
    B = M["B"].reshape(M["J"].shape[0], -1)
    t = a.dt * np.arange(a.steps + 1)
    X, Y = exact_response(M["J"], M["R"], B, M["Q"], t, a.input, a.amp)
    yr = np.load(a.rom_y)
    if yr.shape != Y.shape:
        print("compare.py: %s has shape %s, expected %s" % (a.rom_y, yr.shape, Y.shape))
        return 1
    print("full model: N = %d, m = %d, %d steps of dt = %g, u = %s (exact solution)"
          % (X.shape[0], Y.shape[0], a.steps, a.dt,
             ("%g sin t" % a.amp) if a.input == "sin" else ("%g" % a.amp)))
    print("relative output error of the reduced model  e_y   = %.6e" % rel(Y, yr))
    status = 0
    if a.V0 and a.rom_x:
        Xr = np.load(a.V0) @ np.load(a.rom_x)
        print("relative state error (x ~ V0 xr)            e_red = %.6e" % rel(X, Xr))
    if a.fom_y:
        d = rel(Y, np.load(a.fom_y))
        print("phgmg's full-order GL3 output vs exact             = %.6e" % d)
        if a.check_fom is not None and not d <= a.check_fom:
            print("compare.py: FAILED: GL3 full-order output differs from the exact one by %.3e > %.1e"
                  % (d, a.check_fom))
            status = 1
    return status


if __name__ == "__main__":
    sys.exit(main())
