// The camera model (core/camera.hpp, core/solid.hpp): ray hits of each solid against their
// analytic answers, the pixel rays, shading by a head light and a fixed light, and bad input.
#include <catch2/catch.hpp>
#include <cmath>

#include "handcentric/core/camera.hpp"
#include "handcentric/core/errors.hpp"

using namespace handcentric;

namespace {

PinholeCamera small_camera() {
  return PinholeCamera{8, 6, 90.0, 10.0};
}

}  // namespace

TEST_CASE("solid_hits_from_outside_inside_and_misses", "[unit]") {
  const Solid box = Solid::box(RigidTransform::from_translation(Eigen::Vector3d(0.0, 0.0, 2.5)),
                               Eigen::Vector3d(1.0, 1.0, 0.5));
  const auto in_box = [&](const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
    return hit_in_solid_frame(box, o - Eigen::Vector3d(0.0, 0.0, 2.5), d);
  };
  const auto front = in_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
  REQUIRE(front);
  CHECK(front->t == 2.0);
  CHECK(front->normal == Eigen::Vector3d(0.0, 0.0, -1.0));
  const auto inside = in_box(Eigen::Vector3d(0.0, 0.0, 2.5), Eigen::Vector3d::UnitZ());
  REQUIRE(inside);
  CHECK(inside->t == 0.0);
  CHECK_FALSE(in_box(Eigen::Vector3d::Zero(), -Eigen::Vector3d::UnitZ()));
  CHECK_FALSE(in_box(Eigen::Vector3d(2.0, 0.0, 0.0), Eigen::Vector3d::UnitZ()));
  CHECK_FALSE(in_box(Eigen::Vector3d(-5.0, 0.0, 0.0), Eigen::Vector3d(1.0, 0.0, 1.0)));
  const auto side = in_box(Eigen::Vector3d(-3.5, 0.0, 0.0), Eigen::Vector3d(1.0, 0.0, 1.0));
  REQUIRE(side);
  CHECK(side->t == Approx(2.5));  // enters x = -1
  CHECK(side->normal == Eigen::Vector3d(-1.0, 0.0, 0.0));

  const Solid ball = Solid::sphere(Eigen::Vector3d::Zero(), 0.5);
  const auto near = hit_in_solid_frame(ball, Eigen::Vector3d(0.0, 0.0, -3.0),
                                       Eigen::Vector3d(0.0, 0.0, 2.0));  // not unit: t in its units
  REQUIRE(near);
  CHECK(near->t == Approx(1.25));
  CHECK((near->normal - Eigen::Vector3d(0.0, 0.0, -1.0)).norm() < 1e-15);
  CHECK_FALSE(hit_in_solid_frame(ball, Eigen::Vector3d(0.0, 0.6, -3.0), Eigen::Vector3d::UnitZ()));
  CHECK_FALSE(hit_in_solid_frame(ball, Eigen::Vector3d(0.0, 0.0, 3.0), Eigen::Vector3d::UnitZ()));

  const Solid floor = Solid::plane(RigidTransform::identity());
  const auto down =
      hit_in_solid_frame(floor, Eigen::Vector3d(0.0, 0.0, 2.0), Eigen::Vector3d(1.0, 0.0, -1.0));
  REQUIRE(down);
  CHECK(down->t == 2.0);
  CHECK(down->normal == Eigen::Vector3d::UnitZ());
  CHECK_FALSE(hit_in_solid_frame(floor, Eigen::Vector3d(0.0, 0.0, 2.0), Eigen::Vector3d::UnitX()));
  CHECK(hit_in_solid_frame(floor, Eigen::Vector3d(0.0, 0.0, -1.0), Eigen::Vector3d::UnitX())->t ==
        0.0);  // below the floor is inside it
}

TEST_CASE("a_sphere_ahead_is_rendered_at_its_depth_with_head_light_shading", "[unit]") {
  const PinholeCamera camera = small_camera();
  CHECK(camera.focal_length() == Approx(4.0));
  CHECK(camera.pixel_ray(0, 0).isApprox(Eigen::Vector3d(-3.5 / 4.0, -2.5 / 4.0, 1.0)));
  // A large sphere straight ahead fills the middle pixels; its near point is at depth 3.
  const std::vector<Solid> solids = {
      Solid::sphere(Eigen::Vector3d(0.0, 0.0, 4.0), 1.0, Eigen::Vector3d(1.0, 0.5, 0.0))};
  const CameraImage image = render(solids, camera, RigidTransform::identity());
  REQUIRE(image.depth.size() == 48u);
  REQUIRE(image.rgb.size() == 144u);
  // Pixel (2, 3) looks along (-0.125, -0.125, 1): the analytic root of |o + t d - c| = 1.
  const Eigen::Vector3d d = camera.pixel_ray(2, 3);
  const Eigen::Vector3d c(0.0, 0.0, 4.0);
  const double b = d.dot(c), a = d.squaredNorm();
  const double t = (b - std::sqrt(b * b - a * (c.squaredNorm() - 1.0))) / a;
  CHECK(image.depth_at(2, 3) == Approx(t).epsilon(1e-14));
  // Head light: the shade is ambient + (1 - ambient) cos(normal, ray).
  const Eigen::Vector3d normal = (t * d - c).normalized();
  const double shade = 0.35 + 0.65 * std::max(0.0, -normal.dot(Eigen::Vector3d::UnitZ()));
  CHECK(image.rgb[3 * (2 * 8 + 3)] == Approx(shade).epsilon(1e-12));
  CHECK(image.rgb[3 * (2 * 8 + 3) + 1] == Approx(0.5 * shade).epsilon(1e-12));
  CHECK(image.rgb[3 * (2 * 8 + 3) + 2] == 0.0);
  // A corner pixel misses: max_range and black.
  CHECK(image.depth_at(0, 0) == 10.0);
  CHECK(image.rgb[0] == 0.0);
}

