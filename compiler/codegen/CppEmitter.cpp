#include "codegen/CppEmitter.h"

#include "analysis/Access.h"
#include "analysis/PairQuantityTable.h"
#include "analysis/Passes.h"
#include "body/BodyAnalysis.h"
#include "sema/Geometry.h"

#include "llvm/Support/FileSystem.h"
#include "llvm/Support/Path.h"
#include "llvm/Support/raw_ostream.h"

#include <functional>
#include <map>
#include <set>
#include <sstream>

namespace sphc {

namespace {

using NameMap = std::function<std::string(const std::string&)>;

// A declarative expression as C++ (doubles throughout: `1/2` is 0.5, as a user expects).
std::string exprCpp(const ast::Expr& e, const NameMap& names) {
  switch (e.kind) {
    case ast::Expr::Number: {
      std::string t = e.text.empty() ? std::to_string(e.number) : e.text;
      if (t.find_first_of(".eE") == std::string::npos) t += ".0";
      return t;
    }
    case ast::Expr::Name:
      if (e.text == "pi") return "M_PI";
      if (e.text == "e") return "M_E";
      if (e.text == "true") return "1.0";
      if (e.text == "false") return "0.0";
      return names(e.text);
    case ast::Expr::Unary:
      return "(" + e.op + exprCpp(*e.args[0], names) + ")";
    case ast::Expr::Binary:
      if (e.op == "%")
        return "std::fmod(" + exprCpp(*e.args[0], names) + ", " + exprCpp(*e.args[1], names) +
               ")";
      return "(" + exprCpp(*e.args[0], names) + " " + e.op + " " + exprCpp(*e.args[1], names) +
             ")";
    case ast::Expr::Ternary:
      return "(" + exprCpp(*e.args[0], names) + " ? " + exprCpp(*e.args[1], names) + " : " +
             exprCpp(*e.args[2], names) + ")";
    case ast::Expr::Call: {
      std::string f = e.text;
      if (f == "min") f = "fmin";
      if (f == "max") f = "fmax";
      if (f == "abs") f = "fabs";
      std::string s = "std::" + f + "(";
      for (size_t i = 0; i < e.args.size(); ++i)
        s += (i ? ", " : "") + exprCpp(*e.args[i], names);
      return s + ")";
    }
  }
  return "0.0";
}

// The expression as the user would write it (for --help of the generated program).
std::string exprText(const ast::Expr& e) {
  std::string s = exprCpp(e, [](const std::string& n) { return n; });
  for (size_t at; (at = s.find("std::")) != std::string::npos;) s.erase(at, 5);
  return s;
}

bool isLiteral(const ast::Expr& e) {
  if (e.kind == ast::Expr::Number) return true;
  return e.kind == ast::Expr::Unary && e.op == "-" && e.args[0]->kind == ast::Expr::Number;
}

double literalValue(const ast::Expr& e) {
  return e.kind == ast::Expr::Number ? e.number : -e.args[0]->number;
}

std::string cppType(const std::string& t) {
  if (t == "int") return "std::int32_t";
  if (t == "uint") return "std::uint32_t";
  return "double";
}

std::string propTypeEnum(const std::string& t) {
  if (t == "int") return "sphc::PropType::I32";
  if (t == "uint") return "sphc::PropType::U32";
  return "sphc::PropType::F64";
}

std::string accessor(const std::string& t) {
  if (t == "int") return "i32";
  if (t == "uint") return "u32";
  return "f64";
}

std::string bodyFunctionName(const std::string& owner, const std::string& method) {
  return owner + "_" + method;
}

// A body for --precision=single on the CPU: `double` becomes `float` and every floating
// literal without a suffix gets `f`, so the body computes in float as it does in OpenCL C
// (where `#define double float` and -cl-single-precision-constant do the same). Bodies are
// portable C99 without strings or preprocessor lines, so tokens are identifiers, numbers,
// comments and punctuation; comments are copied as they are.
std::string singlePrecisionBody(const std::string& text) {
  std::string out;
  auto isIdent = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  size_t i = 0;
  while (i < text.size()) {
    char c = text[i];
    if (c == '/' && i + 1 < text.size() && (text[i + 1] == '/' || text[i + 1] == '*')) {
      size_t end = text[i + 1] == '/' ? text.find('\n', i) : text.find("*/", i + 2);
      end = end == std::string::npos ? text.size() : end + (text[i + 1] == '/' ? 0 : 2);
      out += text.substr(i, end - i);
      i = end;
    } else if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      size_t end = i;
      while (end < text.size() && isIdent(text[end])) ++end;
      std::string word = text.substr(i, end - i);
      out += word == "double" ? "float" : word;
      i = end;
    } else if (std::isdigit(static_cast<unsigned char>(c)) ||
               (c == '.' && i + 1 < text.size() &&
                std::isdigit(static_cast<unsigned char>(text[i + 1])))) {
      // A preprocessing number: digits, letters, '.', and a sign after an exponent letter.
      size_t end = i;
      while (end < text.size()) {
        char d = text[end];
        if (isIdent(d) || d == '.') {
          ++end;
        } else if ((d == '+' || d == '-') && (text[end - 1] == 'e' || text[end - 1] == 'E') &&
                   !(text[i] == '0' && i + 1 < text.size() &&
                     (text[i + 1] == 'x' || text[i + 1] == 'X'))) {
          ++end;
        } else {
          break;
        }
      }
      std::string num = text.substr(i, end - i);
      bool hex = num.size() > 1 && num[0] == '0' && (num[1] == 'x' || num[1] == 'X');
      bool floating = !hex && num.find_first_of(".eE") != std::string::npos;
      char last = num.back();
      bool suffixed = last == 'f' || last == 'F' || last == 'l' || last == 'L';
      out += num;
      if (floating && !suffixed) out += "f";
      i = end;
    } else {
      out += c;
      ++i;
    }
  }
  return out;
}

class Emitter {
 public:
  Emitter(const Plan& plan, const DiagnosticEngine& diags, const EmitOptions& opts)
      : plan_(plan),
        diags_(diags),
        openmp_(opts.backend == "openmp"),
        opencl_(opts.backend == "opencl"),
        singlePrecision_(opts.precision == "single"),
        cpuSingle_(singlePrecision_ && !opencl_),
        real_(cpuSingle_ ? "float" : "double") {}
  std::string run();
  const std::string& kernelSource() const { return clText_; }

 private:
  // Parameters of a body function, in order, as (C++ declaration, argument kind) pairs.
  struct BodyParam {
    std::string decl;  // e.g. "const double* s_m"
    enum Kind { Idx, SIdx, T, Dt, Pair, Scalar, DProp, SProp } kind;
    std::string name;  // property, pair quantity or scalar name
  };
  // device: OpenCL C types (`real`, `__global` pointers) for a kernel of --backend=opencl.
  std::vector<BodyParam> bodyParams(const PlanBody& b, int destArray, bool device = false) const;
  void emitKernelFunctions();
  void emitBodyFunction(const PlanBody& b, const std::string& name, const std::string& ret,
                        int destArray, bool device = false);
  // eqValues + sep + scalar: "eq3.rho0" on the host, "eq3_rho0" (a kernel argument) on the
  // device.
  std::string callBody(const std::string& fn, const PlanBody& b, int dest, int src,
                       const std::string& eqValues, const std::string& idx,
                       const std::string& sep = ".") const;
  // The body of the neighbour loop for one candidate s_idx: pair quantities, the neighbour
  // criterion (`skip` leaves the candidate), then every loop body. Shared by the C++ loop
  // (double, Kernel::w) and the OpenCL kernel (real, kernel_w).
  // The destination particle's position, h (and velocity) as locals xi, yi, zi, hi (ui...).
  void emitDestLocals(std::ostream& os, const std::string& indent,
                      const std::set<std::string>& q, bool device) const;
  void emitCandidate(std::ostream& os, const std::set<std::string>& q,
                     const std::vector<const PlanEquation*>& loopers, int d, int s, bool device);
  // ---- --backend=opencl: kernels into cl_, launches into scene_ ----
  struct KernelArgs {
    std::vector<std::string> decls, host;
    std::map<std::string, size_t> at;
    // A buffer that one body reads (const) and another writes becomes non-const.
    void add(const std::string& decl, const std::string& hostExpr, const std::string& key) {
      auto it = at.find(key);
      if (it != at.end()) {
        if (decl.find("const ") == std::string::npos) decls[it->second] = decl;
        return;
      }
      at[key] = decls.size();
      decls.push_back(decl);
      host.push_back(hostExpr);
    }
  };
  std::string devType(int a, const std::string& p) const;
  std::string devBuffer(int a, const std::string& p) const;
  void addBodyArgs(KernelArgs& ka, const PlanBody& b, int dest, int src,
                   const std::string& eqValues) const;
  void beginKernel(const std::string& name, const KernelArgs& ka, bool guard = true);
  std::string launch(const std::string& name, const std::string& n, const KernelArgs& ka) const;
  // The kernels of one destination of phase `name`, and their launches.
  void emitDestinationDevice(int d, const std::vector<const PlanEquation*>& eqs,
                             const PlanGroup* group, const std::string& name,
                             bool onGhosts);
  // After a phase on the real particles of d: refresh_ghosts of the carried properties it
  // wrote.
  void emitGhostRefresh(int d, const std::vector<const PlanEquation*>& eqs, bool onGhosts);
  void emitLineDirective(llvm::SMLoc l);
  void resetLineDirective();
  // The data a scene computes on: host arrays, or their float copies (--precision=single).
  std::string propPtr(int array, const std::string& prop) const;
  // The host array's own data (set-up writes it).
  std::string hostPtr(int array, const std::string& prop) const;
  // The C++ type of a property or constant in the scene's loops (real_ for floating ones).
  std::string hostType(int array, const std::string& prop) const {
    if (constIndex(array, prop) >= 0) return real_;
    const PlanProperty* pp = arr(array).find(prop);
    return pp && (pp->type == "int" || pp->type == "uint") ? cppType(pp->type) : real_;
  }
  // A floating literal of emitted host code ("0.5" or "0.5f").
  std::string lit(const std::string& v, bool device = false) const {
    return cpuSingle_ && !device ? v + "f" : v;
  }
  void emitParams();
  void emitSetup();
  void emitArraySetup(const PlanArray& a);
  void emitGroup(const PlanGroup& g, const std::string& name);
  void emitPhase(const std::vector<int>& eqs, const std::string& name);
  // What a phase does for one destination, whatever the backend executes it with.
  std::vector<const PlanEquation*> destEquations(const std::vector<int>& eqIds, int d) const;
  std::vector<const PlanEquation*> withMethod(const std::vector<const PlanEquation*>& eqs,
                                              ast::Method::Kind kind) const;
  struct NeighbourPass {
    int s = -1;
    std::set<std::string> q;       // pair quantities, closed under what they need
    std::vector<const PlanEquation*> loopers;  // equations with a loop over this source
    std::set<std::string> sprops;  // source properties the loop bodies read
    std::set<std::string> need;    // read on both sides: positions, h, velocities, rho
  };
  // One pass per source, in order of first use; records the arrays the search needs.
  std::vector<NeighbourPass> neighbourPasses(const std::vector<const PlanEquation*>& eqs, int d,
                                             const PlanGroup* group);
  void emitSteppers();
  // The C++ backends: a function per run of consecutive stepper statements of the integrator
  // (see stepperRuns), one pass over each array doing all the run's methods per particle.
  void emitStepperRuns();
  // Runs of consecutive stepper statements (initialize, stageN) of the integrator's step,
  // with the index of each statement in plan_.integratorSteps.
  std::vector<std::vector<size_t>> stepperRuns() const;
  bool isStepperStatement(const std::string& s) const {
    return s != "compute_accelerations" && s != "update_domain";
  }
  std::string stepperRunName(const std::vector<size_t>& run) const {
    std::string name = "stepper";
    for (size_t k : run) name += "_" + plan_.integratorSteps[k];
    return name;
  }
  // Periodic and mirror domains (sphc/domain.h): the box at set-up, wrapping, ghosts.
  bool hasDomain() const { return plan_.domain.any(); }
  bool hasGhosts(int a) const { return hasDomain() && !arr(a).ghostProps.empty(); }
  std::string propIndexList(int a, const std::vector<std::string>& props) const;
  void emitDomainSetup();
  // The data the CPU domain functions work on: "a" (the host array) or, with
  // --precision=single, "f32_a, a" (its float copy, and the host array for the integers).
  std::string hostData(int a) const {
    return (cpuSingle_ ? "f32_" + arr(a).name + ", " : std::string()) + arr(a).name;
  }
  // The search domain of every array in a neighbour loop, from its doubles or (single) floats.
  void emitSearchDomain();
  // Reorders source S into the cell order of cells_S.
  std::string permuteInCellOrder(const std::string& S) const {
    return cpuSingle_ ? "f32_" + S + ".permute(cells_" + S + ".cell_order(), " + S + ");"
                      : S + ".permute(cells_" + S + ".cell_order());";
  }
  // The statement that builds the cell list of source S over its first `count` particles:
  // from its position pointers on the CPU (grid `domain`), from its device buffers with
  // --backend=opencl (grid `grid`).
  std::string cellListBuild(const std::string& S, const std::string& count) const;
  void emitUpdateNeighboursWithGhosts();
  void emitUpdateNeighboursWithGhostsDevice();
  // remove_ghosts of every source array (statements, indented by 4).
  std::string removeGhosts() const;
  // The extents of the arrays in neighbour loops, for ocl.search_domain / ocl.make_grid.
  std::string deviceExtents(const std::string& indent) const;
  void emitUpdateNeighbours();
  void emitTimedNeighbourUpdate();
  void emitStep();
  void emitAdaptiveDt();
  void emitMain();
  std::string loc(llvm::SMLoc l) const { return diags_.lineInfo(l); }
  std::string paramRef(const std::string& n) const { return "P." + n; }
  std::string eqStruct(const PlanEquation& eq) const { return "eq" + std::to_string(eq.id); }
  const PlanArray& arr(int a) const { return plan_.arrays[a]; }
  int propIndex(int a, const std::string& p) const {
    for (size_t i = 0; i < arr(a).props.size(); ++i)
      if (arr(a).props[i].name == p) return static_cast<int>(i);
    return -1;
  }
  int constIndex(int a, const std::string& c) const {
    const auto& cs = arr(a).constants;
    auto it = std::find(cs.begin(), cs.end(), c);
    return it == cs.end() ? -1 : static_cast<int>(it - cs.begin());
  }

