// Values a pair shares, computed once for both particles (CPU backends, double and single
// precision, not --mpi, not --simd-pairs; `sphc --pair-shared-values=off` turns it off).
//
// Where a pair loop evaluates each pair once for both particles (codegen/SymmetricPairs.cpp)
// it calls each loop body twice per pair, for (d_idx, s_idx) and mirrored for (s_idx, d_idx).
// The body analysis records the values of a body that are the same, or exactly the negation,
// in the mirrored call (body/PairShared.cpp: BodyFacts::pairShared), e.g. the continuity
// equation's VIJ . DWIJ or the viscosity's piij. Here:
//
//   - after the body's function, one function per site, NAME_loop_pairsharedK, with the
//     body's parameters but its written d_ properties, returning the site's value (its locals
//     declared first, as the body declares them; an `if` site runs the `if` on its local; a
//     site under a symmetric `if`'s condition, a division or call in `if (R2IJ > 0.0) {...}`,
//     returns 0 where the condition fails, before computing anything: the body reads the
//     value only where it holds);
//   - the body takes `double pair_sharedK` and reads it where it had the expression (an `if`
//     site: `piij = pair_sharedK;` where it had the `if`);
//   - in a pair loop that calls the body both ways, a local `pshared_eqN_K` computed once per
//     pair is passed to both calls (negated to the mirrored call for an antisymmetric value);
//     elsewhere (per-destination loops, the mirrored calls alone) each call passes
//     NAME_loop_pairsharedK(...) of its own arguments: the value the body computed before.
//
// The values are the same bit for bit: the analysis allows only exact IEEE identities (see
// body/PairShared.cpp, also for the sign of a zero), the site's function computes the
// expression with the body's own operations and fused multiply-adds (a site that would split
// a multiply-add is not used), and the properties a site reads are written by no neighbour
// pass of a phase that calls the body (pairLoopWrites).
//
// Single precision: as the hoisted values (codegen/Hoist.cpp), the functions are the float
// text, return `auto` and are followed by their type (NAME_loop_pairsharedK_t), which the
// body's parameter and the pair's local take; they come before the body's function.
#include "codegen/Printer.h"

#include "analysis/PairQuantityTable.h"
#include "body/TextEdits.h"

#include <algorithm>

