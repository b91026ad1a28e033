#include "driver/Build.h"

#include "llvm/ADT/SmallString.h"
#include "llvm/ADT/StringExtras.h"
#include "llvm/ADT/StringMap.h"
#include "llvm/Support/FileSystem.h"
#include "llvm/Support/MemoryBuffer.h"
#include "llvm/Support/Path.h"
#include "llvm/Support/Process.h"
#include "llvm/Support/Program.h"
#include "llvm/Support/Host.h"
#include "llvm/Support/SHA1.h"
#include "llvm/Support/raw_ostream.h"

#include <chrono>
#include <cstdlib>
#include <map>

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
  sha.update(cxx + "\n" + flags + "\n" + libs);
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
  std::string logFile = std::string(dir) + "/build." + pid + ".log";
  {
    llvm::raw_fd_ostream os(cppFile, ec);
    if (ec) {
      res.message = "cannot write '" + cppFile + "': " + ec.message();
      return finish(false);
    }
    os << req.cpp;
  }
  std::string tmpExe = cachedExe + "." + pid + ".tmp";
  std::vector<std::string> args;
  auto cxxPath = llvm::sys::findProgramByName(cxx);
  if (!cxxPath) {
    res.message = "cannot find the C++ compiler '" + cxx + "' (set it with --cxx)";
    return finish(false);
  }
  args.push_back(*cxxPath);
  llvm::SmallVector<llvm::StringRef, 16> parts;
  llvm::StringRef(flags).split(parts, ' ', -1, false);
  for (auto p : parts) args.push_back(p.str());
  args.push_back("-I" + install.includeDir);
  args.push_back(cppFile);
  if (req.mpi) args.push_back(mpiLib);
  args.push_back(runtimeLib);
  parts.clear();
  llvm::StringRef(libs).split(parts, ' ', -1, false);
  for (auto p : parts) args.push_back(p.str());
  args.push_back("-o");
  args.push_back(tmpExe);
  if (req.verbose) {
    for (const auto& a : args) llvm::errs() << a << " ";
    llvm::errs() << "\n";
  }
  std::vector<llvm::StringRef> argRefs(args.begin(), args.end());
  llvm::Optional<llvm::StringRef> redirects[] = {llvm::None, llvm::StringRef(logFile),
                                                 llvm::StringRef(logFile)};
  std::string execErr;
  int rc = llvm::sys::ExecuteAndWait(args[0], argRefs, llvm::None, redirects, 0, 0, &execErr);
  if (rc != 0) {
    std::string log;
    if (auto buf = llvm::MemoryBuffer::getFile(logFile)) log = (*buf)->getBuffer().str();
    if (log.size() > 4000) log = log.substr(0, 4000) + "\n...";
    res.message = "the generated C++ did not compile (" +
                  (execErr.empty() ? "exit code " + std::to_string(rc) : execErr) +
                  "); generated code: " + cppFile + ", log: " + logFile + "\n" + log;
    return finish(false);
  }
  if (auto e = fs::rename(tmpExe, cachedExe)) {
    res.message = "cannot move the built executable into the cache: " + e.message();
    return finish(false);
  }
  // Kept beside the executable for people who want to read what was built.
  fs::rename(cppFile, std::string(dir) + "/scene.cpp");
  fs::remove(logFile);
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
