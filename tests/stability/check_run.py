#!/usr/bin/env python3
"""Stability checker: reads EVERY HDF5 snapshot of a run and checks invariants at each.

Runs nothing itself. It reads the snapshots a solver wrote into OUTPUT_DIR (sphc's
<scene>_NNNNNN.h5, root attributes t, step, dt, dim; one group per particle array) in step
order and checks, at every snapshot (or every output interval), the invariants below. A
violated invariant fails the check with one line naming the invariant, the time and the worst
particles (array, index, position):

    FAILED (2 problems):
      [no-nan] t = 0.7400: /fluid/rho has 3 non-finite values: fluid[17] at (0.51, 0.02), ...

Energies: sum over the fluid of m (...), with m the written masses, or 1 for every particle
when the fluid does not write `m` (equal masses: the energies are then per unit particle
mass, in J/kg, and every energy check is a ratio, so its verdict is the same).

Blanket invariants (every case):
  no-nan        no NaN or Inf in any dataset of any array.
  count         the number of particles of every array is that of the first snapshot,
                less the particles the scene's limits removed up to the snapshot's step (a
                limit's `remove`: water thrown out of an open tank; the solver lists each in
                OUTPUT_DIR/<scene>_removed.csv, read when it is there).
  mass          the total mass of every array that writes `m` is that of the first snapshot
                less the removed particles' (to 1e-12 relative: the masses are constants).
  ke-jump       the kinetic energy of the fluid, KE = sum m |v|^2 / 2, never rises in one
                output interval by more than --ke-jump (default 10%) of its value at the
                start of the interval plus the work its physical source can do in it:
                with --g G the work of gravity, bounded by G(t1) x (potential energy lost,
                sum m (y0 - y1), or z in 3D, when positive), where G(t1) is the gravity at
                the end of the interval (with --tdamp T: ramped as the scenes ramp it,
                G (sin(pi (t / T - 1/2)) + 1) / 2 for t < T, which is increasing, so G(t1)
                bounds it over the interval); plus a floor --ke-floor V (a speed: the energy
                floor is M V^2 / 2 with M the fluid mass), below which a rise is noise.
                With --c0 C (and --rho0, --gamma, default 7) the compression energy of the
                Tait equation of state, sum m e(rho), e = int p / rho^2 drho, is a source too:
                its decrease over the interval is added (an acoustic oscillation trades
                kinetic for compression energy and back).
                Without a source (no --g, no --c0) any rise beyond 10% + floor fails.
                --ke-from T starts the check at T, for a start that holds energy of its own
                (a perturbed lattice under tension releases it; the case says so).
  density       rho / rho0 of the fluid within [--rho-min, --rho-max] (when rho is written).
                --eos edac (the EDAC scheme, which evolves the pressure p and uses its
                summation density rho only as the particle volume): rho is the density the
                written p stands for, rho0 + p / c0^2 (its artificial-compressibility
                equation of state; --c0 and --rho0 required, p must be written), and the
                compression energy below is that of this linear law (Tait at gamma = 1).
  energy        (--energy-tol F, with --c0) once gravity is constant (t >= --tdamp), the
                total mechanical energy KE + g sum m y + compression energy does not rise in
                an interval by more than F times the initial potential energy above the
                lowest fluid particle (a conservative scheme with dissipation only loses
                energy; the tolerance is time-integration error).
                (--density-after T: only at t > T, for a start placed off the lattice on
                purpose, whose summation density scatters by design.)
  dt-drop       the mean time step of an output interval (delta t / delta step, from the
                snapshots' t and step attributes; insensitive to the shortened steps that
                land on output times) never falls below 1/--dt-drop (default 100) of the
                largest mean step of the earlier intervals.

Case invariants (options):
  --box XMIN XMAX YMIN [YMAX]   wall penetration: no fluid particle outside the box (the
                inner faces of the walls) by more than --box-tol dx (default 0.5 dx: a
                particle whose centre is half a spacing behind a wall face has crossed it).
                In 3D (the floor at z = ZMIN): --box XMIN XMAX YMIN YMAX ZMIN [ZMAX]; the
                2D form checks x and y only.
  --min-pair F  fluid-fluid pair distance >= F dx at every snapshot outside the time windows
                --pair-skip T0 T1 (repeatable; e.g. an impact).
                --pair-bulk N: judge only pairs of particles in the bulk of the fluid, those
                with at least N other fluid particles within 2.6 dx (2 h at h = 1.3 dx: about
                20 in a full 2D neighbourhood, 5-9 in a jet or spray one or two particles
                thick, where the pressure is zero and nothing pushes a pair apart or together:
                its distance is that with which it left an impact).
  --wall-rho-min ARRAY F   wall density: rho / rho0 of the particles of ARRAY (dynamic
                boundary particles, whose density follows the continuity equation) >= F at
                every snapshot that writes it. Such a wall's pressure is clamped at zero below
                rho0, so a wall density far below rho0 is no tension but a deficit the wall
                remembers: it must be compressed back before it pushes returning water.
  --quiet-after T, --v-max V    after time T, max |v| of the fluid <= V (m/s).
  --ke-no-growth-after T        with no physical source after T (constant gravity, nothing
                moving): the kinetic energy must not grow. The window [T, tf] is split in
                halves; the largest KE of the second half must not exceed the largest of
                the first (noise that decays or stays level passes, growth fails), beyond
                the --ke-floor.
  --surface-drift-after T       the top of the fluid (the largest y; z in 3D) stays within
                --surface-drift dx (default 1) of its value at the first snapshot at t >= T.
  --max-removed N               removed: at most N particles of the fluid removed by the
                scene's limits (a limit's `remove`, OUTPUT_DIR/<scene>_removed.csv) up to
                each snapshot (water thrown out of an open tank over a wall's top).
  --expect-violation NAME       invert the verdict for the invariant NAME: the check passes
                only if NAME is violated (and prints where); the other invariants must hold.
                For the cases that must show a failure (the tensile instability without
                the correction).
  --summary FILE --case C --scheme S   append one row per checked invariant (case, scheme,
                invariant, worst value, limit) to FILE (tab-separated), for docs/stability.md.

Exit 0 when every invariant holds (or the expected violation happens), 1 when one fails,
2 on bad input.
"""
import argparse
import glob
import math
import os
import sys

