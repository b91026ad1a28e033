#include "sema/Options.h"
#include "sema/Schemes.h"

#include "llvm/ADT/STLExtras.h"
#include "llvm/ADT/StringRef.h"

#include <algorithm>
#include <map>

namespace sphc {

namespace {

// Moves the items of a chosen `when` branch to the end of what it is part of.
template <class T>
void append(std::vector<T>& to, std::vector<T>& from) {
  for (auto& x : from) to.push_back(std::move(x));
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (size_t i = 0; i < names.size(); ++i) s += (i ? ", " : "") + names[i];
  return s;
}

class OptionSelector {
 public:
  OptionSelector(DiagnosticEngine& diags, const std::vector<std::unique_ptr<ast::Module>>& modules)
      : diags_(diags), modules_(&modules) {}

  bool declare(const std::vector<std::unique_ptr<ast::Module>>& modules) {
    bool ok = true;
    for (const auto& mod : modules) {
      for (const auto& o : mod->options) {
        if (auto it = decls_.find(o.name.name); it != decls_.end()) {
          repeated("option '" + o.name.name + "'", "declared", o.name.loc, it->second->name.loc);
          ok = false;
          continue;
        }
        decls_[o.name.name] = &o;
        ChosenOption c;
        c.name = o.name.name;
        std::map<std::string, llvm::SMLoc> seen;
        for (const auto& ch : o.choices) {
          if (auto s = seen.find(ch.name); s != seen.end()) {
            diags_.error(ch.loc, "choice '" + ch.name + "' of option '" + o.name.name +
                                     "' is listed twice");
            ok = false;
            continue;
          }
          seen[ch.name] = ch.loc;
          c.choices.push_back(ch.name);
        }
        if (!llvm::is_contained(c.choices, o.defaultChoice.name)) {
          diags_.error(o.defaultChoice.loc, "the default '" + o.defaultChoice.name +
                                                "' of option '" + o.name.name +
                                                "' is not one of its choices (" +
                                                joined(c.choices) + ")");
          ok = false;
        }
        c.value = o.defaultChoice.name;
        chosen_.push_back(std::move(c));
      }
    }
    for (const auto& mod : modules) {
      for (const auto& e : mod->effects) {
        if (auto it = effectDecls_.find(e.name.name); it != effectDecls_.end()) {
          repeated("effect '" + e.name.name + "'", "declared", e.name.loc, it->second->name.loc);
          ok = false;
          continue;
        }
        if (auto it = decls_.find(e.name.name); it != decls_.end()) {
          diags_.error(e.name.loc, "'" + e.name.name + "' is declared as an option and an effect");
          diags_.note(it->second->name.loc, "the option is declared here");
          ok = false;
          continue;
        }
        effectDecls_[e.name.name] = &e;
        ChosenOption c;
        c.name = e.name.name;
        c.choices = {"off", "on"};
        c.value = "off";
        c.isEffect = true;
        c.doc = e.doc;
        for (const auto& n : e.needs) c.needs.push_back(n.name);
        chosen_.push_back(std::move(c));
      }
    }
    for (const auto& [name, e] : effectDecls_)
      for (const auto& n : e->needs)
        if (!effectDecls_.count(n.name)) {
          diags_.error(n.loc, "effect '" + name + "' needs '" + n.name +
                                  "', which is no effect (" + knownEffects() + ")");
          ok = false;
        }
    return ok;
  }

  // `what` (option 'x', ...) declared or listed (`verb`) a second time, at `again`.
  void repeated(const std::string& what, const char* verb, llvm::SMLoc again, llvm::SMLoc first) {
    diags_.error(again, what + " is " + verb + " twice");
    diags_.note(first, std::string("first ") + verb + " here");
  }

  // The names of every option and effect, in declaration order.
  std::vector<std::string> optionNames() const {
    std::vector<std::string> names;
    for (const auto& o : chosen_) names.push_back(o.name);
    return names;
  }

  std::string knownEffects() const {
    std::vector<std::string> names;
    for (const auto& c : chosen_)
      if (c.isEffect) names.push_back(c.name);
    return names.empty() ? "no effect is declared: declare one with 'effect NAME;'"
                         : "known effects: " + joined(names);
  }

