// sphc runtime, distributed runs: see sphc/mpi/halo.h.
#include "sphc/mpi/halo.h"

#include <mpi.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>

#include "sphc/mpi/comm.h"

namespace sphc::mpi {

namespace {

const char* const kAxis[3] = {"x", "y", "z"};

// Value v of a property along `axis` (position or velocity) through the image bits.
double transformed(const Domain& d, int axis, bool position, std::uint8_t image, double v) {
  const int bits = (image >> (2 * axis)) & 3;
  if (bits == 0) return v;
  const GhostTransform t = ghost_transform(d, axis, bits - 1, position);
  switch (t.op) {
    case GhostOp::Shift: return v + t.t;
    case GhostOp::Reflect: return t.t - v;
    case GhostOp::Negate: return -v;
    case GhostOp::Copy: break;
  }
  return v;
}

std::size_t width_of(const ParticleArray& a, const std::vector<int>& props) {
  std::size_t w = 0;
  for (int p : props) w += static_cast<std::size_t>(a.props[p].stride);
  return w;
}

// Packs `props` of the particles of h's send lists, exchanges them and writes them into
// storage a.n + (received so far) on. Sizes the storage first when `grow`.
void send_props(const Domain& d, ParticleArray& a, Halo& h, const std::vector<int>& props) {
  const int P = size();
  const std::size_t w = width_of(a, props);
  std::vector<int> scount(P), sdispl(P), rcount(P), rdispl(P);
  std::vector<double> send;
  std::vector<int> axes(props.size());
  std::vector<char> is_pos(props.size());
  for (std::size_t k = 0; k < props.size(); ++k) {
    bool position = false;
    axes[k] = ghost_axis(a.props[props[k]], position);
    is_pos[k] = position;
  }
  for (int r = 0; r < P; ++r) {
    sdispl[r] = static_cast<int>(send.size());
    const auto& idx = h.send_index[r];
    const auto& img = h.send_image[r];
    for (std::size_t k = 0; k < idx.size(); ++k) {
      const std::size_t i = idx[k];
      for (std::size_t q = 0; q < props.size(); ++q) {
        const Property& p = a.props[props[q]];
        const std::size_t s = static_cast<std::size_t>(p.stride);
        for (std::size_t c = 0; c < s; ++c) {
          double v = p.type == PropType::F64   ? p.f64[i * s + c]
                     : p.type == PropType::I32 ? static_cast<double>(p.i32[i * s + c])
                                               : static_cast<double>(p.u32[i * s + c]);
          if (axes[q] >= 0) v = transformed(d, axes[q], is_pos[q], img[k], v);
          send.push_back(v);
        }
      }
    }
    scount[r] = static_cast<int>(send.size()) - sdispl[r];
  }
  int total = 0;
  for (int r = 0; r < P; ++r) {
    rcount[r] = h.recv_count[r] * static_cast<int>(w);
    rdispl[r] = total;
    total += rcount[r];
  }
  std::vector<double> recv(static_cast<std::size_t>(total));
  MPI_Alltoallv(send.data(), scount.data(), sdispl.data(), MPI_DOUBLE, recv.data(), rcount.data(),
                rdispl.data(), MPI_DOUBLE, MPI_COMM_WORLD);
  h.bytes_sent += send.size() * sizeof(double);
  const std::size_t n = a.n;
  for (std::size_t k = 0; k < h.count; ++k) {
    const double* v = &recv[k * w];
    for (int pi : props) {
      Property& p = a.props[pi];
      const std::size_t s = static_cast<std::size_t>(p.stride), o = (n + k) * s;
      for (std::size_t c = 0; c < s; ++c, ++v) {
        if (p.type == PropType::F64) p.f64[o + c] = *v;
        else if (p.type == PropType::I32) p.i32[o + c] = static_cast<std::int32_t>(*v);
        else p.u32[o + c] = static_cast<std::uint32_t>(*v);
      }
    }
  }
}

// Grows every property's storage to m particles (ParticleArray::resize sets n too).
void grow_storage(ParticleArray& a, std::size_t m) {
  for (Property& p : a.props) {
    const std::size_t s = m * static_cast<std::size_t>(p.stride);
    if (p.type == PropType::F64) p.f64.resize(s);
    else if (p.type == PropType::I32) p.i32.resize(s);
    else p.u32.resize(s);
  }
}

}  // namespace

std::size_t exchange_halo(const Decomposition& dec, const Domain& d, ParticleArray& a,
                          double cutoff, Halo& h, const std::vector<int>& carried) {
  const int P = size(), me = rank();
  h.send_index.assign(P, {});
  h.send_image.assign(P, {});
  h.recv_count.assign(P, 0);
  // The images of the real particles (find_ghosts: by particle, then image).
  int pos_idx[3] = {-1, -1, -1};
  const double* pos[3] = {nullptr, nullptr, nullptr};
  for (int c = 0; c < dec.dim; ++c) {
    pos_idx[c] = a.find(kAxis[c]);
    if (pos_idx[c] >= 0) pos[c] = a.props[pos_idx[c]].f64.data();
  }
  Ghosts images;
  if (d.any()) find_ghosts(d, pos, a.n, cutoff, images, a.name);
  std::size_t g = 0;
  std::vector<int> ranks;
  if (P == 1) {  // one rank: its halo is the images of its particles, in find_ghosts order
    h.send_index[0].assign(images.source.begin(), images.source.end());
    h.send_image[0].assign(images.image.begin(), images.image.end());
  }
  for (std::size_t i = 0; i < (P == 1 ? 0 : a.n); ++i) {
    // Image 0 (the particle itself), then its ghosts.
    for (bool first = true; first || (g < images.size() && images.source[g] == i); ) {
      std::uint8_t image = 0;
      if (!first) image = images.image[g++];
      first = false;
      double p[3] = {0.0, 0.0, 0.0}, lo[3], hi[3];
      for (int c = 0; c < dec.dim; ++c)
        if (pos[c]) p[c] = transformed(d, c, true, image, pos[c][i]);
      for (int c = 0; c < 3; ++c) {
        lo[c] = c < dec.dim ? p[c] - cutoff : 0.0;
        hi[c] = c < dec.dim ? p[c] + cutoff : 0.0;
      }
      // Needed here only (one rank: its own particles are never in its halo).
      if (image == 0 && (P == 1 || inside_region(dec, lo, hi))) continue;
      ranks_near(dec, lo, hi, ranks);
      for (int r : ranks) {
        if (r == me && image == 0) continue;
        h.send_index[r].push_back(static_cast<std::uint32_t>(i));
        h.send_image[r].push_back(image);
      }
    }
  }
  std::vector<int> scount(P);
  for (int r = 0; r < P; ++r) scount[r] = static_cast<int>(h.send_index[r].size());
  MPI_Alltoall(scount.data(), 1, MPI_INT, h.recv_count.data(), 1, MPI_INT, MPI_COMM_WORLD);
  h.count = 0;
  for (int r = 0; r < P; ++r) h.count += static_cast<std::size_t>(h.recv_count[r]);
  grow_storage(a, a.n + h.count);
  send_props(d, a, h, carried);
  return h.count;
}

void refresh_halo(const Domain& d, ParticleArray& a, Halo& h, const std::vector<int>& props) {
  send_props(d, a, h, props);
}

void remove_halo(ParticleArray& a, Halo& h) {
  grow_storage(a, a.n);
  h.count = 0;
}

namespace {
std::string fmt_weight(const std::string& name, double w) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "=%.4g", w);
  return name + buf;
}
}  // namespace

