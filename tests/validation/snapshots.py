"""Reading sphc (and PySPH) snapshots for the validation checks: the argument parser every
check starts from, the list of snapshot files of an output directory in step order, the
particle arrays and the fluid group of one snapshot, the checks every script makes of it
(required datasets present, no non-finite values), and the report of the failures."""
import argparse
import glob
import math
import os
import re
import sys

import numpy as np

import plots  # tests/validation/plots.py


def argument_parser(doc, outdir_help, plot_name):
    """The parser of a check: described by the first paragraph of its docstring `doc`, with
    the positional OUTPUT_DIR (`outdir`) and --plot PATH, whose default is plot_name in
    OUTPUT_DIR (plots.py). The check adds its own options to it."""
    ap = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    ap.add_argument("outdir", help=outdir_help)
    plots.add_option(ap, plot_name)
    return ap


def snapshot_files(directory):
    """Snapshot files of a directory, in step order: sphc's <scene>_NNNNNN.h5 or, where there
    are none, PySPH's <app>_NNNNN.hdf5."""
    for ext in ("h5", "hdf5"):
        pat = re.compile(r"_(\d+)\.%s$" % ext)
        files = [f for f in glob.glob(os.path.join(directory, "*." + ext))
                 if pat.search(os.path.basename(f))]
        if files:
            return sorted(files, key=lambda f: int(pat.search(os.path.basename(f)).group(1)))
    return []


def snapshots(directory, who, at_least=2):
    """snapshot_files(directory), or None after an error on stderr naming `who` (the script)
    when there are fewer than `at_least`."""
    files = snapshot_files(directory)
    if len(files) < at_least:
        sys.stderr.write("%s: need >= %d <scene>_NNNNNN.h5 files in %s, found %d\n"
                         % (who, at_least, directory, len(files)))
        return None
    return files


def particle_arrays(f):
    """(t, dim, {array name: {property: dataset}}) of an open sphc or PySPH snapshot file;
    dim is None where the file does not say (PySPH's)."""
    if "particles" in f and "solver_data" in f:  # PySPH
        t = float(f["solver_data"].attrs["t"])
        arrays = {name: {k: d for k, d in g["arrays"].items() if hasattr(d, "dtype")}
                  for name, g in f["particles"].items()
                  if not hasattr(g, "dtype") and "arrays" in g}
        return t, None, arrays
    arrays = {name: {k: d for k, d in g.items() if hasattr(d, "dtype")}
              for name, g in f.items() if not hasattr(g, "dtype")}
    dim = int(f.attrs["dim"]) if "dim" in f.attrs else None
    return float(f.attrs["t"]), dim, arrays


def scan_finite(name, arrays, failures):
    """Appends to `failures` one line per floating-point dataset of `arrays` ({array name:
    {property: dataset}}, as particle_arrays gives) with non-finite values; `name` is the
    snapshot's file name."""
    for gname, group in arrays.items():
        for dname, dset in group.items():
            a = dset[()]
            if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
                failures.append("%s: /%s/%s has %d non-finite values"
                                % (name, gname, dname, int(np.count_nonzero(~np.isfinite(a)))))


def fluid_group(f):
    """(t, group of fluid arrays) of a snapshot: sphc's /fluid, or PySPH's
    /particles/fluid/arrays with the time in /solver_data (for comparisons with PySPH's own
    runs of the same case). (None, None) when there is no fluid."""
    if "fluid" in f:
        return float(f.attrs["t"]), f["fluid"]
    if "particles" in f and "fluid" in f["particles"]:
        return float(f["solver_data"].attrs["t"]), f["particles"]["fluid"]["arrays"]
    return None, None


def read_fluid(f, name, keys, who, failures, scan_all=False):
    """(t, [arrays of `keys` as float]) of the open snapshot f (file name `name`), or None
    after an error on stderr naming `who` (the script) when the fluid or one of the keys is
    missing. Appends to `failures` one line per dataset with non-finite values: of the fluid,
    or with scan_all of every particle array (walls too)."""
    t, fl = fluid_group(f)
    if fl is None:
        sys.stderr.write("%s: %s has no fluid particles\n" % (who, name))
        return None
    for key in keys:
        if key not in fl:
            sys.stderr.write("%s: %s has no /fluid/%s\n" % (who, name, key))
            return None
    if scan_all:
        scan_finite(name, particle_arrays(f)[2], failures)
    else:
        scan_finite(name, {"fluid": {k: d for k, d in fl.items() if hasattr(d, "dtype")}},
                    failures)
    return t, [np.asarray(fl[k][()], dtype=float) for k in keys]


