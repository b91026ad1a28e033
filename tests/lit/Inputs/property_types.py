#!/usr/bin/env python3
"""Writes a scene (on stdout) in which every method kind reads and writes a property of every
type: double, int, uint and a strided double (double[3]).

Method kinds: an equation's `initialize`, `loop` (destination reads and writes, and reads of
the source `s_`), `post_loop`, `reduce`, `converged` (of an iterated group), and the
stepper's `initialize` and `stage1` statements. Each method reads the four properties
`pd, pi, pu, pt` (double, int, uint, double[3]: given initial values) and writes four of its
own, `<kind>_d, <kind>_i, <kind>_u, <kind>_t`; everything is output, so nothing is pruned.
The loop runs over two sources, the fluid itself and a `wall` array with the same property
types, so source properties of more than one array are read by one loop body.

`--check OUT.h5` checks the snapshot after the first step of such a run against the values
computed here: they are sums of multiples of 1/8, exact in double and in single precision, so
every backend and precision must give them exactly (through h5close.py's h5dump reader).

`--periodic` (to both) makes x periodic on [0, 2]: the fluid and the wall then get ghosts,
which carry the source properties the loop reads (ints too), and neighbours are counted
through the period.

`--conflict` writes instead a scene where `tag` is an int in one source and a double in the
other, which one loop body cannot read as both (an error, tests/errors).
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

TYPES = [('d', 'double'), ('i', 'int'), ('u', 'uint'), ('t', 'double[3]')]


def reads(prefix, idx):
    """An expression reading every base property through `prefix` (d_ or s_), as a double."""
    return ('{p}pd[{i}] + {p}pi[{i}] + {p}pu[{i}] + {p}pt[3 * {i} + 1]'
            .format(p=prefix, i=idx))


def writes(kind, value, op='='):
    """Statements writing each of the method's own properties from `value` (a double)."""
    return '\n'.join([
        '    d_{k}_d[d_idx] {op} {v};'.format(k=kind, op=op, v=value),
        '    d_{k}_i[d_idx] {op} (int)({v}) - 3;'.format(k=kind, op=op, v=value),
        '    d_{k}_u[d_idx] {op} (unsigned int)({v}) + 1u;'.format(k=kind, op=op, v=value),
        '    for (int c = 0; c < 3; ++c) d_{k}_t[3 * d_idx + c] {op} c * ({v});'.format(
            k=kind, op=op, v=value),
    ])


KINDS = ['init', 'loop', 'post', 'red', 'sinit', 'stage']  # and converged, below


def scene(periodic=False):
    out = []
    out.append('param dx = 0.25;\n')
    for array, x0 in (('fluid', 0.0), ('wall', 1.0)):
        out.append('array %s {' % array)
        out.append('  geometry block(xmin = %g, xmax = %g, ymin = 0, ymax = 0.5, dx = dx);'
                   % (x0, x0 + 1.0))
        out.append('  property h = 1.3 * dx;')
        out.append('  property double pd = 0.5 + x;')
        out.append('  property int pi = 2;')
        out.append('  property uint pu = 3;')
        out.append('  property double[3] pt = y;')
        if array == 'fluid':
            for k in KINDS:
                for t, ty in TYPES:
                    out.append('  property %s %s_%s = 0;' % (ty, k, t))
            out.append('  const total = 0;')
            out.append('  const conv = 0;')
        out.append('}\n')
    out.append('equation AllKinds() {')
    out.append('  initialize {\n%s\n%s\n  }' % (writes('init', reads('d_', 'd_idx')),
                                              writes('loop', '0.0')))
    # Kernel-free, so that the sums over neighbours are exact (multiples of 1/8) in double
    # and single precision alike; RIJ keeps a pair quantity in the pass.
    out.append('  loop {\n%s\n  }' % writes(
        'loop', '%s + %s + 0.0 * RIJ' % (reads('s_', 's_idx'), reads('d_', 'd_idx')),
        op='+='))
    out.append('  post_loop {\n%s\n  }' % writes('post', reads('d_', 'd_idx')))
    out.append('  reduce sum total {\n%s\n    return %s;\n  }'
               % (writes('red', reads('d_', 'd_idx')), reads('d_', 'd_idx')))
    # converged runs once per iteration (d_idx is 0): it writes array constants only.
    out.append('  converged {\n    d_conv[0] = %s;\n    return %s > 0.0 ? 1 : -1;\n  }'
               % (reads('d_', 'd_idx'), reads('d_', 'd_idx')))
    out.append('}\n')
    out.append('stepper Types {')
    out.append('  initialize {\n%s\n  }' % writes('sinit', reads('d_', 'd_idx')))
    out.append('  stage1 {\n%s\n  }' % writes('stage', reads('d_', 'd_idx')))
    out.append('}\n')
    out.append('integrator Once { initialize; compute_accelerations; stage1; }\n')
    props = ['pd', 'pi', 'pu', 'pt', 'total', 'conv'] + [
        '%s_%s' % (k, t) for k in KINDS for t, _ in TYPES]
    out.append('scene types {')
    out.append('  dim = 2;\n  kernel = CubicSpline;\n  tf = 1.0;\n  dt = 1.0;')
    out.append('  integrator = Once;\n  stepper fluid = Types;')
    if periodic:  # ghosts of both arrays carry the properties the loop reads, ints too
        out.append('  domain { periodic x in [0, 2]; }')
    out.append('  output every 1.0 { fluid(%s); wall(pi); }' % ', '.join(props))
    out.append('  equations {')
    out.append('    group (iterate = true, max_iterations = 2) {')
    out.append('      AllKinds(dest = fluid, sources = [fluid, wall]);')
    out.append('    }\n  }\n}')
    return '\n'.join(out) + '\n'


