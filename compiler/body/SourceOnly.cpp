// Source-only subexpressions of a loop body (BodyFacts::sourceOnly): values that depend on the
// source particle alone and cost more than a load, so that the printer may compute them once
// per source particle before the neighbour pass (codegen/Hoist.h) instead of once per pair.
// Destination-only ones (BodyFacts::destinationOnly) likewise, with d_NAME[d_idx] of the
// properties the body does not write: once per destination particle, before its neighbours.
// (GCC does not move them out of the neighbour loop itself: the bodies' stores to d_ arrays
// may alias the d_ arrays they read, so it reloads and divides at every pair.)
//
// An expression is source-only when it is built of
//   - s_NAME[s_idx] (a source property at the pair's source index, nothing else as index),
//   - literals, t, dt and the equation's scalars (constant during an evaluation),
//   - locals declared with a source-only initial value and never assigned afterwards
//     (`double rhoj = s_rho[s_idx];`),
//   - + - * / and unary minus in floating point (no integer division: it could trap on a
//     particle that is no neighbour), casts, and calls of the allowed math functions.
// It is worth hoisting when it is of type double and divides or calls sqrt, pow, exp, ...
// (a load then replaces the costliest scalar operations); only the outermost such expression
// is recorded. Evaluating it for every source particle is harmless: floating-point
// operations do not trap, and the value is the one the pair would compute, bit for bit (the
// same operations in the same order, the solvers are built with -ffp-contract=off).
#include "body/AssignedLocals.h"
#include "body/BodyBatch.h"

#include "clang/AST/ASTContext.h"

#include <algorithm>
#include <map>

namespace sphc::body_detail {

namespace {

// Math functions whose call costs far more than a load (fabs, fmin, floor, ... do not).
bool isCostly(llvm::StringRef name) {
  static const std::set<std::string> cheap = {"fabs", "fmin", "fmax", "floor", "ceil",
                                              "copysign", "round", "trunc"};
  return !cheap.count(name.str());
}

class SourceOnlyFinder : public AssignedLocalsVisitor<SourceOnlyFinder> {
 public:
  // side: "s" (source-only: s_NAME[s_idx]) or "d" (destination-only: d_NAME[d_idx], of
  // properties the body does not write).
  SourceOnlyFinder(const BodySource& body, const SourceRangeOf& rangeOf, const std::string& side,
                   const std::set<std::string>& written)
      : body_(body), rangeOf_(rangeOf), prefix_(side + "_"), index_(side + "_idx"),
        written_(written) {}

  std::vector<SourceOnlySite> find(clang::FunctionDecl* fn) {
    TraverseStmt(fn->getBody());  // locals and what is assigned
    walk(fn->getBody());
    return std::move(sites_);
  }

  // --- the locals and what is assigned (first walk) ---
  bool VisitVarDecl(clang::VarDecl* v) {
    if (!llvm::isa<clang::ParmVarDecl>(v) && v->isLocalVarDecl()) order_[v] = order_.size();
    return true;
  }
  // (VisitBinaryOperator, VisitUnaryOperator: the assigned locals, AssignedLocals.h.)

 private:
  bool isParam(const clang::DeclRefExpr* ref, llvm::StringRef name) const {
    return llvm::isa<clang::ParmVarDecl>(ref->getDecl()) && ref->getDecl()->getName() == name;
  }

  // A local whose value is the same wherever it is read: a scalar of arithmetic type with a
  // source-only initial value, never assigned.
  bool sourceOnlyLocal(const clang::VarDecl* v) {
    if (auto it = localMemo_.find(v); it != localMemo_.end()) return it->second;
    localMemo_[v] = false;  // (no cycles in C, but be safe)
    bool ok = order_.count(v) && !assigned(v) && v->getInit() &&
              v->getType()->isArithmeticType() && !v->getType().isVolatileQualified() &&
              rangeOf_(v->getInit(), dummyBegin_, dummyEnd_) && sourceOnly(v->getInit());
    return localMemo_[v] = ok;
  }

  bool sourceOnly(const clang::Expr* e) {
    if (auto it = memo_.find(e); it != memo_.end()) return it->second;
    bool ok = classify(e);
    memo_[e] = ok;
    return ok;
  }

