// sphc runtime: the run loop and command line of generated solvers (see solver.h).
#include "sphc/solver.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <new>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "sphc/hdf5_io.h"
#include "sphc/memory.h"
#include "sphc/restart.h"

namespace sphc {
namespace {

constexpr int kExitOk = 0;
constexpr int kExitError = 1;
constexpr int kExitUsage = 2;
constexpr int kExitBlowUp = 3;

constexpr double kTimeSlack = 1e-12;     // relative to tf: "t reached tf", "t reached an output"
constexpr double kMinDtFraction = 1e-12; // an adaptive dt below this * tf has collapsed
constexpr long kCheckEvery = 10;         // steps between scans for non-finite values
constexpr long kCheckEveryDevice = 100;  // the same where each scan copies data off a device

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string scene_name(const SceneProgram& prog) {
  return prog.name.empty() ? std::string("scene") : prog.name;
}

// ---------------------------------------------------------------------------------------------
// Command line.

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Options {
  bool help = false;
  bool quiet = false;
  bool no_output = false;
  bool timing = false;
  std::optional<double> tf;
  std::optional<double> dt;
  std::optional<double> output_every;
  std::optional<bool> output_nearest_step;  // --output-landing exact|nearest_step
  long max_steps = std::numeric_limits<long>::max();
  long threads = 0;  // 0: the backend's default (all cores)
  std::string directory;  // empty: <scene>_output
  std::optional<double> max_memory;  // bytes; default: available_memory()
  bool estimate_memory = false;      // print the memory estimate and stop
  std::string limits = "on";         // on, warn (never stop), off (sphc/sanity.h)
  std::vector<std::string> limit_settings;  // --limit ARRAY.QUANTITY.warn|stop=LO:HI
  std::vector<std::pair<std::string, double>> sets;
  std::string metrics_file;  // --metrics FILE (default: DIR/<scene>_metrics.csv)
  std::string restart;       // --restart FILE: continue the run from this output file
  bool restartable = false;  // --restartable: outputs carry every property (restart.h)
};

double parse_number(const std::string& text, const std::string& what) {
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE ||
      !std::isfinite(value)) {
    throw UsageError(fmt::format("{}: '{}' is not a number", what, text));
  }
  return value;
}

double parse_time(const std::string& text, const std::string& option, bool zero_allowed) {
  const double value = parse_number(text, option);
  if (value < 0 || (!zero_allowed && value == 0)) {
    throw UsageError(fmt::format("{}: expected a {} number, got '{}'", option,
                                 zero_allowed ? "non-negative" : "positive", text));
  }
  return value;
}

long parse_count(const std::string& text, const std::string& option) {
  char* end = nullptr;
  errno = 0;
  const long value = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || value < 0) {
    throw UsageError(
        fmt::format("{}: expected a non-negative whole number, got '{}'", option, text));
  }
  return value;
}

std::string parameter_names(const SceneProgram& prog) {
  if (prog.params.empty()) return fmt::format("the scene '{}' has no parameters", scene_name(prog));
  std::string names;
  for (const ParamInfo& p : prog.params) names += (names.empty() ? "" : ", ") + p.name;
  return fmt::format("the parameters of scene '{}' are: {}", scene_name(prog), names);
}

std::pair<std::string, double> parse_set(const std::string& arg, const SceneProgram& prog) {
  const std::size_t eq = arg.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw UsageError(fmt::format("--set expects NAME=VALUE, got '{}'", arg));
  }
  const std::string name = arg.substr(0, eq);
  const bool known = std::any_of(prog.params.begin(), prog.params.end(),
                                 [&](const ParamInfo& p) { return p.name == name; });
  for (const EffectParamInfo& e : prog.effect_params) {
    if (e.name == name) {
      throw UsageError(fmt::format(
          "--set {}: parameter '{}' belongs to the effect '{}', which this executable was "
          "built without; build one with it: `{}`",
          arg, name, e.effect, e.command));
    }
  }
  for (const OptionInfo& o : prog.options) {
    if (o.name == name) {
      throw UsageError(fmt::format(
          "--set {}: '{}' is a compile-time option, fixed to '{}' in this executable; build "
          "another with `sphc SCENE.sph -D {}=CHOICE` (choices: {})",
          arg, name, o.value, name, o.choices));
    }
  }
  if (!known) {
    throw UsageError(
        fmt::format("--set {}: unknown parameter '{}'; {}", arg, name, parameter_names(prog)));
  }
  return {name, parse_number(arg.substr(eq + 1), "--set " + name)};
}

Options parse_command_line(int argc, char** argv, const SceneProgram& prog) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    std::string option = argv[i];
    std::optional<std::string> attached;  // --name=value
    if (option.rfind("--", 0) == 0 && option.find('=') != std::string::npos) {
      attached = option.substr(option.find('=') + 1);
      option.resize(option.find('='));
    }
    auto value = [&]() -> std::string {
      if (attached) return *attached;
      if (i + 1 >= argc) throw UsageError(fmt::format("{} expects a value", option));
      return argv[++i];
    };
    auto flag = [&](bool& target) {
      if (attached) throw UsageError(fmt::format("{} takes no value", option));
      target = true;
    };

    if (option == "-h" || option == "--help") flag(o.help);
    else if (option == "--quiet") flag(o.quiet);
    else if (option == "--no-output") flag(o.no_output);
    else if (option == "--timing") flag(o.timing);
    else if (option == "--tf") o.tf = parse_time(value(), option, true);
    else if (option == "--dt") o.dt = parse_time(value(), option, false);
    else if (option == "--output-every") o.output_every = parse_time(value(), option, true);
    else if (option == "--output-landing") {
      const std::string v = value();
      if (v != "exact" && v != "nearest_step")
        throw UsageError("--output-landing expects exact or nearest_step, not '" + v + "'");
      o.output_nearest_step = v == "nearest_step";
    }
    else if (option == "--max-steps") o.max_steps = parse_count(value(), option);
    else if (option == "--threads") {
      o.threads = parse_count(value(), option);
      if (o.threads < 1) throw UsageError("--threads expects a positive number");
      if (!prog.set_threads)
        throw UsageError("--threads: this solver was built with --backend=" + prog.backend +
                         ", which runs on one thread");
    }
    else if (option == "--omp-wait") {  // acted on before main (choose_omp_wait)
      const std::string w = value();
      if (w != "auto" && w != "passive" && w != "active")
        throw UsageError("--omp-wait expects auto, passive or active, not '" + w + "'");
      if (!prog.set_threads)
        throw UsageError("--omp-wait: this solver was built with --backend=" + prog.backend +
                         ", which has no OpenMP threads");
    }
    else if (option == "--set") o.sets.push_back(parse_set(value(), prog));
    else if (option == "--metrics") {
      o.metrics_file = value();
      if (o.metrics_file.empty()) throw UsageError("--metrics expects a file name");
    }
    else if (option == "--max-memory") {
      const std::string v = value();
      o.max_memory = parse_memory_size(v);
      if (!o.max_memory)
        throw UsageError("--max-memory expects a size such as 4G, 500M or 1e9 (bytes), not '" +
                         v + "'");
    }
    else if (option == "--estimate-memory") flag(o.estimate_memory);
    else if (option == "--restartable") flag(o.restartable);
    else if (option == "--restart") {
      o.restart = value();
      if (o.restart.empty()) throw UsageError("--restart expects an output file");
      if (!prog.restore)
        throw UsageError("--restart: this solver was built without restart support");
    }
    else if (option == "--limits") {
      o.limits = value();
      if (o.limits != "on" && o.limits != "warn" && o.limits != "off")
        throw UsageError("--limits expects on, warn or off, not '" + o.limits + "'");
    }
    else if (option == "--limit") {
      o.limit_settings.push_back(value());
      std::vector<Limit> probe;
      try {
        apply_limit_setting(probe, o.limit_settings.back());
      } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
      }
    }
    else if (option == "-d" || option == "--directory") {
      o.directory = value();
      if (o.directory.empty()) throw UsageError(fmt::format("{} expects a directory", option));
    } else {
      throw UsageError(fmt::format("unknown option '{}'", argv[i]));
    }
  }
  return o;
}

std::string program_name(int argc, char** argv, const SceneProgram& prog) {
  if (argc > 0 && argv[0] && *argv[0]) return std::filesystem::path(argv[0]).filename().string();
  return scene_name(prog);
}

