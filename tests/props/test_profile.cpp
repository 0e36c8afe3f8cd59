// How far from equivariant (profile.hpp): the built-ins' shapes (hand-centric flat at rounding
// under every group, relative flat in translation and growing in rotation, absolute growing in
// both), a C8-symmetrized map at 0 on C8 and not between, ActionFlow's target equivariant in law
// but not pointwise, policies; and planted faults whose profile the test computes on its own, so
// that a profile that ignores g, or divides by the wrong scale, fails here.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/props/checks/profile.hpp"
#include "handcentric/props/random_network.hpp"
#include "run_command.hpp"

using namespace handcentric;
using props::Group;

namespace {

props::Profile profile_of_builtin(const std::string& name, Group group) {
  return props::profile_function(props::actions_of(make_representation(name)), name,
                                 props::Component::actions, group);
}

// hand_centric's actions plus `leak` times the world position of the hand now, p_0: a planted
// symmetry breaking of known size (|f(g s) - f(s)|_inf = leak |R~ p_0 + p~ - p_0|_inf).
props::SceneFunction profile_leaky_hand_centric(double leak) {
  return [leak](const Scene& s) {
    Eigen::VectorXd v = HandCentricRepresentation().encode_actions(s);
    v.head<3>() += leak * s.world_T_hand0().translation();
    return v;
  };
}

// A small "network" on the world-frame chunk positions, m(s) = [relu(x_k), relu(y_k), z_k],
// averaged over C8's orbit about world z: f(s) = 1/8 sum_k m(g_k s) is invariant under C8 (g_j
// permutes the terms), up to the rounding of g_k g_j against g_(k+j), and not under the rotations
// between (the ReLU has harmonics of order 8 in the angle, which the average keeps; a linear m
// would average to a map invariant under every rotation about z).
props::SceneFunction profile_c8_symmetrized() {
  const auto m = [](const Scene& s) {
    Eigen::VectorXd v(3 * static_cast<Eigen::Index>(s.world_T_hand_chunk.size()));
    for (std::size_t k = 0; k < s.world_T_hand_chunk.size(); ++k) {
      const Eigen::Vector3d& p = s.world_T_hand_chunk[k].translation();
      v.segment<3>(3 * static_cast<Eigen::Index>(k)) =
          Eigen::Vector3d(std::max(0.0, p.x()), std::max(0.0, p.y()), p.z());
    }
    return v;
  };
  return [m](const Scene& s) {
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(m(s).size());
    for (int k = 0; k < 8; ++k)
      sum +=
          m(RigidTransform(Rotation::about_z(k * std::numbers::pi / 4.0), Eigen::Vector3d::Zero()) *
            s);
    return Eigen::VectorXd(sum / 8.0);
  };
}

double profile_median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// Adds N(0, sigma^2 I) to every position in the world frame: affine in the noise, equivariant in
// law under rotations (isotropic noise), not pointwise.
class ProfileWorldNoisePolicy final : public props::NoisyPolicy {
 public:
  std::string name() const override { return "profile_world_noise"; }
  Eigen::Index noise_dimension() const override { return 3; }
  std::vector<RigidTransform> act(const Scene& o, const Eigen::VectorXd& noise) const override {
    std::vector<RigidTransform> chunk;
    RigidTransform T = o.world_T_hand0();
    Twist step;
    step << 0.05, 0.0, 0.01, 0.0, 0.1, 0.0;
    for (int k = 0; k < 3; ++k) {
      T = T * RigidTransform::exp(step);
      chunk.push_back(RigidTransform(T.rotation(), T.translation() + 0.01 * noise));
    }
    return chunk;
  }
};

}  // namespace

TEST_CASE("profile_hand_centric_is_flat_at_rounding_under_every_group", "[property]") {
  for (Group group : props::all_groups()) {
    INFO(props::to_string(group));
    const props::Profile p = profile_of_builtin("hand_centric", group);
    REQUIRE(p.points.size() == props::default_profile_sizes(group).size());
    for (const props::ProfilePoint& point : p.points) CHECK(point.pointwise.max < 1e-10);
    CHECK(p.slope.max < 1e-6);
    CHECK_FALSE(p.points.front().distribution.has_value());  // deterministic: no law
  }
}

