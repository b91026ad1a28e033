// SIMD pair loops (sphc --simd-pairs; CPU backends, double precision, not --mpi; off by
// default): the neighbours of one destination in SIMD lanes.
//
// A per-destination pair loop whose destination's sums are locals (codegen/RegisterSums.cpp)
// is printed with its neighbour loop under
//   #pragma omp simd reduction(+: acc_arho, acc_au, ...)
// over the list already filtered to the support (so no cut-off test in the loop), its pair
// quantities scalars (XIJ_0, XIJ_1, XIJ_2 in place of XIJ[3]; a gradient as its factor
// Kernel::gradient_factor times XIJ_k), and each body called in a third printing,
// NAME_loop_simd: the _sums form with `XIJ[k]` written `XIJ_k`. GCC vectorises such a loop
// (source properties gathered, the sums in vector registers, one horizontal sum per
// destination); local arrays passed by pointer (XIJ[3]) it does not (docs/performance.md,
// "SIMD pair loops: measured"). The bodies' `if`s are left to GCC's if-conversion: where it
// cannot, the loop stays scalar, with the same results. The build adds -fopenmp-simd
// (driver/Build.cpp).
//
// Results: each sum is reassociated (one partial sum per lane, added at the end), so they
// differ from the scalar loop's in the last bits; the same loop in serial and OpenMP
// (each destination in one thread) gives the same bits. A pass of each pair once
// (SymmetricPairs.cpp) that could be a SIMD loop is printed per destination instead.
//
// Refused (the loop's comment says why, the scalar loop follows): the sums not in locals,
// a body writing a destination property that is not one of those sums (every lane would
// store it), a body writing a scalar state, a loop_all in the pass, a vector pair quantity
// named otherwise than indexed by a literal component.
#include "analysis/PairQuantityTable.h"
#include "codegen/CppText.h"
#include "codegen/Printer.h"
#include "codegen/SymmetricPairs.h"

#include <algorithm>
#include <functional>
#include <set>