  // `#pragma omp parallel for` (with `clauses`) before a loop over particles, for the OpenMP
  // backend; nothing for serial. Loops over destination particles only write their own
  // particle (gather), so they need no atomics and give the serial result bit for bit.
  std::string parallelFor(const std::string& indent, const std::string& clauses = "") const {
    if (!openmp_) return "";
    return indent + "#pragma omp parallel for schedule(static)" +
           (clauses.empty() ? "" : " " + clauses) + "\n";
  }

  const Plan& plan_;
  const DiagnosticEngine& diags_;
  bool openmp_ = false;
  bool opencl_ = false;
  bool singlePrecision_ = false;
  // --precision=single on the CPU backends: the scene computes on float copies of the arrays
  // (sphc::FloatArray f32_<array>), bodies and neighbour search included; the host arrays
  // (double) serve set-up and, after to_host(), output.
  bool cpuSingle_ = false;
  std::string real_ = "double";  // the C++ floating type the scene computes in
  std::ostringstream cl_;  // OpenCL C of the kernels (--backend=opencl)
  std::string clText_;
  std::ostringstream out_;
  std::ostringstream scene_;  // members of struct Scene
  std::vector<std::string> groupFunctions_;
  std::vector<std::string> iteratedGroups_;  // source locations, in emission order
  std::vector<std::string> postStepCalls_;  // top-level groups with post_step = true
  std::vector<std::string> postStepDue_;    // their conditions (`every`), as C++
  std::set<std::string> sourceArrays_;  // arrays that need a cell list
  std::set<std::string> loopArrays_;    // arrays in a neighbour loop, as dest or source
  int phaseCounter_ = 0;
};

std::vector<Emitter::BodyParam> Emitter::bodyParams(const PlanBody& b, int destArray,
                                                    bool device) const {
  std::vector<BodyParam> ps;
  const std::string real = device ? "real" : real_;
  const std::string global = device ? "__global " : "";
  const BodyFacts& f = b.facts;
  bool isLoop = b.source.kind == BodyKind::Loop;
  ps.push_back({"int d_idx", BodyParam::Idx, ""});
  if (isLoop) ps.push_back({"int s_idx", BodyParam::SIdx, ""});
  ps.push_back({real + " t", BodyParam::T, ""});
  ps.push_back({real + " dt", BodyParam::Dt, ""});
  for (const auto& q : pairQuantityNames())
    if (f.pairQuantities.count(q)) {
      bool vec = findPairQuantity(q)->vector;
      ps.push_back({(vec ? "const " + real + "* " : real + " ") + q, BodyParam::Pair, q});
    }
  for (const auto& s : b.source.scalars)
    if (f.scalarsUsed.count(s)) ps.push_back({real + " " + s, BodyParam::Scalar, s});
  std::set<std::string> written;
  for (const auto& w : f.dWrites) written.insert(w.prop);
  std::set<std::string> dprops;
  for (const auto& r : f.dReads) dprops.insert(r.prop);
  dprops.insert(written.begin(), written.end());
  for (const auto& p : dprops) {
    std::string type = real;
    if (destArray >= 0)
      if (const PlanProperty* pp = arr(destArray).find(p))
        type = device ? devType(destArray, p) : hostType(destArray, p);
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
    std::string type = t == "int" || t == "uint" ? (device ? t : cppType(t)) : real;
    ps.push_back({global + "const " + type + "* s_" + p, BodyParam::SProp, p});
  }
  return ps;
}

void Emitter::emitBodyFunction(const PlanBody& b, const std::string& name,
                               const std::string& ret, int destArray, bool device) {
  auto params = bodyParams(b, destArray, device);
  std::ostream& os = device ? cl_ : out_;
  os << "// " << b.source.label << ", from " << loc(b.source.start) << "\n";
  // OpenCL build errors in the body name the .sph line (the program is built at run time).
  if (device) emitLineDirective(b.source.start);
  os << (device ? "inline " : "static inline ")
     << (ret == "double" ? (device ? std::string("real") : real_) : ret)
     << " " << name << "(";
  for (size_t i = 0; i < params.size(); ++i) os << (i ? ", " : "") << params[i].decl;
  os << ") {";
  // The body exactly as written; its first line continues after the opening brace.
  std::string text = cpuSingle_ && !device ? singlePrecisionBody(b.source.text) : b.source.text;
  os << text;
  if (text.empty() || text.back() != '\n') os << "\n";
  os << "}\n";
  if (device) resetLineDirective();
  os << "\n";
}

// KERNEL_W(r, h) and KERNEL_DWDR(r, h), the scene's kernel and its radial derivative at any
// smoothing length, for bodies that call them (e.g. a kernel at h/2); emitted only then.
void Emitter::emitKernelFunctions() {
  bool used = false;
  for (const auto& b : plan_.bodies)
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
  if (opencl_) {
    cl_ << "inline real KERNEL_W(real r, real h) { return kernel_w(r, h); }\n"
           "inline real KERNEL_DWDR(real r, real h) {\n"
           "  real x[3] = {r, 0.0, 0.0};\n"
           "  real g[3];\n"
           "  kernel_gradient(x, r, h, g);\n"
           "  return r > 0.0 ? g[0] : 0.0;\n"
           "}\n";
    resetLineDirective();
  }
}

void Emitter::emitLineDirective(llvm::SMLoc l) {
  std::string info = loc(l);  // file.sph:line
  size_t colon = info.rfind(':');
  if (colon == std::string::npos) return;
  cl_ << "#line " << info.substr(colon + 1) << " \"" << info.substr(0, colon) << "\"\n";
}

void Emitter::resetLineDirective() {
  // The directive is on line (newlines so far + 1): the next line is one more.
  std::string text = cl_.str();
  long line = std::count(text.begin(), text.end(), '\n') + 2;
  cl_ << "#line " << line << " \"" << plan_.sceneName << ".cl\"\n";
}

std::string Emitter::propPtr(int a, const std::string& p) const {
  if (cpuSingle_) {
    int c = constIndex(a, p);
    if (c >= 0) return "f32_" + arr(a).name + ".constant(" + std::to_string(c) + ")";
    int i = propIndex(a, p);
    if (i >= 0 && arr(a).props[i].type != "int" && arr(a).props[i].type != "uint")
      return "f32_" + arr(a).name + ".f(" + std::to_string(i) + ")";
  }
  return hostPtr(a, p);
}

std::string Emitter::hostPtr(int a, const std::string& p) const {
  int c = constIndex(a, p);
  if (c >= 0) return arr(a).name + ".constant(" + std::to_string(c) + ")";
  int i = propIndex(a, p);
  if (i < 0) SPHC_INTERNAL("property '" + p + "' of '" + arr(a).name + "' was not allocated");
  return arr(a).name + "." + accessor(arr(a).props[i].type) + "(" + std::to_string(i) + ")";
}

std::string Emitter::callBody(const std::string& fn, const PlanBody& b, int dest, int src,
                              const std::string& eqValues, const std::string& time,
                              const std::string& sep) const {
  std::string s = fn + "(";
  bool first = true;
  for (const auto& p : bodyParams(b, dest)) {
    s += first ? "" : ", ";
    first = false;
    switch (p.kind) {
      case BodyParam::Idx: s += "d_idx"; break;
      case BodyParam::SIdx: s += "s_idx"; break;
      case BodyParam::T: s += time; break;
      case BodyParam::Dt: s += "dt"; break;
      case BodyParam::Pair: s += p.name; break;
      case BodyParam::Scalar: s += eqValues + sep + p.name; break;
      case BodyParam::DProp: s += "d_" + p.name; break;
      case BodyParam::SProp: s += "s_" + p.name; break;
    }
  }
  (void)src;
  return s + ")";
}

void Emitter::emitParams() {
  scene_ << "  struct Params {\n";
  for (const auto* p : plan_.params)
    scene_ << "    double " << p->name.name << " = 0.0;  // from " << loc(p->name.loc) << "\n";
  scene_ << "  } P;\n\n";
  // Equation instances: their parameters and constants, evaluated at set-up.
  for (const auto& eq : plan_.equations) {
    if (!eq.live) continue;
    scene_ << "  struct {";
    for (const auto& [n, v] : eq.values) scene_ << " double " << n << " = 0.0;";
    scene_ << " } " << eqStruct(eq) << ";  // " << eq.name << "(dest = " << arr(eq.dest).name
           << "), from " << loc(eq.loc) << "\n";
  }
  scene_ << "\n";
}

void Emitter::emitArraySetup(const PlanArray& a) {
  const std::string& A = a.name;
  scene_ << "    // array " << A << ", from " << loc(a.loc) << "\n    {\n";
  scene_ << "      sphc::Points pts;\n";
  auto paramNames = [&](const std::string& n) { return paramRef(n); };
  for (const auto& g : a.decl->geometry) {
    const GeometryBuilder* b = findGeometryBuilder(g.builder.name);
    std::map<std::string, std::string> args;
    for (const auto& arg : b->args)
      if (arg.defaultValue) args[arg.name] = arg.defaultValue + std::string(".0");
    for (const auto& kw : g.args)
      if (kw.value) args[kw.name.name] = exprCpp(*kw.value, paramNames);
    scene_ << "      {  // geometry " << b->name << ", from " << loc(g.builder.loc) << "\n";
    const std::string& n = b->name;
    if (n == "block" || n == "tank") {
      scene_ << "        const double lo[3] = {" << args["xmin"] << ", " << args["ymin"] << ", "
             << args["zmin"] << "};\n";
      scene_ << "        const double hi[3] = {" << args["xmax"] << ", " << args["ymax"] << ", "
             << args["zmax"] << "};\n";
      if (n == "block")
        scene_ << "        pts.append(sphc::block(DIM, lo, hi, " << args["dx"] << "));\n";
      else
        scene_ << "        pts.append(sphc::tank(DIM, lo, hi, " << args["dx"]
               << ", static_cast<int>(" << args["layers"] << "), " << args["top"]
               << " != 0.0));\n";
    } else if (n == "disk") {
      scene_ << "        pts.append(sphc::disk(" << args["cx"] << ", " << args["cy"] << ", "
             << args["r"] << ", " << args["dx"] << "));\n";
    } else if (n == "sphere") {
      scene_ << "        pts.append(sphc::sphere(" << args["cx"] << ", " << args["cy"] << ", "
             << args["cz"] << ", " << args["r"] << ", " << args["dx"] << "));\n";
    } else if (n == "cylinder") {
      scene_ << "        pts.append(sphc::cylinder(" << args["cx"] << ", " << args["cy"] << ", "
             << args["r"] << ", " << args["zmin"] << ", " << args["zmax"] << ", "
             << args["dx"] << "));\n";
    } else if (n == "line") {
      scene_ << "        const double p0[3] = {" << args["x0"] << ", " << args["y0"] << ", "
             << args["z0"] << "};\n";
      scene_ << "        const double p1[3] = {" << args["x1"] << ", " << args["y1"] << ", "
             << args["z1"] << "};\n";
      scene_ << "        pts.append(sphc::line(p0, p1, " << args["dx"] << "));\n";
    }
    scene_ << "      }\n";
  }
  // Files: positions, and the values of any property of this array that the file has.
  for (const auto& l : a.decl->loads) {
    std::string path = l.path;
    scene_ << "      {  // load \"" << path << "\", from " << loc(l.loc) << "\n";
    scene_ << "        loaded_" << A << ".push_back(sphc::load_particles(source_dir, \"" << path
           << "\", \"" << A << "\"));\n";
    scene_ << "        pts.append(sphc::positions_of(loaded_" << A << ".back()));\n";
    scene_ << "      }\n";
  }
  scene_ << "      " << A << ".name = \"" << A << "\";\n";
  for (const auto& p : a.props)
    scene_ << "      " << A << ".add_property(\"" << p.name << "\", " << propTypeEnum(p.type)
           << ", " << p.stride << ");\n";
  for (const auto* c : [&] {
         std::vector<const ast::ConstDecl*> v;
         for (const auto& c : a.decl->constants) v.push_back(&c);
         return v;
       }()) {
    scene_ << "      " << A << ".add_constant(\"" << c->name.name << "\", " << c->size << ", "
           << (c->init ? exprCpp(*c->init, paramNames) : "0.0") << ");\n";
  }
  for (const auto& c : a.constants) {
    bool declared = false;
    for (const auto& dc : a.decl->constants) declared |= dc.name.name == c;
    if (!declared)
      scene_ << "      " << A << ".add_constant(\"" << c << "\", 1, 0.0);  // reduce target\n";
  }
  scene_ << "      " << A << ".resize(pts.size());\n";
  // Initial values, particle by particle, in declaration order.
  std::vector<const PlanProperty*> inits;
  for (const auto& p : a.props)
    if (p.init) inits.push_back(&p);
  scene_ << "      for (std::size_t i = 0; i < pts.size(); ++i) {\n";
  scene_ << "        const double x = pts.x[i], y = pts.y[i], z = pts.z[i];\n";
  for (const char* c : {"x", "y", "z"})
    if (propIndex(plan_.arrayIndex(A), c) >= 0)
      scene_ << "        " << hostPtr(plan_.arrayIndex(A), c) << "[i] = " << c << ";\n";
  scene_ << "        (void)x; (void)y; (void)z;\n";
  std::set<std::string> locals = {"x", "y", "z"};
  auto initNames = [&](const std::string& n) {
    if (locals.count(n)) return n == "x" || n == "y" || n == "z" ? n : "v_" + n;
    return paramRef(n);
  };
  for (const auto* p : inits) {
    scene_ << "        const double v_" << p->name << " = " << exprCpp(*p->init, initNames)
           << ";  // from " << loc(p->declLoc) << "\n";
    for (int k = 0; k < p->stride; ++k)
      scene_ << "        " << hostPtr(plan_.arrayIndex(A), p->name) << "[i * " << p->stride
             << " + " << k << "] = static_cast<" << cppType(p->type) << ">(v_" << p->name
             << ");\n";
    locals.insert(p->name);
  }
  scene_ << "      }\n";
  if (!a.decl->loads.empty())
    scene_ << "      sphc::apply_loaded(" << A << ", pts.size(), loaded_" << A << ");\n";
  scene_ << "    }\n";
}

void Emitter::emitSetup() {
  scene_ << "  void setup(const std::vector<double>& values, sphc::SceneTimes& times) {\n";
  // Parameters in declaration order: a `param` takes its --set value if given, else its
  // default (which may use earlier ones); a `let` is always computed.
  size_t given = 0;
  for (const auto* p : plan_.params) {
    std::string value = exprCpp(*p->value, [&](const std::string& n) { return paramRef(n); });
    if (p->derived) {
      scene_ << "    P." << p->name.name << " = " << value << ";\n";
      continue;
    }
    scene_ << "    P." << p->name.name << " = std::isnan(values[" << given << "]) ? " << value
           << " : values[" << given << "];\n";
    ++given;
  }
  for (const auto& eq : plan_.equations) {
    if (!eq.live) continue;
    std::set<std::string> earlier;
    std::string s = eqStruct(eq);
    for (const auto& [n, v] : eq.values) {
      // Arguments are scene expressions; defaults and consts use the equation's own values.
      bool own = false;
      const auto* decl = plan_.equationDecls[eq.declIndex].decl;
      for (const auto& c : decl->consts) own |= c.value == v;
      for (const auto& p : decl->params) own |= p.defaultValue == v;
      auto names = [&](const std::string& x) {
        return own && earlier.count(x) ? s + "." + x : paramRef(x);
      };
      scene_ << "    " << s << "." << n << " = " << exprCpp(*v, names) << ";\n";
      earlier.insert(n);
    }
  }
  for (const auto& a : plan_.arrays) emitArraySetup(a);
  if (hasDomain()) emitDomainSetup();
  auto pn = [&](const std::string& n) { return paramRef(n); };
  scene_ << "    times.tf = " << exprCpp(*plan_.tf, pn) << ";\n";
  scene_ << "    times.dt = " << exprCpp(*plan_.dt, pn) << ";\n";
  if (plan_.outputEvery)
    scene_ << "    times.output_every = " << exprCpp(*plan_.outputEvery, pn) << ";\n";
  for (const auto& t : plan_.outputAt)
    scene_ << "    times.output_at.push_back(" << exprCpp(*t, pn) << ");\n";
  scene_ << "  }\n\n";
}

void Emitter::emitDestLocals(std::ostream& os, const std::string& indent,
                             const std::set<std::string>& q, bool device) const {
  const std::string R = device ? "real" : real_;
  // The position, all three axes: the neighbour search takes (xi, yi, zi).
  const char* axes[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k)
    os << indent << "const " << R << " " << axes[k] << "i = "
       << (k < plan_.dim ? std::string("di_") + axes[k] + "[d_idx]" : lit("0.0", device))
       << ";\n";
  os << indent << "const " << R << " hi = di_h[d_idx];\n";
  // The other vectors of which a pair quantity is a difference (VIJ: ui, vi, wi).
  for (const PairQuantity& pq : pairQuantityTable())
    if (pq.form == PairForm::Difference && pq.when != PairWhen::BeforeTest && q.count(pq.name))
      for (int k = 0; k < plan_.dim; ++k)
        os << indent << "const " << R << " " << pq.components[k] << "i = di_"
           << pq.components[k] << "[d_idx];\n";
}

void Emitter::emitCandidate(std::ostream& os, const std::set<std::string>& q,
                            const std::vector<const PlanEquation*>& loopers, int d, int s,
                            bool device) {
  const std::string R = device ? "real" : real_;
  const std::string skip = device ? "continue;" : "return;";
  const std::string indent = "            ";
  PairDialect dialect;
  dialect.real = R;
  dialect.sqrt = device ? "sqrt" : "std::sqrt";
  dialect.kernelW = device ? "kernel_w" : "Kernel::w";
  dialect.kernelGradient = device ? "kernel_gradient" : "Kernel::gradient";
  dialect.literalSuffix = lit("", device);
  os << indent << "const " << R << " hj = sj_h[s_idx];\n";
  for (const PairQuantity& pq : pairQuantityTable())
    if (pq.when == PairWhen::BeforeTest)
      os << pairQuantityStatement(pq, plan_.dim, dialect, indent);
  os << indent << "const " << R << " hmax = hi > hj ? hi : hj;\n";
  os << indent << "if (R2IJ >= RADIUS2 * hmax * hmax) " << skip << "  // not a neighbour\n";
  for (const PairQuantity& pq : pairQuantityTable())
    if (pq.when == PairWhen::EveryNeighbour || (pq.when == PairWhen::IfUsed && q.count(pq.name)))
      os << pairQuantityStatement(pq, plan_.dim, dialect, indent);
  for (const auto* eq : loopers) {
    const auto& pd = plan_.equationDecls[eq->declIndex];
    const PlanBody& b = plan_.bodies[pd.methods.at(ast::Method::Loop)];
    os << "            " << callBody(bodyFunctionName(eq->name, "loop"), b, d, s,
                                         eqStruct(*eq), "t", device ? "_" : ".")
           << ";  // " << eq->name << ", from " << loc(eq->loc) << "\n";
  }
}

std::vector<const PlanEquation*> Emitter::destEquations(const std::vector<int>& eqIds,
                                                        int d) const {
  std::vector<const PlanEquation*> eqs;
  for (int e : eqIds)
    if (plan_.equations[e].live && plan_.equations[e].dest == d)
      eqs.push_back(&plan_.equations[e]);
  return eqs;
}

std::vector<const PlanEquation*> Emitter::withMethod(const std::vector<const PlanEquation*>& eqs,
                                                     ast::Method::Kind kind) const {
  std::vector<const PlanEquation*> with;
  for (const auto* eq : eqs)
    if (plan_.equationDecls[eq->declIndex].methods.count(kind)) with.push_back(eq);
  return with;
}

std::vector<Emitter::NeighbourPass> Emitter::neighbourPasses(
    const std::vector<const PlanEquation*>& eqs, int d, const PlanGroup* group) {
  std::vector<int> sources;
  for (const auto* eq : withMethod(eqs, ast::Method::Loop))
    for (int s : eq->sources)
      if (std::find(sources.begin(), sources.end(), s) == sources.end()) sources.push_back(s);
  std::vector<NeighbourPass> passes;
  for (int s : sources) {
    sourceArrays_.insert(arr(s).name);
    loopArrays_.insert(arr(s).name);
    loopArrays_.insert(arr(d).name);
    NeighbourPass pass;
    pass.s = s;
    if (group) {
      auto it = group->pairQuantities.find({d, s});
      if (it != group->pairQuantities.end()) pass.q = it->second;
    }
    pass.q = pairQuantityClosure(pass.q);
    for (const auto* eq : withMethod(eqs, ast::Method::Loop)) {
      if (std::find(eq->sources.begin(), eq->sources.end(), s) == eq->sources.end()) continue;
      pass.loopers.push_back(eq);
      const PlanBody& b =
          plan_.bodies[plan_.equationDecls[eq->declIndex].methods.at(ast::Method::Loop)];
      for (const auto& r : b.facts.sReads) pass.sprops.insert(r.prop);
    }
    for (const auto& p : pairQuantityProps(plan_.dim, pass.q)) pass.need.insert(p);
    passes.push_back(std::move(pass));
  }
  return passes;
}

// One fused evaluation of a list of equations, as PySPH's Group: per destination, every
// initialize, one neighbour pass per source with every loop, then post_loop and reduce.
void Emitter::emitPhase(const std::vector<int>& eqIds, const std::string& name) {
  std::vector<int> dests;
  for (int e : eqIds) {
    const auto& eq = plan_.equations[e];
    if (eq.live && std::find(dests.begin(), dests.end(), eq.dest) == dests.end())
      dests.push_back(eq.dest);
  }
  const PlanGroup* group = nullptr;
  std::function<const PlanGroup*(const PlanGroup&)> findGroup = [&](const PlanGroup& g) {
    for (int e : g.equations)
      if (e == eqIds.front()) return &g;
    for (const auto& sub : g.subgroups)
      if (auto* r = findGroup(*sub)) return r;
    return static_cast<const PlanGroup*>(nullptr);
  };
  if (!eqIds.empty()) group = findGroup(plan_.root);
  scene_ << "  void " << name << "(double t, double dt) {\n";
  scene_ << "    (void)t; (void)dt;\n";
  for (int d : dests) {
    const std::string& D = arr(d).name;
    std::vector<const PlanEquation*> eqs = destEquations(eqIds, d);
    // Groups with `real = false` run on the ghosts too (they follow the real particles).
    const bool onGhosts = group && !group->real && hasGhosts(d);
    scene_ << "    {  // destination " << D << "\n";
    scene_ << "      const int n = static_cast<int>(" << D << ".n"
           << (onGhosts ? " + ghosts_" + D + ".size()" : std::string("")) << ");"
           << (onGhosts ? "  // real particles and ghosts (real = false)" : "") << "\n";
    if (opencl_) {
      emitDestinationDevice(d, eqs, group, name, onGhosts);
      emitGhostRefresh(d, eqs, onGhosts);
      scene_ << "    }\n";
      continue;
    }
    // Pointers of every destination property the bodies use.
    std::set<std::string> dprops;
    for (const auto* eq : eqs)
      for (const auto& [k, b] : plan_.equationDecls[eq->declIndex].methods) {
        for (const auto& r : plan_.bodies[b].facts.dReads) dprops.insert(r.prop);
        for (const auto& w : plan_.bodies[b].facts.dWrites) dprops.insert(w.prop);
      }
    for (const auto& p : dprops) {
      int c = constIndex(d, p);
      (void)c;
      scene_ << "      " << hostType(d, p) << "* d_" << p << " = " << propPtr(d, p) << ";\n";
    }
    auto perParticle = [&](ast::Method::Kind kind, const char* what) {
      std::vector<const PlanEquation*> with = withMethod(eqs, kind);
      if (with.empty()) return;
      scene_ << parallelFor("      ");
      scene_ << "      for (int d_idx = 0; d_idx < n; ++d_idx) {  // " << what << "\n";
      for (const auto* eq : with) {
        const auto& pd = plan_.equationDecls[eq->declIndex];
        const PlanBody& b = plan_.bodies[pd.methods.at(kind)];
        scene_ << "        "
               << callBody(bodyFunctionName(eq->name, what), b, d, -1, eqStruct(*eq), "t")
               << ";  // " << eq->name << ", from " << loc(eq->loc) << "\n";
      }
      scene_ << "      }\n";
    };
    perParticle(ast::Method::Initialize, "initialize");
    // One neighbour pass per source.
    for (const NeighbourPass& pass : neighbourPasses(eqs, d, group)) {
      const int s = pass.s;
      const std::string& S = arr(s).name;
      const std::set<std::string>& q = pass.q;
      scene_ << "      {  // neighbours: " << D << " <- " << S << "\n";
      for (const auto& p : pass.need) {
        scene_ << "        const " << real_ << "* di_" << p << " = " << propPtr(d, p) << ";\n";
        scene_ << "        const " << real_ << "* sj_" << p << " = " << propPtr(s, p) << ";\n";
      }
      for (const auto& p : pass.sprops)
        scene_ << "        const " << hostType(s, p) << "* s_" << p << " = " << propPtr(s, p)
               << ";\n";
      scene_ << "        const sphc::CellList& cells = cells_" << S << ";\n";
      // Each thread works on its own copies of the array pointers and scalars
      // (default(firstprivate)): shared, the outlined loop reads them through the
      // captured frame at every neighbour, ~4% slower than the serial build (dam break,
      // ~100k particles, 1 thread). The cell list stays shared: a copy would be a waste.
      scene_ << parallelFor("        ", "default(firstprivate) shared(cells)");
      scene_ << "        for (int d_idx = 0; d_idx < n; ++d_idx) {\n";
      emitDestLocals(scene_, "          ", q, false);
      scene_ << "          cells.for_each_candidate(xi, yi, zi, [&](std::uint32_t j) {\n";
      scene_ << "            const int s_idx = static_cast<int>(j);\n";
      emitCandidate(scene_, q, pass.loopers, d, s, false);
      scene_ << "          });\n        }\n      }\n";
    }
    perParticle(ast::Method::PostLoop, "post_loop");
    // Reductions over the destination array into its constants.
    for (const auto* eq : withMethod(eqs, ast::Method::Reduce)) {
      const auto& pd = plan_.equationDecls[eq->declIndex];
      const PlanBody& b = plan_.bodies[pd.methods.at(ast::Method::Reduce)];
      // mean: the sum, divided by the number of particles (0 for an empty array).
      const bool sum = pd.reduceOp == "sum" || pd.reduceOp == "mean";
      std::string init = sum ? "0.0"
                         : pd.reduceOp == "max" ? "-HUGE_VAL"
                                                : "HUGE_VAL";
      std::string combine = sum ? "acc += v"
                             : pd.reduceOp == "max" ? "acc = v > acc ? v : acc"
                                                    : "acc = v < acc ? v : acc";
      scene_ << "      {  // reduce " << pd.reduceOp << " into " << D << "." << pd.reduceTarget
             << ": " << eq->name << ", from " << loc(eq->loc) << "\n";
      scene_ << "        " << real_ << " acc = " << init << ";\n";
      // Reductions see the real particles only (never the ghosts of a non-real group).
      const std::string nReal =
          onGhosts ? "static_cast<int>(" + D + ".n)" : std::string("n");
      const std::string value =
          callBody(bodyFunctionName(eq->name, "reduce"), b, d, -1, eqStruct(*eq), "t");
      if (openmp_ && sum) {
        // A sum in the serial order, so that the result (and an iteration count that a
        // convergence test derives from it) is bitwise the serial one: the values in
        // parallel, the sum on one thread (n additions, cheap next to a neighbour pass).
        const std::string loopHead = "        for (int d_idx = 0; d_idx < " + nReal +
                                     "; ++d_idx)" +
                                     (onGhosts ? "  // real particles only" : "") + "\n";
        scene_ << "        std::vector<" << real_ << ">& values = reduce_scratch;\n";
        scene_ << "        values.resize(" << nReal << ");\n";
        scene_ << parallelFor("        ");
        scene_ << loopHead;
        scene_ << "          values[d_idx] = " << value << ";\n";
        scene_ << loopHead << "          acc += values[d_idx];\n";
        if (pd.reduceOp == "mean")
          scene_ << "        acc = " << nReal << " > 0 ? acc / " << nReal << " : 0.0;\n";
      } else {
        scene_ << parallelFor("        ", std::string("reduction(") +
                                               (sum ? "+" : pd.reduceOp) + " : acc)");
        scene_ << "        for (int d_idx = 0; d_idx < " << nReal << "; ++d_idx) {"
               << (onGhosts ? "  // real particles only" : "") << "\n";
        scene_ << "          const " << real_ << " v = " << value << ";\n          " << combine
               << ";\n        }\n";
        if (pd.reduceOp == "mean")
          scene_ << "        acc = " << nReal << " > 0 ? acc / " << nReal << " : 0.0;\n";
      }
      scene_ << "        " << propPtr(d, pd.reduceTarget) << "[0] = acc;\n      }\n";
    }
    emitGhostRefresh(d, eqs, onGhosts);
    scene_ << "    }\n";
  }
  scene_ << "  }\n\n";
}

// Ghosts copy the values a phase computed on the real particles, where they carry them.
void Emitter::emitGhostRefresh(int d, const std::vector<const PlanEquation*>& eqs,
                               bool onGhosts) {
  if (!hasGhosts(d) || onGhosts) return;
  const std::string& D = arr(d).name;
  std::set<std::string> written;
  for (const auto* eq : eqs)
    for (const auto& [k, b] : plan_.equationDecls[eq->declIndex].methods)
      for (const auto& w : plan_.bodies[b].facts.dWrites) written.insert(w.prop);
  std::vector<std::string> refresh;
  for (const auto& p : arr(d).ghostProps)
    if (written.count(p)) refresh.push_back(p);
  if (refresh.empty()) return;
  scene_ << "      // ghosts follow:";
  for (const auto& p : refresh) scene_ << " " << p;
  if (opencl_)
    scene_ << "\n      ghosts_" << D << ".refresh(ocl, box, " << D << ", dev_" << D << ", "
           << propIndexList(d, refresh) << ");\n";
  else
    scene_ << "\n      sphc::refresh_ghosts(box, " << hostData(d) << ", ghosts_" << D << ", "
           << propIndexList(d, refresh) << ");\n";
}

// ---- --backend=opencl ----------------------------------------------------------------------
// The same phases as the C++ loops above, as kernels: one work item per destination particle
// (a gather, as the OpenMP loops), a kernel per group phase, destination and method, and per
// neighbour pass (destination <- source). Only the buffers and scalars the bodies use are
// arguments. Host code launches them; particle data stays on the device.

std::string Emitter::devType(int a, const std::string& p) const {
  if (constIndex(a, p) >= 0) return "real";
  const PlanProperty* pp = arr(a).find(p);
  if (pp && pp->type == "int") return "int";
  if (pp && pp->type == "uint") return "uint";
  return "real";
}

std::string Emitter::devBuffer(int a, const std::string& p) const {
  int c = constIndex(a, p);
  if (c >= 0) return "dev_" + arr(a).name + ".constant(" + std::to_string(c) + ")";
  int i = propIndex(a, p);
  if (i < 0) SPHC_INTERNAL("property '" + p + "' of '" + arr(a).name + "' was not allocated");
  return "dev_" + arr(a).name + ".prop(" + std::to_string(i) + ")";
}

void Emitter::addBodyArgs(KernelArgs& ka, const PlanBody& b, int dest, int src,
                          const std::string& eqValues) const {
  for (const auto& p : bodyParams(b, dest, true)) {
    switch (p.kind) {
      case BodyParam::Scalar:
        ka.add("const real " + eqValues + "_" + p.name, eqValues + "." + p.name,
               eqValues + "." + p.name);
        break;
      case BodyParam::DProp: ka.add(p.decl, devBuffer(dest, p.name), "d_" + p.name); break;
      case BodyParam::SProp:
        ka.add("__global const " + devType(src, p.name) + "* s_" + p.name,
               devBuffer(src, p.name), "s_" + p.name);
        break;
      default: break;
    }
  }
}

void Emitter::beginKernel(const std::string& name, const KernelArgs& ka, bool guard) {
  cl_ << "__kernel void " << name << "(const int n, const real t, const real dt";
  for (const auto& d : ka.decls) cl_ << ",\n    " << d;
  cl_ << ") {\n";
  if (guard) cl_ << "  const int d_idx = get_global_id(0);\n  if (d_idx >= n) return;\n";
}

std::string Emitter::launch(const std::string& name, const std::string& n,
                            const KernelArgs& ka) const {
  std::string s = "ocl.run(\"" + name + "\", " + n + ", " + n + ", t, dt";
  for (const auto& h : ka.host) s += ", " + h;
  return s + ");";
}

void Emitter::emitDestinationDevice(int d, const std::vector<const PlanEquation*>& eqs,
                                    const PlanGroup* group, const std::string& name,
                                    bool onGhosts) {
  const std::string& D = arr(d).name;
  auto perParticle = [&](ast::Method::Kind kind, const char* what) {
    std::vector<const PlanEquation*> with = withMethod(eqs, kind);
    if (with.empty()) return;
    KernelArgs ka;
    for (const auto* eq : with)
      addBodyArgs(ka, plan_.bodies[plan_.equationDecls[eq->declIndex].methods.at(kind)], d,
                  -1, eqStruct(*eq));
    std::string k = name + "_" + D + "_" + what;
    beginKernel(k, ka);
    for (const auto* eq : with) {
      const auto& pd = plan_.equationDecls[eq->declIndex];
      const PlanBody& b = plan_.bodies[pd.methods.at(kind)];
      cl_ << "  " << callBody(bodyFunctionName(eq->name, what), b, d, -1, eqStruct(*eq), "t", "_")
          << ";  // " << eq->name << ", from " << loc(eq->loc) << "\n";
    }
    cl_ << "}\n\n";
    scene_ << "      " << launch(k, "n", ka) << "  // " << what << "\n";
  };
  perParticle(ast::Method::Initialize, "initialize");
  for (const NeighbourPass& pass : neighbourPasses(eqs, d, group)) {
    const int s = pass.s;
    const std::string& S = arr(s).name;
    const std::set<std::string>& q = pass.q;
    KernelArgs ka;
    for (const auto* eq : pass.loopers)
      addBodyArgs(ka, plan_.bodies[plan_.equationDecls[eq->declIndex].methods.at(
                          ast::Method::Loop)],
                  d, s, eqStruct(*eq));
    for (const auto& p : pass.need) {
      ka.add("__global const real* di_" + p, devBuffer(d, p), "di_" + p);
      ka.add("__global const real* sj_" + p, devBuffer(s, p), "sj_" + p);
    }
    ka.add("SPHC_CELLS_ARGS(cells)", "cells_" + S, "cells");
    ka.add("SPHC_GRID_ARGS", "grid", "grid");
    std::string k = name + "_" + D + "_from_" + S;
    cl_ << "// neighbours: " << D << " <- " << S << "\n";
    beginKernel(k, ka);
    emitDestLocals(cl_, "  ", q, true);
    // The 3^dim cells around the particle's cell, by z, y, x (the CPU candidate order).
    const char* axes[3] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a)
      cl_ << "  const int c" << axes[a] << " = "
          << (a < plan_.dim ? std::string("sphc_axis_cell((") + axes[a] + "i - grid_lo" +
                                  axes[a] + ") * grid_inv, grid_n" + axes[a] + ")"
                            : std::string("0"))
          << ";\n";
    cl_
        << "  for (int kz = max(cz - 1, 0); kz <= min(cz + 1, grid_nz - 1); ++kz)\n"
        << "  for (int ky = max(cy - 1, 0); ky <= min(cy + 1, grid_ny - 1); ++ky)\n"
        << "  for (int kx = max(cx - 1, 0); kx <= min(cx + 1, grid_nx - 1); ++kx) {\n"
        << "    const int cell = (kz * grid_ny + ky) * grid_nx + kx;\n"
        << "    for (uint k = cells_start[cell]; k < cells_end[cell]; ++k) {\n"
        << "            const int s_idx = (int)cells_order[k];\n";
    emitCandidate(cl_, q, pass.loopers, d, s, true);
    cl_ << "    }\n  }\n}\n\n";
    scene_ << "      " << launch(k, "n", ka) << "  // neighbours: " << D << " <- " << S << "\n";
  }
  perParticle(ast::Method::PostLoop, "post_loop");
  // Reductions: per-particle values on the device, partial results there, the last step
  // on the host, into the host copy of the constant (uploaded again).
  for (const auto* eq : withMethod(eqs, ast::Method::Reduce)) {
    const auto& pd = plan_.equationDecls[eq->declIndex];
    const PlanBody& b = plan_.bodies[pd.methods.at(ast::Method::Reduce)];
    KernelArgs ka;
    addBodyArgs(ka, b, d, -1, eqStruct(*eq));
    // Reductions see the real particles only (never the ghosts of a non-real group).
    const std::string nReal = onGhosts ? "static_cast<int>(" + D + ".n)" : std::string("n");
    ka.add("__global real* reduce_values", "ocl.scratch(" + nReal + ")", "reduce_values");
    std::string k = name + "_" + D + "_reduce_" + std::to_string(eq->id);
    beginKernel(k, ka);
    cl_ << "  reduce_values[d_idx] = "
        << callBody(bodyFunctionName(eq->name, "reduce"), b, d, -1, eqStruct(*eq), "t", "_")
        << ";  // " << eq->name << ", from " << loc(eq->loc) << "\n}\n\n";
    int c = constIndex(d, pd.reduceTarget);
    std::string op = pd.reduceOp == "sum" || pd.reduceOp == "mean" ? "Sum"
                     : pd.reduceOp == "max"                         ? "Max"
                                                                    : "Min";
    scene_ << "      {  // reduce " << pd.reduceOp << " into " << D << "." << pd.reduceTarget
           << ": " << eq->name << ", from " << loc(eq->loc) << "\n";
    scene_ << "        " << launch(k, nReal, ka) << (onGhosts ? "  // real particles only" : "")
           << "\n";
    scene_ << "        " << D << ".constant(" << c << ")[0] = ocl.reduce(ocl.scratch(" << nReal
           << "), " << nReal << ", sphc::ocl::Op::" << op << ")"
           << (pd.reduceOp == "mean" ? " / (" + nReal + " > 0 ? " + nReal + " : 1)" : "")
           << ";\n";
    scene_ << "        dev_" << D << ".upload_constant(ocl, " << D << ", " << c << ");\n";
    scene_ << "      }\n";
  }
}

