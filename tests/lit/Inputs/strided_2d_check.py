"""Checks the output of strided-2d-layout.sph: the 2D-layout vector gc equals gk (3D layout,
the same sums), the tensor entries equal their scalar twins, the z entries are 0, and the
sums are not trivially zero (the disk's edge and the density field give gradients)."""
import glob
import sys

import h5py
import numpy as np

files = sorted(glob.glob(sys.argv[1] + "/*.h5"))
assert files, "no output"
with h5py.File(files[-1], "r") as f:
    g = {k: f["fluid/" + k][:] for k in f["fluid"].keys()}
fails = []
def same(a, b, what):
    d = np.max(np.abs(g[a] - g[b]))
    if d > 1e-13 * max(1.0, np.max(np.abs(g[b]))):
        fails.append(f"{what}: {a} vs {b} differ by {d}")
same("gcx", "gkx", "vector x")
same("gcy", "gky", "vector y")
same("txy", "t01", "tensor (0,1)")
same("tyx", "t10", "tensor (1,0)")
if np.max(np.abs(g["tz"])) != 0.0:
    fails.append("z entries not 0")
if np.max(np.abs(g["gcx"])) < 1.0 or np.max(np.abs(g["txx"])) < 0.5:
    fails.append("sums trivially small: %g %g" % (np.max(np.abs(g["gcx"])), np.max(np.abs(g["txx"]))))
for m in fails:
    print("FAIL:", m)
print("n =", len(g["x"]), "max|gc| =", np.max(np.abs(g["gcx"])), "max|txx| =", np.max(np.abs(g["txx"])))
sys.exit(1 if fails else 0)
