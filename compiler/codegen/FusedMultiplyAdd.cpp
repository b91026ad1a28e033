#include "codegen/FusedMultiplyAdd.h"

#include "body/Identifiers.h"

#include <algorithm>
#include <cctype>

namespace sphc {

namespace {

using Site = MultiplyAddSite;

// Whether a site's offsets describe it within `text`: the factors in order around the `*`
// inside the product, the addend on its side of the `+`/`-`, all inside the whole.
bool wellFormed(const Site& s, const std::string& text) {
  auto within = [&](unsigned b, unsigned e) { return s.begin <= b && b < e && e <= s.end; };
  if (s.end > text.size() || !within(s.productBegin, s.productEnd) || !within(s.aBegin, s.aEnd) ||
      !within(s.bBegin, s.bEnd) || !within(s.cBegin, s.cEnd))
    return false;
  if (!(s.productBegin <= s.aBegin && s.aEnd <= s.mulOp && s.mulOp < s.bBegin &&
        s.bEnd <= s.productEnd && text[s.mulOp] == '*'))
    return false;
  bool productFirst = s.form == Site::ProductPlus || s.form == Site::ProductMinus;
  if (productFirst ? !(s.productEnd <= s.addOp && s.addOp < s.cBegin)
                   : !(s.cEnd <= s.addOp && s.addOp < s.productBegin))
    return false;
  char op = s.form == Site::ProductPlus || s.form == Site::PlusProduct || s.form == Site::AddAssign
                ? '+'
                : '-';
  bool assign = s.form == Site::AddAssign || s.form == Site::SubAssign;
  if (text[s.addOp] != op || (assign && (s.addOp + 1 >= text.size() || text[s.addOp + 1] != '=')))
    return false;
  // x = fma(a, b, x) writes x twice: on one line, or the lines after it would move.
  return !assign || text.substr(s.cBegin, s.cEnd - s.cBegin).find('\n') == std::string::npos;
}

class Fuser {
 public:
  Fuser(const std::string& text, const std::vector<Site>& sites, const std::string& fma)
      : text_(text), fma_(fma) {
    for (const Site& s : sites)
      if (wellFormed(s, text)) sites_.push_back(&s);
    // Outer sites first where they begin at the same place.
    std::sort(sites_.begin(), sites_.end(), [](const Site* x, const Site* y) {
      return x->begin != y->begin ? x->begin < y->begin : x->end > y->end;
    });
    // Sites must nest or be apart (they are nodes of one expression tree): any other overlap
    // means the offsets are not what the analysis recorded; print both as written.
    std::vector<const Site*> kept;
    for (size_t i = 0; i < sites_.size(); ++i) {
      bool clash = false;
      for (size_t j = 0; j < sites_.size() && !clash; ++j) {
        const Site& x = *sites_[i];
        const Site& y = *sites_[j];
        clash = i != j && x.begin < y.end && y.begin < x.end &&
                !(x.begin <= y.begin && y.end <= x.end) && !(y.begin <= x.begin && x.end <= y.end);
        clash |= i != j && x.begin == y.begin && x.end == y.end;
      }
      if (!clash) kept.push_back(sites_[i]);
    }
    sites_ = kept;
  }

  std::string print() const { return print(0, static_cast<unsigned>(text_.size())); }

 private:
  // text[from, to) with the sites inside it fused. Parentheses around a site alone, `(a * b
  // + c) / d`, go: a call needs none (not those of a call or an `if`: after a name).
  std::string print(unsigned from, unsigned to) const {
    std::string out;
    unsigned pos = from;
    for (const Site* s : sites_) {
      if (s->begin < pos || s->end > to) continue;
      unsigned open = s->begin, close = s->end;
      while (open > pos && isBlank(text_[open - 1])) --open;
      while (close < to && isBlank(text_[close])) ++close;
      bool parens = open > pos && text_[open - 1] == '(' && close < to && text_[close] == ')';
      if (parens) {
        unsigned before = open - 1;
        while (before > 0 && std::isspace(static_cast<unsigned char>(text_[before - 1])))
          --before;
        parens = before == 0 || !isIdentifierChar(text_[before - 1]);
      }
      out.append(text_, pos, (parens ? open - 1 : s->begin) - pos);
      out += render(*s);
      pos = parens ? close + 1 : s->end;
    }
    out.append(text_, pos, to - pos);
    return out;
  }

  static bool isBlank(char c) { return c == ' ' || c == '\t'; }

  std::string render(const Site& s) const {
    std::string a = print(s.aBegin, s.aEnd), b = print(s.bBegin, s.bEnd);
    std::string c = print(s.cBegin, s.cEnd);
    std::string ab = separator(s.aEnd, s.bBegin, s.mulOp, 1);
    std::string out;
    switch (s.form) {
      case Site::ProductPlus:
        out = fma_ + "(" + a + ab + b + separator(s.productEnd, s.cBegin, s.addOp, 1) + c + ")";
        break;
      case Site::ProductMinus:
        out = fma_ + "(" + a + ab + b + separator(s.productEnd, s.cBegin, s.addOp, 1) +
              negated(c, s) + ")";
        break;
      case Site::PlusProduct:
        out = fma_ + "(" + a + ab + b + separator(s.cEnd, s.productBegin, s.addOp, 1) + c + ")";
        break;
      case Site::MinusProduct:
        out = fma_ + "(" + negated(a, s) + ab + b + separator(s.cEnd, s.productBegin, s.addOp, 1) +
              c + ")";
        break;
      case Site::AddAssign:
      case Site::SubAssign: {
        // `x += a * b` -> `x = fma(a, b, x)`, keeping the spaces around the operator.
        std::string target = print(s.cBegin, s.cEnd) + text_.substr(s.cEnd, s.addOp - s.cEnd) + "=" +
                             text_.substr(s.addOp + 2, s.productBegin - (s.addOp + 2));
        out = target + fma_ + "(" + (s.form == Site::SubAssign ? negated(a, s) : a) + ab + b +
              ", " + c + ")";
        break;
      }
    }
    // Line breaks the rewrite left out (inside dropped parentheses): after it, so that the
    // lines below keep their numbers.
    long lost = std::count(text_.begin() + s.begin, text_.begin() + s.end, '\n') -
                std::count(out.begin(), out.end(), '\n');
    if (lost > 0) out += std::string(static_cast<size_t>(lost), '\n');
    return out;
  }

  // The comma that takes the place of the operator at text[op, op + len) between two
  // operands: ", " where only spaces were around it, else what was there (comments, line
  // breaks and their indentation) without the operator.
  std::string separator(unsigned from, unsigned to, unsigned op, unsigned len) const {
    auto plain = [](const std::string& s) {
      return s.find('\n') == std::string::npos && s.find('/') == std::string::npos;
    };
    std::string before = text_.substr(from, op - from);
    std::string after = text_.substr(op + len, to - (op + len));
    std::string sep = ",";
    if (!plain(before)) sep += before;
    if (!plain(after)) sep += after;
    if (sep.back() != ' ' && sep.back() != '\n' && sep.back() != '\t') sep += " ";
    return sep;
  }

  static std::string negated(const std::string& operand, const Site& s) {
    return s.parenthesizeNegated ? "-(" + operand + ")" : "-" + operand;
  }

  const std::string& text_;
  std::string fma_;
  std::vector<const Site*> sites_;
};

}  // namespace

std::string fuseMultiplyAdds(const std::string& text, const std::vector<MultiplyAddSite>& sites,
                             const std::string& fma) {
  if (sites.empty() || fma.empty()) return text;
  return Fuser(text, sites, fma).print();
}

}  // namespace sphc
