// When a multiply-add's product is zero (MultiplyAddSite::zeroWhen): the conditions, on the
// components a scene's dimension leaves out, under which a factor of `a * b` in `a * b + c`,
// `c + a * b`, `x += a * b`, ... is a zero. The dimension pass (analysis/Dimensions.cpp)
// drops such a term in a 1D or 2D scene where a condition holds (the stress tensor's z row
// and column, the z term of a dot product): GCC cannot, 0.0 * x being NaN for an infinite x
// and fma(a, 0.0, c) = +0 for c = -0.
//
// A factor is zero where each leaf of one conjunction is zero. Leaves: `XIJ[k]`, `VIJ[k]`,
// `DWIJ[k]` with a literal k (the pair vectors' components: "XIJ[2]"), `prop:NAME` (a d_ or
// s_ property, at any index: zero where the dimension pass reads it as 0.0, a left-out
// component such as w), and the literal zero (the empty conjunction). The rules, for finite
// values: x * y and x / y are zero if x is (x * y also if y is), x + y and x - y if both are,
// -x, (x) and casts if x is; a local scalar never assigned after its declaration is its
// initial value; an element at a literal index of a local array whose initialiser lists it
// and which is only ever read by subscript (never assigned, incremented, passed or its
// address taken) is that element's initial value. Anything else (calls, conditionals,
// other names) is not known to be zero. At most 16 conjunctions per factor.
#include "body/AssignedLocals.h"
#include "body/BodyBatch.h"

#include "clang/AST/ASTContext.h"

#include <algorithm>
#include <map>

namespace sphc::body_detail {

namespace {

using Conj = std::vector<std::string>;  // sorted leaves, all zero
using Dnf = std::vector<Conj>;          // any of them

const size_t kMaxConj = 16;

Dnf orOf(Dnf x, const Dnf& y) {
  for (const Conj& c : y)
    if (std::find(x.begin(), x.end(), c) == x.end()) x.push_back(c);
  if (x.size() > kMaxConj) x.resize(kMaxConj);
  return x;
}

Dnf andOf(const Dnf& x, const Dnf& y) {
  Dnf out;
  for (const Conj& a : x)
    for (const Conj& b : y) {
      Conj c = a;
      c.insert(c.end(), b.begin(), b.end());
      std::sort(c.begin(), c.end());
      c.erase(std::unique(c.begin(), c.end()), c.end());
      if (std::find(out.begin(), out.end(), c) == out.end()) out.push_back(c);
      if (out.size() >= kMaxConj) return out;
    }
  return out;
}

class ZeroFinder : public AssignedLocalsVisitor<ZeroFinder> {
 public:
  explicit ZeroFinder(clang::FunctionDecl* fn) { TraverseStmt(fn->getBody()); }

  bool VisitArraySubscriptExpr(clang::ArraySubscriptExpr* a) {
    if (auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(a->getBase()->IgnoreParenImpCasts()))
      subscripted_.insert(ref);
    return true;
  }
  bool VisitDeclRefExpr(clang::DeclRefExpr* r) {
    refs_.push_back(r);
    return true;
  }
  bool VisitBinaryOperator(clang::BinaryOperator* op) {
    AssignedLocalsVisitor::VisitBinaryOperator(op);
    if (op->isAssignmentOp()) markElementWritten(op->getLHS());
    return true;
  }
  bool VisitUnaryOperator(clang::UnaryOperator* op) {
    AssignedLocalsVisitor::VisitUnaryOperator(op);
    if (op->isIncrementDecrementOp() || op->getOpcode() == clang::UO_AddrOf)
      markElementWritten(op->getSubExpr());
    return true;
  }

  Dnf zero(const clang::Expr* e) {
    if (auto it = memo_.find(e); it != memo_.end()) return it->second;
    memo_[e] = {};  // (no cycles, but be safe)
    Dnf d = classify(e);
    memo_[e] = d;
    return d;
  }

 private:
  void markElementWritten(clang::Expr* e) {
    if (auto* a = llvm::dyn_cast<clang::ArraySubscriptExpr>(e->IgnoreParenImpCasts()))
      if (auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(a->getBase()->IgnoreParenImpCasts()))
        if (auto* v = llvm::dyn_cast<clang::VarDecl>(ref->getDecl())) elementsWritten_.insert(v);
  }

