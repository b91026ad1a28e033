// The parser, part 3: expressions (C precedence, calls, the conditional operator).
#include "frontend/Parser.h"
#include "frontend/ParseUtil.h"

#include "llvm/ADT/ScopeExit.h"
#include "llvm/ADT/StringExtras.h"

#include <cstdlib>

namespace sphc {

using ast::ExprPtr;
using namespace parse_detail;

namespace {

// Binary operators by C precedence, loosest first; 0 for any other token.
int binaryPrecedence(Token::Kind kind) {
  switch (kind) {
    case Token::OrOr: return 1;
    case Token::AndAnd: return 2;
    case Token::EqEq: case Token::NotEq: return 3;
    case Token::Less: case Token::LessEq: case Token::Greater: case Token::GreaterEq: return 4;
    case Token::Plus: case Token::Minus: return 5;
    case Token::Star: case Token::Slash: case Token::Percent: return 6;
    default: return 0;
  }
}

std::shared_ptr<ast::Expr> makeExpr(ast::Expr::Kind kind, const Token& tok) {
  auto e = std::make_shared<ast::Expr>();
  e->kind = kind;
  e->loc = tok.loc;
  return e;
}

}  // namespace


// ---------------------------------------------------------------------------------------------
// Expressions

bool Parser::enterNesting() {
  if (exprDepth_ >= kMaxNesting)
    return error(cur().loc, "expression nested too deeply (more than " +
                                llvm::Twine(kMaxNesting) + " levels)");
  ++exprDepth_;
  return true;
}

ExprPtr Parser::parseExpr() {
  if (!enterNesting()) return nullptr;
  auto leave = llvm::make_scope_exit([&] { leaveNesting(); });
  ExprPtr cond = parseBinary(1);
  if (!cond || !cur().is(Token::Question)) return cond;
  auto e = makeExpr(ast::Expr::Ternary, cur());
  advance();
  ExprPtr then = parseExpr();
  if (!then || !expect(Token::Colon, "in conditional expression")) return nullptr;
  ExprPtr otherwise = parseExpr();
  if (!otherwise) return nullptr;
  e->args = {cond, then, otherwise};
  return e;
}

ExprPtr Parser::parseBinary(int minPrecedence) {
  ExprPtr lhs = parseUnary();
  while (lhs) {
    int prec = binaryPrecedence(cur().kind);
    if (prec == 0 || prec < minPrecedence) break;
    auto e = makeExpr(ast::Expr::Binary, cur());
    e->op = cur().text.str();
    advance();
    ExprPtr rhs = parseBinary(prec + 1);
    if (!rhs) return nullptr;
    e->args = {lhs, rhs};
    lhs = e;
  }
  return lhs;
}

ExprPtr Parser::parseUnary() {
  if (!cur().is(Token::Minus) && !cur().is(Token::Plus) && !cur().is(Token::Not))
    return parsePrimary();
  if (!enterNesting()) return nullptr;
  auto leave = llvm::make_scope_exit([&] { leaveNesting(); });
  auto e = makeExpr(ast::Expr::Unary, cur());
  e->op = cur().text.str();
  advance();
  ExprPtr operand = parseUnary();
  if (!operand) return nullptr;
  e->args = {operand};
  return e;
}

ExprPtr Parser::parsePrimary() {
  switch (cur().kind) {
    case Token::Number: {
      auto e = makeExpr(ast::Expr::Number, cur());
      e->text = cur().text.str();
      e->number = std::strtod(e->text.c_str(), nullptr);
      advance();
      return e;
    }
    case Token::Identifier: {
      if (lex_.peek().is(Token::LParen)) return parseCall();
      auto e = makeExpr(ast::Expr::Name, cur());
      e->text = cur().text.str();
      advance();
      // `fluid.total`: an array's constant (its first value), as a Name "fluid.total"; sema
      // says where it may appear (group options start_idx, stop_idx, condition).
      if (cur().is(Token::Dot) && lex_.peek().is(Token::Identifier)) {
        advance();
        e->text += "." + cur().text.str();
        advance();
      }
      return e;
    }
    case Token::LParen:
      return parseParenthesised();
    default:
      error(cur().loc, "expected an expression, found " + describe(cur()));
      return nullptr;
  }
}

ExprPtr Parser::parseParenthesised() {
  llvm::SMLoc open = cur().loc;
  advance();
  ExprPtr e = parseExpr();
  if (!e) return nullptr;
  if (consumeIf(Token::RParen)) return e;
  if (report(cur().loc, "expected ')', found " + describe(cur())))
    diags_.note(open, "to match this '('");
  return nullptr;
}

ExprPtr Parser::parseCall() {
  auto e = makeExpr(ast::Expr::Call, cur());
  e->text = cur().text.str();
  advance();
  advance();  // '('
  if (consumeIf(Token::RParen)) return e;
  do {
    ExprPtr arg = parseExpr();
    if (!arg) return nullptr;
    e->args.push_back(std::move(arg));
  } while (consumeIf(Token::Comma));
  if (consumeIf(Token::RParen)) return e;
  error(cur().loc, "expected ',' or ')' in the arguments of " + quoted(e->text) + ", found " +
                       describe(cur()));
  return nullptr;
}

}  // namespace sphc
