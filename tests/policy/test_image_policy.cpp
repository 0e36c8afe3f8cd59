// Image policies (PolicyConfig::observation = image): the encoder is trained end to end with the
// flow head, model files record it (and damage to it is a typed error), and a policy acts only
// through a camera of its training shape.
#include <catch2/catch.hpp>

#include <cstring>
#include <utility>
#include <vector>

#include "fixtures.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/policy/binary_io.hpp"
#include "handcentric/policy/conv_encoder.hpp"
#include "handcentric/policy/errors.hpp"
#include "handcentric/policy/head.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/policy/trainer.hpp"
#include "image_flow_head.hpp"
#include "throws.hpp"

using namespace handcentric;
using namespace handcentric::policy;

namespace {

LearnedPolicy image_policy(int steps) {
  return train_policy(test::small_image_config("hand_centric", steps), test::small_scenes(32, 2), 3,
                      {}, 100, std::make_shared<const test::BlobCamera>());
}

// The largest change of any encoder weight between two trainings.
float encoder_change(const LearnedPolicy& a, const LearnedPolicy& b) {
  const ConvEncoder* before = image_encoder(a.head());
  const ConvEncoder* after = image_encoder(b.head());
  REQUIRE(before != nullptr);
  REQUIRE(after != nullptr);
  return (before->parameters() - after->parameters()).cwiseAbs().maxCoeff<Eigen::PropagateNaN>();
}

// `count` training samples of config's shape: actions uniform in [-0.5, 0.5), observations
// (proprioception and pixels) in [0, 1).
std::pair<Eigen::MatrixXd, Eigen::MatrixXd> random_samples(const PolicyConfig& config,
                                                           Eigen::Index count, unsigned seed) {
  std::mt19937_64 rng(seed);
  Eigen::MatrixXd actions(config.action_dimension, count);
  Eigen::MatrixXd observations(config.observation_dimension, count);
  for (Eigen::Index i = 0; i < actions.size(); ++i) actions(i) = uniform01(rng) - 0.5;
  for (Eigen::Index i = 0; i < observations.size(); ++i) observations(i) = uniform01(rng);
  return {actions, observations};
}

std::string rechecksummed(std::string bytes) {
  const std::uint64_t hash = fnv1a64(bytes.data(), bytes.size() - 8);
  std::memcpy(bytes.data() + bytes.size() - 8, &hash, 8);
  return bytes;
}

// A model file's bytes with one line of its config text taken out, as a file written before
// the line's key existed: the payload's and the text's lengths (the u64s at bytes 12 and 20,
// model_file.cpp) shrink with it, and the checksum is recomputed.
std::string without_config_line(std::string bytes, const std::string& line) {
  const std::size_t at = bytes.find(line);
  REQUIRE(at != std::string::npos);
  bytes.erase(at, line.size());
  for (const std::size_t length_at : {std::size_t{12}, std::size_t{20}}) {
    std::uint64_t length = 0;
    std::memcpy(&length, bytes.data() + length_at, 8);
    length -= line.size();
    std::memcpy(bytes.data() + length_at, &length, 8);
  }
  return rechecksummed(bytes);
}

}  // namespace

TEST_CASE("image_policies_train_their_encoder_end_to_end", "[unit]") {
  const LearnedPolicy one = image_policy(1), many = image_policy(40);
  const PolicyConfig& config = many.config();
  CHECK(config.image_channels == 1);
  CHECK(config.image_height == 8);
  CHECK(config.image_width == 10);
  CHECK(config.observation_dimension == config.proprio_dimension() + 80);
  CHECK(image_encoder(many.head())->layers().size() == 2);
  // The loss reaches the encoder: its weights move from step 1 to step 40 (same seed, so the
  // same initialization). The planted fault: one training against itself shows no change.
  CHECK(encoder_change(one, many) > 1e-4f);
  CHECK(encoder_change(many, many) == 0.0f);
  // A key-point head has no encoder.
  const LearnedPolicy points = train_policy(test::small_config(HeadKind::flow, "hand_centric", 2),
                                            test::small_scenes(8, 2), 3);
  CHECK(image_encoder(points.head()) == nullptr);
}

