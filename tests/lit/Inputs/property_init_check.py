#!/usr/bin/env python3
"""Checks the snapshot of tests/lit/sema/property-init-reads-property.sph against the initial
values computed here from the positions: q = 2 x + c + k with k = int(10 x) (truncated, as
the int property stores it) and c = 0.5 (the param), shadow = x + 1 (read through the
unallocated property shift = x), base = 0 and two = 2 (properties without an initial value
read as 0).
Prints the particle count and 'exact' (to 1e-12), else fails."""
import sys

import h5py
import numpy as np

with h5py.File(sys.argv[1], 'r') as f:
    g = f['fluid']
    x, q, k, shadow, base, two = (np.asarray(g[n][...])
                                  for n in ('x', 'q', 'k', 'shadow', 'base', 'two'))
assert len(x) > 1, 'no particles'
k_exact = np.trunc(x * 10.0)
for name, got, want in (('k', k, k_exact), ('q', q, 2.0 * x + 0.5 + k_exact),
                        ('shadow', shadow, x + 1.0), ('base', base, 0.0 * x),
                        ('two', two, 0.0 * x + 2.0)):
    err = np.max(np.abs(got - want))
    if err > 1e-12:
        sys.exit('%s differs from the exact value by %g' % (name, err))
print('%d particles: q, k, shadow, base, two exact' % len(x))
