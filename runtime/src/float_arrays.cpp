// sphc runtime: single-precision copies of particle arrays. See float_arrays.h.
#include "sphc/float_arrays.h"

#include "permute_values.h"

#include <stdexcept>
#include <string>

namespace sphc {

namespace {

// In the OpenMP runtime these loops run in parallel (each index written by one thread).
template <class From, class To>
void convert(const std::vector<From>& from, std::vector<To>& to) {
  to.resize(from.size());
  const std::size_t m = from.size();
  const From* in = from.data();
  To* out = to.data();
#pragma omp parallel for schedule(static) if (m > 16384)
  for (std::size_t i = 0; i < m; ++i) out[i] = static_cast<To>(in[i]);
}

}  // namespace

void FloatArray::upload(const ParticleArray& a) {
  n = a.n;
  props.resize(a.props.size());
  for (std::size_t i = 0; i < a.props.size(); ++i) {
    if (a.props[i].type == PropType::F64)
      convert(a.props[i].f64, props[i]);
    else
      props[i].clear();
  }
  constants.resize(a.constants.size());
  for (std::size_t c = 0; c < a.constants.size(); ++c) convert(a.constants[c].values, constants[c]);
  const char* names[4] = {"x", "y", "z", "h"};
  for (int k = 0; k < 4; ++k) {
    const int i = a.find(names[k]);
    position[k] = i >= 0 && a.props[i].type == PropType::F64 ? i : -1;
  }
}

void FloatArray::download(ParticleArray& a) const {
  if (a.props.size() != props.size() || a.constants.size() != constants.size() || a.n != n)
    throw std::invalid_argument("FloatArray::download: array '" + a.name +
                                "' does not have the shape of its float copy");
  for (std::size_t i = 0; i < props.size(); ++i)
    if (a.props[i].type == PropType::F64) convert(props[i], a.props[i].f64);
  for (std::size_t c = 0; c < constants.size(); ++c) convert(constants[c], a.constants[c].values);
}

void FloatArray::permute(const std::vector<std::uint32_t>& order, ParticleArray& host) {
  if (order.size() != n || host.n != n || !is_permutation_of(order, n))
    throw std::invalid_argument("permute of the float copy of array '" + host.name +
                                "': not a permutation of its " + std::to_string(n) +
                                " particles");
  std::vector<float> f;
  std::vector<std::int32_t> i32;
  std::vector<std::uint32_t> u32;
  for (std::size_t i = 0; i < host.props.size(); ++i) {
    Property& p = host.props[i];
    switch (p.type) {
      case PropType::F64: permute_values(props[i], order, p.stride, f); break;
      case PropType::I32: permute_values(p.i32, order, p.stride, i32); break;
      case PropType::U32: permute_values(p.u32, order, p.stride, u32); break;
    }
  }
}

}  // namespace sphc
