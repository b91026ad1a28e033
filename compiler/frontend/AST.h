// The AST of a .sph file: what the parser read, with source locations, and no meaning
// attached (Sema resolves names and binds parameters). Bodies of equations and steppers are
// kept as raw text; Clang parses them in body/BodyAnalysis.
#pragma once

#include "llvm/Support/SMLoc.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace sphc::ast {

struct Ident {
  std::string name;
  llvm::SMLoc loc;
};

// Declarative-layer expressions (params, initial values, equation arguments, scene settings).
struct Expr;
using ExprPtr = std::shared_ptr<const Expr>;
struct Expr {
  enum Kind { Number, Name, Unary, Binary, Call, Ternary };
  Kind kind = Number;
  llvm::SMLoc loc;
  double number = 0.0;        // Number
  std::string text;           // Number: literal as written; Name: identifier; Call: callee
  std::string op;             // Unary: "-", "+", "!"; Binary: + - * / % < <= > >= == != && ||
  std::vector<ExprPtr> args;  // Unary: 1, Binary: 2, Call: n, Ternary: cond, then, else
};

// `name = expr` or `name = [a, b]` in an argument list (equation instances, geometry, group
// options, adaptive_dt).
struct KwArg {
  Ident name;
  ExprPtr value;               // set unless isList
  bool isList = false;
  std::vector<Ident> list;     // `[fluid, boundary]`
};

// Raw C text of a method body: the characters between `{` and the matching `}`.
struct Body {
  std::string text;
  llvm::SMLoc start;           // the first character of `text` (just after `{`)
};

// Compile-time options: `option scheme in [wcsph, edac] = wcsph;` declares one, `sphc -D
// scheme=edac` chooses a value, and `when scheme == edac { ... }` blocks (in a scene, an
// `equations`/`group` list or an array) are kept or dropped by the options pass before Sema.
struct OptionDecl {
  Ident name;
  std::vector<Ident> choices;
  Ident defaultChoice;
};

// `effect delta_sph needs [density_gradient] "Marrone et al. 2011 density diffusion";`: a
// physical effect a scheme can simulate (docs/effects.md). An effect is a compile-time option
// with the choices off and on: a scene's `effects = [...]` turns the listed ones on, `sphc -D
// NAME=on|off` overrides, and `when NAME { ... }` keeps what only the effect needs.
// `vector (ustar, vstar, wstar);`: three scalar properties are the x, y and z components
// of one vector, so that a 2D scene leaves out the third and a 1D scene the second and third
// as it does z, w, az, ... (analysis/Dimensions.cpp; PySPH-style names keep working).
struct VectorDecl {
  llvm::SMLoc loc;              // the `vector` keyword
  std::vector<Ident> components;  // x, y, z
};

struct EffectDecl {
  Ident name;
  std::vector<Ident> needs;     // effects this one needs on
  std::string doc;              // one line for --report and --help (may be empty)
};

// `when NAME == v`, `when NAME != v`, `when NAME in [v, w]`; for an effect `when NAME` and
// `when !NAME` (NAME == on, NAME != on).
struct WhenCondition {
  llvm::SMLoc loc;              // the `when` keyword
  Ident option;
  std::vector<Ident> values;    // one for == and !=
  bool negated = false;         // !=
  bool isIn = false;            // `in [...]`
  bool bare = false;            // `when NAME` / `when !NAME`: an effect's on/off
};

// `when C1 { ... } else when C2 { ... } else { ... }`: the first branch whose condition holds
// is kept (a branch without a condition is the `else`). Body is the fragment of the enclosing
// construct that the branch holds (scene items, group items or array items).
template <class Body>
struct When {
  struct Branch {
    bool hasCondition = false;
    WhenCondition condition;
    Body body;
  };
  std::vector<Branch> branches;
};

struct ImportDecl {
  std::vector<Ident> path;     // import a.b;  -> {a, b}
  llvm::SMLoc loc;
};

struct ParamDecl {
  Ident name;
  ExprPtr value;
  bool derived = false;  // `let`: computed from params, not overridable at run time
  Ident effect;          // `param delta = 0.1 for delta_sph;`: exists only with the effect on
};

