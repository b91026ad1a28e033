// The Plan: a scene after semantic analysis. Sema builds it from the AST (names resolved,
// equations instantiated with their arguments); the analysis passes annotate it (body facts,
// liveness, exact property sets, pair quantities); the code generators read it.
#pragma once

#include "body/BodyAnalysis.h"
#include "frontend/AST.h"
#include "sema/Options.h"

#include "llvm/Support/SMLoc.h"
#include "llvm/Support/raw_ostream.h"

#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace sphc {

class DiagnosticEngine;

// A property of an array as the solver will allocate it.
struct PlanProperty {
  std::string name;
  std::string type = "double";     // double, int, uint
  int stride = 1;
  ast::ExprPtr init;               // initial value (null: 0 or set by geometry)
  llvm::SMLoc declLoc;             // `property` declaration, if any
  bool declared = false;
  bool fromScheme = false;         // declared by a scheme the scene uses, not by the array
  bool written = false;            // by a live equation or stepper
  bool read = false;               // by a live equation, stepper, output or neighbour search
  bool output = false;
};

struct PlanArray {
  std::string name;
  llvm::SMLoc loc;
  const ast::ArrayDecl* decl = nullptr;
  std::vector<PlanProperty> props;       // filled by the properties pass; x, y, z first
  std::vector<std::string> constants;    // declared consts and reduce targets
  int stepper = -1;                      // index into Plan::steppers
  std::vector<std::string> outputProps;  // as listed in the scene's output
  std::vector<std::string> limitProps;   // what the scene's limits read (speed: u, v, w)
  std::vector<std::string> metricProps;  // what the scene's metrics read (sema/Metrics.cpp)
  // What the inlet/outlet manager copies between arrays and sets on the host (sema/Zones.cpp).
  std::vector<std::string> zoneProps;
  // With a periodic or mirror domain: the properties ghost copies of this array's particles
  // carry (what the source side of a loop reads, and what groups with `real = false` read
  // on it), filled by the ghost pass; empty when the array is no source.
  std::vector<std::string> ghostProps;
  const PlanProperty* find(const std::string& p) const;
  PlanProperty* find(const std::string& p);
};

// Adds the names an expression mentions to `out`.
void namesOf(const ast::Expr& e, std::set<std::string>& out);

// The declared properties of array `a` that are not allocated (`allocated` is false for them)
// but that the initial values of allocated ones read, directly or through other initial values
// (`property ui = x; property q = 2 * ui;` with only q used): the set-up computes them per
// particle, in declaration order, without storing them. An initial value reads the properties
// declared before it (docs/language.md, Arrays).
std::set<std::string> initialValueInputs(
    const ast::ArrayDecl& a, const std::function<bool(const std::string&)>& allocated);

// A body after analysis: its source and what Clang found in it.
struct PlanBody {
  BodySource source;
  BodyFacts facts;
};

// An equation declaration used by the scene, with its bodies analysed once.
struct PlanEquationDecl {
  const ast::EquationDecl* decl = nullptr;
  std::map<ast::Method::Kind, int> methods;  // kind -> index into Plan::bodies
  std::string reduceOp, reduceTarget;
};

// One use of an equation: `Name(dest = a, sources = [b, c], p = expr)`.
struct PlanEquation {
  int id = 0;
  int declIndex = -1;                         // into Plan::equationDecls
  std::string name;                           // equation name
  llvm::SMLoc loc;                            // the instance in the scene
  int dest = -1;                              // array index
  std::vector<int> sources;                   // array indices
  // Parameter and const values in evaluation order (params first, then consts).
  std::vector<std::pair<std::string, ast::ExprPtr>> values;
  bool live = true;
  std::string pruneReason;
  // A group's `pre`/`post` body (an unnamed equation with a host reduce): always run, in a
  // phase of its own.
  bool hook = false;
  std::vector<std::string> effects;           // the effects whose `when` kept it
};

