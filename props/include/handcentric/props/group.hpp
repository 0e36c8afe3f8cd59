#pragma once
// The transform families a representation is checked against (docs/AUDIT.md has how each is
// checked).
//
//   translation : p~ in R^3, R~ = I
//   rotation    : R~ in SO(3) about the world origin, p~ = 0
//   se2         : rotation about world z plus an x-y translation (planar SE(2))
//   se3         : any rigid transform
//   c8          : the 8 rotations about world z by multiples of 45 deg, through the origin
#include <string>
#include <vector>

#include "handcentric/props/spelling.hpp"

namespace handcentric::props {

enum class Group { translation, rotation, se2, se3, c8 };

/// All five, in the order above.
const std::vector<Group>& all_groups();

/// "translation", "rotation", "se2", "se3", "c8".
std::string to_string(Group group);

/// Parses a group name; throws handcentric::InvalidArgument naming the value and the valid names.
Group parse_group(const std::string& name);

/// The groups `names` name, in their order, or all_groups() when one of them is "all" (as the
/// command line's `--group rotation se3` and Python's groups=("rotation", "se3") take them).
/// Throws InvalidArgument for an unknown name (parse_group's message) or none, naming the option
/// `option` ("group" on the command line, "groups" in Python) in the caller's spelling.
std::vector<Group> parse_groups(const std::vector<std::string>& names, const std::string& option,
                                const Spelling& spelling = kCommandLineSpelling);

}  // namespace handcentric::props
