// sphc runtime: particle arrays (structure of arrays).
//
// A ParticleArray holds n particles and a list of named properties. Each property is a
// contiguous vector of doubles, int32 or uint32 values with a stride (1 for a scalar, 9 for a
// 3x3 tensor): value k of particle i is at [i * stride + k]. Per-array constants are small
// double vectors (PySPH's `constants`). Generated code looks properties up once per call and
// then works on raw pointers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace sphc {

enum class PropType : std::uint8_t { F64, I32, U32 };

const char* prop_type_name(PropType t);

struct Property {
  std::string name;
  PropType type = PropType::F64;
  int stride = 1;
  std::vector<double> f64;
  std::vector<std::int32_t> i32;
  std::vector<std::uint32_t> u32;
};

// Particle j of `to` takes the values of particle i of `from` (a property of the same type
// and stride; `to` holds j already).
void copy_particle_values(Property& to, std::size_t j, const Property& from, std::size_t i);

struct Constant {
  std::string name;
  std::vector<double> values;
};

struct ParticleArray {
  std::string name;
  std::size_t n = 0;
  std::vector<Property> props;
  std::vector<Constant> constants;

  // Adds a property (sized to n, filled with `init`) and returns its index; if a property of
  // that name exists, returns its index unchanged (type and stride must match, else throws
  // std::invalid_argument naming the array and property).
  int add_property(const std::string& name, PropType type = PropType::F64, int stride = 1,
                   double init = 0.0);
  // Index of a property, -1 if absent.
  int find(const std::string& name) const;
  // Resizes every property to n particles (new entries are 0).
  void resize(std::size_t n);

  double* f64(int idx) { return props[idx].f64.data(); }
  std::int32_t* i32(int idx) { return props[idx].i32.data(); }
  std::uint32_t* u32(int idx) { return props[idx].u32.data(); }
  const double* f64(int idx) const { return props[idx].f64.data(); }
  // By name; throws std::out_of_range naming the array and property if absent or not F64.
  double* f64(const std::string& name);
  const double* f64(const std::string& name) const;

  // Adds a constant with `size` values set to `init` (returns index; existing: its index).
  int add_constant(const std::string& name, int size = 1, double init = 0.0);
  int find_constant(const std::string& name) const;
  double* constant(int idx) { return constants[idx].values.data(); }
  double* constant(const std::string& name);  // throws std::out_of_range if absent

  // Reorders the particles: particle i becomes the old particle order[i], for every property
  // (order must be a permutation of 0..n-1; throws std::invalid_argument otherwise). Used to
  // keep neighbours close in memory (the cell order of the neighbour search). Parallel in the
  // OpenMP runtime (each new slot is written by one thread), with the serial result.
  void permute(const std::vector<std::uint32_t>& order);

  // Appends particle `i` of `src` (same property names) to this array; properties missing in
  // src are 0. Used by inlets and by loading.
  void append_from(const ParticleArray& src, std::size_t i);

  // Removes the particles i with remove[i] != 0 (remove.size() == n, else
  // std::invalid_argument), keeping the order of the others (a stable compaction of every
  // property); returns how many were removed. The storage keeps its capacity, so an array
  // that shrinks and grows again (outlets and inlets) does not reallocate. Serial: the same
  // result on every backend.
  std::size_t remove_particles(const std::vector<std::uint8_t>& remove);
};

// True if order holds each of 0..n-1 exactly once.
bool is_permutation_of(const std::vector<std::uint32_t>& order, std::size_t n);

// The first NaN or infinity among the double (F64) properties of the arrays, in the order
// array, property, value (index into Property::f64, i.e. particle * stride + component);
// nullopt if every value is finite. The run loop's blow-up check. The OpenMP runtime scans
// blocks of values in parallel and takes the first bad block (a min reduction), so it finds
// the same value as the serial scan.
struct NonFiniteValue {
  std::size_t array = 0;  // index into `arrays`
  std::size_t prop = 0;   // index into that array's props
  std::size_t index = 0;  // into props[prop].f64
};
std::optional<NonFiniteValue> find_non_finite(const std::vector<ParticleArray*>& arrays);

}  // namespace sphc
