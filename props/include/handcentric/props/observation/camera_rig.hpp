#pragma once
// The cameras of an audit: the images a policy sees of a scene (core/camera.hpp renders them).
//
//   eye_in_hand  : a camera mounted on the hand (hand_T_camera), rendered in the hand frame. It
//                  sees the eye-in-hand points where they are in the hand frame, and the world
//                  points and extra poses at T_0^-1 q, so g * scene gives the same image for
//                  every g: Theorem 1's assumption ("Guaranteed SE(3)-Equivariant Control via
//                  Hand-Centric Behavior Cloning", Sec. 3.2), made visible.
//   third_person : a camera fixed in the world (world_T_third_person). g moves what it sees, so
//                  its image is not invariant: a policy that reads it is not equivariant.
//
// What is drawn: each eye-in-hand point as an orange sphere, each world point as a green one (of
// radius point_radius), each extra pose as a blue box (2r x r x r/2 along its axes, so that its
// orientation shows). Lit by a head light on each camera, which moves with it.
//
// floor adds what a real cell holds still when g moves the scene: a grey floor, the
// half-space z <= 0 of the world, and a lamp shining straight down (-z). Both are kept by
// rotations about z and x-y translations, so with them the eye-in-hand image is invariant under
// se2 and c8 only (tests/props/test_camera_rig.cpp).
#include <string>
#include <vector>

#include "handcentric/core/camera.hpp"
#include "handcentric/core/scene.hpp"
#include "handcentric/props/view.hpp"

namespace handcentric::props {

/// The camera named "eye_in_hand" or "third_person" (View, view.hpp). Throws InvalidArgument
/// naming the value and the valid names.
View parse_camera_view(const std::string& name);

/// What each pixel carries for a network: depth; red, green, blue; or red, green, blue, depth.
enum class ImageChannels { depth, rgb, rgbd };

/// "depth", "rgb", "rgbd".
std::string to_string(ImageChannels channels);
/// Throws InvalidArgument naming the value and the valid names.
ImageChannels parse_image_channels(const std::string& name);
/// 1, 3 or 4.
int channel_count(ImageChannels channels);

struct CameraRig {
  /// The cameras rendered, in this order (a name at most once).
  std::vector<View> views = {View::eye_in_hand};
  /// Both cameras' intrinsics; lengths in the scene's unit (metres for the audit's scenes).
  PinholeCamera camera{64, 48, 90.0, 20.0};
  ImageChannels channels = ImageChannels::rgbd;
  double point_radius = 0.05;
  bool floor = false;
  /// At the hand's origin, looking along the hand's +z axis.
  RigidTransform hand_T_camera;
  RigidTransform world_T_third_person =
      look_at(Eigen::Vector3d(2.0, -2.0, 1.5), Eigen::Vector3d::Zero());

  /// A camera at `world_eye` whose optical axis points at `world_target`, the image's "up" toward
  /// world +z (OpenCV's frame: x right, y down). Throws InvalidArgument when the two points are
  /// equal or the axis is vertical (no "up" to keep).
  static RigidTransform look_at(const Eigen::Vector3d& world_eye,
                                const Eigen::Vector3d& world_target);

  /// Throws InvalidArgument naming the value and the fix: no view or one twice, a bad camera, a
  /// point radius that is not positive and finite.
  void validate() const;
};

/// The images of rig.views, in that order, for `observation` (its history's T_0, points and extra
/// poses; the chunk is not read). Throws InvalidArgument for a bad rig, InvalidScene for a scene
/// without a history.
std::vector<CameraImage> render_views(const Scene& observation, const CameraRig& rig);

/// An image as a network reads it: channels-first (C, height, width), row-major, as float32
/// (PyTorch's Conv2d layout). RGB in [0, 1], depth in the scene's unit.
std::vector<float> network_image(const CameraImage& image, ImageChannels channels);

}  // namespace handcentric::props
