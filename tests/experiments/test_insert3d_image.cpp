// The 3D task's hand camera as an image policy's ImageSource (experiments/insert3d_image.hpp):
// the image the policy reads is the sim's camera image (one camera model), it is the same for
// g * scene as for the scene whatever g is (what makes a hand-centric image policy equivariant,
// Theorem 1), and a table fixed in the world, in view, breaks that for every g that tilts it.
#include <catch2/catch.hpp>

#include <Eigen/LU>
#include <cmath>
#include <numbers>
#include <utility>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/experiments/insert3d_drawing.hpp"
#include "handcentric/experiments/insert3d_image.hpp"
#include "handcentric/sim/insert3d/rollout.hpp"
#include "handcentric/sim/insert3d/scenes.hpp"
#include "worst_error.hpp"  // tests/support

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
    largest =
        test::worst_of(largest, (image_of(camera, g * observation) - image_of(camera, observation))
                                    .cwiseAbs()
                                    .maxCoeff<Eigen::PropagateNaN>());
  }
  return largest;
}

// `poses` poses of the hand going straight down from its start, 0.5 cm a step.
insert3d::Rollout straight_descent(const insert3d::TaskScene& scene, int poses) {
  insert3d::Rollout rollout;
  for (int t = 0; t < poses; ++t) {
    rollout.world_T_hand.push_back(
        scene.world_T_hand_start *
        RigidTransform::from_translation(Eigen::Vector3d(0.0, 0.0, -0.5 * t)));
  }
  return rollout;
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
  CHECK(colour_image.head(3 * image.size()).maxCoeff<Eigen::PropagateNaN>() <= 1.0);
  CHECK(colour_image.head(3 * image.size()).maxCoeff<Eigen::PropagateNaN>() > 0.1);
}

TEST_CASE("the_hand_cameras_image_is_se3_invariant_and_the_table_breaks_it", "[unit]") {
  CHECK(largest_change_under_g(Insert3dHandCamera(), 5) == 0.0);
  // The planted fault a real cell brings: a table fixed in the world, in view of the camera.
  Insert3dHandCameraOptions with_table;
  with_table.floor = true;
  with_table.table_z = -10.0;  // below the train scenes' slots, in view of the hand camera
  CHECK(largest_change_under_g(Insert3dHandCamera(with_table), 5) > 1.0);
}

TEST_CASE("the_two_camera_rigs_images_are_se3_invariant_and_a_world_fixed_second_breaks_it",
          "[unit]") {
  Insert3dHandCameraOptions two;
  two.channels = Insert3dImageChannels::normals;
  two.cameras = 2;
  const Insert3dHandCamera rig(two);
  CHECK(rig.shape() == policy::ImageShape{6, 24, 32});
  CHECK(largest_change_under_g(rig, 5) == 0.0);
  // The first camera's three channels are the one-camera image; the second's are another view
  // (the mirror's: the same blade, the block from the other side).
  Insert3dHandCameraOptions one = two;
  one.cameras = 1;
  const Scene observation = task_observation(2);
  const Eigen::VectorXd both = image_of(rig, observation);
  const Eigen::Index half = 3 * 24 * 32;
  CHECK(both.head(half) == image_of(Insert3dHandCamera(one), observation));
  CHECK((both.tail(half) - both.head(half)).cwiseAbs().maxCoeff<Eigen::PropagateNaN>() > 1.0);
  // The second camera is the first's mirror about the blade's plane (hand x -> -x), turned
  // half a turn about the hand's z to stay right-handed: it sits 3 cm off the blade's other face.
  const std::vector<insert3d::DepthCamera>& cameras = rig.rig();
  REQUIRE(cameras.size() == 2);
  const Eigen::Vector3d first = cameras[0].hand_T_camera.translation();
  const Eigen::Vector3d second = cameras[1].hand_T_camera.translation();
  CHECK((second - Eigen::Vector3d(-first.x(), -first.y(), first.z())).norm() < 1e-12);
  CHECK(cameras[1].hand_T_camera.rotation().matrix().determinant() == Approx(1.0));
  // The planted fault: the second camera fixed in the world sees g * scene elsewhere.
  Insert3dHandCameraOptions world = two;
  world.second_camera_in_world = true;
  CHECK(largest_change_under_g(Insert3dHandCamera(world), 5) > 1.0);
  // A rig of another size is refused with the value and the fix.
  two.cameras = 3;
  CHECK_THROWS_WITH(Insert3dHandCamera(two),
                    Catch::Contains("3 cameras") && Catch::Contains("use 1"));
  one.second_camera_in_world = true;
  CHECK_THROWS_WITH(Insert3dHandCamera(one), Catch::Contains("needs cameras = 2"));
}