  // The scene's `effects = [a, b];` turns a and b on (before -D, which overrides).
  bool sceneEffects(const ast::SceneDecl& s) {
    bool ok = true;
    std::map<std::string, llvm::SMLoc> seen;
    for (const auto& e : s.effects) {
      ChosenOption* c = find(e.name);
      if (!c || !c->isEffect) {
        diags_.error(e.loc, "unknown effect '" + e.name + "' (" + knownEffects() + ")");
        if (c) diags_.note(decls_[c->name]->name.loc, "'" + e.name + "' is an option: choose "
                                                      "it with 'when' and -D " + e.name + "=...");
        ok = false;
        continue;
      }
      if (auto it = seen.find(e.name); it != seen.end()) {
        repeated("effect '" + e.name + "'", "listed", e.loc, it->second);
        ok = false;
        continue;
      }
      seen[e.name] = e.loc;
      c->value = "on";
      c->fromScene = true;
      effectLocs_[e.name] = e.loc;
    }
    return ok;
  }

  // Every effect that is on has the effects it needs on.
  bool checkNeeds() {
    bool ok = true;
    for (const auto& c : chosen_) {
      if (!c.on()) continue;
      for (const auto& n : c.needs) {
        const ChosenOption* d = find(n);
        if (!d || d->on()) continue;
        std::string how = d->fromCommandLine ? " (-D " + n + "=off)" : "";
        std::string msg = "effect '" + c.name + "' needs '" + n + "', which is off" + how +
                          (c.fromScene ? ": add " + n + " to the scene's effects"
                                       : ": turn it on too, -D " + n + "=on");
        if (auto it = effectLocs_.find(c.name); it != effectLocs_.end())
          diags_.error(it->second, msg);
        else
          diags_.error(msg + " (" + c.name + " is on by -D " + c.name + "=on)");
        const ast::EffectDecl* decl = effectDecls_[c.name];
        for (const auto& need : decl->needs)
          if (need.name == n)
            diags_.note(need.loc, c.name + " needs " + n +
                                      (effectDecls_[n]->doc.empty() ? std::string()
                                                                    : " (" + effectDecls_[n]->doc + ")"));
        ok = false;
      }
    }
    return ok;
  }

  // `param P = v for EFFECT;`: removed when the effect is off (and recorded, so the solver
  // can say which effect a --set of it needs).
  bool effectParams(ast::Module& mod) {
    bool ok = true;
    std::vector<ast::ParamDecl> kept;
    for (auto& p : mod.params) {
      if (p.effect.name.empty()) {
        kept.push_back(std::move(p));
        continue;
      }
      ChosenOption* c = find(p.effect.name);
      if (!c || !c->isEffect) {
        diags_.error(p.effect.loc, "param '" + p.name.name + "' is declared for '" +
                                       p.effect.name + "', which is no effect (" +
                                       knownEffects() + ")");
        ok = false;
        continue;
      }
      if (c->on()) {
        kept.push_back(std::move(p));
        continue;
      }
      c->params.push_back(p.name.name);
    }
    mod.params = std::move(kept);
    return ok;
  }

  bool applyDefines(const std::vector<std::string>& defines) {
    bool ok = true;
    std::map<std::string, std::string> given;
    for (const auto& d : defines) {
      auto [name, value] = llvm::StringRef(d).split('=');
      name = name.trim();
      value = value.trim();
      if (name.empty() || value.empty() || !llvm::StringRef(d).contains('=')) {
        diags_.error("-D expects NAME=CHOICE (as in -D scheme=edac), got '" + d + "'");
        ok = false;
        continue;
      }
      ChosenOption* c = find(name.str());
      if (!c) {
        const std::vector<std::string> names = optionNames();
        diags_.error("-D " + d + ": the scene has no option '" + name.str() + "'" +
                     (names.empty() ? std::string(" (it declares no options)")
                                    : " (its options: " + joined(names) + ")"));
        ok = false;
        continue;
      }
      if (auto g = given.find(c->name); g != given.end() && g->second != value.str()) {
        diags_.error("-D " + c->name + " is given twice, as '" + g->second + "' and '" +
                     value.str() + "'");
        ok = false;
        continue;
      }
      given[c->name] = value.str();
      if (!llvm::is_contained(c->choices, value.str())) {
        diags_.error("-D " + d + ": '" + value.str() + "' is not a choice of option '" +
                     c->name + "' (choices: " + joined(c->choices) + ")");
        diags_.note(decls_[c->name]->name.loc, "option '" + c->name + "' is declared here");
        ok = false;
        continue;
      }
      c->value = value.str();
      c->fromCommandLine = true;
    }
    return ok;
  }

