#pragma once
// Internal: NumPy's .npz files (np.savez, np.savez_compressed), read without Python: a zip
// archive (stored or deflate members, zip64 sizes as NumPy writes them) of .npy arrays
// (format versions 1 to 3, little-endian float64, float32, integers and bools, C order).
// Every size is checked against the file before anything is allocated.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace handcentric::props::npz {

struct Array {
  std::vector<std::int64_t> shape;
  std::vector<double> values;  ///< row-major; every supported dtype widens to double exactly
  bool float32 = false;        ///< stored as float32 (kept so, for a policy's images)
  std::string dtype;           ///< NumPy's descr, e.g. "<f8", for messages
};

/// The arrays of an .npz file by name (".npy" dropped), sorted. Throws FileError naming the
/// file and what is wrong with it: missing, not a zip, truncated, a member that is not .npy, a
/// compression other than stored or deflate, an unsupported dtype or Fortran order (with the
/// fix: np.ascontiguousarray, astype), a member above `max_bytes` decompressed.
std::map<std::string, Array> read(const std::string& path, std::uint64_t max_bytes);

}  // namespace handcentric::props::npz
