#!/usr/bin/env python3
"""sphc against PySPH 1.0b1 on the Taylor-Green vortex with EDAC: prints figures, is not a test.

Measures, in one run, for the Taylor-Green vortex at Re = 100 (nx x nx particles, to t = tf):
  (a) sphc: compile time of `sphc examples/taylor_green.sph -D scheme=edac` with an empty
      cache (SPHC_CACHE_DIR set to a fresh temporary directory), then the serial solver's
      wall time to tf: the time loop ("wall_s" of its --timing line) and the whole command;
  (b) PySPH: `taylor_green --scheme edac --nx N --tf TF` (serial Cython, no OpenMP): its set-up
      time ("Setup took" of a one-step run with an empty ~/.pysph, i.e. a fresh HOME: Cython
      generation and compilation), then, with the cache warm, the run to tf: its time loop
      ("Run took") and the whole command;
  CPU times (user + system, of the solver process and its children) beside the wall times:
  on a shared machine they are the fairer comparison;
  (c) for both, the errors of the final state against the exact solution, computed by the
      same function (tests/validation/taylor_green.py's speed_errors): the decay error of the
      largest speed, max |v| / (U e^{bt}) - 1, and the L1 error of the speed,
      sum | |v| - |v_e| | / sum |v_e|.

Both codes run the same scheme and set-up: EDAC for internal flows (Ramachandran & Puri
2019) with the transport velocity, background pressure pb = rho0 c0^2, the average pressure
subtracted, nu_edac = 0.5 h c0 / 8, c0 = 10 U, quintic spline with h = dx, the predictor-
corrector step, dt = 0.25 h / (c0 + U). The differences: sphc starts the transport velocity
at the velocity (PySPH at 0), and its periodic ghosts copy the density and average pressure
of their particles (PySPH's compute their own, over a truncated neighbourhood).

Both write only the first and the last state (sphc --output-every TF, PySPH --pfreq large).
PySPH's example post-processes its output with matplotlib at the end; this script runs it
through a small driver (`--pysph-driver`) that skips that step and changes nothing else.

The machine may be shared: the load average is printed before and after; compare figures
from runs on an idle machine.

Usage:
  python3 bench/taylor_green_vs_pysph.py [--sphc build/bin/sphc] [--nx 50] [--tf 2]
                                         [--skip-pysph] [--skip-sphc] [--keep]
The Python running it needs numpy and h5py, and PySPH (Debian: python3-pysph) unless
--skip-pysph (or pass --pysph-python).
"""

import glob
import os
import re
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "validation"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import (argument_parser, cpu_model, fmt, load_average, pysph_seconds,  # noqa: E402
                    remove_tmp, require_sphc, run, serial_env, timing_line)


def pysph_driver(argv):
    """Runs PySPH's taylor_green example without its matplotlib post-processing."""
    sys.argv = [sys.argv[0]] + argv
    import pysph.examples.taylor_green as tg

    class TaylorGreenNoPlots(tg.TaylorGreen):
        def post_process(self, info_fname):
            pass

    TaylorGreenNoPlots().run()
    return 0


def last_file(directory, pattern):
    files = glob.glob(os.path.join(directory, pattern))
    files = [f for f in files if re.search(r"_(\d+)\.h(df)?5$", f)]
    if not files:
        sys.stderr.write("no output files %s in %s\n" % (pattern, directory))
        raise SystemExit(1)
    return max(files, key=lambda f: int(re.search(r"_(\d+)\.h(df)?5$", f).group(1)))


def errors(x, y, u, v, t):
    from taylor_green import speed_errors
    return speed_errors(x, y, u, v, t, 100.0)


# ---- sphc ---------------------------------------------------------------------------------



def sphc_all(sphc, tmp, nx, tf):
    import h5py
    import numpy as np
    env = serial_env({"SPHC_CACHE_DIR": os.path.join(tmp, "sphc-cache")})
    exe = os.path.join(tmp, "taylor_green_edac")
    src = os.path.join(ROOT, "examples", "taylor_green.sph")
    compile_s, _ = run([sphc, src, "-D", "scheme=edac", "-o", exe], env=env)
    out = os.path.join(tmp, "sphc-out")
    wall, text = run([exe, "--set", "nx=%d" % nx, "--tf", repr(tf), "--output-every", repr(tf),
                      "--timing", "--quiet", "-d", out], env=env)
    cpu = run.cpu
    m = timing_line(text, "the solver")
    with h5py.File(last_file(out, "*.h5"), "r") as f:
        t = float(f.attrs["t"])
        g = f["fluid"]
        x, y, u, v = (np.asarray(g[k][()], dtype=float) for k in ("x", "y", "u", "v"))
    decay, l1 = errors(x, y, u, v, t)
    return dict(setup=compile_s, run=float(m.group(3)), wall=wall, cpu=cpu,
                steps=int(m.group(1)), particles=int(m.group(2)), t=t, decay=decay, l1=l1)


# ---- PySPH --------------------------------------------------------------------------------

