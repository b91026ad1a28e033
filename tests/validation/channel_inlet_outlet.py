#!/usr/bin/env python3
"""Check of examples/channel_inlet_outlet.sph: plane Poiseuille flow through a channel with
an inlet and a do-nothing outlet. After the start-up transient the mass flux into the fluid
(through the inlet face x = 0) equals the mass flux out of it (through the outlet face
x = L) within --flux-tol (1%), the fluid's particle count stays within --count-tol (10%) of
its initial count at every snapshot, and the time-averaged velocity profile u(y) over the
fluid matches the prescribed one, 6 U y (H - y) / H^2, within --profile-tol (5% of the
centre-line speed 1.5 U) in every bin of y.

The fluxes come from following particles by their global id (gid) from one snapshot to the
next over every array (fluid, inlet, outlet): a particle on the upstream side of a face at
one snapshot and on the downstream side (or removed past the outlet) at the next crossed
it; its mass counts once per crossing, signed. This measures what the particles did, not
the manager's own counters."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plots  # noqa: E402
from snapshots import argument_parser, particle_arrays, scan_finite, snapshots  # noqa: E402

try:
    import h5py
except ImportError:  # pragma: no cover
    sys.stderr.write("channel_inlet_outlet.py: needs h5py\n")
    sys.exit(2)


def read(path, failures):
    with h5py.File(path, "r") as f:
        t, _, arrays = particle_arrays(f)
        scan_finite(os.path.basename(path), arrays, failures)
        out = {}
        for name, props in arrays.items():
            if "gid" not in props:
                continue
            out[name] = {k: np.asarray(props[k][()]) for k in props}
    return t, out


def main():
    ap = argument_parser(__doc__, "the solver's output directory", "channel_inlet_outlet.png")
    ap.add_argument("--H", type=float, default=1.0)
    ap.add_argument("--L", type=float, default=2.0)
    ap.add_argument("--U", type=float, default=1.0)
    ap.add_argument("--rho0", type=float, default=1.0)
    ap.add_argument("--t-start", type=float, default=1.0,
                    help="end of the start-up transient (default 1.0: half a flow-through)")
    ap.add_argument("--flux-tol", type=float, default=0.01)
    ap.add_argument("--count-tol", type=float, default=0.10)
    ap.add_argument("--profile-tol", type=float, default=0.05)
    args = ap.parse_args()
    files = snapshots(args.outdir, "channel_inlet_outlet.py", at_least=3)
    if files is None:
        return 2
    H, L, U = args.H, args.L, args.U
    umax = 1.5 * U
    failures = []
    snaps = [read(p, failures) for p in files]
    if any("fluid" not in s[1] for s in snaps):
        sys.stderr.write("channel_inlet_outlet.py: a snapshot lacks fluid or its gid\n")
        return 2

    def positions(arrays):
        """gid -> (x, m) over every array."""
        g, x, m = [], [], []
        for a in arrays.values():
            g.append(a["gid"])
            x.append(a["x"])
            m.append(a["m"] if "m" in a else np.zeros(len(a["x"])))
        return np.concatenate(g), np.concatenate(x), np.concatenate(m)

    n0 = len(snaps[0][1]["fluid"]["x"])
    counts = []
    flux_in, flux_out, windows = [], [], []
    for k in range(len(snaps)):
        t, arrays = snaps[k]
        n = len(arrays["fluid"]["x"])
        counts.append((t, n))
        if abs(n - n0) > args.count_tol * n0:
            failures.append("t = %.3f: %d fluid particles, %d at the start (more than %.0f%% off)"
                            % (t, n, n0, 100 * args.count_tol))
        g = arrays["fluid"]["gid"]
        if len(np.unique(g)) != len(g):
            failures.append("t = %.3f: duplicate gids in the fluid" % t)
        if k == 0:
            continue
        t0, a0 = snaps[k - 1]
        g0, x0, m0 = positions(a0)
        g1, x1, _ = positions(arrays)
        where = dict(zip(g1.tolist(), x1.tolist()))
        x1_of = np.array([where.get(int(i), np.inf) for i in g0])  # removed: past the outlet
        inn = np.sum(m0[(x0 < 0) & (x1_of >= 0)]) - np.sum(m0[(x0 >= 0) & (x1_of < 0)])
        out = np.sum(m0[(x0 < L) & (x1_of >= L)]) - np.sum(m0[(x0 >= L) & (x1_of < L)])
        # Particles made between the snapshots already downstream of a face: none expected.
        new = ~np.isin(g1, g0)
        if np.any(new & (x1 >= 0)):
            failures.append("t = %.3f: %d new particles appeared in the fluid"
                            % (t, int(np.count_nonzero(new & (x1 >= 0)))))
        flux_in.append(inn / (t - t0))
        flux_out.append(out / (t - t0))
        windows.append((t0, t))
    flux_in, flux_out = np.array(flux_in), np.array(flux_out)
    late = np.array([w[0] >= args.t_start for w in windows])
    if not np.any(late):
        sys.stderr.write("channel_inlet_outlet.py: no snapshots after t = %g\n" % args.t_start)
        return 2
    dts = np.array([w[1] - w[0] for w in windows])
    q_in = float(np.sum(flux_in[late] * dts[late]) / np.sum(dts[late]))
    q_out = float(np.sum(flux_out[late] * dts[late]) / np.sum(dts[late]))
    q_ref = args.rho0 * U * H
    rel = abs(q_in - q_out) / q_in if q_in else np.inf
    print("channel: %d snapshots, t = %.3g to %.3g; %d fluid particles at the start"
          % (len(snaps), snaps[0][0], snaps[-1][0], n0))
    print("mass flux after t = %.3g: in %.6f, out %.6f, prescribed rho U H = %.6f; "
          "in/out differ by %.3f%% (tolerance %.1f%%)"
          % (args.t_start, q_in, q_out, q_ref, 100 * rel, 100 * args.flux_tol))
    if not rel <= args.flux_tol:
        failures.append("mass flux in %.6f and out %.6f differ by %.3f%%, more than %.1f%%"
                        % (q_in, q_out, 100 * rel, 100 * args.flux_tol))
    ns = np.array([c[1] for c in counts])
    print("fluid particles: %d to %d over every snapshot (start %d)" % (ns.min(), ns.max(), n0))

    # The velocity profile: fluid particles of the late snapshots, binned in y.
    ny = max(4, int(round(np.sqrt(n0 * H / L))))
    ys, us = [], []
    for t, arrays in snaps:
        if t < args.t_start:
            continue
        fl = arrays["fluid"]
        ys.append(fl["y"])
        us.append(fl["u"])
    y = np.concatenate(ys)
    u = np.concatenate(us)
    k = np.clip((y / H * ny).astype(int), 0, ny - 1)
    cnt = np.bincount(k, minlength=ny)
    ok = cnt > 0
    yb = np.bincount(k, weights=y, minlength=ny)[ok] / cnt[ok]
    ub = np.bincount(k, weights=u, minlength=ny)[ok] / cnt[ok]
    ue = 6.0 * U * yb * (H - yb) / (H * H)
    err = np.abs(ub - ue) / umax
    print("   y/H     u_SPH   u_prescribed  |error|/u_max")
    for a, b, c, e in zip(yb, ub, ue, err):
        print("  %.4f  %.5f  %.5f  %.4f" % (a / H, b, c, e))
    print("velocity profile: largest error %.3f%% of u_max (tolerance %.1f%%)"
          % (100 * err.max(), 100 * args.profile_tol))
    if not err.max() <= args.profile_tol:
        failures.append("velocity profile off by %.3f%% of u_max, more than %.1f%%"
                        % (100 * err.max(), 100 * args.profile_tol))

    def draw(plt):
        fig, ax = plt.subplots(1, 3, figsize=(13, 3.8))
        tw = [w[1] for w in windows]
        ax[0].plot(tw, flux_in, label="in (x = 0)")
        ax[0].plot(tw, flux_out, label="out (x = L)")
        ax[0].axhline(q_ref, color="k", lw=0.8, ls="--", label="rho U H")
        ax[0].axvline(args.t_start, color="grey", lw=0.8)
        ax[0].set_xlabel("t")
        ax[0].set_ylabel("mass flux")
        ax[0].legend()
        ax[1].plot([c[0] for c in counts], ns)
        ax[1].set_xlabel("t")
        ax[1].set_ylabel("fluid particles")
        yy = np.linspace(0, H, 100)
        ax[2].plot(6 * U * yy * (H - yy) / H ** 2, yy, "k-", label="prescribed")
        ax[2].plot(ub, yb, "o", label="SPH (mean, t >= %.3g)" % args.t_start)
        ax[2].set_xlabel("u")
        ax[2].set_ylabel("y")
        ax[2].legend()
        return fig

    plots.write(args, draw, failures)
    if failures:
        for f in failures[:20]:
            print("FAIL: " + f)
        return 1
    print("OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
