#!/usr/bin/env python3
"""How far apart two runs of the same scene are, snapshot by snapshot (particle by particle).

Runs nothing itself. It reads the snapshots two runs wrote (sphc's <scene>_NNNNNN.h5, built
with --global-ids so that every array writes `gid`) into DIR_A and DIR_B, pairs the snapshots
by their time t and the particles by gid (the runs may sort their particles at different
steps), and prints per snapshot, over the arrays given (default: fluid):

  pos/dx   the largest distance between a particle's two positions, in units of the
           particle spacing --dx (default: the lattice spacing of the first snapshot of
           DIR_A, snapshots.lattice_spacing);
  rho      the largest |rho_a - rho_b| / --rho0 (default: the largest |rho| of the first
           snapshot), where rho is written;
  vel      the largest |v_a - v_b| over the largest |v_a| of the snapshot, where u, v (w)
           are written;
  med pos/dx  the median of the position differences (a systematic drift moves it with
           the largest; round-off growth in a chaotic flow starts at a few particles);
  n>0.1dx  how many particles are more than 0.1 dx apart.

For docs/stability.md, "Whole runs of the scenes in SIMD lanes": two runs whose sums differ
only in their association (the lanes' reduction against the scalar loop) must start ~1e-13
apart and may grow apart as a chaotic flow amplifies round-off; both must then pass their
checks (check_run.py, the validations). --max-pos F / --max-rho F fail (exit 1) when the
difference at the last common snapshot exceeds F (default: only report).

Usage: compare_runs.py DIR_A DIR_B [--arrays fluid,...] [--dx DX] [--rho0 R] [--every N]
                       [--max-pos F] [--max-rho F]
Exit 0 (report, or within the limits), 1 beyond a limit, 2 on bad input.
"""
import argparse
import os
import sys

try:
    import h5py
    import numpy as np
except ImportError as exc:  # pragma: no cover - environment problem
    sys.stderr.write("compare_runs.py needs numpy and h5py (%s)\n" % exc)
    sys.exit(2)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "validation"))
from snapshots import lattice_spacing, snapshots  # noqa: E402

WHO = "compare_runs.py"


def by_time(directory):
    """{t: file} of the snapshots of a run."""
    files = snapshots(directory, WHO, at_least=1)
    if files is None:
        sys.exit(2)
    out = {}
    for name in files:
        with h5py.File(name, "r") as f:
            out[round(float(f.attrs["t"]), 12)] = name
    return out


def load(name, array, keys):
    """{key: array sorted by gid} of one particle array of a snapshot (keys it writes)."""
    with h5py.File(name, "r") as f:
        if array not in f:
            return None
        g = f[array]
        if "gid" not in g:
            sys.stderr.write("%s: %s has no gid in %s: build both runs with --global-ids\n"
                             % (WHO, array, name))
            sys.exit(2)
        order = np.argsort(g["gid"][()])
        return {k: g[k][()][order] for k in keys + ["gid"] if k in g}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dir_a")
    ap.add_argument("dir_b")
    ap.add_argument("--arrays", default="fluid")
    ap.add_argument("--dx", type=float, default=None)
    ap.add_argument("--rho0", type=float, default=None)
    ap.add_argument("--every", type=int, default=1, help="print every N-th common snapshot")
    ap.add_argument("--max-pos", type=float, default=None)
    ap.add_argument("--max-rho", type=float, default=None)
    args = ap.parse_args()

    ta, tb = by_time(args.dir_a), by_time(args.dir_b)
    common = sorted(set(ta) & set(tb))
    if not common:
        sys.stderr.write("%s: the runs have no snapshot time in common\n" % WHO)
        return 2
    arrays = args.arrays.split(",")
    dx, rho0 = args.dx, args.rho0
    print("%10s %8s %11s %11s %11s %11s %8s" % ("t", "step", "pos/dx", "med pos/dx", "rho/rho0",
                                                  "vel", "n>0.1dx"))
    last = None
    for i, t in enumerate(common):
        worst_pos = worst_rho = worst_vel = 0.0
        meds = []
        nfar = 0
        with h5py.File(ta[t], "r") as f:
            step = int(f.attrs.get("step", -1))
            dim = int(f.attrs.get("dim", 3))
        axes = ["x", "y", "z"][:dim]
        vels = ["u", "v", "w"][:dim]
        for array in arrays:
            keys = axes + vels + ["rho"]
            a, b = load(ta[t], array, keys), load(tb[t], array, keys)
            if a is None or b is None:
                continue
            if not np.array_equal(a["gid"], b["gid"]):
                print("t = %g: %s: the runs hold different particles (gid)" % (t, array))
                return 1
            if dx is None:
                dx = lattice_spacing(tuple(a[k] for k in axes))
            if rho0 is None and "rho" in a:
                rho0 = float(np.max(np.abs(a["rho"])))
            d = np.sqrt(sum((a[k] - b[k]) ** 2 for k in axes)) / dx
            worst_pos = max(worst_pos, float(d.max()))
            meds.append(float(np.median(d)))
            nfar += int(np.count_nonzero(d > 0.1))
            if "rho" in a and "rho" in b:
                worst_rho = max(worst_rho, float(np.max(np.abs(a["rho"] - b["rho"]))) / rho0)
            if all(k in a and k in b for k in vels):
                va = np.sqrt(sum(a[k] ** 2 for k in vels))
                dv = np.sqrt(sum((a[k] - b[k]) ** 2 for k in vels))
                scale = float(va.max())
                if scale > 0:
                    worst_vel = max(worst_vel, float(dv.max()) / scale)
        last = (t, worst_pos, worst_rho)
        if i % args.every == 0 or i == len(common) - 1:
            print("%10.5f %8d %11.3e %11.3e %11.3e %11.3e %8d"
                  % (t, step, worst_pos, max(meds) if meds else 0.0, worst_rho, worst_vel,
                     nfar))
    t, worst_pos, worst_rho = last
    bad = []
    if args.max_pos is not None and worst_pos > args.max_pos:
        bad.append("positions %.3e dx apart at t = %g (limit %g)" % (worst_pos, t, args.max_pos))
    if args.max_rho is not None and worst_rho > args.max_rho:
        bad.append("densities %.3e rho0 apart at t = %g (limit %g)" % (worst_rho, t,
                                                                       args.max_rho))
    if bad:
        print("FAILED: " + "; ".join(bad))
        return 1
    print("%d common snapshots; at t = %g: positions %.3e dx, density %.3e rho0 apart"
          % (len(common), t, worst_pos, worst_rho))
    return 0


if __name__ == "__main__":
    sys.exit(main())
