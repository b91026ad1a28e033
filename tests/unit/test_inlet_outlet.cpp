// Unit tests of arrays that grow and shrink: ParticleArray::remove_particles, global ids
// (sphc/global_ids.h) and the inlet/outlet manager (sphc/inlet_outlet.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <utility>
#include <vector>
#include <stdexcept>
#include <string>

#include "sphc/global_ids.h"
#include "sphc/inlet_outlet.h"
#include "sphc/particle_array.h"
#include "sphc/restart.h"

namespace {

using sphc::ParticleArray;
using sphc::PropType;

ParticleArray make_array(const std::string& name, std::size_t n) {
  ParticleArray a;
  a.name = name;
  for (const char* p : {"x", "y", "u", "v", "m"}) a.add_property(p);
  a.add_property("tau", PropType::F64, 3);
  a.add_property("tag", PropType::I32);
  a.resize(n);
  return a;
}

// The channel of the inlet/outlet tests: a lattice of spacing dx (cell centres) over
// [x0, x1] x [0, 1] appended to a, every particle of mass 1, then `set(i, x, y)` for any
// other value of particle i at (x, y).
void fill_lattice(ParticleArray& a, double x0, double x1, double dx,
                  const std::function<void(std::size_t, double, double)>& set = {}) {
  for (double x = x0 + dx / 2; x < x1; x += dx)
    for (double y = dx / 2; y < 1.0; y += dx) {
      a.resize(a.n + 1);
      a.f64("x")[a.n - 1] = x;
      a.f64("y")[a.n - 1] = y;
      a.f64("m")[a.n - 1] = 1.0;
      if (set) set(a.n - 1, x, y);
    }
}

// The outlet zone of that channel: its face at x = 1 (normal +x) across the channel's width
// 1, 0.2 deep, filled by `from`'s particles that cross into it; a do-nothing outlet that
// copies every property both arrays have unless the test lists some.
sphc::OutletZone channel_outlet(ParticleArray& from, ParticleArray& outlet) {
  sphc::OutletZone out;
  out.zone.name = "outlet";
  out.zone.point[0] = 1.0;
  out.zone.point[1] = 0.5;
  out.zone.normal[0] = 1.0;
  out.zone.length = 0.2;
  out.zone.width = 1.0;
  out.outlet = &outlet;
  out.from = &from;
  return out;
}

TEST(RemoveParticles, CompactsStablyEveryPropertyAndStride) {
  ParticleArray a = make_array("fluid", 6);
  for (std::size_t i = 0; i < 6; ++i) {
    a.f64("x")[i] = static_cast<double>(i);
    for (int k = 0; k < 3; ++k) a.f64(a.find("tau"))[i * 3 + k] = 10.0 * i + k;
    a.i32(a.find("tag"))[i] = -static_cast<int>(i);
  }
  const std::size_t removed = a.remove_particles({1, 0, 0, 1, 0, 1});
  EXPECT_EQ(removed, 3u);
  ASSERT_EQ(a.n, 3u);
  const double want[3] = {1, 2, 4};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(a.f64("x")[i], want[i]);
    EXPECT_EQ(a.i32(a.find("tag"))[i], -static_cast<int>(want[i]));
    for (int k = 0; k < 3; ++k) EXPECT_EQ(a.f64(a.find("tau"))[i * 3 + k], 10.0 * want[i] + k);
  }
  for (const auto& p : a.props) {
    const std::size_t size = p.type == PropType::F64 ? p.f64.size() : p.i32.size();
    EXPECT_EQ(size, 3u * p.stride) << p.name;
  }
  EXPECT_EQ(a.remove_particles({0, 0, 0}), 0u);
  EXPECT_THROW(a.remove_particles({0, 1}), std::invalid_argument);
}

