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
// velocities), and the z-components of the vectors of scalars the modules declare
// (`vector (ustar, vstar, wstar);`, sema's plan.vectorComponents); in dim 1 also the
// y-components. A property a scene asks for by name (an
// output, a limit) or gives a value (a `property` declaration with an initial value other
// than 0, a loaded file, another initial value that reads it) is kept as written; a
// declaration at 0 (`property w = 0.0;`, as PySPH ports write) is left out all the same.
//
// Strided properties get the same treatment per component: a declared `double[3]` is a
// spatial vector and a `double[9]` a 3x3 tensor stored row-major (d_L[9 d_idx + 3 i + j]),
// as the stdlib writes them. In a 1D or 2D scene such a property is stored with `dim`
// (resp. dim x dim) components per particle when every indexing of it in every body names
// its component by a literal, `d_gradc[3 * d_idx + 1]`: the left-out components read as 0
// and their writes go to the sink, the others are renumbered (`d_gradc[2 * d_idx + 1]`;
// tensor entry (i, j) at dim i + j). A property indexed otherwise (`+ k`, a loop variable)
// or output, limited, measured, loaded or copied by a zone keeps its 3D layout.
#include "analysis/Passes.h"
#include "body/TextEdits.h"

#include "llvm/ADT/StringRef.h"

#include <algorithm>
#include <functional>
#include <iterator>
#include <map>
#include <regex>

