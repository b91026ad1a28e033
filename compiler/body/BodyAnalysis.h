// Equation and stepper bodies, parsed and checked by Clang (libTooling) as C99 functions that
// sphc synthesises, with #line directives so every Clang diagnostic points into the .sph file.
// The result is what the analysis passes need: which d_/s_ properties a body reads and writes,
// which pair quantities it uses, and whether it uses t and dt. The rest of sphc never sees
// Clang: this header is the whole interface.
#pragma once

#include "analysis/PairQuantityTable.h"
#include "frontend/Diagnostics.h"

#include "llvm/Support/SMLoc.h"

#include <map>
#include <set>
#include <string>
#include <vector>

namespace sphc {

enum class BodyKind {
  Initialize,   // equation: per destination particle
  Loop,         // equation: per (destination, neighbour) pair; s_* and pair quantities visible
  PostLoop,     // equation: per destination particle
  Reduce,       // equation: per destination particle, `return` a double
  Converged,    // equation: once, `return` an int (>0 converged, <0 not, 0 no opinion)
  InitializePair,  // equation: per (destination particle, source array), before the loops
                   // over that source; s_* visible (any index), no s_idx
  LoopAll,      // equation: per (destination particle, source array) with the neighbour list
                // NBRS[0..N_NBRS) of source indices; s_* visible, no pair quantities
  HostReduce,   // equation `reduce { }`: once on the host, N (the number of real particles)
                // instead of d_idx; reads properties at any index, writes constants, states
  StepperInit,  // stepper initialize: per particle
  StepperStage, // stepper stageN: per particle
  Function      // helper function: `text` is the whole C definition (from its return type to
                // its closing `}`); bodies and later functions may call it
};

// How a property is stored, for typing `d_NAME` / `s_NAME` in the synthesised function.
// Properties not listed are double scalars.
struct PropShape {
  std::string type = "double";  // double, int, uint
  int stride = 1;
};

struct BodySource;
// Whether `name` is one of the body's equation states.
bool isState(const BodySource& b, const std::string& name);
// Bodies that run on the host once per call and may write the equation's states.
bool writesStates(BodyKind k);

// Bodies that see the source arrays (s_*): loop, loop_all, initialize_pair.
inline bool seesSources(BodyKind k) {
  return k == BodyKind::Loop || k == BodyKind::LoopAll || k == BodyKind::InitializePair;
}

struct BodySource {
  std::string text;                  // raw text between the braces
  llvm::SMLoc start;                 // location of text[0] in the .sph buffer
  BodyKind kind = BodyKind::Initialize;
  std::string label;                 // for messages: "equation TaitEOS, method initialize"
  std::vector<std::string> scalars;  // double constants visible by name (params, consts,
                                     // states)
  std::vector<std::string> states;   // those of scalars that are the instance's state:
                                     // writable in `converged` (host side), read elsewhere
  std::map<std::string, PropShape> props;  // known property shapes (by property name)
  std::string functionName;          // Function: the name it defines
};

struct PropAccess {
  std::string prop;                  // without the d_/s_ prefix
  llvm::SMLoc loc;                   // first occurrence in the body
};

// Where a body indexes a property: text[begin, end) is `d_NAME[...]` or `s_NAME[...]`. The
// dimension pass (analysis/Dimensions.cpp) rewrites the sites of the z-components of a 2D
// scene (reads become 0, writes go to a local sink) so that they are never allocated.
struct PropSite {
  std::string prop;                  // without the prefix
  bool source = false;               // s_
  bool write = false;                // the left side of an assignment (=, +=, ++, ...)
  unsigned begin = 0, end = 0;       // offsets into BodySource::text
};

// Where a body adds a product to a value in floating point: `a * b + c`, `c + a * b`,
// `a * b - c`, `c - a * b`, `x += a * b`, `x -= a * b`, with a, b, c (x) and the result all of
// the same floating type as written (no conversion between the product and the sum). The
// printers write each as one fused multiply-add, `fma(a, b, c)` (codegen/FusedMultiplyAdd.cpp):
// rounded once, the same on every backend, where the C++ compiler would otherwise choose per
// inlining context (or, with contraction off, not at all). Offsets are into BodySource::text;
// the dimension pass keeps them up to date when it edits the text (body/TextEdits.h).
struct MultiplyAddSite {
  enum Form { ProductPlus, PlusProduct, ProductMinus, MinusProduct, AddAssign, SubAssign };
  Form form = ProductPlus;
  unsigned begin = 0, end = 0;       // the whole sum, difference or compound assignment
  unsigned productBegin = 0, productEnd = 0;  // a * b, with its parentheses if any
  unsigned aBegin = 0, aEnd = 0;     // the factors
  unsigned bBegin = 0, bEnd = 0;
  unsigned cBegin = 0, cEnd = 0;     // the addend (x of a compound assignment)
  unsigned mulOp = 0, addOp = 0;     // the `*` and the `+`, `-`, `+=` or `-=`
  bool parenthesizeNegated = false;  // the negated operand (c of a*b - c, a of c - a*b and
                                     // x -= a*b) is not a primary expression: -(...)
  // When the product is zero (body/ZeroTerms.cpp): where every leaf of one of these lists
  // reads 0 ("XIJ[2]", "VIJ[2]", "DWIJ[2]", "prop:w"; an empty list: always), a factor is
  // zero. The dimension pass drops such a term in a scene whose dimension leaves them out.
  std::vector<std::vector<std::string>> zeroWhen;
  bool statement = false;            // x += a*b, x -= a*b: a statement of its own
};

// A subexpression of a loop body that depends on the source particle only (s_NAME[s_idx],
// literals, the equation's scalars, t, dt, the allowed math functions, and locals declared
// once from such values and never assigned) and costs more than a load (a division, a call
// of sqrt, pow, exp, ...): codegen/Hoist.h computes it once per source particle before the
// neighbour pass and the loop reads it. Offsets are into BodySource::text (kept up to date
// by body/TextEdits.h). BodyFacts::destinationOnly: the same with d_NAME[d_idx] (of properties
// the body does not write), computed once per destination particle before its neighbours.
struct SourceOnlySite {
  struct Local {                     // a local the expression reads: `type name = init;`
    std::string name, type;
    unsigned initBegin = 0, initEnd = 0;
  };
  unsigned begin = 0, end = 0;       // the expression
  std::vector<Local> locals;         // in order of declaration (each after those it reads)
  std::set<std::string> scalars;     // of BodySource::scalars, through the locals too
  bool usesT = false, usesDt = false;
  // BodyFacts::pairShared only: 1 if the mirrored pair's value is the same, -1 if it is its
  // negation; with `result` (an `if` that sets a local, body/PairShared.cpp): the statement
  // text[stmtBegin, stmtEnd), the local's name, and [begin, end) its initial value; id: the
  // site's place in BodyFacts::pairShared (kept when text edits move or drop sites).
  int sign = 1;
  std::string result;
  unsigned stmtBegin = 0, stmtEnd = 0;
  // BodyFacts::pairShared only: a value that divides or calls a function inside a top-level
  // `if` whose condition is the same both ways: text[guardBegin, guardEnd) is that condition
  // (it reads no local), and the value is computed only where it holds (0 elsewhere, where
  // the body does not read it).
  unsigned guardBegin = 0, guardEnd = 0;
  int id = 0;
};

struct BodyFacts {
  bool ok = false;                   // false: errors were reported for this body
  std::vector<PropAccess> dReads;    // d_ properties read (incl. read in `+=`)
  std::vector<PropAccess> dWrites;   // d_ properties written (=, +=, ++, ...)
  std::vector<PropAccess> sReads;    // s_ properties read
  std::set<std::string> pairQuantities;  // those it uses (analysis/PairQuantityTable.h;
                                         // only in Loop bodies)
  bool usesT = false, usesDt = false;
  std::set<std::string> scalarsUsed;     // which of BodySource::scalars appear
  std::set<std::string> statesWritten;   // which of BodySource::states it assigns
  std::vector<PropSite> sites;           // every indexing of a property
  std::vector<MultiplyAddSite> multiplyAdds;  // every product added to a value (floating)
  std::vector<SourceOnlySite> sourceOnly;     // loop bodies: what may be hoisted
  std::vector<SourceOnlySite> destinationOnly;  // the same of the destination (d_NAME[d_idx]
                                                // of properties the body does not write)
  // Loop bodies: values the same (or negated) for the mirrored pair (body/PairShared.cpp),
  // computed once per pair where the pair is evaluated once for both particles.
  std::vector<SourceOnlySite> pairShared;
  // Loop bodies: at the self pair (d_idx = s_idx, r = 0) the body only adds zeros to
  // properties (body/SelfPair.cpp), so an each-pair-once loop of bodies that all do may skip
  // that pair (codegen/SymmetricPairs.cpp).
  bool vanishesOnSelfPair = false;
  // Loop bodies: at the edge of the support (a pair at r = support h_max, where the kernel
  // and its gradient vanish) the body only adds zeros to properties (body/SelfPair.cpp): what
  // it adds is continuous as a pair enters or leaves the neighbours.
  bool vanishesAtSupport = false;
};

// The identifiers every body may use, besides d_/s_ properties and the scalars it is given
// (and, in a loop, the pair quantities: pairQuantityNames()).
const std::vector<std::string>& allowedMathFunctions();
// Whether GCC vectorises a call of this allowed math function without -ffast-math (no SIMD
// clone in glibc is needed: sqrt, fabs, fmin, fmax, floor, ceil, round, trunc, copysign).
// The one list behind both the SIMD pair loops' refusal of the others
// (codegen/SimdPairs.cpp, scalarMathCall) and the values a pair shares under a guard
// (body/PairShared.cpp, rule (3)), so the two cannot disagree.
bool laneMathFunction(const std::string& name);
// Functions of the scene's smoothing kernel that bodies may call: KERNEL_W(r, h) (the kernel)
// and KERNEL_DWDR(r, h) (its radial derivative), at any smoothing length h.
const std::vector<std::string>& kernelFunctions();

class BodyAnalyzer {
 public:
  explicit BodyAnalyzer(DiagnosticEngine& diags) : diags_(diags) {}
  // Analyses all bodies in one Clang invocation; facts[i] belongs to bodies[i]. Errors
  // (Clang's and sphc's portability rules) are reported through the DiagnosticEngine at
  // .sph locations.
  // Helper functions (BodyKind::Function) must come before the bodies that call them, in the
  // order in which they may call each other.
  std::vector<BodyFacts> analyze(const std::vector<BodySource>& bodies);

 private:
  DiagnosticEngine& diags_;
};

}  // namespace sphc
