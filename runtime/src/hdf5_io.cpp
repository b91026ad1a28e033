// sphc runtime: HDF5 / XDMF / CSV input and output (see hdf5_io.h for the file layout).
#include "sphc/hdf5_io.h"

#include <hdf5.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "hdf5_types.h"

namespace sphc {
namespace {

constexpr const char* kConstantsGroup = "constants";
constexpr const char* kPositions[] = {"x", "y", "z"};

// ---------------------------------------------------------------------------------------------
// Files written atomically: everything goes to `path + ".tmp"`, renamed at the end.

std::string tmp_path(const std::string& path) { return path + ".tmp"; }

void replace_with_tmp(const std::string& path) {
  const std::string tmp = tmp_path(path);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    throw std::runtime_error(
        fmt::format("cannot rename '{}' to '{}': {}", tmp, path, std::strerror(err)));
  }
}

// Runs `write(tmp)`, then renames tmp to path; on failure removes tmp and rethrows.
template <class Write>
void write_atomically(const std::string& path, Write&& write) {
  const std::string tmp = tmp_path(path);
  try {
    write(tmp);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  replace_with_tmp(path);
}

// ---------------------------------------------------------------------------------------------
// HDF5 handles and errors.

// An owned HDF5 identifier, closed by the matching H5?close function.
class Hid {
 public:
  using Closer = herr_t (*)(hid_t);
  Hid() = default;
  Hid(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  Hid(const Hid&) = delete;
  Hid& operator=(const Hid&) = delete;
  Hid(Hid&& o) noexcept : id_(o.id_), closer_(o.closer_) { o.id_ = H5I_INVALID_HID; }
  Hid& operator=(Hid&& o) noexcept {
    if (this != &o) {
      close();
      id_ = o.id_;
      closer_ = o.closer_;
      o.id_ = H5I_INVALID_HID;
    }
    return *this;
  }
  ~Hid() { close(); }

  hid_t get() const { return id_; }
  // Closes now and returns the status (for files: a failed close is a failed write).
  herr_t close() {
    herr_t status = 0;
    if (id_ >= 0 && closer_) status = closer_(id_);
    id_ = H5I_INVALID_HID;
    return status;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer closer_ = nullptr;
};

// Innermost description on HDF5's error stack (the root cause), then clears the stack.
std::string hdf5_error_detail() {
  std::string detail;
  auto walk = [](unsigned, const H5E_error2_t* err, void* data) -> herr_t {
    auto* out = static_cast<std::string*>(data);
    if (out->empty() && err->desc && *err->desc) *out = err->desc;
    return 0;
  };
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, walk, &detail);
  H5Eclear2(H5E_DEFAULT);
  return detail;
}

// Turns HDF5 failures in one file into std::runtime_error naming the file and object.
class H5File {
 public:
  explicit H5File(std::string path) : path_(std::move(path)) {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  const std::string& path() const { return path_; }

  [[noreturn]] void fail(const std::string& object, const std::string& what) const {
    const std::string detail = hdf5_error_detail();
    std::string msg = fmt::format("HDF5 file '{}', '{}': {}", path_, object, what);
    if (!detail.empty()) msg += fmt::format(" ({})", detail);
    throw std::runtime_error(msg);
  }
  Hid own(hid_t id, Hid::Closer closer, const std::string& object, const char* what) const {
    if (id < 0) fail(object, what);
    return Hid(id, closer);
  }
  void check(herr_t status, const std::string& object, const char* what) const {
    if (status < 0) fail(object, what);
  }
  // Property lists, dataspaces and datatypes.
  Hid plist(hid_t cls, const char* what) const { return own(H5Pcreate(cls), H5Pclose, "/", what); }
  Hid space(int rank, const hsize_t* dims, const std::string& object) const {
    return own(H5Screate_simple(rank, dims, nullptr), H5Sclose, object, "cannot create dataspace");
  }

 private:
  std::string path_;
};

std::string child_path(const std::string& parent, const std::string& name) {
  return parent == "/" ? "/" + name : parent + "/" + name;
}

// A group creation property list that tracks link and attribute creation order.
Hid ordered_group_plist(const H5File& f) {
  Hid gcpl = f.plist(H5P_GROUP_CREATE, "cannot create group property list");
  const unsigned flags = H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED;
  f.check(H5Pset_link_creation_order(gcpl.get(), flags), "/", "cannot set link order");
  f.check(H5Pset_attr_creation_order(gcpl.get(), flags), "/", "cannot set attribute order");
  return gcpl;
}

// The index to iterate links (or attributes) of `obj` by: creation order when tracked.
H5_index_t iteration_index(const H5File& f, hid_t obj, const std::string& object, bool attributes) {
  Hid gcpl = f.own(H5Gget_create_plist(obj), H5Pclose, object, "cannot read group properties");
  unsigned flags = 0;
  f.check(attributes ? H5Pget_attr_creation_order(gcpl.get(), &flags)
                     : H5Pget_link_creation_order(gcpl.get(), &flags),
          object, "cannot read creation order");
  return (flags & H5P_CRT_ORDER_TRACKED) ? H5_INDEX_CRT_ORDER : H5_INDEX_NAME;
}

// ---------------------------------------------------------------------------------------------
// Attributes.

void write_attribute(const H5File& f, hid_t obj, const std::string& object, const char* name,
                     hid_t type, const void* value, hsize_t count, bool scalar) {
  const std::string where = object + "@" + name;
  Hid space = scalar ? f.own(H5Screate(H5S_SCALAR), H5Sclose, where, "cannot create dataspace")
                     : f.space(1, &count, where);
  Hid attr = f.own(H5Acreate2(obj, name, type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
                   where, "cannot create attribute");
  if (scalar || count > 0) f.check(H5Awrite(attr.get(), type, value), where, "cannot write attribute");
}

template <class T>
void write_scalar_attribute(const H5File& f, hid_t obj, const std::string& object,
                            const char* name, hid_t type, T value) {
  write_attribute(f, obj, object, name, type, &value, 1, true);
}

void write_string_attribute(const H5File& f, hid_t obj, const std::string& object,
                            const char* name, const std::string& value) {
  Hid type = f.own(H5Tcopy(H5T_C_S1), H5Tclose, object, "cannot create string type");
  f.check(H5Tset_size(type.get(), H5T_VARIABLE), object, "cannot create string type");
  f.check(H5Tset_cset(type.get(), H5T_CSET_UTF8), object, "cannot create string type");
  const char* text = value.c_str();
  write_attribute(f, obj, object, name, type.get(), &text, 1, true);
}

// Reads an attribute of any numeric shape as doubles.
std::vector<double> read_double_attribute(const H5File& f, hid_t obj, const std::string& object,
                                          const char* name) {
  const std::string where = object + "@" + name;
  Hid attr = f.own(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose, where, "cannot open attribute");
  Hid space = f.own(H5Aget_space(attr.get()), H5Sclose, where, "cannot read attribute shape");
  const hssize_t count = H5Sget_simple_extent_npoints(space.get());
  if (count < 0) f.fail(where, "cannot read attribute shape");
  std::vector<double> values(static_cast<std::size_t>(count));
  if (count > 0) {
    f.check(H5Aread(attr.get(), H5T_NATIVE_DOUBLE, values.data()), where,
            "cannot read attribute as numbers");
  }
  return values;
}

// ---------------------------------------------------------------------------------------------
// Properties.

std::size_t value_count(const Property& p) {
  switch (p.type) {
    case PropType::F64: return p.f64.size();
    case PropType::I32: return p.i32.size();
    case PropType::U32: return p.u32.size();
  }
  return 0;
}

const void* values_of(const Property& p) {
  switch (p.type) {
    case PropType::F64: return p.f64.data();
    case PropType::I32: return p.i32.data();
    case PropType::U32: return p.u32.data();
  }
  return nullptr;
}

void* values_of(Property& p) { return const_cast<void*>(values_of(std::as_const(p))); }

void resize_values(Property& p, std::size_t count) {
  switch (p.type) {
    case PropType::F64: p.f64.resize(count); break;
    case PropType::I32: p.i32.resize(count); break;
    case PropType::U32: p.u32.resize(count); break;
  }
}

bool is_position(const std::string& name) {
  for (const char* p : kPositions) {
    if (name == p) return true;
  }
  return false;
}

const Property& property_named(const ParticleArray& a, const std::string& name) {
  const int idx = a.find(name);
  if (idx < 0) {
    throw std::runtime_error(
        fmt::format("array '{}' has no property '{}' to write", a.name, name));
  }
  return a.props[static_cast<std::size_t>(idx)];
}

void write_property(const H5File& f, hid_t group, const std::string& group_path,
                    const Property& p, std::size_t n) {
  const std::string where = child_path(group_path, p.name);
  if (p.stride < 1 || value_count(p) != n * static_cast<std::size_t>(p.stride)) {
    throw std::runtime_error(fmt::format(
        "HDF5 file '{}', '{}': property holds {} values, expected {} particles x stride {}",
        f.path(), where, value_count(p), n, p.stride));
  }
  const hsize_t dims[2] = {n, static_cast<hsize_t>(p.stride)};
  Hid space = f.space(p.stride == 1 ? 1 : 2, dims, where);
  const hid_t type = native_type(p.type);
  Hid dset = f.own(H5Dcreate2(group, p.name.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT,
                              H5P_DEFAULT),
                   H5Dclose, where, "cannot create dataset");
  if (value_count(p) > 0) {
    f.check(H5Dwrite(dset.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values_of(p)), where,
            "cannot write dataset");
  }
}

void write_constants(const H5File& f, hid_t group, const std::string& group_path,
                     const ParticleArray& a) {
  if (a.constants.empty()) return;
  const std::string where = child_path(group_path, kConstantsGroup);
  if (a.find(kConstantsGroup) >= 0) {
    throw std::runtime_error(fmt::format(
        "HDF5 file '{}', '{}': a property named '{}' clashes with the group of constants",
        f.path(), where, kConstantsGroup));
  }
  Hid gcpl = ordered_group_plist(f);
  Hid cgroup = f.own(H5Gcreate2(group, kConstantsGroup, H5P_DEFAULT, gcpl.get(), H5P_DEFAULT),
                     H5Gclose, where, "cannot create group");
  for (const Constant& c : a.constants) {
    write_attribute(f, cgroup.get(), where, c.name.c_str(), H5T_NATIVE_DOUBLE, c.values.data(),
                    c.values.size(), false);
  }
}

void write_array(const H5File& f, hid_t file, const OutputArray& out) {
  if (!out.array) throw std::runtime_error(fmt::format("HDF5 file '{}': null array", f.path()));
  const ParticleArray& a = *out.array;
  const std::string where = "/" + a.name;
  Hid gcpl = ordered_group_plist(f);
  Hid group = f.own(H5Gcreate2(file, a.name.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT),
                    H5Gclose, where, "cannot create group");
  write_scalar_attribute(f, group.get(), where, "n", H5T_NATIVE_INT64,
                         static_cast<std::int64_t>(a.n));
  for (const Property* p : output_properties(out)) write_property(f, group.get(), where, *p, a.n);
  // Positions a lower-dimensional scene does not have are written as zeros, so that every
  // file has x, y and z (ParaView's X_Y_Z geometry, and readers that expect all three).
  for (const char* pos : kPositions) {
    if (a.find(pos) >= 0) continue;
    Property zeros;
    zeros.name = pos;
    zeros.f64.assign(a.n, 0.0);
    write_property(f, group.get(), where, zeros, a.n);
  }
  write_constants(f, group.get(), where, a);
}

// Reads one dataset as a property; its first dimension must be n (n < 0: not known yet, set).
// With parts > 1 only the rows [n part / parts, n (part + 1) / parts).
Property read_property(const H5File& f, hid_t group, const std::string& group_path,
                       const std::string& name, long long& n, std::size_t part = 0,
                       std::size_t parts = 1) {
  const std::string where = child_path(group_path, name);
  Hid dset = f.own(H5Dopen2(group, name.c_str(), H5P_DEFAULT), H5Dclose, where,
                   "cannot open dataset");
  Hid type = f.own(H5Dget_type(dset.get()), H5Tclose, where, "cannot read dataset type");
  Property p;
  p.name = name;
  switch (H5Tget_class(type.get())) {
    case H5T_FLOAT: p.type = PropType::F64; break;
    case H5T_INTEGER:
      p.type = H5Tget_sign(type.get()) == H5T_SGN_NONE ? PropType::U32 : PropType::I32;
      break;
    default: f.fail(where, "dataset type is neither floating point nor integer");
  }
  Hid space = f.own(H5Dget_space(dset.get()), H5Sclose, where, "cannot read dataset shape");
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 1 || rank > 2) f.fail(where, fmt::format("dataset has rank {}, expected 1 or 2", rank));
  hsize_t dims[2] = {0, 1};
  if (H5Sget_simple_extent_dims(space.get(), dims, nullptr) < 0) f.fail(where, "cannot read dataset shape");
  if (n < 0) n = static_cast<long long>(dims[0]);
  if (static_cast<long long>(dims[0]) != n) {
    f.fail(where, fmt::format("dataset has {} rows, the array has {} particles", dims[0], n));
  }
  p.stride = static_cast<int>(dims[1]);
  const hsize_t begin = dims[0] * part / parts, end = dims[0] * (part + 1) / parts;
  resize_values(p, (end - begin) * dims[1]);
  if (value_count(p) == 0) return p;
  if (parts == 1) {
    f.check(H5Dread(dset.get(), native_type(p.type), H5S_ALL, H5S_ALL, H5P_DEFAULT, values_of(p)),
            where, "cannot read dataset");
    return p;
  }
  const hsize_t start[2] = {begin, 0}, count[2] = {end - begin, dims[1]};
  f.check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr), where,
          "cannot select rows");
  Hid memory = f.space(rank, count, where);
  f.check(H5Dread(dset.get(), native_type(p.type), memory.get(), space.get(), H5P_DEFAULT,
                  values_of(p)),
          where, "cannot read dataset");
  return p;
}

// Names of the links of `group` whose object is of `type`, in iteration_index order.
std::vector<std::string> child_names(const H5File& f, hid_t group, const std::string& group_path,
                                     H5O_type_t type) {
  struct Visit {
    H5O_type_t type;
    std::vector<std::string> names;
  } visit{type, {}};
  auto callback = [](hid_t g, const char* name, const H5L_info_t*, void* data) -> herr_t {
    auto* v = static_cast<Visit*>(data);
    H5O_info_t info;
    if (H5Oget_info_by_name(g, name, &info, H5P_DEFAULT) < 0) return -1;
    if (info.type == v->type) v->names.emplace_back(name);
    return 0;
  };
  const H5_index_t index = iteration_index(f, group, group_path, false);
  f.check(H5Literate(group, index, H5_ITER_INC, nullptr, callback, &visit), group_path,
          "cannot list group");
  return visit.names;
}

std::vector<std::string> attribute_names(const H5File& f, hid_t obj, const std::string& object) {
  std::vector<std::string> names;
  auto callback = [](hid_t, const char* name, const H5A_info_t*, void* data) -> herr_t {
    static_cast<std::vector<std::string>*>(data)->emplace_back(name);
    return 0;
  };
  const H5_index_t index = iteration_index(f, obj, object, true);
  f.check(H5Aiterate2(obj, index, H5_ITER_INC, nullptr, callback, &names), object,
          "cannot list attributes");
  return names;
}

void read_constants(const H5File& f, hid_t group, const std::string& group_path,
                    ParticleArray& a) {
  const std::string where = child_path(group_path, kConstantsGroup);
  Hid cgroup = f.own(H5Gopen2(group, kConstantsGroup, H5P_DEFAULT), H5Gclose, where,
                     "cannot open group");
  for (const std::string& name : attribute_names(f, cgroup.get(), where)) {
    a.constants.push_back(
        Constant{name, read_double_attribute(f, cgroup.get(), where, name.c_str())});
  }
}

Hid open_file(const H5File& f) {
  return f.own(H5Fopen(f.path().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, "/",
               "cannot open file");
}

// ---------------------------------------------------------------------------------------------
// XDMF.

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

// A DataItem pointing at a dataset. Integer datasets are declared as Float too: the readers
// ask HDF5 for the declared type and HDF5 converts on read.
std::string xdmf_data_item(const std::string& h5_file, const std::string& array,
                           const std::string& prop, std::size_t n, int stride) {
  const std::string dims = stride == 1 ? fmt::format("{}", n) : fmt::format("{} {}", n, stride);
  return fmt::format(
      "            <DataItem Dimensions=\"{}\" NumberType=\"Float\" Precision=\"8\" "
      "Format=\"HDF\">{}:/{}/{}</DataItem>\n",
      dims, xml_escape(h5_file), xml_escape(array), xml_escape(prop));
}

const char* xdmf_attribute_type(int stride) {
  switch (stride) {
    case 1: return "Scalar";
    case 3: return "Vector";
    case 9: return "Tensor";
    default: return nullptr;  // XDMF has no type for other strides: not listed
  }
}


void append_xdmf_grid(std::string& out, const XdmfEntry& e, std::size_t k) {
  const auto& [array, n] = e.arrays[k];
  // ParaView's readers do not accept empty grids.
  if (n == 0) return;
  out += fmt::format("        <Grid Name=\"{}\" GridType=\"Uniform\">\n", xml_escape(array));
  out += fmt::format("          <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\"/>\n", n);
  out += "          <Geometry GeometryType=\"X_Y_Z\">\n";
  for (const char* c : kPositions) out += xdmf_data_item(e.h5_file, array, c, n, 1);
  out += "          </Geometry>\n";
  const auto no_props = std::vector<std::pair<std::string, int>>{};
  for (const auto& [prop, stride] : k < e.props.size() ? e.props[k] : no_props) {
    const char* type = xdmf_attribute_type(stride);
    if (!type || is_position(prop)) continue;
    out += fmt::format("          <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"Node\">\n",
                       xml_escape(prop), type);
    out += xdmf_data_item(e.h5_file, array, prop, n, stride);
    out += "          </Attribute>\n";
  }
  out += "        </Grid>\n";
}

std::string xdmf_document(const std::vector<XdmfEntry>& series, int dim) {
  std::string out =
      "<?xml version=\"1.0\" ?>\n"
      "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
      "<Xdmf Version=\"2.0\">\n"
      "  <Domain>\n";
  out += fmt::format("    <Information Name=\"dim\" Value=\"{}\"/>\n", dim);
  out += "    <Grid Name=\"series\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const XdmfEntry& e : series) {
    out += fmt::format(
        "      <Grid Name=\"{}\" GridType=\"Collection\" CollectionType=\"Spatial\">\n",
        xml_escape(e.h5_file));
    out += fmt::format("        <Time Value=\"{}\"/>\n", e.t);
    for (std::size_t k = 0; k < e.arrays.size(); ++k) append_xdmf_grid(out, e, k);
    out += "      </Grid>\n";
  }
  out += "    </Grid>\n  </Domain>\n</Xdmf>\n";
  return out;
}

// ---------------------------------------------------------------------------------------------
// CSV.

std::string trim(const std::string& s) {
  const char* ws = " \t\r\n";
  const auto b = s.find_first_not_of(ws);
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(ws) - b + 1);
}

struct CsvField {
  std::string text;  // trimmed
  std::size_t column;  // 1-based column of the field's first character
};

std::vector<CsvField> split_csv_line(const std::string& line) {
  std::vector<CsvField> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    const std::size_t end = comma == std::string::npos ? line.size() : comma;
    const std::string raw = line.substr(start, end - start);
    const std::size_t lead = std::min(raw.find_first_not_of(" \t"), raw.size());
    fields.push_back(CsvField{trim(raw), start + lead + 1});
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return fields;
}

bool parse_csv_number(const std::string& text, double& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  errno = 0;
  value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && errno != ERANGE;
}

}  // namespace

