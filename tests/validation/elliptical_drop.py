#!/usr/bin/env python3
"""Checks the elliptical drop (examples/elliptical_drop.sph) against its exact solution.

The case (Monaghan, "Simulating free surface flows with SPH", J. Comput. Phys. 110 (1994)
399-406): a circular drop of radius 1 of inviscid incompressible fluid, no gravity, starts
with u = -A0 x, v = A0 y (A0 = 100 1/s) and stretches into an ellipse along y.

Exact solution. Try the velocity field u = -A(t) x, v = A(t) y (divergence free) and the
pressure p = p0(t) (1 - x^2/a^2 - y^2/b^2), zero on the ellipse x^2/a^2 + y^2/b^2 = 1 that
the flow carries (da/dt = -A a, db/dt = A b, so a b = 1: the area is conserved). Euler's
equations with density 1, Du/Dt = -dp/dx and Dv/Dt = -dp/dy, give

    x (A^2 - dA/dt) = 2 p0 x / a^2,      y (A^2 + dA/dt) = 2 p0 y / b^2,

so the trial fields are exact when (A^2 - dA/dt) a^2 = (A^2 + dA/dt) b^2 (both = 2 p0),
that is, with b = 1/a,

    dA/dt = A^2 (a^4 - 1) / (a^4 + 1),    da/dt = -A a,    A(0) = A0, a(0) = 1,

and p0 = a^2 (A^2 - dA/dt) / 2 (the pressure at the centre). This script integrates these
ODEs with classical RK4 (numpy only, 4,000 steps to tf = 0.0076; halving the step changes b
by less than 1e-12) and compares the semi-major axis b = 1/a at the time of the last snapshot
with the particles':

  - tip:    b_tip = max |y| of the particles (Monaghan's and PySPH's measure). The drop
            starts with a particle exactly on the circle at (0, +-1), which the flow carries
            along the y axis to (0, +-b);
  - moment: b_mom = sqrt(<y^2>(t) / <y^2>(0)): the flow is a linear (affine) map, under
            which the second moment scales exactly with b^2, so this is a fit of the whole
            drop, independent of the particles at the rim.

Tolerance. The judged figure is the relative error of b_tip, |b_tip / b - 1| <= --tol
(default 2%). Where it comes from: the drop is slowed by the artificial viscosity of the
scheme (alpha h c0 / 8 = 0.57 at dx = 0.025, against A0 R^2 = 100, a Reynolds number of
~175), so SPH lags the inviscid solution. PySPH 1.0b1's elliptical_drop example (WCSPH, the
same set-up and resolution, EPEC integrator with an adaptive step) ends 1.03% short of the
exact semi-major axis (1.92443 against 1.94452), and sphc 1.03% short too; the lag shrinks
with h (sphc: -0.55% at dx = 0.0125), as a viscous lag does. 2% is about twice the error of
the reference code at this resolution: a scheme that loses or gains momentum, a wrong
equation of state or a broken integrator changes b by more than that (alpha = 1 instead of
0.1: -6.6%). The moment-based fit (-0.37% at dx = 0.025) is held to the same tolerance.

The particles' figures (max |y|, <y^2>, the density deviation) are the solver's own metrics,
the columns b_tip, y2 and drho of OUTPUT_DIR/elliptical_drop_metrics.csv (the scene's
`metrics { }`); this script recomputes them from the last snapshot to check the metrics
themselves (to 1e-9).

Also checked in every snapshot: all values finite; the number of particles and the total
mass unchanged (mass exactly: particles keep their mass); the density within 5% of rho0
(Monaghan's c0 = 1400 keeps it within ~1%).

Prints a table and exits 0 when every check passes, 1 when one fails, 2 on bad input. It
draws the particles and the exact ellipse, and the semi-axis against time, into
OUTPUT_DIR/elliptical_drop.png (--plot PATH: elsewhere; tests/validation/plots.py).

Usage: elliptical_drop.py OUTPUT_DIR [--tol 0.02] [--A0 100] [--plot out.png]
"""

import os
import sys

try:
    import h5py
    import numpy as np
