"""Helpers shared by the benchmarks of bench/ (running commands and timing them, the machine's
description, the options of the sphc-against-PySPH scripts), and the one place where a
benchmark's PySPH set-up is shared with `sphc study --pysph` (compiler/driver/study_pysph.py:
how PySPH's dam_break_2d is made consistent at a dx other than its own)."""

import argparse
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_DX = 0.03

sys.path.insert(0, os.path.join(ROOT, "compiler", "driver"))
from study_pysph import scale_dambreak  # noqa: E402,F401  (shared with sphc study --pysph)


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown CPU"


def load_average():
    try:
        return "%.2f %.2f %.2f" % os.getloadavg()
    except OSError:
        return "unknown"


def print_machine(load_before):
    """The closing line of a benchmark: the CPU, its cores and the load average before (given)
    and now."""
    print()
    print("%s, %d cores; load average before: %s, after: %s" % (
        cpu_model(), os.cpu_count() or 0, load_before, load_average()))


def children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run(cmd, env=None, cwd=None):
    """Runs cmd; returns (wall seconds, combined output). Exits on failure. The CPU seconds
    (user + system) of cmd and its children are in run.cpu afterwards."""
    t0 = time.perf_counter()
    c0 = children_cpu()
    p = subprocess.run(cmd, env=env, cwd=cwd, stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, universal_newlines=True)
    wall = time.perf_counter() - t0
    run.cpu = children_cpu() - c0
    if p.returncode != 0:
        sys.stderr.write("command failed (exit %d): %s\n%s\n"
                         % (p.returncode, " ".join(cmd), p.stdout[-3000:]))
        raise SystemExit(1)
    return wall, p.stdout


# The solver's `--timing` line: steps (1), particles (2), the time loop's wall seconds (3);
# us_per_particle_step and the rest follow (a script's own pattern reads them).
TIMING_RE = re.compile(r"timing: steps=(\d+) particles=(\d+) wall_s=([0-9.eE+-]+)")


def timing_line(out, what, pattern=TIMING_RE):
    """The match of the solver's `--timing` line in its output `out`; exits (naming `what`, the
    command) where there is none."""
    m = pattern.search(out)
    if not m:
        sys.stderr.write("no 'timing:' line in the output of %s:\n%s\n" % (what, out[-2000:]))
        raise SystemExit(1)
    return m


def require_sphc(sphc, hint="pass --sphc, or --skip-sphc"):
    """False (and a line on stderr) where `sphc` is not an executable."""
    if os.access(sphc, os.X_OK):
        return True
    sys.stderr.write("no sphc at %s (build it, or %s)\n" % (sphc, hint))
    return False


def pysph_seconds(out, what):
    """PySPH's "Setup took" (what = "Setup") or "Run took" ("Run") seconds in its output, or
    None."""
    m = re.search(r"%s took: ([0-9.eE+-]+) secs" % what, out)
    return float(m.group(1)) if m else None


def pysph_timing(out, outdir):
    """PySPH's figures of a run: set-up and run seconds (its output), steps (the calls of
    Integrator.stage1 in outdir's profile_info.csv), particles ("Total: N", else "nfluid = N";
    None where neither). Exits where set-up, run or steps is missing."""
    setup, runt = pysph_seconds(out, "Setup"), pysph_seconds(out, "Run")
    total = re.search(r"Total: (\d+)", out) or re.search(r"nfluid = (\d+)", out)
    steps = None
    prof = os.path.join(outdir, "profile_info.csv")
    if os.path.exists(prof):
        with open(prof) as f:
            for line in f:
                cells = line.strip().split(",")
                if len(cells) == 5 and cells[2] == "Integrator.stage1":
                    steps = int(cells[3])
    if setup is None or runt is None or not steps:
        sys.stderr.write("could not read PySPH's timing from its output:\n%s\n" % out[-3000:])
        raise SystemExit(1)
    return dict(setup=setup, run=runt, steps=steps,
                particles=int(total.group(1)) if total else None)


def serial_env(extra=None):
    env = dict(os.environ)
    env["OMP_NUM_THREADS"] = "1"
    if extra:
        env.update(extra)
    return env


def fmt(v, spec="%.2f"):
    return "-" if v is None else spec % v


def argument_parser(doc):
    """The options every sphc-against-PySPH benchmark takes."""
    ap = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    ap.add_argument("--sphc", default=os.path.join(ROOT, "build", "bin", "sphc"))
    ap.add_argument("--pysph-python", default=sys.executable,
                    help="Python with PySPH (default: this one)")
    ap.add_argument("--skip-pysph", action="store_true")
    ap.add_argument("--skip-sphc", action="store_true")
    ap.add_argument("--keep", action="store_true", help="keep the temporary directory")
    return ap


