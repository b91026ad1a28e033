#!/usr/bin/env python3
"""Where the time of an OpenMP solver goes on N threads, measured so that other processes on
the machine matter little: the per-thread CPU time of every parallel region and the calling
thread's CPU time between them.

    python3 bench/omp_critical_path.py SCENE.sph [--threads 2] [--sphc PATH] [-D k=v]
        [--keep DIR] -- SOLVER_ARGS...

It prints the generated solver (`sphc --backend=openmp --emit=cpp`, one unit), wraps each
`#pragma omp parallel for` loop and each `#pragma omp parallel` region of it so that every
thread adds its CPU time in the region (CLOCK_THREAD_CPUTIME_ID) to a counter of that region,
builds it with the command `sphc -v` shows and runs it with SOLVER_ARGS (e.g. --max-steps 100
--no-output). Per region: calls, the threads' CPU summed, the largest thread's per call
summed ("max"), and max - sum / threads ("imbalance"). Then the calling thread's CPU outside
the regions (from the first region on: the work on one thread, the runtime's own parallel
loops counted there too) and the model speed-up

    (sum of all regions + outside) / (sum of the regions' max + outside),

the 2-thread speed-up the schedule allows where each thread has a core of its own and the
work per thread is the same as measured (it leaves out the wake-ups of the regions and any
slowdown of each thread by the other, e.g. shared cache or memory bandwidth). CPU time is
what a thread ran, so a loaded machine changes it much less than wall time (not at all
only where the other jobs do not share the caches). The solver must not write snapshots
often (each output is outside the regions).
"""

import argparse
import os
import re
import shlex
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

HEADER = r'''
#include <time.h>
#include <omp.h>
#include <cstdio>
namespace sphc_instr {  // bench/omp_critical_path.py
inline double tcpu() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}
constexpr int R = %(regions)d, T = 64;
inline double cur[R][T], smax[R], ssum[R], calls[R];
inline const char* names[R] = {%(names)s};
inline double t0sum = 0, first = -1;
inline void enter(int r) {
  if (first < 0) first = tcpu();
  for (int t = 0; t < T; ++t) cur[r][t] = 0;
}
inline void add(int r, double v) {
  const int t = omp_get_thread_num();
  cur[r][t < T ? t : T - 1] += v;
  if (t == 0) t0sum += v;
}
inline void leave(int r) {
  double mx = 0, s = 0;
  for (int t = 0; t < T; ++t) { mx = cur[r][t] > mx ? cur[r][t] : mx; s += cur[r][t]; }
  smax[r] += mx; ssum[r] += s; calls[r] += 1;
}
struct Dump {
  ~Dump() {
    for (int r = 0; r < R; ++r)
      if (calls[r] > 0)
        std::fprintf(stderr, "instr-region %%d %%.0f %%.6f %%.6f %%s\n", r, calls[r], ssum[r], smax[r], names[r]);
    std::fprintf(stderr, "instr-outside %%.6f threads %%d\n", first < 0 ? 0.0 : tcpu() - first - t0sum, omp_get_max_threads());
  }
};
inline Dump dump_;
}  // namespace sphc_instr
'''


def indent(s):
    return len(s) - len(s.lstrip())


def code(s):
    return s.split("//")[0].rstrip()


