// The AST walk over one equation, stepper or helper body: the facts the analysis passes need
// (property reads and writes, pair quantities, t/dt, scalars) and sphc's portability rules.
#include "body/BodyBatch.h"

#include "clang/AST/ASTContext.h"
#include "clang/AST/RecursiveASTVisitor.h"
#include "clang/Lex/Lexer.h"
#include "llvm/ADT/StringRef.h"

#include <map>
#include <set>

namespace sphc::body_detail {

namespace {

// The AST walk over one body: facts, and sphc's portability rules.
class BodyChecker : public clang::RecursiveASTVisitor<BodyChecker> {
 public:
  BodyChecker(Batch& batch, int index, const clang::SourceManager& sm)
      : batch_(batch), i_(index), sm_(sm), body_(batch.body(index)), facts_(batch.facts[index]) {}

  void check(clang::FunctionDecl* fn) {
    ctx_ = &fn->getASTContext();
    batch_.state[i_].checked = true;
    if (body_.kind == BodyKind::Function) checkSignature(fn);
    TraverseStmt(fn->getBody());
    if (returnsValue(body_.kind) && !returnsValue_) batch_.reportMissingReturn(i_);
    // A name `fma` of the body's own (a local, a scalar) would hide OpenCL's fma: as written.
    for (clang::ParmVarDecl* p : fn->parameters()) namesFma_ |= p->getName() == "fma";
    if (namesFma_) facts_.multiplyAdds.clear();
    if (namesFma_) factors_.clear();
    if (batch_.state[i_].errors == 0) {
      findZeroFactors(fn, factors_, facts_.multiplyAdds);
      SourceRangeOf range = [&](const clang::Stmt* e, unsigned& b, unsigned& en) {
        return textRange(e, b, en);
      };
      facts_.sourceOnly = findSourceOnlySites(body_, fn, range);
      std::set<std::string> written;
      for (const PropAccess& w : facts_.dWrites) written.insert(w.prop);
      facts_.destinationOnly = findDestinationOnlySites(body_, fn, range, written);
      facts_.pairShared = findPairSharedSites(body_, fn, range);
      for (size_t k = 0; k < facts_.pairShared.size(); ++k) facts_.pairShared[k].id = static_cast<int>(k);
      facts_.vanishesOnSelfPair = vanishesOnSelfPair(body_, fn);
      facts_.vanishesAtSupport = vanishesAtSupport(body_, fn);
    }
  }

  // --- facts ---

  bool VisitBinaryOperator(clang::BinaryOperator* op) {
    if (op->isAssignmentOp()) markWritten(op->getLHS(), op->isCompoundAssignmentOp());
    if (recovering_ == 0) recordMultiplyAdd(op);
    return true;
  }

  // The statements of a block (visited before them): a compound assignment among them is
  // a statement of its own (MultiplyAddSite::statement).
  bool VisitCompoundStmt(clang::CompoundStmt* c) {
    for (clang::Stmt* s : c->body()) statements_.insert(s);
    return true;
  }

  bool VisitUnaryOperator(clang::UnaryOperator* op) {
    if (op->isIncrementDecrementOp()) markWritten(op->getSubExpr(), /*alsoRead=*/true);
    if (op->getOpcode() == clang::UO_AddrOf)
      error(op->getOperatorLoc(), "'&' (address-of) is not allowed in bodies: there are no "
                                  "pointers; use the value or index the property directly");
    return true;
  }

  bool VisitArraySubscriptExpr(clang::ArraySubscriptExpr* e) {
    if (body_.kind == BodyKind::Function) return true;  // no properties in helpers
    auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(e->getBase()->IgnoreParenImpCasts());
    if (!ref || !isPropertyParam(ref)) return true;
    indexed_.insert(ref);
    std::string name = ref->getDecl()->getName().str();
    std::string prop = name.substr(2);
    llvm::SMLoc loc = sph(e->getBeginLoc());
    auto w = written_.find(e);
    bool isWrite = w != written_.end(), isRead = !isWrite || w->second;
    llvm::SMLoc end = sph(e->getRBracketLoc());
    if (loc.isValid() && end.isValid() && body_.start.isValid() &&
        end.getPointer() >= loc.getPointer()) {
      unsigned b = static_cast<unsigned>(loc.getPointer() - body_.start.getPointer());
      unsigned en = static_cast<unsigned>(end.getPointer() - body_.start.getPointer()) + 1;
      if (en <= body_.text.size() && body_.text.compare(b, name.size(), name) == 0)
        facts_.sites.push_back({prop, name[0] == 's', isWrite, b, en});
    }
    if (name[0] == 's') {
      if (!seesSources(body_.kind)) batch_.reportOutsideLoop(i_, loc, name);
      else if (isRead) record(facts_.sReads, prop, loc);
      // Writes to s_ elements are rejected by Clang (const) and reported by the forwarder.
    } else {
      if (isRead) record(facts_.dReads, prop, loc);
      if (isWrite) record(facts_.dWrites, prop, loc);
    }
    return true;
  }

