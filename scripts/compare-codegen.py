#!/usr/bin/env python3
"""Compares the code two builds of sphc generate, and optionally what the solvers compute.

The safety net of a change to the code generator that must not change the generated solvers'
behaviour (issue 11: the schedule pass and the printers). REF is a build of sphc before the
change (copy its build tree's bin/sphc somewhere, or point at another worktree's build), NEW
the one after it. For every scene (by default every examples/*.sph, each choice of each
compile-time `option` as a case of its own, plus the scenes under tests/lit/Inputs) x backend
(serial, openmp, opencl) x precision (double, single):

  text   (always): `--emit=cpp` of both, and for opencl also `--emit=opencl`, must be equal
         after normalisation. Without --normalise the texts must be identical; with it,
         what issue 11 allows to change is ignored: comments (`// ...` to the end of a
         line), `#line` directives, `(void)x;` statements, blank lines and trailing
         blanks, and with --rename
         OLD=NEW (repeatable, a regular expression and its replacement) function names.
  run    (--run): both solvers are built and run for --steps steps, a snapshot at every
         step, and every snapshot is compared: serial and openmp bitwise (h5diff), opencl
         within --rtol (tests/lit/Inputs/h5close.py, as tests/lit/backends/every-example.sph
         does; OpenCL builds the same kernel source, but a device may not be deterministic
         across runs). With --run the verdict is the outputs': a case whose texts differ
         (say by a cleanup of the generated code) is 'equal' when its outputs are, and the
         line says how many lines of text differ.

A scene that the reference sphc rejects (say a scene that needs a newer compiler), or whose
reference solver fails to build or run (say it loads a file that a test writes first), is
reported as skipped, not compared. Cases with text differences print a unified diff (the
first --context lines of it).

usage: compare-codegen.py --ref REF_SPHC --new NEW_SPHC [--scenes GLOB ...]
                          [--backend B ...] [--precision P ...] [--normalise]
                          [--rename RE=REPL ...] [--run] [--steps N] [--rtol R]
                          [--out DIR] [--only NAME ...] [--context N]
Prints one line per case, then 'N equal, N different, N skipped'; exits 1 on a difference.
"""
import argparse
import difflib
import glob
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
# One list of a scene's cases (the default build, then each non-default choice of each
# compile-time option): the one every_example.py, the lit test of every example, uses.
sys.path.insert(0, os.path.join(ROOT, 'tests', 'lit', 'Inputs'))
from every_example import cases  # noqa: E402


def normalise(text, renames):
    lines = []
    for line in text.splitlines():
        if re.match(r'\s*#line\b', line):
            continue
        line = re.sub(r'\s*//.*$', '', line).rstrip()
        line = re.sub(r'\s*\(void\)\w+;', '', line)
        for pat, rep in renames:
            line = re.sub(pat, rep, line)
        if line:
            lines.append(line)
    return '\n'.join(lines) + '\n'


def emit(sphc, path, flags, kind):
    r = subprocess.run([sphc, path, '--emit=' + kind] + flags, capture_output=True, text=True)
    return r.returncode, r.stdout, r.stderr


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    return r.returncode == 0, (r.stdout + r.stderr)[-1500:]


class RefFailed(Exception):
    """The reference solver cannot be built or run (say it reads a file a test makes first):
    nothing to compare with."""