void Emitter::emitGroup(const PlanGroup& g, const std::string& name) {
  // Runs of direct equations become fused phases; subgroups run in place, in order.
  std::vector<std::string> calls;
  std::vector<int> run;
  int part = 0;
  auto flush = [&] {
    if (run.empty()) return;
    std::string fn = name + "_" + std::to_string(part++);
    emitPhase(run, fn);
    calls.push_back(fn);
    run.clear();
  };
  for (int entry : g.order) {
    if (entry >= 0) {
      run.push_back(g.equations[entry]);
      continue;
    }
    flush();
    std::string fn = name + "_" + std::to_string(part++);
    const PlanGroup& sub = *g.subgroups[-entry - 1];
    emitGroup(sub, fn);
    // A post_step group (top level only) runs after the time step, not with the others.
    (sub.postStep ? postStepCalls_ : calls).push_back(fn);
    if (sub.postStep && sub.every) postStepDue_.push_back(fn + "_due()");
    if (sub.postStep && !sub.every) postStepDue_.push_back("true");
  }
  flush();
  // The convergence tests of an iterated group: the `converged` of its equations and of those
  // in its subgroups, at any depth (as PySPH's Group), except inside a nested iterated group,
  // which tests its own.
  std::vector<const PlanEquation*> convergers;
  std::function<void(const PlanGroup&)> collect = [&](const PlanGroup& grp) {
    for (int entry : grp.order) {
      if (entry < 0) {
        const PlanGroup& sub = *grp.subgroups[-entry - 1];
        if (!sub.iterate) collect(sub);
        continue;
      }
      const auto& eq = plan_.equations[grp.equations[entry]];
      if (eq.live && plan_.equationDecls[eq.declIndex].methods.count(ast::Method::Converged))
        convergers.push_back(&eq);
    }
  };
  collect(g);
  scene_ << "  // group, from " << loc(g.loc) << "\n";
  if (g.every) {
    // `every = N`: only when the number of completed steps is a multiple of N (N < 1: never).
    auto pn = [&](const std::string& n) { return paramRef(n); };
    scene_ << "  bool " << name << "_due() const {\n"
           << "    const long every = static_cast<long>(std::floor(" << exprCpp(*g.every, pn)
           << " + 0.5));\n"
           << "    return every >= 1 && step_count % every == 0;\n  }\n\n";
  }
  scene_ << "  void " << name << "(double t, double dt) {\n";
  if (g.every) scene_ << "    if (!" << name << "_due()) return;\n";
  if (!g.iterate) {
    for (const auto& c : calls) scene_ << "    " << c << "(t, dt);\n";
    scene_ << "    (void)t; (void)dt;\n  }\n\n";
    return;
  }
  const int statsIndex = static_cast<int>(iteratedGroups_.size());
  iteratedGroups_.push_back(loc(g.loc));
  scene_ << "    int iteration = 1;\n    bool converged = true;\n";
  scene_ << "    for (;; ++iteration) {\n";
  for (const auto& c : calls) scene_ << "      " << c << "(t, dt);\n";
  scene_ << "      converged = true;\n";
  for (const auto* eq : convergers) {
    const auto& pd = plan_.equationDecls[eq->declIndex];
    const PlanBody& b = plan_.bodies[pd.methods.at(ast::Method::Converged)];
    scene_ << "      {\n        const int d_idx = 0;\n";
    std::set<std::string> dprops, written;
    for (const auto& r : b.facts.dReads) dprops.insert(r.prop);
    // It may write array constants (its state; analysis/Properties.cpp refuses particle
    // properties): on OpenCL they go to the device after the test.
    for (const auto& w : b.facts.dWrites) written.insert(w.prop);
    dprops.insert(written.begin(), written.end());
    // OpenCL: the test runs on the host; constants are current there, properties are not.
    bool needsProps = false;
    for (const auto& p : dprops) needsProps |= constIndex(eq->dest, p) < 0;
    if (opencl_ && needsProps)
      scene_ << "        dev_" << arr(eq->dest).name << ".download(ocl, " << arr(eq->dest).name
             << ");\n";
    for (const auto& p : dprops)
      scene_ << "        " << hostType(eq->dest, p) << "* d_" << p << " = "
             << propPtr(eq->dest, p) << ";\n";
    scene_ << "        converged = converged && "
           << callBody(bodyFunctionName(eq->name, "converged"), b, eq->dest, -1,
                       eqStruct(*eq), "t")
           << " > 0;  // " << eq->name << ", from " << loc(eq->loc) << "\n";
    if (opencl_)
      for (const auto& p : written)
        if (int c = constIndex(eq->dest, p); c >= 0)
          scene_ << "        dev_" << arr(eq->dest).name << ".upload_constant(ocl, "
                 << arr(eq->dest).name << ", " << c << ");\n";
    scene_ << "      }\n";
  }
  scene_ << "      if (converged && iteration >= " << g.minIterations << ") break;\n";
  scene_ << "      if (iteration >= " << g.maxIterations << ") break;\n";
  scene_ << "    }\n";
  scene_ << "    iteration_stats[" << statsIndex << "].record(iteration, converged);\n  }\n\n";
  groupFunctions_.push_back(name);
}

