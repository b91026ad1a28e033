#!/usr/bin/env python3
"""Time to solution, sphc against PySPH 1.0b1, side by side in one run: prints figures, is not a test.

What a user waits for is the time to reach a simulated time at a stated accuracy, not the
time per particle-step. For each case this script runs, interleaved in one go,

  sphc serial        (--backend=serial, OMP_NUM_THREADS=1)
  sphc OpenMP        (--backend=openmp --threads T, default T = 2)
  PySPH serial       (its Cython, no --openmp, OMP_NUM_THREADS=1)
  PySPH OpenMP       (--openmp, OMP_NUM_THREADS=T)

with each code's own OpenMP wait policy, what a user who sets nothing gets (--omp-wait
default: OMP_WAIT_POLICY unset; libgomp's policy for PySPH, the solver's --omp-wait auto for
sphc). On a shared, loaded machine libgomp's spinning makes 2-thread runs several times
slower: there --omp-wait passive sets OMP_WAIT_POLICY=passive for all of them (--omp-wait
active: active), and reports for each

  - wall time of the time loop to tf (sphc: wall_s of --timing; PySPH: "Run took"),
  - CPU time (user + system) of the time loop: the CPU time of the whole process less that
    of the same command stopped after 1 step (start-up, imports, particle creation),
  - steps, particles, microseconds per particle-step (loop wall / (steps x particles)),
  - the accuracy reached:
      dam break: the surge front against Koshizuka & Oka (1996), experiment and MPS
        calculation, computed by tests/validation/dambreak_front.py's front_position on every
        snapshot with T = t sqrt(2g/L) >= 1: the largest relative error;
      Taylor-Green: the L1 error of the speed and the decay error of max |v| against the
        exact solution at tf (tests/validation/taylor_green.py's speed_errors);
      cube: none (a timing case: 5x more steps of PySPH's benchmark);
  - compile / set-up time, excluded from the above: sphc cold (empty SPHC_CACHE_DIR) and
    cached; PySPH's "Setup took" at first use (empty ~/.pysph: Cython generation and
    compilation) and with its cache warm;
  - the ratios PySPH / sphc of the loop's wall and CPU time (higher: sphc faster).

Cases (both codes run the same numerics; see bench/README.md for the details of each):
  dambreak  examples/dambreak.sph (adaptive dt, WCSPH) vs PySPH dam_break_2d (wcsph,
            adaptive dt), dx = 0.03, to t = 0.5 s, snapshots every 0.02 s (sphc) / 50 steps
            (PySPH); --dambreak-large-tf T adds dx = 0.0047 (~100k particles) to t = T
  dambreak-pysph-numerics  the same with PySPH's effects and cfl (no density diffusion, no
            shifting, cfl 0.3); with --dambreak-large-tf T also at dx = 0.0047 to t = T
  cube      bench/cube.sph vs PySPH cube, 47^3 = 103,823 particles, to t = 2.5e-3 (25 steps)
  tg        examples/taylor_green.sph -D scheme=edac vs PySPH taylor_green --scheme edac,
            Re = 100, nx = 100, to t = 1

Usage:
  python3 bench/time_to_solution.py                  # all cases (~10 min on an idle 2-core machine)
  python3 bench/time_to_solution.py --quick          # a few minutes: shorter runs, tg nx = 50
  python3 bench/time_to_solution.py --cases dambreak,tg --threads 2 --repeat 2
Options: --sphc PATH, --pysph-python PYTHON, --skip-pysph, --skip-sphc, --skip-omp,
--keep, --tf-dambreak, --tf-cube, --nx-tg, --tf-tg, --max-steps N (smoke test: every run
stops after N steps; accuracy then not judged).
"""

import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "tests", "validation"))
sys.path.insert(0, HERE)
from common import (argument_parser, cpu_model, fmt, load_average, pysph_timing,  # noqa: E402
                    remove_tmp, require_sphc, run, timing_line)
