#!/usr/bin/python3
"""Exchange .npy files between real NumPy and phgmg.h's reader/writer.

Usage: /usr/bin/python3 tests/test_npy_numpy.py build/npy_tool

Writes arrays of every supported kind with NumPy (format versions 1.0, 2.0
and 3.0 when this NumPy has it; '<f8', '>f8', '<f4', '>f4'; C and Fortran
order; 0-d, 1-d, 2-d, 1x1 and empty shapes; NaN/Inf/-0/subnormals), has
npy_tool read each one and write it back (Fortran or C order, float64 or
float32), and checks with NumPy that the values round trip exactly and that
the written header is what was asked for. Integer and bool arrays (int8 ...
int64, uint8 ... uint64, both byte orders, bool) must read back as
exactly the same values in float64, also through a pipe; NumPy's default
int64 index array (np.arange) included. Files NumPy writes but phgmg does
not support (complex, float16, int64 beyond 2^53, 3-d, structured,
truncated) must be refused with exit status 1 and a message saying why.
Exit status: 0 if every check passed, 1 otherwise; a summary is printed.
"""
import os
import subprocess
import sys
import tempfile

import numpy as np

fmt = np.lib.format


def versions():
    vs = [(1, 0), (2, 0)]
    try:  # version 3.0 (utf8 header) exists since NumPy 1.17
        import io
        fmt.write_array(io.BytesIO(), np.zeros(1), version=(3, 0))
        vs.append((3, 0))
    except ValueError:
        pass
    return vs


def base_arrays(rng):
    """name -> float64 array (logical values; dtype/order applied later)."""
    arrs = {
        "0d": np.array(rng.standard_normal()),
        "1d_7": rng.standard_normal(7),
        "1d_1": np.array([2.5]),
        "1d_0": np.zeros(0),
        "1x1": np.array([[-3.25]]),
        "5x3": rng.standard_normal((5, 3)) * 10.0 ** rng.integers(-30, 30, (5, 3)),
        "1x6": rng.standard_normal((1, 6)),
        "6x1": rng.standard_normal((6, 1)),
        "37x29": rng.standard_normal((37, 29)),  # more than one 4 KiB chunk
        "0x4": np.zeros((0, 4)),
        "3x0": np.zeros((3, 0)),
        "special": np.array([[np.nan, np.inf, -np.inf],
                             [-0.0, 5e-324, 1e300]]),
    }
    return arrs


def same(out, want):
    """Exact equality incl. NaN positions and the sign of zeros."""
    if out.shape != want.shape:
        return False
    o = out.astype(np.float64)
    w = want.astype(np.float64)
    if not np.array_equal(o, w, equal_nan=True):
        return False
    return bool(np.array_equal(np.signbit(o), np.signbit(w)))


def header_of(path):
    with open(path, "rb") as f:
        major, minor = fmt.read_magic(f)
        if (major, minor) != (1, 0):
            return None
        shape, fortran, dtype = fmt.read_array_header_1_0(f)
        return shape, fortran, dtype, f.tell()


