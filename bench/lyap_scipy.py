"""SciPy's solve_continuous_lyapunov (Bartels-Stewart: real Schur + trsyl) on
the matrices bench/bench_lyap.c wrote, and the LAPACK/BLAS kernels at the same
order (bench/README.md, "Dense Lyapunov").

  /usr/bin/python3 bench/lyap_scipy.py DIR [RUNS]      # DIR/A.npy, DIR/F.npy
  /usr/bin/python3 bench/lyap_scipy.py --kernels N [RUNS]

Run with OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 (one thread). Prints the
median CPU time (time.process_time) of RUNS (default 3) solves and the relative
residual ||A X + X A^T + F||_F / (2 ||A||_F ||X||_F + ||F||_F) (the formula of
phgmg_lyap_residual); with --kernels the GFLOP/s of dgemm, dgetrf, the inverse
(dgetrf + dgetri) and the pieces of Bartels-Stewart (real Schur with vectors,
trsyl, the two back transformations)."""
import sys
import time

import numpy as np
import scipy.linalg as sl


def cpu_median(fn, runs):
    """Median CPU seconds of runs calls of fn."""
    t = []
    for _ in range(runs):
        t0 = time.process_time()
        fn()
        t.append(time.process_time() - t0)
    return float(np.median(t))


def solve(d, runs):
    """Times solve_continuous_lyapunov(A, -F) on DIR's matrices."""
    A = np.load(d + "/A.npy")
    F = np.load(d + "/F.npy")
    n = A.shape[0]
    X = sl.solve_continuous_lyapunov(A, -F)
    t = cpu_median(lambda: sl.solve_continuous_lyapunov(A, -F), runs)
    res = np.linalg.norm(A @ X + X @ A.T + F) / (2 * np.linalg.norm(A) * np.linalg.norm(X) + np.linalg.norm(F))
    print("scipy_lyap n=%d cpu_median=%.3f s (%d runs) residual=%.2e" % (n, t, runs, res))


def kernels(n, runs):
    """GFLOP/s of the BLAS/LAPACK kernels at order n, and Bartels-Stewart's parts."""
    rng = np.random.default_rng(1)
    A = np.asfortranarray(rng.random((n, n)) - 0.5 + 4 * np.eye(n))
    B = np.asfortranarray(rng.random((n, n)) - 0.5)
    n3 = float(n) ** 3
    rows = [("dgemm", 2.0, lambda: A @ B),
            ("dgetrf", 2.0 / 3.0, lambda: sl.lu_factor(A)),
            ("inverse", 2.0, lambda: sl.inv(A))]
    for name, fl, fn in rows:
        t = cpu_median(fn, runs)
        print("%-10s n=%d cpu_median=%.4f s  %.2f GFLOP/s" % (name, n, t, fl * n3 / t * 1e-9))
    T, U = sl.schur(A)
    trsyl = sl.get_lapack_funcs("trsyl", (T,))
    F = B + B.T
    parts = [("schur", lambda: sl.schur(A)),
             ("UtFU", lambda: U.T @ F @ U),
             ("trsyl", lambda: trsyl(T, T.T, U.T @ F @ U, tranb="T")),
             ("UYUt", lambda: U @ F @ U.T)]
    for name, fn in parts:
        print("%-10s n=%d cpu_median=%.4f s" % (name, n, cpu_median(fn, runs)))


def main():
    if len(sys.argv) >= 3 and sys.argv[1] == "--kernels":
        kernels(int(sys.argv[2]), int(sys.argv[3]) if len(sys.argv) > 3 else 3)
    elif len(sys.argv) >= 2:
        solve(sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 3)
    else:
        print(__doc__)
        sys.exit(2)


if __name__ == "__main__":
    main()
