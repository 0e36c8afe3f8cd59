// `handcentric render`: PNG drawings of the 2D insertion task (sim/draw.hpp): one scene, a demo
// file, or one closed-loop rollout; for the 3D task (an insert3d model, or --task insert3d), a 3D
// scene or a rollout of the expert or a 3D model from a fixed viewpoint, the hand camera's depth
// images beside it (experiments/insert3d_drawing.hpp).
#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "task_of_files.hpp"
#include "insert3d_options.hpp"
#include "policy_source.hpp"
#include "handcentric/experiments/insert3d_drawing.hpp"
#include "handcentric/experiments/table2.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/draw.hpp"
#include "handcentric/sim/policies.hpp"
#include "handcentric/sim/rollout.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::apps {
namespace {

struct RenderOptions {
  std::string task;  ///< --task as given; empty: the --demos or --model file's, else peg2d
  std::string rotate_deg;
  bool scene = false;
  std::string demos;
  bool rollout = false;
  std::string policy = "expert";
  std::string model;
  std::string dist = "train";
  std::uint64_t seed = 1;
  std::uint64_t index = 0;
  int max_demos = sim::kDrawnDemos;
  int size = sim::kDrawingSize;
  std::string out;
  std::string camera_frames;  ///< 3D rollouts: also the hand camera's images along it, as a PNG
};

// The 3D task: scene --index of --dist or --rotate-deg, alone (--scene) or with a rollout.
int run_insert3d_render(const RenderOptions& options) {
  if (!options.demos.empty()) {
    throw InvalidArgument("--demos draws 2D demo files only, and '" + options.demos +
                          "' is one of task insert3d: draw its scenes with --scene or --rollout "
                          "(and --task insert3d)");
  }
  if (options.policy != "expert") {
    throw InvalidArgument("--policy " + options.policy +
                          " is a 2D scripted policy: with --task insert3d use "
                          "--policy expert or --model FILE");
  }
  const sim::insert3d::SceneDistribution distribution = insert3d_distribution(
      options.rotate_deg.empty() ? options.dist : "", options.rotate_deg, "", "");
  const sim::insert3d::TaskScene scene =
      sim::insert3d::sample_scene(distribution, options.seed, options.index);
  sim::insert3d::Rollout rollout;
  sim::insert3d::DepthCamera camera;
  std::vector<sim::insert3d::DepthCamera> rig{camera};
  bool normals = false;
  std::string what = "scene";
  if (options.scene) {
    rollout.world_T_hand = {scene.world_T_hand_start};
  } else {
    const LoadedInsert3dPolicy loaded = load_insert3d_policy(options.model);
    const ChunkPolicy& policy = *loaded.policy;
    camera = loaded.camera;
    rig = loaded.rig;
    normals = loaded.normals;
    const sim::insert3d::CollisionChecker checker;
    rollout = sim::insert3d::rollout(policy, scene, sim::stream_seed(options.seed, options.index),
                                     checker, loaded.rollout_options);
    what = "rollout (" + sim::outcome_name(rollout.outcome) + " after " +
           std::to_string(rollout.world_T_hand.size() - 1) + " steps)";
    what += " of " + policy.name();
  }
  const std::string caption = "insert3d '" + distribution.name() + "' scene " +
                              std::to_string(options.index) + " (seed " +
                              std::to_string(options.seed) + "): " + what;
  // The side panels show the camera the policy looked through (an image model's own).
  sim::write_png(options.out,
                 experiments::draw_insert3d_rollout(scene, rollout, caption, {}, camera));
  std::cout << "wrote " << what << " to " << options.out << "\n";
  if (!options.camera_frames.empty()) {
    sim::write_png(options.camera_frames, experiments::draw_insert3d_camera_frames(
                                              scene, rollout, experiments::kCameraFrameEvery,
                                              experiments::kCameraFrameColumns, {}, rig, normals));
    std::cout << "wrote the hand " << (rig.size() == 2 ? "cameras' " : "camera's ")
              << (normals ? "depth and normals" : "depth") << " images of "
              << rollout.world_T_hand.size() << " poses (every " << experiments::kCameraFrameEvery
              << "th and the last) to " << options.camera_frames << "\n";
  }
  return 0;
}

int run_render(const RenderOptions& options) {
  const std::string task =
      !options.demos.empty()
          ? resolve_task(options.task, demo_task(options.demos),
                         "--demos '" + options.demos + "', a demo file")
          : resolve_task(options.task, options.rollout ? model_task(options.model) : "",
                         "--model '" + options.model + "', a model");
  if (task == policy::kTaskInsert3d) return run_insert3d_render(options);
  if (!options.camera_frames.empty())
    throw InvalidArgument(
        "--camera-frames draws the 3D task's hand camera: add --task insert3d "
        "or give an insert3d model");
  refuse_3d_options(options.dist, options.rotate_deg);
  const sim::CollisionChecker checker;
  sim::Image image;
  std::string what;
  if (!options.demos.empty()) {
    if (options.max_demos < 1)
      throw InvalidArgument("--max must be at least 1, got " + std::to_string(options.max_demos));
    auto demos = sim::load_demos(options.demos);
    if (demos.size() > static_cast<std::size_t>(options.max_demos))
      demos.resize(static_cast<std::size_t>(options.max_demos));
    image = sim::draw_demos(demos, checker.geometry(), options.size);
    what = std::to_string(demos.size()) + " demos";
  } else {
    const sim::TaskScene scene =
        sim::sample_scene(sim::SceneDistribution::parse(options.dist), options.seed, options.index);
    if (options.scene) {
      image = sim::draw_scene(scene, checker.geometry(), options.size);
      what = "scene";
    } else {
      const LoadedPolicy loaded = load_chunk_policy(options.model, options.policy);
      const sim::Rollout rollout =
          sim::rollout(*loaded.policy, scene, checker,
                       sim::stream_seed(options.seed, options.index), loaded.rollout_options);
      image = sim::draw_rollout(scene, rollout, checker.geometry(), options.size);
      what = "rollout (" + sim::outcome_name(rollout.outcome) + " after " +
             std::to_string(rollout.steps) + " steps)";
    }
  }
  sim::write_png(options.out, image);
  std::cout << "wrote " << what << " to " << options.out << "\n";
  return 0;
}

}  // namespace

