#include "handcentric/policy/model_file.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "handcentric/core/atomic_file.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/policy/binary_io.hpp"
#include "handcentric/policy/errors.hpp"

namespace handcentric::policy {
namespace {
constexpr char kMagic[8] = {'H', 'C', 'P', 'O', 'L', 'I', 'C', 'Y'};
constexpr std::size_t kHeaderBytes = 8 + 4 + 8;
}  // namespace

std::string serialize_model(const LearnedPolicy& policy) {
  ByteWriter payload;
  payload.string(policy.config().to_text());
  payload.string(policy.representation().name());
  payload.string(to_string(policy.head().kind()));
  policy.head().write(payload);
  ByteWriter file;
  file.raw(kMagic, sizeof kMagic);
  file.u32(kModelFormatVersion);
  file.u64(payload.bytes().size());
  file.raw(payload.bytes().data(), payload.bytes().size());
  file.u64(fnv1a64(file.bytes().data(), file.bytes().size()));
  return file.bytes();
}

LearnedPolicy deserialize_model(const std::string& bytes, const std::string& source,
                                const SamplingOverrides& overrides) {
  ByteReader header(bytes, source);
  if (bytes.size() > kMaxModelFileBytes) {
    throw InvalidModelFile(source + ": " + std::to_string(bytes.size()) + " bytes, more than the " +
                           std::to_string(kMaxModelFileBytes) +
                           " a model file may have: give a file written by "
                           "`handcentric train --out`");
  }
  if (bytes.size() < sizeof kMagic || bytes.compare(0, sizeof kMagic, kMagic, sizeof kMagic) != 0) {
    throw InvalidModelFile(
        source +
        ": not a handcentric model file (it does not start with HCPOLICY): give a "
        "file written by `handcentric train --out`");
  }
  if (bytes.size() < kHeaderBytes + 8) header.fail("truncated header");
  header.u64();  // the magic, checked above
  const std::uint32_t version = header.u32();
  if (version != kModelFormatVersion) {
    throw InvalidModelFile(source + ": model format version " + std::to_string(version) +
                           ", this build reads version " + std::to_string(kModelFormatVersion) +
                           ": retrain the model with this build");
  }
  const std::uint64_t payload_size = header.u64();
  if (payload_size != bytes.size() - kHeaderBytes - 8) {
    header.fail("the header announces " + std::to_string(payload_size) +
                " payload bytes but the file has " +
                std::to_string(bytes.size() - kHeaderBytes - 8) + " (truncated or appended to)");
  }
  std::uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + bytes.size() - 8, 8);
  if (stored != fnv1a64(bytes.data(), bytes.size() - 8))
    header.fail("checksum mismatch (corrupted)");

  ByteReader in(bytes, source, kHeaderBytes, bytes.size() - 8);
  PolicyConfig config;
  try {
    config = PolicyConfig::from_text(in.string());
  } catch (const InvalidArgument& error) {
    in.fail(std::string("bad config: ") + error.what());
  }
  if (overrides.noise_scale) config.noise_scale = *overrides.noise_scale;
  if (overrides.execute) config.execute = *overrides.execute;
  if (overrides.euler_steps) config.euler_steps = *overrides.euler_steps;
  config.validate();
  const std::string representation_name = in.string(256);
  const std::string head_name = in.string(256);
  if (representation_name != config.representation || head_name != to_string(config.head)) {
    in.fail("the config says " + to_string(config.head) + "/" + config.representation +
            " but the file stores " + head_name + "/" + representation_name);
  }
  // Before make_head allocates the network (and Adam's state beside it): the weights it
  // describes must be in this file, so a damaged or hostile config cannot ask for more memory
  // than a few times the file's size.
  std::uint64_t parameters = 0;
  try {
    parameters = parameter_count(config);
  } catch (const InvalidArgument& error) {
    in.fail(error.what());
  }
  if (parameters > in.remaining() / sizeof(float)) {
    in.fail("the config describes a network of " + std::to_string(parameters) + " parameters (" +
            std::to_string(parameters * sizeof(float)) + " bytes of weights) but only " +
            std::to_string(in.remaining()) + " bytes follow");
  }
  std::shared_ptr<const Representation> representation;
  std::shared_ptr<Head> head;
  try {
    representation = make_representation(representation_name);
    head = make_head(config);
  } catch (const InvalidArgument& error) {
    in.fail(error.what());
  }
  head->read(in);
  if (!in.at_end()) in.fail(std::to_string(in.remaining()) + " unexpected bytes after the weights");
  return LearnedPolicy(config, representation, head);
}

void save_model(const LearnedPolicy& policy, const std::string& path) {
  write_file_atomically(path, serialize_model(policy));
}

LearnedPolicy load_model(const std::string& path, const SamplingOverrides& overrides) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw InvalidModelFile(
        path + ": no such model file: give the path written by `handcentric train --out`");
  }
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error)
    throw InvalidModelFile(path + ": cannot read the file's size (" + error.message() +
                           "): check its permissions");
  if (size > kMaxModelFileBytes) {
    throw InvalidModelFile(path + ": " + std::to_string(size) + " bytes, more than the " +
                           std::to_string(kMaxModelFileBytes) +
                           " a model file may have (checked before reading): "
                           "give a file written by `handcentric train --out`");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InvalidModelFile(path + ": cannot open the file: check its permissions");
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size ||
      in.peek() != std::char_traits<char>::eof()) {
    throw InvalidModelFile(path + ": the file changed while it was read: load it again");
  }
  return deserialize_model(bytes, path, overrides);
}

void require_task(const LearnedPolicy& policy, const std::string& task, const std::string& source) {
  const std::string& trained = policy.config().task;
  if (trained == task) return;
  throw TaskMismatch(source + ": a model trained on task '" + trained + "', used on task '" + task +
                     "': pass --task " + trained + " to use it, or train a model for " + task +
                     " with `handcentric train --task " + task + " --demos <" + task + " demos>`");
}

}  // namespace handcentric::policy
