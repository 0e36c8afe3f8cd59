#include "handcentric/policy/c8_action.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/so3.hpp"

namespace handcentric::policy::c8 {

Eigen::Matrix3d rotation(int k) {
  const int m = ((k % 8) + 8) % 8;
  // Exact values at multiples of 90 deg; cos/sin of pi/4 otherwise.
  const double c = std::cos(m * std::numbers::pi / 4.0), s = std::sin(m * std::numbers::pi / 4.0);
  const double cr = m % 2 == 0 ? std::round(c) : c, sr = m % 2 == 0 ? std::round(s) : s;
  Eigen::Matrix3d R;
  R << cr, -sr, 0.0, sr, cr, 0.0, 0.0, 0.0, 1.0;
  return R;
}

Eigen::Matrix3d right_jacobian(const Eigen::Vector3d& r) {
  // Jr(r) = I - (1 - cos t) / t^2 [r]x + (t - sin t) / t^3 [r]x^2, t = |r|; series below 1e-4.
  const double t = r.norm();
  const Eigen::Matrix3d K = so3::hat(r);
  double a, b;
  if (t < 1e-4) {
    a = 0.5 - t * t / 24.0;
    b = 1.0 / 6.0 - t * t / 120.0;
  } else {
    a = (1.0 - std::cos(t)) / (t * t);
    b = (t - std::sin(t)) / (t * t * t);
  }
  return Eigen::Matrix3d::Identity() - a * K + b * K * K;
}

Eigen::Matrix3d right_jacobian_inverse(const Eigen::Vector3d& r) {
  // Jr^{-1}(r) = I + 1/2 [r]x + (1 / t^2 - cot(t / 2) / (2 t)) [r]x^2; finite at t = pi.
  const double t = r.norm();
  const Eigen::Matrix3d K = so3::hat(r);
  const double c =
      t < 1e-4 ? 1.0 / 12.0 + t * t / 720.0 : 1.0 / (t * t) - 1.0 / (2.0 * t * std::tan(t / 2.0));
  return Eigen::Matrix3d::Identity() + 0.5 * K + c * K * K;
}

namespace {
void check_length(Eigen::Index size, Eigen::Index expected, const std::string& what) {
  if (size != expected) {
    throw InvalidArgument("C8 action on " + what + ": length " + std::to_string(size) +
                          ", expected " + std::to_string(expected) +
                          " (an absolute vector of the trained layout)");
  }
}
void act_on_poses(const Eigen::Matrix3d& R, Eigen::Ref<Eigen::VectorXd> poses) {
  for (Eigen::Index i = 0; i + 6 <= poses.size(); i += 6) {
    poses.segment<3>(i) = R * poses.segment<3>(i);
    poses.segment<3>(i + 3) = so3::log(R * so3::exp(poses.segment<3>(i + 3)));
  }
}
}  // namespace

Eigen::VectorXd act_on_actions(const Eigen::Matrix3d& R, const Eigen::VectorXd& a) {
  check_length(a.size(), (a.size() / 6) * 6, "actions");
  Eigen::VectorXd out = a;
  act_on_poses(R, out);
  return out;
}

Eigen::VectorXd act_on_observation(const Eigen::Matrix3d& R, const Eigen::VectorXd& o,
                                   int history_length, int hand_points) {
  const Eigen::Index poses = 6 * (history_length + 1), hand = 3 * hand_points;
  if (o.size() < poses + hand || (o.size() - poses - hand) % 3 != 0) {
    check_length(o.size(), poses + hand, "observation");
  }
  Eigen::VectorXd out = o;
  act_on_poses(R, out.head(poses));
  for (Eigen::Index i = poses + hand; i + 3 <= out.size(); i += 3)
    out.segment<3>(i) = R * o.segment<3>(i);
  return out;
}

Eigen::VectorXd push_velocity(const Eigen::Matrix3d& R, const Eigen::VectorXd& a,
                              const Eigen::VectorXd& v) {
  check_length(v.size(), a.size(), "a velocity");
  check_length(a.size(), (a.size() / 6) * 6, "actions");
  Eigen::VectorXd out(v.size());
  for (Eigen::Index i = 0; i < a.size(); i += 6) {
    out.segment<3>(i) = R * v.segment<3>(i);
    const Eigen::Vector3d r = a.segment<3>(i + 3);
    const Eigen::Vector3d r_moved = so3::log(R * so3::exp(r));
    out.segment<3>(i + 3) =
        right_jacobian_inverse(r_moved) * (right_jacobian(r) * v.segment<3>(i + 3));
  }
  return out;
}

}  // namespace handcentric::policy::c8
