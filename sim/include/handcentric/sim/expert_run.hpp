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
  int unsolved = 0;             ///< scenes where every attempt was invalid
  int solutions = 0;            ///< plans made
  int discarded = 0;            ///< invalid plans among them
  double discard_rate() const { return solutions == 0 ? 0.0 : static_cast<double>(discarded) / solutions; }
  double solved_rate() const { return scenes == 0 ? 0.0 : 1.0 - static_cast<double>(unsolved) / scenes; }

  /// Adds another run's counts and moves its demos to the end.
  void append(BasicExpertRun&& other) {
    scenes += other.scenes;
    unsolved += other.unsolved;
    solutions += other.solutions;
    discarded += other.discarded;
    for (DemoType& demo : other.demos) demos.push_back(std::move(demo));
  }
};

}  // namespace handcentric::sim
