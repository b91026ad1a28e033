#include "sema/Schemes.h"

#include <map>
#include <optional>
#include <string>

namespace sphc {

namespace {

// A parameter's value at one use: an array list or an expression.
struct Binding {
  bool isList = false;
  std::vector<ast::Ident> arrays;
  ast::ExprPtr expr;
};

class Expander {
 public:
  Expander(DiagnosticEngine& diags, const std::map<std::string, Binding>& b, llvm::SMLoc use,
           std::string scheme)
      : diags_(diags), bind_(b), use_(use), scheme_(std::move(scheme)) {}

  bool ok = true;

  ast::ExprPtr expr(const ast::ExprPtr& e) {
    if (!e) return e;
    if (e->kind == ast::Expr::Name) {
      auto it = bind_.find(e->text);
      if (it == bind_.end()) return e;
      if (it->second.isList) {
        diags_.error(e->loc, "scheme parameter '" + e->text +
                                 "' is a list of arrays, used here as a value");
        ok = false;
        return e;
      }
      return it->second.expr;
    }
    if (e->args.empty()) return e;
    auto copy = std::make_shared<ast::Expr>(*e);
    for (auto& a : copy->args) a = expr(a);
    return copy;
  }

  // An array name, or the arrays of a list parameter.
  std::vector<ast::Ident> arrays(const ast::Ident& id) {
    auto it = bind_.find(id.name);
    if (it == bind_.end()) return {id};
    if (!it->second.isList) {
      diags_.error(id.loc, "scheme parameter '" + id.name +
                               "' is a value, used here as a list of arrays");
      ok = false;
      return {id};
    }
    return it->second.arrays;
  }

  std::vector<ast::KwArg> kwargs(const std::vector<ast::KwArg>& in) {
    std::vector<ast::KwArg> out;
    for (const auto& a : in) {
      ast::KwArg k = a;
      if (a.isList) {
        k.list.clear();
        for (const auto& id : a.list)
          for (auto& x : arrays(id)) k.list.push_back(x);
      } else {
        k.value = expr(a.value);
      }
      out.push_back(std::move(k));
    }
    return out;
  }

  // One equation instance becomes none, one, or one per destination array.
  void equation(const ast::EquationInstance& eq, std::vector<ast::GroupItem>& out) {
    std::vector<ast::Ident> dests;
    bool hasDest = false;
    for (const auto& a : eq.args) {
      if (a.name.name == "dest" && !a.isList && a.value && a.value->kind == ast::Expr::Name) {
        hasDest = true;
        ast::Ident id{a.value->text, a.value->loc};
        dests = arrays(id);
      }
    }
    std::vector<ast::KwArg> args;
    for (const auto& a : eq.args) {
      bool isDest = a.name.name == "dest" && !a.isList;
      auto one = isDest ? std::vector<ast::KwArg>{a} : kwargs({a});
      args.push_back(one.front());
    }
    for (size_t i = 0; i < eq.args.size(); ++i)
      if (eq.args[i].name.name == "sources" && eq.args[i].isList && !eq.args[i].list.empty() &&
          args[i].list.empty())
        return;  // every source is an empty list parameter
    if (!hasDest) {
      auto inst = std::make_shared<ast::EquationInstance>(eq);
      inst->args = args;
      out.push_back(ast::GroupItem{nullptr, inst, nullptr});
      return;
    }
    for (const auto& d : dests) {
      auto inst = std::make_shared<ast::EquationInstance>(eq);
      inst->args = args;
      for (auto& a : inst->args)
        if (a.name.name == "dest" && !a.isList) {
          auto v = std::make_shared<ast::Expr>();
          v->kind = ast::Expr::Name;
          v->text = d.name;
          v->loc = d.loc;
          a.value = v;
        }
      out.push_back(ast::GroupItem{nullptr, inst, nullptr});
    }
  }

