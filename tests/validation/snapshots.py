"""Reading sphc (and PySPH) snapshots for the validation checks: the list of snapshot files
of an output directory in step order, the fluid group of one snapshot, and the checks every
script makes of it (required datasets present, no non-finite values)."""
import glob
import os
import re
import sys

import numpy as np


def snapshot_files(directory):
    """Snapshot files <scene>_NNNNNN.h5 (sphc) or <app>_NNNNN.hdf5 (PySPH), in step order."""
    files = [f for f in glob.glob(os.path.join(directory, "*.h5")) +
             glob.glob(os.path.join(directory, "*.hdf5"))
             if re.search(r"_\d+\.(h5|hdf5)$", os.path.basename(f))]
    return sorted(files, key=lambda f: int(re.search(r"_(\d+)\.(h5|hdf5)$", f).group(1)))


def fluid_group(f):
    """(t, group of fluid arrays) of a snapshot: sphc's /fluid, or PySPH's
    /particles/fluid/arrays with the time in /solver_data (for comparisons with PySPH's own
    runs of the same case). (None, None) when there is no fluid."""
    if "fluid" in f:
        return float(f.attrs["t"]), f["fluid"]
    if "particles" in f and "fluid" in f["particles"]:
        return float(f["solver_data"].attrs["t"]), f["particles"]["fluid"]["arrays"]
    return None, None


def read_fluid(f, name, keys, who, failures):
    """(t, [arrays of `keys` as float]) of the open snapshot f (file name `name`), or None
    after an error on stderr naming `who` (the script) when the fluid or one of the keys is
    missing. Appends to `failures` one line per dataset with non-finite values."""
    t, fl = fluid_group(f)
    if fl is None:
        sys.stderr.write("%s: %s has no fluid particles\n" % (who, name))
        return None
    for key in keys:
        if key not in fl:
            sys.stderr.write("%s: %s has no /fluid/%s\n" % (who, name, key))
            return None
    for dname, dset in fl.items():
        a = dset[()]
        if a.dtype.kind == "f" and a.ndim and not np.all(np.isfinite(a)):
            failures.append("%s: /fluid/%s has %d non-finite values"
                            % (name, dname, int(np.count_nonzero(~np.isfinite(a)))))
    return t, [np.asarray(fl[k][()], dtype=float) for k in keys]
