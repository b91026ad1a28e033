#include "codegen/CppEmitter.h"

#include "analysis/Access.h"
#include "analysis/Passes.h"
#include "sema/Geometry.h"

#include "llvm/Support/FileSystem.h"
#include "llvm/Support/Path.h"
#include "llvm/Support/raw_ostream.h"

#include <functional>
#include <map>
#include <set>
#include <sstream>

namespace sphc {

namespace {

using NameMap = std::function<std::string(const std::string&)>;

// A declarative expression as C++ (doubles throughout: `1/2` is 0.5, as a user expects).
std::string exprCpp(const ast::Expr& e, const NameMap& names) {
  switch (e.kind) {
    case ast::Expr::Number: {
      std::string t = e.text.empty() ? std::to_string(e.number) : e.text;
      if (t.find_first_of(".eE") == std::string::npos) t += ".0";
      return t;
    }
    case ast::Expr::Name:
      if (e.text == "pi") return "M_PI";
      if (e.text == "e") return "M_E";
      if (e.text == "true") return "1.0";
      if (e.text == "false") return "0.0";
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

std::string bodyFunctionName(const std::string& owner, const std::string& method) {
  return owner + "_" + method;
}

class Emitter {
 public:
  Emitter(const Plan& plan, const DiagnosticEngine& diags, const EmitOptions& opts)
      : plan_(plan), diags_(diags), openmp_(opts.backend == "openmp") {}
  std::string run();

 private:
  // Parameters of a body function, in order, as (C++ declaration, argument kind) pairs.
  struct BodyParam {
    std::string decl;  // e.g. "const double* s_m"
    enum Kind { Idx, SIdx, T, Dt, Pair, Scalar, DProp, SProp } kind;
    std::string name;  // property, pair quantity or scalar name
  };
  std::vector<BodyParam> bodyParams(const PlanBody& b, int destArray) const;
  void emitBodyFunction(const PlanBody& b, const std::string& name, const std::string& ret,
                        int destArray);
  std::string callBody(const std::string& fn, const PlanBody& b, int dest, int src,
                       const std::string& eqValues, const std::string& idx) const;
  std::string propPtr(int array, const std::string& prop) const;
  void emitParams();
  void emitSetup();
  void emitArraySetup(const PlanArray& a);
  void emitGroup(const PlanGroup& g, const std::string& name);
  void emitPhase(const std::vector<int>& eqs, const std::string& name);
  void emitSteppers();
  void emitStep();
  void emitAdaptiveDt();
  void emitMain();
  std::string loc(llvm::SMLoc l) const { return diags_.lineInfo(l); }
  std::string paramRef(const std::string& n) const { return "P." + n; }
  std::string eqStruct(const PlanEquation& eq) const { return "eq" + std::to_string(eq.id); }
  const PlanArray& arr(int a) const { return plan_.arrays[a]; }
  int propIndex(int a, const std::string& p) const {
    for (size_t i = 0; i < arr(a).props.size(); ++i)
      if (arr(a).props[i].name == p) return static_cast<int>(i);
    return -1;
  }
  int constIndex(int a, const std::string& c) const {
    const auto& cs = arr(a).constants;
    auto it = std::find(cs.begin(), cs.end(), c);
    return it == cs.end() ? -1 : static_cast<int>(it - cs.begin());
  }

  // `#pragma omp parallel for` (with `clauses`) before a loop over particles, for the OpenMP
  // backend; nothing for serial. Loops over destination particles only write their own
  // particle (gather), so they need no atomics and give the serial result bit for bit.
  std::string parallelFor(const std::string& indent, const std::string& clauses = "") const {
    if (!openmp_) return "";
    return indent + "#pragma omp parallel for schedule(static)" +
           (clauses.empty() ? "" : " " + clauses) + "\n";
  }

  const Plan& plan_;
  const DiagnosticEngine& diags_;
  bool openmp_ = false;
  std::ostringstream out_;
  std::ostringstream scene_;  // members of struct Scene
  std::vector<std::string> groupFunctions_;
  std::set<std::string> sourceArrays_;  // arrays that need a cell list
  std::set<std::string> loopArrays_;    // arrays in a neighbour loop, as dest or source
  int phaseCounter_ = 0;
};

std::vector<Emitter::BodyParam> Emitter::bodyParams(const PlanBody& b, int destArray) const {
  std::vector<BodyParam> ps;
  const BodyFacts& f = b.facts;
  bool isLoop = b.source.kind == BodyKind::Loop;
  ps.push_back({"int d_idx", BodyParam::Idx, ""});
  if (isLoop) ps.push_back({"int s_idx", BodyParam::SIdx, ""});
  ps.push_back({"double t", BodyParam::T, ""});
  ps.push_back({"double dt", BodyParam::Dt, ""});
  for (const auto& q : pairQuantityNames())
    if (f.pairQuantities.count(q)) {
      bool vec = q == "XIJ" || q == "VIJ" || q == "DWIJ" || q == "DWI" || q == "DWJ";
      ps.push_back({std::string(vec ? "const double* " : "double ") + q, BodyParam::Pair, q});
    }
  for (const auto& s : b.source.scalars)
    if (f.scalarsUsed.count(s)) ps.push_back({"double " + s, BodyParam::Scalar, s});
  std::set<std::string> written;
  for (const auto& w : f.dWrites) written.insert(w.prop);
  std::set<std::string> dprops;
  for (const auto& r : f.dReads) dprops.insert(r.prop);
  dprops.insert(written.begin(), written.end());
  for (const auto& p : dprops) {
    std::string type = "double";
    if (destArray >= 0)
      if (const PlanProperty* pp = arr(destArray).find(p)) type = cppType(pp->type);
    bool isConst = destArray >= 0 && constIndex(destArray, p) >= 0;
    ps.push_back({std::string(written.count(p) || isConst ? "" : "const ") + type + "* d_" + p,
                  BodyParam::DProp, p});
  }
  std::set<std::string> sprops;
  for (const auto& r : f.sReads) sprops.insert(r.prop);
  for (const auto& p : sprops) ps.push_back({"const double* s_" + p, BodyParam::SProp, p});
  return ps;
}

void Emitter::emitBodyFunction(const PlanBody& b, const std::string& name,
                               const std::string& ret, int destArray) {
  auto params = bodyParams(b, destArray);
  out_ << "// " << b.source.label << ", from " << loc(b.source.start) << "\n";
  out_ << "static inline " << ret << " " << name << "(";
  for (size_t i = 0; i < params.size(); ++i) out_ << (i ? ", " : "") << params[i].decl;
  out_ << ") {";
  // The body exactly as written; its first line continues after the opening brace.
  std::string text = b.source.text;
  out_ << text;
  if (text.empty() || text.back() != '\n') out_ << "\n";
  out_ << "}\n\n";
}

std::string Emitter::propPtr(int a, const std::string& p) const {
  int c = constIndex(a, p);
  if (c >= 0) return arr(a).name + ".constant(" + std::to_string(c) + ")";
  int i = propIndex(a, p);
  if (i < 0) SPHC_INTERNAL("property '" + p + "' of '" + arr(a).name + "' was not allocated");
  return arr(a).name + "." + accessor(arr(a).props[i].type) + "(" + std::to_string(i) + ")";
}

std::string Emitter::callBody(const std::string& fn, const PlanBody& b, int dest, int src,
                              const std::string& eqValues, const std::string& time) const {
  std::string s = fn + "(";
  bool first = true;
  for (const auto& p : bodyParams(b, dest)) {
    s += first ? "" : ", ";
    first = false;
    switch (p.kind) {
      case BodyParam::Idx: s += "d_idx"; break;
      case BodyParam::SIdx: s += "s_idx"; break;
      case BodyParam::T: s += time; break;
      case BodyParam::Dt: s += "dt"; break;
      case BodyParam::Pair: s += p.name; break;
      case BodyParam::Scalar: s += eqValues + "." + p.name; break;
      case BodyParam::DProp: s += "d_" + p.name; break;
      case BodyParam::SProp: s += "s_" + p.name; break;
    }
  }
  (void)src;
  return s + ")";
}

void Emitter::emitParams() {
  scene_ << "  struct Params {\n";
  for (const auto* p : plan_.params)
    scene_ << "    double " << p->name.name << " = 0.0;  // from " << loc(p->name.loc) << "\n";
  scene_ << "  } P;\n\n";
  // Equation instances: their parameters and constants, evaluated at set-up.
  for (const auto& eq : plan_.equations) {
    if (!eq.live) continue;
    scene_ << "  struct {";
    for (const auto& [n, v] : eq.values) scene_ << " double " << n << " = 0.0;";
    scene_ << " } " << eqStruct(eq) << ";  // " << eq.name << "(dest = " << arr(eq.dest).name
           << "), from " << loc(eq.loc) << "\n";
  }
  scene_ << "\n";
}

void Emitter::emitArraySetup(const PlanArray& a) {
  const std::string& A = a.name;
  scene_ << "    // array " << A << ", from " << loc(a.loc) << "\n    {\n";
  scene_ << "      sphc::Points pts;\n";
  auto paramNames = [&](const std::string& n) { return paramRef(n); };
  for (const auto& g : a.decl->geometry) {
    const GeometryBuilder* b = findGeometryBuilder(g.builder.name);
    std::map<std::string, std::string> args;
    for (const auto& arg : b->args)
      if (arg.defaultValue) args[arg.name] = arg.defaultValue + std::string(".0");
    for (const auto& kw : g.args)
      if (kw.value) args[kw.name.name] = exprCpp(*kw.value, paramNames);
    scene_ << "      {  // geometry " << b->name << ", from " << loc(g.builder.loc) << "\n";
    const std::string& n = b->name;
    if (n == "block" || n == "tank") {
      scene_ << "        const double lo[3] = {" << args["xmin"] << ", " << args["ymin"] << ", "
             << args["zmin"] << "};\n";
      scene_ << "        const double hi[3] = {" << args["xmax"] << ", " << args["ymax"] << ", "
             << args["zmax"] << "};\n";
      if (n == "block")
        scene_ << "        pts.append(sphc::block(DIM, lo, hi, " << args["dx"] << "));\n";
      else
        scene_ << "        pts.append(sphc::tank(DIM, lo, hi, " << args["dx"]
               << ", static_cast<int>(" << args["layers"] << "), " << args["top"]
               << " != 0.0));\n";
    } else if (n == "disk") {
      scene_ << "        pts.append(sphc::disk(" << args["cx"] << ", " << args["cy"] << ", "
             << args["r"] << ", " << args["dx"] << "));\n";
    } else if (n == "sphere") {
      scene_ << "        pts.append(sphc::sphere(" << args["cx"] << ", " << args["cy"] << ", "
             << args["cz"] << ", " << args["r"] << ", " << args["dx"] << "));\n";
    } else if (n == "cylinder") {
      scene_ << "        pts.append(sphc::cylinder(" << args["cx"] << ", " << args["cy"] << ", "
             << args["r"] << ", " << args["zmin"] << ", " << args["zmax"] << ", "
             << args["dx"] << "));\n";
    } else if (n == "line") {
      scene_ << "        const double p0[3] = {" << args["x0"] << ", " << args["y0"] << ", "
             << args["z0"] << "};\n";
      scene_ << "        const double p1[3] = {" << args["x1"] << ", " << args["y1"] << ", "
             << args["z1"] << "};\n";
      scene_ << "        pts.append(sphc::line(p0, p1, " << args["dx"] << "));\n";
    }
    scene_ << "      }\n";
  }
  // Files: positions, and the values of any property of this array that the file has.
  for (const auto& l : a.decl->loads) {
    std::string path = l.path;
    scene_ << "      {  // load \"" << path << "\", from " << loc(l.loc) << "\n";
    scene_ << "        loaded_" << A << ".push_back(sphc::load_particles(source_dir, \"" << path
           << "\", \"" << A << "\"));\n";
    scene_ << "        pts.append(sphc::positions_of(loaded_" << A << ".back()));\n";
    scene_ << "      }\n";
  }
  scene_ << "      " << A << ".name = \"" << A << "\";\n";
  for (const auto& p : a.props)
    scene_ << "      " << A << ".add_property(\"" << p.name << "\", " << propTypeEnum(p.type)
           << ", " << p.stride << ");\n";
  for (const auto* c : [&] {
         std::vector<const ast::ConstDecl*> v;
         for (const auto& c : a.decl->constants) v.push_back(&c);
         return v;
       }()) {
    scene_ << "      " << A << ".add_constant(\"" << c->name.name << "\", " << c->size << ", "
           << (c->init ? exprCpp(*c->init, paramNames) : "0.0") << ");\n";
  }
  for (const auto& c : a.constants) {
    bool declared = false;
    for (const auto& dc : a.decl->constants) declared |= dc.name.name == c;
    if (!declared)
      scene_ << "      " << A << ".add_constant(\"" << c << "\", 1, 0.0);  // reduce target\n";
  }
  scene_ << "      " << A << ".resize(pts.size());\n";
  // Initial values, particle by particle, in declaration order.
  std::vector<const PlanProperty*> inits;
  for (const auto& p : a.props)
    if (p.init) inits.push_back(&p);
  scene_ << "      for (std::size_t i = 0; i < pts.size(); ++i) {\n";
  scene_ << "        const double x = pts.x[i], y = pts.y[i], z = pts.z[i];\n";
  for (const char* c : {"x", "y", "z"})
    if (propIndex(plan_.arrayIndex(A), c) >= 0)
      scene_ << "        " << propPtr(plan_.arrayIndex(A), c) << "[i] = " << c << ";\n";
  scene_ << "        (void)x; (void)y; (void)z;\n";
  std::set<std::string> locals = {"x", "y", "z"};
  auto initNames = [&](const std::string& n) {
    if (locals.count(n)) return n == "x" || n == "y" || n == "z" ? n : "v_" + n;
    return paramRef(n);
  };
  for (const auto* p : inits) {
    scene_ << "        const double v_" << p->name << " = " << exprCpp(*p->init, initNames)
           << ";  // from " << loc(p->declLoc) << "\n";
    for (int k = 0; k < p->stride; ++k)
      scene_ << "        " << propPtr(plan_.arrayIndex(A), p->name) << "[i * " << p->stride
             << " + " << k << "] = static_cast<" << cppType(p->type) << ">(v_" << p->name
             << ");\n";
    locals.insert(p->name);
  }
  scene_ << "      }\n";
  if (!a.decl->loads.empty())
    scene_ << "      sphc::apply_loaded(" << A << ", pts.size(), loaded_" << A << ");\n";
  scene_ << "    }\n";
}

void Emitter::emitSetup() {
  scene_ << "  void setup(const std::vector<double>& values, sphc::SceneTimes& times) {\n";
  // Parameters in declaration order: a `param` takes its --set value if given, else its
  // default (which may use earlier ones); a `let` is always computed.
  size_t given = 0;
  for (const auto* p : plan_.params) {
    std::string value = exprCpp(*p->value, [&](const std::string& n) { return paramRef(n); });
    if (p->derived) {
      scene_ << "    P." << p->name.name << " = " << value << ";\n";
      continue;
    }
    scene_ << "    P." << p->name.name << " = std::isnan(values[" << given << "]) ? " << value
           << " : values[" << given << "];\n";
    ++given;
  }
  for (const auto& eq : plan_.equations) {
    if (!eq.live) continue;
    std::set<std::string> earlier;
    std::string s = eqStruct(eq);
    for (const auto& [n, v] : eq.values) {
      // Arguments are scene expressions; defaults and consts use the equation's own values.
      bool own = false;
      const auto* decl = plan_.equationDecls[eq.declIndex].decl;
      for (const auto& c : decl->consts) own |= c.value == v;
      for (const auto& p : decl->params) own |= p.defaultValue == v;
      auto names = [&](const std::string& x) {
        return own && earlier.count(x) ? s + "." + x : paramRef(x);
      };
      scene_ << "    " << s << "." << n << " = " << exprCpp(*v, names) << ";\n";
      earlier.insert(n);
    }
  }
  for (const auto& a : plan_.arrays) emitArraySetup(a);
  auto pn = [&](const std::string& n) { return paramRef(n); };
  scene_ << "    times.tf = " << exprCpp(*plan_.tf, pn) << ";\n";
  scene_ << "    times.dt = " << exprCpp(*plan_.dt, pn) << ";\n";
  if (plan_.outputEvery)
    scene_ << "    times.output_every = " << exprCpp(*plan_.outputEvery, pn) << ";\n";
  for (const auto& t : plan_.outputAt)
    scene_ << "    times.output_at.push_back(" << exprCpp(*t, pn) << ");\n";
  scene_ << "  }\n\n";
}

// One fused evaluation of a list of equations, as PySPH's Group: per destination, every
// initialize, one neighbour pass per source with every loop, then post_loop and reduce.
void Emitter::emitPhase(const std::vector<int>& eqIds, const std::string& name) {
  std::vector<int> dests;
  for (int e : eqIds) {
    const auto& eq = plan_.equations[e];
    if (eq.live && std::find(dests.begin(), dests.end(), eq.dest) == dests.end())
      dests.push_back(eq.dest);
  }
  const PlanGroup* group = nullptr;
  std::function<const PlanGroup*(const PlanGroup&)> findGroup = [&](const PlanGroup& g) {
    for (int e : g.equations)
      if (e == eqIds.front()) return &g;
    for (const auto& sub : g.subgroups)
      if (auto* r = findGroup(*sub)) return r;
    return static_cast<const PlanGroup*>(nullptr);
  };
  if (!eqIds.empty()) group = findGroup(plan_.root);
  scene_ << "  void " << name << "(double t, double dt) {\n";
  scene_ << "    (void)t; (void)dt;\n";
  for (int d : dests) {
    const std::string& D = arr(d).name;
    std::vector<const PlanEquation*> eqs;
    for (int e : eqIds)
      if (plan_.equations[e].live && plan_.equations[e].dest == d)
        eqs.push_back(&plan_.equations[e]);
    scene_ << "    {  // destination " << D << "\n";
    scene_ << "      const int n = static_cast<int>(" << D << ".n);\n";
    // Pointers of every destination property the bodies use.
    std::set<std::string> dprops;
    for (const auto* eq : eqs)
      for (const auto& [k, b] : plan_.equationDecls[eq->declIndex].methods) {
        for (const auto& r : plan_.bodies[b].facts.dReads) dprops.insert(r.prop);
        for (const auto& w : plan_.bodies[b].facts.dWrites) dprops.insert(w.prop);
      }
    for (const auto& p : dprops) {
      int c = constIndex(d, p);
      std::string type = c >= 0 ? "double" : cppType(arr(d).props[propIndex(d, p)].type);
      scene_ << "      " << type << "* d_" << p << " = " << propPtr(d, p) << ";\n";
    }
    auto perParticle = [&](ast::Method::Kind kind, const char* what) {
      std::vector<const PlanEquation*> with;
      for (const auto* eq : eqs)
        if (plan_.equationDecls[eq->declIndex].methods.count(kind)) with.push_back(eq);
      if (with.empty()) return;
      scene_ << parallelFor("      ");
      scene_ << "      for (int d_idx = 0; d_idx < n; ++d_idx) {  // " << what << "\n";
      for (const auto* eq : with) {
        const auto& pd = plan_.equationDecls[eq->declIndex];
        const PlanBody& b = plan_.bodies[pd.methods.at(kind)];
        scene_ << "        "
               << callBody(bodyFunctionName(eq->name, what), b, d, -1, eqStruct(*eq), "t")
               << ";  // " << eq->name << ", from " << loc(eq->loc) << "\n";
      }
      scene_ << "      }\n";
    };
    perParticle(ast::Method::Initialize, "initialize");
    // One neighbour pass per source.
    std::vector<int> sources;
    for (const auto* eq : eqs)
      if (plan_.equationDecls[eq->declIndex].methods.count(ast::Method::Loop))
        for (int s : eq->sources)
          if (std::find(sources.begin(), sources.end(), s) == sources.end())
            sources.push_back(s);
    for (int s : sources) {
      const std::string& S = arr(s).name;
      sourceArrays_.insert(S);
      loopArrays_.insert(S);
      loopArrays_.insert(D);
      std::set<std::string> q;
      if (group) {
        auto it = group->pairQuantities.find({d, s});
        if (it != group->pairQuantities.end()) q = it->second;
      }
      q = pairQuantityClosure(q);
      std::set<std::string> sprops;
      std::vector<const PlanEquation*> loopers;
      for (const auto* eq : eqs) {
        const auto& pd = plan_.equationDecls[eq->declIndex];
        auto it = pd.methods.find(ast::Method::Loop);
        if (it == pd.methods.end()) continue;
        if (std::find(eq->sources.begin(), eq->sources.end(), s) == eq->sources.end()) continue;
        loopers.push_back(eq);
        for (const auto& r : plan_.bodies[it->second].facts.sReads) sprops.insert(r.prop);
      }
      scene_ << "      {  // neighbours: " << D << " <- " << S << "\n";
      std::vector<std::string> pos = positionProps(plan_.dim);
      std::set<std::string> need(pos.begin(), pos.end());
      need.insert("h");
      std::vector<std::string> vel = {"u", "v", "w"};
      vel.resize(plan_.dim);
      if (q.count("VIJ")) need.insert(vel.begin(), vel.end());
      if (q.count("RHOIJ")) need.insert("rho");
      for (const auto& p : need) {
        scene_ << "        const double* di_" << p << " = " << propPtr(d, p) << ";\n";
        scene_ << "        const double* sj_" << p << " = " << propPtr(s, p) << ";\n";
      }
      for (const auto& p : sprops)
        scene_ << "        const double* s_" << p << " = " << propPtr(s, p) << ";\n";
      scene_ << "        const sphc::CellList& cells = cells_" << S << ";\n";
      scene_ << parallelFor("        ");
      scene_ << "        for (int d_idx = 0; d_idx < n; ++d_idx) {\n";
      const char* axes[3] = {"x", "y", "z"};
      for (int k = 0; k < 3; ++k)
        scene_ << "          const double " << axes[k] << "i = "
               << (k < plan_.dim ? std::string("di_") + axes[k] + "[d_idx]" : "0.0") << ";\n";
      scene_ << "          const double hi = di_h[d_idx];\n";
      if (q.count("VIJ"))
        for (int k = 0; k < plan_.dim; ++k)
          scene_ << "          const double " << vel[k] << "i = di_" << vel[k] << "[d_idx];\n";
      scene_ << "          cells.for_each_candidate(xi, yi, zi, [&](std::uint32_t j) {\n";
      scene_ << "            const int s_idx = static_cast<int>(j);\n";
      scene_ << "            const double hj = sj_h[s_idx];\n";
      scene_ << "            const double XIJ[3] = {";
      for (int k = 0; k < 3; ++k)
        scene_ << (k ? ", " : "")
               << (k < plan_.dim ? std::string(axes[k]) + "i - sj_" + axes[k] + "[s_idx]"
                                 : "0.0");
      scene_ << "};\n";
      scene_ << "            const double R2IJ = XIJ[0] * XIJ[0] + XIJ[1] * XIJ[1] + XIJ[2] * "
                "XIJ[2];\n";
      scene_ << "            const double hmax = hi > hj ? hi : hj;\n";
      scene_ << "            if (R2IJ >= RADIUS2 * hmax * hmax) return;  // not a neighbour\n";
      scene_ << "            const double HIJ = 0.5 * (hi + hj);\n";
      if (q.count("RIJ")) scene_ << "            const double RIJ = std::sqrt(R2IJ);\n";
      if (q.count("VIJ")) {
        scene_ << "            const double VIJ[3] = {";
        for (int k = 0; k < 3; ++k)
          scene_ << (k ? ", " : "")
                 << (k < plan_.dim ? vel[k] + "i - sj_" + vel[k] + "[s_idx]" : "0.0");
        scene_ << "};\n";
      }
      if (q.count("WIJ")) scene_ << "            const double WIJ = Kernel::w(RIJ, HIJ);\n";
      if (q.count("WI")) scene_ << "            const double WI = Kernel::w(RIJ, hi);\n";
      if (q.count("WJ")) scene_ << "            const double WJ = Kernel::w(RIJ, hj);\n";
      if (q.count("DWIJ"))
        scene_ << "            double DWIJ[3];\n"
                  "            Kernel::gradient(XIJ, RIJ, HIJ, DWIJ);\n";
      if (q.count("DWI"))
        scene_ << "            double DWI[3];\n"
                  "            Kernel::gradient(XIJ, RIJ, hi, DWI);\n";
      if (q.count("DWJ"))
        scene_ << "            double DWJ[3];\n"
                  "            Kernel::gradient(XIJ, RIJ, hj, DWJ);\n";
      if (q.count("RHOIJ"))
        scene_ << "            const double RHOIJ = 0.5 * (di_rho[d_idx] + sj_rho[s_idx]);\n";
      if (q.count("RHOIJ1")) scene_ << "            const double RHOIJ1 = 1.0 / RHOIJ;\n";
      if (q.count("EPS")) scene_ << "            const double EPS = 0.01 * HIJ * HIJ;\n";
      for (const auto* eq : loopers) {
        const auto& pd = plan_.equationDecls[eq->declIndex];
        const PlanBody& b = plan_.bodies[pd.methods.at(ast::Method::Loop)];
        scene_ << "            " << callBody(bodyFunctionName(eq->name, "loop"), b, d, s,
                                             eqStruct(*eq), "t")
               << ";  // " << eq->name << ", from " << loc(eq->loc) << "\n";
      }
      scene_ << "          });\n        }\n      }\n";
    }
    perParticle(ast::Method::PostLoop, "post_loop");
    // Reductions over the destination array into its constants.
    for (const auto* eq : eqs) {
      const auto& pd = plan_.equationDecls[eq->declIndex];
      auto it = pd.methods.find(ast::Method::Reduce);
      if (it == pd.methods.end()) continue;
      const PlanBody& b = plan_.bodies[it->second];
      std::string init = pd.reduceOp == "sum" ? "0.0"
                         : pd.reduceOp == "max" ? "-HUGE_VAL"
                                                : "HUGE_VAL";
      std::string combine = pd.reduceOp == "sum" ? "acc += v"
                             : pd.reduceOp == "max" ? "acc = v > acc ? v : acc"
                                                    : "acc = v < acc ? v : acc";
      scene_ << "      {  // reduce " << pd.reduceOp << " into " << D << "." << pd.reduceTarget
             << ": " << eq->name << ", from " << loc(eq->loc) << "\n";
      scene_ << "        double acc = " << init << ";\n";
      scene_ << parallelFor("        ", std::string("reduction(") +
                                             (pd.reduceOp == "sum" ? "+" : pd.reduceOp) +
                                             " : acc)");
      scene_ << "        for (int d_idx = 0; d_idx < n; ++d_idx) {\n";
      scene_ << "          const double v = "
             << callBody(bodyFunctionName(eq->name, "reduce"), b, d, -1, eqStruct(*eq), "t")
             << ";\n          " << combine << ";\n        }\n";
      scene_ << "        " << D << ".constant(" << constIndex(d, pd.reduceTarget)
             << ")[0] = acc;\n      }\n";
    }
    scene_ << "    }\n";
  }
  scene_ << "  }\n\n";
}

void Emitter::emitGroup(const PlanGroup& g, const std::string& name) {
  // Runs of direct equations become fused phases; subgroups run in place, in order.
  std::vector<std::string> calls;
  std::vector<int> run;
  int part = 0;
  auto flush = [&] {
    if (run.empty()) return;
    std::string fn = name + "_" + std::to_string(part++);
    emitPhase(run, fn);
    calls.push_back(fn);
    run.clear();
  };
  for (int entry : g.order) {
    if (entry >= 0) {
      run.push_back(g.equations[entry]);
      continue;
    }
    flush();
    std::string fn = name + "_" + std::to_string(part++);
    emitGroup(*g.subgroups[-entry - 1], fn);
    calls.push_back(fn);
  }
  flush();
  std::vector<const PlanEquation*> convergers;
  for (int e : g.equations) {
    const auto& eq = plan_.equations[e];
    if (eq.live && plan_.equationDecls[eq.declIndex].methods.count(ast::Method::Converged))
      convergers.push_back(&eq);
  }
  scene_ << "  // group, from " << loc(g.loc) << "\n";
  scene_ << "  void " << name << "(double t, double dt) {\n";
  if (!g.iterate) {
    for (const auto& c : calls) scene_ << "    " << c << "(t, dt);\n";
    scene_ << "    (void)t; (void)dt;\n  }\n\n";
    return;
  }
  scene_ << "    for (int iteration = 1;; ++iteration) {\n";
  for (const auto& c : calls) scene_ << "      " << c << "(t, dt);\n";
  scene_ << "      bool converged = true;\n";
  for (const auto* eq : convergers) {
    const auto& pd = plan_.equationDecls[eq->declIndex];
    const PlanBody& b = plan_.bodies[pd.methods.at(ast::Method::Converged)];
    scene_ << "      {\n        const int d_idx = 0;\n";
    std::set<std::string> dprops;
    for (const auto& r : b.facts.dReads) dprops.insert(r.prop);
    for (const auto& p : dprops)
      scene_ << "        double* d_" << p << " = " << propPtr(eq->dest, p) << ";\n";
    scene_ << "        converged = converged && "
           << callBody(bodyFunctionName(eq->name, "converged"), b, eq->dest, -1,
                       eqStruct(*eq), "t")
           << " > 0;  // " << eq->name << ", from " << loc(eq->loc) << "\n      }\n";
  }
  scene_ << "      last_iterations = iteration;\n";
  scene_ << "      if (converged && iteration >= " << g.minIterations << ") break;\n";
  scene_ << "      if (iteration >= " << g.maxIterations << ") break;\n";
  scene_ << "    }\n  }\n\n";
  groupFunctions_.push_back(name);
}

void Emitter::emitSteppers() {
  std::set<std::string> methods;
  for (const auto& a : plan_.arrays)
    if (a.stepper >= 0)
      for (const auto& [m, b] : plan_.steppers[a.stepper].methods) methods.insert(m);
  for (const auto& m : methods) {
    scene_ << "  void stepper_" << m << "(double t, double dt) {\n    (void)t; (void)dt;\n";
    for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a) {
      const PlanArray& A = arr(a);
      if (A.stepper < 0) continue;
      const PlanStepper& st = plan_.steppers[A.stepper];
      auto it = st.methods.find(m);
      if (it == st.methods.end()) continue;
      const PlanBody& b = plan_.bodies[it->second];
      scene_ << "    {  // " << A.name << ": " << st.decl->name.name << "." << m << "\n";
      scene_ << "      const int n = static_cast<int>(" << A.name << ".n);\n";
      std::set<std::string> dprops;
      for (const auto& r : b.facts.dReads) dprops.insert(r.prop);
      for (const auto& w : b.facts.dWrites) dprops.insert(w.prop);
      for (const auto& p : dprops)
        scene_ << "      " << (constIndex(a, p) >= 0 ? "double" : cppType(A.find(p)->type))
               << "* d_" << p << " = " << propPtr(a, p) << ";\n";
      scene_ << parallelFor("      ");
      scene_ << "      for (int d_idx = 0; d_idx < n; ++d_idx)\n";
      scene_ << "        "
             << callBody(bodyFunctionName(st.decl->name.name, m), b, a, -1, "", "t")
             << ";\n    }\n";
    }
    scene_ << "  }\n\n";
  }
}

void Emitter::emitStep() {
  scene_ << "  // Rebuilds the neighbour search of every array that is a source.\n";
  scene_ << "  void update_neighbours() {\n";
  if (!loopArrays_.empty()) {
    // The search domain spans every array that takes part in a neighbour loop.
    scene_ << "    const std::vector<const sphc::ParticleArray*> all = {";
    bool first = true;
    for (const auto& a : plan_.arrays) {
      if (!loopArrays_.count(a.name)) continue;
      scene_ << (first ? "" : ", ") << "&" << a.name;
      first = false;
    }
    scene_ << "};\n";
    scene_ << "    domain = sphc::make_search_domain(all, DIM, Kernel::radius_scale);\n";
  }
  if (!sourceArrays_.empty()) {
    // Every REORDER_EVERY builds the particles are sorted in cell order, so that neighbours
    // are close in memory; all per-particle state moves with them.
    scene_ << "    const bool reorder = builds++ % REORDER_EVERY == 0;\n";
  }
  for (const auto& S : sourceArrays_) {
    int s = plan_.arrayIndex(S);
    const char* axes[3] = {"x", "y", "z"};
    std::string build = "cells_" + S + ".build(domain";
    for (int k = 0; k < 3; ++k)
      build += ", " + (k < plan_.dim ? propPtr(s, axes[k]) : std::string("nullptr"));
    build += ", " + S + ".n);";
    scene_ << "    " << build << "\n";
    scene_ << "    if (reorder) {\n      " << S << ".permute(cells_" << S
           << ".cell_order());\n      " << build << "\n    }\n";
  }
  scene_ << "  }\n\n";
  scene_ << "  void compute_accelerations(double t, double dt) {\n";
  scene_ << "    update_neighbours();\n    equations(t, dt);\n  }\n\n";
  // The integrator's time step; after stage k of m the time is t + k/m dt.
  int stages = 0;
  for (const auto& s : plan_.integratorSteps) stages += s.rfind("stage", 0) == 0;
  scene_ << "  // integrator " << plan_.integratorName << "\n";
  scene_ << "  void step(double t, double dt) {\n";
  int done = 0;
  for (const auto& s : plan_.integratorSteps) {
    std::string time = done == 0 ? "t" : "t + " + std::to_string(done) + ".0 / " +
                                             std::to_string(stages) + ".0 * dt";
    if (s == "compute_accelerations")
      scene_ << "    compute_accelerations(" << time << ", dt);\n";
    else if (s == "update_domain")
      scene_ << "    // update_domain: no periodic or mirror domain in this scene\n";
    else {
      bool any = false;
      for (const auto& a : plan_.arrays)
        any |= a.stepper >= 0 && plan_.steppers[a.stepper].methods.count(s);
      if (any) scene_ << "    stepper_" << s << "(" << time << ", dt);\n";
      if (s.rfind("stage", 0) == 0) ++done;
    }
  }
  scene_ << "  }\n\n";
}

void Emitter::emitAdaptiveDt() {
  if (!plan_.adaptiveDt) return;
  auto pn = [&](const std::string& n) { return paramRef(n); };
  std::string cfl = plan_.cfl ? exprCpp(*plan_.cfl, pn) : "0.3";
  scene_ << "  // The stable time step: CFL (h / (c + |v|)), force (sqrt(h / |a|)) and viscous\n"
            "  // (h^2 / nu) limits over moving particles.\n";
  scene_ << "  double adaptive_dt() {\n";
  scene_ << "    double dt_cfl = HUGE_VAL, dt_force = HUGE_VAL, h2min = HUGE_VAL;\n";
  std::vector<std::string> vel = {"u", "v", "w"}, acc = {"au", "av", "aw"};
  for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a) {
    if (!movesParticles(plan_, a)) continue;
    const std::string& A = arr(a).name;
    scene_ << "    {  // " << A << "\n";
    scene_ << "      const double* h = " << propPtr(a, "h") << ";\n";
    if (plan_.cfl || !plan_.forceFactor) {
      scene_ << "      const double* cs = " << propPtr(a, "cs") << ";\n";
      for (int k = 0; k < plan_.dim; ++k)
        scene_ << "      const double* " << vel[k] << " = " << propPtr(a, vel[k]) << ";\n";
    }
    if (plan_.forceFactor)
      for (int k = 0; k < plan_.dim; ++k)
        scene_ << "      const double* " << acc[k] << " = " << propPtr(a, acc[k]) << ";\n";
    scene_ << parallelFor("      ", "reduction(min : dt_cfl, dt_force, h2min)");
    scene_ << "      for (std::size_t i = 0; i < " << A << ".n; ++i) {\n";
    if (plan_.cfl || !plan_.forceFactor) {
      scene_ << "        const double vmag = std::sqrt(";
      for (int k = 0; k < plan_.dim; ++k)
        scene_ << (k ? " + " : "") << vel[k] << "[i] * " << vel[k] << "[i]";
      scene_ << ");\n";
      scene_ << "        dt_cfl = std::fmin(dt_cfl, h[i] / (cs[i] + vmag));\n";
    }
    if (plan_.nu) scene_ << "        h2min = std::fmin(h2min, h[i] * h[i]);\n";
    if (plan_.forceFactor) {
      scene_ << "        const double amag = std::sqrt(";
      for (int k = 0; k < plan_.dim; ++k)
        scene_ << (k ? " + " : "") << acc[k] << "[i] * " << acc[k] << "[i]";
      scene_ << ");\n";
      scene_ << "        if (amag > 0) dt_force = std::fmin(dt_force, std::sqrt(h[i] / amag));\n";
    }
    scene_ << "      }\n    }\n";
  }
  scene_ << "    double dt = std::fmin(" << cfl << " * dt_cfl, "
         << (plan_.forceFactor ? exprCpp(*plan_.forceFactor, pn) : "1.0") << " * dt_force);\n";
  if (plan_.nu)
    scene_ << "    dt = std::fmin(dt, "
           << (plan_.viscousFactor ? exprCpp(*plan_.viscousFactor, pn) : "0.125")
           << " * h2min / " << exprCpp(*plan_.nu, pn) << ");  // viscous limit\n";
  scene_ << "    return dt;\n";
  scene_ << "  }\n\n";
}

void Emitter::emitMain() {
  out_ << "int main(int argc, char** argv) {\n";
  out_ << "  static Scene scene;\n";
  out_ << "  sphc::SceneProgram prog;\n";
  out_ << "  prog.name = \"" << plan_.sceneName << "\";\n";
  out_ << "  prog.dim = DIM;\n";
  out_ << "  prog.backend = \"" << (openmp_ ? "openmp" : "serial") << "\";\n";
  if (openmp_)
    out_ << "  prog.set_threads = [](int n) {\n"
            "    if (n > 0) omp_set_num_threads(n);\n"
            "    return omp_get_max_threads();\n  };\n";
  for (const auto* p : plan_.params) {
    if (p->derived) continue;  // `let`: not overridable
    bool lit = isLiteral(*p->value);
    char buf[64];
    snprintf(buf, sizeof buf, "%.17g", lit ? literalValue(*p->value) : 0.0);
    out_ << "  prog.params.push_back({\"" << p->name.name << "\", "
         << (lit ? std::string(buf) : "std::nan(\"\")") << ", \""
         << (lit ? std::string("") : "= " + exprText(*p->value)) << "\"});\n";
  }
  out_ << "  prog.setup = [](const std::vector<double>& v, sphc::SceneTimes& times) {\n"
          "    scene.setup(v, times);\n  };\n";
  out_ << "  prog.arrays = [] { return std::vector<sphc::ParticleArray*>{";
  bool first = true;
  for (const auto& a : plan_.arrays) {
    out_ << (first ? "" : ", ") << "&scene." << a.name;
    first = false;
  }
  out_ << "}; };\n";
  out_ << "  prog.compute_initial = [](double t, double dt) { scene.compute_accelerations(t, dt); "
          "};\n";
  out_ << "  prog.step = [](double t, double dt) { scene.step(t, dt); };\n";
  if (plan_.adaptiveDt) out_ << "  prog.adaptive_dt = [] { return scene.adaptive_dt(); };\n";
  bool anyOutput = false;
  for (const auto& a : plan_.arrays) anyOutput |= !a.outputProps.empty();
  for (const auto& a : plan_.arrays) {
    if (anyOutput && a.outputProps.empty()) continue;
    out_ << "  prog.output.push_back({\"" << a.name << "\", {";
    bool firstProp = true;
    for (const auto& p : a.outputProps) {
      if (constIndex(plan_.arrayIndex(a.name), p) >= 0) continue;  // constants: always written
      out_ << (firstProp ? "" : ", ") << "\"" << p << "\"";
      firstProp = false;
    }
    out_ << "}});\n";
  }
  out_ << "  return sphc::run_main(argc, argv, prog);\n}\n";
}

std::string Emitter::run() {
  std::string file = llvm::sys::path::filename(plan_.mainFile).str();
  out_ << "// Generated by sphc from " << file << ": do not edit; edit the .sph and recompile.\n";
  out_ << "// Backend: " << (openmp_ ? "openmp (loops over particles in parallel)" : "serial")
       << ".\n";
  out_ << "// Scene '" << plan_.sceneName << "': dim " << plan_.dim << ", kernel "
       << plan_.kernel << ", integrator "
       << (plan_.integratorName.empty() ? "none" : plan_.integratorName) << ".\n";
  out_ << "#include \"sphc/geometry.h\"\n#include \"sphc/kernels.h\"\n"
          "#include \"sphc/nnps.h\"\n#include \"sphc/particle_array.h\"\n"
          "#include \"sphc/solver.h\"\n";
  bool anyLoad = false;
  for (const auto& a : plan_.arrays) anyLoad |= !a.decl->loads.empty();
  if (anyLoad) out_ << "#include \"sphc/load.h\"\n";
  out_ << "\n#include <math.h>\n#include <cmath>\n#include <cstdint>\n#include <vector>\n";
  if (openmp_) out_ << "\n#include <omp.h>\n";
  out_ << "\n";
  out_ << "namespace {\n\n";
  out_ << "constexpr int DIM = " << plan_.dim << ";\n";
  out_ << "using Kernel = sphc::" << plan_.kernel << "<DIM>;\n";
  out_ << "constexpr double RADIUS2 = Kernel::radius_scale * Kernel::radius_scale;\n\n";
  out_ << "// ---- Equation and stepper bodies, as written in the .sph files ----\n\n";
  // Bodies of live equations (each declaration once) and of steppers.
  std::set<int> emittedDecls;
  for (const auto& eq : plan_.equations) {
    if (!eq.live || !emittedDecls.insert(eq.declIndex).second) continue;
    const auto& pd = plan_.equationDecls[eq.declIndex];
    static const char* names[] = {"initialize", "loop", "post_loop", "reduce", "converged"};
    static const char* rets[] = {"void", "void", "void", "double", "int"};
    for (const auto& [kind, b] : pd.methods)
      emitBodyFunction(plan_.bodies[b], bodyFunctionName(eq.name, names[kind]), rets[kind],
                       eq.dest);
  }
  std::set<int> emittedSteppers;
  for (int a = 0; a < static_cast<int>(plan_.arrays.size()); ++a) {
    int s = arr(a).stepper;
    if (s < 0 || !emittedSteppers.insert(s).second) continue;
    for (const auto& [m, b] : plan_.steppers[s].methods)
      emitBodyFunction(plan_.bodies[b], bodyFunctionName(plan_.steppers[s].decl->name.name, m),
                       "void", a);
  }

  emitParams();
  emitSetup();
  emitGroup(plan_.root, "equations");
  emitSteppers();
  emitStep();
  emitAdaptiveDt();

  out_ << "// ---- The scene ----\n\n";
  out_ << "struct Scene {\n";
  for (const auto& a : plan_.arrays) out_ << "  sphc::ParticleArray " << a.name << ";\n";
  for (const auto& a : plan_.arrays)
    if (!a.decl->loads.empty())
      out_ << "  std::vector<sphc::ParticleArray> loaded_" << a.name << ";\n";
  out_ << "  sphc::SearchDomain domain;\n";
  for (const auto& S : sourceArrays_) out_ << "  sphc::CellList cells_" << S << ";\n";
  out_ << "  int last_iterations = 0;\n";
  if (!sourceArrays_.empty()) {
    out_ << "  static constexpr long REORDER_EVERY = 50;\n";
    out_ << "  long builds = 0;\n";
  }
  if (anyLoad) {
    llvm::SmallString<256> dir(plan_.mainFile);
    llvm::sys::fs::make_absolute(dir);
    out_ << "  std::string source_dir = \"" << llvm::sys::path::parent_path(dir).str()
         << "\";  // where the .sph file is\n";
  }
  out_ << "\n" << scene_.str() << "};\n\n}  // namespace\n\n";
  emitMain();
  return out_.str();
}

}  // namespace

std::string emitCpp(const Plan& plan, const DiagnosticEngine& diags, const EmitOptions& opts) {
  return Emitter(plan, diags, opts).run();
}

}  // namespace sphc