TEST_CASE("profile_relative_is_flat_in_translation_and_grows_in_rotation", "[property]") {
  const props::Profile translation = profile_of_builtin("relative", Group::translation);
  for (const props::ProfilePoint& point : translation.points) CHECK(point.pointwise.max < 1e-10);
  CHECK(translation.slope.max < 1e-6);
  const props::Profile rotation = profile_of_builtin("relative", Group::rotation);
  // Up to 1 rad the error grows with the angle, about linearly (slope * t) at small angles.
  for (std::size_t k = 1; k < rotation.points.size() && rotation.points[k].size <= 1.0; ++k)
    CHECK(rotation.points[k].pointwise.median > rotation.points[k - 1].pointwise.median);
  // Only the positions p_k - p_0 turn with g (a few cm), beside rotation vectors of up to a few
  // rad that do not: relative to the chunk's scale, the error is small but far above rounding.
  CHECK(rotation.points.back().pointwise.median > 1e-3);
  CHECK(rotation.points.back().pointwise.median > 1e3 * rotation.points.front().pointwise.median);
  CHECK(rotation.slope.median > 1e-4);
  CHECK(rotation.points.front().pointwise.median / rotation.points.front().size ==
        Approx(rotation.slope.median).epsilon(0.05));
}

TEST_CASE("profile_absolute_grows_in_translation_and_in_rotation", "[property]") {
  for (Group group : {Group::translation, Group::rotation, Group::se3}) {
    INFO(props::to_string(group));
    const props::Profile p = profile_of_builtin("absolute", group);
    CHECK(p.points.front().pointwise.median > 1e-5);
    CHECK(p.points.back().pointwise.median > 100 * p.points.front().pointwise.median);
    CHECK(p.slope.median > 1e-2);
  }
}

TEST_CASE("profile_of_a_planted_leak_is_the_one_the_test_computes_itself", "[property]") {
  // Independent of profile_transform: g is built here from the case's direction, and the
  // normalization is the documented max(|f(s)|_inf, 1e-3). A profile that ignored g (all 0) or
  // divided by another scale would differ.
  const double leak = 1e-3;
  const props::SceneFunction f = profile_leaky_hand_centric(leak);
  props::ProfileOptions options;
  options.scenes = 9;
  const props::Profile p =
      props::profile_function(f, "leaky", props::Component::actions, Group::translation, options);
  const std::vector<props::ProfileCase> cases = props::profile_cases(options);
  REQUIRE(cases.size() == 9);
  for (const props::ProfilePoint& point : p.points) {
    std::vector<double> expected;
    for (const props::ProfileCase& c : cases) {
      const double scale = std::max(f(c.scene).lpNorm<Eigen::Infinity>(), 1e-3);
      expected.push_back(leak * point.size * c.direction.lpNorm<Eigen::Infinity>() / scale);
    }
    INFO("size " << point.size);
    CHECK(point.pointwise.median == Approx(profile_median(expected)).epsilon(1e-6));
    CHECK(point.pointwise.max ==
          Approx(*std::max_element(expected.begin(), expected.end())).epsilon(1e-6));
  }
  std::vector<double> slopes;
  for (const props::ProfileCase& c : cases)
    slopes.push_back(leak * c.direction.lpNorm<Eigen::Infinity>() /
                     std::max(f(c.scene).lpNorm<Eigen::Infinity>(), 1e-3));
  CHECK(p.slope.median == Approx(profile_median(slopes)).epsilon(1e-6));
  // The same leak in a map 1000 times larger is the same relative error.
  const props::SceneFunction scaled = [f](const Scene& s) { return Eigen::VectorXd(1e3 * f(s)); };
  const props::Profile q = props::profile_function(
      scaled, "leaky x 1000", props::Component::actions, Group::translation, options);
  for (std::size_t k = 0; k < p.points.size(); ++k)
    CHECK(q.points[k].pointwise.median == Approx(p.points[k].pointwise.median).epsilon(1e-9));
}

TEST_CASE("profile_c8_symmetrized_map_vanishes_on_c8_and_not_between", "[property]") {
  const props::Profile p = props::profile_function(profile_c8_symmetrized(), "c8_average",
                                                   props::Component::actions, Group::c8);
  int in_group = 0, between = 0;
  for (const props::ProfilePoint& point : p.points) {
    INFO("angle " << point.size);
    if (point.in_group) {
      ++in_group;
      CHECK(point.pointwise.max < 1e-10);
    } else {
      ++between;
      CHECK(point.pointwise.median > 1e-3);
    }
  }
  CHECK(in_group == 8);
  CHECK(between == 8);
  CHECK(p.slope.median > 1e-3);  // C8 is discrete: no symmetry at the identity
  // The absolute map it averages is not C8-invariant at all.
  const props::Profile plain = profile_of_builtin("absolute", Group::c8);
  CHECK(plain.points[1].pointwise.median > 1e-3);
}

