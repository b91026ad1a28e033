#!/usr/bin/env python3
"""Instructions executed by the generated solvers with and without explicit fused
multiply-adds (`sphc --fma=on|off`; issue 16): prints figures, is not a test.

The solvers are built without contraction (-ffp-contract=off) so that every backend rounds the
same arithmetic; with --fma=on (the default) sphc writes each product added to a value in the
bodies as std::fma (C++) / fma (OpenCL C), which gives the FMAs back deterministically
(codegen/FusedMultiplyAdd.h). Each scene is built three times with the same flags, for AVX2 +
FMA so that valgrind 3.19 can run it (`-std=c++17 -O3 -march=x86-64-v3 -fno-math-errno -g`):

  off    --fma=off, -ffp-contract=off   each + - * rounded as written (the solvers before)
  on     --fma=on,  -ffp-contract=off   the bodies' multiply-adds as std::fma (the default)
  fast   --fma=off, -ffp-contract=fast  GCC fuses wherever an inlining context allows it (a
                                        reference only: not the same choice on every backend)

and each runs a fixed number of steps without output under `valgrind --tool=callgrind`; the
total instruction count (Ir, the whole process: set-up included) and its ratio to `off` are
printed. Instruction counts do not depend on the machine's load.

Usage: python3 bench/fma_instructions.py [--scenes dambreak,cube] [--sphc build/bin/sphc] [--keep]
Needs valgrind.
"""

import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from common import (SCENE_FILES, callgrind_build_run, instruction_parser, instructions,  # noqa: E402
                    remove_tmp)

FLAGS = "-std=c++17 -O3 -march=x86-64-v3 -fno-math-errno -g"
# scene: (file, run-time options)
SCENES = {
    "dambreak": (SCENE_FILES["dambreak"], ["--set", "dx=0.03", "--max-steps", "100"]),
    "cube": (SCENE_FILES["cube"], ["--set", "nx=20", "--max-steps", "5"]),
}
VARIANTS = [("off", "off", "off"), ("on", "on", "off"), ("fast", "off", "fast")]



def main():
    args = instruction_parser(__doc__).parse_args()
    tmp = tempfile.mkdtemp(prefix="sphc_fma_")
    print("built with --cxxflags \"%s -ffp-contract=...\"; instructions under callgrind" % FLAGS)
    print("%-10s %-6s %-8s %-14s %15s %9s" % ("scene", "--fma", "contract", "run", "instructions",
                                             "/ off"))
    for scene in args.scenes.split(","):
        path, options = SCENES[scene]
        base = None
        for name, fma, contract in VARIANTS:
            exe = os.path.join(tmp, "%s_%s" % (scene, name))
            cg = callgrind_build_run(args.sphc, path, exe, ["--fma=" + fma, "--cxxflags",
                                                            FLAGS + " -ffp-contract=" + contract],
                                     options)
            n = instructions(cg)
            base = base or n
            print("%-10s %-6s %-8s %-14s %15.4g %9.3f" % (scene, fma, contract,
                                                         " ".join(options[-2:]), n, n / base))
            sys.stdout.flush()
    remove_tmp(tmp, args.keep)


if __name__ == "__main__":
    main()
