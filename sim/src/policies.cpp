// Expert, replay and scripted policies (policies.hpp).
#include "handcentric/sim/policies.hpp"

#include <cmath>
#include <limits>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric::sim {
namespace {

std::vector<RigidTransform> pad_chunk(std::vector<RigidTransform> chunk, const RigidTransform& last,
                                      int length) {
  if (chunk.size() > static_cast<std::size_t>(length))
    chunk.resize(static_cast<std::size_t>(length));
  while (chunk.size() < static_cast<std::size_t>(length))
    chunk.push_back(chunk.empty() ? last : chunk.back());
  return chunk;
}

void check_chunk_length(int chunk_length) {
  if (chunk_length < 1)
    throw InvalidArgument("chunk length must be >= 1, got " + std::to_string(chunk_length));
}

}  // namespace

RigidTransform hand_T_hole_from_observation(const Scene& observation) {
  observation.validate_observation();
  if (observation.hand_points.size() != 2) {
    throw InvalidScene(
        "the 2D task observes exactly 2 eye-in-hand points (the opening's corners), got " +
        std::to_string(observation.hand_points.size()));
  }
  const Eigen::Vector3d& left = observation.hand_points[0];
  const Eigen::Vector3d& right = observation.hand_points[1];
  const Eigen::Vector3d across = right - left;  // the hole's +x in the hand frame
  if (across.head<2>().norm() < 1e-9) {
    throw InvalidScene("the two eye-in-hand corners coincide: " + format_matrix(left) +
                       "; cannot read the hole");
  }
  const Eigen::Vector3d middle = 0.5 * (left + right);
  return RigidTransform::planar(std::atan2(across.y(), across.x()), middle.x(), middle.y());
}

ExpertPolicy::ExpertPolicy(const PegHoleGeometry& geometry, int chunk_length)
    : checker_(geometry), chunk_length_(chunk_length) {
  check_chunk_length(chunk_length);
}

std::vector<RigidTransform> ExpertPolicy::act(const Scene& observation,
                                              std::uint64_t noise_seed) const {
  const RigidTransform world_T_hand0 = observation.world_T_hand0();
  const RigidTransform world_T_hole = world_T_hand0 * hand_T_hole_from_observation(observation);
  const RigidTransform hole_T_hand0 = world_T_hole.inverse_compose(world_T_hand0);
  const Eigen::Vector3d q = planar_coordinates(hole_T_hand0);
  std::vector<RigidTransform> hole_T_plan;
  // on the hole's axis below the pre-insertion pose: straight down (what the plan does there)
  if (std::abs(q(0)) < 1e-6 && std::abs(q(1)) < 1e-6 &&
      q(2) <= kPegLength + kPreInsertionTipHeight + 1e-9) {
    hole_T_plan = resample_at_control_step(
        {hole_T_hand0, RigidTransform::planar(0.0, 0.0, kPegLength - kInsertionDepth)});
  } else {
    ExpertOptions options;
    options.random_via = false;  // closed loop: replan the smoothest path, no detour
    std::mt19937_64 rng(noise_seed);
    hole_T_plan = plan_in_hole_frame(hole_T_hand0, rng, checker_, options).hole_T_hand;
  }
  std::vector<RigidTransform> chunk;
  for (std::size_t t = 1; t < hole_T_plan.size(); ++t)
    chunk.push_back(world_T_hole * hole_T_plan[t]);
  return pad_chunk(std::move(chunk), world_T_hand0, chunk_length_);
}

ReplayPolicy::ReplayPolicy(const Demo& demo, int chunk_length) : chunk_length_(chunk_length) {
  check_chunk_length(chunk_length);
  if (demo.world_T_hand.empty()) throw InvalidArgument("replay: the demo has no hand pose");
  for (const RigidTransform& world_T_hand : demo.world_T_hand) {
    hole_T_hand_.push_back(demo.world_T_hole.inverse_compose(world_T_hand));
  }
}

std::vector<RigidTransform> ReplayPolicy::act(const Scene& observation,
                                              std::uint64_t /*noise_seed*/) const {
  const RigidTransform world_T_hand0 = observation.world_T_hand0();
  const RigidTransform world_T_hole = world_T_hand0 * hand_T_hole_from_observation(observation);
  const RigidTransform hole_T_hand0 = world_T_hole.inverse_compose(world_T_hand0);
  std::size_t nearest = 0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < hole_T_hand_.size(); ++t) {
    const double d = distance(hole_T_hand_[t], hole_T_hand0);
    if (d < best) best = d, nearest = t;
  }
  std::vector<RigidTransform> chunk;
  for (std::size_t t = nearest + 1; t < hole_T_hand_.size(); ++t)
    chunk.push_back(world_T_hole * hole_T_hand_[t]);
  return pad_chunk(std::move(chunk), world_T_hand0, chunk_length_);
}

StraightPolicy::StraightPolicy(double step_cm, int chunk_length)
    : step_cm_(step_cm), chunk_length_(chunk_length) {
  check_chunk_length(chunk_length);
  if (!(step_cm > 0.0) || !std::isfinite(step_cm)) {
    throw InvalidArgument("straight policy: step must be a positive number of cm, got " +
                          format_number(step_cm));
  }
}

std::vector<RigidTransform> StraightPolicy::act(const Scene& observation,
                                                std::uint64_t /*noise_seed*/) const {
  observation.validate_observation();
  std::vector<RigidTransform> chunk;
  for (int k = 1; k <= chunk_length_; ++k) {
    chunk.push_back(observation.world_T_hand0() * RigidTransform::planar(0.0, 0.0, -step_cm_ * k));
  }
  return chunk;
}

std::vector<RigidTransform> HoldPolicy::act(const Scene& observation,
                                            std::uint64_t /*noise_seed*/) const {
  observation.validate_observation();
  return std::vector<RigidTransform>(static_cast<std::size_t>(kChunkLength),
                                     observation.world_T_hand0());
}

std::vector<std::string> scripted_policy_names() {
  return {"expert", "straight", "hold"};
}

std::unique_ptr<ChunkPolicy> make_scripted_policy(const std::string& name) {
  if (name == "expert") return std::make_unique<ExpertPolicy>();
  if (name == "straight") return std::make_unique<StraightPolicy>();
  if (name == "hold") return std::make_unique<HoldPolicy>();
  throw InvalidArgument("unknown policy '" + name +
                        "'; use expert, straight or hold (or --model FILE)");
}

}  // namespace handcentric::sim
