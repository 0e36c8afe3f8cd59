#pragma once
// One plug-in process and the request/answer exchange with it (docs/AUDIT.md, "--exec"): a
// Subprocess (subprocess.hpp) that sends protocol lines (plugin_protocol.hpp) and turns every
// way the plug-in can misbehave into a PluginError. The first line of the message says what
// happened; when the plug-in wrote on stderr, its last 20 lines follow, indented. After a
// failure the connection refuses further requests. Not thread-safe.
#include <chrono>
#include <string>
#include <vector>

#include "handcentric/props/transport/plugin_protocol.hpp"
#include "handcentric/props/transport/subprocess.hpp"

namespace handcentric::props {

/// Seconds a plug-in has for each answer unless its caller says otherwise (`handcentric audit
/// --timeout`): long enough for a network's first call, short enough that a hung plug-in is
/// named within a CI step.
inline constexpr double kDefaultPluginTimeout = 10.0;

class PluginConnection {
 public:
  /// Starts `command`. Throws InvalidArgument for an empty command or a timeout <= 0,
  /// PluginError if the process cannot be started.
  PluginConnection(std::string command, double timeout_seconds);

  /// Sends request `body` (the next id) and returns its parsed, validated answer.
  /// A policy reply is read under `interface` when given (plugin_protocol.hpp, parse_reply).
  PluginReply exchange(RequestKind kind, const std::string& body, bool hello_allowed,
                       const PolicyInterface* interface = nullptr);
  /// Sends one batched request (plugin_protocol.hpp, "batch") holding `bodies`, each the body
  /// of a single request written in `encoding`, and returns the answers in their order. The
  /// deadline is the timeout times the number of scenes.
  std::vector<PluginReply> exchange_batch(RequestKind kind, const std::vector<std::string>& bodies,
                                          NumberEncoding encoding,
                                          const PolicyInterface* interface = nullptr);
  /// Throws PluginError(what + the stderr tail) and refuses further requests.
  [[noreturn]] void fail(const std::string& what);

  const std::string& command() const { return command_; }
  /// "plug-in 'COMMAND'", for messages.
  std::string who() const { return "plug-in '" + command_ + "'"; }
  /// The id of the last request sent (-1 before the first).
  int last_id() const { return next_id_ - 1; }
  /// Requests sent.
  int requests_sent() const { return next_id_; }
  /// Seconds spent exchanging (formatting, writing, waiting, parsing), and the part of it spent
  /// waiting for the plug-in's answer: their difference is the pipe's overhead.
  double seconds_asking() const { return seconds_asking_; }
  double seconds_waiting() const { return seconds_waiting_; }

 private:
  [[noreturn]] void fail_exited(const std::string& when);
  /// Writes request `body` (the next id) answering for `scenes` scenes, and reads its line.
  std::string round_trip(const std::string& body, int scenes);

  std::string command_;
  double timeout_seconds_;
  Subprocess process_;
  int next_id_ = 0;
  bool dead_ = false;
  double seconds_asking_ = 0.0, seconds_waiting_ = 0.0;
  std::chrono::steady_clock::time_point started_;  ///< when the last round trip began
};

}  // namespace handcentric::props