TEST(GlobalIds, UniqueOverArraysAndKeptThroughMoves) {
  ParticleArray a = make_array("fluid", 3), b = make_array("inlet", 2);
  sphc::GlobalIds ids;
  sphc::assign_global_ids({&a, &b}, ids);
  EXPECT_EQ(ids.next, 5u);
  const std::uint32_t* ga = a.u32(a.find("gid"));
  const std::uint32_t* gb = b.u32(b.find("gid"));
  EXPECT_EQ(ga[0], 0u);
  EXPECT_EQ(ga[2], 2u);
  EXPECT_EQ(gb[0], 3u);
  EXPECT_EQ(gb[1], 4u);
  // Moving a particle keeps its id; permuting keeps ids with their particles.
  sphc::CopyMap m = sphc::make_copy_map(a, b, {});
  sphc::append_particle(a, b, 1, m);
  EXPECT_EQ(a.u32(a.find("gid"))[3], 4u);
  a.permute({3, 2, 1, 0});
  EXPECT_EQ(a.u32(a.find("gid"))[0], 4u);
  EXPECT_EQ(a.u32(a.find("gid"))[3], 0u);
}

TEST(CopyMap, ListedPropertiesOnlyAndErrors) {
  ParticleArray a = make_array("fluid", 0), b = make_array("inlet", 1);
  b.f64("m")[0] = 2.0;
  b.f64("u")[0] = 3.0;
  sphc::CopyMap m = sphc::make_copy_map(a, b, {"m"});
  sphc::append_particle(a, b, 0, m);
  EXPECT_EQ(a.f64("m")[0], 2.0);
  EXPECT_EQ(a.f64("u")[0], 0.0);  // not listed
  try {
    sphc::make_copy_map(a, b, {"p"});
    ADD_FAILURE() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'p'"), std::string::npos) << e.what();
  }
}

TEST(Zone, ChecksWithNumbers) {
  sphc::Zone z;
  z.name = "inlet 'in'";
  z.length = 0.1;
  z.width = 1.0;
  EXPECT_THROW(sphc::check_zone(z, 0.05), std::invalid_argument);  // zero normal
  z.normal[0] = -2.0;
  sphc::check_zone(z, 0.05);
  EXPECT_DOUBLE_EQ(z.normal[0], -1.0);
  try {
    sphc::check_zone(z, 0.2);
    ADD_FAILURE() << "expected an error";
  } catch (const std::invalid_argument& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("inlet 'in'"), std::string::npos) << w;
    EXPECT_NE(w.find("0.1"), std::string::npos) << w;
    EXPECT_NE(w.find("0.2"), std::string::npos) << w;
  }
  const double in[3] = {-0.05, 0.4, 0}, out[3] = {-0.05, 0.6, 0};
  EXPECT_DOUBLE_EQ(z.depth(in), 0.05);
  EXPECT_TRUE(z.across(in));
  EXPECT_FALSE(z.across(out));
}

