#!/usr/bin/env python3
"""Self-test of pair_series.py: snapshots of a 2D lattice (20 x 20, spacing 0.1) written here,
with one bulk pair moved to 0.45 dx at t = 0.1, a corner pair (not bulk: ~7 neighbours within
2.6 dx) to 0.2 dx at t = 0.2 and a bulk pair to 0.6 dx at t = 0.3. pair_series.py must report
0.45 dx at t = 0.1, the next output 0.6 dx, the same minimum as check_run.py's --pair-bulk 12,
and 0.6 dx with --pair-skip 0.05 0.15. Usage: pair_series_selftest.py [PYTHON]"""
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def write_run(directory):
    g = (np.arange(20) + 0.5) * 0.1
    x0, y0 = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    mid = 10 * 20 + 10          # (1.05, 1.05); its neighbour along y is mid + 1
    corner = 0                  # (0.05, 0.05); its neighbour along y is 1
    for step, t, who, gap in ((0, 0.0, None, None), (100, 0.1, mid, 0.45),
                              (200, 0.2, corner, 0.2), (300, 0.3, mid, 0.6)):
        x, y = x0.copy(), y0.copy()
        if who is not None:
            y[who] = y[who + 1] - gap * 0.1
        with h5py.File(os.path.join(directory, "lat_%06d.h5" % step), "w") as f:
            f.attrs["t"] = t
            f.attrs["step"] = step
            f.attrs["dt"] = 1e-3
            f.attrs["dim"] = 2
            fl = f.create_group("fluid")
            fl["x"], fl["y"] = x, y
            fl["u"] = fl["v"] = np.zeros_like(x)
            fl["rho"] = np.full_like(x, 1000.0)


def run(py, script, *args):
    r = subprocess.run([py, os.path.join(HERE, script)] + list(args),
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return r.stdout


def main():
    py = sys.argv[1] if len(sys.argv) > 1 else sys.executable
    bad = []
    with tempfile.TemporaryDirectory() as d:
        write_run(d)
        out = run(py, "pair_series.py", d, "--label", "L")
        row = [l for l in out.splitlines() if l.startswith("L\t")]
        if not row:
            bad.append("no summary row:\n" + out)
        else:
            f = row[0].split("\t")
            if abs(float(f[1]) - 0.45) > 1e-9 or abs(float(f[2]) - 0.1) > 1e-12 \
                    or abs(float(f[3]) - 0.6) > 1e-9:
                bad.append("expected 0.45 dx at t = 0.1, next 0.6: " + row[0])
        chk = run(py, "check_run.py", d, "--rho0", "1000", "--min-pair", "0.5",
                  "--pair-bulk", "12")
        line = [l for l in chk.splitlines() if l.startswith("min-pair")]
        if not line or abs(float(line[0].split()[1]) - 0.45) > 1e-3:
            bad.append("check_run.py's closest bulk pair is not 0.45:\n" + chk)
        out = run(py, "pair_series.py", d, "--pair-skip", "0.05", "0.15", "--label", "S")
        row = [l for l in out.splitlines() if l.startswith("S\t")]
        if not row or abs(float(row[0].split("\t")[1]) - 0.6) > 1e-9:
            bad.append("with --pair-skip 0.05 0.15 expected 0.6 dx:\n" + out)
    for b in bad:
        print("FAILED: " + b)
    if not bad:
        print("PASSED: pair_series.py reports the bulk pairs check_run.py judges, per output")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
