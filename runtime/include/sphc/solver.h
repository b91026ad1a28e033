// sphc runtime: the run loop and command line of every generated solver.
//
// The generated `main` fills a SceneProgram and returns run_main(argc, argv, prog). run_main
// owns the command line (see --help), the time loop, output (HDF5 files plus an XDMF index),
// the progress line and the blow-up diagnosis.
//
// Exit codes: 0 success, 1 error (an exception from the scene or from output, or a run that
// needs more memory than is available: see sphc/memory.h), 2 bad usage,
// 3 the simulation blew up (a non-finite value, a quantity past the stop bound of a limit:
// sphc/sanity.h, or the adaptive time step collapsed).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <chrono>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "sphc/hdf5_io.h"
#include "sphc/memory.h"
#include "sphc/metrics.h"
#include "sphc/particle_array.h"
#include "sphc/sanity.h"

namespace sphc {

struct ParamInfo {
  std::string name;
  double value = 0.0;  // default; NaN: computed at set-up from other parameters (see help)
  std::string help;
};

// A compile-time option of the scene (`option NAME in [...]`, chosen with `sphc -D NAME=...`):
// fixed in this executable; shown by --help and refused by --set with a hint to rebuild.
struct OptionInfo {
  std::string name;
  std::string value;
  std::string choices;  // "wcsph, edac, tvf"
};

// A parameter of an effect this executable was built without (`param delta = 0.1 for
// delta_sph;`, docs/effects.md): `--set` of it is an error that names the effect and the
// sphc command that builds a solver with it.
struct EffectParamInfo {
  std::string name;
  std::string effect;
  std::string command;  // "sphc dambreak.sph -D density_gradient=on -D delta_sph=on"
};

// The generated main's lists of parameters, options and effects' parameters, as plain data
// appended in order: `sphc::add_params(prog.params, {{"dx", 0.03, ""}, ...})` puts no code per
// entry in the solver's text, as a push_back of each would (docs/performance-log.md, "Compile
// time: the runtime's code in its library").
struct ParamSpec {
  const char* name;
  double value;
  const char* help;
};
struct OptionSpec {
  const char* name;
  const char* value;
  const char* choices;
};
struct EffectParamSpec {
  const char* name;
  const char* effect;
  const char* command;
};
void add_params(std::vector<ParamInfo>& to, std::initializer_list<ParamSpec> specs);
void add_options(std::vector<OptionInfo>& to, std::initializer_list<OptionSpec> specs);
void add_effect_params(std::vector<EffectParamInfo>& to,
                       std::initializer_list<EffectParamSpec> specs);

// Times a scene computes from its parameters; the command line may override them.
struct SceneTimes {
  double tf = 1.0;                 // final time
  double dt = 1e-4;                // fixed time step, or the initial one with adaptive_dt
  double output_every = 0.0;       // sim-time interval; 0 = no periodic output
  std::vector<double> output_at;   // extra output times
  // output_landing = nearest_step (docs/language.md, "Output times"): steps keep their length
  // and each output (and the end) is taken at the end of the step nearest to its time, with
  // the time actually reached; for schemes whose result depends on the step (IISPH).
  bool output_nearest_step = false;
  // The stable bound of a fixed step (the compiler's analysis/DtBound.cpp, computed by the
  // scene's set-up with the actual parameters) and its limiting term; HUGE_VAL: none stated.
  // A fixed dt above it is reported at start-up (bound_dt, check_fixed_dt).
  double dt_bound = HUGE_VAL;
  std::string dt_bound_term;
};

// A term's description: "acoustic limit ... (h = 0.039, c0 = 62.64, alpha = 0.1; SOURCE)".
inline std::string dt_bound_text(const char* formula, const char* source, double h,
                                 std::initializer_list<std::pair<const char*, double>> values) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4g", h);
  std::string s = std::string(formula) + " (h = " + buf;
  for (const auto& [name, v] : values) {
    std::snprintf(buf, sizeof buf, "%.4g", v);
    s += std::string(", ") + name + " = " + buf;
  }
  return s + "; " + source + ")";
}

// One term of the bound: keeps the smallest positive finite one.
inline void bound_dt(SceneTimes& times, double dt, const std::string& term) {
  if (std::isfinite(dt) && dt > 0 && dt < times.dt_bound) {
    times.dt_bound = dt;
    times.dt_bound_term = term;
  }
}

// The wall time of one top-level group of the equations, or of one group with
// post_step = true (run after each time step), for --timing.
struct GroupSeconds {
  std::string name;     // FILE:LINE of the group
  std::string equations;  // its live equations, comma-separated
  double seconds = 0.0;
  bool post_step = false;  // a post_step group (after the time step, in prog.step)
};

