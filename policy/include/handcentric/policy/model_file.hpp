#pragma once
// Model files: one trained LearnedPolicy, versioned and checksummed.
//
//   magic        8 bytes "HCPOLICY"        (anything else: not a handcentric model)
//   version      u32 = kModelFormatVersion
//   payload size u64
//   payload      config (PolicyConfig::to_text), representation name, head kind,
//                the head's normalization statistics and weights (Head::write)
//   checksum     u64 FNV-1a 64 of every byte before it
//
// Little-endian; written to "<path>.tmp.<pid>" and renamed over `path` (atomic on POSIX).
//
// Bounded input: a file above kMaxModelFileBytes is refused from its size, before it is read,
// and a config is refused before the head is built when the network it describes has more
// weights than the payload has bytes for (a file claiming 1e12 parameters allocates nothing).
// Loading then costs a few times the file's size (weights, optimizer state).
#include <cstdint>
#include <optional>
#include <string>

#include "handcentric/policy/learned_policy.hpp"

namespace handcentric::policy {

constexpr std::uint32_t kModelFormatVersion = 1;

/// The largest model file load_model reads: 256 MiB, 64M float32 weights (the default network
/// has ~0.2M; width 4096 x 3 layers ~34M).
constexpr std::uint64_t kMaxModelFileBytes = std::uint64_t{256} << 20;

/// The file's bytes (for tests that damage them).
std::string serialize_model(const LearnedPolicy& policy);

/// Settings that change how a trained model samples and acts, not its weights; a set one
/// replaces the stored value (PolicyConfig::noise_scale, execute, euler_steps).
struct SamplingOverrides {
  std::optional<double> noise_scale;
  std::optional<int> execute;
  std::optional<int> euler_steps;
};

/// Throws InvalidModelFile naming `source` for any damage: truncated, wrong magic, wrong version,
/// bad checksum, a config or lengths that do not fit, trailing bytes, more than
/// kMaxModelFileBytes, a network larger than the file; InvalidArgument for an override out of
/// its range (PolicyConfig::validate).
LearnedPolicy deserialize_model(const std::string& bytes, const std::string& source,
                                const SamplingOverrides& overrides = {});

/// Writes atomically. Throws InvalidArgument naming the path when it cannot be written.
void save_model(const LearnedPolicy& policy, const std::string& path);

/// Throws InvalidModelFile naming the path (missing, unreadable, damaged, or larger than
/// kMaxModelFileBytes, which is checked before reading).
LearnedPolicy load_model(const std::string& path, const SamplingOverrides& overrides = {});

/// Throws TaskMismatch naming `source`, the model's task, `task` and the fix unless `policy` was
/// trained for `task` (PolicyConfig::task; a file without one is a peg2d model).
void require_task(const LearnedPolicy& policy, const std::string& task, const std::string& source);

}  // namespace handcentric::policy
