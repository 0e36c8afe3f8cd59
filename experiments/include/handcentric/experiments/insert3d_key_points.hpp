#pragma once
// The input of the 3D task's learned policies: the eye-in-hand observation (the slot opening's
// four corners in the hand frame, sim/insert3d/rollout.hpp) followed by five more points of the
// slot computed from them: the block's four outer top corners and the slot's bottom centre.
//
// Why: the four opening corners span only 0.6 cm across the slot (2 x (0.2 + 0.1)), so a tilt of
// the blade by theta about the slot's long axis changes them by 0.6 sin(theta) beyond what a
// sideways shift of the hand does (0.03 cm at 3 deg): a policy fed the corners alone brings the
// tip to the opening but leaves the blade tilted by 1-13 deg (measured on the tuning seeds),
// far more than the 0.7 deg the 0.1 cm clearance allows. The corners fix hand_T_slot exactly
// (hand_T_slot_from_corners), so the added points carry no new information, only better
// conditioned: the outer corners span 4.6 by 8.2 cm and the bottom centre lies 6 cm down the
// axis. They are a function of hand-frame points alone, so g * scene gets the same input and the
// hand-centric policy stays equivariant (Theorem 1 holds for any network input built this way).
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "handcentric/core/chunk_policy.hpp"
#include "handcentric/core/scene.hpp"

namespace handcentric::experiments {

/// Points added to the four corners.
inline constexpr int kSlotKeyPoints = 5;

/// `observation` with the five slot points appended to its four hand points. Throws
/// InvalidScene unless it has exactly four hand points.
Scene with_slot_key_points(const Scene& observation);

/// with_slot_key_points on every scene (training data).
std::vector<Scene> with_slot_key_points(const std::vector<Scene>& scenes);

/// A policy trained on with_slot_key_points inputs, acting on the 3D rollout's observations.
class SlotKeyPointPolicy final : public ChunkPolicy {
 public:
  explicit SlotKeyPointPolicy(std::shared_ptr<const ChunkPolicy> inner)
      : inner_(std::move(inner)) {}
  std::string name() const override { return inner_->name(); }
  std::vector<RigidTransform> act(const Scene& observation,
                                  std::uint64_t noise_seed) const override {
    return inner_->act(with_slot_key_points(observation), noise_seed);
  }

 private:
  std::shared_ptr<const ChunkPolicy> inner_;
};

}  // namespace handcentric::experiments
