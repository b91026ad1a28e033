#!/usr/bin/env python3
"""PySPH's side of `sphc study --pysph` (docs/accuracy-cost.md).

For a scene that has a matching example in PySPH 1.0b1 (CASES below), this

  - maps a study variant onto the example's options (`pysph_args`): the varied or fixed
    resolution (dx, nx) and the scheme; names PySPH has no counterpart for (backend,
    precision, kernel, sphc effects) are left out, so one PySPH run stands for all the sphc
    variants that differ only in them;
  - runs the example through this file's driver (`run` mode, under a Python that has PySPH),
    which patches what the example fixes at module level and does not derive from its own
    options (the dam break's particle mass and smoothing length, fixed for dx = 0.03), asks
    the solver for output at the sphc run's metric times, times the time loop alone (wall and
    CPU; PySPH's set-up and Cython compilation are outside it, as sphc's compilation is), and
    then
  - computes the scene's metrics from PySPH's output files with the same definitions
    (`METRICS`), writing a metric file in the solver's format and the solver's `timing:` and
    `metrics:` lines, so the study reads PySPH's runs as it reads sphc's.

The metric functions take plain arrays (x, y, u, v, m, rho, p of the fluid) and are tested on
synthetic data (tests/lit/study/pysph-metrics.test).
"""

import csv
import json
import math
import os
import sys
import time

# ---- references (the scene's CSV tables) ---------------------------------------------------


def read_table(path, column):
    """(at, values) of a reference CSV: '#' comment lines, a header, the first column is the
    abscissa."""
    with open(path) as f:
        lines = [l for l in f if l.strip() and not l.lstrip().startswith("#")]
    rows = list(csv.reader(lines))
    head = [h.strip() for h in rows[0]]
    k = head.index(column)
    pts = sorted((float(r[0]), float(r[k])) for r in rows[1:] if len(r) > k)
    return [a for a, _ in pts], [v for _, v in pts]


def interpolate(table, at):
    """Linear interpolation, NaN outside the table (as the runtime's: no extrapolation)."""
    xs, ys = table
    if not xs or not (xs[0] <= at <= xs[-1]):
        return float("nan")
    for i in range(1, len(xs)):
        if at <= xs[i]:
            x0, x1 = xs[i - 1], xs[i]
            w = 0.0 if x1 == x0 else (at - x0) / (x1 - x0)
            return ys[i - 1] + w * (ys[i] - ys[i - 1])
    return ys[-1]


def compared(name, value, ref, relative=True):
    err = value / ref - 1.0 if relative else value - ref
    if not math.isfinite(ref):
        err = float("nan")
    return [(name, value), (name + "_ref", ref), (name + "_err", err)]


# ---- the metrics of each case, on PySPH's arrays ---------------------------------------------

def metrics_dambreak(a, t, ctx):
    """front and front_mps of examples/dambreak*.sph: max x / L of the water against Koshizuka &
    Oka's experiment and MPS curve at T = t sqrt(2 g / L), relative. PySPH's first wall layer
    lies at x = 0 and its first water column at dx; the wall face of sphc's scenes (x = 0
    there, half a spacing inside the first layer) is at dx / 2 in PySPH's frame."""
    L, g, dx = ctx["L"], ctx["g"], ctx["dx"]
    front = (max(a["x"]) - 0.5 * dx) / L
    T = t * math.sqrt(2.0 * g / L)
    out = []
    for name, table in (("front", ctx["surge"]), ("front_mps", ctx["mps"])):
        out += compared(name, front, interpolate(table, T))
    return out


def metrics_taylor_green(a, t, ctx):
    """decay, l1 and mass of examples/taylor_green.sph."""
    U, L, Re = ctx["U"], ctx["L"], ctx["Re"]
    nu, k = U * L / Re, 2.0 * math.pi / L
    amp = U * math.exp(-2.0 * nu * k * k * t)
    speed = [math.hypot(u, v) for u, v in zip(a["u"], a["v"])]
    exact = [amp * math.hypot(math.cos(k * x) * math.sin(k * y),
                              math.sin(k * x) * math.cos(k * y))
             for x, y in zip(a["x"], a["y"])]
    den = sum(abs(e) for e in exact)
    l1 = sum(abs(s - e) for s, e in zip(speed, exact)) / den if den else float("nan")
    return compared("decay", max(speed), amp) + [("l1", l1), ("mass", sum(a["m"]))]


