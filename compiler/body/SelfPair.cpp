// Loop bodies that add nothing for the self pair (BodyFacts::vanishesOnSelfPair): where a
// pair loop's destination array is its source, particle i is its own neighbour (r = 0), and
// an each-pair-once loop (codegen/SymmetricPairs.cpp) evaluates that pair like any other: the
// cut-off test, the pair quantities (a sqrt, the kernel, its gradient), every body. For most
// bodies of a momentum or continuity equation it adds zeros: at d_idx = s_idx, XIJ, VIJ
// (differences of one particle's values), R2IJ, RIJ and the kernel gradients DWIJ, DWI, DWJ
// (RadialKernel::gradient: 0 for r <= 1e-12) are zeros, and a product with a zero factor is a
// zero. Where every body of the loop is such, the printer starts i's pairs after i itself.
//
// A body vanishes on the self pair when every write of a property in it is `d_X[...] += e` or
// `d_X[...] -= e` with e a zero there, or lies in the branch of an `if` that the self pair
// does not take. e is a zero when it is XIJ[k], VIJ[k], DWIJ[k], DWI[k], DWJ[k], R2IJ, RIJ, a
// literal 0, d_X[d_idx] - s_X[s_idx] (one property of one particle: x - x), a product with a
// zero factor, a quotient with a zero numerator, -e, e + e' and e - e' of zeros, fma(a, b, c)
// with a or b and c zeros, c ? e : e', sqrt or fabs of a zero, or a local declared once from
// a zero and never assigned. A condition the self pair does not take: a < b or b > a with a a
// zero and b a zero or a literal <= 0 (e.g. `vijdotxij < 0.0`), a > b or b < a with a a zero
// and b a zero or a literal >= 0 (`R2IJ > 0.0`, `RIJ > 1e-12`), a != b of zeros, && with
// such a side, || with both. Refused: a call of anything but the math and kernel functions
// (a helper could write through a property), a division by a zero or a math function other
// than sqrt, fabs, fma, exp, sin, cos, KERNEL_W, KERNEL_DWDR of a zero outside the branches
// not taken (an infinity or NaN there would make the other factors of a product non-finite),
// any other write of a property (=, *=, ++, ...).
//
// What the skipped pair would have added is a zero of either sign: x + (+-0) = x for every
// x but -0 (-0 + +0 = +0), so the sums are the same bit for bit unless a sum is -0 when the
// self pair comes (it starts as -0, e.g. set to a -0 velocity, and everything added before is
// -0), and unless a factor of the product was not finite (inf * 0 = NaN: a sum the run's
// checks would have stopped on). docs/performance-log.md, "The self pair" (stop 35).
//
// The same check at the edge of the support (BodyFacts::vanishesAtSupport, stop 38): a pair
// is a neighbour while r < support h_max (the cut-off test), and at r = support h_max the
// kernel values WIJ, WI, WJ and gradients DWIJ, DWI, DWJ are zeros (q >= support for each
// smoothing length; of a kernel that vanishes there, with its derivative: not the truncated
// Gaussians). Where every write adds such a zero, what a pair adds goes to zero as it
// reaches the cut-off, and a pair that comes in or leaves by a rounding of the positions
// changes the sums by as little (a continuous function of the positions); a body that adds
// a count (`d_nnbr[d_idx] += 1.0`) or a source's value unweighted (`d_pavg[d_idx] +=
// s_p[s_idx]`, EDACAveragePressure) jumps by a whole term there. The zeros at the support:
// WIJ, WI, WJ, DWIJ[k], DWI[k], DWJ[k], a literal 0, and products, quotients, sums, ... of
// them as above; no branch is taken as known (both sides of an `if` must add zeros).
#include "body/AssignedLocals.h"
#include "body/BodyBatch.h"

#include "clang/AST/ASTContext.h"

#include <set>

namespace sphc::body_detail {

namespace {

// Where the body is checked: at the self pair (r = 0), or at the edge of the support (a pair
// at r = support h_max: the top of the file and vanishesAtSupport below).
enum class At { SelfPair, Support };

class SelfPairCheck : public AssignedLocalsVisitor<SelfPairCheck> {
 public:
  SelfPairCheck(const BodySource& body, At at) : body_(body), at_(at) {}

  bool check(clang::FunctionDecl* fn) {
    TraverseStmt(fn->getBody());  // the locals that are assigned after their declaration
    return vanishes(fn->getBody());
  }

 private:
  // A property indexed: `d_NAME[...]` or `s_NAME[...]` with NAME's parameter.
  static const clang::DeclRefExpr* propertyBase(const clang::Expr* e) {
    auto* a = llvm::dyn_cast<clang::ArraySubscriptExpr>(e->IgnoreParenImpCasts());
    if (!a) return nullptr;
    auto* base = llvm::dyn_cast<clang::DeclRefExpr>(a->getBase()->IgnoreParenImpCasts());
    if (!base || !llvm::isa<clang::ParmVarDecl>(base->getDecl()) ||
        !isPropertyName(base->getDecl()->getName()))
      return nullptr;
    return base;
  }

