#!/usr/bin/env python3
"""Check the square droplet (examples/square_droplet.sph: surface tension, the continuum
surface force of Morris 2000) against the Young-Laplace pressure jump dp = sigma / R, over
the whole run.

Every snapshot: the run finite, the mass exact (to round-off), the colours unchanged, and no
two particles closer than --min-pair dx (particles that pair up at the interface make its
curvature wrong: with the quintic spline they did, from t = 2 on). Every snapshot from
--t-settled on: the pressure jump dp = mean p (r < R - 3 dx) - mean p (r > R + 3 dx), r from
the drop's centroid, within --dp-tol-each of sigma / R, R = side / sqrt(pi) (the circle of the
square's area), and the drop a circle: the radius of its outermost particle in each of 32
sectors within --shape-tol of R - dx/2 (where the outermost particle centres of a circle of
radius R lie; the square starts 11% inside and 25% outside); the mean jump over those
snapshots within --dp-tol.

With --static (a run of --set circle=1 --tf 0: the colours of a circle on the lattice, no
motion), the force the interface exerts instead: the integral across the interface of the
colour gradient's radial part, int |n| dr, within --static-tol of 1, and of sigma kappa |n|
(the pressure jump the force balances) within --static-tol of sigma / R, with both estimated
from the particles as sum_a V_a (F_a . -r^_a) / (2 pi r_a).

With --oscillation (a run of --set circle=1 --set amp=A: the circle's radius perturbed by
A cos(2 theta)), the n = 2 capillary oscillation instead: the drop's deformation
D = (Ixx - Iyy) / (Ixx + Iyy) (second moments of its particles about the centroid) fitted by
C + exp(-g t) (a cos(w t) + b sin(w t)) over the snapshots (up to --t-fit-end), and the
fitted frequency w and damping rate g within --omega-tol and --gamma-tol of the viscous
theory's (capillary_2d.py: the normal mode of a 2D drop of viscosity --nu in a fluid of the
same density and viscosity, in the periodic box of side --box). Printed too: w against
Rayleigh's inviscid frequency for two fluids without the box (Lamb, Hydrodynamics, art. 275),

    omega^2 = (n^3 - n) sigma / ((rho_in + rho_out) R^3) = 6 sigma / (2 rho R^3)   (n = 2).
"""
import sys

import numpy as np

import capillary_2d
import snapshots

WHO = "square_droplet.py"


def nearest_pair(x, y, box):
    """The smallest distance between two particles (nearest periodic images in a box of
    side `box`), by rows of 512 particles."""
    best = np.inf
    for i in range(0, len(x), 512):
        ddx = (x[i:i + 512, None] - x[None, :] + 0.5 * box) % box - 0.5 * box
        ddy = (y[i:i + 512, None] - y[None, :] + 0.5 * box) % box - 0.5 * box
        d2 = ddx * ddx + ddy * ddy
        d2[np.arange(d2.shape[0]), np.arange(i, i + d2.shape[0])] = np.inf
        best = min(best, float(d2.min()))
    return float(np.sqrt(best))


def fit_oscillation(t, d, omega0):
    """(w, g, C) of the least-squares fit D = C + exp(-g t) (a cos w t + b sin w t): for each
    (w, g) of a grid the fit is linear in (C, a, b); the grid is refined about its best
    point three times."""
    def resid(w, g):
        e = np.exp(-g * t)
        A = np.column_stack([np.ones_like(t), e * np.cos(w * t), e * np.sin(w * t)])
        coef, *_ = np.linalg.lstsq(A, d, rcond=None)
        return float(((A @ coef - d) ** 2).sum()), coef[0]
    ws = np.linspace(0.3 * omega0, 2.0 * omega0, 171)
    gs = np.linspace(0.0, 2.0 * omega0, 101)
    for _ in range(4):
        best = min((resid(w, g)[0], w, g) for w in ws for g in gs)
        _, w, g = best
        dw, dg = ws[1] - ws[0], gs[1] - gs[0]
        ws = np.linspace(w - 2 * dw, w + 2 * dw, 41)
        gs = np.linspace(max(0.0, g - 2 * dg), g + 2 * dg, 41)
    return w, g, resid(w, g)[1]


