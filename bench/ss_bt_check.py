"""The sampled H-infinity error of a state-space BT model written by
`phgmg reduce --method bt --form ss` against its sparse descriptor model.

  /usr/bin/python3 bench/ss_bt_check.py MODEL_DIR OUT_DIR/NAME [--nw 200] [--wmin 1e-2] [--wmax 1e2]

MODEL_DIR holds the COO files J.npy, R.npy, Q.npy, E.npy ((nnz, 3) triplets)
and B.npy (bench/fe_mesh.py, bench/rlc_grid.py); OUT_DIR/NAME_A.npy ...
NAME_D.npy and NAME.json are the reduced model and its record. At each of nw
log-spaced frequencies w the full transfer function G(iw) = C (iw E - A)^{-1} B
(A = (J - R) Q, C = B^T Q; the whole pencil, algebraic lines included) is
evaluated by SciPy's sparse LU (splu) and compared with
G_r(iw) = C_r (iw I - A_r)^{-1} B_r + D_r in the spectral norm. Prints the
largest error, where it is, max ||G||, and the record's bound
2 sum_{i>r} sigma_i; exit 1 if the sampled error exceeds the bound."""
import json, os, sys, time
import numpy as np
import scipy.sparse as sps
import scipy.sparse.linalg as spla


def coo(path, N):
    t = np.load(path)
    return sps.csc_matrix((t[:, 2], (t[:, 0].astype(int), t[:, 1].astype(int))), shape=(N, N))


def main(argv):
    opt = {"--nw": "200", "--wmin": "1e-2", "--wmax": "1e2"}
    for k in list(opt):
        if k in argv:
            i = argv.index(k)
            opt[k] = argv[i + 1]
            argv = argv[:i] + argv[i + 2:]
    d, pre = argv[0], argv[1]
    B = np.load(os.path.join(d, "B.npy"))
    if B.ndim == 1:
        B = B[:, None]
    N = B.shape[0]
    J, R, Q, E = (coo(os.path.join(d, n + ".npy"), N) for n in "JRQE")
    A = ((J - R) @ Q).tocsc()
    C = (Q.T @ B).T
    Ar, Br, Cr, Dr = (np.load("%s_%s.npy" % (pre, f)) for f in "ABCD")
    info = json.load(open(pre + ".json"))["info"]
    r = Ar.shape[0]
    W = np.logspace(np.log10(float(opt["--wmin"])), np.log10(float(opt["--wmax"])), int(opt["--nw"]))
    e, we, gmax, t0 = 0.0, 0.0, 0.0, time.process_time()
    for w in W:
        G = C @ spla.splu((1j * w * E - A).tocsc()).solve(B.astype(complex))
        Gr = Cr @ np.linalg.solve(1j * w * np.eye(r) - Ar, Br) + Dr
        ew = np.linalg.norm(G - Gr, 2)
        gmax = max(gmax, np.linalg.norm(G, 2))
        if ew > e:
            e, we = ew, w
    bound = info["error_bound"]
    s = info["hankel_singular_values"]
    print("N = %d, m = %d, r = %d; Hankel singular values %s ... sigma_r = %.4g, sigma_{r+1} = %.4g" %
          (N, B.shape[1], r, " ".join("%.4g" % v for v in s[:5]), s[-1], info["hsv_next"]))
    print("Gramian ranks %s, ADI steps %s, Lyapunov residuals %s, values computed %d, max|D| %.3g" %
          (info["gramian_rank"], info["adi_steps"], info["lyapunov_residual"], info["values_computed"],
           info["feedthrough_max"]))
    print("sampled H-infinity error %.4g (at w = %.4g) within the bound %.4g: %s; max ||G(iw)|| = %.4g "
          "(%d frequencies in [%s, %s], %.1f s CPU)" % (e, we, bound, "yes" if e <= bound else "NO", gmax, len(W),
                                                        opt["--wmin"], opt["--wmax"], time.process_time() - t0))
    return 0 if e <= bound else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