try:
    import h5py
    import numpy as np
except ImportError as exc:  # pragma: no cover - environment problem
    sys.stderr.write("check_run.py needs numpy and h5py (%s)\n" % exc)
    sys.exit(2)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "validation"))
from snapshots import lattice_spacing, particle_arrays, snapshots  # noqa: E402

WHO = "check_run.py"


def box_excess(b, pos):
    """How far each particle lies outside the box b (the inner faces of the walls), per face
    (positive outside): b = XMIN XMAX YMIN [YMAX] in 2D; in 3D, where the floor is z,
    XMIN XMAX YMIN YMAX ZMIN [ZMAX] (side walls at y = YMIN and YMAX), or the 2D form,
    which leaves z unchecked."""
    out = [b[0] - pos[0], pos[0] - b[1], b[2] - pos[1]]
    if len(b) > 3:
        out.append(pos[1] - b[3])
    if len(b) > 4:
        out.append(b[4] - pos[2])
    if len(b) > 5:
        out.append(pos[2] - b[5])
    return out


def cell_pairs(pos, cell):
    """The candidate pairs of the points pos = (x, y[, z]) in the same or neighbouring cells of
    size `cell`: yields (i, j) index arrays, i < j, one cell offset at a time."""
    n = len(pos[0])
    dim = len(pos)
    ic = [np.floor(c / cell).astype(np.int64) for c in pos]
    lo = [a.min() - 1 for a in ic]
    ext = [a.max() - l + 2 for a, l in zip(ic, lo)]
    def key(offs):
        k = np.zeros(n, dtype=np.int64)
        for d in range(dim):
            k = k * ext[d] + (ic[d] - lo[d] + offs[d])
        return k
    own = key([0] * dim)
    order = np.argsort(own, kind="stable")
    sk = own[order]
    offsets = [[a, b, c][:dim] for a in (-1, 0, 1) for b in (-1, 0, 1)
               for c in ((-1, 0, 1) if dim == 3 else (0,))]
    if dim == 1:
        offsets = [[-1], [0], [1]]
    seen = set()
    for off in offsets:
        t = tuple(off)
        if t in seen:
            continue
        seen.add(t)
        nk = key(off)
        start = np.searchsorted(sk, nk, side="left")
        stop = np.searchsorted(sk, nk, side="right")
        cnt = stop - start
        if cnt.sum() == 0:
            continue
        i = np.repeat(np.arange(n), cnt)
        first = np.repeat(start, cnt)
        within = np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        j = order[first + within]
        keep = i < j
        if np.any(keep):
            yield i[keep], j[keep]


