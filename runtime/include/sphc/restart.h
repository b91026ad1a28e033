// sphc runtime: restarting a run from one of its output files (--restart FILE).
//
// What a restart needs (docs/design.md, "Restart"):
//   - every property of every array and the arrays' constants: an output written with
//     --restartable has them all (a plain output only the scene's selection);
//   - the root attributes t, dt (the last step's length) and step, and the run state
//     (OutputMeta::state, attributes restart_NAME): the time loop's landing point for a fixed
//     dt (landed_t, landed_step) and the scene's counters (SceneProgram::run_state).
// The output times already written follow from t (the run loop marks the times up to it as
// written, as the uninterrupted run had). A restart from a file written at the end of a step
// therefore continues exactly as the run that wrote it: on the serial and OpenMP backends the
// outputs are bitwise those of the uninterrupted run (tests/lit/restart). The cluster-pair
// tiles' layout and slot order are in no file: a --restartable run starts them afresh after
// each output (SceneProgram::restart_point, stop 43), as the restarted run does, so a restart
// from one of its outputs is bitwise in the tiles too (from a last file at a step that was no
// output of the uninterrupted run, only in the scalar loops and the lanes).
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "sphc/hdf5_io.h"
#include "sphc/inlet_outlet.h"
#include "sphc/particle_array.h"

namespace sphc {

using RunState = std::vector<std::pair<std::string, double>>;

// Reads the output file `path` into `arrays` (the solver's, after its set-up): each array's
// particles become the file's (block `part` of `parts`: a distributed run's rank reads its
// block, sphc/mpi re-balances after), every property of the solver's array taken from the
// file's dataset of that name (type and stride must agree), and every constant. Throws
// std::runtime_error naming the file and what does not fit: another scene or dimension, an
// array or property or constant the file lacks (a plain output: written without
// --restartable), a property the solver lacks (other than gid, and the zero y or z of a 1D or
// 2D file), a constant of another size. Returns the file's root attributes.
OutputMeta read_restart(const std::string& path, const std::vector<ParticleArray*>& arrays,
                        const std::string& scene, int dim, std::size_t part = 0,
                        std::size_t parts = 1);

// The value `name` of a run state read from a restart file; throws std::runtime_error when
// the file has none (a file written by a solver without that state).
double state_value(const RunState& state, const std::string& name);
// The same, or `otherwise` when the file has none (state a restart can do without).
double state_value(const RunState& state, const std::string& name, double otherwise);

// The inlet/outlet manager's state (sphc/inlet_outlet.h): the next global id, each zone's
// counters and a characteristic or hybrid outlet's running means (u_ref; hybrid: and the
// pressure's; per bin, with t_last), appended to `state` as io.NAME; restore_inlet_outlet
// sets them from a file's.
void inlet_outlet_state(const InletOutlet& io, RunState& state);
void restore_inlet_outlet(InletOutlet& io, const RunState& state);

}  // namespace sphc
