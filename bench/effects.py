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

Usage: python3 bench/effects.py [--sphc build/bin/sphc] [--steps 300] [--repeat 2]
                                [--only dambreak|taylor_green]
"""

import argparse
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

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


def bench(sphc, scene, base, defaults, steps, repeat, tmp, run_args):
    rows = []
    for label, d in variants(defaults):
        extra = base + defines(d)
        exe = os.path.join(tmp, re.sub(r"[^a-z0-9]+", "_", os.path.basename(scene) + label))
        subprocess.run([sphc, scene, "-o", exe] + extra, check=True, capture_output=True)
        rows.append([label, extra, exe, bytes_per_particle(sphc, scene, extra), []])
    for _ in range(repeat):
        for r in rows:
            r[4].append(time_per_step(r[2], steps, run_args))
    t0 = min(rows[0][4])[0]
    b0 = rows[0][3][0]
    print(f"\n{os.path.relpath(scene, ROOT)}: {steps} steps, best of {repeat}")
    print(f"{'build':34s} {'props':>5s} {'B/particle':>10s} {'mem ratio':>9s} "
          f"{'us/particle/step':>16s} {'time ratio':>10s} {'post_step share':>15s}")
    for label, _, _, (b, n), ts in rows:
        t, post = min(ts)
        print(f"{label:34s} {n:5d} {b:10d} {b / b0:9.2f} {t:16.3f} {t / t0:10.2f} {post:15.2f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sphc", default=os.path.join(ROOT, "build", "bin", "sphc"))
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--only", choices=["dambreak", "taylor_green"], help="one scene only")
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
                  a.repeat, tmp, [])
        if a.only != "dambreak":
            scene = os.path.join(ROOT, "examples", "taylor_green.sph")
            bench(a.sphc, scene, [], scene_effects(scene), a.steps, a.repeat, tmp, [])


if __name__ == "__main__":
    sys.exit(main())