  // Whether the condition holds; false (after an error) if it names an unknown option or
  // choice. `ok` is cleared on error.
  bool holds(const ast::WhenCondition& cond, bool& ok) {
    ChosenOption* c = find(cond.option.name);
    if (cond.bare) {
      if (!c || !c->isEffect) {
        diags_.error(cond.option.loc,
                     "'when " + cond.option.name + "' without a comparison needs an effect; '" +
                         cond.option.name + "' is " +
                         (c ? "an option (write 'when " + cond.option.name + " == CHOICE')"
                            : std::string("no effect (") + knownEffects() + ")"));
        ok = false;
        return false;
      }
      return c->on() != cond.negated;
    }
    if (!c) {
      const std::vector<std::string> names = optionNames();
      diags_.error(cond.option.loc,
                   "unknown option '" + cond.option.name + "' in 'when'" +
                       (names.empty() ? std::string(": declare it first, as in 'option " +
                                                    cond.option.name + " in [a, b] = a;'")
                                      : " (options: " + joined(names) + ")"));
      ok = false;
      return false;
    }
    bool any = false;
    for (const auto& v : cond.values) {
      if (!llvm::is_contained(c->choices, v.name)) {
        diags_.error(v.loc, "'" + v.name + "' is not a choice of option '" + c->name +
                                "' (choices: " + joined(c->choices) + ")");
        diags_.note(decls_[c->name]->name.loc, "option '" + c->name + "' is declared here");
        ok = false;
      }
      any |= v.name == c->value;
    }
    return cond.negated ? !any : any;
  }

  // The body of the chosen branch, or null. Every branch's condition is checked.
  template <class Body>
  Body* choose(ast::When<Body>& w, bool& ok) {
    Body* pick = nullptr;
    for (auto& b : w.branches) {
      bool h = !b.hasCondition || holds(b.condition, ok);
      if (h && !pick) {
        pick = &b.body;
      } else if (b.hasCondition && b.condition.bare && !b.condition.negated) {
        if (ChosenOption* c = find(b.condition.option.name)) recordDropped(b.body, *c);
      }
    }
    return pick;
  }

  void tagEffect(std::vector<ast::GroupItem>& items, const std::string& effect) {
    for (auto& item : items) {
      if (item.equation) {
        auto copy = std::make_shared<ast::EquationInstance>(*item.equation);
        copy->effects.push_back(effect);
        item.equation = copy;
      }
      if (item.group) tagEffect(item.group->items, effect);
    }
  }

  // What a `when EFFECT` branch not taken held, for --report ("left out").
  void recordDropped(const std::vector<ast::GroupItem>& items, ChosenOption& c) {
    for (const auto& item : items) {
      if (item.group) recordDropped(item.group->items, c);
      if (item.equation) {
        std::string dest;
        for (const auto& a : item.equation->args)
          if (a.name.name == "dest" && a.value && a.value->kind == ast::Expr::Name)
            dest = " -> " + a.value->text;
        c.droppedEquations.push_back(item.equation->equation.name + dest);
      }
      if (item.when)
        for (const auto& b : item.when->branches) recordDropped(b.body, c);
    }
  }
  void recordDropped(const ast::SceneDecl& s, ChosenOption& c) {
    recordDropped(s.equations, c);
    for (const auto& item : s.arrayItems)  // a scheme's `property fluids ...;`
      for (const auto& p : item.item.properties)
        for (const auto& a : item.arrays) c.droppedProperties.push_back(a.name + "." + p.name.name);
  }
  void recordDropped(const ast::ArrayDecl& a, ChosenOption& c) {
    for (const auto& p : a.properties) c.droppedProperties.push_back(a.name.name + "." + p.name.name);
  }

  // Flattens `when` items into the enclosing list, in place, recursively.
  void groupItems(std::vector<ast::GroupItem>& items, bool& ok) {
    std::vector<ast::GroupItem> out;
    for (auto& item : items) {
      if (item.when) {
        if (auto* body = choose(*item.when, ok)) {
          groupItems(*body, ok);
          // The effect whose `when` kept these items (for --report).
          for (const auto& b : item.when->branches)
            if (&b.body == body && b.hasCondition && b.condition.bare && !b.condition.negated)
              tagEffect(*body, b.condition.option.name);
          for (auto& sub : *body) out.push_back(std::move(sub));
        }
        continue;
      }
      if (item.group) groupItems(item.group->items, ok);
      out.push_back(std::move(item));
    }
    items = std::move(out);
  }

  void array(ast::ArrayDecl& a, bool& ok) {
    auto whens = std::move(a.whens);
    a.whens.clear();
    for (auto& w : whens) {
      ast::ArrayDecl* part = choose(*w, ok);
      if (!part) continue;
      array(*part, ok);
      append(a.geometry, part->geometry);
      append(a.loads, part->loads);
      append(a.properties, part->properties);
      append(a.constants, part->constants);
    }
  }

