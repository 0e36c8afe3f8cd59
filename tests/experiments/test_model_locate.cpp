// `handcentric audit --model M --locate` (experiments/model_locate.hpp): each layer of a model
// of this library decided on the audit's pointwise cases, the first break located where it is
// planted. Small in-memory models (tests/policy/fixtures.hpp: 2 hidden layers of 32, 20 Adam
// steps), 12 cases each: a few seconds in all.
//
// The mutants each test was seen failing on (run by tests/experiments/mutant_locate.sh, which
// plants each in the source, rebuilds test_experiments and expects these tests to fail):
//   skip_layer    Mlp::infer hands no hidden layer to the watches (a hook that skips a layer):
//                 the rows' count and the planted bias's location fail (mlp.layer3 breaks first);
//   chunk_kind    the decoded chunk marked "features" instead of "poses": a hand-centric model's
//                 chunk breaks (it moves with g), so "no break" fails;
//   bias_after    the fault's watch installed outside the recorder (the recorder sees layer 2
//                 before the bias): the break is found one layer late, at mlp.layer3;
//   no_rounding   the rounding rule left out (floor only): unchanged here (float32 layers of an
//                 invariant input are the same bits), so it is not one of the mutants.
#include <catch2/catch.hpp>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "../policy/fixtures.hpp"
#include "handcentric/experiments/layer_fault.hpp"
#include "handcentric/experiments/locate_page.hpp"
#include "handcentric/experiments/model_locate.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/policy/trainer.hpp"

using namespace handcentric;
using experiments::LocatedLayer;
using experiments::ModelLocation;

namespace {

constexpr int kCases = 12;

std::shared_ptr<const policy::LearnedPolicy> small_model(
    const std::string& representation, std::shared_ptr<const policy::ImageSource> camera = {}) {
  const policy::PolicyConfig config =
      camera ? test::small_image_config(representation, 20)
             : test::small_config(policy::HeadKind::flow, representation, 20);
  return std::make_shared<policy::LearnedPolicy>(
      policy::train_policy(config, test::small_scenes(64, 21), 5, {}, 20, camera));
}

// The audit's options for the model, as locate_model narrows them, then located under se3.
ModelLocation located(std::shared_ptr<const ChunkPolicy> policy,
                      const policy::PolicyConfig& config) {
  props::AuditOptions audit;
  audit.cases = kCases;
  audit.groups = {props::Group::se3};
  return experiments::locate_on_model_cases(std::move(policy), config, audit, props::Group::se3);
}

std::vector<std::string> names(const ModelLocation& r) {
  std::vector<std::string> out;
  for (const LocatedLayer& layer : r.layers) out.push_back(layer.name);
  return out;
}

int count_of(const ModelLocation& r, const std::string& name) {
  int n = 0;
  for (const LocatedLayer& layer : r.layers) n += layer.name == name;
  return n;
}

}  // namespace

TEST_CASE("locate_watches_every_layer_of_a_hand_centric_model_and_finds_no_break", "[unit]") {
  const auto model = small_model("hand_centric");
  const ModelLocation r = located(model, model->config());
  INFO(experiments::locate_text(r));
  CHECK(r.first_break() == nullptr);
  CHECK_FALSE(r.witness.has_value());
  CHECK(r.chunk_equivariant);
  CHECK(r.cases == kCases);
  // observation, each of the 3 MLP layers at each Euler step, action, chunk: in that order.
  const int steps = model->config().euler_steps;
  REQUIRE(r.layers.size() == static_cast<std::size_t>(3 + 3 * steps));
  CHECK(names(r).front() == "observation");
  CHECK(r.layers[1].name == "mlp.layer1");
  CHECK(r.layers[2].name == "mlp.layer2");
  CHECK(r.layers[3].name == "mlp.layer3");
  CHECK(r.layers[4].name == "mlp.layer1");
  CHECK(r.layers[4].call == 1);
  for (const std::string layer : {"mlp.layer1", "mlp.layer2", "mlp.layer3"})
    CHECK(count_of(r, layer) == steps);
  CHECK(r.layers[r.layers.size() - 2].name == "action");
  CHECK(r.layers.back().name == "chunk");
  CHECK(r.layers.back().kind == experiments::LayerKind::poses);
  CHECK(r.layers.back().verdict == "equivariant");
  for (const LocatedLayer& layer : r.layers) {
    if (layer.kind == experiments::LayerKind::features) CHECK(layer.verdict == "invariant");
  }
}

