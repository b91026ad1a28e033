#!/usr/bin/env python3
"""Compares the particles two runs of one scene removed (a limit's `remove`), by global id.

    compare_removed.py REFERENCE_DIR OTHER_DIR [--tol T] [--log REF_ERR OTHER_ERR]

Both directories hold a run's DIR/SCENE_removed.csv (written with global ids: `sphc
--global-ids`, implied by `--mpi`). The other run must have the reference's rows: the same
count, in the same order (by step, then gid), with step, limit, array and gid equal and every
value column (t, x, y, z, u, v, w, m, rho) within T times that column's scale (its largest
|value| in the reference, at least 1e-300). The column `index` (the particle's index in its
array, under --mpi on its rank) is not compared.

With --log, the lines `removed ...` of the two runs' stderr must be the same but for their
numbers, each within T of the reference's (relative): the count, the steps and the positions
as printed.
"""
import argparse
import glob
import os
import re
import sys

NUMBER = re.compile(r"-?\d+(?:\.\d*)?(?:e[-+]?\d+)?")


def rows(directory):
    files = sorted(glob.glob(os.path.join(directory, "*_removed.csv")))
    if len(files) != 1:
        sys.exit(f"compare_removed: {len(files)} removed-particles files in {directory}")
    with open(files[0]) as f:
        header = f.readline().strip().split(",")
        return header, [line.rstrip("\n").split(",") for line in f if line.strip()]


def close(a, b, tol, scale):
    if a == b:
        return True
    if a == "" or b == "":
        return False
    return abs(float(a) - float(b)) <= tol * scale


def compare_logs(ref, other, tol):
    def lines(path):
        with open(path) as f:
            return [line.rstrip("\n") for line in f if line.startswith("removed")]
    a, b = lines(ref), lines(other)
    if len(a) != len(b):
        print(f"compare_removed: {len(b)} 'removed' lines in {other}, {len(a)} in {ref}")
        return False
    for x, y in zip(a, b):
        nx, ny = NUMBER.findall(x), NUMBER.findall(y)
        if NUMBER.sub("#", x) != NUMBER.sub("#", y) or len(nx) != len(ny) or not all(
                close(p, q, tol, max(abs(float(p)), 1e-300)) for p, q in zip(nx, ny)):
            print(f"compare_removed: log line\n  {y}\nexpected\n  {x}")
            return False
    print(f"compare_removed: {len(a)} 'removed' lines alike (numbers within {tol:g})")
    return True


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("ref_dir")
    ap.add_argument("other_dir")
    ap.add_argument("--tol", type=float, default=1e-9)
    ap.add_argument("--log", nargs=2, metavar=("REF_ERR", "OTHER_ERR"))
    a = ap.parse_args()
    tol, logs, ref_dir, other_dir = a.tol, a.log, a.ref_dir, a.other_dir
    hr, r = rows(ref_dir)
    ho, o = rows(other_dir)
    ok = True
    if hr != ho:
        print(f"compare_removed: columns {ho}, expected {hr}")
        return 1
    if len(r) != len(o):
        print(f"compare_removed: {len(o)} removed particles, the reference {len(r)}")
        return 1
    exact = [hr.index(k) for k in ("step", "limit", "array", "gid")]
    values = [k for k, name in enumerate(hr) if name not in ("step", "limit", "array", "gid",
                                                             "index")]
    worst = {}
    for k in values:
        scale = max([abs(float(row[k])) for row in r if row[k] != ""] + [1e-300])
        for x, y in zip(r, o):
            if not close(x[k], y[k], tol, scale):
                print(f"compare_removed: {hr[k]} of gid {y[hr.index('gid')]}: {y[k]}, "
                      f"expected {x[k]}")
                ok = False
            elif x[k] != "":
                worst[hr[k]] = max(worst.get(hr[k], 0.0), abs(float(x[k]) - float(y[k])) / scale)
    for x, y in zip(r, o):
        if [x[k] for k in exact] != [y[k] for k in exact]:
            print(f"compare_removed: row {','.join(y)}, expected {','.join(x)}")
            ok = False
    print("compare_removed: " + ", ".join(f"{k} {d:.1e}" for k, d in worst.items()) +
          " of the column's scale")
    if logs:
        ok = compare_logs(logs[0], logs[1], tol) and ok
    print(f"compare_removed: {len(r)} removed particles, tolerance {tol:g}: "
          f"{'ok' if ok else 'FAILED'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
