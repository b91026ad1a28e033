#include "frontend/Diagnostics.h"

#include "llvm/Support/MemoryBuffer.h"

#include <cstdlib>

namespace sphc {

void DiagnosticEngine::emit(llvm::SMLoc loc, llvm::SourceMgr::DiagKind kind,
                            const llvm::Twine& msg) {
  if (loc.isValid())
    sm_.PrintMessage(os_, loc, kind, msg);
  else
    sm_.PrintMessage(os_, llvm::SMDiagnostic("sphc", kind, msg.str()));
}

void DiagnosticEngine::error(llvm::SMLoc loc, const llvm::Twine& msg) {
  ++errors_;
  emit(loc, llvm::SourceMgr::DK_Error, msg);
}

void DiagnosticEngine::error(const llvm::Twine& msg) { error(llvm::SMLoc(), msg); }

void DiagnosticEngine::warning(llvm::SMLoc loc, const llvm::Twine& msg) {
  if (werror_) return error(loc, msg);
  ++warnings_;
  emit(loc, llvm::SourceMgr::DK_Warning, msg);
}

void DiagnosticEngine::note(llvm::SMLoc loc, const llvm::Twine& msg) {
  emit(loc, llvm::SourceMgr::DK_Note, msg);
}

void DiagnosticEngine::remark(llvm::SMLoc loc, const llvm::Twine& msg) {
  emit(loc, llvm::SourceMgr::DK_Remark, msg);
}

llvm::SMLoc DiagnosticEngine::locFor(llvm::StringRef file, unsigned line, unsigned col) const {
  for (unsigned id = 1; id <= sm_.getNumBuffers(); ++id) {
    const llvm::MemoryBuffer* buf = sm_.getMemoryBuffer(id);
    if (buf->getBufferIdentifier() != file) continue;
    const char* start = buf->getBufferStart();
    const char* end = buf->getBufferEnd();
    const char* p = start;
    for (unsigned l = 1; l < line && p < end; ++p)
      if (*p == '\n') ++l;
    if (p > end) return llvm::SMLoc();
    const char* q = p;
    for (unsigned c = 1; c < col && q < end && *q != '\n'; ++c) ++q;
    return llvm::SMLoc::getFromPointer(q);
  }
  return llvm::SMLoc();
}

DiagnosticEngine::Position DiagnosticEngine::position(llvm::SMLoc loc) const {
  Position pos;
  if (!loc.isValid()) return pos;
  unsigned id = sm_.FindBufferContainingLoc(loc);
  if (id == 0) return pos;
  auto lc = sm_.getLineAndColumn(loc, id);
  pos.file = sm_.getMemoryBuffer(id)->getBufferIdentifier().str();
  pos.line = lc.first;
  pos.col = lc.second;
  return pos;
}

std::string DiagnosticEngine::lineInfo(llvm::SMLoc loc) const {
  Position p = position(loc);
  if (p.file.empty()) return "<unknown>";
  // Provenance shows the file name relative to nothing: just its last path component.
  llvm::StringRef f(p.file);
  size_t slash = f.rfind('/');
  if (slash != llvm::StringRef::npos) f = f.substr(slash + 1);
  return (f + ":" + llvm::Twine(p.line)).str();
}

void internalError(const char* file, int line, const llvm::Twine& msg) {
  llvm::errs() << "sphc: internal compiler error: " << msg << "\n  at " << file << ":" << line
               << "\nThis is a bug in sphc, not in your scene; please report it with the "
                  "scene that triggered it.\n";
  std::abort();
}

}  // namespace sphc
