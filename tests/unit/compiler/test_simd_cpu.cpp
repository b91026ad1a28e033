// --simd-pairs=auto by the CPU (codegen/SimdCpu.h): the host's cpuid, --simd-cpu's form and
// the rule (the lanes on AMD family 26 and later and on Intel models 207 and 143, with gathers
// allowed by the build; the scalar loops on other Intel CPUs and elsewhere).
#include "codegen/SimdCpu.h"

#include <gtest/gtest.h>

namespace sphc {
namespace {

TEST(SimdCpu, ParsesVendorFamilyModel) {
  SimdCpu cpu;
  std::string why;
  ASSERT_TRUE(parseSimdCpu("GenuineIntel:6:207", cpu, why));
  EXPECT_EQ(cpu.vendor, "GenuineIntel");
  EXPECT_EQ(cpu.family, 6);
  EXPECT_EQ(cpu.model, 207);
  EXPECT_EQ(cpu.describe(), "GenuineIntel family 6 model 207 (--simd-cpu)");
  ASSERT_TRUE(parseSimdCpu("AuthenticAMD:0x1a:0x2", cpu, why));
  EXPECT_EQ(cpu.family, 26);
  EXPECT_EQ(cpu.model, 2);
  EXPECT_TRUE(cpu.avx512f);
  ASSERT_TRUE(parseSimdCpu("AuthenticAMD:26:2:noavx512", cpu, why));
  EXPECT_FALSE(cpu.avx512f);
  EXPECT_EQ(cpu.model, 2);
  EXPECT_EQ(cpu.describe(), "AuthenticAMD family 26 model 2 without AVX-512 (--simd-cpu)");
  for (const char* bad : {"intel", "GenuineIntel:6", "GenuineIntel:6:207:1", ":6:207",
                          "GenuineIntel:x:1", "GenuineIntel:6:", "GenuineIntel:-1:2",
                          "GenuineIntel:6:207:avx2"}) {
    why.clear();
    EXPECT_FALSE(parseSimdCpu(bad, cpu, why)) << bad;
    EXPECT_NE(why.find("VENDOR:FAMILY:MODEL"), std::string::npos) << bad;
  }
}

TEST(SimdCpu, LanesWhereMeasuredToPay) {
  auto lanes = [](const char* text) {
    SimdCpu cpu;
    std::string why;
    EXPECT_TRUE(parseSimdCpu(text, cpu, why)) << text;
    const SimdCpuVerdict v = simdLanesOnCpu(cpu);
    EXPECT_NE(v.why.find(cpu.describe()), std::string::npos) << v.why;
    return v.lanes;
  };
  EXPECT_TRUE(lanes("AuthenticAMD:26:2"));     // Zen 5 (stop 33: 0.82-0.86 of a cube step)
  EXPECT_TRUE(lanes("AuthenticAMD:27:0"));     // later AMD families
  EXPECT_TRUE(lanes("GenuineIntel:6:207"));    // Emerald Rapids (stop 35, gathers: 0.80-0.82)
  EXPECT_TRUE(lanes("GenuineIntel:6:143"));    // Sapphire Rapids: the same cores
  EXPECT_FALSE(lanes("GenuineIntel:6:85"));    // Skylake-SP / Cascade Lake: not measured
  EXPECT_FALSE(lanes("GenuineIntel:6:106"));   // Ice Lake-SP: not measured
  EXPECT_FALSE(lanes("GenuineIntel:6:207:noavx512"));
  EXPECT_FALSE(lanes("AuthenticAMD:25:17"));   // Zen 4: not measured
  EXPECT_FALSE(lanes("HygonGenuine:24:0"));    // not measured
  // Without AVX-512F GCC 12 does not if-convert the bodies' divisions: no lanes anywhere.
  EXPECT_FALSE(lanes("AuthenticAMD:26:2:noavx512"));
}

// auto's cluster-pair tiles for its 3D loops (stop 38): where they were measured to pay, the
// Intel models of the lanes; not on AMD (not measured), nor where the lanes are refused.
TEST(SimdCpu, TilesWhereMeasuredToPay) {
  auto tiles = [](const char* text) {
    SimdCpu cpu;
    std::string why;
    EXPECT_TRUE(parseSimdCpu(text, cpu, why)) << text;
    const SimdCpuVerdict v = simdLanesOnCpu(cpu);
    if (v.tiles) {
      EXPECT_TRUE(v.lanes) << text;
      EXPECT_NE(v.tilesWhy.find(cpu.describe()), std::string::npos) << v.tilesWhy;
    }
    return v.tiles;
  };
  EXPECT_TRUE(tiles("GenuineIntel:6:207"));    // Emerald Rapids (stop 38: measured)
  EXPECT_TRUE(tiles("GenuineIntel:6:143"));    // Sapphire Rapids: the same cores
  EXPECT_FALSE(tiles("AuthenticAMD:26:2"));    // Zen 5: the lanes (tiles not measured)
  EXPECT_FALSE(tiles("GenuineIntel:6:85"));
  EXPECT_FALSE(tiles("GenuineIntel:6:207:noavx512"));
  EXPECT_FALSE(tiles("HygonGenuine:24:0"));
}

TEST(SimdCpu, HostIsReadOnX86) {
  const SimdCpu cpu = hostSimdCpu();
  EXPECT_EQ(cpu.origin, "this machine");
#if defined(__x86_64__) || defined(__i386__)
  EXPECT_EQ(cpu.vendor.size(), 12u);
  EXPECT_GT(cpu.family, 0);
  EXPECT_GE(cpu.model, 0);
#else
  EXPECT_TRUE(cpu.vendor.empty());
#endif
}

}  // namespace
}  // namespace sphc
