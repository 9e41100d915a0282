#!/usr/bin/env python3
"""Checks the acceptance items of the Morse-chain example ("a new
example") on results/morse_errors.csv written by examples/morse_chain.c:
  - every reduced model was built and simulated (rc 0, finite errors) for
    every r = 6..20 step 2, every method (SP1-POD, SP2-POD, GMG-POD, GMG-QM),
    with DEIM and with every term kept;
  - zero Newton failures (training and test input; the models without DEIM
    see the test input only with morse_chain --all-terms-test);
  - errors decrease with r: GMG-POD and GMG-QM, with and without DEIM,
    e_red and e_y on the training input strictly decrease from each r to the
    next; every method's e_red and e_y at r = 20 are below those at r = 6;
  - GMG-POD's output error e_y is below SP2-POD's at every r (training input,
    with and without DEIM);
  - every reduced model's maximum energy-balance error is within 10x of the
    full model's on the same input (training and test input).
usage: check_morse.py RESULTS_DIR ; exit status 1 if an item fails."""
import csv, math, sys

d = sys.argv[1] if len(sys.argv) > 1 else "results"
fails = 0
checks = 0


def claim(ok, text):
    global fails, checks
    checks += 1
    if not ok:
        fails += 1
        print("FAIL  " + text)


with open(f"{d}/morse_errors.csv") as f:
    rows = list(csv.DictReader(f))
fom = [r for r in rows if r["method"] == "FOM"]
claim(len(fom) == 1, "morse: one FOM row")
fom_en, fom_en_test = float(fom[0]["energy"]), float(fom[0]["energy_test"])
rom = {(int(r["r"]), r["method"], int(r["deim"])): r for r in rows if r["method"] != "FOM"}
methods = ("SP1-POD", "SP2-POD", "GMG-POD", "GMG-QM")
rs = list(range(6, 21, 2))
missing = [(r, m, dd) for r in rs for m in methods for dd in (0, 1) if (r, m, dd) not in rom]
claim(not missing, f"morse: a row for every r = 6..20 step 2, method and DEIM setting (missing {missing})")
if missing:
    print(f"morse claims: {checks - fails} of {checks} hold")
    sys.exit(1)


def val(r, m, dd, q):
    return float(rom[(r, m, dd)][q])


for (r, m, dd), row in sorted(rom.items()):
    tag = f"morse {m}{' + DEIM' if dd else ''} r={r}"
    claim(int(row["rc"]) == 0, f"{tag}: reduced and simulated (rc {row['rc']})")
    # the models without DEIM are simulated with the test input only with
    # morse_chain --all-terms-test (nan otherwise); the DEIM models always
    tested = dd == 1 or not math.isnan(float(row["e_y_test"]))
    qs = ("e_red", "e_y", "energy") + (("e_red_test", "e_y_test", "energy_test") if tested else ())
    claim(all(math.isfinite(float(row[q])) for q in qs), f"{tag}: finite errors")
    claim(float(row["newton_failures"]) == 0, f"{tag}: Newton failures {row['newton_failures']} == 0")
    e, et = float(row["energy"]), float(row["energy_test"])
    claim(e <= 10 * fom_en, f"{tag}: max energy error {e:.3e} within 10x of the FOM's {fom_en:.3e} (training)")
    if tested:
        claim(et <= 10 * fom_en_test, f"{tag}: max energy error {et:.3e} within 10x of the FOM's {fom_en_test:.3e} (test)")

for dd in (0, 1):
    suffix = " + DEIM" if dd else ""
    for m in methods:
        for q in ("e_red", "e_y"):
            a, b = val(rs[0], m, dd, q), val(rs[-1], m, dd, q)
            claim(b < a, f"morse {m}{suffix} {q}: r={rs[-1]} {b:.3e} < r={rs[0]} {a:.3e}")
    for m in ("GMG-POD", "GMG-QM"):
        for q in ("e_red", "e_y"):
            for r0, r1 in zip(rs, rs[1:]):
                a, b = val(r0, m, dd, q), val(r1, m, dd, q)
                claim(b < a, f"morse {m}{suffix} {q}: decreases from r={r0} {a:.3e} to r={r1} {b:.3e}")
    for r in rs:
        pod, sp2 = val(r, "GMG-POD", dd, "e_y"), val(r, "SP2-POD", dd, "e_y")
        claim(pod < sp2, f"morse r={r}{suffix}: e_y GMG-POD {pod:.3e} < SP2-POD {sp2:.3e}")
print(f"morse claims: {checks - fails} of {checks} hold")
sys.exit(1 if fails else 0)