// A 1 x 1 channel along x with uniform flow u = 1: an inlet zone [-0.2, 0] (normal -x), an
// outlet zone [1, 1.2] (normal +x), particles on a lattice of dx = 0.1 moved by hand
// (x += u dt) as a stepper would. Mass in = mass out once the channel has flushed, the
// counts stay bounded, ids stay unique, and every particle ever made has a distinct id.
TEST(InletOutlet, UniformFlowThroughAChannel) {
  const double dx = 0.1, dt = 0.025;
  ParticleArray fluid = make_array("fluid", 0), inlet = make_array("inlet", 0),
                outlet = make_array("outlet", 0);
  fill_lattice(fluid, 0.0, 1.0, dx);
  fill_lattice(inlet, -0.2, 0.0, dx);
  sphc::InletOutlet io;
  sphc::InletZone in;
  in.zone.name = "inlet";
  in.zone.normal[0] = -1.0;
  in.zone.length = 0.2;
  in.zone.width = 1.0;
  in.zone.point[1] = 0.5;
  in.inlet = &inlet;
  in.feeds = &fluid;
  in.copy = {"x", "y", "u", "v", "m"};
  in.velocity = [](const double*, double, double* v) { v[0] = 1.0; };
  io.inlets.push_back(in);
  io.outlets.push_back(channel_outlet(fluid, outlet));
  sphc::init_inlet_outlet(io, {&fluid, &inlet, &outlet}, 0.15, 0.0);
  EXPECT_EQ(fluid.n, 100u);
  EXPECT_EQ(inlet.f64("u")[0], 1.0);

  auto move = [&](ParticleArray& a) {
    for (std::size_t i = 0; i < a.n; ++i) a.f64("x")[i] += dt * a.f64("u")[i];
  };
  // The fluid moves with u = 1 too (its particles got it from the inlet; the first ones by hand).
  for (std::size_t i = 0; i < fluid.n; ++i) fluid.f64("u")[i] = 1.0;
  std::set<std::uint32_t> seen;
  const int steps = 200;  // t = 5: five channel lengths
  for (int s = 1; s <= steps; ++s) {
    move(fluid);
    move(inlet);
    move(outlet);
    const bool due = sphc::inlet_outlet_due(io);
    EXPECT_EQ(sphc::update_inlet_outlet(io, s * dt), due);
    EXPECT_EQ(inlet.n, 20u);
    EXPECT_LE(fluid.n, 110u);
    EXPECT_LE(outlet.n, 30u);
    std::set<std::uint32_t> now;
    for (ParticleArray* a : {&fluid, &inlet, &outlet}) {
      const std::uint32_t* g = a->u32(a->find("gid"));
      for (std::size_t i = 0; i < a->n; ++i) {
        EXPECT_TRUE(now.insert(g[i]).second) << "duplicate gid " << g[i];
        seen.insert(g[i]);
      }
    }
  }
  // 5 time units at u = 1 through a face of width 1 with 10 particles per 0.1 of length:
  // 500 particles in, and out of the fluid after the first 100 left.
  EXPECT_EQ(io.inlets[0].created, 500u);
  EXPECT_EQ(io.outlets[0].entered, 500u);
  EXPECT_EQ(io.outlets[0].returned, 0u);
  EXPECT_EQ(fluid.n, 100u);
  EXPECT_EQ(io.outlets[0].removed, 500u - outlet.n);
  EXPECT_EQ(seen.size(), 120u + 500u);  // every id seen once, none reused
  EXPECT_EQ(io.ids.next, 120u + 500u);  // initial ids, then one per recycled inlet particle
  // Positions of the fluid: still the lattice (nothing lost or doubled).
  double xs = 0.0;
  for (std::size_t i = 0; i < fluid.n; ++i) xs += fluid.f64("x")[i];
  EXPECT_NEAR(xs / fluid.n, 0.5, 0.05);
}

TEST(InletOutlet, BackflowReturnsToTheSource) {
  ParticleArray fluid = make_array("fluid", 1), outlet = make_array("outlet", 1);
  fluid.f64("x")[0] = 0.95;
  outlet.f64("x")[0] = 1.05;
  fluid.f64("y")[0] = outlet.f64("y")[0] = 0.5;  // mid-channel
  sphc::InletOutlet io;
  io.outlets.push_back(channel_outlet(fluid, outlet));
  sphc::init_inlet_outlet(io, {&fluid, &outlet}, 0.1, 0.0);
  EXPECT_FALSE(sphc::inlet_outlet_due(io));
  EXPECT_FALSE(sphc::update_inlet_outlet(io, 0.05));
  fluid.f64("x")[0] = 1.01;   // enters
  EXPECT_TRUE(sphc::inlet_outlet_due(io));
  outlet.f64("x")[0] = 0.99;  // flows back
  EXPECT_TRUE(sphc::update_inlet_outlet(io, 0.1));
  ASSERT_EQ(fluid.n, 1u);
  ASSERT_EQ(outlet.n, 1u);
  EXPECT_EQ(fluid.f64("x")[0], 0.99);
  EXPECT_EQ(fluid.u32(fluid.find("gid"))[0], 1u);
  EXPECT_EQ(outlet.u32(outlet.find("gid"))[0], 0u);
  outlet.f64("x")[0] = 1.3;  // past the zone
  EXPECT_TRUE(sphc::update_inlet_outlet(io, 0.2));
  EXPECT_EQ(outlet.n, 0u);
  EXPECT_FALSE(sphc::update_inlet_outlet(io, 0.3));
}

}  // namespace