def min_pair_distance(pos, cell):
    """(d, i, j): the smallest distance between two of the points pos = (x, y[, z]) and the
    pair, using cells of size `cell` (pairs farther apart than `cell` may be missed; then
    d = inf is returned when no pair is closer than `cell`)."""
    if len(pos[0]) < 2:
        return math.inf, -1, -1
    best = (math.inf, -1, -1)
    for i, j in cell_pairs(pos, cell):
        r2 = np.zeros(len(i))
        for c in pos:
            r2 += (c[i] - c[j]) ** 2
        k = int(np.argmin(r2))
        if math.sqrt(r2[k]) < best[0]:
            best = (math.sqrt(r2[k]), int(i[k]), int(j[k]))
    return best


def where(name, idx, pos):
    """'name[i] at (x, y)' for the particle idx of array `name`."""
    return "%s[%d] at (%s)" % (name, idx, ", ".join("%.4g" % c[idx] for c in pos))


def elastic_energy(m, rho, rho0, c0, gamma):
    """sum m e(rho): the compression energy of the Tait equation of state
    p = B ((rho / rho0)^gamma - 1), B = rho0 c0^2 / gamma, e(rho) = int_rho0^rho p / r^2 dr
    = B / rho0^gamma (rho^(gamma-1) - rho0^(gamma-1)) / (gamma - 1) + B (1 / rho - 1 / rho0)
    (gamma = 1: B / rho0 ln(rho / rho0) + B (1 / rho - 1 / rho0))."""
    B = rho0 * c0 * c0 / gamma
    r = rho / rho0
    if abs(gamma - 1.0) < 1e-12:
        e = B / rho0 * np.log(r)
    else:
        e = B / rho0 * (r ** (gamma - 1.0) - 1.0) / (gamma - 1.0)
    e = e + B * (1.0 / rho - 1.0 / rho0)
    return float(np.sum(m * e))


def eos_density(fl, args):
    """The fluid's density as the checks judge it (None when the snapshot has none): the
    written rho (--eos tait), or with --eos edac the density the EDAC pressure stands for.
    EDAC (Ramachandran & Puri 2019) evolves the pressure p, not the density, and its rho is a
    summation density used only as the particle volume (short of rho0 at a free surface by
    design); its pressure equation dp/dt = -rho c0^2 div(u) is that of artificial
    compressibility with the linear equation of state p = c0^2 (rho - rho0), so the density
    it implies is rho0 + p / c0^2, and the compression energy is the Tait one at gamma = 1."""
    if args.eos == "edac":
        if "p" not in fl:
            return None
        return args.rho0 + fl["p"].astype(float) / (args.c0 * args.c0)
    return fl["rho"].astype(float) if "rho" in fl else None


def gravity_at(t, g, tdamp):
    if tdamp > 0 and t < tdamp:
        return g * 0.5 * (math.sin(math.pi * (t / tdamp - 0.5)) + 1.0)
    return g


class Invariant:
    """The worst value of one invariant over the run, its limit, and its violations."""

    def __init__(self, name, limit, describe):
        self.name, self.limit, self.describe = name, limit, describe
        self.worst = None
        self.violations = []

    def record(self, value, worse):
        """Keeps `value` as the worst if `worse(value, current)`."""
        if value is None or (isinstance(value, float) and math.isnan(value)):
            return
        if self.worst is None or worse(value, self.worst):
            self.worst = value

    def fail(self, t, msg):
        self.violations.append("[%s] t = %.4f: %s" % (self.name, t, msg))


