// A policy plug-in that speaks its own interface (props/transport/policy_interface.hpp): pose
// layouts, named outputs, two hands and episodes, end to end through `handcentric audit
// --policy-exec` and tests/props/plugins/policy_as_shipped.py, and the hello's and answers'
// refusals through the protocol itself. Mutants each test was seen failing on are named above it.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/props/transport/plugin_protocol.hpp"
#include "run_command.hpp"

using namespace handcentric;
using Catch::Matchers::Contains;

namespace {

std::string shipped_audit(const std::string& arguments, const std::string& flags) {
  return test::cli() + " audit --policy-exec '" +
         test::test_plugin("policy_as_shipped.py", arguments) + "' " + flags;
}

// verdicts[output][mode] under `group` in the eye-in-hand view, from the JSON of an audit.
std::map<std::string, std::map<std::string, bool>> verdicts_by_output(const std::string& json,
                                                                      const std::string& group) {
  std::map<std::string, std::map<std::string, bool>> out;
  const auto parsed = nlohmann::json::parse(json);
  for (const auto& policy : parsed.at("policies")) {
    for (const auto& check : policy.at("checks")) {
      if (check.at("group") != group || check.at("view") != "eye_in_hand") continue;
      CHECK(check.at("output") == policy.at("output"));
      out[check.at("output")][check.at("mode")] = check.at("equivariant");
    }
  }
  return out;
}

}  // namespace

// Mutants: the result's output left unset (no "output" in the JSON); PipePolicy::chunks always
// taking the first output (the gripper audited as the hand).
TEST_CASE("a_shipped_policy_is_audited_in_its_own_layouts_output_by_output", "[unit]") {
  const std::string flags = "--cases 25 --group translation --view eye_in_hand --json";
  const auto held = test::run_command(shipped_audit("", flags));
  REQUIRE(held.exit_code == 0);
  const auto parsed = nlohmann::json::parse(held.out);
  REQUIRE(parsed.at("policies").size() == 2);
  CHECK(parsed.at("policies").at(0).at("output") == "hand");  // the hello's order
  CHECK(parsed.at("policies").at(1).at("kind") == "invariant");
  const auto& interface = parsed.at("policies").at(0).at("interface");
  CHECK(interface.at("state_format") == "pos_quat_xyzw");
  CHECK(interface.at("action_format") == "pos_quat_xyzw");
  CHECK(interface.at("outputs").at("gripper") == "invariant");
  const auto all = verdicts_by_output(held.out, "translation");
  CHECK(all.at("hand").at("pointwise"));
  CHECK(all.at("gripper").at("pointwise"));
  // The planted fault: a gripper width that reads the hand's world height.
  const auto fault = test::run_command(shipped_audit("gripper_height", flags));
  REQUIRE(fault.exit_code == 0);
  const auto broken = verdicts_by_output(fault.out, "translation");
  CHECK(broken.at("hand").at("pointwise"));
  CHECK_FALSE(broken.at("gripper").at("pointwise"));
  const auto text = test::run_command(shipped_audit("", "--cases 25 --group translation"));
  CHECK_THAT(text.out, Contains("the plug-in's hello declares state_format pos_quat_xyzw") &&
                           Contains("output 'gripper' (invariant)"));
}

// Mutant: PipePolicy::chunks always taking the first output (the right hand audited as the
// left: its fault unseen). (The right hand's history sent as the left's is caught below, by
// a_request_under_an_interface_speaks_the_policy_layouts: this policy's fault shows either way.)
TEST_CASE("two_hands_are_audited_per_hand_and_a_witness_names_the_hand", "[unit]") {
  const std::string flags = "--cases 25 --group translation --view eye_in_hand --json";
  const auto held = test::run_command(shipped_audit("--hands", flags));
  REQUIRE(held.exit_code == 0);
  const auto all = verdicts_by_output(held.out, "translation");
  REQUIRE(all.size() == 3);
  for (const char* output : {"left", "right", "gripper"}) CHECK(all.at(output).at("pointwise"));
  const auto fault = test::run_command(shipped_audit("--hands right_world_x", flags));
  REQUIRE(fault.exit_code == 0);
  const auto broken = verdicts_by_output(fault.out, "translation");
  CHECK(broken.at("left").at("pointwise"));
  CHECK_FALSE(broken.at("right").at("pointwise"));
  const auto fault_json = nlohmann::json::parse(fault.out);  // not a temporary: a range-for
  for (const auto& policy : fault_json.at("policies")) {     // over its member would dangle
    if (policy.at("output") != "right") continue;
    const auto& witness = policy.at("checks").at(0).at("witness");
    REQUIRE(witness.is_object());
    CHECK(witness.at("scene").at("extra_poses").contains("hand:right"));
  }
  CHECK(broken.at("gripper").at("pointwise"));  // the left hand's plan's
  // Batched (the histories stacked per hand), the same verdicts.
  const auto batched = test::run_command(shipped_audit("--hands --batched", flags));
  REQUIRE(batched.exit_code == 0);
  CHECK(verdicts_by_output(batched.out, "translation") == all);
}

