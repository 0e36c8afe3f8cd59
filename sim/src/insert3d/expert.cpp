#include "handcentric/sim/insert3d/expert.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/core/so3.hpp"
#include "handcentric/sim/scenes.hpp"
#include "../scene_helpers.hpp"

namespace handcentric::sim::insert3d {
namespace {

using detail::radians;
using detail::uniform;

// The step limits with a 2% margin, so rounding never takes a step past them.
constexpr double kStepCm = 0.98 * kMaxStepCm;
const double kStepAngle = 0.98 * radians(kMaxStepDeg);

RigidTransform pre_insertion() {
  return RigidTransform::from_translation(
      Eigen::Vector3d(0.0, 0.0, kBladeLength + kPreInsertionTipHeight));
}

/// The approach curve of expert.hpp, step 1.
class Approach {
 public:
  Approach(const RigidTransform& slot_T_hand_start, const Eigen::Vector3d& via,
           const Eigen::Vector3d& wiggle)
      : start_(slot_T_hand_start),
        via_(via),
        wiggle_(wiggle),
        turn_(so3::log(slot_T_hand_start.rotation().matrix().transpose())) {}

  RigidTransform at(double s) const {
    const Eigen::Vector3d p0 = start_.translation();
    const Eigen::Vector3d p3 = pre_insertion().translation();
    const Eigen::Vector3d p2 = p3 + Eigen::Vector3d(0.0, 0.0, kArrivalLift);
    const double r = 1.0 - s;
    const Eigen::Vector3d p =
        r * r * r * p0 + 3.0 * r * r * s * via_ + 3.0 * r * s * s * p2 + s * s * s * p3;
    const double eased = s * s * (3.0 - 2.0 * s);
    const double bump = 16.0 * s * s * r * r;
    const Eigen::Matrix3d R =
        start_.rotation().matrix() * so3::exp(eased * turn_) * so3::exp(bump * wiggle_);
    return RigidTransform::unchecked(R, p);
  }

 private:
  RigidTransform start_;
  Eigen::Vector3d via_;
  Eigen::Vector3d wiggle_;
  Eigen::Vector3d turn_;
};

bool within_step_limits(const RigidTransform& a, const RigidTransform& b) {
  return (b.translation() - a.translation()).norm() <= kStepCm &&
         so3::angle(a.rotation().inverse_compose(b.rotation()).matrix()) <= kStepAngle;
}

/// The fewest even steps of `path` over [0, 1] that keep every step within the limits (more
/// than kMaxDemoSteps: the plan is too long and gives up).
template <typename Path>
std::vector<RigidTransform> resample(const Path& path) {
  for (int n = 1; n <= kMaxDemoSteps; ++n) {
    std::vector<RigidTransform> poses{path(0.0)};
    bool ok = true;
    for (int i = 1; i <= n && ok; ++i) {
      poses.push_back(i == n ? path(1.0) : path(static_cast<double>(i) / n));
      ok = within_step_limits(poses[poses.size() - 2], poses.back());
    }
    if (ok) return poses;
  }
  return {};
}

}  // namespace

void ExpertOptions::validate() const {
  if (attempts < 1) {
    throw InvalidArgument("expert attempts per scene must be >= 1, got " +
                          std::to_string(attempts) + "; e.g. 8");
  }
}

ExpertPlan plan_in_slot_frame(const RigidTransform& slot_T_hand_start, std::mt19937_64& rng,
                              const CollisionChecker& checker, const ExpertOptions& options) {
  const Eigen::Vector3d p0 = slot_T_hand_start.translation();
  const Eigen::Vector3d p3 = pre_insertion().translation();
  Eigen::Vector3d via = 0.5 * (p0 + p3);
  Eigen::Vector3d wiggle = Eigen::Vector3d::Zero();
  if (options.random_via) {
    const double u = uniform(rng, 0.3, 0.7);
    via =
        (1.0 - u) * p0 + u * p3 +
        Eigen::Vector3d(uniform(rng, -3.0, 3.0), uniform(rng, -3.0, 3.0), uniform(rng, -1.0, 3.0));
    wiggle = radians(uniform(rng, 0.0, 15.0)) * sphere_point(uniform01(rng), uniform01(rng));
  }
  const Approach approach(slot_T_hand_start, via, wiggle);
  ExpertPlan plan;
  plan.slot_T_hand = resample([&approach](double s) { return approach.at(s); });
  const RigidTransform pre = plan.slot_T_hand.empty() ? pre_insertion() : plan.slot_T_hand.back();
  const RigidTransform inserted_pose =
      RigidTransform::from_translation(Eigen::Vector3d(0.0, 0.0, kBladeLength - kInsertionDepth));
  const std::vector<RigidTransform> insertion =
      resample([&pre, &inserted_pose](double s) { return interpolate(pre, inserted_pose, s); });
  if (plan.slot_T_hand.empty() || insertion.empty()) return plan;
  plan.slot_T_hand.insert(plan.slot_T_hand.end(), insertion.begin() + 1, insertion.end());
  if (static_cast<int>(plan.slot_T_hand.size()) > kMaxDemoSteps) return plan;
  if (checker.collides(plan.slot_T_hand.front())) return plan;
  for (std::size_t i = 1; i < plan.slot_T_hand.size(); ++i) {
    if (checker.motion_collides(plan.slot_T_hand[i - 1], plan.slot_T_hand[i])) return plan;
  }
  plan.valid = inserted(checker.geometry(), plan.slot_T_hand.back());
  return plan;
}

ExpertRun expert_demo(const TaskScene& scene, std::uint64_t seed, std::uint64_t index,
                      const CollisionChecker& checker, const ExpertOptions& options) {
  options.validate();
  std::mt19937_64 rng(stream_seed(seed, index));
  const RigidTransform slot_T_hand_start =
      scene.world_T_slot.inverse_compose(scene.world_T_hand_start);
  return first_valid_plan<Demo>(
      options.attempts,
      [&] { return plan_in_slot_frame(slot_T_hand_start, rng, checker, options); },
      [&](const ExpertPlan& plan) {
        Demo demo{scene.world_T_slot,
                  {scene.world_T_hand_start}};  // the start exactly, not rounded through the slot
        demo.world_T_hand.reserve(plan.slot_T_hand.size());
        for (std::size_t t = 1; t < plan.slot_T_hand.size(); ++t) {
          demo.world_T_hand.push_back(scene.world_T_slot * plan.slot_T_hand[t]);
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

}  // namespace handcentric::sim::insert3d
