#!/usr/bin/env python3
"""SIMD pair loops, measured by hand-edited generated C++ (issue 16; docs/performance-log.md
"SIMD pair loops: measured"): prints figures, is not a test.

For the cube (bench/cube.sph, 3D, 103,823 particles) and the dam break with PySPH's effects
(examples/dambreak.sph -D density_diffusion=off -D shifting=off, --set cfl=0.3, 2D, at
dx = 0.0047: 98,415 particles) the solver's C++ (`sphc --emit=cpp`, serial) is taken in four
forms, of the fluid <- fluid pair loop only:

  sym      each pair once for both particles (today's default), scalar
  ns       per destination (--no-symmetric-pairs), scalar
  ns-simd  per destination: the neighbour loop (the list already filtered to the support) as
           `#pragma omp simd reduction(+: sums)`, the destination's sums in locals, the
           kernel branch-free (its pieces computed, selected on q), the viscosity's branch
           as a select, the source's properties gathered
  sym-simd each pair once: the same over the kept list from s_idx > d_idx (the self pair, whose
           terms are all zero here, left out), the cut-off a mask, the source's sums written
           through masked scatters (distinct s_idx in one list: no conflicts in a vector)

The simd forms are built with the driver's flags plus -fopenmp-simd. For each form: the
vector instructions of the pair loop's function (objdump), the largest difference of the
sums and state against `sym` after N steps (--restartable snapshots; needs h5py), and the
CPU time per step, (long - short run) / steps, interleaved rounds (`/usr/bin/time`): the
minimum and median over the rounds.

The edits are text replacements of the emitted loop: they follow the generated code of the
commit they were written for and stop with an error where it changed.

Usage: python3 bench/simd_pairs.py [--scenes cube,dambreak] [--rounds 5] [--sphc build/bin/sphc]
"""

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from common import ROOT, load_average, print_machine, remove_tmp, run  # noqa: E402

# ---- the edits ---------------------------------------------------------------------------

KERNEL = {
    # CubicSpline, 3D: 1 - 1.5 q^2 (1 - q/2) for q < 1, (2 - q)^3 / 4 for q < 2
    "cube": r'''            const double ih = 1.0 / HIJ;
            const double ihd = ih * ih * ih;
            const double q = RIJ / HIJ;
            const double tq = 2.0 - q;
            const double fq = q < 1.0 ? 1.0 - 1.5 * q * q * (1.0 - 0.5 * q) : (q < 2.0 ? 0.25 * tq * tq * tq : 0.0);
            const double dfq = q < 1.0 ? q * (2.25 * q - 3.0) : (q < 2.0 ? -0.75 * tq * tq : 0.0);
''',
    # WendlandQuintic, 2D: (1 - q/2)^4 (2q + 1) for q < 2
    "dambreak": r'''            const double ih = 1.0 / HIJ;
            const double ihd = ih * ih;
            const double q = RIJ / HIJ;
            const double tq = 1.0 - 0.5 * q, tq2 = tq * tq;
            const double fq = q < 2.0 ? tq2 * tq2 * (2.0 * q + 1.0) : 0.0;
            const double dfq = q < 2.0 ? -5.0 * q * tq * tq * tq : 0.0;
''',
}

COMMON = r'''            const double HIJ = 0.5 * (hi + hj);
            const double RIJ = std::sqrt(R2IJ);
%(kernel)s            const double WIJ = Kernel::sigma * ihd * fq;
            const double dwdq = Kernel::sigma * ihd * dfq;
            const bool rpos = RIJ > 1e-12;
            const double gs = rpos ? dwdq / (HIJ * (rpos ? RIJ : 1.0)) : 0.0;
            const double dwx = gs * xij, dwy = gs * yij%(dwz)s;
            const double RHOIJ1 = 1.0 / (0.5 * (rhoi + sj_rho[s_idx]));
            const double EPS = 0.01 * HIJ * HIJ;
            const double mj = s_m[s_idx];
            const double vdw = %(vdw)s;
            const double vijdotxij = %(vx)s;
            const double cij = 0.5 * (csi + s_cs[s_idx]);
            const double muij = HIJ * vijdotxij / (R2IJ + EPS);
            const double piij_v = std::fma(-alpha * cij, muij, beta * muij * muij) * RHOIJ1;
            const double piij = vijdotxij < 0.0 ? piij_v : 0.0;
'''

