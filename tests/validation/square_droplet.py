#!/usr/bin/env python3
"""Check the square droplet (examples/square_droplet.sph: surface tension, the continuum
surface force of Morris 2000) against the Young-Laplace pressure jump dp = sigma / R.

Every snapshot: the run finite, the mass exact (to round-off), the colours unchanged. At the
end of the run, the mean over the snapshots with t >= --t-settled of the pressure jump
dp = mean p (r < R - 3h) - mean p (r > R + 3h), r from the drop's centroid, within --dp-tol of
sigma / R, R = side / sqrt(pi) (the circle of the square's area), and each of those snapshots
within --dp-tol-each; the drop a circle: the radius of its outermost particle in each of 32
sectors within --shape-tol of R - dx/2 (where the outermost particle centres of a circle
of radius R lie) in the last snapshot, while the square starts 15% inside and 19% outside.

With --static (a run of --set circle=1 --tf 0: the colours of a circle on the lattice, no
motion), the force the interface exerts instead: the integral across the interface of the
colour gradient's radial part, int |n| dr, within --static-tol of 1, and of sigma kappa |n|
(the pressure jump the force balances) within --static-tol of sigma / R, with both estimated
from the particles as sum_a V_a (F_a . -r^_a) / (2 pi r_a)."""
import sys

import h5py
import numpy as np

import plots
import snapshots

WHO = "square_droplet.py"


def main():
    ap = snapshots.argument_parser(__doc__, "the scene's output directory", "square_droplet.png")
    ap.add_argument("--side", type=float, default=0.5, help="side of the initial square")
    ap.add_argument("--box", type=float, default=1.0, help="side of the periodic box")
    ap.add_argument("--sigma", type=float, default=1.0, help="surface tension")
    ap.add_argument("--nx", type=int, default=40, help="particles along the box (h = dx)")
    ap.add_argument("--t-settled", type=float, default=1.5,
                    help="the jump is averaged over the snapshots from this time on")
    ap.add_argument("--dp-tol", type=float, default=0.10,
                    help="relative tolerance of the mean pressure jump")
    ap.add_argument("--dp-tol-each", type=float, default=0.15,
                    help="relative tolerance of the jump at each settled snapshot")
    ap.add_argument("--shape-tol", type=float, default=0.03,
                    help="relative tolerance of the outermost radius per sector")
    ap.add_argument("--static", action="store_true",
                    help="check the interface force of a circle at t = 0 instead")
    ap.add_argument("--static-tol", type=float, default=0.02)
    args = ap.parse_args()

    files = snapshots.snapshots(args.outdir, WHO, at_least=1 if args.static else 2)
    if files is None:
        return 2
    R = args.side / np.sqrt(np.pi)
    dx = args.box / args.nx
    h = dx
    exact = args.sigma / R
    failures = []
    rows = []
    mass0 = None
    color0 = None
    last = None
    for name in files:
        with h5py.File(name, "r") as f:
            keys = ["x", "y", "p", "m", "rho", "color", "kappa", "cgrad"]
            got = snapshots.read_fluid(f, name, keys, WHO, failures)
            if got is None:
                return 2
            t, (x, y, p, m, rho, color, kappa, cgrad) = got
        mass = m.sum()
        if mass0 is None:
            mass0, color0 = mass, color.copy()
        if abs(mass - mass0) > 1e-12 * mass0:
            failures.append("t = %g: mass %.15g, at the start %.15g" % (t, mass, mass0))
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
        pin = p[r < R - 3 * h]
        pout = p[r > R + 3 * h]
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
        rows.append((t, dp, fint, nint, rb.min(), rb.max()))
        last = (ddx, ddy, inside)

    print("sigma / R = %.4f (R = %.4f), h = %.4f" % (exact, R, h))
    print("%6s %10s %8s %14s %10s %10s %10s" % ("t", "dp", "dp err", "force int err",
                                                 "int|n|dr", "rmin/R'", "rmax/R'"))
    Rb = R - 0.5 * dx
    for t, dp, fint, nint, rmin, rmax in rows:
        print("%6.2f %10.4f %+7.2f%% %+13.2f%% %10.4f %10.4f %10.4f"
              % (t, dp, 100 * (dp / exact - 1), 100 * (fint / exact - 1), nint, rmin / Rb,
                 rmax / Rb))

    if args.static:
        t, dp, fint, nint, _, _ = rows[0]
        if abs(nint - 1) > args.static_tol:
            failures.append("int |n| dr = %.4f, not within %g of 1" % (nint, args.static_tol))
        if abs(fint / exact - 1) > args.static_tol:
            failures.append("the force balances a jump %.4f, not within %g of sigma / R = %.4f"
                            % (fint, args.static_tol, exact))
        print("static: int |n| dr = %.4f, force integral %.4f = (1 %+.2f%%) sigma / R"
              % (nint, fint, 100 * (fint / exact - 1)))
    else:
        settled = [(t, dp) for t, dp, *_ in rows if t >= args.t_settled - 1e-9]
        if len(settled) < 2:
            failures.append("fewer than 2 snapshots from t = %g on" % args.t_settled)
        else:
            mean_dp = float(np.mean([dp for _, dp in settled]))
            err = mean_dp / exact - 1
            print("mean jump over t >= %g (%d snapshots): %.4f, error %+.2f%% (tolerance %g%%)"
                  % (args.t_settled, len(settled), mean_dp, 100 * err, 100 * args.dp_tol))
            if not abs(err) <= args.dp_tol:
                failures.append("mean pressure jump %.4f: %+.2f%% from sigma / R = %.4f"
                                % (mean_dp, 100 * err, exact))
            for t, dp in settled:
                if not abs(dp / exact - 1) <= args.dp_tol_each:
                    failures.append("t = %g: pressure jump %.4f, %+.2f%% from sigma / R"
                                    % (t, dp, 100 * (dp / exact - 1)))
        t, _, _, _, rmin, rmax = rows[-1]
        for v, what in ((rmin, "smallest"), (rmax, "largest")):
            if not abs(v / Rb - 1) <= args.shape_tol:
                failures.append("t = %g: the %s outermost radius is %.4f R' (R' = R - dx/2), "
                                "not within %g" % (t, what, v / Rb, args.shape_tol))

    def draw(plt):
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
        ts = [r[0] for r in rows]
        a1.plot(ts, [r[1] for r in rows], "o-", label="SPH: p inside - p outside")
        a1.plot(ts, [r[2] for r in rows], "s--", label="the force's jump (int sigma kappa |n| dr)")
        a1.axhline(exact, color="k", label="sigma / R")
        a1.set_xlabel("t")
        a1.set_ylabel("pressure jump")
        a1.legend(fontsize=8)
        ddx, ddy, inside = last
        a2.plot(ddx[~inside], ddy[~inside], ".", ms=2, color="0.7")
        a2.plot(ddx[inside], ddy[inside], ".", ms=2, color="C0")
        th = np.linspace(0, 2 * np.pi, 200)
        a2.plot(R * np.cos(th), R * np.sin(th), "k-", lw=0.8)
        a2.set_aspect("equal")
        a2.set_title("t = %g" % rows[-1][0])
        return fig

    plots.write(args, draw, failures)
    if snapshots.report_failures(failures, limit=20):
        return 1
    print("OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
