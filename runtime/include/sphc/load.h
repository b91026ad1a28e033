// sphc runtime: arrays whose particles come from files (`load "file.h5";` in a scene).
// Positions are appended after those of the array's geometry; properties the file holds
// override the scene's initial values for the loaded particles.
#pragma once

#include "sphc/geometry.h"
#include "sphc/particle_array.h"

#include <string>
#include <vector>

namespace sphc {

// Reads `path` (.h5/.hdf5: the group named `array`; .csv: columns with a header row);
// a relative path is taken relative to `dir` (the directory of the .sph file).
ParticleArray load_particles(const std::string& dir, const std::string& path,
                             const std::string& array);
// The positions of a loaded array (missing y/z are 0).
Points positions_of(const ParticleArray& a);
// Copies the properties of `loaded` (in order) into the last particles of `a`, which holds
// `total` particles: the loaded ones are at its end, in the same order.
void apply_loaded(ParticleArray& a, std::size_t total, const std::vector<ParticleArray>& loaded);

}  // namespace sphc