namespace sphc {

namespace {

size_t skipBlanks(const std::string& text, size_t i) {
  while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
  return i;
}

// Calls visit(word, begin, end) for each identifier of text outside comments (which keep
// their words: `// VIJ = v_a - v_b`); visit returns where the scan goes on (end, or past
// what it read), or npos to stop.
void scanIdentifiers(const std::string& text,
                     const std::function<size_t(const std::string&, size_t, size_t)>& visit) {
  for (size_t at = 0; at < text.size();) {
    if (text.compare(at, 2, "//") == 0) {
      at = text.find('\n', at);
      continue;
    }
    if (text.compare(at, 2, "/*") == 0) {
      at = text.find("*/", at + 2);
      at = at == std::string::npos ? at : at + 2;
      continue;
    }
    if (!isIdentifierChar(text[at])) {
      ++at;
      continue;
    }
    size_t end = at;
    while (end < text.size() && isIdentifierChar(text[end])) ++end;
    at = visit(text.substr(at, end - at), at, end);
  }
}

// The first call in `text` of a math function GCC does not vectorise without -ffast-math
// (no SIMD clone in glibc then), "" if none. With one in a body the loop may or may not
// vectorise depending on where GCC inlines it (the serial and the OpenMP builds would differ
// in their bits): refused instead.
std::string scalarMathCall(const std::string& text) {
  static const std::set<std::string> scalarOnly = {
      "pow",  "exp",  "exp2", "expm1", "log",   "log2",  "log10", "log1p", "sin",    "cos",
      "tan",  "asin", "acos", "atan",  "atan2", "sinh",  "cosh",  "tanh",  "cbrt",   "erf",
      "erfc", "tgamma", "lgamma", "hypot", "fmod"};
  std::string found;
  scanIdentifiers(text, [&](const std::string& word, size_t, size_t end) {
    const size_t open = skipBlanks(text, end);
    if (open < text.size() && text[open] == '(' && scalarOnly.count(word)) {
      found = word;
      return std::string::npos;
    }
    return end;
  });
  return found;
}

}  // namespace

bool scalarPairEdits(const std::string& text, std::vector<TextEdit>& edits, std::string& why) {
  scanIdentifiers(text, [&](const std::string& word, size_t at, size_t end) {
    const PairQuantity* pq = findPairQuantity(word);
    if (!pq || !pq->vector) return end;
    const size_t open = skipBlanks(text, end), digit = skipBlanks(text, open + 1),
                 close = skipBlanks(text, digit + 1);
    if (close >= text.size() || text[open] != '[' || text[digit] < '0' || text[digit] > '2' ||
        text[close] != ']') {
      why = word + " is used otherwise than by a literal component (" + word + "[0])";
      return std::string::npos;
    }
    edits.push_back({static_cast<unsigned>(at), static_cast<unsigned>(close + 1),
                     word + "_" + text[digit]});
    return close + 1;
  });
  return why.empty();
}

std::string ScenePrinter::simdPairsRefusal(const DestinationWork& w,
                                           const NeighbourPass& pass) const {
  if (!simdPairs_) return "off";
  if (pass.equations.empty()) return "no loop bodies";
  if (!pass.loopAll.empty()) return pass.loopAll[0]->name + " has a loop_all";
  const RegisterSums rs = registerSums(w, pass);
  if (!rs.active())
    return "the destination's sums are not in locals" +
           (rs.refusal.empty() ? std::string() : " (" + rs.refusal + ")");
  for (const PlanEquation* eq : pass.equations) {
    const PlanBody& b = methodBody(*eq, ast::Method::Loop);
    for (const PropAccess& x : b.facts.dWrites)
      if (!rs.props.count(x.prop))
        return eq->name + " writes d_" + x.prop + ", which is no sum in locals";
    if (!b.facts.statesWritten.empty())
      return eq->name + " writes the state " + *b.facts.statesWritten.begin();
    std::vector<TextEdit> edits;
    std::string why;
    if (!scalarPairEdits(b.source.text, edits, why)) return eq->name + ": " + why;
    const std::string call = scalarMathCall(b.source.text);
    if (!call.empty())
      return eq->name + " calls " + call + ", which GCC does not vectorise (its loop would be "
             "scalar or not depending on inlining)";
  }
  return "";
}

bool ScenePrinter::emitSimdNeighbours(std::ostream& os, const DestinationWork& w,
                                      const NeighbourPass& pass, const RegisterSums& sums) {
  if (!simdPairs_) return false;
  const std::string why = simdPairsRefusal(w, pass);
  const std::string in = "          ";
  if (!why.empty()) {
    os << in << "// Not in SIMD lanes (codegen/SimdPairs.cpp): " << why << ".\n";
    return false;
  }
  std::string reduction;
  for (const auto& [p, sc] : sums.props)
    for (int k : sc.second)
      reduction += (reduction.empty() ? "" : ", ") +
                   (sc.first == 1 ? "acc_" + p : "acc" + std::to_string(k) + "_" + p);
  os << in << "// The neighbours in SIMD lanes, the sums reduced across them (codegen/SimdPairs.cpp;\n"
     << in << "// sphc --simd-pairs; the list holds neighbours only: no cut-off test).\n";
  emitDestinationValueLoads(os, w, pass, in);
  os << in << "#pragma omp simd reduction(+: " << reduction << ")\n";
  os << in << "for (int k_nbr = 0; k_nbr < n_nbrs; ++k_nbr) {\n";
  const std::string body = in + "  ";
  os << body << "const int s_idx = static_cast<int>(NBRS[k_nbr]);\n";
  // The pair quantities as scalars: vectors by component, gradients as a factor times XIJ.
  emitLanePairQuantities(os, pass.pairQuantities, /*both=*/false, body, /*mask=*/false);
  for (const PlanEquation* eq : pass.equations)
    os << body << pairCall(*eq, w.array, sums, /*scalarPairs=*/true);
  os << in << "}\n";
  return true;
}

// The destination's other properties the bodies read, loaded once.
void ScenePrinter::emitDestinationValueLoads(std::ostream& os, const DestinationWork& w,
                                             const NeighbourPass& pass,
                                             const std::string& in) const {
  std::set<std::string> loads;
  for (const PlanEquation* eq : pass.equations)
    for (const auto& [p, sc] : destinationValues(methodBody(*eq, ast::Method::Loop), w.array))
      for (int k : sc.second)
        if (loads.insert(destinationValueName(p, sc.first, k)).second)
          os << in << destinationValueLoad(p, sc.first, k) << "\n";
}

// ---- Each pair once in SIMD lanes ----
//
// A same-array pass that may be each pair once (SymmetricPairs.cpp) and in SIMD lanes
// (simdPairsRefusal) is printed, after emitSymmetricPass's kept lists and destination-only
// values of every particle, as: per destination d_idx (increasing), its sums loaded in locals;
// the self pair, scalar, for d_idx alone (its _simd call on the locals: it has no mirrored
// call); then the rest of the list's upper part (every s_idx > d_idx) under
//   #pragma omp simd reduction(+: acc_...)
// with the pair quantities and their mirrors as scalars, the cut-off a mask (the kept lists
// hold the skin): each body's _simd form called twice per pair, for d_idx on the pair's
// terms pd_acc_NAME and for s_idx (mirrored quantities) on ps_acc_NAME, both starting at 0;
// acc_NAME += in_support ? pd_acc_NAME : 0.0 (the lane reduction); the source side added at
// s_idx under the mask (masked gathers and scatters). That scatter is legal in omp simd: the
// s_idx of one destination's list are distinct (no two lanes write one particle) and none is
// d_idx (whose sums are locals).
//
// Serial and OpenMP give the same bits. Particle j receives: the terms of every i < j, in
// increasing i, each added once to d_NAME[j] (i's mirrored terms), then at its own turn its
// sums loaded, the self pair, the lanes' reduction over its upper list. OpenMP (contiguous
// blocks of destinations, one per thread): (1) for the destinations of the block, their
// neighbours in earlier blocks, scalar, in list order: the same _simd call for (j, i) on
// pd_ locals, added to j's sums when in support: bitwise i's mirrored terms (the mirrored
// quantities are today's (j, i) values, SymmetricPairs.cpp; IEEE arithmetic the same in lanes
// and scalar: no contraction, no fast math); (2) the serial loop over the block, its scatter
// also masked to s_idx < b_end (later blocks have had theirs in their (1)); serial prints
// the same loop with b_end = n. So each destination's lane reduction runs over the same
// range in both, and each particle's additions come in the serial order.
std::string ScenePrinter::simdMirroredCall(const PlanEquation& eq, int d,
                                           const RegisterSums& sums,
                                           const std::string& sumsPrefix) const {
  const PlanBody& b = methodBody(eq, ast::Method::Loop);
  const auto values = destinationValues(b, d);
  const auto svalues = sourceValues(b);
  const std::string eqValues = eqStruct(eq);
  auto argument = [&](const BodyParam& p) -> std::string {
    switch (p.kind) {
      case BodyParam::Idx: return "s_idx";
      case BodyParam::SIdx: return "d_idx";
      case BodyParam::Pair: {
        const std::string m = mirroredPairQuantity(p.name);
        return findPairQuantity(p.name)->vector ? m + "_0, " + m + "_1, " + m + "_2" : m;
      }
      case BodyParam::DHoisted: return symmetricDestinationHoisted(eqValues, p.name) + "[s_idx]";
      case BodyParam::SProp: {  // particle d_idx's values, loaded before the lanes
        std::string args;
        if (svalues.count(p.name))
          for (int k : svalues.at(p.name).second)
            args += (args.empty() ? "" : ", ") +
                    sourceValueName(p.name, svalues.at(p.name).first, k);
        return args;
      }
      case BodyParam::DProp: {
        if (!values.count(p.name)) return "";
        std::string args;  // particle s_idx's values: gathers
        const auto& sc = values.at(p.name);
        for (int k : sc.second)
          args += (args.empty() ? "" : ", ") + std::string("d_") + p.name + "[" +
                  (sc.first == 1 ? std::string("s_idx")
                                 : std::to_string(sc.first) + " * s_idx + " + std::to_string(k)) +
                  "]";
        return args;
      }
      default: return "";
    }
  };
  const std::string fn = bodyFunctionName(eq.name, "loop") + "_simd";
  std::string call = pairCall(eq, d, sums, /*scalarPairs=*/true, sumsPrefix, argument);
  call.replace(0, fn.size(), fn + "_mirror");  // the form taking the source's values
  const size_t at = call.rfind('\n');  // its comment: say which destination
  return call.substr(0, at) + ": destination s_idx, source d_idx\n";
}

void ScenePrinter::emitLanePairQuantities(std::ostream& os, const std::set<std::string>& q,
                                          bool both, const std::string& body, bool mask) const {
  const std::string& R = host_.real;
  const PairDialect dialect = pairDialectOf(host_);
  os << body << "const " << R << " hj = sj_h[s_idx];\n";
  for (const PairQuantity& pq : pairQuantityTable()) {
    if (!(pq.when == PairWhen::BeforeTest || pq.when == PairWhen::EveryNeighbour ||
          q.count(pq.name)))
      continue;
    if (pq.form == PairForm::Difference) {
      for (int k = 0; k < 3; ++k)
        os << body << "const " << R << " " << pq.name << "_" << k << " = "
           << (k < plan_.dim ? pq.components[k] + "i - sj_" + pq.components[k] + "[s_idx]"
                             : std::string("0.0"))
           << ";\n";
      if (both)  // as a difference: a zero keeps the scalar form's sign
        for (int k = 0; k < 3; ++k)
          os << body << "const " << R << " " << pq.name << "_ji_" << k << " = "
             << (k < plan_.dim ? "sj_" + pq.components[k] + "[s_idx] - " + pq.components[k] + "i"
                               : std::string("0.0"))
             << ";\n";
    } else if (pq.form == PairForm::Gradient) {
      // grad_j of the mirrored call: DWIJ -> DWIJ_ji (same h), DWI (h_i) -> DWJ_ji, DWJ
      // (h_j) -> DWI_ji; the factor of (RIJ, h) once for both.
      const std::string partner =
          pq.name == "DWI" ? "DWJ_ji" : pq.name == "DWJ" ? "DWI_ji" : pq.name + "_ji";
      os << body << "const " << R << " " << pq.name << "_f = Kernel::gradient_factor(RIJ, "
         << pq.h << ");\n";
      for (int k = 0; k < 3; ++k)
        os << body << "const " << R << " " << pq.name << "_" << k << " = " << pq.name
           << "_f * XIJ_" << k << ";\n";
      if (both)
        for (int k = 0; k < 3; ++k)
          os << body << "const " << R << " " << partner << "_" << k << " = " << pq.name
             << "_f * XIJ_ji_" << k << ";\n";
    } else {
      std::string s = pairQuantityStatement(pq, plan_.dim, dialect, body);
      std::vector<TextEdit> edits;
      std::string unused;
      scalarPairEdits(s, edits, unused);
      std::sort(edits.begin(), edits.end(),
                [](const TextEdit& a, const TextEdit& b) { return a.begin > b.begin; });
      for (const TextEdit& e : edits) s.replace(e.begin, e.end - e.begin, e.replacement);
      os << s;
    }
  }
  if (!mask) return;
  os << body << "const " << R << " hmax = hi > hj ? hi : hj;\n";
  os << body << "const bool in_support = !(R2IJ >= RADIUS2 * hmax * hmax);  // the cut-off\n";
}

void ScenePrinter::emitSymmetricSimdLoops(const DestinationWork& w, const NeighbourPass& pass,
                                          const std::string& lists, bool openmp,
                                          const std::set<std::string>& q,
                                          const RegisterSums& sums) {
  const int d = w.array;
  std::string reduction, zeros, sumsOf, scatter;
  for (const auto& [p, sc] : sums.props)
    for (int k : sc.second) {
      const std::string acc = sc.first == 1 ? "acc_" + p : "acc" + std::to_string(k) + "_" + p;
      const std::string at = sc.first == 1 ? std::string("s_idx")
                                           : std::to_string(sc.first) + " * s_idx + " +
                                                 std::to_string(k);
      reduction += (reduction.empty() ? "" : ", ") + acc;
      zeros += (zeros.empty() ? "" : ", ") + std::string("pd_") + acc + " = 0.0, ps_" + acc +
               " = 0.0";
      sumsOf += "@" + acc + " += in_support ? pd_" + acc + " : 0.0;\n";
      scatter += "@  d_" + p + "[" + at + "] += ps_" + acc + ";\n";
    }
  auto lines = [](const std::string& text, const std::string& indent) {
    std::string out;
    for (size_t at = 0; at < text.size();) {
      const size_t nl = text.find('\n', at);
      out += indent + text.substr(at + 1, nl - at);  // past the '@'
      at = nl + 1;
    }
    return out;
  };
  // One destination loop's head: the destination's values, its kept list, its sums in locals.
  auto head = [&](const std::string& indent, const std::string& begin, const std::string& end,
                  const std::string& comment, const std::string& skip) {
    scene_ << indent << "for (int d_idx = " << begin << "; d_idx < " << end << "; ++d_idx) {"
           << comment << "\n";
    const std::string in = indent + "  ";
    emitSymmetricDestination(in, pass, q, lists);  // SymmetricPairs.cpp
    if (!skip.empty()) scene_ << in << "if (" << skip << ") continue;\n";
    emitSumsLoad(scene_, in, sums);  // codegen/RegisterSums.cpp
    emitDestinationValueLoads(scene_, w, pass, in);
  };
  // The destinations [begin, end) of a block (serial: one block, b_end = n).
  auto lanes = [&](const std::string& indent, const std::string& begin, const std::string& end) {
    head(indent, begin, end, "  // pairs (d_idx, s_idx >= d_idx)", "");
    const std::string in = indent + "  ", body = in + "  ";
    scene_ << in << "const std::uint32_t* k_lanes = kept.data() + " << lists
           << ".upper[d_idx];  // s_idx >= d_idx\n";
    scene_ << in << "if (k_lanes != k_end && *k_lanes == static_cast<std::uint32_t>(d_idx)) {"
           << "  // the self pair, scalar: d_idx alone\n";
    scene_ << body << "++k_lanes;\n" << body << "const int s_idx = d_idx;\n";
    emitLanePairQuantities(scene_, q, false, body);
    scene_ << body << "if (in_support) {\n";
    for (const PlanEquation* eq : pass.equations)
      scene_ << body << "  " << pairCall(*eq, d, sums, /*scalarPairs=*/true);
    scene_ << body << "}\n" << in << "}\n";
    scene_ << in << "const int n_lanes = static_cast<int>(k_end - k_lanes);\n";
    std::set<std::string> loads;  // the mirrored calls' source values: particle d_idx's
    for (const PlanEquation* eq : pass.equations)
      for (const auto& [p, sc] : sourceValues(methodBody(*eq, ast::Method::Loop)))
        for (int k : sc.second)
          if (loads.insert(sourceValueName(p, sc.first, k)).second)
            scene_ << in << "const " << host_.real << " " << sourceValueName(p, sc.first, k)
                   << " = s_" << p << "["
                   << (sc.first == 1 ? std::string("d_idx")
                                     : std::to_string(sc.first) + " * d_idx + " +
                                           std::to_string(k))
                   << "];\n";
    scene_ << in << "// The neighbours s_idx > d_idx in SIMD lanes, each pair once: d_idx's sums reduced\n"
           << in << "// across the lanes, s_idx's added at s_idx (a masked scatter: the s_idx of one\n"
           << in << "// list are distinct and none is d_idx, so no two lanes write one particle).\n";
    scene_ << in << "#pragma omp simd reduction(+: " << reduction << ")\n";
    scene_ << in << "for (int k_nbr = 0; k_nbr < n_lanes; ++k_nbr) {\n";
    scene_ << body << "const int s_idx = static_cast<int>(k_lanes[k_nbr]);\n";
    emitLanePairQuantities(scene_, q, true, body);
    scene_ << body << "double " << zeros << ";  // the pair's terms for d_idx, s_idx\n";
    for (const PlanEquation* eq : pass.equations)
      scene_ << body << pairCall(*eq, d, sums, /*scalarPairs=*/true, "pd_");
    for (const PlanEquation* eq : pass.equations)
      scene_ << body << simdMirroredCall(*eq, d, sums, "ps_");
    scene_ << lines(sumsOf, body);
    scene_ << body << "if (in_support && s_idx < b_end) {  // later blocks: in their (1)\n"
           << lines(scatter, body) << body << "}\n";
    scene_ << in << "}\n";
    emitSumsStore(scene_, in, sums);
    scene_ << indent << "}\n";
  };
  if (!openmp) {
    scene_ << "        {\n          const int b_end = n;  // one block: the OpenMP form's loop\n";
    lanes("          ", "0", "n");
    scene_ << "        }\n";
    return;
  }
  const std::string pragma = "        #pragma omp parallel for schedule(static) "
                             "default(firstprivate) shared(cells)\n";
  scene_ << "        const int n_blocks = std::max(1, std::min(n, omp_get_max_threads()));\n";
  scene_ << pragma;
  scene_ << "        for (int blk = 0; blk < n_blocks; ++blk) {\n";
  scene_ << "          const int b_begin = static_cast<int>(static_cast<long>(n) * blk / n_blocks);\n";
  scene_ << "          const int b_end = static_cast<int>(static_cast<long>(n) * (blk + 1) / n_blocks);\n";
  scene_ << "          // (1) from the neighbours in earlier blocks, per destination, scalar, in list\n"
            "          // order: bitwise the terms the serial loop's lanes scatter\n";
  scene_ << "          if (b_begin > 0) {\n";
  const std::string ind = "            ", in = ind + "  ", body = in + "  ";
  head(ind, "b_begin", "b_end", "",
       "k_end == kept.data() || kept.front() >= static_cast<std::uint32_t>(b_begin)");
  scene_ << in << "for (const std::uint32_t* k = kept.data(); k != k_end && *k < "
                  "static_cast<std::uint32_t>(b_begin); ++k) {\n";
  scene_ << body << "const int s_idx = static_cast<int>(*k);\n";
  emitLanePairQuantities(scene_, q, false, body);
  scene_ << body << "if (!in_support) continue;\n";
  std::string pd;
  for (const auto& [p, sc] : sums.props)
    for (int k : sc.second) {
      const std::string acc = sc.first == 1 ? "acc_" + p : "acc" + std::to_string(k) + "_" + p;
      pd += (pd.empty() ? "" : ", ") + std::string("pd_") + acc + " = 0.0";
    }
  scene_ << body << "double " << pd << ";\n";
  for (const PlanEquation* eq : pass.equations)
    scene_ << body << pairCall(*eq, d, sums, /*scalarPairs=*/true, "pd_");
  std::string adds = sumsOf;  // as in the lanes, in_support being true here
  scene_ << lines(adds, body);
  scene_ << in << "}\n";
  emitSumsStore(scene_, in, sums);
  scene_ << ind << "}\n";
  scene_ << "          }\n";
  scene_ << "          // (2) the block, as the serial loop; its scatter kept to the block\n";
  lanes("          ", "b_begin", "b_end");
  scene_ << "        }\n";
}

void ScenePrinter::emitSimdFunction(const PlanEquation& eq, std::ostringstream& os) {
  if (!simdPairs_) return;
  if (!simdDecls_) {  // the declarations whose loop some SIMD pass calls
    simdDecls_ = std::make_unique<std::set<int>>();
    walkPasses(sched_.equations, [&](const Phase&, const DestinationWork& w,
                                     const NeighbourPass& pass) {
      if (simdPairsRefusal(w, pass).empty())
        for (const PlanEquation* e : pass.equations) {
          simdDecls_->insert(e->declIndex);
          if (simdSymmetric_ && pass.source == w.array)  // each pair once: the mirrored form
            simdDecls_->insert(-1 - e->declIndex);
        }
    });
  }
  if (simdDecls_->count(eq.declIndex)) printSumsFunction(eq, true, os);
  if (simdDecls_->count(-1 - eq.declIndex)) printSumsFunction(eq, true, os, /*mirror=*/true);
}

}  // namespace sphc