  // `d_X[d_idx]` (dest) or `s_X[s_idx]`: X, else "".
  static std::string particleValue(const clang::Expr* e, bool dest) {
    auto* a = llvm::dyn_cast<clang::ArraySubscriptExpr>(e->IgnoreParenImpCasts());
    const clang::DeclRefExpr* base = propertyBase(e);
    if (!a || !base) return "";
    auto* ix = llvm::dyn_cast<clang::DeclRefExpr>(a->getIdx()->IgnoreParenImpCasts());
    const std::string name = base->getDecl()->getName().str();
    if (!ix || !llvm::isa<clang::ParmVarDecl>(ix->getDecl()) || name[0] != (dest ? 'd' : 's') ||
        ix->getDecl()->getName() != (dest ? "d_idx" : "s_idx"))
      return "";
    return name.substr(2);
  }

  static bool literal(const clang::Expr* e, double& v) {
    e = e->IgnoreParenImpCasts();
    if (auto* u = llvm::dyn_cast<clang::UnaryOperator>(e);
        u && (u->getOpcode() == clang::UO_Minus || u->getOpcode() == clang::UO_Plus)) {
      if (!literal(u->getSubExpr(), v)) return false;
      if (u->getOpcode() == clang::UO_Minus) v = -v;
      return true;
    }
    if (auto* f = llvm::dyn_cast<clang::FloatingLiteral>(e)) {
      v = f->getValueAsApproximateDouble();
      return true;
    }
    if (auto* i = llvm::dyn_cast<clang::IntegerLiteral>(e)) {
      v = static_cast<double>(i->getValue().getSExtValue());
      return true;
    }
    return false;
  }

  // Whether e is a zero at the self pair (see the top of the file).
  bool zero(const clang::Expr* e) {
    e = e->IgnoreParens();
    if (auto* c = llvm::dyn_cast<clang::ImplicitCastExpr>(e))
      return c->getType()->isArithmeticType() && zero(c->getSubExpr());
    if (auto* c = llvm::dyn_cast<clang::CStyleCastExpr>(e))
      return c->getType()->isRealFloatingType() && zero(c->getSubExpr());
    double v = 1;
    if (literal(e, v)) return v == 0.0;
    if (auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(e)) {
      const clang::ValueDecl* d = ref->getDecl();
      if (auto* var = llvm::dyn_cast<clang::VarDecl>(d); var && !llvm::isa<clang::ParmVarDecl>(var))
        return var->isLocalVarDecl() && !assigned(var) && var->getInit() &&
               var->getType()->isArithmeticType() && zero(var->getInit());
      const std::string name = d->getName().str();
      if (!llvm::isa<clang::ParmVarDecl>(d) || nameRole(body_, name) != NameRole::PairQuantity)
        return false;
      return at_ == At::SelfPair ? name == "R2IJ" || name == "RIJ"
                                 : name == "WIJ" || name == "WI" || name == "WJ";
    }
    if (auto* a = llvm::dyn_cast<clang::ArraySubscriptExpr>(e)) {
      auto* base = llvm::dyn_cast<clang::DeclRefExpr>(a->getBase()->IgnoreParenImpCasts());
      if (!base || !llvm::isa<clang::ParmVarDecl>(base->getDecl())) return false;
      static const std::set<std::string> atSelf = {"XIJ", "VIJ", "DWIJ", "DWI", "DWJ"};
      static const std::set<std::string> atSupport = {"DWIJ", "DWI", "DWJ"};
      return (at_ == At::SelfPair ? atSelf : atSupport).count(base->getDecl()->getName().str()) > 0;
    }
    if (auto* u = llvm::dyn_cast<clang::UnaryOperator>(e))
      return (u->getOpcode() == clang::UO_Minus || u->getOpcode() == clang::UO_Plus) &&
             zero(u->getSubExpr());
    if (auto* b = llvm::dyn_cast<clang::BinaryOperator>(e)) {
      switch (b->getOpcode()) {
        case clang::BO_Mul: return zero(b->getLHS()) || zero(b->getRHS());
        case clang::BO_Div: return zero(b->getLHS());
        case clang::BO_Add: return zero(b->getLHS()) && zero(b->getRHS());
        case clang::BO_Sub: {
          if (zero(b->getLHS()) && zero(b->getRHS())) return true;
          if (at_ == At::Support) return false;
          // One property of one particle: d_X[d_idx] - s_X[s_idx] (either way round).
          for (bool dl : {true, false}) {
            const std::string l = particleValue(b->getLHS(), dl);
            if (!l.empty() && l == particleValue(b->getRHS(), !dl)) return true;
          }
          return false;
        }
        default: return false;
      }
    }
    if (auto* co = llvm::dyn_cast<clang::ConditionalOperator>(e))
      return zero(co->getTrueExpr()) && zero(co->getFalseExpr());
    if (auto* call = llvm::dyn_cast<clang::CallExpr>(e)) {
      const clang::FunctionDecl* fn = call->getDirectCallee();
      const std::string name = fn ? fn->getName().str() : "";
      if (name == "fma" && call->getNumArgs() == 3)
        return (zero(call->getArg(0)) || zero(call->getArg(1))) && zero(call->getArg(2));
      if ((name == "sqrt" || name == "fabs") && call->getNumArgs() == 1)
        return zero(call->getArg(0));
    }
    return false;
  }