// The mirror outlet: every outlet particle takes the velocity (and any copied property other
// than positions, m, h, gid) of the fluid interpolated at its image across the face (x = 1).
// A field that varies only along the face (u = 1 + 0.5 y) comes out exactly at particles whose image neighbourhood is
// symmetric in y (a lattice row away from the walls); positions, masses and ids are kept;
// with an interpolation radius that reaches no fluid particle the values are kept; the
// do-nothing outlet changes nothing.
TEST(InletOutlet, MirrorOutletInterpolatesAtTheImage) {
  const double dx = 0.1;
  auto fill = [&](ParticleArray& a, double x0, double x1) {
    fill_lattice(a, x0, x1, dx, [&](std::size_t i, double x, double y) {
      a.f64("u")[i] = x < 1.0 ? 1.0 + 0.5 * y : -7.0;
      a.f64("v")[i] = x < 1.0 ? 0.2 * x : -7.0;
    });
  };
  for (const sphc::OutletKind kind : {sphc::OutletKind::Mirror, sphc::OutletKind::DoNothing}) {
    for (const double support : {0.2, 0.01}) {
      ParticleArray fluid = make_array("fluid", 0), outlet = make_array("outlet", 0);
      fill(fluid, 0.0, 1.0);
      fill(outlet, 1.0, 1.2);
      outlet.f64("y")[0] += 0.03;  // off the lattice: its image is 0.03 from any particle
      sphc::InletOutlet io;
      sphc::OutletZone out = channel_outlet(fluid, outlet);
      out.copy = {"x", "y", "u", "v", "m"};
      out.kind = kind;
      io.outlets.push_back(out);
      sphc::init_inlet_outlet(io, {&fluid, &outlet}, support, 0.0);
      ASSERT_EQ(outlet.n, 20u);
      const std::uint32_t gid0 = outlet.u32(outlet.find("gid"))[3];
      EXPECT_EQ(sphc::inlet_outlet_due(io), kind == sphc::OutletKind::Mirror);
      sphc::update_inlet_outlet(io, 0.0);
      ASSERT_EQ(outlet.n, 20u);
      ASSERT_EQ(fluid.n, 100u);
      EXPECT_EQ(outlet.u32(outlet.find("gid"))[3], gid0);
      const bool mirror = kind == sphc::OutletKind::Mirror;
      for (std::size_t i = 0; i < outlet.n; ++i) {
        const double x = outlet.f64("x")[i], y = outlet.f64("y")[i];
        const double img = 2.0 - x;  // the image across x = 1
        EXPECT_EQ(outlet.f64("m")[i], 1.0);
        EXPECT_GT(x, 1.0);
        if (!mirror || (support < dx && i == 0)) {  // nothing to interpolate from: kept
          EXPECT_EQ(outlet.f64("u")[i], -7.0) << i;
          EXPECT_EQ(outlet.f64("v")[i], -7.0) << i;
        } else if (support < dx) {  // the image is a fluid particle, the only one in reach
          EXPECT_NEAR(outlet.f64("u")[i], 1.0 + 0.5 * y, 1e-12) << i;
          EXPECT_NEAR(outlet.f64("v")[i], 0.2 * img, 1e-12) << i;
        } else {
          // v = 0.2 x, interpolated one-sided (no fluid beyond the face): within the values
          // of the fluid in reach of the image, below the face's 0.2.
          EXPECT_GT(outlet.f64("v")[i], 0.2 * (img - support)) << i;
          EXPECT_LT(outlet.f64("v")[i], 0.2) << i;
          // u = 1 + 0.5 y: exact where the fluid around the image is symmetric in y.
          if (i > 0 && y > support && y < 1.0 - support)
            EXPECT_NEAR(outlet.f64("u")[i], 1.0 + 0.5 * y, 1e-12) << i;
          else
            EXPECT_NEAR(outlet.f64("u")[i], 1.0 + 0.5 * y, 0.5 * support) << i;
        }
      }
      if (mirror) EXPECT_EQ(sphc::mirror_outlet(io.outlets[0]), support < dx ? 1u : 0u);
    }
  }
}

