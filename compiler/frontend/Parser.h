// Recursive-descent parser of .sph files (docs/language.md) into the AST. Purely syntactic:
// no name resolution and no checks of meaning, which are Sema's. Errors go to the
// DiagnosticEngine; after one, the parser skips to the next `;`, `}` or top-level keyword so
// that one mistake gives one error, and it gives up after 20 errors.
#pragma once

#include "frontend/AST.h"
#include "frontend/Diagnostics.h"
#include "frontend/Lexer.h"

#include "llvm/ADT/FunctionExtras.h"
#include "llvm/ADT/StringRef.h"
#include "llvm/ADT/Twine.h"
#include "llvm/Support/SourceMgr.h"

#include <memory>
#include <optional>
#include <vector>

namespace sphc {

class Parser {
 public:
  Parser(DiagnosticEngine& diags, llvm::SourceMgr& sm, unsigned bufferId);

  // Always returns a module, partial if there were errors (see DiagnosticEngine).
  std::unique_ptr<ast::Module> parseModule();

  static constexpr unsigned kMaxErrors = 20;
  static constexpr unsigned kMaxNesting = 256;

 private:
  // Tokens.
  const Token& cur() const { return lex_.cur(); }
  bool atWord(llvm::StringRef word) const { return cur().isWord(word); }
  void advance();
  bool consumeIf(Token::Kind kind);
  // Consumes a `kind` token or reports "expected 'kind' <context>" (a missing ';' is reported
  // just after the previous token, as Clang does).
  bool expect(Token::Kind kind, const llvm::Twine& context);
  bool parseIdent(ast::Ident& out, const llvm::Twine& expected);
  // `{ raw text }` of `method` of `owner` ("equation 'Foo'").
  bool parseBody(ast::Body& out, llvm::StringRef method, const std::string& owner);

  // Errors and recovery.
  // Reports an error unless the parser is recovering from one or the current token is a
  // lexical error (already reported); true if it was shown. error() returns false.
  bool report(llvm::SMLoc loc, const llvm::Twine& msg);
  bool error(llvm::SMLoc loc, const llvm::Twine& msg);
  void checkErrorLimit();
  bool atTopLevelItem();
  void skipToTopLevelItem();
  void skipStatement();

  // `{ item* }` of a declaration called `what` ("array 'fluid'"); `parseItem` parses one item
  // and returns false after an error. `sceneStepper`: `stepper X` is an item here, not the
  // start of a top-level stepper.
  bool parseBlock(const std::string& what, llvm::function_ref<bool()> parseItem,
                  bool sceneStepper = false);
  // A block of the scene, `KEYWORD { item* }` at its keyword (domain, limits, metrics): one
  // Decl located at the keyword, its items parsed by `parseItem`, appended to `into` (as far
  // as it got, after an error).
  template <class Decl>
  bool parseSceneBlock(const char* keyword, std::vector<Decl>& into,
                       bool (Parser::*parseItem)(Decl&)) {
    Decl decl;
    decl.loc = cur().loc;
    advance();
    bool ok = parseBlock(keyword, [&] { return (this->*parseItem)(decl); });
    into.push_back(std::move(decl));
    return ok;
  }

