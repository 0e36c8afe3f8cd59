// Exact collision at the clearance: the checker sees a 0.01 gap that Box2D's skin
// hides, the tilt that closes the gap, and motions that pass through a wall between free poses.
#include <box2d/b2_collision.h>
#include <box2d/b2_polygon_shape.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "handcentric/core/errors.hpp"
#include "handcentric/sim/collision.hpp"
#include "motion_check_faults.hpp"

using namespace handcentric;
using namespace handcentric::sim;

namespace {

using MotionCheck = bool (*)(const CollisionChecker&, const RigidTransform&, const RigidTransform&);

bool continuous(const CollisionChecker& checker, const RigidTransform& a, const RigidTransform& b) {
  return checker.motion_collides(a, b);
}

// Claim: motions that pass through a wall (or clip a wall's corner) between two collision-free
// poses are caught; the free insertion down the axis is not flagged.
bool catches_motions_through_walls(MotionCheck check) {
  const CollisionChecker checker;
  const RigidTransform inside = RigidTransform::planar(0.0, 0.0, 4.0);  // tip 4 deep, centred
  const RigidTransform far_right =
      RigidTransform::planar(0.0, 20.0, 4.0);  // well right of the right wall
  const RigidTransform above_left =
      RigidTransform::planar(0.0, -3.5, 8.3);  // tip 0.3 above the left wall
  if (checker.collides(inside) || checker.collides(far_right) || checker.collides(above_left))
    return false;
  // straight through the right wall (2 thick) in one 20 cm command
  if (!check(checker, inside, far_right)) return false;
  // diagonally into the hole from above the left wall: the peg's corner cuts the wall's top corner
  if (!check(checker, above_left, inside)) return false;
  // the free insertion is free
  return !check(checker, RigidTransform::planar(0.0, 0.0, 9.0),
                RigidTransform::planar(0.0, 0.0, 2.5));
}

}  // namespace

TEST_CASE("a_centred_peg_in_the_hole_does_not_collide", "[unit]") {
  const CollisionChecker checker;
  for (const double y :
       {9.0, 8.0, 5.0, 2.5, 2.01}) {  // tip 1 above, at the opening, 3 / 5.5 / 5.99 deep
    INFO("hand at y = " << y);
    CHECK_FALSE(checker.collides(RigidTransform::planar(0.0, 0.0, y)));
  }
  // the clearance is 0.05 per side, seen to float precision
  CHECK(checker.distance(RigidTransform::planar(0.0, 0.0, 4.0)) == Approx(0.05).margin(1e-5));
  CHECK(checker.collides(RigidTransform::planar(0.0, 0.0, 2.0 - 1e-3)));  // tip into the bottom
}

TEST_CASE("a_peg_shifted_sideways_by_0_06_collides_and_by_0_04_does_not", "[unit]") {
  const CollisionChecker checker;
  for (const double sign : {-1.0, 1.0}) {
    CHECK(checker.collides(RigidTransform::planar(0.0, sign * 0.06, 4.0)));
    CHECK_FALSE(checker.collides(RigidTransform::planar(0.0, sign * 0.04, 4.0)));
  }
}

TEST_CASE("a_peg_tilted_by_the_angle_that_closes_the_gap_collides", "[unit]") {
  // Hand at (0, 4): the bottom corner (1, -8) turned by phi sits at x = cos(phi) + 8 sin(phi),
  // which reaches the right wall (x = 1.05) at phi* = atan2(8, 1) - acos(1.05 / sqrt(65)).
  const CollisionChecker checker;
  const double phi_star = std::atan2(8.0, 1.0) - std::acos(1.05 / std::sqrt(65.0));
  REQUIRE(phi_star > 0.0);
  CHECK(checker.collides(RigidTransform::planar(1.05 * phi_star, 0.0, 4.0)));
  CHECK_FALSE(checker.collides(RigidTransform::planar(0.95 * phi_star, 0.0, 4.0)));
  CHECK(checker.collides(
      RigidTransform::planar(-1.05 * phi_star, 0.0, 4.0)));  // and to the left wall
  CHECK_FALSE(checker.collides(RigidTransform::planar(-0.95 * phi_star, 0.0, 4.0)));
}

TEST_CASE("box2d_skin_would_report_a_collision_that_the_exact_check_does_not", "[unit]") {
  // Shifted by 0.045, the gap is 0.005: less than the two 0.01 skins b2TestOverlap counts.
  const CollisionChecker checker;
  CHECK_FALSE(checker.collides(RigidTransform::planar(0.0, 0.045, 4.0)));
  b2PolygonShape peg, right_wall;
  peg.SetAsBox(1.0f, 4.0f, b2Vec2(0.0f, -4.0f), 0.0f);
  right_wall.SetAsBox(1.0f, 3.0f, b2Vec2(2.05f, -3.0f), 0.0f);
  b2Transform hole_T_hand(b2Vec2(0.045f, 4.0f), b2Rot(0.0f));
  b2Transform identity;
  identity.SetIdentity();
  CHECK(b2TestOverlap(&peg, 0, &right_wall, 0, hole_T_hand, identity));
}

