#include "sema/Geometry.h"

namespace sphc {

const std::vector<GeometryBuilder>& geometryBuilders() {
  static const std::vector<GeometryBuilder> builders = {
      {"block", {{"xmin", nullptr}, {"xmax", nullptr}, {"ymin", "0"}, {"ymax", "0"},
                 {"zmin", "0"}, {"zmax", "0"}, {"dx", nullptr}}},
      {"tank", {{"xmin", nullptr}, {"xmax", nullptr}, {"ymin", "0"}, {"ymax", "0"},
                {"zmin", "0"}, {"zmax", "0"}, {"dx", nullptr}, {"layers", "3"}, {"top", "0"}}},
      {"disk", {{"cx", nullptr}, {"cy", nullptr}, {"r", nullptr}, {"dx", nullptr}}},
      {"sphere",
       {{"cx", nullptr}, {"cy", nullptr}, {"cz", nullptr}, {"r", nullptr}, {"dx", nullptr}}},
      {"cylinder", {{"cx", nullptr}, {"cy", nullptr}, {"r", nullptr}, {"zmin", nullptr},
                    {"zmax", nullptr}, {"dx", nullptr}}},
      {"line", {{"x0", nullptr}, {"y0", "0"}, {"z0", "0"}, {"x1", nullptr}, {"y1", "0"},
                {"z1", "0"}, {"dx", nullptr}}},
  };
  return builders;
}

const GeometryBuilder* findGeometryBuilder(const std::string& name) {
  for (const auto& b : geometryBuilders())
    if (b.name == name) return &b;
  return nullptr;
}

}  // namespace sphc
