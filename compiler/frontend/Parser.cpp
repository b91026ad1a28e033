// The parser, part 1: tokens, errors and recovery, and the module items (imports, options,
// params, arrays, equations, functions, steppers, integrators). The scene block is in
// ParseScene.cpp, expressions in ParseExpr.cpp.
#include "frontend/Parser.h"
#include "frontend/ParseUtil.h"

#include "llvm/ADT/STLExtras.h"
#include "llvm/ADT/ScopeExit.h"
#include "llvm/ADT/StringExtras.h"
#include "llvm/Support/MemoryBuffer.h"

#include <cstdlib>

namespace sphc {

using ast::ExprPtr;

namespace {

constexpr llvm::StringLiteral kTopLevelKeywords[] = {
    "import", "option", "param", "let", "array", "equation", "function", "stepper", "integrator",
    "scene"};

// `stage` followed by one or more digits.
bool isStageName(llvm::StringRef word) {
  return word.consume_front("stage") && !word.empty() && llvm::all_of(word, llvm::isDigit);
}

bool isStepperMethod(llvm::StringRef word) { return word == "initialize" || isStageName(word); }

bool isIntegratorStatement(llvm::StringRef word) {
  return isStepperMethod(word) || word == "compute_accelerations" || word == "update_domain";
}

}  // namespace

using namespace parse_detail;


Parser::Parser(DiagnosticEngine& diags, llvm::SourceMgr& sm, unsigned bufferId)
    : diags_(diags),
      bufferId_(bufferId),
      filename_(sm.getMemoryBuffer(bufferId)->getBufferIdentifier().str()),
      errorsAtStart_(diags.errorCount()),
      lex_(diags, sm.getMemoryBuffer(bufferId)->getBuffer()) {}

// ---------------------------------------------------------------------------------------------
// Tokens, errors and recovery

void Parser::advance() {
  prevEnd_ = cur().endLoc();
  lex_.advance();
}

bool Parser::consumeIf(Token::Kind kind) {
  if (!cur().is(kind)) return false;
  advance();
  return true;
}

bool Parser::expect(Token::Kind kind, const llvm::Twine& context) {
  if (consumeIf(kind)) return true;
  llvm::SMLoc loc = kind == Token::Semi && prevEnd_.isValid() ? prevEnd_ : cur().loc;
  return error(loc, "expected " + describe(kind) + " " + context);
}

bool Parser::parseIdent(ast::Ident& out, const llvm::Twine& expected) {
  if (!cur().is(Token::Identifier)) return error(cur().loc, expected);
  out = identOf(cur());
  advance();
  return true;
}

bool Parser::parseBody(ast::Body& out, llvm::StringRef method, const std::string& owner) {
  if (!cur().is(Token::LBrace))
    return error(cur().loc, "expected '{' to start the body of " + quoted(method) + " in " + owner);
  out = lex_.lexBody(method);
  prevEnd_ = llvm::SMLoc::getFromPointer(out.start.getPointer() + out.text.size() + 1);
  return true;
}

bool Parser::report(llvm::SMLoc loc, const llvm::Twine& msg) {
  bool consequence = cur().is(Token::Error) || (cur().is(Token::Eof) && lex_.hitEofByError());
  bool show = !panic_ && !stopped_ && !consequence;
  panic_ = true;
  if (!show) return false;
  diags_.error(loc, msg);
  checkErrorLimit();
  return true;
}

bool Parser::error(llvm::SMLoc loc, const llvm::Twine& msg) {
  report(loc, msg);
  return false;
}

void Parser::checkErrorLimit() {
  if (stopped_ || diags_.errorCount() - errorsAtStart_ < kMaxErrors) return;
  stopped_ = true;
  diags_.note(llvm::SMLoc(), "too many errors in " + filename_ + "; stopping");
  lex_.stop();
}

bool Parser::atTopLevelItem() {
  if (!cur().is(Token::Identifier)) return false;
  if (cur().text == "vector") return lex_.peek().is(Token::LParen);  // vector (u, v, w);
  return llvm::is_contained(kTopLevelKeywords, cur().text) &&
         lex_.peek().is(Token::Identifier);
}

void Parser::skipToTopLevelItem() {
  lex_.setSuppressed(true);
  while (!cur().is(Token::Eof) && !atTopLevelItem()) {
    if (cur().is(Token::LBrace))
      lex_.lexBody("");
    else
      advance();
  }
  lex_.setSuppressed(false);
}

void Parser::skipStatement() {
  // A statement ends at `;` or with a `{ ... }` (skipped whole, its text may be C); a `}` or
  // a top-level keyword ends the enclosing block.
  lex_.setSuppressed(true);
  while (!cur().is(Token::Eof) && !cur().is(Token::RBrace) && !atTopLevelItem()) {
    if (cur().is(Token::LBrace)) {
      lex_.lexBody("");
      panic_ = false;
      break;
    }
    if (cur().is(Token::Semi)) {
      lex_.setSuppressed(false);
      advance();
      panic_ = false;
      return;
    }
    advance();
  }
  lex_.setSuppressed(false);
  if (cur().is(Token::RBrace)) panic_ = false;
}

bool Parser::parseBlock(const std::string& what, llvm::function_ref<bool()> parseItem,
                        bool sceneStepper) {
  llvm::SMLoc open = cur().loc;
  if (!expect(Token::LBrace, "to start the body of " + what)) return false;
  while (!cur().is(Token::RBrace)) {
    if (cur().is(Token::Eof)) {
      if (report(cur().loc, "unexpected end of file in " + what + ": missing '}'"))
        diags_.note(open, "to match this '{'");
      return false;
    }
    if (atTopLevelItem() && !(sceneStepper && atWord("stepper"))) {
      if (report(cur().loc, "expected '}' at the end of " + what + " before " +
                                quoted(cur().text)))
        diags_.note(open, "to match this '{'");
      return false;
    }
    if (!parseItem()) skipStatement();
  }
  advance();
  return true;
}

// ---------------------------------------------------------------------------------------------
// Declarations

std::unique_ptr<ast::Module> Parser::parseModule() {
  auto mod = std::make_unique<ast::Module>();
  mod->filename = filename_;
  mod->bufferId = bufferId_;
  while (!cur().is(Token::Eof)) {
    panic_ = false;
    checkErrorLimit();
    if (!parseItem(*mod)) skipToTopLevelItem();
  }
  return mod;
}

bool Parser::parseItem(ast::Module& mod) {
  if (atWord("import")) return parseImport(mod);
  if (atWord("option")) return parseOption(mod);
  if (atWord("effect")) return parseEffect(mod);
  if (atWord("vector")) return parseVector(mod);
  if (atWord("scheme")) return parseSchemeDecl(mod);
  if (atWord("param") || atWord("let")) return parseParam(mod);
  if (atWord("array")) return parseArray(mod);
  if (atWord("equation")) return parseEquation(mod);
  if (atWord("function")) return parseFunction(mod);
  if (atWord("stepper")) return parseStepper(mod);
  if (atWord("integrator")) return parseIntegrator(mod);
  if (atWord("scene")) return parseScene(mod);
  const char* expected =
      "import, option, effect, vector, scheme, param, let, array, equation, function, "
      "stepper, integrator or scene";
  if (cur().is(Token::Identifier))
    return error(cur().loc, "unknown declaration " + quoted(cur().text) + ": expected " + expected);
  return error(cur().loc, "expected a declaration (" + llvm::Twine(expected) + "), found " +
                              describe(cur()));
}

bool Parser::parseImport(ast::Module& mod) {
  ast::ImportDecl imp;
  imp.loc = cur().loc;
  advance();
  do {
    ast::Ident part;
    if (!parseIdent(part, "expected a module name after 'import'")) return false;
    imp.path.push_back(std::move(part));
  } while (consumeIf(Token::Dot));
  mod.imports.push_back(std::move(imp));
  return expect(Token::Semi, "after import");
}

// option NAME in [a, b, c] = a;
bool Parser::parseOption(ast::Module& mod) {
  advance();
  ast::OptionDecl opt;
  if (!parseIdent(opt.name, "expected an option name after 'option'")) return false;
  if (!atWord("in"))
    return error(cur().loc, "expected 'in [choice, ...]' after option " + quoted(opt.name.name) +
                                ", found " + describe(cur()));
  advance();
  if (!expect(Token::LBracket, "after 'in'")) return false;
  if (cur().is(Token::RBracket))
    return error(cur().loc, "option " + quoted(opt.name.name) + " needs at least one choice");
  if (!parseNameList(opt.choices, "the choices of option " + quoted(opt.name.name)))
    return false;
  if (!expect(Token::Assign, "after the choices of option " + quoted(opt.name.name) +
                                 " (the default: '= choice')") ||
      !parseIdent(opt.defaultChoice, "expected the default choice of option " +
                                         quoted(opt.name.name)))
    return false;
  mod.options.push_back(std::move(opt));
  return expect(Token::Semi, "after option declaration");
}

// effect NAME (needs [a, b])? "doc"? ;
bool Parser::parseEffect(ast::Module& mod) {
  advance();
  ast::EffectDecl e;
  if (!parseIdent(e.name, "expected an effect name after 'effect'")) return false;
  if (atWord("needs")) {
    advance();
    if (!expect(Token::LBracket, "after 'needs'") ||
        !parseNameList(e.needs, "the effects " + quoted(e.name.name) + " needs"))
      return false;
  }
  if (cur().is(Token::String)) {
    e.doc = cur().value;
    advance();
  }
  mod.effects.push_back(std::move(e));
  return expect(Token::Semi, "after effect declaration");
}

// vector (x_name, y_name, z_name);
bool Parser::parseVector(ast::Module& mod) {
  ast::VectorDecl v;
  v.loc = cur().loc;
  advance();
  if (!expect(Token::LParen, "after 'vector' (the x, y and z components: "
                             "'vector (u, v, w);')"))
    return false;
  do {
    ast::Ident c;
    if (!parseIdent(c, "expected a property name (a component of the vector)")) return false;
    v.components.push_back(std::move(c));
  } while (consumeIf(Token::Comma));
  if (!expect(Token::RParen, "after the components of the vector")) return false;
  if (v.components.size() != 3)
    return error(v.loc, "a vector names 3 properties, its x, y and z components (" +
                            std::to_string(v.components.size()) + " given)");
  for (size_t i = 0; i < 3; ++i)
    for (size_t j = 0; j < i; ++j)
      if (v.components[i].name == v.components[j].name)
        return error(v.components[i].loc, "property " + quoted(v.components[i].name) +
                                              " is named twice in one vector");
  mod.vectors.push_back(std::move(v));
  return expect(Token::Semi, "after vector declaration");
}

// scheme NAME(p, q = expr, r = [a, b]) { scene items }
bool Parser::parseSchemeDecl(ast::Module& mod) {
  advance();
  ast::SchemeDecl sc;
  if (!parseIdent(sc.name, "expected a scheme name after 'scheme'") ||
      !expect(Token::LParen, "after scheme " + quoted(sc.name.name)))
    return false;
  if (!consumeIf(Token::RParen)) {
    do {
      ast::SchemeParam p;
      if (!parseIdent(p.name, "expected a parameter name of scheme " + quoted(sc.name.name)))
        return false;
      if (consumeIf(Token::Assign)) {
        p.hasDefault = true;
        p.defaultValue.name = p.name;
        if (consumeIf(Token::LBracket)) {
          p.defaultValue.isList = true;
          if (!parseNameList(p.defaultValue.list, "the default of " + quoted(p.name.name)))
            return false;
        } else if (!(p.defaultValue.value = parseExpr())) {
          return false;
        }
      }
      sc.params.push_back(std::move(p));
    } while (consumeIf(Token::Comma));
    if (!expect(Token::RParen, "after the parameters of scheme " + quoted(sc.name.name)))
      return false;
  }
  sc.body = std::make_shared<ast::SceneDecl>();
  sc.body->name = sc.name;
  inScheme_ = true;
  bool ok = parseBlock(
      "scheme " + quoted(sc.name.name), [&] { return parseSceneItem(*sc.body); },
      /*sceneStepper=*/true);
  inScheme_ = false;
  mod.schemes.push_back(std::move(sc));
  return ok;
}

// `when` starts a conditional block where it is followed by an option or effect name (so that
// an equation, setting or property called `when` still parses), or by `!` and an effect.
bool Parser::atWhen() {
  return atWord("when") &&
         (lex_.peek().is(Token::Identifier) || lex_.peek().is(Token::Not));
}

// NAME == v | NAME != v | NAME in [v, w] | EFFECT | !EFFECT
bool Parser::parseWhenCondition(ast::WhenCondition& cond) {
  cond.loc = cur().loc;
  advance();
  if (consumeIf(Token::Not)) {
    cond.bare = true;
    cond.negated = true;
    return parseIdent(cond.option, "expected an effect name after 'when !'");
  }
  if (!parseIdent(cond.option, "expected an option name after 'when'")) return false;
  if (cur().is(Token::LBrace)) {
    cond.bare = true;
    return true;
  }
  if (cur().is(Token::EqEq) || cur().is(Token::NotEq)) {
    cond.negated = cur().is(Token::NotEq);
    advance();
    ast::Ident value;
    if (!parseIdent(value, "expected a choice of option " + quoted(cond.option.name) +
                               " after " + (cond.negated ? "'!='" : "'=='")))
      return false;
    cond.values.push_back(std::move(value));
    return true;
  }
  if (atWord("in")) {
    cond.isIn = true;
    advance();
    if (!expect(Token::LBracket, "after 'in'")) return false;
    if (cur().is(Token::RBracket))
      return error(cur().loc, "expected at least one choice in 'when " + cond.option.name +
                                  " in [...]'");
    return parseNameList(cond.values, "the choices of 'when " + cond.option.name + " in'");
  }
  return error(cur().loc, "expected '==', '!=', 'in' or '{' after 'when " + cond.option.name +
                              "', found " + describe(cur()));
}

template <class Body>
bool Parser::parseWhen(std::vector<std::shared_ptr<ast::When<Body>>>& out,
                       const std::string& what, llvm::function_ref<bool(Body&)> parseItem,
                       bool sceneStepper) {
  if (whenDepth_ >= kMaxNesting)
    return error(cur().loc, "'when' blocks nested too deeply (more than " +
                                llvm::Twine(kMaxNesting) + " levels)");
  ++whenDepth_;
  auto leave = llvm::make_scope_exit([&] { --whenDepth_; });
  auto when = std::make_shared<ast::When<Body>>();
  out.push_back(when);
  for (;;) {
    typename ast::When<Body>::Branch branch;
    bool hasCondition = atWhen();
    if (hasCondition) {
      branch.hasCondition = true;
      if (!parseWhenCondition(branch.condition)) return false;
    }
    auto& b = when->branches.emplace_back(std::move(branch));
    if (!parseBlock(
            "'when' in " + what, [&] { return parseItem(b.body); }, sceneStepper))
      return false;
    if (!hasCondition || !atWord("else")) return true;
    advance();  // else
    if (atWord("when") && !lex_.peek().is(Token::Identifier) && !lex_.peek().is(Token::Not))
      return error(lex_.peek().loc, "expected an option name after 'else when', found " +
                                        describe(lex_.peek()));
  }
}

bool Parser::parseParam(ast::Module& mod) {
  ast::ParamDecl param;
  param.derived = atWord("let");
  advance();
  if (!parseIdent(param.name, param.derived ? "expected a name after 'let'"
                                            : "expected a parameter name after 'param'") ||
      !expect(Token::Assign, "after parameter name " + quoted(param.name.name)))
    return false;
  param.value = parseExpr();
  if (!param.value) return false;
  if (atWord("for")) {
    advance();
    if (!parseIdent(param.effect, "expected an effect name after 'for'")) return false;
  }
  mod.params.push_back(std::move(param));
  return expect(Token::Semi, "after parameter declaration");
}

bool Parser::parseArray(ast::Module& mod) {
  advance();
  ast::ArrayDecl array;
  if (!parseIdent(array.name, "expected an array name after 'array'")) return false;
  bool ok = parseBlock("array " + quoted(array.name.name), [&] { return parseArrayItem(array); });
  mod.arrays.push_back(std::move(array));
  return ok;
}

bool Parser::parseArrayItem(ast::ArrayDecl& array) {
  if (atWord("geometry")) return parseGeometry(array);
  if (atWord("load")) return parseLoad(array);
  if (atWord("property")) return parseProperty(array);
  if (atWord("const")) return parseArrayConst(array);
  if (atWhen())
    return parseWhen<ast::ArrayDecl>(array.whens, "array " + quoted(array.name.name),
                                     [&](ast::ArrayDecl& part) {
                                       part.name = array.name;
                                       return parseArrayItem(part);
                                     });
  const char* expected = "'geometry', 'load', 'property', 'const' or 'when'";
  if (cur().is(Token::Identifier))
    return error(cur().loc, "unknown item " + quoted(cur().text) + " in array " +
                                quoted(array.name.name) + ": expected " + expected);
  return error(cur().loc, "expected " + llvm::Twine(expected) + " in array " +
                              quoted(array.name.name) + ", found " + describe(cur()));
}

bool Parser::parseGeometry(ast::ArrayDecl& array) {
  advance();
  ast::GeometryDecl geom;
  if (!parseIdent(geom.builder, "expected a geometry builder after 'geometry' (block, tank, "
                                "disk, sphere, cylinder or line)") ||
      !expect(Token::LParen, "after geometry builder " + quoted(geom.builder.name)) ||
      !parseKwArgs(geom.args))
    return false;
  array.geometry.push_back(std::move(geom));
  return expect(Token::Semi, "after geometry declaration");
}

bool Parser::parseLoad(ast::ArrayDecl& array) {
  ast::LoadDecl load;
  load.loc = cur().loc;
  advance();
  if (!cur().is(Token::String))
    return error(cur().loc, "expected a file name string after 'load', found " + describe(cur()));
  load.path = cur().value;
  advance();
  array.loads.push_back(std::move(load));
  return expect(Token::Semi, "after load declaration");
}

bool Parser::parseProperty(ast::ArrayDecl& array) {
  llvm::SMLoc loc = cur().loc;
  advance();
  return parsePropertyRest(array, loc);
}

bool Parser::parsePropertyRest(ast::ArrayDecl& array, llvm::SMLoc loc) {
  ast::PropertyDecl prop;
  prop.loc = loc;
  // `property TYPE NAME` or `property TYPE[N] NAME`: the word before the name is a type.
  if (cur().is(Token::Identifier) &&
      (lex_.peek().is(Token::Identifier) || lex_.peek().is(Token::LBracket))) {
    llvm::StringRef type = cur().text;
    if (type != "double" && type != "int" && type != "uint")
      return error(cur().loc, "unknown property type " + quoted(type) +
                                  ": expected double, int or uint");
    prop.type = type.str();
    advance();
    if (consumeIf(Token::LBracket)) {
      std::optional<int> stride = parseBracketedSize("stride");
      if (!stride) return false;
      prop.stride = *stride;
    }
  }
  if (!parseIdent(prop.name, "expected a property name after 'property'")) return false;
  if (consumeIf(Token::Assign) && !(prop.init = parseExpr())) return false;
  array.properties.push_back(std::move(prop));
  return expect(Token::Semi, "after property declaration");
}

bool Parser::parseArrayConst(ast::ArrayDecl& array) {
  advance();
  return parseArrayConstRest(array);
}

bool Parser::parseArrayConstRest(ast::ArrayDecl& array) {
  ast::ConstDecl c;
  if (!parseIdent(c.name, "expected a constant name after 'const'")) return false;
  if (consumeIf(Token::LBracket)) {
    std::optional<int> size = parseBracketedSize("size");
    if (!size) return false;
    c.size = *size;
  }
  if (consumeIf(Token::Assign) && !(c.init = parseExpr())) return false;
  array.constants.push_back(std::move(c));
  return expect(Token::Semi, "after constant declaration");
}

std::optional<int> Parser::parseBracketedSize(const llvm::Twine& what) {
  unsigned value = 0;
  if (!cur().is(Token::Number) || cur().text.getAsInteger(10, value) || value < 1 ||
      value > 1u << 20) {
    error(cur().loc, "expected a positive integer " + what + " in '[ ]', found " + describe(cur()));
    return std::nullopt;
  }
  advance();
  if (!expect(Token::RBracket, "after the " + what)) return std::nullopt;
  return static_cast<int>(value);
}

bool Parser::parseEquation(ast::Module& mod) {
  advance();
  ast::EquationDecl eq;
  if (!parseIdent(eq.name, "expected an equation name after 'equation'")) return false;
  std::string what = "equation " + quoted(eq.name.name);
  if (!expect(Token::LParen, "after the name of " + what) || !parseEquationParams(eq))
    return false;
  bool ok = parseBlock(what, [&] { return parseEquationItem(eq); });
  mod.equations.push_back(std::move(eq));
  return ok;
}

bool Parser::parseEquationParams(ast::EquationDecl& eq) {
  if (consumeIf(Token::RParen)) return true;
  do {
    ast::EqParam param;
    if (!parseIdent(param.name, "expected a parameter name in equation " + quoted(eq.name.name)))
      return false;
    if (consumeIf(Token::Assign) && !(param.defaultValue = parseExpr())) return false;
    eq.params.push_back(std::move(param));
  } while (consumeIf(Token::Comma));
  return expect(Token::RParen, "after the parameters of equation " + quoted(eq.name.name));
}

bool Parser::parseEquationItem(ast::EquationDecl& eq) {
  static constexpr std::pair<llvm::StringLiteral, ast::Method::Kind> kMethods[] = {
      {"initialize_pair", ast::Method::InitializePair},
      {"initialize", ast::Method::Initialize},
      {"loop_all", ast::Method::LoopAll},
      {"loop", ast::Method::Loop},
      {"post_loop", ast::Method::PostLoop},
      {"converged", ast::Method::Converged}};
  std::string owner = "equation " + quoted(eq.name.name);
  if (atWord("const")) return parseEquationConst(eq);
  if (atWord("state")) return parseEquationState(eq);
  if (atWord("reduce")) return parseReduce(eq);
  for (const auto& [name, kind] : kMethods) {
    if (!atWord(name)) continue;
    ast::Method method;
    method.kind = kind;
    method.loc = cur().loc;
    advance();
    if (!parseBody(method.body, name, owner)) return false;
    eq.methods.push_back(std::move(method));
    return true;
  }
  if (cur().is(Token::Identifier))
    return error(cur().loc, "unknown method " + quoted(cur().text) + " in " + owner +
                                ": expected initialize, initialize_pair, loop, loop_all, post_loop, reduce "
                                "or converged");
  return error(cur().loc, "expected a method, 'const' or 'state' in " + owner + ", found " +
                              describe(cur()));
}

bool Parser::parseEquationConst(ast::EquationDecl& eq) {
  advance();
  ast::EqConst c;
  if (!parseIdent(c.name, "expected a constant name after 'const'") ||
      !expect(Token::Assign, "after constant " + quoted(c.name.name)) ||
      !(c.value = parseExpr()))
    return false;
  eq.consts.push_back(std::move(c));
  return expect(Token::Semi, "after constant declaration");
}

// `state NAME = expr;` (PySPH's self.NAME): like a const, but bodies may write it.
bool Parser::parseEquationState(ast::EquationDecl& eq) {
  advance();
  ast::EqConst c;
  if (!parseIdent(c.name, "expected a state name after 'state'") ||
      !expect(Token::Assign, "after state " + quoted(c.name.name) +
                                 " (a state needs its initial value: state NAME = EXPR;)") ||
      !(c.value = parseExpr()))
    return false;
  eq.states.push_back(std::move(c));
  return expect(Token::Semi, "after state declaration");
}

bool Parser::parseReduce(ast::EquationDecl& eq) {
  ast::Method method;
  method.kind = ast::Method::Reduce;
  method.loc = cur().loc;
  advance();
  if (cur().is(Token::LBrace)) {
    // PySPH's reduce(dst, t, dt): once per evaluation on the host, over the whole array.
    method.kind = ast::Method::HostReduce;
    if (!parseBody(method.body, "reduce", "equation " + quoted(eq.name.name))) return false;
    eq.methods.push_back(std::move(method));
    return true;
  }
  if (atWord("sum") || atWord("max") || atWord("min") || atWord("mean")) {
    method.reduceOp = cur().text.str();
    advance();
  } else if (cur().is(Token::Identifier) && lex_.peek().is(Token::Identifier)) {
    return error(cur().loc, "unknown reduction operator " + quoted(cur().text) +
                                ": expected sum, max, min or mean");
  } else {
    return error(cur().loc,
                 "expected a reduction operator after 'reduce': sum, max, min or mean "
                 "(or a body: 'reduce { ... }', once on the host over the whole array)");
  }
  if (!parseIdent(method.reduceTarget, "expected the array constant receiving the result after "
                                       "'reduce " + method.reduceOp + "'") ||
      !parseBody(method.body, "reduce", "equation " + quoted(eq.name.name)))
    return false;
  eq.methods.push_back(std::move(method));
  return true;
}

// `function TYPE NAME(PARAMS) { BODY }`. The parameters are skipped here as tokens up to the
// matching `)` (Clang checks them); the definition's text is kept whole from TYPE to `}`.
bool Parser::parseFunction(ast::Module& mod) {
  ast::FunctionDecl fn;
  fn.loc = cur().loc;
  advance();
  const char* start = cur().text.begin();
  if (!(atWord("double") || atWord("int") || atWord("void")))
    return error(cur().loc, "expected the return type of a function after 'function': double, "
                            "int or void (as in `function double NAME(double a) { ... }`)");
  fn.returnType = cur().text.str();
  advance();
  if (!parseIdent(fn.name, "expected a function name after 'function " + fn.returnType + "'"))
    return false;
  std::string what = "function " + quoted(fn.name.name);
  if (!expect(Token::LParen, "after the name of " + what)) return false;
  for (int depth = 1; depth > 0;) {
    if (cur().is(Token::Eof) || cur().is(Token::LBrace) || cur().is(Token::RBrace) ||
        cur().is(Token::Semi))
      return error(cur().loc, "expected ')' to end the parameters of " + what + ", found " +
                                  describe(cur()));
    if (cur().is(Token::LParen)) ++depth;
    if (cur().is(Token::RParen)) --depth;
    advance();
  }
  ast::Body body;
  if (!parseBody(body, "function", what)) return false;
  const char* end = body.start.getPointer() + body.text.size() + 1;  // after the `}`
  fn.text.start = llvm::SMLoc::getFromPointer(start);
  fn.text.text = std::string(start, end);
  mod.functions.push_back(std::move(fn));
  return true;
}

bool Parser::parseStepper(ast::Module& mod) {
  advance();
  ast::StepperDecl stepper;
  if (!parseIdent(stepper.name, "expected a stepper name after 'stepper'")) return false;
  std::string what = "stepper " + quoted(stepper.name.name);
  bool ok = parseBlock(what, [&] {
    if (cur().is(Token::Identifier) && isStepperMethod(cur().text)) {
      ast::StepperMethod method;
      method.name = identOf(cur());
      advance();
      if (!parseBody(method.body, method.name.name, what)) return false;
      stepper.methods.push_back(std::move(method));
      return true;
    }
    if (cur().is(Token::Identifier))
      return error(cur().loc, quoted(cur().text) +
                                  " is not a stepper method: expected initialize or stageN");
    return error(cur().loc, "expected a stepper method (initialize or stageN), found " +
                                describe(cur()));
  });
  mod.steppers.push_back(std::move(stepper));
  return ok;
}

bool Parser::parseIntegrator(ast::Module& mod) {
  advance();
  ast::IntegratorDecl integrator;
  if (!parseIdent(integrator.name, "expected an integrator name after 'integrator'")) return false;
  const char* expected = "initialize, stageN, compute_accelerations or update_domain";
  bool ok = parseBlock("integrator " + quoted(integrator.name.name), [&] {
    if (cur().is(Token::Identifier) && isIntegratorStatement(cur().text)) {
      integrator.steps.push_back(identOf(cur()));
      advance();
      return expect(Token::Semi, "after integrator statement");
    }
    if (cur().is(Token::Identifier))
      return error(cur().loc, quoted(cur().text) + " is not an integrator statement: expected " +
                                  expected);
    return error(cur().loc, "expected an integrator statement (" + llvm::Twine(expected) +
                                "), found " + describe(cur()));
  });
  mod.integrators.push_back(std::move(integrator));
  return ok;
}

// parseWhen is defined here and instantiated for each block that may hold `when` branches
// (the scene's items and groups are parsed in ParseScene.cpp): a new kind needs a line here.
template bool Parser::parseWhen<ast::SceneDecl>(
    std::vector<std::shared_ptr<ast::When<ast::SceneDecl>>>&, const std::string&,
    llvm::function_ref<bool(ast::SceneDecl&)>, bool);
template bool Parser::parseWhen<std::vector<ast::GroupItem>>(
    std::vector<std::shared_ptr<ast::When<std::vector<ast::GroupItem>>>>&, const std::string&,
    llvm::function_ref<bool(std::vector<ast::GroupItem>&)>, bool);

}  // namespace sphc
