// The CPU printer, --verlet-skin=auto: the kept neighbour lists with the skin and the
// cell-order re-sort chosen at run time (runtime sphc/verlet_tune.h); --verlet-skin=F prints
// the fixed skin's code of CpuPrinter.cpp.
#include "codegen/CpuVerletTune.h"

namespace sphc::verlet_tune {

namespace {

std::string arrayList(const std::vector<std::string>& arrays) {
  std::string r = "{";
  for (std::size_t k = 0; k < arrays.size(); ++k) r += (k ? ", &" : "&") + arrays[k];
  return r + "}";
}

}  // namespace

void members(std::ostream& out) {
  out << "  // --verlet-skin=auto: the skin chosen at run time from how far the particles move\n"
         "  // between rebuilds; the cell-order sort when the particles left that order\n"
         "  // (sphc/verlet_tune.h).\n";
  out << "  sphc::SkinTuner verlet_tune{DIM};\n";
  out << "  double verlet_skin = sphc::SkinTuner::kStart;  // of the lists built now\n";
  out << "  double verlet_radius2 = RADIUS2 * (1.0 + verlet_skin) * (1.0 + verlet_skin);\n";
  out << "  static constexpr long SORT_CHECK_EVERY = 10;  // neighbour updates between sort "
         "checks\n";
}

// The rebuild check of a pair loop's kept lists. A static array (nothing writes its x, y, z,
// and no array of a pair loop changes h: CpuPrinter::isStatic) is left out of the check and
// of the positions kept: its particles never move, so the pairs it is in close in at most by
// the other array's displacement, and their radius at the build was at least radius_scale
// times the h of the moving particle (sphc/verlet.h's bound with h_min over the moving
// arrays). With neither array moving the lists are built once.
void rebuildCheck(std::ostream& scene, const KeptLoop& loop) {
  const std::string& lists = loop.lists;
  const std::string range = loop.begin + ", " + loop.end;
  if (loop.moving.empty()) {
    scene << "        // Neither array moves: the lists are built once.\n";
    scene << "        const bool verlet_build = !" << lists << ".built_for(" << range << ");\n";
  } else {
    if (!loop.staticArray.empty())
      scene << "        // Checked over the array that moves (" << loop.staticArray
            << " is static).\n";
    scene << "        const bool verlet_build = !" << lists << ".built_for(" << range << ") || "
          << lists << ".skin.must_rebuild(" << arrayList(loop.moving)
          << ", Kernel::radius_scale);\n";
  }
  scene << "        if (verlet_build) {\n";
  if (!loop.moving.empty()) {
    if (!loop.ranged)
      scene << "          verlet_tune.rebuilt(" << lists
            << ".skin, Kernel::radius_scale);  // the movement since the last build\n";
    scene << "          " << lists << ".skin.set_skin(verlet_skin);\n";
    scene << "          " << lists << ".skin.mark(" << arrayList(loop.moving) << ");\n";
  }
  scene << "          " << lists << ".begin = " << loop.begin << ";\n";
  scene << "          " << lists << ".end = " << loop.end << ";\n";
  scene << "          " << lists << ".lists.resize(" << loop.dest << ".n);\n";
  if (loop.clearUpper) scene << "          " << lists << ".upper.clear();  // found again by the loops over each pair once\n";
  if (loop.clearCross) scene << "          " << lists << "_by_source.clear();  // found again by the pass over pairs of two arrays once\n";
  if (loop.clearOccupied) scene << "          " << lists << ".occupied_found = false;  // found again by the loops over two arrays\n";
  scene << "        }\n";
}

void updateNeighbours(std::ostream& scene, const Update& u,
                      const std::function<void()>& searchDomain,
                      const std::function<void()>& lazyCellsDue) {
  scene << "    // --verlet-skin=auto: the skin of the lists built from now on (sphc/verlet_tune.h).\n";
  scene << "    verlet_skin = verlet_tune.skin();\n";
  scene << "    verlet_radius2 = RADIUS2 * (1.0 + verlet_skin) * (1.0 + verlet_skin);\n";
  bool reordersMoving = false;
  for (const Source& S : u.sources) reordersMoving |= !S.isStatic && S.reorders;
  if (u.loopArrays) {
    if (!u.lazyCells)
      searchDomain();
    else if (reordersMoving || u.anyStatic)
      scene << u.loopArraysDecl;  // for order_domain; the domain: make_domain (CpuLazyCells.cpp)
  }
  // Sorts go into the cell order of the support's grid (order_domain), as without lists.
  const std::string& orderDomain = u.orderDomain;
  if (u.anyStatic)
    scene << "    if (!static_cells_built) {  // once: they never move\n      " << orderDomain
          << "\n      build_static_cells();\n    }\n";
  if (reordersMoving) {
    // The particles are sorted in cell order (neighbours close in memory) at the first
    // update, then where a check every SORT_CHECK_EVERY updates finds them out of that order
    // (verlet_tune.sort_due). A sort permutes the particles under the kept lists, which are
    // then rebuilt (forget: a permutation is no movement to measure).
    scene << "    const bool sort_check = builds++ % SORT_CHECK_EVERY == 0;\n";
    scene << "    if (sort_check) " << orderDomain << "\n";
  } else if (u.anyReorders) {
    scene << "    ++builds;  // counted as with moving arrays (restart state)\n";
  }
  for (const Source& S : u.sources) {
    if (S.isStatic) continue;  // build_static_cells
    if (S.reorders) {
      scene << "    if (sort_check) {\n      " << S.orderCells << "\n";
      scene << "      if (builds == 1 ? (verlet_tune.sorted(), true) : verlet_tune.sort_due(cells_"
            << S.name << ".cell_order())) {\n";
      scene << "        " << S.permute << "\n";
      for (const auto& lists : S.lists) scene << "        " << lists << ".skin.forget();\n";
      scene << "      }\n    }\n";
    }
    if (!u.lazyCells) scene << "    " << S.cells << "\n";
  }
  if (u.lazyCells) lazyCellsDue();  // the cells: build_cells_S, where a list is rebuilt
}

}  // namespace sphc::verlet_tune
