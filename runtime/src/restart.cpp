// sphc runtime: restarting from an output file (see restart.h).
#include "sphc/restart.h"

#include <cstdint>
#include <stdexcept>

#include <fmt/format.h>

namespace sphc {
namespace {

// The solver's array `a` takes the particles and constants of the file's `f`.
void take(ParticleArray& a, ParticleArray& f, const std::string& path) {
  const std::string hint =
      "; a restart needs every property: write the outputs with --restartable";
  for (const Property& q : f.props) {
    const bool zero_position = (q.name == "y" || q.name == "z") && a.find(q.name) < 0;
    if (a.find(q.name) < 0 && q.name != "gid" && !zero_position)
      throw std::runtime_error(fmt::format(
          "restart file '{}': array '{}' has a property '{}' this solver's array does not "
          "have (a file of another scene, or of another build of it?)",
          path, a.name, q.name));
  }
  for (Property& p : a.props) {
    const int k = f.find(p.name);
    if (k < 0)
      throw std::runtime_error(fmt::format("restart file '{}': array '{}' has no property '{}'{}",
                                           path, a.name, p.name, hint));
    Property& q = f.props[static_cast<std::size_t>(k)];
    if (q.type != p.type || q.stride != std::max(p.stride, 1))
      throw std::runtime_error(fmt::format(
          "restart file '{}': property '{}' of array '{}' is {} with {} component(s), the "
          "solver's is {} with {}",
          path, p.name, a.name, prop_type_name(q.type), q.stride, prop_type_name(p.type),
          p.stride));
    // read_particles_hdf5 checked the rows: n x stride values of the property's type.
    p.f64 = std::move(q.f64);
    p.i32 = std::move(q.i32);
    p.u32 = std::move(q.u32);
  }
  a.n = f.n;
  for (Constant& c : a.constants) {
    const Constant* g = nullptr;
    for (const Constant& k : f.constants)
      if (k.name == c.name) g = &k;
    if (!g)
      throw std::runtime_error(fmt::format("restart file '{}': array '{}' has no constant '{}'",
                                           path, a.name, c.name));
    if (g->values.size() != c.values.size())
      throw std::runtime_error(fmt::format(
          "restart file '{}': constant '{}' of array '{}' has {} values, the solver's {}", path,
          c.name, a.name, g->values.size(), c.values.size()));
    c.values = g->values;
  }
}

}  // namespace

OutputMeta read_restart(const std::string& path, const std::vector<ParticleArray*>& arrays,
                        const std::string& scene, int dim, std::size_t part, std::size_t parts) {
  OutputMeta meta = read_meta_hdf5(path);
  if (!meta.scene.empty() && meta.scene != scene)
    throw std::runtime_error(fmt::format("restart file '{}' was written by scene '{}', not '{}'",
                                         path, meta.scene, scene));
  if (meta.dim != dim)
    throw std::runtime_error(
        fmt::format("restart file '{}' is {}D, the scene {}D", path, meta.dim, dim));
  if (meta.state.empty())
    throw std::runtime_error(fmt::format(
        "restart file '{}' has no run state (root attributes {}*): it was not written by an "
        "sphc solver that can restart",
        path, kRunStatePrefix));
  for (ParticleArray* a : arrays) {
    ParticleArray f = read_particles_hdf5(path, a->name, part, parts);
    take(*a, f, path);
  }
  return meta;
}

double state_value(const RunState& state, const std::string& name) {
  for (const auto& [key, value] : state)
    if (key == name) return value;
  throw std::runtime_error(fmt::format(
      "the restart file has no run state '{}' (root attribute {}{}): written by another "
      "build of the scene?",
      name, kRunStatePrefix, name));
}

double state_value(const RunState& state, const std::string& name, double otherwise) {
  for (const auto& [key, value] : state)
    if (key == name) return value;
  return otherwise;
}

void inlet_outlet_state(const InletOutlet& io, RunState& state) {
  state.emplace_back("io.next_gid", static_cast<double>(io.ids.next));
  for (std::size_t k = 0; k < io.inlets.size(); ++k)
    state.emplace_back(fmt::format("io.inlet{}.created", k),
                       static_cast<double>(io.inlets[k].created));
  for (std::size_t k = 0; k < io.outlets.size(); ++k) {
    const OutletZone& o = io.outlets[k];
    state.emplace_back(fmt::format("io.outlet{}.entered", k), static_cast<double>(o.entered));
    state.emplace_back(fmt::format("io.outlet{}.returned", k), static_cast<double>(o.returned));
    state.emplace_back(fmt::format("io.outlet{}.removed", k), static_cast<double>(o.removed));
    const bool hybrid = o.kind == OutletKind::Hybrid;
    if ((o.kind != OutletKind::Characteristic && !hybrid) || !o.started) continue;
    // The characteristic outlet's running mean u_ref per bin (and which bins have one; the
    // hybrid outlet's also its mean pressure) and when it was last updated: a restart goes
    // on averaging as the uninterrupted run does.
    state.emplace_back(fmt::format("io.outlet{}.t_last", k), o.t_last);
    state.emplace_back(fmt::format("io.outlet{}.bins", k), static_cast<double>(o.uref.size()));
    for (std::size_t b = 0; b < o.uref.size(); ++b) {
      state.emplace_back(fmt::format("io.outlet{}.uref{}", k, b), o.uref[b]);
      state.emplace_back(fmt::format("io.outlet{}.uref_set{}", k, b),
                         static_cast<double>(o.uref_set[b]));
      if (hybrid) state.emplace_back(fmt::format("io.outlet{}.pref{}", k, b), o.pref[b]);
    }
  }
}

void restore_inlet_outlet(InletOutlet& io, const RunState& state) {
  io.ids.next = static_cast<std::uint32_t>(state_value(state, "io.next_gid"));
  for (std::size_t k = 0; k < io.inlets.size(); ++k)
    io.inlets[k].created =
        static_cast<std::size_t>(state_value(state, fmt::format("io.inlet{}.created", k)));
  for (std::size_t k = 0; k < io.outlets.size(); ++k) {
    OutletZone& o = io.outlets[k];
    o.entered = static_cast<std::size_t>(state_value(state, fmt::format("io.outlet{}.entered", k)));
    o.returned =
        static_cast<std::size_t>(state_value(state, fmt::format("io.outlet{}.returned", k)));
    o.removed = static_cast<std::size_t>(state_value(state, fmt::format("io.outlet{}.removed", k)));
    // The characteristic outlet's running mean (absent: not started, or a file of a build
    // that did not save it; the mean then starts afresh).
    const double bins = state_value(state, fmt::format("io.outlet{}.bins", k), -1.0);
    const bool hybrid = o.kind == OutletKind::Hybrid;
    if ((o.kind != OutletKind::Characteristic && !hybrid) || bins < 0.0) continue;
    o.started = true;
    o.t_last = state_value(state, fmt::format("io.outlet{}.t_last", k));
    o.uref.assign(static_cast<std::size_t>(bins), 0.0);
    o.uref_set.assign(o.uref.size(), 0);
    if (hybrid) o.pref.assign(o.uref.size(), 0.0);
    for (std::size_t b = 0; b < o.uref.size(); ++b) {
      o.uref[b] = state_value(state, fmt::format("io.outlet{}.uref{}", k, b));
      o.uref_set[b] = state_value(state, fmt::format("io.outlet{}.uref_set{}", k, b)) != 0.0;
      if (hybrid) o.pref[b] = state_value(state, fmt::format("io.outlet{}.pref{}", k, b));
    }
  }
}

}  // namespace sphc
