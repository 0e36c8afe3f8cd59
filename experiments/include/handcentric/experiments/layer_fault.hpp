#pragma once
// A planted fault for locating (model_locate.hpp): a model whose layer gets a world-frame bias,
// the world frame leaking into the network in the middle, where no input of it is. What the
// report page locates beside the hand-centric model it is planted in, and what the tests of
// `audit --model --locate` find at the right layer.
#include <memory>
#include <string>
#include <vector>

#include "handcentric/core/chunk_policy.hpp"

namespace handcentric::experiments {

class WorldFrameBias final : public ChunkPolicy {
 public:
  /// `model` (a policy on this library's networks) with `scale` times the world x coordinate of
  /// the current hand pose T_0 added to every unit of the output of `layer` (a name of
  /// policy/layer_watch.hpp, e.g. "mlp.layer2") at each of its calls, before the next layer
  /// reads it. Throws InvalidArgument for a null model or an empty layer name.
  WorldFrameBias(std::shared_ptr<const ChunkPolicy> model, std::string layer, double scale = 0.1);

  /// "<model> + world-frame bias at <layer>".
  std::string name() const override;
  std::vector<RigidTransform> act(const Scene& observation,
                                  std::uint64_t noise_seed) const override;

 private:
  std::shared_ptr<const ChunkPolicy> model_;
  std::string layer_;
  double scale_;
};

}  // namespace handcentric::experiments
