// sphc runtime: particle arrays. See particle_array.h.
#include "sphc/particle_array.h"

#include "sphc/memory.h"

#include "permute_values.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace sphc {

namespace {

// Resizes a property's values to n particles; new values are 0.
void resize_prop(Property& p, std::size_t n) {
  const std::size_t len = n * static_cast<std::size_t>(p.stride);
  switch (p.type) {
    case PropType::F64: p.f64.resize(len, 0.0); break;
    case PropType::I32: p.i32.resize(len, 0); break;
    case PropType::U32: p.u32.resize(len, 0u); break;
  }
}

}  // namespace

void copy_particle_values(Property& to, std::size_t j, const Property& from, std::size_t i) {
  const std::size_t s = static_cast<std::size_t>(to.stride);
  for (std::size_t c = 0; c < s; ++c) {
    switch (to.type) {
      case PropType::F64: to.f64[j * s + c] = from.f64[i * s + c]; break;
      case PropType::I32: to.i32[j * s + c] = from.i32[i * s + c]; break;
      case PropType::U32: to.u32[j * s + c] = from.u32[i * s + c]; break;
    }
  }
}

const char* prop_type_name(PropType t) {
  switch (t) {
    case PropType::F64: return "double";
    case PropType::I32: return "int";
    case PropType::U32: return "unsigned";
  }
  return "?";
}

int ParticleArray::add_property(const std::string& pname, PropType type, int stride,
                                double init) {
  const std::string where = "array '" + name + "', property '" + pname + "'";
  if (stride < 1) {
    throw std::invalid_argument(where + ": stride must be >= 1 (got " + std::to_string(stride) +
                                ")");
  }
  const int existing = find(pname);
  if (existing >= 0) {
    const Property& p = props[existing];
    if (p.type != type || p.stride != stride) {
      throw std::invalid_argument(where + " exists as " + prop_type_name(p.type) + "[" +
                                  std::to_string(p.stride) + "], requested as " +
                                  prop_type_name(type) + "[" + std::to_string(stride) + "]");
    }
    return existing;
  }
  Property p;
  p.name = pname;
  p.type = type;
  p.stride = stride;
  const std::size_t len = n * static_cast<std::size_t>(stride);
  switch (type) {
    case PropType::F64: p.f64.assign(len, init); break;
    case PropType::I32: p.i32.assign(len, static_cast<std::int32_t>(init)); break;
    case PropType::U32: p.u32.assign(len, static_cast<std::uint32_t>(init)); break;
  }
  props.push_back(std::move(p));
  return static_cast<int>(props.size()) - 1;
}

int ParticleArray::find(const std::string& pname) const {
  for (std::size_t k = 0; k < props.size(); ++k) {
    if (props[k].name == pname) return static_cast<int>(k);
  }
  return -1;
}

void ParticleArray::resize(std::size_t new_n) {
  if (counting_particles()) count_resize(*this, new_n);  // sphc/memory.h: record the size
  for (Property& p : props) resize_prop(p, new_n);
  n = new_n;
}

double* ParticleArray::f64(const std::string& pname) {
  return const_cast<double*>(static_cast<const ParticleArray&>(*this).f64(pname));
}

const double* ParticleArray::f64(const std::string& pname) const {
  const int idx = find(pname);
  if (idx < 0) throw std::out_of_range("array '" + name + "' has no property '" + pname + "'");
  if (props[idx].type != PropType::F64) {
    throw std::out_of_range("array '" + name + "', property '" + pname + "' is " +
                            prop_type_name(props[idx].type) + ", not double");
  }
  return props[idx].f64.data();
}

int ParticleArray::add_constant(const std::string& cname, int size, double init) {
  const int existing = find_constant(cname);
  if (existing >= 0) return existing;
  if (size < 0) {
    throw std::invalid_argument("array '" + name + "', constant '" + cname +
                                "': size must be >= 0 (got " + std::to_string(size) + ")");
  }
  constants.push_back(Constant{cname, std::vector<double>(static_cast<std::size_t>(size), init)});
  return static_cast<int>(constants.size()) - 1;
}

int ParticleArray::find_constant(const std::string& cname) const {
  for (std::size_t k = 0; k < constants.size(); ++k) {
    if (constants[k].name == cname) return static_cast<int>(k);
  }
  return -1;
}

double* ParticleArray::constant(const std::string& cname) {
  const int idx = find_constant(cname);
  if (idx < 0) throw std::out_of_range("array '" + name + "' has no constant '" + cname + "'");
  return constants[idx].values.data();
}

void ParticleArray::append_from(const ParticleArray& src, std::size_t i) {
  if (i >= src.n) {
    throw std::out_of_range("append_from: particle " + std::to_string(i) + " of array '" +
                            src.name + "' (which has " + std::to_string(src.n) + ")");
  }
  // Check everything before changing anything, so a failure leaves this array intact.
  std::vector<int> src_idx(props.size());
  for (std::size_t k = 0; k < props.size(); ++k) {
    const Property& p = props[k];
    src_idx[k] = src.find(p.name);
    if (src_idx[k] < 0) continue;
    const Property& q = src.props[src_idx[k]];
    if (q.type != p.type || q.stride != p.stride) {
      throw std::invalid_argument("append_from: property '" + p.name + "' is " +
                                  prop_type_name(p.type) + "[" + std::to_string(p.stride) +
                                  "] in array '" + name + "' but " + prop_type_name(q.type) +
                                  "[" + std::to_string(q.stride) + "] in array '" + src.name +
                                  "'");
    }
  }
  // src may be *this: grow first, then read src by index (never through stale pointers).
  for (std::size_t k = 0; k < props.size(); ++k) {
    Property& p = props[k];
    resize_prop(p, n + 1);
    if (src_idx[k] >= 0) copy_particle_values(p, n, src.props[src_idx[k]], i);
  }
  ++n;
}

