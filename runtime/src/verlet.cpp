// sphc runtime: the kept neighbour lists' displacement checks and marks, and the order of a
// kept list (see sphc/verlet.h). In the library rather than the header: every phase of a
// solver with kept lists calls them, and a solver compiled them anew at -O3 in each cold
// build (~0.3 s of the dam break's phases unit; docs/performance-log.md, "Compile time: the
// runtime's code in its library"). The code is the header's as it was, bit for bit the same
// answers; libsphc_runtime_omp compiles the scan's OpenMP reduction as the OpenMP solvers did.
#include "sphc/verlet.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <vector>

namespace sphc {

namespace {

// A coordinate array, nullptr if the array has none (y and z below 3D may be absent).
const double* coordinate(const ParticleArray& pa, const char* axis) {
  const int k = pa.find(axis);
  return k < 0 ? nullptr : pa.f64(k);
}
const double* h_of(const ParticleArray& pa) { return pa.f64("h"); }
const float* coordinate(const FloatArray& pa, const char* axis) {
  return pa.position_of(axis[0] - 'x');
}
const float* h_of(const FloatArray& pa) { return pa.position_of(3); }
template <class Array>
std::shared_ptr<const MarkedPositions> copy_positions(const Array& pa) {
  auto s = std::make_shared<MarkedPositions>();
  s->n = pa.n;
  const char* axes[3] = {"x", "y", "z"};
  std::vector<double>* to[3] = {&s->x, &s->y, &s->z};
  for (int k = 0; k < 3; ++k) {
    const auto* c = coordinate(pa, axes[k]);
    if (c)
      to[k]->assign(c, c + pa.n);
    else
      to[k]->assign(pa.n, 0.0);
  }
  s->h.assign(h_of(pa), h_of(pa) + pa.n);
  for (double h : s->h) {
    s->hmin = h < s->hmin ? h : s->hmin;
    s->hnan = s->hnan || h != h;
  }
  return s;
}
// The largest squared displacement and growth of h of one array since mark(), and whether
// a NaN was met. OpenMP (from 16,384 particles, the runtime's threshold): a max reduction,
// whose value does not depend on the order. T: double, or float (--precision=single; each
// float read as the double it is).
// HasH false (VerletSkin::h_fixed): h unchanged since mark(), so h - saved h is +0, or NaN
// where h is NaN: growth 0 and the NaN recorded at mark(), without reading h.
template <bool HasY, bool HasZ, class T, bool HasH = true>
void moved_since_mark(const T* x, const T* y, const T* z, const T* h, const MarkedPositions& s,
                      long n, double& d2max, double& growth, bool& nan_met) {
  const double* sx = s.x.data();
  const double* sy = s.y.data();
  const double* sz = s.z.data();
  const double* sh = s.h.data();
  double d2m = 0.0, gm = 0.0;
  bool nan = false;
#pragma omp parallel for schedule(static) reduction(max : d2m, gm) reduction(| : nan) if (n > 16384)
  for (long i = 0; i < n; ++i) {
    const double dx = static_cast<double>(x[i]) - sx[i];
    double d2 = dx * dx;
    if (HasY) {
      const double dy = static_cast<double>(y[i]) - sy[i];
      d2 = dx * dx + dy * dy;
      if (HasZ) {
        const double dz = static_cast<double>(z[i]) - sz[i];
        d2 = dx * dx + dy * dy + dz * dz;
      }
    }
    d2m = d2 > d2m ? d2 : d2m;
    if (HasH) {
      const double dh = static_cast<double>(h[i]) - sh[i];
      gm = dh > gm ? dh : gm;
      nan = nan | (dh != dh);
    }
    nan = nan | (d2 != d2);
  }
  d2max = d2m;
  growth = gm;
  nan_met = HasH ? nan : nan || s.hnan;
}

// An axis missing below a present one: the 3D loop with the saved zeros read for it.
void moved_since_missing(const double* x, const double* y, const double* z,
                         const double* h, const MarkedPositions& s, long n, double& d2m,
                         double& gm, bool& nan) {
  moved_since_mark<true, true>(x ? x : s.x.data(), y ? y : s.y.data(), z ? z : s.z.data(), h,
                               s, n, d2m, gm, nan);
}
// Single precision: the same, with float zeros read for a missing axis (0 - 0 = +0).
void moved_since_missing(const float* x, const float* y, const float* z,
                         const float* h, const MarkedPositions& s, long n, double& d2m,
                         double& gm, bool& nan) {
  std::vector<float> zeros(static_cast<std::size_t>(n), 0.0f);
  moved_since_mark<true, true>(x ? x : zeros.data(), y ? y : zeros.data(),
                               z ? z : zeros.data(), h, s, n, d2m, gm, nan);
}
// The largest squared displacement and growth of h of one array since its mark.
template <class Array>
void moved_since(const Array& pa, const MarkedPositions& s, bool h_fixed, double& d2m,
                 double& gm, bool& nan) {
  const auto* x = coordinate(pa, "x");
  const auto* y = coordinate(pa, "y");
  const auto* z = coordinate(pa, "z");
  const auto* h = h_of(pa);
  const decltype(h) none = nullptr;  // a missing axis, of the array's type
  const long n = static_cast<long>(pa.n);
  // One loop per set of coordinates present (1D, 2D, 3D): no test of a missing axis per
  // particle. A missing axis was saved as zeros by mark(), so its term was +0 and d2, hence
  // the answer, is bit for bit the same without it. Any other set (an axis missing below a
  // present one) is the 3D loop with the saved zeros read for a missing axis: 0 - 0 = +0,
  // as a missing axis read as 0 gave.
  // h_fixed: h is not read (moved_since_mark<..., false>).
  using T = std::remove_cv_t<std::remove_pointer_t<decltype(h)>>;
  if (x && y && z && h_fixed)
    moved_since_mark<true, true, T, false>(x, y, z, h, s, n, d2m, gm, nan);
  else if (x && y && z)
    moved_since_mark<true, true>(x, y, z, h, s, n, d2m, gm, nan);
  else if (x && y && !z && h_fixed)
    moved_since_mark<true, false, T, false>(x, y, none, h, s, n, d2m, gm, nan);
  else if (x && y && !z)
    moved_since_mark<true, false>(x, y, none, h, s, n, d2m, gm, nan);
  else if (x && !y && !z && h_fixed)
    moved_since_mark<false, false, T, false>(x, none, none, h, s, n, d2m, gm, nan);
  else if (x && !y && !z)
    moved_since_mark<false, false>(x, none, none, h, s, n, d2m, gm, nan);
  else
    moved_since_missing(x, y, z, h, s, n, d2m, gm, nan);
}
}  // namespace

PhaseDisplacements::~PhaseDisplacements() = default;

template <class Array>
bool VerletSkin::must_rebuild_of(const std::vector<const Array*>& arrays, double radius_scale,
                                 PhaseDisplacements* phase) const {
  ++checks_;
  last_moved_ = -1.0;
  if (saved_.size() != arrays.size()) return true;
  double d2max = 0.0, growth = 0.0;
  for (std::size_t a = 0; a < arrays.size(); ++a) {
    const Array& pa = *arrays[a];
    const MarkedPositions& s = *saved_[a];
    if (pa.n != s.n) return true;
    const PhaseDisplacements::Moved* known = phase ? phase->find(&s) : nullptr;
    double d2m = 0.0, gm = 0.0;
    bool nan = false;
    if (known) {
      d2m = known->d2max;
      gm = known->growth;
      nan = known->nan;
    } else {
      moved_since(pa, s, h_fixed_, d2m, gm, nan);
      if (phase) phase->add({saved_[a], d2m, gm, nan});
    }
    if (nan) return true;  // NaN
    d2max = d2m > d2max ? d2m : d2max;
    growth = gm > growth ? gm : growth;
  }
  const double moved = 2.0 * std::sqrt(d2max) + radius_scale * growth;
  last_moved_ = moved;
  return !(moved <= skin_ * radius_scale * hmin_);
}

template <class Array>
void VerletSkin::mark_of(const std::vector<const Array*>& arrays, PhaseDisplacements* phase) {
  checks_ = 0;
  saved_.resize(arrays.size());
  hmin_ = HUGE_VAL;
  for (std::size_t a = 0; a < arrays.size(); ++a) {
    const Array& pa = *arrays[a];
    std::shared_ptr<const MarkedPositions> s = phase ? phase->marked(&pa) : nullptr;
    if (!s) {
      s = copy_positions(pa);
      if (phase) phase->add(&pa, s);
    }
    saved_[a] = s;
    hmin_ = s->hmin < hmin_ ? s->hmin : hmin_;
  }
}

bool VerletSkin::must_rebuild(const std::vector<const ParticleArray*>& arrays,
                              double radius_scale, PhaseDisplacements* phase) const {
  return must_rebuild_of(arrays, radius_scale, phase);
}

bool VerletSkin::must_rebuild(std::initializer_list<const FloatArray*> arrays,
                              double radius_scale, PhaseDisplacements* phase) const {
  return must_rebuild_of(std::vector<const FloatArray*>(arrays), radius_scale, phase);
}

void VerletSkin::mark(const std::vector<const ParticleArray*>& arrays,
                      PhaseDisplacements* phase) {
  mark_of(arrays, phase);
}

void VerletSkin::mark(std::initializer_list<const FloatArray*> arrays,
                      PhaseDisplacements* phase) {
  mark_of(std::vector<const FloatArray*>(arrays), phase);
}

void keep_in_index_order(std::vector<std::uint32_t>& kept, const std::uint32_t* cand,
                         std::size_t n) {
  kept.assign(cand, cand + n);
  // In particles sorted into the cells' order the candidates often come sorted already, and
  // otherwise as a few ascending runs (one per cell, or per row of cells). Short lists (2D,
  // ~25 candidates; 3D with few neighbours) by insertion, which costs n compares on a sorted
  // list and one move per inversion; long ones by std::sort. The indices are distinct, so both
  // give the one increasing order: the lists, and every sum over them, are the same bit for bit.
  if (n <= kInsertionSortMax) {
    std::uint32_t* a = kept.data();
    for (std::size_t i = 1; i < n; ++i) {
      const std::uint32_t v = a[i];
      std::size_t j = i;
      for (; j > 0 && a[j - 1] > v; --j) a[j] = a[j - 1];
      a[j] = v;
    }
  } else if (!std::is_sorted(kept.begin(), kept.end())) {
    std::sort(kept.begin(), kept.end());
  }
}

void find_occupied(VerletLists& lists) {
  lists.occupied.clear();
  for (long d = lists.begin; d < lists.end; ++d)
    if (!lists.lists[static_cast<std::size_t>(d)].empty())
      lists.occupied.push_back(static_cast<std::uint32_t>(d));
  lists.occupied_found = true;
}

}  // namespace sphc
