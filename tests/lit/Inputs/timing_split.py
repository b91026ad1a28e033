#!/usr/bin/env python3
"""Checks a solver's --timing output (stdin) for the per-group lines: at least --groups
`timing-group:` lines, each with s >= 0; their sum equals the `timing-split:` line's groups_s
(to its printed precision); every part of the split is >= 0 (up to clock resolution, 1e-3 of
wall_s) and the parts add up to wall_s, which equals the `timing:` line's; the groups and the
neighbour search take at least --min-share of wall_s (the equations are the step's work, so
timing them must account for most of it). Prints one line 'timing split ok: ...' or what is
wrong, and exits 1 then."""
import argparse
import re
import sys


def fields(line):
    return dict(kv.split("=", 1) for kv in line.split()[1:] if "=" in kv)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--groups", type=int, default=1)
    ap.add_argument("--min-share", type=float, default=0.5)
    a = ap.parse_args()
    timing, split, groups = None, None, []
    for line in sys.stdin:
        if line.startswith("timing: "):
            timing = fields(line)
        elif line.startswith("timing-split: "):
            split = {k: float(v) for k, v in fields(line).items()}
        elif line.startswith("timing-group: "):
            groups.append(fields(line))
    bad = []
    if timing is None or split is None:
        bad.append("no timing: or timing-split: line")
    elif len(groups) < a.groups:
        bad.append("%d timing-group lines, expected >= %d" % (len(groups), a.groups))
    else:
        wall = split["wall_s"]
        eps = 1e-3 * wall + 1e-6
        if abs(wall - float(timing["wall_s"])) > 1e-5 * wall:
            bad.append("wall_s %g != timing's %s" % (wall, timing["wall_s"]))
        s = [float(g["s"]) for g in groups]
        if min(s) < 0:
            bad.append("a group with negative time: %s" % s)
        if abs(sum(s) - split["groups_s"]) > 1e-5 * wall + 1e-6 * len(s):
            bad.append("the groups sum to %g, groups_s = %g" % (sum(s), split["groups_s"]))
        parts = ["groups_s", "nnps_s", "integrator_s", "outside_steps_s"]
        for p in parts:
            if split[p] < -eps:
                bad.append("%s = %g < 0" % (p, split[p]))
        total = sum(split[p] for p in parts)
        if abs(total - wall) > eps:
            bad.append("the parts add up to %g, wall_s = %g" % (total, wall))
        share = (split["groups_s"] + split["nnps_s"]) / wall if wall > 0 else 0
        if share < a.min_share:
            bad.append("groups and neighbour search %.3f of wall_s < %g" % (share, a.min_share))
    if bad:
        print("timing split wrong: " + "; ".join(bad))
        return 1
    print("timing split ok: %d groups, groups+nnps %.2f of wall_s" % (len(groups), share))
    return 0


if __name__ == "__main__":
    sys.exit(main())