std::vector<const Property*> output_properties(const OutputArray& out) {
  const ParticleArray& a = *out.array;
  std::vector<std::string> names(std::begin(kPositions), std::end(kPositions));
  if (out.props.empty()) {
    for (const Property& p : a.props) names.push_back(p.name);
  } else {
    names.insert(names.end(), out.props.begin(), out.props.end());
  }
  std::vector<const Property*> selected;
  for (const std::string& name : names) {
    // A 1D or 2D scene has no y/z: write_array writes zeros for them instead.
    if (is_position(name) && name != "x" && a.find(name) < 0) continue;
    const Property& p = property_named(a, name);
    bool seen = false;
    for (const Property* q : selected) seen = seen || q == &p;
    if (!seen) selected.push_back(&p);
  }
  return selected;
}

// -------------------------------------------------------------------------------------------------

void write_particles_hdf5(const std::string& path, const std::vector<OutputArray>& arrays,
                          const OutputMeta& meta) {
  write_atomically(path, [&](const std::string& tmp) {
    const H5File f(tmp);
    Hid fcpl = f.plist(H5P_FILE_CREATE, "cannot create file property list");
    const unsigned flags = H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED;
    f.check(H5Pset_link_creation_order(fcpl.get(), flags), "/", "cannot set link order");
    f.check(H5Pset_attr_creation_order(fcpl.get(), flags), "/", "cannot set attribute order");
    Hid file = f.own(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, fcpl.get(), H5P_DEFAULT), H5Fclose,
                     "/", "cannot create file");
    write_scalar_attribute(f, file.get(), "/", "t", H5T_NATIVE_DOUBLE, meta.t);
    write_scalar_attribute(f, file.get(), "/", "step", H5T_NATIVE_INT64,
                           static_cast<std::int64_t>(meta.step));
    write_scalar_attribute(f, file.get(), "/", "dt", H5T_NATIVE_DOUBLE, meta.dt);
    write_scalar_attribute(f, file.get(), "/", "dim", H5T_NATIVE_INT32,
                           static_cast<std::int32_t>(meta.dim));
    write_string_attribute(f, file.get(), "/", "scene", meta.scene);
    for (const auto& [name, value] : meta.state)
      write_scalar_attribute(f, file.get(), "/", (kRunStatePrefix + name).c_str(),
                             H5T_NATIVE_DOUBLE, value);
    for (const OutputArray& out : arrays) write_array(f, file.get(), out);
    f.check(file.close(), "/", "cannot close file");
  });
}

