#!/usr/bin/env python3
"""What each effect costs: memory per particle and time per step of the dam break and the
Taylor-Green vortex built with effects on and off (docs/effects.md). Prints figures; is not a
test.

Each variant is one build, `sphc SCENE -D EFFECT=on|off ...` (compile-time specialisation:
an effect that is off is absent from the solver), timed over --steps steps of the time loop
(`--max-steps N --no-output --timing`, best of --repeat runs). Memory: the bytes per particle
of the fluid array that `sphc --report` prints (double precision). Time: microseconds per
particle per step, and the ratio to the scene's default build, which is what stays meaningful
on a loaded machine (all variants run in one sitting, interleaved when --repeat > 1), and the
share of the time loop in post_step groups (shifting's), from --timing. The default build is
the one of the effects the scene lists; "minimal" has every effect off, "every effect on"
all of the WCSPH scheme's effects listed in WCSPH.
The dam break runs with its fixed time step (-D timestep=fixed), so every variant takes the
same steps.

--callgrind adds a load-independent time: the instructions (valgrind --tool=callgrind, Ir)
per particle per step of the time loop, from two runs of --callgrind-steps N1,N2 steps
((Ir(N2) - Ir(N1)) / (N2 - N1) / particles: the setup and the first evaluation cancel), with
each variant built with --cxxflags="CALLGRIND_CXXFLAGS" (valgrind does not decode the AVX-512
the default -march=native emits on some machines).

--accuracy adds, for the Taylor-Green vortex, the metrics the effects change: each variant run
to the last of --tg-times (0.05,0.2: WCSPH at nx = 50 follows the exact solution to t = 0.05
and breaks up from 0.075, tests/validation/taylor_green.py) and the solver's own metrics at
those times: the decay error of the largest speed, max |v| / (U e^{bt}) - 1, and the L1
error of the speed (the columns decay_err and l1 of taylor_green_metrics.csv).

Usage: python3 bench/effects.py [--sphc build/bin/sphc] [--steps 300] [--repeat 2]
                                [--only dambreak|taylor_green] [--callgrind] [--accuracy]
                                [--no-wall]
"""

import argparse
import csv
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CALLGRIND_CXXFLAGS = "-std=c++17 -O3 -march=x86-64-v3 -fno-math-errno"

WCSPH = ["gravity", "artificial_viscosity", "laminar_viscosity", "xsph", "density_gradient",
         "delta_sph", "density_diffusion", "shifting"]


def variants(defaults):
    """(label, {effect: on/off}) pairs: the default, each effect toggled, minimal, all on."""
    out = [("default (" + ", ".join(defaults) + ")", {})]
    for e in WCSPH:
        if e == "density_gradient":
            continue
        on = e not in defaults
        d = {e: "on" if on else "off"}
        if e == "delta_sph" and on:
            d["density_gradient"] = "on"
        out.append(((" + " if on else " - ") + e, d))
    out.append(("minimal (no effect)", {e: "off" for e in WCSPH}))
    out.append(("every effect on", {e: "on" for e in WCSPH}))
    return out


def scene_effects(scene):
    """The effects a scene lists (`effects = [...]`): its default build."""
    m = re.search(r"^\s*effects\s*=\s*\[([^\]]*)\]", open(scene).read(), re.M)
    return [e.strip() for e in m.group(1).split(",") if e.strip()] if m else []


def defines(d):
    return [a for e, v in d.items() for a in ("-D", f"{e}={v}")]


def bytes_per_particle(sphc, scene, extra):
    rep = subprocess.run([sphc, scene, "--report"] + extra, capture_output=True, text=True,
                         check=True).stdout
    m = re.search(r"array fluid .*?(\d+) properties, (\d+) bytes per particle", rep)
    return int(m.group(2)), int(m.group(1))


def time_per_step(exe, steps, args):
    """(microseconds per particle per step, share of wall_s in post_step groups) of a run."""
    out = subprocess.run([exe, "--max-steps", str(steps), "--no-output", "--timing", "--quiet"]
                         + args, capture_output=True, text=True, check=True)
    text = out.stdout + out.stderr
    m = re.search(r"us_per_particle_step=([0-9.eE+-]+)", text)
    post = sum(float(g) for g in re.findall(r"^timing-group: .* share=([0-9.]+) .*when=post_step",
                                            text, re.M))
    return float(m.group(1)), post


def instructions(exe, steps, args):
    """(instructions executed, particles) of a run of `steps` steps under callgrind."""
    with tempfile.TemporaryDirectory() as tmp:
        out = subprocess.run(["valgrind", "--tool=callgrind",
                              "--callgrind-out-file=" + os.path.join(tmp, "cg.out"), exe,
                              "--max-steps", str(steps), "--no-output", "--timing", "--quiet"]
                             + args, capture_output=True, text=True, check=True)
    text = out.stdout + out.stderr
    return (int(re.search(r"Collected : (\d+)", text).group(1)),
            int(re.search(r"particles=(\d+)", text).group(1)))


def ir_per_particle_step(exe, n1, n2, args):
    """Instructions per particle per step of the time loop: the difference of two runs."""
    i1, n = instructions(exe, n1, args)
    i2, _ = instructions(exe, n2, args)
    return (i2 - i1) / (n2 - n1) / n


