#!/usr/bin/env python3
"""Checks that every value of datasets of an sphc output file (HDF5) lies in an interval,
through h5dump (no h5py needed).

usage: h5range.py FILE.h5 DATASET LO HI [DATASET LO HI ...]   (an end may be '-': unbounded)

Prints 'DATASET min max' for each; exit 1 naming each dataset with a value outside.
"""
import subprocess
import sys


def values(path, dataset):
    text = subprocess.run(['h5dump', '-m', '%.17g', '-w', '0', '-d', dataset, path],
                          check=True, capture_output=True, text=True).stdout
    data = text[text.index('DATA {'):]
    out = []
    for line in data.splitlines()[1:]:
        line = line.strip()
        if line.startswith('}'):
            break
        if ':' in line:
            line = line.split(':', 1)[1]
        out += [float(v) for v in line.split(',') if v.strip()]
    return out


def main(argv):
    if len(argv) < 5 or (len(argv) - 2) % 3:
        sys.exit(__doc__)
    path, ok = argv[1], True
    for k in range(2, len(argv), 3):
        name, lo, hi = argv[k], argv[k + 1], argv[k + 2]
        v = values(path, '/' + name.lstrip('/'))
        print(f'{name} {min(v):.6g} {max(v):.6g}')
        if (lo != '-' and min(v) < float(lo)) or (hi != '-' and max(v) > float(hi)):
            print(f'error: {name} has values outside [{lo}, {hi}]', file=sys.stderr)
            ok = False
    sys.exit(0 if ok else 1)


if __name__ == '__main__':
    main(sys.argv)
