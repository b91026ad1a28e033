// A double as text: the one way the compiler prints numbers, in reports and diagnostics
// (formatNumber) and in the code it generates (exactNumber).
#pragma once

#include <cstdio>
#include <string>

namespace sphc {

// v in printf's %g style with `digits` significant digits (6, %g's own default, unless
// asked): for messages and --report, where a short number reads best.
inline std::string formatNumber(double v, int digits = 6) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

// v with 17 significant digits (%.17g), which read back as the same double: for generated
// code, where the solver must compute with the compiler's value to the last bit.
inline std::string exactNumber(double v) { return formatNumber(v, 17); }

}  // namespace sphc
