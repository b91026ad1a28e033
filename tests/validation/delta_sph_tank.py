#!/usr/bin/env python3
"""delta-SPH in the hydrostatic tank: pressure noise with and without the diffusive term.

Two runs of examples/hydrostatic_tank.sph (water of depth H at rest in a tank with the
Adami et al. 2012 walls, gravity ramped up over 0.25 s, run to t = 1 s), both with the
artificial viscosity alpha = 0.1 (the value of the dam break, too weak to damp the start-up
waves by t = 1 s: the case where the pressure field is noisy), one without (delta = 0) and one
with the delta-SPH density diffusion of Marrone et al., Comput. Methods Appl. Mech. Engrg. 200
(2011) 1526-1542 (delta = 0.1, stdlib/delta_sph.sph).

Figures, from the last snapshot, over all fluid particles, in units of rho0 g H:

  - error:  rms of p - rho0 g (H - y) (the exact hydrostatic pressure);
  - noise:  rms of the residual of p about its least-squares fit a + b y. The exact field is
            linear in y; the fit absorbs what is smooth and systematic (the 2.7% excess slope
            from the Wendland kernel's sum at h = 1.3 dx, and the weak-compressibility offset,
            see hydrostatic_tank.py), so what remains is particle-scale and acoustic noise,
            which is what density diffusion is meant to remove.

Checks: noise(with) <= --ratio (0.5) x noise(without): Marrone et al. show the diffusive term
removing the high-frequency pressure oscillations of WCSPH, so it must at least halve the
noise (sphc measures a factor ~5); and error(with) < error(without). A term with the wrong
sign or scale (or switched off) fails: it leaves the noise or makes it grow. Both runs must
also be finite and keep their particles in the tank.

It draws the pressure of both runs against rho0 g (H - y) into delta_sph_tank.png in the
directory that holds both (--plot PATH: elsewhere; tests/validation/plots.py).

Usage: delta_sph_tank.py DIR_WITHOUT DIR_WITH [--H 0.5] [--g 9.81] [--rho0 1000]
                         [--ratio 0.5] [--plot out.png]
"""

import os
import sys

try:
    import h5py
    import numpy as np
except ImportError as exc:  # pragma: no cover
    sys.stderr.write("delta_sph_tank.py needs numpy and h5py (%s)\n" % exc)
    sys.exit(2)

import plots  # noqa: E402  (tests/validation/plots.py)
from snapshots import argument_parser, report_failures, snapshots  # noqa: E402


def figures(path, H, g, rho0):
    with h5py.File(path, "r") as f:
        t = float(f.attrs["t"])
        fl = f["fluid"]
        x, y, p = (np.asarray(fl[k][()], dtype=float) for k in ("x", "y", "p"))
    pref = rho0 * g * H
    err = (p - rho0 * g * (H - y)) / pref
    A = np.vstack([np.ones_like(y), y]).T
    coef, *_ = np.linalg.lstsq(A, p, rcond=None)
    res = (p - A @ coef) / pref
    ok = bool(np.all(np.isfinite(p)) and np.all(y >= 0))
    return dict(t=t, x=x, y=y, p=p, err_rms=float(np.sqrt(np.mean(err ** 2))),
                err_max=float(np.abs(err).max()), noise_rms=float(np.sqrt(np.mean(res ** 2))),
                noise_max=float(np.abs(res).max()), ok=ok, n=len(p))


def main():
    ap = argument_parser(__doc__, "directory of the run without delta-SPH", "delta_sph_tank.png")
    ap.add_argument("with_", metavar="with", help="directory of the run with delta-SPH")
    ap.add_argument("--H", type=float, default=0.5)
    ap.add_argument("--g", type=float, default=9.81)
    ap.add_argument("--rho0", type=float, default=1000.0)
    ap.add_argument("--ratio", type=float, default=0.5)
    args = ap.parse_args()
    runs = []
    for d in (args.outdir, args.with_):
        files = snapshots(d, "delta_sph_tank.py", at_least=1)
        if files is None:
            return 2
        runs.append(figures(files[-1], args.H, args.g, args.rho0))
    a, b = runs
    print("hydrostatic tank, alpha = 0.1, t = %.3f, %d fluid particles; units of rho0 g H"
          % (a["t"], a["n"]))
    print("%-22s %10s %10s %10s %10s" % ("run", "error rms", "error max", "noise rms",
                                          "noise max"))
    for name, r in (("without delta-SPH", a), ("delta-SPH, delta 0.1", b)):
        print("%-22s %9.3f%% %9.3f%% %9.3f%% %9.3f%%" % (name, 100 * r["err_rms"],
                                                         100 * r["err_max"],
                                                         100 * r["noise_rms"],
                                                         100 * r["noise_max"]))
    failures = []
    for name, r in (("without", a), ("with", b)):
        if not r["ok"]:
            failures.append("run %s: non-finite pressure or particles below the floor" % name)
    if abs(a["t"] - b["t"]) > 1e-9:
        failures.append("the runs end at different times (%g, %g)" % (a["t"], b["t"]))
    if not b["noise_rms"] <= args.ratio * a["noise_rms"]:
        failures.append("noise with delta-SPH %.3f%% > %.2f x %.3f%% without"
                        % (100 * b["noise_rms"], args.ratio, 100 * a["noise_rms"]))
    if not b["err_rms"] < a["err_rms"]:
        failures.append("error with delta-SPH %.3f%% not below %.3f%% without"
                        % (100 * b["err_rms"], 100 * a["err_rms"]))
    def draw(plt):
        fig, axes = plt.subplots(1, 2, figsize=(10, 4.5), sharey=True)
        pref = args.rho0 * args.g * args.H
        for ax, r, title in zip(axes, runs, ("without delta-SPH", "delta-SPH, delta = 0.1")):
            ax.plot(r["p"] / pref, r["y"] / args.H, ".", ms=2, label="sphc, t = %.3g s" % r["t"])
            ys = np.linspace(0, 1, 20)
            ax.plot(1 - ys, ys, "k-", lw=1, label=r"$\rho_0 g (H - y)$")
            ax.set_title("%s: noise rms %.2f%%, error rms %.2f%% of $\\rho_0 g H$"
                         % (title, 100 * r["noise_rms"], 100 * r["err_rms"]), fontsize=9)
            ax.set_xlabel(r"$p / (\rho_0 g H)$")
            ax.legend(fontsize=8)
        axes[0].set_ylabel(r"$y / H$")
        return fig

    # Both runs are in subdirectories of the test's output directory: the plot goes there.
    plots.write(args, draw, failures,
                directory=os.path.commonpath([os.path.abspath(args.outdir),
                                              os.path.abspath(args.with_)]), dpi=120)
    if report_failures(failures):
        return 1
    print("PASSED: delta-SPH cuts the pressure noise from %.3f%% to %.3f%% of rho0 g H (a factor "
          "%.1f; required >= %.1f) and the rms error from %.3f%% to %.3f%%"
          % (100 * a["noise_rms"], 100 * b["noise_rms"], a["noise_rms"] / b["noise_rms"],
             1 / args.ratio, 100 * a["err_rms"], 100 * b["err_rms"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
