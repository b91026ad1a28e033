// sphc runtime: the domain manager (periodic and mirror boundaries, ghost particles).
//
// A scene's `domain { periodic x in [0, L]; mirror y >= 0; }` becomes a Domain: per axis, what
// its low and high side are. Before every acceleration evaluation the generated solver
//
//   1. wraps particles that left a periodic box back into it (wrap_periodic: x in [lo, hi));
//   2. appends to each array that is a neighbour source its ghost particles (add_ghosts):
//      copies of the real particles within `cutoff` (the largest interaction radius,
//      radius_scale * max h) of a periodic or mirror side,
//        - periodic: shifted by the period, to the other side of the box;
//        - mirror:   reflected through the plane, with the normal velocity component negated;
//      and, where a particle is near two or three sides (corners, edges), every combination
//      of those images, so the 3^dim neighbourhood of a real particle near a corner is
//      complete;
//   3. builds the cell lists over real particles and ghosts; ghosts are neighbours of every
//      loop, and destinations only of groups with `real = false`;
//   4. after the evaluation, removes the ghosts again (remove_ghosts).
//
// Storage. Ghosts live after the n real particles in every property's storage: during an
// evaluation particle n + g (g < ghosts.size()) is ghost g. `ParticleArray::n` stays the
// number of real particles throughout, so steppers, output, the adaptive time step and the
// progress line see real particles only; outside an evaluation the storage holds exactly n
// particles again.
//
// Properties. Only the properties listed (by index) are copied to ghosts: what the solver
// reads of them (the compiler's ghost pass, PlanArray::ghostProps). By name: x, y, z are
// positions (shifted or reflected); u, v, w are the velocity (a mirror negates the component
// normal to it); every other property (any type or stride) is copied unchanged. Other
// properties of ghosts have storage but unspecified values.
//
// Single precision (--precision=single on the CPU backends). The scene computes on the float
// copy of each array (sphc::FloatArray, float_arrays.h); the overloads taking a FloatArray do
// the same on it: its floats hold the positions and ghosts, the integer properties of the host
// array (which have no float copy) grow ghosts as above, and the host doubles are left alone
// (they hold n particles). The arithmetic is that of the element type: wrapping and the
// ghost transforms round the planes and periods to float first and then compute in float, as
// the OpenCL kernels do with `real` = float; ghosts are found by comparing the float positions,
// widened to double, with the double planes (the OpenCL backend reads its float positions
// into doubles for find_ghosts), so every backend finds the same ghosts from the same
// positions.
//
// Requirements: a periodic axis needs hi - lo >= cutoff (one image per side is then
// enough), and so does an axis with mirrors on both sides; add_ghosts throws
// std::invalid_argument otherwise. Particles are never moved back through a mirror plane (the
// ghosts' pressure keeps them inside). Ghosts are found serially in a deterministic order
// (by real particle, then image), so serial and OpenMP solvers agree bit for bit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "sphc/float_arrays.h"
#include "sphc/nnps.h"
#include "sphc/particle_array.h"

namespace sphc {

enum class Boundary : std::uint8_t { Open, Periodic, Mirror };

struct Domain {
  int dim = 2;
  Boundary lo_kind[3] = {Boundary::Open, Boundary::Open, Boundary::Open};
  Boundary hi_kind[3] = {Boundary::Open, Boundary::Open, Boundary::Open};
  double lo[3] = {0.0, 0.0, 0.0};  // the low planes (periodic: the box is [lo, hi))
  double hi[3] = {0.0, 0.0, 0.0};