struct PropertyDecl {
  Ident name;
  std::string type = "double";  // "double", "int", "uint"
  int stride = 1;
  ExprPtr init;                 // may be null: 0
  llvm::SMLoc loc;              // the `property` keyword
  bool fromScheme = false;      // added by a scheme (sema/Schemes.cpp)
};

struct ConstDecl {
  Ident name;
  int size = 1;
  ExprPtr init;                 // may be null: 0
};

struct GeometryDecl {
  Ident builder;                // block, tank, disk, sphere, cylinder, line
  std::vector<KwArg> args;
};

struct LoadDecl {
  std::string path;             // as written (relative to the .sph file)
  llvm::SMLoc loc;
};

struct ArrayDecl {
  Ident name;
  std::vector<GeometryDecl> geometry;
  std::vector<LoadDecl> loads;
  std::vector<PropertyDecl> properties;
  std::vector<ConstDecl> constants;
  std::vector<std::shared_ptr<When<ArrayDecl>>> whens;  // items of the chosen branch are
                                                        // added after the others
};

struct EqParam {
  Ident name;
  ExprPtr defaultValue;         // may be null: required argument
};

struct EqConst {
  Ident name;
  ExprPtr value;
};

struct Method {
  // InitializePair (per destination particle and source array, before that source's
  // neighbours) and LoopAll (per destination particle and source array, with the whole
  // neighbour list NBRS, N_NBRS) are PySPH's initialize_pair and loop_all.
  // HostReduce: `reduce { }` without an operator, PySPH's reduce(dst, t, dt): once per
  // evaluation, on the host, after the group's per-particle work on the destination.
  enum Kind { Initialize, Loop, PostLoop, Reduce, Converged, InitializePair, LoopAll,
              HostReduce };
  Kind kind = Initialize;
  llvm::SMLoc loc;              // the method keyword
  std::string reduceOp;         // Reduce: "sum", "max", "min", "mean"
  Ident reduceTarget;           // Reduce: the array constant receiving the result
  Body body;
};

// The method's keyword in .sph (and in generated function names).
inline const char* methodKeyword(Method::Kind k) {
  static const char* const names[] = {"initialize", "loop",           "post_loop", "reduce",
                                      "converged",  "initialize_pair", "loop_all",  "reduce"};
  return names[k];
}

// The methods that see the source arrays (s_*): they run once per source the instance lists.
inline bool seesSources(Method::Kind k) {
  return k == Method::Loop || k == Method::LoopAll || k == Method::InitializePair;
}

struct EquationDecl {
  Ident name;
  std::vector<EqParam> params;
  std::vector<EqConst> consts;
  // `state NAME = expr;`: per-instance state (PySPH's self.NAME), initialised at set-up from
  // the instance's parameters and consts, kept between calls; `converged` may write it.
  std::vector<EqConst> states;
  std::vector<Method> methods;
};

// `function double NAME(PARAMS) { C99 }`: a helper function that bodies (and later helpers)
// may call. The parser checks the return type and the name; the parameters and the body are
// C99 for Clang (body/BodyAnalysis). `text` runs from the return type to the closing `}`
// inclusive, so Clang's positions in the signature map back to the .sph file too.
struct FunctionDecl {
  Ident name;
  std::string returnType;       // double, int, void
  llvm::SMLoc loc;              // the `function` keyword
  Body text;                    // the whole definition without the `function` keyword
};

struct StepperMethod {
  Ident name;                   // "initialize", "stage1", "stage2", ...
  Body body;
};

struct StepperDecl {
  Ident name;
  std::vector<StepperMethod> methods;
};

struct IntegratorDecl {
  Ident name;
  std::vector<Ident> steps;     // initialize, stageN, compute_accelerations, update_domain
};

struct EquationInstance {
  Ident equation;
  std::vector<KwArg> args;      // dest = a, sources = [b, c], param = expr
  // A group's `pre ARRAY { }` / `post ARRAY { }`: an unnamed equation whose only method is a
  // host `reduce { }` (set only for those; `equation` then names it for messages).
  std::shared_ptr<EquationDecl> inlineDecl;
  std::vector<std::string> effects;  // the `when EFFECT` blocks it was kept by (options pass)
};

