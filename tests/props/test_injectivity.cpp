// Injectivity at a resolution: maps that lose the chunk below a bin (a 256-bin tokenizer, 1 cm
// voxels) are not injective, with about their bin as resolution; faithful maps, float32 ones
// included, are not called lossy. The planted fault is the pairs search alone (no scan).
#include <catch2/catch.hpp>
#include <cstring>
#include <memory>

#include "handcentric/core/representations.hpp"
#include "handcentric/props/checks/injectivity.hpp"
#include "mutants.hpp"

using namespace handcentric;

namespace {

props::CheckOptions third_person() {
  props::CheckOptions options = props::options_for(props::View::third_person);
  options.cases = 200;  // the audit's count at its default 1000 cases
  return options;
}

// Chunks of up to 4 steps (at most 0.17 m each) stay within the tokenizer's +-1 m.
props::CheckOptions within_one_metre() {
  props::CheckOptions options = third_person();
  options.shape.max_chunk = 4;
  return options;
}

// The pair at the resolution collides: its chunks differ, its actions do not.
void check_witness(const props::Injectivity& result) {
  REQUIRE(result.collision.has_value());
  const props::Collision& c = *result.collision;
  CHECK(c.search == "resolution");
  CHECK(c.chunk_distance > 0.0);
  CHECK(c.action_distance <= c.tolerance);
  CHECK(c.first.world_T_hand_history.size() == c.second.world_T_hand_history.size());
}

}  // namespace

TEST_CASE("a_256_bin_tokenizer_is_not_injective_below_its_bin", "[property]") {
  const props::Injectivity tokens =
      props::check_injectivity(std::make_shared<test::Tokenizer256>(), third_person());
  INFO(tokens.how);
  CHECK(tokens.injective == false);
  REQUIRE(tokens.resolution.has_value());
  CHECK(tokens.resolution_unit == "m");
  CHECK(*tokens.resolution >= 4e-3);  // its bin: 2 m / 256 = 7.8e-3 m
  CHECK(*tokens.resolution <= 2e-2);
  REQUIRE(tokens.rotation_resolution.has_value());
  CHECK(*tokens.rotation_resolution >= 1e-2);  // its bin: 2 pi / 256 = 0.025 rad
  CHECK(*tokens.rotation_resolution <= 1e-1);
  check_witness(tokens);
  // On chunks within its +-1 m (no clamping), the same: the bin alone loses the chunk.
  const props::Injectivity in_range =
      props::check_injectivity(std::make_shared<test::Tokenizer256>(), within_one_metre());
  CHECK(in_range.injective == false);
  REQUIRE(in_range.resolution.has_value());
  CHECK(*in_range.resolution >= 4e-3);
  CHECK(*in_range.resolution <= 2e-2);
}

TEST_CASE("the_pairs_search_alone_names_no_resolution_for_the_tokenizer", "[property]") {
  // The planted fault: the check as it was, chunks apart by 1e-3 or more and no resolution scan.
  // Its first cases change a chunk by its smallest change, 1 mm (RapidCheck draws them at small
  // sizes, whose numbers lie near 0), inside the tokenizer's 7.8 mm bin: it finds a collision,
  // but not below what size the map loses the chunk.
  props::ResolutionOptions no_scan;
  no_scan.decades = {};
  const auto tokenizer = std::make_shared<test::Tokenizer256>();
  const props::Injectivity blind = props::check_injectivity(tokenizer, third_person(), no_scan);
  CHECK(blind.round_trip_failure.has_value());
  CHECK_FALSE(blind.resolution.has_value());
  CHECK(blind.scales.empty());
  const props::Injectivity scanned = props::check_injectivity(tokenizer, third_person());
  CHECK(scanned.injective == false);
  CHECK(scanned.resolution.has_value());
}

TEST_CASE("a_1_cm_5_degree_binned_hand_centric_map_is_not_injective_below_1_cm", "[property]") {
  const props::Injectivity binned =
      props::check_injectivity(std::make_shared<test::BinnedHandCentric>(), third_person());
  INFO(binned.how);
  CHECK(binned.injective == false);
  REQUIRE(binned.resolution.has_value());
  CHECK(binned.resolution_unit == "m");
  CHECK(*binned.resolution >= 5e-3);  // 1 cm voxels
  CHECK(*binned.resolution <= 2e-2);
  REQUIRE(binned.rotation_resolution.has_value());
  CHECK(*binned.rotation_resolution >= 3e-2);  // 5 degrees = 0.087 rad
  CHECK(*binned.rotation_resolution <= 2e-1);
  check_witness(binned);
  // Per decade: nothing collides at 1e-6 m, much collides at 1e-3 m (not most: a chunk at rest,
  // one scene in eight, sits on the bin edge at 0, where any move changes a bin).
  REQUIRE(binned.scales.size() == 10);
  CHECK(binned.scales[0].scale == 1e-6);
  CHECK(binned.scales[0].unit == "m");
  CHECK(binned.scales[6].scale == 1e-3);
  CHECK(binned.scales[6].collisions > binned.scales[6].pairs / 8);
}

