#!/usr/bin/env python3
"""The scaling model of docs/scaling.md: a 3D dam break of 100M particles on 1..1024 ranks.

Prints, per rank count, the time of one step split into computation, halo traffic and the
collectives, for strong scaling (N = 1e8 fixed) and weak scaling (N/P = 97,656 fixed). Every
input is a measured figure of this repository or a stated assumption (docs/scaling.md):

  c      1.84 us per particle per step: the serial 3D dam break (examples/dambreak3d.sph,
         40,928 particles, 10 steps) measured on the shared 2-core machine;
  k      3 layers of halo: the cut-off 2 x 1.3 dx = 2.6 dx covers the particles 0.5, 1.5,
         2.5 dx from a cut (measured: the 2D dam break at dx = 0.01 on 2 ranks received 600
         fluid halo particles over a 200-particle cut, 3 per particle of the interface);
  bytes  104 B per halo particle and step: 11 properties sent (8 B each) at the exchange and
         2 refreshed after the equation of state (--dump-after=schedule --mpi);
  alpha  2 us latency, beta 12.5 GB/s per rank (100 Gb/s InfiniBand), both assumed;
  subdomains are cubes of n = N/P particles (RCB of a full box; P >= 8);
  collectives per step as the runtime does them now: 10 all-to-alls (migration, halo counts
  and data, 2 refreshes; each ~ P/2 alpha, pairwise) and 5 allreduces (~ 2 log2 P alpha);
  the halo particles' own work (cell lists over n + h, packing): 10% of c per halo particle.
"""
import math

C, K, BYTES, ALPHA, BETA = 1.84e-6, 3, 104, 2e-6, 12.5e9


def step(P, n):
    comp = C * n
    if P == 1:
        return comp, 0.0, 0.0, 0.0
    a = n ** (1 / 3)
    h = (a + 2 * K) ** 3 - a ** 3
    halo = 3 * 26 * ALPHA + h * BYTES / BETA + 0.1 * C * h
    coll = 10 * (P / 2) * ALPHA + 5 * 2 * math.log2(P) * ALPHA
    return comp, halo, coll, h / n


def table(title, n_of):
    print(title)
    print("| ranks | particles/rank | halo/particles | compute ms | halo ms | collectives ms | step ms | efficiency |")
    print("|---|---|---|---|---|---|---|---|")
    base = sum(step(1, n_of(1))[:3])
    for P in [1, 8, 64, 256, 1024]:
        n = n_of(P)
        comp, halo, coll, hr = step(P, n)
        tot = comp + halo + coll
        eff = (base / P if n_of(1) != n_of(2) else base) / tot
        print(f"| {P} | {n:,.0f} | {hr:.2f} | {comp*1e3:.1f} | {halo*1e3:.2f} | {coll*1e3:.2f} | "
              f"{tot*1e3:.1f} | {eff:.2f} |")
    print()


table("strong scaling, N = 1e8", lambda P: 1e8 / P)
table("weak scaling, N/P = 97,656", lambda P: 1e8 / 1024)
