"""Hankel singular values of `phgmg reduce --method bt` (low-rank solvers, COO input) against a
dense reference: SciPy's solve_continuous_lyapunov for both Gramians, sigma = the singular values
of Lo^T Lp (P = Lp Lp^T, O = Lo Lo^T by eigh). The models of bench/lowrank_models.py.

    OPENBLAS_NUM_THREADS=1 /usr/bin/python3 bench/lowrank_hsv_ref.py build/phgmg WORKDIR [HEAT_N LATTICE_N]

(defaults 40 and 28: N = 1 600 and 1 568). Prints max_{i <= 25} |sigma_i - ref_i| / sigma_1."""
import json, os, subprocess, sys, time
import numpy as np
import scipy.linalg as sla

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import lowrank_models as lm   # noqa: E402


def reduce_bt(exe, work, kind, n):
    """The scrambled model written to WORK/KINDn and `phgmg reduce --method bt --r 20` run on
    it: (N, its Hankel singular values)."""
    d = os.path.join(work, "%s%d" % (kind, n))
    N, trip, B = lm.model(kind, n)
    os.makedirs(d, exist_ok=True)
    for nm, t in zip("JRQ", trip):
        np.save(os.path.join(d, nm + ".npy"), t)
    np.save(os.path.join(d, "B.npy"), B)
    subprocess.run([exe, "reduce", "--J-coo", d + "/J.npy", "--R-coo", d + "/R.npy", "--Q-coo", d + "/Q.npy",
                    "--B", d + "/B.npy", "--method", "bt", "--r", "20", "--out", d, "--name", "bt", "--quiet"],
                   check=True)
    return N, np.array(json.load(open(os.path.join(d, "bt.json")))["info"]["hankel_singular_values"])


def dense_reference(kind, n):
    """The Hankel singular values from SciPy's dense Lyapunov solutions (sigma = the singular
    values of Lo^T Lp, P = Lp Lp^T, O = Lo Lo^T by eigh)."""
    N, trip, B = lm.model(kind, n)
    J, R, Q = (lm.dense(N, t) for t in trip)
    A, C = (J - R) @ Q, B.T @ Q
    P = sla.solve_continuous_lyapunov(A, -B @ B.T)
    O = sla.solve_continuous_lyapunov(A.T, -C.T @ C)

    def fac(X):
        w, U = np.linalg.eigh((X + X.T) / 2)
        return U * np.sqrt(np.maximum(w, 0))
    return np.linalg.svd(fac(O).T @ fac(P), compute_uv=False)


def main(argv):
    exe, work = argv[0], argv[1]
    sizes = (int(argv[2]), int(argv[3])) if len(argv) > 3 else (40, 28)
    for kind, n in zip(("heat", "lattice"), sizes):
        N, s = reduce_bt(exe, work, kind, n)
        c0 = time.process_time()
        ref = dense_reference(kind, n)
        print("%s n=%d N=%d: max_{i<=25} |sigma_i - ref_i| / sigma_1 = %.2e (SciPy dense %.1f s CPU)" %
              (kind, n, N, np.abs(s[:25] - ref[:25]).max() / ref[0], time.process_time() - c0))


if __name__ == "__main__":
    main(sys.argv[1:])