struct PlanGroup {
  llvm::SMLoc loc;
  bool real = true;
  bool iterate = false;
  int minIterations = 1, maxIterations = 1;
  // `every = N` (an expression of params, evaluated at each evaluation): the group runs only
  // when the number of completed time steps is a multiple of N (never when N < 1); null:
  // always. `post_step = true` (top-level groups only): the group runs after each time step
  // instead of in compute_accelerations.
  ast::ExprPtr every;
  bool postStep = false;
  // `start_idx = A, stop_idx = B` (expressions of params and array constants `arr.c`,
  // rounded to the nearest integer at each evaluation): the group's direct equations run on
  // destination particles A <= d_idx < B only (clamped to the particles there are); null:
  // from 0, to the end. Reductions still see every real particle (PySPH's reduce sees the
  // whole array). `condition = E` (params, array constants, `t`, `dt`): the group runs only
  // at evaluations where E is non-zero, tested once before it (and before `pre`).
  ast::ExprPtr startIdx, stopIdx, condition;
  // `update_nnps = true`: the neighbour search is rebuilt after the group's members ran
  // (after each iteration of an iterated group), so that a later group sees positions the
  // group changed.
  bool updateNnps = false;
  std::vector<int> equations;                 // direct members, in order
  std::vector<std::unique_ptr<PlanGroup>> subgroups;
  // Order of members: entry >= 0 is equations[entry]; entry < 0 is subgroups[-entry - 1].
  std::vector<int> order;
  // Pair quantities needed per (dest, source) loop: filled by the pair-quantity pass.
  std::map<std::pair<int, int>, std::set<std::string>> pairQuantities;
};

// One side (low or high end) of an axis of the scene's `domain { }`.
struct PlanBoundary {
  enum Kind { Open, Periodic, Mirror };
  Kind kind = Open;
  ast::ExprPtr at;                            // the plane (Periodic: an end of the box)
  llvm::SMLoc loc;                            // the domain item that set it
};

// The scene's domain: per axis, its low and high side. Periodic axes have both sides
// Periodic; a mirror is per side.
struct PlanDomain {
  llvm::SMLoc loc;                            // the `domain` keyword
  PlanBoundary lo[3], hi[3];
  bool any() const {
    for (int a = 0; a < 3; ++a)
      if (lo[a].kind != PlanBoundary::Open || hi[a].kind != PlanBoundary::Open) return true;
    return false;
  }
};

// One limit of the scene's `limits { }` (docs/language.md, Limits): the run warns once when
// the quantity leaves `warn` and stops (as a blow-up) when it leaves `stop`. Absent ends
// are unbounded; both absent: no such bound.
struct PlanLimit {
  llvm::SMLoc loc;                            // the array name of the item
  int array = -1;
  std::string quantity;                       // a property, or "speed"
  bool hasWarn = false, hasStop = false;
  ast::ExprPtr warnLo, warnHi, stopLo, stopHi;
  // `remove [lo, hi] where C in [lo, hi]` (quantity x, y or z): the particles outside the
  // remove bound where the coordinate C lies within its bound are taken out of the run,
  // counted; C empty: no condition. Absent ends are unbounded.
  bool hasRemove = false;
  llvm::SMLoc removeLoc;                      // the `remove` keyword
  ast::ExprPtr removeLo, removeHi;
  std::string removeWhere;                    // "x", "y", "z" or empty
  ast::ExprPtr whereLo, whereHi;
};

// One metric of the scene's `metrics { }` (docs/language.md, Metrics; sema/Metrics.cpp):
// evaluated on the host at every output time (runtime/include/sphc/metrics.h).
struct PlanMetric {
  enum Kind { L1, L2, Linf, Max, Min, Sum, Mean };
  llvm::SMLoc loc;                            // the metric's name
  std::string name;
  Kind kind = L1;
  int array = -1;
  ast::ExprPtr expr;                          // per particle
  ast::ExprPtr exact;                         // norms: per particle; scalars: of t and params
  ast::ExprPtr where;                         // per particle; null: every particle
  ast::ExprPtr at;                            // the reference's abscissa at time t (default t)
  bool relative = false;
  std::string reference;                      // the table's file, as written
  std::string column, abscissa;               // its columns
  std::vector<double> refAt, refValue;        // the table, read at compile time
  std::vector<std::string> reads;             // the array's properties it reads
  // A profile (a norm with a reference): the expression fitted at one point per table row.
  ast::ExprPtr point[3];                      // x, y, z of a row's point, of s and params
  ast::ExprPtr rows;                          // which rows (of s and params); null: all
  ast::ExprPtr radius;                        // the fit's radius (params)
  ast::ExprPtr average;                       // the time window of the mean (params); null: 0
  bool isNorm() const { return kind == L1 || kind == L2 || kind == Linf; }
  bool isProfile() const { return isNorm() && !reference.empty(); }
  bool compared() const { return !isNorm() && (exact || !reference.empty()); }
};

