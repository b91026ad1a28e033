#include "sema/Options.h"

#include "llvm/ADT/STLExtras.h"
#include "llvm/ADT/StringRef.h"

#include <map>

namespace sphc {

namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (size_t i = 0; i < names.size(); ++i) s += (i ? ", " : "") + names[i];
  return s;
}

class OptionSelector {
 public:
  OptionSelector(DiagnosticEngine& diags) : diags_(diags) {}

  bool declare(const std::vector<std::unique_ptr<ast::Module>>& modules) {
    bool ok = true;
    for (const auto& mod : modules) {
      for (const auto& o : mod->options) {
        if (auto it = decls_.find(o.name.name); it != decls_.end()) {
          diags_.error(o.name.loc, "option '" + o.name.name + "' is declared twice");
          diags_.note(it->second->name.loc, "first declared here");
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
        std::vector<std::string> names;
        for (const auto& o : chosen_) names.push_back(o.name);
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
    if (!c) {
      std::vector<std::string> names;
      for (const auto& o : chosen_) names.push_back(o.name);
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
      if (h && !pick) pick = &b.body;
    }
    return pick;
  }

  // Flattens `when` items into the enclosing list, in place, recursively.
  void groupItems(std::vector<ast::GroupItem>& items, bool& ok) {
    std::vector<ast::GroupItem> out;
    for (auto& item : items) {
      if (item.when) {
        if (auto* body = choose(*item.when, ok)) {
          groupItems(*body, ok);
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
      auto append = [](auto& to, auto& from) {
        for (auto& x : from) to.push_back(std::move(x));
      };
      append(a.geometry, part->geometry);
      append(a.loads, part->loads);
      append(a.properties, part->properties);
      append(a.constants, part->constants);
    }
  }

  void scene(ast::SceneDecl& s, bool& ok) {
    groupItems(s.equations, ok);
    auto whens = std::move(s.whens);
    s.whens.clear();
    for (auto& w : whens) {
      ast::SceneDecl* part = choose(*w, ok);
      if (!part) continue;
      scene(*part, ok);
      auto append = [](auto& to, auto& from) {
        for (auto& x : from) to.push_back(std::move(x));
      };
      append(s.settings, part->settings);
      append(s.steppers, part->steppers);
      append(s.outputs, part->outputs);
      append(s.domains, part->domains);
      append(s.limits, part->limits);
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
  }

  std::vector<ChosenOption> chosen() const { return chosen_; }

 private:
  ChosenOption* find(const std::string& name) {
    for (auto& c : chosen_)
      if (c.name == name) return &c;
    return nullptr;
  }

  DiagnosticEngine& diags_;
  std::map<std::string, const ast::OptionDecl*> decls_;
  std::vector<ChosenOption> chosen_;
};

}  // namespace

bool selectOptions(std::vector<std::unique_ptr<ast::Module>>& modules,
                   const std::vector<std::string>& defines, DiagnosticEngine& diags,
                   std::vector<ChosenOption>& chosen) {
  OptionSelector sel(diags);
  bool ok = sel.declare(modules);
  ok = sel.applyDefines(defines) && ok;
  for (auto& mod : modules) {
    for (auto& a : mod->arrays) sel.array(a, ok);
    for (auto& s : mod->scenes) sel.scene(s, ok);
  }
  chosen = sel.chosen();
  return ok;
}

}  // namespace sphc
