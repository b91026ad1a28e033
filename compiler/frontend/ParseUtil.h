// Small helpers shared by the parser's source files (Parser.cpp, ParseScene.cpp,
// ParseExpr.cpp). Internal to the front end.
#pragma once

#include "frontend/Lexer.h"
#include "frontend/AST.h"

#include "llvm/ADT/StringRef.h"

#include <string>

namespace sphc::parse_detail {

inline ast::Ident identOf(const Token& tok) { return ast::Ident{tok.text.str(), tok.loc}; }

inline std::string quoted(llvm::StringRef s) { return "'" + s.str() + "'"; }

}  // namespace sphc::parse_detail
