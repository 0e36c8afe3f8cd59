// `handcentric table2`: the analogue of the paper's Table 2 on the simulated 3D blade insertion
// (experiments/table2.hpp): hand-centric, relative and absolute flow policies trained on train
// scenes, each evaluated on train, ood and random-se3 scenes.
//
//   handcentric table2 --demos 100 --trials 100 --out table2 --seed 1 --jobs 2
//   handcentric table2 --observation key_points,image   # also from the hand camera's pixels
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include "commands.hpp"
#include "image_options.hpp"
#include "handcentric/experiments/table2.hpp"

namespace handcentric::apps {
namespace {

// PREFIX-copies, PREFIX-cm and PREFIX-deg for one Perturbation (experiments/table2.hpp).
void add_perturbation_options(CLI::App* cmd, const std::string& prefix, const std::string& rows,
                              experiments::Perturbation& perturbation) {
  cmd->add_option(prefix + "-copies", perturbation.copies,
                  rows + " noise-injected copies of every training scene (0: the demos only)")
      ->capture_default_str();
  cmd->add_option(prefix + "-cm", perturbation.max_cm,
                  rows + " largest move of a copy's hand, per axis, in the hand frame (cm)")
      ->capture_default_str();
  cmd->add_option(prefix + "-deg", perturbation.max_deg,
                  rows + " largest turn of a copy's hand, per rotation-vector axis (deg)")
      ->capture_default_str();
}

}  // namespace

void add_table2_command(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<experiments::Table2Options>();
  auto observations = std::make_shared<std::vector<std::string>>(
      std::vector<std::string>{policy::to_string(policy::ObservationKind::key_points)});
  CLI::App* cmd = app.add_subcommand(
      "table2",
      "Table 2's analogue: hand-centric, relative, absolute flow policies on the 3D insertion");
  cmd->add_option("--demos", options->demos, "expert demos of train scenes to train on")
      ->capture_default_str();
  cmd->add_option("--trials", options->trials, "rollouts per method and scene set")
      ->capture_default_str();
  cmd->add_option("--out", options->out,
                  "directory for table2.json, table2.md, table2.png, table2.svg")
      ->capture_default_str();
  cmd->add_option("--seed", options->seed,
                  "seed of the demos and training; evaluation scenes use seed + 1")
      ->capture_default_str();
  cmd->add_option("--jobs", options->jobs,
                  "cores to use: key-point trainings at once, and the threads of each image "
                  "training, one image row at a time (0: one per hardware thread)")
      ->capture_default_str();
  cmd->add_option("--steps", options->steps,
                  "Adam steps per policy (0: automatic: the library's budget for the key-point "
                  "rows, the image rows' own)")
      ->capture_default_str();
  cmd->add_option("--methods", options->methods, "representations, one row each (comma-separated)")
      ->delimiter(',')
      ->capture_default_str();
  // The key-point rows' and the image rows' noise injection (DART), one set of flags each.
  add_perturbation_options(cmd, "--perturb", "the key-point rows'", options->perturbation);
  add_perturbation_options(cmd, "--image-perturb", "the image rows'", options->image_perturbation);
  cmd->add_option("--observation", *observations,
                  "key_points and/or image (the hand camera's image through a CNN), one "
                  "set of rows each (comma-separated)")
      ->delimiter(',')
      ->check(CLI::IsMember({"key_points", "image"}))
      ->capture_default_str();
  auto image = std::make_shared<ImageFlags>();
  add_image_options(cmd, image);
  cmd->add_flag("--save-models", options->save_models,
                "also write each row's trained model to --out (METHOD.hcm, METHOD_image.hcm), "
                "for eval, render --rollout and audit --model");
  cmd->add_flag("--quiet", options->quiet, "no progress lines on stderr");
  cmd->callback([options, observations, image, &exit_code] {
    options->image = image->resolve();
    options->observations.clear();
    for (const std::string& name : *observations)
      options->observations.push_back(policy::parse_observation(name));
    const auto rows = experiments::run_table2(*options);
    std::cout << experiments::table2_markdown(rows) << "wrote " << options->out
              << "/table2.json, table2.md, "
              << "table2.png, table2.svg\n";
    exit_code = 0;
  });
}

}  // namespace handcentric::apps
