// SpatialSoftmax (spatial_softmax.hpp), the soft-argmax after the image encoder, against a
// double-precision reference written here from the definition (each channel's softmax over its
// own (y, x) grid, stored [b][c][y][x], not the layer's channels-fastest order): forward and
// backward on odd maps, one channel, one pixel, and logits large enough to overflow exp without
// the shift. The reference's backward is checked by central differences of its forward. Each
// check is seen failing on a planted fault (a reference whose pixel centres are off by half a
// pixel, or whose backward leaves out the expectation it subtracts).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/policy/spatial_softmax.hpp"
#include "throws.hpp"
#include "worst_error.hpp"  // tests/support

using namespace handcentric;
using namespace handcentric::policy;
using Catch::Matchers::Contains;

namespace {

enum class SoftmaxFault { none, half_pixel, no_centring };

// maps: the layer's storage, ((y width + x) channels + c) per column.
struct SoftArgmaxReference {
  ImageShape map;
  SoftmaxFault fault = SoftmaxFault::none;

  double u(int x) const {
    return (2.0 * x + (fault == SoftmaxFault::half_pixel ? 0.0 : 1.0)) / map.width - 1.0;
  }
  double v(int y) const { return (2.0 * y + 1.0) / map.height - 1.0; }
  double logit(const Eigen::MatrixXd& maps, int b, int c, int y, int x) const {
    return maps((static_cast<Eigen::Index>(y) * map.width + x) * map.channels + c, b);
  }
  // p[b][c][y][x] by the definition, exp of (z - max) for large logits.
  std::vector<double> probabilities(const Eigen::MatrixXd& maps) const {
    std::vector<double> p(static_cast<std::size_t>(maps.cols()) * map.size());
    for (Eigen::Index b = 0; b < maps.cols(); ++b) {
      for (int c = 0; c < map.channels; ++c) {
        double largest = -INFINITY, total = 0;
        for (int y = 0; y < map.height; ++y)
          for (int x = 0; x < map.width; ++x) largest = std::max(largest, logit(maps, b, c, y, x));
        for (int y = 0; y < map.height; ++y)
          for (int x = 0; x < map.width; ++x) total += std::exp(logit(maps, b, c, y, x) - largest);
        for (int y = 0; y < map.height; ++y) {
          for (int x = 0; x < map.width; ++x) {
            p[at(b, c, y, x)] = std::exp(logit(maps, b, c, y, x) - largest) / total;
          }
        }
      }
    }
    return p;
  }
  std::size_t at(Eigen::Index b, int c, int y, int x) const {
    return static_cast<std::size_t>(((b * map.channels + c) * map.height + y) * map.width + x);
  }
  Eigen::MatrixXd forward(const Eigen::MatrixXd& maps) const {
    const std::vector<double> p = probabilities(maps);
    Eigen::MatrixXd points = Eigen::MatrixXd::Zero(2 * map.channels, maps.cols());
    for (Eigen::Index b = 0; b < maps.cols(); ++b) {
      for (int c = 0; c < map.channels; ++c) {
        for (int y = 0; y < map.height; ++y) {
          for (int x = 0; x < map.width; ++x) {
            points(2 * c, b) += p[at(b, c, y, x)] * u(x);
            points(2 * c + 1, b) += p[at(b, c, y, x)] * v(y);
          }
        }
      }
    }
    return points;
  }
  // d <g, forward(z)> / dz by the softmax's Jacobian, dp_i/dz_j = p_i (delta_ij - p_j).
  Eigen::MatrixXd backward(const Eigen::MatrixXd& maps, const Eigen::MatrixXd& g) const {
    const std::vector<double> p = probabilities(maps);
    const Eigen::MatrixXd points = forward(maps);
    const bool centred = fault != SoftmaxFault::no_centring;
    Eigen::MatrixXd d = Eigen::MatrixXd::Zero(maps.rows(), maps.cols());
    for (Eigen::Index b = 0; b < maps.cols(); ++b) {
      for (int c = 0; c < map.channels; ++c) {
        for (int y = 0; y < map.height; ++y) {
          for (int x = 0; x < map.width; ++x) {
            const double du = u(x) - (centred ? points(2 * c, b) : 0.0);
            const double dv = v(y) - (centred ? points(2 * c + 1, b) : 0.0);
            d((static_cast<Eigen::Index>(y) * map.width + x) * map.channels + c, b) =
                p[at(b, c, y, x)] * (g(2 * c, b) * du + g(2 * c + 1, b) * dv);
          }
        }
      }
    }
    return d;
  }
};

Eigen::MatrixXd uniform_matrix(Eigen::Index rows, Eigen::Index cols, double scale,
                               std::mt19937_64& rng) {
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m(i) = scale * (2.0 * uniform01(rng) - 1.0);
  return m;
}

double largest_relative_error(const Eigen::MatrixXd& got, const Eigen::MatrixXd& want) {
  return (got - want).cwiseAbs().maxCoeff<Eigen::PropagateNaN>() /
         (1.0 + want.cwiseAbs().maxCoeff<Eigen::PropagateNaN>());
}

struct SoftmaxCase {
  ImageShape map;
  int batch;
  double scale;  ///< logits uniform in +-scale
};

// Odd maps, one channel, a single pixel, a row, and logits of +-200 (exp overflows float
// without the shift by the largest).
const SoftmaxCase kSoftmaxCases[] = {
    {{3, 5, 7}, 4, 3.0}, {{1, 12, 16}, 3, 2.0}, {{16, 6, 8}, 2, 1.0},
    {{2, 1, 1}, 2, 1.0}, {{5, 1, 9}, 3, 4.0},   {{4, 3, 4}, 2, 200.0},
};

}  // namespace

