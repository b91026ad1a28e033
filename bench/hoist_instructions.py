#!/usr/bin/env python3
"""Instructions executed by the generated solvers with and without the source-only values
hoisted out of the pair loops (`sphc --no-hoist`; issue 16): prints figures, is not a test.

By default sphc computes each subexpression of a pair-loop body that depends on the source
particle only and divides or calls sqrt, pow, ... once per source particle before the
neighbour pass (codegen/Hoist.cpp); --no-hoist computes it per pair, as written. Each scene is
built both ways with the same flags, for AVX2 + FMA so that valgrind 3.19 can run it
(`-std=c++17 -O3 -march=x86-64-v3 -fno-math-errno -ffp-contract=off -g`), and runs a fixed
number of steps without output under `valgrind --tool=callgrind`; the total instruction count
(Ir, the whole process: set-up included) and its ratio to --no-hoist are printed, with the
instructions of the pair-loop functions (the phase functions `group_*`, where the loops are
inlined). Instruction counts do not depend on the machine's load.

With --cpu, instead: CPU time per particle-step at ~100k particles of the default
(-march=native) builds, from a short and a long run of each (per step = (long - short) / the
steps between them), the two variants interleaved, --rounds times; the process's CPU time
(user + system) is what is measured, so the figures mean something on a loaded machine only
as ratios of interleaved runs.

Usage: python3 bench/hoist_instructions.py [--scenes dambreak,cube] [--sphc build/bin/sphc]
       python3 bench/hoist_instructions.py --cpu [--rounds 3]
Needs valgrind and callgrind_annotate (not with --cpu).
"""

import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from common import (build_variants, CALLGRIND_FLAGS, SCENE_FILES,  # noqa: E402
                    callgrind_build_run, group_instructions, instruction_parser,
                    instructions, load_average, remove_tmp, run)

# scene: (file, run-time options)
SCENES = {
    "dambreak": (SCENE_FILES["dambreak"], ["--set", "dx=0.03", "--max-steps", "100"]),
    "cube": (SCENE_FILES["cube"], ["--set", "nx=20", "--max-steps", "20"]),
    "taylor_green": (SCENE_FILES["taylor_green"], ["--set", "nx=50", "--max-steps", "20"]),
}
VARIANTS = [("no-hoist", ["--no-hoist"]), ("hoist", [])]
# --cpu: scene -> (file, options, particles, short steps, long steps)
CPU_SCENES = {
    "cube": (SCENE_FILES["cube"], ["--set", "nx=47"], 103823, 1, 11),
    "dambreak": (SCENE_FILES["dambreak"], ["--set", "dx=0.0046"], 102243, 1, 41),
}


def cpu_per_step(args, tmp):
    print("CPU s per step (user + system; (long - short) / steps), default -march=native builds")
    print("%-10s %-9s %-7s %12s %20s" % ("scene", "variant", "round", "CPU s/step",
                                        "us / particle-step"))
    for scene in args.scenes.split(","):
        path, options, particles, short, long_ = CPU_SCENES[scene]
        exes = build_variants(args.sphc, scene, path, [], VARIANTS, tmp)
        per = {name: [] for name, _ in VARIANTS}
        for r in range(args.rounds):
            for name, _ in VARIANTS:
                cpu = []
                for steps in (short, long_):
                    run([exes[name]] + options + ["--max-steps", str(steps), "--no-output",
                                                  "--quiet", "-d", exes[name] + "_out"])
                    cpu.append(run.cpu)
                step = (cpu[1] - cpu[0]) / (long_ - short)
                per[name].append(step)
                print("%-10s %-9s %-7d %12.4f %20.3f" % (scene, name, r + 1, step,
                                                         step / particles * 1e6))
                sys.stdout.flush()
        med = {name: sorted(v)[len(v) // 2] for name, v in per.items()}
        print("%-10s median: no-hoist %.4f s, hoist %.4f s per step: hoist / no-hoist = %.3f"
              % (scene, med["no-hoist"], med["hoist"], med["hoist"] / med["no-hoist"]))


def main():
    ap = instruction_parser(__doc__)
    ap.add_argument("--cpu", action="store_true", help="CPU time per step at ~100k particles")
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="sphc_hoist_")
    if args.cpu:
        print("load average before: %s" % load_average())
        cpu_per_step(args, tmp)
        print("load average after: %s" % load_average())
        remove_tmp(tmp, args.keep)
        return
    print("built with --cxxflags \"%s\"; instructions under callgrind" % CALLGRIND_FLAGS)
    print("%-13s %-9s %-18s %15s %9s %15s %9s" % ("scene", "variant", "run", "instructions",
                                                  "/ off", "group_* (self)", "/ off"))
    for scene in args.scenes.split(","):
        path, options = SCENES[scene]
        base = gbase = None
        for name, flags in VARIANTS:
            exe = os.path.join(tmp, "%s_%s" % (scene, name))
            cg = callgrind_build_run(args.sphc, path, exe,
                                     ["--cxxflags", CALLGRIND_FLAGS] + flags, options)
            n = instructions(cg)
            g = group_instructions(cg)
            base = base or n
            gbase = gbase or g
            print("%-13s %-9s %-18s %15.4g %9.3f %15.4g %9.3f" % (
                scene, name, " ".join(options[1:2] + options[-1:]), n, n / base, g,
                g / gbase if gbase else 0))
            sys.stdout.flush()
    remove_tmp(tmp, args.keep)


if __name__ == "__main__":
    main()
