#!/usr/bin/env python3
"""Every bundled example on every backend: builds each examples/*.sph (and, for a scene with
compile-time options, each choice of each option, the others at their defaults) with
--backend=serial, openmp and, with --opencl, opencl; runs each for a few steps writing a
snapshot at every step; and compares every snapshot with the serial one:

  openmp (2 threads): bitwise (h5diff), since every parallel loop is a gather that sums its
          neighbours in the serial order and reductions are summed in the serial order;
  opencl (double):    within rtol 1e-10 of each property's scale (h5close.py; the reasons it
          is not bitwise and the margin are in tests/lit/backends/opencl-serial-equal.sph).

With --precision single every solver is built with --precision=single (the scene computes on
float copies of its arrays, periodic and mirror ghosts included) and the serial single run is
the reference: the OpenMP one must equal it bitwise as above (the float arithmetic is in the
same order on both). The single runs are not compared with the double ones here (that needs
a tolerance per scene: tests/lit/backends/single-double.sph, tests/lit/domain/
single-precision.sph); --opencl is refused with single for the same reason.

A new example is covered by being in examples/: nothing to register. A case that a backend
cannot run yet is named with --skip SCENE[:CHOICE]:BACKEND and reported as skipped, so the
exclusions are visible in the RUN line of the test that calls this script; likewise
--rtol CASE=R widens the OpenCL tolerance of one case, and --scale CASE:NAME=S gives a
dataset of one case (an example's name: each choice of its options) a physical scale (h5close.py --scale; the test says why).

usage: every_example.py --sphc SPHC --examples DIR --out DIR [--opencl] [--steps N]
                        [--precision double|single]
                        [--skip CASE:BACKEND ...] [--rtol CASE=R ...]
                        [--scale CASE:NAME=S ...] [--only NAME ...]
Prints one line per case and backend ('ok', 'skipped' or what failed) and a closing line
'N passed, N failed, N skipped'; exits 1 if anything failed.
"""
import argparse
import glob
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
OPTION = re.compile(r'^\s*option\s+(\w+)\s+in\s+\[([^\]]*)\]\s*=\s*(\w+)\s*;', re.M)


def cases(path):
    """(case name, [sphc -D flags]) for a scene: the default build, then every non-default
    choice of each option."""
    scene = os.path.splitext(os.path.basename(path))[0]
    with open(path) as f:
        text = f.read()
    # Comments may mention `option`: only declarations at the start of a line count.
    out = [(scene, [])]
    for name, choices, default in OPTION.findall(text):
        for c in (c.strip() for c in choices.split(',')):
            if c and c != default:
                out.append((scene + ':' + c, ['-D', name + '=' + c]))
    return out


def run(cmd, log):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        log.append('$ ' + ' '.join(cmd) + '\n' + r.stdout[-2000:] + r.stderr[-2000:])
    return r.returncode == 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--sphc', required=True)
    ap.add_argument('--examples', required=True)
    ap.add_argument('--out', required=True)
    ap.add_argument('--opencl', action='store_true')
    ap.add_argument('--steps', type=int, default=12)
    ap.add_argument('--skip', action='append', default=[])
    ap.add_argument('--rtol', action='append', default=[])
    ap.add_argument('--scale', action='append', default=[])
    ap.add_argument('--only', action='append', default=[])
    ap.add_argument('--precision', choices=['double', 'single'], default='double')
    a = ap.parse_args()
    if a.precision == 'single' and a.opencl:
        ap.error('--opencl compares with a double tolerance: not with --precision single')
    # Every build writes the particles' global ids: the CPU backends keep the arrays of the
    # cluster-pair tiles in the tiles' slot order (docs/performance-log.md, "Particles in the
    # tiles' slot order (stop 40)"), the device in cell order, so OpenCL's snapshots are
    # compared particle by particle through gid (h5close.py --key gid); serial and OpenMP
    # keep the same order and are compared bitwise as they are.
    precision = ['--precision=' + a.precision, '--global-ids']

    backends = ['openmp'] + (['opencl'] if a.opencl else [])
    skip = set(a.skip)
    rtol = dict(r.split('=', 1) for r in a.rtol)
    scales = {}
    for sc in a.scale:
        c, rest = sc.split(':', 1)
        scales.setdefault(c, []).extend(['--scale', rest])
    passed = failed = skipped = 0
    examples = sorted(glob.glob(os.path.join(a.examples, '*.sph')))
    if not examples:
        print('no examples found in', a.examples)
        return 1
    for path in examples:
        for case, flags in cases(path):
            if a.only and case.split(':')[0] not in a.only:
                continue
            tag = case.replace(':', '_')
            exe = {}
            log = []
            for b in ['serial'] + backends:
                exe[b] = os.path.join(a.out, tag + '_' + b)
            # Serial is the reference: without it nothing of this case can be compared.
            outs = {}
            ok = run([a.sphc, path, '-o', exe['serial']] + flags + precision, log)
            if ok:
                outs['serial'] = os.path.join(a.out, tag + '_serial_out')
                ok = run([exe['serial'], '--max-steps', str(a.steps), '--output-every', '1e-12',
                          '-d', outs['serial'], '--quiet'], log)
            if not ok:
                print('%-32s serial  FAILED\n%s' % (case, '\n'.join(log)))
                failed += 1
                continue
            snaps = sorted(f for f in os.listdir(outs['serial']) if f.endswith('.h5'))
            # A scene may end before --steps (a static check ends at its tf): at least the
            # first and the last state; the other backends must write the same snapshots.
            if len(snaps) < 2:
                print('%-32s serial  FAILED: %d snapshots' % (case, len(snaps)))
                failed += 1
                continue
            passed += 1
            for b in backends:
                if case + ':' + b in skip or case.split(':')[0] + ':' + b in skip:
                    print('%-32s %-7s skipped (--skip)' % (case, b))
                    skipped += 1
                    continue
                log = []
                out = os.path.join(a.out, tag + '_' + b + '_out')
                threads = ['--threads', '2'] if b == 'openmp' else []
                ok = (run([a.sphc, path, '-o', exe[b], '--backend=' + b] + flags + precision, log) and
                      run([exe[b], '--max-steps', str(a.steps), '--output-every', '1e-12',
                           '-d', out, '--quiet'] + threads, log))
                bad = []
                if ok:
                    for s in snaps:
                        mine = os.path.join(out, s)
                        if not os.path.exists(mine):
                            bad.append(s + ' missing')
                            continue
                        ref = os.path.join(outs['serial'], s)
                        cmp = (['h5diff', ref, mine] if b == 'openmp' else
                               [sys.executable, os.path.join(HERE, 'h5close.py'), ref, mine,
                                '--rtol', rtol.get(case, '1e-10'), '--key', 'gid'] +
                                scales.get(case, scales.get(case.split(':')[0], [])))
                        r = subprocess.run(cmp, capture_output=True, text=True)
                        if r.returncode != 0:
                            bad.append(s + ': ' + (r.stdout + r.stderr).strip()[-400:])
                if ok and not bad:
                    print('%-32s %-7s ok (%d snapshots equal%s)' %
                          (case, b, len(snaps),
                           '' if b == 'openmp' else ' within ' + rtol.get(case, '1e-10')))
                    passed += 1
                else:
                    print('%-32s %-7s FAILED\n%s' % (case, b, '\n'.join(log + bad[:3])))
                    failed += 1
    print('%d passed, %d failed, %d skipped' % (passed, failed, skipped))
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
