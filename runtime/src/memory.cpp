// sphc runtime: the memory estimate of a run. See memory.h.
#include "sphc/memory.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>

#include "sphc/particle_array.h"

namespace sphc {
namespace {

// The state of the one CountingPass (the set-up runs on one thread).
struct Counting {
  bool active = false;
  std::size_t pending = 0;  // points counted since the last resize
  std::map<const ParticleArray*, std::size_t> planned;
};

Counting& counting() {
  static Counting c;
  return c;
}

double value_bytes(PropType t) { return t == PropType::F64 ? 8.0 : 4.0; }

std::string count_text(std::size_t n) {
  // 200000000 -> "200,000,000": easier to read than 2e+08 and exact.
  std::string digits = std::to_string(n), out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

// The first number of a line "Key: 123 kB" of /proc/meminfo, in bytes.
std::optional<double> meminfo(const std::string& key) {
  std::ifstream f("/proc/meminfo");
  std::string line;
  while (std::getline(f, line)) {
    if (line.rfind(key + ":", 0) != 0) continue;
    std::istringstream in(line.substr(key.size() + 1));
    double value = 0;
    std::string unit;
    if (!(in >> value)) return std::nullopt;
    in >> unit;
    return unit == "kB" ? value * 1024.0 : value;
  }
  return std::nullopt;
}

// A number in a file (cgroup limits); nullopt for "max", a missing file or no number.
std::optional<double> number_in(const char* path) {
  std::ifstream f(path);
  std::string word;
  if (!(f >> word) || word == "max") return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(word.c_str(), &end);
  if (end == word.c_str() || !(v > 0)) return std::nullopt;
  return v;
}

}  // namespace

CountingPass::CountingPass() {
  Counting& c = counting();
  c = Counting{};
  c.active = true;
}

CountingPass::~CountingPass() { counting() = Counting{}; }

std::size_t CountingPass::planned(const ParticleArray& a) const {
  const auto& p = counting().planned;
  auto it = p.find(&a);
  return it == p.end() ? 0 : it->second;
}

bool counting_particles() { return counting().active; }

void count_points(std::size_t n) { counting().pending += n; }

void count_resize(const ParticleArray& a, std::size_t n) {
  Counting& c = counting();
  c.planned[&a] = n + c.pending;
  c.pending = 0;
}

ArrayFootprint footprint(const ParticleArray& a, std::size_t particles) {
  ArrayFootprint f;
  f.name = a.name;
  f.particles = particles;
  for (const Property& p : a.props) {
    const double stride = std::max(p.stride, 1);
    const double bytes = stride * value_bytes(p.type);
    f.bytes_per_particle += bytes;
    if (p.type == PropType::F64) f.doubles_per_particle += stride;
    f.largest_property_bytes = std::max(f.largest_property_bytes, bytes);
  }
  return f;
}

std::string MemoryEstimate::describe() const {
  std::vector<MemoryItem> sorted = items;
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const MemoryItem& a, const MemoryItem& b) { return a.bytes > b.bytes; });
  std::string text;
  for (const MemoryItem& i : sorted) {
    if (i.bytes <= 0) continue;
    text += fmt::format("{}{} {}", text.empty() ? "" : ", ", i.what, format_bytes(i.bytes));
  }
  return text;
}

MemoryEstimate estimate_memory(const std::vector<ArrayFootprint>& arrays, bool single_precision) {
  MemoryEstimate e;
  double scratch = 0, points = 0, particles = 0;
  for (const ArrayFootprint& a : arrays) {
    const double n = static_cast<double>(a.particles);
    particles += n;
    e.items.push_back({fmt::format("particle data of array '{}' ({} particles x {} B)", a.name,
                                   count_text(a.particles), a.bytes_per_particle),
                       n * a.bytes_per_particle});
    if (single_precision && a.doubles_per_particle > 0) {
      e.items.push_back({fmt::format("float copies of array '{}' (--precision=single)", a.name),
                         n * a.doubles_per_particle * 4.0});
    }
    scratch = std::max(scratch, n * a.largest_property_bytes);
    points = std::max(points, n * 24.0);
  }
  e.items.push_back({"cell lists of the neighbour search", particles * kSearchBytesPerParticle});
  e.items.push_back({"reorder and output scratch", scratch});
  e.items.push_back({"geometry points during the set-up", points});
  double sum = 0;
  for (const MemoryItem& i : e.items) sum += i.bytes;
  e.items.push_back({fmt::format("margin for ghosts and slack ({:.0f}%)", kMarginFraction * 100),
                     sum * kMarginFraction});
  e.total = sum * (1.0 + kMarginFraction);
  return e;
}

std::optional<double> available_memory() {
  std::optional<double> avail = meminfo("MemAvailable");
  // cgroup v2: the limit less what the group uses now; v1: the same from its files.
  std::optional<double> limit = number_in("/sys/fs/cgroup/memory.max");
  std::optional<double> used = number_in("/sys/fs/cgroup/memory.current");
  if (!limit) {
    limit = number_in("/sys/fs/cgroup/memory/memory.limit_in_bytes");
    used = number_in("/sys/fs/cgroup/memory/memory.usage_in_bytes");
  }
  // v1 reports "no limit" as a huge number (2^63 rounded to pages): ignore it.
  if (limit && *limit < 1e18) {
    const double free_in_group = std::max(0.0, *limit - used.value_or(0.0));
    avail = avail ? std::min(*avail, free_in_group) : free_in_group;
  }
  return avail;
}

std::optional<double> parse_memory_size(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || !std::isfinite(v) || !(v > 0)) return std::nullopt;
  std::string unit(end);
  if (!unit.empty() && (unit.back() == 'B' || unit.back() == 'b')) unit.pop_back();
  if (unit.size() > 1) return std::nullopt;
  double scale = 1;
  if (!unit.empty()) {
    const std::string units = "kmgt";
    const auto k = units.find(static_cast<char>(std::tolower(unit[0])));
    if (k == std::string::npos) return std::nullopt;
    scale = std::pow(1024.0, static_cast<double>(k + 1));
  }
  return v * scale;
}

std::string format_bytes(double bytes) {
  const char* units[] = {"B", "kB", "MB", "GB", "TB", "PB"};
  int u = 0;
  while (bytes >= 1024.0 && u < 5) {
    bytes /= 1024.0;
    ++u;
  }
  return u == 0 ? fmt::format("{:.0f} B", bytes) : fmt::format("{:.3g} {}", bytes, units[u]);
}

}  // namespace sphc
