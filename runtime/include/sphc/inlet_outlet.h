// sphc runtime: the inlet/outlet manager (open boundaries).
//
// A zone is a box outside the fluid: a face (a plane through `point` with the unit outward
// normal `normal`, pointing away from the fluid), the zone's depth `length` along the normal
// and its `width` across it (centred on `point`; in 3D a square of that side). A position x
// is in the zone when 0 <= s <= length and |t_k| <= width / 2 for the tangential coordinates,
// with s = (x - point) . normal.
//
// Inlet [the open boundaries of PySPH's inlet/outlet manager and of Negi, Ramachandran &
// Haftu (2019)]: the zone holds the particles of the inlet array, which move with the
// prescribed velocity (towards the fluid, -normal). After each time step (update_inlet):
//   - every inlet particle gets the prescribed velocity at its position and the new time;
//   - an inlet particle that crossed the face (s < 0) is appended to the fed array (the
//     listed properties copied, its gid kept), and the inlet particle itself moves back by
//     `length` along the normal (to the far end of the zone) with a fresh gid: the zone keeps
//     its particles and the lattice they came in.
// Outlet: the zone holds the particles of the outlet array. After each time step
// (update_outlet):
//   - a particle of the source array inside the outlet zone's cross-section with s >= 0 moves
//     to the outlet array (copied, gid kept, removed from the source);
//   - an outlet particle with s < 0 (flowing back) returns to the source array;
//   - an outlet particle past the zone (s > length) is removed.
// The outlet condition (how outlet particles get their properties):
//   - do_nothing (Negi et al. 2019, sec. 3.1): their velocity and pressure are those they
//     carried in; the manager changes nothing (the scene's equations on the outlet array may).
//   - mirror (after the mirror condition of Negi et al. 2019: outlet properties taken from
//     the fluid through the image point): after the moves, every outlet particle at depth s
//     takes the copied properties other than x, y, z, m, h and gid (velocity, pressure,
//     density, ...) interpolated from the source array at its mirror image across the face,
//     p - 2 s normal, by a Shepard average with the Wendland C2 weight of radius `support`
//     (the kernel support). A zero normal gradient at the face: the outflow continues with
//     the fluid's velocity profile and pressure instead of the values frozen when each
//     particle left. A particle whose image has no source particle within the support keeps
//     its values. The fluid particles are added in gid order (ImageBand).
//   - characteristic (the method of characteristics of Lastiwka, Basa & Quinlan 2009, one of
//     the outlets compared by Negi et al. 2019): the image interpolation of `mirror` gives
//     each outlet particle the fluid's p_f, u_f, rho_f at its image; of the three
//     characteristic variables of the 1D Euler equations along the normal (reference state
//     p_ref, u_ref), the incoming one, J3 = -rho c (u_n - u_ref) + (p - p_ref), is set to 0
//     (no wave comes in through the outlet) and the outgoing acoustic one,
//     J2 = rho c (u_n - u_ref) + (p - p_ref), is the fluid's: p = p_ref + J2 / 2,
//     u_n = u_ref + J2 / (2 rho c); the tangential velocity and the density are the image's
//     (J1, the entropy wave, would only change rho, which an EDAC scheme does not read).
//     u_ref is the image's normal velocity averaged in time (exponentially, time scale `tau`,
//     default 20 length / c) in bins across the face of width support / 2: the mean outflow,
//     from which an acoustic wave leaving the fluid (u_n - u_ref = (p - p_ref) / (rho c))
//     passes unchanged. p_ref (default 0) pins the pressure level at the outlet: a steady
//     fluid pressure p gives the outlet (p + p_ref) / 2, so the level cannot drift as it can
//     with the other outlets under EDAC, where no equation of state fixes it. (Tried and
//     dropped: J2 sampled half a support inside the face and delayed by the travel time to
//     each outlet particle: the channel's pulse reflected more, R = -0.13 against +0.08.)
//   - hybrid (the hybrid outlet of Negi, Ramachandran & Haftu 2019: the mean flow of the
//     frozen-particle outlet plus the fluctuation of the characteristic one): the outlet's
//     velocity and pressure are a time average plus a fluctuation. The average, per bin across
//     the face (the bins of u_ref), is a running mean in time (time scale `tau`, default
//     20 length / c) of the fluid's mean normal velocity u_ta and pressure p_ta over its
//     particles within a kernel support of the face, in that bin, set from the first step.
//     Pressure samples count only while quiet (Negi et al.'s criterion, as their PySPH
//     implementation, pysph/sph/bc/hybrid, applies it; the formulas here are in this file's
//     notation, the paper's equation numbers not checked): their acoustic
//     intensity (p - p_ref)^2 / (2 rho c) below I_min = (rho U^2 / 2)^2 / (2 rho c), i.e.
//     |p - p_ref| < rho U^2 / 2, U and rho the face's mean normal velocity and density at that
//     step (p_ref default 0: the outlet's intended pressure); the velocity's always count.
//     The fluctuation is the outgoing characteristic measured from that average at each outlet
//     particle's image, J2 = rho c (u_n - u_ta) + (p - p_ta) (u_n, p: the mirror
//     interpolation), the incoming one set to 0: p = p_ta + J2 / 2, u_n = u_ta + J2 / (2 rho c)
//     (the paper's outlet velocity and pressure from J2 and the time averages); the
//     tangential velocity and the density are the image's. While the fluid's pressure at the
//     face stays within rho U^2 / 2 of p_ref, steady flow leaves with it (zero normal
//     gradient, as mirror); beyond, p_ta holds and the outlet acts as the characteristic one
//     around it (pulling the level back towards p_ta: the level does not drift as with the
//     do-nothing and mirror outlets). A wave leaving the fluid passes (u_n - u_ta =
//     (p - p_ta) / (rho c): J2 = 2 (p - p_ta)), one coming in is removed. Not as in the paper:
//     the average is a running mean per bin of the fluid at the face, not each fluid
//     particle's average of its last 6 quiet samples frozen into it when it leaves, and the
//     quiet test is on the bin's mean pressure (U: the face's mean now, not a given speed) and
//     gates the pressure only (gating the velocity too would keep u_ta = 0 in a flow started
//     from rest, where U = 0: nothing is quiet).
//
// Arrays change size only here, between time steps, never during an evaluation: the neighbour
// search, ghosts and cell lists are rebuilt from the current sizes at every evaluation. All
// of it is serial and in particle order, so every backend produces the same arrays. A
// distributed run (sphc --mpi) does the same steps on each rank's particles with the few
// collectives of sphc/mpi/zones.h between them: fresh ids in old-id order, the image band
// gathered from every rank, the characteristic and hybrid outlets' bin sums added over the
// ranks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "sphc/global_ids.h"
#include "sphc/particle_array.h"

