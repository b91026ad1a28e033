#!/usr/bin/env python3
"""Compares the outputs of two runs of one scene particle by particle, matched by global id.

    compare_runs.py REFERENCE_DIR OTHER_DIR [--tol T] [--gid-order]

Both directories hold the HDF5 files of a run (scene_NNNNNN.h5) written with global ids
(`sphc --global-ids`, implied by `--mpi`). Every file of the reference must exist in the other
run (every output time); in each, every array must have the same particles (the same set of
gid) and every property (and constant) of the reference must agree within T times that property's scale
(the largest |value| of the reference's property in that file, at least 1e-300). Prints the
worst difference per property over all files and exits 1 if any exceeds T or anything is
missing.

The files must also have the reference's layout: the same root attributes (step, dim and scene
equal, t, dt and the run state restart_NAME of --restartable files within T), the same array groups and datasets in the same order with the same
types and shapes; with --gid-order, the other run's particles in gid order (the order a
distributed run writes, whatever the rank count; a serial run may have reordered its own).

Where the reference has a metrics CSV (*_metrics.csv, the scene's metrics { }), the other run
must have it too, with the same rows (step, t) and every metric column (value, reference,
error) within T times that column's scale (its largest |value| in the reference); the time
columns wall_s and cpu_s are not compared.
"""
import glob
import os
import sys

import h5py
import numpy as np


def arrays(path):
    out = {}
    with h5py.File(path, "r") as f:
        grp = f["particles"] if "particles" in f else f
        for name in grp:
            g = grp[name]
            if not isinstance(g, h5py.Group):
                continue
            props = g["arrays"] if "arrays" in g else g
            out[name] = {k: np.array(props[k]) for k in props if isinstance(props[k], h5py.Dataset)}
            if "constants" in g:  # per-array constants (reductions), as attributes
                for k, v in g["constants"].attrs.items():
                    out[name]["const:" + k] = np.array(v)
    return out


def layout_problems(fr, fo, tol, gid_order):
    """What differs in the layout (attributes, groups, datasets, order) of two files."""
    out = []
    with h5py.File(fr, "r") as a, h5py.File(fo, "r") as b:
        if sorted(a.attrs) != sorted(b.attrs):
            out.append(f"root attributes {sorted(b.attrs)}, expected {sorted(a.attrs)}")
        for k in ("step", "dim", "scene"):
            if k in a.attrs and k in b.attrs and a.attrs[k] != b.attrs[k]:
                out.append(f"root attribute {k} = {b.attrs[k]}, expected {a.attrs[k]}")
        # t, dt and the run state of --restartable files (restart_NAME: step counts, the
        # inlet/outlet manager's next id, counters and running mean) within tol.
        for k in a.attrs:
            if k not in ("t", "dt") and not k.startswith("restart_"):
                continue
            if k in b.attrs and abs(a.attrs[k] - b.attrs[k]) > tol * max(abs(a.attrs[k]), 1e-300):
                out.append(f"root attribute {k} = {b.attrs[k]}, expected {a.attrs[k]}")
        if list(a.keys()) != list(b.keys()):
            out.append(f"groups {list(b.keys())}, expected {list(a.keys())}")
        for name in a:
            if name not in b or not isinstance(a[name], h5py.Group):
                continue
            ga, gb = a[name], b[name]
            if list(ga.keys()) != list(gb.keys()):
                out.append(f"{name}: members {list(gb.keys())}, expected {list(ga.keys())}")
            if ga.attrs.get("n") != gb.attrs.get("n"):
                out.append(f"{name}: n = {gb.attrs.get('n')}, expected {ga.attrs.get('n')}")
            for k in ga:
                if k in gb and isinstance(ga[k], h5py.Dataset):
                    if ga[k].dtype != gb[k].dtype or ga[k].shape != gb[k].shape:
                        out.append(f"{name}/{k}: {gb[k].dtype} {gb[k].shape}, expected "
                                   f"{ga[k].dtype} {ga[k].shape}")
            if gid_order and "gid" in gb:
                if not np.all(np.diff(np.array(gb["gid"]).astype(np.int64)) > 0):
                    out.append(f"{name}: particles not in gid order")
    return out


def read_csv(path):
    with open(path) as f:
        header = f.readline().strip().split(",")
        rows = [[float(v) for v in line.strip().split(",")] for line in f if line.strip()]
    return header, np.array(rows, dtype=float).reshape(len(rows), len(header))


