// sphc runtime: reading and writing particle arrays (HDF5, XDMF index, CSV).
//
// HDF5 layout (plain enough for h5py):
//   /                   attributes t (double), step (int64), dt (double), dim (int32),
//                       scene (UTF-8 string), and the run state a restart needs beyond the
//                       particles (OutputMeta::state): one double attribute restart_NAME
//                       each (sphc/solver.h, --restart; docs/design.md, "Restart")
//   /<array>            one group per array, attribute n (int64, particle count)
//   /<array>/<prop>     one dataset per property, native type (double / int32 / uint32),
//                       shape (n,) for stride 1, else (n, stride)
//   /<array>/constants  present when the array has constants: one attribute per constant,
//                       a 1-D double array
// Groups, datasets and constants keep their creation order, so a file read back has the
// arrays, properties and constants in the order they were written.
//
// Every failure throws std::runtime_error naming the file and the dataset or group.
// HDF5's automatic error printing is switched off by these functions.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "sphc/particle_array.h"

namespace sphc {

// One array to write and the properties to write (empty = all). x, y and z are always
// written, first; a name listed twice is written once.
struct OutputArray {
  const ParticleArray* array = nullptr;
  std::vector<std::string> props;
};

// The properties write_particles_hdf5 writes for `out`, in its order: x, then y and z where
// the array has them (it writes zeros for the others), then the requested properties (or
// all), each once. Throws, naming the array and the property, where a requested one is
// missing. Every writer of the format (the serial one, the MPI ranks' collective one) uses it.
std::vector<const Property*> output_properties(const OutputArray& out);

// Root attributes of an output file.
struct OutputMeta {
  double t = 0.0;
  long step = 0;
  double dt = 0.0;
  int dim = 2;
  std::string scene;
  // The run state beyond the particles (the time loop's and the scene's counters), written as
  // root attributes restart_NAME (double; integers below 2^53 exactly); empty: none.
  std::vector<std::pair<std::string, double>> state;
};

// The root attributes of an output file (read_meta_hdf5): OutputMeta's, with `state` holding
// every numeric root attribute whose name starts with restart_ (the prefix removed).
OutputMeta read_meta_hdf5(const std::string& path);
// The prefix of the run-state attributes.
inline constexpr const char* kRunStatePrefix = "restart_";

// Writes `path + ".tmp"` and renames it to `path`, so `path` is never half written.
void write_particles_hdf5(const std::string& path, const std::vector<OutputArray>& arrays,
                          const OutputMeta& meta);

// Reads every property (type and stride preserved) and constant of group `array_name`. The
// returned array is named `array_name`. With parts > 1, only the block of particles
// [n part / parts, n (part + 1) / parts) is read (each rank of a distributed restart reads
// one block of the file; the constants whole).
ParticleArray read_particles_hdf5(const std::string& path, const std::string& array_name,
                                  std::size_t part = 0, std::size_t parts = 1);

// Names of the array groups in a file, in creation order (name order for files written by
// other tools).
std::vector<std::string> list_arrays_hdf5(const std::string& path);

// One output file of a time series, as indexed by the XDMF file.
struct XdmfEntry {
  std::string h5_file;  // relative to the xdmf file
  double t = 0.0;
  std::vector<std::pair<std::string, std::size_t>> arrays;        // array name, n
  std::vector<std::vector<std::pair<std::string, int>>> props;    // per array: name, stride
};

// The entry describing what write_particles_hdf5(…, arrays, …) writes into `h5_file`.
XdmfEntry make_xdmf_entry(const std::string& h5_file, double t,
                          const std::vector<OutputArray>& arrays);

// The entry of an existing output file `path` (named `h5_file` in the index): its t, arrays,
// particle counts and datasets. A restarted run indexes the files before its restart so.
XdmfEntry read_xdmf_entry_hdf5(const std::string& path, const std::string& h5_file);

// Writes the XDMF index of a time series for ParaView (rewritten whole and atomically: tmp +
// rename): a temporal collection of spatial collections, one Polyvertex grid per array with
// X_Y_Z geometry and one attribute per property of stride 1 (Scalar), 3 (Vector) or
// 9 (Tensor). x, y, z and properties of other strides are not listed as attributes.
void write_xdmf(const std::string& xdmf_path, const std::vector<XdmfEntry>& series, int dim);

// Reads a CSV file: a header row of property names (must include x; y and z are added as
// zeros when absent), then one row of comma-separated numbers per particle. Blank lines are
// skipped. All properties are F64. Errors name file:line:column.
ParticleArray read_particles_csv(const std::string& path, const std::string& array_name);

}  // namespace sphc
