#!/usr/bin/env python3
"""Per-step cost of the generated solvers with and without the SIMD pair loops, the matrix
behind `sphc --simd-pairs=auto` (issue 16; docs/performance-log.md "SIMD pair loops chosen by the
compiler"): prints figures, is not a test.

For each scene and each variant (by default: off = the scalar loops, each pair once where the
bodies allow it; on = `--simd-pairs`, every loop that allows it in SIMD lanes; auto = the
compiler's choice), serial and OpenMP:

- instructions per step of the serial build by callgrind (not OpenMP: the openmp builds do
  not start under valgrind 3.19 here), (long - short run) / the steps between them, built for AVX2 + FMA so that
  valgrind 3.19 can run it (`-std=c++17 -O3 -march=x86-64-v3 -fno-math-errno
  -ffp-contract=off -g`; the driver adds -fopenmp-simd where it prints `omp simd` loops); instruction counts do not depend on the machine's load, but AVX2 lanes hold 4
  doubles where the default -march=native build's AVX-512 lanes hold 8;
- CPU seconds (user + system) per step of the default builds (-march=native), (long - short
  run) / steps, the variants interleaved, --rounds times (serial: OMP_NUM_THREADS=1, OpenMP:
  2 threads); min and median over the rounds. On a loaded machine only ratios of interleaved
  runs mean something.

Usage: python3 bench/simd_auto.py [--scenes cube20,cube47,...] [--variants off,on,auto,once]
       [--rounds 3] [--no-callgrind] [--no-cpu] [--backends serial,openmp]
"""

import os
import statistics
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from common import (CALLGRIND_FLAGS, ROOT, SCENE_FILES, instruction_parser,  # noqa: E402
                    instructions, load_average, remove_tmp, run)

PYSPH_EFFECTS = ["-D", "density_diffusion=off", "-D", "shifting=off"]
DB3 = os.path.join(ROOT, "examples", "dambreak3d.sph")
DSPH = os.path.join(ROOT, "bench", "dambreak3d_dualsphysics.sph")
# scene: (file, sphc flags, run-time options, (callgrind short, long steps),
#         (CPU short, long steps), CPU run-time options (None: the same))
SCENES = {
    "cube20": (SCENE_FILES["cube"], [], ["--set", "nx=20", "--tf", "1"], (3, 8), (2, 42), None),
    "cube47": (SCENE_FILES["cube"], [], ["--set", "nx=47", "--tf", "1"], None, (2, 12), None),
    "dambreak3d": (DB3, [], [], (5, 15), (5, 105), None),
    "dsph": (DSPH, [], ["--set", "dp=0.02"], (3, 8), (3, 33), None),
    "dambreak": (SCENE_FILES["dambreak"], [], [], (20, 60), (20, 220), None),
    "dambreak_pysph": (SCENE_FILES["dambreak"], PYSPH_EFFECTS, ["--set", "cfl=0.3"], (20, 60),
                       (20, 320), None),
    "taylor_green": (SCENE_FILES["taylor_green"], [], [], (20, 60), (20, 420), None),
    # Neighbour counts between the 2D dam break's ~21 and the 3D scenes' 74-174: h/dx set at
    # run time (the support ball 4/3 pi (2 hdx)^3 in 3D, pi (2 hdx)^2 in 2D).
    "cube20_h10": (SCENE_FILES["cube"], [], ["--set", "nx=20", "--set", "hdx=1.0", "--tf", "1"],
                   (3, 8), (2, 42), None),
    "cube20_h12": (SCENE_FILES["cube"], [], ["--set", "nx=20", "--set", "hdx=1.2", "--tf", "1"],
                   (3, 8), (2, 42), None),
    # ~100k particles (dx = 0.0047, as bench/backends.py; stop 36).
    "dambreak_100k": (SCENE_FILES["dambreak"], [], ["--set", "dx=0.0047"], None, (2, 12), None),
    "dambreak_pysph_100k": (SCENE_FILES["dambreak"], PYSPH_EFFECTS,
                            ["--set", "cfl=0.3", "--set", "dx=0.0047"], None, (2, 12), None),
    "taylor_green_edac": (SCENE_FILES["taylor_green"], ["-D", "scheme=edac"],
                          ["--set", "nx=100"], (5, 15), (10, 110), None),
    # Scenes whose loops are per destination anyway (periodic, zones; stop 36).
    "dambreak_pysph_nosym": (SCENE_FILES["dambreak"], PYSPH_EFFECTS + ["--no-symmetric-pairs"],
                             ["--set", "cfl=0.3"], None, (20, 320), None),
    "poiseuille": (os.path.join(ROOT, "examples", "poiseuille.sph"), [], [], None, (10, 110),
                   None),
    "cylinder": (os.path.join(ROOT, "examples", "cylinder.sph"), [], [], None, (10, 110), None),
    "dambreak_pysph_h16": (SCENE_FILES["dambreak"], PYSPH_EFFECTS,
                           ["--set", "cfl=0.3", "--set", "hdx=1.6"], (20, 60), (20, 320), None),
    "dambreak_pysph_h20": (SCENE_FILES["dambreak"], PYSPH_EFFECTS,
                           ["--set", "cfl=0.3", "--set", "hdx=2.0"], (20, 60), (20, 320), None),
}
GATHER_FLAGS = ("-std=c++17 -O3 -march=native -mtune-ctrl=use_gather -fno-math-errno "
                "-ffp-contract=off")