ParticleArray read_particles_hdf5(const std::string& path, const std::string& array_name,
                                  std::size_t part, std::size_t parts) {
  if (parts == 0 || part >= parts)
    throw std::invalid_argument(fmt::format("read_particles_hdf5: part {} of {}", part, parts));
  const H5File f(path);
  Hid file = open_file(f);
  const std::string where = "/" + array_name;
  if (H5Lexists(file.get(), array_name.c_str(), H5P_DEFAULT) <= 0) {
    std::string known;
    for (const std::string& name : list_arrays_hdf5(path)) known += (known.empty() ? "" : ", ") + name;
    f.fail(where, fmt::format("no array '{}' (the file has: {})", array_name,
                              known.empty() ? "no arrays" : known));
  }
  Hid group = f.own(H5Gopen2(file.get(), array_name.c_str(), H5P_DEFAULT), H5Gclose, where,
                    "cannot open group");
  long long n = -1;
  if (H5Aexists(group.get(), "n") > 0) {
    const std::vector<double> attr = read_double_attribute(f, group.get(), where, "n");
    if (attr.size() != 1 || attr[0] < 0) f.fail(where + "@n", "particle count is not a count");
    n = static_cast<long long>(attr[0]);
  }
  std::vector<Property> props;
  for (const std::string& name : child_names(f, group.get(), where, H5O_TYPE_DATASET)) {
    props.push_back(read_property(f, group.get(), where, name, n, part, parts));
  }

  ParticleArray a;
  a.name = array_name;
  const std::size_t total = static_cast<std::size_t>(std::max(n, 0LL));
  a.n = total * (part + 1) / parts - total * part / parts;
  a.props = std::move(props);
  if (H5Lexists(group.get(), kConstantsGroup, H5P_DEFAULT) > 0) read_constants(f, group.get(), where, a);
  return a;
}

