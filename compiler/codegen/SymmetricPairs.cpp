// Each pair once for both particles (codegen/SymmetricPairs.h): when a pair loop may, and
// how the CPU printer writes it.
//
// Why it is the same bit for bit. Today destination i gathers over its kept list (increasing
// source index): its sums receive the bodies' contributions in increasing source order. Here
// the outer loop takes i in increasing order and, for each neighbour j >= i of i's list,
// computes the pair quantities once and calls the bodies for (d = i, s = j), then, unless
// j == i, for (d = j, s = i). Particle j thus receives the contributions of every i < j in
// increasing i (at their turns), then its own and those of every k > j in increasing k (at
// its turn): today's order. The mirrored quantities are today's values of (d = j, s = i):
// XJI = x_j - x_i and VJI are computed as differences (so that a zero keeps today's sign);
// R2IJ, RIJ, HIJ = 0.5 (h_i + h_j), WIJ, RHOIJ, RHOIJ1 and EPS are symmetric expressions
// (IEEE addition and multiplication commute); WI and WJ swap; the gradients are s * XIJ with a
// factor s of (RIJ, h) only, computed once for both (Kernel::gradient_pair). The conditions
// (symmetricPairsRefusal): the bodies write only d_ properties at d_idx, read no s_ property
// and the pair quantities no property the pass writes (so that what they read of the other
// particle is what it was before the pass), index nothing but d_idx and s_idx, and no
// loop_all needs the neighbour list; every initialize ran for all particles before the pass
// (the CPU printer's destination loops: initialize, then the passes).
#include "codegen/SymmetricPairs.h"

#include "analysis/PairQuantityTable.h"
#include "codegen/CppText.h"
#include "codegen/Printer.h"

#include <algorithm>