namespace sphc {

namespace {

bool overlapRange(unsigned b0, unsigned e0, unsigned b1, unsigned e1) { return b0 < e1 && b1 < e0; }
bool inside(unsigned b, unsigned e, unsigned begin, unsigned end) { return begin <= b && e <= end; }

// The ranges of a site's text: its expression (an if site: its local's initial value), its
// statement, its locals' initial values.
std::vector<std::pair<unsigned, unsigned>> siteRanges(const SourceOnlySite& s) {
  std::vector<std::pair<unsigned, unsigned>> r = {{s.begin, s.end}};
  if (s.stmtBegin < s.stmtEnd) r.push_back({s.stmtBegin, s.stmtEnd});
  if (s.guardBegin < s.guardEnd) r.push_back({s.guardBegin, s.guardEnd});
  for (const auto& l : s.locals) r.push_back({l.initBegin, l.initEnd});
  return r;
}

std::string K(size_t k) { return std::to_string(k); }

// The site of `facts` (its offsets moved by the other edits of the text) with the id of
// `site`; a copy, so that no later edit of `facts` can move it under the caller.
SourceOnlySite movedSite(const BodyFacts& facts, const SourceOnlySite& site, const std::string& cut) {
  auto it = std::find_if(facts.pairShared.begin(), facts.pairShared.end(),
                         [&](const SourceOnlySite& s) { return s.id == site.id; });
  if (it == facts.pairShared.end()) SPHC_INTERNAL(cut);
  return *it;
}

}  // namespace

std::vector<SourceOnlySite> ScenePrinter::pairSharedSites(const PlanBody& b, const Dialect& d) const {
  if (!pairShared_ || !d.hoist || b.source.kind != BodyKind::Loop || !b.facts.ok ||
      b.facts.pairShared.empty() || b.source.text.find("pair_shared") != std::string::npos)
    return {};
  if (!pairSharedBodies_)
    pairSharedBodies_ = std::make_unique<std::set<const PlanBody*>>(pairSharedBodies());
  if (!pairSharedBodies_->count(&b)) return {};  // no loop calls it both ways: as before
  const std::set<std::string>& written = pairLoopWrites(b);  // by the passes of its phases
  std::vector<SourceOnlySite> kept;
  for (const SourceOnlySite& s : b.facts.pairShared) {
    bool ok = true;
    for (const PropSite& p : b.facts.sites)
      for (const auto& [rb, re] : siteRanges(s))
        if (inside(p.begin, p.end, rb, re) && written.count(p.prop)) ok = false;
    // A site must not split a multiply-add: it holds the whole sum, or lies within a factor
    // or the addend, or outside it.
    for (const MultiplyAddSite& m : b.facts.multiplyAdds)
      for (const auto& [rb, re] : siteRanges(s)) {
        if (!overlapRange(rb, re, m.begin, m.end) || inside(m.begin, m.end, rb, re)) continue;
        if (inside(rb, re, m.aBegin, m.aEnd) || inside(rb, re, m.bBegin, m.bEnd) ||
            inside(rb, re, m.cBegin, m.cEnd))
          continue;
        ok = false;
      }
    if (ok) kept.push_back(s);
  }
  return kept;
}

void ScenePrinter::replacePairShared(const PlanBody& b, const Dialect& d, std::string& text,
                                     BodyFacts& facts) const {
  const std::vector<SourceOnlySite> sites = pairSharedSites(b, d);
  if (sites.empty()) return;
  std::vector<TextEdit> edits;
  for (size_t k = 0; k < sites.size(); ++k) {
    const SourceOnlySite s =
        movedSite(facts, sites[k], "a pair-shared value cut by another edit in " + b.source.label);
    const unsigned begin = s.result.empty() ? s.begin : s.stmtBegin;
    const unsigned end = s.result.empty() ? s.end : s.stmtEnd;
    // The lines after it keep their numbers (#line): its line breaks follow it.
    const long lines = std::count(text.begin() + begin, text.begin() + end, '\n');
    const std::string name = "pair_shared" + K(k);
    edits.push_back({begin, end,
                     (s.result.empty() ? name : s.result + " = " + name + ";") +
                         std::string(static_cast<size_t>(lines), '\n')});
  }
  if (!applyTextEdits(text, edits, facts))
    SPHC_INTERNAL("overlapping pair-shared values in " + b.source.label);
}

std::vector<ScenePrinter::BodyParam> ScenePrinter::pairSharedParams(const PlanBody& b, int destArray,
                                                                    const Dialect& d) const {
  std::set<std::string> written;
  for (const PropAccess& w : b.facts.dWrites) written.insert(w.prop);
  std::vector<BodyParam> ps;
  for (const BodyParam& p : bodyParams(b, destArray, d))
    if (p.kind != BodyParam::PairShared && !(p.kind == BodyParam::DProp && written.count(p.name)))
      ps.push_back(p);
  return ps;
}

void ScenePrinter::emitPairSharedFunctions(const PlanBody& b, const std::string& name,
                                           int destArray, const Dialect& d,
                                           std::ostringstream& os) const {
  printPairShared(b, name, destArray, d, false, os);
}

void ScenePrinter::emitPairSharedSimdFunctions(const PlanBody& b, const std::string& name,
                                               int destArray, std::ostringstream& os) const {
  printPairShared(b, name, destArray, host_, true, os);
}

// The _simd form (SimdPairs.cpp): the vector pair quantities three scalars (XIJ_0), the
// destination's other properties values (dval_NAME), as the body's NAME_loop_simd takes them.
void ScenePrinter::printPairShared(const PlanBody& b, const std::string& name, int destArray,
                                   const Dialect& d, bool simd, std::ostringstream& os) const {
  const std::vector<SourceOnlySite> sites = pairSharedSites(b, d);
  if (sites.empty()) return;
  std::string text;
  BodyFacts facts;
  // the hoisted values as the body reads them
  hoistedText(b, d, simd ? simdValueEdits(b, destArray) : std::vector<TextEdit>(), text, facts);
  std::string params;
  const auto values = simd ? destinationValues(b, destArray)
                           : decltype(destinationValues(b, destArray))();
  std::vector<std::string> types;  // of the parameters (single: the value's type)
  for (const BodyParam& p : pairSharedParams(b, destArray, d)) {
    std::string decl = p.decl;
    if (simd && p.kind == BodyParam::Pair && findPairQuantity(p.name)->vector) {
      decl.clear();
      for (int c = 0; c < 3; ++c)
        decl += (c ? ", " : "") + d.real + " " + p.name + "_" + std::to_string(c);
    } else if (simd && p.kind == BodyParam::DProp && values.count(p.name)) {
      decl.clear();
      const auto& sc = values.at(p.name);
      for (int c : sc.second)
        decl += (decl.empty() ? "" : ", ") + d.real + " " + destinationValueName(p.name, sc.first, c);
    }
    params += (params.empty() ? "" : ", ") + decl;
    types.push_back(p.decl.substr(0, p.decl.rfind(' ')));
  }
  const bool single = d.floatBodies;
  auto inDialect = [&](const std::string& t) { return single ? singlePrecisionBody(t) : t; };
  for (size_t k = 0; k < sites.size(); ++k) {
    const SourceOnlySite s =
        movedSite(facts, sites[k], "a pair-shared value cut by a hoisted one in " + b.source.label);
    const std::string value = inDialect(fusedRange(text, facts, s.begin, s.end, d.fma));
    os << "// " << b.source.label << ", from " << loc(b.source.start)
       << ": a value the pair shares, " << (s.sign < 0 ? "negated" : "the same")
       << " for the mirrored pair (once per pair\n// where each pair is evaluated once; "
          "codegen/PairShared.cpp; --pair-shared-values=off: in each call)\n";
    const bool guarded = s.guardBegin < s.guardEnd;
    const std::string guard =
        guarded ? inDialect(fusedRange(text, facts, s.guardBegin, s.guardEnd, d.fma)) : "";
    if (s.result.empty())
      os << "//   " << oneLine(text.substr(s.begin, s.end - s.begin))
         << (guarded ? "   (where " + oneLine(guard) + ")" : "") << "\n";
    else
      os << "//   " << s.result << " after " << oneLine(text.substr(s.stmtBegin, s.stmtEnd - s.stmtBegin))
         << "\n";
    const std::string fn = name + "_pairshared" + K(k) + (simd ? "_simd" : "");
    os << d.functionPrefix << (single ? "auto" : d.real) << " " << fn << "(" << params << ") {\n";
    // The body reads the value only where the condition holds: tested first; in the lanes'
    // form (simd) a select after the value instead, no branch in the lanes (the value where
    // the condition fails, an infinity of a division by 0 perhaps, is dropped); in single
    // precision too, with the int 0, so that the function's `auto` is the value's own type
    // (float, or double where the value is, e.g. a kernel function's).
    const bool select = guarded && (simd || single);
    if (guarded && !select)
      os << "  if (!(" << guard << (endStatement(guard) == ";" ? "" : "\n") << ")) return "
         << inDialect("0.0") << ";\n";
    for (const auto& l : s.locals) {
      std::string init = inDialect(fusedRange(text, facts, l.initBegin, l.initEnd, d.fma));
      os << "  const " << inDialect(l.type) << " " << l.name << " = " << init
         << endStatement(init) << "\n";
    }
    if (s.result.empty() && select) {
      const auto close = [](const std::string& e) { return endStatement(e) == ";" ? "" : "\n"; };
      os << "  return (" << guard << close(guard) << ") ? (" << value << close(value) << ") : "
         << (single ? "0" : "0.0") << ";\n}\n";
    } else if (s.result.empty()) {
      os << "  return " << value << endStatement(value) << "\n}\n";
    } else {
      os << "  " << inDialect("double") << " " << s.result << " = " << value
         << endStatement(value) << "\n";
      os << "  " << inDialect(fusedRange(text, facts, s.stmtBegin, s.stmtEnd, d.fma)) << "\n";
      os << "  return " << s.result << ";\n}\n";
    }
    if (single) os << valueTypeAlias(fn, types);
    os << "\n";
  }
}

void ScenePrinter::emitPairSharedLocals(std::ostream& os, const std::string& indent, int dest,
                                        const std::vector<const PlanEquation*>& direct,
                                        const std::vector<const PlanEquation*>& mirrored,
                                        bool simd) const {
  for (const PlanEquation* eq : direct) {
    const PlanBody& b = methodBody(*eq, ast::Method::Loop);
    const std::vector<SourceOnlySite> sites = pairSharedSites(b, host_);
    for (size_t k = 0; k < sites.size(); ++k) {
      // The mirrored calls that take it: the same equation, or (the pairs of two arrays)
      // another of the same declaration where the value reads none of its parameters.
      std::vector<const PlanEquation*> users;
      for (const PlanEquation* m : mirrored)
        if (m == eq || (m->declIndex == eq->declIndex && sites[k].scalars.empty()))
          users.push_back(m);
      if (users.empty()) continue;
      const std::string local = "pshared_" + eqStruct(*eq) + "_" + K(k);
      const std::string fn =
          bodyFunctionName(eq->name, "loop") + "_pairshared" + K(k) + (simd ? "_simd" : "");
      std::string call = fn + "(";
      bool first = true;
      const auto values = simd ? destinationValues(b, dest) : decltype(destinationValues(b, dest))();
      for (const BodyParam& p : pairSharedParams(b, dest, host_)) {
        call += first ? "" : ", ";
        first = false;
        if (simd && p.kind == BodyParam::Pair && findPairQuantity(p.name)->vector) {
          call += p.name + "_0, " + p.name + "_1, " + p.name + "_2";
        } else if (simd && p.kind == BodyParam::DProp && values.count(p.name)) {
          const auto& sc = values.at(p.name);
          std::string args;
          for (int c : sc.second)
            args += (args.empty() ? "" : ", ") + destinationValueName(p.name, sc.first, c);
          call += args;
        } else {
          call += callBodyDefault(p, eqStruct(*eq), "t", ".");
        }
      }
      os << indent << "const " << pairSharedValueType(b, host_, k) << " " << local << " = "
         << call << ");  // " << eq->name
         << ": " << (sites[k].sign < 0 ? "minus this" : "the same") << " for (s_idx, d_idx)\n";
      pairSharedScope_[eqStruct(*eq) + "/" + K(k)] = {local, sites[k].sign};
      for (const PlanEquation* m : users)
        pairSharedScope_[eqStruct(*m) + "/" + K(k)] = {local, sites[k].sign};
    }
  }
}

std::string ScenePrinter::pairSharedValueType(const PlanBody& b, const Dialect& d, size_t k) const {
  if (!d.floatBodies) return d.real;
  return loopFunctionName(b) + "_pairshared" + K(k) + "_t";
}

}  // namespace sphc
