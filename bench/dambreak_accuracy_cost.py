#!/usr/bin/env python3
"""The dam-break front against wall time, sphc and PySPH 1.0b1 on one plot (issue 14).

Runs

    sphc study examples/dambreak.sph --vary dx=DXS --tf TF --pysph \
        --metric front_mps_err_max --metric front_err_max [--repeat N] -o DIR

(sphc's WCSPH dam break and PySPH's dam_break_2d, scheme wcsph, at the same particle
spacings; PySPH's mass and smoothing length follow dx, see docs/accuracy-cost.md), then the
same study again with --cost cpu_s (it reuses the runs: nothing is run twice), and prints,
for each front-error level reached by both codes, the cheapest variant of each and the ratio
of their wall (and CPU) times. The plots are DIR/front_mps_err_max_vs_wall.png (and _vs_cpu,
and front_err_max_*); the tables DIR/summary_wall_s.txt and DIR/summary_cpu_s.txt.

This is a benchmark, not a test: the wall times depend on the machine's load. Fixed-case time
to solution (one resolution, both codes) is bench/time_to_solution.py's.

Usage:
  python3 bench/dambreak_accuracy_cost.py [--sphc build/bin/sphc] [--dx 0.06,0.045,0.03,0.02]
                                          [--tf 0.6] [--repeat 1] [-o dambreak-accuracy-cost]
"""

import argparse
import os
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sphc", default=os.path.join(ROOT, "build", "bin", "sphc"))
    ap.add_argument("--dx", default="0.06,0.045,0.03,0.02")
    ap.add_argument("--tf", default="0.6")
    ap.add_argument("--repeat", default="1")
    ap.add_argument("-o", "--output", default="dambreak-accuracy-cost")
    args = ap.parse_args()
    base = [args.sphc, "study", os.path.join(ROOT, "examples", "dambreak.sph"),
            "--vary", "dx=" + args.dx, "--tf", args.tf, "--repeat", args.repeat, "--pysph",
            "--metric", "front_mps_err_max", "--metric", "front_err_max", "-o", args.output]
    for cost in ("wall_s", "cpu_s"):
        cmd = base + ["--cost", cost]
        sys.stderr.write("$ %s\n" % " ".join(cmd))
        r = subprocess.run(cmd, stdout=subprocess.PIPE, universal_newlines=True)
        if r.returncode != 0:
            sys.stdout.write(r.stdout)
            sys.stderr.write("the study failed (exit %d)\n" % r.returncode)
            return 1
        shutil.copyfile(os.path.join(args.output, "summary.txt"),
                        os.path.join(args.output, "summary_%s.txt" % cost))
        if cost == "wall_s":
            sys.stdout.write(r.stdout)
        else:
            sys.stdout.write("\nThe same runs, cost = CPU time of the time loop:\n")
            for line in r.stdout.splitlines():
                if "sphc against PySPH" in line or line.startswith("    |"):
                    sys.stdout.write(line + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
