// The audit's cameras (props/observation): the eye-in-hand image of g * scene is the image of
// the scene for every g (Theorem 1's assumption, made visible), the third-person image is not; with
// the fixed cell (floor and lamp) the eye-in-hand image is invariant under se2 and c8 only. A
// random network on the eye-in-hand image inside a hand-centric policy audits as equivariant;
// the same network on the third-person image does not, with a witness.
#include <catch2/catch.hpp>
#include <memory>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/props/catch.hpp"
#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/observation/generators.hpp"
#include "handcentric/props/observation/camera_policy.hpp"
#include "handcentric/props/observation/camera_rig.hpp"
#include "handcentric/props/random_network.hpp"

using namespace handcentric;
using props::CameraRig;
using props::Group;
using props::View;

namespace {

constexpr int kImageChunk = 2;

CameraRig small_rig(View view, bool floor = false) {
  CameraRig rig;
  rig.views = {view};
  rig.camera = PinholeCamera{16, 12, 90.0, 20.0};
  rig.point_radius = 0.05;
  rig.floor = floor;
  return rig;
}

// Scenes the cameras see something of: two to three points of each kind.
props::SceneShape seen_shape() {
  props::SceneShape shape;
  shape.max_history = 1;
  shape.max_chunk = 2;
  shape.min_hand_points = 2;
  shape.min_world_points = 2;
  shape.extra_pose_names = {"start"};
  return shape;
}

double largest_pixel_change(const CameraRig& rig, const RigidTransform& g, const Scene& scene) {
  return largest_image_difference(props::render_views(g * scene, rig).front(),
                                  props::render_views(scene, rig).front());
}

/// image(g * scene) = image(scene) within 1e-9 m of depth and 1e-9 of colour, g in `group`.
auto image_is_invariant(CameraRig rig, Group group) {
  return [rig, group] {
    const Scene scene = *props::scene(seen_shape());
    const RigidTransform g = *props::group_element(group);
    RC_ASSERT(largest_pixel_change(rig, g, scene) <= 1e-9);
  };
}

// A random network on the image of the rig's one view and the hand-centric proprioception, its
// output decoded in the hand frame (eq. 1): equivariant exactly when the image is invariant.
class RandomImagePolicy final : public props::ImagePolicy {
 public:
  explicit RandomImagePolicy(const CameraRig& rig)
      : channels_(rig.channels),
        inputs_(props::channel_count(rig.channels) * rig.camera.width * rig.camera.height),
        network_(inputs_ + 6 + 6 * kImageChunk, {16}, 6 * kImageChunk, 7) {}
  std::string name() const override { return "random_image_policy"; }
  Eigen::Index noise_dimension() const override { return 6 * kImageChunk; }
  std::vector<RigidTransform> act(const Scene& o, const std::vector<CameraImage>& images,
                                  const Eigen::VectorXd& noise) const override {
    Eigen::VectorXd input(network_.inputs());
    const std::vector<float> pixels = props::network_image(images.front(), channels_);
    for (int i = 0; i < inputs_; ++i) input(i) = pixels[static_cast<std::size_t>(i)];
    Scene now = o;
    now.world_T_hand_history.resize(1);
    input.segment(inputs_, 6) = hand_centric_.encode_observation(now).head(6);
    input.tail(6 * kImageChunk) = noise;
    return hand_centric_.decode_actions(0.1 * network_(input), o.world_T_hand0());
  }

 private:
  props::ImageChannels channels_;
  int inputs_;
  props::RandomMlp network_;
  HandCentricRepresentation hand_centric_;
};

props::Verdict audit_image_policy(View view) {
  const CameraRig rig = small_rig(view);
  const props::CameraPolicy policy(std::make_shared<RandomImagePolicy>(rig), rig);
  props::CheckOptions options;
  options.cases = 60;
  options.shape = seen_shape();
  return props::check_policy_equivariance(policy, Group::se3, options);
}

}  // namespace

TEST_CASE("the_eye_in_hand_image_is_se3_invariant", "[property]") {
  props::require_property("eye-in-hand image under se3",
                          image_is_invariant(small_rig(View::eye_in_hand), Group::se3));
}

TEST_CASE("mutant_the_third_person_image_is_not_invariant", "[property]") {
  for (const Group group : {Group::translation, Group::rotation, Group::se2, Group::c8}) {
    INFO(props::to_string(group));
    props::require_falsified("third-person image",
                             image_is_invariant(small_rig(View::third_person), group));
  }
}

