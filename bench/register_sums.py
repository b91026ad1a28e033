#!/usr/bin/env python3
"""Instructions and CPU time per step of the generated solvers with the destination's sums in
locals across the neighbours (the default) and in memory at every pair (`sphc
--no-register-sums`; issue 16): prints figures, is not a test.

By default the d_ properties the pair-loop bodies accumulate at d_idx are locals of the
destination loop, loaded before its neighbours and stored after them
(codegen/RegisterSums.cpp); --no-register-sums updates them in memory at every pair.

Instructions: each scene built both ways for AVX2 + FMA so that valgrind 3.19 can run it
(`-std=c++17 -O3 -march=x86-64-v3 -fno-math-errno -ffp-contract=off -g`), run for a short and
a long number of steps without output under `valgrind --tool=callgrind`; per step = (long -
short) / the steps between them (set-up and the first list builds cancel). Also per step: the
instructions of the phase functions `group_*` (where the pair loops are inlined). Instruction
counts do not depend on the machine's load.

With --cpu, instead: CPU time per step (user + system) of the default (-march=native) builds,
from a short and a long run of each, the two variants interleaved, --rounds times; the
minimum over the rounds is printed (on a loaded machine only ratios of interleaved runs mean
something).

Usage: python3 bench/register_sums.py [--scenes dambreak,dambreak_pysph,cube]
       python3 bench/register_sums.py --cpu [--rounds 5]
Needs valgrind and callgrind_annotate (not with --cpu).
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from common import (build_variants, CALLGRIND_FLAGS, cpu_or_instructions,  # noqa: E402
                    SCENE_FILES, cpu_per_step_rounds, group_instructions,
                    instruction_parser, instructions, run)

# The dam break with PySPH's effects (bench/time_to_solution.py): its sphc defines and options.
PYSPH_EFFECTS = ["-D", "density_diffusion=off", "-D", "shifting=off"]
# scene: (file, sphc flags, run-time options, short steps, long steps)
SCENES = {
    "dambreak": (SCENE_FILES["dambreak"], [], [], 50, 150),
    "dambreak_pysph": (SCENE_FILES["dambreak"], PYSPH_EFFECTS, ["--set", "cfl=0.3"], 50, 150),
    "cube": (SCENE_FILES["cube"], [], ["--set", "nx=20", "--tf", "1"], 5, 15),
}
# --cpu: the same at ~100k particles (dam break dx = 0.0046; cube nx = 47, PySPH's).
CPU_SCENES = {
    "dambreak": (SCENE_FILES["dambreak"], [], ["--set", "dx=0.0046"], 1, 21),
    "dambreak_pysph": (SCENE_FILES["dambreak"], PYSPH_EFFECTS,
                       ["--set", "dx=0.0046", "--set", "cfl=0.3"], 1, 21),
    "cube": (SCENE_FILES["cube"], [], ["--set", "nx=47", "--tf", "1"], 1, 11),
}
VARIANTS = [("memory", ["--no-register-sums"]), ("locals", [])]


def callgrind(exe, options, steps):
    cg = "%s_%d.callgrind" % (exe, steps)
    run(["valgrind", "--tool=callgrind", "--callgrind-out-file=" + cg, exe] + options +
        ["--max-steps", str(steps), "--no-output", "-d", exe + "_out", "--quiet"])
    return instructions(cg), group_instructions(cg)


def instructions_per_step(args, tmp):
    print("built with --cxxflags \"%s\"; instructions per step under callgrind, "
          "(long - short) / steps" % CALLGRIND_FLAGS)
    print("%-15s %-8s %-11s %15s %9s %15s %9s" % ("scene", "variant", "steps", "Ir / step",
                                                  "/ memory", "group_* / step", "/ memory"))
    for scene in args.scenes.split(","):
        path, sflags, options, short, long_ = SCENES[scene]
        base = gbase = None
        for name, flags in VARIANTS:
            exe = os.path.join(tmp, "%s_%s" % (scene, name))
            run([args.sphc, path, "-o", exe, "--cxxflags", CALLGRIND_FLAGS] + sflags + flags)
            n0, g0 = callgrind(exe, options, short)
            n1, g1 = callgrind(exe, options, long_)
            n = (n1 - n0) / (long_ - short)
            g = (g1 - g0) / (long_ - short)
            base = base or n
            gbase = gbase or g
            print("%-15s %-8s %-11s %15.4g %9.3f %15.4g %9s" % (
                scene, name, "%d-%d" % (short, long_), n, n / base, g,
                "%.3f" % (g / gbase) if gbase else "-"))
            sys.stdout.flush()


def cpu_per_step(args, tmp):
    print("CPU s per step (user + system; (long - short) / steps), default -march=native "
          "builds, variants interleaved")
    for scene in args.scenes.split(","):
        path, sflags, options, short, long_ = CPU_SCENES[scene]
        exes = build_variants(args.sphc, scene, path, sflags, VARIANTS, tmp)
        per = cpu_per_step_rounds(exes, options, short, long_, args.rounds)
        best = {name: min(v) for name, v in per.items()}
        print("%-15s memory %.4f s, locals %.4f s per step (min of %d): locals / memory = %.3f"
              "  [all: memory %s; locals %s]" % (
                  scene, best["memory"], best["locals"], args.rounds,
                  best["locals"] / best["memory"],
                  " ".join("%.4f" % v for v in per["memory"]),
                  " ".join("%.4f" % v for v in per["locals"])))
        sys.stdout.flush()


def main():
    ap = instruction_parser(__doc__)
    ap.set_defaults(scenes="dambreak,dambreak_pysph,cube")
    ap.add_argument("--cpu", action="store_true", help="CPU time per step at ~100k particles")
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    cpu_or_instructions(args, "sphc_regsums_", cpu_per_step, instructions_per_step)


if __name__ == "__main__":
    main()
