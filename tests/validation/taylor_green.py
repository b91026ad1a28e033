#!/usr/bin/env python3
"""Checks the Taylor-Green vortex (examples/taylor_green.sph) against its exact solution.

The case: the periodic unit square, Re = U L / nu = 100, U = L = 1. The exact solution of the
incompressible Navier-Stokes equations,

    u = -U e^{bt} cos(2 pi x) sin(2 pi y),   v = U e^{bt} sin(2 pi x) cos(2 pi y),

decays at the rate b = -2 nu k^2 with k = 2 pi / L, i.e. b = -8 pi^2 nu / L^2 = -8 pi^2 / Re
(the viscous term of the momentum equation is nu lap v = -2 nu k^2 v for this field, and the
nonlinear term is a gradient balanced by the pressure). The speed |v| = U e^{bt}
sqrt(cos^2(kx) sin^2(ky) + sin^2(kx) cos^2(ky)) has the maximum U e^{bt}.

Measures, in every snapshot (those of Adami, Hu & Adams 2013 and Ramachandran & Puri 2019):

  - decay error: max_i |v_i| / (U e^{bt}) - 1, the largest particle speed against the exact
    amplitude;
  - L1 error of the speed: sum_i | |v_i| - |v_e(x_i, t)| | / sum_i |v_e(x_i, t)|, the exact
    field evaluated at the particle positions.

Both are the solver's own metrics (the scene's `metrics { }`: columns decay_err and l1 of
OUTPUT_DIR/taylor_green_metrics.csv, one row per snapshot); this script checks them, and
recomputes them from the last snapshot to check the metrics themselves (to 1e-9).

Tolerances (judged at the last snapshot; --decay-tol, --l1-tol; with --whole-run at every
snapshot). Standard WCSPH (no background pressure, no particle shifting or transport
velocity; the scene's `-D shifting=off -D density_diffusion=off`) follows the exact solution
only for a short time on this problem: the negative pressures of the vortex (down to
-rho0 U^2/2) drive the tensile instability, the particles cluster, and the velocity field
breaks up (PySPH 1.0b1's WCSPH, `pysph run taylor_green --scheme wcsph --nx 50`, measured
here, is 18% below the exact amplitude at t = 0.14 and 98% at t = 2; Ramachandran & Puri
2019 show the same failure of WCSPH and fix it with EDAC): within 0.25% (decay) and 0.3%
(L1) up to t = 0.05, broken up from t = 0.075 (docs/validation.md). The defaults, 1% for both
errors, were set for that scheme at t = 0.05 (about 4 times the measured errors). The scene's
WCSPH now adds the delta+-SPH particle shifting and a density diffusion and stays on the
exact solution (docs/stability.md, "Taylor-Green with WCSPH"): nx = 50 to t = 1 with
--whole-run --decay-tol 0.015 --l1-tol 0.015 (tests/validation/CMakeLists.txt), about 1.6-1.8
times the largest measured errors, +0.93% and 0.82% (both at t = 1).

The other schemes of the scene (sphc -D scheme=edac|tvf) are checked with tolerances given
on the command line (tests/validation/CMakeLists.txt):
  - EDAC (Ramachandran & Puri 2019, with the transport velocity; the scene starts it off
    the lattice by up to +-0.1 dx and shifts the particles after each step), nx = 50 to
    t = 1: --whole-run --decay-tol 0.025 --l1-tol 0.015, about 1.5 and 1.8 times the largest
    measured, +1.71% (t = 0.1) and 0.81% (t = 1) (+1.61% and 1.17% at t = 2; on the exact
    lattice without the shift -4.84% and 3.45% at t = 1; PySPH 1.0b1's EDAC, on the lattice:
    -1.85% and 2.16% at t = 2), while a viscosity 25% off moves the amplitude at t = 1 by 18%
    (measured: the scene run at Re = 80 ends at -21.6% and 20.5%) and a WCSPH-like break-up
    gives errors of 40% and more;
  - TVF (Adami, Hu & Adams 2013), the particles started off the lattice by up to +-0.1 dx
    (on the exact lattice it breaks up from t ~ 0.08, as PySPH 1.0b1's example does), nx = 50
    to t = 1: --decay-tol 0.05 --l1-tol 0.10, about 1.5 times the measured -3.0% and 7.1%
    (-3.0% and 9.7% at t = 2; PySPH 1.0b1's `--perturb 0.1`: -2.7% and 6.7% at t = 0.5,
    sphc +1.8% and 5.5%), while the lattice start ends at -40% and 43% at t = 0.5 and a
    viscosity 25% off moves the amplitude at t = 1 by 18%.

Also checked: all values finite, the particle count and total mass constant (exactly: the
particles keep their mass), positions inside the periodic box [0, L).

Prints a table and exits 0 when every check passes, 1 when one fails, 2 on bad input. It
draws the decay of the largest speed against the exact one, the L1 error against time, and
the particle speeds at the last snapshot into OUTPUT_DIR/taylor_green.png (--plot PATH:
elsewhere; tests/validation/plots.py).

Usage: taylor_green.py OUTPUT_DIR [--re 100] [--decay-tol 0.01] [--l1-tol 0.01] [--whole-run]
                       [--plot out.png]
"""