namespace sphc {

namespace {

const PlanBody& loopBody(const Plan& plan, const PlanEquation& eq) {
  return plan.bodies[plan.equationDecls[eq.declIndex].methods.at(ast::Method::Loop)];
}

// The index text of a property site `d_NAME[ index ]`, trimmed.
std::string siteIndex(const BodySource& src, const PropSite& site) {
  std::string t = src.text.substr(site.begin, site.end - site.begin);
  size_t open = t.find('['), close = t.rfind(']');
  if (open == std::string::npos || close == std::string::npos || close < open) return "";
  std::string idx = t.substr(open + 1, close - open - 1);
  idx.erase(0, idx.find_first_not_of(" \t\n"));
  idx.erase(idx.find_last_not_of(" \t\n") + 1);
  return idx;
}

// The name of a pair quantity for the mirrored call (destination j, source i).
std::string mirrored(const std::string& q) {
  if (q == "WI") return "WJ";
  if (q == "WJ") return "WI";
  const PairQuantity* pq = findPairQuantity(q);
  if (pq && (pq->form == PairForm::Difference || pq->form == PairForm::Gradient))
    return q + "_ji";
  return q;  // symmetric in i and j
}

// The pair quantities the pass computes: q, with WI and WJ, DWI and DWJ together (each is the
// other's mirror).
std::set<std::string> withMirrors(std::set<std::string> q) {
  if (q.count("WI") || q.count("WJ")) q.insert({"WI", "WJ"});
  if (q.count("DWI") || q.count("DWJ")) q.insert({"DWI", "DWJ"});
  return q;
}

// symmetricPairsRefusal without the same-array condition: what the bodies and the pass of
// w must be for a pair's mirrored call (also for a pair loop of two arrays, crossPairsRefusal).
std::string pairBodiesRefusal(const Plan& plan, const DestinationWork& w,
                              const NeighbourPass& pass, bool listsKept) {
  if (!listsKept) return "no lists kept in index order here (--verlet-skin off)";
  if (w.ranged()) return "the group has start_idx or stop_idx";
  if (w.onGhosts) return "the group runs on the ghosts";
  if (!pass.loopAll.empty()) return pass.loopAll[0]->name + " has a loop_all (NBRS)";
  if (pass.equations.empty()) return "no loop body";
  if (pass.order != LoopOrder::Parallel) return "the schedule runs the pass in particle order";
  const PlanArray& A = plan.arrays[w.array];
  auto isConstant = [&](const std::string& p) {
    return std::find(A.constants.begin(), A.constants.end(), p) != A.constants.end();
  };
  std::map<std::string, std::string> writer;  // property -> the first equation writing it
  for (const PlanEquation* eq : pass.equations)
    for (const PropAccess& a : loopBody(plan, *eq).facts.dWrites) writer.emplace(a.prop, eq->name);
  for (const std::string& p : pass.shared)
    if (writer.count(p))
      return writer[p] + " writes d_" + p + ", which the pair quantities read";
  for (const PlanEquation* eq : pass.equations) {
    const PlanBody& b = loopBody(plan, *eq);
    if (!b.facts.statesWritten.empty())
      return eq->name + " writes its state " + *b.facts.statesWritten.begin();
    for (const std::string& q : b.facts.pairQuantities)
      if (!findPairQuantity(q)) return eq->name + " uses " + q + ", which has no mirror";
    for (const PropSite& site : b.facts.sites) {
      const std::string name = (site.source ? "s_" : "d_") + site.prop;
      if (site.write && site.source) return eq->name + " writes " + name;
      if (!site.source && isConstant(site.prop)) {
        if (site.write) return eq->name + " writes the constant " + name;
        continue;  // read: the same for every particle
      }
      const std::string idx = siteIndex(b.source, site);
      if (idx != (site.source ? "s_idx" : "d_idx"))
        return eq->name + " indexes " + name + " with `" + idx + "`";
      if (site.source && writer.count(site.prop))
        return eq->name + " reads " + name + ", which " + writer[site.prop] +
               " writes in the pass";
    }
  }
  return "";
}

}  // namespace

std::string mirroredPairQuantity(const std::string& q) { return mirrored(q); }

std::string symmetricPairsRefusal(const Plan& plan, const DestinationWork& w,
                                  const NeighbourPass& pass, bool listsKept) {
  if (pass.source != w.array) return "the source is another array";
  return pairBodiesRefusal(plan, w, pass, listsKept);
}

std::string crossPairsRefusal(const Plan& plan, const Phase& ph, size_t a, size_t b,
                              bool listsKept) {
  const DestinationWork& A = ph.destinations[a];
  const DestinationWork& B = ph.destinations[b];
  const std::string& nameA = plan.arrays[A.array].name;
  const std::string& nameB = plan.arrays[B.array].name;
  if (b != a + 1) return nameB + " is not the destination after " + nameA + " in the phase";
  const NeighbourPass& ab = A.passes.back();
  const NeighbourPass& ba = B.passes.front();
  if (ab.source != B.array) return nameA + " <- " + nameB + " is not " + nameA + "'s last pair loop";
  if (ba.source != A.array) return nameB + " <- " + nameA + " is not " + nameB + "'s first pair loop";
  if (!A.postLoop.empty() || !A.reductions.empty() || !A.hostReduce.empty() ||
      !A.ghostRefresh.empty())
    return nameA + " has work after its pair loops (post_loop, a reduction, ghosts to refresh)";
  if (!ab.initializePair.empty() || !ba.initializePair.empty()) return "an initialize_pair";
  for (const auto& [w, pass] : {std::pair{&A, &ab}, std::pair{&B, &ba}}) {
    const std::string why = pairBodiesRefusal(plan, *w, *pass, listsKept);
    if (!why.empty())
      return plan.arrays[w->array].name + " <- " + plan.arrays[pass->source].name + ": " + why;
  }
  // What each loop reads of the other's destination (its source properties, those of its
  // pair quantities) must not change during the pass: today it is read before (A <- B) or
  // after (B <- A) the other loop.
  auto reads = [](const NeighbourPass& p) {
    std::set<std::string> r = p.sourceProps;
    r.insert(p.shared.begin(), p.shared.end());
    return r;
  };
  auto writes = [&](const NeighbourPass& p, const PlanEquation*& who, const std::string& prop) {
    for (const PlanEquation* eq : p.equations)
      for (const PropAccess& w : loopBody(plan, *eq).facts.dWrites)
        if (w.prop == prop) return who = eq, true;
    return false;
  };
  const PlanEquation* who = nullptr;
  for (const std::string& p : reads(ab))
    if (writes(ba, who, p))
      return who->name + " writes " + nameB + "." + p + ", which " + nameA + " <- " + nameB +
             " reads";
  for (const std::string& p : reads(ba))
    if (writes(ab, who, p))
      return who->name + " writes " + nameA + "." + p + ", which " + nameB + " <- " + nameA +
             " reads";
  // B's initialize runs before the pass, today after A <- B.
  for (const PlanEquation* eq : B.initialize) {
    const auto& methods = plan.equationDecls[eq->declIndex].methods;
    for (const PropAccess& w : plan.bodies[methods.at(ast::Method::Initialize)].facts.dWrites)
      if (reads(ab).count(w.prop))
        return eq->name + "'s initialize writes " + nameB + "." + w.prop + ", which " + nameA +
               " <- " + nameB + " reads before it";
  }
  return "";
}

std::vector<std::string> symmetricPairsNotes(
    const Schedule& sched, const EmitOptions& opts,
    const std::function<bool(const DestinationWork&, const NeighbourPass&)>& inLanes) {
  const std::string lanes = "--simd-pairs puts its neighbours in SIMD lanes per destination";
  std::vector<std::string> notes;
  const Plan& plan = *sched.plan;
  // The CPU printer keeps lists where --verlet-skin is on for it (CpuPrinter's verlet()), in
  // double and single precision (until stop 37 this note said per destination for every
  // single-precision loop, while the printer evaluated them each pair once).
  const bool listsKept = opts.verletSkin > 0 && opts.backend != Backend::OpenCL &&
                         !sched.distribution.enabled && plan.zones.empty();
  const bool single = opts.precision == Precision::Single;
  walkPasses(sched.equations, [&](const Phase& ph, const DestinationWork& w,
                                  const NeighbourPass& pass) {
    if (pass.source != w.array || !pass.searches()) return;
    const std::string loop = plan.arrays[w.array].name + " <- " + plan.arrays[pass.source].name +
                             " in " + ph.name;
    std::string why = opts.symmetricPairs ? symmetricPairsRefusal(plan, w, pass, listsKept)
                                          : "--no-symmetric-pairs";
    // Ghosts of periodic or mirror sides are sources only: a pair with a ghost is evaluated
    // for the real particle alone (its original has the pair through the other's image).
    // Written for the scalar loops of double precision (CpuPrinter::symmetricPass).
    if (why.empty() && inLanes && inLanes(w, pass)) why = lanes;
    if (why.empty() && sched.domain && single)
      why = "single precision with periodic or mirror ghosts (each pair once with them is "
            "written for double)";
    if (opts.backend == Backend::OpenCL) why = "the OpenCL backend gathers per destination";
    notes.push_back(why.empty() ? "each pair once for both particles: " + loop +
                                      (sched.domain ? " (a pair with a periodic or mirror ghost "
                                                      "for the real particle only)"
                                                    : "")
                                : "pairs per destination particle: " + loop + ": " + why);
  });
  // Pair loops of two arrays, A <- B and B <- A in one phase.
  walkPhases(sched.equations, [&](const Phase& ph) {
    for (size_t a = 0; a < ph.destinations.size(); ++a)
      for (size_t b = a + 1; b < ph.destinations.size(); ++b) {
        auto loopOver = [](const DestinationWork& w, int s) -> const NeighbourPass* {
          for (const NeighbourPass& p : w.passes)
            if (p.source == s && p.searches()) return &p;
          return nullptr;
        };
        const DestinationWork& A = ph.destinations[a];
        const DestinationWork& B = ph.destinations[b];
        const NeighbourPass* ab = loopOver(A, B.array);
        const NeighbourPass* ba = loopOver(B, A.array);
        if (A.array == B.array || !ab || !ba) continue;
        const std::string loop = plan.arrays[A.array].name + " <- " +
                                 plan.arrays[B.array].name + " with " +
                                 plan.arrays[B.array].name + " <- " +
                                 plan.arrays[A.array].name + " in " + ph.name;
        std::string why = opts.symmetricPairs ? crossPairsRefusal(plan, ph, a, b, listsKept)
                                              : "--no-symmetric-pairs";
        if (why.empty() && sched.domain) why = "the sources include periodic or mirror ghosts";
        if (why.empty() && inLanes && (inLanes(A, *ab) || inLanes(B, *ba)))
          why = "--simd-pairs puts the neighbours of " +
                plan.arrays[inLanes(A, *ab) ? A.array : B.array].name +
                " in SIMD lanes per destination";
        if (opts.backend == Backend::OpenCL) why = "the OpenCL backend gathers per destination";
        notes.push_back(why.empty() ? "each pair once for both particles: " + loop
                                    : "pairs per destination particle: " + loop + ": " + why);
      }
  });
  return notes;
}

// ---- The printer ----

std::function<std::string(const ScenePrinter::BodyParam&)> ScenePrinter::mirroredArgument(
    const PlanEquation& eq, const std::string& pointers) const {
  const std::string eqValues = eqStruct(eq);
  // callBody's arguments but for the swapped indices, the mirrored pair quantities and the
  // destination-only values of particle s_idx (a value of the parameters alone: the pass's).
  return [this, &eq, eqValues, pointers](const BodyParam& p) -> std::string {
    switch (p.kind) {
      case BodyParam::Idx: return "s_idx";
      case BodyParam::SIdx: return "d_idx";
      case BodyParam::Pair: return mirrored(p.name);
      case BodyParam::DHoisted: {
        const std::string once = passDestinationHoisted(eq, std::stoul(p.name));
        return once.empty() ? symmetricDestinationHoisted(eqValues, p.name) + "[s_idx]" : once;
      }
      case BodyParam::PairShared: {  // computed once for the pair (codegen/PairShared.cpp)
        auto it = pairSharedScope_.find(eqValues + "/" + p.name);
        if (it == pairSharedScope_.end()) return "";  // callBody: computed in the call
        return (it->second.sign < 0 ? "-" : "") + it->second.local;
      }
      case BodyParam::DProp: return pointers.empty() ? "" : pointers + "d_" + p.name;
      case BodyParam::SProp: return pointers.empty() ? "" : pointers + "s_" + p.name;
      case BodyParam::Nbrs:
      case BodyParam::NNbrs:
      case BodyParam::N: SPHC_INTERNAL("a pair loop body with NBRS or N");
      default: return "";
    }
  };
}

std::string ScenePrinter::callBodyMirrored(const PlanEquation& eq, int dest,
                                           const std::string& pointers) const {
  const PlanBody& b = methodBody(eq, ast::Method::Loop);
  return callBody(bodyFunctionName(eq.name, "loop"), b, dest, eqStruct(eq), "t", ".",
                  mirroredArgument(eq, pointers)) +
         ";  // " + eq.name + ", from " + loc(eq.loc) + ": destination s_idx, source d_idx\n";
}

void ScenePrinter::emitSymmetricMembers(std::ostream& os) const {
  forEachLoopBody([&](const PlanEquation& eq, const PlanBody& b) {
    const auto sites = hoistedDestinationSites(b, host_);
    for (size_t k = 0; k < sites.size(); ++k) {
      if (!passDestinationHoisted(eq, k).empty()) continue;  // a value of the parameters alone: the pass's
      os << "  std::vector<" << hoistedValueType(b, host_, false, k) << "> dhoist_" << eqStruct(eq)
         << "_" << k << ";  // " << eq.name
         << ": its loop's destination-only value " << k
         << " per particle (each pair once for both particles)\n";
    }
  });
}

// The kernel lanes (EmitOptions::kernelLanes; docs/performance-log.md, "Taylor-Green's kernel
// in SIMD lanes (stop 44)"). In a scalar each-pair-once loop a pair's kernel values wait for
// a chain of the square root, r / h, the shape's polynomial and, for the gradient, a second
// division; and the cut-off test's branch, taken for about one candidate in six within a
// list's skin, flushes what the core had started of the next pairs. So each destination's
// candidates of [first, end of its list) go first through a loop in SIMD lanes (a lambda
// compiled without jump threading, as the tiles: GCC 12 threads the shape's branches before
// if-conversion), which writes per candidate whether it is a neighbour (the test's own
// operands and comparison, negated: a NaN distance passes as in the scalar test) and its
// W(RIJ, HIJ) and the gradient's factor s (Kernel::gradient_factor, gradient()'s s bit for
// bit); then the positions of the neighbours among them, in the list's order (no branch),
// and the pair loops over those, their other pair quantities as before, DWIJ = s XIJ as
// gradient() and gradient_pair() compute it. Every value is the one the loop computed
// before (the same IEEE operations per candidate; -ffp-contract=off), the neighbours come in
// the same order: the same sums bit for bit. Where: the serial printer (the OpenMP blocks
// keep the kernel in the pair loop, so OpenMP = serial bitwise still holds), double
// precision, the kernel values of the pass WIJ and DWIJ only (not WI, WJ, DWI, DWJ), a kernel
// without exp (the Gaussians: a vector exp is not the scalar one's bits).
std::string ScenePrinter::kernelLanesRefusal(const std::set<std::string>& q, bool openmp) const {
  if (kernelLanes_ == "off") return "--kernel-lanes=off";
  if (openmp) return "the OpenMP blocks";
  if (singlePrecision_) return "single precision";
  if (plan_.kernel == "Gaussian" || plan_.kernel == "SuperGaussian")
    return "the kernel " + plan_.kernel + " calls exp";
  for (const char* k : {"WI", "WJ", "DWI", "DWJ"})
    if (q.count(k)) return std::string("the pass uses ") + k;
  if (!q.count("WIJ") && !q.count("DWIJ")) return "no kernel value in the pass";
  // auto: where measured to pay (stop 44): Taylor-Green (one array, periodic, the quintic
  // spline, W summed: its summation density, its shifting's sums), EDAC 0.90x and WCSPH 0.92x
  // of the serial CPU at nx = 100, 0.87x at nx = 50. Measured losing: the dam break 1.13x
  // (WendlandQuintic, walls, no domain; `--simd-pairs=off`), poiseuille 1.07x and the cavity
  // 1.03x (walls), heat_conduction 1.05x (periodic and the quintic spline, no W summed: its
  // one pass a gradient), square_droplet 1.02x (WendlandQuintic).
  if (kernelLanes_ == "auto") {
    bool sumsW = false;
    forEachLoopBody([&](const PlanEquation&, const PlanBody& b) {
      sumsW = sumsW || b.facts.pairQuantities.count("WIJ");
    });
    if (!(hasDomain() && plan_.arrays.size() == 1 && plan_.kernel == "QuinticSpline" && sumsW))
      return "--kernel-lanes=auto: only a scene of one array in a periodic or mirror domain, "
             "with the quintic spline and a pair loop that uses WIJ (measured to pay there)";
  }
  return "";
}

void ScenePrinter::emitSymmetricPass(const DestinationWork& w, const NeighbourPass& pass,
                                     const std::string& lists, bool openmp,
                                     const std::string& listRadius2) {
  const int d = w.array;
  const std::set<std::string> q = withMirrors(pass.pairQuantities);
  const std::string pragma = openmp ? "        #pragma omp parallel for schedule(static) "
                                      "default(firstprivate) shared(cells)\n"
                                    : "";
  const bool simd = onceLanes(w, pass);  // --simd-pairs=once (SimdPairs.cpp)
  // --simd-pairs=cluster: in cluster-pair tiles where they can (ClusterPairs.cpp).
  const std::string clusterWhy = simd ? clusterTilesRefusal(w, pass) : "off";
  if (clusterWhy.empty())
    return emitClusterTiles(w, pass, lists, listRadius2, q, registerSums(w, pass), openmp);
  if (clusterWhy != "off")
    scene_ << "        // Not in cluster-pair tiles (codegen/ClusterPairs.cpp): " << clusterWhy << ".\n";
  if (simd)
    scene_ << "        // Each pair once for both particles in SIMD lanes (codegen/SimdPairs.cpp;\n"
              "        // sphc --simd-pairs=once): the sums reassociated across the lanes.\n";
  else
    scene_ << "        // Each pair once for both particles (codegen/SymmetricPairs.cpp; sphc\n"
              "        // --no-symmetric-pairs: per destination particle): the same sums bit for bit.\n";
  // The kept lists first, all of them: a pair is visited from its lower particle's list.
  emitKeptListsBuild(lists, openmp, listRadius2);
  // Where s_idx >= d_idx starts in each kept list: once per build (whichever loop built).
  scene_ << "        if (" << lists << ".upper.empty()) {  // after a build: where s_idx >= d_idx "
            "starts in each kept list\n";
  scene_ << "          " << lists << ".upper.resize(n);\n" << (openmp ? "  " + pragma : "");
  scene_ << "          for (int d_idx = 0; d_idx < n; ++d_idx) " << lists
         << ".upper[d_idx] = sphc::upper_start(" << lists << ".lists[d_idx], d_idx);\n";
  scene_ << "        }\n";
  // The destination-only values of every particle, for the mirrored calls.
  emitDestinationHoistedAll(pass, pragma);
  const RegisterSums sums = registerSums(w, pass);
  if (simd) return emitSymmetricSimdLoops(w, pass, lists, openmp, q, sums);
  const bool lanes = kernelLanesRefusal(q, openmp).empty();
  if (lanes) {
    const char* ax[3] = {"x", "y", "z"};
    std::string ptrs;
    for (int k = 0; k < plan_.dim; ++k) ptrs += std::string("const double* const sj_") + ax[k] + ", ";
    scene_ << "        // The kernel in SIMD lanes first (codegen/SymmetricPairs.cpp, kernelLanesRefusal;\n"
              "        // sphc --kernel-lanes=off: in the pair loop): per candidate of a destination's list,\n"
              "        // whether it is a neighbour, its W and its gradient's factor; then the bodies over\n"
              "        // the neighbours among them in the list's order. The same values bit for bit.\n";
    scene_ << "        std::vector<int> kl_in_v(64), kl_c_v(64);\n";
    scene_ << "        std::vector<double> kl_w_v(64), kl_s_v(64);\n";
    scene_ << "#if defined(__GNUC__) && !defined(__clang__)\n"
              "#define SPHC_KERNEL_LANES_OPTIMIZE __attribute__((optimize(\"no-thread-jumps\")))\n"
              "#else\n"
              "#define SPHC_KERNEL_LANES_OPTIMIZE\n"
              "#endif\n";
    // h uniform on both sides (stop 45): the pass's values as arguments (kl_hj, kl_cut2,
    // kl_HIJ, kl_ihd: a lambda without captures), no h per candidate.
    const bool klUniform = uhI_ && uhJ_;
    scene_ << "        auto kernel_lanes = [](const std::uint32_t* const kb, const int k_count, "
              "const double xi, const double yi, const double zi, const double hi, " << ptrs
           << "const double* const sj_h, int* const kl_in, double* const kl_w, double* const kl_s"
           << (klUniform ? ", const double kl_hj, const double kl_cut2, const double kl_HIJ, const double kl_ihd" : "")
           << ") SPHC_KERNEL_LANES_OPTIMIZE {\n";
    if (klUniform) scene_ << "          (void)hi; (void)sj_h;  // h uniform: kl_hj, kl_cut2, kl_HIJ, kl_ihd\n";
    scene_ << "          (void)xi; (void)yi; (void)zi; (void)kl_w; (void)kl_s;\n";
    scene_ << "          #pragma omp simd\n";
    scene_ << "          for (int kl_k = 0; kl_k < k_count; ++kl_k) {\n";
    const std::string lb = "            ";
    scene_ << lb << "const int s_idx = static_cast<int>(kb[kl_k]);\n";
    // The neighbour test's operands and its comparison as a value (emitNeighbourTest skips
    // where R2IJ >= RADIUS2 * hmax * hmax).
    // (a lambda without captures: one side uniform, hj per candidate and hi its argument as
    // before stop 45; both, the arguments kl_NAME)
    const bool i = uhI_, j = uhJ_;
    const std::string prefix = uhPrefix_;
    uhI_ = uhJ_ = klUniform;
    uhPrefix_ = "kl_";
    emitTestOperands(scene_, host_, lb);
    if (!klUniform) scene_ << lb << "const double hmax = hi > hj ? hi : hj;\n";
    scene_ << lb << "kl_in[kl_k] = !(R2IJ >= " << cutoffValue("RADIUS2") << ") ? 1 : 0;  // a neighbour\n";
    scene_ << lb << "const double HIJ = " << (klUniform ? "kl_HIJ" : "0.5 * (hi + hj)") << ";\n";
    scene_ << lb << "const double RIJ = std::sqrt(R2IJ);\n";
    if (q.count("WIJ")) scene_ << lb << "kl_w[kl_k] = " << kernelCall("w", "RIJ, ", "HIJ", "") << ";\n";
    if (q.count("DWIJ"))
      scene_ << lb << "kl_s[kl_k] = " << kernelCall("gradient_factor", "RIJ, ", "HIJ", "") << ";\n";
    uhI_ = i;
    uhJ_ = j;
    uhPrefix_ = prefix;
    scene_ << "          }\n        };\n";
  }
  // One destination's neighbours in [from, to) of its kept list (sorted): the pair
  // quantities, the bodies for d_idx and, with `both`, for s_idx (unless the self pair).
  // With `tail` (OpenMP blocks), the rest of the list after `to` follows for d_idx alone, in
  // the same destination loop: d_idx's sums are complete but for these once its turn in the
  // block has come (later turns write only s_idx > their d_idx), so they come in the same
  // order as from a loop of their own after the block.
  struct Segment {
    std::string indent;
    std::string begin, end;  // the destinations d_idx in [begin, end)
    std::string from;        // the first entry of the list walked
    std::string to;          // appended to `k != k_end` (a bound on k); with tail the block's end
    bool both = true;        // the bodies for s_idx too (each pair once)
    std::string comment;     // after the destination loop's opening line
    bool tail = false;
    std::string skip;        // a condition under which d_idx has nothing in [from, to)
    bool skipSelf = false;   // from is where s_idx >= d_idx starts: past d_idx itself
  };
  // Periodic or mirror ghosts (kept with the lists, CpuPrinter's updateNeighboursKeptGhosts):
  // numbered after the n real particles, so they end each sorted list. A pair with a ghost
  // is evaluated for the real particle only, in the tail after the real neighbours (the
  // ghost's original gets the same pair from its own list, through the image of the real
  // particle): each particle's sums in its list's order, as per destination.
  const bool ghosts = hasDomain();
  const bool skipSelf = skipsSelfPair(pass);
  auto segment = [&](const Segment& sg) {
    const std::string& indent = sg.indent;
    const std::string& from = sg.from;
    const std::string& to = sg.to;
    const std::string& skip = sg.skip;
    const bool both = sg.both;
    scene_ << indent << "for (int d_idx = " << sg.begin << "; d_idx < " << sg.end << "; ++d_idx) {"
           << sg.comment << "\n";
    const std::string in = indent + "  ";
    std::ostringstream locals;
    emitDestLocals(locals, in, q, host_);
    scene_ << locals.str();
    // The destination-only values as they were before the pass (a body may write what they
    // read: at i's turn, i has already had the contributions of the particles before it).
    for (const PlanEquation* eq : pass.equations) {
      const PlanBody& b = methodBody(*eq, ast::Method::Loop);
      const auto sites = hoistedDestinationSites(b, host_);
      for (size_t k = 0; k < sites.size(); ++k) {
        const std::string K = std::to_string(k), once = passDestinationHoisted(*eq, k);
        scene_ << in << "const " << hoistedValueType(b, host_, false, k) << " "
               << hoistDestinationArgument(eqStruct(*eq), K) << " = "
               << (once.empty() ? symmetricDestinationHoisted(eqStruct(*eq), K) + "[d_idx]" : once)
               << ";\n";
      }
    }
    scene_ << in << "const std::vector<std::uint32_t>& kept = " << lists << ".lists[d_idx];\n";
    scene_ << in << "const std::uint32_t* const k_end = kept.data() + kept.size();\n";
    if (!skip.empty()) scene_ << in << "if (" << skip << ") continue;  // no neighbour in [from, to)\n";
    if (sg.skipSelf) {
      scene_ << in << "const std::uint32_t* k_first = " << from << ";\n";
      scene_ << in << "if (k_first != k_end && *k_first == static_cast<std::uint32_t>(d_idx)) "
                      "++k_first;  // the self pair: every body adds zeros there (sphc\n"
             << in << "// --no-self-pair-skip: evaluated; body/SelfPair.cpp)\n";
    }
    const std::string first = sg.skipSelf ? std::string("k_first") : from;
    emitSumsLoad(scene_, in, sums);  // codegen/RegisterSums.cpp
    const std::string body = in + "  ";
    // The mirrored calls: with the sums in locals, particle s_idx's too, for the pair's
    // calls (loaded before them, stored after: the same operations on the same values, but
    // the bodies' stores no longer alias what the next body reads, so the C++ compiler
    // computes the values they share, e.g. m / rho of s_idx, once for the pair).
    auto mirroredCalls = [&](const std::string& mb) {
      if (!sums.active()) {
        for (const PlanEquation* eq : pass.equations) scene_ << mb << callBodyMirrored(*eq, d);
        return;
      }
      scene_ << mb << "// s_idx's sums in locals for its calls (codegen/SymmetricPairs.cpp)\n";
      for (const auto& [p, sc] : sums.props)
        for (int k : sc.second)
          scene_ << mb << host_.real << " m_" << sumsLocalName(p, sc.first, k) << " = d_" << p
                 << "[" << sumsIndexText(sc.first, k, "s_idx") << "];\n";
      for (const PlanEquation* eq : pass.equations) {
        std::string call = pairCall(*eq, d, sums, false, "m_", mirroredArgument(*eq));
        call.insert(call.size() - 1, ": destination s_idx, source d_idx");
        scene_ << mb << call;
      }
      for (const auto& [p, sc] : sums.props)
        for (int k : sc.second)
          scene_ << mb << "d_" << p << "[" << sumsIndexText(sc.first, k, "s_idx") << "] = m_"
                 << sumsLocalName(p, sc.first, k) << ";\n";
    };
    // A pair's calls for d_idx, then (each pair once) the mirrored ones for s_idx, and the
    // close of the neighbour loop: the same in the kernel lanes' loop and the plain one.
    auto pairCallsAndClose = [&](bool bothSides) {
      if (bothSides) emitPairSharedLocals(scene_, body, d, pass.equations, pass.equations);
      for (const PlanEquation* eq : pass.equations) scene_ << body << pairCall(*eq, d, sums);
      if (bothSides && sg.skipSelf) {  // s_idx > d_idx: the self pair is not in the loop's range
        scene_ << body << "// the same pair for particle s_idx\n";
        mirroredCalls(body);
      } else if (bothSides) {
        scene_ << body << "if (s_idx != d_idx) {  // the same pair for particle s_idx\n";
        mirroredCalls(body + "  ");
        scene_ << body << "}\n";
      }
      endPairShared();
      scene_ << in << "}\n";
    };
    if (lanes) {  // serial: the segment `all` (kernelLanesRefusal)
      const char* ax[3] = {"x", "y", "z"};
      std::string ptrs;
      for (int k = 0; k < plan_.dim; ++k) ptrs += std::string("sj_") + ax[k] + ", ";
      scene_ << in << "const std::uint32_t* const k_lanes = " << first << ";\n";
      scene_ << in << "const int k_count = static_cast<int>(k_end - k_lanes);\n";
      scene_ << in << "if (kl_in_v.size() < static_cast<std::size_t>(k_count)) {\n"
             << in << "  kl_in_v.resize(2 * k_count + 64);\n"
             << in << "  kl_c_v.resize(2 * k_count + 64);\n"
             << in << "  kl_w_v.resize(2 * k_count + 64);\n"
             << in << "  kl_s_v.resize(2 * k_count + 64);\n"
             << in << "}\n";
      scene_ << in << "int* const kl_c = kl_c_v.data();\n";
      scene_ << in << "const int* const kl_in = kl_in_v.data();\n";
      scene_ << in << "const double* const kl_w = kl_w_v.data();\n";
      scene_ << in << "const double* const kl_s = kl_s_v.data();\n";
      scene_ << in << "(void)kl_w; (void)kl_s;\n";
      scene_ << in << "kernel_lanes(k_lanes, k_count, xi, yi, zi, hi, " << ptrs
             << "sj_h, kl_in_v.data(), kl_w_v.data(), kl_s_v.data()"
             << (uhI_ && uhJ_ ? ", uh_hj, uh_cut2, uh_HIJ, uh_ihd" : "") << ");\n";
      if (sg.tail)
        scene_ << in << "const int k_mid = k_count == 0 || k_lanes[k_count - 1] < static_cast<std::uint32_t>("
               << to << ")\n"
               << in << "    ? k_count : static_cast<int>(std::lower_bound(k_lanes, k_end, "
                        "static_cast<std::uint32_t>(" << to << ")) - k_lanes);\n";
      else
        scene_ << in << "const int k_mid = k_count;\n";
      scene_ << in << "// the neighbours' positions in the list, in its order (no branch)\n";
      scene_ << in << "int e_n = 0;\n";
      scene_ << in << "for (int kl_k = 0; kl_k < k_mid; ++kl_k) {\n"
             << in << "  kl_c[e_n] = kl_k;\n" << in << "  e_n += kl_in[kl_k];\n" << in << "}\n";
      scene_ << in << "const int e_mid = e_n;\n";
      if (sg.tail)
        scene_ << in << "for (int kl_k = k_mid; kl_k < k_count; ++kl_k) {\n"
               << in << "  kl_c[e_n] = kl_k;\n" << in << "  e_n += kl_in[kl_k];\n" << in << "}\n";
      auto lanePairs = [&](bool bothSides, const std::string& range, const std::string& note) {
        scene_ << in << "for (int e = " << range << "; ++e) {" << note << "\n";
        scene_ << body << "const int kl_k = kl_c[e];\n";
        scene_ << body << "const int s_idx = static_cast<int>(k_lanes[kl_k]);\n";
        emitTestOperands(scene_, host_, body);
        emitPairQuantitiesOnce(q, bothSides, body, true);
        pairCallsAndClose(bothSides);
      };
      lanePairs(sg.both, "0; e < e_mid", "");
      if (sg.tail) lanePairs(false, "e_mid; e < e_n", "  // the ghosts: d_idx only");
      emitSumsStore(scene_, in, sums);
      scene_ << indent << "}\n";
      return;
    }
    auto pairs = [&](bool bothSides) {
      scene_ << body << "const int s_idx = static_cast<int>(*k);\n";
      emitNeighbourTest(scene_, host_, "continue;", body);
      emitPairQuantitiesOnce(q, bothSides, body);
      pairCallsAndClose(bothSides);
    };
    if (!sg.tail) {
      scene_ << in << "for (const std::uint32_t* k = " << first << "; k != k_end" << to
             << "; ++k) {\n";
      pairs(both);
    } else {
      // `to` is the block's end: where the list passes it (found once; the last block's
      // lists end there).
      scene_ << in << "const std::uint32_t* k = " << first << ";\n";
      scene_ << in << "const std::uint32_t* const k_mid = "
             << (ghosts ? std::string() : to + " == n || ") << "k == k_end || "
             << "k_end[-1] < static_cast<std::uint32_t>(" << to << ")\n"
             << in << "    ? k_end : std::lower_bound(k, k_end, static_cast<std::uint32_t>(" << to
             << "));\n";
      scene_ << in << "for (; k != k_mid; ++k) {\n";
      pairs(both);
      scene_ << in << "for (; k != k_end; ++k) {  // "
             << (openmp ? "(3) the neighbours in later blocks" : "the ghosts")
             << (openmp && ghosts ? " and the ghosts" : "") << ": d_idx only\n";
      pairs(false);
    }
    emitSumsStore(scene_, in, sums);
    scene_ << indent << "}\n";
  };
  const std::string upper = "kept.data() + " + lists + ".upper[d_idx]";  // s_idx >= d_idx
  if (!openmp) {
    Segment all{"        ", "0", "n", upper};
    all.comment = skipSelf ? "  // pairs (d_idx, s_idx > d_idx)" : "  // pairs (d_idx, s_idx >= d_idx)";
    all.skipSelf = skipSelf;
    if (ghosts) {  // the real neighbours each pair once, then the ghosts for d_idx only
      all.to = "n";
      all.tail = true;
    }
    segment(all);
    return;
  }
  // OpenMP: contiguous blocks, one per thread; each particle's contributions in the serial
  // order whatever the blocks.
  scene_ << "        const int n_blocks = std::max(1, std::min(n, omp_get_max_threads()));\n";
  scene_ << pragma;
  scene_ << "        for (int blk = 0; blk < n_blocks; ++blk) {\n";
  scene_ << "          const int b_begin = static_cast<int>(static_cast<long>(n) * blk / n_blocks);\n";
  scene_ << "          const int b_end = static_cast<int>(static_cast<long>(n) * (blk + 1) / n_blocks);\n";
  scene_ << "          // (1) from the neighbours in earlier blocks, per destination (none in the first)\n";
  scene_ << "          if (b_begin > 0) {\n";
  Segment earlier{"            ", "b_begin", "b_end", "kept.data()"};
  earlier.to = " && *k < static_cast<std::uint32_t>(b_begin)";
  earlier.both = false;
  earlier.skip = "k_end == kept.data() || kept.front() >= static_cast<std::uint32_t>(b_begin)";
  segment(earlier);
  scene_ << "          }\n";
  scene_ << "          // (2) the pairs within the block, once for both particles, then (3) from the\n"
            "          // neighbours in later blocks, per destination, in the same loop\n";
  Segment block{"          ", "b_begin", "b_end", upper};
  block.to = "b_end";
  block.tail = true;
  block.skipSelf = skipSelf;
  segment(block);
  scene_ << "        }\n";
}

bool ScenePrinter::skipsSelfPair(const NeighbourPass& pass) const {
  if (!skipSelfPairs_ || pass.equations.empty()) return false;
  for (const PlanEquation* eq : pass.equations)
    if (!loopBody(plan_, *eq).facts.vanishesOnSelfPair) return false;
  return true;
}

void ScenePrinter::emitKeptListsBuild(const std::string& lists, bool openmp,
                                      const std::string& listRadius2) {
  const std::string thread = openmp ? "omp_get_thread_num()" : "0";
  const std::string pragma = openmp ? "        #pragma omp parallel for schedule(static) "
                                      "default(firstprivate) shared(cells)\n"
                                    : "";
  scene_ << "        nbrs_lists.resize(std::max<std::size_t>(nbrs_lists.size(), "
         << (openmp ? "omp_get_max_threads()" : "1") << "));\n";
  scene_ << "        if (verlet_build) {\n";
  scene_ << (openmp ? "  " + pragma : "");
  scene_ << "          for (int d_idx = 0; d_idx < n; ++d_idx) {\n";
  emitDestLocals(scene_, "            ", {}, host_);
  scene_ << "            std::vector<std::uint32_t>& nbrs_list = nbrs_lists[" << thread << "];\n";
  scene_ << "            const std::size_t n_kept = cells.gather_neighbours(xi, yi, zi, "
            "nbrs_list, [&](std::uint32_t j) {\n";
  scene_ << "              const int s_idx = static_cast<int>(j);\n";
  emitNeighbourTest(scene_, host_, "return false;", "              ", listRadius2);
  scene_ << "              return true;\n            });\n";
  scene_ << "            sphc::keep_in_index_order(" << lists
         << ".lists[d_idx], nbrs_list.data(), n_kept);\n";
  scene_ << "          }\n        }\n";
}

void ScenePrinter::emitDestinationHoistedAll(const NeighbourPass& pass, const std::string& pragma,
                                             const std::string& space) {
  std::vector<std::string> fills;
  // The same value as an earlier equation's of the pass: its array (Hoist.cpp).
  const SameHoisted sameAs = sameDestinationHoisted(pass);
  for (const PlanEquation* eq : pass.equations) {
    const PlanBody& b = methodBody(*eq, ast::Method::Loop);
    const auto sites = hoistedDestinationSites(b, host_);
    for (size_t k = 0; k < sites.size(); ++k) {
      const std::string K = std::to_string(k), E = eqStruct(*eq);
      const std::string ptr = symmetricDestinationHoisted(E, K);
      if (!passDestinationHoisted(*eq, k).empty()) continue;  // the pass's value (stop 46)
      const auto same = sameAs.find({eq, k});
      if (same != sameAs.end()) {
        scene_ << "        " << hoistedValueType(b, host_, false, k) << "* const " << ptr
               << " = " << symmetricDestinationHoisted(same->second.first, same->second.second)
               << ";  // " << eq->name << ": the same value, computed above\n";
        continue;
      }
      scene_ << "        dhoist_" << E << "_" << K << ".resize(n);\n";
      scene_ << "        " << hoistedValueType(b, host_, false, k) << "* const " << ptr
             << " = dhoist_" << E << "_" << K << ".data();\n";
      fills.push_back(E + "_" + K);
    }
  }
  if (!fills.empty()) {
    std::ostringstream loop;  // kept for one region where a queue is open (OmpRegions.cpp)
    loop << "        for (int d_idx = 0; d_idx < n; ++d_idx) {\n";
    emitDestinationHoisted(loop, pass, "          ");
    for (const PlanEquation* eq : pass.equations) {
      const auto sites = hoistedDestinationSites(methodBody(*eq, ast::Method::Loop), host_);
      for (size_t k = 0; k < sites.size(); ++k) {
        const std::string K = std::to_string(k);
        if (sameAs.count({eq, k}) || !passDestinationHoisted(*eq, k).empty()) continue;  // filled above; the pass's
        loop << "          " << symmetricDestinationHoisted(eqStruct(*eq), K) << "[d_idx] = "
             << hoistDestinationArgument(eqStruct(*eq), K) << ";\n";
      }
    }
    loop << "        }\n";
    ompLoop(scene_, pragma, loop.str(), space);
  }
}

void ScenePrinter::emitPairQuantitiesOnce(const std::set<std::string>& q, bool both,
                                          const std::string& body, bool lanes) {
  const PairDialect dialect = pairDialectOf(host_);
  auto difference = [&](const PairQuantity& pq, bool mirror) {
    scene_ << body << "const " << dialect.real << " " << pq.name << (mirror ? "_ji" : "") << "[3] = {";
    for (int c = 0; c < 3; ++c) {
      scene_ << (c ? ", " : "");
      if (c >= plan_.dim)
        scene_ << "0.0" << dialect.literalSuffix;
      else if (mirror)
        scene_ << "sj_" << pq.components[c] << "[s_idx] - " << pq.components[c] << "i";
      else
        scene_ << pq.components[c] << "i - sj_" << pq.components[c] << "[s_idx]";
    }
    scene_ << "};\n";
  };
  if (both) difference(*findPairQuantity("XIJ"), true);
  for (const PairQuantity& pq : pairQuantityTable()) {
    if (!(pq.when == PairWhen::EveryNeighbour || (pq.when == PairWhen::IfUsed && q.count(pq.name))))
      continue;
    if (lanes && pq.name == "WIJ") {  // the kernel lanes' value (kernelLanesRefusal)
      scene_ << body << "const " << dialect.real << " WIJ = kl_w[kl_k];\n";
      continue;
    }
    if (lanes && pq.name == "DWIJ") {  // s XIJ with the lanes' factor s: gradient()'s values
      scene_ << body << "const " << dialect.real << " kl_sf = kl_s[kl_k];\n";
      for (const char* side : both ? std::vector<const char*>{"", "_ji"} : std::vector<const char*>{""})
        scene_ << body << dialect.real << " DWIJ" << side << "[3] = {kl_sf * XIJ" << side
               << "[0], kl_sf * XIJ" << side << "[1], kl_sf * XIJ" << side << "[2]};\n";
      continue;
    }
    if (both && pq.form == PairForm::Difference) {
      difference(pq, false);
      difference(pq, true);
    } else if (both && pq.form == PairForm::Gradient) {
      // grad_j of the mirrored call: DWIJ -> DWIJ_ji (same h), DWI (h_i) -> DWJ_ji, DWJ
      // (h_j) -> DWI_ji.
      const std::string partner =
          pq.name == "DWI" ? "DWJ_ji" : pq.name == "DWJ" ? "DWI_ji" : pq.name + "_ji";
      scene_ << body << dialect.real << " " << pq.name << "[3], " << partner << "[3];\n";
      scene_ << body << kernelCall("gradient_pair", "XIJ, XIJ_ji, RIJ, ", pq.h,
                                   ", " + pq.name + ", " + partner) << ";\n";
    } else {
      scene_ << pairStatement(pq, dialect, body);
    }
  }
}

void ScenePrinter::emitCrossPass(const DestinationWork& A, const NeighbourPass& ab,
                                 const DestinationWork& B, const NeighbourPass& ba,
                                 const std::string& lists, const std::string& listRadius2,
                                 const std::function<void()>& listsCheck,
                                 const std::string& hoistPragma) {
  const bool openmp = !hoistPragma.empty();
  const std::string& nameA = arr(A.array).name;
  const std::string& nameB = arr(B.array).name;
  std::set<std::string> q = ab.pairQuantities;
  q.insert(ba.pairQuantities.begin(), ba.pairQuantities.end());
  q = withMirrors(q);
  std::set<std::string> shared = ab.shared;
  shared.insert(ba.shared.begin(), ba.shared.end());
  scene_ << "      {  // neighbours: " << nameA << " <- " << nameB << " with " << nameB << " <- "
         << nameA << ", each pair once for both particles\n";
  scene_ << "        // (codegen/SymmetricPairs.cpp; sphc --no-symmetric-pairs: a pass per destination\n"
            "        // array): the same sums bit for bit. First what the calls for " << nameB
         << " <- " << nameA << " take:\n"
            "        // " << nameA << "'s properties and source-only values, the destination-only "
            "values of every\n        // " << nameB << " particle, its pointers (mirror_).\n";
  for (const auto& p : ba.sourceProps)
    scene_ << "        const " << hostType(A.array, p) << "* s_" << p << " = "
           << propPtr(A.array, p) << ";\n";
  emitHoistedValues(scene_, ba, nameA + ".n", hoistPragma);
  emitDestinationHoistedAll(ba, openmp ? "        #pragma omp parallel for schedule(static)\n" : "");
  std::set<std::string> dprops;  // of B, in the bodies of B <- A
  for (const PlanEquation* eq : ba.equations)
    for (const BodyParam& p : bodyParams(methodBody(*eq, ast::Method::Loop), B.array, host_))
      if (p.kind == BodyParam::DProp) dprops.insert(p.name);
  for (const auto& p : dprops) scene_ << "        auto* const mirror_d_" << p << " = d_" << p << ";\n";
  for (const auto& p : ba.sourceProps)
    scene_ << "        auto* const mirror_s_" << p << " = s_" << p << ";\n";
  scene_ << "        {  // " << nameA << " <- " << nameB << ": d_idx a particle of " << nameA
         << ", s_idx of " << nameB << "\n";
  scene_ << "        const int n = static_cast<int>(" << nameA << ".n);\n";
  for (const auto& p : A.destProps)
    scene_ << "        " << hostType(A.array, p) << "* d_" << p << " = " << propPtr(A.array, p)
           << ";\n";
  for (const auto& p : shared) {
    scene_ << "        const " << host_.real << "* di_" << p << " = " << propPtr(A.array, p) << ";\n";
    scene_ << "        const " << host_.real << "* sj_" << p << " = " << propPtr(B.array, p) << ";\n";
  }
  if (shared.count("h")) beginUniformH(A.array, B.array, "        ");  // (stop 45; d_idx of A)
  for (const auto& p : ab.sourceProps)
    scene_ << "        const " << hostType(B.array, p) << "* s_" << p << " = "
           << propPtr(B.array, p) << ";\n";
  emitHoistedValues(scene_, ab, nameB + ".n", hoistPragma);
  scene_ << "        const sphc::CellList& cells = cells_" << nameB << ";\n";
  listsCheck();
  emitKeptListsBuild(lists, openmp, listRadius2);
  const bool occupied = occupiedRefusal(A, ab).empty();
  if (occupied) {
    scene_ << "        // Only " << nameA << "'s particles with a candidate (occupiedRefusal; "
              "sphc --no-skip-empty-lists:\n"
              "        // every one): found once per build of the lists.\n";
    scene_ << "        if (!" << lists << ".occupied_found) sphc::find_occupied(" << lists << ");\n";
    scene_ << "        const std::uint32_t* const occ = " << lists << ".occupied.data();\n";
    scene_ << "        const int n_occ = static_cast<int>(" << lists << ".occupied.size());\n";
  }
  if (openmp) emitCrossBlocksHead(lists, nameA, nameB);
  // OpenMP: blocks of A's particles (emitCrossBlocksHead), two spaces further in.
  const std::string in = openmp ? "  " : "";
  if (occupied) {
    if (openmp) {  // the block's: those in [b_begin, b_end)
      scene_ << in << "        const int v_begin = static_cast<int>(std::lower_bound(occ, occ + n_occ, u_begin) - occ);\n";
      scene_ << in << "        const int v_end = static_cast<int>(std::lower_bound(occ, occ + n_occ, u_end) - occ);\n";
    }
    scene_ << in << "        for (int v = " << (openmp ? "v_begin" : "0") << "; v < "
           << (openmp ? "v_end" : "n_occ") << "; ++v) {  // pairs (d_idx of " << nameA
           << ", s_idx of " << nameB << ")\n";
    scene_ << in << "          const int d_idx = static_cast<int>(occ[v]);\n";
  } else {
    scene_ << in << "        for (int d_idx = " << (openmp ? "b_begin" : "0") << "; d_idx < "
           << (openmp ? "b_end" : "n") << "; ++d_idx) {  // pairs (d_idx of " << nameA
           << ", s_idx of " << nameB << ")\n";
  }
  emitDestLocals(scene_, in + "          ", q, host_);
  emitDestinationHoisted(scene_, ab, in + "          ");
  scene_ << in << "          const std::vector<std::uint32_t>& kept = " << lists << ".lists[d_idx];\n";
  scene_ << in << "          const std::uint32_t* const k_end = kept.data() + kept.size();\n";
  const RegisterSums sums = registerSums(A, ab, &ba);  // codegen/RegisterSums.cpp
  emitSumsLoad(scene_, in + "          ", sums);
  scene_ << in << "          for (const std::uint32_t* k = kept.data(); k != k_end; ++k) {\n";
  const std::string body = in + "            ";
  scene_ << body << "const int s_idx = static_cast<int>(*k);\n";
  emitNeighbourTest(scene_, host_, "continue;", body);
  emitPairQuantitiesOnce(q, true, body);
  emitPairSharedLocals(scene_, body, A.array, ab.equations, ba.equations);
  for (const PlanEquation* eq : ab.equations) scene_ << body << pairCall(*eq, A.array, sums);
  if (openmp)
    scene_ << body << "if (by_source_first[s_idx] >= u_begin && by_source_last[s_idx] < u_end) {  "
              "// all of " << nameB << " s_idx's candidates in this block\n";
  for (const PlanEquation* eq : ba.equations)
    scene_ << body << (openmp ? "  " : "") << callBodyMirrored(*eq, B.array, "mirror_");
  if (openmp) scene_ << body << "}\n";
  endPairShared();
  scene_ << in << "          }\n";
  emitSumsStore(scene_, in + "          ", sums);
  scene_ << in << "        }\n";
  if (openmp) emitCrossSpanning(ba, B.array, q, lists, nameA, nameB);
  scene_ << "        }\n      }\n";
  endUniformH();
}

std::string ScenePrinter::occupiedRefusal(const DestinationWork& w,
                                         const NeighbourPass& pass) const {
  if (!skipEmptyLists_) return "--no-skip-empty-lists";
  if (w.array == pass.source) return "one array (every particle has candidates)";
  return "";
}

void ScenePrinter::emitOccupiedHead(const std::string& lists, const std::string& begin,
                                    const std::string& end, const std::string& pragma) {
  const bool zero = begin == "0";
  scene_ << "        // Only the destinations with a candidate (occupiedRefusal; sphc "
            "--no-skip-empty-lists:\n"
            "        // every one): all while the lists' are not found (a build), then those.\n";
  scene_ << "        const bool occ_all = !" << lists << ".occupied_found;\n";
  scene_ << "        const std::uint32_t* const occ = " << lists << ".occupied.data();\n";
  scene_ << "        const int n_visit = occ_all ? " << (zero ? end : end + " - " + begin)
         << " : static_cast<int>(" << lists << ".occupied.size());\n";
  scene_ << pragma;
  scene_ << "        for (int v = 0; v < n_visit; ++v) {\n";
  scene_ << "          const int d_idx = occ_all ? " << (zero ? "v" : begin + " + v")
         << " : static_cast<int>(occ[v]);\n";
}

void ScenePrinter::emitCrossBlocksHead(const std::string& lists, const std::string& nameA,
                                       const std::string& nameB) {
  scene_ << "        // " << nameA << " in contiguous blocks, one per thread; each " << nameB
         << " particle's sums in increasing\n"
            "        // " << nameA << " index whatever the blocks (sphc/cross_pairs.h): in the "
            "block holding all its\n"
            "        // candidates, else after the blocks. The lists read from " << nameB
         << "'s side, again after a build\n"
            "        // (by whichever loop builds the lists):\n";
  scene_ << "        if (" << lists << "_by_source.empty()) " << lists << "_by_source.build("
         << lists << ".lists, " << nameB << ".n);\n";
  scene_ << "        const std::uint32_t* const by_source_first = " << lists << "_by_source.first.data();\n";
  scene_ << "        const std::uint32_t* const by_source_last = " << lists << "_by_source.last.data();\n";
  scene_ << "        const int n_blocks = std::max(1, std::min(n, omp_get_max_threads()));\n";
  if (ompRegions_on_) {
    // The blocks and the spanning particles (emitCrossSpanning) in one parallel region
    // (stop 46; --no-omp-regions: a region each), `omp for nowait`: the spanning loop writes
    // only the sums of nameB's particles that no block writes (those whose candidates lie in
    // several blocks) and reads no sum (a pass reads no property its group writes while the
    // passes run: analysis/Hazards.cpp); which ones span is a function of the lists alone.
    scene_ << "        // The " << nameB << " particles whose candidates lie in several blocks "
              "(emitCrossSpanning's loop,\n"
              "        // in the blocks' region: codegen/OmpRegions.cpp, sphc --no-omp-regions: "
              "a region each).\n";
    emitSpanningHead(lists);
    // (the region's braces two spaces out: its loops keep their indentation)
    scene_ << "      #pragma omp parallel default(firstprivate) shared(cells, spanning)\n";
    scene_ << "      {\n";
    scene_ << "        #pragma omp for schedule(static) nowait\n";
  } else {
    scene_ << "        #pragma omp parallel for schedule(static) default(firstprivate) shared(cells)\n";
  }
  scene_ << "        for (int blk = 0; blk < n_blocks; ++blk) {\n";
  scene_ << "          const int b_begin = static_cast<int>(static_cast<long>(n) * blk / n_blocks);\n";
  scene_ << "          const int b_end = static_cast<int>(static_cast<long>(n) * (blk + 1) / n_blocks);\n";
  scene_ << "          const std::uint32_t u_begin = static_cast<std::uint32_t>(b_begin), "
            "u_end = static_cast<std::uint32_t>(b_end);\n";
}

void ScenePrinter::emitCrossSpanning(const NeighbourPass& ba, int b, const std::set<std::string>& q,
                                     const std::string& lists, const std::string& nameA,
                                     const std::string& nameB) {
  scene_ << "        }\n";
  scene_ << "        // The " << nameB << " particles whose candidates lie in several blocks: "
            "each over its\n"
            "        // candidates in increasing " << nameA << " index, the pair as above (d_idx of "
         << nameA << ", s_idx of " << nameB << ").\n";
  if (ompRegions_on_) {
    scene_ << "        #pragma omp for schedule(static) nowait\n";
  } else {
    emitSpanningHead(lists);
    scene_ << "        #pragma omp parallel for schedule(static) default(firstprivate) shared(spanning)\n";
  }
  scene_ << "        for (int m = 0; m < n_spanning; ++m) {\n";
  scene_ << "          const int s_idx = static_cast<int>(spanning[m]);\n";
  scene_ << "          const std::uint32_t* const k_end = by_source_dests + by_source_starts[s_idx + 1];\n";
  scene_ << "          for (const std::uint32_t* k = by_source_dests + by_source_starts[s_idx]; "
            "k != k_end; ++k) {\n";
  const std::string body = "            ";
  scene_ << body << "const int d_idx = static_cast<int>(*k);\n";
  emitDestLocals(scene_, body, q, host_);
  emitNeighbourTest(scene_, host_, "continue;", body);
  emitPairQuantitiesOnce(q, true, body);
  for (const PlanEquation* eq : ba.equations) scene_ << body << callBodyMirrored(*eq, b, "mirror_");
  scene_ << "          }\n        }\n";
  if (ompRegions_on_) scene_ << "      }  // the blocks' and the spanning particles' region\n";
}

void ScenePrinter::emitSpanningHead(const std::string& lists) {
  scene_ << "        const std::vector<std::uint32_t>& spanning = " << lists
         << "_by_source.spanning_blocks(n, n_blocks);\n";
  scene_ << "        const int n_spanning = static_cast<int>(spanning.size());\n";
  scene_ << "        const std::uint32_t* const by_source_starts = " << lists
         << "_by_source.starts.data();\n";
  scene_ << "        const std::uint32_t* const by_source_dests = " << lists
         << "_by_source.dests.data();\n";
}

// --report's notes as this printer prints the loops: a pass it puts in SIMD lanes per
// destination (simdPairsRefusal "") is named so, not as each pair once.
std::vector<std::string> ScenePrinter::pairLoopNotes(const EmitOptions& opts) const {
  std::vector<std::string> notes = symmetricPairsNotes(
      sched_, opts, [this](const DestinationWork& w, const NeighbourPass& pass) {
        // With ghosts the each-pair-once lanes are not written for: lanes per destination.
        return simdPairsRefusal(w, pass).empty() && (hasDomain() || !onceLanes(w, pass));
      });
  for (std::string& note : simdPairsNotes()) notes.push_back(std::move(note));  // SimdPairs.cpp
  return notes;
}

}  // namespace sphc