  bool periodic(int axis) const { return lo_kind[axis] == Boundary::Periodic; }
  bool any() const;
};

// Throws std::invalid_argument (naming the axis) unless: dim is 1..3; axes beyond dim are
// open; a periodic axis is periodic on both sides; every plane used is finite; lo < hi on an
// axis with two boundaries.
void check_domain(const Domain& d);

// Throws std::invalid_argument unless every axis with images on both sides (periodic, or
// mirrors on both) spans at least `cutoff`, the message naming the axis and ending in `why`
// (the generated solver says which of its choices needs that span and how to do without).
void check_ghost_span(const Domain& d, double cutoff, const std::string& why);

// Ghost particles of one array: ghost g copies real particle source[g] through image[g].
// image: 2 bits per axis (bits 2a, 2a+1): 0 = no image along axis a, 1 = the image through
// the low side (periodic: x + L; mirror: 2 lo - x), 2 = through the high side (x - L;
// 2 hi - x).
struct Ghosts {
  std::vector<std::uint32_t> source;
  std::vector<std::uint8_t> image;
  std::size_t size() const { return source.size(); }
};

// How a ghost's value of a position or velocity component along an axis comes from its
// source's value v through the image of one side: Shift (periodic position: v + t, t = +-L),
// Reflect (mirrored position: t - v, t = 2 * plane), Negate (velocity normal to a mirror: -v)
// or Copy. The one definition: add_ghosts and the OpenCL ghost-fill kernel both use it.
enum class GhostOp : std::uint8_t { Copy = 0, Shift = 1, Reflect = 2, Negate = 3 };
struct GhostTransform {
  GhostOp op = GhostOp::Copy;
  double t = 0.0;
};
// The transform of a position (position = true) or velocity component along `axis` through
// the image of side 0 (low) or 1 (high).
GhostTransform ghost_transform(const Domain& d, int axis, int side, bool position);

// What ghosts do with property p: for a double, stride 1 position x, y, z (position = true)
// or velocity u, v, w (position = false) the axis (0..2) of its transform; -1 for every other
// property (copied unchanged).
int ghost_axis(const Property& p, bool& position);

// Moves the real particles of `a` that left a periodic box back into [lo, hi) along each
// periodic axis (by whole periods). Non-finite coordinates are left as they are. Positions
// missing from the array are skipped.
void wrap_periodic(const Domain& d, ParticleArray& a);

// The one definition of which ghosts exist and in which order (add_ghosts and the OpenCL
// backend both use it): the ghosts of particles 0..n-1 with coordinates pos[0..2] (nullptr
// beyond dim; an axis with a periodic or mirror side needs its coordinates) within `cutoff`
// of a periodic or mirror side, into `g` (replacing its content), by particle, then image
// (x fastest, then y, then z; each axis: none, low, high). `array` names the array in
// errors. Returns g.size().
std::size_t find_ghosts(const Domain& d, const double* const pos[3], std::size_t n,
                        double cutoff, Ghosts& g, const std::string& array);
std::size_t find_ghosts(const Domain& d, const float* const pos[3], std::size_t n,
                        double cutoff, Ghosts& g, const std::string& array);

// Finds the ghosts of the real particles of `a` within `cutoff` of a periodic or mirror side
// (find_ghosts, into `g`, replacing its content), grows the storage of every property of `a` to
// a.n + g.size() particles and copies the properties `carried` (indices into a.props) to the
// ghosts. a.n is unchanged. Returns g.size().
std::size_t add_ghosts(const Domain& d, ParticleArray& a, double cutoff, Ghosts& g,
                       const std::vector<int>& carried);

// Copies the properties `props` (indices into a.props) from the real particles to their
// ghosts again (after an evaluation phase changed them on the real particles).
void refresh_ghosts(const Domain& d, ParticleArray& a, const Ghosts& g,
                    const std::vector<int>& props);

// Removes the ghosts: the storage of every property back to a.n particles; g emptied.
void remove_ghosts(ParticleArray& a, Ghosts& g);

// Kept ghosts (neighbour lists kept across steps, sphc --verlet-skin; docs/performance-log.md,
// "Neighbour lists with periodic and mirror sides"). Between two rebuilds of the lists the
// ghosts stay the same particles, in the same order, so the kept lists' indices stay valid:
//   - wrap_periodic_far moves back into the box only the real particles further than
//     margin * h outside it along a periodic axis (wrap_periodic wraps them all; a particle
//     closer to the box keeps its place and its ghosts, and interacts through them);
//   - hide_ghosts ends an evaluation: the storage back to a.n particles, `g` kept;
//   - restore_ghosts starts the next one with the same ghosts: the storage grown to
//     a.n + g.size() and the properties `carried` copied from their real particles through
//     their images, as add_ghosts does (the positions follow their originals). Returns g.size().
void wrap_periodic_far(const Domain& d, ParticleArray& a, double margin);
void hide_ghosts(ParticleArray& a);
std::size_t restore_ghosts(const Domain& d, ParticleArray& a, const Ghosts& g,
                           const std::vector<int>& carried);

// The same on the float copy `f` of `a` (--precision=single; see above).
void wrap_periodic(const Domain& d, FloatArray& f, const ParticleArray& a);
std::size_t add_ghosts(const Domain& d, FloatArray& f, ParticleArray& a, double cutoff, Ghosts& g,
                       const std::vector<int>& carried);
void refresh_ghosts(const Domain& d, FloatArray& f, ParticleArray& a, const Ghosts& g,
                    const std::vector<int>& props);
void remove_ghosts(FloatArray& f, ParticleArray& a, Ghosts& g);
void wrap_periodic_far(const Domain& d, FloatArray& f, const ParticleArray& a, double margin);
void hide_ghosts(FloatArray& f, ParticleArray& a);
std::size_t restore_ghosts(const Domain& d, FloatArray& f, ParticleArray& a, const Ghosts& g,
                           const std::vector<int>& carried);

// Widens a search domain made from the real particles so that it covers the ghosts too:
// `cutoff` beyond each periodic or mirror plane.
void extend_for_ghosts(SearchDomain& s, const Domain& d, double cutoff);

}  // namespace sphc
