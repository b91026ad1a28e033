#include "frontend/ASTPrinter.h"

#include "llvm/ADT/STLExtras.h"
#include "llvm/ADT/StringRef.h"
#include "llvm/Support/Path.h"

namespace sphc {

void printExpr(const ast::Expr& expr, llvm::raw_ostream& os) {
  auto arg = [&](size_t i) -> const ast::Expr& { return *expr.args[i]; };
  switch (expr.kind) {
    case ast::Expr::Number:
    case ast::Expr::Name:
      os << expr.text;
      return;
    case ast::Expr::Unary:
      os << "(" << expr.op;
      printExpr(arg(0), os);
      os << ")";
      return;
    case ast::Expr::Binary:
      os << "(";
      printExpr(arg(0), os);
      os << " " << expr.op << " ";
      printExpr(arg(1), os);
      os << ")";
      return;
    case ast::Expr::Ternary:
      os << "(";
      printExpr(arg(0), os);
      os << " ? ";
      printExpr(arg(1), os);
      os << " : ";
      printExpr(arg(2), os);
      os << ")";
      return;
    case ast::Expr::Call:
      os << expr.text << "(";
      llvm::interleaveComma(expr.args, os, [&](const ast::ExprPtr& a) { printExpr(*a, os); });
      os << ")";
      return;
  }
}

namespace {

class Printer {
 public:
  Printer(llvm::raw_ostream& os, const DiagnosticEngine& diags) : os_(os), diags_(diags) {}

  void module(const ast::Module& mod) {
    os_ << "module '" << llvm::sys::path::filename(mod.filename) << "'\n";
    for (const auto& imp : mod.imports) {
      line(0) << "import ";
      llvm::interleave(imp.path, os_, [&](const ast::Ident& p) { os_ << p.name; }, ".");
      at(imp.loc) << "\n";
    }
    for (const auto& o : mod.options) {
      decl(0, "option", o.name) << " in [";
      llvm::interleaveComma(o.choices, os_, [&](const ast::Ident& c) { os_ << c.name; });
      os_ << "] = " << o.defaultChoice.name << "\n";
    }
    for (const auto& p : mod.params) {
      decl(0, p.derived ? "let" : "param", p.name);
      init(p.value);
      os_ << "\n";
    }
    for (const auto& a : mod.arrays) array(a);
    for (const auto& eq : mod.equations) equation(eq);
    for (const auto& f : mod.functions) {
      decl(0, "function", f.name) << " returns " << f.returnType;
      body(f.text);
    }
    for (const auto& s : mod.steppers) {
      decl(0, "stepper", s.name) << "\n";
      for (const auto& m : s.methods) {
        line(1) << m.name.name;
        at(m.name.loc);
        body(m.body);
      }
    }
    for (const auto& in : mod.integrators) {
      decl(0, "integrator", in.name) << ":";
      for (const auto& step : in.steps) os_ << " " << step.name;
      os_ << "\n";
    }
    for (const auto& s : mod.scenes) scene(s);
  }

 private:
  llvm::raw_ostream& line(int indent) { return os_.indent(2 * indent); }

  // ` <line:col>`
  llvm::raw_ostream& at(llvm::SMLoc loc) {
    DiagnosticEngine::Position pos = diags_.position(loc);
    if (pos.line == 0) return os_ << " <?>";
    return os_ << " <" << pos.line << ":" << pos.col << ">";
  }

  // `KIND name <line:col>`
  llvm::raw_ostream& decl(int indent, llvm::StringRef kind, const ast::Ident& name) {
    line(indent) << kind << " " << name.name;
    return at(name.loc);
  }

  // ` = expr`, nothing for a null expression.
  void init(const ast::ExprPtr& e) {
    if (!e) return;
    os_ << " = ";
    printExpr(*e, os_);
  }

  // ` (a = 1, b = [x, y])`
  void kwargs(const std::vector<ast::KwArg>& args) {
    os_ << " (";
    llvm::interleaveComma(args, os_, [&](const ast::KwArg& a) {
      os_ << a.name.name << " = ";
      if (!a.isList) return printExpr(*a.value, os_);
      os_ << "[";
      llvm::interleaveComma(a.list, os_, [&](const ast::Ident& i) { os_ << i.name; });
      os_ << "]";
    });
    os_ << ")";
  }

  // ` body <line:col> "first line" ... N lines`
  void body(const ast::Body& b) {
    llvm::StringRef text(b.text);
    llvm::StringRef first;
    for (llvm::StringRef rest = text; !rest.empty() && first.empty();) {
      auto [l, tail] = rest.split('\n');
      first = l.trim();
      rest = tail;
    }
    size_t lines = text.count('\n') + 1;
    os_ << " body";
    at(b.start) << " \"" << first << "\" ... " << lines << (lines == 1 ? " line" : " lines")
                << "\n";
  }

  void array(const ast::ArrayDecl& a) {
    decl(0, "array", a.name) << "\n";
    arrayItems(a, 1);
  }

  void arrayItems(const ast::ArrayDecl& a, int indent) {
    for (const auto& g : a.geometry) {
      decl(indent, "geometry", g.builder);
      kwargs(g.args);
      os_ << "\n";
    }
    for (const auto& l : a.loads) {
      line(indent) << "load \"" << l.path << "\"";
      at(l.loc) << "\n";
    }
    for (const auto& p : a.properties) {
      line(indent) << "property " << p.type;
      if (p.stride != 1) os_ << "[" << p.stride << "]";
      os_ << " " << p.name.name;
      at(p.name.loc);
      init(p.init);
      os_ << "\n";
    }
    for (const auto& c : a.constants) {
      line(indent) << "const " << c.name.name;
      if (c.size != 1) os_ << "[" << c.size << "]";
      at(c.name.loc);
      init(c.init);
      os_ << "\n";
    }
    for (const auto& w : a.whens)
      when(*w, indent, [&](const ast::ArrayDecl& part, int in) { arrayItems(part, in); });
  }

