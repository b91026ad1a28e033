// A readable, stable dump of the AST (`sphc --emit=ast`, `--dump-after=parse`, lit tests):
// one declaration per line with its <line:col>, expressions fully parenthesised, bodies as
// their first line and their line count.
#pragma once

#include "frontend/AST.h"
#include "frontend/Diagnostics.h"

#include "llvm/Support/raw_ostream.h"

namespace sphc {

void printModule(const ast::Module& mod, llvm::raw_ostream& os, const DiagnosticEngine& diags);

// `(a + (b * c))`, `f(x, (-y))`, `(c ? a : b)`.
void printExpr(const ast::Expr& expr, llvm::raw_ostream& os);

}  // namespace sphc
