// The pair quantities of a `loop` body (XIJ, VIJ, RIJ, WIJ, DWIJ, RHOIJ, ...), defined once:
// their names and shapes (what body analysis declares to Clang and what body parameters are),
// what each is computed from (the closure the pair-quantity pass takes), the properties each
// reads of both particles (implicit reads for property inference, what ghosts carry, the
// pointers a neighbour pass takes), whether it evaluates the kernel, and how it is computed
// (the statements the emitter prints). Nothing else in sphc lists pair quantities.
//
// The vocabulary of the formulas (and of the code generated from them): `hi`, `hj` are the
// smoothing lengths of the destination and source particle, `Pi` (xi, ui, ...) the
// destination's component P, `di_P[d_idx]` and `sj_P[s_idx]` its property P and the source's.
#pragma once

#include <set>
#include <string>
#include <vector>

namespace sphc {

enum class PairForm {
  Difference,  // a 3-vector: Pi - sj_P[s_idx] for each component P of `components` within
               // the dimension, 0 beyond it (XIJ, VIJ)
  Formula,     // a scalar: `formula`, of other pair quantities, hi, hj, di_/sj_ properties
  Kernel,      // a scalar: the smoothing kernel W(RIJ, `h`)
  Gradient,    // a 3-vector: the kernel gradient at (XIJ, RIJ) and smoothing length `h`
};

enum class PairWhen {
  BeforeTest,      // computed for every candidate: the neighbour test needs it (XIJ, R2IJ)
  EveryNeighbour,  // computed for every neighbour, used or not (HIJ)
  IfUsed,          // computed when a loop body of the pass uses it, or one it depends on
};

struct PairQuantity {
  std::string name;
  bool vector = false;  // 3 components (XIJ[0..2]); else a scalar
  PairForm form = PairForm::Formula;
  std::vector<std::string> components;  // Difference: the vector's properties (x, y, z)
  std::string formula;                  // Formula: the expression (neutral C, see above)
  std::string h;                        // Kernel, Gradient: the smoothing length argument
  std::vector<std::string> needs;       // the pair quantities it is computed from
  std::vector<std::string> reads;       // properties read of both particles (beyond the
                                        // neighbour test's), within the dimension
  PairWhen when = PairWhen::IfUsed;
  int param = 0;  // its place in body parameter lists (the order bodies have always had)

  bool kernel() const { return form == PairForm::Kernel || form == PairForm::Gradient; }
};

// Every pair quantity, in the order the generated code computes them (each after those it
// needs; the neighbour test follows the BeforeTest ones).
const std::vector<PairQuantity>& pairQuantityTable();
// The row of `name`, or nullptr if it is no pair quantity.
const PairQuantity* findPairQuantity(const std::string& name);
// The names, in body-parameter order (XIJ, VIJ, DWIJ, DWI, DWJ, R2IJ, RIJ, HIJ, WIJ, WI, WJ,
// RHOIJ, RHOIJ1, EPS).
const std::vector<std::string>& pairQuantityNames();
// Pair quantities a loop computes given those its bodies use: the BeforeTest ones and the
// closure over `needs` (e.g. DWIJ needs XIJ, RIJ and HIJ; RIJ needs R2IJ).
std::set<std::string> pairQuantityClosure(const std::set<std::string>& used);
// The properties a neighbour pass reads of both the destination and the source particles to
// compute the quantities `q` (a closure): the neighbour test's (positions, h), then what the
// quantities read (velocities for VIJ, rho for RHOIJ), each once, in that order.
std::vector<std::string> pairQuantityProps(int dim, const std::set<std::string>& q);

// How a printer spells what the formulas leave open (host C++ or OpenCL C).
struct PairDialect {
  std::string real;            // the floating type: double, float, real
  std::string sqrt;            // std::sqrt or sqrt
  std::string kernelW;         // Kernel::w or kernel_w
  std::string kernelGradient;  // Kernel::gradient or kernel_gradient
  std::string literalSuffix;   // appended to floating literals ("f" for host float code)
};
// The statements that compute `q` (a row of the table), each line starting with `indent`,
// e.g. "const double RIJ = std::sqrt(R2IJ);\n".
std::string pairQuantityStatement(const PairQuantity& q, int dim, const PairDialect& dialect,
                                  const std::string& indent);

}  // namespace sphc