except ImportError as exc:  # pragma: no cover - environment problem, not a test failure
    sys.stderr.write("elliptical_drop.py needs numpy and h5py (%s)\n" % exc)
    sys.exit(2)

import plots  # noqa: E402  (tests/validation/plots.py)
from metrics_csv import read_metrics, row_at  # noqa: E402  (metrics_csv.py)
from snapshots import (FluidCount, argument_parser, read_fluid, report_failures,  # noqa: E402
                       snapshots)


def rhs(state):
    """Right-hand side of the ODEs for (A, a)."""
    A, a = state
    a4 = a ** 4
    return np.array([A * A * (a4 - 1.0) / (a4 + 1.0), -A * a])


def exact(t, A0=100.0, nsteps=4000):
    """(A, a, b, p0) at time t: RK4 from (A0, 1) in nsteps steps."""
    y = np.array([A0, 1.0])
    if t > 0:
        k = t / nsteps
        for _ in range(nsteps):
            k1 = rhs(y)
            k2 = rhs(y + 0.5 * k * k1)
            k3 = rhs(y + 0.5 * k * k2)
            k4 = rhs(y + k * k3)
            y = y + k / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    A, a = y
    dA = rhs(y)[0]
    return A, a, 1.0 / a, 0.5 * a * a * (A * A - dA)


