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
// The rule (stop 44: by features, the models only as measured exceptions): the lanes on AMD
// family 0x1A and later with AVX-512F; on Intel with AVX-512F and AVX512-FP16 or AMX-TILE
// (Sapphire Rapids-class cores and later: every Intel CPU measured to gain has them, model 207
// and stop 43's VM, which reports model 167 on such cores; model 143 has them too, its code
// measured emulated in stop 44), and on Intel family 6 models 207 (Emerald Rapids, measured) and 143 (Sapphire
// Rapids) whatever features a VM shows; the scalar loops on other Intel CPUs (AVX-512 without
// FP16 or AMX: Skylake-SP, Cascade Lake, Ice Lake servers, Rocket Lake; not measured, scalar
// as before), without AVX-512F, and on every CPU not measured (the scalar loops were the
// default before stop 33 on every machine). Before stop 44 the Intel rule went by the models
// 207, 143 and 167 alone: a VM that masks its model took the scalar loops (stop 43's VM, 2-3x
// slower on 3D scenes, until 167 was added), and a real Rocket Lake (model 167, no FP16 or AMX,
// never measured) took the tiles; now the features decide both.
// The cluster-pair tiles (codegen/ClusterPairs.cpp; docs/performance-log.md, "Cluster-pair tiles
// under OpenMP (stop 38)") for auto's 3D loops each pair once in lanes: on the Intel models of
// the lanes (measured on Emerald Rapids: the cube, the 3D dam break and the DualSPHysics
// scene, serial and OpenMP); not on AMD (not measured: the lanes).
// Stop 42 measured those 3D tiles in GROMACS' 2xMM form too (--cluster-3d-2xmm): no better
// than the 8 x 8 tiles with their row test as one mask, so auto keeps 8 x 8.
#include "codegen/SimdCpu.h"

#include <cstdio>
#include <cstdlib>
#include <utility>
#include <vector>

#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#endif

