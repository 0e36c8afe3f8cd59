// Long runs (docs/RELIABILITY.md, item 6): a policy that returns a non-finite pose on some scenes
// makes those trials invalid (failures with their own count) instead of ending the evaluation; with
// stop_on_invalid (`eval --strict`) the first one is an error. Planted faults: a scripted policy
// that returns nan where the hand starts right of a line, one that throws NonFiniteAction there,
// and a model file whose finite weights overflow to infinity on part of the scenes.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "child_process.hpp"  // tests/support
#include "handcentric/core/errors.hpp"
#include "handcentric/policy/binary_io.hpp"
#include "handcentric/policy/head.hpp"
#include "handcentric/policy/learned_policy.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/sim/policies.hpp"
#include "handcentric/sim/rollout.hpp"
#include "handcentric/sim/scenes.hpp"

using namespace handcentric;
using namespace handcentric::sim;
using Catch::Matchers::Contains;

namespace {

// Holds the hand still (every trial times out), except where the hand is right of world x =
// `line`: there it returns a nan pose, or throws NonFiniteAction as LearnedPolicy does.
class NanRightOf final : public ChunkPolicy {
 public:
  NanRightOf(double line, bool throws) : line_(line), throws_(throws) {}
  std::string name() const override { return "nan_right_of_line"; }
  std::vector<RigidTransform> act(const Scene& observation, std::uint64_t seed) const override {
    if (observation.world_T_hand0().translation().x() <= line_)
      return HoldPolicy().act(observation, seed);
    if (throws_) throw NonFiniteAction("the planted network diverged");
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {RigidTransform::unchecked(Eigen::Matrix3d::Identity(), Eigen::Vector3d(nan, 0.0, 0.0))};
  }

 private:
  double line_;
  bool throws_;
};

std::vector<TaskScene> scenes() {
  return sample_scenes(SceneDistribution::train(), 12, 5);
}

// The median start x of the scenes: about half of them are right of it.
double median_start_x(const std::vector<TaskScene>& all) {
  std::vector<double> x;
  for (const TaskScene& scene : all) x.push_back(scene.world_T_hand_start.translation().x());
  std::sort(x.begin(), x.end());
  return 0.5 * (x[x.size() / 2 - 1] + x[x.size() / 2]);
}

std::string invalid_temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("handcentric_test_invalid_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

// A flow / hand_centric model file (H = 0, K = 1, one ReLU unit, one Euler step) whose weights
// are all finite: the unit reads only o[6], the x of the left opening corner seen from the hand,
// normalized with mean `threshold` and scale 1e-30, times 3e38. Above the threshold the velocity
// overflows to infinity (a non-finite action); below it the unit is 0 and the action is noise.
std::string diverging_model(double threshold) {
  using namespace handcentric::policy;
  PolicyConfig config;
  config.head = HeadKind::flow;
  config.representation = "hand_centric";
  config.chunk_length = 1;
  config.history_length = 0;
  config.hand_points = 2;
  config.action_dimension = 6;
  config.observation_dimension = 12;  // the hand's own pose (6), two corners (3 each)
  config.hidden_width = 1;
  config.hidden_layers = 1;
  config.activation = Activation::relu;
  config.time_embedding = 0;
  config.euler_steps = 1;
  ByteWriter payload;
  payload.string(config.to_text());
  payload.string(config.representation);
  payload.string(to_string(config.head));
  payload.doubles(Eigen::VectorXd::Zero(6));  // action mean, scale, active
  payload.doubles(Eigen::VectorXd::Ones(6));
  payload.doubles(Eigen::VectorXd::Ones(6));
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(12), scale = Eigen::VectorXd::Ones(12);
  mean[6] = threshold;
  scale[6] = 1e-30;
  payload.doubles(mean);
  payload.doubles(scale);
  // W1 (1 x [6 actions, 1 time, 12 observation]), b1, W2 (6 x 1), b2
  Eigen::VectorXf weights = Eigen::VectorXf::Zero(19 + 1 + 6 + 6);
  weights[6 + 1 + 6] = 3e38f;
  weights.segment(20, 6).setOnes();
  REQUIRE(static_cast<std::uint64_t>(weights.size()) == parameter_count(config));
  payload.floats(weights);
  ByteWriter file;
  file.raw("HCPOLICY", 8);
  file.u32(kModelFormatVersion);
  file.u64(payload.bytes().size());
  file.raw(payload.bytes().data(), payload.bytes().size());
  file.u64(fnv1a64(file.bytes().data(), file.bytes().size()));
  return file.bytes();
}

}  // namespace

TEST_CASE("a_policy_returning_nan_on_some_scenes_makes_those_trials_invalid_not_fatal", "[unit]") {
  const CollisionChecker checker;
  const auto all = scenes();
  const double line = median_start_x(all);
  int right = 0, first_right = -1;
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (all[i].world_T_hand_start.translation().x() > line) {
      if (right++ == 0) first_right = static_cast<int>(i);
    }
  }
  REQUIRE(right > 0);
  REQUIRE(right < static_cast<int>(all.size()));
  for (const bool throws : {false, true}) {
    INFO((throws ? "throws NonFiniteAction" : "returns a nan pose"));
    const RolloutSummary summary = evaluate(NanRightOf(line, throws), all, checker, 1);
    CHECK(summary.trials == static_cast<int>(all.size()));
    CHECK(summary.invalid == right);
    CHECK(summary.timeout == summary.trials - right);  // the others are held until they time out
    CHECK(summary.success + summary.collision == 0);
    CHECK(summary.first_invalid_scene == first_right);
    CHECK_THAT(summary.first_invalid_reason, Contains("nan_right_of_line") && Contains("replan 0"));
    CHECK_THAT(summary.first_invalid_reason,
               Contains(throws ? "the planted network diverged" : "non-finite pose"));

    RolloutOptions strict;
    strict.stop_on_invalid = true;
    CHECK_THROWS_AS(evaluate(NanRightOf(line, throws), all, checker, 1, strict), NonFiniteAction);
    CHECK_THROWS_WITH(
        evaluate(NanRightOf(line, throws), all, checker, 1, strict),
        Contains("scene " + std::to_string(first_right) + ": ") && Contains("nan_right_of_line"));
  }
}