def lattice_spacing(pos):
    """The particle spacing of a lattice (the initial fluid): the median nearest-neighbour
    distance over ~200 of its particles; pos = (x, y) or (x, y, z)."""
    n = len(pos[0])
    d = []
    for i in range(0, n, max(1, n // 200)):
        r2 = np.zeros_like(pos[0])
        for c in pos:
            r2 += (c - c[i]) ** 2
        r2[i] = np.inf
        d.append(np.sqrt(r2.min()))
    return float(np.median(d))


def report_failures(failures, limit=None):
    """Prints the failures of a check (the first `limit` of them, if given) under a FAILED
    line; True when there are any (the check then exits 1)."""
    if not failures:
        return False
    print("FAILED (%d problems):" % len(failures))
    for msg in failures[:limit]:
        print("  " + msg)
    return True


def read_series(directory, keys, who, at_least=2):
    """Every snapshot of an output directory in step order (snapshots()), read with
    read_fluid: ([(file name, t, [arrays of `keys`])], failures), the failures listing the
    non-finite values found; None after an error on stderr naming `who` (too few snapshots,
    or a snapshot without the fluid or one of the keys)."""
    import h5py  # here: the other helpers serve scripts that read no HDF5

    files = snapshots(directory, who, at_least)
    if files is None:
        return None
    failures = []
    series = []
    for name in files:
        with h5py.File(name, "r") as f:
            got = read_fluid(f, name, keys, who, failures)
        if got is None:
            return None
        series.append((name, got[0], got[1]))
    return series, failures


class FluidCount:
    """The fluid's particle count and total mass at the first snapshot checked, and the check
    of each snapshot against them: the same count, and the same mass to the bit (summed with
    math.fsum, which is exact, so independent of the particles' order)."""

    def __init__(self):
        self.n0 = self.mass0 = None

    def check(self, name, m, failures):
        """Appends to `failures` a line where snapshot `name` (the fluid's masses m) has another
        particle count or total mass than the first; returns its total mass."""
        mass = math.fsum(m)
        if self.n0 is None:
            self.n0, self.mass0 = len(m), mass
        if len(m) != self.n0:
            failures.append("%s: %d fluid particles, the first snapshot has %d"
                            % (name, len(m), self.n0))
        if mass != self.mass0:
            failures.append("%s: fluid mass %.17g, initially %.17g (not conserved)"
                            % (name, mass, self.mass0))
        return mass


def check_conserved(what, t, value, start, tol, failures):
    """Appends to `failures` a line when `value` (of the quantity `what` at time t) differs
    from `start` by more than tol relative to |start|."""
    if abs(value - start) > tol * abs(start):
        failures.append("t = %g: %s %.15g, at the start %.15g" % (t, what, value, start))


def finish(args, draw, failures, limit=20, **plot_options):
    """The end of a check: its plot (plots.write(args, draw, failures, **plot_options); draw
    None: no plot), then the failures (report_failures) or OK. Returns the exit status: 1
    with failures, else 0."""
    if draw is not None:
        plots.write(args, draw, failures, **plot_options)
    if report_failures(failures, limit):
        return 1
    print("OK")
    return 0


def port_result(failures, tol):
    """The end of a check of a port against PySPH's run: the failures (the first 20), or OK.
    Returns the exit status: 1 with failures, else 0."""
    if report_failures(failures, limit=20):
        return 1
    print("OK: sphc's port agrees with PySPH within %.0e at every snapshot" % tol)
    return 0


def pysph_comparison(description, load_run, read_reference, write_reference, extra=()):
    """The command line shared by the checks against a PySPH run (SPHC_OUT with --reference
    FILE or --pysph-dir DIR; --write-reference FILE --pysph-dir DIR stores PySPH's run), and
    the checks every such comparison starts with: the same number of snapshots and the same
    initial particles (the run's and the reference's "ij" lattice indices). Returns
    (args, run, ref) to compare, or (args, None, exit code) when done or failed. EXTRA: more
    (flag, help) options."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("sphc_out", nargs="?")
    ap.add_argument("--reference")
    ap.add_argument("--pysph-dir")
    ap.add_argument("--write-reference")
    ap.add_argument("--tol", type=float, default=1e-9)
    for flag, text in extra:
        ap.add_argument(flag, help=text)
    a = ap.parse_args()
    if a.write_reference:
        if not a.pysph_dir:
            ap.error("--write-reference needs --pysph-dir")
        write_reference(load_run(a.pysph_dir), a.write_reference)
        print("wrote %s" % a.write_reference)
        return a, None, 0
    if not a.sphc_out or bool(a.reference) == bool(a.pysph_dir):
        ap.error("give SPHC_OUT and one of --reference, --pysph-dir")
    run = load_run(a.sphc_out)
    ref = read_reference(a.reference) if a.reference else load_run(a.pysph_dir)
    failures = []
    if len(run["t"]) != len(ref["t"]):
        failures.append("%d snapshots, PySPH has %d" % (len(run["t"]), len(ref["t"])))
    if run["ij"].shape != ref["ij"].shape or np.any(run["ij"] != ref["ij"]):
        failures.append("the initial particles differ from PySPH's (%d, PySPH %d)"
                        % (len(run["ij"]), len(ref["ij"])))
    if failures:
        report_failures(failures)
        return a, None, 1
    return a, run, ref
