#pragma once
// Errors of the policy module, on top of core/errors.hpp.
#include "handcentric/core/errors.hpp"

namespace handcentric {

/// A model file that cannot be read: missing, truncated, corrupted (checksum), a wrong version
/// or not a handcentric model at all. The message names the file and what to do.
class InvalidModelFile : public Error {
 public:
  using Error::Error;
};

/// A model used on a task it was not trained for (a 2D model on the 3D task or the reverse): the
/// message names the file, both tasks and the fix.
class TaskMismatch : public InvalidArgument {
 public:
  using InvalidArgument::InvalidArgument;
};

}  // namespace handcentric
