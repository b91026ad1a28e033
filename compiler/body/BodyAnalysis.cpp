// Equation and stepper bodies through Clang. All bodies of a scene become one small C99
// translation unit (a prelude with the allowed math.h functions and constants, then one
// function per body), which Clang parses in a single in-memory invocation. Clang's diagnostics
// are forwarded to sphc's DiagnosticEngine at .sph locations; sphc's own portability rules and
// the facts the analysis passes need (property reads/writes, pair quantities, t/dt, scalars)
// come from a walk over each function's AST.
//
// A reduce body `{ return c0 * d_h[d_idx]; }` at eq.sph:5:10, whose equation has the scalar
// c0, becomes
//
//   double __sphc_body_1(const int d_idx, const double t, const double dt, const double c0,
//                        double *const d_h) {
//   #line 5 "eq.sph"
//            return c0 * d_h[d_idx]; }
//
// (a loop body also gets `const int s_idx`, pair quantities such as `const double
// DWIJ[const 3]`, and `const double *const s_m` for source properties; only the names a body
// mentions are declared),
// so Clang's presumed locations are the .sph positions. Since the body text is copied verbatim,
// a location inside it maps back to the .sph buffer exactly by its offset from the body's start
// (O(1), and robust to anything the user writes in the body); the #line directive keeps Clang's
// own view of the positions (__LINE__, presumed locations) consistent with that.
#include "body/BodyAnalysis.h"
#include "body/BodyBatch.h"
#include "body/Identifiers.h"

#include "clang/AST/ASTConsumer.h"
#include "clang/AST/ASTContext.h"
#include "clang/Basic/DiagnosticSema.h"
#include "clang/Frontend/CompilerInstance.h"
#include "clang/Frontend/CompilerInvocation.h"
#include "clang/Frontend/FrontendAction.h"
#include "clang/Lex/PreprocessorOptions.h"
#include "llvm/ADT/SmallString.h"
#include "llvm/ADT/StringRef.h"
#include "llvm/Support/MemoryBuffer.h"

#include <algorithm>
#include <cctype>
#include <memory>
#include <set>
#include <utility>

namespace sphc {

const std::vector<std::string>& allowedMathFunctions() {
  static const std::vector<std::string> names = {
      "sqrt", "pow",   "exp",  "log",  "log10", "sin",   "cos",  "tan",   "asin", "acos",
      "atan", "atan2", "sinh", "cosh", "tanh",  "fabs",  "fmin", "fmax",  "floor", "ceil",
      "fmod", "hypot", "cbrt", "copysign", "erf", "round", "trunc"};
  return names;
}

bool laneMathFunction(const std::string& name) {
  static const std::set<std::string> lanes = {"sqrt",  "fabs",  "fmin",  "fmax",    "floor",
                                              "ceil",  "round", "trunc", "copysign"};
  return lanes.count(name) > 0;
}

bool writesStates(BodyKind k) { return k == BodyKind::Converged || k == BodyKind::HostReduce; }

bool isState(const BodySource& b, const std::string& name) {
  return std::find(b.states.begin(), b.states.end(), name) != b.states.end();
}

const std::vector<std::string>& kernelFunctions() {
  static const std::vector<std::string> names = {"KERNEL_W", "KERNEL_DWDR"};
  return names;
}

}  // namespace sphc