import dambreak_vs_pysph  # noqa: E402
import taylor_green_vs_pysph  # noqa: E402



def pysph_driver(argv):
    """`--pysph-driver CASE ARGS`: runs a PySPH example (dambreak: dx first)."""
    case, rest = argv[0], argv[1:]
    if case == "dambreak":
        return dambreak_vs_pysph.pysph_driver(rest)
    if case == "tg":
        return taylor_green_vs_pysph.pysph_driver(rest)
    if case == "cube":
        sys.argv = [sys.argv[0]] + rest
        import pysph.examples.cube as cube
        app = cube.Cube()
        app.run()
        print("Total: %d" % sum(pa.get_number_of_particles() for pa in app.particles))
        return 0
    raise SystemExit("unknown PySPH case %s" % case)


def environment(threads, wait):
    env = dict(os.environ)
    env["OMP_NUM_THREADS"] = str(threads)
    if wait == "default":
        # What a user gets who sets nothing: libgomp's own policy for PySPH (spin a while,
        # then sleep), the solver's --omp-wait auto for sphc (libgomp's policy on an idle
        # machine, passive on a loaded one).
        env.pop("OMP_WAIT_POLICY", None)
        env.pop("GOMP_SPINCOUNT", None)
    else:
        env["OMP_WAIT_POLICY"] = wait
    return env


# ---- the cases ----------------------------------------------------------------------------

class Case:
    """A case: how to build and run it with sphc and PySPH, and how to judge its accuracy."""

    def __init__(self, name, title, source, sphc_defines, sphc_args, pysph_args, accuracy,
                 output):
        self.name, self.title, self.source = name, title, source
        self.sphc_defines, self.sphc_args, self.pysph_args = sphc_defines, sphc_args, pysph_args
        self.accuracy = accuracy   # function(outdir, who) -> {label: value}
        self.output = output       # sphc output options, PySPH output options


def dambreak_case(dx, tf, tag="dambreak", pysph_numerics=False):
    # PySPH's tank: innermost wall layer at x = 0, its wall face at dx/2, 4 layers.
    def acc(outdir, who):
        return dambreak_accuracy(outdir, dx / 2 if who == "pysph" else 0.0)
    sargs = ["--tf", repr(tf)] + ([] if dx == 0.03 else ["--set", "dx=%r" % dx])
    defines, title = [], "2D dam break, dx = %g, to t = %g s" % (dx, tf)
    if pysph_numerics:
        # The effects and the step of PySPH's dam_break_2d (WCSPHScheme's defaults): no
        # density diffusion, no particle shifting, adaptive step with cfl 0.3.
        defines = ["-D", "density_diffusion=off", "-D", "shifting=off"]
        sargs += ["--set", "cfl=0.3"]
        title += ", sphc with PySPH's effects and cfl (no density diffusion, no shifting)"
    return Case(tag, title,
                os.path.join(ROOT, "examples", "dambreak.sph"), defines, sargs,
                ["dambreak", repr(dx), "--tf", repr(tf)], acc,
                (["--output-every", "0.02"], ["--pfreq", "50"]))


def cube_case(tf):
    return Case("cube", "3D cube (PySPH's `cube`), 103,823 particles, to t = %g s" % tf,
                os.path.join(HERE, "cube.sph"), [], ["--tf", repr(tf)],
                ["cube", "--tf", repr(tf)], None,
                (["--no-output"], ["--disable-output"]))


def tg_case(nx, tf):
    def acc(outdir, who):
        return tg_accuracy(outdir, who)
    return Case("tg", "Taylor-Green, Re = 100, EDAC, nx = %d, to t = %g" % (nx, tf),
                os.path.join(ROOT, "examples", "taylor_green.sph"), ["-D", "scheme=edac"],
                ["--set", "nx=%d" % nx, "--tf", repr(tf)],
                ["tg", "--scheme", "edac", "--nx", str(nx), "--tf", repr(tf)], acc,
                (["--output-every", repr(tf)], ["--pfreq", "100000000"]))