struct GroupDecl;
// One entry of an `equations { }` or `group { }` list: exactly one of the three is set. The
// options pass replaces each `when` by the items of its chosen branch, in place.
struct GroupItem {
  std::shared_ptr<GroupDecl> group;
  std::shared_ptr<EquationInstance> equation;
  std::shared_ptr<When<std::vector<GroupItem>>> when;
};

struct GroupDecl {
  llvm::SMLoc loc;              // the `group` keyword
  std::vector<KwArg> options;   // real, iterate, min_iterations, max_iterations
  std::vector<GroupItem> items;
  // `pre ARRAY { BODY }`, `post ARRAY { BODY }` (PySPH's Group(pre=, post=)): host bodies run
  // before and after the group's members (in each iteration of an iterated group).
  std::shared_ptr<EquationInstance> pre, post;
};

struct OutputDecl {
  llvm::SMLoc loc;
  ExprPtr every;                // `output every T`, or null
  std::vector<ExprPtr> at;      // `output at [t1, t2]`
  struct Item {
    Ident array;
    std::vector<Ident> props;
  };
  std::vector<Item> items;
};

struct SceneSetting {
  Ident key;                    // dim, kernel, tf, dt, integrator, ...
  ExprPtr value;                // identifiers (CubicSpline, PECIntegrator) are Name exprs
};

struct SceneStepper {
  Ident array;
  Ident stepper;
};

// `domain { periodic x in [0, L]; mirror y >= 0; }`: the boundaries of the simulated box.
// One item per axis and kind; sema checks the axes, intervals and clashes.
struct DomainItem {
  enum Kind { Periodic, Mirror };
  Kind kind = Periodic;
  llvm::SMLoc loc;              // the `periodic` / `mirror` keyword
  Ident axis;                   // x, y or z (as written; sema checks)
  // `in [lo, hi]`: both; `>= lo`: lo only; `<= hi`: hi only.
  ExprPtr lo, hi;
};

struct DomainDecl {
  llvm::SMLoc loc;              // the `domain` keyword
  std::vector<DomainItem> items;
};

// `limits { fluid.rho warn [lo, hi] stop [lo, hi]; fluid.speed stop <= c; }`: what the run
// watches (docs/language.md, Limits). A bound is an interval or one side of one.
struct LimitBound {
  llvm::SMLoc loc;              // the `warn` / `stop` keyword
  ExprPtr lo, hi;               // either may be absent (`<= hi`, `>= lo`), not both
};

struct LimitItem {
  Ident array;
  Ident quantity;               // a property of the array, or `speed` (|(u, v, w)|)
  std::optional<LimitBound> warn, stop;
  // `remove [lo, hi] where y >= W`: the particles outside `remove` (where the condition on
  // another coordinate holds) leave the run, counted (docs/language.md, Limits).
  std::optional<LimitBound> remove;
  Ident removeWhere;            // the condition's coordinate (empty name: no condition)
  std::optional<LimitBound> removeWhereBound;
};

struct LimitsDecl {
  llvm::SMLoc loc;              // the `limits` keyword
  std::vector<LimitItem> items;
};

// `metrics { NAME = KIND(ARRAY, EXPR, key = value, ...); }`: what the solver measures at output
// times (docs/language.md, Metrics). KIND: L1, L2, Linf (a norm against `exact`), max, min,
// sum, mean (a scalar, compared with `exact` or `reference` if given).
struct MetricArg {
  Ident name;
  ExprPtr value;                // an expression, unless isString
  bool isString = false;
  std::string text;             // the string's contents
  llvm::SMLoc loc;              // the value
};

struct MetricItem {
  Ident name;
  Ident kind;
  Ident array;
  ExprPtr expr;                 // per particle: properties of the array, params, t
  std::vector<MetricArg> args;
};

