#!/usr/bin/env python3
"""Cost per particle-step from 10k to 1M particles, 2D and 3D, serial and OpenMP: prints
figures, is not a test (issue 16, first part: flat within 25%, or the reason it is not).

Scenes: the 2D dam break (examples/dambreak.sph, WendlandQuintic, h = 1.3 dx; --dx, default
0.0158, 0.0088, 0.0047, 0.00265, 0.00143: about 10k, 30k, 100k, 300k and 1M particles) and
PySPH's 3D cube (bench/cube.sph, cubic spline, h = 1.5 dx; --nx, default 22, 32, 47, 68, 100).
Each is built serial and OpenMP (--threads, default 2; OMP_WAIT_POLICY=passive).

Each size runs a short and a long run of a fixed number of steps (--short, default 2;
--long, default 22); the difference divided by the steps between and the particles is the
figure, so set-up (particle creation, the first neighbour build, the first steps) is removed:

  CPU       user + system seconds of the solver process (all its threads);
  wall      wall seconds of the time loop (the solver's `--timing` line).

The rounds (--repeat, default 2) run every size and backend in turn, interleaved; the table
gives the lowest figure of the rounds and the spread (highest / lowest - 1). The other
columns, from one extra run of 0 steps that writes the initial state (h5py, scipy):

  fluid %      the share of the particles in the array `fluid` (the rest: walls);
  nb/particle  ordered pairs within the kernel support 2h (the particle itself excluded) of
               the main interaction group, per particle: a KD-tree count on the initial
               state (destinations sampled above 200k particles: the mean of 200k);
  arrays MB    particles x bytes per particle of each array (`sphc --report`): the
               properties only, not the neighbour lists;
  ns/pair      CPU per step / those pairs;
  nnps         the neighbour search's share of the loop's wall time (`--timing`);
  / first      CPU per particle-step against the scene's first (smallest) size, same backend.

Usage:
  python3 bench/scaling.py [--scenes dambreak2d,cube] [--backends serial,openmp] [--repeat 2]
                           [--dx 0.0158,...] [--nx 22,...] [--short 2] [--long 22]
                           [--max-particles 1100000] [--sphc build/bin/sphc] [--keep]
  python3 bench/scaling.py --quick      # tiny sizes, a few steps, one round: a smoke run
"""

import argparse
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from common import load_average, print_machine, remove_tmp  # noqa: E402
from pair_rate import SCENES, build, last_positions, pairs_per_step, solve  # noqa: E402

# scene: (parameter, default values, values of --quick, h at a value)
SIZES = {
    "dambreak2d": ("dx", [0.0158, 0.0088, 0.0047, 0.00265, 0.00143], [0.06, 0.045],
                   lambda dx: 1.3 * dx),
    "cube": ("nx", [22, 32, 47, 68, 100], [8, 10], lambda nx: 1.5 / nx),
}
COLUMNS = ("scene", "param", "particles", "fluid%", "nb/particle", "arrays_MB", "backend",
           "steps", "us/p-step_CPU", "spread", "us/p-step_wall", "ns/pair_CPU", "nnps",
           "/first")
NNPS_RE = re.compile(r"nnps_share=([0-9.eE+-]+)")


def bytes_per_particle(sphc, scene, tmp):
    """{array: bytes per particle} from `sphc --report`."""
    env = dict(os.environ)
    env.setdefault("SPHC_CACHE_DIR", os.path.join(tmp, "cache"))
    out = subprocess.run([sphc, os.path.join(ROOT, SCENES[scene][0]), "--report"]
                         + SCENES[scene][1], env=env, stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, universal_newlines=True).stdout
    return {m.group(1): int(m.group(2)) for m in
            re.finditer(r"^array (\w+) .*?(\d+) bytes per particle", out, re.M)}


def describe(exe, scene, extra, h, bpp, tmp, count_pairs):
    """Particles per array, pairs per step and array bytes from the initial state."""
    out = os.path.join(tmp, "init-%s" % abs(hash(tuple(extra))))
    solve(exe, 0, extra, outdir=out)
    pos = last_positions(out, scene)
    counts = {a: len(p) for a, p in pos.items()}
    pairs = None
    if count_pairs:
        try:
            pairs, _ = pairs_per_step(pos, h, SCENES[scene][4], SCENES[scene][3],
                                      sample=200000)
        except ImportError:
            pairs = None   # no scipy: the column shows '-'
    subprocess.run(["rm", "-rf", out])
    mb = sum(n * bpp.get(a, 0) for a, n in counts.items()) / 1e6
    return counts, pairs, mb


def timed(exe, steps, extra, threads):
    r = solve(exe, steps, extra, threads=threads)
    m = NNPS_RE.search(r.get("out", ""))
    r["nnps"] = float(m.group(1)) if m else None
    return r


