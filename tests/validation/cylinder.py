#!/usr/bin/env python3
"""Check of examples/cylinder.sph: flow past a cylinder in a channel (the 2D benchmark of
Schaefer & Turek 1996, "DFG benchmark"), with an inlet and an outlet. Reads the run's metrics
(cylinder_metrics.csv: cd, cl, their time integrals cd_int, cl_int, and nfluid) at every
output.

Steady case (Re = 20, [ST96] case 2D-1, the default): the mean drag and lift coefficients over
[--t-start, end], from the time integrals (exact means of every step's force, not of the
sampled snapshots), must lie within --cd-tol (relative) of Cd = 5.58 and within --cl-tol
(absolute) of Cl = 0.0106 ([ST96] table 4: Cd 5.57-5.59, Cl 0.0104-0.0110; the blockage of
the channel, D/H = 0.24, is part of the benchmark). The mean over the second half of that
window must differ from the mean over the first half by less than --drift-tol (relative):
the flow has settled. At every output the fluid's particle count stays within --count-tol of
its start (the inlet feeds what the outlet removes) and every metric is finite. With
--flux-tol (needs the snapshots with gids): the mass that entered the fluid from the inlet
and the mass that left it into the outlet after --t-start, from following each particle's
gid from one snapshot to the next, agree within --flux-tol (relative); the mean inflow is
also printed against rho Ubar H. With --count-end-tol: the count at the end is within that
of the count at --t-start (no slow drift that the wide --count-tol would hide). With
--symmetry-tol (steady case): the mean streamwise velocity of the fluid in the box x = cx +
D/2 to cx + 5D/2, y = cy to cy + D (above the wake's axis: the recirculation region and its
shear layer), averaged over the snapshots after --t-start, over the same in the mirror box
below the axis is within --symmetry-tol of 1: the steady 2D-1 wake is symmetric but for the
cylinder's offset of 0.005 below the channel's centre line ([ST96]'s lift is 0.2% of the
drag). The range of the ratio snapshot by snapshot is printed (the particles' noise).

Shedding case (--shedding: Re = 100, [ST96] case 2D-2): the Strouhal number St = f D / Ubar,
f the peak of the spectrum of the lift after --t-start (averaged over --smooth), within
--st-tol (relative) of 0.300 ([ST96]: 0.295-0.305), at least 3 periods; the mean drag and
the lift amplitude are printed against [ST96]'s Cd_max 3.22-3.24 and Cl_max 0.99-1.01 (not
checked: at D/10 the drag is ~20% high, as the steady case's is 10-13%).

Re = 200 past a nearly unbounded cylinder (--reference re200, implies --shedding: the scene
with --set slip=1, a uniform inflow between free-slip walls far from the cylinder): St within
--st-tol and the mean drag within --cd-tol (relative) of the mean of five published
two-dimensional computations, St = 0.197 and Cd = 1.302 (RE200 below: St 0.192-0.202, mean Cd
1.17-1.40, Cl amplitude 0.50-0.75): Braza, Chassaing & Ha Minh (1986, J. Fluid Mech. 165,
79-130), Liu, Zheng & Sung (1998, J. Comput. Phys. 139, 35-57), Calhoun (2002, J. Comput.
Phys. 176, 231-275), Russell & Wang (2003, J. Comput. Phys. 191, 177-205), Linnick & Fasel
(2005, J. Comput. Phys. 204, 157-192). Each is printed beside the result.

With --min-amplitude (shedding cases): the lift's amplitude (the standard deviation of the
averaged lift after --t-start times sqrt 2) must exceed it: vortices are shed.

Periodicity (--periodic-tol, shedding cases): the lift (averaged over --smooth) after
--t-start is cut into cycles at its upward zero crossings; there must be at least
--min-periods whole cycles, and the cycles' periods and amplitudes (half of max - min) must
each scatter by at most --periodic-tol (standard deviation over mean), the mean lift over the
whole cycles must be within --periodic-tol of 0 relative to the amplitude, and the mean drag
of the first half of the cycles within --periodic-tol of that of the second half: a periodic
state, not a drifting one. With --flux-tol the mass flux into the fluid over the first and the
second half of the window must also agree within --flux-tol (no drift of the mean flow
rate)."""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plots  # noqa: E402
from metrics_csv import read_metrics  # noqa: E402
from snapshots import argument_parser, snapshot_files  # noqa: E402

