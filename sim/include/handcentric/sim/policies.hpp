#pragma once
// Policies that need no training, for testing the rollout loop and for the benchmarks. All of
// them read only the observation (hand history and eye-in-hand points), so they are equivariant,
// eq. (4): act(g * o, s) = g * act(o, s) for every planar g (tests/sim checks the expert's).
//
//   ExpertPolicy   : the trajectory-optimization expert, closed loop: reads the hole from the two
//                    eye-in-hand corners, replans from the current pose without a via point.
//   ReplayPolicy   : replays one demo in the hole frame read from the observation: returns the
//                    K demo poses after the demo pose nearest to the hand now.
//   StraightPolicy : scripted, moves along the hand's own -y axis (the peg's axis) by a step.
//   HoldPolicy     : scripted, commands the current pose (ends in a timeout).
#include <memory>
#include <string>
#include <vector>

#include "handcentric/core/chunk_policy.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/expert.hpp"

namespace handcentric::sim {

/// The chunk length of the paper's rollouts (Sec. 4.2): K = 16 future poses.
constexpr int kChunkLength = 16;

/// hand_T_hole from the two eye-in-hand corners (left, right) of the opening. Throws
/// InvalidScene when there are not exactly two points or they coincide.
RigidTransform hand_T_hole_from_observation(const Scene& observation);

class ExpertPolicy final : public ChunkPolicy {
 public:
  explicit ExpertPolicy(const PegHoleGeometry& geometry = PegHoleGeometry(),
                        int chunk_length = kChunkLength);
  std::string name() const override { return "expert"; }
  std::vector<RigidTransform> act(const Scene& observation,
                                  std::uint64_t noise_seed) const override;

 private:
  CollisionChecker checker_;
  int chunk_length_;
};

class ReplayPolicy final : public ChunkPolicy {
 public:
  /// Throws InvalidArgument for an empty demo.
  explicit ReplayPolicy(const Demo& demo, int chunk_length = kChunkLength);
  std::string name() const override { return "replay"; }
  std::vector<RigidTransform> act(const Scene& observation,
                                  std::uint64_t noise_seed) const override;

 private:
  std::vector<RigidTransform> hole_T_hand_;
  int chunk_length_;
};

class StraightPolicy final : public ChunkPolicy {
 public:
  explicit StraightPolicy(double step_cm = kMaxStepCm, int chunk_length = kChunkLength);
  std::string name() const override { return "straight"; }
  std::vector<RigidTransform> act(const Scene& observation,
                                  std::uint64_t noise_seed) const override;

 private:
  double step_cm_;
  int chunk_length_;
};

class HoldPolicy final : public ChunkPolicy {
 public:
  std::string name() const override { return "hold"; }
  std::vector<RigidTransform> act(const Scene& observation,
                                  std::uint64_t noise_seed) const override;
};

/// "expert", "straight", "hold" (the policies a command line can name without a file).
std::vector<std::string> scripted_policy_names();

/// One of scripted_policy_names(); throws InvalidArgument naming the value and the valid names.
std::unique_ptr<ChunkPolicy> make_scripted_policy(const std::string& name);

}  // namespace handcentric::sim
