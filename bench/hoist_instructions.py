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

Usage: python3 bench/hoist_instructions.py [--scenes dambreak,cube] [--sphc build/bin/sphc]
Needs valgrind and callgrind_annotate.
"""

import argparse
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from common import remove_tmp, run  # noqa: E402
from fma_instructions import instructions  # noqa: E402

FLAGS = "-std=c++17 -O3 -march=x86-64-v3 -fno-math-errno -ffp-contract=off -g"
# scene: (file, run-time options)
SCENES = {
    "dambreak": (os.path.join(ROOT, "examples", "dambreak.sph"),
                 ["--set", "dx=0.03", "--max-steps", "100"]),
    "cube": (os.path.join(ROOT, "bench", "cube.sph"), ["--set", "nx=20", "--max-steps", "20"]),
    "taylor_green": (os.path.join(ROOT, "examples", "taylor_green.sph"),
                     ["--set", "nx=50", "--max-steps", "20"]),
}
VARIANTS = [("no-hoist", ["--no-hoist"]), ("hoist", [])]


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


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default="dambreak,cube")
    ap.add_argument("--sphc", default=os.path.join(ROOT, "build", "bin", "sphc"))
    ap.add_argument("--keep", action="store_true", help="keep the temporary directory")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="sphc_hoist_")
    print("built with --cxxflags \"%s\"; instructions under callgrind" % FLAGS)
    print("%-13s %-9s %-18s %15s %9s %15s %9s" % ("scene", "variant", "run", "instructions",
                                                  "/ off", "group_* (self)", "/ off"))
    for scene in args.scenes.split(","):
        path, options = SCENES[scene]
        base = gbase = None
        for name, flags in VARIANTS:
            exe = os.path.join(tmp, "%s_%s" % (scene, name))
            run([args.sphc, path, "-o", exe, "--cxxflags", FLAGS] + flags)
            cg = exe + ".callgrind"
            run(["valgrind", "--tool=callgrind", "--callgrind-out-file=" + cg, exe] + options +
                ["--no-output", "-d", exe + "_out", "--quiet"])
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
