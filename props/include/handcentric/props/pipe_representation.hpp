#pragma once
// A representation written in any language, spoken to over a pipe (docs/AUDIT.md, "--exec").
//
// The command is started once, through /bin/sh -c, and answers JSON Lines on stdin/stdout:
//   request : {"id": n, "history": [H+1 matrices, [0] = T_0], "chunk": [K matrices],
//              "hand_points": [[x, y, z], ...], "world_points": [[x, y, z], ...]}
//             (each matrix 16 numbers, row-major 4x4)
//   response: {"id": n, "actions": [numbers], "observation": [numbers]}  (observation optional)
// Every way a plug-in can misbehave becomes a PluginError with a one-line message: the command
// is not found, exits early (its stderr is quoted), answers something that is not JSON, the
// wrong id, a NaN or Inf, a vector whose length changes between scenes of the same shape, or
// nothing within the timeout (read with poll(), so the audit never hangs).
//
// Answers are cached by request, so a scene is sent once however many checks read it. Not
// thread-safe. Constructing one ignores SIGPIPE for the process (a dead plug-in must give an
// error, not kill the audit).
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <unordered_map>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/representation.hpp"

namespace handcentric::props {

/// A plug-in that failed: not found, crashed, wrong answer, too slow.
class PluginError : public Error {
 public:
  using Error::Error;
};

class PipeRepresentation final : public Representation {
 public:
  /// Starts `command`. Throws InvalidArgument for an empty command or a timeout <= 0,
  /// PluginError if the process cannot be started.
  PipeRepresentation(std::string command, double timeout_seconds);
  ~PipeRepresentation() override;
  PipeRepresentation(const PipeRepresentation&) = delete;
  PipeRepresentation& operator=(const PipeRepresentation&) = delete;

  std::string name() const override;
  Eigen::VectorXd encode_actions(const Scene& scene) const override;
  /// Empty when the plug-in sends no observation.
  Eigen::VectorXd encode_observation(const Scene& scene) const override;
  bool can_decode() const override { return false; }
  /// Throws InvalidArgument: a plug-in only encodes.
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& actions,
                                             const RigidTransform& world_T_hand0) const override;

  /// Whether the plug-in sent an "observation" (asks it about a small scene if not asked yet).
  bool provides_observation() const;
  /// Requests actually sent (cache misses).
  int requests_sent() const { return next_id_; }
  /// Seconds spent in ask() for requests sent (formatting, writing, waiting, parsing), and the
  /// part of it spent waiting for the plug-in's answer: their difference is the pipe's overhead.
  double seconds_asking() const { return seconds_asking_; }
  double seconds_waiting() const { return seconds_waiting_; }

 private:
  struct Answer {
    Eigen::VectorXd actions;
    Eigen::VectorXd observation;
    bool has_observation = false;
  };
  const Answer& ask(const Scene& scene) const;
  std::string read_line(int id) const;
  [[noreturn]] void fail_exited(const std::string& when) const;
  std::string drain_stderr() const;

  std::string command_;
  double timeout_seconds_;
  mutable int pid_ = -1;
  int to_child_ = -1, from_child_ = -1;
  mutable int child_stderr_ = -1;
  mutable int next_id_ = 0;
  mutable std::string buffer_;  ///< bytes read past the last newline
  mutable std::unordered_map<std::string, Answer> cache_;
  /// (H, K, #hand points, #world points) -> (actions length, observation length, has observation)
  mutable std::map<std::tuple<int, int, int, int>, std::tuple<Eigen::Index, Eigen::Index, bool>> lengths_;
  mutable bool dead_ = false;
  mutable std::string stderr_tail_;
  mutable double seconds_asking_ = 0.0, seconds_waiting_ = 0.0;  ///< the last 4000 bytes of its stderr
};

}  // namespace handcentric::props
