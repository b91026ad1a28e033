// BodyAnalysis: facts and diagnostics of equation and stepper bodies, over a fake .sph buffer.
#include "body/BodyAnalysis.h"

#include "llvm/Support/MemoryBuffer.h"

#include <gtest/gtest.h>

#include <chrono>
#include <string>

namespace sphc {
namespace {

class BodyAnalysisTest : public ::testing::Test {
 protected:
  // Loads `sph` as the buffer "eq.sph"; bodies are then found in it by `body`.
  void load(const std::string& sph) {
    sm_.AddNewSourceBuffer(llvm::MemoryBuffer::getMemBufferCopy(sph, "eq.sph"), llvm::SMLoc());
    buffer_ = sm_.getMemoryBuffer(sm_.getMainFileID())->getBuffer();
  }

  // The body whose `{` follows the first occurrence of `marker` (e.g. "loop").
  BodySource body(const std::string& marker, BodyKind kind) {
    size_t at = buffer_.find(marker);
    EXPECT_NE(at, llvm::StringRef::npos) << marker;
    size_t open = buffer_.find('{', at + marker.size()), close = open + 1;
    for (int depth = 1; depth > 0; ++close)
      depth += buffer_[close] == '{' ? 1 : buffer_[close] == '}' ? -1 : 0;
    BodySource b;
    b.text = buffer_.slice(open + 1, close - 1).str();
    b.start = llvm::SMLoc::getFromPointer(buffer_.data() + open + 1);
    b.kind = kind;
    b.label = "equation Test, method " + marker;
    return b;
  }

  std::vector<BodyFacts> analyze(const std::vector<BodySource>& bodies) {
    return BodyAnalyzer(diags_).analyze(bodies);
  }

  std::string output() { return out_.str(); }
  std::string where(llvm::SMLoc loc) {
    auto p = diags_.position(loc);
    return p.file + ":" + std::to_string(p.line) + ":" + std::to_string(p.col);
  }