OutputMeta read_meta_hdf5(const std::string& path) {
  const H5File f(path);
  Hid file = open_file(f);
  Hid root = f.own(H5Gopen2(file.get(), "/", H5P_DEFAULT), H5Gclose, "/", "cannot open group");
  OutputMeta meta;
  auto number = [&](const char* name) {
    if (H5Aexists(root.get(), name) <= 0) f.fail(std::string("/@") + name, "no such attribute");
    const std::vector<double> v = read_double_attribute(f, root.get(), "/", name);
    if (v.size() != 1) f.fail(std::string("/@") + name, "not a single number");
    return v[0];
  };
  meta.t = number("t");
  meta.dt = number("dt");
  meta.step = static_cast<long>(number("step"));
  meta.dim = static_cast<int>(number("dim"));
  if (H5Aexists(root.get(), "scene") > 0) {
    Hid attr = f.own(H5Aopen(root.get(), "scene", H5P_DEFAULT), H5Aclose, "/@scene",
                     "cannot open attribute");
    Hid type = f.own(H5Aget_type(attr.get()), H5Tclose, "/@scene", "cannot read its type");
    if (H5Tget_class(type.get()) == H5T_STRING && H5Tis_variable_str(type.get()) > 0) {
      char* text = nullptr;
      f.check(H5Aread(attr.get(), type.get(), &text), "/@scene", "cannot read attribute");
      meta.scene = text ? text : "";
      H5free_memory(text);
    }
  }
  const std::string prefix = kRunStatePrefix;
  for (const std::string& name : attribute_names(f, root.get(), "/")) {
    if (name.rfind(prefix, 0) != 0) continue;
    const std::vector<double> v = read_double_attribute(f, root.get(), "/", name.c_str());
    if (v.size() != 1) f.fail("/@" + name, "not a single number");
    meta.state.emplace_back(name.substr(prefix.size()), v[0]);
  }
  return meta;
}