# per scene: the components, the sums, the momentum's terms (cube: one equation with the
# viscosity inside; dam break: pressure gradient, then the viscosity), the equations' structs
SCENES = {
    "cube": dict(
        sphc=[os.path.join(ROOT, "bench", "cube.sph")], run=[], steps=(2, 22),
        dims="xyz", vel="uvw", acc="uvw", eq="alpha = eq2.alpha, beta = eq2.beta, eps = eq3.eps",
        hoist="eq2_0", fused_pressure=True),
    "dambreak": dict(
        sphc=[os.path.join(ROOT, "examples", "dambreak.sph"), "-D", "density_diffusion=off",
              "-D", "shifting=off"],
        run=["--set", "dx=0.0047", "--set", "cfl=0.3"], steps=(5, 105),
        dims="xy", vel="uv", acc="uv", eq="alpha = eq6.alpha, beta = eq6.beta, eps = eq7.eps",
        hoist="eq4_0", fused_pressure=False),
}


def loop_text(scene, symmetric):
    s = SCENES[scene]
    d, v = s["dims"], s["vel"]
    pos = ["%sij" % c for c in d]
    vel = ["v%s" % c for c in d]
    dw = ["dw%s" % c for c in d]
    sums = ["arho"] + ["a" + c for c in s["acc"]] + ["a" + c for c in d]

    def dot(a, b):  # as the bodies write it: fma(a2, b2, fma(a0, b0, a1 * b1))
        e = "%s * %s" % (a[1], b[1])
        e = "std::fma(%s, %s, %s)" % (a[0], b[0], e)
        if len(a) == 3:
            e = "std::fma(%s, %s, %s)" % (a[2], b[2], e)
        return e

    head = "".join("            const double %sij = %si - sj_%s[s_idx];\n" % (c, c, c) for c in d)
    head += "            const double R2IJ = %s;\n" % " + ".join("%s * %s" % (p, p) for p in pos)
    head += "".join("            const double v%s = %si - sj_%s[s_idx];\n" % (c, w, w)
                    for c, w in zip(d, v))
    body = COMMON % dict(kernel=KERNEL[scene], dwz=", dwz = gs * zij" if len(d) == 3 else "",
                         vdw=dot(vel, dw), vx=dot(vel, pos))
    h = s["hoist"]
    pre = ("          const double rhoi = di_rho[d_idx], csi = d_cs[d_idx];\n"
           "          const double %s;\n" % s["eq"] +
           "".join("          double %s = d_%s[d_idx];\n" % (x, x) for x in sums))
    post = "".join("          d_%s[d_idx] = %s;\n" % (x, x) for x in sums) + "        }\n"

    def updates(side):  # (sum, update expression) of the destination (side "") or the source
        m = "mj" if side == "" else "mi"
        sgn = "" if side == "" else "-"
        dh = "dhoisted_%s" % h if side == "" else "dhoisted_all_%s[s_idx]" % h
        sh = "hoisted_%s[s_idx]" % h if side == "" else "hoist_d_as_src"
        out = [("arho", "std::fma(%s, vdw, %%s)" % m)]
        for c, a in zip(d, s["acc"]):
            if s["fused_pressure"]:
                out.append(("a" + a, "std::fma(-%s * ((%s + %s) + piij), %sdw%s, %%s)"
                            % (m, dh, sh, sgn, c)))
            else:
                out.append(("a" + a, "std::fma(-%s * piij, %sdw%s, std::fma(-%s * (%s + %s), %sdw%s, %%s))"
                            % (m, sgn, c, m, dh, sh, sgn, c)))
        for c in d:
            out.append(("a" + c, "std::fma(-eps * %s * RHOIJ1 * WIJ, %sv%s, %%s)" % (m, sgn, c)))
        return out

    red = "#pragma omp simd reduction(+: %s)\n" % ", ".join(sums)
    if not symmetric:
        text = ("          const std::uint32_t* NBRS = nbrs_list.data();\n" + pre + red +
                "          for (int k_nbr = 0; k_nbr < n_nbrs; ++k_nbr) {\n"
                "            const int s_idx = static_cast<int>(NBRS[k_nbr]);\n"
                "            const double hj = sj_h[s_idx];\n" + head + body +
                "".join("            %s = %s;\n" % (x, e % x) for x, e in updates("")) +
                "          }\n" + post)
        return text
    text = (pre + "          const double mi = s_m[d_idx], hoist_d_as_src = hoisted_%s[d_idx];\n" % h +
            "          const std::vector<std::uint32_t>& kept = verlet_fluid_fluid.lists[d_idx];\n"
            "          const std::uint32_t* const K = kept.data();\n"
            "          int k0 = static_cast<int>(verlet_fluid_fluid.upper[d_idx]);\n"
            "          const int k1 = static_cast<int>(kept.size());\n"
            "          if (k0 < k1 && static_cast<int>(K[k0]) == d_idx) ++k0;  // the self pair: zero terms\n" +
            red + "          for (int k = k0; k < k1; ++k) {\n"
            "            const int s_idx = static_cast<int>(K[k]);\n"
            "            const double hj = sj_h[s_idx];\n" + head +
            "            const double hmax = hi > hj ? hi : hj;\n"
            "            const bool in = R2IJ < RADIUS2 * hmax * hmax;\n" + body +
            "".join("            %s = in ? %s : %s;\n" % (x, e % x, x) for x, e in updates("")) +
            "            if (in) {  // the same pair for particle s_idx\n" +
            "".join("              d_%s[s_idx] = %s;\n" % (x, e % ("d_%s[s_idx]" % x))
                    for x, e in updates("s")) +
            "            }\n          }\n" + post)
    return text


