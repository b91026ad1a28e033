#include "sema/Sema.h"
#include "sema/SemaImpl.h"
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

const BuiltinConstant* builtinConstant(const std::string& name) {
  static const BuiltinConstant table[] = {{"pi", M_PI, "M_PI", true},
                                          {"e", M_E, "M_E", true},
                                          {"true", 1.0, "1.0", false},
                                          {"false", 0.0, "0.0", false}};
  for (const BuiltinConstant& b : table)
    if (name == b.name) return &b;
  return nullptr;
}

bool checkExpr(const ast::Expr& e, const std::function<bool(const std::string&)>& isKnown,
               const std::string& what, DiagnosticEngine& diags) {
  bool ok = true;
  switch (e.kind) {
    case ast::Expr::Number:
      break;
    case ast::Expr::Name:
      if (builtinConstant(e.text)) break;
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

namespace sema_detail {

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

}  // namespace sema_detail

bool overrideKernel(Plan& plan, const std::string& name, std::string& error) {
  const auto& ks = sema_detail::kernelNames();
  if (std::find(ks.begin(), ks.end(), name) == ks.end()) {
    error = "unknown kernel '" + name + "'; kernels are: " + sema_detail::joinNames(ks);
    return false;
  }
  plan.kernel = name;
  plan.kernelRadiusScale = sema_detail::kernelRadius(name);
  return true;
}

namespace sema_detail {

std::string joinNames(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}


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
  buildVectors();
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

// `vector (u, v, w);` declarations of every module: the component of each named property.
// One name is one component: the same declaration twice (two modules) is fine, a name given
// two components is an error, and so is a component an array declares with a stride (a
// `double[3]` already is a vector: the dimension pass lays it out by itself).
void SemaImpl::buildVectors() {
  static const char* axis[] = {"x", "y", "z"};
  std::map<std::string, llvm::SMLoc> where;
  for (const auto& m : modules_)
    for (const auto& v : m->vectors)
      for (int k = 0; k < static_cast<int>(v.components.size()); ++k) {
        const ast::Ident& c = v.components[k];
        auto [it, inserted] = plan_->vectorComponents.emplace(c.name, k);
        if (!inserted && it->second != k) {
          diags_.error(c.loc, "property '" + c.name + "' is the " + axis[k] +
                                  "-component of this vector and the " + axis[it->second] +
                                  "-component of another");
          diags_.note(where[c.name], "the other vector is declared here");
          continue;
        }
        if (inserted) where[c.name] = v.loc;
        for (const auto& mm : modules_)
          for (const auto& a : mm->arrays)
            for (const auto& p : a.properties)
              if (p.name.name == c.name && p.stride != 1) {
                diags_.error(c.loc, "property '" + c.name + "' is a component of a vector, "
                                    "but array '" + a.name.name + "' declares it with stride " +
                                    std::to_string(p.stride) + "; a component is a scalar");
                diags_.note(p.loc, "declared here");
              }
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
        if (p.init) checkPropertyInit(a, p, seen);
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
        prop.fromScheme = p.fromScheme;
        pa.props.push_back(prop);
      }
      for (const auto& c : a.constants) {
        if (c.init) checkSceneExpr(c.init, "constant '" + c.name.name + "'");
        pa.constants.push_back(c.name.name);
      }
      plan_->arrays.push_back(std::move(pa));
    }
}

// An initial value may name x, y, z, params and the properties of its array declared before
// it (not a name that is both). A property named at or after its own
// declaration, an array constant or another array's property gets an error saying so.
void SemaImpl::checkPropertyInit(const ast::ArrayDecl& a, const ast::PropertyDecl& p,
                                 const std::set<std::string>& before) {
  const std::string what = "the initial value of '" + p.name.name + "'";
  const std::string may = "an initial value may read x, y, z, params and the properties of "
                          "its array declared before it";
  // The error for a name that is a property or constant but not one the value may read, and
  // where that is declared; nullopt for other names (checkExpr reports those).
  auto misplaced = [&](const std::string& n)
      -> std::optional<std::pair<std::string, const ast::Ident*>> {
    if (before.count(n) || isParam(n)) return std::nullopt;
    if (n == p.name.name)
      return std::make_pair(what + " reads the property itself; " + may, nullptr);
    for (const auto& q : a.properties)
      if (q.name.name == n)
        return std::make_pair(what + " reads property '" + n + "', declared after it; " + may +
                                  " (declare '" + n + "' first)",
                              &q.name);
    for (const auto& c : a.constants)
      if (c.name.name == n)
        return std::make_pair(what + " reads '" + n + "', a constant of array '" +
                                  a.name.name + "'; " + may + " (make '" + n + "' a param)",
                              &c.name);
    for (const auto& m : modules_)
      for (const auto& other : m->arrays)
        if (&other != &a)
          for (const auto& q : other.properties)
            if (q.name.name == n)
              return std::make_pair(what + " reads '" + n + "', a property of array '" +
                                        other.name.name + "'; " + may,
                                    &q.name);
    return std::nullopt;
  };
  std::function<void(const ast::Expr&)> walk = [&](const ast::Expr& e) {
    // A name both a param and an earlier property would be read as one here and as the other
    // where the compiler evaluates initial values (h's, for the time-step bound).
    if (e.kind == ast::Expr::Name && before.count(e.text) && isParam(e.text))
      for (const auto& q : a.properties)
        if (q.name.name == e.text) {
          diags_.error(e.loc, what + " names '" + e.text + "', both a param and a property of "
                                  "array '" + a.name.name + "' declared before it; rename one");
          diags_.note(q.name.loc, "property '" + e.text + "' is declared here");
          break;
        }
    if (e.kind == ast::Expr::Name)
      if (auto m = misplaced(e.text)) {
        diags_.error(e.loc, m->first);
        if (m->second) diags_.note(m->second->loc, "'" + e.text + "' is declared here");
      }
    for (const auto& arg : e.args)
      if (arg) walk(*arg);
  };
  walk(*p.init);
  checkExpr(*p.init,
            [&](const std::string& n) {
              return before.count(n) || isParam(n) || misplaced(n).has_value();
            },
            what + " (it may use x, y, z, params and properties declared before it)", diags_);
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
    if (kw.name.name == "where") {  // keep the points where E != 0 (any builder)
      if (!given.insert("where").second)
        diags_.error(kw.name.loc, "argument 'where' is given twice");
      if (kw.isList || !kw.value)
        diags_.error(kw.name.loc, "geometry argument 'where' takes an expression of x, y, z");
      else
        checkExpr(*kw.value,
                  [&](const std::string& n) {
                    return isParam(n) || n == "x" || n == "y" || n == "z";
                  },
                  "'where' of a geometry of array '" + array +
                      "' (it may use x, y, z and params)",
                  diags_);
      continue;
    }
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
  std::vector<std::string> states;
  for (const auto& st : decl->states) {
    if (std::find(scalars.begin(), scalars.end(), st.name.name) != scalars.end())
      diags_.error(st.name.loc, "state '" + st.name.name + "' has the name of a parameter, "
                                "const or state of equation '" + decl->name.name + "'");
    scalars.push_back(st.name.name);
    states.push_back(st.name.name);
  }
  for (const auto& m : decl->methods) {
    if (pd.methods.count(m.kind)) {
      diags_.error(m.loc, "equation '" + decl->name.name + "' defines this method twice");
      continue;
    }
    static const BodyKind kinds[] = {BodyKind::Initialize, BodyKind::Loop, BodyKind::PostLoop,
                                     BodyKind::Reduce, BodyKind::Converged,
                                     BodyKind::InitializePair, BodyKind::LoopAll,
                                     BodyKind::HostReduce};
    PlanBody body;
    body.source.text = m.body.text;
    body.source.start = m.body.start;
    body.source.kind = kinds[m.kind];
    body.source.label = "equation " + decl->name.name + ", method " + ast::methodKeyword(m.kind);
    body.source.scalars = scalars;
    body.source.states = states;
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

}  // namespace sema_detail

std::unique_ptr<Plan> buildPlan(const std::vector<std::unique_ptr<ast::Module>>& modules,
                                DiagnosticEngine& diags) {
  if (modules.empty()) return nullptr;
  return sema_detail::SemaImpl(modules, diags).run();
}

}  // namespace sphc
