// The trajectory-optimization expert (expert.hpp): CHOMP-style smoothing with a random via point
// and a collision penalty, in the hole frame, then exact validation.
#include "handcentric/sim/expert.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "scene_helpers.hpp"

namespace handcentric::sim {
namespace {

/// cm per radian: how much a turn of the peg weighs against a translation in the smoothness cost
/// (about half the peg's length: the distance its tip moves per radian, halved).
constexpr double kAngleScale = 4.0;
constexpr double kViaWeight = 0.05;
constexpr double kCollisionWeight = 5.0;
constexpr double kStepSize = 0.5;
/// The penalty starts this far (cm) from the walls; the pre-insertion pose is ~1 cm away.
constexpr double kPenaltyMargin = 0.3;
constexpr double kFiniteDifference = 1e-4;
constexpr double kMaxUpdate = 0.25;
/// Via points (hole frame): a random point of the straight start -> pre-insertion line (fraction
/// in [0.3, 0.7]) moved by up to 3 cm sideways, -3..+2 cm up and +-15 deg: diverse demos without
/// loops, and low enough that some of them sit on the walls' tops.
constexpr double kViaMinFraction = 0.3, kViaMaxFraction = 0.7;
constexpr double kViaMaxAbsDx = 3.0, kViaMinDy = -3.0, kViaMaxDy = 2.0, kViaMaxAbsDegrees = 15.0;

using Vec3 = Eigen::Vector3d;  // u = (kAngleScale * theta, x, y)

double box_sdf(const Box& box, double px, double py) {
  const double dx = std::abs(px - 0.5 * (box.x0 + box.x1)) - 0.5 * (box.x1 - box.x0);
  const double dy = std::abs(py - 0.5 * (box.y0 + box.y1)) - 0.5 * (box.y1 - box.y0);
  const double outside = std::hypot(std::max(dx, 0.0), std::max(dy, 0.0));
  return outside + std::min(std::max(dx, dy), 0.0);
}

/// A smooth stand-in for the clearance (b2Distance gives 0 inside, with no gradient): points on
/// the peg's outline against the walls, and the walls' corners against the peg.
class ClearancePenalty {
 public:
  explicit ClearancePenalty(const PegHoleGeometry& geometry)
      : walls_(geometry.hole_walls()), peg_(geometry.peg_in_hand()) {
    const auto corners = geometry.peg_corners();
    for (int e = 0; e < 4; ++e) {
      const Vec3& a = corners[static_cast<std::size_t>(e)];
      const Vec3& b = corners[static_cast<std::size_t>((e + 1) % 4)];
      const int n = static_cast<int>(std::ceil((b - a).norm() / 0.25));
      for (int i = 0; i < n; ++i) outline_.push_back(a + (b - a) * (static_cast<double>(i) / n));
    }
    for (const Box& wall : walls_) {
      for (const double x : {wall.x0, wall.x1}) {
        for (const double y : {wall.y0, wall.y1}) wall_corners_.push_back(Vec3(x, y, 0.0));
      }
    }
  }

  double operator()(const Vec3& u) const {
    const RigidTransform hole_T_hand = RigidTransform::planar(u(0) / kAngleScale, u(1), u(2));
    double total = 0.0;
    for (const Vec3& hand_p : outline_) {
      const Vec3 hole_p = hole_T_hand * hand_p;
      for (const Box& wall : walls_) total += hinge(box_sdf(wall, hole_p.x(), hole_p.y()));
    }
    const RigidTransform hand_T_hole = hole_T_hand.inverse();
    for (const Vec3& hole_c : wall_corners_) {
      const Vec3 hand_c = hand_T_hole * hole_c;
      total += hinge(box_sdf(peg_, hand_c.x(), hand_c.y()));
    }
    return total;
  }

  Vec3 gradient(const Vec3& u) const {
    Vec3 g;
    for (int k = 0; k < 3; ++k) {
      Vec3 hi = u, lo = u;
      hi(k) += kFiniteDifference;
      lo(k) -= kFiniteDifference;
      g(k) = ((*this)(hi) - (*this)(lo)) / (2.0 * kFiniteDifference);
    }
    return g;
  }