void print_help(const std::string& program, const SceneProgram& prog) {
  const std::string scene = scene_name(prog);
  fmt::print(
      "usage: {0} [options]\n"
      "\n"
      "Runs the sphc scene '{1}' ({2}D).\n"
      "\n"
      "options:\n"
      "  --tf T                final time (default: the scene's)\n"
      "  --dt DT               time step: the fixed one, or the initial one with an adaptive\n"
      "                        time step (default: the scene's)\n"
      "  --output-every T      output interval in simulation time, replacing the scene's\n"
      "                        output times (0: first and last state only)\n"
      "  --output-landing L    exact: steps are shortened to end on output times and tf;\n"
      "                        nearest_step: steps keep their length, each output is taken\n"
      "                        at the step end nearest to its time (default: the scene's)\n"
      "  --max-steps N         stop after N time steps\n"
      "  --threads N           threads to use (multi-threaded backends; default: all cores)\n"
      "  --omp-wait W          OpenMP barrier wait: active (spin: fastest on an idle machine),\n"
      "                        passive (sleep: far faster when other processes load the\n"
      "                        cores), auto (default: passive if at start the 1-minute load\n"
      "                        average is at least the number of cores and the processes\n"
      "                        running now with this run's threads exceed the cores, else\n"
      "                        libgomp's default; OMP_WAIT_POLICY or GOMP_SPINCOUNT set:\n"
      "                        left alone)\n"
      "  -d, --directory DIR   output directory (default: {1}_output)\n"
      "  --set NAME=VALUE      set a scene parameter (repeatable)\n"
      "  --max-memory SIZE     refuse to start when the memory estimate exceeds SIZE (4G,\n"
      "                        500M, bytes; default: MemAvailable of /proc/meminfo, or a\n"
      "                        lower cgroup limit)\n"
      "  --estimate-memory     print the memory estimate of the run, item by item, and stop\n"
      "  --limits on|warn|off  the scene's limits (limits {{ }}; without any, a box around the\n"
      "                        particles at set-up): warn once outside warn bounds and stop\n"
      "                        outside stop bounds (on, the default); only warn; not checked\n"
      "  --limit A.Q.warn=LO:HI, --limit A.Q.stop=LO:HI\n"
      "                        set a bound of the limit on quantity Q (a property or speed) of\n"
      "                        array A (an end may be empty: unbounded; =off removes it)\n"
      "  --quiet               no progress line and no summary\n"
      "  --no-output           write no snapshots (benchmarks)\n"
      "  --restartable         write every property of every array into each output, so\n"
      "                        that a run can restart from it (--restart); the\n"
      "                        cluster-pair tiles' layout is built afresh after each\n"
      "                        output, as in a run restarted from it (bitwise restarts)\n"
      "  --restart FILE        continue the run from the output FILE (written with\n"
      "                        --restartable): its particles, time, step and run state;\n"
      "                        outputs follow from the next output time on; --max-steps\n"
      "                        counts the steps of the whole run\n"
      "  --metrics FILE        write the scene's metrics (metrics {{ }}) to FILE, also with\n"
      "                        --no-output (default: DIR/{1}_metrics.csv)\n"
      "  --timing              print at the end, for the time loop:\n"
      "                        timing: steps=N particles=P wall_s=W us_per_particle_step=U\n"
      "                        backend=B threads=T [omp_wait=W] precision=double|single\n"
      "                        [nnps_s=S nnps_share=F: time in the neighbour search]\n"
      "                        [iterations=I: of iterated groups, in all]\n"
      "                        [launches_per_step=L: device kernel launches (OpenCL)]\n"
      "                        serial, OpenMP: per top-level group of the equations,\n"
      "                        timing-group: name=FILE:LINE s=S share=F equations=E,...\n"
      "                        and timing-split: wall_s=W groups_s=G nnps_s=N\n"
      "                        integrator_s=I outside_steps_s=O (G+N+I+O = W)\n"
      "                        and, per iterated group, the iterations of its evaluations:\n"
      "                        iterations: group=FILE:LINE evaluations=E total=N mean=M\n"
      "                        min=A max=B unconverged=U\n"
      "                        and the scene's metrics at the end, with the time loop's wall\n"
      "                        and CPU seconds: metrics: t=T wall_s=W cpu_s=C NAME=V ...\n"
      "  -h, --help            print this help\n"
      "\n"
      "Output: DIR/{1}_NNNNNN.h5 (NNNNNN: the step) and DIR/{1}.xdmf (for ParaView).\n"
      "Exit codes: 0 done, 1 error (also: more memory needed than available), 2 bad usage,\n"
      "3 the simulation blew up.\n",
      program, scene, prog.dim);
  if (!prog.options.empty()) {
    fmt::print("\ncompile-time options (sphc -D NAME=CHOICE builds another executable):\n");
    for (const OptionInfo& o : prog.options)
      fmt::print("  {} = {}  (choices: {})\n", o.name, o.value, o.choices);
  }
  if (prog.params.empty()) return;
  std::size_t width = 0;
  std::vector<std::string> lefts;
  for (const ParamInfo& p : prog.params) {
    // NaN: the default is computed from other parameters at set-up (help says how).
    lefts.push_back(std::isnan(p.value) ? p.name : fmt::format("{} = {}", p.name, p.value));
    width = std::max(width, lefts.back().size());
  }
  fmt::print("\nparameters (--set NAME=VALUE; defaults shown):\n");
  for (std::size_t k = 0; k < lefts.size(); ++k) {
    fmt::print("  {:<{}}  {}\n", lefts[k], width, prog.params[k].help);
  }
}

// ---------------------------------------------------------------------------------------------
// Progress line on stderr: in place (\r, at most 4 a second) on a terminal, else a plain line
// every 10% of tf.

class Progress {
 public:
  void start(bool enabled, double tf) {
    enabled_ = enabled && tf > 0;
    tty_ = isatty(fileno(stderr)) != 0;
    tf_ = tf;
    start_ = Clock::now();
    last_print_ = start_;
  }

  void update(double t, long step, double dt, std::size_t particles) {
    if (!enabled_) return;
    const double fraction = std::min(t / tf_, 1.0);
    if (tty_) {
      if (seconds_since(last_print_) < 0.25) return;
      const std::string text = line(t, step, dt, particles, fraction);
      fmt::print(stderr, "\r{:<{}}", text, shown_);
      shown_ = text.size();
      last_print_ = Clock::now();
    } else if (fraction >= next_fraction_ * (1.0 - 1e-9)) {
      // Every 10% of tf; the slack lets t = 0.09999999999999999 of tf = 0.1 count as 10%.
      fmt::print(stderr, "{}\n", line(t, step, dt, particles, fraction));
      next_fraction_ = (std::floor(fraction * 10.0 * (1.0 + 1e-9)) + 1.0) / 10.0;
    }
    std::fflush(stderr);
  }

  // The scene's metrics at the latest output, shown at the end of the line.
  void set_metrics(std::string text) { metrics_ = std::move(text); }

  // Ends an in-place line, before anything else is printed.
  void break_line() {
    if (shown_ > 0) fmt::print(stderr, "\n");
    shown_ = 0;
  }

 private:
  std::string line(double t, long step, double dt, std::size_t particles, double fraction) const {
    // Enough decimals to show four significant digits of tf.
    const int decimals = std::clamp(3 - static_cast<int>(std::floor(std::log10(tf_))), 4, 12);
    std::string eta = "?";
    if (fraction > 0) {
      const long s = std::lround(seconds_since(start_) * (1.0 - fraction) / fraction);
      eta = s >= 3600 ? fmt::format("{}h{:02}m", s / 3600, s / 60 % 60)
                      : fmt::format("{}m{:02}s", s / 60, s % 60);
    }
    return fmt::format("t={:.{}f}/{:.{}f}  step {}  dt={:.2g}  particles {}  {:.1f}% ETA {}", t,
                       decimals, tf_, decimals, step, dt, particles, 100.0 * fraction, eta) +
           (metrics_.empty() ? "" : "  " + metrics_);
  }

  bool enabled_ = false;
  bool tty_ = false;
  double tf_ = 1.0;
  Clock::time_point start_;
  Clock::time_point last_print_;
  double next_fraction_ = 0.1;
  std::size_t shown_ = 0;  // length of the in-place line on screen, 0 if none
  std::string metrics_;    // set_metrics
};

// ---------------------------------------------------------------------------------------------
// Output files.

class OutputWriter {
 public:
  OutputWriter(const SceneProgram& prog, std::string directory, bool enabled)
      : prog_(prog), scene_(scene_name(prog)), dir_(std::move(directory)), enabled_(enabled) {
    if (enabled_) std::filesystem::create_directories(dir_);
  }

