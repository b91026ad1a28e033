// The scene's `metrics { }` (docs/language.md, Metrics): names resolved, arguments checked and
// reference tables read, into Plan::metrics. Called by Sema after the scene's limits.
#pragma once

#include "frontend/AST.h"
#include "frontend/Diagnostics.h"
#include "sema/Plan.h"

#include <functional>
#include <string>

namespace sphc {

// `isParam(n)`: whether n is a param or let of the scene.
void buildMetrics(const ast::SceneDecl& scene, Plan& plan, DiagnosticEngine& diags,
                  const std::function<bool(const std::string&)>& isParam);

// A reference table (CSV: '#' comment lines, a header of column names, rows of numbers) read
// into `at` (column `abscissa`, default the first) and `value` (column `column`, default the
// second), sorted by increasing abscissa. False with `error` set if the file cannot be read or
// is malformed (the message names the file's line where it applies).
bool readReferenceTable(const std::string& path, std::string& abscissa, std::string& column,
                        std::vector<double>& at, std::vector<double>& value, std::string& error);

}  // namespace sphc
