#!/usr/bin/env python3
"""Check two blocks in thermal contact (examples/heat_conduction.sph: the heat conduction of
Cleary & Monaghan 1999) against the exact solution of two half-spaces in contact.

The left block (x < 0) starts at T1 with the conductivity k1, the right one at T2 with k2,
rho c_p = 1 on both sides (the scene's defaults, or the options below). The exact solution
(Carslaw & Jaeger 1959, section 2.15), a = k / (rho c_p), e = sqrt(k rho c_p):

    T = Ti + (T1 - Ti) erf(-x / (2 sqrt(a1 t)))   (x < 0),
    T = Ti + (T2 - Ti) erf( x / (2 sqrt(a2 t)))   (x > 0),    Ti = (e1 T1 + e2 T2) / (e1 + e2).

Every snapshot after t = 0: the largest error over the particles, |T - T_exact|, within --tol
(relative to |T1 - T2|), at the last snapshot within --tol-final; the heat sum m c_p T
conserved within --heat-tol (relative); no non-finite values."""
import math
import sys

import numpy as np

import snapshots

WHO = "heat_conduction.py"


def exact(x, t, a):
    T1, T2, k1, k2, rc = a.T1, a.T2, a.k1, a.k2, a.rhocp
    a1, a2 = k1 / rc, k2 / rc
    e1, e2 = math.sqrt(k1 * rc), math.sqrt(k2 * rc)
    Ti = (e1 * T1 + e2 * T2) / (e1 + e2)
    erf = np.vectorize(math.erf)
    left = Ti + (T1 - Ti) * erf(-x / (2 * math.sqrt(a1 * t)))
    right = Ti + (T2 - Ti) * erf(x / (2 * math.sqrt(a2 * t)))
    return np.where(x < 0, left, right)


def main():
    ap = snapshots.argument_parser(__doc__, "the scene's output directory", "heat_conduction.png")
    ap.add_argument("--T1", type=float, default=1.0)
    ap.add_argument("--T2", type=float, default=0.0)
    ap.add_argument("--k1", type=float, default=0.01)
    ap.add_argument("--k2", type=float, default=0.04)
    ap.add_argument("--rhocp", type=float, default=1.0, help="rho c_p (both blocks)")
    ap.add_argument("--tol", type=float, default=0.01,
                    help="largest error at any snapshot, relative to |T1 - T2|")
    ap.add_argument("--tol-final", type=float, default=0.002,
                    help="largest error at the last snapshot, relative to |T1 - T2|")
    ap.add_argument("--heat-tol", type=float, default=1e-12)
    args = ap.parse_args()

    got = snapshots.read_series(args.outdir, ["x", "T", "m"], WHO)
    if got is None:
        return 2
    series, failures = got
    scale = abs(args.T1 - args.T2)
    heat0 = None
    rows = []
    last = None
    for _, t, (x, T, m) in series:
        heat = float((m * T).sum())
        if heat0 is None:
            heat0 = heat
        snapshots.check_conserved("heat", t, heat, heat0, args.heat_tol, failures)
        if t <= 0:
            continue
        err = np.abs(T - exact(x, t, args)) / scale
        i = int(np.argmax(err))
        rows.append((t, float(err.max()), float(x[i]), float(err.mean()), heat / heat0 - 1))
        if not err.max() <= args.tol:
            failures.append("t = %g: largest error %.4g at x = %.4g (tolerance %g)"
                            % (t, err.max(), x[i], args.tol))
        last = (t, x, T)
    if not rows:
        failures.append("no snapshot after t = 0")
    else:
        print("%8s %12s %10s %12s %12s" % ("t", "max error", "at x", "mean error", "heat drift"))
        for t, emax, xm, emean, dh in rows:
            print("%8.3f %12.3e %10.4f %12.3e %12.2e" % (t, emax, xm, emean, dh))
        if not rows[-1][1] <= args.tol_final:
            failures.append("last snapshot (t = %g): largest error %.4g, tolerance %g"
                            % (rows[-1][0], rows[-1][1], args.tol_final))

    def draw(plt):
        fig, ax = plt.subplots(figsize=(7, 4))
        t, x, T = last
        o = np.argsort(x)
        xs = np.linspace(x.min(), x.max(), 400)
        ax.plot(x[o], T[o], ".", ms=3, label="SPH, t = %g" % t)
        ax.plot(xs, exact(xs, t, args), "k-", lw=1, label="exact (erf)")
        ax.set_xlabel("x")
        ax.set_ylabel("T")
        ax.legend()
        return fig

    return snapshots.finish(args, draw if last is not None else None, failures)


if __name__ == "__main__":
    sys.exit(main())