namespace sphc {

namespace {

// No initial value (0), or a literal zero (`0`, `0.0`, `-0.0`).
bool zeroValue(const ast::Expr* e) {
  if (!e) return true;
  if (e->kind == ast::Expr::Unary && e->op != "!" && e->args.size() == 1)
    return e->args[0] && zeroValue(e->args[0].get());
  return e->kind == ast::Expr::Number && e->number == 0.0;
}

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
  // The components of the scalar vectors the modules declare (`vector (ustar, vstar, wstar);`).
  for (const auto& [name, component] : plan.vectorComponents)
    if (component >= plan.dim) out.insert(name);
  // A declared one is kept when the scene gives it a value: an initial value other than a
  // literal 0, a file that loads the array, or another initial value that reads it. A PySPH
  // port's `property w = 0.0;` in a 2D scene is left out like an undeclared one.
  std::set<std::string> keep;
  for (const auto& a : plan.arrays) {
    for (const auto& p : a.outputProps) keep.insert(p);
    for (const auto& p : a.limitProps) keep.insert(p);
    if (!a.decl) continue;
    std::set<std::string> readByInit;
    std::function<void(const ast::Expr&)> names = [&](const ast::Expr& e) {
      if (e.kind == ast::Expr::Name) readByInit.insert(e.text);
      for (const auto& arg : e.args)
        if (arg) names(*arg);
    };
    for (const auto& p : a.decl->properties)
      if (p.init) names(*p.init);
    for (const auto& p : a.decl->properties)
      if (!a.decl->loads.empty() || !zeroValue(p.init.get()) || readByInit.count(p.name.name))
        keep.insert(p.name.name);
  }
  for (const auto& p : keep) out.erase(p);
  return out;
}

void erase(std::vector<PropAccess>& list, const std::string& prop) {
  list.erase(std::remove_if(list.begin(), list.end(),
                            [&](const PropAccess& a) { return a.prop == prop; }),
             list.end());
}


// The 2D (1D) layout of strided properties: for each qualifying property, its new stride.
struct StridedSite {
  int stride = 0;    // 3 or 9
  int comp = 0;      // the literal component
  char prefix = 'd';
};

// `3 * d_idx + 1`, `9 * s_idx + 4`, `3 * d_idx` -> stride, component; false otherwise.
bool literalComponent(llvm::StringRef site, StridedSite& out) {
  size_t open = site.find('[');
  if (open == llvm::StringRef::npos || !site.endswith("]")) return false;
  std::string index = site.substr(open + 1, site.size() - open - 2).str();
  static const std::regex form(R"(^\s*(3|9)\s*\*\s*([ds])_idx\s*(?:\+\s*(\d+)\s*)?$)");
  std::smatch m;
  if (!std::regex_match(index, m, form)) return false;
  out.stride = std::stoi(m[1].str());
  out.prefix = m[2].str()[0];
  out.comp = m[3].matched ? std::stoi(m[3].str()) : 0;
  return out.comp < out.stride && site.startswith(std::string(1, out.prefix) + "_");
}

// The new index of a kept component, or -1 for a left-out one.
int reducedComponent(int stride, int comp, int dim) {
  if (stride == 3) return comp < dim ? comp : -1;
  int i = comp / 3, j = comp % 3;
  return (i < dim && j < dim) ? i * dim + j : -1;
}

std::map<std::string, int> reducedStrides(const Plan& plan) {
  std::map<std::string, int> stride;  // declared strided properties (3 or 9), by name
  std::set<std::string> keep;
  for (const auto& a : plan.arrays) {
    for (const auto& p : a.props) {
      if (p.stride != 3 && p.stride != 9) continue;
      auto it = stride.find(p.name);
      if (it != stride.end() && it->second != p.stride) keep.insert(p.name);
      stride[p.name] = p.stride;
      if (a.decl && !a.decl->loads.empty()) keep.insert(p.name);
    }
    for (const auto* list : {&a.outputProps, &a.limitProps, &a.metricProps, &a.zoneProps})
      keep.insert(list->begin(), list->end());
  }
  for (const auto& b : plan.bodies) {
    for (const auto& s : b.facts.sites) {
      auto it = stride.find(s.prop);
      if (it == stride.end()) continue;
      StridedSite site;
      if (!b.facts.ok || s.end > b.source.text.size() ||
          !literalComponent(llvm::StringRef(b.source.text).slice(s.begin, s.end), site) ||
          site.stride != it->second)
        keep.insert(s.prop);
    }
    // An indexing the site list does not hold (the text would still name it): keep.
    for (const auto& [name, st] : stride) {
      size_t listed = 0;
      for (const auto& s : b.facts.sites) listed += s.prop == name;
      std::regex any("\\b[ds]_" + name + "\\s*\\[");
      auto n = std::distance(std::sregex_iterator(b.source.text.begin(), b.source.text.end(), any),
                             std::sregex_iterator());
      if (static_cast<size_t>(n) != listed) keep.insert(name);
    }
  }
  std::map<std::string, int> out;
  for (const auto& [name, st] : stride)
    if (!keep.count(name)) out[name] = st == 3 ? plan.dim : plan.dim * plan.dim;
  return out;
}

// The replacement of one strided site (reducedStrides checked it is literal).
std::string stridedReplacement(llvm::StringRef siteText, const PropSite& s, int newStride,
                               int dim) {
  StridedSite site;
  literalComponent(siteText, site);
  int c = reducedComponent(site.stride, site.comp, dim);
  if (c < 0) return s.write ? "sphc_sink" : "0.0";
  return std::string(1, site.prefix) + "_" + s.prop + "[" + std::to_string(newStride) + " * " +
         site.prefix + "_idx + " + std::to_string(c) + "]";
}

// Rewrites one body; false (unchanged) if some indexing of a left-out property was not
// found by the body analysis (the text would still name it).
bool rewrite(PlanBody& b, const std::set<std::string>& leftOut,
             const std::map<std::string, int>& reduced, int dim) {
  std::vector<TextEdit> edits;
  bool sink = false;
  for (const auto& s : b.facts.sites) {
    if (!leftOut.count(s.prop) && !reduced.count(s.prop)) continue;
    if (s.end > b.source.text.size()) return false;
    llvm::StringRef site(b.source.text.data() + s.begin, s.end - s.begin);
    if (site.contains('\n')) return false;
    std::string repl;
    if (leftOut.count(s.prop)) {
      repl = s.write ? "sphc_sink" : "0.0";
    } else {
      repl = stridedReplacement(site, s, reduced.at(s.prop), dim);
    }
    sink |= repl == "sphc_sink";
    edits.push_back({s.begin, s.end, repl});
  }
  if (edits.empty()) return true;
  // On the first line, so the #line mapping of the lines below is unchanged.
  if (sink) edits.push_back({0, 0, " double sphc_sink = 0.0; (void)sphc_sink;"});
  // The other sites and the multiply-add sites move with the text (body/TextEdits.h).
  std::string text = b.source.text;
  BodyFacts facts = b.facts;
  if (!applyTextEdits(text, edits, facts)) return false;  // overlapping: leave it
  for (const auto& p : leftOut) {
    std::regex still("\\b[ds]_" + p + "\\s*\\[");
    if (std::regex_search(text, still)) return false;
  }
  b.source.text = text;
  b.facts = facts;
  for (const auto& p : leftOut) {
    erase(b.facts.dReads, p);
    erase(b.facts.dWrites, p);
    erase(b.facts.sReads, p);
  }
  // What the rewritten sites named is gone (a 0.0, the sink) or renumbered: drop them.
  b.facts.sites.erase(std::remove_if(b.facts.sites.begin(), b.facts.sites.end(),
                                     [&](const PropSite& s) {
                                       return leftOut.count(s.prop) || reduced.count(s.prop);
                                     }),
                      b.facts.sites.end());
  for (auto& [name, shape] : b.source.props) {
    auto it = reduced.find(name);
    if (it != reduced.end()) shape.stride = it->second;
  }
  return true;
}

// Terms with a zero factor (MultiplyAddSite::zeroWhen, body/ZeroTerms.cpp): a product one
// of whose factors is a zero of the scene's dimension (XIJ[2], VIJ[2], DWIJ[2] and a
// left-out component read as 0.0 in 2D) is dropped from its multiply-add: `a * b + c`,
// `c + a * b` and `c - a * b` become `c`, `a * b - c` becomes `-(c)`, and a statement
// `x += a * b;` or `x -= a * b;` becomes `(void)0;`. GCC cannot do it itself (0.0 * x is NaN
// for an infinite x; fma(a, 0.0, c) is +0 for c = -0). The folded body differs from the
// body as written only (1) where the other factor, or a value a factor is zero through
// (x in 0.0 * x), is infinite or NaN: the written body's sum is NaN there, and (2) in the
// sign of a zero: where c (x) is -0 and the product +0 (a - c: c = +0 and the product +0),
// the written sum is +0 and the folded one -0. Anything else adds an exact zero to a value
// it leaves unchanged. Returns the number of terms dropped; the multiply-add sites inside
// the deleted text are dropped with it, those of the kept addend move (body/TextEdits.h).
int foldZeroTerms(PlanBody& b, const std::set<std::string>& zeros) {
  auto isZero = [&](const MultiplyAddSite& m) {
    for (const auto& conj : m.zeroWhen) {
      bool all = true;
      for (const auto& leaf : conj) all = all && zeros.count(leaf);
      if (all) return true;
    }
    return false;
  };
  std::vector<const MultiplyAddSite*> sites;
  for (const auto& m : b.facts.multiplyAdds)
    if (isZero(m) && ((m.form != MultiplyAddSite::AddAssign &&
                       m.form != MultiplyAddSite::SubAssign) || m.statement))
      sites.push_back(&m);
  // Outermost first: a site inside text another deletes goes with it.
  std::sort(sites.begin(), sites.end(), [](const MultiplyAddSite* x, const MultiplyAddSite* y) {
    return x->end - x->begin > y->end - y->begin;
  });
  const std::string& text = b.source.text;
  auto keepLines = [&](unsigned from, unsigned to, std::string r) {
    return r + std::string(static_cast<size_t>(std::count(text.begin() + from, text.begin() + to, '\n')), '\n');
  };
  std::vector<std::pair<unsigned, unsigned>> deleted;
  std::vector<TextEdit> edits;
  int n = 0;
  for (const MultiplyAddSite* m : sites) {
    bool inside = false;
    for (const auto& [db, de] : deleted) inside = inside || (db <= m->begin && m->end <= de);
    if (inside) continue;
    switch (m->form) {
      case MultiplyAddSite::ProductPlus:
        edits.push_back({m->begin, m->cBegin, keepLines(m->begin, m->cBegin, "")});
        deleted.push_back({m->begin, m->cBegin});
        break;
      case MultiplyAddSite::PlusProduct:
      case MultiplyAddSite::MinusProduct:
        edits.push_back({m->cEnd, m->end, keepLines(m->cEnd, m->end, "")});
        deleted.push_back({m->cEnd, m->end});
        break;
      case MultiplyAddSite::ProductMinus:
        edits.push_back({m->begin, m->cBegin, keepLines(m->begin, m->cBegin, "-(")});
        edits.push_back({m->cEnd, m->cEnd, ")"});
        deleted.push_back({m->begin, m->cBegin});
        break;
      case MultiplyAddSite::AddAssign:
      case MultiplyAddSite::SubAssign:
        edits.push_back({m->begin, m->end, keepLines(m->begin, m->end, "(void)0")});
        deleted.push_back({m->begin, m->end});
        break;
    }
    ++n;
  }
  if (edits.empty()) return 0;
  std::string out = text;
  BodyFacts facts = b.facts;
  if (!applyTextEdits(out, edits, facts)) return 0;  // (nested sites: not expected)
  b.source.text = out;
  b.facts = facts;
  return n;
}

}  // namespace