# ---- accuracy -----------------------------------------------------------------------------

def dambreak_accuracy(outdir, x0, g=9.81, L=1.0):
    """Largest relative errors of the surge front (T >= 1) against the K&O experiment, the
    nearest experimental series and the K&O MPS calculation; None where nothing was judged."""
    import h5py
    import numpy as np
    import dambreak_front as df
    from snapshots import lattice_spacing, particle_arrays, snapshot_files
    exp = df.load_csv(df.DEFAULT_DATA)
    mps = df.load_csv(df.DEFAULT_MPS)
    mm = df.load_csv(df.DEFAULT_MM)
    series = [(exp["T"], exp["Z_L"])]
    for a in sorted(set(mm["a_in"])):
        sel = mm["a_in"] == a
        series.append((mm["T"][sel], mm["Z_L"][sel]))
    tscale = np.sqrt(2.0 * g / L)

    def rel(Ti, zi, tref, zref):
        if Ti < tref.min() or Ti > tref.max():
            return None
        zr = float(np.interp(Ti, tref, zref))
        if zr >= df.Z_WALL_LIMIT or zi >= df.Z_WALL_LIMIT:
            return None
        return (zi - zr) / zr

    worst = {"K&O exp": None, "nearest exp": None, "K&O MPS": None}
    dx = None
    nsnap = 0
    for path in snapshot_files(outdir):
        with h5py.File(path, "r") as f:
            t, _, arrays = particle_arrays(f)
            pos = [np.asarray(arrays["fluid"][a][()], dtype=float) for a in ("x", "y")]
        pos[0] = pos[0] - x0
        if dx is None:
            dx = lattice_spacing(pos)
        T = t * tscale
        if T < df.T_JUDGE_MIN:
            continue
        z = df.front_position(tuple(pos), dx) / L
        nsnap += 1
        errs = [rel(T, z, ts, zs) for ts, zs in series]
        cand = {"K&O exp": errs[0], "K&O MPS": rel(T, z, mps["T"], mps["Z_L"]),
                "nearest exp": min((e for e in errs if e is not None), key=abs, default=None)}
        for k, e in cand.items():
            if e is not None and (worst[k] is None or abs(e) > abs(worst[k])):
                worst[k] = e
    out = {"front snapshots judged (T >= 1)": nsnap}
    for k, e in worst.items():
        out["front error vs %s, worst [%%]" % k] = None if e is None else 100 * e
    return out


def tg_accuracy(outdir, who):
    import numpy as np
    last = taylor_green_vs_pysph.last_file(outdir, "*.h5" if who == "sphc" else "*.hdf5")
    import h5py
    from snapshots import particle_arrays
    with h5py.File(last, "r") as f:
        t, _, arrays = particle_arrays(f)
        fl = arrays["fluid"]
        x, y, u, v = (np.asarray(fl[k][()], dtype=float) for k in ("x", "y", "u", "v"))
        if "tag" in fl:   # PySPH: real (local) particles only, where it tags them
            real = np.asarray(fl["tag"][()]) == 0
            if real.any():
                x, y, u, v = x[real], y[real], u[real], v[real]
    decay, l1 = taylor_green_vs_pysph.errors(x, y, u, v, t)
    return {"t reached": t, "L1 error of |v| [%]": 100 * l1,
            "decay error of max |v| [%]": 100 * decay}


# ---- running ------------------------------------------------------------------------------

def sphc_build(args, case, tmp, backend):
    """Compiles the case's solver; returns (exe, cold seconds, cached seconds)."""
    cache = os.path.join(tmp, "cache-%s-%s" % (case.name, backend))
    os.makedirs(cache)
    env = environment(1, "passive")
    env["SPHC_CACHE_DIR"] = cache
    exe = os.path.join(tmp, "%s_%s" % (case.name, backend))
    cmd = [args.sphc, case.source, "--backend=" + backend] + case.sphc_defines + args.sphc_flag
    cold, _ = run(cmd + ["-o", exe], env=env)
    cached, _ = run(cmd + ["-o", exe + "_cached"], env=env)
    return exe, cold, cached


