// The parser's part for open boundaries (docs/language.md, Inlets and outlets):
//
//   inlet NAME(array = A, feeds = F, x = .., y = .., nx = .., ny = .., length = .., ...);
//   outlet NAME(array = A, from = F, ..., type = do_nothing);
//
// Keyword arguments as in an equation instance; sema/Zones.cpp gives them meaning.
#include "frontend/Parser.h"

namespace sphc {

bool Parser::parseZone(ast::SceneDecl& scene) {
  ast::ZoneDecl zone;
  zone.inlet = atWord("inlet");
  zone.loc = cur().loc;
  const std::string what = zone.inlet ? "inlet" : "outlet";
  advance();
  if (!parseIdent(zone.name, "expected a name after '" + what + "', as in '" + what +
                                 " in1(array = ..., ...);'") ||
      !expect(Token::LParen, "after " + what + " '" + zone.name.name + "'") ||
      !parseKwArgs(zone.args))
    return false;
  scene.zones.push_back(std::move(zone));
  return expect(Token::Semi, "after " + what + " '" + scene.zones.back().name.name + "'");
}

}  // namespace sphc