TEST_CASE("spatial_softmax_matches_the_double_reference", "[unit]") {
  constexpr double kTolerance = 2e-5;  // float32 sums over at most 192 pixels
  std::mt19937_64 rng(61);
  for (const SoftmaxCase& c : kSoftmaxCases) {
    INFO("map " << c.map.channels << " x " << c.map.height << " x " << c.map.width << ", batch "
                << c.batch << ", logits +-" << c.scale);
    SpatialSoftmax layer(c.map);
    REQUIRE(layer.output_size() == 2 * c.map.channels);
    const Eigen::MatrixXd maps = uniform_matrix(c.map.size(), c.batch, c.scale, rng);
    const Eigen::MatrixXd g = uniform_matrix(layer.output_size(), c.batch, 1.0, rng);
    const Eigen::MatrixXd points = layer.forward(maps.cast<float>()).cast<double>();
    const Eigen::MatrixXd d_maps = layer.backward(g.cast<float>()).cast<double>();
    REQUIRE(points.allFinite());
    REQUIRE(d_maps.allFinite());
    const SoftArgmaxReference reference{c.map};
    CHECK(largest_relative_error(points, reference.forward(maps)) < kTolerance);
    CHECK(largest_relative_error(d_maps, reference.backward(maps, g)) < kTolerance);
    // Planted faults: the check tells a half-pixel shift of the centres and a backward without
    // the expectation subtracted (on maps of more than one pixel, where either changes a thing).
    const SoftArgmaxReference shifted{c.map, SoftmaxFault::half_pixel};
    const SoftArgmaxReference uncentred{c.map, SoftmaxFault::no_centring};
    if (c.map.width > 1)
      CHECK(largest_relative_error(points, shifted.forward(maps)) > 10 * kTolerance);
    if (c.map.width * c.map.height > 1)
      CHECK(largest_relative_error(d_maps, uncentred.backward(maps, g)) > 10 * kTolerance);
  }
}

TEST_CASE("the_soft_argmax_reference_backward_matches_central_differences", "[unit]") {
  std::mt19937_64 rng(67);
  const SoftmaxCase& c = kSoftmaxCases[0];
  const Eigen::MatrixXd maps = uniform_matrix(c.map.size(), c.batch, c.scale, rng);
  const Eigen::MatrixXd g = uniform_matrix(2 * c.map.channels, c.batch, 1.0, rng);
  const SoftArgmaxReference reference{c.map};
  const SoftArgmaxReference uncentred{c.map, SoftmaxFault::no_centring};
  const Eigen::MatrixXd exact = reference.backward(maps, g);
  const Eigen::MatrixXd wrong = uncentred.backward(maps, g);
  const auto loss = [&](const Eigen::MatrixXd& z) {
    return (reference.forward(z).array() * g.array()).sum();
  };
  const double h = 1e-6;
  double worst = 0, worst_wrong = 0;
  for (Eigen::Index i = 0; i < maps.size(); ++i) {
    Eigen::MatrixXd z = maps;
    z(i) += h;
    const double plus = loss(z);
    z(i) -= 2 * h;
    const double numeric = (plus - loss(z)) / (2 * h);
    worst = test::worst_of(worst, std::abs(numeric - exact(i)));
    worst_wrong = test::worst_of(worst_wrong, std::abs(numeric - wrong(i)));
  }
  CHECK(worst < 1e-8);
  CHECK(worst_wrong > 1e-3);  // planted fault: the expectation not subtracted
}

TEST_CASE("the_soft_argmax_finds_a_peak_between_pixel_centres", "[unit]") {
  // Two equal logits side by side put the point halfway between their centres, which no
  // argmax (and no flattened map of pixels) can say.
  const ImageShape map{1, 3, 4};
  SpatialSoftmax layer(map);
  Eigen::MatrixXf z = Eigen::MatrixXf::Constant(map.size(), 1, -60.0f);
  z((1 * 4 + 1), 0) = 0.0f;
  z((1 * 4 + 2), 0) = 0.0f;
  const Eigen::MatrixXf points = layer.forward(z);
  CHECK(points(0, 0) == Approx(0.0).margin(1e-6));  // halfway between x = 1 and 2 of 4
  CHECK(points(1, 0) == Approx(0.0).margin(1e-6));  // the middle row of 3
}

TEST_CASE("spatial_softmax_shapes_are_refused_with_the_value_and_the_fix", "[unit]") {
  HC_CHECK_THROWS(SpatialSoftmax(ImageShape{0, 4, 4}), InvalidArgument,
                  Contains("0 x 4 x 4 is empty"));
  SpatialSoftmax layer(ImageShape{2, 3, 3});
  HC_CHECK_THROWS(layer.backward(Eigen::MatrixXf::Zero(4, 1)), InvalidArgument,
                  Contains("call forward() first"));
  HC_CHECK_THROWS(layer.forward(Eigen::MatrixXf::Zero(17, 2)), InvalidArgument,
                  Contains("17 rows, expected 18"));
  layer.forward(Eigen::MatrixXf::Zero(18, 2));
  HC_CHECK_THROWS(layer.backward(Eigen::MatrixXf::Zero(4, 3)), InvalidArgument,
                  Contains("expected 4x2"));
}
