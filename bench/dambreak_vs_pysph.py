#!/usr/bin/env python3
"""sphc against PySPH 1.0b1 on the 2D dam break: prints figures, is not a test.

Measures, in one run:
  (a) sphc compile time of examples/dambreak.sph, cold (SPHC_CACHE_DIR set to a fresh
      temporary directory) and cached (the same command again);
  (b) microseconds per particle per time step of the generated solver, serial, at the default
      resolution (dx = 0.03) and at ~100k particles (--dx-large, default 0.0047), each run for
      a fixed number of steps with `--max-steps N --no-output --timing`;
  (c) the same figure for PySPH's `dam_break_2d` example (scheme wcsph, serial Cython,
      --disable-output, --max-steps N), from PySPH's own "Run took" time and step count
      (its profile_info.csv); PySPH's set-up time (Cython generation and compilation with an
      empty cache, then with a warm one) is reported separately and excluded from the
      per-step figure;
  (d) the ratio PySPH / sphc.

Both codes run the same case: WCSPH with the Tait equation of state, Monaghan artificial
viscosity, XSPH, the predictor-corrector integrator (one acceleration evaluation per step),
a Wendland quintic kernel with h = 1.3 dx. The particle counts differ a little (PySPH's tank
has 4 wall layers, sphc's 3), hence the per-particle figure.

PySPH's dam_break_2d fixes the particle mass and smoothing length for dx = 0.03 whatever --dx
says (so `--dx 0.0047` would put ~40 times too much mass in each particle and give each one
hundreds of neighbours). This script therefore runs PySPH's example through a small driver
(`--pysph-driver`, below) that sets the example module's `dx`, `h` and `m` consistently before
running it; nothing else of the example changes.

Usage:
  python3 bench/dambreak_vs_pysph.py [--sphc build/bin/sphc] [--steps 1000]
                                     [--steps-large 100] [--dx-large 0.0047]
                                     [--skip-pysph] [--skip-sphc] [--repeat 1]
The Python running it must have PySPH (Debian: python3-pysph) unless --skip-pysph.
"""

import os
import re
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import (ROOT, DEFAULT_DX, argument_parser, cpu_model, fmt, pysph_timing,  # noqa: E402,F401
                    remove_tmp, require_sphc, run, scale_dambreak, serial_env, timing_line)


def pysph_driver(argv):
    """Runs PySPH's dam_break_2d with dx, h and m all derived from the given dx."""
    dx = float(argv[0])
    sys.argv = [sys.argv[0]] + ["--dx", repr(dx)] + argv[1:]
    import pysph.examples.dam_break_2d as db
    scale_dambreak(db, dx)
    app = db.DamBreak2D()
    app.run()
    return 0


# ---- sphc ---------------------------------------------------------------------------------

def sphc_compile(sphc, tmp, backend="serial"):
    cache = os.path.join(tmp, "sphc-cache-" + backend)
    os.makedirs(cache)
    env = serial_env({"SPHC_CACHE_DIR": cache})
    src = os.path.join(ROOT, "examples", "dambreak.sph")
    exe = os.path.join(tmp, "dambreak_" + backend)
    flags = ["--backend=" + backend]
    cold, _ = run([sphc, src, "-o", exe] + flags, env=env)
    cached, _ = run([sphc, src, "-o", exe + "_cached"] + flags, env=env)
    return exe, cold, cached


TIMING_RE = re.compile(r"timing: steps=(\d+) particles=(\d+) wall_s=([0-9.eE+-]+) "
                       r"us_per_particle_step=([0-9.eE+-]+)")


def sphc_timing(exe, dx, steps, repeat, threads=None):
    best = None
    for _ in range(repeat):
        cmd = [exe, "--max-steps", str(steps), "--no-output", "--timing", "--quiet"]
        if dx != DEFAULT_DX:
            cmd += ["--set", "dx=%r" % dx]
        env = serial_env()
        if threads:
            cmd += ["--threads", str(threads)]
            env["OMP_NUM_THREADS"] = str(threads)
        _, out = run(cmd, env=env)
        m = timing_line(out, cmd, TIMING_RE)
        r = dict(steps=int(m.group(1)), particles=int(m.group(2)), wall=float(m.group(3)),
                 us=float(m.group(4)))
        if best is None or r["us"] < best["us"]:
            best = r
    return best


