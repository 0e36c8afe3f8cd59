#include "handcentric/policy/slice_team.hpp"

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "handcentric/core/errors.hpp"

namespace handcentric::policy {

// One mutex guards the step in flight: which step the workers are on (generation), how many are
// still in it (running), how many slices are in the sum (added), and the first failure. Waits are
// per slice (milliseconds of work each), so a lock per slice costs nothing measurable.
struct SliceTeam::Shared {
  std::mutex mutex;
  std::condition_variable wake;      // a new step, or the team's end
  std::condition_variable finished;  // the last worker left the step
  std::condition_variable in_sum;    // `added` grew, or a lane failed
  std::vector<std::thread> workers;
  bool stop = false;
  long generation = 0;
  int running = 0;
  // The step in flight.
  const Compute* compute = nullptr;
  const Add* add = nullptr;
  long batch = 0, slice = 0, slices = 0;
  int threads = 1;  ///< lanes, set once by the constructor
  long added = 0;   ///< slices [0, added) are in the sum
  bool failed = false;
  std::exception_ptr error;

  void fail(std::exception_ptr e) {
    {
      const std::lock_guard<std::mutex> lock(mutex);
      if (!failed) error = e;
      failed = true;
    }
    in_sum.notify_all();
  }

  // Lane `lane`'s slices of the step in flight, each added after the slice before it.
  void run_lane(int lane) {
    try {
      for (long s = lane; s < slices; s += threads) {
        const long first = s * slice;
        (*compute)(lane, first, std::min(slice, batch - first));
        {
          std::unique_lock<std::mutex> lock(mutex);
          in_sum.wait(lock, [&] { return added == s || failed; });
          if (failed) return;
        }
        (*add)(lane, first);
        {
          const std::lock_guard<std::mutex> lock(mutex);
          added = s + 1;
        }
        in_sum.notify_all();
      }
    } catch (...) {
      fail(std::current_exception());
    }
  }

  void work(int lane) {
    long seen = 0;
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex);
        wake.wait(lock, [&] { return stop || generation != seen; });
        if (stop) return;
        seen = generation;
      }
      run_lane(lane);
      {
        const std::lock_guard<std::mutex> lock(mutex);
        if (--running == 0) finished.notify_one();
      }
    }
  }

  void end() {
    {
      const std::lock_guard<std::mutex> lock(mutex);
      stop = true;
    }
    wake.notify_all();
    for (std::thread& worker : workers) worker.join();
    workers.clear();
  }
};

SliceTeam::SliceTeam(int threads) : threads_(threads), shared_(std::make_unique<Shared>()) {
  if (threads < 1 || threads > kMaxThreads) {
    throw InvalidArgument("SliceTeam: " + std::to_string(threads) + " threads; use 1 to " +
                          std::to_string(kMaxThreads));
  }
  shared_->threads = threads;
  try {
    for (int lane = 1; lane < threads; ++lane) {
      shared_->workers.emplace_back([shared = shared_.get(), lane] { shared->work(lane); });
    }
  } catch (...) {
    shared_->end();  // the workers started so far
    throw;
  }
}

SliceTeam::~SliceTeam() {
  if (shared_) shared_->end();
}

void SliceTeam::run(long batch, long slice, const Compute& compute, const Add& add) {
  if (batch < 1 || slice < 1) {
    throw InvalidArgument("SliceTeam: a step of " + std::to_string(batch) +
                          " samples in slices of " + std::to_string(slice) +
                          "; both must be 1 or more");
  }
  const long slices = (batch + slice - 1) / slice;
  if (threads_ == 1) {  // no worker: compute and add each slice in turn
    for (long s = 0; s < slices; ++s) {
      const long first = s * slice;
      compute(0, first, std::min(slice, batch - first));
      add(0, first);
    }
    return;
  }
  Shared& shared = *shared_;
  {
    const std::lock_guard<std::mutex> lock(shared.mutex);
    shared.compute = &compute;
    shared.add = &add;
    shared.batch = batch;
    shared.slice = slice;
    shared.slices = slices;
    shared.added = 0;
    shared.failed = false;
    shared.error = nullptr;
    shared.running = threads_ - 1;
    ++shared.generation;
  }
  shared.wake.notify_all();
  shared.run_lane(0);
  std::unique_lock<std::mutex> lock(shared.mutex);
  shared.finished.wait(lock, [&] { return shared.running == 0; });
  if (shared.error) std::rethrow_exception(shared.error);
}

}  // namespace handcentric::policy
