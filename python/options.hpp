#pragma once
// The audits' options from Python arguments: groups, views, cases, tolerance, the keywords of
// Setup (batch_size, array, device, quiet, fixed scene sizes), each checked at once with a one-line
// error naming the value and its bound; the progress line; the callables wrapped as the checks
// call them (props/batch.hpp).
#include <pybind11/pybind11.h>

#include <chrono>
#include <cstdlib>
#include <iomanip>
#include <sstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "callables.hpp"
#include "handcentric/props/audit.hpp"
#include "handcentric/props/transport/batch.hpp"
#include "handcentric/props/checks/classifier.hpp"

namespace handcentric::python {

/// The keywords every audit takes besides its groups, views, cases and tolerance: how the
/// callable is called (batch_size, array, device), the progress line, and the scene sizes a
/// network with fixed inputs needs (None: the audit's ranges).
struct Setup {
  py::handle batch_size = py::none();
  std::string array = "numpy";
  py::handle device = py::none();
  bool quiet = false;
  py::handle history = py::none(), hand_points = py::none(), world_points = py::none(),
             chunk = py::none();
  py::handle cameras = py::none(), image_size = py::none();
  std::string channels = "rgbd";
  bool floor = false;
  py::handle workspace = py::none();
  py::handle observations = py::none();
  py::handle detect = py::none();
};

/// The docstring part about Setup's keywords.
inline constexpr const char* kSetupDoc = R"doc(
Every keyword argument a callable receives: with extra_poses / scalars (names), extra_poses=
{name: (4, 4)} and scalars={name: float}. cases: 1 to MAX_CASES (10**7;
None: 1000); or detect=f instead, e.g. detect=0.01: as many cases as find a breaking on a share
f of the (scene, g) draws with 99% probability (ceil(ln 0.01 / ln(1 - f)), 459 for 0.01; the
default 1000 cases find 0.0046).
batch_size=B (1 to MAX_BATCH_SIZE): the callables are called on stacked arrays with a leading
batch axis of at most B: history (B, H+1, 4, 4), chunk (B, K, 4, 4), hand_points (B, n, 3),
world_points (B, m, 3), noise (B, d), each extra pose (B, 4, 4) and scalar (B,); they return
(B, a) (a representation's actions or observation) or (B, K, 4, 4) (a policy). Each row must
depend on its own inputs only; then the verdicts are those of batch_size=None (one scene per
call) bit for bit. Scenes of one shape share a batch: history=, hand_points=, world_points=
(third-person view) and chunk= fix the sizes (None: the audit draws them per case).
array="torch" passes float64 torch tensors (on device=, e.g. "cuda"), array="numpy" (default)
NumPy arrays; results may be either, on any device, with or without grad.
cameras=("eye_in_hand",) (or "third_person", or both) renders, for each scene, the images a
policy would see and passes images={name: array} as a keyword: (C, h, w) float32 per scene,
(B, C, h, w) batched; image_size=(w, h) (default (64, 48)); channels "rgbd" (default: red,
green, blue in [0, 1], then depth in m), "rgb" or "depth"; floor=True adds the floor z <= 0 and a
lamp straight down, which do not move with g. Each point is drawn as a sphere of radius 5 cm
(eye-in-hand points orange, world points green), each extra pose as a blue box;
handcentric.render_cameras shows what the audit rendered for a scene.
workspace=((x0, y0, z0), (x1, y1, z1)) (m): every scene is drawn inside this box and every g so
that g o stays inside too (a policy meant for its cell); each verdict's note says so.
observations=[{...}, ...] or a path to a .jsonl / .npz file: draw every scene from your own
recorded observations instead of random ones, each a dict of world-frame "history" (H+1, 4, 4)
(and "chunk" (K, 4, 4), needed by audit()), "world_points" (m, 3) and "extra_poses" {name:
(4, 4)}, which move with g, and "hand_points" (n, 3), "scalars" {name: number} and "held"
{name: array} (a wrist camera's image, token ids), which g leaves alone; the callables then get
the recorded extra_poses= and scalars= and held={name: array} (float32 kept) as keywords. Without
world points in the data only the eye-in-hand view is audited. "episode": an integer per
observation, read by audit_policy's episodes= alone; with hands=, "history" is {hand: array}.
A progress line with the time left goes to stderr after 3 s (quiet=True: none). Needs NumPy
(ImportError at once without it); Ctrl-C stops it with KeyboardInterrupt.)doc";

struct CommonOptions {
  props::AuditOptions audit;
  std::vector<std::string> extra_poses, scalars;
  std::optional<int> batch_size;  ///< none: one scene per call
  CallOptions call;
  bool quiet = false;
  std::optional<int> history, hand_points, world_points, chunk;
};

/// ImportError, at once, unless NumPy imports: every argument of a callable under audit is a
/// NumPy array, and without NumPy no case could run (an audit used to report every cell failed
/// on 0 cases then).
void require_numpy(const char* function);

/// `noise` in [1, MAX_NOISE].
int noise_of(py::handle noise);

/// An optional integer keyword `name` in [low, high] (None: not given); ValueError / TypeError
/// naming the value and `bound` (how the caller spells the upper bound).
std::optional<int> optional_integer(py::handle value, const char* name, long long low,
                                    long long high, const char* bound);

/// The camera rig of cameras=, image_size=, channels= and floor= (None when cameras=None), its
/// images per batch bounded (2**26 float32 numbers) before anything is allocated.
std::shared_ptr<const props::CameraRig> camera_rig_of(const Setup& setup,
                                                      std::optional<int> batch_size);

/// What the caller does with recorded observations beyond single calls: replays their episodes
/// (audit_policy with episodes=), audits several hands (hands=). Data that carry an episode index
/// or one history per hand are refused otherwise, naming the keyword that reads them.
struct RecordedUse {
  bool episodes = false;
  bool hands = false;
};

CommonOptions common_options(py::handle groups, py::handle views, py::handle cases,
                             std::uint64_t seed, std::optional<double> tolerance,
                             const std::string& precision, py::handle extra_poses,
                             py::handle scalars, const Setup& setup, RecordedUse use = {});

props::ClassifierOptions classifier_for(const CommonOptions& o);

/// A whole policy's rng= (None, "torch", "numpy", "generator"), reset= (None or a callable),
/// action_format= and state_format= (pose format names, core/pose_format.hpp) checked and set on
/// o.call (ValueError / TypeError naming the value), and the preflight's fixes in Python's words
/// on c (`caller` is the function, for mode= advice).
void set_policy_call(CommonOptions& o, props::ClassifierOptions& c, py::handle rng,
                     py::handle reset, py::handle action_format, py::handle state_format,
                     const std::string& caller);

/// Prints "handcentric.audit_policy: 12 of 20 checks, 51200 rows asked (830 rows/s), 61.7 s,
/// about 41 s left" on stderr (the same line again on a terminal, a new line at most every 5 s
/// otherwise) once an audit has run for 3 s, while its checks run and as each ends, and lets a
/// pending Ctrl-C stop it between checks too.
class ProgressLine {
 public:
  ProgressLine(std::string function, bool quiet)
      : function_(std::move(function)), quiet_(quiet), start_(Clock::now()) {
    // HANDCENTRIC_PROGRESS_AFTER=S: print from S seconds on (a test's 0).
    if (const char* after = std::getenv("HANDCENTRIC_PROGRESS_AFTER")) after_ = std::atof(after);
  }
  ~ProgressLine() {
    if (!printed_ || !tty_) return;
    try {
      write("\n");
    } catch (...) {
    }
  }
  /// A check finished: `done` of `total`.
  void operator()(int done, int total) {
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    done_ = done;
    total_ = total;
    show(done >= total);
  }
  /// The callable is about to be asked about `rows` more observations (CallOptions::asked): a
  /// long check shows its progress before it ends.
  void asked(std::size_t rows) {
    rows_ += rows;
    show(false);
  }

 private:
  using Clock = std::chrono::steady_clock;
  static double seconds_since(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  }
  static void write(const std::string& text) {
    py::object err = py::module_::import("sys").attr("stderr");
    err.attr("write")(text);
    err.attr("flush")();
  }
  // "handcentric.audit_policy: 3 of 20 checks, 12416 rows asked (830 rows/s), 15.0 s, about 85 s
  // left": the time left from the checks done so far (none before the first ends).
  void show(bool last) {
    if (quiet_) return;
    const double elapsed = seconds_since(start_);
    if (elapsed < after_ || (done_ <= 0 && rows_ == 0)) return;
    if (!printed_) tty_ = py::module_::import("sys").attr("stderr").attr("isatty")().cast<bool>();
    if (printed_ && seconds_since(last_) < (tty_ ? 1.0 : 5.0) && !last) return;
    std::ostringstream line;
    line << std::fixed << std::setprecision(1) << (tty_ ? "\r" : "") << "handcentric." << function_
         << ": ";
    if (total_ > 0) {
      line << done_ << " of " << total_ << " checks";
    } else {
      line << "first check";  // the count of checks is known once one has ended
    }
    if (rows_ > 0) {
      line << ", " << rows_ << " rows asked (" << static_cast<long>(rows_ / elapsed + 0.5)
           << " rows/s)";
    }
    line << ", " << elapsed << " s";
    if (total_ > 0 && done_ >= total_) {
      line << ", done";
    } else if (done_ > 0) {
      const double left = elapsed / done_ * (total_ - done_);
      line << ", about " << static_cast<long>(left + 0.5) << " s left";
    }
    line << (tty_ ? "   " : "\n");
    write(line.str());
    printed_ = true;
    last_ = Clock::now();
  }
  std::string function_;
  bool quiet_;
  Clock::time_point start_, last_;
  bool printed_ = false, tty_ = false;
  double after_ = 3.0;
  int done_ = 0, total_ = 0;
  std::size_t rows_ = 0;
};

/// The callables as the checks see them (props/batch.hpp): answers cached, and batched when the
/// caller gave batch_size (InvalidArgument when batch_size x noise is above 2**24 numbers).
std::shared_ptr<props::BatchedRepresentation> batched_representation(py::object actions,
                                                                     py::object observation,
                                                                     py::object decode,
                                                                     const CommonOptions& o);
std::shared_ptr<props::BatchedPolicy> batched_policy(py::object policy, int noise,
                                                     const CommonOptions& o);

}  // namespace handcentric::python
