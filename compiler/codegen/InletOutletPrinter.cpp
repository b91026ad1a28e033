// Inlets and outlets in the host program every backend shares (docs/design.md, Arrays that
// grow and shrink): the zones built in setup() and the schedule's InletOutlet statement, the
// Scene member inlet_outlet(t). The manager itself is the runtime's (sphc/inlet_outlet.h); a
// backend only says how the resized arrays reach the host and go back (arraysToHost,
// arraysFromHost).
#include "codegen/Printer.h"

namespace sphc {

void ScenePrinter::emitZoneSetup() {
  auto pn = [&](const std::string& n) { return paramRef(n); };
  static const char* kAxes[3] = {"x", "y", "z"};
  scene_ << "    // inlets and outlets (sphc/inlet_outlet.h)\n";
  scene_ << "    io = sphc::InletOutlet{};\n";
  for (const PlanZone& z : plan_.zones) {
    const std::string kind = z.inlet ? "inlet" : "outlet";
    scene_ << "    {  // " << kind << " " << z.name << ", from " << loc(z.loc) << "\n";
    scene_ << "      sphc::" << (z.inlet ? "InletZone" : "OutletZone") << " zn;\n";
    scene_ << "      zn.zone.name = \"" << kind << " '" << z.name << "' (" << loc(z.loc)
           << ")\";\n";
    scene_ << "      zn.zone.dim = DIM;\n";
    for (int k = 0; k < plan_.dim; ++k) {
      if (z.point[k]) scene_ << "      zn.zone.point[" << k << "] = " << exprCpp(*z.point[k], pn) << ";\n";
      if (z.normal[k]) scene_ << "      zn.zone.normal[" << k << "] = " << exprCpp(*z.normal[k], pn) << ";\n";
    }
    scene_ << "      zn.zone.length = " << exprCpp(*z.length, pn) << ";\n";
    if (z.width) scene_ << "      zn.zone.width = " << exprCpp(*z.width, pn) << ";\n";
    const std::string& A = arr(z.array).name;
    const std::string& O = arr(z.other).name;
    if (z.inlet)
      scene_ << "      zn.inlet = &" << A << ";\n      zn.feeds = &" << O << ";\n";
    else
      scene_ << "      zn.outlet = &" << A << ";\n      zn.from = &" << O << ";\n";
    if (!z.inlet && z.type == "mirror")  // properties interpolated at the image points
      scene_ << "      zn.kind = sphc::OutletKind::Mirror;\n";
    if (!z.inlet && z.type == "characteristic")  // mirror interpolation + characteristics
      scene_ << "      zn.kind = sphc::OutletKind::Characteristic;\n";
    if (!z.inlet && z.type == "hybrid")  // time average + outgoing characteristic's fluctuation
      scene_ << "      zn.kind = sphc::OutletKind::Hybrid;\n";
    if (!z.inlet && (z.type == "characteristic" || z.type == "hybrid")) {
      scene_ << "      zn.c = " << exprCpp(*z.c, pn) << ";\n";
      if (z.pRef) scene_ << "      zn.p_ref = " << exprCpp(*z.pRef, pn) << ";\n";
      if (z.tau) scene_ << "      zn.tau = " << exprCpp(*z.tau, pn) << ";\n";
    }
    if (!z.copy.empty()) {
      scene_ << "      zn.copy = {";
      for (size_t i = 0; i < z.copy.size(); ++i)
        scene_ << (i ? ", " : "") << "\"" << z.copy[i] << "\"";
      scene_ << "};\n";
    }
    bool prescribed = false;
    for (const auto& v : z.velocity) prescribed |= v != nullptr;
    if (z.inlet && prescribed) {
      // The prescribed velocity: an expression of params, the position and the time.
      auto names = [&](const std::string& n) {
        return n == "x" || n == "y" || n == "z" || n == "t" ? n : paramRef(n);
      };
      scene_ << "      zn.velocity = [this](const double* pos, double t, double* vel) {\n";
      scene_ << "        const double x = pos[0], y = pos[1], z = pos[2];\n";
      scene_ << "        (void)x; (void)y; (void)z; (void)t;\n";
      for (int k = 0; k < 3; ++k)
        if (z.velocity[k])
          scene_ << "        vel[" << k << "] = " << exprCpp(*z.velocity[k], names) << ";  // "
                 << "uvw"[k] << "\n";
      scene_ << "      };\n";
    }
    scene_ << "      io." << kind << "s.push_back(std::move(zn));\n";
    scene_ << "    }\n";
  }
  scene_ << "    {\n      const std::vector<sphc::ParticleArray*> all{";
  for (size_t a = 0; a < plan_.arrays.size(); ++a) scene_ << (a ? ", " : "") << "&" << arr(a).name;
  scene_ << "};\n";
  scene_ << "      // Zones are checked against the kernel support (radius_scale * largest h).\n";
  scene_ << "      sphc::init_inlet_outlet(io, all, Kernel::radius_scale * sphc::largest_h(all), "
            "0.0);\n    }\n";
  (void)kAxes;
}

void ScenePrinter::emitInletOutlet() {
  scene_ << "  // Inlets and outlets, after each time step (new time t): particles enter the\n"
            "  // fluid, leave it into outlets and are removed (sphc/inlet_outlet.h); the arrays";
  for (int a : sched_.resized) scene_ << " " << arr(a).name;
  scene_ << "\n  // change size here, between steps only.\n";
  scene_ << "  void inlet_outlet(double t) {\n";
  scene_ << "    const double start = sphc::wall_seconds();\n";
  bool mirror = false;  // a mirror outlet sets its particles every step: no shortcut
  for (const PlanZone& z : plan_.zones) mirror |= !z.inlet && z.type != "do_nothing";
  // The shortcut is a rank's own decision: a distributed run always takes the collective path.
  if (checksZonesFirst() && !mirror && !mpi_) {
    std::vector<int> inlets;
    for (const PlanZone& z : plan_.zones)
      if (z.inlet) inlets.push_back(z.array);
    positionsToHost(sched_.resized);
    scene_ << "    if (!sphc::inlet_outlet_due(io)) {  // no particle changes array this step\n";
    scene_ << "      sphc::set_inlet_velocities(io, t);\n";
    inletVelocitiesFromHost(inlets);
    scene_ << "      io_seconds += sphc::wall_seconds() - start;\n      return;\n    }\n";
  }
  arraysToHost(sched_.resized);
  if (mpi_)  // --mpi: the same steps with collectives between them (sphc/mpi/zones.h)
    scene_ << "    sphc::mpi::update_inlet_outlet(io, t);\n";
  else
    scene_ << "    sphc::update_inlet_outlet(io, t);\n";
  arraysFromHost(sched_.resized);
  scene_ << "    io_seconds += sphc::wall_seconds() - start;  // for --timing\n";
  scene_ << "  }\n\n";
}

}  // namespace sphc