// The characteristic outlet: a wave leaving the fluid (u - u_ref = (p - p_ref) / (rho c))
// passes into the outlet unchanged; one that would come in through it
// (u - u_ref = -(p - p_ref) / (rho c)) is removed (p = p_ref, u = u_ref); a steady pressure is
// halved towards p_ref. u_ref is set from the first call, then moves by dt / tau per call.
TEST(InletOutlet, CharacteristicOutletPassesOutgoingWavesOnly) {
  const double dx = 0.1, c = 10.0, rho = 1.0, U = 1.0, P = 0.3;
  auto fill = [&](ParticleArray& a, double x0, double x1) {
    fill_lattice(a, x0, x1, dx, [&](std::size_t i, double x, double) {
      a.f64("rho")[i] = rho;
      a.f64("u")[i] = x < 1.0 ? U : -7.0;
      a.f64("v")[i] = x < 1.0 ? 0.25 : -7.0;
      a.f64("p")[i] = x < 1.0 ? 0.0 : -7.0;
    });
  };
  auto props = [](ParticleArray& a) {
    a.add_property("rho");
    a.add_property("p");
  };
  // sign = +1: outgoing wave, -1: incoming, 0: a steady pressure P (velocity unchanged).
  for (const int sign : {1, -1, 0}) {
    ParticleArray fluid = make_array("fluid", 0), outlet = make_array("outlet", 0);
    props(fluid);
    props(outlet);
    fill(fluid, 0.0, 1.0);
    fill(outlet, 1.0, 1.2);
    sphc::InletOutlet io;
    sphc::OutletZone out = channel_outlet(fluid, outlet);
    out.copy = {"x", "y", "u", "v", "m", "rho", "p"};
    out.kind = sphc::OutletKind::Characteristic;
    out.c = c;
    out.tau = 1e9;  // u_ref stays the first call's
    io.outlets.push_back(out);
    sphc::init_inlet_outlet(io, {&fluid, &outlet}, 0.2, 0.0);
    EXPECT_TRUE(sphc::inlet_outlet_due(io));
    sphc::update_inlet_outlet(io, 0.0);  // u_ref = U
    for (std::size_t i = 0; i < outlet.n; ++i) {
      EXPECT_NEAR(outlet.f64("p")[i], 0.0, 1e-12) << i;
      EXPECT_NEAR(outlet.f64("u")[i], U, 1e-12) << i;
      EXPECT_NEAR(outlet.f64("v")[i], 0.25, 1e-12) << i;
    }
    for (std::size_t j = 0; j < fluid.n; ++j) {
      fluid.f64("p")[j] = P;
      fluid.f64("u")[j] = U + sign * P / (rho * c);
    }
    sphc::update_inlet_outlet(io, 0.01);
    for (std::size_t i = 0; i < outlet.n; ++i) {
      const double p = outlet.f64("p")[i], u = outlet.f64("u")[i];
      if (sign > 0) {
        EXPECT_NEAR(p, P, 1e-9) << i;
        EXPECT_NEAR(u, U + P / (rho * c), 1e-9) << i;
      } else if (sign < 0) {
        EXPECT_NEAR(p, 0.0, 1e-9) << i;
        EXPECT_NEAR(u, U, 1e-9) << i;
      } else {
        EXPECT_NEAR(p, 0.5 * P, 1e-9) << i;
        EXPECT_NEAR(u, U + 0.5 * P / (rho * c), 1e-9) << i;
      }
      EXPECT_NEAR(outlet.f64("v")[i], 0.25, 1e-12) << i;  // tangential: the image's
    }
  }
  // Without a sound speed it refuses to run, as the hybrid outlet does, each by its name.
  ParticleArray fluid = make_array("fluid", 0), outlet = make_array("outlet", 0);
  props(fluid);
  props(outlet);
  for (const auto kind : {sphc::OutletKind::Characteristic, sphc::OutletKind::Hybrid}) {
    sphc::OutletZone out;
    out.zone.name = "outlet 'o'";
    out.outlet = &outlet;
    out.from = &fluid;
    out.kind = kind;
    const bool hybrid = kind == sphc::OutletKind::Hybrid;
    try {
      hybrid ? sphc::hybrid_outlet(out, 0.0) : sphc::characteristic_outlet(out, 0.0);
      ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& e) {
      const std::string want = std::string("the ") + (hybrid ? "hybrid" : "characteristic") +
                               " outlet needs the sound speed";
      EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << e.what();
    }
  }
}