namespace sphc::body_detail {

bool isTwoArgumentMathFunction(llvm::StringRef name) {
  return name == "pow" || name == "atan2" || name == "fmin" || name == "fmax" ||
         name == "fmod" || name == "hypot" || name == "copysign";
}

// What a quick lexical scan of a body finds: its identifiers (in order of first appearance,
// outside comments and literals) and the offsets of preprocessor directives other than
// #pragma (`#` first on a line), which bodies may not contain.
struct BodyTokens {
  std::vector<std::string> identifiers;
  std::vector<size_t> directives;
  // The first bracket that does not balance ((), [], {}), and what is wrong with it; Clang
  // would otherwise read past the end of the body into the next one.
  size_t unbalancedAt = std::string::npos;
  std::string unbalanced;
  bool has(const std::string& name) const {
    return std::find(identifiers.begin(), identifiers.end(), name) != identifiers.end();
  }
};

BodyTokens scanBody(llvm::StringRef text) {
  BodyTokens tokens;
  std::vector<std::pair<char, size_t>> open;  // unclosed brackets
  auto mismatch = [&](size_t at, const std::string& what) {
    if (tokens.unbalancedAt == std::string::npos) {
      tokens.unbalancedAt = at;
      tokens.unbalanced = what;
    }
  };
  bool lineStart = true;  // only blanks so far on this line
  for (size_t i = 0; i < text.size();) {
    char c = text[i];
    if (c == '\n') { lineStart = true; ++i; continue; }
    if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') { ++i; continue; }
    bool wasLineStart = lineStart;
    lineStart = false;
    if (text.substr(i).startswith("//")) {
      i = std::min(text.find('\n', i), text.size());
    } else if (text.substr(i).startswith("/*")) {
      size_t end = text.find("*/", i + 2);
      i = end == llvm::StringRef::npos ? text.size() : end + 2;
    } else if (c == '"' || c == '\'') {
      for (++i; i < text.size() && text[i] != c && text[i] != '\n'; ++i)
        if (text[i] == '\\') ++i;
      ++i;
    } else if (c == '#' && wasLineStart) {
      // `#pragma` (e.g. a loop hint) is harmless; other directives are not allowed.
      size_t name = text.find_first_not_of(" \t", i + 1);
      if (name == llvm::StringRef::npos || !text.substr(name).startswith("pragma"))
        tokens.directives.push_back(i);
      ++i;
    } else if (c == '(' || c == '[' || c == '{') {
      open.push_back({c, i});
      ++i;
    } else if (c == ')' || c == ']' || c == '}') {
      char want = c == ')' ? '(' : c == ']' ? '[' : '{';
      if (open.empty() || open.back().first != want)
        mismatch(i, std::string("unexpected '") + c + "'" +
                        (open.empty() ? std::string("")
                                      : std::string(": '") + open.back().first +
                                            "' is still open"));
      else
        open.pop_back();
      ++i;
    } else if (isIdentifierChar(c)) {
      size_t j = i;
      while (j < text.size() && isIdentifierChar(text[j])) ++j;
      std::string ident = text.slice(i, j).str();
      if (!std::isdigit(static_cast<unsigned char>(c)) && !tokens.has(ident))
        tokens.identifiers.push_back(ident);
      i = j;
    } else {
      ++i;
    }
  }
  if (!open.empty())
    mismatch(open.back().second, std::string("'") + open.back().first +
                                     "' is not closed in this body");
  return tokens;
}

std::string cTypeOf(const PropShape& shape) {
  if (shape.type == "int") return "int";
  if (shape.type == "uint") return "unsigned int";
  return "double";
}

// A string as a C string literal (for #line).
std::string quoted(llvm::StringRef s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

// math.h's constants, as macros of the prelude: {name, value}.
const std::vector<std::pair<const char*, const char*>>& mathConstants() {
  static const std::vector<std::pair<const char*, const char*>> constants = {
      {"M_E", "2.71828182845904523536"},    {"M_LOG2E", "1.44269504088896340736"},
      {"M_LOG10E", "0.434294481903251827651"}, {"M_LN2", "0.693147180559945309417"},
      {"M_LN10", "2.30258509299404568402"}, {"M_PI", "3.14159265358979323846"},
      {"M_PI_2", "1.57079632679489661923"}, {"M_PI_4", "0.785398163397448309616"},
      {"M_1_PI", "0.318309886183790671538"}, {"M_2_PI", "0.636619772367581343076"},
      {"M_2_SQRTPI", "1.12837916709551257390"}, {"M_SQRT2", "1.41421356237309504880"},
      {"M_SQRT1_2", "0.707106781186547524401"}};
  return constants;
}

// A name that cannot be a parameter of the synthesised function: a C99 keyword or a macro of
// the prelude. (Sema should not let such a scalar through; if it does, the body's own use of
// the name is what Clang then reports.)
bool isReservedInC(const std::string& name) {
  static const std::set<std::string> keywords = {
      "auto",     "break",  "case",     "char",   "const",    "continue", "default",
      "do",       "double", "else",     "enum",   "extern",   "float",    "for",
      "goto",     "if",     "inline",   "int",    "long",     "register", "restrict",
      "return",   "short",  "signed",   "sizeof", "static",   "struct",   "switch",
      "typedef",  "union",  "unsigned", "void",   "volatile", "while",    "_Bool",
      "_Complex", "_Imaginary"};
  if (keywords.count(name)) return true;
  for (const auto& c : mathConstants())
    if (name == c.first) return true;
  return false;
}

// Declarations every body sees: the allowed math.h functions (double versions) and constants.
std::string prelude() {
  std::string out = "/* sphc: equation and stepper bodies, one function each */\n";
  for (const auto& c : mathConstants())
    out += std::string("#define ") + c.first + " " + c.second + "\n";
  for (const std::string& f : allowedMathFunctions())
    out += "double " + f + (isTwoArgumentMathFunction(f) ? "(double, double);\n" : "(double);\n");
  // The scene's smoothing kernel at any (r, h): KERNEL_W(r, h) = W(r, h), KERNEL_DWDR(r, h) =
  // dW/dr (the generated code defines them for the scene's kernel and dimension).
  for (const std::string& f : kernelFunctions()) out += "double " + f + "(double r, double h);\n";
  return out;
}

// The function of a body. Every sphc name the body mentions is a const parameter, so the C type
// system rejects writes to it; s_ names and pair quantities are declared in every kind of body
// that mentions them, so that using them outside 'loop' gets sphc's clear message instead of
// "undeclared".
void Batch::synthesise() {
  unit_ = prelude();
  regions_.resize(bodies_.size());
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const BodySource& b = bodies_[i];
    if (b.start.isValid()) {
      // The mapping back to .sph is by offset: the text must be the buffer's text at start.
      const llvm::SourceMgr& sm = diags_.sourceMgr();
      unsigned id = sm.FindBufferContainingLoc(b.start);
      const llvm::MemoryBuffer* buf = id ? sm.getMemoryBuffer(id) : nullptr;
      if (!buf || !llvm::StringRef(b.start.getPointer(), buf->getBufferEnd() - b.start.getPointer())
                       .startswith(b.text))
        SPHC_INTERNAL("BodySource.text is not the .sph text at BodySource.start (" + b.label +
                      ")");
    }

    // Preprocessor directives (an #include would even stop Clang) are reported here and
    // blanked out of the unit, keeping every offset.
    BodyTokens tokens = scanBody(b.text);
    std::string text = b.text;
    for (size_t at : tokens.directives) {
      error(static_cast<int>(i), b.start.isValid()
                                     ? llvm::SMLoc::getFromPointer(b.start.getPointer() + at)
                                     : llvm::SMLoc(),
            "preprocessor directives are not allowed in bodies");
      for (size_t k = at; k < text.size() && text[k] != '\n'; ++k) text[k] = ' ';
    }

    // Unbalanced brackets: reported here, and the body is left out of the unit (blanked,
    // keeping offsets), since Clang would read on into the next body.
    if (tokens.unbalancedAt != std::string::npos) {
      error(static_cast<int>(i), b.start.isValid()
                                     ? llvm::SMLoc::getFromPointer(b.start.getPointer() +
                                                                   tokens.unbalancedAt)
                                     : llvm::SMLoc(),
            tokens.unbalanced);
      for (char& ch : text)
        if (ch != '\n') ch = ' ';
      tokens = BodyTokens();
      state[i].blanked = true;
    }

    // The body's text where it stands in its file (#line, then blanks up to its column), so
    // that Clang's locations map back to the .sph file.
    auto appendText = [&](const char* unnamed) {
      DiagnosticEngine::Position pos = diags_.position(b.start);
      unit_ += "#line " + std::to_string(pos.line ? pos.line : 1) + " " +
               quoted(pos.file.empty() ? unnamed : pos.file) + "\n";
      unit_ += std::string(pos.col ? pos.col - 1 : 0, ' ');
      regions_[i].textBegin = unit_.size();
      unit_ += text;
    };

    if (b.kind == BodyKind::Function) {
      // A helper function is its own C definition, copied as written.
      appendText("<function>");
      regions_[i].end = unit_.size() ? unit_.size() - 1 : 0;
      unit_ += "\n";
      continue;
    }

    // Only the names the body mentions become parameters (besides indices and time).
    std::vector<std::string> params;
    auto param = [&](const std::string& decl, const std::string& name) {
      if (tokens.has(name)) params.push_back(decl);
    };
    // A host reduce has the number of real particles N instead of a particle index.
    params.push_back(b.kind == BodyKind::HostReduce ? "const int N" : "const int d_idx");
    // loop_all and initialize_pair have no s_idx of their own: a body may declare one
    // (`int s_idx = NBRS[k];`, as PySPH's loop_all bodies do).
    if (b.kind != BodyKind::LoopAll && b.kind != BodyKind::InitializePair)
      param("const int s_idx", "s_idx");
    param("const unsigned int *const NBRS", "NBRS");
    param("const int N_NBRS", "N_NBRS");
    params.push_back("const double t");
    params.push_back("const double dt");
    for (const std::string& q : pairQuantityNames())
      param(findPairQuantity(q)->vector ? "const double " + q + "[const 3]"
                                        : "const double " + q,
            q);
    std::set<std::string> declared = {"d_idx", "s_idx", "t", "dt", "NBRS", "N_NBRS"};
    declared.insert(pairQuantityNames().begin(), pairQuantityNames().end());
    for (const std::string& s : b.scalars)
      if (!isPropertyName(s) && !isReservedInC(s) && declared.insert(s).second)
        param((isState(b, s) && writesStates(b.kind) ? "double " : "const double ") + s, s);
    for (const std::string& p : tokens.identifiers) {
      if (!isPropertyName(p)) continue;
      auto shape = b.props.find(p.substr(2));
      std::string type = cTypeOf(shape == b.props.end() ? PropShape() : shape->second);
      params.push_back((p[0] == 's' ? "const " : "") + type + " *const " + p);
    }

    const char* ret = b.kind == BodyKind::Reduce ? "double"
                      : b.kind == BodyKind::Converged ? "int" : "void";
    unit_ += std::string(ret) + " " + kFunctionPrefix.str() + std::to_string(i) + "(";
    for (size_t k = 0; k < params.size(); ++k) unit_ += (k ? ", " : "") + params[k];
    unit_ += ") {\n";
    appendText("<body>");
    regions_[i].end = unit_.size();
    unit_ += "}\n";
  }
}

// The first identifier at `p` (after opening parentheses and blanks).
llvm::StringRef identifierAt(const char* p) {
  while (*p == '(' || *p == ' ' || *p == '\t') ++p;
  const char* q = p;
  while (isIdentifierChar(*q)) ++q;
  return llvm::StringRef(p, q - p);
}

// Forwards Clang's diagnostics to sphc's DiagnosticEngine at .sph locations, replacing a few
// by sphc's own clearer messages.
class DiagnosticForwarder : public clang::DiagnosticConsumer {
 public:
  explicit DiagnosticForwarder(Batch& batch) : batch_(batch) {}

