#!/usr/bin/env python3
"""Checks the start-up of plane Poiseuille and Couette flow (examples/poiseuille.sph,
examples/couette.sph) against the exact series solutions.

The set-up (J. P. Morris, P. J. Fox, Y. Zhu, "Modeling low Reynolds number incompressible
flows using SPH", J. Comput. Phys. 136 (1997) 214-226; also the Poiseuille and Couette tests
of S. Adami, X. Y. Hu, N. A. Adams, J. Comput. Phys. 241 (2013) 292-307): fluid between
plates y = 0 and y = d, periodic in x, at rest at t = 0; d = 1e-3 m, nu = 1e-6 m^2/s.
Poiseuille: both plates fixed, a body force F = 1e-4 m/s^2 along x. Couette: no force, the
plate y = d moves with U = 1.25e-5 m/s. Both at Re = 0.0125.

The exact solutions (derived here; the flow is u(y, t) along x with u_t = nu u_yy + F):
write u = u_s(y) + w(y, t) with the steady profile u_s and w_t = nu w_yy, w = 0 on the
plates, w(y, 0) = -u_s(y); expand w in sin(k pi y / d), whose modes decay as
exp(-k^2 pi^2 nu t / d^2), with the sine coefficients of -u_s:

  Poiseuille: u_s = F y (d - y) / (2 nu) (u_max = F d^2 / (8 nu) at y = d/2);
      (2/d) int_0^d y (d - y) sin(k pi y / d) dy = 8 d^2 / (k pi)^3 for odd k, 0 for even k:
      u = F y (d - y) / (2 nu)
          - sum_{k odd} 4 F d^2 / (nu pi^3 k^3) sin(k pi y / d) exp(-k^2 pi^2 nu t / d^2).
      (The form F y (y - d) / (2 nu) + sum_{k odd} ... with the same terms, as it is
      sometimes quoted, is -u: the velocity counted against the force.)
  Couette: u_s = U y / d;  (2/d) int_0^d (y / d) sin(n pi y / d) dy = 2 (-1)^(n+1) / (n pi):
      u = U y / d + sum_{n >= 1} 2 U (-1)^n / (n pi) sin(n pi y / d) exp(-n^2 pi^2 nu t / d^2).

The script checks these series before using them (self_test): at t = 0 they sum to
u = 0 inside the channel (to the truncation error of the slowly converging t = 0 series),
at large t they equal u_s, and a finite-difference solution of u_t = nu u_yy + F (Crank-
Nicolson, 400 cells) agrees with them at t = 0.0225 and 0.1125 s to 1e-4 u_ref.

How the SPH profile is read: the fluid particles are binned in y into ny bins of width
d / ny (ny = the number of particle rows at t = 0, so a bin holds one row of the lattice);
in each bin the mean of u is compared with the mean of the exact u(y_j, t) over the same
particles, at the snapshot's time t. Error figures in units of u_ref (u_max for Poiseuille,
U for Couette; a relative error of the local velocity would blow up at the walls, where
u -> 0): the largest |u_SPH - u_exact| over the bins, and the rms. Checked at the snapshots
nearest to t = 0.0225, 0.045, 0.1125, 0.225, 0.45 s (in units of d^2 / nu; from a fifth of
the slowest mode's decay time d^2 / (pi^2 nu) = 0.101 s to 4.5 times it) and at the last
snapshot, which is the steady state when tf >= 1 s (the slowest
mode has decayed to exp(-pi^2) = 5e-5 of its start: the series and u_s differ by < 1e-4
u_ref); the table also gives the error against u_s there.

Tolerances (--tol; defaults 1.5% of u_ref for Poiseuille, 1% for Couette, at every checked
time):
  * Morris et al. (1997) show SPH and series profiles agreeing to within the symbol size in
    figures (no table); Adami et al. (2013) show the TVF Poiseuille and Couette profiles in
    close agreement with the series, also in figures only: neither gives an error figure.
  * Measured with sphc (docs/validation.md), TVF: Poiseuille, largest at the steady state
    and mid-channel: ny = 20: 1.00%; ny = 40 (CI): 0.73%; ny = 80: 0.65%. The error does
    not vanish with dx: about 0.6% of it is the regularisation EPS = 0.01 h^2 in the
    denominator r^2 + EPS of the viscous term of Adami et al. (2013) (Morris et al.'s
    eta^2 = 0.01 h^2), which on the lattice with h = dx makes the SPH Laplacian of a
    quadratic 0.60% too small (the quintic spline summed over the lattice), so the steady
    speed is 0.6% too high; with EPS = 1e-6 h^2 instead the error is 0.41% (ny = 20) and
    0.12% (ny = 40). The rest, a slip at the walls, shrinks with dx. Couette, largest at the
    earliest time (t = 0.0225 s, the steep profile next to the moving plate): ny = 20:
    0.47%; ny = 40: 0.24%; ny = 80: 0.17%; < 0.03% at the steady state (a linear profile
    has no Laplacian: the EPS bias does not act). The WCSPH variant: Poiseuille 1.00% /
    0.72%, Couette 0.67% / 0.28% (ny = 20 / 40). PySPH 1.0b1's TVF examples give the same
    errors to 0.001% (Couette at ny = 20, Poiseuille at ny = 60 to t = 0.45 s).
  * The tolerances are 1.5 times the largest error measured at ny = 20, the coarsest
    resolution run (Poiseuille 1.00%, Couette 0.67%, rounded up to 1%), well inside what
    agreement "within the symbol size" of the papers' figures allows (a few percent). Runs that must fail do (ny = 20): without the
    no-slip wall term (Poiseuille 790%, Couette 97.5%: the fluid slips), and with 5% too
    little viscosity (Poiseuille 6.3%, Couette 1.7% at t = 0.0225 s).

The error checked is the solver's own metric (the scene's `metrics { }`: u_err, the largest
|u - u_exact| / u_ref over the fluid particles against the series truncated in the scene,
column u_err of OUTPUT_DIR/<scene>_metrics.csv) at the checked times; this script recomputes
it from each checked snapshot with the 400-term series to check the metric itself (to 1e-6
u_ref), and prints the binned profile errors beside it (a bin's mean error is never larger
than the largest error of its particles). PySPH's snapshots (*.hdf5, no metric file) are
judged on the binned error.

Also checked, in every snapshot: all values finite, the number of fluid particles and
their mass unchanged, every fluid particle inside the channel (0 < y < d), |v| < 1% u_ref
(the flow is parallel).

OUTPUT_DIR may also hold PySPH's snapshots (`pysph run couette -d DIR`, *.hdf5; PySPH's
units: --d 1 --nu 0.01 --U 1.25e-4, or --F 1e-5 for its poiseuille), for the comparison in
docs/validation.md.

Prints the table of errors per time (and the profile at the last time); exits 0 when every
check passes, 1 when one fails, 2 on bad input. It draws the binned profiles and the series
at the checked times into OUTPUT_DIR/channel_flow.png (--plot PATH: elsewhere;
tests/validation/plots.py).

Usage: channel_flow.py OUTPUT_DIR [--flow poiseuille|couette] [--d 1e-3] [--nu 1e-6]
                       [--F 1e-4] [--U 1.25e-5] [--tol 0.015] [--plot out.png]
"""