  // Declarations.
  bool parseItem(ast::Module& mod);
  bool parseImport(ast::Module& mod);
  bool parseOption(ast::Module& mod);
  bool parseEffect(ast::Module& mod);
  bool parseVector(ast::Module& mod);
  bool parseSchemeDecl(ast::Module& mod);
  bool parseSceneEffects(ast::SceneDecl& scene);
  bool parseSchemeUse(ast::SceneDecl& scene);
  bool atWhen();
  bool parseWhenCondition(ast::WhenCondition& cond);
  // `when C { items } else when C { items } else { items }`; parseItem parses one item of the
  // enclosing construct into a branch's body.
  template <class Body>
  bool parseWhen(std::vector<std::shared_ptr<ast::When<Body>>>& out, const std::string& what,
                 llvm::function_ref<bool(Body&)> parseItem, bool sceneStepper = false);
  bool parseParam(ast::Module& mod);
  bool parseArray(ast::Module& mod);
  bool parseArrayItem(ast::ArrayDecl& array);
  bool parseGeometry(ast::ArrayDecl& array);
  bool parseLoad(ast::ArrayDecl& array);
  bool parseProperty(ast::ArrayDecl& array);
  bool parseArrayConst(ast::ArrayDecl& array);
  // After the keyword: `[TYPE[N]] NAME [= init];` / `NAME[[N]] [= init];`; `loc` is the keyword's.
  bool parsePropertyRest(ast::ArrayDecl& array, llvm::SMLoc loc);
  bool parseArrayConstRest(ast::ArrayDecl& array);
  // `property ARRAYS TYPE NAME = init;` / `const ARRAYS NAME = init;` in a scheme.
  bool parseSchemeArrayItem(ast::SceneDecl& scene);
  std::optional<int> parseBracketedSize(const llvm::Twine& what);
  bool parseEquation(ast::Module& mod);
  bool parseEquationParams(ast::EquationDecl& eq);
  bool parseEquationItem(ast::EquationDecl& eq);
  bool parseReduce(ast::EquationDecl& eq);
  bool parseEquationConst(ast::EquationDecl& eq);
  bool parseEquationState(ast::EquationDecl& eq);
  bool parseFunction(ast::Module& mod);
  bool parseStepper(ast::Module& mod);
  bool parseIntegrator(ast::Module& mod);
  bool parseScene(ast::Module& mod);
  bool parseSceneItem(ast::SceneDecl& scene);
  bool parseSceneSetting(ast::SceneDecl& scene);
  bool parseSceneStepper(ast::SceneDecl& scene);
  bool parseAdaptiveDt(ast::SceneDecl& scene);
  bool parseOutput(ast::SceneDecl& scene);
  bool parseOutputItem(ast::OutputDecl& out);
  bool parseDomain(ast::SceneDecl& scene);
  bool parseDomainItem(ast::DomainDecl& domain);
  bool parseLimits(ast::SceneDecl& scene);
  bool parseZone(ast::SceneDecl& scene);  // ParseZones.cpp
  bool parseLimitItem(ast::LimitsDecl& limits);
  bool parseLimitBound(ast::LimitBound& bound, const std::string& head);
  // metrics { } (ParseMetrics.cpp)
  bool parseMetrics(ast::SceneDecl& scene);
  bool parseMetricItem(ast::MetricsDecl& metrics);
  bool parseGroupItem(std::vector<ast::GroupItem>& items, unsigned depth);
  // `pre ARRAY { BODY }` / `post ARRAY { BODY }` in a group (ParseGroupHooks.cpp).
  bool atGroupHook();
  bool parseGroupHook(ast::GroupDecl& group);
  // After `(`: `kwarg, ...)`, consuming the `)`.
  bool parseKwArgs(std::vector<ast::KwArg>& args);
  // After `[`: `name, ...]`, consuming the `]`; `what` names the list in errors.
  bool parseNameList(std::vector<ast::Ident>& names, const llvm::Twine& what);

  // Expressions (C precedence); null after an error.
  ast::ExprPtr parseExpr();
  ast::ExprPtr parseBinary(int minPrecedence);
  ast::ExprPtr parseUnary();
  ast::ExprPtr parsePrimary();
  ast::ExprPtr parseParenthesised();
  ast::ExprPtr parseCall();
  // Counts one level of expression nesting; false (with an error) past kMaxNesting. The
  // caller pairs a true result with leaveNesting().
  bool enterNesting();
  void leaveNesting() { --exprDepth_; }

  DiagnosticEngine& diags_;
  unsigned bufferId_;
  std::string filename_;
  unsigned errorsAtStart_;    // before lex_: the lexer reports from its constructor on
  Lexer lex_;
  llvm::SMLoc prevEnd_;       // just after the last consumed token
  bool panic_ = false;        // an error was reported and the parser has not resynchronised
  bool stopped_ = false;      // too many errors
  unsigned exprDepth_ = 0;
  unsigned whenDepth_ = 0;  // nesting of `when` blocks
  bool inScheme_ = false;   // parsing a scheme's body (it may declare array properties)
};

}  // namespace sphc
