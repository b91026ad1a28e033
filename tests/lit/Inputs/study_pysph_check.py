#!/usr/bin/env python3
"""Unit checks of `sphc study --pysph` (compiler/driver/study_pysph.py and study.py's
comparison of the two codes), on synthetic data: no PySPH needed except for `--pysph-file`.

    study_pysph_check.py SHARE_DIR [--pysph-file TMPDIR]

SHARE_DIR holds study.py and study_pysph.py (the build tree's share/sphc). Prints one line per
check and exits 1 at the first that fails.
"""

import math
import os
import sys

sys.path.insert(0, sys.argv[1])
import study  # noqa: E402
import study_pysph as sp  # noqa: E402


def check(what, cond, detail=""):
    if not cond:
        sys.stdout.write("FAIL %s %s\n" % (what, detail))
        sys.exit(1)
    sys.stdout.write("ok %s\n" % what)


def close(a, b, tol=1e-12):
    return abs(a - b) <= tol * max(1.0, abs(b))


# ---- the mapping of variants onto PySPH's options ------------------------------------------
db = sp.case_of("somewhere/examples/dambreak.sph")
check("dambreak.sph is dam_break_2d wcsph", db is not None and db["args"] == ["--scheme", "wcsph"])
check("dambreak_iisph.sph is dam_break_2d iisph",
      sp.case_of("dambreak_iisph.sph")["args"] == ["--scheme", "iisph"])
check("no counterpart for couette", sp.case_of("examples/couette.sph") is None)
args, ctx, skipped = sp.pysph_args(db, [("dx", "0.045"), ("backend", "openmp")], [])
check("dx maps to --dx", args == ["--scheme", "wcsph", "--dx", "0.045"], args)
check("the metrics' dx follows", ctx["dx"] == 0.045)
check("backend has no counterpart", skipped == ["backend"], skipped)
args2, _, _ = sp.pysph_args(db, [("dx", "0.045"), ("backend", "serial")], [])
check("variants differing in skipped names are one PySPH run",
      sp.pysph_key(args) == sp.pysph_key(args2))
tg = sp.case_of("taylor_green.sph")
args, ctx, _ = sp.pysph_args(tg, [("nx", "30"), ("scheme", "tvf")], [("Re", "200")])
check("taylor_green: nx, Re, scheme", args == ["--re", "200.0", "--nx", "30", "--scheme", "tvf"],
      args)
check("taylor_green: the metrics' Re follows --set", ctx["Re"] == 200.0)
check("taylor_green: a scheme PySPH lacks is no run",
      sp.pysph_args(tg, [("nx", "30"), ("scheme", "isph")], []) is None)
args, _, _ = sp.pysph_args(tg, [("nx", "20")], [])
check("taylor_green: the scene's default scheme", args[-2:] == ["--scheme", "wcsph"], args)
ed = sp.case_of("elliptical_drop.sph")
args, _, _ = sp.pysph_args(ed, [("dx", "0.025")], [])
check("elliptical_drop: dx = 0.025 is --nx 40", args[-2:] == ["--nx", "40"], args)

# ---- the metrics on synthetic arrays -------------------------------------------------------
table = ([0.0, 1.0, 2.0], [1.0, 2.0, 4.0])
check("interpolate inside", close(sp.interpolate(table, 1.5), 3.0))
check("no extrapolation", math.isnan(sp.interpolate(table, 2.5)))
g = 9.81
t = 1.5 / math.sqrt(2 * g)  # T = 1.5: reference 3.0
ctx = dict(L=1.0, g=g, dx=0.03, surge=table, mps=([0.0, 2.0], [1.0, 2.0]))
m = dict(sp.metrics_dambreak({"x": [0.015, 1.2, 3.315]}, t, ctx))
check("front: max x less half a spacing (PySPH's wall face)", close(m["front"], 3.3), m)
check("front against the reference at T", close(m["front_ref"], 3.0) and
      close(m["front_err"], 0.1), m)
