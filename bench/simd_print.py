#!/usr/bin/env python3
"""CPU time per step of the generated solvers with the SIMD pair loops of `sphc --simd-pairs`
against the default (issue 16; docs/performance-log.md "SIMD pair loops in the printer"): prints
figures, is not a test.

--simd-pairs prints each pair loop that allows it per destination with its neighbours under
`#pragma omp simd reduction(+: sums)` (codegen/SimdPairs.cpp); the default evaluates each
pair of a same-array loop once for both particles, scalar. Both serial, the default
-march=native builds; CPU time (user + system) per step = (long - short run) / steps, the
two variants interleaved, --rounds times; the minimum and the median over the rounds are
printed (on a loaded machine only ratios of interleaved runs mean something). Also the
zmm gathers (vgatherdpd) in each executable.

Usage: python3 bench/simd_print.py [--scenes cube,dambreak,dambreak_pysph] [--rounds 5] [--with-ns]
"""

import os
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from common import (build_variants, SCENE_FILES, cpu_per_step_rounds,  # noqa: E402
                    instruction_parser, load_average, remove_tmp)

PYSPH_EFFECTS = ["-D", "density_diffusion=off", "-D", "shifting=off"]
# scene: (file, sphc flags, run-time options, short steps, long steps); ~100k particles
SCENES = {
    "cube": (SCENE_FILES["cube"], [], ["--set", "nx=47", "--tf", "1"], 2, 22),
    "dambreak": (SCENE_FILES["dambreak"], [], ["--set", "dx=0.0047"], 5, 45),
    "dambreak_pysph": (SCENE_FILES["dambreak"], PYSPH_EFFECTS,
                       ["--set", "dx=0.0047", "--set", "cfl=0.3"], 5, 105),
}
VARIANTS = [("default", []), ("simd", ["--simd-pairs"])]


def gathers(exe):
    dis = subprocess.run(["objdump", "-d", "--no-show-raw-insn", exe], stdout=subprocess.PIPE,
                         universal_newlines=True).stdout
    return sum(1 for line in dis.splitlines() if "vgatherdpd" in line and "zmm" in line)


def main():
    ap = instruction_parser(__doc__)
    ap.set_defaults(scenes="cube,dambreak,dambreak_pysph")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--with-ns", action="store_true",
                    help="also the scalar per-destination loops (--no-symmetric-pairs)")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="sphc_simdprint_")
    print("load average before: %s" % load_average())
    for scene in args.scenes.split(","):
        path, sflags, options, short, long_ = SCENES[scene]
        variants = VARIANTS + ([("ns", ["--no-symmetric-pairs"])] if args.with_ns else [])
        exes = build_variants(args.sphc, scene, path, sflags, variants, tmp)
        per = cpu_per_step_rounds(exes, options, short, long_, args.rounds)
        d, s = per["default"], per["simd"]
        print("%-15s steps %d-%d, min of %d: default %.4f s, simd %.4f s per step: simd / default "
              "= %.3f (medians %.3f); zmm gathers %d / %d  [all: default %s; simd %s]" % (
                  scene, short, long_, args.rounds, min(d), min(s), min(s) / min(d),
                  statistics.median(s) / statistics.median(d), gathers(exes["default"]),
                  gathers(exes["simd"]), " ".join("%.4f" % v for v in d),
                  " ".join("%.4f" % v for v in s)))
        if args.with_ns:
            print("%-15s scalar per destination (--no-symmetric-pairs): %.4f s (/ default %.3f); "
                  "simd / ns = %.3f  [all: %s]" % (
                      scene, min(per["ns"]), min(per["ns"]) / min(d), min(s) / min(per["ns"]),
                      " ".join("%.4f" % v for v in per["ns"])))
        sys.stdout.flush()
    print("load average after: %s" % load_average())
    remove_tmp(tmp, args.keep)


if __name__ == "__main__":
    main()
