// The 3D task's eye-in-hand observation: the depth image rendered from the hand camera, and the
// opening's corners in the hand frame, are the same for g * scene as for the scene, for every g
// in SE(3) (a camera fixed in the world is the planted fault that must fail).
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/props/catch.hpp"
#include "handcentric/props/observation/generators.hpp"
#include "handcentric/sim/insert3d/camera.hpp"
#include "handcentric/sim/insert3d/scenes.hpp"
#include "worst_error.hpp"  // tests/support

using namespace handcentric;
using namespace handcentric::sim::insert3d;

namespace {

constexpr double kImageTolerance = 1e-9;

/// The hand 1 cm above the opening, upright and centred: where the insertion starts.
const RigidTransform kSlotTHandPreInsertion =
    RigidTransform::from_translation(Eigen::Vector3d(0.0, 0.0, kBladeLength + 1.0));

double largest_difference(const CameraImage& a, const CameraImage& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.depth.size(); ++i)
    worst = test::worst_of(worst, std::abs(a.depth[i] - b.depth[i]));
  return worst;
}

using Renderer = CameraImage (*)(const RigidTransform& world_T_hand,
                                 const RigidTransform& world_T_slot);

CameraImage hand_camera(const RigidTransform& world_T_hand, const RigidTransform& world_T_slot) {
  return render_depth(BladeSlotGeometry(), DepthCamera(), world_T_hand, world_T_slot);
}

// A planted fault: the camera fixed in the world, 80 cm above the origin looking down, instead
// of on the hand.
CameraImage world_camera(const RigidTransform&, const RigidTransform& world_T_slot) {
  return render_depth(BladeSlotGeometry(), DepthCamera(),
                      RigidTransform::from_translation(Eigen::Vector3d(0.0, 0.0, 80.0)),
                      world_T_slot);
}

/// Claim: image(g * scene) = image(scene) within 1e-9, for a train scene, the hand at its start
/// or on the way in (at pre-insertion or partly inserted), and g in SE(3) with the props edge
/// cases (translations up to 1e3 cm).
auto image_is_invariant(Renderer render) {
  return [render] {
    const auto index = *rc::gen::inRange<std::uint64_t>(0, 1000000);
    const TaskScene scene = sample_scene(SceneDistribution::train(), 1, index);
    const double depth = *rc::gen::inRange(0, 600) / 100.0;  // tip from 1 above to 5 deep
    const RigidTransform world_T_hand =
        *rc::gen::element(0, 1) == 0
            ? scene.world_T_hand_start
            : scene.world_T_slot * RigidTransform::from_translation(
                                       Eigen::Vector3d(0.0, 0.0, kBladeLength + 1.0 - depth));
    const RigidTransform g = *props::group_element(props::Group::se3);
    const CameraImage original = render(world_T_hand, scene.world_T_slot);
    const CameraImage moved = render(g * world_T_hand, g * scene.world_T_slot);
    RC_ASSERT(moved.depth.size() == original.depth.size());
    // not vacuous: the hand camera sees the block in every case generated (checked apart from
    // `render`, so the planted fault fails on the invariance alone)
    const CameraImage seen = hand_camera(world_T_hand, scene.world_T_slot);
    RC_ASSERT(*std::min_element(seen.depth.begin(), seen.depth.end()) < DepthCamera().max_range);
    RC_ASSERT(largest_difference(moved, original) <= kImageTolerance);
  };
}

}  // namespace

TEST_CASE("insert3d_hand_camera_depth_image_is_se3_invariant", "[property]") {
  props::require_property("depth(g * scene) = depth(scene) within 1e-9",
                          image_is_invariant(hand_camera));
}

TEST_CASE("mutant_insert3d_world_fixed_camera_is_not_se3_invariant", "[property]") {
  const props::PropertyOutcome outcome = props::require_falsified(
      "a world-fixed camera's depth image under se3", image_is_invariant(world_camera));
  CHECK_THAT(outcome.message,
             Catch::Matchers::Contains("largest_difference"));  // the invariance failed
}