def main():
    if len(sys.argv) != 2:
        print("usage: test_npy_numpy.py path/to/npy_tool")
        return 2
    tool = os.path.abspath(sys.argv[1])
    np.seterr(over="ignore")  # 1e300 -> float32 overflows to inf on purpose
    rng = np.random.default_rng(2024)
    fails = []
    nfiles = nchecks = 0
    vers = versions()
    out_opts = [[], ["--c-order"], ["--f32"], ["--c-order", "--f32"]]

    def run(*args):
        return subprocess.run([tool] + list(args), capture_output=True, text=True)

    with tempfile.TemporaryDirectory(prefix="phgmg_npy_") as tmp:
        for name, base in base_arrays(rng).items():
            for dt in ["<f8", ">f8", "<f4", ">f4"]:
                for order in ["C", "F"]:
                    if base.ndim < 2 and order == "F":
                        continue  # 1-d/0-d: NumPy writes fortran_order False anyway
                    a = np.asarray(base.astype(dt), order=order)
                    for ver in vers:
                        src = os.path.join(tmp, "in.npy")
                        with open(src, "wb") as f:
                            fmt.write_array(f, a, version=ver)
                        nfiles += 1
                        tag = "%s %s %s-order v%d.0" % (name, dt, order, ver[0])
                        for opts in out_opts:
                            dst = os.path.join(tmp, "out.npy")
                            if os.path.exists(dst):
                                os.remove(dst)
                            r = run("copy", src, dst, *opts)
                            nchecks += 1
                            what = "%s -> %s" % (tag, " ".join(opts) or "default")
                            if r.returncode != 0:
                                fails.append("%s: exit %d %s" % (what, r.returncode,
                                                                 r.stderr.strip()))
                                continue
                            b = np.load(dst)
                            want = a.astype("<f4") if "--f32" in opts else a
                            if not same(b, want):
                                fails.append("%s: values differ" % what)
                            h = header_of(dst)
                            wdt = np.dtype("<f4" if "--f32" in opts else "<f8")
                            wfo = "--c-order" not in opts
                            if h is None:
                                fails.append("%s: not version 1.0" % what)
                            elif (h[0] != a.shape or h[2] != wdt or h[3] % 64 != 0 or
                                  (a.ndim == 2 and h[1] != wfo)):
                                fails.append("%s: header %r" % (what, h))
                        # the reader's own view of the shape
                        r = run("info", src)
                        if a.ndim == 0:
                            want_dims = (1, 1, 0)
                        elif a.ndim == 1:
                            want_dims = (a.shape[0], 1, 1)
                        else:
                            want_dims = (a.shape[0], a.shape[1], 2)
                        got = tuple(int(t) for t in r.stdout.split()) if r.returncode == 0 else None
                        nchecks += 1
                        if got != want_dims:
                            fails.append("%s: info %r, want %r" % (tag, got, want_dims))

        # a Fortran-order header on shapes NumPy would write as C order
        for shape in [(1, 5), (5, 1), (1, 1)]:
            a = rng.standard_normal(shape)
            src = os.path.join(tmp, "in.npy")
            with open(src, "wb") as f:
                fmt.write_array_header_1_0(f, {"descr": "<f8", "fortran_order": True,
                                               "shape": shape})
                f.write(a.tobytes(order="F"))
            nfiles += 1
            dst = os.path.join(tmp, "out.npy")
            r = run("copy", src, dst)
            nchecks += 1
            if r.returncode != 0 or not same(np.load(dst), a):
                fails.append("manual fortran header %r" % (shape,))

        # integer and bool dtypes: exact values in float64 (file and pipe)
        ints = []
        for kind in "iu":
            for size in [1, 2, 4, 8]:
                info = np.iinfo(np.dtype("%s%d" % (kind, size)))
                lo, hi = max(info.min, -2 ** 53), min(info.max, 2 ** 53)
                for bo in "<>":
                    dt = np.dtype("%s%s%d" % (bo, kind, size))
                    vals = np.array([[lo, hi, 0], [1, lo // 3, hi // 7]], dtype=dt)
                    ints.append(("%s %s" % (dt.str, "C"), vals))
                    ints.append(("%s %s" % (dt.str, "F"), np.asfortranarray(vals)))
                    ints.append(("%s 1-d" % dt.str, np.arange(11, dtype=dt)))
        ints.append(("arange default", np.arange(20)))            # nl_idx.npy as users write it
        ints.append(("bool", np.array([[True, False], [False, True], [True, True]])))
        ints.append(("bool 0-d", np.array(True)))
        for name, a in ints:
            for ver in vers:
                src = os.path.join(tmp, "int.npy")
                with open(src, "wb") as f:
                    fmt.write_array(f, a, version=ver)
                nfiles += 1
                for how in ["file", "pipe"]:
                    dst = os.path.join(tmp, "out.npy")
                    if os.path.exists(dst):
                        os.remove(dst)
                    if how == "file":
                        r = run("copy", src, dst)
                    else:
                        r = subprocess.run([tool, "copy", "/dev/stdin", dst],
                                           input=open(src, "rb").read(), capture_output=True)
                    nchecks += 1
                    what = "%s v%d.0 (%s)" % (name, ver[0], how)
                    if r.returncode != 0:
                        fails.append("%s: exit %d %r" % (what, r.returncode, r.stderr))
                        continue
                    b = np.load(dst)
                    want = a.astype(np.float64)
                    if b.dtype != np.float64 or not same(b, want):
                        fails.append("%s: values differ" % what)
                    if not np.array_equal(b.astype(a.dtype), a):  # and back, exactly
                        fails.append("%s: not exact" % what)

        # files NumPy writes that phgmg must refuse cleanly (exit status 1),
        # with the reason in the message
        bad = {
            "int64 2^53+1": (np.array([0, 2 ** 53 + 1], dtype="<i8"), "2^53"),
            "int64 -2^53-1": (np.array([-(2 ** 53) - 1], dtype=">i8"), "2^53"),
            "uint64 max": (np.array([2 ** 64 - 1], dtype="<u8"), "2^53"),
            "complex": (np.ones(3, dtype="<c16"), "dtype"),
            "float16": (np.ones(3, dtype="<f2"), "dtype"),
            "3d": (np.zeros((2, 2, 2)), "malformed"),
            "structured": (np.zeros(2, dtype=[("a", "<f8"), ("b", "<f8")]), "dtype"),
        }
        for name, (a, why) in bad.items():
            src = os.path.join(tmp, "bad.npy")
            with open(src, "wb") as f:
                fmt.write_array(f, a, version=(1, 0))
            nfiles += 1
            r = run("copy", src, os.path.join(tmp, "never.npy"))
            nchecks += 1
            if r.returncode != 1 or os.path.exists(os.path.join(tmp, "never.npy")):
                fails.append("refuse %s: exit %d" % (name, r.returncode))
            elif why not in r.stderr:
                fails.append("refuse %s: message %r does not say %r" % (name, r.stderr, why))
        src = os.path.join(tmp, "trunc.npy")
        full = os.path.join(tmp, "full.npy")
        np.save(full, rng.standard_normal((4, 4)))
        data = open(full, "rb").read()
        for cut in [0, 5, 9, 40, 128, len(data) - 1]:
            with open(src, "wb") as f:
                f.write(data[:cut])
            nfiles += 1
            r = run("info", src)
            nchecks += 1
            if r.returncode != 1:
                fails.append("refuse truncated at %d: exit %d" % (cut, r.returncode))

    for f in fails[:40]:
        print("FAIL", f)
    print("npy/numpy: NumPy %s, versions %s: %d files, %d checks, %d failed"
          % (np.__version__, ",".join("%d.0" % v[0] for v in vers), nfiles, nchecks,
             len(fails)))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
