// Values hoisted out of the pair loops (CPU backends, double and single precision, not --mpi).
//
// The body analysis records the subexpressions of a loop body that depend on the source
// particle alone and divide or call sqrt, pow, ... (body/SourceOnly.cpp: BodyFacts::
// sourceOnly), e.g. the momentum equation's `s_p[s_idx] / (rhoj * rhoj)`. Per pair they cost
// a division; here each is computed once per source particle and evaluation:
//
//   - after the loop body's function, one function per site, `PressureGradient_loop_hoisted0
//     (s_idx, ..., s_p, s_rho)`, returning the site's value (its locals declared first, as the
//     body declares them);
//   - in the neighbour pass, before the destination loop, an array of the source's particles
//     (a member of Scene, `hoist_eq5_0`: scratch, neither a property nor output nor in
//     restarts) filled by a loop over the source particles, ghosts included;
//   - the body reads `s_hoisted0[s_idx]` where it had the expression.
//
// Destination-only subexpressions (BodyFacts::destinationOnly, e.g. `d_p[d_idx] / (rhoi *
// rhoi)`) of properties that no neighbour pass of the phases calling the body writes
// (pairLoopWrites; until stop 37 no pair loop of the whole plan, which left out, e.g., every
// value of rho in the momentum group after a summation density) likewise: a function
// `PressureGradient_loop_dhoisted0(d_idx, d_p, d_rho)`, called in the destination loop before
// the neighbours into a local `dhoisted_eq5_0`, read by the body as `d_hoisted0`. GCC does not
// do this itself: the bodies' stores to d_ arrays may alias the d_ arrays they read.
// Expressions of scalars alone (found on both sides) go with the destination.
//
// The value is the same bit for bit: the same operations in the same order, with the same
// fused multiply-adds (codegen/FusedMultiplyAdd.h: the sites inside the expression are fused
// in it as they were in the body), and the solvers are built with -ffp-contract=off. The
// source properties it reads are not written while the pass runs (analysis/Hazards.cpp), and
// initialize, which may write them for the same array, has finished. `sphc --no-hoist` keeps
// the bodies as written. OpenCL and --mpi keep the bodies as written.
//
// Single precision (--precision=single on the CPU): the functions are the site's float text
// (singlePrecisionBody, as the body's), returning `auto`: a site's type in that text is float,
// or double where it calls a double function (KERNEL_W: `1.0f / KERNEL_W(...)` is a double),
// and the value must keep it to round as the body did. Each function is followed by its type,
// `using NAME_hoistedK_t = decltype(NAME_hoistedK(...))`, which the body's parameter, the
// scratch arrays and the locals are declared with; the functions and types come before the
// body's function. The same bits as --no-hoist, as in double.
#include "body/TextEdits.h"
#include "codegen/FusedMultiplyAdd.h"
#include "codegen/Printer.h"

#include <algorithm>
#include <map>