def remove_tmp(tmp, keep):
    """The end of a benchmark: its temporary directory removed, or named with --keep."""
    if keep:
        print("kept %s" % tmp)
    else:
        shutil.rmtree(tmp, ignore_errors=True)


# The scenes of the callgrind benchmarks (fma_instructions.py, hoist_instructions.py).
SCENE_FILES = {
    "dambreak": os.path.join(ROOT, "examples", "dambreak.sph"),
    "cube": os.path.join(ROOT, "bench", "cube.sph"),
    "taylor_green": os.path.join(ROOT, "examples", "taylor_green.sph"),
}


def build_variants(sphc, scene, path, flags, variants, tmp):
    """Builds scene (the file path, sphc flags common to all) once per variant ([(name, sphc
    flags)]) into tmp/SCENE_NAME: {name: executable}, in the variants' order."""
    exes = {}
    for name, vflags in variants:
        exes[name] = os.path.join(tmp, "%s_%s" % (scene, name))
        run([sphc, path, "-o", exes[name]] + flags + vflags)
    return exes


def cpu_per_step_rounds(exes, options, short, long_, rounds):
    """CPU seconds (user + system) per step of each executable ({name: path}), (long - short
    run) / steps, without output, on one OpenMP thread; the executables interleaved, `rounds`
    times: {name: [per round]}."""
    env = dict(os.environ, OMP_NUM_THREADS="1")
    per = {name: [] for name in exes}
    for _ in range(rounds):
        for name, exe in exes.items():
            cpu = []
            for steps in (short, long_):
                run([exe] + options + ["--max-steps", str(steps), "--no-output", "--quiet",
                                       "-d", exe + "_out"], env=env)
                cpu.append(run.cpu)
            per[name].append((cpu[1] - cpu[0]) / (long_ - short))
    return per


# The C++ flags of the callgrind builds: valgrind 3.19 cannot run AVX-512, so x86-64-v3; -g for
# callgrind_annotate; no contraction, so the counts compare the printed arithmetic.
CALLGRIND_FLAGS = "-std=c++17 -O3 -march=x86-64-v3 -fno-math-errno -ffp-contract=off -g"


def cpu_or_instructions(args, prefix, cpu_per_step, instructions_per_step):
    """The body of a benchmark that measures CPU per step (--cpu) or instructions per step:
    a temporary directory, the load average before and after, the directory removed (or kept
    with --keep)."""
    tmp = tempfile.mkdtemp(prefix=prefix)
    print("load average before: %s" % load_average())
    if args.cpu:
        cpu_per_step(args, tmp)
    else:
        instructions_per_step(args, tmp)
    print("load average after: %s" % load_average())
    remove_tmp(tmp, args.keep)


def instruction_parser(doc):
    """The options every callgrind benchmark takes: the scenes, sphc, --keep."""
    ap = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    ap.add_argument("--scenes", default="dambreak,cube")
    ap.add_argument("--sphc", default=os.path.join(ROOT, "build", "bin", "sphc"))
    ap.add_argument("--keep", action="store_true", help="keep the temporary directory")
    return ap


def instructions(callgrind_file):
    """The total instruction count (Ir) of a callgrind output file."""
    with open(callgrind_file) as f:
        for line in f:
            m = re.match(r"(?:summary|totals):\s+(\d+)", line)
            if m:
                return int(m.group(1))
    raise SystemExit("no instruction total in " + callgrind_file)


def group_instructions(callgrind_file):
    """Instructions of the functions named group_* (inclusive of what is inlined in them)."""
    out = subprocess.run(["callgrind_annotate", "--inclusive=no", callgrind_file],
                         capture_output=True, text=True, check=True).stdout
    total = 0
    for line in out.splitlines():
        m = re.match(r"\s*([\d,]+)\s.*\bScene::(group_\w+)", line)
        if m:
            total += int(m.group(1).replace(",", ""))
    return total


def callgrind_build_run(sphc, path, exe, sphc_flags, options):
    """Builds the scene path into exe (sphc path -o exe sphc_flags), runs it with the run-time
    options and without output under valgrind --tool=callgrind; returns the callgrind file."""
    run([sphc, path, "-o", exe] + sphc_flags)
    cg = exe + ".callgrind"
    run(["valgrind", "--tool=callgrind", "--callgrind-out-file=" + cg, exe] + options +
        ["--no-output", "-d", exe + "_out", "--quiet"])
    return cg
