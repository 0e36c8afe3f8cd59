// The 3D task's hand camera as an image policy's ImageSource (experiments/insert3d_image.hpp):
// the image the policy reads is the sim's camera image (one camera model), it is the same for
// g * scene as for the scene whatever g is (what makes a hand-centric image policy equivariant,
// Theorem 1), and a table fixed in the world, in view, breaks that for every g that tilts it.
#include <catch2/catch.hpp>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/experiments/insert3d_drawing.hpp"
#include "handcentric/experiments/insert3d_image.hpp"
#include "handcentric/sim/insert3d/rollout.hpp"
#include "handcentric/sim/insert3d/scenes.hpp"

using namespace handcentric;
using namespace handcentric::experiments;
namespace insert3d = handcentric::sim::insert3d;

namespace {

Scene task_observation(std::uint64_t index) {
  const insert3d::TaskScene scene =
      insert3d::sample_scene(insert3d::SceneDistribution::train(), 11, index);
  return insert3d::observe(scene, {scene.world_T_hand_start}, 0);
}

Eigen::VectorXd image_of(const Insert3dHandCamera& camera, const Scene& observation) {
  Eigen::VectorXd image(camera.shape().size());
  camera.render(observation, image);
  return image;
}

// The largest pixel change of `camera`'s image under a random g, over a few scenes.
double largest_change_under_g(const Insert3dHandCamera& camera, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  double largest = 0.0;
  for (std::uint64_t i = 0; i < 8; ++i) {
    const Scene observation = task_observation(i);
    const RigidTransform g = random_transform(rng, 30.0);
    largest = std::max(
        largest,
        (image_of(camera, g * observation) - image_of(camera, observation)).cwiseAbs().maxCoeff());
  }
  return largest;
}

}  // namespace

TEST_CASE("the_image_policy_reads_the_sims_hand_camera", "[unit]") {
  const Insert3dHandCamera camera;
  CHECK(camera.shape() == policy::ImageShape{1, 24, 32});
  const insert3d::TaskScene scene =
      insert3d::sample_scene(insert3d::SceneDistribution::train(), 11, 3);
  const CameraImage sim_image =
      insert3d::render_depth(insert3d::BladeSlotGeometry(), insert3d::DepthCamera(),
                             scene.world_T_hand_start, scene.world_T_slot);
  const Eigen::VectorXd image =
      image_of(camera, insert3d::observe(scene, {scene.world_T_hand_start}, 0));
  for (std::size_t p = 0; p < sim_image.depth.size(); ++p)
    REQUIRE(image[static_cast<Eigen::Index>(p)] == Approx(sim_image.depth[p]).margin(1e-9));
  // The slot is in view: some pixels nearer than the camera's range.
  CHECK(image.minCoeff() < 0.5 * insert3d::DepthCamera().max_range);
  // rgbd: shaded colour in [0, 1], then the same depth.
  Insert3dHandCameraOptions rgbd;
  rgbd.channels = Insert3dImageChannels::rgbd;
  const Insert3dHandCamera colour(rgbd);
  const Eigen::VectorXd colour_image =
      image_of(colour, insert3d::observe(scene, {scene.world_T_hand_start}, 0));
  CHECK(colour_image.tail(image.size()) == image);
  CHECK(colour_image.head(3 * image.size()).maxCoeff() <= 1.0);
  CHECK(colour_image.head(3 * image.size()).maxCoeff() > 0.1);
}

TEST_CASE("the_hand_cameras_image_is_se3_invariant_and_the_table_breaks_it", "[unit]") {
  CHECK(largest_change_under_g(Insert3dHandCamera(), 5) == 0.0);
  // The planted fault a real cell brings: a table fixed in the world, in view of the camera.
  Insert3dHandCameraOptions with_table;
  with_table.floor = true;
  with_table.table_z = -10.0;  // below the train scenes' slots, in view of the hand camera
  CHECK(largest_change_under_g(Insert3dHandCamera(with_table), 5) > 1.0);
}

TEST_CASE("the_hand_camera_renders_any_four_points_and_refuses_other_counts", "[unit]") {
  const Insert3dHandCamera camera;
  Scene observation = task_observation(0);
  for (Eigen::Vector3d& p : observation.hand_points) p = Eigen::Vector3d::Zero();
  CHECK(image_of(camera, observation).allFinite());
  observation.hand_points.pop_back();
  Eigen::VectorXd image(camera.shape().size());
  CHECK_THROWS_AS(camera.render(observation, image), InvalidScene);
  CHECK_THROWS_AS(parse_insert3d_image_channels("rgb"), InvalidArgument);
}

TEST_CASE("the_camera_frames_show_every_fourth_pose_and_the_last", "[unit]") {
  const insert3d::TaskScene scene =
      insert3d::sample_scene(insert3d::SceneDistribution::train(), 11, 2);
  insert3d::Rollout rollout;
  for (int t = 0; t < 10; ++t) {
    rollout.world_T_hand.push_back(
        scene.world_T_hand_start *
        RigidTransform::from_translation(Eigen::Vector3d(0.0, 0.0, -0.5 * t)));
  }
  // Steps 0, 4, 8 and 9: four panels of 128 x 96 in one row, 6 pixels apart, 18 for the label.
  const sim::Image sheet = draw_insert3d_camera_frames(scene, rollout);
  CHECK(sheet.width == 4 * (128 + 6) + 6);
  CHECK(sheet.height == 96 + 18 + 2 * 6);
  const sim::Image two_rows = draw_insert3d_camera_frames(scene, rollout, 4, 2);
  CHECK(two_rows.width == 2 * (128 + 6) + 6);
  CHECK(two_rows.height == 2 * (96 + 18 + 6) + 6);
  CHECK_THROWS_AS(draw_insert3d_camera_frames(scene, rollout, 0), InvalidArgument);
  CHECK_THROWS_AS(draw_insert3d_camera_frames(scene, insert3d::Rollout{}), InvalidArgument);
}