import os
import sys

try:
    import h5py
    import numpy as np
except ImportError as exc:  # pragma: no cover - environment problem, not a test failure
    sys.stderr.write("channel_flow.py needs numpy and h5py (%s)\n" % exc)
    sys.exit(2)

import plots  # noqa: E402  (tests/validation/plots.py)
from metrics_csv import metrics_file, read_metrics, row_at  # noqa: E402  (metrics_csv.py)
from snapshots import (FluidCount, argument_parser, read_fluid, report_failures,  # noqa: E402
                       snapshots)

# In units of d^2 / nu (= 1 s in Morris's set-up).
CHECK_TIMES = (0.0225, 0.045, 0.1125, 0.225, 0.45)


def poiseuille_exact(y, t, d, nu, F, terms=400):
    """Start-up of plane Poiseuille flow (module docstring)."""
    y = np.asarray(y, dtype=float)
    u = F * y * (d - y) / (2.0 * nu)
    for k in range(1, 2 * terms, 2):
        u = u - (4.0 * F * d * d / (nu * np.pi ** 3 * k ** 3) * np.sin(k * np.pi * y / d) *
                 np.exp(-k * k * np.pi ** 2 * nu * t / (d * d)))
    return u


def couette_exact(y, t, d, nu, U, terms=4000):
    """Start-up of plane Couette flow (module docstring)."""
    y = np.asarray(y, dtype=float)
    u = U * y / d
    for n in range(1, terms + 1):
        u = u + (2.0 * U * (-1) ** n / (n * np.pi) * np.sin(n * np.pi * y / d) *
                 np.exp(-n * n * np.pi ** 2 * nu * t / (d * d)))
    return u