def conflict():
    return '''param dx = 0.25;

array fluid {
  geometry block(xmin = 0, xmax = 1, ymin = 0, ymax = 0.5, dx = dx);
  property m = dx * dx;
  property h = 1.3 * dx;
  property int tag = 1;
  property count = 0;
}

array wall {
  geometry block(xmin = 1, xmax = 2, ymin = 0, ymax = 0.5, dx = dx);
  property m = dx * dx;
  property h = 1.3 * dx;
  property double tag = 0.5;
}

equation CountTags() {
  initialize { d_count[d_idx] = 0.0; }
  loop { d_count[d_idx] += s_tag[s_idx]; }
}

scene conflict {
  dim = 2;  kernel = CubicSpline;  tf = 1.0;  dt = 1.0;
  output every 1.0 { fluid(count); }
  equations {
    group { CountTags(dest = fluid, sources = [fluid, wall]); }
  }
}
'''


def check(path, periodic=False):
    sys.path.insert(0, HERE)
    from h5close import read
    items = read(path)

    def values(key):
        if key not in items:
            raise SystemExit('%s: no %s' % (path, key))
        return [float(v) for v in items[key][1]]

    def value(x, y):  # pd + pi + pu + pt[1] of a particle at (x, y)
        return (0.5 + x) + 2 + 3 + y

    fluid = list(zip(values('fluid/x'), values('fluid/y')))
    wall = list(zip(values('wall/x'), values('wall/y')))
    radius2 = (2 * 1.3 * 0.25) ** 2  # CubicSpline: 2 h
    expected = {}
    for k in KINDS:
        per = {t: [] for t, _ in TYPES}
        for (x, y) in fluid:
            v = value(x, y)
            if k != 'loop':
                terms, base = [v], {'d': 0.0, 'i': 0, 'u': 0, 't': 0.0}
            else:  # zeroed in initialize (int: -3, uint: 1), then one term per neighbour
                def dx(xj):  # the nearest image along x in the periodic box [0, 2]
                    d = x - xj
                    return d - 2.0 * round(d / 2.0) if periodic else d
                terms = [value(xj, yj) + v for (xj, yj) in fluid + wall
                         if dx(xj) ** 2 + (y - yj) ** 2 < radius2]
                base = {'d': 0.0, 'i': -3, 'u': 1, 't': 0.0}
            per['d'].append(base['d'] + sum(terms))
            per['i'].append(base['i'] + sum(int(w) - 3 for w in terms))
            per['u'].append(base['u'] + sum(int(w) + 1 for w in terms))
            per['t'].extend(c * sum(terms) for c in range(3))
        for t, _ in TYPES:
            expected['fluid/%s_%s' % (k, t)] = per[t]
    expected['fluid/constants@total'] = [sum(value(x, y) for (x, y) in fluid)]
    expected['fluid/constants@conv'] = [value(*fluid[0])]
    bad = []
    for key, want in sorted(expected.items()):
        got = values(key)
        if got != want:
            bad.append('%s: got %s, expected %s' % (key, got, want))
    for b in bad:
        print(b)
    print('%s: %d properties, %s' % (os.path.basename(path), len(expected),
                                     'all exact' if not bad else '%d wrong' % len(bad)))
    return 1 if bad else 0


if __name__ == '__main__':
    args = sys.argv[1:]
    periodic = '--periodic' in args
    if '--check' in args:
        sys.exit(check(args[args.index('--check') + 1], periodic))
    sys.stdout.write(conflict() if '--conflict' in args else scene(periodic))
