// Compile-time values of declarative expressions (params, lets, scene settings, equation
// arguments): constant folding over the AST with every `param` at its default and every
// `let` computed from them. What depends on anything else (a property, t, an array constant)
// has no value. The solver recomputes the same expressions at start-up with the values of
// --set, so what the compiler concludes from these values is about the defaults only.
#pragma once

#include "frontend/AST.h"
#include "sema/Plan.h"

#include <map>
#include <optional>
#include <string>

namespace sphc {

class ConstEval {
 public:
  explicit ConstEval(const Plan& plan);
  // Overrides or adds a name (e.g. a scheme parameter) with a fixed value.
  void set(const std::string& name, double value) { fixed_[name] = value; }
  // The expression's value, or nothing (an unknown name, a cycle, a function it lacks).
  std::optional<double> operator()(const ast::Expr& e, int depth = 0) const;
  std::optional<double> operator()(const ast::ExprPtr& e) const {
    return e ? (*this)(*e) : std::nullopt;
  }

 private:
  std::map<std::string, const ast::Expr*> decls_;
  std::map<std::string, double> fixed_;
};

}  // namespace sphc