def finite_difference(flow, t_end, d, nu, F, U, cells=400, steps=4000):
    """u(y, t_end) of u_t = nu u_yy + F (Crank-Nicolson, u = 0 at t = 0): an independent
    check of the series. Returns (y, u) at the interior nodes."""
    dy = d / cells
    y = np.arange(1, cells) * dy
    dt = t_end / steps
    r = nu * dt / dy ** 2
    n = cells - 1
    force = F if flow == "poiseuille" else 0.0
    top = U if flow == "couette" else 0.0
    # (I - r/2 D2) u^{n+1} = (I + r/2 D2) u^n + dt F + boundary terms; the matrix is fixed,
    # so it is inverted once.
    lhs = (np.diag(np.full(n, 1.0 + r)) + np.diag(np.full(n - 1, -0.5 * r), 1) +
           np.diag(np.full(n - 1, -0.5 * r), -1))
    inv = np.linalg.inv(lhs)
    u = np.zeros(n)
    for _ in range(steps):
        rhs = (1.0 - r) * u + dt * force
        rhs[1:] += 0.5 * r * u[:-1]
        rhs[:-1] += 0.5 * r * u[1:]
        rhs[-1] += r * top  # the plate value, at both time levels
        u = inv @ rhs
    return y, u


def self_test(flow, d, nu, F, U, uref):
    """Checks the series (module docstring). Returns a list of failures."""
    out = []
    exact = ((lambda y, t: poiseuille_exact(y, t, d, nu, F)) if flow == "poiseuille"
             else (lambda y, t: couette_exact(y, t, d, nu, U)))
    steady = ((lambda y: F * y * (d - y) / (2 * nu)) if flow == "poiseuille"
              else (lambda y: U * y / d))
    # t = 0: the series sums to zero inside (the t = 0 Couette series converges like 1/n,
    # with its Gibbs overshoot at y = d: test away from the moving plate).
    yi = np.linspace(0.05, 0.9, 18) * d
    e0 = float(np.max(np.abs(exact(yi, 0.0)))) / uref
    if not e0 < 2e-3:
        out.append("self-test: the series at t = 0 is %.2e u_ref, not 0" % e0)
    ys = np.linspace(0.0, 1.0, 21) * d
    einf = float(np.max(np.abs(exact(ys, 5.0 * d * d / nu) - steady(ys)))) / uref
    if not einf < 1e-9:
        out.append("self-test: the series at large t differs from the steady profile by "
                   "%.2e u_ref" % einf)
    for tt in (0.0225, 0.1125):
        tt_s = tt * d * d / nu  # times in units of d^2 / nu (= 1 s in Morris's set-up)
        yf, uf = finite_difference(flow, tt_s, d, nu, F, U)
        efd = float(np.max(np.abs(exact(yf, tt_s) - uf))) / uref
        if not efd < 1e-4:
            out.append("self-test: the series and a finite-difference solution differ by "
                       "%.2e u_ref at t = %g" % (efd, tt_s))
    return out, e0, einf