  void HandleDiagnostic(clang::DiagnosticsEngine::Level level,
                        const clang::Diagnostic& info) override {
    DiagnosticConsumer::HandleDiagnostic(level, info);
    if (level == clang::DiagnosticsEngine::Ignored) return;
    if (level == clang::DiagnosticsEngine::Note) {
      // A note belongs to the diagnostic before it; notes pointing into the prelude or a
      // signature ("declared here") mean nothing to the user.
      if (dropNotes_ || !info.hasSourceManager()) return;
      int i = batch_.bodyAt(info.getSourceManager(), info.getLocation());
      if (i >= 0) forward(i, llvm::SourceMgr::DK_Note, info);
      return;
    }
    dropNotes_ = true;
    if (!info.hasSourceManager() || info.getLocation().isInvalid()) {
      // Nothing to point at (should not happen for a syntax-only parse of bodies).
      llvm::SmallString<128> msg;
      info.FormatDiagnostic(msg);
      if (level >= clang::DiagnosticsEngine::Error) batch_.diags().error("in bodies: " + msg);
      return;
    }
    const clang::SourceManager& sm = info.getSourceManager();
    int i = batch_.bodyAt(sm, info.getLocation());
    if (i < 0 && batch_.diags().hasErrors()) return;  // a consequence of an error reported
    if (i < 0) {
      llvm::SmallString<128> msg;
      info.FormatDiagnostic(msg);
      clang::PresumedLoc p = sm.getPresumedLoc(info.getLocation());
      SPHC_INTERNAL("diagnostic outside the bodies in the synthesised unit, line " +
                    llvm::Twine(p.isValid() ? p.getLine() : 0) + ": " + msg);
    }
    if (replaced(i, info)) return;
    dropNotes_ = false;
    forward(i, level >= clang::DiagnosticsEngine::Error ? llvm::SourceMgr::DK_Error
                                                        : llvm::SourceMgr::DK_Warning,
            info);
  }

