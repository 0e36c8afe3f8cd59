// The MLP's hand-written backprop, the losses, Adam and the noise, checked against finite
// differences in double and against planted faults.
#include <catch2/catch.hpp>

#include <cmath>
#include <functional>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/policy/adam.hpp"
#include "handcentric/policy/cvae_loss.hpp"
#include "handcentric/policy/gaussian.hpp"
#include "handcentric/policy/losses.hpp"
#include "handcentric/policy/mlp.hpp"
#include "handcentric/policy/time_embedding.hpp"
#include "throws.hpp"
#include "worst_error.hpp"  // tests/support

using namespace handcentric;
using namespace handcentric::policy;
using MlpD = MlpT<double>;

namespace {

// A scalar loss of the network output: L = sum(weights .* output) + 1/2 |output|^2, so that
// dL/doutput = weights + output exercises every output entry.
double probe_loss(const Eigen::MatrixXd& output, const Eigen::MatrixXd& weights) {
  return (weights.array() * output.array()).sum() + 0.5 * output.squaredNorm();
}

struct GradientErrors {
  double parameters = 0.0;  ///< max |analytic - numeric| / (1 + |numeric|) over the parameters
  double input = 0.0;       ///< the same over the input
};

// Central differences (step 1e-6) of probe_loss through `numeric_net` against the backprop of
// `net`; `fault` may plant an error in the analytic gradient.
GradientErrors gradient_errors(MlpD& net, MlpD& numeric_net, const Eigen::MatrixXd& input,
                               const Eigen::MatrixXd& weights,
                               const std::function<void(Eigen::VectorXd&)>& fault = {}) {
  const Eigen::MatrixXd output = net.forward(input);
  Eigen::MatrixXd d_input = net.backward(weights + output);
  Eigen::VectorXd analytic = net.gradient();
  if (fault) fault(analytic);
  const double h = 1e-6;
  GradientErrors errors;
  const auto loss_at = [&](const Eigen::MatrixXd& x) {
    return probe_loss(numeric_net.forward(x), weights);
  };
  numeric_net.parameters() = net.parameters();
  for (Eigen::Index i = 0; i < net.parameter_count(); ++i) {
    const double saved = numeric_net.parameters()[i];
    numeric_net.parameters()[i] = saved + h;
    const double plus = loss_at(input);
    numeric_net.parameters()[i] = saved - h;
    const double minus = loss_at(input);
    numeric_net.parameters()[i] = saved;
    const double numeric = (plus - minus) / (2 * h);
    errors.parameters =
        std::max(errors.parameters, std::abs(analytic[i] - numeric) / (1.0 + std::abs(numeric)));
  }
  for (Eigen::Index i = 0; i < input.size(); ++i) {
    Eigen::MatrixXd x = input;
    x(i) += h;
    const double plus = loss_at(x);
    x(i) -= 2 * h;
    const double minus = loss_at(x);
    const double numeric = (plus - minus) / (2 * h);
    errors.input =
        std::max(errors.input, std::abs(d_input(i) - numeric) / (1.0 + std::abs(numeric)));
  }
  return errors;
}

struct MlpProblem {
  MlpD net;
  Eigen::MatrixXd input, weights;
};

MlpProblem make_mlp_problem(Activation activation, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  MlpProblem problem{MlpD({5, 7, 6, 3}, activation), Eigen::MatrixXd(5, 4), Eigen::MatrixXd(3, 4)};
  problem.net.initialize(rng);
  // Inputs away from 0 so that no ReLU pre-activation sits within h of its kink.
  for (Eigen::Index i = 0; i < problem.input.size(); ++i)
    problem.input(i) = 2.0 * uniform01(rng) - 1.0;
  for (Eigen::Index i = 0; i < problem.weights.size(); ++i)
    problem.weights(i) = 2.0 * uniform01(rng) - 1.0;
  return problem;
}

// Finite-difference agreement for well-conditioned central differences of a smooth function in
// double: truncation ~h^2 = 1e-12, rounding ~eps/h = 1e-10; 1e-6 leaves a wide margin and still
// catches any real error (those are O(1) relative).
constexpr double kGradientTolerance = 1e-6;

}  // namespace