check("front_mps against its own table", close(m["front_mps_ref"], 1.75), m)
m = dict(sp.metrics_dambreak({"x": [2.0]}, 10.0, ctx))
check("past the table: no error", math.isnan(m["front_err"]) and m["front"] == 1.985, m)

# Taylor-Green: the exact field scaled by 1.02 everywhere: l1 = decay_err = 0.02.
U, Re, tt = 1.0, 100.0, 0.3
k = 2 * math.pi
amp = U * math.exp(-2 * (U / Re) * k * k * tt)
n = 16
xs = [(i + 0.5) / n for i in range(n) for _ in range(n)]
ys = [(j + 0.5) / n for _ in range(n) for j in range(n)]
us = [-1.02 * amp * math.cos(k * x) * math.sin(k * y) for x, y in zip(xs, ys)]
vs = [1.02 * amp * math.sin(k * x) * math.cos(k * y) for x, y in zip(xs, ys)]
m = dict(sp.metrics_taylor_green({"x": xs, "y": ys, "u": us, "v": vs, "m": [1.0 / n / n] *
                                  (n * n)}, tt, dict(U=U, L=1.0, Re=Re)))
check("taylor_green l1 of a 2% faster field", close(m["l1"], 0.02, 1e-9), m)
check("taylor_green decay reference", close(m["decay_ref"], amp), m)
lattice_max = max(math.hypot(math.cos(k * x) * math.sin(k * y), math.sin(k * x) *
                             math.cos(k * y)) for x, y in zip(xs, ys))
check("taylor_green decay error: the lattice's largest speed, 2% fast",
      close(m["decay_err"], 1.02 * lattice_max - 1.0, 1e-9), m)
check("taylor_green mass", close(m["mass"], 1.0), m)
m = dict(sp.metrics_elliptical_drop({"y": [-1.5, 0.5], "rho": [1.01, 0.98]}, 0.0,
                                    dict(ro=1.0)))
check("elliptical_drop b_tip, y2, drho", close(m["b_tip"], 1.5) and close(m["y2"], 1.25) and
      close(m["drho"], 0.02), m)

# The cavity: nx and Re map; on a linear field the fit is exact, so the samples at Ghia's points
# are the field there; a second output averages with the first (window L/U = 1).
cv = sp.case_of("examples/cavity.sph")
args, cctx, skipped = sp.pysph_args(cv, [("nx", "20"), ("kernel", "WendlandQuintic")],
                                   [("Re", "100")])
check("cavity: nx and Re map", args == ["--re", "100.0", "--nx", "20"] and cctx["nx"] == 20.0 and
      skipped == ["kernel"], (args, skipped))
ghia = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(
    __file__)))), "data")  # tests/data
cctx.update(ghia_u=sp.read_table(os.path.join(ghia, "ghia1982_re100_u.csv"), "u"),
           ghia_v=sp.read_table(os.path.join(ghia, "ghia1982_re100_v.csv"), "v"))
n = 20
xs = [(i + 0.5) / n for i in range(n) for _ in range(n)]
ys = [(j + 0.5) / n for _ in range(n) for j in range(n)]
def field(c):
    return {"x": xs, "y": ys, "u": [c * (y - 0.5) for y in ys], "v": [c * (x - 0.5) for x in xs],
            "m": [1.0 / n / n] * (n * n)}
def expect(c):
    out = {}
    for name, tab in (("u", cctx["ghia_u"]), ("v", cctx["ghia_v"])):
        e = [c * (s - 0.5) - r for s, r in zip(*tab) if 0 < s < 1]
        out[name + "_max"] = max(abs(v) for v in e)
        out[name + "_rms"] = math.sqrt(sum(v * v for v in e) / len(e))
    return out
m = dict(sp.metrics_cavity(field(0.4), 0.0, cctx))
want = expect(0.4)
check("cavity: Ghia's centre lines without the wall rows, exact on a linear field",
      all(close(m[k], want[k], 1e-9) for k in want), (m, want))
check("cavity: ke", close(m["ke"], sum(0.5 / n / n * 0.16 * ((x - 0.5) ** 2 + (y - 0.5) ** 2)
                                      for x, y in zip(xs, ys)), 1e-12), m)
