#include "handcentric/experiments/layer_fault.hpp"

#include "handcentric/core/errors.hpp"
#include "handcentric/policy/layer_watch.hpp"

namespace handcentric::experiments {
namespace {

// Adds `bias` to every unit of one layer's output, as it passes (a watch installed inside any
// recording one, so a recorder sees the biased values the next layer reads).
class AddBias final : public policy::LayerWatch {
 public:
  AddBias(const std::string& layer, double bias) : layer_(layer), bias_(bias) {}
  void output(const std::string& layer, Eigen::Ref<Eigen::MatrixXf> value) override {
    if (layer == layer_) value.array() += static_cast<float>(bias_);
  }
  void output(const std::string& layer, Eigen::Ref<Eigen::MatrixXd> value) override {
    if (layer == layer_) value.array() += bias_;
  }

 private:
  const std::string& layer_;
  double bias_;
};

}  // namespace

WorldFrameBias::WorldFrameBias(std::shared_ptr<const ChunkPolicy> model, std::string layer,
                               double scale)
    : model_(std::move(model)), layer_(std::move(layer)), scale_(scale) {
  if (!model_) throw InvalidArgument("WorldFrameBias: null model");
  if (layer_.empty())
    throw InvalidArgument("WorldFrameBias: empty layer name; give one such as mlp.layer2");
}

std::string WorldFrameBias::name() const {
  return model_->name() + " + world-frame bias at " + layer_;
}

std::vector<RigidTransform> WorldFrameBias::act(const Scene& observation,
                                                std::uint64_t noise_seed) const {
  AddBias bias(layer_, scale_ * observation.world_T_hand0().translation().x());
  const policy::ScopedLayerWatch watch(bias);
  return model_->act(observation, noise_seed);
}

}  // namespace handcentric::experiments