bool dropAbsentComponents(Plan& plan, DiagnosticEngine& diags, bool foldZeros) {
  if (plan.dim >= 3) return true;
  std::set<std::string> leftOut = componentsLeftOut(plan);
  plan.leftOutComponents = leftOut;
  std::map<std::string, int> reduced = reducedStrides(plan);
  std::set<std::string> dropped;
  // The zeros of the scene's dimension, as MultiplyAddSite::zeroWhen names them.
  std::set<std::string> zeros;
  for (int k = plan.dim; k < 3; ++k)
    for (const char* v : {"XIJ", "VIJ", "DWIJ"}) zeros.insert(std::string(v) + "[" + std::to_string(k) + "]");
  for (const auto& p : leftOut) zeros.insert("prop:" + p);
  std::vector<std::string> folded;
  for (auto& b : plan.bodies) {
    if (!b.facts.ok) continue;
    std::set<std::string> here;
    for (const auto& s : b.facts.sites)
      if (leftOut.count(s.prop)) here.insert(s.prop);
    bool strided = false;
    for (const auto& s : b.facts.sites) strided |= reduced.count(s.prop) > 0;
    if (rewrite(b, leftOut, reduced, plan.dim)) {
      dropped.insert(here.begin(), here.end());
      if (foldZeros) {
        int k = foldZeroTerms(b, zeros);
        if (k > 0) folded.push_back(b.source.label + " (" + std::to_string(k) + ")");
      }
    } else if (strided) {
      // Its strided properties are stored with fewer components now: the text must follow.
      diags.error(b.source.start, "internal: " + b.source.label + ": the strided properties' " +
                                      std::to_string(plan.dim) +
                                      "D layout could not be applied to it");
      return false;
    } else {
      diags.warning(b.source.start, "internal: " + b.source.label + ": the components a " +
                                        std::to_string(plan.dim) +
                                        "D scene leaves out could not be removed from it");
    }
  }
  if (!reduced.empty()) {
    for (auto& a : plan.arrays)
      for (auto& p : a.props) {
        auto it = reduced.find(p.name);
        if (it != reduced.end()) p.stride = it->second;
      }
    std::string list;
    for (const auto& [name, st] : reduced)
      list += (list.empty() ? "" : " ") + name + "[" + std::to_string(st) + "]";
    plan.notes.push_back("dim " + std::to_string(plan.dim) +
                         ": strided properties stored without their left-out components: " +
                         list);
  }
  if (!dropped.empty()) {
    std::string list;
    for (const auto& p : dropped) list += (list.empty() ? "" : " ") + p;
    plan.notes.push_back("dim " + std::to_string(plan.dim) +
                         ": components left out of every body (read as 0, never stored): " + list);
  }
  if (!folded.empty()) {
    std::string list;
    for (const auto& f : folded) list += (list.empty() ? "" : ", ") + f;
    plan.notes.push_back("dim " + std::to_string(plan.dim) +
                         ": terms with a zero factor dropped (--no-fold-zero-terms keeps them): " +
                         list);
  }
  return true;
}

}  // namespace sphc
