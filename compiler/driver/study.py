#!/usr/bin/env python3
"""sphc study: what accuracy costs in time (docs/accuracy-cost.md).

    sphc study SCENE.sph --vary NAME=v1,v2,... [--vary ...] [--tf T] [--repeat N]
               [--threads N] [--set NAME=V ...] [--budget METRIC<=VALUE ...]
               [--metric COLUMN ...] [--cost wall_s|cpu_s] [--resolution NAME] [--pysph] -o DIR

Builds and runs the cross product of the variants and collects, per run, the particles,
steps, wall and CPU seconds of the time loop, the peak memory and every metric of the scene
(its `metrics { }`). A varied NAME is

  - backend, precision or kernel: sphc's --backend / --precision / --kernel (a rebuild,
    through sphc's build cache);
  - a compile-time option of the scene (`option NAME in [...]`): sphc -D NAME=v (a rebuild,
    through the cache);
  - threads: the solver's --threads, for the variants built for OpenMP (the only backend
    with threads); the others run once, shown with threads "-";
  - otherwise a parameter of the scene: the solver's --set NAME=v (no rebuild).

Output in DIR: study.csv (one row per run; a study started again with the same DIR reuses the
runs already in it), summary.txt (the runs, the Pareto front of each metric against the cost,
the cheapest variant within each error level, the observed convergence orders, and the
answers to --budget), and, where matplotlib is installed, for each metric M
M_vs_wall.{png,svg} (M_vs_cpu with --cost cpu_s; log-log, the Pareto front marked, every
point labelled with its variant) and M_convergence.{png,svg} (M against the resolution
parameter, with the fitted order). The cost is the time loop's wall time, or with --cost
cpu_s its CPU time (on a loaded machine the wall time measures the load as much as the run).

With --pysph, PySPH's matching example runs at the same resolutions (study_pysph.py); its
rows have code = pysph, and the summary and plots show each code's Pareto front and, for each
error level reached by both, the cheapest variant of each and the ratio of their costs.

Per run and metric column C of the solver's metric file, study.csv has C (its value at the
last output where it is finite) and C_max (the largest |C| over the outputs). The error of a
compared metric is its column NAME_err; a plot or budget names any column (e.g. l1,
front_err_max).

Why a Python helper beside sphc and not C++ in the driver: the study is process management,
CSV handling and plotting, and the plots need matplotlib, as the validation plots do; the
helper needs nothing else but the standard library (the fits are written out). `sphc study
...` runs it with python3 ($SPHC_PYTHON if set), from share/sphc/study.py of the install or
build tree (compiler/driver/Study.cpp).
"""

import argparse
import csv
import itertools
import math
import os
import re
import shlex
import subprocess
import threading
import sys
import time

COST = "wall_s"  # --cost
SPHC_FLAGS = {"backend": "--backend", "precision": "--precision", "kernel": "--kernel"}
# The backends whose solvers take --threads (the OpenMP one; a serial or OpenCL solver refuses
# the option: runtime/src/solver.cpp). sphc's default backend is serial.
THREADED_BACKENDS = ("openmp",)
DEFAULT_BACKEND = "serial"


def fail(msg, code=2):
    sys.stderr.write("sphc study: error: %s\n" % msg)
    sys.exit(code)


