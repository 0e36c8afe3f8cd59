// Every case of a check is a draw of one law: the documented one (log-uniform scene scales from
// 1 cm to 10 m, the group's elements, a recorded file's observations uniformly), whatever the
// case's number. RapidCheck's own inRange scales its range with a size that grows with the case
// number, so without props::uniform_integer a check's first cases draw near the low end only;
// the planted fault below is that inRange, and the same statistics must catch it.
#include <catch2/catch.hpp>

#include <cmath>
#include <functional>
#include <memory>
#include <vector>

#include "checks/check_runner.hpp"
#include "handcentric/props/observation/generators.hpp"
#include "handcentric/props/observation/recorded.hpp"

namespace handcentric::props {
namespace {

// What `draw` returns in each of `cases` cases of one RapidCheck run (as a check runs them).
std::vector<double> drawn_over_cases(const std::function<double()>& draw, int cases) {
  std::vector<double> values;
  detail::run_silently([&] { values.push_back(draw()); }, "the law of the cases", 7, cases);
  return values;
}

double fraction_above(const std::vector<double>& values, double threshold) {
  double above = 0.0;
  for (double v : values) above += v > threshold ? 1.0 : 0.0;
  return above / static_cast<double>(values.size());
}

double mean_of(const std::vector<double>& values) {
  double sum = 0.0;
  for (double v : values) sum += v;
  return sum / static_cast<double>(values.size());
}

// The fraction of 2000 cases in the upper two thirds of [0, 2^20): 2/3 for uniform draws,
// about 0.30 when the range grows with the case number.
double upper_fraction(const std::function<rc::Gen<int>()>& integers) {
  constexpr int kHigh = 1 << 20;
  return fraction_above(
      drawn_over_cases([&] { return static_cast<double>(*integers()) / kHigh; }, 2000), 1.0 / 3.0);
}

}  // namespace

TEST_CASE("an_integer_is_uniform_in_every_case_and_the_sized_inRange_is_caught", "[property]") {
  const double uniform = upper_fraction([] { return uniform_integer(0, 1 << 20); });
  CHECK(uniform == Approx(2.0 / 3.0).epsilon(0.05));
  // The planted fault: RapidCheck's inRange, whose range grows with the case number.
  const double sized = upper_fraction([] { return rc::gen::inRange(0, 1 << 20); });
  CHECK_FALSE(sized == Approx(2.0 / 3.0).epsilon(0.05));
  CHECK(sized < 0.4);
}

TEST_CASE("scene_scales_are_log_uniform_from_1_cm_to_10_m_in_the_first_cases_too", "[property]") {
  // P(L > 0.1 m) = log(100) / log(1000) = 2/3 for L log-uniform in [0.01, 10] m, in a check of
  // 10 cases (an in-distribution check's) as in one of 2000.
  const SceneShape shape = eye_in_hand_shape();
  auto scale = [&] {
    const auto [scene, g] = detail::draw_case(shape, Group::se3);
    return scene.world_T_hand_history.front().translation().norm();
  };
  CHECK(fraction_above(drawn_over_cases(scale, 2000), 0.1) == Approx(2.0 / 3.0).epsilon(0.05));
  int far_in_small_checks = 0;  // 20 checks of 10 cases: 200 draws
  for (int run = 0; run < 20; ++run) {
    std::vector<double> values;
    detail::run_silently([&] { values.push_back(scale()); }, "ten cases",
                         static_cast<std::uint64_t>(run + 1), 10);
    for (double v : values) far_in_small_checks += v > 0.1 ? 1 : 0;
  }
  CHECK(far_in_small_checks / 200.0 == Approx(2.0 / 3.0).epsilon(0.12));
}

TEST_CASE("c8_draws_each_of_its_eight_elements_equally_often", "[property]") {
  auto angle = [] {
    return std::abs(detail::draw_case(eye_in_hand_shape(), Group::c8).second.rotation().log().z());
  };
  const std::vector<double> angles = drawn_over_cases(angle, 2000);
  // The identity is one element of eight (angle 0); the half turn another (angle pi).
  CHECK(1.0 - fraction_above(angles, 1e-9) == Approx(1.0 / 8.0).epsilon(0.25));
  CHECK(fraction_above(angles, 3.0) == Approx(1.0 / 8.0).epsilon(0.25));
}

TEST_CASE("recorded_observations_are_drawn_uniformly_from_the_whole_file", "[property]") {
  auto recorded = std::make_shared<RecordedObservations>();
  recorded->source = "a file of 100 observations";
  for (int i = 0; i < 100; ++i) {
    Scene s;
    s.world_T_hand_history.push_back(
        RigidTransform(Rotation::identity(), Eigen::Vector3d(0.01 * (i + 1), 0.0, 0.0)));
    recorded->scenes.push_back(s);
  }
  SceneShape shape = eye_in_hand_shape();
  shape.recorded = recorded;
  auto index = [&] {
    const auto [scene, g] = detail::draw_case(shape, Group::translation);
    return std::round(scene.world_T_hand_history.front().translation().x() / 0.01) - 1.0;
  };
  // The mean index of uniform draws from 0..99 is 49.5 (sd of the mean over 1000: 0.9).
  CHECK(mean_of(drawn_over_cases(index, 1000)) == Approx(49.5).epsilon(0.08));
}

}  // namespace handcentric::props
