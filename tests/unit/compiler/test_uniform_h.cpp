// hPerParticleReason (analysis/UniformH.cpp, stop 45): which arrays' h is one value for the
// whole run, on plans built by hand (the lit tests tests/lit/codegen/uniform-h*.sph check the
// driver and the generated loops end to end).
#include "analysis/UniformH.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

namespace sphc {
namespace {

ast::ExprPtr num(double v) {
  auto e = std::make_shared<ast::Expr>();
  e->kind = ast::Expr::Number;
  e->number = v;
  return e;
}

ast::ExprPtr name(const std::string& n) {
  auto e = std::make_shared<ast::Expr>();
  e->kind = ast::Expr::Name;
  e->text = n;
  return e;
}

ast::ExprPtr mul(ast::ExprPtr a, ast::ExprPtr b) {
  auto e = std::make_shared<ast::Expr>();
  e->kind = ast::Expr::Binary;
  e->op = "*";
  e->args = {a, b};
  return e;
}

class UniformHTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dx_.name.name = "dx";
    dx_.value = num(0.1);
    hdx_.name.name = "hdx";
    hdx_.value = num(1.3);
    hdx_.derived = true;  // a `let` is a param too
    plan_.params = {&dx_, &hdx_};
    decl_.name.name = "fluid";
  }
  // An array `fluid` whose h starts at `init` (null: none of its own).
  void array(ast::ExprPtr init, bool written = false) {
    PlanArray a;
    a.name = "fluid";
    a.decl = &decl_;
    PlanProperty h;
    h.name = "h";
    h.init = init;
    h.written = written;
    a.props.push_back(h);
    plan_.arrays.push_back(a);
  }
  std::string why() { return hPerParticleReason(plan_, 0); }

  ast::ParamDecl dx_, hdx_;
  ast::ArrayDecl decl_;
  Plan plan_;
};

TEST_F(UniformHTest, ParamsAndConstantsAreUniform) {
  array(mul(mul(name("hdx"), name("dx")), name("pi")));
  EXPECT_EQ(why(), "");
  EXPECT_EQ(uniformHNote(plan_, ""), "h uniform: fluid (the CPU pair loops read it once per pass)");
  EXPECT_EQ(uniformHNote(plan_, "--no-uniform-h"),
            "h uniform: fluid (the pair loops read h per particle: --no-uniform-h)");
}

TEST_F(UniformHTest, WrittenIsPerParticle) {
  array(mul(name("hdx"), name("dx")), /*written=*/true);
  EXPECT_EQ(why(), "an equation, stepper or group hook writes h");
  EXPECT_EQ(uniformHNote(plan_, ""),
            "h per particle: fluid (an equation, stepper or group hook writes h)");
}

TEST_F(UniformHTest, InitialValueOfAPositionOrPropertyIsPerParticle) {
  array(mul(name("dx"), name("y")));
  EXPECT_EQ(why(), "its initial h reads y");
  plan_.arrays.clear();
  array(mul(name("rho"), num(2.0)));
  EXPECT_EQ(why(), "its initial h reads rho");
}

TEST_F(UniformHTest, NoInitialValueIsPerParticle) {
  array(nullptr);
  EXPECT_EQ(why(), "h has no initial value of its own");
}

TEST_F(UniformHTest, AnUnknownFunctionIsPerParticle) {
  auto call = std::make_shared<ast::Expr>();
  call->kind = ast::Expr::Call;
  call->text = "rand";
  array(call);
  EXPECT_EQ(why(), "its initial h is not an expression of params");
}

TEST_F(UniformHTest, LoadsAndZonesArePerParticle) {
  array(mul(name("hdx"), name("dx")));
  decl_.loads.push_back(ast::LoadDecl{"particles.csv", llvm::SMLoc()});
  EXPECT_EQ(why(), "its particles are loaded from a file");
  decl_.loads.clear();
  PlanZone z;
  z.inlet = true;
  z.name = "in";
  z.array = 1;
  z.other = 0;  // the inlet feeds fluid
  plan_.zones.push_back(z);
  EXPECT_EQ(why(), "the inlet 'in' adds or takes its particles");
}

TEST_F(UniformHTest, NoH) {
  PlanArray a;
  a.name = "probe";
  a.decl = &decl_;
  plan_.arrays.push_back(a);
  EXPECT_EQ(why(), "it has no h");
  EXPECT_EQ(uniformHNote(plan_, ""), "");
}

}  // namespace
}  // namespace sphc
