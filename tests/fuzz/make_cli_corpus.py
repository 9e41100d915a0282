#!/usr/bin/env python3
"""Write the seeds tests/fuzz/corpus/cli/seed_* of fuzz_cli.c for validate, sparse
input, potentials, exponentials, several training runs, output collisions, a huge
--dt-map and --lambda auto with --X, simulate with the descriptor, feedthrough, damper
and reference files (outputs naming them, directly or through a link): each seed is
a command line, one byte per token (the index of the token in fuzz_cli.c's
vocabulary, read from its source). The seeds file_* are file-mode inputs (0xFF, the
file's number, then its content: a .npy written with NumPy) that fuzz the content of
those files.
Run from the repository root: python3 tests/fuzz/make_cli_corpus.py"""
import re, os
src = open('tests/fuzz/fuzz_cli.c').read()
def arr(name):
    m = re.search(r'static const char \*const ' + name + r'\[\] = \{(.*?)NULL\};', src, re.S)
    return re.findall(r'"((?:[^"\\]|\\.)*)"', m.group(1))
toks = arr('words') + arr('files') + arr('words2') + arr('files2') + arr('words3') + arr('words4') + arr('files4') + arr('words5') + arr('words6') + arr('words7')
assert len(toks) <= 160, len(toks)
idx = {}
for i, t in enumerate(toks):
    idx.setdefault(t, i)
def seed(name, line):
    b = bytes(idx[t] for t in line.split())
    assert all(x < 256 for x in b)
    open('tests/fuzz/corpus/cli/seed_' + name, 'wb').write(b)
SYS = "--J J.npy --R R.npy --Q Q.npy --B B.npy"
seed('validate', f"validate {SYS} --simulate --steps 2 --method gmg-pod --r 2 --out o --test-input sin --test-input u.npy --test-amp 1 --test-steps 3 --max-ey 0.1")
seed('validate_X', f"validate {SYS} --X X.npy --X-input sin --method gmg-pod --r 3 --out o")
seed('validate_bad', f"validate {SYS} --simulate --method gmg-pod --r 2 --out o --max-ey 0 --test-steps 2147483646 --test-input square")
seed('coo', "reduce --J-coo Jc.npy --R-coo Rc.npy --Q-coo Qc.npy --B B.npy --simulate --steps 2 --method gmg-pod --r 2 --out o")
seed('potential', f"reduce {SYS} --potential toda --poly-idx idx.npy --simulate --steps 3 --method gmg-pod --r 2 --hyper ecsw --hyper-tol 1e-300 --out o")
seed('potential_bad', f"reduce {SYS} --potential fpu:: --poly-idx idx.npy --simulate --method gmg-pod --r 2 --out o")
seed('potential_morse', f"reduce {SYS} --potential morse:-1:1 --poly-idx idx_i8.npy --simulate --method sp1 --r 2 --out o")
seed('exp', f"reduce {SYS} --poly poly.npy --exp exp.npy --poly-idx idx.npy --hyper qdeim --deim-tol 0.1 --simulate --steps 2 --method gmg-pod --r 2 --out o")
seed('train', f"reduce {SYS} --simulate --steps 2 --train-input sin --train-input const --method gmg-qm --r 2 --lambda auto --manifold altmin --out o")
seed('collide', f"reduce {SYS} --X X.npy --poly-w o/rom_V0.npy --method gmg-pod --r 3 --out o --name rom --save-snapshots")
seed('sim_collide', "simulate-rom --model m.phgmgrom --out m.phgmgrom --states y.npy")
seed('dtmap', f"reduce {SYS} --X X.npy --method gmg-pod --r 3 --dt-map 1e15 --out o")
seed('lambda_X', f"reduce {SYS} --X X.npy --method gmg-qm --r 2 --lambda auto --out o")
seed('sim_dampers_out', f"simulate {SYS} --dampers d.npy --steps 3 --out d.npy")
seed('sim_states_link', f"simulate {SYS} --dampers d.npy --steps 3 --out y.npy --states ln_d.npy")
seed('sim_out_states', f"simulate {SYS} --steps 3 --out y.npy --states y.npy")
seed('sim_E_mix', "simulate --J-coo Jc.npy --R-coo Rc.npy --Q-coo Qc.npy --B B.npy --E E.npy --steps 3 --out y.npy")
seed('sim_E', f"simulate {SYS} --E E.npy --steps 3 --out y.npy --states xr.npy")
seed('sim_E_alg', f"simulate {SYS} --E E_alg.npy --steps 3 --out y.npy --states xr.npy")
seed('sim_huge_dt', f"simulate {SYS} --dt 1e300 --steps 3 --out y.npy")
seed('ref_alg', f"reduce {SYS} --E E_alg.npy --simulate --steps 3 --method gmg-pod --r 2 --ref ref.npy --out o")
seed('feed', f"reduce {SYS} --P P.npy --S S.npy --N N.npy --simulate --steps 3 --method gmg-pod --r 2 --out o")
seed('feed_ref', f"reduce {SYS} --S S.npy --simulate --steps 3 --method gmg-pod --r 2 --ref mean --out o")
seed('damp_V0', f"reduce {SYS} --dampers o/rom_V0.npy --X X.npy --method gmg-pod --r 3 --out o")
seed('damp_qm', f"reduce {SYS} --dampers d.npy --simulate --steps 3 --method gmg-qm --r 2 --out o")
import io
import numpy as np
def file_seed(name, k, A):
    b = io.BytesIO(); np.save(b, np.asarray(A, dtype=np.float64))
    open('tests/fuzz/corpus/cli/file_' + name, 'wb').write(bytes([0xFF, k]) + b.getvalue())
E4 = np.eye(4); E4[1, 3] = E4[3, 1] = 0.1
Ea = np.eye(4); Ea[3, 3] = 0.0
file_seed('dampers', 0, [[1, -1, 0.1, 1.0], [3, 1, 0.05, 0.5]])
file_seed('E', 1, E4)
file_seed('E_coo', 2, [[0, 0, 1], [1, 1, 1], [2, 2, 1], [3, 3, 1], [1, 3, 0.1], [3, 1, 0.1]])
file_seed('P', 3, [[0], [0.1], [0], [0]])
file_seed('S', 4, [[0.2]])
file_seed('N', 5, [[0.0]])
file_seed('ref', 6, [0.1, 0, 0.1, 0])
file_seed('E_alg', 7, Ea)
file_seed('dampers_reduce', 8, [[1, -1, 0.1, 1.0]])
print(len(toks), "tokens")
