#!/usr/bin/env python3
"""The closest pair of the bulk of the fluid at every snapshot of a run (a report, not a check).

check_run.py --min-pair judges the smallest of these over the run; this script prints the
whole series, to tell a minimum that one snapshot decides (a single close encounter, which
rounding-level changes of the run move from output to output) from a run whose pairs close
up in general (many outputs near the minimum).

For every snapshot outside the --pair-skip windows: the closest pair among the fluid
particles with at least --pair-bulk other fluid particles within 2.6 dx (check_run.py's
definition of the bulk), in dx; only pairs closer than --cut dx (0.8) are looked at, so a
snapshot whose bulk pairs are all farther apart reports the cut. Prints one line per snapshot with
--series, then the summary: the smallest value and its time and place, the next smallest
snapshots, how many snapshots lie below each of --below's values, the median and quartiles.

Usage: pair_series.py OUTPUT_DIR [--pair-bulk 12] [--pair-skip 0.6 1.0] [--dx DX]
                      [--below 0.4 0.5 0.6] [--series] [--label NAME]
With --label the summary ends with one tab-separated line:
  NAME min t_min second third n_below... median
"""
import argparse
import math
import os
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "validation"))
from snapshots import lattice_spacing, particle_arrays, snapshots  # noqa: E402
from check_run import cell_pairs, neighbour_counts  # noqa: E402


def close_pairs(pos, r):
    """(i, j, d) of every pair of the points pos = (x, y[, z]) closer than r (cells of size r)."""
    pairs = list(cell_pairs(pos, r))
    if not pairs:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty, np.zeros(0)
    i = np.concatenate([p[0] for p in pairs])
    j = np.concatenate([p[1] for p in pairs])
    d = np.sqrt(sum((c[i] - c[j]) ** 2 for c in pos))
    keep = d < r
    return i[keep], j[keep], d[keep]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("--fluid", default="fluid")
    ap.add_argument("--dx", type=float, default=None)
    ap.add_argument("--pair-bulk", type=int, default=12)
    ap.add_argument("--pair-skip", type=float, nargs=2, action="append", default=[])
    ap.add_argument("--below", type=float, nargs="+", default=[0.4, 0.5, 0.6])
    ap.add_argument("--series", action="store_true")
    ap.add_argument("--label", default=None)
    ap.add_argument("--cut", type=float, default=0.8,
                    help="pairs are looked for below this many dx (default 0.8); a snapshot "
                         "with no bulk pair closer reports the cut")
    args = ap.parse_args()
    files = snapshots(args.out, "pair_series.py")
    if files is None:
        return 2
    dx = args.dx
    rows = []  # (d, t, x, y, n_bulk)
    for path in files:
        with h5py.File(path, "r") as f:
            t, dim, arrays = particle_arrays(f)
            fl = arrays[args.fluid]
            pos = [np.asarray(fl[c][()], dtype=float) for c in ("x", "y", "z")[:dim or 2]]
        if any(a <= t <= b for a, b in args.pair_skip):
            continue
        if dx is None:
            dx = lattice_spacing(pos)
        # The pairs closer than the cut, then the bulk test (>= pair_bulk others within
        # 2.6 dx, check_run.py's) for their particles only: the same minimum as check_run.py
        # wherever it is below the cut.
        pi, pj, pd = close_pairs(pos, args.cut * dx)
        cand = np.unique(np.concatenate([pi, pj]))
        isbulk = np.zeros(len(pos[0]), dtype=bool)
        if len(cand):
            isbulk[cand] = neighbour_counts(pos, 2.6 * dx, cand) >= args.pair_bulk
        ok = isbulk[pi] & isbulk[pj]
        if np.any(ok):
            k = int(np.flatnonzero(ok)[np.argmin(pd[ok])])
            d = pd[k] / dx
            i, j = int(pi[k]), int(pj[k])
            xy = tuple(0.5 * (c[i] + c[j]) for c in pos)
        else:
            d = args.cut
            xy = (math.nan,) * len(pos)
        rows.append((d, t, xy))
        if args.series:
            print("t = %.4f  closest bulk pair %.4f dx  at (%s)"
                  % (t, d, ", ".join("%.3f" % c for c in xy)))
    if not rows:
        sys.stderr.write("pair_series.py: every snapshot skipped\n")
        return 2
    ds = np.array([r[0] for r in rows])
    order = np.argsort(ds, kind="stable")
    lo = rows[order[0]]
    print("%s: %d snapshots judged; closest bulk pair %.4f dx at t = %.4f (%s)"
          % (args.out, len(rows), lo[0], lo[1], ", ".join("%.3f" % c for c in lo[2])))
    nxt = [rows[k] for k in order[1:6]]
    print("  next smallest snapshots: " + ", ".join("%.4f (t = %.2f)" % (r[0], r[1]) for r in nxt))
    q1, med, q3 = np.percentile(ds, [25, 50, 75])
    print("  below " + ", ".join("%g dx: %d" % (b, int((ds < b).sum())) for b in args.below)
          + "; quartiles %.4f / %.4f / %.4f dx" % (q1, med, q3))
    if args.label:
        sec = rows[order[1]][0] if len(rows) > 1 else math.nan
        thr = rows[order[2]][0] if len(rows) > 2 else math.nan
        print("\t".join([args.label, "%.4f" % lo[0], "%.4f" % lo[1], "%.4f" % sec, "%.4f" % thr]
                        + ["%d" % int((ds < b).sum()) for b in args.below] + ["%.4f" % med]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