namespace sphc {

struct Zone {
  std::string name;           // for messages: "inlet 'in' (channel.sph:40:3)"
  int dim = 2;
  double point[3] = {0, 0, 0};
  double normal[3] = {0, 0, 0};  // outward; normalised by check_zone
  double length = 0.0;
  double width = 0.0;
  // s (along the normal) of position p, and whether p lies within the zone's cross-section.
  double depth(const double p[3]) const;
  bool across(const double p[3]) const;
};

// Throws std::invalid_argument naming the zone and the numbers unless the normal has
// non-zero length (then it is normalised), length > 0 and width > 0, and length >= support
// (the kernel's support radius_scale * h: a thinner zone leaves fluid particles near the face
// with an incomplete neighbourhood).
void check_zone(Zone& z, double support);

// How the properties of a particle moving between arrays are copied: to[k] from from[k]
// (indices into the arrays' props; properties not listed are 0 in the new particle).
struct CopyMap {
  std::vector<int> to, from;
};
// The map of the properties `names` (empty: every property both arrays have), gid always
// included. Throws std::invalid_argument if a name is missing from either array or types
// differ.
CopyMap make_copy_map(const ParticleArray& to, const ParticleArray& from,
                      const std::vector<std::string>& names);
// Appends particle i of `from` to `to` through the map.
void append_particle(ParticleArray& to, const ParticleArray& from, std::size_t i,
                     const CopyMap& map);

struct InletZone {
  Zone zone;
  ParticleArray* inlet = nullptr;  // the zone's particles
  ParticleArray* feeds = nullptr;  // the array they join
  std::vector<std::string> copy;   // properties copied (empty: all common)
  // The prescribed velocity at position p and time t into v[0..2] (empty: velocities kept).
  std::function<void(const double* p, double t, double* v)> velocity;
  CopyMap map;                     // set by init_inlet_outlet
  std::size_t created = 0;         // particles that entered the fed array so far
};

enum class OutletKind : std::uint8_t { DoNothing, Mirror, Characteristic, Hybrid };

struct OutletZone {
  Zone zone;
  ParticleArray* outlet = nullptr;  // the zone's particles
  ParticleArray* from = nullptr;    // the array whose particles flow into it
  std::vector<std::string> copy;
  OutletKind kind = OutletKind::DoNothing;
  CopyMap in, back;                 // from -> outlet, outlet -> from
  std::size_t entered = 0, returned = 0, removed = 0;
  double support = 0.0;             // mirror: the interpolation radius (set by init)
  CopyMap mirrored;                 // mirror: outlet <- from, the interpolated properties
  // characteristic and hybrid: the sound speed, reference pressure (hybrid: of the quiet test),
  // averaging time (0: 20 length / c), and the state: the mean normal velocity per bin across
  // the face (hybrid: and the mean pressure, pref), the last time seen.
  double c = 0.0, p_ref = 0.0, tau = 0.0;
  std::vector<double> uref, pref;
  std::vector<std::uint8_t> uref_set;
  double t_last = 0.0;
  bool started = false;
};

struct InletOutlet {
  std::vector<InletZone> inlets;
  std::vector<OutletZone> outlets;
  GlobalIds ids;
};

// The largest smoothing length h over the arrays (0 if none has h or particles).
double largest_h(const std::vector<ParticleArray*>& arrays);

// After set-up: checks every zone (support: radius_scale * the largest h of the arrays),
// numbers the particles of `all` (every array of the scene) with global ids, makes the copy
// maps and sets the inlet velocities at time t.
void init_inlet_outlet(InletOutlet& io, const std::vector<ParticleArray*>& all, double support,
                       double t);

// Whether update_inlet_outlet would move any particle (from positions only): a backend
// whose data lives elsewhere reads the positions, and everything else only when this says so.
bool inlet_outlet_due(const InletOutlet& io);
// The prescribed velocities of every inlet's particles at time t (positions only).
void set_inlet_velocities(InletOutlet& io, double t);

// One inlet or outlet after a time step (new time t); update_inlet_outlet does every inlet,
// then every outlet. Returns whether any array changed size.
bool update_inlet(InletZone& in, GlobalIds& ids, double t);
bool update_outlet(OutletZone& out);
// The mirror condition (OutletKind::Mirror): interpolates out.mirrored at every outlet
// particle's image point. Returns the number of particles that found no source near their
// image (and kept their values).
std::size_t mirror_outlet(OutletZone& out);
// The characteristic condition (OutletKind::Characteristic) at time t: the mirror
// interpolation, then p and the normal velocity from the outgoing characteristic (above).
// Throws std::invalid_argument unless c > 0 and the outlet array has p and u (v, w in 2D/3D).
std::size_t characteristic_outlet(OutletZone& out, double t);
// The hybrid condition (OutletKind::Hybrid) at time t: as characteristic_outlet, with the
// running mean pressure per bin in place of p_ref (above). The same checks.
std::size_t hybrid_outlet(OutletZone& out, double t);
bool update_inlet_outlet(InletOutlet& io, double t);

// ---- The steps these are made of (a distributed run, sphc/mpi/zones.h, puts collectives
// between them; a serial run calls them in a row). ----

// Fresh ids. The inlet particles that crossed the face get fresh ids in the order of their
// old ids (not of their places in the array, which depend on reorders and, in a distributed
// run, on the ranks), so every run numbers them alike. enter_fluid appends every inlet
// particle that crossed to the fed array and moves it back by the zone length; it returns
// their places in the inlet array (ids untouched, `created` unchanged).
std::vector<std::size_t> enter_fluid(InletZone& in);
// The old gids of the inlet particles at `crossed`.
std::vector<std::uint32_t> old_ids(const InletZone& in, const std::vector<std::size_t>& crossed);
// `entering`: the old gids of every particle that crossed this inlet (all ranks), ascending;
// the particle at crossed[k] gets first + (the place of its old gid in `entering`). Throws
// std::logic_error if its old gid is not there.
void give_fresh_ids(InletZone& in, const std::vector<std::size_t>& crossed,
                    const std::vector<std::uint32_t>& entering, std::uint32_t first);
// The inlet particles' prescribed velocities at time t (update_inlet's last step).
void set_inlet_velocity(InletZone& in, double t);

// The band of the source array an outlet's image points can reach (depth in
// [-(2 length + support), 0]): positions (3 per particle), the values of out.mirrored
// (np per particle) and gid, in gid order (so the interpolation adds them in an order that
// does not depend on reorders or ranks).
struct ImageBand {
  std::size_t np = 0;
  std::vector<double> pos, vals;
  std::vector<std::uint32_t> gid;
  std::size_t size() const { return gid.size(); }
};
// This array's particles in the band (unsorted); sort_band puts a band in gid order.
ImageBand image_band(const OutletZone& out);
void sort_band(ImageBand& band);
// The interpolation at every outlet particle's image from the band: vals[i * np + k],
// found[i] = 0 where no band particle lies within the support (lonely counts them).
struct ImageValues {
  std::vector<double> vals;
  std::vector<std::uint8_t> found;
  std::size_t lonely = 0;
};
ImageValues interpolate_images(const OutletZone& out, const ImageBand& band);
// The mirror condition from interpolated values.
void apply_mirror(OutletZone& out, const ImageValues& iv);
// The characteristic and hybrid conditions in three steps: the image normal velocity of every
// outlet particle and its sums per bin across the face (sum, count: this array's particles; a
// distributed run adds them over the ranks), the running means (u_ref; hybrid: and p_ta)
// updated from the sums at time t, and p and u_n set from the outgoing characteristic.
struct NormalBins {
  std::vector<std::size_t> bin;  // per outlet particle
  std::vector<double> un;        // per outlet particle: the image's normal velocity
  std::vector<double> sum, count;  // per bin
  std::vector<double> psum, rsum;  // per bin, hybrid only (empty otherwise): p and rho
};
NormalBins normal_bins(const OutletZone& out, const ImageValues& iv);
// The hybrid outlet's sums instead: sum (normal velocity), psum (pressure) and count per bin
// over the band's particles within a kernel support of the face (and within its width), in
// the band's order (a gathered band: the same sums on every rank, nothing to add up).
void face_sums(const OutletZone& out, const ImageBand& band, NormalBins& b);
void advance_reference(OutletZone& out, const NormalBins& b, double t);
void apply_characteristic(OutletZone& out, ImageValues& iv, const NormalBins& b);

}  // namespace sphc
