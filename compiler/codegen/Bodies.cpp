// Equation and stepper bodies as functions, their parameters and calls, and the per-candidate
// code of a neighbour pass (pair quantities, then the loop bodies): written once, printed in
// a Dialect (the C++ of the CPU backends or the OpenCL C of the kernels).
#include "analysis/Access.h"
#include "analysis/PairQuantityTable.h"
#include "analysis/UniformH.h"
#include "body/BodyAnalysis.h"
#include "codegen/FusedMultiplyAdd.h"
#include "codegen/Printer.h"

#include <algorithm>
#include <cctype>

namespace sphc {

ScenePrinter::ScenePrinter(const Schedule& sched, const DiagnosticEngine& diags,
                           const EmitOptions& opts)
    : sched_(sched),
      plan_(*sched.plan),
      diags_(diags),
      backendName_(backendName(opts.backend)),
      singlePrecision_(opts.precision == Precision::Single),
      cpuSingle_(singlePrecision_ && opts.backend != Backend::OpenCL),
      real_(cpuSingle_ ? "float" : "double") {
  host_ = {real_,        "std::int32_t", "std::uint32_t", "",       "static inline ",
           "Kernel::w",  "Kernel::gradient", "std::sqrt",  "return;", ".",
           cpuSingle_,   cpuSingle_,     true,            "scene.cpp"};
  device_ = {"real",     "int",          "uint",          "__global ", "inline ",
             "kernel_w", "kernel_gradient", "sqrt",     "continue;", "_",
             false,      false,          true,            plan_.sceneName + ".cl"};
  if (opts.fma) {
    host_.fma = "std::fma";
    device_.fma = "fma";
  }
  // Single precision too (the values' own types, Hoist.cpp).
  host_.hoist = opts.hoist && opts.backend != Backend::OpenCL && !sched.distribution.enabled;
  for (int a : sched.cellLists) sourceArrays_.push_back(arr(a).name);
  for (int a : sched.searchArrays) loopArrays_.insert(arr(a).name);
  mpi_ = sched.distribution.enabled;
  globalIds_ = opts.globalIds || mpi_;
  splitPhases_ = opts.splitUnits && opts.backend != Backend::OpenCL && !mpi_;
  intPow_ = opts.intPow && !singlePrecision_;
  // In single precision too: the locals are of the scene's real type (float), as the sums in
  // memory, so the same operations round alike (RegisterSums.cpp).
  registerSums_ = opts.registerSums && opts.backend != Backend::OpenCL && !mpi_;
  kernelLanes_ = opts.backend != Backend::OpenCL && !mpi_ ? opts.kernelLanes : "off";
  simdPairs_ = opts.simdPairs && registerSums_;  // SimdPairs.cpp: on the sums in locals
  simdAuto_ = opts.simdPairsAuto;
  simdCpu_ = opts.simdCpu;
  simdNeighbours_ = opts.simdAutoNeighbours < 0 ? kSimdAutoNeighbours : opts.simdAutoNeighbours;
  simdOnceNeighbours_ = opts.simdOnceNeighbours;
  simdPerDestNeighbours_ = opts.simdPerDestNeighbours >= 0 ? opts.simdPerDestNeighbours : kSimdPerDestNeighbours;
  simdSymmetric_ = opts.symmetricPairs && opts.verletSkin > 0 && !hasZones() && !hasDomain();
  simdSymmetricSwitch_ = opts.symmetricPairs;
  // The scalar loops of a periodic or mirror scene with kept lists evaluate each pair once,
  // a pair with a ghost for the real particle only (CpuPrinter::symmetricPass; double only).
  simdGhostOnce_ = opts.symmetricPairs && opts.verletSkin > 0 && hasDomain() && !singlePrecision_;
  // SimdPairs.cpp: each pair once in the lanes (double precision: the pair-shared values).
  simdOnce_ = opts.simdPairsOnce && simdPairs_ && simdSymmetric_ && !singlePrecision_;
  simdCluster_ = opts.simdPairsCluster && simdOnce_;  // ClusterPairs.cpp
  simdClusterAuto_ = opts.simdPairsClusterAuto;
  simdClusterAuto2d_ = opts.simdPairsClusterAuto2d;
  cluster2d8x8_ = opts.cluster2d8x8;
  cluster2dDoubled_ = opts.cluster2dDoubled;
  cluster3d2xmm_ = opts.cluster3d2xmm;
  clusterQueue_ = opts.clusterQueue;
  clusterSlotOrder_ = opts.clusterSlotOrder;
  tileMathRecip_ = opts.tileMathRecip;
  tileMathBatched_ = opts.tileMathBatched;
  // h read once per pass where it is one value (stop 45): the CPU backends, not --mpi (its
  // halos are not looked at).
  hUniform_.assign(plan_.arrays.size(), false);
  if (opts.uniformH && opts.backend != Backend::OpenCL && !mpi_)
    for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a)
      hUniform_[a] = hPerParticleReason(plan_, a).empty();
  simdClusterWhy_ = opts.simdPairsClusterAuto ? "--simd-pairs=auto: " + opts.simdCpu.tilesWhy
                                              : std::string("--simd-pairs=cluster");
  // PairShared.cpp: with --simd-pairs=auto too (its each-pair-once loops are those not in
  // lanes); --simd-pairs=on prints every loop that allows it per destination.
  pairShared_ = opts.pairShared && host_.hoist && (!simdPairs_ || simdAuto_);
  skipSelfPairs_ = opts.skipSelfPairs;
  filteredLists_ = opts.filteredLists;
  skipEmptyLists_ = opts.skipEmptyLists;
  initInAddBack_on_ = opts.initInAddBack;
  ompRegions_on_ = opts.ompRegions;
  constantValues_ = opts.constantValues;
}

