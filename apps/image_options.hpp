#pragma once
// The image policy's options that `train` and `table2` share (--observation image): the hand
// cameras' channels, size, field of view and number, the encoder and its features; one place for
// their flags, help and defaults (experiments::Insert3dImageSettings).
#include <CLI/CLI.hpp>
#include <memory>
#include <tuple>
#include <string>

#include "handcentric/experiments/insert3d_image.hpp"

namespace handcentric::apps {

struct ImageFlags {
  std::string channels;
  std::string size;  ///< WxH; empty: the default
  std::string features;
  experiments::Insert3dImageSettings settings;

  /// The settings the flags give. Throws InvalidArgument for a bad size or feature name.
  experiments::Insert3dImageSettings resolve() const {
    experiments::Insert3dImageSettings out = settings;
    out.channels = experiments::parse_insert3d_image_channels(channels);
    if (!size.empty()) std::tie(out.width, out.height) = experiments::parse_image_size(size);
    if (!features.empty()) out.features = policy::parse_image_features(features);
    return out;
  }
};

inline void add_image_options(CLI::App* cmd, const std::shared_ptr<ImageFlags>& flags) {
  experiments::Insert3dImageSettings& s = flags->settings;
  flags->size = std::to_string(s.width) + "x" + std::to_string(s.height);
  flags->features = policy::to_string(s.features);
  flags->channels = experiments::to_string(s.channels);
  cmd->add_option("--image-channels", flags->channels,
                  "--observation image: depth, rgbd (the camera's shaded colour and depth) or "
                  "normals (the surface normal's x, y from the depth, and depth)")
      ->check(CLI::IsMember({"depth", "rgbd", "normals"}))
      ->capture_default_str();
  cmd->add_option("--image-size", flags->size, "--observation image: the hand camera's WxH pixels")
      ->capture_default_str();
  cmd->add_option("--image-fov", s.fov_deg,
                  "--observation image: the hand camera's horizontal field of view (deg)")
      ->capture_default_str();
  cmd->add_option("--image-cameras", s.cameras,
                  "--observation image: hand cameras, 1 or 2 (the second the first's mirror about "
                  "the blade, seeing what the blade hides; their images stacked as channels)")
      ->check(CLI::IsMember({1, 2}))
      ->capture_default_str();
  cmd->add_option("--encoder", s.encoder,
                  "--observation image: out channels of each 3x3 convolution, comma-separated, "
                  "stride 2 unless written C/1")
      ->capture_default_str();
  cmd->add_option("--image-features", flags->features,
                  "--observation image: flatten (the last map) or spatial_softmax (an x, y per "
                  "channel)")
      ->check(CLI::IsMember({"flatten", "spatial_softmax"}))
      ->capture_default_str();
}

}  // namespace handcentric::apps
