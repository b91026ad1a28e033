// Values a pair shares (BodyFacts::pairShared): subexpressions of a loop body whose value for
// the mirrored pair (destination s_idx, source d_idx: XIJ_ji, VIJ_ji, DWIJ_ji, d_NAME <->
// s_NAME) is the same double, or exactly its negation, so that where a pair is evaluated once
// for both particles (codegen/SymmetricPairs.cpp) the printer computes it once and passes it
// to both calls (codegen/PairShared.cpp).
//
// Each expression is put in a canonical form twice, as written and mirrored: XIJ[k], VIJ[k],
// DWIJ[k] change sign, d_NAME[d_idx] and s_NAME[s_idx] swap, the symmetric pair quantities
// (R2IJ, RIJ, HIJ, WIJ, RHOIJ, RHOIJ1, EPS), scalars, t, dt and literals stay. The forms use
// only what holds bit for bit in IEEE round-to-nearest, node by node, never regrouping:
//   a * b = b * a, a + b = b + a, (-a) * b = -(a * b), (-a) / b = -(a / b),
//   a - b = -(b - a), fma(a, b, c) = fma(b, a, c), fma(-a, b, -c) = -fma(a, b, c),
//   but a * b + c (which the printer fuses into fma(a, b, c)) keeps its product and its
//   addend in their places: fma(a, b, c * d) is not fma(c, d, a * b),
//   f(x) of the same x (sqrt, exp, ... and the kernel), fabs(-x) = fabs(x),
//   a comparison of the same operands (c ? x : y where c is the same both ways).
// Locals declared once and never assigned stand for their initial values. An expression is
// symmetric when both forms are the same string with the same sign, antisymmetric when the
// signs differ. One exception to "the same double": x_i - x_j and x_j - x_i are both +0 where
// the coordinates are equal (not -0 and +0), so a value built from the differences may be a
// zero of the other sign in the mirrored call; a zero's sign changes a result only through a
// division by it or a function with a pole or a sign at 0, so a divisor or such an argument
// must not depend on XIJ, VIJ or DWIJ (fabs and sqrt may: sqrt(-0) = -0, fabs(-0) = +0).
//
// Recorded (the outermost ones, of type double, costing at least one operation, reading the
// pair): (1) expressions not inside a conditional statement or loop (evaluating them for
// every pair is what the body does); (2) an `if` without else at the body's top level whose
// condition is the same both ways and whose block only declares locals and assigns symmetric
// values to one local declared before it with a symmetric initial value (the viscosity's
// piij): the value of that local after the `if`; (3) in the block of an `if` without else
// at the body's top level whose condition is the same both ways and reads no local
// (FourtakasDensityDiffusion's `if (R2IJ > 0.0)`), outside any conditional or loop nested in
// it, also expressions that divide or call a function: the site records the condition
// (guardBegin, guardEnd) and its value is computed only where the condition holds, where the
// body reads it (so such a division is done once per pair, as the body would do it in each
// call). Properties of the pair are recorded through the sites (the condition's too); the
// printer keeps only sites whose properties no pair loop writes.
#include "body/BodyBatch.h"

#include "clang/AST/ASTContext.h"
#include "clang/AST/RecursiveASTVisitor.h"

#include <algorithm>
#include <map>

namespace sphc::body_detail {

namespace {

struct Canon {
  bool ok = false;
  std::string s;      // the canonical string (sign taken out)
  int sign = 1;       // the value is sign * s
  bool taint = false; // depends on XIJ, VIJ or DWIJ (a zero of either sign)
  bool pair = false;  // reads a pair quantity or a property
};

Canon fail() { return Canon{}; }

bool symmetricPairQuantity(const std::string& q) {
  static const std::set<std::string> sym = {"R2IJ", "RIJ", "HIJ", "WIJ", "RHOIJ", "RHOIJ1", "EPS"};
  return sym.count(q) > 0;
}
bool antisymmetricPairVector(const std::string& q) {
  return q == "XIJ" || q == "VIJ" || q == "DWIJ";
}

class PairSharedFinder : public clang::RecursiveASTVisitor<PairSharedFinder> {
 public:
  PairSharedFinder(const BodySource& body, const SourceRangeOf& rangeOf)
      : body_(body), rangeOf_(rangeOf) {}

