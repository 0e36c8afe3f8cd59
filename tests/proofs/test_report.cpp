// The claims report: its JSON shape, the committed docs/CLAIMS.md being up to date, and the
// atomic file writer.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "handcentric/proofs/claims.hpp"
#include "handcentric/proofs/report.hpp"

using namespace handcentric::proofs;

namespace {

const std::vector<ClaimOutcome>& outcomes() {
  static const std::vector<ClaimOutcome> all = certify_all(paper_claims());
  return all;
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  std::ostringstream out;
  out << file.rdbuf();
  return out.str();
}

// A copy of the outcomes with the first certificate failed: what a broken claim would report.
std::vector<ClaimOutcome> with_first_failed() {
  std::vector<ClaimOutcome> broken = outcomes();
  broken.front().result.verified = false;
  return broken;
}

}  // namespace

TEST_CASE("prove_json_lists_every_claim_with_the_documented_fields", "[proofs]") {
  const nlohmann::json document = nlohmann::json::parse(report_json(outcomes()));
  REQUIRE(document.at("claims").size() == outcomes().size());
  for (const nlohmann::json& claim : document.at("claims")) {
    CHECK(claim.at("id").is_string());
    CHECK(claim.at("statement").is_string());
    const std::string kind = claim.at("kind").get<std::string>();
    CHECK((kind == "identity" || kind == "counterexample"));
    CHECK(claim.at("verified").get<bool>());
    CHECK(claim.at("witness").is_null() == (kind == "identity"));
  }
  CHECK(document.at("verified").get<int>() == static_cast<int>(outcomes().size()));
  // Planted fault: a failed certificate shows up as verified: false and in the count.
  const nlohmann::json broken = nlohmann::json::parse(report_json(with_first_failed()));
  CHECK_FALSE(broken.at("claims").at(0).at("verified").get<bool>());
  CHECK(broken.at("verified").get<int>() == static_cast<int>(outcomes().size()) - 1);
}

TEST_CASE("text_and_summary_report_the_verdict_of_every_claim", "[proofs]") {
  const std::string n = std::to_string(outcomes().size());
  CHECK_THAT(summary_text(outcomes()), Catch::StartsWith(n + "/" + n + " certificates verified"));
  CHECK_THAT(report_text(outcomes()),
             Catch::Contains("A.3 eq. (23)") && Catch::Contains("witness: T~ = "));
  CHECK_THAT(summary_text(with_first_failed()), Catch::Contains("FAIL"));
  CHECK_THAT(report_text(with_first_failed()), Catch::Contains("NOT VERIFIED"));
}

TEST_CASE("committed_claims_report_is_up_to_date", "[proofs]") {
  const std::filesystem::path committed =
      std::filesystem::path(HANDCENTRIC_SOURCE_DIR) / "docs" / "CLAIMS.md";
  INFO("regenerate with: handcentric prove --markdown docs/CLAIMS.md");
  REQUIRE(std::filesystem::exists(committed));
  const std::string fresh = report_markdown(outcomes());
  CHECK(read_file(committed) == fresh);
  // Planted fault: a report with one failed certificate differs from the committed one.
  CHECK(read_file(committed) != report_markdown(with_first_failed()));
}