def metrics_elliptical_drop(a, t, ctx):
    """b_tip, y2 and drho of examples/elliptical_drop.sph (no reference: monitored)."""
    ys = a["y"]
    return [("b_tip", max(abs(y) for y in ys)),
            ("y2", sum(y * y for y in ys) / len(ys)),
            ("drho", max(abs(r / ctx["ro"] - 1.0) for r in a["rho"]))]


def _quintic_shape(q):
    w = (3.0 - q) ** 5 if q < 3.0 else 0.0
    if q < 2.0:
        w -= 6.0 * (2.0 - q) ** 5
    if q < 1.0:
        w += 15.0 * (1.0 - q) ** 5
    return w


def profile_fit(px, py, x, y, f, radius):
    """The value at (px, py) of the weighted least-squares linear fit of f to the particles
    within `radius` (weights: the quintic spline's shape at q = 3 r / radius), as the solver's
    profile metrics (runtime/src/metrics.cpp): NaN with fewer than 6 particles or a singular
    fit. Plain Python (the study's Python need not have numpy)."""
    M = [[0.0] * 4 for _ in range(3)]  # [normal matrix | right-hand side]
    n = 0
    for xj, yj, fj in zip(x, y, f):
        dx, dy = xj - px, yj - py
        if abs(dx) >= radius or abs(dy) >= radius:
            continue
        r = math.hypot(dx, dy)
        if not r < radius:
            continue
        w = _quintic_shape(3.0 * r / radius)
        a = (1.0, dx, dy)
        for i in range(3):
            for j in range(3):
                M[i][j] += w * a[i] * a[j]
            M[i][3] += w * a[i] * fj
        n += 1
    if n < 6:
        return float("nan")
    for c in range(3):  # Gaussian elimination with partial pivoting
        p = max(range(c, 3), key=lambda i: abs(M[i][c]))
        if not abs(M[p][c]) > 1e-12 * abs(M[0][0]):
            return float("nan")
        M[c], M[p] = M[p], M[c]
        for i in range(c + 1, 3):
            l = M[i][c] / M[c][c]
            for j in range(c, 4):
                M[i][j] -= l * M[c][j]
    sol = [0.0, 0.0, 0.0]
    for i in (2, 1, 0):
        sol[i] = (M[i][3] - sum(M[i][j] * sol[j] for j in range(i + 1, 3))) / M[i][i]
    return sol[0]


def metrics_cavity(a, t, ctx):
    """u_max, u_rms, v_max, v_rms and ke of examples/cavity.sph: Ghia et al.'s centre lines
    without their wall rows, the velocity / U fitted at each row's point from the particles
    within 3 h (h = hdx L / nx), averaged over the outputs of the last L / U (ctx["history"]
    keeps the earlier outputs' samples: call in time order), Linf and rms of the errors."""
    L, U = ctx["L"], ctx["U"]
    radius = 3.0 * ctx.get("hdx", 1.0) * L / ctx["nx"]
    x, y = list(a["x"]), list(a["y"])
    u, v = list(a["u"]), list(a["v"])
    lines = []
    for name, (at, val), f, point in (
            ("u", ctx["ghia_u"], u, lambda s: (0.5 * L, s * L)),
            ("v", ctx["ghia_v"], v, lambda s: (s * L, 0.5 * L))):
        rows = [(s, r) for s, r in zip(at, val) if 0.0 < s < 1.0]
        fu = [fj / U for fj in f]
        sample = [profile_fit(*point(s), x, y, fu, radius) for s, _ in rows]
        lines.append((name, [r for _, r in rows], sample))
    hist = ctx.setdefault("history", [])
    if hist and hist[-1][0] == t:
        hist.pop()
    hist.append((t, [smp for _, _, smp in lines]))
    window = ctx.get("average", L / U)
    hist[:] = [h for h in hist if h[0] >= t - window - 1e-9 * max(1.0, abs(t))]
    out = []
    for k, (name, ref, _) in enumerate(lines):
        err = [sum(h[1][k][p] for h in hist) / len(hist) - ref[p] for p in range(len(ref))]
        out += [(name + "_max", max(abs(e) for e in err) if all(e == e for e in err)
                 else float("nan")),
                (name + "_rms", math.sqrt(sum(e * e for e in err) / len(err)))]
    out.append(("ke", math.fsum(0.5 * mj * (uj * uj + vj * vj)
                                for mj, uj, vj in zip(a["m"], u, v))))
    return out


