#!/usr/bin/env python3
"""Instructions and CPU time per step in single against double precision, each with and
without the SIMD pair loops of `sphc --simd-pairs` (issue 16; docs/performance-log.md "SIMD pair
loops in single precision"): prints figures, is not a test.

Variants: double (the default), double --simd-pairs, --precision=single (the destination's
sums in float locals), --precision=single --simd-pairs (the neighbours in float SIMD lanes:
16 per zmm register against 8 doubles).

Instructions (the default): each scene built for AVX2 + FMA so that valgrind 3.19 can run it
(`-std=c++17 -O3 -march=x86-64-v3 -fno-math-errno -ffp-contract=off -g`), run for a short and
a long number of steps without output under `valgrind --tool=callgrind`; per step = (long -
short) / the steps between them. Instruction counts do not depend on the machine's load.

With --cpu, instead: CPU time per step (user + system) of the default (-march=native) builds,
(long - short run) / steps, the variants interleaved, --rounds times; the minimum and the
median over the rounds (on a loaded machine only ratios of interleaved runs mean something).
Also the zmm gathers (vgatherdpd, vgatherdps) in each executable.

Usage: python3 bench/simd_single.py [--scenes cube,dambreak,dambreak_pysph,dambreak3d]
       python3 bench/simd_single.py --cpu [--rounds 3] [--scenes cube47,...]
"""

import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from common import (build_variants, CALLGRIND_FLAGS, cpu_or_instructions, ROOT,  # noqa: E402
                    SCENE_FILES, cpu_per_step_rounds, instruction_parser,
                    instructions, run)

PYSPH_EFFECTS = ["-D", "density_diffusion=off", "-D", "shifting=off"]
DAMBREAK3D = os.path.join(ROOT, "examples", "dambreak3d.sph")
# scene: (file, sphc flags, run-time options, short steps, long steps)
SCENES = {
    "cube": (SCENE_FILES["cube"], [], ["--set", "nx=20", "--tf", "1"], 5, 15),
    "dambreak": (SCENE_FILES["dambreak"], [], [], 50, 150),
    "dambreak_pysph": (SCENE_FILES["dambreak"], PYSPH_EFFECTS, ["--set", "cfl=0.3"], 50, 150),
    "dambreak3d": (DAMBREAK3D, [], [], 5, 15),
    # Periodic (the kept lists opt in with a number: the *_skin variants).
    "taylor_green": (SCENE_FILES["taylor_green"], [], [], 20, 60),
}
# --cpu: the cube at nx = 20 and 47 (PySPH's ~100k), the dam breaks at ~100k particles.
CPU_SCENES = {
    "cube20": (SCENE_FILES["cube"], [], ["--set", "nx=20", "--tf", "1"], 5, 45),
    "cube47": (SCENE_FILES["cube"], [], ["--set", "nx=47", "--tf", "1"], 2, 12),
    "dambreak": (SCENE_FILES["dambreak"], [], ["--set", "dx=0.0047"], 5, 25),
    "dambreak_pysph": (SCENE_FILES["dambreak"], PYSPH_EFFECTS,
                       ["--set", "dx=0.0047", "--set", "cfl=0.3"], 5, 45),
    "dambreak3d": (DAMBREAK3D, [], [], 5, 25),
    "taylor_green": (SCENE_FILES["taylor_green"], [], ["--set", "nx=100"], 5, 45),
}
ALL_VARIANTS = {
    "double": [], "double_simd": ["--simd-pairs"],
    "single": ["--precision=single"], "single_simd": ["--precision=single", "--simd-pairs"],
    # Double without kept lists (so per destination, as single precision, which has none).
    "double_nolists": ["--verlet-skin=off"],
    "double_nolists_simd": ["--verlet-skin=off", "--simd-pairs"],
    # Single precision with and without kept lists (stop 34; docs/performance-log.md "Kept lists
    # in single precision"): 0.1 is --verlet-skin=auto's skin.
    "single_nolists": ["--precision=single", "--verlet-skin=off"],
    "single_lists": ["--precision=single", "--verlet-skin=0.1"],
    "single_lists_simd": ["--precision=single", "--verlet-skin=0.1", "--simd-pairs"],
    # Stop 35: single precision without hoisting, without the lanes, and the kept lists of a
    # periodic or mirror scene (opt in with a number, in double too).
    "single_nohoist": ["--precision=single", "--no-hoist"],
    "single_simd_off": ["--precision=single", "--simd-pairs=off"],
    "double_skin": ["--verlet-skin=0.1"],
    "single_skin": ["--precision=single", "--verlet-skin=0.1"],
}
VARIANTS = [(n, ALL_VARIANTS[n]) for n in ("double", "double_simd", "single", "single_simd")]


