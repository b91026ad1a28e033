#!/usr/bin/env python3
"""Pair interactions per second per core, and the cost per particle-step from 10k to 1M
particles: prints figures, is not a test.

Pair rate (default): for each scene, the serial solver runs a few steps (`--max-steps N
--timing`, first and last state written), and the pairs one step evaluates are counted from
the last state's positions with a KD-tree (scipy): for every (destination, source) pair of
arrays of the main interaction group, the neighbours within the kernel support 2h (the
particle itself excluded). Then

    pairs / s / core = pairs per step x steps / wall time of the time loop (serial)

which counts the whole step (equation of state, neighbour search, steppers) against the
pairs, as the peers' figures do. Beside it: DualSPHysics 5.4's rates measured on this kind of
machine (docs/performance.md, shared field notes): CaseDambreakVal2D 0.62-0.66 us per
particle-step (~32 M pairs/s/core) and CaseDambreak (3D, 171,496 particles, ~163 neighbours)
5.9 us per particle-step, i.e. 163 / 5.9 us = 27.6 M pairs/s/core.

Scenes: examples/dambreak.sph (2D, dx = 0.03, WendlandQuintic, h = 1.3 dx), bench/cube.sph
(3D, 103,823 particles, cubic spline, h = 1.5 dx) and bench/dambreak3d_dualsphysics.sph
(DualSPHysics' CaseDambreak parameters: 3D, dp = 0.0085, h = sqrt(3) dp, cubic spline).

--scaling: then bench/scaling.py (the cost per particle-step from 10k to 1M particles) with
the serial backend; --max-particles caps its sizes. --scaling-only: that alone.

Usage:
  python3 bench/pair_rate.py [--steps 10] [--scenes dambreak2d,cube,...] [--scaling]
                             [--max-particles 1100000] [--sphc build/bin/sphc] [--keep]
                             [--sphc-opt=--simd-pairs=cluster ...]
"""

import argparse
import glob
import os
import re
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from common import children_cpu, load_average, print_machine, remove_tmp  # noqa: E402
TIMING_RE = re.compile(r"timing: steps=(\d+) particles=(\d+) wall_s=([0-9.eE+-]+)")

# name: (source, defines, h at the scene's default parameters, kernel support in h,
# [(dest, [sources])] of the main interaction group, dim)
SCENES = {
    "dambreak2d": ("examples/dambreak.sph", [], 1.3 * 0.03, 2.0,
                   [("fluid", ["fluid", "boundary"]), ("boundary", ["fluid"])], 2),
    "cube": ("bench/cube.sph", [], 1.5 / 47, 2.0, [("fluid", ["fluid"])], 3),
    "dambreak3d_dualsphysics": ("bench/dambreak3d_dualsphysics.sph", [],
                                3 ** 0.5 * 0.0085, 2.0,
                                [("fluid", ["fluid", "boundary"]), ("boundary", ["fluid"])],
                                3),
}
DUALSPHYSICS = {"2D (CaseDambreakVal2D)": 32e6,
                "3D (CaseDambreak, 163 nb)": 163 / 5.9e-6}


def run(cmd, env=None):
    c0 = children_cpu()
    t0 = time.perf_counter()
    p = subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       universal_newlines=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        sys.stderr.write("command failed (exit %d): %s\n%s\n"
                         % (p.returncode, " ".join(cmd), p.stdout[-3000:]))
        raise SystemExit(1)
    return p.stdout, wall, children_cpu() - c0


def build(sphc, scene, tmp, backend="serial", sphc_opts=()):
    src, defines = SCENES[scene][0], SCENES[scene][1]
    exe = os.path.join(tmp, scene + "_" + backend)
    env = dict(os.environ)
    env.setdefault("SPHC_CACHE_DIR", os.path.join(tmp, "cache"))
    run([sphc, os.path.join(ROOT, src), "-o", exe, "--backend=" + backend] + defines +
        list(sphc_opts), env=env)
    return exe


def solve(exe, steps, extra, outdir=None, threads=1):
    env = dict(os.environ)
    env["OMP_NUM_THREADS"] = str(threads)
    env.setdefault("OMP_WAIT_POLICY", "passive")
    cmd = [exe, "--max-steps", str(steps), "--timing", "--quiet"] + extra
    if threads > 1:
        cmd += ["--threads", str(threads)]
    if outdir:
        cmd += ["-d", outdir, "--output-every", "1e9"]
    else:
        cmd += ["--no-output"]
    out, wall, cpu = run(cmd, env)
    m = TIMING_RE.search(out)
    if not m:
        raise SystemExit("no timing line from %s:\n%s" % (cmd, out[-2000:]))
    return dict(steps=int(m.group(1)), particles=int(m.group(2)), loop=float(m.group(3)),
                wall=wall, cpu=cpu, out=out)


def last_positions(outdir, scene):
    """{array: positions (n x dim)} of the last snapshot in outdir."""
    import h5py
    import numpy as np
    files = sorted(glob.glob(os.path.join(outdir, "*.h5")),
                   key=lambda f: int(re.search(r"_(\d+)\.h5$", f).group(1)))
    dim = SCENES[scene][5]
    with h5py.File(files[-1], "r") as f:
        pos = {}
        for name in f:
            g = f[name]
            if not hasattr(g, "keys") or "x" not in g:
                continue
            pos[name] = np.stack([np.asarray(g[a][()], dtype=float)
                                  for a in ("x", "y", "z")[:dim]], axis=1)
    return pos