// The trainer hands an image head the drawn columns of the training set without copying them
// out (Head::reads_the_set): the head normalizes them from the set, and must train the bits it
// trains on the same columns copied out, step after step (the loss, then every weight written).
TEST_CASE("an_image_head_trains_the_same_bits_from_the_sets_columns_as_from_a_copy", "[unit]") {
  const PolicyConfig config = image_policy(1).config();
  const auto samples = random_samples(config, 40, 5);
  const Eigen::MatrixXd& actions = samples.first;  // named, not bound: the lambdas below use them
  const Eigen::MatrixXd& observations = samples.second;
  const Eigen::MatrixXf set_actions = actions.cast<float>();
  const Eigen::MatrixXf set_observations = observations.cast<float>();
  // 37 columns: two whole slices of kImageTrainSlice samples and a part of one.
  const std::vector<Eigen::Index> columns = {3,  3,  39, 0,  17, 22, 8,  8,  31, 12, 5,  26, 1,
                                             2,  4,  6,  7,  9,  10, 11, 13, 14, 15, 16, 18, 19,
                                             20, 21, 23, 24, 25, 27, 28, 29, 30, 32, 33};
  const auto n = static_cast<Eigen::Index>(columns.size());
  Eigen::MatrixXf copied_actions(set_actions.rows(), n);
  Eigen::MatrixXf copied_observations(set_observations.rows(), n);
  for (Eigen::Index j = 0; j < n; ++j) {
    copied_actions.col(j) = set_actions.col(columns[static_cast<std::size_t>(j)]);
    copied_observations.col(j) = set_observations.col(columns[static_cast<std::size_t>(j)]);
  }
  const Eigen::MatrixXf none;
  const Minibatch batch{set_actions, set_observations, columns, none, none};
  const auto trained = [&](bool from_the_set, const Eigen::MatrixXf& observations_copy) {
    const std::unique_ptr<Head> head = make_head(config);
    std::mt19937_64 rng(7);
    head->prepare(actions, observations, rng);
    std::vector<double> losses;
    for (int step = 0; step < 3; ++step) {
      losses.push_back(from_the_set ? head->train_step_on(batch, rng)
                                    : head->train_step(copied_actions, observations_copy, rng));
    }
    head->finish_training();
    ByteWriter out;
    head->write(out);
    return std::pair{losses, out.bytes()};
  };
  CHECK(make_head(config)->reads_the_set());
  const auto from_the_set = trained(true, copied_observations);
  CHECK(from_the_set == trained(false, copied_observations));
  // The planted fault: one pixel of one copied column changed trains other weights.
  Eigen::MatrixXf changed = copied_observations;
  changed(changed.rows() - 1, 4) += 0.25f;
  CHECK(from_the_set.second != trained(false, changed).second);
}