def removed_particles(outdir):
    """The particles the solver removed (a limit's `remove`), from OUTPUT_DIR/*_removed.csv:
    (step, limit, array, mass) per particle (mass 0 where the array has no m)."""
    rows = []
    for path in sorted(glob.glob(os.path.join(outdir, "*_removed.csv"))):
        with open(path) as f:
            header = f.readline().strip().split(",")
            col = {k: i for i, k in enumerate(header)}
            for line in f:
                v = line.rstrip("\n").split(",")
                if len(v) != len(header):
                    continue
                m = v[col["m"]]
                rows.append((int(v[col["step"]]), v[col["limit"]], v[col["array"]],
                             float(m) if m else 0.0))
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("outdir")
    ap.add_argument("--fluid", default="fluid", help="the fluid array (default fluid)")
    ap.add_argument("--rho0", type=float, default=None, help="reference density")
    ap.add_argument("--rho-min", type=float, default=None, help="smallest rho / rho0")
    ap.add_argument("--rho-max", type=float, default=None, help="largest rho / rho0")
    ap.add_argument("--density-after", type=float, default=None,
                    help="check the density only at t > this (a start that is off the "
                         "lattice on purpose)")
    ap.add_argument("--g", type=float, default=0.0, help="gravity (the physical source)")
    ap.add_argument("--tdamp", type=float, default=0.0, help="gravity ramp time")
    ap.add_argument("--c0", type=float, default=None, help="sound speed of the Tait EOS")
    ap.add_argument("--gamma", type=float, default=7.0, help="exponent of the Tait EOS")
    ap.add_argument("--eos", choices=("tait", "edac"), default="tait",
                    help="where the fluid's density and compression energy come from: the "
                         "written rho with the Tait EOS (default), or the written EDAC "
                         "pressure p (rho0 + p / c0^2, gamma = 1)")
    ap.add_argument("--energy-tol", type=float, default=None)
    ap.add_argument("--ke-jump", type=float, default=0.10)
    ap.add_argument("--ke-floor", type=float, default=0.0, help="speed below which KE is noise")
    ap.add_argument("--ke-from", type=float, default=None, help="start of the ke-jump check")
    ap.add_argument("--dt-drop", type=float, default=100.0)
    ap.add_argument("--dx", type=float, default=None, help="particle spacing (default: the "
                    "initial fluid lattice's)")
    ap.add_argument("--box", type=float, nargs="+", default=None)
    ap.add_argument("--box-tol", type=float, default=0.5)
    ap.add_argument("--min-pair", type=float, default=None)
    ap.add_argument("--pair-bulk", type=int, default=0)
    ap.add_argument("--pair-skip", type=float, nargs=2, action="append", default=[])
    ap.add_argument("--wall-rho-min", nargs=2, default=None, metavar=("ARRAY", "F"))
    ap.add_argument("--quiet-after", type=float, default=None)
    ap.add_argument("--v-max", type=float, default=None)
    ap.add_argument("--ke-no-growth-after", type=float, default=None)
    ap.add_argument("--surface-drift-after", type=float, default=None)
    ap.add_argument("--surface-drift", type=float, default=1.0)
    ap.add_argument("--max-removed", type=int, default=None)
    ap.add_argument("--expect-violation", default=None)
    ap.add_argument("--summary", default=None)
    ap.add_argument("--case", default="?")
    ap.add_argument("--scheme", default="?")
    ap.add_argument("--show", type=int, default=3, help="particles named per violation")
    args = ap.parse_args()

    if args.eos == "edac" and (args.c0 is None or args.rho0 is None):
        sys.stderr.write("%s: --eos edac needs --c0 and --rho0\n" % WHO)
        return 2
    gamma = 1.0 if args.eos == "edac" else args.gamma

    files = snapshots(args.outdir, WHO)
    if files is None:
        return 2

    inv = {}

    def add(name, limit, describe):
        inv[name] = Invariant(name, limit, describe)
        return inv[name]

    nan = add("no-nan", 0, "non-finite values (count)")
    count = add("count", 0, "particles gained or lost")
    gone_fluid = add("removed", args.max_removed,
                     "fluid particles removed by the scene's limits (out of the tank)") \
        if args.max_removed is not None else None
    mass = add("mass", 1e-12, "relative change of the total mass")
    kej = add("ke-jump", args.ke_jump, "largest KE rise in one interval beyond its source, "
              "relative to KE at its start")
    dens = None
    if args.rho_min is not None or args.rho_max is not None:
        if args.rho0 is None:
            sys.stderr.write("%s: --rho-min/--rho-max need --rho0\n" % WHO)
            return 2
        dens = add("density", (args.rho_min, args.rho_max), "rho / rho0 range")
    energy = None
    if args.energy_tol is not None:
        if args.c0 is None or args.rho0 is None:
            sys.stderr.write("%s: --energy-tol needs --c0 and --rho0\n" % WHO)
            return 2
        energy = add("energy", args.energy_tol, "largest rise of KE + PE + compression energy "
                     "in one interval / initial PE")
    dtd = add("dt-drop", args.dt_drop, "largest earlier mean step / mean step")
    box = add("wall", args.box_tol, "largest distance outside the walls [dx]") if args.box else None
    pair = add("min-pair", args.min_pair, "smallest fluid pair distance [dx]") \
        if args.min_pair is not None else None
    wall_rho = None
    if args.wall_rho_min is not None:
        if args.rho0 is None:
            sys.stderr.write("%s: --wall-rho-min needs --rho0\n" % WHO)
            return 2
        wall_arr, wall_min = args.wall_rho_min[0], float(args.wall_rho_min[1])
        wall_rho = add("wall-density", wall_min, "smallest rho / rho0 of %s" % wall_arr)
    quiet = add("v-max", args.v_max, "largest speed after t = %g [m/s]" % args.quiet_after) \
        if args.quiet_after is not None else None
    drift = add("surface-drift", args.surface_drift,
                "free-surface drift after t = %g [dx]" % args.surface_drift_after) \
        if args.surface_drift_after is not None else None
    grow = add("ke-growth", 1.0, "max KE of the 2nd half / max KE of the 1st half after "
               "t = %g" % args.ke_no_growth_after) if args.ke_no_growth_after is not None else None

    removed = removed_particles(args.outdir)
    if removed:
        print("%s: %d particles removed by the scene's limits (%s), accounted in count and mass"
              % (WHO, len(removed), ", ".join(sorted({r[1] for r in removed}))))

    first = None
    prev = None
    dx = args.dx
    dts = []
    series = []  # (t, KE, top)
    top_ref = None
    for path in files:
        name = os.path.basename(path)
        with h5py.File(path, "r") as f:
            t, dim, arrays = particle_arrays(f)
            step = int(f.attrs["step"]) if "step" in f.attrs else None
            data = {a: {k: np.asarray(d[()]) for k, d in g.items()} for a, g in arrays.items()}
        dim = dim or 2
        if args.fluid not in data:
            sys.stderr.write("%s: %s has no array %s\n" % (WHO, name, args.fluid))
            return 2
        fl = data[args.fluid]
        for k in ("x", "y") + (("z",) if dim == 3 else ()):
            if k not in fl:
                sys.stderr.write("%s: %s has no /%s/%s\n" % (WHO, name, args.fluid, k))
                return 2
        vert = "z" if dim == 3 else "y"
        if args.box is not None and not 3 <= len(args.box) <= (6 if dim == 3 else 4):
            sys.stderr.write("%s: --box takes XMIN XMAX YMIN [YMAX]%s (%d values given)\n"
                             % (WHO, " [ZMIN [ZMAX]] in 3D" if dim == 3 else " in 2D",
                                len(args.box)))
            return 2
        if args.eos == "edac" and "p" not in fl:
            sys.stderr.write("%s: --eos edac: %s has no /%s/p (the EDAC pressure)\n"
                             % (WHO, name, args.fluid))
            return 2

        # no-nan: name the particles of every dataset with non-finite values.
        bad_here = 0
        for a, props in data.items():
            apos = [props[c] for c in ("x", "y", "z")[:dim] if c in props]
            for k, v in props.items():
                if v.dtype.kind != "f":
                    continue
                bad = ~np.isfinite(v)
                if v.ndim > 1:
                    bad = bad.reshape(len(bad), -1).any(axis=1)
                if np.any(bad):
                    idx = np.flatnonzero(bad)
                    bad_here += len(idx)
                    named = ", ".join(where(a, i, apos) for i in idx[:args.show]) \
                        if len(apos) == dim else ", ".join("%s[%d]" % (a, i) for i in idx[:args.show])
                    nan.fail(t, "/%s/%s has %d non-finite values: %s"
                             % (a, k, len(idx), named))
        nan.record(bad_here, lambda a, b: a > b)
        if bad_here:
            # Nothing else is meaningful once values are not finite.
            prev = None
            continue

        pos = [fl[c].astype(float) for c in ("x", "y", "z")[:dim]]
        n = len(pos[0])
        if dx is None:
            dx = lattice_spacing(pos)
        m = fl["m"].astype(float) if "m" in fl else np.full(n, 1.0)
        vel = [fl[c].astype(float) for c in ("u", "v", "w")[:dim] if c in fl]
        v2 = sum(c * c for c in vel) if len(vel) == dim else None
        ke = 0.5 * float(np.sum(m * v2)) if v2 is not None else None
        msum = float(np.sum(m))
        pe_h = float(np.sum(m * fl[vert].astype(float)))  # sum m * height
        rho = eos_density(fl, args)
        eint = None
        if args.c0 is not None and rho is not None and args.rho0 is not None:
            eint = elastic_energy(m, rho, args.rho0, args.c0, gamma)
        if first is None:
            first = {"t": t, "step": step,
                     "n": {a: len(p["x"]) for a, p in data.items() if "x" in p},
                     "m": {a: float(np.sum(p["m"])) for a, p in data.items() if "m" in p},
                     "M": msum,
                     "eref": args.g * float(np.sum(m * (fl[vert] - fl[vert].min())))}
        # count and mass
        # (the particles removed after the first snapshot and up to this one, per array)
        gone = [r for r in removed if step is not None and first.get("step") is not None
                and first["step"] < r[0] <= step]
        if gone_fluid is not None:
            k = sum(1 for r in gone if r[2] == args.fluid)
            gone_fluid.record(k, lambda a_, b: a_ > b)
            if k > args.max_removed:
                gone_fluid.fail(t, "%d fluid particles removed by the scene's limits so far "
                                   "(limit %d)" % (k, args.max_removed))
        for a, n0 in first["n"].items():
            na = len(data[a]["x"]) if a in data and "x" in data[a] else 0
            na += sum(1 for r in gone if r[2] == a)
            count.record(abs(na - n0), lambda a_, b: a_ > b)
            if na != n0:
                count.fail(t, "array %s has %d particles and %d removed, the first snapshot %d"
                           % (a, na - sum(1 for r in gone if r[2] == a),
                              sum(1 for r in gone if r[2] == a), n0))
        for a, m0 in first["m"].items():
            if a in data and "m" in data[a]:
                ma = float(np.sum(data[a]["m"])) + sum(r[3] for r in gone if r[2] == a)
                rel = abs(ma - m0) / abs(m0) if m0 else 0.0
                mass.record(rel, lambda a_, b: a_ > b)
                if rel > mass.limit:
                    mass.fail(t, "total mass of %s changed by %.3g (relative)" % (a, rel))
        floor_e = 0.5 * first["M"] * args.ke_floor ** 2
        # ke-jump
        if prev is not None and ke is not None and prev["ke"] is not None \
                and (args.ke_from is None or prev["t"] >= args.ke_from):
            work = max(0.0, gravity_at(t, args.g, args.tdamp) * (prev["pe_h"] - pe_h))
            if eint is not None and prev["eint"] is not None:
                work += max(0.0, prev["eint"] - eint)
            rise = ke - prev["ke"] - work - floor_e
            rel = rise / prev["ke"] if prev["ke"] > 0 else (math.inf if rise > 0 else 0.0)
            kej.record(rel, lambda a, b: a > b)
            if rel > args.ke_jump:
                i = int(np.argmax(v2))
                kej.fail(t, "KE rose from %.4g to %.4g J (x%.3g) since t = %.4f; the work of "
                         "gravity bounds %.4g J, the floor %.3g J; fastest: %s with |v| = %.4g"
                         % (prev["ke"], ke, ke / prev["ke"] if prev["ke"] else math.inf,
                            prev["t"], work, floor_e, where(args.fluid, i, pos),
                            math.sqrt(v2[i])))
        # density
        if dens is not None and rho is not None and \
                (args.density_after is None or t > args.density_after):
            r = rho / args.rho0
            lo, hi = float(r.min()), float(r.max())
            dens.worst = (lo, hi) if dens.worst is None else \
                (min(dens.worst[0], lo), max(dens.worst[1], hi))
            badr = np.zeros(n, dtype=bool)
            if args.rho_min is not None:
                badr |= r < args.rho_min
            if args.rho_max is not None:
                badr |= r > args.rho_max
            if np.any(badr):
                idx = np.flatnonzero(badr)
                idx = idx[np.argsort(-np.abs(r[idx] - 1.0))][:args.show]
                dens.fail(t, "%d fluid particles with rho / rho0 outside [%s, %s]: %s"
                          % (int(badr.sum()), args.rho_min, args.rho_max,
                             ", ".join("%s rho/rho0 = %.4g" % (where(args.fluid, i, pos), r[i])
                                       for i in idx)))
        # wall density
        if wall_rho is not None and wall_arr in data and "rho" in data[wall_arr]:
            wa = data[wall_arr]
            wr = wa["rho"].astype(float) / args.rho0
            wall_rho.record(float(wr.min()), lambda a, b: a < b)
            badw = np.flatnonzero(wr < wall_min)
            if len(badw):
                wpos = [wa[c].astype(float) for c in ("x", "y", "z")[:dim]]
                idx = badw[np.argsort(wr[badw])][:args.show]
                wall_rho.fail(t, "%d particles of %s with rho / rho0 below %s: %s"
                              % (len(badw), wall_arr, wall_min,
                                 ", ".join("%s rho/rho0 = %.4g" % (where(wall_arr, i, wpos), wr[i])
                                           for i in idx)))
        # dt-drop
        if prev is not None and step is not None and prev["step"] is not None \
                and step > prev["step"]:
            mean_dt = (t - prev["t"]) / (step - prev["step"])
            if dts:
                ratio = max(dts) / mean_dt
                dtd.record(ratio, lambda a, b: a > b)
                if ratio > args.dt_drop:
                    dtd.fail(t, "mean dt %.4g over (%.4f, %.4f] is %.4g times below the "
                             "largest earlier mean dt %.4g" % (mean_dt, prev["t"], t, ratio,
                                                               max(dts)))
            dts.append(mean_dt)
        # wall penetration
        if box is not None:
            out = np.maximum.reduce(box_excess(args.box, pos)) / dx
            box.record(float(max(out.max(), 0.0)), lambda a, b_: a > b_)
            bad = out > args.box_tol
            if np.any(bad):
                idx = np.flatnonzero(bad)
                idx = idx[np.argsort(-out[idx])][:args.show]
                box.fail(t, "%d fluid particles more than %.2g dx behind a wall face: %s"
                         % (int(bad.sum()), args.box_tol,
                            ", ".join("%s (%.3g dx out)" % (where(args.fluid, i, pos), out[i])
                                      for i in idx)))
        # minimum pair distance
        if pair is not None and not any(a <= t <= b for a, b in args.pair_skip):
            if args.pair_bulk > 0:
                bulk = np.flatnonzero(neighbour_counts(pos, 2.6 * dx) >= args.pair_bulk)
                d, i, j = min_pair_distance([c[bulk] for c in pos], dx)
                if i >= 0:
                    i, j = int(bulk[i]), int(bulk[j])
            else:
                d, i, j = min_pair_distance(pos, dx)
            d /= dx
            pair.record(d, lambda a, b: a < b)
            if d < args.min_pair:
                # how many particles have a neighbour closer than the limit
                close = count_close(pos, args.min_pair * dx)
                pair.fail(t, "fluid pair %.3g dx apart (limit %.3g dx): %s and %s; %d fluid "
                          "particles closer than %.3g dx to a neighbour"
                          % (d, args.min_pair, where(args.fluid, i, pos),
                             where(args.fluid, j, pos), close, args.min_pair))
        # quiet after
        if quiet is not None and t >= args.quiet_after and v2 is not None:
            i = int(np.argmax(v2))
            vm = math.sqrt(float(v2[i]))
            quiet.record(vm, lambda a, b: a > b)
            if vm > args.v_max:
                quiet.fail(t, "largest speed %.4g m/s > %.4g m/s: %s"
                           % (vm, args.v_max, where(args.fluid, i, pos)))
        # surface drift
        top = float(pos[-1].max())
        if drift is not None and t >= args.surface_drift_after:
            if top_ref is None:
                top_ref = top
            dd = abs(top - top_ref) / dx
            drift.record(dd, lambda a, b: a > b)
            if dd > args.surface_drift:
                i = int(np.argmax(pos[-1]))
                drift.fail(t, "top of the fluid moved %.3g dx since t = %g: %s"
                           % (dd, args.surface_drift_after, where(args.fluid, i, pos)))
        series.append((t, ke, top))
        # total mechanical energy, once gravity is constant
        if energy is not None and ke is not None and eint is not None and t >= args.tdamp:
            etot = ke + args.g * pe_h + eint
            if prev is not None and prev.get("etot") is not None:
                rise = (etot - prev["etot"]) / first["eref"]
                energy.record(rise, lambda a, b: a > b)
                if rise > args.energy_tol:
                    energy.fail(t, "total energy KE + PE + compression rose by %.3g of the "
                                "initial potential energy %.4g J since t = %.4f (KE %.4g J)"
                                % (rise, first["eref"], prev["t"], ke))
        else:
            etot = None
        prev = {"t": t, "ke": ke, "pe_h": pe_h, "step": step, "eint": eint, "etot": etot}

    # ke-growth over the quiet window
    if grow is not None:
        w = [(t, k) for t, k, _ in series if t >= args.ke_no_growth_after and k is not None]
        if len(w) < 4:
            sys.stderr.write("%s: --ke-no-growth-after %g leaves %d snapshots (need >= 4)\n"
                             % (WHO, args.ke_no_growth_after, len(w)))
            return 2
        half = len(w) // 2
        k1 = max(k for _, k in w[:half])
        t2, k2 = max(w[half:], key=lambda p: p[1])
        floor_e = 0.5 * first["M"] * args.ke_floor ** 2
        ratio = (k2 - floor_e) / k1 if k1 > 0 else math.inf
        ratio = max(ratio, 0.0)
        grow.record(ratio, lambda a, b: a > b)
        if ratio > 1.0:
            grow.fail(t2, "KE %.4g J in [%.4f, %.4f] exceeds the largest KE %.4g J of "
                      "[%.4f, %.4f] (x%.3g, floor %.3g J): the kinetic energy grows with no "
                      "source" % (k2, w[half][0], w[-1][0], k1, w[0][0], w[half - 1][0],
                                  k2 / k1 if k1 else math.inf, floor_e))

    print("%s: %d snapshots in %s, t = %.4g .. %.4g, dx = %.4g, %d fluid particles"
          % (WHO, len(files), args.outdir, first["t"] if first else float("nan"),
             series[-1][0] if series else float("nan"), dx or float("nan"),
             first["n"].get(args.fluid, 0) if first else 0))
    if dts:
        print("mean dt per output interval: first %.4g, min %.4g, max %.4g; steps %s"
              % (dts[0], min(dts), max(dts), prev["step"] if prev else "?"))
    print("%-15s %-24s %-24s %s" % ("invariant", "worst", "limit", "meaning"))
    rows = []
    for k, v in inv.items():
        ws = fmt_val(v.worst)
        ls = fmt_val(v.limit)
        print("%-15s %-24s %-24s %s" % (k, ws, ls, v.describe))
        rows.append((args.case, args.scheme, k, ws, ls))
    if args.summary:
        with open(args.summary, "a") as out:
            for r in rows:
                out.write("\t".join(r) + "\n")

    failures = []
    expected = None
    for k, v in inv.items():
        if k == args.expect_violation:
            expected = v
            continue
        failures += v.violations
    if args.expect_violation is not None:
        if expected is None:
            sys.stderr.write("%s: --expect-violation %s: no such invariant checked (%s)\n"
                             % (WHO, args.expect_violation, ", ".join(inv)))
            return 2
        if not expected.violations:
            failures.append("[%s] expected to be violated (the case must show the failure), "
                            "but it held at every snapshot: worst %s, limit %s"
                            % (expected.name, fmt_val(expected.worst), fmt_val(expected.limit)))
        else:
            print("expected violation of %s, seen at %d snapshots; the first:"
                  % (expected.name, len(expected.violations)))
            print("  " + expected.violations[0])
    if failures:
        print("FAILED (%d problems):" % len(failures))
        for msg in failures[:40]:
            print("  " + msg)
        if len(failures) > 40:
            print("  ... and %d more" % (len(failures) - 40))
        return 1
    print("PASSED")
    return 0


