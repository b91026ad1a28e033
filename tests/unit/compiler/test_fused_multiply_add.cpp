// Fused multiply-adds: the sites the body analysis records (body/BodyAnalysis.h,
// MultiplyAddSite), how they move when a pass edits the text (body/TextEdits.h) and how the
// printer writes them (codegen/FusedMultiplyAdd.h), over a fake .sph buffer.
#include "body/BodyAnalysis.h"
#include "body/TextEdits.h"
#include "codegen/FusedMultiplyAdd.h"

#include "llvm/Support/MemoryBuffer.h"

#include <gtest/gtest.h>

#include <string>

namespace sphc {
namespace {

class FusedMultiplyAddTest : public ::testing::Test {
 protected:
  // The facts of `text` as the body of a loop (s_ names and pair quantities visible).
  BodyFacts analyze(const std::string& text, std::vector<std::string> scalars = {}) {
    std::string sph = "equation Test() {\n  loop {" + text + "}\n}\n";
    unsigned id = sm_.AddNewSourceBuffer(llvm::MemoryBuffer::getMemBufferCopy(sph, "eq.sph"),
                                         llvm::SMLoc());
    llvm::StringRef buffer = sm_.getMemoryBuffer(id)->getBuffer();
    size_t open = buffer.find('{', buffer.find("loop"));
    BodySource b;
    b.text = text;
    b.start = llvm::SMLoc::getFromPointer(buffer.data() + open + 1);
    b.kind = BodyKind::Loop;
    b.label = "equation Test, method loop";
    b.scalars = scalars;
    auto facts = BodyAnalyzer(diags_).analyze({b});
    EXPECT_EQ(out_.str(), "");
    EXPECT_TRUE(facts[0].ok);
    return facts[0];
  }

  std::string fused(const std::string& text, std::vector<std::string> scalars = {}) {
    return fuseMultiplyAdds(text, analyze(text, scalars).multiplyAdds, "fma");
  }