int ScenePrinter::propIndex(int a, const std::string& p) const {
  for (size_t i = 0; i < arr(a).props.size(); ++i)
    if (arr(a).props[i].name == p) return static_cast<int>(i);
  return -1;
}

int ScenePrinter::constIndex(int a, const std::string& c) const {
  const auto& cs = arr(a).constants;
  auto it = std::find(cs.begin(), cs.end(), c);
  return it == cs.end() ? -1 : static_cast<int>(it - cs.begin());
}

std::string ScenePrinter::propType(int a, const std::string& p, const Dialect& d) const {
  if (constIndex(a, p) >= 0) return d.real;
  const PlanProperty* pp = arr(a).find(p);
  if (pp && pp->type == "int") return d.intType;
  if (pp && pp->type == "uint") return d.uintType;
  return d.real;
}

std::vector<ScenePrinter::BodyParam> ScenePrinter::bodyParams(const PlanBody& b, int destArray,
                                                              const Dialect& d) const {
  std::vector<BodyParam> ps;
  const std::string& real = d.real;
  const std::string& global = d.global;
  const BodyFacts& f = b.facts;
  bool isLoop = b.source.kind == BodyKind::Loop;
  if (b.source.kind == BodyKind::HostReduce)
    ps.push_back({"int N", BodyParam::N, ""});  // the real particles of the destination
  else
    ps.push_back({"int d_idx", BodyParam::Idx, ""});
  if (isLoop) ps.push_back({"int s_idx", BodyParam::SIdx, ""});
  if (b.source.kind == BodyKind::LoopAll) {
    // PySPH's neighbour list: source indices, and how many.
    ps.push_back({"const " + d.uintType + "* NBRS", BodyParam::Nbrs, ""});
    ps.push_back({"int N_NBRS", BodyParam::NNbrs, ""});
  }
  ps.push_back({real + " t", BodyParam::T, ""});
  ps.push_back({real + " dt", BodyParam::Dt, ""});
  for (const auto& q : pairQuantityNames())
    if (f.pairQuantities.count(q)) {
      bool vec = findPairQuantity(q)->vector;
      ps.push_back({(vec ? "const " + real + "* " : real + " ") + q, BodyParam::Pair, q});
    }
  for (const auto& s : b.source.scalars)
    if (f.scalarsUsed.count(s))
      // A state the body writes (converged, on the host): the instance's own member.
      ps.push_back({(f.statesWritten.count(s) ? std::string("double&") : real) + " " + s,
                    BodyParam::Scalar, s});
  std::set<std::string> written;
  for (const auto& w : f.dWrites) written.insert(w.prop);
  std::set<std::string> dprops;
  for (const auto& r : f.dReads) dprops.insert(r.prop);
  dprops.insert(written.begin(), written.end());
  for (const auto& p : dprops) {
    std::string type = real;
    if (destArray >= 0)
      if (arr(destArray).find(p)) type = propType(destArray, p, d);
    bool isConst = destArray >= 0 && constIndex(destArray, p) >= 0;
    ps.push_back({global + (written.count(p) || isConst ? "" : "const ") + type + "* d_" + p,
                  BodyParam::DProp, p});
  }
  std::set<std::string> sprops;
  for (const auto& r : f.sReads) sprops.insert(r.prop);
  for (const auto& p : sprops) {
    // The type the body was checked with, which is the property's type in every source
    // array (analysis/Properties.cpp checks that).
    auto shape = b.source.props.find(p);
    std::string t = shape == b.source.props.end() ? "double" : shape->second.type;
    std::string type = t == "int" ? d.intType : t == "uint" ? d.uintType : real;
    ps.push_back({global + "const " + type + "* s_" + p, BodyParam::SProp, p});
  }
  // Values computed once per source particle (codegen/Hoist.cpp): s_hoisted0, ...
  const auto hoisted = hoistedSites(b, d);
  for (size_t k = 0; k < hoisted.size(); ++k)
    ps.push_back({"const " + hoistedValueType(b, d, true, k) + "* s_hoisted" + std::to_string(k),
                  BodyParam::Hoisted, std::to_string(k)});
  // ... and once per destination particle: d_hoisted0, ...
  const auto dHoisted = hoistedDestinationSites(b, d);
  for (size_t k = 0; k < dHoisted.size(); ++k)
    ps.push_back({hoistedValueType(b, d, false, k) + " d_hoisted" + std::to_string(k),
                  BodyParam::DHoisted, std::to_string(k)});
  // ... and once per pair for both particles (codegen/PairShared.cpp): pair_shared0, ...
  const auto shared = pairSharedSites(b, d);
  for (size_t k = 0; k < shared.size(); ++k)
    ps.push_back({pairSharedValueType(b, d, k) + " pair_shared" + std::to_string(k),
                  BodyParam::PairShared, std::to_string(k)});
  return ps;
}