  std::vector<SourceOnlySite> find(clang::FunctionDecl* fn) {
    TraverseStmt(fn->getBody());  // locals and what is assigned
    auto* top = llvm::dyn_cast<clang::CompoundStmt>(fn->getBody());
    if (!top) return {};
    zeroSignMatters_ = zeroSignMatters(fn->getBody());
    for (clang::Stmt* s : top->body()) {
      if (auto* i = llvm::dyn_cast<clang::IfStmt>(s)) {
        if (ifSite(i, top)) continue;
        if (guardable(i)) {  // rule (3)
          walk(i->getCond(), true);
          guard_ = i->getCond();
          walk(i->getThen(), true, false, true);
          guard_ = nullptr;
          continue;
        }
      }
      walk(s, false);
    }
    return std::move(sites_);
  }

  bool VisitVarDecl(clang::VarDecl* v) {
    if (!llvm::isa<clang::ParmVarDecl>(v) && v->isLocalVarDecl()) order_[v] = order_.size();
    return true;
  }
  bool VisitBinaryOperator(clang::BinaryOperator* op) {
    if (op->isAssignmentOp()) markAssigned(op->getLHS(), op);
    return true;
  }
  bool VisitUnaryOperator(clang::UnaryOperator* op) {
    if (op->isIncrementDecrementOp() || op->getOpcode() == clang::UO_AddrOf)
      markAssigned(op->getSubExpr(), nullptr);
    return true;
  }

 private:
  void markAssigned(clang::Expr* e, clang::BinaryOperator* op) {
    if (auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(e->IgnoreParenImpCasts()))
      if (auto* v = llvm::dyn_cast<clang::VarDecl>(ref->getDecl())) {
        assigned_.insert(v);
        assignments_[v].push_back(op);
      }
  }

  // A local that stands for its initial value: arithmetic, initialised, never assigned.
  bool fixedLocal(const clang::VarDecl* v) const {
    return order_.count(v) && !assigned_.count(v) && v->getInit() &&
           v->getType()->isArithmeticType() && !v->getType().isVolatileQualified();
  }

  Canon canon(const clang::Expr* e, bool mirror) {
    auto key = std::make_pair(e, mirror);
    if (auto it = memo_.find(key); it != memo_.end()) return it->second;
    Canon c = classify(e, mirror);
    memo_[key] = c;
    return c;
  }

  static Canon leaf(const std::string& s, bool pair = false) {
    Canon c;
    c.ok = true;
    c.s = s;
    c.pair = pair;
    return c;
  }

