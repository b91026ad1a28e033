// Building generated C++ into an executable, with a content-hash cache: an unchanged scene
// (same generated code, compiler, flags and runtime) is not compiled again.
#pragma once

#include <string>

namespace sphc {

// Where sphc's own files are: found relative to the sphc executable (<prefix>/bin/sphc).
struct Install {
  std::string prefix;
  std::string includeDir;   // <prefix>/include       (holds sphc/*.h)
  std::string libDir;       // <prefix>/lib           (libsphc_runtime.a)
  std::string stdlibDir;    // <prefix>/share/sphc/stdlib
  std::string buildInfo;    // <prefix>/share/sphc/buildinfo.txt
};
Install locateInstall(const char* argv0);

struct BuildRequest {
  std::string cpp;          // the generated code
  std::string output;       // executable to write
  std::string cxx;          // override of the C++ compiler ("" = from buildinfo)
  std::string cxxflags;     // override of the flags ("" = from buildinfo)
  std::string backend = "serial";  // serial, openmp or opencl: which runtime and flags
  bool mpi = false;         // --mpi: link libsphc_mpi, MPI and Zoltan
  bool simd = false;        // --simd-pairs: -fopenmp-simd (the loops' `omp simd`)
  bool useCache = true;
  bool verbose = false;
};

struct BuildResult {
  bool ok = false;
  bool cached = false;
  std::string message;      // on failure: what went wrong, with the log's location
  double seconds = 0.0;
};

BuildResult buildExecutable(const Install& install, const BuildRequest& req);

// Whether solvers of --backend=opencl can be built (CMake found OpenCL: buildinfo.txt has a
// non-empty opencl_libs and lib/libsphc_runtime_ocl.a exists); else false and why.
bool openclAvailable(const Install& install, std::string& why);

// Whether solvers of --mpi can be built (CMake found MPI and Zoltan: buildinfo.txt has a
// non-empty mpi_libs and lib/libsphc_mpi.a exists); else false and why.
bool mpiAvailable(const Install& install, std::string& why);

// The cache directory: $SPHC_CACHE_DIR, else $XDG_CACHE_HOME/sphc, else ~/.cache/sphc.
std::string cacheDirectory();

}  // namespace sphc
