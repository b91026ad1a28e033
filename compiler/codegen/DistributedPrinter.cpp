// The printing of a distributed run (sphc --mpi; the schedule's Distribution, codegen/
// Schedule.h) and of global particle ids (--global-ids): the few statements the CPU printers
// and the host program add, calling the MPI runtime (runtime/include/sphc/mpi/). Kept in its
// own file so that the serial printers read as before.
#include "codegen/Printer.h"
#include "frontend/FormatNumber.h"

namespace sphc {

std::string ScenePrinter::allArrays(const std::string& prefix) const {
  std::string s = "{";
  for (size_t a = 0; a < plan_.arrays.size(); ++a)
    s += (a ? ", &" : "&") + prefix + plan_.arrays[a].name;
  return s + "}";
}

void ScenePrinter::emitMigration() {
  const Distribution& d = sched_.distribution;
  scene_ << "    // Particles that left this rank's region go to their owner with every property;\n"
            "    // a re-balance every "
         << d.rebalanceEvery << " evaluations or above " << d.imbalanceLimit
         << " imbalance (sphc/mpi/decomposition.h).\n";
  scene_ << "    sphc::mpi::update(decomposition, " << allArrays("") << ");\n";
}

void ScenePrinter::emitHaloExchange() {
  scene_ << "    // The halo: other ranks' particles and the periodic/mirror images of all within the\n"
            "    // interaction radius of this rank's region, in the ghosts' place (sphc/mpi/halo.h).\n";
  scene_ << "    const double cutoff = sphc::mpi::global_cutoff(all, Kernel::radius_scale);\n";
  for (const auto& [a, props] : sched_.distribution.halo) {
    const std::string& S = arr(a).name;
    scene_ << "    sphc::mpi::exchange_halo(decomposition, box, " << S << ", cutoff, ghosts_" << S
           << ", " << propIndexList(a, props) << ");  //";
    for (const auto& p : props) scene_ << " " << p;
    scene_ << "\n";
  }
  scene_ << "    domain = sphc::mpi::halo_search_domain(all, {";
  bool first = true;
  for (const auto& a : plan_.arrays) {
    if (!loopArrays_.count(a.name)) continue;
    bool source = false;
    for (const auto& S : sourceArrays_) source |= S == a.name;
    scene_ << (first ? "" : ", ") << (source ? "ghosts_" + a.name + ".size()" : std::string("0"));
    first = false;
  }
  scene_ << "}, DIM, Kernel::radius_scale);\n";
}

std::string ScenePrinter::globalReduction(const std::string& op, const std::string& nReal) const {
  if (op == "mean")
    return "        {  // the mean over every rank's particles\n"
           "          const long count = sphc::mpi::sum(static_cast<long>(" + nReal + "));\n"
           "          acc = sphc::mpi::sum(acc);\n"
           "          acc = count > 0 ? acc / static_cast<double>(count) : 0.0;\n        }\n";
  const std::string f = op == "sum" ? "sum" : op == "max" ? "max" : "min";
  return "        acc = sphc::mpi::" + f + "(acc);  // over every rank's particles\n";
}

void ScenePrinter::distributedMembers() {
  if (mpi_) {
    out_ << "  sphc::mpi::Decomposition decomposition;  // this rank's region (Zoltan)\n";
    out_ << "  std::vector<sphc::Limit> default_limits;  // the whole set-up's box (sanity.h)\n";
  }
}

void ScenePrinter::distributedFunctions() {
  if (mpi_) {
    const Distribution& d = sched_.distribution;
    scene_ << "  // --mpi: the set-up ran on every rank; each keeps the particles of its region, with\n"
              "  // a global id gid (set-up order, sphc/global_ids.h).\n";
    scene_ << "  void distribute() {\n";
    scene_ << "    sphc::mpi::init_decomposition(decomposition, DIM, \"" << d.method << "\");\n";
    scene_ << "    decomposition.rebalance_every = " << d.rebalanceEvery << ";\n";
    scene_ << "    decomposition.imbalance_limit = " << d.imbalanceLimit << ";\n";
    scene_ << "    // Work per particle of each array (1 + neighbour passes as destination).\n";
    scene_ << "    sphc::mpi::set_weights(decomposition, {";
    for (size_t a = 0; a < d.weights.size(); ++a)
      scene_ << (a ? ", " : "") << exactNumber(d.weights[a]);
    scene_ << "});\n";
    scene_ << "    default_limits = sphc::bounding_box_limits(" << allArrays("") << ", DIM);\n";
    scene_ << "    sphc::mpi::distribute(decomposition, " << allArrays("") << ");\n";
    scene_ << "  }\n\n";
  } else if (globalIds_) {
    scene_ << "  // --global-ids: every particle gets a global id gid, unique over the arrays in set-up\n"
              "  // order (sphc/global_ids.h, as --mpi numbers them), which moves with it.\n";
    scene_ << "  void number_particles() {\n";
    scene_ << "    sphc::GlobalIds ids;\n";
    scene_ << "    sphc::assign_global_ids(" << allArrays("") << ", ids);\n";
    scene_ << "  }\n\n";
  }
}

std::string ScenePrinter::afterSetupDistributed() const {
  if (mpi_) return "    if (!sphc::counting_particles()) scene.distribute();\n";
  if (globalIds_) return "    if (!sphc::counting_particles()) scene.number_particles();\n";
  return "";
}

std::string ScenePrinter::distributedReport() const {
  std::string halos, arrays;
  for (const auto& S : sourceArrays_) {
    halos += (halos.empty() ? "&scene.ghosts_" : ", &scene.ghosts_") + S;
    arrays += (arrays.empty() ? "&scene." : ", &scene.") + S;
  }
  return "  sphc::mpi::report_stats(scene.decomposition, {" + arrays + "}, {" + halos + "}, " +
         allArrays("scene.") + ");  // SPHC_MPI_STATS=1\n";
}

void ScenePrinter::distributedMain() {
  if (!mpi_) return;
  out_ << "  prog.rank = sphc::mpi::rank();  // rank 0 writes the files and the progress line\n";
  out_ << "  prog.ranks = sphc::mpi::size();  // a restart reads one block of the file per rank\n";
  out_ << "  // Output: collective parallel HDF5, or gathered to rank 0 (sphc/mpi/output.h).\n";
  out_ << "  sphc::mpi::set_output(prog, [] {\n";
  out_ << "    return std::vector<sphc::ParticleArray*>" << allArrays("scene.") << ";\n  });\n";
  out_ << "  prog.default_limits = [] { return scene.default_limits; };\n";
  bool removes = false;
  for (const auto& l : plan_.limits) removes |= l.hasRemove;
  if (removes)
    out_ << "  // limits' remove: each rank removes its own, rank 0 logs every rank's "
            "(sphc/mpi/output.h).\n"
         << "  sphc::mpi::set_removal(prog, scene.decomposition, " << allArrays("scene.")
         << ");\n";
}

}  // namespace sphc