def steps_and_output(args, output, max_steps, no_output):
    """A run's options: max_steps steps without output (no_output, the solver's option) where
    given, else the case's output options `output` (and the command line's --max-steps)."""
    if max_steps is not None:
        return ["--max-steps", str(max_steps), no_output]
    return output + (["--max-steps", str(args.max_steps)] if args.max_steps else [])


def sphc_run(args, case, exe, threads, outdir, max_steps=None):
    env = environment(threads, args.omp_wait)
    cmd = [exe, "--timing", "--quiet", "-d", outdir] + case.sphc_args
    if threads > 1:
        cmd += ["--threads", str(threads)]
    cmd += steps_and_output(args, case.output[0], max_steps, "--no-output")
    wall, out = run(cmd, env=env)
    cpu = run.cpu
    m = timing_line(out, cmd)
    return dict(loop=float(m.group(3)), steps=int(m.group(1)), particles=int(m.group(2)),
                wall=wall, cpu=cpu)


def pysph_run(args, case, threads, outdir, home, max_steps=None):
    env = environment(threads, args.omp_wait)
    env["HOME"] = home
    cmd = [args.pysph_python, os.path.abspath(__file__), "--pysph-driver"] + case.pysph_args
    cmd += ["-d", outdir]
    if threads > 1:
        cmd.append("--openmp")
    cmd += steps_and_output(args, case.output[1], max_steps, "--disable-output")
    wall, out = run(cmd, env=env)
    cpu = run.cpu
    r = pysph_timing(out, outdir)
    return dict(setup=r["setup"], loop=r["run"], steps=r["steps"], particles=r["particles"],
                wall=wall, cpu=cpu)


def run_case(args, case, tmp, home):
    """All runs of one case; returns {variant: result}."""
    res = {}
    variants = []
    if not args.skip_sphc:
        variants.append(("sphc serial", "sphc", 1))
    if not args.skip_pysph:
        variants.append(("PySPH serial", "pysph", 1))
    if not args.skip_omp:
        if not args.skip_sphc:
            variants.append(("sphc OpenMP", "sphc", args.threads))
        if not args.skip_pysph:
            variants.append(("PySPH OpenMP", "pysph", args.threads))
    exes, compile_s, startup = {}, {}, {}
    for label, who, threads in variants:
        d = os.path.join(tmp, "%s-%s-%d-start" % (case.name, who, threads))
        if who == "sphc":
            backend = "serial" if threads == 1 else "openmp"
            print("  %s: compiling (cold, cached) ..." % label, flush=True)
            exe, cold, cached = sphc_build(args, case, tmp, backend)
            exes[label] = exe
            compile_s[label] = (cold, cached)
            one = sphc_run(args, case, exe, threads, d, max_steps=1)
            startup[label] = max(one["cpu"] - one["loop"], 0.0)
        else:
            print("  %s: first use (empty cache), then cached ..." % label, flush=True)
            cold = pysph_run(args, case, threads, d + "-cold", home, max_steps=1)
            warm = pysph_run(args, case, threads, d, home, max_steps=1)
            compile_s[label] = (cold["setup"], warm["setup"])
            startup[label] = max(warm["cpu"] - warm["loop"], 0.0)
    for rep in range(args.repeat):
        for label, who, threads in variants:
            print("  %s: run %d ..." % (label, rep + 1), flush=True)
            d = os.path.join(tmp, "%s-%s-%d-%d" % (case.name, who, threads, rep))
            if who == "sphc":
                r = sphc_run(args, case, exes[label], threads, d)
            else:
                r = pysph_run(args, case, threads, d, home)
            r["loop_cpu"] = max(r["cpu"] - startup[label], 0.0)
            if case.accuracy and not args.max_steps and (threads == 1 or args.accuracy_omp):
                try:
                    r["accuracy"] = case.accuracy(d, who)
                except Exception as exc:  # report the timing even so
                    print("  %s: accuracy not computed: %s" % (label, exc), flush=True)
            if label not in res or r["loop"] < res[label]["loop"]:
                res[label] = r
    for label in res:
        res[label]["compile"] = compile_s[label]
    return res


