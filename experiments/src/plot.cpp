#include "handcentric/experiments/plot.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "drawing.hpp"
#include "handcentric/core/errors.hpp"

namespace handcentric::experiments {
namespace {

using drawing::dashed;
using drawing::rgb;
using drawing::text;

// Colour-blind-safe (Okabe-Ito) colours, one per series in row order.
const cv::Scalar kColours[] = {rgb(0, 114, 178),   rgb(213, 94, 0),  rgb(0, 158, 115),
                               rgb(204, 121, 167), rgb(230, 159, 0), rgb(86, 180, 233),
                               rgb(0, 0, 0)};

}  // namespace

sim::Image draw_table1(const std::vector<Row>& rows, int width, int height) {
  if (rows.empty())
    throw InvalidArgument("draw_table1: no rows to draw (no cell has a result yet)");
  cv::Mat canvas(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 70, right = width - 300, top = 70, bottom = height - 60;
  int max_demos = 0;
  for (const Row& r : rows) max_demos = std::max(max_demos, r.demos);
  const double x_max = std::max(10, static_cast<int>(std::ceil(max_demos / 10.0)) * 10);
  // `shift`: a horizontal offset in pixels, so that series and their OOD markers at one demo
  // count stay apart whatever the axis' scale.
  const auto px = [&](double demos, double success, int shift = 0) {
    return cv::Point(static_cast<int>(std::lround(left + (right - left) * demos / x_max)) + shift,
                     static_cast<int>(std::lround(bottom - (bottom - top) * success)));
  };
  // Axes, grid and ticks.
  for (int k = 0; k <= 10; k += 2) {
    const double y = k / 10.0;
    cv::line(canvas, px(0, y), px(x_max, y), rgb(225, 225, 225), 1);
    char label[8];
    std::snprintf(label, sizeof label, "%.1f", y);
    text(canvas, label, px(0, y) + cv::Point(-40, 5));
  }
  for (int d = 0; d <= x_max; d += static_cast<int>(x_max) / 10) {
    cv::line(canvas, px(d, 0), px(d, 0) + cv::Point(0, 5), rgb(20, 20, 20), 1);
    text(canvas, std::to_string(d), px(d, 0) + cv::Point(-10, 22));
  }
  cv::rectangle(canvas, px(0, 1), px(x_max, 0), rgb(20, 20, 20), 1);
  text(canvas, "number of demos", cv::Point((left + right) / 2 - 60, height - 15), 0.55);
  text(canvas, "success", cv::Point(8, top - 15), 0.55);
  text(canvas, "Closed-loop success (bars: Wilson 95% intervals)", cv::Point(left, 28), 0.65);

  std::vector<std::pair<std::string, std::string>> series;
  for (const Row& r : rows) {
    if (std::find(series.begin(), series.end(), std::make_pair(r.method, r.head)) == series.end()) {
      series.emplace_back(r.method, r.head);
    }
  }
  const std::uint64_t seed = rows.front().train_seed;
  for (std::size_t s = 0; s < series.size(); ++s) {
    const cv::Scalar colour = kColours[s % std::size(kColours)];
    std::vector<const Row*> points;
    for (const Row& r : rows) {
      if (r.method == series[s].first && r.head == series[s].second && r.train_seed == seed)
        points.push_back(&r);
    }
    std::sort(points.begin(), points.end(),
              [](const Row* a, const Row* b) { return a->demos < b->demos; });
    const int shift =
        static_cast<int>(std::lround((static_cast<double>(s) - 0.5 * (series.size() - 1)) * 5.0));
    const int ood_shift = shift + 7;
    const Row* previous = nullptr;
    for (const Row* r : points) {
      const double x = r->demos;
      if (r->id_success) {
        if (r->id_ci)
          cv::line(canvas, px(x, r->id_ci->lo, shift), px(x, r->id_ci->hi, shift), colour, 1,
                   cv::LINE_AA);
        if (previous && previous->id_success) {
          cv::line(canvas, px(previous->demos, *previous->id_success, shift),
                   px(x, *r->id_success, shift), colour, 2, cv::LINE_AA);
        }
        cv::circle(canvas, px(x, *r->id_success, shift), 5, colour, cv::FILLED, cv::LINE_AA);
      }
      if (r->ood_success) {
        if (r->ood_ci) {
          cv::line(canvas, px(x, r->ood_ci->lo, ood_shift), px(x, r->ood_ci->hi, ood_shift), colour,
                   1, cv::LINE_AA);
        }
        if (previous && previous->ood_success) {
          dashed(canvas, px(previous->demos, *previous->ood_success, ood_shift),
                 px(x, *r->ood_success, ood_shift), colour);
        }
        const cv::Point c = px(x, *r->ood_success, ood_shift);
        cv::rectangle(canvas, c - cv::Point(5, 5), c + cv::Point(5, 5), rgb(255, 255, 255),
                      cv::FILLED);
        cv::rectangle(canvas, c - cv::Point(5, 5), c + cv::Point(5, 5), colour, 2, cv::LINE_AA);
      }
      previous = r;
    }
    // Legend.
    const cv::Point at(right + 20, top + 20 + 28 * static_cast<int>(s));
    cv::line(canvas, at, at + cv::Point(30, 0), colour, 2, cv::LINE_AA);
    cv::circle(canvas, at + cv::Point(15, 0), 5, colour, cv::FILLED, cv::LINE_AA);
    text(canvas, series[s].first + "/" + series[s].second, at + cv::Point(40, 5));
  }
  const cv::Point key(right + 20, top + 40 + 28 * static_cast<int>(series.size()));
  cv::circle(canvas, key + cv::Point(15, 0), 5, rgb(90, 90, 90), cv::FILLED, cv::LINE_AA);
  text(canvas, "train-distribution scenes", key + cv::Point(40, 5));
  cv::rectangle(canvas, key + cv::Point(10, 23), key + cv::Point(20, 33), rgb(90, 90, 90), 2,
                cv::LINE_AA);
  text(canvas, "OOD scenes (own seed)", key + cv::Point(40, 33));
  char seed_text[64];
  std::snprintf(seed_text, sizeof seed_text, "training seed %llu",
                static_cast<unsigned long long>(seed));
  text(canvas, seed_text, key + cv::Point(40, 61));

  return drawing::to_image(canvas);
}

void write_table1_png(const std::string& path, const std::vector<Row>& rows) {
  sim::write_png(path, draw_table1(rows));
}

}  // namespace handcentric::experiments
