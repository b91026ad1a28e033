// SIMD pair loops (sphc --simd-pairs; CPU backends, double or single precision, not --mpi;
// off by default): the neighbours of one destination in SIMD lanes (8 doubles or 16 floats
// per zmm register).
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
// (driver/Build.cpp). In single precision the bodies' double arguments (t, dt, the equations'
// scalars) are float locals converted before the loop (f_t, f_eq2_alpha): GCC does not
// if-convert a conversion it sank into an `if` (it may trap), which kept the loop scalar.
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
//
// --simd-pairs=auto (the default): the SIMD form only where it pays (simdPairsAutoChoice;
// docs/performance.md "SIMD pair loops chosen by the compiler"): where the loop's expected
// neighbour count (the kernel support's ball over dx^dim, from the scene's defaults) reaches
// kSimdAutoNeighbours. Below it, each pair once saves more than the lanes (the 2D dam
// breaks); a loop that is per destination anyway stays scalar there too (measured to pay on
// one 2D scene only; --simd-pairs=on).
#include "analysis/PairQuantityTable.h"
#include "codegen/CppText.h"
#include "codegen/Printer.h"
#include "codegen/SymmetricPairs.h"
#include "sema/ConstEval.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
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

// The neighbours a destination of array d finds among the particles of array s in a full
// support: the volume of the ball of radius kernelRadiusScale * h (h: the larger initial h of
// the two arrays) over dx^dim (dx: the smallest spacing of s's geometry), with every param
// at its default; nothing where h or dx is no expression of params (a file's particles, the
// particles of an inlet, an h set elsewhere). `how` says what it used.
std::optional<double> expectedNeighbours(const Plan& plan, int d, int s, std::string& how) {
  ConstEval eval(plan);
  std::optional<double> h, dx;
  for (int a : {d, s}) {
    const PlanProperty* p = plan.arrays[a].find("h");
    std::optional<double> v = p && p->init ? eval(*p->init) : std::nullopt;
    if (!v || !(*v > 0) || !std::isfinite(*v)) {
      h.reset();
      break;
    }
    h = h ? std::fmax(*h, *v) : *v;
  }
  const ast::ArrayDecl* decl = plan.arrays[s].decl;
  if (decl && decl->loads.empty())
    for (const ast::GeometryDecl& g : decl->geometry)
      for (const ast::KwArg& kw : g.args)
        if (kw.name.name == "dx" && kw.value)
          if (std::optional<double> v = eval(*kw.value); v && *v > 0 && std::isfinite(*v))
            dx = dx ? std::fmin(*dx, *v) : *v;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%dD, support %g h", plan.dim, plan.kernelRadiusScale);
  how = buf;
  if (!h || !dx) return std::nullopt;
  const double hdx = *h / *dx;
  std::snprintf(buf, sizeof buf, ", h = %.3g dx", hdx);
  how += buf;
  const double r = plan.kernelRadiusScale * hdx;
  return plan.dim == 3 ? 4.0 / 3.0 * M_PI * r * r * r
         : plan.dim == 2 ? M_PI * r * r
                         : 2.0 * r;
}

}  // namespace

bool ScenePrinter::eachPairOncePossible(const DestinationWork& w,
                                        const NeighbourPass& pass) const {
  if (!simdSymmetric_) return false;
  if (pass.source == w.array) return symmetricPairsRefusal(plan_, w, pass, true).empty();
  // Two arrays: A <- B as A's last pair loop and B <- A as B's first (CpuPrinter::crossPair).
  bool found = false;
  walkPhases(sched_.equations, [&](const Phase& ph) {
    for (size_t a = 0; a + 1 < ph.destinations.size(); ++a) {
      const DestinationWork& A = ph.destinations[a];
      const DestinationWork& B = ph.destinations[a + 1];
      if (A.array == B.array || A.passes.empty() || B.passes.empty()) continue;
      if (!((&w == &A && &pass == &A.passes.back()) || (&w == &B && &pass == &B.passes.front())))
        continue;
      found |= A.passes.back().source == B.array && B.passes.front().source == A.array &&
               A.passes.back().searches() && B.passes.front().searches() &&
               crossPairsRefusal(plan_, ph, a, a + 1, true).empty();
    }
  });
  return found;
}