// The hybrid outlet (Negi et al. 2019): the mean (u_ta, p_ta) is the fluid's at the face,
// averaged in time; the fluctuation is the outgoing characteristic from that mean at the
// image. With the mean held (tau huge) it acts as the characteristic outlet around it: an
// outgoing wave passes, an incoming one is removed, a step in the pressure is halved. With
// the mean following at once (tau below the time step) a quiet pressure (|p - p_ref| below
// rho U^2 / 2 = 0.5) leaves unchanged; a loud one (0.85) does not enter p_ta, whose velocity
// still follows. The means are per bin across the face, from the fluid within the support of
// it (set at the first call, before any particle is in the outlet), and they are in the
// restart state.
TEST(InletOutlet, HybridOutletMeanPlusOutgoingFluctuation) {
  const double dx = 0.1, c = 10.0, rho = 1.0, U = 1.0, P0 = 0.05;
  auto props = [](ParticleArray& a) {
    a.add_property("rho");
    a.add_property("p");
  };
  // sign = +1: outgoing wave, -1: incoming, 0: a step in the pressure (velocity unchanged).
  for (const auto& [tau, P] : {std::pair<double, double>{1e9, 0.3}, {1e-6, 0.3}, {1e-6, 0.8}})
    for (const int sign : {1, -1, 0}) {
      ParticleArray fluid = make_array("fluid", 0), outlet = make_array("outlet", 0);
      props(fluid);
      props(outlet);
      fill_lattice(fluid, 0.0, 1.0, dx, [&](std::size_t i, double, double) {
        fluid.f64("rho")[i] = rho;
        fluid.f64("u")[i] = U;
        fluid.f64("v")[i] = 0.25;
        fluid.f64("p")[i] = P0;
      });
      sphc::InletOutlet io;
      sphc::OutletZone out = channel_outlet(fluid, outlet);
      out.copy = {"x", "y", "u", "v", "m", "rho", "p"};
      out.kind = sphc::OutletKind::Hybrid;
      out.c = c;
      out.tau = tau;
      io.outlets.push_back(out);
      sphc::init_inlet_outlet(io, {&fluid, &outlet}, 0.2, 0.0);
      EXPECT_TRUE(sphc::inlet_outlet_due(io));
      sphc::update_inlet_outlet(io, 0.0);  // no outlet particle yet: the means are set
      const sphc::OutletZone& o = io.outlets[0];
      ASSERT_EQ(o.uref.size(), 10u);  // width 1 / (support 0.2 / 2)
      for (std::size_t b = 0; b < o.uref.size(); ++b) {
        EXPECT_NEAR(o.uref[b], U, 1e-12) << b;
        EXPECT_NEAR(o.pref[b], P0, 1e-12) << b;
      }
      fill_lattice(outlet, 1.0, 1.2, dx, [&](std::size_t i, double, double) {
        outlet.f64("u")[i] = outlet.f64("v")[i] = outlet.f64("p")[i] = -7.0;
        outlet.f64("rho")[i] = rho;
      });
      for (std::size_t j = 0; j < fluid.n; ++j) {
        fluid.f64("p")[j] = P0 + P;
        fluid.f64("u")[j] = U + sign * P / (rho * c);
      }
      sphc::update_inlet_outlet(io, 0.01);
      ASSERT_EQ(outlet.n, 20u);
      for (std::size_t i = 0; i < outlet.n; ++i) {
        const double p = outlet.f64("p")[i], u = outlet.f64("u")[i];
        if (tau < 1.0 && P < 0.5) {  // the mean is the fluid's now: J2 = 0, it leaves
          EXPECT_NEAR(p, P0 + P, 1e-9) << i;
          EXPECT_NEAR(u, U + sign * P / (rho * c), 1e-9) << i;
        } else if (tau < 1.0) {  // loud: u_ta is the fluid's, p_ta held: J2 = P
          EXPECT_NEAR(p, P0 + 0.5 * P, 1e-9) << i;
          EXPECT_NEAR(u, U + sign * P / (rho * c) + 0.5 * P / (rho * c), 1e-9) << i;
        } else if (sign > 0) {
          EXPECT_NEAR(p, P0 + P, 1e-9) << i;
          EXPECT_NEAR(u, U + P / (rho * c), 1e-9) << i;
        } else if (sign < 0) {
          EXPECT_NEAR(p, P0, 1e-9) << i;
          EXPECT_NEAR(u, U, 1e-9) << i;
        } else {
          EXPECT_NEAR(p, P0 + 0.5 * P, 1e-9) << i;
          EXPECT_NEAR(u, U + 0.5 * P / (rho * c), 1e-9) << i;
        }
        EXPECT_NEAR(outlet.f64("v")[i], 0.25, 1e-12) << i;  // tangential: the image's
      }
      // The running means are restart state (with the counters): restored, they are equal.
      sphc::RunState state;
      sphc::inlet_outlet_state(io, state);
      sphc::InletOutlet back;
      back.outlets.push_back(out);
      sphc::restore_inlet_outlet(back, state);
      EXPECT_EQ(back.outlets[0].pref, o.pref);
      EXPECT_EQ(back.outlets[0].uref, o.uref);
      EXPECT_EQ(back.outlets[0].t_last, o.t_last);
      EXPECT_TRUE(back.outlets[0].started);
    }
}

