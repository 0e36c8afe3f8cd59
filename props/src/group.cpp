#include "handcentric/props/group.hpp"

#include "handcentric/core/errors.hpp"

namespace handcentric::props {

const std::vector<Group>& all_groups() {
  static const std::vector<Group> groups = {Group::translation, Group::rotation, Group::se2,
                                            Group::se3, Group::c8};
  return groups;
}

std::string to_string(Group group) {
  switch (group) {
    case Group::translation:
      return "translation";
    case Group::rotation:
      return "rotation";
    case Group::se2:
      return "se2";
    case Group::se3:
      return "se3";
    case Group::c8:
      return "c8";
  }
  return "unknown";
}

Group parse_group(const std::string& name) {
  for (Group group : all_groups()) {
    if (to_string(group) == name) return group;
  }
  throw InvalidArgument("unknown group '" + name +
                        "'; choose one of translation, rotation, se2, se3, c8");
}

std::vector<Group> parse_groups(const std::vector<std::string>& names, const std::string& option,
                                const Spelling& spelling) {
  std::vector<Group> out;
  for (const std::string& name : names) {
    if (name == "all") return all_groups();
    out.push_back(parse_group(name));
  }
  if (out.empty())
    throw InvalidArgument(spelling.option(option) +
                          " is empty; name at least one of translation, rotation, se2, se3, c8");
  return out;
}

}  // namespace handcentric::props