// How many iterations the evaluations of one iterated group took (group (iterate = true)):
// the generated code records every evaluation; --timing prints the figures.
struct IterationStats {
  std::string where;       // the group's source location, file:line
  long evaluations = 0;    // evaluations of the group (one per compute_accelerations)
  long total = 0;          // iterations over all evaluations
  int min = 0, max = 0;    // fewest and most iterations of one evaluation
  int last = 0;            // iterations of the latest evaluation
  long unconverged = 0;    // evaluations stopped by max_iterations before converging

  void record(int iterations, bool converged) {
    min = evaluations == 0 || iterations < min ? iterations : min;
    max = iterations > max ? iterations : max;
    last = iterations;
    total += iterations;
    ++evaluations;
    if (!converged) ++unconverged;
  }
};

struct SceneProgram {
  std::string name;  // scene name (used for output names)
  int dim = 2;
  std::vector<ParamInfo> params;  // defaults, in order; --set overrides by name
  std::vector<OptionInfo> options;  // compile-time options this executable was built with
  std::vector<EffectParamInfo> effect_params;  // params of effects it was built without
  // Called with the final parameter values (same order as params). Builds arrays, sets the
  // scene's tf, dt and output times (they may depend on params). run_main calls it twice:
  // first inside a CountingPass (sphc/memory.h: no particles are made, only counted, for the
  // memory estimate; copies to a device or to float arrays are then skipped), then for real.
  std::function<void(const std::vector<double>& params, SceneTimes& times)> setup;
  std::function<std::vector<ParticleArray*>()> arrays;
  std::function<void(double t, double dt)> compute_initial;  // may be empty
  std::function<void(double t, double dt)> step;             // one time step from t to t+dt
  std::function<double()> adaptive_dt;                       // empty = fixed dt
  // Iterated groups (a nested one before the group around it): their iteration counts so
  // far (may be empty).
  std::function<std::vector<IterationStats>()> iterations;
  // Device backends: copies the device's particle data into the host arrays. The run loop
  // calls it only before it reads them (output, blow-up checks); empty = data lives on the host.
  std::function<void()> to_host;
  // Called before each output is written (and its metrics evaluated); empty = nothing. A scene
  // whose kept neighbour lists let particles stay slightly outside a periodic box between
  // rebuilds wraps them into it here, so that every output holds positions in the box.
  std::function<void()> before_output;
  // Multi-threaded backends: sets the number of threads (--threads N) and returns the number
  // in use; empty for a serial solver, which then refuses --threads.
  std::function<int(int threads)> set_threads;
  // The backend the solver was built with, for the timing line ("serial", "openmp", ...).
  std::string backend = "serial";
  // The floating point type the scene computes in ("double" or "single"), for the timing line.
  std::string precision = "double";
  // Wall seconds spent so far in the neighbour search (search domain, cell lists, reorders
  // into cell order), for the --timing line; empty where not measured.
  std::function<double()> neighbour_seconds;
  // Wall seconds spent so far in each top-level group of the equations, with its name
  // (FILE:LINE and the equations in it), for the --timing lines `timing-group:`; empty where
  // not measured (OpenCL: its kernels run asynchronously, so the host's clock would time
  // their enqueueing, not their work).
  std::function<std::vector<GroupSeconds>()> group_seconds;
  // Wall seconds spent so far in the inlet/outlet step (sphc/inlet_outlet.h, with the data
  // movement it needs), for the --timing line; empty without inlets and outlets.
  std::function<double()> inlet_outlet_seconds;
  // Device backends: kernel launches so far (scene and runtime kernels, reductions included),
  // for the --timing line's launches_per_step; empty where nothing is launched.
  std::function<long()> device_launches;
  // The scene's limits { } (sphc/sanity.h), computed from the parameters after the set-up;
  // empty: none declared (the default bounding box applies).
  std::function<std::vector<Limit>()> limits;
  // After the run loop took particles of array `a` out of the host arrays (a limit's
  // `remove`): moves the array where the scene computes on it (--precision=single: its float
  // copy) and forgets what depended on its particles (a static array's cells); empty: nothing
  // to do (kept lists see the new count and are rebuilt).
  std::function<void(const ParticleArray& a)> after_removal;
  // Distributed runs with a limit's `remove` (sphc/mpi/output.h, set_removal). Collective:
  // every rank calls them in the same order. gather_removed, at every check for each remove
  // bound, after the rank took its particles `mask` (empty: none) out of `a` (and
  // after_removal): the domain decomposition forgets their counted work, and `gone` (those
  // particles, the removed-particles file's columns) becomes every rank's on rank 0, in gid
  // order (empty on the others). sum_over_ranks: a sum over the ranks (the array's mass at
  // the start). Empty: one process.
  std::function<void(const ParticleArray& a, const std::vector<std::uint8_t>& mask,
                     ParticleArray& gone)>
      gather_removed;
  std::function<double(double)> sum_over_ranks;
  // The scene's metrics { } (sphc/metrics.h): what they are, and their values at time t from
  // the host arrays (the run loop calls it where it writes output); empty: none declared.
  std::vector<MetricInfo> metrics;
  std::function<std::vector<MetricValue>(double t)> evaluate_metrics;
  // Array name -> properties written (empty list = all); empty = every array, all properties.
  std::vector<std::pair<std::string, std::vector<std::string>>> output;
  // Distributed runs (sphc --mpi, sphc/mpi/): this process's rank (-1: not distributed). Only
  // rank 0 writes files and prints the progress line and the summary; the --timing lines of
  // every rank name it (rank=R), so iteration counts can be compared between ranks.
  int rank = -1;
  // The arrays an output writes, when they are not `arrays` (distributed: every rank's
  // particles gathered to rank 0). Called on every rank at each output (collective).
  std::function<std::vector<ParticleArray*>()> output_arrays;
  // Distributed runs with collective output (sphc/mpi/output.h): writes the output file `path`
  // (named `file` in the output directory) from every rank's particles of the selection, on
  // every rank together, and returns the file's XDMF entry (whole-job particle counts).
  // Empty: rank 0 writes with write_particles_hdf5.
  std::function<XdmfEntry(const std::string& path, const std::string& file,
                          const std::vector<OutputArray>& selection, const OutputMeta& meta)>
      write_particles;
  // Restart (--restart FILE; docs/design.md, "Restart"). run_state: the scene's state beyond
  // its particles and constants (completed steps, neighbour builds, global-id counters), as
  // named numbers; every output file carries it (root attributes restart_NAME) with the
  // time loop's. restore: after the run loop has replaced the particles and constants of
  // `arrays` by the file's, sets that state again and moves the data where the scene
  // computes on it (device, float copies; a distributed run re-balances). Empty restore: the
  // solver cannot restart (--restart is refused).
  std::function<std::vector<std::pair<std::string, double>>()> run_state;
  std::function<void(const std::vector<std::pair<std::string, double>>& state)> restore;
  // --restartable: called after each output is written (a restart file). A scene whose pair
  // loops keep state a restart cannot read from the file (the cluster-pair tiles' layout,
  // slot order and sort bookkeeping, built from the particles' history: stop 43) starts it
  // afresh here, as a run restarted from that file starts it, so that the restarted run goes
  // on bitwise as this one. Empty: nothing to start afresh (the scalar loops' kept lists are
  // in index order, a function of the particles now: sphc/verlet.h).
  std::function<void()> restart_point;
  // Distributed runs: the number of ranks (rank r of a restart reads block r of the file).
  int ranks = 1;
  // The default box limits (sanity.h), when not those of `arrays` after the set-up
  // (distributed: the box of the whole set-up, taken before each rank kept its particles).
  std::function<std::vector<Limit>()> default_limits;
};

