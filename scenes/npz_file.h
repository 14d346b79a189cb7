// NumPy's files read into arrays of numbers (internal to the scene library): an .npz is a zip of
// .npy members, stored (numpy.savez) or deflated (numpy.savez_compressed), zip64 included; an
// .npy is one array. Read: little- and big-endian integers (1, 2, 4, 8 bytes, signed or not),
// floats (4, 8 bytes) and booleans, in C or Fortran order, of any shape. Not read: pickled
// object arrays, strings, complex numbers, structured types; encrypted or otherwise compressed
// members. `[system] from = "FILE.npz"` gives the [system] arrays this way.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace flexure::scenes::detail {

struct NumpyArray {
  std::string name;            // the member's name without ".npy" (an .npy file: its stem)
  std::vector<size_t> shape;   // () for a scalar
  std::vector<double> values;  // in C (row-major) order
  bool integer = false;        // an integer or boolean type (every value exact as a double)
};

// Every array of an .npz or .npy file's bytes; SceneError at `file` (line 1, column 1) with what
// cannot be read, naming the member.
std::vector<NumpyArray> readNumpyBytes(std::string_view bytes, const std::string& file);

// The same for a file on disk (up to 4 GiB).
std::vector<NumpyArray> readNumpyFile(const std::string& path);

}  // namespace flexure::scenes::detail