TEST_CASE("mlp_backprop_matches_finite_differences_for_every_layer", "[unit]") {
  for (Activation activation : {Activation::silu, Activation::relu}) {
    INFO(to_string(activation));
    MlpProblem p = make_mlp_problem(activation, 7);
    MlpD numeric = p.net;
    const GradientErrors errors = gradient_errors(p.net, numeric, p.input, p.weights);
    CHECK(errors.parameters < kGradientTolerance);
    CHECK(errors.input < kGradientTolerance);
  }
}

TEST_CASE("mutant_gradients_fail_the_finite_difference_check", "[unit]") {
  MlpProblem p = make_mlp_problem(Activation::silu, 7);
  MlpD numeric = p.net;
  // A dropped bias gradient of the last layer (the last 3 parameters are b_3).
  const auto drop_last_bias = [](Eigen::VectorXd& g) { g.tail(3).setZero(); };
  CHECK(gradient_errors(p.net, numeric, p.input, p.weights, drop_last_bias).parameters > 1e-2);
  // A SiLU network's backprop against the numeric gradient of the same weights under ReLU:
  // a wrong activation derivative.
  MlpD relu({5, 7, 6, 3}, Activation::relu);
  CHECK(gradient_errors(p.net, relu, p.input, p.weights).parameters > 1e-2);
}

TEST_CASE("mse_and_kl_gradients_match_finite_differences", "[unit]") {
  std::mt19937_64 rng(3);
  Eigen::MatrixXd pred(3, 4), target(3, 4), mu(2, 4), log_var(2, 4);
  for (Eigen::MatrixXd* m : {&pred, &target, &mu, &log_var}) {
    for (Eigen::Index i = 0; i < m->size(); ++i) (*m)(i) = 2.0 * uniform01(rng) - 1.0;
  }
  Eigen::MatrixXd d_pred, d_mu, d_log_var, scratch_a, scratch_b;
  mse_loss<double>(pred, target, d_pred);
  gaussian_kl_loss<double>(mu, log_var, 0.3, d_mu, d_log_var);
  const double h = 1e-6;
  double worst = 0.0;
  for (Eigen::Index i = 0; i < pred.size(); ++i) {
    Eigen::MatrixXd plus = pred, minus = pred;
    plus(i) += h;
    minus(i) -= h;
    const double numeric =
        (mse_loss<double>(plus, target, scratch_a) - mse_loss<double>(minus, target, scratch_a)) /
        (2 * h);
    worst = test::worst_of(worst, std::abs(numeric - d_pred(i)));
  }
  for (Eigen::Index i = 0; i < mu.size(); ++i) {
    Eigen::MatrixXd plus = mu, minus = mu;
    plus(i) += h;
    minus(i) -= h;
    double numeric = (gaussian_kl_loss<double>(plus, log_var, 0.3, scratch_a, scratch_b) -
                      gaussian_kl_loss<double>(minus, log_var, 0.3, scratch_a, scratch_b)) /
                     (2 * h);
    worst = test::worst_of(worst, std::abs(numeric - d_mu(i)));
    plus = log_var;
    minus = log_var;
    plus(i) += h;
    minus(i) -= h;
    numeric = (gaussian_kl_loss<double>(mu, plus, 0.3, scratch_a, scratch_b) -
               gaussian_kl_loss<double>(mu, minus, 0.3, scratch_a, scratch_b)) /
              (2 * h);
    worst = test::worst_of(worst, std::abs(numeric - d_log_var(i)));
  }
  CHECK(worst < kGradientTolerance);
  // Planted fault: the gradient of the mean absolute error is not that of the MSE.
  CHECK((d_pred - (pred - target).cwiseSign() / static_cast<double>(pred.size()))
            .cwiseAbs()
            .maxCoeff<Eigen::PropagateNaN>() > 1e-3);
}

TEST_CASE("adam_minimizes_a_quadratic_and_clipping_bounds_the_norm", "[unit]") {
  Eigen::VectorXf x = Eigen::VectorXf::Constant(4, 3.0f);
  Adam adam(4, AdamOptions{0.05, 0.9, 0.999, 1e-8, 0.0});
  for (int i = 0; i < 2000; ++i) {
    Eigen::VectorXf gradient = 2.0f * (x - Eigen::VectorXf::LinSpaced(4, -1.0f, 1.0f));
    adam.step(x, gradient);
  }
  CHECK(
      (x - Eigen::VectorXf::LinSpaced(4, -1.0f, 1.0f)).cwiseAbs().maxCoeff<Eigen::PropagateNaN>() <
      1e-3f);
  Eigen::VectorXf g = Eigen::VectorXf::Constant(4, 10.0f);
  CHECK(clip_gradient_norm(g, 1.0) == Approx(20.0));
  CHECK(g.norm() == Approx(1.0f));
  HC_CHECK_THROWS(Adam(4, AdamOptions{-1.0}), InvalidArgument, Catch::Contains("lr > 0"));
}

