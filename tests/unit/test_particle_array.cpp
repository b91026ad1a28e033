// Unit tests of sphc::ParticleArray (runtime/include/sphc/particle_array.h).
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "non_finite_checks.h"
#include "sphc/particle_array.h"

namespace {

using sphc::ParticleArray;
using sphc::PropType;

// Expects `f` to throw E whose message contains each of `words`.
template <class E, class F>
void expect_error(F&& f, std::initializer_list<const char*> words) {
  try {
    f();
    ADD_FAILURE() << "expected an exception";
  } catch (const E& e) {
    for (const char* w : words) {
      EXPECT_NE(std::string(e.what()).find(w), std::string::npos)
          << "message '" << e.what() << "' lacks '" << w << "'";
    }
  }
}

TEST(ParticleArray, AddAndFindProperties) {
  ParticleArray pa;
  pa.name = "fluid";
  pa.resize(4);
  const int rho = pa.add_property("rho", PropType::F64, 1, 1000.0);
  const int tag = pa.add_property("tag", PropType::I32, 1, -2.0);
  const int gid = pa.add_property("gid", PropType::U32, 1, 7.0);
  const int tau = pa.add_property("tau", PropType::F64, 9);
  EXPECT_EQ(pa.find("rho"), rho);
  EXPECT_EQ(pa.find("tag"), tag);
  EXPECT_EQ(pa.find("gid"), gid);
  EXPECT_EQ(pa.find("tau"), tau);
  EXPECT_EQ(pa.find("p"), -1);
  EXPECT_EQ(pa.props[rho].f64.size(), 4u);
  EXPECT_EQ(pa.props[tau].f64.size(), 36u);
  EXPECT_EQ(pa.f64(rho)[3], 1000.0);
  EXPECT_EQ(pa.i32(tag)[0], -2);
  EXPECT_EQ(pa.u32(gid)[2], 7u);
  EXPECT_EQ(pa.f64("rho"), pa.f64(rho));
  const ParticleArray& cpa = pa;
  EXPECT_EQ(cpa.f64("rho"), cpa.f64(rho));
  // Adding again returns the same index and keeps the values.
  pa.f64(rho)[0] = 5.0;
  EXPECT_EQ(pa.add_property("rho", PropType::F64, 1, 3.0), rho);
  EXPECT_EQ(pa.f64(rho)[0], 5.0);
  EXPECT_STREQ(sphc::prop_type_name(PropType::F64), "double");
  EXPECT_STREQ(sphc::prop_type_name(PropType::I32), "int");
  EXPECT_STREQ(sphc::prop_type_name(PropType::U32), "unsigned");
}

TEST(ParticleArray, PropertyErrors) {
  ParticleArray pa;
  pa.name = "fluid";
  pa.add_property("rho");
  pa.add_property("tag", PropType::I32);
  expect_error<std::invalid_argument>([&] { pa.add_property("rho", PropType::I32); },
                                      {"fluid", "rho"});
  expect_error<std::invalid_argument>([&] { pa.add_property("rho", PropType::F64, 3); },
                                      {"fluid", "rho"});
  expect_error<std::invalid_argument>([&] { pa.add_property("v", PropType::F64, 0); },
                                      {"fluid", "v", "stride"});
  expect_error<std::out_of_range>([&] { pa.f64("p"); }, {"fluid", "p"});
  expect_error<std::out_of_range>([&] { pa.f64("tag"); }, {"fluid", "tag"});
  const ParticleArray& cpa = pa;
  expect_error<std::out_of_range>([&] { cpa.f64("p"); }, {"fluid", "p"});
}

TEST(ParticleArray, Resize) {
  ParticleArray pa;
  pa.add_property("m", PropType::F64, 1, 2.0);
  pa.add_property("tau", PropType::F64, 9);
  pa.add_property("tag", PropType::I32);
  pa.resize(3);
  EXPECT_EQ(pa.n, 3u);
  EXPECT_EQ(pa.props[0].f64.size(), 3u);
  EXPECT_EQ(pa.props[1].f64.size(), 27u);
  EXPECT_EQ(pa.props[2].i32.size(), 3u);
  EXPECT_EQ(pa.f64("m")[2], 0.0);  // new entries are 0, not the add_property init value
  pa.f64("m")[0] = 1.5;
  pa.resize(1);
  EXPECT_EQ(pa.props[1].f64.size(), 9u);
  EXPECT_EQ(pa.f64("m")[0], 1.5);
  pa.resize(0);
  EXPECT_EQ(pa.props[0].f64.size(), 0u);
}

TEST(ParticleArray, Constants) {
  ParticleArray pa;
  pa.name = "fluid";
  const int c = pa.add_constant("total_mass", 1, 3.0);
  const int v = pa.add_constant("bounds", 4);
  EXPECT_EQ(pa.find_constant("total_mass"), c);
  EXPECT_EQ(pa.find_constant("bounds"), v);
  EXPECT_EQ(pa.find_constant("nope"), -1);
  EXPECT_EQ(pa.constant(c)[0], 3.0);
  EXPECT_EQ(pa.constants[v].values.size(), 4u);
  pa.constant("bounds")[3] = 9.0;
  EXPECT_EQ(pa.constant(v)[3], 9.0);
  EXPECT_EQ(pa.add_constant("total_mass", 1, 7.0), c);  // existing: unchanged
  EXPECT_EQ(pa.constant(c)[0], 3.0);
  expect_error<std::out_of_range>([&] { pa.constant("nope"); }, {"fluid", "nope"});
}

TEST(ParticleArray, AppendFrom) {
  ParticleArray src;
  src.name = "inlet";
  src.resize(2);
  src.add_property("x");
  src.add_property("tag", PropType::I32);
  src.add_property("tau", PropType::F64, 2);
  src.add_property("only_in_src");
  src.f64("x")[1] = 4.5;
  src.i32(src.find("tag"))[1] = -3;
  src.f64("tau")[2] = 1.0;
  src.f64("tau")[3] = 2.0;

  ParticleArray dst;
  dst.name = "fluid";
  dst.resize(1);
  dst.add_property("x", PropType::F64, 1, 1.0);
  dst.add_property("tag", PropType::I32);
  dst.add_property("tau", PropType::F64, 2);
  dst.add_property("rho", PropType::F64, 1, 1000.0);  // missing in src: appended as 0
  dst.append_from(src, 1);
  ASSERT_EQ(dst.n, 2u);
  EXPECT_EQ(dst.f64("x")[0], 1.0);
  EXPECT_EQ(dst.f64("x")[1], 4.5);
  EXPECT_EQ(dst.i32(dst.find("tag"))[1], -3);
  EXPECT_EQ(dst.f64("tau")[2], 1.0);
  EXPECT_EQ(dst.f64("tau")[3], 2.0);
  EXPECT_EQ(dst.f64("rho")[1], 0.0);
  EXPECT_EQ(dst.find("only_in_src"), -1);

  // Appending from itself.
  dst.append_from(dst, 1);
  ASSERT_EQ(dst.n, 3u);
  EXPECT_EQ(dst.f64("x")[2], 4.5);
  EXPECT_EQ(dst.f64("tau")[5], 2.0);

  // Errors leave the array untouched.
  expect_error<std::out_of_range>([&] { dst.append_from(src, 2); }, {"inlet"});
  ParticleArray other;
  other.name = "odd";
  other.resize(1);
  other.add_property("x");
  other.add_property("tag", PropType::U32);
  expect_error<std::invalid_argument>([&] { dst.append_from(other, 0); }, {"tag", "odd"});
  EXPECT_EQ(dst.n, 3u);
  for (const auto& p : dst.props) {
    const std::size_t len = p.type == PropType::F64 ? p.f64.size() : p.i32.size();
    EXPECT_EQ(len, 3u * p.stride) << p.name;
  }
}

}  // namespace