ScenePrinter::SimdAutoChoice ScenePrinter::simdPairsAutoChoice(const DestinationWork& w,
                                                               const NeighbourPass& pass) const {
  std::string how;
  const std::optional<double> n = expectedNeighbours(plan_, w.array, pass.source, how);
  // h/dx not known before the run: by the dimension (h = 1.3 dx: 3D 74 neighbours, 2D 21).
  bool lanes = n ? *n >= kSimdAutoNeighbours : plan_.dim == 3;
  char buf[160];
  if (n)
    std::snprintf(buf, sizeof buf, "~%.0f neighbours expected (%s) %s %g: ", *n, how.c_str(),
                  lanes ? ">=" : "<", kSimdAutoNeighbours);
  else
    std::snprintf(buf, sizeof buf, "h/dx not known before the run, by the dimension (%s): ",
                  how.c_str());
  std::string why = buf;
  // The CPU the solver is built for (SimdCpu.cpp): where the lanes lose, the scalar loops.
  if (lanes && !simdCpu_.lanes) {
    lanes = false;
    why.replace(why.size() - 2, 2, ", but " + simdCpu_.why + ": ");
  }
  if (eachPairOncePossible(w, pass))
    why += lanes ? "the lanes pay more than each pair once" : "each pair once pays more";
  else
    why += lanes ? "the lanes pay more than the scalar loop per destination"
                 : "scalar per destination (--simd-pairs=on puts it in lanes)";
  if (lanes && !simdCpu_.why.empty()) why += " (" + simdCpu_.why + ")";
  return {lanes, why};
}

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
  const std::string blocker = simdPairsBlocker(w, pass);
  if (!blocker.empty()) return blocker;
  if (simdAuto_) {  // --simd-pairs=auto: where the lanes pay
    const SimdAutoChoice c = simdPairsAutoChoice(w, pass);
    if (!c.lanes) return "--simd-pairs=auto: " + c.why;
  }
  return "";
}

