// The run loop and command line of generated solvers (runtime/src/solver.cpp), driven with a
// tiny synthetic scene: particles moving at constant speed, x += u * dt.
#include "sphc/solver.h"

#include <gtest/gtest.h>

#include "scratch_dir.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "sphc/hdf5_io.h"

namespace fs = std::filesystem;
using namespace sphc;

namespace {

fs::path fresh_dir() { return fresh_test_dir("tmp_solver"); }

// The scene "mover": params u (speed) and tf; dt = 0.01, output every 0.25.
struct Mover {
  ParticleArray fluid;
  std::vector<double> seen_params;
  long steps = 0;
  double last_t_plus_dt = 0;
  std::vector<double> step_t, step_dt;  // t and dt of every step
  SceneProgram prog;

  Mover() {
    prog.name = "mover";
    prog.dim = 2;
    prog.params = {{"u", 1.0, "speed"}, {"tf", 1.0, "final time"}};
    prog.setup = [this](const std::vector<double>& params, SceneTimes& times) {
      seen_params = params;
      fluid.name = "fluid";
      fluid.n = 4;
      for (const char* p : {"x", "y", "z", "u", "rho"}) fluid.add_property(p);
      for (std::size_t i = 0; i < fluid.n; ++i) {
        fluid.f64("x")[i] = static_cast<double>(i);
        fluid.f64("u")[i] = params[0];
      }
      times.tf = params[1];
      times.dt = 0.01;
      times.output_every = 0.25;
    };
    prog.arrays = [this] { return std::vector<ParticleArray*>{&fluid}; };
    prog.step = [this](double t, double dt) {
      double* x = fluid.f64("x");
      const double* u = fluid.f64("u");
      for (std::size_t i = 0; i < fluid.n; ++i) x[i] += u[i] * dt;
      ++steps;
      last_t_plus_dt = t + dt;
      step_t.push_back(t);
      step_dt.push_back(dt);
    };
    prog.output = {{"fluid", {"u"}}};
  }

