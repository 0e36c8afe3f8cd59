// Exact 3D collision at the clearance: a centred blade is free, shifts and tilts past the
// clearance collide, and motions through a wall, or dipping into one by 0.001 cm, between free
// poses are caught. The same cases as the 2D task's test_collision.cpp.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "handcentric/core/errors.hpp"
#include "handcentric/sim/insert3d/collision.hpp"
#include "motion_check_faults.hpp"

using namespace handcentric;
using namespace handcentric::sim::insert3d;

namespace {

RigidTransform at(double x, double y, double z) {
  return RigidTransform::from_translation(Eigen::Vector3d(x, y, z));
}

/// The hand at (0, 0, z) turned by `angle` about its own axis `axis` (unit).
RigidTransform tilted(const Eigen::Vector3d& axis, double angle, double z) {
  return RigidTransform(Rotation::exp(angle * axis), Eigen::Vector3d(0.0, 0.0, z));
}

using MotionCheck = bool (*)(const CollisionChecker&, const RigidTransform&, const RigidTransform&);

bool continuous(const CollisionChecker& checker, const RigidTransform& a, const RigidTransform& b) {
  return checker.motion_collides(a, b);
}

// Claim: motions that pass through a wall, or sweep across the block's top 0.001 cm too low,
// between collision-free poses are caught; the free insertion and a sweep 0.001 cm above the
// block are not flagged.
bool catches_motions_through_walls(MotionCheck check) {
  const CollisionChecker checker;
  const RigidTransform inside = at(0.0, 0.0, 4.0);      // tip 4 deep, centred
  const RigidTransform far_right = at(20.0, 0.0, 4.0);  // well beyond the +x plate
  const RigidTransform far_back = at(0.0, 20.0, 4.0);   // well beyond the +y end wall
  if (checker.collides(inside) || checker.collides(far_right) || checker.collides(far_back))
    return false;
  if (!check(checker, inside, far_right))
    return false;                                       // through the +x plate in one 20 cm command
  if (!check(checker, inside, far_back)) return false;  // through the +y end wall
  // sweeping across the block's top with the tip 0.001 below it: free at x = -10, 0, +10
  const double low = kBladeLength - 0.001;
  if (checker.collides(at(-10.0, 0.0, low)) || checker.collides(at(0.0, 0.0, low))) return false;
  if (!check(checker, at(-10.0, 0.0, low), at(10.0, 0.0, low))) return false;
  // the same sweep 0.001 above the top, and the insertion down the axis, are free
  const double high = kBladeLength + 0.001;
  if (check(checker, at(-10.0, 0.0, high), at(10.0, 0.0, high))) return false;
  return !check(checker, at(0.0, 0.0, 9.0), at(0.0, 0.0, 2.5));
}

}  // namespace

TEST_CASE("insert3d_a_centred_blade_in_the_slot_does_not_collide", "[unit]") {
  const CollisionChecker checker;
  for (const double z :
       {9.0, 8.0, 5.0, 2.5, 2.01}) {  // tip 1 above, at the opening, 3 / 5.5 / 5.99 deep
    INFO("hand at z = " << z);
    CHECK_FALSE(checker.collides(at(0.0, 0.0, z)));
  }
  // the clearance, 0.1 per side, seen by FCL to 1e-9
  CHECK(std::abs(checker.distance(at(0.0, 0.0, 4.0)) - 0.1) < 1e-9);
  CHECK(std::abs(checker.distance(at(0.0, 0.0, 2.01)) - 0.01) < 1e-9);  // the bottom is nearer
  CHECK(checker.collides(at(0.0, 0.0, 2.0 - 1e-3)));                    // tip into the bottom
}

TEST_CASE("insert3d_a_blade_shifted_by_more_than_the_clearance_collides_and_by_less_does_not",
          "[unit]") {
  const CollisionChecker checker;
  for (const double sign : {-1.0, 1.0}) {
    CHECK(checker.collides(at(sign * 0.11, 0.0, 4.0)));  // into a plate
    CHECK_FALSE(checker.collides(at(sign * 0.09, 0.0, 4.0)));
    CHECK(std::abs(checker.distance(at(sign * 0.09, 0.0, 4.0)) - 0.01) < 1e-9);
    CHECK(checker.collides(at(0.0, sign * 0.11, 4.0)));  // into an end wall
    CHECK_FALSE(checker.collides(at(0.0, sign * 0.09, 4.0)));
    CHECK(std::abs(checker.distance(at(0.0, sign * 0.09, 4.0)) - 0.01) < 1e-9);
  }
}

TEST_CASE("insert3d_a_blade_tilted_by_the_angle_that_closes_the_gap_collides", "[unit]") {
  // Hand at (0, 0, 4), tip 4 deep. Turning about the hand's y axis by phi swings the bottom
  // edge (x = -+0.2, z = -8) toward a plate: it reaches |x| = 0.3 at
  // phi* = asin(0.3 / |(0.2, 8)|) - atan2(0.2, 8). About x, the bottom edge (y = -+2) reaches an
  // end wall (|y| = 2.1) at asin(2.1 / |(2, 8)|) - atan2(2, 8).
  const CollisionChecker checker;
  const struct {
    Eigen::Vector3d axis;
    double half_size;
    double half_gap;
  } cases[] = {{Eigen::Vector3d::UnitY(), 0.2, 0.3}, {Eigen::Vector3d::UnitX(), 2.0, 2.1}};
  for (const auto& c : cases) {
    const double phi_star =
        std::asin(c.half_gap / std::hypot(c.half_size, 8.0)) - std::atan2(c.half_size, 8.0);
    REQUIRE(phi_star > 0.0);
    INFO("axis " << c.axis.transpose() << ", phi* = " << phi_star);
    for (const double sign : {-1.0, 1.0}) {
      CHECK(checker.collides(tilted(c.axis, sign * 1.05 * phi_star, 4.0)));
      CHECK_FALSE(checker.collides(tilted(c.axis, sign * 0.95 * phi_star, 4.0)));
    }
  }
}

