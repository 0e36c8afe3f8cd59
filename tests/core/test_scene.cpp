// Scene: how a global transform acts on it (Sec. 2.2), and validation.
#include <catch2/catch.hpp>

#include "throws.hpp"  // tests/support

#include "handcentric/core/errors.hpp"
#include "handcentric/core/scene.hpp"
#include "handcentric/props/catch.hpp"
#include "handcentric/props/observation/generators.hpp"
#include "handcentric/props/show.hpp"

using namespace handcentric;

namespace {

using Action = Scene (*)(const RigidTransform&, const Scene&);

Scene real_action(const RigidTransform& g, const Scene& scene) {
  return g * scene;
}

// A fault: treats eye-in-hand points as world points and moves them too.
Scene moves_hand_points(const RigidTransform& g, const Scene& scene) {
  Scene moved = g * scene;
  for (auto& x : moved.hand_points) x = g * x;
  return moved;
}

auto acts_as_in_sec_2_2(Action act) {
  return [act] {
    const Scene scene = *props::scene();
    const RigidTransform g = *props::group_element(props::Group::se3);
    const Scene moved = act(g, scene);
    RC_ASSERT(moved.history_length() == scene.history_length());
    RC_ASSERT(moved.chunk_length() == scene.chunk_length());
    for (std::size_t h = 0; h < scene.world_T_hand_history.size(); ++h) {
      RC_ASSERT(distance(moved.world_T_hand_history[h], g * scene.world_T_hand_history[h]) == 0.0);
    }
    for (std::size_t k = 0; k < scene.world_T_hand_chunk.size(); ++k) {
      RC_ASSERT(distance(moved.world_T_hand_chunk[k], g * scene.world_T_hand_chunk[k]) == 0.0);
    }
    for (std::size_t i = 0; i < scene.world_points.size(); ++i) {
      RC_ASSERT(moved.world_points[i] == g * scene.world_points[i]);
    }
    RC_ASSERT(moved.hand_points == scene.hand_points);
  };
}

}  // namespace

TEST_CASE("global_transform_moves_poses_and_world_points_not_eye_in_hand_points", "[property]") {
  props::require_property("g * scene", acts_as_in_sec_2_2(real_action));
}

TEST_CASE("mutant_scene_transform_that_moves_eye_in_hand_points_is_caught", "[property]") {
  props::require_falsified("g * scene moving eye-in-hand points",
                           acts_as_in_sec_2_2(moves_hand_points));
}

TEST_CASE("scene_validation_names_the_problem", "[unit]") {
  Scene scene;
  HC_CHECK_THROWS(scene.validate(), InvalidScene, Catch::Matchers::Contains("no hand pose"));
  scene.world_T_hand_history.push_back(RigidTransform());
  HC_CHECK_THROWS(scene.validate(), InvalidScene, Catch::Matchers::Contains("empty action chunk"));
  scene.world_T_hand_chunk.push_back(RigidTransform());
  CHECK_NOTHROW(scene.validate());
  scene.world_points.push_back(Eigen::Vector3d(0, 0, std::nan("")));
  HC_CHECK_THROWS(scene.validate(), InvalidScene,
                  Catch::Matchers::Contains("world point 0") && Catch::Matchers::Contains("nan"));
}
