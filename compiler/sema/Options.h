// Options: the compile-time options pass, run between parsing and Sema.
//
// A scene declares `option NAME in [a, b, c] = a;` and chooses between variants with
// `when NAME == b { ... } else { ... }` blocks in the scene, in `equations`/`group` lists and
// in arrays. `sphc scene.sph -D NAME=b` picks a choice (the default otherwise). This pass
// checks the declarations, the -D values and every `when` condition (also in branches not
// taken, so a misspelt choice is an error whatever is chosen), then replaces each `when` by
// the items of its chosen branch. After it, the AST holds no `when`, and Sema sees one plain
// scene: only the chosen scheme's equations exist, so only its properties are allocated.
#pragma once

#include "frontend/AST.h"
#include "frontend/Diagnostics.h"

#include <memory>
#include <string>
#include <vector>

namespace sphc {

struct ChosenOption {
  std::string name;
  std::string value;
  std::vector<std::string> choices;  // as declared; the first-declared default is `value`
                                     // unless -D changed it
  bool fromCommandLine = false;
  // An effect (`effect NAME ...;`, docs/effects.md): choices off and on.
  bool isEffect = false;
  std::string doc;
  std::vector<std::string> needs;
  bool fromScene = false;                  // listed in the scene's `effects = [...]`
  // With the effect off: the params declared `for` it (removed from the scene), and the
  // equations of the `when NAME` branches dropped, "Name -> dest", for --report.
  std::vector<std::string> params;
  std::vector<std::string> droppedEquations;
  std::vector<std::string> droppedProperties;  // "fluid.L" of `when NAME` array items
  bool on() const { return isEffect && value == "on"; }
};

// Effects: `effect NAME needs [..] "doc";` declares one (an option with the choices off and
// on), the scene's `effects = [a, b];` turns effects on, -D NAME=on|off overrides, `when NAME`
// keeps what only the effect needs, `param P = v for NAME;` exists only with it, and an effect
// on whose `needs` is off is an error. Schemes used by the scene are expanded here too
// (sema/Schemes.h), before the `when`s are chosen.
//
// `defines` are the -D arguments, "NAME=VALUE". Returns false after reporting errors.
bool selectOptions(std::vector<std::unique_ptr<ast::Module>>& modules,
                   const std::vector<std::string>& defines, DiagnosticEngine& diags,
                   std::vector<ChosenOption>& chosen);

}  // namespace sphc
