// The CPU printer's --verlet-skin=auto (CpuVerletTune.cpp): the kept neighbour lists with the
// skin and the cell-order re-sort chosen at run time (runtime sphc/verlet_tune.h);
// --verlet-skin=F prints the fixed skin's code of CpuPrinter.cpp. Internal to codegen;
// CpuPrinter.cpp calls them with what it knows of the scene.
#ifndef SPHC_CODEGEN_CPUVERLETTUNE_H
#define SPHC_CODEGEN_CPUVERLETTUNE_H

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace sphc::verlet_tune {

// Members of struct Scene: the tuner, the skin of the lists built now and their radius.
void members(std::ostream& out);

// A pair loop's kept lists, for their rebuild check.
struct KeptLoop {
  std::string lists;                // the member (CpuPrinter::verletLists)
  std::string begin, end;           // the destination's range
  std::string dest;                 // the destination array
  std::string staticArray;          // the one array of two that is static, else ""
  std::vector<std::string> moving;  // the arrays that may move (destination first)
  bool ranged = false;              // a range of its own (start_idx, stop_idx)
  bool clearUpper = false;          // a symmetric loop's `upper` found again after a build
  bool clearCross = false;          // OpenMP pairs of two arrays once: LISTS_by_source too
  bool clearOccupied = false;       // pairs of two arrays: LISTS.occupied found again
};
// `verlet_build` and the rebuild: skin, positions, range.
void rebuildCheck(std::ostream& scene, const KeptLoop& loop);

// A source of a neighbour loop at update_neighbours.
struct Source {
  std::string name;
  bool isStatic = false;           // cells of build_static_cells
  bool reorders = false;           // sorted into cell order (not a ranged group's source)
  std::string orderCells, cells;   // its cell-list build on order_domain / on domain
  std::string permute;             // its permutation into cell order
  std::vector<std::string> lists;  // the kept lists it is in (forgotten after a sort)
};
struct Update {
  bool lazyCells = false;   // CpuLazyCells.h: the cells where a list is rebuilt
  bool loopArrays = false;  // some array in a neighbour loop
  bool anyStatic = false;
  bool anyReorders = false;
  std::string loopArraysDecl;  // lazy_cells::loopArraysDecl
  std::string orderDomain;     // the statement that makes order_domain (CpuPrinter::orderDomain)
  std::vector<Source> sources;
};
// update_neighbours of a scene without periodic or mirror domain: the skin of the lists built
// from now on, the search domain (searchDomain, without lazy cells) with cells that large,
// the sort into cell order where due, the cell lists (lazyCellsDue with lazy cells).
void updateNeighbours(std::ostream& scene, const Update& u,
                      const std::function<void()>& searchDomain,
                      const std::function<void()>& lazyCellsDue);

}  // namespace sphc::verlet_tune

#endif  // SPHC_CODEGEN_CPUVERLETTUNE_H
