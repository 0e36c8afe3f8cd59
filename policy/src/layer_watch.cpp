#include "handcentric/policy/layer_watch.hpp"

#include <algorithm>
#include <vector>

namespace handcentric::policy {
namespace {

// This thread's watches, outermost first.
thread_local std::vector<LayerWatch*> watches;

std::string layer_name(const char* name, int index) {
  return index >= 1 ? std::string(name) + std::to_string(index) : std::string(name);
}

template <typename Value>
void hand_to_watches(const char* name, int index, Value& value) {
  if (watches.empty()) return;
  const std::string layer = layer_name(name, index);
  // A copy: a watch that installs another one while it looks must not move this loop's vector.
  const std::vector<LayerWatch*> now = watches;
  for (auto it = now.rbegin(); it != now.rend(); ++it) (*it)->output(layer, value);
}

}  // namespace

ScopedLayerWatch::ScopedLayerWatch(LayerWatch& watch) : watch_(&watch) {
  watches.push_back(watch_);
}

ScopedLayerWatch::~ScopedLayerWatch() {
  const auto it = std::find(watches.rbegin(), watches.rend(), watch_);
  if (it != watches.rend()) watches.erase(std::next(it).base());
}

bool layers_watched() {
  return !watches.empty();
}

void watch_layer(const char* name, int index, Eigen::Ref<Eigen::MatrixXf> value) {
  hand_to_watches(name, index, value);
}

void watch_layer(const char* name, int index, Eigen::Ref<Eigen::MatrixXd> value) {
  hand_to_watches(name, index, value);
}

}  // namespace handcentric::policy