void Emitter::emitSteppers() {
  if (!opencl_) {
    emitStepperRuns();
    return;
  }
  std::set<std::string> methods;
  for (const auto& a : plan_.arrays)
    if (a.stepper >= 0)
      for (const auto& [m, b] : plan_.steppers[a.stepper].methods) methods.insert(m);
  for (const auto& m : methods) {
    scene_ << "  void stepper_" << m << "(double t, double dt) {\n    (void)t; (void)dt;\n";
    for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a) {
      const PlanArray& A = arr(a);
      if (A.stepper < 0) continue;
      const PlanStepper& st = plan_.steppers[A.stepper];
      auto it = st.methods.find(m);
      if (it == st.methods.end()) continue;
      const PlanBody& b = plan_.bodies[it->second];
      scene_ << "    {  // " << A.name << ": " << st.decl->name.name << "." << m << "\n";
      scene_ << "      const int n = static_cast<int>(" << A.name << ".n);\n";
      std::string fn = bodyFunctionName(st.decl->name.name, m);
      if (opencl_) {
        KernelArgs ka;
        addBodyArgs(ka, b, a, -1, "");
        std::string k = "stepper_" + m + "_" + A.name;
        beginKernel(k, ka);
        cl_ << "  " << callBody(fn, b, a, -1, "", "t", "_") << ";\n}\n\n";
        scene_ << "      " << launch(k, "n", ka) << "\n    }\n";
        continue;
      }
      std::set<std::string> dprops;
      for (const auto& r : b.facts.dReads) dprops.insert(r.prop);
      for (const auto& w : b.facts.dWrites) dprops.insert(w.prop);
      for (const auto& p : dprops)
        scene_ << "      " << hostType(a, p) << "* d_" << p << " = " << propPtr(a, p) << ";\n";
      scene_ << parallelFor("      ");
      scene_ << "      for (int d_idx = 0; d_idx < n; ++d_idx)\n";
      scene_ << "        " << callBody(fn, b, a, -1, "", "t") << ";\n    }\n";
    }
    scene_ << "  }\n\n";
  }
}