void ScenePrinter::emitBodyFunction(const PlanBody& b, const std::string& name,
                                    const std::string& ret, int destArray, const Dialect& d,
                                    std::ostringstream& os) {
  auto params = bodyParams(b, destArray, d);
  // Single precision: the hoisted and pair-shared values' functions first, their types name
  // the body's parameters (Hoist.cpp, PairShared.cpp).
  if (d.floatBodies) {
    emitHoistFunctions(b, name, d, os);
    emitPairSharedFunctions(b, name, destArray, d, os);
  }
  os << "// " << b.source.label << ", from " << loc(b.source.start) << "\n";
  // OpenCL build errors in the body name the .sph line (the program is built at run time).
  if (d.lineDirectives) emitLineDirective(os, b.source.start);
  os << d.functionPrefix << (ret == "double" ? d.real : ret) << " " << name << "(";
  for (size_t i = 0; i < params.size(); ++i) os << (i ? ", " : "") << params[i].decl;
  os << ") {";
  // The body as written (its multiply-adds fused); its first line continues after the
  // opening brace.
  std::string text = bodyText(b, d);
  os << text;
  if (text.empty() || text.back() != '\n') os << "\n";
  os << "}\n";
  if (d.lineDirectives) resetLineDirective(os, d);
  os << "\n";
  if (!d.floatBodies) {
    emitHoistFunctions(b, name, d, os);
    emitPairSharedFunctions(b, name, destArray, d, os);
  }
}

