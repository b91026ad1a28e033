// --simd-pairs=auto by the CPU (codegen/SimdCpu.h): the host's cpuid, --simd-cpu's form and
// the rule (the lanes on AMD family 26 and later; on Intel with AVX512-FP16 or AMX-TILE, and
// models 207 and 143 without them, with gathers allowed by the build; the scalar loops on other
// Intel CPUs and elsewhere).
#include "codegen/SimdCpu.h"

#include <fstream>

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
  // Without a feature list: AVX-512F and none of leaf 7's others.
  ASSERT_TRUE(parseSimdCpu("GenuineIntel:6:207", cpu, why));
  EXPECT_TRUE(cpu.avx512f);
  EXPECT_FALSE(cpu.avx512fp16 || cpu.amxTile || cpu.avx512vbmi2);
  for (const char* bad : {"intel", "GenuineIntel:6", "GenuineIntel:6:207:1", ":6:207",
                          "GenuineIntel:x:1", "GenuineIntel:6:", "GenuineIntel:-1:2",
                          "GenuineIntel:6:207:avx2", "GenuineIntel:6:207:", "GenuineIntel:6:207:+",
                          "GenuineIntel:6:207:+avx2", "GenuineIntel:6:207:avx512fp16",
                          "GenuineIntel:6:207:+amx,", "GenuineIntel:6:207:+amx:+avx512fp16",
                          "GenuineIntel:6:207:noavx512:+amx"}) {
    why.clear();
    EXPECT_FALSE(parseSimdCpu(bad, cpu, why)) << bad;
    EXPECT_NE(why.find("VENDOR:FAMILY:MODEL"), std::string::npos) << bad;
  }
}

// The features after the model (stop 44): +F / -F, comma separated; noavx512 as before.
TEST(SimdCpu, ParsesFeatures) {
  SimdCpu cpu;
  std::string why;
  ASSERT_TRUE(parseSimdCpu("GenuineIntel:6:167:+avx512fp16,+amx", cpu, why)) << why;
  EXPECT_EQ(cpu.model, 167);
  EXPECT_TRUE(cpu.avx512f);
  EXPECT_TRUE(cpu.avx512fp16);
  EXPECT_TRUE(cpu.amxTile);
  EXPECT_FALSE(cpu.avx512vbmi2);
  EXPECT_EQ(cpu.describe(), "GenuineIntel family 6 model 167 with AVX512-FP16, AMX-TILE (--simd-cpu)");
  ASSERT_TRUE(parseSimdCpu("GenuineIntel:6:106:+vbmi2", cpu, why)) << why;
  EXPECT_TRUE(cpu.avx512vbmi2);
  EXPECT_FALSE(cpu.avx512fp16 || cpu.amxTile);
  EXPECT_EQ(cpu.describe(), "GenuineIntel family 6 model 106 with AVX512-VBMI2 (--simd-cpu)");
  ASSERT_TRUE(parseSimdCpu("GenuineIntel:6:143:+amx-tile,+avx512vbmi2,+avx512fp16,-avx512f", cpu,
                           why))
      << why;
  EXPECT_FALSE(cpu.avx512f);
  EXPECT_TRUE(cpu.amxTile && cpu.avx512vbmi2 && cpu.avx512fp16);
  EXPECT_EQ(cpu.describe(), "GenuineIntel family 6 model 143 without AVX-512, with AVX512-FP16, "
                            "AMX-TILE, AVX512-VBMI2 (--simd-cpu)");
  // The last word on a feature holds; noavx512 within a list.
  ASSERT_TRUE(parseSimdCpu("GenuineIntel:6:143:+amx,-amx,noavx512", cpu, why)) << why;
  EXPECT_FALSE(cpu.amxTile);
  EXPECT_FALSE(cpu.avx512f);
}

