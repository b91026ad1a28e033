// sphc runtime: the memory a run needs, estimated before anything large is allocated.
//
// run_main (solver.h) first runs the scene's set-up inside a CountingPass: the geometry
// builders (geometry.h) then return no points but count the ones they would make, and
// ParticleArray::resize records how many particles each array would get (file loads are read:
// they are small). With those counts and the properties each array has (add_property runs as
// usual), estimate_memory says how many bytes the run will need, item by item; run_main
// refuses to go on when that exceeds available_memory() (or --max-memory), and only then
// runs the set-up for real.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace sphc {

struct ParticleArray;

// While a CountingPass is alive (one at a time, on the thread that runs the set-up), geometry
// builders count instead of building and ParticleArray::resize records the sizes asked for.
class CountingPass {
 public:
  CountingPass();
  ~CountingPass();
  CountingPass(const CountingPass&) = delete;
  CountingPass& operator=(const CountingPass&) = delete;
  // The particles `a` would have: the points counted by builders before its last resize plus
  // the size that resize asked for (loaded particles). 0 for an array never resized.
  std::size_t planned(const ParticleArray& a) const;
};

// True inside a CountingPass.
bool counting_particles();
// Geometry builders: `n` points would be made (added to the next ParticleArray::resize).
void count_points(std::size_t n);
// ParticleArray::resize: `a` is being resized to n real particles.
void count_resize(const ParticleArray& a, std::size_t n);

// What the estimate assumes per particle, beyond the particle's properties (measured against
// runtime/src/nnps.cpp, particle_array.cpp and float_arrays.cpp; see estimate_memory).
constexpr double kSearchBytesPerParticle = 40.0;  // cell list: order, cell of each particle
                                                  // (4 B each), hash table of >= 2n slots of
                                                  // 12 B, cell starts
constexpr double kMarginFraction = 0.10;  // ghosts of periodic and mirror boundaries, allocator
                                          // slack, the libraries' own buffers

// One array as the estimate sees it.
struct ArrayFootprint {
  std::string name;
  std::size_t particles = 0;
  double bytes_per_particle = 0;     // every property (stride x 8 or 4 bytes)
  double doubles_per_particle = 0;   // double values per particle (float copies of them)
  double largest_property_bytes = 0; // per particle: the scratch of a reorder or an output
};

// The footprint of `a` with `particles` particles (its properties as declared).
ArrayFootprint footprint(const ParticleArray& a, std::size_t particles);

struct MemoryItem {
  std::string what;  // "particle data of array 'fluid' (2e+08 particles x 280 B)"
  double bytes = 0;
};

struct MemoryEstimate {
  std::vector<MemoryItem> items;
  double total = 0;
  // "61.6 GB: particle data of array 'fluid' (...) 56 GB, ..." (the items, largest first).
  std::string describe() const;
};

// The bytes of a run with these arrays: their properties; float copies of the double
// properties (single_precision: --precision=single, on the CPU or a device); a cell list per
// array; the scratch of the largest reorder and output; the points of the largest array,
// alive during its set-up (24 B each); and kMarginFraction of it all for ghosts and slack.
MemoryEstimate estimate_memory(const std::vector<ArrayFootprint>& arrays, bool single_precision);

// Bytes this process may still allocate: MemAvailable of /proc/meminfo, or less where a
// cgroup (v2 memory.max, v1 memory.limit_in_bytes) sets a lower limit; nullopt if unknown.
std::optional<double> available_memory();

// "2G", "500M", "64k", "1.5GB", "1e9" (bytes; k/M/G/T are powers of 1024). nullopt if the
// text is not a positive size.
std::optional<double> parse_memory_size(const std::string& text);

// "61.6 GB", "512 MB", "780 B" (powers of 1024, three significant digits).
std::string format_bytes(double bytes);

}  // namespace sphc
