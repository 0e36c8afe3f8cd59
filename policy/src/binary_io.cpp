#include "handcentric/policy/binary_io.hpp"

#include <bit>
#include <cstring>

#include "handcentric/policy/errors.hpp"

namespace handcentric::policy {

static_assert(std::endian::native == std::endian::little, "model files are written little-endian");

void ByteWriter::raw(const void* data, std::size_t size) {
  bytes_.append(static_cast<const char*>(data), size);
}
void ByteWriter::u32(std::uint32_t value) {
  raw(&value, sizeof value);
}
void ByteWriter::u64(std::uint64_t value) {
  raw(&value, sizeof value);
}
void ByteWriter::f64(double value) {
  raw(&value, sizeof value);
}
void ByteWriter::string(const std::string& value) {
  u64(value.size());
  raw(value.data(), value.size());
}
void ByteWriter::floats(const Eigen::VectorXf& values) {
  u64(static_cast<std::uint64_t>(values.size()));
  raw(values.data(), sizeof(float) * static_cast<std::size_t>(values.size()));
}
void ByteWriter::doubles(const Eigen::VectorXd& values) {
  u64(static_cast<std::uint64_t>(values.size()));
  raw(values.data(), sizeof(double) * static_cast<std::size_t>(values.size()));
}

ByteReader::ByteReader(const std::string& bytes, std::string source, std::size_t begin,
                       std::size_t end)
    : bytes_(bytes),
      source_(std::move(source)),
      position_(begin),
      end_(std::min(end, bytes.size())) {}

void ByteReader::fail(const std::string& what) const {
  throw InvalidModelFile(
      source_ + ": " + what + " (at byte " + std::to_string(position_) +
      "); the file is damaged or not a handcentric model: train it again with `handcentric train`");
}

void ByteReader::take(void* out, std::size_t size) {
  if (size > end_ - position_) fail("truncated: needed " + std::to_string(size) + " more bytes");
  std::memcpy(out, bytes_.data() + position_, size);
  position_ += size;
}

std::uint32_t ByteReader::u32() {
  std::uint32_t value = 0;
  take(&value, sizeof value);
  return value;
}
std::uint64_t ByteReader::u64() {
  std::uint64_t value = 0;
  take(&value, sizeof value);
  return value;
}
double ByteReader::f64() {
  double value = 0;
  take(&value, sizeof value);
  return value;
}

std::string ByteReader::string(std::size_t max_length) {
  const std::uint64_t size = u64();
  if (size > max_length || size > end_ - position_)
    fail("a string of " + std::to_string(size) + " bytes");
  std::string value(bytes_.data() + position_, size);
  position_ += size;
  return value;
}

namespace {
template <typename Vector>
Vector allocate_vector(ByteReader& reader, Eigen::Index expected) {
  using Scalar = typename Vector::Scalar;
  const std::uint64_t size = reader.u64();
  if (expected >= 0 && size != static_cast<std::uint64_t>(expected)) {
    reader.fail("an array of " + std::to_string(size) + " numbers where " +
                std::to_string(expected) + " belong");
  }
  if (size > reader.remaining() / sizeof(Scalar))
    reader.fail("truncated: an array of " + std::to_string(size) + " numbers");
  Vector values(static_cast<Eigen::Index>(size));
  return values;
}
}  // namespace

Eigen::VectorXf ByteReader::floats(Eigen::Index expected) {
  Eigen::VectorXf values = allocate_vector<Eigen::VectorXf>(*this, expected);
  take(values.data(), sizeof(float) * static_cast<std::size_t>(values.size()));
  if (!values.allFinite()) fail("a non-finite weight");
  return values;
}

Eigen::VectorXd ByteReader::doubles(Eigen::Index expected) {
  Eigen::VectorXd values = allocate_vector<Eigen::VectorXd>(*this, expected);
  take(values.data(), sizeof(double) * static_cast<std::size_t>(values.size()));
  if (!values.allFinite()) fail("a non-finite statistic");
  return values;
}

std::uint64_t fnv1a64(const char* data, std::size_t size) {
  std::uint64_t hash = 14695981039346656037ull;
  for (std::size_t i = 0; i < size; ++i) {
    hash ^= static_cast<unsigned char>(data[i]);
    hash *= 1099511628211ull;
  }
  return hash;
}

}  // namespace handcentric::policy