def edit(src, scene, symmetric):
    """The emitted C++ with its fluid <- fluid loop in the simd form."""
    if symmetric:
        start = ("          const std::vector<std::uint32_t>& kept = verlet_fluid_fluid.lists[d_idx];\n"
                 "          const std::uint32_t* const k_end")
        last = "XSPHCorrection_loop(s_idx, d_idx"
    else:
        start = "          const std::uint32_t* NBRS = nbrs_list.data();"
        last = "XSPHCorrection_loop(d_idx, s_idx"
    a = src.find(start)
    b = src.find(last, a)
    if a < 0 or b < 0:
        raise SystemExit("simd_pairs.py: the emitted %s loop changed; update the edit" % scene)
    close = "          }\n        }\n"
    b = src.index(close, b) + len(close)
    return src[:a] + loop_text(scene, symmetric) + src[b:]


# ---- building, checking, timing ----------------------------------------------------------

def driver_commands(sphc, scene_args, tmp):
    """The driver's compiler, flags and link inputs (from `sphc -v --single-unit --no-cache`)."""
    _, out = run([sphc] + scene_args + ["-v", "--single-unit", "--no-cache", "-o",
                                        os.path.join(tmp, "probe")])
    words = next(l for l in out.splitlines() if " -std=" in l and ".cpp " in l).split()
    src = next(i for i, w in enumerate(words) if w.endswith(".cpp"))
    return words[0], words[1:src], words[src + 1:words.index("-o")]


