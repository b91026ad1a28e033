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

// auto's verdict per CPU: the lanes where they were measured to pay, and for its 3D loops the
// cluster-pair tiles (stop 38) on the Intel models of the lanes only (not on AMD: not
// measured; never where the lanes are refused), for its 2D loops too on model 207 only (stop
// 43). Each reason names the CPU.
TEST(SimdCpu, VerdictsWhereMeasuredToPay) {
  struct Case {
    const char* cpu;
    bool lanes, tiles;
    bool tiles2d = false;
  };
  const Case cases[] = {
      {"AuthenticAMD:26:2", true, false},    // Zen 5 (stop 33: 0.82-0.86 of a cube step)
      {"AuthenticAMD:27:0", true, false},    // later AMD families
      {"GenuineIntel:6:207", true, true, true},  // Emerald Rapids (stop 35, gathers: 0.80-0.82;
                                                 // tiles: stop 38; 2D tiles: stop 43, measured)
      // Sapphire Rapids: the same cores; its 2D loops scalar (GCC 12 tunes for it with 256-bit
      // vectors, where the 2D tiles lost: stop 43).
      {"GenuineIntel:6:143", true, true, false},
      // A VM reporting model 167 with Sapphire Rapids-class cores (AMX, AVX512-FP16): measured
      // with the SIMD builds' 512-bit preference (stop 43).
      {"GenuineIntel:6:167", true, true, true},
      {"GenuineIntel:6:85", false, false},   // Skylake-SP / Cascade Lake: not measured
      {"GenuineIntel:6:106", false, false},  // Ice Lake-SP: not measured
      {"GenuineIntel:6:207:noavx512", false, false},
      {"AuthenticAMD:25:17", false, false},  // Zen 4: not measured
      {"HygonGenuine:24:0", false, false},   // not measured
      // Without AVX-512F GCC 12 does not if-convert the bodies' divisions: no lanes anywhere.
      {"AuthenticAMD:26:2:noavx512", false, false},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.cpu);
    SimdCpu cpu;
    std::string why;
    ASSERT_TRUE(parseSimdCpu(c.cpu, cpu, why));
    const SimdCpuVerdict v = simdLanesOnCpu(cpu);
    EXPECT_EQ(v.lanes, c.lanes);
    EXPECT_EQ(v.tiles, c.tiles);
    EXPECT_EQ(v.tiles2d, c.tiles2d);
    EXPECT_NE(v.why.find(cpu.describe()), std::string::npos) << v.why;
    if (v.tiles) EXPECT_NE(v.tilesWhy.find(cpu.describe()), std::string::npos) << v.tilesWhy;
  }
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
