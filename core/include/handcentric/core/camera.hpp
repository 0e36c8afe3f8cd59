#pragma once
// A pinhole camera and the images it renders by ray casting: depth, and colour by simple shading.
// One camera model for the simulator's hand camera (sim/insert3d) and the audit's observation
// models (props/observation), so that what the audit hands a policy is what the task renders.
//
// Camera frame (OpenCV's): +z along the optical axis, +x to the right of the image, +y down.
// Pixel (row, col) looks along ((col + 0.5 - W/2) / f, (row + 0.5 - H/2) / f, 1) with
// f = (W/2) / tan(horizontal_fov / 2), so the ray parameter of a hit is its depth (camera z).
// A ray that hits nothing within max_range reads max_range and colour 0 (black).
//
// Colour: albedo * (ambient + (1 - ambient) max(0, -n . l)), n the outward normal at the hit and
// l the direction the light travels. A head light travels along the optical axis and moves with
// the camera; a directional light is fixed in the rendering frame (a world-fixed lamp, which
// does not move with a global transform g: see props/observation/camera_rig.hpp).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/solid.hpp"

namespace handcentric {

struct PinholeCamera {
  int width = 64;
  int height = 48;
  double horizontal_fov_deg = 90.0;
  /// Depth read where a ray hits nothing, in the scene's length unit.
  double max_range = 20.0;

  /// Throws InvalidArgument naming the value and the fix: sizes outside [1, 4096], a field of
  /// view outside (0, 170) deg, a non-positive or non-finite range. `what` names the camera in
  /// the message (e.g. "depth camera").
  void validate(const std::string& what = "camera") const;

  /// f, the focal length in pixels.
  double focal_length() const;

  /// The ray of pixel (row, col) in the camera frame, with z = 1 (see the top of this file).
  Eigen::Vector3d pixel_ray(int row, int col) const;
};

struct Light {
  /// True: the light travels along the camera's optical axis (a head light, moves with the
  /// camera). False: it travels along `frame_direction`, fixed in the rendering frame.
  bool head_light = true;
  Eigen::Vector3d frame_direction = -Eigen::Vector3d::UnitZ();
  /// The share of light every lit surface gets, whatever its normal, in [0, 1].
  double ambient = 0.35;

  static Light head() { return Light{}; }
  /// Throws InvalidArgument for a zero or non-finite direction or an ambient outside [0, 1].
  static Light directional(const Eigen::Vector3d& frame_direction, double ambient = 0.35);
};

/// A rendered image, row-major: depth(row, col) = depth[row * width + col], colour channel c of
/// that pixel = rgb[3 (row * width + col) + c], in [0, 1].
struct CameraImage {
  int width = 0;
  int height = 0;
  std::vector<double> depth;
  std::vector<double> rgb;

  double depth_at(int row, int col) const {
    return depth[static_cast<std::size_t>(row) * static_cast<std::size_t>(width) +
                 static_cast<std::size_t>(col)];
  }
};

/// The image `camera` at frame_T_camera sees of `solids` (each placed in the same frame F) lit by
/// `light`. Each solid is hit in its own frame (solid.hpp). Throws InvalidArgument for a bad
/// camera.
CameraImage render(const std::vector<Solid>& solids, const PinholeCamera& camera,
                   const RigidTransform& frame_T_camera, const Light& light = Light::head());

/// The largest absolute difference of the depths and of the colours of two images of one size;
/// +infinity when their sizes differ.
double largest_image_difference(const CameraImage& a, const CameraImage& b);

}  // namespace handcentric
