#!/usr/bin/env python3
"""Compares a single-precision sphc run with the double-precision run of the same scene
(through h5dump, like h5close.py, so it needs no h5py or numpy).

usage: precision_compare.py DOUBLE.h5 SINGLE.h5 --id x00,y00 --rtol R [--prop-rtol p=R ...]
                            [--verbose]

1. Storage: every floating point value of every dataset of SINGLE must be a float (a double
   that survives the round trip through IEEE single). A solver that kept a property in double
   by mistake fails here, as one that copied doubles out without computing in float would.
2. Accuracy: the particle order of the two runs may differ (cell coordinates from rounded
   positions), so particles are matched by the --id properties (per-particle values set at
   start-up and never changed, e.g. the initial position: unique, and equal in both runs up
   to float rounding). For each property, max |a - b| <= rtol * max(max|a|, max|b|) (the
   error relative to the property's scale), with --prop-rtol overriding rtol per property.
Exit 0 if both hold, else 1 naming what does not.
"""
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from h5close import read  # noqa: E402


def is_float32(v):
    return v != v or struct.unpack('f', struct.pack('f', v))[0] == v


def arrays(items):
    """{'fluid': {'x': [floats]}} for the floating point datasets."""
    out = {}
    for key, (is_float, values) in items.items():
        if not is_float or '@' in key or '/' not in key:
            continue
        array, prop = key.rsplit('/', 1)
        out.setdefault(array, {})[prop] = [float(v) for v in values]
    return out


def main(argv):
    rtol, prop_rtol, ids, verbose, files = None, {}, [], False, []
    i = 1
    while i < len(argv):
        a = argv[i]
        if a == '--rtol':
            rtol = float(argv[i + 1]); i += 1
        elif a == '--prop-rtol':
            name, value = argv[i + 1].split('='); prop_rtol[name] = float(value); i += 1
        elif a == '--id':
            ids = argv[i + 1].split(','); i += 1
        elif a == '--verbose':
            verbose = True
        else:
            files.append(a)
        i += 1
    if len(files) != 2 or rtol is None or not ids:
        sys.stderr.write(__doc__)
        return 2
    da, sa = arrays(read(files[0])), arrays(read(files[1]))
    bad = []
    for array, props in sorted(sa.items()):
        for prop, values in sorted(props.items()):
            n = sum(0 if is_float32(v) else 1 for v in values)
            if n:
                bad.append('%s/%s: %d of %d values are not floats' % (array, prop, n, len(values)))
    for array, dprops in sorted(da.items()):
        sprops = sa.get(array)
        if sprops is None or any(k not in dprops or k not in sprops for k in ids):
            bad.append('%s: missing in the single run or without the id properties' % array)
            continue
        # Match: the single-run particle whose ids are nearest (within 1e-5 of their scale,
        # while float rounding moves them by ~6e-8), found through a grid of that size.
        n = len(dprops[ids[0]])
        if len(sprops[ids[0]]) != n:
            bad.append('%s: %d vs %d particles' % (array, n, len(sprops[ids[0]])))
            continue
        cell = [1e-5 * (max(abs(v) for v in dprops[k]) or 1.0) for k in ids]
        grid = {}
        for j in range(n):
            key = tuple(int(sprops[k][j] // c) for k, c in zip(ids, cell))
            grid.setdefault(key, []).append(j)
        perm, used = [], set()
        for j in range(n):
            v = [dprops[k][j] for k in ids]
            base = [int(x // c) for x, c in zip(v, cell)]
            best = None
            for off in range(3 ** len(ids)):
                key = tuple(b + (off // 3 ** a) % 3 - 1 for a, b in enumerate(base))
                for m in grid.get(key, []):
                    d = max(abs(sprops[k][m] - x) for k, x in zip(ids, v))
                    if best is None or d < best[0]:
                        best = (d, m)
            if best is None or best[1] in used:
                break
            used.add(best[1])
            perm.append(best[1])
        if len(perm) != n:
            bad.append('%s: the id properties do not match particles one to one' % array)
            continue
        for prop, a in sorted(dprops.items()):
            if prop in ids:
                continue
            if prop not in sprops:
                bad.append('%s/%s: missing in the single run' % (array, prop))
                continue
            b = [sprops[prop][j] for j in perm]
            scale = max([abs(x) for x in a + b] + [0.0])
            err = max([abs(x - y) for x, y in zip(a, b)] + [0.0])
            rel = err / scale if scale > 0 else err
            tol = prop_rtol.get(prop, rtol)
            if verbose:
                print('precision_compare: %s %s/%s: relative difference %.3g (tolerance %g)' %
                      (os.path.basename(files[0]), array, prop, rel, tol))
            if not rel <= tol:
                bad.append('%s/%s: relative difference %.3g > %g' % (array, prop, rel, tol))
    for line in bad:
        print('precision_compare: %s vs %s: %s' % (files[0], files[1], line))
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
