// `sphc study ...`: runs the study helper (compiler/driver/study.py, installed as
// share/sphc/study.py) with python3, telling it where this sphc is.
#pragma once

namespace sphc {

// Replaces the process with `python3 <prefix>/share/sphc/study.py --sphc <this sphc>
// ARGS...` (argv[1] is "study"); returns an exit code only if that fails.
int runStudy(int argc, char** argv);

}  // namespace sphc