import os
import sys

try:
    import h5py
    import numpy as np
except ImportError as exc:  # pragma: no cover - environment problem, not a test failure
    sys.stderr.write("taylor_green.py needs numpy and h5py (%s)\n" % exc)
    sys.exit(2)

import plots  # noqa: E402  (tests/validation/plots.py)
from snapshots import FluidCount, argument_parser, read_fluid, snapshots  # noqa: E402  (snapshots.py)
from metrics_csv import read_metrics, row_at  # noqa: E402  (metrics_csv.py)


def exact_velocity(x, y, t, re, U=1.0, L=1.0):
    """The exact (u, v) at (x, y, t)."""
    k = 2.0 * np.pi / L
    nu = U * L / re
    f = U * np.exp(-2.0 * nu * k * k * t)
    return -f * np.cos(k * x) * np.sin(k * y), f * np.sin(k * x) * np.cos(k * y)


def speed_errors(x, y, u, v, t, re, U=1.0, L=1.0):
    """(decay error, L1 error of the speed) of the particle velocities (u, v) at (x, y, t):
    max |v| / (U e^{bt}) - 1 and sum | |v| - |v_e| | / sum |v_e| (bench/taylor_green_vs_pysph.py
    applies the same to PySPH's output)."""
    ue, ve = exact_velocity(x, y, t, re, U, L)
    speed = np.hypot(u, v)
    speed_e = np.hypot(ue, ve)
    nu = U * L / re
    amp = U * np.exp(-2.0 * nu * (2.0 * np.pi / L) ** 2 * t)
    decay_err = float(speed.max() / amp - 1.0)
    l1 = float(np.sum(np.abs(speed - speed_e)) / np.sum(speed_e))
    return decay_err, l1