TEST_CASE("insert3d_motions_through_walls_between_free_poses_are_caught", "[unit]") {
  CHECK(catches_motions_through_walls(continuous));
}

TEST_CASE("mutant_insert3d_endpoint_only_motion_check_is_caught", "[unit]") {
  CHECK_FALSE(catches_motions_through_walls(testing::endpoints_only<CollisionChecker>));
}

TEST_CASE("mutant_insert3d_fixed_four_sample_motion_check_is_caught", "[unit]") {
  CHECK_FALSE(catches_motions_through_walls(testing::four_samples<CollisionChecker, interpolate>));
}

TEST_CASE("insert3d_advancement_takes_big_steps_far_from_the_block_and_small_ones_near_it",
          "[unit]") {
  const CollisionChecker checker;
  const std::uint64_t before = checker.queries();
  CHECK_FALSE(checker.motion_collides(at(-20.0, 0.0, 30.0), at(20.0, 0.0, 30.0)));
  const std::uint64_t far_queries = checker.queries() - before;
  CHECK(far_queries < 40);
  // 0.01 from a plate, every step is at most that distance: >= 0.5 / 0.01 queries for 0.5 cm.
  const std::uint64_t mid = checker.queries();
  CHECK_FALSE(checker.motion_collides(at(0.09, 0.0, 7.5), at(0.09, 0.0, 7.0)));
  CHECK(checker.queries() - mid >= 50);
}

TEST_CASE("insert3d_interpolation_commutes_with_global_transforms_and_hits_both_ends", "[unit]") {
  const RigidTransform a(Rotation::exp(Eigen::Vector3d(0.3, -2.0, 1.0)),
                         Eigen::Vector3d(1.0, 2.0, 3.0));
  const RigidTransform b(Rotation::exp(Eigen::Vector3d(-1.0, 0.5, 2.5)),
                         Eigen::Vector3d(-4.0, 0.0, 7.0));
  const RigidTransform g(Rotation::exp(Eigen::Vector3d(2.0, 1.0, -0.5)),
                         Eigen::Vector3d(30.0, -20.0, 5.0));
  CHECK(distance(interpolate(a, b, 0.0), a) < 1e-12);
  CHECK(distance(interpolate(a, b, 1.0), b) < 1e-12);
  for (const double s : {0.1, 0.5, 0.9}) {
    CHECK(distance(interpolate(g * a, g * b, s), g * interpolate(a, b, s)) < 1e-12);
  }
}

TEST_CASE("insert3d_a_bad_clearance_is_rejected_with_the_value_and_the_fix", "[unit]") {
  BladeSlotGeometry geometry;
  geometry.clearance_per_side = -0.1;
  CHECK_THROWS_WITH(CollisionChecker{geometry},
                    Catch::Matchers::Contains("-0.1") && Catch::Matchers::Contains("e.g. 0.1"));
  geometry.clearance_per_side = std::nan("");
  CHECK_THROWS_AS(CollisionChecker{geometry}, InvalidArgument);
  geometry.clearance_per_side = 2.0;
  CHECK_THROWS_AS(CollisionChecker{geometry}, InvalidArgument);
}

TEST_CASE("insert3d_only_a_tip_inside_the_slot_deep_enough_is_an_insertion", "[unit]") {
  const CollisionChecker checker;
  const BladeSlotGeometry& geometry = checker.geometry();
  // The hand upright with the tip at depth d: hand at z = kBladeLength - d.
  CHECK(inserted(geometry, at(0.0, 0.0, kBladeLength - 5.5)));
  CHECK(inserted(geometry, at(0.0, 0.0, kBladeLength - kSlotDepth)));  // on the floor
  CHECK_FALSE(inserted(geometry, at(0.0, 0.0, kBladeLength - 4.9)));   // not deep enough
  CHECK_FALSE(inserted(geometry, at(geometry.inner_half_x() + 0.01, 0.0, kBladeLength - 5.5)));

  // Under the block, the blade turned by pi about x (pointing away from the slot): contact-free,
  // inside the footprint and deeper than kSuccessDepth, but not inserted.
  const double tip_z = -kSlotDepth - kSlotWallThickness - 1.0;
  const RigidTransform under =
      tilted(Eigen::Vector3d::UnitX(), std::numbers::pi, tip_z - kBladeLength);
  REQUIRE(tip_in_slot(under).z() == Approx(tip_z));
  CHECK_FALSE(checker.collides(under));
  CHECK_FALSE(inserted(geometry, under));
  // Planted fault: the test without its floor calls that pose a success.
  const Eigen::Vector3d tip = tip_in_slot(under);
  CHECK((tip.z() <= -kSuccessDepth && std::abs(tip.x()) < geometry.inner_half_x() &&
         std::abs(tip.y()) < geometry.inner_half_y()));
}
