// The parser, part 2: the scene block (settings, output, domain, limits, groups) and the
// keyword-argument and name lists it uses. Part 1 (module items) is Parser.cpp.
#include "frontend/Parser.h"
#include "frontend/ParseUtil.h"

#include "llvm/ADT/STLExtras.h"
#include "llvm/ADT/StringExtras.h"

namespace sphc {

using ast::ExprPtr;
using namespace parse_detail;

bool Parser::parseScene(ast::Module& mod) {
  advance();
  ast::SceneDecl scene;
  if (!parseIdent(scene.name, "expected a scene name after 'scene'")) return false;
  bool ok = parseBlock(
      "scene " + quoted(scene.name.name), [&] { return parseSceneItem(scene); },
      /*sceneStepper=*/true);
  mod.scenes.push_back(std::move(scene));
  return ok;
}

bool Parser::parseSceneItem(ast::SceneDecl& scene) {
  if (!cur().is(Token::Identifier))
    return error(cur().loc, "expected a scene item ('name = value;', stepper, adaptive_dt, "
                            "output, domain, limits, metrics, inlet, outlet, equations or when), found " + describe(cur()));
  // The scene's keywords are contextual: `output = 3;` is a setting named output.
  if (atWord("effects") && lex_.peek().is(Token::Assign)) return parseSceneEffects(scene);
  if (lex_.peek().is(Token::Assign)) return parseSceneSetting(scene);
  if (atWord("scheme") && lex_.peek().is(Token::Identifier)) return parseSchemeUse(scene);
  if ((atWord("property") || atWord("const")) &&
      (lex_.peek().is(Token::Identifier) || lex_.peek().is(Token::LBracket)))
    return parseSchemeArrayItem(scene);
  if (atWhen())
    return parseWhen<ast::SceneDecl>(
        scene.whens, "scene " + quoted(scene.name.name),
        [&](ast::SceneDecl& part) {
          part.name = scene.name;
          return parseSceneItem(part);
        },
        /*sceneStepper=*/true);
  if (atWord("stepper")) return parseSceneStepper(scene);
  if (atWord("adaptive_dt")) return parseAdaptiveDt(scene);
  if (atWord("output")) return parseOutput(scene);
  if (atWord("domain")) return parseDomain(scene);
  if (atWord("limits")) return parseLimits(scene);
  if (atWord("metrics")) return parseMetrics(scene);
  if (atWord("inlet") || atWord("outlet")) return parseZone(scene);
  if (atWord("equations")) {
    scene.equationsLoc = cur().loc;
    advance();
    return parseBlock("equations", [&] { return parseGroupItem(scene.equations, 0); });
  }
  return error(lex_.peek().loc, "expected '=' after scene setting " + quoted(cur().text));
}

// `effects = [a, b];` in a scene.
bool Parser::parseSceneEffects(ast::SceneDecl& scene) {
  llvm::SMLoc loc = cur().loc;
  advance();
  advance();  // '='
  if (scene.effectsLoc.isValid())
    return error(loc, "the scene's effects are given twice");
  scene.effectsLoc = loc;
  if (!expect(Token::LBracket, "after 'effects =' (a list: effects = [gravity, xsph])") ||
      !parseNameList(scene.effects, "the scene's effects"))
    return false;
  return expect(Token::Semi, "after the scene's effects");
}

// `property fluids double[3] gradc = 0;` or `const [fluids, solids] umax = 0;` in a scheme: the
// arrays (list parameters), then what `property` / `const` declares in an array.
bool Parser::parseSchemeArrayItem(ast::SceneDecl& scene) {
  const bool isConst = atWord("const");
  const std::string kw = isConst ? "const" : "property";
  llvm::SMLoc loc = cur().loc;
  if (!inScheme_)
    return error(loc, "'" + kw + "' in a scene: declare it in its array ('array NAME { " + kw +
                          " ...; }'); a scheme declares " +
                          (isConst ? "constants" : "properties") +
                          " on its array-list parameters ('" + kw + " fluids ...;')");
  advance();
  ast::SchemeArrayItem item;
  if (consumeIf(Token::LBracket)) {
    if (!parseNameList(item.arrays, "the arrays of '" + kw + "'")) return false;
  } else {
    ast::Ident id;
    if (!parseIdent(id, "expected the arrays (a list parameter of the scheme) after '" + kw + "'"))
      return false;
    if (!isConst && (id.name == "double" || id.name == "int" || id.name == "uint"))
      return error(id.loc, "a property of a scheme names its arrays first: 'property fluids " +
                               id.name + " NAME = ...;' (fluids: an array-list parameter)");
    item.arrays.push_back(id);
  }
  item.item.name = item.arrays.empty() ? ast::Ident{} : item.arrays.front();
  if (!(isConst ? parseArrayConstRest(item.item) : parsePropertyRest(item.item, loc)))
    return false;
  scene.arrayItems.push_back(std::move(item));
  return true;
}

// `scheme NAME(arg = value, ...);` in a scene.
bool Parser::parseSchemeUse(ast::SceneDecl& scene) {
  ast::SchemeUse use;
  use.loc = cur().loc;
  advance();
  if (!parseIdent(use.scheme, "expected a scheme name after 'scheme'") ||
      !expect(Token::LParen, "after scheme " + quoted(use.scheme.name)) ||
      !parseKwArgs(use.args))
    return false;
  std::string what = "after 'scheme " + use.scheme.name + "(...)'";
  scene.schemes.push_back(std::move(use));
  return expect(Token::Semi, what);
}

bool Parser::parseSceneSetting(ast::SceneDecl& scene) {
  ast::SceneSetting setting;
  setting.key = identOf(cur());
  advance();
  advance();  // '='
  if (!(setting.value = parseExpr())) return false;
  scene.settings.push_back(std::move(setting));
  return expect(Token::Semi, "after scene setting " + quoted(scene.settings.back().key.name));
}

bool Parser::parseSceneStepper(ast::SceneDecl& scene) {
  advance();
  ast::SceneStepper st;
  if (!parseIdent(st.array, "expected an array name after 'stepper'") ||
      !expect(Token::Assign, "after 'stepper " + st.array.name + "'") ||
      !parseIdent(st.stepper, "expected a stepper name after 'stepper " + st.array.name + " ='"))
    return false;
  scene.steppers.push_back(std::move(st));
  return expect(Token::Semi, "after scene stepper");
}

bool Parser::parseAdaptiveDt(ast::SceneDecl& scene) {
  scene.hasAdaptiveDt = true;
  scene.adaptiveDtLoc = cur().loc;
  advance();
  if (!expect(Token::LParen, "after 'adaptive_dt'") || !parseKwArgs(scene.adaptiveDt))
    return false;
  return expect(Token::Semi, "after 'adaptive_dt(...)'");
}

bool Parser::parseOutput(ast::SceneDecl& scene) {
  ast::OutputDecl out;
  out.loc = cur().loc;
  advance();
  if (atWord("every")) {
    advance();
    if (!(out.every = parseExpr())) return false;
  } else if (atWord("at")) {
    advance();
    if (!expect(Token::LBracket, "after 'output at'")) return false;
    do {
      ExprPtr t = parseExpr();
      if (!t) return false;
      out.at.push_back(std::move(t));
    } while (consumeIf(Token::Comma));
    if (!consumeIf(Token::RBracket))
      return error(cur().loc, "expected ',' or ']' in the output times, found " + describe(cur()));
  } else {
    return error(cur().loc, "expected 'every' or 'at' after 'output', found " + describe(cur()));
  }
  bool ok = parseBlock("output", [&] { return parseOutputItem(out); });
  scene.outputs.push_back(std::move(out));
  return ok;
}

bool Parser::parseOutputItem(ast::OutputDecl& out) {
  ast::OutputDecl::Item item;
  if (!parseIdent(item.array, "expected an array name in output, as in 'fluid(x, y);'") ||
      !expect(Token::LParen, "after array " + quoted(item.array.name) + " in output"))
    return false;
  do {
    ast::Ident prop;
    if (!parseIdent(prop, "expected a property name in the output of " + quoted(item.array.name)))
      return false;
    item.props.push_back(std::move(prop));
  } while (consumeIf(Token::Comma));
  if (!consumeIf(Token::RParen))
    return error(cur().loc, "expected ',' or ')' in the output of " + quoted(item.array.name) +
                                ", found " + describe(cur()));
  out.items.push_back(std::move(item));
  return expect(Token::Semi, "after output item");
}

bool Parser::parseDomain(ast::SceneDecl& scene) {
  return parseSceneBlock("domain", scene.domains, &Parser::parseDomainItem);
}

// periodic AXIS in [lo, hi];  mirror AXIS in [lo, hi];  mirror AXIS >= lo;  mirror AXIS <= hi;
bool Parser::parseDomainItem(ast::DomainDecl& domain) {
  ast::DomainItem item;
  if (atWord("periodic"))
    item.kind = ast::DomainItem::Periodic;
  else if (atWord("mirror"))
    item.kind = ast::DomainItem::Mirror;
  else
    return error(cur().loc, "expected 'periodic' or 'mirror' in domain, found " + describe(cur()));
  std::string what = item.kind == ast::DomainItem::Periodic ? "periodic" : "mirror";
  item.loc = cur().loc;
  advance();
  if (!parseIdent(item.axis, "expected an axis (x, y or z) after '" + what + "'")) return false;
  const std::string head = "'" + what + " " + item.axis.name + "'";
  if (atWord("in")) {
    advance();
    if (!expect(Token::LBracket, "after " + head + " in")) return false;
    if (!(item.lo = parseExpr())) return false;
    if (!consumeIf(Token::Comma))
      return error(cur().loc, "expected ',' between the ends of the interval of " + head +
                                  ", found " + describe(cur()));
    if (!(item.hi = parseExpr())) return false;
    if (!consumeIf(Token::RBracket))
      return error(cur().loc, "expected ']' after the interval of " + head + ", found " +
                                  describe(cur()));
  } else if (consumeIf(Token::GreaterEq)) {
    if (!(item.lo = parseExpr())) return false;
  } else if (consumeIf(Token::LessEq)) {
    if (!(item.hi = parseExpr())) return false;
  } else {
    return error(cur().loc, "expected 'in [lo, hi]', '>= lo' or '<= hi' after " + head +
                                ", found " + describe(cur()));
  }
  domain.items.push_back(std::move(item));
  return expect(Token::Semi, "after domain item");
}

bool Parser::parseLimits(ast::SceneDecl& scene) {
  return parseSceneBlock("limits", scene.limits, &Parser::parseLimitItem);
}

// ARRAY.QUANTITY (warn BOUND)? (stop BOUND)? (remove BOUND (where COORD COND)?)?;  at least
// one of warn, stop and remove (in any order), COND: '>= lo', '<= hi' or 'in [lo, hi]'.
bool Parser::parseLimitItem(ast::LimitsDecl& limits) {
  ast::LimitItem item;
  if (!parseIdent(item.array, "expected a limit, as in 'fluid.rho warn [990, 1010];', found " +
                                  describe(cur())))
    return false;
  if (!expect(Token::Dot, "after array " + quoted(item.array.name) + " in a limit") ||
      !parseIdent(item.quantity, "expected a property or 'speed' after '" + item.array.name +
                                     ".' in a limit"))
    return false;
  const std::string head = "limit '" + item.array.name + "." + item.quantity.name + "'";
  while (atWord("warn") || atWord("stop") || atWord("remove")) {
    const std::string kind = cur().text.str();
    auto& slot = kind == "warn" ? item.warn : kind == "stop" ? item.stop : item.remove;
    if (slot) return error(cur().loc, "'" + kind + "' is given twice in " + head);
    slot.emplace();
    slot->loc = cur().loc;
    advance();
    if (!parseLimitBound(*slot, head + " " + kind)) return false;
    if (kind != "remove" || !atWord("where")) continue;
    // where COORD (>= lo | <= hi | in [lo, hi]): the particles removed are those outside the
    // bound where the condition holds.
    advance();
    const std::string cond = head + " remove where";
    if (!parseIdent(item.removeWhere, "expected a coordinate after 'where' in " + head +
                                          " (as in 'remove [0, 4] where y >= 4'), found " +
                                          describe(cur())))
      return false;
    item.removeWhereBound.emplace();
    item.removeWhereBound->loc = item.removeWhere.loc;
    if (consumeIf(Token::LessEq)) {
      if (!(item.removeWhereBound->hi = parseExpr())) return false;
    } else if (consumeIf(Token::GreaterEq)) {
      if (!(item.removeWhereBound->lo = parseExpr())) return false;
    } else if (atWord("in")) {
      advance();
      if (!cur().is(Token::LBracket))
        return error(cur().loc, "expected '[lo, hi]' after 'in' in " + cond + ", found " +
                                    describe(cur()));
      if (!parseLimitBound(*item.removeWhereBound, cond)) return false;
      item.removeWhereBound->loc = item.removeWhere.loc;
    } else {
      return error(cur().loc, "expected '>= lo', '<= hi' or 'in [lo, hi]' after '" +
                                  item.removeWhere.name + "' in " + cond + ", found " +
                                  describe(cur()));
    }
  }
  if (!item.warn && !item.stop && !item.remove)
    return error(cur().loc, "expected 'warn', 'stop' or 'remove' and a bound after " + head +
                                ", found " + describe(cur()));
  limits.items.push_back(std::move(item));
  return expect(Token::Semi, "after " + head);
}

// '[' lo ',' hi ']'  |  '<=' hi  |  '>=' lo
bool Parser::parseLimitBound(ast::LimitBound& bound, const std::string& head) {
  if (consumeIf(Token::LBracket)) {
    if (!(bound.lo = parseExpr())) return false;
    if (!consumeIf(Token::Comma))
      return error(cur().loc, "expected ',' between the ends of the interval of " + head +
                                  ", found " + describe(cur()));
    if (!(bound.hi = parseExpr())) return false;
    if (!consumeIf(Token::RBracket))
      return error(cur().loc, "expected ']' after the interval of " + head + ", found " +
                                  describe(cur()));
    return true;
  }
  if (consumeIf(Token::LessEq)) return static_cast<bool>(bound.hi = parseExpr());
  if (consumeIf(Token::GreaterEq)) return static_cast<bool>(bound.lo = parseExpr());
  return error(cur().loc, "expected '[lo, hi]', '<= hi' or '>= lo' after " + head + ", found " +
                              describe(cur()));
}

bool Parser::parseGroupItem(std::vector<ast::GroupItem>& items, unsigned depth) {
  if (atWord("group") && (lex_.peek().is(Token::LParen) || lex_.peek().is(Token::LBrace))) {
    if (depth >= kMaxNesting)
      return error(cur().loc, "groups nested too deeply (more than " +
                                  llvm::Twine(kMaxNesting) + " levels)");
    auto group = std::make_shared<ast::GroupDecl>();
    group->loc = cur().loc;
    advance();
    if (consumeIf(Token::LParen) && !parseKwArgs(group->options)) return false;
    items.push_back(ast::GroupItem{group, nullptr, nullptr});
    return parseBlock("group", [&] {
      if (atGroupHook()) return parseGroupHook(*group);
      return parseGroupItem(group->items, depth + 1);
    });
  }
  if (atWhen()) {
    std::vector<std::shared_ptr<ast::When<std::vector<ast::GroupItem>>>> whens;
    bool ok = parseWhen<std::vector<ast::GroupItem>>(
        whens, "an equations list", [&](std::vector<ast::GroupItem>& part) {
          return parseGroupItem(part, depth + 1);
        });
    if (!whens.empty()) items.push_back(ast::GroupItem{nullptr, nullptr, whens.front()});
    return ok;
  }
  if (!cur().is(Token::Identifier))
    return error(cur().loc, "expected an equation instance 'Name(arg = value, ...);' or a group, "
                            "found " + describe(cur()));
  auto inst = std::make_shared<ast::EquationInstance>();
  inst->equation = identOf(cur());
  advance();
  if (!expect(Token::LParen, "after equation " + quoted(inst->equation.name)) ||
      !parseKwArgs(inst->args))
    return false;
  items.push_back(ast::GroupItem{nullptr, inst, nullptr});
  return expect(Token::Semi, "after equation instance " + quoted(inst->equation.name));
}

bool Parser::parseKwArgs(std::vector<ast::KwArg>& args) {
  if (consumeIf(Token::RParen)) return true;
  do {
    if (!cur().is(Token::Identifier))
      return error(cur().loc, "expected an argument 'name = value', found " + describe(cur()));
    if (!lex_.peek().is(Token::Assign))
      return error(lex_.peek().loc, "expected '=' after argument name " + quoted(cur().text));
    ast::KwArg arg;
    arg.name = identOf(cur());
    advance();
    advance();  // '='
    if (consumeIf(Token::LBracket)) {
      arg.isList = true;
      if (!parseNameList(arg.list, "the list of " + quoted(arg.name.name))) return false;
    } else if (!(arg.value = parseExpr())) {
      return false;
    }
    args.push_back(std::move(arg));
  } while (consumeIf(Token::Comma));
  if (!consumeIf(Token::RParen))
    return error(cur().loc, "expected ',' or ')' after argument " + quoted(args.back().name.name) +
                                ", found " + describe(cur()));
  return true;
}

bool Parser::parseNameList(std::vector<ast::Ident>& names, const llvm::Twine& what) {
  if (consumeIf(Token::RBracket)) return true;
  do {
    ast::Ident name;
    if (!parseIdent(name, "expected an array name in " + what)) return false;
    names.push_back(std::move(name));
  } while (consumeIf(Token::Comma));
  if (!consumeIf(Token::RBracket))
    return error(cur().loc, "expected ',' or ']' in " + what + ", found " + describe(cur()));
  return true;
}
}  // namespace sphc
