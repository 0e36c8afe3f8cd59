// Batched requests over the --exec pipe (docs/AUDIT.md, "--exec", batched requests): a plug-in
// whose hello declares "batch" is audited in batches with the same JSON as one scene at a time,
// and a wrong batched answer is a PluginError naming the plug-in, the request, the item and the
// fix. The same for the base64 encoding of batched lines ("Encoded numbers").
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>

#include "handcentric/core/sampling.hpp"
#include "handcentric/props/transport/pipe_policy.hpp"
#include "handcentric/props/transport/pipe_representation.hpp"
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

// `before` + `body` + `after`, appended piece by piece (GCC 12 at -O3 reports a false overflow for
// a chain of operator+ on literals, as run_command.hpp says).
std::string wrapped(const char* before, const std::string& body, const char* after) {
  std::string out = before;
  out += body;
  out += after;
  return out;
}

}  // namespace

TEST_CASE("a_batched_exec_audit_gives_the_unbatched_json_byte_for_byte", "[unit]") {
  const std::string example = test::python_example();
  const std::string options = " --cases 60 --seed 5";
  const std::string one_at_a_time = audit_json("--exec '" + example + "'" + options);
  // Batched with base64 (the example's default) and with the numbers as JSON text.
  CHECK(audit_json("--exec '" + example + " --batched'" + options, " --batched") == one_at_a_time);
  CHECK(audit_json("--exec '" + example + " --batched --text'" + options, " --batched --text") ==
        one_at_a_time);
  // The planted fault: a wire that rounds the answers to float32 changes the JSON.
  const std::string float32_wire = test::test_plugin("float32_wire.py");
  std::string lossy = audit_json("--exec '" + float32_wire + "'" + options);
  lossy.replace(lossy.find(float32_wire), float32_wire.size(), example);
  CHECK(lossy != one_at_a_time);
  // Fewer requests: the example answers up to 256 scenes per line.
  const props::PipeRepresentation plugin(example + " --batched", 10.0);
  CHECK(plugin.batch_size() == 256);
  const std::vector<Scene> scenes = scenes_of_one_shape(40);
  const auto batched = plugin.encode_actions_batch(pointers(scenes));
  const auto observed = plugin.encode_observation_batch(pointers(scenes));
  CHECK(plugin.requests_sent() == 3);  // the probe, its answer after the hello, one batch
  CHECK(plugin.capabilities().encoding == props::NumberEncoding::base64);
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
  CHECK(audit_json("--policy-exec '" + policy + " --batched text'" + options, " --batched text") ==
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
  // 0.5 s per scene, 1 s per answer: a batch of 4 scenes (2 s) is within 4 s; a single timeout
  // for the whole batch (the planted fault) would have fired. At 0.4 s per answer the batch is
  // late (1.6 s); the plug-in's start, within the first answer's 0.4 s, leaves a loaded machine
  // room (0.04 s did not).
  const auto start = std::chrono::steady_clock::now();
  CHECK(batch_error("slow", 1.0, 4).empty());
  CHECK_THAT(batch_error("slow", 0.4, 4), Contains("no answer to request 2 within 1.6 s") &&
                                              Contains("0.4 s per scene, 4 scenes"));
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(10));
}

TEST_CASE("encoded_numbers_read_back_bit_for_bit_and_text_lines_keep_their_form", "[unit]") {
  // The encoder's output fed to the reply parser: every bit back, signed zero, subnormals and
  // the extremes included.
  const double tiny = std::numeric_limits<double>::denorm_min();
  Eigen::VectorXd noise(9);
  noise << 0.1, -0.0, tiny, -tiny, std::numeric_limits<double>::max(),
      std::numeric_limits<double>::min(), M_PI, -1.0 / 3.0, std::nextafter(1.0, 2.0);
  const Scene scene = scenes_of_one_shape(1).front();
  const std::string body = props::policy_request_body(scene, noise, props::NumberEncoding::base64);
  const auto request = nlohmann::json::parse(wrapped("{", body, "}"));
  CHECK(request["history"]["shape"] == nlohmann::json::array({2, 4, 4}));
  CHECK(request["hand_points"]["shape"] == nlohmann::json::array({2, 3}));
  CHECK(request["world_points"] ==
        nlohmann::json::parse(R"({"dtype": "float64", "shape": [0, 3], "data": ""})"));
  const std::string reply =
      wrapped(R"({"id": 4, "batch": [{"actions": )", request["noise"].dump(), "}]}");
  const auto replies = props::parse_batch_reply(reply, 4, props::RequestKind::encode, "p", 1);
  REQUIRE(replies.front().actions.size() == noise.size());
  CHECK(std::memcmp(replies.front().actions.data(), noise.data(), sizeof(double) * 9) == 0);
  // The planted fault: one number a bit off is told apart.
  Eigen::VectorXd off = noise;
  off(0) = std::nextafter(off(0), 1.0);
  const auto encoded_off = nlohmann::json::parse(
      wrapped("{", props::policy_request_body(scene, off, props::NumberEncoding::base64), "}"));
  CHECK(encoded_off["noise"] != request["noise"]);
  // Text bodies and lines are as they were: JSON numbers, no "encoding".
  const std::string text = props::policy_request_body(scene, noise);
  CHECK(text.find("dtype") == std::string::npos);
  CHECK(props::batch_request_body({text}) == wrapped("\"batch\": [{", text, "}]"));
  CHECK(props::batch_request_body({body}, props::NumberEncoding::base64) ==
        wrapped("\"encoding\": \"base64\", \"batch\": [{", body, "}]"));
}

TEST_CASE("a_wrong_encoded_answer_is_a_plugin_error_naming_item_field_and_fix", "[unit]") {
  CHECK(batch_error("b64_right").empty());  // encoded lines out, encoded answers read back
  CHECK(policy_batch_error("b64_right").empty());
  // The second item of each batch is spoiled (request 2 is the first batch of 3 scenes).
  const std::string item = "batched request 2 (item 1 of 3) with \"actions\"";
  CHECK_THAT(batch_error("b64_base64"), Contains(item + " whose \"data\" is not base64: '!' at "
                                                        "character 4") &&
                                            Contains("standard base64"));
  CHECK_THAT(batch_error("b64_length"),
             Contains(item + " of shape [6] and dtype float64, which needs 48 bytes, but "
                             "\"data\" holding 40") &&
                 Contains("send every element"));
  CHECK_THAT(batch_error("b64_dtype"), Contains(item + " of dtype float32; the protocol's numbers "
                                                       "are float64") &&
                                           Contains("astype('<f8')"));
  CHECK_THAT(batch_error("b64_unknown"), Contains(item + " of dtype \"float16\"") &&
                                             Contains("\"float64\", \"float32\" or \"uint8\""));
  CHECK_THAT(batch_error("b64_nan"),
             Contains("batched request 2 (item 1 of 3) with a non-finite \"actions\"[2] = nan") &&
                 Contains("send finite numbers only"));
  CHECK_THAT(batch_error("b64_shape"),
             Contains(item + " of shape [2, 3]; \"actions\" has shape [n]"));
  CHECK_THAT(policy_batch_error("b64_shape"),
             Contains("(item 1 of 3) with \"chunk\" of shape [1, 16]; \"chunk\" has shape "
                      "[K, 4, 4]"));
  CHECK_THAT(policy_batch_error("b64_nan"), Contains("non-finite \"chunk\"[2] = nan"));
  // An old plug-in (no "encodings") gets text lines: batched_raw.py exits on an encoded one.
  CHECK(batch_error("right").empty());
}