TEST_CASE("insert3d_the_hand_camera_sees_the_slot_at_pre_insertion", "[unit]") {
  const BladeSlotGeometry geometry;
  const DepthCamera camera;
  const CameraImage image = render_depth(geometry, camera, kSlotTHandPreInsertion.inverse());
  REQUIRE(image.depth.size() == 32u * 24u);
  int hits = 0;
  for (const double depth : image.depth) hits += depth < camera.max_range;
  CHECK(hits > static_cast<int>(image.depth.size()) / 3);
  CHECK(hits < static_cast<int>(image.depth.size()));  // and some rays pass beside the block
  // Pixel (12, 16): its ray, in the slot frame, hits the block's top (z = 0) where the analytic
  // plane intersection says, on the +x plate (x in [0.3, 2.3]).
  const double f = camera.focal_length();
  const RigidTransform slot_T_camera = kSlotTHandPreInsertion * camera.hand_T_camera;
  const Eigen::Vector3d ray = slot_T_camera.rotation() * Eigen::Vector3d(0.5 / f, 0.5 / f, 1.0);
  const double t = -slot_T_camera.translation().z() / ray.z();
  const Eigen::Vector3d hit = slot_T_camera.translation() + t * ray;
  REQUIRE((hit.x() > geometry.inner_half_x() &&
           hit.x() < geometry.inner_half_x() + kSlotWallThickness));
  CHECK(std::abs(image.depth_at(12, 16) - t) < 1e-12);
  // The slot's gap: a pixel whose ray enters the opening reads deeper than the block's top.
  const double deepest =
      *std::max_element(image.depth.begin(), image.depth.end(), [&](double a, double b) {
        return (a < camera.max_range ? a : 0.0) < (b < camera.max_range ? b : 0.0);
      });
  CHECK(deepest > t + 1.0);
}

TEST_CASE("insert3d_opening_corners_in_the_hand_frame_are_se3_invariant", "[unit]") {
  const BladeSlotGeometry geometry;
  const TaskScene scene = sample_scene(SceneDistribution::train(), 1, 0);
  const RigidTransform world_T_hand = scene.world_T_slot * kSlotTHandPreInsertion;
  const auto corners = opening_corners_in_hand(geometry, world_T_hand, scene.world_T_slot);
  CHECK((corners[0] - Eigen::Vector3d(-0.3, -2.1, -9.0)).norm() < 1e-12);
  CHECK((corners[2] - Eigen::Vector3d(0.3, 2.1, -9.0)).norm() < 1e-12);
  std::mt19937_64 rng(5);
  for (int i = 0; i < 100; ++i) {
    const RigidTransform g = random_transform(rng, 1000.0);
    const auto moved = opening_corners_in_hand(geometry, g * world_T_hand, g * scene.world_T_slot);
    for (std::size_t k = 0; k < 4; ++k) CHECK((moved[k] - corners[k]).norm() < 1e-9);
  }
}

TEST_CASE("insert3d_a_bad_camera_is_rejected_with_the_value_and_the_fix", "[unit]") {
  const BladeSlotGeometry geometry;
  DepthCamera camera;
  camera.width = 0;
  CHECK_THROWS_WITH(
      render_depth(geometry, camera, RigidTransform()),
      Catch::Matchers::Contains("0 x 24") && Catch::Matchers::Contains("e.g. 32 x 24"));
  camera = DepthCamera();
  camera.horizontal_fov_deg = 180.0;
  CHECK_THROWS_WITH(render_depth(geometry, camera, RigidTransform()),
                    Catch::Matchers::Contains("180"));
  camera = DepthCamera();
  camera.max_range = std::nan("");
  CHECK_THROWS_AS(render_depth(geometry, camera, RigidTransform()), InvalidArgument);
}
