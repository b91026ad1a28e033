// The semantic analysis's internal class, shared by its source files: Sema.cpp (tables,
// functions, arrays, equations and steppers used), SemaScene.cpp (the scene block: settings,
// limits, domain) and SemaGroups.cpp (groups and equation instances). Internal to sema/.
#pragma once

#include "sema/Sema.h"

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace sphc::sema_detail {

const std::vector<std::string>& kernelNames();
double kernelRadius(const std::string& k);
std::string joinNames(const std::vector<std::string>& v);
// The value of an expression made of literals only; nothing if it names a parameter.
std::optional<double> literalValue(const ast::Expr& e);

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
  void buildVectors();
  void buildArrays();
  void checkGeometry(const ast::GeometryDecl& g, const std::string& array);
  void checkPropertyInit(const ast::ArrayDecl& a, const ast::PropertyDecl& p,
                         const std::set<std::string>& before);
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

}  // namespace sphc::sema_detail