def measure(args, tmp):
    scenes = [s for s in args.scenes.split(",") if s]
    backends = [b for b in args.backends.split(",") if b]
    cases = []          # (scene, value, extra, h)
    exes = {}
    info = {}
    for scene in scenes:
        param, values, quick, h_of = SIZES[scene]
        chosen = getattr(args, param)
        values = [float(v) if param == "dx" else int(v) for v in chosen.split(",")] \
            if chosen else (quick if args.quick else values)
        print("%s: compiling (%s) ..." % (scene, ", ".join(backends)), flush=True)
        for b in backends:
            exes[scene, b] = build(args.sphc, scene, tmp, backend=b)
        bpp = bytes_per_particle(args.sphc, scene, tmp)
        for v in values:
            extra = ["--set", "%s=%r" % (param, v), "--tf", "100"]  # steps decide, not tf
            counts, pairs, mb = describe(exes[scene, backends[0]], scene, extra, h_of(v), bpp,
                                         tmp, not args.no_neighbours)
            n = sum(counts.values())
            if n > args.max_particles:
                print("%s %s=%r: %d particles, above --max-particles: left out"
                      % (scene, param, v, n), flush=True)
                continue
            info[scene, v] = dict(particles=n, fluid=counts.get("fluid", 0) / n, pairs=pairs,
                                  mb=mb)
            cases.append((scene, v, extra))
    res = {}   # (scene, v, backend) -> [per-round dicts]
    for rnd in range(args.repeat):
        print("round %d of %d (load average %s) ..." % (rnd + 1, args.repeat, load_average()),
              flush=True)
        for scene, v, extra in cases:
            for b in backends:
                threads = args.threads if b == "openmp" else 1
                short = timed(exes[scene, b], args.short, extra, threads)
                long_ = timed(exes[scene, b], args.long, extra, threads)
                steps = long_["steps"] - short["steps"]
                n = long_["particles"]
                res.setdefault((scene, v, b), []).append(dict(
                    steps=steps, cpu=1e6 * (long_["cpu"] - short["cpu"]) / (steps * n),
                    wall=1e6 * (long_["loop"] - short["loop"]) / (steps * n),
                    nnps=long_["nnps"]))
    return cases, info, res, backends


def table(cases, info, res, backends, param_of):
    rows = []
    first = {}
    for scene, v, _ in cases:
        for b in backends:
            rs = res[scene, v, b]
            cpu = min(r["cpu"] for r in rs)
            first.setdefault((scene, b), cpu)
            i = info[scene, v]
            pairs = i["pairs"]
            rows.append([scene, "%s=%g" % (param_of[scene], v), str(i["particles"]),
                         "%.1f" % (100 * i["fluid"]),
                         "%.1f" % (pairs / i["particles"]) if pairs else "-",
                         "%.1f" % i["mb"], b, str(rs[0]["steps"]), "%.3f" % cpu,
                         "%.0f%%" % (100 * (max(r["cpu"] for r in rs) / cpu - 1))
                         if cpu > 0 else "-",
                         "%.3f" % min(r["wall"] for r in rs),
                         "%.2f" % (1e3 * cpu * i["particles"] / pairs) if pairs else "-",
                         "%.3f" % rs[-1]["nnps"] if rs[-1]["nnps"] is not None else "-",
                         "%.2f" % (cpu / first[scene, b]) if first[scene, b] > 0 else "-"])
    widths = [max(len(c), *(len(r[k]) for r in rows)) for k, c in enumerate(COLUMNS)] \
        if rows else [len(c) for c in COLUMNS]
    print()
    print("  ".join(c.rjust(w) for c, w in zip(COLUMNS, widths)))
    for r in rows:
        print("  ".join(c.rjust(w) for c, w in zip(r, widths)))
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sphc", default=os.path.join(ROOT, "build", "bin", "sphc"))
    ap.add_argument("--scenes", default="dambreak2d,cube")
    ap.add_argument("--backends", default="serial,openmp")
    ap.add_argument("--threads", type=int, default=2, help="OpenMP threads (default 2)")
    ap.add_argument("--dx", default="", help="dam-break spacings, comma-separated")
    ap.add_argument("--nx", default="", help="cube particles per side, comma-separated")
    ap.add_argument("--short", type=int, default=None, help="steps of the short run (2)")
    ap.add_argument("--long", type=int, default=None, help="steps of the long run (22)")
    ap.add_argument("--repeat", type=int, default=None, help="interleaved rounds (2)")
    ap.add_argument("--max-particles", type=int, default=1100000)
    ap.add_argument("--no-neighbours", action="store_true",
                    help="skip the KD-tree count (nb/particle and ns/pair show '-')")
    ap.add_argument("--quick", action="store_true",
                    help="smoke run: tiny sizes, 1 and 3 steps, one round")
    ap.add_argument("--keep", action="store_true")
    args = ap.parse_args(argv)
    for name, full, quick in (("short", 2, 1), ("long", 22, 3), ("repeat", 2, 1)):
        if getattr(args, name) is None:
            setattr(args, name, quick if args.quick else full)
    if args.long <= args.short:
        ap.error("--long must exceed --short")
    tmp = tempfile.mkdtemp(prefix="sphc-scaling-")
    load0 = load_average()
    try:
        cases, info, res, backends = measure(args, tmp)
        table(cases, info, res, backends, {s: SIZES[s][0] for s in SIZES})
    finally:
        remove_tmp(tmp, args.keep)
    print_machine(load0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