TEST_CASE("faithful_maps_have_no_resolution_and_float32_rounding_decides_nothing", "[property]") {
  for (const std::string& name : builtin_representation_names()) {
    INFO(name);
    const props::Injectivity builtin =
        props::check_injectivity(make_representation(name), third_person());
    CHECK(builtin.injective == true);
    CHECK_FALSE(builtin.resolution.has_value());
    REQUIRE(builtin.scales.size() == 10);
    for (const props::ScaleCollisions& decade : builtin.scales) CHECK(decade.pairs > 0);
  }
  // float32 is spaced 9.5e-7 m apart 10 m out: changes of 1e-7 m vanish in its rounding. Such
  // collisions are reported, and decide nothing.
  const auto float32_map = std::make_shared<test::Float32HandCentric>();
  const props::Injectivity float32 = props::check_injectivity(float32_map, third_person());
  CHECK(float32.injective != false);
  if (float32.resolution) CHECK(*float32.resolution < props::kSmallestLoss);
  props::ResolutionOptions finer;
  finer.decades = {1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2};
  const props::Injectivity rounding = props::check_injectivity(float32_map, third_person(), finer);
  INFO(rounding.how);
  CHECK(rounding.injective != false);
  REQUIRE(rounding.resolution.has_value());
  CHECK(*rounding.resolution < props::kSmallestLoss);
  CHECK_THAT(rounding.how, Catch::Matchers::Contains("rounding, not a loss of information"));
  // At float32's tolerance, 1e-4 (1 + L), changes the tolerance cannot tell are not pairs: a
  // faithful map stays injective, and both the float32 map and the tokenizer keep their verdicts.
  props::CheckOptions loose = third_person();
  loose.relative_tolerance = props::kFloat32RelativeTolerance;
  const props::Injectivity hand =
      props::check_injectivity(make_representation("hand_centric"), loose);
  CHECK(hand.injective == true);
  CHECK_FALSE(hand.resolution.has_value());
  CHECK(hand.scales[0].pairs == 0);  // 1e-6 m is below the tolerance of every scene
  CHECK(props::check_injectivity(std::make_shared<test::Float32HandCentric>(), loose).injective !=
        false);
  props::CheckOptions loose_in_range = within_one_metre();
  loose_in_range.relative_tolerance = props::kFloat32RelativeTolerance;
  CHECK(
      props::check_injectivity(std::make_shared<test::Tokenizer256>(), loose_in_range).injective ==
      false);
}

TEST_CASE("the_resolution_is_the_same_bits_for_the_same_seed", "[unit]") {
  const auto binned = std::make_shared<test::BinnedHandCentric>();
  props::CheckOptions options = third_person();
  options.cases = 100;
  const props::Injectivity first = props::check_injectivity(binned, options);
  const props::Injectivity again = props::check_injectivity(binned, options);
  REQUIRE(first.resolution.has_value());
  REQUIRE(again.resolution.has_value());
  CHECK(std::memcmp(&*first.resolution, &*again.resolution, sizeof(double)) == 0);
  CHECK(first.how == again.how);
  for (std::size_t i = 0; i < first.scales.size(); ++i)
    CHECK(first.scales[i].collisions == again.scales[i].collisions);
}

TEST_CASE("resolution_options_are_validated_and_resolutions_print_in_their_unit", "[unit]") {
  props::ResolutionOptions bad;
  bad.decades = {1e-3, 0.0};
  CHECK_THROWS_AS(
      props::check_injectivity(make_representation("hand_centric"), third_person(), bad),
      InvalidArgument);
  CHECK(props::format_resolution(7.8125e-3, "m") == "7.8e-3 m");
  CHECK(props::format_resolution(0.0245, "rad") == "2.5e-2 rad");
  CHECK(props::format_resolution(1e-4, "m") == "1.0e-4 m");
}
