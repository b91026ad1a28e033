// The geometry builders an array may use, with their arguments. Sema checks `geometry`
// declarations against this table; the code generator maps them to runtime/geometry.h.
#pragma once

#include <string>
#include <vector>

namespace sphc {

struct GeometryArg {
  std::string name;
  const char* defaultValue;  // nullptr: required
};

struct GeometryBuilder {
  std::string name;
  std::vector<GeometryArg> args;
};

const std::vector<GeometryBuilder>& geometryBuilders();
const GeometryBuilder* findGeometryBuilder(const std::string& name);

}  // namespace sphc