  Canon classify(const clang::Expr* e, bool mirror) {
    if (auto* f = llvm::dyn_cast<clang::FloatingLiteral>(e)) {
      llvm::SmallString<32> str;
      f->getValue().toString(str, 0, 0);
      return leaf(std::string(str));
    }
    if (auto* i = llvm::dyn_cast<clang::IntegerLiteral>(e))
      return leaf(std::to_string(i->getValue().getSExtValue()));
    if (auto* p = llvm::dyn_cast<clang::ParenExpr>(e)) return canon(p->getSubExpr(), mirror);
    if (auto* c = llvm::dyn_cast<clang::ImplicitCastExpr>(e)) {
      if (!c->getType()->isArithmeticType()) return fail();
      Canon x = canon(c->getSubExpr(), mirror);
      if (x.ok && c->getCastKind() != clang::CK_LValueToRValue && c->getCastKind() != clang::CK_NoOp)
        x.s = "(" + c->getType().getAsString() + ")" + x.s;
      return x;
    }
    if (auto* c = llvm::dyn_cast<clang::CStyleCastExpr>(e)) {
      if (!c->getType()->isArithmeticType()) return fail();
      Canon x = canon(c->getSubExpr(), mirror);
      if (x.ok) x.s = "(" + c->getType().getAsString() + ")" + x.s;
      return x;
    }
    if (auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(e)) {
      const clang::ValueDecl* d = ref->getDecl();
      if (auto* v = llvm::dyn_cast<clang::VarDecl>(d); v && !llvm::isa<clang::ParmVarDecl>(v))
        return fixedLocal(v) ? canon(v->getInit(), mirror) : fail();
      if (!llvm::isa<clang::ParmVarDecl>(d)) return fail();
      const std::string name = d->getName().str();
      switch (nameRole(body_, name)) {
        case NameRole::Time:
        case NameRole::TimeStep:
        case NameRole::Scalar: return leaf(name);
        case NameRole::PairQuantity:
          return symmetricPairQuantity(name) ? leaf(name, true) : fail();
        default: return fail();
      }
    }
    if (auto* a = llvm::dyn_cast<clang::ArraySubscriptExpr>(e)) {
      auto* base = llvm::dyn_cast<clang::DeclRefExpr>(a->getBase()->IgnoreParenImpCasts());
      if (!base || !llvm::isa<clang::ParmVarDecl>(base->getDecl()) ||
          !a->getType()->isArithmeticType())
        return fail();
      const std::string name = base->getDecl()->getName().str();
      const clang::Expr* idx = a->getIdx()->IgnoreParenImpCasts();
      if (antisymmetricPairVector(name)) {
        auto* lit = llvm::dyn_cast<clang::IntegerLiteral>(idx);
        if (!lit) return fail();
        Canon c = leaf(name + "[" + std::to_string(lit->getValue().getSExtValue()) + "]", true);
        c.sign = mirror ? -1 : 1;
        c.taint = true;
        return c;
      }
      auto* ix = llvm::dyn_cast<clang::DeclRefExpr>(idx);
      if (!ix || !isPropertyName(name) || !llvm::isa<clang::ParmVarDecl>(ix->getDecl()))
        return fail();
      const std::string prop = name.substr(2);
      const bool dest = name[0] == 'd';
      if (ix->getDecl()->getName() != (dest ? "d_idx" : "s_idx")) return fail();
      // Mirrored, the destination's property is the source's and the other way round.
      return leaf(((dest != mirror) ? "d_" : "s_") + prop, true);
    }
    if (auto* u = llvm::dyn_cast<clang::UnaryOperator>(e)) {
      if (!u->getType()->isRealFloatingType()) return fail();
      Canon x = canon(u->getSubExpr(), mirror);
      if (u->getOpcode() == clang::UO_Minus) x.sign = -x.sign;
      else if (u->getOpcode() != clang::UO_Plus) return fail();
      return x;
    }
    if (auto* b = llvm::dyn_cast<clang::BinaryOperator>(e)) {
      const auto op = b->getOpcode();
      if (!b->getType()->isRealFloatingType()) return fail();
      Canon l = canon(b->getLHS(), mirror), r = canon(b->getRHS(), mirror);
      if (!l.ok || !r.ok) return fail();
      Canon c;
      c.ok = true;
      c.taint = l.taint || r.taint;
      c.pair = l.pair || r.pair;
      switch (op) {
        case clang::BO_Mul:
          c.s = "(" + std::min(l.s, r.s) + "*" + std::max(l.s, r.s) + ")";
          c.sign = l.sign * r.sign;
          return c;
        case clang::BO_Div:
          if (r.taint) return fail();  // a zero's sign would give the other infinity
          c.s = "(" + l.s + "/" + r.s + ")";
          c.sign = l.sign * r.sign;
          return c;
        case clang::BO_Add:
        case clang::BO_Sub: {
          // A product and an addend: the printer may fuse them (left product first, as
          // BodyChecker's recordMultiplyAdd), and fma(a, b, c * d) is not fma(c, d, a * b).
          const int rs = op == clang::BO_Sub ? -1 : 1;
          if (product(b->getLHS())) return fused(l, r, rs);
          if (product(b->getRHS())) {
            Canon p = r;
            p.sign = rs * r.sign;
            return fused(p, l, 1);
          }
          return sum(l, r, rs, "+", "-");
        }
        default: return fail();
      }
    }
    if (auto* co = llvm::dyn_cast<clang::ConditionalOperator>(e)) {
      Canon cond = condition(co->getCond(), mirror);
      Canon x = canon(co->getTrueExpr(), mirror), y = canon(co->getFalseExpr(), mirror);
      if (!cond.ok || !x.ok || !y.ok || x.sign != y.sign) return fail();
      Canon c;
      c.ok = true;
      c.s = "(" + cond.s + "?" + x.s + ":" + y.s + ")";
      c.sign = x.sign;
      c.taint = x.taint || y.taint;
      c.pair = cond.pair || x.pair || y.pair;
      return c;
    }
    if (auto* call = llvm::dyn_cast<clang::CallExpr>(e)) {
      const clang::FunctionDecl* fn = call->getDirectCallee();
      if (!fn || !call->getType()->isRealFloatingType()) return fail();
      const std::string name = fn->getName().str();
      if (!isMathOrKernelFunction(name)) return fail();
      std::vector<Canon> args;
      for (const clang::Expr* arg : call->arguments()) {
        args.push_back(canon(arg, mirror));
        if (!args.back().ok) return fail();
      }
      if (name == "fma" && args.size() == 3) {
        Canon p;
        p.ok = true;
        p.s = "(" + std::min(args[0].s, args[1].s) + "*" + std::max(args[0].s, args[1].s) + ")";
        p.sign = args[0].sign * args[1].sign;
        p.taint = args[0].taint || args[1].taint;
        p.pair = args[0].pair || args[1].pair;
        return fused(p, args[2], 1);
      }
      Canon c;
      c.ok = true;
      c.s = name + "(";
      for (size_t k = 0; k < args.size(); ++k) {
        const Canon& a = args[k];
        c.pair = c.pair || a.pair;
        if (name == "fabs") {  // fabs(-x) = fabs(x), and +0 for either zero
          c.s += a.s;
          continue;
        }
        if (a.sign != 1) return fail();
        if (a.taint && name != "sqrt") return fail();
        c.taint = c.taint || a.taint;
        c.s += (k ? "," : "") + a.s;
      }
      c.s += ")";
      return c;
    }
    return fail();
  }