def parse_args(argv):
    ap = argparse.ArgumentParser(prog="sphc study", description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", help="the .sph scene")
    ap.add_argument("--vary", action="append", default=[], metavar="NAME=v1,v2,...",
                    help="a variable and its values (repeatable; the runs are the cross "
                         "product)")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=V",
                    help="a parameter fixed for every run")
    ap.add_argument("-D", action="append", default=[], dest="defines", metavar="NAME=CHOICE",
                    help="a compile-time option fixed for every run")
    ap.add_argument("--tf", type=float, help="final time of every run")
    ap.add_argument("--repeat", type=int, default=1, help="runs per variant (default 1; the "
                    "summary takes the fastest wall time)")
    ap.add_argument("--threads", type=int, help="threads of every run built for OpenMP "
                    "(--vary backend=openmp); the other solvers run on one thread")
    ap.add_argument("--budget", action="append", default=[], metavar="METRIC<=VALUE",
                    help="the cheapest variant with METRIC <= VALUE, and how far the others "
                         "miss it")
    ap.add_argument("--metric", action="append", default=[], metavar="COLUMN",
                    help="analyse and plot only these columns of the metrics (repeatable; "
                         "default: every column)")
    ap.add_argument("--cost", choices=("wall_s", "cpu_s"), default="wall_s",
                    help="the cost the fronts, levels and budgets use: the time loop's wall "
                         "seconds (default) or its CPU seconds (fairer on a loaded machine)")
    ap.add_argument("--resolution", help="the varied parameter the convergence plot and the "
                    "orders use (default: the first varied parameter whose values are "
                    "numbers)")
    ap.add_argument("--pysph", action="store_true", help="also run PySPH's matching example "
                    "(where the scene has one and PySPH is installed) at the same resolutions "
                    "and put its points on the same CSV, summary and plots")
    ap.add_argument("--pysph-python", default=os.environ.get("SPHC_PYSPH_PYTHON"),
                    help="the Python that has PySPH (default: the first of python3 and "
                         "/usr/bin/python3 that imports it)")
    ap.add_argument("--progress-every", type=float, default=10.0, metavar="S",
                    help="while a run goes on, how far it is (its t, percent and ETA, from "
                         "the solver's progress line) every S seconds of wall time (default "
                         "10; 0: every new progress line)")
    ap.add_argument("-o", "--output", required=True, help="the study's directory")
    ap.add_argument("--sphc", default=os.environ.get("SPHC", "sphc"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.repeat < 1:
        fail("--repeat expects a positive number")
    varies = []
    for v in args.vary:
        m = re.match(r"^([A-Za-z_][A-Za-z0-9_]*)=(.+)$", v)
        if not m:
            fail("--vary %s: expected NAME=v1,v2,..." % v)
        values = [x.strip() for x in m.group(2).split(",") if x.strip()]
        if not values:
            fail("--vary %s: no values" % v)
        if m.group(1) in [n for n, _ in varies]:
            fail("--vary %s: %s is varied twice" % (v, m.group(1)))
        varies.append((m.group(1), values))
    if not varies:
        fail("nothing to vary: give --vary NAME=v1,v2,...")
    budgets = []
    for b in args.budget:
        m = re.match(r"^([A-Za-z_][A-Za-z0-9_]*)\s*<=\s*(\S+)$", b)
        if not m:
            fail("--budget %s: expected METRIC<=VALUE" % b)
        budgets.append((m.group(1), float(m.group(2))))
    return args, varies, budgets


# ---- the scene's solver: what it can vary ------------------------------------------------

def solver_help(exe):
    """(compile-time options {name: choices}, parameters [names]) from the solver's --help."""
    out = subprocess.run([exe, "--help"], capture_output=True, text=True).stdout
    options, params, section = {}, [], None
    for line in out.splitlines():
        if line.startswith("compile-time options"):
            section = "options"
            continue
        if line.startswith("parameters"):
            section = "params"
            continue
        if not line.startswith("  "):
            section = None if line.strip() == "" and section is None else section
            continue
        m = re.match(r"^  ([A-Za-z_][A-Za-z0-9_]*)", line)
        if not m:
            continue
        if section == "options":
            c = re.search(r"choices: ([^)]*)\)", line)
            options[m.group(1)] = [x.strip() for x in c.group(1).split(",")] if c else []
        elif section == "params":
            params.append(m.group(1))
    return options, params


def classify(varies, options, params):
    kinds = {}
    for name, values in varies:
        if name in SPHC_FLAGS and name not in options:
            kinds[name] = "sphc"
        elif name == "threads":
            kinds[name] = "threads"
        elif name in options:
            bad = [v for v in values if options[name] and v not in options[name]]
            if bad:
                fail("--vary %s: %s not among the choices %s" % (name, ", ".join(bad),
                                                                  ", ".join(options[name])))
            kinds[name] = "option"
        elif name in params:
            for v in values:
                try:
                    float(v)
                except ValueError:
                    fail("--vary %s: parameter values are numbers, not '%s'" % (name, v))
            kinds[name] = "param"
        else:
            fail("--vary %s: not a parameter (%s), a compile-time option (%s), backend, "
                 "precision, kernel or threads" % (name, ", ".join(params) or "none",
                                                   ", ".join(options) or "none"))
    return kinds


# ---- runs --------------------------------------------------------------------------------

def takes_threads(variant, kinds):
    """Whether the solver of a variant takes --threads: built for an OpenMP backend."""
    backend = next((v for n, v in variant if n == "backend" and kinds.get(n) == "sphc"),
                   DEFAULT_BACKEND)
    return backend in THREADED_BACKENDS


def thread_runs(runs, kinds, fixed_threads):
    """The runs with threads only where they apply: a varied `threads` of a variant whose
    solver runs on one thread (not OpenMP) is shown as "-" and that variant is run once, not
    once per thread count. Warns when --threads or a varied threads applies to no run."""
    varied = "threads" in kinds.values()
    out, seen = [], set()
    for variant, rep in runs:
        if varied and not takes_threads(variant, kinds):
            variant = [(n, "-" if kinds.get(n) == "threads" else v) for n, v in variant]
        key = (tuple(variant), rep)
        if key not in seen:
            seen.add(key)
            out.append((variant, rep))
    if (fixed_threads is not None or varied) and \
            not any(takes_threads(v, kinds) for v, _ in out):
        what = "--threads %d" % fixed_threads if fixed_threads is not None else \
            "--vary threads"
        sys.stderr.write("sphc study: %s: no variant is built for a multi-threaded backend "
                         "(%s; --vary backend=openmp): every run is on one thread\n"
                         % (what, ", ".join(THREADED_BACKENDS)))
    return out


def build(args, variant, kinds, bindir, cache):
    """The solver of a variant's compile-time settings (built once per study, through sphc's
    build cache)."""
    flags = []
    for d in args.defines:
        flags += ["-D", d]
    for name, value in variant:
        if kinds.get(name) == "sphc":
            flags.append("%s=%s" % (SPHC_FLAGS[name], value))
        elif kinds.get(name) == "option":
            flags += ["-D", "%s=%s" % (name, value)]
    key = "_".join(re.sub(r"[^A-Za-z0-9.=-]", "", f) for f in flags if f != "-D") or "base"
    if key in cache:
        return cache[key]
    exe = os.path.join(bindir, "solver_" + key)
    cmd = [args.sphc, args.scene] + flags + ["-o", exe]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        fail("building %s failed:\n%s%s" % (" ".join(map(shlex.quote, cmd)), r.stdout,
                                               r.stderr), 1)
    cache[key] = exe
    return exe


def read_metric_file(path):
    """{column: (last finite value, largest |value|)} of a solver's metric file."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    out = {}
    if not rows:
        return out
    for col in rows[0].keys():
        if col in ("step", "t", "dt", "wall_s", "cpu_s"):
            continue
        vals = []
        for r in rows:
            try:
                vals.append(float(r[col]))
            except ValueError:
                pass
        finite = [v for v in vals if math.isfinite(v)]
        out[col] = (finite[-1] if finite else float("nan"),
                    max(abs(v) for v in finite) if finite else float("nan"))
    return out


def run_one(args, exe, variant, kinds, rundir):
    os.makedirs(rundir, exist_ok=True)
    mfile = os.path.join(rundir, "metrics.csv")
    cmd = [exe, "--timing", "--no-output", "--metrics", mfile]
    if args.tf is not None:
        cmd += ["--tf", repr(args.tf)]
    threaded = takes_threads(variant, kinds)
    if args.threads is not None and threaded:
        cmd += ["--threads", str(args.threads)]
    for s in args.set:
        cmd += ["--set", s]
    for name, value in variant:
        if kinds.get(name) == "param":
            cmd += ["--set", "%s=%s" % (name, value)]
        elif kinds.get(name) == "threads" and threaded:
            cmd += ["--threads", value]
    start = time.time()
    with open(os.path.join(rundir, "stdout.txt"), "w") as so, \
            open(os.path.join(rundir, "stderr.txt"), "w") as se:
        p = subprocess.Popen(cmd, stdout=so, stderr=se)
        status, usage = wait_reporting(p, os.path.join(rundir, "stderr.txt"),
                                       args.progress_every)
    elapsed = time.time() - start
    code = os.waitstatus_to_exitcode(status) if hasattr(os, "waitstatus_to_exitcode") else status
    row = {"status": "ok" if code == 0 else "exit %d" % code,
           "process_s": "%.6g" % elapsed,
           "peak_rss_mb": "%.4g" % (usage.ru_maxrss / 1024.0),
           "command": " ".join(map(shlex.quote, cmd))}
    parse_run(row, os.path.join(rundir, "stdout.txt"), mfile)
    return row


# The solver's progress line (on stderr when that is not a terminal):
#   t=0.0600/0.2000  step 132  dt=0.00045  particles 2500  30.0% ETA 0m02s  ...
PROGRESS_LINE = re.compile(r"^t=(\S+)/(\S+)\s.*?\s(\d+(?:\.\d+)?)% ETA (\S+)")


def last_progress(path):
    """(t, tf, percent, ETA) of the last progress line the solver wrote to path, or None."""
    try:
        with open(path, "rb") as f:
            f.seek(0, os.SEEK_END)
            f.seek(max(0, f.tell() - 4096))
            lines = f.read().decode("utf-8", "replace").splitlines()
    except OSError:
        return None
    for line in reversed(lines):
        m = PROGRESS_LINE.match(line)
        if m:
            return m.groups()
    return None


def wait_reporting(p, stderr_path, every):
    """Waits for the solver p while a second thread says how far it is, every `every` seconds
    (0: each new progress line). Returns (wait status, resource usage) as os.wait4 does."""
    done = threading.Event()

    def report():
        said = None
        while not done.wait(max(every, 0.05)):
            now = last_progress(stderr_path)
            if now and now != said:
                sys.stderr.write("    t=%s of %s (%s%%, this run's ETA %s)\n" % now)
                sys.stderr.flush()
                said = now

    reporter = threading.Thread(target=report, daemon=True)
    reporter.start()
    try:
        _, status, usage = os.wait4(p.pid, 0)
    finally:
        done.set()
        reporter.join()
    return status, usage


def parse_run(row, stdout_path, mfile):
    """The `timing:` and `metrics:` lines of a run's output and its metric file, into row."""
    with open(stdout_path) as f:
        text = f.read()
    m = re.search(r"^timing: steps=(\d+) particles=(\d+) wall_s=(\S+)", text, re.M)
    if m:
        row.update(steps=m.group(1), particles=m.group(2), wall_s=m.group(3))
    m = re.search(r"^metrics: t=(\S+) step=\S+ wall_s=\S+ cpu_s=(\S+)", text, re.M)
    if m:
        row.update(t_end=m.group(1), cpu_s=m.group(2))
    if os.path.exists(mfile):
        for col, (last, biggest) in read_metric_file(mfile).items():
            row[col] = repr(last)
            row[col + "_max"] = repr(biggest)


def find_pysph_python(args):
    """The Python that imports pysph (--pysph-python, else python3, else /usr/bin/python3)."""
    cands = [args.pysph_python] if args.pysph_python else ["python3", "/usr/bin/python3"]
    for c in cands:
        try:
            if subprocess.run([c, "-c", "import pysph"], capture_output=True).returncode == 0:
                return c
        except OSError:
            pass
    return None


def run_pysph(args, python, case_name, pargs, ctx, times, rundir):
    """One run of PySPH's example (study_pysph.py's driver): the row of the study's CSV."""
    import json
    os.makedirs(rundir, exist_ok=True)
    mfile = os.path.join(rundir, "metrics.csv")
    # The scene's end time where the study gives none (the last time of the sphc run's metric
    # file): PySPH's examples have their own (the dam break's 2.5 s, against the scene's 1 s).
    tf = args.tf if args.tf is not None else (max(times) if times else None)
    spec = {"case": case_name, "args": pargs, "ctx": ctx, "tf": tf, "times": times,
            "outdir": os.path.join(rundir, "pysph_out"), "metrics_file": mfile,
            "scene_dir": os.path.dirname(os.path.abspath(args.scene)),
            "threads": args.threads}
    with open(os.path.join(rundir, "spec.json"), "w") as f:
        json.dump(spec, f, indent=1)
    driver = os.path.join(os.path.dirname(os.path.abspath(__file__)), "study_pysph.py")
    cmd = [python, driver, "run", os.path.join(rundir, "spec.json")]
    env = dict(os.environ)
    # libgomp's default spin-wait makes PySPH's OpenMP runs many times slower on a shared
    # machine (docs/accuracy-cost.md): wait passively; serial unless --threads.
    env["OMP_WAIT_POLICY"] = "passive"
    env["OMP_NUM_THREADS"] = str(args.threads or 1)
    start = time.time()
    with open(os.path.join(rundir, "stdout.txt"), "w") as so, \
            open(os.path.join(rundir, "stderr.txt"), "w") as se:
        p = subprocess.Popen(cmd, stdout=so, stderr=se, env=env)
        _, status, usage = os.wait4(p.pid, 0)
    code = os.waitstatus_to_exitcode(status) if hasattr(os, "waitstatus_to_exitcode") else status
    row = {"status": "ok" if code == 0 else "exit %d" % code,
           "process_s": "%.6g" % (time.time() - start),
           "peak_rss_mb": "%.4g" % (usage.ru_maxrss / 1024.0),
           "command": "PySPH " + case_name + " " + " ".join(map(shlex.quote, pargs))}
    parse_run(row, os.path.join(rundir, "stdout.txt"), mfile)
    return row


def metric_times(path):
    """The output times of a metric file (where PySPH is asked for output)."""
    try:
        with open(path, newline="") as f:
            return sorted({float(r["t"]) for r in csv.DictReader(f)})
    except (OSError, KeyError, ValueError):
        return []


def pysph_runs(args, names, runs, rows, out, csv_path, fixed):
    """--pysph: PySPH's matching example for each distinct mapped variant (and repeat) not in
    rows yet; appends to rows."""
    import study_pysph as sp
    case = sp.case_of(args.scene)
    stem = os.path.splitext(os.path.basename(args.scene))[0]
    if case is None:
        sys.stderr.write("sphc study: --pysph: %s has no PySPH counterpart (the cases: %s); "
                         "no PySPH runs\n" % (stem, ", ".join(sorted(sp.CASES))))
        return
    python = find_pysph_python(args)
    if python is None:
        sys.stderr.write("sphc study: --pysph: no Python here imports pysph (PySPH 1.0b1: "
                         "Debian python3-pysph; or --pysph-python): no PySPH runs\n")
        return
    fixed_sets = [tuple(x.split("=", 1)) for x in args.set if "=" in x]
    todo, seen = [], set()
    for variant, rep in runs:
        mapped = sp.pysph_args(case, variant, fixed_sets)
        if mapped is None:
            continue
        pargs, ctx, skipped = mapped
        key = (sp.pysph_key(pargs), rep)
        if key in seen:
            continue
        seen.add(key)
        shown = [(n, "-" if n in skipped else v) for n, v in variant]
        todo.append((shown, rep, pargs, ctx, variant))
    done = {(tuple(r.get(n, "") for n in names), r.get("repeat")) for r in rows
            if r.get("code") == "pysph"}
    todo = [t for t in todo if (tuple(v for _, v in t[0]), str(t[1])) not in done]
    started = time.time()
    for k, (shown, rep, pargs, ctx, variant) in enumerate(todo):
        eta = fmt_s((time.time() - started) / k * (len(todo) - k)) if k else "?"
        sys.stderr.write("[PySPH %d/%d] %s  %s  (ETA %s)\n" % (
            k + 1, len(todo), stem, " ".join(pargs), eta))
        sphc_dir = os.path.join(out, "runs", run_dir_name(variant) + "_r0")
        times = metric_times(os.path.join(sphc_dir, "metrics.csv"))
        if not times:
            every = case["every"]
            tf = args.tf if args.tf is not None else 1.0
            times = [i * every for i in range(int(tf / every + 1e-9) + 1)]
        rundir = os.path.join(out, "runs", "pysph_" + run_dir_name(shown) + "_r%d" % rep)
        row = dict(shown)
        row.update(code="pysph", repeat=str(rep))
        row.update(run_pysph(args, python, os.path.basename(os.path.splitext(
            args.scene)[0]), pargs, ctx, times, rundir))
        sys.stderr.write("  %s\n" % ("wall %s s, %s particles, %s steps" % (
            row.get("wall_s", "?"), row.get("particles", "?"), row.get("steps", "?"))
            if row["status"] == "ok" else "%s (see %s)" % (row["status"], rundir)))
        rows.append(row)
        write_rows(csv_path, rows, fixed)


def run_dir_name(variant):
    return re.sub(r"[^A-Za-z0-9.=_-]", "_", "_".join("%s=%s" % nv for nv in variant))


def variant_label(variant):
    return " ".join("%s=%s" % nv for nv in variant if nv[1] != "-")


def label(names, key):
    """A variant's label; key is its values and the code (per_variant)."""
    return ("PySPH " if key[-1] == "pysph" else "") + variant_label(zip(names, key))


def load_done(path):
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def write_rows(path, rows, fixed):
    cols = list(fixed)
    for r in rows:
        for c in r:
            if c not in cols:
                cols.append(c)
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols, restval="")
        w.writeheader()
        for r in rows:
            w.writerow(r)
    os.replace(tmp, path)


def fmt_s(s):
    s = max(0, int(round(s)))
    return "%dh%02dm" % (s // 3600, s // 60 % 60) if s >= 3600 else "%dm%02ds" % (s // 60, s % 60)


# ---- analysis ----------------------------------------------------------------------------

def num(r, c):
    try:
        v = float(r.get(c, ""))
    except ValueError:
        return float("nan")
    return v


def per_variant(rows, names):
    """One entry per variant: its label, values, the fastest wall time of its repeats, the
    CPU time of that run and its metrics."""
    groups = {}
    for r in rows:
        if r.get("status") != "ok":
            continue
        key = tuple(r[n] for n in names) + (r.get("code") or "sphc",)
        best = groups.get(key)
        if best is None or num(r, COST) < num(best, COST):
            groups[key] = r
    return [(key, groups[key]) for key in sorted(groups, key=lambda k: num(groups[k], COST))]


def metric_columns(rows, fixed):
    cols = []
    for r in rows:
        for c in r:
            if c not in fixed and c not in cols:
                cols.append(c)
    return cols


def pareto(points):
    """Indices of the points (cost, error) no other point beats in both (sorted by cost)."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], float("inf")
    for i in order:
        e = points[i][1]
        if math.isfinite(e) and e < best:
            front.append(i)
            best = e
    return front


def fit_order(xs, ys):
    """Least-squares slope and intercept of log y against log x (None with < 2 points)."""
    pts = [(math.log(x), math.log(y)) for x, y in zip(xs, ys)
           if x > 0 and y > 0 and math.isfinite(y)]
    if len(pts) < 2:
        return None
    n = len(pts)
    mx = sum(p[0] for p in pts) / n
    my = sum(p[1] for p in pts) / n
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    if sxx == 0:
        return None
    slope = sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx
    return slope, my - slope * mx


def error_levels(lo, hi):
    """The error levels 1, 1.5, 2, 3, 5, 7 x 10^k between lo and the first level >= hi,
    largest first."""
    out = []
    for k in range(math.floor(math.log10(lo)), math.ceil(math.log10(hi)) + 1):
        out += [m * 10.0 ** k for m in (1, 1.5, 2, 3, 5, 7)]
    out = [v for v in out if v >= lo]
    above = [v for v in out if v >= hi]
    return sorted([v for v in out if v < hi] + above[:1], reverse=True)


def compare_codes(c, pts, variants, names):
    """Lines: for each error level (1, 1.5, 2, 3, 5, 7 x 10^k) reached by both sphc and PySPH,
    the cheapest variant of each and the ratio of their costs."""
    out = ["  sphc against PySPH: the cheapest variant of each code within each error level "
           "reached by both, and PySPH's cost / sphc's:"]
    finite = [e for _, e in pts if math.isfinite(e) and e > 0]
    n = 0
    for level in error_levels(min(finite), max(finite)):
        best = {}
        for code in ("sphc", "pysph"):
            ok = [i for i, (k, _) in enumerate(variants) if k[-1] == code and pts[i][1] <= level]
            if ok:
                best[code] = min(ok, key=lambda j: pts[j][0])
        if len(best) < 2:
            continue
        i, j = best["sphc"], best["pysph"]
        n += 1
        out.append("    |%s| <= %-6.2g sphc: %-24s %8.4g s  PySPH: %-24s %8.4g s  ratio %.3g"
                   % (c, level, label(names, variants[i][0]), pts[i][0],
                      label(names, variants[j][0])[6:], pts[j][0], pts[j][0] / pts[i][0]))
    if n == 0:
        out.append("    none: no error level is reached by both codes")
    return out


def analyse(rows, names, kinds, resolution, budgets, fixed, outdir, only=()):
    variants = per_variant(rows, names)
    cols = [c for c in metric_columns(rows, fixed) if c not in names]
    if only:
        missing = [c for c in only if c not in cols]
        if missing:
            fail("--metric %s: no such column; the columns are %s"
                 % (", ".join(missing), ", ".join(cols)))
        cols = list(only)
    lines = []
    p = lines.append
    p("sphc study: %d runs, %d variants (%s)" % (len(rows), len(variants), ", ".join(names)))
    p("wall_s, cpu_s: the time loop's wall and CPU seconds; cost: %s (of each variant, the "
      "repeat with the least)" % COST)
    p("")
    head = ["variant", "particles", "steps", "wall_s", "cpu_s", "peak_rss_mb"] + cols
    table = [[label(names, k), r.get("particles", ""), r.get("steps", ""),
              r.get("wall_s", ""), r.get("cpu_s", ""), r.get("peak_rss_mb", "")] +
             ["%.4g" % num(r, c) for c in cols] for k, r in variants]
    widths = [max(len(str(x)) for x in col) for col in zip(head, *table)] if table else []
    for row in [head] + table:
        p("  ".join(str(x).rjust(w) for x, w in zip(row, widths)))
    for r in rows:
        if r.get("code") == "pysph" and r.get("status") != "ok":
            p("PySPH run failed (%s): %s" % (r.get("status"), r.get("command")))
    p("")
    fronts = {}
    codes = sorted({k[-1] for k, _ in variants}, key=lambda c: c != "sphc")
    for c in cols:
        pts = [(num(r, COST), abs(num(r, c))) for _, r in variants]
        if not any(math.isfinite(e) for _, e in pts):
            continue
        fronts[c] = {}
        for code in codes:
            mine = [i for i, (k, _) in enumerate(variants) if k[-1] == code]
            front = [mine[j] for j in pareto([pts[i] for i in mine])]
            fronts[c][code] = front
            p("%s against %s: %sPareto front (no variant is both cheaper and more accurate):"
              % (c, COST, "PySPH's " if code == "pysph" else "sphc's " if len(codes) > 1
                 else ""))
            for i in front:
                p("  %-40s cost %8.4g s  |%s| %.4g" % (label(names, variants[i][0]),
                                                     pts[i][0], c, pts[i][1]))
        finite = sorted(e for _, e in pts if math.isfinite(e) and e > 0)
        if finite and len(codes) == 1:
            lo = math.floor(math.log10(finite[0]))
            hi = math.ceil(math.log10(finite[-1]))
            p("  cheapest variant within each error level:")
            for k in range(hi, lo - 1, -1):
                level = 10.0 ** k
                ok = [i for i in range(len(pts)) if pts[i][1] <= level]
                if not ok:
                    p("    |%s| <= %-8.0e none" % (c, level))
                    continue
                i = min(ok, key=lambda j: pts[j][0])
                p("    |%s| <= %-8.0e %s (cost %.4g s)" % (c, level, label(
                    names, variants[i][0]), pts[i][0]))
        elif finite:
            for code_line in compare_codes(c, pts, variants, names):
                p(code_line)
        p("")
    orders = {}
    if resolution:
        others = [n for n in names if n != resolution]
        for c in cols:
            groups = {}
            for k, r in variants:
                key = tuple(r[n] for n in others) + (k[-1],)
                groups.setdefault(key, []).append((float(r[resolution]), abs(num(r, c))))
            for key, pts in groups.items():
                f = fit_order([x for x, _ in pts], [y for _, y in pts])
                if f is None:
                    continue
                orders[(c, key)] = (f, pts)
        if orders:
            p("observed orders: the slope s of log|metric| against log %s (|metric| ~ %s^s; "
              "s = -p for a count per length such as nx, s = p for a spacing such as dx)"
              % (resolution, resolution))
            for (c, key), ((s, _), pts) in sorted(orders.items()):
                p("  %-16s %-30s s = %+.3g over %s = %s" % (
                    c, label(others, key) or ("sphc" if len(codes) > 1 else "(all)"), s,
                    resolution,
                    ", ".join("%g" % x for x, _ in sorted(pts))))
            p("")
    for metric, limit in budgets:
        p("budget %s <= %g:" % (metric, limit))
        if metric not in cols:
            p("  no such column; columns: %s" % ", ".join(cols))
            continue
        meets = [(num(r, COST), k, r) for k, r in variants if abs(num(r, metric)) <= limit]
        if meets:
            w, k, r = min(meets)
            p("  cheapest: %s (cost %.4g s, |%s| = %.4g)" % (label(names, k), w,
                                                           metric, abs(num(r, metric))))
        else:
            p("  no variant measured meets it")
        for k, r in variants:
            v = abs(num(r, metric))
            if not v <= limit:
                p("  misses: %-40s |%s| = %.4g, %.3g x the budget (cost %.4g s)"
                  % (label(names, k), metric, v, v / limit if limit else
                     float("inf"), num(r, COST)))
        p("")
    text = "\n".join(lines) + "\n"
    with open(os.path.join(outdir, "summary.txt"), "w") as f:
        f.write(text)
    plot(variants, names, cols, fronts, orders, resolution, outdir)
    return text


def plot(variants, names, cols, fronts, orders, resolution, outdir):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        sys.stderr.write("sphc study: matplotlib is not installed: no plots (the CSV and "
                         "summary.txt are written)\n")
        return
    for c in cols:
        if c not in fronts:
            continue
        pts = [(num(r, COST), abs(num(r, c))) for _, r in variants]
        ok = [i for i, (w, e) in enumerate(pts) if w > 0 and e > 0 and math.isfinite(e)]
        if not ok:
            continue
        fig, ax = plt.subplots(figsize=(7, 5))
        fr = []
        for code, (mark, col, line) in (("sphc", ("o", "C0", "C3")),
                                        ("pysph", ("s", "C1", "C2"))):
            mine = [i for i in ok if variants[i][0][-1] == code]
            if not mine:
                continue
            name = "sphc" if code == "sphc" else "PySPH"
            ax.loglog([pts[i][0] for i in mine], [pts[i][1] for i in mine], mark, color=col,
                      label="%s variants" % name)
            f = [i for i in fronts[c].get(code, []) if i in ok]
            fr += f
            ax.loglog([pts[i][0] for i in f], [pts[i][1] for i in f], "-", color=line,
                      lw=1.5, label="%s Pareto front" % name)
        for i in ok:
            ax.annotate(label(names, variants[i][0]), pts[i], fontsize=7,
                        xytext=(4, 3), textcoords="offset points",
                        weight="bold" if i in fr else "normal")
        ax.set_xlabel("%s time of the time loop [s]" % ("wall" if COST == "wall_s" else "CPU"))
        ax.set_ylabel("|%s|" % c)
        ax.set_title("%s against %s" % (c, COST))
        ax.legend(fontsize=8)
        fig.tight_layout()
        for ext in ("png", "svg"):
            fig.savefig(os.path.join(outdir, "%s_vs_%s.%s" % (c, COST[:-2], ext)), dpi=120)
        plt.close(fig)
        mine = {k: v for k, v in orders.items() if k[0] == c}
        if not mine:
            continue
        fig, ax = plt.subplots(figsize=(7, 5))
        for n, ((_, key), ((s, b), pts2)) in enumerate(sorted(mine.items())):
            pts2 = sorted(pts2)
            xs = [x for x, _ in pts2]
            lbl = label([m for m in names if m != resolution], key) or c
            ax.loglog(xs, [y for _, y in pts2], "o", color="C%d" % n)
            ax.loglog(xs, [math.exp(b) * x ** s for x in xs], "--", color="C%d" % n,
                      label="%s: slope %+.2f" % (lbl, s))
        ax.set_xlabel(resolution)
        ax.set_ylabel("|%s|" % c)
        ax.set_title("convergence of %s (fitted slope)" % c)
        ax.legend(fontsize=8)
        fig.tight_layout()
        for ext in ("png", "svg"):
            fig.savefig(os.path.join(outdir, "%s_convergence.%s" % (c, ext)), dpi=120)
        plt.close(fig)


# ---- main --------------------------------------------------------------------------------

def main(argv):
    args, varies, budgets = parse_args(argv)
    global COST
    COST = args.cost
    if not os.path.exists(args.scene):
        fail("%s: no such file" % args.scene)
    out = args.output
    bindir = os.path.join(out, "bin")
    os.makedirs(bindir, exist_ok=True)
    names = [n for n, _ in varies]
    cache = {}
    base = build(args, [], {}, bindir, cache)
    options, params = solver_help(base)
    kinds = classify(varies, options, params)
    resolution = args.resolution
    if resolution is None:
        resolution = next((n for n, vals in varies if kinds[n] == "param"), None)
    elif resolution not in names:
        fail("--resolution %s: not a varied name" % resolution)
    runs = [(list(zip(names, combo)), rep) for combo in itertools.product(*[v for _, v in varies])
            for rep in range(args.repeat)]
    runs = thread_runs(runs, kinds, args.threads)
    fixed = names + ["code", "repeat", "status", "particles", "steps", "wall_s", "cpu_s", "t_end",
                     "peak_rss_mb", "process_s", "command"]
    csv_path = os.path.join(out, "study.csv")
    rows = load_done(csv_path)
    for r in rows:
        r["code"] = r.get("code") or "sphc"
    done = {(tuple(r.get(n, "") for n in names), r.get("repeat")) for r in rows
            if r.get("status") == "ok" and r["code"] == "sphc"}
    rows = [r for r in rows if r.get("status") == "ok"]
    todo = [(v, rep) for v, rep in runs if (tuple(x for _, x in v), str(rep)) not in done]
    if len(todo) < len(runs):
        sys.stderr.write("sphc study: %d of %d sphc runs already in %s; running the other %d\n"
                         % (len(runs) - len(todo), len(runs), csv_path, len(todo)))
    started = time.time()
    for k, (variant, rep) in enumerate(todo):
        eta = "?"
        if k > 0:
            eta = fmt_s((time.time() - started) / k * (len(todo) - k))
        sys.stderr.write("[%d/%d] %s%s  (ETA %s)\n" % (k + 1, len(todo), variant_label(variant),
                                                      " repeat %d" % rep if args.repeat > 1
                                                      else "", eta))
        exe = build(args, variant, kinds, bindir, cache)
        rundir = os.path.join(out, "runs", run_dir_name(variant) + "_r%d" % rep)
        row = dict(variant)
        row.update(code="sphc", repeat=str(rep))
        row.update(run_one(args, exe, variant, kinds, rundir))
        if row["status"] != "ok":
            sys.stderr.write("  %s: %s (see %s)\n" % (variant_label(variant), row["status"],
                                                      rundir))
        else:
            sys.stderr.write("  wall %s s, %s particles, %s steps\n"
                             % (row.get("wall_s", "?"), row.get("particles", "?"),
                                row.get("steps", "?")))
        rows.append(row)
        write_rows(csv_path, rows, fixed)  # after every run: an interrupted study resumes
    if args.pysph:
        pysph_runs(args, names, runs, rows, out, csv_path, fixed)
    write_rows(csv_path, rows, fixed)
    text = analyse(rows, names, kinds, resolution, budgets, fixed, out, args.metric)
    sys.stdout.write(text)
    failed = [r for r in rows if r.get("status") != "ok" and r.get("code") != "pysph"]
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
