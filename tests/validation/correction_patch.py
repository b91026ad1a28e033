#!/usr/bin/env python3
"""Checks the static correction tests (examples/correction_patch.sph) against exact results.

A square patch [0, 1]^2 of particles with a free surface all around, on a square lattice
(snapshot t = 0) and on a randomly perturbed one (t = 1, displacements up to +-0.15 h).

Exact results, checked in both snapshots:

  - gradient correction and mixed kernel and gradient correction (Bonet & Lok, Comput.
    Methods Appl. Mech. Engrg. 180 (1999) 97-115): for the linear density
    rho = ro (1 + gx x + gy y) the corrected SPH gradient equals (ro gx, ro gy) at every
    particle, the free surface included. Both are exact by construction for linear fields,
    so the only error is round-off: the sums have ~30 terms of size rho / h, i.e. ~1e2 times
    the gradient, so the relative error should be ~1e-14; the tolerance --exact-tol (1e-10,
    relative to |grad rho|) leaves four orders of magnitude and still catches any
    inconsistency in the matrix (a wrong sign or transposition gives O(1) errors).
  - delta-SPH diffusive term (Marrone et al., Comput. Methods Appl. Mech. Engrg. 200 (2011)
    1526-1542): delta h c0 sum_b psi_ba . grad W_ab V_b, with the renormalised density
    gradients in psi, is zero for a linear density at every particle, free surface
    included; error |arho| in units of delta c0 |grad rho| (the size of one of its terms),
    tolerance --exact-tol. The Molteni & Colagrossi (2009) term, without the gradients,
    must not vanish at the free surface (> --fail-min in the same units; Antuono et al. 2012).
  - Shepard filter (Shepard 1968; Colagrossi & Landrini, J. Comput. Phys. 191 (2003)
    448-475): sum_b m_b W_ab / sum_b V_b W_ab reproduces a uniform density ro at every
    particle; tolerance --exact-tol relative to ro.

And the uncorrected forms must visibly fail (so the test would notice the corrections being
lost): the plain SPH gradient is off by more than --fail-min (1%) somewhere (O(1) at the free
surface, where half the kernel support is empty; 2.6% inside on the square lattice, the
Wendland quintic's sum_b V_b x_ab dW/dx at h = 1.3 dx being 0.974 instead of 1); the plain
summation density sum_b m_b W_ab is off by more than 10% at the free surface.

Prints a table of max relative errors (all particles; interior = farther than 2.15 h from the
edge) and exits 0 when every check passes, 1 when one fails, 2 on bad input. It draws the
error of the plain and the corrected gradient over the perturbed patch into
OUTPUT_DIR/correction_patch.png (--plot PATH: elsewhere; tests/validation/plots.py).

Usage: correction_patch.py OUTPUT_DIR [--dx 0.05] [--hdx 1.3] [--ro 1000] [--gx 0.1]
                           [--gy 0.2] [--exact-tol 1e-10] [--fail-min 0.01] [--plot out.png]
"""

import sys

try:
    import h5py
    import numpy as np
except ImportError as exc:  # pragma: no cover - environment problem, not a test failure
    sys.stderr.write("correction_patch.py needs numpy and h5py (%s)\n" % exc)
    sys.exit(2)

import plots  # noqa: E402  (tests/validation/plots.py)
from snapshots import argument_parser, report_failures, snapshots  # noqa: E402