// Fresh ids in (inlet, old id) order: an inlet's particles split over 1, 2 and 4 "ranks" (each
// its own inlet array holding a share in another order, as migration and reorders leave them)
// get, through the steps a distributed run takes (enter_fluid on each share, the old ids of
// every share gathered and sorted, give_fresh_ids with one first id: sphc/mpi/zones.h),
// exactly the ids the serial update_inlet gives the whole array, particle by particle (matched
// by position); and those are next, next + 1, ... in the order of the old ids.
TEST(InletOutlet, FreshIdsInOldIdOrderOverRanks) {
  const double dx = 0.1;
  auto with_gid = [](const std::string& name) {
    ParticleArray a = make_array(name, 0);
    a.add_property("gid", PropType::U32, 1);
    return a;
  };
  // A 4 x 10 lattice at x = -0.15, -0.05, 0.05, 0.15 (the inlet face at x = 0, normal -x: the
  // two columns at x > 0 crossed), particle k with old id 100 + 7 k mod 40 (place and id
  // orders differ).
  auto lattice = [&](ParticleArray& a, const std::vector<std::size_t>& which) {
    for (std::size_t k : which) {
      const std::size_t i = a.n;
      a.resize(i + 1);
      a.f64("x")[i] = dx * static_cast<double>(k % 4) - 0.15;
      a.f64("y")[i] = dx * (static_cast<double>(k / 4) + 0.5);
      a.u32(a.find("gid"))[i] = static_cast<std::uint32_t>(100 + (7 * k) % 40);
    }
  };
  auto zone = [&](ParticleArray& inlet, ParticleArray& fluid) {
    sphc::InletZone in;
    in.zone.name = "inlet";
    in.zone.dim = 2;
    in.zone.normal[0] = -1.0;
    in.zone.length = 0.4;
    in.zone.width = 1.0;
    in.zone.point[1] = 0.5;
    in.inlet = &inlet;
    in.feeds = &fluid;
    in.map = sphc::make_copy_map(fluid, inlet, {"x", "y"});
    return in;
  };
  // A position as integers (half dx units).
  auto key = [&](double x, double y) {
    return std::make_pair(std::lround(x / dx * 2), std::lround(y / dx * 2));
  };
  std::vector<std::size_t> all(40);
  for (std::size_t k = 0; k < 40; ++k) all[k] = (13 * k + 5) % 40;  // a scrambled order
  ParticleArray inlet = with_gid("inlet"), fluid = with_gid("fluid");
  lattice(inlet, all);
  sphc::InletZone in = zone(inlet, fluid);
  sphc::GlobalIds ids;
  ids.next = 500;
  EXPECT_TRUE(sphc::update_inlet(in, ids, 0.0));
  ASSERT_EQ(fluid.n, 20u);
  EXPECT_EQ(ids.next, 520u);
  EXPECT_EQ(in.created, 20u);
  std::map<std::pair<long, long>, std::uint32_t> want;  // serial: position -> id
  for (std::size_t i = 0; i < inlet.n; ++i)
    want[key(inlet.f64("x")[i], inlet.f64("y")[i])] = inlet.u32(inlet.find("gid"))[i];
  ASSERT_EQ(want.size(), 40u);
  // The fed particles kept their old ids; the inlet particle that replaced each (moved back by
  // the zone length, 0.4 in -x) has 500 + the place of that old id among the 20.
  const std::uint32_t* fg = fluid.u32(fluid.find("gid"));
  std::vector<std::uint32_t> old(fg, fg + fluid.n);
  std::sort(old.begin(), old.end());
  for (std::size_t j = 0; j < fluid.n; ++j) {
    const auto k = std::lower_bound(old.begin(), old.end(), fg[j]) - old.begin();
    EXPECT_EQ(want.at(key(fluid.f64("x")[j] - 0.4, fluid.f64("y")[j])), 500u + k)
        << "old id " << fg[j];
  }
  for (int ranks : {1, 2, 4}) {
    std::vector<ParticleArray> inl, flu;
    for (int r = 0; r < ranks; ++r) {
      inl.push_back(with_gid("inlet"));
      flu.push_back(with_gid("fluid"));
      std::vector<std::size_t> share;  // every ranks-th particle, in reverse: another order
      for (std::size_t k = 0; k < 40; ++k)
        if (static_cast<int>(k % ranks) == r) share.push_back(all[39 - k]);
      lattice(inl[r], share);
    }
    std::vector<sphc::InletZone> zones;
    for (int r = 0; r < ranks; ++r) zones.push_back(zone(inl[r], flu[r]));
    std::vector<std::vector<std::size_t>> crossed(ranks);
    std::vector<std::uint32_t> entering;  // what all_entering gathers
    for (int r = 0; r < ranks; ++r) {
      crossed[r] = sphc::enter_fluid(zones[r]);
      const auto ids_r = sphc::old_ids(zones[r], crossed[r]);
      entering.insert(entering.end(), ids_r.begin(), ids_r.end());
    }
    std::sort(entering.begin(), entering.end());
    ASSERT_EQ(entering.size(), 20u);
    sphc::GlobalIds rank_ids;
    rank_ids.next = 500;
    const std::uint32_t first = rank_ids.take(entering.size());
    for (int r = 0; r < ranks; ++r) sphc::give_fresh_ids(zones[r], crossed[r], entering, first);
    EXPECT_EQ(rank_ids.next, ids.next);
    std::size_t seen = 0, fed = 0;
    for (int r = 0; r < ranks; ++r) {
      for (std::size_t i = 0; i < inl[r].n; ++i, ++seen)
        EXPECT_EQ(inl[r].u32(inl[r].find("gid"))[i],
                  want.at(key(inl[r].f64("x")[i], inl[r].f64("y")[i])))
            << ranks << " ranks, rank " << r << ", particle " << i;
      fed += flu[r].n;
    }
    EXPECT_EQ(seen, 40u);
    EXPECT_EQ(fed, 20u);
  }
  // A crossing particle whose old id is not among the entering ones is an error.
  std::vector<std::size_t> one{0};
  EXPECT_THROW(sphc::give_fresh_ids(in, one, {}, 0), std::logic_error);
}
