#include "handcentric/props/pipe_representation.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <thread>

#include "handcentric/core/format.hpp"

namespace handcentric::props {
namespace {

using Clock = std::chrono::steady_clock;

void append_number(std::string& out, double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.17g", value);
  out += text;
}

void append_matrix(std::string& out, const RigidTransform& T) {
  const Eigen::Matrix4d M = T.matrix();
  out += '[';
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      if (r + c > 0) out += ", ";
      append_number(out, M(r, c));
    }
  }
  out += ']';
}

void append_points(std::string& out, const std::vector<Eigen::Vector3d>& points) {
  out += '[';
  for (std::size_t i = 0; i < points.size(); ++i) {
    out += i > 0 ? ", [" : "[";
    for (int j = 0; j < 3; ++j) {
      if (j > 0) out += ", ";
      append_number(out, points[i](j));
    }
    out += ']';
  }
  out += ']';
}

// The request without its id: also the cache key.
std::string request_body(const Scene& scene) {
  std::string out = "\"history\": [";
  for (std::size_t h = 0; h < scene.world_T_hand_history.size(); ++h) {
    if (h > 0) out += ", ";
    append_matrix(out, scene.world_T_hand_history[h]);
  }
  out += "], \"chunk\": [";
  for (std::size_t k = 0; k < scene.world_T_hand_chunk.size(); ++k) {
    if (k > 0) out += ", ";
    append_matrix(out, scene.world_T_hand_chunk[k]);
  }
  out += "], \"hand_points\": ";
  append_points(out, scene.hand_points);
  out += ", \"world_points\": ";
  append_points(out, scene.world_points);
  return out + "}\n";
}

// One line, at most `limit` characters: for quoting what a plug-in said.
std::string one_line(std::string text, std::size_t limit = 200) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) text.pop_back();
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = '|';
  }
  if (text.size() > limit) text = text.substr(0, limit) + "...";
  return text;
}

// A duration as the user typed it: 0.3, not 0.29999999999999999.
std::string seconds_text(double seconds) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", seconds);
  return text;
}

int remaining_ms(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left <= 0 ? 0 : static_cast<int>(std::min<long long>(left, 1 << 30));
}

Eigen::VectorXd read_numbers(const nlohmann::json& value, const std::string& field, int id, const std::string& who) {
  if (!value.is_array()) {
    throw PluginError(who + " answered request " + std::to_string(id) + " with \"" + field +
                      "\" that is not an array of numbers");
  }
  Eigen::VectorXd v(static_cast<Eigen::Index>(value.size()));
  for (std::size_t i = 0; i < value.size(); ++i) {
    if (!value[i].is_number()) {
      throw PluginError(who + " answered request " + std::to_string(id) + " with \"" + field + "\"[" +
                        std::to_string(i) + "] = " + one_line(value[i].dump(), 40) + ", not a number");
    }
    const double x = value[i].get<double>();
    if (!std::isfinite(x)) {
      throw PluginError(who + " answered request " + std::to_string(id) + " with a non-finite \"" + field +
                        "\"[" + std::to_string(i) + "] = " + format_number(x) + "; send finite numbers only");
    }
    v(static_cast<Eigen::Index>(i)) = x;
  }
  return v;
}

}  // namespace

