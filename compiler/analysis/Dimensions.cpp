// The components a scene's dimension leaves out. Bodies are written for 3D (PySPH's
// convention: `d_w[d_idx]`, `d_az[d_idx] += f * DWIJ[2]`); in a 2D scene the z-components of
// positions, velocities and their rates are identically 0 (XIJ[2], VIJ[2], DWIJ[2] are 0 and
// nothing else sets them), so a 2D solver need not store them. This pass rewrites every
// indexing of such a property in the bodies: a read becomes `0.0`, the target of a write a
// local sink that the C++ compiler discards. The property is then neither read nor written,
// so it is never allocated (x, y, u, v, ... are; z, w, az, aw, z0, w0 are not).
//
// The components: in dim < 3 z, w and their conventional derivatives (az, aw, z0, w0, what,
// awhat, wg, wf: PySPH's names of rates, saved values, transport velocities and wall
// velocities); in dim 1 also the y-components. A property a scene asks for by name (an
// output, a limit, a `property` declaration) is kept as written.
#include "analysis/Passes.h"

#include "llvm/ADT/StringRef.h"

#include <algorithm>
#include <regex>

namespace sphc {

namespace {

std::set<std::string> componentsLeftOut(const Plan& plan) {
  std::set<std::string> out;
  auto add = [&](const char* c, const char* v) {
    for (const char* base : {c, v}) {
      std::string b = base;
      for (const std::string& n : {b, "a" + b, b + "0", b + "hat", "a" + b + "hat"}) out.insert(n);
    }
    out.insert(std::string(v) + "g");
    out.insert(std::string(v) + "f");
  };
  if (plan.dim < 3) add("z", "w");
  if (plan.dim < 2) add("y", "v");
  for (const auto& a : plan.arrays) {
    for (const auto& p : a.outputProps) out.erase(p);
    for (const auto& p : a.limitProps) out.erase(p);
    if (a.decl)
      for (const auto& p : a.decl->properties) out.erase(p.name.name);
  }
  return out;
}

void erase(std::vector<PropAccess>& list, const std::string& prop) {
  list.erase(std::remove_if(list.begin(), list.end(),
                            [&](const PropAccess& a) { return a.prop == prop; }),
             list.end());
}

// Rewrites one body; false (unchanged) if some indexing of a left-out property was not
// found by the body analysis (the text would still name it).
bool rewrite(PlanBody& b, const std::set<std::string>& leftOut) {
  std::vector<PropSite> sites;
  for (const auto& s : b.facts.sites)
    if (leftOut.count(s.prop)) sites.push_back(s);
  if (sites.empty()) return true;
  std::sort(sites.begin(), sites.end(),
            [](const PropSite& x, const PropSite& y) { return x.begin > y.begin; });
  std::string text = b.source.text;
  bool sink = false;
  unsigned last = ~0u;
  for (const auto& s : sites) {
    if (s.end > last || s.end > text.size()) return false;  // overlapping: leave it
    llvm::StringRef site(text.data() + s.begin, s.end - s.begin);
    if (site.contains('\n')) return false;
    text.replace(s.begin, s.end - s.begin, s.write ? "sphc_sink" : "0.0");
    sink |= s.write;
    last = s.begin;
  }
  for (const auto& p : leftOut) {
    std::regex still("\\b[ds]_" + p + "\\s*\\[");
    if (std::regex_search(text, still)) return false;
  }
  // On the first line, so the #line mapping of the lines below is unchanged.
  if (sink) text = " double sphc_sink = 0.0; (void)sphc_sink;" + text;
  b.source.text = text;
  for (const auto& p : leftOut) {
    erase(b.facts.dReads, p);
    erase(b.facts.dWrites, p);
    erase(b.facts.sReads, p);
  }
  b.facts.sites.erase(std::remove_if(b.facts.sites.begin(), b.facts.sites.end(),
                                     [&](const PropSite& s) { return leftOut.count(s.prop); }),
                      b.facts.sites.end());
  return true;
}

}  // namespace

bool dropAbsentComponents(Plan& plan, DiagnosticEngine& diags) {
  if (plan.dim >= 3) return true;
  std::set<std::string> leftOut = componentsLeftOut(plan);
  std::set<std::string> dropped;
  for (auto& b : plan.bodies) {
    if (!b.facts.ok) continue;
    std::set<std::string> here;
    for (const auto& s : b.facts.sites)
      if (leftOut.count(s.prop)) here.insert(s.prop);
    if (rewrite(b, leftOut)) {
      dropped.insert(here.begin(), here.end());
    } else {
      diags.warning(b.source.start, "internal: " + b.source.label + ": the components a " +
                                        std::to_string(plan.dim) +
                                        "D scene leaves out could not be removed from it");
    }
  }
  if (!dropped.empty()) {
    std::string list;
    for (const auto& p : dropped) list += (list.empty() ? "" : " ") + p;
    plan.notes.push_back("dim " + std::to_string(plan.dim) +
                         ": components left out of every body (read as 0, never stored): " + list);
  }
  return true;
}

}  // namespace sphc
