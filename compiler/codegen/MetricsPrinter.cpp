// The scene's metrics { } in the host program (docs/language.md, Metrics): a member function
// of struct Scene that evaluates every metric on the host arrays (the run loop calls it where
// it writes output, after a device backend's data came back), and the metrics' descriptions
// in `main` (sphc/metrics.h). Shared by every backend; under --mpi each metric's sums are
// combined over the ranks before it is finished (a collective call on every rank).
#include "codegen/Printer.h"
#include "frontend/FormatNumber.h"

#include <functional>

namespace sphc {

namespace {

const char* normKind(PlanMetric::Kind k) {
  switch (k) {
    case PlanMetric::L1: return "sphc::NormKind::L1";
    case PlanMetric::L2: return "sphc::NormKind::L2";
    case PlanMetric::Linf: return "sphc::NormKind::Linf";
    default: return "";
  }
}

const char* reduceKind(PlanMetric::Kind k) {
  switch (k) {
    case PlanMetric::Max: return "sphc::ReduceKind::Max";
    case PlanMetric::Min: return "sphc::ReduceKind::Min";
    case PlanMetric::Sum: return "sphc::ReduceKind::Sum";
    case PlanMetric::Mean: return "sphc::ReduceKind::Mean";
    default: return "";
  }
}

}  // namespace

// Scene::metrics(t): one block per metric, a loop over the real particles of its array.
// The loop over a metric's real particles, opened: pointers to the properties it reads, the
// particle's values as locals q_NAME, its `where`. Returns the names of the loop body's scope
// (coordinates the scene has not: 0). The caller writes the body and closes the loop.
std::function<std::string(const std::string&)> ScenePrinter::emitMetricParticleLoop(
    const PlanMetric& m) {
  const int a = m.array;
  const std::string A = arr(a).name;
  std::vector<std::string> locals;
  for (const auto& p : m.reads)
    if (constIndex(a, p) < 0 && propIndex(a, p) >= 0) locals.push_back(p);
  std::function<std::string(const std::string&)> particleNames =
      [this, a, A, locals](const std::string& n) -> std::string {
    if (n == "t") return "t";
    if (constIndex(a, n) >= 0) return A + ".constant(" + std::to_string(constIndex(a, n)) + ")[0]";
    for (const auto& l : locals)
      if (l == n) return "q_" + n;
    if (n == "x" || n == "y" || n == "z") return "0.0";
    return paramRef(n);
  };
  for (const auto& p : locals)
    scene_ << "      const auto* p_" << p << " = " << hostPtr(a, p) << ";\n";
  scene_ << "      for (std::size_t i = 0; i < " << A << ".n; ++i) {  // real particles\n";
  for (const auto& p : locals) {
    const int stride = arr(a).props[propIndex(a, p)].stride;
    scene_ << "        const double q_" << p << " = static_cast<double>(p_" << p << "[i"
           << (stride > 1 ? " * " + std::to_string(stride) : std::string("")) << "]);\n";
  }
  if (m.where) scene_ << "        if (!(" << exprCpp(*m.where, particleNames) << ")) continue;\n";
  return particleNames;
}

void ScenePrinter::emitMetrics() {
  if (plan_.metrics.empty()) return;
  scene_ << "  // metrics { }: evaluated on the host at every output (sphc/metrics.h)\n";
  scene_ << "  std::vector<sphc::MetricValue> metrics(double t) {\n";
  scene_ << "    std::vector<sphc::MetricValue> r(" << plan_.metrics.size() << ");\n";
  for (size_t k = 0; k < plan_.metrics.size(); ++k) {
    const PlanMetric& m = plan_.metrics[k];
    const int a = m.array;
    const std::string& A = arr(a).name;
    scene_ << "    {  // " << m.name << ", from " << loc(m.loc) << "\n";
    if (!m.refAt.empty()) {
      scene_ << "      // reference \"" << m.reference << "\": " << m.abscissa << " -> "
             << m.column << " (" << m.refAt.size() << " rows, read by sphc)\n";
      scene_ << "      static const sphc::ReferenceTable ref{{";
      for (size_t i = 0; i < m.refAt.size(); ++i)
        scene_ << (i ? ", " : "") << exactNumber(m.refAt[i]);
      scene_ << "},\n                                           {";
      for (size_t i = 0; i < m.refValue.size(); ++i)
        scene_ << (i ? ", " : "") << exactNumber(m.refValue[i]);
      scene_ << "}};\n";
    }
    if (m.isProfile()) {
      emitProfile(m, k);
      continue;
    }
    scene_ << "      " << (m.isNorm() ? "sphc::NormSums" : "sphc::ScalarSums") << " acc;\n";
    const auto particleNames = emitMetricParticleLoop(m);
    const std::string value = exprCpp(*m.expr, particleNames);
    if (m.isNorm())
      scene_ << "        sphc::add(acc, " << value << ", " << exprCpp(*m.exact, particleNames)
             << ");\n";
    else
      scene_ << "        sphc::add(acc, " << value << ");\n";
    scene_ << "      }\n";
    // --mpi: the sums of every rank's particles (sphc/mpi/comm.h), the same on every rank.
    if (mpi_) scene_ << "      sphc::mpi::all_reduce(acc);  // over every rank's particles\n";
    if (m.isNorm()) {
      scene_ << "      r[" << k << "].value = sphc::norm(acc, " << normKind(m.kind) << ", "
             << (m.relative ? "true" : "false") << ");\n";
    } else {
      const std::string v = "sphc::reduce(acc, " + std::string(reduceKind(m.kind)) + ")";
      auto timeNames = [&](const std::string& n) { return n == "t" ? n : paramRef(n); };
      if (m.exact)
        scene_ << "      r[" << k << "] = sphc::compare(" << v << ", "
               << exprCpp(*m.exact, timeNames) << ", " << (m.relative ? "true" : "false")
               << ");\n";
      else if (!m.refAt.empty())
        scene_ << "      r[" << k << "] = sphc::compare(" << v << ", sphc::interpolate(ref, "
               << (m.at ? exprCpp(*m.at, timeNames) : std::string("t")) << "), "
               << (m.relative ? "true" : "false") << ");\n";
      else
        scene_ << "      r[" << k << "].value = " << v << ";\n";
    }
    scene_ << "    }\n";
  }
  scene_ << "    return r;\n  }\n\n";
}

// A profile (a norm with a reference table sampled at points): the points of the table's rows,
// one least-squares fit per point over the real particles, the mean over the time window, and
// the norm of the differences from the rows' values. Inside the metric's block, after `ref`.
void ScenePrinter::emitProfile(const PlanMetric& m, size_t k) {
  const int a = m.array;
  const std::string& A = arr(a).name;
  auto paramNames = [&](const std::string& n) { return paramRef(n); };
  auto rowNames = [&](const std::string& n) { return n == "s" ? n : paramRef(n); };
  scene_ << "      // a profile: the expression fitted at each row's point, radius "
         << exprCpp(*m.radius, paramNames) << "\n";
  scene_ << "      static sphc::ProfileHistory history;  // the samples of the latest outputs\n";
  scene_ << "      sphc::ProfileFit fit(" << plan_.dim << ", " << exprCpp(*m.radius, paramNames)
         << ");\n";
  scene_ << "      for (std::size_t row = 0; row < ref.at.size(); ++row) {\n";
  scene_ << "        const double s = ref.at[row];\n";
  scene_ << "        (void)s;\n";
  if (m.rows) scene_ << "        if (!(" << exprCpp(*m.rows, rowNames) << ")) continue;\n";
  scene_ << "        fit.add_point(row";
  for (int d = 0; d < 3; ++d)
    scene_ << ", " << (m.point[d] ? "static_cast<double>(" + exprCpp(*m.point[d], rowNames) + ")"
                                  : std::string("0.0"));
  scene_ << ");\n      }\n";
  const auto particleNames = emitMetricParticleLoop(m);
  scene_ << "        sphc::add(fit, " << particleNames("x") << ", " << particleNames("y") << ", "
         << particleNames("z") << ", " << exprCpp(*m.expr, particleNames) << ");\n";
  scene_ << "      }\n";
  if (mpi_) scene_ << "      sphc::mpi::all_reduce(fit);  // over every rank's particles\n";
  scene_ << "      const std::vector<double> mean = sphc::average(history, t, sphc::solve(fit), "
         << (m.average ? exprCpp(*m.average, paramNames) : std::string("0.0")) << ");\n";
  scene_ << "      sphc::NormSums acc;\n";
  scene_ << "      for (std::size_t p = 0; p < mean.size(); ++p)\n";
  scene_ << "        sphc::add(acc, mean[p], ref.value[fit.row[p]]);\n";
  scene_ << "      r[" << k << "].value = sphc::norm(acc, " << normKind(m.kind) << ", "
         << (m.relative ? "true" : "false") << ");\n";
  scene_ << "    }\n";
}

// In main: what each metric is (for the CSV header and the progress line) and how to
// evaluate them.
void ScenePrinter::emitMetricsMain() {
  if (plan_.metrics.empty()) return;
  for (const auto& m : plan_.metrics)
    out_ << "  prog.metrics.push_back({\"" << m.name << "\", " << (m.compared() ? "true" : "false")
         << ", " << (m.relative ? "true" : "false") << ", \"" << loc(m.loc) << "\"});\n";
  out_ << "  prog.evaluate_metrics = [](double t) { return scene.metrics(t); };\n";
}

}  // namespace sphc
