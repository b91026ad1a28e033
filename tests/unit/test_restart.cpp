// Restart input (runtime/src/restart.cpp, the block and run-state reading of hdf5_io.cpp):
// the file's particles into a solver's arrays, in blocks per rank, and what it refuses.
#include "sphc/restart.h"

#include <gtest/gtest.h>

#include "scratch_dir.h"

#include <filesystem>
#include <stdexcept>
#include <string>

namespace fs = std::filesystem;
using namespace sphc;

namespace {

fs::path fresh_dir() { return fresh_test_dir("tmp_io"); }

// 7 particles: x = i, a 3-component tensor, an int and the gid; a constant.
ParticleArray make_array(std::size_t n = 7) {
  ParticleArray a;
  a.name = "fluid";
  a.n = n;
  a.add_property("x");
  a.add_property("y");
  a.add_property("tau", PropType::F64, 3);
  a.add_property("tag", PropType::I32);
  a.add_property("gid", PropType::U32);
  for (std::size_t i = 0; i < n; ++i) {
    a.props[0].f64[i] = static_cast<double>(i) + 1.0 / 3.0;
    a.props[1].f64[i] = -static_cast<double>(i);
    for (int k = 0; k < 3; ++k) a.props[2].f64[3 * i + k] = 10.0 * i + k + 0.1;
    a.props[3].i32[i] = -static_cast<int>(i);
    a.props[4].u32[i] = 100 + static_cast<unsigned>(i);
  }
  a.add_constant("total", 2, 0.0);
  a.constant("total")[1] = 0.7;
  return a;
}

std::string write(const fs::path& dir, const ParticleArray& a, const std::string& scene = "s") {
  const std::string path = (dir / "s_000005.h5").string();
  OutputMeta meta{0.25, 5, 1e-3, 2, scene, {{"landed_t", 0.2}, {"builds", 11}}};
  write_particles_hdf5(path, {OutputArray{&a, {}}}, meta);
  return path;
}

// The solver's array after its set-up: other particles, the same properties.
ParticleArray solver_array() { return make_array(3); }

}  // namespace

TEST(Restart, RunStateRoundTripsAsRootAttributesInOrder) {
  const ParticleArray a = make_array();
  const OutputMeta m = read_meta_hdf5(write(fresh_dir(), a));
  EXPECT_EQ(m.t, 0.25);
  EXPECT_EQ(m.step, 5);
  EXPECT_EQ(m.dt, 1e-3);
  EXPECT_EQ(m.dim, 2);
  EXPECT_EQ(m.scene, "s");
  ASSERT_EQ(m.state.size(), 2u);
  EXPECT_EQ(m.state[0], (std::pair<std::string, double>{"landed_t", 0.2}));
  EXPECT_EQ(m.state[1], (std::pair<std::string, double>{"builds", 11}));
  EXPECT_EQ(state_value(m.state, "builds"), 11);
  EXPECT_EQ(state_value(m.state, "missing", -1.0), -1.0);
  EXPECT_THROW(state_value(m.state, "missing"), std::runtime_error);
}

TEST(Restart, TakesEveryPropertyAndConstantOfTheFile) {
  const ParticleArray a = make_array();
  const std::string path = write(fresh_dir(), a);
  ParticleArray s = solver_array();
  const OutputMeta m = read_restart(path, {&s}, "s", 2);
  EXPECT_EQ(m.step, 5);
  ASSERT_EQ(s.n, a.n);
  for (std::size_t k = 0; k < a.props.size(); ++k) {
    EXPECT_EQ(s.props[k].f64, a.props[k].f64) << a.props[k].name;
    EXPECT_EQ(s.props[k].i32, a.props[k].i32) << a.props[k].name;
    EXPECT_EQ(s.props[k].u32, a.props[k].u32) << a.props[k].name;
  }
  EXPECT_EQ(s.constants[0].values, a.constants[0].values);
}

// Each rank of a distributed restart reads one block; the blocks tile the file in order.
TEST(Restart, BlocksPerRankTileTheArray) {
  const ParticleArray a = make_array();
  const std::string path = write(fresh_dir(), a);
  for (std::size_t parts : {1u, 2u, 3u, 4u, 9u}) {
    std::vector<double> x, tau;
    std::vector<unsigned> gid;
    for (std::size_t part = 0; part < parts; ++part) {
      ParticleArray s = solver_array();
      read_restart(path, {&s}, "s", 2, part, parts);
      EXPECT_EQ(s.n, a.n * (part + 1) / parts - a.n * part / parts);
      x.insert(x.end(), s.props[0].f64.begin(), s.props[0].f64.end());
      tau.insert(tau.end(), s.props[2].f64.begin(), s.props[2].f64.end());
      gid.insert(gid.end(), s.props[4].u32.begin(), s.props[4].u32.end());
      EXPECT_EQ(s.constants[0].values, a.constants[0].values);  // whole on every rank
    }
    EXPECT_EQ(x, a.props[0].f64) << parts << " parts";
    EXPECT_EQ(tau, a.props[2].f64) << parts << " parts";
    EXPECT_EQ(gid, a.props[4].u32) << parts << " parts";
  }
}

TEST(Restart, RefusesWhatDoesNotFit) {
  const fs::path dir = fresh_dir();
  const ParticleArray a = make_array();
  const std::string path = write(dir, a);
  auto message = [&](ParticleArray s, const std::string& scene = "s", int dim = 2) {
    try {
      read_restart(path, {&s}, scene, dim);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(solver_array(), "other").find("written by scene 's', not 'other'"),
            std::string::npos);
  EXPECT_NE(message(solver_array(), "s", 3).find("is 2D, the scene 3D"), std::string::npos);
  ParticleArray more = solver_array();
  more.add_property("rho");
  EXPECT_NE(message(more).find("array 'fluid' has no property 'rho'; a restart needs every "
                               "property: write the outputs with --restartable"),
            std::string::npos);
  ParticleArray fewer = solver_array();
  fewer.props.erase(fewer.props.begin() + 3);  // tag
  EXPECT_NE(message(fewer).find("has a property 'tag' this solver's array does not have"),
            std::string::npos);
  ParticleArray typed = make_array(3);
  typed.props[3].type = PropType::F64;
  EXPECT_NE(message(typed).find("property 'tag' of array 'fluid' is int with 1 component(s), the solver's is double"), std::string::npos)
      << message(typed);
  ParticleArray constant = solver_array();
  constant.add_constant("other");
  EXPECT_NE(message(constant).find("has no constant 'other'"), std::string::npos);
  // A file without run state (written by an output without it, or another tool).
  const std::string bare = (dir / "bare.h5").string();
  write_particles_hdf5(bare, {OutputArray{&a, {}}}, OutputMeta{0.25, 5, 1e-3, 2, "s"});
  ParticleArray s = solver_array();
  EXPECT_THROW(read_restart(bare, {&s}, "s", 2), std::runtime_error);
}
