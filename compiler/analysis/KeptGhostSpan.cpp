// The kept lists' span on a periodic or mirror domain, with the parameter defaults. Without
// kept lists an axis needs one support (the runtime's add_ghosts); with them 1 + skin +
// kKeptWrapMargin supports, so a box between the two keeps gathering its lists at every
// evaluation instead of failing at run time (a narrow periodic channel, poiseuille with
// ny = 8). `--set` may still narrow the box at run time: then check_ghost_span stops the
// solver with a message that names --verlet-skin=off.
#include "analysis/KeptGhostSpan.h"

#include "frontend/FormatNumber.h"
#include "sema/ConstEval.h"

#include <cmath>
#include <optional>

namespace sphc {

std::string keptGhostSpanRefusal(const Plan& plan, double skin) {
  if (!plan.domain.any()) return "";
  ConstEval eval(plan);
  // The support: radius_scale x the largest initial h of the arrays (as sema/Zones.cpp).
  std::optional<double> hmax;
  for (const auto& a : plan.arrays)
    if (const PlanProperty* p = a.find("h"); p && p->init)
      if (auto h = eval(*p->init); h && std::isfinite(*h))
        hmax = hmax ? std::fmax(*hmax, *h) : *h;
  if (!hmax || !(*hmax > 0)) return "";
  const double support = plan.kernelRadiusScale * *hmax;
  const double need = (1.0 + skin + kKeptWrapMargin) * support;
  static const char* const kAxis[3] = {"x", "y", "z"};
  for (int a = 0; a < plan.dim && a < 3; ++a) {
    const PlanBoundary& lo = plan.domain.lo[a];
    const PlanBoundary& hi = plan.domain.hi[a];
    if (lo.kind == PlanBoundary::Open || hi.kind == PlanBoundary::Open) continue;
    std::optional<double> l = eval(lo.at), h = eval(hi.at);
    if (!l || !h) continue;
    if (*h - *l < need)
      return std::string("a periodic or mirror domain narrower than the kept lists' ") +
             formatNumber(1.0 + skin + kKeptWrapMargin) + " supports (" + kAxis[a] + " spans " +
             formatNumber(*h - *l) + ", the support " + formatNumber(support) +
             " with the parameter defaults)";
  }
  return "";
}

}  // namespace sphc
