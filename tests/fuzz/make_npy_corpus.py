#!/usr/bin/python3
"""Regenerate the seed corpus tests/fuzz/corpus/npy/seed_* for fuzz_npy.c:
valid files of each supported kind (written by NumPy) and a few malformed ones.
Usage: /usr/bin/python3 tests/fuzz/make_npy_corpus.py [outdir]"""
import io
import os
import sys

import numpy as np

fmt = np.lib.format
out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "corpus", "npy")
os.makedirs(out, exist_ok=True)
rng = np.random.default_rng(7)


def npy(a, version=(1, 0)):
    f = io.BytesIO()
    fmt.write_array(f, a, version=version)
    return f.getvalue()


def put(name, data):
    with open(os.path.join(out, "seed_" + name), "wb") as f:
        f.write(data)


m = rng.standard_normal((2, 3))
for ver in [(1, 0), (2, 0), (3, 0)]:
    for dt in ["<f8", ">f8", "<f4", ">f4"]:
        put("v%d_%s_c_2x3.npy" % (ver[0], dt[0] == "<" and "l" + dt[1:] or "b" + dt[1:]),
            npy(m.astype(dt), ver))
put("v1_lf8_f_2x3.npy", npy(np.asfortranarray(m)))
put("v1_bf4_f_3x2.npy", npy(np.asfortranarray(m.T.astype(">f4"))))
put("v1_lf8_0d.npy", npy(np.array(1.5)))
put("v1_lf8_1d.npy", npy(np.arange(4.0)))
put("v1_lf8_empty1d.npy", npy(np.zeros(0)))
put("v1_lf8_3x0.npy", npy(np.zeros((3, 0))))
put("v1_lf8_1x1.npy", npy(np.ones((1, 1))))
put("v1_lf8_special.npy", npy(np.array([np.nan, np.inf, -0.0, 5e-324])))
hdr = b"{ \"shape\":(2L,3L,),'descr':'<f8' , 'fortran_order':True}   \n"
put("manual_spelling.npy", b"\x93NUMPY\x01\x00" + bytes([len(hdr), 0]) + hdr +
    m.tobytes(order="F"))
# malformed
good = npy(m)
put("bad_magic.npy", b"\x93NUMPX" + good[6:])
put("bad_truncated.npy", good[:-3])
put("bad_hlen.npy", good[:8] + b"\xff\xff" + good[10:])
put("bad_int64.npy", npy(np.arange(6, dtype="<i8")))
put("bad_3d.npy", npy(np.zeros((1, 2, 1))))
put("bad_notuple.npy", good.replace(b"(2, 3)", b"(6)   "))
# integer and bool dtypes, refused ones, and a short stream that
# claims a huge shape (a pipe's buffer must grow with
# the data; fuzz_npy_stream.c reads these from a file and a pipe too)
for dt in ["<i1", "|u1", "<i2", ">i2", "<u2", "<i4", ">u4", "<i8", ">i8", "<u8"]:
    name = dt.replace("<", "l").replace(">", "b").replace("|", "n")
    put("int_%s_c_2x3.npy" % name, npy(np.arange(6, dtype=dt).reshape(2, 3)))
put("int_arange_default.npy", npy(np.arange(20)))
put("int_li4_f_2x3.npy", npy(np.asfortranarray(np.arange(6, dtype="<i4").reshape(2, 3))))
put("bool_2x2.npy", npy(np.array([[True, False], [False, True]])))
put("bad_int64_big.npy", npy(np.array([2 ** 53 + 1, -5], dtype="<i8")))
put("bad_uint64_max.npy", npy(np.array([2 ** 64 - 1], dtype="<u8")))
put("bad_complex.npy", npy(np.ones(2, dtype="<c16")))
h = "{'descr': '<f8', 'fortran_order': False, 'shape': (200000, 200000), }"
h = h + " " * (117 - len(h)) + "\n"
put("bad_huge_claim.npy", b"\x93NUMPY\x01\x00" + bytes([len(h), 0]) + h.encode() + b"\0" * 64)
