#pragma once
// LayerWatch: this library's forward hooks. While a ScopedLayerWatch is alive on a thread, every
// layer of this library's networks that runs on that thread hands its output to the watch, in
// execution order (what PyTorch's register_forward_hook on every module of named_modules() sees):
//
//   "observation"        LearnedPolicy: the observation vector as the representation encoded it
//                        (an image policy's: proprioception, then the image)     (double)
//   "encoder.conv<l>"    ConvEncoder: layer l's SiLU map, l = 1, 2, ...           (float)
//   "encoder.keypoints"  SpatialSoftmax: the (x, y) per channel of the last map   (float)
//   "mlp.layer<l>"       Mlp::infer: hidden layer l after its activation, the last layer's
//                        linear output; once per call (each sampling step)       (float)
//   "action"             LearnedPolicy: the head's raw action vector, before decoding (double)
//
// One column per sample. A watch may change the output in place (a planted fault: a world-frame
// bias added to a layer), and the network goes on with the changed values, as PyTorch's hook
// may replace a module's output. Watches nest: the innermost sees an output first, then the
// ones outside it. Nothing is watched on other threads (a training step's SliceTeam lanes), and
// with no watch alive a layer pays one thread-local load.
#include <Eigen/Core>
#include <string>

namespace handcentric::policy {

class LayerWatch {
 public:
  virtual ~LayerWatch() = default;
  /// `layer`'s output (one column per sample), float32 for the network's layers.
  virtual void output(const std::string& layer, Eigen::Ref<Eigen::MatrixXf> value) = 0;
  /// The same for the double vectors around the network ("observation", "action").
  virtual void output(const std::string& layer, Eigen::Ref<Eigen::MatrixXd> value) = 0;
};

/// Installs `watch` on this thread until destroyed (inside any watch already installed).
class ScopedLayerWatch {
 public:
  explicit ScopedLayerWatch(LayerWatch& watch);
  ~ScopedLayerWatch();
  ScopedLayerWatch(const ScopedLayerWatch&) = delete;
  ScopedLayerWatch& operator=(const ScopedLayerWatch&) = delete;

 private:
  LayerWatch* watch_;
};

/// True when a watch is alive on this thread (a layer builds its name only then).
bool layers_watched();

/// Hands `value` to this thread's watches, innermost first: `name`, or `name` followed by
/// `index` when index >= 1 ("mlp.layer" and 2 give "mlp.layer2"). No-op when none is alive.
void watch_layer(const char* name, int index, Eigen::Ref<Eigen::MatrixXf> value);
void watch_layer(const char* name, int index, Eigen::Ref<Eigen::MatrixXd> value);

}  // namespace handcentric::policy