  bool enabled() const { return enabled_; }
  const std::string& newest() const { return newest_; }
  // --restartable: every property of every array, whatever the scene's output selection.
  void write_all_properties() { all_properties_ = true; }
  // A restarted run: its index starts with the files of the run up to the restart step
  // (SCENE_NNNNNN.h5 in the output directory, NNNNNN <= step), where they are there.
  void continue_series(long step) {
    if (!enabled_ || prog_.rank > 0 || !std::filesystem::is_directory(dir_)) return;
    std::vector<std::pair<long, std::string>> files;
    const std::string prefix = scene_ + "_";
    for (const auto& entry : std::filesystem::directory_iterator(dir_)) {
      const std::string name = entry.path().filename().string();
      if (name.size() != prefix.size() + 9 || name.rfind(prefix, 0) != 0 ||
          name.substr(name.size() - 3) != ".h5")
        continue;
      const std::string digits = name.substr(prefix.size(), 6);
      if (digits.find_first_not_of("0123456789") != std::string::npos) continue;
      const long k = std::stol(digits);
      if (k <= step) files.emplace_back(k, name);
    }
    std::sort(files.begin(), files.end());
    for (const auto& [k, name] : files) series_.push_back(read_xdmf_entry_hdf5(in_dir(name), name));
  }

  void write(const std::vector<ParticleArray*>& arrays, const OutputMeta& meta) {
    if (!enabled_) return;
    const std::string file = fmt::format("{}_{:06d}.h5", scene_, meta.step);
    const std::vector<OutputArray> selection = selected(arrays);
    if (prog_.write_particles) {  // every rank writes its part (sphc/mpi/output.h)
      series_.push_back(prog_.write_particles(in_dir(file), file, selection, meta));
    } else {
      write_particles_hdf5(in_dir(file), selection, meta);
      series_.push_back(make_xdmf_entry(file, meta.t, selection));
    }
    if (prog_.rank <= 0) write_xdmf(in_dir(scene_ + ".xdmf"), series_, prog_.dim);
    newest_ = in_dir(file);
  }

  // Every property of every array, for inspection; not indexed by the XDMF file.
  std::string write_blowup(const std::vector<ParticleArray*>& arrays, const OutputMeta& meta) {
    // A distributed run: each rank that stops writes its own particles.
    const std::string path =
        in_dir(prog_.rank > 0 ? fmt::format("{}_blowup_rank{}.h5", scene_, prog_.rank)
                              : scene_ + "_blowup.h5");
    std::vector<OutputArray> all;
    for (const ParticleArray* a : arrays) all.push_back(OutputArray{a, {}});
    write_particles_hdf5(path, all, meta);
    return path;
  }

 private:
  std::string in_dir(const std::string& file) const {
    return (std::filesystem::path(dir_) / file).string();
  }

  std::vector<OutputArray> selected(const std::vector<ParticleArray*>& arrays) const {
    std::vector<OutputArray> out;
    if (prog_.output.empty() || all_properties_) {
      for (const ParticleArray* a : arrays) out.push_back(OutputArray{a, {}});
      return out;
    }
    for (const auto& [name, props] : prog_.output) {
      auto it = std::find_if(arrays.begin(), arrays.end(),
                             [&](const ParticleArray* a) { return a->name == name; });
      if (it == arrays.end()) {
        throw std::runtime_error(fmt::format("the output names array '{}', which the scene '{}' "
                                             "does not have", name, scene_));
      }
      out.push_back(OutputArray{*it, props});
    }
    return out;
  }

  const SceneProgram& prog_;
  std::string scene_;
  std::string dir_;
  bool enabled_;
  std::vector<XdmfEntry> series_;
  std::string newest_;
  bool all_properties_ = false;
};

// Requested times: the outputs (multiples of output_every, the output_at times) and tf.
// Steps land on them (docs/language.md, "Output times"):
// - A step from t whose nominal length dt (fixed, or this step's adaptive one) would pass a
//   requested time is shortened to end exactly on it; a requested time at most
//   kMergeFraction * dt beyond t + dt is reached by lengthening the step instead, so no step
//   shorter than that fraction of dt is left behind. The same holds for tf.
// - Requested times closer together than kMergeFraction * dt are written once, at the later.
// - Several output_at times within one step each get their own (shortened) step, as in
//   PySPH; multiples of an output_every shorter than dt do not shorten steps to that
//   interval: the step ends on the last multiple it reaches, and one snapshot is written.
// PySPH (solver.py) shortens the step to an output_at time or to tf with a slack of round-off
// only (2 machine epsilon * tf * steps); sphc's slack is kMergeFraction of the step instead,
// so that a near miss (tf = 1 with dt = 0.3333) does not leave a step of 1e-4 dt.
constexpr double kMergeFraction = 1e-3;

class OutputSchedule {
 public:
  OutputSchedule(const SceneTimes& times, double slack)
      : every_(times.output_every), at_(times.output_at), tf_(times.tf), slack_(slack),
        nearest_(times.output_nearest_step) {
    std::sort(at_.begin(), at_.end());
    // t = 0 is always written; requested times too close to it to take a step are written
    // with it (nearest_step: those nearer to 0 than to the end of the first step).
    reached(0.0, nearest_ ? 0.5 * times.dt : kMergeFraction * times.dt);
  }

  // True if t reached output times not reached before (within tol, by default the
  // round-off slack: steps end exactly on the times they land on). With nearest_step, `dt`
  // is the step just taken, the estimate of the next one: a time T is due at the step end
  // t nearest to it, t >= T - dt/2 (a time halfway between two ends goes to the earlier).
  bool due(double t, double dt) {
    return reached(t, nearest_ ? 0.5 * dt + slack_ : slack_);
  }

  // nearest_step: the run ends at the step end nearest to tf: not with one more step of dt
  // from t when t is at least as near to tf as t + dt would be (within the slack).
  bool ends_before_step(double t, double dt) const {
    return nearest_ && t >= tf_ - 0.5 * dt - slack_;
  }

  // The step from t whose nominal length is dt: it ends at t + dt, or exactly on the
  // requested time it lands on (landed).
  struct Step {
    double length;
    double end;
    bool landed;
  };
  Step plan(double t, double dt) const {
    if (nearest_) return {dt, t + dt, false};  // steps keep their length
    const double merge = kMergeFraction * dt;
    double end = first_target(t, t + dt, t + dt + merge);
    if (!(end < std::numeric_limits<double>::infinity())) return {dt, t + dt, false};
    // Requested times within `merge` after the one landed on are reached in the same step.
    // (Multiples of an output interval shorter than that are not: one output per step.)
    for (int k = 0; k < 64; ++k) {
      const double later = first_target(end, end + merge, end + merge, every_ > merge);
      if (!(later < std::numeric_limits<double>::infinity())) break;
      end = later;
    }
    // A requested time within rounding of t + dt (a multiple of a fixed dt, reached by
    // summing dt) is landed on with the step's own length: dt is not perturbed by a rounding.
    const double rounding =
        16 * std::numeric_limits<double>::epsilon() * std::max(std::fabs(t), std::fabs(end));
    return {std::fabs(end - (t + dt)) <= rounding ? dt : end - t, end, true};
  }

 private:
  bool reached(double t, double tol) {
    bool reached = false;
    if (every_ > 0 && static_cast<double>(next_k_) * every_ <= t + tol) {
      // Jump to the first multiple beyond t at once: a step may pass very many output times
      // (--output-every far below dt), and counting them one by one would not end.
      reached = true;
      const double k = std::floor((t + tol) / every_);
      next_k_ = std::max(next_k_, static_cast<long>(std::min(k, 9.0e18))) + 1;
      while (static_cast<double>(next_k_ - 1) * every_ > t + tol) --next_k_;  // rounding
      while (static_cast<double>(next_k_) * every_ <= t + tol) ++next_k_;      // rounding
    }
    while (next_at_ < at_.size() && at_[next_at_] <= t + tol) {
      reached = true;
      ++next_at_;
    }
    return reached;
  }

  // The earliest requested time after t that a step ending at `nominal` (lengthened up to
  // `reach`) lands on, or infinity if it lands on none. Only times not written yet count.
  double first_target(double t, double nominal, double reach, bool with_every = true) const {
    double end = std::numeric_limits<double>::infinity();
    const double after = t + slack_;
    if (tf_ > after && tf_ <= reach) end = std::min(end, tf_);
    const auto it = std::upper_bound(at_.begin() + static_cast<long>(next_at_), at_.end(), after);
    if (it != at_.end() && *it <= reach) end = std::min(end, *it);
    if (every_ > 0 && with_every) {
      // The last multiple the nominal step reaches, else the first one within reach.
      const double first = std::max(static_cast<double>(next_k_), std::floor(after / every_) + 1);
      const double last = std::floor(nominal / every_);
      double m = std::numeric_limits<double>::infinity();
      if (last >= first) {
        m = last * every_;
      } else if (first * every_ <= reach) {
        m = first * every_;
      }
      if (m > after) end = std::min(end, m);
    }
    return end;
  }

