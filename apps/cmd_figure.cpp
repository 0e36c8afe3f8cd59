// `handcentric figure`: the paper's illustrative figures as PNGs. `figure flow` is Fig. 3
// (experiments/flow_figure.hpp): the rectified-flow problem of the first action under a global
// transform, for absolute, relative and hand-centric actions.
#include <iomanip>
#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/experiments/flow_figure.hpp"

namespace handcentric::apps {
namespace {

struct FigureOptions {
  experiments::FlowFigureOptions flow;
  std::string out;
};

int run_flow_figure(const FigureOptions& options) {
  const experiments::FlowFigure figure = experiments::compute_flow_figure(options.flow);
  experiments::write_flow_figure_png(options.out, figure);
  std::cout << "wrote Fig. 3 to " << options.out
            << ": how far a global transform g moves a_1 (all six numbers)\n";
  for (const auto& column : figure.columns) {
    std::cout << "  " << std::left << std::setw(13) << column.representation << ' ' << std::setw(9)
              << format_significant(column.a1_change, 3) << ' '
              << (column.invariant() ? "(invariant: the flow problem is the same)"
                                     : "(the flow problem moved)")
              << "\n";
  }
  return 0;
}

}  // namespace

void add_figure_command(CLI::App& app, int& exit_code) {
  CLI::App* cmd = app.add_subcommand("figure", "the paper's figures as PNGs (flow: Fig. 3)");
  cmd->require_subcommand(1);
  auto options = std::make_shared<FigureOptions>();
  CLI::App* flow = cmd->add_subcommand(
      "flow", "Fig. 3: the flow towards the first action, before and after a global transform g");
  flow->add_option("--demos", options->flow.demos, "expert demos whose training samples are drawn")
      ->capture_default_str();
  flow->add_option("--seed", options->flow.seed,
                   "seed of the scenes, the expert and the noise draws")
      ->capture_default_str();
  flow->add_option("--noise-draws", options->flow.noise_draws, "arrows per panel")
      ->capture_default_str();
  flow->add_option("--rotate-deg", options->flow.rotation_deg,
                   "g's rotation about the world z axis")
      ->capture_default_str();
  flow->add_option("--shift-x", options->flow.translation_x, "g's translation along x (cm)")
      ->capture_default_str();
  flow->add_option("--shift-y", options->flow.translation_y, "g's translation along y (cm)")
      ->capture_default_str();
  flow->add_option("--out", options->out, "output PNG (written atomically)")->required();
  flow->callback([options, &exit_code] { exit_code = run_flow_figure(*options); });
}

}  // namespace handcentric::apps