TEST_CASE("motions_through_walls_between_free_poses_are_caught", "[unit]") {
  CHECK(catches_motions_through_walls(continuous));
}

TEST_CASE("mutant_endpoint_only_motion_check_is_caught", "[unit]") {
  CHECK_FALSE(catches_motions_through_walls(testing::endpoints_only<CollisionChecker>));
}

TEST_CASE("mutant_fixed_four_sample_motion_check_is_caught", "[unit]") {
  CHECK_FALSE(
      catches_motions_through_walls(testing::four_samples<CollisionChecker, interpolate_planar>));
}

TEST_CASE("continuous_check_steps_by_the_clearance_and_never_coarser_than_c_over_4_near_walls",
          "[unit]") {
  // A long free motion far above the hole: conservative advancement takes big steps there...
  const CollisionChecker checker;
  const std::uint64_t before = checker.queries();
  CHECK_FALSE(checker.motion_collides(RigidTransform::planar(0.0, -20.0, 30.0),
                                      RigidTransform::planar(0.0, 20.0, 30.0)));
  const std::uint64_t far_queries = checker.queries() - before;
  // ...and 0.01 from a wall (shifted by 0.04) it takes at least one query per c/4 = 0.025 of
  // travel.
  const std::uint64_t mid = checker.queries();
  CHECK_FALSE(checker.motion_collides(RigidTransform::planar(0.0, 0.04, 7.5),
                                      RigidTransform::planar(0.0, 0.04, 7.0)));
  const std::uint64_t near_queries = (checker.queries() - mid) / 3;  // 3 walls per query point
  CHECK(near_queries >= 0.5 / 0.025);
  CHECK(far_queries / 3 < 40);
}

TEST_CASE("interpolation_takes_the_short_way_round", "[unit]") {
  const RigidTransform a = RigidTransform::planar(3.0, 0.0, 0.0);
  const RigidTransform b = RigidTransform::planar(-3.0, 2.0, 0.0);
  const Eigen::Vector3d mid = planar_coordinates(interpolate_planar(a, b, 0.5));
  CHECK(std::abs(std::abs(mid(0)) - (3.0 + (2.0 * M_PI - 6.0) / 2.0)) < 1e-12);
  CHECK(mid(1) == Approx(1.0));
}

TEST_CASE("a_bad_clearance_is_rejected_with_the_value_and_the_fix", "[unit]") {
  PegHoleGeometry geometry;
  geometry.clearance = -0.1;
  CHECK_THROWS_WITH(CollisionChecker{geometry},
                    Catch::Matchers::Contains("-0.1") && Catch::Matchers::Contains("0.1"));
  geometry.clearance = std::nan("");
  CHECK_THROWS_AS(CollisionChecker{geometry}, InvalidArgument);
}

namespace {

// The success test as it was before it had a floor: deep enough and under the opening. A
// planted fault the test below must catch.
bool mutant_inserted_without_a_floor(const RigidTransform& hole_T_hand) {
  const Eigen::Vector3d tip = tip_in_hole(hole_T_hand);
  return tip.y() <= -kSuccessDepth && std::abs(tip.x()) < 0.5 * PegHoleGeometry().inner_width();
}

// The hand with the peg's tip at (x, tip_y) of the hole frame, the peg pointing into the hole
// (upright) or away from it (turned by pi, as a peg that went around the hole comes back).
RigidTransform hand_with_tip_at(double x, double tip_y, bool turned = false) {
  return turned ? RigidTransform::planar(std::numbers::pi, x, tip_y - kPegLength)
                : RigidTransform::planar(0.0, x, tip_y + kPegLength);
}

}  // namespace

TEST_CASE("only_a_tip_inside_the_hole_deep_enough_is_an_insertion", "[unit]") {
  const CollisionChecker checker;
  CHECK(is_inserted(hand_with_tip_at(0.0, -5.5)));
  CHECK(is_inserted(hand_with_tip_at(0.0, -kHoleDepth)));  // on the floor
  CHECK_FALSE(is_inserted(hand_with_tip_at(0.0, -4.9)));   // not deep enough
  CHECK_FALSE(is_inserted(hand_with_tip_at(1.06, -5.5)));  // beside the opening

  // Behind the bottom wall, the peg pointing away from the hole: collision-free, under the
  // opening and deeper than kSuccessDepth, which is how an absolute policy "succeeded" on
  // bottom-up holes by going around them.
  const RigidTransform behind = hand_with_tip_at(0.0, -kHoleDepth - kWallThickness - 1.0, true);
  REQUIRE(tip_in_hole(behind).y() == Approx(-9.0));
  CHECK_FALSE(checker.collides(behind));
  CHECK_FALSE(is_inserted(behind));
  CHECK(mutant_inserted_without_a_floor(behind));  // the planted fault calls it a success
}
