#include "body/TextEdits.h"

#include <algorithm>

namespace sphc {

namespace {

// Where the offsets of the old text are in the new one.
class OffsetMap {
 public:
  explicit OffsetMap(const std::vector<TextEdit>& edits) : edits_(edits) {}

  // Moves `pos`, the first offset of a range (or a point such as an operator), or the offset
  // one past its end; false if it lies strictly inside a replaced range.
  bool move(unsigned& pos, bool isEnd) const {
    long shift = 0;
    for (const TextEdit& e : edits_) {
      long delta = static_cast<long>(e.replacement.size()) - static_cast<long>(e.end - e.begin);
      if (e.begin == e.end) {
        if (pos > e.begin || (pos == e.begin && !isEnd)) shift += delta;
        else break;
      } else if (pos <= e.begin) {
        break;
      } else if (pos >= e.end) {
        shift += delta;
      } else {
        return false;
      }
    }
    pos = static_cast<unsigned>(static_cast<long>(pos) + shift);
    return true;
  }

  bool moveRange(unsigned& begin, unsigned& end) const {
    return move(begin, false) && move(end, true);
  }

 private:
  const std::vector<TextEdit>& edits_;
};

}  // namespace

bool applyTextEdits(std::string& text, std::vector<TextEdit> edits, BodyFacts& facts) {
  std::sort(edits.begin(), edits.end(), [](const TextEdit& x, const TextEdit& y) {
    return x.begin != y.begin ? x.begin < y.begin : x.end < y.end;
  });
  for (size_t i = 0; i < edits.size(); ++i) {
    if (edits[i].end < edits[i].begin || edits[i].end > text.size()) return false;
    if (i > 0 && edits[i].begin < edits[i - 1].end) return false;
  }
  std::string out;
  unsigned pos = 0;
  for (const TextEdit& e : edits) {
    out.append(text, pos, e.begin - pos);
    out += e.replacement;
    pos = e.end;
  }
  out.append(text, pos, std::string::npos);

  OffsetMap map(edits);
  // A property site is a subscript: an edit replaces it whole or lies inside or outside it
  // (one cut into would no longer be that subscript: dropped).
  facts.sites.erase(std::remove_if(facts.sites.begin(), facts.sites.end(),
                                   [&](PropSite& s) { return !map.moveRange(s.begin, s.end); }),
                    facts.sites.end());
  std::vector<MultiplyAddSite> kept;
  for (MultiplyAddSite s : facts.multiplyAdds) {
    if (map.moveRange(s.begin, s.end) && map.moveRange(s.productBegin, s.productEnd) &&
        map.moveRange(s.aBegin, s.aEnd) && map.moveRange(s.bBegin, s.bEnd) &&
        map.moveRange(s.cBegin, s.cEnd) && map.move(s.mulOp, false) && map.move(s.addOp, false))
      kept.push_back(s);
  }
  facts.multiplyAdds = kept;
  // A source-only expression (and the initial values of its locals) moves with its text; one
  // an edit cuts into is dropped (computed in the pair loop as written).
  for (auto* list : {&facts.sourceOnly, &facts.destinationOnly, &facts.pairShared}) {
    std::vector<SourceOnlySite> kept;
    for (SourceOnlySite s : *list) {
      bool ok = map.moveRange(s.begin, s.end);
      if (s.stmtBegin < s.stmtEnd) ok = ok && map.moveRange(s.stmtBegin, s.stmtEnd);
      if (s.guardBegin < s.guardEnd) ok = ok && map.moveRange(s.guardBegin, s.guardEnd);
      for (auto& l : s.locals) ok = ok && map.moveRange(l.initBegin, l.initEnd);
      if (ok) kept.push_back(s);
    }
    *list = kept;
  }
  text = out;
  return true;
}

}  // namespace sphc
