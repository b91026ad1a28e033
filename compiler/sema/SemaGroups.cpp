// Semantic analysis of the scene's groups and equation instances: group options (compile
// time and run time), equation arguments and constants.
#include "sema/SemaImpl.h"

#include "sema/Geometry.h"

#include "llvm/ADT/StringExtras.h"

#include <cmath>

namespace sphc::sema_detail {

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
      } else if (k == "before_scheme") {
        // The options pass placed it first (sema/Options.cpp); here only checked.
        bool first = false;
        boolValue(first);
        if (depth != 0)
          diags_.error(kw.name.loc, "before_scheme is an option of a top-level group (one "
                                    "directly in `equations`), not of a nested group");
      } else
        diags_.error(kw.name.loc, "unknown group option '" + k +
                                      "'; options are: real, iterate, min_iterations, "
                                      "max_iterations, every, post_step, before_scheme, "
                                      "start_idx, stop_idx, condition, update_nnps");
    }
    if ((hasMin || hasMax) && !sub->iterate)
      diags_.error(gd.loc, "min_iterations/max_iterations need `iterate = true`");
    if (sub->iterate && !hasMax) sub->maxIterations = 100;
    if (sub->minIterations > sub->maxIterations)
      diags_.error(gd.loc, "min_iterations is larger than max_iterations");
    if (gd.pre) instantiate(*gd.pre, *sub);    // PySPH's pre: before the members
    buildGroup(gd.items, *sub, depth + 1);
    if (gd.post) instantiate(*gd.post, *sub);  // and post after them
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
  if (!inst.inlineDecl && it == equations_.end()) {
    diags_.error(inst.equation.loc, "unknown equation '" + inst.equation.name +
                                        "' (is its module imported?)");
    return;
  }
  const ast::EquationDecl* decl = inst.inlineDecl ? inst.inlineDecl.get() : it->second;
  PlanEquation eq;
  eq.hook = inst.inlineDecl != nullptr;
  eq.name = decl->name.name;
  eq.loc = inst.equation.loc;
  eq.effects = inst.effects;
  bool hasLoop = false;
  const char* loopKind = "loop";  // the first method that needs sources
  for (const auto& m : decl->methods)
    if (ast::seesSources(m.kind) && !hasLoop) {
      hasLoop = true;
      loopKind = ast::methodKeyword(m.kind);
    }
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
    diags_.error(inst.equation.loc, "equation '" + decl->name.name + "' has a " + loopKind +
                                    " and needs sources: sources = [ARRAY, ...]");
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
    // States: initial values of the parameters, consts and earlier states (set-up time).
    for (const auto& st : decl->states) {
      checkExpr(*st.value, [&](const std::string& n) { return visible.count(n) != 0; },
                "state '" + st.name.name + "' of equation '" + decl->name.name +
                    "' (its initial value may use the equation's parameters, consts and "
                    "earlier states)",
                diags_);
      visible.insert(st.name.name);
      eq.values.emplace_back(st.name.name, st.value);
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

}  // namespace sphc::sema_detail
