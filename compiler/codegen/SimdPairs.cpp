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
// destination); local arrays passed by pointer (XIJ[3]) it does not (docs/performance-log.md,
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
// docs/performance-log.md "SIMD pair loops chosen by the compiler"): where the loop's expected
// neighbour count (the kernel support's ball over dx^dim, from the scene's defaults) reaches
// kSimdAutoNeighbours. Below it, each pair once saves more than the lanes (the 2D dam
// breaks: in the each-pair-once lane form too, stop 36: 1.19-1.24x the scalar step at dx =
// 0.03, 1.02-1.35x at ~100k, on Intel with gathers; 0.84-0.86 from h = 1.6 dx, ~32). A loop
// over its own array that is per destination anyway by the scene (a periodic or mirror
// domain; zones where every pair body vanishes at the support, stop 38) goes in the lanes at
// any count (kSimdPerDestNeighbours; stop 36: 0.84-0.97 of the scalar step at ~28 neighbours,
// 0.79-0.81 for a per-destination loop at ~21; the zones' channel 0.76-0.82); one over
// another array (walls) keeps the threshold (the dam break's shifting fluid <- boundary in
// lanes: 1.08-1.10x).
//
// --simd-pairs=once: auto's loops, but a loop that could be each pair once is printed each
// pair once in the lanes (emitSymmetricSimdLoops, below): the values the pair shares once per
// pair, the source side scattered.
#include "analysis/PairQuantityTable.h"
#include "body/BodyAnalysis.h"
#include "codegen/CppText.h"
#include "codegen/Printer.h"
#include "codegen/SymmetricPairs.h"
#include "sema/ConstEval.h"

