// The pair-quantity table (compiler/analysis/PairQuantityTable.h): the one definition that body
// analysis, property inference, ghost selection, pair selection and the emitter read.
#include <gtest/gtest.h>

#include <map>

#include "analysis/PairQuantityTable.h"

namespace sphc {
namespace {

using Names = std::vector<std::string>;
using Set = std::set<std::string>;

TEST(PairQuantityTable, NamesInBodyParameterOrder) {
  EXPECT_EQ(pairQuantityNames(), (Names{"XIJ", "VIJ", "DWIJ", "DWI", "DWJ", "R2IJ", "RIJ", "HIJ",
                                        "WIJ", "WI", "WJ", "RHOIJ", "RHOIJ1", "EPS"}));
  EXPECT_EQ(findPairQuantity("NOPE"), nullptr);
  for (const char* v : {"XIJ", "VIJ", "DWIJ", "DWI", "DWJ"})
    EXPECT_TRUE(findPairQuantity(v)->vector) << v;
  for (const char* s : {"R2IJ", "RIJ", "HIJ", "WIJ", "WI", "WJ", "RHOIJ", "RHOIJ1", "EPS"})
    EXPECT_FALSE(findPairQuantity(s)->vector) << s;
}

TEST(PairQuantityTable, ComputedAfterWhatTheyNeedAndTheTestFirst) {
  std::map<std::string, size_t> at;
  const auto& table = pairQuantityTable();
  bool pastTest = false;
  for (size_t i = 0; i < table.size(); ++i) {
    at[table[i].name] = i;
    // The neighbour test's quantities come before every other one.
    if (table[i].when != PairWhen::BeforeTest)
      pastTest = true;
    else
      EXPECT_FALSE(pastTest) << table[i].name;
  }
  for (const auto& q : table)
    for (const auto& n : q.needs) {
      ASSERT_TRUE(at.count(n)) << q.name << " needs unknown " << n;
      EXPECT_LT(at[n], at[q.name]) << q.name << " is computed before " << n;
    }
}

TEST(PairQuantityTable, KernelEvaluations) {
  Set kernel;
  for (const auto& q : pairQuantityTable())
    if (q.kernel()) kernel.insert(q.name);
  EXPECT_EQ(kernel, (Set{"WIJ", "WI", "WJ", "DWIJ", "DWI", "DWJ"}));
}

TEST(PairQuantityTable, Closure) {
  // The neighbour test's XIJ and R2IJ always.
  EXPECT_EQ(pairQuantityClosure({}), (Set{"XIJ", "R2IJ"}));
  EXPECT_EQ(pairQuantityClosure({"DWIJ"}), (Set{"DWIJ", "XIJ", "R2IJ", "RIJ", "HIJ"}));
  EXPECT_EQ(pairQuantityClosure({"WI"}), (Set{"WI", "RIJ", "XIJ", "R2IJ"}));
  EXPECT_EQ(pairQuantityClosure({"RHOIJ1", "EPS"}),
            (Set{"RHOIJ1", "RHOIJ", "EPS", "HIJ", "XIJ", "R2IJ"}));
}

TEST(PairQuantityTable, PropertiesReadOfBothParticles) {
  EXPECT_EQ(pairQuantityProps(2, pairQuantityClosure({"WIJ"})), (Names{"x", "y", "h"}));
  EXPECT_EQ(pairQuantityProps(2, pairQuantityClosure({"VIJ", "RHOIJ1"})),
            (Names{"x", "y", "h", "u", "v", "rho"}));
  EXPECT_EQ(pairQuantityProps(3, pairQuantityClosure({"VIJ"})),
            (Names{"x", "y", "z", "h", "u", "v", "w"}));
  EXPECT_EQ(pairQuantityProps(1, pairQuantityClosure({"VIJ"})), (Names{"x", "h", "u"}));
}

TEST(PairQuantityTable, StatementsInEachDialect) {
  const PairDialect host{"double", "std::sqrt", "Kernel::w", "Kernel::gradient", ""};
  const PairDialect hostFloat{"float", "std::sqrt", "Kernel::w", "Kernel::gradient", "f"};
  const PairDialect device{"real", "sqrt", "kernel_w", "kernel_gradient", ""};
  struct Case {
    const char* quantity;
    int dim;
    const PairDialect& dialect;
    const char* indent;
    const char* statement;
  };
  const Case cases[] = {
      {"XIJ", 2, host, "  ", "  const double XIJ[3] = {xi - sj_x[s_idx], yi - sj_y[s_idx], 0.0};\n"},
      {"VIJ", 2, hostFloat, "", "const float VIJ[3] = {ui - sj_u[s_idx], vi - sj_v[s_idx], 0.0f};\n"},
      {"RIJ", 3, host, "", "const double RIJ = std::sqrt(R2IJ);\n"},
      {"RIJ", 3, device, "", "const real RIJ = sqrt(R2IJ);\n"},
      {"EPS", 3, hostFloat, "", "const float EPS = 0.01f * HIJ * HIJ;\n"},
      {"R2IJ", 3, hostFloat, "", "const float R2IJ = XIJ[0] * XIJ[0] + XIJ[1] * XIJ[1] + XIJ[2] * XIJ[2];\n"},
      // The scene's axes only: the others' literal 0 squared adds +0 (exact).
      {"R2IJ", 2, host, "", "const double R2IJ = XIJ[0] * XIJ[0] + XIJ[1] * XIJ[1];\n"},
      {"R2IJ", 1, host, "", "const double R2IJ = XIJ[0] * XIJ[0];\n"},
      {"WJ", 2, device, "", "const real WJ = kernel_w(RIJ, hj);\n"},
      {"DWIJ", 2, host, "  ", "  double DWIJ[3];\n  Kernel::gradient(XIJ, RIJ, HIJ, DWIJ);\n"},
      {"RHOIJ", 2, hostFloat, "", "const float RHOIJ = 0.5f * (di_rho[d_idx] + sj_rho[s_idx]);\n"},
  };
  for (const Case& c : cases)
    EXPECT_EQ(pairQuantityStatement(*findPairQuantity(c.quantity), c.dim, c.dialect, c.indent),
              c.statement)
        << c.quantity << ", dim " << c.dim << ", " << c.dialect.real;
}

}  // namespace
}  // namespace sphc
