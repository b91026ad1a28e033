// The locals of a loop body that are assigned after their declaration: `x = e`, `x += e` (every
// assignment operator), `++x`, `x--`, and `&x` (the address taken: it may be written through).
// A local that is not is the value of its initialiser wherever it is read, which the body
// analyses use: SelfPair.cpp (a local declared from a zero stays a zero) and SourceOnly.cpp
// (a local declared from a source-only value is source-only). One visitor for both: a CRTP
// base of their RecursiveASTVisitor, whose VisitBinaryOperator and VisitUnaryOperator collect
// the assigned locals during the visitor's first TraverseStmt of the body (the derived class
// may add Visit* methods of other nodes, e.g. VisitVarDecl).
#pragma once

#include "clang/AST/Expr.h"
#include "clang/AST/RecursiveASTVisitor.h"

#include <set>

namespace sphc::body_detail {

template <typename Derived>
class AssignedLocalsVisitor : public clang::RecursiveASTVisitor<Derived> {
 public:
  bool VisitBinaryOperator(clang::BinaryOperator* op) {
    if (op->isAssignmentOp()) markAssigned(op->getLHS());
    return true;
  }
  bool VisitUnaryOperator(clang::UnaryOperator* op) {
    if (op->isIncrementDecrementOp() || op->getOpcode() == clang::UO_AddrOf)
      markAssigned(op->getSubExpr());
    return true;
  }

 protected:
  // Whether v is assigned after its declaration (after the traversal).
  bool assigned(const clang::VarDecl* v) const { return assigned_.count(v) > 0; }

 private:
  void markAssigned(clang::Expr* e) {
    if (auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(e->IgnoreParenImpCasts()))
      if (auto* v = llvm::dyn_cast<clang::VarDecl>(ref->getDecl())) assigned_.insert(v);
  }

  std::set<const clang::VarDecl*> assigned_;
};

}  // namespace sphc::body_detail
