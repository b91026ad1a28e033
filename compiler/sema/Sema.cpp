#include "sema/Sema.h"
#include "sema/Zones.h"

#include "frontend/Parser.h"
#include "sema/Geometry.h"

#include "llvm/ADT/StringExtras.h"
#include "llvm/Support/FileSystem.h"
#include "llvm/Support/MemoryBuffer.h"
#include "llvm/Support/Path.h"

#include <cmath>
#include <map>
#include <optional>
#include <set>

namespace sphc {

// ---------------------------------------------------------------------------------------
// Imports
// ---------------------------------------------------------------------------------------

namespace {

std::string joinImport(const ast::ImportDecl& imp) {
  std::string s;
  for (const auto& p : imp.path) {
    if (!s.empty()) s += ".";
    s += p.name;
  }
  return s;
}

// Reads and parses one file; null if it cannot be read.
std::unique_ptr<ast::Module> parseFile(const std::string& path, DiagnosticEngine& diags,
                                       llvm::SMLoc importLoc) {
  auto buf = llvm::MemoryBuffer::getFile(path, /*IsText=*/true);
  if (!buf) {
    if (importLoc.isValid())
      diags.error(importLoc, "cannot read '" + path + "': " + buf.getError().message());
    else
      diags.error("cannot read '" + path + "': " + buf.getError().message());
    return nullptr;
  }
  unsigned id = diags.sourceMgr().AddNewSourceBuffer(std::move(*buf), importLoc);
  Parser parser(diags, diags.sourceMgr(), id);
  auto mod = parser.parseModule();
  if (mod) {
    mod->filename = path;
    mod->bufferId = id;
  }
  return mod;
}

}  // namespace

std::vector<std::unique_ptr<ast::Module>> loadModules(const std::string& mainFile,
                                                      const std::vector<std::string>& includeDirs,
                                                      const std::string& stdlibDir,
                                                      DiagnosticEngine& diags) {
  std::vector<std::unique_ptr<ast::Module>> modules;
  auto main = parseFile(mainFile, diags, llvm::SMLoc());
  if (!main) return modules;
  modules.push_back(std::move(main));
  std::set<std::string> loaded;  // canonical paths
  {
    llvm::SmallString<256> real;
    if (!llvm::sys::fs::real_path(mainFile, real)) loaded.insert(std::string(real));
  }
  // Breadth-first over imports; each file once.
  for (size_t m = 0; m < modules.size(); ++m) {
    std::string dir = std::string(llvm::sys::path::parent_path(modules[m]->filename));
    std::vector<ast::ImportDecl> imports = modules[m]->imports;
    for (const auto& imp : imports) {
      llvm::SmallString<128> rel;
      for (size_t i = 0; i < imp.path.size(); ++i) {
        if (i + 1 < imp.path.size())
          llvm::sys::path::append(rel, imp.path[i].name);
        else
          llvm::sys::path::append(rel, imp.path[i].name + ".sph");
      }
      std::vector<std::string> candidates;
      candidates.push_back(dir.empty() ? std::string(rel) : (dir + "/" + std::string(rel)));
      for (const auto& inc : includeDirs) candidates.push_back(inc + "/" + std::string(rel));
      if (!stdlibDir.empty()) candidates.push_back(stdlibDir + "/" + std::string(rel));
      std::string found;
      for (const auto& c : candidates)
        if (llvm::sys::fs::is_regular_file(c)) {
          found = c;
          break;
        }
      if (found.empty()) {
        llvm::SMLoc loc = imp.path.empty() ? imp.loc : imp.path.front().loc;
        diags.error(loc, "cannot find module '" + joinImport(imp) + "' (looked for '" +
                             std::string(rel) + "' next to this file, in -I directories and " +
                             "in the stdlib)");
        continue;
      }
      llvm::SmallString<256> real;
      std::string key = llvm::sys::fs::real_path(found, real) ? found : std::string(real);
      if (!loaded.insert(key).second) continue;
      auto mod = parseFile(found, diags, imp.loc);
      if (mod) modules.push_back(std::move(mod));
    }
  }
  return modules;
}

// ---------------------------------------------------------------------------------------
// Expressions
// ---------------------------------------------------------------------------------------

int mathFunctionArity(const std::string& name) {
  static const std::map<std::string, int> arity = {
      {"sqrt", 1},  {"exp", 1},   {"log", 1},   {"log10", 1}, {"sin", 1},  {"cos", 1},
      {"tan", 1},   {"asin", 1},  {"acos", 1},  {"atan", 1},  {"sinh", 1}, {"cosh", 1},
      {"tanh", 1},  {"fabs", 1},  {"abs", 1},   {"floor", 1}, {"ceil", 1}, {"round", 1},
      {"cbrt", 1},  {"pow", 2},   {"atan2", 2}, {"fmin", 2},  {"fmax", 2}, {"min", 2},
      {"max", 2},   {"fmod", 2},  {"hypot", 2}};
  auto it = arity.find(name);
  return it == arity.end() ? -1 : it->second;
}

bool checkExpr(const ast::Expr& e, const std::function<bool(const std::string&)>& isKnown,
               const std::string& what, DiagnosticEngine& diags) {
  bool ok = true;
  switch (e.kind) {
    case ast::Expr::Number:
      break;
    case ast::Expr::Name:
      if (e.text == "pi" || e.text == "e" || e.text == "true" || e.text == "false") break;
      if (!isKnown(e.text)) {
        diags.error(e.loc, "unknown name '" + e.text + "' in " + what);
        ok = false;
      }
      break;
    case ast::Expr::Call: {
      int n = mathFunctionArity(e.text);
      if (n < 0) {
        diags.error(e.loc, "unknown function '" + e.text + "' in " + what +
                               ": expressions may call math functions only (sqrt, pow, exp, "
                               "log, sin, cos, tan, atan2, fabs, fmin, fmax, floor, ceil, ...)");
        ok = false;
      } else if (static_cast<int>(e.args.size()) != n) {
        diags.error(e.loc, "'" + e.text + "' takes " + llvm::Twine(n) + " argument" +
                               (n == 1 ? "" : "s") + ", not " + llvm::Twine(e.args.size()));
        ok = false;
      }
      for (const auto& a : e.args) ok &= checkExpr(*a, isKnown, what, diags);
      break;
    }
    default:
      for (const auto& a : e.args) ok &= checkExpr(*a, isKnown, what, diags);
  }
  return ok;
}

// ---------------------------------------------------------------------------------------
// Plan building
// ---------------------------------------------------------------------------------------

namespace {

const std::vector<std::string>& kernelNames() {
  static const std::vector<std::string> k = {"CubicSpline",       "QuinticSpline",
                                             "WendlandQuintic",   "Gaussian",
                                             "WendlandQuinticC4", "WendlandQuinticC6",
                                             "SuperGaussian"};
  return k;
}

double kernelRadius(const std::string& k) {
  return (k == "QuinticSpline" || k == "Gaussian" || k == "SuperGaussian") ? 3.0 : 2.0;
}

std::string joinNames(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

class SemaImpl {
 public:
  SemaImpl(const std::vector<std::unique_ptr<ast::Module>>& modules, DiagnosticEngine& diags)
      : modules_(modules), diags_(diags) {}

  std::unique_ptr<Plan> run();

 private:
  template <class Decl>
  void collect(std::map<std::string, const Decl*>& table, const Decl& d, const char* kind) {
    auto [it, inserted] = table.emplace(d.name.name, &d);
    if (!inserted) {
      diags_.error(d.name.loc, std::string("redefinition of ") + kind + " '" + d.name.name + "'");
      diags_.note(it->second->name.loc, "previous definition is here");
    }
  }
  bool isParam(const std::string& n) const { return paramIndex_.count(n) != 0; }
  bool checkSceneExpr(const ast::ExprPtr& e, const std::string& what) {
    return e && checkExpr(*e, [this](const std::string& n) { return isParam(n); }, what, diags_);
  }
  void buildFunctions();
  void buildArrays();
  void checkGeometry(const ast::GeometryDecl& g, const std::string& array);
  void buildScene();
  void buildDomain(const ast::DomainDecl& d);
  void buildGroup(const std::vector<ast::GroupItem>& items, PlanGroup& g, int depth);
  void instantiate(const ast::EquationInstance& inst, PlanGroup& g);
  // Group options evaluated at run time from params, array constants (and t, dt):
  // start_idx, stop_idx, condition.
  void groupRunTimeOption(const ast::KwArg& kw, PlanGroup& g);
  bool isArrayConstant(const std::string& n) const;
  int useEquationDecl(const ast::EquationDecl* decl);
  int useStepper(const ast::StepperDecl* decl);
  std::map<std::string, PropShape> propShapes() const;
  int arrayFromName(const ast::Ident& id, const std::string& role);
  void buildLimits(const ast::LimitsDecl& d);

  const std::vector<std::unique_ptr<ast::Module>>& modules_;
  DiagnosticEngine& diags_;
  std::unique_ptr<Plan> plan_;
  std::map<std::string, size_t> paramIndex_;
  std::map<std::string, const ast::ArrayDecl*> arrays_;
  std::map<std::string, const ast::EquationDecl*> equations_;
  std::map<std::string, const ast::StepperDecl*> steppers_;
  std::map<std::string, const ast::FunctionDecl*> functions_;
  std::map<std::string, const ast::IntegratorDecl*> integrators_;
  std::map<const ast::EquationDecl*, int> usedEquations_;
  std::map<const ast::StepperDecl*, int> usedSteppers_;
  bool integratorGiven_ = false;
};

std::unique_ptr<Plan> SemaImpl::run() {
  plan_ = std::make_unique<Plan>();
  const ast::Module& main = *modules_.front();
  plan_->mainFile = main.filename;

  // Global tables over all modules: the main file and what it imports share one namespace.
  for (const auto& m : modules_) {
    for (const auto& p : m->params) {
      if (paramIndex_.count(p.name.name)) {
        diags_.error(p.name.loc, "redefinition of '" + p.name.name + "'");
        diags_.note(plan_->params[paramIndex_[p.name.name]]->name.loc,
                    "previous definition is here");
        continue;
      }
      // A parameter's default may use the parameters declared before it.
      checkSceneExpr(p.value, "the value of parameter '" + p.name.name +
                                  "' (it may use parameters declared before it)");
      paramIndex_[p.name.name] = plan_->params.size();
      plan_->params.push_back(&p);
    }
    for (const auto& a : m->arrays) collect(arrays_, a, "array");
    for (const auto& e : m->equations) collect(equations_, e, "equation");
    for (const auto& s : m->steppers) collect(steppers_, s, "stepper");
    for (const auto& i : m->integrators) collect(integrators_, i, "integrator");
  }
  for (size_t m = 1; m < modules_.size(); ++m)
    for (const auto& s : modules_[m]->scenes) {
      diags_.error(s.name.loc, "scene '" + s.name.name + "' in an imported module: a module "
                               "meant for import holds no scene");
    }
  if (main.scenes.empty()) {
    diags_.error(diags_.sourceMgr().getMemoryBuffer(main.bufferId)->getBufferStart() ?
                     llvm::SMLoc::getFromPointer(
                         diags_.sourceMgr().getMemoryBuffer(main.bufferId)->getBufferStart()) :
                     llvm::SMLoc(),
                 "no scene in '" + main.filename + "': add `scene NAME { ... }`");
    return nullptr;
  }
  if (main.scenes.size() > 1) {
    diags_.error(main.scenes[1].name.loc, "a file holds one scene; '" +
                                              main.scenes[1].name.name + "' is the second");
    diags_.note(main.scenes[0].name.loc, "first scene is here");
  }
  plan_->scene = &main.scenes.front();
  plan_->sceneName = plan_->scene->name.name;

  buildArrays();
  buildFunctions();
  buildScene();
  if (!diags_.hasErrors()) buildZones(*plan_->scene, *plan_, diags_);  // sema/Zones.cpp
  if (diags_.hasErrors()) return nullptr;
  return std::move(plan_);
}

// Names a helper function may not take: they would collide with what the generated C++ and
// OpenCL C already declare (keywords, math and OpenCL built-in functions, the kernel functions,
// the generated code's own names).
static bool isReservedFunctionName(const std::string& n) {
  static const std::set<std::string> reserved = {
      // C99 and C++ keywords, OpenCL C qualifiers and types
      "auto", "break", "case", "char", "const", "continue", "default", "do", "double", "else",
      "enum", "extern", "float", "for", "goto", "if", "inline", "int", "long", "register",
      "restrict", "return", "short", "signed", "sizeof", "static", "struct", "switch",
      "typedef", "union", "unsigned", "void", "volatile", "while", "bool", "true", "false",
      "class", "namespace", "new", "delete", "template", "this", "operator", "private",
      "public", "protected", "virtual", "friend", "using", "typename", "try", "catch", "throw",
      "explicit", "mutable", "constexpr", "nullptr", "noexcept", "decltype", "and", "or",
      "not", "xor", "kernel", "global", "local", "constant", "read_only", "write_only", "half",
      "uint", "uchar", "ushort", "ulong", "size_t", "real", "main",
      // OpenCL C built-in functions (math, common, geometric, integer, relational, work-item)
      "acosh", "acospi", "asinh", "asinpi", "atanh", "atanpi", "atan2pi", "cospi", "erfc",
      "exp2", "exp10", "expm1", "fdim", "fma", "fract", "frexp", "ilogb", "ldexp", "lgamma",
      "log2", "log1p", "logb", "mad", "maxmag", "minmag", "modf", "nan", "nextafter", "pown",
      "powr", "remainder", "remquo", "rint", "rootn", "rsqrt", "sincos", "sinpi", "tanpi",
      "tgamma", "abs", "abs_diff", "clamp", "degrees", "radians", "max", "min", "mix", "sign",
      "step", "smoothstep", "cross", "dot", "distance", "length", "normalize", "fast_length",
      "fast_distance", "fast_normalize", "select", "isnan", "isinf", "isfinite", "signbit",
      "any", "all", "bitselect", "mul24", "mad24", "clz", "popcount", "rotate", "upsample",
      "hadd", "rhadd", "barrier", "get_global_id", "get_local_id", "get_group_id",
      "get_global_size", "get_local_size", "get_num_groups", "get_work_dim", "printf",
      // the generated code's names
      "DIM", "Kernel", "RADIUS2", "Scene", "kernel_w", "kernel_gradient", "std", "sphc"};
  if (reserved.count(n)) return true;
  for (const std::string& f : allowedMathFunctions())
    if (n == f) return true;
  for (const std::string& f : kernelFunctions())
    if (n == f) return true;
  return n.empty() || n[0] == '_' || n.find("__") != std::string::npos ||
         llvm::StringRef(n).startswith("sphc_") || llvm::StringRef(n).startswith("d_") ||
         llvm::StringRef(n).startswith("s_") || llvm::StringRef(n).startswith("di_") ||
         llvm::StringRef(n).startswith("sj_");
}

// Helper functions of all modules, callees first: modules in reverse load order (an imported
// module before the one importing it), each module's in declaration order.
void SemaImpl::buildFunctions() {
  for (auto m = modules_.rbegin(); m != modules_.rend(); ++m)
    for (const auto& f : (*m)->functions) {
      if (isReservedFunctionName(f.name.name)) {
        diags_.error(f.name.loc, "'" + f.name.name + "' cannot name a function: it is a keyword "
                                 "or a name the generated C++ or OpenCL code already uses "
                                 "(e.g. a math or OpenCL built-in function, or d_/s_/_ "
                                 "prefixed); choose another name");
        continue;
      }
      auto [it, inserted] = functions_.emplace(f.name.name, &f);
      if (!inserted) {
        diags_.error(f.name.loc, "redefinition of function '" + f.name.name + "'");
        diags_.note(it->second->name.loc, "previous definition is here");
        continue;
      }
      if (equations_.count(f.name.name) || steppers_.count(f.name.name) ||
          arrays_.count(f.name.name) || isParam(f.name.name)) {
        diags_.error(f.name.loc, "function '" + f.name.name + "' has the name of an equation, "
                                 "stepper, array or parameter; choose another name");
        continue;
      }
      PlanBody body;
      body.source.text = f.text.text;
      body.source.start = f.text.start;
      body.source.kind = BodyKind::Function;
      body.source.label = "function " + f.name.name;
      body.source.functionName = f.name.name;
      plan_->functions.push_back(std::move(body));
    }
}

void SemaImpl::buildArrays() {
  // Arrays are instantiated in declaration order, main module first.
  for (const auto& m : modules_)
    for (const auto& a : m->arrays) {
      if (arrays_[a.name.name] != &a) continue;  // a redefinition, already reported
      PlanArray pa;
      pa.name = a.name.name;
      pa.loc = a.name.loc;
      pa.decl = &a;
      std::set<std::string> seen = {"x", "y", "z"};
      for (const auto& g : a.geometry) checkGeometry(g, pa.name);
      if (a.geometry.empty() && a.loads.empty())
        diags_.warning(a.name.loc, "array '" + pa.name + "' has no geometry and no load: it "
                                   "starts with no particles");
      for (const auto& p : a.properties) {
        if (p.name.name == "x" || p.name.name == "y" || p.name.name == "z") {
          diags_.error(p.name.loc, "'" + p.name.name + "' is a position: it is set by the "
                                   "array's geometry or load, not by a property declaration");
          continue;
        }
        if (p.init)
          checkExpr(*p.init,
                    [&](const std::string& n) { return isParam(n) || seen.count(n); },
                    "the initial value of '" + p.name.name +
                        "' (it may use x, y, z, params and properties declared before it)",
                    diags_);
        if (!seen.insert(p.name.name).second) {
          diags_.error(p.name.loc, "property '" + p.name.name + "' of array '" + pa.name +
                                       "' is declared twice");
          continue;
        }
        PlanProperty prop;
        prop.name = p.name.name;
        prop.type = p.type;
        prop.stride = p.stride;
        prop.init = p.init;
        prop.declLoc = p.name.loc;
        prop.declared = true;
        pa.props.push_back(prop);
      }
      for (const auto& c : a.constants) {
        if (c.init) checkSceneExpr(c.init, "constant '" + c.name.name + "'");
        pa.constants.push_back(c.name.name);
      }
      plan_->arrays.push_back(std::move(pa));
    }
}

void SemaImpl::checkGeometry(const ast::GeometryDecl& g, const std::string& array) {
  const GeometryBuilder* b = findGeometryBuilder(g.builder.name);
  if (!b) {
    std::vector<std::string> names;
    for (const auto& gb : geometryBuilders()) names.push_back(gb.name);
    diags_.error(g.builder.loc, "unknown geometry '" + g.builder.name + "'; geometries are: " +
                                    joinNames(names));
    return;
  }
  std::set<std::string> given;
  for (const auto& kw : g.args) {
    bool known = false;
    for (const auto& a : b->args) known |= a.name == kw.name.name;
    if (!known) {
      std::vector<std::string> names;
      for (const auto& a : b->args) names.push_back(a.name);
      diags_.error(kw.name.loc, "geometry '" + b->name + "' has no argument '" + kw.name.name +
                                    "'; arguments are: " + joinNames(names));
      continue;
    }
    if (!given.insert(kw.name.name).second)
      diags_.error(kw.name.loc, "argument '" + kw.name.name + "' is given twice");
    if (kw.isList)
      diags_.error(kw.name.loc, "geometry argument '" + kw.name.name + "' takes a number");
    else
      checkSceneExpr(kw.value, "geometry of array '" + array + "'");
  }
  for (const auto& a : b->args)
    if (!a.defaultValue && !given.count(a.name))
      diags_.error(g.builder.loc, "geometry '" + b->name + "' needs argument '" + a.name + "'");
}

int SemaImpl::arrayFromName(const ast::Ident& id, const std::string& role) {
  int idx = plan_->arrayIndex(id.name);
  if (idx < 0) {
    std::vector<std::string> names;
    for (const auto& a : plan_->arrays) names.push_back(a.name);
    diags_.error(id.loc, "unknown array '" + id.name + "' as " + role +
                             (names.empty() ? std::string(": no arrays are declared")
                                            : "; arrays are: " + joinNames(names)));
  }
  return idx;
}

std::map<std::string, PropShape> SemaImpl::propShapes() const {
  std::map<std::string, PropShape> shapes;
  for (const auto& a : plan_->arrays)
    for (const auto& p : a.props) shapes[p.name] = PropShape{p.type, p.stride};
  return shapes;
}

int SemaImpl::useEquationDecl(const ast::EquationDecl* decl) {
  auto it = usedEquations_.find(decl);
  if (it != usedEquations_.end()) return it->second;
  PlanEquationDecl pd;
  pd.decl = decl;
  std::vector<std::string> scalars;
  for (const auto& p : decl->params) scalars.push_back(p.name.name);
  for (const auto& c : decl->consts) scalars.push_back(c.name.name);
  for (const auto& m : decl->methods) {
    if (pd.methods.count(m.kind)) {
      diags_.error(m.loc, "equation '" + decl->name.name + "' defines this method twice");
      continue;
    }
    static const char* names[] = {"initialize", "loop", "post_loop", "reduce", "converged"};
    static const BodyKind kinds[] = {BodyKind::Initialize, BodyKind::Loop, BodyKind::PostLoop,
                                     BodyKind::Reduce, BodyKind::Converged};
    PlanBody body;
    body.source.text = m.body.text;
    body.source.start = m.body.start;
    body.source.kind = kinds[m.kind];
    body.source.label = "equation " + decl->name.name + ", method " + names[m.kind];
    body.source.scalars = scalars;
    body.source.props = propShapes();
    pd.methods[m.kind] = static_cast<int>(plan_->bodies.size());
    plan_->bodies.push_back(std::move(body));
    if (m.kind == ast::Method::Reduce) {
      pd.reduceOp = m.reduceOp;
      pd.reduceTarget = m.reduceTarget.name;
    }
  }
  int idx = static_cast<int>(plan_->equationDecls.size());
  plan_->equationDecls.push_back(pd);
  usedEquations_[decl] = idx;
  return idx;
}

int SemaImpl::useStepper(const ast::StepperDecl* decl) {
  auto it = usedSteppers_.find(decl);
  if (it != usedSteppers_.end()) return it->second;
  PlanStepper ps;
  ps.decl = decl;
  for (const auto& m : decl->methods) {
    if (ps.methods.count(m.name.name)) {
      diags_.error(m.name.loc, "stepper '" + decl->name.name + "' defines '" + m.name.name +
                                   "' twice");
      continue;
    }
    PlanBody body;
    body.source.text = m.body.text;
    body.source.start = m.body.start;
    body.source.kind =
        m.name.name == "initialize" ? BodyKind::StepperInit : BodyKind::StepperStage;
    body.source.label = "stepper " + decl->name.name + ", " + m.name.name;
    body.source.props = propShapes();
    ps.methods[m.name.name] = static_cast<int>(plan_->bodies.size());
    plan_->bodies.push_back(std::move(body));
  }
  int idx = static_cast<int>(plan_->steppers.size());
  plan_->steppers.push_back(ps);
  usedSteppers_[decl] = idx;
  return idx;
}

void SemaImpl::buildScene() {
  const ast::SceneDecl& s = *plan_->scene;
  std::set<std::string> seen;
  static const std::vector<std::string> known = {"dim", "kernel", "tf", "dt", "integrator"};
  for (const auto& set : s.settings) {
    const std::string& k = set.key.name;
    if (!seen.insert(k).second) {
      diags_.error(set.key.loc, "scene setting '" + k + "' is given twice");
      continue;
    }
    const ast::Expr& v = *set.value;
    if (k == "dim") {
      if (v.kind != ast::Expr::Number || (v.number != 1 && v.number != 2 && v.number != 3))
        diags_.error(v.loc, "dim must be 1, 2 or 3");
      else
        plan_->dim = static_cast<int>(v.number);
    } else if (k == "kernel") {
      const auto& ks = kernelNames();
      if (v.kind != ast::Expr::Name || std::find(ks.begin(), ks.end(), v.text) == ks.end())
        diags_.error(v.loc, "unknown kernel" +
                                (v.kind == ast::Expr::Name ? " '" + v.text + "'" : "") +
                                "; kernels are: " + joinNames(ks));
      else {
        plan_->kernel = v.text;
        plan_->kernelRadiusScale = kernelRadius(v.text);
      }
    } else if (k == "tf") {
      if (checkSceneExpr(set.value, "tf")) plan_->tf = set.value;
    } else if (k == "dt") {
      if (checkSceneExpr(set.value, "dt")) plan_->dt = set.value;
    } else if (k == "integrator") {
      integratorGiven_ = true;
      auto it = v.kind == ast::Expr::Name ? integrators_.find(v.text) : integrators_.end();
      if (it == integrators_.end()) {
        std::vector<std::string> names;
        for (const auto& [n, d] : integrators_) names.push_back(n);
        diags_.error(v.loc, "unknown integrator" +
                                (v.kind == ast::Expr::Name ? " '" + v.text + "'" : "") +
                                (names.empty() ? std::string("; none is declared (import "
                                                             "integrators;)")
                                               : "; integrators are: " + joinNames(names)));
      } else {
        plan_->integratorName = v.text;
        for (const auto& st : it->second->steps) plan_->integratorSteps.push_back(st.name);
      }
    } else {
      diags_.error(set.key.loc, "unknown scene setting '" + k + "'; settings are: " +
                                    joinNames(known) +
                                    ", and stepper, adaptive_dt, output, equations");
    }
  }
  if (!plan_->tf) diags_.error(s.name.loc, "scene '" + s.name.name + "' has no final time: "
                                            "add `tf = ...;`");
  if (!plan_->dt) diags_.error(s.name.loc, "scene '" + s.name.name + "' has no time step: "
                                            "add `dt = ...;` (the fixed or initial step)");

  for (const auto& st : s.steppers) {
    int a = arrayFromName(st.array, "the array of a stepper");
    auto it = steppers_.find(st.stepper.name);
    if (it == steppers_.end()) {
      std::vector<std::string> names;
      for (const auto& [n, d] : steppers_) names.push_back(n);
      diags_.error(st.stepper.loc, "unknown stepper '" + st.stepper.name + "'" +
                                       (names.empty() ? std::string("")
                                                      : "; steppers are: " + joinNames(names)));
      continue;
    }
    if (a < 0) continue;
    if (plan_->arrays[a].stepper >= 0) {
      diags_.error(st.array.loc, "array '" + st.array.name + "' already has a stepper");
      continue;
    }
    plan_->arrays[a].stepper = useStepper(it->second);
  }
  bool anyStepper = false;
  for (const auto& a : plan_->arrays) anyStepper |= a.stepper >= 0;
  if (anyStepper && !integratorGiven_)
    diags_.error(s.name.loc, "scene '" + s.name.name + "' has steppers but no integrator: add "
                             "`integrator = PECIntegrator;` (import integrators;)");
  // Integrator stages must exist in the steppers that are used.
  for (const auto& step : plan_->integratorSteps)
    if (step.rfind("stage", 0) == 0)
      for (const auto& a : plan_->arrays)
        if (a.stepper >= 0 && !plan_->steppers[a.stepper].methods.count(step))
          diags_.error(plan_->steppers[a.stepper].decl->name.loc,
                       "stepper '" + plan_->steppers[a.stepper].decl->name.name +
                           "' (used for array '" + a.name + "') has no '" + step +
                           "', which integrator '" + plan_->integratorName + "' calls");

  if (s.hasAdaptiveDt) {
    plan_->adaptiveDt = true;
    for (const auto& kw : s.adaptiveDt) {
      if (kw.isList) {
        diags_.error(kw.name.loc, "adaptive_dt arguments are numbers");
        continue;
      }
      if (!checkSceneExpr(kw.value, "adaptive_dt")) continue;
      if (kw.name.name == "cfl")
        plan_->cfl = kw.value;
      else if (kw.name.name == "force")
        plan_->forceFactor = kw.value;
      else if (kw.name.name == "viscous")
        plan_->viscousFactor = kw.value;
      else if (kw.name.name == "nu")
        plan_->nu = kw.value;
      else
        diags_.error(kw.name.loc, "unknown adaptive_dt argument '" + kw.name.name +
                                      "'; arguments are: cfl, force, viscous, nu");
    }
  }

  if (plan_->viscousFactor && !plan_->nu)
    diags_.error(s.adaptiveDtLoc, "adaptive_dt: the viscous limit needs the kinematic "
                                  "viscosity: nu = ...");

  for (const auto& out : s.outputs) {
    if (out.every) {
      if (plan_->outputEvery)
        diags_.error(out.loc, "output interval given twice");
      else if (checkSceneExpr(out.every, "the output interval"))
        plan_->outputEvery = out.every;
    }
    for (const auto& t : out.at)
      if (checkSceneExpr(t, "an output time")) plan_->outputAt.push_back(t);
    for (const auto& item : out.items) {
      int a = arrayFromName(item.array, "an output");
      if (a < 0) continue;
      for (const auto& p : item.props) plan_->arrays[a].outputProps.push_back(p.name);
    }
  }

  for (size_t i = 0; i < s.domains.size(); ++i) {
    if (i > 0) {
      diags_.error(s.domains[i].loc, "the scene has a second domain; give all boundaries in one "
                                     "`domain { ... }`");
      diags_.note(s.domains[0].loc, "first domain is here");
      continue;
    }
    buildDomain(s.domains[i]);
  }

  for (const auto& l : s.limits) buildLimits(l);

  plan_->root.loc = s.equationsLoc;
  buildGroup(s.equations, plan_->root, 0);
}

// The value of an expression made of literals only (numbers, pi, e, arithmetic); nothing if
// it names a parameter (whose value is known only at run time) or calls a function.
std::optional<double> literalValue(const ast::Expr& e) {
  switch (e.kind) {
    case ast::Expr::Number: return e.number;
    case ast::Expr::Name:
      if (e.text == "pi") return M_PI;
      if (e.text == "e") return M_E;
      return std::nullopt;
    case ast::Expr::Unary: {
      auto v = literalValue(*e.args[0]);
      if (!v) return std::nullopt;
      if (e.op == "-") return -*v;
      if (e.op == "+") return *v;
      return std::nullopt;
    }
    case ast::Expr::Binary: {
      auto a = literalValue(*e.args[0]), b = literalValue(*e.args[1]);
      if (!a || !b) return std::nullopt;
      if (e.op == "+") return *a + *b;
      if (e.op == "-") return *a - *b;
      if (e.op == "*") return *a * *b;
      if (e.op == "/" && *b != 0) return *a / *b;
      return std::nullopt;
    }
    default: return std::nullopt;
  }
}

// limits { ARRAY.QUANTITY warn BOUND stop BOUND; }: the array exists, each quantity is limited
// once, the bounds are scene expressions, literal intervals are not empty and a literal warn
// bound lies within the stop bound. Whether the property exists is known after the property
// analysis (analysis/Properties.cpp reports a limit on a property nothing sets).
void SemaImpl::buildLimits(const ast::LimitsDecl& d) {
  for (const auto& item : d.items) {
    const int a = arrayFromName(item.array, "a limit");
    if (a < 0) continue;
    const std::string name = item.array.name + "." + item.quantity.name;
    bool ok = true;
    for (const auto& prev : plan_->limits) {
      if (prev.array == a && prev.quantity == item.quantity.name) {
        diags_.error(item.array.loc, "limit '" + name + "' is given twice");
        diags_.note(prev.loc, "first given here");
        ok = false;
        break;
      }
    }
    auto checkBound = [&](const ast::LimitBound& b, const char* kind) {
      for (const auto* e : {&b.lo, &b.hi})
        if (*e) ok &= checkSceneExpr(*e, "a limit (it may use params)");
      if (!ok || !b.lo || !b.hi) return;
      auto lo = literalValue(*b.lo), hi = literalValue(*b.hi);
      if (lo && hi && !(*lo <= *hi)) {
        diags_.error(b.lo->loc, std::string("empty ") + kind + " interval of limit '" + name +
                                    "': the low end must not be above the high end");
        ok = false;
      }
    };
    if (item.warn) checkBound(*item.warn, "warn");
    if (item.stop) checkBound(*item.stop, "stop");
    if (!ok) continue;
    if (item.warn && item.stop) {
      // A warn bound outside the stop bound would never warn: said when both are literals.
      auto outside = [&](const ast::ExprPtr& w, const ast::ExprPtr& st, bool low) {
        if (!st || !w) return false;  // an unbounded side: no bound to compare
        auto wv = literalValue(*w), sv = literalValue(*st);
        return wv && sv && (low ? *wv < *sv : *wv > *sv);
      };
      if (outside(item.warn->lo, item.stop->lo, true) ||
          outside(item.warn->hi, item.stop->hi, false)) {
        diags_.error(item.warn->loc, "the warn bound of limit '" + name +
                                         "' reaches beyond its stop bound; it would never warn");
        diags_.note(item.stop->loc, "the stop bound is here");
        continue;
      }
    }
    PlanLimit l;
    l.loc = item.array.loc;
    l.array = a;
    l.quantity = item.quantity.name;
    if (item.warn) {
      l.hasWarn = true;
      l.warnLo = item.warn->lo;
      l.warnHi = item.warn->hi;
    }
    if (item.stop) {
      l.hasStop = true;
      l.stopLo = item.stop->lo;
      l.stopHi = item.stop->hi;
    }
    auto& props = plan_->arrays[a].limitProps;
    if (l.quantity == "speed") {
      static const char* kVel[3] = {"u", "v", "w"};
      for (int k = 0; k < plan_->dim; ++k) props.push_back(kVel[k]);
    } else {
      props.push_back(l.quantity);
    }
    plan_->limits.push_back(std::move(l));
  }
}

void SemaImpl::buildDomain(const ast::DomainDecl& d) {
  PlanDomain& dom = plan_->domain;
  dom.loc = d.loc;
  static const char* kAxes[3] = {"x", "y", "z"};
  for (const auto& item : d.items) {
    const bool periodic = item.kind == ast::DomainItem::Periodic;
    const std::string what = periodic ? "periodic" : "mirror";
    int a = -1;
    for (int k = 0; k < 3; ++k)
      if (item.axis.name == kAxes[k]) a = k;
    if (a < 0) {
      diags_.error(item.axis.loc, "unknown axis '" + item.axis.name + "' in the domain; axes "
                                  "are x, y and z");
      continue;
    }
    if (a >= plan_->dim) {
      diags_.error(item.axis.loc, "axis '" + item.axis.name + "' is beyond the scene's " +
                                      llvm::Twine(plan_->dim) + " dimension" +
                                      (plan_->dim == 1 ? "" : "s") + " (dim = " +
                                      llvm::Twine(plan_->dim) + ")");
      continue;
    }
    if (periodic && (!item.lo || !item.hi)) {
      diags_.error(item.loc, "a periodic axis needs both ends: periodic " + item.axis.name +
                                 " in [lo, hi]");
      continue;
    }
    bool ok = true;
    for (const auto* e : {&item.lo, &item.hi})
      if (*e) ok &= checkSceneExpr(*e, "the domain (it may use params)");
    if (!ok) continue;
    if (item.lo && item.hi) {
      auto lo = literalValue(*item.lo), hi = literalValue(*item.hi);
      if (lo && hi && !(*lo < *hi)) {
        diags_.error(item.lo->loc, "empty interval for axis '" + item.axis.name +
                                       "': the low end must be below the high end");
        continue;
      }
    }
    // Each side of an axis has one boundary.
    auto setSide = [&](PlanBoundary& side, const ast::ExprPtr& at, const char* sideName) {
      if (side.kind != PlanBoundary::Open) {
        const bool same = (side.kind == PlanBoundary::Periodic) == periodic;
        diags_.error(item.loc, std::string("the ") + sideName + " side of axis '" +
                                   item.axis.name + "' " +
                                   (same ? "is given twice"
                                         : std::string("is both periodic and a mirror")));
        diags_.note(side.loc, "first given here");
        return;
      }
      side.kind = periodic ? PlanBoundary::Periodic : PlanBoundary::Mirror;
      side.at = at;
      side.loc = item.loc;
    };
    if (periodic && (dom.lo[a].kind != PlanBoundary::Open || dom.hi[a].kind != PlanBoundary::Open)) {
      const PlanBoundary& prev = dom.lo[a].kind != PlanBoundary::Open ? dom.lo[a] : dom.hi[a];
      const bool same = prev.kind == PlanBoundary::Periodic;
      diags_.error(item.loc, "axis '" + item.axis.name + "' " +
                                 (same ? std::string("is periodic twice")
                                       : std::string("is both periodic and a mirror")));
      diags_.note(prev.loc, "first given here");
      continue;
    }
    if (item.lo) setSide(dom.lo[a], item.lo, "low");
    if (item.hi) setSide(dom.hi[a], item.hi, "high");
  }
}

void SemaImpl::buildGroup(const std::vector<ast::GroupItem>& items, PlanGroup& g, int depth) {
  for (const auto& item : items) {
    if (item.equation) {
      instantiate(*item.equation, g);
      continue;
    }
    const ast::GroupDecl& gd = *item.group;
    auto sub = std::make_unique<PlanGroup>();
    sub->loc = gd.loc;
    sub->real = g.real;  // `real = false` applies to the groups inside too
    bool hasMin = false, hasMax = false;
    for (const auto& kw : gd.options) {
      const std::string& k = kw.name.name;
      auto boolValue = [&](bool& out) {
        const ast::Expr* v = kw.isList ? nullptr : kw.value.get();
        if (v && v->kind == ast::Expr::Name && (v->text == "true" || v->text == "false"))
          out = v->text == "true";
        else if (v && v->kind == ast::Expr::Number && (v->number == 0 || v->number == 1))
          out = v->number != 0;
        else
          diags_.error(kw.name.loc, "group option '" + k + "' takes true or false");
      };
      auto intValue = [&](int& out) {
        const ast::Expr* v = kw.isList ? nullptr : kw.value.get();
        if (v && v->kind == ast::Expr::Number && v->number >= 1 &&
            v->number == static_cast<int>(v->number))
          out = static_cast<int>(v->number);
        else
          diags_.error(kw.name.loc, "group option '" + k + "' takes a positive integer");
      };
      if (k == "real")
        boolValue(sub->real);
      else if (k == "iterate")
        boolValue(sub->iterate);
      else if (k == "min_iterations") {
        intValue(sub->minIterations);
        hasMin = true;
      } else if (k == "max_iterations") {
        intValue(sub->maxIterations);
        hasMax = true;
      } else if (k == "every") {
        if (kw.isList || !kw.value)
          diags_.error(kw.name.loc, "group option 'every' takes a number of time steps (an "
                                    "expression of params)");
        else if (checkSceneExpr(kw.value, "group option 'every'"))
          sub->every = kw.value;
      } else if (k == "start_idx" || k == "stop_idx" || k == "condition") {
        groupRunTimeOption(kw, *sub);
      } else if (k == "update_nnps") {
        boolValue(sub->updateNnps);
      } else if (k == "post_step") {
        boolValue(sub->postStep);
        if (sub->postStep && depth != 0)
          diags_.error(kw.name.loc, "post_step is an option of a top-level group (one directly "
                                    "in `equations`), not of a nested group");
      } else
        diags_.error(kw.name.loc, "unknown group option '" + k +
                                      "'; options are: real, iterate, min_iterations, "
                                      "max_iterations, every, post_step, start_idx, "
                                      "stop_idx, condition, update_nnps");
    }
    if ((hasMin || hasMax) && !sub->iterate)
      diags_.error(gd.loc, "min_iterations/max_iterations need `iterate = true`");
    if (sub->iterate && !hasMax) sub->maxIterations = 100;
    if (sub->minIterations > sub->maxIterations)
      diags_.error(gd.loc, "min_iterations is larger than max_iterations");
    buildGroup(gd.items, *sub, depth + 1);
    g.order.push_back(-static_cast<int>(g.subgroups.size()) - 1);
    g.subgroups.push_back(std::move(sub));
  }
}

// `arr.c`: a `const` declared in array `arr` (the Name the parser makes of `arr.c`).
bool SemaImpl::isArrayConstant(const std::string& n) const {
  size_t dot = n.find('.');
  if (dot == std::string::npos) return false;
  auto it = arrays_.find(n.substr(0, dot));
  if (it == arrays_.end()) return false;
  for (const auto& c : it->second->constants)
    if (c.name.name == n.substr(dot + 1)) return true;
  return false;
}

void SemaImpl::groupRunTimeOption(const ast::KwArg& kw, PlanGroup& g) {
  const std::string& k = kw.name.name;
  const bool cond = k == "condition";
  const std::string takes =
      cond ? "an expression of params, array constants (`fluid.c`), t and dt"
           : "a particle index: an expression of params and array constants (`fluid.c`)";
  if (kw.isList || !kw.value) {
    diags_.error(kw.name.loc, "group option '" + k + "' takes " + takes);
    return;
  }
  auto known = [&](const std::string& n) {
    if (isParam(n) || isArrayConstant(n)) return true;
    if (cond && (n == "t" || n == "dt")) return true;
    if (n.find('.') != std::string::npos) {
      diags_.error(kw.value->loc, "'" + n + "' in group option '" + k +
                                      "' is not a `const` of an array (write `array.const`)");
      return true;  // reported here
    }
    return false;
  };
  if (!checkExpr(*kw.value, known, "group option '" + k + "' (it takes " + takes + ")",
                 diags_))
    return;
  (k == "start_idx" ? g.startIdx : k == "stop_idx" ? g.stopIdx : g.condition) = kw.value;
}

void SemaImpl::instantiate(const ast::EquationInstance& inst, PlanGroup& g) {
  auto it = equations_.find(inst.equation.name);
  if (it == equations_.end()) {
    diags_.error(inst.equation.loc, "unknown equation '" + inst.equation.name +
                                        "' (is its module imported?)");
    return;
  }
  const ast::EquationDecl* decl = it->second;
  PlanEquation eq;
  eq.name = decl->name.name;
  eq.loc = inst.equation.loc;
  bool hasLoop = false;
  for (const auto& m : decl->methods) hasLoop |= m.kind == ast::Method::Loop;
  std::map<std::string, ast::ExprPtr> given;
  bool sawDest = false, sawSources = false;
  for (const auto& kw : inst.args) {
    const std::string& k = kw.name.name;
    if (k == "dest") {
      sawDest = true;
      if (kw.isList || kw.value->kind != ast::Expr::Name) {
        diags_.error(kw.name.loc, "dest takes one array name: dest = fluid");
        continue;
      }
      eq.dest = arrayFromName(ast::Ident{kw.value->text, kw.value->loc}, "dest");
    } else if (k == "sources") {
      sawSources = true;
      std::vector<ast::Ident> names = kw.list;
      if (!kw.isList) {
        if (kw.value->kind != ast::Expr::Name) {
          diags_.error(kw.name.loc, "sources takes array names: sources = [fluid, boundary]");
          continue;
        }
        names.push_back(ast::Ident{kw.value->text, kw.value->loc});
      }
      for (const auto& n : names) {
        int a = arrayFromName(n, "a source");
        if (a < 0) continue;
        if (std::find(eq.sources.begin(), eq.sources.end(), a) != eq.sources.end())
          diags_.error(n.loc, "array '" + n.name + "' is listed twice in sources");
        else
          eq.sources.push_back(a);
      }
    } else {
      bool isParamName = false;
      for (const auto& p : decl->params) isParamName |= p.name.name == k;
      if (!isParamName) {
        std::vector<std::string> names;
        for (const auto& p : decl->params) names.push_back(p.name.name);
        diags_.error(kw.name.loc, "equation '" + decl->name.name + "' has no parameter '" + k +
                                      "'" + (names.empty() ? std::string("")
                                                           : "; parameters are: " +
                                                                 joinNames(names)) +
                                      " (and dest, sources)");
        diags_.note(decl->name.loc, "equation '" + decl->name.name + "' is declared here");
        continue;
      }
      if (kw.isList) {
        diags_.error(kw.name.loc, "parameter '" + k + "' takes a number, not a list");
        continue;
      }
      if (given.count(k)) {
        diags_.error(kw.name.loc, "parameter '" + k + "' is given twice");
        continue;
      }
      checkSceneExpr(kw.value, "argument '" + k + "' of " + decl->name.name);
      given[k] = kw.value;
    }
  }
  if (!sawDest) diags_.error(inst.equation.loc, "equation '" + decl->name.name +
                                                    "' needs a destination: dest = ARRAY");
  if (hasLoop && (!sawSources || eq.sources.empty()) && sawDest)
    diags_.error(inst.equation.loc, "equation '" + decl->name.name + "' has a loop and needs "
                                    "sources: sources = [ARRAY, ...]");
  if (!hasLoop && !eq.sources.empty())
    diags_.warning(inst.equation.loc, "equation '" + decl->name.name + "' has no loop: its "
                                      "sources are not used");
  for (const auto& p : decl->params) {
    auto git = given.find(p.name.name);
    ast::ExprPtr v = git != given.end() ? git->second : p.defaultValue;
    if (!v) {
      diags_.error(inst.equation.loc, "missing argument '" + p.name.name + "' of equation '" +
                                          decl->name.name + "'");
      diags_.note(p.name.loc, "parameter declared here without a default");
      continue;
    }
    if (git == given.end()) {
      // A default may use the equation's earlier parameters only.
      std::set<std::string> earlier;
      for (const auto& q : decl->params) {
        if (&q == &p) break;
        earlier.insert(q.name.name);
      }
      checkExpr(*v, [&](const std::string& n) { return earlier.count(n) != 0; },
                "the default of '" + p.name.name + "'", diags_);
    }
    eq.values.emplace_back(p.name.name, v);
  }
  {
    std::set<std::string> visible;
    for (const auto& p : decl->params) visible.insert(p.name.name);
    for (const auto& c : decl->consts) {
      if (c.value)
        checkExpr(*c.value, [&](const std::string& n) { return visible.count(n) != 0; },
                  "const '" + c.name.name + "' of equation '" + decl->name.name +
                      "' (it may use the equation's parameters and earlier consts)",
                  diags_);
      visible.insert(c.name.name);
      eq.values.emplace_back(c.name.name, c.value);
    }
  }
  if (eq.dest < 0) return;
  eq.declIndex = useEquationDecl(decl);
  const auto& pd = plan_->equationDecls[eq.declIndex];
  if (!pd.reduceTarget.empty()) {
    auto& consts = plan_->arrays[eq.dest].constants;
    if (std::find(consts.begin(), consts.end(), pd.reduceTarget) == consts.end())
      consts.push_back(pd.reduceTarget);
  }
  eq.id = static_cast<int>(plan_->equations.size());
  g.equations.push_back(eq.id);
  g.order.push_back(static_cast<int>(g.equations.size()) - 1);
  plan_->equations.push_back(std::move(eq));
}

}  // namespace

std::unique_ptr<Plan> buildPlan(const std::vector<std::unique_ptr<ast::Module>>& modules,
                                DiagnosticEngine& diags) {
  if (modules.empty()) return nullptr;
  return SemaImpl(modules, diags).run();
}

}  // namespace sphc
