// FloatArray (runtime/include/sphc/float_arrays.h): the float copies of --precision=single.
#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

#include "sphc/float_arrays.h"
#include "sphc/particle_array.h"

namespace {

sphc::ParticleArray sample() {
  sphc::ParticleArray pa;
  pa.name = "fluid";
  pa.resize(4);
  pa.add_property("x");
  pa.add_property("tau", sphc::PropType::F64, 2);
  pa.add_property("tag", sphc::PropType::I32);
  pa.add_constant("c", 2, 0.1);
  for (int i = 0; i < 4; ++i) {
    pa.f64(0)[i] = 0.1 * (i + 1);  // not floats
    pa.f64(1)[2 * i] = i;
    pa.f64(1)[2 * i + 1] = -i;
    pa.i32(2)[i] = 10 + i;
  }
  return pa;
}

TEST(FloatArray, UploadRoundsDownloadWritesBack) {
  sphc::ParticleArray pa = sample();
  sphc::FloatArray f;
  f.upload(pa);
  ASSERT_EQ(f.n, 4u);
  EXPECT_TRUE(f.props[2].empty());  // integers stay in the host array
  for (int i = 0; i < 4; ++i) EXPECT_EQ(f.f(0)[i], static_cast<float>(0.1 * (i + 1)));
  EXPECT_EQ(f.constant(0)[1], 0.1f);
  f.f(0)[3] = 2.5f;
  f.constant(0)[0] = 0.25f;
  f.download(pa);
  // Every double is now the float value, exactly.
  for (int i = 0; i < 3; ++i) EXPECT_EQ(pa.f64(0)[i], static_cast<double>(static_cast<float>(0.1 * (i + 1))));
  EXPECT_EQ(pa.f64(0)[3], 2.5);
  EXPECT_EQ(pa.constant(0)[0], 0.25);
  EXPECT_EQ(pa.constant(0)[1], static_cast<double>(0.1f));
  EXPECT_EQ(pa.props[2].i32[1], 11);
  sphc::ParticleArray other = sample();
  other.resize(3);
  EXPECT_THROW(f.download(other), std::invalid_argument);
}

TEST(FloatArray, PermuteMovesFloatsAndHostIntegers) {
  sphc::ParticleArray pa = sample();
  sphc::FloatArray f;
  f.upload(pa);
  const std::vector<std::uint32_t> order = {2, 0, 3, 1};
  f.permute(order, pa);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(f.f(0)[i], static_cast<float>(0.1 * (order[i] + 1)));
    EXPECT_EQ(f.f(1)[2 * i], static_cast<float>(order[i]));
    EXPECT_EQ(f.f(1)[2 * i + 1], -static_cast<float>(order[i]));
    EXPECT_EQ(pa.props[2].i32[i], 10 + static_cast<int>(order[i]));
  }
  EXPECT_THROW(f.permute({0, 0, 1, 2}, pa), std::invalid_argument);
  EXPECT_THROW(f.permute({0, 1, 2}, pa), std::invalid_argument);
}

}  // namespace