  bool classify(const clang::Expr* e) {
    if (llvm::isa<clang::FloatingLiteral>(e) || llvm::isa<clang::IntegerLiteral>(e)) return true;
    if (auto* p = llvm::dyn_cast<clang::ParenExpr>(e)) return sourceOnly(p->getSubExpr());
    if (auto* c = llvm::dyn_cast<clang::CastExpr>(e)) {
      if (!llvm::isa<clang::ImplicitCastExpr>(c) && !llvm::isa<clang::CStyleCastExpr>(c))
        return false;
      return c->getType()->isArithmeticType() && sourceOnly(c->getSubExpr());
    }
    if (auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(e)) {
      const clang::ValueDecl* d = ref->getDecl();
      const std::string name = d->getName().str();
      if (auto* v = llvm::dyn_cast<clang::VarDecl>(d); v && !llvm::isa<clang::ParmVarDecl>(v))
        return sourceOnlyLocal(v);
      if (!llvm::isa<clang::ParmVarDecl>(d)) return false;
      const NameRole role = nameRole(body_, name);
      return role == NameRole::Time || role == NameRole::TimeStep || role == NameRole::Scalar;
    }
    if (auto* a = llvm::dyn_cast<clang::ArraySubscriptExpr>(e)) {
      auto* base = llvm::dyn_cast<clang::DeclRefExpr>(a->getBase()->IgnoreParenImpCasts());
      auto* idx = llvm::dyn_cast<clang::DeclRefExpr>(a->getIdx()->IgnoreParenImpCasts());
      return base && idx && llvm::isa<clang::ParmVarDecl>(base->getDecl()) &&
             base->getDecl()->getName().startswith(prefix_) &&
             isPropertyName(base->getDecl()->getName()) &&
             !written_.count(base->getDecl()->getName().drop_front(2).str()) &&
             isParam(idx, index_) && a->getType()->isArithmeticType();
    }
    if (auto* u = llvm::dyn_cast<clang::UnaryOperator>(e))
      return (u->getOpcode() == clang::UO_Minus || u->getOpcode() == clang::UO_Plus) &&
             u->getType()->isRealFloatingType() && sourceOnly(u->getSubExpr());
    if (auto* b = llvm::dyn_cast<clang::BinaryOperator>(e)) {
      const auto op = b->getOpcode();
      return (op == clang::BO_Add || op == clang::BO_Sub || op == clang::BO_Mul ||
              op == clang::BO_Div) &&
             b->getType()->isRealFloatingType() && sourceOnly(b->getLHS()) &&
             sourceOnly(b->getRHS());
    }
    if (auto* call = llvm::dyn_cast<clang::CallExpr>(e)) {
      const clang::FunctionDecl* fn = call->getDirectCallee();
      if (!fn) return false;
      if (!isMathOrKernelFunction(fn->getName().str())) return false;
      for (const clang::Expr* arg : call->arguments())
        if (!sourceOnly(arg)) return false;
      return true;
    }
    return false;
  }

  // Whether a source-only expression does work worth a load: a division or a costly call
  // (not counting its locals, whose own values the body computes anyway).
  bool costly(const clang::Stmt* s) const {
    if (auto* b = llvm::dyn_cast<clang::BinaryOperator>(s); b && b->getOpcode() == clang::BO_Div)
      return true;
    if (auto* call = llvm::dyn_cast<clang::CallExpr>(s))
      if (const clang::FunctionDecl* fn = call->getDirectCallee(); fn && isCostly(fn->getName()))
        return true;
    for (const clang::Stmt* c : s->children())
      if (c && costly(c)) return true;
    return false;
  }

  // The outermost source-only, costly expressions of type double.
  void walk(clang::Stmt* s) {
    if (!s) return;
    if (auto* e = llvm::dyn_cast<clang::Expr>(s)) {
      if (e->getType()->isSpecificBuiltinType(clang::BuiltinType::Double) && !e->isLValue() &&
          sourceOnly(e) && costly(e) && record(e))
        return;
    }
    for (clang::Stmt* c : s->children()) walk(c);
  }

  bool record(const clang::Expr* e) {
    SourceOnlySite site;
    if (!rangeOf_(e, site.begin, site.end)) return false;
    // The locals it reads (and those their values read), in order of declaration.
    std::set<const clang::VarDecl*> locals;
    std::vector<const clang::Expr*> todo = {e};
    while (!todo.empty()) {
      const clang::Expr* x = todo.back();
      todo.pop_back();
      collect(x, locals, site, todo);
    }
    if (!appendSiteLocals(locals, order_, rangeOf_, site)) return false;
    sites_.push_back(site);
    return true;
  }

  void collect(const clang::Stmt* s, std::set<const clang::VarDecl*>& locals, SourceOnlySite& site,
               std::vector<const clang::Expr*>& todo) {
    if (auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(s)) {
      const clang::ValueDecl* d = ref->getDecl();
      const std::string name = d->getName().str();
      if (auto* v = llvm::dyn_cast<clang::VarDecl>(d); v && !llvm::isa<clang::ParmVarDecl>(v)) {
        if (locals.insert(v).second) todo.push_back(v->getInit());
      } else {
        noteParameterUse(body_, name, site);
      }
    }
    for (const clang::Stmt* c : s->children())
      if (c) collect(c, locals, site, todo);
  }

  const BodySource& body_;
  const SourceRangeOf& rangeOf_;
  const std::string prefix_, index_;        // s_ and s_idx, or d_ and d_idx
  const std::set<std::string>& written_;    // properties of that side the body writes
  std::map<const clang::VarDecl*, size_t> order_;  // local -> order of declaration
  std::map<const clang::Expr*, bool> memo_;
  std::map<const clang::VarDecl*, bool> localMemo_;
  unsigned dummyBegin_ = 0, dummyEnd_ = 0;
  std::vector<SourceOnlySite> sites_;
};

}  // namespace

std::vector<SourceOnlySite> findSourceOnlySites(const BodySource& body, clang::FunctionDecl* fn,
                                                const SourceRangeOf& rangeOf) {
  if (body.kind != BodyKind::Loop || !fn->hasBody()) return {};
  const std::set<std::string> none;
  return SourceOnlyFinder(body, rangeOf, "s", none).find(fn);
}

std::vector<SourceOnlySite> findDestinationOnlySites(const BodySource& body,
                                                     clang::FunctionDecl* fn,
                                                     const SourceRangeOf& rangeOf,
                                                     const std::set<std::string>& written) {
  if (body.kind != BodyKind::Loop || !fn->hasBody()) return {};
  return SourceOnlyFinder(body, rangeOf, "d", written).find(fn);
}

}  // namespace sphc::body_detail