// A body's or helper's text in a dialect: its multiply-adds fused, in float for
// --precision=single on the CPU.
std::string ScenePrinter::bodyText(const PlanBody& b, const Dialect& d) const {
  if (!hoistedSites(b, d).empty() || !hoistedDestinationSites(b, d).empty() ||
      !pairSharedSites(b, d).empty())
    return d.floatBodies ? singlePrecisionBody(hoistedBodyText(b, d)) : hoistedBodyText(b, d);
  std::string text = fuseMultiplyAdds(b.source.text, b.facts.multiplyAdds, d.fma);
  return d.floatBodies ? singlePrecisionBody(text) : text;
}

// A helper function (`function double f(...) { }`), as written after `function`: a plain C
// definition, the same in C++ and OpenCL C.
void ScenePrinter::emitHelperFunction(const PlanBody& f, const Dialect& d,
                                      std::ostringstream& os) {
  os << "// " << f.source.label << ", from " << loc(f.source.start) << "\n";
  if (d.lineDirectives) emitLineDirective(os, f.source.start);
  os << d.functionPrefix << bodyText(f, d) << "\n";
  if (d.lineDirectives) resetLineDirective(os, d);
  os << "\n";
}

// KERNEL_W(r, h) and KERNEL_DWDR(r, h), the scene's kernel and its radial derivative at any
// smoothing length, for bodies that call them (e.g. a kernel at h/2); emitted only then.
void ScenePrinter::emitKernelFunctions() {
  bool used = false;
  for (const auto& b : plan_.bodies)
    for (const std::string& f : kernelFunctions())
      used |= b.source.text.find(f) != std::string::npos;
  for (const auto& b : plan_.functions)
    for (const std::string& f : kernelFunctions())
      used |= b.source.text.find(f) != std::string::npos;
  if (!used) return;
  out_ << "static inline double KERNEL_W(double r, double h) { return Kernel::w(r, h); }\n"
          "static inline double KERNEL_DWDR(double r, double h) {\n"
          "  const double x[3] = {r, 0.0, 0.0};\n"
          "  double g[3];\n"
          "  Kernel::gradient(x, r, h, g);\n"
          "  return r > 0.0 ? g[0] : 0.0;\n"
          "}\n\n";
  deviceKernelFunctions();
}

// pow(x, y) in the bodies and helper functions (found by a lexical scan for the identifier).
bool ScenePrinter::intPowUsed() const {
  if (!intPow_) return false;
  auto calls = [](const std::string& text) { return identifierOccurrences(text, "pow") > 0; };
  for (const auto& b : plan_.bodies)
    if (calls(b.source.text)) return true;
  for (const auto& f : plan_.functions)
    if (calls(f.source.text)) return true;
  return false;
}

// A `pow` of the scene's namespace, which the bodies' unqualified calls find before the C
// library's: sphc::pow_int multiplies where the exponent is a small integer (docs/
// performance-log.md, "Cheaper arithmetic"); the OpenCL device the same (devicePowFunction).
// Not in single precision.
void ScenePrinter::emitPowFunction() {
  if (!intPowUsed()) return;
  out_ << "// pow(x, y) of the bodies: x^y by multiplications where y is an integer with |y| <= 8\n"
          "// (within 8 ulp of the C library's pow), pow itself otherwise (sphc/pow.h; sphc\n"
          "// --int-pow=off: the C library's pow).\n"
          "static inline double pow(double x, double y) { return sphc::pow_int(x, y); }\n\n";
  devicePowFunction();
}