METRICS = {"dambreak": metrics_dambreak, "taylor_green": metrics_taylor_green,
           "elliptical_drop": metrics_elliptical_drop, "cavity": metrics_cavity}


# ---- the cases: scene -> PySPH example ---------------------------------------------------

def _dambreak(scheme):
    return dict(metrics="dambreak", module="pysph.examples.dam_break_2d", app="DamBreak2D",
                args=["--scheme", scheme], every=0.02,
                params={"dx": "dx"},
                ctx=dict(L=1.0, g=9.81, dx=0.03,
                         surge=("../tests/data/koshizuka_oka_1996_surge.csv", "Z_L"),
                         mps=("../tests/data/koshizuka_oka_1996_mps.csv", "Z_L")))


CASES = {
    "dambreak": _dambreak("wcsph"),
    "dambreak_edac": _dambreak("edac"),
    "dambreak_iisph": _dambreak("iisph"),
    "dambreak_sisph": _dambreak("sisph"),
    "taylor_green": dict(metrics="taylor_green", module="pysph.examples.taylor_green",
                         app="TaylorGreen", args=[], every=0.1,
                         params={"nx": "nx", "Re": "re", "hdx": "hdx"},
                         options={"scheme": {"wcsph": "wcsph", "edac": "edac",
                                             "tvf": "tvf"}},
                         default_options={"scheme": "wcsph"},
                         ctx=dict(U=1.0, L=1.0, Re=100.0)),
    # PySPH's cavity: the same case and numerics (TVF, Adami walls, quintic spline, h = dx,
    # c0 = 10 U, the same dt); its walls have 5 layers (sphc's 3: the kernel reaches 3 h).
    "cavity": dict(metrics="cavity", module="pysph.examples.cavity", app="LidDrivenCavity",
                   args=[], every=0.25, params={"nx": "nx", "Re": "re"},
                   ctx=dict(L=1.0, U=1.0, nx=50.0, average=1.0,
                            ghia_u=("../tests/data/ghia1982_re100_u.csv", "u"),
                            ghia_v=("../tests/data/ghia1982_re100_v.csv", "v"))),
    "elliptical_drop": dict(metrics="elliptical_drop", module="pysph.examples.elliptical_drop",
                            app="EllipticalDrop", args=["--scheme", "wcsph"], every=0.0019,
                            params={"dx": "nx"}, ctx=dict(ro=1.0)),
}


def case_of(scene):
    """The case of a scene file (by its name), or None."""
    return CASES.get(os.path.splitext(os.path.basename(scene))[0])


def pysph_args(case, variant, fixed_sets):
    """(PySPH options, the context of the metrics, skipped names) of a variant: a list of
    (name, value) of the study (parameters, compile-time options, sphc flags) plus the
    --set NAME=V of every run. None when a value has no PySPH counterpart (a scheme PySPH's
    example lacks)."""
    args = list(case["args"])
    ctx = dict(case["ctx"])
    skipped = []
    opts = dict(case.get("default_options", {}))
    for name, value in list(fixed_sets) + list(variant):
        if name in case["params"]:
            opt = case["params"][name]
            v = float(value)
            if opt == "nx" and name == "dx":      # points per unit length
                args += ["--nx", str(int(round(1.0 / v)))]
            elif opt == "nx":
                args += ["--nx", str(int(round(v)))]
            else:
                args += ["--" + opt, repr(v)]
            if name == "dx":
                ctx["dx"] = v
            if name in ("Re", "nx", "hdx"):
                ctx[name] = v
        elif name in case.get("options", {}):
            if value not in case["options"][name]:
                return None
            opts[name] = value
        else:
            skipped.append(name)
    for name, value in opts.items():
        args += ["--" + name, case["options"][name][value]]
    return args, ctx, skipped


def pysph_key(args):
    """A PySPH run's identity: its options."""
    return " ".join(args)


# ---- the driver (runs under the Python that has PySPH) -------------------------------------

def load_arrays(path, name="fluid"):
    from pysph.solver.utils import load
    data = load(path)
    pa = data["arrays"][name]
    sd = data["solver_data"]
    a = {p: list(pa.get(p)) for p in ("x", "y", "u", "v", "m", "rho", "p")
         if p in pa.properties}
    return float(sd["t"]), int(sd.get("count", 0)), float(sd.get("dt", float("nan"))), a