def pairs_per_step(pos, h, groups, support, sample=None):
    """Pairs (destination particle, source particle) within support * h, the particle itself
    excluded, summed over groups [(dest, [sources])]; and the mean per destination array.
    With sample = K, destination arrays of more than K particles are counted on K of them
    (every (n / K)-th) and the sum scaled to all."""
    import numpy as np
    from scipy.spatial import cKDTree
    trees = {}
    total = 0
    per_dest = {}
    for dest, sources in groups:
        n = 0
        d = pos[dest]
        stride = max(1, len(d) // sample) if sample else 1
        for src in sources:
            if src not in trees:
                trees[src] = cKDTree(pos[src])
            cnt = trees[src].query_ball_point(d[::stride], r=support * h, return_length=True)
            n += (float(np.mean(cnt)) - (1 if src == dest else 0)) * len(d)
        n = int(round(n))
        per_dest[dest] = n / len(d)
        total += n
    return total, per_dest


def pair_rates(args, tmp):
    import numpy as np
    rows = []
    for scene in args.scenes.split(","):
        print("%s: compiling ..." % scene, flush=True)
        exe = build(args.sphc, scene, tmp, sphc_opts=args.sphc_opt)
        out = os.path.join(tmp, scene + "-out")
        extra = ["--tf", "100"]   # the step count decides, not the scene's tf (cube: 5 steps)
        one = solve(exe, 1, extra)
        # at least --steps, and at least --particle-steps / particles (small scenes)
        steps = max(args.steps, int(args.particle_steps / one["particles"]) + 1)
        print("%s: %d particles, %d steps ..." % (scene, one["particles"], steps), flush=True)
        r = solve(exe, steps, extra, outdir=out)
        pos = last_positions(out, scene)
        _, _, h, support, groups, _ = SCENES[scene]
        pairs, per_dest = pairs_per_step(pos, h, groups, support)
        loop = r["loop"]
        steps = r["steps"]
        rows.append(dict(scene=scene, particles=r["particles"], steps=steps, pairs=pairs,
                         nb=per_dest, us=1e6 * loop / (steps * r["particles"]),
                         rate_wall=pairs * steps / loop,
                         rate_cpu=pairs * (steps - 1) / max(r["cpu"] - one["cpu"], 1e-9)))
    print()
    print("%-26s %9s %6s %12s %16s %9s %14s %14s" % (
        "scene (serial)", "particles", "steps", "pairs/step", "neighbours (dest)",
        "us/p-step", "Mpairs/s wall", "Mpairs/s CPU"))
    for r in rows:
        nb = ", ".join("%s %.1f" % (k, v) for k, v in r["nb"].items())
        print("%-26s %9d %6d %12d %16s %9.3f %14.1f %14.1f" % (
            r["scene"], r["particles"], r["steps"], r["pairs"], nb, r["us"],
            r["rate_wall"] / 1e6, r["rate_cpu"] / 1e6))
    print()
    for k, v in DUALSPHYSICS.items():
        print("DualSPHysics 5.4 %-28s %6.1f M pairs/s/core (measured on this kind of machine,"
              " idle)" % (k + ":", v / 1e6))
    for r in rows:
        ref = DUALSPHYSICS["3D (CaseDambreak, 163 nb)"] if r["scene"] != "dambreak2d" \
            else DUALSPHYSICS["2D (CaseDambreakVal2D)"]
        print("%-26s sphc / DualSPHysics per pair: %.2fx (wall), %.2fx (CPU)"
              % (r["scene"], r["rate_wall"] / ref, r["rate_cpu"] / ref))
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sphc", default=os.path.join(ROOT, "build", "bin", "sphc"))
    ap.add_argument("--steps", type=int, default=10)
    ap.add_argument("--sphc-opt", action="append", default=[],
                    help="an sphc option for the pair-rate builds (repeatable), e.g. "
                         "--sphc-opt=--simd-pairs=cluster")
    ap.add_argument("--scenes", default="dambreak2d,cube,dambreak3d_dualsphysics")
    ap.add_argument("--scaling", action="store_true", help="cost from 10k to 1M particles")
    ap.add_argument("--scaling-only", action="store_true")
    ap.add_argument("--scaling-scenes", default="dambreak2d,cube")
    ap.add_argument("--max-particles", type=int, default=1100000)
    ap.add_argument("--particle-steps", type=float, default=3e6,
                    help="at least this many particle-steps per pair-rate run (default 3e6)")
    ap.add_argument("--keep", action="store_true")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="sphc-pairs-")
    load0 = load_average()
    try:
        if not args.scaling_only:
            pair_rates(args, tmp)
        if args.scaling or args.scaling_only:
            import scaling
            scaling.main(["--sphc", args.sphc, "--scenes", args.scaling_scenes,
                          "--backends", "serial", "--max-particles", str(args.max_particles)])
    finally:
        remove_tmp(tmp, args.keep)
    print_machine(load0)
    return 0


if __name__ == "__main__":
    sys.path.insert(0, HERE)
    sys.exit(main())
