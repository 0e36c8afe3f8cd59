#include "handcentric/experiments/methods.hpp"

#include <algorithm>
#include <sstream>

#include "handcentric/core/errors.hpp"

namespace handcentric::experiments {
namespace {

constexpr const char* kMethodNames =
    "hand_centric, relative, absolute, c8_centre, c8_base, c8_averaged, c8flow_centre, "
    "c8flow_averaged";

}  // namespace

std::vector<std::string> split_list(const std::string& list) {
  std::vector<std::string> items;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) items.push_back(item);
  return items;
}

const std::vector<Method>& table1_methods() {
  static const std::vector<Method> methods = {
      {"hand_centric", "hand_centric", "", "Hand-Centric"},
      {"relative", "relative", "", "Relative-Action"},
      {"absolute", "absolute", "", "Absolute-Action"},
      {"c8_centre", "absolute", "c8ddpm",
       "C8 DDPM about the workspace centre (0, 0) (stand-in for Equivariant-DiffPo [7])",
       kWorkspaceCentre},
      {"c8_base", "absolute", "c8ddpm",
       "C8 DDPM about a robot base at (0, -60) (stand-in for Equivariant-DiffPo [7])", kRobotBase},
      {"c8_averaged", "absolute", "c8ddpm_avg",
       "C8 DDPM about the workspace centre (0, 0), each denoising step averaged over C8: "
       "equivariant by construction (stand-in for Equivariant-DiffPo [7])",
       kWorkspaceCentre},
      {"c8flow_centre", "absolute", "c8flow_planar",
       "C8 flow about the workspace centre (0, 0) (the rectified flow in place of the DDPM)",
       kWorkspaceCentre},
      {"c8flow_averaged", "absolute", "c8flow_avg",
       "C8 flow about the workspace centre (0, 0), each Euler step averaged over C8: "
       "equivariant by construction",
       kWorkspaceCentre},
  };
  return methods;
}

std::vector<Method> parse_methods(const std::string& list) {
  std::vector<Method> chosen;
  for (const std::string& name : split_list(list)) {
    const auto& all = table1_methods();
    const auto it =
        std::find_if(all.begin(), all.end(), [&](const Method& m) { return m.name == name; });
    if (it == all.end()) {
      throw InvalidArgument("--methods: unknown method '" + name + "': use " + kMethodNames);
    }
    if (std::any_of(chosen.begin(), chosen.end(),
                    [&](const Method& m) { return m.name == name; })) {
      throw InvalidArgument("--methods: '" + name + "' is listed twice: name each method once");
    }
    chosen.push_back(*it);
  }
  if (chosen.empty()) {
    throw InvalidArgument(std::string("--methods is empty: name at least one of ") + kMethodNames);
  }
  return chosen;
}

std::vector<std::string> parse_heads(const std::string& list) {
  std::vector<std::string> heads;
  for (const std::string& head : split_list(list)) {
    if (head != "flow" && head != "ddpm" && head != "cvae") {
      throw InvalidArgument("--heads: unknown head '" + head + "': use flow, ddpm, cvae");
    }
    if (std::find(heads.begin(), heads.end(), head) != heads.end()) {
      throw InvalidArgument("--heads: '" + head + "' is listed twice: name each head once");
    }
    heads.push_back(head);
  }
  if (heads.empty())
    throw InvalidArgument("--heads is empty: name at least one of flow, ddpm, cvae");
  return heads;
}

std::optional<PaperRow> paper_row(const std::string& method, const std::string& head) {
  if (method == "hand_centric" && head == "flow") {
    return PaperRow{"Hand-Centric-Flow", {0.01, 0.25, 0.56, 0.79, 0.90, 0.94, 0.98}, 0.96};
  }
  if (method == "relative" && head == "flow") {
    return PaperRow{"Relative-Action-Flow", {0.00, 0.00, 0.05, 0.16, 0.42, 0.48, 0.58}, 0.01};
  }
  if (method == "absolute" && head == "flow") {
    return PaperRow{"Absolute-Action-Flow", {0.00, 0.00, 0.01, 0.06, 0.08, 0.12, 0.14}, 0.02};
  }
  if (method == "c8_centre" || method == "c8_base" || method == "c8_averaged" ||
      method == "c8flow_centre" || method == "c8flow_averaged") {
    return PaperRow{"Equivariant-DiffPo [7]", {0.00, 0.01, 0.03, 0.07, 0.12, 0.18, 0.27}, 0.12};
  }
  return std::nullopt;
}

}  // namespace handcentric::experiments
