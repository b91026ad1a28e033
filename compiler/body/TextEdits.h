// Edits of a body's text that keep what the body analysis recorded about it in step. The facts
// (body/BodyAnalysis.h) hold offsets into BodySource::text: where each property is indexed,
// where a product is added to a value. A pass that rewrites the text (the dimension pass:
// analysis/Dimensions.cpp) applies its replacements here, and every recorded range moves with
// the code it named, so that a later pass or the printer (codegen/FusedMultiplyAdd.cpp) still
// finds that code at its offsets.
#pragma once

#include "body/BodyAnalysis.h"

#include <string>
#include <vector>

namespace sphc {

struct TextEdit {
  unsigned begin = 0, end = 0;  // text[begin, end) is replaced; begin == end: an insertion
  std::string replacement;
};

// Applies `edits` (in any order, none overlapping another) to `text` and moves the offsets of
// `facts` with them. A recorded range that an edit replaces exactly becomes the replacement's;
// an insertion goes before a range that begins where it is and after one that ends there. A
// site that an edit cuts into (a position strictly inside a replaced range) is dropped: a
// multiply-add site so dropped is printed as written. False, with nothing changed, if two
// edits overlap or one reaches past the text.
bool applyTextEdits(std::string& text, std::vector<TextEdit> edits, BodyFacts& facts);

}  // namespace sphc