TEST_CASE("standard_normal_noise_is_seeded_and_standard", "[unit]") {
  std::mt19937_64 a(11), b(11);
  Eigen::MatrixXf x(100, 100), y(100, 100);
  fill_standard_normal(a, x);
  fill_standard_normal(b, y);
  CHECK(x == y);
  CHECK(std::abs(x.mean()) < 0.02f);  // 10^4 samples: the mean's standard error is 0.01
  CHECK(std::abs(x.squaredNorm() / 1e4f - 1.0f) < 0.05f);
}

TEST_CASE("sinusoidal_time_features_are_bounded_and_distinguish_times", "[unit]") {
  Eigen::VectorXf a(16), b(16);
  time_features(0.3, 16, a);
  time_features(0.31, 16, b);
  CHECK(a.cwiseAbs().maxCoeff<Eigen::PropagateNaN>() <= 1.0f);
  CHECK((a - b).norm() > 1e-2f);
  Eigen::VectorXf raw(1);
  time_features(0.3, 0, raw);
  CHECK(raw[0] == 0.3f);
  HC_CHECK_THROWS(time_features(0.3, 16, raw), InvalidArgument, Catch::Contains("expected 16"));
}

TEST_CASE("mlp_rejects_bad_shapes", "[unit]") {
  HC_CHECK_THROWS(MlpD({5}, Activation::silu), InvalidArgument, Catch::Contains("at least"));
  HC_CHECK_THROWS(MlpD({5, 0, 2}, Activation::silu), InvalidArgument, Catch::Contains("is 0"));
  MlpD net({5, 3}, Activation::silu);
  HC_CHECK_THROWS(net.forward(Eigen::MatrixXd::Zero(4, 2)), InvalidArgument,
                  Catch::Contains("expected 5"));
}

TEST_CASE("cvae_loss_gradients_match_finite_differences_through_the_reparameterization", "[unit]") {
  std::mt19937_64 rng(5);
  const int da = 3, dobs = 2, Z = 2, batch = 4;
  MlpD encoder({da + dobs, 6, 2 * Z}, Activation::silu),
      decoder({Z + dobs, 6, da}, Activation::silu);
  encoder.initialize(rng);
  decoder.initialize(rng);
  Eigen::MatrixXd a(da, batch), o(dobs, batch), noise(Z, batch);
  for (Eigen::MatrixXd* m : {&a, &o, &noise}) {
    for (Eigen::Index i = 0; i < m->size(); ++i) (*m)(i) = 2.0 * uniform01(rng) - 1.0;
  }
  CvaeBuffers<double> buffers;
  const auto loss = [&](MlpD& e, MlpD& d) {
    return cvae_loss_and_gradients<double>(e, d, a, o, noise, 0.3, buffers);
  };
  loss(encoder, decoder);
  const Eigen::VectorXd encoder_gradient = encoder.gradient(),
                        decoder_gradient = decoder.gradient();
  const double h = 1e-6;
  const auto worst_error = [&](MlpD& net, const Eigen::VectorXd& analytic) {
    double worst = 0.0;
    for (Eigen::Index i = 0; i < net.parameter_count(); ++i) {
      const double saved = net.parameters()[i];
      net.parameters()[i] = saved + h;
      const double plus = loss(encoder, decoder);
      net.parameters()[i] = saved - h;
      const double minus = loss(encoder, decoder);
      net.parameters()[i] = saved;
      const double numeric = (plus - minus) / (2 * h);
      worst = test::worst_of(worst, std::abs(analytic[i] - numeric) / (1.0 + std::abs(numeric)));
    }
    return worst;
  };
  CHECK(worst_error(encoder, encoder_gradient) < kGradientTolerance);
  CHECK(worst_error(decoder, decoder_gradient) < kGradientTolerance);
  // Planted fault: the encoder gradient off by a factor of 2 (as a dropped factor of the MSE would
  // be).
  Eigen::VectorXd wrong = encoder_gradient;
  wrong *= 0.5;
  CHECK(worst_error(encoder, wrong) > 1e-3);
}