def vector_counts(exe, function):
    dis = subprocess.run(["objdump", "-d", "--no-show-raw-insn", exe], stdout=subprocess.PIPE,
                         universal_newlines=True).stdout
    counts, inside = {}, False
    for line in dis.splitlines():
        if line.endswith(">:"):
            inside = function in line
        elif inside:
            m = re.search(r"\s(vgather\w+|vscatter\w+|vf\w*madd\w+pd|vdivpd|vsqrtpd|vdivsd)\s", line)
            if m:
                k = m.group(1)
                k = "vfmadd*pd" if "madd" in k else k
                counts[k] = counts.get(k, 0) + 1
    return " ".join("%s %d" % kv for kv in sorted(counts.items()))


def largest_differences(a, b):
    try:
        import h5py
        import numpy as np
    except ImportError:
        return "(h5py missing)"
    worst = (0.0, "")
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        for arr in fa:
            for prop in fa[arr]:
                x = fa[arr][prop][...]
                if x.dtype.kind != "f" or prop not in fb[arr]:
                    continue
                y = fb[arr][prop][...]
                scale = float(np.max(np.abs(x))) or 1.0
                rel = float(np.max(np.abs(x - y))) / scale
                worst = max(worst, (rel, "%s.%s" % (arr, prop)))
    return "bitwise" if worst[0] == 0.0 else "%.1e of its largest value (%s)" % worst


def cpu(exe, options):
    subprocess.run(["/usr/bin/time", "-f", "%U", "-o", exe + ".time", exe] + options,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    with open(exe + ".time") as f:
        return float(f.read().split()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sphc", default=os.path.join(ROOT, "build", "bin", "sphc"))
    ap.add_argument("--scenes", default="cube,dambreak")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--keep", action="store_true")
    args = ap.parse_args()
    load = load_average()
    tmp = tempfile.mkdtemp(prefix="sphc_simd_")
    for scene in args.scenes.split(","):
        s = SCENES[scene]
        cxx, flags, libs = driver_commands(args.sphc, s["sphc"], tmp)
        exes = {}
        for form, nosym, simd in [("sym", False, False), ("ns", True, False),
                                  ("ns-simd", True, True), ("sym-simd", False, True)]:
            _, src = run([args.sphc] + s["sphc"] + ["--emit=cpp"] +
                         (["--no-symmetric-pairs"] if nosym else []))
            if simd:
                src = edit(src, scene, not nosym)
            path = os.path.join(tmp, "%s_%s.cpp" % (scene, form))
            with open(path, "w") as f:
                f.write(src)
            exe = path[:-4]
            run([cxx] + flags + (["-fopenmp-simd"] if simd else []) + [path] + libs + ["-o", exe])
            exes[form] = exe
        short, long_ = s["steps"]
        common = s["run"] + ["--tf", "100", "--output-every", "0"]
        for form, exe in exes.items():
            run([exe] + common + ["--max-steps", str(long_), "--restartable", "-d", exe + "_out"])
        print("%s: fluid <- fluid loop; CPU s per step from %d- and %d-step runs, %d rounds" % (
            scene, short, long_, args.rounds))
        per = {f: [] for f in exes}
        for _ in range(args.rounds):
            for form, exe in exes.items():
                a = cpu(exe, common + ["--no-output", "--max-steps", str(short)])
                b = cpu(exe, common + ["--no-output", "--max-steps", str(long_)])
                per[form].append((b - a) / (long_ - short))
        base = min(per["sym"])
        base_med = statistics.median(per["sym"])
        snap = "%s_%06d.h5" % ("dambreak" if scene == "dambreak" else "cube", long_)
        for form, exe in exes.items():
            fn = "group_2_ContinuityEquation"  # the rates' phase of both scenes
            print("  %-9s min %.4f (%.2f)  median %.4f (%.2f)  | %s | vs sym after %d steps: %s" % (
                form, min(per[form]), min(per[form]) / base, statistics.median(per[form]),
                statistics.median(per[form]) / base_med, vector_counts(exe, fn), long_,
                largest_differences(os.path.join(exes["sym"] + "_out", snap),
                                    os.path.join(exe + "_out", snap))))
    print_machine(load)
    remove_tmp(tmp, args.keep)


if __name__ == "__main__":
    main()
