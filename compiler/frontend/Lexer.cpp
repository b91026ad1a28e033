#include "frontend/Lexer.h"

#include "llvm/ADT/StringExtras.h"

namespace sphc {

namespace {

bool isIdentStart(char c) { return llvm::isAlpha(c) || c == '_'; }
bool isIdentChar(char c) { return llvm::isAlnum(c) || c == '_'; }

const char* punctuationSpelling(Token::Kind kind) {
  switch (kind) {
    case Token::LBrace: return "{";
    case Token::RBrace: return "}";
    case Token::LParen: return "(";
    case Token::RParen: return ")";
    case Token::LBracket: return "[";
    case Token::RBracket: return "]";
    case Token::Semi: return ";";
    case Token::Comma: return ",";
    case Token::Assign: return "=";
    case Token::Dot: return ".";
    case Token::Question: return "?";
    case Token::Colon: return ":";
    case Token::Plus: return "+";
    case Token::Minus: return "-";
    case Token::Star: return "*";
    case Token::Slash: return "/";
    case Token::Percent: return "%";
    case Token::Less: return "<";
    case Token::LessEq: return "<=";
    case Token::Greater: return ">";
    case Token::GreaterEq: return ">=";
    case Token::EqEq: return "==";
    case Token::NotEq: return "!=";
    case Token::AndAnd: return "&&";
    case Token::OrOr: return "||";
    case Token::Not: return "!";
    default: return nullptr;
  }
}

}  // namespace

std::string describe(Token::Kind kind) {
  switch (kind) {
    case Token::Eof: return "end of file";
    case Token::Error: return "invalid token";
    case Token::Identifier: return "identifier";
    case Token::Number: return "number";
    case Token::String: return "string";
    default: return std::string("'") + punctuationSpelling(kind) + "'";
  }
}

std::string describe(const Token& tok) {
  switch (tok.kind) {
    case Token::Eof:
    case Token::Error: return describe(tok.kind);
    default: return "'" + tok.text.str() + "'";
  }
}

Lexer::Lexer(DiagnosticEngine& diags, llvm::StringRef buffer)
    : diags_(diags), pos_(buffer.begin()), end_(buffer.end()) {
  advance();
}

const Token& Lexer::peek() {
  if (!hasNext_) {
    next_ = lexToken();
    hasNext_ = true;
  }
  return next_;
}

void Lexer::advance() {
  if (cur_.is(Token::Eof) && cur_.loc.isValid()) return;
  cur_ = hasNext_ ? std::move(next_) : lexToken();
  hasNext_ = false;
  if (cur_.is(Token::Error)) report(cur_);
}

void Lexer::report(const Token& tok) {
  if (!suppressed_) diags_.error(tok.loc, tok.error);
}

void Lexer::stop() {
  pos_ = end_;
  hasNext_ = false;
  cur_ = make(Token::Eof, end_, end_);
}

Token Lexer::make(Token::Kind kind, const char* start, const char* end) const {
  Token tok;
  tok.kind = kind;
  tok.text = llvm::StringRef(start, end - start);
  tok.loc = llvm::SMLoc::getFromPointer(start);
  return tok;
}

Token Lexer::makeError(const char* start, const char* end, std::string msg, bool reachesEof) {
  Token tok = make(Token::Error, start, end);
  tok.error = std::move(msg);
  if (reachesEof) eofByError_ = true;
  return tok;
}

const char* Lexer::skipComment(const char* p) const {
  if (p[1] == '/') {
    while (p < end_ && *p != '\n') ++p;
    return p;
  }
  for (p += 2; p + 1 < end_; ++p)
    if (p[0] == '*' && p[1] == '/') return p + 2;
  return nullptr;
}

const char* Lexer::skipQuoted(const char* p) const {
  char quote = *p++;
  while (p < end_ && *p != quote && *p != '\n') p += (*p == '\\' && p + 1 < end_) ? 2 : 1;
  return (p < end_ && *p == quote) ? p + 1 : p;
}

bool Lexer::skipTrivia(Token& err) {
  while (pos_ < end_) {
    if (llvm::isSpace(*pos_)) {
      ++pos_;
    } else if (*pos_ == '/' && pos_ + 1 < end_ && (pos_[1] == '/' || pos_[1] == '*')) {
      const char* after = skipComment(pos_);
      if (!after) {
        err = makeError(pos_, pos_ + 2, "unterminated comment: missing '*/'", true);
        pos_ = end_;
        return false;
      }
      pos_ = after;
    } else {
      break;
    }
  }
  return true;
}

Token Lexer::lexNumber(const char* start) {
  const char* p = start;
  auto digits = [&] {
    const char* from = p;
    while (p < end_ && llvm::isDigit(*p)) ++p;
    return p != from;
  };
  bool valid = digits();
  if (p < end_ && *p == '.') {
    ++p;
    valid = digits() || valid;
  }
  if (valid && p < end_ && (*p == 'e' || *p == 'E')) {
    ++p;
    if (p < end_ && (*p == '+' || *p == '-')) ++p;
    valid = digits();
  }
  // A number runs into the letters, digits and dots that follow it: `1e`, `2x`, `1.2.3`.
  bool junk = false;
  while (p < end_ && (isIdentChar(*p) || *p == '.')) {
    ++p;
    junk = true;
  }
  if (!valid || junk) {
    llvm::StringRef text(start, p - start);
    return makeError(start, p, "invalid number '" + text.str() + "'", false);
  }
  return make(Token::Number, start, p);
}

Token Lexer::lexString(const char* start) {
  std::string value;
  const char* p = start + 1;
  while (p < end_ && *p != '"' && *p != '\n') {
    if (*p == '\\' && p + 1 < end_ && (p[1] == '"' || p[1] == '\\')) ++p;
    value += *p++;
  }
  if (p == end_ || *p != '"')
    return makeError(start, p, "unterminated string: missing '\"'", p == end_);
  Token tok = make(Token::String, start, p + 1);
  tok.value = std::move(value);
  return tok;
}

Token Lexer::lexToken() {
  Token err;
  if (!skipTrivia(err)) return err;
  const char* start = pos_;
  if (pos_ == end_) return make(Token::Eof, end_, end_);

  char c = *pos_;
  auto single = [&](Token::Kind kind) { return make(kind, start, ++pos_); };
  // `c` alone, or `c` followed by `second` as `pair`.
  auto maybePair = [&](char second, Token::Kind pair, Token::Kind alone) {
    if (pos_ + 1 < end_ && pos_[1] == second) {
      pos_ += 2;
      return make(pair, start, pos_);
    }
    return make(alone, start, ++pos_);
  };

  if (isIdentStart(c)) {
    while (pos_ < end_ && isIdentChar(*pos_)) ++pos_;
    return make(Token::Identifier, start, pos_);
  }
  if (llvm::isDigit(c) || (c == '.' && pos_ + 1 < end_ && llvm::isDigit(pos_[1]))) {
    Token tok = lexNumber(start);
    pos_ = tok.text.end();
    return tok;
  }
  if (c == '"') {
    Token tok = lexString(start);
    pos_ = tok.text.end();
    return tok;
  }
  switch (c) {
    case '{': return single(Token::LBrace);
    case '}': return single(Token::RBrace);
    case '(': return single(Token::LParen);
    case ')': return single(Token::RParen);
    case '[': return single(Token::LBracket);
    case ']': return single(Token::RBracket);
    case ';': return single(Token::Semi);
    case ',': return single(Token::Comma);
    case '.': return single(Token::Dot);
    case '?': return single(Token::Question);
    case ':': return single(Token::Colon);
    case '+': return single(Token::Plus);
    case '-': return single(Token::Minus);
    case '*': return single(Token::Star);
    case '/': return single(Token::Slash);
    case '%': return single(Token::Percent);
    case '=': return maybePair('=', Token::EqEq, Token::Assign);
    case '!': return maybePair('=', Token::NotEq, Token::Not);
    case '<': return maybePair('=', Token::LessEq, Token::Less);
    case '>': return maybePair('=', Token::GreaterEq, Token::Greater);
    default: break;
  }
  if ((c == '&' || c == '|') && pos_ + 1 < end_ && pos_[1] == c) {
    pos_ += 2;
    return make(c == '&' ? Token::AndAnd : Token::OrOr, start, pos_);
  }

  // A stray character; a multi-byte UTF-8 sequence counts as one.
  ++pos_;
  if (static_cast<unsigned char>(c) >= 0xC0)
    while (pos_ < end_ && (static_cast<unsigned char>(*pos_) & 0xC0) == 0x80) ++pos_;
  std::string shown = llvm::isPrint(c) ? std::string(1, c)
                                       : "\\x" + llvm::utohexstr(static_cast<unsigned char>(c));
  return makeError(start, pos_, "unexpected character '" + shown + "'", false);
}

ast::Body Lexer::lexBody(llvm::StringRef owner) {
  const Token open = cur_;
  ast::Body body;
  const char* p = open.text.end();
  body.start = llvm::SMLoc::getFromPointer(p);
  int depth = 1;
  while (p < end_) {
    char c = *p;
    if (c == '"' || c == '\'') {
      p = skipQuoted(p);
    } else if (c == '/' && p + 1 < end_ && (p[1] == '/' || p[1] == '*')) {
      p = skipComment(p);
      if (!p) break;
    } else if (c == '}' && --depth == 0) {
      body.text.assign(open.text.end(), p);
      pos_ = p + 1;
      hasNext_ = false;
      advance();
      return body;
    } else {
      if (c == '{') ++depth;
      ++p;
    }
  }
  if (!suppressed_)
    diags_.error(open.loc, "body of '" + owner + "' is not closed: missing '}'");
  eofByError_ = true;
  stop();
  return body;
}

}  // namespace sphc