def compare_metrics(ref_dir, other_dir, tol):
    """(ok, lines) for the metrics CSVs; ok is None without one in the reference."""
    files = sorted(glob.glob(os.path.join(ref_dir, "*_metrics.csv")))
    if not files:
        return None, []
    ok, lines = True, []
    for fr in files:
        fo = os.path.join(other_dir, os.path.basename(fr))
        if not os.path.exists(fo):
            return False, [f"compare_runs: {fo} missing (the reference has metrics)"]
        hr, r = read_csv(fr)
        ho, o = read_csv(fo)
        if hr != ho or r.shape != o.shape:
            return False, [f"compare_runs: {fo}: columns {ho} and {o.shape[0]} rows, the "
                           f"reference {hr} and {r.shape[0]} rows"]
        if not np.array_equal(r[:, 0], o[:, 0]):
            return False, [f"compare_runs: {fo}: other steps than the reference"]
        for k, name in enumerate(hr):
            if name in ("step", "wall_s", "cpu_s"):
                continue
            a, b = r[:, k], o[:, k]
            if not np.array_equal(np.isnan(a), np.isnan(b)):
                ok = False
                lines.append(f"metric {name:<10} NaN in one run only")
                continue
            m = ~np.isnan(a)
            scale = max(float(np.max(np.abs(a[m]))) if m.any() else 0.0, 1e-300)
            d = float(np.max(np.abs(a[m] - b[m]))) / scale if m.any() else 0.0
            lines.append(f"metric {name:<10} worst {d:.3e} of its scale ({r.shape[0]} rows)")
            ok = ok and d <= tol
    return ok, lines


def main():
    args = sys.argv[1:]
    tol = 1e-9
    if "--tol" in args:
        k = args.index("--tol")
        tol = float(args[k + 1])
        del args[k:k + 2]
    gid_order = "--gid-order" in args
    if gid_order:
        args.remove("--gid-order")
    ref_dir, other_dir = args
    files = sorted(glob.glob(os.path.join(ref_dir, "*_[0-9]*.h5")))
    if not files:
        print(f"compare_runs: no output files in {ref_dir}")
        return 1
    worst = {}
    ok = True
    for fr in files:
        fo = os.path.join(other_dir, os.path.basename(fr))
        if not os.path.exists(fo):
            print(f"compare_runs: {fo} missing (the reference has {os.path.basename(fr)})")
            return 1
        for problem in layout_problems(fr, fo, tol, gid_order):
            print(f"compare_runs: {fo}: {problem}")
            ok = False
        ra, oa = arrays(fr), arrays(fo)
        for name, rp in ra.items():
            if name not in oa or "gid" not in rp or "gid" not in oa[name]:
                print(f"compare_runs: array {name} or its gid missing in {fo}")
                return 1
            op = oa[name]
            ri, oi = np.argsort(rp["gid"]), np.argsort(op["gid"])
            if not np.array_equal(rp["gid"][ri], op["gid"][oi]):
                print(f"compare_runs: {fo}: array {name} has other particles "
                      f"({len(op['gid'])} against {len(rp['gid'])})")
                return 1
            for prop, rv in rp.items():
                if prop not in op:
                    print(f"compare_runs: {fo}: {name}.{prop} missing")
                    return 1
                if prop.startswith("const:"):  # one value per array, not per particle
                    a, b = rv.astype(float), op[prop].astype(float)
                else:
                    a = rv[ri].astype(float)
                    b = op[prop][oi].astype(float)
                scale = max(np.max(np.abs(a)) if a.size else 0.0, 1e-300)
                d = float(np.max(np.abs(a - b)) / scale) if a.size else 0.0
                key = f"{name}.{prop}"
                if d > worst.get(key, (-1, ""))[0]:
                    worst[key] = (d, os.path.basename(fr))
                ok = ok and d <= tol
    for key, (d, f) in sorted(worst.items()):
        print(f"{key:<16} worst {d:.3e} of its scale ({f})")
    mok, lines = compare_metrics(ref_dir, other_dir, tol)
    for line in lines:
        print(line)
    if mok is not None:
        ok = ok and mok
    print(f"compare_runs: {len(files)} files, tolerance {tol:g}: {'ok' if ok else 'FAILED'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