void report_stats(const Decomposition& dec, const std::vector<const ParticleArray*>& arrays,
                  const std::vector<const Halo*>& halos,
                  const std::vector<const ParticleArray*>& all) {
  if (!std::getenv("SPHC_MPI_STATS")) return;
  std::size_t bytes = 0;
  std::string sizes;
  for (std::size_t k = 0; k < halos.size(); ++k) {
    bytes += halos[k]->bytes_sent;
    std::size_t last = 0;
    for (int c : halos[k]->recv_count) last += static_cast<std::size_t>(c);
    sizes += " halo_" + (k < arrays.size() ? arrays[k]->name : std::to_string(k)) + "=" +
             std::to_string(last);
  }
  std::size_t n = 0;
  for (const ParticleArray* a : arrays) {
    n += a->n;
    sizes += " n_" + a->name + "=" + std::to_string(a->n);
  }
  // Counted work (decomposition.h) of the last evaluation, per array and in all, and the
  // weights of the last cut.
  long work = 0;
  for (std::size_t k = 0; k < all.size(); ++k) {
    const long w = array_work(dec, k, all[k]->n);
    work += w;
    sizes += " work_" + all[k]->name + "=" + std::to_string(w);
    sizes += " pairs_" + all[k]->name + "=" +
             std::to_string(k < dec.pairs_now.size() ? dec.pairs_now[k] : 0);
    sizes += " candidates_" + all[k]->name + "=" +
             std::to_string(k < dec.candidates_now.size() ? dec.candidates_now[k] : 0);
  }
  sizes += " work=" + std::to_string(work);
  for (std::size_t k = 0; k < all.size() && k < dec.weights.size(); ++k)
    sizes += fmt_weight(" weight_" + all[k]->name, dec.weights[k]);
  const char* modes[] = {"measured", "estimated", "none"};
  sizes += std::string(" weights=") + modes[static_cast<int>(dec.mode)];
  if (dec.work_imbalance_count > 0) {
    char buf[160];
    std::snprintf(buf, sizeof buf, " mean_work_imbalance=%.4f imbalance_rebalances=%ld",
                  dec.work_imbalance_sum / dec.work_imbalance_count, dec.imbalance_rebalances);
    sizes += buf;
  }
  std::fprintf(stderr,
               "mpi: rank=%d ranks=%d particles=%zu evaluations=%ld rebalances=%ld migrated=%ld "
               "halo_bytes=%zu halo_bytes_per_evaluation=%.0f%s\n",
               rank(), size(), n, dec.evaluations, dec.rebalances, dec.migrated, bytes,
               dec.evaluations ? static_cast<double>(bytes) / dec.evaluations : 0.0,
               sizes.c_str());
}

