"""What examples/circuit_dae.c claims, checked on its CSV (make demo runs it):
the RLC ladder with capacitor-less nodes (index one) is simulated with
consistent states (the largest Kirchhoff residual at the algebraic nodes
<= 1e-12 of the largest current) and reduced by every method; every reduced
run completes; the training e_y falls with r for every method; at r = 18
GMG-POD and SP1 reach e_y <= 1e-3 on the training input and <= 2e-2 on the
unseen test input; GMG-QM with the validated lambda is never worse than
GMG-POD by more than the validation's admissible ratio (1.02)."""
import csv, math, os, sys

d = sys.argv[1] if len(sys.argv) > 1 else "results"
rows = list(csv.DictReader(open(os.path.join(d, "circuit_dae.csv"))))
kcl = [float(r["ey_train"]) for r in rows if r["method"] == "KCL"]
e = {(r["method"], int(r["r"])): (float(r["ey_train"]), float(r["ey_test"])) for r in rows if r["method"] != "KCL"}
bad = []
if len(kcl) != 1 or not kcl[0] <= 1e-12:
    bad.append("Kirchhoff residual at the algebraic nodes: %s (want <= 1e-12)" % kcl)
rs = (6, 10, 14, 18)
for k, (a, b) in sorted(e.items()):
    if not (0.0 < a < math.inf and 0.0 < b < math.inf):
        bad.append("%s r=%d: a reduced run failed (e_y %g, %g)" % (k[0], k[1], a, b))
for m in ("GMG-POD", "GMG-QM", "SP1", "SP2"):
    seq = [e.get((m, r), (math.nan, math.nan))[0] for r in rs]
    if not all(seq[i] > seq[i + 1] for i in range(len(seq) - 1)):
        bad.append("%s: training e_y does not fall with r: %s" % (m, seq))
for m in ("GMG-POD", "SP1"):
    a, b = e.get((m, 18), (math.nan, math.nan))
    if not a <= 1e-3:
        bad.append("%s r=18: training e_y %.3g > 1e-3" % (m, a))
    if not b <= 2e-2:
        bad.append("%s r=18: test e_y %.3g > 2e-2" % (m, b))
for r in rs:
    q, p = e.get(("GMG-QM", r)), e.get(("GMG-POD", r))
    if q and p and not q[0] <= 1.02 * p[0]:
        bad.append("GMG-QM r=%d: training e_y %.3g above 1.02 x GMG-POD's %.3g" % (r, q[0], p[0]))
if len(e) != 16:
    bad.append("expected 4 methods x 4 orders, got %d rows" % len(e))
for b in bad:
    print("check_circuit: FAIL " + b)
if bad:
    sys.exit(1)
print("check_circuit: %d reduced models of the index-one RLC ladder, claims hold" % len(e))