def resolve_ctx(case, ctx, scene_dir):
    ctx = dict(ctx)
    for k in ("surge", "mps", "ghia_u", "ghia_v"):
        if k in ctx and isinstance(ctx[k], (list, tuple)) and isinstance(ctx[k][0], str):
            ctx[k] = read_table(os.path.join(scene_dir, ctx[k][0]), ctx[k][1])
    return ctx


def metric_rows(case, ctx, files, loader):
    """(step, t, dt, [(column, value)]) of each output file, in time order; loader(file) gives
    (t, step, dt, arrays) (load_arrays for PySPH's files)."""
    loaded = sorted((loader(fn) for fn in files), key=lambda r: r[0])
    rows = []
    for t, step, dt, a in loaded:  # in time order (the cavity's metrics average over time)
        rows.append((step, t, dt, METRICS[case["metrics"]](a, t, ctx)))
    return rows


def write_metrics(path, rows, wall, cpu):
    """The solver's metric-file format: step, t, dt, wall_s, cpu_s, then the metrics (the
    time loop's totals on the last row; PySPH does not time its outputs)."""
    cols = [c for c, _ in rows[0][3]]
    with open(path, "w") as f:
        f.write(",".join(["step", "t", "dt", "wall_s", "cpu_s"] + cols) + "\n")
        for i, (step, t, dt, vals) in enumerate(rows):
            last = i == len(rows) - 1
            cells = [str(step), repr(t), repr(dt), repr(wall) if last else "nan",
                     repr(cpu) if last else "nan"]
            cells += ["nan" if not math.isfinite(v) else repr(v) for _, v in vals]
            f.write(",".join(cells) + "\n")


def scale_dambreak(mod, dx):
    """PySPH's dam_break_2d (the module `mod`) builds its particles with the module's h and m,
    fixed for dx = 0.03 whatever --dx says: make them follow dx, as the example's own hdx and
    ro define them (nothing else of the example changes). Also used by bench/."""
    mod.dx = dx
    mod.h = mod.hdx * dx
    mod.m = mod.ro * dx * dx


def drive(spec_path):
    with open(spec_path) as f:
        spec = json.load(f)
    case = CASES[spec["case"]]
    import importlib
    mod = importlib.import_module(case["module"])
    dx = spec["ctx"].get("dx")
    if case["metrics"] == "dambreak" and dx is not None:
        scale_dambreak(mod, dx)
    app = getattr(mod, case["app"])()
    outdir = spec["outdir"]
    argv = spec["args"] + ["-d", outdir, "--pfreq", "100000000", "-q"]
    if spec.get("tf") is not None:
        argv += ["--tf", repr(spec["tf"])]
    if spec.get("threads"):
        argv += ["--openmp"]
    app.setup(argv)
    if spec.get("times"):
        app.solver.set_output_at_times(spec["times"])
    t0, c0 = time.perf_counter(), time.process_time()
    app.solver.solve(False)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    app._write_info(app.info_filename, completed=True, cpu_time=wall)
    from pysph.solver.utils import get_files
    files = get_files(outdir, app.fname)
    ctx = resolve_ctx(case, spec["ctx"], spec["scene_dir"])
    particles = sum(pa.get_number_of_particles(real=True) for pa in app.particles)  # no ghosts
    rows = metric_rows(case, ctx, files, load_arrays)
    write_metrics(spec["metrics_file"], rows, wall, cpu)
    steps = app.solver.count
    sys.stdout.write("timing: steps=%d particles=%d wall_s=%.6g us_per_particle_step=%.6g "
                     "backend=pysph\n" % (steps, particles, wall,
                                          1e6 * wall / max(1, steps * particles)))
    last = rows[-1]
    sys.stdout.write("metrics: t=%.10g step=%d wall_s=%.6g cpu_s=%.6g %s\n" % (
        last[1], steps, wall, cpu, " ".join("%s=%.10g" % nv for nv in last[3])))
    return 0


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "run":
        sys.exit(drive(sys.argv[2]))
    sys.stderr.write("usage: study_pysph.py run SPEC.json (started by `sphc study --pysph`)\n")
    sys.exit(2)
