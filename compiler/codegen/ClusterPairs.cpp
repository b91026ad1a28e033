// Each pair once in cluster-pair tiles (sphc --simd-pairs=cluster; opt-in since stop 37;
// docs/performance-log.md "Cluster-pair tiles in the printer (stop 37)"; GROMACS' nbnxm scheme,
// Pall & Hess 2013, as measured by hand in bench/cluster_pairs.cpp).
//
// A pass that --simd-pairs=once prints each pair once in SIMD lanes (onceLanes: same array,
// kept lists, double precision, no periodic or mirror domain, no zones) is printed, where
// clusterTilesRefusal() allows it, as tiles of 8 i's x 8 j's over the runtime's cluster-pair
// lists (sphc/cluster_pairs.h):
//   - at a rebuild of the pass's kept lists (verlet_build: the same VerletSkin; the kept lists
//     themselves are not built), the cluster layout of the array and the outer list of
//     cluster pairs at the kept lists' radius (1 + skin) radius_scale h_max (each pair once:
//     j-clusters >= i);
//   - per evaluation, the positions in slot order (padding far away), the boxes, the list
//     pruned at the support radius radius_scale h_max (h_max now), and slot-order copies of
//     every property and hoisted value the bodies read (cl_NAME);
//   - per i-cluster ci and j-cluster of its list, per real i of ci (d_idx: its slot), a first
//     `omp simd` loop over the 8 lanes finds whether any is within the cut-off (else the row
//     is skipped), then the lanes under `#pragma omp simd`: s_idx is the LANE, the source's
//     copies offset to the j-cluster (sj_x = cl_x + j0, s_m = cl_m + j0: no int arithmetic in
//     the loop, which would make GCC 12 take 16 lanes for its ints and 256-bit vectors), the
//     pair quantities and their mirrors (negations), the pair-shared values, each body's _simd
//     call for d_idx on its lane sums (ti_NAME[ii][lane], across ci's list) and _simd_mirror
//     call for the lane's particle on the tile's sums (tj_NAME[lane], across the tile's i's),
//     each kept under its mask (the cut-off; on the diagonal tile the lanes j > i, and j == i
//     for d_idx where the self pair is evaluated);
//   - the tile's j sums added to the slot sums once per tile, i's lane sums once per
//     i-cluster; the slot sums added to the particles' sums (add_slots).
// 2D (stop 39; docs/performance-log.md "2D tiles in the 2xMM form (stop 39)"): GROMACS' AVX-512
// double "2xMM" form instead (--cluster-2d-8x8 keeps the 8 x 8 one, a measurement knob): the
// layout of width CL_W = 4 (the column side 2 spacings, the spacing sqrt(mean m / rho) where
// the array has m and rho), a tile = a 4-cluster of i's x a 4-cluster of j's in two
// registers of CL_LANES = 8 lanes, lane l of register r holding i = 2 r + l / 4 and j = l % 4:
//   - the j side from copies doubled per cluster (cl2_NAME: a cluster's 4 values twice, one
//     contiguous load of 8 lanes), gathered so in one call (gather_slots_doubled with
//     arrays of pointers; what nothing writes at the build only, the rest per evaluation:
//     tileover's pieces, merged), the hoisted values computed from the doubled copies (at
//     the first half, written to both), the positions gathered in slot order with the
//     boxes (gather_positions_boxes) and doubled by a printed loop;
//   - the i side from the i-cluster's registers (ri_NAME[r][lane], built once per i-cluster
//     from the doubled copies), read in the lanes with d_idx = the lane (so the bodies' [d_idx] and
//     the mirrored calls' source arrays index them: no gathers, no int arithmetic but the
//     lane);
//   - the register's cut-off alone first (skipped when no lane is within it), the diagonal
//     tile's j > i from lane tables (cl_ilane, cl_jlane);
//   - i's sums per register in 8 lane partial sums across the i-cluster's list, reduced per
//     i (4 lanes each) once per i-cluster; j's per tile, the two halves folded (lanes l and
//     l + 4: j l) onto the slot sums.
// The same OpenMP blocks and half tiles as the 8 x 8 form (bitwise the serial tiles).
// 3D (stop 42; docs/performance-log.md "3D tiles in the 2xMM form (stop 42)"): the same 2xMM
// form where clusterTiles2xMM() says so (--cluster-3d-2xmm; auto keeps the 8 x 8 tiles): the
// column side 2 spacings from the spacing cbrt(mean m / rho), so the 4-clusters are mostly 2 x 2
// x 1 lattice cells; every other piece is printed per dimension as in 2D.
// Slot order (stop 40; docs/performance-log.md "Particles in the tiles' slot order (stop 40)";
// --no-slot-order keeps the copies above): where clusterSlotOrder() allows it the array is
// kept in the tiles' order (update_neighbours permutes it into sphc::cluster_order where the
// lists are expected to be rebuilt and the clusters loosened, emitClusterSlotOrder), the
// layout is built in that order (slot s = particle s, only the last cluster padded), and the
// tiles read the pass's own arrays (8 x 8; 2xMM since stop 41 too: a j-cluster's 4 values
// doubled per tile into tile-local registers, sphc::load_doubled4, the i registers from the
// arrays; --cluster-2d-doubled keeps stop 39-40's doubled copies, contiguous reads) and sum
// onto the particles' own (cl_acc_NAME = d_NAME; the components' slot sums zeroed by their
// add-back, stop 41): no slot-order
// copies of the i side, no add_slots; the padded last cluster's j side reads and sums in
// W-value tails (cl_t_NAME, cl_tacc_NAME), picked per tile (jt, ja_NAME).
// The tiles are a lambda compiled without jump threading (GCC 12 threads the kernel's
// branches before if-conversion, "control flow in loop": the lanes stay scalar).
//
// Results: the sums reassociated (per i: 8 lane partial sums across its cluster pairs, summed
// in lane order; per j: the tile's i's first, then tile by tile; added to the value each sum
// had before the pass), so not bitwise the lanes' or the scalar loops' (tests: lit
// codegen/simd-pairs-cluster*.sph, stability.cluster_compare_*).
//
// OpenMP (stop 38): contiguous blocks of i-clusters, one per thread (balanced by the pruned
// list's pairs, since stop 41 a tile across two blocks counted as its two halves:
// sphc::tile_block_cuts), each writing only its own slots' sums, in the serial order whatever the
// blocks: (1) the j sides of the tiles of earlier i-clusters whose j-cluster is in the block
// (half tiles, i-clusters in increasing order), (2) the block's i-clusters, their tiles with
// j-clusters in the block whole, those with j-clusters in later blocks for the i side only.
// A tile across two blocks is computed twice, each side once (the scalar loops' OpenMP
// scheme, SymmetricPairs.cpp, in tiles), so the OpenMP build's sums are the serial tiles'
// bit for bit for any thread count (test: stability.cluster_omp_*). Since stop 44 a half tile
// is the whole tile with its other side's sums left unwritten (one copy of the tile's code).
#include "analysis/PairQuantityTable.h"
#include "codegen/CppText.h"
#include "codegen/Printer.h"

#include <map>
#include <regex>
#include <set>
#include <stdexcept>
#include <vector>

namespace sphc {

namespace {

// Stop 40: the particles are put in the tiles' order again when the outer list, built in
// their present order, holds this many times the cluster pairs per cluster that it held at
// the first build after the last sort (the clusters loosened as the particles moved).
constexpr const char* kSlotOrderLoosened = "1.05";

// Whether `text` names d_idx or s_idx other than as a whole subscript `[d_idx]` (with the
// slot indices of the tiles, an index used as a number would change meaning).
bool indexUsedAsNumber(const std::string& text) {
  for (const char* name : {"d_idx", "s_idx"}) {
    const std::string n = name;
    for (size_t at = text.find(n); at != std::string::npos; at = text.find(n, at + 1)) {
      if ((at > 0 && isIdentifierChar(text[at - 1])) ||
          (at + n.size() < text.size() && isIdentifierChar(text[at + n.size()])))
        continue;
      size_t before = at;
      while (before > 0 && (text[before - 1] == ' ' || text[before - 1] == '\t')) --before;
      size_t after = at + n.size();
      while (after < text.size() && (text[after] == ' ' || text[after] == '\t')) ++after;
      if (before == 0 || text[before - 1] != '[' || after >= text.size() || text[after] != ']')
        return true;
    }
  }
  return false;
}

// `text` with each site of a sum's component, `d_NAME[S * d_idx + K]` (NAME in `sums`), as
// `d_NAME[d_idx]`: the bodies' _simd forms have their locals there (stop 40).
std::string withoutSumComponents(const std::string& text, const std::set<std::string>& sums) {
  static const std::regex site(R"(\bd_([A-Za-z_][A-Za-z0-9_]*)\s*\[\s*\d+\s*\*\s*d_idx\s*(\+\s*\d+\s*)?\])");
  std::string out;
  size_t last = 0;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), site); it != std::sregex_iterator(); ++it) {
    const std::smatch& m = *it;
    if (!sums.count(m[1].str())) continue;
    out += text.substr(last, m.position(0) - last) + "d_" + m[1].str() + "[d_idx]";
    last = m.position(0) + m.length(0);
  }
  return out + text.substr(last);
}

// `call` (NAME(a, b, ...);  // comment) with each argument that is a whole key of `rename`
// replaced by its value.
std::string withArguments(const std::string& call, const std::map<std::string, std::string>& rename) {
  const size_t open = call.find('('), close = call.find(");");
  if (open == std::string::npos || close == std::string::npos) return call;
  std::string out = call.substr(0, open + 1);
  size_t at = open + 1;
  while (at <= close) {
    size_t end = call.find(", ", at);
    if (end == std::string::npos || end > close) end = close;
    const std::string arg = call.substr(at, end - at);
    auto it = rename.find(arg);
    out += it == rename.end() ? arg : it->second;
    if (end == close) break;
    out += ", ";
    at = end + 2;
  }
  return out + call.substr(close);
}

}  // namespace

std::string ScenePrinter::clusterTilesRefusal(const DestinationWork& w,
                                              const NeighbourPass& pass) const {
  if (!simdCluster_) return "off";
  if (clusterAutoSkipsDim()) return "off";  // auto: the 3D loops, the 2D ones where measured (stop 41)
  if (!onceLanes(w, pass)) return "not each pair once in SIMD lanes";
  return clusterTilesFormRefusal(w, pass);
}

std::string ScenePrinter::initInAddBackRefusal(const DestinationWork& w,
                                               const NeighbourPass& pass) const {
  if (!initInAddBack_on_) return "--no-init-in-add-back";
  if (w.initialize.empty()) return "no initialize";
  if (w.ranged() || w.onGhosts || hasDomain()) return "a range, ghosts or a periodic domain";
  if (!pass.initializePair.empty()) return "an initialize_pair";
  if (&pass != &w.passes.front()) return "not the destination's first pass";
  if (!clusterSlotOrder(w, pass)) return "the tiles not in the particles' order";
  // Every sum with components (slot sums and an add-back in the particles' order; a sum of
  // stride 1 goes straight onto its array in the tiles, kComponentsInPlace false).
  const RegisterSums sums = registerSums(w, pass);
  if (!sums.active()) return "no sums";
  for (const auto& [p, sc] : sums.props)
    if (sc.first == 1) return "the sum " + p + " is written in the tiles (stride 1)";
  // The initialize writes only those sums (nothing the pass reads: its bodies read no sum,
  // RegisterSums.cpp); not the positions, h or what the pass reads by name, to be sure.
  std::set<std::string> read(pass.shared.begin(), pass.shared.end());
  read.insert(pass.sourceProps.begin(), pass.sourceProps.end());
  for (const char* p : {"x", "y", "z", "h", "m", "rho"}) read.insert(p);
  for (const PlanEquation* eq : w.initialize)
    for (const PropAccess& x : methodBody(*eq, ast::Method::Initialize).facts.dWrites) {
      if (!sums.props.count(x.prop)) return "an initialize writes " + x.prop + ", not a sum of the tiles";
      if (read.count(x.prop)) return "an initialize writes " + x.prop + ", which the pass reads";
    }
  return "";
}

