// Demo files of the 2D task (the shared format: demo_file.hpp, docs/SIM.md) and training scenes.
#include "handcentric/sim/demos.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "demo_file.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::sim {
namespace {

const detail::DemoFileTask kPeg2d{"peg2d", "world_T_hole", true, "clearance"};

}  // namespace

void save_demos(const std::string& path, const std::vector<Demo>& demos,
                const PegHoleGeometry& geometry) {
  geometry.validate();
  std::vector<detail::DemoRecord> records;
  records.reserve(demos.size());
  for (const Demo& demo : demos) records.push_back({demo.world_T_hole, demo.world_T_hand});
  detail::save_demo_records(path, kPeg2d, geometry.clearance, records);
}

namespace {

std::vector<Demo> to_demos(std::vector<detail::DemoRecord> records) {
  std::vector<Demo> demos;
  demos.reserve(records.size());
  for (detail::DemoRecord& record : records)
    demos.push_back({record.world_T_object, std::move(record.world_T_hand)});
  return demos;
}

}  // namespace

std::vector<Demo> load_demos(const std::string& path, const DemoFileLimits& limits) {
  return to_demos(detail::load_demo_records(path, kPeg2d, limits));
}

std::vector<Demo> parse_demos(const std::string& bytes, const std::string& source,
                              const DemoFileLimits& limits) {
  return to_demos(detail::parse_demo_records(bytes, source, kPeg2d, limits));
}

std::vector<Eigen::Vector3d> eye_in_hand_points(const RigidTransform& world_T_hole,
                                                const RigidTransform& world_T_hand,
                                                const PegHoleGeometry& geometry) {
  const RigidTransform hand_T_hole = world_T_hand.inverse_compose(world_T_hole);
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector3d& hole_p_corner : geometry.opening_corners())
    points.push_back(hand_T_hole * hole_p_corner);
  return points;
}

std::vector<Scene> training_scenes(const Demo& demo, int H, int K,
                                   const PegHoleGeometry& geometry) {
  return detail::demo_training_scenes(
      demo.world_T_hand, H, K, [&](const RigidTransform& world_T_hand) {
        return eye_in_hand_points(demo.world_T_hole, world_T_hand, geometry);
      });
}

std::vector<Scene> training_scenes(const std::vector<Demo>& demos, int H, int K, int max_demos,
                                   const PegHoleGeometry& geometry) {
  return detail::demos_training_scenes(
      demos, max_demos, [&](const Demo& demo) { return training_scenes(demo, H, K, geometry); });
}

Demo mirrored_about_hole_axis(const Demo& demo) {
  if (demo.world_T_hand.empty())
    throw InvalidArgument("mirrored_about_hole_axis: the demo has no hand pose");
  Demo mirrored;
  mirrored.world_T_hole = demo.world_T_hole;
  mirrored.world_T_hand.reserve(demo.world_T_hand.size());
  for (const RigidTransform& world_T_hand : demo.world_T_hand) {
    const RigidTransform hole_T_hand = demo.world_T_hole.inverse_compose(world_T_hand);
    const Eigen::Matrix3d& R = hole_T_hand.rotation().matrix();
    const Eigen::Vector3d& p = hole_T_hand.translation();
    if (std::abs(p.z()) > 1e-9 || std::abs(R(2, 2) - 1.0) > 1e-9) {
      throw InvalidArgument(
          "mirrored_about_hole_axis: a hand pose is not planar in its hole's frame (z = " +
          std::to_string(p.z()) + "): only planar demos can be mirrored");
    }
    const double theta = std::atan2(R(1, 0), R(0, 0));
    mirrored.world_T_hand.push_back(demo.world_T_hole *
                                    RigidTransform::planar(-theta, -p.x(), p.y()));
  }
  return mirrored;
}

std::vector<Demo> with_mirrored_demos(const std::vector<Demo>& demos) {
  std::vector<Demo> all = demos;
  all.reserve(2 * demos.size());
  for (const Demo& demo : demos) all.push_back(mirrored_about_hole_axis(demo));
  return all;
}

void TrainingData::validate() const {
  const auto refuse = [](const std::string& what) {
    throw InvalidArgument("training data: " + what);
  };
  if (perturbed_copies < 0 || perturbed_copies > 64) {
    refuse("perturbed_copies must be in [0, 64], got " + std::to_string(perturbed_copies));
  }
  if (!(offset_cm >= 0.0 && offset_cm <= 10.0))
    refuse("offset_cm must be in [0, 10], got " + std::to_string(offset_cm));
  if (!(offset_deg >= 0.0 && offset_deg <= 90.0)) {
    refuse("offset_deg must be in [0, 90], got " + std::to_string(offset_deg));
  }
  if (recovery_steps < 1)
    refuse("recovery_steps must be >= 1, got " + std::to_string(recovery_steps));
}

