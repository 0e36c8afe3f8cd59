// Fig. 3 (experiments/flow_figure.hpp): the numbers behind it follow App. A (absolute moves
// under every g, relative only under rotations, hand-centric never), and the picture shows it:
// a column whose flow problem is invariant draws the same pixels in both rows, and one that is
// not (the absolute column, the planted contrast) does not.
#include <catch2/catch.hpp>

#include "handcentric/core/errors.hpp"
#include "handcentric/experiments/flow_figure.hpp"
#include "throws.hpp"

using namespace handcentric;
using namespace handcentric::experiments;
using Catch::Matchers::Contains;

namespace {

FlowFigureOptions small(double rotation_deg) {
  FlowFigureOptions options;
  options.demos = 4;
  options.noise_draws = 5;
  options.rotation_deg = rotation_deg;
  return options;
}

const FlowColumn& column(const FlowFigure& figure, const std::string& name) {
  for (const auto& c : figure.columns) {
    if (c.representation == name) return c;
  }
  FAIL("no column " << name);
  return figure.columns.front();
}

// Pixels that differ between the two rows' panels of `c`.
int changed_pixels(const sim::Image& image, int c, int panel_size) {
  const PanelBox top = flow_panel_box(c, 0, panel_size), bottom = flow_panel_box(c, 1, panel_size);
  int changed = 0;
  for (int y = 0; y <= panel_size; ++y) {
    for (int x = 0; x <= panel_size; ++x) {
      const auto at = [&](const PanelBox& b, int channel) {
        return image
            .rgb[static_cast<std::size_t>(((b.y + y) * image.width + b.x + x) * 3 + channel)];
      };
      for (int channel = 0; channel < 3; ++channel) {
        if (at(top, channel) != at(bottom, channel)) {
          ++changed;
          break;
        }
      }
    }
  }
  return changed;
}

}  // namespace

TEST_CASE("fig3_a1_moves_under_g_for_absolute_and_relative_and_not_for_hand_centric", "[unit]") {
  const FlowFigure rotated = compute_flow_figure(small(120.0));
  CHECK(column(rotated, "absolute").a1_change > 1.0);
  CHECK(column(rotated, "relative").a1_change > 1e-3);
  CHECK(column(rotated, "hand_centric").a1_change < 1e-9);
  // A pure translation: relative actions are translation-invariant (App. A.2).
  const FlowFigure shifted = compute_flow_figure(small(0.0));
  CHECK(column(shifted, "absolute").a1_change > 1.0);
  CHECK(column(shifted, "relative").a1_change < 1e-9);
  CHECK(column(shifted, "hand_centric").a1_change < 1e-9);
  CHECK(column(rotated, "hand_centric").training_positions.size() > 4);
}

TEST_CASE("fig3_draws_an_invariant_column_identically_in_both_rows_and_a_moved_one_differently",
          "[unit]") {
  const FlowFigure figure = compute_flow_figure(small(120.0));
  const int panel = 200;
  const sim::Image image = draw_flow_figure(figure, panel);
  REQUIRE(figure.columns.size() == 3);
  CHECK(changed_pixels(image, 2, panel) == 0);       // hand_centric
  CHECK(changed_pixels(image, 0, panel) > 100);      // absolute: the contrast the check must see
  CHECK(changed_pixels(image, 1, panel) > 100);      // relative
  CHECK(image.count_pixels(230, 120, 0, 10) > 100);  // the orange flow is drawn
  // Deterministic: the same options give the same bits.
  CHECK(draw_flow_figure(compute_flow_figure(small(120.0)), panel).rgb == image.rgb);
}

TEST_CASE("fig3_rejects_bad_options_naming_them", "[unit]") {
  FlowFigureOptions options;
  options.demos = 0;
  HC_CHECK_THROWS(compute_flow_figure(options), InvalidArgument, Contains("demos = 0"));
  options = FlowFigureOptions();
  options.rotation_deg = std::nan("");
  HC_CHECK_THROWS(compute_flow_figure(options), InvalidArgument, Contains("finite"));
  HC_CHECK_THROWS(draw_flow_figure(FlowFigure()), InvalidArgument, Contains("no columns"));
  HC_CHECK_THROWS(draw_flow_figure(compute_flow_figure(small(10.0)), 50), InvalidArgument,
                  Contains("panel_size 50"));
}
