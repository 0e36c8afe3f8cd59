// `handcentric train`: behavior cloning of a policy (policy/) on expert demonstrations
// (sim/demos.hpp), written to a model file (policy/model_file.hpp).
//
//   handcentric train --demos demos.jsonl --out m.model   # the library defaults (PolicyConfig)
//   handcentric train --demos d3.jsonl --out m3.hcm   # a 3D demo file: the 3D blade insertion
//   handcentric train --demos d3.jsonl --out i3.hcm --observation image   # from the hand camera
//
// The task is the one the demo file records (--task may repeat it; naming another is an error
// naming both), and the model records it (PolicyConfig::task). The 3D task has no mirror images
// (--no-mirror is implied).
//
// Progress on stderr (step, loss, samples/s, ETA): one line rewritten in place on a terminal, a
// line every 10% otherwise; the final summary line on stdout.
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "image_options.hpp"
#include "task_of_files.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/experiments/cell.hpp"
#include "handcentric/experiments/insert3d_image.hpp"
#include "handcentric/experiments/insert3d_key_points.hpp"
#include "handcentric/experiments/table2.hpp"
#include "handcentric/policy/kernels.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/policy/slice_team.hpp"
#include "handcentric/policy/trainer.hpp"
#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/insert3d/demos.hpp"

