#!/usr/bin/env python3
"""A roofline point for the main interaction loop of the generated solvers: prints figures,
is not a test.

For each scene (the 3D cube and the 2D dam break by default):

  flops per pair   counted, not estimated: the solver is built for AVX2 + FMA
                   (`--cxxflags "... -march=x86-64-v3 -no-pie"`: valgrind 3.19 cannot run
                   AVX-512), run under `valgrind --tool=callgrind --dump-instr=yes` for S1 and
                   S2 steps; every executed instruction of the interaction function
                   (`group_*` with the most instructions) is matched to its mnemonic
                   (objdump) and counted as floating-point operations: add, sub, mul, div,
                   sqrt 1 per lane, FMA 2 per lane (scalar sd: 1 lane; xmm: 2, ymm: 4 doubles);
                   the difference of the two runs divided by S2 - S1 is the count per step, and
                   divided by the pairs within the support per step (KD-tree count of
                   bench/pair_rate.py) the count per pair (neighbour candidates rejected by the
                   distance test included: their flops are part of the loop's work). The pairs
                   are ordered (i, j) and (j, i): where the loop evaluates each pair once for
                   both particles (symmetric pairs) one evaluation covers two of them;
  time of the loop the default (-march=native) serial solver at the benchmark size, `perf
                   record -e cpu-clock` of two runs (2 and 2 + N steps): the difference of
                   the function's samples / the sampling rate = its CPU seconds in N steps
                   (set-up and the first neighbour-list build left out);
  achieved rate    flops per step x steps / time of the loop, against the core's FP64 peak,
                   two ways: MEASURED (since stop 44; the one the target reads) by
                   bench/fma_peak.cpp, fused multiply-adds on 12 independent chains of zmm,
                   ymm and scalar registers, by CPU time, best of 7, with the clock from a
                   chain of dependent integer adds; and NOMINAL, clock (/proc/cpuinfo "cpu
                   MHz": on a VM the TSC rate, not the clock the cores run at) x FMA units (2,
                   assumed) x 2 flops x doubles per vector (AVX2: 4; AVX-512: 8 where the flags
                   show avx512f) -- each printed for scalar, AVX2 and AVX-512 code;
  memory           bytes per step the loop must move at least (each property array it reads
                   once, each it writes twice: read and write back; 8 bytes per particle
                   each, from the generated C++; with kept neighbour lists also the entries
                   it walks, s_idx >= d_idx: half the pairs within (1 + 0.1) 2h, 4 bytes
                   each, and 24 bytes of vector per particle), against the STREAM-triad bandwidth measured
                   by bench/stream_triad.cpp: arithmetic intensity = flops / bytes, and the
                   time those bytes take at the measured bandwidth.

Usage: python3 bench/roofline.py [--scenes cube,dambreak2d] [--sphc build/bin/sphc] [--keep]
                                  [--count-flags=--simd-pairs=off] [--time-flags=OPTS]
Needs valgrind, objdump (binutils), perf (linux-perf; without it the callgrind instruction
share stands in for the time share), scipy, h5py.
"""

import argparse
import collections
import os
import re
import subprocess
import sys
import tempfile

HZ = 1000   # perf's sampling rate (cpu-clock)
PERF_SHORT = 2   # steps of the short perf run (its samples are subtracted)
SKIN = 0.1   # the kept lists' skin of --verlet-skin=auto: lists hold the pairs within (1 + SKIN) 2h
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import pair_rate  # noqa: E402
from pair_rate import SCENES, last_positions, pairs_per_step, run  # noqa: E402
from common import remove_tmp  # noqa: E402

# scene: (parameters of the counted run, parameters of the timed run, steps S1, S2, timed
# steps, h of the counted run, h of the timed run)
SIZES = {
    "cube": (["--set", "nx=20"], ["--tf", "1"], 1, 3, 10, 1.5 / 20, 1.5 / 47),
    "dambreak2d": (["--set", "dx=0.03"], ["--set", "dx=0.0047"], 1, 3, 30, 1.3 * 0.03,
                   1.3 * 0.0047),
    "dambreak3d_dualsphysics": (["--set", "dp=0.02"], [], 1, 3, 5, 3 ** 0.5 * 0.02,
                                3 ** 0.5 * 0.0085),
}

FMA_RE = re.compile(r"^vf(n?m(add|sub)|maddsub|msubadd)(132|213|231)?(s|p)(d|s)$")
ARITH_RE = re.compile(r"^v?(add|sub|mul|div|sqrt)(s|p)(d|s)$")


def flops_of(mnemonic, operands):
    """FP64 (or FP32) operations of one instruction."""
    m = FMA_RE.match(mnemonic)
    per = 2 if m else 1
    if not m:
        m = ARITH_RE.match(mnemonic)
        if not m:
            return 0
    scalar = m.group(m.lastindex - 1) == "s"
    double = m.group(m.lastindex) == "d"
    if scalar:
        return per
    width = 512 if "zmm" in operands else 256 if "ymm" in operands else 128
    return per * width // (64 if double else 32)


