// `handcentric audit --policy-exec CMD --locate`: a plug-in that declares the stages of its
// pipeline in its hello (props/transport/policy_interface.hpp, "stages"), located stage by stage
// through tests/props/plugins/policy_stages.py, and the hello's and answers' refusals through
// the protocol itself. The mutant each test was seen failing on is named above it.
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/props/transport/plugin_protocol.hpp"
#include "run_command.hpp"

using namespace handcentric;
using Catch::Matchers::Contains;

namespace {

std::string staged_locate(const std::string& arguments, const std::string& flags) {
  return test::cli() + " audit --policy-exec '" + test::test_plugin("policy_stages.py", arguments) +
         "' --locate " + flags;
}

// The one location of a --json run under one group and view.
nlohmann::json located_once(const std::string& arguments, const std::string& group) {
  const auto run = test::run_command(
      staged_locate(arguments, "--group " + group + " --view eye_in_hand --cases 30 --json"));
  REQUIRE(run.exit_code == 0);
  const auto parsed = nlohmann::json::parse(run.out);
  REQUIRE(parsed.at("locate").size() == 1);
  return parsed.at("locate").at(0);
}

std::vector<std::string> stage_names(const nlohmann::json& location) {
  std::vector<std::string> out;
  for (const auto& row : location.at("stages")) out.push_back(row.at("name"));
  return out;
}

bool stage_breaks(const nlohmann::json& location, const std::string& name) {
  for (const auto& row : location.at("stages"))
    if (row.at("name") == name) return row.at("breaks").get<bool>();
  FAIL("no stage " << name);
  return false;
}

}  // namespace

// Mutants: every stage taken as "features" in plugin_locate.cpp's watched_stages (the decoder's
// world poses then break invariance: a break where there is none); the interface's "stages" left
// out of audit_json.cpp.
TEST_CASE("a_hand_centric_pipeline_breaks_at_no_stage", "[unit]") {
  const auto r = located_once("", "se3");
  CHECK(r.at("watched") == "stages");
  CHECK(stage_names(r) ==
        std::vector<std::string>{"to_hand", "normalize", "network", "decode", "unnormalize"});
  CHECK(r.at("stages").at(3).at("kind") == "poses");
  CHECK(r.at("stages").at(3).at("verdict") == "equivariant");
  CHECK(r.at("stages").at(0).at("verdict") == "invariant");
  for (const auto& row : r.at("stages")) CHECK_FALSE(row.at("breaks").get<bool>());
  CHECK(r.at("first_break").is_null());
  CHECK(r.at("chunk").at("equivariant").get<bool>());
  // The audit itself asks no stages, and its JSON lists the declared ones.
  const auto audit = test::run_command(test::cli() + " audit --policy-exec '" +
                                       test::test_plugin("policy_stages.py") +
                                       "' --group se3 --view eye_in_hand --cases 20 --json");
  REQUIRE(audit.exit_code == 0);
  const auto policy = nlohmann::json::parse(audit.out).at("policies").at(0);
  CHECK(policy.at("interface").at("stages").at(3) ==
        nlohmann::json({{"name", "decode"}, {"kind", "poses"}}));
  CHECK(policy.at("checks").at(0).at("equivariant").get<bool>());
}

// Mutants: read_named (policy_wire.cpp) reading the stages in their sorted order, as
// nlohmann::json keeps an answer's object, instead of the hello's (each row then holds another
// stage's values: the shapes and the decoder's break); watched_stages skipping the first stage
// (the first break reported at 'decode').
TEST_CASE("a_normalizer_fit_in_world_coordinates_breaks_at_normalize", "[unit]") {
  const auto r = located_once("world_normalizer", "translation");
  CHECK(stage_names(r) ==
        std::vector<std::string>{"normalize", "to_hand", "network", "decode", "unnormalize"});
  CHECK(r.at("first_break") == "normalize");
  CHECK(r.at("witness").at("name") == "normalize");
  CHECK(r.at("stages").at(0).at("kind") == "poses");
  CHECK(r.at("stages").at(0).at("case") == 1);
  CHECK(r.at("stages").at(2).at("shape") == nlohmann::json({18, 1}));  // network: 3 poses of 6
  CHECK(r.at("stages").at(3).at("shape") == nlohmann::json({16, 3}));  // decode: 3 poses
  CHECK_FALSE(stage_breaks(r, "to_hand"));  // a per-axis scale commutes with translations
  CHECK(stage_breaks(r, "decode"));         // downstream of the break
  CHECK_FALSE(r.at("chunk").at("equivariant").get<bool>());
  // Batched requests, the same table bit for bit.
  auto batched = located_once("world_normalizer --batched", "translation");
  batched["policy"] = r.at("policy");
  CHECK(batched == r);
}

// Mutant: locate_text's column header and summary kept as a model's "layer" (the table of a
// plug-in's stages then says "layer").
TEST_CASE("an_unnormalizer_adding_the_world_mean_breaks_at_unnormalize_under_rotation", "[unit]") {
  const auto moved = located_once("world_unnormalizer", "translation");
  CHECK(moved.at("first_break").is_null());  // adding a world offset commutes with translations
  const auto r = located_once("world_unnormalizer", "se3");
  CHECK(r.at("first_break") == "unnormalize");
  CHECK_FALSE(stage_breaks(r, "decode"));
  CHECK_FALSE(r.at("chunk").at("equivariant").get<bool>());
  const auto text = test::run_command(
      staged_locate("world_unnormalizer", "--group se3 --view eye_in_hand --cases 30"));
  REQUIRE(text.exit_code == 0);
  CHECK_THAT(text.out, Contains("first break at 'unnormalize'") && Contains("   stage ") &&
                           Contains(">> unnormalize[0]  poses     neither") &&
                           Contains("   decode[0]       poses     equivariant") &&
                           Contains("the policy's chunk: NOT equivariant"));
}

