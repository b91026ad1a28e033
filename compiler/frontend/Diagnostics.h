// User diagnostics of sphc: `file:line:col: error: message`, the source line and a caret,
// through LLVM's SourceMgr. Every error a user can cause goes through DiagnosticEngine;
// internal errors (bugs in sphc) use SPHC_INTERNAL and are never blamed on the user.
#pragma once

#include "llvm/ADT/Twine.h"
#include "llvm/Support/SMLoc.h"
#include "llvm/Support/SourceMgr.h"
#include "llvm/Support/raw_ostream.h"

#include <string>

namespace sphc {

class DiagnosticEngine {
 public:
  explicit DiagnosticEngine(llvm::SourceMgr& sm, llvm::raw_ostream& os = llvm::errs())
      : sm_(sm), os_(os) {}

  void error(llvm::SMLoc loc, const llvm::Twine& msg);
  void warning(llvm::SMLoc loc, const llvm::Twine& msg);
  void note(llvm::SMLoc loc, const llvm::Twine& msg);
  void remark(llvm::SMLoc loc, const llvm::Twine& msg);
  // An error with no source position (e.g. a missing input file).
  void error(const llvm::Twine& msg);

  unsigned errorCount() const { return errors_; }
  unsigned warningCount() const { return warnings_; }
  bool hasErrors() const { return errors_ > 0; }
  void setWarningsAsErrors(bool on) { werror_ = on; }

  llvm::SourceMgr& sourceMgr() { return sm_; }

  // The location of (line, col), both 1-based, in the buffer whose identifier (file name) is
  // `file`; an invalid SMLoc if there is no such buffer or position. Used to map Clang's
  // presumed locations (`#line N "file"`) back into the .sph file.
  llvm::SMLoc locFor(llvm::StringRef file, unsigned line, unsigned col) const;
  // "file:line" of a location, for provenance comments in generated code.
  std::string lineInfo(llvm::SMLoc loc) const;
  // The buffer identifier (file name) and 1-based line and column of a location.
  struct Position { std::string file; unsigned line = 0, col = 0; };
  Position position(llvm::SMLoc loc) const;

 private:
  void emit(llvm::SMLoc loc, llvm::SourceMgr::DiagKind kind, const llvm::Twine& msg);
  llvm::SourceMgr& sm_;
  llvm::raw_ostream& os_;
  unsigned errors_ = 0, warnings_ = 0;
  bool werror_ = false;
};

// An internal compiler error: a bug in sphc, not in the user's scene.
[[noreturn]] void internalError(const char* file, int line, const llvm::Twine& msg);
#define SPHC_INTERNAL(msg) ::sphc::internalError(__FILE__, __LINE__, (msg))

}  // namespace sphc