CD_ST96, CL_ST96 = 5.58, 0.0106          # 2D-1, Re = 20
ST_ST96, CDMAX_ST96, CLMAX_ST96 = 0.300, 3.23, 1.00   # 2D-2, Re = 100
# Re = 200, unbounded, 2D computations: (St, mean Cd, Cl amplitude). The check is against
# their mean (St 0.197, Cd 1.302; they spread by -2.6% to +2.5% and -10% to +7.5% about it).
RE200 = (("Braza, Chassaing & Ha Minh 1986", 0.20, 1.40, 0.75),
         ("Liu, Zheng & Sung 1998", 0.192, 1.31, 0.69),
         ("Calhoun 2002", 0.202, 1.172, 0.668),
         ("Russell & Wang 2003", 0.195, 1.29, 0.50),
         ("Linnick & Fasel 2005", 0.197, 1.34, 0.69))
ST_RE200 = sum(r[1] for r in RE200) / len(RE200)
CD_RE200 = sum(r[2] for r in RE200) / len(RE200)


def mean_between(t, integral, a, b):
    """(I(b) - I(a)) / (b - a) with the outputs nearest a and b."""
    i = min(range(len(t)), key=lambda k: abs(t[k] - a))
    j = min(range(len(t)), key=lambda k: abs(t[k] - b))
    if t[j] <= t[i]:
        return float("nan")
    return (integral[j] - integral[i]) / (t[j] - t[i])


def crossing_flux(outdir, t_start, t_end=float("inf")):
    """(mean mass flux into the fluid, out of it, time span) after t_start, from the gids of
    consecutive snapshots: a gid in the inlet then in the fluid came in; a gid in the fluid
    then not (in the outlet or removed) went out, one in the outlet then back in the fluid
    counts against that. None without snapshots or gids."""
    try:
        import h5py
        import numpy as np
    except ImportError:
        return None
    files = snapshot_files(outdir)
    prev = None
    m_in = m_out = 0.0
    t0 = None
    t_last = None
    for path in files:
        with h5py.File(path, "r") as f:
            t = float(f.attrs["t"])
            if "fluid" not in f or "gid" not in f["fluid"]:
                return None
            cur = {a: (np.asarray(f[a]["gid"][()]), np.asarray(f[a]["m"][()]))
                   for a in ("fluid", "inlet", "outlet") if a in f and "gid" in f[a]}
        if t > t_end + 1e-9:
            break
        if prev is not None and prev[0] >= t_start - 1e-9:
            if t0 is None:
                t0 = prev[0]
            pf_g, pf_m = prev[1]["fluid"]
            cf_g = cur["fluid"][0]
            left = ~np.isin(pf_g, cf_g)
            m_out += float(np.sum(pf_m[left]))
            came = ~np.isin(cf_g, pf_g)
            cm = cur["fluid"][1]
            if "outlet" in prev[1]:
                back = came & np.isin(cf_g, prev[1]["outlet"][0])
                m_out -= float(np.sum(cm[back]))
                came &= ~back
            m_in += float(np.sum(cm[came]))
            t_last = t
        prev = (t, cur)
    if t0 is None or t_last is None or t_last <= t0:
        return None
    return m_in / (t_last - t0), m_out / (t_last - t0), t_last - t0


def lift_cycles(ts, sig):
    """[(t0, t1, amplitude)] of the whole cycles of the signal sig(ts) (mean 0) between
    consecutive upward zero crossings (linearly interpolated); amplitude = (max - min) / 2
    over the cycle. A crossing counts only after the signal has fallen below -a/2 since the
    last one (a = its standard deviation times sqrt 2), so that the noise left on the
    averaged lift does not cut a cycle into pieces."""
    low = -0.5 * math.sqrt(2.0) * float(sig.std())
    ups = []
    armed = False
    for k in range(len(sig) - 1):
        armed = armed or sig[k] < low
        if armed and sig[k] < 0 <= sig[k + 1]:
            ups.append((k, ts[k] - sig[k] * (ts[k + 1] - ts[k]) / (sig[k + 1] - sig[k])))
            armed = False
    out = []
    for (k0, t0), (k1, t1) in zip(ups, ups[1:]):
        seg = sig[k0:k1 + 2]
        out.append((t0, t1, 0.5 * (max(seg) - min(seg))))
    return out