// An image head runs its training step forward and backward one slice of samples at a time
// (kImageTrainSlice), summing the gradients over the slices: whatever the slicing, the step's
// gradient is the whole batch's, up to the rounding of the sums' order (a few float epsilons
// relative to its norm). 37 samples in slices of 16 (16, 16 and 5), 5, 1 and all 37. A slice
// scaled by its own size, a slice left out, or actions paired with another slice's images would
// each move the gradient by a large fraction of it. The planted fault: the same comparison
// against a batch with one pixel changed.
TEST_CASE("an_image_heads_sliced_step_has_the_whole_batchs_gradient", "[unit]") {
  const PolicyConfig config = image_policy(1).config();
  const auto samples = random_samples(config, 37, 11);
  const Eigen::MatrixXd& actions = samples.first;  // named, not bound: the lambdas below use them
  const Eigen::MatrixXd& observations = samples.second;
  const Eigen::MatrixXf batch_actions = actions.cast<float>();
  const auto step = [&](int slice, const Eigen::MatrixXf& batch_observations) {
    ImageFlowHead head(config);
    std::mt19937_64 rng(7);
    head.prepare(actions, observations, rng);
    head.set_train_slice(slice);
    const double loss = head.train_step(batch_actions, batch_observations, rng);
    Eigen::VectorXf gradient(head.network_gradient().size() + head.encoder_gradient().size());
    gradient << head.network_gradient(), head.encoder_gradient();
    return std::pair{loss, gradient};
  };
  const Eigen::MatrixXf batch_observations = observations.cast<float>();
  const auto whole_step = step(37, batch_observations);
  const double whole_loss = whole_step.first;
  const Eigen::VectorXf& whole = whole_step.second;  // named, not bound: a lambda uses it
  REQUIRE(whole.norm() > 0.0f);
  const auto relative_distance = [&](const Eigen::VectorXf& gradient) {
    return (gradient - whole).norm() / whole.norm();
  };
  for (const int slice : {kImageTrainSlice, 5, 1}) {
    INFO("slices of " << slice);
    const auto [loss, gradient] = step(slice, batch_observations);
    CHECK(loss == Approx(whole_loss).epsilon(1e-6));
    CHECK(relative_distance(gradient) < 1e-5f);
  }
  Eigen::MatrixXf changed = batch_observations;
  changed(changed.rows() - 1, 20) += 0.25f;
  CHECK(relative_distance(step(kImageTrainSlice, changed).second) > 1e-5f);
  HC_CHECK_THROWS(ImageFlowHead(config).set_train_slice(0), InvalidArgument,
                  Catch::Contains("slice of 0 samples"));
  // A step on no samples is refused by name (Adam would get an empty gradient).
  ImageFlowHead empty(config);
  std::mt19937_64 rng(7);
  empty.prepare(actions, observations, rng);
  HC_CHECK_THROWS(empty.train_step(batch_actions.leftCols(0), batch_observations.leftCols(0), rng),
                  InvalidArgument, Catch::Contains("no samples"));
}

// A step's slices on several threads (SliceTeam) give the weights of one thread, bit for bit:
// each slice's gradient is added in slice order whichever lane computed it. 37 samples in
// slices of 5 (8 slices) over three steps, on 2 threads, 3 (the last round short of a lane)
// and 9 (more than the slices: a lane is left out), with both kinds of image features, compared
// byte for byte. Mutants run by hand: a lane adding its slice without waiting for the one before
// (the sums in completion order) and a lane computing on weights not refreshed at the step both
// fail it.
TEST_CASE("an_image_heads_steps_give_the_same_bits_on_any_number_of_threads", "[unit]") {
  for (const ImageFeatures features : {ImageFeatures::flatten, ImageFeatures::spatial_softmax}) {
    PolicyConfig config = image_policy(1).config();
    config.image_features = features;
    const auto samples = random_samples(config, 37, 13);
    const Eigen::MatrixXf batch_actions = samples.first.cast<float>();
    const Eigen::MatrixXf batch_observations = samples.second.cast<float>();
    const auto weights = [&](int threads) {
      ImageFlowHead head(config);
      std::mt19937_64 rng(5);
      head.prepare(samples.first, samples.second, rng);
      head.set_train_slice(5);
      head.set_threads(threads);
      for (int step = 0; step < 3; ++step) head.train_step(batch_actions, batch_observations, rng);
      Eigen::VectorXf all(head.network().parameters().size() + head.encoder().parameter_count());
      all << head.network().parameters(), head.encoder().parameters();
      return all;
    };
    const Eigen::VectorXf one = weights(1);
    for (const int threads : {2, 3, 9}) {
      INFO(to_string(features) << " features, " << threads << " threads");
      const Eigen::VectorXf many = weights(threads);
      REQUIRE(many.size() == one.size());
      CHECK(std::memcmp(many.data(), one.data(), sizeof(float) * one.size()) == 0);
    }
  }
  // Through the trainer (train_policy's threads), the model files' bytes.
  const auto trained = [](int threads) {
    return serialize_model(train_policy(test::small_image_config("hand_centric", 4),
                                        test::small_scenes(40, 2), 3, {}, 100,
                                        std::make_shared<const test::BlobCamera>(), threads));
  };
  CHECK(trained(1) == trained(3));
  HC_CHECK_THROWS(ImageFlowHead(image_policy(1).config()).set_threads(0), InvalidArgument,
                  Catch::Contains("training threads 0"));
  HC_CHECK_THROWS(
      train_policy(test::small_image_config("hand_centric", 1), test::small_scenes(4, 2), 3, {},
                   100, std::make_shared<const test::BlobCamera>(), -1),
      InvalidArgument, Catch::Contains("-1 threads"));
}

