// Products added to values, printed as fused multiply-adds. The solvers are built without
// contraction (-ffp-contract=off; `#pragma OPENCL FP_CONTRACT OFF` in the kernels) so that
// every backend rounds each + - * / as the source says; the printers then write each
// multiply-add the body analysis found (body/BodyAnalysis.h, MultiplyAddSite) as one explicit
// fused multiply-add, rounded once, identically in C++ (std::fma) and in OpenCL C (fma):
//
//   a * b + c   c + a * b   ->  fma(a, b, c)        x += a * b  ->  x = fma(a, b, x)
//   a * b - c               ->  fma(a, b, -c)       x -= a * b  ->  x = fma(-a, b, x)
//   c - a * b               ->  fma(-a, b, c)
//
// The negations are exact, so each fma is the sum or difference rounded once. Nested sites
// nest (`a * b + c * d + e` is fma(a, b, c * d) + e: only the left product of a sum of two is
// fused). Everything else of the body is printed as written, its comments and line breaks
// included (the #line mapping of the lines after a site does not change).
#pragma once

#include "body/BodyAnalysis.h"

#include <string>
#include <vector>

namespace sphc {

// `text` with the multiply-add `sites` (offsets into it) written as calls of `fma` (the
// function's spelling: "std::fma", "fma"). A site whose offsets do not fit the text, or that
// overlaps another without nesting in it, is printed as written.
std::string fuseMultiplyAdds(const std::string& text, const std::vector<MultiplyAddSite>& sites,
                             const std::string& fma);

}  // namespace sphc
