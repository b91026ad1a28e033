#include "analysis/PairQuantityTable.h"

#include "body/Identifiers.h"

#include <algorithm>
#include <cctype>
#include <map>

namespace sphc {

namespace {

PairQuantity difference(const std::string& name, std::vector<std::string> components, PairWhen when,
                        int param) {
  PairQuantity q;
  q.name = name;
  q.vector = true;
  q.form = PairForm::Difference;
  q.reads = components;
  q.components = std::move(components);
  q.when = when;
  q.param = param;
  return q;
}

PairQuantity formula(const std::string& name, const std::string& f, std::vector<std::string> needs,
                     std::vector<std::string> reads, PairWhen when, int param) {
  PairQuantity q;
  q.name = name;
  q.formula = f;
  q.needs = std::move(needs);
  q.reads = std::move(reads);
  q.when = when;
  q.param = param;
  return q;
}

PairQuantity kernel(const std::string& name, PairForm form, const std::string& h,
                    std::vector<std::string> needs, int param) {
  PairQuantity q;
  q.name = name;
  q.vector = form == PairForm::Gradient;
  q.form = form;
  q.h = h;
  q.needs = std::move(needs);
  q.param = param;
  return q;
}

}  // namespace

const std::vector<PairQuantity>& pairQuantityTable() {
  using W = PairWhen;
  static const std::vector<PairQuantity> table = {
      // The neighbour test: XIJ, R2IJ and the particles' h.
      difference("XIJ", {"x", "y", "z"}, W::BeforeTest, 0),
      formula("R2IJ", "XIJ[0] * XIJ[0] + XIJ[1] * XIJ[1] + XIJ[2] * XIJ[2]", {"XIJ"}, {},
              W::BeforeTest, 5),
      // Neighbours only.
      formula("HIJ", "0.5 * (hi + hj)", {}, {"h"}, W::EveryNeighbour, 7),
      formula("RIJ", "sqrt(R2IJ)", {"R2IJ"}, {}, W::IfUsed, 6),
      difference("VIJ", {"u", "v", "w"}, W::IfUsed, 1),
      kernel("WIJ", PairForm::Kernel, "HIJ", {"RIJ", "HIJ"}, 8),
      kernel("WI", PairForm::Kernel, "hi", {"RIJ"}, 9),
      kernel("WJ", PairForm::Kernel, "hj", {"RIJ"}, 10),
      kernel("DWIJ", PairForm::Gradient, "HIJ", {"XIJ", "RIJ", "HIJ"}, 2),
      kernel("DWI", PairForm::Gradient, "hi", {"XIJ", "RIJ"}, 3),
      kernel("DWJ", PairForm::Gradient, "hj", {"XIJ", "RIJ"}, 4),
      formula("RHOIJ", "0.5 * (di_rho[d_idx] + sj_rho[s_idx])", {}, {"rho"}, W::IfUsed, 11),
      formula("RHOIJ1", "1.0 / RHOIJ", {"RHOIJ"}, {}, W::IfUsed, 12),
      formula("EPS", "0.01 * HIJ * HIJ", {"HIJ"}, {}, W::IfUsed, 13),
  };
  return table;
}

const PairQuantity* findPairQuantity(const std::string& name) {
  for (const auto& q : pairQuantityTable())
    if (q.name == name) return &q;
  return nullptr;
}

const std::vector<std::string>& pairQuantityNames() {
  static const std::vector<std::string> names = [] {
    std::vector<const PairQuantity*> rows;
    for (const auto& q : pairQuantityTable()) rows.push_back(&q);
    std::sort(rows.begin(), rows.end(),
              [](const PairQuantity* a, const PairQuantity* b) { return a->param < b->param; });
    std::vector<std::string> out;
    for (const auto* q : rows) out.push_back(q->name);
    return out;
  }();
  return names;
}

std::set<std::string> pairQuantityClosure(const std::set<std::string>& used) {
  std::set<std::string> out = used;
  for (const auto& q : pairQuantityTable())
    if (q.when == PairWhen::BeforeTest) out.insert(q.name);
  for (bool changed = true; changed;) {
    changed = false;
    for (const auto& name : std::set<std::string>(out))
      if (const PairQuantity* q = findPairQuantity(name))
        for (const auto& d : q->needs) changed |= out.insert(d).second;
  }
  return out;
}

std::vector<std::string> pairQuantityProps(int dim, const std::set<std::string>& q) {
  std::vector<std::string> props = {"x", "y", "z"};
  props.resize(dim);
  props.push_back("h");  // the neighbour test: positions and h
  static const std::set<std::string> axes = {"x", "y", "z", "u", "v", "w"};
  for (const auto& row : pairQuantityTable()) {
    if (!q.count(row.name)) continue;
    for (size_t k = 0; k < row.reads.size(); ++k) {
      // Components of a vector beyond the dimension are not read (they are 0).
      if (row.form == PairForm::Difference && static_cast<int>(k) >= dim) break;
      if (std::find(props.begin(), props.end(), row.reads[k]) == props.end())
        props.push_back(row.reads[k]);
    }
  }
  return props;
}

namespace {

// `f` in the dialect: floating literals get the suffix, sqrt its spelling.
std::string spell(const std::string& f, const PairDialect& d) {
  std::string out;
  for (size_t i = 0; i < f.size();) {
    char c = f[i];
    if (isIdentifierStart(c)) {
      size_t j = i;
      while (j < f.size() && isIdentifierChar(f[j])) ++j;
      std::string word = f.substr(i, j - i);
      out += word == "sqrt" ? d.sqrt : word;
      i = j;
    } else if (std::isdigit(static_cast<unsigned char>(c))) {
      size_t j = i;
      while (j < f.size() && (std::isdigit(static_cast<unsigned char>(f[j])) || f[j] == '.')) ++j;
      std::string number = f.substr(i, j - i);
      out += number;
      if (number.find('.') != std::string::npos) out += d.literalSuffix;
      i = j;
    } else {
      out += c;
      ++i;
    }
  }
  return out;
}

}  // namespace

std::string pairQuantityStatement(const PairQuantity& q, int dim, const PairDialect& d,
                                  const std::string& indent) {
  const std::string& R = d.real;
  switch (q.form) {
    case PairForm::Difference: {
      std::string s = indent + "const " + R + " " + q.name + "[3] = {";
      for (int k = 0; k < 3; ++k)
        s += (k ? ", " : "") + (k < dim ? q.components[k] + "i - sj_" + q.components[k] + "[s_idx]"
                                        : "0.0" + d.literalSuffix);
      return s + "};\n";
    }
    case PairForm::Formula:
      if (q.name == "R2IJ" && dim >= 1 && dim < 3) {
        // The axes of the scene only: the others' XIJ[k] is the literal 0, whose square adds
        // +0 to a sum of squares, which is never -0: the same value bit for bit (NaN and
        // inf too), without the addition.
        std::string s = "XIJ[0] * XIJ[0]";
        if (dim == 2) s += " + XIJ[1] * XIJ[1]";
        return indent + "const " + R + " " + q.name + " = " + s + ";\n";
      }
      return indent + "const " + R + " " + q.name + " = " + spell(q.formula, d) + ";\n";
    case PairForm::Kernel:
      return indent + "const " + R + " " + q.name + " = " + d.kernelW + "(RIJ, " + q.h + ");\n";
    case PairForm::Gradient:
      return indent + R + " " + q.name + "[3];\n" + indent + d.kernelGradient + "(XIJ, RIJ, " +
             q.h + ", " + q.name + ");\n";
  }
  return "";
}

}  // namespace sphc