  llvm::SourceMgr sm_;
  std::string messages_;
  llvm::raw_string_ostream out_{messages_};
  DiagnosticEngine diags_{sm_, out_};
};

TEST_F(FusedMultiplyAddTest, EveryForm) {
  EXPECT_EQ(fused(" d_a[d_idx] = XIJ[0] * k + R2IJ; ", {"k"}),
            " d_a[d_idx] = fma(XIJ[0], k, R2IJ); ");
  EXPECT_EQ(fused(" d_a[d_idx] = R2IJ + XIJ[0] * k; ", {"k"}),
            " d_a[d_idx] = fma(XIJ[0], k, R2IJ); ");
  EXPECT_EQ(fused(" d_a[d_idx] = XIJ[0] * k - R2IJ; ", {"k"}),
            " d_a[d_idx] = fma(XIJ[0], k, -R2IJ); ");
  EXPECT_EQ(fused(" d_a[d_idx] = R2IJ - XIJ[0] * k; ", {"k"}),
            " d_a[d_idx] = fma(-XIJ[0], k, R2IJ); ");
  EXPECT_EQ(fused(" d_a[d_idx] += s_m[s_idx] * DWIJ[0]; "),
            " d_a[d_idx] = fma(s_m[s_idx], DWIJ[0], d_a[d_idx]); ");
  EXPECT_EQ(fused(" d_a[d_idx] -= s_m[s_idx] * DWIJ[0]; "),
            " d_a[d_idx] = fma(-s_m[s_idx], DWIJ[0], d_a[d_idx]); ");
  // Negated operands that are not primary expressions keep their meaning.
  EXPECT_EQ(fused(" d_a[d_idx] = R2IJ - (k + 1.0) * k - XIJ[0] * XIJ[1]; ", {"k"}),
            " d_a[d_idx] = fma(-XIJ[0], XIJ[1], fma(-(k + 1.0), k, R2IJ)); ");
  EXPECT_EQ(fused(" d_a[d_idx] = XIJ[0] * k - R2IJ * k; ", {"k"}),
            " d_a[d_idx] = fma(XIJ[0], k, -(R2IJ * k)); ");
}

TEST_F(FusedMultiplyAddTest, NestingParenthesesCommentsAndLines) {
  EXPECT_EQ(fused(" d_a[d_idx] = (XIJ[0] * XIJ[0] + XIJ[1]) * R2IJ + (XIJ[1] * XIJ[1] + R2IJ); "),
            " d_a[d_idx] = fma(fma(XIJ[0], XIJ[0], XIJ[1]), R2IJ, fma(XIJ[1], XIJ[1], R2IJ)); ");
  EXPECT_EQ(fused(" d_a[d_idx] = sqrt(XIJ[0] * XIJ[0] + R2IJ) / (XIJ[1] * R2IJ + 1.0); "),
            " d_a[d_idx] = sqrt(fma(XIJ[0], XIJ[0], R2IJ)) / fma(XIJ[1], R2IJ, 1.0); ");
  EXPECT_EQ(fused(" d_a[d_idx] = XIJ[0] * XIJ[0]  // first\n"
                  "               + XIJ[1] * XIJ[1]; "),
            " d_a[d_idx] = fma(XIJ[0], XIJ[0],  // first\n"
            "               XIJ[1] * XIJ[1]); ");
  // A line break dropped with parentheses comes back after the site: lines below keep their
  // numbers.
  std::string out = fused(" d_a[d_idx] = (XIJ[0] *\n XIJ[1]\n) + R2IJ; ");
  EXPECT_EQ(out, " d_a[d_idx] = fma(XIJ[0],\n XIJ[1], R2IJ)\n; ");
}

TEST_F(FusedMultiplyAddTest, OnlyOneFloatingTypeAsWritten) {
  // Integer arithmetic, an int factor, a float product converted to double, a target with a
  // side effect (written twice by x = fma(a, b, x)): as written.
  for (const char* text : {" int i = d_idx * 2 + 1; d_a[i] = i; ",
                           " d_a[d_idx] = 2 * R2IJ + 1.0; ",
                           " d_a[d_idx] = R2IJ * R2IJ + 1; ",
                           " float f = R2IJ; d_a[d_idx] = f * f + R2IJ; ",
                           " int i = d_idx; d_a[i++] += R2IJ * R2IJ; "})
    EXPECT_EQ(fused(text), text) << text;
  // A body that names something `fma` (it would hide OpenCL's): as written.
  EXPECT_EQ(fused(" double fma = 2.0; d_a[d_idx] = fma * R2IJ + 1.0; "),
            " double fma = 2.0; d_a[d_idx] = fma * R2IJ + 1.0; ");
  EXPECT_EQ(fused(" d_a[d_idx] = fma * R2IJ + 1.0; ", {"fma"}), " d_a[d_idx] = fma * R2IJ + 1.0; ");
  EXPECT_EQ(fused(" float f = R2IJ; f = f * f + f; d_a[d_idx] = f; "),
            " float f = R2IJ; f = fma(f, f, f); d_a[d_idx] = f; ");
  EXPECT_EQ(fused(" d_a[d_idx] = M_PI * R2IJ + 1.0; "), " d_a[d_idx] = fma(M_PI, R2IJ, 1.0); ");
}

TEST_F(FusedMultiplyAddTest, SitesMoveWithEdits) {
  std::string text = " d_w[d_idx] += s_m[s_idx] * d_z[d_idx]; d_a[d_idx] = d_z[d_idx] * k + 1.0; ";
  BodyFacts facts = analyze(text, {"k"});
  ASSERT_EQ(facts.multiplyAdds.size(), 2u);
  std::vector<TextEdit> edits;
  for (const PropSite& s : facts.sites) {
    if (s.prop == "z") edits.push_back({s.begin, s.end, "0.0"});
    if (s.prop == "w") edits.push_back({s.begin, s.end, "sphc_sink"});
  }
  edits.push_back({0, 0, " double sphc_sink = 0.0;"});
  ASSERT_TRUE(applyTextEdits(text, edits, facts));
  EXPECT_EQ(text, " double sphc_sink = 0.0; sphc_sink += s_m[s_idx] * 0.0; d_a[d_idx] = 0.0 * k "
                  "+ 1.0; ");
  EXPECT_EQ(fuseMultiplyAdds(text, facts.multiplyAdds, "std::fma"),
            " double sphc_sink = 0.0; sphc_sink = std::fma(s_m[s_idx], 0.0, sphc_sink); "
            "d_a[d_idx] = std::fma(0.0, k, 1.0); ");
  // The remaining property sites name their code in the new text.
  for (const PropSite& s : facts.sites)
    if (s.prop == "a" || s.prop == "m")
      EXPECT_EQ(text.substr(s.begin, s.end - s.begin), s.prop == "a" ? "d_a[d_idx]" : "s_m[s_idx]");
  // An edit that cuts into a site drops it (printed as written); overlapping edits: refused.
  std::string cut = text;
  BodyFacts cutFacts = facts;
  unsigned at = static_cast<unsigned>(cut.find("0.0 * k"));
  ASSERT_TRUE(applyTextEdits(cut, {{at + 2, at + 7, "0 * kk"}}, cutFacts));
  EXPECT_EQ(cutFacts.multiplyAdds.size(), 1u);
  std::string before = text;
  EXPECT_FALSE(applyTextEdits(text, {{1, 5, "x"}, {3, 8, "y"}}, facts));
  EXPECT_EQ(text, before);
}

}  // namespace
}  // namespace sphc
