#include "handcentric/core/camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric {

void PinholeCamera::validate(const std::string& what) const {
  if (width < 1 || width > 4096 || height < 1 || height > 4096) {
    throw InvalidArgument(what + " size must be 1..4096 pixels each way, got " +
                          std::to_string(width) + " x " + std::to_string(height) +
                          "; e.g. 32 x 24");
  }
  if (!std::isfinite(horizontal_fov_deg) || horizontal_fov_deg <= 0.0 ||
      horizontal_fov_deg >= 170.0) {
    throw InvalidArgument(what + " horizontal field of view must be in (0, 170) deg, got " +
                          format_number(horizontal_fov_deg) + "; e.g. 70");
  }
  if (!std::isfinite(max_range) || max_range <= 0.0) {
    throw InvalidArgument(what + " max_range must be a positive number, got " +
                          format_number(max_range) + "; e.g. 60");
  }
}

double PinholeCamera::focal_length() const {
  return 0.5 * width / std::tan(0.5 * horizontal_fov_deg * std::numbers::pi / 180.0);
}

Eigen::Vector3d PinholeCamera::pixel_ray(int row, int col) const {
  const double f = focal_length();
  return Eigen::Vector3d((col + 0.5 - 0.5 * width) / f, (row + 0.5 - 0.5 * height) / f, 1.0);
}

Light Light::directional(const Eigen::Vector3d& frame_direction, double ambient) {
  const double length = frame_direction.norm();
  if (!std::isfinite(length) || length == 0.0) {
    throw InvalidArgument("a directional light needs a finite non-zero direction, got " +
                          format_matrix(frame_direction) + "; e.g. 0 0 -1 (straight down)");
  }
  if (!std::isfinite(ambient) || ambient < 0.0 || ambient > 1.0) {
    throw InvalidArgument("a light's ambient share must be in [0, 1], got " +
                          format_number(ambient) + "; e.g. 0.35");
  }
  return Light{false, frame_direction / length, ambient};
}

CameraImage render(const std::vector<Solid>& solids, const PinholeCamera& camera,
                   const RigidTransform& frame_T_camera, const Light& light) {
  camera.validate();
  if (!std::isfinite(light.ambient) || light.ambient < 0.0 || light.ambient > 1.0) {
    throw InvalidArgument("a light's ambient share must be in [0, 1], got " +
                          format_number(light.ambient) + "; e.g. 0.35");
  }
  // Per solid, the camera in the solid's frame: the only place the two poses meet, so a camera
  // and solids moved together by g give solid_T_camera equal up to rounding.
  std::vector<RigidTransform> solid_T_camera;
  solid_T_camera.reserve(solids.size());
  for (const Solid& solid : solids)
    solid_T_camera.push_back(solid.frame_T_solid.inverse_compose(frame_T_camera));
  const Eigen::Vector3d camera_light =
      light.head_light ? Eigen::Vector3d::UnitZ()
                       : Eigen::Vector3d(frame_T_camera.rotation().matrix().transpose() *
                                         light.frame_direction.normalized());

  CameraImage image{camera.width, camera.height, {}, {}};
  const std::size_t pixels =
      static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
  image.depth.assign(pixels, camera.max_range);
  image.rgb.assign(3 * pixels, 0.0);
  for (int row = 0; row < camera.height; ++row) {
    for (int col = 0; col < camera.width; ++col) {
      const Eigen::Vector3d camera_ray = camera.pixel_ray(row, col);
      double nearest = camera.max_range;
      const Solid* seen = nullptr;
      Eigen::Vector3d camera_normal = Eigen::Vector3d::Zero();
      for (std::size_t i = 0; i < solids.size(); ++i) {
        const Eigen::Matrix3d& solid_R_camera = solid_T_camera[i].rotation().matrix();
        const auto hit = hit_in_solid_frame(solids[i], solid_T_camera[i].translation(),
                                            solid_R_camera * camera_ray);
        if (hit && hit->t < nearest) {
          nearest = hit->t;
          seen = &solids[i];
          camera_normal = solid_R_camera.transpose() * hit->normal;
        }
      }
      const std::size_t pixel = static_cast<std::size_t>(row) * camera.width + col;
      image.depth[pixel] = nearest;
      if (seen == nullptr) continue;
      const double lit = std::max(0.0, -camera_normal.dot(camera_light));
      const double shade = light.ambient + (1.0 - light.ambient) * lit;
      for (int c = 0; c < 3; ++c) image.rgb[3 * pixel + c] = seen->albedo(c) * shade;
    }
  }
  return image;
}

double largest_image_difference(const CameraImage& a, const CameraImage& b) {
  if (a.width != b.width || a.height != b.height || a.depth.size() != b.depth.size() ||
      a.rgb.size() != b.rgb.size()) {
    return std::numeric_limits<double>::infinity();
  }
  double worst = 0.0;
  for (std::size_t i = 0; i < a.depth.size(); ++i)
    worst = std::max(worst, std::abs(a.depth[i] - b.depth[i]));
  for (std::size_t i = 0; i < a.rgb.size(); ++i)
    worst = std::max(worst, std::abs(a.rgb[i] - b.rgb[i]));
  return worst;
}

}  // namespace handcentric