// auto's verdict per CPU class: the lanes where they were measured to pay, and for its 3D
// loops the cluster-pair tiles (stop 38) on the Intel CPUs of the lanes only (not on AMD: not
// measured; never where the lanes are refused), for its 2D loops too (stop 43). Since stop 44
// Intel goes by its features: AVX512-FP16 or AMX-TILE (with AVX-512F) whatever the model, the
// models 207 and 143 without them; AVX-512 without them is not measured. Each reason names the
// CPU, and the Intel ones the features or the model that decided.
TEST(SimdCpu, VerdictsWhereMeasuredToPay) {
  struct Case {
    const char* cpu;
    bool lanes, tiles;
    bool tiles2d = false;
    const char* decided = "";  // in the reason
  };
  const Case cases[] = {
      // AMD: Zen 5 and later (stop 33: 0.82-0.86 of a cube step), whatever its features.
      {"AuthenticAMD:26:2", true, false, false, "(AMD Zen 5 and later)"},
      {"AuthenticAMD:27:0", true, false, false, "(AMD Zen 5 and later)"},
      {"AuthenticAMD:26:2:+avx512vbmi2", true, false, false, "(AMD Zen 5 and later)"},
      // Intel by features: Sapphire Rapids-class cores and later, whatever model is reported.
      // Stop 43's VM: model 167 (Rocket Lake's number) on cores with AMX and AVX512-FP16.
      {"GenuineIntel:6:167:+avx512fp16,+amx,+avx512vbmi2", true, true, true,
       "(Intel with AVX-512F and AVX512-FP16 and AMX-TILE: Sapphire Rapids-class"},
      // Emerald Rapids as the hardware reports it (stop 35-42's machine had both features).
      {"GenuineIntel:6:207:+avx512fp16,+amx,+avx512vbmi2", true, true, true,
       "AVX512-FP16 and AMX-TILE"},
      // One of the two is enough (a VM that hides AMX; one that hides FP16); any model, any
      // family (Intel's later families).
      {"GenuineIntel:6:85:+avx512fp16", true, true, true, "(Intel with AVX-512F and AVX512-FP16:"},
      {"GenuineIntel:6:1:+amx", true, true, true, "(Intel with AVX-512F and AMX-TILE:"},
      {"GenuineIntel:19:1:+avx512fp16,+amx", true, true, true, "AVX512-FP16 and AMX-TILE"},
      // Intel by model, the measured exceptions where a VM hides both features.
      {"GenuineIntel:6:207", true, true, true, "(Intel model 207, Emerald Rapids, by its model)"},
      // Model 143 takes the 2D tiles too since stop 44 (measured as GCC 12 builds it,
      // -march=sapphirerapids, on stop 43's VM: 0.885x and 0.72x of the dam breaks' CPU).
      {"GenuineIntel:6:143", true, true, true,
       "(Intel model 143, Sapphire Rapids, by its model)"},
      {"GenuineIntel:6:143:+avx512fp16,+amx", true, true, true, "AVX512-FP16"},
      // Intel AVX-512 without FP16 or AMX: not measured, the scalar loops (Skylake-SP /
      // Cascade Lake 85, Ice Lake-SP 106 with VBMI2, a real Rocket Lake 167).
      {"GenuineIntel:6:85", false, false, false, "neither AVX512-FP16 nor AMX-TILE"},
      {"GenuineIntel:6:106:+avx512vbmi2", false, false, false, "neither AVX512-FP16 nor AMX-TILE"},
      {"GenuineIntel:6:167", false, false, false, "neither AVX512-FP16 nor AMX-TILE"},
      {"GenuineIntel:6:167:+avx512vbmi2", false, false, false, "not measured"},
      // Without AVX-512F GCC 12 does not if-convert the bodies' divisions: no lanes anywhere,
      // whatever else the CPU has.
      {"GenuineIntel:6:207:noavx512", false, false, false, "GCC does not vectorise"},
      {"GenuineIntel:6:167:+avx512fp16,+amx,-avx512f", false, false, false,
       "GCC does not vectorise"},
      {"AuthenticAMD:26:2:noavx512", false, false, false, "GCC does not vectorise"},
      // Not measured.
      {"AuthenticAMD:25:17", false, false, false, "not measured"},  // Zen 4
      {"AuthenticAMD:25:17:+avx512vbmi2", false, false, false, "not measured"},
      {"HygonGenuine:24:0", false, false, false, "not measured"},
      {"HygonGenuine:24:0:+avx512fp16,+amx", false, false, false, "not measured"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.cpu);
    SimdCpu cpu;
    std::string why;
    ASSERT_TRUE(parseSimdCpu(c.cpu, cpu, why)) << why;
    const SimdCpuVerdict v = simdLanesOnCpu(cpu);
    EXPECT_EQ(v.lanes, c.lanes);
    EXPECT_EQ(v.tiles, c.tiles);
    EXPECT_EQ(v.tiles2d, c.tiles2d);
    EXPECT_NE(v.why.find(cpu.describe()), std::string::npos) << v.why;
    EXPECT_NE(v.why.find(c.decided), std::string::npos) << v.why;
    if (v.tiles) EXPECT_NE(v.tilesWhy.find(cpu.describe()), std::string::npos) << v.tilesWhy;
    if (v.tiles) EXPECT_NE(v.tilesWhy.find(c.decided), std::string::npos) << v.tilesWhy;
    EXPECT_EQ(v.tilesWhy.find("in 2D") != std::string::npos, v.tiles2d) << v.tilesWhy;
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

// The leaf-7 features as Linux reads them from cpuid (/proc/cpuinfo's flags avx512_fp16 and
// avx512_vbmi2). AMX-TILE is not compared: the kernel leaves amx_tile out where it cannot save
// the tile state, and sphc reads the CPU's identity, not whether AMX can be used.
TEST(SimdCpu, HostFeaturesAsLinuxReadsThem) {
#if defined(__x86_64__) || defined(__i386__)
  std::ifstream in("/proc/cpuinfo");
  std::string line, flags;
  while (std::getline(in, line))
    if (line.rfind("flags", 0) == 0) {
      flags = line.substr(line.find(':') + 1) + " ";
      break;
    }
  if (flags.empty()) GTEST_SKIP() << "no /proc/cpuinfo flags";
  const SimdCpu cpu = hostSimdCpu();
  EXPECT_EQ(cpu.avx512f, flags.find(" avx512f ") != std::string::npos);
  EXPECT_EQ(cpu.avx512fp16, flags.find(" avx512_fp16 ") != std::string::npos);
  EXPECT_EQ(cpu.avx512vbmi2, flags.find(" avx512_vbmi2 ") != std::string::npos);
  // The host's reason names what it read.
  if (cpu.avx512fp16) EXPECT_NE(cpu.describe().find("AVX512-FP16"), std::string::npos);
#else
  GTEST_SKIP() << "not x86";
#endif
}

}  // namespace
}  // namespace sphc
