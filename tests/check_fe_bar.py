"""What examples/fe_bar.c claims, checked on its CSV (make demo runs it with
--n 200): the descriptor bar (consistent mass, scrambled sparse input) is
reduced by every method; every reduced run completes with a finite error;
GMG-POD and SP1 reach e_y <= 1e-2 on the training input at r = 20 and <= 2e-2
on the unseen test input, and their errors fall from r = 8 to 14 to 20 on
both; GMG-QM with the validated lambda is never worse than GMG-POD by more
than the validation's admissible ratio (1.02)."""
import csv
import math
import os
import sys

d = sys.argv[1] if len(sys.argv) > 1 else "results"
rows = list(csv.DictReader(open(os.path.join(d, "fe_bar.csv"))))
e = {(r["method"], int(r["r"])): (float(r["ey_train"]), float(r["ey_test"])) for r in rows}
bad = []
for k, (a, b) in sorted(e.items()):
    if not (0.0 < a < math.inf and 0.0 < b < math.inf):
        bad.append("%s r=%d: a reduced run failed (e_y %g, %g)" % (k[0], k[1], a, b))
for m in ("GMG-POD", "SP1"):
    if (m, 20) in e:
        if not e[(m, 20)][0] <= 1e-2:
            bad.append("%s r=20: training e_y %.3g > 1e-2" % (m, e[(m, 20)][0]))
        if not e[(m, 20)][1] <= 2e-2:
            bad.append("%s r=20: test e_y %.3g > 2e-2" % (m, e[(m, 20)][1]))
    for j in (0, 1):
        seq = [e.get((m, r), (math.nan, math.nan))[j] for r in (8, 14, 20)]
        if not (seq[0] > seq[1] > seq[2]):
            bad.append("%s: e_y (%s) does not fall with r: %s" % (m, "train test".split()[j], seq))
for r in (8, 14, 20):
    q, p = e.get(("GMG-QM", r)), e.get(("GMG-POD", r))
    if q and p and not q[0] <= 1.02 * p[0]:
        bad.append("GMG-QM r=%d: training e_y %.3g above 1.02 x GMG-POD's %.3g" % (r, q[0], p[0]))
if len(e) != 12:
    bad.append("expected 4 methods x 3 orders, got %d rows" % len(e))
for b in bad:
    print("check_fe_bar: FAIL " + b)
if bad:
    sys.exit(1)
print("check_fe_bar: %d reduced models of the descriptor bar, claims hold" % len(e))
