#include "handcentric/experiments/insert3d_image.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <charconv>
#include <cmath>

#include "handcentric/core/errors.hpp"
#include "handcentric/experiments/insert3d_key_points.hpp"
#include "handcentric/sim/insert3d/rollout.hpp"

namespace handcentric::experiments {

std::string to_string(Insert3dImageChannels channels) {
  switch (channels) {
    case Insert3dImageChannels::rgbd:
      return "rgbd";
    case Insert3dImageChannels::normals:
      return "normals";
    case Insert3dImageChannels::depth:
      break;
  }
  return "depth";
}

Insert3dImageChannels parse_insert3d_image_channels(const std::string& name) {
  if (name == "depth") return Insert3dImageChannels::depth;
  if (name == "rgbd") return Insert3dImageChannels::rgbd;
  if (name == "normals") return Insert3dImageChannels::normals;
  throw InvalidArgument("unknown image channels '" + name + "': use depth, rgbd or normals");
}

namespace {

// hand_T_slot from the four eye-in-hand points as the expert reads it
// (hand_T_slot_from_corners); points that span no plane get the axes they lack fixed, so that
// every finite observation renders (the audit's scenes are not all slot openings).
RigidTransform hand_T_slot_of(const std::vector<Eigen::Vector3d>& hand_points) {
  if (hand_points.size() != 4) {
    throw InvalidScene(
        "the 3D task's hand camera renders the slot from its 4 eye-in-hand points "
        "(the opening's corners), got " +
        std::to_string(hand_points.size()));
  }
  constexpr double kTiny = 1e-9;
  const Eigen::Vector3d along_x = hand_points[1] - hand_points[0];
  const Eigen::Vector3d along_y = hand_points[3] - hand_points[0];
  const Eigen::Vector3d x =
      along_x.norm() > kTiny ? along_x.normalized() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d off_x = along_y - along_y.dot(x) * x;
  if (along_x.norm() > kTiny && off_x.norm() > kTiny * (1.0 + along_y.norm()))
    return sim::insert3d::hand_T_slot_from_corners(hand_points);
  const Eigen::Vector3d other =
      std::abs(x.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d y = (other - other.dot(x) * x).normalized();
  Eigen::Matrix3d R;
  R << x, y, x.cross(y);
  return RigidTransform::unchecked(
      R, 0.25 * (hand_points[0] + hand_points[1] + hand_points[2] + hand_points[3]));
}

}  // namespace

// The points depth * pixel_ray of the pixel's neighbours, along each axis the neighbour whose
// depth is nearest the pixel's (the same surface, but at a one-pixel sliver), crossed and turned
// toward the camera.
std::vector<Eigen::Vector3d> normals_from_depth(const CameraImage& picture,
                                                const PinholeCamera& camera) {
  const int w = picture.width, h = picture.height;
  const auto point = [&](int row, int col) {
    return Eigen::Vector3d(picture.depth_at(row, col) * camera.pixel_ray(row, col));
  };
  const auto seen = [&](int row, int col) { return picture.depth_at(row, col) < camera.max_range; };
  // The step (+-1) toward the neighbour along one axis nearest in depth, or 0 for none seen.
  const auto step = [&](int row, int col, int d_row, int d_col) {
    int best = 0;
    double nearest = INFINITY;
    for (int s : {1, -1}) {
      const int r = row + s * d_row, c = col + s * d_col;
      if (r < 0 || r >= h || c < 0 || c >= w || !seen(r, c)) continue;
      const double gap = std::abs(picture.depth_at(r, c) - picture.depth_at(row, col));
      if (gap < nearest) {
        nearest = gap;
        best = s;
      }
    }
    return best;
  };
  std::vector<Eigen::Vector3d> normals(static_cast<std::size_t>(w) * h, Eigen::Vector3d::Zero());
  for (int row = 0; row < h; ++row) {
    for (int col = 0; col < w; ++col) {
      if (!seen(row, col)) continue;
      const int sx = step(row, col, 0, 1), sy = step(row, col, 1, 0);
      if (sx == 0 || sy == 0) continue;
      const Eigen::Vector3d p = point(row, col);
      const Eigen::Vector3d along_x = sx * (point(row, col + sx) - p);
      const Eigen::Vector3d along_y = sy * (point(row + sy, col) - p);
      Eigen::Vector3d n = along_x.cross(along_y);
      if (!(n.norm() > 1e-12)) continue;
      n.normalize();
      if (n.dot(p) > 0.0) n = -n;  // toward the camera
      normals[static_cast<std::size_t>(row) * w + col] = n;
    }
  }
  return normals;
}

Insert3dHandCamera::Insert3dHandCamera(Insert3dHandCameraOptions options)
    : options_(std::move(options)),
      rig_(sim::insert3d::hand_camera_rig(options_.camera, options_.cameras)) {
  if (!std::isfinite(options_.table_z)) throw InvalidArgument("the table's height must be finite");
  if (options_.second_camera_in_world && options_.cameras != 2) {
    throw InvalidArgument("a second camera fixed in the world needs cameras = 2, got " +
                          std::to_string(options_.cameras));
  }
}

std::string Insert3dHandCamera::name() const {
  return "insert3d hand camera (" + to_string(options_.channels) + ", " +
         std::to_string(options_.camera.width) + " x " + std::to_string(options_.camera.height) +
         (options_.cameras == 2 ? ", 2 cameras" : "") +
         (options_.second_camera_in_world ? ", the second fixed in the world" : "") +
         (options_.floor ? ", with the table" : "") + ")";
}

policy::ImageShape Insert3dHandCamera::shape() const {
  const int channels = options_.channels == Insert3dImageChannels::rgbd      ? 4
                       : options_.channels == Insert3dImageChannels::normals ? 3
                                                                             : 1;
  return policy::ImageShape{channels * options_.cameras, options_.camera.height,
                            options_.camera.width};
}

CameraImage Insert3dHandCamera::render_image(const Scene& observation) const {
  return render_images(observation).front();
}

std::vector<CameraImage> Insert3dHandCamera::render_images(const Scene& observation) const {
  observation.validate_observation();
  const RigidTransform hand_T_slot = hand_T_slot_of(observation.hand_points);
  const sim::insert3d::BladeSlotGeometry geometry;
  std::vector<Solid> solids = sim::insert3d::task_solids_in_hand(geometry, hand_T_slot);
  if (options_.floor) {
    // The table stays in the world: the hand sees it at T_0^-1 world_T_table.
    const RigidTransform world_T_table =
        RigidTransform::from_translation(Eigen::Vector3d(0.0, 0.0, options_.table_z));
    solids.push_back(Solid::plane(observation.world_T_hand0().inverse_compose(world_T_table),
                                  Eigen::Vector3d(0.5, 0.4, 0.3)));
  }
  std::vector<CameraImage> pictures;
  for (std::size_t k = 0; k < rig_.size(); ++k) {
    RigidTransform hand_T_camera = rig_[k].hand_T_camera;
    if (k == 1 && options_.second_camera_in_world) {
      // Where the camera would be with the hand at the identity, seen from the hand at T_0.
      hand_T_camera = observation.world_T_hand0().inverse_compose(hand_T_camera);
    }
    pictures.push_back(handcentric::render(solids, rig_[k], hand_T_camera));
  }
  return pictures;
}

void Insert3dHandCamera::render(const Scene& observation, Eigen::Ref<Eigen::VectorXd> image) const {
  const policy::ImageShape image_shape = shape();
  if (image.size() != image_shape.size()) {
    throw InvalidArgument(name() + ": an image of " + std::to_string(image_shape.size()) +
                          " values, got room for " + std::to_string(image.size()));
  }
  Eigen::Index channel = 0;
  for (const CameraImage& picture : render_images(observation)) {
    const Eigen::Index pixels = static_cast<Eigen::Index>(picture.width) * picture.height;
    if (options_.channels == Insert3dImageChannels::rgbd) {
      for (int c = 0; c < 3; ++c, ++channel) {
        for (Eigen::Index p = 0; p < pixels; ++p)
          image[channel * pixels + p] = picture.rgb[static_cast<std::size_t>(3 * p + c)];
      }
    }
    if (options_.channels == Insert3dImageChannels::normals) {
      const std::vector<Eigen::Vector3d> normals = normals_from_depth(picture, options_.camera);
      for (int c = 0; c < 2; ++c, ++channel) {
        for (Eigen::Index p = 0; p < pixels; ++p)
          image[channel * pixels + p] = normals[static_cast<std::size_t>(p)][c];
      }
    }
    for (Eigen::Index p = 0; p < pixels; ++p)
      image[channel * pixels + p] = picture.depth[static_cast<std::size_t>(p)];
    ++channel;
  }
}

std::shared_ptr<const Insert3dHandCamera> insert3d_camera_of(const policy::PolicyConfig& config,
                                                             bool floor) {
  if (config.task != policy::kTaskInsert3d ||
      config.observation != policy::ObservationKind::image) {
    throw InvalidArgument("insert3d_camera_of: a " + config.task + " model with observation " +
                          policy::to_string(config.observation) +
                          " has no hand camera: give an image model of the 3D task (insert3d)");
  }
  Insert3dHandCameraOptions options;
  options.cameras = config.image_cameras;
  const int per_camera = config.image_channels / std::max(1, config.image_cameras);
  options.channels = per_camera == 4   ? Insert3dImageChannels::rgbd
                     : per_camera == 3 ? Insert3dImageChannels::normals
                                       : Insert3dImageChannels::depth;
  options.camera.width = config.image_width;
  options.camera.height = config.image_height;
  options.camera.horizontal_fov_deg = config.image_fov_deg;
  options.floor = floor;
  return std::make_shared<const Insert3dHandCamera>(options);
}

std::shared_ptr<const Insert3dHandCamera> Insert3dImageSettings::apply(
    policy::PolicyConfig& config) const {
  if (steps < 0) {
    throw InvalidArgument("image policies' steps " + std::to_string(steps) +
                          " is negative: use 0 (the library's automatic budget) or more");
  }
  Insert3dHandCameraOptions options;
  options.channels = channels;
  options.camera.width = width;
  options.camera.height = height;
  options.camera.horizontal_fov_deg = fov_deg;
  options.cameras = cameras;
  auto camera = std::make_shared<const Insert3dHandCamera>(options);  // checks the camera
  config.observation = policy::ObservationKind::image;
  const policy::ImageShape shape = camera->shape();
  config.image_channels = shape.channels;
  config.image_height = shape.height;
  config.image_width = shape.width;
  config.image_fov_deg = fov_deg;
  config.image_cameras = cameras;
  config.encoder = encoder;
  config.image_features = features;
  if (config.steps == 0) config.steps = steps;
  return camera;
}

std::pair<int, int> parse_image_size(const std::string& text) {
  const std::size_t x = text.find('x');
  int width = 0, height = 0;
  bool ok = x != std::string::npos;
  if (ok) {
    const auto [w_end, w_ec] = std::from_chars(text.data(), text.data() + x, width);
    const auto [h_end, h_ec] =
        std::from_chars(text.data() + x + 1, text.data() + text.size(), height);
    ok = w_ec == std::errc() && h_ec == std::errc() && w_end == text.data() + x &&
         h_end == text.data() + text.size() && width >= 1 && height >= 1 && width <= 4096 &&
         height <= 4096;
  }
  if (!ok) {
    throw InvalidArgument("image size '" + text +
                          "' is not WIDTHxHEIGHT with each 1..4096: give e.g. 64x48");
  }
  return {width, height};
}

policy::LearnedPolicy with_task_camera(const policy::LearnedPolicy& model, bool floor) {
  const policy::PolicyConfig& config = model.config();
  if (config.task != policy::kTaskInsert3d || config.observation != policy::ObservationKind::image)
    return model;
  return model.with_camera(insert3d_camera_of(config, floor));
}

std::shared_ptr<const ChunkPolicy> insert3d_model_policy(
    std::shared_ptr<const policy::LearnedPolicy> model) {
  if (model->config().observation == policy::ObservationKind::image) {
    if (model->camera()) return model;
    return std::make_shared<const policy::LearnedPolicy>(with_task_camera(*model));
  }
  // Key-point models are trained on the corners and the slot points computed from them.
  return std::make_shared<const SlotKeyPointPolicy>(std::move(model));
}

}  // namespace handcentric::experiments