  // `top`: the scene itself (not a `when` branch of it), where schemes are expanded: first
  // those it uses outright, then those of its chosen branches.
  void scene(ast::SceneDecl& s, bool& ok, bool top = true) {
    if (top && !s.schemes.empty()) ok = expandSchemes(*modules_, s, diags_) && ok;
    groupItems(s.equations, ok);
    auto whens = std::move(s.whens);
    s.whens.clear();
    for (auto& w : whens) {
      ast::SceneDecl* part = choose(*w, ok);
      if (!part) continue;
      if (part->effectsLoc.isValid()) {
        diags_.error(part->effectsLoc, "the scene's effects cannot be inside a 'when'");
        ok = false;
      }
      scene(*part, ok, /*top=*/false);
      append(s.schemes, part->schemes);
      append(s.arrayItems, part->arrayItems);
      append(s.settings, part->settings);
      append(s.steppers, part->steppers);
      append(s.outputs, part->outputs);
      append(s.domains, part->domains);
      append(s.limits, part->limits);
      append(s.metrics, part->metrics);
      append(s.zones, part->zones);
      if (part->hasAdaptiveDt) {
        if (s.hasAdaptiveDt) {
          diags_.error(part->adaptiveDtLoc, "adaptive_dt is given twice");
          diags_.note(s.adaptiveDtLoc, "first given here");
          ok = false;
        } else {
          s.hasAdaptiveDt = true;
          s.adaptiveDtLoc = part->adaptiveDtLoc;
          s.adaptiveDt = std::move(part->adaptiveDt);
        }
      }
      if (part->equationsLoc.isValid()) {
        if (s.equationsLoc.isValid()) {
          diags_.error(part->equationsLoc,
                       "the scene's equations are given twice (here and outside the 'when')");
          diags_.note(s.equationsLoc,
                      "put the 'when' inside this 'equations { }' to choose groups or "
                      "equations");
          ok = false;
        } else {
          s.equationsLoc = part->equationsLoc;
          s.equations = std::move(part->equations);
        }
      }
    }
    if (top && !s.schemes.empty()) scene(s, ok);  // schemes a chosen branch used
    if (top) beforeSchemeFirst(s.equations);
  }

  // `group (before_scheme = true) { }` of the scene's equations: placed first, before the
  // groups of the schemes it uses (which expandSchemes put before the scene's own), in their
  // order. A set-up the scheme's first evaluation must see (examples/taylor_green.sph: the
  // particles moved off the lattice before the first density).
  static bool beforeScheme(const ast::GroupItem& item) {
    if (!item.group) return false;
    for (const auto& kw : item.group->options)
      if (kw.name.name == "before_scheme" && !kw.isList && kw.value &&
          ((kw.value->kind == ast::Expr::Name && kw.value->text == "true") ||
           (kw.value->kind == ast::Expr::Number && kw.value->number == 1)))
        return true;
    return false;
  }
  static void beforeSchemeFirst(std::vector<ast::GroupItem>& items) {
    std::stable_partition(items.begin(), items.end(), beforeScheme);
  }

  std::vector<ChosenOption> chosen() const { return chosen_; }

 private:
  ChosenOption* find(const std::string& name) {
    for (auto& c : chosen_)
      if (c.name == name) return &c;
    return nullptr;
  }

  DiagnosticEngine& diags_;
  const std::vector<std::unique_ptr<ast::Module>>* modules_;
  std::map<std::string, const ast::OptionDecl*> decls_;
  std::map<std::string, const ast::EffectDecl*> effectDecls_;
  std::map<std::string, llvm::SMLoc> effectLocs_;  // where the scene turned an effect on
  std::vector<ChosenOption> chosen_;
};

}  // namespace

bool selectOptions(std::vector<std::unique_ptr<ast::Module>>& modules,
                   const std::vector<std::string>& defines, DiagnosticEngine& diags,
                   std::vector<ChosenOption>& chosen) {
  OptionSelector sel(diags, modules);
  bool ok = sel.declare(modules);
  for (auto& mod : modules)
    for (auto& s : mod->scenes) ok = sel.sceneEffects(s) && ok;
  ok = sel.applyDefines(defines) && ok;
  ok = ok && sel.checkNeeds();
  for (auto& mod : modules) ok = sel.effectParams(*mod) && ok;
  for (auto& mod : modules) {
    for (auto& a : mod->arrays) sel.array(a, ok);
    for (auto& s : mod->scenes) sel.scene(s, ok);
  }
  // The properties and constants the kept branches of the scenes' schemes declare, added to
  // their arrays once every array's own `when`s are chosen.
  for (auto& mod : modules)
    for (auto& s : mod->scenes) ok = addSchemeArrayItems(modules, s, diags) && ok;
  chosen = sel.chosen();
  return ok;
}

}  // namespace sphc