// Mutant: locate_plugin taking the answer's first output as the chunk (the gripper's widths,
// invariant, passed as poses at T_0: an equivariant "chunk" beside the broken hand).
TEST_CASE("a_plugin_with_named_outputs_has_its_first_pose_output_decided_as_its_chunk", "[unit]") {
  const auto r = located_once("world_unnormalizer --outputs --batched", "se3");
  CHECK(r.at("first_break") == "unnormalize");
  CHECK_FALSE(r.at("chunk").at("equivariant").get<bool>());
  CHECK(located_once("--outputs", "se3").at("chunk").at("equivariant").get<bool>());
}

TEST_CASE("locate_on_a_plugin_that_declares_no_stages_is_a_one_line_error", "[unit]") {
  const auto run = test::run_command(test::cli() + " audit --policy-exec '" +
                                     test::test_plugin("policy_hand_centric.py") +
                                     "' --locate --group se3 --cases 5");
  CHECK(run.exit_code == 1);
  CHECK_THAT(run.err, Contains("declares no \"stages\"") && Contains("stages=[("));
  CHECK(std::count(run.err.begin(), run.err.end(), '\n') == 1);
  const auto looped = test::run_command(staged_locate("", "--episodes 2 --cases 5"));
  CHECK(looped.exit_code == 1);
  CHECK_THAT(looped.err, Contains("--locate cannot honour --episodes"));
}

// Mutant: read_stages' repeated-name check removed (the second "a" passes).
TEST_CASE("a_hello_with_bad_stages_is_refused_naming_the_value_and_the_fix", "[unit]") {
  const auto refused = [](const std::string& stages, const std::string& says) {
    const std::string hello =
        "{\"id\": 0, \"hello\": {\"protocol\": 2, \"stages\": " + stages + "}}";
    CHECK_THROWS_WITH(props::parse_reply(hello, 0, props::RequestKind::policy, "p", true),
                      Contains(says));
  };
  refused("[{\"name\": \"a\", \"kind\": \"pose\"}]",
          "\"stages\"[0] (\"a\") has kind \"pose\"; a stage is \"poses\"");
  refused("[{\"name\": \"a\", \"kind\": \"poses\"}, {\"name\": \"a\", \"kind\": \"features\"}]",
          "name \"a\" twice; give each stage a name of its own");
  refused("{\"a\": \"poses\"}", "declare the stages in execution order");
  refused("[{\"kind\": \"poses\"}]", "\"stages\"[0] is {\"kind\":\"poses\"}");
  const props::PluginReply ok = props::parse_reply(
      "{\"id\": 0, \"hello\": {\"stages\": [{\"name\": \"b\", \"kind\": \"features\"}, "
      "{\"name\": \"a\", \"kind\": \"poses\"}]}}",
      0, props::RequestKind::policy, "p", true);
  const auto& stages = ok.hello->policy.stages;
  REQUIRE(stages.size() == 2);
  CHECK(stages[0].name == "b");  // the hello's order
  CHECK(stages[1].kind == props::StageKind::poses);
  CHECK_THAT(props::describe(ok.hello->policy), Contains("stages b (features), a (poses)"));
}

// Mutant: read_staged_answer not reading the stages (a staged answer without them accepted).
TEST_CASE("a_staged_answer_missing_or_misshaping_a_stage_is_refused_naming_it", "[unit]") {
  props::PolicyInterface interface;
  interface.stages = {{"net", props::StageKind::features}, {"decode", props::StageKind::poses}};
  const std::string pose = "[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]";
  const auto answer = [&](const std::string& stages) {
    return "{\"id\": 3, \"chunk\": [" + pose + "]" + stages + "}";
  };
  const auto read = [&](const std::string& stages) {
    return props::parse_reply(answer(stages), 3, props::RequestKind::policy_stages, "p", false,
                              &interface);
  };
  const auto ok = read(", \"stages\": {\"decode\": [" + pose + "], \"net\": [[1, 2], [3]]}");
  REQUIRE(ok.stages.size() == 2);
  CHECK(ok.stages[0].numbers.size() == 3);  // net first, as declared
  CHECK(ok.stages[1].poses.size() == 1);
  CHECK_THROWS_WITH(
      read(""), Contains("without \"stages\": {name: value}") && Contains("\"net\", \"decode\""));
  CHECK_THROWS_WITH(read(", \"stages\": {\"net\": [1]}"),
                    Contains("without the stage \"decode\" its hello declares"));
  CHECK_THROWS_WITH(read(", \"stages\": {\"net\": [1], \"decode\": [[1, 2, 3, 4, 5]]}"),
                    Contains("\"stages\"[\"decode\"][0] of 5 numbers") && Contains("16"));
  CHECK_THROWS_WITH(read(", \"stages\": {\"net\": [], \"decode\": [" + pose + "]}"),
                    Contains("\"stages\"[\"net\"] holding no numbers"));
  CHECK_THROWS_WITH(read(", \"stages\": {\"net\": [1], \"decode\": [" + pose + "], \"x\": [1]}"),
                    Contains("a stage \"x\" its hello does not declare"));
  // A plain policy request is answered without them.
  CHECK(props::parse_reply(answer(""), 3, props::RequestKind::policy, "p", false, &interface)
            .chunk.size() == 1);
}
