#!/usr/bin/env python3
"""Compares a periodic run with the middle tile of a non-periodic run on a tiling of the box.

usage: periodic_tiles.py PERIODIC.h5 TILED.h5 [--L 1] [--rtol 1e-9]

A particle of the periodic run is matched with the particle of the tiled run that started at
the same place (properties x_start, y_start). Until a disturbance from the outer edge of the
tiling reaches the middle tile, the two runs solve the same problem, so positions (modulo
the period L), velocities and densities must agree within rounding: the sums over neighbours
run in another order and ghosts are shifted by L (rounding of x + L). Max differences are
printed relative to the scale of each property; exit 0 if all are <= rtol, else 1.
Needs h5dump only (reads through h5close.py).
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from h5close import read  # noqa: E402


def values(items, name):
    is_float, vals = items['fluid/' + name]
    return [float(v) for v in vals]


def main(argv):
    args = [a for a in argv[1:]]
    L, rtol = 1.0, 1e-9
    if '--L' in args:
        i = args.index('--L')
        L = float(args[i + 1])
        del args[i:i + 2]
    if '--rtol' in args:
        i = args.index('--rtol')
        rtol = float(args[i + 1])
        del args[i:i + 2]
    per, til = read(args[0]), read(args[1])
    key = lambda x0, y0: (round(x0 * 1e9), round(y0 * 1e9))
    index = {}
    tx0, ty0 = values(til, 'x_start'), values(til, 'y_start')
    for j, (a, b) in enumerate(zip(tx0, ty0)):
        index[key(a, b)] = j
    px0, py0 = values(per, 'x_start'), values(per, 'y_start')
    matched = [index.get(key(a, b)) for a, b in zip(px0, py0)]
    if any(j is None for j in matched):
        print('periodic_tiles: %d particles of the periodic run have no partner'
              % sum(j is None for j in matched))
        return 1
    worst = 0.0
    for name in ('x', 'y', 'u', 'v', 'rho', 'p'):
        a, b = values(per, name), values(til, name)
        if name in ('x', 'y'):
            # modulo the period: the closest image of the tiled particle
            diffs = [abs(((p - b[j]) + 0.5 * L) % L - 0.5 * L) for p, j in zip(a, matched)]
            scale = L
        else:
            diffs = [abs(p - b[j]) for p, j in zip(a, matched)]
            scale = max(max(abs(v) for v in a), 1e-300)
        rel = max(diffs) / scale
        worst = max(worst, rel)
        print('%-4s max |periodic - tiled| / scale = %.3g' % (name, rel))
    print('particles: %d; %s' % (len(px0), 'AGREE' if worst <= rtol else 'DIFFER'))
    return 0 if worst <= rtol else 1


if __name__ == '__main__':
    sys.exit(main(sys.argv))