 private:
  static double hinge(double sdf) {
    const double h = kPenaltyMargin - sdf;
    return h > 0.0 ? h * h : 0.0;
  }
  std::array<Box, 3> walls_;
  Box peg_;
  std::vector<Vec3> outline_;
  std::vector<Vec3> wall_corners_;
};

Vec3 to_u(const RigidTransform& pose) {
  const Vec3 q = planar_coordinates(pose);
  return Vec3(kAngleScale * q(0), q(1), q(2));
}

RigidTransform from_u(const Vec3& u) {
  return RigidTransform::planar(u(0) / kAngleScale, u(1), u(2));
}

using detail::uniform;

bool is_planar(const RigidTransform& pose) {
  const Eigen::Matrix4d M = pose.matrix();
  return std::abs(M(2, 3)) < 1e-9 && std::abs(M(2, 2) - 1.0) < 1e-9;
}

/// Every motion between consecutive poses collision-free, and the last one inserted.
bool is_valid(const std::vector<RigidTransform>& hole_T_hand, const CollisionChecker& checker) {
  for (std::size_t t = 0; t + 1 < hole_T_hand.size(); ++t) {
    if (checker.motion_collides(hole_T_hand[t], hole_T_hand[t + 1])) return false;
  }
  if (hole_T_hand.size() == 1 && checker.collides(hole_T_hand[0])) return false;
  return is_inserted(hole_T_hand.back(), checker.geometry());
}

}  // namespace

std::vector<RigidTransform> resample_at_control_step(const std::vector<RigidTransform>& path,
                                                     double step_cm, double step_deg) {
  if (path.empty()) throw InvalidArgument("resample_at_control_step: empty path");
  if (!(step_cm > 0.0) || !(step_deg > 0.0)) {
    throw InvalidArgument("control step limits must be positive, got " + std::to_string(step_cm) +
                          " cm and " + std::to_string(step_deg) + " deg");
  }
  const double step_rad = step_deg * std::numbers::pi / 180.0;
  std::vector<double> effort(path.size(),
                             0.0);  // cumulative: max(|dp| / step_cm, |dtheta| / step_rad)
  for (std::size_t i = 1; i < path.size(); ++i) {
    const RigidTransform delta = path[i - 1].inverse_compose(path[i]);
    effort[i] = effort[i - 1] +
                std::max(delta.translation().norm() / step_cm, delta.rotation().angle() / step_rad);
  }
  // 2% headroom keeps every step strictly inside the limits despite rounding
  const int steps = std::max(1, static_cast<int>(std::ceil(effort.back() / 0.98)));
  std::vector<RigidTransform> out{path.front()};
  std::size_t segment = 1;
  for (int k = 1; k < steps; ++k) {
    const double s = effort.back() * k / steps;
    while (segment + 1 < path.size() && effort[segment] < s) ++segment;
    const double length = effort[segment] - effort[segment - 1];
    const double f = length > 0.0 ? std::clamp((s - effort[segment - 1]) / length, 0.0, 1.0) : 1.0;
    out.push_back(interpolate_planar(path[segment - 1], path[segment], f));
  }
  if (path.size() > 1) out.push_back(path.back());
  return out;
}

ExpertPlan plan_in_hole_frame(const RigidTransform& hole_T_hand_start, std::mt19937_64& rng,
                              const CollisionChecker& checker, const ExpertOptions& options) {
  if (!is_planar(hole_T_hand_start)) throw InvalidArgument("expert: the start pose is not planar");
  if (!(options.arrival_weight >= 0.0) || !std::isfinite(options.arrival_weight)) {
    throw InvalidArgument("expert: arrival weight must be finite and >= 0, got " +
                          std::to_string(options.arrival_weight));
  }
  if (options.waypoints < 3 || options.iterations < 0) {
    throw InvalidArgument("expert: need at least 3 waypoints and >= 0 iterations, got " +
                          std::to_string(options.waypoints) + " and " +
                          std::to_string(options.iterations));
  }
  const int N = options.waypoints;
  const int free = N - 1;  // q_1 .. q_{N-1}
  const Vec3 start = to_u(hole_T_hand_start);
  const Vec3 pre(0.0, 0.0, kPegLength + kPreInsertionTipHeight);
  const Vec3 inserted(0.0, 0.0, kPegLength - kInsertionDepth);
  // quadratic part: |K q + e|^2 (squared accelerations) + w_via |q_m - via|^2
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(free, free);
  for (int i = 0; i < free; ++i) {
    K(i, i) = -2.0;
    if (i > 0) K(i, i - 1) = 1.0;
    if (i + 1 < free) K(i, i + 1) = 1.0;
  }
  Eigen::MatrixX3d e = Eigen::MatrixX3d::Zero(free, 3);
  e.row(0) += start.transpose();
  e.row(free - 1) += pre.transpose();
  Eigen::MatrixXd A = K.transpose() * K;
  Eigen::MatrixX3d b = -K.transpose() * e;
  // Arrival: the insertion continues the path, q_{N+1} = pre - s e_y with s = |start - pre| / N
  // the mean segment length, so the acceleration at q_N = pre is q_{N-1} - (pre + s e_y); it is
  // weighted options.arrival_weight: the approach arrives moving along the hole axis, without the
  // jump in lateral and angular velocity at pre-insertion that a policy would have to reproduce
  // exactly.
  const Vec3 above_pre = pre + Vec3(0.0, 0.0, (start - pre).norm() / N);
  A(free - 1, free - 1) += options.arrival_weight;
  b.row(free - 1) += options.arrival_weight * above_pre.transpose();
  if (options.random_via) {
    const int m = free / 2;
    const double fraction = uniform(rng, kViaMinFraction, kViaMaxFraction);
    // One draw per statement: the arguments of one call are evaluated in an unspecified order
    // (GCC right to left, clang left to right), which made the demos depend on the compiler.
    // This is GCC's order, so the demo files GCC builds made stay the same.
    const double dy = uniform(rng, kViaMinDy, kViaMaxDy);
    const double dx = uniform(rng, -kViaMaxAbsDx, kViaMaxAbsDx);
    const double degrees = uniform(rng, -kViaMaxAbsDegrees, kViaMaxAbsDegrees);
    const Vec3 offset(kAngleScale * degrees * std::numbers::pi / 180.0, dx, dy);
    const Vec3 via = start + fraction * (pre - start) + offset;
    A(m, m) += kViaWeight;
    b.row(m) += kViaWeight * via.transpose();
  }
  const Eigen::LDLT<Eigen::MatrixXd> A_inverse(A);
  Eigen::MatrixX3d q = A_inverse.solve(b);  // the smooth optimum, then pushed off the walls
  const ClearancePenalty penalty(checker.geometry());
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    Eigen::MatrixX3d gradient = A * q - b;
    bool touching = false;
    for (int i = 0; i < free; ++i) {
      const Vec3 u = q.row(i).transpose();
      if (penalty(u) > 0.0) {
        gradient.row(i) += kCollisionWeight * penalty.gradient(u).transpose();
        touching = true;
      }
    }
    if (!touching && iteration > 0) break;  // the quadratic part is already at its optimum
    Eigen::MatrixX3d update = kStepSize * A_inverse.solve(gradient);
    // a trust region: no waypoint moves more than kMaxUpdate per iteration (deep penetrations
    // have large penalty gradients, and A^{-1} spreads them along the whole trajectory)
    const double largest = update.rowwise().norm().maxCoeff();
    if (largest > kMaxUpdate) update *= kMaxUpdate / largest;
    q -= update;
  }
  std::vector<RigidTransform> path{hole_T_hand_start};
  for (int i = 0; i < free; ++i) path.push_back(from_u(q.row(i).transpose()));
  path.push_back(from_u(pre));
  path.push_back(from_u(inserted));
  ExpertPlan plan;
  plan.hole_T_hand = resample_at_control_step(path);
  // a demo must fit in a rollout's step budget (25 replans x 8 steps)
  plan.valid = static_cast<int>(plan.hole_T_hand.size()) <= kMaxDemoSteps &&
               is_valid(plan.hole_T_hand, checker);
  return plan;
}