void add_render_command(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand(
      "render", "PNG of a scene, a demo file or a rollout (2D, or 3D with --task insert3d)");
  cmd->add_option("--task", options->task,
                  "peg2d (the 2D task) or insert3d (the 3D blade insertion); default: the task "
                  "the --demos or --model file records, else peg2d")
      ->check(CLI::IsMember({"peg2d", "insert3d"}));
  cmd->add_option(
      "--rotate-deg", options->rotate_deg,
      "insert3d: a train scene under the global rotation RX,RY,RZ (XYZ Euler, degrees)");
  auto* scene = cmd->add_flag("--scene", options->scene, "draw scene --index of --dist / --seed");
  auto* demos =
      cmd->add_option("--demos", options->demos, "draw the demos of this file (in the hole frame)");
  auto* rollout =
      cmd->add_flag("--rollout", options->rollout, "draw a rollout of --policy on scene --index");
  scene->excludes(demos)->excludes(rollout);
  demos->excludes(rollout);
  auto* policy = cmd->add_option("--policy", options->policy, "policy of --rollout")
                     ->check(CLI::IsMember(sim::scripted_policy_names()))
                     ->capture_default_str();
  cmd->add_option("--model", options->model, "a trained model for --rollout (instead of --policy)")
      ->excludes(policy);
  cmd->add_option(
         "--dist", options->dist,
         "train, ood or a hole-angle range A:B in degrees (insert3d: train, ood, random-se3)")
      ->capture_default_str();
  cmd->add_option("--seed", options->seed, "seed of the scene stream (as in `handcentric eval`)")
      ->capture_default_str();
  cmd->add_option("--index", options->index, "which scene of the stream")->capture_default_str();
  cmd->add_option("--max", options->max_demos, "at most this many demos (--demos)")
      ->capture_default_str();
  cmd->add_option("--size", options->size, "image width and height in pixels")
      ->capture_default_str();
  cmd->add_option("--out", options->out, "output PNG (written atomically)")->required();
  cmd->add_option("--camera-frames", options->camera_frames,
                  "insert3d: also a PNG of the hand camera's depth images along the rollout "
                  "(every " +
                      std::to_string(experiments::kCameraFrameEvery) +
                      "th pose and the last), what an image policy sees");
  cmd->callback([options, &exit_code] {
    if (!options->scene && options->demos.empty() && !options->rollout)
      throw CLI::RequiredError("--scene, --demos or --rollout");
    exit_code = run_render(*options);
  });
}

}  // namespace handcentric::apps