namespace sphc {

std::string SimdCpu::describe() const {
  std::string s = vendor.empty() ? std::string("a CPU that is not x86") : vendor;
  if (!vendor.empty())
    s += " family " + std::to_string(family) + " model " + std::to_string(model);
  if (!vendor.empty() && !avx512f) s += " without AVX-512";
  std::string with;
  for (const auto& [has, name] : {std::pair<bool, const char*>{avx512fp16, "AVX512-FP16"},
                                  {amxTile, "AMX-TILE"},
                                  {avx512vbmi2, "AVX512-VBMI2"}})
    if (has) with += std::string(with.empty() ? "" : ", ") + name;
  if (!with.empty()) s += (avx512f ? " with " : ", with ") + with;
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
  // Leaf 7, sub-leaf 0 (__get_cpuid_count fails where the CPU's highest leaf is below 7).
  if (__get_cpuid_count(7, 0, &eax, &ebx, &ecx, &edx)) {
    cpu.avx512fp16 = (edx >> 23) & 1;
    cpu.amxTile = (edx >> 24) & 1;
    cpu.avx512vbmi2 = (ecx >> 6) & 1;
  }
#endif
  return cpu;
}

bool parseSimdCpu(const std::string& text, SimdCpu& cpu, std::string& why) {
  why = "it is VENDOR:FAMILY:MODEL[:FEATURES] as cpuid gives them (GenuineIntel:6:207, "
        "AuthenticAMD:0x1a:2, GenuineIntel:6:167:+avx512fp16,+amx), FEATURES a comma list of "
        "+F or -F with F one of avx512f, avx512fp16, amx, avx512vbmi2 (without it: AVX-512F "
        "and none of the others; noavx512 is -avx512f)";
  std::vector<std::string> fields;
  for (size_t start = 0;;) {
    const size_t colon = text.find(':', start);
    fields.push_back(text.substr(start, colon == std::string::npos ? colon : colon - start));
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
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
  c.avx512f = true;
  if ((fields.size() != 3 && fields.size() != 4) || fields[0].empty() ||
      !number(fields[1], c.family) || !number(fields[2], c.model))
    return false;
  c.vendor = fields[0];
  if (fields.size() == 4) {
    if (fields[3].empty()) return false;
    for (size_t start = 0;;) {
      const size_t comma = fields[3].find(',', start);
      const std::string item =
          fields[3].substr(start, comma == std::string::npos ? comma : comma - start);
      const std::string name = item.size() > 1 ? item.substr(1) : std::string();
      bool* flag = name == "avx512f"                       ? &c.avx512f
                   : name == "avx512fp16"                  ? &c.avx512fp16
                   : name == "amx" || name == "amx-tile"   ? &c.amxTile
                   : name == "avx512vbmi2" || name == "vbmi2" ? &c.avx512vbmi2
                                                           : nullptr;
      if (item == "noavx512")
        c.avx512f = false;
      else if (flag && (item[0] == '+' || item[0] == '-'))
        *flag = item[0] == '+';
      else
        return false;
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
  why.clear();
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
  } else if (cpu.vendor == "GenuineIntel" &&
             (cpu.avx512fp16 || cpu.amxTile ||
              (cpu.family == 6 && (cpu.model == 207 || cpu.model == 143)))) {
    // By features (stop 44): AVX-512F with AVX512-FP16 or AMX-TILE is a Sapphire Rapids-class
    // core or later (Golden Cove and later server cores), whatever model a VM reports. Stop 43's VM reports model 167 (Rocket Lake's number) on such cores
    // (AMX, AVX512-FP16): measured there with the SIMD builds' 512-bit preference
    // (runtime/CMakeLists.txt), the 2D dam break's tiles 0.91x of the scalar loops' CPU,
    // dambreak3d's lanes and tiles 0.74x, the cube's tiles 0.38x (docs/performance-log.md,
    // "512-bit vectors for the SIMD builds; a CPU that reports model 167 (stop 43)").
    // By model, the measured exceptions: 207 (Emerald Rapids, stops 35-42's machine) and 143
    // (Sapphire Rapids), the same verdict where a VM hides FP16 and AMX (some hide AMX, whose
    // tile state the hypervisor must save).
    const bool byFeatures = cpu.avx512fp16 || cpu.amxTile;
    std::string decided;
    if (byFeatures) {
      decided = std::string("Intel with AVX-512F and ") +
                (cpu.avx512fp16 && cpu.amxTile ? "AVX512-FP16 and AMX-TILE"
                 : cpu.avx512fp16             ? "AVX512-FP16"
                                              : "AMX-TILE") +
                ": Sapphire Rapids-class cores or later, whatever the model";
    } else {
      decided = cpu.model == 207 ? "Intel model 207, Emerald Rapids, by its model"
                                 : "Intel model 143, Sapphire Rapids, by its model";
    }
    v.lanes = true;
    v.why = "on " + cpu.describe() + " (" + decided + ") the lanes pay with gathers allowed";
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
    // (stop 43)"): auto takes the 2D loops as --simd-pairs=cluster does. GCC 12 does not know
    // model 207 and tunes for `generic` (512-bit vectors), where the tiles took 0.88x of the own
    // dam break's CPU and 0.70x of the PySPH-effects one's; with a tuning that prefers 256-bit
    // vectors, as GCC 12's -march=native gives model 143 (sapphirerapids) and stop 43's VM
    // (rocketlake), the own dam break's tiles took 1.10-1.11x. With the SIMD builds'
    // -mprefer-vector-width=512 (stop 43) the tuning's preference no longer decides: stop 43's
    // VM took 0.91x, and stop 44 measured a model-143 build (emulated on that VM's cores:
    // -march=sapphirerapids, the SIMD flags as sphc adds them): the own dam break's tiles
    // 0.885x of the scalar loops' CPU, the PySPH-effects one's 0.72x, the cube's 3D tiles
    // 0.52x; the same build without the 512-bit preference lost again (docs/performance-log.md,
    // "The verdict by features; model 143 emulated (stop 44)"). So every CPU of this verdict
    // takes the 2D tiles.
    v.tiles2d = true;
    // 3D (stop 42): the 2xMM form (the 2D tiles' 4-clusters, here 2 x 2 x 1 lattice cells, 2
    // i's x 4 j's per register) took 0.89x of the 8 x 8 tiles' loop CPU on the cube and
    // 0.87x on the DualSPHysics scene against stop 41's 8 x 8 rows, but with the 8 x 8 rows'
    // test as one compare mask (stop 42) the 8 x 8 tiles' loop is as fast on the cube and
    // 0.985-0.99x of the 2xMM form's on the DualSPHysics scene and dambreak3d (measured on
    // model 207; docs/performance-log.md, "3D tiles in the 2xMM form (stop 42)"): auto keeps
    // 8 x 8 on every CPU; --cluster-3d-2xmm names the 2xMM form.
    v.tilesWhy = "on " + cpu.describe() + " (" + decided + ")" +
                 " the cluster-pair tiles pay in 3D (serial and OpenMP; stop 38)" +
                 (v.tiles2d ? std::string(" and in 2D (stop 41)") : std::string());
  } else if (cpu.vendor == "GenuineIntel") {
    // AVX-512F without AVX512-FP16 or AMX-TILE: Skylake-SP, Cascade Lake, Cooper Lake, Ice
    // Lake servers, Rocket Lake, Tiger Lake: never measured, the scalar loops as before stop 44
    // (but a real Rocket Lake, model 167, which took the tiles by stop 43's model rule).
    v.lanes = false;
    v.why = "on " + cpu.describe() +
            " (Intel with AVX-512F but neither AVX512-FP16 nor AMX-TILE: Skylake-SP to Ice Lake "
            "servers, not measured) the lanes were not measured to pay: the scalar loops";
  } else {
    v.lanes = false;
    v.why = "on " + cpu.describe() + " the lanes were not measured: the scalar loops";
  }
  return v;
}

}  // namespace sphc
