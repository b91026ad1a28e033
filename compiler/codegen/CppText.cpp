#include "codegen/CppText.h"
#include "sema/Sema.h"

#include <cctype>
#include <set>

namespace sphc {

// A declarative expression as C++ (doubles throughout: `1/2` is 0.5, as a user expects).
std::string exprCpp(const ast::Expr& e, const NameMap& names) {
  switch (e.kind) {
    case ast::Expr::Number: {
      std::string t = e.text.empty() ? std::to_string(e.number) : e.text;
      if (t.find_first_of(".eE") == std::string::npos) t += ".0";
      return t;
    }
    case ast::Expr::Name:
      if (const BuiltinConstant* b = builtinConstant(e.text)) return b->cpp;
      return names(e.text);
    case ast::Expr::Unary:
      return "(" + e.op + exprCpp(*e.args[0], names) + ")";
    case ast::Expr::Binary:
      if (e.op == "%")
        return "std::fmod(" + exprCpp(*e.args[0], names) + ", " + exprCpp(*e.args[1], names) +
               ")";
      return "(" + exprCpp(*e.args[0], names) + " " + e.op + " " + exprCpp(*e.args[1], names) +
             ")";
    case ast::Expr::Ternary:
      return "(" + exprCpp(*e.args[0], names) + " ? " + exprCpp(*e.args[1], names) + " : " +
             exprCpp(*e.args[2], names) + ")";
    case ast::Expr::Call: {
      std::string f = e.text;
      if (f == "min") f = "fmin";
      if (f == "max") f = "fmax";
      if (f == "abs") f = "fabs";
      std::string s = "std::" + f + "(";
      for (size_t i = 0; i < e.args.size(); ++i)
        s += (i ? ", " : "") + exprCpp(*e.args[i], names);
      return s + ")";
    }
  }
  return "0.0";
}

// The expression as the user would write it (for --help of the generated program).
std::string exprText(const ast::Expr& e) {
  std::string s = exprCpp(e, [](const std::string& n) { return n; });
  for (size_t at; (at = s.find("std::")) != std::string::npos;) s.erase(at, 5);
  return s;
}

bool mentions(const ast::Expr& e, const std::string& name) {
  if (e.kind == ast::Expr::Name && e.text == name) return true;
  for (const auto& a : e.args)
    if (a && mentions(*a, name)) return true;
  return false;
}

bool isLiteral(const ast::Expr& e) {
  if (e.kind == ast::Expr::Number) return true;
  return e.kind == ast::Expr::Unary && e.op == "-" && e.args[0]->kind == ast::Expr::Number;
}

double literalValue(const ast::Expr& e) {
  return e.kind == ast::Expr::Number ? e.number : -e.args[0]->number;
}

std::string cppType(const std::string& t) {
  if (t == "int") return "std::int32_t";
  if (t == "uint") return "std::uint32_t";
  return "double";
}

std::string propTypeEnum(const std::string& t) {
  if (t == "int") return "sphc::PropType::I32";
  if (t == "uint") return "sphc::PropType::U32";
  return "sphc::PropType::F64";
}

std::string accessor(const std::string& t) {
  if (t == "int") return "i32";
  if (t == "uint") return "u32";
  return "f64";
}

std::string cppSafeName(const std::string& name) {
  static const std::set<std::string> keywords = {
      "alignas", "alignof", "and", "and_eq", "asm", "auto", "bitand", "bitor", "bool", "break",
      "case", "catch", "char", "char16_t", "char32_t", "char8_t", "class", "co_await",
      "co_return", "co_yield", "compl", "concept", "const", "const_cast", "consteval",
      "constexpr", "constinit", "continue", "decltype", "default", "delete", "do", "double",
      "dynamic_cast", "else", "enum", "explicit", "export", "extern", "false", "float", "for",
      "friend", "goto", "if", "inline", "int", "long", "mutable", "namespace", "new",
      "noexcept", "not", "not_eq", "nullptr", "operator", "or", "or_eq", "private",
      "protected", "public", "register", "reinterpret_cast", "requires", "return", "short",
      "signed", "sizeof", "static", "static_assert", "static_cast", "struct", "switch",
      "template", "this", "thread_local", "throw", "true", "try", "typedef", "typeid",
      "typename", "union", "unsigned", "using", "virtual", "void", "volatile", "wchar_t",
      "while", "xor", "xor_eq"};
  return keywords.count(name) ? name + "_" : name;
}

std::string bodyFunctionName(const std::string& owner, const std::string& method) {
  return owner + "_" + method;
}

// A body for --precision=single on the CPU: `double` becomes `float` and every floating
// literal without a suffix gets `f`, so the body computes in float as it does in OpenCL C
// (where `#define double float` and -cl-single-precision-constant do the same). Bodies are
// portable C99 without strings or preprocessor lines, so tokens are identifiers, numbers,
// comments and punctuation; comments are copied as they are.
std::string singlePrecisionBody(const std::string& text) {
  std::string out;
  size_t i = 0;
  while (i < text.size()) {
    char c = text[i];
    if (c == '/' && i + 1 < text.size() && (text[i + 1] == '/' || text[i + 1] == '*')) {
      size_t end = text[i + 1] == '/' ? text.find('\n', i) : text.find("*/", i + 2);
      end = end == std::string::npos ? text.size() : end + (text[i + 1] == '/' ? 0 : 2);
      out += text.substr(i, end - i);
      i = end;
    } else if (isIdentifierStart(c)) {
      size_t end = i;
      while (end < text.size() && isIdentifierChar(text[end])) ++end;
      std::string word = text.substr(i, end - i);
      out += word == "double" ? "float" : word;
      i = end;
    } else if (std::isdigit(static_cast<unsigned char>(c)) ||
               (c == '.' && i + 1 < text.size() &&
                std::isdigit(static_cast<unsigned char>(text[i + 1])))) {
      // A preprocessing number: digits, letters, '.', and a sign after an exponent letter.
      size_t end = i;
      while (end < text.size()) {
        char d = text[end];
        if (isIdentifierChar(d) || d == '.') {
          ++end;
        } else if ((d == '+' || d == '-') && (text[end - 1] == 'e' || text[end - 1] == 'E') &&
                   !(text[i] == '0' && i + 1 < text.size() &&
                     (text[i + 1] == 'x' || text[i + 1] == 'X'))) {
          ++end;
        } else {
          break;
        }
      }
      std::string num = text.substr(i, end - i);
      bool hex = num.size() > 1 && num[0] == '0' && (num[1] == 'x' || num[1] == 'X');
      bool floating = !hex && num.find_first_of(".eE") != std::string::npos;
      char last = num.back();
      bool suffixed = last == 'f' || last == 'F' || last == 'l' || last == 'L';
      out += num;
      if (floating && !suffixed) out += "f";
      i = end;
    } else {
      out += c;
      ++i;
    }
  }
  return out;
}

size_t identifierOccurrences(const std::string& text, const std::string& name) {
  size_t n = 0;
  for (size_t at = text.find(name); at != std::string::npos; at = text.find(name, at + 1))
    if ((at == 0 || !isIdentifierChar(text[at - 1])) &&
        (at + name.size() >= text.size() || !isIdentifierChar(text[at + name.size()])))
      ++n;
  return n;
}

}  // namespace sphc
