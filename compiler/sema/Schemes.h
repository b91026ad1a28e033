// Schemes: the expansion of `scheme NAME(args);` scene items, run by the options pass before
// the `when`s are chosen.
//
// A scheme (`scheme wcsph(fluids, solids = [], rho0, c0, ...) { ... }` at top level, usually
// in stdlib/) is scene items written once, with a `when EFFECT { }` block per effect. A scene
// that writes `scheme wcsph(fluids = [fluid], solids = [boundary], rho0 = ro, c0 = co);` gets
// a copy of those items with the parameters replaced by the arguments: an expression
// parameter wherever its name appears in an expression, an array-list parameter in `dest =`
// (one instance per array; none for an empty list), in `sources = [...]` (spliced; an instance
// whose sources all vanish is dropped) and in `stepper P = S;` (one per array). Groups left
// empty are dropped. The scheme's equations come before the scene's own.
#pragma once

#include "frontend/AST.h"
#include "frontend/Diagnostics.h"

#include <memory>
#include <vector>

namespace sphc {

// Expands every `scheme` item of the scene in place. Returns false after reporting errors.
bool expandSchemes(const std::vector<std::unique_ptr<ast::Module>>& modules, ast::SceneDecl& scene,
                   DiagnosticEngine& diags);

// Adds the properties and constants that the scene's schemes declare (`property fluids
// double[3] gradc = 0;` in the `when` branches the options pass kept) to the arrays the
// scheme's list parameters are bound to, after the arrays' own. Where the array declares the
// name itself with the same type and shape, the array's declaration (its initial value) wins;
// another type or shape, or a property against a constant, is an error at both declarations.
// Returns false after reporting errors.
bool addSchemeArrayItems(const std::vector<std::unique_ptr<ast::Module>>& modules,
                         ast::SceneDecl& scene, DiagnosticEngine& diags);

}  // namespace sphc
