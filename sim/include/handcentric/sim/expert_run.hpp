#pragma once
// The tally of an expert over scenes, shared by the 2D and the 3D task: the demos of the solved
// scenes, the plans made, those discarded as invalid, and the scenes left unsolved.
#include <utility>
#include <vector>

namespace handcentric::sim {

template <typename DemoType>
struct BasicExpertRun {
  std::vector<DemoType> demos;  ///< one per solved scene, in scene order
  int scenes = 0;
  int unsolved = 0;   ///< scenes where every attempt was invalid
  int solutions = 0;  ///< plans made
  int discarded = 0;  ///< invalid plans among them
  double discard_rate() const {
    return solutions == 0 ? 0.0 : static_cast<double>(discarded) / solutions;
  }
  double solved_rate() const {
    return scenes == 0 ? 0.0 : 1.0 - static_cast<double>(unsolved) / scenes;
  }

  /// Adds another run's counts and moves its demos to the end.
  void append(BasicExpertRun&& other) {
    scenes += other.scenes;
    unsolved += other.unsolved;
    solutions += other.solutions;
    discarded += other.discarded;
    for (DemoType& demo : other.demos) demos.push_back(std::move(demo));
  }
};

/// The expert on one scene: up to `attempts` plans, each made by `plan_once()`, the first valid
/// one (`plan.valid`) turned into a demo by `to_demo(plan)`. Every plan is counted, an invalid
/// one as discarded; a scene whose plans are all invalid is unsolved.
template <typename DemoType, typename PlanOnce, typename ToDemo>
BasicExpertRun<DemoType> first_valid_plan(int attempts, PlanOnce&& plan_once, ToDemo&& to_demo) {
  BasicExpertRun<DemoType> run;
  run.scenes = 1;
  for (int attempt = 0; attempt < attempts; ++attempt) {
    const auto plan = plan_once();
    ++run.solutions;
    if (!plan.valid) {
      ++run.discarded;
      continue;
    }
    run.demos.push_back(to_demo(plan));
    return run;
  }
  run.unsolved = 1;
  return run;
}

/// `one_scene(scene, i)` on every scene, in order, tallied into one run.
template <typename DemoType, typename Scene, typename OneScene>
BasicExpertRun<DemoType> on_every_scene(const std::vector<Scene>& scenes, OneScene&& one_scene) {
  BasicExpertRun<DemoType> total;
  for (std::size_t i = 0; i < scenes.size(); ++i) total.append(one_scene(scenes[i], i));
  return total;
}

}  // namespace handcentric::sim