PipeRepresentation::PipeRepresentation(std::string command, double timeout_seconds)
    : command_(std::move(command)), timeout_seconds_(timeout_seconds) {
  if (command_.find_first_not_of(" \t") == std::string::npos) {
    throw InvalidArgument("--exec needs a command, got an empty one; e.g. --exec 'python3 repr.py'");
  }
  if (!(timeout_seconds_ > 0.0) || !std::isfinite(timeout_seconds_)) {
    throw InvalidArgument("--timeout must be a positive number of seconds, got " + format_number(timeout_seconds_));
  }
  ::signal(SIGPIPE, SIG_IGN);  // a dead plug-in gives EPIPE, which we report
  int in[2], out[2], err[2];
  if (pipe2(in, O_CLOEXEC) != 0 || pipe2(out, O_CLOEXEC) != 0 || pipe2(err, O_CLOEXEC) != 0) {
    throw PluginError("cannot create pipes for plug-in '" + command_ + "': " + std::strerror(errno));
  }
  pid_ = fork();
  if (pid_ < 0) throw PluginError("cannot start plug-in '" + command_ + "': " + std::strerror(errno));
  if (pid_ == 0) {  // child: its own process group, stdin, stdout, stderr onto the pipes, then the shell
    setpgid(0, 0);
    dup2(in[0], 0);
    dup2(out[1], 1);
    dup2(err[1], 2);
    execl("/bin/sh", "sh", "-c", command_.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  close(in[0]);
  close(out[1]);
  close(err[1]);
  to_child_ = in[1];
  from_child_ = out[0];
  child_stderr_ = err[0];
  fcntl(from_child_, F_SETFL, fcntl(from_child_, F_GETFL) | O_NONBLOCK);
  fcntl(child_stderr_, F_SETFL, fcntl(child_stderr_, F_GETFL) | O_NONBLOCK);
  fcntl(to_child_, F_SETFL, fcntl(to_child_, F_GETFL) | O_NONBLOCK);
}

PipeRepresentation::~PipeRepresentation() {
  if (to_child_ >= 0) close(to_child_);  // EOF on its stdin: a well-behaved plug-in exits
  if (pid_ > 0) {
    int status = 0;
    bool reaped = false;
    for (int i = 0; i < 50 && !reaped; ++i) {
      reaped = waitpid(pid_, &status, WNOHANG) == pid_;
      if (!reaped) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (!reaped) {
      kill(-pid_, SIGKILL);  // the shell and whatever it started
      waitpid(pid_, &status, 0);
    }
  }
  if (from_child_ >= 0) close(from_child_);
  if (child_stderr_ >= 0) close(child_stderr_);
}

std::string PipeRepresentation::name() const { return "exec: " + command_; }

std::string PipeRepresentation::drain_stderr() const {
  if (child_stderr_ < 0) return stderr_tail_;
  char chunk[4096];
  for (;;) {
    const ssize_t n = read(child_stderr_, chunk, sizeof(chunk));
    if (n <= 0) break;
    stderr_tail_.append(chunk, static_cast<std::size_t>(n));
    if (stderr_tail_.size() > 4000) stderr_tail_.erase(0, stderr_tail_.size() - 4000);
  }
  return stderr_tail_;
}

void PipeRepresentation::fail_exited(const std::string& when) const {
  dead_ = true;
  int status = 0;
  bool reaped = false;
  for (int i = 0; i < 100 && !reaped; ++i) {  // it closed its stdout; give it up to 1 s to exit
    reaped = waitpid(pid_, &status, WNOHANG) == pid_;
    if (!reaped) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (!reaped) {
    kill(-pid_, SIGKILL);  // the shell and whatever it started
    waitpid(pid_, &status, 0);
  }
  pid_ = -1;
  const std::string err = one_line(drain_stderr());
  const std::string quoted = err.empty() ? "(nothing on stderr)" : "its stderr: " + err;
  if (reaped && WIFEXITED(status) && WEXITSTATUS(status) == 127) {
    throw PluginError("plug-in command not found: '" + command_ + "' (" + quoted +
                      "); check the program name and path");
  }
  std::string how = "closed its stdout";
  if (reaped && WIFEXITED(status)) how = "exited with status " + std::to_string(WEXITSTATUS(status));
  if (reaped && WIFSIGNALED(status)) how = "was killed by signal " + std::to_string(WTERMSIG(status));
  throw PluginError("plug-in '" + command_ + "' " + how + " " + when + "; " + quoted);
}

std::string PipeRepresentation::read_line(int id) const {
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(timeout_seconds_));
  for (;;) {
    const std::size_t newline = buffer_.find('\n');
    if (newline != std::string::npos) {
      std::string line = buffer_.substr(0, newline);
      buffer_.erase(0, newline + 1);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      return line;
    }
    pollfd fds[2] = {{from_child_, POLLIN, 0}, {child_stderr_, POLLIN, 0}};
    const int ready = poll(fds, child_stderr_ >= 0 ? 2 : 1, remaining_ms(deadline));
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0) {
      dead_ = true;
      kill(-pid_, SIGKILL);  // the shell and whatever it started
      throw PluginError("plug-in '" + command_ + "' gave no answer to request " + std::to_string(id) + " within " +
                        seconds_text(timeout_seconds_) + " s; make it answer one line per request, or raise --timeout");
    }
    if (child_stderr_ >= 0 && (fds[1].revents & (POLLIN | POLLHUP)) != 0) {
      char chunk[4096];
      const ssize_t n = read(child_stderr_, chunk, sizeof(chunk));
      if (n > 0) {
        stderr_tail_.append(chunk, static_cast<std::size_t>(n));
        if (stderr_tail_.size() > 4000) stderr_tail_.erase(0, stderr_tail_.size() - 4000);
      } else if (n == 0) {
        close(child_stderr_);
        child_stderr_ = -1;
      }
    }
    if ((fds[0].revents & (POLLIN | POLLHUP | POLLERR)) != 0) {
      char chunk[65536];
      const ssize_t n = read(from_child_, chunk, sizeof(chunk));
      if (n > 0) {
        buffer_.append(chunk, static_cast<std::size_t>(n));
      } else if (n == 0) {
        fail_exited("before answering request " + std::to_string(id));
      } else if (errno != EAGAIN && errno != EINTR) {
        fail_exited("(read error " + std::string(std::strerror(errno)) + ")");
      }
    }
  }
}

const PipeRepresentation::Answer& PipeRepresentation::ask(const Scene& scene) const {
  scene.validate_observation();
  const std::string body = request_body(scene);
  if (const auto hit = cache_.find(body); hit != cache_.end()) return hit->second;
  if (dead_) throw PluginError("plug-in '" + command_ + "' failed earlier and was stopped");
  const int id = next_id_++;
  const auto started = Clock::now();
  const std::string line = "{\"id\": " + std::to_string(id) + ", " + body;
  // Write the whole line, waiting (up to the timeout) while the plug-in's stdin pipe is full.
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(timeout_seconds_));
  for (std::size_t written = 0; written < line.size();) {
    const ssize_t n = write(to_child_, line.data() + written, line.size() - written);
    if (n > 0) {
      written += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EPIPE) fail_exited("before reading request " + std::to_string(id));
    if (n < 0 && errno != EAGAIN && errno != EINTR) {
      throw PluginError("cannot write to plug-in '" + command_ + "': " + std::strerror(errno));
    }
    pollfd fd = {to_child_, POLLOUT, 0};
    if (poll(&fd, 1, remaining_ms(deadline)) == 0) {
      dead_ = true;
      kill(-pid_, SIGKILL);  // the shell and whatever it started
      throw PluginError("plug-in '" + command_ + "' did not read request " + std::to_string(id) + " within " +
                        seconds_text(timeout_seconds_) + " s; raise --timeout if it is just slow");
    }
  }
  const auto written = Clock::now();
  const std::string reply = read_line(id);
  seconds_waiting_ += std::chrono::duration<double>(Clock::now() - written).count();
  const std::string who = "plug-in '" + command_ + "'";
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(reply);
  } catch (const nlohmann::json::exception& e) {
    dead_ = true;
    // JSON has no NaN or Infinity; Python's json module writes them anyway, and 1e999 overflows.
    const bool non_finite = reply.find("NaN") != std::string::npos || reply.find("Infinity") != std::string::npos ||
                            std::string(e.what()).find("overflow") != std::string::npos;
    throw PluginError(who + " answered request " + std::to_string(id) +
                      (non_finite ? " with a non-finite number (NaN, Infinity or an overflow, e.g. 1e999 -> inf), which is not JSON; send finite numbers only: "
                                  : " with a line that is not JSON: ") +
                      "'" + one_line(reply, 120) + "'");
  }
  if (!json.is_object() || !json.contains("id") || !json.contains("actions")) {
    dead_ = true;
    throw PluginError(who + " answered request " + std::to_string(id) +
                      " without \"id\" and \"actions\": '" + one_line(reply, 120) + "'");
  }
  if (!json["id"].is_number_integer() || json["id"].get<long long>() != id) {
    dead_ = true;
    throw PluginError(who + " answered request " + std::to_string(id) + " with id " + one_line(json["id"].dump(), 40) +
                      "; answer each request, in order, with its own id");
  }
  Answer answer;
  answer.actions = read_numbers(json["actions"], "actions", id, who);
  if (answer.actions.size() == 0) throw PluginError(who + " answered request " + std::to_string(id) + " with no actions");
  answer.has_observation = json.contains("observation") && !json["observation"].is_null();
  if (answer.has_observation) answer.observation = read_numbers(json["observation"], "observation", id, who);
  const auto shape = std::make_tuple(scene.history_length(), scene.chunk_length(),
                                     static_cast<int>(scene.hand_points.size()), static_cast<int>(scene.world_points.size()));
  const auto lengths = std::make_tuple(answer.actions.size(), answer.observation.size(), answer.has_observation);
  const auto [known, inserted] = lengths_.emplace(shape, lengths);
  if (!inserted && known->second != lengths) {
    dead_ = true;
    throw PluginError(who + " changed its vector lengths between scenes of the same shape (H = " +
                      std::to_string(std::get<0>(shape)) + ", K = " + std::to_string(std::get<1>(shape)) + ", " +
                      std::to_string(std::get<2>(shape)) + " eye-in-hand and " + std::to_string(std::get<3>(shape)) +
                      " world points): actions " + std::to_string(std::get<0>(known->second)) + " then " +
                      std::to_string(answer.actions.size()) + " numbers, observation " +
                      std::to_string(std::get<1>(known->second)) + " then " + std::to_string(answer.observation.size()) +
                      " (request " + std::to_string(id) + "); a length may depend on the scene's shape only");
  }
  seconds_asking_ += std::chrono::duration<double>(Clock::now() - started).count();
  if (cache_.size() > 200000) cache_.clear();
  return cache_.emplace(body, std::move(answer)).first->second;
}

Eigen::VectorXd PipeRepresentation::encode_actions(const Scene& scene) const { return ask(scene).actions; }

Eigen::VectorXd PipeRepresentation::encode_observation(const Scene& scene) const { return ask(scene).observation; }

std::vector<RigidTransform> PipeRepresentation::decode_actions(const Eigen::VectorXd&, const RigidTransform&) const {
  throw InvalidArgument("representation '" + name() + "' is a plug-in: it encodes only, it cannot decode actions");
}

bool PipeRepresentation::provides_observation() const {
  if (lengths_.empty()) {
    Scene probe;
    probe.world_T_hand_history = {RigidTransform::identity()};
    probe.world_T_hand_chunk = {RigidTransform::from_translation(Eigen::Vector3d(0.1, 0.0, 0.0))};
    ask(probe);
  }
  for (const auto& entry : lengths_) {
    if (std::get<2>(entry.second)) return true;
  }
  return false;
}

}  // namespace handcentric::props