def main():
    ap = argument_parser(__doc__, "directory with the Taylor-Green HDF5 snapshots",
                         "taylor_green.png")
    ap.add_argument("--re", type=float, default=100.0, help="Reynolds number (default 100)")
    ap.add_argument("--L", type=float, default=1.0, help="side of the box (default 1)")
    ap.add_argument("--U", type=float, default=1.0, help="velocity scale (default 1)")
    ap.add_argument("--decay-tol", type=float, default=0.01,
                    help="largest |decay error| at the last snapshot (default 0.01)")
    ap.add_argument("--l1-tol", type=float, default=0.01,
                    help="largest L1 error of the speed at the last snapshot (default 0.01)")
    ap.add_argument("--whole-run", action="store_true",
                    help="judge both tolerances at every snapshot, not only the last")
    args = ap.parse_args()

    files = snapshots(args.outdir, "taylor_green.py")
    if files is None:
        return 2
    # The errors are the solver's own metrics (the scene's metrics { }: decay_err, l1), one
    # row per snapshot; the last snapshot's are recomputed here from the particles as a check
    # of the metrics themselves.
    metrics = read_metrics(args.outdir, "taylor_green.py", ("decay_err", "l1", "mass"))
    if metrics is None:
        return 2

    failures = []
    rows = []
    count = FluidCount()
    last = None
    for path in files:
        name = os.path.basename(path)
        with h5py.File(path, "r") as f:
            got = read_fluid(f, name, ("x", "y", "u", "v", "m"), "taylor_green.py", failures)
            if got is None:
                return 2
            t, (x, y, u, v, m) = got
        count.check(name, m, failures)
        outside = int(np.count_nonzero((x < 0) | (x >= args.L) | (y < 0) | (y >= args.L)))
        if outside:
            failures.append("%s: %d particles outside the periodic box [0, %g)^2"
                            % (name, outside, args.L))
        speed = np.hypot(u, v)
        nu = args.U * args.L / args.re
        amp = args.U * np.exp(-2.0 * nu * (2.0 * np.pi / args.L) ** 2 * t)
        k = row_at(metrics, t)
        if k is None:
            failures.append("%s: no row of the metric file at t = %.17g" % (name, t))
            continue
        decay_err, l1 = metrics["decay_err"][k], metrics["l1"][k]
        rows.append((t, float(speed.max()), amp, decay_err, l1))
        last = (t, x, y, u, v, speed)
    if len(metrics["t"]) != len(files):
        failures.append("the metric file has %d rows, there are %d snapshots"
                        % (len(metrics["t"]), len(files)))
    if last is not None:
        # The metrics against an independent computation from the last snapshot (numpy).
        t, x, y, u, v, _ = last
        py_decay, py_l1 = speed_errors(x, y, u, v, t, args.re, args.U, args.L)
        for what, ours, theirs in (("decay error", rows[-1][3], py_decay),
                                   ("L1 error", rows[-1][4], py_l1)):
            if not abs(ours - theirs) <= 1e-9 * max(abs(theirs), 1e-12):
                failures.append("t = %.4f: the solver's metric %s %.17g differs from the one "
                                "computed from the snapshot, %.17g" % (t, what, ours, theirs))
    if not rows:
        print("FAILED: " + "; ".join(failures))
        return 1

    print("Taylor-Green vortex, Re = %g, vs the exact solution: %d snapshots in %s, "
          "%d particles" % (args.re, len(files), args.outdir, count.n0))
    print("decay error = max|v| / (U exp(-8 pi^2 t / Re)) - 1;  L1 = sum| |v| - |v_e| | / "
          "sum |v_e|")
    print()
    print("%8s %10s %10s %12s %10s" % ("t", "max |v|", "exact", "decay err", "L1 err"))
    for t, vmax, amp, de, l1 in rows:
        print("%8.4f %10.5f %10.5f %+11.2f%% %9.2f%%" % (t, vmax, amp, 100 * de, 100 * l1))
    print()

    if rows[-1][0] <= 0.0:
        failures.append("the last snapshot is at t = 0: the run did not advance")
    for t, vmax, amp, decay_err, l1 in (rows if args.whole_run else rows[-1:]):
        if not abs(decay_err) <= args.decay_tol:
            failures.append("t = %.4f: largest speed %.5f, exact %.5f: decay error %+.2f%% "
                            "(tolerance %.2f%%)" % (t, vmax, amp, 100 * decay_err,
                                                    100 * args.decay_tol))
        if not l1 <= args.l1_tol:
            failures.append("t = %.4f: L1 error of the speed %.2f%% (tolerance %.2f%%)"
                            % (t, 100 * l1, 100 * args.l1_tol))
    t, vmax, amp, decay_err, l1 = rows[-1]

    def draw(plt):
        r = np.array(rows)
        fig, (ax1, ax2, ax3) = plt.subplots(1, 3, figsize=(14, 4.2))
        ts = np.linspace(0, r[-1, 0], 200)
        nu = args.U * args.L / args.re
        ax1.semilogy(ts, args.U * np.exp(-2.0 * nu * (2 * np.pi / args.L) ** 2 * ts), "k-",
                     label="exact U exp(-8 pi^2 nu t / L^2)")
        ax1.semilogy(r[:, 0], r[:, 1], "o", label="sphc, max |v|")
        ax1.set_xlabel("t [L/U]")
        ax1.set_ylabel("max |v| / U")
        ax1.set_title("Re = %g: decay error %+.2f%% at t = %.3g (tolerance %.1f%%)"
                      % (args.re, 100 * decay_err, r[-1, 0], 100 * args.decay_tol),
                      fontsize=9)
        ax1.legend(fontsize=8)
        ax2.plot(r[:, 0], 100 * r[:, 4], "o-", label="L1 error of |v|")
        ax2.plot(r[:, 0], 100 * np.abs(r[:, 3]), "s-", label="|decay error|")
        ax2.set_xlabel("t [L/U]")
        ax2.set_ylabel("error [%]")
        ax2.legend(fontsize=8)
        t, x, y, _, _, speed = last
        sc = ax3.scatter(x, y, c=speed, s=2, cmap="viridis")
        fig.colorbar(sc, ax=ax3, label="|v| / U")
        ax3.set_aspect("equal")
        ax3.set_xlabel("x / L")
        ax3.set_ylabel("y / L")
        ax3.set_title("particle speeds at t = %.3f" % t, fontsize=9)
        return fig

    plots.write(args, draw, failures)

    if failures:
        print("FAILED (%d problems):" % len(failures))
        for msg in failures:
            print("  " + msg)
        return 1
    if args.whole_run:
        worst_d = max(abs(r[3]) for r in rows)
        worst_l1 = max(r[4] for r in rows)
        print("PASSED: every snapshot to t = %.4f: |decay error| at most %.2f%% (tolerance "
              "%.2f%%), L1 error at most %.2f%% (tolerance %.2f%%); mass conserved exactly; "
              "all values finite" % (t, 100 * worst_d, 100 * args.decay_tol, 100 * worst_l1,
                                     100 * args.l1_tol))
        return 0
    print("PASSED: t = %.4f, decay error %+.2f%% (tolerance %.1f%%), L1 error %.2f%% "
          "(tolerance %.1f%%); mass conserved exactly; all values finite"
          % (t, 100 * decay_err, 100 * args.decay_tol, 100 * l1, 100 * args.l1_tol))
    return 0


if __name__ == "__main__":
    sys.exit(main())
