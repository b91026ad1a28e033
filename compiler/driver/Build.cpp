#include "driver/Build.h"

#include "codegen/CppEmitter.h"

#include "llvm/ADT/SmallString.h"
#include "llvm/ADT/StringExtras.h"
#include "llvm/ADT/StringMap.h"
#include "llvm/Support/FileSystem.h"
#include "llvm/Support/Format.h"
#include "llvm/Support/MemoryBuffer.h"
#include "llvm/Support/Path.h"
#include "llvm/Support/Process.h"
#include "llvm/Support/Program.h"
#include "llvm/Support/Host.h"
#include "llvm/Support/SHA1.h"
#include "llvm/Support/raw_ostream.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <map>
#include <thread>

namespace sphc {

namespace fs = llvm::sys::fs;
namespace path = llvm::sys::path;

Install locateInstall(const char* argv0) {
  static int anchor;
  std::string exe = fs::getMainExecutable(argv0, &anchor);
  llvm::SmallString<256> prefix(exe);
  path::remove_filename(prefix);  // bin/
  path::remove_filename(prefix);  // <prefix>
  Install in;
  in.prefix = std::string(prefix);
  auto join = [&](std::initializer_list<const char*> parts) {
    llvm::SmallString<256> p(prefix);
    for (const char* s : parts) path::append(p, s);
    return std::string(p);
  };
  in.includeDir = join({"include"});
  in.libDir = join({"lib"});
  in.stdlibDir = join({"share", "sphc", "stdlib"});
  in.buildInfo = join({"share", "sphc", "buildinfo.txt"});
  return in;
}

std::string cacheDirectory() {
  if (const char* d = std::getenv("SPHC_CACHE_DIR")) return d;
  if (const char* x = std::getenv("XDG_CACHE_HOME")) return std::string(x) + "/sphc";
  if (const char* h = std::getenv("HOME")) return std::string(h) + "/.cache/sphc";
  return ".sphc-cache";
}

namespace {

std::map<std::string, std::string> readBuildInfo(const std::string& file, std::string& err) {
  std::map<std::string, std::string> info;
  auto buf = llvm::MemoryBuffer::getFile(file);
  if (!buf) {
    err = "cannot read '" + file + "': " + buf.getError().message() +
          " (is sphc installed or run from its build tree?)";
    return info;
  }
  llvm::SmallVector<llvm::StringRef, 8> lines;
  (*buf)->getBuffer().split(lines, '\n', -1, false);
  for (auto l : lines) {
    auto [k, v] = l.split('=');
    info[k.trim().str()] = v.trim().str();
  }
  return info;
}

void addFileToHash(llvm::SHA1& h, const std::string& file) {
  if (auto buf = llvm::MemoryBuffer::getFile(file)) h.update((*buf)->getBuffer());
  h.update(file);
}

bool writeFile(const std::string& file, const std::string& text, std::string& message) {
  std::error_code ec;
  llvm::raw_fd_ostream os(file, ec);
  if (ec) {
    message = "cannot write '" + file + "': " + ec.message();
    return false;
  }
  os << text;
  return true;
}

// The generated code's translation units. A CPU solver's phases (the pair loops) are defined
// out of struct Scene between two marker lines (codegen/HostProgram.cpp, unless
// --single-unit): one unit is the code before the end marker (the declarations and the
// phases), the other the code without the phases (the rest of the scene and main), each
// compiled on its own, in parallel. The file as a whole is one valid unit too (--emit=cpp).
std::vector<std::string> splitUnits(const std::string& cpp) {
  const std::size_t begin = cpp.find(std::string("\n") + kPhasesBeginMarker);
  const std::size_t end = cpp.find(std::string("\n") + kPhasesEndMarker);
  if (begin == std::string::npos || end == std::string::npos || end < begin) return {cpp};
  // Compiler messages about the code after the phases name the lines of the whole file
  // (the build keeps it as scene.cpp).
  const long line = 2 + std::count(cpp.begin(), cpp.begin() + end, '\n');
  return {cpp.substr(0, end + 1),
          cpp.substr(0, begin + 1) + "#line " + std::to_string(line) + " \"scene.cpp\"\n" +
              cpp.substr(end + 1)};
}

// The flags of a build with pair loops in SIMD lanes: buildinfo's simd_flags for its own
// compiler (GCC: -mtune-ctrl=use_gather too), -fopenmp-simd for another (--cxx) or an older
// buildinfo.
std::string simdFlags(std::map<std::string, std::string>& info, const std::string& cxx) {
  return cxx == info["cxx"] && info.count("simd_flags") && !info["simd_flags"].empty()
             ? info["simd_flags"]
             : "-fopenmp-simd";
}

// Whether the build can use the precompiled runtime headers: buildinfo's compiler and
// default flags (plus the OpenMP flag), a serial or OpenMP solver, and the .gch in place.
bool usesDefaultFlags(std::map<std::string, std::string>& info, const std::string& cxx,
                      const std::string& flags, const BuildRequest& req) {
  if (cxx != info["cxx"] || req.mpi) return false;
  std::string expected = info["cxxflags"];
  if (req.backend == "openmp")
    expected += " " + (info.count("openmp_flags") ? info["openmp_flags"] : "-fopenmp");
  else if (req.backend != "serial")
    return false;
  if (req.simd) expected += " " + simdFlags(info, cxx);  // --simd-pairs
  return flags == expected;
}
bool usesScenePch(const Install& install, std::map<std::string, std::string>& info,
                  const std::string& cxx, const std::string& flags, const BuildRequest& req) {
  return usesDefaultFlags(info, cxx, flags, req) &&
         fs::exists(install.includeDir + "/sphc/scene_pch.h.gch/" + req.backend + ".gch");
}

}  // namespace

BuildResult buildExecutable(const Install& install, const BuildRequest& req) {
  auto start = std::chrono::steady_clock::now();
  BuildResult res;
  std::string err;
  auto info = readBuildInfo(install.buildInfo, err);
  if (!err.empty()) {
    res.message = err;
    return res;
  }
  std::string cxx = req.cxx.empty() ? info["cxx"] : req.cxx;
  std::string flags = req.cxxflags.empty() ? info["cxxflags"] : req.cxxflags;
  std::string libs = info["libs"];
  std::string runtimeLib = install.libDir + "/libsphc_runtime.a";
  if (req.backend == "openmp") {
    // The OpenMP runtime library and the compiler's OpenMP flag (compile and link).
    runtimeLib = install.libDir + "/libsphc_runtime_omp.a";
    std::string omp = info.count("openmp_flags") ? info["openmp_flags"] : "-fopenmp";
    flags += " " + omp;
    libs += " " + omp;
  } else if (req.backend == "opencl") {
    // The OpenCL runtime library and the ICD loader (kernels are built when the solver runs).
    runtimeLib = install.libDir + "/libsphc_runtime_ocl.a";
    flags += " " + (info.count("opencl_flags") ? info["opencl_flags"]
                                                : std::string("-DCL_TARGET_OPENCL_VERSION=120"));
    libs += " " + info["opencl_libs"];
  }
  // --simd-pairs: the pair loops' `#pragma omp simd` (codegen/SimdPairs.cpp), with GCC
  // gathers allowed (buildinfo's simd_flags; runtime/CMakeLists.txt says why).
  if (req.simd) flags += " " + simdFlags(info, cxx);
  // --mpi: libsphc_mpi (before the runtime it uses), MPI and Zoltan.
  const std::string mpiLib = install.libDir + "/libsphc_mpi.a";
  if (req.mpi) {
    flags += " " + info["mpi_flags"];
    // Parallel HDF5 in place of the serial library (collective output), where found.
    const std::string base = info["mpi_base_libs"];
    if (!base.empty() && libs.compare(0, info["libs"].size(), info["libs"]) == 0)
      libs = base + libs.substr(info["libs"].size());
    libs = info["mpi_libs"] + " " + libs;
  }

  // The key: generated code, compiler, flags, libraries, the runtime library and headers.
  llvm::SHA1 sha;
  sha.update(req.cpp);
  // The linker option of buildinfo (link_flags: -fuse-ld=gold where CMake found it), with its
  // compiler only.
  const std::string linkerFlags = cxx == info["cxx"] ? info["link_flags"] : "";
  // Split units with the default flags: the unit without the phases and the time step (set-up,
  // output, main: code that runs once or at outputs) is compiled at -Og (cold_flags, which
  // GCC's precompiled header accepts); the phases' unit keeps the default flags.
  const std::string coldFlags =
      usesDefaultFlags(info, cxx, flags, req) ? info["cold_flags"] : "";
  sha.update(cxx + "\n" + flags + "\n" + libs);
  if (!linkerFlags.empty() || !coldFlags.empty())
    sha.update("\n" + linkerFlags + "\n" + coldFlags);
  addFileToHash(sha, runtimeLib);
  std::error_code ec;
  std::vector<std::string> headers;
  for (fs::directory_iterator it(install.includeDir + "/sphc", ec), end; it != end && !ec;
       it.increment(ec))
    headers.push_back(it->path());
  std::sort(headers.begin(), headers.end());
  for (const auto& hdr : headers) addFileToHash(sha, hdr);
  if (req.mpi) {
    addFileToHash(sha, mpiLib);
    for (fs::directory_iterator it(install.includeDir + "/sphc/mpi", ec), end; it != end && !ec;
         it.increment(ec))
      addFileToHash(sha, it->path());
  }
  // -march=native builds for this machine's CPU: a cache directory shared by machines with
  // other CPUs must not hand out a binary built for another instruction set.
  if (flags.find("-march=native") != std::string::npos) {
    sha.update(llvm::sys::getHostCPUName());
    llvm::StringMap<bool> features;
    if (llvm::sys::getHostCPUFeatures(features)) {
      std::vector<std::string> on;
      for (const auto& f : features)
        if (f.second) on.push_back(f.first().str());
      std::sort(on.begin(), on.end());
      for (const auto& f : on) sha.update(f + ",");
    }
  }
  std::string key = llvm::toHex(sha.final()).substr(0, 24);

  llvm::SmallString<256> dir(cacheDirectory());
  path::append(dir, key);
  std::string cachedExe = std::string(dir) + "/scene";
  auto finish = [&](bool ok) {
    res.ok = ok;
    res.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return res;
  };
  auto deliver = [&]() {
    fs::remove(req.output);
    if (auto e = fs::copy_file(cachedExe, req.output)) {
      res.message = "cannot write '" + req.output + "': " + e.message();
      return finish(false);
    }
    fs::setPermissions(req.output, fs::all_read | fs::all_exe | fs::owner_write);
    return finish(true);
  };
  if (req.useCache && fs::can_execute(cachedExe)) {
    res.cached = true;
    return deliver();
  }
  if (auto e = fs::create_directories(dir)) {
    res.message = "cannot create the cache directory '" + std::string(dir) + "': " + e.message();
    return finish(false);
  }
  // Per-process names: two sphc runs building the same scene at once (parallel tests, make -j)
  // must not write each other's files. The finished executable is renamed into place, which
  // is atomic, so a reader sees either no cached build or a whole one.
  const std::string pid = std::to_string(llvm::sys::Process::getProcessId());
  std::string cppFile = std::string(dir) + "/scene." + pid + ".cpp";
  if (!writeFile(cppFile, req.cpp, res.message)) return finish(false);
  std::string tmpExe = cachedExe + "." + pid + ".tmp";
  auto cxxPath = llvm::sys::findProgramByName(cxx);
  if (!cxxPath) {
    res.message = "cannot find the C++ compiler '" + cxx + "' (set it with --cxx)";
    return finish(false);
  }
  std::vector<std::string> compile{*cxxPath};
  llvm::SmallVector<llvm::StringRef, 16> parts;
  llvm::StringRef(flags).split(parts, ' ', -1, false);
  for (auto p : parts) compile.push_back(p.str());
  std::vector<std::string> linkFlags = compile;  // the compiler and flags (-fopenmp)
  std::vector<std::string> linker;                 // -fuse-ld=gold
  parts.clear();
  llvm::StringRef(linkerFlags).split(parts, ' ', -1, false);
  for (auto p : parts) linker.push_back(p.str());
  linkFlags.insert(linkFlags.end(), linker.begin(), linker.end());
  compile.push_back("-I" + install.includeDir);
  // The precompiled runtime headers (sphc/scene_pch.h.gch/<backend>.gch, built with the
  // default flags by runtime/CMakeLists.txt): only for a build with buildinfo's compiler and
  // flags. GCC checks the rest (CPU, macros) and parses the header where the .gch does not fit.
  if (usesScenePch(install, info, cxx, flags, req)) {
    compile.push_back("-include");
    compile.push_back("sphc/scene_pch.h");
  }
  std::vector<std::string> link;
  if (req.mpi) link.push_back(mpiLib);
  link.push_back(runtimeLib);
  parts.clear();
  llvm::StringRef(libs).split(parts, ' ', -1, false);
  for (auto p : parts) link.push_back(p.str());
  link.push_back("-o");
  link.push_back(tmpExe);

  // One or two translation units (splitUnits): two are compiled at once, then linked.
  const std::vector<std::string> units = splitUnits(req.cpp);
  std::vector<std::string> logs, tmpFiles;
  std::vector<std::vector<std::string>> commands;
  if (units.size() == 1) {
    std::vector<std::string> args = compile;
    args.insert(args.end(), linker.begin(), linker.end());
    args.push_back(cppFile);
    args.insert(args.end(), link.begin(), link.end());
    commands.push_back(args);
    logs.push_back(std::string(dir) + "/build." + pid + ".log");
  } else {
    std::vector<std::string> linkArgs = linkFlags;
    for (std::size_t k = 0; k < units.size(); ++k) {
      const std::string base = std::string(dir) + "/scene." + pid + ".unit" + std::to_string(k);
      if (!writeFile(base + ".cpp", units[k], res.message)) return finish(false);
      std::vector<std::string> args = compile;
      if (k == 1 && !coldFlags.empty()) {
        llvm::SmallVector<llvm::StringRef, 4> cold;
        llvm::StringRef(coldFlags).split(cold, ' ', -1, false);
        for (auto c : cold) args.push_back(c.str());
      }
      args.insert(args.end(), {"-c", base + ".cpp", "-o", base + ".o"});
      commands.push_back(args);
      logs.push_back(base + ".log");
      tmpFiles.insert(tmpFiles.end(), {base + ".cpp", base + ".o"});
      linkArgs.push_back(base + ".o");
    }
    linkArgs.insert(linkArgs.end(), link.begin(), link.end());
    commands.push_back(linkArgs);
    logs.push_back(std::string(dir) + "/link." + pid + ".log");
  }
  auto failed = [&](std::size_t k, const std::string& why) {
    std::string log;
    if (auto buf = llvm::MemoryBuffer::getFile(logs[k])) log = (*buf)->getBuffer().str();
    if (log.size() > 4000) log = log.substr(0, 4000) + "\n...";
    res.message = "the generated C++ did not compile (" + why + "); generated code: " + cppFile +
                  ", log: " + logs[k] + "\n" + log;
    return finish(false);
  };
  if (req.verbose)
    for (const auto& c : commands) {
      for (const auto& a : c) llvm::errs() << a << " ";
      llvm::errs() << "\n";
    }
  // The compiles (all but the link when there are units) run at once; the link after them.
  const std::size_t nCompiles = units.size() == 1 ? 1 : units.size();
  std::vector<std::vector<llvm::StringRef>> argRefs;
  for (const auto& c : commands) argRefs.emplace_back(c.begin(), c.end());
  std::vector<llvm::sys::ProcessInfo> running;
  for (std::size_t k = 0; k < nCompiles; ++k) {
    llvm::Optional<llvm::StringRef> redirects[] = {llvm::None, llvm::StringRef(logs[k]),
                                                   llvm::StringRef(logs[k])};
    std::string execErr;
    running.push_back(llvm::sys::ExecuteNoWait(commands[k][0], argRefs[k], llvm::None,
                                               redirects, 0, &execErr));
    if (running.back().Pid == llvm::sys::ProcessInfo::InvalidPid) {
      for (std::size_t j = 0; j + 1 < running.size(); ++j)
        llvm::sys::Wait(running[j], 0, /*WaitUntilTerminates=*/true);
      return failed(k, execErr);
    }
  }
  // -v: each process's CPU time (the compiler's own processes included), when it ended.
  auto report = [&](std::size_t k, const llvm::Optional<llvm::sys::ProcessStatistics>& stat) {
    if (!req.verbose || !stat) return;
    const std::string what = commands.size() == 1 ? "compile and link"
                             : k + 1 == commands.size() ? "link"
                                                        : "unit" + std::to_string(k);
    auto secs = [](std::chrono::microseconds us) { return us.count() / 1e6; };
    llvm::errs() << "sphc: " << what << " done at "
                 << llvm::format("%.3f", std::chrono::duration<double>(
                                             std::chrono::steady_clock::now() - start)
                                             .count())
                 << " s (CPU " << llvm::format("%.2f", secs(stat->TotalTime)) << " s, user "
                 << llvm::format("%.2f", secs(stat->UserTime)) << " s)\n";
  };
  int firstFailure = -1;
  std::string why;
  // Polled (not waited for in order) so that -v tells when each one ended.
  std::vector<bool> ended(running.size(), false);
  for (std::size_t left = running.size(); left > 0;) {
    for (std::size_t k = 0; k < running.size(); ++k) {
      if (ended[k]) continue;
      std::string execErr;
      llvm::Optional<llvm::sys::ProcessStatistics> stat;
      auto done = llvm::sys::Wait(running[k], 0, /*WaitUntilTerminates=*/false, &execErr, &stat);
      if (done.Pid == 0) continue;  // still running
      ended[k] = true;
      --left;
      report(k, stat);
      if (done.ReturnCode != 0 && firstFailure < 0) {
        firstFailure = static_cast<int>(k);
        why = execErr.empty() ? "exit code " + std::to_string(done.ReturnCode) : execErr;
      }
    }
    if (left > 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (firstFailure >= 0) return failed(firstFailure, why);
  if (commands.size() > nCompiles) {
    const std::size_t k = commands.size() - 1;
    llvm::Optional<llvm::StringRef> redirects[] = {llvm::None, llvm::StringRef(logs[k]),
                                                   llvm::StringRef(logs[k])};
    std::string execErr;
    llvm::Optional<llvm::sys::ProcessStatistics> stat;
    int rc = llvm::sys::ExecuteAndWait(commands[k][0], argRefs[k], llvm::None, redirects, 0, 0,
                                       &execErr, nullptr, &stat);
    report(k, stat);
    if (rc != 0) return failed(k, execErr.empty() ? "exit code " + std::to_string(rc) : execErr);
  }
  for (const auto& f : tmpFiles) fs::remove(f);
  for (const auto& l : logs) fs::remove(l);
  if (auto e = fs::rename(tmpExe, cachedExe)) {
    res.message = "cannot move the built executable into the cache: " + e.message();
    return finish(false);
  }
  // Kept beside the executable for people who want to read what was built.
  fs::rename(cppFile, std::string(dir) + "/scene.cpp");
  return deliver();
}

namespace {

// Whether this build of sphc has an optional runtime: CMake found what it needs (buildinfo.txt's
// `key` is set; else `why` is `notFound`) and its library `lib` (of `what`: MPI, OpenCL) is in
// place.
bool optionalRuntime(const Install& install, const char* key, const char* notFound,
                     const char* what, const char* lib, std::string& why) {
  std::string err;
  auto info = readBuildInfo(install.buildInfo, err);
  if (!err.empty()) {
    why = err;
    return false;
  }
  if (info[key].empty()) {
    why = notFound;
    return false;
  }
  const std::string path = install.libDir + "/" + lib;
  if (!fs::exists(path)) {
    why = std::string("the ") + what + " runtime library '" + path + "' is missing";
    return false;
  }
  return true;
}

}  // namespace

bool mpiAvailable(const Install& install, std::string& why) {
  return optionalRuntime(
      install, "mpi_libs",
      "CMake did not find MPI and Zoltan when sphc was built (scripts/setup-deps.sh "
      "installs them: libopenmpi-dev openmpi-bin libtrilinos-zoltan-dev; then reconfigure)",
      "MPI", "libsphc_mpi.a", why);
}

bool openclAvailable(const Install& install, std::string& why) {
  return optionalRuntime(
      install, "opencl_libs",
      "CMake did not find OpenCL when sphc was built (install an OpenCL loader and "
      "headers, e.g. ocl-icd-opencl-dev opencl-headers, plus a driver such as "
      "pocl-opencl-icd, and reconfigure)",
      "OpenCL", "libsphc_runtime_ocl.a", why);
}

}  // namespace sphc