void ScenePrinter::emitLineDirective(std::ostringstream& os, llvm::SMLoc l) const {
  std::string info = loc(l);  // file.sph:line
  size_t colon = info.rfind(':');
  if (colon == std::string::npos) return;
  os << "#line " << info.substr(colon + 1) << " \"" << info.substr(0, colon) << "\"\n";
}

void ScenePrinter::resetLineDirective(std::ostringstream& os, const Dialect& d) const {
  // The directive is on line (newlines so far + 1): the next line is one more.
  std::string text = os.str();
  long line = std::count(text.begin(), text.end(), '\n') + 2;
  os << "#line " << line << " \"" << d.lineFile << "\"\n";
}

std::string ScenePrinter::propPtr(int a, const std::string& p) const {
  if (cpuSingle_) {
    int c = constIndex(a, p);
    if (c >= 0) return "f32_" + arr(a).name + ".constant(" + constSlot(a, c) + ")";
    int i = propIndex(a, p);
    if (i >= 0 && arr(a).props[i].type != "int" && arr(a).props[i].type != "uint")
      return "f32_" + arr(a).name + ".f(" + propSlot(a, i) + ")";
  }
  return hostPtr(a, p);
}

std::string ScenePrinter::hostPtr(int a, const std::string& p) const {
  int c = constIndex(a, p);
  if (c >= 0) return arr(a).name + ".constant(" + constSlot(a, c) + ")";
  int i = propIndex(a, p);
  if (i < 0) SPHC_INTERNAL("property '" + p + "' of '" + arr(a).name + "' was not allocated");
  return arr(a).name + "." + accessor(arr(a).props[i].type) + "(" + propSlot(a, i) + ")";
}

std::string ScenePrinter::propSlot(int a, int i) const {
  return arr(a).name + "_props::" + cppSafeName(arr(a).props[i].name);
}

std::string ScenePrinter::constSlot(int a, int c) const {
  return arr(a).name + "_consts::" + cppSafeName(arr(a).constants[c]);
}

// One enum of property slots (and one of constant slots) per array, in the order setup()
// adds them, so that generated code says `fluid.f64(fluid_props::rho)`, not `fluid.f64(3)`.
void ScenePrinter::emitSlots() {
  out_ << "// Where each array keeps its properties and constants (the order setup() adds them).\n";
  for (size_t a = 0; a < plan_.arrays.size(); ++a) {
    const auto& A = arr(static_cast<int>(a));
    auto emitEnum = [&](const std::string& kind, const std::vector<std::string>& names) {
      out_ << "struct " << A.name << "_" << kind << " {\n  enum : int {";
      std::string line;
      for (size_t i = 0; i < names.size(); ++i) {
        std::string item = cppSafeName(names[i]) + " = " + std::to_string(i) +
                           (i + 1 < names.size() ? "," : "");
        if (line.size() + item.size() > 88) {
          out_ << line << "\n";
          line = "   ";
        }
        line += " " + item;
      }
      out_ << line << " };\n};\n";
    };
    std::vector<std::string> props;
    for (const auto& p : A.props) props.push_back(p.name);
    emitEnum("props", props);
    if (!A.constants.empty()) emitEnum("consts", A.constants);
  }
  out_ << "\n";
}

