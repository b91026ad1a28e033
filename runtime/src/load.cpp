#include "sphc/load.h"

#include "sphc/hdf5_io.h"
#include "sphc/memory.h"

#include <cmath>
#include <map>
#include <utility>
#include <stdexcept>
#include <string>

namespace sphc {

namespace {
bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

ParticleArray read_file(const std::string& full, const std::string& array) {
  if (endsWith(full, ".csv")) return read_particles_csv(full, array);
  if (endsWith(full, ".h5") || endsWith(full, ".hdf5")) return read_particles_hdf5(full, array);
  throw std::runtime_error("cannot load '" + full + "' for array '" + array +
                           "': expected a .h5, .hdf5 or .csv file");
}

// The set-up runs twice (sphc/memory.h: a counting pass, then the real one). A file read in
// the counting pass is kept here and handed over, once, to the real pass: each file is read
// once per run, and the real pass sees exactly what was counted.
std::map<std::pair<std::string, std::string>, ParticleArray>& read_while_counting() {
  static std::map<std::pair<std::string, std::string>, ParticleArray> kept;
  return kept;
}
}  // namespace

ParticleArray load_particles(const std::string& dir, const std::string& path,
                             const std::string& array) {
  std::string full = (!path.empty() && path[0] == '/') || dir.empty() ? path : dir + "/" + path;
  auto& kept = read_while_counting();
  const auto key = std::make_pair(full, array);
  if (counting_particles()) {
    ParticleArray a = read_file(full, array);
    kept[key] = a;
    return a;
  }
  if (auto it = kept.find(key); it != kept.end()) {
    ParticleArray a = std::move(it->second);
    kept.erase(it);
    return a;
  }
  return read_file(full, array);
}

Points positions_of(const ParticleArray& a) {
  Points p;
  const char* axes[3] = {"x", "y", "z"};
  std::vector<double>* out[3] = {&p.x, &p.y, &p.z};
  for (int k = 0; k < 3; ++k) {
    int i = a.find(axes[k]);
    if (i >= 0)
      *out[k] = a.props[i].f64;
    else if (k == 0)
      throw std::runtime_error("loaded array '" + a.name + "' has no 'x' column");
    else
      out[k]->assign(a.n, 0.0);
  }
  return p;
}

void apply_loaded(ParticleArray& a, std::size_t total, const std::vector<ParticleArray>& loaded) {
  std::size_t count = 0;
  for (const auto& l : loaded) count += l.n;
  std::size_t offset = total - count;
  for (const auto& l : loaded) {
    for (const auto& src : l.props) {
      int i = a.find(src.name);
      if (i < 0) continue;  // the scene does not use this property
      Property& dst = a.props[i];
      if (dst.stride != src.stride)
        throw std::runtime_error("property '" + src.name + "' of loaded array '" + a.name +
                                 "' has stride " + std::to_string(src.stride) +
                                 " in the file but " + std::to_string(dst.stride) +
                                 " in the scene");
      if (dst.type != src.type && src.type != PropType::F64)
        throw std::runtime_error("property '" + src.name + "' of loaded array '" + a.name +
                                 "' is " + prop_type_name(src.type) + " in the file but " +
                                 prop_type_name(dst.type) + " in the scene");
      std::size_t s = static_cast<std::size_t>(dst.stride);
      for (std::size_t j = 0; j < l.n * s; ++j) {
        const std::size_t k = offset * s + j;
        if (dst.type == src.type) {
          if (dst.type == PropType::F64) dst.f64[k] = src.f64[j];
          if (dst.type == PropType::I32) dst.i32[k] = src.i32[j];
          if (dst.type == PropType::U32) dst.u32[k] = src.u32[j];
          continue;
        }
        // A CSV column (always read as doubles) into an int or uint property: whole numbers
        // in range only.
        const double v = src.f64[j];
        const bool isU = dst.type == PropType::U32;
        if (v != std::floor(v) || v < (isU ? 0.0 : -2147483648.0) ||
            v > (isU ? 4294967295.0 : 2147483647.0))
          throw std::runtime_error("property '" + src.name + "' of loaded array '" + a.name +
                                   "' is " + prop_type_name(dst.type) +
                                   " in the scene, but the file has " + std::to_string(v) +
                                   " for particle " + std::to_string(j / s));
        if (isU)
          dst.u32[k] = static_cast<std::uint32_t>(v);
        else
          dst.i32[k] = static_cast<std::int32_t>(v);
      }
    }
    offset += l.n;
  }
}

}  // namespace sphc