def compare_runs(a, path, flags, tag, backend):
    """Builds and runs both solvers; '' if every snapshot agrees, else what does not."""
    outs = {}
    for which, sphc in (('ref', a.ref), ('new', a.new)):
        exe = os.path.join(a.out, tag + '_' + which)
        ok, log = run([sphc, path, '-o', exe] + flags)
        if not ok and which == 'ref':
            raise RefFailed('build: ' + log.strip()[-200:])
        if not ok:
            return which + ' build failed: ' + log
        outs[which] = os.path.join(a.out, tag + '_' + which + '_out')
        threads = ['--threads', '2'] if backend == 'openmp' else []
        ok, log = run([exe, '--max-steps', str(a.steps), '--output-every', '1e-12', '-d',
                       outs[which], '--quiet'] + threads)
        if not ok and which == 'ref':
            raise RefFailed('run: ' + log.strip()[-200:])
        if not ok:
            return which + ' run failed: ' + log
    snaps = sorted(f for f in os.listdir(outs['ref']) if f.endswith('.h5'))
    if not snaps:
        return 'no snapshots'
    for s in snaps:
        mine = os.path.join(outs['new'], s)
        if not os.path.exists(mine):
            return s + ' missing'
        ref = os.path.join(outs['ref'], s)
        cmp = (['h5diff', ref, mine] if backend != 'opencl' else
               [sys.executable, os.path.join(ROOT, 'tests', 'lit', 'Inputs', 'h5close.py'), ref,
                mine, '--rtol', a.rtol])
        ok, log = run(cmd=cmp)
        if not ok:
            return s + ': ' + log.strip()[-400:]
    return ''


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--ref', required=True)
    ap.add_argument('--new', required=True)
    ap.add_argument('--scenes', action='append', default=[])
    ap.add_argument('--backend', action='append', default=[])
    ap.add_argument('--precision', action='append', default=[])
    ap.add_argument('--normalise', action='store_true')
    ap.add_argument('--rename', action='append', default=[])
    ap.add_argument('--run', action='store_true')
    ap.add_argument('--steps', type=int, default=5)
    ap.add_argument('--rtol', default='1e-10')
    ap.add_argument('--out')
    ap.add_argument('--only', action='append', default=[])
    ap.add_argument('--context', type=int, default=40)
    a = ap.parse_args()
    a.ref, a.new = os.path.abspath(a.ref), os.path.abspath(a.new)
    globs = a.scenes or [os.path.join(ROOT, 'examples', '*.sph'),
                         os.path.join(ROOT, 'tests', 'lit', 'Inputs', '*.sph')]
    backends = a.backend or ['serial', 'openmp', 'opencl']
    precisions = a.precision or ['double', 'single']
    renames = [tuple(r.split('=', 1)) for r in a.rename]
    if a.run and not a.out:
        a.out = tempfile.mkdtemp(prefix='compare-codegen-')
    if a.run:
        os.makedirs(a.out, exist_ok=True)
    equal = different = skipped = 0
    paths = sorted(p for g in globs for p in glob.glob(g))
    if not paths:
        print('no scenes found')
        return 1
    for path in paths:
        for case, dflags in cases(path):
            if a.only and case.split(':')[0] not in a.only:
                continue
            for b in backends:
                for p in precisions:
                    flags = dflags + ['--backend=' + b, '--precision=' + p]
                    name = '%s %s %s' % (case, b, p)
                    kinds = ['cpp'] + (['opencl'] if b == 'opencl' else [])
                    diffs, skip, changed = [], False, 0
                    for kind in kinds:
                        rc, ref, err = emit(a.ref, path, flags, kind)
                        if rc != 0:
                            skip = True
                            break
                        rc2, new, err2 = emit(a.new, path, flags, kind)
                        if rc2 != 0:
                            diffs.append('new sphc failed (--emit=%s): %s' % (kind, err2[-800:]))
                            continue
                        if a.normalise:
                            ref, new = normalise(ref, renames), normalise(new, renames)
                        if ref != new:
                            changed += sum(1 for l in difflib.ndiff(ref.splitlines(),
                                                                    new.splitlines())
                                           if l[:1] in '+-')
                            d = list(difflib.unified_diff(ref.splitlines(), new.splitlines(),
                                                          'ref --emit=' + kind,
                                                          'new --emit=' + kind, lineterm='',
                                                          n=2))
                            diffs.append('\n'.join(d[:a.context]))
                    if skip:
                        print('%-44s skipped (the reference sphc rejects it)' % name)
                        skipped += 1
                        continue
                    if a.run and not any(d.startswith('new sphc failed') for d in diffs):
                        tag = re.sub(r'[^A-Za-z0-9_]', '_', name)
                        try:
                            why = compare_runs(a, path, flags, tag, b)
                        except RefFailed as e:
                            print('%-44s skipped (the reference solver failed: %s)' %
                                  (name, str(e).replace('\n', ' ')))
                            skipped += 1
                            continue
                        if why:
                            diffs = ['outputs differ: ' + why]
                        else:
                            print('%-44s equal outputs (%s)' %
                                  (name, 'text identical' if not changed else
                                   '%d lines of text differ' % changed))
                            equal += 1
                            continue
                    if diffs:
                        print('%-44s DIFFERENT\n%s' % (name, '\n'.join(diffs)))
                        different += 1
                    else:
                        print('%-44s equal' % name)
                        equal += 1
    print('%d equal, %d different, %d skipped' % (equal, different, skipped))
    return 1 if different else 0


if __name__ == '__main__':
    sys.exit(main())