namespace sphc {

// text[begin, end) with the multiply-adds inside it fused (as they are in the whole body).
std::string fusedRange(const std::string& text, const BodyFacts& f, unsigned begin, unsigned end,
                       const std::string& fma) {
  std::vector<MultiplyAddSite> inside;
  for (MultiplyAddSite s : f.multiplyAdds) {
    if (s.begin < begin || s.end > end) continue;
    for (unsigned* o : {&s.begin, &s.end, &s.productBegin, &s.productEnd, &s.aBegin, &s.aEnd,
                        &s.bBegin, &s.bEnd, &s.cBegin, &s.cEnd, &s.mulOp, &s.addOp})
      *o -= begin;
    inside.push_back(s);
  }
  return fuseMultiplyAdds(text.substr(begin, end - begin), inside, fma);
}

// An expression on one line, for a comment.
std::string oneLine(const std::string& text) {
  std::string out;
  for (char c : text) {
    bool blank = c == ' ' || c == '\n' || c == '\t' || c == '\r';
    if (blank && (out.empty() || out.back() == ' ')) continue;
    out += blank ? ' ' : c;
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out.size() > 90 ? out.substr(0, 87) + "..." : out;
}

// The end of a statement after an expression: on its own line if the expression ends in a
// comment.
std::string endStatement(const std::string& expr) {
  size_t nl = expr.rfind('\n');
  return expr.find("//", nl == std::string::npos ? 0 : nl) != std::string::npos ? "\n;" : ";";
}

namespace {

bool within(unsigned b, unsigned e, unsigned begin, unsigned end) {
  return begin <= b && e <= end;
}

// The properties of one side (source: s_, destination: d_) a site reads, directly or through
// its locals (the parameters of its function, in this order).
std::set<std::string> sideReads(const BodyFacts& f, const SourceOnlySite& s, bool source) {
  std::set<std::string> props;
  for (const PropSite& p : f.sites) {
    if (p.source != source || p.write) continue;
    bool in = within(p.begin, p.end, s.begin, s.end);
    for (const auto& l : s.locals) in = in || within(p.begin, p.end, l.initBegin, l.initEnd);
    if (in) props.insert(p.prop);
  }
  return props;
}

bool overlaps(const SourceOnlySite& x, const SourceOnlySite& y) {
  return x.begin < y.end && y.begin < x.end;
}

// A destination-only site of the equation's parameters (and t, dt) alone: no property, no
// local, no d_idx (e.g. the shifting normaliser 1 / KERNEL_W(1 / hdx, 1)). Its value is the
// same for every particle of a pass: computed once per pass (passHoisted), before the
// destination loop, and the loop's local takes it.
bool particleFree(const std::string& text, const BodyFacts& f, const SourceOnlySite& s) {
  return s.locals.empty() && sideReads(f, s, false).empty() &&
         text.substr(s.begin, s.end - s.begin).find("d_idx") == std::string::npos;
}

std::string passHoisted(const std::string& eqStruct, size_t k) {
  return "pass_dhoisted_" + eqStruct + "_" + std::to_string(k);
}

}  // namespace

const std::set<std::string>& ScenePrinter::pairLoopWrites(const PlanBody& b) const {
  if (!pairLoopWrites_) {
    pairLoopWrites_ = std::make_unique<std::set<std::string>>();
    for (const PlanBody& other : plan_.bodies)
      if (other.source.kind == BodyKind::Loop || other.source.kind == BodyKind::LoopAll)
        for (const PropAccess& w : other.facts.dWrites) pairLoopWrites_->insert(w.prop);
    // Per loop body: the d_ properties the neighbour passes of the phases that call it write
    // (their loop, loop_all and initialize_pair bodies, every destination of the phase). A
    // value hoisted per destination or shared by a pair is computed within such a pass (before
    // the destination's neighbours, before the pass, or at the pair) and read at its pairs:
    // only what runs between, the pass's own bodies, can change what it read. Another phase
    // (e.g. the summation density writing rho before the momentum group reads it) runs
    // wholly before or after.
    pairLoopWritesByBody_ = std::make_unique<std::map<const PlanBody*, std::set<std::string>>>();
    walkPhases(sched_.equations, [&](const Phase& ph) {
      std::set<std::string> written;
      std::set<const PlanBody*> loops;
      for (const DestinationWork& w : ph.destinations)
        for (const NeighbourPass& pass : w.passes) {
          auto add = [&](const std::vector<const PlanEquation*>& eqs, ast::Method::Kind kind) {
            for (const PlanEquation* eq : eqs)
              for (const PropAccess& a : methodBody(*eq, kind).facts.dWrites)
                written.insert(a.prop);
          };
          add(pass.equations, ast::Method::Loop);
          add(pass.loopAll, ast::Method::LoopAll);
          add(pass.initializePair, ast::Method::InitializePair);
          for (const PlanEquation* eq : pass.equations)
            loops.insert(&methodBody(*eq, ast::Method::Loop));
        }
      for (const PlanBody* l : loops) (*pairLoopWritesByBody_)[l].insert(written.begin(), written.end());
    });
  }
  // A body in no pass (printed, never called in a pair loop): every pair loop's writes.
  auto it = pairLoopWritesByBody_->find(&b);
  return it == pairLoopWritesByBody_->end() ? *pairLoopWrites_ : it->second;
}

std::vector<SourceOnlySite> ScenePrinter::hoistedDestinationSites(const PlanBody& b,
                                                                  const Dialect& d) const {
  if (!d.hoist || b.source.kind != BodyKind::Loop || !b.facts.ok ||
      b.source.text.find("d_hoisted") != std::string::npos)  // the names would clash
    return {};
  // A property some pair loop writes (an accumulator such as au) changes during the
  // neighbour loop of its destination: not hoisted. Checked over the neighbour passes of
  // every phase that calls the body (pairLoopWrites).
  const std::set<std::string>& written = pairLoopWrites(b);
  std::vector<SourceOnlySite> kept;
  for (const SourceOnlySite& s : b.facts.destinationOnly) {
    bool ok = true;
    for (const auto& p : sideReads(b.facts, s, false)) ok = ok && !written.count(p);
    if (ok) kept.push_back(s);
  }
  return kept;
}

std::vector<SourceOnlySite> ScenePrinter::hoistedSites(const PlanBody& b, const Dialect& d) const {
  if (!d.hoist || b.source.kind != BodyKind::Loop || !b.facts.ok ||
      b.source.text.find("s_hoisted") != std::string::npos)  // the names would clash
    return {};
  // An expression of scalars alone is found on both sides: it goes with the destination
  // (a local of the destination loop rather than an array read per pair).
  const std::vector<SourceOnlySite> dest = hoistedDestinationSites(b, d);
  std::vector<SourceOnlySite> kept;
  for (const SourceOnlySite& s : b.facts.sourceOnly)
    if (std::none_of(dest.begin(), dest.end(),
                     [&](const SourceOnlySite& x) { return overlaps(s, x); }))
      kept.push_back(s);
  return kept;
}

std::string ScenePrinter::hoistedBodyText(const PlanBody& b, const Dialect& d,
                                          const std::vector<TextEdit>& extra) const {
  std::string text;
  BodyFacts facts;
  hoistedText(b, d, extra, text, facts);
  replacePairShared(b, d, text, facts);  // codegen/PairShared.cpp
  return fuseMultiplyAdds(text, facts.multiplyAdds, d.fma);
}

void ScenePrinter::hoistedText(const PlanBody& b, const Dialect& d,
                               const std::vector<TextEdit>& extra, std::string& text,
                               BodyFacts& facts) const {
  text = b.source.text;
  facts = b.facts;
  std::vector<TextEdit> edits = extra;
  auto replace = [&](const std::vector<SourceOnlySite>& sites, const std::string& name,
                     const std::string& index) {
    for (size_t k = 0; k < sites.size(); ++k) {
      const SourceOnlySite& s = sites[k];
      // The lines after it keep their numbers (#line): its line breaks follow it.
      long lines = std::count(text.begin() + s.begin, text.begin() + s.end, '\n');
      edits.push_back({s.begin, s.end,
                       name + std::to_string(k) + index +
                           std::string(static_cast<size_t>(lines), '\n')});
    }
  };
  replace(hoistedSites(b, d), "s_hoisted", "[s_idx]");
  replace(hoistedDestinationSites(b, d), "d_hoisted", "");
  if (!applyTextEdits(text, edits, facts))
    SPHC_INTERNAL("overlapping hoisted expressions in " + b.source.label);
}

void ScenePrinter::emitHoistFunctions(const PlanBody& b, const std::string& name, const Dialect& d,
                                      std::ostringstream& os) const {
  const std::string& text = b.source.text;
  // Single precision: the body's float text (as bodyText), the value's own type (above).
  const bool single = d.floatBodies;
  auto inDialect = [&](const std::string& t) { return single ? singlePrecisionBody(t) : t; };
  auto emit = [&](const std::vector<SourceOnlySite>& sites, bool source) {
    const std::string side = source ? "s" : "d";
    for (size_t k = 0; k < sites.size(); ++k) {
      const SourceOnlySite& s = sites[k];
      const std::string fn = name + "_" + (source ? "" : "d") + "hoisted" + std::to_string(k);
      std::vector<std::string> types = {"int"};  // of its parameters, for its type (single)
      os << "// " << b.source.label << ", from " << loc(b.source.start) << ": once per "
         << (source ? "source" : "destination")
         << " particle (hoisted out of the pair loop; --no-hoist: per pair)\n";
      os << "//   " << oneLine(text.substr(s.begin, s.end - s.begin)) << "\n";
      os << d.functionPrefix << (single ? "auto" : d.real) << " " << fn << "(int " << side
         << "_idx";
      auto param = [&](const std::string& type, const std::string& pname) {
        os << ", " << type << " " << pname;
        types.push_back(type);
      };
      if (s.usesT) param(d.real, "t");
      if (s.usesDt) param(d.real, "dt");
      for (const auto& sc : s.scalars) param(d.real, sc);
      for (const auto& p : sideReads(b.facts, s, source)) {
        auto shape = b.source.props.find(p);
        std::string t = shape == b.source.props.end() ? "double" : shape->second.type;
        param("const " + (t == "int" ? d.intType : t == "uint" ? d.uintType : d.real) + "*",
              side + "_" + p);
      }
      os << ") {\n";
      if (!source && s.locals.empty() && sideReads(b.facts, s, false).empty())
        os << "  (void)d_idx;  // scalars only\n";
      for (const auto& l : s.locals) {
        std::string init = inDialect(fusedRange(text, b.facts, l.initBegin, l.initEnd, d.fma));
        os << "  const " << inDialect(l.type) << " " << l.name << " = " << init
           << endStatement(init) << "\n";
      }
      std::string value = inDialect(fusedRange(text, b.facts, s.begin, s.end, d.fma));
      os << "  return " << value << endStatement(value) << "\n}\n";
      if (single) os << valueTypeAlias(fn, types);
      os << "\n";
    }
  };
  emit(hoistedSites(b, d), true);
  emit(hoistedDestinationSites(b, d), false);
}

// The arguments of a hoisted site's function after its index.
static std::string hoistArguments(const SourceOnlySite& s, const BodyFacts& f, bool source,
                                  const std::string& eqValues) {
  std::string args;
  if (s.usesT) args += ", t";
  if (s.usesDt) args += ", dt";
  for (const auto& sc : s.scalars) args += ", " + eqValues + "." + sc;
  for (const auto& p : sideReads(f, s, source)) args += (source ? ", s_" : ", d_") + p;
  return args;
}

std::string ScenePrinter::hoistedCall(const PlanEquation& eq, size_t k, bool source,
                                      const std::string& index,
                                      const std::map<std::string, std::string>& rename) const {
  const PlanBody& b = methodBody(eq, ast::Method::Loop);
  const auto sites = source ? hoistedSites(b, host_) : hoistedDestinationSites(b, host_);
  if (k >= sites.size()) return "";
  const SourceOnlySite& s = sites[k];
  if (!source && particleFree(b.source.text, b.facts, s)) return "";
  std::string args;
  if (s.usesT) args += ", t";
  if (s.usesDt) args += ", dt";
  for (const auto& sc : s.scalars) args += ", " + eqStruct(eq) + "." + sc;
  for (const auto& p : sideReads(b.facts, s, source)) {
    auto it = rename.find(p);
    if (it == rename.end()) return "";
    args += ", " + it->second;
  }
  return bodyFunctionName(eq.name, "loop") + (source ? "_hoisted" : "_dhoisted") +
         std::to_string(k) + "(" + index + args + ")";
}

ScenePrinter::SameHoisted ScenePrinter::sameDestinationHoisted(const NeighbourPass& pass) const {
  SameHoisted same;
  std::map<std::string, std::pair<std::string, std::string>> first;  // key -> (eq struct, k)
  for (const PlanEquation* e : pass.equations) {
    const PlanBody& b = methodBody(*e, ast::Method::Loop);
    const auto sites = hoistedDestinationSites(b, host_);
    for (size_t j = 0; j < sites.size(); ++j) {
      if (particleFree(b.source.text, b.facts, sites[j])) continue;
      const std::string key =
          hoistedSiteKey(b, sites[j], hoistedValueType(b, host_, false, j), false);
      if (key.empty()) continue;
      const auto found = first.emplace(key, std::make_pair(eqStruct(*e), std::to_string(j)));
      if (!found.second) same.emplace(std::make_pair(e, j), found.first->second);
    }
  }
  return same;
}

std::map<std::string, std::string> ScenePrinter::sameSourceHoisted(const NeighbourPass& pass) const {
  std::map<std::string, std::string> same;
  std::map<std::string, std::string> first;  // hoistedSiteKey -> the first pointer
  for (const PlanEquation* eq : pass.equations) {
    const PlanBody& b = methodBody(*eq, ast::Method::Loop);
    const auto sites = hoistedSites(b, host_);
    for (size_t k = 0; k < sites.size(); ++k) {
      const std::string key = hoistedSiteKey(b, sites[k], hoistedValueType(b, host_, true, k));
      if (key.empty()) continue;
      const std::string ptr = hoistArgument(eqStruct(*eq), std::to_string(k));
      const auto found = first.emplace(key, ptr);
      if (!found.second) same.emplace(ptr, found.first->second);
    }
  }
  return same;
}

std::string ScenePrinter::passDestinationHoisted(const PlanEquation& eq, size_t k) const {
  const PlanBody& b = methodBody(eq, ast::Method::Loop);
  const auto sites = hoistedDestinationSites(b, host_);
  if (k >= sites.size() || !particleFree(b.source.text, b.facts, sites[k])) return "";
  return passHoisted(eqStruct(eq), k);
}

void ScenePrinter::emitDestinationHoisted(std::ostream& os, const NeighbourPass& pass,
                                          const std::string& indent) const {
  const SameHoisted sameAs = sameDestinationHoisted(pass);
  for (const PlanEquation* eq : pass.equations) {
    const PlanBody& b = methodBody(*eq, ast::Method::Loop);
    const auto sites = hoistedDestinationSites(b, host_);
    for (size_t k = 0; k < sites.size(); ++k) {
      const std::string local = hoistDestinationArgument(eqStruct(*eq), std::to_string(k));
      const std::string type = hoistedValueType(b, host_, false, k);
      if (particleFree(b.source.text, b.facts, sites[k])) {  // emitHoistedValues computed it
        os << indent << "const " << type << " " << local << " = " << passHoisted(eqStruct(*eq), k)
           << ";  // " << eq->name << ": once per pass\n";
        continue;
      }
      // The same value as an earlier equation's of the pass (e.g. the EDAC momentum bodies'
      // m_a / rho_a): its local, the same double.
      const auto same = sameAs.find({eq, k});
      if (same != sameAs.end()) {
        os << indent << "const " << type << " " << local << " = "
           << hoistDestinationArgument(same->second.first, same->second.second) << ";  // "
           << eq->name << ": "
           << oneLine(b.source.text.substr(sites[k].begin, sites[k].end - sites[k].begin))
           << ", computed above\n";
        continue;
      }
      os << indent << "const " << type << " " << local
         << " = " << bodyFunctionName(eq->name, "loop") << "_dhoisted" << k << "(d_idx"
         << hoistArguments(sites[k], b.facts, false, eqStruct(*eq)) << ");  // " << eq->name
         << ": " << oneLine(b.source.text.substr(sites[k].begin, sites[k].end - sites[k].begin))
         << "\n";
    }
  }
}

void ScenePrinter::emitHoistedValues(std::ostream& os, const NeighbourPass& pass,
                                     const std::string& count, const std::string& pragma,
                                     const std::string& space) const {
  // The destination-only values of the parameters alone, once per pass (particleFree; read
  // by emitDestinationHoisted's locals).
  for (const PlanEquation* eq : pass.equations) {
    const PlanBody& b = methodBody(*eq, ast::Method::Loop);
    const auto sites = hoistedDestinationSites(b, host_);
    for (size_t k = 0; k < sites.size(); ++k)
      if (particleFree(b.source.text, b.facts, sites[k]))
        os << "        const " << hoistedValueType(b, host_, false, k) << " "
           << passHoisted(eqStruct(*eq), k) << " = "
           << bodyFunctionName(eq->name, "loop") << "_dhoisted" << k << "(0"
           << hoistArguments(sites[k], b.facts, false, eqStruct(*eq)) << ");  // " << eq->name
           << ": "
           << oneLine(b.source.text.substr(sites[k].begin, sites[k].end - sites[k].begin))
           << ", of the parameters only: once per pass\n";
  }
  std::vector<std::string> calls;
  // A value another equation of the pass already computes (the same function of the same
  // source properties: e.g. the shifting's two bodies' s_m[s_idx] / s_rho[s_idx]) reads that
  // equation's array: the same doubles, computed once.
  const std::map<std::string, std::string> computed = sameSourceHoisted(pass);  // pointer -> the earlier one
  bool any = false;
  for (const PlanEquation* eq : pass.equations) {
    const PlanBody& b = methodBody(*eq, ast::Method::Loop);
    const auto sites = hoistedSites(b, host_);
    for (size_t k = 0; k < sites.size(); ++k) {
      const SourceOnlySite& s = sites[k];
      if (!any)
        os << "        // Values of the loop bodies that depend on the source particle only, once "
              "per\n        // particle (codegen/Hoist.cpp; sphc --no-hoist: per pair).\n"
           << "        const int n_src = static_cast<int>(" << count << ");\n";
      any = true;
      const std::string K = std::to_string(k);
      const std::string ptr = hoistArgument(eqStruct(*eq), K);
      const std::string type = hoistedValueType(b, host_, true, k);
      const auto same = computed.find(ptr);
      if (same != computed.end()) {
        os << "        " << type << "* const " << ptr << " = " << same->second << ";  // "
           << eq->name << ": " << oneLine(b.source.text.substr(s.begin, s.end - s.begin))
           << ", computed above\n";
        continue;
      }
      const std::string member = "hoist_" + eqStruct(*eq) + "_" + K;
      // Grown, never shrunk: an equation with several sources fills its member for each in
      // turn, and a resize down then up value-initialises every double again (a memset of the
      // larger array per evaluation: the own dam break's fluid after its boundary, stop 46).
      os << "        if (" << member << ".size() < static_cast<std::size_t>(n_src)) " << member
         << ".resize(n_src);  // " << eq->name << ": "
         << oneLine(b.source.text.substr(s.begin, s.end - s.begin)) << "\n";
      os << "        " << type << "* const " << ptr << " = "
         << member << ".data();\n";
      calls.push_back(ptr + "[s_idx] = " + bodyFunctionName(eq->name, "loop") + "_hoisted" + K +
                      "(s_idx" + hoistArguments(s, b.facts, true, eqStruct(*eq)) + ");");
    }
  }
  if (calls.empty()) return;
  std::string loop = "        for (int s_idx = 0; s_idx < n_src; ++s_idx) {\n";
  for (const auto& c : calls) loop += "          " + c + "\n";
  loop += "        }\n";
  ompLoop(os, pragma, loop, space);  // kept for one region where a queue is open (OmpRegions.cpp)
}

std::string ScenePrinter::hoistedSiteKey(const PlanBody& b, const SourceOnlySite& s,
                                         const std::string& type, bool source) const {
  // The equation's scalars are its own (eqN.k): not compared, such a value is not shared.
  if (!s.scalars.empty()) return "";
  const std::string& text = b.source.text;
  // Single precision: the type is the function's decltype alias, named per equation; the same
  // float text gives the same type.
  std::string key = std::string(source ? "s|" : "d|") +
                    (host_.floatBodies ? std::string("float text") : type) + "|" +
                    (s.usesT ? "t" : "") + (s.usesDt ? "dt" : "") + "|";
  for (const auto& p : sideReads(b.facts, s, source)) key += p + ",";
  for (const auto& l : s.locals)
    key += "|" + l.type + " " + l.name + " = " +
           fusedRange(text, b.facts, l.initBegin, l.initEnd, host_.fma);
  return key + "|" + fusedRange(text, b.facts, s.begin, s.end, host_.fma);
}

std::string ScenePrinter::valueTypeAlias(const std::string& fn,
                                         const std::vector<std::string>& types) {
  std::string r = "using " + fn + "_t = decltype(" + fn + "(";
  for (size_t i = 0; i < types.size(); ++i)
    r += (i ? ", std::declval<" : "std::declval<") + types[i] + ">()";
  return r + "));  // the value's type in the float text\n";
}

std::string ScenePrinter::loopFunctionName(const PlanBody& b) const {
  // Named after the first live equation of its declaration (emitBodies), which every
  // equation of the declaration names it by.
  for (const PlanEquation& eq : plan_.equations)
    if (eq.live && plan_.equationDecls[eq.declIndex].methods.count(ast::Method::Loop) &&
        &methodBody(eq, ast::Method::Loop) == &b)
      return bodyFunctionName(eq.name, "loop");
  SPHC_INTERNAL("the loop " + b.source.label + " of no live equation");
}

std::string ScenePrinter::hoistedValueType(const PlanBody& b, const Dialect& d, bool source,
                                           size_t k) const {
  if (!d.floatBodies) return d.real;
  return loopFunctionName(b) + (source ? "_hoisted" : "_dhoisted") + std::to_string(k) + "_t";
}

void ScenePrinter::emitHoistMembers(std::ostream& os) const {
  forEachLoopBody([&](const PlanEquation& eq, const PlanBody& b) {
    const auto sites = hoistedSites(b, host_);
    for (size_t k = 0; k < sites.size(); ++k)
      os << "  std::vector<" << hoistedValueType(b, host_, true, k) << "> hoist_" << eqStruct(eq)
         << "_" << k << ";  // " << eq.name
         << ": " << oneLine(b.source.text.substr(sites[k].begin, sites[k].end - sites[k].begin))
         << " per source particle\n";
  });
}

}  // namespace sphc