  std::vector<ast::GroupItem> items(const std::vector<ast::GroupItem>& in) {
    std::vector<ast::GroupItem> out;
    for (const auto& item : in) {
      if (item.equation) {
        equation(*item.equation, out);
      } else if (item.group) {
        auto g = std::make_shared<ast::GroupDecl>();
        g->loc = item.group->loc;
        g->options = kwargs(item.group->options);
        g->items = items(item.group->items);
        if (!g->items.empty()) out.push_back(ast::GroupItem{g, nullptr, nullptr});
      } else if (item.when) {
        auto w = std::make_shared<ast::When<std::vector<ast::GroupItem>>>();
        for (const auto& b : item.when->branches) {
          auto& nb = w->branches.emplace_back();
          nb.hasCondition = b.hasCondition;
          nb.condition = b.condition;
          nb.body = items(b.body);
        }
        out.push_back(ast::GroupItem{nullptr, nullptr, w});
      }
    }
    return out;
  }

  // `property fluids ...;`: one item per list parameter, its arrays the scene's, its initial
  // value substituted. A name that is no list parameter of the scheme is an error.
  void arrayItem(const ast::SchemeArrayItem& in, ast::SceneDecl& to) {
    for (const auto& id : in.arrays) {
      auto it = bind_.find(id.name);
      if (it == bind_.end() || !it->second.isList) {
        diags_.error(id.loc, std::string(in.item.properties.empty() ? "a constant" : "a property") +
                                 " of scheme '" + scheme_ + "' is declared on '" + id.name +
                                 "', which is no array-list parameter of the scheme");
        diags_.note(use_, "the scheme is used here");
        ok = false;
        continue;
      }
      ast::SchemeArrayItem out;
      out.arrays = it->second.arrays;
      out.item = in.item;
      for (auto& p : out.item.properties) p.init = expr(p.init);
      for (auto& c : out.item.constants) c.init = expr(c.init);
      out.param = id;
      out.scheme = scheme_;
      out.use = use_;
      to.arrayItems.push_back(std::move(out));
    }
  }

  // The scheme's scene items, substituted, added to `to`.
  void scene(const ast::SceneDecl& from, ast::SceneDecl& to) {
    for (const auto& s : from.settings) {
      ast::SceneSetting c = s;
      c.value = expr(s.value);
      // internal_flow_needs is about the scene that uses the scheme (analysis/InternalFlow):
      // its key is placed at the use, its value stays where the scheme names the effect.
      if (c.key.name == "internal_flow_needs") c.key.loc = use_;
      to.settings.push_back(std::move(c));
    }
    for (const auto& item : from.arrayItems) arrayItem(item, to);
    for (const auto& st : from.steppers)
      for (const auto& a : arrays(st.array)) to.steppers.push_back(ast::SceneStepper{a, st.stepper});
    if (from.hasAdaptiveDt) {
      to.hasAdaptiveDt = true;
      to.adaptiveDtLoc = from.adaptiveDtLoc;
      to.adaptiveDt = kwargs(from.adaptiveDt);
    }
    if (from.equationsLoc.isValid()) {
      to.equationsLoc = from.equationsLoc;
      std::vector<ast::GroupItem> eqs = items(from.equations);
      for (auto& e : to.equations) eqs.push_back(std::move(e));
      to.equations = std::move(eqs);
    }
    for (const auto& w : from.whens) {
      auto nw = std::make_shared<ast::When<ast::SceneDecl>>();
      for (const auto& b : w->branches) {
        auto& nb = nw->branches.emplace_back();
        nb.hasCondition = b.hasCondition;
        nb.condition = b.condition;
        nb.body.name = to.name;
        scene(b.body, nb.body);
      }
      to.whens.push_back(nw);
    }
  }

