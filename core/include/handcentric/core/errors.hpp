#pragma once
// Typed errors thrown at every boundary that takes outside data. Each message names the
// offending value and says how to fix it; `handcentric` prints it on one line and exits 1.
#include <stdexcept>
#include <string>

namespace handcentric {

/// Base of every error handcentric throws on bad input.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
  /// The message, then the context added by a caller that knows where it happened (the audit
  /// names the case, the seed and the observation of an error raised by the policy).
  const char* what() const noexcept override {
    return full_.empty() ? std::runtime_error::what() : full_.c_str();
  }
  /// Appends " (context)" to what(); the dynamic type is kept, so a caller that catches by
  /// reference, adds where, and rethrows changes nothing else.
  void add_context(const std::string& context) {
    full_ = std::string(what()) + " (" + context + ")";
    context_ = context_.empty() ? context : context_ + "; " + context;
  }
  /// What add_context added, "" when nothing was.
  const std::string& context() const { return context_; }

 private:
  std::string full_, context_;
};

/// A matrix or quaternion that is not a rotation: non-finite, not orthonormal, det = -1, zero.
class InvalidRotation : public Error {
 public:
  using Error::Error;
};

/// A rigid transform with a non-finite translation or a bad homogeneous row.
class InvalidTransform : public Error {
 public:
  using Error::Error;
};

/// A scene that a representation cannot read: empty history or chunk, non-finite points.
class InvalidScene : public Error {
 public:
  using Error::Error;
};

/// A policy produced a non-finite action or pose (nan or infinity): its network diverged on this
/// observation, or the observation is far outside its training data. A ChunkPolicy throws it
/// rather than return such a chunk; sim's rollouts count the trial as invalid instead of stopping
/// (`handcentric eval --strict` stops).
class NonFiniteAction : public InvalidScene {
 public:
  using InvalidScene::InvalidScene;
};

/// A file that cannot be read or written: names the path, the reason and the fix.
class FileError : public Error {
 public:
  using Error::Error;
};

/// Any other bad argument: a wrong vector length, an unknown name, an out-of-range number.
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

}  // namespace handcentric