std::string ScenePrinter::simdPairsBlocker(const DestinationWork& w,
                                           const NeighbourPass& pass) const {
  if (pass.equations.empty()) return "no loop bodies";
  // The Gaussian kernels' W and gradient call exp (runtime/include/sphc/kernel_shapes.h),
  // which GCC does not vectorise without -ffast-math: the loop would stay scalar, evaluating
  // each pair twice (the elliptical drops: 1.13-1.47x the CPU of --simd-pairs=off, stop 34).
  const bool expKernel = plan_.kernel == "Gaussian" || plan_.kernel == "SuperGaussian";
  if (expKernel) {
    bool usesKernel = false;
    for (const std::string& q : pass.pairQuantities) {
      const PairQuantity* pq = findPairQuantity(q);
      usesKernel |= pq && pq->kernel();
    }
    for (const PlanEquation* eq : pass.equations)
      usesKernel |= methodBody(*eq, ast::Method::Loop).source.text.find("KERNEL_") !=
                    std::string::npos;
    if (usesKernel)
      return "the " + plan_.kernel + " kernel calls exp, which GCC does not vectorise";
  }
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

std::vector<std::string> ScenePrinter::simdPairsNotes() const {
  std::vector<std::string> notes;
  if (!simdPairs_) return notes;
  walkPasses(sched_.equations, [&](const Phase& ph, const DestinationWork& w,
                                   const NeighbourPass& pass) {
    if (!pass.searches() || pass.equations.empty()) return;
    const std::string loop =
        arr(w.array).name + " <- " + arr(pass.source).name + " in " + ph.name;
    const std::string why = simdPairsRefusal(w, pass);
    if (!why.empty())
      notes.push_back("pair loop not in SIMD lanes: " + loop + ": " + why);
    else
      notes.push_back("pair loop in SIMD lanes: " + loop + ": " +
                      (simdAuto_ ? "--simd-pairs=auto: " + simdPairsAutoChoice(w, pass).why
                                 : std::string("--simd-pairs=on")));
  });
  return notes;
}

bool ScenePrinter::emitSimdNeighbours(std::ostream& os, const DestinationWork& w,
                                      const NeighbourPass& pass, const RegisterSums& sums) {
  if (!simdPairs_) return false;
  const std::string why = simdPairsRefusal(w, pass);
  const std::string in = "          ";
  if (!why.empty()) {
    if (!simdAuto_)  // auto: --report says why (its scalar loops are --simd-pairs=off's)
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
  // The destination's other properties the bodies read, loaded once.
  std::set<std::string> loads;
  for (const PlanEquation* eq : pass.equations)
    for (const auto& [p, sc] : destinationValues(methodBody(*eq, ast::Method::Loop), w.array))
      for (int k : sc.second)
        if (loads.insert(destinationValueName(p, sc.first, k)).second)
          os << in << destinationValueLoad(p, sc.first, k) << "\n";
  // Single precision: the double arguments (t, dt, the equations' scalars) as float locals;
  // converted in the loop, GCC would not if-convert a conversion under an `if` (it may trap).
  if (host_.floatBodies) {
    std::set<std::string> converted;
    for (const PlanEquation* eq : pass.equations)
      for (const BodyParam& p : bodyParams(methodBody(*eq, ast::Method::Loop), w.array, host_)) {
        const std::string name = floatScalarName(eqStruct(*eq), p);
        if (!name.empty() && converted.insert(name).second)
          os << in << "const float " << name << " = static_cast<float>("
             << (p.kind == BodyParam::Scalar ? eqStruct(*eq) + "." + p.name
                                             : std::string(p.kind == BodyParam::T ? "t" : "dt"))
             << ");\n";
      }
  }
  os << in << "#pragma omp simd reduction(+: " << reduction << ")\n";
  os << in << "for (int k_nbr = 0; k_nbr < n_nbrs; ++k_nbr) {\n";
  const std::string body = in + "  ";
  os << body << "const int s_idx = static_cast<int>(NBRS[k_nbr]);\n";
  os << body << "const " << host_.real << " hj = sj_h[s_idx];\n";
  // The pair quantities as scalars: vectors by component, gradients as a factor times XIJ.
  const PairDialect dialect = pairDialectOf(host_);
  for (const PairQuantity& pq : pairQuantityTable()) {
    if (!(pq.when == PairWhen::BeforeTest || pq.when == PairWhen::EveryNeighbour ||
          pass.pairQuantities.count(pq.name)))
      continue;
    if (pq.form == PairForm::Difference) {
      for (int k = 0; k < 3; ++k)
        os << body << "const " << host_.real << " " << pq.name << "_" << k << " = "
           << (k < plan_.dim ? pq.components[k] + "i - sj_" + pq.components[k] + "[s_idx]"
                             : std::string(host_.floatBodies ? "0.0f" : "0.0"))
           << ";\n";
    } else if (pq.form == PairForm::Gradient) {
      os << body << "const " << host_.real << " " << pq.name << "_f = Kernel::gradient_factor(RIJ, "
         << pq.h << ");\n";
      for (int k = 0; k < 3; ++k)
        os << body << "const " << host_.real << " " << pq.name << "_" << k << " = " << pq.name
           << "_f * XIJ_" << k << ";\n";
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
  for (const PlanEquation* eq : pass.equations)
    os << body << pairCall(*eq, w.array, sums, /*scalarPairs=*/true);
  os << in << "}\n";
  return true;
}

std::string ScenePrinter::floatScalarName(const std::string& eqValues, const BodyParam& p) {
  switch (p.kind) {
    case BodyParam::T: return "f_t";
    case BodyParam::Dt: return "f_dt";
    case BodyParam::Scalar: return "f_" + eqValues + "_" + p.name;
    default: return "";
  }
}

void ScenePrinter::emitSimdFunction(const PlanEquation& eq, std::ostringstream& os) {
  if (!simdPairs_) return;
  if (!simdDecls_) {  // the declarations whose loop some SIMD pass calls
    simdDecls_ = std::make_unique<std::set<int>>();
    walkPasses(sched_.equations, [&](const Phase&, const DestinationWork& w,
                                     const NeighbourPass& pass) {
      if (simdPairsRefusal(w, pass).empty())
        for (const PlanEquation* e : pass.equations) simdDecls_->insert(e->declIndex);
    });
  }
  if (simdDecls_->count(eq.declIndex)) printSumsFunction(eq, true, os);
}

}  // namespace sphc
