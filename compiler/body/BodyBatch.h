// The body analysis's internal pieces shared by BodyAnalysis.cpp (the synthesised unit, Clang's
// invocation, diagnostics) and BodyChecker.cpp (the AST walk over each body). Internal to body/.
#pragma once

#include "body/BodyAnalysis.h"
#include "analysis/PairQuantityTable.h"

#include "clang/AST/Decl.h"
#include "clang/AST/Expr.h"
#include "clang/Basic/SourceManager.h"
#include "llvm/ADT/StringRef.h"
#include "llvm/Support/SourceMgr.h"

#include <algorithm>
#include <functional>
#include <set>
#include <string>
#include <vector>

namespace sphc::body_detail {

// Names of the synthesised translation unit and of the body functions in it.
constexpr const char* kUnitName = "<sphc-bodies>.c";
constexpr llvm::StringLiteral kFunctionPrefix = "__sphc_body_";

inline bool isPairQuantity(const std::string& name) { return findPairQuantity(name) != nullptr; }

// `d_NAME` / `s_NAME` (a property access), but not the indices d_idx / s_idx.
inline bool isPropertyName(llvm::StringRef name) {
  return (name.startswith("d_") || name.startswith("s_")) && name.size() > 2 &&
         name != "d_idx" && name != "s_idx";
}

// What a parameter of a body function stands for, by its name, in the order the body checker
// (BodyChecker.cpp) and the source-only finder (SourceOnly.cpp) both classify names: a property
// (d_NAME / s_NAME), the neighbour list (NBRS, N_NBRS), a pair quantity, the indices, t, dt, one
// of the scalars the body is given, or none of these.
enum class NameRole {
  Property, Neighbours, PairQuantity, SourceIndex, DestinationIndex, Time, TimeStep, Scalar, Other
};

inline NameRole nameRole(const BodySource& body, llvm::StringRef name) {
  if (isPropertyName(name)) return NameRole::Property;
  if (name == "NBRS" || name == "N_NBRS") return NameRole::Neighbours;
  if (isPairQuantity(name.str())) return NameRole::PairQuantity;
  if (name == "s_idx") return NameRole::SourceIndex;
  if (name == "d_idx") return NameRole::DestinationIndex;
  if (name == "t") return NameRole::Time;
  if (name == "dt") return NameRole::TimeStep;
  if (std::find(body.scalars.begin(), body.scalars.end(), name) != body.scalars.end())
    return NameRole::Scalar;
  return NameRole::Other;
}

// One of the math functions a body may call (allowedMathFunctions) or a kernel function.
inline bool isMathOrKernelFunction(const std::string& name) {
  const auto& math = allowedMathFunctions();
  const auto& kernel = kernelFunctions();
  return std::find(math.begin(), math.end(), name) != math.end() ||
         std::find(kernel.begin(), kernel.end(), name) != kernel.end();
}

inline const char* kindName(BodyKind kind) {
  switch (kind) {
    case BodyKind::Initialize: return "initialize";
    case BodyKind::Loop: return "loop";
    case BodyKind::PostLoop: return "post_loop";
    case BodyKind::Reduce: return "reduce";
    case BodyKind::Converged: return "converged";
    case BodyKind::HostReduce: return "reduce";
    case BodyKind::InitializePair: return "initialize_pair";
    case BodyKind::LoopAll: return "loop_all";
    case BodyKind::StepperInit: return "initialize";
    case BodyKind::StepperStage: return "stage";
    case BodyKind::Function: return "function";
  }
  return "body";
}

inline bool returnsValue(BodyKind kind) { return kind == BodyKind::Reduce || kind == BodyKind::Converged; }

// Where a body's text (and the closing brace after it) lies in the translation unit.
struct BodyRegion {
  unsigned textBegin = 0;  // offset of text[0]
  unsigned end = 0;        // offset of the closing `}` (the .sph `}` after the text)
};

// Per-body bookkeeping shared by the diagnostic forwarder and the AST walk.
struct BodyState {
  unsigned errors = 0;
  bool checked = false;  // its function reached the AST walk (not after a fatal error)
  bool missingReturnReported = false;
  bool blanked = false;  // left out of the unit after an error (unbalanced brackets)
  std::set<std::string> reportedOutsideLoop;  // s_/pair-quantity names already reported
};

// One analysis: the bodies, the synthesised unit, and everything reported so far.
class Batch {
 public:
  Batch(DiagnosticEngine& diags, const std::vector<BodySource>& bodies)
      : facts(bodies.size()), state(bodies.size()), diags_(diags), bodies_(bodies) {
    synthesise();
  }