 private:
  void forward(int i, llvm::SourceMgr::DiagKind kind, const clang::Diagnostic& info) {
    llvm::SmallString<128> buf;
    info.FormatDiagnostic(buf);
    // Clang may name the synthesised function ("void function '__sphc_body_3' ...").
    std::string msg = buf.str().str();
    std::string fn = "'" + kFunctionPrefix.str() + std::to_string(i) + "'";
    for (size_t at; (at = msg.find(fn)) != std::string::npos;)
      msg.replace(at, fn.size(), std::string("'") + kindName(batch_.body(i).kind) + "' body");
    batch_.report(i, kind, batch_.toSph(info.getSourceManager(), info.getLocation(), i), msg);
  }

  // sphc's own message instead of Clang's, for cases where Clang's would confuse; true when
  // the diagnostic was handled (replaced or dropped).
  bool replaced(int i, const clang::Diagnostic& info) {
    const clang::SourceManager& sm = info.getSourceManager();
    llvm::SMLoc loc = batch_.toSph(sm, info.getLocation(), i);
    BodyKind kind = batch_.body(i).kind;
    if (kind == BodyKind::Function) {
      // A helper is plain C: Clang's own messages say it best, except for these.
      switch (info.getID()) {
        case clang::diag::ext_implicit_function_decl:
        case clang::diag::ext_implicit_lib_function_decl:
        case clang::diag::warn_implicit_function_decl:
          return true;  // the AST walk reports every call it does not allow
        case clang::diag::warn_falloff_nonvoid_function:
          batch_.reportMissingReturn(i);
          return true;
        case clang::diag::err_conflicting_types:
          // Only after an implicit declaration by an earlier call (names are unique): that
          // call was reported as calling a function declared after it.
          return true;
        default:
          return false;
      }
    }
    switch (info.getID()) {
      case clang::diag::ext_implicit_function_decl:
      case clang::diag::ext_implicit_lib_function_decl:
      case clang::diag::warn_implicit_function_decl:
        return true;  // the AST walk reports every call of a non-math function
      case clang::diag::warn_falloff_nonvoid_function:
        batch_.reportMissingReturn(i);
        return true;
      case clang::diag::ext_return_has_expr:
        batch_.error(i, loc, std::string("'return' with a value is only allowed in 'reduce' and "
                                         "'converged' bodies; use 'return;' in '") +
                                 kindName(kind) + "'");
        return true;
      case clang::diag::ext_return_missing_expr:
        batch_.error(i, loc, std::string("a '") + kindName(kind) +
                                 "' body must return a value: 'return EXPR;'");
        batch_.state[i].missingReturnReported = true;  // that says it all
        return true;
      case clang::diag::err_typecheck_assign_const: {
        // A write to what sphc declares read-only: s_NAME[...] (const elements), d_NAME and
        // s_NAME themselves (const pointers), pair quantities, indices, t, dt and scalars.
        if (info.getNumRanges() == 0) return false;
        clang::CharSourceRange range = info.getRange(0);
        clang::SourceLocation begin = sm.getExpansionLoc(range.getBegin());
        std::string name = identifierAt(sm.getCharacterData(begin)).str();
        llvm::SMLoc at = batch_.toSph(sm, begin, i);
        bool whole = sm.getExpansionLoc(range.getEnd()) == begin;  // `name = ...`
        const BodySource& b = batch_.body(i);
        bool scalar = std::find(b.scalars.begin(), b.scalars.end(), name) != b.scalars.end();
        if (isPropertyName(name) && whole)
          batch_.error(i, at, "cannot assign to property '" + name +
                                  "' itself; write its elements, e.g. " + name + "[" +
                                  name.substr(0, 2) + "idx] = ...");
        else if (isPropertyName(name) && name[0] == 'd')
          return false;  // d_ elements are writable: something else is const
        else if (name[0] == 's' && isPropertyName(name) && seesSources(kind))
          batch_.error(i, at, "cannot write to source property '" + name +
                                  "': another thread may own that particle; write d_ "
                                  "properties only");
        else if (name == "NBRS" || name == "N_NBRS") {
          if (kind != BodyKind::LoopAll)
            batch_.reportOutsideLoop(i, at, name);
          else
            batch_.error(i, at, "'" + name + "' is read-only in bodies");
        } else if ((name[0] == 's' && isPropertyName(name)) || name == "s_idx" ||
                 isPairQuantity(name)) {
          if (kind != BodyKind::Loop)
            batch_.reportOutsideLoop(i, at, name);
          else if (name[0] == 's' && name != "s_idx")
            batch_.error(i, at, "cannot write to source property '" + name +
                                    "': another thread may own that particle; write d_ "
                                    "properties only");
          else
            batch_.error(i, at, "'" + name + "' is read-only in bodies");
        } else if (scalar && isState(b, name)) {
          batch_.error(i, at, "state '" + name + "' can be written only in 'converged' and "
                              "'reduce { }' (on the host, once per call); '" + kindName(kind) +
                              "' runs per particle, in parallel, and reads it");
        } else if (name == "d_idx" || name == "t" || name == "dt" || scalar) {
          batch_.error(i, at, "'" + name + "' is read-only in bodies");
        } else {
          return false;
        }
        return true;
      }
      default:
        return false;
    }
  }

