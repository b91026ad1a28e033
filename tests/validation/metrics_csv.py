"""Reading the metric file a solver writes beside its snapshots (OUTPUT_DIR/<scene>_metrics.csv:
the scene's `metrics { }`, docs/language.md, Metrics): one row per output time with the step,
t, dt, the wall and CPU seconds of the time loop and every metric (NAME; NAME_ref and NAME_err
for a compared scalar). The validation checks read their error figures from it instead of
recomputing them from the snapshots."""
import csv
import glob
import math
import os
import sys


def metrics_file(directory):
    """The one *_metrics.csv file of an output directory, or None."""
    files = glob.glob(os.path.join(directory, "*_metrics.csv"))
    return files[0] if len(files) == 1 else None


def read_metrics(directory, who, needed=()):
    """{column: [float per row]} of the metric file of `directory` (rows in output order), or
    None after an error on stderr naming `who` (the script): no file, or a column of `needed`
    missing."""
    path = metrics_file(directory)
    if path is None:
        sys.stderr.write("%s: no <scene>_metrics.csv in %s (does the scene declare its metrics "
                         "{ }?)\n" % (who, directory))
        return None
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.stderr.write("%s: %s has no rows\n" % (who, path))
        return None
    missing = [c for c in needed if c not in rows[0]]
    if missing:
        sys.stderr.write("%s: %s has no column %s; its columns: %s\n"
                         % (who, path, ", ".join(missing), ", ".join(rows[0].keys())))
        return None
    return {c: [float(r[c]) for r in rows] for c in rows[0].keys()}


def row_at(metrics, t, tol=1e-9):
    """The index of the row at time t (within tol * max(1, |t|)), or None."""
    for k, tk in enumerate(metrics["t"]):
        if abs(tk - t) <= tol * max(1.0, abs(t)):
            return k
    return None


def finite(v):
    return v is not None and math.isfinite(v)