def gathers(exe):
    dis = subprocess.run(["objdump", "-d", "--no-show-raw-insn", exe], stdout=subprocess.PIPE,
                         universal_newlines=True).stdout
    return sum(1 for line in dis.splitlines()
               if ("vgatherdpd" in line or "vgatherdps" in line) and "zmm" in line)


def callgrind(exe, options, steps):
    cg = "%s_%d.callgrind" % (exe, steps)
    run(["valgrind", "--tool=callgrind", "--callgrind-out-file=" + cg, exe] + options +
        ["--max-steps", str(steps), "--no-output", "-d", exe + "_out", "--quiet"])
    return instructions(cg)


def instructions_per_step(args, tmp):
    print("built with --cxxflags \"%s\"; instructions per step under callgrind, "
          "(long - short) / steps" % CALLGRIND_FLAGS)
    print("%-15s %-12s %-9s %12s %9s" % ("scene", "variant", "steps", "Ir / step",
                                          "/ " + VARIANTS[0][0]))
    for scene in args.scenes.split(","):
        path, sflags, options, short, long_ = SCENES[scene]
        base = None
        for name, flags in VARIANTS:
            exe = os.path.join(tmp, "%s_%s" % (scene, name))
            run([args.sphc, path, "-o", exe, "--cxxflags", CALLGRIND_FLAGS] + sflags + flags)
            n = (callgrind(exe, options, long_) - callgrind(exe, options, short)) / (long_ - short)
            base = base or n
            print("%-15s %-12s %-9s %12.4g %9.3f" % (scene, name, "%d-%d" % (short, long_), n,
                                                     n / base))
            sys.stdout.flush()


def cpu_per_step(args, tmp):
    print("CPU s per step (user + system; (long - short) / steps), default -march=native "
          "builds, variants interleaved; min (median) over %d rounds, / double" % args.rounds)
    for scene in args.scenes.split(","):
        path, sflags, options, short, long_ = CPU_SCENES[scene]
        exes = build_variants(args.sphc, scene, path, sflags, VARIANTS, tmp)
        per = cpu_per_step_rounds(exes, options, short, long_, args.rounds)
        lo = {n: min(v) for n, v in per.items()}
        med = {n: statistics.median(v) for n, v in per.items()}
        print("%s steps %d-%d:" % (scene, short, long_))
        for name, _ in VARIANTS:
            print("  %-12s %.4f s (%.3f; median %.3f)  zmm gathers %d  [all: %s]" % (
                name, lo[name], lo[name] / lo[VARIANTS[0][0]],
                med[name] / med[VARIANTS[0][0]],
                gathers(exes[name]), " ".join("%.4f" % v for v in per[name])))
        sys.stdout.flush()


def main():
    ap = instruction_parser(__doc__)
    ap.set_defaults(scenes=None)
    ap.add_argument("--cpu", action="store_true", help="CPU time per step")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--variants", default=None,
                    help="comma-separated, the first the base of the ratios (default: "
                    "double,double_simd,single,single_simd; also double_nolists, "
                    "double_nolists_simd, single_nolists, single_lists, single_lists_simd, "
                    "single_nohoist, single_simd_off, double_skin, single_skin)")
    args = ap.parse_args()
    if args.variants:
        VARIANTS[:] = [(n, ALL_VARIANTS[n]) for n in args.variants.split(",")]
    if args.scenes is None:
        args.scenes = ",".join(CPU_SCENES if args.cpu else SCENES)
    cpu_or_instructions(args, "sphc_simdsingle_", cpu_per_step, instructions_per_step)


if __name__ == "__main__":
    main()