namespace {
template <class T>
void compact_values(std::vector<T>& v, const std::vector<std::uint8_t>& remove, std::size_t s) {
  std::size_t out = 0;
  for (std::size_t i = 0; i < remove.size(); ++i) {
    if (remove[i]) continue;
    if (out != i)
      for (std::size_t k = 0; k < s; ++k) v[out * s + k] = v[i * s + k];
    ++out;
  }
  v.resize(out * s);
}
}  // namespace

std::size_t ParticleArray::remove_particles(const std::vector<std::uint8_t>& remove) {
  if (remove.size() != n) {
    throw std::invalid_argument("remove_particles: array '" + name + "' has " +
                                std::to_string(n) + " particles, the removal mask " +
                                std::to_string(remove.size()));
  }
  std::size_t removed = 0;
  for (std::uint8_t r : remove) removed += r != 0;
  if (removed == 0) return 0;
  for (Property& p : props) {
    const std::size_t s = static_cast<std::size_t>(p.stride);
    switch (p.type) {
      case PropType::F64: compact_values(p.f64, remove, s); break;
      case PropType::I32: compact_values(p.i32, remove, s); break;
      case PropType::U32: compact_values(p.u32, remove, s); break;
    }
  }
  n -= removed;
  return removed;
}

bool is_permutation_of(const std::vector<std::uint32_t>& order, std::size_t n) {
  if (order.size() != n) return false;
  // Every entry in range and every slot hit: n entries hitting n slots is a bijection. A
  // duplicate makes two threads mark one slot (an atomic store, a plain one on x86).
  std::vector<unsigned char> seen(n, 0);
  long bad = 0;
#pragma omp parallel for schedule(static) reduction(+ : bad) if (n > 16384)
  for (std::size_t i = 0; i < n; ++i) {
    if (order[i] >= n)
      ++bad;
    else {
#pragma omp atomic write
      seen[order[i]] = 1;
    }
  }
  if (bad) return false;
  long missing = 0;
#pragma omp parallel for schedule(static) reduction(+ : missing) if (n > 16384)
  for (std::size_t i = 0; i < n; ++i) missing += seen[i] == 0;
  return missing == 0;
}

void ParticleArray::permute(const std::vector<std::uint32_t>& order) {
  if (order.size() != n)
    throw std::invalid_argument("permute of array '" + name + "': the order has " +
                                std::to_string(order.size()) + " entries for " +
                                std::to_string(n) + " particles");
  if (!is_permutation_of(order, n))
    throw std::invalid_argument("permute of array '" + name + "': not a permutation");
  std::vector<double> f;
  std::vector<std::int32_t> i32;
  std::vector<std::uint32_t> u32;
  for (Property& p : props) {
    switch (p.type) {
      case PropType::F64: permute_values(p.f64, order, p.stride, f); break;
      case PropType::I32: permute_values(p.i32, order, p.stride, i32); break;
      case PropType::U32: permute_values(p.u32, order, p.stride, u32); break;
    }
  }
}

namespace {

// Values per block of the non-finite scan, and the fewest values worth a parallel scan.
constexpr std::size_t kFiniteBlock = 4096;
constexpr std::size_t kFiniteParallelMin = 65536;

// True if v[0..n) holds a NaN or an infinity (all exponent bits set). No early exit and no
// branch, so that the compiler vectorises it.
bool has_non_finite(const double* v, std::size_t n) {
  constexpr std::uint64_t kExponent = 0x7ff0000000000000ull;
  std::uint64_t bad = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t bits;
    std::memcpy(&bits, v + i, sizeof bits);
    bad |= static_cast<std::uint64_t>((~bits & kExponent) == 0);
  }
  return bad != 0;
}

struct FiniteBlock {
  const double* v;
  std::size_t n;
  std::size_t array, prop, begin;
};

}  // namespace

std::optional<NonFiniteValue> find_non_finite(const std::vector<ParticleArray*>& arrays) {
  std::vector<FiniteBlock> blocks;
  std::size_t total = 0;
  for (std::size_t a = 0; a < arrays.size(); ++a) {
    const ParticleArray* pa = arrays[a];
    if (pa == nullptr) continue;
    for (std::size_t k = 0; k < pa->props.size(); ++k) {
      const Property& p = pa->props[k];
      if (p.type != PropType::F64) continue;
      const std::size_t size = p.f64.size();
      for (std::size_t b = 0; b < size; b += kFiniteBlock) {
        blocks.push_back(FiniteBlock{p.f64.data() + b, std::min(kFiniteBlock, size - b), a, k, b});
      }
      total += size;
    }
  }
  // The first block with a bad value: blocks are in scan order, so the smallest index.
  const long nb = static_cast<long>(blocks.size());
  long first = std::numeric_limits<long>::max();
#pragma omp parallel for schedule(static) reduction(min : first) if (total >= kFiniteParallelMin)
  for (long b = 0; b < nb; ++b) {
    if (b < first && has_non_finite(blocks[b].v, blocks[b].n)) first = b;
  }
  if (first >= nb) return std::nullopt;
  const FiniteBlock& blk = blocks[static_cast<std::size_t>(first)];
  for (std::size_t i = 0; i < blk.n; ++i) {
    if (!std::isfinite(blk.v[i])) return NonFiniteValue{blk.array, blk.prop, blk.begin + i};
  }
  return std::nullopt;  // not reached: has_non_finite and isfinite agree
}

}  // namespace sphc
