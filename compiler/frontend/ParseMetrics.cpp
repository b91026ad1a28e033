// The scene's `metrics { }` block (docs/language.md, Metrics): kept apart from Parser.cpp so
// that the grammar of metrics is in one place.
//
//   metrics { item* }
//   item := IDENT '=' KIND '(' ARRAY ',' expr (',' IDENT '=' (STRING | expr))* ')' ';'
//
// What KIND, ARRAY, the names in the expressions and the arguments mean is Sema's
// (sema/Metrics.cpp).
#include "frontend/Parser.h"

namespace sphc {

bool Parser::parseMetrics(ast::SceneDecl& scene) {
  return parseSceneBlock("metrics", scene.metrics, &Parser::parseMetricItem);
}

bool Parser::parseMetricItem(ast::MetricsDecl& metrics) {
  ast::MetricItem item;
  const char* example = "as in 'l1 = L1(fluid, u, exact = sin(x));'";
  if (!parseIdent(item.name, llvm::Twine("expected a metric name, ") + example))
    return false;
  const std::string head = "metric '" + item.name.name + "'";
  if (!expect(Token::Assign, "after " + head) ||
      !parseIdent(item.kind, "expected L1, L2, Linf, max, min, sum or mean after '" +
                                 item.name.name + " ='") ||
      !expect(Token::LParen, "after '" + item.kind.name + "' in " + head) ||
      !parseIdent(item.array, "expected an array name as the first argument of " + head) ||
      !expect(Token::Comma, "after the array of " + head + " (then the measured expression)"))
    return false;
  if (!(item.expr = parseExpr())) return false;
  while (consumeIf(Token::Comma)) {
    ast::MetricArg arg;
    if (!parseIdent(arg.name, "expected an argument of " + head +
                                  " (exact, relative, where, reference, column, abscissa, at, "
                                  "x, y, z, rows, radius, average)") ||
        !expect(Token::Assign, "after '" + arg.name.name + "' in " + head))
      return false;
    arg.loc = cur().loc;
    if (cur().is(Token::String)) {
      arg.isString = true;
      arg.text = cur().value;
      advance();
    } else if (!(arg.value = parseExpr())) {
      return false;
    }
    item.args.push_back(std::move(arg));
  }
  if (!consumeIf(Token::RParen))
    return error(cur().loc, "expected ',' or ')' in " + head + ", found " + describe(cur()));
  metrics.items.push_back(std::move(item));
  return expect(Token::Semi, "after " + head);
}

}  // namespace sphc
