#!/usr/bin/env python3
"""Prints the largest |value| of datasets of an sphc output file, through h5dump.

usage: h5max.py FILE.h5 DATASET... [--below LIMIT]

Prints 'max |DATASET| = X' per dataset; with --below, also 'below LIMIT' or 'NOT below LIMIT'
and exits 1 when one is not.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from h5close import read  # noqa: E402


def main(argv):
    args = argv[1:]
    limit = None
    if '--below' in args:
        i = args.index('--below')
        limit = float(args[i + 1])
        del args[i:i + 2]
    items = read(args[0])
    ok = True
    for name in args[1:]:
        m = max(abs(float(v)) for v in items[name][1])
        line = 'max |%s| = %.3g' % (name, m)
        if limit is not None:
            below = m < limit
            ok &= below
            line += (' below %g' if below else ' NOT below %g') % limit
        print(line)
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main(sys.argv))