  const std::string& unit() const { return unit_; }
  const BodySource& body(int i) const { return bodies_[i]; }
  DiagnosticEngine& diags() { return diags_; }

  // The body whose text contains `loc` (after macro expansion), or -1.
  int bodyAt(const clang::SourceManager& sm, clang::SourceLocation loc) const {
    if (loc.isInvalid()) return -1;
    loc = sm.getExpansionLoc(loc);
    if (sm.getFileID(loc) != sm.getMainFileID()) return -1;
    unsigned off = sm.getFileOffset(loc);
    auto it = std::upper_bound(regions_.begin(), regions_.end(), off,
                               [](unsigned o, const BodyRegion& r) { return o < r.textBegin; });
    if (it == regions_.begin()) return -1;
    --it;
    return off <= it->end ? static_cast<int>(it - regions_.begin()) : -1;
  }

  // The .sph location of `loc`, which lies in body `i`.
  llvm::SMLoc toSph(const clang::SourceManager& sm, clang::SourceLocation loc, int i) const {
    if (!bodies_[i].start.isValid()) return llvm::SMLoc();
    unsigned off = sm.getFileOffset(sm.getExpansionLoc(loc));
    return llvm::SMLoc::getFromPointer(bodies_[i].start.getPointer() +
                                       (off - regions_[i].textBegin));
  }

  // The .sph `}` closing body `i`.
  llvm::SMLoc closingBrace(int i) const {
    const BodySource& b = bodies_[i];
    // A function's text ends with its `}`; a body's text ends just before it.
    size_t at = b.text.size() - (b.kind == BodyKind::Function && !b.text.empty() ? 1 : 0);
    return b.start.isValid() ? llvm::SMLoc::getFromPointer(b.start.getPointer() + at)
                             : llvm::SMLoc();
  }

  // The helper function (BodyKind::Function) that `fn` is the definition of, or -1.
  int functionOf(const clang::SourceManager& sm, const clang::FunctionDecl* fn) const {
    const clang::FunctionDecl* def = fn ? fn->getDefinition() : nullptr;
    if (!def) return -1;
    int j = bodyAt(sm, def->getLocation());
    if (j < 0 || bodies_[j].kind != BodyKind::Function ||
        def->getName() != bodies_[j].functionName)
      return -1;
    return j;
  }
  // The helper function named `name`, or -1.
  int functionNamed(llvm::StringRef name) const {
    for (size_t j = 0; j < bodies_.size(); ++j)
      if (bodies_[j].kind == BodyKind::Function && bodies_[j].functionName == name)
        return static_cast<int>(j);
    return -1;
  }

  // Reports a diagnostic of body `i`, counting the errors it causes (warnings may be errors).
  void report(int i, llvm::SourceMgr::DiagKind kind, llvm::SMLoc loc, const llvm::Twine& msg) {
    unsigned before = diags_.errorCount();
    switch (kind) {
      case llvm::SourceMgr::DK_Error: diags_.error(loc, msg); break;
      case llvm::SourceMgr::DK_Warning: diags_.warning(loc, msg); break;
      case llvm::SourceMgr::DK_Remark: diags_.remark(loc, msg); break;
      case llvm::SourceMgr::DK_Note: diags_.note(loc, msg); break;
    }
    if (i >= 0) state[i].errors += diags_.errorCount() - before;
  }
  void error(int i, llvm::SMLoc loc, const llvm::Twine& msg) {
    report(i, llvm::SourceMgr::DK_Error, loc, msg);
  }

  // sphc's messages shared by the diagnostic forwarder and the AST walk.
  void reportMissingReturn(int i) {
    if (state[i].missingReturnReported || state[i].blanked) return;
    state[i].missingReturnReported = true;
    const BodySource& b = bodies_[i];
    std::string what = b.label.empty() ? std::string("a '") + kindName(b.kind) + "' body"
                                       : b.label;
    error(i, closingBrace(i),
          "missing 'return': " + what + " must return a value on every path ('return EXPR;')");
  }
  void reportOutsideLoop(int i, llvm::SMLoc loc, const std::string& name) {
    if (!state[i].reportedOutsideLoop.insert(name).second) return;
    if (name == "s_idx")
      error(i, loc, "'s_idx' (the neighbour's index) is only available in 'loop'");
    else if (name == "NBRS" || name == "N_NBRS")
      error(i, loc, "'" + name + "' (the neighbour list) is only available in 'loop_all', not "
                        "in '" + kindName(bodies_[i].kind) + "'");
    else if (llvm::StringRef(name).startswith("s_"))
      error(i, loc, "'" + name + "': s_ properties are only available in 'loop', 'loop_all' "
                        "and 'initialize_pair', not in '" + kindName(bodies_[i].kind) + "'");
    else
      error(i, loc, name + " is a pair quantity, only available in 'loop'");
  }

