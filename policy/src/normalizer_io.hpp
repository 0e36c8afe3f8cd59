#pragma once
// The normalization statistics as a model file stores them (action mean, scale, active mask,
// then observation mean, scale), shared by every head's write() and read().
#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/policy/binary_io.hpp"
#include "handcentric/policy/config.hpp"
#include "handcentric/policy/normalizer.hpp"

namespace handcentric::policy {

inline void write_normalizers(ByteWriter& out, const Normalizer& actions,
                              const Normalizer& observations) {
  out.doubles(actions.mean());
  out.doubles(actions.scale());
  out.doubles(actions.active());
  out.doubles(observations.mean());
  out.doubles(observations.scale());
}

/// Reads what write_normalizers() wrote; bad statistics fail the reader with a clear message.
inline void read_normalizers(ByteReader& in, const PolicyConfig& config, Normalizer& actions,
                             Normalizer& observations) {
  try {
    Eigen::VectorXd mean = in.doubles(config.action_dimension);
    Eigen::VectorXd scale = in.doubles(config.action_dimension);
    Eigen::VectorXd active = in.doubles(config.action_dimension);
    actions = Normalizer(mean, scale, active);
    mean = in.doubles(config.observation_dimension);
    scale = in.doubles(config.observation_dimension);
    observations = Normalizer(mean, scale);
  } catch (const InvalidArgument& error) {
    in.fail(std::string("bad normalization statistics: ") + error.what());
  }
}

}  // namespace handcentric::policy
