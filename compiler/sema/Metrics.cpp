// The scene's `metrics { }` (docs/language.md, Metrics; sema/Metrics.h).
#include "sema/Metrics.h"

#include "sema/Sema.h"

#include "llvm/ADT/SmallString.h"
#include "llvm/ADT/StringExtras.h"
#include "llvm/ADT/StringRef.h"
#include "llvm/Support/MemoryBuffer.h"
#include "llvm/Support/Path.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <set>

namespace sphc {

namespace {

const std::map<std::string, PlanMetric::Kind>& kinds() {
  static const std::map<std::string, PlanMetric::Kind> k = {
      {"L1", PlanMetric::L1},   {"L2", PlanMetric::L2},   {"Linf", PlanMetric::Linf},
      {"max", PlanMetric::Max}, {"min", PlanMetric::Min}, {"sum", PlanMetric::Sum},
      {"mean", PlanMetric::Mean}};
  return k;
}

// Column names of the metric CSV that a metric may not take.
bool reservedColumn(const std::string& n) {
  return n == "step" || n == "t" || n == "dt" || n == "wall_s" || n == "cpu_s";
}

bool isCoordinate(const std::string& n) { return n == "x" || n == "y" || n == "z"; }

class MetricsBuilder {
 public:
  MetricsBuilder(Plan& plan, DiagnosticEngine& diags,
                 const std::function<bool(const std::string&)>& isParam)
      : plan_(plan), diags_(diags), isParam_(isParam) {}

  void item(const ast::MetricItem& it);

 private:
  // A per-particle expression of array `a`: params, t, and otherwise properties of the array
  // (whether they exist is the property analysis's question: analysis/Properties.cpp).
  bool particleExpr(const ast::ExprPtr& e, int a, const std::string& what,
                    std::set<std::string>& props);
  bool readReference(PlanMetric& m, const ast::MetricArg& file, const ast::MetricArg* column,
                     const ast::MetricArg* abscissa);
  // A profile's points, rows, radius and time window.
  bool profileArgs(PlanMetric& m, const ast::MetricItem& it, const std::string& head,
                   const std::function<const ast::MetricArg*(const char*)>& arg,
                   std::set<std::string>& props);