  Batch& batch_;
  bool dropNotes_ = true;  // the last error/warning was not forwarded: drop its notes
};

}  // namespace sphc::body_detail

namespace sphc {
namespace {
using namespace body_detail;

// Checks each body function as soon as Clang has parsed it, so sphc's messages come right
// after Clang's for the same body.
class BodyConsumer : public clang::ASTConsumer {
 public:
  explicit BodyConsumer(Batch& batch) : batch_(batch) {}

  bool HandleTopLevelDecl(clang::DeclGroupRef group) override {
    for (clang::Decl* d : group) {
      auto* fn = llvm::dyn_cast<clang::FunctionDecl>(d);
      if (!fn || !fn->hasBody()) continue;
      if (int j = batch_.functionOf(fn->getASTContext().getSourceManager(), fn); j >= 0) {
        checkBodyFunction(batch_, j, fn->getASTContext().getSourceManager(), fn);
        continue;
      }
      if (!fn->getName().startswith(kFunctionPrefix)) continue;
      unsigned index = 0;
      if (fn->getName().drop_front(kFunctionPrefix.size()).getAsInteger(10, index))
        SPHC_INTERNAL("unexpected body function " + fn->getName());
      checkBodyFunction(batch_, index, fn->getASTContext().getSourceManager(), fn);
    }
    return true;
  }