TEST_CASE("a_fixed_light_shades_by_the_surface_normal_in_the_rendering_frame", "[unit]") {
  // The camera 2 above a floor, looking straight down; the lamp straight down lights the floor
  // fully, a lamp along the floor not at all (ambient only).
  const RigidTransform frame_T_camera(
      Rotation::from_matrix(Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal().toDenseMatrix()),
      Eigen::Vector3d(0.0, 0.0, 2.0));
  const std::vector<Solid> floor = {Solid::plane(RigidTransform::identity())};
  const CameraImage overhead =
      render(floor, small_camera(), frame_T_camera, Light::directional(-Eigen::Vector3d::UnitZ()));
  const CameraImage grazing =
      render(floor, small_camera(), frame_T_camera, Light::directional(Eigen::Vector3d::UnitX()));
  for (std::size_t p = 0; p < overhead.depth.size(); ++p) {
    CHECK(overhead.depth[p] == Approx(2.0));  // the ray's z is 1: depth is the camera's height
    CHECK(overhead.rgb[3 * p] == Approx(0.8));
    CHECK(grazing.rgb[3 * p] == Approx(0.8 * 0.35));
  }
  CHECK(largest_image_difference(overhead, grazing) == Approx(0.8 * 0.65));
}

TEST_CASE("mutant_a_camera_and_solids_moved_apart_render_differently", "[unit]") {
  // The renderer reads only solid_T_camera: moving both by one g keeps the image, moving only the
  // camera (the planted fault) does not.
  const std::vector<Solid> solids = {
      Solid::sphere(Eigen::Vector3d(0.2, 0.1, 3.0), 0.7),
      Solid::box(RigidTransform(Rotation::exp(Eigen::Vector3d(0.0, 0.4, 0.0)),
                                Eigen::Vector3d(-0.5, 0.3, 4.0)),
                 Eigen::Vector3d(0.6, 0.3, 0.2))};
  const RigidTransform g(Rotation::exp(2.0 * Eigen::Vector3d(1.0, 2.0, 3.0).normalized()),
                         Eigen::Vector3d(30.0, -7.0, 2.0));
  std::vector<Solid> moved = solids;
  for (Solid& solid : moved) solid.frame_T_solid = g * solid.frame_T_solid;
  const CameraImage image = render(solids, small_camera(), RigidTransform::identity());
  CHECK(largest_image_difference(image, render(moved, small_camera(), g)) < 1e-12);
  CHECK(largest_image_difference(image, render(solids, small_camera(), g)) > 1.0);
}

TEST_CASE("bad_cameras_solids_and_lights_are_refused_with_the_value_and_the_fix", "[unit]") {
  PinholeCamera camera = small_camera();
  camera.width = 0;
  CHECK_THROWS_WITH(
      render({}, camera, RigidTransform::identity()),
      Catch::Matchers::Contains("0 x 6") && Catch::Matchers::Contains("e.g. 32 x 24"));
  camera = small_camera();
  camera.horizontal_fov_deg = 170.0;
  CHECK_THROWS_WITH(camera.validate("hand camera"),
                    Catch::Matchers::Contains("hand camera") && Catch::Matchers::Contains("170"));
  camera = small_camera();
  camera.max_range = -1.0;
  CHECK_THROWS_AS(camera.validate(), InvalidArgument);
  CHECK_THROWS_WITH(Solid::sphere(Eigen::Vector3d::Zero(), 0.0),
                    Catch::Matchers::Contains("radius"));
  CHECK_THROWS_WITH(Solid::sphere(Eigen::Vector3d::Zero(), 1.0, Eigen::Vector3d(1.0, 2.0, 0.0)),
                    Catch::Matchers::Contains("albedo"));
  CHECK_THROWS_WITH(Solid::box(RigidTransform::identity(), Eigen::Vector3d(1.0, -1.0, 1.0)),
                    Catch::Matchers::Contains("half extents"));
  CHECK_THROWS_WITH(Solid::sphere(Eigen::Vector3d(0.0, std::nan(""), 0.0), 1.0),
                    Catch::Matchers::Contains("nan"));
  CHECK_THROWS_WITH(Light::directional(Eigen::Vector3d::Zero()),
                    Catch::Matchers::Contains("direction"));
  CHECK_THROWS_WITH(Light::directional(Eigen::Vector3d::UnitZ(), 1.5),
                    Catch::Matchers::Contains("1.5"));
  CHECK(largest_image_difference(
            render({}, small_camera(), RigidTransform::identity()),
            render({}, PinholeCamera{4, 3, 90.0, 10.0}, RigidTransform::identity())) == INFINITY);
}
