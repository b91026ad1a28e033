// sphc runtime, distributed runs: see sphc/mpi/gather.h.
#include "sphc/mpi/gather.h"

#include <mpi.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>

#include "sphc/mpi/comm.h"
#include "sphc/mpi/decomposition.h"

namespace sphc::mpi {

void gather_arrays(const std::vector<ParticleArray*>& arrays, std::vector<ParticleArray>& out) {
  const int P = size(), me = rank();
  out.resize(arrays.size());
  for (std::size_t k = 0; k < arrays.size(); ++k) {
    const ParticleArray& a = *arrays[k];
    ParticleArray& o = out[k];
    o.name = a.name;
    o.constants = a.constants;
    o.props.clear();
    for (const Property& p : a.props) o.add_property(p.name, p.type, p.stride);
    const std::size_t w = packed_size(a);
    std::vector<double> send;
    send.reserve(a.n * w);
    for (std::size_t i = 0; i < a.n; ++i) pack_particle(a, i, send);
    // Counted in particles (an MPI type of w doubles): MPI's int counts and displacements
    // then hold up to 2^31 - 1 particles per array in all; beyond, a clear error.
    const std::size_t limit = static_cast<std::size_t>(std::numeric_limits<int>::max());
    const long whole = sum(static_cast<long>(a.n));
    if (static_cast<std::size_t>(whole) > limit)
      throw std::runtime_error(fmt::format(
          "gathered output of array '{}': {} particles, more than MPI's int counts hold ({}); "
          "write collectively (parallel HDF5) instead", a.name, whole, limit));
    const int mine = static_cast<int>(a.n);
    std::vector<int> counts(P), displ(P);
    MPI_Gather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    int total = 0;
    for (int r = 0; r < P; ++r) {
      displ[r] = total;
      total += counts[r];
    }
    std::vector<double> recv(me == 0 ? static_cast<std::size_t>(total) * w : 0);
    MPI_Datatype particle;
    MPI_Type_contiguous(static_cast<int>(std::max<std::size_t>(w, 1)), MPI_DOUBLE, &particle);
    MPI_Type_commit(&particle);
    MPI_Gatherv(send.data(), mine, particle, recv.data(), counts.data(), displ.data(), particle, 0,
                MPI_COMM_WORLD);
    MPI_Type_free(&particle);
    if (me != 0) {
      o.resize(0);
      continue;
    }
    const std::size_t n = w ? recv.size() / w : 0;
    o.resize(n);
    for (std::size_t i = 0; i < n; ++i) unpack_particle(o, i, &recv[i * w]);
    const int g = o.find("gid");
    if (g >= 0) {
      std::vector<std::uint32_t> order(n);
      std::iota(order.begin(), order.end(), 0u);
      const auto& gid = o.props[g].u32;
      std::sort(order.begin(), order.end(),
                [&](std::uint32_t x, std::uint32_t y) { return gid[x] < gid[y]; });
      o.permute(order);
    }
  }
}

}  // namespace sphc::mpi