# ---- report -------------------------------------------------------------------------------

def report(case, res, threads):
    print()
    print("== %s" % case.title)
    labels = [v for v in ("sphc serial", "PySPH serial", "sphc OpenMP", "PySPH OpenMP")
              if v in res]
    print("%-40s" % "" + "".join("%15s" % v.replace("OpenMP", "OMP %d" % threads)
                                 for v in labels))

    def row(name, f, spec):
        vals = []
        for v in labels:
            try:
                x = f(res[v])
            except (KeyError, TypeError, ZeroDivisionError):
                x = None
            vals.append(fmt(x, spec) if x is not None else "-")
        print("%-40s" % name + "".join("%15s" % x for x in vals))

    row("compile / set-up, empty cache [s]", lambda r: r["compile"][0], "%.2f")
    row("compile / set-up, cached [s]", lambda r: r["compile"][1], "%.3f")
    row("particles", lambda r: r["particles"], "%d")
    row("steps", lambda r: r["steps"], "%d")
    row("time loop, wall [s]", lambda r: r["loop"], "%.2f")
    row("time loop, CPU [s]", lambda r: r["loop_cpu"], "%.2f")
    row("us / particle-step (wall)", lambda r: 1e6 * r["loop"] / (r["steps"] * r["particles"]),
        "%.3f")
    row("us / particle-step (CPU)",
        lambda r: 1e6 * r["loop_cpu"] / (r["steps"] * r["particles"]), "%.3f")
    keys = []
    for v in labels:
        for k in res[v].get("accuracy", {}):
            if k not in keys:
                keys.append(k)
    for k in keys:
        row(k, lambda r, k=k: r["accuracy"][k], "%.4g")
    pairs = (("serial", "sphc serial", "PySPH serial"),
             ("OpenMP", "sphc OpenMP", "PySPH OpenMP"),
             ("sphc OpenMP vs PySPH serial", "sphc OpenMP", "PySPH serial"))
    for name, a, b in pairs:
        if a in res and b in res:
            print("PySPH / sphc, %-28s wall %.2fx, CPU %.2fx" % (
                name + ":", res[b]["loop"] / res[a]["loop"],
                res[b]["loop_cpu"] / res[a]["loop_cpu"] if res[a]["loop_cpu"] else float("nan")))
    for who in ("sphc", "PySPH"):
        s, o = res.get(who + " serial"), res.get(who + " OpenMP")
        if s and o:
            print("%s OpenMP speed-up over its serial: %.2fx (wall)" % (who, s["loop"] / o["loop"]))


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--pysph-driver":
        return pysph_driver(sys.argv[2:])
    ap = argument_parser(__doc__)
    ap.add_argument("--quick", action="store_true",
                    help="a few minutes: dam break to 0.3 s, cube to 1e-3, tg nx = 50 to 0.2")
    ap.add_argument("--cases", default="dambreak,cube,tg",
                    help="dambreak, dambreak-pysph-numerics (sphc's dam break with the effects and cfl of PySPH's), cube, tg")
    ap.add_argument("--sphc-flag", action="append", default=[],
                    help="a flag for every sphc build (repeatable), e.g. "
                         "--sphc-flag=--verlet-skin=0.1")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--skip-omp", action="store_true", help="serial runs only")
    ap.add_argument("--omp-wait", default="default", choices=("passive", "active", "default"),
                    help="OMP_WAIT_POLICY of every run; default (the default): none set, "
                    "what a user who sets nothing gets (libgomp's policy for PySPH, the "
                    "solver's --omp-wait auto for sphc); passive on a loaded machine")
    ap.add_argument("--repeat", type=int, default=1, help="rounds; the fastest is kept")
    ap.add_argument("--tf-dambreak", type=float, default=None)
    ap.add_argument("--dambreak-large-tf", type=float, default=0.0,
                    help="also the dam break at dx = 0.0047 (~100k particles) to this t "
                         "(with dambreak-pysph-numerics: that case at dx = 0.0047 too)")
    ap.add_argument("--tf-cube", type=float, default=None)
    ap.add_argument("--nx-tg", type=int, default=None)
    ap.add_argument("--tf-tg", type=float, default=None)
    ap.add_argument("--max-steps", type=int, default=0,
                    help="stop every run after N steps (smoke test; no accuracy)")
    ap.add_argument("--pysph-home", default=None,
                    help="HOME for PySPH (its ~/.pysph cache); default: a fresh, empty one, so "
                         "that the first use compiles. A kept one skips PySPH's Cython builds"
                         " (its 'first use' column then shows a cached set-up)")
    ap.add_argument("--accuracy-omp", action="store_true",
                    help="also judge the accuracy of the OpenMP runs")
    args = ap.parse_args()
    q = args.quick
    tf_db = args.tf_dambreak or (0.3 if q else 0.5)
    tf_cube = args.tf_cube or (1e-3 if q else 2.5e-3)
    nx_tg = args.nx_tg or (50 if q else 100)
    tf_tg = args.tf_tg or (0.2 if q else 1.0)
    cases = []
    for c in args.cases.split(","):
        if c == "dambreak":
            cases.append(dambreak_case(0.03, tf_db))
            if args.dambreak_large_tf > 0:
                cases.append(dambreak_case(0.0047, args.dambreak_large_tf, "dambreak100k"))
        elif c == "dambreak-pysph-numerics":
            cases.append(dambreak_case(0.03, tf_db, "dambreak_pn", pysph_numerics=True))
            if args.dambreak_large_tf > 0:
                cases.append(dambreak_case(0.0047, args.dambreak_large_tf, "dambreak_pn100k",
                                           pysph_numerics=True))
        elif c == "cube":
            cases.append(cube_case(tf_cube))
        elif c == "tg":
            cases.append(tg_case(nx_tg, tf_tg))
        else:
            ap.error("unknown case %s (dambreak, dambreak-pysph-numerics, cube, tg)" % c)
    if not args.skip_sphc and not require_sphc(args.sphc, "pass --sphc"):
        return 1

    load0 = load_average()
    tmp = tempfile.mkdtemp(prefix="sphc-tts-")
    home = args.pysph_home or os.path.join(tmp, "pysph-home")  # empty: the first use compiles
    os.makedirs(home, exist_ok=True)
    print("Time to solution: sphc against PySPH 1.0b1, %s, %d cores, OMP_WAIT_POLICY=%s"
          % (cpu_model(), os.cpu_count() or 0,
             args.omp_wait if args.omp_wait != "default" else "unset (each code's default)"))
    try:
        for case in cases:
            print()
            print("%s ... (load average %s)" % (case.title, load_average()), flush=True)
            report(case, run_case(args, case, tmp, home), args.threads)
            sys.stdout.flush()
    finally:
        remove_tmp(tmp, args.keep)
    print()
    print("load average before: %s, after: %s; best of %d round(s), runs interleaved"
          % (load0, load_average(), args.repeat))
    print("Loop wall: sphc's --timing wall_s, PySPH's 'Run took' (both include the snapshots")
    print("written). Loop CPU: the process's user + system time less that of the same command")
    print("stopped after one step. Compile / set-up is excluded from both. Ratios > 1: sphc")
    print("is faster. On a shared machine the CPU figures of the serial runs are the fairer.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
