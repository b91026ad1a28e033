// --simd-pairs=auto by the CPU the solver is built for (SimdCpu.h).
//
// What was measured (docs/performance-log.md, "SIMD pair loops by the CPU"), CPU per step of the
// lanes against the scalar loops that evaluate each pair once, serial:
//   AMD EPYC Zen 5 (family 0x1A, AVX-512; stop 33): the cube 0.82-0.86, the 3D dam breaks
//     0.86-0.93.
//   Intel Xeon Emerald Rapids (family 6, model 207, AVX-512; stop 35): the cube, dambreak3d
//     and the DualSPHysics scene 1.56-1.60: GCC 12 does not know the model, tunes for
//     `generic`, which has no gathers, and leaves the loop scalar (each pair twice). Forced
//     to gather (-mtune=sapphirerapids) the lanes take 1.00-1.12 of the cube's step and
//     0.85-0.90 of the dam breaks'; the build does not do that (not kept).
//     Since the build allows gathers (buildinfo's simd_flags: -mtune-ctrl=use_gather with
//     GCC; runtime/CMakeLists.txt), the each-pair-once lanes take 0.80-0.82 of the cube's
//     scalar step (idle), 0.91 of dambreak3d's and 0.66 of the DualSPHysics scene's.
//   Without AVX-512 (-march=x86-64-v3) GCC 12 does not vectorise the loops at all: the
//     bodies' divisions under an `if` need masked divisions to be if-converted.
// The rule: the lanes on AMD family 0x1A and later and on Intel family 6 models 207 (Emerald
// Rapids, measured) and 143 (Sapphire Rapids, the same cores), with AVX-512F; the scalar
// loops on other Intel CPUs, without AVX-512F, and on every CPU not measured (the scalar loops
// were the default before stop 33 on every machine).
// The cluster-pair tiles (codegen/ClusterPairs.cpp; docs/performance-log.md, "Cluster-pair tiles
// under OpenMP (stop 38)") for auto's 3D loops each pair once in lanes: on the Intel models of
// the lanes (measured on Emerald Rapids: the cube, the 3D dam break and the DualSPHysics
// scene, serial and OpenMP); not on AMD (not measured: the lanes).
// Stop 42 measured those 3D tiles in GROMACS' 2xMM form too (--cluster-3d-2xmm): no better
// than the 8 x 8 tiles with their row test as one mask, so auto keeps 8 x 8.
#include "codegen/SimdCpu.h"

#include <cstdio>
#include <cstdlib>

#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#endif

