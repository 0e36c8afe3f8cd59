#include "handcentric/props/observation/camera_rig.hpp"

#include <algorithm>
#include <Eigen/Geometry>
#include <cmath>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric::props {
namespace {

const Eigen::Vector3d kHandPointAlbedo(0.95, 0.55, 0.15);
const Eigen::Vector3d kWorldPointAlbedo(0.2, 0.75, 0.3);
const Eigen::Vector3d kExtraPoseAlbedo(0.3, 0.45, 0.9);
const Eigen::Vector3d kFloorAlbedo(0.5, 0.5, 0.5);

// The scene's solids in the frame F = frame_T_world's left frame; eye-in-hand points are given
// in the hand frame and placed by frame_T_hand.
std::vector<Solid> scene_solids(const Scene& observation, const CameraRig& rig,
                                const RigidTransform& frame_T_world,
                                const RigidTransform& frame_T_hand, bool hand_is_frame) {
  std::vector<Solid> solids;
  const double r = rig.point_radius;
  for (const Eigen::Vector3d& hand_point : observation.hand_points) {
    // In the hand frame the point is used as it is: no rounding for the eye-in-hand camera.
    solids.push_back(
        Solid::sphere(hand_is_frame ? hand_point : Eigen::Vector3d(frame_T_hand * hand_point), r,
                      kHandPointAlbedo));
  }
  for (const Eigen::Vector3d& world_point : observation.world_points)
    solids.push_back(Solid::sphere(frame_T_world * world_point, r, kWorldPointAlbedo));
  for (const auto& [name, world_T_pose] : observation.extra_poses) {
    solids.push_back(Solid::box(frame_T_world * world_T_pose, Eigen::Vector3d(2.0 * r, r, 0.5 * r),
                                kExtraPoseAlbedo));
  }
  if (rig.floor) solids.push_back(Solid::plane(frame_T_world, kFloorAlbedo));
  return solids;
}

Light rig_light(const CameraRig& rig, const RigidTransform& frame_T_world) {
  if (!rig.floor) return Light::head();
  return Light::directional(frame_T_world.rotation().matrix() * -Eigen::Vector3d::UnitZ());
}

}  // namespace

View parse_camera_view(const std::string& name) {
  if (name == "eye_in_hand") return View::eye_in_hand;
  if (name == "third_person") return View::third_person;
  throw InvalidArgument("unknown camera '" + name +
                        "': the cameras are eye_in_hand (on the hand) and third_person (fixed "
                        "in the world)");
}

std::string to_string(ImageChannels channels) {
  switch (channels) {
    case ImageChannels::depth:
      return "depth";
    case ImageChannels::rgb:
      return "rgb";
    case ImageChannels::rgbd:
      return "rgbd";
  }
  return "rgbd";
}

ImageChannels parse_image_channels(const std::string& name) {
  if (name == "depth") return ImageChannels::depth;
  if (name == "rgb") return ImageChannels::rgb;
  if (name == "rgbd") return ImageChannels::rgbd;
  throw InvalidArgument("unknown image channels '" + name +
                        "': use depth (1 channel), rgb (3) or rgbd (4: red, green, blue, depth)");
}

int channel_count(ImageChannels channels) {
  switch (channels) {
    case ImageChannels::depth:
      return 1;
    case ImageChannels::rgb:
      return 3;
    case ImageChannels::rgbd:
      return 4;
  }
  return 4;
}

RigidTransform CameraRig::look_at(const Eigen::Vector3d& world_eye,
                                  const Eigen::Vector3d& world_target) {
  const Eigen::Vector3d forward = world_target - world_eye;
  if (!forward.allFinite() || forward.norm() == 0.0) {
    throw InvalidArgument("look_at: the eye " + format_matrix(world_eye) + " and the target " +
                          format_matrix(world_target) + " must be distinct finite points");
  }
  const Eigen::Vector3d z = forward.normalized();
  const Eigen::Vector3d right = z.cross(Eigen::Vector3d::UnitZ());
  if (right.norm() < 1e-9) {
    throw InvalidArgument("look_at: the camera looks straight up or down from " +
                          format_matrix(world_eye) +
                          "; move the eye sideways so the image has an up direction");
  }
  Eigen::Matrix3d world_R_camera;
  world_R_camera.col(0) = right.normalized();
  world_R_camera.col(2) = z;
  world_R_camera.col(1) = z.cross(world_R_camera.col(0));  // image down
  return RigidTransform(Rotation::from_matrix(world_R_camera), world_eye);
}

void CameraRig::validate() const {
  if (views.empty()) {
    throw InvalidArgument("a camera rig needs at least one camera: eye_in_hand or third_person");
  }
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (std::count(views.begin(), views.end(), views[i]) > 1) {
      throw InvalidArgument("the camera " + to_string(views[i]) +
                            " is named twice; name each camera once");
    }
  }
  camera.validate("camera");
  if (!std::isfinite(point_radius) || point_radius <= 0.0) {
    throw InvalidArgument("the cameras' point radius must be positive and finite, got " +
                          format_number(point_radius) + "; e.g. 0.05 (m)");
  }
}

std::vector<CameraImage> render_views(const Scene& observation, const CameraRig& rig) {
  rig.validate();
  observation.validate_observation();
  const RigidTransform& world_T_hand = observation.world_T_hand0();
  std::vector<CameraImage> images;
  images.reserve(rig.views.size());
  for (const View view : rig.views) {
    if (view == View::eye_in_hand) {
      // Rendered in the hand frame: only world-frame things pass through T_0^-1.
      const RigidTransform hand_T_world = world_T_hand.inverse();
      images.push_back(
          render(scene_solids(observation, rig, hand_T_world, RigidTransform::identity(), true),
                 rig.camera, rig.hand_T_camera, rig_light(rig, hand_T_world)));
    } else {
      images.push_back(
          render(scene_solids(observation, rig, RigidTransform::identity(), world_T_hand, false),
                 rig.camera, rig.world_T_third_person, rig_light(rig, RigidTransform::identity())));
    }
  }
  return images;
}

std::vector<float> network_image(const CameraImage& image, ImageChannels channels) {
  const std::size_t pixels =
      static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  std::vector<float> out;
  out.reserve(static_cast<std::size_t>(channel_count(channels)) * pixels);
  if (channels != ImageChannels::depth) {
    for (int c = 0; c < 3; ++c)
      for (std::size_t p = 0; p < pixels; ++p)
        out.push_back(static_cast<float>(image.rgb[3 * p + c]));
  }
  if (channels != ImageChannels::rgb) {
    for (std::size_t p = 0; p < pixels; ++p) out.push_back(static_cast<float>(image.depth[p]));
  }
  return out;
}

}  // namespace handcentric::props
