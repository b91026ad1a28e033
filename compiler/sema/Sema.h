// Sema: from parsed modules to a Plan. Resolves imports, names (arrays, equations, steppers,
// integrators, params), binds equation arguments and checks declarative-layer expressions.
// It does not look inside bodies: that is body/BodyAnalysis, run by the driver afterwards.
#pragma once

#include "frontend/AST.h"
#include "frontend/Diagnostics.h"
#include "sema/Plan.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace sphc {

// Parses `mainFile` and, transitively, the modules it imports. Import `a.b` is looked up as
// a/b.sph next to the importing file, then in each of `includeDirs`, then in `stdlibDir`.
// Returns the modules, main file first; an empty vector if the main file cannot be read.
std::vector<std::unique_ptr<ast::Module>> loadModules(
    const std::string& mainFile, const std::vector<std::string>& includeDirs,
    const std::string& stdlibDir, DiagnosticEngine& diags);

// Builds the plan of the (single) scene of modules[0]. Returns null after reporting errors.
std::unique_ptr<Plan> buildPlan(const std::vector<std::unique_ptr<ast::Module>>& modules,
                                DiagnosticEngine& diags);

// sphc --kernel=NAME: the scene's kernel replaced (before the analysis; `sphc study --vary
// kernel=...` rebuilds with it). False with `error` set for an unknown kernel.
bool overrideKernel(Plan& plan, const std::string& name, std::string& error);

// Checks a declarative-layer expression: every name must satisfy `isKnown` (which may report
// nothing; the error is reported here with `what` describing the context), calls must be
// math functions with the right number of arguments.
bool checkExpr(const ast::Expr& e, const std::function<bool(const std::string&)>& isKnown,
               const std::string& what, DiagnosticEngine& diags);

// The math functions allowed in declarative expressions, with their arity.
int mathFunctionArity(const std::string& name);  // -1 if unknown

// The names every declarative expression knows without a declaration: the numbers pi and e,
// the booleans true and false; their value and how generated C++ spells them.
struct BuiltinConstant {
  const char* name;
  double value;
  const char* cpp;
  bool number;  // pi, e (not a boolean)
};
const BuiltinConstant* builtinConstant(const std::string& name);  // nullptr if none

}  // namespace sphc