TEST_CASE("image_models_record_their_encoder_and_need_their_camera", "[unit]") {
  const LearnedPolicy policy = image_policy(20);
  const std::string bytes = serialize_model(policy);
  const LearnedPolicy loaded = deserialize_model(bytes, "image.model");
  CHECK(loaded.config().observation == ObservationKind::image);
  CHECK(encoder_change(policy, loaded) == 0.0f);
  const Scene scene = test::small_scenes(1, 9).front();
  // A model file holds no camera: the task gives it back.
  HC_CHECK_THROWS(loaded.action_vector(scene, 4), InvalidArgument,
                  Catch::Contains("without its camera"));
  const LearnedPolicy seeing = loaded.with_camera(std::make_shared<const test::BlobCamera>());
  CHECK(seeing.action_vector(scene, 4) == policy.action_vector(scene, 4));
  // A camera of another shape is refused by name.
  class WideCamera final : public ImageSource {
   public:
    std::string name() const override { return "wide camera"; }
    ImageShape shape() const override { return {1, 8, 12}; }
    void render(const Scene&, Eigen::Ref<Eigen::VectorXd> image) const override { image.setZero(); }
  };
  HC_CHECK_THROWS(loaded.with_camera(std::make_shared<const WideCamera>()), InvalidArgument,
                  Catch::Contains("wide camera renders 1 x 8 x 12"));
}

TEST_CASE("damaged_image_model_files_are_typed_errors", "[unit]") {
  const std::string bytes = serialize_model(image_policy(5));
  for (std::size_t length : {bytes.size() / 2, bytes.size() - 9, bytes.size() - 1}) {
    INFO("truncated to " << length);
    HC_CHECK_THROWS(deserialize_model(bytes.substr(0, length), "cut.model"), InvalidModelFile,
                    Catch::Contains("cut.model"));
  }
  // A config that describes another encoder than the one stored (8 -> 9 channels in layer 2).
  std::string edited = bytes;
  const std::size_t at = edited.find("encoder=4,8");
  REQUIRE(at != std::string::npos);
  edited[at + std::strlen("encoder=4,")] = '9';
  CHECK_THROWS_AS(deserialize_model(rechecksummed(edited), "edited.model"), InvalidModelFile);
  // An encoder of a head that has none: refused before any weight is read.
  edited = bytes;
  const std::size_t head = edited.find("head=flow");
  REQUIRE(head != std::string::npos);
  edited.replace(head, std::strlen("head=flow"), "head=ddpm");
  HC_CHECK_THROWS(deserialize_model(rechecksummed(edited), "ddpm.model"), InvalidModelFile,
                  Catch::Contains("flow"));
}