def disassemble(exe):
    """{address: (function, mnemonic, flops)} of the executable's text."""
    out = subprocess.run(["objdump", "-d", "--no-show-raw-insn", "-C", exe],
                         stdout=subprocess.PIPE, universal_newlines=True).stdout
    table = {}
    fn = None
    for line in out.splitlines():
        h = re.match(r"^([0-9a-f]+) <(.*)>:$", line)
        if h:
            fn = h.group(2)
            continue
        m = re.match(r"^\s+([0-9a-f]+):\s+(\S+)\s*(.*)$", line)
        if m and fn:
            mn = m.group(2)
            table[int(m.group(1), 16)] = (fn, mn, flops_of(mn, m.group(3)))
    return table


def callgrind_counts(path):
    """{address: executed count} of a callgrind file written with --dump-instr=yes
    --compress-pos=no --compress-strings=no --dump-line=no (self costs only)."""
    counts = collections.Counter()
    skip = False
    with open(path) as f:
        for line in f:
            if line.startswith("calls="):
                skip = True   # the next line is the call's inclusive cost
                continue
            if line.startswith("0x"):
                if skip:
                    skip = False
                    continue
                a, c = line.split()[:2]
                counts[int(a, 16)] += int(c)
            else:
                skip = False if not line.startswith("calls=") else skip
    return counts


def per_function(table, counts):
    """{function: [instructions, flops]}."""
    res = collections.defaultdict(lambda: [0, 0])
    for a, c in counts.items():
        t = table.get(a)
        if t is None:
            continue
        res[t[0]][0] += c
        res[t[0]][1] += c * t[2]
    return res


def peak():
    flags, mhz, model = set(), None, "unknown CPU"
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("flags") and not flags:
                flags = set(line.split(":", 1)[1].split())
            elif line.startswith("cpu MHz") and mhz is None:
                mhz = float(line.split(":", 1)[1])
            elif line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
    ghz = (mhz or 0) / 1000
    p = {"scalar": ghz * 2 * 2 * 1}
    if "avx2" in flags and "fma" in flags:
        p["AVX2"] = ghz * 2 * 2 * 4
    if "avx512f" in flags:
        p["AVX-512"] = ghz * 2 * 2 * 8
    return model, ghz, p


def measured_peak(tmp, env):
    """The FP64 FMA throughput of one core and its clock, measured by bench/fma_peak.cpp:
    ({"scalar": GFLOP/s, "AVX2": ..., "AVX-512": ...}, clock in GHz)."""
    exe = os.path.join(tmp, "fma_peak")
    run(["c++", "-O2", "-march=native", os.path.join(HERE, "fma_peak.cpp"), "-o", exe])
    out, _, _ = run([exe], env)
    p = {}
    for key, name in (("scalar", "scalar"), ("AVX2", "ymm"), ("AVX-512", "zmm")):
        m = re.search(r"fma_GFLOPs_%s=([0-9.]+)" % name, out)
        if m:
            p[key] = float(m.group(1))
    return p, float(re.search(r"clock_GHz=([0-9.]+)", out).group(1))