 private:
  Batch& batch_;
};

class BodyAction : public clang::ASTFrontendAction {
 public:
  explicit BodyAction(Batch& batch) : batch_(batch) {}

 protected:
  std::unique_ptr<clang::ASTConsumer> CreateASTConsumer(clang::CompilerInstance&,
                                                        llvm::StringRef) override {
    return std::make_unique<BodyConsumer>(batch_);
  }

 private:
  Batch& batch_;
};

}  // namespace

std::vector<BodyFacts> BodyAnalyzer::analyze(const std::vector<BodySource>& bodies) {
  if (bodies.empty()) return {};
  Batch batch(diags_, bodies);

  // A syntax-only cc1 invocation over the in-memory unit: C99, no headers searched.
  const char* args[] = {"-fsyntax-only", "-x", "c", "-std=c99", "-nostdsysteminc", "-nobuiltininc",
                        "-fno-caret-diagnostics",  // also: no "N errors generated." on stderr
                        "-Wall", "-Wuninitialized", "-Wsometimes-uninitialized",
                        "-Werror=implicit-function-declaration", "-Werror=implicit-int",
                        "-Werror=return-type", "-Werror=vla",
                        // helpers take arrays: passing the wrong kind is an error in C++ too
                        "-Werror=incompatible-pointer-types",
                        "-Werror=incompatible-pointer-types-discards-qualifiers",
                        "-Werror=int-conversion", kUnitName};
  auto invocation = std::make_shared<clang::CompilerInvocation>();
  {
    // Our own arguments: any complaint about them is a bug in sphc.
    clang::IgnoringDiagConsumer ignore;
    llvm::IntrusiveRefCntPtr<clang::DiagnosticsEngine> argDiags =
        clang::CompilerInstance::createDiagnostics(new clang::DiagnosticOptions, &ignore, false);
    if (!clang::CompilerInvocation::CreateFromArgs(*invocation, args, *argDiags))
      SPHC_INTERNAL("bad Clang arguments for body analysis");
  }
  // The invocation owns the remapped buffer.
  invocation->getPreprocessorOpts().addRemappedFile(
      kUnitName, llvm::MemoryBuffer::getMemBufferCopy(batch.unit(), kUnitName).release());

  DiagnosticForwarder forwarder(batch);
  clang::CompilerInstance ci;
  ci.setInvocation(std::move(invocation));
  ci.createDiagnostics(&forwarder, /*ShouldOwnClient=*/false);
  BodyAction action(batch);
  ci.ExecuteAction(action);

  for (size_t i = 0; i < bodies.size(); ++i)
    batch.facts[i].ok = batch.state[i].checked && batch.state[i].errors == 0;
  return std::move(batch.facts);
}

}  // namespace sphc