TEST_CASE("profile_actionflow_target_is_equivariant_in_law_not_pointwise", "[property]") {
  const auto target = std::make_shared<ActionFlowTarget>();
  const props::Profile rotation =
      props::profile_flow(target, props::Component::flow_target, Group::rotation);
  CHECK(rotation.distribution_method == "exact_gaussian");
  CHECK(rotation.points.back().pointwise.median > 0.1);
  for (const props::ProfilePoint& point : rotation.points) {
    REQUIRE(point.distribution.has_value());
    CHECK(point.distribution->max < 1e-9);
  }
  const props::Profile translation =
      props::profile_flow(target, props::Component::flow_target, Group::translation);
  CHECK(translation.points.back().distribution->median > 1e-2);
  CHECK_THROWS_AS(props::profile_flow(target, props::Component::actions, Group::rotation),
                  InvalidArgument);
}

TEST_CASE("profile_of_policies_pointwise_and_in_law", "[property]") {
  // Theorem 1: any network inside the hand-centric outer policy; seeded, so in law by energy.
  const auto inner = std::make_shared<props::RandomOuterPolicy>(
      std::make_shared<HandCentricRepresentation>(), 6, 3, std::vector<int>{16}, 3);
  const props::SeededPolicy hand_centric(inner);
  props::ProfileOptions options;
  options.scenes = 6;
  options.samples = 8;
  options.shape.min_history = options.shape.max_history = 0;
  options.shape.max_hand_points = 0;
  const props::Profile p = props::profile_policy(hand_centric, Group::se3, options);
  CHECK(p.distribution_method == "energy_distance");
  REQUIRE(p.distribution_floor.has_value());
  CHECK(*p.distribution_floor > 1e-3);  // two samples of one law are not at 0
  for (const props::ProfilePoint& point : p.points) {
    CHECK(point.pointwise.max < 1e-9);
    CHECK(point.distribution->max < 1e-9);  // the same noise on both sides
  }
  // World-frame isotropic noise: pointwise it grows with the angle; in law it stays at rounding.
  const ProfileWorldNoisePolicy world;
  const props::Profile w = props::profile_policy(world, Group::rotation, options);
  CHECK(w.distribution_method == "exact_gaussian");
  CHECK(w.points.back().pointwise.median > 10 * w.points.front().pointwise.median);
  for (const props::ProfilePoint& point : w.points) CHECK(point.distribution->max < 1e-9);
}

TEST_CASE("profile_is_deterministic_and_its_json_lists_every_size", "[unit]") {
  props::ProfileOptions options;
  options.scenes = 4;
  const auto once = [&] {
    return props::profile_json(
        {props::profile_function(props::actions_of(make_representation("relative")), "relative",
                                 props::Component::actions, Group::se2, options)});
  };
  const std::string a = once();
  CHECK(a == once());
  const nlohmann::json j = nlohmann::json::parse(a);
  REQUIRE(j["profiles"].size() == 1);
  CHECK(j["profiles"][0]["sizes"].size() == props::default_profile_sizes(Group::se2).size());
  CHECK(j["profiles"][0]["pointwise"]["median"].size() == j["profiles"][0]["sizes"].size());
  CHECK(j["profiles"][0]["unit"] == "rad and m");
  CHECK(j["profiles"][0]["distribution"].is_null());
  options.seed = 2;
  CHECK(a != once());
}

TEST_CASE("profile_refuses_bad_options_naming_the_value", "[unit]") {
  const props::SceneFunction f = props::actions_of(make_representation("relative"));
  props::ProfileOptions options;
  options.sizes = {0.1, -1.0};
  CHECK_THROWS_WITH(
      props::profile_function(f, "r", props::Component::actions, Group::rotation, options),
      Catch::Matchers::Contains("size -1") && Catch::Matchers::Contains("(0, 1000]"));
  options.sizes = {std::nan("")};
  CHECK_THROWS_AS(
      props::profile_function(f, "r", props::Component::actions, Group::rotation, options),
      InvalidArgument);
  options = {};
  options.scenes = 0;
  CHECK_THROWS_WITH(
      props::profile_function(f, "r", props::Component::actions, Group::rotation, options),
      Catch::Matchers::Contains("scenes 0"));
  options = {};
  options.slope_step = 0.0;
  CHECK_THROWS_AS(
      props::profile_function(f, "r", props::Component::actions, Group::rotation, options),
      InvalidArgument);
  options = {};
  options.shape.workspace = props::Workspace::parse("-1,-1,-1,1,1,1");
  CHECK_THROWS_WITH(
      props::profile_function(f, "r", props::Component::actions, Group::rotation, options),
      Catch::Matchers::Contains("workspace"));
}

