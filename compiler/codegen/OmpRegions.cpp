// Per-particle loops of a destination in one OpenMP parallel region (stop 46).
//
// Each `#pragma omp parallel for` starts the team and ends with its join: two waits for a
// thread that may be asleep (OMP_WAIT_POLICY=passive, what the solvers' --omp-wait auto
// picks on a loaded machine: ~127 us a region on a 2-vCPU VM, stop 45). The loops without
// neighbours that the CPU printer prints one after the other before a pair loop (the
// destination's initialize, the source-only values of its first pass, the destination-only
// values of its tiles) are kept here and printed as one region:
//
//   #pragma omp parallel if (n >= OMP_MIN_PARTICLES || n_src >= OMP_MIN_PARTICLES)
//   {
//     #pragma omp for schedule(static) nowait
//     for (int d_idx = 0; d_idx < n; ++d_idx) { ... }   // initialize
//     #pragma omp for schedule(static) nowait
//     for (int s_idx = 0; s_idx < n_src; ++s_idx) { ... }   // hoisted
//     ...
//   }
//
// Why no barrier is needed between them (OpenMP 5.2, 11.5.3 "static": two loops of one
// region with the same number of iterations and schedule(static) give each thread the same
// iterations): a loop over the same particles of the same array reads what an earlier one
// wrote only for its own particle (the hoisted values read s_NAME[s_idx] and d_NAME[d_idx],
// by construction; the printer keeps an initialize_pair, which may index as it likes, out),
// which the same thread wrote; a loop over another array's particles reads nothing an
// earlier loop wrote (an initialize writes its destination only; the hoisted values go to
// arrays of their own). A loop over the same array with another count (a range, ghosts)
// gets a barrier. The statements the loops move past (pointers, h where uniform, the
// scratch arrays' resize, the kept lists' rebuild check) read nothing the loops write: the
// printer keeps a destination whose initialize writes x, y, z or h out. Each particle's
// values are computed by the same operations as before on any thread: the results are the
// same bit for bit, serial = OpenMP.
#include "codegen/Printer.h"

#include <algorithm>
#include <sstream>

namespace sphc {

void ScenePrinter::ompQueueOpen(bool openmp, const std::string& indent) const {
  ompQueue_.clear();
  ompQueueing_ = openmp && ompRegions_on_;
  ompQueueIndent_ = indent;
}

void ScenePrinter::ompLoop(std::ostream& os, const std::string& pragma, const std::string& loop,
                           const std::string& space) const {
  if (!ompQueueing_ || pragma.empty()) {
    os << pragma << loop;
    return;
  }
  if (ompQueue_.empty()) {
    ompQueueOs_ = static_cast<const void*>(&os) == static_cast<const void*>(&scene_)
                      ? const_cast<std::ostringstream*>(&scene_)
                      : nullptr;
    ompQueueAt_ = os.tellp();
  }
  ompQueue_.push_back({pragma, loop, space});
}

namespace {
// `#pragma omp parallel for schedule(static) CLAUSES if (COND)\n` -> CLAUSES, COND.
void splitPragma(const std::string& pragma, std::string& clauses, std::string& cond) {
  const std::string head = "#pragma omp parallel for schedule(static)";
  const size_t at = pragma.find(head);
  std::string rest = at == std::string::npos ? "" : pragma.substr(at + head.size());
  while (!rest.empty() && (rest.back() == '\n' || rest.back() == ' ')) rest.pop_back();
  cond.clear();
  const size_t i = rest.find("if (");
  if (i != std::string::npos) {
    int depth = 0;
    size_t j = i + 3;
    for (; j < rest.size(); ++j) {
      if (rest[j] == '(') ++depth;
      if (rest[j] == ')' && --depth == 0) break;
    }
    cond = rest.substr(i + 4, j - (i + 4));
    rest = rest.substr(0, i) + (j + 1 < rest.size() ? rest.substr(j + 1) : "");
  }
  while (!rest.empty() && rest.back() == ' ') rest.pop_back();
  while (!rest.empty() && rest.front() == ' ') rest.erase(0, 1);
  clauses = rest;
}
// The loop's text moved to `indent` (its first line's indentation replaced by it, the
// others shifted alike).
std::string indented(const std::string& text, const std::string& indent) {
  const size_t first = text.find_first_not_of(' ');
  const long shift = static_cast<long>(indent.size()) -
                     static_cast<long>(first == std::string::npos ? 0 : first);
  std::string r;
  size_t i = 0;
  while (i < text.size()) {
    size_t e = text.find('\n', i);
    if (e == std::string::npos) e = text.size();
    std::string line = text.substr(i, e - i);
    if (!line.empty()) {
      if (shift >= 0) line.insert(0, static_cast<size_t>(shift), ' ');
      else line.erase(0, std::min(line.find_first_not_of(' '), static_cast<size_t>(-shift)));
    }
    r += line;
    if (e < text.size()) r += '\n';
    i = e + 1;
  }
  return r;
}
}  // namespace

void ScenePrinter::ompQueueFlush(std::ostream& os) const {
  ompQueueing_ = false;
  std::vector<OmpQueuedLoop> loops;
  loops.swap(ompQueue_);
  if (loops.empty()) return;
  if (loops.size() == 1) {  // where it was given, as without the queue
    std::ostringstream* at = ompQueueOs_;
    if (at && ompQueueAt_ >= 0) {
      std::string text = at->str();
      text.insert(static_cast<size_t>(ompQueueAt_), loops[0].pragma + loops[0].loop);
      at->str(text);
      at->seekp(0, std::ios_base::end);
    } else {
      os << loops[0].pragma << loops[0].loop;
    }
    return;
  }
  const std::string& in = ompQueueIndent_;
  std::vector<std::string> conds;
  bool always = false;  // a loop without `if`: the region is parallel whatever the counts
  for (const OmpQueuedLoop& l : loops) {
    std::string clauses, cond;
    splitPragma(l.pragma, clauses, cond);
    if (cond.empty()) always = true;
    else if (std::find(conds.begin(), conds.end(), cond) == conds.end()) conds.push_back(cond);
  }
  os << in << "// " << loops.size()
     << " loops without neighbours in one parallel region (codegen/OmpRegions.cpp; sphc\n"
     << in << "// --no-omp-regions: a region each): the same iterations on the same threads\n";
  os << in << "#pragma omp parallel";
  if (!always && !conds.empty()) {
    os << " if (";
    for (size_t i = 0; i < conds.size(); ++i) os << (i ? " || " : "") << conds[i];
    os << ")";
  }
  os << "\n" << in << "{\n";
  for (size_t k = 0; k < loops.size(); ++k) {
    const OmpQueuedLoop& l = loops[k];
    // A barrier where an earlier loop ran over the same array with another count.
    const std::string array = l.space.substr(0, l.space.find('|'));
    bool barrier = false;
    for (size_t e = 0; e < k; ++e)
      if (loops[e].space.substr(0, loops[e].space.find('|')) == array && loops[e].space != l.space)
        barrier = true;
    if (barrier)
      os << in << "  #pragma omp barrier  // another count over " << array << "\n";
    std::string clauses, cond;
    splitPragma(l.pragma, clauses, cond);
    os << in << "  #pragma omp for schedule(static)" << (clauses.empty() ? "" : " " + clauses)
       << " nowait\n";
    os << indented(l.loop, in + "  ");
  }
  os << in << "}\n";
}

}  // namespace sphc
