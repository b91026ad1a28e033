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

#include "clang/AST/ASTConsumer.h"
#include "clang/AST/ASTContext.h"
#include "clang/AST/RecursiveASTVisitor.h"
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

const std::vector<std::string>& kernelFunctions() {
  static const std::vector<std::string> names = {"KERNEL_W", "KERNEL_DWDR"};
  return names;
}

namespace {

// Names of the synthesised translation unit and of the body functions in it.
constexpr const char* kUnitName = "<sphc-bodies>.c";
constexpr llvm::StringLiteral kFunctionPrefix = "__sphc_body_";

bool isPairQuantity(const std::string& name) { return findPairQuantity(name) != nullptr; }

bool isTwoArgumentMathFunction(llvm::StringRef name) {
  return name == "pow" || name == "atan2" || name == "fmin" || name == "fmax" ||
         name == "fmod" || name == "hypot" || name == "copysign";
}

bool isIdentChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// `d_NAME` / `s_NAME` (a property access), but not the indices d_idx / s_idx.
bool isPropertyName(llvm::StringRef name) {
  return (name.startswith("d_") || name.startswith("s_")) && name.size() > 2 &&
         name != "d_idx" && name != "s_idx";
}

const char* kindName(BodyKind kind) {
  switch (kind) {
    case BodyKind::Initialize: return "initialize";
    case BodyKind::Loop: return "loop";
    case BodyKind::PostLoop: return "post_loop";
    case BodyKind::Reduce: return "reduce";
    case BodyKind::Converged: return "converged";
    case BodyKind::InitializePair: return "initialize_pair";
    case BodyKind::LoopAll: return "loop_all";
    case BodyKind::StepperInit: return "initialize";
    case BodyKind::StepperStage: return "stage";
    case BodyKind::Function: return "function";
  }
  return "body";
}

bool returnsValue(BodyKind kind) { return kind == BodyKind::Reduce || kind == BodyKind::Converged; }

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
    } else if (isIdentChar(c)) {
      size_t j = i;
      while (j < text.size() && isIdentChar(text[j])) ++j;
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

// Where a body's text (and the closing brace after it) lies in the translation unit.
struct BodyRegion {
  unsigned textBegin = 0;  // offset of text[0]
  unsigned end = 0;        // offset of the closing `}` (the .sph `}` after the text)
};

// Per-body bookkeeping shared by the diagnostic forwarder and the AST walk.
struct BodyState {
  unsigned errors = 0;
  bool checked = false;  // its function reached the AST walk (not after a fatal error)
  bool missingReturnReported = false;
  bool blanked = false;  // left out of the unit after an error (unbalanced brackets)
  std::set<std::string> reportedOutsideLoop;  // s_/pair-quantity names already reported
};

// One analysis: the bodies, the synthesised unit, and everything reported so far.
class Batch {
 public:
  Batch(DiagnosticEngine& diags, const std::vector<BodySource>& bodies)
      : facts(bodies.size()), state(bodies.size()), diags_(diags), bodies_(bodies) {
    synthesise();
  }

  const std::string& unit() const { return unit_; }
  const BodySource& body(int i) const { return bodies_[i]; }
  DiagnosticEngine& diags() { return diags_; }

  // The body whose text contains `loc` (after macro expansion), or -1.
  int bodyAt(const clang::SourceManager& sm, clang::SourceLocation loc) const {
    if (loc.isInvalid()) return -1;
    loc = sm.getExpansionLoc(loc);
    if (sm.getFileID(loc) != sm.getMainFileID()) return -1;
    unsigned off = sm.getFileOffset(loc);
    auto it = std::upper_bound(regions_.begin(), regions_.end(), off,
                               [](unsigned o, const BodyRegion& r) { return o < r.textBegin; });
    if (it == regions_.begin()) return -1;
    --it;
    return off <= it->end ? static_cast<int>(it - regions_.begin()) : -1;
  }

  // The .sph location of `loc`, which lies in body `i`.
  llvm::SMLoc toSph(const clang::SourceManager& sm, clang::SourceLocation loc, int i) const {
    if (!bodies_[i].start.isValid()) return llvm::SMLoc();
    unsigned off = sm.getFileOffset(sm.getExpansionLoc(loc));
    return llvm::SMLoc::getFromPointer(bodies_[i].start.getPointer() +
                                       (off - regions_[i].textBegin));
  }

  // The .sph `}` closing body `i`.
  llvm::SMLoc closingBrace(int i) const {
    const BodySource& b = bodies_[i];
    // A function's text ends with its `}`; a body's text ends just before it.
    size_t at = b.text.size() - (b.kind == BodyKind::Function && !b.text.empty() ? 1 : 0);
    return b.start.isValid() ? llvm::SMLoc::getFromPointer(b.start.getPointer() + at)
                             : llvm::SMLoc();
  }

  // The helper function (BodyKind::Function) that `fn` is the definition of, or -1.
  int functionOf(const clang::SourceManager& sm, const clang::FunctionDecl* fn) const {
    const clang::FunctionDecl* def = fn ? fn->getDefinition() : nullptr;
    if (!def) return -1;
    int j = bodyAt(sm, def->getLocation());
    if (j < 0 || bodies_[j].kind != BodyKind::Function ||
        def->getName() != bodies_[j].functionName)
      return -1;
    return j;
  }
  // The helper function named `name`, or -1.
  int functionNamed(llvm::StringRef name) const {
    for (size_t j = 0; j < bodies_.size(); ++j)
      if (bodies_[j].kind == BodyKind::Function && bodies_[j].functionName == name)
        return static_cast<int>(j);
    return -1;
  }

  // Reports a diagnostic of body `i`, counting the errors it causes (warnings may be errors).
  void report(int i, llvm::SourceMgr::DiagKind kind, llvm::SMLoc loc, const llvm::Twine& msg) {
    unsigned before = diags_.errorCount();
    switch (kind) {
      case llvm::SourceMgr::DK_Error: diags_.error(loc, msg); break;
      case llvm::SourceMgr::DK_Warning: diags_.warning(loc, msg); break;
      case llvm::SourceMgr::DK_Remark: diags_.remark(loc, msg); break;
      case llvm::SourceMgr::DK_Note: diags_.note(loc, msg); break;
    }
    if (i >= 0) state[i].errors += diags_.errorCount() - before;
  }
  void error(int i, llvm::SMLoc loc, const llvm::Twine& msg) {
    report(i, llvm::SourceMgr::DK_Error, loc, msg);
  }

  // sphc's messages shared by the diagnostic forwarder and the AST walk.
  void reportMissingReturn(int i) {
    if (state[i].missingReturnReported || state[i].blanked) return;
    state[i].missingReturnReported = true;
    const BodySource& b = bodies_[i];
    std::string what = b.label.empty() ? std::string("a '") + kindName(b.kind) + "' body"
                                       : b.label;
    error(i, closingBrace(i),
          "missing 'return': " + what + " must return a value on every path ('return EXPR;')");
  }
  void reportOutsideLoop(int i, llvm::SMLoc loc, const std::string& name) {
    if (!state[i].reportedOutsideLoop.insert(name).second) return;
    if (name == "s_idx")
      error(i, loc, "'s_idx' (the neighbour's index) is only available in 'loop'");
    else if (name == "NBRS" || name == "N_NBRS")
      error(i, loc, "'" + name + "' (the neighbour list) is only available in 'loop_all', not "
                        "in '" + kindName(bodies_[i].kind) + "'");
    else if (llvm::StringRef(name).startswith("s_"))
      error(i, loc, "'" + name + "': s_ properties are only available in 'loop', 'loop_all' "
                        "and 'initialize_pair', not in '" + kindName(bodies_[i].kind) + "'");
    else
      error(i, loc, name + " is a pair quantity, only available in 'loop'");
  }

  std::vector<BodyFacts> facts;
  std::vector<BodyState> state;

 private:
  void synthesise();

  DiagnosticEngine& diags_;
  const std::vector<BodySource>& bodies_;
  std::string unit_;
  std::vector<BodyRegion> regions_;  // ordered by offset
};

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

    if (b.kind == BodyKind::Function) {
      // A helper function is its own C definition, copied as written.
      DiagnosticEngine::Position pos = diags_.position(b.start);
      unit_ += "#line " + std::to_string(pos.line ? pos.line : 1) + " " +
               quoted(pos.file.empty() ? "<function>" : pos.file) + "\n";
      unit_ += std::string(pos.col ? pos.col - 1 : 0, ' ');
      regions_[i].textBegin = unit_.size();
      unit_ += text;
      regions_[i].end = unit_.size() ? unit_.size() - 1 : 0;
      unit_ += "\n";
      continue;
    }

    // Only the names the body mentions become parameters (besides indices and time).
    std::vector<std::string> params;
    auto param = [&](const std::string& decl, const std::string& name) {
      if (tokens.has(name)) params.push_back(decl);
    };
    params.push_back("const int d_idx");
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
        param("const double " + s, s);
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

    DiagnosticEngine::Position pos = diags_.position(b.start);
    unit_ += "#line " + std::to_string(pos.line ? pos.line : 1) + " " +
             quoted(pos.file.empty() ? "<body>" : pos.file) + "\n";
    unit_ += std::string(pos.col ? pos.col - 1 : 0, ' ');
    regions_[i].textBegin = unit_.size();
    unit_ += text;
    regions_[i].end = unit_.size();
    unit_ += "}\n";
  }
}