  double every_;
  std::vector<double> at_;
  double tf_;
  double slack_;
  bool nearest_ = false;
  long next_k_ = 1;
  std::size_t next_at_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Blow-up diagnosis.

// What the blow-up message says of the first non-finite value (sphc::find_non_finite of
// particle_array.h, parallel in the OpenMP runtime).
std::string describe(const std::vector<ParticleArray*>& arrays, const NonFiniteValue& bad) {
  const ParticleArray& a = *arrays[bad.array];
  const Property& prop = a.props[bad.prop];
  const std::size_t stride = static_cast<std::size_t>(std::max(prop.stride, 1));
  const std::string component =
      stride > 1 ? fmt::format("component {} of ", bad.index % stride) : std::string();
  return fmt::format("{}property '{}' of particle {} in array '{}' is {}", component, prop.name,
                     bad.index / stride, a.name, prop.f64[bad.index]);
}

// ---------------------------------------------------------------------------------------------
// The run.

class Simulation {
 public:
  Simulation(SceneProgram& prog, const Options& opt, Progress& progress)
      : prog_(prog), opt_(opt), progress_(progress) {}

  int run() {
    if (!prog_.setup || !prog_.step) {
      throw std::runtime_error("the scene program has no setup or no step function");
    }
    threads_ = prog_.set_threads ? prog_.set_threads(static_cast<int>(opt_.threads)) : 1;
    if (!check_memory()) return opt_.estimate_memory ? kExitOk : kExitError;
    SceneTimes times;
    phase_ = "setting up the arrays";
    prog_.setup(parameter_values(), times);
    phase_.clear();
    apply_overrides(times);
    check_fixed_dt(times);
    arrays_ = prog_.arrays ? prog_.arrays() : std::vector<ParticleArray*>{};
    set_up_limits();
    set_up_removals();
    const std::string dir =
        opt_.directory.empty() ? scene_name(prog_) + "_output" : opt_.directory;
    // Distributed: rank 0 writes, or every rank with collective output (write_particles).
    OutputWriter writer(prog_, dir,
                        !opt_.no_output && (prog_.rank <= 0 || prog_.write_particles != nullptr));
    writer_ = &writer;
    if (opt_.restartable) writer.write_all_properties();
    if (!opt_.restart.empty()) writer.continue_series(read_meta_hdf5(opt_.restart).step);
    open_metrics(dir);
    open_removed(dir);

    const double tf = times.tf;
    const double slack = kTimeSlack * tf;
    OutputSchedule schedule(times, slack);
    dt_ = times.dt;
    if (!opt_.restart.empty()) {
      restart(schedule);  // the state at the end of the step that wrote the file
    } else {
      // As PySPH: the equations run once before the first output, so the t = 0 snapshot
      // holds computed quantities (pressures, summation densities) and not zeros.
      if (prog_.compute_initial) prog_.compute_initial(t_, dt_);
      if (auto bad = check_finite()) return blow_up("simulation blew up", *bad);
      if (auto bad = remove_and_check_limits()) return blow_up(kLeftLimits, *bad);
      write_output();
    }

    const long check_every = prog_.to_host ? kCheckEveryDevice : kCheckEvery;
    const auto loop_start = Clock::now();
    first_step_ = step_;
    metrics_clock_ = {loop_start, cpu_seconds()};
    nnps_start_ = prog_.neighbour_seconds ? prog_.neighbour_seconds() : 0.0;
    io_start_ = prog_.inlet_outlet_seconds ? prog_.inlet_outlet_seconds() : 0.0;
    launches_start_ = prog_.device_launches ? prog_.device_launches() : 0;
    if (prog_.group_seconds) group_start_ = prog_.group_seconds();
    progress_.start(!opt_.quiet && prog_.rank <= 0, tf);
    double particle_steps = 0;
    while (t_ < tf - slack && step_ < opt_.max_steps) {
      double dt = times.dt;
      if (prog_.adaptive_dt) {
        dt = prog_.adaptive_dt();
        if (!std::isfinite(dt) || dt < kMinDtFraction * tf) return time_step_failure(dt, tf);
      }
      if (schedule.ends_before_step(t_, dt)) break;  // nearest_step: t_ is nearest to tf
      const OutputSchedule::Step planned = schedule.plan(t_, dt);  // lands on outputs and tf
      const auto step_start = Clock::now();
      prog_.step(t_, planned.length);
      step_seconds_ += std::chrono::duration<double>(Clock::now() - step_start).count();
      ++step_;
      dt_ = planned.length;
      advance_time(planned, times.dt);
      particle_steps += static_cast<double>(particles());

      const bool output_due = schedule.due(t_, planned.length);
      if (output_due || step_ % check_every == 0) {
        if (auto bad = check_finite()) return blow_up("simulation blew up", *bad);
        if (auto bad = remove_and_check_limits()) return blow_up(kLeftLimits, *bad);
      }
      if (output_due) write_output();
      progress_.update(t_, step_, dt_, particles());
    }
    if (last_output_step_ != step_) {
      if (auto bad = check_finite()) return blow_up("simulation blew up", *bad);
      if (auto bad = remove_and_check_limits()) return blow_up(kLeftLimits, *bad);
      write_output();
    }
    report_limits();
    report_removals();
    report(seconds_since(loop_start), particle_steps, tf);
    report_metrics();
    return kExitOk;
  }

 private:
  // The memory the run needs, before the set-up allocates it (sphc/memory.h): the set-up runs
  // once counting particles, not making them. False: stop here (the estimate was printed, or
  // the run does not fit, said on stderr).
  bool check_memory() {
    if (!prog_.arrays) return !opt_.estimate_memory;
    std::vector<ArrayFootprint> arrays;
    {
      CountingPass pass;
      SceneTimes unused;
      prog_.setup(parameter_values(), unused);
      for (const ParticleArray* a : prog_.arrays())
        arrays.push_back(footprint(*a, pass.planned(*a)));
    }
    const MemoryEstimate e = estimate_memory(arrays, prog_.precision == "single");
    estimate_ = e.total;
    const std::optional<double> available =
        opt_.max_memory ? opt_.max_memory : available_memory();
    const std::string limit =
        !available ? std::string("unknown")
        : opt_.max_memory ? fmt::format("{} (--max-memory)", format_bytes(*available))
                          : fmt::format("{} available (MemAvailable of /proc/meminfo or the "
                                        "cgroup's limit; --max-memory SIZE sets another)",
                                        format_bytes(*available));
    if (opt_.estimate_memory) {
      fmt::print("memory: {} needed, limit {}\n", format_bytes(e.total), limit);
      for (const MemoryItem& i : e.items)
        fmt::print("  {:>9}  {}\n", format_bytes(i.bytes), i.what);
      return false;
    }
    if (!available || e.total <= *available) return true;
    fmt::print(stderr,
               "error: the run needs about {} of memory, more than the limit of {}: {}; use "
               "fewer particles (a larger dx or a smaller domain)\n",
               format_bytes(e.total), limit, e.describe());
    return false;
  }

  std::vector<double> parameter_values() const {
    std::vector<double> values;
    for (const ParamInfo& p : prog_.params) values.push_back(p.value);
    for (const auto& [name, value] : opt_.sets) {
      for (std::size_t k = 0; k < prog_.params.size(); ++k) {
        if (prog_.params[k].name == name) values[k] = value;
      }
    }
    return values;
  }

  void apply_overrides(SceneTimes& times) const {
    if (opt_.tf) times.tf = *opt_.tf;
    if (opt_.dt) times.dt = *opt_.dt;
    if (opt_.output_every) {
      times.output_every = *opt_.output_every;
      times.output_at.clear();
    }
    if (opt_.output_nearest_step) times.output_nearest_step = *opt_.output_nearest_step;
    auto require = [](bool ok, const char* what, double value) {
      if (!ok) {
        throw std::runtime_error(
            fmt::format("the scene's {} is {} (check the parameters)", what, value));
      }
    };
    require(std::isfinite(times.tf) && times.tf >= 0, "final time tf", times.tf);
    require(std::isfinite(times.dt) && times.dt > 0, "time step dt", times.dt);
    require(std::isfinite(times.output_every) && times.output_every >= 0,
            "output interval", times.output_every);
  }