  // A local array only ever read by subscript.
  bool readOnlyArray(const clang::VarDecl* v) {
    if (elementsWritten_.count(v) || assigned(v)) return false;
    for (const clang::DeclRefExpr* r : refs_)
      if (r->getDecl() == v && !subscripted_.count(r)) return false;  // passed, decayed, ...
    return true;
  }

  Dnf classify(const clang::Expr* e) {
    const Dnf yes = {Conj{}};
    e = e->IgnoreParens();
    if (auto* f = llvm::dyn_cast<clang::FloatingLiteral>(e))
      return f->getValue().isZero() ? yes : Dnf{};
    if (auto* i = llvm::dyn_cast<clang::IntegerLiteral>(e))
      return i->getValue() == 0 ? yes : Dnf{};
    if (auto* c = llvm::dyn_cast<clang::CastExpr>(e)) {
      if (!llvm::isa<clang::ImplicitCastExpr>(c) && !llvm::isa<clang::CStyleCastExpr>(c))
        return {};
      if (!c->getType()->isArithmeticType()) return {};
      return zero(c->getSubExpr());
    }
    if (auto* u = llvm::dyn_cast<clang::UnaryOperator>(e)) {
      if (u->getOpcode() == clang::UO_Minus || u->getOpcode() == clang::UO_Plus)
        return zero(u->getSubExpr());
      return {};
    }
    if (auto* b = llvm::dyn_cast<clang::BinaryOperator>(e)) {
      switch (b->getOpcode()) {
        case clang::BO_Mul: return orOf(zero(b->getLHS()), zero(b->getRHS()));
        case clang::BO_Div: return zero(b->getLHS());
        case clang::BO_Add:
        case clang::BO_Sub: return andOf(zero(b->getLHS()), zero(b->getRHS()));
        default: return {};
      }
    }
    if (auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(e)) {
      auto* v = llvm::dyn_cast<clang::VarDecl>(ref->getDecl());
      if (!v || llvm::isa<clang::ParmVarDecl>(v) || !v->isLocalVarDecl()) return {};
      if (assigned(v) || !v->getInit() || !v->getType()->isArithmeticType() ||
          v->getType().isVolatileQualified())
        return {};
      return zero(v->getInit());
    }
    if (auto* a = llvm::dyn_cast<clang::ArraySubscriptExpr>(e)) {
      auto* base = llvm::dyn_cast<clang::DeclRefExpr>(a->getBase()->IgnoreParenImpCasts());
      if (!base) return {};
      const std::string name = base->getDecl()->getName().str();
      if (auto* p = llvm::dyn_cast<clang::ParmVarDecl>(base->getDecl())) {
        if (name == "XIJ" || name == "VIJ" || name == "DWIJ") {
          auto* lit = llvm::dyn_cast<clang::IntegerLiteral>(a->getIdx()->IgnoreParenImpCasts());
          if (!lit) return {};
          return {Conj{name + "[" + std::to_string(lit->getValue().getZExtValue()) + "]"}};
        }
        if (isPropertyName(p->getName())) return {Conj{"prop:" + name.substr(2)}};
        return {};
      }
      auto* v = llvm::dyn_cast<clang::VarDecl>(base->getDecl());
      auto* lit = llvm::dyn_cast<clang::IntegerLiteral>(a->getIdx()->IgnoreParenImpCasts());
      if (!v || !lit || !v->isLocalVarDecl() || !readOnlyArray(v)) return {};
      auto* init = llvm::dyn_cast_or_null<clang::InitListExpr>(v->getInit());
      const uint64_t k = lit->getValue().getZExtValue();
      if (!init || k >= init->getNumInits()) return {};
      return zero(init->getInit(static_cast<unsigned>(k)));
    }
    return {};
  }

  std::set<const clang::DeclRefExpr*> subscripted_;
  std::vector<const clang::DeclRefExpr*> refs_;
  std::set<const clang::VarDecl*> elementsWritten_;
  std::map<const clang::Expr*, Dnf> memo_;
};

}  // namespace

void findZeroFactors(clang::FunctionDecl* fn, const std::vector<ProductFactors>& factors,
                     std::vector<MultiplyAddSite>& sites) {
  if (!fn->hasBody() || factors.size() != sites.size()) return;
  ZeroFinder z(fn);
  for (size_t k = 0; k < sites.size(); ++k)
    sites[k].zeroWhen = orOf(z.zero(factors[k].a), z.zero(factors[k].b));
}

}  // namespace sphc::body_detail
