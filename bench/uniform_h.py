#!/usr/bin/env python3
"""CPU time of the generated solvers with h read once per pass where an array's h is one value
for the whole run (the default since stop 45) and per particle (`sphc --no-uniform-h`; issue
16): prints figures, is not a test.

Each scene is built both ways with the default flags (-march=native) and run with the same
options, without output, the two variants interleaved (A B A B ...), --rounds times. Measured:
the process's CPU time (user + system) of a long and a short run (the loop's CPU = long -
short: the set-up and the first step cancel), and the time loop's wall seconds of the long
run's `done:` line. The minimum over the rounds and the ratio uniform / per particle are
printed; the load average before and after (the figures are ratios of interleaved runs on a
shared machine).

Scenes:
  cube           bench/cube.sph, 103,823 particles, 25 steps (short: 1)
  dambreak       examples/dambreak.sph with its own effects, 1,500 steps (short: 1)
  dambreak-pysph the same with PySPH's effects (-D density_diffusion=off -D shifting=off
                 --set cfl=0.3), 1,500 steps (short: 1)

Usage: python3 bench/uniform_h.py [--scenes cube,dambreak,dambreak-pysph] [--rounds 5]
       [--sphc build/bin/sphc] [--threads N (an OpenMP build on N threads)]
"""

import argparse
import os
import re
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from common import ROOT, SCENE_FILES, load_average, remove_tmp, run  # noqa: E402

# scene: (file, sphc flags, run-time options, short steps, long steps); a tf past the steps
SCENES = {
    "cube": (SCENE_FILES["cube"], [], ["--tf", "1"], 1, 25),
    "dambreak": (SCENE_FILES["dambreak"], [], ["--tf", "10"], 1, 1500),
    "dambreak-pysph": (SCENE_FILES["dambreak"], ["-D", "density_diffusion=off", "-D", "shifting=off"],
                       ["--set", "cfl=0.3", "--tf", "10"], 1, 1500),
}
VARIANTS = [("per-particle", ["--no-uniform-h"]), ("uniform", [])]
DONE_RE = re.compile(r"done: t=\S+ after (\d+) steps.*?, ([0-9.eE+-]+) s,")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sphc", default=os.path.join(ROOT, "build", "bin", "sphc"))
    ap.add_argument("--scenes", default="cube,dambreak,dambreak-pysph")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--threads", type=int, default=0, help="an OpenMP build on N threads")
    ap.add_argument("--keep", action="store_true")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="sphc_uniform_h_")
    print("load average before: %s" % load_average())
    omp = ["--backend=openmp"] if args.threads else []
    env = dict(os.environ, OMP_NUM_THREADS=str(args.threads or 1), OMP_WAIT_POLICY="passive")
    threads = ["--threads", str(args.threads)] if args.threads else []
    for scene in args.scenes.split(","):
        path, flags, options, short, long_ = SCENES[scene]
        exes = {}
        for name, vflags in VARIANTS:
            exes[name] = os.path.join(tmp, "%s_%s" % (scene, name))
            run([args.sphc, path, "-o", exes[name]] + flags + omp + vflags)
        cpu = {name: [] for name, _ in VARIANTS}
        loop = {name: [] for name, _ in VARIANTS}
        for r in range(args.rounds):
            for name, _ in VARIANTS:
                c = []
                for steps in (short, long_):
                    _, out = run([exes[name]] + options + threads +
                                 ["--max-steps", str(steps), "--output-every", "0",
                                  "-d", exes[name] + "_out"], env=env)
                    c.append(run.cpu)
                m = DONE_RE.search(out)
                if not m or int(m.group(1)) != long_:
                    sys.stderr.write("no `done:` line after %d steps:\n%s\n" % (long_, out[-2000:]))
                    raise SystemExit(1)
                cpu[name].append(c[1] - c[0])
                loop[name].append(float(m.group(2)))
                print("%-15s %-13s round %d: loop CPU %.4f s, loop wall (done:) %.4f s"
                      % (scene, name, r + 1, cpu[name][-1], loop[name][-1]))
                sys.stdout.flush()
        a, b = VARIANTS[0][0], VARIANTS[1][0]
        print("%-15s min of %d: CPU %s %.4f s, %s %.4f s: %.3fx; done: %s %.4f s, %s %.4f s: %.3fx"
              % (scene, args.rounds, a, min(cpu[a]), b, min(cpu[b]), min(cpu[b]) / min(cpu[a]),
                 a, min(loop[a]), b, min(loop[b]), min(loop[b]) / min(loop[a])))
        print("%-15s CPU ranges: %s %.4f-%.4f s, %s %.4f-%.4f s" % (
            scene, a, min(cpu[a]), max(cpu[a]), b, min(cpu[b]), max(cpu[b])))
        sys.stdout.flush()
    print("load average after: %s" % load_average())
    remove_tmp(tmp, args.keep)


if __name__ == "__main__":
    main()
