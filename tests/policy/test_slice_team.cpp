// SliceTeam (slice_team.hpp): a training step's slices on several threads, added in slice order
// whichever lane finishes first, so that the step's sums have the bits of one thread.
#include <catch2/catch.hpp>

#include <chrono>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/policy/slice_team.hpp"
#include "throws.hpp"

using namespace handcentric;
using namespace handcentric::policy;

namespace {

struct Call {
  int lane;
  long first, count;
};

}  // namespace

// 23 samples in slices of 3 (8 slices, the last of 2). Later slices are made to finish first
// (slice s sleeps 8 - s ms), so a lane that added its slice without waiting for the one before
// would put slice 1 before slice 0. Every slice is computed once, on lane s % threads, and
// added on that lane, in slice order.
TEST_CASE("a_slice_team_adds_the_slices_in_order_whatever_lane_finishes_first", "[unit]") {
  constexpr long batch = 23, slice = 3, slices = 8;
  for (const int threads : {1, 2, 3, 5, 9}) {
    INFO(threads << " threads");
    SliceTeam team(threads);
    CHECK(team.threads() == threads);
    std::mutex mutex;
    std::vector<Call> computed, added;
    const SliceTeam::Compute compute = [&](int lane, long first, long count) {
      std::this_thread::sleep_for(std::chrono::milliseconds(slices - first / slice));
      const std::lock_guard<std::mutex> lock(mutex);
      computed.push_back({lane, first, count});
    };
    const SliceTeam::Add add = [&](int lane, long first) {
      const std::lock_guard<std::mutex> lock(mutex);
      added.push_back({lane, first, 0});
    };
    for (int run = 0; run < 2; ++run) {  // a team runs step after step
      computed.clear();
      added.clear();
      team.run(batch, slice, compute, add);
      REQUIRE(added.size() == static_cast<std::size_t>(slices));
      REQUIRE(computed.size() == static_cast<std::size_t>(slices));
      for (long s = 0; s < slices; ++s) {
        CHECK(added[static_cast<std::size_t>(s)].first == s * slice);
        CHECK(added[static_cast<std::size_t>(s)].lane == s % threads);
      }
      std::vector<int> seen(slices, 0);
      for (const Call& call : computed) {
        REQUIRE(call.first % slice == 0);
        const long s = call.first / slice;
        ++seen[static_cast<std::size_t>(s)];
        CHECK(call.lane == s % threads);
        CHECK(call.count == (s + 1 < slices ? slice : batch - call.first));
      }
      CHECK(seen == std::vector<int>(slices, 1));
    }
  }
}

// A lane's exception stops the step and reaches the caller (the first one, here the only one)
// instead of leaving the other lanes waiting for a slice that never comes; the team runs the
// next step as usual.
TEST_CASE("a_slice_teams_failure_reaches_the_caller_and_the_team_runs_again", "[unit]") {
  for (const int threads : {1, 2, 3}) {
    INFO(threads << " threads");
    SliceTeam team(threads);
    long added = 0;
    const SliceTeam::Add add = [&](int, long) { ++added; };
    const SliceTeam::Compute failing = [](int, long first, long) {
      if (first == 12) throw std::runtime_error("slice at sample 12 failed");
    };
    CHECK_THROWS_WITH(team.run(20, 4, failing, add), Catch::Contains("sample 12"));
    CHECK(added <= 3);  // slices 0-2 at most: nothing after the failed one is added
    added = 0;
    team.run(
        20, 4, [](int, long, long) {}, add);
    CHECK(added == 5);
    added = 0;
    const SliceTeam::Add failing_add = [&](int, long first) {
      if (first == 4) throw std::runtime_error("adding the slice at sample 4 failed");
      ++added;
    };
    CHECK_THROWS_WITH(team.run(
                          20, 4, [](int, long, long) {}, failing_add),
                      Catch::Contains("sample 4"));
    CHECK(added == 1);
  }
}

TEST_CASE("a_slice_team_refuses_bad_sizes_by_name", "[unit]") {
  HC_CHECK_THROWS(SliceTeam(0), InvalidArgument, Catch::Contains("0 threads; use 1 to 64"));
  HC_CHECK_THROWS(SliceTeam(SliceTeam::kMaxThreads + 1), InvalidArgument,
                  Catch::Contains("65 threads"));
  SliceTeam team(2);
  const SliceTeam::Compute compute = [](int, long, long) {};
  const SliceTeam::Add add = [](int, long) {};
  HC_CHECK_THROWS(team.run(0, 4, compute, add), InvalidArgument,
                  Catch::Contains("a step of 0 samples"));
  HC_CHECK_THROWS(team.run(8, 0, compute, add), InvalidArgument, Catch::Contains("in slices of 0"));
}
