// Spellings every printer of the back half shares: declarative expressions (params, initial
// values, group options) as C++, property types and accessors of the runtime, the names of
// body functions, and a body rewritten for --precision=single. Free functions of text only.
#pragma once

#include "body/Identifiers.h"
#include "frontend/AST.h"

#include <functional>
#include <string>

namespace sphc {

using NameMap = std::function<std::string(const std::string&)>;

// A declarative expression as C++ (doubles throughout: `1/2` is 0.5, as a user expects);
// names are spelled by `names` (e.g. a param `dx` as `P.dx`).
std::string exprCpp(const ast::Expr& e, const NameMap& names);
// The expression as the user would write it (for --help of the generated program).
std::string exprText(const ast::Expr& e);
// Whether the expression refers to `name`.
bool mentions(const ast::Expr& e, const std::string& name);
// A number, or a negated number, and its value.
bool isLiteral(const ast::Expr& e);
double literalValue(const ast::Expr& e);

// A property type (double, int, uint) as a C++ type, a sphc::PropType and the
// ParticleArray accessor (f64, i32, u32).
std::string cppType(const std::string& t);
std::string propTypeEnum(const std::string& t);
std::string accessor(const std::string& t);

// The function holding method `method` of an equation or stepper: Owner_method.
std::string bodyFunctionName(const std::string& owner, const std::string& method);

// How many times the identifier `name` occurs in text as a whole word.
size_t identifierOccurrences(const std::string& text, const std::string& name);

// `name`, or `name_` where `name` is a C++ keyword (a property may be called `new`).
std::string cppSafeName(const std::string& name);

// A body for --precision=single on the CPU: `double` becomes `float` and every floating
// literal without a suffix gets `f`, so the body computes in float as it does in OpenCL C.
std::string singlePrecisionBody(const std::string& text);

}  // namespace sphc
