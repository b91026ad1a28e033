// Inlets and outlets of a scene into Plan::zones (sema/Zones.h).
//
//   inlet NAME(array = A, feeds = F, x = X, y = Y, z = Z, nx = NX, ny = NY, nz = NZ,
//              length = L, width = W, u = U, v = V, w = W, copy = [p, q, ...]);
//   outlet NAME(array = A, from = F, x = .., nx = .., length = .., width = .., copy = [..],
//               type = do_nothing | mirror | characteristic | hybrid,
//               c = C, p_ref = P, tau = T);   // c, p_ref, tau: characteristic and hybrid
//
// (x, y, z): a point on the face between the fluid and the zone; (nx, ny, nz): the outward
// normal (away from the fluid); length: the zone's depth along it; width: its extent across.
// u, v, w: the inlet velocity, expressions of params, x, y, z and t.
#include "sema/Zones.h"
#include "frontend/FormatNumber.h"
#include "sema/ConstEval.h"
#include "sema/Sema.h"

#include "llvm/Support/Format.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <set>

namespace sphc {

namespace {

struct Box {
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  llvm::SMLoc loc;
  bool empty() const { return !(lo[0] <= hi[0]); }
  void add(const double p[3]) {
    for (int k = 0; k < 3; ++k) lo[k] = std::fmin(lo[k], p[k]), hi[k] = std::fmax(hi[k], p[k]);
  }
};

// The boxes of an array's `block` and `tank` geometry, with the default parameters (others
// are skipped: the checks are about what can be known before the run).
std::vector<Box> geometryBoxes(const ast::ArrayDecl& a, int dim, ConstEval& eval) {
  std::vector<Box> boxes;
  for (const auto& g : a.geometry) {
    if (g.builder.name != "block" && g.builder.name != "tank") continue;
    std::map<std::string, double> v = {{"zmin", 0.0}, {"zmax", 0.0}};
    bool ok = true;
    for (const auto& kw : g.args) {
      if (!kw.value || kw.name.name == "where") continue;  // where: the box still bounds
      auto x = eval(*kw.value);
      if (x) v[kw.name.name] = *x;
      else if (kw.name.name != "dx") ok = false;
    }
    if (!ok) continue;
    const char* lo[3] = {"xmin", "ymin", "zmin"};
    const char* hi[3] = {"xmax", "ymax", "zmax"};
    Box b;
    b.loc = g.builder.loc;
    for (int k = 0; k < 3; ++k) {
      if (k >= dim) {
        b.lo[k] = b.hi[k] = 0.0;
        continue;
      }
      if (!v.count(lo[k]) || !v.count(hi[k])) ok = false;
      else b.lo[k] = v[lo[k]], b.hi[k] = v[hi[k]];
    }
    if (ok) boxes.push_back(b);
  }
  return boxes;
}

struct ZoneValues {
  double point[3] = {0, 0, 0}, normal[3] = {0, 0, 0}, length = 0, width = 0;
  // (s, tangential offsets) of a position.
  double depth(const double p[3], int dim) const {
    double s = 0;
    for (int k = 0; k < dim; ++k) s += (p[k] - point[k]) * normal[k];
    return s;
  }
  double across(const double p[3], int dim) const {  // largest tangential offset
    const double s = depth(p, dim);
    double t = 0;
    for (int k = 0; k < dim; ++k) t = std::fmax(t, std::fabs(p[k] - point[k] - s * normal[k]));
    return t;
  }
  // The corners of a box (8 in 3D, 4 in 2D).
  static std::vector<std::array<double, 3>> corners(const Box& b, int dim) {
    std::vector<std::array<double, 3>> c;
    for (int m = 0; m < (1 << dim); ++m) {
      std::array<double, 3> p = {0, 0, 0};
      for (int k = 0; k < dim; ++k) p[k] = (m >> k) & 1 ? b.hi[k] : b.lo[k];
      c.push_back(p);
    }
    return c;
  }
  // The zone's own bounding box.
  Box box(int dim) const {
    Box b;
    // Tangent directions: in 2D (-ny, nx); in 3D the zone is bounded per axis by the
    // width around the point off the normal, and the length along it.
    for (int si = 0; si < 2; ++si)
      for (int m = 0; m < (1 << (dim - 1)); ++m) {
        double p[3] = {0, 0, 0};
        const double s = si ? length : 0.0;
        for (int k = 0; k < dim; ++k) p[k] = point[k] + s * normal[k];
        if (dim == 2) {
          const double t = (m & 1 ? 0.5 : -0.5) * width;
          p[0] += -normal[1] * t;
          p[1] += normal[0] * t;
        } else if (dim == 3) {
          for (int k = 0; k < 3; ++k)
            if (std::fabs(normal[k]) < 0.5) p[k] += ((m >> (k > 0 ? k - 1 : 0)) & 1 ? 0.5 : -0.5) * width;
        }
        b.add(p);
      }
    for (int k = dim; k < 3; ++k) b.lo[k] = b.hi[k] = 0.0;
    return b;
  }
};

}  // namespace

bool buildZones(const ast::SceneDecl& scene, Plan& plan, DiagnosticEngine& diags) {
  const unsigned errorsBefore = diags.errorCount();
  ConstEval eval(plan);
  std::set<std::string> params;
  for (const auto* p : plan.params) params.insert(p->name.name);
  const int dim = plan.dim;
  // The kernel support with default parameters: radius_scale * the largest declared h.
  std::optional<double> hmax;
  for (const auto& a : plan.arrays)
    for (const auto& p : a.decl->properties)
      if (p.name.name == "h" && p.init)
        if (auto h = eval(*p.init)) hmax = hmax ? std::fmax(*hmax, *h) : *h;
  const std::optional<double> support =
      hmax ? std::optional<double>(plan.kernelRadiusScale * *hmax) : std::nullopt;

  std::set<std::string> names;
  for (const auto& z : scene.zones) {
    const std::string what = std::string(z.inlet ? "inlet" : "outlet") + " '" + z.name.name + "'";
    if (!names.insert(z.name.name).second) {
      diags.error(z.name.loc, "a second zone named '" + z.name.name + "'");
      continue;
    }
    PlanZone pz;
    pz.inlet = z.inlet;
    pz.name = z.name.name;
    pz.loc = z.loc;
    const std::string otherKey = z.inlet ? "feeds" : "from";
    std::map<std::string, const ast::KwArg*> args;
    std::set<std::string> known = {"array", otherKey, "x", "y", "z", "nx", "ny", "nz",
                                   "length", "width", "copy"};
    if (z.inlet) known.insert({"u", "v", "w"});
    else known.insert({"type", "c", "p_ref", "tau"});
    bool ok = true;
    for (const auto& kw : z.args) {
      if (!known.count(kw.name.name)) {
        std::string list;
        for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
        diags.error(kw.name.loc, "unknown argument '" + kw.name.name + "' of " + what +
                                     " (it takes " + list + ")");
        ok = false;
      } else if (!args.emplace(kw.name.name, &kw).second) {
        diags.error(kw.name.loc, "argument '" + kw.name.name + "' given twice");
        ok = false;
      }
    }
    auto arrayArg = [&](const std::string& key) {
      auto it = args.find(key);
      if (it == args.end()) {
        diags.error(z.name.loc, what + " needs '" + key + " = ARRAY'");
        return -1;
      }
      const ast::KwArg& kw = *it->second;
      if (kw.isList || !kw.value || kw.value->kind != ast::Expr::Name) {
        diags.error(kw.name.loc, "'" + key + "' of " + what + " is an array name");
        return -1;
      }
      int a = plan.arrayIndex(kw.value->text);
      if (a < 0) diags.error(kw.value->loc, "unknown array '" + kw.value->text + "' in " + what);
      return a;
    };
    pz.array = arrayArg("array");
    pz.other = arrayArg(otherKey);
    if (pz.array >= 0 && pz.array == pz.other) {
      diags.error(z.name.loc, what + ": 'array' and '" + otherKey + "' name the same array");
      ok = false;
    }
    auto expr = [&](const std::string& key, bool required, bool ofPosition) -> ast::ExprPtr {
      auto it = args.find(key);
      if (it == args.end()) {
        if (required) {
          diags.error(z.name.loc, what + " needs '" + key + " = ...'");
          ok = false;
        }
        return nullptr;
      }
      const ast::KwArg& kw = *it->second;
      if (kw.isList || !kw.value) {
        diags.error(kw.name.loc, "'" + key + "' of " + what + " is an expression");
        ok = false;
        return nullptr;
      }
      auto isKnown = [&](const std::string& n) {
        return params.count(n) || (ofPosition && (n == "x" || n == "y" || n == "z" || n == "t"));
      };
      if (!checkExpr(*kw.value, isKnown, "'" + key + "' of " + what, diags)) ok = false;
      return kw.value;
    };
    const char* axes[3] = {"x", "y", "z"};
    const char* normals[3] = {"nx", "ny", "nz"};
    const char* vels[3] = {"u", "v", "w"};
    for (int k = 0; k < 3; ++k) {
      pz.point[k] = expr(axes[k], false, false);
      pz.normal[k] = expr(normals[k], false, false);
      if (k >= dim && (pz.point[k] || pz.normal[k]))
        diags.warning(z.name.loc, what + ": '" + axes[k] + "' and '" + normals[k] +
                                      "' are ignored in a " + std::to_string(dim) + "D scene");
      if (z.inlet) pz.velocity[k] = expr(vels[k], false, true);
    }
    pz.length = expr("length", true, false);
    pz.width = expr("width", dim > 1, false);
    if (auto it = args.find("copy"); it != args.end()) {
      if (!it->second->isList) {
        diags.error(it->second->name.loc, "'copy' of " + what + " is a list of properties, "
                                          "as in copy = [m, h, rho, u, v, p]");
        ok = false;
      }
      for (const auto& p : it->second->list) pz.copy.push_back(p.name);
    }
    if (auto it = args.find("type"); it != args.end()) {
      const ast::KwArg& kw = *it->second;
      const std::string t = kw.value && kw.value->kind == ast::Expr::Name ? kw.value->text : "";
      if (t == "do_nothing" || t == "mirror" || t == "characteristic" || t == "hybrid") {
        pz.type = t;
      } else {
        diags.error(kw.value ? kw.value->loc : kw.name.loc,
                    "outlet type is do_nothing, mirror, characteristic or hybrid" +
                        (t.empty() ? std::string() : " (found '" + t + "')"));
        ok = false;
      }
    }
    if (!z.inlet) {
      // The sound speed (characteristic and hybrid, required), the reference pressure and the
      // averaging time.
      const bool characteristic = pz.type == "characteristic";
      const bool hybrid = pz.type == "hybrid";
      for (const char* key : {"c", "p_ref", "tau"})
        if (auto it = args.find(key); it != args.end() && !characteristic && !hybrid) {
          diags.error(it->second->name.loc, "'" + std::string(key) + "' of " + what +
                                                " is for type = characteristic or hybrid only");
          ok = false;
        }
      if (characteristic || hybrid) {
        pz.c = expr("c", true, false);
        pz.pRef = expr("p_ref", false, false);
        pz.tau = expr("tau", false, false);
        // Sound speed and averaging time must be positive (the defaults of the params).
        for (const auto& [key, e] : {std::pair<const char*, ast::ExprPtr>{"c", pz.c},
                                     std::pair<const char*, ast::ExprPtr>{"tau", pz.tau}}) {
          if (!e) continue;
          if (auto x = eval(*e); x && !(*x > 0.0)) {
            diags.error(e->loc, "'" + std::string(key) + "' of " + what + " must be positive (" +
                                    (std::string(key) == "c" ? "the sound speed" : "the averaging time") +
                                    "; it is " + formatNumber(*x) + ")");
            ok = false;
          }
        }
      }
    }
    if (pz.array < 0 || pz.other < 0 || !ok) continue;
    const PlanArray& A = plan.arrays[pz.array];
    if (A.stepper < 0)
      diags.error(z.name.loc, what + ": array '" + A.name + "' has no stepper, so its "
                              "particles never move" + (z.inlet ? " into the fluid" : "") +
                              "; give it one (stepper " + A.name + " = ...;)");

    // Numbers, with the parameters' defaults.
    ZoneValues v;
    bool known_values = true;
    for (int k = 0; k < dim; ++k) {
      auto p = pz.point[k] ? eval(*pz.point[k]) : std::optional<double>(0.0);
      auto n = pz.normal[k] ? eval(*pz.normal[k]) : std::optional<double>(0.0);
      if (!p || !n) known_values = false;
      else v.point[k] = *p, v.normal[k] = *n;
    }
    auto len = eval(*pz.length);
    auto wid = pz.width ? eval(*pz.width) : std::optional<double>(1.0);
    if (!len || !wid) known_values = false;
    else v.length = *len, v.width = *wid;
    if (known_values) {
      double n2 = 0;
      for (int k = 0; k < dim; ++k) n2 += v.normal[k] * v.normal[k];
      if (!(n2 > 0)) {
        diags.error(z.name.loc, what + ": the outward normal (nx, ny" +
                                    std::string(dim == 3 ? ", nz" : "") +
                                    ") has zero length; give the direction pointing away from "
                                    "the fluid, e.g. nx = 1.0");
        continue;
      }
      for (int k = 0; k < dim; ++k) v.normal[k] /= std::sqrt(n2);
      if (!(v.length > 0) || (dim > 1 && !(v.width > 0))) {
        diags.error(z.name.loc, what + ": length " + formatNumber(v.length) + " and width " +
                                    formatNumber(v.width) + " must be positive");
        continue;
      }
      if (support && v.length < *support) {
        diags.error(args.at("length")->name.loc,
                    what + " is " + formatNumber(v.length) +
                        " deep, narrower than the kernel support " + formatNumber(*support) + " (" +
                        formatNumber(plan.kernelRadiusScale) + " x h = " + formatNumber(*hmax) +
                        "): particles near its face would miss neighbours; "
                        "make length at least " + formatNumber(*support));
      }
      const Box zb = v.box(dim);
      if (z.inlet) {
        // Other arrays (walls) with particles inside the inlet zone.
        std::set<int> zoneArrays;
        for (const auto& d : scene.zones)
          for (const auto& kw : d.args)
            if (kw.name.name == "array" && kw.value && kw.value->kind == ast::Expr::Name)
              zoneArrays.insert(plan.arrayIndex(kw.value->text));
        for (int a = 0; a < static_cast<int>(plan.arrays.size()); ++a) {
          if (a == pz.array || a == pz.other || zoneArrays.count(a)) continue;
          for (const Box& b : geometryBoxes(*plan.arrays[a].decl, dim, eval)) {
            double overlap = HUGE_VAL;
            for (int k = 0; k < dim; ++k)
              overlap = std::fmin(overlap, std::fmin(b.hi[k], zb.hi[k]) -
                                               std::fmax(b.lo[k], zb.lo[k]));
            if (overlap > 1e-9 * std::fmax(v.length, v.width)) {
              std::string range;
              for (int k = 0; k < dim; ++k)
                range += std::string(k ? " x " : "") + "[" + formatNumber(zb.lo[k]) + ", " +
                         formatNumber(zb.hi[k]) + "]";
              std::string brange;
              for (int k = 0; k < dim; ++k)
                brange += std::string(k ? " x " : "") + "[" + formatNumber(b.lo[k]) + ", " +
                          formatNumber(b.hi[k]) + "]";
              diags.error(z.name.loc, what + " (" + range + ") overlaps array '" +
                                          plan.arrays[a].name + "' (" + brange +
                                          "): its particles would be inside the inlet");
              diags.note(b.loc, "the geometry of '" + plan.arrays[a].name + "' is here");
            }
          }
        }
      } else {
        // An outlet the fluid cannot reach: beside the fluid's extent, or farther from it
        // than a kernel support.
        Box fluid;
        for (const Box& b : geometryBoxes(*plan.arrays[pz.other].decl, dim, eval)) {
          fluid.add(b.lo);
          fluid.add(b.hi);
        }
        if (!fluid.empty()) {
          double smax = -HUGE_VAL, tmin = HUGE_VAL;
          for (auto& c : ZoneValues::corners(fluid, dim)) smax = std::fmax(smax, v.depth(c.data(), dim));
          // Tangential reach: the closest approach of the fluid box to the zone's
          // cross-section, per tangential axis (boxes: intervals).
          bool beside = false;
          if (dim > 1) {
            for (int k = 0; k < dim; ++k) {
              if (std::fabs(v.normal[k]) > 1e-12 && std::fabs(v.normal[k]) < 1 - 1e-12) {
                beside = false;  // an oblique normal: no tangential test
                break;
              }
              if (std::fabs(v.normal[k]) > 0.5) continue;
              const double lo = v.point[k] - 0.5 * v.width, hi = v.point[k] + 0.5 * v.width;
              if (fluid.hi[k] < lo || fluid.lo[k] > hi) beside = true;
            }
          }
          (void)tmin;
          const double reach = support ? *support : 0.0;
          if (beside) {
            diags.error(z.name.loc, what + ": no particle of '" + plan.arrays[pz.other].name +
                                        "' can reach it: its cross-section (width " +
                                        formatNumber(v.width) +
                                        " around the point) lies beside them");
          } else if (smax < -reach) {
            diags.error(z.name.loc,
                        what + ": no particle of '" + plan.arrays[pz.other].name +
                            "' can reach it: the nearest is " + formatNumber(-smax) +
                            " from its face, farther than the kernel support " +
                            formatNumber(reach) + " (is the normal pointing away from the fluid?)");
          }
        }
      }
    }
    // What the manager reads and writes on the host.
    auto addProp = [&](int a, const std::string& p) {
      auto& zp = plan.arrays[a].zoneProps;
      if (std::find(zp.begin(), zp.end(), p) == zp.end()) zp.push_back(p);
    };
    for (const auto& p : pz.copy) {
      addProp(pz.array, p);
      addProp(pz.other, p);
    }
    for (int k = 0; k < dim; ++k) addProp(pz.array, axes[k]);
    if (z.inlet)
      for (int k = 0; k < 3; ++k)
        if (pz.velocity[k]) addProp(pz.array, vels[k]);
    plan.zones.push_back(std::move(pz));
  }
  return diags.errorCount() == errorsBefore;
}

}  // namespace sphc
