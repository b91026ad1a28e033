// HDF5 output and input, the XDMF index and CSV loading (runtime/src/hdf5_io.cpp).
#include "sphc/hdf5_io.h"
#include "sphc/load.h"
#include "sphc/memory.h"

#include <gtest/gtest.h>

#include "scratch_dir.h"
#include <hdf5.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace sphc;

namespace {

fs::path fresh_dir() { return fresh_test_dir("tmp_io"); }

ParticleArray sample_array() {
  ParticleArray a;
  a.name = "fluid";
  a.n = 5;
  for (const char* p : {"x", "y", "z"}) a.add_property(p);
  a.add_property("rho");
  a.add_property("tau", PropType::F64, 9);
  a.add_property("tag", PropType::I32);
  a.add_property("gid", PropType::U32, 2);
  for (Property& p : a.props) {
    for (std::size_t k = 0; k < p.f64.size(); ++k) p.f64[k] = 0.1 * k + 1.0 / 3.0 + p.name.size();
    for (std::size_t k = 0; k < p.i32.size(); ++k) p.i32[k] = -7 * static_cast<int>(k);
    for (std::size_t k = 0; k < p.u32.size(); ++k) p.u32[k] = 4000000000u + static_cast<unsigned>(k);
  }
  a.add_constant("c0", 1, 12.5);
  a.add_constant("gravity", 3, 0.0);
  a.constant("gravity")[1] = -9.81;
  return a;
}

void expect_same(const ParticleArray& a, const ParticleArray& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.n, b.n);
  ASSERT_EQ(a.props.size(), b.props.size());
  for (std::size_t i = 0; i < a.props.size(); ++i) {
    SCOPED_TRACE(a.props[i].name);
    EXPECT_EQ(a.props[i].name, b.props[i].name);
    EXPECT_EQ(a.props[i].type, b.props[i].type);
    EXPECT_EQ(a.props[i].stride, b.props[i].stride);
    EXPECT_EQ(a.props[i].f64, b.props[i].f64);
    EXPECT_EQ(a.props[i].i32, b.props[i].i32);
    EXPECT_EQ(a.props[i].u32, b.props[i].u32);
  }
  ASSERT_EQ(a.constants.size(), b.constants.size());
  for (std::size_t i = 0; i < a.constants.size(); ++i) {
    EXPECT_EQ(a.constants[i].name, b.constants[i].name);
    EXPECT_EQ(a.constants[i].values, b.constants[i].values);
  }
}

double read_root_double(const std::string& path, const char* name) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(file, 0);
  const hid_t attr = H5Aopen(file, name, H5P_DEFAULT);
  double value = -1;
  EXPECT_GE(H5Aread(attr, H5T_NATIVE_DOUBLE, &value), 0);
  H5Aclose(attr);
  H5Fclose(file);
  return value;
}

std::vector<std::string> files_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

TEST(Hdf5Io, RoundTripsAllTypesStridesAndConstantsExactly) {
  const fs::path dir = fresh_dir();
  const std::string path = (dir / "out.h5").string();
  const ParticleArray a = sample_array();
  write_particles_hdf5(path, {OutputArray{&a, {}}}, OutputMeta{0.125, 42, 1e-4, 2, "dambreak"});

  expect_same(a, read_particles_hdf5(path, "fluid"));
  EXPECT_EQ(read_root_double(path, "t"), 0.125);
  EXPECT_EQ(read_root_double(path, "step"), 42);
  EXPECT_EQ(read_root_double(path, "dt"), 1e-4);
  EXPECT_EQ(read_root_double(path, "dim"), 2);
}

TEST(Hdf5Io, WritesPositionsAndTheSelectedPropertiesOnce) {
  const fs::path dir = fresh_dir();
  const std::string path = (dir / "out.h5").string();
  const ParticleArray a = sample_array();
  write_particles_hdf5(path, {OutputArray{&a, {"tag", "x", "tag"}}}, OutputMeta{});
  const ParticleArray b = read_particles_hdf5(path, "fluid");
  std::vector<std::string> names;
  for (const Property& p : b.props) names.push_back(p.name);
  EXPECT_EQ(names, (std::vector<std::string>{"x", "y", "z", "tag"}));
  EXPECT_EQ(b.props[3].i32, a.props[static_cast<std::size_t>(a.find("tag"))].i32);
}

TEST(Hdf5Io, ListsArraysInWriteOrderAndRoundTripsEmptyArrays) {
  const fs::path dir = fresh_dir();
  const std::string path = (dir / "out.h5").string();
  const ParticleArray fluid = sample_array();
  ParticleArray wall;
  wall.name = "boundary";
  for (const char* p : {"x", "y", "z"}) wall.add_property(p);
  wall.add_property("v", PropType::F64, 3);
  write_particles_hdf5(path, {OutputArray{&fluid, {}}, OutputArray{&wall, {}}}, OutputMeta{});

  EXPECT_EQ(list_arrays_hdf5(path), (std::vector<std::string>{"fluid", "boundary"}));
  const ParticleArray back = read_particles_hdf5(path, "boundary");
  expect_same(wall, back);
  EXPECT_EQ(back.props[3].stride, 3);
}

