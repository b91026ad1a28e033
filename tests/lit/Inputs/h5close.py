#!/usr/bin/env python3
"""Compares two sphc output files (HDF5) within a relative tolerance, through h5dump (so it
needs hdf5-tools only, no h5py or numpy).

usage: h5close.py A.h5 B.h5 [--rtol 1e-10] [--sorted] [--verbose] [--scale NAME=S ...]

Every dataset and attribute of A must exist in B with as many values. Floating point ones
must satisfy max|a - b| <= rtol * max(max|a|, max|b|): the error is relative to the scale of
the property (a relative error per value means nothing for values that cross zero, such as
velocities). --scale NAME=S (NAME as printed, e.g. fluid/arho) makes the scale of that
dataset at least S: for a property that is exactly zero up to round-off (a patch test), its
own largest value is round-off and says nothing; S is then its physical scale. Integers and strings must be equal. --sorted compares the sorted values of each
floating point dataset (for runs whose particle order may differ, e.g. single precision). --key
NAME (e.g. gid, written by sphc --global-ids) compares the particles of each array in the order
of its dataset NAME (the same particle with itself where the runs sorted them differently).
Exit 0 if they agree, else 1 naming each property that does not.
"""
import re
import subprocess
import sys

INDEX = re.compile(r'\(\d+(?:,\d+)*\):')


def read(path):
    """{'fluid/p': [is_float, [values as str]]} from h5dump's text."""
    text = subprocess.run(['h5dump', '-m', '%.17g', '-w', '0', path], check=True,
                          capture_output=True, text=True).stdout
    items, stack = {}, []  # stack of (kind, name) per open brace
    for raw in text.splitlines():
        line = raw.strip()
        if line.endswith('{'):
            m = re.match(r'(GROUP|DATASET|ATTRIBUTE) "(.*)" \{$', line)
            kind, name = (m.group(1), m.group(2)) if m else (line.split()[0], '')
            stack.append((kind, name))
            if kind in ('DATASET', 'ATTRIBUTE'):
                path = '/'.join(n for k, n in stack[:-1] if k in ('GROUP', 'DATASET') and
                                n != '/')
                key = path + ('@' if kind == 'ATTRIBUTE' else '/') + name
                items[key] = [False, []]
                stack[-1] = (kind, name, key)
            continue
        if line == '}':
            stack.pop()
            continue
        owner = next((e[2] for e in reversed(stack) if len(e) == 3), None)
        if owner is None:
            continue
        if line.startswith('DATATYPE') and len(stack[-1]) == 3:
            items[owner][0] = 'IEEE_F' in line
        elif stack and stack[-1][0] == 'DATA':
            values = INDEX.sub('', line)
            items[owner][1].extend(v.strip() for v in values.split(',') if v.strip())
    return items


def by_key(items, key):
    """Each array's datasets (GROUP/NAME) in the order of its dataset GROUP/key; a dataset of
    S values per particle keeps its S values together."""
    orders = {}
    for name, (_, ids) in items.items():
        if '@' not in name and name.endswith('/' + key) and ids:
            orders[name[:-len(key) - 1]] = sorted(range(len(ids)), key=lambda k: float(ids[k]))
    for name, entry in items.items():
        order = orders.get(name.rsplit('/', 1)[0]) if '@' not in name else None
        if not order or len(entry[1]) % len(order):
            continue
        stride = len(entry[1]) // len(order)
        entry[1] = [entry[1][k * stride + c] for k in order for c in range(stride)]


def main(argv):
    rtol, verbose, ordered, files, floor, key = 1e-10, False, True, [], {}, None
    i = 1
    while i < len(argv):
        if argv[i] == '--rtol':
            rtol = float(argv[i + 1])
            i += 1
        elif argv[i] == '--scale':
            name, value = argv[i + 1].split('=', 1)
            floor[name] = float(value)
            i += 1
        elif argv[i] == '--verbose':
            verbose = True
        elif argv[i] == '--sorted':
            ordered = False
        elif argv[i] == '--key':
            key = argv[i + 1]
            i += 1
        else:
            files.append(argv[i])
        i += 1
    a_items, b_items = read(files[0]), read(files[1])
    if key:
        by_key(a_items, key)
        by_key(b_items, key)
    bad, worst = [], (0.0, '')
    for name, (is_float, va) in sorted(a_items.items()):
        if name not in b_items:
            bad.append(name + ': missing')
            continue
        vb = b_items[name][1]
        if len(va) != len(vb):
            bad.append('%s: %d vs %d values' % (name, len(va), len(vb)))
            continue
        if not is_float:
            if va != vb:
                bad.append(name + ': values differ')
            continue
        fa, fb = [float(x) for x in va], [float(x) for x in vb]
        if not ordered:
            fa, fb = sorted(fa), sorted(fb)
        scale = max([abs(x) for x in fa + fb] + [floor.get(name, 0.0)])
        diffs = [abs(x - y) for x, y in zip(fa, fb)]
        err = max(diffs + [0.0])
        rel = err / scale if scale > 0 else err
        if rel != rel:  # NaN somewhere
            bad.append(name + ': NaN')
            continue
        if rel > worst[0]:
            worst = (rel, name)
        if rel > rtol:
            k = diffs.index(err)
            bad.append('%s: relative difference %.3g > %g (value %d: %s vs %s)' %
                       (name, rel, rtol, k, va[k], vb[k]))
    for line in bad:
        print('h5close: %s vs %s: %s' % (files[0], files[1], line))
    if verbose:
        print('h5close: %s: worst relative difference %.3g (%s)' % (files[0], worst[0], worst[1]))
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
