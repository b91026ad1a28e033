#!/usr/bin/env python3
"""Self-test of check_run.py's wall check in 3D (`--box`), on snapshots written here.

In 3D the floor is z = ZMIN: `--box XMIN XMAX YMIN YMAX ZMIN [ZMAX]`. Before this test the
check read only x and y in 3D (the 2D form XMIN XMAX YMIN [YMAX]), so water through the floor
of a 3D tank passed unseen (the 3D dam break was checked with `--box 0 4 0 0.5 0 2.5`, whose
last two values were ignored). Writes a 4 x 4 x 4 lattice at rest (dx = 0.1) in the unit box
at t = 0 and t = 0.1, in the second snapshot one particle moved to z = -0.2 (2 dx below the
floor) or to x = 1.2 (2 dx past the far wall), and requires:
  - the particle below the floor fails `--box 0 1 0 1 0` and `--box 0 1 0 1 0 1` (exit 1,
    "[wall]"), passes the 2D form `--box 0 1 0 1` (z unchecked, as documented);
  - the particle past x = 1 fails every form; the lattice untouched passes every form;
  - more values than the dimension has fail as bad input (exit 2).
Exit 0 when all hold, 1 otherwise.

Usage: check_run_box3d.py [PYTHON]
"""
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def write_run(directory, dim, moved=None):
    """Two snapshots of a lattice at rest; `moved` = (axis, value) for particle 0 at t = 0.1."""
    g = (np.arange(4) + 0.5) * 0.1
    axes = np.meshgrid(*([g] * dim), indexing="ij")
    pos = [a.ravel() for a in axes]
    for step, t in ((0, 0.0), (100, 0.1)):
        p = [c.copy() for c in pos]
        if moved is not None and step > 0:
            p[moved[0]][0] = moved[1]
        with h5py.File(os.path.join(directory, "box_%06d.h5" % step), "w") as f:
            f.attrs["t"] = t
            f.attrs["step"] = step
            f.attrs["dt"] = 1e-3
            f.attrs["dim"] = dim
            fl = f.create_group("fluid")
            for name, c in zip("xyz", p):
                fl[name] = c
            for name in "uvw"[:dim]:
                fl[name] = np.zeros_like(p[0])
            fl["rho"] = np.full_like(p[0], 1000.0)


def check(py, directory, box):
    """(exit code, output) of check_run.py on the run with --box box."""
    r = subprocess.run([py, os.path.join(HERE, "check_run.py"), directory, "--rho0", "1000",
                        "--box"] + [str(b) for b in box],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return r.returncode, r.stdout


def main():
    py = sys.argv[1] if len(sys.argv) > 1 else sys.executable
    box2 = [0, 1, 0, 1]
    floor = [0, 1, 0, 1, 0]
    closed = [0, 1, 0, 1, 0, 1]
    cases = [  # (dim, moved, box, expected exit code, must print "[wall]")
        (3, (2, -0.2), floor, 1, True),
        (3, (2, -0.2), closed, 1, True),
        (3, (2, -0.2), box2, 0, False),
        (3, (2, 1.2), closed, 1, True),
        (3, (0, 1.2), floor, 1, True),
        (3, (0, 1.2), box2, 1, True),
        (3, None, closed, 0, False),
        (3, None, floor, 0, False),
        (3, None, closed + [2], 2, False),
        (2, None, floor, 2, False),
        (2, (1, -0.2), box2, 1, True),
    ]
    bad = 0
    for dim, moved, box, want, wall in cases:
        with tempfile.TemporaryDirectory() as d:
            write_run(d, dim, moved)
            rc, out = check(py, d, box)
        ok = rc == want and (not wall or "[wall]" in out)
        print("%s: %dD, particle 0 moved %s, --box %s: exit %d (expected %d)"
              % ("ok" if ok else "FAILED", dim, moved, " ".join(map(str, box)), rc, want))
        if not ok:
            bad += 1
            print(out)
    print("PASSED" if not bad else "FAILED: %d cases" % bad)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