 private:
  DiagnosticEngine& diags_;
  const std::map<std::string, Binding>& bind_;
  llvm::SMLoc use_;  // the scheme's use in the scene (`scheme NAME(...)`)
  std::string scheme_;
};

// What a scheme may hold: the items a scheme decides, not those of one scene.
bool checkSchemeItems(const ast::SceneDecl& body, const std::string& name,
                      DiagnosticEngine& diags, llvm::SMLoc loc) {
  bool ok = true;
  auto bad = [&](const char* what) {
    diags.error(loc, "scheme '" + name + "' holds " + what +
                         ": a scheme holds settings, steppers, adaptive_dt, equations and its "
                         "arrays' properties and constants; "
                         "outputs, domains, limits and effects belong to the scene");
    ok = false;
  };
  if (!body.outputs.empty()) bad("an output");
  if (!body.domains.empty()) bad("a domain");
  if (!body.limits.empty()) bad("limits");
  if (body.effectsLoc.isValid()) bad("an effects list");
  if (!body.schemes.empty()) bad("a scheme");
  for (const auto& w : body.whens)
    for (const auto& b : w->branches) ok = checkSchemeItems(b.body, name, diags, loc) && ok;
  return ok;
}

}  // namespace

bool expandSchemes(const std::vector<std::unique_ptr<ast::Module>>& modules, ast::SceneDecl& scene,
                   DiagnosticEngine& diags) {
  bool ok = true;
  auto uses = std::move(scene.schemes);
  scene.schemes.clear();
  for (const auto& use : uses) {
    const ast::SchemeDecl* decl = nullptr;
    std::vector<std::string> known;
    for (const auto& mod : modules)
      for (const auto& s : mod->schemes) {
        known.push_back(s.name.name);
        if (s.name.name == use.scheme.name) decl = &s;
      }
    if (!decl) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      diags.error(use.scheme.loc, "unknown scheme '" + use.scheme.name + "'" +
                                      (list.empty() ? std::string(" (no imported module declares "
                                                                  "a scheme)")
                                                    : " (known schemes: " + list + ")"));
      ok = false;
      continue;
    }
    std::map<std::string, Binding> bind;
    std::map<std::string, const ast::KwArg*> given;
    bool good = true;
    for (const auto& a : use.args) {
      bool isParam = false;
      for (const auto& p : decl->params) isParam |= p.name.name == a.name.name;
      if (!isParam) {
        std::string list;
        for (const auto& p : decl->params) list += (list.empty() ? "" : ", ") + p.name.name;
        diags.error(a.name.loc, "scheme '" + decl->name.name + "' has no parameter '" +
                                    a.name.name + "' (its parameters: " + list + ")");
        diags.note(decl->name.loc, "scheme '" + decl->name.name + "' is declared here");
        good = false;
        continue;
      }
      if (given.count(a.name.name)) {
        diags.error(a.name.loc, "argument '" + a.name.name + "' is given twice");
        good = false;
        continue;
      }
      given[a.name.name] = &a;
    }
    for (const auto& p : decl->params) {
      const ast::KwArg* a = nullptr;
      if (auto it = given.find(p.name.name); it != given.end()) a = it->second;
      else if (p.hasDefault) a = &p.defaultValue;
      if (!a) {
        diags.error(use.scheme.loc, "scheme '" + decl->name.name + "' needs the argument '" +
                                        p.name.name + "'");
        diags.note(p.name.loc, "parameter '" + p.name.name + "' is declared here");
        good = false;
        continue;
      }
      Binding b;
      b.isList = a->isList;
      b.arrays = a->list;
      b.expr = a->value;
      bind[p.name.name] = b;
    }
    good = checkSchemeItems(*decl->body, decl->name.name, diags, decl->name.loc) && good;
    if (!good) {
      ok = false;
      continue;
    }
    Expander ex(diags, bind, use.scheme.loc, decl->name.name);
    ex.scene(*decl->body, scene);
    ok = ex.ok && ok;
  }
  return ok;
}