TEST_CASE("with_the_floor_the_eye_in_hand_image_is_invariant_under_se2_and_c8_only", "[property]") {
  const CameraRig rig = small_rig(View::eye_in_hand, true);
  for (const Group group : {Group::se2, Group::c8}) {
    INFO(props::to_string(group));
    props::require_property("eye-in-hand image with floor and lamp",
                            image_is_invariant(rig, group));
  }
  for (const Group group : {Group::translation, Group::rotation, Group::se3}) {
    INFO(props::to_string(group));
    props::require_falsified("eye-in-hand image with floor and lamp",
                             image_is_invariant(rig, group));
  }
}

TEST_CASE("the_eye_in_hand_image_shows_the_points_where_the_hand_sees_them", "[unit]") {
  // One eye-in-hand point 1 m straight ahead of the camera (the hand's +z), drawn with radius
  // 0.2: the centre pixels read its near surface, just beyond 1 - r, the corners see nothing.
  CameraRig rig = small_rig(View::eye_in_hand);
  rig.point_radius = 0.2;
  Scene scene;
  scene.world_T_hand_history = {RigidTransform::planar(0.7, 3.0, -2.0)};
  scene.hand_points = {Eigen::Vector3d(0.0, 0.0, 1.0)};
  const CameraImage image = props::render_views(scene, rig).front();
  CHECK(image.depth_at(6, 8) > 0.8);
  CHECK(image.depth_at(6, 8) < 0.82);  // 0.8134, the analytic hit of the off-axis ray
  CHECK(image.depth_at(0, 0) == rig.camera.max_range);
  const std::vector<float> pixels = props::network_image(image, props::ImageChannels::rgbd);
  REQUIRE(pixels.size() == 4u * 16u * 12u);
  const std::size_t centre = 6 * 16 + 8;
  CHECK(pixels[centre] > 0.9f);            // red: orange, lit head-on
  CHECK(pixels[2 * 192 + centre] < 0.2f);  // blue
  CHECK(pixels[3 * 192 + centre] == static_cast<float>(image.depth_at(6, 8)));  // depth last
  CHECK(props::network_image(image, props::ImageChannels::depth).size() == 192u);
  CHECK(props::network_image(image, props::ImageChannels::rgb).size() == 576u);
}

TEST_CASE("a_network_on_the_eye_in_hand_image_is_equivariant_on_the_third_person_image_not",
          "[property]") {
  const props::Verdict eye = audit_image_policy(View::eye_in_hand);
  INFO((eye.witness ? props::format_witness(*eye.witness) : std::string("no witness")));
  CHECK(eye.invariant);
  CHECK(eye.cases > 30);  // a verdict with cases behind it
  const props::Verdict fixed = audit_image_policy(View::third_person);
  CHECK_FALSE(fixed.invariant);
  REQUIRE(fixed.witness);
}

TEST_CASE("bad_camera_rigs_are_refused_with_the_value_and_the_fix", "[unit]") {
  CameraRig rig;
  rig.views = {};
  CHECK_THROWS_WITH(rig.validate(), Catch::Matchers::Contains("at least one camera"));
  rig.views = {View::eye_in_hand, View::eye_in_hand};
  CHECK_THROWS_WITH(rig.validate(), Catch::Matchers::Contains("named twice"));
  rig = CameraRig();
  rig.point_radius = 0.0;
  CHECK_THROWS_WITH(rig.validate(), Catch::Matchers::Contains("point radius"));
  rig = CameraRig();
  rig.camera.width = 5000;
  CHECK_THROWS_WITH(rig.validate(), Catch::Matchers::Contains("5000 x 48"));
  CHECK_THROWS_WITH(props::parse_camera_view("wrist"), Catch::Matchers::Contains("eye_in_hand"));
  CHECK_THROWS_WITH(props::parse_image_channels("bgr"), Catch::Matchers::Contains("rgbd"));
  CHECK_THROWS_WITH(CameraRig::look_at(Eigen::Vector3d::Zero(), -Eigen::Vector3d::UnitZ()),
                    Catch::Matchers::Contains("straight up or down"));
  CHECK_THROWS_AS(props::CameraPolicy(nullptr, CameraRig()), InvalidArgument);
  Scene empty;
  CHECK_THROWS_AS(props::render_views(empty, CameraRig()), InvalidScene);
}
