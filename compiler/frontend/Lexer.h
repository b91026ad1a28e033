// The lexer of the declarative layer of .sph files. Keywords are contextual, so every word is
// an Identifier and the parser decides what it means. Bodies of methods are not tokenised:
// lexBody() hands back their raw text for Clang.
#pragma once

#include "frontend/AST.h"
#include "frontend/Diagnostics.h"

#include "llvm/ADT/StringRef.h"
#include "llvm/Support/SMLoc.h"

#include <string>

namespace sphc {

struct Token {
  enum Kind {
    Eof,
    Error,       // a lexical error, already reported (or suppressed) when it became current
    Identifier,
    Number,
    String,
    LBrace, RBrace, LParen, RParen, LBracket, RBracket,
    Semi, Comma, Assign, Dot, Question, Colon,
    Plus, Minus, Star, Slash, Percent,
    Less, LessEq, Greater, GreaterEq, EqEq, NotEq, AndAnd, OrOr, Not,
  };
  Kind kind = Eof;
  llvm::StringRef text;  // the characters as written
  llvm::SMLoc loc;       // the first character
  std::string value;     // String: the contents with escapes resolved
  std::string error;     // Error: the message reported for it

  bool is(Kind k) const { return kind == k; }
  bool isWord(llvm::StringRef word) const { return kind == Identifier && text == word; }
  llvm::SMLoc endLoc() const { return llvm::SMLoc::getFromPointer(text.end()); }
};

// How a token kind is written in messages: "';'", "identifier", "end of file".
std::string describe(Token::Kind kind);
// How a particular token is written in messages: "'foo'", "'3.5'", "end of file".
std::string describe(const Token& tok);

class Lexer {
 public:
  Lexer(DiagnosticEngine& diags, llvm::StringRef buffer);

  // The current token and the one after it.
  const Token& cur() const { return cur_; }
  const Token& peek();
  // Moves to the next token. A lexical error is reported when its token becomes current,
  // unless diagnostics are suppressed.
  void advance();

  // Positioned at a `{`: the raw text up to the matching `}`, skipping braces in strings,
  // character literals and comments; the current token becomes the one after the `}`.
  // `owner` names the body in the error for a missing `}` (e.g. "loop").
  ast::Body lexBody(llvm::StringRef owner);

  // While suppressed (error recovery), lexical errors and unclosed bodies are not reported.
  void setSuppressed(bool on) { suppressed_ = on; }
  // True once a lexical error consumed the rest of the file (unterminated comment, string or
  // body): errors at the end of file are consequences of it.
  bool hitEofByError() const { return eofByError_; }
  // Makes the current token the end of file (the parser gives up).
  void stop();

 private:
  Token lexToken();
  Token make(Token::Kind kind, const char* start, const char* end) const;
  Token makeError(const char* start, const char* end, std::string msg, bool reachesEof);
  Token lexNumber(const char* start);
  Token lexString(const char* start);
  // Skips whitespace and comments; false (with `err` set) on an unterminated comment.
  bool skipTrivia(Token& err);
  // From a `"` or `'`, the position after the closing quote (or the end of the line/buffer).
  const char* skipQuoted(const char* p) const;
  // From `/` followed by `/` or `*`, the position after the comment; null if unterminated.
  const char* skipComment(const char* p) const;
  void report(const Token& tok);

  DiagnosticEngine& diags_;
  const char* pos_;
  const char* end_;
  Token cur_;
  Token next_;
  bool hasNext_ = false;
  bool suppressed_ = false;
  bool eofByError_ = false;
};

}  // namespace sphc
