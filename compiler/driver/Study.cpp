// `sphc study ...` (compiler/driver/study.py, docs/accuracy-cost.md): the study itself is a
// Python helper (process management, CSV, matplotlib plots); this finds it beside sphc and
// runs it.
#include "driver/Study.h"

#include "driver/Build.h"

#include "llvm/Support/FileSystem.h"
#include "llvm/Support/Path.h"
#include "llvm/Support/raw_ostream.h"

#include <unistd.h>

#include <cstdlib>
#include <string>
#include <vector>

namespace sphc {

int runStudy(int argc, char** argv) {
  Install install = locateInstall(argv[0]);
  llvm::SmallString<256> script(install.prefix);
  llvm::sys::path::append(script, "share", "sphc", "study.py");
  if (!llvm::sys::fs::exists(script)) {
    llvm::errs() << "sphc: error: the study helper " << script << " is missing\n";
    return 1;
  }
  static int anchor;
  const std::string self = llvm::sys::fs::getMainExecutable(argv[0], &anchor);
  // $SPHC_PYTHON, else the first of python3 and /usr/bin/python3 (Debian's, where
  // scripts/setup-deps.sh installs matplotlib) that has matplotlib for the plots, else python3
  // (the study then writes its CSV and summary without plots).
  const char* py = std::getenv("SPHC_PYTHON");
  std::string python = py && *py ? py : "";
  if (python.empty()) {
    for (const char* cand : {"python3", "/usr/bin/python3"}) {
      const std::string probe =
          std::string(cand) + " -c 'import matplotlib' >/dev/null 2>&1";
      if (std::system(probe.c_str()) == 0) {
        python = cand;
        break;
      }
    }
    if (python.empty()) python = "python3";
  }
  std::vector<std::string> args = {python, script.str().str(), "--sphc", self};
  for (int i = 2; i < argc; ++i) args.push_back(argv[i]);
  std::vector<char*> cargs;
  for (auto& a : args) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  execvp(python.c_str(), cargs.data());
  llvm::errs() << "sphc: error: cannot run " << python << " for `sphc study`"
               << " (set SPHC_PYTHON to a Python 3 interpreter)\n";
  return 1;
}

}  // namespace sphc