  bool VisitDeclRefExpr(clang::DeclRefExpr* e) {
    clang::ValueDecl* decl = e->getDecl();
    if (llvm::isa<clang::FunctionDecl>(decl)) {
      if (!callees_.count(e) && recovering_ == 0)
        error(e->getLocation(), "a function can only be called in a body, not used as a value");
      return true;
    }
    if (!llvm::isa<clang::ParmVarDecl>(decl)) return true;
    if (body_.kind == BodyKind::Function) return true;  // its parameters are the user's
    std::string name = decl->getName().str();
    if (isPropertyParam(e)) {
      if (!indexed_.count(e) && recovering_ == 0)
        error(e->getLocation(), "property '" + name + "' must be indexed, e.g. " + name + "[" +
                                    name.substr(0, 2) + "idx]; there are no pointers in bodies");
      return true;
    }
    switch (nameRole(body_, name)) {
      case NameRole::Neighbours:
        if (body_.kind != BodyKind::LoopAll)
          batch_.reportOutsideLoop(i_, sph(e->getLocation()), name);
        break;
      case NameRole::PairQuantity:
      case NameRole::SourceIndex:
        if (body_.kind != BodyKind::Loop)
          batch_.reportOutsideLoop(i_, sph(e->getLocation()), name);
        else if (name != "s_idx")
          facts_.pairQuantities.insert(name);
        break;
      case NameRole::Time: facts_.usesT = true; break;
      case NameRole::TimeStep: facts_.usesDt = true; break;
      case NameRole::Scalar: facts_.scalarsUsed.insert(name); break;
      default: break;
    }
    return true;
  }

  bool VisitReturnStmt(clang::ReturnStmt* s) {
    if (s->getRetValue()) returnsValue_ = true;
    return true;
  }

  // Inside an expression Clang could not build (already an error), a call or a subscript need
  // not look like one: the "must be indexed" and "only called" rules are not checked there.
  bool TraverseRecoveryExpr(clang::RecoveryExpr* e) {
    ++recovering_;
    bool more = RecursiveASTVisitor::TraverseRecoveryExpr(e);
    --recovering_;
    return more;
  }

  // --- portability rules ---

  bool VisitCallExpr(clang::CallExpr* call) {
    clang::Expr* callee = call->getCallee()->IgnoreParenImpCasts();
    if (auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(callee)) callees_.insert(ref);
    clang::FunctionDecl* fn = call->getDirectCallee();
    if (fn && isAllowedMath(fn)) return true;
    if (int j = batch_.functionOf(sm_, fn); j >= 0) {
      if (j == i_)
        error(callee->getBeginLoc(), "function '" + fn->getName() + "' calls itself: recursion "
                                     "is not allowed (OpenCL C has none); use a loop");
      else
        checkArraySizes(call, fn);
      return true;
    }
    if (fn) {
      int j = batch_.functionNamed(fn->getName());
      if (j >= 0 && j != i_) {
        error(callee->getBeginLoc(), "function '" + fn->getName() + "' is declared after this "
                                     "one: a function may call only functions declared "
                                     "before it");
        return true;
      }
    }
    std::string list;
    for (const std::string& f : allowedMathFunctions()) list += (list.empty() ? "" : ", ") + f;
    std::string what = fn ? "call of '" + fn->getName().str() + "'" : std::string("this call");
    error(callee->getBeginLoc(), what + " is not allowed: bodies may call only the math.h "
                                        "functions " + list +
                                        ", the kernel's KERNEL_W(r, h), KERNEL_DWDR(r, h) "
                                        "and the .sph file's functions");
    return true;
  }

