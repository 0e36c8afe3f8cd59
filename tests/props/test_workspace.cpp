// Audits inside a workspace (props/workspace.hpp): every case drawn inside the box stays inside
// under its g; a policy that clips world positions to its +-1 m box is equivariant within the
// box and not beyond, and a box larger than the policy's (the planted fault) is caught.
#include <catch2/catch.hpp>

#include "handcentric/core/errors.hpp"
#include "handcentric/props/catch.hpp"
#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/observation/generators.hpp"
#include "handcentric/props/checks/policy_audit.hpp"
#include "handcentric/props/observation/workspace.hpp"

using namespace handcentric;
using props::Group;
using props::Workspace;

namespace {

const Workspace kCell{Eigen::Vector3d(-1.0, -1.0, 0.0), Eigen::Vector3d(1.0, 1.0, 1.0)};

props::SceneShape shape_in(const Workspace& box) {
  props::SceneShape shape;
  shape.max_world_points = 3;
  shape.extra_pose_names = {"start"};
  shape.workspace = box;
  return shape;
}

// The box grown by a margin: a translation at the edge of the feasible ones may land a position
// an ulp outside, and a witness is the case moved off by up to ~1e-4 (1 + L) (check.hpp, step 3).
Workspace with_margin(const Workspace& box, double margin = 1e-12) {
  return Workspace{box.min.array() - margin, box.max.array() + margin};
}

// A hand-centric straight-line policy that first clips its hand's position to +-1 m (a
// normalizer fit on its cell): T_k = clip(T_0) exp(k step). Equivariant while T_0 is inside.
class ClippingPolicy final : public props::NoisyPolicy {
 public:
  std::string name() const override { return "clips_to_1m"; }
  Eigen::Index noise_dimension() const override { return 1; }
  std::vector<RigidTransform> act(const Scene& o, const Eigen::VectorXd& noise) const override {
    const RigidTransform& T0 = o.world_T_hand0();
    RigidTransform T(T0.rotation(), T0.translation().cwiseMax(-1.0).cwiseMin(1.0));
    Twist step;
    step << 0.02, 0.0, 0.01 * noise(0), 0.0, 0.1, 0.0;
    std::vector<RigidTransform> chunk;
    for (int k = 0; k < 3; ++k) chunk.push_back(T = T * RigidTransform::exp(step));
    return chunk;
  }
};

props::Verdict audit_clipping(Group group, std::optional<Workspace> box) {
  props::CheckOptions options;
  options.cases = 200;
  options.shape.max_world_points = 0;
  options.shape.workspace = box;
  return props::check_policy_equivariance(ClippingPolicy(), group, options);
}

}  // namespace

TEST_CASE("every_case_drawn_in_a_workspace_stays_in_it_under_its_g", "[property]") {
  const Workspace around_origin{Eigen::Vector3d(-0.5, -2.0, -1.0), Eigen::Vector3d(3.0, 1.0, 0.2)};
  for (const bool cell : {true, false}) {
    const Workspace box = cell ? kCell : around_origin;
    for (const Group group : props::all_groups()) {
      if (group == Group::rotation && cell) continue;  // the origin is on the cell's floor
      INFO(props::to_string(group) << " in " << box.describe());
      props::require_property("inside", [box, group] {
        const auto [scene, g] = *props::case_in_workspace(shape_in(box), group, box);
        RC_ASSERT(with_margin(box).contains(scene));
        RC_ASSERT(with_margin(box).contains(g * scene));
      });
    }
  }
}

TEST_CASE("the_2d_tasks_planar_scenes_stay_in_their_plane_inside_a_workspace", "[property]") {
  props::SceneShape planar = shape_in(kCell);
  planar.planar = true;
  for (const Group group : {Group::translation, Group::se2, Group::c8}) {
    INFO(props::to_string(group));
    props::require_property("planar and inside", [planar, group] {
      const auto [scene, g] = *props::case_in_workspace(planar, group, kCell);
      const Scene moved = g * scene;
      RC_ASSERT(with_margin(kCell).contains(scene));
      RC_ASSERT(with_margin(kCell).contains(moved));
      for (const Scene* s : {&scene, &moved}) {
        for (const RigidTransform& T : s->world_T_hand_history)
          RC_ASSERT(T.translation().z() == 0.0);
        for (const Eigen::Vector3d& p : s->world_points) RC_ASSERT(p.z() == 0.0);
      }
    });
  }
  const Workspace above{Eigen::Vector3d(-1.0, -1.0, 0.5), Eigen::Vector3d(1.0, 1.0, 1.0)};
  CHECK_THROWS_WITH(props::case_in_workspace(planar, Group::se2, above),
                    Catch::Matchers::Contains("plane z = 0"));
}

TEST_CASE("a_policy_clipping_to_its_box_is_equivariant_within_it_and_not_beyond", "[property]") {
  for (const Group group : {Group::translation, Group::se2, Group::se3}) {
    INFO(props::to_string(group));
    const props::Verdict within = audit_clipping(group, Workspace{});  // [-1, 1]^3
    CHECK(within.invariant);
    CHECK(within.cases > 100);
    CHECK_THAT(within.note, Catch::Matchers::Contains("inside the workspace [-1, 1] x [-1, 1] x "
                                                      "[-1, 1] m"));
    const props::Verdict anywhere = audit_clipping(group, std::nullopt);
    CHECK_FALSE(anywhere.invariant);
  }
}

TEST_CASE("mutant_a_workspace_larger_than_the_policys_box_is_caught", "[property]") {
  const props::Verdict wider = audit_clipping(
      Group::se3, Workspace{Eigen::Vector3d::Constant(-3.0), Eigen::Vector3d::Constant(3.0)});
  CHECK_FALSE(wider.invariant);
  REQUIRE(wider.witness);
  INFO(props::format_witness(*wider.witness));
  const Workspace wide{Eigen::Vector3d::Constant(-3.0), Eigen::Vector3d::Constant(3.0)};
  CHECK(with_margin(wide, 1e-3).contains(wider.witness->scene));
  CHECK(with_margin(wide, 1e-3).contains(wider.witness->g * wider.witness->scene));
}

TEST_CASE("bad_workspaces_are_refused_with_the_value_and_the_fix", "[unit]") {
  CHECK(Workspace::parse("-1,-1,0,1,1,1").min == Eigen::Vector3d(-1.0, -1.0, 0.0));
  CHECK_THROWS_WITH(Workspace::parse("-1,-1,0,1,1"), Catch::Matchers::Contains("has 5 numbers"));
  CHECK_THROWS_WITH(Workspace::parse("-1,-1,0,1,one,1"), Catch::Matchers::Contains("'one'"));
  CHECK_THROWS_WITH(Workspace::parse("1,-1,0,-1,1,1"), Catch::Matchers::Contains("along x") &&
                                                           Catch::Matchers::Contains("min before"));
  CHECK_THROWS_WITH(Workspace::parse("-1,-1,nan,1,1,1"), Catch::Matchers::Contains("finite"));
  CHECK_THROWS_WITH(props::case_in_workspace(shape_in(kCell), Group::rotation, kCell),
                    Catch::Matchers::Contains("does not contain the origin"));
  const Workspace off_axis{Eigen::Vector3d(2.0, 2.0, 0.0), Eigen::Vector3d(3.0, 3.0, 1.0)};
  CHECK_THROWS_WITH(props::case_in_workspace(shape_in(off_axis), Group::c8, off_axis),
                    Catch::Matchers::Contains("z axis"));
}
