#include "handcentric/core/sampling.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "handcentric/core/errors.hpp"

namespace handcentric {

double uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

double standard_normal(std::mt19937_64& rng) {
  const double u1 = 1.0 - uniform01(rng);  // (0, 1]: log is finite
  const double u2 = uniform01(rng);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

Rotation shoemake_rotation(double u1, double u2, double u3) {
  // Shoemake (1992), "Uniform random rotations", Graphics Gems III.
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  const double t1 = 2.0 * std::numbers::pi * u2, t2 = 2.0 * std::numbers::pi * u3;
  return Rotation::from_quaternion(b * std::cos(t2), a * std::sin(t1), a * std::cos(t1),
                                   b * std::sin(t2));
}

namespace {

// t - sin t without the cancellation of its two terms at small t: below 1 rad, the Taylor
// series t^3/3! - t^5/5! + ... (ten terms leave less than 1e-19 of the first).
double t_minus_sin(double t) {
  if (t >= 1.0) return t - std::sin(t);
  const double t2 = t * t;
  double term = t * t2 / 6.0, sum = 0.0;
  for (int n = 1; n <= 10; ++n) {
    sum += term;
    term *= -t2 / ((2.0 * n + 2.0) * (2.0 * n + 3.0));
  }
  return sum;
}

}  // namespace

double haar_angle(double u) {
  constexpr double kPi = std::numbers::pi;
  if (!(u > 0.0)) return 0.0;
  if (u >= 1.0) return kPi;
  // Solve F(t) = (t - sin t) / pi = u by Newton's method, kept inside a bracket of the root
  // (bisection when a step leaves it). t - sin t <= t^3 / 6, so cbrt(6 pi u) starts at or below
  // the root; F is convex on [0, pi], so after one step the iterates fall monotonically to it.
  const double target = kPi * u;
  double low = 0.0, high = kPi;
  double t = std::min(std::cbrt(6.0 * target), kPi);
  for (int i = 0; i < 100; ++i) {
    const double f = t_minus_sin(t) - target;
    if (f == 0.0) break;
    (f < 0.0 ? low : high) = t;
    const double half_sine = std::sin(0.5 * t);
    const double step = f / (2.0 * half_sine * half_sine);  // pi F'(t) = 1 - cos t
    if (std::abs(step) <= 4.0 * std::numeric_limits<double>::epsilon() * t) {
      t -= step;
      break;
    }
    t -= step;
    if (!(t > low && t < high)) t = 0.5 * (low + high);
  }
  return t;
}

namespace {

Eigen::Vector3d uniform_box(std::mt19937_64& rng, double max_abs) {
  Eigen::Vector3d p;
  for (int i = 0; i < 3; ++i) p(i) = max_abs * (2.0 * uniform01(rng) - 1.0);
  return p;
}

}  // namespace

Eigen::Vector3d sphere_point(double u1, double u2) {
  const double z = 2.0 * u1 - 1.0;  // Archimedes: z is uniform on the sphere
  const double theta = 2.0 * std::numbers::pi * u2;
  const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
  return Eigen::Vector3d(s * std::cos(theta), s * std::sin(theta), z);
}

Rotation random_rotation(std::mt19937_64& rng) {
  const double u1 = uniform01(rng), u2 = uniform01(rng), u3 = uniform01(rng);
  return shoemake_rotation(u1, u2, u3);
}

Rotation random_rotation_with_angle(std::mt19937_64& rng, double angle) {
  const double u1 = uniform01(rng), u2 = uniform01(rng);
  return Rotation::exp(angle * sphere_point(u1, u2));
}

RigidTransform random_transform(std::mt19937_64& rng, double max_abs) {
  const Rotation R = random_rotation(rng);
  return RigidTransform(R, uniform_box(rng, max_abs));
}

namespace {

RigidTransform random_step(std::mt19937_64& rng) {
  Twist twist;
  twist << uniform_box(rng, 0.1), uniform_box(rng, 0.3);
  return RigidTransform::exp(twist);
}

}  // namespace

Scene random_scene(std::mt19937_64& rng, int H, int K, int hand_points, int world_points,
                   double max_abs) {
  if (H < 0 || K < 1 || hand_points < 0 || world_points < 0) {
    throw InvalidArgument(
        "random_scene needs H >= 0, K >= 1 and non-negative point counts, got H = " +
        std::to_string(H) + ", K = " + std::to_string(K));
  }
  Scene scene;
  scene.world_T_hand_history.push_back(random_transform(rng, max_abs));
  const RigidTransform step_forward = random_step(rng), step_backward = random_step(rng);
  for (int h = 1; h <= H; ++h) {
    scene.world_T_hand_history.push_back(scene.world_T_hand_history.back() * step_backward);
  }
  RigidTransform world_T_handk = scene.world_T_hand0();
  for (int k = 1; k <= K; ++k) {
    world_T_handk = world_T_handk * step_forward;
    scene.world_T_hand_chunk.push_back(world_T_handk);
  }
  for (int i = 0; i < hand_points; ++i) scene.hand_points.push_back(uniform_box(rng, 1.0));
  for (int i = 0; i < world_points; ++i) scene.world_points.push_back(uniform_box(rng, max_abs));
  return scene;
}

}  // namespace handcentric
