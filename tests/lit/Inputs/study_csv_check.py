#!/usr/bin/env python3
"""Checks on the study.csv of `sphc study` (tests/lit/driver/study-*.sph).

  study_csv_check.py STUDY.csv --same COLUMN AXIS TOL
      the runs that differ only in the varied AXIS (and the repeat) give COLUMN within a
      relative TOL of each other (e.g. the error in double and single precision);

The varied axes are the columns before `code`. Exit 0 when every check holds, 1 otherwise."""
import csv
import sys


def main(argv):
    if len(argv) < 3:
        sys.stderr.write(__doc__)
        return 2
    with open(argv[1], newline="") as f:
        reader = csv.DictReader(f)
        cols = reader.fieldnames
        rows = [r for r in reader if r.get("status") == "ok"]
    axes = cols[:cols.index("code")]
    bad = []
    if argv[2] == "--same" and len(argv) == 6:
        col, axis, tol = argv[3], argv[4], float(argv[5])
        groups = {}
        for r in rows:
            key = tuple(r[a] for a in axes if a != axis)
            groups.setdefault(key, []).append((r[axis], float(r[col])))
        for key, vals in sorted(groups.items()):
            ref = max(abs(v) for _, v in vals)
            spread = max(v for _, v in vals) - min(v for _, v in vals)
            ok = spread <= tol * ref
            print("%s %s over %s: %s (spread %.3g, relative %.3g) %s"
                  % (col, " ".join(key), axis, ", ".join("%s %.10g" % p for p in vals),
                     spread, spread / ref if ref else 0.0, "ok" if ok else "FAIL"))
            if not ok:
                bad.append(key)
        if len(groups) == 0:
            bad.append("no runs")
    else:
        sys.stderr.write(__doc__)
        return 2
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