def instrument(lines):
    """The lines with every parallel loop and region timed per thread; the regions' names."""
    out, names = [], []
    func, label = "?", ""
    i = 0
    while i < len(lines):
        line = lines[i]
        m = re.match(r"\s*(?:void|double|bool|int|long) (\w+)\(.*\{\s*$", line)
        if m:
            func = m.group(1)
        c = re.search(r"//\s*(neighbours: [^,(]*|destination \w+|\(\d\)[^\n]*|fluid: .*|\w+: \w+\.\w+.*)$", line)
        if c:
            label = c.group(1).strip()[:40]
        m = re.match(r"(\s*)#pragma omp parallel for(.*)$", line)
        if m and lines[i + 1].lstrip().startswith("for ("):
            ind, clauses = m.group(1), m.group(2)
            head = lines[i + 1]
            j = i + 1
            if code(head).endswith("{"):
                j = i + 2
                while not (indent(lines[j]) == indent(head) and lines[j].strip().startswith("}")):
                    j += 1
            sched = re.search(r"schedule\([^)]*\)", clauses)
            reds = re.findall(r"reduction\([^)]*\)", clauses)
            rest = re.sub(r"schedule\([^)]*\)|reduction\([^)]*\)", "", clauses)
            body = "\n".join(lines[i + 1:j + 1])
            kind = ("initialize" if "// initialize" in head else "post_loop" if "// post_loop" in head
                    else "pairs, each once (blocks)" if "for (int blk" in head
                    else "pairs (lists built in the loop)" if "gather_neighbours" in body and "k_nbr" in body
                    else "kept lists' build" if "gather_neighbours" in body
                    else "upper starts" if "upper_start" in head
                    else "hoisted, per source" if "for (int s_idx" in head
                    else "dest.-only values" if "dhoisted" in body
                    else "pairs" if "kept" in body or "neighbours(" in body
                    else "reduction" if reds else "loop")
            names.append("%s:%d %s: %s" % (func, i + 1, label, kind))
            rid = len(names) - 1
            out.append(ind + "{ const int rid_ = %d; sphc_instr::enter(rid_);" % rid)
            out.append(ind + "#pragma omp parallel" + rest)
            out.append(ind + "{ const double c0_ = sphc_instr::tcpu();")
            out.append(ind + "#pragma omp for " + " ".join(([sched.group(0)] if sched else []) + reds))
            out.extend(lines[i + 1:j + 1])
            out.append(ind + "sphc_instr::add(rid_, sphc_instr::tcpu() - c0_); }")
            out.append(ind + "sphc_instr::leave(rid_); }")
            i = j + 1
            continue
        m = re.match(r"(\s*)#pragma omp parallel( .*)?$", line)
        if m and lines[i + 1].strip() == "{":
            j = i + 2
            while not (indent(lines[j]) == indent(lines[i + 1]) and lines[j].strip().startswith("}")):
                j += 1
            # A destination's loops without neighbours in one region (codegen/OmpRegions.cpp,
            # stop 46), a pass of two arrays' blocks with its spanning particles: named by the
            # pass, as their loops were.
            if "in one parallel region" in lines[i - 1] + lines[i - 2]:
                names.append("%s:%d %s: loops without neighbours (one region)" % (func, i + 1, label))
            elif "shared(cells, spanning)" in line:
                names.append("%s:%d %s: pairs of two arrays (blocks, spanning)" % (func, i + 1, label))
            else:
                names.append("%s:%d region" % (func, i + 1))
            rid = len(names) - 1
            out.append(m.group(1) + "{ const int rid_ = %d; sphc_instr::enter(rid_);" % rid)
            out.append(line)
            out.append(lines[i + 1] + " const double c0_ = sphc_instr::tcpu();")
            out.extend(lines[i + 2:j])
            out.append(m.group(1) + "sphc_instr::add(rid_, sphc_instr::tcpu() - c0_); }")
            out.append(m.group(1) + "sphc_instr::leave(rid_); }")
            i = j + 1
            continue
        out.append(line)
        i += 1
    last_include = max(k for k, l in enumerate(out) if l.startswith("#include"))
    header = HEADER % {"regions": max(1, len(names)),
                       "names": ", ".join('"%s"' % n.replace('"', "'") for n in names)}
    out.insert(last_include + 1, header)
    return out, names


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--sphc", default=os.path.join(ROOT, "build", "bin", "sphc"))
    ap.add_argument("-D", action="append", default=[], help="a compile-time option of the scene")
    ap.add_argument("--sphc-arg", action="append", default=[], help="another sphc option")
    ap.add_argument("--keep", help="directory for the instrumented source and solver")
    ap.add_argument("--top", type=int, default=12, help="regions listed (by max)")
    argv = sys.argv[1:]
    cut = argv.index("--") if "--" in argv else len(argv)
    a = ap.parse_args(argv[:cut])
    args = argv[cut + 1:]
    work = a.keep or tempfile.mkdtemp(prefix="omp_cp_")
    os.makedirs(work, exist_ok=True)
    sphc = [a.sphc, a.scene, "--backend=openmp"] + sum((["-D", d] for d in a.D), []) + a.sphc_arg
    src = subprocess.run(sphc + ["--emit=cpp"], check=True, stdout=subprocess.PIPE,
                         universal_newlines=True).stdout.split("\n")
    lines, names = instrument(src)
    cpp = os.path.join(work, "scene_instr.cpp")
    with open(cpp, "w") as f:
        f.write("\n".join(lines))
    # The build command of this scene (one unit), with the instrumented source.
    v = subprocess.run(sphc + ["--single-unit", "--no-cache", "-v", "-o", os.path.join(work, "plain")],
                       check=True, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       universal_newlines=True).stdout
    cmd = next(l for l in v.split("\n") if " -fopenmp " in l and re.search(r"scene[.\w]*\.cpp", l))
    cmd = shlex.split(cmd)
    cmd = [cpp if re.search(r"scene[.\w]*\.cpp$", c) else c for c in cmd]
    exe = os.path.join(work, "solver_instr")
    cmd[cmd.index("-o") + 1] = exe
    subprocess.run(cmd, check=True)
    env = dict(os.environ)
    env.setdefault("OMP_WAIT_POLICY", "passive")
    r = subprocess.run([exe, "--threads", str(a.threads), "--quiet", "-d",
                        os.path.join(work, "out")] + args, env=env, stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, universal_newlines=True)
    if r.returncode != 0:
        sys.exit(r.stdout)
    regions, outside, threads = [], 0.0, a.threads
    for l in r.stdout.split("\n"):
        if l.startswith("instr-region "):
            _, rid, calls, s, mx, name = l.split(" ", 5)
            regions.append((name, float(calls), float(s), float(mx)))
        elif l.startswith("instr-outside "):
            parts = l.split()
            outside, threads = float(parts[1]), int(parts[3])
    total_sum = sum(x[2] for x in regions)
    total_max = sum(x[3] for x in regions)
    print("%s, %d threads, solver %s" % (a.scene, threads, " ".join(args)))
    print("%-80s %7s %9s %9s %9s" % ("region (function:line of the --emit=cpp, label)", "calls",
                                      "CPU sum", "max", "imbal."))
    for name, calls, s, mx in sorted(regions, key=lambda x: -x[3])[:a.top]:
        print("%-80s %7.0f %9.3f %9.3f %9.3f" % (name, calls, s, mx, mx - s / threads))
    print("%-80s %7s %9.3f %9.3f %9.3f" % ("all %d regions" % len(regions), "", total_sum,
                                           total_max, total_max - total_sum / threads))
    print("calling thread outside the regions [s CPU]: %.3f (%.1f%% of the work)"
          % (outside, 100.0 * outside / max(1e-12, total_sum + outside)))
    print("model speed-up on %d threads: %.2fx (regions' imbalance alone: %.2fx, one-thread part alone: %.2fx)"
          % (threads, (total_sum + outside) / max(1e-12, total_max + outside),
             (total_sum + outside) / max(1e-12, total_max + outside - (total_max - total_sum / threads)),
             (total_sum + outside) / max(1e-12, total_sum / threads + outside)))
    print("load average: %.2f %.2f %.2f" % os.getloadavg())


if __name__ == "__main__":
    main()