#include <algorithm>
#include <cctype>
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
// (no SIMD clone in glibc then: the allowed math functions but laneMathFunction's,
// body/BodyAnalysis.h), "" if none. With one in a body the loop may or may not vectorise
// depending on where GCC inlines it (the serial and the OpenMP builds would differ in their
// bits): refused instead.
std::string scalarMathCall(const std::string& text) {
  static const std::set<std::string> scalarOnly = [] {
    std::set<std::string> names;
    for (const std::string& f : allowedMathFunctions())
      if (!laneMathFunction(f)) names.insert(f);
    return names;
  }();
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

// text with its comments blanked (offsets kept).
std::string withoutComments(std::string text) {
  for (size_t at = 0; at < text.size();) {
    if (text.compare(at, 2, "//") == 0) {
      const size_t nl = text.find('\n', at);
      const size_t end = nl == std::string::npos ? text.size() : nl;
      std::fill(text.begin() + at, text.begin() + end, ' ');
      at = end;
    } else if (text.compare(at, 2, "/*") == 0) {
      size_t end = text.find("*/", at + 2);
      end = end == std::string::npos ? text.size() : end + 2;
      for (size_t k = at; k < end; ++k)
        if (text[k] != '\n') text[k] = ' ';
      at = end;
    } else {
      ++at;
    }
  }
  return text;
}

// Whether text[at] (comments blanked) is in a branch: an operand after a `?` of its
// statement, or a block opened by `if (...)` or `else`, at any depth.
bool inBranch(const std::string& text, size_t at) {
  int paren = 0;
  bool statement = true;  // still in the call's statement (no `;`, `{`, `}` at depth 0 met)
  for (size_t k = at; k-- > 0;) {
    const char c = text[k];
    if (c == ')') ++paren;
    else if (c == '(') paren = std::max(0, paren - 1);
    else if (c == '?' && statement && paren == 0) return true;
    else if (c == ';' || c == '}') {
      if (c == '}') {  // skip the whole block before
        int depth = 1;
        while (k-- > 0 && depth > 0) depth += text[k] == '}' ? 1 : text[k] == '{' ? -1 : 0;
        if (depth > 0) return false;
      }
      statement = false;
      paren = 0;
    } else if (c == '{') {  // the enclosing block: its opener
      statement = false;
      paren = 0;
      size_t b = k;
      while (b > 0 && std::isspace(static_cast<unsigned char>(text[b - 1]))) --b;
      if (b >= 4 && text.compare(b - 4, 4, "else") == 0 && (b == 4 || !isIdentifierChar(text[b - 5])))
        return true;
      if (b > 0 && text[b - 1] == ')') {
        int depth = 0;
        size_t o = b;
        while (o-- > 0) {
          depth += text[o] == ')' ? 1 : text[o] == '(' ? -1 : 0;
          if (depth == 0) break;
        }
        if (o == std::string::npos || o > b) return false;
        size_t w = o;
        while (w > 0 && std::isspace(static_cast<unsigned char>(text[w - 1]))) --w;
        if (w >= 2 && text.compare(w - 2, 2, "if") == 0 && (w == 2 || !isIdentifierChar(text[w - 3])))
          return true;
      }
    }
  }
  return false;
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

std::vector<std::pair<unsigned, unsigned>> scalarMathCallSites(const std::string& text) {
  std::vector<std::pair<unsigned, unsigned>> sites;
  for (size_t from = 0; from < text.size();) {
    const std::string rest = text.substr(from);
    const std::string call = scalarMathCall(rest);
    if (call.empty()) break;
    size_t at = std::string::npos;  // where scalarMathCall found it
    scanIdentifiers(rest, [&](const std::string& word, size_t b, size_t end) {
      const size_t open = skipBlanks(rest, end);
      if (word == call && open < rest.size() && rest[open] == '(') {
        at = from + b;
        return std::string::npos;
      }
      return end;
    });
    if (at == std::string::npos) break;
    sites.push_back({static_cast<unsigned>(at), static_cast<unsigned>(at + call.size())});
    from = at + call.size();
  }
  return sites;
}

std::string ScenePrinter::rareCallsRefusal(const PlanBody& b) const {
  const std::string& text = b.source.text;
  const std::string plain = withoutComments(text);
  std::vector<std::pair<unsigned, unsigned>> values;  // the hoisted and pair-shared values' text
  for (const SourceOnlySite& h : allHoistedSites(b)) values.push_back({h.begin, h.end});
  for (const SourceOnlySite& h : b.facts.pairShared) {  // (every candidate: pairSharedSites asks the lanes)
    values.push_back({h.begin, h.end});
    if (h.stmtBegin < h.stmtEnd) values.push_back({h.stmtBegin, h.stmtEnd});
    for (const auto& l : h.locals) values.push_back({l.initBegin, l.initEnd});
  }
  for (const auto& [begin, end] : scalarMathCallSites(text)) {
    const std::string call = text.substr(begin, end - begin);
    for (const auto& [vb, ve] : values)
      if (vb <= begin && end <= ve)
        return "its call of " + call + " is in a value computed outside the lanes";
    if (!inBranch(plain, begin)) return "its call of " + call + " is in no branch (every pair takes it)";
  }
  return "";
}

bool ScenePrinter::rareCalls(const NeighbourPass& pass) const {
  for (const PlanEquation* eq : pass.equations)
    if (!scalarMathCall(methodBody(*eq, ast::Method::Loop).source.text).empty()) return true;
  return false;
}

bool ScenePrinter::rareCallsInTiles(const DestinationWork& w, const NeighbourPass& pass) const {
  return simdCluster_ && !clusterAutoSkipsDim() && rareCalls(pass) &&
         onceForm(w, pass) && clusterTilesFormRefusal(w, pass).empty();
}

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

std::string ScenePrinter::zonesLanesRefusal() const {
  // The lanes sum a destination's neighbours in another order than the scalar loop, so the
  // positions differ in their last bits after a step; a pair at the cut-off may then be a
  // neighbour in one build and not in the other. Harmless (a change of the order of the
  // round-off) where what a pair adds vanishes at the cut-off (body/SelfPair.cpp,
  // vanishesAtSupport): not with a kernel that does not vanish there, a loop_all body (it
  // sees the list), or a loop body that adds a count or an unweighted value.
  if (plan_.kernel == "Gaussian" || plan_.kernel == "SuperGaussian")
    return "the kernel " + plan_.kernel + " does not vanish at its support";
  for (const PlanEquation& eq : plan_.equations) {
    if (!eq.live || eq.sources.empty()) continue;
    const auto& methods = plan_.equationDecls[eq.declIndex].methods;
    if (methods.count(ast::Method::LoopAll))
      return eq.name + " has a loop_all body (it sees the neighbour list)";
    auto loop = methods.find(ast::Method::Loop);
    if (loop != methods.end() && !plan_.bodies[loop->second].facts.vanishesAtSupport)
      return eq.name + " adds what does not vanish at the support (a pair at the cut-off, in "
                       "or out by a rounding of the positions, changes its sums by a whole term)";
  }
  return "";
}

ScenePrinter::SimdAutoChoice ScenePrinter::simdPairsAutoChoice(const DestinationWork& w,
                                                               const NeighbourPass& pass) const {
  std::string how;
  const std::optional<double> n = expectedNeighbours(plan_, w.array, pass.source, how);
  const bool onceAnyway = eachPairOncePossible(w, pass);
  // A loop over its own array that is per destination anyway by the scene (a periodic or
  // mirror domain: no each pair once there): in the lanes from kSimdPerDestNeighbours
  // (stop 36: 0.84-0.97 of the scalar step at ~28 neighbours in 2D; a per-destination loop at
  // ~21, the dam break with --no-symmetric-pairs, 0.79-0.81). Not where a
  // switch makes it per destination (--no-symmetric-pairs: the reference of the each-pair-once
  // loops) nor where its bodies refuse each pair once (the tests' bitwise references; not
  // measured): scalar as before. A loop over another array (walls) keeps the threshold: most of
  // its destinations have few or no neighbours there (the dam break's fluid <- boundary in
  // lanes: 1.08-1.10x).
  // With zones (inlets, outlets: the lists are gathered at every evaluation, so the loops
  // are per destination anyway), with or without a domain, where every pair-loop body of the
  // scene adds what vanishes at the support (zonesLanesRefusal). Stop 36 left zones out (the channel's TVF
  // scene's serial and OpenMP bits: GCC's inlining of the kernel, fixed in stop 37); stop 37
  // found the cylinder in lanes 2.3e-10 of u from OpenCL and the scalar loops after one step
  // at two particles: its lattice start (h = dx, support 3 h) puts pairs at r = 3 h exactly,
  // the lanes' sums round the first evaluation's transport acceleration (a near-cancelling
  // sum) otherwise, one particle moves 1 ulp otherwise, and the pair at the cut-off is in one
  // build and out in the other: EDACAveragePressure's count and sum of p jump there (p_avg
  // by 1/26), not the kernel-weighted sums. Stop 38: the channel 0.76-0.82 of the scalar CPU
  // time, the cylinder (EDACAveragePressure) scalar (docs/performance-log.md, "Loose ends (stop
  // 38)").
  // Not where the scalar loop evaluates each pair once with the ghosts kept with the lists
  // (stop 36, CpuPrinter::symmetricPass): Taylor-Green EDAC nx = 100 took 1.05x the CPU of
  // the scalar each-pair-once loops with these two loops per destination in lanes (3.19-3.23
  // against 3.03-3.10 s for 110 steps, interleaved, load ~1).
  const bool ghostOnceScalar =
      simdGhostOnce_ && pass.source == w.array &&
      symmetricPairsRefusal(plan_, w, pass, true).empty();
  const bool perDestOwn = !onceAnyway && !ghostOnceScalar && pass.source == w.array &&
                          plan_.dim >= 2 && simdSymmetricSwitch_ &&
                          (hasZones() ? zonesLanesRefusal().empty() : hasDomain());
  // --simd-once-neighbours: a threshold of its own for a loop the lanes print each pair once.
  const bool once = simdOnce_ && onceForm(w, pass) && simdOnceNeighbours_ >= 0;
  const double threshold = once ? simdOnceNeighbours_
                           : perDestOwn ? simdPerDestNeighbours_
                                        : simdNeighbours_;
  // h/dx not known before the run: by the dimension (h = 1.3 dx: 3D 74 neighbours, 2D 21).
  bool lanes = n ? *n >= threshold : plan_.dim == 3 || (perDestOwn && threshold <= 0);
  char buf[240];
  if (n && perDestOwn && threshold <= 0)
    std::snprintf(buf, sizeof buf, "~%.0f neighbours expected (%s), over its own array and per "
                  "destination anyway (lanes at any count): ", *n, how.c_str());
  else if (n)
    std::snprintf(buf, sizeof buf, "~%.0f neighbours expected (%s) %s %g%s: ", *n, how.c_str(),
                  lanes ? ">=" : "<", threshold,
                  once ? " (each pair once in lanes)"
                       : perDestOwn ? " (over its own array, per destination anyway)" : "");
  else
    std::snprintf(buf, sizeof buf, "h/dx not known before the run, by the dimension (%s)%s: ",
                  how.c_str(), perDestOwn ? " and the loop (over its own array, per destination anyway)" : "");
  std::string why = buf;
  if (!perDestOwn && !onceAnyway && !ghostOnceScalar && pass.source == w.array &&
      plan_.dim >= 2 && simdSymmetricSwitch_ && hasZones() && !lanes)
    why.insert(why.size() - 2, " (zones: not at any count, " + zonesLanesRefusal() + ")");
  // The CPU the solver is built for (SimdCpu.cpp): where the lanes lose, the scalar loops.
  if (lanes && !simdCpu_.lanes) {
    lanes = false;
    why.replace(why.size() - 2, 2, ", but " + simdCpu_.why + ": ");
  }
  // --simd-pairs=cluster (opt-in; stop 38): a 2D loop each pair once over its own array below
  // the threshold goes to the lanes where the tiles take it (clusterTilesFormRefusal), to be
  // printed as tiles, never as lanes (the lanes lose in 2D; a loop the tiles refuse keeps the
  // scalar loop). Stops 38-40 kept it out of auto's rule (at ~100k particles the tiles lost to
  // the scalar loops: docs/performance-log.md, "Cluster-pair tiles for the 2D scenes (stop 38)",
  // "The tile branches merged; 2D tiles by default? (stop 40)").
  // Auto's rule too where SimdCpuVerdict::tiles2d holds (stop 41: with the j side read from
  // the particles' arrays the tiles beat the scalar loops at dx = 0.03 and ~100k,
  // docs/performance-log.md, "2D tiles by default? (stop 41)"; auto's default on Intel
  // model 207 since stop 43, on every CPU of the tiles since stop 44: SimdCpu.cpp).
  if (!lanes && simdCluster_ && !clusterAutoSkipsDim() && plan_.dim == 2 && simdCpu_.lanes &&
      onceForm(w, pass) && clusterTilesFormRefusal(w, pass).empty())
    return {true, why + "in cluster-pair tiles at any count (" + simdClusterWhy_ + ")"};
  if (onceAnyway || ghostOnceScalar)
    why += lanes ? (simdOnce_ && pass.source == w.array ? "the lanes pay, each pair once in them"
                                                         : "the lanes pay more than each pair once")
                 : "each pair once pays more";
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

// A pair quantity's statement with its vector quantities read as their scalar components
// (scalarPairEdits), as the lane loops print it.
static std::string scalarPairStatement(std::string s) {
  std::vector<TextEdit> edits;
  std::string unused;
  scalarPairEdits(s, edits, unused);
  std::sort(edits.begin(), edits.end(),
            [](const TextEdit& a, const TextEdit& b) { return a.begin > b.begin; });
  for (const TextEdit& e : edits) s.replace(e.begin, e.end - e.begin, e.replacement);
  return s;
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
    if (!call.empty() && !rareCallsInTiles(w, pass))
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
    if (!why.empty()) {
      // --simd-pairs=cluster: why a 2D loop each pair once is not in the tiles either (the
      // tiles' own refusal, clusterTilesFormRefusal; stop 40).
      std::string tiles;
      if (simdCluster_ && !clusterAutoSkipsDim() && plan_.dim == 2 && onceForm(w, pass)) {
        const std::string t = clusterTilesFormRefusal(w, pass);
        if (!t.empty()) tiles = " (not in cluster-pair tiles: " + t + ")";
      }
      notes.push_back("pair loop not in SIMD lanes: " + loop + ": " + why + tiles);
    }
    else if (onceLanes(w, pass) && clusterTilesRefusal(w, pass).empty())  // ClusterPairs.cpp
      notes.push_back("pair loop in cluster-pair tiles, each pair once: " + loop + ": " +
                      simdClusterWhy_);
    else if (onceLanes(w, pass))
      notes.push_back("pair loop in SIMD lanes, each pair once: " + loop +
                      ": --simd-pairs=auto: " + simdPairsAutoChoice(w, pass).why +
                      (clusterTilesRefusal(w, pass) != "off" ? " (not in cluster-pair tiles: " +
                                                                   clusterTilesRefusal(w, pass) + ")"
                                                             : std::string()));
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
  emitDestinationValueLoads(os, w, pass, in);
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
  os << body << "const " << host_.real << " hj = " << hjValue("sj_h[s_idx]") << ";\n";
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
      os << body << "const " << host_.real << " " << pq.name << "_f = "
         << kernelCall("gradient_factor", "RIJ, ", pq.h, "") << ";\n";
      for (int k = 0; k < 3; ++k)
        os << body << "const " << host_.real << " " << pq.name << "_" << k << " = " << pq.name
           << "_f * XIJ_" << k << ";\n";
    } else {
      os << scalarPairStatement(pairStatement(pq, dialect, body));
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
        for (const PlanEquation* e : pass.equations) {
          simdDecls_->insert(e->declIndex);
          if (onceLanes(w, pass))  // each pair once in the lanes: the mirrored form too
            simdDecls_->insert(-1 - e->declIndex);
        }
    });
  }
  // The tiles' rare forms (a body with scalar math calls is in lanes only in the tiles).
  const bool rare = !scalarMathCall(methodBody(eq, ast::Method::Loop).source.text).empty();
  if (rare && !rareHelperPrinted_ && simdDecls_->count(eq.declIndex)) {
    rareHelperPrinted_ = true;
    os << "// The tiles' rare path (codegen/ClusterPairs.cpp, stop 40): in the lanes a body's call of a\n"
          "// math function GCC does not vectorise marks the lane (its pair is redone by the\n"
          "// scalar fix-up with the real call) and gives 0.\n"
          "// (The mark counts, read and written: GCC 12 if-converts that in a branch, not a\n"
          "// plain store, `rare = 1.0`, which leaves the lanes scalar, \"control flow in loop\";\n"
          "// nor a struct holding a reference to it, which takes its address.)\n"
          "template <class... A>\n"
          "static inline double sphc_rare_call(double& rare, A...) {\n"
          "  rare = rare + 1.0;\n"
          "  return 0.0;\n"
          "}\n\n";
  }
  if (simdDecls_->count(eq.declIndex)) {
    if (rare) printSumsFunction(eq, true, os, false, true);
    printSumsFunction(eq, true, os);
    emitPairSharedSimdFunctions(methodBody(eq, ast::Method::Loop),
                                bodyFunctionName(eq.name, "loop"), eq.dest, os);
  }
  if (simdDecls_->count(-1 - eq.declIndex)) {
    printSumsFunction(eq, true, os, /*mirror=*/true);
    if (rare) printSumsFunction(eq, true, os, /*mirror=*/true, true);
  }
}