  // A fixed step (no adaptive_dt) above the stable bound the scene states (SceneTimes::
  // dt_bound, with the actual parameters and --dt): said before the first step, once.
  void check_fixed_dt(const SceneTimes& times) const {
    if (prog_.adaptive_dt || prog_.rank > 0 || !(times.dt > times.dt_bound * (1.0 + 1e-9)))
      return;
    fmt::print(stderr,
               "warning: the fixed time step dt = {:.4g} is {:.3g} times the stable bound "
               "{:.4g} of the {}: expect the run to blow up; take a smaller --dt (or build "
               "the scene with adaptive_dt)\n",
               times.dt, times.dt / times.dt_bound, times.dt_bound, times.dt_bound_term);
  }

  // Brings device data to the host (device backends) and looks for NaN or Inf in it: the
  // blow-up message's description of the first one found, or nullopt.
  std::optional<std::string> check_finite() {
    if (prog_.to_host) prog_.to_host();
    const auto bad = find_non_finite(arrays_);
    if (!bad) return std::nullopt;
    return describe(arrays_, *bad);
  }

  std::size_t particles() const {
    std::size_t n = 0;
    for (const ParticleArray* a : arrays_) n += a->n;
    return n;
  }

  OutputMeta meta() const {
    OutputMeta m{t_, step_, dt_, prog_.dim, scene_name(prog_), {}};
    // The run state a restart needs (restart.h): the time loop's, then the scene's.
    m.state = {{"landed_t", landed_t_}, {"landed_step", static_cast<double>(landed_step_)}};
    if (prog_.run_state)
      for (auto& kv : prog_.run_state()) m.state.push_back(std::move(kv));
    return m;
  }

  // --restart FILE: the particles, constants, time, step and run state of the file (each rank
  // of a distributed run reads its block), then the output times up to t marked as written,
  // as the run that wrote the file had them after that step. No t = 0 evaluation, no output
  // of the restart state (the file is it).
  void restart(OutputSchedule& schedule) {
    const std::size_t parts = static_cast<std::size_t>(std::max(prog_.ranks, 1));
    const std::size_t part = static_cast<std::size_t>(std::max(prog_.rank, 0));
    phase_ = "reading the restart file";
    const OutputMeta m = read_restart(opt_.restart, arrays_, scene_name(prog_), prog_.dim, part,
                                      parts);
    t_ = m.t;
    dt_ = m.dt;
    step_ = m.step;
    landed_t_ = state_value(m.state, "landed_t");
    landed_step_ = static_cast<long>(state_value(m.state, "landed_step"));
    prog_.restore(m.state);
    phase_.clear();
    schedule.due(t_, dt_);
    last_output_step_ = step_;
  }

  // t after a step: the requested time it landed on, exactly; else, with a fixed dt, the
  // last landing plus steps * dt (so rounding errors do not accumulate), with an adaptive dt
  // t + dt.
  void advance_time(const OutputSchedule::Step& planned, double fixed_dt) {
    if (planned.landed) {
      t_ = planned.end;
      landed_t_ = t_;
      landed_step_ = step_;
    } else if (prog_.adaptive_dt) {
      t_ += planned.length;
    } else {
      t_ = landed_t_ + static_cast<double>(step_ - landed_step_) * fixed_dt;
    }
  }

  void write_output() {
    if (prog_.before_output) prog_.before_output();
    writer_->write(prog_.output_arrays ? prog_.output_arrays() : arrays_, meta());
    last_output_step_ = step_;
    // A restart file: the state it cannot carry starts afresh, as in a run restarted from it.
    if (opt_.restartable && prog_.restart_point) prog_.restart_point();
    record_metrics();
  }

  // -------------------------------------------------------------------------------------------
  // Metrics (sphc/metrics.h): evaluated with every output (the data is on the host then), one
  // CSV row each, shown on the progress line and at the end.

  void open_metrics(const std::string& dir) {
    if (prog_.metrics.empty() || !prog_.evaluate_metrics) return;
    std::string path = opt_.metrics_file;
    if (path.empty() && !opt_.no_output)
      path = (std::filesystem::path(dir) / (scene_name(prog_) + "_metrics.csv")).string();
    if (path.empty() || prog_.rank > 0) return;  // a distributed run: rank 0 writes it
    // A restart continues the file: the rows up to the restart step are kept (a run that went
    // on past it wrote rows the restarted run writes again).
    std::vector<std::string> kept;
    if (!opt_.restart.empty()) kept = metrics_rows_until(path, read_meta_hdf5(opt_.restart).step);
    metrics_csv_.open(path, std::ios::trunc);
    if (!metrics_csv_) throw std::runtime_error("cannot write the metrics to '" + path + "'");
    metrics_csv_ << metrics_csv_header(prog_.metrics) << "\n";
    for (const std::string& row : kept) metrics_csv_ << row << "\n";
    metrics_csv_ << std::flush;
  }

  // The rows of an existing metrics CSV (of this scene's header) whose step is at most `step`.
  std::vector<std::string> metrics_rows_until(const std::string& path, long step) const {
    std::vector<std::string> rows;
    std::ifstream in(path);
    std::string line;
    if (!in || !std::getline(in, line) || line != metrics_csv_header(prog_.metrics)) return rows;
    while (std::getline(in, line)) {
      char* end = nullptr;
      const long row_step = std::strtol(line.c_str(), &end, 10);
      if (end != line.c_str() && *end == ',' && row_step <= step) rows.push_back(line);
    }
    return rows;
  }

  void record_metrics() {
    if (prog_.metrics.empty() || !prog_.evaluate_metrics) return;
    MetricsRow row;
    row.step = step_;
    row.t = t_;
    row.dt = dt_;
    if (metrics_clock_) {  // 0 before the time loop starts (the first output)
      row.wall_s = seconds_since(metrics_clock_->first);
      row.cpu_s = cpu_seconds() - metrics_clock_->second;
    }
    row.values = prog_.evaluate_metrics(t_);
    progress_.set_metrics(metrics_text(prog_.metrics, row.values));
    if (metrics_csv_.is_open()) metrics_csv_ << metrics_csv_row(prog_.metrics, row) << "\n" << std::flush;
    last_metrics_ = std::move(row);
  }

  void report_metrics() {
    if (!last_metrics_) return;
    const MetricsRow& r = *last_metrics_;
    if (!opt_.quiet && prog_.rank <= 0)
      fmt::print(stderr, "metrics at t={}: {}\n", r.t, metrics_text(prog_.metrics, r.values));
    if (opt_.timing) {
      fmt::print("metrics: t={} step={} wall_s={:.6g} cpu_s={:.6g} {}\n", r.t, r.step, r.wall_s,
                 r.cpu_s, metrics_text(prog_.metrics, r.values, true));
      std::fflush(stdout);
    }
  }

  std::optional<std::pair<Clock::time_point, double>> metrics_clock_;  // wall, CPU at the loop start
  std::ofstream metrics_csv_;
  std::optional<MetricsRow> last_metrics_;

  // -------------------------------------------------------------------------------------------
  // Limits (sphc/sanity.h): kept apart from the time loop, which only calls check_limits
  // where it checks for non-finite values, and report_limits at the end.

  static constexpr const char* kLeftLimits = "simulation left its limits";

  struct Watched {
    Limit limit;
    const ParticleArray* array = nullptr;
    bool warned = false;
    long checks_outside = 0;       // checks that found a particle outside the warn bound
    double worst_excess = 0;
    std::string worst;             // that particle, and when
  };

  // The scene's limits, a default box for every array without a declared limit on a
  // position, then the command line's --limit settings.
  void set_up_limits() {
    if (opt_.limits == "off") return;
    std::vector<Limit> limits = prog_.limits ? prog_.limits() : std::vector<Limit>{};
    for (const Limit& box : prog_.default_limits ? prog_.default_limits()
                                                  : bounding_box_limits(arrays_, prog_.dim)) {
      const bool declared = std::any_of(limits.begin(), limits.end(), [&](const Limit& l) {
        return l.array == box.array && l.quantity == box.quantity;
      });
      if (!declared) limits.push_back(box);
    }
    for (const std::string& s : opt_.limit_settings) apply_limit_setting(limits, s);
    if (opt_.limits == "warn")
      for (Limit& l : limits) l.stop.reset();
    std::string names;
    for (const ParticleArray* a : arrays_) names += (names.empty() ? "" : ", ") + a->name;
    for (const Limit& l : limits) {
      auto it = std::find_if(arrays_.begin(), arrays_.end(),
                             [&](const ParticleArray* a) { return a->name == l.array; });
      if (it == arrays_.end())
        throw std::runtime_error(fmt::format("limit '{}'{}: the scene has no array '{}' (its "
                                             "arrays: {})", l.name(),
                                             l.where.empty() ? "" : " (" + l.where + ")",
                                             l.array, names));
      if (!l.warn && !l.stop) continue;
      check_limit(l, **it, prog_.dim);  // throws if the quantity does not exist
      watched_.push_back(Watched{l, *it});
    }
  }

