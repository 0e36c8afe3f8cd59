// drawn_cases: the cases a pointwise check decides, in its order, for a tool that asks the map
// about them itself (handcentric.locate). The check's own questions are recorded and compared:
// case k's scene and g o are the k-th pair the check asked about. The planted fault draws g
// before the scene, which gives other cases from the same seed.
#include <catch2/catch.hpp>

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "checks/check_runner.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/checks/drawn_cases.hpp"
#include "handcentric/props/observation/generators.hpp"

namespace handcentric::props {
namespace {

// The scenes an invariant check asks about: s, then g s, per case (the floor holds at once).
std::vector<Scene> asked_by_the_check(const CheckOptions& options, Group group) {
  std::vector<Scene> asked;
  const SceneFunction f = [&asked](const Scene& s) {
    asked.push_back(s);
    return Eigen::VectorXd::Zero(1).eval();
  };
  (void)check_invariance(f, Component::observation, group, options);
  return asked;
}

bool same_scene(const Scene& a, const Scene& b) {
  if (a.world_T_hand_history.size() != b.world_T_hand_history.size() ||
      a.hand_points.size() != b.hand_points.size() ||
      a.world_points.size() != b.world_points.size())
    return false;
  for (std::size_t i = 0; i < a.world_T_hand_history.size(); ++i) {
    if (a.world_T_hand_history[i].matrix() != b.world_T_hand_history[i].matrix()) return false;
  }
  for (std::size_t i = 0; i < a.world_points.size(); ++i) {
    if (a.world_points[i] != b.world_points[i]) return false;
  }
  return true;
}

// True when `cases` are the pairs (s, g s) the check asked about, in its order.
bool are_the_checks_cases(const std::vector<std::pair<Scene, RigidTransform>>& cases,
                          const std::vector<Scene>& asked) {
  if (asked.size() != 2 * cases.size()) return false;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    if (!same_scene(cases[k].first, asked[2 * k]) ||
        !same_scene(cases[k].second * cases[k].first, asked[2 * k + 1]))
      return false;
  }
  return true;
}

}  // namespace

TEST_CASE("drawn_cases_are_the_cases_a_check_decides_in_its_order", "[unit]") {
  CheckOptions options = options_for(View::third_person);
  options.cases = 30;
  for (const std::uint64_t seed : {1ULL, 9ULL}) {
    options.seed = seed;
    for (const Group group : {Group::se3, Group::c8}) {
      const auto cases = drawn_cases(options, group);
      REQUIRE(cases.size() == 30);
      CHECK(are_the_checks_cases(cases, asked_by_the_check(options, group)));
    }
  }
}

TEST_CASE("mutant_cases_drawn_g_first_are_not_the_checks", "[unit]") {
  CheckOptions options = options_for(View::eye_in_hand);
  options.cases = 30;
  std::vector<std::pair<Scene, RigidTransform>> g_first;
  detail::run_silently(
      [&] {
        const RigidTransform g = *group_element(Group::se3);
        g_first.emplace_back(*scene(options.shape), g);
      },
      "g first", options.seed, options.cases);
  const std::vector<Scene> asked = asked_by_the_check(options, Group::se3);
  CHECK_FALSE(are_the_checks_cases(g_first, asked));
  CHECK(are_the_checks_cases(drawn_cases(options, Group::se3), asked));
  options.cases = 0;
  CHECK_THROWS_AS(drawn_cases(options, Group::se3), InvalidArgument);
}

}  // namespace handcentric::props