// ---- Each pair once in SIMD lanes (--simd-pairs=once) ----
//
// A same-array pass that may be each pair once (SymmetricPairs.cpp) and that the lanes take
// (simdPairsRefusal) is printed, after emitSymmetricPass's kept lists and destination-only
// values of every particle, as: per destination d_idx (increasing), its sums loaded in
// locals; the self pair, scalar, for d_idx alone (it has no mirrored call), or skipped where
// every body adds zeros there (skipsSelfPair, body/SelfPair.cpp; as the scalar loops, bit for
// bit but for the sign of a sum that is -0 then; --no-self-pair-skip keeps it); then the rest
// of the list's upper part (every s_idx > d_idx) under
//   #pragma omp simd reduction(+: acc_...)
// with the pair quantities and their mirrors as scalars, the cut-off a mask (the kept lists
// hold the skin), the values the pair shares (body/PairShared.cpp) computed once per pair
// (pshared_eqN_K, NAME_loop_pairsharedK_simd), and each body's _simd form called twice on
// them: for d_idx on the pair's terms pd_acc_NAME (from 0), acc_NAME += in_support ?
// pd_acc_NAME : 0.0 (the lane reduction); mirrored, for s_idx on its sums gathered (ps_acc_NAME,
// an antisymmetric shared value negated), stored back under the mask (a gather and a masked
// scatter per sum). The scatter is legal in omp simd: the s_idx of one list are distinct (no
// two lanes write one particle) and none is d_idx (whose sums are locals).
//
// Serial and OpenMP give the same bits. Particle j receives the calls of every i < j, in
// increasing i, each on d_NAME[j], then at its own turn its sums loaded, the self pair, the lanes' reduction over its upper list. OpenMP (contiguous blocks of destinations,
// one per thread): (1) for the destinations of the block, their neighbours in earlier
// blocks, scalar, in list order: the same _simd call for (j, i) on j's sums in locals when
// in support: bitwise i's mirrored call on them (the mirrored quantities are the (j, i)
// values, computed as differences; a shared value is the same double or its negation both
// ways; IEEE arithmetic alike in lanes and scalar: no contraction, no fast math); (2) the
// serial loop over the block, its scatter also masked to s_idx < b_end (later blocks have
// had theirs in their (1)); serial prints the same loop with b_end = n.
bool ScenePrinter::onceLanes(const DestinationWork& w, const NeighbourPass& pass) const {
  return onceForm(w, pass) && simdPairsRefusal(w, pass).empty();
}

