#!/usr/bin/python3
"""Scaling model of the distributed offline phase (manual 2.7).

Reads the JSON of bench_mpi_phases (build/bench_mpi_phases) measured at P = 1
at two local sizes (to separate the per-row cost from the fixed cost) and at
P = 2 (the halo and the MPI calls by kind), and predicts the time of every
phase for N rows on P ranks (weak scaling: N / P rows per rank):

  time(P, n) = compute(n) + stack(P) + collectives(P) + halo(P, n),  n = N / P

  compute(n)     a + b n from the CPU times at P = 1 outside MPI calls and
                 the user's solves (compute_cpu): the per-row and the fixed
                 cost of each phase
  stack(P)       the replicated QR of the P stacked ns x ns factors of each
                 TSQR (one per allgather): 4 P w^3 flops for w columns, at
                 the flop rate of the measured TSQR (6 ns^2 flops per row)
  collectives    per call, with latency alpha and inverse bandwidth beta:
                 allreduce, reduce, bcast (binomial tree): log2(P) (alpha +
                 beta bytes); allgather (recursive doubling): log2(P) alpha
                 + (P - 1) beta bytes -- the bytes received grow with P;
                 alltoall(v) (pairwise): (P - 1) alpha + beta bytes
  halo           per exchange: (neighbours) alpha + beta bytes, the bytes
                 per neighbour measured at P = 2 and scaled with the
                 lattice's boundary (2-D: sqrt(n), chain: constant)

The user's solves (phgmg_mpi_gmg_pod_linear's callback) are reported apart
and excluded from the efficiency. Memory per rank: the peak RSS of the
library's phases at P = 1 (fixed + per row) plus TSQR's replicated buffers,
(2 P + 3) ns^2 doubles.

  /usr/bin/python3 bench/mpi_scaling.py build/scal/*.json [--alpha 2e-6]
      [--bw 10e9] [--N 1e9] [--P 1000] [--alpha-local 1e-6] [--bw-local 5e9]
      [--same A.json B.json]
"""
import argparse
import json
import math
import sys

COLL = ("allreduce", "reduce", "bcast", "allgather", "alltoall", "alltoallv")


def load(paths):
    runs = []
    for p in paths:
        with open(p) as f:
            d = json.load(f)
        d["path"] = p
        d["ph"] = {q["name"]: q for q in d["phases"]}
        runs.append(d)
    return runs


def fit_compute(r1a, r1b):
    """Per phase (a, b): CPU seconds = a + b * nloc at P = 1 (solves removed)."""
    out = {}
    na, nb = r1a["nloc"], r1b["nloc"]
    for name in r1a["ph"]:
        ta = r1a["ph"][name]["compute_cpu"]
        tb = r1b["ph"][name]["compute_cpu"]
        b = (tb - ta) / (nb - na)
        if b < 0.0:   # noise on a phase of constant cost: no per-row part
            b, a = 0.0, 0.5 * (ta + tb)
        else:
            a = ta - b * na
            if a < 0.0:   # no measurable fixed part
                a, b = 0.0, tb / nb
        out[name] = (a, b)
    return out


def flop_rate(fit, ns):
    """Flops per second of the local Householder QR (TSQR: ~6 ns^2 flops per row)."""
    b = fit["tsqr"][1]
    return 6.0 * ns * ns / b if b > 0 else 1e9


def stack_time(ph, P, rate):
    """The replicated QR of the stacked factors of each TSQR allgather."""
    c, B = ph["calls"]["allgather"]
    if c == 0 or P == 1:
        return 0.0
    w = math.sqrt(B / c / 8.0)
    return c * 4.0 * (P - 1) * w ** 3 / rate


def coll_time(ph, P, alpha, beta, Pm, hscale=1.0):
    """The collectives of one phase on P ranks (counts from a run on Pm ranks;
    hscale: the halo's growth from the measured run, for the plan's indices)."""
    if P == 1:
        return 0.0
    L = math.log2(P)
    t = 0.0
    for k in ("allreduce", "reduce", "bcast"):
        c, B = ph["calls"][k]
        t += c * L * alpha + L * beta * B
    c, B = ph["calls"]["allgather"]
    t += c * L * alpha + (P - 1) * beta * B
    c, B = ph["calls"]["alltoall"]   # counts to every rank: bytes grow with P
    t += c * (P - 1) * alpha + beta * B / Pm * P
    c, B = ph["calls"]["alltoallv"]  # indices to the neighbours only
    t += c * (P - 1) * alpha + beta * B * hscale * min(P - 1, 2)
    return t


def halo_time(ph, P, alpha, beta, n, ref, lattice):
    """Halo exchanges: ref is the phase measured at P = 2 (one neighbour)."""
    if P == 1 or ph["exchanges"] == 0:
        return 0.0, 0.0
    nnb = min(P - 1, 2)
    per_nb = ref["exchange_bytes"] / ref["exchanges"]   # one neighbour, at the measured n
    scale = math.sqrt(n / ref["_nloc"]) if lattice == "2d" else 1.0
    bytes_ex = nnb * per_nb * scale
    return ph["exchanges"] * (nnb * alpha + beta * bytes_ex), bytes_ex


