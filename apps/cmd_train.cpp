// `handcentric train`: behavior cloning of a policy (policy/) on expert demonstrations
// (sim/demos.hpp), written to a model file (policy/model_file.hpp).
//
//   handcentric train --demos demos.jsonl --repr hand_centric --head flow --steps 5000 --seed 1 --out m.model
//
// Progress on stderr (step, loss, samples/s, ETA): one line rewritten in place on a terminal, a
// line every 10% otherwise; the final summary line on stdout.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/policy/kernels.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/policy/trainer.hpp"
#include "handcentric/sim/demos.hpp"

namespace handcentric::apps {
namespace {

struct TrainOptions {
  std::string demos, out;
  std::string representation = "hand_centric";
  std::string head = "flow";
  int steps = 5000;
  std::uint64_t seed = 1;
  int max_demos = 0;
  int chunk = 16;
  int history = 0;  // H = 2 lets the policy copy the demo's velocity past pre-insertion (docs/SIM.md)
  int batch = 256;
  int width = 256;
  int layers = 3;
  double learning_rate = 1e-3;
  std::string lr_schedule = "cosine";
  double ema = 0.0;
  int euler_steps = 10;
  int time_embedding = 16;
  bool quiet = false;
};

std::string clock_text(double seconds) {
  const long s = static_cast<long>(seconds + 0.5);
  char text[32];
  std::snprintf(text, sizeof text, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  return text;
}

int run_train(const TrainOptions& options) {
  policy::PolicyConfig config;
  config.head = policy::parse_head(options.head);
  config.representation = options.representation;
  make_representation(options.representation);  // an unknown name fails before the demos load
  if (options.steps < 1) {
    throw InvalidArgument("--steps must be at least 1, got " + std::to_string(options.steps) +
                          " (an untrained model has no final loss to report)");
  }
  config.steps = options.steps;
  config.chunk_length = options.chunk;
  config.history_length = options.history;
  config.batch_size = options.batch;
  config.hidden_width = options.width;
  config.hidden_layers = options.layers;
  config.learning_rate = options.learning_rate;
  config.lr_schedule = policy::parse_schedule(options.lr_schedule);
  config.ema_decay = options.ema;
  config.euler_steps = options.euler_steps;
  config.time_embedding = options.time_embedding;
  config.validate();
  if (options.max_demos < 0) {
    throw InvalidArgument("--max-demos must be >= 0 (0 = all), got " + std::to_string(options.max_demos));
  }
  const std::filesystem::path out_dir = std::filesystem::absolute(options.out).parent_path();
  if (!std::filesystem::is_directory(out_dir)) {
    throw InvalidArgument("--out '" + options.out + "': the directory " + out_dir.string() +
                          " does not exist: create it first");
  }

  const std::vector<sim::Demo> demos = sim::load_demos(options.demos);
  if (options.max_demos > static_cast<int>(demos.size())) {
    throw InvalidArgument("--max-demos " + std::to_string(options.max_demos) + " but '" + options.demos + "' holds " +
                          std::to_string(demos.size()) + " demos: ask for at most that many");
  }
  const std::size_t used = options.max_demos == 0 ? demos.size() : static_cast<std::size_t>(options.max_demos);
  std::vector<Scene> scenes;
  for (std::size_t i = 0; i < used; ++i) {
    for (Scene& scene : sim::training_scenes(demos[i], config.history_length, config.chunk_length)) {
      scenes.push_back(std::move(scene));
    }
  }

  const bool terminal = ::isatty(STDERR_FILENO) != 0;
  const int report_every = terminal ? 50 : std::max(1, config.steps / 10);
  double last_loss = 0.0, last_rate = 0.0;
  const auto progress = [&](const policy::TrainingProgress& p) {
    last_loss = p.loss;
    last_rate = p.samples_per_second;
    if (options.quiet) return;
    std::fprintf(stderr, "%sstep %d/%d  loss %.5f  %.0f samples/s  ETA %s%s", terminal ? "\r" : "", p.step, p.steps,
                 p.loss, p.samples_per_second, clock_text(p.eta_seconds).c_str(), terminal ? "  " : "\n");
    if (terminal && p.step == p.steps) std::fprintf(stderr, "\n");
  };
  const auto start = std::chrono::steady_clock::now();
  const policy::LearnedPolicy trained = policy::train_policy(config, scenes, options.seed, progress, report_every);
  policy::save_model(trained, options.out);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "trained " << trained.name() << " on " << scenes.size() << " scenes from " << used << " demos: "
            << config.steps << " steps, final loss " << last_loss << ", " << static_cast<long>(last_rate)
            << " samples/s (" << policy::to_string(policy::kernel_isa()) << " kernels), " << clock_text(seconds)
            << " -> " << options.out << "\n";
  return 0;
}

void add_train_command(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<TrainOptions>();
  CLI::App* cmd = app.add_subcommand("train", "train a policy on demonstrations and write a model file");
  cmd->add_option("--demos", options->demos, "demo file (handcentric demos --out)")->required();
  cmd->add_option("--out", options->out, "model file to write (atomically)")->required();
  cmd->add_option("--repr", options->representation, "absolute|relative|relative_diff|hand_centric")
      ->capture_default_str();
  cmd->add_option("--head", options->head, "flow|ddpm|cvae|c8flow (c8flow needs --repr absolute)")
      ->capture_default_str();
  cmd->add_option("--steps", options->steps, "Adam steps")->capture_default_str();
  cmd->add_option("--seed", options->seed, "seed of initialization, minibatches and noise")->capture_default_str();
  cmd->add_option("--max-demos", options->max_demos, "train on the first N demos only (0 = all)")
      ->capture_default_str();
  cmd->add_option("--chunk", options->chunk, "K, actions per chunk")->capture_default_str();
  cmd->add_option("--history", options->history, "H, past poses in the observation")->capture_default_str();
  cmd->add_option("--batch", options->batch, "minibatch size")->capture_default_str();
  cmd->add_option("--width", options->width, "hidden layer width")->capture_default_str();
  cmd->add_option("--layers", options->layers, "hidden layers")->capture_default_str();
  cmd->add_option("--lr", options->learning_rate, "Adam learning rate")->capture_default_str();
  cmd->add_option("--ema", options->ema, "keep the moving average of the weights with this decay (0: off; 0.999 is usual)")
      ->capture_default_str();
  cmd->add_option("--lr-schedule", options->lr_schedule, "constant|cosine (from --lr down to ~0 at the last step)")
      ->capture_default_str();
  cmd->add_option("--euler-steps", options->euler_steps, "Euler steps of the flow sampler")->capture_default_str();
  cmd->add_option("--time-embedding", options->time_embedding, "sinusoidal features of t (even), 0 for t itself")
      ->capture_default_str();
  cmd->add_flag("--quiet", options->quiet, "no progress display");
  cmd->callback([options, &exit_code] { exit_code = run_train(*options); });
}

const CommandRegistration train_command("train", add_train_command);

}  // namespace
}  // namespace handcentric::apps
