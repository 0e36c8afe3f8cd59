#pragma once
// How a front end names the audit's options in the errors and notes of props: the command line
// writes "--extra-poses" and "--precision float32", Python "extra_poses=" and
// precision="float32". props names no option on its own; the front end hands its spelling to
// AuditOptions (audit.hpp), and a message then reads in the words its caller typed.
#include <string>

namespace handcentric::props {

struct Spelling {
  bool command_line = true;  ///< false: Python's keywords
  /// The option `name` (in Python's spelling, e.g. "extra_poses") as the caller names it:
  /// "--extra-poses" or "extra_poses".
  std::string option(const std::string& name) const;
  /// The option with a value: "--precision float32" or "precision=\"float32\"" (the value
  /// quoted in Python when `quoted`).
  std::string with_value(const std::string& name, const std::string& value,
                         bool quoted = true) const;
};

inline const Spelling kCommandLineSpelling{true};
inline const Spelling kPythonSpelling{false};

}  // namespace handcentric::props