  // -------------------------------------------------------------------------------------------
  // Removal (a limit's `remove`, sphc/sanity.h): at every check, before the bounds are
  // checked, the particles outside a remove bound (where its condition holds) are taken out
  // of the host arrays (ParticleArray::remove_particles: a stable compaction, so the others
  // keep their order), counted, and written with their last state to DIR/SCENE_removed.csv
  // (as DualSPHysics' excluded particles); prog.after_removal moves the array back where the
  // scene computes. Serial and in particle order: every thread count removes the same.

  struct Removing {
    Limit limit;
    ParticleArray* array = nullptr;
    std::size_t removed = 0;      // particles so far
    double mass = 0.0;            // their mass (NaN: the array has no m)
    double mass_at_start = 0.0;   // the array's at the start
    double first_t = 0.0, last_t = 0.0;
    std::string last;             // the last particle removed: its position and t
  };
  std::vector<Removing> removing_;
  std::ofstream removed_csv_;

  static constexpr const char* kRemovedHeader =
      "step,t,limit,array,index,gid,x,y,z,u,v,w,m,rho";
  static constexpr const char* kRemovedValues[8] = {"x", "y", "z", "u", "v", "w", "m", "rho"};

  void set_up_removals() {
    if (!prog_.limits) return;
    for (const Limit& l : prog_.limits()) {
      if (!l.remove) continue;
      auto it = std::find_if(arrays_.begin(), arrays_.end(),
                             [&](const ParticleArray* a) { return a->name == l.array; });
      if (it == arrays_.end())
        throw std::runtime_error(fmt::format("limit '{}' ({}): the scene has no array '{}'",
                                             l.name(), l.where, l.array));
      removal_mask(l, **it, prog_.dim);  // throws if a quantity does not exist
      Removing r{l, *it};
      const int m = (*it)->find("m");
      r.mass = m >= 0 && (*it)->props[m].type == PropType::F64 ? 0.0 : std::nan("");
      if (m >= 0 && (*it)->props[m].type == PropType::F64)
        for (std::size_t i = 0; i < (*it)->n; ++i) r.mass_at_start += (*it)->f64(m)[i];
      if (prog_.sum_over_ranks) r.mass_at_start = prog_.sum_over_ranks(r.mass_at_start);
      removing_.push_back(std::move(r));
    }
  }

  // DIR/SCENE_removed.csv: one row per removed particle. A restart keeps the rows up to its
  // step and counts them again.
  void open_removed(const std::string& dir) {
    if (removing_.empty() || opt_.no_output || prog_.rank > 0) return;
    const std::string path =
        (std::filesystem::path(dir) / (scene_name(prog_) + "_removed.csv")).string();
    std::vector<std::string> kept;
    if (!opt_.restart.empty()) {
      const long step = read_meta_hdf5(opt_.restart).step;
      std::ifstream in(path);
      std::string line;
      if (in && std::getline(in, line) && line == kRemovedHeader)
        while (std::getline(in, line)) {
          char* end = nullptr;
          const long row_step = std::strtol(line.c_str(), &end, 10);
          if (end == line.c_str() || *end != ',' || row_step > step) continue;
          kept.push_back(line);
          // step,t,limit,array,index,gid,x,y,z,u,v,w,m,rho: count it for its limit.
          std::vector<std::string> f;
          for (std::size_t a = 0, b; a <= line.size(); a = b + 1) {
            b = line.find(',', a);
            if (b == std::string::npos) b = line.size();
            f.push_back(line.substr(a, b - a));
          }
          if (f.size() < 14) continue;
          for (Removing& r : removing_)
            if (r.limit.name() == f[2]) {
              if (r.removed++ == 0) r.first_t = std::strtod(f[1].c_str(), nullptr);
              r.last_t = std::strtod(f[1].c_str(), nullptr);
              r.mass += std::strtod(f[12].c_str(), nullptr);
            }
        }
    }
    removed_csv_.open(path, std::ios::trunc);
    if (!removed_csv_) throw std::runtime_error("cannot write the removed particles to '" + path + "'");
    removed_csv_ << kRemovedHeader << "\n";
    for (const std::string& row : kept) removed_csv_ << row << "\n";
    removed_csv_ << std::flush;
  }

  // The particles `mask` of `a` with the CSV's columns: index (in `a`), gid (where `a` has
  // global ids) and the positions, velocities (up to dim), m and rho that `a` has.
  ParticleArray removed_rows(const ParticleArray& a, const std::vector<std::uint8_t>& mask) const {
    ParticleArray g;
    g.name = a.name;
    std::vector<std::pair<int, int>> from;  // (a's property, g's)
    from.push_back({-1, g.add_property("index", PropType::U32)});
    const int gid = a.find("gid");
    if (gid >= 0 && a.props[gid].type == PropType::U32)
      from.push_back({gid, g.add_property("gid", PropType::U32)});
    for (int k = 0; k < 8; ++k) {
      const int p = k % 3 < prog_.dim || k >= 6 ? a.find(kRemovedValues[k]) : -1;
      if (p >= 0 && a.props[p].type == PropType::F64 && a.props[p].stride == 1)
        from.push_back({p, g.add_property(kRemovedValues[k])});
    }
    std::size_t count = 0;
    for (std::uint8_t m : mask) count += m != 0;
    g.resize(count);
    for (std::size_t i = 0, j = 0; i < mask.size(); ++i) {
      if (!mask[i]) continue;
      g.u32(from[0].second)[j] = static_cast<std::uint32_t>(i);
      for (std::size_t c = 1; c < from.size(); ++c) copy_particle_values(g.props[from[c].second], j, a.props[from[c].first], i);
      ++j;
    }
    return g;
  }

  // Takes the particles past each remove bound out of their array, and logs them (rank 0):
  // in gid order where the array has global ids (--global-ids, --mpi), else in particle order.
  // A distributed run removes each rank's own and gathers them to rank 0 (gather_removed,
  // collective: every rank at every check).
  void remove_particles() {
    for (Removing& r : removing_) {
      ParticleArray& a = *r.array;
      const std::vector<std::uint8_t> mask = removal_mask(r.limit, a, prog_.dim);
      if (mask.empty() && !prog_.gather_removed) continue;
      ParticleArray gone = removed_rows(a, mask);
      if (!mask.empty()) {
        a.remove_particles(mask);
        if (prog_.after_removal) prog_.after_removal(a);
      }
      if (prog_.gather_removed) {
        prog_.gather_removed(a, mask, gone);
      } else if (const int g = gone.find("gid"); g >= 0) {
        std::vector<std::uint32_t> order(gone.n);
        for (std::uint32_t j = 0; j < order.size(); ++j) order[j] = j;
        const std::uint32_t* id = gone.u32(g);
        std::stable_sort(order.begin(), order.end(),
                         [&](std::uint32_t x, std::uint32_t y) { return id[x] < id[y]; });
        gone.permute(order);
      }
      if (gone.n == 0 || prog_.rank > 0) continue;
      log_removal(r, gone);
    }
  }

  // The removed particles `gone` (removed_rows) of one check: the CSV's rows, the counts and
  // the log line.
  void log_removal(Removing& r, const ParticleArray& gone) {
    const int gid = gone.find("gid"), index = gone.find("index");
    const double* col[8];
    for (int k = 0; k < 8; ++k) {
      const int p = gone.find(kRemovedValues[k]);
      col[k] = p >= 0 ? gone.f64(p) : nullptr;
    }
    double mass = 0.0;
    std::string positions;
    for (std::size_t i = 0; i < gone.n; ++i) {
      std::string pos;
      for (int k = 0; k < prog_.dim && k < 3; ++k)
        pos += fmt::format("{}{:.6g}", k ? ", " : "", col[k] ? col[k][i] : 0.0);
      if (i < 4) positions += fmt::format("{}({})", i ? ", " : "", pos);
      if (col[6]) mass += col[6][i];
      r.last = fmt::format("({}) at t={}", pos, t_);
      if (!removed_csv_.is_open()) continue;
      removed_csv_ << fmt::format("{},{:.17g},{},{},{},{}", step_, t_, r.limit.name(),
                                  gone.name, gone.props[index].u32[i],
                                  gid >= 0 ? std::to_string(gone.props[gid].u32[i]) : std::string());
      for (int k = 0; k < 8; ++k)
        removed_csv_ << "," << (col[k] ? fmt::format("{:.17g}", col[k][i]) : std::string());
      removed_csv_ << "\n";
    }
    if (removed_csv_.is_open()) removed_csv_ << std::flush;
    const std::size_t count = gone.n;
    if (r.removed == 0) r.first_t = t_;
    r.last_t = t_;
    r.removed += count;
    r.mass += mass;
    progress_.break_line();
    const std::string from = r.limit.where.empty() ? "" : " (" + r.limit.where + ")";
    fmt::print(stderr,
               "removed at t={}, step {}: {} particle{} of array '{}' {} (limit '{}'{}){}: "
               "{}{}; {} removed so far{}\n",
               t_, step_, count, count == 1 ? "" : "s", gone.name, r.limit.remove_text(),
               r.limit.name(), from, col[6] ? fmt::format(", mass {:.6g}", mass) : "", "at ",
               positions + (count > 4 ? ", ..." : ""), r.removed,
               col[6] ? fmt::format(" (mass {:.6g})", r.mass) : "");
  }

