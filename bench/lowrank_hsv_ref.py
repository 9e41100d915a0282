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

exe, work = sys.argv[1], sys.argv[2]
sizes = (int(sys.argv[3]), int(sys.argv[4])) if len(sys.argv) > 4 else (40, 28)
for kind, n in zip(("heat", "lattice"), sizes):
    d = os.path.join(work, "%s%d" % (kind, n))
    N, trip, B = lm.model(kind, n)
    os.makedirs(d, exist_ok=True)
    for nm, t in zip("JRQ", trip):
        np.save(os.path.join(d, nm + ".npy"), t)
    np.save(os.path.join(d, "B.npy"), B)
    subprocess.run([exe, "reduce", "--J-coo", d + "/J.npy", "--R-coo", d + "/R.npy", "--Q-coo", d + "/Q.npy",
                    "--B", d + "/B.npy", "--method", "bt", "--r", "20", "--out", d, "--name", "bt", "--quiet"],
                   check=True)
    s = np.array(json.load(open(os.path.join(d, "bt.json")))["info"]["hankel_singular_values"])
    J, R, Q = (lm.dense(N, t) for t in trip)
    A, C = (J - R) @ Q, B.T @ Q
    c0 = time.process_time()
    P = sla.solve_continuous_lyapunov(A, -B @ B.T)
    O = sla.solve_continuous_lyapunov(A.T, -C.T @ C)

    def fac(X):
        w, U = np.linalg.eigh((X + X.T) / 2)
        return U * np.sqrt(np.maximum(w, 0))
    ref = np.linalg.svd(fac(O).T @ fac(P), compute_uv=False)
    print("%s n=%d N=%d: max_{i<=25} |sigma_i - ref_i| / sigma_1 = %.2e (SciPy dense %.1f s CPU)" %
          (kind, n, N, np.abs(s[:25] - ref[:25]).max() / ref[0], time.process_time() - c0))
