#!/usr/bin/env python3
"""Checks the paper's qualitative claims (Section 5) on the CSVs written by
`make demo` (issue 5 acceptance):
  - linear: GMG-POD below SP1-POD in e_red and e_y at every r;
  - both examples: GMG-QM <= GMG-POD (within 2 %) in e_red and e_y at every r;
  - nonlinear: GMG-POD's e_y below SP2-POD's at every r;
  - nonlinear, r = 16: every ROM's max energy error within 10x of the FOM's.
Issue 5, automatic lambda (results/linear_<sin|const>_lambda_auto.csv from
`msd_linear --lambda auto`):
  - linear, both inputs, every r = 6..20 present: GMG-QM with the automatic
    lambda has e_red <= GMG-POD / 1.5, and no Newton failures.
usage: check_claims.py RESULTS_DIR ; exit status 1 if a claim fails."""
import csv, math, sys

d = sys.argv[1] if len(sys.argv) > 1 else "results"
fails = 0
checks = 0

def load(name):
    with open(f"{d}/{name}") as f:
        rows = list(csv.reader(f))
    head = rows[0]
    return {h: [float(r[i]) for r in rows[1:]] for i, h in enumerate(head)}

def claim(ok, text):
    global fails, checks
    checks += 1
    if not ok:
        fails += 1
        print("FAIL  " + text)

for ex, sp in (("linear", "SP1-POD"), ("nonlinear", "SP2-POD")):
    for inp in ("sin", "const"):
        for q in ("e_red", "e_y"):
            t = load(f"{ex}_{inp}_{q}.csv")
            for k, r in enumerate(t["r"]):
                pod, qm, spv = t["GMG-POD"][k], t["GMG-QM"][k], t[sp][k]
                if ex == "linear" or q == "e_y":
                    claim(pod < spv, f"{ex} {inp} {q} r={int(r)}: GMG-POD {pod:.3e} < {sp} {spv:.3e}")
                claim(qm <= 1.02 * pod, f"{ex} {inp} {q} r={int(r)}: GMG-QM {qm:.3e} <= 1.02 GMG-POD {pod:.3e}")
    if ex == "nonlinear":
        for inp in ("sin", "const"):
            t = load(f"nonlinear_{inp}_energy.csv")
            fom = max(t["FOM"])
            for m in ("SP2-POD", "GMG-POD", "GMG-QM"):
                e = max(v for v in t[m] if not math.isnan(v))
                claim(e <= 10 * fom, f"nonlinear {inp} energy r=16: {m} {e:.3e} within 10x of FOM {fom:.3e}")
for inp in ("sin", "const"):
    t = load(f"linear_{inp}_lambda_auto.csv")
    rs = [int(r) for r in t["r"]]
    claim(all(r in rs for r in range(6, 21)), f"linear {inp} lambda auto: rows for every r = 6..20 (got {rs})")
    for k, r in enumerate(rs):
        if not 6 <= r <= 20:
            continue
        pod, qm, nf = t["GMG-POD"][k], t["GMG-QM-auto"][k], t["newton_failures"][k]
        claim(qm <= pod / 1.5, f"linear {inp} r={r}: GMG-QM-auto {qm:.3e} <= GMG-POD/1.5 {pod / 1.5:.3e}")
        claim(nf == 0, f"linear {inp} r={r}: GMG-QM-auto Newton failures {nf:g} == 0")
print(f"paper claims: {checks - fails} of {checks} hold")
sys.exit(1 if fails else 0)
