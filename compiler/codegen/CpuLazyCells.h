// The CPU printer's lazy cell lists (CpuLazyCells.cpp): --verlet-skin without a periodic or
// mirror domain builds the search domain and the moving sources' cell lists only at the
// neighbour updates where some pair loop rebuilds its kept lists (docs/performance-log.md, "Cell
// lists only when a kept list is rebuilt"). Internal to codegen; CpuPrinter.cpp calls them.
#ifndef SPHC_CODEGEN_CPULAZYCELLS_H
#define SPHC_CODEGEN_CPULAZYCELLS_H

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace sphc::lazy_cells {

// `const std::vector<const sphc::ParticleArray*> all = {&a, ...};`: the arrays of the
// neighbour loops (the search domain's), in the plan's order.
std::string loopArraysDecl(const std::vector<std::string>& loopArrays);
// Members of struct Scene: domain_due and cells_due_S of each moving (not static) source.
void members(std::ostream& out, const std::vector<std::string>& movingSources);
// End of update_neighbours: the domain and cells out of date.
void markDue(std::ostream& scene, const std::vector<std::string>& movingSources);
// Functions of struct Scene: make_domain (its body printed by searchDomain) and build_cells_S
// of each moving source (its build statement: cellListBuild(S)).
void functions(std::ostream& scene, const std::vector<std::string>& movingSources,
               const std::function<void()>& searchDomain,
               const std::function<std::string(const std::string&)>& cellListBuild);

}  // namespace sphc::lazy_cells

#endif  // SPHC_CODEGEN_CPULAZYCELLS_H