def main():
    ap = argument_parser(__doc__, "directory with the patch's two HDF5 snapshots",
                         "correction_patch.png")
    ap.add_argument("--dx", type=float, default=0.05)
    ap.add_argument("--hdx", type=float, default=1.3)
    ap.add_argument("--ro", type=float, default=1000.0)
    ap.add_argument("--gx", type=float, default=0.1)
    ap.add_argument("--gy", type=float, default=0.2)
    ap.add_argument("--co", type=float, default=10.0)
    ap.add_argument("--delta", type=float, default=0.1)
    ap.add_argument("--exact-tol", type=float, default=1e-10)
    ap.add_argument("--fail-min", type=float, default=0.01)
    args = ap.parse_args()

    files = snapshots(args.outdir, "correction_patch.py")
    if files is None:
        return 2
    if len(files) != 2:
        sys.stderr.write("correction_patch.py: expected 2 snapshots in %s, found %d\n"
                         % (args.outdir, len(files)))
        return 2
    h = args.hdx * args.dx
    G = args.ro * np.array([args.gx, args.gy])
    failures = []
    rows = []
    plotdata = {}
    for path, label in zip(files, ["square lattice", "perturbed lattice"]):
        with h5py.File(path, "r") as f:
            for name in ("raw", "corr", "mixed"):
                g = f[name]
                x, y = g["x"][()], g["y"][()]
                grad = g["gradrho"][()][:, :2]
                if not np.all(np.isfinite(grad)):
                    failures.append("%s, %s: non-finite gradients" % (label, name))
                    continue
                err = np.linalg.norm(grad - G, axis=1) / np.linalg.norm(G)
                edge = np.minimum(np.minimum(x, 1 - x), np.minimum(y, 1 - y))
                inner = edge > 2.15 * h
                rows.append((label, name, float(err.max()), float(err[inner].max())))
                plotdata[(label, name)] = (x, y, err)
                if name == "raw":
                    if not err.max() > args.fail_min:
                        failures.append("%s: the plain gradient is exact (max error %.3g): the "
                                        "test cannot tell corrections apart" % (label, err.max()))
                elif not err.max() <= args.exact_tol:
                    failures.append("%s, %s: corrected gradient error %.3g > %.3g"
                                    % (label, name, err.max(), args.exact_tol))
            scale = args.delta * args.co * np.linalg.norm(G)
            for name in ("dsph", "mc"):
                g = f[name]
                x, y = g["x"][()], g["y"][()]
                edge = np.minimum(np.minimum(x, 1 - x), np.minimum(y, 1 - y))
                inner = edge > 2.15 * h
                e = np.abs(g["arho"][()]) / scale
                rows.append((label, name, float(e.max()), float(e[inner].max())))
                if name == "dsph" and not e.max() <= args.exact_tol:
                    failures.append("%s: delta-SPH term %.3g for a linear density > %.3g"
                                    % (label, e.max(), args.exact_tol))
                if name == "mc" and not e.max() > args.fail_min:
                    failures.append("%s: Molteni-Colagrossi term vanishes too (%.3g): the test "
                                    "cannot tell the forms apart" % (label, e.max()))
            s = f["shep"]
            x, y = s["x"][()], s["y"][()]
            edge = np.minimum(np.minimum(x, 1 - x), np.minimum(y, 1 - y))
            inner = edge > 2.15 * h
            ef = np.abs(s["rhof"][()] / args.ro - 1)
            es = np.abs(s["rhosum"][()] / args.ro - 1)
            rows.append((label, "shepard", float(ef.max()), float(ef[inner].max())))
            rows.append((label, "summation", float(es.max()), float(es[inner].max())))
            if not ef.max() <= args.exact_tol:
                failures.append("%s: Shepard-filtered uniform density off by %.3g > %.3g"
                                % (label, ef.max(), args.exact_tol))
            if not es.max() > 0.1:
                failures.append("%s: the plain summation density is within 10%% at the free "
                                "surface (%.3g): wrong set-up" % (label, es.max()))

    print("correction patch: %s, dx = %g, h = %g, grad rho = (%g, %g)"
          % (args.outdir, args.dx, h, G[0], G[1]))
    print("%-18s %-10s %14s %14s" % ("lattice", "form", "max rel. err", "interior"))
    for label, name, e_all, e_in in rows:
        print("%-18s %-10s %14.3e %14.3e" % (label, name, e_all, e_in))
    print("(raw: plain SPH gradient; corr: Bonet-Lok gradient correction; mixed: mixed kernel "
          "and gradient correction;\n dsph: delta-SPH term / (delta c0 |grad rho|);\n"
          " mc: Molteni-Colagrossi term, same units; shepard: Shepard filter of a uniform density; summation: "
          "sum_b m_b W_ab of it)")

    def draw(plt):
        fig, axes = plt.subplots(1, 2, figsize=(10, 4.5))
        for ax, name in zip(axes, ("raw", "corr")):
            if ("perturbed lattice", name) not in plotdata:  # non-finite: in the failures
                continue
            x, y, err = plotdata[("perturbed lattice", name)]
            sc = ax.scatter(x, y, c=np.log10(np.maximum(err, 1e-17)), s=12, cmap="viridis")
            ax.set_aspect("equal")
            ax.set_xlabel("x")
            ax.set_ylabel("y")
            ax.set_title("%s gradient: max error %.2g"
                         % ("plain SPH" if name == "raw" else "Bonet-Lok corrected",
                            float(err.max())), fontsize=9)
            fig.colorbar(sc, ax=ax, label=r"$\log_{10}$ (|grad rho - exact| / |grad rho|)")
        fig.suptitle("correction patch, perturbed lattice, dx = %g, h = %g: "
                     "rho = ro (1 + %g x + %g y)" % (args.dx, h, args.gx, args.gy), fontsize=10)
        return fig

    plots.write(args, draw, failures, dpi=120)

    if report_failures(failures):
        return 1
    print("PASSED: corrected gradients and the Shepard filter exact to %.1e (tolerance %.0e); "
          "the uncorrected forms off by up to %.0f%% (gradient) and %.0f%% (density)"
          % (max(r[2] for r in rows if r[1] in ("corr", "mixed", "dsph", "shepard")), args.exact_tol,
             100 * max(r[2] for r in rows if r[1] == "raw"),
             100 * max(r[2] for r in rows if r[1] == "summation")))
    return 0


if __name__ == "__main__":
    sys.exit(main())