  bool VisitVarDecl(clang::VarDecl* v) {
    namesFma_ |= v->getName() == "fma";
    if (v->isStaticLocal())
      error(v->getLocation(), "'static' local variables are not allowed in bodies: a body keeps "
                              "no state between calls; use a property");
    else if (v->hasExternalStorage())
      error(v->getLocation(), "'extern' declarations are not allowed in bodies");
    if (containsPointer(v->getType()))
      error(v->getLocation(), "pointer variables are not allowed in bodies; use a local array "
                              "or index a property (d_NAME[d_idx])");
    return true;
  }

  bool VisitCStyleCastExpr(clang::CStyleCastExpr* e) {
    if (containsPointer(e->getTypeAsWritten()))
      error(e->getBeginLoc(), "pointer casts are not allowed in bodies");
    return true;
  }

  bool VisitGotoStmt(clang::GotoStmt* s) { return gotoError(s->getBeginLoc()); }
  bool VisitIndirectGotoStmt(clang::IndirectGotoStmt* s) { return gotoError(s->getBeginLoc()); }
  bool VisitAddrLabelExpr(clang::AddrLabelExpr* e) { return gotoError(e->getBeginLoc()); }

  bool VisitStringLiteral(clang::StringLiteral* e) {
    error(e->getBeginLoc(), "string literals are not allowed in bodies");
    return true;
  }

  bool VisitAsmStmt(clang::AsmStmt* s) {
    error(s->getBeginLoc(), "inline assembly is not allowed in bodies");
    return true;
  }

 private:
  // A helper's parameters: values or arrays (`double a[9]`), never pointers or `...`.
  void checkSignature(clang::FunctionDecl* fn) {
    for (clang::ParmVarDecl* p : fn->parameters()) {
      if (containsPointer(p->getOriginalType()))
        error(p->getLocation(), "pointer parameters are not allowed in functions; declare an "
                                "array parameter, e.g. 'double a[3]'");
      else if (p->getOriginalType()->isIncompleteArrayType())
        error(p->getLocation(), "an array parameter needs its size, e.g. 'double a[3]'");
    }
    if (fn->isVariadic())
      error(fn->getLocation(), "variadic functions ('...') are not allowed");
  }

  // An array argument must be at least as long as the array parameter it is passed to (C
  // does not check; out of bounds is undefined on every backend).
  void checkArraySizes(clang::CallExpr* call, clang::FunctionDecl* fn) {
    for (unsigned k = 0; k < call->getNumArgs() && k < fn->getNumParams(); ++k) {
      const auto* want = llvm::dyn_cast_or_null<clang::ConstantArrayType>(
          fn->getParamDecl(k)->getOriginalType()->getAsArrayTypeUnsafe());
      if (!want) continue;
      const clang::Expr* arg = call->getArg(k)->IgnoreParenImpCasts();
      const auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(arg);
      if (!ref) continue;
      clang::QualType type = ref->getDecl()->getType();
      if (auto* p = llvm::dyn_cast<clang::ParmVarDecl>(ref->getDecl())) type = p->getOriginalType();
      const auto* have = llvm::dyn_cast_or_null<clang::ConstantArrayType>(
          type->getAsArrayTypeUnsafe());
      if (have && have->getSize().ult(want->getSize()))
        error(arg->getBeginLoc(), "array '" + ref->getDecl()->getName() + "' has " +
                                      llvm::Twine(have->getSize().getZExtValue()) +
                                      " elements; parameter '" +
                                      fn->getParamDecl(k)->getName() + "' of '" +
                                      fn->getName() + "' needs " +
                                      llvm::Twine(want->getSize().getZExtValue()));
    }
  }

  // --- fused multiply-adds (codegen/FusedMultiplyAdd.cpp prints them) ---