// Seconds on a steady clock (for the scene's own timers, e.g. neighbour_seconds).
inline double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Runs the scene as the command line asks; returns the process exit code.
int run_main(int argc, char** argv, SceneProgram& prog);

// OpenMP solvers call this first thing in main. libgomp reads its barrier wait policy from
// the environment when it is loaded, before main. Its default spins: the fastest on an idle
// machine (dam break, 3.4k particles, 2 threads: 0.20 us per particle per step against 0.58
// sleeping), but when other processes load the cores a thread spins while the one it waits
// for is not running (measured at load 10 on 2 cores: 100 us spinning, 1.5 sleeping).
// `--omp-wait active|passive` re-executes the solver once with OMP_WAIT_POLICY set so;
// `auto` (the default) does so with passive only when the machine is loaded at start
// (wants_passive_wait), and never when the user set OMP_WAIT_POLICY or GOMP_SPINCOUNT. If the
// exec fails the run goes on as it is. run_main checks the option.
void choose_omp_wait(int argc, char** argv);

// The rule of `--omp-wait auto`: sleep at barriers when the cores are oversubscribed, i.e.
// both the 1-minute load average `load1` is at least `cores` (a sustained load) and the
// processes runnable right now besides this one (`others`, from /proc/loadavg) plus the
// `threads` this run starts exceed `cores`. The load average alone lags by a minute: a
// benchmark that has just finished its serial runs on an idle machine still shows load 2,
// and spinning would then have been right (dam break, ~100k particles, 2 threads: 0.231 us
// per particle per step spinning against 0.244-0.252 sleeping).
bool wants_passive_wait(double load1, long others, long threads, long cores);

}  // namespace sphc