def main():
    ap = argument_parser(__doc__, "directory with the scene's HDF5 snapshots", "channel_flow.png")
    ap.add_argument("--flow", choices=("poiseuille", "couette"), default=None,
                    help="the flow (default: from the snapshot names)")
    ap.add_argument("--d", type=float, default=1e-3, help="channel width (default 1e-3 m)")
    ap.add_argument("--nu", type=float, default=1e-6, help="viscosity (default 1e-6 m^2/s)")
    ap.add_argument("--F", type=float, default=1e-4,
                    help="Poiseuille body force (default 1e-4 m/s^2)")
    ap.add_argument("--U", type=float, default=1.25e-5,
                    help="Couette plate speed (default 1.25e-5 m/s)")
    ap.add_argument("--tol", type=float, default=None,
                    help="largest |u_SPH - u_exact| / u_ref at every checked time "
                         "(default 0.015 for Poiseuille, 0.01 for Couette)")
    args = ap.parse_args()

    files = snapshots(args.outdir, "channel_flow.py")
    if files is None:
        return 2
    flow = args.flow
    if flow is None:
        base = os.path.basename(files[0])
        flow = next((f for f in ("poiseuille", "couette") if base.startswith(f)), None)
        if flow is None:
            sys.stderr.write("channel_flow.py: cannot tell the flow from %s: give --flow\n"
                             % base)
            return 2
    d, nu, F, U = args.d, args.nu, args.F, args.U
    tol = args.tol if args.tol is not None else (0.015 if flow == "poiseuille" else 0.01)
    if flow == "poiseuille":
        uref = F * d * d / (8.0 * nu)
        exact = lambda y, t: poiseuille_exact(y, t, d, nu, F)  # noqa: E731
        steady = lambda y: F * y * (d - y) / (2.0 * nu)  # noqa: E731
    else:
        uref = U
        exact = lambda y, t: couette_exact(y, t, d, nu, U)  # noqa: E731
        steady = lambda y: U * y / d  # noqa: E731

    failures, e0, einf = self_test(flow, d, nu, F, U, uref)
    # The solver's metric file (not with PySPH's snapshots, *.hdf5).
    metrics = None
    if metrics_file(args.outdir) is not None or not files[0].endswith(".hdf5"):
        metrics = read_metrics(args.outdir, "channel_flow.py", ("u_err",))
        if metrics is None:
            return 2

    snaps = []  # (t, y, u)
    count = FluidCount()
    ny = None
    for path in files:
        name = os.path.basename(path)
        with h5py.File(path, "r") as f:
            got = read_fluid(f, name, ("x", "y", "u", "v", "m"), "channel_flow.py", failures)
            if got is None:
                return 2
            t, (_, y, u, v, m) = got
        if ny is None:
            ny = len(np.unique(np.round(y / d * 1e6)))
        count.check(name, m, failures)
        out = (y <= 0) | (y >= d)
        if np.any(out):
            failures.append("t = %.4f: %d fluid particles outside the channel"
                            % (t, int(np.count_nonzero(out))))
        vmax = float(np.max(np.abs(v))) / uref if len(v) else 0.0
        if not vmax < 0.01:
            failures.append("t = %.4f: |v| up to %.3g u_ref (flow not parallel)" % (t, vmax))
        snaps.append((t, y, u))

    def profile(y, u, t):
        """Bin means (y, u_SPH, u_exact, u_steady) over the ny bins."""
        k = np.clip((y / d * ny).astype(int), 0, ny - 1)
        cnt = np.bincount(k, minlength=ny)
        ok = cnt > 0
        def mean(q):
            return np.bincount(k, weights=q, minlength=ny)[ok] / cnt[ok]
        return mean(y), mean(u), mean(exact(y, t)), mean(steady(y))

    # The snapshots nearest to the check times (within the scene's end), and the last one.
    tf = snaps[-1][0]
    chosen = []
    for tc in CHECK_TIMES:
        if tc * d * d / nu > tf + 1e-12:
            continue
        i = int(np.argmin([abs(s[0] - tc * d * d / nu) for s in snaps]))
        if i not in chosen and snaps[i][0] > 0:
            chosen.append(i)
    if len(snaps) - 1 not in chosen:
        chosen.append(len(snaps) - 1)

    print("%s flow: %d snapshots in %s, %d fluid particles (ny = %d rows), t = %.4g s"
          % (flow, len(files), args.outdir, count.n0, ny, tf))
    print("u_ref = %.4g m/s (%s); Re = %.4g" % (uref, "u_max" if flow == "poiseuille" else "U",
                                                 uref * d / nu))
    print("series self-test: |u(t = 0)| <= %.1e u_ref, |u(t -> inf) - u_s| <= %.1e u_ref, "
          "finite differences agree" % (e0, einf) if not failures else
          "series self-test: see the failures below")
    print()
    # u at mid-channel (Poiseuille) or in the row next to the moving plate (Couette)
    where = "centre" if flow == "poiseuille" else "top"
    print("%10s %12s %10s %10s %10s %12s %12s" % ("t (s)", "t nu/d^2", "u_err", "bin max",
                                                  "bin rms", "u_%s SPH" % where,
                                                  "u_%s exact" % where))
    rows = []
    for i in chosen:
        t, y, u = snaps[i]
        yb, ub, ue, us = profile(y, u, t)
        err = (ub - ue) / uref
        emax = float(np.max(np.abs(err)))
        erms = float(np.sqrt(np.mean(err ** 2)))
        j = int(np.argmin(np.abs(yb - 0.5 * d))) if flow == "poiseuille" else len(yb) - 1
        judged = emax
        metric = float("nan")
        if metrics is not None:
            k = row_at(metrics, t)
            if k is None:
                failures.append("t = %.4f s: no row of the metric file at this time" % t)
            else:
                metric = metrics["u_err"][k]
                mine = float(np.max(np.abs(u - exact(y, t)))) / uref
                if not abs(metric - mine) <= 1e-6:
                    failures.append("t = %.4f s: the solver's metric u_err %.9g differs from "
                                    "the one recomputed here, %.9g" % (t, metric, mine))
                judged = metric
        rows.append((t, yb, ub, ue, us, emax, erms))
        print("%10.4f %12.4f %9.3f%% %9.3f%% %9.3f%% %12.5f %12.5f"
              % (t, t * nu / (d * d), 100 * metric, 100 * emax, 100 * erms, ub[j] / uref,
                 ue[j] / uref))
        if not judged <= tol:
            failures.append("t = %.4f s: %s %.3f%% of u_ref (tolerance %.2f%%)"
                            % (t, "u_err" if metrics is not None else "max error",
                               100 * judged, 100 * tol))
    t, yb, ub, ue, us, emax, erms = rows[-1]
    esteady = float(np.max(np.abs(ub - us))) / uref
    print()
    print("profile at t = %.4f s (bins of width d/%d):" % (t, ny))
    print("%8s %10s %10s %10s %9s" % ("y/d", "u_SPH", "u_exact", "u_steady", "error"))
    for k in range(0, len(yb), max(1, len(yb) // 20)):
        print("%8.4f %10.5f %10.5f %10.5f %+8.3f%%" % (yb[k] / d, ub[k] / uref, ue[k] / uref,
                                                      us[k] / uref,
                                                      100 * (ub[k] - ue[k]) / uref))
    print()
    print("at t = %.4f s: max error %.3f%% of u_ref against the series, %.3f%% against the "
          "steady profile (series - steady: %.2e u_ref)"
          % (t, 100 * emax, 100 * esteady, float(np.max(np.abs(ue - us))) / uref))
    print()

    def draw(plt):
        fig, ax = plt.subplots(figsize=(6, 4.5))
        yl = np.linspace(0, d, 201)
        for k, (t, yb, ub, ue, us, emax, erms) in enumerate(rows):
            col = "C%d" % (k % 10)
            ax.plot(exact(yl, t) / uref, yl / d, "-", color=col, lw=1)
            ax.plot(ub / uref, yb / d, "o", color=col, mfc="none", ms=4,
                    label="t = %.4g s (max err %.2f%%)" % (t, 100 * emax))
        ax.set_xlabel("u / u_ref (u_ref = %.3g m/s)" % uref)
        ax.set_ylabel("y / d")
        ax.set_title("%s start-up, %d rows: sphc (o), series (-)"
                     % (flow.capitalize(), ny))
        ax.legend(fontsize=7)
        return fig

    plots.write(args, draw, failures)

    if report_failures(failures, 20):
        return 1
    print("PASSED: %s flow, %d rows, profiles within %.3f%% of u_ref of the series at %d "
          "times up to t = %.4g s (tolerance %.2f%%); mass conserved, all values finite"
          % (flow, ny, 100 * max(r[5] for r in rows), len(rows), rows[-1][0], 100 * tol))
    return 0


if __name__ == "__main__":
    sys.exit(main())