TEST_CASE("profile_transform_has_the_documented_size", "[unit]") {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 2) / 3.0, direction(0.6, 0.0, 0.8);
  CHECK(props::profile_transform(Group::translation, 2.0, axis, direction).translation().norm() ==
        Approx(2.0));
  CHECK(props::profile_transform(Group::rotation, 0.5, axis, direction).rotation().log().norm() ==
        Approx(0.5));
  const RigidTransform se2 = props::profile_transform(Group::se2, 0.5, axis, direction);
  CHECK(se2.translation().z() == 0.0);
  CHECK(se2.translation().norm() == Approx(0.5));
  CHECK(se2.rotation().log().normalized().z() == Approx(1.0));
  CHECK(props::profile_size_in_group(Group::c8, 3 * std::numbers::pi / 4));
  CHECK_FALSE(props::profile_size_in_group(Group::c8, 3 * std::numbers::pi / 8));
}

TEST_CASE("audit_profile_writes_json_and_png_and_names_bad_input", "[unit]") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "handcentric_test_profile_cli";
  fs::remove_all(dir);
  const auto ok = test::run_command(test::cli() + " audit --profile rotation --repr relative " +
                                    "--repr hand_centric --profile-scenes 4 --out " + dir.string());
  REQUIRE(ok.exit_code == 0);
  CHECK_THAT(ok.out, Catch::Matchers::Contains("relative actions: pointwise"));
  std::ifstream json_file(dir / "profile.json");
  const nlohmann::json json = nlohmann::json::parse(json_file);
  REQUIRE(json.at("profiles").size() == 2);
  CHECK(json["profiles"][1]["name"] == "hand_centric");
  CHECK(json["profiles"][0]["scenes"] == 4);
  std::ifstream png(dir / "profile.png", std::ios::binary);
  std::string magic(4, '\0');
  png.read(magic.data(), 4);
  CHECK(magic == "\x89PNG");
  // A plug-in over the pipe: the Python example is hand-centric, flat at rounding.
  const auto plugin =
      test::run_command(test::cli() + " audit --profile se3 --profile-scenes 3 " + "--out " +
                        (dir / "exec").string() + " --exec '" + test::python_example() + "'");
  REQUIRE(plugin.exit_code == 0);
  std::ifstream plugin_file(dir / "exec" / "profile.json");
  const nlohmann::json exec_json = nlohmann::json::parse(plugin_file);
  for (double e : exec_json["profiles"][0]["pointwise"]["max"].get<std::vector<double>>())
    CHECK(e < 1e-10);

  const fs::path bad = dir / "bad";
  const auto negative = test::run_command(
      test::cli() + " audit --profile rotation --profile-sizes 0.1,-1 --out " + bad.string());
  CHECK(negative.exit_code == 1);
  CHECK_THAT(negative.err, Catch::Matchers::Contains("size -1"));
  CHECK(negative.err.find('\n') == negative.err.size() - 1);
  CHECK_FALSE(fs::exists(bad / "profile.json"));  // nothing half-written
  const auto all = test::run_command(test::cli() + " audit --profile all --out " + bad.string());
  CHECK(all.exit_code == 1);
  CHECK_THAT(all.err, Catch::Matchers::Contains("--profile all"));
  const auto unknown =
      test::run_command(test::cli() + " audit --profile so3 --out " + bad.string());
  CHECK(unknown.exit_code == 1);
  CHECK_THAT(unknown.err, Catch::Matchers::Contains("so3"));
  const auto folder =
      test::run_command(test::cli() + " audit --profile rotation --out /proc/no_such/dir");
  CHECK(folder.exit_code == 1);
  CHECK_THAT(folder.err, Catch::Matchers::Contains("/proc/no_such/dir"));
  CHECK(test::run_command(test::cli() + " audit --profile rotation").exit_code == 2);
  CHECK(test::run_command(test::cli() + " audit --profile rotation --json --out " + bad.string())
            .exit_code == 2);
  const auto workspace = test::run_command(test::cli() + " audit --profile rotation --out " +
                                           bad.string() + " --workspace -1,-1,-1,1,1,1");
  CHECK(workspace.exit_code == 1);
  CHECK_THAT(workspace.err, Catch::Matchers::Contains("--workspace"));
  // Recorded observations are not drawn by a profile: refused, not ignored.
  const auto recorded = test::run_command(test::cli() + " audit --profile rotation --out " +
                                          bad.string() + " --observations log.jsonl");
  CHECK(recorded.exit_code == 1);
  CHECK_THAT(recorded.err, Catch::Matchers::Contains("--observations"));
  fs::remove_all(dir);
}
