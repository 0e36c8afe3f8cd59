// The --exec pipe: the Python example plug-in agrees with the built-in hand_centric, and every
// way a plug-in can misbehave gives a one-line PluginError, never a hang or a crash.
#include <catch2/catch.hpp>
#include <chrono>
#include <memory>
#include <random>

#include "handcentric/core/representations.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/props/pipe_representation.hpp"
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
    const Scene scene = random_scene(rng, static_cast<int>(seed % 4), 1 + static_cast<int>(seed % 7), 2, 0, 1e3);
    const Eigen::VectorXd actions = plugin.encode_actions(scene);
    REQUIRE(actions.size() == builtin.encode_actions(scene).size());
    CHECK((actions - builtin.encode_actions(scene)).lpNorm<Eigen::Infinity>() < 1e-9);
    CHECK((plugin.encode_observation(scene) - builtin.encode_observation(scene)).lpNorm<Eigen::Infinity>() < 1e-9);
  }
  const int sent = plugin.requests_sent();
  plugin.encode_actions(small_scene(1));
  plugin.encode_actions(small_scene(1));  // the second time comes from the cache
  CHECK(plugin.requests_sent() <= sent + 1);
  CHECK_FALSE(plugin.can_decode());
  CHECK_THROWS_AS(plugin.decode_actions(Eigen::VectorXd::Zero(6), RigidTransform()), InvalidArgument);
}

TEST_CASE("bad_plugins_give_one_line_errors", "[unit]") {
  const std::string not_found = plugin_error("handcentric_no_such_plugin_xyz --flag");
  CHECK_THAT(not_found, Contains("command not found") && Contains("handcentric_no_such_plugin_xyz"));
  CHECK_THAT(plugin_error("echo 'plug-in crashed' >&2; exit 3"),
             Contains("exited with status 3") && Contains("plug-in crashed"));
  CHECK_THAT(plugin_error(test::faulty_plugin("exit_early")),
             Contains("exited with status 3") && Contains("giving up on request 1"));
  CHECK_THAT(plugin_error(test::faulty_plugin("not_json")), Contains("not JSON") && Contains("actions: 1 2 3"));
  CHECK_THAT(plugin_error(test::faulty_plugin("wrong_id")), Contains("request 0 with id 1"));
  CHECK_THAT(plugin_error(test::faulty_plugin("nan")), Contains("NaN"));
  CHECK_THAT(plugin_error(test::faulty_plugin("big")), Contains("non-finite") && Contains("inf"));
  CHECK_THAT(plugin_error(test::faulty_plugin("length")), Contains("changed its vector lengths") &&
                                                              Contains("actions 6 then 7"));
  for (const char* mode : {"not_json", "wrong_id", "nan", "length", "exit_early"}) {
    CHECK(plugin_error(test::faulty_plugin(mode)).find('\n') == std::string::npos);
  }
}

TEST_CASE("a_silent_plugin_times_out_instead_of_hanging", "[unit]") {
  const auto start = std::chrono::steady_clock::now();
  CHECK_THAT(plugin_error(test::faulty_plugin("silent"), 0.3), Contains("no answer to request 0 within 0.3"));
  CHECK_THAT(plugin_error("sleep 30", 0.3), Contains("no answer"));
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(5));
}

TEST_CASE("pipe_representation_rejects_an_empty_command_and_a_bad_timeout", "[unit]") {
  CHECK_THROWS_WITH(props::PipeRepresentation("  ", 1.0), Contains("needs a command"));
  CHECK_THROWS_WITH(props::PipeRepresentation("cat", 0.0), Contains("--timeout"));
  CHECK_THROWS_WITH(props::PipeRepresentation("cat", std::nan("")), Contains("--timeout"));
}
