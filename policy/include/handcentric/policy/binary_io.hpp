#pragma once
// Little-endian byte buffers for model files: a writer that appends, and a reader that checks
// every read against the end of the data, so a truncated or corrupted file is an
// InvalidModelFile error naming the file, never an out-of-bounds read.
#include <Eigen/Core>
#include <cstdint>
#include <string>

namespace handcentric::policy {

class ByteWriter {
 public:
  void u32(std::uint32_t value);
  void u64(std::uint64_t value);
  void f64(double value);
  void string(const std::string& value);
  void floats(const Eigen::VectorXf& values);
  void doubles(const Eigen::VectorXd& values);
  void raw(const void* data, std::size_t size);
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

class ByteReader {
 public:
  /// `source` names the file in error messages.
  ByteReader(const std::string& bytes, std::string source, std::size_t begin = 0,
             std::size_t end = std::string::npos);
  std::uint32_t u32();
  std::uint64_t u64();
  double f64();
  /// A length-prefixed string of at most `max_length` bytes.
  std::string string(std::size_t max_length = 1 << 20);
  /// A length-prefixed vector; throws InvalidModelFile for a length != `expected` (when given)
  /// or a non-finite entry.
  Eigen::VectorXf floats(Eigen::Index expected = -1);
  Eigen::VectorXd doubles(Eigen::Index expected = -1);
  std::size_t position() const { return position_; }
  bool at_end() const { return position_ == end_; }
  std::size_t remaining() const { return end_ - position_; }
  /// Throws InvalidModelFile "<source>: <what>; ..." .
  [[noreturn]] void fail(const std::string& what) const;

 private:
  void take(void* out, std::size_t size);
  const std::string& bytes_;
  std::string source_;
  std::size_t position_, end_;
};

/// 64-bit FNV-1a of `data` (Fowler-Noll-Vo; offset basis 14695981039346656037, prime
/// 1099511628211).
std::uint64_t fnv1a64(const char* data, std::size_t size);

}  // namespace handcentric::policy