std::vector<std::vector<size_t>> Emitter::stepperRuns() const {
  std::vector<std::vector<size_t>> runs;
  bool open = false;
  for (size_t k = 0; k < plan_.integratorSteps.size(); ++k) {
    if (!isStepperStatement(plan_.integratorSteps[k])) {
      open = false;
      continue;
    }
    if (!open) runs.emplace_back();
    runs.back().push_back(k);
    open = true;
  }
  return runs;
}

// Steppers are per particle (a body reads and writes its own particle d_idx only, as the
// parallel loops of the OpenMP backend already require), so running the methods of a run
// one after the other on each particle, in one pass, gives what running each method on all
// particles in turn gives, bit for bit, with less memory traffic (PECIntegrator's
// initialize and stage1 both read and write x, u, rho, ...). The arrays' passes share one
// parallel region (`omp for nowait`: each array's particles are its own).
void Emitter::emitStepperRuns() {
  std::set<std::string> emitted;
  for (const auto& run : stepperRuns()) {
    const std::string name = stepperRunName(run);
    if (!emitted.insert(name).second) continue;
    struct Part {
      int a;
      const PlanStepper* st;
      std::vector<std::pair<size_t, const PlanBody*>> bodies;  // (position in run, body)
    };
    std::vector<Part> parts;
    for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a) {
      const PlanArray& A = arr(a);
      if (A.stepper < 0) continue;
      Part part{a, &plan_.steppers[A.stepper], {}};
      for (size_t k = 0; k < run.size(); ++k) {
        auto it = part.st->methods.find(plan_.integratorSteps[run[k]]);
        if (it != part.st->methods.end()) part.bodies.push_back({k, &plan_.bodies[it->second]});
      }
      if (!part.bodies.empty()) parts.push_back(part);
    }
    if (parts.empty()) continue;
    scene_ << "  void " << name << "(";
    for (size_t k = 0; k < run.size(); ++k) scene_ << "double t_" << k << ", ";
    scene_ << "double dt) {\n   ";
    for (size_t k = 0; k < run.size(); ++k) scene_ << " (void)t_" << k << ";";
    scene_ << " (void)dt;\n";
    if (openmp_) scene_ << "    #pragma omp parallel\n";
    scene_ << "    {\n";
    for (const Part& part : parts) {
      const PlanArray& A = arr(part.a);
      scene_ << "      {  // " << A.name << ": " << part.st->decl->name.name;
      for (size_t i = 0; i < part.bodies.size(); ++i)
        scene_ << (i ? ", " : ".") << plan_.integratorSteps[run[part.bodies[i].first]];
      scene_ << "\n        const int n = static_cast<int>(" << A.name << ".n);\n";
      std::set<std::string> dprops;
      for (const auto& [k, b] : part.bodies) {
        for (const auto& r : b->facts.dReads) dprops.insert(r.prop);
        for (const auto& w : b->facts.dWrites) dprops.insert(w.prop);
      }
      for (const auto& p : dprops)
        scene_ << "        " << hostType(part.a, p) << "* d_" << p << " = " << propPtr(part.a, p)
               << ";\n";
      if (openmp_) scene_ << "        #pragma omp for schedule(static) nowait\n";
      scene_ << "        for (int d_idx = 0; d_idx < n; ++d_idx) {\n";
      for (const auto& [k, b] : part.bodies) {
        const std::string m = plan_.integratorSteps[run[k]];
        scene_ << "          "
               << callBody(bodyFunctionName(part.st->decl->name.name, m), *b, part.a, -1, "",
                           "t_" + std::to_string(k))
               << ";\n";
      }
      scene_ << "        }\n      }\n";
    }
    scene_ << "    }\n  }\n\n";
  }
}

