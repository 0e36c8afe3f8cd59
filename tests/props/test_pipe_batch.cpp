// Batched requests over the --exec pipe (docs/AUDIT.md, "--exec", batched requests): a plug-in
// whose hello declares "batch" is audited in batches with the same JSON as one scene at a time,
// and a wrong batched answer is a PluginError naming the plug-in, the request, the item and the
// fix.
#include <catch2/catch.hpp>
#include <chrono>
#include <memory>
#include <random>

#include "handcentric/core/sampling.hpp"
#include "handcentric/props/pipe_policy.hpp"
#include "handcentric/props/pipe_representation.hpp"
#include "run_command.hpp"

using namespace handcentric;
using Catch::Matchers::Contains;

namespace {

// `count` scenes of one shape (H = 1, K = 3, 2 eye-in-hand points).
std::vector<Scene> scenes_of_one_shape(int count) {
  std::vector<Scene> out;
  for (int i = 0; i < count; ++i) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(i + 1));
    out.push_back(random_scene(rng, 1, 3, 2, 0, 10.0));
  }
  return out;
}

std::vector<const Scene*> pointers(const std::vector<Scene>& scenes) {
  std::vector<const Scene*> out;
  for (const Scene& s : scenes) out.push_back(&s);
  return out;
}

// The PluginError of asking the batching test plug-in in `mode` for 3 scenes' actions at once
// (empty if none).
std::string batch_error(const std::string& mode, double timeout = 5.0, int count = 3) {
  try {
    const props::PipeRepresentation plugin(test::test_plugin("batched_raw.py", mode), timeout);
    const std::vector<Scene> scenes = scenes_of_one_shape(count);
    const auto actions = plugin.encode_actions_batch(pointers(scenes));
    if (actions.size() != scenes.size()) return "wrong count";
  } catch (const props::PluginError& e) {
    return e.what();
  }
  return "";
}

std::string policy_batch_error(const std::string& mode) {
  try {
    const props::PipePolicy plugin(test::test_plugin("batched_raw.py", mode + " policy"), 5.0);
    const std::vector<Scene> scenes = scenes_of_one_shape(3);
    const Eigen::VectorXd noise = Eigen::VectorXd::Zero(plugin.noise_dimension());
    plugin.act_batch(pointers(scenes), {&noise, &noise, &noise});
  } catch (const props::PluginError& e) {
    return e.what();
  }
  return "";
}

// `handcentric audit ARGS --json` with the batched plug-in's command written as the unbatched
// one's (the command is the report's name; everything else must be the same byte for byte).
std::string audit_json(const std::string& args, const std::string& batched_suffix = "") {
  const auto result = test::run_command(test::cli() + " audit " + args + " --json");
  INFO(result.err);
  REQUIRE(result.exit_code == 0);
  std::string out = result.out;
  if (!batched_suffix.empty()) {
    const std::size_t at = out.find(batched_suffix);
    REQUIRE(at != std::string::npos);
    out.erase(at, batched_suffix.size());
  }
  return out;
}

}  // namespace

TEST_CASE("a_batched_exec_audit_gives_the_unbatched_json_byte_for_byte", "[unit]") {
  const std::string example = test::python_example();
  const std::string options = " --cases 60 --seed 5";
  const std::string one_at_a_time = audit_json("--exec '" + example + "'" + options);
  CHECK(audit_json("--exec '" + example + " --batched'" + options, " --batched") == one_at_a_time);
  // Fewer requests: the example answers up to 256 scenes per line.
  const props::PipeRepresentation plugin(example + " --batched", 10.0);
  CHECK(plugin.batch_size() == 256);
  const std::vector<Scene> scenes = scenes_of_one_shape(40);
  const auto batched = plugin.encode_actions_batch(pointers(scenes));
  const auto observed = plugin.encode_observation_batch(pointers(scenes));
  CHECK(plugin.requests_sent() == 3);  // the probe, its answer after the hello, one batch
  const props::PipeRepresentation single(example, 10.0);
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    CHECK(batched[i] == single.encode_actions(scenes[i]));  // the same bits
    CHECK(observed[i] == single.encode_observation(scenes[i]));
  }
}

TEST_CASE("a_batched_policy_exec_audit_gives_the_unbatched_json_and_sees_a_batch_bias", "[unit]") {
  const std::string policy = test::test_plugin("policy_hand_centric.py");
  const std::string options = " --cases 30 --view eye_in_hand --seed 2";
  const std::string one_at_a_time = audit_json("--policy-exec '" + policy + "'" + options);
  CHECK(audit_json("--policy-exec '" + policy + " --batched'" + options, " --batched") ==
        one_at_a_time);
  // The planted fault: an answer that depends on its row in the batch changes the JSON.
  CHECK(audit_json("--policy-exec '" + policy + " --batched row_bias'" + options,
                   " --batched row_bias") != one_at_a_time);
}

TEST_CASE("a_wrong_batched_answer_is_a_plugin_error_naming_request_item_and_fix", "[unit]") {
  CHECK(batch_error("right").empty());  // the same plug-in answering right: no error
  const std::string plugin = "plug-in '" + test::test_plugin("batched_raw.py", "short") + "'";
  // Request 0 is the probe (answered by the hello), 1 the probe again, 2 the batch.
  CHECK_THAT(batch_error("short"),
             Contains(plugin + " answered batched request 2 with 2 answers for 3 scenes") &&
                 Contains("with one answer per scene"));
  CHECK_THAT(batch_error("item_shape"),
             Contains("batched request 2 (item 1 of 3) without \"actions\""));
  CHECK_THAT(batch_error("unbatched"), Contains("without a \"batch\" list"));
  CHECK(policy_batch_error("right").empty());
  CHECK_THAT(policy_batch_error("short"),
             Contains("batched request 2 with 2 answers for 3 scenes"));
  CHECK_THAT(policy_batch_error("item_shape"),
             Contains("batched request 2 (item 1 of 3), a policy request, without a \"chunk\""));
  // Through the CLI: the audit stops with the message.
  for (const char* flag : {"--exec", "--policy-exec"}) {
    const std::string kind = std::string(flag) == "--exec" ? "short" : "short policy";
    const auto result = test::run_command(test::cli() + " audit " + flag + " '" +
                                          test::test_plugin("batched_raw.py", kind) +
                                          "' --cases 5 --view eye_in_hand");
    CHECK(result.exit_code != 0);
    CHECK_THAT(result.err, Contains("answers for") && Contains("one answer per scene"));
  }
}

TEST_CASE("a_batch_has_as_many_timeouts_as_scenes", "[unit]") {
  // 0.06 s per scene, 0.2 s per answer: a batch of 4 scenes (0.24 s) is within 0.8 s; a single
  // timeout for the whole batch (the planted fault) would have fired.
  const auto start = std::chrono::steady_clock::now();
  CHECK(batch_error("slow", 0.2, 4).empty());
  CHECK_THAT(batch_error("slow", 0.04, 4), Contains("no answer to request 2 within 0.16 s") &&
                                               Contains("0.04 s per scene, 4 scenes"));
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(10));
}