// permute: particle i becomes old particle order[i], in every property, whatever its type
// and stride; a non-permutation is refused and changes nothing.
TEST(ParticleArrayPermute, ReordersEveryPropertyByTheGivenOrder) {
  sphc::ParticleArray a;
  a.name = "fluid";
  int x = a.add_property("x");
  int tag = a.add_property("tag", sphc::PropType::I32);
  int s = a.add_property("s", sphc::PropType::F64, 2);
  a.resize(3);
  for (int i = 0; i < 3; ++i) {
    a.f64(x)[i] = 10.0 * i;
    a.i32(tag)[i] = 100 + i;
    a.f64(s)[2 * i] = i;
    a.f64(s)[2 * i + 1] = -i;
  }
  a.permute({2, 0, 1});
  EXPECT_EQ(a.f64(x)[0], 20.0);
  EXPECT_EQ(a.f64(x)[1], 0.0);
  EXPECT_EQ(a.f64(x)[2], 10.0);
  EXPECT_EQ(a.i32(tag)[0], 102);
  EXPECT_EQ(a.i32(tag)[2], 101);
  EXPECT_EQ(a.f64(s)[0], 2.0);
  EXPECT_EQ(a.f64(s)[1], -2.0);
  EXPECT_EQ(a.f64(s)[5], -1.0);
  EXPECT_THROW(a.permute({0, 0, 1}), std::invalid_argument);
  EXPECT_THROW(a.permute({0, 1}), std::invalid_argument);
  EXPECT_EQ(a.f64(x)[0], 20.0);
}

// The run loop's blow-up scan: the first NaN or infinity, as a plain loop finds it.
TEST(FindNonFinite, FirstBadValueInScanOrder) {
  for (std::size_t n : {0, 1, 5, 3000, 20000}) {
    SCOPED_TRACE(testing::Message() << n << " particles");
    sphc_test::check_find_non_finite(n);
  }
}