double global_cutoff(const std::vector<const ParticleArray*>& arrays, double radius_scale) {
  double hmax = 0.0;
  for (const ParticleArray* a : arrays) {
    const int hi = a->find("h");
    if (hi < 0) continue;
    for (std::size_t i = 0; i < a->n; ++i) {
      const double v = a->props[hi].f64[i];
      if (std::isfinite(v) && v > hmax) hmax = v;
    }
  }
  hmax = max(hmax);
  return radius_scale * (hmax > 0 ? hmax : 1.0 / radius_scale);
}

SearchDomain halo_search_domain(const std::vector<const ParticleArray*>& arrays,
                                const std::vector<std::size_t>& halo_sizes, int dim,
                                double radius_scale) {
  const double inf = std::numeric_limits<double>::infinity();
  double lo[3] = {inf, inf, inf}, hi[3] = {-inf, -inf, -inf};
  for (std::size_t k = 0; k < arrays.size(); ++k) {
    const ParticleArray& a = *arrays[k];
    const std::size_t m = a.n + (k < halo_sizes.size() ? halo_sizes[k] : 0);
    for (int c = 0; c < dim; ++c) {
      const int p = a.find(kAxis[c]);
      if (p < 0) {
        if (m > 0) lo[c] = std::min(lo[c], 0.0), hi[c] = std::max(hi[c], 0.0);
        continue;
      }
      for (std::size_t i = 0; i < m; ++i) {
        const double v = a.props[p].f64[i];
        if (!std::isfinite(v)) continue;
        lo[c] = std::min(lo[c], v);
        hi[c] = std::max(hi[c], v);
      }
    }
  }
  const double hmax = global_cutoff(arrays, radius_scale) / radius_scale;
  return search_domain_of_box(lo, hi, hmax, dim, radius_scale);
}

}  // namespace sphc::mpi