  Plan& plan_;
  DiagnosticEngine& diags_;
  const std::function<bool(const std::string&)>& isParam_;
};

bool MetricsBuilder::particleExpr(const ast::ExprPtr& e, int a, const std::string& what,
                                  std::set<std::string>& props) {
  const ast::ArrayDecl* decl = plan_.arrays[a].decl;
  auto declared = [&](const std::string& n) {
    for (const auto& p : decl->properties)
      if (p.name.name == n) return true;
    return false;
  };
  bool ok = checkExpr(*e, [](const std::string&) { return true; }, what, diags_);
  std::set<std::string> names;
  namesOf(*e, names);
  for (const auto& n : names) {
    if (n == "t" || builtinConstant(n)) continue;
    if (isParam_(n) && !declared(n) && !isCoordinate(n)) continue;
    if (n == "z" && plan_.dim < 3) continue;  // 0 in 1D and 2D
    if (n == "y" && plan_.dim < 2) continue;
    props.insert(n);
  }
  return ok;
}

bool MetricsBuilder::readReference(PlanMetric& m, const ast::MetricArg& file,
                                   const ast::MetricArg* column, const ast::MetricArg* abscissa) {
  llvm::SmallString<256> path(file.text);
  if (!llvm::sys::path::is_absolute(path)) {
    path = llvm::sys::path::parent_path(plan_.mainFile);
    llvm::sys::path::append(path, file.text);
  }
  m.reference = file.text;
  m.column = column ? column->text : "";
  m.abscissa = abscissa ? abscissa->text : "";
  std::string error;
  if (!readReferenceTable(path.str().str(), m.abscissa, m.column, m.refAt, m.refValue, error)) {
    diags_.error(file.loc, "reference of metric '" + m.name + "': " + error);
    return false;
  }
  return true;
}

bool MetricsBuilder::profileArgs(PlanMetric& m, const ast::MetricItem& it,
                                 const std::string& head,
                                 const std::function<const ast::MetricArg*(const char*)>& arg,
                                 std::set<std::string>& props) {
  bool ok = true;
  if (const auto* at = arg("at")) {
    diags_.error(at->name.loc, "'at' of the profile " + head + ": a profile's table is read at "
                               "its rows' points (x = , y = , z = , of s, the row's abscissa), "
                               "not at a time");
    ok = false;
  }
  static const char* kCoord[3] = {"x", "y", "z"};
  const auto ofRow = [&](const std::string& n) { return n == "s" || isParam_(n); };
  std::string missing;
  for (int d = 0; d < 3; ++d) {
    const auto* p = arg(kCoord[d]);
    if (d >= plan_.dim) {
      if (p) {
        diags_.error(p->name.loc, std::string("'") + kCoord[d] + "' of the profile " + head +
                                      ": the scene is " + std::to_string(plan_.dim) + "D");
        ok = false;
      }
      continue;
    }
    props.insert(kCoord[d]);  // the fit reads the particles' positions
    if (!p) {
      missing += (missing.empty() ? "" : ", ") + std::string(kCoord[d]) + " = ";
      continue;
    }
    m.point[d] = p->value;
    ok &= checkExpr(*p->value, ofRow,
                    std::string("the point '") + kCoord[d] + "' of " + head +
                        " (it may use s, the row's abscissa, and params)",
                    diags_);
  }
  if (!missing.empty()) {
    diags_.error(it.kind.loc, "the profile " + head + " needs the point of each row of its "
                              "table: " + missing + "(expressions of s, the row's abscissa, "
                              "and params)");
    ok = false;
  }
  if (const auto* r = arg("rows")) {
    m.rows = r->value;
    ok &= checkExpr(*r->value, ofRow,
                    "the 'rows' of " + head + " (it may use s, the row's abscissa, and params)",
                    diags_);
  }
  const auto params = [&](const std::string& n) { return isParam_(n); };
  if (const auto* r = arg("radius")) {
    m.radius = r->value;
    ok &= checkExpr(*r->value, params, "the 'radius' of " + head + " (it may use params)",
                    diags_);
  } else {
    diags_.error(it.kind.loc, "the profile " + head + " needs 'radius = R': the particles "
                              "within R of a row's point are fitted (e.g. the kernel's "
                              "support)");
    ok = false;
  }
  if (const auto* w = arg("average")) {
    m.average = w->value;
    ok &= checkExpr(*w->value, params, "the 'average' of " + head + " (it may use params)",
                    diags_);
  }
  return ok;
}

void MetricsBuilder::item(const ast::MetricItem& it) {
  PlanMetric m;
  m.loc = it.name.loc;
  m.name = it.name.name;
  const std::string head = "metric '" + m.name + "'";
  for (const auto& prev : plan_.metrics)
    if (prev.name == m.name) {
      diags_.error(it.name.loc, head + " is given twice");
      diags_.note(prev.loc, "first given here");
      return;
    }
  if (reservedColumn(m.name)) {
    diags_.error(it.name.loc, "a metric may not be called '" + m.name +
                                  "': the metric file has a column of that name (step, t, dt, "
                                  "wall_s, cpu_s)");
    return;
  }
  auto kind = kinds().find(it.kind.name);
  if (kind == kinds().end()) {
    diags_.error(it.kind.loc, "unknown kind of " + head + ": '" + it.kind.name +
                                  "'; kinds are L1, L2, Linf (norms against 'exact') and max, "
                                  "min, sum, mean (scalars of the array)");
    return;
  }
  m.kind = kind->second;
  m.array = plan_.arrayIndex(it.array.name);
  if (m.array < 0) {
    std::string names;
    for (const auto& a : plan_.arrays) names += (names.empty() ? "" : ", ") + a.name;
    diags_.error(it.array.loc, "unknown array '" + it.array.name + "' in " + head +
                                   "; arrays are: " + names);
    return;
  }
  bool ok = true;
  std::set<std::string> props;
  m.expr = it.expr;
  ok &= particleExpr(it.expr, m.array, head, props);

  std::map<std::string, const ast::MetricArg*> args;
  for (const auto& a : it.args) {
    static const std::set<std::string> known = {"exact",  "relative", "where", "reference",
                                                "column", "abscissa", "at",    "x",
                                                "y",      "z",        "rows",  "radius",
                                                "average"};
    if (!known.count(a.name.name)) {
      diags_.error(a.name.loc, "unknown argument '" + a.name.name + "' of " + head +
                                   "; arguments are exact, relative, where, reference, "
                                   "column, abscissa, at, and for a profile x, y, z, rows, "
                                   "radius and average");
      ok = false;
      continue;
    }
    if (!args.emplace(a.name.name, &a).second) {
      diags_.error(a.name.loc, "argument '" + a.name.name + "' of " + head + " is given twice");
      ok = false;
      continue;
    }
    const bool wantsString =
        a.name.name == "reference" || a.name.name == "column" || a.name.name == "abscissa";
    if (wantsString != a.isString) {
      diags_.error(a.loc, "argument '" + a.name.name + "' of " + head +
                              (wantsString ? " is a file or column name, in quotes"
                                           : " is an expression, not a string"));
      ok = false;
    }
  }
  if (!ok) return;
  auto arg = [&](const char* n) -> const ast::MetricArg* {
    auto i = args.find(n);
    return i == args.end() ? nullptr : i->second;
  };

  if (const auto* r = arg("relative")) {
    const ast::Expr& e = *r->value;
    const bool literal = e.kind == ast::Expr::Name && (e.text == "true" || e.text == "false");
    const bool number = e.kind == ast::Expr::Number && (e.number == 0 || e.number == 1);
    if (!literal && !number) {
      diags_.error(r->loc, "'relative' of " + head + " is true or false");
      return;
    }
    m.relative = literal ? e.text == "true" : e.number == 1;
  }
  if (const auto* w = arg("where")) {
    m.where = w->value;
    ok &= particleExpr(w->value, m.array, "the 'where' of " + head, props);
  }
  const auto* exact = arg("exact");
  const auto* reference = arg("reference");
  if (exact && reference) {
    diags_.error(reference->name.loc, head + " has both 'exact' and 'reference'; give one");
    return;
  }
  if (m.isNorm() && !exact && !reference) {
    diags_.error(it.kind.loc, "the norm " + head + " needs 'exact = EXPR' (an expression of "
                              "x, y, z, t, params and properties), or a 'reference' table "
                              "sampled at points (a profile)");
    return;
  }
  const bool profile = m.isNorm() && reference;
  if (!profile)
    for (const char* n : {"x", "y", "z", "rows", "radius", "average"})
      if (arg(n)) {
        diags_.error(arg(n)->name.loc,
                     std::string("'") + n + "' of " + head + " belongs to a profile (a norm "
                         "L1, L2 or Linf with a 'reference' table sampled at points)");
        ok = false;
      }
  if (profile) ok &= profileArgs(m, it, head, arg, props);
  if (exact) {
    m.exact = exact->value;
    // Norms: per particle, like the measured expression (x, y, z, t, params and the array's
    // properties, e.g. an initial position for a Lagrangian exact solution); scalars: of the
    // time and params only.
    if (m.isNorm())
      ok &= particleExpr(m.exact, m.array, "the exact value of " + head, props);
    else
      ok &= checkExpr(
          *m.exact, [&](const std::string& n) { return n == "t" || isParam_(n); },
          "the exact value of " + head + " (it may use t and params)", diags_);
  }
  for (const char* n : {"column", "abscissa", "at"})
    if (arg(n) && !reference) {
      diags_.error(arg(n)->name.loc, std::string("'") + n + "' of " + head +
                                         " belongs to a 'reference' table, which it has not");
      ok = false;
    }
  if (const auto* at = arg("at"); at && !profile) {
    m.at = at->value;
    ok &= checkExpr(
        *m.at, [&](const std::string& n) { return n == "t" || isParam_(n); },
        "the 'at' of " + head + " (it may use t and params)", diags_);
  }
  if (reference) ok &= readReference(m, *reference, arg("column"), arg("abscissa"));
  if (!ok) return;
  m.reads.assign(props.begin(), props.end());
  auto& mp = plan_.arrays[m.array].metricProps;
  for (const auto& p : props)
    if (std::find(mp.begin(), mp.end(), p) == mp.end()) mp.push_back(p);
  plan_.metrics.push_back(std::move(m));
}

}  // namespace

bool readReferenceTable(const std::string& path, std::string& abscissa, std::string& column,
                        std::vector<double>& at, std::vector<double>& value,
                        std::string& error) {
  auto buf = llvm::MemoryBuffer::getFile(path);
  const std::string name = "'" + llvm::sys::path::filename(path).str() + "'";
  if (!buf) {
    error = "cannot read " + name + " (" + path + "): " + buf.getError().message();
    return false;
  }
  llvm::SmallVector<llvm::StringRef, 0> lines;
  (*buf)->getBuffer().split(lines, '\n');
  std::vector<std::string> header;
  int ia = -1, iv = -1;
  std::vector<std::pair<double, double>> rows;
  for (size_t k = 0; k < lines.size(); ++k) {
    llvm::StringRef line = lines[k].trim();
    if (line.empty() || line.startswith("#")) continue;
    llvm::SmallVector<llvm::StringRef, 8> cells;
    line.split(cells, ',');
    const std::string where = name + " line " + std::to_string(k + 1);
    if (header.empty()) {
      for (auto c : cells) header.push_back(c.trim().str());
      auto find = [&](std::string& want, int fallback, const char* what) {
        if (want.empty()) {
          if (fallback >= static_cast<int>(header.size())) return -1;
          want = header[fallback];
          return fallback;
        }
        for (size_t c = 0; c < header.size(); ++c)
          if (header[c] == want) return static_cast<int>(c);
        std::string names;
        for (const auto& h : header) names += (names.empty() ? "" : ", ") + h;
        error = name + " has no " + what + " column '" + want + "'; its columns (" + where +
                ") are: " + names;
        return -2;
      };
      ia = find(abscissa, 0, "abscissa");
      if (ia == -2) return false;
      iv = find(column, 1, "value");
      if (iv == -2) return false;
      if (ia < 0 || iv < 0) {
        error = name + " needs two columns (" + where + " is its header)";
        return false;
      }
      continue;
    }
    if (cells.size() != header.size()) {
      error = where + " has " + std::to_string(cells.size()) + " fields, the header " +
              std::to_string(header.size());
      return false;
    }
    double v[2];
    int idx[2] = {ia, iv};
    for (int j = 0; j < 2; ++j) {
      const std::string cell = cells[idx[j]].trim().str();
      char* end = nullptr;
      v[j] = std::strtod(cell.c_str(), &end);
      if (cell.empty() || *end != '\0' || !std::isfinite(v[j])) {
        error = where + ": '" + cell + "' is not a number";
        return false;
      }
    }
    rows.emplace_back(v[0], v[1]);
  }
  if (rows.size() < 2) {
    error = name + " has " + std::to_string(rows.size()) +
            " rows of data; a reference needs at least two";
    return false;
  }
  std::stable_sort(rows.begin(), rows.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (size_t k = 1; k < rows.size(); ++k)
    if (rows[k].first == rows[k - 1].first) {
      error = name + " has the abscissa " + abscissa + " = " +
              std::to_string(rows[k].first) + " twice";
      return false;
    }
  at.clear();
  value.clear();
  for (const auto& [a, b] : rows) {
    at.push_back(a);
    value.push_back(b);
  }
  return true;
}

void buildMetrics(const ast::SceneDecl& scene, Plan& plan, DiagnosticEngine& diags,
                  const std::function<bool(const std::string&)>& isParam) {
  MetricsBuilder b(plan, diags, isParam);
  for (const auto& d : scene.metrics)
    for (const auto& it : d.items) b.item(it);
}

}  // namespace sphc
