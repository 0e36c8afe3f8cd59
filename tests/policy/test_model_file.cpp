// Model files: a round trip gives the same actions bit for bit; every kind of damage is an
// InvalidModelFile naming the file, never a crash or garbage actions.
#include <catch2/catch.hpp>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "fixtures.hpp"
#include "handcentric/policy/binary_io.hpp"
#include "handcentric/policy/errors.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/policy/trainer.hpp"
#include "throws.hpp"

using namespace handcentric;
using namespace handcentric::policy;

namespace {

const LearnedPolicy& small_policy() {
  static const LearnedPolicy policy = train_policy(
      test::small_config(HeadKind::flow, "hand_centric", 20), test::small_scenes(16, 2), 3);
  return policy;
}

// Rewrites the trailing checksum so that a deliberate edit reaches the parser.
std::string with_valid_checksum(std::string bytes) {
  const std::uint64_t hash = fnv1a64(bytes.data(), bytes.size() - 8);
  std::memcpy(bytes.data() + bytes.size() - 8, &hash, 8);
  return bytes;
}

std::string temporary_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("handcentric_test_policy_" + name)).string();
}

}  // namespace

TEST_CASE("saved_models_load_and_act_identically", "[unit]") {
  for (HeadKind head : {HeadKind::flow, HeadKind::ddpm, HeadKind::cvae, HeadKind::c8flow}) {
    INFO(to_string(head));
    const std::vector<Scene> scenes = test::small_scenes(16, 2);
    const std::string representation = head == HeadKind::c8flow ? "absolute" : "hand_centric";
    const LearnedPolicy policy =
        train_policy(test::small_config(head, representation, 20), scenes, 3);
    const std::string path = temporary_path("roundtrip.model");
    save_model(policy, path);
    const LearnedPolicy loaded = load_model(path);
    std::filesystem::remove(path);
    CHECK(loaded.name() == policy.name());
    CHECK(loaded.action_vector(scenes[0], 4) == policy.action_vector(scenes[0], 4));
    CHECK_FALSE(std::filesystem::exists(path + ".tmp"));
  }
}

TEST_CASE("damaged_model_files_are_typed_errors", "[unit]") {
  const std::string bytes = serialize_model(small_policy());
  CHECK_NOTHROW(deserialize_model(bytes, "intact.model"));  // the positive control
  for (std::size_t length : {std::size_t{0}, std::size_t{5}, std::size_t{19}, std::size_t{40},
                             bytes.size() / 2, bytes.size() - 1}) {
    INFO("truncated to " << length);
    HC_CHECK_THROWS(deserialize_model(bytes.substr(0, length), "cut.model"), InvalidModelFile,
                    Catch::Contains("cut.model"));
  }
  for (std::size_t position = 0; position < bytes.size(); position += 97) {
    INFO("byte " << position << " flipped");
    std::string damaged = bytes;
    damaged[position] = static_cast<char>(damaged[position] ^ 0x5a);
    CHECK_THROWS_AS(deserialize_model(damaged, "flipped.model"), InvalidModelFile);
  }
  HC_CHECK_THROWS(deserialize_model(bytes + "x", "long.model"), InvalidModelFile,
                  Catch::Contains("appended"));
  HC_CHECK_THROWS(deserialize_model("{\"demos\": []}", "demos.json"), InvalidModelFile,
                  Catch::Contains("not a handcentric model"));
  std::string version = bytes;
  version[8] = 7;
  HC_CHECK_THROWS(deserialize_model(with_valid_checksum(version), "v7.model"), InvalidModelFile,
                  Catch::Contains("version 7"));
  // A consistent checksum over an edited config: the weights no longer fit the network. A
  // narrower one (12) is found at the weight array, a wider one (42) before anything is built.
  std::string edited = bytes;
  const std::size_t at = edited.find("hidden_width=32");
  REQUIRE(at != std::string::npos);
  edited[at + std::strlen("hidden_width=")] = '1';
  HC_CHECK_THROWS(deserialize_model(with_valid_checksum(edited), "edited.model"), InvalidModelFile,
                  Catch::Contains("numbers where"));
  edited[at + std::strlen("hidden_width=")] = '4';
  HC_CHECK_THROWS(deserialize_model(with_valid_checksum(edited), "edited.model"), InvalidModelFile,
                  Catch::Contains("the config describes a network of 5232 parameters"));
}

TEST_CASE("missing_or_unwritable_model_paths_are_typed_errors", "[unit]") {
  HC_CHECK_THROWS(load_model("/nonexistent/dir/x.model"), InvalidModelFile,
                  Catch::Contains("no such model file"));
  HC_CHECK_THROWS(save_model(small_policy(), "/nonexistent/dir/x.model"), FileError,
                  Catch::Contains("/nonexistent/dir/x.model"));
}

TEST_CASE("c8ddpm_models_keep_their_centre_and_a_damaged_centre_is_a_typed_error", "[unit]") {
  // Planar scenes (c8ddpm encodes rotations about z only): the hand turns about z.
  std::vector<Scene> scenes;
  for (int i = 0; i < 8; ++i) {
    Scene scene;
    for (int h = 0; h < 3; ++h) {
      scene.world_T_hand_history.push_back(RigidTransform::planar(0.3 * i - h, i, h));
    }
    for (int k = 0; k < 4; ++k) {
      scene.world_T_hand_chunk.push_back(RigidTransform::planar(0.3 * i + k, i + k, 1));
    }
    scene.hand_points = {Eigen::Vector3d(1.0, 0.1 * i, 0.0), Eigen::Vector3d(-1.0, 0.2, 0.0)};
    scenes.push_back(scene);
  }
  PolicyConfig config = test::small_config(HeadKind::c8ddpm, "absolute", 20);
  config.c8_centre_x = 2.5;
  config.c8_centre_y = -60.0;
  const LearnedPolicy policy = train_policy(config, scenes, 3);
  const std::string bytes = serialize_model(policy);
  const LearnedPolicy loaded = deserialize_model(bytes, "c8.model");
  CHECK(loaded.config().c8_centre_x == 2.5);
  CHECK(loaded.config().c8_centre_y == -60.0);
  CHECK(loaded.action_vector(scenes[0], 4) == policy.action_vector(scenes[0], 4));
  std::string edited = bytes;
  const std::size_t at = edited.find("c8_centre_y=-60");
  REQUIRE(at != std::string::npos);
  edited[at + std::strlen("c8_centre_y=-6")] = 'x';
  HC_CHECK_THROWS(deserialize_model(with_valid_checksum(edited), "centre.model"), InvalidModelFile,
                  Catch::Contains("centre.model") && Catch::Contains("c8_centre_y"));
  edited = bytes;
  edited[at + 3] ^= 0x20;  // "c8_Centre_y": an unknown key, even with a valid checksum
  CHECK_THROWS_AS(deserialize_model(with_valid_checksum(edited), "key.model"), InvalidModelFile);
  CHECK_THROWS_AS(deserialize_model(bytes.substr(0, bytes.size() - 9), "cut.model"),
                  InvalidModelFile);
}