  // sign_l * l + rsign * sign_r * r, commuted into one form; a difference as (x - y) with the
  // lesser string first: x - y = -(y - x).
  static Canon sum(const Canon& l, const Canon& r, int rsign, const std::string& plus,
                   const std::string& minus) {
    Canon c;
    c.ok = true;
    c.taint = l.taint || r.taint;
    c.pair = l.pair || r.pair;
    const int rs = r.sign * rsign;
    if (l.sign == rs) {
      c.s = "(" + std::min(l.s, r.s) + plus + std::max(l.s, r.s) + ")";
      c.sign = l.sign;
      return c;
    }
    c.taint = true;  // a difference: x - x is +0 both ways, not a zero of the other sign
    if (l.s < r.s) {  // l.sign * (l - r)
      c.s = "(" + l.s + minus + r.s + ")";
      c.sign = l.sign;
    } else {  // rs * (r - l)
      c.s = "(" + r.s + minus + l.s + ")";
      c.sign = rs;
    }
    return c;
  }

  // A product that the printer may fuse with what is added to it (codegen/FusedMultiplyAdd.cpp).
  static bool product(const clang::Expr* e) {
    auto* m = llvm::dyn_cast<clang::BinaryOperator>(e->IgnoreParenImpCasts());
    return m && m->getOpcode() == clang::BO_Mul;
  }

  // p + rsign * c where p is a product that may be fused with c: fma(a, b, c) rounds once, so
  // a + b = b + a does not hold there (fma(a, b, c * d) and fma(c, d, a * b) differ). The form
  // keeps the product and the addend in their places; signs move as fma(-a, b, -c) =
  // -fma(a, b, c). (Unfused, round(round(a * b) + c) keeps them in place too.)
  static Canon fused(const Canon& p, const Canon& c, int rsign) {
    Canon f;
    f.ok = true;
    f.taint = p.taint || c.taint;
    f.pair = p.pair || c.pair;
    const int cs = c.sign * rsign;
    f.sign = p.sign;
    f.s = "fma(" + p.s + (p.sign == cs ? "+" : "-") + c.s + ")";
    if (p.sign != cs) f.taint = true;  // a difference: x - x is +0 both ways
    return f;
  }