# ---- PySPH --------------------------------------------------------------------------------

def pysph_run(python, dx, steps, outdir, home=None, threads=None):
    """One PySPH run (serial, or --openmp with `threads`); returns set-up time, run time,
    steps, particles, total wall."""
    env = serial_env({"HOME": home} if home else None)
    cmd = [python, os.path.abspath(__file__), "--pysph-driver", repr(dx),
           "--max-steps", str(steps), "--tf", "100", "--disable-output",
           "-d", outdir]
    if threads:
        cmd.append("--openmp")
        env["OMP_NUM_THREADS"] = str(threads)
    wall, out = run(cmd, env=env)
    r = pysph_timing(out, outdir)
    if r["particles"] is None:
        sys.stderr.write("no particle count in PySPH's output:\n%s\n" % out[-3000:])
        raise SystemExit(1)
    r["wall"] = wall
    r["us"] = r["run"] / (r["steps"] * r["particles"]) * 1e6
    return r


def pysph_parallel(python, tmp, dx_large, steps, steps_large, threads):
    res = {}
    home = os.path.join(tmp, "pysph-home")
    for key, dx, n in (("small", DEFAULT_DX, steps), ("large", dx_large, steps_large)):
        d = os.path.join(tmp, "pysph-omp-%s" % key)
        os.makedirs(d)
        res[key] = pysph_run(python, dx, n, d, home=home, threads=threads)
    return res


def pysph_all(python, tmp, dx_large, steps, steps_large, repeat):
    res = {}
    # Cold: an empty PySPH cache (~/.pysph) via a fresh HOME; one step is enough.
    home = os.path.join(tmp, "pysph-home")
    os.makedirs(home)
    cold_dir = os.path.join(tmp, "pysph-cold")
    os.makedirs(cold_dir)
    res["cold"] = pysph_run(python, DEFAULT_DX, 1, cold_dir, home=home)
    cached_dir = os.path.join(tmp, "pysph-cached")
    os.makedirs(cached_dir)
    res["cached"] = pysph_run(python, DEFAULT_DX, 1, cached_dir, home=home)
    for key, dx, n in (("small", DEFAULT_DX, steps), ("large", dx_large, steps_large)):
        best = None
        for i in range(repeat):
            d = os.path.join(tmp, "pysph-%s-%d" % (key, i))
            os.makedirs(d)
            r = pysph_run(python, dx, n, d, home=home)
            if best is None or r["us"] < best["us"]:
                best = r
        res[key] = best
    return res


# ---- report -------------------------------------------------------------------------------