// Mutant: PipePolicy::start_episode not called by the closed loop (no "episode" in the
// requests: the plug-in resets before each, and the world-memory fault never shows).
TEST_CASE("a_stateful_plugin_is_audited_in_closed_loop_over_episodes", "[unit]") {
  const std::string flags =
      "--cases 30 --group translation --view eye_in_hand --episodes 3 --episode-length 4 --json";
  const auto held = test::run_command(shipped_audit("--stateful", flags));
  REQUIRE(held.exit_code == 0);
  const auto all = verdicts_by_output(held.out, "translation");
  CHECK(all.at("hand").at("closed_loop"));
  CHECK(all.at("gripper").at("closed_loop"));
  const auto fault = test::run_command(shipped_audit("--stateful world_memory", flags));
  REQUIRE(fault.exit_code == 0);
  const auto broken = verdicts_by_output(fault.out, "translation");
  CHECK(broken.at("hand").at("pointwise"));  // every single call, after its reset, holds
  CHECK_FALSE(broken.at("hand").at("closed_loop"));
  bool executed_note = false;
  const auto fault_json = nlohmann::json::parse(fault.out);
  for (const auto& policy : fault_json.at("policies"))
    for (const auto& check : policy.at("checks"))
      if (check.contains("note") && check.at("note").get<std::string>().find(
                                        "hand executed, gripper compared") != std::string::npos)
        executed_note = true;
  CHECK(executed_note);
  // The same audit as a page (--page): a grid per output with its closed-loop row, each NO
  // linked to its witness and picture (mutant: write_audit_page not called -> no index.html).
  const std::string page = std::filesystem::temp_directory_path() / "hc_audit_page";
  std::filesystem::remove_all(page);
  const auto paged = test::run_command(
      shipped_audit("--stateful world_memory",
                    "--cases 30 --group translation --view eye_in_hand --episodes 3 "
                    "--episode-length 4 --page " +
                        page));
  REQUIRE(paged.exit_code == 0);
  std::ifstream in(page + "/index.html");
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK_THAT(html, Contains("output &#39;gripper&#39; (invariant)") &&
                       Contains("policy (closed loop)") &&
                       Contains("hand executed, gripper "
                                "compared"));
  CHECK(std::filesystem::exists(page + "/index.md"));
  CHECK(std::distance(std::filesystem::directory_iterator(page + "/witness"),
                      std::filesystem::directory_iterator{}) == 2);
  std::filesystem::remove_all(page);
  const auto without = test::run_command(
      test::cli() + " audit --episodes 2 --repr hand_centric --group se3 --cases 5");
  CHECK(without.exit_code != 0);
  CHECK_THAT(without.err, Contains("--episodes"));
}

// Recorded episodes (an 'episode' index in --observations) are the closed loop's episodes over
// the pipe too, replayed as recorded (mutant: AuditOptions::closed_loop not set by --episodes
// -> the data refused).
TEST_CASE("recorded_episodes_are_replayed_over_the_pipe", "[unit]") {
  const std::string path = std::filesystem::temp_directory_path() / "hc_recorded_episodes.jsonl";
  {
    std::ofstream out(path);
    for (int e = 0; e < 2; ++e) {
      for (int t = 0; t < 4; ++t) {
        const double x = 0.1 * t + 0.3 * e, y = 0.05 * t;
        out << "{\"history\": [[[1,0,0," << x << "],[0,1,0," << y << "],[0,0,1,0.2],[0,0,0,1]]], "
            << "\"hand_points\": [[0.1, 0.0, 0.2]], \"episode\": " << e << "}\n";
      }
    }
  }
  const std::string flags = "--cases 10 --group translation --view eye_in_hand --observations " +
                            path + " --episodes 2 --json";
  const auto held = test::run_command(shipped_audit("--stateful", flags));
  REQUIRE(held.exit_code == 0);
  CHECK(verdicts_by_output(held.out, "translation").at("hand").at("closed_loop"));
  const auto fault = test::run_command(shipped_audit("--stateful world_memory", flags));
  REQUIRE(fault.exit_code == 0);
  CHECK_FALSE(verdicts_by_output(fault.out, "translation").at("hand").at("closed_loop"));
  const auto length = test::run_command(shipped_audit("--stateful", flags + " --episode-length 3"));
  CHECK(length.exit_code != 0);
  CHECK_THAT(length.err, Contains("replayed as long as recorded"));
  const auto single = test::run_command(shipped_audit(
      "--stateful", "--cases 10 --group translation --view eye_in_hand --observations " + path));
  CHECK(single.exit_code != 0);
  CHECK_THAT(single.err, Contains("--episodes N"));
  std::filesystem::remove(path);
}