  // A condition whose value is the same both ways: comparisons of operands that are the
  // same value both ways (not negated: a < b would become -a < -b), &&, ||, !.
  Canon condition(const clang::Expr* e, bool mirror) {
    e = e->IgnoreParenImpCasts();
    if (auto* u = llvm::dyn_cast<clang::UnaryOperator>(e); u && u->getOpcode() == clang::UO_LNot) {
      Canon x = condition(u->getSubExpr(), mirror);
      if (x.ok) x.s = "!" + x.s;
      return x;
    }
    auto* b = llvm::dyn_cast<clang::BinaryOperator>(e);
    if (!b) return fail();
    if (b->getOpcode() == clang::BO_LAnd || b->getOpcode() == clang::BO_LOr) {
      Canon l = condition(b->getLHS(), mirror), r = condition(b->getRHS(), mirror);
      if (!l.ok || !r.ok) return fail();
      Canon c = leaf("(" + l.s + (b->getOpcode() == clang::BO_LAnd ? "&&" : "||") + r.s + ")",
                     l.pair || r.pair);
      return c;
    }
    if (!b->isComparisonOp()) return fail();
    Canon l = canon(b->getLHS(), mirror), r = canon(b->getRHS(), mirror);
    if (!l.ok || !r.ok || l.sign != 1 || r.sign != 1) return fail();
    return leaf("(" + l.s + b->getOpcodeStr().str() + r.s + ")", l.pair || r.pair);
  }

  // Whether e has the same (sign 1) or the negated (sign -1) value for the mirrored pair.
  int shared(const clang::Expr* e) {
    Canon a = canon(e, false), b = canon(e, true);
    if (!a.ok || !b.ok || a.s != b.s || !a.pair) return 0;
    if (a.taint && zeroSignMatters_) return 0;  // see zeroSignMatters
    return a.sign * b.sign;
  }

  // A value built from the differences (XIJ, VIJ, DWIJ, d_X - s_X) may be a zero whose sign
  // the mirrored call would see flipped. Such a value is shared only where no zero's sign can
  // reach a result: the body divides by nothing, passes nothing to a function (but fabs and
  // fma) and stores (`=`, `*=`) nothing that is not known untouched by the differences.
  // (Sums are safe: +0 + -0 = +0.) A sum of a nonzero literal and such a value is known
  // untouched (absorbsZeroSign: c + 0 = c for either zero).
  bool zeroSignMatters(const clang::Stmt* s) {
    if (!s) return false;
    const auto unsafe = [&](const clang::Expr* e) {
      if (absorbsZeroSign(e)) return false;
      Canon c = canon(e, false);
      return !c.ok || c.taint;
    };
    if (auto* b = llvm::dyn_cast<clang::BinaryOperator>(s)) {
      if ((b->getOpcode() == clang::BO_Div || b->getOpcode() == clang::BO_DivAssign) &&
          unsafe(b->getRHS()))
        return true;
      if ((b->getOpcode() == clang::BO_Assign || b->getOpcode() == clang::BO_MulAssign) &&
          llvm::isa<clang::ArraySubscriptExpr>(b->getLHS()->IgnoreParenImpCasts()) &&
          unsafe(b->getRHS()))
        return true;
    }
    if (auto* call = llvm::dyn_cast<clang::CallExpr>(s)) {
      const clang::FunctionDecl* fn = call->getDirectCallee();
      const std::string name = fn ? fn->getName().str() : "";
      if (name != "fabs" && name != "fma")
        for (const clang::Expr* arg : call->arguments())
          if (unsafe(arg)) return true;
    }
    for (const clang::Stmt* c : s->children())
      if (zeroSignMatters(c)) return true;
    return false;
  }

