// The CPU printer, --verlet-skin without a periodic or mirror domain: the search domain and
// the cell lists of the moving sources are built only at the neighbour updates where some
// pair loop rebuilds its kept lists (docs/performance-log.md, "Cell lists only when a kept list is
// rebuilt").
//
// With kept lists the cells are read only where lists are built (the gather of a rebuild):
// every pair loop, loop_all included, sums over its kept list. So update_neighbours keeps
// the permutation into cell order (every REORDER_EVERY-th update, or the sort checks of
// --verlet-skin=auto, counted as before) and marks the domain and cells out of date; the
// first pair loop of a source that rebuilds its lists calls build_cells_S, which makes the
// domain (once per update, shared by the sources) and the source's cells on the present
// positions. A static source keeps its cells of build_static_cells. The kept lists hold the
// candidates within the lists' radius in increasing index, whichever cells they came from,
// so the lists, and the sums, are those of cells built at the update.
#include "codegen/CpuLazyCells.h"

namespace sphc::lazy_cells {

std::string loopArraysDecl(const std::vector<std::string>& loopArrays) {
  std::string r = "    const std::vector<const sphc::ParticleArray*> all = {";
  bool first = true;
  for (const auto& a : loopArrays) {
    r += (first ? "&" : ", &") + a;
    first = false;
  }
  return r + "};\n";
}

void members(std::ostream& out, const std::vector<std::string>& movingSources) {
  out << "  // --verlet-skin: the search domain and the moving sources' cell lists are made at the\n"
         "  // first pair loop of an update that rebuilds kept lists (make_domain, build_cells_S).\n";
  out << "  bool domain_due = true;\n";
  for (const auto& S : movingSources) out << "  bool cells_due_" << S << " = true;\n";
}

// The positions of this update are the cells' from now on.
void markDue(std::ostream& scene, const std::vector<std::string>& movingSources) {
  scene << "    // The search domain and the cell lists: at the first pair loop that rebuilds kept\n"
           "    // lists from them (build_cells_S), none where no list is rebuilt.\n";
  scene << "    domain_due = true;\n";
  for (const auto& S : movingSources) scene << "    cells_due_" << S << " = true;\n";
}

void functions(std::ostream& scene, const std::vector<std::string>& movingSources,
               const std::function<void()>& searchDomain,
               const std::function<std::string(const std::string&)>& cellListBuild) {
  scene << "  // The search domain of this neighbour update, on the present positions.\n";
  scene << "  void make_domain() {\n";
  searchDomain();
  scene << "    domain_due = false;\n  }\n\n";
  for (const auto& S : movingSources) {  // a static source: build_static_cells
    scene << "  // The cell list of " << S << " for this neighbour update, built at its first call.\n";
    scene << "  void build_cells_" << S << "() {\n";
    scene << "    if (!cells_due_" << S << ") return;\n";
    scene << "    if (domain_due) make_domain();\n";
    scene << "    " << cellListBuild(S) << "\n";
    scene << "    cells_due_" << S << " = false;\n  }\n\n";
  }
}

}  // namespace sphc::lazy_cells