std::string TrainingData::to_text() const {
  return "mirror=" + std::to_string(mirror ? 1 : 0) +
         "\nperturbed_copies=" + std::to_string(perturbed_copies) +
         "\noffset_cm=" + format_number(offset_cm) + "\noffset_deg=" + format_number(offset_deg) +
         "\nrecovery_steps=" + std::to_string(recovery_steps) +
         "\nperturbation_seed=" + std::to_string(perturbation_seed) + "\n";
}

namespace {

struct PlanarPose {
  double theta, x, y;
};

PlanarPose planar_parameters(const RigidTransform& hole_T_hand) {
  const Eigen::Matrix3d& R = hole_T_hand.rotation().matrix();
  return {std::atan2(R(1, 0), R(0, 0)), hole_T_hand.translation().x(),
          hole_T_hand.translation().y()};
}

// The perturbed copies of demo's samples (TrainingData::perturbed_copies): sample t of copy c
// draws its offset from stream (seed, (demo_index, t, c)), so the copies do not depend on how
// many others were dropped.
void append_perturbed_scenes(const Demo& demo, std::uint64_t demo_index, int H, int K,
                             const TrainingData& data, const CollisionChecker& checker,
                             const PegHoleGeometry& geometry, std::vector<Scene>& scenes) {
  const int T = static_cast<int>(demo.world_T_hand.size());
  std::vector<RigidTransform> hole_T_hand;
  hole_T_hand.reserve(demo.world_T_hand.size());
  for (const RigidTransform& world_T_hand : demo.world_T_hand) {
    hole_T_hand.push_back(demo.world_T_hole.inverse_compose(world_T_hand));
  }
  const auto pose = [&](int t) {
    return hole_T_hand[static_cast<std::size_t>(std::clamp(t, 0, T - 1))];
  };
  const double offset_rad = data.offset_deg * std::numbers::pi / 180.0;
  for (int t = 0; t < T; ++t) {
    for (int c = 0; c < data.perturbed_copies; ++c) {
      const std::uint64_t index =
          (demo_index * 1'000'003ull + static_cast<std::uint64_t>(t)) * 65ull +
          static_cast<std::uint64_t>(c);
      std::mt19937_64 rng(stream_seed(data.perturbation_seed, index));
      std::uniform_real_distribution<double> unit(-1.0, 1.0);
      const double d_theta = offset_rad * unit(rng);
      const double d_x = data.offset_cm * unit(rng);
      const double d_y = data.offset_cm * unit(rng);
      // Offset k steps after the perturbation: shrinks linearly to 0 at recovery_steps.
      const auto moved = [&](int k) {
        const double left = std::max(0.0, 1.0 - static_cast<double>(k) / data.recovery_steps);
        const PlanarPose p = planar_parameters(pose(t + k));
        return RigidTransform::planar(p.theta + left * d_theta, p.x + left * d_x, p.y + left * d_y);
      };
      bool valid = !checker.collides(moved(0));
      for (int k = 1; valid && k <= std::min(K, data.recovery_steps); ++k) {
        valid = !checker.motion_collides(moved(k - 1), moved(k));
      }
      if (!valid) continue;
      Scene scene;
      scene.world_T_hand_history.push_back(demo.world_T_hole * moved(0));
      // The past as the demo had it: the perturbation happened at t.
      for (int h = 1; h <= H; ++h)
        scene.world_T_hand_history.push_back(demo.world_T_hole * pose(t - h));
      for (int k = 1; k <= K; ++k) scene.world_T_hand_chunk.push_back(demo.world_T_hole * moved(k));
      scene.hand_points =
          eye_in_hand_points(demo.world_T_hole, scene.world_T_hand_history.front(), geometry);
      scenes.push_back(std::move(scene));
    }
  }
}

}  // namespace

std::vector<Scene> training_scenes(const std::vector<Demo>& demos, int H, int K, int max_demos,
                                   const TrainingData& data, const PegHoleGeometry& geometry) {
  data.validate();
  std::vector<Scene> scenes = training_scenes(demos, H, K, max_demos, geometry);
  const std::size_t used = max_demos == 0 ? demos.size() : static_cast<std::size_t>(max_demos);
  if (data.mirror) {
    for (std::size_t i = 0; i < used; ++i) {
      for (Scene& scene : training_scenes(mirrored_about_hole_axis(demos[i]), H, K, geometry)) {
        scenes.push_back(std::move(scene));
      }
    }
  }
  if (data.perturbed_copies > 0) {
    const CollisionChecker checker(geometry);
    for (std::size_t i = 0; i < used; ++i) {
      append_perturbed_scenes(demos[i], 2 * i, H, K, data, checker, geometry, scenes);
      if (data.mirror) {
        append_perturbed_scenes(mirrored_about_hole_axis(demos[i]), 2 * i + 1, H, K, data, checker,
                                geometry, scenes);
      }
    }
  }
  return scenes;
}

}  // namespace handcentric::sim