TEST_CASE("image_configs_out_of_range_are_typed_errors", "[unit]") {
  PolicyConfig config = test::small_image_config("hand_centric", 2);
  config.encoder = "4,,8";
  HC_CHECK_THROWS(config.validate(), InvalidArgument, Catch::Contains("'4,,8'"));
  config.encoder = "4,999";
  HC_CHECK_THROWS(config.validate(), InvalidArgument, Catch::Contains("'999'"));
  config = test::small_image_config("hand_centric", 2);
  config.head = HeadKind::cvae;
  HC_CHECK_THROWS(config.validate(), InvalidArgument, Catch::Contains("flow"));
  // Without a camera there is nothing to train on.
  HC_CHECK_THROWS(
      train_policy(test::small_image_config("hand_centric", 2), test::small_scenes(8, 2), 3),
      InvalidArgument, Catch::Contains("ImageSource"));
  // The config text round-trips, and a key-point config writes none of the image keys.
  const PolicyConfig trained = image_policy(2).config();
  CHECK(PolicyConfig::from_text(trained.to_text()).to_text() == trained.to_text());
  CHECK(PolicyConfig().to_text().find("encoder") == std::string::npos);
}

TEST_CASE("spatial_softmax_image_policies_train_and_reload", "[unit]") {
  // encoder 4,6/1 on the 8 x 10 blob image: 4 x 5 x 4, then 4 x 5 x 6 at stride 1, then one
  // (x, y) per channel: 12 features in the MLP's input instead of 120.
  const auto train = [](int steps) {
    PolicyConfig config = test::small_image_config("hand_centric", steps);
    config.encoder = "4,6/1";
    config.image_features = ImageFeatures::spatial_softmax;
    return train_policy(config, test::small_scenes(32, 2), 3, {}, 100,
                        std::make_shared<const test::BlobCamera>());
  };
  const LearnedPolicy one = train(1), many = train(30);
  const ConvEncoder* encoder = image_encoder(many.head());
  REQUIRE(encoder != nullptr);
  CHECK(encoder->layers()[1].stride() == 1);
  CHECK(encoder->output_shape() == ImageShape{6, 4, 5});
  // The loss reaches the encoder through the soft-argmax (planted fault: a training against
  // itself shows no change).
  CHECK(encoder_change(one, many) > 1e-4f);
  CHECK(encoder_change(many, many) == 0.0f);
  const LearnedPolicy loaded = deserialize_model(serialize_model(many), "keypoints.model");
  CHECK(loaded.config().image_features == ImageFeatures::spatial_softmax);
  const Scene scene = test::small_scenes(1, 9).front();
  const LearnedPolicy seeing = loaded.with_camera(std::make_shared<const test::BlobCamera>());
  CHECK(seeing.action_vector(scene, 4) == many.action_vector(scene, 4));
  // The same weights read as flattened features are another network: the key decides.
  std::string bytes = serialize_model(many);
  const std::size_t at = bytes.find("image_features=spatial_softmax");
  REQUIRE(at != std::string::npos);
  bytes.replace(at, std::strlen("image_features=spatial_softmax"), "image_features=flatten");
  CHECK_THROWS_AS(deserialize_model(rechecksummed(bytes), "flat.model"), InvalidModelFile);
}

TEST_CASE("image_model_files_from_before_the_feature_and_fov_keys_read_as_they_were_trained",
          "[unit]") {
  // A file written before image_features and image_fov_deg existed has neither line: it reads
  // as flattened features and the 70 deg camera, what every such model was trained with.
  const std::string text = image_policy(2).config().to_text();
  REQUIRE(text.find("image_features=flatten\n") != std::string::npos);
  REQUIRE(text.find("image_fov_deg=70\n") != std::string::npos);
  std::string old = text;
  for (const std::string line : {"image_features=flatten\n", "image_fov_deg=70\n"})
    old.erase(old.find(line), line.size());
  const PolicyConfig read = PolicyConfig::from_text(old);
  CHECK(read.image_features == ImageFeatures::flatten);
  CHECK(read.image_fov_deg == 70.0);
  CHECK(read.to_text() == text);
  // Planted fault: a file that says otherwise is read as it says.
  std::string other = text;
  other.replace(other.find("image_fov_deg=70"), std::strlen("image_fov_deg=70"),
                "image_fov_deg=45");
  CHECK(PolicyConfig::from_text(other).image_fov_deg == 45.0);
  // A key-point config still writes none of them.
  CHECK(PolicyConfig().to_text().find("image_") == std::string::npos);
}