struct MetricsDecl {
  llvm::SMLoc loc;              // the `metrics` keyword
  std::vector<MetricItem> items;
};

// `scheme wcsph(fluids = [fluid], solids = [boundary], rho0 = ro, c0 = co);` in a scene: the
// scheme's items (sema/Schemes.cpp) are added to the scene with the arguments substituted.
struct SchemeUse {
  Ident scheme;
  std::vector<KwArg> args;
  llvm::SMLoc loc;              // the `scheme` keyword
};

// `inlet NAME(array = a, feeds = fluid, ...);` / `outlet NAME(array = a, from = fluid, ...);`:
// an open-boundary zone (docs/language.md, Inlets and outlets; sema/Zones.cpp checks it).
struct ZoneDecl {
  bool inlet = true;
  Ident name;
  llvm::SMLoc loc;              // the `inlet` / `outlet` keyword
  std::vector<KwArg> args;
};

// `property fluids double[3] gradc = 0;` / `const fluids umax = 0;` in a scheme: a property or
// constant the scheme's equations need, declared on the arrays of an array-list parameter
// (sema/Schemes.cpp). The expansion replaces the parameter with the scene's arrays; the
// options pass adds the items of the chosen `when` branches to those arrays, where a
// declaration of the array itself (same type and shape) wins.
struct SchemeArrayItem {
  std::vector<Ident> arrays;    // as written: list parameters; expanded: the scene's arrays
  ArrayDecl item;               // one property or one constant
  Ident param;                  // expanded: the list parameter the arrays came from
  std::string scheme;           // expanded: the scheme that declares it
  llvm::SMLoc use;              // expanded: the scheme's use in the scene
};

struct SceneDecl {
  Ident name;
  llvm::SMLoc effectsLoc;       // `effects = [a, b];` (invalid when the scene has none)
  std::vector<Ident> effects;
  std::vector<SchemeUse> schemes;
  std::vector<SceneSetting> settings;
  std::vector<SceneStepper> steppers;
  bool hasAdaptiveDt = false;
  llvm::SMLoc adaptiveDtLoc;
  std::vector<KwArg> adaptiveDt;
  std::vector<OutputDecl> outputs;
  std::vector<DomainDecl> domains;  // sema allows one
  std::vector<LimitsDecl> limits;
  std::vector<MetricsDecl> metrics;
  std::vector<ZoneDecl> zones;
  llvm::SMLoc equationsLoc;
  std::vector<GroupItem> equations;
  std::vector<SchemeArrayItem> arrayItems;  // a scheme's properties and constants
  std::vector<std::shared_ptr<When<SceneDecl>>> whens;  // the chosen branch's items are
                                                        // added after the others
};

// `scheme NAME(fluids, solids = [], rho0, c0, alpha = 0.1) { scene items }` at top level: a
// scheme written once, as per-effect `when` blocks of scene items (integrator, steppers,
// settings, adaptive_dt, equations). A parameter is bound to an array list (`[fluid]`) or an
// expression; array-list parameters expand in `dest =`, `sources = [...]` and `stepper`.
struct SchemeParam {
  Ident name;
  bool hasDefault = false;
  KwArg defaultValue;           // name = the parameter's name
};

struct SchemeDecl {
  Ident name;
  std::vector<SchemeParam> params;
  std::shared_ptr<SceneDecl> body;
};

// One parsed file. Sema merges a scene's module with the modules it imports.
struct Module {
  std::string filename;         // as given on the command line or resolved for an import
  unsigned bufferId = 0;        // in the DiagnosticEngine's SourceMgr
  std::vector<ImportDecl> imports;
  std::vector<OptionDecl> options;
  std::vector<EffectDecl> effects;
  std::vector<VectorDecl> vectors;
  std::vector<SchemeDecl> schemes;
  std::vector<ParamDecl> params;
  std::vector<ArrayDecl> arrays;
  std::vector<EquationDecl> equations;
  std::vector<FunctionDecl> functions;
  std::vector<StepperDecl> steppers;
  std::vector<IntegratorDecl> integrators;
  std::vector<SceneDecl> scenes;
};

}  // namespace sphc::ast