  // c + x, x + c, c - x or x - c (through locals that stand for their initial values) with c
  // a nonzero finite literal and x an expression of the canonical forms (canon ok, tainted or
  // not): where x is a zero, of either sign, the value is c; elsewhere x is the same (or the
  // same shared value) both ways. So a zero's sign in x never reaches the value, and passing
  // it to a function, dividing by it or storing it is safe (FourtakasDensityDiffusion's
  // pow(1 + (p_a + dph) / B, 1 / gamma), whose dph and x . dw are then shared).
  bool absorbsZeroSign(const clang::Expr* e) {
    e = e->IgnoreParenImpCasts();
    if (auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(e)) {
      auto* v = llvm::dyn_cast<clang::VarDecl>(ref->getDecl());
      return v && !llvm::isa<clang::ParmVarDecl>(v) && fixedLocal(v) &&
             absorbsZeroSign(v->getInit());
    }
    auto* b = llvm::dyn_cast<clang::BinaryOperator>(e);
    if (!b || (b->getOpcode() != clang::BO_Add && b->getOpcode() != clang::BO_Sub) ||
        !b->getType()->isRealFloatingType())
      return false;
    const auto nonzeroLiteral = [](const clang::Expr* x) {
      auto* f = llvm::dyn_cast<clang::FloatingLiteral>(x->IgnoreParenImpCasts());
      return f && f->getValue().isFiniteNonZero();
    };
    const clang::Expr* other = nonzeroLiteral(b->getLHS())   ? b->getRHS()
                               : nonzeroLiteral(b->getRHS()) ? b->getLHS()
                                                             : nullptr;
    return other && canon(other, false).ok && canon(other, true).ok;
  }

  // Operations in the expression's own text (not through its locals).
  static int operations(const clang::Stmt* s) {
    int n = 0;
    if (llvm::isa<clang::CallExpr>(s)) ++n;
    if (auto* b = llvm::dyn_cast<clang::BinaryOperator>(s); b && !b->isAssignmentOp()) ++n;
    for (const clang::Stmt* c : s->children())
      if (c) n += operations(c);
    return n;
  }

  // Whether an expression divides or calls a function (other than fabs): computed for every
  // pair, it should be one the body computes for every pair.
  static bool costly(const clang::Stmt* s) {
    if (auto* b = llvm::dyn_cast<clang::BinaryOperator>(s); b && b->getOpcode() == clang::BO_Div)
      return true;
    if (auto* call = llvm::dyn_cast<clang::CallExpr>(s))
      if (const clang::FunctionDecl* fn = call->getDirectCallee();
          fn && fn->getName() != "fabs" && fn->getName() != "fma")
        return true;
    for (const clang::Stmt* c : s->children())
      if (c && costly(c)) return true;
    return false;
  }

  // conditional: inside an if or ?: (a site there is computed for every pair: only cheap
  // ones); loop: inside a loop (none: its locals change); guarded: directly in the block of
  // rule (3)'s `if` (guard_), where a costly site is computed under its condition.
  void walk(clang::Stmt* s, bool conditional, bool loop = false, bool guarded = false) {
    if (!s) return;
    if (auto* e = llvm::dyn_cast<clang::Expr>(s); e && !loop) {
      if (e->getType()->isSpecificBuiltinType(clang::BuiltinType::Double) && !e->isLValue() &&
          operations(e) > 0 && (!conditional || guarded || !costly(e))) {
        const bool underGuard = conditional && costly(e);
        if (int sign = shared(e); sign != 0 && record(e, sign, underGuard)) return;
      }
    }
    const auto* b = llvm::dyn_cast<clang::BinaryOperator>(s);
    const bool branch = llvm::isa<clang::IfStmt>(s) || llvm::isa<clang::ConditionalOperator>(s) ||
                        (b && (b->getOpcode() == clang::BO_LAnd || b->getOpcode() == clang::BO_LOr));
    loop = loop || llvm::isa<clang::ForStmt>(s) || llvm::isa<clang::WhileStmt>(s) ||
           llvm::isa<clang::DoStmt>(s) || llvm::isa<clang::SwitchStmt>(s);
    conditional = conditional || llvm::isa<clang::IfStmt>(s) ||
                  llvm::isa<clang::ConditionalOperator>(s);
    guarded = guarded && !branch && !loop;
    for (clang::Stmt* c : s->children()) walk(c, conditional, loop, guarded);
  }

  // underGuard: the site is computed under guard_'s condition (rule (3)).
  bool record(const clang::Expr* e, int sign, bool underGuard = false) {
    SourceOnlySite site;
    site.sign = sign;
    if (!rangeOf_(e, site.begin, site.end)) return false;
    if (!addLocals(e, site)) return false;
    if (underGuard) {
      if (!laneCallsOnly(e)) return false;
      if (!guard_ || !rangeOf_(guard_, site.guardBegin, site.guardEnd)) return false;
      if (!addLocals(guard_, site)) return false;  // none (guardable): its scalars, t, dt
    }
    sites_.push_back(site);
    return true;
  }

