// The JSON document of `handcentric audit --json` (docs/AUDIT.md).
#include <cmath>
#include <nlohmann/json.hpp>

#include "handcentric/props/audit.hpp"
#include "handcentric/props/checks/policy_audit.hpp"

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

nlohmann::json number_or_inf(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json("inf");
}

// A failing check: the number of the case (from 1, near-identity ones included) on which the
// search first failed, before shrinking; `cases` counts the far cases up to it. null when no
// case failed.
nlohmann::json failed_at_case(const Verdict& v) {
  return v.witness ? nlohmann::json(v.cases + v.near_identity_cases) : nlohmann::json(nullptr);
}

// A scene as the --exec protocol sends it (extra poses and scalars only when it has them).
nlohmann::json scene_json(const Scene& scene) {
  nlohmann::json history = nlohmann::json::array(), chunk = nlohmann::json::array();
  for (const auto& T : scene.world_T_hand_history) history.push_back(matrix16(T));
  for (const auto& T : scene.world_T_hand_chunk) chunk.push_back(matrix16(T));
  nlohmann::json out = {{"history", history},
                        {"chunk", chunk},
                        {"hand_points", points(scene.hand_points)},
                        {"world_points", points(scene.world_points)}};
  if (!scene.extra_poses.empty()) {
    nlohmann::json extra = nlohmann::json::object();
    for (const auto& [name, T] : scene.extra_poses) extra[name] = matrix16(T);
    out["extra_poses"] = extra;
  }
  if (!scene.scalars.empty()) {
    nlohmann::json scalars = nlohmann::json::object();
    for (const auto& [name, value] : scene.scalars) scalars[name] = value;
    out["scalars"] = scalars;
  }
  if (!scene.held.empty()) {  // described, not copied: an image would swamp the report
    nlohmann::json held = nlohmann::json::object();
    for (const auto& [name, array] : scene.held) held[name] = array->describe();
    out["held"] = held;
  }
  return out;
}

nlohmann::json witness_json(const Witness& w, Method method) {
  nlohmann::json out = {
      {"g", matrix16(w.g)},        {"scene", scene_json(w.scene)},    {"before", numbers(w.before)},
      {"after", numbers(w.after)}, {"error", number_or_inf(w.error)},
  };
  // A witness of the tests has a p-value below its level; one of an exact comparison (of every
  // coordinate, or of the affine ones of a partly_exact cell) has p = 1 and a tolerance.
  if (method != Method::exact_gaussian && w.p_value < 1.0) {
    out["p_value"] = w.p_value;
    out["alpha"] = w.tolerance;
  } else {
    out["tolerance"] = w.tolerance;
  }
  if (!w.detail.empty()) out["detail"] = w.detail;
  if (method != Method::energy_test && w.length_scale > 0.0) out["length_scale"] = w.length_scale;
  if (w.rounding_response > 0.0) out["rounding_response"] = w.rounding_response;
  if (w.off_case) out["off_case"] = true;
  if (w.noise_seed) out["noise_seed"] = *w.noise_seed;
  return out;
}

// What a pointwise decision adds to a check (check.hpp): the cases that sat on a discontinuity.
void add_rounding_fields(nlohmann::json& check, const Verdict& v) {
  if (v.mode != Mode::pointwise) return;
  check["discontinuities"] = v.discontinuities;
  // What a pointwise "yes" could have missed (verdict.hpp).
  if (v.invariant) check["detectable_frequency"] = detectable_frequency(v.cases);
}

// Its calls and rows are left out: a batched audit asks more (the batch check), and its JSON is
// the unbatched one's, byte for byte (batch.hpp).
nlohmann::json preflight_json(const Preflight& p) {
  return {{"repeatable", p.repeatable},
          {"note", p.note},
          {"draws", p.draws},
          {"repeat_difference", p.repeat_difference}};
}

nlohmann::json injectivity_json(const Injectivity& injectivity) {
  nlohmann::json out = {{"injective", injectivity.injective ? nlohmann::json(*injectivity.injective)
                                                            : nlohmann::json(nullptr)},
                        {"how", injectivity.how},
                        {"cases", injectivity.cases},
                        {"round_trips", injectivity.round_trips},
                        {"collision", nullptr},
                        {"round_trip_failure", nullptr}};
  const auto number_or_null = [](const std::optional<double>& x) {
    return x ? nlohmann::json(*x) : nlohmann::json(nullptr);
  };
  out["resolution"] = number_or_null(injectivity.resolution);
  out["resolution_unit"] = injectivity.resolution ? nlohmann::json(injectivity.resolution_unit)
                                                  : nlohmann::json(nullptr);
  out["translation_resolution"] = number_or_null(injectivity.translation_resolution);
  out["rotation_resolution"] = number_or_null(injectivity.rotation_resolution);
  out["smallest_loss"] = kSmallestLoss;
  nlohmann::json scales = nlohmann::json::array();
  for (const ScaleCollisions& s : injectivity.scales) {
    scales.push_back(
        {{"scale", s.scale}, {"unit", s.unit}, {"pairs", s.pairs}, {"collisions", s.collisions}});
  }
  out["scales"] = scales;
  if (const auto& c = injectivity.collision) {
    out["collision"] = {{"first", scene_json(c->first)},
                        {"second", scene_json(c->second)},
                        {"actions", numbers(c->actions_first)},
                        {"actions_second", numbers(c->actions_second)},
                        {"chunk_distance", c->chunk_distance},
                        {"action_distance", c->action_distance},
                        {"tolerance", c->tolerance},
                        {"change", c->change},
                        {"search", c->search}};
  }
  if (const auto& r = injectivity.round_trip_failure) {
    nlohmann::json decoded = nlohmann::json::array();
    for (const auto& T : r->decoded) decoded.push_back(matrix16(T));
    out["round_trip_failure"] = {{"scene", scene_json(r->scene)},
                                 {"decoded", decoded},
                                 {"error", number_or_inf(r->error)},
                                 {"tolerance", r->tolerance}};
  }
  return out;
}