TEST_CASE("locate_finds_a_world_frame_bias_in_the_second_layer_at_that_layer", "[unit]") {
  const auto model = small_model("hand_centric");
  const auto faulty = std::make_shared<experiments::WorldFrameBias>(model, "mlp.layer2");
  const ModelLocation r = located(faulty, model->config());
  INFO(experiments::locate_text(r));
  const LocatedLayer* first = r.first_break();
  REQUIRE(first != nullptr);
  CHECK(first->name == "mlp.layer2");
  CHECK(first->call == 0);
  CHECK(first->verdict == "neither");
  CHECK(r.layers[0].verdict == "invariant");  // observation
  CHECK(r.layers[1].verdict == "invariant");  // mlp.layer1
  REQUIRE(r.witness.has_value());
  CHECK(r.witness->name == "mlp.layer2");
  CHECK(r.witness->case_error > r.witness->tolerance);
  CHECK_FALSE(r.chunk_equivariant);
  CHECK(r.layers.back().verdict == "neither");
  const std::string text = experiments::locate_text(r);
  CHECK(text.find("first break at 'mlp.layer2'") != std::string::npos);
  CHECK(text.find(">> mlp.layer2[0]") != std::string::npos);
  CHECK(text.find("!  mlp.layer3[0]") != std::string::npos);
  const auto json = nlohmann::json::parse(experiments::locate_json({r}));
  CHECK(json["locate"][0]["first_break"] == "mlp.layer2");
  CHECK(json["locate"][0]["witness"]["name"] == "mlp.layer2");
}

TEST_CASE("locate_finds_an_absolute_model_broken_at_its_observation", "[unit]") {
  const auto model = small_model("absolute");
  const ModelLocation r = located(model, model->config());
  INFO(experiments::locate_text(r));
  REQUIRE(r.first_break() != nullptr);
  CHECK(r.first_break()->name == "observation");
  CHECK_FALSE(r.chunk_equivariant);
}

TEST_CASE("locate_watches_an_image_models_encoder_and_finds_a_bias_in_its_second_layer", "[unit]") {
  const auto model = small_model("hand_centric", std::make_shared<const test::BlobCamera>(true));
  const ModelLocation clean = located(model, model->config());
  INFO(experiments::locate_text(clean));
  CHECK(clean.first_break() == nullptr);
  REQUIRE(clean.layers.size() > 3);
  CHECK(clean.layers[0].name == "observation");
  CHECK(clean.layers[1].name == "encoder.conv1");
  CHECK(clean.layers[2].name == "encoder.conv2");
  CHECK(clean.layers[3].name == "mlp.layer1");
  const ModelLocation biased = located(
      std::make_shared<experiments::WorldFrameBias>(model, "encoder.conv2"), model->config());
  INFO(experiments::locate_text(biased));
  REQUIRE(biased.first_break() != nullptr);
  CHECK(biased.first_break()->name == "encoder.conv2");
  CHECK(biased.layers[1].verdict == "invariant");
}

// The report's section (locate_page.hpp): the two models side by side, the planted fault's first
// break marked on its row, every hand-centric cell a yes, and the page's rules kept (a NO cell
// links to the witnesses). Mutant (mutant_locate.sh page_mark): the fault's column never marked.
TEST_CASE("report_section_puts_the_planted_fault_beside_the_hand_centric_model", "[unit]") {
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "locate_page.hcm";
  policy::save_model(*small_model("hand_centric"), file.string());
  const std::vector<experiments::Section> sections =
      experiments::locate_sections(file.string(), "a test model", props::Group::se3, kCases, 1);
  std::filesystem::remove(file);
  REQUIRE(sections.size() == 2);
  CHECK(sections[0].id == "locate");
  CHECK(sections[1].id == "locate-witness");
  const auto* table = std::get_if<experiments::Table>(&sections[0].blocks.at(1));
  REQUIRE(table != nullptr);
  int marked = 0;
  for (const auto& row : table->rows) {
    CHECK(row[2].mark == experiments::Mark::yes);  // the hand-centric model
    if (row[3].detail.find("FIRST BREAK") == std::string::npos) continue;
    ++marked;
    CHECK(row[0].text.at(0).text == "▶ mlp.layer2[0]");
    CHECK(row[3].mark == experiments::Mark::no);
    CHECK(row[3].link == "#locate-witness");
  }
  CHECK(marked == 1);
  experiments::Document document;
  document.title = "locate";
  document.sections = sections;
  CHECK_NOTHROW(experiments::check(document));
}
