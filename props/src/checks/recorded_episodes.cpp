#include "handcentric/props/checks/recorded_episodes.hpp"

#include <rapidcheck.h>

#include <algorithm>
#include <random>

#include "closed_loop_episode.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/props/observation/generators.hpp"
#include "handcentric/props/observation/recorded.hpp"
#include "handcentric/props/run.hpp"
#include "handcentric/props/tolerance.hpp"

namespace handcentric::props {
namespace {

/// The policy's answers to `scenes` in order, started afresh: the recorded observations replayed.
RolloutChunks replay(const NoisyPolicy& policy, const std::vector<Scene>& scenes,
                     const std::vector<Eigen::VectorXd>& noises, const ClosedLoopOptions& loop) {
  RolloutChunks returned;
  if (loop.start_episode) loop.start_episode();
  for (std::size_t t = 0; t < scenes.size(); ++t) {
    const std::vector<const Scene*> one = {&scenes[t]};
    const std::vector<const Eigen::VectorXd*> noise = {&noises[t]};
    returned.push_back(policy.act_fresh(one, noise).front());
    if (returned.back().empty()) throw InvalidArgument(policy.name() + " returned an empty chunk");
  }
  return returned;
}

std::vector<const Scene*> pointers(const std::vector<Scene>& scenes) {
  std::vector<const Scene*> out;
  for (const Scene& s : scenes) out.push_back(&s);
  return out;
}

std::string steps_text(const std::vector<RecordedEpisode>& episodes) {
  std::size_t shortest = episodes.front().steps, longest = shortest;
  for (const RecordedEpisode& e : episodes) {
    shortest = std::min(shortest, e.steps);
    longest = std::max(longest, e.steps);
  }
  return shortest == longest ? std::to_string(shortest)
                             : std::to_string(shortest) + " to " + std::to_string(longest);
}

}  // namespace

Verdict check_policy_recorded_episodes(const NoisyPolicy& policy, Group group,
                                       const CheckOptions& options, const ClosedLoopOptions& loop) {
  const std::shared_ptr<const RecordedObservations>& data = options.shape.recorded;
  std::vector<RecordedEpisode> episodes = data ? data->episodes() : std::vector<RecordedEpisode>{};
  if (episodes.empty())
    throw InvalidArgument(
        "the closed loop on recorded episodes needs observations with an "
        "'episode' index: give each observation its episode");
  if (loop.episodes < 1 || static_cast<std::size_t>(loop.episodes) > episodes.size()) {
    throw InvalidArgument("episodes=" + std::to_string(loop.episodes) +
                          " but the observations of " + data->source + " record " +
                          std::to_string(episodes.size()) + " episodes: give episodes= from 1 to " +
                          std::to_string(episodes.size()));
  }
  if (loop.compared_from > 1) {
    throw InvalidArgument("compared_from=" + std::to_string(loop.compared_from) +
                          ": at most one executed pose precedes the chunk compared");
  }
  episodes.resize(static_cast<std::size_t>(loop.episodes));
  for (const RecordedEpisode& e : episodes) {
    const int history = data->scenes[e.first].history_length() + 1;
    if (e.steps < static_cast<std::size_t>(history)) {
      throw InvalidArgument("recorded episode " + std::to_string(e.index) + " of " + data->source +
                            " has " + std::to_string(e.steps) + " observations, fewer than the " +
                            std::to_string(history) +
                            " poses of its history: record at least H+1 steps per episode, or "
                            "leave that episode out");
    }
  }
  Verdict verdict = closed_loop_verdict(group, options);
  rc::Random random(options.seed ^ 0x6c6f6f70ULL);  // the generated episodes' g, for the same seed
  std::mt19937_64 perturb(options.seed);
  const rc::Gen<RigidTransform> elements = group_element(group, options.shape.planar);
  const bool eye_in_hand = options.shape.max_world_points == 0;
  for (std::size_t e = 0; e < episodes.size(); ++e) {
    const RecordedEpisode& recorded = episodes[e];
    (void)random.split();  // where a generated episode draws its scene: the same g per seed
    const RigidTransform g = elements(random.split(), rc::kNominalSize).value();
    std::vector<Scene> scenes, moved;
    for (std::size_t t = 0; t < recorded.steps; ++t) {
      scenes.push_back(data->scenes[recorded.first + t]);
      if (eye_in_hand) scenes.back().world_points.clear();
      moved.push_back(g * scenes.back());
    }
    const std::vector<Eigen::VectorXd> noises = closed_loop_noises(
        policy.noise_dimension(), options, static_cast<int>(e), static_cast<int>(recorded.steps));
    ClosedLoopEpisode episode;
    episode.start = &scenes.front();
    episode.g = g;
    episode.a = replay(policy, scenes, noises, loop);
    episode.b = replay(policy, moved, noises, loop);
    episode.length_scale = std::max(rollout_scale(pointers(scenes), episode.a),
                                    rollout_scale(pointers(moved), episode.b));
    episode.nudged = [&] {
      std::vector<Scene> nudged;
      for (const Scene& s : scenes)
        nudged.push_back(
            rounding_perturbation(s, options.unit_roundoff, perturb, options.shape.planar));
      return replay(policy, nudged, noises, loop);
    };
    episode.name = "closed loop, recorded episode " + std::to_string(recorded.index) + " (" +
                   std::to_string(e + 1) + " of " + std::to_string(episodes.size()) +
                   ", observations " + std::to_string(recorded.first) + " to " +
                   std::to_string(recorded.first + recorded.steps - 1) + " of " + data->source +
                   ")";
    if (!judge_closed_loop_episode(verdict, episode, options, loop.compared_from)) return verdict;
  }
  if (verdict.cases == 0) verdict.invariant = false;  // no far episode: nothing was shown
  verdict.note = "closed loop: " + std::to_string(episodes.size()) + " recorded episodes of " +
                 steps_text(episodes) + " steps (" + data->source +
                 "), each replayed as recorded with one g, each policy started afresh; the hand " +
                 "does not move to the executed pose: this audits the policy's state over the " +
                 "recorded observations, not the executed trajectory";
  return verdict;
}

}  // namespace handcentric::props