std::string Emitter::propIndexList(int a, const std::vector<std::string>& props) const {
  std::string s = "{";
  for (size_t k = 0; k < props.size(); ++k) {
    int i = propIndex(a, props[k]);
    if (i < 0) SPHC_INTERNAL("ghost property '" + props[k] + "' of '" + arr(a).name +
                             "' was not allocated");
    s += (k ? ", " : "") + std::to_string(i);
  }
  return s + "}";
}

void Emitter::emitDomainSetup() {
  const PlanDomain& dom = plan_.domain;
  auto pn = [&](const std::string& n) { return paramRef(n); };
  static const char* kAxes[3] = {"x", "y", "z"};
  scene_ << "    // domain, from " << loc(dom.loc) << "\n";
  scene_ << "    box.dim = DIM;\n";
  for (int a = 0; a < 3; ++a)
    for (int side = 0; side < 2; ++side) {
      const PlanBoundary& b = side == 0 ? dom.lo[a] : dom.hi[a];
      if (b.kind == PlanBoundary::Open) continue;
      const std::string which = side == 0 ? "lo" : "hi";
      scene_ << "    box." << which << "_kind[" << a << "] = sphc::Boundary::"
             << (b.kind == PlanBoundary::Periodic ? "Periodic" : "Mirror") << ";  // "
             << kAxes[a] << ", from " << loc(b.loc) << "\n";
      scene_ << "    box." << which << "[" << a << "] = " << exprCpp(*b.at, pn) << ";\n";
    }
  scene_ << "    sphc::check_domain(box);\n";
}

void Emitter::emitSearchDomain() {
  if (cpuSingle_) {
    // The search domain spans every array that takes part in a neighbour loop (float data).
    const char* axes[3] = {"x", "y", "z"};
    scene_ << "    domain = sphc::make_search_domain_float({";
    bool first = true;
    for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a) {
      if (!loopArrays_.count(arr(a).name)) continue;
      scene_ << (first ? "" : ",\n                                             ") << "{";
      for (int k = 0; k < 3; ++k)
        scene_ << (k < plan_.dim ? propPtr(a, axes[k]) : std::string("nullptr")) << ", ";
      scene_ << propPtr(a, "h") << ", " << arr(a).name << ".n}";
      first = false;
    }
    scene_ << "}, DIM, Kernel::radius_scale);\n";
    return;
  }
  // The search domain spans every array that takes part in a neighbour loop.
  scene_ << "    const std::vector<const sphc::ParticleArray*> all = {";
  bool first = true;
  for (const auto& a : plan_.arrays) {
    if (!loopArrays_.count(a.name)) continue;
    scene_ << (first ? "" : ", ") << "&" << a.name;
    first = false;
  }
  scene_ << "};\n";
  scene_ << "    domain = sphc::make_search_domain(all, DIM, Kernel::radius_scale);\n";
}

std::string Emitter::cellListBuild(const std::string& S, const std::string& count) const {
  const char* axes[3] = {"x", "y", "z"};
  const int s = plan_.arrayIndex(S);
  std::string b = "cells_" + S + (opencl_ ? ".build(ocl, grid" : ".build(domain");
  for (int k = 0; k < 3; ++k)
    b += ", " + (k >= plan_.dim ? std::string("nullptr")
                 : opencl_      ? devBuffer(s, axes[k])
                                : propPtr(s, axes[k]));
  return b + ", " + count + ");";
}

// update_neighbours of a scene with a periodic or mirror domain: the search domain of the
// real particles, the cell-order permutation (of real particles), then the ghosts of every
// source array, and the cell lists over real particles and ghosts.
void Emitter::emitUpdateNeighboursWithGhosts() {
  if (loopArrays_.empty()) return;
  emitSearchDomain();
  if (sourceArrays_.empty()) return;
  scene_ << "    // Every REORDER_EVERY builds the real particles are sorted in cell order.\n";
  scene_ << "    if (builds++ % REORDER_EVERY == 0) {\n";
  for (const auto& S : sourceArrays_)
    scene_ << "      " << cellListBuild(S, S + ".n") << "\n      " << permuteInCellOrder(S) << "\n";
  scene_ << "    }\n";
  scene_ << "    // Ghosts within the largest interaction radius of a periodic or mirror side.\n";
  scene_ << "    const double cutoff = domain.cell_size;\n";
  for (const auto& S : sourceArrays_) {
    int s = plan_.arrayIndex(S);
    scene_ << "    sphc::add_ghosts(box, " << hostData(s) << ", cutoff, ghosts_" << S << ", "
           << propIndexList(s, arr(s).ghostProps) << ");  //";
    for (const auto& p : arr(s).ghostProps) scene_ << " " << p;
    scene_ << "\n";
  }
  scene_ << "    sphc::extend_for_ghosts(domain, box, cutoff);\n";
  for (const auto& S : sourceArrays_)
    scene_ << "    " << cellListBuild(S, S + ".n + ghosts_" + S + ".size()") << "\n";
}

std::string Emitter::removeGhosts() const {
  std::string r;
  for (const auto& S : sourceArrays_)
    r += opencl_ ? "    ghosts_" + S + ".remove();\n"
                 : "    sphc::remove_ghosts(" + hostData(plan_.arrayIndex(S)) + ", ghosts_" + S +
                           ");\n";
  return r;
}

std::string Emitter::deviceExtents(const std::string& indent) const {
  const char* axes[3] = {"x", "y", "z"};
  auto buf = [&](int a, int k) {
    return k < plan_.dim ? devBuffer(a, axes[k]) : std::string("nullptr");
  };
  std::string r = "{";
  bool first = true;
  for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a) {
    if (!loopArrays_.count(arr(a).name)) continue;
    r += (first ? "" : ",\n" + indent) + "{" + buf(a, 0) + ", " + buf(a, 1) + ", " + buf(a, 2) +
         ", " + devBuffer(a, "h") + ", " + arr(a).name + ".n}";
    first = false;
  }
  return r + "}";
}

// The same on the device (--backend=opencl): the search domain of the real particles from
// device reductions, the cell-order permutation of the real particles on the device, then the
// ghost list of every source found on the host from its downloaded positions (the CPU's
// find_ghosts, so the same ghosts in the same order), the ghost slots filled on the device,
// and the cell tables over real particles and ghosts on the widened grid.
void Emitter::emitUpdateNeighboursWithGhostsDevice() {
  if (loopArrays_.empty()) return;
  scene_ << "    sphc::SearchDomain domain = ocl.search_domain(" << deviceExtents("        ")
         << ", DIM, Kernel::radius_scale);\n";
  scene_ << "    grid = ocl.grid_of(domain);\n";
  if (sourceArrays_.empty()) return;
  scene_ << "    // Every REORDER_EVERY builds the real particles are sorted in cell order.\n";
  scene_ << "    if (builds++ % REORDER_EVERY == 0) {\n";
  for (const auto& S : sourceArrays_)
    scene_ << "      " << cellListBuild(S, S + ".n") << "\n      dev_" << S
           << ".permute(ocl, cells_" << S << ", " << S << ");\n";
  scene_ << "    }\n";
  scene_ << "    // Ghosts within the largest interaction radius of a periodic or mirror side.\n";
  scene_ << "    const double cutoff = domain.cell_size;\n";
  for (const auto& S : sourceArrays_) {
    int s = plan_.arrayIndex(S);
    scene_ << "    ghosts_" << S << ".add(ocl, box, " << S << ", dev_" << S << ", cutoff, "
           << propIndexList(s, arr(s).ghostProps) << ");  //";
    for (const auto& p : arr(s).ghostProps) scene_ << " " << p;
    scene_ << "\n";
  }
  scene_ << "    sphc::extend_for_ghosts(domain, box, cutoff);\n";
  scene_ << "    grid = ocl.grid_of(domain);\n";
  for (const auto& S : sourceArrays_)
    scene_ << "    " << cellListBuild(S, S + ".n + ghosts_" + S + ".size()") << "\n";
}

// update_neighbours and compute_accelerations of a scene without periodic or mirror domain.
void Emitter::emitUpdateNeighbours() {
  scene_ << "  // Rebuilds the neighbour search of every array that is a source.\n";
  scene_ << "  void update_neighbours() {\n";
  if (opencl_) {
    // On the device: the search domain from min/max reductions, then a cell table per
    // source (cell keys, bitonic sort, cell start/end). Positions never leave the device.
    if (!loopArrays_.empty())
      scene_ << "    grid = ocl.make_grid(" << deviceExtents("                          ")
             << ", DIM, Kernel::radius_scale);\n";
    // Every REORDER_EVERY builds the particles are sorted in cell order on the device, as
    // on the CPU (same grid, same order), so outputs list particles in the same order.
    if (!sourceArrays_.empty())
      scene_ << "    const bool reorder = builds++ % REORDER_EVERY == 0;\n";
    for (const auto& S : sourceArrays_) {
      const std::string build = cellListBuild(S, S + ".n");
      scene_ << "    " << build << "\n";
      scene_ << "    if (reorder) {\n      dev_" << S << ".permute(ocl, cells_" << S << ", " << S
             << ");\n      " << build << "\n    }\n";
    }
  }
  if (!loopArrays_.empty() && !opencl_) emitSearchDomain();
  if (!sourceArrays_.empty() && !opencl_) {
    // Every REORDER_EVERY builds the particles are sorted in cell order, so that neighbours
    // are close in memory; all per-particle state moves with them.
    scene_ << "    const bool reorder = builds++ % REORDER_EVERY == 0;\n";
  }
  for (const auto& S : sourceArrays_) {
    if (opencl_) break;
    const std::string build = cellListBuild(S, S + ".n");
    scene_ << "    " << build << "\n";
    scene_ << "    if (reorder) {\n      " << permuteInCellOrder(S) << "\n      " << build
           << "\n    }\n";
  }
  scene_ << "  }\n\n";
  scene_ << "  void compute_accelerations(double t, double dt) {\n";
  emitTimedNeighbourUpdate();
  scene_ << "    equations(t, dt);\n  }\n\n";
}