  // Output at the given times only (no output interval), as a scene's `output at`.
  void output_only_at(std::vector<double> at) {
    const auto setup = prog.setup;
    prog.setup = [setup, at](const std::vector<double>& params, SceneTimes& times) {
      setup(params, times);
      times.output_every = 0;
      times.output_at = at;
    };
  }
};

int run(SceneProgram& prog, std::vector<std::string> args) {
  args.insert(args.begin(), "mover");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  return run_main(static_cast<int>(args.size()), argv.data(), prog);
}

// Runs with stderr captured into `err`.
int run_capturing(SceneProgram& prog, std::vector<std::string> args, std::string& err) {
  ::testing::internal::CaptureStderr();
  const int code = run(prog, std::move(args));
  err = ::testing::internal::GetCapturedStderr();
  return code;
}

std::vector<std::string> h5_files(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ".h5") names.push_back(e.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

double output_time(const fs::path& file) {
  // The time of an output is visible through its particles: x = i + u t with u = 1.
  const ParticleArray a = read_particles_hdf5(file.string(), "fluid");
  return a.f64("x")[0];
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST(Solver, RunsToTheFinalTimeWithPeriodicOutputs) {
  const fs::path dir = fresh_dir();
  Mover m;
  EXPECT_EQ(run(m.prog, {"--quiet", "-d", dir.string()}), 0);
  EXPECT_EQ(m.steps, 100);
  EXPECT_EQ(h5_files(dir), (std::vector<std::string>{"mover_000000.h5", "mover_000025.h5",
                                                     "mover_000050.h5", "mover_000075.h5",
                                                     "mover_000100.h5"}));
  const double expected[] = {0, 0.25, 0.5, 0.75, 1.0};
  const auto files = h5_files(dir);
  for (std::size_t k = 0; k < files.size(); ++k) EXPECT_NEAR(output_time(dir / files[k]), expected[k], 1e-12);
  EXPECT_TRUE(fs::exists(dir / "mover.xdmf"));
  // Written: x, y, z and the requested u only.
  EXPECT_EQ(read_particles_hdf5((dir / files[0]).string(), "fluid").props.size(), 4u);
}

TEST(Solver, LastStepIsClippedToEndExactlyAtTf) {
  const fs::path dir = fresh_dir();
  Mover m;
  EXPECT_EQ(run(m.prog, {"--quiet", "-d", dir.string(), "--tf", "0.105", "--output-every", "0"}), 0);
  EXPECT_EQ(m.steps, 11);
  EXPECT_EQ(m.last_t_plus_dt, 0.105);
  EXPECT_EQ(h5_files(dir), (std::vector<std::string>{"mover_000000.h5", "mover_000011.h5"}));
  EXPECT_NEAR(output_time(dir / "mover_000011.h5"), 0.105, 1e-12);
}

TEST(Solver, StepsLandOnOutputAtTimes) {
  // dt = 0.01, output at 0.3 (a multiple of dt) and 0.305 (not): step 31 is shortened to
  // 0.005 so that its output is at t = 0.305, the steps after it are 0.01 again, and the last
  // one is shortened to end on tf = 1 (PySPH's rule, pysph/solver/solver.py).
  const fs::path dir = fresh_dir();
  Mover m;
  m.output_only_at({0.305, 0.3});
  EXPECT_EQ(run(m.prog, {"--quiet", "-d", dir.string()}), 0);
  EXPECT_EQ(h5_files(dir), (std::vector<std::string>{"mover_000000.h5", "mover_000030.h5",
                                                     "mover_000031.h5", "mover_000101.h5"}));
  ASSERT_EQ(m.steps, 101);
  EXPECT_EQ(m.step_t[30], 0.3);  // landed exactly (within rounding: here exact)
  EXPECT_NEAR(m.step_dt[30], 0.005, 1e-15);
  EXPECT_EQ(m.step_t[31], 0.305);
  EXPECT_EQ(m.step_dt[31], 0.01);
  EXPECT_NEAR(m.step_dt[100], 0.005, 1e-15);
  EXPECT_EQ(m.last_t_plus_dt, 1.0);
  EXPECT_NEAR(output_time(dir / "mover_000031.h5"), 0.305, 1e-12);
  EXPECT_NEAR(output_time(dir / "mover_000101.h5"), 1.0, 1e-12);
  // No step other than those two is shortened (the steps landing on 0.3 and 1.0, multiples
  // of dt, differ from 0.01 by a rounding).
  for (long k = 0; k < m.steps; ++k)
    if (k != 30 && k != 100) EXPECT_NEAR(m.step_dt[k], 0.01, 1e-15) << "step " << k;
}

TEST(Solver, NearMissesAreMergedNotTinySteps) {
  // tf 5e-4 dt beyond the 100th step's end (below kMergeFraction = 1e-3 of dt): the last step
  // is lengthened to 0.010005 instead of leaving a step of 5e-6. At 2e-3 dt beyond, a
  // shortened 101st step of 2e-5 is taken.
  {
    const fs::path dir = fresh_dir();
    Mover m;
    EXPECT_EQ(run(m.prog, {"--quiet", "-d", dir.string(), "--tf", "1.000005", "--output-every", "0"}), 0);
    EXPECT_EQ(m.steps, 100);
    EXPECT_NEAR(m.step_dt.back(), 0.010005, 1e-15);
    EXPECT_EQ(m.last_t_plus_dt, 1.000005);
  }
  {
    const fs::path dir = fresh_dir();
    Mover m;
    EXPECT_EQ(run(m.prog, {"--quiet", "-d", dir.string(), "--tf", "1.00002", "--output-every", "0"}), 0);
    EXPECT_EQ(m.steps, 101);
    EXPECT_NEAR(m.step_dt.back(), 2e-5, 1e-15);
    EXPECT_EQ(m.last_t_plus_dt, 1.00002);
  }
  // Two output times closer than 1e-3 dt: one snapshot, at the later, in one step.
  {
    const fs::path dir = fresh_dir();
    Mover m;
    m.output_only_at({0.5, 0.500001});
    EXPECT_EQ(run(m.prog, {"--quiet", "-d", dir.string()}), 0);
    // Then 49 steps of 0.01 and a last one of 0.009999 to tf.
    EXPECT_EQ(h5_files(dir), (std::vector<std::string>{"mover_000000.h5", "mover_000050.h5",
                                                       "mover_000100.h5"}));
    EXPECT_NEAR(m.step_dt[49], 0.010001, 1e-15);
    EXPECT_EQ(m.step_t[50], 0.500001);
    EXPECT_NEAR(output_time(dir / "mover_000050.h5"), 0.500001, 1e-12);
  }
}

TEST(Solver, AdaptiveStepsLandOnOutputTimes) {
  // An adaptive dt of 0.03 with outputs every 0.25: the steps reaching 0.25, 0.5, 0.75 and
  // 1.0 are shortened to end on them (0.25 = 8 * 0.03 + 0.01), each output at its time.
  const fs::path dir = fresh_dir();
  Mover m;
  m.prog.adaptive_dt = [] { return 0.03; };
  EXPECT_EQ(run(m.prog, {"--quiet", "-d", dir.string()}), 0);
  const auto files = h5_files(dir);
  ASSERT_EQ(files.size(), 5u);
  const double expected[] = {0, 0.25, 0.5, 0.75, 1.0};
  for (std::size_t k = 0; k < files.size(); ++k)
    EXPECT_NEAR(output_time(dir / files[k]), expected[k], 1e-12) << files[k];
  // Each quarter: 8 steps of 0.03 and one of 0.01.
  EXPECT_EQ(m.steps, 36);
  for (long k = 0; k < m.steps; ++k) {
    EXPECT_NEAR(m.step_dt[k], k % 9 == 8 ? 0.01 : 0.03, 1e-14) << "step " << k;
    if (k % 9 == 8) EXPECT_EQ(m.step_t[k] + m.step_dt[k], expected[k / 9 + 1]) << "step " << k;
  }
}

TEST(Solver, OutputIntervalBelowTheStepWritesOncePerStep) {
  // Output every 0.004 with dt = 0.01: each step ends on the last multiple of 0.004 it
  // reaches (0.008, 0.016, ..., 0.096), one snapshot per step, all at multiples of 0.004; the
  // last step, 0.004, ends on tf = 0.1.
  const fs::path dir = fresh_dir();
  Mover m;
  EXPECT_EQ(run(m.prog, {"--quiet", "-d", dir.string(), "--tf", "0.1", "--output-every", "0.004"}), 0);
  for (long k = 0; k < m.steps; ++k) {
    const double end = m.step_t[k] + m.step_dt[k];
    EXPECT_NEAR(end / 0.004, std::round(end / 0.004), 1e-9) << "step " << k;
    EXPECT_NEAR(m.step_dt[k], k + 1 < m.steps ? 0.008 : 0.004, 1e-15) << "step " << k;
  }
  EXPECT_EQ(m.steps, 13);
  EXPECT_EQ(static_cast<long>(h5_files(dir).size()), m.steps + 1);
  EXPECT_EQ(m.last_t_plus_dt, 0.1);
  // --output-every 1e-12 (every step): the steps stay 0.01 to within the interval (each ends
  // on a multiple of 1e-12, so differs from 0.01 by less than 1e-12 on each side: 2e-12).
  const fs::path dir2 = fresh_dir();
  Mover m2;
  EXPECT_EQ(run(m2.prog, {"--quiet", "-d", dir2.string(), "--tf", "0.1", "--output-every", "1e-12"}), 0);
  EXPECT_EQ(m2.steps, 10);
  for (long k = 0; k < m2.steps; ++k) EXPECT_NEAR(m2.step_dt[k], 0.01, 2e-12) << "step " << k;
  EXPECT_EQ(static_cast<long>(h5_files(dir2).size()), 11);
}

TEST(Solver, SetOverridesReachSetup) {
  const fs::path dir = fresh_dir();
  Mover m;
  EXPECT_EQ(run(m.prog, {"--quiet", "-d", dir.string(), "--set", "u=2", "--set=tf=0.5"}), 0);
  EXPECT_EQ(m.seen_params, (std::vector<double>{2.0, 0.5}));
  EXPECT_EQ(m.steps, 50);
  EXPECT_NEAR(m.fluid.f64("x")[3], 3.0 + 2.0 * 0.5, 1e-12);
}

TEST(Solver, BadUsageExitsWithCode2) {
  const fs::path dir = fresh_dir();
  Mover m;
  std::string err;
  EXPECT_EQ(run_capturing(m.prog, {"-d", dir.string(), "--set", "speed=2"}, err), 2);
  EXPECT_TRUE(contains(err, "speed")) << err;
  EXPECT_TRUE(contains(err, "u, tf")) << err;
  EXPECT_EQ(run_capturing(m.prog, {"--set", "u=fast"}, err), 2);
  EXPECT_TRUE(contains(err, "fast")) << err;
  EXPECT_EQ(run_capturing(m.prog, {"--dt", "0"}, err), 2);
  EXPECT_EQ(run_capturing(m.prog, {"--max-steps"}, err), 2);
  EXPECT_EQ(run_capturing(m.prog, {"--frobnicate"}, err), 2);
  EXPECT_TRUE(contains(err, "--frobnicate")) << err;
  EXPECT_EQ(m.steps, 0);
}

TEST(Solver, HelpListsOptionsAndParameters) {
  Mover m;
  ::testing::internal::CaptureStdout();
  EXPECT_EQ(run(m.prog, {"--help"}), 0);
  const std::string out = ::testing::internal::GetCapturedStdout();
  for (const char* part : {"--tf", "--dt", "--output-every", "--max-steps", "--directory",
                           "--set", "--quiet", "--no-output", "--timing", "u = 1", "speed",
                           "tf = 1", "final time"}) {
    EXPECT_TRUE(contains(out, part)) << part << " missing in:\n" << out;
  }
  EXPECT_EQ(m.steps, 0);
}

TEST(Solver, MaxStepsStopsEarlyAndWritesTheLastState) {
  const fs::path dir = fresh_dir();
  Mover m;
  EXPECT_EQ(run(m.prog, {"--quiet", "-d", dir.string(), "--max-steps", "7"}), 0);
  EXPECT_EQ(m.steps, 7);
  EXPECT_EQ(h5_files(dir), (std::vector<std::string>{"mover_000000.h5", "mover_000007.h5"}));
}

// --restartable (stop 43): prog.restart_point after each output is written (the step count
// then is the file's), the last one's included; never without --restartable.
TEST(Solver, RestartPointFollowsEachOutputOnlyWhenRestartable) {
  for (const bool restartable : {true, false}) {
    const fs::path dir = fresh_dir();
    Mover m;
    std::vector<long> at;  // the steps completed at each call
    m.prog.restart_point = [&] { at.push_back(m.steps); };
    std::vector<std::string> args = {"--quiet", "-d", dir.string(), "--max-steps", "60"};
    if (restartable) args.push_back("--restartable");
    EXPECT_EQ(run(m.prog, args), 0);
    EXPECT_EQ(h5_files(dir), (std::vector<std::string>{"mover_000000.h5", "mover_000025.h5",
                                                       "mover_000050.h5", "mover_000060.h5"}));
    EXPECT_EQ(at, restartable ? (std::vector<long>{0, 25, 50, 60}) : std::vector<long>{})
        << "restartable " << restartable;
  }
}

TEST(Solver, TimingLineAndNoOutput) {
  const fs::path dir = fresh_dir() / "never";
  Mover m;
  ::testing::internal::CaptureStdout();
  EXPECT_EQ(run(m.prog, {"--quiet", "--no-output", "--timing", "-d", dir.string()}), 0);
  const std::string out = ::testing::internal::GetCapturedStdout();
  EXPECT_TRUE(contains(out, "timing: steps=100 particles=4 wall_s=")) << out;
  EXPECT_TRUE(contains(out, " us_per_particle_step=")) << out;
  EXPECT_FALSE(fs::exists(dir));
}

TEST(Solver, NanBlowUpIsDiagnosedAndKeepsTheLastGoodOutput) {
  const fs::path dir = fresh_dir();
  Mover m;
  const auto step = m.prog.step;
  m.prog.step = [&](double t, double dt) {
    step(t, dt);
    if (m.steps == 37) m.fluid.f64("rho")[2] = std::nan("");
  };
  std::string err;
  EXPECT_EQ(run_capturing(m.prog, {"--quiet", "-d", dir.string()}, err), 3);
  EXPECT_EQ(m.steps, 40);  // found by the scan every 10 steps
  EXPECT_TRUE(contains(err, "error: simulation blew up at t=")) << err;
  EXPECT_TRUE(contains(err, "step 40")) << err;
  EXPECT_TRUE(contains(err, "property 'rho' of particle 2 in array 'fluid' is nan")) << err;
  EXPECT_EQ(h5_files(dir),
            (std::vector<std::string>{"mover_000000.h5", "mover_000025.h5", "mover_blowup.h5"}));
  EXPECT_TRUE(contains(err, "mover_blowup.h5")) << err;
  // The XDMF index lists the good outputs only.
  std::ifstream xdmf(dir / "mover.xdmf");
  const std::string text((std::istreambuf_iterator<char>(xdmf)), std::istreambuf_iterator<char>());
  EXPECT_TRUE(contains(text, "mover_000025.h5"));
  EXPECT_FALSE(contains(text, "blowup"));
}

TEST(Solver, CollapsingAdaptiveTimeStepIsDiagnosed) {
  const fs::path dir = fresh_dir();
  Mover m;
  double dt = 0.01;
  m.prog.adaptive_dt = [&] { return dt *= 0.1; };
  std::string err;
  EXPECT_EQ(run_capturing(m.prog, {"--quiet", "-d", dir.string()}, err), 3);
  EXPECT_TRUE(contains(err, "time step collapsed")) << err;

  Mover n;
  n.prog.adaptive_dt = [] { return std::numeric_limits<double>::quiet_NaN(); };
  EXPECT_EQ(run_capturing(n.prog, {"--quiet", "--no-output"}, err), 3);
  EXPECT_TRUE(contains(err, "adaptive time step is nan")) << err;
}

TEST(Solver, AdaptiveTimeStepEndsExactlyAtTf) {
  const fs::path dir = fresh_dir();
  Mover m;
  m.prog.adaptive_dt = [] { return 0.03; };
  EXPECT_EQ(run(m.prog, {"--quiet", "-d", dir.string(), "--output-every", "0"}), 0);
  EXPECT_EQ(m.steps, 34);
  EXPECT_EQ(m.last_t_plus_dt, 1.0);
}

TEST(Solver, ExceptionsFromTheSceneExitWithCode1) {
  Mover m;
  m.prog.step = [](double, double) { throw std::runtime_error("boom"); };
  std::string err;
  EXPECT_EQ(run_capturing(m.prog, {"--quiet", "--no-output"}, err), 1);
  EXPECT_TRUE(contains(err, "error: boom")) << err;
}

// --omp-wait auto: sleep at barriers only when the cores are oversubscribed now and have been
// loaded for the last minute (sphc/solver.h).
TEST(Solver, AutoWaitPolicySleepsOnlyOnAnOversubscribedMachine) {
  // Idle 2-core machine: spin.
  EXPECT_FALSE(sphc::wants_passive_wait(0.1, 0, 2, 2));
  // Sustained load and another process running now: sleep.
  EXPECT_TRUE(sphc::wants_passive_wait(10.0, 8, 2, 2));
  EXPECT_TRUE(sphc::wants_passive_wait(2.0, 1, 2, 2));
  // The load average still counts a run that has just ended, but nothing else runs now.
  EXPECT_FALSE(sphc::wants_passive_wait(2.2, 0, 2, 2));
  // Something runs now, but the machine was idle over the last minute.
  EXPECT_FALSE(sphc::wants_passive_wait(0.5, 1, 2, 2));
  // Enough cores for the others and this run's threads.
  EXPECT_FALSE(sphc::wants_passive_wait(16.0, 4, 8, 16));
  EXPECT_TRUE(sphc::wants_passive_wait(16.0, 12, 8, 16));
  // One thread and three others on 2 cores: oversubscribed too.
  EXPECT_TRUE(sphc::wants_passive_wait(4.0, 3, 1, 2));
  // No core count: leave libgomp alone.
  EXPECT_FALSE(sphc::wants_passive_wait(10.0, 8, 2, 0));
}