// An inlet or outlet of the scene (sema/Zones.cpp; runtime: sphc/inlet_outlet.h). The
// expressions are of params; the velocity of an inlet also of x, y, z and t.
struct PlanZone {
  bool inlet = true;
  std::string name;
  llvm::SMLoc loc;
  int array = -1;      // the zone's particles
  int other = -1;      // inlet: the array it feeds; outlet: the array it takes from
  ast::ExprPtr point[3], normal[3], length, width;
  ast::ExprPtr velocity[3];  // inlet: u, v, w (null: not prescribed on that axis: 0)
  std::vector<std::string> copy;  // empty: every property both arrays have
  std::string type = "do_nothing";  // outlet condition
  ast::ExprPtr c, pRef, tau;        // characteristic outlet: sound speed, p_ref, averaging time
};

struct PlanStepper {
  const ast::StepperDecl* decl = nullptr;
  std::map<std::string, int> methods;         // "initialize", "stage1", ... -> body index
};

struct Plan {
  std::string sceneName;
  std::string mainFile;
  const ast::SceneDecl* scene = nullptr;
  int dim = 2;
  std::string kernel = "CubicSpline";
  double kernelRadiusScale = 2.0;
  ast::ExprPtr tf, dt;
  bool adaptiveDt = false;
  ast::ExprPtr cfl, forceFactor;
  ast::ExprPtr viscousFactor, nu;  // viscous limit: viscousFactor * h^2 / nu (if nu is given)
  // What bounds a fixed step (scene settings sound_speed, av_alpha, viscosity, body_force;
  // analysis/DtBound.cpp), and the smallest initial h of the moving arrays it found (null:
  // none known before the run, no bound).
  ast::ExprPtr soundSpeed, avAlpha, viscosity, bodyForce, dtBoundH;
  // The effect a scheme needs in an internal flow (setting internal_flow_needs, a Name;
  // analysis/InternalFlow.cpp), and where it is set: the scheme's use in the scene.
  ast::ExprPtr internalFlowNeeds;
  llvm::SMLoc internalFlowNeedsLoc;
  ast::ExprPtr outputEvery;
  std::vector<ast::ExprPtr> outputAt;
  bool outputNearestStep = false;  // output_landing = nearest_step
  std::vector<std::string> integratorSteps;   // initialize, stage1, compute_accelerations, ...
  std::string integratorName;
  std::vector<const ast::ParamDecl*> params;  // in order
  std::vector<PlanArray> arrays;
  std::vector<PlanEquationDecl> equationDecls;
  std::vector<PlanEquation> equations;
  std::vector<PlanStepper> steppers;
  std::vector<PlanBody> bodies;
  // Helper functions (`function double f(...) { }`) of every module, callees first (imported
  // modules before the modules importing them, each in declaration order): analysed with the
  // bodies and emitted once, before them, into the C++ and the OpenCL source.
  std::vector<PlanBody> functions;
  PlanDomain domain;                          // periodic and mirror boundaries
  std::vector<PlanLimit> limits;              // what the run watches (limits { })
  std::vector<PlanMetric> metrics;            // what the run measures (metrics { })
  std::vector<PlanZone> zones;                // inlets and outlets, in order
  PlanGroup root;                             // the scene's equations { } as a group
  // Dimension pass: the components a 1D/2D scene leaves out (read as 0, never stored);
  // a declared one is not allocated and not warned about.
  std::set<std::string> leftOutComponents;
  // `vector (ustar, vstar, wstar);` of every module: each named scalar property and its
  // component (0 x, 1 y, 2 z), which the dimension pass leaves out when it is >= dim.
  std::map<std::string, int> vectorComponents;
  std::vector<std::string> notes;             // what the passes decided, for --report
  std::vector<ChosenOption> options;          // compile-time options (sema/Options.h)
  // sphc --mpi: a distributed solver. Halos of remote particles play the ghosts' part, with or
  // without a domain (analysis/Ghosts selects what they carry; codegen/Schedule the steps).
  bool distributed = false;

  int arrayIndex(const std::string& name) const;
};

// Prints the plan (used by --dump-after and --report).
void printPlan(const Plan& plan, llvm::raw_ostream& os, bool report);

}  // namespace sphc