def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--pysph-driver":
        return pysph_driver(sys.argv[2:])

    ap = argument_parser(__doc__)
    ap.add_argument("--steps", type=int, default=1000, help="steps at dx = 0.03")
    ap.add_argument("--steps-large", type=int, default=100, help="steps at ~100k particles")
    ap.add_argument("--dx-large", type=float, default=0.0047,
                    help="dx giving ~100k particles (default 0.0047)")
    ap.add_argument("--repeat", type=int, default=1, help="runs per figure; the best is kept")
    ap.add_argument("--threads", type=int, default=0,
                    help="also time sphc --backend=openmp and PySPH --openmp with this many "
                         "threads (default: none)")
    args = ap.parse_args()

    tmp = tempfile.mkdtemp(prefix="sphc-bench-")
    s = {}
    p = {}
    try:
        if not args.skip_sphc:
            if not require_sphc(args.sphc):
                return 1
            print("sphc: compiling examples/dambreak.sph (cold, then cached) ...", flush=True)
            exe, s["cold"], s["cached"] = sphc_compile(args.sphc, tmp)
            print("sphc: timing %d steps at dx = %g ..." % (args.steps, DEFAULT_DX), flush=True)
            s["small"] = sphc_timing(exe, DEFAULT_DX, args.steps, args.repeat)
            print("sphc: timing %d steps at dx = %g ..." % (args.steps_large, args.dx_large),
                  flush=True)
            s["large"] = sphc_timing(exe, args.dx_large, args.steps_large, args.repeat)
            if args.threads:
                print("sphc: OpenMP build, %d threads ..." % args.threads, flush=True)
                omp_exe, _, _ = sphc_compile(args.sphc, tmp, "openmp")
                s["omp_small"] = sphc_timing(omp_exe, DEFAULT_DX, args.steps, args.repeat,
                                             args.threads)
                s["omp_large"] = sphc_timing(omp_exe, args.dx_large, args.steps_large,
                                             args.repeat, args.threads)
        if not args.skip_pysph:
            print("PySPH: dam_break_2d, cold cache, then %d steps at dx = %g and %d at dx = %g ..."
                  % (args.steps, DEFAULT_DX, args.steps_large, args.dx_large), flush=True)
            p = pysph_all(args.pysph_python, tmp, args.dx_large, args.steps,
                          args.steps_large, args.repeat)
            if args.threads:
                print("PySPH: --openmp, %d threads ..." % args.threads, flush=True)
                for k, v in pysph_parallel(args.pysph_python, tmp, args.dx_large, args.steps,
                                           args.steps_large, args.threads).items():
                    p["omp_" + k] = v
    finally:
        remove_tmp(tmp, args.keep)

    def g(d, k, f):
        return d[k][f] if k in d else None

    print()
    print("2D dam break, serial, %s, %d cores" % (cpu_model(), os.cpu_count() or 0))
    print("sphc: examples/dambreak.sph    PySPH 1.0b1: dam_break_2d (wcsph), Cython, no OpenMP")
    print()
    print("%-44s %12s %12s %12s" % ("", "sphc", "PySPH", "PySPH/sphc"))
    rows = [
        ("compile / set-up, empty cache [s]", s.get("cold"), g(p, "cold", "setup")),
        ("compile / set-up, cached [s]", s.get("cached"), g(p, "cached", "setup")),
        ("    whole command, cached, 1 step [s]", s.get("cached"), g(p, "cached", "wall")),
    ]
    for label, a, b in rows:
        ratio = b / a if (a and b) else None
        print("%-44s %12s %12s %12s" % (label, fmt(a), fmt(b), fmt(ratio, "%.1fx")))
    for key, dx in (("small", DEFAULT_DX), ("large", args.dx_large)):
        a, b = g(s, key, "us"), g(p, key, "us")
        ratio = b / a if (a and b) else None
        print("%-44s %12s %12s %12s" % ("us / particle / step, dx = %g" % dx, fmt(a, "%.3f"),
                                         fmt(b, "%.3f"), fmt(ratio, "%.2fx")))
        print("%-44s %12s %12s" % ("    particles, steps timed",
                                   "-" if a is None else "%d, %d" % (s[key]["particles"],
                                                                    s[key]["steps"]),
                                   "-" if b is None else "%d, %d" % (p[key]["particles"],
                                                                    p[key]["steps"])))
    if args.threads:
        print()
        print("parallel, %d threads: sphc --backend=openmp, PySPH --openmp" % args.threads)
        for key, dx in (("small", DEFAULT_DX), ("large", args.dx_large)):
            a, b = g(s, "omp_" + key, "us"), g(p, "omp_" + key, "us")
            ratio = b / a if (a and b) else None
            print("%-44s %12s %12s %12s" % ("us / particle / step, dx = %g" % dx,
                                             fmt(a, "%.3f"), fmt(b, "%.3f"),
                                             fmt(ratio, "%.2fx")))
            sa, ss = g(s, key, "us"), g(s, "omp_" + key, "us")
            pa, ps = g(p, key, "us"), g(p, "omp_" + key, "us")
            print("%-44s %12s %12s" % ("    speed-up over own serial",
                                       fmt(sa / ss if sa and ss else None, "%.2fx"),
                                       fmt(pa / ps if pa and ps else None, "%.2fx")))
    print()
    print("sphc compile times are wall times of the whole `sphc` command. PySPH set-up is its")
    print("'Setup took' (code generation, Cython compilation when the cache is empty, particle")
    print("creation; Python start-up and imports are only in the 'whole command' row); its")
    print("per-step figure is 'Run took' / (steps x particles). Lower is better.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