  // Rule (3): `if (cond) { ... }` at the top level, no else, cond the same both ways and
  // reading no local (the site's function tests it before anything else).
  bool guardable(const clang::IfStmt* i) {
    if (i->getElse() || i->getInit() || i->getConditionVariable()) return false;
    Canon c0 = condition(i->getCond(), false), c1 = condition(i->getCond(), true);
    if (!c0.ok || !c1.ok || c0.s != c1.s) return false;
    return !readsLocal(i->getCond());
  }

  // Whether the expression (through its locals' initial values) calls no function but the
  // math functions the SIMD lanes take (laneMathFunction, body/BodyAnalysis.h) and the
  // kernel's (KERNEL_*): a guarded site computes its calls outside the body's branch, where
  // the SIMD pair loops would refuse a call such as pow or exp (codegen/SimdPairs.cpp,
  // scalarMathCall, the same list: they take it only in a branch), so such a value stays in
  // the calls and the loops' choice stays what it was. A scene's own functions stay too.
  bool laneCallsOnly(const clang::Stmt* s) {
    if (auto* call = llvm::dyn_cast<clang::CallExpr>(s)) {
      const clang::FunctionDecl* fn = call->getDirectCallee();
      const std::string name = fn ? fn->getName().str() : "";
      if (!laneMathFunction(name) && name.rfind("KERNEL_", 0) != 0) return false;
    }
    if (auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(s))
      if (auto* v = llvm::dyn_cast<clang::VarDecl>(ref->getDecl());
          v && !llvm::isa<clang::ParmVarDecl>(v) && v->getInit() && !laneCallsOnly(v->getInit()))
        return false;
    for (const clang::Stmt* c : s->children())
      if (c && !laneCallsOnly(c)) return false;
    return true;
  }

  static bool readsLocal(const clang::Stmt* s) {
    if (auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(s))
      if (auto* v = llvm::dyn_cast<clang::VarDecl>(ref->getDecl()); v && !llvm::isa<clang::ParmVarDecl>(v))
        return true;
    for (const clang::Stmt* c : s->children())
      if (c && readsLocal(c)) return true;
    return false;
  }

  // The locals an expression (or statement) reads, and those their values read, in order of
  // declaration; `inside`: locals declared within the statement itself are not listed.
  bool addLocals(const clang::Stmt* root, SourceOnlySite& site,
                 const std::set<const clang::VarDecl*>& inside = {}) {
    std::set<const clang::VarDecl*> locals;
    std::vector<const clang::Stmt*> todo = {root};
    while (!todo.empty()) {
      const clang::Stmt* x = todo.back();
      todo.pop_back();
      collect(x, locals, site, todo, inside);
    }
    for (const clang::VarDecl* v : locals)
      if (!fixedLocal(v)) return false;
    return appendSiteLocals(locals, order_, rangeOf_, site);
  }

  void collect(const clang::Stmt* s, std::set<const clang::VarDecl*>& locals, SourceOnlySite& site,
               std::vector<const clang::Stmt*>& todo, const std::set<const clang::VarDecl*>& inside) {
    if (auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(s)) {
      const clang::ValueDecl* d = ref->getDecl();
      const std::string name = d->getName().str();
      if (auto* v = llvm::dyn_cast<clang::VarDecl>(d); v && !llvm::isa<clang::ParmVarDecl>(v)) {
        if (!inside.count(v) && locals.insert(v).second && v->getInit()) todo.push_back(v->getInit());
      } else {
        noteParameterUse(body_, name, site);
      }
    }
    for (const clang::Stmt* c : s->children())
      if (c) collect(c, locals, site, todo, inside);
  }