  // Whether the self pair does not take a branch under condition e.
  bool falseAtSelf(const clang::Expr* e) {
    if (at_ == At::Support) return false;  // at the support: no branch known not taken
    e = e->IgnoreParenImpCasts();
    if (auto* b = llvm::dyn_cast<clang::BinaryOperator>(e)) {
      const clang::Expr* l = b->getLHS();
      const clang::Expr* r = b->getRHS();
      double v = 0;
      // a < b false at a = 0 where b <= 0; a > b false at a = 0 where b >= 0.
      auto atMost0 = [&](const clang::Expr* x) { return zero(x) || (literal(x, v) && v <= 0.0); };
      auto atLeast0 = [&](const clang::Expr* x) { return zero(x) || (literal(x, v) && v >= 0.0); };
      switch (b->getOpcode()) {
        case clang::BO_LT: return (zero(l) && atMost0(r)) || (zero(r) && atLeast0(l));
        case clang::BO_GT: return (zero(l) && atLeast0(r)) || (zero(r) && atMost0(l));
        case clang::BO_NE: return zero(l) && zero(r);
        case clang::BO_LAnd: return falseAtSelf(l) || falseAtSelf(r);
        case clang::BO_LOr: return falseAtSelf(l) && falseAtSelf(r);
        default: return false;
      }
    }
    return false;
  }

  // Whether statement s (evaluated at the self pair) changes no property but by adding a
  // zero, and computes no infinity or NaN from a zero.
  bool vanishes(const clang::Stmt* s) {
    if (!s) return true;
    if (auto* i = llvm::dyn_cast<clang::IfStmt>(s)) {
      if (i->getInit() && !vanishes(i->getInit())) return false;
      if (i->getConditionVariableDeclStmt()) return false;
      if (!vanishes(i->getCond())) return false;
      if (!falseAtSelf(i->getCond()) && !vanishes(i->getThen())) return false;
      return vanishes(i->getElse());
    }
    if (auto* b = llvm::dyn_cast<clang::BinaryOperator>(s)) {
      if (b->isAssignmentOp() && propertyBase(b->getLHS())) {
        if (b->getOpcode() != clang::BO_AddAssign && b->getOpcode() != clang::BO_SubAssign)
          return false;
        return zero(b->getRHS()) && vanishes(b->getLHS()) && vanishes(b->getRHS());
      }
      if ((b->getOpcode() == clang::BO_Div || b->getOpcode() == clang::BO_DivAssign) &&
          zero(b->getRHS()))
        return false;
    }
    if (auto* u = llvm::dyn_cast<clang::UnaryOperator>(s))
      if (u->isIncrementDecrementOp() && propertyBase(u->getSubExpr())) return false;
    if (auto* call = llvm::dyn_cast<clang::CallExpr>(s)) {
      const clang::FunctionDecl* fn = call->getDirectCallee();
      const std::string name = fn ? fn->getName().str() : "";
      if (!isMathOrKernelFunction(name)) return false;
      static const std::set<std::string> finiteAtZero = {"sqrt", "fabs", "fma", "exp", "sin",
                                                          "cos", "KERNEL_W", "KERNEL_DWDR"};
      if (!finiteAtZero.count(name))
        for (const clang::Expr* arg : call->arguments())
          if (zero(arg)) return false;
    }
    for (const clang::Stmt* c : s->children())
      if (!vanishes(c)) return false;
    return true;
  }

  const BodySource& body_;
  const At at_;
};

}  // namespace

bool vanishesOnSelfPair(const BodySource& body, clang::FunctionDecl* fn) {
  if (body.kind != BodyKind::Loop || !fn->getBody()) return false;
  return SelfPairCheck(body, At::SelfPair).check(fn);
}

bool vanishesAtSupport(const BodySource& body, clang::FunctionDecl* fn) {
  if (body.kind != BodyKind::Loop || !fn->getBody()) return false;
  return SelfPairCheck(body, At::Support).check(fn);
}

}  // namespace sphc::body_detail