def main():
    ap = argument_parser(__doc__, "directory with the elliptical drop's HDF5 snapshots",
                         "elliptical_drop.png")
    ap.add_argument("--tol", type=float, default=0.02,
                    help="largest relative error of the semi-major axis (default 0.02)")
    ap.add_argument("--rho-tol", type=float, default=0.05,
                    help="largest relative deviation of the density from rho0 (default 0.05)")
    ap.add_argument("--A0", type=float, default=100.0, help="initial strain rate (default 100)")
    ap.add_argument("--rho0", type=float, default=1.0, help="reference density (default 1)")
    args = ap.parse_args()

    files = snapshots(args.outdir, "elliptical_drop.py")
    if files is None:
        return 2
    # The semi-axis measures and the density deviation are the solver's own metrics (the
    # scene's metrics { }: b_tip, y2, drho, one row per snapshot); the last snapshot's are
    # recomputed here from the particles as a check of the metrics themselves.
    metrics = read_metrics(args.outdir, "elliptical_drop.py", ("b_tip", "y2", "drho"))
    if metrics is None:
        return 2
    if len(metrics["t"]) != len(files):
        sys.stderr.write("elliptical_drop.py: the metric file has %d rows, there are %d "
                         "snapshots\n" % (len(metrics["t"]), len(files)))
        return 2

    failures = []
    rows = []
    count = FluidCount()
    mass0 = y20 = None
    first = last = None
    for path in files:
        name = os.path.basename(path)
        with h5py.File(path, "r") as f:
            got = read_fluid(f, name, ("x", "y", "rho", "m"), "elliptical_drop.py", failures)
            if got is None:
                return 2
            t, (x, y, rho, m) = got
        k = row_at(metrics, t)
        if k is None:
            sys.stderr.write("elliptical_drop.py: no row of the metric file at t = %.17g\n" % t)
            return 2
        if first is None:
            y20 = metrics["y2"][k]
            first = (t, x, y)
        mass = count.check(name, m, failures)
        mass0 = count.mass0
        drho = metrics["drho"][k]
        if not drho <= args.rho_tol:
            failures.append("%s: density deviates by %.2f%% from rho0 (tolerance %.0f%%)"
                            % (name, 100 * drho, 100 * args.rho_tol))
        b_ex = exact(t, args.A0)[2]
        b_tip = metrics["b_tip"][k]
        b_mom = float(np.sqrt(metrics["y2"][k] / y20))
        rows.append((t, b_ex, b_tip, b_mom, mass - mass0, drho))
        last = (t, x, y)
        last_rho = rho
    # The metrics against an independent computation from the last snapshot (numpy).
    t, x, y = last
    for what, ours, theirs in (
            ("max |y|", rows[-1][2], float(np.max(np.abs(y)))),
            ("<y^2>", metrics["y2"][-1], float(np.mean(y * y))),
            ("max |rho/rho0 - 1|", rows[-1][5], float(np.max(np.abs(last_rho / args.rho0 - 1.0))))):
        if not abs(ours - theirs) <= 1e-9 * max(abs(theirs), 1e-12):
            failures.append("t = %.5f: the solver's metric %s %.17g differs from the one "
                            "computed from the snapshot, %.17g" % (t, what, ours, theirs))

    print("elliptical drop vs exact solution (Monaghan 1994): %d snapshots in %s, %d particles"
          % (len(files), args.outdir, count.n0))
    print("b = semi-major axis: exact (RK4 of the ODEs), tip = max |y|, moment = "
          "sqrt(<y^2>/<y^2>_0)")
    print()
    print("%9s %9s %9s %8s %9s %8s %11s %9s"
          % ("t [s]", "b exact", "b tip", "err", "b moment", "err", "mass - m0", "max|drho|"))
    for t, b_ex, b_tip, b_mom, dm, drho in rows:
        print("%9.5f %9.5f %9.5f %+7.2f%% %9.5f %+7.2f%% %11.3g %8.2f%%"
              % (t, b_ex, b_tip, 100 * (b_tip / b_ex - 1), b_mom, 100 * (b_mom / b_ex - 1),
                 dm, 100 * drho))
    print()

    t, b_ex, b_tip, b_mom = rows[-1][:4]
    err_tip = b_tip / b_ex - 1.0
    err_mom = b_mom / b_ex - 1.0
    if t <= 0.0:
        failures.append("the last snapshot is at t = 0: the run did not advance")
    if not abs(err_tip) <= args.tol:
        failures.append("t = %.5f: semi-major axis (max |y|) %.5f, exact %.5f: error %+.2f%% "
                        "(tolerance %.1f%%)" % (t, b_tip, b_ex, 100 * err_tip, 100 * args.tol))
    if not abs(err_mom) <= args.tol:
        failures.append("t = %.5f: semi-major axis (second moment) %.5f, exact %.5f: error "
                        "%+.2f%% (tolerance %.1f%%)"
                        % (t, b_mom, b_ex, 100 * err_mom, 100 * args.tol))

    def draw(plt):
        fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4.8))
        th = np.linspace(0, 2 * np.pi, 400)
        ax1.plot(first[1], first[2], ".", ms=1, color="0.7", label="t = 0")
        ax1.plot(last[1], last[2], ".", ms=1.5, label="sphc, t = %.4f s" % t)
        a_ex = 1.0 / b_ex
        ax1.plot(a_ex * np.cos(th), b_ex * np.sin(th), "k-", lw=1, label="exact ellipse")
        ax1.set_aspect("equal")
        ax1.set_xlabel("x [m]")
        ax1.set_ylabel("y [m]")
        ax1.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=3, fontsize=7)
        ts = np.linspace(0, t, 60)
        ax2.plot(ts, [exact(s, args.A0, 400)[2] for s in ts], "k-", label="exact b (ODEs)")
        r = np.array(rows)
        ax2.plot(r[:, 0], r[:, 2], "o", label="sphc, max |y|")
        ax2.plot(r[:, 0], r[:, 3], "s", mfc="none", label="sphc, second moment")
        ax2.set_xlabel("t [s]")
        ax2.set_ylabel("semi-major axis b [m]")
        ax2.set_title("at t = %.4f s: error %+.2f%% (max |y|), %+.2f%% (moment); "
                      "tolerance %.1f%%" % (t, 100 * err_tip, 100 * err_mom, 100 * args.tol),
                      fontsize=9)
        ax2.legend(loc="upper left", fontsize=8)
        return fig

    plots.write(args, draw, failures)

    if report_failures(failures):
        return 1
    print("PASSED: t = %.5f, semi-major axis error %+.2f%% (max |y|), %+.2f%% (second moment), "
          "tolerance %.1f%%; mass conserved exactly; all values finite"
          % (t, 100 * err_tip, 100 * err_mom, 100 * args.tol))
    return 0


if __name__ == "__main__":
    sys.exit(main())