// The first identifier at `p` (after opening parentheses and blanks).
llvm::StringRef identifierAt(const char* p) {
  while (*p == '(' || *p == ' ' || *p == '\t') ++p;
  const char* q = p;
  while (isIdentChar(*q)) ++q;
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

// The AST walk over one body: facts, and sphc's portability rules.
class BodyChecker : public clang::RecursiveASTVisitor<BodyChecker> {
 public:
  BodyChecker(Batch& batch, int index, const clang::SourceManager& sm)
      : batch_(batch), i_(index), sm_(sm), body_(batch.body(index)), facts_(batch.facts[index]) {}

  void check(clang::FunctionDecl* fn) {
    batch_.state[i_].checked = true;
    if (body_.kind == BodyKind::Function) checkSignature(fn);
    TraverseStmt(fn->getBody());
    if (returnsValue(body_.kind) && !returnsValue_) batch_.reportMissingReturn(i_);
  }

  // --- facts ---

  bool VisitBinaryOperator(clang::BinaryOperator* op) {
    if (op->isAssignmentOp()) markWritten(op->getLHS(), op->isCompoundAssignmentOp());
    return true;
  }

  bool VisitUnaryOperator(clang::UnaryOperator* op) {
    if (op->isIncrementDecrementOp()) markWritten(op->getSubExpr(), /*alsoRead=*/true);
    if (op->getOpcode() == clang::UO_AddrOf)
      error(op->getOperatorLoc(), "'&' (address-of) is not allowed in bodies: there are no "
                                  "pointers; use the value or index the property directly");
    return true;
  }

  bool VisitArraySubscriptExpr(clang::ArraySubscriptExpr* e) {
    if (body_.kind == BodyKind::Function) return true;  // no properties in helpers
    auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(e->getBase()->IgnoreParenImpCasts());
    if (!ref || !isPropertyParam(ref)) return true;
    indexed_.insert(ref);
    std::string name = ref->getDecl()->getName().str();
    std::string prop = name.substr(2);
    llvm::SMLoc loc = sph(e->getBeginLoc());
    auto w = written_.find(e);
    bool isWrite = w != written_.end(), isRead = !isWrite || w->second;
    if (name[0] == 's') {
      if (!seesSources(body_.kind)) batch_.reportOutsideLoop(i_, loc, name);
      else if (isRead) record(facts_.sReads, prop, loc);
      // Writes to s_ elements are rejected by Clang (const) and reported by the forwarder.
    } else {
      if (isRead) record(facts_.dReads, prop, loc);
      if (isWrite) record(facts_.dWrites, prop, loc);
    }
    return true;
  }

  bool VisitDeclRefExpr(clang::DeclRefExpr* e) {
    clang::ValueDecl* decl = e->getDecl();
    if (llvm::isa<clang::FunctionDecl>(decl)) {
      if (!callees_.count(e) && recovering_ == 0)
        error(e->getLocation(), "a function can only be called in a body, not used as a value");
      return true;
    }
    if (!llvm::isa<clang::ParmVarDecl>(decl)) return true;
    if (body_.kind == BodyKind::Function) return true;  // its parameters are the user's
    std::string name = decl->getName().str();
    if (isPropertyParam(e)) {
      if (!indexed_.count(e) && recovering_ == 0)
        error(e->getLocation(), "property '" + name + "' must be indexed, e.g. " + name + "[" +
                                    name.substr(0, 2) + "idx]; there are no pointers in bodies");
    } else if (name == "NBRS" || name == "N_NBRS") {
      if (body_.kind != BodyKind::LoopAll)
        batch_.reportOutsideLoop(i_, sph(e->getLocation()), name);
    } else if (isPairQuantity(name) || name == "s_idx") {
      if (body_.kind != BodyKind::Loop)
        batch_.reportOutsideLoop(i_, sph(e->getLocation()), name);
      else if (name != "s_idx")
        facts_.pairQuantities.insert(name);
    } else if (name == "t") {
      facts_.usesT = true;
    } else if (name == "dt") {
      facts_.usesDt = true;
    } else if (std::find(body_.scalars.begin(), body_.scalars.end(), name) !=
               body_.scalars.end()) {
      facts_.scalarsUsed.insert(name);
    }
    return true;
  }

  bool VisitReturnStmt(clang::ReturnStmt* s) {
    if (s->getRetValue()) returnsValue_ = true;
    return true;
  }

  // Inside an expression Clang could not build (already an error), a call or a subscript need
  // not look like one: the "must be indexed" and "only called" rules are not checked there.
  bool TraverseRecoveryExpr(clang::RecoveryExpr* e) {
    ++recovering_;
    bool more = RecursiveASTVisitor::TraverseRecoveryExpr(e);
    --recovering_;
    return more;
  }

  // --- portability rules ---

  bool VisitCallExpr(clang::CallExpr* call) {
    clang::Expr* callee = call->getCallee()->IgnoreParenImpCasts();
    if (auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(callee)) callees_.insert(ref);
    clang::FunctionDecl* fn = call->getDirectCallee();
    if (fn && isAllowedMath(fn)) return true;
    if (int j = batch_.functionOf(sm_, fn); j >= 0) {
      if (j == i_)
        error(callee->getBeginLoc(), "function '" + fn->getName() + "' calls itself: recursion "
                                     "is not allowed (OpenCL C has none); use a loop");
      else
        checkArraySizes(call, fn);
      return true;
    }
    if (fn) {
      int j = batch_.functionNamed(fn->getName());
      if (j >= 0 && j != i_) {
        error(callee->getBeginLoc(), "function '" + fn->getName() + "' is declared after this "
                                     "one: a function may call only functions declared "
                                     "before it");
        return true;
      }
    }
    std::string list;
    for (const std::string& f : allowedMathFunctions()) list += (list.empty() ? "" : ", ") + f;
    std::string what = fn ? "call of '" + fn->getName().str() + "'" : std::string("this call");
    error(callee->getBeginLoc(), what + " is not allowed: bodies may call only the math.h "
                                        "functions " + list +
                                        ", the kernel's KERNEL_W(r, h), KERNEL_DWDR(r, h) "
                                        "and the .sph file's functions");
    return true;
  }

  bool VisitVarDecl(clang::VarDecl* v) {
    if (v->isStaticLocal())
      error(v->getLocation(), "'static' local variables are not allowed in bodies: a body keeps "
                              "no state between calls; use a property");
    else if (v->hasExternalStorage())
      error(v->getLocation(), "'extern' declarations are not allowed in bodies");
    if (containsPointer(v->getType()))
      error(v->getLocation(), "pointer variables are not allowed in bodies; use a local array "
                              "or index a property (d_NAME[d_idx])");
    return true;
  }

  bool VisitCStyleCastExpr(clang::CStyleCastExpr* e) {
    if (containsPointer(e->getTypeAsWritten()))
      error(e->getBeginLoc(), "pointer casts are not allowed in bodies");
    return true;
  }

  bool VisitGotoStmt(clang::GotoStmt* s) { return gotoError(s->getBeginLoc()); }
  bool VisitIndirectGotoStmt(clang::IndirectGotoStmt* s) { return gotoError(s->getBeginLoc()); }
  bool VisitAddrLabelExpr(clang::AddrLabelExpr* e) { return gotoError(e->getBeginLoc()); }

  bool VisitStringLiteral(clang::StringLiteral* e) {
    error(e->getBeginLoc(), "string literals are not allowed in bodies");
    return true;
  }

  bool VisitAsmStmt(clang::AsmStmt* s) {
    error(s->getBeginLoc(), "inline assembly is not allowed in bodies");
    return true;
  }

 private:
  // A helper's parameters: values or arrays (`double a[9]`), never pointers or `...`.
  void checkSignature(clang::FunctionDecl* fn) {
    for (clang::ParmVarDecl* p : fn->parameters()) {
      if (containsPointer(p->getOriginalType()))
        error(p->getLocation(), "pointer parameters are not allowed in functions; declare an "
                                "array parameter, e.g. 'double a[3]'");
      else if (p->getOriginalType()->isIncompleteArrayType())
        error(p->getLocation(), "an array parameter needs its size, e.g. 'double a[3]'");
    }
    if (fn->isVariadic())
      error(fn->getLocation(), "variadic functions ('...') are not allowed");
  }

  // An array argument must be at least as long as the array parameter it is passed to (C
  // does not check; out of bounds is undefined on every backend).
  void checkArraySizes(clang::CallExpr* call, clang::FunctionDecl* fn) {
    for (unsigned k = 0; k < call->getNumArgs() && k < fn->getNumParams(); ++k) {
      const auto* want = llvm::dyn_cast_or_null<clang::ConstantArrayType>(
          fn->getParamDecl(k)->getOriginalType()->getAsArrayTypeUnsafe());
      if (!want) continue;
      const clang::Expr* arg = call->getArg(k)->IgnoreParenImpCasts();
      const auto* ref = llvm::dyn_cast<clang::DeclRefExpr>(arg);
      if (!ref) continue;
      clang::QualType type = ref->getDecl()->getType();
      if (auto* p = llvm::dyn_cast<clang::ParmVarDecl>(ref->getDecl())) type = p->getOriginalType();
      const auto* have = llvm::dyn_cast_or_null<clang::ConstantArrayType>(
          type->getAsArrayTypeUnsafe());
      if (have && have->getSize().ult(want->getSize()))
        error(arg->getBeginLoc(), "array '" + ref->getDecl()->getName() + "' has " +
                                      llvm::Twine(have->getSize().getZExtValue()) +
                                      " elements; parameter '" +
                                      fn->getParamDecl(k)->getName() + "' of '" +
                                      fn->getName() + "' needs " +
                                      llvm::Twine(want->getSize().getZExtValue()));
    }
  }

  llvm::SMLoc sph(clang::SourceLocation loc) const { return batch_.toSph(sm_, loc, i_); }
  void error(clang::SourceLocation loc, const llvm::Twine& msg) { batch_.error(i_, sph(loc), msg); }

  bool gotoError(clang::SourceLocation loc) {
    error(loc, "'goto' is not allowed in bodies; use if, for, while, break and continue");
    return true;
  }

  static bool isPropertyParam(const clang::DeclRefExpr* ref) {
    return llvm::isa<clang::ParmVarDecl>(ref->getDecl()) &&
           isPropertyName(ref->getDecl()->getName());
  }

  // A math function declared by the prelude (not only implicitly or by a body itself). The
  // prelude's declaration of a library builtin such as sqrt redeclares Clang's implicit one.
  bool isAllowedMath(const clang::FunctionDecl* fn) const {
    const auto& allowed = allowedMathFunctions();
    const auto& kernel = kernelFunctions();
    const std::string name = fn->getName().str();
    if (std::find(allowed.begin(), allowed.end(), name) == allowed.end() &&
        std::find(kernel.begin(), kernel.end(), name) == kernel.end())
      return false;
    for (const clang::FunctionDecl* d : fn->redecls())
      if (!d->isImplicit() && batch_.bodyAt(sm_, d->getLocation()) < 0) return true;
    return false;
  }

  static bool containsPointer(clang::QualType type) {
    for (const clang::Type* t = type.getTypePtrOrNull(); t;) {
      if (t->isPointerType()) return true;
      const clang::ArrayType* a = t->getAsArrayTypeUnsafe();
      if (!a) return false;
      t = a->getElementType().getTypePtrOrNull();
    }
    return false;
  }

  // `lhs` is assigned to (and also read, for compound assignment and ++/--).
  void markWritten(clang::Expr* lhs, bool alsoRead) {
    if (auto* e = llvm::dyn_cast<clang::ArraySubscriptExpr>(lhs->IgnoreParens()))
      written_[e] = alsoRead;
  }

  static void record(std::vector<PropAccess>& list, const std::string& prop, llvm::SMLoc loc) {
    for (const PropAccess& a : list)
      if (a.prop == prop) return;
    list.push_back({prop, loc});
  }

  Batch& batch_;
  int i_;
  const clang::SourceManager& sm_;
  const BodySource& body_;
  BodyFacts& facts_;
  bool returnsValue_ = false;
  int recovering_ = 0;  // depth of RecoveryExprs being traversed
  std::map<const clang::ArraySubscriptExpr*, bool> written_;  // -> also read
  std::set<const clang::DeclRefExpr*> indexed_;  // d_/s_ references that are subscripted
  std::set<const clang::DeclRefExpr*> callees_;  // function references that are called
};

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
        BodyChecker(batch_, j, fn->getASTContext().getSourceManager()).check(fn);
        continue;
      }
      if (!fn->getName().startswith(kFunctionPrefix)) continue;
      unsigned index = 0;
      if (fn->getName().drop_front(kFunctionPrefix.size()).getAsInteger(10, index))
        SPHC_INTERNAL("unexpected body function " + fn->getName());
      BodyChecker(batch_, index, fn->getASTContext().getSourceManager()).check(fn);
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
