#include "handcentric/props/transport/subprocess.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <thread>

namespace handcentric::props {
namespace {

using Clock = std::chrono::steady_clock;

Clock::time_point deadline_after(double seconds) {
  return Clock::now() +
         std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

int remaining_ms(Clock::time_point deadline) {
  const auto left =
      std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left <= 0 ? 0 : static_cast<int>(std::min<long long>(left, 1 << 30));
}

void set_nonblocking(int fd) {
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
}

}  // namespace

std::string Subprocess::Exit::describe() const {
  if (exited) return "exited with status " + std::to_string(status);
  if (signaled) return "was killed by signal " + std::to_string(signal);
  return "closed its stdout";
}

Subprocess::Subprocess(std::string command, std::size_t max_line_bytes)
    : command_(std::move(command)), max_line_bytes_(max_line_bytes) {
  ::signal(SIGPIPE, SIG_IGN);  // a dead child gives EPIPE, which the caller reports
  int in[2], out[2], err[2];
  if (pipe2(in, O_CLOEXEC) != 0)
    throw PluginError("cannot create pipes for '" + command_ + "': " + std::strerror(errno));
  if (pipe2(out, O_CLOEXEC) != 0 || pipe2(err, O_CLOEXEC) != 0) {
    const std::string reason = std::strerror(errno);
    close(in[0]);
    close(in[1]);
    throw PluginError("cannot create pipes for '" + command_ + "': " + reason);
  }
  pid_ = fork();
  if (pid_ < 0) {
    const std::string reason = std::strerror(errno);
    for (int fd : {in[0], in[1], out[0], out[1], err[0], err[1]}) close(fd);
    throw PluginError("cannot start '" + command_ + "': " + reason);
  }
  if (pid_ ==
      0) {  // child: its own process group, the pipes as stdin, stdout, stderr, then the shell
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
  stdin_ = in[1];
  stdout_ = out[0];
  stderr_ = err[0];
  for (int fd : {stdin_, stdout_, stderr_}) set_nonblocking(fd);
}

Subprocess::~Subprocess() {
  finish(0.5);
  close_fd(stdout_);
  close_fd(stderr_);
}

void Subprocess::close_fd(int& fd) {
  if (fd >= 0) close(fd);
  fd = -1;
}

void Subprocess::drain_stderr(bool until_eof) {
  char chunk[4096];
  while (stderr_ >= 0) {
    const ssize_t n = read(stderr_, chunk, sizeof(chunk));
    if (n == 0) {
      close_fd(stderr_);
      break;
    }
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN && until_eof) {
        pollfd fd = {stderr_, POLLIN, 0};
        if (poll(&fd, 1, 100) > 0) continue;
      }
      break;
    }
    for (ssize_t i = 0; i < n; ++i) {
      if (chunk[i] == '\n') {
        stderr_lines_.push_back(std::move(stderr_partial_));
        stderr_partial_.clear();
        if (stderr_lines_.size() > static_cast<std::size_t>(kStderrLines))
          stderr_lines_.pop_front();
      } else if (stderr_partial_.size() < kStderrLineBytes) {
        stderr_partial_ += chunk[i];
      }
    }
  }
}

std::string Subprocess::stderr_tail() {
  drain_stderr(false);
  std::deque<std::string> lines = stderr_lines_;
  if (!stderr_partial_.empty()) lines.push_back(stderr_partial_);
  while (lines.size() > static_cast<std::size_t>(kStderrLines)) lines.pop_front();
  std::string text;
  for (std::string& line : lines) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    text += line + "\n";
  }
  return text;
}

Subprocess::Outcome Subprocess::write_all(const std::string& bytes, double timeout) {
  const auto deadline = deadline_after(timeout);
  for (std::size_t written = 0; written < bytes.size();) {
    if (stdin_ < 0) return Outcome::closed;
    const ssize_t n = write(stdin_, bytes.data() + written, bytes.size() - written);
    if (n > 0) {
      written += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno != EAGAIN) return Outcome::closed;  // EPIPE: the child is gone
    drain_stderr(false);  // a child blocked on a full stderr pipe would never read its stdin
    pollfd fd = {stdin_, POLLOUT, 0};
    if (poll(&fd, 1, std::min(remaining_ms(deadline), 50)) == 0 && remaining_ms(deadline) == 0) {
      return Outcome::timed_out;
    }
  }
  return Outcome::done;
}

Subprocess::Outcome Subprocess::read_line(std::string& line, double timeout) {
  const auto deadline = deadline_after(timeout);
  for (;;) {
    const std::size_t newline = stdout_buffer_.find('\n');
    if (newline != std::string::npos) {
      line = stdout_buffer_.substr(0, newline);
      stdout_buffer_.erase(0, newline + 1);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      return Outcome::done;
    }
    if (stdout_buffer_.size() > max_line_bytes_) return Outcome::too_long;
    if (stdout_ < 0) return Outcome::closed;
    pollfd fds[2] = {{stdout_, POLLIN, 0}, {stderr_, POLLIN, 0}};
    const int ready = poll(fds, stderr_ >= 0 ? 2 : 1, remaining_ms(deadline));
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0) return Outcome::timed_out;
    if (stderr_ >= 0 && (fds[1].revents & (POLLIN | POLLHUP | POLLERR)) != 0) drain_stderr(false);
    if ((fds[0].revents & (POLLIN | POLLHUP | POLLERR)) != 0) {
      char chunk[65536];
      const ssize_t n = read(stdout_, chunk, sizeof(chunk));
      if (n > 0) {
        stdout_buffer_.append(chunk, static_cast<std::size_t>(n));
      } else if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
        close_fd(stdout_);
        return Outcome::closed;
      }
    }
  }
}

void Subprocess::kill() {
  if (pid_ > 0 && !exit_) ::kill(-pid_, SIGKILL);
}

Subprocess::Exit Subprocess::finish(double grace) {
  if (exit_) return *exit_;
  close_fd(stdin_);  // EOF on its stdin: a well-behaved child exits
  Exit result;
  int status = 0;
  const auto deadline = deadline_after(grace);
  for (;;) {
    const pid_t got = waitpid(pid_, &status, WNOHANG);
    if (got == pid_) {
      result.reaped = true;
      break;
    }
    if (got < 0 && errno != EINTR) break;
    if (remaining_ms(deadline) == 0) break;
    drain_stderr(false);  // a child blocked on a full stderr pipe could not exit
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (!result.reaped) {
    ::kill(-pid_, SIGKILL);  // the shell and whatever it started
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
  }
  // Whatever the child still had to say on stderr (a traceback written just before exiting).
  drain_stderr(true);
  result.exited = result.reaped && WIFEXITED(status);
  result.status = result.exited ? WEXITSTATUS(status) : 0;
  result.signaled = result.reaped && WIFSIGNALED(status);
  result.signal = result.signaled ? WTERMSIG(status) : 0;
  exit_ = result;
  return result;
}

}  // namespace handcentric::props