// Everything but the switch and the lanes (onceLanes): --simd-pairs=cluster's choice of the
// 2D loops asks it before they are in the lanes (SimdPairs.cpp, simdPairsAutoChoice; stop 38).
std::string ScenePrinter::clusterTilesFormRefusal(const DestinationWork& w,
                                                  const NeighbourPass& pass) const {
  if (plan_.dim < 2) return "a 1D scene";
  const int d = w.array;
  auto oneDouble = [&](const std::string& p) -> std::string {
    const PlanProperty* prop = arr(d).find(p);
    if (!prop) return "";
    if (prop->stride != 1) return p + " has " + std::to_string(prop->stride) + " components";
    if (hostType(d, p) != "double") return p + " is " + hostType(d, p);
    return "";
  };
  for (const std::string& p : pass.shared)
    if (std::string why = oneDouble(p); !why.empty()) return why;
  for (const std::string& p : pass.sourceProps)
    if (std::string why = oneDouble(p); !why.empty()) return why;
  // (sums with components: a lane array per component, stop 40)
  std::set<std::string> sums;
  for (const auto& [p, sc] : registerSums(w, pass).props) sums.insert(p);
  for (const PlanEquation* eq : pass.equations) {
    const PlanBody& b = methodBody(*eq, ast::Method::Loop);
    for (const auto& [p, sc] : destinationValues(b, d))
      if (sc.first != 1) return eq->name + " reads " + p + " of " + std::to_string(sc.first) + " components";
    for (const auto& [p, sc] : sourceValues(b))
      if (sc.first != 1) return eq->name + " reads " + p + " of " + std::to_string(sc.first) + " components";
    if (std::string why = rareCallsRefusal(b); !why.empty()) return eq->name + ": " + why;
    if (indexUsedAsNumber(withoutSumComponents(b.source.text, sums)))
      return eq->name + " uses d_idx or s_idx otherwise than as a subscript";
    const auto sites = hoistedSites(b, host_);
    for (size_t k = 0; k < sites.size(); ++k)
      if (hoistedValueType(b, host_, true, k) != "double")
        return eq->name + "'s hoisted value " + std::to_string(k) + " is no double";
    const auto dsites = hoistedDestinationSites(b, host_);
    for (size_t k = 0; k < dsites.size(); ++k)
      if (hoistedValueType(b, host_, false, k) != "double")
        return eq->name + "'s destination value " + std::to_string(k) + " is no double";
  }
  return "";
}

void ScenePrinter::clusterTilesMembers(std::ostream& os, const std::string& state,
                                       const std::string& what, int users) {
  os << "  // " << what << " in cluster-pair tiles (--simd-pairs=cluster, sphc/cluster_pairs.h): the\n"
        "  // layout and outer list (built with the kept lists' skin), the pruned list, the\n"
        "  // slot-order copies and sums.\n";
  os << "  sphc::ClusterLayout " << state << "_layout;\n";
  os << "  sphc::ClusterPairList " << state << "_outer, " << state << "_pruned;\n";
  for (int u = 0; u < users; ++u)
    os << "  std::vector<double> " << state << "_slots" << (u ? std::to_string(u) : "")
       << ";" << (users > 1 ? "  // the slot buffer of pass " + std::to_string(u) + " of these lists" : "") << "\n";
  os << "  double " << state << "_hmax = 0.0;  // the largest h at the build (where nothing writes h)\n";
  os << "  std::vector<std::uint32_t> " << state << "_order;  // the tiles' slot order (stop 40; update_neighbours)\n";
  os << "  // (stop 40) whether the particles are to be put in the tiles' order at the next expected\n"
        "  // rebuild; whether they were since the last build; the outer list's pairs per cluster then\n";
  // (the values clusterSortFresh sets again: change both together)
  os << "  bool " << state << "_order_due = true, " << state << "_sorted = false;\n";
  os << "  double " << state << "_pairs0 = 0.0;\n";
}

std::string ScenePrinter::clusterSortFresh(const std::string& prefix, const std::string& ind) {
  return ind + prefix + "_order_due = true;\n" + ind + prefix + "_sorted = false;\n" + ind +
         prefix + "_pairs0 = 0.0;\n";
}

// The column side of the 2xMM layout, from the particle spacing where the array has m and
// rho (columns of 2 spacings, clusters about square; the bounding box's rule grows with the
// flow's empty space: docs/performance-log.md, stop 38), else "0.0": the layout's rule from
// the bounding box. 3D (stop 42): the spacing's cube root, columns of 2 spacings as the
// 8-clusters': the 4-clusters 2 x 2 x 1 lattice cells (spacing 4^(1/3) would give 1 x 1 x 4
// and 2 x 1 x 2). emitClusterSlotOrder and emitClusterTiles build the same layout with it.
std::string ScenePrinter::emitClusterColumnSide(int d, bool mm, const std::string& guard,
                                                const std::string& count,
                                                const std::string& in) {
  auto plainDouble = [&](const std::string& p) {
    const PlanProperty* prop = arr(d).find(p);
    return prop && prop->stride == 1 && propIndex(d, p) >= 0 && hostType(d, p) == "double";
  };
  if (!mm || !plainDouble("m") || !plainDouble("rho")) return "0.0";
  const bool three = plan_.dim == 3;
  scene_ << in << "double cl_side = 0.0;  // the column side: the spacing "
         << (three ? "cbrt" : "sqrt") << "(mean m / rho) x 2 (2xMM)\n";
  scene_ << in << "if (" << guard << ") {\n";
  scene_ << in << "  const double* const cl_vm = " << hostPtr(d, "m") << ";\n";
  scene_ << in << "  const double* const cl_vrho = " << hostPtr(d, "rho") << ";\n";
  scene_ << in << "  double cl_vol = 0.0;\n";
  scene_ << in << "  for (std::size_t i = 0; i < static_cast<std::size_t>(" << count
         << "); ++i) cl_vol += cl_vm[i] / cl_vrho[i];\n";
  scene_ << in << "  cl_vol /= static_cast<double>(" << count << ");\n";
  scene_ << in << "  if (cl_vol > 0.0 && std::isfinite(cl_vol)) cl_side = sphc::cluster_column_side("
         << (three ? "std::cbrt(cl_vol), DIM, sphc::kClusterSize" : "std::sqrt(cl_vol), DIM, sphc::kClusterSize / 2")
         << ");\n";
  scene_ << in << "}\n";
  return "cl_side";
}

// Stop 40: the statements of update_neighbours that put the pass's array into its tiles'
// slot order (sphc::cluster_order, the layout's column side and width as emitClusterTiles
// builds it) where its lists are expected to be rebuilt at this evaluation
// (VerletSkin::rebuild_expected), and make every kept list in `forget` rebuild.
void ScenePrinter::emitClusterSlotOrder(const DestinationWork& w, const std::string& state,
                                        const std::vector<std::string>& forget,
                                        const std::string& ind) {
  const int d = w.array;
  const std::string A = arr(d).name;
  const bool mm = clusterTiles2xMM();
  scene_ << ind << "// --simd-pairs=cluster (stop 40): " << A << " in its tiles' slot order (sphc/cluster_pairs.h,\n"
         << ind << "// cluster_order) where their lists are expected to be rebuilt now; every kept list\n"
         << ind << "// of " << A << " then rebuilt (a permutation is no movement to measure).\n";
  scene_ << ind << "if (" << state << "_order_due && " << state << ".skin.rebuild_expected(Kernel::radius_scale)) {\n";
  const std::string in = ind + "  ";
  const std::string side = emitClusterColumnSide(d, mm, A + ".n > 0", A + ".n", in);
  scene_ << in << "sphc::cluster_order(" << state << "_order, " << hostPtr(d, "x") << ", " << hostPtr(d, "y") << ", "
         << (plan_.dim == 3 ? hostPtr(d, "z") : std::string("nullptr")) << ", " << A << ".n, DIM, " << side << ", "
         << (mm ? "sphc::kClusterSize / 2" : "sphc::kClusterSize") << ");\n";
  scene_ << in << A << ".permute(" << state << "_order);\n";
  for (const std::string& l : forget) scene_ << in << l << ".skin.forget();\n";
  scene_ << in << state << "_order_due = false;\n";
  scene_ << in << state << "_sorted = true;\n";
  scene_ << ind << "}\n";
}