def pysph_all(python, tmp, nx, tf):
    home = os.path.join(tmp, "pysph-home")      # an empty ~/.pysph: set-up compiles
    os.makedirs(home)
    env = serial_env({"HOME": home})

    def cmd(out, extra):
        return [python, os.path.abspath(__file__), "--pysph-driver", "--scheme", "edac",
                "--nx", str(nx), "--pfreq", "100000000", "-d", out] + extra

    # One step with the empty cache: the set-up time (Cython generation and compilation).
    _, text = run(cmd(os.path.join(tmp, "pysph-cold"), ["--max-steps", "1"]), env=env)
    setup = pysph_seconds(text, "Setup")
    # The run, with the cache now warm (its CPU time is then nearly all the time loop's).
    out = os.path.join(tmp, "pysph-out")
    wall, text = run(cmd(out, ["--tf", repr(tf)]), env=env)
    cpu = run.cpu
    runt = pysph_seconds(text, "Run")
    if setup is None or runt is None:
        sys.stderr.write("could not read PySPH's timing from its output:\n%s\n" % text[-3000:])
        raise SystemExit(1)
    # Read PySPH's last state with PySPH's own loader, in its Python.
    reader = ("import sys, numpy as np\n"
              "from pysph.solver.utils import load\n"
              "d = load(sys.argv[1]); a = d['arrays']['fluid']\n"
              "n = a.get_number_of_particles(real=True)\n"
              "np.savez(sys.argv[2], t=d['solver_data']['t'], x=a.x[:n], y=a.y[:n],"
              " u=a.u[:n], v=a.v[:n], count=d['solver_data']['count'])\n")
    npz = os.path.join(tmp, "pysph-last.npz")
    run([python, "-c", reader, last_file(out, "*.hdf5"), npz], env=env)
    import numpy as np
    d = np.load(npz)
    decay, l1 = errors(d["x"], d["y"], d["u"], d["v"], float(d["t"]))
    return dict(setup=setup, run=runt, wall=wall, cpu=cpu,
                steps=int(d["count"]), particles=len(d["x"]), t=float(d["t"]), decay=decay,
                l1=l1)


# ---- report -------------------------------------------------------------------------------

def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--pysph-driver":
        return pysph_driver(sys.argv[2:])

    ap = argument_parser(__doc__)
    ap.add_argument("--nx", type=int, default=50, help="particles along a side (default 50)")
    ap.add_argument("--tf", type=float, default=2.0, help="final time (default 2)")
    args = ap.parse_args()

    load0 = load_average()
    tmp = tempfile.mkdtemp(prefix="sphc-bench-tg-")
    s = p = None
    try:
        if not args.skip_sphc:
            if not require_sphc(args.sphc):
                return 1
            print("sphc: compiling examples/taylor_green.sph -D scheme=edac, running nx = %d "
                  "to t = %g ..." % (args.nx, args.tf), flush=True)
            s = sphc_all(args.sphc, tmp, args.nx, args.tf)
        if not args.skip_pysph:
            print("PySPH: taylor_green --scheme edac --nx %d --tf %g (empty cache) ..."
                  % (args.nx, args.tf), flush=True)
            p = pysph_all(args.pysph_python, tmp, args.nx, args.tf)
    finally:
        remove_tmp(tmp, args.keep)

    def g(d, k):
        return None if d is None else d[k]

    print()
    print("Taylor-Green vortex, Re = 100, EDAC, nx = %d, t = 0..%g, serial, %s, %d cores"
          % (args.nx, args.tf, cpu_model(), os.cpu_count() or 0))
    print("load average before: %s, after: %s" % (load0, load_average()))
    print("sphc: examples/taylor_green.sph -D scheme=edac    PySPH 1.0b1: taylor_green "
          "--scheme edac, Cython, no OpenMP")
    print()
    print("%-40s %12s %12s %12s" % ("", "sphc", "PySPH", "PySPH/sphc"))
    for label, key, spec in (("compile / set-up, empty cache [s]", "setup", "%.2f"),
                             ("time loop to tf, wall [s]", "run", "%.2f"),
                             ("whole run, wall [s]", "wall", "%.2f"),
                             ("whole run, CPU (user + sys) [s]", "cpu", "%.2f")):
        a, b = g(s, key), g(p, key)
        ratio = b / a if (a and b) else None
        print("%-40s %12s %12s %12s" % (label, fmt(a, spec), fmt(b, spec), fmt(ratio, "%.2fx")))
    print("%-40s %12s %12s" % ("particles, steps", "-" if s is None else "%d, %d"
                               % (s["particles"], s["steps"]),
                               "-" if p is None else "%d, %d" % (p["particles"], p["steps"])))
    print("%-40s %12s %12s" % ("final t", fmt(g(s, "t"), "%.4f"), fmt(g(p, "t"), "%.4f")))
    for label, key, spec in (("decay error of max |v| [%]", "decay", "%+.2f"),
                             ("L1 error of |v| [%]", "l1", "%.2f")):
        a, b = g(s, key), g(p, key)
        print("%-40s %12s %12s" % (label, fmt(None if a is None else 100 * a, spec),
                                   fmt(None if b is None else 100 * b, spec)))
    if s and p:
        print()
        faster = p["run"] / s["run"]
        faster_cpu = p["cpu"] / s["cpu"]
        print("sphc faster than PySPH: %.2fx (time loop, wall), %.2fx (whole run, CPU); "
              "L1 error: sphc %.2f%%, PySPH %.2f%%"
              % (faster, faster_cpu, 100 * s["l1"], 100 * p["l1"]))
        # "Same" error: at most 5% (relative) above PySPH's.
        ok = min(faster, faster_cpu) >= 2.0 and s["l1"] <= 1.05 * p["l1"]
        print("target (L1 error at most 1.05 x PySPH's, at most half PySPH's time, wall and "
              "CPU): %s" % ("met" if ok else "NOT met"))
    print()
    print("The time loop is sphc's --timing wall_s and PySPH's 'Run took'; the whole run adds")
    print("start-up, particle creation and output (PySPH's with its cache warm: its set-up is")
    print("timed by a separate one-step run). CPU times count only the process itself, so")
    print("they are the fairer figure on a shared machine. Errors: the same function, on the")
    print("last state of each.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
