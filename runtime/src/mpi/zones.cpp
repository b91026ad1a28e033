// sphc runtime, distributed runs: see sphc/mpi/zones.h.
#include "sphc/mpi/zones.h"

#include <mpi.h>

#include <algorithm>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>

#include "sphc/mpi/comm.h"  // size

namespace sphc::mpi {

namespace {

// Every rank's `mine`, in rank order, on every rank.
template <class T>
std::vector<T> all_gather(const std::vector<T>& mine, MPI_Datatype type) {
  const int P = size();
  if (mine.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw std::runtime_error("inlet/outlet: more values on one rank than MPI's int counts hold");
  const int n = static_cast<int>(mine.size());
  std::vector<int> counts(static_cast<std::size_t>(P)), disp(static_cast<std::size_t>(P));
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  long total = 0;
  for (int r = 0; r < P; ++r) {
    if (total > std::numeric_limits<int>::max())
      throw std::runtime_error("inlet/outlet: more values over the ranks than MPI's int counts hold");
    disp[static_cast<std::size_t>(r)] = static_cast<int>(total);
    total += counts[static_cast<std::size_t>(r)];
  }
  std::vector<T> all(static_cast<std::size_t>(total));
  MPI_Allgatherv(mine.data(), n, type, all.data(), counts.data(), disp.data(), type,
                 MPI_COMM_WORLD);
  return all;
}

// x summed over the ranks, element by element.
void sum_over_ranks(std::vector<double>& x) {
  if (x.empty()) return;
  MPI_Allreduce(MPI_IN_PLACE, x.data(), static_cast<int>(x.size()), MPI_DOUBLE, MPI_SUM,
                MPI_COMM_WORLD);
}

// Counters after this rank changed them (now - before): before + the changes of every rank
// (one MPI_Allreduce for all of them).
void count_over_ranks(const std::vector<std::size_t*>& counters,
                      const std::vector<std::size_t>& before) {
  std::vector<long> change(counters.size());
  for (std::size_t k = 0; k < counters.size(); ++k)
    change[k] = static_cast<long>(*counters[k] - before[k]);
  MPI_Allreduce(MPI_IN_PLACE, change.data(), static_cast<int>(change.size()), MPI_LONG, MPI_SUM,
                MPI_COMM_WORLD);
  for (std::size_t k = 0; k < counters.size(); ++k)
    *counters[k] = before[k] + static_cast<std::size_t>(change[k]);
}

}  // namespace

std::vector<std::uint32_t> all_entering(const std::vector<std::uint32_t>& mine) {
  std::vector<std::uint32_t> all = all_gather(mine, MPI_UINT32_T);
  std::sort(all.begin(), all.end());
  return all;
}

ImageBand all_band(const ImageBand& mine) {
  ImageBand band;
  band.np = mine.np;
  band.pos = all_gather(mine.pos, MPI_DOUBLE);
  band.vals = all_gather(mine.vals, MPI_DOUBLE);
  band.gid = all_gather(mine.gid, MPI_UINT32_T);
  sort_band(band);
  return band;
}

bool update_inlet_outlet(InletOutlet& io, double t) {
  bool changed = false;
  for (InletZone& in : io.inlets) {  // inlet after inlet: the serial numbering
    const std::vector<std::size_t> crossed = enter_fluid(in);
    const std::vector<std::uint32_t> entering = all_entering(old_ids(in, crossed));
    give_fresh_ids(in, crossed, entering, io.ids.take(entering.size()));
    in.created += entering.size();
    set_inlet_velocity(in, t);
    changed |= !crossed.empty();
  }
  for (OutletZone& out : io.outlets) {
    const std::vector<std::size_t> before{out.entered, out.returned, out.removed};
    changed |= update_outlet(out);
    count_over_ranks({&out.entered, &out.returned, &out.removed}, before);
    if (out.kind == OutletKind::DoNothing) continue;
    const ImageBand band = all_band(image_band(out));
    ImageValues iv = interpolate_images(out, band);
    if (out.kind == OutletKind::Mirror) {
      apply_mirror(out, iv);
    } else {
      NormalBins b = normal_bins(out, iv);
      if (out.kind == OutletKind::Hybrid) {
        face_sums(out, band, b);  // from the gathered band: the same on every rank
      } else {
        sum_over_ranks(b.sum);
        sum_over_ranks(b.count);
      }
      advance_reference(out, b, t);
      apply_characteristic(out, iv, b);
    }
  }
  return changed;
}

}  // namespace sphc::mpi
