#!/usr/bin/env python3
"""Checks that a restarted run wrote the uninterrupted run's outputs bitwise.

    restart_bitwise.py UNINTERRUPTED_DIR RESTARTED_DIR

Every HDF5 file of RESTARTED_DIR (scene_NNNNNN.h5) must exist in UNINTERRUPTED_DIR and hold
the same root attributes (t, dt, step, dim, scene and the run state restart_*), the same
arrays, and every dataset and constant with the same dtype, shape and bytes (NaN compares by
bit pattern). The restarted run must have written at least one file. Prints one line per
file compared; exits 1 at the first difference (in the particles of any file, then in the
attributes).
"""
import glob
import os
import sys

import h5py
import numpy as np


def fail(msg):
    print("restart_bitwise: " + msg)
    sys.exit(1)


def same(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def main():
    ref_dir, new_dir = sys.argv[1], sys.argv[2]
    files = sorted(glob.glob(os.path.join(new_dir, "*.h5")))
    if not files:
        fail(f"no output files in {new_dir}")
    checked, attr_problems = [], []
    for path in files:
        name = os.path.basename(path)
        ref = os.path.join(ref_dir, name)
        if not os.path.exists(ref):
            fail(f"{name}: the uninterrupted run has no such file")
        with h5py.File(ref, "r") as a, h5py.File(path, "r") as b:
            if list(a.keys()) != list(b.keys()):
                fail(f"{name}: arrays {list(b.keys())} != {list(a.keys())}")
            values = 0
            for arr in a:
                ga, gb = a[arr], b[arr]
                if list(ga.keys()) != list(gb.keys()):
                    fail(f"{name}: {arr}: datasets {list(gb.keys())} != {list(ga.keys())}")
                for k in ga:
                    if isinstance(ga[k], h5py.Group):  # constants
                        if sorted(ga[k].attrs) != sorted(gb[k].attrs):
                            fail(f"{name}: {arr}/{k}: attributes differ")
                        for c in ga[k].attrs:
                            if not same(ga[k].attrs[c], gb[k].attrs[c]):
                                fail(f"{name}: {arr}: constant {c} differs")
                        continue
                    x, y = ga[k][()], gb[k][()]
                    if not same(x, y):
                        diff = "shape/dtype" if x.shape != y.shape or x.dtype != y.dtype else \
                            f"{int(np.sum(x != y))} values, largest |diff| {np.max(np.abs(x.astype(float) - y.astype(float)))}"
                        fail(f"{name}: {arr}/{k} differs ({diff})")
                    values += x.size
            # The particles of every file first, then the attributes (a wrong run state
            # shows in both, the particles' difference says more).
            if sorted(a.attrs) != sorted(b.attrs):
                attr_problems.append(f"{name}: root attributes {sorted(b.attrs)} != {sorted(a.attrs)}")
            for k in a.attrs:
                if k in b.attrs and not same(a.attrs[k], b.attrs[k]):
                    attr_problems.append(
                        f"{name}: root attribute {k} = {b.attrs[k]!r}, expected {a.attrs[k]!r}")
        checked.append(f"{name}: bitwise equal ({values} values)")
    if attr_problems:
        fail(attr_problems[0])
    print("\n".join(checked))


main()
