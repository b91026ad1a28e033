// sphc runtime: particle position generators (the `geometry` builders of .sph scenes).
//
// All builders place particles on a lattice of spacing dx, so that each particle stands for a
// volume dx^dim. Coordinates of unused axes are 0 (z in 2D, y and z in 1D). Bad arguments
// (dx <= 0, hi < lo, layers < 1, r <= 0, non-finite values, dim not 1..3, or more than 1e9
// points) throw std::invalid_argument with a message naming the builder and the argument,
// e.g. "block: dx must be > 0 (got -0.1)".
#pragma once

#include <cstddef>
#include <vector>

namespace sphc {

struct Points {
  std::vector<double> x, y, z;
  std::size_t size() const { return x.size(); }
  void append(const Points& other);
  void push(double px, double py, double pz) {
    x.push_back(px);
    y.push_back(py);
    z.push_back(pz);
  }
};

// Number of lattice cells of size dx in [lo, hi]: round((hi - lo) / dx), with a relative
// slack of 1e-9 so that floating error (e.g. 0.3 / 0.1 = 2.9999999999999996) does not lose a
// cell; halves round up.
std::size_t lattice_count(double lo, double hi, double dx);

// Cell centres lo + (i + 1/2) dx, i < lattice_count(lo, hi, dx), on each of the first `dim`
// axes (x fastest, then y, then z). lo and hi are 3-vectors; entries beyond dim are ignored.
Points block(int dim, const double lo[3], const double hi[3], double dx);

// Walls of a container whose inner face is the box [lo, hi]: `layers` layers of particles
// outside it, at lo - (k + 1/2) dx and hi + (k + 1/2) dx (k < layers) along each of the first
// `dim` axes, continued along the walls on the lattice of `block` (so a block filling the same
// box sits exactly dx from the walls at lo, and at hi when (hi - lo) / dx is whole).
// The vertical axis is the last one (x in 1D, y in 2D, z in 3D); there is a lid (at hi on
// that axis) only when `top`. Corners are filled, each point once.
Points tank(int dim, const double lo[3], const double hi[3], double dx, int layers = 3,
            bool top = false);

// Points (cx + i dx, cy + j dx) (integer i, j: the centre is a point) within distance r of
// the centre; z = 0.
Points disk(double cx, double cy, double r, double dx);

// Points (cx + i dx, cy + j dx, cz + k dx) within distance r of the centre.
Points sphere(double cx, double cy, double cz, double r, double dx);

// The disk(cx, cy, r, dx) cross-section repeated on the layers z = zmin + (k + 1/2) dx,
// k < lattice_count(zmin, zmax, dx) (axis along z).
Points cylinder(double cx, double cy, double r, double zmin, double zmax, double dx);

// Points along the segment p0 -> p1, both ends included, equally spaced with a spacing as
// close to dx as possible (round(length / dx) intervals, at least one). A zero-length segment
// gives the single point p0.
Points line(const double p0[3], const double p1[3], double dx);

}  // namespace sphc