namespace sphc {

std::string SimdCpu::describe() const {
  std::string s = vendor.empty() ? std::string("a CPU that is not x86") : vendor;
  if (!vendor.empty())
    s += " family " + std::to_string(family) + " model " + std::to_string(model);
  if (!vendor.empty() && !avx512f) s += " without AVX-512";
  if (!origin.empty()) s += " (" + origin + ")";
  return s;
}

SimdCpu hostSimdCpu() {
  SimdCpu cpu;
  cpu.origin = "this machine";
#if defined(__x86_64__) || defined(__i386__)
  unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
  if (!__get_cpuid(0, &eax, &ebx, &ecx, &edx)) return cpu;
  char v[13];
  for (int i = 0; i < 4; ++i) {
    v[i] = static_cast<char>(ebx >> (8 * i));
    v[4 + i] = static_cast<char>(edx >> (8 * i));
    v[8 + i] = static_cast<char>(ecx >> (8 * i));
  }
  v[12] = 0;
  cpu.vendor = v;
  if (!__get_cpuid(1, &eax, &ebx, &ecx, &edx)) return cpu;
  const int base = (eax >> 8) & 0xf, ext = (eax >> 20) & 0xff;
  const int model = (eax >> 4) & 0xf, extModel = (eax >> 16) & 0xf;
  cpu.family = base == 0xf ? base + ext : base;
  cpu.model = base == 0x6 || base == 0xf ? (extModel << 4) + model : model;
  __builtin_cpu_init();
  cpu.avx512f = __builtin_cpu_supports("avx512f");
#endif
  return cpu;
}

bool parseSimdCpu(const std::string& input, SimdCpu& cpu, std::string& why) {
  const std::string suffix = ":noavx512";
  const bool noAvx512 = input.size() > suffix.size() &&
                        input.compare(input.size() - suffix.size(), suffix.size(), suffix) == 0;
  const std::string text = noAvx512 ? input.substr(0, input.size() - suffix.size()) : input;
  const size_t a = text.find(':'), b = a == std::string::npos ? a : text.find(':', a + 1);
  auto number = [](const std::string& s, int& out) {
    if (s.empty()) return false;
    char* end = nullptr;
    const long v = std::strtol(s.c_str(), &end, 0);
    if (*end || v < 0 || v > 0xffff) return false;
    out = static_cast<int>(v);
    return true;
  };
  SimdCpu c;
  c.origin = "--simd-cpu";
  if (a == 0 || b == std::string::npos || text.find(':', b + 1) != std::string::npos ||
      !number(text.substr(a + 1, b - a - 1), c.family) || !number(text.substr(b + 1), c.model)) {
    why = "it is VENDOR:FAMILY:MODEL as cpuid gives them (GenuineIntel:6:207, "
          "AuthenticAMD:0x1a:2), :noavx512 after them for a CPU without AVX-512F";
    return false;
  }
  c.vendor = text.substr(0, a);
  c.avx512f = !noAvx512;
  cpu = c;
  return true;
}

SimdCpuVerdict simdLanesOnCpu(const SimdCpu& cpu) {
  SimdCpuVerdict v;
  if (!cpu.vendor.empty() && !cpu.avx512f) {
    v.lanes = false;
    v.why = "on " + cpu.describe() + " GCC does not vectorise the loops (no masked divisions "
            "to if-convert the bodies' branches): the scalar loops";
  } else if (cpu.vendor == "AuthenticAMD" && cpu.family >= 0x1a) {
    v.lanes = true;
    v.why = "on " + cpu.describe() + " (AMD Zen 5 and later) the lanes pay";
  } else if (cpu.vendor == "GenuineIntel" && cpu.family == 6 &&
             (cpu.model == 207 || cpu.model == 143 || cpu.model == 167)) {
    // Model 167 (stop 43): a VM whose cores report it (Rocket Lake's number) but have AMX and
    // AVX512-FP16, Sapphire Rapids-class Xeon cores with the model masked. Measured there with
    // the SIMD builds' 512-bit preference (runtime/CMakeLists.txt): the 2D dam break's tiles
    // 0.91x of the scalar loops' CPU, dambreak3d's lanes and tiles 0.74x, the cube's tiles
    // 0.38x (docs/performance-log.md, "512-bit vectors for the SIMD builds; a CPU that
    // reports model 167 (stop 43)").
    v.lanes = true;
    v.why = "on " + cpu.describe() +
            " (Intel Sapphire/Emerald Rapids) the lanes pay with gathers allowed";
    v.tiles = true;
    // 2D (stop 41): the 2xMM tiles reading the particles' arrays beat the scalar loops each
    // pair once on both dam breaks at dx = 0.03 and ~100k particles, the hydrostatic tank,
    // the cavity, the column and the EDAC dam break (measured on model 207), but the dam
    // break's whole run at dx = 0.03 in the tiles fails stability.dambreak_long's bulk pair
    // check (0.45 dx at t = 2.04 s, limit 0.5; the scalar loops 0.72 dx, both with dx one ulp
    // larger 0.66-0.67 dx: the flow's chaos, one realisation), so auto kept the 2D loops
    // scalar until that check was settled (docs/performance-log.md, "2D tiles by default?
    // (stop 41)"). Stop 42 settled it (the re-entry's close pairs are free-surface pairs,
    // which the shift now keeps apart: the 2D stability ctests pass in the tiles), and stop
    // 43 made it the default on model 207 (docs/performance-log.md, "2D tiles by default
    // (stop 43)"): auto takes the 2D loops as --simd-pairs=cluster does. Only there: GCC 12
    // does not know model 207 and tunes for `generic` (512-bit vectors), where the tiles took
    // 0.88x of the own dam break's CPU and 0.70x of the PySPH-effects one's; with a tuning
    // that prefers 256-bit vectors, as GCC 12's -march=native gives model 143 (sapphirerapids),
    // the own dam break's tiles took 1.11x (measured with -mtune=rocketlake and
    // -mtune=sapphirerapids on the same cores): model 143 keeps its 2D loops scalar.
    // With the SIMD builds' -mprefer-vector-width=512 (stop 43) the tuning's preference no
    // longer decides: model 167 takes the 2D tiles too (measured 0.91x, above); model 143's
    // 2D tiles were not measured with it, so it keeps its 2D loops scalar.
    v.tiles2d = cpu.model == 207 || cpu.model == 167;
    // 3D (stop 42): the 2xMM form (the 2D tiles' 4-clusters, here 2 x 2 x 1 lattice cells, 2
    // i's x 4 j's per register) took 0.89x of the 8 x 8 tiles' loop CPU on the cube and
    // 0.87x on the DualSPHysics scene against stop 41's 8 x 8 rows, but with the 8 x 8 rows'
    // test as one compare mask (stop 42) the 8 x 8 tiles' loop is as fast on the cube and
    // 0.985-0.99x of the 2xMM form's on the DualSPHysics scene and dambreak3d (measured on
    // model 207; docs/performance-log.md, "3D tiles in the 2xMM form (stop 42)"): auto keeps
    // 8 x 8 on every CPU; --cluster-3d-2xmm names the 2xMM form.
    v.tilesWhy = "on " + cpu.describe() +
                 " the cluster-pair tiles pay in 3D (serial and OpenMP; stop 38)" +
                 (v.tiles2d ? std::string(" and in 2D (stop 41)") : std::string());
  } else if (cpu.vendor == "GenuineIntel") {
    v.lanes = false;
    v.why = "on " + cpu.describe() + " (Intel) the lanes were not measured to pay: the scalar loops";
  } else {
    v.lanes = false;
    v.why = "on " + cpu.describe() + " the lanes were not measured: the scalar loops";
  }
  return v;
}

}  // namespace sphc