// The call of update_neighbours() in compute_accelerations. CPU backends time it for
// --timing; the OpenCL launches are asynchronous, so a host timer would measure nothing there.
void Emitter::emitTimedNeighbourUpdate() {
  if (opencl_)
    scene_ << "    update_neighbours();\n";
  else
    scene_ << "    const double nnps_t0 = sphc::wall_seconds();\n"
              "    update_neighbours();\n"
              "    nnps_seconds += sphc::wall_seconds() - nnps_t0;\n";
}

void Emitter::emitStep() {
  if (hasDomain()) {
    scene_ << "  // Periodic axes: particles that left the box come back in.\n";
    scene_ << "  void update_domain() {\n";
    for (const auto& a : plan_.arrays)
      if (opencl_)
        scene_ << "    sphc::ocl::wrap_periodic(ocl, box, dev_" << a.name << ", " << a.name
               << ");\n";
      else
        scene_ << "    sphc::wrap_periodic(box, " << hostData(plan_.arrayIndex(a.name)) << ");\n";
    scene_ << "  }\n\n";
    scene_ << "  // Rebuilds the neighbour search of every array that is a source, with ghosts.\n";
    scene_ << "  void update_neighbours() {\n";
    if (opencl_)
      emitUpdateNeighboursWithGhostsDevice();
    else
      emitUpdateNeighboursWithGhosts();
    scene_ << "  }\n\n";
    scene_ << "  // Ghosts exist during an evaluation only: outside it arrays hold real particles.\n";
    scene_ << "  void compute_accelerations(double t, double dt) {\n";
    scene_ << "    update_domain();\n";
    emitTimedNeighbourUpdate();
    scene_ << "    equations(t, dt);\n";
    scene_ << removeGhosts();
    scene_ << "  }\n\n";
  } else {
    emitUpdateNeighbours();
  }
  if (!postStepCalls_.empty()) {
    // Groups with post_step = true: after the integrator's time step, on the new positions.
    scene_ << "  // groups with post_step = true, after each time step\n";
    // No neighbour update when no group is due (a disabled group changes nothing at all).
    scene_ << "  void post_step(double t, double dt) {\n    if (!(";
    for (size_t i = 0; i < postStepDue_.size(); ++i)
      scene_ << (i ? " || " : "") << postStepDue_[i];
    scene_ << ")) return;\n";
    scene_ << (hasDomain() ? "    update_domain();\n" : "") << "    update_neighbours();\n";
    for (const auto& c : postStepCalls_) scene_ << "    " << c << "(t, dt);\n";
    if (hasDomain()) scene_ << removeGhosts();
    scene_ << "  }\n\n";
  }
  // The integrator's time step; after stage k of m the time is t + k/m dt.
  int stages = 0;
  for (const auto& s : plan_.integratorSteps) stages += s.rfind("stage", 0) == 0;
  scene_ << "  // integrator " << plan_.integratorName << "\n";
  scene_ << "  void step(double t, double dt) {\n";
  int done = 0;
  auto timeAfter = [&](int stagesDone) {
    return stagesDone == 0 ? std::string("t")
                           : "t + " + std::to_string(stagesDone) + ".0 / " +
                                 std::to_string(stages) + ".0 * dt";
  };
  // The C++ backends: a run of stepper statements calls its fused function (emitStepperRuns)
  // at the run's first statement, with each statement's time.
  std::map<size_t, std::vector<size_t>> runAt;
  std::set<size_t> inRun;
  if (!opencl_) {
    for (const auto& run : stepperRuns()) {
      runAt[run.front()] = run;
      inRun.insert(run.begin(), run.end());
    }
  }
  for (size_t k = 0; k < plan_.integratorSteps.size(); ++k) {
    const std::string& s = plan_.integratorSteps[k];
    std::string time = timeAfter(done);
    if (inRun.count(k)) {
      auto it = runAt.find(k);
      if (it != runAt.end()) {
        bool any = false;  // does an array have one of the run's methods?
        std::string args;
        int d = done;
        for (size_t j : it->second) {
          const std::string& m = plan_.integratorSteps[j];
          for (const auto& a : plan_.arrays)
            any |= a.stepper >= 0 && plan_.steppers[a.stepper].methods.count(m);
          args += timeAfter(d) + ", ";
          if (m.rfind("stage", 0) == 0) ++d;
        }
        if (any) scene_ << "    " << stepperRunName(it->second) << "(" << args << "dt);\n";
      }
      if (s.rfind("stage", 0) == 0) ++done;
      continue;
    }
    if (s == "compute_accelerations")
      scene_ << "    compute_accelerations(" << time << ", dt);\n";
    else if (s == "update_domain")
      scene_ << (hasDomain() ? "    update_domain();\n"
                             : "    // update_domain: no periodic or mirror domain in this scene\n");
    else {
      bool any = false;
      for (const auto& a : plan_.arrays)
        any |= a.stepper >= 0 && plan_.steppers[a.stepper].methods.count(s);
      if (any) scene_ << "    stepper_" << s << "(" << time << ", dt);\n";
      if (s.rfind("stage", 0) == 0) ++done;
    }
  }
  scene_ << "    ++step_count;\n";
  if (!postStepCalls_.empty()) scene_ << "    post_step(t + dt, dt);\n";
  scene_ << "  }\n\n";
}

void Emitter::emitAdaptiveDt() {
  if (!plan_.adaptiveDt) return;
  auto pn = [&](const std::string& n) { return paramRef(n); };
  std::string cfl = plan_.cfl ? exprCpp(*plan_.cfl, pn) : "0.3";
  scene_ << "  // The stable time step: CFL (h / (c + |v|)), force (sqrt(h / |a|)) and viscous\n"
            "  // (h^2 / nu) limits over moving particles.\n";
  scene_ << "  double adaptive_dt() {\n";
  scene_ << "    double dt_cfl = HUGE_VAL, dt_force = HUGE_VAL, h2min = HUGE_VAL;\n";
  std::vector<std::string> vel = {"u", "v", "w"}, acc = {"au", "av", "aw"};
  for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a) {
    if (!movesParticles(plan_, a)) continue;
    const std::string& A = arr(a).name;
    scene_ << "    {  // " << A << "\n";
    bool useCfl = plan_.cfl || !plan_.forceFactor;
    if (opencl_) {
      // Per-particle limits on the device, their minima from device partial reductions.
      KernelArgs ka;
      std::vector<std::string> props = {"h"};
      if (useCfl) props.push_back("cs");
      for (int k = 0; k < plan_.dim; ++k) {
        if (useCfl) props.push_back(vel[k]);
        if (plan_.forceFactor) props.push_back(acc[k]);
      }
      for (const auto& p : props) ka.add("__global const real* " + p, devBuffer(a, p), p);
      const char* outs[3] = {"dt_cfl", "dt_force", "h2min"};
      for (int o = 0; o < 3; ++o)
        ka.add(std::string("__global real* out_") + outs[o],
               "ocl.scratch(n, " + std::to_string(o + 1) + ")", outs[o]);
      std::string k = "adaptive_dt_" + A;
      beginKernel(k, ka);
      cl_ << "  const int i = d_idx;\n";
      auto mag = [&](const std::vector<std::string>& c) {
        std::string m = "sqrt(";
        for (int k = 0; k < plan_.dim; ++k) m += (k ? " + " : "") + c[k] + "[i] * " + c[k] + "[i]";
        return m + ")";
      };
      cl_ << "  out_dt_cfl[i] = " << (useCfl ? "h[i] / (cs[i] + " + mag(vel) + ")" : "INFINITY")
          << ";\n";
      cl_ << "  out_h2min[i] = h[i] * h[i];\n";
      if (plan_.forceFactor)
        cl_ << "  const real amag = " << mag(acc) << ";\n"
            << "  out_dt_force[i] = amag > 0 ? sqrt(h[i] / amag) : INFINITY;\n";
      else
        cl_ << "  out_dt_force[i] = INFINITY;\n";
      cl_ << "}\n\n";
      scene_ << "      const int n = static_cast<int>(" << A << ".n);\n";
      scene_ << "      const double t = 0.0, dt = 0.0;  // (kernel arguments, unused)\n";
      scene_ << "      " << launch(k, "n", ka) << "\n";
      // The minima in one round trip: (limit, scratch slot) for the limits the scene uses.
      std::vector<std::pair<std::string, int>> mins;
      if (useCfl) mins.push_back({"dt_cfl", 1});
      if (plan_.forceFactor) mins.push_back({"dt_force", 2});
      if (plan_.nu) mins.push_back({"h2min", 3});
      scene_ << "      const std::vector<double> mins = ocl.reduce_all({";
      for (size_t m = 0; m < mins.size(); ++m)
        scene_ << (m ? ", " : "") << "{ocl.scratch(n, " << mins[m].second
               << "), static_cast<std::size_t>(n), sphc::ocl::Op::Min}";
      scene_ << "});\n";
      for (size_t m = 0; m < mins.size(); ++m)
        scene_ << "      " << mins[m].first << " = std::fmin(" << mins[m].first << ", mins[" << m
               << "]);\n";
      scene_ << "    }\n";
      continue;
    }
    scene_ << "      const " << real_ << "* h = " << propPtr(a, "h") << ";\n";
    if (plan_.cfl || !plan_.forceFactor) {
      scene_ << "      const " << real_ << "* cs = " << propPtr(a, "cs") << ";\n";
      for (int k = 0; k < plan_.dim; ++k)
        scene_ << "      const " << real_ << "* " << vel[k] << " = " << propPtr(a, vel[k]) << ";\n";
    }
    if (plan_.forceFactor)
      for (int k = 0; k < plan_.dim; ++k)
        scene_ << "      const " << real_ << "* " << acc[k] << " = " << propPtr(a, acc[k]) << ";\n";
    scene_ << parallelFor("      ", "reduction(min : dt_cfl, dt_force, h2min)");
    scene_ << "      for (std::size_t i = 0; i < " << A << ".n; ++i) {\n";
    if (plan_.cfl || !plan_.forceFactor) {
      scene_ << "        const double vmag = std::sqrt(";
      for (int k = 0; k < plan_.dim; ++k)
        scene_ << (k ? " + " : "") << vel[k] << "[i] * " << vel[k] << "[i]";
      scene_ << ");\n";
      scene_ << "        dt_cfl = std::fmin(dt_cfl, h[i] / (cs[i] + vmag));\n";
    }
    if (plan_.nu) scene_ << "        h2min = std::fmin(h2min, h[i] * h[i]);\n";
    if (plan_.forceFactor) {
      scene_ << "        const double amag = std::sqrt(";
      for (int k = 0; k < plan_.dim; ++k)
        scene_ << (k ? " + " : "") << acc[k] << "[i] * " << acc[k] << "[i]";
      scene_ << ");\n";
      scene_ << "        if (amag > 0) dt_force = std::fmin(dt_force, std::sqrt(h[i] / amag));\n";
    }
    scene_ << "      }\n    }\n";
  }
  scene_ << "    double dt = std::fmin(" << cfl << " * dt_cfl, "
         << (plan_.forceFactor ? exprCpp(*plan_.forceFactor, pn) : "1.0") << " * dt_force);\n";
  if (plan_.nu)
    scene_ << "    dt = std::fmin(dt, "
           << (plan_.viscousFactor ? exprCpp(*plan_.viscousFactor, pn) : "0.125")
           << " * h2min / " << exprCpp(*plan_.nu, pn) << ");  // viscous limit\n";
  scene_ << "    return dt;\n";
  scene_ << "  }\n\n";
}

