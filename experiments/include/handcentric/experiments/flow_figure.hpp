#pragma once
// Figure 3 of "Guaranteed SE(3)-Equivariant Control via Hand-Centric Behavior Cloning" (Sec. 3,
// App. A): what a global rigid transform does to the rectified-flow problem of the first action
// a_1, for absolute, relative and hand-centric actions.
//
// For each representation, on the 2D peg-in-hole task:
//   - the training samples of a_1's 2D position (x, y of its translation) over all training
//     scenes of the demos (blue dots in the figure);
//   - one demonstrated chunk's a_1, and the same chunk after a global transform g (orange);
//   - the rectified flow towards it from a few noise draws eps: the target a_1 - eps (eq. 5)
//     is constant along the straight path eps -> a_1, drawn as an arrow.
// The same noise draws serve the original and the transformed chunk, so a panel whose flow is
// invariant under g is drawn identically in both rows. The numbers behind the picture (how far
// a_1 moved) are in FlowFigure and printed under each panel.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/props/tolerance.hpp"
#include "handcentric/sim/draw.hpp"

namespace handcentric::experiments {

struct FlowFigureOptions {
  int demos = 20;               ///< expert demos on train scenes (training samples drawn)
  std::uint64_t seed = 1;       ///< of the demo scenes, the expert and the noise draws
  int noise_draws = 10;         ///< arrows per panel
  double rotation_deg = 120.0;  ///< g's rotation about the world z axis
  double translation_x = 40.0;  ///< g's translation (same units as the sim: cm)
  double translation_y = -25.0;
  /// Throws InvalidArgument naming the field and its range.
  void validate() const;
};

/// One column of the figure: one representation, the chunk before and after g.
struct FlowColumn {
  std::string representation;                          ///< "absolute", "relative", "hand_centric"
  std::vector<Eigen::Vector2d> training_positions;     ///< a_1's (x, y) over the training scenes
  Eigen::Vector2d original = Eigen::Vector2d::Zero();  ///< a_1 of the chosen chunk
  Eigen::Vector2d transformed = Eigen::Vector2d::Zero();  ///< a_1 of g * that chunk
  /// |a_1(g * scene) - a_1(scene)| over all six numbers of a_1: 0 when a_1's flow problem is
  /// invariant under g (up to rounding).
  double a1_change = 0.0;
  /// a1_change below the audit's float64 floor REL (props::kRelativeTolerance): what is left is
  /// rounding, and the figure calls the column invariant where the audit would.
  bool invariant() const { return a1_change < props::kRelativeTolerance; }
};

struct FlowFigure {
  RigidTransform g;
  std::vector<Eigen::Vector2d> noise;  ///< eps's first two numbers, shared by every panel
  std::vector<FlowColumn> columns;     ///< absolute, relative, hand_centric
};

/// Builds the figure's data from expert demos on train scenes. Deterministic in options.seed.
FlowFigure compute_flow_figure(const FlowFigureOptions& options = FlowFigureOptions());

/// Two rows (the chunk, g * the chunk) by one column per representation; each column keeps one
/// scale in both rows, so a change under g is visible as a change of the picture.
sim::Image draw_flow_figure(const FlowFigure& figure, int panel_size = 380);

/// Where draw_flow_figure puts the panel of `column` and `row` (0: the chunk, 1: g * the chunk):
/// its top-left pixel and side. Tests compare the two rows of a column with it.
struct PanelBox {
  int x = 0;
  int y = 0;
  int size = 0;
};
PanelBox flow_panel_box(int column, int row, int panel_size = 380);

/// draw_flow_figure, written atomically as a PNG.
void write_flow_figure_png(const std::string& path, const FlowFigure& figure);

}  // namespace handcentric::experiments
