#pragma once
// The seam between the checks and a batched map (batch.hpp): a prefetch pass. A check runs its
// cases as it always does; during a prefetch pass, a batched map asked for an input it has no
// answer for records it and throws PendingEvaluation, which ends that case only; the runner
// (check_runner.hpp) then has the recorded inputs evaluated together and starts the next pass.
// Checks name their upcoming questions with ask_ahead(), which does nothing outside a pass.
// batch.hpp says why the verdicts stay those of an unbatched check, bit for bit.
#include <cstddef>
#include <functional>
#include <vector>

namespace handcentric::props {

/// Thrown, during a prefetch pass only, by a batched map asked for an input it has not evaluated
/// yet (the input is recorded). Deliberately not a std::exception: only the check runner and
/// ask_ahead() catch it.
struct PendingEvaluation {};

/// Something that records inputs during a prefetch pass and then evaluates them together.
class Prefetcher {
 public:
  virtual ~Prefetcher() = default;
  /// Evaluates the recorded inputs; returns how many it evaluated.
  virtual std::size_t flush() = 0;
};

/// True while a prefetch pass runs on this thread.
bool prefetching();

/// A check names the questions it is about to ask, so that a batched map can answer them
/// together: `inputs()` gives them and ask(input) asks one. The check then asks each input
/// itself, in its own order, and finds the answer cached. inputs() is called only while a
/// batched map is collecting questions (a prefetch pass); otherwise this does nothing, and the
/// questions are asked when the check gets to them.
template <class MakeInputs, class Ask>
void ask_ahead(const MakeInputs& inputs, const Ask& ask) {
  if (!prefetching()) return;
  for (const auto& input : inputs()) {
    try {
      (void)ask(input);
    } catch (const PendingEvaluation&) {
    }
  }
}

namespace detail {

/// Called by a prefetcher for each input it records in this thread's current prefetch pass.
void enlist(Prefetcher& prefetcher);

/// The prefetch passes of one check (check_runner.hpp): while alive, prefetching() is true
/// during pass(); flush() evaluates what the pass recorded. Nested checks keep their own state.
class PrefetchPasses {
 public:
  PrefetchPasses();
  ~PrefetchPasses();
  PrefetchPasses(const PrefetchPasses&) = delete;
  PrefetchPasses& operator=(const PrefetchPasses&) = delete;
  /// Runs one prefetch pass.
  void pass(const std::function<void()>& body);
  /// Evaluates the inputs the last pass recorded; returns how many.
  std::size_t flush();
  /// Inputs recorded since the last flush.
  std::size_t recorded() const { return recorded_; }

 private:
  bool prefetching_ = false;
  std::size_t recorded_ = 0;
  std::vector<Prefetcher*> enlisted_;
  PrefetchPasses* outer_ = nullptr;
  friend bool props::prefetching();
  friend void enlist(Prefetcher& prefetcher);
};

}  // namespace detail
}  // namespace handcentric::props
