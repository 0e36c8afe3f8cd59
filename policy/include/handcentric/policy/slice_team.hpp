#pragma once
// SliceTeam: the slices of one training step (kImageTrainSlice samples each, conv_encoder.hpp)
// run on several threads, with the bits of one thread.
//
// Lane k of T runs slices k, k + T, k + 2T, ..., each forward and backward into its own buffers
// (a lane keeps its own copy of the network's activations and gradient). The slices' gradients
// are then added into the step's sum in slice order, slice s right after slice s - 1 whichever
// lane ran it: the same additions in the same order as one thread running every slice, so the
// weights do not depend on the number of threads. A lane adds its slice as soon as the one
// before it is in the sum, while the other lanes go on computing theirs: only the additions
// (tens of microseconds for the default image policy's 130k parameters) are serial, against a
// slice's milliseconds of products.
#include <functional>
#include <memory>

namespace handcentric::policy {

class SliceTeam {
 public:
  /// More lanes than this are refused: a lane holds a slice's activations (megabytes), and a
  /// step of 256 samples has 16 slices.
  static constexpr int kMaxThreads = 64;

  /// `threads` lanes: the calling thread and threads - 1 workers, which live as long as the
  /// team and sleep between steps. Throws InvalidArgument for threads outside 1..kMaxThreads.
  explicit SliceTeam(int threads = 1);
  ~SliceTeam();
  SliceTeam(const SliceTeam&) = delete;
  SliceTeam& operator=(const SliceTeam&) = delete;

  int threads() const { return threads_; }

  /// compute(lane, first, count): a slice's forward and backward pass on `lane`'s buffers.
  using Compute = std::function<void(int lane, long first, long count)>;
  /// add(lane, first): that slice's gradient (in `lane`'s buffers) into the step's sum.
  using Add = std::function<void(int lane, long first)>;

  /// Cuts samples [0, batch) into slices of `slice` samples (the last may be shorter), and for
  /// slice s (first sample s * slice) calls compute on lane s % threads(), then add on the same
  /// lane, the add of slice s after the add of slice s - 1 has returned. Returns when every slice
  /// is added. If a call throws, the lanes stop at their next slice and the first exception is
  /// rethrown here (the sum then holds some slices). Throws InvalidArgument for batch < 1 or
  /// slice < 1. Not reentrant: one run() at a time per team.
  void run(long batch, long slice, const Compute& compute, const Add& add);

 private:
  struct Shared;
  int threads_ = 1;
  std::unique_ptr<Shared> shared_;
};

}  // namespace handcentric::policy