def predict(fit, runs_p2, P, n, alpha, beta, ns, lattice, rate, mem_fit):
    """Per phase: compute, stack, collectives, halo, solves (seconds)."""
    ref = max(runs_p2, key=lambda d: d["nloc"])
    rows = []
    for name, (a, b) in fit.items():
        ph = ref["ph"][name]
        ph["_nloc"] = ref["nloc"]
        comp = a + b * n
        st = stack_time(ph, P, rate)
        hs = math.sqrt(n / ref["nloc"]) if lattice == "2d" else 1.0
        co = coll_time(ph, P, alpha, beta, ref["P"], hs)
        ha, hb = halo_time(ph, P, alpha, beta, n, ph, lattice)
        rows.append(dict(name=name, compute=comp, stack=st, coll=co, halo=ha, halo_bytes=hb,
                         ncoll=sum(ph["calls"][k][0] for k in COLL),
                         ag_bytes=ph["calls"]["allgather"][1] * (P - 1)))
    mem = mem_fit[0] + mem_fit[1] * n + 8.0 * (2 * P + 3) * ns * ns / 2 ** 20
    return rows, mem


def totals(rows):
    comp = sum(r["compute"] + r["stack"] for r in rows)
    coll = sum(r["coll"] for r in rows)
    halo = sum(r["halo"] for r in rows)
    return comp, coll, halo, comp + coll + halo


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("json", nargs="+")
    ap.add_argument("--alpha", type=float, default=2e-6, help="latency per message [s] (2 us)")
    ap.add_argument("--bw", type=float, default=10e9, help="bandwidth per link [bytes/s] (10 GB/s)")
    ap.add_argument("--N", type=float, default=1e9)
    ap.add_argument("--P", type=int, default=1000)
    ap.add_argument("--alpha-local", type=float, default=1e-6, help="latency of this machine (shared memory)")
    ap.add_argument("--bw-local", type=float, default=5e9, help="bandwidth of this machine (shared memory)")
    ap.add_argument("--same", nargs=2, metavar=("A", "B"), help="check: the same collectives and bytes in A and B")
    o = ap.parse_args()
    runs = load(o.json)
    r1 = sorted([d for d in runs if d["P"] == 1], key=lambda d: d["nloc"])
    p2 = [d for d in runs if d["P"] == 2 and d["lattice"] == r1[0]["lattice"]]
    if len(r1) < 2 or not p2:
        sys.exit("mpi_scaling.py: need P = 1 at two local sizes and one P = 2 run")
    r1a, r1b = r1[0], r1[-1]
    ns, lattice = r1a["ns"], r1a["lattice"]
    fit = fit_compute(r1a, r1b)
    rate = flop_rate(fit, ns)
    mb = (r1b["rss_lib_mb"] - r1a["rss_lib_mb"]) / (r1b["nloc"] - r1a["nloc"])
    mem_fit = (r1a["rss_lib_mb"] - mb * r1a["nloc"], mb)
    alpha, beta = o.alpha, 1.0 / o.bw
    n = o.N / o.P

    print("## Fit at P = 1 (CPU seconds = a + b nloc; nloc %d and %d; %s lattice, ns = %d, r = %d)\n"
          % (r1a["nloc"], r1b["nloc"], lattice, ns, r1a["r"]))
    print("| phase | a [ms] | b [ns/row] | collectives | bytes/rank | halo exchanges |")
    print("|---|---|---|---|---|---|")
    ref = max(p2, key=lambda d: d["nloc"])
    for name, (a, b) in fit.items():
        ph = ref["ph"][name]
        print("| %s | %.2f | %.1f | %d | %d | %d |" % (name, 1e3 * a, 1e9 * b, ph["collectives"], ph["bytes"],
                                                     ph["exchanges"]))
    print("\nflop rate of the local QR: %.2f GFLOP/s; memory: %.1f MB + %.0f bytes per row (peak RSS of the "
          "library's phases at P = 1)\n" % (rate / 1e9, mem_fit[0], mem_fit[1] * 2 ** 20))

    print("## Prediction: N = %.3g on P = %d (n = %.3g rows per rank), alpha = %.3g us, %.3g GB/s\n"
          % (o.N, o.P, n, alpha * 1e6, o.bw / 1e9))
    rows, mem = predict(fit, p2, o.P, n, alpha, beta, ns, lattice, rate, mem_fit)
    print("| phase | compute [s] | stack QR [s] | collectives [s] (calls) | halo [s] | share of comm. |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        tot = r["compute"] + r["stack"] + r["coll"] + r["halo"]
        print("| %s | %.3f | %.4f | %.2e (%d) | %.2e | %.3f %% |" % (
            r["name"], r["compute"], r["stack"], r["coll"], r["ncoll"], r["halo"], 100 * (r["coll"] + r["halo"]) / tot))
    comp, coll, halo, tot = totals(rows)
    rows1, _ = predict(fit, p2, 1, n, alpha, beta, ns, lattice, rate, mem_fit)
    t1 = totals(rows1)[3]
    eff = t1 / tot
    solve = sum(r1b["ph"][k]["solve_cpu"] for k in r1b["ph"])
    print("\ntotal (without the user's solves): %.2f s = compute %.2f + collectives %.3g + halo %.3g" % (tot, comp, coll, halo))
    print("collectives: %.3f %% of the time (bar < 1 %%: %s); collectives + halo %.3f %%"
          % (100 * coll / tot, "met" if coll / tot < 0.01 else "NOT met", 100 * (coll + halo) / tot))
    print("weak-scaling efficiency P = 1 -> %d at %.3g rows per rank: %.1f %% (bar >= 90 %%: %s)"
          % (o.P, n, 100 * eff, "met" if eff >= 0.9 else "NOT met"))
    print("memory per rank: %.0f MB (of it TSQR's replicated buffers %.1f MB)" % (mem, 8.0 * (2 * o.P + 3) * ns * ns / 2 ** 20))
    print("user's solves (not modelled, excluded): %.3f s CPU at P = 1, nloc = %d" % (solve, r1b["nloc"]))
    ag = [r for r in rows if r["ag_bytes"] > 0]
    print("allgather bytes received per rank at P = %d: %s" % (
        o.P, ", ".join("%s %.1f MB" % (r["name"], r["ag_bytes"] / 1e6) for r in ag)))

    print("\n## Weak scaling at %.3g rows per rank\n" % n)
    print("| P | N | time [s] | collectives | halo | stack QR | efficiency | memory/rank [MB] |")
    print("|---|---|---|---|---|---|---|---|")
    for P in (1, 2, 8, 64, 256, 1000, 4000, 16000):
        rs, m = predict(fit, p2, P, n, alpha, beta, ns, lattice, rate, mem_fit)
        c, co, ha, t = totals(rs)
        st = sum(r["stack"] for r in rs)
        print("| %d | %.3g | %.2f | %.3f %% | %.3f %% | %.2f %% | %.1f %% | %.0f |"
              % (P, n * P, t, 100 * co / t, 100 * ha / t, 100 * st / t, 100 * t1 / t, m))

    print("\n## Against the measurements on this machine (alpha %.3g us, %.3g GB/s)\n" % (o.alpha_local * 1e6, o.bw_local / 1e9))
    print("| run | phase | calls by kind: predicted = measured | compute predicted / measured [s] | communication predicted / measured wall in MPI [s] |")
    print("|---|---|---|---|---|")
    for d in sorted([d for d in runs if d["P"] > 1 and d["lattice"] == lattice], key=lambda d: (d["P"], d["nloc"])):
        rs, _ = predict(fit, p2, d["P"], d["nloc"], o.alpha_local, 1.0 / o.bw_local, ns, lattice, rate, mem_fit)
        okall = True
        for r in rs:
            ph = d["ph"][r["name"]]
            refph = ref["ph"][r["name"]]
            ok = True
            for k in COLL:
                c, B = refph["calls"][k]
                Bp = B / ref["P"] * d["P"] if k == "alltoall" else B
                if ph["calls"][k][0] != c or abs(ph["calls"][k][1] - Bp) > 0.5:
                    ok = (k == "alltoallv" and ph["calls"][k][0] == c)   # index bytes follow the halo
                    if not ok:
                        break
            okall = okall and ok
            pred = r["compute"] + r["stack"]
            print("| P=%d n=%d | %s | %s | %.4f / %.4f | %.2e / %.2e |" % (
                d["P"], d["nloc"], r["name"], "yes" if ok else "NO", pred, ph["compute_cpu"],
                r["coll"] + r["halo"], ph["mpi_wall"]))
        print("| P=%d n=%d | all | %s | | |" % (d["P"], d["nloc"], "yes" if okall else "NO"))

    if o.same:
        a, b = load(o.same)
        print("\n## Communication independent of N: %s (N = %d) and %s (N = %d)\n" % (a["path"], a["N"], b["path"], b["N"]))
        print("| phase | collectives | bytes | halo exchanges | halo bytes | identical |")
        print("|---|---|---|---|---|---|")
        for name in a["ph"]:
            x, y = a["ph"][name], b["ph"][name]
            same = all(x[k] == y[k] for k in ("collectives", "bytes", "exchanges")) and x["calls"] == y["calls"]
            print("| %s | %d / %d | %d / %d | %d / %d | %d / %d | %s |" % (
                name, x["collectives"], y["collectives"], x["bytes"], y["bytes"], x["exchanges"], y["exchanges"],
                x["exchange_bytes"], y["exchange_bytes"], "yes" if same else "NO"))


if __name__ == "__main__":
    main()
