// Each pair once for both particles (sphc --no-symmetric-pairs turns it off): in a pair loop
// whose destination array is its source, the CPU backends with kept neighbour lists
// (--verlet-skin, lists in increasing particle index, the neighbour relation symmetric) visit
// every pair i < j once, from i's list, compute its pair quantities once and call every loop
// body twice: for destination i with source j, then for destination j with source i with the
// mirrored quantities (XIJ, VIJ as x_j - x_i, ..., the kernel gradient's factor shared).
// Every particle then receives its contributions in the order it gathers them today (sources
// in increasing index), so the results are the same bit for bit; with OpenMP the particles
// are split into contiguous blocks, one per thread: per block, each particle gathers from its
// neighbours in earlier blocks, the pairs within the block are evaluated once, then each
// gathers from later blocks (the serial order of contributions whatever the thread count).
// The emission is codegen/SymmetricPairs.cpp (ScenePrinter::emitSymmetricPass); this header
// is what the driver's --report asks.
#pragma once

#include "codegen/CppEmitter.h"
#include "codegen/Schedule.h"

#include <functional>
#include <string>
#include <vector>

namespace sphc {

// The name of a pair quantity in the mirrored call (destination j, source i): XIJ_ji, WJ for
// WI, ...; a symmetric one its own.
std::string mirroredPairQuantity(const std::string& q);

// Why the neighbour pass `pass` of destination work `w` cannot evaluate each pair once for
// both particles ("" where it can). listsKept: the printer keeps neighbour lists (in index
// order) for the pass.

std::string symmetricPairsRefusal(const Plan& plan, const DestinationWork& w,
                                  const NeighbourPass& pass, bool listsKept);

// Pair loops of two arrays (A <- B and B <- A, e.g. fluid <- boundary with boundary <- fluid):
// why destinations a and b of phase ph cannot evaluate each pair once for both ("" where
// they can). The CPU printer then runs A <- B, A's last pair loop, in B's place, as B's
// first: for each particle a of A, each b of a's kept list (index order), the pair
// quantities once, A's bodies for (a, b), then B's for (b, a) with the mirrored quantities.
// Each particle receives its contributions in the order it gathers them today.
std::string crossPairsRefusal(const Plan& plan, const Phase& ph, size_t a, size_t b,
                              bool listsKept);

// --report: one note per same-array pair loop of the schedule, whether it evaluates each pair
// once and, where not, why; then one per pair of loops A <- B, B <- A of one phase. inLanes,
// where given, says which passes the printer puts in SIMD lanes per destination instead
// (--simd-pairs; ScenePrinter::pairLoopNotes).
std::vector<std::string> symmetricPairsNotes(
    const Schedule& sched, const EmitOptions& opts,
    const std::function<bool(const DestinationWork&, const NeighbourPass&)>& inLanes = {});

}  // namespace sphc