def wake_symmetry(outdir, t_start, cx, cy, D):
    """[(t, mean u above the wake's axis, mean u below it)] for the snapshots at t >= t_start
    (the boxes of --symmetry-tol), or None without snapshots."""
    try:
        import h5py
        import numpy as np
    except ImportError:
        return None
    out = []
    for path in snapshot_files(outdir):
        with h5py.File(path, "r") as f:
            t = float(f.attrs["t"])
            if t < t_start - 1e-9 or "fluid" not in f:
                continue
            x, y, u = (np.asarray(f["fluid"][k][()]) for k in ("x", "y", "u"))
        inx = (x >= cx + 0.5 * D) & (x <= cx + 2.5 * D)
        up = inx & (y > cy) & (y <= cy + D)
        down = inx & (y < cy) & (y >= cy - D)
        if not up.any() or not down.any():
            continue
        out.append((t, float(u[up].mean()), float(u[down].mean())))
    return out or None


def main():
    ap = argument_parser(__doc__, "the solver's output directory", "cylinder.png")
    ap.add_argument("--t-start", type=float, default=1.0,
                    help="end of the start-up transient (default 1.0: 2 D / Ubar)")
    ap.add_argument("--cd-tol", type=float, default=0.15)
    ap.add_argument("--cl-tol", type=float, default=0.1)
    ap.add_argument("--drift-tol", type=float, default=0.03)
    ap.add_argument("--count-tol", type=float, default=0.10)
    ap.add_argument("--flux-tol", type=float, default=None)
    ap.add_argument("--count-end-tol", type=float, default=None)
    ap.add_argument("--symmetry-tol", type=float, default=None)
    ap.add_argument("--H", type=float, default=0.41)
    ap.add_argument("--cx", type=float, default=0.2)
    ap.add_argument("--cy", type=float, default=0.2)
    ap.add_argument("--shedding", action="store_true")
    ap.add_argument("--reference", choices=("st96", "re200"), default="st96",
                    help="re200: the unbounded cylinder at Re = 200 (implies --shedding)")
    ap.add_argument("--periodic-tol", type=float, default=None)
    ap.add_argument("--min-periods", type=int, default=3)
    ap.add_argument("--min-amplitude", type=float, default=None,
                    help="shedding cases: the lift amplitude (averaged over --smooth) must "
                         "exceed this (vortices are shed, not noise)")
    ap.add_argument("--st-tol", type=float, default=0.10)
    ap.add_argument("--smooth", type=float, default=0.2,
                    help="--shedding: the window the lift is averaged over (default 0.2)")
    ap.add_argument("--D", type=float, default=0.1)
    ap.add_argument("--Ubar", type=float, default=0.2)
    args = ap.parse_args()
    if args.reference == "re200":
        args.shedding = True
    m = read_metrics(args.outdir, "cylinder.py", ("t", "cd", "cl", "cd_int", "cl_int", "nfluid"))
    if m is None:
        return 2
    t, cd, cl = m["t"], m["cd"], m["cl"]
    failures = []
    for name in ("cd", "cl", "cd_int", "cl_int", "nfluid"):
        bad = [t[k] for k, v in enumerate(m[name]) if not math.isfinite(v)]
        if bad:
            failures.append("%s is not finite at t = %g" % (name, bad[0]))
    n0 = m["nfluid"][0]
    lo, hi = min(m["nfluid"]), max(m["nfluid"])
    print("fluid particles: %d to %d over %d outputs (start %d)" % (lo, hi, len(t), n0))
    if lo < (1 - args.count_tol) * n0 or hi > (1 + args.count_tol) * n0:
        failures.append("the fluid's particle count left %d +- %.0f%%: %d to %d"
                        % (n0, 100 * args.count_tol, lo, hi))
    t_end = t[-1]
    if args.count_end_tol is not None:
        k0 = min(range(len(t)), key=lambda k: abs(t[k] - args.t_start))
        drift = m["nfluid"][-1] / m["nfluid"][k0] - 1
        print("fluid particles at t = %g: %d, at the end: %d (%+.2f%%, tolerance %.1f%%)"
              % (t[k0], m["nfluid"][k0], m["nfluid"][-1], 100 * drift, 100 * args.count_end_tol))
        if not abs(drift) <= args.count_end_tol:
            failures.append("the fluid count drifts by %+.2f%% from t = %g to the end"
                            % (100 * drift, t[k0]))
    if args.flux_tol is not None:
        fl = crossing_flux(args.outdir, args.t_start)
        if fl is None:
            failures.append("no snapshots with gids for the mass flux")
        else:
            q_in, q_out, span = fl
            rel = abs(q_in - q_out) / q_in if q_in > 0 else float("inf")
            print("mass flux over t = %g to %g (gids): in %.6f, out %.6f (rho Ubar H = %.6f); "
                  "in/out differ by %.3f%% (tolerance %.1f%%)"
                  % (args.t_start, args.t_start + span, q_in, q_out, args.Ubar * args.H,
                     100 * rel, 100 * args.flux_tol))
            if not rel <= args.flux_tol:
                failures.append("mass flux in %.6f and out %.6f differ by %.3f%%"
                                % (q_in, q_out, 100 * rel))
            if args.periodic_tol is not None:
                # The mean flow rate over the two halves of the window.
                tm = args.t_start + 0.5 * span
                h1 = crossing_flux(args.outdir, args.t_start, tm)
                h2 = crossing_flux(args.outdir, tm)
                if h1 is None or h2 is None:
                    failures.append("too few snapshots for the flux over each half")
                else:
                    d_in = h2[0] / h1[0] - 1
                    d_out = h2[1] / h1[1] - 1
                    print("mass flux, first / second half of the window: in %.6f / %.6f "
                          "(%+.3f%%), out %.6f / %.6f (%+.3f%%; tolerance %.1f%%)"
                          % (h1[0], h2[0], 100 * d_in, h1[1], h2[1], 100 * d_out,
                             100 * args.flux_tol))
                    if not (abs(d_in) <= args.flux_tol and abs(d_out) <= args.flux_tol):
                        failures.append("the mean flow rate drifts: in %+.3f%%, out %+.3f%% "
                                        "from the first half to the second"
                                        % (100 * d_in, 100 * d_out))
    if args.symmetry_tol is not None:
        sym = wake_symmetry(args.outdir, args.t_start, args.cx, args.cy, args.D)
        if sym is None:
            failures.append("no snapshots after t = %g for the wake's symmetry" % args.t_start)
        else:
            r = [a / b for _, a, b in sym]
            q = sum(a for _, a, _ in sym) / sum(b for _, _, b in sym)
            print("wake symmetry (mean u above / below the axis, x = %g to %g, %d snapshots "
                  "after t = %g): %.3f (tolerance %.0f%%; snapshot by snapshot %.3f to %.3f)"
                  % (args.cx + 0.5 * args.D, args.cx + 2.5 * args.D, len(r), args.t_start,
                     q, 100 * args.symmetry_tol, min(r), max(r)))
            if not abs(q - 1) <= args.symmetry_tol:
                failures.append("the wake is asymmetric: %.3f" % q)
    if t_end <= args.t_start:
        sys.stderr.write("cylinder.py: the run ends at t = %g, before --t-start %g\n"
                         % (t_end, args.t_start))
        return 2
    cd_mean = mean_between(t, m["cd_int"], args.t_start, t_end)
    cl_mean = mean_between(t, m["cl_int"], args.t_start, t_end)
    mid = 0.5 * (args.t_start + t_end)
    cd_1 = mean_between(t, m["cd_int"], args.t_start, mid)
    cd_2 = mean_between(t, m["cd_int"], mid, t_end)
    print("mean over t = %g to %g (from the force integrals): Cd = %.4f, Cl = %.4f"
          % (args.t_start, t_end, cd_mean, cl_mean))
    print("   first half Cd = %.4f, second half Cd = %.4f (drift %+.2f%%)"
          % (cd_1, cd_2, 100 * (cd_2 / cd_1 - 1)))
    if not args.shedding:
        err = cd_mean / CD_ST96 - 1
        print("Cd vs Schaefer & Turek 2D-1 (5.58): %+.2f%% (tolerance %.0f%%); Cl vs 0.0106: "
              "%+.4f (tolerance %.3f)" % (100 * err, 100 * args.cd_tol, cl_mean - CL_ST96,
                                         args.cl_tol))
        if not abs(err) <= args.cd_tol:
            failures.append("Cd %.4f is %+.1f%% from 5.58" % (cd_mean, 100 * err))
        if not abs(cl_mean - CL_ST96) <= args.cl_tol:
            failures.append("Cl %.4f is %+.4f from 0.0106" % (cl_mean, cl_mean - CL_ST96))
        if not abs(cd_2 / cd_1 - 1) <= args.drift_tol:
            failures.append("Cd still drifts: %.4f then %.4f" % (cd_1, cd_2))
    else:
        # The lift averaged over windows of --smooth (from its time integral: the sampled
        # snapshots carry the step-to-step pressure noise), its mean removed, Hann-windowed;
        # the shedding frequency is the peak of its spectrum (zero-padded 16 times).
        import numpy as np
        tt, ii = np.array(t), np.array(m["cl_int"])
        w = max(1, int(round(0.5 * args.smooth / (tt[1] - tt[0]))))
        cls = (ii[2 * w:] - ii[:-2 * w]) / (tt[2 * w:] - tt[:-2 * w])
        tm = tt[w:-w]
        sel = tm >= args.t_start
        sig, ts = cls[sel] - cls[sel].mean(), tm[sel]
        if len(sig) < 8:
            failures.append("too few outputs after t = %g for a spectrum" % args.t_start)
        else:
            n = 16 * len(sig)
            freq = np.fft.rfftfreq(n, ts[1] - ts[0])
            amp = abs(np.fft.rfft(sig * np.hanning(len(sig)), n))
            k = int(np.argmax(amp[1:])) + 1
            st = freq[k] * args.D / args.Ubar
            periods = freq[k] * (ts[-1] - ts[0])
            cl_amp = float(sig.std() * math.sqrt(2.0))
            if args.reference == "st96":
                st_ref = ST_ST96
                print("shedding: %.1f periods after t = %g, St = %.4f (Schaefer & Turek 2D-2: "
                      "0.295-0.305), mean Cd = %.3f (their Cd_max %.2f), lift amplitude %.3f "
                      "(averaged over %g; their Cl_max %.2f)"
                      % (periods, args.t_start, st, cd_mean, CDMAX_ST96, cl_amp, args.smooth,
                         CLMAX_ST96))
            else:
                st_ref, cd_ref = ST_RE200, CD_RE200
                print("shedding: %.1f periods after t = %g, St = %.4f, mean Cd = %.4f, lift "
                      "amplitude %.3f (averaged over %g)"
                      % (periods, args.t_start, st, cd_mean, cl_amp, args.smooth))
                for name, st_r, cd_r, cl_r in RE200:
                    print("   vs %s: St %.3f (%+.1f%%), Cd %.3f (%+.1f%%), Cl amplitude %.3f"
                          % (name, st_r, 100 * (st / st_r - 1), cd_r, 100 * (cd_mean / cd_r - 1),
                             cl_r))
                print("   vs their mean: St %.4f (%+.1f%%, tolerance %.0f%%), Cd %.4f (%+.1f%%, "
                      "tolerance %.0f%%)" % (st_ref, 100 * (st / st_ref - 1), 100 * args.st_tol,
                                             cd_ref, 100 * (cd_mean / cd_ref - 1),
                                             100 * args.cd_tol))
                if not abs(cd_mean / cd_ref - 1) <= args.cd_tol:
                    failures.append("mean Cd %.4f is %+.1f%% from %.3f (the published mean)"
                                    % (cd_mean, 100 * (cd_mean / cd_ref - 1), cd_ref))
            if periods < 3:
                failures.append("fewer than 3 shedding periods after t = %g" % args.t_start)
            if args.min_amplitude is not None and not cl_amp >= args.min_amplitude:
                failures.append("the lift amplitude %.3f is below %g: no shedding"
                                % (cl_amp, args.min_amplitude))
            if not abs(st / st_ref - 1) <= args.st_tol:
                failures.append("St %.4f is %+.1f%% from %.3f" % (st, 100 * (st / st_ref - 1),
                                                                  st_ref))
            if args.periodic_tol is not None:
                cyc = lift_cycles(ts, sig)
                print("lift cycles after t = %g: %d" % (args.t_start, len(cyc)))
                if len(cyc) < args.min_periods:
                    failures.append("%d whole lift cycles after t = %g, fewer than %d"
                                    % (len(cyc), args.t_start, args.min_periods))
                if len(cyc) >= 2:
                    per = np.array([b - a for a, b, _ in cyc])
                    amp_c = np.array([c for _, _, c in cyc])
                    t0c, t1c = cyc[0][0], cyc[-1][1]
                    cl_c = mean_between(t, m["cl_int"], t0c, t1c)
                    half = cyc[len(cyc) // 2][0]
                    cd_a = mean_between(t, m["cd_int"], t0c, half)
                    cd_b = mean_between(t, m["cd_int"], half, t1c)
                    sp, sa = per.std() / per.mean(), amp_c.std() / amp_c.mean()
                    rl, rd = abs(cl_c) / amp_c.mean(), cd_b / cd_a - 1
                    print("   period %.4f (%.3f to %.3f, scatter %.2f%%), amplitude %.4f (%.4f to "
                          "%.4f, scatter %.2f%%), mean lift %.4f (%.2f%% of the amplitude), mean "
                          "Cd first / second half of the cycles %.4f / %.4f (%+.2f%%); tolerance "
                          "%.1f%%" % (per.mean(), per.min(), per.max(), 100 * sp, amp_c.mean(),
                                      amp_c.min(), amp_c.max(), 100 * sa, cl_c, 100 * rl, cd_a,
                                      cd_b, 100 * rd, 100 * args.periodic_tol))
                    for what, v in (("periods", sp), ("amplitudes", sa)):
                        if not v <= args.periodic_tol:
                            failures.append("the lift cycles' %s scatter by %.2f%%"
                                            % (what, 100 * v))
                    if not rl <= args.periodic_tol:
                        failures.append("the mean lift over the cycles is %.2f%% of the "
                                        "amplitude" % (100 * rl))
                    if not abs(rd) <= args.periodic_tol:
                        failures.append("the mean drag drifts by %+.2f%% over the cycles"
                                        % (100 * rd))

    def draw(plt):
        fig, ax = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
        ax[0].plot(t, cd, lw=0.8, label="Cd (sampled at outputs)")
        if args.reference == "re200":
            ref, ref_label = CD_RE200, "mean of 5 published 2D computations"
        elif args.shedding:
            ref, ref_label = CDMAX_ST96, "Schaefer & Turek 1996 (Cd_max)"
        else:
            ref, ref_label = CD_ST96, "Schaefer & Turek 1996"
        ax[0].axhline(ref, color="k", ls="--", label=ref_label)
        ax[0].axhline(cd_mean, color="r", label="SPH, mean after t = %g" % args.t_start)
        ax[0].set_ylim(0, 2 * ref)
        ax[0].set_ylabel("Cd")
        ax[1].plot(t, cl, lw=0.8, label="Cl (sampled at outputs)")
        if args.shedding and len(t) > 3:
            # The coefficients averaged over --smooth, from the integrals (as the spectrum).
            w = max(1, int(round(0.5 * args.smooth / (t[1] - t[0]))))
            tm = t[w:-w]
            for a, key, name in ((ax[0], "cd_int", "Cd"), (ax[1], "cl_int", "Cl")):
                ii = m[key]
                a.plot(tm, [(ii[k + 2 * w] - ii[k]) / (t[k + 2 * w] - t[k])
                            for k in range(len(tm))],
                       color="C1", lw=1.2, label="%s averaged over %g" % (name, args.smooth))
            ax[1].legend(fontsize=8)
        ax[0].legend(fontsize=8)
        ax[1].set_ylabel("Cl")
        ax[1].set_xlabel("t")
        return fig

    plots.write(args, draw, failures)
    for f in failures:
        print("FAILED: " + f)
    if failures:
        return 1
    print("OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
