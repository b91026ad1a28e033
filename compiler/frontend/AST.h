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

// `when NAME == v`, `when NAME != v`, `when NAME in [v, w]`.
struct WhenCondition {
  llvm::SMLoc loc;              // the `when` keyword
  Ident option;
  std::vector<Ident> values;    // one for == and !=
  bool negated = false;         // !=
  bool isIn = false;            // `in [...]`
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
};

struct PropertyDecl {
  Ident name;
  std::string type = "double";  // "double", "int", "uint"
  int stride = 1;
  ExprPtr init;                 // may be null: 0
  llvm::SMLoc loc;              // the `property` keyword
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
  enum Kind { Initialize, Loop, PostLoop, Reduce, Converged };
  Kind kind = Initialize;
  llvm::SMLoc loc;              // the method keyword
  std::string reduceOp;         // Reduce: "sum", "max", "min", "mean"
  Ident reduceTarget;           // Reduce: the array constant receiving the result
  Body body;
};

struct EquationDecl {
  Ident name;
  std::vector<EqParam> params;
  std::vector<EqConst> consts;
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
};

struct LimitsDecl {
  llvm::SMLoc loc;              // the `limits` keyword
  std::vector<LimitItem> items;
};

// `inlet NAME(array = a, feeds = fluid, ...);` / `outlet NAME(array = a, from = fluid, ...);`:
// an open-boundary zone (docs/language.md, Inlets and outlets; sema/Zones.cpp checks it).
struct ZoneDecl {
  bool inlet = true;
  Ident name;
  llvm::SMLoc loc;              // the `inlet` / `outlet` keyword
  std::vector<KwArg> args;
};

struct SceneDecl {
  Ident name;
  std::vector<SceneSetting> settings;
  std::vector<SceneStepper> steppers;
  bool hasAdaptiveDt = false;
  llvm::SMLoc adaptiveDtLoc;
  std::vector<KwArg> adaptiveDt;
  std::vector<OutputDecl> outputs;
  std::vector<DomainDecl> domains;  // sema allows one
  std::vector<LimitsDecl> limits;
  std::vector<ZoneDecl> zones;
  llvm::SMLoc equationsLoc;
  std::vector<GroupItem> equations;
  std::vector<std::shared_ptr<When<SceneDecl>>> whens;  // the chosen branch's items are
                                                        // added after the others
};

// One parsed file. Sema merges a scene's module with the modules it imports.
struct Module {
  std::string filename;         // as given on the command line or resolved for an import
  unsigned bufferId = 0;        // in the DiagnosticEngine's SourceMgr
  std::vector<ImportDecl> imports;
  std::vector<OptionDecl> options;
  std::vector<ParamDecl> params;
  std::vector<ArrayDecl> arrays;
  std::vector<EquationDecl> equations;
  std::vector<FunctionDecl> functions;
  std::vector<StepperDecl> steppers;
  std::vector<IntegratorDecl> integrators;
  std::vector<SceneDecl> scenes;
};

}  // namespace sphc::ast
