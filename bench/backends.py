#!/usr/bin/env python3
"""sphc's backends and precisions side by side on the 2D dam break: prints figures, is not a
test.

One run builds examples/dambreak.sph six ways and times each at the default resolution
(dx = 0.03, ~3.4k particles) and at ~100k particles (--dx-large, default 0.0047):

    serial double, serial single, openmp double, openmp single (--threads N, default 2),
    opencl double, opencl single (the first OpenCL device, e.g. PoCL on the CPU;
    --opencl-device P,D picks another; skipped when sphc was built without OpenCL)

Each figure is microseconds per particle per step of the time loop (`--max-steps N
--no-output --timing`, best of --repeat runs), with the share of the neighbour search where
the solver measures it (CPU backends). Ratios: single / double time for each backend, and each
build against serial double (speed-up > 1 is faster). OpenCL builds its kernels at the first
launch and PoCL caches them, so the first OpenCL run of a scene is slower: a warm-up run of
one step precedes the timed ones.

Usage:
  python3 bench/backends.py [--sphc build/bin/sphc] [--threads 2] [--steps 500]
                            [--steps-large 50] [--dx-large 0.0047] [--repeat 2] [--quick]
--quick: 20 steps at dx = 0.03 and 3 at dx = 0.0047, one run each: checks that everything
builds and runs (a minute), the figures mean little.
"""

import argparse
import os
import re
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import (ROOT, DEFAULT_DX, cpu_model, remove_tmp, run,  # noqa: E402
                    serial_env, timing_line)

TIMING_RE = re.compile(r"timing: steps=(\d+) particles=(\d+) wall_s=([0-9.eE+-]+) "
                       r"us_per_particle_step=([0-9.eE+-]+) backend=(\w+) threads=(\d+) "
                       r"precision=(\w+)(?: nnps_s=([0-9.eE+-]+) nnps_share=([0-9.eE+-]+))?")

BUILDS = [("serial", "double"), ("serial", "single"), ("openmp", "double"),
          ("openmp", "single"), ("opencl", "double"), ("opencl", "single")]


def opencl_available(sphc):
    info = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(sphc))), "share", "sphc",
                        "buildinfo.txt")
    try:
        with open(info) as f:
            return any(l.startswith("opencl_libs=") and l.strip() != "opencl_libs=" for l in f)
    except OSError:
        return False


def build(sphc, tmp, backend, precision):
    exe = os.path.join(tmp, "dambreak_%s_%s" % (backend, precision))
    run([sphc, os.path.join(ROOT, "examples", "dambreak.sph"), "-o", exe,
         "--backend=" + backend, "--precision=" + precision])
    return exe


def timing(exe, backend, dx, steps, repeat, threads, device):
    cmd = [exe, "--max-steps", str(steps), "--no-output", "--timing", "--quiet"]
    if dx != DEFAULT_DX:
        cmd += ["--set", "dx=%r" % dx]
    env = serial_env()
    if backend == "openmp":
        cmd += ["--threads", str(threads)]
        env["OMP_NUM_THREADS"] = str(threads)
    if backend == "opencl":
        if device:
            p, d = device.split(",")
            cmd += ["--platform", p, "--device", d]
        warm = list(cmd)
        warm[warm.index("--max-steps") + 1] = "1"
        run(warm, env=env)  # kernels built and cached
    best = None
    for _ in range(repeat):
        _, out = run(cmd, env=env)
        m = timing_line(out, cmd, TIMING_RE)
        r = dict(particles=int(m.group(2)), steps=int(m.group(1)), us=float(m.group(4)),
                 precision=m.group(7), nnps=float(m.group(9)) if m.group(9) else None)
        # (nnps: the share of the time loop in the neighbour search)
        if best is None or r["us"] < best["us"]:
            best = r
    return best


def fmt(v, f="%.3f"):
    return "-" if v is None else f % v


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sphc", default=os.path.join(ROOT, "build", "bin", "sphc"))
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--steps", type=int, default=500)
    ap.add_argument("--steps-large", type=int, default=50)
    ap.add_argument("--dx-large", type=float, default=0.0047)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--opencl-device", default="", help="P,D: --platform P --device D")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--keep", action="store_true")
    args = ap.parse_args()
    if args.quick:
        args.steps, args.steps_large, args.repeat = 20, 3, 1
    ocl = opencl_available(args.sphc)
    builds = [b for b in BUILDS if ocl or b[0] != "opencl"]
    sizes = (("default", DEFAULT_DX, args.steps), ("large", args.dx_large, args.steps_large))
    tmp = tempfile.mkdtemp(prefix="sphc-bench-backends-")
    res = {}
    try:
        for backend, precision in builds:
            print("building %s %s ..." % (backend, precision), flush=True)
            exe = build(args.sphc, tmp, backend, precision)
            for key, dx, steps in sizes:
                print("  %d steps at dx = %g ..." % (steps, dx), flush=True)
                r = timing(exe, backend, dx, steps, args.repeat, args.threads, args.opencl_device)
                if r["precision"] != precision:
                    sys.stderr.write("%s reports precision=%s\n" % (exe, r["precision"]))
                    return 1
                res[(backend, precision, key)] = r
    finally:
        remove_tmp(tmp, args.keep)

    print()
    print("2D dam break (examples/dambreak.sph), %s, %d cores; openmp: %d threads"
          % (cpu_model(), os.cpu_count() or 0, args.threads))
    if not ocl:
        print("(no OpenCL in this build of sphc: opencl rows skipped)")
    for key, dx, steps in sizes:
        base = res.get(("serial", "double", key))
        any_r = next(r for k, r in res.items() if k[2] == key)
        print()
        print("dx = %g: %d particles, %d steps timed%s" % (
            dx, any_r["particles"], steps, " (--quick: indicative only)" if args.quick else ""))
        print("%-22s %14s %14s %14s %14s %14s" % ("us/particle/step", "double", "single",
                                                  "single/double", "nnps share", "vs serial dbl"))
        for backend in ("serial", "openmp", "opencl"):
            d, s = res.get((backend, "double", key)), res.get((backend, "single", key))
            if d is None and s is None:
                continue
            label = backend + (" (%d threads)" % args.threads if backend == "openmp" else "")
            ratio = s["us"] / d["us"] if d and s else None
            share = "/".join(fmt(100 * r["nnps"], "%.1f%%") if r and r["nnps"] is not None
                             else "-" for r in (d, s))
            speed = "/".join(fmt(base["us"] / r["us"], "%.2fx") if r else "-" for r in (d, s))
            print("%-22s %14s %14s %14s %14s %14s" % (label, fmt(d and d["us"]), fmt(s and s["us"]),
                                                      fmt(ratio, "%.2f"), share, speed))
    print()
    print("single/double < 1: single is faster. nnps share: the neighbour search (domain, cell")
    print("lists, reorder) in the time loop, double/single. vs serial dbl: serial double time /")
    print("this time, double/single (> 1: faster).")
    return 0


if __name__ == "__main__":
    sys.exit(main())
