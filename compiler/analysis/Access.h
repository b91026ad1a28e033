// Who reads and writes which (array, property): the facts every analysis pass works from.
// Explicit accesses come from the Clang facts of bodies; implicit ones from what the
// generated code reads on a body's behalf (positions and h for neighbour search, and what the
// pair quantities a loop uses read: analysis/PairQuantityTable.h).
#pragma once

#include "analysis/PairQuantityTable.h"
#include "sema/Plan.h"

#include <string>
#include <vector>

namespace sphc {

struct Access {
  int array = -1;
  std::string prop;
  llvm::SMLoc loc;         // where in a body (or the equation instance, for implicit reads)
  bool write = false;
  bool viaSource = false;  // an s_ read in a loop
  bool implicit = false;   // read by generated code (pair quantities, neighbour search)
  int equation = -1;       // PlanEquation id, or -1 for a stepper
  ast::Method::Kind method = ast::Method::Initialize;  // for equations
  std::string stepperMethod;                           // for steppers
};

// All accesses of one equation instance (all its methods, every source).
std::vector<Access> equationAccesses(const Plan& plan, const PlanEquation& eq);
// All accesses of the stepper of array `a` (empty if it has none).
std::vector<Access> stepperAccesses(const Plan& plan, int a);
// The positions an array has in this dimension: x; x, y; x, y, z.
std::vector<std::string> positionProps(int dim);

}  // namespace sphc