  // At the end of a run: what each remove bound took out.
  void report_removals() {
    if (prog_.rank > 0) return;
    for (const Removing& r : removing_) {
      if (r.removed == 0) continue;
      progress_.break_line();
      const std::string from = r.limit.where.empty() ? "" : " (" + r.limit.where + ")";
      const std::string mass =
          std::isnan(r.mass) ? ""
                             : fmt::format(", mass {:.6g} ({:.3g}% of the array's at the start)",
                                           r.mass, r.mass_at_start > 0
                                                       ? 100.0 * r.mass / r.mass_at_start
                                                       : 0.0);
      fmt::print(stderr,
                 "removed: {} particle{} of array '{}' {} (limit '{}'{}){}, from t={} to "
                 "t={}; the last at {}\n",
                 r.removed, r.removed == 1 ? "" : "s", r.array->name, r.limit.remove_text(),
                 r.limit.name(), from, mass, r.first_t, r.last_t, r.last);
    }
  }

  // The removals, then the limits (on host data: call after check_finite).
  std::optional<std::string> remove_and_check_limits() {
    remove_particles();
    return check_limits();
  }

  // Checks the limits (on host data: call after check_finite) and the iterated groups.
  // Warns once per limit (and per group); the stop message of the first limit past its stop
  // bound, or nullopt.
  std::optional<std::string> check_limits() {
    check_iterations();
    for (Watched& w : watched_) {
      const LimitCheck c = check_limit(w.limit, *w.array, prog_.dim);
      const std::string from = w.limit.where.empty() ? "" : " (" + w.limit.where + ")";
      const std::string particle =
          describe_particle(*w.array, c.worst, prog_.dim, w.limit.quantity, c.value);
      if (c.outside_stop > 0) {
        return fmt::format("limit '{}'{}: {} particle{} outside the stop bound {}; the worst: {}",
                           w.limit.name(), from, c.outside_stop, c.outside_stop == 1 ? "" : "s",
                           w.limit.stop->text(), particle);
      }
      if (c.outside_warn == 0) continue;
      ++w.checks_outside;
      if (c.excess > w.worst_excess) {
        w.worst_excess = c.excess;
        w.worst = fmt::format("{} at t={}", particle, t_);
      }
      if (w.warned) continue;
      w.warned = true;
      if (!first_warning_) first_warning_ = {t_, writer_->newest()};
      progress_.break_line();
      fmt::print(stderr,
                 "warning: at t={}, step {}: limit '{}'{}: {} particle{} outside the warn bound "
                 "{}{}; the worst: {} (warned once per limit)\n",
                 t_, step_, w.limit.name(), from, c.outside_warn, c.outside_warn == 1 ? "" : "s",
                 w.limit.warn->text(),
                 w.limit.stop ? "; the run stops outside " + w.limit.stop->text() : "", particle);
    }
    return std::nullopt;
  }

  // An iterated group whose evaluation stopped at max_iterations: warned once per group.
  void check_iterations() {
    if (!prog_.iterations) return;
    const std::vector<IterationStats> stats = prog_.iterations();
    unconverged_warned_.resize(stats.size(), false);
    for (std::size_t k = 0; k < stats.size(); ++k) {
      if (stats[k].unconverged == 0 || unconverged_warned_[k]) continue;
      unconverged_warned_[k] = true;
      if (!first_warning_) first_warning_ = {t_, writer_->newest()};
      progress_.break_line();
      fmt::print(stderr,
                 "warning: at t={}, step {}: the iterated group at {} stopped at its "
                 "max_iterations without converging ({} of {} evaluations so far; warned once "
                 "per group, counted at the end)\n",
                 t_, step_, stats[k].where, stats[k].unconverged, stats[k].evaluations);
    }
  }

  // At the end of a run: how often each limit was exceeded, and unconverged groups.
  void report_limits() {
    progress_.break_line();
    for (const Watched& w : watched_) {
      if (w.checks_outside == 0) continue;
      fmt::print(stderr, "warning: limit '{}' outside its warn bound {} at {} check{}; the "
                         "furthest: {}\n",
                 w.limit.name(), w.limit.warn->text(), w.checks_outside,
                 w.checks_outside == 1 ? "" : "s", w.worst);
    }
    if (!prog_.iterations) return;
    for (const IterationStats& s : prog_.iterations()) {
      if (s.unconverged == 0) continue;
      fmt::print(stderr, "warning: the iterated group at {} did not converge in {} of {} "
                         "evaluations\n",
                 s.where, s.unconverged, s.evaluations);
    }
  }

  int time_step_failure(double dt, double tf) {
    // A non-finite property usually explains a bad time step: name it if there is one.
    if (auto bad = check_finite()) return blow_up("simulation blew up", *bad);
    if (!std::isfinite(dt) || dt <= 0) {
      return blow_up("simulation blew up", fmt::format("the adaptive time step is {}", dt));
    }
    return blow_up("time step collapsed",
                   fmt::format("the adaptive time step {} is below {} * tf = {}", dt,
                               kMinDtFraction, kMinDtFraction * tf));
  }

  int blow_up(const std::string& headline, const std::string& detail) {
    progress_.break_line();
    fmt::print(stderr, "error: {} at t={}, step {} (dt={}): {}\n", headline, t_, step_, dt_,
               detail);
    if (writer_->enabled()) {
      try {
        const std::string path = writer_->write_blowup(arrays_, meta());
        fmt::print(stderr, "note: the bad state is in '{}'; the last good output is '{}'\n", path,
                   writer_->newest());
        if (first_warning_)
          fmt::print(stderr, "note: the first warning was at t={}; the last output before it is "
                             "'{}'\n", first_warning_->first, first_warning_->second);
      } catch (const std::exception& e) {
        fmt::print(stderr, "note: could not write the bad state: {}\n", e.what());
      }
    }
    return kExitBlowUp;
  }

  void report(double wall_s, double particle_steps, double tf) {
    const double us = particle_steps > 0 ? wall_s * 1e6 / particle_steps : 0.0;
    progress_.break_line();
    if (!opt_.quiet && prog_.rank <= 0) {
      const char* why = step_ >= opt_.max_steps && t_ < tf ? " (--max-steps reached)" : "";
      fmt::print(stderr, "done: t={} after {} steps{}, {:.3g} s, {:.3g} us/particle/step\n", t_,
                 step_, why, wall_s, us);
    }
    if (opt_.timing) {
      // nnps_s: the part of wall_s spent in the neighbour search (when the scene measures
      // it), nnps_share = nnps_s / wall_s.
      std::string nnps;
      if (prog_.neighbour_seconds) {
        const double s = prog_.neighbour_seconds() - nnps_start_;
        nnps = fmt::format(" nnps_s={:.6g} nnps_share={:.4f}", s, wall_s > 0 ? s / wall_s : 0.0);
      }
      if (prog_.inlet_outlet_seconds) {
        const double s = prog_.inlet_outlet_seconds() - io_start_;
        nnps += fmt::format(" io_s={:.6g} io_share={:.4f}", s, wall_s > 0 ? s / wall_s : 0.0);
      }
      // Device backends: kernel launches per time step (the time loop's, over its steps).
      if (prog_.device_launches && step_ > first_step_)
        nnps += fmt::format(" launches_per_step={:.4g}",
                            static_cast<double>(prog_.device_launches() - launches_start_) /
                                static_cast<double>(step_ - first_step_));
      if (prog_.iterations) {
        long total = 0;
        for (const IterationStats& s : prog_.iterations()) total += s.total;
        nnps += fmt::format(" iterations={}", total);
      }
      // OpenMP: the barrier wait policy in force (choose_omp_wait).
      std::string wait;
      if (prog_.set_threads) {
        const char* w = std::getenv("OMP_WAIT_POLICY");
        wait = std::string(" omp_wait=") + (w ? w : std::getenv("GOMP_SPINCOUNT") ? "spincount"
                                                                                 : "default");
      }
      fmt::print("timing: steps={} particles={} wall_s={:.6g} us_per_particle_step={:.6g} "
                 "backend={} threads={}{} precision={}{}{}\n",
                 step_, particles(), wall_s, us, prog_.backend, threads_, wait, prog_.precision,
                 nnps, prog_.rank >= 0 ? fmt::format(" rank={}", prog_.rank) : "");
      if (prog_.group_seconds) report_groups(wall_s);
      // Counted from the first evaluation, the one before the first step, included.
      if (prog_.iterations) {
        for (const IterationStats& s : prog_.iterations()) {
          fmt::print("iterations: group={} evaluations={} total={} mean={:.4g} min={} max={} "
                     "unconverged={}\n",
                     s.where, s.evaluations, s.total,
                     s.evaluations ? static_cast<double>(s.total) / s.evaluations : 0.0, s.min,
                     s.max, s.unconverged);
        }
      }
      std::fflush(stdout);
    }
  }

