#!/usr/bin/env python3
"""Where a cluster-pair tile pass's time goes (docs/performance-log.md, "The tiles' per-evaluation
pieces (stop 39)").

Prints the scene's C++ (`sphc SCENE --emit=cpp ...`), puts timers between the pieces of every
tile pass (the destination-only values, the largest h, the layout at a rebuild, the positions'
gather (with the boxes since stop 39), the boxes, the outer list at a rebuild, the pruning, the other gathers
(and the hoisted values computed in slot order since stop 39), the tiles, the sums added back), builds it with the flags and libraries sphc builds the scene with (`sphc -v`),
runs it and prints per piece the wall and process CPU time (all threads), per evaluation and in
all, and their shares of the tile passes.

  bench/tile_pieces.py --sphc build/bin/sphc bench/cube.sph --backend=openmp \
      -- --tf 1 --max-steps 25 --no-output --threads 2

Arguments before `--` go to sphc (the scene first), after it to the solver. The timers cost a
clock_gettime (wall) and one of the process CPU clock per piece (a system call, ~0.3 us).
"""
import argparse
import os
import re
import shlex
import subprocess
import sys
import tempfile

PIECES = ["dvalues", "hmax", "layout", "gpos", "boxes", "outer", "prune", "gathers", "tiles", "add"]

# The lines of a tile pass that end a piece: the piece's timer stops after such a line (ENDS_AFTER)
# or before it (ENDS_BEFORE). The layout (its rebuilds counted) and the sums added back (after the
# last add_slots) are instrumented in instrument() itself.
ENDS_AFTER = [
    ("sphc::ClusterLayout& cl_layout =", "dvalues"),
    ("for (int i = 0; i < n; ++i) cl_hmax", "hmax"),
    ("sphc::gather_positions(", "gpos"),
    ("sphc::gather_positions_boxes(", "gpos"),
    ("sphc::update_boxes(", "boxes"),
    ("if (verlet_build) sphc::build_cluster_pairs(", "outer"),
    ("sphc::prune_cluster_pairs(", "prune"),
]
ENDS_BEFORE = [
    # the copies (and, since stop 39, the hoisted values in slot order) end here
    ("#if defined(__GNUC__) && !defined(__clang__)", "gathers"),
    ("// The slot sums onto the particles' sums", "tiles"),
]

PRELUDE = r"""
#include <time.h>
#include <cstdio>
namespace sphc_tp {
inline double wall_now() { timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }
inline double cpu_now() { timespec t; clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }
static const char* const names[] = {%(names)s};
constexpr int N = %(n)d;
struct Acc {
  double wall[N] = {}, cpu[N] = {};
  long count[N] = {};
  double lw = 0, lc = 0;
  long evals = 0, builds = 0;
  void start() { lw = wall_now(); lc = cpu_now(); ++evals; }
  void lap(int k) {
    const double w = wall_now(), c = cpu_now();
    wall[k] += w - lw; cpu[k] += c - lc; ++count[k]; lw = w; lc = c;
  }
  ~Acc() {
    double tw = 0, tc = 0;
    for (int k = 0; k < N; ++k) tw += wall[k], tc += cpu[k];
    std::fprintf(stderr, "tile_pieces: %%ld tile pass evaluations, %%ld rebuilds\n", evals, builds);
    std::fprintf(stderr, "tile_pieces: %%-8s %%10s %%10s %%7s %%10s %%10s %%7s %%6s\n", "piece", "wall s", "ms/eval", "wall%%", "cpu s", "ms/eval", "cpu%%", "count");
    for (int k = 0; k < N; ++k)
      std::fprintf(stderr, "tile_pieces: %%-8s %%10.4f %%10.4f %%6.1f%%%% %%10.4f %%10.4f %%6.1f%%%% %%6ld\n", names[k], wall[k],
                   evals ? 1e3 * wall[k] / evals : 0.0, tw > 0 ? 100 * wall[k] / tw : 0.0, cpu[k],
                   evals ? 1e3 * cpu[k] / evals : 0.0, tc > 0 ? 100 * cpu[k] / tc : 0.0, count[k]);
    std::fprintf(stderr, "tile_pieces: %%-8s %%10.4f %%10.4f %%7s %%10.4f %%10.4f\n", "all", tw, evals ? 1e3 * tw / evals : 0.0, "", tc, evals ? 1e3 * tc / evals : 0.0);
  }
};
static Acc acc;
}  // namespace sphc_tp
"""