void Emitter::emitMain() {
  out_ << "int main(int argc, char** argv) {\n";
  if (openmp_)
    out_ << "  sphc::choose_omp_wait(argc, argv);  // spin or sleep at barriers (sphc/solver.h)\n";
  out_ << "  static Scene scene;\n";
  out_ << "  sphc::SceneProgram prog;\n";
  out_ << "  prog.name = \"" << plan_.sceneName << "\";\n";
  out_ << "  prog.dim = DIM;\n";
  out_ << "  prog.backend = \"" << (opencl_ ? "opencl" : openmp_ ? "openmp" : "serial")
       << "\";\n";
  if (opencl_) out_ << "  scene.selection = sphc::ocl::take_options(argc, argv);\n";
  if (openmp_)
    out_ << "  prog.set_threads = [](int n) {\n"
            "    if (n > 0) omp_set_num_threads(n);\n"
            "    return omp_get_max_threads();\n  };\n";
  for (const auto* p : plan_.params) {
    if (p->derived) continue;  // `let`: not overridable
    bool lit = isLiteral(*p->value);
    char buf[64];
    snprintf(buf, sizeof buf, "%.17g", lit ? literalValue(*p->value) : 0.0);
    out_ << "  prog.params.push_back({\"" << p->name.name << "\", "
         << (lit ? std::string(buf) : "std::nan(\"\")") << ", \""
         << (lit ? std::string("") : "= " + exprText(*p->value)) << "\"});\n";
  }
  for (const auto& o : plan_.options) {
    std::string choices;
    for (const auto& c : o.choices) choices += (choices.empty() ? "" : ", ") + c;
    out_ << "  prog.options.push_back({\"" << o.name << "\", \"" << o.value << "\", \"" << choices
         << "\"});  // sphc -D " << o.name << "=...\n";
  }
  if (singlePrecision_) out_ << "  prog.precision = \"single\";\n";
  out_ << "  prog.setup = [](const std::vector<double>& v, sphc::SceneTimes& times) {\n"
          "    scene.setup(v, times);\n"
       << (opencl_ ? "    scene.to_device();\n" : cpuSingle_ ? "    scene.to_single();\n" : "")
       << "  };\n";
  out_ << "  prog.arrays = [] { return std::vector<sphc::ParticleArray*>{";
  bool first = true;
  for (const auto& a : plan_.arrays) {
    out_ << (first ? "" : ", ") << "&scene." << a.name;
    first = false;
  }
  out_ << "}; };\n";
  out_ << "  prog.compute_initial = [](double t, double dt) { scene.compute_accelerations(t, dt); };\n";
  out_ << "  prog.step = [](double t, double dt) { scene.step(t, dt); };\n";
  // OpenCL: particle data stays on the device; the run loop asks for it back only when it
  // writes output or checks for a blow-up.
  // --precision=single on the CPU: likewise for the float copies.
  if (opencl_ || cpuSingle_) out_ << "  prog.to_host = [] { scene.to_host(); };\n";
  if (plan_.adaptiveDt) out_ << "  prog.adaptive_dt = [] { return scene.adaptive_dt(); };\n";
  if (!iteratedGroups_.empty())
    out_ << "  prog.iterations = [] { return scene.iteration_stats; };\n";
  if (!opencl_) out_ << "  prog.neighbour_seconds = [] { return scene.nnps_seconds; };\n";
  bool anyOutput = false;
  for (const auto& a : plan_.arrays) anyOutput |= !a.outputProps.empty();
  for (const auto& a : plan_.arrays) {
    if (anyOutput && a.outputProps.empty()) continue;
    out_ << "  prog.output.push_back({\"" << a.name << "\", {";
    bool firstProp = true;
    for (const auto& p : a.outputProps) {
      if (constIndex(plan_.arrayIndex(a.name), p) >= 0) continue;  // constants: always written
      out_ << (firstProp ? "" : ", ") << "\"" << p << "\"";
      firstProp = false;
    }
    out_ << "}});\n";
  }
  out_ << "  return sphc::run_main(argc, argv, prog);\n}\n";
}

std::string Emitter::run() {
  std::string file = llvm::sys::path::filename(plan_.mainFile).str();
  out_ << "// Generated by sphc from " << file << ": do not edit; edit the .sph and recompile.\n";
  out_ << "// Backend: "
       << (opencl_ ? std::string("opencl (kernels in SCENE_CL, ") +
                         (singlePrecision_ ? "single" : "double") + " precision)"
           : openmp_ ? "openmp (loops over particles in parallel)"
                     : "serial")
       << (cpuSingle_ ? "; single precision (float copies of the arrays)" : "") << ".\n";
  out_ << "// Scene '" << plan_.sceneName << "': dim " << plan_.dim << ", kernel "
       << plan_.kernel << ", integrator "
       << (plan_.integratorName.empty() ? "none" : plan_.integratorName) << ".\n";
  out_ << "#include \"sphc/geometry.h\"\n#include \"sphc/kernels.h\"\n"
          "#include \"sphc/nnps.h\"\n#include \"sphc/particle_array.h\"\n"
          "#include \"sphc/solver.h\"\n";
  bool anyLoad = false;
  for (const auto& a : plan_.arrays) anyLoad |= !a.decl->loads.empty();
  if (anyLoad) out_ << "#include \"sphc/load.h\"\n";
  if (hasDomain()) out_ << "#include \"sphc/domain.h\"\n";
  if (cpuSingle_) out_ << "#include \"sphc/float_arrays.h\"\n";
  out_ << "\n#include <math.h>\n#include <cmath>\n#include <cstdint>\n#include <vector>\n";
  if (openmp_) out_ << "\n#include <omp.h>\n";
  if (opencl_) out_ << "\n#include \"sphc/opencl.h\"\n";
  out_ << "\n";
  out_ << "namespace {\n\n";
  out_ << "constexpr int DIM = " << plan_.dim << ";\n";
  out_ << "using Kernel = sphc::" << plan_.kernel << "<DIM>;\n";
  out_ << "constexpr " << real_
       << " RADIUS2 = Kernel::radius_scale * Kernel::radius_scale;\n\n";
  out_ << "// ---- Equation and stepper bodies, as written in the .sph files ----\n\n";
  // OpenCL: line 1 of the kernel source is this directive, so lines are the source's own.
  if (opencl_) cl_ << "#line 2 \"" << plan_.sceneName << ".cl\"\n";
  emitKernelFunctions();
  // Bodies of live equations (each declaration once) and of steppers.
  std::set<int> emittedDecls;
  for (const auto& eq : plan_.equations) {
    if (!eq.live || !emittedDecls.insert(eq.declIndex).second) continue;
    const auto& pd = plan_.equationDecls[eq.declIndex];
    static const char* names[] = {"initialize", "loop", "post_loop", "reduce", "converged"};
    static const char* rets[] = {"void", "void", "void", "double", "int"};
    // OpenCL: every body runs on the device but `converged`, which the host evaluates from
    // the host copy of the constants.
    for (const auto& [kind, b] : pd.methods)
      emitBodyFunction(plan_.bodies[b], bodyFunctionName(eq.name, names[kind]), rets[kind],
                       eq.dest, opencl_ && kind != ast::Method::Converged);
  }
  std::set<int> emittedSteppers;
  for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a) {
    int s = arr(a).stepper;
    if (s < 0 || !emittedSteppers.insert(s).second) continue;
    for (const auto& [m, b] : plan_.steppers[s].methods)
      emitBodyFunction(plan_.bodies[b], bodyFunctionName(plan_.steppers[s].decl->name.name, m),
                       "void", a, opencl_);
  }

  emitParams();
  emitSetup();
  emitGroup(plan_.root, "equations");
  emitSteppers();
  emitStep();
  emitAdaptiveDt();
  if (opencl_) {
    clText_ = cl_.str();
    out_ << "// ---- OpenCL C of the kernels, built at start-up with the runtime's ----\n\n";
    out_ << "constexpr bool DOUBLE_PRECISION = " << (singlePrecision_ ? "false" : "true")
         << ";\n";
    out_ << "const char* const SCENE_CL = R\"SPHC_CL(" << clText_ << ")SPHC_CL\";\n\n";
  }

  out_ << "// ---- The scene ----\n\n";
  out_ << "struct Scene {\n";
  for (const auto& a : plan_.arrays) out_ << "  sphc::ParticleArray " << a.name << ";\n";
  for (const auto& a : plan_.arrays)
    if (!a.decl->loads.empty())
      out_ << "  std::vector<sphc::ParticleArray> loaded_" << a.name << ";\n";
  if (opencl_) {
    out_ << "  sphc::ocl::Selection selection;  // --platform, --device\n";
    out_ << "  sphc::ocl::Context ocl;\n";
    for (const auto& a : plan_.arrays) out_ << "  sphc::ocl::DeviceArray dev_" << a.name << ";\n";
    out_ << "  sphc::ocl::Grid grid;\n";
    for (const auto& S : sourceArrays_) out_ << "  sphc::ocl::CellTable cells_" << S << ";\n";
  } else {
    out_ << "  sphc::SearchDomain domain;\n";
    if (cpuSingle_)
      for (const auto& a : plan_.arrays)
        out_ << "  sphc::FloatArray f32_" << a.name << ";  // what the scene computes on\n";
    for (const auto& S : sourceArrays_) out_ << "  sphc::CellList cells_" << S << ";\n";
  }
  if (hasDomain()) {
    out_ << "  sphc::Domain box;  // periodic and mirror boundaries\n";
    for (const auto& S : sourceArrays_)
      out_ << "  " << (opencl_ ? "sphc::ocl::DeviceGhosts" : "sphc::Ghosts") << " ghosts_" << S
           << ";\n";
  }
  if (openmp_) out_ << "  std::vector<" << real_ << "> reduce_scratch;  // reduce sum/mean, OpenMP\n";
  // Iterations per evaluation of each iterated group (--timing prints them).
  out_ << "  std::vector<sphc::IterationStats> iteration_stats{";
  for (std::size_t k = 0; k < iteratedGroups_.size(); ++k)
    out_ << (k ? ", " : "") << "sphc::IterationStats{\"" << iteratedGroups_[k] << "\"}";
  out_ << "};\n";
  out_ << "  long step_count = 0;  // completed time steps (group option `every`)\n";
  if (!opencl_) out_ << "  double nnps_seconds = 0.0;  // in update_neighbours, for --timing\n";
  if (!sourceArrays_.empty()) {
    out_ << "  static constexpr long REORDER_EVERY = 50;\n";
    out_ << "  long builds = 0;\n";
  }
  if (anyLoad) {
    llvm::SmallString<256> dir(plan_.mainFile);
    llvm::sys::fs::make_absolute(dir);
    out_ << "  std::string source_dir = \"" << llvm::sys::path::parent_path(dir).str()
         << "\";  // where the .sph file is\n";
  }
  if (opencl_) {
    // Data movement: everything up after set-up; properties back for output and checks.
    scene_ << "  void to_device() {\n";
    scene_ << "    ocl.init(selection, DOUBLE_PRECISION, sphc::ocl::kernel_function_source(\""
           << plan_.kernel << "\", DIM) + SCENE_CL, \"" << plan_.sceneName << "\");\n";
    for (const auto& a : plan_.arrays)
      scene_ << "    dev_" << a.name << ".upload(ocl, " << a.name << ");\n";
    scene_ << "  }\n\n";
    scene_ << "  void to_host() {\n";
    for (const auto& a : plan_.arrays)
      scene_ << "    dev_" << a.name << ".download(ocl, " << a.name << ");\n";
    scene_ << "  }\n\n";
  }
  if (cpuSingle_) {
    // The float copies: made after set-up; the host doubles updated for output and checks.
    scene_ << "  void to_single() {\n";
    for (const auto& a : plan_.arrays) scene_ << "    f32_" << a.name << ".upload(" << a.name << ");\n";
    scene_ << "  }\n\n";
    scene_ << "  void to_host() {\n";
    for (const auto& a : plan_.arrays)
      scene_ << "    f32_" << a.name << ".download(" << a.name << ");\n";
    scene_ << "  }\n\n";
  }
  out_ << "\n" << scene_.str() << "};\n\n}  // namespace\n\n";
  emitMain();
  return out_.str();
}

}  // namespace

std::string emitCpp(const Plan& plan, const DiagnosticEngine& diags, const EmitOptions& opts) {
  return Emitter(plan, diags, opts).run();
}

std::string emitOpenCL(const Plan& plan, const DiagnosticEngine& diags, EmitOptions opts) {
  opts.backend = "opencl";
  Emitter e(plan, diags, opts);
  e.run();
  return e.kernelSource();
}

}  // namespace sphc