  std::vector<BodyFacts> facts;
  std::vector<BodyState> state;

 private:
  void synthesise();

  DiagnosticEngine& diags_;
  const std::vector<BodySource>& bodies_;
  std::string unit_;
  std::vector<BodyRegion> regions_;  // ordered by offset
};

// The AST walk over body `index` of the batch (BodyChecker.cpp): facts and sphc's rules.
void checkBodyFunction(Batch& batch, int index, const clang::SourceManager& sm,
                       clang::FunctionDecl* fn);

// text[begin, end) of an expression of the body being checked; false where it has none.
using SourceRangeOf = std::function<bool(const clang::Stmt*, unsigned&, unsigned&)>;
// The source-only subexpressions of a loop body worth computing once per source particle
// (SourceOnly.cpp; BodyFacts::sourceOnly).
std::vector<SourceOnlySite> findSourceOnlySites(const BodySource& body, clang::FunctionDecl* fn,
                                                const SourceRangeOf& rangeOf);
// The destination-only ones (BodyFacts::destinationOnly), reading no d_ property in `written`.
std::vector<SourceOnlySite> findDestinationOnlySites(const BodySource& body,
                                                     clang::FunctionDecl* fn,
                                                     const SourceRangeOf& rangeOf,
                                                     const std::set<std::string>& written);
// A site's use of a body parameter `name`: t, dt or one of the scalars (SourceOnlySite's
// usesT, usesDt, scalars; SourceOnly.cpp, PairShared.cpp).
inline void noteParameterUse(const BodySource& body, const std::string& name, SourceOnlySite& site) {
  switch (nameRole(body, name)) {
    case NameRole::Time: site.usesT = true; break;
    case NameRole::TimeStep: site.usesDt = true; break;
    case NameRole::Scalar: site.scalars.insert(name); break;
    default: break;
  }
}
// A site's locals (SourceOnlySite::locals: name, type, the range of the initial value) from
// `locals`, in order of declaration (`order`: a local's position in the body); false where
// two have one name (shadowing) or an initial value has no range in the body (SourceOnly.cpp,
// PairShared.cpp).
template <class Order>
bool appendSiteLocals(const std::set<const clang::VarDecl*>& locals, const Order& order,
                      const SourceRangeOf& rangeOf, SourceOnlySite& site) {
  std::vector<const clang::VarDecl*> ordered(locals.begin(), locals.end());
  std::sort(ordered.begin(), ordered.end(), [&](const clang::VarDecl* a, const clang::VarDecl* b) {
    return order.at(a) < order.at(b);
  });
  std::set<std::string> names;
  for (const clang::VarDecl* v : ordered) {
    SourceOnlySite::Local l;
    l.name = v->getName().str();
    l.type = v->getType().getUnqualifiedType().getAsString();
    if (!names.insert(l.name).second) return false;  // shadowed: two locals of one name
    if (!rangeOf(v->getInit(), l.initBegin, l.initEnd)) return false;
    site.locals.push_back(l);
  }
  return true;
}
// The values of a loop body the mirrored pair shares (BodyFacts::pairShared; PairShared.cpp).
std::vector<SourceOnlySite> findPairSharedSites(const BodySource& body, clang::FunctionDecl* fn,
                                                const SourceRangeOf& rangeOf);
// The factors a and b of each multiply-add site's product, in the order of the sites.
struct ProductFactors {
  const clang::Expr* a = nullptr;
  const clang::Expr* b = nullptr;
};
// MultiplyAddSite::zeroWhen of each site (ZeroTerms.cpp).
void findZeroFactors(clang::FunctionDecl* fn, const std::vector<ProductFactors>& factors,
                     std::vector<MultiplyAddSite>& sites);
// Whether a loop body adds only zeros to properties at the self pair (BodyFacts::
// vanishesOnSelfPair; SelfPair.cpp).
bool vanishesOnSelfPair(const BodySource& body, clang::FunctionDecl* fn);
// Whether it adds only zeros at the edge of the support, where the kernel and its gradient
// vanish (BodyFacts::vanishesAtSupport; SelfPair.cpp).
bool vanishesAtSupport(const BodySource& body, clang::FunctionDecl* fn);

}  // namespace sphc::body_detail
