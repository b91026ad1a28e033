// The destination's sums in locals across its neighbours (CPU backends, double and single
// precision, not --mpi; sphc --no-register-sums: in memory at every pair). The locals have
// the arrays' type (float in single precision: the sums accumulate in float, as in memory).
//
// A loop body accumulates into its destination's arrays: `d_au[d_idx] += ...`,
// `d_binv[4 * d_idx + 1] = fma(..., d_binv[4 * d_idx + 1])`. Printed as written, every pair
// loads and stores each sum: the C++ compiler cannot keep them in registers across the
// neighbours, as the stores through d_ pointers may alias what the next pair reads (and in a
// pass of each pair once, SymmetricPairs.cpp, the mirrored calls do write the same arrays at
// s_idx). Here, for a pair loop that allows it, each component k of an accumulated property
// is a local of the destination loop, `acc_NAME` (stride 1) or `acck_NAME` (`acc0_binv`):
// loaded before the neighbours, stored after them. The bodies' calls for d_idx take a second
// printing of the body, NAME_loop_sums, whose sites `d_NAME[S * d_idx + k]` are those locals,
// passed by reference (once inlined, their addresses are not taken: GCC keeps them in
// registers; local arrays passed by pointer stayed on the stack). The mirrored calls
// (destination s_idx) write memory as before.
//
// Why it is the same bit for bit: the same operations in the same order, on the same values.
// During the neighbour loop of d_idx no other code reads or writes d_NAME[S * d_idx + k]:
//   - the bodies index the property only as `S * d_idx + k` (a literal component k < S, one
//     stride S per property), and only bodies that write it touch it (no plain reader of a
//     sum another body accumulates), and name it nowhere else (no bare `d_NAME`);
//   - the mirrored calls of a pass of each pair once write at s_idx != d_idx (the self pair
//     has no mirrored call), which is another particle's slot as k < S;
//   - no body reads it as a source property of the same array (s_NAME: at the self pair
//     s_idx == d_idx, or from a mirrored call, it would see the sum before this loop), nor do
//     the pair quantities (the destination's are loaded before the loop in either form);
//   - no loop_all runs in the pass (it would read the sums between the loads and the loop).
// Where a loop is refused, a comment in the generated code says why.
#include "analysis/PairQuantityTable.h"
#include "codegen/CppText.h"
#include "codegen/Printer.h"

#include <regex>

