#include "handcentric/policy/trainer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <numbers>
#include <random>
#include <thread>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/policy/c8_planar.hpp"
#include "handcentric/policy/slice_team.hpp"

namespace handcentric::policy {

int training_budget(long long samples) {
  if (samples < 1)
    throw InvalidArgument("training_budget: no training samples (got " + std::to_string(samples) +
                          ")");
  const double steps = kBudgetStepsPerSample * static_cast<double>(samples);
  return static_cast<int>(std::clamp(std::llround(steps), static_cast<long long>(kBudgetMinSteps),
                                     static_cast<long long>(kBudgetMaxSteps)));
}

int training_budget(HeadKind head, long long samples) {
  const int copies = c8::augmentation_copies(head);
  if (copies == 1) return training_budget(samples);
  const int budget = training_budget(copies * samples);
  return trained_as(head) == HeadKind::c8ddpm ? std::min(budget, kC8BudgetMaxSteps) : budget;
}

double learning_rate_at(const PolicyConfig& config, int step) {
  if (step < 1 || step > config.steps) {
    throw InvalidArgument("learning_rate_at: step " + std::to_string(step) + " is outside 1.." +
                          std::to_string(config.steps));
  }
  switch (config.lr_schedule) {
    case LearningRateSchedule::constant:
      return config.learning_rate;
    case LearningRateSchedule::cosine: {
      const double progress = static_cast<double>(step - 1) / config.steps;  // [0, 1)
      return config.learning_rate * 0.5 * (1.0 + std::cos(std::numbers::pi * progress));
    }
  }
  return config.learning_rate;
}

namespace {
void require_camera(const ImageSource* camera) {
  if (camera == nullptr) {
    throw InvalidArgument(
        "train_policy: an image policy (observation = image) needs the camera that renders its "
        "observations: pass an ImageSource");
  }
}
}  // namespace

int training_threads() {
  const auto cores = static_cast<int>(std::thread::hardware_concurrency());
  return std::clamp(cores, 1, SliceTeam::kMaxThreads);
}

LearnedPolicy train_policy(PolicyConfig config, const std::vector<Scene>& scenes,
                           std::uint64_t seed, const ProgressCallback& progress, int report_every,
                           std::shared_ptr<const ImageSource> camera, int threads) {
  config.validate();
  const auto representation = make_representation(config.representation);
  const bool image = config.observation == ObservationKind::image;
  if (image) require_camera(camera.get());
  return train_policy(config,
                      encode_scenes(*representation, scenes, config.history_length,
                                    config.chunk_length, image ? camera.get() : nullptr),
                      seed, progress, report_every, camera, threads);
}

LearnedPolicy train_policy(PolicyConfig config, const Dataset& data, std::uint64_t seed,
                           const ProgressCallback& progress, int report_every,
                           std::shared_ptr<const ImageSource> camera, int threads) {
  config.validate();
  if (threads < 0) {
    throw InvalidArgument("train_policy: " + std::to_string(threads) +
                          " threads; use 0 (this machine's cores) or 1 or more");
  }
  if (config.observation == ObservationKind::image) {
    require_camera(camera.get());
    const ImageShape shape = camera->shape();
    config.image_channels = shape.channels;
    config.image_height = shape.height;
    config.image_width = shape.width;
    if (data.observations.rows() <= shape.size()) {
      throw InvalidArgument("train_policy: observations of " +
                            std::to_string(data.observations.rows()) + " rows hold no " +
                            camera->name() + " image of " + std::to_string(shape.size()) +
                            " values after the proprioception: encode them with this camera");
    }
  } else {
    camera = nullptr;  // a key-point policy looks through no camera
  }
  std::shared_ptr<const Representation> representation = make_representation(config.representation);
  if (data.size() == 0)
    throw InvalidScene("no training samples: give at least one demonstration step");
  if (config.steps == 0) {
    config.steps = training_budget(config.head, data.size());
  }
  config.action_dimension = static_cast<int>(data.actions.rows());
  config.observation_dimension = static_cast<int>(data.observations.rows());
  config.hand_points = data.hand_points;
  config.world_points = data.world_points;
  std::shared_ptr<Head> head = make_head(config);
  head->set_threads(threads > 0 ? threads : training_threads());

  std::mt19937_64 rng(seed);
  head->prepare(data.actions, data.observations, rng);
  const Eigen::MatrixXf actions = data.actions.cast<float>();
  const Eigen::MatrixXf observations = data.observations.cast<float>();
  if (!actions.allFinite() || !observations.allFinite()) {
    throw InvalidScene(
        "the training data has a value beyond the float32 range (|x| > 3.4e38): express poses and "
        "points in metres and radians");
  }
  // Not filled (nor allocated) for a head that reads the set's columns itself.
  const bool gather = !head->reads_the_set();
  Eigen::MatrixXf batch_actions(actions.rows(), gather ? config.batch_size : 0);
  Eigen::MatrixXf batch_observations(observations.rows(), gather ? config.batch_size : 0);
  std::vector<Eigen::Index> columns(static_cast<std::size_t>(config.batch_size));
  const Minibatch batch{actions, observations, columns, batch_actions, batch_observations};

  const auto start = std::chrono::steady_clock::now();
  double loss_sum = 0.0;
  int loss_count = 0;
  const auto n = static_cast<std::uint64_t>(data.size());
  for (int step = 1; step <= config.steps; ++step) {
    for (int j = 0; j < config.batch_size; ++j) {
      const auto i = static_cast<Eigen::Index>(rng() % n);
      columns[static_cast<std::size_t>(j)] = i;
      if (!gather) continue;
      batch_actions.col(j) = actions.col(i);
      batch_observations.col(j) = observations.col(i);
    }
    const double learning_rate = learning_rate_at(config, step);
    head->set_learning_rate(learning_rate);
    const double loss = head->train_step_on(batch, rng);
    if (!std::isfinite(loss)) {
      throw InvalidArgument("training diverged at step " + std::to_string(step) + " (loss " +
                            std::to_string(loss) + ", learning rate " +
                            std::to_string(learning_rate) +
                            "): lower the learning rate or keep gradient clipping on");
    }
    loss_sum += loss;
    ++loss_count;
    if (progress && (step % std::max(report_every, 1) == 0 || step == config.steps)) {
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      TrainingProgress report;
      report.step = step;
      report.steps = config.steps;
      report.loss = loss_sum / loss_count;
      report.samples_per_second =
          seconds > 0.0 ? static_cast<double>(step) * config.batch_size / seconds : 0.0;
      report.eta_seconds = seconds / step * (config.steps - step);
      progress(report);
      loss_sum = 0.0;
      loss_count = 0;
    }
  }
  head->finish_training();  // the weight average, when config.ema_decay > 0
  return LearnedPolicy(config, representation, head, camera);
}

}  // namespace handcentric::policy
