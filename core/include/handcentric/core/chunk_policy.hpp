#pragma once
// ChunkPolicy: anything that maps an observation to a world-frame action chunk, closed loop.
// The learned outer policy (policy/), the expert and scripted policies (sim/) and the
// equivariance checks (props/) all meet at this interface.
#include <cstdint>
#include <string>
#include <vector>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"

namespace handcentric {

class ChunkPolicy {
 public:
  virtual ~ChunkPolicy() = default;

  virtual std::string name() const = 0;

  /// The world-frame chunk T_1..T_K for `observation` (its history and points; its chunk is
  /// ignored and may be empty). Same observation and same `noise_seed`, same chunk, bit for bit.
  /// Equivariance (eq. 4) means act(g * o, s) = g * act(o, s) for every rigid g.
  virtual std::vector<RigidTransform> act(const Scene& observation,
                                          std::uint64_t noise_seed) const = 0;
};

}  // namespace handcentric
