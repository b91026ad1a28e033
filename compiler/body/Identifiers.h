// The characters of C identifiers, for the quick lexical scans of body text that the passes
// and printers make (the body analysis's token scan, the single-precision rewrite, the
// multiply-add printer, the pair-quantity spellings, whole-word counts): one definition, so
// that every scan agrees on where a name begins and ends.
#pragma once

#include <cctype>
#include <string>

namespace sphc {

// A letter, digit or underscore: a character of a C identifier.
inline bool isIdentifierChar(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}

// A character that may begin a C identifier: a letter or an underscore.
inline bool isIdentifierStart(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) || c == '_';
}

}  // namespace sphc