  // `when` blocks: one line per branch, its body one level deeper.
  template <class Body, class PrintBody>
  void when(const ast::When<Body>& w, int indent, PrintBody printBody) {
    bool first = true;
    for (const auto& b : w.branches) {
      if (!b.hasCondition) {
        line(indent) << "else\n";
      } else {
        const auto& c = b.condition;
        line(indent) << (first ? "" : "else ") << "when " << c.option.name
                     << (c.isIn ? " in [" : c.negated ? " != " : " == ");
        llvm::interleaveComma(c.values, os_, [&](const ast::Ident& v) { os_ << v.name; });
        os_ << (c.isIn ? "]" : "");
        at(c.loc) << "\n";
      }
      first = false;
      printBody(b.body, indent + 1);
    }
  }

  void equation(const ast::EquationDecl& eq) {
    decl(0, "equation", eq.name) << " (";
    llvm::interleaveComma(eq.params, os_, [&](const ast::EqParam& p) {
      os_ << p.name.name;
      init(p.defaultValue);
    });
    os_ << ")\n";
    for (const auto& c : eq.consts) {
      decl(1, "const", c.name);
      init(c.value);
      os_ << "\n";
    }
    for (const auto& m : eq.methods) {
      line(1) << ast::methodKeyword(m.kind);
      if (m.kind == ast::Method::Reduce) os_ << " " << m.reduceOp << " " << m.reduceTarget.name;
      at(m.loc);
      body(m.body);
    }
  }

  void scene(const ast::SceneDecl& s) {
    decl(0, "scene", s.name) << "\n";
    sceneItems(s, 1);
  }

  void sceneItems(const ast::SceneDecl& s, int indent) {
    for (const auto& set : s.settings) {
      decl(indent, "set", set.key);
      init(set.value);
      os_ << "\n";
    }
    for (const auto& st : s.steppers) {
      line(indent) << "stepper " << st.array.name << " = " << st.stepper.name;
      at(st.array.loc) << "\n";
    }
    if (s.hasAdaptiveDt) {
      line(indent) << "adaptive_dt";
      at(s.adaptiveDtLoc);
      kwargs(s.adaptiveDt);
      os_ << "\n";
    }
    for (const auto& out : s.outputs) output(out, indent);
    for (const auto& d : s.domains) domain(d, indent);
    for (const auto& z : s.zones) {  // inlet NAME (kwargs) <loc>  (ParseZones.cpp)
      line(indent) << (z.inlet ? "inlet " : "outlet ") << z.name.name;
      kwargs(z.args);
      at(z.loc) << "\n";
    }
    if (s.equationsLoc.isValid()) {
      line(indent) << "equations";
      at(s.equationsLoc) << "\n";
      groupItems(s.equations, indent + 1);
    }
    for (const auto& w : s.whens)
      when(*w, indent, [&](const ast::SceneDecl& part, int in) { sceneItems(part, in); });
  }

  void domain(const ast::DomainDecl& d, int indent) {
    line(indent) << "domain";
    at(d.loc) << "\n";
    for (const auto& item : d.items) {
      line(indent + 1) << (item.kind == ast::DomainItem::Periodic ? "periodic " : "mirror ")
              << item.axis.name;
      if (item.lo && item.hi) {
        os_ << " in [";
        printExpr(*item.lo, os_);
        os_ << ", ";
        printExpr(*item.hi, os_);
        os_ << "]";
      } else if (item.lo) {
        os_ << " >= ";
        printExpr(*item.lo, os_);
      } else if (item.hi) {
        os_ << " <= ";
        printExpr(*item.hi, os_);
      }
      at(item.loc) << "\n";
    }
  }

  void output(const ast::OutputDecl& out, int indent) {
    line(indent) << "output";
    at(out.loc);
    if (out.every) {
      os_ << " every ";
      printExpr(*out.every, os_);
    } else {
      os_ << " at [";
      llvm::interleaveComma(out.at, os_, [&](const ast::ExprPtr& t) { printExpr(*t, os_); });
      os_ << "]";
    }
    os_ << "\n";
    for (const auto& item : out.items) {
      line(indent + 1) << item.array.name << "(";
      llvm::interleaveComma(item.props, os_, [&](const ast::Ident& p) { os_ << p.name; });
      os_ << ")";
      at(item.array.loc) << "\n";
    }
  }

  void groupItems(const std::vector<ast::GroupItem>& items, int indent) {
    for (const auto& item : items) {
      if (item.group) {
        line(indent) << "group";
        at(item.group->loc);
        if (!item.group->options.empty()) kwargs(item.group->options);
        os_ << "\n";
        groupItems(item.group->items, indent + 1);
      } else if (item.when) {
        when(*item.when, indent, [&](const std::vector<ast::GroupItem>& part, int in) {
          groupItems(part, in);
        });
      } else {
        decl(indent, "instance", item.equation->equation);
        kwargs(item.equation->args);
        os_ << "\n";
      }
    }
  }

  llvm::raw_ostream& os_;
  const DiagnosticEngine& diags_;
};

}  // namespace

void printModule(const ast::Module& mod, llvm::raw_ostream& os, const DiagnosticEngine& diags) {
  Printer(os, diags).module(mod);
}

}  // namespace sphc
