// The JSON document of `handcentric audit --json` (docs/AUDIT.md).
#include <cmath>
#include <nlohmann/json.hpp>

#include "handcentric/props/audit.hpp"

namespace handcentric::props {
namespace {

nlohmann::json numbers(const Eigen::VectorXd& v) {
  nlohmann::json array = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) array.push_back(v(i));
  return array;
}

// A pose as its 16 numbers, row-major (the --exec protocol's layout).
nlohmann::json matrix16(const RigidTransform& T) {
  const Eigen::Matrix4d M = T.matrix();
  nlohmann::json array = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) array.push_back(M(r, c));
  }
  return array;
}

nlohmann::json points(const std::vector<Eigen::Vector3d>& xs) {
  nlohmann::json array = nlohmann::json::array();
  for (const auto& x : xs) array.push_back({x.x(), x.y(), x.z()});
  return array;
}

nlohmann::json witness_json(const Witness& w, Mode mode) {
  nlohmann::json history = nlohmann::json::array(), chunk = nlohmann::json::array();
  for (const auto& T : w.scene.world_T_hand_history) history.push_back(matrix16(T));
  for (const auto& T : w.scene.world_T_hand_chunk) chunk.push_back(matrix16(T));
  nlohmann::json out = {
      {"g", matrix16(w.g)},
      {"scene", {{"history", history}, {"chunk", chunk}, {"hand_points", points(w.scene.hand_points)},
                 {"world_points", points(w.scene.world_points)}}},
      {"before", numbers(w.before)},
      {"after", numbers(w.after)},
      {"error", std::isfinite(w.error) ? nlohmann::json(w.error) : nlohmann::json("inf")},
  };
  if (mode == Mode::distribution) {
    out["p_value"] = w.p_value;
    out["alpha"] = w.tolerance;
  } else {
    out["tolerance"] = w.tolerance;
  }
  return out;
}

}  // namespace

std::string audit_json(const std::vector<Classification>& classifications) {
  nlohmann::json representations = nlohmann::json::array();
  for (const Classification& classification : classifications) {
    nlohmann::json checks = nlohmann::json::array();
    for (const Verdict& v : classification.verdicts) {
      nlohmann::json check = {
          {"component", to_string(v.component)},
          {"group", to_string(v.group)},
          {"mode", to_string(v.mode)},
          {"invariant", v.invariant},
          {"max_error", std::isfinite(v.max_error) ? nlohmann::json(v.max_error) : nlohmann::json("inf")},
          {"cases", v.cases},
          {"near_identity_cases", v.near_identity_cases},
          {"seed", v.seed},
          {"witness", v.witness ? witness_json(*v.witness, v.mode) : nlohmann::json(nullptr)},
      };
      if (v.mode == Mode::distribution) check["min_p_value"] = v.min_p_value;
      checks.push_back(check);
    }
    representations.push_back({{"name", classification.name}, {"checks", checks}});
  }
  return nlohmann::json({{"representations", representations}}).dump(2) + "\n";
}

}  // namespace handcentric::props