def instrument(src):
    idx = {p: k for k, p in enumerate(PIECES)}
    out, n_passes = [], 0
    lines = src.split("\n")
    in_pass = False
    for i, line in enumerate(lines):
        s = line.strip()
        ind = line[: len(line) - len(line.lstrip())]
        lap = lambda p: "%ssphc_tp::acc.lap(%d);  // tile_pieces: %s" % (ind, idx[p], p)
        if s.startswith("// Each pair once for both particles in cluster-pair tiles"):
            out.append(ind + "sphc_tp::acc.start();  // tile_pieces")
            out.append(line)
            in_pass = True
            n_passes += 1
            continue
        if in_pass and s.startswith("if (verlet_build) sphc::build_cluster_layout("):
            out.append(ind + "if (verlet_build) ++sphc_tp::acc.builds;")
            out.append(line)
            out.append(lap("layout"))
            continue
        ends = in_pass and [p for start, p in ENDS_AFTER if s.startswith(start)]
        if ends:
            out.append(line)
            out.append(lap(ends[0]))
            continue
        ends = in_pass and [p for start, p in ENDS_BEFORE if s.startswith(start)]
        if ends:
            out.append(lap(ends[0]))
            out.append(line)
            continue
        if in_pass and s.startswith("sphc::add_slots(") and not lines[i + 1].strip().startswith("sphc::add_slots("):
            out.append(line)
            out.append(lap("add"))
            in_pass = False
            continue
        out.append(line)
    text = "\n".join(out)
    # after the includes: the first line that is not an #include or a comment
    pre = PRELUDE % {"names": ", ".join('"%s"' % p for p in PIECES), "n": len(PIECES)}
    last = [mm.end() for mm in re.finditer(r"^#include[^\n]*\n", text, re.M)][-1]
    text = text[:last] + pre + text[last:]
    return text, n_passes


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sphc", default="build/bin/sphc")
    ap.add_argument("--exe", help="write the solver here (default: a temporary directory)")
    ap.add_argument("--no-run", action="store_true")
    ap.add_argument("args", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    args = a.args
    if "--" in args:
        k = args.index("--")
        sargs, rargs = args[:k], args[k + 1:]
    else:
        sargs, rargs = args, []
    tmp = tempfile.mkdtemp(prefix="tile_pieces.")
    cpp = subprocess.run([a.sphc] + sargs + ["--emit=cpp"], check=True, capture_output=True, text=True).stdout
    text, n = instrument(cpp)
    if n == 0:
        sys.exit("tile_pieces: no tile pass in the generated C++")
    src = os.path.join(tmp, "scene.cpp")
    with open(src, "w") as f:
        f.write(text)
    # sphc's own build commands: its compile flags and its link line.
    v = subprocess.run([a.sphc] + sargs + ["-v", "--no-cache", "-o", os.path.join(tmp, "ref")], check=True,
                       capture_output=True, text=True)
    cmds = [l for l in (v.stdout + v.stderr).split("\n") if " -o " in l and ("c++" in l or "g++" in l)]
    comp = shlex.split([c for c in cmds if " -c " in c][0])
    link = shlex.split([c for c in cmds if " -c " not in c][-1])
    ci = comp.index("-c")
    flags = [f for f in comp[1:ci] if f != "-Og"]
    objs = [t for t in link if t.endswith(".o")]
    exe = a.exe or os.path.join(tmp, "solver")
    obj = os.path.join(tmp, "scene.o")
    subprocess.run([comp[0]] + flags + ["-c", src, "-o", obj], check=True)
    lk = [obj if t == objs[0] else t for t in link if t not in objs[1:]]
    lk[lk.index("-o") + 1] = exe
    subprocess.run(lk, check=True)
    print("tile_pieces: %d tile pass(es) instrumented, solver %s" % (n, exe), flush=True)
    if not a.no_run:
        subprocess.run([exe] + rargs, check=True)


if __name__ == "__main__":
    main()