  // Rule (2): `double v = init; ... if (cond) { locals; v = expr; }` with cond the same both
  // ways and init, expr symmetric: the value of v after the if.
  bool ifSite(clang::IfStmt* i, clang::CompoundStmt* top) {
    if (i->getElse() || i->getInit() || i->getConditionVariable()) return false;
    if (!condition(i->getCond(), false).ok || !condition(i->getCond(), true).ok ||
        condition(i->getCond(), false).s != condition(i->getCond(), true).s)
      return false;
    auto* block = llvm::dyn_cast<clang::CompoundStmt>(i->getThen());
    if (!block) return false;
    const clang::VarDecl* result = nullptr;
    const clang::Expr* value = nullptr;
    std::set<const clang::VarDecl*> inside;
    for (clang::Stmt* s : block->body()) {
      if (auto* ds = llvm::dyn_cast<clang::DeclStmt>(s)) {
        for (clang::Decl* d : ds->decls()) {
          auto* v = llvm::dyn_cast<clang::VarDecl>(d);
          if (!v || !fixedLocal(v)) return false;
          inside.insert(v);
        }
        continue;
      }
      auto* as = llvm::dyn_cast<clang::BinaryOperator>(s);
      if (!as || as->getOpcode() != clang::BO_Assign || result) return false;
      auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(as->getLHS()->IgnoreParenImpCasts());
      auto* v = ref ? llvm::dyn_cast<clang::VarDecl>(ref->getDecl()) : nullptr;
      if (!v || llvm::isa<clang::ParmVarDecl>(v) || !order_.count(v) || !v->getInit() ||
          !v->getType()->isSpecificBuiltinType(clang::BuiltinType::Double))
        return false;
      result = v;
      value = as->getRHS();
    }
    if (!result || assignments_[result].size() != 1) return false;
    // Declared at the top level before the if, with a symmetric initial value (0.0).
    bool declaredBefore = false;
    for (clang::Stmt* s : top->body()) {
      if (s == i) break;
      if (auto* ds = llvm::dyn_cast<clang::DeclStmt>(s))
        for (clang::Decl* d : ds->decls()) declaredBefore = declaredBefore || d == result;
    }
    if (!declaredBefore) return false;
    Canon i0 = canon(result->getInit(), false), i1 = canon(result->getInit(), true);
    if (!i0.ok || !i1.ok || i0.s != i1.s || i0.sign != i1.sign) return false;
    Canon v0 = canon(value, false), v1 = canon(value, true);
    if (!v0.ok || !v1.ok || v0.s != v1.s || v0.sign != v1.sign || !v0.pair) return false;
    if ((v0.taint || i0.taint) && zeroSignMatters_) return false;
    SourceOnlySite site;
    site.sign = 1;
    site.result = result->getName().str();
    if (!rangeOf_(result->getInit(), site.begin, site.end)) return false;
    if (!rangeOf_(i, site.stmtBegin, site.stmtEnd)) return false;
    // The locals it reads, declared before it (the result's initial value too); the result
    // itself is declared by the site's function.
    inside.insert(result);
    if (!addLocals(i, site, inside) || !addLocals(result->getInit(), site, inside)) return false;
    std::set<std::string> seen;
    std::vector<SourceOnlySite::Local> unique;
    for (const auto& l : site.locals)
      if (seen.insert(l.name).second) unique.push_back(l);
    std::sort(unique.begin(), unique.end(), [](const auto& a, const auto& b) { return a.initBegin < b.initBegin; });
    site.locals = unique;
    sites_.push_back(site);
    return true;
  }

  const BodySource& body_;
  const SourceRangeOf& rangeOf_;
  std::map<const clang::VarDecl*, size_t> order_;
  std::set<const clang::VarDecl*> assigned_;
  std::map<const clang::VarDecl*, std::vector<clang::BinaryOperator*>> assignments_;
  std::map<std::pair<const clang::Expr*, bool>, Canon> memo_;
  std::vector<SourceOnlySite> sites_;
  bool zeroSignMatters_ = true;
  const clang::Expr* guard_ = nullptr;  // rule (3)'s condition while its block is walked
};

}  // namespace

std::vector<SourceOnlySite> findPairSharedSites(const BodySource& body, clang::FunctionDecl* fn,
                                                const SourceRangeOf& rangeOf) {
  if (body.kind != BodyKind::Loop || !fn->hasBody()) return {};
  return PairSharedFinder(body, rangeOf).find(fn);
}

}  // namespace sphc::body_detail
