#!/usr/bin/env python3
"""CPU time of each process of a cold sphc build (docs/performance-log.md "Compile time").

For each sphc given (--sphc LABEL=PATH), scene and backend: a cold build into an empty cache
directory with `-v`, which prints the compile and link commands; then the same commands run
again one after the other, each timed alone (user + sys CPU of the process and its children),
on the translation units rebuilt from the split file the build keeps (scene.cpp in the cache
directory, cut at the phases' markers as compiler/driver/Build.cpp cuts it). Rounds interleave
the sphc builds, so that a loaded machine slows all of them alike; the table gives each
figure's minimum over the rounds and the 2-core estimate of a cold build's wall time on an idle
machine: sphc's front end (its `emit done` time) + the longest compile + the link.

  python3 bench/compile_units.py --sphc main=/path/to/main/sphc --sphc new=build/bin/sphc \\
      --scene examples/dambreak.sph --scene bench/cube.sph --backend serial --rounds 3
"""
import argparse
import os
import re
import resource
import shutil
import subprocess
import tempfile

BEGIN = "// ---- sphc: the phases, a translation unit of their own"
END = "// ---- sphc: end of the phases"


def split_units(cpp):
    """The units as compiler/driver/Build.cpp's splitUnits cuts the file."""
    b, e = cpp.find("\n" + BEGIN), cpp.find("\n" + END)
    if b < 0 or e < 0 or e < b:
        return [cpp]
    line = 2 + cpp[:e].count("\n")
    return [cpp[:e + 1], cpp[:b + 1] + '#line %d "scene.cpp"\n' % line + cpp[e + 1:]]


def cpu_of(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def one_build(sphc, scene, backend, work):
    cache = tempfile.mkdtemp(dir=work)
    env = dict(os.environ, SPHC_CACHE_DIR=cache)
    exe = os.path.join(work, "exe")
    p = subprocess.run([sphc, scene, "-o", exe, "-v", "--backend=" + backend], env=env,
                       capture_output=True, text=True, check=True)
    front = float(re.search(r"sphc: emit done at ([0-9.]+) s", p.stderr).group(1))
    cmds = [l.split() for l in p.stderr.splitlines() if l.startswith("/") and " -o " in l]
    (key,) = os.listdir(cache)
    cpp = open(os.path.join(cache, key, "scene.cpp")).read()
    units = split_units(cpp)
    times = {}
    for cmd in cmds:
        srcs = [a for a in cmd if a.endswith(".cpp")]
        for s in srcs:  # the build deleted its units: the same text again
            m = re.search(r"\.unit(\d+)\.cpp$", s)
            open(s, "w").write(units[int(m.group(1))] if m else cpp)
        if "-c" in cmd:
            name = "unit" + re.search(r"\.unit(\d+)\.cpp$", srcs[0]).group(1)
        else:
            name = "link" if not srcs else "one unit"
        times[name] = cpu_of(cmd)
    shutil.rmtree(cache)
    return front, times


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sphc", action="append", required=True, help="LABEL=PATH")
    ap.add_argument("--scene", action="append", required=True)
    ap.add_argument("--backend", action="append", default=None)
    ap.add_argument("--rounds", type=int, default=3)
    a = ap.parse_args()
    sphcs = [s.split("=", 1) for s in a.sphc]
    backends = a.backend or ["serial"]
    work = tempfile.mkdtemp(prefix="sphc-compile-units-")
    best = {}
    for _ in range(a.rounds):
        for scene in a.scene:
            for backend in backends:
                for label, path in sphcs:
                    front, times = one_build(path, scene, backend, work)
                    key = (os.path.basename(scene), backend, label)
                    rec = best.setdefault(key, {"front": front})
                    rec["front"] = min(rec["front"], front)
                    for k, v in times.items():
                        rec[k] = min(rec.get(k, v), v)
    shutil.rmtree(work)
    print("| scene | backend | sphc | front end | unit0 | unit1 | one unit | link | 2-core estimate |")
    print("|---|---|---|---|---|---|---|---|---|")
    for (scene, backend, label), r in best.items():
        compiles = [r[k] for k in ("unit0", "unit1", "one unit") if k in r]
        est = r["front"] + max(compiles) + r.get("link", 0.0)
        cell = lambda k: "%.2f" % r[k] if k in r else "-"
        print("| %s | %s | %s | %.2f | %s | %s | %s | %s | %.2f |" % (
            scene, backend, label, r["front"], cell("unit0"), cell("unit1"), cell("one unit"),
            cell("link"), est))
    print("load average (1, 5, 15 min): %.2f %.2f %.2f" % os.getloadavg())


if __name__ == "__main__":
    main()
