// Compile-time values of declarative expressions (sema/ConstEval.h).
#include "sema/ConstEval.h"
#include "sema/Sema.h"

#include <cmath>
#include <vector>

namespace sphc {

ConstEval::ConstEval(const Plan& plan) {
  for (const auto* p : plan.params) decls_[p->name.name] = p->value.get();
}

std::optional<double> ConstEval::operator()(const ast::Expr& e, int depth) const {
  if (depth > 64) return std::nullopt;
  auto sub = [&](size_t i) { return (*this)(*e.args[i], depth + 1); };
  switch (e.kind) {
    case ast::Expr::Number: return e.number;
    case ast::Expr::Name: {
      if (const BuiltinConstant* b = builtinConstant(e.text)) return b->value;
      if (auto f = fixed_.find(e.text); f != fixed_.end()) return f->second;
      auto it = decls_.find(e.text);
      if (it == decls_.end() || !it->second) return std::nullopt;
      return (*this)(*it->second, depth + 1);
    }
    case ast::Expr::Unary: {
      auto v = sub(0);
      if (!v) return v;
      if (e.op == "-") return -*v;
      if (e.op == "!") return *v == 0.0 ? 1.0 : 0.0;
      return v;
    }
    case ast::Expr::Binary: {
      auto a = sub(0), b = sub(1);
      if (!a || !b) return std::nullopt;
      const std::string& o = e.op;
      if (o == "+") return *a + *b;
      if (o == "-") return *a - *b;
      if (o == "*") return *a * *b;
      if (o == "/") return *a / *b;
      if (o == "%") return std::fmod(*a, *b);
      if (o == "<") return double(*a < *b);
      if (o == "<=") return double(*a <= *b);
      if (o == ">") return double(*a > *b);
      if (o == ">=") return double(*a >= *b);
      if (o == "==") return double(*a == *b);
      if (o == "!=") return double(*a != *b);
      if (o == "&&") return double(*a != 0 && *b != 0);
      if (o == "||") return double(*a != 0 || *b != 0);
      return std::nullopt;
    }
    case ast::Expr::Ternary: {
      auto c = sub(0);
      if (!c) return c;
      return *c != 0 ? sub(1) : sub(2);
    }
    case ast::Expr::Call: {
      std::vector<double> v;
      for (size_t i = 0; i < e.args.size(); ++i) {
        auto x = sub(i);
        if (!x) return x;
        v.push_back(*x);
      }
      static const std::map<std::string, double (*)(double)> one = {
          {"sqrt", std::sqrt}, {"exp", std::exp},   {"log", std::log},   {"sin", std::sin},
          {"cos", std::cos},   {"tan", std::tan},   {"fabs", std::fabs}, {"abs", std::fabs},
          {"floor", std::floor}, {"ceil", std::ceil}, {"round", std::round},
          {"cbrt", std::cbrt}, {"log10", std::log10}, {"tanh", std::tanh},
          {"asin", std::asin}, {"acos", std::acos}, {"atan", std::atan},
          {"sinh", std::sinh}, {"cosh", std::cosh}};
      if (v.size() == 1 && one.count(e.text)) return one.at(e.text)(v[0]);
      if (v.size() == 2) {
        if (e.text == "pow") return std::pow(v[0], v[1]);
        if (e.text == "fmin" || e.text == "min") return std::fmin(v[0], v[1]);
        if (e.text == "fmax" || e.text == "max") return std::fmax(v[0], v[1]);
        if (e.text == "atan2") return std::atan2(v[0], v[1]);
        if (e.text == "hypot") return std::hypot(v[0], v[1]);
        if (e.text == "fmod") return std::fmod(v[0], v[1]);
      }
      return std::nullopt;
    }
  }
  return std::nullopt;
}

}  // namespace sphc
