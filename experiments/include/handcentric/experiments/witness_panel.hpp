#pragma once
// The camera image a policy was shown of a witness (`handcentric audit --witness-dir`), as a
// picture: the colour image beside its depth (near bright, black at the camera's range), each
// pixel 4 x 4, so that a 64 x 48 image reads at a glance. The pixels are the camera's data, so
// the panel is a raster with no text on it.
#include "handcentric/core/camera.hpp"
#include "handcentric/sim/image.hpp"

namespace handcentric::experiments {

/// `image` as colour | depth, 4x enlarged, a 4-pixel white gap between them.
sim::Image witness_panel(const CameraImage& image, double max_range);

}  // namespace handcentric::experiments