bool ScenePrinter::onceForm(const DestinationWork& w, const NeighbourPass& pass) const {
  if (!simdOnce_ || pass.source != w.array || !pass.searches()) return false;
  if (!symmetricPairsRefusal(plan_, w, pass, true).empty()) return false;
  // The sums only added to (`d_NAME[...] +=` or `-=`): the pair's terms from 0 are added to
  // the sums after the bodies.
  const RegisterSums rs = registerSums(w, pass);
  for (const PlanEquation* eq : pass.equations) {
    const std::string& text = methodBody(*eq, ast::Method::Loop).source.text;
    for (const auto& [p, sc] : rs.props) {
      const std::string name = "d_" + p;
      for (size_t at = text.find(name); at != std::string::npos; at = text.find(name, at + 1)) {
        if ((at > 0 && isIdentifierChar(text[at - 1])) ||
            (at + name.size() < text.size() && isIdentifierChar(text[at + name.size()])))
          continue;
        const size_t close = text.find(']', at);
        if (close == std::string::npos) return false;
        const size_t op = skipBlanks(text, close + 1);
        if (text.compare(op, 2, "+=") != 0 && text.compare(op, 2, "-=") != 0) return false;
      }
    }
  }
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
      case BodyParam::DHoisted: {  // (a value of the parameters alone: the pass's, stop 46)
        const std::string once = passDestinationHoisted(eq, std::stoul(p.name));
        return once.empty() ? symmetricDestinationHoisted(eqValues, p.name) + "[s_idx]" : once;
      }
      case BodyParam::PairShared: {  // computed once for the pair in the lanes
        auto it = pairSharedScope_.find(eqValues + "/" + p.name);
        if (it == pairSharedScope_.end())
          SPHC_INTERNAL("a pair-shared value with no local in the lanes: " + eq.name);
        return (it->second.sign < 0 ? "-" : "") + it->second.local;
      }
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
        // Particle s_idx's values: gathers, through s_NAME where the body reads it too (the
        // same array: one gather for both calls).
        bool viaSource = false;
        for (const PropAccess& r : b.facts.sReads) viaSource |= r.prop == p.name;
        std::string args;
        const auto& sc = values.at(p.name);
        for (int k : sc.second)
          args += (args.empty() ? "" : ", ") + std::string(viaSource ? "s_" : "d_") + p.name + "[" +
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
                                          bool both, const std::string& body, bool mask,
                                          bool negatedMirrors, bool tileRecip) const {
  const std::string& R = host_.real;
  const PairDialect dialect = pairDialectOf(host_);
  os << body << "const " << R << " hj = " << hjValue("sj_h[s_idx]") << ";\n";
  auto printed = [&](const PairQuantity& pq) {
    return pq.when == PairWhen::BeforeTest || pq.when == PairWhen::EveryNeighbour ||
           q.count(pq.name);
  };
  // --tile-math=batched (stop 45): where a lane needs RHOIJ1 and the kernel's 1/r^2 (a
  // gradient), those two reciprocals from one division (sphc::tile_reciprocals, kernels.h),
  // printed before the first kernel value, with RHOIJ moved there. The kernel's 1/h stays a
  // division of its own, once per pass where h is uniform (uh_ih; analysis/UniformH.cpp), so
  // that --no-uniform-h gives the same values bit for bit; without RHOIJ1 or a gradient:
  // recip's forms (docs/performance-log.md, "One division for the tiles' reciprocals (stop
  // 45)").
  std::set<std::string> kernelHs;
  bool needR2 = false, needRho = false;
  if (tileRecip && tileMathBatched_)
    for (const PairQuantity& pq : pairQuantityTable()) {
      if (!printed(pq)) continue;
      if (pq.form == PairForm::Kernel || pq.form == PairForm::Gradient) kernelHs.insert(pq.h);
      needR2 |= pq.form == PairForm::Gradient;
      needRho |= pq.name == "RHOIJ1";
    }
  const bool batched = needRho && needR2;
  bool batchPrinted = false;
  auto printBatch = [&] {
    batchPrinted = true;
    for (const PairQuantity& pq : pairQuantityTable())
      if (pq.name == "RHOIJ")
        os << scalarPairStatement(pairQuantityStatement(pq, plan_.dim, dialect, body));
    os << body << R << " tile_ir2, RHOIJ1;  // one division for 2 reciprocals (--tile-math=batched)\n";
    os << body << "sphc::tile_reciprocals(sphc::tile_r2_guard(R2IJ), RHOIJ, tile_ir2, RHOIJ1);\n";
    for (const std::string& h : kernelHs)  // the kernel's 1 / h: once per pass where uniform
      os << body << "const " << R << " tile_ih_" << h << " = "
         << (uhI_ && uhJ_ && h == "HIJ" ? uhPrefix_ + "ih;  // h uniform: once per pass"
                                        : "1.0 / " + h + ";")
         << "\n";
  };
  for (const PairQuantity& pq : pairQuantityTable()) {
    if (!printed(pq)) continue;
    if (batched && !batchPrinted &&
        (pq.form == PairForm::Kernel || pq.form == PairForm::Gradient || pq.name == "RHOIJ1"))
      printBatch();
    if (batched && (pq.name == "RHOIJ" || pq.name == "RHOIJ1") && needRho) continue;
    if (pq.form == PairForm::Difference) {
      for (int k = 0; k < 3; ++k)
        os << body << "const " << R << " " << pq.name << "_" << k << " = "
           << (k < plan_.dim ? pq.components[k] + "i - sj_" + pq.components[k] + "[s_idx]"
                             : std::string("0.0"))
           << ";\n";
      if (both)  // as a difference: a zero keeps the scalar form's sign
        for (int k = 0; k < 3; ++k)
          os << body << "const " << R << " " << pq.name << "_ji_" << k << " = "
             << (k >= plan_.dim    ? std::string("0.0")
                 : negatedMirrors ? "-" + pq.name + "_" + std::to_string(k)
                                  : "sj_" + pq.components[k] + "[s_idx] - " + pq.components[k] + "i")
             << ";\n";
    } else if (pq.form == PairForm::Gradient) {
      // grad_j of the mirrored call: DWIJ -> DWIJ_ji (same h), DWI (h_i) -> DWJ_ji, DWJ
      // (h_j) -> DWI_ji; the factor of (RIJ, h) once for both.
      const std::string partner =
          pq.name == "DWI" ? "DWJ_ji" : pq.name == "DWJ" ? "DWI_ji" : pq.name + "_ji";
      if (batched)  // (1/r^2 from the batch above, 1/h beside it)
        os << body << "const " << R << " " << pq.name
           << "_f = Kernel::gradient_factor_tile_rcp(RIJ, tile_ir2, tile_ih_" << pq.h << ");\n";
      else if (tileRecip)  // (the tiles: no division after the square root, kernels.h)
        os << body << "const " << R << " " << pq.name
           << "_f = " << kernelCall("gradient_factor_tile", "RIJ, R2IJ, ", pq.h, "") << ";\n";
      else
        os << body << "const " << R << " " << pq.name << "_f = "
           << kernelCall("gradient_factor", "RIJ, ", pq.h, "") << ";\n";
      for (int k = 0; k < 3; ++k)
        os << body << "const " << R << " " << pq.name << "_" << k << " = " << pq.name
           << "_f * XIJ_" << k << ";\n";
      if (both)
        for (int k = 0; k < 3; ++k)
          os << body << "const " << R << " " << partner << "_" << k << " = " << pq.name
             << "_f * XIJ_ji_" << k << ";\n";
    } else if (pq.form == PairForm::Kernel && batched) {
      os << body << "const " << R << " " << pq.name << " = Kernel::w_tile_rcp(RIJ, tile_ih_" << pq.h
         << ");\n";
    } else if (pq.form == PairForm::Kernel && tileRecip) {
      os << body << "const " << R << " " << pq.name << " = " << kernelCall("w_tile", "RIJ, ", pq.h, "")
         << ";\n";
    } else {
      os << scalarPairStatement(pairStatement(pq, dialect, body));
    }
  }
  if (!mask) return;
  os << body << "const " << R << " hmax = " << hmaxValue() << ";\n";
  os << body << "const bool in_support = !(R2IJ >= " << cutoffValue("RADIUS2") << ");  // the cut-off\n";
}