namespace sphc {

namespace {

// `d_idx`, `S * d_idx`, `S * d_idx + k` -> stride S (1 for d_idx), component k < S; false
// otherwise. `source`: the same with s_idx.
bool destinationComponent(const std::string& index, int& stride, int& comp, bool source = false) {
  static const std::regex form(R"(^\s*(?:(\d+)\s*\*\s*)?d_idx\s*(?:\+\s*(\d+)\s*)?$)");
  static const std::regex sform(R"(^\s*(?:(\d+)\s*\*\s*)?s_idx\s*(?:\+\s*(\d+)\s*)?$)");
  std::smatch m;
  if (!std::regex_match(index, m, source ? sform : form)) return false;
  stride = m[1].matched ? std::stoi(m[1].str()) : 1;
  comp = m[2].matched ? std::stoi(m[2].str()) : 0;
  return stride >= 1 && stride <= 64 && comp < stride;
}

// Where the text indexes d_NAME: [begin, end) of `d_NAME[index]`, the stride and component.
// The text itself is scanned, not the body analysis' sites: the 2D layout of strided
// properties (analysis/Dimensions.cpp) rewrites their sites and drops them from the list.
struct DestinationSite {
  unsigned begin = 0, end = 0;
  int stride = 0, comp = 0;
};
// The d_ properties body b writes, constants of array a (if any) left out.
std::set<std::string> written(const PlanBody& b, const PlanArray* a = nullptr) {
  std::set<std::string> w;
  for (const PropAccess& x : b.facts.dWrites)
    if (!a || std::find(a->constants.begin(), a->constants.end(), x.prop) == a->constants.end())
      w.insert(x.prop);
  return w;
}

// Every indexing of d_NAME in text, or false if one is not `d_NAME[S * d_idx + k]` or the
// name occurs otherwise (a bare pointer).
bool destinationSites(const std::string& text, const std::string& prop,
                      std::vector<DestinationSite>& out, bool source = false) {
  const std::string name = (source ? "s_" : "d_") + prop;
  out.clear();
  for (size_t at = text.find(name); at != std::string::npos; at = text.find(name, at + 1)) {
    if ((at > 0 && isIdentifierChar(text[at - 1])) ||
        (at + name.size() < text.size() && isIdentifierChar(text[at + name.size()])))
      continue;
    size_t open = at + name.size();
    while (open < text.size() && (text[open] == ' ' || text[open] == '\t')) ++open;
    if (open >= text.size() || text[open] != '[') return false;
    size_t close = text.find_first_of("[]", open + 1);
    if (close == std::string::npos || text[close] != ']') return false;
    DestinationSite site;
    if (!destinationComponent(text.substr(open + 1, close - open - 1), site.stride, site.comp,
                              source))
      return false;
    site.begin = static_cast<unsigned>(at);
    site.end = static_cast<unsigned>(close + 1);
    out.push_back(site);
  }
  return true;
}

// The local of component k of a sum of stride S: acc_NAME (S = 1), accK_NAME.
std::string localName(const std::string& prop, int stride, int comp) {
  return stride == 1 ? "acc_" + prop : "acc" + std::to_string(comp) + "_" + prop;
}

// The components of d_NAME a body's text updates (its stride: 1 where it indexes none).
std::set<int> bodyComponents(const std::string& text, const std::string& prop, int& stride) {
  std::vector<DestinationSite> sites;
  std::set<int> comps;
  stride = 1;
  if (!destinationSites(text, prop, sites)) return comps;
  for (const DestinationSite& s : sites) {
    comps.insert(s.comp);
    stride = s.stride;
  }
  return comps;
}

std::string indexText(int stride, int comp) {
  return stride == 1 ? std::string("d_idx")
                     : std::to_string(stride) + " * d_idx + " + std::to_string(comp);
}

}  // namespace

std::string ScenePrinter::sumsLocalName(const std::string& prop, int stride, int comp) {
  return localName(prop, stride, comp);
}

std::string ScenePrinter::sumsIndexText(int stride, int comp, const std::string& idx) {
  return stride == 1 ? idx : std::to_string(stride) + " * " + idx + " + " + std::to_string(comp);
}

RegisterSums ScenePrinter::registerSums(const DestinationWork& w,
                                                      const NeighbourPass& pass,
                                                      const NeighbourPass* mirrored) const {
  RegisterSums rs;
  if (!registerSums_ || pass.equations.empty()) return rs;
  const PlanArray& A = arr(w.array);
  // The accumulated properties: every d_ property a loop body of the pass writes.
  std::set<std::string> sums;
  for (const PlanEquation* eq : pass.equations)
    for (const std::string& p : written(methodBody(*eq, ast::Method::Loop), &A)) sums.insert(p);
  if (sums.empty()) return rs;
  auto refuse = [&](const std::string& why) {
    rs.props.clear();
    rs.refusal = why;
    return rs;
  };
  if (!pass.loopAll.empty()) return refuse(pass.loopAll[0]->name + " has a loop_all");
  for (const std::string& p : sums) {
    if (pass.shared.count(p) || (mirrored && mirrored->shared.count(p)))
      return refuse("the pair quantities read " + p);
    if (propType(w.array, p, host_) != host_.real) return refuse(p + " is not floating");
  }
  for (const PlanEquation* eq : pass.equations) {
    const PlanBody& b = methodBody(*eq, ast::Method::Loop);
    if (!b.facts.ok || b.source.kind != BodyKind::Loop) return refuse(eq->name + " is no plain loop");
    const std::set<std::string> own = written(b, &A);
    for (const std::string& p : sums) {
      if (pass.source == w.array && identifierOccurrences(b.source.text, "s_" + p))
        return refuse(eq->name + " reads s_" + p + ", a sum of the pass");
      if (!own.count(p)) {
        if (identifierOccurrences(b.source.text, "d_" + p))
          return refuse(eq->name + " reads d_" + p + ", which another body accumulates");
        continue;
      }
      std::vector<DestinationSite> sites;
      if (!destinationSites(b.source.text, p, sites))
        return refuse(eq->name + " indexes d_" + p + " otherwise than by d_idx and a literal "
                      "component");
      auto& entry = rs.props[p];
      for (const DestinationSite& site : sites) {
        if (entry.first != 0 && entry.first != site.stride)
          return refuse("d_" + p + " is indexed with two strides");
        entry.first = site.stride;
        entry.second.insert(site.comp);
      }
      if (entry.second.empty()) return refuse(eq->name + " writes d_" + p + " nowhere found");
      // The array's layout: then the mirrored calls' d_NAME[S * s_idx + k'] (s_idx != d_idx,
      // k' < S) never touch the destination's slots.
      const PlanProperty* pp = A.find(p);
      if (!pp || pp->stride != entry.first)
        return refuse(eq->name + " indexes d_" + p + " with a stride other than its own");
    }
  }
  // The locals' names are free in the bodies.
  for (const PlanEquation* eq : pass.equations)
    for (const auto& [p, sc] : rs.props)
      for (int k : sc.second)
        if (identifierOccurrences(methodBody(*eq, ast::Method::Loop).source.text, localName(p, sc.first, k)))
          return refuse(eq->name + " names " + localName(p, sc.first, k));
  if (mirrored)
    for (const PlanEquation* eq : mirrored->equations)
      for (const std::string& p : sums)
        if (identifierOccurrences(methodBody(*eq, ast::Method::Loop).source.text, "s_" + p))
          return refuse(eq->name + " (the mirrored calls) reads s_" + p + ", a sum of the pass");
  return rs;
}

void ScenePrinter::emitSumsLoad(std::ostream& os, const std::string& indent,
                                const RegisterSums& rs) const {
  if (!rs.active()) {
    if (!rs.refusal.empty())
      os << indent << "// The destination's sums stay in memory (codegen/RegisterSums.cpp): "
         << rs.refusal << ".\n";
    return;
  }
  std::string names;
  for (const auto& [p, sc] : rs.props) names += (names.empty() ? "" : ", ") + p;
  os << indent << "// The destination's sums in locals across its neighbours (codegen/RegisterSums.cpp;\n"
     << indent << "// sphc --no-register-sums: in memory at every pair): " << names << ".\n";
  for (const auto& [p, sc] : rs.props)
    for (int k : sc.second)
      os << indent << host_.real << " " << localName(p, sc.first, k) << " = d_" << p << "["
         << indexText(sc.first, k) << "];\n";
}

void ScenePrinter::emitSumsStore(std::ostream& os, const std::string& indent,
                                 const RegisterSums& rs) const {
  for (const auto& [p, sc] : rs.props)
    for (int k : sc.second)
      os << indent << "d_" << p << "[" << indexText(sc.first, k) << "] = "
         << localName(p, sc.first, k) << ";\n";
}

// The sites of d_NAME outside the hoisted expressions (which the body's text loses).
static bool valueSites(const std::string& text, const std::string& prop,
                       const std::vector<SourceOnlySite>& hoisted,
                       std::vector<DestinationSite>& sites, bool source = false) {
  if (!destinationSites(text, prop, sites, source)) return false;
  sites.erase(std::remove_if(sites.begin(), sites.end(),
                             [&](const DestinationSite& s) {
                               for (const SourceOnlySite& h : hoisted)
                                 if (s.begin >= h.begin && s.end <= h.end) return true;
                               return false;
                             }),
              sites.end());
  return true;
}

// Property p of a body's text as a value (destinationValues, sourceValues): its stride and
// components, where every site outside the hoisted expressions is `X_p[S * X_idx + k]` of
// one stride and the values' names (`name`) are free.
static void addValue(const std::string& text, const std::string& p,
                     const std::vector<SourceOnlySite>& hoisted, bool source,
                     std::string (*name)(const std::string&, int, int),
                     std::map<std::string, std::pair<int, std::set<int>>>& values) {
  std::vector<DestinationSite> sites;
  if (!valueSites(text, p, hoisted, sites, source) || sites.empty()) return;
  auto& entry = values[p];
  for (const DestinationSite& site : sites) {
    if (entry.first != 0 && entry.first != site.stride) {
      values.erase(p);
      return;
    }
    entry.first = site.stride;
    entry.second.insert(site.comp);
  }
  for (int k : entry.second)
    if (identifierOccurrences(text, name(p, entry.first, k))) {
      values.erase(p);
      return;
    }
}

std::vector<SourceOnlySite> ScenePrinter::allHoistedSites(const PlanBody& b) const {
  std::vector<SourceOnlySite> hoisted = hoistedSites(b, host_);
  for (const SourceOnlySite& h : hoistedDestinationSites(b, host_)) hoisted.push_back(h);
  return hoisted;
}

std::map<std::string, std::pair<int, std::set<int>>> ScenePrinter::destinationValues(
    const PlanBody& b, int d) const {
  std::map<std::string, std::pair<int, std::set<int>>> values;
  const std::set<std::string> own = written(b);
  const std::vector<SourceOnlySite> hoisted = allHoistedSites(b);
  for (const PropAccess& r : b.facts.dReads) {
    const std::string& p = r.prop;
    if (own.count(p) || values.count(p) || !arr(d).find(p) || propType(d, p, host_) != host_.real)
      continue;
    addValue(b.source.text, p, hoisted, false, &ScenePrinter::destinationValueName, values);
  }
  return values;
}

std::map<std::string, std::pair<int, std::set<int>>> ScenePrinter::sourceValues(
    const PlanBody& b) const {
  std::map<std::string, std::pair<int, std::set<int>>> values;
  const std::vector<SourceOnlySite> hoisted = allHoistedSites(b);
  for (const PropAccess& r : b.facts.sReads) {
    const std::string& p = r.prop;
    if (values.count(p)) continue;
    addValue(b.source.text, p, hoisted, true, &ScenePrinter::sourceValueName, values);
  }
  return values;
}

std::string ScenePrinter::sourceValueName(const std::string& prop, int stride, int comp) {
  return stride == 1 ? "sval_" + prop : "sval" + std::to_string(comp) + "_" + prop;
}

std::string ScenePrinter::destinationValueName(const std::string& prop, int stride, int comp) {
  return stride == 1 ? "dval_" + prop : "dval" + std::to_string(comp) + "_" + prop;
}

std::string ScenePrinter::destinationValueLoad(const std::string& prop, int stride, int comp) const {
  return "const " + host_.real + " " + destinationValueName(prop, stride, comp) + " = d_" + prop +
         "[" + indexText(stride, comp) + "];";
}

std::string ScenePrinter::pairCall(const PlanEquation& eq, int d, const RegisterSums& rs,
                                   bool scalarPairs, const std::string& sumsPrefix,
                                   const std::function<std::string(const BodyParam&)>& first) const {
  const PlanBody& b = methodBody(eq, ast::Method::Loop);
  const std::set<std::string> own = written(b, &arr(d));
  bool any = false;
  for (const std::string& p : own) any = any || rs.props.count(p);
  if (!any && !scalarPairs) return equationCall(eq, ast::Method::Loop, d);
  const auto values = scalarPairs ? destinationValues(b, d) : decltype(destinationValues(b, d))();
  auto argument = [&](const BodyParam& p) -> std::string {
    if (first) {
      const std::string a = first(p);
      if (!a.empty()) return a;
    }
    if (scalarPairs && host_.floatBodies && !floatScalarName(eqStruct(eq), p).empty())
      return floatScalarName(eqStruct(eq), p);
    if (scalarPairs && p.kind == BodyParam::Pair && findPairQuantity(p.name)->vector)
      return p.name + "_0, " + p.name + "_1, " + p.name + "_2";
    if (p.kind == BodyParam::DProp && values.count(p.name)) {
      std::string args;
      const auto& sc = values.at(p.name);
      for (int k : sc.second)
        args += (args.empty() ? "" : ", ") + destinationValueName(p.name, sc.first, k);
      return args;
    }
    if (p.kind != BodyParam::DProp || !own.count(p.name)) return "";
    int stride = 1;
    std::string args;
    for (int k : bodyComponents(b.source.text, p.name, stride))
      args += (args.empty() ? "" : ", ") + sumsPrefix + localName(p.name, stride, k);
    return args;
  };
  return callBody(bodyFunctionName(eq.name, "loop") + (scalarPairs ? "_simd" : "_sums"), b, d,
                  eqStruct(eq), "t", ".", argument) +
         ";  // " + eq.name + ", from " + loc(eq.loc) + "\n";
}

void ScenePrinter::emitSumsFunction(const PlanEquation& eq, std::ostringstream& os) {
  if (!registerSums_) return;
  if (!sumsDecls_) {  // the declarations whose loop some pass calls on the locals
    sumsDecls_ = std::make_unique<std::set<int>>();
    walkPasses(sched_.equations, [&](const Phase&, const DestinationWork& w,
                                     const NeighbourPass& pass) {
      const RegisterSums rs = registerSums(w, pass);
      for (const PlanEquation* e : pass.equations) {
        bool any = false;
        for (const PropAccess& a : methodBody(*e, ast::Method::Loop).facts.dWrites)
          any = any || rs.props.count(a.prop);
        if (any) sumsDecls_->insert(e->declIndex);
      }
    });
  }
  if (!sumsDecls_->count(eq.declIndex)) return;
  printSumsFunction(eq, false, os);
}

std::vector<TextEdit> ScenePrinter::simdValueEdits(const PlanBody& b, int d) const {
  std::vector<TextEdit> edits;
  std::string why;
  if (!scalarPairEdits(b.source.text, edits, why)) return {};
  const std::vector<SourceOnlySite> hoisted = allHoistedSites(b);
  for (const auto& [p, sc] : destinationValues(b, d)) {
    std::vector<DestinationSite> sites;
    valueSites(b.source.text, p, hoisted, sites);
    for (const DestinationSite& site : sites)
      edits.push_back({site.begin, site.end, destinationValueName(p, site.stride, site.comp)});
  }
  return edits;
}

void ScenePrinter::printSumsFunction(const PlanEquation& eq, bool scalarPairs,
                                     std::ostringstream& os, bool mirror, bool rare) const {
  const PlanBody& b = methodBody(eq, ast::Method::Loop);
  const std::set<std::string> own = written(b, &arr(eq.dest));
  std::vector<TextEdit> edits;
  for (const std::string& p : own) {
    std::vector<DestinationSite> sites;
    if (!destinationSites(b.source.text, p, sites)) return;  // refused (registerSums)
    for (const DestinationSite& site : sites)
      edits.push_back({site.begin, site.end, localName(p, site.stride, site.comp)});
  }
  std::string why;
  if (scalarPairs && !scalarPairEdits(b.source.text, edits, why)) return;  // refused
  // The destination's other properties as values loaded before the SIMD loop (a load at
  // d_idx under an `if` GCC does not vectorise).
  const auto values = scalarPairs ? destinationValues(b, eq.dest)
                                  : decltype(destinationValues(b, eq.dest))();
  const std::vector<SourceOnlySite> hoisted =
      values.empty() ? std::vector<SourceOnlySite>() : allHoistedSites(b);
  for (const auto& [p, sc] : values) {
    std::vector<DestinationSite> sites;
    valueSites(b.source.text, p, hoisted, sites);
    for (const DestinationSite& site : sites)
      edits.push_back({site.begin, site.end, destinationValueName(p, site.stride, site.comp)});
  }
  // The mirrored calls' form (SimdPairs.cpp, each pair once in lanes): the source's
  // properties as values too (the source of those calls is the lanes' common d_idx: a load
  // under an `if` GCC does not vectorise either).
  const auto svalues = mirror ? sourceValues(b) : decltype(sourceValues(b))();
  for (const auto& [p, sc] : svalues) {
    std::vector<DestinationSite> sites;
    valueSites(b.source.text, p, allHoistedSites(b), sites, /*source=*/true);
    for (const DestinationSite& site : sites)
      edits.push_back({site.begin, site.end, sourceValueName(p, site.stride, site.comp)});
  }
  if (rare)  // the tiles' rare form: each scalar math call a mark of the lane (stop 40)
    for (const auto& [begin, end] : scalarMathCallSites(b.source.text)) {
      size_t open = end;  // the call's '(' too: the mark is its first argument
      while (open < b.source.text.size() && b.source.text[open] != '(') ++open;
      edits.push_back({begin, static_cast<unsigned>(open + 1), "sphc_rare_call(sphc_rare, "});
    }
  const std::string name = bodyFunctionName(eq.name, "loop") +
                           (mirror ? "_simd_mirror" : scalarPairs ? "_simd" : "_sums") +
                           (rare ? "_rare" : "");
  os << "// " << b.source.label << ", from " << loc(b.source.start)
     << ": the destination's sums in locals (acc_NAME, accK_NAME: component K;\n"
     << (scalarPairs ? "// the pair quantities' components scalars, XIJ_0 for XIJ[0]: the SIMD "
                       "pair loops,\n// codegen/SimdPairs.cpp)\n"
                     : "// codegen/RegisterSums.cpp)\n")
     << (mirror ? "// For the mirrored calls of each pair once in SIMD lanes: the source's "
                  "properties as values\n// (sval_NAME, particle d_idx's).\n"
                : "")
     << (rare ? "// The tiles' rare form (codegen/ClusterPairs.cpp): a scalar math call marks "
                "the lane (sphc_rare),\n// whose pair the tiles redo with the form without "
                "_rare.\n"
              : "");
  if (host_.lineDirectives) emitLineDirective(os, b.source.start);
  os << host_.functionPrefix << "void " << name << "(";
  bool first = true;
  for (const BodyParam& p : bodyParams(b, eq.dest, host_)) {
    if (scalarPairs && p.kind == BodyParam::Pair && findPairQuantity(p.name)->vector) {
      for (int k = 0; k < 3; ++k)
        os << (first && k == 0 ? "" : ", ") << host_.real << " " << p.name << "_" << k;
      first = false;
      continue;
    }
    if (p.kind == BodyParam::DProp && values.count(p.name)) {
      const auto& sc = values.at(p.name);
      for (int k : sc.second) {
        os << (first ? "" : ", ") << host_.real << " " << destinationValueName(p.name, sc.first, k);
        first = false;
      }
      continue;
    }
    if (p.kind == BodyParam::SProp && svalues.count(p.name)) {
      const auto& sc = svalues.at(p.name);
      for (int k : sc.second) {
        os << (first ? "" : ", ") << host_.real << " " << sourceValueName(p.name, sc.first, k);
        first = false;
      }
      continue;
    }
    if (p.kind == BodyParam::DProp && own.count(p.name)) {
      int stride = 1;
      for (int k : bodyComponents(b.source.text, p.name, stride)) {
        os << (first ? "" : ", ") << host_.real << "& " << localName(p.name, stride, k);
        first = false;
      }
      continue;
    }
    os << (first ? "" : ", ") << p.decl;
    first = false;
  }
  if (rare) os << (first ? "" : ", ") << "double& sphc_rare";
  os << ") {";
  std::string text = hoistedBodyText(b, host_, edits);
  if (host_.floatBodies) text = singlePrecisionBody(text);  // as bodyText: float, 0.5f
  os << text;
  if (text.empty() || text.back() != '\n') os << "\n";
  os << "}\n";
  if (host_.lineDirectives) resetLineDirective(os, host_);
  os << "\n";
}

}  // namespace sphc
