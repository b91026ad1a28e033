// The printed text of the kept lists (sphc/verlet.h KeptLists: per loop one contiguous array,
// offsets and indices): the build and the access of every printer that reads them
// (CpuPrinter.cpp, CpuVerletTune.cpp, SymmetricPairs.cpp), in one place.
#pragma once

#include <string>

namespace sphc::kept_lists {

// The thread that keeps a particle's list, and the number of threads that may.
inline std::string thread(bool openmp) { return openmp ? "omp_get_thread_num()" : "0"; }
inline std::string threads(bool openmp) { return openmp ? "omp_get_max_threads()" : "1"; }

// A build of `lists` for `n` particles begins (before the loop that keeps them).
inline std::string startBuild(const std::string& lists, const std::string& n, bool openmp) {
  return lists + ".lists.start_build(" + n + ", " + threads(openmp) + ");";
}
// d_idx's list: its candidates cand[0, count), kept sorted (a sphc::KeptList).
inline std::string keep(const std::string& lists, bool openmp, const std::string& cand,
                        const std::string& count) {
  return lists + ".lists.keep(" + thread(openmp) + ", d_idx, " + cand + ", " + count + ")";
}
// The build ends (after the loop that kept every list): the offsets and the one array.
inline std::string finishBuild(const std::string& lists) {
  return lists + ".lists.finish_build();";
}
// d_idx's kept list, built: a sphc::KeptList (data(), size(), front(), begin(), end()).
inline std::string listOf(const std::string& lists, const std::string& idx = "d_idx") {
  return lists + ".lists[" + idx + "]";
}
// `const sphc::KeptList kept = <d_idx's list>;`
inline std::string declareKept(const std::string& indent, const std::string& lists) {
  return indent + "const sphc::KeptList kept = " + listOf(lists) + ";\n";
}

}  // namespace sphc::kept_lists