VARIANT_FLAGS = {"off": ["--simd-pairs=off"], "on": ["--simd-pairs=on"], "auto": [],
                 "once": ["--simd-pairs=once"], "perdest": ["--simd-pairs=perdest"],
                 "perdest_gather": ["--simd-pairs=perdest", "--cxxflags=" + GATHER_FLAGS],
                 # The driver's flags with GCC's gathers allowed (-mtune-ctrl=use_gather): GCC
                 # 12.2 (Debian 12.2.0-14+deb12u1) tuning for `generic` (what -march=native
                 # gives on the stop-35 Intel machine, cooperlake) uses no gathers, and the
                 # loops printed in lanes stay scalar without it.
                 "auto_gather": ["--cxxflags=" + GATHER_FLAGS],
                 "once_gather": ["--simd-pairs=once", "--cxxflags=" + GATHER_FLAGS],
                 "legacy_off": [], "legacy_on": ["--simd-pairs"],
                 # Stop 36, the 2D scenes in the lanes on Intel with gathers: every loop that
                 # allows them (each pair once where it may, the cross passes and loops per
                 # destination anyway in lanes per destination), or only the loops printed
                 # each pair once in the lanes (the others as auto leaves them).
                 "once_all": ["--simd-pairs=once", "--simd-neighbours=0"],
                 "once_only": ["--simd-pairs=once", "--simd-once-neighbours=0"],
                 # The same in 4-lane (ymm) vectors: 2D's ~12 neighbours above d_idx fill
                 # fewer 8-lane vectors (an experiment, stop 36).
                 # The self pair evaluated in the each-pair-once lanes (before stop 36).
                 "noskip": ["--no-self-pair-skip"],
                 # Only the loops per destination anyway (periodic, no kept lists) in lanes.
                 "perdest_only": ["--simd-perdest-neighbours=0"],
                 "once_only_256": ["--simd-pairs=once", "--simd-once-neighbours=0",
                                   "--cxxflags=" + GATHER_FLAGS + " -mprefer-vector-width=256"]}


def exec_run(exe, options, steps, threads, tool=None):
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    cmd = (tool or []) + [exe] + options + ["--max-steps", str(steps), "--no-output", "--quiet",
                                            "-d", exe + "_out"]
    run(cmd, env=env)
    return run.cpu


def main():
    ap = instruction_parser(__doc__)
    ap.set_defaults(scenes=",".join(SCENES))
    ap.add_argument("--variants", default="off,on")
    ap.add_argument("--backends", default="serial,openmp")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--no-callgrind", action="store_true")
    ap.add_argument("--no-cpu", action="store_true")
    args = ap.parse_args()
    variants = args.variants.split(",")
    tmp = tempfile.mkdtemp(prefix="sphc_simdauto_")
    print("load average before: %s" % load_average())
    for scene in args.scenes.split(","):
        path, sflags, options, cg_steps, cpu_steps, cpu_options = SCENES[scene]
        cpu_options = options if cpu_options is None else cpu_options
        for backend in args.backends.split(","):
            threads = 2 if backend == "openmp" else 1
            bflags = ["--backend=" + backend]
            if cg_steps and not args.no_callgrind and backend == "serial":
                ins = {}
                for v in variants:
                    exe = os.path.join(tmp, "%s_%s_%s_cg" % (scene, backend, v))
                    flags = sflags + bflags + VARIANT_FLAGS[v]
                    run([args.sphc, path, "-o", exe, "--cxxflags=" + CALLGRIND_FLAGS] + flags)
                    n = []
                    for steps in cg_steps:
                        cg = "%s_%d.callgrind" % (exe, steps)
                        exec_run(exe, options, steps, threads,
                                 ["valgrind", "--tool=callgrind", "--callgrind-out-file=" + cg])
                        n.append(instructions(cg))
                    ins[v] = (n[1] - n[0]) / (cg_steps[1] - cg_steps[0])
                base = ins[variants[0]]
                print("%-15s %-6s callgrind (AVX2) instructions / step, steps %d-%d: %s" % (
                    scene, backend, cg_steps[0], cg_steps[1], "; ".join(
                        "%s %.4g (%.3f)" % (v, ins[v], ins[v] / base) for v in variants)))
                sys.stdout.flush()
            if args.no_cpu:
                continue
            exes = {}
            for v in variants:
                exes[v] = os.path.join(tmp, "%s_%s_%s" % (scene, backend, v))
                run([args.sphc, path, "-o", exes[v]] + sflags + bflags + VARIANT_FLAGS[v])
            per = {v: [] for v in variants}
            short, long_ = cpu_steps
            for _ in range(args.rounds):
                for v in variants:
                    a = exec_run(exes[v], cpu_options, short, threads)
                    b = exec_run(exes[v], cpu_options, long_, threads)
                    per[v].append((b - a) / (long_ - short))
            base = per[variants[0]]
            print("%-15s %-6s CPU s / step, steps %d-%d, %d rounds: %s  [all: %s]" % (
                scene, backend, short, long_, args.rounds, "; ".join(
                    "%s min %.4g (%.3f) median (%.3f)" % (
                        v, min(per[v]), min(per[v]) / min(base),
                        statistics.median(per[v]) / statistics.median(base)) for v in variants),
                " | ".join(v + " " + " ".join("%.4g" % x for x in per[v]) for v in variants)))
            sys.stdout.flush()
    print("load average after: %s" % load_average())
    remove_tmp(tmp, args.keep)


if __name__ == "__main__":
    main()