def count_close(pos, r):
    """The number of points with another point closer than r."""
    n = len(pos[0])
    close = np.zeros(n, dtype=bool)
    # brute force by chunks over a cell-sorted subset: only points whose nearest is < r
    for i0 in range(0, n, 512):
        sl = slice(i0, min(n, i0 + 512))
        r2 = np.zeros((sl.stop - sl.start, n))
        for c in pos:
            r2 += (c[sl, None] - c[None, :]) ** 2
        r2[np.arange(sl.stop - sl.start), np.arange(sl.start, sl.stop)] = np.inf
        close[sl] = (r2 < r * r).any(axis=1)
    return int(close.sum())


def neighbour_counts(pos, r, idx=None):
    """The number of other points closer than r, for every point (or the points idx)."""
    n = len(pos[0])
    idx = np.arange(n) if idx is None else np.asarray(idx)
    counts = np.zeros(len(idx), dtype=np.int64)
    for i0 in range(0, len(idx), 512):
        sl = idx[i0:i0 + 512]
        r2 = np.zeros((len(sl), n))
        for c in pos:
            r2 += (c[sl, None] - c[None, :]) ** 2
        counts[i0:i0 + len(sl)] = (r2 < r * r).sum(axis=1) - 1
    return counts


def fmt_val(v):
    if v is None:
        return "-"
    if isinstance(v, tuple):
        return "[" + ", ".join(fmt_val(x) for x in v) + "]"
    if isinstance(v, float):
        return "%.4g" % v
    return str(v)


if __name__ == "__main__":
    sys.exit(main())