namespace {

// "double[3]", "int", "a constant", "a constant[3]": what a declaration makes of a name.
std::string shape(const ast::ArrayDecl& one) {
  if (!one.properties.empty()) {
    const auto& p = one.properties.front();
    return p.stride == 1 ? p.type : p.type + "[" + std::to_string(p.stride) + "]";
  }
  const auto& c = one.constants.front();
  return c.size == 1 ? "a constant" : "a constant[" + std::to_string(c.size) + "]";
}

const ast::Ident& declaredName(const ast::ArrayDecl& one) {
  return one.properties.empty() ? one.constants.front().name : one.properties.front().name;
}

// The array's declaration of `name`, a property or a constant, as a one-item ArrayDecl.
std::optional<ast::ArrayDecl> declarationOf(const ast::ArrayDecl& a, const std::string& name) {
  ast::ArrayDecl one;
  for (const auto& p : a.properties)
    if (p.name.name == name) {
      one.properties.push_back(p);
      return one;
    }
  for (const auto& c : a.constants)
    if (c.name.name == name) {
      one.constants.push_back(c);
      return one;
    }
  return std::nullopt;
}

std::string listText(const std::vector<ast::Ident>& arrays) {
  std::string s;
  for (const auto& a : arrays) s += (s.empty() ? "" : ", ") + a.name;
  return "[" + s + "]";
}

}  // namespace

bool addSchemeArrayItems(const std::vector<std::unique_ptr<ast::Module>>& modules,
                         ast::SceneDecl& scene, DiagnosticEngine& diags) {
  bool ok = true;
  // The scheme item that added a name to an array, for the wording of a later conflict.
  std::map<std::pair<std::string, std::string>, const ast::SchemeArrayItem*> added;
  auto items = std::move(scene.arrayItems);
  scene.arrayItems.clear();
  for (const auto& item : items) {
    const ast::Ident& name = declaredName(item.item);
    const std::string want = shape(item.item);
    for (const auto& arrayId : item.arrays) {
      ast::ArrayDecl* array = nullptr;
      for (const auto& m : modules)
        for (auto& a : m->arrays)
          if (!array && a.name.name == arrayId.name) array = &a;
      if (!array) {
        diags.error(arrayId.loc, "'" + arrayId.name + "' is no array: scheme '" + item.scheme +
                                     "' declares '" + name.name + "' on its parameter '" +
                                     item.param.name + "'");
        diags.note(name.loc, "'" + name.name + "' is declared here");
        ok = false;
        continue;
      }
      // What the array already holds under the name: its own declaration or an earlier
      // scheme item's.
      std::optional<ast::ArrayDecl> have = declarationOf(*array, name.name);
      if (!have) {
        for (const auto& p : item.item.properties) {
          array->properties.push_back(p);
          array->properties.back().fromScheme = true;
        }
        for (const auto& c : item.item.constants) array->constants.push_back(c);
        added[{array->name.name, name.name}] = &item;
        continue;
      }
      const std::string haveShape = shape(*have);
      if (haveShape == want) continue;  // the array's declaration (or the first scheme's) wins
      auto by = added.find({array->name.name, name.name});
      const bool byScheme = by != added.end();
      diags.error(declaredName(*have).loc,
                  "'" + name.name + "' of array '" + array->name.name + "' is declared " +
                      haveShape + " here" +
                      (byScheme ? " by scheme '" + by->second->scheme + "'" : std::string()) +
                      ", and " + want + " by scheme '" + item.scheme +
                      "': the declarations must agree in type and shape" +
                      (byScheme ? std::string()
                                : " (declare it as the scheme does, or leave it to the scheme)"));
      diags.note(name.loc, "scheme '" + item.scheme + "' declares '" + name.name + "' " + want +
                               " here, on its parameter '" + item.param.name + "'");
      diags.note(item.use, "the scene uses scheme '" + item.scheme + "' here, with " +
                               item.param.name + " = " + listText(item.arrays));
      ok = false;
    }
  }
  return ok;
}

}  // namespace sphc
