// The closed-loop check (props/checks/closed_loop.hpp) on stateful C++ policies: a policy whose
// state is a step count in the hand frame holds; one whose state accumulates a world-frame offset
// fails under translation with the episode and step named; the rollouts are started afresh and
// see the objects from where the hand is.
#include <catch2/catch.hpp>

#include <memory>

#include "handcentric/core/errors.hpp"
#include "handcentric/props/checks/closed_loop.hpp"

using namespace handcentric;

namespace {

// Moves 1 cm along its own x each step, and by `world_drift` along world x times its step count
// (a state kept in world coordinates); records the eye-in-hand points it saw.
class SteppingPolicy final : public props::NoisyPolicy {
 public:
  explicit SteppingPolicy(double world_drift) : world_drift_(world_drift) {}
  std::string name() const override { return "stepping"; }
  Eigen::Index noise_dimension() const override { return 2; }
  std::vector<RigidTransform> act(const Scene& o, const Eigen::VectorXd& /*noise*/) const override {
    ++steps_;
    const RigidTransform& T0 = o.world_T_hand_history.front();
    RigidTransform next = T0 * RigidTransform::from_translation(Eigen::Vector3d(0.01, 0, 0));
    if (!o.hand_points.empty()) seen_.push_back(T0 * o.hand_points.front());
    return {RigidTransform::from_translation(Eigen::Vector3d(world_drift_ * steps_, 0, 0)) * next};
  }
  void reset() const { steps_ = 0; }
  mutable std::vector<Eigen::Vector3d> seen_;  // where each seen hand point lies in the world

 private:
  double world_drift_;
  mutable int steps_ = 0;
};

// Executes 1 cm along its own x each step; returns a second pose after it, 2 cm along its own x
// plus `world_drift` along world x times its step count (a planned pose, never executed, that
// reads a state kept in world coordinates).
class PlanningPolicy final : public props::NoisyPolicy {
 public:
  explicit PlanningPolicy(double world_drift) : world_drift_(world_drift) {}
  std::string name() const override { return "planning"; }
  Eigen::Index noise_dimension() const override { return 2; }
  std::vector<RigidTransform> act(const Scene& o, const Eigen::VectorXd& /*noise*/) const override {
    ++steps_;
    const RigidTransform& T0 = o.world_T_hand_history.front();
    const RigidTransform planned =
        RigidTransform::from_translation(Eigen::Vector3d(world_drift_ * steps_, 0, 0)) * T0 *
        RigidTransform::from_translation(Eigen::Vector3d(0.02, 0, 0));
    return {T0 * RigidTransform::from_translation(Eigen::Vector3d(0.01, 0, 0)), planned};
  }
  void reset() const { steps_ = 0; }

 private:
  double world_drift_;
  mutable int steps_ = 0;
};

template <class Policy>
props::ClosedLoopOptions loop_of(const Policy& policy, int episodes, int steps) {
  props::ClosedLoopOptions loop;
  loop.episodes = episodes;
  loop.steps = steps;
  loop.start_episode = [&policy] { policy.reset(); };
  return loop;
}

}  // namespace

TEST_CASE("a_state_kept_in_the_hand_frame_holds_in_the_closed_loop", "[unit]") {
  const SteppingPolicy policy(0.0);
  const props::Verdict v = props::check_policy_closed_loop(
      policy, props::Group::se3, props::options_for(props::View::eye_in_hand),
      loop_of(policy, 6, 5));
  CHECK(v.invariant);
  CHECK(v.mode == props::Mode::closed_loop);
  CHECK(v.cases + v.near_identity_cases == 6);
  // The eye-in-hand point is an object fixed in the world: seen from every step's hand, it is
  // the same world point within each rollout.
  REQUIRE(policy.seen_.size() >= 5);
  CHECK((policy.seen_[4] - policy.seen_[0]).norm() < 1e-9);
}

TEST_CASE("a_state_kept_in_world_coordinates_fails_naming_the_episode_and_step", "[unit]") {
  const SteppingPolicy policy(0.001);
  const props::Verdict v = props::check_policy_closed_loop(
      policy, props::Group::rotation, props::options_for(props::View::eye_in_hand),
      loop_of(policy, 6, 5));
  REQUIRE_FALSE(v.invariant);
  REQUIRE(v.witness);
  CHECK_THAT(v.witness->detail,
             Catch::Contains("closed loop, episode 0 of 6") && Catch::Contains("at step 1 of 5"));
}

TEST_CASE("mutant_a_closed_loop_without_a_fresh_start_blames_g_for_the_state", "[unit]") {
  // Without start_episode the second rollout continues the first's step count, so the drift it
  // adds differs from the first's whatever g is: the check would blame g for the policy's state.
  // Started afresh, the same policy holds under translation (a drift along x commutes with it).
  const SteppingPolicy drifting(0.001);
  props::ClosedLoopOptions no_reset = loop_of(drifting, 3, 4);
  no_reset.start_episode = nullptr;
  const props::Verdict v = props::check_policy_closed_loop(
      drifting, props::Group::translation, props::options_for(props::View::eye_in_hand), no_reset);
  CHECK_FALSE(v.invariant);
  const props::Verdict fresh = props::check_policy_closed_loop(
      drifting, props::Group::translation, props::options_for(props::View::eye_in_hand),
      loop_of(drifting, 3, 4));
  CHECK(fresh.invariant);
}

TEST_CASE("closed_loop_episodes_and_steps_out_of_range_are_refused", "[unit]") {
  const SteppingPolicy policy(0.0);
  const auto options = props::options_for(props::View::eye_in_hand);
  CHECK_THROWS_AS(
      props::check_policy_closed_loop(policy, props::Group::se3, options, loop_of(policy, 0, 5)),
      InvalidArgument);
  CHECK_THROWS_AS(
      props::check_policy_closed_loop(policy, props::Group::se3, options, loop_of(policy, 2, 0)),
      InvalidArgument);
}

TEST_CASE("a_planned_pose_never_executed_is_compared_too", "[unit]") {
  // The chunk is compared whole, as the pointwise checks compare it: a second pose that reads a
  // world-frame state breaks the map o -> chunk even though the executed first pose holds.
  // Planted fault (run by hand): comparing the executed pose alone says yes here.
  const auto options = props::options_for(props::View::eye_in_hand);
  const PlanningPolicy drifting(0.001);
  const props::Verdict v = props::check_policy_closed_loop(drifting, props::Group::rotation,
                                                           options, loop_of(drifting, 4, 4));
  REQUIRE_FALSE(v.invariant);
  REQUIRE(v.witness);
  CHECK_THAT(v.witness->detail, Catch::Contains("returns pose 2 of the chunk compared"));
  // With the executed pose handed ahead of another output's chunk (compared_from 1), the second
  // pose is the first one compared.
  props::ClosedLoopOptions behind = loop_of(drifting, 4, 4);
  behind.compared_from = 1;
  const props::Verdict w =
      props::check_policy_closed_loop(drifting, props::Group::rotation, options, behind);
  REQUIRE_FALSE(w.invariant);
  CHECK_THAT(w.witness->detail, Catch::Contains("returns pose 1 of the chunk compared"));
  const PlanningPolicy steady(0.0);
  CHECK(props::check_policy_closed_loop(steady, props::Group::se3, options, loop_of(steady, 4, 4))
            .invariant);
  behind.compared_from = 2;
  CHECK_THROWS_AS(props::check_policy_closed_loop(steady, props::Group::se3, options, behind),
                  InvalidArgument);
}
