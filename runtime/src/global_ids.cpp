// sphc runtime: global particle ids (sphc/global_ids.h).
#include "sphc/global_ids.h"

#include <stdexcept>

namespace sphc {

std::uint32_t GlobalIds::take() {
  if (next == UINT32_MAX) throw std::overflow_error("global particle ids exhausted (2^32 - 1 used)");
  return next++;
}

std::uint32_t GlobalIds::take(std::size_t count) {
  if (count > static_cast<std::size_t>(UINT32_MAX - next))
    throw std::overflow_error("global particle ids exhausted (2^32 - 1 used)");
  const std::uint32_t first = next;
  next += static_cast<std::uint32_t>(count);
  return first;
}

void assign_global_ids(const std::vector<ParticleArray*>& arrays, GlobalIds& ids) {
  for (ParticleArray* a : arrays) {
    const int g = a->add_property("gid", PropType::U32, 1);
    std::uint32_t* gid = a->u32(g);
    for (std::size_t i = 0; i < a->n; ++i) gid[i] = ids.take();
  }
}

}  // namespace sphc
