// sphc runtime: physical sanity checks of a run, beyond NaN (docs/language.md, Limits).
//
// A Limit bounds one quantity of one array: a property (rho: the density deviation of a
// weakly compressible scheme; x, y, z: particles leaving the tank or crossing a wall) or
// `speed`, |(u, v, w)| (against the sound speed). The run loop (solver.cpp) checks every limit
// where it checks for non-finite values (before each output and every few steps): outside
// `warn` it warns once per limit, naming the numbers and the worst particle (array, index,
// position); outside `stop` it stops as a blow-up, so every output it writes is within the
// stop bounds. Scenes declare limits in `limits { }`; without any, each array gets a box
// (bounding_box_limits) around where the particles were at set-up.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "sphc/particle_array.h"

namespace sphc {

// [lo, hi]; an absent end is infinite.
struct Bounds {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool contains(double v) const { return v >= lo && v <= hi; }
  // How far v is outside (0 inside; NaN counts as infinitely far).
  double excess(double v) const {
    if (std::isnan(v)) return std::numeric_limits<double>::infinity();
    return v < lo ? lo - v : v > hi ? v - hi : 0.0;
  }
  std::string text() const;  // "[990, 1010]", "<= 60", ">= -0.09"
};

struct Limit {
  std::string array;     // the array's name
  std::string quantity;  // a property (stride 1), or "speed"
  std::string where;     // source location of the scene's item ("dambreak.sph:151"); empty:
                         // set on the command line or a default
  std::optional<Bounds> warn, stop;
  // `remove [lo, hi] where C in [lo, hi]` (a position only): the particles outside `remove`
  // whose coordinate `remove_where` ("x", "y", "z"; empty: every particle) lies within
  // `where_bounds` are taken out of the run before the bounds are checked (an open tank's
  // splash over a wall). The scene's, kept under --limits warn and off.
  std::optional<Bounds> remove;
  std::string remove_where;
  Bounds where_bounds;
  std::string name() const { return array + "." + quantity; }
  // "outside [-0.06, 4.06] where y >= 4"
  std::string remove_text() const;
};

// The default limits of a scene that declares none: for every array with positions, the
// bounding box of all arrays' particles, grown on each side by `warn_margin` (warn) and
// `stop_margin` (stop) times its largest side (per axis of the first `dim`).
constexpr double kDefaultWarnMargin = 1.0;
constexpr double kDefaultStopMargin = 10.0;
std::vector<Limit> bounding_box_limits(const std::vector<ParticleArray*>& arrays, int dim,
                                       double warn_margin = kDefaultWarnMargin,
                                       double stop_margin = kDefaultStopMargin);

// One limit checked on one state: how many particles are outside each bound and the worst
// of them (the furthest outside; the stop bound's if any is outside it, else the warn one's).
struct LimitCheck {
  std::size_t outside_warn = 0, outside_stop = 0;
  std::size_t worst = 0;     // particle index
  double value = 0;          // its value of the quantity
  double excess = 0;         // how far outside
};

// Checks `limit` on `a` (the array it names; a quantity it lacks: std::runtime_error naming
// the limit and where it comes from).
LimitCheck check_limit(const Limit& limit, const ParticleArray& a, int dim);

// The particles of `a` that `limit`'s remove bound takes out now: mask[i] = 1 for each (the
// size of the array; empty if none). A particle with a NaN in the quantity or the condition's
// coordinate is not removed (the run's NaN check names it). std::runtime_error as check_limit
// for a quantity the array lacks.
std::vector<std::uint8_t> removal_mask(const Limit& limit, const ParticleArray& a, int dim);

// "particle 37 of array 'fluid' at (0.015, -0.062) has rho = 607000"
std::string describe_particle(const ParticleArray& a, std::size_t i, int dim,
                              const std::string& quantity, double value);

// Applies a command-line setting `ARRAY.QUANTITY.warn=LO:HI` or `...stop=LO:HI` (either end
// may be empty: unbounded; the value `off` removes that bound) to `limits`, adding a limit if
// the scene has none for that quantity. std::invalid_argument with a message if malformed.
void apply_limit_setting(std::vector<Limit>& limits, const std::string& setting);

}  // namespace sphc
