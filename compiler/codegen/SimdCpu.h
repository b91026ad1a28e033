// --simd-pairs=auto by the CPU the solver is built for (codegen/SimdCpu.cpp).
//
// The solvers are built with -march=native (runtime/CMakeLists.txt, SPHC_SCENE_CXXFLAGS), so
// the CPU that runs sphc is the one the solver's code is compiled for: sphc reads its cpuid
// (vendor, family, model) and puts the pair loops in SIMD lanes only on a CPU class where
// the lanes were measured to pay (docs/performance-log.md, "SIMD pair loops by the CPU").
// Since stop 44 the Intel verdict goes by the CPU's features (cpuid leaf 7: AVX512-FP16,
// AMX-TILE), the model numbers only as measured exceptions: a VM may report another model
// than its cores' (stop 43's VM: model 167, Rocket Lake's number, on Sapphire Rapids-class
// cores). `sphc --simd-cpu=VENDOR:FAMILY:MODEL[:FEATURES]` names another CPU (the lit tests; a
// solver built for another machine's CPU with --cxxflags); --simd-pairs=on|off override the
// choice.
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
  // cpuid leaf 7 (sub-leaf 0): the features that tell Sapphire Rapids-class Intel cores and
  // later (Golden Cove and later server cores) from earlier AVX-512 Xeons, whatever model
  // number a VM reports: AVX512-FP16 (EDX bit 23) and AMX-TILE (EDX bit 24). AVX512-VBMI2
  // (ECX bit 6; Ice Lake and later, --cluster-queue's compress) is read and named but decides
  // nothing (Ice Lake servers have it too).
  bool avx512fp16 = false;
  bool amxTile = false;
  bool avx512vbmi2 = false;
  std::string origin;  // "this machine" or "--simd-cpu"
  // "GenuineIntel family 6 model 207 (this machine)"; with the leaf-7 features it has,
  // "GenuineIntel family 6 model 167 with AVX512-FP16, AMX-TILE, AVX512-VBMI2 (this machine)".
  std::string describe() const;
};

// The CPU sphc runs on (cpuid; on other architectures an empty vendor).
SimdCpu hostSimdCpu();
// `VENDOR:FAMILY:MODEL[:FEATURES]` (decimal or 0x hex numbers), e.g. GenuineIntel:6:207,
// AuthenticAMD:0x1a:2, GenuineIntel:6:167:+avx512fp16,+amx. FEATURES is a comma list of +F or
// -F, F one of avx512f, avx512fp16, amx (or amx-tile), avx512vbmi2 (or vbmi2); without it the
// CPU has AVX-512F and none of the others; `noavx512` (the form before stop 44) is -avx512f.
// False and why if the text is not of that form.
bool parseSimdCpu(const std::string& text, SimdCpu& cpu, std::string& why);

// Whether the SIMD lanes of --simd-pairs=auto pay on `cpu`, and why (measured, or the
// scalar loops where not measured): the reason names the CPU, its features and the class
// they put it in (SimdCpu.cpp).
struct SimdCpuVerdict {
  bool lanes = true;
  std::string why;
  // Whether auto prints the 3D loops it puts each pair once in lanes as cluster-pair tiles
  // (codegen/ClusterPairs.cpp) on `cpu`, and why: where the tiles were measured to pay.
  bool tiles = false;
  std::string tilesWhy;
  // Whether auto also puts the 2D loops each pair once over their own array in the tiles
  // (GROMACS' 2xMM form; stop 41), where `tiles` holds: measured to pay on those CPUs (stop
  // 43: models 207 and 167 with FP16 and AMX; stop 44: a model 143 build, emulated).
  bool tiles2d = false;
};
SimdCpuVerdict simdLanesOnCpu(const SimdCpu& cpu);

}  // namespace sphc