std::string ScenePrinter::callBody(const std::string& fn, const PlanBody& b, int dest,
                                   const std::string& eqValues, const std::string& time,
                                   const std::string& sep,
                                   const std::function<std::string(const BodyParam&)>& argument) const {
  std::string s = fn + "(";
  bool first = true;
  for (const auto& p : bodyParams(b, dest, host_)) {
    s += first ? "" : ", ";
    first = false;
    if (argument) {
      const std::string a = argument(p);
      if (!a.empty()) {
        s += a;
        continue;
      }
    }
    if (p.kind == BodyParam::PairShared) {
      // The value computed once for the pair (emitPairSharedLocals), else computed here by
      // the site's function on the call's own arguments.
      auto it = pairSharedScope_.find(eqValues + "/" + p.name);
      if (it != pairSharedScope_.end()) {
        s += it->second.local;
        continue;
      }
      std::string base = fn;
      bool simd = false;  // NAME_loop_simd: the value's _simd form (PairShared.cpp)
      for (const char* suffix : {"_sums", "_simd"})
        if (base.size() > 5 && base.compare(base.size() - 5, 5, suffix) == 0) {
          simd = std::string(suffix) == "_simd";
          base.erase(base.size() - 5);
        }
      std::string call = base + "_pairshared" + p.name + (simd ? "_simd" : "") + "(";
      bool firstArg = true;
      for (const auto& q : pairSharedParams(b, dest, host_)) {
        call += firstArg ? "" : ", ";
        firstArg = false;
        const std::string a = argument ? argument(q) : "";
        if (!a.empty()) {
          call += a;
          continue;
        }
        call += callBodyDefault(q, eqValues, time, sep);
      }
      s += call + ")";
      continue;
    }
    s += callBodyDefault(p, eqValues, time, sep);
  }
  return s + ")";
}

std::string ScenePrinter::callBodyDefault(const BodyParam& p, const std::string& eqValues,
                                          const std::string& time, const std::string& sep) const {
  std::string s;
  {
    switch (p.kind) {
      case BodyParam::Idx: s += "d_idx"; break;
      case BodyParam::SIdx: s += "s_idx"; break;
      case BodyParam::T: s += time; break;
      case BodyParam::Dt: s += "dt"; break;
      case BodyParam::Pair: s += p.name; break;
      case BodyParam::Scalar: s += eqValues + sep + p.name; break;
      case BodyParam::DProp: s += "d_" + p.name; break;
      case BodyParam::SProp: s += "s_" + p.name; break;
      case BodyParam::Nbrs: s += "NBRS"; break;
      case BodyParam::NNbrs: s += "N_NBRS"; break;
      case BodyParam::N: s += "N"; break;
      case BodyParam::Hoisted: s += hoistArgument(eqValues, p.name); break;
      case BodyParam::DHoisted: s += hoistDestinationArgument(eqValues, p.name); break;
      case BodyParam::PairShared: break;  // (callBody)
    }
  }
  return s;
}

void ScenePrinter::emitDestLocals(std::ostream& os, const std::string& indent,
                                  const std::set<std::string>& q, const Dialect& d) const {
  const std::string& R = d.real;
  // The position, all three axes: the neighbour search takes (xi, yi, zi).
  const char* axes[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k)
    os << indent << "const " << R << " " << axes[k] << "i = "
       << (k < plan_.dim ? std::string("di_") + axes[k] + "[d_idx]" : d.lit("0.0")) << ";\n";
  os << indent << "const " << R << " hi = " << hiValue("di_h[d_idx]") << ";\n";
  // The other vectors of which a pair quantity is a difference (VIJ: ui, vi, wi).
  for (const PairQuantity& pq : pairQuantityTable())
    if (pq.form == PairForm::Difference && pq.when != PairWhen::BeforeTest && q.count(pq.name))
      for (int k = 0; k < plan_.dim; ++k)
        os << indent << "const " << R << " " << pq.components[k] << "i = di_"
           << pq.components[k] << "[d_idx];\n";
}

PairDialect pairDialectOf(const Dialect& dl) {
  PairDialect dialect;
  dialect.real = dl.real;
  dialect.sqrt = dl.sqrt;
  dialect.kernelW = dl.kernelW;
  dialect.kernelGradient = dl.kernelGradient;
  dialect.literalSuffix = dl.lit("");
  return dialect;
}

