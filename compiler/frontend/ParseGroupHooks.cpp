// A group's host hooks: `pre ARRAY { BODY }` and `post ARRAY { BODY }` (PySPH's
// Group(pre=..., post=...)). Each becomes an unnamed equation instance (dest = ARRAY) whose
// only method is a host `reduce { }`: Sema places it first (pre) or last (post) among the
// group's members.
#include "frontend/Parser.h"

namespace sphc {

bool Parser::atGroupHook() {
  return (atWord("pre") || atWord("post")) && lex_.peek().is(Token::Identifier);
}

bool Parser::parseGroupHook(ast::GroupDecl& group) {
  static unsigned counter = 0;
  const bool isPre = atWord("pre");
  const std::string kind = isPre ? "pre" : "post";
  auto decl = std::make_shared<ast::EquationDecl>();
  decl->name = ast::Ident{"group_" + kind + "_" + std::to_string(++counter), cur().loc};
  ast::Method method;
  method.kind = ast::Method::HostReduce;
  method.loc = cur().loc;
  advance();
  ast::Ident array;
  if (!parseIdent(array, "expected the array after '" + kind + "' (" + kind +
                             " ARRAY { ... }: a host body with ARRAY's properties and "
                             "constants)") ||
      !parseBody(method.body, kind, "group"))
    return false;
  std::shared_ptr<ast::EquationInstance>& slot = isPre ? group.pre : group.post;
  if (slot)
    return error(method.loc, "this group already has a '" + kind + "' body");
  decl->methods.push_back(std::move(method));
  auto inst = std::make_shared<ast::EquationInstance>();
  inst->equation = ast::Ident{kind, decl->name.loc};
  ast::KwArg dest;
  dest.name = ast::Ident{"dest", array.loc};
  auto value = std::make_shared<ast::Expr>();
  value->kind = ast::Expr::Name;
  value->text = array.name;
  value->loc = array.loc;
  dest.value = value;
  inst->args.push_back(std::move(dest));
  inst->inlineDecl = decl;
  slot = inst;
  return true;
}

}  // namespace sphc
