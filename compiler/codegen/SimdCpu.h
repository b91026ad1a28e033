// --simd-pairs=auto by the CPU the solver is built for (codegen/SimdCpu.cpp).
//
// The solvers are built with -march=native (runtime/CMakeLists.txt, SPHC_SCENE_CXXFLAGS), so
// the CPU that runs sphc is the one the solver's code is compiled for: sphc reads its cpuid
// (vendor, family, model) and puts the pair loops in SIMD lanes only on a CPU class where
// the lanes were measured to pay (docs/performance-log.md, "SIMD pair loops by the CPU").
// `sphc --simd-cpu=VENDOR:FAMILY:MODEL` names another CPU (the lit tests; a solver built for
// another machine's CPU with --cxxflags); --simd-pairs=on|off override the choice.
#pragma once

#include <string>

namespace sphc {

struct SimdCpu {
  std::string vendor;  // cpuid leaf 0: GenuineIntel, AuthenticAMD, ...; "" if not x86
  int family = -1;     // cpuid leaf 1, with the extended family (AMD 0x1A = 26: Zen 5)
  int model = -1;      // with the extended model (Intel 207: Emerald Rapids)
  // AVX-512F (and the OS saving zmm registers): without its masked divisions GCC 12 does not
  // if-convert the bodies' and kernel's divisions under an `if`, and the loop stays scalar.
  bool avx512f = false;
  std::string origin;  // "this machine" or "--simd-cpu"
  // "GenuineIntel family 6 model 207 (this machine)".
  std::string describe() const;
};

// The CPU sphc runs on (cpuid; on other architectures an empty vendor).
SimdCpu hostSimdCpu();
// `VENDOR:FAMILY:MODEL[:noavx512]` (decimal or 0x hex numbers), e.g. GenuineIntel:6:207,
// AuthenticAMD:0x1a:2 (with AVX-512F unless :noavx512); false and why if it is not of that
// form.
bool parseSimdCpu(const std::string& text, SimdCpu& cpu, std::string& why);

// Whether the SIMD lanes of --simd-pairs=auto pay on `cpu`, and why (measured, or the
// scalar loops where not measured).
struct SimdCpuVerdict {
  bool lanes = true;
  std::string why;
  // Whether auto prints the 3D loops it puts each pair once in lanes as cluster-pair tiles
  // (codegen/ClusterPairs.cpp) on `cpu`, and why: where the tiles were measured to pay.
  bool tiles = false;
  std::string tilesWhy;
  // Whether auto also puts the 2D loops each pair once over their own array in the tiles
  // (GROMACS' 2xMM form; stop 41), where `tiles` holds: measured to pay on this CPU's model.
  bool tiles2d = false;
};
SimdCpuVerdict simdLanesOnCpu(const SimdCpu& cpu);

}  // namespace sphc
