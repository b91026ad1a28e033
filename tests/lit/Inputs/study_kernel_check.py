#!/usr/bin/env python3
"""Checks the study.csv of tests/lit/driver/study-kernel.sph: every run's metric rho_err (the
summation density of Inputs/study-kernel.sph's periodic nx x nx lattice, minus 1) against the
lattice sum computed here from the kernels' published formulas, for the run's kernel and hdx:

    rho - 1 = dx^2 sum_(i, j) W(dx sqrt(i^2 + j^2), h) - 1,   h = hdx dx,
    W(r, h) = sigma / h^2 f(r / h), over the lattice points within the support (periodic
    images included: the box is 1 wide, the support < 1 / 2 at the tested nx and hdx)

  CubicSpline      f = 1 - 3/2 q^2 + 3/4 q^3 (q < 1), (2 - q)^3 / 4 (q < 2); sigma = 10 / (7 pi)
                   (Monaghan 1992)
  QuinticSpline    f = (3 - q)^5 - 6 (2 - q)^5 + 15 (1 - q)^5, each term where positive;
                   sigma = 7 / (478 pi) (Morris, Fox & Zhu 1997)
  WendlandQuintic  f = (1 - q/2)^4 (2 q + 1), q < 2; sigma = 7 / (4 pi) (Wendland 1995, the
                   C2 function with support 2 h)
  Gaussian         f = exp(-q^2), q < 3; sigma = 1 / pi

Usage: study_kernel_check.py STUDY.csv TOL [--nx N]. Exit 0 when every run is within TOL
(absolute) of its sum, and the kernels give different sums (the kernel did change)."""
import csv
import math
import sys


def shape(kernel, q):
    if kernel == "CubicSpline":
        return (1 - 1.5 * q * q + 0.75 * q ** 3) if q < 1 else 0.25 * (2 - q) ** 3 if q < 2 else 0.0
    if kernel == "QuinticSpline":
        return sum(c * max(0.0, a - q) ** 5 for a, c in ((3, 1.0), (2, -6.0), (1, 15.0)))
    if kernel == "WendlandQuintic":
        return (1 - 0.5 * q) ** 4 * (2 * q + 1) if q < 2 else 0.0
    if kernel == "Gaussian":
        return math.exp(-q * q) if q < 3 else 0.0
    raise KeyError(kernel)


SIGMA = {"CubicSpline": 10.0 / (7.0 * math.pi), "QuinticSpline": 7.0 / (478.0 * math.pi),
         "WendlandQuintic": 7.0 / (4.0 * math.pi), "Gaussian": 1.0 / math.pi}


def lattice_sum(kernel, hdx, nx):
    dx = 1.0 / nx
    h = hdx * dx
    n = int(math.ceil(3 * hdx)) + 1
    total = 0.0
    for i in range(-n, n + 1):
        for j in range(-n, n + 1):
            total += shape(kernel, math.hypot(i, j) / hdx)
    return dx * dx * SIGMA[kernel] / (h * h) * total - 1.0


def main(argv):
    if len(argv) not in (3, 5):
        sys.stderr.write(__doc__)
        return 2
    nx = int(argv[4]) if len(argv) == 5 else 10
    tol = float(argv[2])
    with open(argv[1], newline="") as f:
        rows = [r for r in csv.DictReader(f)]
    bad = 0
    sums = {}
    for r in rows:
        want = lattice_sum(r["kernel"], float(r["hdx"]), nx)
        got = float(r["rho_err"])
        ok = r["status"] == "ok" and abs(got - want) <= tol
        sums.setdefault(r["hdx"], set()).add(round(got, 9))
        print("kernel=%s hdx=%s: rho_err %.10g, lattice sum %.10g %s"
              % (r["kernel"], r["hdx"], got, want, "ok" if ok else "FAIL"))
        bad += not ok
    kernels = {r["kernel"] for r in rows}
    for hdx, vals in sorted(sums.items()):
        if len(vals) != len(kernels):
            print("hdx=%s: %d kernels gave %d distinct sums: FAIL" % (hdx, len(kernels), len(vals)))
            bad += 1
    if not rows:
        print("no runs: FAIL")
        bad += 1
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