void ScenePrinter::emitSymmetricSimdLoops(const DestinationWork& w, const NeighbourPass& pass,
                                          const std::string& lists, bool openmp,
                                          const std::set<std::string>& q,
                                          const RegisterSums& sums) {
  const int d = w.array;
  std::string reduction, pdZeros, psGathers, sumsOf, scatter;
  for (const auto& [p, sc] : sums.props)
    for (int k : sc.second) {
      const std::string acc = sc.first == 1 ? "acc_" + p : "acc" + std::to_string(k) + "_" + p;
      const std::string at = sc.first == 1 ? std::string("s_idx")
                                           : std::to_string(sc.first) + " * s_idx + " +
                                                 std::to_string(k);
      reduction += (reduction.empty() ? "" : ", ") + acc;
      pdZeros += (pdZeros.empty() ? "" : ", ") + std::string("pd_") + acc + " = 0.0";
      psGathers += "@double ps_" + acc + " = s_idx < b_end ? d_" + p + "[" + at + "] : 0.0;\n";
      sumsOf += "@" + acc + " += in_support ? pd_" + acc + " : 0.0;\n";
      scatter += "@  d_" + p + "[" + at + "] = ps_" + acc + ";\n";
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
  // One destination loop's head: its values, its destination-only values as they were
  // before the pass, its kept list, its sums in locals, its other values (dval_NAME).
  auto head = [&](const std::string& indent, const std::string& begin, const std::string& end,
                  const std::string& comment, const std::string& skip) {
    scene_ << indent << "for (int d_idx = " << begin << "; d_idx < " << end << "; ++d_idx) {"
           << comment << "\n";
    const std::string in = indent + "  ";
    emitDestLocals(scene_, in, q, host_);
    for (const PlanEquation* eq : pass.equations) {
      const auto sites = hoistedDestinationSites(methodBody(*eq, ast::Method::Loop), host_);
      for (size_t k = 0; k < sites.size(); ++k) {
        const std::string K = std::to_string(k), once = passDestinationHoisted(*eq, k);
        scene_ << in << "const double " << hoistDestinationArgument(eqStruct(*eq), K) << " = "
               << (once.empty() ? symmetricDestinationHoisted(eqStruct(*eq), K) + "[d_idx]" : once)
               << ";\n";
      }
    }
    scene_ << in << "const std::vector<std::uint32_t>& kept = " << lists << ".lists[d_idx];\n";
    scene_ << in << "const std::uint32_t* const k_end = kept.data() + kept.size();\n";
    if (!skip.empty()) scene_ << in << "if (" << skip << ") continue;\n";
    emitSumsLoad(scene_, in, sums);  // codegen/RegisterSums.cpp
    emitDestinationValueLoads(scene_, w, pass, in);
  };
  // The calls of one pair, the values it shares computed once: `lanes`, d_idx's on the
  // pair's terms pd_ (added to its sums under the mask) and s_idx's on its sums gathered
  // (ps_, scattered back under the mask by the caller); else d_idx's on its sums (a
  // destination's neighbours in earlier blocks, OpenMP; the self pair).
  auto calls = [&](const std::string& body, bool lanes) {
    emitPairSharedLocals(scene_, body, d, pass.equations, pass.equations, /*simd=*/true);
    if (lanes) {
      scene_ << body << "double " << pdZeros << ";  // the pair's terms for d_idx\n";
      scene_ << body << "// s_idx's sums (in this block; a later block adds the pair in its (1))\n";
      scene_ << lines(psGathers, body);
    }
    for (const PlanEquation* eq : pass.equations)
      scene_ << body << pairCall(*eq, d, sums, /*scalarPairs=*/true, lanes ? "pd_" : "");
    if (lanes)
      for (const PlanEquation* eq : pass.equations)
        scene_ << body << simdMirroredCall(*eq, d, sums, "ps_");
    endPairShared();
    if (lanes) scene_ << lines(sumsOf, body);
  };
  // The destinations [begin, end) of a block (serial: one block, b_end = n).
  auto lanes = [&](const std::string& indent, const std::string& begin, const std::string& end) {
    head(indent, begin, end,
         skipsSelfPair(pass) ? "  // pairs (d_idx, s_idx > d_idx)" : "  // pairs (d_idx, s_idx >= d_idx)",
         "");
    const std::string in = indent + "  ", body = in + "  ";
    scene_ << in << "const std::uint32_t* k_lanes = kept.data() + " << lists
           << ".upper[d_idx];  // s_idx >= d_idx\n";
    if (skipsSelfPair(pass)) {  // every body adds zeros there (SymmetricPairs.cpp's skip)
      scene_ << in << "if (k_lanes != k_end && *k_lanes == static_cast<std::uint32_t>(d_idx)) "
                      "++k_lanes;  // the self pair: every body adds zeros there (sphc\n"
             << in << "// --no-self-pair-skip: evaluated; body/SelfPair.cpp)\n";
    } else {
      scene_ << in << "if (k_lanes != k_end && *k_lanes == static_cast<std::uint32_t>(d_idx)) {"
             << "  // the self pair, scalar: d_idx alone\n";
      scene_ << body << "++k_lanes;\n" << body << "const int s_idx = d_idx;\n";
      emitLanePairQuantities(scene_, q, false, body, true);
      scene_ << body << "if (in_support) {\n";
      calls(body + "  ", false);
      scene_ << body << "}\n" << in << "}\n";
    }
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
    emitLanePairQuantities(scene_, q, true, body, true);
    calls(body, true);
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
  scene_ << "        const int n_blocks = std::max(1, std::min(n, omp_get_max_threads()));\n";
  scene_ << "        #pragma omp parallel for schedule(static) default(firstprivate) shared(cells)\n";
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
  emitLanePairQuantities(scene_, q, false, body, true);
  scene_ << body << "if (!in_support) continue;\n";
  calls(body, false);
  scene_ << in << "}\n";
  emitSumsStore(scene_, in, sums);
  scene_ << ind << "}\n";
  scene_ << "          }\n";
  scene_ << "          // (2) the block, as the serial loop; its scatter kept to the block\n";
  lanes("          ", "b_begin", "b_end");
  scene_ << "        }\n";
}

}  // namespace sphc