std::vector<std::string> list_arrays_hdf5(const std::string& path) {
  const H5File f(path);
  Hid file = open_file(f);
  Hid root = f.own(H5Gopen2(file.get(), "/", H5P_DEFAULT), H5Gclose, "/", "cannot open group");
  return child_names(f, root.get(), "/", H5O_TYPE_GROUP);
}

XdmfEntry make_xdmf_entry(const std::string& h5_file, double t,
                          const std::vector<OutputArray>& arrays) {
  XdmfEntry e;
  e.h5_file = h5_file;
  e.t = t;
  for (const OutputArray& out : arrays) {
    e.arrays.emplace_back(out.array->name, out.array->n);
    auto& props = e.props.emplace_back();
    for (const Property* p : output_properties(out)) props.emplace_back(p->name, p->stride);
  }
  return e;
}

XdmfEntry read_xdmf_entry_hdf5(const std::string& path, const std::string& h5_file) {
  XdmfEntry e;
  e.h5_file = h5_file;
  e.t = read_meta_hdf5(path).t;
  const H5File f(path);
  Hid file = open_file(f);
  for (const std::string& array : list_arrays_hdf5(path)) {
    const std::string where = "/" + array;
    Hid group = f.own(H5Gopen2(file.get(), array.c_str(), H5P_DEFAULT), H5Gclose, where,
                      "cannot open group");
    const std::vector<double> n = read_double_attribute(f, group.get(), where, "n");
    if (n.size() != 1 || n[0] < 0) f.fail(where + "@n", "particle count is not a count");
    e.arrays.emplace_back(array, static_cast<std::size_t>(n[0]));
    auto& props = e.props.emplace_back();
    for (const std::string& name : child_names(f, group.get(), where, H5O_TYPE_DATASET)) {
      const std::string at = child_path(where, name);
      Hid dset = f.own(H5Dopen2(group.get(), name.c_str(), H5P_DEFAULT), H5Dclose, at,
                       "cannot open dataset");
      Hid space = f.own(H5Dget_space(dset.get()), H5Sclose, at, "cannot read dataset shape");
      hsize_t dims[2] = {0, 1};
      if (H5Sget_simple_extent_dims(space.get(), dims, nullptr) < 0)
        f.fail(at, "cannot read dataset shape");
      props.emplace_back(name, static_cast<int>(dims[1]));
    }
  }
  return e;
}