def bytes_per_particle(sphc, scene, tmp):
    """Property arrays the interaction function touches, from the generated C++:
    (read-only arrays, written arrays, whether it keeps neighbour lists), counted per
    destination particle."""
    src = os.path.join(ROOT, SCENES[scene][0])
    env = dict(os.environ)
    env.setdefault("SPHC_CACHE_DIR", os.path.join(tmp, "cache"))
    cpp = subprocess.run([sphc, src, "--emit=cpp"] + SCENES[scene][1], env=env,
                         stdout=subprocess.PIPE, universal_newlines=True).stdout
    # The interaction group: the group_* function whose body has neighbour loops.
    bodies = re.split(r"\n  void ", cpp)
    best = None
    def loops(b):   # neighbour loops of a function body: cell lists or kept lists
        return b.count("for_each_candidate") + b.count("gather_neighbours")
    for b in bodies:
        if b.startswith("group_") and loops(b):
            if best is None or loops(b) > loops(best):
                best = b
    if best is None:
        return None
    reads, writes = set(), set()
    for m in re.finditer(r"(const )?double\* (\w+) = (\w+)\.f64\((\w+)::(\w+)\)", best):
        key = (m.group(3), m.group(5))
        (reads if m.group(1) else writes).add(key)
    reads -= writes
    return reads, writes, "gather_neighbours" in best


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sphc", default=os.path.join(ROOT, "build", "bin", "sphc"))
    ap.add_argument("--scenes", default="cube,dambreak2d")
    ap.add_argument("--keep", action="store_true")
    ap.add_argument("--count-flags", default="",
                    help="sphc options of the counted (callgrind) build only, e.g. "
                    "'--simd-pairs=off': the flops of the scalar loops, i.e. the useful "
                    "arithmetic per pair, where the default counts every executed lane "
                    "(a SIMD loop's masked tail lanes included); the timed build is the "
                    "default either way")
    ap.add_argument("--time-flags", default="",
                    help="sphc options of the timed (native) build only, e.g. "
                    "'--cluster-3d-2xmm' (stop 42): another form's loop time over the same "
                    "counted flops")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="sphc-roofline-")
    env = dict(os.environ)
    env.setdefault("SPHC_CACHE_DIR", os.path.join(tmp, "cache"))
    model, ghz, peaks = peak()
    rows = []
    try:
        mpeaks, mghz = measured_peak(tmp, dict(env, OMP_NUM_THREADS="1"))
        triad = os.path.join(tmp, "triad")
        run(["c++", "-O3", "-march=native", "-fopenmp", os.path.join(HERE, "stream_triad.cpp"),
             "-o", triad])
        bw = {}
        for t in (1, 2):
            e = dict(env, OMP_NUM_THREADS=str(t))
            out, _, _ = run([triad], e)
            bw[t] = float(re.search(r"triad_GBps=([0-9.]+)", out).group(1))
        for scene in args.scenes.split(","):
            counted, timed, s1, s2, tsteps, h_counted, h_timed = SIZES[scene]
            src = os.path.join(ROOT, SCENES[scene][0])
            exe = os.path.join(tmp, scene + "_avx2")
            print("%s: counting flops under callgrind (%d and %d steps) ..." % (scene, s1, s2),
                  flush=True)
            run([args.sphc, src, "-o", exe, "--cxxflags",
                 "-std=c++17 -O3 -march=x86-64-v3 -fno-math-errno -ffp-contract=off -no-pie"]
                + SCENES[scene][1] + args.count_flags.split(), env)
            table = disassemble(exe)
            funcs = {}
            outdir = os.path.join(tmp, scene + "-cg-out")
            for s in (s1, s2):
                cg = os.path.join(tmp, "%s-%d.cg" % (scene, s))
                cmd = ["valgrind", "--tool=callgrind", "--dump-instr=yes", "--compress-pos=no",
                       "--compress-strings=no", "--dump-line=no", "--callgrind-out-file=" + cg,
                       exe, "--max-steps", str(s), "--quiet"] + counted
                cmd += (["-d", outdir, "--output-every", "1e9"] if s == s2 else ["--no-output"])
                run(cmd, env)
                funcs[s] = per_function(table, callgrind_counts(cg))
            cands = [f for f in funcs[s2] if "::group_" in f]
            loop_fn = max(cands, key=lambda f: funcs[s2][f][0])
            d_ins = (funcs[s2][loop_fn][0] - funcs[s1][loop_fn][0]) / (s2 - s1)
            d_fl = (funcs[s2][loop_fn][1] - funcs[s1][loop_fn][1]) / (s2 - s1)
            pos = last_positions(outdir, scene)
            pairs_small, _ = pairs_per_step(pos, h_counted, SCENES[scene][4], SCENES[scene][3])
            fpp = d_fl / pairs_small
            ipp = d_ins / pairs_small
            # Timed run: default (native) build at the benchmark size, perf for the share.
            print("%s: timing %d steps (perf record) ..." % (scene, tsteps), flush=True)
            nexe = pair_rate.build(args.sphc, scene, tmp, sphc_opts=args.time_flags.split())
            tout = os.path.join(tmp, scene + "-timed")
            e = dict(env, OMP_NUM_THREADS="1")
            short = re.search(r"group_\w+", loop_fn).group(0)
            # Two runs, PERF_SHORT and PERF_SHORT + tsteps steps: the difference of the
            # function's samples leaves out its evaluations outside the time loop (set-up)
            # and the first neighbour-list build.
            samples, share = {}, 0.0
            for n_steps in (PERF_SHORT, PERF_SHORT + tsteps):
                pdata = os.path.join(tmp, "%s-%d.perf" % (scene, n_steps))
                out, _, _ = run(["perf", "record", "-q", "-e", "cpu-clock", "-F", str(HZ),
                                 "-o", pdata, nexe, "--max-steps", str(n_steps), "--timing",
                                 "--quiet", "-d", tout, "--output-every", "1e9"] + timed, e)
                rep = subprocess.run(["perf", "report", "-i", pdata, "--stdio", "-n",
                                      "--sort", "symbol"],
                                     stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                     universal_newlines=True).stdout
                share, samples[n_steps] = 0.0, 0
                for line in rep.splitlines():
                    mm = re.match(r"^\s+([0-9.]+)%\s+(\d+)\s.*\b" + re.escape(short) + r"\b",
                                  line)
                    if mm:
                        share += float(mm.group(1)) / 100
                        samples[n_steps] += int(mm.group(2))
            m = pair_rate.TIMING_RE.search(out)
            steps, npart, loop = tsteps, int(m.group(2)), float(m.group(3))
            # CPU seconds in the function over the tsteps steps: its cpu-clock samples / the
            # sampling rate (on a shared machine the wall time counts the other jobs' time too).
            t_cpu = (samples[PERF_SHORT + tsteps] - samples[PERF_SHORT]) / HZ
            tpos = last_positions(tout, scene)
            pairs, nb = pairs_per_step(tpos, h_timed, SCENES[scene][4], SCENES[scene][3])
            t_loop = t_cpu
            gflops = fpp * pairs * steps / t_loop / 1e9 if t_loop > 0 else float("nan")
            rw = bytes_per_particle(args.sphc, scene, tmp)
            # The kept lists the loop reads per step: the entries s_idx >= d_idx (half of the
            # pairs within the lists' radius), 4 bytes each, and a vector header (24 bytes) per
            # destination particle; only when the function keeps lists.
            list_pairs, _ = pairs_per_step(tpos, h_timed, SCENES[scene][4],
                                           SCENES[scene][3] * (1 + SKIN))
            list_bytes = (4 * list_pairs / 2 + 24 * npart) if rw and rw[2] else 0
            nbytes = None
            if rw:
                nbytes = (8 * (len(rw[0]) + 2 * len(rw[1])) * npart + list_bytes) * steps
            rows.append(dict(scene=scene, fn=short, fpp=fpp, ipp=ipp, particles=npart,
                             pairs=pairs, nb=nb, steps=steps, loop=loop, share=share,
                             t_loop=t_loop, gflops=gflops, nbytes=nbytes, rw=rw))
    finally:
        remove_tmp(tmp, args.keep)

    print()
    print("%s; FP64 peak per core:" % model)
    print("  measured (bench/fma_peak.cpp, FMA throughput; clock %.2f GHz by dependent integer"
          " adds; the target reads these): %s" % (mghz, ", ".join(
              "%s %.1f GFLOP/s (%.1f flops/cycle)" % (k, v, v / mghz)
              for k, v in mpeaks.items())))
    print("  nominal (/proc/cpuinfo %.3f GHz x 2 FMA units x 2 flops x lanes): %s"
          % (ghz, ", ".join("%s %.1f GFLOP/s" % (k, v) for k, v in peaks.items())))
    print("STREAM triad (bench/stream_triad.cpp): %.2f GB/s on 1 thread, %.2f GB/s on 2"
          % (bw[1], bw[2]))
    print()
    for r in rows:
        print("== %s: interaction function %s" % (r["scene"], r["fn"]))
        print("  counted (callgrind, AVX2 build%s): %.1f flops and %.0f instructions per pair "
              "within the support" % (", sphc " + args.count_flags if args.count_flags else "",
                                      r["fpp"], r["ipp"]))
        print("  timed: %d particles, %d steps, %.0f pairs/step (%s neighbours per destination),"
              " loop %.2f s wall; the function: %.1f%% of the samples, %.3f s CPU"
              % (r["particles"], r["steps"], r["pairs"],
                 ", ".join("%s %.1f" % kv for kv in r["nb"].items()), r["loop"],
                 100 * r["share"], r["t_loop"]))
        print("  achieved %.2f GFLOP/s = %s of the measured peak; %s of the nominal"
              % (r["gflops"], ", ".join("%.1f%% of %s" % (100 * r["gflops"] / v, k)
                                        for k, v in mpeaks.items()),
                 ", ".join("%.1f%% of %s" % (100 * r["gflops"] / v, k)
                           for k, v in peaks.items())))
        if r["nbytes"]:
            ai = r["fpp"] * r["pairs"] * r["steps"] / r["nbytes"]
            bwmax = max(bw.values())
            need = r["nbytes"] / (bwmax * 1e9)
            print("  memory: %d arrays read-only, %d read/write (const / non-const in the"
                  " function; each once per particle) and the kept lists: %.1f MB per step;"
                  " intensity %.1f flop/byte; at %.2f GB/s those bytes take %.3f s of the"
                  " %.3f s (%.0f%%)" % (len(r["rw"][0]), len(r["rw"][1]),
                                         r["nbytes"] / r["steps"] / 1e6, ai, bwmax, need,
                                         r["t_loop"], 100 * need / r["t_loop"]))
            ridge = mpeaks.get("AVX2", mpeaks.get("scalar", 0)) / bwmax
            print("  roofline: ridge point (AVX2 peak / measured bandwidth) %.1f flop/byte; the"
                  " loop is %s" % (ridge, "compute-side (latency / instruction bound)"
                                   if ai > ridge else "memory-side"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