TEST_CASE("a_layout_the_numbers_contradict_is_an_error_naming_the_pose", "[unit]") {
  const std::string flags = "--cases 10 --group translation --view eye_in_hand";
  const auto bad = test::run_command(shipped_audit("bad_quat", flags));
  CHECK(bad.exit_code != 0);
  CHECK_THAT(bad.err, Contains("\"outputs\"[\"hand\"][0]") && Contains("norm 1.5") &&
                          Contains("pos_quat_xyzw"));
  // Mutant: the lengths of invariant outputs not checked (their poses compared instead: NO).
  const auto length = test::run_command(shipped_audit("gripper_length", flags));
  CHECK(length.exit_code != 0);
  CHECK_THAT(length.err, Contains("output \"gripper\" 3 numbers after 4"));
  const auto undeclared = test::run_command(shipped_audit("undeclared", flags));
  CHECK(undeclared.exit_code != 0);
  CHECK_THAT(undeclared.err, Contains("action_format="));
}

// The hello's fields, each refused with the field and the fix (mutant: read_interface's rng
// check removed -> the unknown rng passes).
TEST_CASE("a_hello_with_a_bad_interface_field_is_refused_naming_it", "[unit]") {
  const auto hello = [](const std::string& fields) {
    return "{\"id\": 0, \"hello\": {\"protocol\": 2, " + fields + "}}";
  };
  const auto refused = [&](const std::string& fields, const std::string& says) {
    CHECK_THROWS_WITH(props::parse_reply(hello(fields), 0, props::RequestKind::policy, "p", true),
                      Contains(says));
  };
  refused("\"action_format\": \"pos_quat\"", "action_format");
  refused("\"state_format\": 7", "\"state_format\" is 7");
  refused("\"outputs\": {\"hand\": \"position\"}", "\"pose\" (a chunk");
  refused("\"outputs\": {\"gripper\": \"invariant\"}", "names no \"pose\" output");
  refused("\"hands\": [\"left\"]", "two or more distinct names");
  refused("\"hands\": [\"left\", \"left\"]", "two or more distinct names");
  refused("\"hands\": [\"left\", \"right\"], \"outputs\": {\"right\": \"invariant\"}", "is a hand");
  refused("\"rng\": \"cuda\"", "\"torch\", \"numpy\" or \"generator\"");
  refused("\"episodes\": 1", "not true or false");
  const props::PluginReply ok = props::parse_reply(
      hello("\"hands\": [\"left\", \"right\"], \"outputs\": {\"gripper\": \"invariant\", "
            "\"base\": \"pose\"}, \"rng\": \"torch\", \"episodes\": true"),
      0, props::RequestKind::policy, "p", true);
  const props::PolicyInterface& interface = ok.hello->policy;
  REQUIRE(interface.outputs.size() == 4);  // the hands first, then the hello's order
  CHECK(interface.outputs[0].name == "left");
  CHECK(interface.outputs[1].name == "right");
  CHECK(interface.outputs[2].name == "gripper");
  CHECK(interface.outputs[3].name == "base");
  CHECK(interface.rng == "torch");
  CHECK(interface.episodes);
}

// Mutant: the other hands' histories sent as the first hand's (other_hand_history bypassed).
// What a request under an interface carries: the history per hand in the state layout, no
// hand among the extra poses, the episode step.
TEST_CASE("a_request_under_an_interface_speaks_the_policy_layouts", "[unit]") {
  props::PolicyInterface interface;
  interface.state_format = parse_pose_format("pos_quat_wxyz", "state_format");
  interface.hands = {"left", "right"};
  interface.outputs = props::outputs_with_hands(interface.hands, {}, "outputs");
  Scene scene;
  scene.world_T_hand_history = {RigidTransform::from_translation(Eigen::Vector3d(1, 2, 3)),
                                RigidTransform::identity()};
  scene.extra_poses = {{"hand:right", RigidTransform::from_translation(Eigen::Vector3d(0, 1, 0))},
                       {"mug", RigidTransform::identity()}};
  const props::EpisodeStep step{3, 2};
  const std::string body = props::policy_request_body(
      scene, Eigen::VectorXd::Zero(2), props::NumberEncoding::text, &interface, &step);
  const auto request = nlohmann::json::parse("{" + body + "}");
  const auto& right = request.at("history").at("right");
  REQUIRE(right.size() == 2);
  // S_k = S_0 T_0^-1 T_k: right now at (0, 1, 0), before at (0, 1, 0) - (1, 2, 3).
  CHECK(right.at(0) == nlohmann::json({0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0}));
  CHECK(right.at(1) == nlohmann::json({-1.0, -1.0, -3.0, 1.0, 0.0, 0.0, 0.0}));
  CHECK(request.at("history").at("left").at(0).size() == 7);
  CHECK_FALSE(request.at("extra_poses").contains("hand:right"));
  CHECK(request.at("extra_poses").at("mug").size() == 7);
  CHECK(request.at("episode") == nlohmann::json({{"index", 3}, {"step", 2}}));
}