  llvm::SourceMgr sm_;
  std::string text_;
  llvm::raw_string_ostream out_{text_};
  DiagnosticEngine diags_{sm_, out_};
  llvm::StringRef buffer_;
};

TEST_F(BodyAnalysisTest, ContinuityLoopFacts) {
  load("equation ContinuityEquation() {\n"
       "  loop {\n"
       "    double vijdotdwij = VIJ[0]*DWIJ[0] + VIJ[1]*DWIJ[1] + VIJ[2]*DWIJ[2];\n"
       "    d_arho[d_idx] += s_m[s_idx] * vijdotdwij;\n"
       "  }\n"
       "}\n");
  auto facts = analyze({body("loop", BodyKind::Loop)});
  ASSERT_EQ(facts.size(), 1u);
  EXPECT_EQ(output(), "");
  EXPECT_TRUE(facts[0].ok);
  ASSERT_EQ(facts[0].dReads.size(), 1u);
  EXPECT_EQ(facts[0].dReads[0].prop, "arho");  // `+=` reads
  ASSERT_EQ(facts[0].dWrites.size(), 1u);
  EXPECT_EQ(facts[0].dWrites[0].prop, "arho");
  EXPECT_EQ(where(facts[0].dWrites[0].loc), "eq.sph:4:5");
  ASSERT_EQ(facts[0].sReads.size(), 1u);
  EXPECT_EQ(facts[0].sReads[0].prop, "m");
  EXPECT_EQ(where(facts[0].sReads[0].loc), "eq.sph:4:22");
  EXPECT_EQ(facts[0].pairQuantities, (std::set<std::string>{"DWIJ", "VIJ"}));
  EXPECT_FALSE(facts[0].usesT);
  EXPECT_FALSE(facts[0].usesDt);
}

TEST_F(BodyAnalysisTest, WritesReadsScalarsAndTime) {
  load("stepper S {\n"
       "  stage1 {\n"
       "    d_rho[d_idx] = d_rho0[d_idx] + dt * d_arho[d_idx];\n"
       "    d_n[d_idx]++;\n"
       "    d_sigma[9*d_idx + 3] = c0 * sin(M_PI * t) + fabs(d_x[d_idx]);\n"
       "  }\n"
       "}\n");
  BodySource b = body("stage1", BodyKind::StepperStage);
  b.scalars = {"c0", "unused"};
  b.props["n"] = PropShape{"int", 1};
  b.props["sigma"] = PropShape{"double", 9};
  auto facts = analyze({b});
  EXPECT_EQ(output(), "");
  EXPECT_TRUE(facts[0].ok);
  std::vector<std::string> reads, writes;
  for (auto& a : facts[0].dReads) reads.push_back(a.prop);
  for (auto& a : facts[0].dWrites) writes.push_back(a.prop);
  EXPECT_EQ(reads, (std::vector<std::string>{"rho0", "arho", "n", "x"}));
  EXPECT_EQ(writes, (std::vector<std::string>{"rho", "n", "sigma"}));
  EXPECT_TRUE(facts[0].usesT);
  EXPECT_TRUE(facts[0].usesDt);
  EXPECT_EQ(facts[0].scalarsUsed, (std::set<std::string>{"c0"}));
  EXPECT_TRUE(facts[0].pairQuantities.empty());
}

// What a loop body may compute once per source or destination particle (BodyFacts::
// sourceOnly, destinationOnly; codegen/Hoist.cpp): the outermost one-sided expressions that
// divide or call a costly math function, with the locals they read.
TEST_F(BodyAnalysisTest, SourceAndDestinationOnlyExpressions) {
  load("equation E(k) {\n"
       "  loop {\n"
       "    double rhoj = s_rho[s_idx];\n"
       "    double q = s_m[s_idx];\n"
       "    q = q * 2.0;\n"
       "    int n = s_i[s_idx] / 2;\n"
       "    d_a[d_idx] += s_p[s_idx] / (rhoj * rhoj) * WIJ;\n"
       "    d_a[d_idx] += q / s_rho[s_idx];\n"
       "    d_a[d_idx] += s_m[d_idx] / s_rho[s_idx];\n"
       "    d_a[d_idx] += s_m[s_idx] * k * WIJ;\n"
       "    d_a[d_idx] += sqrt(s_m[s_idx] + k * t) * WIJ;\n"
       "    d_a[d_idx] += s_m[s_idx] / RIJ;\n"
       "    d_a[d_idx] += fabs(s_m[s_idx]) + n;\n"
       "    d_b[d_idx] = d_c[d_idx] / d_rho[d_idx];\n"
       "    d_a[d_idx] += d_a[d_idx] / d_rho[d_idx];\n"
       "  }\n"
       "}\n");
  BodySource b = body("loop", BodyKind::Loop);
  b.scalars = {"k"};
  b.props["i"] = PropShape{"int", 1};
  auto facts = analyze({b});
  EXPECT_EQ(output(), "");
  ASSERT_TRUE(facts[0].ok);
  auto text = [&](unsigned begin, unsigned end) { return b.text.substr(begin, end - begin); };
  // Not: q is assigned after its declaration, s_m[d_idx] is not the source particle's, the
  // product costs no more than a load, RIJ is a pair quantity, fabs is cheap, the int
  // division could trap.
  ASSERT_EQ(facts[0].sourceOnly.size(), 2u);
  const SourceOnlySite& p = facts[0].sourceOnly[0];
  EXPECT_EQ(text(p.begin, p.end), "s_p[s_idx] / (rhoj * rhoj)");
  ASSERT_EQ(p.locals.size(), 1u);
  EXPECT_EQ(p.locals[0].name, "rhoj");
  EXPECT_EQ(p.locals[0].type, "double");
  EXPECT_EQ(text(p.locals[0].initBegin, p.locals[0].initEnd), "s_rho[s_idx]");
  EXPECT_TRUE(p.scalars.empty());
  const SourceOnlySite& r = facts[0].sourceOnly[1];
  EXPECT_EQ(text(r.begin, r.end), "sqrt(s_m[s_idx] + k * t)");
  EXPECT_EQ(r.scalars, (std::set<std::string>{"k"}));
  EXPECT_TRUE(r.usesT);
  EXPECT_FALSE(r.usesDt);
  // Of the destination: not a, which the body writes.
  ASSERT_EQ(facts[0].destinationOnly.size(), 1u);
  const SourceOnlySite& d = facts[0].destinationOnly[0];
  EXPECT_EQ(text(d.begin, d.end), "d_c[d_idx] / d_rho[d_idx]");
}

TEST_F(BodyAnalysisTest, SourceWriteIsAnError) {
  load("equation E() {\n"
       "  loop { s_rho[s_idx] = 1.0; }\n"
       "}\n");
  auto facts = analyze({body("loop", BodyKind::Loop)});
  EXPECT_FALSE(facts[0].ok);
  EXPECT_EQ(output(),
            "eq.sph:2:10: error: cannot write to source property 's_rho': another thread may "
            "own that particle; write d_ properties only\n"
            "  loop { s_rho[s_idx] = 1.0; }\n"
            "         ^\n");
  EXPECT_EQ(diags_.errorCount(), 1u);
}

TEST_F(BodyAnalysisTest, AssigningAPropertyItselfIsAnError) {
  load("equation E() {\n"
       "  initialize { d_rho = d_p; }\n"
       "}\n");
  auto facts = analyze({body("initialize", BodyKind::Initialize)});
  EXPECT_FALSE(facts[0].ok);
  EXPECT_NE(output().find("eq.sph:2:16: error: cannot assign to property 'd_rho' itself"),
            std::string::npos)
      << output();
}

TEST_F(BodyAnalysisTest, UnknownFunctionIsAnError) {
  load("equation E() {\n"
       "  initialize {\n"
       "    d_p[d_idx] = sqrt(2.0) + foo(d_rho[d_idx]);\n"
       "  }\n"
       "}\n");
  auto facts = analyze({body("initialize", BodyKind::Initialize)});
  EXPECT_FALSE(facts[0].ok);
  EXPECT_EQ(diags_.errorCount(), 1u) << output();
  EXPECT_EQ(output().rfind("eq.sph:3:30: error: call of 'foo' is not allowed: bodies may call "
                           "only the math.h functions sqrt, pow,", 0),
            0u)
      << output();
}

TEST_F(BodyAnalysisTest, PointersAddressOfGotoStaticAndStringsAreErrors) {
  load("equation E() {\n"
       "  initialize {\n"
       "    double *p;\n"
       "    static int calls;\n"
       "    double a = *(&d_rho[d_idx]);\n"
       "    goto out;\n"
       "    out: d_p[d_idx] = a + (long)\"x\";\n"
       "  }\n"
       "}\n");
  auto facts = analyze({body("initialize", BodyKind::Initialize)});
  EXPECT_FALSE(facts[0].ok);
  std::string out = output();
  EXPECT_NE(out.find("eq.sph:3:13: error: pointer variables are not allowed"), std::string::npos)
      << out;
  EXPECT_NE(out.find("eq.sph:4:16: error: 'static' local variables are not allowed"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("eq.sph:5:18: error: '&' (address-of) is not allowed"), std::string::npos)
      << out;
  EXPECT_NE(out.find("eq.sph:6:5: error: 'goto' is not allowed"), std::string::npos) << out;
  EXPECT_NE(out.find("eq.sph:7:33: error: string literals are not allowed"), std::string::npos)
      << out;
}

TEST_F(BodyAnalysisTest, UndeclaredIdentifierOnFirstAndLaterLines) {
  // The first body starts mid-line: Clang's column must still be the .sph column.
  load("equation E() {\n"
       "  post_loop { d_p[d_idx] = rhoo; }\n"
       "  initialize {\n"
       "    double a = 1.0;\n"
       "\td_p[d_idx] = a * cs;\n"
       "  }\n"
       "}\n");
  auto facts = analyze({body("post_loop", BodyKind::PostLoop),
                        body("initialize", BodyKind::Initialize)});
  EXPECT_FALSE(facts[0].ok);
  EXPECT_FALSE(facts[1].ok);
  // (SourceMgr prints tabs expanded; the column counts the tab as one.)
  std::string out = output();
  EXPECT_EQ(out.rfind("eq.sph:2:28: error: use of undeclared identifier 'rhoo'\n"
                      "  post_loop { d_p[d_idx] = rhoo; }\n"
                      "                           ^\n"
                      "eq.sph:5:19: error: use of undeclared identifier 'cs'\n",
                      0),
            0u)
      << out;
  EXPECT_EQ(diags_.errorCount(), 2u);
}

TEST_F(BodyAnalysisTest, LoopOnlyNamesOutsideLoop) {
  load("equation E() {\n"
       "  post_loop { d_p[d_idx] = s_rho[s_idx] * WIJ + XIJ[0] + XIJ[1]; }\n"
       "}\n");
  auto facts = analyze({body("post_loop", BodyKind::PostLoop)});
  EXPECT_FALSE(facts[0].ok);
  std::string out = output();
  EXPECT_NE(out.find("eq.sph:2:28: error: 's_rho': s_ properties are only available in 'loop'"),
            std::string::npos)
      << out;
  EXPECT_NE(
      out.find("eq.sph:2:34: error: 's_idx' (the neighbour's index) is only available in 'loop'"),
      std::string::npos)
      << out;
  EXPECT_NE(out.find("eq.sph:2:43: error: WIJ is a pair quantity, only available in 'loop'"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("eq.sph:2:49: error: XIJ is a pair quantity"), std::string::npos) << out;
  EXPECT_EQ(diags_.errorCount(), 4u) << out;  // XIJ once
}

TEST_F(BodyAnalysisTest, ReturnRules) {
  load("equation E() {\n"
       "  reduce max dtmax { double a = d_h[d_idx]; a = a * 2.0; }\n"
       "  converged { if (d_res[0] < 1e-3) return 1; return -1; }\n"
       "  initialize { return 1.0; }\n"
       "}\n");
  auto facts = analyze({body("reduce", BodyKind::Reduce), body("converged", BodyKind::Converged),
                        body("initialize", BodyKind::Initialize)});
  EXPECT_FALSE(facts[0].ok);
  EXPECT_TRUE(facts[1].ok) << output();
  EXPECT_FALSE(facts[2].ok);
  std::string out = output();
  EXPECT_NE(out.find("eq.sph:2:58: error: missing 'return': equation Test, method reduce must "
                     "return a value"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("eq.sph:4:16: error: 'return' with a value is only allowed in 'reduce' "
                     "and 'converged' bodies"),
            std::string::npos)
      << out;
  EXPECT_EQ(diags_.errorCount(), 2u) << out;
}

TEST_F(BodyAnalysisTest, PragmasAndOddScalarNamesAreHarmless) {
  // Scalars named like a C keyword or a math constant are not declared (no internal error).
  load("equation E() {\n"
       "  initialize {\n"
       "    #pragma unroll\n"
       "    for (int k = 0; k < 3; ++k) d_v[3*d_idx + k] = M_PI * k;\n"
       "  }\n"
       "}\n");
  BodySource b = body("initialize", BodyKind::Initialize);
  b.scalars = {"int", "M_PI", "k"};
  auto facts = analyze({b});
  EXPECT_EQ(output(), "");
  EXPECT_TRUE(facts[0].ok);
  EXPECT_TRUE(facts[0].scalarsUsed.empty());  // k is the loop's own variable
}

TEST_F(BodyAnalysisTest, ClangWarningsAreForwarded) {
  load("equation E() {\n"
       "  initialize { double unused; d_p[d_idx] = 0.0; }\n"
       "}\n");
  auto facts = analyze({body("initialize", BodyKind::Initialize)});
  EXPECT_TRUE(facts[0].ok);
  EXPECT_NE(output().find("eq.sph:2:23: warning: unused variable 'unused'"), std::string::npos)
      << output();
}

TEST_F(BodyAnalysisTest, ManyBodiesInOneCall) {
  // 40 equations with a loop each; every other one has an error, which must not leak into the
  // facts of the others.
  std::string sph;
  for (int i = 0; i < 40; ++i) {
    sph += "equation E" + std::to_string(i) + "() {\n  loop {\n";
    sph += "    double r = RIJ / HIJ;\n";
    sph += "    d_a" + std::to_string(i) + "[d_idx] += s_m[s_idx] * WIJ * r" +
           (i % 2 ? " * oops" : "") + ";\n  }\n}\n";
  }
  load(sph);
  std::vector<BodySource> bodies;
  for (int i = 0; i < 40; ++i) 
    bodies.push_back(body("E" + std::to_string(i) + "() {\n  loop", BodyKind::Loop));
  auto t0 = std::chrono::steady_clock::now();
  auto facts = analyze(bodies);
  double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                  .count();
  std::printf("40 bodies analysed in %.1f ms\n", ms);
  ASSERT_EQ(facts.size(), 40u);
  EXPECT_EQ(diags_.errorCount(), 20u);
  for (int i = 0; i < 40; ++i) {
    EXPECT_EQ(facts[i].ok, i % 2 == 0) << i;
    ASSERT_EQ(facts[i].dWrites.size(), 1u) << i;
    EXPECT_EQ(facts[i].dWrites[0].prop, "a" + std::to_string(i));
    EXPECT_EQ(facts[i].pairQuantities, (std::set<std::string>{"HIJ", "RIJ", "WIJ"})) << i;
  }
  EXPECT_NE(output().find("eq.sph:10:43: error: use of undeclared identifier 'oops'"),
            std::string::npos)
      << output();
}

TEST(BodyNames, PairQuantitiesAndMath) {
  EXPECT_EQ(pairQuantityNames().size(), 14u);
  EXPECT_EQ(allowedMathFunctions().size(), 27u);
}

}  // namespace
}  // namespace sphc
