"""What examples/damped_chain.c claims, checked on its CSV (make demo runs it):
the chain with a cubic damper on every mass is reduced by GMG-POD, SP1 and
SP2; every reduced run completes; every reduced model's discrete energy
balance (with the dampers' dissipation) holds to 1e-9 of its energy; the
training e_y falls with r for every method, and the test e_y at the largest
r is below that at the smallest."""
import csv, math, os, sys

d = sys.argv[1] if len(sys.argv) > 1 else "results"
rows = list(csv.DictReader(open(os.path.join(d, "damped_chain.csv"))))
bad = []
meths = sorted(set(r["method"] for r in rows))
for m in meths:
    rr = sorted((int(r["r"]), float(r["ey_train"]), float(r["ey_test"]), float(r["energy"])) for r in rows if r["method"] == m)
    for r, a, b, e in rr:
        if not (0.0 < a < math.inf and 0.0 < b < math.inf):
            bad.append("%s r=%d: a reduced run failed (e_y %g, %g)" % (m, r, a, b))
        if not (0.0 <= e <= 1e-9):
            bad.append("%s r=%d: energy balance off by %g of the energy" % (m, r, e))
    tr = [x[1] for x in rr]
    if not all(tr[i] > tr[i + 1] for i in range(len(tr) - 1)):
        bad.append("%s: training e_y does not fall with r: %s" % (m, tr))
    if not rr[-1][2] < rr[0][2]:
        bad.append("%s: test e_y at r=%d (%g) not below r=%d (%g)" % (m, rr[-1][0], rr[-1][2], rr[0][0], rr[0][2]))
if meths != ["GMG-POD", "SP1", "SP2"] or len(rows) != 12:
    bad.append("expected GMG-POD, SP1, SP2 x 4 orders, got %s, %d rows" % (meths, len(rows)))
for b in bad:
    print("check_damped: FAIL " + b)
if bad:
    sys.exit(1)
print("check_damped: %d reduced models of the chain with nonlinear dampers, claims hold" % len(rows))