TEST(Hdf5Io, WriteIsAtomic) {
  const fs::path dir = fresh_dir();
  const std::string path = (dir / "out.h5").string();
  const ParticleArray a = sample_array();
  write_particles_hdf5(path, {OutputArray{&a, {}}}, OutputMeta{1.0, 1, 0.1, 2, "s"});
  write_particles_hdf5(path, {OutputArray{&a, {}}}, OutputMeta{2.0, 2, 0.1, 2, "s"});
  EXPECT_EQ(files_in(dir), (std::vector<std::string>{"out.h5"}));
  EXPECT_EQ(read_root_double(path, "t"), 2.0);

  // A failed write leaves the previous file as it was and no temporary file.
  EXPECT_THROW(write_particles_hdf5(path, {OutputArray{&a, {"nope"}}}, OutputMeta{3.0, 3, 0.1, 2, "s"}),
               std::runtime_error);
  EXPECT_EQ(files_in(dir), (std::vector<std::string>{"out.h5"}));
  EXPECT_EQ(read_root_double(path, "t"), 2.0);
}

TEST(Hdf5Io, ErrorsNameTheFileAndTheArray) {
  const fs::path dir = fresh_dir();
  const std::string path = (dir / "out.h5").string();
  const ParticleArray a = sample_array();
  write_particles_hdf5(path, {OutputArray{&a, {}}}, OutputMeta{});
  try {
    read_particles_hdf5(path, "solid");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("solid"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("fluid"), std::string::npos) << e.what();
  }
  const std::string missing = (dir / "missing.h5").string();
  try {
    list_arrays_hdf5(missing);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// XDMF: a minimal XML reader (tags, attributes, text), enough to check the structure.

namespace {

struct XmlElement {
  std::string name;
  std::map<std::string, std::string> attrs;
  std::string text;
  std::string parent;
};

// Parses `xml`; fails the test on unbalanced tags.
std::vector<XmlElement> parse_xml(const std::string& xml) {
  std::vector<XmlElement> elements;
  std::vector<std::size_t> open;  // indices into elements
  std::size_t pos = 0;
  while ((pos = xml.find('<', pos)) != std::string::npos) {
    const std::size_t end = xml.find('>', pos);
    EXPECT_NE(end, std::string::npos);
    if (end == std::string::npos) break;
    std::string tag = xml.substr(pos + 1, end - pos - 1);
    const std::size_t text_start = end + 1;
    pos = end + 1;
    if (tag[0] == '?' || tag[0] == '!') continue;
    if (tag[0] == '/') {
      EXPECT_FALSE(open.empty()) << "unmatched </" << tag << ">";
      if (open.empty()) break;
      EXPECT_EQ(elements[open.back()].name, tag.substr(1));
      open.pop_back();
      continue;
    }
    const bool self_closing = tag.back() == '/';
    if (self_closing) tag.pop_back();
    XmlElement e;
    std::istringstream in(tag);
    in >> e.name;
    std::string rest((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (std::size_t eq; (eq = rest.find("=\"")) != std::string::npos;) {
      const std::size_t close = rest.find('"', eq + 2);
      std::string key = rest.substr(0, eq);
      key.erase(0, key.find_first_not_of(' '));
      e.attrs[key] = rest.substr(eq + 2, close - eq - 2);
      rest = rest.substr(close + 1);
    }
    e.parent = open.empty() ? "" : elements[open.back()].name;
    e.text = xml.substr(text_start, xml.find('<', text_start) - text_start);
    elements.push_back(e);
    if (!self_closing) open.push_back(elements.size() - 1);
  }
  EXPECT_TRUE(open.empty()) << "unclosed elements";
  return elements;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

}  // namespace

TEST(Xdmf, IndexesEveryOutputWithTimesAndAttributes) {
  const fs::path dir = fresh_dir();
  ParticleArray a = sample_array();
  a.add_property("v", PropType::F64, 3);
  std::vector<XdmfEntry> series;
  const std::vector<OutputArray> out{OutputArray{&a, {"rho", "v", "tau", "gid"}}};
  for (int k = 0; k < 2; ++k) {
    const std::string file = "s_00000" + std::to_string(k) + ".h5";
    write_particles_hdf5((dir / file).string(), out, OutputMeta{0.5 * k, k, 0.1, 2, "s"});
    series.push_back(make_xdmf_entry(file, 0.5 * k, out));
    write_xdmf((dir / "s.xdmf").string(), series, 2);
  }
  EXPECT_EQ(files_in(dir), (std::vector<std::string>{"s.xdmf", "s_000000.h5", "s_000001.h5"}));

  const std::vector<XmlElement> xml = parse_xml(read_text(dir / "s.xdmf"));
  std::vector<std::string> times, items;
  std::map<std::string, std::string> attribute_types;
  int temporal = 0, polyvertex = 0;
  for (const XmlElement& e : xml) {
    if (e.name == "Grid" && e.attrs.count("CollectionType") && e.attrs.at("CollectionType") == "Temporal") ++temporal;
    if (e.name == "Time") times.push_back(e.attrs.at("Value"));
    if (e.name == "Topology" && e.attrs.at("TopologyType") == "Polyvertex") {
      ++polyvertex;
      EXPECT_EQ(e.attrs.at("NumberOfElements"), "5");
    }
    if (e.name == "Attribute") attribute_types[e.attrs.at("Name")] = e.attrs.at("AttributeType");
    if (e.name == "DataItem") items.push_back(e.text);
  }
  EXPECT_EQ(temporal, 1);
  EXPECT_EQ(polyvertex, 2);
  EXPECT_EQ(times, (std::vector<std::string>{"0", "0.5"}));
  // gid has stride 2: no XDMF attribute type, not listed.
  EXPECT_EQ(attribute_types, (std::map<std::string, std::string>{
                                 {"rho", "Scalar"}, {"v", "Vector"}, {"tau", "Tensor"}}));
  // Per file: x, y, z, rho, v, tau.
  ASSERT_EQ(items.size(), 12u);
  EXPECT_EQ(items[0], "s_000000.h5:/fluid/x");
  EXPECT_EQ(items[2], "s_000000.h5:/fluid/z");
  EXPECT_EQ(items[10], "s_000001.h5:/fluid/v");
  for (const std::string& item : items) {
    EXPECT_TRUE(fs::exists(dir / item.substr(0, item.find(':')))) << item;
  }
}

// ---------------------------------------------------------------------------------------------
// CSV.

namespace {

std::string write_csv(const fs::path& dir, const std::string& text) {
  const std::string path = (dir / "in.csv").string();
  std::ofstream(path) << text;
  return path;
}

std::string csv_error(const std::string& path) {
  try {
    read_particles_csv(path, "fluid");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an error";
  return {};
}

}  // namespace

TEST(Csv, ReadsColumnsAndAddsMissingPositions) {
  const fs::path dir = fresh_dir();
  const std::string path = write_csv(dir, "x, y ,rho\n0.5,1e-3,1000\n\n-2, 3.25 ,999.5\r\n");
  const ParticleArray a = read_particles_csv(path, "fluid");
  EXPECT_EQ(a.name, "fluid");
  ASSERT_EQ(a.n, 2u);
  EXPECT_EQ(std::vector<double>(a.f64("x"), a.f64("x") + 2), (std::vector<double>{0.5, -2}));
  EXPECT_EQ(std::vector<double>(a.f64("y"), a.f64("y") + 2), (std::vector<double>{1e-3, 3.25}));
  EXPECT_EQ(std::vector<double>(a.f64("rho"), a.f64("rho") + 2), (std::vector<double>{1000, 999.5}));
  EXPECT_EQ(std::vector<double>(a.f64("z"), a.f64("z") + 2), (std::vector<double>{0, 0}));
}

// The set-up runs twice (a counting pass, then the real one): a file is read once, in the
// counting pass, and the real pass gets what was counted even if the file changed since.
TEST(Csv, ALoadedFileIsReadOnceForBothSetUpPasses) {
  const fs::path dir = fresh_dir();
  const std::string path = write_csv(dir, "x,rho\n0.5,1000\n1.5,999\n");
  {
    CountingPass pass;
    EXPECT_EQ(load_particles("", path, "fluid").n, 2u);
  }
  fs::remove(path);  // a second read would fail now
  const ParticleArray a = load_particles("", path, "fluid");
  ASSERT_EQ(a.n, 2u);
  EXPECT_EQ(a.f64("rho")[1], 999);
  // Handed over once: a later set-up (another run in this process) reads the file again.
  EXPECT_THROW(load_particles("", path, "fluid"), std::runtime_error);
}

TEST(Csv, BadNumberNamesFileLineAndColumn) {
  const fs::path dir = fresh_dir();
  const std::string path = write_csv(dir, "x,rho\n1,2\n3, 4x\n");
  const std::string msg = csv_error(path);
  EXPECT_NE(msg.find(path + ":3:4:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'4x'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("rho"), std::string::npos) << msg;
}

TEST(Csv, RejectsMissingXAndRaggedRows) {
  const fs::path dir = fresh_dir();
  EXPECT_NE(csv_error(write_csv(dir, "y,rho\n1,2\n")).find("'x'"), std::string::npos);
  const std::string ragged = write_csv(dir, "x,rho\n1,2\n3\n");
  EXPECT_NE(csv_error(ragged).find(ragged + ":3:"), std::string::npos);
  EXPECT_NE(csv_error((dir / "missing.csv").string()).find("missing.csv"), std::string::npos);
}
