// The --exec pipe: the Python example plug-in agrees with the built-in hand_centric, and every
// way a plug-in can misbehave gives a one-line PluginError, never a hang or a crash.
#include <catch2/catch.hpp>
#include <chrono>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>

#include "handcentric/core/representations.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/props/transport/pipe_representation.hpp"
#include "run_command.hpp"

using namespace handcentric;
using Catch::Matchers::Contains;

namespace {

Scene small_scene(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  return random_scene(rng, 1, 3, 2, 0, 10.0);
}

// The PluginError that asking `plugin` about a few scenes raises (empty if none).
std::string plugin_error(const std::string& command, double timeout = 5.0) {
  try {
    const props::PipeRepresentation plugin(command, timeout);
    for (std::uint64_t seed = 1; seed <= 4; ++seed) plugin.encode_actions(small_scene(seed));
  } catch (const props::PluginError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("python_example_plugin_encodes_like_the_builtin_hand_centric", "[unit]") {
  const props::PipeRepresentation plugin(test::python_example(), 10.0);
  const HandCentricRepresentation builtin;
  CHECK(plugin.provides_observation());
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    std::mt19937_64 rng(seed);
    const Scene scene =
        random_scene(rng, static_cast<int>(seed % 4), 1 + static_cast<int>(seed % 7), 2, 0, 1e3);
    const Eigen::VectorXd actions = plugin.encode_actions(scene);
    REQUIRE(actions.size() == builtin.encode_actions(scene).size());
    CHECK((actions - builtin.encode_actions(scene)).lpNorm<Eigen::Infinity>() < 1e-9);
    CHECK((plugin.encode_observation(scene) - builtin.encode_observation(scene))
              .lpNorm<Eigen::Infinity>() < 1e-9);
  }
  const int sent = plugin.requests_sent();
  plugin.encode_actions(small_scene(1));
  plugin.encode_actions(small_scene(1));  // the second time comes from the cache
  CHECK(plugin.requests_sent() <= sent + 1);
  CHECK_FALSE(plugin.can_decode());
  CHECK(plugin.capabilities().protocol == 1);  // no hello
  CHECK_THROWS_AS(plugin.decode_actions(Eigen::VectorXd::Zero(6), RigidTransform()),
                  InvalidArgument);
}

TEST_CASE("bad_plugins_give_errors_whose_first_line_says_what_happened", "[unit]") {
  const std::string not_found = plugin_error("handcentric_no_such_plugin_xyz --flag");
  CHECK_THAT(not_found,
             Contains("command not found") && Contains("handcentric_no_such_plugin_xyz"));
  CHECK_THAT(plugin_error("echo 'plug-in crashed' >&2; exit 3"),
             Contains("exited with status 3") && Contains("plug-in crashed"));
  CHECK_THAT(plugin_error(test::faulty_plugin("exit_early")),
             Contains("exited with status 3") && Contains("giving up on request 1"));
  CHECK_THAT(plugin_error(test::faulty_plugin("not_json")),
             Contains("not JSON") && Contains("actions: 1 2 3"));
  CHECK_THAT(plugin_error(test::faulty_plugin("wrong_id")), Contains("request 0 with id 1"));
  CHECK_THAT(plugin_error(test::faulty_plugin("nan")), Contains("NaN"));
  CHECK_THAT(plugin_error(test::faulty_plugin("big")), Contains("non-finite") && Contains("inf"));
  // The handshake's probe is request 0, so the seventh number comes with the first real scene.
  CHECK_THAT(plugin_error(test::faulty_plugin("length")),
             Contains("changed its vector lengths") && Contains("actions 7 then 6"));
  // Without stderr the message is one line; with stderr, its lines follow, indented.
  for (const char* mode : {"not_json", "wrong_id", "nan", "length"}) {
    CHECK(plugin_error(test::faulty_plugin(mode)).find('\n') == std::string::npos);
  }
  const std::string early = plugin_error(test::faulty_plugin("exit_early"));
  CHECK(early.substr(0, early.find('\n')).find("exited with status 3") != std::string::npos);
  CHECK_THAT(early, Contains("\n    faulty plug-in: giving up on request"));
}

TEST_CASE("subprocess_keeps_the_last_20_lines_of_stderr_and_reaps_once", "[unit]") {
  // The first-lines reader is the planted fault: a traceback's last line is what matters.
  auto keeps_the_end = [](const std::string& tail) {
    return tail.find("line 40\n") != std::string::npos &&
           tail.find("line 21\n") != std::string::npos &&
           tail.find("line 20\n") == std::string::npos;
  };
  std::string tail;
  {
    props::Subprocess child("for i in $(seq 1 40); do echo line $i >&2; done; exit 4");
    const props::Subprocess::Exit exit = child.finish(5.0);
    CHECK(exit.exited);
    CHECK(exit.status == 4);
    CHECK(child.finish(0.0).status == 4);  // reaped once; later calls give the same answer
    tail = child.stderr_tail();
  }
  CHECK(keeps_the_end(tail));
  std::string first_lines;  // what a reader of the first 20 lines would have kept
  for (int i = 1; i <= 20; ++i) first_lines += "line " + std::to_string(i) + "\n";
  CHECK_FALSE(keeps_the_end(first_lines));
  // Lines are cut at kStderrLineBytes, so a child cannot make the tail grow without bound.
  props::Subprocess noisy("head -c 100000 /dev/zero | tr '\\0' x >&2");
  noisy.finish(5.0);
  CHECK(noisy.stderr_tail().size() <= props::Subprocess::kStderrLineBytes + 1);
}

TEST_CASE("subprocess_reads_with_a_deadline_and_sees_a_closed_stdout", "[unit]") {
  props::Subprocess cat("cat");
  REQUIRE(cat.write_all("hello\n", 1.0) == props::Subprocess::Outcome::done);
  std::string line;
  REQUIRE(cat.read_line(line, 1.0) == props::Subprocess::Outcome::done);
  CHECK(line == "hello");
  CHECK(cat.read_line(line, 0.05) == props::Subprocess::Outcome::timed_out);
  props::Subprocess quiet("exit 0");
  CHECK(quiet.read_line(line, 5.0) == props::Subprocess::Outcome::closed);
}

TEST_CASE("a_hellos_cameras_are_read_and_each_bad_field_named", "[unit]") {
  using props::RequestKind;
  const auto hello_with = [](const std::string& cameras) {
    return props::parse_reply(R"({"id": 0, "hello": {"protocol": 2, "cameras": )" + cameras + "}}",
                              0, RequestKind::policy, "plug-in 'x'", true);
  };
  const auto good = hello_with(
      R"({"views": ["third_person", "eye_in_hand"], "image_size": [32, 24], "channels": "depth",)"
      R"( "floor": true})");
  REQUIRE(good.hello->cameras);
  CHECK(good.hello->cameras->views ==
        std::vector<props::View>{props::View::third_person, props::View::eye_in_hand});
  CHECK(good.hello->cameras->camera.width == 32);
  CHECK(good.hello->cameras->channels == props::ImageChannels::depth);
  CHECK(good.hello->cameras->floor);
  CHECK_FALSE(hello_with("null").hello->cameras);
  for (const auto& [cameras, named] : std::vector<std::pair<std::string, std::string>>{
           {R"(["eye_in_hand"])", "declare {\"views\""},
           {R"({"views": ["wrist"]})", "unknown camera 'wrist'"},
           {R"({"views": []})", "at least one camera"},
           {R"({"views": ["eye_in_hand"], "image_size": [0, 48]})", "[0,48]"},
           {R"({"views": ["eye_in_hand"], "image_size": [64]})", "[width, height]"},
           {R"({"views": ["eye_in_hand"], "channels": "bgr"})", "unknown image channels"},
           {R"({"views": ["eye_in_hand"], "floor": 1})", "true or false"}}) {
    INFO(cameras);
    CHECK_THROWS_AS(hello_with(cameras), props::PluginError);
    CHECK_THROWS_WITH(hello_with(cameras), Contains(named) && Contains("plug-in 'x'"));
  }
}

TEST_CASE("protocol_replies_are_validated_field_by_field", "[unit]") {
  using props::RequestKind;
  const std::string who = "plug-in 'x'";
  const auto hello =
      props::parse_reply(R"({"id": 0, "hello": {"protocol": 2, "extra_poses": ["start"], )"
                         R"("scalars": ["gripper"], "decode": true}})",
                         0, RequestKind::encode, who, true);
  REQUIRE(hello.hello.has_value());
  CHECK(hello.hello->extra_pose_names == std::vector<std::string>{"start"});
  CHECK(hello.hello->scalar_names == std::vector<std::string>{"gripper"});
  CHECK(hello.hello->decode);
  CHECK_FALSE(hello.hello->flow);
  CHECK_THROWS_WITH(
      props::parse_reply(R"({"id": 3, "hello": {}})", 3, RequestKind::encode, who, false),
      Contains("only answer the first request"));
  CHECK_THROWS_WITH(props::parse_reply(R"({"id": 0, "hello": {"protocol": 9}})", 0,
                                       RequestKind::encode, who, true),
                    Contains("protocol 9"));
  // Not wrapped into range by a conversion to int.
  CHECK_THROWS_WITH(props::parse_reply(R"({"id": 0, "hello": {"protocol": 4294967298}})", 0,
                                       RequestKind::encode, who, true),
                    Contains("protocol 4294967298"));
  // A noise length past props::kMaxPolicyNoise is refused (it would be allocated per request).
  CHECK_THROWS_WITH(props::parse_reply(R"({"id": 0, "hello": {"protocol": 2, "noise": 65537}})", 0,
                                       RequestKind::policy, who, true),
                    Contains("\"noise\" is 65537, not a length between 1 and 65536"));
  CHECK(props::parse_reply(R"({"id": 0, "hello": {"protocol": 2, "noise": 65536}})", 0,
                           RequestKind::policy, who, true)
            .hello->noise == 65536);
  CHECK_THROWS_WITH(props::parse_reply(R"({"id": 0, "hello": {"scalars": [1]}})", 0,
                                       RequestKind::encode, who, true),
                    Contains("not a name"));
  CHECK_THROWS_WITH(
      props::parse_reply(R"({"id": 1, "actions": [1]})", 1, RequestKind::flow, who, false),
      Contains("flow_input"));
  CHECK_THROWS_WITH(props::parse_reply(
                        R"({"id": 1, "chunk": [[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 2]]})",
                        1, RequestKind::decode, who, false),
                    Contains("last row 0 0 0 1"));
  const auto decoded = props::parse_reply(
      R"({"id": 1, "chunk": [[1, 0, 0, 5, 0, 1, 0, 6, 0, 0, 1, 7, 0, 0, 0, 1]]})", 1,
      RequestKind::decode, who, false);
  REQUIRE(decoded.chunk.size() == 1);
  CHECK(decoded.chunk[0].translation() == Eigen::Vector3d(5, 6, 7));
  // Requests: the extras and the flow query go on the wire.
  Scene scene = small_scene(3);
  scene.extra_poses = {{"start", RigidTransform::identity()}};
  scene.scalars = {{"gripper", 0.25}};
  const Eigen::VectorXd eps = Eigen::VectorXd::Ones(2);
  const std::string line =
      props::request_line(7, props::encode_request_body(scene, props::FlowQuery{&eps, 0.5}));
  const auto json = nlohmann::json::parse(line);
  CHECK(json.at("id") == 7);
  CHECK(json.at("protocol") == 2);
  CHECK(json.at("extra_poses").at("start").size() == 16);
  CHECK(json.at("scalars").at("gripper") == 0.25);
  CHECK(json.at("eps").size() == 2);
  CHECK(json.at("t") == 0.5);
  CHECK(nlohmann::json::parse(props::request_line(8, props::decode_request_body(eps, scene)))
            .at("decode")
            .size() == 2);
}

TEST_CASE("a_silent_plugin_times_out_instead_of_hanging", "[unit]") {
  const auto start = std::chrono::steady_clock::now();
  CHECK_THAT(plugin_error(test::faulty_plugin("silent"), 0.3),
             Contains("no answer to request 0 within 0.3"));
  CHECK_THAT(plugin_error("sleep 30", 0.3), Contains("no answer"));
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(5));
}

TEST_CASE("pipe_representation_rejects_an_empty_command_and_a_bad_timeout", "[unit]") {
  CHECK_THROWS_WITH(props::PipeRepresentation("  ", 1.0), Contains("needs a command"));
  CHECK_THROWS_WITH(props::PipeRepresentation("cat", 0.0), Contains("--timeout"));
  CHECK_THROWS_WITH(props::PipeRepresentation("cat", std::nan("")), Contains("--timeout"));
}

TEST_CASE("plugin_replies_are_bounded_in_length_and_nesting", "[unit]") {
  // A reply line over the limit stops the reading before more of it is kept.
  props::Subprocess endless("head -c 5000 /dev/zero | tr '\\0' x", 1024);
  std::string line;
  CHECK(endless.read_line(line, 5.0) == props::Subprocess::Outcome::too_long);
  // Built with append: GCC 12 misreads operator+ on long temporaries (-Warray-bounds).
  std::string deep = "{\"id\": 0, \"actions\": ";
  deep.append(1000, '[').append(1000, ']').append("}");
  std::string in_string = "{\"id\": 0, \"note\": \"";
  in_string.append(100, '[').append("\"}");
  CHECK_THROWS_WITH(props::parse_reply(deep, 0, props::RequestKind::encode, "plug-in 'x'", false),
                    Contains("nested deeper than"));
  // Brackets inside strings do not count.
  CHECK_THROWS_WITH(
      props::parse_reply(in_string, 0, props::RequestKind::encode, "plug-in 'x'", false),
      Contains("without \"actions\""));
}