ExpertRun expert_demo(const TaskScene& scene, std::uint64_t seed, std::uint64_t index,
                      const CollisionChecker& checker, const ExpertOptions& options) {
  std::mt19937_64 rng(stream_seed(seed, index));
  const RigidTransform hole_T_hand_start =
      scene.world_T_hole.inverse_compose(scene.world_T_hand_start);
  return first_valid_plan<Demo>(
      std::max(1, options.attempts),
      [&] { return plan_in_hole_frame(hole_T_hand_start, rng, checker, options); },
      [&](const ExpertPlan& plan) {
        Demo demo;
        demo.world_T_hole = scene.world_T_hole;
        demo.world_T_hand.push_back(
            scene.world_T_hand_start);  // exactly, not rounded through the hole frame
        for (std::size_t t = 1; t < plan.hole_T_hand.size(); ++t) {
          demo.world_T_hand.push_back(scene.world_T_hole * plan.hole_T_hand[t]);
        }
        return demo;
      });
}

ExpertRun expert_demos(const std::vector<TaskScene>& scenes, std::uint64_t seed,
                       const CollisionChecker& checker, const ExpertOptions& options) {
  return on_every_scene<Demo>(scenes, [&](const TaskScene& scene, std::size_t i) {
    return expert_demo(scene, seed, i, checker, options);
  });
}

}  // namespace handcentric::sim
