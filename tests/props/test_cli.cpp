// `handcentric audit` and `handcentric report` end to end: exit codes, the JSON document, the
// --exec audit of the Python example, one-line errors.
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "run_command.hpp"

using namespace handcentric;
using Catch::Matchers::Contains;

TEST_CASE("audit_json_lists_every_check_of_a_builtin", "[unit]") {
  const auto result = test::run_command(test::cli() + " audit --repr relative --group rotation --cases 100 --seed 3 --json");
  REQUIRE(result.exit_code == 0);
  const auto json = nlohmann::json::parse(result.out);
  const auto& relative = json.at("representations").at(0);
  CHECK(relative.at("name") == "relative");
  REQUIRE(relative.at("checks").size() == 6);  // 4 pointwise components + 2 in distribution
  const auto& actions = relative.at("checks").at(0);
  CHECK(actions.at("component") == "actions");
  CHECK(actions.at("group") == "rotation");
  CHECK(actions.at("mode") == "pointwise");
  CHECK(actions.at("invariant") == false);
  CHECK(actions.at("seed") == 3);
  CHECK(actions.at("witness").at("g").size() == 16);
  CHECK(actions.at("witness").at("scene").at("chunk").size() >= 1);
  CHECK(actions.at("max_error").get<double>() > 0.0);
}

TEST_CASE("python_plugin_audit_matches_the_builtin_hand_centric", "[unit]") {
  const auto result =
      test::run_command(test::cli() + " audit --exec '" + test::python_example() + "' --cases 100 --json");
  INFO(result.err);
  REQUIRE(result.exit_code == 0);
  const auto json = nlohmann::json::parse(result.out);
  const auto& checks = json.at("representations").at(0).at("checks");
  CHECK(checks.size() == 30);  // actions, observation, flow input, flow target x 5 groups + 2 x 5 in distribution
  for (const auto& check : checks) {
    INFO(check.dump());
    CHECK(check.at("invariant") == true);
  }
}

TEST_CASE("audit_errors_are_one_line_with_exit_code_1_and_usage_errors_exit_2", "[unit]") {
  const auto timeout = test::run_command(test::cli() + " audit --exec 'sleep 30' --timeout 0.3");
  CHECK(timeout.exit_code == 1);
  CHECK_THAT(timeout.err, Contains("handcentric: error: plug-in 'sleep 30' gave no answer"));
  CHECK(timeout.err.find('\n') == timeout.err.size() - 1);
  const auto not_found = test::run_command(test::cli() + " audit --exec 'no_such_plugin_abc'");
  CHECK(not_found.exit_code == 1);
  CHECK_THAT(not_found.err, Contains("command not found"));
  const auto group = test::run_command(test::cli() + " audit --group so3");
  CHECK(group.exit_code == 1);
  CHECK_THAT(group.err, Contains("so3"));
  const auto repr = test::run_command(test::cli() + " audit --repr nope --cases 10");
  CHECK(repr.exit_code == 1);
  CHECK_THAT(repr.err, Contains("'nope'"));
  CHECK(test::run_command(test::cli() + " audit --cases").exit_code == 2);
  CHECK(test::run_command(test::cli() + " audit --repr absolute --exec cat").exit_code == 2);
}

TEST_CASE("main_report_opens_with_the_audit_summary_and_matches_the_paper", "[unit]") {
  const auto result = test::run_command(test::cli() + " report --cases 100 --seed 2");
  INFO(result.out << result.err);
  CHECK(result.exit_code == 0);
  CHECK_THAT(result.out, Contains("1. Audit of the built-in representations") && Contains("hand_centric") &&
                             Contains("actionflow") && Contains("Every cell matches App. A"));
  CHECK(result.out.find("witness:") == std::string::npos);
  const auto human = test::run_command(test::cli() + " audit --repr absolute --group c8 --cases 50");
  CHECK(human.exit_code == 0);
  CHECK_THAT(human.out, Contains("witness: actions under c8") && Contains("g: r = "));
}

TEST_CASE("a_plugin_without_observation_is_audited_on_actions_and_flow_only", "[unit]") {
  const auto result = test::run_command(test::cli() + " audit --exec '" + test::faulty_plugin("constant") +
                                        "' --cases 50 --json");
  INFO(result.err);
  REQUIRE(result.exit_code == 0);
  const auto checks = nlohmann::json::parse(result.out).at("representations").at(0).at("checks");
  CHECK(checks.size() == 25);  // actions, flow input, flow target x 5 groups + 2 x 5 in distribution
  for (const auto& check : checks) CHECK(check.at("component") != "observation");
}
