// sphc runtime: the skin of the kept neighbour lists and the cell-order re-sort chosen at run
// time (`sphc --verlet-skin=auto`; header only). See sphc/verlet.h for the lists.
//
// The skin. A set of lists costs, per evaluation, a filter pass over its kept candidates
// (~(1 + F)^dim of the neighbours) and, every N evaluations, a rebuild: a candidate scan of
// the 3^dim cells around each particle (cells (1 + F) times the support), the kept list
// copied and put in index order. The lists are rebuilt when the largest "moved" (2 d +
// radius_scale g of VerletSkin::must_rebuild) passes F radius_scale h_min, so with m the
// moved per evaluation, N = F / u, u = m / (radius_scale h_min). Per evaluation the lists cost
//   (1 + F)^dim (1 + r u / F)   (in units of one filter pass at F = 0),
// r = (rebuild cost) / (filter cost) per candidate; the pair arithmetic over the neighbours
// does not depend on F. Its minimum is the root of dim F^2 + (dim - 1) k F - k = 0, k = r u
// (optimal_skin). r is modelled from the candidates a rebuild scans per kept one (3^dim
// cells against the support's ball: 9 / pi in 2D, 27 / (4 pi / 3) in 3D) plus one for the
// copy and the order (cost_ratio). u is measured: each rebuild that the movement caused
// reports the moved and the evaluations since the last build (SkinTuner::rebuilt), smoothed
// over the rebuilds; until the first report the skin is kStart (the former fixed 0.1). The
// skin stays in [kMin, kMax]. It changes no result: the kept lists hold every pair within
// the support whatever F is, and the pair loops filter them with the support's test and sum
// in increasing index (sphc/verlet.h), so only the work changes.
//
// The re-sort. The particles are sorted in cell order (of the support's grid) for memory
// locality; a sort permutes every property and rebuilds every kept list. Instead of every
// 50th neighbour update, every SORT_CHECK_EVERY-th update looks how far the particles are
// from cell order (sort_due: the share of places where the sorted order breaks the present
// one, out_of_order) and sorts when it passes kSortDisorder. The decision is a function of
// the particles' present state and the update count, both in restart files, so a run
// continued with --restart sorts where the uninterrupted run sorts (the same bits).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "sphc/verlet.h"

namespace sphc {

// The share of the n - 1 consecutive places k of a permutation `order` (a cell order) with
// order[k] != order[k - 1] + 1: 0 when the particles are in that order already, ~2 x the
// share of particles that left their place in it.
inline double out_of_order(const std::vector<std::uint32_t>& order) {
  if (order.size() < 2) return 0.0;
  std::size_t breaks = 0;
  for (std::size_t k = 1; k < order.size(); ++k) breaks += order[k] != order[k - 1] + 1 ? 1 : 0;
  return static_cast<double>(breaks) / static_cast<double>(order.size() - 1);
}

class SkinTuner {
 public:
  static constexpr double kStart = 0.1;   // before the first measured rebuild
  static constexpr double kMin = 0.02;    // shorter lists gain little, rebuild often
  static constexpr double kMax = 0.3;     // static walls' cells are made for this skin
  static constexpr double kSortDisorder = 0.25;  // sort_due's threshold (out_of_order)

  explicit SkinTuner(int dim) : dim_(dim), skin_(kStart) {
    stats_ = std::getenv("SPHC_VERLET_STATS") != nullptr;
  }
  ~SkinTuner() {
    if (stats_)
      std::fprintf(stderr,
                   "verlet: skin %.4g (u %.3g per evaluation), %ld rebuilds (%ld measured), "
                   "%ld sort checks, %ld sorts\n",
                   skin_, u_, rebuilds_, measured_, sort_checks_, sorts_);
  }

  // The skin for the lists built from now on.
  double skin() const { return skin_; }

  // A set of lists is about to be rebuilt; `s` is its skin before mark(). A rebuild that the
  // movement caused (not the first, nor one after a count change or a sort) reports the
  // moved per evaluation since the last build.
  void rebuilt(const VerletSkin& s, double radius_scale) {
    ++rebuilds_;
    const double moved = s.last_moved();
    if (!(moved > 0.0) || s.checks() <= 0 || !(s.hmin() > 0.0) || !std::isfinite(moved)) return;
    const double u = moved / static_cast<double>(s.checks()) / (radius_scale * s.hmin());
    u_ = measured_++ == 0 ? u : 0.5 * (u_ + u);
    skin_ = std::min(kMax, std::max(kMin, optimal_skin(dim_, cost_ratio(dim_) * u_)));
  }

  // Whether particles whose cell order (of the support's grid) is `order` should be sorted.
  bool sort_due(const std::vector<std::uint32_t>& order) {
    ++sort_checks_;
    const bool due = out_of_order(order) > kSortDisorder;
    sorts_ += due ? 1 : 0;
    return due;
  }
  // A sort that is due whatever the order (the first neighbour update).
  void sorted() { ++sorts_; }

  // The F that minimises (1 + F)^dim (1 + k / F): the positive root of
  // dim F^2 + (dim - 1) k F - k = 0 (0 for k <= 0).
  static double optimal_skin(int dim, double k) {
    if (!(k > 0.0)) return 0.0;
    const double b = (dim - 1) * k;
    return (-b + std::sqrt(b * b + 4.0 * dim * k)) / (2.0 * dim);
  }
  // Rebuild / filter cost per kept candidate: the 3^dim cells' candidates per candidate of
  // the support's ball, plus one (the copy and the index order).
  static double cost_ratio(int dim) {
    const double pi = 3.14159265358979323846;
    const double ball = dim == 1 ? 2.0 : dim == 2 ? pi : 4.0 * pi / 3.0;
    return std::pow(3.0, dim) / ball + 1.0;
  }

  long rebuilds() const { return rebuilds_; }
  long sorts() const { return sorts_; }

 private:
  int dim_;
  double skin_;
  double u_ = 0.0;
  long rebuilds_ = 0, measured_ = 0, sort_checks_ = 0, sorts_ = 0;
  bool stats_ = false;
};

}  // namespace sphc
