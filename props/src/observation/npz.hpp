#pragma once
// Internal: NumPy's .npz files (np.savez, np.savez_compressed), read without Python: a zip
// archive read with libzip (stored or deflate members, zip64, each member's CRC checked) of .npy
// arrays (format versions 1 to 3, little-endian float64, float32, integers and bools, C order).
// Every size is checked before anything is allocated for it.
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace handcentric::props::npz {

struct Array {
  std::vector<std::int64_t> shape;
  std::vector<double> values;  ///< row-major; every supported dtype widens to double exactly
  bool float32 = false;        ///< stored as float32 (kept so, for a policy's images)
  std::string dtype;           ///< NumPy's descr, e.g. "<f8", for messages
};

/// The arrays of an .npz file by name (".npy" dropped), sorted. Throws FileError naming the
/// file and what is wrong with it: missing, not a zip, truncated or damaged, a member that is
/// not .npy, a compression other than stored or deflate, encryption, a CRC mismatch, an
/// unsupported dtype or Fortran order (with the fix: np.ascontiguousarray, astype), a file or a
/// member above `max_bytes` (decompressed).
std::map<std::string, Array> read(const std::string& path, std::uint64_t max_bytes);

/// The same from the file's bytes in memory; `source` names them in messages as a path would.
std::map<std::string, Array> read_bytes(std::string_view bytes, const std::string& source,
                                        std::uint64_t max_bytes);

}  // namespace handcentric::props::npz

namespace handcentric::props {

// Declared, not included: recorded.cpp reads .npz files through this header, so this header
// reaching back up to recorded.hpp would be an include running back up; callers include both.
struct RecordedObservations;

/// read_observations of an .npz file's bytes (the fuzz target's and the mutation test's entry,
/// recorded.cpp); `source` names them in messages as a path would.
RecordedObservations observations_from_npz(std::string_view bytes, const std::string& source);

}  // namespace handcentric::props
