// Whether the scene sees where a particle is only through differences and increments: then
// a periodic axis may wrap the particles lazily (kept neighbour lists with periodic or mirror
// sides: between permutations a particle may sit up to WRAP_MARGIN supports outside the box,
// docs/performance-log.md, "Neighbour lists with periodic and mirror sides") and no equation can
// tell, but for the rounding of the increments (x + P + d against x + d + P).
//
// A position property is x, y or z, or a property set from one of them by a copy or an
// increment (`d_x0[d_idx] = d_x[d_idx];`: the integrators' x0). Every read of a position
// property in the bodies of the live equations and the steppers must be one of
//   d_Q[d_idx] = d_P[d_idx];  d_Q[d_idx] = d_P[d_idx] + E;  d_Q[d_idx] = d_P[d_idx] - E;
// (Q a position property of P's axis, E reading no position property and holding no
// operator that binds looser than + and -), or the left side of `d_P[d_idx] += E;` or
// `-= E;`. Everything else (`double x = d_x[d_idx];`, `sin(d_x[d_idx])`, a source's s_x, a
// reduce's d_x[i], `*=`) reads the position itself. The pair quantities (XIJ, RIJ, ...) are
// differences of positions (ghosts are images) and not bodies. Outputs and metrics see the
// particles wrapped (the CPU printer's before_output); a limit on x, y or z does not.
//
// A top-level group of `equations` (not post_step) whose `condition` names only t, dt and
// params may read positions: the printer wraps every particle into the box before an
// evaluation where the condition holds (the group then reads positions in the box, as with
// a wrap at every evaluation), e.g. Taylor-Green's jitter at t = 0.
#include "analysis/PositionReads.h"

#include "codegen/CppText.h"

#include <map>
#include <regex>
#include <set>

namespace sphc {

namespace {

int axisOf(const std::string& p) {
  if (p == "x") return 0;
  if (p == "y") return 1;
  if (p == "z") return 2;
  return -1;
}

// The statement around text[at]: from after the previous ';', '{' or '}' to its ';'.
std::string statementAround(const std::string& text, size_t at) {
  size_t b = text.find_last_of(";{}", at);
  b = b == std::string::npos ? 0 : b + 1;
  size_t e = text.find(';', at);
  e = e == std::string::npos ? text.size() : e;
  return text.substr(b, e - b);
}

struct Body {
  const PlanBody* body;
  const PlanEquation* equation;  // null: a stepper's
};

}  // namespace

PositionReads positionReads(const Plan& plan) {
  PositionReads r;
  std::vector<Body> bodies;
  for (const PlanEquation& eq : plan.equations) {
    if (!eq.live) continue;
    for (const auto& [kind, idx] : plan.equationDecls[eq.declIndex].methods)
      bodies.push_back({&plan.bodies[idx], &eq});
  }
  for (const PlanStepper& st : plan.steppers)
    for (const auto& [name, idx] : st.methods) bodies.push_back({&plan.bodies[idx], nullptr});

  static const std::regex copyOrShift(
      R"(^\s*d_(\w+)\s*\[\s*d_idx\s*\]\s*=\s*d_(\w+)\s*\[\s*d_idx\s*\]\s*(([-+])([^?:<>=!&|,]*))?$)");
  // The position properties and their axis: x, y, z, then what is copied or shifted from them.
  std::map<std::string, int> axis = {{"x", 0}, {"y", 1}, {"z", 2}};
  for (bool grown = true; grown;) {
    grown = false;
    for (const Body& b : bodies)
      for (const PropSite& s : b.body->facts.sites) {
        if (s.source || s.write || !axis.count(s.prop)) continue;
        std::smatch m;
        const std::string st = statementAround(b.body->source.text, s.begin);
        if (std::regex_match(st, m, copyOrShift) && m[2] == s.prop && !axis.count(m[1]))
          grown |= axis.emplace(m[1], axis.at(s.prop)).second;
      }
  }
  // Every site of a position property.
  auto absolute = [&](const Body& b, const PropSite& s) -> bool {
    const std::string& text = b.body->source.text;
    const std::string st = statementAround(text, s.begin);
    if (s.source) return true;
    if (s.write) {  // `=`, `+=` or `-=` (what the right side reads is checked at its sites)
      size_t op = text.find_first_not_of(" \t\n", s.end);
      if (op == std::string::npos) return true;
      if (text.compare(op, 2, "+=") == 0 || text.compare(op, 2, "-=") == 0) return false;
      return !(text[op] == '=' && (op + 1 >= text.size() || text[op + 1] != '='));
    }
    // A read: the left side of `+=` / `-=` is a write site (the same text); this is the
    // right side of a copy or shift into a position property of the same axis, alone.
    std::smatch m;
    if (!std::regex_match(st, m, copyOrShift) || m[2] != s.prop || !axis.count(m[1]) ||
        axis.at(m[1]) != axis.at(s.prop))
      return true;
    // The right side's d_P is this site, and E reads no position property.
    const std::string tail = m[5].matched ? m[5].str() : std::string();
    for (const auto& [p, a] : axis)
      if (identifierOccurrences(tail, "d_" + p) || identifierOccurrences(tail, "s_" + p))
        return true;
    return false;
  };
  std::set<const PlanEquation*> readers;
  for (const Body& b : bodies)
    for (const PropSite& s : b.body->facts.sites)
      if (axis.count(s.prop) && absolute(b, s)) {
        const std::string what = (s.source ? "s_" : "d_") + s.prop;
        if (!b.equation) {
          r.refusal = b.body->source.label + " reads " + what + " (not as a copy or increment)";
          return r;
        }
        if (readers.insert(b.equation).second && r.reader.empty())
          r.reader = b.body->source.label + " reads " + what;
      }
  for (const PlanLimit& l : plan.limits)
    if (axis.count(l.quantity)) {
      r.refusal = "a limit on " + l.quantity;
      return r;
    }
  // The output and the metrics see x, y and z wrapped (before_output), not their copies.
  for (const auto& [p, a] : axis) {
    if (axisOf(p) >= 0) continue;
    for (const PlanArray& arr : plan.arrays) {
      const PlanProperty* q = arr.find(p);
      if (q && q->output) {
        r.refusal = "the output holds " + p + ", a copy of a position";
        return r;
      }
    }
    for (const PlanMetric& m : plan.metrics)
      for (const std::string& read : m.reads)
        if (read == p) {
          r.refusal = "a metric reads " + p + ", a copy of a position";
          return r;
        }
  }
  if (readers.empty()) return r;
  // The readers: each in a top-level group of `equations` with a condition of t, dt, params.
  std::set<const PlanEquation*> covered;
  for (const auto& g : plan.root.subgroups) {
    if (g->postStep || !g->condition || !g->subgroups.empty()) continue;
    bool simple = true;
    exprCpp(*g->condition, [&](const std::string& n) {
      if (n.find('.') != std::string::npos) simple = false;  // an array constant
      return n;
    });
    if (!simple) continue;
    bool reads = false;
    for (int e : g->equations) reads |= readers.count(&plan.equations[e]) > 0;
    if (!reads) continue;
    for (int e : g->equations) covered.insert(&plan.equations[e]);
    r.wrapBefore.push_back(g.get());
  }
  for (const PlanEquation* eq : readers)
    if (!covered.count(eq)) {
      r.refusal = r.reader + " (not as a copy or increment; not in a top-level group with a "
                  "condition of t, dt and params)";
      r.wrapBefore.clear();
      return r;
    }
  return r;
}

}  // namespace sphc
