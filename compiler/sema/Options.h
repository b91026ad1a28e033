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
};

// `defines` are the -D arguments, "NAME=VALUE". Returns false after reporting errors.
bool selectOptions(std::vector<std::unique_ptr<ast::Module>>& modules,
                   const std::vector<std::string>& defines, DiagnosticEngine& diags,
                   std::vector<ChosenOption>& chosen);

}  // namespace sphc