TEST_CASE("a_two_camera_model_records_its_rig_and_gets_it_back", "[unit]") {
  Insert3dImageSettings settings;
  settings.width = 32;
  settings.height = 24;
  settings.cameras = 2;
  policy::PolicyConfig config;
  config.task = policy::kTaskInsert3d;
  const auto camera = settings.apply(config);
  CHECK(camera->shape() == policy::ImageShape{6, 24, 32});
  CHECK((config.image_cameras == 2 && config.image_channels == 6));
  config.validate();
  const auto rebuilt = insert3d_camera_of(config);
  CHECK(rebuilt->rig().size() == 2);
  CHECK(rebuilt->options().channels == Insert3dImageChannels::normals);
  const Scene observation = task_observation(4);
  CHECK(image_of(*rebuilt, observation) == image_of(*camera, observation));
  // Planted fault: the config without its cameras key reads as one camera, which no six-channel
  // image fits: refused, not rebuilt as another camera.
  policy::PolicyConfig forgotten = config;
  forgotten.image_cameras = 1;
  CHECK_THROWS_AS(forgotten.validate(), InvalidArgument);
  // A one-camera config (every model file before the key) rebuilds one camera.
  settings.cameras = 1;
  settings.apply(config);
  CHECK(insert3d_camera_of(config)->rig().size() == 1);
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
  const insert3d::Rollout rollout = straight_descent(scene, 10);
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

// The rollout picture's two camera panels fit beside the view for the image models' camera
// (64 x 48, the default) as for the task's 32 x 24: 8x the smaller, 4x the
// larger. At 8x, the 64 x 48 panels ran off the canvas (OpenCV's region check threw).
TEST_CASE("the_rollout_picture_fits_the_camera_panels_of_any_image_size", "[unit]") {
  const insert3d::TaskScene scene =
      insert3d::sample_scene(insert3d::SceneDistribution::train(), 11, 2);
  const insert3d::Rollout rollout = straight_descent(scene, 3);
  insert3d::DepthCamera small;
  const sim::Image with_small = draw_insert3d_rollout(scene, rollout, "32 x 24", {}, small);
  insert3d::DepthCamera large = small;
  large.width = 64;
  large.height = 48;
  const sim::Image with_large = draw_insert3d_rollout(scene, rollout, "64 x 48", {}, large);
  CHECK(with_large.width == with_small.width);  // 64 x 4 = 32 x 8 pixels of panel
  CHECK(with_large.height == with_small.height);
  insert3d::DepthCamera tall = small;
  tall.width = 320;
  tall.height = 240;
  const sim::Image with_tall = draw_insert3d_rollout(scene, rollout, "320 x 240", {}, tall);
  CHECK(with_tall.height == 180 + 2 * 240);  // 1x, on a taller canvas
}

// Each panel stacks the rig's cameras, the first on top: the second camera's depth is drawn
// below the first's (planted fault: drawing the first camera twice fails the pixel check).
TEST_CASE("the_camera_frames_draw_both_cameras_of_a_two_camera_rig", "[unit]") {
  const insert3d::TaskScene scene =
      insert3d::sample_scene(insert3d::SceneDistribution::train(), 11, 2);
  insert3d::Rollout rollout;
  rollout.world_T_hand = {scene.world_T_hand_start};
  const std::vector<insert3d::DepthCamera> rig = insert3d::hand_camera_rig({}, 2);
  const sim::Image one = draw_insert3d_camera_frames(scene, rollout, 4, 8, {}, {rig[0]});
  const sim::Image two = draw_insert3d_camera_frames(scene, rollout, 4, 8, {}, rig);
  CHECK(one.height == 96 + 18 + 2 * 6);
  REQUIRE(two.height == 2 * 96 + 6 + 18 + 2 * 6);
  REQUIRE(two.width == one.width);
  // The top image is the first camera's, bit for bit; the one below differs from it.
  const auto row_bytes = [](const sim::Image& image, int y) {
    const auto begin = image.rgb.begin() + 3 * y * image.width;
    return std::vector<std::uint8_t>(begin, begin + 3 * image.width);
  };
  int differing_rows = 0;
  for (int y = 6 + 18; y < 6 + 18 + 96; ++y) {
    REQUIRE(row_bytes(two, y) == row_bytes(one, y));
    if (row_bytes(two, y + 96 + 6) != row_bytes(two, y)) ++differing_rows;
  }
  CHECK(differing_rows > 10);
  CHECK_THROWS_AS(draw_insert3d_camera_frames(scene, rollout, 4, 8, {}, {}), InvalidArgument);
}

// A planted fault (the normals panel left black, or x and y swapped) fails the pixel checks.
TEST_CASE("the_camera_frames_show_the_normals_the_policy_sees_beside_the_depth", "[unit]") {
  const insert3d::TaskScene scene =
      insert3d::sample_scene(insert3d::SceneDistribution::train(), 11, 2);
  insert3d::Rollout rollout;
  rollout.world_T_hand = {scene.world_T_hand_start};
  const insert3d::DepthCamera camera;
  const sim::Image sheet = draw_insert3d_camera_frames(scene, rollout, 4, 8, {}, {camera}, true);
  // One panel: depth 128 x 96, 6 pixels, normals 128 x 96; 6 pixels around, 18 for the label.
  REQUIRE(sheet.width == 2 * 128 + 6 + 2 * 6);
  REQUIRE(sheet.height == 96 + 18 + 2 * 6);
  const CameraImage picture =
      insert3d::render_depth({}, camera, scene.world_T_hand_start, scene.world_T_slot);
  const std::vector<Eigen::Vector3d> normals = normals_from_depth(picture, camera);
  int tilted = 0;
  for (int row = 0; row < camera.height; ++row) {
    for (int col = 0; col < camera.width; ++col) {
      const Eigen::Vector3d& n = normals[static_cast<std::size_t>(row * camera.width + col)];
      const int x = 6 + 128 + 6 + 4 * col + 2, y = 6 + 18 + 4 * row + 2;
      const std::uint8_t* pixel = &sheet.rgb[static_cast<std::size_t>(3 * (y * sheet.width + x))];
      const int red = n.isZero() ? 0 : static_cast<int>(std::lround(127.5 * (1.0 + n.x())));
      const int green = n.isZero() ? 0 : static_cast<int>(std::lround(127.5 * (1.0 + n.y())));
      CHECK(pixel[0] == red);
      CHECK(pixel[1] == green);
      if (std::abs(n.x()) > 0.1 || std::abs(n.y()) > 0.1) ++tilted;
    }
  }
  CHECK(tilted > 0);  // the block's faces are seen at an angle, so the check sees colours
}

TEST_CASE("image_settings_make_the_camera_the_model_records_and_gets_back", "[unit]") {
  Insert3dImageSettings settings;
  settings.width = 48;
  settings.height = 36;
  settings.fov_deg = 50.0;
  settings.encoder = "8,16/1";
  settings.features = policy::ImageFeatures::spatial_softmax;
  policy::PolicyConfig config;
  config.task = policy::kTaskInsert3d;
  const auto camera = settings.apply(config);
  // The default channels (normals, 3) of each of the default two cameras.
  CHECK(camera->shape() == policy::ImageShape{6, 36, 48});
  CHECK(config.observation == policy::ObservationKind::image);
  CHECK((config.image_width == 48 && config.image_height == 36 && config.image_fov_deg == 50.0));
  CHECK((config.encoder == "8,16/1" &&
         config.image_features == policy::ImageFeatures::spatial_softmax));
  // The camera a loaded model gets back is the one it was trained with, field of view too: the
  // same pixels. Planted fault: the default 70 deg camera of that size sees another image.
  const auto rebuilt = insert3d_camera_of(config);
  CHECK(rebuilt->options().camera.horizontal_fov_deg == 50.0);
  const Scene observation = task_observation(1);
  CHECK(image_of(*rebuilt, observation) == image_of(*camera, observation));
  // The same rig (both cameras, the same channels and size), only the field of view changed, so
  // the two images have one shape and differ in their pixels.
  Insert3dHandCameraOptions seventy = camera->options();
  seventy.camera.horizontal_fov_deg = 70.0;
  const Eigen::VectorXd seventy_image = image_of(Insert3dHandCamera(seventy), observation);
  REQUIRE(seventy_image.size() == image_of(*camera, observation).size());
  CHECK(seventy_image != image_of(*camera, observation));
  // A narrower camera is still only a function of the hand-frame points.
  CHECK(largest_change_under_g(*camera, 7) == 0.0);
  // The image policies' own budget fills in steps the command left automatic (0), and only those.
  // Planted fault: apply() leaving config.steps alone keeps 0, the library's 30000-step budget.
  settings.steps = 1234;
  config.steps = 0;
  settings.apply(config);
  CHECK(config.steps == 1234);
  config.steps = 500;
  settings.apply(config);
  CHECK(config.steps == 500);
  CHECK(Insert3dImageSettings{}.steps > 0);
  settings.steps = -1;
  CHECK_THROWS_WITH(settings.apply(config), Catch::Contains("-1") && Catch::Contains("use 0"));
}

TEST_CASE("image_sizes_and_fields_of_view_are_checked_with_the_value_and_the_fix", "[unit]") {
  CHECK(parse_image_size("64x48") == std::pair<int, int>{64, 48});
  for (const char* bad : {"64", "64x", "x48", "64x48x2", "0x48", "64x-1", "64 x 48", "5000x48"}) {
    INFO(bad);
    CHECK_THROWS_WITH(parse_image_size(bad), Catch::Contains(std::string("'") + bad + "'") &&
                                                 Catch::Contains("e.g. 64x48"));
  }
  Insert3dImageSettings settings;
  settings.fov_deg = 175.0;
  policy::PolicyConfig config;
  CHECK_THROWS_AS(settings.apply(config), InvalidArgument);
}

TEST_CASE("normals_from_depth_are_exact_on_a_plane_and_invariant_under_g", "[unit]") {
  // A floor tilted 20 deg about the camera's x and 10 about its y, 30 cm in front of it: every
  // pixel that sees it gets its normal from the depths alone, to rounding.
  PinholeCamera camera{32, 24, 70.0, 200.0};
  const Rotation tilt = Rotation::exp(Eigen::Vector3d(20.0, 10.0, 0.0) * std::numbers::pi / 180.0);
  // The plane's +z faces the camera (which looks along +z): turned half a turn about x.
  const Rotation facing = tilt * Rotation::exp(Eigen::Vector3d(std::numbers::pi, 0.0, 0.0));
  const RigidTransform camera_T_plane(facing, Eigen::Vector3d(0.0, 0.0, 30.0));
  const CameraImage picture = render({Solid::plane(camera_T_plane, Eigen::Vector3d(0.5, 0.5, 0.5))},
                                     camera, RigidTransform::identity());
  const Eigen::Vector3d truth = facing.matrix().col(2);
  REQUIRE(truth.z() < 0.0);  // toward the camera
  const auto worst_error = [&](const PinholeCamera& assumed) {
    double worst = 0.0;
    int seen = 0;
    const std::vector<Eigen::Vector3d> normals = normals_from_depth(picture, assumed);
    for (std::size_t p = 0; p < normals.size(); ++p) {
      if (picture.depth[p] >= camera.max_range) continue;
      ++seen;
      worst = test::worst_of(worst, (normals[p] - truth).norm());
    }
    CHECK(seen > 300);
    return worst;
  };
  CHECK(worst_error(camera) < 1e-9);
  // Planted fault: the rays of another camera (60 deg) bend the plane's points.
  PinholeCamera other = camera;
  other.horizontal_fov_deg = 60.0;
  CHECK(worst_error(other) > 1e-2);
  // The task's normals image is a function of hand-frame points: the same under every g.
  Insert3dHandCameraOptions options;
  options.channels = Insert3dImageChannels::normals;
  const Insert3dHandCamera normals(options);
  CHECK(normals.shape() == policy::ImageShape{3, 24, 32});
  CHECK(largest_change_under_g(normals, 5) == 0.0);
  // Its last channel is the depth image; its first two the normals' x and y, unit or 0.
  const Scene observation = task_observation(3);
  const Eigen::VectorXd image = image_of(normals, observation);
  CHECK(image.tail(24 * 32) == image_of(Insert3dHandCamera(), observation));
  CHECK(image.head(2 * 24 * 32).cwiseAbs().maxCoeff<Eigen::PropagateNaN>() <= 1.0);
  CHECK(image.head(2 * 24 * 32).cwiseAbs().maxCoeff<Eigen::PropagateNaN>() > 0.05);
  CHECK(parse_insert3d_image_channels("normals") == Insert3dImageChannels::normals);
}