void write_xdmf(const std::string& xdmf_path, const std::vector<XdmfEntry>& series, int dim) {
  const std::string text = xdmf_document(series, dim);
  write_atomically(xdmf_path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.close();
    if (!out) throw std::runtime_error(fmt::format("cannot write '{}'", tmp));
  });
}

ParticleArray read_particles_csv(const std::string& path, const std::string& array_name) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(fmt::format("cannot open '{}'", path));
  std::string line;
  std::size_t line_no = 0;
  auto next_line = [&]() {
    while (std::getline(in, line)) {
      ++line_no;
      if (!trim(line).empty()) return true;
    }
    return false;
  };

  if (!next_line()) throw std::runtime_error(fmt::format("{}: empty file, expected a header row", path));
  std::vector<std::string> names;
  for (const CsvField& field : split_csv_line(line)) {
    const std::string where = fmt::format("{}:{}:{}", path, line_no, field.column);
    if (field.text.empty()) throw std::runtime_error(where + ": empty property name");
    for (const std::string& seen : names) {
      if (seen == field.text) {
        throw std::runtime_error(fmt::format("{}: property '{}' appears twice", where, seen));
      }
    }
    names.push_back(field.text);
  }
  bool has_x = false;
  for (const std::string& name : names) has_x = has_x || name == "x";
  if (!has_x) throw std::runtime_error(fmt::format("{}:{}: the header has no column 'x'", path, line_no));

  std::vector<std::vector<double>> columns(names.size());
  while (next_line()) {
    const std::vector<CsvField> fields = split_csv_line(line);
    if (fields.size() != names.size()) {
      throw std::runtime_error(fmt::format("{}:{}: {} values, expected {} (one per header column)",
                                           path, line_no, fields.size(), names.size()));
    }
    for (std::size_t c = 0; c < fields.size(); ++c) {
      double value = 0.0;
      if (!parse_csv_number(fields[c].text, value)) {
        throw std::runtime_error(fmt::format("{}:{}:{}: bad number '{}' in column '{}'", path,
                                             line_no, fields[c].column, fields[c].text, names[c]));
      }
      columns[c].push_back(value);
    }
  }
  if (in.bad()) throw std::runtime_error(fmt::format("cannot read '{}'", path));

  ParticleArray a;
  a.name = array_name;
  a.n = columns[0].size();
  for (std::size_t c = 0; c < names.size(); ++c) {
    const int idx = a.add_property(names[c]);
    a.props[static_cast<std::size_t>(idx)].f64 = std::move(columns[c]);
  }
  for (const char* pos : kPositions) a.add_property(pos);
  return a;
}

}  // namespace sphc