  // A product added to or subtracted from a value, everything of one floating type as written
  // (so that fma(a, b, c) computes in the type the sum did, in C++ and in OpenCL C alike).
  void recordMultiplyAdd(clang::BinaryOperator* op) {
    const clang::BinaryOperatorKind opc = op->getOpcode();
    const bool compound = opc == clang::BO_AddAssign || opc == clang::BO_SubAssign;
    if (opc != clang::BO_Add && opc != clang::BO_Sub && !compound) return;
    if (op->containsErrors()) return;  // reported; the body is not printed
    const clang::QualType type = op->getType();
    if (type.isNull() || !type->isRealFloatingType()) return;
    auto product = [&](clang::Expr* e) -> clang::BinaryOperator* {
      auto* m = llvm::dyn_cast<clang::BinaryOperator>(e->IgnoreParens());
      return m && m->getOpcode() == clang::BO_Mul && sameType(m->getType(), type) ? m : nullptr;
    };
    MultiplyAddSite s;
    clang::BinaryOperator* mul = nullptr;
    clang::Expr* productExpr = nullptr;
    clang::Expr* c = nullptr;
    if (compound) {
      auto* ca = llvm::cast<clang::CompoundAssignOperator>(op);
      if (!sameType(ca->getComputationLHSType(), type) ||
          !sameType(ca->getComputationResultType(), type) ||
          op->getLHS()->HasSideEffects(*ctx_))
        return;  // x is written twice in x = fma(a, b, x): it must be a plain place
      mul = product(op->getRHS());
      productExpr = op->getRHS();
      c = op->getLHS();
      s.form = opc == clang::BO_AddAssign ? MultiplyAddSite::AddAssign : MultiplyAddSite::SubAssign;
    } else if ((mul = product(op->getLHS()))) {
      productExpr = op->getLHS();
      c = op->getRHS();
      s.form = opc == clang::BO_Add ? MultiplyAddSite::ProductPlus : MultiplyAddSite::ProductMinus;
    } else if ((mul = product(op->getRHS()))) {
      productExpr = op->getRHS();
      c = op->getLHS();
      s.form = opc == clang::BO_Add ? MultiplyAddSite::PlusProduct : MultiplyAddSite::MinusProduct;
    }
    if (!mul) return;
    clang::Expr* a = mul->getLHS();
    clang::Expr* b = mul->getRHS();
    for (clang::Expr* e : {a, b, c})
      if (!sameType(e->IgnoreImpCasts()->getType(), type)) return;  // e.g. `2 * x + y`
    if (!textRange(op, s.begin, s.end) || !textRange(productExpr, s.productBegin, s.productEnd) ||
        !textRange(a, s.aBegin, s.aEnd) || !textRange(b, s.bBegin, s.bEnd) ||
        !textRange(c, s.cBegin, s.cEnd) || !textOffset(mul->getOperatorLoc(), s.mulOp) ||
        !textOffset(op->getOperatorLoc(), s.addOp))
      return;
    llvm::StringRef text(body_.text);
    llvm::StringRef opText = clang::BinaryOperator::getOpcodeStr(opc);
    if (text.substr(s.mulOp, 1) != "*" || text.substr(s.addOp, opText.size()) != opText) return;
    clang::Expr* negated = s.form == MultiplyAddSite::ProductMinus ? c
                           : s.form == MultiplyAddSite::MinusProduct ||
                                   s.form == MultiplyAddSite::SubAssign
                               ? a
                               : nullptr;
    if (negated) s.parenthesizeNegated = !isPrimary(negated);
    s.statement = compound && statements_.count(op);
    facts_.multiplyAdds.push_back(s);
    factors_.push_back({a, b});
  }

  bool sameType(clang::QualType x, clang::QualType y) const {
    return !x.isNull() && !y.isNull() && ctx_->hasSameUnqualifiedType(x, y);
  }

  // An operand that a unary minus in front of it negates as a whole: `-x`, `-d_p[d_idx]`.
  static bool isPrimary(const clang::Expr* e) {
    e = e->IgnoreImpCasts();
    return llvm::isa<clang::DeclRefExpr>(e) || llvm::isa<clang::ArraySubscriptExpr>(e) ||
           llvm::isa<clang::CallExpr>(e) || llvm::isa<clang::ParenExpr>(e) ||
           llvm::isa<clang::FloatingLiteral>(e) || llvm::isa<clang::IntegerLiteral>(e);
  }