TEST_CASE("one_camera_model_files_from_before_the_cameras_key_load_and_act_the_same", "[unit]") {
  // A file written before image_cameras existed has no such line: it reads as one camera, the
  // only rig there was, and its policy gives the same actions bit for bit.
  const LearnedPolicy model = image_policy(2);
  CHECK(model.config().image_cameras == 1);
  const std::string bytes = serialize_model(model);
  const std::string old = without_config_line(bytes, "image_cameras=1\n");
  REQUIRE(old.size() + std::strlen("image_cameras=1\n") == bytes.size());
  const LearnedPolicy loaded = deserialize_model(old, "one_camera.model");
  CHECK(loaded.config().image_cameras == 1);
  CHECK(loaded.config().to_text() == model.config().to_text());
  const Scene scene = test::small_scenes(1, 9).front();
  const LearnedPolicy seeing = loaded.with_camera(std::make_shared<const test::BlobCamera>());
  CHECK(seeing.action_vector(scene, 4) == model.action_vector(scene, 4));
  // Planted fault: the same file claiming two cameras describes an image it cannot hold (one
  // channel for two cameras): a typed error naming the file, not a model.
  std::string two = bytes;
  two.replace(two.find("image_cameras=1"), std::strlen("image_cameras=1"), "image_cameras=2");
  HC_CHECK_THROWS(deserialize_model(rechecksummed(two), "two.model"), InvalidModelFile,
                  Catch::Contains("two.model") && Catch::Contains("image_cameras"));
}

TEST_CASE("image_cameras_and_their_channels_are_checked_with_the_value_and_the_fix", "[unit]") {
  PolicyConfig config = test::small_image_config("hand_centric", 2);
  config.image_cameras = 2;
  config.image_channels = 6;  // normals from each of two cameras
  CHECK_NOTHROW(config.validate());
  config.image_channels = 3;
  HC_CHECK_THROWS(
      config.validate(), InvalidArgument,
      Catch::Contains("image_channels = 3") && Catch::Contains("times image_cameras (2)"));
  config.image_channels = 0;
  config.image_cameras = 3;
  HC_CHECK_THROWS(config.validate(), InvalidArgument,
                  Catch::Contains("image_cameras") && Catch::Contains("1 or 2"));
  config.image_cameras = 0;
  HC_CHECK_THROWS(config.validate(), InvalidArgument, Catch::Contains("image_cameras"));
}

TEST_CASE("encoder_strides_and_image_features_are_parsed_or_refused_by_name", "[unit]") {
  const std::vector<EncoderLayerSetting> layers = parse_encoder("8,16/1,32");
  REQUIRE(layers.size() == 3);
  CHECK((layers[0].channels == 8 && layers[0].stride == 2));
  CHECK((layers[1].channels == 16 && layers[1].stride == 1));
  CHECK((layers[2].channels == 32 && layers[2].stride == 2));
  HC_CHECK_THROWS(parse_encoder("8,16/2"), InvalidArgument, Catch::Contains("'16/2'"));
  HC_CHECK_THROWS(parse_encoder("8,/1"), InvalidArgument, Catch::Contains("'/1'"));
  HC_CHECK_THROWS(parse_image_features("softmax"), InvalidArgument,
                  Catch::Contains("flatten or spatial_softmax"));
  PolicyConfig config = test::small_image_config("hand_centric", 2);
  config.image_fov_deg = 180.0;
  HC_CHECK_THROWS(config.validate(), InvalidArgument, Catch::Contains("image_fov_deg"));
}