void ScenePrinter::emitTestOperands(std::ostream& os, const Dialect& dl,
                                    const std::string& indent) const {
  const PairDialect dialect = pairDialectOf(dl);
  os << indent << "const " << dl.real << " hj = " << hjValue("sj_h[s_idx]") << ";\n";
  for (const PairQuantity& pq : pairQuantityTable())
    if (pq.when == PairWhen::BeforeTest)
      os << pairStatement(pq, dialect, indent);
}

std::string ScenePrinter::pairStatement(const PairQuantity& pq, const PairDialect& dialect,
                                        const std::string& indent) const {
  if (uhI_ && uhJ_ && pq.name == "HIJ")
    return indent + "const " + dialect.real + " HIJ = " + uhPrefix_ + "HIJ;  // h uniform: once per pass\n";
  if (uhI_ && uhJ_ && pq.h == "HIJ" && pq.form == PairForm::Kernel)
    return indent + "const " + dialect.real + " " + pq.name + " = " + kernelCall("w", "RIJ, ", "HIJ", "") + ";\n";
  if (uhI_ && uhJ_ && pq.h == "HIJ" && pq.form == PairForm::Gradient)
    return indent + dialect.real + " " + pq.name + "[3];\n" + indent +
           kernelCall("gradient", "XIJ, RIJ, ", "HIJ", ", " + pq.name) + ";\n";
  return pairQuantityStatement(pq, plan_.dim, dialect, indent);
}

std::string ScenePrinter::kernelCall(const std::string& fn, const std::string& before,
                                     const std::string& h, const std::string& after) const {
  if (!(uhI_ && uhJ_) || h != "HIJ") return "Kernel::" + fn + "(" + before + h + after + ")";
  const bool tile = fn == "w_tile" || fn == "gradient_factor_tile";  // (1 / h in h's place)
  return "Kernel::" + fn + "_ih(" + before + (tile ? uhPrefix_ + "ih" : h) + ", " + uhPrefix_ +
         "ihd" + after + ")";
}

void ScenePrinter::beginUniformH(int d, int s, const std::string& in) {
  endUniformH();
  uhI_ = hUniform_[d];
  uhJ_ = hUniform_[s];
  if (!uhI_ && !uhJ_) return;
  const std::string& R = host_.real;
  const std::string& D = arr(d).name;
  const std::string& S = arr(s).name;
  scene_ << in << "// h the same for every particle of "
         << (uhI_ && uhJ_ ? (d == s ? D : D + " and of " + S)
                          : uhI_ ? D + " (not of " + S + ")" : S + " (not of " + D + ")")
         << " all the run (analysis/UniformH.cpp): read once\n";
  scene_ << in << "// (sphc --no-uniform-h: per particle; the same values bit for bit)\n";
  if (uhI_)
    scene_ << in << "const " << R << " uh_hi = " << arr(d).name << ".n > 0 ? di_h[0] : " << R << "(0);\n";
  if (uhJ_)
    scene_ << in << "const " << R << " uh_hj = " << arr(s).name << ".n > 0 ? sj_h[0] : " << R << "(0);\n";
  if (!(uhI_ && uhJ_)) return;
  // hmax, the cut-off and HIJ as the pair loops write them, once.
  scene_ << in << R << " uh_hmax, uh_cut2, uh_HIJ, uh_ih, uh_ihd;\n";
  scene_ << in << "{\n";
  scene_ << in << "  const " << R << " hi = uh_hi;\n";
  scene_ << in << "  const " << R << " hj = uh_hj;\n";
  scene_ << in << "  const " << R << " hmax = hi > hj ? hi : hj;\n";
  for (const PairQuantity& pq : pairQuantityTable())
    if (pq.name == "HIJ")
      scene_ << pairQuantityStatement(pq, plan_.dim, pairDialectOf(host_), in + "  ");
  scene_ << in << "  uh_hmax = hmax;\n";
  scene_ << in << "  uh_cut2 = RADIUS2 * hmax * hmax;\n";
  scene_ << in << "  uh_HIJ = HIJ;\n";
  scene_ << in << "  uh_ih = Kernel::inv_h(HIJ);  // the kernel's 1 / h and 1 / h^dim (kernels.h, FN_ih)\n";
  scene_ << in << "  uh_ihd = Kernel::inv_h_dim(HIJ);\n";
  scene_ << in << "}\n";
}