  // The offset in the body's text of a location in it (a macro such as M_PI: where it is
  // written).
  bool textOffset(clang::SourceLocation loc, unsigned& off) const {
    if (loc.isInvalid() || !body_.start.isValid()) return false;
    loc = sm_.getExpansionLoc(loc);
    if (batch_.bodyAt(sm_, loc) != i_) return false;
    llvm::SMLoc at = sph(loc);
    if (!at.isValid() || at.getPointer() < body_.start.getPointer()) return false;
    off = static_cast<unsigned>(at.getPointer() - body_.start.getPointer());
    return off < body_.text.size();
  }

  // text[begin, end) is the expression, from its first token to the end of its last.
  bool textRange(const clang::Stmt* e, unsigned& begin, unsigned& end) const {
    clang::SourceLocation last = sm_.getExpansionLoc(e->getEndLoc());
    if (!textOffset(e->getBeginLoc(), begin) || !textOffset(last, end)) return false;
    end += clang::Lexer::MeasureTokenLength(last, sm_, ctx_->getLangOpts());
    return begin < end && end <= body_.text.size();
  }

  llvm::SMLoc sph(clang::SourceLocation loc) const { return batch_.toSph(sm_, loc, i_); }
  void error(clang::SourceLocation loc, const llvm::Twine& msg) { batch_.error(i_, sph(loc), msg); }

  bool gotoError(clang::SourceLocation loc) {
    error(loc, "'goto' is not allowed in bodies; use if, for, while, break and continue");
    return true;
  }

  static bool isPropertyParam(const clang::DeclRefExpr* ref) {
    return llvm::isa<clang::ParmVarDecl>(ref->getDecl()) &&
           isPropertyName(ref->getDecl()->getName());
  }

  // A math function declared by the prelude (not only implicitly or by a body itself). The
  // prelude's declaration of a library builtin such as sqrt redeclares Clang's implicit one.
  bool isAllowedMath(const clang::FunctionDecl* fn) const {
    if (!isMathOrKernelFunction(fn->getName().str())) return false;
    for (const clang::FunctionDecl* d : fn->redecls())
      if (!d->isImplicit() && batch_.bodyAt(sm_, d->getLocation()) < 0) return true;
    return false;
  }

  static bool containsPointer(clang::QualType type) {
    for (const clang::Type* t = type.getTypePtrOrNull(); t;) {
      if (t->isPointerType()) return true;
      const clang::ArrayType* a = t->getAsArrayTypeUnsafe();
      if (!a) return false;
      t = a->getElementType().getTypePtrOrNull();
    }
    return false;
  }

  // `lhs` is assigned to (and also read, for compound assignment and ++/--).
  void markWritten(clang::Expr* lhs, bool alsoRead) {
    if (auto* e = llvm::dyn_cast<clang::ArraySubscriptExpr>(lhs->IgnoreParens()))
      written_[e] = alsoRead;
    // An equation state assigned (only `converged` declares them writable).
    if (auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(lhs->IgnoreParens()))
      if (llvm::isa<clang::ParmVarDecl>(ref->getDecl()) &&
          isState(body_, ref->getDecl()->getName().str()))
        facts_.statesWritten.insert(ref->getDecl()->getName().str());
  }

  static void record(std::vector<PropAccess>& list, const std::string& prop, llvm::SMLoc loc) {
    for (const PropAccess& a : list)
      if (a.prop == prop) return;
    list.push_back({prop, loc});
  }

  Batch& batch_;
  int i_;
  const clang::SourceManager& sm_;
  const clang::ASTContext* ctx_ = nullptr;
  const BodySource& body_;
  BodyFacts& facts_;
  bool returnsValue_ = false;
  int recovering_ = 0;  // depth of RecoveryExprs being traversed
  bool namesFma_ = false;  // the body declares something named `fma`
  std::vector<ProductFactors> factors_;
  std::set<const clang::Stmt*> statements_;  // of the blocks visited (VisitCompoundStmt)  // of facts_.multiplyAdds, in order (ZeroTerms.cpp)
  std::map<const clang::ArraySubscriptExpr*, bool> written_;  // -> also read
  std::set<const clang::DeclRefExpr*> indexed_;  // d_/s_ references that are subscripted
  std::set<const clang::DeclRefExpr*> callees_;  // function references that are called
};

}  // namespace

void checkBodyFunction(Batch& batch, int index, const clang::SourceManager& sm,
                       clang::FunctionDecl* fn) {
  BodyChecker(batch, index, sm).check(fn);
}

}  // namespace sphc::body_detail