TEST_CASE("eval_counts_a_diverging_model_as_invalid_trials_and_strict_stops_at_the_first",
          "[unit]") {
  // The model diverges where the left corner is right of the hand by more than on the median
  // scene; eval through the command line must count what evaluate() counts in process.
  const auto all = scenes();
  std::vector<double> corner_x;
  for (const TaskScene& scene : all) {
    corner_x.push_back(
        observation(scene.world_T_hole, {scene.world_T_hand_start}, 0).hand_points[0].x());
  }
  std::sort(corner_x.begin(), corner_x.end());
  const std::string path = invalid_temp_path("diverging.model");
  std::ofstream(path, std::ios::binary) << diverging_model(0.5 * (corner_x[5] + corner_x[6]));

  const policy::LearnedPolicy model = policy::load_model(path);
  RolloutOptions options;
  options.history = 0;
  const RolloutSummary expected = evaluate(model, all, CollisionChecker(), 5, options);
  INFO("invalid " << expected.invalid << " of " << expected.trials << ", first: scene "
                  << expected.first_invalid_scene);
  REQUIRE(expected.invalid > 0);
  REQUIRE(expected.invalid < expected.trials);

  const std::vector<std::string> eval = {HANDCENTRIC_CLI, "eval",     "--model", path,     "--dist",
                                         "train",         "--trials", "12",      "--seed", "5"};
  std::vector<std::string> json_eval = eval;
  json_eval.push_back("--json");
  const test::ChildRun run = test::run_program(json_eval);
  INFO("stdout: " << run.out << "stderr: " << run.err);
  REQUIRE(run.exit_code == 0);
  const nlohmann::json out = nlohmann::json::parse(run.out);
  CHECK(out.at("invalid").get<int>() == expected.invalid);
  CHECK(out.at("trials").get<int>() == 12);
  CHECK(out.at("success").get<double>() * 12 + out.at("collision").get<double>() * 12 +
            out.at("timeout").get<double>() * 12 + expected.invalid ==
        Approx(12));
  // one warning line naming the first such scene
  CHECK(std::count(run.err.begin(), run.err.end(), '\n') == 1);
  CHECK_THAT(run.err,
             Contains("handcentric: warning: " + std::to_string(expected.invalid) +
                      " of 12 trials invalid") &&
                 Contains("scene " + std::to_string(expected.first_invalid_scene) + ", ") &&
                 Contains("flow/hand_centric") && Contains("--strict"));

  std::vector<std::string> strict = eval;
  strict.push_back("--strict");
  const test::ChildRun stopped = test::run_program(strict);
  INFO("strict stdout: " << stopped.out << "stderr: " << stopped.err);
  CHECK(stopped.exit_code == 1);
  CHECK(stopped.out.empty());
  CHECK(std::count(stopped.err.begin(), stopped.err.end(), '\n') == 1);
  CHECK_THAT(stopped.err, Contains("handcentric: error: scene " +
                                   std::to_string(expected.first_invalid_scene) + ": ") &&
                              Contains("non-finite"));
  std::filesystem::remove(path);
}