def fit_curve(t, d, w, g):
    """The fitted curve C + exp(-g t) (a cos w t + b sin w t) at the times t."""
    e = np.exp(-g * t)
    A = np.column_stack([np.ones_like(t), e * np.cos(w * t), e * np.sin(w * t)])
    coef, *_ = np.linalg.lstsq(A, d, rcond=None)
    return A @ coef


def main():
    ap = snapshots.argument_parser(__doc__, "the scene's output directory", "square_droplet.png")
    ap.add_argument("--side", type=float, default=0.5, help="side of the initial square")
    ap.add_argument("--box", type=float, default=1.0, help="side of the periodic box")
    ap.add_argument("--sigma", type=float, default=1.0, help="surface tension")
    ap.add_argument("--rho", type=float, default=1.0, help="density (both colours)")
    ap.add_argument("--nx", type=int, default=40, help="particles along the box")
    ap.add_argument("--t-settled", type=float, default=1.5,
                    help="the jump and the outline are checked from this time on")
    ap.add_argument("--dp-tol", type=float, default=0.08,
                    help="relative tolerance of the mean pressure jump")
    ap.add_argument("--dp-tol-each", type=float, default=0.10,
                    help="relative tolerance of the jump at each settled snapshot")
    ap.add_argument("--shape-tol", type=float, default=0.04,
                    help="relative tolerance of the outermost radius per sector")
    ap.add_argument("--min-pair", type=float, default=0.1,
                    help="smallest distance allowed between two particles, in dx")
    ap.add_argument("--static", action="store_true",
                    help="check the interface force of a circle at t = 0 instead")
    ap.add_argument("--static-tol", type=float, default=0.02)
    ap.add_argument("--oscillation", action="store_true",
                    help="check the frequency of the n = 2 oscillation instead")
    ap.add_argument("--nu", type=float, default=0.05,
                    help="kinematic viscosity of the run (both colours)")
    ap.add_argument("--omega-tol", type=float, default=0.05,
                    help="relative tolerance of the oscillation's frequency")
    ap.add_argument("--gamma-tol", type=float, default=0.25,
                    help="relative tolerance of the oscillation's damping rate")
    ap.add_argument("--t-fit-end", type=float, default=None,
                    help="fit the oscillation over the snapshots up to this time (default: all)")
    args = ap.parse_args()

    keys = ["x", "y", "p", "m", "rho", "color", "kappa", "cgrad"]
    got = snapshots.read_series(args.outdir, keys, WHO, at_least=1 if args.static else 2)
    if got is None:
        return 2
    series, failures = got
    R = args.side / np.sqrt(np.pi)
    dx = args.box / args.nx
    exact = args.sigma / R
    rows = []
    mass0 = None
    color0 = None
    last = None
    for _, t, (x, y, p, m, rho, color, kappa, cgrad) in series:
        mass = m.sum()
        if mass0 is None:
            mass0, color0 = mass, color.copy()
        snapshots.check_conserved("mass", t, mass, mass0, 1e-12, failures)
        # (The solver sorts the particles into cell order: compare the sorted colours.)
        if not np.array_equal(np.sort(color), np.sort(color0)):
            failures.append("t = %g: the colours changed" % t)
        inside = color > 0.5
        # The drop's centroid; distances by the nearest periodic image.
        cx = x[inside].mean()
        cy = y[inside].mean()
        ddx = (x - cx + 0.5 * args.box) % args.box - 0.5 * args.box
        ddy = (y - cy + 0.5 * args.box) % args.box - 0.5 * args.box
        r = np.hypot(ddx, ddy)
        pin = p[r < R - 3 * dx]
        pout = p[r > R + 3 * dx]
        dp = pin.mean() - pout.mean() if len(pin) and len(pout) else float("nan")
        n = cgrad.reshape(-1, 3)
        nr = -(n[:, 0] * ddx + n[:, 1] * ddy) / np.maximum(r, 1e-12)
        vol = m / rho
        nint = (vol * nr / np.maximum(r, 1e-12)).sum() / (2 * np.pi)
        fint = args.sigma * (vol * kappa * nr / np.maximum(r, 1e-12)).sum() / (2 * np.pi)
        theta = np.arctan2(ddy, ddx)
        rb = []
        for i in range(32):
            s = inside & (theta >= -np.pi + i * np.pi / 16) & (theta < -np.pi + (i + 1) * np.pi / 16)
            rb.append(r[s].max() if s.any() else float("nan"))
        rb = np.array(rb)
        pair = nearest_pair(x, y, args.box) / dx
        if not pair >= args.min_pair:
            failures.append("t = %g: two particles %.4f dx apart (at least %g dx allowed)"
                            % (t, pair, args.min_pair))
        xi, yi = ddx[inside], ddy[inside]
        deform = ((xi * xi).sum() - (yi * yi).sum()) / ((xi * xi).sum() + (yi * yi).sum())
        rows.append((t, dp, fint, nint, rb.min(), rb.max(), pair, deform))
        last = (ddx, ddy, inside)

    print("sigma / R = %.4f (R = %.4f), dx = %.4f" % (exact, R, dx))
    print("%6s %10s %8s %14s %10s %10s %10s %9s %8s" % (
        "t", "dp", "dp err", "force int err", "int|n|dr", "rmin/R'", "rmax/R'", "pair/dx", "D"))
    Rb = R - 0.5 * dx
    for t, dp, fint, nint, rmin, rmax, pair, deform in rows:
        print("%6.2f %10.4f %+7.2f%% %+13.2f%% %10.4f %10.4f %10.4f %9.4f %+8.4f"
              % (t, dp, 100 * (dp / exact - 1), 100 * (fint / exact - 1), nint, rmin / Rb,
                 rmax / Rb, pair, deform))

    fit = None
    if args.static:
        t, dp, fint, nint = rows[0][:4]
        if abs(nint - 1) > args.static_tol:
            failures.append("int |n| dr = %.4f, not within %g of 1" % (nint, args.static_tol))
        if abs(fint / exact - 1) > args.static_tol:
            failures.append("the force balances a jump %.4f, not within %g of sigma / R = %.4f"
                            % (fint, args.static_tol, exact))
        print("static: int |n| dr = %.4f, force integral %.4f = (1 %+.2f%%) sigma / R"
              % (nint, fint, 100 * (fint / exact - 1)))
    elif args.oscillation:
        w0 = capillary_2d.omega0(2, R, args.sigma, args.rho)
        wv, gv = capillary_2d.mode(2, R, args.sigma, args.rho, args.nu, args.box)
        ts = np.array([row[0] for row in rows])
        ds = np.array([row[7] for row in rows])
        if args.t_fit_end is not None:
            ds = ds[ts <= args.t_fit_end + 1e-9]
            ts = ts[ts <= args.t_fit_end + 1e-9]
        w, g, c = fit_oscillation(ts, ds, w0)
        fit = (w, g, c)
        # The reference: the theory's drop started from rest like the run (the initial-value
        # problem), fitted the same way over the same time window (at 29 times: a smooth curve;
        # about 10 s of CPU), the normal mode printed too.
        ti = np.linspace(ts[0], ts[-1], 29)
        ai = capillary_2d.initial_value(2, R, args.sigma, args.rho, args.nu, args.box, ti)
        wi, gi, _ = fit_oscillation(ti, ai, w0)
        werr = w / wi - 1
        gerr = g / gi - 1
        print("n = 2 oscillation over %d snapshots (t = 0-%g, %.2f periods): fitted frequency"
              " %.4f, damping rate %.4f" % (len(ts), ts[-1], ts[-1] * w / (2 * np.pi), w, g))
        print("  viscous theory (capillary_2d.py, nu = %g, periodic box %g), started from rest"
              " and fitted over the same snapshots: frequency %.4f, damping rate %.4f; its normal"
              " mode: %.4f, %.4f; inviscid (Rayleigh, two fluids, no box) %.4f"
              % (args.nu, args.box, wi, gi, wv, gv, w0))
        print("  error: frequency %+.2f%% (tolerance %g%%), damping rate %+.2f%% (tolerance %g%%);"
              " against the normal mode %+.2f%%, %+.2f%%; the frequency against Rayleigh's"
              " inviscid %+.2f%%"
              % (100 * werr, 100 * args.omega_tol, 100 * gerr, 100 * args.gamma_tol,
                 100 * (w / wv - 1), 100 * (g / gv - 1), 100 * (w / w0 - 1)))
        if ts[-1] * w < 4 * np.pi:
            failures.append("the run covers %.2f periods, fewer than 2" % (ts[-1] * w / (2 * np.pi)))
        if not abs(werr) <= args.omega_tol:
            failures.append("oscillation frequency %.4f: %+.2f%% from the viscous theory's %.4f"
                            % (w, 100 * werr, wi))
        if not abs(gerr) <= args.gamma_tol:
            failures.append("damping rate %.4f: %+.2f%% from the viscous theory's %.4f"
                            % (g, 100 * gerr, gi))
    else:
        settled = [row for row in rows if row[0] >= args.t_settled - 1e-9]
        if len(settled) < 2:
            failures.append("fewer than 2 snapshots from t = %g on" % args.t_settled)
        else:
            mean_dp = float(np.mean([row[1] for row in settled]))
            err = mean_dp / exact - 1
            print("mean jump over t >= %g (%d snapshots): %.4f, error %+.2f%% (tolerance %g%%)"
                  % (args.t_settled, len(settled), mean_dp, 100 * err, 100 * args.dp_tol))
            if not abs(err) <= args.dp_tol:
                failures.append("mean pressure jump %.4f: %+.2f%% from sigma / R = %.4f"
                                % (mean_dp, 100 * err, exact))
        for t, dp, _, _, rmin, rmax, _, _ in settled:
            if not abs(dp / exact - 1) <= args.dp_tol_each:
                failures.append("t = %g: pressure jump %.4f, %+.2f%% from sigma / R"
                                % (t, dp, 100 * (dp / exact - 1)))
            for v, what in ((rmin, "smallest"), (rmax, "largest")):
                if not abs(v / Rb - 1) <= args.shape_tol:
                    failures.append("t = %g: the %s outermost radius is %.4f R' (R' = R - dx/2),"
                                    " not within %g" % (t, what, v / Rb, args.shape_tol))

    def draw(plt):
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
        ts = np.array([row[0] for row in rows])
        if fit is None:
            a1.plot(ts, [row[1] for row in rows], "o-", label="SPH: p inside - p outside")
            a1.plot(ts, [row[2] for row in rows], "s--",
                    label="the force's jump (int sigma kappa |n| dr)")
            a1.axhline(exact, color="k", label="sigma / R")
            a1.set_ylabel("pressure jump")
        else:
            w, g, c = fit
            a1.plot(ts, [row[7] for row in rows], ".", label="SPH: D = (Ixx - Iyy) / (Ixx + Iyy)")
            a1.axhline(c, color="0.6", lw=0.8)
            a1.plot(ts, fit_curve(ts, np.array([row[7] for row in rows]), w, g), "-", lw=0.8,
                    label="fit: omega %.3f, gamma %.3f" % (w, g))
            wv, gv = capillary_2d.mode(2, R, args.sigma, args.rho, args.nu, args.box)
            a1.set_title("viscous theory: omega %.3f, gamma %.3f" % (wv, gv))
            a1.set_ylabel("deformation")
        a1.set_xlabel("t")
        a1.legend(fontsize=8)
        ddx, ddy, inside = last
        a2.plot(ddx[~inside], ddy[~inside], ".", ms=2, color="0.7")
        a2.plot(ddx[inside], ddy[inside], ".", ms=2, color="C0")
        th = np.linspace(0, 2 * np.pi, 200)
        a2.plot(R * np.cos(th), R * np.sin(th), "k-", lw=0.8)
        a2.set_aspect("equal")
        a2.set_title("t = %g" % rows[-1][0])
        return fig

    return snapshots.finish(args, draw, failures)

if __name__ == "__main__":
    sys.exit(main())
