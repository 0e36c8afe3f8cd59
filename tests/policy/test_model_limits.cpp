// Bounded input (docs/RELIABILITY.md, item 4): model files that claim absurd sizes are
// InvalidModelFile errors raised before anything of that size is read or allocated. Each case runs
// the loader in a child process, and `handcentric eval --model` as another, and checks that the
// child's peak memory stays under 512 MB (child_process.hpp).
#include <catch2/catch.hpp>

#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "child_process.hpp"  // tests/support
#include "cli_refusal.hpp"    // tests/support
#include "fixtures.hpp"
#include "handcentric/policy/binary_io.hpp"
#include "handcentric/policy/errors.hpp"
#include "handcentric/policy/head.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/policy/trainer.hpp"

using namespace handcentric;
using namespace handcentric::policy;
using Catch::Matchers::Contains;

namespace {

// A sealed model file (magic, version, size, checksum all right) around `payload`.
std::string sealed(const std::string& payload) {
  ByteWriter file;
  file.raw("HCPOLICY", 8);
  file.u32(kModelFormatVersion);
  file.u64(payload.size());
  file.raw(payload.data(), payload.size());
  file.u64(fnv1a64(file.bytes().data(), file.bytes().size()));
  return file.bytes();
}

// The payload of a flow / hand_centric model with `config`, whose weights are `weight_bytes`
// bytes of whatever (the loader must refuse before it reads them).
std::string payload_claiming(const PolicyConfig& config, std::size_t weight_bytes) {
  ByteWriter payload;
  payload.string(config.to_text());
  payload.string(config.representation);
  payload.string(to_string(config.head));
  const std::string filler(weight_bytes, '\0');
  payload.raw(filler.data(), filler.size());
  return payload.bytes();
}

PolicyConfig trained_like() {
  PolicyConfig config = test::small_config(HeadKind::flow, "hand_centric", 1);
  config.action_dimension = 24;
  config.observation_dimension = 24;
  config.hand_points = 2;
  return config;
}

void write(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// What load_model(path) throws, run in a child: "<type>: <message>".
test::ChildRun load_in_child(const std::string& path) {
  return test::run_in_child([&] {
    try {
      load_model(path);
      return std::string("loaded");
    } catch (const InvalidModelFile& error) {
      return std::string("InvalidModelFile: ") + error.what();
    }
  });
}

// `handcentric eval --model path` must exit 1 with one line on stderr matching `what`, within
// the memory limit.
void check_cli_refuses(const std::string& path, const std::string& what) {
  test::check_cli_refuses(
      {HANDCENTRIC_CLI, "eval", "--model", path, "--dist", "train", "--trials", "1"}, path, what);
}

}  // namespace

TEST_CASE("parameter_count_is_what_every_head_stores", "[unit]") {
  for (HeadKind kind : {HeadKind::flow, HeadKind::ddpm, HeadKind::cvae, HeadKind::c8flow}) {
    INFO(to_string(kind));
    PolicyConfig config = trained_like();
    config.head = kind;
    config.representation = kind == HeadKind::c8flow ? "absolute" : "hand_centric";
    ByteWriter stored;
    make_head(config)->write(stored);
    // normalizers: 5 double vectors (3 of actions, 2 of observations); then 1 float vector (2 for
    // cvae); ddpm adds its clip range (one double)
    const std::size_t float_vectors = kind == HeadKind::cvae ? 2 : 1;
    const std::size_t normalizers = 8 * (5 + 3 * 24 + 2 * 24);
    const std::size_t extra = kind == HeadKind::ddpm ? 8 : 0;
    CHECK(stored.bytes().size() ==
          normalizers + 8 * float_vectors + sizeof(float) * parameter_count(config) + extra);
  }
}

TEST_CASE("a_model_file_over_256_MiB_is_refused_from_its_size_before_it_is_read", "[unit]") {
  // 2 GiB, sparse: a real model's header, then holes that read as zeros.
  const std::string path = test::limits_temp_path("huge.model");
  write(path, serialize_model(train_policy(test::small_config(HeadKind::flow, "hand_centric", 2),
                                           test::small_scenes(4, 1), 1)));
  std::filesystem::resize_file(path, std::uintmax_t{2} << 30);
  const test::ChildRun run = load_in_child(path);
  INFO(run.out);
  CHECK(run.exit_code == 0);
  CHECK_THAT(run.out, Contains("InvalidModelFile") &&
                          Contains(std::to_string(std::uint64_t{2} << 30) + " bytes") &&
                          Contains(std::to_string(kMaxModelFileBytes)));
  CHECK(run.peak_bytes < test::kPeakMemoryLimitBytes);
  check_cli_refuses(path, "more than the 268435456");
  std::filesystem::remove(path);
}

TEST_CASE("a_model_config_describing_3e11_parameters_is_refused_before_allocating", "[unit]") {
  // Within every bound of the config on its own (width 65536, 64 layers), but 2.7e11 weights:
  // 1.1 TB, where the file holds 1 KB.
  PolicyConfig config = trained_like();
  config.hidden_width = 65536;
  config.hidden_layers = 64;
  REQUIRE(parameter_count(config) > 270'000'000'000ull);
  const std::string path = test::limits_temp_path("wide.model");
  write(path, sealed(payload_claiming(config, 1024)));
  const test::ChildRun run = load_in_child(path);
  INFO(run.out);
  CHECK(run.exit_code == 0);
  CHECK_THAT(run.out, Contains("InvalidModelFile") &&
                          Contains(std::to_string(parameter_count(config)) + " parameters") &&
                          Contains("only 1024 bytes follow"));
  CHECK(run.peak_bytes < test::kPeakMemoryLimitBytes);
  check_cli_refuses(path, "parameters");
  std::filesystem::remove(path);
}

TEST_CASE("a_model_config_with_a_1e12_parameter_layer_is_refused_before_allocating", "[unit]") {
  // observation_dimension 2e9 with width 512: a first layer of 1e12 weights (and an int overflow
  // in the layer's input size, were it built).
  PolicyConfig config = trained_like();
  config.hidden_width = 512;
  std::string text = config.to_text();
  const std::string key = "observation_dimension=24\n";
  REQUIRE(text.find(key) != std::string::npos);
  text.replace(text.find(key), key.size(), "observation_dimension=2000000000\n");
  ByteWriter payload;
  payload.string(text);
  payload.string(config.representation);
  payload.string(to_string(config.head));
  const std::string path = test::limits_temp_path("layer.model");
  write(path, sealed(payload.bytes()));
  const test::ChildRun run = load_in_child(path);
  INFO(run.out);
  CHECK(run.exit_code == 0);
  CHECK_THAT(run.out, Contains("InvalidModelFile") &&
                          Contains("observation_dimension = 2000000000") && Contains("0..1048576"));
  CHECK(run.peak_bytes < test::kPeakMemoryLimitBytes);
  check_cli_refuses(path, "observation_dimension = 2000000000");
  std::filesystem::remove(path);
}

TEST_CASE("a_weight_array_claiming_1e12_entries_is_refused_before_allocating", "[unit]") {
  // A real model whose stored parameter count is rewritten to 1e12 (the config still says
  // 24x32...).
  const LearnedPolicy policy = train_policy(test::small_config(HeadKind::flow, "hand_centric", 2),
                                            test::small_scenes(4, 1), 1);
  std::string bytes = serialize_model(policy);
  // the weights are the last array: its u64 length sits 8 + 4 * n bytes before the checksum
  const std::uint64_t n = parameter_count(policy.config());
  const std::size_t at = bytes.size() - 8 - 4 * n - 8;
  std::uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + at, 8);
  REQUIRE(stored == n);
  const std::uint64_t claim = 1'000'000'000'000ull;
  std::memcpy(bytes.data() + at, &claim, 8);
  const std::string path = test::limits_temp_path("array.model");
  write(path, sealed(bytes.substr(20, bytes.size() - 28)));
  const test::ChildRun run = load_in_child(path);
  INFO(run.out);
  CHECK(run.exit_code == 0);
  CHECK_THAT(run.out, Contains("InvalidModelFile") && Contains("1000000000000 numbers"));
  CHECK(run.peak_bytes < test::kPeakMemoryLimitBytes);
  check_cli_refuses(path, "1000000000000 numbers");
  std::filesystem::remove(path);
}