void ScenePrinter::uniformHLocals(const std::string& in) {
  if (!uhI_ && !uhJ_) return;
  const std::string& R = host_.real;
  for (const char* v : {"hi", "hj", "hmax", "cut2", "HIJ", "ih", "ihd"}) {
    const std::string n = v;
    if ((n == "hi" && !uhI_) || (n == "hj" && !uhJ_) || (n != "hi" && n != "hj" && !(uhI_ && uhJ_)))
      continue;
    scene_ << in << "const " << R << " uhl_" << n << " = uh_" << n << ";  // h uniform: a local copy\n";
  }
  uhPrefix_ = "uhl_";
}

void ScenePrinter::emitNeighbourTest(std::ostream& os, const Dialect& dl, const std::string& skip,
                                     const std::string& indent, const std::string& radius2) {
  emitTestOperands(os, dl, indent);
  const std::string cut = cutoffValue(radius2);
  if (cut.find("hmax") != std::string::npos)
    os << indent << "const " << dl.real << " hmax = " << hmaxValue() << ";\n";
  os << indent << "if (R2IJ >= " << cut << ") " << skip
     << (radius2 == "RADIUS2" ? "  // not a neighbour\n" : "  // beyond the list's radius\n");
}

// The pair quantities of one candidate, from the table (analysis/PairQuantityTable): those
// before the neighbour test (XIJ, R2IJ), the test, then every-neighbour and used ones.
void ScenePrinter::emitPairQuantities(std::ostream& os, const std::set<std::string>& q,
                                      const Dialect& dl, bool test, const std::string& skip) {
  const std::string indent = "            ";
  const PairDialect dialect = pairDialectOf(dl);
  if (test) {
    emitNeighbourTest(os, dl, skip.empty() ? dl.skipCandidate : skip, indent);
  } else {  // a neighbour: what the test computes, without the test
    emitTestOperands(os, dl, indent);
  }
  for (const PairQuantity& pq : pairQuantityTable())
    if (pq.when == PairWhen::EveryNeighbour || (pq.when == PairWhen::IfUsed && q.count(pq.name)))
      os << pairStatement(pq, dialect, indent);
}

void ScenePrinter::emitCandidate(std::ostream& os, const std::set<std::string>& q,
                                 const std::vector<const PlanEquation*>& loopers, int d,
                                 const Dialect& dl, bool test, const RegisterSums* sums,
                                 const std::string& skip) {
  emitPairQuantities(os, q, dl, test, skip);
  for (const auto* eq : loopers)
    os << "            "
       << (sums ? pairCall(*eq, d, *sums) : equationCall(*eq, ast::Method::Loop, d, dl.scalarSep));
}

std::string ScenePrinter::equationCall(const PlanEquation& eq, ast::Method::Kind kind, int d,
                                       const std::string& sep) const {
  return callBody(bodyFunctionName(eq.name, ast::methodKeyword(kind)), methodBody(eq, kind), d,
                  eqStruct(eq), "t", sep) +
         ";  // " + eq.name + ", from " + loc(eq.loc) + "\n";
}

std::string ScenePrinter::propIndexList(int a, const std::vector<std::string>& props) const {
  std::string s = "{";
  for (size_t k = 0; k < props.size(); ++k) {
    int i = propIndex(a, props[k]);
    if (i < 0) SPHC_INTERNAL("ghost property '" + props[k] + "' of '" + arr(a).name +
                             "' was not allocated");
    s += (k ? ", " : "") + propSlot(a, i);
  }
  return s + "}";
}

}  // namespace sphc