void ScenePrinter::emitClusterTiles(const DestinationWork& w, const NeighbourPass& pass,
                                    const std::string& state, const std::string& listRadius2,
                                    const std::set<std::string>& q, const RegisterSums& sums,
                                    bool openmp) {
  const int d = w.array;
  const std::string R = "double";
  const bool selfPair = !skipsSelfPair(pass);
  // 2D (stop 39; 3D where clusterTiles2xMM(), stop 42): GROMACS' 2xMM form, layouts of
  // width 4, a register = 2 i's x the 4 j's (see the top of this file); else 8 x 8 tiles.
  const bool mm = clusterTiles2xMM();
  // Stop 40: the array kept in the tiles' slot order (update_neighbours permutes it where the
  // lists are due; the layout in that order: slot s = particle s, the last cluster padded):
  // the tiles read and write the particles' arrays (2xMM: the doubled copies stay, now
  // contiguous reads), the padded last cluster from W-value tails (cl_t_NAME, cl_tacc_NAME).
  const bool inOrder = clusterSlotOrder(w, pass);
  // Stop 41: in order the 2xMM tiles read their j side from the particles' arrays too, a
  // j-cluster's 4 values doubled into a tile-local register per tile (sphc::load_doubled4),
  // the padded cluster from its tails; `dbl`: the copies doubled per cluster per evaluation
  // instead (stops 39-40: out of order, or --cluster-2d-doubled). `arrays`: the tiles read
  // the particles' arrays (in order, but for the doubled copies).
  const bool dbl = mm && (!inOrder || cluster2dDoubled_);
  const bool arrays = inOrder && !dbl;
  // The copies in slot order: positions first, then every property the lanes read (by name:
  // di_NAME, sj_NAME, s_NAME and d_NAME of one array are one array), the hoisted values, the
  // sums. name -> the array it is gathered from.
  std::vector<std::pair<std::string, std::string>> copies;
  std::set<std::string> named;
  auto copy = [&](const std::string& name, const std::string& from) {
    if (named.insert(name).second) copies.push_back({name, from});
  };
  const char* axes[3] = {"x", "y", "z"};
  for (int k = 0; k < plan_.dim; ++k) copy(axes[k], "");
  for (const std::string& p : pass.shared) copy(p, "di_" + p);
  for (const std::string& p : pass.sourceProps) copy(p, "s_" + p);
  std::set<std::string> dvals;  // the destination values (dval_NAME) the bodies read
  for (const PlanEquation* eq : pass.equations)
    for (const auto& [p, sc] : destinationValues(methodBody(*eq, ast::Method::Loop), d)) {
      copy(p, "d_" + p);
      dvals.insert(p);
    }
  std::vector<std::string> hoisted, dhoisted;  // pointers in the tiles: source, destination
  // Stop 46: a source-hoisted value another equation of the pass hoists too (the same doubles
  // in one array, Hoist.cpp) is loaded once, its pointer that one's (hoistedAlias); a
  // destination-only value of the parameters alone is the pass's (passDestinationHoisted, a
  // local copy in the tiles), not a per-particle array loaded per tile.
  const std::map<std::string, std::string> hoistedAlias = sameSourceHoisted(pass);
  std::map<std::string, std::string> passValues;  // the pass's value -> the tiles' local copy
  for (const PlanEquation* eq : pass.equations) {
    const PlanBody& b = methodBody(*eq, ast::Method::Loop);
    for (size_t k = 0; k < hoistedSites(b, host_).size(); ++k) {
      const std::string ptr = hoistArgument(eqStruct(*eq), std::to_string(k));
      if (hoistedAlias.count(ptr)) continue;
      hoisted.push_back(ptr);
      copy(ptr, ptr);
    }
    for (size_t k = 0; k < hoistedDestinationSites(b, host_).size(); ++k) {
      const std::string once = passDestinationHoisted(*eq, k);
      if (!once.empty()) {
        passValues[once] = "tile_" + once;
        continue;
      }
      const std::string ptr = symmetricDestinationHoisted(eqStruct(*eq), std::to_string(k));
      dhoisted.push_back(ptr);
      copy(ptr, ptr);
    }
  }
  // A lane's destination-only value k of eq: the pass's (its tiles' copy) or i's (ir_ or cl_).
  auto destinationHoistedIn = [&](const PlanEquation& eq, size_t k, const std::string& pre) {
    const std::string once = passDestinationHoisted(eq, k);
    if (!once.empty()) return passValues.at(once);
    return pre + symmetricDestinationHoisted(eqStruct(eq), std::to_string(k)) + "[d_idx]";
  };
  // The j side's pointers of the aliases, after those of the values they alias (the i side:
  // the mirrored calls' `absolute` names).
  auto hoistedAliases = [&](const std::string& ind) {
    for (const auto& [alias, of] : hoistedAlias)
      scene_ << ind << "const double* const " << alias << " = " << of
             << ";  // the same values (Hoist.cpp): loaded once\n";
  };
  // The hoisted values computed in slot order from the copies of what they read (the same
  // function of the same doubles, so the values a gather would give, padding included: a
  // padding slot holds its cluster's first particle's values; stop 39), where every property
  // they read is a copy (not the positions, whose padding lies far away): name -> the call.
  std::map<std::string, std::string> rename;
  for (const auto& c : copies)
    if (c.second.rfind("di_", 0) == 0 || c.second.rfind("s_", 0) == 0 || c.second.rfind("d_", 0) == 0)
      rename[c.first] = (dbl ? "cl2_" : "cl_") + c.first;  // 2xMM: the doubled copies
  // (2xMM: computed into the doubled arrays, at cl_s2 = CL_LANES c + l for slot CL_W c + l.)
  const std::string slotIndex = dbl ? "cl_s2" : "s_idx";
  std::map<std::string, std::string> inSlots;
  for (const PlanEquation* eq : pass.equations) {
    const PlanBody& b = methodBody(*eq, ast::Method::Loop);
    for (size_t k = 0; k < hoistedSites(b, host_).size(); ++k) {
      const std::string call = hoistedCall(*eq, k, true, slotIndex, rename);
      if (!call.empty()) inSlots[hoistArgument(eqStruct(*eq), std::to_string(k))] = call;
    }
    for (size_t k = 0; k < hoistedDestinationSites(b, host_).size(); ++k) {
      const std::string call = hoistedCall(*eq, k, false, slotIndex, rename);
      if (!call.empty()) inSlots[symmetricDestinationHoisted(eqStruct(*eq), std::to_string(k))] = call;
    }
  }
  // In order: what a copy is read from (the pass's own pointers; the hoisted values' arrays
  // in the particles' order).
  auto origin = [&](const std::pair<std::string, std::string>& c) {
    return c.second.empty() ? "di_" + c.first : c.second;
  };
  bool allDestinationInSlots = true;
  for (const std::string& h : dhoisted) allDestinationInSlots &= inSlots.count(h) > 0;
  // The sums, one lane array per component (stop 40): NAME (stride 1) or K_NAME (component K
  // of a property of stride S, d_NAME[S * d_idx + K]); their locals in the lanes acc_NAME,
  // accK_NAME (the bodies' _simd forms' names, RegisterSums.cpp).
  std::vector<std::string> accs;
  std::map<std::string, std::string> accLocal;           // lane name -> the bodies' local
  std::map<std::string, std::pair<int, int>> accStride;  // lane name -> stride, component
  for (const auto& [p, sc] : sums.props)
    for (int k : sc.second) {
      const std::string lane = sc.first == 1 ? p : std::to_string(k) + "_" + p;
      accs.push_back(lane);
      accLocal[lane] = sumsLocalName(p, sc.first, k);
      accStride[lane] = {sc.first, k};
    }
  // In order (stop 40, the tile branches merged): the sums go straight onto the particles'
  // arrays, a component's onto d_NAME + K with the property's stride (no add-back); its
  // tail (the padded cluster's j sides) strided the same. `idx`: a slot.
  // Measured (docs/performance-log.md, "The tile branches merged"): the components' sums
  // straight onto the particles' arrays, strided, cost the own dam break's shifting tiles 25%
  // more than they saved (the fold's stride-2 and stride-4 writes); so in order a sum with
  // components keeps its slot sums (zeroed per block) and an add-back in the particles'
  // order (slot s = particle s: no slot map), unless kComponentsInPlace.
  constexpr bool kComponentsInPlace = false;
  auto direct = [&](const std::string& p) {
    return inOrder && (accStride[p].first == 1 || kComponentsInPlace);
  };
  auto accStrideOf = [&](const std::string& p) { return direct(p) ? accStride[p].first : 1; };
  auto accAt = [&](const std::string& p, const std::string& idx) {
    const int S = accStrideOf(p);
    return S == 1 ? "[" + idx + "]" : "[" + std::to_string(S) + " * (" + idx + ")]";
  };
  size_t accTailWidths = 0;  // the sums' tails, in units of CL_W
  size_t nSlotAccs = 0;  // the sums with slot sums in the buffer
  for (const std::string& p : accs) {
    if (direct(p)) accTailWidths += static_cast<size_t>(accStrideOf(p));
    else ++nSlotAccs;
  }
  const std::string in = "          ";
  if (mm)
    scene_ << "        // Each pair once for both particles in cluster-pair tiles (codegen/ClusterPairs.cpp;\n"
              "        // sphc --simd-pairs=cluster), GROMACS' 2xMM form: 4-clusters of i's x 4-clusters\n"
              "        // of j's of the runtime's cluster-pair lists (sphc/cluster_pairs.h, a layout of\n"
              "        // width 4), a tile in two registers of 8 lanes (lane l: i 2 r + l / 4, j l % 4),\n"
              "        // rebuilt with the kept lists (verlet_build; the lists themselves are not built),\n"
              "        // pruned at the support per evaluation; the sums reassociated (lane sums per i\n"
              "        // across its list, per j across a tile).\n";
  else
    scene_ << "        // Each pair once for both particles in cluster-pair tiles (codegen/ClusterPairs.cpp;\n"
              "        // sphc --simd-pairs=cluster): 8 i's x 8 j's of the runtime's cluster-pair lists\n"
              "        // (sphc/cluster_pairs.h), rebuilt with the kept lists (verlet_build; the lists\n"
              "        // themselves are not built), pruned at the support per evaluation; the sums\n"
              "        // reassociated (lane sums per i across its list, per j across a tile).\n";
  // The destination-only values of every particle, for the mirrored calls (gathered below;
  // a loop without neighbours: --omp-min-particles' `if`, stop 39).
  const std::string ompIfN = openmp ? ompMinIf("n") : "";  // "" or if (n >= OMP_MIN_PARTICLES)
  if (!allDestinationInSlots || arrays)
    emitDestinationHoistedAll(pass, openmp ? "        #pragma omp parallel for schedule(static)" +
                                                 (ompIfN.empty() ? "" : " " + ompIfN) + "\n" : "",
                              ompSpace(w));
  // The loops the CPU printer kept before this pass (its initialize, the hoisted values) and
  // the one above: one parallel region (OmpRegions.cpp); nothing below before the tiles.
  ompQueueFlush(scene_);
  // The properties nothing writes between two builds (no live equation or stepper writes
  // them: PlanProperty::written; a sort of the particles rebuilds the layout) are copied at
  // the build only; the largest h too where nothing writes h (stop 39). The slot buffer is
  // this pass's own: the tiles take no pass whose kept lists another pass shares
  // (CpuPrinter.cpp, "its kept lists are shared with another pass"); were that allowed, a
  // pass would have to copy again where another one filled the buffer since.
  // Kept lists shared with other passes in tiles (stop 40): the layout is rebuilt by
  // whichever pass sees the rebuild first, so a pass copies everything at each evaluation.
  const std::pair<int, int> share = clusterListsShare(w, pass);
  auto unchanged = [&](const std::string& p) {
    const PlanProperty* prop = arr(d).find(p);
    return prop && !prop->written && share.second == 1;
  };
  const bool hFixed = unchanged("h");
  // Under OpenMP the pieces without neighbours honour --omp-min-particles (their `if`).
  const std::string par = ompIfN.empty() ? "" : ", n >= OMP_MIN_PARTICLES";
  scene_ << "        {\n";
  // The tiles' shape: CL_LANES lanes per register (one zmm of doubles: the runtime's
  // kClusterSize), CL_W slots per cluster (the layout's width).
  scene_ << in << "constexpr int CL_LANES = sphc::kClusterSize;  // the lanes of a register: one zmm of doubles\n";
  if (mm)
    scene_ << in << "constexpr int CL_W = CL_LANES / 2;  // 2xMM: the layout's width; a register holds 2 i's x CL_W j's\n";
  else
    scene_ << in << "constexpr int CL_W = CL_LANES;  // the layout's width; a register holds one i x CL_W j's\n";
  scene_ << in << "static_assert(CL_LANES == 8 && CL_W <= sphc::kMaxClusterSize, \"codegen/ClusterPairs.cpp prints "
                  "its lane tables for registers of 8 doubles (sphc::kClusterSize)\");\n";
  scene_ << in << "sphc::ClusterLayout& cl_layout = " << state << "_layout;\n";
  const std::string zIn = plan_.dim == 3 ? "di_z" : "nullptr";
  if (hUniform_[d]) {  // (analysis/UniformH.cpp: every particle's h the same, all the run)
    scene_ << in << "const double cl_hmax = n > 0 ? std::max(0.0, di_h[0]) : 0.0;  // the largest h: h uniform\n";
  } else if (hFixed) {
    scene_ << in << "// the largest h: at the build (nothing writes h)\n";
    scene_ << in << "if (verlet_build) {\n";
    scene_ << in << "  double cl_hmax_build = 0.0;\n";
    if (openmp)  // (stop 41; max is exact: the same value whatever the threads)
      scene_ << in << "  #pragma omp parallel for schedule(static) reduction(max: cl_hmax_build)"
             << (ompIfN.empty() ? "" : " " + ompIfN) << "\n";
    scene_ << in << "  for (int i = 0; i < n; ++i) cl_hmax_build = std::max(cl_hmax_build, di_h[i]);\n";
    scene_ << in << "  " << state << "_hmax = cl_hmax_build;\n";
    scene_ << in << "}\n";
    scene_ << in << "const double cl_hmax = " << state << "_hmax;  // the largest h now\n";
  } else {
    scene_ << in << "double cl_hmax = 0.0;  // the largest h now\n";
    if (openmp)
      scene_ << in << "#pragma omp parallel for schedule(static) reduction(max: cl_hmax)"
             << (ompIfN.empty() ? "" : " " + ompIfN) << "\n";
    scene_ << in << "for (int i = 0; i < n; ++i) cl_hmax = std::max(cl_hmax, di_h[i]);\n";
  }
  const std::string side = emitClusterColumnSide(d, mm, "verlet_build && n > 0", "n", in);
  scene_ << in << "if (verlet_build) sphc::" << (inOrder ? "build_cluster_layout_in_order" : "build_cluster_layout")
         << "(cl_layout, di_x, di_y, " << zIn << ", static_cast<std::size_t>(n), DIM, " << side << ", CL_W);\n";
  if (inOrder)
    scene_ << in << "const std::uint32_t cl_tail = static_cast<std::uint32_t>(sphc::tail_cluster(cl_layout));  // the padded cluster (n_clusters: none)\n";
  scene_ << in << "const std::size_t n_slots = cl_layout.slots();\n";
  scene_ << in << "std::vector<double>& cl_buf = " << state << "_slots"
         << (share.first ? std::to_string(share.first) : "") << ";\n";
  // 2xMM: after the copies and the sums, each copy doubled per cluster (cl2_NAME: cluster c's
  // CL_W values twice, the j side of a register in one contiguous load).
  // (2xMM: the positions alone in slot order, for the boxes; every copy doubled)
  const size_t nSlotCopies = inOrder ? 0 : mm ? static_cast<size_t>(plan_.dim) : copies.size();
  const size_t nAccs = nSlotAccs;  // in order: the plain sums in the particles' arrays
  const size_t nBuf = nSlotCopies + nAccs + (dbl ? 2 * copies.size() : 0);
  // In order: the tails (the padded cluster's values, CL_W each) after the slot buffers.
  const size_t nTails = inOrder ? (dbl ? 0 : copies.size()) + accTailWidths : 0;
  // In order (stop 41): the slot sums (of the sums with components) are zero between
  // evaluations, their add-back zeroing them as it reads them (no fill per evaluation); a
  // buffer of another size (n_slots changed: the tails move) zeroed here.
  const bool zeroedSlotSums = inOrder && nSlotAccs > 0;
  const std::string bufSize = std::to_string(nBuf) + " * n_slots" + (nTails ? " + " + std::to_string(nTails) + " * CL_W" : "");
  if (zeroedSlotSums)
    scene_ << in << "const bool cl_resized = cl_buf.size() != " << bufSize << ";\n";
  scene_ << in << "cl_buf.resize(" << bufSize << ");  // (kept: the copies made at the build)\n";
  if (zeroedSlotSums)
    scene_ << in << "if (cl_resized) std::fill(cl_buf.begin(), cl_buf.begin() + " << nSlotAccs
           << " * n_slots, 0.0);  // the slot sums: zero (then kept so by their add-back)\n";
  size_t at = 0;
  for (size_t k = 0; k < nSlotCopies; ++k)
    scene_ << in << "double* const cl_" << copies[k].first << " = cl_buf.data() + " << at++ << " * n_slots;\n";
  for (const std::string& p : accs)
    if (!direct(p)) scene_ << in << "double* const cl_acc_" << p << " = cl_buf.data() + " << at++ << " * n_slots;\n";
  if (dbl)
    for (const auto& c : copies) {
      scene_ << in << "double* const cl2_" << c.first << " = cl_buf.data() + " << at << " * n_slots;\n";
      at += 2;
    }
  // In order: the tails' pointers (printed again in the tiles).
  auto tailPointers = [&](const std::string& ind) {
    size_t k = 0;
    if (!dbl)
      for (const auto& c : copies)
        scene_ << ind << "double* const cl_t_" << c.first << " = cl_buf.data() + " << at << " * n_slots + " << k++ << " * CL_W;\n";
    for (const std::string& p : accs) {
      if (!direct(p)) continue;
      scene_ << ind << "double* const cl_tacc_" << p << " = cl_buf.data() + " << at << " * n_slots + " << k << " * CL_W;\n";
      k += static_cast<size_t>(accStrideOf(p));
    }
  };
  if (inOrder) tailPointers(in);
  scene_ << in << "// The positions in slot order (padding slots 4 supports away from every particle)\n"
         << in << "// and the boxes in one pass, the outer list at a rebuild, the list pruned at the\n"
         << in << "// support now.\n";
  if (inOrder && dbl) {
    scene_ << in << "// (in order: the boxes and the doubled positions from the particles' own)\n";
    scene_ << in << "sphc::positions_doubled_boxes(cl_layout, di_x, di_y, " << zIn << ", cl2_x, cl2_y, "
           << (plan_.dim == 3 ? "cl2_z" : "nullptr") << ", 4.0 * Kernel::radius_scale * cl_hmax" << par << ");\n";
  } else if (inOrder) {
    scene_ << in << "// (in order: the boxes from the particles' positions, the padded cluster's in its tail)\n";
    scene_ << in << "sphc::update_boxes(cl_layout, di_x, di_y, " << zIn << par << ");\n";
    scene_ << in << "sphc::tail_positions(cl_layout, di_x, di_y, " << zIn << ", cl_t_x, cl_t_y, "
           << (plan_.dim == 3 ? "cl_t_z" : "nullptr") << ", 4.0 * Kernel::radius_scale * cl_hmax);\n";
  } else {
    scene_ << in << "sphc::gather_positions_boxes(cl_layout, di_x, di_y, " << zIn << ", cl_x, cl_y, "
           << (plan_.dim == 3 ? "cl_z" : "nullptr") << ", 4.0 * Kernel::radius_scale * cl_hmax" << par << ");\n";
  }
  scene_ << in << "if (verlet_build) sphc::build_cluster_pairs(cl_layout, cl_layout, std::sqrt("
         << listRadius2 << ") * cl_hmax, true, " << state << "_outer" << par << ");\n";
  if (inOrder) {
    scene_ << in << "if (verlet_build) {  // (stop 40) sorted again where the clusters loosened: 5% more cluster pairs\n"
           << in << "  const double cl_pairs = static_cast<double>(" << state << "_outer.pairs()) / static_cast<double>(std::max<std::size_t>(1, cl_layout.n_clusters));\n"
           << in << "  if (" << state << "_sorted) " << state << "_pairs0 = cl_pairs;  // the reference: just sorted\n"
           << in << "  else if (cl_pairs > " << kSlotOrderLoosened << " * " << state << "_pairs0) " << state << "_order_due = true;\n"
           << in << "  " << state << "_sorted = false;\n"
           << in << "}\n";
  }
  scene_ << in << "sphc::prune_cluster_pairs(cl_layout, cl_layout, " << state
         << "_outer, Kernel::radius_scale * cl_hmax, " << state << "_pruned" << par << ");\n";
  scene_ << in << "const sphc::ClusterPairList& cl_pruned = " << state << "_pruned;\n";
  // The other copies in one pass each: those nothing writes at the build, the rest now.
  std::vector<std::pair<std::string, std::string>> fixedCopies, evalCopies;
  for (const auto& c : copies) {
    if (c.second.empty()) continue;  // the positions
    const bool prop = c.second.rfind("di_", 0) == 0 || c.second.rfind("s_", 0) == 0 || c.second.rfind("d_", 0) == 0;
    const std::string name = prop ? c.second.substr(c.second.find('_') + 1) : "";
    if (inSlots.count(c.first)) continue;  // computed from the copies below
    (prop && unchanged(name) ? fixedCopies : evalCopies).push_back(c);
  }
  auto gathers = [&](const std::vector<std::pair<std::string, std::string>>& cs, const std::string& ind) {
    scene_ << ind << "const double* const cl_from[] = {";
    for (size_t k = 0; k < cs.size(); ++k) scene_ << (k ? ", " : "") << cs[k].second;
    scene_ << "};\n";
    scene_ << ind << "double* const cl_to[] = {";
    for (size_t k = 0; k < cs.size(); ++k) scene_ << (k ? ", " : "") << (dbl ? "cl2_" : "cl_") << cs[k].first;
    scene_ << "};\n";
    scene_ << ind << (dbl ? "sphc::gather_slots_doubled" : "sphc::gather_slots") << "(cl_layout, cl_from, cl_to, "
           << cs.size() << par << ");\n";
  };
  if (arrays) {  // the tiles read the arrays themselves: the padded cluster's tails only
    fixedCopies.clear();
    evalCopies.clear();
    std::vector<std::string> from, to;
    for (size_t k = static_cast<size_t>(plan_.dim); k < copies.size(); ++k) {
      from.push_back(origin(copies[k]));
      to.push_back("cl_t_" + copies[k].first);
    }
    if (!from.empty()) {
      scene_ << in << "{  // the padded cluster's values (its padding lanes: its first particle's)\n";
      scene_ << in << "  const double* const cl_from[] = {";
      for (size_t k = 0; k < from.size(); ++k) scene_ << (k ? ", " : "") << from[k];
      scene_ << "};\n" << in << "  double* const cl_to[] = {";
      for (size_t k = 0; k < to.size(); ++k) scene_ << (k ? ", " : "") << to[k];
      scene_ << "};\n" << in << "  sphc::gather_tail(cl_layout, cl_from, cl_to, " << from.size() << ");\n" << in << "}\n";
    }
  }
  if (!fixedCopies.empty()) {
    scene_ << in << "if (verlet_build) {  // the copies of what nothing writes: at the build only\n";
    gathers(fixedCopies, in + "  ");
    scene_ << in << "}\n";
  }
  if (!evalCopies.empty()) {
    scene_ << in << "{  // the copies of what changes between builds\n";
    gathers(evalCopies, in + "  ");
    scene_ << in << "}\n";
  }
  if (mm && !inOrder) {  // the positions doubled (the copies above are doubled as they are gathered)
    scene_ << in << "// The positions doubled: cluster c's CL_W values twice (the j side of a register in\n"
           << in << "// one load of 8 lanes; the i-cluster's registers from its first half).\n";
    if (openmp)
      scene_ << in << "#pragma omp parallel for schedule(static)" << (ompIfN.empty() ? "" : " " + ompIfN) << "\n";
    scene_ << in << "for (std::size_t c = 0; c < cl_layout.n_clusters; ++c) {\n";
    scene_ << in << "  #pragma omp simd  // (one vector of CL_W per copy: without it GCC 12 stores every value alone)\n";
    scene_ << in << "  for (int l = 0; l < CL_W; ++l) {\n";
    for (int k = 0; k < plan_.dim; ++k) {
      const auto& c = copies[k];
      scene_ << in << "    const double v_" << c.first << " = cl_" << c.first << "[CL_W * c + l];\n";
      scene_ << in << "    cl2_" << c.first << "[CL_LANES * c + l] = v_" << c.first << ";\n";
      scene_ << in << "    cl2_" << c.first << "[CL_LANES * c + CL_W + l] = v_" << c.first << ";\n";
    }
    scene_ << in << "  }\n";
    scene_ << in << "}\n";
  }
  if (dbl && !inSlots.empty()) {
    scene_ << in << "// the hoisted values in slot order from the doubled copies (the same function of the\n"
           << in << "// same doubles as in the particles' order: the values a gather would copy), doubled\n";
    if (openmp)
      scene_ << in << "#pragma omp parallel for schedule(static)" << (ompIfN.empty() ? "" : " " + ompIfN) << "\n";
    scene_ << in << "for (std::size_t c = 0; c < cl_layout.n_clusters; ++c)\n";
    scene_ << in << "  for (int l = 0; l < CL_W; ++l) {\n";
    scene_ << in << "    const int cl_s2 = static_cast<int>(CL_LANES * c) + l;  // slot CL_W c + l, first half\n";
    for (const auto& c : copies)
      if (auto it = inSlots.find(c.first); it != inSlots.end())
        scene_ << in << "    cl2_" << c.first << "[cl_s2] = cl2_" << c.first << "[cl_s2 + CL_W] = " << it->second << ";\n";
    scene_ << in << "  }\n";
  } else if (!inSlots.empty() && !inOrder) {
    scene_ << in << "// the hoisted values in slot order from the copies (the same function of the same\n"
           << in << "// doubles as in the particles' order: the values a gather would copy)\n";
    if (openmp)
      scene_ << in << "#pragma omp parallel for schedule(static)" << (ompIfN.empty() ? "" : " " + ompIfN) << "\n";
    scene_ << in << "for (int s_idx = 0; s_idx < static_cast<int>(n_slots); ++s_idx) {\n";
    for (const auto& c : copies)
      if (auto it = inSlots.find(c.first); it != inSlots.end())
        scene_ << in << "  cl_" << c.first << "[s_idx] = " << it->second << ";\n";
    scene_ << in << "}\n";
  }
  // The tiles, in a lambda without jump threading (see above), over the i-clusters [cb, ce)
  // of one block: serial, one block of them all; OpenMP, blocks in parallel, the same sums.
  // OpenMP (stop 44): without loop splitting too, which cut the loop over the i-clusters at
  // ci == cb into two copies of the tile code, the earlier blocks' and the block's own
  // (docs/performance-log.md "Cold compile back under 3 s (stop 44)").
  scene_ << "#if defined(__GNUC__) && !defined(__clang__)\n"
            "#define SPHC_TILES_OPTIMIZE __attribute__((optimize(\"no-thread-jumps\""
         << (openmp ? ", \"no-split-loops\"" : "") << ")))\n"
            "#else\n"
            "#define SPHC_TILES_OPTIMIZE\n"
            "#endif\n";
  if (openmp)
    scene_ << in << "// OpenMP: contiguous blocks of i-clusters, one per thread, balanced by the pruned\n"
           << in << "// list's pairs and half tiles; a block writes only its own slots' sums, each sum\n"
           << in << "// in the serial order whatever the blocks (so the serial tiles' bits for any\n"
           << in << "// thread count):\n"
           << in << "// (1) the j sides of the tiles of EARLIER i-clusters whose j-cluster is in the\n"
           << in << "//     block (j-side half tiles, i-clusters in increasing order: the serial order\n"
           << in << "//     of those tiles' sums, which come before the block's own),\n"
           << in << "// (2) the block's i-clusters: their tiles with j-clusters in the block for both\n"
           << in << "//     sides, those with j-clusters in LATER blocks for the i side only (i-side\n"
           << in << "//     half tiles: the later block computes their j sides in its (1)).\n"
           << in << "// A tile across two blocks is computed twice, each side once: a half tile is the\n"
           << in << "// whole tile with its other side's sums left unwritten (one copy of the tile's code).\n";
  if (inOrder && accs.size() > nSlotAccs) {
    scene_ << in << "// the padded cluster's j-side sums (written by the block that holds it only)\n";
    for (const std::string& p : accs)
      if (direct(p))
        scene_ << in << "std::fill(cl_tacc_" << p << ", cl_tacc_" << p << " + "
             << (accStrideOf(p) == 1 ? "" : std::to_string(accStrideOf(p)) + " * ") << "CL_W, 0.0);\n";
  }
  scene_ << in << "auto tiles = [&](const int cb, const int ce) SPHC_TILES_OPTIMIZE {\n";
  const std::string t = in + "  ";
  if (mm) {
    scene_ << t << "// lane l of a register: its i the register's first + l / CL_W, its j l % CL_W\n";
    scene_ << t << "static constexpr double cl_ilane[8] = {0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0};\n";
    scene_ << t << "static constexpr double cl_jlane[8] = {0.0, 1.0, 2.0, 3.0, 0.0, 1.0, 2.0, 3.0};\n";
  } else {
    scene_ << t << "static constexpr double cl_lane[8] = {0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0};\n";
  }
  // The copies' pointers again, locals of the lambda (captured by reference, GCC reloads them
  // in the loops), and the lists' arrays.
  at = 0;
  if (arrays) {
    scene_ << t << "// in order: slot s is particle s (cl_NAME: the arrays), the padded cluster's tails\n";
    for (const auto& c : copies) scene_ << t << "const double* const cl_" << c.first << " = " << origin(c) << ";\n";
  }
  for (size_t k = 0; k < nSlotCopies; ++k)
    if (!mm) scene_ << t << "double* const cl_" << copies[k].first << " = cl_buf.data() + " << at++ << " * n_slots;\n";
    else ++at;  // (2xMM: the tiles read the doubled copies only)
  for (const std::string& p : accs)
    if (direct(p))
      scene_ << t << "double* const cl_acc_" << p << " = "
             << (accStride[p].first == 1 ? "d_" + p
                                         : "d_" + p.substr(p.find('_') + 1) + " + " + std::to_string(accStride[p].second))
             << ";  // (in order: the particles' sums" << (accStride[p].first == 1 ? "" : ", stride " + std::to_string(accStride[p].first)) << ")\n";
    else
      scene_ << t << "double* const cl_acc_" << p << " = cl_buf.data() + " << at++ << " * n_slots;\n";
  if (dbl)
    for (const auto& c : copies) {
      scene_ << t << "const double* const cl2_" << c.first << " = cl_buf.data() + " << at << " * n_slots;\n";
      at += 2;
    }
  if (inOrder) tailPointers(t);
  // The equations' values as locals (stop 40): read through the scene in the lanes, GCC 12
  // loaded those read under a mask (a body's branch) by gathers with every lane at one
  // address (8 vgatherqpd per register in the own dam break's rates pass).
  {
    std::set<std::string> eqs;
    for (const PlanEquation* eq : pass.equations)
      if (eqs.insert(eqStruct(*eq)).second)
        scene_ << t << "const auto " << eqStruct(*eq) << " = this->" << eqStruct(*eq) << ";  // "
               << eq->name << "'s values, a local copy\n";
  }
  uniformHLocals(t);  // h uniform (stop 45): the lambda's own copies
  for (const auto& [once, local] : passValues)
    scene_ << t << "const double " << local << " = " << once << ";  // the pass's value: a local copy\n";
  scene_ << t << "const std::uint32_t* const cl_begin = cl_pruned.begin.data();\n";
  scene_ << t << "const std::uint32_t* const cl_j = cl_pruned.j.data();\n";
  scene_ << t << "const std::uint8_t* const cl_real = cl_layout.real_mask.data();\n";
  if (!mm) {
    scene_ << t << "// The destination side: the copies at d_idx, the slot of particle i.\n";
    for (const std::string& p : pass.shared)
      scene_ << t << "const double* const di_" << p << " = cl_" << p << ";\n";
  }
  if (nSlotAccs && !zeroedSlotSums) scene_ << t << "// the block's slot sums (only this block writes them)\n";
  for (const std::string& p : accs)
    if (!direct(p) && !zeroedSlotSums)
    scene_ << t << "std::fill(cl_acc_" << p << " + CL_W * static_cast<std::size_t>(cb), cl_acc_" << p
           << " + CL_W * static_cast<std::size_t>(ce), 0.0);\n";
  // 2xMM: the i-cluster's two registers' values (ri_NAME[r][lane], i = 2 r + lane / CL_W),
  // once per i-cluster.
  auto iRegisters = [&](const std::string& c1) {
    scene_ << c1 << "// its two registers' i's: lane l of register r holds slot ci CL_W + 2 r + l / CL_W\n";
    for (const auto& c : copies) scene_ << c1 << "alignas(64) double ri_" << c.first << "[2][CL_LANES];\n";
    if (arrays) {  // (stop 41) from the particles' arrays, the padded cluster from its tails
      scene_ << c1 << "const bool cl_it = static_cast<std::uint32_t>(ci) == cl_tail;\n";
      scene_ << c1 << "const int i0 = cl_it ? 0 : ci * CL_W;  // its first slot (the tails': 0)\n";
      // (stop 47) each array's source chosen once, not at each of its 16 reads: GCC compiled
      // the choice in the reads as a compare and a branch each, ~900 instructions an i-cluster
      // in the own dam break's rates pass (docs/performance-log.md, "The i-clusters' values
      // (stop 47)")
      for (const auto& c : copies)
        scene_ << c1 << "const double* const ci_" << c.first << " = (cl_it ? cl_t_" << c.first
               << " : cl_" << c.first << ") + i0;\n";
    }
    scene_ << c1 << "for (int l = 0; l < CL_W; ++l) {\n";
    for (const auto& c : copies) {
      const std::string src = arrays ? "ci_" + c.first + "[" : "cl2_" + c.first + "[CL_LANES * ci + ";
      scene_ << c1 << "  ri_" << c.first << "[0][l] = " << src << "0]; ri_" << c.first << "[0][CL_W + l] = "
             << src << "1]; ri_" << c.first << "[1][l] = " << src << "2]; ri_" << c.first
             << "[1][CL_W + l] = " << src << "3];\n";
    }
    scene_ << c1 << "}\n";
  };
  // The j side's sums: in order the padded cluster's in its tails.
  auto jAcc = [&](const std::string& p) {
    return (direct(p) ? "ja_" : "cl_acc_") + p;
  };
  // --cluster-queue (stop 43; docs/performance-log.md "The tiles' pairs compacted (stop 43)"):
  // the 8 x 8 tiles' pairs within the support compacted, 8 to a register. Not for the 2xMM
  // form, a pass that keeps the self pair (its two sides' masks differ on the diagonal) or one
  // whose bodies call a rare math function (their marked lanes' fix-up is per row).
  const bool queueTiles = clusterQueue_ && !mm && !selfPair && !rareCalls(pass);
  // One tile (j-cluster cl_j[e] of i-cluster ci), both sides; jKept (OpenMP): the condition
  // under which its j sums are added (its j-cluster in the block), empty: always.
  auto tile = [&](const std::string& c2, const std::string& jKept) {
    const std::string L = "CL_LANES";  // the lanes of a register
    if (mm) {
      if (inOrder) {
        scene_ << c2 << "const bool jt = cl_j[e] == cl_tail;  // the padded cluster: its sums in its tails\n";
        scene_ << c2 << "const int j0 = jt ? 0 : static_cast<int>(cl_j[e]) * CL_W;  // its first slot\n";
      } else {
        scene_ << c2 << "const int j0 = static_cast<int>(cl_j[e]) * CL_W;  // its first slot\n";
      }
      if (dbl) scene_ << c2 << "const int j2 = static_cast<int>(cl_j[e]) * CL_LANES;  // in the doubled copies\n";
    } else {
      if (inOrder) {
        scene_ << c2 << "const bool jt = cl_j[e] == cl_tail;  // the padded cluster: from its tails\n";
        scene_ << c2 << "const int j0 = jt ? 0 : static_cast<int>(cl_j[e]) * CL_W;\n";
      } else {
        scene_ << c2 << "const int j0 = static_cast<int>(cl_j[e]) * CL_W;\n";
      }
    }
    const std::string jOff = dbl ? "cl2_" : "cl_";
    const std::string jAt = dbl ? " + j2" : " + j0";
    // (in order, 8 x 8: the padded cluster's values from its tails; 2xMM reading the arrays:
    // the tile-local doubled registers tj2_NAME)
    auto jPtr = [&](const std::string& name) {
      if (mm && arrays) return "tj2_" + name;
      return !mm && inOrder ? "(jt ? cl_t_" + name + " : cl_" + name + ")" + jAt : jOff + name + jAt;
    };
    scene_ << c2 << "const bool diagonal = cl_j[e] == static_cast<std::uint32_t>(ci);\n";
    if (mm && arrays) {
      scene_ << c2 << "// The source side: the j-cluster's CL_W values twice in tile-local registers, s_idx the\n"
             << c2 << "// lane (stop 41: from the particles' arrays, the padded cluster from its tails).\n";
      for (const auto& c : copies) scene_ << c2 << "alignas(64) double tj2_" << c.first << "[CL_LANES];\n";
      for (const auto& c : copies)
        scene_ << c2 << "sphc::load_doubled4(tj2_" << c.first << ", (jt ? cl_t_" << c.first << " : cl_" << c.first << ") + j0);\n";
    } else if (mm)
      scene_ << c2 << "// The source side: the j-cluster's CL_W slots twice (the doubled copies), s_idx the lane.\n";
    else
      scene_ << c2 << "// The source side: the j-cluster's 8 slots, s_idx the lane.\n";
    for (const std::string& p : pass.shared)
      scene_ << c2 << "const double* const sj_" << p << " = " << jPtr(p) << ";\n";
    for (const std::string& p : pass.sourceProps)
      scene_ << c2 << "const double* const s_" << p << " = " << jPtr(p) << ";\n";
    for (const std::string& h : hoisted) scene_ << c2 << "const double* const " << h << " = " << jPtr(h) << ";\n";
    hoistedAliases(c2);
    // (the mirrored calls read particle s_idx's destination values through d_NAME)
    for (const std::string& p : dvals) scene_ << c2 << "const double* const d_" << p << " = " << jPtr(p) << ";\n";
    for (const std::string& h : dhoisted) scene_ << c2 << "const double* const " << h << " = " << jPtr(h) << ";\n";
    scene_ << c2 << "// j's sums over the tile's i's" << (mm ? " (lanes l and l + CL_W: j l)" : "") << "\n";
    for (const std::string& p : accs) scene_ << c2 << "alignas(64) double tj_" << p << "[" << L << "] = {};\n";
    std::string c3 = c2 + "  ";
    // --cluster-queue (stop 43): the rows below are printed, then moved after the queue's
    // form as its #else (the queue's lanes print with laneBody, defined with the rows).
    const bool queue = queueTiles;
    const std::streampos rowsAt = scene_.tellp();
    if (mm) {
      scene_ << c2 << "for (int r = 0; r < 2 && (real_i >> (2 * r) & 1u); ++r) {  // the registers with a real i (first)\n";
      scene_ << c3 << "// the register's i's: d_idx is the lane too (ir_NAME: the i of lane d_idx)\n";
      for (const auto& c : copies) scene_ << c3 << "const double* const ir_" << c.first << " = ri_" << c.first << "[r];\n";
      for (const std::string& p : pass.shared) scene_ << c3 << "const double* const di_" << p << " = ir_" << p << ";\n";
      scene_ << c3 << "// the diagonal tile: lanes j > i (" << (selfPair ? "and the self pair j == i for d_idx" : "the self pair skipped: every body adds zeros there") << ")\n";
      scene_ << c3 << "const double lane_s = diagonal ? 2.0 * r : -8.0;  // + cl_ilane: the lane's i in the cluster\n";
      scene_ << c3 << "const double lane_d = lane_s" << (selfPair ? " - 1.0" : "") << ";\n";
    } else {
      scene_ << c2 << "for (int ii = 0; ii < CL_W && (real_i >> ii & 1u); ++ii) {  // the real i's (first)\n";
      scene_ << c3 << "const int d_idx = ci * CL_W + ii;\n";
      emitDestLocals(scene_, c3, q, host_);
      for (const PlanEquation* eq : pass.equations) {
        const PlanBody& b = methodBody(*eq, ast::Method::Loop);
        for (size_t k = 0; k < hoistedDestinationSites(b, host_).size(); ++k) {
          const std::string K = std::to_string(k);
          scene_ << c3 << "const double " << hoistDestinationArgument(eqStruct(*eq), K) << " = "
                 << destinationHoistedIn(*eq, k, "cl_") << ";\n";
        }
      }
      for (const std::string& p : dvals)  // the destination's values (the d_NAME above are offset)
        scene_ << c3 << "const double " << destinationValueName(p, 1, 0) << " = cl_" << p << "[d_idx];\n";
      {  // the mirrored calls' source values: particle d_idx's
        std::set<std::string> loads;
        for (const PlanEquation* eq : pass.equations)
          for (const auto& [p, sc] : sourceValues(methodBody(*eq, ast::Method::Loop)))
            if (loads.insert(sourceValueName(p, 1, 0)).second)
              scene_ << c3 << "const double " << sourceValueName(p, 1, 0) << " = cl_" << p << "[d_idx];\n";
      }
      scene_ << c3 << "// the diagonal tile: lanes j > i (" << (selfPair ? "and the self pair j == i for d_idx" : "the self pair skipped: every body adds zeros there") << ")\n";
      scene_ << c3 << "const double lane_s = diagonal ? static_cast<double>(ii) : -1.0;\n";
      scene_ << c3 << "const double lane_d = diagonal ? static_cast<double>(ii" << (selfPair ? " - 1" : "") << ") : -1.0;\n";
    }
    // 2xMM: the i's values of a lane (d_idx = the lane), at the top of a lane loop's body.
    auto laneDest = [&](const std::string& b) {
      scene_ << b << "const int d_idx = s_idx;  // the lane's i: its values ir_NAME[d_idx]\n";
      emitDestLocals(scene_, b, q, host_);
      for (const PlanEquation* eq : pass.equations) {
        const PlanBody& pb = methodBody(*eq, ast::Method::Loop);
        for (size_t k = 0; k < hoistedDestinationSites(pb, host_).size(); ++k) {
          const std::string K = std::to_string(k);
          scene_ << b << "const double " << hoistDestinationArgument(eqStruct(*eq), K) << " = "
                 << destinationHoistedIn(*eq, k, "ir_") << ";\n";
        }
      }
      for (const std::string& p : dvals)
        scene_ << b << "const double " << destinationValueName(p, 1, 0) << " = ir_" << p << "[d_idx];\n";
      std::set<std::string> loads;
      for (const PlanEquation* eq : pass.equations)
        for (const auto& [p, sc] : sourceValues(methodBody(*eq, ast::Method::Loop)))
          if (loads.insert(sourceValueName(p, 1, 0)).second)
            scene_ << b << "const double " << sourceValueName(p, 1, 0) << " = ir_" << p << "[d_idx];\n";
    };
    // The lane's position in the diagonal tile's comparisons.
    const std::string jl = mm ? "cl_jlane[s_idx]" : "cl_lane[s_idx]";
    const std::string il = mm ? "cl_ilane[s_idx] + " : "";
    // The row's (register's) cut-off alone first: a row with no pair within it is skipped.
    // (a double sum of 0 or 1: an int reduction makes GCC 12 take 8 int lanes, so this loop in
    // 256-bit vectors, 10-12% more per sweep in bench/cluster_pairs.cpp)
    // 8 x 8 (stop 42; docs/performance-log.md "The 3D tiles' rows (stop 42)"): the branch is
    // data-dependent (1.7 of a tile's 8 rows have no pair in the cube), so what it costs is how
    // long its condition takes: under AVX-512 one compare mask tested at once
    // (sphc::tile_row_any, kortest), else the lanes' test reduced by max (a tree of 3 steps)
    // rather than + (8 scalar adds in a chain): the cube's tiles 0.91x and 0.93x of the sum's
    // time, the same rows skipped (the sums bit for bit).
    if (!mm && uhI_ && uhJ_) {  // h uniform (stop 45): the row's test against one cut-off
      scene_ << "#if defined(__AVX512F__)\n";
      scene_ << c3 << "if (!sphc::tile_row_any_cut<DIM>(xi, yi, " << (plan_.dim == 3 ? "zi" : "0.0")
             << ", sj_x, sj_y, " << (plan_.dim == 3 ? "sj_z" : "nullptr") << ", cl_lane, "
             << "lane_d, " << cutoffValue("RADIUS2") << ")) continue;  // no pair of the row within the support\n";
      scene_ << "#else\n";
    } else if (!mm) {
      scene_ << "#if defined(__AVX512F__)\n";
      scene_ << c3 << "if (!sphc::tile_row_any<DIM>(xi, yi, " << (plan_.dim == 3 ? "zi" : "0.0")
             << ", hi, sj_x, sj_y, " << (plan_.dim == 3 ? "sj_z" : "nullptr") << ", sj_h, cl_lane, "
             << "lane_d, RADIUS2)) continue;  // no pair of the row within the support\n";
      scene_ << "#else\n";
    } else {
      // 2xMM (stop 46): the register's test the same way (sphc::tile_row_any2, each lane's i
      // from the register's ri_NAME[r]): the max reduction's chain took ~11% of the own dam
      // break's shifting tiles (docs/performance-log.md "The own dam break's shifting tiles
      // (stop 46)"); the same registers skipped.
      const std::string zs = plan_.dim == 3 ? "ir_z, " : "nullptr, ";
      const std::string zj = plan_.dim == 3 ? "sj_z, " : "nullptr, ";
      scene_ << "#if defined(__AVX512F__)\n";
      if (uhI_ && uhJ_)
        scene_ << c3 << "if (!sphc::tile_row_any2_cut<DIM>(ir_x, ir_y, " << zs << "sj_x, sj_y, " << zj
               << "cl_jlane, cl_ilane, lane_d, " << cutoffValue("RADIUS2") << ")) continue;  // no pair of the register within the support\n";
      else
        scene_ << c3 << "if (!sphc::tile_row_any2<DIM>(ir_x, ir_y, " << zs << "ir_h, sj_x, sj_y, " << zj
               << "sj_h, cl_jlane, cl_ilane, lane_d, RADIUS2)) continue;  // no pair of the register within the support\n";
      scene_ << "#else\n";
    }
    scene_ << c3 << "double any = 0.0;\n";
    scene_ << c3 << "#pragma omp simd reduction(max: any)  // (a tree: + adds the lanes in a chain)\n";
    scene_ << c3 << "for (int s_idx = 0; s_idx < " << L << "; ++s_idx) {\n";
    {
      const std::string b = c3 + "  ";
      if (mm) {
        scene_ << b << "const double hi = " << hiValue("ir_h[s_idx]") << ";\n";
        for (int k = 0; k < plan_.dim; ++k)
          scene_ << b << "const double " << axes[k] << "i = ir_" << axes[k] << "[s_idx];\n";
      }
      scene_ << b << "const double hj = " << hjValue("sj_h[s_idx]") << ";\n";
      std::string r2;
      for (int k = 0; k < plan_.dim; ++k) {
        scene_ << b << "const double XIJ_" << k << " = " << axes[k] << "i - sj_" << axes[k] << "[s_idx];\n";
        r2 += (k ? " + " : "") + std::string("XIJ_") + std::to_string(k) + " * XIJ_" + std::to_string(k);
      }
      scene_ << b << "const double R2IJ = " << r2 << ";\n";
      scene_ << b << "const double hmax = " << hmaxValue() << ";\n";
      const std::string in = "!(R2IJ >= " + cutoffValue("RADIUS2") + ") & (" + jl + " > " + il + "lane_d)";
      scene_ << b << "const double in_l = " << in << " ? 1.0 : 0.0;\n";
      scene_ << b << "any = any > in_l ? any : in_l;\n";
    }
    scene_ << c3 << "}\n";
    scene_ << c3 << "if (!(any > 0.0)) continue;  // no pair of the " << (mm ? "register" : "row") << " within the support\n";
    scene_ << "#endif\n";
    for (const std::string& p : accs)
      scene_ << c3 << "double* const ti_" << p << "_i = ti_" << p << "[" << (mm ? "r" : "ii") << "];\n";
    // The lanes' body. `mode` (stop 40, a pass whose bodies call a math function GCC does not
    // vectorise, rareCalls): Lanes, the bodies' _simd forms; Marked, their _simd_rare forms,
    // a call marking the lane (sphc_rare), whose sums are then left as they were and whose
    // pair is redone after the lanes by Fixup, the _simd forms, scalar, on the marked lanes
    // alone. Each lane's sums get the same terms in the same order as if every lane were
    // computed by the _simd forms (the fix-up before the next tile).
    enum class Mode { Lanes, Marked, Fixup };
    // inQueue: the lanes of a register of queued pairs (--cluster-queue): d_idx the lane too
    // (the i's values ir_NAME), every lane before q_cnt a pair within the support.
    bool inQueue = false;
    auto laneBody = [&](const std::string& body, Mode mode) {
      if (mm || inQueue) laneDest(body);
      emitLanePairQuantities(scene_, q, true, body, false, /*negatedMirrors=*/true,
                             /*tileRecip=*/tileMathRecip_);
      scene_ << body << "const double hmax = " << hmaxValue() << ";\n";
      scene_ << body << "const bool in_cut = !(R2IJ >= " << cutoffValue("RADIUS2") << ");  // the cut-off\n";
      if (!inQueue) {
        scene_ << body << "const bool in_d = in_cut & (" << jl << " > " << il << "lane_d);  // for d_idx\n";
        scene_ << body << "const bool in_s = in_cut & (" << jl << " > " << il << "lane_s);  // for the lane's particle\n";
      }
      std::string inD = "in_d", inS = "in_s";
      if (inQueue) {  // (the self pair is never queued: --cluster-queue refuses a pass that keeps it)
        // (the lane against q_cnt as doubles, cl_lane[s_idx] < q_lanes: an int compare in the
        // lanes made GCC 12 vectorize the whole register in ymm halves under
        // -mprefer-vector-width=512; stop 44, docs/performance-log.md "The interaction loop
        // against the measured peak (stop 44)")
        scene_ << body << "const bool in_q = in_cut & (cl_lane[s_idx] < q_lanes);  // a queued pair (in_cut: the queue's own test)\n";
        inD = inS = "in_q";
      }
      emitPairSharedLocals(scene_, body, d, pass.equations, pass.equations, /*simd=*/true);
      for (const std::string& p : accs) {
        scene_ << body << "double pd_" << accLocal[p] << " = ti_" << p << "_i[s_idx];\n";
        scene_ << body << "double ps_" << accLocal[p] << " = tj_" << p << "[s_idx];\n";
      }
      // Marked: the _simd_rare forms, the lane's mark last.
      auto marked = [&](const PlanEquation& eq, std::string call) {
        if (mode != Mode::Marked ||
            scalarMathCallSites(methodBody(eq, ast::Method::Loop).source.text).empty())
          return call;
        for (const char* form : {"_simd_mirror(", "_simd("}) {
          const size_t at = call.find(form);
          if (at != std::string::npos && at < call.find('(')) {
            call.insert(at + std::string(form).size() - 1, "_rare");
            break;
          }
        }
        const size_t close = call.find(");");
        if (close != std::string::npos) call.insert(close, ", sphc_rare");
        return call;
      };
      // (the mark loaded from rare_l, zeroed before the lanes: with `= 0.0` GCC 12 left the
      // OpenMP build's half tiles scalar, "no vectype for stmt")
      if (mode == Mode::Marked)
        scene_ << body << "double sphc_rare = rare_l[s_idx];  // a body's scalar math call: the pair is redone below\n";
      for (const PlanEquation* eq : pass.equations)
        scene_ << body << marked(*eq, pairCall(*eq, d, sums, /*scalarPairs=*/true, "pd_"));
      // The mirrored calls index the source's arrays they are given as pointers (a source
      // property, a source-hoisted value) with their s_idx, d_idx here: the copies themselves,
      // not offset to the j-cluster (2xMM: the register's i's, d_idx the lane).
      {
        std::map<std::string, std::string> absolute;
        const std::string pre = mm || inQueue ? "ir_" : "cl_";
        for (const std::string& p : pass.sourceProps) absolute["s_" + p] = pre + p;
        for (const std::string& h : hoisted) absolute[h] = pre + h;
        for (const auto& [alias, of] : hoistedAlias) absolute[alias] = pre + of;
        // the pass's values: the lane's local (the same double for both particles)
        for (const PlanEquation* eq : pass.equations) {
          const PlanBody& pb = methodBody(*eq, ast::Method::Loop);
          for (size_t k = 0; k < hoistedDestinationSites(pb, host_).size(); ++k)
            if (!passDestinationHoisted(*eq, k).empty())
              absolute[passDestinationHoisted(*eq, k)] = hoistDestinationArgument(eqStruct(*eq), std::to_string(k));
        }
        for (const PlanEquation* eq : pass.equations)
          scene_ << body << marked(*eq, withArguments(simdMirroredCall(*eq, d, sums, "ps_"), absolute));
      }
      endPairShared();
      if (mode == Mode::Marked) {
        scene_ << body << "const bool in_rare = (in_d | in_s) & (sphc_rare > 0.0);  // redone below\n";
        scene_ << body << "rare_l[s_idx] = in_rare ? 1.0 : 0.0;\n";
        scene_ << body << "n_rare += in_rare ? 1.0 : 0.0;\n";
        inD = "(" + inD + " & !in_rare)";
        inS = "(" + inS + " & !in_rare)";
      }
      for (const std::string& p : accs) {
        scene_ << body << "ti_" << p << "_i[s_idx] = " << inD << " ? pd_" << accLocal[p] << " : ti_" << p << "_i[s_idx];\n";
        scene_ << body << "tj_" << p << "[s_idx] = " << inS << " ? ps_" << accLocal[p] << " : tj_" << p << "[s_idx];\n";
      }
    };
    const bool rare = rareCalls(pass);
    if (rare) {
      scene_ << c3 << "// the lanes whose pair took a body's rare path (a call GCC does not vectorise)\n";
      scene_ << c3 << "alignas(64) double rare_l[" << L << "] = {};\n";
      scene_ << c3 << "double n_rare = 0.0;\n";
    }
    scene_ << c3 << "#pragma omp simd" << (rare ? " reduction(+: n_rare)" : "") << "\n";
    scene_ << c3 << "for (int s_idx = 0; s_idx < " << L << "; ++s_idx) {\n";
    laneBody(c3 + "  ", rare ? Mode::Marked : Mode::Lanes);
    scene_ << c3 << "}\n";
    if (rare) {
      scene_ << c3 << "if (n_rare > 0.0) {  // the marked lanes' pairs, scalar, with the bodies' calls\n";
      scene_ << c3 << "  for (int s_idx = 0; s_idx < " << L << "; ++s_idx) {\n";
      scene_ << c3 << "    if (!(rare_l[s_idx] > 0.0)) continue;\n";
      laneBody(c3 + "    ", Mode::Fixup);
      scene_ << c3 << "  }\n";
      scene_ << c3 << "}\n";
    }
    scene_ << c2 << "}\n";
    if (queue) {
      const std::string all = scene_.str();
      const std::string rows = all.substr(static_cast<size_t>(rowsAt));
      scene_.str(all.substr(0, static_cast<size_t>(rowsAt)));
      scene_.seekp(0, std::ios_base::end);
      scene_ << "#if defined(__AVX512F__) && defined(__AVX512VBMI2__)\n";
      scene_ << c2 << "// The tile's pairs within the support compacted (--cluster-queue, stop 43): the rows'\n"
             << c2 << "// masks (bit 8 ii + l), their pairs' indices packed in order, 8 pairs to a register:\n"
             << c2 << "// the values by permutes of the clusters' 8 slots, the sums back per row (i: its lane\n"
             << c2 << "// partial sums, lane by lane; j: through the inverse of the row's compaction).\n";
      const std::string z = plan_.dim == 3 ? "di_z + ci * CL_W" : "nullptr";
      scene_ << c2 << "const std::uint64_t q_mask = sphc::tile_pair_mask<DIM>(di_x + ci * CL_W, di_y + ci * CL_W, "
             << z << ", di_h + ci * CL_W, real_i, sj_x, sj_y, " << (plan_.dim == 3 ? "sj_z" : "nullptr")
             << ", sj_h, diagonal, RADIUS2);\n";
      scene_ << c2 << "alignas(64) std::uint8_t q_idx[64];\n";
      scene_ << c2 << "const int q_n = q_mask ? sphc::tile_pair_list(q_mask, q_idx) : 0;\n";
      scene_ << c2 << "for (int q_v = 0; q_v < q_n; q_v += CL_LANES) {\n";
      const std::string v = c2 + "  ";
      scene_ << v << "const int q_cnt = q_n - q_v < CL_LANES ? q_n - q_v : CL_LANES;\n";
      scene_ << v << "const double q_lanes = static_cast<double>(q_cnt);  // (the lanes' test in doubles: zmm)\n";
      scene_ << v << "const sphc::TileQueueLanes q_at = sphc::tile_queue_lanes(q_idx + q_v);\n";
      scene_ << v << "// the pairs' i values (ir_NAME) and j values (q_NAME, then the j pointers' names)\n";
      for (const auto& c : copies) {
        scene_ << v << "alignas(64) double ir_" << c.first << "[CL_LANES];\n";
        scene_ << v << "sphc::tile_queue_take(ir_" << c.first << ", q_at.i, cl_" << c.first
               << " + ci * CL_W, static_cast<__mmask8>(real_i));\n";
      }
      std::vector<std::string> jNames;
      for (const std::string& p : pass.shared) jNames.push_back("sj_" + p);
      for (const std::string& p : pass.sourceProps) jNames.push_back("s_" + p);
      for (const std::string& h : hoisted) jNames.push_back(h);
      for (const std::string& p : dvals) jNames.push_back("d_" + p);
      for (const std::string& h : dhoisted) jNames.push_back(h);
      for (const std::string& n : jNames) {
        scene_ << v << "alignas(64) double q_" << n << "[CL_LANES];\n";
        scene_ << v << "sphc::tile_queue_take(q_" << n << ", q_at.j, " << n << ", 0xff);\n";
      }
      scene_ << v << "{\n";
      const std::string b = v + "  ";
      for (const std::string& n : jNames) scene_ << b << "const double* const " << n << " = q_" << n << ";\n";
      hoistedAliases(b);
      for (const std::string& p : pass.shared) scene_ << b << "const double* const di_" << p << " = ir_" << p << ";\n";
      for (const std::string& p : accs) {
        scene_ << b << "alignas(64) double qr_i_" << p << "[CL_LANES] = {};\n";
        scene_ << b << "double* const ti_" << p << "_i = qr_i_" << p << ";\n";
        scene_ << b << "double* const q_tj_" << p << " = tj_" << p << ";\n";
        scene_ << b << "alignas(64) double qr_j_" << p << "[CL_LANES] = {};\n";
        scene_ << b << "double* const tj_" << p << " = qr_j_" << p << ";\n";
      }
      scene_ << b << "#pragma omp simd\n";
      scene_ << b << "for (int s_idx = 0; s_idx < CL_LANES; ++s_idx) {\n";
      inQueue = true;
      laneBody(b + "  ", Mode::Lanes);
      inQueue = false;
      scene_ << b << "}\n";
      scene_ << b << "for (int q_k = 0; q_k < q_cnt;) {  // the sums back, row by row\n";
      scene_ << b << "  const sphc::TileQueueSegment q_s = sphc::tile_queue_segment(q_idx + q_v, q_k, q_cnt);\n";
      for (const std::string& p : accs) {
        scene_ << b << "  sphc::tile_queue_add_i(ti_" << p << "[q_s.ii], q_s, qr_i_" << p << ");\n";
        scene_ << b << "  sphc::tile_queue_add_j(q_tj_" << p << ", q_s, qr_j_" << p << ");\n";
      }
      scene_ << b << "  q_k = q_s.end;\n";
      scene_ << b << "}\n";
      scene_ << v << "}\n";
      scene_ << c2 << "}\n";
      scene_ << "#else\n" << rows << "#endif\n";
    }
    {  // the j sums folded onto the slots' sums
      const std::string c2o = c2;  // (the tile's indent; the fold's under jKept)
      const std::string c2 = jKept.empty() ? c2o : c2o + "  ";
      if (!jKept.empty())
        scene_ << c2o << "if (" << jKept << ") {  // the j side: its j-cluster in the block\n";
      if (inOrder && nSlotAccs)  // the slot sums' (the padded cluster's in its own slots)
        scene_ << c2 << "const int jslot = static_cast<int>(cl_j[e]) * CL_W;\n";
      if (inOrder)  // the fold's targets, chosen once per tile
        for (const std::string& p : accs)
          if (direct(p)) scene_ << c2 << "double* const ja_" << p << " = jt ? cl_tacc_" << p << " : cl_acc_" << p << ";\n";
      if (mm) {
        scene_ << c2 << "#pragma omp simd  // the two halves folded (j l: lanes l, l + CL_W), onto the slot sums\n";
        scene_ << c2 << "for (int l = 0; l < CL_W; ++l) {\n";
        for (const std::string& p : accs)
          scene_ << c2 << "  " << jAcc(p) << (inOrder && !direct(p) ? "[jslot + l]" : accAt(p, "j0 + l")) << " += tj_" << p << "[l] + tj_" << p << "[CL_W + l];\n";
      } else {
        scene_ << c2 << "#pragma omp simd  // (a vector: unrolled, the tj_ arrays would be scalars)\n";
        scene_ << c2 << "for (int l = 0; l < CL_LANES; ++l) {\n";
        for (const std::string& p : accs)
          scene_ << c2 << "  " << jAcc(p) << (inOrder && !direct(p) ? "[jslot + l]" : accAt(p, "j0 + l")) << " += tj_" << p << "[l];\n";
      }
      scene_ << c2 << "}\n";
      if (!jKept.empty()) scene_ << c2o << "}\n";
    }
  };
  // OpenMP (stop 44): each i-cluster's tiles printed once, whole (the half tiles were copies
  // of them: three tile bodies per pass for GCC to optimise, the pair loops' unit 1.6x the
  // serial one's CPU); a half tile computes the whole tile and keeps one side's sums.
  const std::string c1 = t + "  ";
  if (openmp) {
    scene_ << t << "for (int ci = 0; ci < ce; ++ci) {  // (1) the earlier blocks' i-clusters, (2) the block's\n";
    scene_ << c1 << "const std::uint32_t e_end = cl_begin[ci + 1];\n";
    scene_ << c1 << "if (cl_begin[ci] == e_end || (ci < cb && cl_j[e_end - 1] < static_cast<std::uint32_t>(cb))) continue;\n";
    scene_ << c1 << "std::uint32_t e_first = cl_begin[ci], e_last = e_end;\n";
    scene_ << c1 << "if (ci < cb) {  // an earlier block's i-cluster: its tiles with j-clusters in [cb, ce)\n";
    scene_ << c1 << "  e_first = static_cast<std::uint32_t>(std::lower_bound(cl_j + e_first, cl_j + e_end, static_cast<std::uint32_t>(cb)) - cl_j);\n";
    scene_ << c1 << "  e_last = static_cast<std::uint32_t>(std::lower_bound(cl_j + e_first, cl_j + e_end, static_cast<std::uint32_t>(ce)) - cl_j);\n";
    scene_ << c1 << "  if (e_first == e_last) continue;\n";
    scene_ << c1 << "}\n";
  } else {
    scene_ << t << "for (int ci = cb; ci < ce; ++ci) {\n";
    scene_ << c1 << "const std::uint32_t e_end = cl_begin[ci + 1];\n";
    scene_ << c1 << "if (cl_begin[ci] == e_end) continue;\n";
  }
  scene_ << c1 << "const unsigned real_i = cl_real[ci];\n";
  if (mm) {
    iRegisters(c1);
    scene_ << c1 << "// i's sums: per register 8 lane partial sums across its cluster pairs (i 2 r + l / CL_W)\n";
    for (const std::string& p : accs) scene_ << c1 << "alignas(64) double ti_" << p << "[2][CL_LANES] = {};\n";
  } else {
    scene_ << c1 << "// i's sums: 8 lane partial sums per i across its cluster pairs\n";
    for (const std::string& p : accs) scene_ << c1 << "alignas(64) double ti_" << p << "[CL_W][CL_LANES] = {};\n";
  }
  if (openmp) {
    scene_ << c1 << "for (std::uint32_t e = e_first; e < e_last; ++e) {\n";
    // (the j-cluster's block by its index, not by e: GCC's -fsplit-loops would split the loop
    // where e reaches the later blocks, a copy of the tile each side)
    tile(c1 + "  ", "cl_j[e] < static_cast<std::uint32_t>(ce)");
    scene_ << c1 << "}\n";
    scene_ << c1 << "if (ci < cb) continue;  // an earlier block's i-cluster: its i sums are that block's\n";
  } else {
    scene_ << c1 << "for (std::uint32_t e = cl_begin[ci]; e < e_end; ++e) {\n";
    tile(c1 + "  ", "");
    scene_ << c1 << "}\n";
  }
  if (mm) {
    scene_ << c1 << "for (int k = 0; k < CL_W" << (inOrder ? " && (real_i >> k & 1u)" : "")
           << "; ++k) {  // slot k: register k / 2, lanes (k % 2) CL_W ...\n";
    for (const std::string& p : accs) {
      scene_ << c1 << "  double s_" << p << " = 0.0;\n";
      scene_ << c1 << "  for (int l = 0; l < CL_W; ++l) s_" << p << " += ti_" << p << "[k / 2][(k % 2) * CL_W + l];\n";
      scene_ << c1 << "  cl_acc_" << p << accAt(p, "ci * CL_W + k") << " += s_" << p << ";\n";
    }
  } else {
    scene_ << c1 << "for (int ii = 0; ii < CL_W" << (inOrder ? " && (real_i >> ii & 1u)" : "") << "; ++ii) {\n";
    for (const std::string& p : accs) {
      scene_ << c1 << "  double s_" << p << " = 0.0;\n";
      scene_ << c1 << "  for (int l = 0; l < CL_LANES; ++l) s_" << p << " += ti_" << p << "[ii][l];\n";
      scene_ << c1 << "  cl_acc_" << p << accAt(p, "ci * CL_W + ii") << " += s_" << p << ";\n";
    }
  }
  scene_ << c1 << "}\n";
  scene_ << t << "}\n";
  scene_ << in << "};\n";
  if (uhPrefix_ == "uhl_") uhPrefix_ = "uh_";  // (the lambda's copies: in it only)
  if (!openmp) {
    scene_ << in << "tiles(0, static_cast<int>(cl_layout.n_clusters));\n";
  } else {
    scene_ << in << "{  // the blocks: balanced by the pruned list's pairs, a tile across two blocks as its\n"
           << in << "   // two halves (sphc::tile_block_cuts; the sums do not depend on them)\n";
    scene_ << in << "  const int n_ci = static_cast<int>(cl_layout.n_clusters);\n";
    scene_ << in << "  const int n_blocks = std::max(1, std::min(n_ci, omp_get_max_threads()));\n";
    scene_ << in << "  std::vector<int> cl_cb;\n";
    scene_ << in << "  sphc::tile_block_cuts(cl_pruned, n_blocks, cl_cb);\n";
    scene_ << in << "  #pragma omp parallel for schedule(static, 1)\n";
    scene_ << in << "  for (int blk = 0; blk < n_blocks; ++blk) tiles(cl_cb[blk], cl_cb[blk + 1]);\n";
    scene_ << in << "}\n";
  }
  if (inOrder && accs.size() > nSlotAccs) {
    scene_ << in << "// In order the tiles summed onto the particles' sums, but for the padded cluster's\n"
           << in << "// j sides, in its tails: added to its real particles.\n";
    scene_ << in << "if (cl_tail < cl_layout.n_clusters)\n";
    scene_ << in << "  for (std::size_t s = static_cast<std::size_t>(cl_tail) * CL_W, l = 0; s < cl_layout.n; ++s, ++l) {\n";
    for (const std::string& p : accs) {
      if (!direct(p)) continue;
      const auto [S, K] = accStride[p];
      if (S == 1)
        scene_ << in << "    d_" << p << "[s] += cl_tacc_" << p << "[l];\n";
      else
        scene_ << in << "    d_" << p.substr(p.find('_') + 1) << "[" << S << " * s + " << K << "] += cl_tacc_" << p << "[" << S << " * l];\n";
    }
    scene_ << in << "  }\n";
  }
  if (!inOrder) scene_ << in << "// The slot sums onto the particles' sums (padding slots never read), in one pass.\n";
  std::vector<std::string> plain, strided;  // stride 1: add_slots; components: a loop
  if (!inOrder)  // (in order: none, the tiles summed onto the particles' arrays)
    for (const std::string& p : accs) (accStride[p].first == 1 ? plain : strided).push_back(p);
  if (!plain.empty()) {
    scene_ << in << "{\n";
    scene_ << in << "  const double* const cl_sums[] = {";
    for (size_t k = 0; k < plain.size(); ++k) scene_ << (k ? ", " : "") << "cl_acc_" << plain[k];
    scene_ << "};\n";
    scene_ << in << "  double* const cl_into[] = {";
    for (size_t k = 0; k < plain.size(); ++k) scene_ << (k ? ", " : "") << "d_" << plain[k];
    scene_ << "};\n";
    scene_ << in << "  sphc::add_slots(cl_layout, cl_sums, cl_into, " << plain.size() << par << ");\n";
    scene_ << in << "}\n";
  }
  const bool initHere = initInAddBack_ == &w;
  initInAddBack_ = nullptr;  // (the first pass's only)
  if (initHere && !(inOrder && nSlotAccs == accs.size() && nSlotAccs > 0))
    throw std::logic_error("codegen/ClusterPairs.cpp: the initialize in the add-back of tiles without one");
  if (inOrder && nSlotAccs) {
    scene_ << in << "{  // (in order) the components' slot sums onto the particles' (slot s = particle s)\n";
    if (initHere)
      scene_ << in << "  // with the destination's initialize first, per particle (initInAddBackRefusal;\n"
             << in << "  // sphc --no-init-in-add-back: in a loop before the pass)\n";
    if (openmp)
      scene_ << in << "  #pragma omp parallel for schedule(static)" << (ompIfN.empty() ? "" : " " + ompIfN) << "\n";
    scene_ << in << "  for (std::size_t s = 0; s < cl_layout.n; ++s) {\n";
    if (initHere) {
      scene_ << in << "    const int d_idx = static_cast<int>(s);\n";
      for (const PlanEquation* eq : w.initialize)
        scene_ << in << "    " << equationCall(*eq, ast::Method::Initialize, d);
    }
    for (const std::string& p : accs) {
      if (direct(p)) continue;
      const auto [S, K] = accStride[p];
      scene_ << in << "    d_" << p.substr(p.find('_') + 1) << "[" << S << " * s + " << K << "] += cl_acc_" << p << "[s];\n";
    }
    for (const std::string& p : accs)  // (stop 41) zero for the next evaluation: no fill there
      if (!direct(p)) scene_ << in << "    cl_acc_" << p << "[s] = 0.0;\n";
    scene_ << in << "  }\n";
    for (const std::string& p : accs)  // the padding slots' (only zeros are added there)
      if (!direct(p))
        scene_ << in << "  std::fill(cl_acc_" << p << " + cl_layout.n, cl_acc_" << p << " + n_slots, 0.0);\n";
    scene_ << in << "}\n";
  }
  if (!strided.empty()) {
    // The components' slot sums onto d_NAME[S * i + K] (stop 40), in slot order: the slot
    // sums read in order, a particle's S components written together (one pass over the
    // particles read 2 x 7 slot arrays at random: 4% of the dam break's step at ~100k).
    scene_ << in << "{  // the sums with components onto the particles' (padding slots skipped)\n";
    scene_ << in << "  const std::uint32_t* const cl_slot = cl_layout.slot.data();\n";
    if (openmp)
      scene_ << in << "  #pragma omp parallel for schedule(static)" << (ompIfN.empty() ? "" : " " + ompIfN) << "\n";
    scene_ << in << "  for (std::size_t s = 0; s < n_slots; ++s) {\n";
    scene_ << in << "    const std::uint32_t i = cl_slot[s];\n";
    scene_ << in << "    if (i == sphc::kPadSlot) continue;\n";
    for (const std::string& p : strided) {
      const auto [S, K] = accStride[p];
      const std::string prop = p.substr(p.find('_') + 1);
      scene_ << in << "    d_" << prop << "[" << S << " * i + " << K << "] += cl_acc_" << p << "[s];\n";
    }
    scene_ << in << "  }\n";
    scene_ << in << "}\n";
  }
  scene_ << "        }\n";
}

}  // namespace sphc