namespace handcentric::apps {
namespace {

// The library's PolicyConfig holds every default; the command line only overrides it.
struct TrainOptions {
  std::string task;  ///< --task as given; empty: the demo file's
  std::string demos, out;
  policy::PolicyConfig config;
  std::string head = policy::to_string(config.head);
  std::string lr_schedule = policy::to_string(config.lr_schedule);
  std::string ddpm_prediction = policy::to_string(config.ddpm_prediction);
  std::string observation = policy::to_string(config.observation);
  std::shared_ptr<ImageFlags> image = std::make_shared<ImageFlags>();
  std::uint64_t seed = 1;
  int max_demos = 0;
  int threads = 0;  ///< 0: policy::training_threads()
  sim::TrainingData data;
  bool quiet = false;
};

// The number of demos trained on: --max-demos of the `held` in the file, 0 meaning all.
std::size_t demos_used(const TrainOptions& options, std::size_t held) {
  if (options.max_demos < 0 || options.max_demos > static_cast<int>(held)) {
    throw InvalidArgument("--max-demos " + std::to_string(options.max_demos) + " but '" +
                          options.demos + "' holds " + std::to_string(held) +
                          " demos: give 0 (all) up to " + std::to_string(held));
  }
  return options.max_demos == 0 ? held : static_cast<std::size_t>(options.max_demos);
}

int run_train(const TrainOptions& options) {
  policy::PolicyConfig config = options.config;
  config.head = policy::parse_head(options.head);
  config.lr_schedule = policy::parse_schedule(options.lr_schedule);
  config.ddpm_prediction = policy::parse_ddpm_prediction(options.ddpm_prediction);
  config.observation = policy::parse_observation(options.observation);
  const bool image = config.observation == policy::ObservationKind::image;
  std::shared_ptr<const experiments::Insert3dHandCamera> camera;
  if (image) camera = options.image->resolve().apply(config);
  make_representation(config.representation);  // an unknown name fails before the demos load
  if (config.steps < 0) {
    throw InvalidArgument("--steps must be >= 1, or 0 for the automatic budget, got " +
                          std::to_string(config.steps));
  }
  config.validate();
  const std::filesystem::path out_dir = std::filesystem::absolute(options.out).parent_path();
  if (!std::filesystem::is_directory(out_dir)) {
    throw InvalidArgument("--out '" + options.out + "': the directory " + out_dir.string() +
                          " does not exist: create it first");
  }

  config.task = resolve_task(options.task, demo_task(options.demos),
                             "--demos '" + options.demos + "', a demo file");
  const bool planar = config.task == policy::kTaskPeg2d;
  if (image && planar) {
    throw InvalidArgument(
        "--observation image: the 2D task (peg2d) has no camera; train on a 3D "
        "demo file (task insert3d) or leave --observation key_points");
  }
  // The 2D task's recipe (mirror images, perturbed copies); the 3D task's is Table 2's
  // (experiments::insert3d_default_perturbation: noise-injected copies in the hand frame).
  sim::TrainingData data = options.data;
  data.mirror = planar && options.data.mirror;
  data.perturbed_copies = planar ? options.data.perturbed_copies : 0;
  data.perturbation_seed = options.seed;  // one seed names the whole training run
  std::size_t used = 0;                   // demos trained on
  long long demo_samples = 0;             // the samples the automatic budget counts
  std::vector<Scene> scenes;
  experiments::Perturbation recipe_3d;  // the 3D task's noise injection
  if (planar) {
    const std::vector<sim::Demo> demos = sim::load_demos(options.demos);
    used = demos_used(options, demos.size());
    // Recovery copies must clear the hole the demos were made with.
    scenes = sim::training_scenes(demos, config.history_length, config.chunk_length,
                                  options.max_demos, data, sim::demo_file_geometry(options.demos));
    for (std::size_t i = 0; i < used; ++i)  // one per pose of each demo
      demo_samples += static_cast<long long>(demos[i].world_T_hand.size());
  } else {
    const std::vector<sim::insert3d::Demo> demos = sim::insert3d::load_demos(options.demos);
    used = demos_used(options, demos.size());
    recipe_3d = experiments::insert3d_default_perturbation(config.observation);
    scenes = experiments::insert3d_training_data(
        std::vector<sim::insert3d::Demo>(demos.begin(),
                                         demos.begin() + static_cast<std::ptrdiff_t>(used)),
        config.history_length, config.chunk_length, recipe_3d, options.seed);
    // The key-point policy input of the 3D task: the corners and the slot points computed from
    // them. An image policy sees the hand camera's image of the corners' slot instead.
    if (!image) scenes = experiments::with_slot_key_points(scenes);
    // The copies counted too, as Table 2's budget (policy::training_budget of its data) does.
    demo_samples = static_cast<long long>(scenes.size());
  }
  if (config.steps == 0)
    config.steps = experiments::automatic_steps(data, config.head, demo_samples);

  const bool terminal = ::isatty(STDERR_FILENO) != 0;
  const int report_every = terminal ? 50 : std::max(1, config.steps / 10);
  double last_loss = 0.0, last_rate = 0.0;
  const auto progress = [&](const policy::TrainingProgress& p) {
    last_loss = p.loss;
    last_rate = p.samples_per_second;
    if (options.quiet) return;
    std::cerr << (terminal ? "\r" : "") << "step " << p.step << '/' << p.steps << "  loss "
              << format_fixed(p.loss, 5) << "  " << format_fixed(p.samples_per_second, 0)
              << " samples/s  ETA " << format_clock(p.eta_seconds) << (terminal ? "  " : "\n");
    if (terminal && p.step == p.steps) std::cerr << "\n";
    std::cerr.flush();
  };
  const auto start = std::chrono::steady_clock::now();
  const policy::LearnedPolicy trained = policy::train_policy(config, scenes, options.seed, progress,
                                                             report_every, camera, options.threads);
  policy::save_model(trained, options.out);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "trained " << trained.name() << " on " << scenes.size() << " scenes from " << used
            << " demos" << (data.mirror ? " and their mirror images" : "")
            << (data.perturbed_copies > 0
                    ? " (" + std::to_string(data.perturbed_copies) + " perturbed copies each)"
                    : "")
            << (recipe_3d.copies > 0 ? " (" + std::to_string(recipe_3d.copies) +
                                           " noise-injected copies each, turned up to " +
                                           format_shortest(recipe_3d.max_deg) + " deg)"
                                     : "")
            << " (task " << config.task
            << (image ? ", " + camera->name() + ", encoder " + config.encoder + " " +
                            policy::to_string(config.image_features)
                      : std::string())
            << "): " << config.steps << " steps, final loss " << last_loss << ", "
            << static_cast<long>(last_rate) << " samples/s ("
            << policy::to_string(policy::kernel_isa()) << " kernels), " << format_clock(seconds)
            << " -> " << options.out << "\n";
  return 0;
}

}  // namespace

void add_train_command(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<TrainOptions>();
  CLI::App* cmd =
      app.add_subcommand("train", "train a policy on demonstrations and write a model file");
  cmd->add_option("--task", options->task,
                  "peg2d (the 2D peg-in-hole) or insert3d (the 3D blade insertion); default: the "
                  "task the demo file records")
      ->check(CLI::IsMember({policy::kTaskPeg2d, policy::kTaskInsert3d}));
  cmd->add_option("--demos", options->demos, "demo file (handcentric demos --out)")->required();
  cmd->add_option("--out", options->out, "model file to write (atomically)")->required();
  policy::PolicyConfig& config = options->config;
  cmd->add_option("--repr", config.representation, "absolute|relative|relative_diff|hand_centric")
      ->capture_default_str();
  cmd->add_option("--head", options->head,
                  "flow|ddpm|cvae|c8flow|c8ddpm|c8flow_planar|c8ddpm_avg|c8flow_avg (the c8 heads "
                  "need --repr absolute)")
      ->capture_default_str();
  cmd->add_option("--c8-centre-x", config.c8_centre_x,
                  "c8ddpm, c8flow_planar, c8ddpm_avg, c8flow_avg: x of the C8 centre (cm)")
      ->capture_default_str();
  cmd->add_option("--c8-centre-y", config.c8_centre_y,
                  "c8ddpm, c8flow_planar, c8ddpm_avg, c8flow_avg: y of the C8 centre (cm)")
      ->capture_default_str();
  cmd->add_option("--steps", config.steps,
                  "Adam steps (0: the automatic budget for the number of training samples; "
                  "--observation image: the image policies' own)")
      ->capture_default_str();
  cmd->add_option("--seed", options->seed,
                  "seed of initialization, minibatches, noise and the perturbed copies")
      ->capture_default_str();
  cmd->add_flag("--no-mirror{false}", options->data.mirror,
                "train on the demos only, not also on their mirror images about the hole axis");
  cmd->add_option("--perturbed-copies", options->data.perturbed_copies,
                  "relabelled recovery copies of each training sample, the hand moved off the demo "
                  "(0: none)")
      ->capture_default_str();
  cmd->add_option("--offset-cm", options->data.offset_cm,
                  "largest offset of a perturbed copy along x and y (cm)")
      ->capture_default_str();
  cmd->add_option("--offset-deg", options->data.offset_deg,
                  "largest angle offset of a perturbed copy (degrees)")
      ->capture_default_str();
  cmd->add_option("--recovery-steps", options->data.recovery_steps,
                  "steps over which a perturbed copy's chunk returns to the demo")
      ->capture_default_str();
  cmd->add_option("--max-demos", options->max_demos, "train on the first N demos only (0 = all)")
      ->capture_default_str();
  cmd->add_option("--chunk", config.chunk_length, "K, actions per chunk")->capture_default_str();
  cmd->add_option("--history", config.history_length, "H, past poses in the observation")
      ->capture_default_str();
  cmd->add_option("--batch", config.batch_size, "minibatch size")->capture_default_str();
  cmd->add_option("--width", config.hidden_width, "hidden layer width")->capture_default_str();
  cmd->add_option("--layers", config.hidden_layers, "hidden layers")->capture_default_str();
  cmd->add_option("--lr", config.learning_rate, "Adam learning rate")->capture_default_str();
  cmd->add_option("--ema", config.ema_decay,
                  "keep the moving average of the weights with this decay (0: off; 0.999 is usual)")
      ->capture_default_str();
  cmd->add_option("--lr-schedule", options->lr_schedule,
                  "constant|cosine (from --lr down to ~0 at the last step)")
      ->capture_default_str();
  cmd->add_option("--euler-steps", config.euler_steps, "Euler steps of the flow sampler")
      ->capture_default_str();
  cmd->add_option("--ddpm-prediction", options->ddpm_prediction,
                  "head ddpm: what the network predicts, sample (the clean chunk) or epsilon (the "
                  "noise)")
      ->capture_default_str();
  cmd->add_option("--cvae-kl-weight", config.cvae_kl_weight,
                  "head cvae: weight of the KL term in the loss")
      ->capture_default_str();
  cmd->add_option("--time-embedding", config.time_embedding,
                  "sinusoidal features of t (even), 0 for t itself")
      ->capture_default_str();
  cmd->add_option("--observation", options->observation,
                  "key_points, or image: the 3D task's hand camera through a CNN encoder trained "
                  "end to end (head flow)")
      ->check(CLI::IsMember({"key_points", "image"}))
      ->capture_default_str();
  add_image_options(cmd, options->image);
  cmd->add_option("--threads", options->threads,
                  "threads of an image policy's training steps (the same model for any number; "
                  "0 = this machine's cores)")
      ->check(CLI::Range(0, policy::SliceTeam::kMaxThreads))
      ->capture_default_str();
  cmd->add_flag("--quiet", options->quiet, "no progress display");
  cmd->callback([options, &exit_code] { exit_code = run_train(*options); });
}

}  // namespace handcentric::apps
