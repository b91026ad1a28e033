// sphc runtime, internal: the HDF5 type of each property type, shared by the serial writer
// and reader (hdf5_io.cpp) and the collective writer (mpi/output.cpp, compiled against the
// parallel HDF5 headers: the macros resolve to that library's types there).
#pragma once

#include <hdf5.h>

#include "sphc/particle_array.h"

namespace sphc {

inline hid_t native_type(PropType t) {
  switch (t) {
    case PropType::F64: return H5T_NATIVE_DOUBLE;
    case PropType::I32: return H5T_NATIVE_INT32;
    case PropType::U32: return H5T_NATIVE_UINT32;
  }
  return H5T_NATIVE_DOUBLE;
}

}  // namespace sphc
