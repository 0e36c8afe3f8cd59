#include "handcentric/props/transport/plugin_connection.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>

#include "handcentric/core/format.hpp"

namespace handcentric::props {
namespace {

using Clock = std::chrono::steady_clock;

const std::string& checked(const std::string& command, double timeout_seconds) {
  if (command.find_first_not_of(" \t") == std::string::npos) {
    throw InvalidArgument(
        "--exec needs a command, got an empty one; e.g. --exec 'python3 repr.py'");
  }
  if (!(timeout_seconds > 0.0) || !std::isfinite(timeout_seconds)) {
    throw InvalidArgument("--timeout must be a positive number of seconds, got " +
                          format_number(timeout_seconds));
  }
  return command;
}

}  // namespace

PluginConnection::PluginConnection(std::string command, double timeout_seconds)
    : command_(std::move(command)),
      timeout_seconds_(timeout_seconds),
      process_(checked(command_, timeout_seconds)) {}

void PluginConnection::fail(const std::string& what) {
  dead_ = true;
  const std::string tail = process_.stderr_tail();
  if (tail.empty()) throw PluginError(what + " (nothing on stderr)");
  std::string quoted;
  std::size_t begin = 0;
  for (std::size_t end; (end = tail.find('\n', begin)) != std::string::npos; begin = end + 1) {
    quoted += "\n    " + tail.substr(begin, end - begin);
  }
  throw PluginError(what + "; its stderr (last lines):" + quoted);
}

void PluginConnection::fail_exited(const std::string& when) {
  const Subprocess::Exit exit = process_.finish(1.0);
  if (exit.exited && exit.status == 127)
    fail("plug-in command not found: '" + command_ + "'; check the program name and path");
  fail(who() + " " + exit.describe() + " " + when);
}

std::string PluginConnection::round_trip(const std::string& body, int scenes) {
  if (dead_) throw PluginError(who() + " failed earlier and was stopped");
  const int id = next_id_++;
  // --timeout is per answer: a batch of n scenes has n times as long (to be read and answered).
  const double timeout = timeout_seconds_ * scenes;
  const std::string allowed =
      format_shortest(timeout) + (scenes > 1
                                      ? " s (--timeout " + format_shortest(timeout_seconds_) +
                                            " s per scene, " + std::to_string(scenes) + " scenes)"
                                      : " s");
  const auto started = Clock::now();
  switch (process_.write_all(request_line(id, body), timeout)) {
    case Subprocess::Outcome::done:
      break;
    case Subprocess::Outcome::closed:
      fail_exited("before reading request " + std::to_string(id));
    case Subprocess::Outcome::too_long:
      break;  // writing has no line limit
    case Subprocess::Outcome::timed_out:
      process_.kill();
      fail(who() + " did not read request " + std::to_string(id) + " within " + allowed +
           "; raise --timeout if it is just slow");
  }
  const auto written = Clock::now();
  std::string line;
  switch (process_.read_line(line, timeout)) {
    case Subprocess::Outcome::done:
      break;
    case Subprocess::Outcome::closed:
      fail_exited("before answering request " + std::to_string(id));
    case Subprocess::Outcome::too_long:
      process_.kill();
      fail(who() + " answered request " + std::to_string(id) + " with a line longer than " +
           std::to_string(Subprocess::kMaxLineBytes >> 20) +
           " MiB; answers are one line of JSON, " +
           (scenes > 1 ? "far shorter (or declare a smaller \"batch\" in the hello)"
                       : "far shorter"));
    case Subprocess::Outcome::timed_out:
      process_.kill();
      fail(who() + " gave no answer to request " + std::to_string(id) + " within " + allowed +
           "; a plug-in must write one line per request and flush it (Python: print(..., "
           "flush=True) or sys.stdout.flush(), or run it as python3 -u: a pipe is block-buffered), "
           "or raise --timeout if it is just slow");
  }
  seconds_waiting_ += std::chrono::duration<double>(Clock::now() - written).count();
  started_ = started;
  return line;
}

PluginReply PluginConnection::exchange(RequestKind kind, const std::string& body,
                                       bool hello_allowed, const PolicyInterface* interface) {
  const std::string line = round_trip(body, 1);
  PluginReply reply;
  try {
    reply = parse_reply(line, last_id(), kind, who(), hello_allowed, interface);
  } catch (const PluginError& e) {
    fail(e.what());
  }
  seconds_asking_ += std::chrono::duration<double>(Clock::now() - started_).count();
  return reply;
}

std::vector<PluginReply> PluginConnection::exchange_batch(RequestKind kind,
                                                          const std::vector<std::string>& bodies,
                                                          NumberEncoding encoding,
                                                          const PolicyInterface* interface) {
  const std::string line =
      round_trip(batch_request_body(bodies, encoding), static_cast<int>(bodies.size()));
  std::vector<PluginReply> replies;
  try {
    replies = parse_batch_reply(line, last_id(), kind, who(), bodies.size(), interface);
  } catch (const PluginError& e) {
    fail(e.what());
  }
  seconds_asking_ += std::chrono::duration<double>(Clock::now() - started_).count();
  return replies;
}

}  // namespace handcentric::props