def tg_accuracy(exe, times):
    """[(decay error, L1 error of the speed)] of a Taylor-Green run at each of the times."""
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([exe, "--quiet", "--tf", str(max(times)), "--output-every", "0.0125",
                        "-d", tmp], check=True, capture_output=True)
        with open(os.path.join(tmp, "taylor_green_metrics.csv")) as f:
            rows = list(csv.DictReader(f))
    out = []
    for t in times:
        r = min(rows, key=lambda r: abs(float(r["t"]) - t))
        out.append((float(r["decay_err"]), float(r["l1"])))
    return out


def bench(sphc, scene, base, defaults, steps, repeat, tmp, run_args, opts):
    rows = []
    for label, d in variants(defaults):
        extra = base + defines(d)
        exe = os.path.join(tmp, re.sub(r"[^a-z0-9]+", "_", os.path.basename(scene) + label))
        subprocess.run([sphc, scene, "-o", exe] + extra, check=True, capture_output=True)
        row = {"label": label, "bytes": bytes_per_particle(sphc, scene, extra), "times": []}
        if opts.callgrind:
            subprocess.run([sphc, scene, "-o", exe + "_cg", "--cxxflags=" + CALLGRIND_CXXFLAGS]
                           + extra, check=True, capture_output=True)
            row["ir"] = ir_per_particle_step(exe + "_cg", opts.callgrind_steps[0],
                                             opts.callgrind_steps[1], run_args)
        if opts.accuracy and os.path.basename(scene) == "taylor_green.sph":
            row["acc"] = tg_accuracy(exe, opts.tg_times)
        row["exe"] = exe
        rows.append(row)
    if not opts.no_wall:
        for _ in range(repeat):
            for r in rows:
                r["times"].append(time_per_step(r["exe"], steps, run_args))
    b0 = rows[0]["bytes"][0]
    head = f"{'build':34s} {'props':>5s} {'B/particle':>10s} {'mem ratio':>9s}"
    if not opts.no_wall:
        head += f" {'us/particle/step':>16s} {'time ratio':>10s} {'post_step share':>15s}"
    if opts.callgrind:
        head += f" {'Ir/particle/step':>16s} {'Ir ratio':>8s}"
    if any("acc" in r for r in rows):
        for t in opts.tg_times:
            head += f" {'decay err t=' + str(t):>17s} {'L1 err t=' + str(t):>14s}"
    print(f"\n{os.path.relpath(scene, ROOT)}: "
          + (f"{steps} steps, best of {repeat}" if not opts.no_wall else "no wall-clock timing")
          + (f"; callgrind steps {opts.callgrind_steps[0]}-{opts.callgrind_steps[1]}"
             if opts.callgrind else "")
          + (f"; accuracy at t = {opts.tg_times}" if any("acc" in r for r in rows) else ""))
    print(head)
    for r in rows:
        b, n = r["bytes"]
        line = f"{r['label']:34s} {n:5d} {b:10d} {b / b0:9.2f}"
        if not opts.no_wall:
            t0 = min(rows[0]["times"])[0]
            t, post = min(r["times"])
            line += f" {t:16.3f} {t / t0:10.2f} {post:15.2f}"
        if opts.callgrind:
            line += f" {r['ir']:16.0f} {r['ir'] / rows[0]['ir']:8.2f}"
        for decay, l1 in r.get("acc", []):
            line += f" {100 * decay:+16.3f}% {100 * l1:13.3f}%"
        print(line)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sphc", default=os.path.join(ROOT, "build", "bin", "sphc"))
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--only", choices=["dambreak", "taylor_green"], help="one scene only")
    ap.add_argument("--callgrind", action="store_true",
                    help="also count instructions per particle per step (valgrind)")
    ap.add_argument("--callgrind-steps", type=lambda v: [int(x) for x in v.split(",")],
                    default=[5, 15], help="N1,N2: the two run lengths of --callgrind")
    ap.add_argument("--accuracy", action="store_true",
                    help="Taylor-Green: the decay and L1 errors of each variant at --tg-tf")
    ap.add_argument("--tg-times", type=lambda v: [float(x) for x in v.split(",")],
                    default=[0.05, 0.2], help="T1,T2,...: the times of --accuracy")
    ap.add_argument("--no-wall", action="store_true", help="no wall-clock timing")
    a = ap.parse_args()
    cpu = "unknown CPU"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    print(f"sphc effects benchmark on {cpu} (serial, double)")
    with tempfile.TemporaryDirectory() as tmp:
        if a.only != "taylor_green":
            scene = os.path.join(ROOT, "examples", "dambreak.sph")
            bench(a.sphc, scene, ["-D", "timestep=fixed"], scene_effects(scene), a.steps,
                  a.repeat, tmp, [], a)
        if a.only != "dambreak":
            scene = os.path.join(ROOT, "examples", "taylor_green.sph")
            bench(a.sphc, scene, [], scene_effects(scene), a.steps, a.repeat, tmp, [], a)


if __name__ == "__main__":
    sys.exit(main())