  // --timing, serial and OpenMP: the time loop's wall time by part. One line per top-level
  // group of the equations (all its evaluations in the time loop) and per post_step group
  // (marked when=post_step), then the split of wall_s: groups_s (their sum), nnps_s (the
  // neighbour search), integrator_s (the rest of the time steps: steppers, periodic wraps,
  // ghosts, inlets/outlets) and
  // outside_steps_s (output, blow-up and limit checks, metrics, progress); the four add up
  // to wall_s.
  void report_groups(double wall_s) {
    const std::vector<GroupSeconds> now = prog_.group_seconds();
    double groups = 0.0;
    for (std::size_t k = 0; k < now.size(); ++k) {
      const double s = now[k].seconds - (k < group_start_.size() ? group_start_[k].seconds : 0.0);
      groups += s;
      fmt::print("timing-group: name={} s={:.6g} share={:.4f} equations={}{}\n", now[k].name, s,
                 wall_s > 0 ? s / wall_s : 0.0, now[k].equations,
                 now[k].post_step ? " when=post_step" : "");
    }
    const double nnps = prog_.neighbour_seconds ? prog_.neighbour_seconds() - nnps_start_ : 0.0;
    fmt::print("timing-split: wall_s={:.6g} groups_s={:.6g} nnps_s={:.6g} integrator_s={:.6g} "
               "outside_steps_s={:.6g}\n",
               wall_s, groups, nnps, step_seconds_ - groups - nnps, wall_s - step_seconds_);
  }

  SceneProgram& prog_;
  const Options& opt_;
  Progress& progress_;
  int threads_ = 1;
  double nnps_start_ = 0.0;  // neighbour_seconds() when the time loop started
  long launches_start_ = 0;  // device_launches() when the time loop started
  long first_step_ = 0;      // step_ when the time loop started (a restart's step)
  double io_start_ = 0.0;    // inlet_outlet_seconds() then
  std::vector<GroupSeconds> group_start_;  // group_seconds() then
  double step_seconds_ = 0.0;  // wall seconds in prog_.step within the time loop
  OutputWriter* writer_ = nullptr;
  std::vector<ParticleArray*> arrays_;
  double t_ = 0.0;
  double dt_ = 0.0;
  long step_ = 0;
  long last_output_step_ = -1;
  double landed_t_ = 0.0;  // the last requested time a step landed on (advance_time)
  long landed_step_ = 0;
  std::vector<Watched> watched_;
  std::vector<bool> unconverged_warned_;
  std::optional<std::pair<double, std::string>> first_warning_;  // t, the output before it

 public:
  // For the out-of-memory message: what the run was doing, and its estimate.
  std::string where() const {
    return phase_.empty() ? fmt::format("at t={}, step {}", t_, step_) : "while " + phase_;
  }
  double estimate_ = 0;  // bytes (check_memory)

 private:
  std::string phase_;
};

std::string out_of_memory_hint(double estimate) {
  const std::optional<double> available = available_memory();
  return fmt::format(
      "an allocation failed (std::bad_alloc); {}{}; use fewer particles (a larger dx or a "
      "smaller domain)",
      estimate > 0 ? "the estimate before the start was " + format_bytes(estimate) : "",
      available ? fmt::format("{}{} is available now", estimate > 0 ? ", " : "",
                              format_bytes(*available))
                : "");
}

// std::terminate's handler: an exception no one caught (one thrown inside an OpenMP parallel
// region ends the program there) gets a message, not a bare "terminate called".
[[noreturn]] void report_uncaught() {
  std::fflush(stdout);
  if (std::exception_ptr e = std::current_exception()) {
    try {
      std::rethrow_exception(e);
    } catch (const std::bad_alloc&) {
      std::fprintf(stderr, "\nerror: out of memory: %s\n", out_of_memory_hint(0).c_str());
    } catch (const std::exception& x) {
      std::fprintf(stderr, "\nerror: %s\n", x.what());
    } catch (...) {
      std::fprintf(stderr, "\nerror: an unknown exception\n");
    }
  } else {
    std::fprintf(stderr, "\nerror: std::terminate was called\n");
  }
  std::fflush(stderr);
  std::_Exit(kExitError);
}

}  // namespace

bool wants_passive_wait(double load1, long others, long threads, long cores) {
  if (cores < 1) return false;
  return load1 >= static_cast<double>(cores) && (others < 0 ? 0 : others) + threads > cores;
}

void choose_omp_wait(int argc, char** argv) {
  std::string want = "auto";
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--omp-wait") want = argv[i + 1];
  const char* policy = nullptr;
  if (want == "passive" || want == "active") {
    policy = want == "passive" ? "passive" : "active";
  } else if (want == "auto") {
    if (std::getenv("OMP_WAIT_POLICY") || std::getenv("GOMP_SPINCOUNT")) return;
    // /proc/loadavg: "load1 load5 load15 runnable/total lastpid"; runnable counts this
    // process.
    double load = 0.0, load5 = 0.0, load15 = 0.0;
    long runnable = 0, total = 0;
    if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {
      if (std::fscanf(f, "%lf %lf %lf %ld/%ld", &load, &load5, &load15, &runnable, &total) != 5)
        load = 0.0;
      std::fclose(f);
    }
    const long cores = sysconf(_SC_NPROCESSORS_ONLN);
    long threads = cores;
    for (int i = 1; i + 1 < argc; ++i)
      if (std::string(argv[i]) == "--threads") threads = std::atol(argv[i + 1]);
    if (!wants_passive_wait(load, runnable - 1, threads > 0 ? threads : cores, cores)) return;
    policy = "passive";
  } else {
    return;  // run_main reports the bad value
  }
  const char* now = std::getenv("OMP_WAIT_POLICY");
  if (now && std::string(now) == policy) return;  // already so (this is the re-executed run)
  if (setenv("OMP_WAIT_POLICY", policy, 1) != 0) return;
  execv("/proc/self/exe", argv);  // returns only on failure: go on as we are
}

void add_params(std::vector<ParamInfo>& to, std::initializer_list<ParamSpec> specs) {
  for (const ParamSpec& s : specs) to.push_back({s.name, s.value, s.help});
}

void add_options(std::vector<OptionInfo>& to, std::initializer_list<OptionSpec> specs) {
  for (const OptionSpec& s : specs) to.push_back({s.name, s.value, s.choices});
}

void add_effect_params(std::vector<EffectParamInfo>& to,
                       std::initializer_list<EffectParamSpec> specs) {
  for (const EffectParamSpec& s : specs) to.push_back({s.name, s.effect, s.command});
}

int run_main(int argc, char** argv, SceneProgram& prog) {
  Options opt;
  try {
    opt = parse_command_line(argc, argv, prog);
  } catch (const UsageError& e) {
    fmt::print(stderr, "error: {}\nrun '{} --help' for the options\n", e.what(),
               program_name(argc, argv, prog));
    return kExitUsage;
  }
  if (opt.help) {
    print_help(program_name(argc, argv, prog), prog);
    return kExitOk;
  }
  Progress progress;
  std::set_terminate(report_uncaught);
  std::optional<Simulation> sim;
  try {
    sim.emplace(prog, opt, progress);
    return sim->run();
  } catch (const std::bad_alloc&) {
    progress.break_line();
    fmt::print(stderr, "error: out of memory {}: {}\n", sim ? sim->where() : "at the start",
               out_of_memory_hint(sim ? sim->estimate_ : 0));
    return kExitError;
  } catch (const std::exception& e) {
    progress.break_line();
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitError;
  }
}

}  // namespace sphc
