// The moving average of the weights (weight_average.hpp, PolicyConfig::ema_decay): its formula
// with the warm-up, and that a trained model keeps the average of the iterates, not the last one.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

#include "fixtures.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/policy/binary_io.hpp"
#include "handcentric/policy/trainer.hpp"
#include "handcentric/policy/weight_average.hpp"
#include "throws.hpp"

using namespace handcentric;
using namespace handcentric::policy;

namespace {

// The average of `iterates` by the documented formula, with the warm-up or (planted fault)
// without it.
Eigen::VectorXf expected_average(const std::vector<Eigen::VectorXf>& iterates, double decay,
                                 bool warm_up = true) {
  Eigen::VectorXf average = iterates.front();
  for (std::size_t i = 1; i < iterates.size(); ++i) {
    const double t = static_cast<double>(i + 1);
    const float d = static_cast<float>(warm_up ? std::min(decay, (1.0 + t) / (10.0 + t)) : decay);
    average = d * average + (1.0f - d) * iterates[i];
  }
  return average;
}

// The weights a head wrote last: the trailing [u64 count][count floats] block of Head::write.
Eigen::VectorXf trailing_weights(const Head& head) {
  ByteWriter out;
  head.write(out);
  const std::string& bytes = out.bytes();
  for (std::size_t count = 1; 8 + 4 * count <= bytes.size(); ++count) {
    std::uint64_t stored = 0;
    std::memcpy(&stored, bytes.data() + bytes.size() - 4 * count - 8, 8);
    if (stored == count) {
      Eigen::VectorXf weights(static_cast<Eigen::Index>(count));
      std::memcpy(weights.data(), bytes.data() + bytes.size() - 4 * count, 4 * count);
      return weights;
    }
  }
  FAIL("no trailing weight block");
  return {};
}

}  // namespace

TEST_CASE("weight_average_follows_its_formula_with_the_warm_up", "[unit]") {
  std::vector<Eigen::VectorXf> iterates;
  for (int t = 0; t < 40; ++t)
    iterates.push_back(Eigen::VectorXf::Constant(3, static_cast<float>(t * t) * 0.01f));
  WeightAverage average(0.95);
  for (const Eigen::VectorXf& theta : iterates) average.update(theta);
  CHECK(average.updates() == 40);
  CHECK((average.average() - expected_average(iterates, 0.95))
            .cwiseAbs()
            .maxCoeff<Eigen::PropagateNaN>() < 1e-6f);
  // Planted fault: the same check against an average without the warm-up fails.
  CHECK((average.average() - expected_average(iterates, 0.95, false))
            .cwiseAbs()
            .maxCoeff<Eigen::PropagateNaN>() > 1e-3f);

  WeightAverage off(0.0);
  off.update(iterates.back());
  CHECK_FALSE(off.active());
  CHECK(off.updates() == 0);
  CHECK(off.average().size() == 0);
  HC_CHECK_THROWS(WeightAverage(1.0), InvalidArgument, Catch::Contains("[0, 1)"));
  HC_CHECK_THROWS(WeightAverage(-0.1), InvalidArgument, Catch::Contains("-0.1"));
}

TEST_CASE("a_model_trained_with_ema_keeps_the_average_of_its_iterates", "[unit]") {
  // Constant learning rate: training n steps gives the first n iterates of a longer run, so
  // the iterates theta_1..theta_6 come from six runs without the average. Flow's head writes
  // its weights last (DDPM and c8flow average through the same NetworkHead code).
  const std::vector<Scene> scenes = test::small_scenes(8, 21);
  {
    PolicyConfig config = test::small_config(HeadKind::flow, "hand_centric", 0);
    config.lr_schedule = LearningRateSchedule::constant;
    std::vector<Eigen::VectorXf> iterates;
    for (int steps = 1; steps <= 6; ++steps) {
      config.steps = steps;
      iterates.push_back(trailing_weights(train_policy(config, scenes, 5).head()));
    }
    config.ema_decay = 0.9;
    const Eigen::VectorXf averaged = trailing_weights(train_policy(config, scenes, 5).head());
    CHECK((averaged - expected_average(iterates, 0.9)).cwiseAbs().maxCoeff<Eigen::PropagateNaN>() <
          1e-6f);
    // A trainer that forgot finish_training() would keep the last iterate.
    CHECK((averaged - iterates.back()).cwiseAbs().maxCoeff<Eigen::PropagateNaN>() > 1e-5f);
  }
}

TEST_CASE("ema_decay_is_validated_and_stored_in_the_model_config", "[unit]") {
  PolicyConfig config;
  config.ema_decay = 0.999;
  CHECK(PolicyConfig::from_text(config.to_text()).ema_decay == 0.999);
  config.ema_decay = 1.0;
  HC_CHECK_THROWS(config.validate(), InvalidArgument, Catch::Contains("ema_decay"));
}