// {view: {component: {mode: {group: invariant}}}}
nlohmann::json summary_json(const Classification& classification) {
  nlohmann::json summary = nlohmann::json::object();
  for (const Verdict& v : classification.verdicts) {
    summary[to_string(v.view)][to_string(v.component)][to_string(v.mode)][to_string(v.group)] =
        v.invariant;
  }
  return summary;
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
          {"view", to_string(v.view)},
          {"invariant", v.invariant},
          {"max_error", number_or_inf(v.max_error)},
          {"cases", v.cases},
          {"near_identity_cases", v.near_identity_cases},
          {"failed_at_case", failed_at_case(v)},
          {"seed", v.seed},
          {"relative_tolerance", v.relative_tolerance},
          {"witness", v.witness ? witness_json(*v.witness, v.method) : nlohmann::json(nullptr)},
      };
      if (v.mode == Mode::distribution) {
        check["method"] = to_string(v.method);
        if (v.method != Method::exact_gaussian) check["min_p_value"] = v.min_p_value;
        if (v.detectable_shift) check["detectable_shift"] = *v.detectable_shift;
        if (v.detectable_scale_ratio) check["detectable_scale_ratio"] = *v.detectable_scale_ratio;
      }
      add_rounding_fields(check, v);
      if (!v.note.empty()) check["note"] = v.note;
      checks.push_back(check);
    }
    nlohmann::json representation = {{"name", classification.name},
                                     {"summary", summary_json(classification)}};
    if (classification.injectivity) {
      representation["injective"] = classification.injectivity->injective
                                        ? nlohmann::json(*classification.injectivity->injective)
                                        : nlohmann::json(nullptr);
      representation["injectivity"] = injectivity_json(*classification.injectivity);
    }
    representation["checks"] = checks;
    representations.push_back(representation);
  }
  return nlohmann::json({{"representations", representations}}).dump(2) + "\n";
}

}  // namespace handcentric::props

namespace handcentric::props {

std::string policy_audit_json(const std::vector<Classification>& policies,
                              const PolicyInterface* interface) {
  nlohmann::json out = nlohmann::json::array();
  for (const Classification& policy : policies) {
    nlohmann::json checks = nlohmann::json::array(), summary = nlohmann::json::object();
    for (const Verdict& v : policy.verdicts) {
      nlohmann::json check = {
          {"group", to_string(v.group)},
          {"mode", to_string(v.mode)},
          {"view", to_string(v.view)},
          {"equivariant", v.invariant},
          {"max_error", number_or_inf(v.max_error)},
          {"cases", v.cases},
          {"near_identity_cases", v.near_identity_cases},
          {"failed_at_case", failed_at_case(v)},
          {"seed", v.seed},
          {"relative_tolerance", v.relative_tolerance},
          {"witness", v.witness ? witness_json(*v.witness, v.method) : nlohmann::json(nullptr)},
      };
      if (v.mode == Mode::distribution) {
        check["method"] = to_string(v.method);
        if (v.method != Method::exact_gaussian) check["min_p_value"] = v.min_p_value;
        if (v.detectable_shift) check["detectable_shift"] = *v.detectable_shift;
        if (v.detectable_scale_ratio) check["detectable_scale_ratio"] = *v.detectable_scale_ratio;
      }
      add_rounding_fields(check, v);
      if (!v.note.empty()) check["note"] = v.note;
      if (policy.output) {
        check["output"] = policy.output->name;
        check["kind"] = to_string(policy.output->kind);
      }
      checks.push_back(check);
      summary[to_string(v.view)][to_string(v.mode)][to_string(v.group)] = v.invariant;
    }
    nlohmann::json entry = {{"name", policy.name}, {"summary", summary}, {"checks", checks}};
    if (policy.output) {
      entry["output"] = policy.output->name;
      entry["kind"] = to_string(policy.output->kind);
    }
    if (policy.preflight) entry["preflight"] = preflight_json(*policy.preflight);
    if (interface != nullptr) {
      nlohmann::json outputs = nlohmann::json::object();
      for (const NamedOutput& o : interface->outputs) outputs[o.name] = to_string(o.kind);
      entry["interface"] = {{"state_format", interface->state_format.name()},
                            {"action_format", interface->action_format.name()},
                            {"outputs", outputs},
                            {"hands", interface->hands},
                            {"rng", interface->rng.empty() ? nlohmann::json(nullptr)
                                                           : nlohmann::json(interface->rng)},
                            {"episodes", interface->episodes}};
      if (!interface->stages.empty()) {
        nlohmann::json stages = nlohmann::json::array();
        for (const PipelineStage& stage : interface->stages)
          stages.push_back({{"name", stage.name}, {"kind", to_string(stage.kind)}});
        entry["interface"]["stages"] = std::move(stages);
      }
    }
    out.push_back(entry);
  }
  return nlohmann::json({{"policies", out}}).dump(2) + "\n";
}

}  // namespace handcentric::props