m = dict(sp.metrics_cavity(field(0.2), 0.5, cctx))
want = expect(0.3)  # the mean of the two outputs' samples
check("cavity: averaged over the outputs of the last L/U",
      all(close(m[k], want[k], 1e-9) for k in want), (m, want))
m = dict(sp.metrics_cavity(field(0.2), 2.0, cctx))
check("cavity: outputs older than L/U leave the average",
      all(close(m[k], expect(0.2)[k], 1e-9) for k in want), m)

# ---- a synthetic PySPH output through the metric file the study reads ---------------------
outputs = {"f0": (0.0, 0, 1e-3, {"x": [0.015, 0.985]}),
           "f2": (t, 200, 1e-3, {"x": [0.015, 3.315]}),
           "f1": (0.5 * t, 100, 1e-3, {"x": [0.015, 2.0]})}
rows = sp.metric_rows(db, ctx, sorted(outputs), lambda f: outputs[f])
check("rows in time order", [r[0] for r in rows] == [0, 100, 200])
tmp = os.environ.get("TMPDIR", "/tmp")
mfile = os.path.join(tmp, "study_pysph_check_%d.csv" % os.getpid())
sp.write_metrics(mfile, rows, 2.5, 1.25)
read = study.read_metric_file(mfile)
check("front_err: last value and largest magnitude", close(read["front_err"][0], 0.1) and
      close(read["front_err"][1], 1.985 / 1.75 - 1.0), read["front_err"])
with open(mfile) as f:
    head = f.readline().strip()
    last = f.readlines()[-1]
check("solver's metric-file header", head == "step,t,dt,wall_s,cpu_s,front,front_ref,front_err,"
      "front_mps,front_mps_ref,front_mps_err", head)
check("time loop's totals on the last row", last.split(",")[3:5] == ["2.5", "1.25"], last)
os.remove(mfile)

# ---- the comparison of the two codes -------------------------------------------------------
lv = study.error_levels(0.031, 0.2)
check("error levels 1-1.5-2-3-5-7", [round(v, 6) for v in lv] == [0.2, 0.15, 0.1, 0.07, 0.05],
      lv)
variants = [(("0.06", "sphc"), {}), (("0.03", "sphc"), {}), (("0.06", "pysph"), {}),
            (("0.03", "pysph"), {})]
pts = [(1.0, 0.09), (8.0, 0.04), (3.0, 0.06), (20.0, 0.035)]
lines = study.compare_codes("e", pts, variants, ["dx"])
check("comparison at 0.1: both at dx=0.06, ratio 3", any(
    "<= 0.1 " in l and "ratio 3" in l for l in lines), lines)
check("comparison at 0.07: sphc dx=0.03 against PySPH dx=0.06, ratio 0.375",
      any("<= 0.07" in l and "dx=0.03" in l and "ratio 0.375" in l for l in lines), lines)
check("comparison at 0.05: ratio 2.5", any("<= 0.05" in l and "ratio 2.5" in l
                                           for l in lines), lines)
check("no level below both", not any("<= 0.03" in l for l in lines), lines)

# ---- PySPH's own file format (needs PySPH) -------------------------------------------------
if len(sys.argv) > 3 and sys.argv[2] == "--pysph-file":
    from pysph.base.utils import get_particle_array
    from pysph.solver.utils import dump
    fluid = get_particle_array(name="fluid", x=[0.1, 0.7], y=[0.2, 0.4], u=[1.0, 2.0],
                               v=[0.5, 0.0], m=[1.0, 1.0], rho=[1000.0, 1010.0])
    path = os.path.join(sys.argv[3], "synthetic_00042.hdf5")
    dump(path, [fluid], dict(t=0.25, dt=1e-3, count=42))
    t, step, dt, a = sp.load_arrays(path)
    check("PySPH file: t, count, dt", (t, step, dt) == (0.25, 42, 1e-3), (t, step, dt))
    check("PySPH file: arrays", a["x"] == [0.1, 0.7] and a["rho"] == [1000.0, 1010.0], a)
sys.stdout.write("all checks passed\n")
